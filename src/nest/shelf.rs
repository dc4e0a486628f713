//! Shelf packing of bounding boxes: the simple, always valid layout (and the baseline
//! the peers use). Each part is turned to its smallest bounding box among `rotations`
//! steps, lying flat (wider than tall); parts go largest-height first into the first
//! shelf of the first sheet with room, shelves stack from the top of the sheet.

use glam::DVec2;

use super::layout::{Layout, Placement, SheetSpec, TooLarge};
use crate::plane::{orient, Oriented};

/// Lays out parts (outer outlines in mm). Deterministic: ties break by part index.
pub fn shelf_layout(
    parts: &[Vec<DVec2>],
    sheet: SheetSpec,
    rotations: u32,
) -> Result<Layout, TooLarge> {
    let (usable_w, usable_h) = (sheet.usable_width(), sheet.usable_height());
    let oriented: Vec<Oriented> = parts
        .iter()
        .enumerate()
        .map(|(i, outline)| {
            orient(outline, rotations, usable_w, usable_h).ok_or_else(|| {
                let best = orient(outline, rotations, f64::INFINITY, f64::INFINITY)
                    .map_or(DVec2::ZERO, |o| o.size);
                TooLarge {
                    part: i,
                    width: best.x,
                    height: best.y,
                    usable_width: usable_w,
                    usable_height: usable_h,
                }
            })
        })
        .collect::<Result<_, _>>()?;

    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| {
        let (sa, sb) = (oriented[a].size, oriented[b].size);
        sb.y.total_cmp(&sa.y)
            .then(sb.x.total_cmp(&sa.x))
            .then(a.cmp(&b))
    });

    struct Shelf {
        top: f64,
        height: f64,
        used: f64,
    }
    let mut sheets: Vec<Vec<Shelf>> = Vec::new();
    let mut placements = vec![Placement::default(); parts.len()];
    for i in order {
        let o = oriented[i];
        let (w, h) = (o.size.x, o.size.y);
        let mut spot = None;
        'search: for (s, shelves) in sheets.iter_mut().enumerate() {
            for shelf in shelves.iter_mut() {
                if h <= shelf.height && shelf.used + w <= usable_w {
                    spot = Some((s, shelf.used, shelf.top));
                    shelf.used += w + sheet.spacing;
                    break 'search;
                }
            }
            let below = shelves
                .last()
                .map_or(0.0, |l| l.top + l.height + sheet.spacing);
            if below + h <= usable_h {
                shelves.push(Shelf {
                    top: below,
                    height: h,
                    used: w + sheet.spacing,
                });
                spot = Some((s, 0.0, below));
                break;
            }
        }
        let (s, x, top) = spot.unwrap_or_else(|| {
            sheets.push(vec![Shelf {
                top: 0.0,
                height: h,
                used: w + sheet.spacing,
            }]);
            (sheets.len() - 1, 0.0, 0.0)
        });
        // Shelf `top` counts down from the sheet's top margin; the part's box sits
        // with its top edge on the shelf's top.
        let corner = DVec2::new(sheet.margin + x, sheet.height - sheet.margin - top - h);
        placements[i] = Placement {
            part: i,
            sheet: s,
            rotation: o.rotation,
            translation: corner - o.lo,
            mirrored: false,
        };
    }
    Ok(Layout {
        sheet,
        sheets: sheets.len(),
        placements,
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_rectangle as rect;
    use super::*;
    use crate::plane::bounds;

    #[test]
    fn boxes_stay_inside_margins_and_apart() {
        let sheet = SheetSpec {
            width: 100.0,
            height: 100.0,
            margin: 5.0,
            spacing: 2.0,
        };
        // 60 parts of 8 x (10..69): 18960 mm² against 8100 usable per sheet.
        let parts: Vec<Vec<DVec2>> = (0..60).map(|i| rect(10.0 + i as f64, 8.0)).collect();
        let layout = shelf_layout(&parts, sheet, 4).unwrap();
        assert!(layout.sheets >= 3);
        let boxes: Vec<(usize, DVec2, DVec2)> = layout
            .placements
            .iter()
            .map(|p| {
                let (lo, hi) = bounds(parts[p.part].iter().map(|&q| p.apply(q)));
                (p.sheet, lo, hi)
            })
            .collect();
        for &(_, lo, hi) in &boxes {
            assert!(lo.x >= 5.0 - 1e-9 && lo.y >= 5.0 - 1e-9);
            assert!(hi.x <= 95.0 + 1e-9 && hi.y <= 95.0 + 1e-9);
        }
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                if a.0 != b.0 {
                    continue;
                }
                let apart = a.2.x + 2.0 <= b.1.x + 1e-9
                    || b.2.x + 2.0 <= a.1.x + 1e-9
                    || a.2.y + 2.0 <= b.1.y + 1e-9
                    || b.2.y + 2.0 <= a.1.y + 1e-9;
                assert!(apart, "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn a_part_larger_than_the_sheet_is_refused() {
        let sheet = SheetSpec {
            width: 50.0,
            height: 50.0,
            margin: 5.0,
            spacing: 1.0,
        };
        let e = shelf_layout(&[rect(10.0, 10.0), rect(60.0, 60.0)], sheet, 32).unwrap_err();
        assert_eq!(e.part, 1);
        assert!((e.width - 60.0).abs() < 1e-9);
    }
}
