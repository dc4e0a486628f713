//! Unrolling a 3D panel into the plane: breadth-first over its facets, each rotated
//! about the hinge it shares with an already placed facet. The result is an isometry
//! per facet (used to place holes and labels, and given again by [`facet_frames`] to
//! map any flat point back to 3D), and the developability error is the largest change
//! of any facet edge length.

use std::collections::VecDeque;

use glam::{DVec2, DVec3};

use crate::labels::{fit_labels, LabelOptions, LeftOut};
use crate::mesh::geometry::vector_area;
use crate::panel::{
    fill_arena, FacetFrame, FlatHole, FlatPanel, FlatPanels, Fold, FoldKind, PanelRef, Panels,
    Tallied,
};
use crate::plane::loop_signed_area;

/// Why a panel cannot be unrolled (a bug in the scheme that made it).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FlattenError {
    /// An edge shared by more than two facets.
    #[error("panel {panel}: facet edge {a}-{b} is shared by more than two facets")]
    NonManifold { panel: String, a: u32, b: u32 },
    /// Facets that no hinge connects to the first.
    #[error("panel {panel}: its facets are not connected by hinges")]
    Disconnected { panel: String },
    /// The cut edges do not close into loops.
    #[error("panel {panel}: its outline does not close")]
    OpenOutline { panel: String },
    /// A facet with no area.
    #[error("panel {panel}: facet {facet} has no area")]
    DegenerateFacet { panel: String, facet: u32 },
}

/// One use of a facet edge: its two vertices (smaller first), the facet, and the
/// direction the facet runs it.
#[derive(Clone, Copy, Debug)]
struct EdgeUse {
    key: (u32, u32),
    facet: u32,
    from: u32,
    to: u32,
}

/// Fold angles up to this (radians) are not scored: the two facets are coplanar.
pub const LEAST_SCORED_FOLD: f64 = 1e-9;

/// Unrolls a panel. The first facet keeps its own frame (first corner at the origin,
/// first edge along +x); every other facet is placed across a hinge.
pub fn flatten<'a>(panel: impl Into<PanelRef<'a>>) -> Result<FlatPanel, FlattenError> {
    unroll(panel.into(), LEAST_SCORED_FOLD).map(|(flat, _)| flat)
}

/// The isometry of every facet of `panel` between 3D and the flat panel that
/// [`flatten`] makes of it: the flat panel's map back to 3D for any point (a hole, a
/// label). Flat panels do not keep it (a million panels would carry a hundred bytes
/// per facet for it), so it is computed again, by the same unrolling, where wanted.
pub fn facet_frames<'a>(panel: impl Into<PanelRef<'a>>) -> Result<Vec<FacetFrame>, FlattenError> {
    unroll(panel.into(), LEAST_SCORED_FOLD).map(|(_, frames)| frames)
}

/// The flat panel and its facet frames; hinges that fold by `least_fold` (radians) or
/// less are not scored.
fn unroll(panel: PanelRef, least_fold: f64) -> Result<(FlatPanel, Vec<FacetFrame>), FlattenError> {
    let fail_id = || panel.id().to_string();
    let normals = facet_normals(panel)?;
    let edges = edge_uses(panel);
    let (hinges, folds) = hinges_and_folds(panel, &normals, &edges, least_fold)?;
    let (points, frames) = lay_out_facets(panel, &normals, &hinges)?;

    let mut developability_error = 0.0f64;
    let mut area = 0.0;
    for facet in &panel.facets {
        area += loop_signed_area(&points, facet);
        for k in 0..facet.len() {
            let (i, j) = (facet[k] as usize, facet[(k + 1) % facet.len()] as usize);
            let d3 = panel.vertices[i].distance(panel.vertices[j]);
            let d2 = points[i].distance(points[j]);
            developability_error = developability_error.max((d3 - d2).abs());
        }
    }

    let outline = outline_loops(&edges, &points)
        .ok_or_else(|| FlattenError::OpenOutline { panel: fail_id() })?;
    let holes = panel
        .holes
        .iter()
        .map(|h| FlatHole {
            center: frames[h.facet as usize].to_2d(h.position),
            diameter: h.diameter,
            connection: h.connection,
            facet: h.facet,
        })
        .collect();
    let flat = FlatPanel {
        source: panel.source,
        points,
        outline: outline.into_iter().collect(),
        folds,
        holes,
        labels: Vec::new(),
        developability_error,
        area,
    };
    Ok((flat, frames))
}

/// The unit normal of every facet of `panel`; a facet without area is an error.
fn facet_normals(panel: PanelRef) -> Result<Vec<DVec3>, FlattenError> {
    panel
        .facets
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let n = vector_area(f.iter().map(|&i| panel.vertices[i as usize]));
            if n.length() > 0.0 {
                Ok(n.normalize())
            } else {
                Err(FlattenError::DegenerateFacet {
                    panel: panel.id().to_string(),
                    facet: k as u32,
                })
            }
        })
        .collect()
}

/// Every facet edge of `panel` once per use, grouped by its two vertices (smaller
/// first); the stable sort keeps the uses of an edge in facet order.
fn edge_uses(panel: PanelRef) -> Vec<EdgeUse> {
    let mut edges: Vec<EdgeUse> = Vec::with_capacity(panel.facets.index_count());
    for (k, facet) in panel.facets.iter().enumerate() {
        for i in 0..facet.len() {
            let (from, to) = (facet[i], facet[(i + 1) % facet.len()]);
            edges.push(EdgeUse {
                key: (from.min(to), from.max(to)),
                facet: k as u32,
                from,
                to,
            });
        }
    }
    edges.sort_by_key(|e| e.key);
    edges
}

/// A hinge: (facet, other facet, a, b), where the two facets share the edge ab.
type Hinge = (u32, u32, u32, u32);

/// The hinges between facets, both ways, sorted by their first facet (in edge order
/// per facet), and the folds: the hinges that bend by more than `least_fold`. An edge
/// used by three or more facets is an error.
fn hinges_and_folds(
    panel: PanelRef,
    normals: &[DVec3],
    edges: &[EdgeUse],
    least_fold: f64,
) -> Result<(Vec<Hinge>, Vec<Fold>), FlattenError> {
    let mut hinges: Vec<Hinge> = Vec::new();
    let mut folds = Vec::new();
    for users in edges.chunk_by(|x, y| x.key == y.key) {
        let (a, b) = users[0].key;
        match users {
            [_] => {}
            [f_use, g_use] => {
                let (f, g) = (f_use.facet, g_use.facet);
                hinges.push((f, g, a, b));
                hinges.push((g, f, a, b));
                let (nf, ng) = (normals[f as usize], normals[g as usize]);
                // atan2 of sine and cosine: acos of a cosine next to 1 is off by 1e-8.
                if nf.cross(ng).length().atan2(nf.dot(ng)) > least_fold {
                    // The edge runs from → to in f.
                    let along =
                        panel.vertices[f_use.to as usize] - panel.vertices[f_use.from as usize];
                    let kind = FoldKind::between(nf, ng, along);
                    folds.push(Fold { ends: [a, b], kind });
                }
            }
            _ => {
                return Err(FlattenError::NonManifold {
                    panel: panel.id().to_string(),
                    a,
                    b,
                })
            }
        }
    }
    hinges.sort_by_key(|h| h.0);
    Ok((hinges, folds))
}

/// Every vertex of `panel` laid flat and every facet's frame: the first facet on the
/// x axis, then each facet turned about a hinge onto the one it joins, breadth first.
/// A facet no hinge reaches is an error.
fn lay_out_facets(
    panel: PanelRef,
    normals: &[DVec3],
    hinges: &[Hinge],
) -> Result<(Vec<DVec2>, Vec<FacetFrame>), FlattenError> {
    let hinges_of = |f: usize| {
        let start = hinges.partition_point(|h| (h.0 as usize) < f);
        let end = hinges.partition_point(|h| (h.0 as usize) <= f);
        &hinges[start..end]
    };
    let mut points = vec![DVec2::NAN; panel.vertices.len()];
    let mut frames: Vec<Option<FacetFrame>> = vec![None; panel.facets.len()];
    let mut queue = VecDeque::new();
    if let Some(first) = panel.facets.first() {
        let (a, b) = (first[0] as usize, first[1] as usize);
        frames[0] = Some(FacetFrame::on_hinge(
            panel.vertices[a],
            panel.vertices[b],
            normals[0],
            DVec2::ZERO,
            DVec2::X,
        ));
        queue.push_back(0usize);
    }
    while let Some(f) = queue.pop_front() {
        let frame = frames[f].expect("queued facets have frames");
        for &i in &panel.facets[f] {
            if points[i as usize].is_nan() {
                points[i as usize] = frame.to_2d(panel.vertices[i as usize]);
            }
        }
        for &(_, g, a, b) in hinges_of(f) {
            let g = g as usize;
            if frames[g].is_some() {
                continue;
            }
            // Rotate g about the hinge: its frame sits on the hinge, whose ends are
            // already placed by f.
            let (a, b) = (a as usize, b as usize);
            frames[g] = Some(FacetFrame::on_hinge(
                panel.vertices[a],
                panel.vertices[b],
                normals[g],
                points[a],
                points[b],
            ));
            queue.push_back(g);
        }
    }
    let frames: Vec<FacetFrame> =
        frames
            .into_iter()
            .collect::<Option<_>>()
            .ok_or_else(|| FlattenError::Disconnected {
                panel: panel.id().to_string(),
            })?;
    Ok((points, frames))
}

/// Unrolls a panel and fits its labels: the flatten stage for one panel. Returns how
/// many labels were left out.
pub fn unroll_and_fit<'a>(
    panel: impl Into<PanelRef<'a>>,
    options: LabelOptions,
) -> Result<(FlatPanel, LeftOut), FlattenError> {
    unroll_fit(panel.into(), options, LEAST_SCORED_FOLD)
}

/// [`unroll_and_fit`], scoring only hinges that fold by more than `least_fold`
/// (radians): the labels fit as the flatten stage fits them for a scheme that scores
/// only those.
pub fn unroll_fit(
    panel: PanelRef,
    options: LabelOptions,
    least_fold: f64,
) -> Result<(FlatPanel, LeftOut), FlattenError> {
    let (mut flat, frames) = unroll(panel, least_fold)?;
    let left_out = fit_labels(&mut flat, panel, &frames, options);
    Ok((flat, left_out))
}

/// Unrolls every panel and fits its labels (the pipeline's flatten stage), in
/// parallel, scoring the hinges that fold by more than `least_fold` (radians; the
/// scheme's, or [`LEAST_SCORED_FOLD`]); the flat panels come in panel order, in one arena,
/// with how many labels were left out. On failure the error is that of the first
/// panel, in panel order, that fails, whatever the thread count.
pub fn unroll_all(
    panels: &Panels,
    options: LabelOptions,
    least_fold: f64,
) -> Result<(FlatPanels, LeftOut), FlattenError> {
    let Tallied {
        panels: mut flat,
        tally: left_out,
    } = fill_arena(panels.len(), |i| {
        crate::internal::for_panel(i, || unroll_fit(panels.get(i), options, least_fold))
    })?;
    flat.shrink_to_fit();
    Ok((flat, left_out))
}

/// Chains the edges used by one facet into loops, outer (largest area, counter-
/// clockwise) first; each loop starts at its smallest vertex, loops in the order of
/// those. `None` when they do not close or a corner has two ways on.
fn outline_loops(edges: &[EdgeUse], points: &[DVec2]) -> Option<Vec<Vec<u32>>> {
    const NONE: u32 = u32::MAX;
    let mut next_of = vec![NONE; points.len()];
    for users in edges.chunk_by(|x, y| x.key == y.key) {
        if let [cut] = users {
            let slot = next_of.get_mut(cut.from as usize)?;
            if *slot != NONE {
                return None;
            }
            *slot = cut.to;
        }
    }
    let mut loops = Vec::new();
    for start in 0..next_of.len() {
        if next_of[start] == NONE {
            continue;
        }
        let mut lp = vec![start as u32];
        let mut at = std::mem::replace(&mut next_of[start], NONE);
        while at as usize != start {
            lp.push(at);
            let next = std::mem::replace(next_of.get_mut(at as usize)?, NONE);
            if next == NONE {
                return None;
            }
            at = next;
        }
        loops.push(lp);
    }
    if loops.is_empty() {
        return None;
    }
    // Outer loop first: the largest absolute area.
    let areas: Vec<f64> = loops
        .iter()
        .map(|lp| loop_signed_area(points, lp))
        .collect();
    let outer = (0..loops.len())
        .max_by(|&a, &b| areas[a].abs().total_cmp(&areas[b].abs()))
        .unwrap_or(0);
    loops.swap(0, outer);
    Some(loops)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::{Hole, Panel, Source};
    use crate::plane::signed_area;

    /// A unit square facet and a second square folded up by 90° along x = 1, plus a
    /// hole on the folded facet.
    fn folded_strip() -> Panel {
        Panel::new(
            Source::face(0),
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
            ],
            [vec![0, 1, 2, 3], vec![1, 4, 5, 2]].into_iter().collect(),
            vec![Hole {
                position: DVec3::new(1.0, 0.5, 0.5),
                diameter: 0.1,
                connection: 7,
                facet: 1,
            }],
            vec![],
        )
    }

    #[test]
    fn folded_strip_unrolls_flat_and_keeps_lengths() {
        let flat = flatten(&folded_strip()).unwrap();
        assert!(flat.developability_error < 1e-12);
        assert!((flat.area - 2.0).abs() < 1e-12);
        // Unrolled, the fold at x = 1 opens to a 2 x 1 rectangle.
        assert!(flat.points[4].distance(DVec2::new(2.0, 0.0)) < 1e-12);
        assert!(flat.points[5].distance(DVec2::new(2.0, 1.0)) < 1e-12);
        // Folded up towards the first facet's outside: a valley.
        assert_eq!(
            flat.folds,
            vec![Fold {
                ends: [1, 2],
                kind: FoldKind::Valley
            }]
        );
        assert_eq!(flat.outline.len(), 1);
        assert_eq!(flat.outline[0].len(), 6);
        assert!(signed_area(&flat.outer()) > 0.0, "outside face up");
        // The hole maps into the plane and back to the same 3D point.
        let hole = &flat.holes[0];
        assert!(hole.center.distance(DVec2::new(1.5, 0.5)) < 1e-12);
        let back = facet_frames(&folded_strip()).unwrap()[1].to_3d(hole.center);
        assert!(back.distance(DVec3::new(1.0, 0.5, 0.5)) < 1e-12);
    }

    #[test]
    fn folded_away_from_the_outside_is_a_mountain() {
        let mut panel = folded_strip();
        panel.vertices[4] = DVec3::new(1.0, 0.0, -1.0);
        panel.vertices[5] = DVec3::new(1.0, 1.0, -1.0);
        panel.holes.clear();
        let flat = flatten(&panel).unwrap();
        assert_eq!(flat.folds.len(), 1);
        assert_eq!(flat.folds[0].kind, FoldKind::Mountain);
    }

    #[test]
    fn coplanar_facets_are_not_scored() {
        let mut panel = folded_strip();
        panel.vertices[4] = DVec3::new(2.0, 0.0, 0.0);
        panel.vertices[5] = DVec3::new(2.0, 1.0, 0.0);
        panel.holes.clear();
        let flat = flatten(&panel).unwrap();
        assert!(flat.folds.is_empty());
    }

    #[test]
    fn disconnected_facets_are_an_error() {
        let mut panel = folded_strip();
        panel.facets = [vec![0, 1, 2], vec![4, 5, 3]].into_iter().collect();
        panel.vertices[3] = DVec3::new(5.0, 5.0, 0.0);
        panel.holes.clear();
        assert!(flatten(&panel).is_err());
    }
}
