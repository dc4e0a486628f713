//! The pieces cut from the welded strips: the island engine's islands grown along
//! each strip's rungs, cut again where a piece meets itself, and joined where one has
//! no room for its id.

use std::collections::BTreeMap;

use rayon::prelude::*;

use super::welded::{shared_edge, Welded};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::scheme::island::{islands_along, IslandNames, IslandNet, IslandOptions, OwnNet};
use crate::scheme::SchemeOutput;

/// The pieces: islands grown along the strips' rungs, in order, each strip longer than
/// `piece_length` first cut at rungs into equal pieces no longer. A piece whose outline,
/// tabs included, meets itself when unrolled (its faces wrap round a corner of its
/// strip's side until two of their edges lie on one line) is cut at its middle rung
/// and the pieces are grown again. A piece with no room for its id (a sliver where a
/// strip's two curves nearly touch, or a stub at a strip's end) is joined to the
/// neighbour piece it shares its longest edge with, or the next, as far as the join
/// keeps that piece clear of itself and on the sheet. Returns the net and each
/// piece's faces, in the order of its panels.
pub(super) fn clear_pieces(
    welded: &Welded,
    options: &IslandOptions,
    piece_length: f64,
    tab_first: &dyn Fn(HalfedgeId) -> bool,
) -> (IslandNet, Vec<Vec<u32>>) {
    // The faces of each piece, in the order of the panels, as the net names them.
    let members = std::cell::RefCell::new(Vec::new());
    let names = |faces: &[Vec<u32>]| {
        *members.borrow_mut() = faces.to_vec();
        welded.names(faces)
    };
    let mut folds = welded.shorter_than(piece_length);
    // Each piece without room for its id, by its lowest face: the edges it may join a
    // neighbour along, longest first, and which of them is tried.
    let mut joins: BTreeMap<u32, (Vec<EdgeId>, usize)> = BTreeMap::new();
    loop {
        let own = OwnNet {
            names: &names,
            tab_first,
            seams: true,
        };
        let mut along = folds.clone();
        along.extend(joins.values().filter_map(|(edges, k)| edges.get(*k)));
        let net = islands_along(&welded.mesh, options, &along, &IslandNames::Own(own));
        let faces_of = members.borrow();
        let cut = net.output.panels.iter().enumerate().find_map(|(k, panel)| {
            let flat = crate::flatten::flatten(panel).ok()?;
            if crate::plane::is_simple(&flat.outer()) {
                return None;
            }
            middle_rung(&welded.mesh, &faces_of[k], &folds)
        });
        if let Some(rung) = cut {
            folds.retain(|&e| e != rung);
            continue;
        }
        if !next_joins(
            &welded.mesh,
            &net.output,
            &faces_of,
            options.flat_fold,
            &mut joins,
        ) {
            drop(faces_of);
            return (net, members.take());
        }
    }
}

/// Updates the joins of pieces with no room for their id (`joins`, see
/// [`clear_pieces`]) after a net was grown with them (its ids fitted as the flatten
/// stage fits them, scoring folds over `least_fold`): a piece still without room
/// tries its next edge, a new one its first, and one whose last edge left it without
/// room drops that join, which only took its neighbour's room. False when nothing
/// changed.
fn next_joins(
    mesh: &Mesh,
    output: &SchemeOutput,
    faces_of: &[Vec<u32>],
    least_fold: f64,
    joins: &mut BTreeMap<u32, (Vec<EdgeId>, usize)>,
) -> bool {
    let labels = crate::labels::LabelOptions::default();
    let roomless: Vec<bool> = (0..output.panels.len())
        .into_par_iter()
        .map(|k| {
            crate::flatten::unroll_fit(output.panels.get(k), labels, least_fold)
                .is_ok_and(|(_, left)| left.panel > 0)
        })
        .collect();
    let mut piece_of = vec![usize::MAX; mesh.face_count()];
    for (k, faces) in faces_of.iter().enumerate() {
        for &f in faces {
            piece_of[f as usize] = k;
        }
    }
    let mut changed = false;
    for (k, faces) in faces_of.iter().enumerate() {
        if !roomless[k] {
            continue;
        }
        let tried = joins
            .iter_mut()
            .find(|(first, _)| piece_of[**first as usize] == k);
        match tried {
            // Past the last edge, no edge is tried (`edges.get` finds none).
            Some((_, (edges, next))) if *next < edges.len() => {
                *next += 1;
                changed = true;
            }
            Some(_) => {}
            None => {
                let piece = |f: u32| piece_of[f as usize];
                let edges = joining_edges(mesh, faces, &piece, &|k| !roomless[k]);
                changed |= !edges.is_empty();
                joins.insert(faces[0], (edges, 0));
            }
        }
    }
    changed
}

/// The longest edge between `faces` and each other piece that has room for its id
/// (`piece_of` a face, `roomy`), longest first: a join refused along one edge is
/// seldom made along a shorter one to the same piece.
fn joining_edges(
    mesh: &Mesh,
    faces: &[u32],
    piece_of: &dyn Fn(u32) -> usize,
    roomy: &dyn Fn(usize) -> bool,
) -> Vec<EdgeId> {
    let mut longest: BTreeMap<usize, (f64, EdgeId)> = BTreeMap::new();
    for h in faces.iter().flat_map(|&f| mesh.face_half_edges(FaceId(f))) {
        let Some(across) = mesh.face(h.twin()) else {
            continue;
        };
        let piece = piece_of(across.0);
        if faces.contains(&across.0) || !roomy(piece) {
            continue;
        }
        let edge = (mesh.edge_length(h.edge()), h.edge());
        let best = longest.entry(piece).or_insert(edge);
        if edge.0 > best.0 || (edge.0 == best.0 && edge.1 < best.1) {
            *best = edge;
        }
    }
    let mut edges: Vec<(f64, EdgeId)> = longest.into_values().collect();
    edges.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    edges.into_iter().map(|(_, e)| e).collect()
}

/// The fold between two faces of `faces` (a run of one strip) nearest its middle.
fn middle_rung(mesh: &Mesh, faces: &[u32], folds: &[EdgeId]) -> Option<EdgeId> {
    let mid = faces.len() / 2;
    let mut order: Vec<usize> = (1..faces.len()).collect();
    order.sort_by_key(|&k| k.abs_diff(mid));
    order.into_iter().find_map(|k| {
        shared_edge(mesh, FaceId(faces[k - 1]), FaceId(faces[k])).filter(|e| folds.contains(e))
    })
}
