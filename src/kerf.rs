//! Kerf compensation: the laser's beam burns away a strip of material as wide as its
//! kerf, centred on the path it follows, so every closed cut loop moves by half the
//! kerf into the waste: a panel's outline outward, its inner cuts inward, its holes
//! narrower. Score and engrave lines stay where they are (they remove no material
//! across).
//!
//! Where two cut edges run closer together than the kerf (a tab beside the face next to
//! it, the tip of a sharp notch), no path keeps the beam off the part; growing the
//! outline there would close the gap and leave the two joined. There the cut stays on
//! its nominal line, as if there were no kerf. Those places are what the panel's
//! morphological closing (grown, then shrunk back with round corners) adds to it: the
//! gaps narrower than the kerf, and in every inside corner the fillet a round beam
//! cannot reach, which is left alone when it is that small.
//!
//! The offsets and booleans are i_overlay's, on its integer grid (exact, and the same
//! on every machine), with mitred corners so a convex corner of the part stays sharp.

use glam::DVec2;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

use crate::panel::{fill_arena, FlatPanel, FlatPanelRef, FlatPanels, Loops, Tallied};
use crate::plane::{perimeter, signed_area};

/// Corners sharper than this (radians, inside angle) are bevelled instead of mitred:
/// the miter of a needle tip would reach far past the part for no gain.
const MITER_MIN_ANGLE: f64 = std::f64::consts::PI / 12.0;

/// The closing's gaps are opened by this (mm) before use: what is thinner is the
/// integer grid's rounding along edges that stay where they were.
const SLIVER: f64 = 1e-3;

/// A gap the closing fills counts as narrower than the kerf when its perimeter passes
/// this many kerfs: a smaller one is the fillet a round beam leaves in an inside corner
/// (a right angle's is under 2 kerfs round), or the last few tenths of a millimetre of
/// a notch, which the material tears through.
const GAP_MIN_PERIMETER: f64 = 4.0;

/// Corners closer together than this (mm) are merged, and a contour that folds back on
/// itself at one (a spike of the integer grid) loses it: the files give 0.1 µm.
const CORNER_MERGE: f64 = 1e-3;

/// Round corners of the shrinking step of the closing: segments of at most this
/// fraction of the radius.
const ROUND_STEP: f64 = 0.2;

/// Shapes as i_overlay takes them: each an outer contour (counter-clockwise) and its
/// holes (clockwise).
type Shapes = Vec<Vec<Vec<[f64; 2]>>>;

/// The panels with their cut loops offset for the kerf, and how many of them have cut
/// edges closer together than the kerf, cut on their nominal line there.
pub struct Compensated {
    /// The panels, in the order given.
    pub panels: FlatPanels,
    /// Panels with places where cut edges run closer together than the kerf.
    pub narrow_panels: usize,
}

/// Offsets every panel's cut loops by half of `kerf` (mm) and shrinks every fastener
/// hole's diameter by `kerf`, in parallel, the panels in their order. `kerf` must be
/// below every hole's diameter (the options check it).
pub fn compensate_all(panels: &FlatPanels, kerf: f64) -> Compensated {
    let tallied: Result<Tallied<usize>, std::convert::Infallible> = fill_arena(panels.len(), |i| {
        let (panel, narrow) = crate::internal::for_panel(i, || compensate(panels.get(i), kerf));
        Ok((panel, usize::from(narrow)))
    });
    let Ok(Tallied {
        mut panels,
        tally: narrow_panels,
    }) = tallied;
    panels.shrink_to_fit();
    Compensated {
        panels,
        narrow_panels,
    }
}

/// One panel compensated for `kerf`: the new loops' corners are appended to its points
/// (fold lines keep the nominal corners they end at), the outer outline first. Also
/// says whether some of its cut edges run closer together than the kerf.
pub fn compensate(panel: FlatPanelRef<'_>, kerf: f64) -> (FlatPanel, bool) {
    let mut flat = panel.to_flat_panel();
    if kerf <= 0.0 {
        return (flat, false);
    }
    for hole in &mut flat.holes {
        hole.diameter -= kerf;
    }
    let half = 0.5 * kerf;
    let part: Shapes = vec![panel
        .outline
        .iter()
        .map(|lp| {
            lp.iter()
                .map(|&i| point(panel.points[i as usize]))
                .collect()
        })
        .collect()];
    let grown = offset(&part, half, LineJoin::Miter(MITER_MIN_ANGLE));
    let closed = offset(&grown, -half, LineJoin::Round(ROUND_STEP));
    let mut gaps = closed.overlay_as::<i64>(&part, OverlayRule::Difference, FillRule::NonZero);
    if !gaps.is_empty() {
        // Opened a little: no whisker of the grid's rounding along an edge is left.
        let miter = || LineJoin::Miter(MITER_MIN_ANGLE);
        gaps = offset(&offset(&gaps, -SLIVER, miter()), SLIVER, miter());
    }
    gaps.retain(|shape| {
        let perimeter: f64 = shape
            .iter()
            .map(|c| perimeter(&c.iter().map(|&p| vec2(p)).collect::<Vec<_>>()))
            .sum();
        perimeter > GAP_MIN_PERIMETER * kerf
    });
    let narrow = !gaps.is_empty();
    let cut = if narrow {
        // OGC-valid: no contour touches itself, so every loop on the sheet is simple.
        FloatOverlay::<[f64; 2], i64>::from_subj_and_clip_custom(
            &grown,
            &gaps,
            OverlayOptions::ogc(),
            Solver::default(),
        )
        .overlay(OverlayRule::Difference, FillRule::NonZero)
    } else {
        grown
    };
    // The largest outline first, as the flatten stage orders loops; then every hole.
    let mut outers: Vec<Vec<DVec2>> = Vec::new();
    let mut inners: Vec<Vec<DVec2>> = Vec::new();
    for shape in cut {
        let mut contours = shape
            .into_iter()
            .map(|c| clean(c.into_iter().map(vec2).collect()));
        outers.extend(contours.next().flatten());
        // A hole much smaller than the beam is waste it burns anyway (the bottom of a
        // notch the grown outline closes over).
        inners.extend(
            contours
                .flatten()
                .filter(|c| perimeter(c) > GAP_MIN_PERIMETER * kerf),
        );
    }
    outers.sort_by(|a, b| signed_area(b).total_cmp(&signed_area(a)));
    let mut loops = Loops::with_capacity(outers.len() + inners.len(), 0);
    for contour in outers.iter().chain(&inners) {
        let start = flat.points.len() as u32;
        flat.points.extend_from_slice(contour);
        loops.push(start..start + contour.len() as u32);
    }
    flat.outline = loops;
    (flat, narrow)
}

/// A contour with corners nearer than [`CORNER_MERGE`] merged and fold-backs taken
/// out, or `None` when nothing with an area is left.
fn clean(mut contour: Vec<DVec2>) -> Option<Vec<DVec2>> {
    loop {
        let n = contour.len();
        if n < 3 {
            return None;
        }
        let drop = (0..n).find(|&i| {
            let (a, v, b) = (contour[(i + n - 1) % n], contour[i], contour[(i + 1) % n]);
            let (u, w) = (v - a, b - v);
            v.distance(b) < CORNER_MERGE
                || (u.perp_dot(w).abs() <= 1e-9 * u.length() * w.length() && u.dot(w) < 0.0)
        });
        match drop {
            Some(i) => {
                contour.remove(i);
            }
            None => break,
        }
    }
    (signed_area(&contour).abs() > CORNER_MERGE * CORNER_MERGE).then_some(contour)
}

fn point(p: DVec2) -> [f64; 2] {
    [p.x, p.y]
}

fn vec2([x, y]: [f64; 2]) -> DVec2 {
    DVec2::new(x, y)
}

/// `shapes` grown by `by` mm (shrunk when `by` < 0), corners joined by `join`.
fn offset(shapes: &Shapes, by: f64, join: LineJoin<f64>) -> Shapes {
    let mut style = OutlineStyle::new(by);
    style.join = join;
    shapes.outline_as::<i64>(&style)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::{FlatHole, Source};
    use crate::plane::distance_to_border;

    /// A 100 x 100 mm L-shaped panel with a square inner cut and a hole.
    fn l_panel() -> FlatPanel {
        let points = [
            (0.0, 0.0),
            (100.0, 0.0),
            (100.0, 50.0),
            (50.0, 50.0),
            (50.0, 100.0),
            (0.0, 100.0),
            (10.0, 10.0),
            (10.0, 30.0),
            (30.0, 30.0),
            (30.0, 10.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
        FlatPanel {
            source: Source::face(0),
            points,
            outline: [vec![0, 1, 2, 3, 4, 5], vec![6, 7, 8, 9]]
                .into_iter()
                .collect(),
            folds: vec![],
            holes: vec![FlatHole {
                center: DVec2::new(80.0, 20.0),
                diameter: 3.0,
                connection: 0,
                facet: 0,
            }],
            labels: vec![],
            developability_error: 0.0,
            area: 7500.0,
        }
    }

    /// Distance from `p` to the nearest cut loop of `flat`.
    fn to_cut(flat: &FlatPanel, p: DVec2) -> f64 {
        flat.outline
            .iter()
            .map(|lp| distance_to_border(&flat.loop_points(lp), p))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn outlines_grow_and_inner_cuts_shrink_by_half_the_kerf() {
        let kerf = 0.2;
        let (flat, narrow) = compensate(l_panel().view(), kerf);
        assert!(!narrow);
        assert_eq!(flat.outline.len(), 2);
        let outer = signed_area(&flat.loop_points(&flat.outline[0]));
        let inner = signed_area(&flat.loop_points(&flat.outline[1]));
        // Mitred corners: a rectilinear loop grows by its perimeter × K/2 and (K/2)²
        // per convex corner less (K/2)² per reflex one.
        let h = kerf / 2.0;
        assert!(
            (outer - (7500.0 + 400.0 * h + 4.0 * h * h)).abs() < 1e-6,
            "{outer}"
        );
        assert!(
            (inner - -(400.0 - 80.0 * h + 4.0 * h * h)).abs() < 1e-6,
            "{inner}"
        );
        assert!((flat.holes[0].diameter - 2.8).abs() < 1e-12);
        // The nominal corners stay for the fold lines; every one is half the kerf from
        // the beam's path.
        assert_eq!(flat.points[..10], l_panel().points[..]);
        // (The corners of the square cut are h√2 from its shrunk corners.)
        for &p in &l_panel().points {
            let d = to_cut(&flat, p);
            assert!(d > h - 1e-6 && d < h * 2f64.sqrt() + 1e-6, "{p}: {d}");
        }
    }

    #[test]
    fn an_inner_cut_narrower_than_the_kerf_stays_on_its_line() {
        let mut panel = l_panel();
        panel.points[8] = DVec2::new(10.1, 30.0);
        panel.points[9] = DVec2::new(10.1, 10.0);
        let (flat, narrow) = compensate(panel.view(), 0.2);
        assert!(narrow);
        assert_eq!(flat.outline.len(), 2);
        let inner = flat.loop_points(&flat.outline[1]);
        assert!((signed_area(&inner) + 2.0).abs() < 1e-6);
        for &p in &panel.points[6..] {
            assert!(to_cut(&flat, p) < 1e-6);
        }
    }

    #[test]
    fn a_slit_narrower_than_the_kerf_is_still_cut_open() {
        // Two prongs 0.05 mm apart, joined 10 mm down: growing the outline alone would
        // close the slit and leave the prongs joined.
        let points = [
            (0.0, 0.0),
            (20.05, 0.0),
            (20.05, 20.0),
            (10.05, 20.0),
            (10.05, 10.0),
            (10.0, 10.0),
            (10.0, 20.0),
            (0.0, 20.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
        let panel = FlatPanel {
            points: points.clone(),
            outline: [(0..8).collect::<Vec<u32>>()].into_iter().collect(),
            holes: vec![],
            ..l_panel()
        };
        let (flat, narrow) = compensate(panel.view(), 0.2);
        assert!(narrow);
        // The slit's sides and bottom are cut where they are; the rest grows.
        for &p in &points[3..7] {
            assert!(to_cut(&flat, p) < 1e-6, "{p}");
        }
        for &p in [points[0], points[1], points[2], points[7]].iter() {
            assert!((to_cut(&flat, p) - 0.1).abs() < 1e-6, "{p}");
        }
        // The slit is a loop of its own inside the grown outline.
        assert_eq!(flat.outline.len(), 2);
        let slit = signed_area(&flat.loop_points(&flat.outline[1]));
        assert!((slit + 0.5).abs() < 1e-6, "{slit}");
    }

    #[test]
    fn no_kerf_changes_nothing() {
        let (flat, narrow) = compensate(l_panel().view(), 0.0);
        assert_eq!((flat, narrow), (l_panel(), false));
    }
}
