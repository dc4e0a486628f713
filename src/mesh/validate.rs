//! Connectivity invariants of the half-edge mesh, checked one rule at a time.

use super::halfedge::{Mesh, NO_FACE};
use super::ids::{FaceId, HalfedgeId, VertexId};

/// The first broken rule found by [`Mesh::validate`]. Each variant is one invariant,
/// so a test (or a bug report) says exactly what went wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ConnectivityError {
    /// Array lengths disagree with each other.
    #[error("table sizes disagree: {0}")]
    Sizes(&'static str),
    /// A stored handle points past the end of its table.
    #[error("{what} of {at} is out of range")]
    OutOfRange { what: &'static str, at: String },
    /// `next(prev(h)) != h` or `prev(next(h)) != h`.
    #[error("next and prev disagree at {0}")]
    NextPrev(HalfedgeId),
    /// A half-edge and its twin start at the same vertex, or `next(h)` does not start
    /// where `h` ends.
    #[error("half-edge {0} does not connect head to tail with its neighbours")]
    Endpoints(HalfedgeId),
    /// A face loop does not close within the half-edge count, or mixes faces.
    #[error("the loop of face {0} does not close on itself")]
    FaceLoop(FaceId),
    /// An edge with no face on either side.
    #[error("edge of half-edge {0} has no face on either side")]
    FacelessEdge(HalfedgeId),
    /// A vertex's stored half-edge does not start at it.
    #[error("the stored half-edge of {0} does not start there")]
    VertexHalfedge(VertexId),
    /// A boundary vertex whose stored half-edge is not its boundary half-edge.
    #[error("boundary vertex {0} does not store its boundary half-edge")]
    BoundaryVertexHalfedge(VertexId),
    /// Turning around a vertex does not visit all its outgoing half-edges (a bow-tie).
    #[error("vertex {0} has more than one fan of faces")]
    NonManifoldVertex(VertexId),
    /// A face with fewer than three corners.
    #[error("face {0} has fewer than 3 corners")]
    DegenerateFace(FaceId),
}

impl Mesh {
    /// Checks every connectivity invariant: sizes, then index ranges, then every loop
    /// with a step limit, then vertex fans. O(n); meant for tests and debug builds.
    pub fn validate(&self) -> Result<(), ConnectivityError> {
        self.check_sizes()?;
        self.check_ranges()?;
        self.check_half_edge_links()?;
        self.check_face_loops()?;
        self.check_vertex_fans()
    }

    /// Checks that the tables agree in length and that half-edges come in pairs.
    fn check_sizes(&self) -> Result<(), ConnectivityError> {
        use ConnectivityError as E;
        let nh = self.half_edge_count();
        let (nv, nf) = (self.vertex_count(), self.face_count());
        if !nh.is_multiple_of(2) {
            return Err(E::Sizes("odd number of half-edges"));
        }
        if self.half_edge_prev.len() != nh
            || self.half_edge_origin.len() != nh
            || self.half_edge_face.len() != nh
        {
            return Err(E::Sizes("half-edge tables"));
        }
        if self.vertex_half_edge.len() != nv || self.vertex_source.len() != nv {
            return Err(E::Sizes("vertex tables"));
        }
        if self.face_source.len() != nf {
            return Err(E::Sizes("face tables"));
        }
        Ok(())
    }

    /// Checks that every stored handle points into its table.
    fn check_ranges(&self) -> Result<(), ConnectivityError> {
        let nh = self.half_edge_count();
        let (nv, nf) = (self.vertex_count(), self.face_count());
        let out_of_range = |what, at: String| Err(ConnectivityError::OutOfRange { what, at });
        for h in self.half_edges() {
            let i = h.index();
            if self.half_edge_next[i].index() >= nh {
                return out_of_range("next", h.to_string());
            }
            if self.half_edge_prev[i].index() >= nh {
                return out_of_range("prev", h.to_string());
            }
            if self.half_edge_origin[i].index() >= nv {
                return out_of_range("origin", h.to_string());
            }
            let f = self.half_edge_face[i];
            if f != NO_FACE && f as usize >= nf {
                return out_of_range("face", h.to_string());
            }
        }
        for v in self.vertices() {
            if self.vertex_half_edge[v.index()].index() >= nh {
                return out_of_range("half-edge", v.to_string());
            }
        }
        for f in self.faces() {
            if self.face_half_edge[f.index()].index() >= nh {
                return out_of_range("half-edge", f.to_string());
            }
        }
        Ok(())
    }

    /// Checks that next and prev are inverse, that half-edges join head to tail, and
    /// that every edge has a face on at least one side.
    fn check_half_edge_links(&self) -> Result<(), ConnectivityError> {
        use ConnectivityError as E;
        for h in self.half_edges() {
            if self.prev(self.next(h)) != h || self.next(self.prev(h)) != h {
                return Err(E::NextPrev(h));
            }
            if self.origin(self.next(h)) != self.dest(h) || self.origin(h) == self.dest(h) {
                return Err(E::Endpoints(h));
            }
            if self.is_boundary_half_edge(h) && self.is_boundary_half_edge(h.twin()) {
                return Err(E::FacelessEdge(h));
            }
        }
        Ok(())
    }

    /// Checks that every face loop closes on itself, within the half-edge count, and
    /// has at least three corners.
    fn check_face_loops(&self) -> Result<(), ConnectivityError> {
        use ConnectivityError as E;
        let nh = self.half_edge_count();
        for f in self.faces() {
            let start = self.face_half_edge(f);
            let mut h = start;
            let mut steps = 0usize;
            loop {
                if self.face(h) != Some(f) {
                    return Err(E::FaceLoop(f));
                }
                h = self.next(h);
                steps += 1;
                if h == start {
                    break;
                }
                if steps > nh {
                    return Err(E::FaceLoop(f));
                }
            }
            if steps < 3 {
                return Err(E::DegenerateFace(f));
            }
        }
        Ok(())
    }

    /// Checks that turning around each vertex from its stored half-edge reaches all its
    /// outgoing half-edges, and that a boundary vertex stores its boundary half-edge.
    fn check_vertex_fans(&self) -> Result<(), ConnectivityError> {
        use ConnectivityError as E;
        let nv = self.vertex_count();
        let mut outgoing = vec![0u32; nv];
        let mut boundary_out = vec![0u32; nv];
        for h in self.half_edges() {
            let o = self.origin(h).index();
            outgoing[o] += 1;
            if self.is_boundary_half_edge(h) {
                boundary_out[o] += 1;
            }
        }
        for v in self.vertices() {
            let start = self.vertex_half_edge(v);
            if self.origin(start) != v {
                return Err(E::VertexHalfedge(v));
            }
            if boundary_out[v.index()] > 1 {
                return Err(E::NonManifoldVertex(v));
            }
            if boundary_out[v.index()] == 1 && !self.is_boundary_half_edge(start) {
                return Err(E::BoundaryVertexHalfedge(v));
            }
            let mut turned = 0u32;
            let mut h = start;
            loop {
                if self.origin(h) != v {
                    return Err(E::Endpoints(h));
                }
                turned += 1;
                h = self.next(h.twin());
                if h == start {
                    break;
                }
                if turned > outgoing[v.index()] {
                    return Err(E::NonManifoldVertex(v));
                }
            }
            if turned != outgoing[v.index()] {
                return Err(E::NonManifoldVertex(v));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::tetrahedron;
    use crate::mesh::build_from_faces;
    use glam::DVec3;

    /// Two triangles sharing the edge 1-2: an open square with one boundary loop.
    fn square() -> Mesh {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ];
        build_from_faces(p, &[[0u32, 1, 2], [2, 1, 3]]).unwrap()
    }

    /// A half-edge of `mesh` starting at `v` that satisfies `keep`.
    fn outgoing(mesh: &Mesh, v: VertexId, keep: impl Fn(HalfedgeId) -> bool) -> HalfedgeId {
        mesh.half_edges()
            .find(|&h| mesh.origin(h) == v && keep(h))
            .expect("such a half-edge")
    }

    #[test]
    fn built_meshes_are_valid() {
        assert_eq!(tetrahedron().validate(), Ok(()));
        assert_eq!(square().validate(), Ok(()));
    }

    #[test]
    fn tables_of_different_lengths_are_sizes() {
        let mut odd = tetrahedron();
        odd.half_edge_next.push(HalfedgeId(0));
        assert_eq!(
            odd.validate(),
            Err(ConnectivityError::Sizes("odd number of half-edges"))
        );
        let mut short = tetrahedron();
        short.vertex_source.pop();
        assert_eq!(
            short.validate(),
            Err(ConnectivityError::Sizes("vertex tables"))
        );
        let mut faces = tetrahedron();
        faces.face_source.push(0);
        assert_eq!(
            faces.validate(),
            Err(ConnectivityError::Sizes("face tables"))
        );
    }

    #[test]
    fn a_handle_past_its_table_is_out_of_range() {
        let mut mesh = tetrahedron();
        mesh.half_edge_origin[3] = VertexId(99);
        assert_eq!(
            mesh.validate(),
            Err(ConnectivityError::OutOfRange {
                what: "origin",
                at: HalfedgeId(3).to_string()
            })
        );
        let mut mesh = tetrahedron();
        mesh.face_half_edge[2] = HalfedgeId(99);
        assert!(matches!(
            mesh.validate(),
            Err(ConnectivityError::OutOfRange {
                what: "half-edge",
                ..
            })
        ));
    }

    #[test]
    fn a_prev_that_is_not_the_inverse_of_next_is_found() {
        let mut mesh = tetrahedron();
        let h = HalfedgeId(0);
        let next = mesh.next(h);
        mesh.half_edge_prev[next.index()] = next;
        assert!(matches!(
            mesh.validate(),
            Err(ConnectivityError::NextPrev(_))
        ));
    }

    #[test]
    fn a_moved_origin_breaks_the_endpoints() {
        let mut mesh = tetrahedron();
        let h = HalfedgeId(0);
        // h now starts where its twin starts.
        mesh.half_edge_origin[h.index()] = mesh.origin(h.twin());
        assert!(matches!(
            mesh.validate(),
            Err(ConnectivityError::Endpoints(_))
        ));
    }

    #[test]
    fn an_edge_without_faces_is_found() {
        let mut mesh = tetrahedron();
        let h = HalfedgeId(4);
        mesh.half_edge_face[h.index()] = NO_FACE;
        mesh.half_edge_face[h.twin().index()] = NO_FACE;
        assert_eq!(mesh.validate(), Err(ConnectivityError::FacelessEdge(h)));
    }

    #[test]
    fn a_loop_that_mixes_faces_is_found() {
        let mut mesh = tetrahedron();
        let f = FaceId(1);
        let h = mesh.next(mesh.face_half_edge(f));
        mesh.half_edge_face[h.index()] = 0;
        assert!(matches!(
            mesh.validate(),
            Err(ConnectivityError::FaceLoop(_))
        ));
    }

    #[test]
    fn a_stored_half_edge_elsewhere_is_found() {
        let mut mesh = tetrahedron();
        let v = VertexId(2);
        let elsewhere = outgoing(&mesh, VertexId(0), |_| true);
        mesh.vertex_half_edge[v.index()] = elsewhere;
        assert_eq!(mesh.validate(), Err(ConnectivityError::VertexHalfedge(v)));
    }

    #[test]
    fn a_boundary_vertex_must_store_its_boundary_half_edge() {
        let mut mesh = square();
        // Vertex 1 is on the boundary and has an interior outgoing half-edge (to 2).
        let v = VertexId(1);
        let inner = outgoing(&mesh, v, |h| {
            !mesh.is_boundary_half_edge(h) && !mesh.is_boundary_half_edge(h.twin())
        });
        mesh.vertex_half_edge[v.index()] = inner;
        assert_eq!(
            mesh.validate(),
            Err(ConnectivityError::BoundaryVertexHalfedge(v))
        );
    }

    #[test]
    fn two_fans_at_one_vertex_are_a_non_manifold_vertex() {
        // Two triangles meeting only at vertex 0: the builder splits it into one
        // vertex per fan; joining the copies back makes a bow-tie.
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
        ];
        let mut mesh = build_from_faces(p, &[[0u32, 1, 2], [0, 3, 4]]).unwrap();
        assert_eq!(mesh.vertex_count(), 6, "the bow-tie was split");
        assert_eq!(mesh.validate(), Ok(()));
        let copy = VertexId(5);
        for origin in &mut mesh.half_edge_origin {
            if *origin == copy {
                *origin = VertexId(0);
            }
        }
        assert_eq!(
            mesh.validate(),
            Err(ConnectivityError::NonManifoldVertex(VertexId(0)))
        );
    }

    #[test]
    fn a_face_of_two_corners_is_degenerate() {
        // Two vertices joined by two edges, each side a two-cornered face: every
        // other rule holds.
        let mesh = Mesh {
            positions: vec![DVec3::ZERO, DVec3::X],
            vertex_half_edge: vec![HalfedgeId(0), HalfedgeId(1)],
            // h0: 0→1 and h3: 1→0 bound face 0; h2: 0→1 and h1: 1→0 bound face 1.
            half_edge_next: vec![HalfedgeId(3), HalfedgeId(2), HalfedgeId(1), HalfedgeId(0)],
            half_edge_prev: vec![HalfedgeId(3), HalfedgeId(2), HalfedgeId(1), HalfedgeId(0)],
            half_edge_origin: vec![VertexId(0), VertexId(1), VertexId(0), VertexId(1)],
            half_edge_face: vec![0, 1, 1, 0],
            face_half_edge: vec![HalfedgeId(0), HalfedgeId(2)],
            vertex_source: vec![0, 1],
            face_source: vec![0, 1],
        };
        assert_eq!(
            mesh.validate(),
            Err(ConnectivityError::DegenerateFace(FaceId(0)))
        );
    }
}
