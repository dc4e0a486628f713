//! Building the half-edge mesh from polygons in O(n log n): one sort of the face corners
//! by undirected edge pairs the half-edges, a union-find over corners finds vertex fans.

use glam::DVec3;

use super::halfedge::{Mesh, NO_FACE};
use super::ids::{HalfedgeId, VertexId};
use super::polygons::Polygons;
use super::soup::{corner_edge, corner_fans, CornerEdges};

/// Why a polygon soup cannot become a half-edge mesh. Indices are the soup's own
/// (0-based); the prepare stage translates them into the user's file numbering.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BuildError {
    /// A face with fewer than three corners.
    #[error("face {face} has {corners} corners; a face needs at least 3")]
    TooFewCorners { face: u32, corners: u32 },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange { face: u32, vertex: u32, count: u32 },
    /// A face visits the same vertex twice.
    #[error("face {face} uses vertex {vertex} more than once")]
    RepeatedVertex { face: u32, vertex: u32 },
    /// An edge shared by more than two faces.
    #[error("edge {a}-{b} is shared by {} faces", faces.len())]
    NonManifoldEdge { a: u32, b: u32, faces: Vec<u32> },
    /// Two faces run through their shared edge in the same direction.
    #[error("faces {} and {} run through edge {a}-{b} in the same direction", faces[0], faces[1])]
    InconsistentOrientation { a: u32, b: u32, faces: [u32; 2] },
    /// A vertex no face uses (the prepare stage drops these before building).
    #[error("vertex {vertex} is used by no face")]
    IsolatedVertex { vertex: u32 },
    /// More elements than `u32` handles can address.
    #[error("the mesh has more than 2^31 edges or corners")]
    TooLarge,
}

/// Repairs the builder made: bow-tie vertices split into one vertex per fan.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// For every split vertex: its soup index and the number of fans it had.
    pub split_vertices: Vec<(u32, u32)>,
}

/// Checks that every face has ≥ 3 distinct, in-range corners.
pub(crate) fn check_faces(polys: &Polygons) -> Result<(), BuildError> {
    let count = polys.positions.len() as u32;
    let mut seen: Vec<u32> = Vec::new();
    for (f, face) in polys.faces().enumerate() {
        let face_id = f as u32;
        if face.len() < 3 {
            return Err(BuildError::TooFewCorners {
                face: face_id,
                corners: face.len() as u32,
            });
        }
        if let Some(&vertex) = face.iter().find(|&&v| v >= count) {
            return Err(BuildError::IndexOutOfRange {
                face: face_id,
                vertex,
                count,
            });
        }
        seen.clear();
        seen.extend_from_slice(face);
        seen.sort_unstable();
        if let Some(w) = seen.windows(2).find(|w| w[0] == w[1]) {
            return Err(BuildError::RepeatedVertex {
                face: face_id,
                vertex: w[0],
            });
        }
    }
    Ok(())
}

/// Builds the half-edge mesh of a consistently oriented, edge-manifold polygon soup.
///
/// Every vertex must be used by a face (the prepare stage drops the others). Bow-tie vertices (several fans meeting
/// at one point) are split into one vertex per fan and listed in the report.
///
/// `vertex_source` and `face_source` map soup indices to the user's input indices; pass
/// `None` for the identity.
pub fn build_mesh(
    polys: &Polygons,
    vertex_source: Option<&[u32]>,
    face_source: Option<&[u32]>,
) -> Result<(Mesh, BuildReport), BuildError> {
    if polys.indices.len() >= (1usize << 31) {
        return Err(BuildError::TooLarge);
    }
    check_faces(polys)?;
    let corners = CornerEdges::new(polys);
    let (group_of_corner, group_count) = pair_corners(polys, &corners)?;
    let fans = corner_fans(polys, &corners);
    drop(corners);
    let (corner_half_edge, edge_count) = number_half_edges(&group_of_corner, group_count);
    drop(group_of_corner);

    let (mut tables, face_half_edge) = link_faces(polys, &corner_half_edge, edge_count);
    let vertices = split_fans(
        polys,
        vertex_source,
        &fans,
        &corner_half_edge,
        &mut tables.origin,
    );
    drop(fans);
    drop(corner_half_edge);

    let boundary_out = link_boundary(&mut tables, vertices.positions.len());
    let vertex_half_edge = vertex_half_edges(&tables.origin, &boundary_out)?;
    let report = split_report(&vertices.extra_fans, &vertices.source);
    let face_source_out = match face_source {
        Some(s) => s.to_vec(),
        None => (0..polys.face_count() as u32).collect(),
    };
    let mesh = Mesh {
        positions: vertices.positions,
        vertex_half_edge,
        half_edge_next: tables.next,
        half_edge_prev: tables.prev,
        half_edge_origin: tables.origin,
        half_edge_face: tables.face,
        face_half_edge,
        vertex_source: vertices.source,
        face_source: face_source_out,
    };
    Ok((mesh, report))
}

/// A half-edge slot not filled in yet.
const UNSET: HalfedgeId = HalfedgeId(u32::MAX);

/// Groups the corners by the undirected edge they start (one group per edge, in the
/// order of the edge keys) and returns each corner's group and the number of groups.
/// Rejects edges of three or more faces and edges two faces run through in the same
/// direction.
fn pair_corners(polys: &Polygons, corners: &CornerEdges) -> Result<(Vec<u32>, u32), BuildError> {
    let mut group_of_corner = vec![0u32; polys.indices.len()];
    let mut group_count = 0u32;
    for group in corners.groups() {
        if group.len() > 2 {
            let (a, b) = corner_edge(polys, &corners.corner_face, group[0].1);
            let faces = group
                .iter()
                .map(|&(_, c)| corners.corner_face[c as usize])
                .collect();
            return Err(BuildError::NonManifoldEdge {
                a: a.min(b),
                b: a.max(b),
                faces,
            });
        }
        if let [(_, c1), (_, c2)] = *group {
            let e1 = corner_edge(polys, &corners.corner_face, c1);
            let e2 = corner_edge(polys, &corners.corner_face, c2);
            if e1 == e2 {
                return Err(BuildError::InconsistentOrientation {
                    a: e1.0,
                    b: e1.1,
                    faces: [
                        corners.corner_face[c1 as usize],
                        corners.corner_face[c2 as usize],
                    ],
                });
            }
        }
        for &(_, c) in group {
            group_of_corner[c as usize] = group_count;
        }
        group_count += 1;
    }
    Ok((group_of_corner, group_count))
}

/// The half-edge of every corner and the number of edges. Edges are numbered in the
/// order their first corner appears in the file, so edge ids follow the user's face
/// order; that first corner gets the even half-edge of the pair.
fn number_half_edges(group_of_corner: &[u32], group_count: u32) -> (Vec<HalfedgeId>, u32) {
    let mut edge_of_group = vec![u32::MAX; group_count as usize];
    let mut corner_half_edge = vec![HalfedgeId(0); group_of_corner.len()];
    let mut edge_count = 0u32;
    for (c, &g) in group_of_corner.iter().enumerate() {
        let slot = &mut edge_of_group[g as usize];
        corner_half_edge[c] = if *slot == u32::MAX {
            *slot = edge_count;
            edge_count += 1;
            HalfedgeId(2 * *slot)
        } else {
            HalfedgeId(2 * *slot + 1)
        };
    }
    (corner_half_edge, edge_count)
}

/// The per-half-edge tables of the mesh being built.
struct HalfedgeTables {
    /// The next half-edge around the face (or boundary loop).
    next: Vec<HalfedgeId>,
    /// The previous half-edge around the face (or boundary loop).
    prev: Vec<HalfedgeId>,
    /// The face on the left, or [`NO_FACE`] on the boundary.
    face: Vec<u32>,
    /// The vertex each half-edge starts at.
    origin: Vec<VertexId>,
}

/// Links the half-edges of every face into its loop; returns the tables (boundary
/// half-edges and origins still unset) and the first half-edge of every face.
fn link_faces(
    polys: &Polygons,
    corner_half_edge: &[HalfedgeId],
    edge_count: u32,
) -> (HalfedgeTables, Vec<HalfedgeId>) {
    let half_edge_count = 2 * edge_count as usize;
    let mut tables = HalfedgeTables {
        next: vec![UNSET; half_edge_count],
        prev: vec![UNSET; half_edge_count],
        face: vec![NO_FACE; half_edge_count],
        origin: vec![VertexId(u32::MAX); half_edge_count],
    };
    let mut face_half_edge = Vec::with_capacity(polys.face_count());
    for f in 0..polys.face_count() {
        let (start, end) = (polys.offsets[f] as usize, polys.offsets[f + 1] as usize);
        face_half_edge.push(corner_half_edge[start]);
        for c in start..end {
            let h = corner_half_edge[c].index();
            let n = if c + 1 == end { start } else { c + 1 };
            let hn = corner_half_edge[n];
            tables.next[h] = hn;
            tables.prev[hn.index()] = HalfedgeId(h as u32);
            tables.face[h] = f as u32;
        }
    }
    (tables, face_half_edge)
}

/// The vertices of the mesh: one per fan of faces around a soup vertex.
struct FanVertices {
    /// Positions: the soup's, then one copy for every extra fan.
    positions: Vec<DVec3>,
    /// The user's vertex index of every vertex.
    source: Vec<u32>,
    /// The soup vertex of every extra fan (one entry per vertex appended).
    extra_fans: Vec<u32>,
}

/// Makes one vertex per fan and sets the origin of every face half-edge. The first fan
/// of a soup vertex keeps its index; later fans get new vertices appended, in half-edge
/// order so that the result is deterministic.
fn split_fans(
    polys: &Polygons,
    vertex_source: Option<&[u32]>,
    fans: &[u32],
    corner_half_edge: &[HalfedgeId],
    origin: &mut [VertexId],
) -> FanVertices {
    let soup_vertex_count = polys.positions.len();
    let mut positions = polys.positions.clone();
    let mut source: Vec<u32> = match vertex_source {
        Some(s) => s.to_vec(),
        None => (0..soup_vertex_count as u32).collect(),
    };
    let mut first_root = vec![u32::MAX; soup_vertex_count];
    let mut vertex_of_root = vec![u32::MAX; polys.indices.len()];
    let mut extra_fans: Vec<u32> = Vec::new();
    for (c, &root) in fans.iter().enumerate() {
        let root = root as usize;
        if vertex_of_root[root] == u32::MAX {
            let sv = polys.indices[c] as usize;
            if first_root[sv] == u32::MAX {
                first_root[sv] = root as u32;
                vertex_of_root[root] = sv as u32;
            } else {
                vertex_of_root[root] = positions.len() as u32;
                positions.push(positions[sv]);
                source.push(source[sv]);
                extra_fans.push(sv as u32);
            }
        }
        origin[corner_half_edge[c].index()] = VertexId(vertex_of_root[root]);
    }
    FanVertices {
        positions,
        source,
        extra_fans,
    }
}

/// Sets the origins of the boundary half-edges and links them into boundary loops;
/// returns every vertex's outgoing boundary half-edge ([`UNSET`] for interior ones).
///
/// The twin of face half-edge u→w runs w→u, so its origin is the origin of next(h). Each
/// (post-split) vertex has at most one outgoing boundary half-edge, so boundary loops
/// link without ambiguity.
fn link_boundary(tables: &mut HalfedgeTables, vertex_count: usize) -> Vec<HalfedgeId> {
    let half_edge_count = tables.face.len();
    let mut boundary_out = vec![UNSET; vertex_count];
    for h in 0..half_edge_count {
        if tables.face[h] == NO_FACE {
            let interior = HalfedgeId(h as u32).twin();
            let o = tables.origin[tables.next[interior.index()].index()];
            tables.origin[h] = o;
            boundary_out[o.index()] = HalfedgeId(h as u32);
        }
    }
    for h in 0..half_edge_count {
        if tables.face[h] == NO_FACE {
            let head = tables.origin[HalfedgeId(h as u32).twin().index()];
            let n = boundary_out[head.index()];
            tables.next[h] = n;
            tables.prev[n.index()] = HalfedgeId(h as u32);
        }
    }
    boundary_out
}

/// The stored half-edge of every vertex: its boundary half-edge on the boundary, else
/// its lowest outgoing one. Rejects a vertex with no half-edge.
fn vertex_half_edges(
    origin: &[VertexId],
    boundary_out: &[HalfedgeId],
) -> Result<Vec<HalfedgeId>, BuildError> {
    let mut vertex_half_edge = vec![UNSET; boundary_out.len()];
    for h in (0..origin.len()).rev() {
        // Reverse order so the lowest outgoing half-edge wins for interior vertices.
        vertex_half_edge[origin[h].index()] = HalfedgeId(h as u32);
    }
    for (v, &b) in boundary_out.iter().enumerate() {
        if b != UNSET {
            vertex_half_edge[v] = b;
        }
    }
    if let Some(v) = vertex_half_edge.iter().position(|&h| h == UNSET) {
        return Err(BuildError::IsolatedVertex { vertex: v as u32 });
    }
    Ok(vertex_half_edge)
}

/// The report of split bow-tie vertices: each split soup vertex (in the user's
/// numbering, from `vertex_source`) with its number of fans.
fn split_report(extra_fans: &[u32], vertex_source: &[u32]) -> BuildReport {
    let mut report = BuildReport::default();
    if !extra_fans.is_empty() {
        let mut counts = std::collections::BTreeMap::new();
        for &sv in extra_fans {
            *counts.entry(sv).or_insert(1u32) += 1;
        }
        report.split_vertices = counts
            .into_iter()
            .map(|(sv, n)| (vertex_source[sv as usize], n))
            .collect();
    }
    report
}

/// A convenience for tests and examples: builds from positions and face lists.
pub fn build_from_faces<F: AsRef<[u32]>>(
    positions: Vec<DVec3>,
    faces: &[F],
) -> Result<Mesh, BuildError> {
    let polys = Polygons::from_faces(positions, faces);
    build_mesh(&polys, None, None).map(|(mesh, _)| mesh)
}

/// A closed regular tetrahedron, for the mesh modules' unit tests.
#[cfg(test)]
pub(crate) fn tetrahedron() -> Mesh {
    let p = vec![
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    build_from_faces(p, &[[0u32, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]).unwrap()
}

/// The corners of a cube of `side` with a corner at the origin (corner i at
/// (i & 1, i >> 1 & 1, i >> 2 & 1) · `side`) and its faces, bottom, top, front, back,
/// left, right, counter-clockwise seen from outside, for the unit tests.
#[cfg(test)]
pub(crate) fn cube_faces(side: f64) -> (Vec<DVec3>, [[u32; 4]; 6]) {
    let corners = (0..8)
        .map(|i| side * DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
        .collect();
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [3, 2, 6, 7],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    (corners, faces)
}

/// A closed cube of `side` with a corner at the origin (see [`cube_faces`]), for the
/// unit tests.
#[cfg(test)]
pub(crate) fn cube(side: f64) -> Mesh {
    let (corners, faces) = cube_faces(side);
    build_from_faces(corners, &faces).expect("cube builds")
}

/// Two triangles hinged on the edge (0,0,0)–(60,0,0) mm, for the schemes' unit tests:
/// face 0 is (0,0,0), (30,−30,0), (60,0,0) in z = 0 (normal +z), face 1 is (0,0,0),
/// (60,0,0), `apex`. The hinge is edge 2 (half-edge 4 runs (60,0,0) → (0,0,0) in face
/// 0, half-edge 5 the other way in face 1); edges 0, 1, 3 and 4 are boundary edges.
#[cfg(test)]
pub(crate) fn two_triangles(apex: DVec3) -> Mesh {
    let p = vec![
        DVec3::ZERO,
        DVec3::new(60.0, 0.0, 0.0),
        DVec3::new(30.0, -30.0, 0.0),
        apex,
    ];
    build_from_faces(p, &[[0u32, 2, 1], [0, 1, 3]]).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::EdgeId;

    /// `count` points on the parabola y = x² in z = 0 (no three in a line).
    fn points(count: usize) -> Vec<DVec3> {
        (0..count)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
            .collect()
    }

    /// The error `build_mesh` gives for these faces over `count` points.
    fn error_of(count: usize, faces: &[&[u32]]) -> BuildError {
        build_from_faces(points(count), faces).unwrap_err()
    }

    #[test]
    fn a_face_of_two_corners_is_refused() {
        assert_eq!(
            error_of(4, &[&[0, 1, 2], &[2, 3]]),
            BuildError::TooFewCorners {
                face: 1,
                corners: 2
            }
        );
    }

    #[test]
    fn a_corner_past_the_last_vertex_is_refused() {
        assert_eq!(
            error_of(4, &[&[0, 1, 9]]),
            BuildError::IndexOutOfRange {
                face: 0,
                vertex: 9,
                count: 4
            }
        );
    }

    #[test]
    fn a_face_visiting_a_vertex_twice_is_refused() {
        // Corners 1 and 3 of face 1 are both vertex 2.
        assert_eq!(
            error_of(5, &[&[0, 1, 2], &[1, 2, 3, 2, 4]]),
            BuildError::RepeatedVertex { face: 1, vertex: 2 }
        );
    }

    #[test]
    fn an_edge_of_three_faces_is_refused_naming_all_three() {
        // Edge 0–1 in faces 0, 1 and 2 (whatever their directions).
        assert_eq!(
            error_of(5, &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]),
            BuildError::NonManifoldEdge {
                a: 0,
                b: 1,
                faces: vec![0, 1, 2]
            }
        );
    }

    #[test]
    fn two_faces_running_an_edge_the_same_way_are_refused() {
        // Both faces run 0 → 1.
        assert_eq!(
            error_of(4, &[&[0, 1, 2], &[0, 1, 3]]),
            BuildError::InconsistentOrientation {
                a: 0,
                b: 1,
                faces: [0, 1]
            }
        );
    }

    #[test]
    fn a_vertex_no_face_uses_is_refused() {
        assert_eq!(
            error_of(4, &[&[0, 1, 2]]),
            BuildError::IsolatedVertex { vertex: 3 }
        );
    }

    #[test]
    fn a_face_of_collinear_corners_still_builds() {
        // The builder judges topology only: a zero-area face is the validator's business.
        let p = vec![DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        let mesh = build_from_faces(p, &[[0u32, 1, 2]]).unwrap();
        assert_eq!((mesh.face_count(), mesh.edge_count()), (1, 3));
        assert_eq!(mesh.face_area(crate::mesh::FaceId(0)), 0.0);
    }

    #[test]
    fn a_bow_tie_vertex_is_split_and_reported_in_the_users_numbering() {
        // Two triangles meeting only at vertex 0: two fans there.
        let polys = Polygons::from_faces(points(5), &[[0u32, 1, 2], [0, 3, 4]]);
        let source = [10, 11, 12, 13, 14];
        let (mesh, report) = build_mesh(&polys, Some(&source), Some(&[7, 8])).unwrap();
        assert_eq!(report.split_vertices, vec![(10, 2)]);
        // The second fan gets vertex 5, at vertex 0's place and from its source.
        assert_eq!(mesh.vertex_count(), 6);
        assert_eq!(mesh.positions()[5], mesh.positions()[0]);
        assert_eq!(mesh.vertex_source(VertexId(5)), 10);
        assert_eq!(
            mesh.face_vertices(crate::mesh::FaceId(1))
                .map(|v| v.0)
                .collect::<Vec<_>>(),
            vec![5, 3, 4]
        );
        assert_eq!(mesh.face_source(crate::mesh::FaceId(1)), 8);
    }

    #[test]
    fn a_manifold_soup_reports_no_repair() {
        let polys = Polygons::from_faces(points(4), &[[0u32, 1, 2], [0, 2, 3]]);
        let (mesh, report) = build_mesh(&polys, None, None).unwrap();
        assert_eq!(report, BuildReport::default());
        // 5 edges: 4 on the boundary and the diagonal 0–2; V − E + F = 4 − 5 + 2 = 1.
        assert_eq!((mesh.vertex_count(), mesh.edge_count()), (4, 5));
    }

    #[test]
    fn edges_are_numbered_in_face_order_with_the_first_face_on_the_even_half_edge() {
        let mesh = two_triangles(DVec3::new(30.0, 30.0, 0.0));
        // Corners in file order: 0→2, 2→1, 1→0 (face 0), 0→1, 1→3, 3→0 (face 1).
        let ends: Vec<(u32, u32)> = mesh
            .edges()
            .map(|e| {
                let h = e.half_edge();
                (mesh.origin(h).0, mesh.dest(h).0)
            })
            .collect();
        assert_eq!(ends, vec![(0, 2), (2, 1), (1, 0), (1, 3), (3, 0)]);
        // Only edge 2 has a face on both sides; the twin of every other is a boundary.
        let interior: Vec<u32> = mesh
            .edges()
            .filter(|&e| !mesh.is_boundary_edge(e))
            .map(|e| e.0)
            .collect();
        assert_eq!(interior, vec![2]);
        assert!(mesh.is_boundary_half_edge(EdgeId(0).half_edge().twin()));
        // The boundary loop runs round both faces: 4 half-edges, each the twin of a
        // boundary edge's face half-edge.
        assert_eq!(mesh.boundary_loops().len(), 1);
        assert_eq!(mesh.loop_from(mesh.boundary_loops()[0]).count(), 4);
    }

    #[test]
    fn the_tetrahedron_fixture_is_closed() {
        let mesh = tetrahedron();
        // V − E + F = 4 − 6 + 4 = 2, no boundary.
        assert_eq!(
            (mesh.vertex_count(), mesh.edge_count(), mesh.face_count()),
            (4, 6, 4)
        );
        assert!(mesh.edges().all(|e| !mesh.is_boundary_edge(e)));
    }
}
