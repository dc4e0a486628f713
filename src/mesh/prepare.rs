//! From a raw model to a valid half-edge mesh: every repair is reported with the element
//! it touched, every unrecoverable problem is an [`InputError`] naming file, element and
//! fix.
//!
//! Order matters: degenerate faces go first (they would fake non-manifold edges), then
//! unreferenced vertices, then the optional weld, then the edge-manifold check, then
//! orientation, then the half-edge build (which splits bow-tie vertices).

use std::collections::VecDeque;

use serde::Serialize;

use super::build::{build_mesh, BuildError, BuildReport};
use super::geometry::diameter;
use super::halfedge::Mesh;
use rayon::slice::ParallelSliceMut;

use super::polygons::Polygons;
use super::read::{Group, RawModel};
use super::soup::{corner_edge, soup_facts, CornerEdges, SoupFacts};
use super::weld::{cluster_positions, weld_tolerance, weld_where_manifold};
use crate::error::{InputError, Location};

/// Options of the prepare stage.
#[derive(Clone, Debug, Default)]
pub struct PrepareOptions {
    /// Merge vertices that share a position where the result stays manifold.
    pub weld: bool,
}

/// One repair or observation, for the report.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Note {
    /// A short stable key (`unreferenced-vertices`, `flipped-faces`, …).
    pub kind: &'static str,
    /// What happened, naming elements in the file's numbering.
    pub message: String,
}

/// A model ready for the schemes.
#[derive(Clone, Debug)]
pub struct PreparedModel {
    /// The valid, consistently oriented half-edge mesh (model units).
    pub mesh: Mesh,
    /// Facts of the input as the file gives it.
    pub input: SoupFacts,
    /// Facts of the welded soup (before bow-ties are split), with `--weld`.
    pub welded: Option<SoupFacts>,
    /// Repairs and observations, in the order they happened.
    pub notes: Vec<Note>,
    /// Named groups of the input.
    pub groups: Vec<Group>,
    /// The surface before simplifying (after repairs), as triangles in model units:
    /// kept when simplified and asked for (`ModelSettings::keep_unsimplified`).
    pub unsimplified: Option<Vec<[glam::DVec3; 3]>>,
}

/// How many elements a note names before it says "and N more".
const EXAMPLES: usize = 5;

/// Validates and repairs a raw model and builds its half-edge mesh.
pub fn prepare(raw: &RawModel, options: &PrepareOptions) -> Result<PreparedModel, InputError> {
    let input = soup_facts(&raw.polys);
    let mut notes = Vec::new();

    let (polys, face_source) = clean_faces(raw, &mut notes);
    if polys.face_count() == 0 {
        return Err(InputError::new(
            &raw.path,
            Location::File,
            "no usable faces are left after removing degenerate ones",
            "the model has no area; check the export",
        ));
    }
    let (mut polys, mut vertex_source) = drop_unused_vertices(raw, polys, &mut notes);

    let mut welded_facts = None;
    let tolerance = weld_tolerance(&polys.positions);
    if raw.welded_corners > 0 {
        notes.push(Note {
            kind: "welded-stl",
            message: format!(
                "STL triangle corners welded by position (tolerance {tolerance:.3e} model units): {} vertices",
                raw.polys.positions.len()
            ),
        });
    }
    if options.weld {
        (polys, vertex_source) = weld(raw, &polys, &vertex_source, tolerance, &mut notes);
        welded_facts = Some(soup_facts(&polys));
    } else {
        note_shared_positions(raw, &polys, &vertex_source, tolerance, &mut notes);
    }

    let located = Located {
        raw,
        face_source: &face_source,
        vertex_source: &vertex_source,
    };
    let edges = CornerEdges::new(&polys);
    check_edge_manifold(&polys, &edges, &located)?;
    orient(&mut polys, &edges, &located, &mut notes)?;
    drop(edges);

    let (mesh, report) = build_mesh(&polys, Some(&vertex_source), Some(&face_source))
        .map_err(|e| located.build_error(e))?;
    note_split_vertices(raw, &report, &mut notes);
    debug_assert_eq!(mesh.validate(), Ok(()));
    Ok(PreparedModel {
        mesh,
        input,
        welded: welded_facts,
        notes,
        groups: raw.groups.clone(),
        unsimplified: None,
    })
}

/// Drops the vertices no face uses, with a note naming them; returns the compacted soup
/// and its map to the file's vertices.
fn drop_unused_vertices(
    raw: &RawModel,
    polys: Polygons,
    notes: &mut Vec<Note>,
) -> (Polygons, Vec<u32>) {
    let unused: Vec<u32> = unused_vertices(&polys).collect();
    let (polys, vertex_source) = drop_unreferenced(polys, None);
    if !unused.is_empty() {
        notes.push(Note {
            kind: "unreferenced-vertices",
            message: format!(
                "{} vertices are used by no face and were dropped{}",
                unused.len(),
                examples(
                    unused
                        .iter()
                        .map(|&v| format!("vertex {}", raw.vertex_label(v))),
                    unused.len()
                )
            ),
        });
    }
    (polys, vertex_source)
}

/// Merges vertices that share a position where the mesh stays manifold (`--weld`),
/// with notes on what was merged and what was kept apart; returns the welded soup and
/// its map to the file's vertices.
fn weld(
    raw: &RawModel,
    polys: &Polygons,
    vertex_source: &[u32],
    tolerance: f64,
    notes: &mut Vec<Note>,
) -> (Polygons, Vec<u32>) {
    let (welded, report) = weld_where_manifold(polys, tolerance);
    let (welded, source) = drop_unreferenced(welded, Some(vertex_source));
    notes.push(Note {
        kind: "welded",
        message: format!(
            "--weld merged {} vertices that shared a position",
            report.merged
        ),
    });
    if !report.skipped.is_empty() {
        let count = report.skipped.len();
        notes.push(Note {
            kind: "weld-skipped",
            message: format!(
                "{count} groups of vertices share a position but were kept apart because merging them would make a non-manifold edge or a bow-tie vertex{}",
                examples(
                    report.skipped.iter().map(|g| {
                        let labels: Vec<String> = g
                            .iter()
                            .map(|&v| raw.vertex_label(v).to_string())
                            .collect();
                        format!("vertices {}", labels.join(" and "))
                    }),
                    count
                )
            ),
        });
    }
    (welded, source)
}

/// Notes the vertices that repeat another vertex's position, kept apart without
/// `--weld`.
fn note_shared_positions(
    raw: &RawModel,
    polys: &Polygons,
    vertex_source: &[u32],
    tolerance: f64,
    notes: &mut Vec<Note>,
) {
    let clusters = cluster_positions(&polys.positions, tolerance);
    let repeated: Vec<(u32, u32)> = clusters
        .iter()
        .enumerate()
        .filter(|&(i, &r)| r as usize != i)
        .map(|(i, &r)| (vertex_source[r as usize], vertex_source[i]))
        .collect();
    if !repeated.is_empty() {
        notes.push(Note {
            kind: "shared-positions",
            message: format!(
                "{} vertices repeat the position of another vertex and are kept apart (seams may be intentional; --weld merges them where the mesh stays manifold){}",
                repeated.len(),
                examples(
                    repeated.iter().map(|&(a, b)| format!(
                        "vertices {} and {}",
                        raw.vertex_label(a),
                        raw.vertex_label(b)
                    )),
                    repeated.len()
                )
            ),
        });
    }
}

/// Notes the bow-tie vertices the build split into one vertex per fan.
fn note_split_vertices(raw: &RawModel, report: &BuildReport, notes: &mut Vec<Note>) {
    if !report.split_vertices.is_empty() {
        let count = report.split_vertices.len();
        notes.push(Note {
            kind: "split-vertices",
            message: format!(
                "{count} vertices are bow-ties (separate fans of faces meet there) and were split into one vertex per fan{}",
                examples(
                    report.split_vertices.iter().map(|&(v, fans)| format!(
                        "vertex {} with {fans} fans",
                        raw.vertex_label(v)
                    )),
                    count
                )
            ),
        });
    }
}

/// Maps soup indices back to the user's file for messages.
struct Located<'a> {
    raw: &'a RawModel,
    face_source: &'a [u32],
    vertex_source: &'a [u32],
}

impl Located<'_> {
    fn face(&self, f: u32) -> String {
        let source = self.face_source[f as usize];
        match self.raw.face_location(source as usize) {
            Location::Line(n) => format!("face {source} (line {n})"),
            Location::Byte(n) => format!("triangle {source} (byte {n})"),
            Location::File => format!("face {source}"),
        }
    }

    fn location(&self, f: u32) -> Location {
        self.raw
            .face_location(self.face_source[f as usize] as usize)
    }

    fn vertex(&self, v: u32) -> u64 {
        self.raw.vertex_label(self.vertex_source[v as usize])
    }

    fn error(&self, f: u32, problem: String, fix: &str) -> InputError {
        InputError::new(&self.raw.path, self.location(f), problem, fix)
    }

    /// Build errors that the earlier checks should have caught, translated anyway.
    fn build_error(&self, e: BuildError) -> InputError {
        let face = match &e {
            BuildError::TooFewCorners { face, .. }
            | BuildError::IndexOutOfRange { face, .. }
            | BuildError::RepeatedVertex { face, .. } => Some(*face),
            BuildError::NonManifoldEdge { faces, .. } => faces.first().copied(),
            BuildError::InconsistentOrientation { faces, .. } => Some(faces[0]),
            BuildError::IsolatedVertex { .. } | BuildError::TooLarge => None,
        };
        match face {
            Some(f) => self.error(
                f,
                format!("{}: {e}", self.face(f)),
                "please report this model",
            ),
            None => InputError::new(
                &self.raw.path,
                Location::File,
                e.to_string(),
                "simplify the model",
            ),
        }
    }
}

/// "(e.g. a, b, c and 4 more)" for a note.
fn examples(items: impl Iterator<Item = String>, total: usize) -> String {
    let shown: Vec<String> = items.take(EXAMPLES).collect();
    if shown.is_empty() {
        return String::new();
    }
    let more = total.saturating_sub(shown.len());
    if more > 0 {
        format!(": {} and {more} more", shown.join(", "))
    } else {
        format!(": {}", shown.join(", "))
    }
}

/// Removes degenerate faces: repeated consecutive corners are collapsed; faces with
/// fewer than three distinct corners, pinched faces (a vertex visited twice), faces of
/// zero area and exact duplicates of an earlier face are dropped and reported.
fn clean_faces(raw: &RawModel, notes: &mut Vec<Note>) -> (Polygons, Vec<u32>) {
    let mut defects = FaceDefects::default();
    let (out, face_source) = drop_degenerate_faces(&raw.polys, &mut defects);
    let (out, face_source) = drop_duplicate_faces(out, face_source, &mut defects.duplicates);
    defects.report(raw, notes);
    (out, face_source)
}

/// The faces cleaning changed or dropped, in the file's numbering.
#[derive(Default)]
struct FaceDefects {
    /// Faces that repeated a corner in a row (kept, repeats removed).
    collapsed: Vec<usize>,
    /// Faces of fewer than three distinct corners.
    too_few: Vec<usize>,
    /// Faces that visit a vertex twice.
    pinched: Vec<usize>,
    /// Faces of zero area.
    zero_area: Vec<usize>,
    /// Faces that repeat an earlier face, with that earlier face.
    duplicates: Vec<(usize, u32)>,
}

/// Collapses repeated consecutive corners of every face and drops the faces left with
/// fewer than three distinct corners, pinched or of zero area, recording each in
/// `defects`; returns the kept faces and their indices in the file.
fn drop_degenerate_faces(src: &Polygons, defects: &mut FaceDefects) -> (Polygons, Vec<u32>) {
    let mut out = Polygons {
        positions: src.positions.clone(),
        ..Polygons::new()
    };
    let mut face_source = Vec::with_capacity(src.face_count());
    let mut corners: Vec<u32> = Vec::new();
    let mut sorted: Vec<u32> = Vec::new();
    let mut points = Vec::new();
    for (f, face) in src.faces().enumerate() {
        collapse_repeats(face, &mut corners);
        if corners.len() != face.len() {
            defects.collapsed.push(f);
        }
        sorted.clear();
        sorted.extend_from_slice(&corners);
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() < 3 {
            defects.too_few.push(f);
            continue;
        }
        if sorted.len() != corners.len() {
            defects.pinched.push(f);
            continue;
        }
        points.clear();
        points.extend(corners.iter().map(|&v| src.positions[v as usize]));
        let size = diameter(&points);
        if fan_area(&points) <= 1e-12 * size * size {
            defects.zero_area.push(f);
            continue;
        }
        out.push_face(&corners);
        face_source.push(f as u32);
    }
    (out, face_source)
}

/// Writes `face` into `corners` without corners that repeat the one before, the last
/// corner counting as before the first.
fn collapse_repeats(face: &[u32], corners: &mut Vec<u32>) {
    corners.clear();
    for &v in face {
        if corners.last() != Some(&v) {
            corners.push(v);
        }
    }
    while corners.len() > 1 && corners.first() == corners.last() {
        corners.pop();
    }
}

impl FaceDefects {
    /// Adds one note per kind of defect found, naming the first faces.
    fn report(&self, raw: &RawModel, notes: &mut Vec<Note>) {
        let face_name = |f: usize| match raw.face_location(f) {
            Location::Line(n) => format!("face {f} (line {n})"),
            Location::Byte(n) => format!("triangle {f} (byte {n})"),
            Location::File => format!("face {f}"),
        };
        let mut report = |kind: &'static str, list: &[usize], what: &str| {
            if !list.is_empty() {
                notes.push(Note {
                    kind,
                    message: format!(
                        "{} {what}{}",
                        list.len(),
                        examples(list.iter().map(|&f| face_name(f)), list.len())
                    ),
                });
            }
        };
        report(
            "collapsed-corners",
            &self.collapsed,
            "faces repeat a corner in a row; the repeats were removed",
        );
        report(
            "degenerate-faces",
            &self.too_few,
            "faces have fewer than 3 distinct corners and were dropped",
        );
        report(
            "pinched-faces",
            &self.pinched,
            "faces visit a vertex twice (pinched polygons) and were dropped; split them into simple polygons to keep them",
        );
        report(
            "zero-area-faces",
            &self.zero_area,
            "faces have zero area and were dropped (the mesh may have a slit there)",
        );
        if !self.duplicates.is_empty() {
            notes.push(Note {
                kind: "duplicate-faces",
                message: format!(
                    "{} faces repeat an earlier face's corners and were dropped{}",
                    self.duplicates.len(),
                    examples(
                        self.duplicates
                            .iter()
                            .map(|&(f, first)| format!("{} repeats face {first}", face_name(f))),
                        self.duplicates.len()
                    )
                ),
            });
        }
    }
}

/// Drops faces with the same set of corners as an earlier face. Faces are sorted by a
/// hash of their sorted corners and only equal hashes are compared, so no per-face
/// allocation is needed. `duplicates` receives (dropped face, earlier face) in the
/// file's numbering.
fn drop_duplicate_faces(
    polys: Polygons,
    face_source: Vec<u32>,
    duplicates: &mut Vec<(usize, u32)>,
) -> (Polygons, Vec<u32>) {
    let sorted_corners = |f: usize| {
        let mut c = polys.face(f).to_vec();
        c.sort_unstable();
        c
    };
    let mut keyed: Vec<(u64, u32)> = (0..polys.face_count())
        .map(|f| {
            let mut corners: [u32; 8] = [u32::MAX; 8];
            let face = polys.face(f);
            // Hash of the sorted corners; long faces hash their 8 smallest corners.
            let mut buf: Vec<u32>;
            let sorted: &[u32] = if face.len() <= 8 {
                corners[..face.len()].copy_from_slice(face);
                corners[..face.len()].sort_unstable();
                &corners[..face.len()]
            } else {
                buf = face.to_vec();
                buf.sort_unstable();
                &buf
            };
            let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ sorted.len() as u64;
            for &v in sorted {
                h = (h ^ v as u64).wrapping_mul(0x0100_0000_01b3);
            }
            (h, f as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    let mut drop = vec![false; polys.face_count()];
    for run in keyed.chunk_by(|a, b| a.0 == b.0).filter(|r| r.len() > 1) {
        for (k, &(_, f)) in run.iter().enumerate() {
            let corners = sorted_corners(f as usize);
            if let Some(&(_, first)) = run[..k]
                .iter()
                .find(|&&(_, g)| !drop[g as usize] && sorted_corners(g as usize) == corners)
            {
                drop[f as usize] = true;
                duplicates.push((
                    face_source[f as usize] as usize,
                    face_source[first as usize],
                ));
            }
        }
    }
    if duplicates.is_empty() {
        return (polys, face_source);
    }
    duplicates.sort_unstable();
    let mut out = Polygons {
        positions: polys.positions.clone(),
        ..Polygons::new()
    };
    let mut source = Vec::with_capacity(face_source.len());
    for f in 0..polys.face_count() {
        if !drop[f] {
            out.push_face(polys.face(f));
            source.push(face_source[f]);
        }
    }
    (out, source)
}

/// Sum of the triangle areas of a fan from the centroid: zero only when every corner
/// lies on one line, for planar and non-planar polygons alike.
fn fan_area(points: &[glam::DVec3]) -> f64 {
    let centre = points.iter().copied().sum::<glam::DVec3>() / points.len() as f64;
    (0..points.len())
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % points.len()]);
            0.5 * (a - centre).cross(b - centre).length()
        })
        .sum()
}

/// Vertices of `polys` used by no face, in index order.
fn unused_vertices(polys: &Polygons) -> impl Iterator<Item = u32> + '_ {
    let mut used = vec![false; polys.positions.len()];
    for &v in &polys.indices {
        used[v as usize] = true;
    }
    (0..polys.positions.len() as u32).filter(move |&v| !used[v as usize])
}

/// Compacts away vertices used by no face. `previous_source` maps the input soup's
/// vertices to the file (identity when `None`); returns the new soup and its map to the
/// file's vertices.
pub(super) fn drop_unreferenced(
    polys: Polygons,
    previous_source: Option<&[u32]>,
) -> (Polygons, Vec<u32>) {
    let mut new_index = vec![u32::MAX; polys.positions.len()];
    let mut positions = Vec::new();
    let mut source = Vec::new();
    for &v in &polys.indices {
        if new_index[v as usize] == u32::MAX {
            new_index[v as usize] = 0; // mark used; numbered below in index order
        }
    }
    for (v, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = positions.len() as u32;
            positions.push(polys.positions[v]);
            source.push(previous_source.map_or(v as u32, |s| s[v]));
        }
    }
    let indices = polys
        .indices
        .iter()
        .map(|&v| new_index[v as usize])
        .collect();
    (
        Polygons {
            positions,
            offsets: polys.offsets,
            indices,
        },
        source,
    )
}

/// Rejects edges shared by three or more faces, naming the first one.
fn check_edge_manifold(
    polys: &Polygons,
    edges: &CornerEdges,
    at: &Located,
) -> Result<(), InputError> {
    let mut worst: Option<&[(u64, u32)]> = None;
    let mut count = 0usize;
    for group in edges.groups() {
        if group.len() > 2 {
            count += 1;
            // Report the one that appears first in the file.
            if worst.is_none_or(|w| group[0].1 < w[0].1) {
                worst = Some(group);
            }
        }
    }
    let Some(group) = worst else {
        return Ok(());
    };
    let (a, b) = corner_edge(polys, &edges.corner_face, group[0].1);
    let faces: Vec<String> = group
        .iter()
        .map(|&(_, c)| at.face(edges.corner_face[c as usize]))
        .collect();
    let others = if count > 1 {
        format!("; {} more edges like it", count - 1)
    } else {
        String::new()
    };
    Err(at.error(
        edges.corner_face[group[0].1 as usize],
        format!(
            "non-manifold edge between vertices {} and {}: it is shared by {} faces ({}){others}",
            at.vertex(a),
            at.vertex(b),
            group.len(),
            faces.join(", ")
        ),
        "a buildable surface joins at most two faces at an edge; remove the extra faces or separate the parts",
    ))
}

/// Orients every component consistently (flipping the minority of its faces), then
/// turns closed components outward (positive enclosed volume). Rejects non-orientable
/// components.
fn orient(
    polys: &mut Polygons,
    edges: &CornerEdges,
    at: &Located,
    notes: &mut Vec<Note>,
) -> Result<(), InputError> {
    let neighbours = FaceNeighbours::new(polys, edges);
    let mut walk = ComponentWalk::new(polys.face_count());
    let mut flipped_faces = Vec::new();
    let mut inside_out = Vec::new();
    for seed in 0..polys.face_count() {
        if walk.component[seed] != u32::MAX {
            continue;
        }
        let closed = walk.spread(seed, polys, &neighbours, at)?;
        // Flip the minority so the fewest faces change.
        let flipped = walk.members.iter().filter(|&&f| walk.flip[f]).count();
        if 2 * flipped > walk.members.len() {
            for &f in &walk.members {
                walk.flip[f] = !walk.flip[f];
            }
        }
        let flipped: Vec<usize> = walk
            .members
            .iter()
            .copied()
            .filter(|&f| walk.flip[f])
            .collect();
        for &f in &flipped {
            polys.flip_face(f);
        }
        flipped_faces.extend(flipped);
        if closed && signed_volume(polys, &walk.members) < 0.0 {
            for &f in &walk.members {
                polys.flip_face(f);
            }
            inside_out.push(seed as u32);
        }
    }
    note_orientation(at, flipped_faces, &inside_out, notes);
    Ok(())
}

/// The neighbours of every face across its shared edges, and whether each runs through
/// the edge the same way (then exactly one of the two must be flipped), in compressed
/// rows: face f's neighbours are `pairs[row[f]..row[f + 1]]`.
struct FaceNeighbours {
    /// (face, neighbour, same direction), sorted by face.
    pairs: Vec<(u32, u32, bool)>,
    /// Where each face's run of `pairs` starts, plus a final end.
    row: Vec<usize>,
}

impl FaceNeighbours {
    /// The neighbours across every edge shared by two faces.
    fn new(polys: &Polygons, edges: &CornerEdges) -> Self {
        let face_count = polys.face_count();
        let mut pairs: Vec<(u32, u32, bool)> = Vec::with_capacity(polys.indices.len());
        for group in edges.groups() {
            if let [(_, c1), (_, c2)] = *group {
                let (f1, f2) = (
                    edges.corner_face[c1 as usize],
                    edges.corner_face[c2 as usize],
                );
                let same = corner_edge(polys, &edges.corner_face, c1)
                    == corner_edge(polys, &edges.corner_face, c2);
                pairs.push((f1, f2, same));
                pairs.push((f2, f1, same));
            }
        }
        pairs.sort_unstable();
        let mut row = vec![0usize; face_count + 1];
        for &(f, _, _) in &pairs {
            row[f as usize + 1] += 1;
        }
        for f in 0..face_count {
            row[f + 1] += row[f];
        }
        FaceNeighbours { pairs, row }
    }

    /// The neighbours of face `f`, each with whether it runs the same way through the
    /// shared edge.
    fn of(&self, f: usize) -> impl Iterator<Item = (u32, bool)> + '_ {
        self.pairs[self.row[f]..self.row[f + 1]]
            .iter()
            .map(|&(_, g, same)| (g, same))
    }

    /// How many neighbours face `f` has.
    fn count(&self, f: usize) -> usize {
        self.row[f + 1] - self.row[f]
    }
}

/// A breadth-first walk over the faces, one component at a time, deciding which faces
/// to flip.
struct ComponentWalk {
    /// Whether each face is to be flipped.
    flip: Vec<bool>,
    /// The component of each face (its seed), `u32::MAX` before it is reached.
    component: Vec<u32>,
    /// Faces reached but not yet visited.
    queue: VecDeque<usize>,
    /// The faces of the current component, in visiting order.
    members: Vec<usize>,
}

impl ComponentWalk {
    /// A walk over `face_count` faces, none reached yet.
    fn new(face_count: usize) -> Self {
        ComponentWalk {
            flip: vec![false; face_count],
            component: vec![u32::MAX; face_count],
            queue: VecDeque::new(),
            members: Vec::new(),
        }
    }

    /// Visits the component of `seed`, setting `flip` so that its faces agree with the
    /// seed and filling `members`; returns whether the component is closed. Rejects a
    /// non-orientable component.
    fn spread(
        &mut self,
        seed: usize,
        polys: &Polygons,
        neighbours: &FaceNeighbours,
        at: &Located,
    ) -> Result<bool, InputError> {
        let id = seed as u32;
        self.component[seed] = id;
        self.members.clear();
        self.queue.push_back(seed);
        let mut closed = true;
        while let Some(f) = self.queue.pop_front() {
            self.members.push(f);
            if neighbours.count(f) < polys.face(f).len() {
                closed = false;
            }
            for (g, same) in neighbours.of(f) {
                let want = self.flip[f] ^ same;
                let g = g as usize;
                if self.component[g] == u32::MAX {
                    self.component[g] = id;
                    self.flip[g] = want;
                    self.queue.push_back(g);
                } else if self.flip[g] != want {
                    return Err(at.error(
                        seed as u32,
                        format!(
                            "the part of the model containing {} is non-orientable (like a Möbius strip): its faces cannot all face one way",
                            at.face(seed as u32)
                        ),
                        "a panel model needs an inside and an outside; rebuild that part as an orientable surface",
                    ));
                }
            }
        }
        Ok(closed)
    }
}

/// Notes the faces flipped to agree with their neighbours and the closed parts turned
/// outward (each named by its first face).
fn note_orientation(
    at: &Located,
    mut flipped_faces: Vec<usize>,
    inside_out: &[u32],
    notes: &mut Vec<Note>,
) {
    if !flipped_faces.is_empty() {
        flipped_faces.sort_unstable();
        notes.push(Note {
            kind: "flipped-faces",
            message: format!(
                "{} faces were oriented against their neighbours and were flipped{}",
                flipped_faces.len(),
                examples(
                    flipped_faces.iter().map(|&f| at.face(f as u32)),
                    flipped_faces.len()
                )
            ),
        });
    }
    if !inside_out.is_empty() {
        notes.push(Note {
            kind: "inside-out",
            message: format!(
                "{} closed parts had their faces pointing inward and were turned outward{}",
                inside_out.len(),
                examples(
                    inside_out
                        .iter()
                        .map(|&f| format!("the part containing {}", at.face(f))),
                    inside_out.len()
                )
            ),
        });
    }
}

/// Six times the volume enclosed by the faces (divergence theorem over fan triangles).
fn signed_volume(polys: &Polygons, faces: &[usize]) -> f64 {
    let mut volume = 0.0;
    for &f in faces {
        let face = polys.face(f);
        let p0 = polys.positions[face[0] as usize];
        for k in 1..face.len() - 1 {
            let p1 = polys.positions[face[k] as usize];
            let p2 = polys.positions[face[k + 1] as usize];
            volume += p0.dot(p1.cross(p2));
        }
    }
    volume
}
