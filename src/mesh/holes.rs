//! Closing the holes of a mesh (`--fill-holes`): each boundary loop becomes one face
//! whose corners are the loop's vertices, wound the way the loop runs, so the mesh
//! stays oriented and every edge gets its second face. A scan's holes (the bunny's
//! base) and a patch model's open rims (the teapot's spout) keep short edges at any
//! simplification budget, and the woven scheme needs a closed mesh; a cap removes
//! both. Caps are ordinary faces afterwards: a warped or concave one is split into
//! triangles like any other, and simplification may collapse across it.

use super::build::{build_mesh, BuildError};
use super::{Mesh, Polygons};

/// What [`fill_holes`] closed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FilledHoles {
    /// Holes closed (boundary loops).
    pub holes: usize,
    /// Edges of the largest of them.
    pub largest: usize,
}

/// The mesh with every boundary loop closed by one face (no face source: a cap is
/// not in the file), or `None` when the mesh is closed already. Vertices keep their
/// indices and sources; faces keep theirs, the caps follow them.
pub fn fill_holes(mesh: &Mesh) -> Result<Option<(Mesh, FilledHoles)>, BuildError> {
    let loops = mesh.boundary_loops();
    if loops.is_empty() {
        return Ok(None);
    }
    let mut polys = Polygons::new();
    polys.positions = mesh.positions().to_vec();
    let vertex_source: Vec<u32> = mesh.vertices().map(|v| mesh.vertex_source(v)).collect();
    let mut face_source = Vec::with_capacity(mesh.face_count() + loops.len());
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        polys.push_face(&corners);
        face_source.push(mesh.face_source(f));
    }
    let mut filled = FilledHoles::default();
    for &start in &loops {
        // A boundary half-edge runs the way the missing face would wind.
        let corners: Vec<u32> = mesh.loop_from(start).map(|h| mesh.origin(h).0).collect();
        filled.holes += 1;
        filled.largest = filled.largest.max(corners.len());
        polys.push_face(&corners);
        face_source.push(u32::MAX);
    }
    let (closed, _) = build_mesh(&polys, Some(&vertex_source), Some(&face_source))?;
    Ok(Some((closed, filled)))
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
                largest: 4
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
}
