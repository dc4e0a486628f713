//! Fitting labels into flat panels: each label keeps its wanted cap height if its text
//! box fits inside its facet (with a margin), clear of holes and of labels already
//! placed; otherwise it shrinks, and below the smallest legible height it is left out.

use glam::DVec2;

use crate::font::text_width;
pub use crate::panel::label_box;
use crate::panel::{
    box_area, label_extent, FacetFrame, FlatLabel, FlatPanel, Fold, LabelKind, LoopsRef, PanelRef,
    FRAME_PAD, TIGHT_FRAME_PAD,
};
pub use crate::panel::{LeftOut, MIN_HEIGHT};
use crate::plane::{contains, distance_to_border, polygons_touch, segments_intersect};

/// Label fitting settings (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LabelOptions {
    /// Free space kept around a label's box.
    pub margin: f64,
}

impl Default for LabelOptions {
    fn default() -> Self {
        Self { margin: 0.5 }
    }
}

/// Shrink factor per attempt.
const SHRINK: f64 = 0.9;

/// How many times labels are fitted again to give each kind one height.
const HEIGHT_PASSES: usize = 3;

/// Where a sliding partner id is tried along its reading direction, in parts of its
/// slide, nearest its anchor first; other labels try [`COARSE_SLIDES`].
const SLIDES: [f64; 9] = [0.0, -0.25, 0.25, -0.5, 0.5, -0.75, 0.75, -1.0, 1.0];
const COARSE_SLIDES: [f64; 5] = [0.0, -0.5, 0.5, -1.0, 1.0];

/// Free space kept between two labels, in cap heights of the taller one: about a word
/// space, so neighbouring ids never read as one ("E587 F371", not "E587F371").
pub const LABEL_GAP: f64 = 0.4;

/// Fits the labels a scheme wants on a panel (the 3D panel `source`'s labels, mapped
/// through the facet frames of its unrolling); returns how many of each kind were
/// left out. Panel ids go first, then partner ids, then marks, so the important ones
/// get the room. Labels of one kind share one height where room allows: when a fit
/// gives them different heights, they are fitted again at most at the smallest, and
/// the new fit is kept unless it leaves more of some kind out. No label is larger
/// than the panel's own id, which a builder looks for first: where one would be, the
/// others are fitted again at most at the id's height.
pub fn fit_labels(
    panel: &mut FlatPanel,
    source: PanelRef,
    frames: &[FacetFrame],
    options: LabelOptions,
) -> LeftOut {
    let mut chosen = fit_pass(panel, source, frames, options, [f64::INFINITY; 3]);
    for _ in 0..HEIGHT_PASSES {
        let caps = height_caps(&chosen.labels);
        if within(&chosen.labels, caps) {
            break;
        }
        let next = fit_pass(panel, source, frames, options, caps);
        let keeps_all = LabelKind::ALL
            .into_iter()
            .all(|kind| next.dropped.of(kind) <= chosen.dropped.of(kind));
        if !keeps_all {
            break;
        }
        chosen = next;
    }
    // Kept even if it leaves a partner id out: an id smaller than the labels beside
    // it reads as one of them.
    let caps = id_caps(&chosen.labels);
    if !within(&chosen.labels, caps) {
        chosen = fit_pass(panel, source, frames, options, caps);
    }
    panel.labels = chosen.labels;
    chosen.dropped
}

/// The height each kind of label is fitted at most at in the next pass: its smallest
/// height now (one height per kind), and for the others no more than the panel's id.
fn height_caps(labels: &[FlatLabel]) -> [f64; 3] {
    let mut smallest = [f64::INFINITY; 3];
    for label in labels {
        let k = kind_index(label.kind);
        smallest[k] = smallest[k].min(label.height);
    }
    let id = smallest[kind_index(LabelKind::Panel)];
    smallest.map(|cap| cap.min(id))
}

/// No cap for the id; the other kinds at most at the id's height.
fn id_caps(labels: &[FlatLabel]) -> [f64; 3] {
    let id = labels
        .iter()
        .filter(|l| l.kind == LabelKind::Panel)
        .map(|l| l.height)
        .fold(f64::INFINITY, f64::min);
    let mut caps = [id; 3];
    caps[kind_index(LabelKind::Panel)] = f64::INFINITY;
    caps
}

/// Whether every label is at most its kind's cap (to rounding).
fn within(labels: &[FlatLabel], caps: [f64; 3]) -> bool {
    labels
        .iter()
        .all(|l| l.height <= caps[kind_index(l.kind)] * (1.0 + 1e-9))
}

/// Slot of a kind in per-kind arrays.
fn kind_index(kind: LabelKind) -> usize {
    match kind {
        LabelKind::Panel => 0,
        LabelKind::Partner => 1,
        LabelKind::Mark => 2,
    }
}

/// The labels one fitting pass placed, and how many it left out.
struct Fitted {
    labels: Vec<FlatLabel>,
    dropped: LeftOut,
}

/// One fitting pass, each label at most at its wanted height and at its kind's cap.
fn fit_pass(
    panel: &FlatPanel,
    source: PanelRef,
    frames: &[FacetFrame],
    options: LabelOptions,
    caps: [f64; 3],
) -> Fitted {
    let wanted_labels = source.labels;
    let facets = source.facets;
    let mut order: Vec<usize> = (0..wanted_labels.len()).collect();
    order.sort_by_key(|&i| (wanted_labels[i].kind, i));
    let mut placed: Vec<Placed> = Vec::new();
    let mut labels = Vec::new();
    let mut dropped = source.labels_dropped;
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
        let is_panel = wanted.kind == LabelKind::Panel;
        if is_panel {
            // A panel without its id cannot be found: if the wanted place is too
            // small, try the panel's largest facets.
            attempts.extend(fallback_attempts(panel, facets, wanted.facet as usize));
        }
        let text = Text {
            frame: 0.0,
            thorough: wanted.kind == LabelKind::Partner,
            width: text_width(wanted.text),
            height: wanted.height.min(caps[kind_index(wanted.kind)]),
        };
        // A panel id is framed; on a panel too small for the frame, tightly framed,
        // and only on one too small for that, unframed rather than missing.
        let frame_pads: &[f64] = if is_panel {
            &[FRAME_PAD, TIGHT_FRAME_PAD, 0.0]
        } else {
            &[0.0]
        };
        let fitted = frame_pads.iter().find_map(|&frame| {
            let text = Text { frame, ..text };
            attempts.iter().find_map(|attempt| {
                fit_one(panel, facets, attempt, text, &placed, options).map(|fit| (fit, frame))
            })
        });
        match fitted {
            Some(((center, direction, height, bx), frame)) => {
                placed.push(Placed { bx, height });
                labels.push(FlatLabel {
                    text: wanted.text,
                    center,
                    direction,
                    height,
                    kind: wanted.kind,
                    frame,
                });
            }
            None => dropped.count(wanted.kind),
        }
    }
    Fitted { labels, dropped }
}

/// What is being fitted: its frame (see [`FlatLabel::frame`]), its text width at cap
/// height 1 and the largest cap height it may have.
#[derive(Clone, Copy)]
struct Text {
    frame: f64,
    width: f64,
    height: f64,
    /// Searched at more places (partner ids: what the builder pairs panels by).
    thorough: bool,
}

/// A label already placed: its box and cap height.
struct Placed {
    bx: [DVec2; 4],
    height: f64,
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
fn fallback_attempts(panel: &FlatPanel, facets: LoopsRef, skip: usize) -> Vec<Attempt> {
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

/// The largest height (from the text's height down, shrinking) and position at which
/// a label fits in its attempt's facet: (centre, direction, height, box).
fn fit_one(
    panel: &FlatPanel,
    facets: LoopsRef,
    attempt: &Attempt,
    text: Text,
    placed: &[Placed],
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
    let steps: &[f64] = if text.thorough {
        &SLIDES
    } else {
        &COARSE_SLIDES
    };
    let slides: Vec<f64> = if attempt.slide > 0.0 {
        steps.iter().map(|f| f * attempt.slide).collect()
    } else {
        vec![0.0]
    };
    // A box inside the facet has less area than the facet: heights whose box is
    // larger are skipped untested (the same heights are visited, so the result is
    // that of testing them all). Most labels of tiny panels fail here at once.
    let room = crate::plane::area(&facet);
    let mut height = text.height;
    while height >= MIN_HEIGHT && box_area(text.frame, text.width, height) > room {
        height *= SHRINK;
    }
    while height >= MIN_HEIGHT {
        let (width, across) = label_extent(text.frame, text.width, height);
        // A sliding partner id may also step sideways by up to its own height, round
        // holes and labels placed before it; an edge label keeps to its edge.
        let sideways: &[f64] = if text.thorough && attempt.slide > 0.0 && !attempt.on_edge {
            &[0.0, -0.5, 0.5, -1.0, 1.0]
        } else {
            &[0.0]
        };
        for &side in sideways {
            for &shift in &slides {
                let mut center =
                    attempt.anchor + shift * direction + side * height * direction.perp();
                if attempt.on_edge {
                    // Twice the margin off the edge: the fit test wants at least one
                    // margin, and rounding must not make an exact margin fail every
                    // size.
                    center += (2.0 * options.margin + 0.5 * across) * direction.perp();
                }
                let bx = label_box(center, direction, width, across);
                if box_fits(&bx, height, &facet, panel, placed, options.margin) {
                    return Some((center, direction, height, bx));
                }
            }
        }
        height *= SHRINK;
    }
    None
}

fn box_fits(
    bx: &[DVec2; 4],
    height: f64,
    facet: &[DVec2],
    panel: &FlatPanel,
    placed: &[Placed],
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
    // Clear of holes and score lines. What lies beyond the box's bounds, farther than
    // it must keep clear, is passed untested (a label box is tried at many places).
    let (lo, hi) = crate::plane::bounds(bx.iter().copied());
    let beyond = |points: &[DVec2], clear: f64| {
        let reach = clear.max(0.0) + 1e-6;
        points.iter().all(|p| p.x < lo.x - reach)
            || points.iter().all(|p| p.x > hi.x + reach)
            || points.iter().all(|p| p.y < lo.y - reach)
            || points.iter().all(|p| p.y > hi.y + reach)
    };
    for hole in &panel.holes {
        let clear = 0.5 * hole.diameter + margin;
        if beyond(&[hole.center], clear) {
            continue;
        }
        if contains(bx, hole.center) || distance_to_border(bx, hole.center) < clear {
            return false;
        }
    }
    for &Fold { ends: [a, b], .. } in &panel.folds {
        let (p, q) = (panel.points[a as usize], panel.points[b as usize]);
        if beyond(&[p, q], 0.0) {
            continue;
        }
        if contains(bx, p) || (0..4).any(|k| segments_intersect(p, q, bx[k], bx[(k + 1) % 4])) {
            return false;
        }
    }
    // Clear of labels already placed: their boxes grown by the gap between labels
    // (a box grown by d reaches at most d√2 further along either axis).
    placed.iter().all(|other| {
        let gap = margin.max(LABEL_GAP * height.max(other.height));
        beyond(&other.bx, 1.5 * gap) || !polygons_touch(bx, &grow(&other.bx, gap))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::unroll_and_fit;
    use crate::panel::{Label, Name, Panel, Source};
    use glam::DVec3;

    fn label(text: Name, kind: LabelKind, facet: u32, height: f64, anchor: DVec3) -> Label {
        Label {
            text,
            anchor,
            direction: DVec3::Y,
            height,
            facet,
            kind,
            on_edge: false,
            slide: 0.0,
        }
    }

    /// A 20 mm square facet hinged along x = 20 to a strip 20 mm long whose far side
    /// is `across` from the hinge.
    fn square_beside(across: DVec3, labels: Vec<Label>) -> Panel {
        let hinge = [DVec3::new(20.0, 0.0, 0.0), DVec3::new(20.0, 20.0, 0.0)];
        Panel::new(
            Source::edge(7),
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                hinge[0],
                hinge[1],
                DVec3::new(0.0, 20.0, 0.0),
                hinge[0] + across,
                hinge[1] + across,
            ],
            [vec![0, 1, 2, 3], vec![1, 4, 5, 2]].into_iter().collect(),
            Vec::new(),
            labels,
        )
    }

    /// A 20 mm square facet hinged to a 0.2 mm wide strip folded up by 90°.
    fn square_and_strip(labels: Vec<Label>) -> Panel {
        square_beside(DVec3::new(0.0, 0.0, 0.2), labels)
    }

    #[test]
    fn labels_that_cannot_fit_are_dropped_early_without_changing_the_fit() {
        let on_strip = DVec3::new(20.0, 10.0, 0.1);
        let on_square = DVec3::new(4.0, 10.0, 0.0);
        let wanted = vec![
            // The panel id may move to the square: kept.
            label(Name::edge(7), LabelKind::Panel, 1, 3.0, on_strip),
            // A partner id on the 4 mm² strip: its box at 1.5 mm is larger.
            label(Name::edge(123), LabelKind::Partner, 1, 3.0, on_strip),
            // A mark on the square: kept.
            label(Name::vertex(5), LabelKind::Mark, 0, 3.0, on_square),
            // Wanted below the legible height: never tried.
            label(Name::face(9), LabelKind::Mark, 0, 1.0, on_square),
        ];
        assert!(box_area(0.0, text_width(Name::edge(123)), MIN_HEIGHT) > 1.01 * 4.0);
        let pruned = square_and_strip(wanted.clone());
        let kinds: Vec<LabelKind> = pruned.labels.iter().map(|l| l.kind).collect();
        assert_eq!(kinds, [LabelKind::Panel, LabelKind::Mark]);
        assert_eq!(
            pruned.labels_dropped,
            LeftOut {
                panel: 0,
                partner: 1,
                mark: 1
            }
        );
        // The same panel keeping every label fits the same labels, at the same places,
        // and leaves out as many of each kind.
        let full = Panel {
            labels: wanted,
            labels_dropped: LeftOut::default(),
            ..pruned.clone()
        };
        let options = LabelOptions::default();
        let (flat_pruned, out_pruned) = unroll_and_fit(&pruned, options).unwrap();
        let (flat_full, out_full) = unroll_and_fit(&full, options).unwrap();
        assert_eq!(flat_pruned.labels, flat_full.labels);
        assert_eq!(flat_pruned.labels.len(), 2, "{:?}", flat_pruned.labels);
        assert_eq!(out_pruned, out_full);
        assert_eq!(out_full.total(), 2);
    }

    #[test]
    fn no_label_is_larger_than_the_panels_own_id() {
        // A 20 mm square beside a 5 mm wide strip in its plane; the id is wanted on
        // the strip, where it fits only small, and a partner id 4 mm high on the square.
        let panel = square_beside(
            DVec3::new(5.0, 0.0, 0.0),
            vec![
                label(
                    Name::edge(7),
                    LabelKind::Panel,
                    1,
                    4.0,
                    DVec3::new(22.5, 10.0, 0.0),
                ),
                label(
                    Name::edge(123),
                    LabelKind::Partner,
                    0,
                    4.0,
                    DVec3::new(10.0, 10.0, 0.0),
                ),
            ],
        );
        let (flat, left_out) = unroll_and_fit(&panel, LabelOptions::default()).unwrap();
        assert_eq!(left_out.total(), 0);
        let height = |kind: LabelKind| {
            flat.labels
                .iter()
                .find(|l| l.kind == kind)
                .map(|l| l.height)
                .unwrap()
        };
        let id = height(LabelKind::Panel);
        assert!(id < 4.0 * SHRINK, "the id is on the strip: {id} mm");
        assert!(
            height(LabelKind::Partner) <= id * (1.0 + 1e-9),
            "{:?}",
            flat.labels
        );
    }
}
