//! Fitting labels into flat panels: each label keeps its wanted cap height if its text
//! box fits inside its facet (with a margin), clear of holes and of labels already
//! placed; otherwise it shrinks, and below the smallest legible height it is left out.

use glam::DVec2;

use crate::font::text_strokes;
use crate::panel::{FlatLabel, FlatPanel, LabelKind};
use crate::plane::{contains, distance_to_border, polygons_touch, segments_intersect};

/// Label fitting settings (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelOptions {
    /// Smallest cap height worth engraving.
    pub min_height: f64,
    /// Free space kept around a label's box.
    pub margin: f64,
}

impl Default for LabelOptions {
    fn default() -> Self {
        Self {
            min_height: 1.5,
            margin: 0.5,
        }
    }
}

/// Shrink factor per attempt.
const SHRINK: f64 = 0.9;

/// The text box of a label: corners counter-clockwise (baseline first).
pub fn label_box(center: DVec2, direction: DVec2, width: f64, height: f64) -> [DVec2; 4] {
    let along = 0.5 * width * direction;
    let up = 0.5 * height * direction.perp();
    [
        center - along - up,
        center + along - up,
        center + along + up,
        center - along + up,
    ]
}

/// Fits the panel's wanted labels; returns how many were left out. The panel's own id
/// goes first so it gets the room it needs.
pub fn fit_labels(panel: &mut FlatPanel, options: LabelOptions) -> usize {
    let mut order: Vec<usize> = (0..panel.wanted_labels.len()).collect();
    order.sort_by_key(|&i| (panel.wanted_labels[i].kind != LabelKind::Panel, i));
    let mut placed: Vec<[DVec2; 4]> = Vec::new();
    let mut labels = Vec::new();
    let mut dropped = 0;
    for i in order {
        let wanted = &panel.wanted_labels[i];
        let frame = panel.frames[wanted.facet as usize];
        let facet: Vec<DVec2> = panel.facets[wanted.facet as usize]
            .iter()
            .map(|&k| panel.points[k as usize])
            .collect();
        let anchor = frame.to_2d(wanted.anchor);
        let direction = frame.direction_to_2d(wanted.direction).normalize_or_zero();
        if direction == DVec2::ZERO {
            dropped += 1;
            continue;
        }
        let text_width = text_strokes(&wanted.text).width;
        let mut height = wanted.height;
        let mut fitted = None;
        // Positions along the reading direction, nearest the anchor first.
        let slides: Vec<f64> = if wanted.slide > 0.0 {
            [0.0, -0.5, 0.5, -1.0, 1.0]
                .iter()
                .map(|f| f * wanted.slide)
                .collect()
        } else {
            vec![0.0]
        };
        'sizes: while height >= options.min_height {
            for &shift in &slides {
                let mut center = anchor + shift * direction;
                if wanted.on_edge {
                    // Twice the margin off the edge: the fit test wants at least one
                    // margin, and rounding must not make an exact margin fail every
                    // size.
                    center += (2.0 * options.margin + 0.5 * height) * direction.perp();
                }
                let bx = label_box(center, direction, text_width * height, height);
                if box_fits(&bx, &facet, panel, &placed, options.margin) {
                    fitted = Some((center, bx));
                    break 'sizes;
                }
            }
            height *= SHRINK;
        }
        match fitted {
            Some((center, bx)) => {
                placed.push(bx);
                labels.push(FlatLabel {
                    text: wanted.text.clone(),
                    center,
                    direction,
                    height,
                    kind: wanted.kind,
                });
            }
            None => dropped += 1,
        }
    }
    panel.labels = labels;
    dropped
}

fn box_fits(
    bx: &[DVec2; 4],
    facet: &[DVec2],
    panel: &FlatPanel,
    placed: &[[DVec2; 4]],
    margin: f64,
) -> bool {
    // Inside the facet, away from its border.
    if !bx
        .iter()
        .all(|&c| contains(facet, c) && distance_to_border(facet, c) >= margin)
    {
        return false;
    }
    for i in 0..facet.len() {
        let (p, q) = (facet[i], facet[(i + 1) % facet.len()]);
        if contains(bx, p) || (0..4).any(|k| segments_intersect(p, q, bx[k], bx[(k + 1) % 4])) {
            return false;
        }
    }
    // Clear of holes and score lines.
    for hole in &panel.holes {
        let clear = 0.5 * hole.diameter + margin;
        if contains(bx, hole.center) || distance_to_border(bx, hole.center) < clear {
            return false;
        }
    }
    for &[a, b] in &panel.scores {
        let (p, q) = (panel.points[a as usize], panel.points[b as usize]);
        if contains(bx, p) || (0..4).any(|k| segments_intersect(p, q, bx[k], bx[(k + 1) % 4])) {
            return false;
        }
    }
    // Clear of labels already placed (their boxes grown by the margin).
    placed.iter().all(|other| {
        let grown = grow(other, margin);
        !polygons_touch(bx, &grown)
    })
}

/// A box grown by `d` on every side.
fn grow(bx: &[DVec2; 4], d: f64) -> [DVec2; 4] {
    let along = (bx[1] - bx[0]).normalize_or_zero();
    let up = along.perp();
    [
        bx[0] - d * along - d * up,
        bx[1] + d * along - d * up,
        bx[2] + d * along + d * up,
        bx[3] - d * along + d * up,
    ]
}
