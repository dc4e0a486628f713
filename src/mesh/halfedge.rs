//! The half-edge mesh: connectivity in flat arrays, navigation as methods.
//!
//! Conventions (shared by every scheme):
//! - half-edges come in pairs, `twin(h) = h ^ 1`, `edge(h) = h / 2`;
//! - a face's half-edges run counter-clockwise seen from outside (outward normal by the
//!   right-hand rule);
//! - every edge has two half-edges; on the boundary one of them has no face. Boundary
//!   half-edges are linked by `next`/`prev` into boundary loops, so a hole can be walked
//!   like a face;
//! - a boundary vertex's stored half-edge is its outgoing boundary half-edge, so
//!   `is_boundary_vertex` is O(1) and a walk around the vertex covers its whole fan;
//! - every vertex is manifold (one fan); the builder splits bow-ties to ensure it.

use glam::DVec3;

use super::ids::{EdgeId, FaceId, HalfedgeId, VertexId};

/// Marks "no face" in the half-edge → face table (boundary half-edges).
pub(crate) const NO_FACE: u32 = u32::MAX;

/// A polygon mesh with half-edge connectivity and vertex positions.
///
/// Elements remember where they came from in the input (`vertex_source`,
/// `face_source`), so every message and every panel can name the user's own indices.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub(crate) positions: Vec<DVec3>,
    pub(crate) vertex_half_edge: Vec<HalfedgeId>,
    pub(crate) half_edge_next: Vec<HalfedgeId>,
    pub(crate) half_edge_prev: Vec<HalfedgeId>,
    pub(crate) half_edge_origin: Vec<VertexId>,
    pub(crate) half_edge_face: Vec<u32>,
    pub(crate) face_half_edge: Vec<HalfedgeId>,
    pub(crate) vertex_source: Vec<u32>,
    pub(crate) face_source: Vec<u32>,
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of half-edges (twice the number of edges).
    pub fn half_edge_count(&self) -> usize {
        self.half_edge_next.len()
    }

    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.half_edge_next.len() / 2
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.face_half_edge.len()
    }

    /// All vertex handles in index order.
    pub fn vertices(&self) -> impl ExactSizeIterator<Item = VertexId> {
        (0..self.vertex_count() as u32).map(VertexId)
    }

    /// All half-edge handles in index order.
    pub fn half_edges(&self) -> impl ExactSizeIterator<Item = HalfedgeId> {
        (0..self.half_edge_count() as u32).map(HalfedgeId)
    }

    /// All edge handles in index order.
    pub fn edges(&self) -> impl ExactSizeIterator<Item = EdgeId> {
        (0..self.edge_count() as u32).map(EdgeId)
    }

    /// All face handles in index order.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = FaceId> {
        (0..self.face_count() as u32).map(FaceId)
    }

    /// Position of a vertex, in model units.
    #[inline]
    pub fn position(&self, v: VertexId) -> DVec3 {
        self.positions[v.index()]
    }

    /// All vertex positions, indexed by vertex.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Replaces every position (one per vertex, in vertex order): the connectivity
    /// stays, only the geometry moves (planarization).
    pub fn set_positions(&mut self, positions: Vec<DVec3>) {
        assert_eq!(
            positions.len(),
            self.positions.len(),
            "one position per vertex"
        );
        self.positions = positions;
    }

    /// Multiplies every position by `factor` (model units to millimetres, say).
    pub fn scale(&mut self, factor: f64) {
        for p in &mut self.positions {
            *p *= factor;
        }
    }

    /// The input vertex (0-based, as counted in the file) this vertex came from. The
    /// parts of a split bow-tie vertex share one source.
    #[inline]
    pub fn vertex_source(&self, v: VertexId) -> u32 {
        self.vertex_source[v.index()]
    }

    /// The input face (0-based index among the file's faces) this face came from.
    #[inline]
    pub fn face_source(&self, f: FaceId) -> u32 {
        self.face_source[f.index()]
    }

    /// The opposite half-edge.
    #[inline]
    pub fn twin(&self, h: HalfedgeId) -> HalfedgeId {
        h.twin()
    }

    /// The next half-edge around the face (or boundary loop).
    #[inline]
    pub fn next(&self, h: HalfedgeId) -> HalfedgeId {
        self.half_edge_next[h.index()]
    }

    /// The previous half-edge around the face (or boundary loop).
    #[inline]
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        self.half_edge_prev[h.index()]
    }

    /// The vertex a half-edge starts at.
    #[inline]
    pub fn origin(&self, h: HalfedgeId) -> VertexId {
        self.half_edge_origin[h.index()]
    }

    /// The vertex a half-edge ends at.
    #[inline]
    pub fn dest(&self, h: HalfedgeId) -> VertexId {
        self.origin(h.twin())
    }

    /// The face to the left of a half-edge, `None` on the boundary.
    #[inline]
    pub fn face(&self, h: HalfedgeId) -> Option<FaceId> {
        match self.half_edge_face[h.index()] {
            NO_FACE => None,
            f => Some(FaceId(f)),
        }
    }

    /// True for half-edges without a face (they run along holes).
    #[inline]
    pub fn is_boundary_half_edge(&self, h: HalfedgeId) -> bool {
        self.half_edge_face[h.index()] == NO_FACE
    }

    /// True for edges with a face on one side only.
    #[inline]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = e.half_edge();
        self.is_boundary_half_edge(h) || self.is_boundary_half_edge(h.twin())
    }

    /// True for vertices on a boundary loop.
    #[inline]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.is_boundary_half_edge(self.vertex_half_edge(v))
    }

    /// One outgoing half-edge of a vertex (the boundary one for boundary vertices).
    #[inline]
    pub fn vertex_half_edge(&self, v: VertexId) -> HalfedgeId {
        self.vertex_half_edge[v.index()]
    }

    /// One half-edge of a face.
    #[inline]
    pub fn face_half_edge(&self, f: FaceId) -> HalfedgeId {
        self.face_half_edge[f.index()]
    }

    /// The two end vertices of an edge (origin and destination of `2e`).
    pub fn edge_vertices(&self, e: EdgeId) -> (VertexId, VertexId) {
        let h = e.half_edge();
        (self.origin(h), self.dest(h))
    }

    /// The length of an edge.
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        let (a, b) = self.edge_vertices(e);
        self.position(a).distance(self.position(b))
    }

    /// Every edge's length, shortest first (for medians and percentiles).
    pub fn sorted_edge_lengths(&self) -> Vec<f64> {
        let mut lengths: Vec<f64> = self.edges().map(|e| self.edge_length(e)).collect();
        lengths.sort_unstable_by(f64::total_cmp);
        lengths
    }

    /// The half-edges of a face, counter-clockwise from its stored half-edge.
    pub fn face_half_edges(&self, f: FaceId) -> LoopIter<'_> {
        self.loop_from(self.face_half_edge(f))
    }

    /// The half-edges of the loop (face or boundary) that `start` belongs to.
    pub fn loop_from(&self, start: HalfedgeId) -> LoopIter<'_> {
        LoopIter {
            mesh: self,
            start,
            current: Some(start),
            steps_left: self.half_edge_count(),
        }
    }

    /// The corner vertices of a face, counter-clockwise.
    pub fn face_vertices(&self, f: FaceId) -> impl Iterator<Item = VertexId> + '_ {
        self.face_half_edges(f).map(move |h| self.origin(h))
    }

    /// The corner positions of a face, counter-clockwise.
    pub fn face_positions(&self, f: FaceId) -> impl Iterator<Item = DVec3> + '_ {
        self.face_vertices(f).map(move |v| self.position(v))
    }

    /// Number of corners of a face.
    pub fn face_degree(&self, f: FaceId) -> usize {
        self.face_half_edges(f).count()
    }

    /// The outgoing half-edges of a vertex, starting with its stored half-edge and
    /// turning through its fan (for a boundary vertex, the boundary half-edge first).
    pub fn vertex_outgoing(&self, v: VertexId) -> VertexIter<'_> {
        let start = self.vertex_half_edge(v);
        VertexIter {
            mesh: self,
            start,
            current: Some(start),
            steps_left: self.half_edge_count(),
        }
    }

    /// The faces around a vertex (each once).
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.vertex_outgoing(v).filter_map(move |h| self.face(h))
    }

    /// The vertices adjacent to a vertex.
    pub fn vertex_neighbours(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        self.vertex_outgoing(v).map(move |h| self.dest(h))
    }

    /// The average of a face's corners: the thesis' "face centre" used by every scheme.
    pub fn face_centre(&self, f: FaceId) -> DVec3 {
        let (sum, n) = self
            .face_positions(f)
            .fold((DVec3::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
        sum / n as f64
    }

    /// The vector area of a face (half the sum of corner cross products): its length is
    /// the area of a planar face and its direction the outward normal.
    pub fn face_vector_area(&self, f: FaceId) -> DVec3 {
        super::geometry::vector_area(self.face_positions(f))
    }

    /// The unit outward normal of a face (zero for a degenerate face).
    pub fn face_normal(&self, f: FaceId) -> DVec3 {
        self.face_vector_area(f).normalize_or_zero()
    }

    /// A face's plane with axes, its origin at the face centre (the frame the schemes
    /// draw a face's band and connectors in).
    pub fn face_frame(&self, f: FaceId) -> super::geometry::PlaneFrame {
        super::geometry::PlaneFrame::new(self.face_centre(f), self.face_normal(f))
    }

    /// The area of a face (of its vector area; exact for planar faces).
    pub fn face_area(&self, f: FaceId) -> f64 {
        self.face_vector_area(f).length()
    }
}

/// Walks a face or boundary loop by `next`. Stops after returning to its start, or
/// after as many steps as there are half-edges, so a corrupt mesh cannot hang a walk.
pub struct LoopIter<'a> {
    mesh: &'a Mesh,
    start: HalfedgeId,
    current: Option<HalfedgeId>,
    steps_left: usize,
}

impl Iterator for LoopIter<'_> {
    type Item = HalfedgeId;
    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.current?;
        let n = self.mesh.next(h);
        self.steps_left = self.steps_left.saturating_sub(1);
        self.current = (n != self.start && self.steps_left > 0).then_some(n);
        Some(h)
    }
}

/// Turns around a vertex: from outgoing `h`, the next outgoing half-edge is
/// `next(twin(h))`. Like [`LoopIter`], bounded by the half-edge count.
pub struct VertexIter<'a> {
    mesh: &'a Mesh,
    start: HalfedgeId,
    current: Option<HalfedgeId>,
    steps_left: usize,
}

impl Iterator for VertexIter<'_> {
    type Item = HalfedgeId;
    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.current?;
        let n = self.mesh.next(h.twin());
        self.steps_left = self.steps_left.saturating_sub(1);
        self.current = (n != self.start && self.steps_left > 0).then_some(n);
        Some(h)
    }
}
