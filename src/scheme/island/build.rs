//! A net from grown islands: the tabs placed on its cuts, the islands named and
//! numbered, their panels, and what the report says of them.

use std::collections::{BTreeMap, HashMap};

use glam::DVec2;

use super::grow::{fold_angle, Islands, JoinRules};
use super::options::{IslandOptions, ISLAND};
use super::panel::{island_panel, BuiltNet};
use super::summary::Summary;
use super::tabs::{clear_tab, fits_sheet, tab_options, Obstacle, ISLAND_GAP, NOTCH_GAP, TAB_STEPS};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::panel::surface::group_anchor;
use crate::panel::{Covers, FaceGroup, Name, Panel, Source};
use crate::plane::convex_hull;
use crate::scheme::kit::tab::{make_tab, Tab};
use crate::scheme::{ConnectionName, SchemeOutput};
use crate::union_find::UnionFind;

/// How a net's islands are named and what of the model they cover.
pub enum IslandNames<'a> {
    /// `N1`, `N2`, … in the order of their lowest face; each covers its faces.
    Numbered,
    /// Named by the scheme ([`OwnNet`]).
    Own(OwnNet<'a>),
}

/// What a scheme that grows a net its own way says of its islands and tabs.
pub struct OwnNet<'a> {
    /// The islands' names from every island's faces (in the order of their lowest
    /// face, each list increasing).
    pub names: &'a dyn Fn(&[Vec<u32>]) -> Vec<Name>,
    /// True when the face of half-edge `h` is to own its edge's tab, rather than the
    /// face across (that side is tried first).
    pub tab_first: &'a dyn Fn(HalfedgeId) -> bool,
    /// One match number for each seam (a run of cut edges end to end between the same
    /// two islands), inside the faces on both sides of the edge with the most room
    /// beside it, rather than one at every cut edge: along a strip's curve the edges
    /// are many and short.
    pub seams: bool,
}

/// A net and what its report says of it.
pub struct IslandNet {
    /// Its panels, connections and notes (no report or manifest lines yet).
    pub output: SchemeOutput,
    /// Its counts, for the scheme's report and manifest.
    pub summary: Summary,
}

/// Islands grown only along `folds`, in that order, each join still keeping the
/// island clear of itself and on the sheet with room for its tabs; every other
/// interior edge is cut and gets a tab. For a scheme that chooses its folds itself
/// (the strip scheme's rungs).
pub fn islands_along(
    mesh: &Mesh,
    options: &IslandOptions,
    folds: &[EdgeId],
    names: &IslandNames,
) -> IslandNet {
    let lengths = mesh.sorted_edge_lengths();
    let mut islands = Islands::of_faces(mesh, &lengths);
    let component_faces = vec![usize::MAX; mesh.face_count()];
    let rules = JoinRules {
        options,
        scale: lengths.last().copied().unwrap_or(1.0),
        spread: f64::INFINITY,
        small: usize::MAX,
        component_faces: &component_faces,
    };
    for &e in folds {
        islands.try_join(mesh, e, &rules);
    }
    let interior: Vec<EdgeId> = mesh
        .edges()
        .filter(|&e| fold_angle(mesh, e).is_some())
        .collect();
    island_net(mesh, options, islands, &interior, names)
}

/// The panels of grown islands: tabs on the interior edges of `order` left cut, the
/// islands numbered in the order of their lowest face.
pub(in crate::scheme) fn island_net(
    mesh: &Mesh,
    options: &IslandOptions,
    islands: Islands,
    order: &[EdgeId],
    names: &IslandNames,
) -> IslandNet {
    let cuts: Vec<EdgeId> = order
        .iter()
        .filter(|e| !islands.fold[e.index()])
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let first = |e: EdgeId| match names {
        // Even edges try the face of half-edge 2e first, odd ones the other.
        IslandNames::Numbered => e.0.is_multiple_of(2),
        IslandNames::Own(own) => (own.tab_first)(e.half_edge()),
    };
    let tabs = place_tabs(mesh, &islands, &cuts, options, &first);

    // Islands in the order of their lowest face, numbered from 1.
    let mut members: Vec<Vec<u32>> = islands
        .faces
        .iter()
        .filter(|f| !f.is_empty())
        .map(|f| {
            let mut f = f.clone();
            f.sort_unstable();
            f
        })
        .collect();
    members.sort();
    let ids: Vec<Name> = match names {
        IslandNames::Numbered => (1..=members.len() as u32)
            .map(|k| Name::new(&ISLAND, k))
            .collect(),
        IslandNames::Own(own) => (own.names)(&members),
    };
    let mut number = vec![0u32; mesh.face_count()];
    let mut facet_of = vec![0u32; mesh.face_count()];
    for (k, faces) in members.iter().enumerate() {
        for (i, &f) in faces.iter().enumerate() {
            number[f as usize] = k as u32 + 1;
            facet_of[f as usize] = i as u32;
        }
    }
    let seams = matches!(names, IslandNames::Own(OwnNet { seams: true, .. }));
    let net = BuiltNet {
        mesh,
        islands: &islands,
        tabs: &tabs,
        match_of: match_numbers(mesh, &cuts, &number, seams),
        seams,
        facet_of,
        options,
    };
    let built: Vec<Panel> = members
        .iter()
        .enumerate()
        .map(|(k, faces)| {
            let covers = Covers::Faces(k as u32);
            island_panel(&net, Source { id: ids[k], covers }, faces)
        })
        .collect();

    let tab_count = tabs.iter().flatten().count();
    let shortened = tabs.iter().flatten().filter(|t| t.shortened).count();
    let summary = Summary::of(
        mesh, &islands, &members, &cuts, tab_count, shortened, options,
    );
    let face_groups = members
        .into_iter()
        .map(|faces| FaceGroup {
            anchor: group_anchor(mesh, &faces),
            faces,
        })
        .collect();
    IslandNet {
        output: SchemeOutput {
            panels: built.into_iter().collect(),
            connections: cuts.len(),
            notes: tab_notes(cuts.len(), tab_count, shortened),
            unfastened: unfastened(mesh, &cuts, &tabs, (&number, &ids), options),
            face_groups,
            ..SchemeOutput::default()
        },
        summary,
    }
}

/// The tabs of every cut edge, by edge (`None`: no room for one). The island's hull,
/// tabs included, must still fit the sheet.
fn place_tabs(
    mesh: &Mesh,
    islands: &Islands,
    cuts: &[EdgeId],
    options: &IslandOptions,
    first: &dyn Fn(EdgeId) -> bool,
) -> Vec<Option<Tab>> {
    let mut placed: Vec<Option<Tab>> = (0..mesh.edge_count()).map(|_| None).collect();
    // Tabs already placed, per island: (owner face, flat outline); and the hulls.
    let mut island_tabs: HashMap<u32, Vec<(u32, Vec<DVec2>)>> = HashMap::new();
    let mut hulls: Vec<Vec<DVec2>> = islands.hull.clone();
    for &e in cuts {
        let h = e.half_edge();
        let sides = if first(e) {
            [h, h.twin()]
        } else {
            [h.twin(), h]
        };
        'found: for step in TAB_STEPS {
            for owner in sides {
                let Some(f) = mesh.face(owner) else { continue };
                let wanted = tab_options(options, step * options.tab_height);
                let Some(tab) = make_tab(mesh, owner, &wanted) else {
                    continue;
                };
                let frame = islands.tab_frame(mesh, owner);
                let island = islands.of_face[f.index()];
                // The faces folded to this one round the tab's ends come nearest its
                // inset base: they only have to stay clear of it.
                let need = |x: u32| {
                    if islands.meets_at(mesh, x, owner)
                        || islands.meets_at(mesh, x, mesh.next(owner))
                    {
                        NOTCH_GAP
                    } else {
                        ISLAND_GAP
                    }
                };
                let probe: Vec<DVec2> = [tab.base[1], tab.base[0]]
                    .iter()
                    .chain(&tab.top)
                    .map(|&p| frame.flat(p))
                    .collect();
                let mut obstacles: Vec<Obstacle> = islands.grid[island as usize]
                    .near(&probe)
                    .into_iter()
                    .filter(|&x| x != f.0)
                    .map(|x| Obstacle {
                        outline: islands.polygon(mesh, FaceId(x)).into(),
                        need: need(x),
                    })
                    .collect();
                // Tabs on other edges of the same face lie beyond different edges of a
                // convex polygon: they never meet.
                let others = island_tabs.entry(island).or_default();
                obstacles.extend(others.iter().filter(|(face, _)| *face != f.0).map(
                    |(face, outline)| Obstacle {
                        outline: outline.as_slice().into(),
                        need: need(*face),
                    },
                ));
                let Some((mut tab, outline)) = clear_tab(&tab, &frame, &obstacles, options) else {
                    continue;
                };
                let mut hull = hulls[island as usize].clone();
                hull.extend_from_slice(&outline);
                let hull = convex_hull(&hull);
                if !fits_sheet(&hull, options, 0.0) {
                    continue;
                }
                hulls[island as usize] = hull;
                others.push((f.0, outline));
                // Lower than asked for, or cut back (`clear_tab` says so).
                tab.shortened |= step < 1.0;
                placed[e.index()] = Some(tab);
                break 'found;
            }
        }
    }
    placed
}

/// The report's notes on cut edges left without a tab and tabs shortened.
fn tab_notes(cuts: usize, tabs: usize, shortened: usize) -> Vec<String> {
    let mut notes = Vec::new();
    if tabs < cuts {
        notes.push(format!(
            "{} of {cuts} cut edges have no tab: no room for one beside their island's other faces (glue them edge to edge, or try a smaller --tab-height)",
            cuts - tabs
        ));
    }
    if shortened > 0 {
        notes.push(format!(
            "{shortened} tabs were shortened to stay inside their neighbour face and clear of their island"
        ));
    }
    notes
}

/// The cuts whose tab holds no fastener hole although holes were asked for, named by
/// their two islands (`number` of each face) and the edge.
fn unfastened(
    mesh: &Mesh,
    cuts: &[EdgeId],
    tabs: &[Option<Tab>],
    (number, ids): (&[u32], &[Name]),
    options: &IslandOptions,
) -> Vec<ConnectionName> {
    if options.panel.holes == 0 {
        return Vec::new();
    }
    cuts.iter()
        .filter(|e| tabs[e.index()].as_ref().is_none_or(|t| t.holes.is_empty()))
        .filter_map(|&e| {
            let h = e.half_edge();
            let (f, g) = (mesh.face(h)?, mesh.face(h.twin())?);
            Some(ConnectionName {
                panels: [
                    ids[number[f.index()] as usize - 1],
                    ids[number[g.index()] as usize - 1],
                ],
                at: Name::edge(e.0),
            })
        })
        .collect()
}

/// A match number's width per unit of its height, about (three digits).
const NUMBER_WIDTH: f64 = 2.5;

/// Each cut edge's match number, from 1 in the order of `cuts`: one for each cut, or
/// with `seams`, one for each seam, only at the edge with the most room beside it (the
/// first of equals). `number` is each face's island.
fn match_numbers(mesh: &Mesh, cuts: &[EdgeId], number: &[u32], seams: bool) -> HashMap<u32, u32> {
    if !seams {
        return (cuts.iter().enumerate())
            .map(|(k, e)| (e.0, k as u32 + 1))
            .collect();
    }
    // The two islands a cut edge lies between, lower first.
    let islands = |e: EdgeId| {
        let h = e.half_edge();
        let of = |h: HalfedgeId| mesh.face(h).map_or(0, |f| number[f.index()]);
        let (a, b) = (of(h), of(h.twin()));
        (a.min(b), a.max(b))
    };
    // Cut edges meeting at a vertex between the same two islands are one seam.
    let mut seam_sets = UnionFind::new(cuts.len());
    let mut at_vertex: BTreeMap<(u32, (u32, u32)), u32> = BTreeMap::new();
    for (k, &e) in cuts.iter().enumerate() {
        let h = e.half_edge();
        for v in [mesh.origin(h), mesh.dest(h)] {
            match at_vertex.entry((v.0, islands(e))) {
                std::collections::btree_map::Entry::Vacant(slot) => {
                    slot.insert(k as u32);
                }
                std::collections::btree_map::Entry::Occupied(slot) => {
                    seam_sets.union(*slot.get(), k as u32);
                }
            }
        }
    }
    // The largest number an edge has room for beside it, about: its length over a
    // number's width per unit of height, or the height of the faces over it.
    let room = |e: EdgeId| {
        let h = e.half_edge();
        let length = mesh
            .position(mesh.origin(h))
            .distance(mesh.position(mesh.dest(h)));
        let height = |h: HalfedgeId| {
            mesh.face(h)
                .map_or(0.0, |f| 2.0 * mesh.face_area(f) / length)
        };
        (length / NUMBER_WIDTH).min(height(h)).min(height(h.twin()))
    };
    // Each seam's roomiest edge, seams in the order of their first edge.
    let mut roomiest: BTreeMap<u32, (u32, usize)> = BTreeMap::new();
    for (k, &e) in cuts.iter().enumerate() {
        let seam = seam_sets.find(k as u32);
        let first = roomiest.entry(seam).or_insert((k as u32, k));
        if room(e) > room(cuts[first.1]) {
            first.1 = k;
        }
    }
    let mut firsts: Vec<(u32, usize)> = roomiest.into_values().collect();
    firsts.sort_unstable();
    (firsts.iter().enumerate())
        .map(|(m, &(_, k))| (cuts[k].0, m as u32 + 1))
        .collect()
}
