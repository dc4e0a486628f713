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
        let out_of_range = |what, at: String| Err(E::OutOfRange { what, at });
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

        // Every outgoing half-edge of a vertex must be reached by turning around it from
        // its stored half-edge; a boundary vertex must store its boundary half-edge.
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
