//! Fitting labels into flat panels: each label keeps its wanted cap height if its text
//! box fits inside its facet (with a margin), clear of holes and of labels already
//! placed; otherwise it shrinks, and below the smallest legible height it is left out.

use glam::DVec2;

use crate::font::text_width;
use crate::panel::{FacetFrame, FlatLabel, FlatPanel, LabelKind, Loops, Panel};
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

/// How many labels of each kind were left out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeftOut {
    /// Panel ids.
    pub panel: usize,
    /// Partner ids at connections.
    pub partner: usize,
    /// Vertex and face marks.
    pub mark: usize,
}

impl LeftOut {
    /// All kinds together.
    pub fn total(&self) -> usize {
        self.panel + self.partner + self.mark
    }

    fn count(&mut self, kind: LabelKind) {
        match kind {
            LabelKind::Panel => self.panel += 1,
            LabelKind::Partner => self.partner += 1,
            LabelKind::Mark => self.mark += 1,
        }
    }
}

impl std::ops::Add for LeftOut {
    type Output = LeftOut;
    fn add(self, o: LeftOut) -> LeftOut {
        LeftOut {
            panel: self.panel + o.panel,
            partner: self.partner + o.partner,
            mark: self.mark + o.mark,
        }
    }
}

/// Fits the labels a scheme wants on a panel (the 3D panel `source`'s labels, mapped
/// through the facet frames of its unrolling); returns how many of each kind were
/// left out. Panel ids go first, then partner ids, then marks, so the important ones
/// get the room.
pub fn fit_labels(
    panel: &mut FlatPanel,
    source: &Panel,
    frames: &[FacetFrame],
    options: LabelOptions,
) -> LeftOut {
    let wanted_labels = &source.labels;
    let facets = &source.facets;
    let mut order: Vec<usize> = (0..wanted_labels.len()).collect();
    order.sort_by_key(|&i| (wanted_labels[i].kind, i));
    let mut placed: Vec<[DVec2; 4]> = Vec::new();
    let mut labels = Vec::new();
    let mut dropped = LeftOut::default();
    for i in order {
        let wanted = &wanted_labels[i];
        let frame = frames[wanted.facet as usize];
        let mut attempts = vec![Attempt {
            facet: wanted.facet as usize,
            anchor: frame.to_2d(wanted.anchor),
            direction: frame.direction_to_2d(wanted.direction).normalize_or_zero(),
            on_edge: wanted.on_edge,
            slide: wanted.slide,
        }];
        if wanted.kind == LabelKind::Panel {
            // A panel without its id cannot be found: if the wanted place is too
            // small, try the panel's largest facets.
            attempts.extend(fallback_attempts(panel, facets, wanted.facet as usize));
        }
        let text_width = text_width(wanted.text);
        let fitted = attempts.iter().find_map(|attempt| {
            fit_one(
                panel,
                facets,
                attempt,
                text_width,
                wanted.height,
                &placed,
                options,
            )
        });
        match fitted {
            Some((center, direction, height, bx)) => {
                placed.push(bx);
                labels.push(FlatLabel {
                    text: wanted.text,
                    center,
                    direction,
                    height,
                    kind: wanted.kind,
                });
            }
            None => dropped.count(wanted.kind),
        }
    }
    panel.labels = labels;
    dropped
}

/// One place to try a label.
struct Attempt {
    facet: usize,
    anchor: DVec2,
    direction: DVec2,
    on_edge: bool,
    slide: f64,
}

/// The three largest other facets, each at its centroid along its longest edge.
fn fallback_attempts(panel: &FlatPanel, facets: &Loops, skip: usize) -> Vec<Attempt> {
    let mut by_area: Vec<(f64, usize)> = facets
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != skip)
        .map(|(k, f)| {
            let pts: Vec<DVec2> = f.iter().map(|&i| panel.points[i as usize]).collect();
            (crate::plane::area(&pts), k)
        })
        .collect();
    by_area.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    by_area
        .into_iter()
        .take(3)
        .map(|(_, k)| {
            let pts: Vec<DVec2> = facets[k]
                .iter()
                .map(|&i| panel.points[i as usize])
                .collect();
            let n = pts.len();
            let longest = (0..n)
                .max_by(|&a, &b| {
                    let la = pts[a].distance(pts[(a + 1) % n]);
                    let lb = pts[b].distance(pts[(b + 1) % n]);
                    la.total_cmp(&lb).then(b.cmp(&a))
                })
                .unwrap_or(0);
            Attempt {
                facet: k,
                anchor: pts.iter().copied().sum::<DVec2>() / n as f64,
                direction: (pts[(longest + 1) % n] - pts[longest]).normalize_or_zero(),
                on_edge: false,
                slide: 0.0,
            }
        })
        .collect()
}

/// The largest height (from `wanted` down, shrinking) and position at which a label
/// fits in its attempt's facet: (centre, direction, height, box).
fn fit_one(
    panel: &FlatPanel,
    facets: &Loops,
    attempt: &Attempt,
    text_width: f64,
    wanted: f64,
    placed: &[[DVec2; 4]],
    options: LabelOptions,
) -> Option<(DVec2, DVec2, f64, [DVec2; 4])> {
    let direction = attempt.direction;
    if direction == DVec2::ZERO {
        return None;
    }
    let facet: Vec<DVec2> = facets[attempt.facet]
        .iter()
        .map(|&k| panel.points[k as usize])
        .collect();
    // Positions along the reading direction, nearest the anchor first.
    let slides: Vec<f64> = if attempt.slide > 0.0 {
        [0.0, -0.5, 0.5, -1.0, 1.0]
            .iter()
            .map(|f| f * attempt.slide)
            .collect()
    } else {
        vec![0.0]
    };
    // A box inside the facet has less area than the facet: heights whose box is
    // larger are skipped untested (the same heights are visited, so the result is
    // that of testing them all). Most labels of tiny panels fail here at once.
    let room = crate::plane::area(&facet).abs();
    let mut height = wanted;
    while height >= options.min_height && text_width * height * height > room {
        height *= SHRINK;
    }
    while height >= options.min_height {
        for &shift in &slides {
            let mut center = attempt.anchor + shift * direction;
            if attempt.on_edge {
                // Twice the margin off the edge: the fit test wants at least one
                // margin, and rounding must not make an exact margin fail every size.
                center += (2.0 * options.margin + 0.5 * height) * direction.perp();
            }
            let bx = label_box(center, direction, text_width * height, height);
            if box_fits(&bx, &facet, panel, placed, options.margin) {
                return Some((center, direction, height, bx));
            }
        }
        height *= SHRINK;
    }
    None
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
