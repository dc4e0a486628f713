//! Closing the holes of a mesh (`--fill-holes`): each boundary loop becomes one face
//! whose corners are the loop's vertices, wound the way the loop runs, so the mesh
//! stays oriented and every edge gets its second face. A scan's holes (the bunny's
//! base) and a patch model's open rims (the teapot's spout) keep short edges at any
//! simplification budget, and the woven scheme needs a closed mesh; a cap removes
//! both. Caps are ordinary faces afterwards: a warped or concave one is split into
//! triangles like any other, and simplification may collapse across it.

use super::build::{build_mesh, BuildError};
use super::{Mesh, Polygons};
use crate::union_find::UnionFind;
use glam::DVec3;

/// What [`fill_holes`] closed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FilledHoles {
    /// Holes closed (boundary loops).
    pub holes: usize,
    /// Edges of the largest of them.
    pub largest: usize,
    /// Holes whose rim runs back along itself or passes through one point twice (an
    /// open seam): joined where the rim meets itself, capped only where it does not.
    pub joined: usize,
}

/// The mesh with every boundary loop closed (no face source: a cap is not in the
/// file), or `None` when the mesh is closed already. A loop closes with one face. A
/// rim that meets itself (an open seam: out along a line and back, or through one
/// point twice) is first joined there, its two vertices at each such point made one,
/// and capped only where it encloses area: a single face would need triangles of no
/// area, which no panel can be built on. Vertices keep their sources (a joined pair
/// the first's); faces keep theirs, the caps follow them.
pub fn fill_holes(mesh: &Mesh) -> Result<Option<(Mesh, FilledHoles)>, BuildError> {
    let loops = mesh.boundary_loops();
    if loops.is_empty() {
        return Ok(None);
    }
    let mut filled = FilledHoles::default();
    let mut caps = Vec::new();
    let mut joined_to = UnionFind::new(mesh.vertex_count());
    for &start in &loops {
        // A boundary half-edge runs the way the missing face would wind.
        let corners: Vec<u32> = mesh.loop_from(start).map(|h| mesh.origin(h).0).collect();
        filled.holes += 1;
        filled.largest = filled.largest.max(corners.len());
        let before = caps.len();
        let mut joined = false;
        close_loop(
            corners,
            mesh.positions(),
            &mut joined_to,
            &mut joined,
            &mut caps,
        );
        filled.joined += usize::from(joined);
        debug_assert!(joined || caps.len() == before + 1);
    }
    if filled.joined > 0 {
        if let Ok(closed) = closed_with(mesh, &caps, &joined_to) {
            return Ok(Some((closed, filled)));
        }
        // A join that would make a vertex or an edge non-manifold: one face per loop.
        filled.joined = 0;
        caps = loops
            .iter()
            .map(|&start| mesh.loop_from(start).map(|h| mesh.origin(h).0).collect())
            .collect();
        joined_to = UnionFind::new(mesh.vertex_count());
    }
    Ok(Some((closed_with(mesh, &caps, &joined_to)?, filled)))
}

/// Closes the loop `corners`, pushing its caps. Where the rim runs out to a corner and
/// back along the same line, the two vertices at either side are joined and the two
/// rim edges become one edge (no cap); where it passes through one point twice, the
/// two vertices there are joined and each side is closed on its own. `joined` is set
/// when either happened.
fn close_loop(
    corners: Vec<u32>,
    positions: &[DVec3],
    joined_to: &mut UnionFind,
    joined: &mut bool,
    caps: &mut Vec<Vec<u32>>,
) {
    let n = corners.len();
    if n < 3 {
        // Two rim edges left, between the same two vertices: they are one edge now.
        return;
    }
    let at = |i: usize| positions[corners[i % n] as usize];
    let mut join = |later: u32, earlier: u32, joined_to: &mut UnionFind| {
        joined_to.join_onto(later, earlier);
        *joined = true;
    };
    if n > 3 {
        if let Some(i) = (0..n).find(|&i| at(i) == at(i + 2)) {
            join(corners[(i + 2) % n], corners[i], joined_to);
            let rest: Vec<u32> = (0..n)
                .filter(|&k| k != (i + 1) % n && k != (i + 2) % n)
                .map(|k| corners[k])
                .collect();
            return close_loop(rest, positions, joined_to, joined, caps);
        }
    }
    let pinch = (0..n)
        .flat_map(|i| (i + 3..n).map(move |j| (i, j)))
        .find(|&(i, j)| n - (j - i) >= 3 && at(i) == at(j));
    let Some((i, j)) = pinch else {
        caps.push(corners);
        return;
    };
    join(corners[j], corners[i], joined_to);
    let first = corners[i..j].to_vec();
    let second: Vec<u32> = std::iter::once(corners[i])
        .chain(corners[j + 1..].iter().copied())
        .chain(corners[..i].iter().copied())
        .collect();
    close_loop(first, positions, joined_to, joined, caps);
    close_loop(second, positions, joined_to, joined, caps);
}

/// `mesh`'s faces and the `caps`, each vertex replaced by the one it was joined to
/// and vertices no face uses left out.
fn closed_with(mesh: &Mesh, caps: &[Vec<u32>], joined_to: &UnionFind) -> Result<Mesh, BuildError> {
    let mut polys = Polygons::new();
    polys.positions = mesh.positions().to_vec();
    let faces = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.0).collect::<Vec<u32>>())
        .chain(caps.iter().cloned());
    for corners in faces {
        let joined: Vec<u32> = corners.into_iter().map(|v| joined_to.root(v)).collect();
        polys.push_face(&joined);
    }
    let sources: Vec<u32> = mesh.vertices().map(|v| mesh.vertex_source(v)).collect();
    let (polys, vertex_source) = super::prepare::drop_unreferenced(polys, Some(&sources));
    let face_source: Vec<u32> = mesh
        .faces()
        .map(|f| mesh.face_source(f))
        .chain(caps.iter().map(|_| u32::MAX))
        .collect();
    let (closed, _) = build_mesh(&polys, Some(&vertex_source), Some(&face_source))?;
    Ok(closed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::two_triangles;
    use glam::DVec3;

    #[test]
    fn an_open_square_closes_into_a_pillow_of_the_same_vertices() {
        let open = two_triangles(DVec3::new(30.0, 30.0, 10.0));
        assert_eq!(open.topology().boundary_loops, 1);
        let (closed, filled) = fill_holes(&open).unwrap().expect("it has a hole");
        assert_eq!(
            filled,
            FilledHoles {
                holes: 1,
                largest: 4,
                joined: 0
            }
        );
        let topology = closed.topology();
        assert_eq!(topology.boundary_loops, 0);
        assert_eq!(topology.genus, 0);
        assert_eq!(
            (
                closed.vertex_count(),
                closed.edge_count(),
                closed.face_count()
            ),
            (4, 5, 3)
        );
        assert_eq!(closed.validate(), Ok(()));
        // The cap is not in the file; the two triangles keep their sources.
        let sources: Vec<u32> = closed.faces().map(|f| closed.face_source(f)).collect();
        assert_eq!(sources, vec![0, 1, u32::MAX]);
    }

    #[test]
    fn a_closed_mesh_is_left_alone() {
        let open = two_triangles(DVec3::new(30.0, 30.0, 10.0));
        let (closed, _) = fill_holes(&open).unwrap().unwrap();
        assert!(fill_holes(&closed).unwrap().is_none());
    }

    /// An octahedron cut open along the seam top–E0–bottom: E0 has a copy at its
    /// position on one side of the seam.
    fn slit_octahedron() -> Mesh {
        let positions = vec![
            DVec3::new(0.0, 0.0, 10.0),  // 0 top
            DVec3::new(0.0, 0.0, -10.0), // 1 bottom
            DVec3::new(10.0, 0.0, 0.0),  // 2 E0
            DVec3::new(0.0, 10.0, 0.0),  // 3 E1
            DVec3::new(-10.0, 0.0, 0.0), // 4 E2
            DVec3::new(0.0, -10.0, 0.0), // 5 E3
            DVec3::new(10.0, 0.0, 0.0),  // 6 E0's copy
        ];
        let faces = [
            [0u32, 2, 3],
            [0, 3, 4],
            [0, 4, 5],
            [0, 5, 6],
            [1, 3, 2],
            [1, 4, 3],
            [1, 5, 4],
            [1, 6, 5],
        ];
        crate::mesh::build_from_faces(positions, &faces).unwrap()
    }

    #[test]
    fn an_open_seam_is_joined_shut_without_a_cap() {
        let open = slit_octahedron();
        assert_eq!(open.topology().boundary_loops, 1);
        let (closed, filled) = fill_holes(&open).unwrap().unwrap();
        assert_eq!(filled.joined, 1);
        // The octahedron again: no cap of no area, E0's copy joined to it.
        assert_eq!(
            (
                closed.vertex_count(),
                closed.edge_count(),
                closed.face_count()
            ),
            (6, 12, 8)
        );
        let topology = closed.topology();
        assert_eq!((topology.boundary_loops, topology.genus), (0, 0));
        assert_eq!(closed.validate(), Ok(()));
        assert!(closed.faces().all(|f| closed.face_source(f) != u32::MAX));
    }

    #[test]
    fn a_rim_through_one_point_twice_is_capped_on_each_side_of_it() {
        // A 4 x 4 grid of unit squares without the two squares that meet at the corner
        // (2, 2) only: the hole's rim passes that point twice, so it has a copy there.
        let mut positions: Vec<DVec3> = (0..25)
            .map(|i| DVec3::new((i % 5) as f64 * 10.0, (i / 5) as f64 * 10.0, 0.0))
            .collect();
        positions.push(positions[12]);
        let mut faces = Vec::new();
        for (x, y) in (0..4).flat_map(|y| (0..4).map(move |x| (x, y))) {
            if (x, y) == (1, 1) || (x, y) == (2, 2) {
                continue;
            }
            let v = |dx: u32, dy: u32| (y + dy) * 5 + x + dx;
            let mut quad = [v(0, 0), v(1, 0), v(1, 1), v(0, 1)];
            // The square above-left of the pinch takes the copy.
            if (x, y) == (1, 2) {
                quad[1] = 25;
            }
            faces.push(quad);
        }
        let open = crate::mesh::build_from_faces(positions, &faces).unwrap();
        assert_eq!(open.topology().boundary_loops, 2);
        let (closed, filled) = fill_holes(&open).unwrap().unwrap();
        assert_eq!((filled.holes, filled.joined, filled.largest), (2, 1, 16));
        // 14 squares, the outer cap and one cap for each missing square.
        assert_eq!((closed.vertex_count(), closed.face_count()), (25, 17));
        let caps: Vec<usize> = closed
            .faces()
            .filter(|&f| closed.face_source(f) == u32::MAX)
            .map(|f| closed.face_degree(f))
            .collect();
        assert_eq!(caps, vec![16, 4, 4]);
        let topology = closed.topology();
        assert_eq!((topology.boundary_loops, topology.genus), (0, 0));
        assert_eq!(closed.validate(), Ok(()));
    }
}
