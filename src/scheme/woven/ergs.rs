//! The extended graph rotation system (paper 002, thesis ch. 5) as a view of the
//! half-edge mesh: a twist flag per edge, and face tracing that flips between the
//! rotation successor and predecessor each time it crosses a twisted edge. With every
//! edge twisted each traced cycle is a zig-zag (Petrie) walk, and the cycles form a
//! plain weave: every edge is crossed twice, once over and once under, and over and
//! under alternate along every cycle. With no edge twisted the cycles are the faces.
//!
//! Half-edge form of a step: after walking dart h (u → w), a left step continues along
//! the face on h's left, `next(h)`; a right step along the face on its right,
//! `twin(prev(twin(h)))`. A step passes one face corner (at w), named here by the
//! face half-edge that ends there: h for a left step, `prev(twin(h))` for a right one.

use crate::mesh::{EdgeId, HalfedgeId, Mesh};

/// Which face a step follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The face on the left of the dart (rotation successor).
    Left,
    /// The face on the right of the dart (rotation predecessor).
    Right,
}

impl Side {
    fn flipped(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// One traced cycle (a thread of the weave).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WeaveCycle {
    /// The darts walked, in order.
    pub darts: Vec<HalfedgeId>,
    /// The side of the step after each dart.
    pub sides: Vec<Side>,
    /// The face corner passed after each dart (the face half-edge ending there).
    pub corners: Vec<HalfedgeId>,
    /// At each dart's edge: `Some(true)` where the thread goes over, `Some(false)`
    /// under, `None` where the edge is not twisted (the thread runs beside it).
    pub over: Vec<Option<bool>>,
}

impl WeaveCycle {
    /// Number of edges walked.
    pub fn len(&self) -> usize {
        self.darts.len()
    }

    /// True for an empty cycle (never produced).
    pub fn is_empty(&self) -> bool {
        self.darts.is_empty()
    }

    /// The edges walked, in order.
    pub fn edges(&self) -> impl Iterator<Item = EdgeId> + '_ {
        self.darts.iter().map(|h| h.edge())
    }
}

/// Why cycles cannot be traced.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TraceError {
    /// A walk reached a boundary edge (no face on the side it must follow).
    #[error("the walk reaches boundary edge {0}: weaving needs a closed mesh")]
    Boundary(EdgeId),
    /// The twist table does not have one flag per edge.
    #[error("{given} twist flags for {edges} edges")]
    TwistCount { given: usize, edges: usize },
}

/// Traces every cycle of the rotation system with the given twist per edge. Cycles
/// come in a deterministic order (by their first untraced face corner in half-edge
/// order); each cycle is traced once, not once per direction.
pub fn trace_cycles(mesh: &Mesh, twisted: &[bool]) -> Result<Vec<WeaveCycle>, TraceError> {
    if twisted.len() != mesh.edge_count() {
        return Err(TraceError::TwistCount {
            given: twisted.len(),
            edges: mesh.edge_count(),
        });
    }
    let mut traced = vec![false; mesh.half_edge_count()];
    let mut cycles = Vec::new();
    for start in mesh.half_edges() {
        if mesh.is_boundary_half_edge(start) || traced[start.index()] {
            continue;
        }
        // Start just before the corner at dest(start) of start's face: a left step.
        let mut cycle = WeaveCycle {
            darts: Vec::new(),
            sides: Vec::new(),
            corners: Vec::new(),
            over: Vec::new(),
        };
        let (mut h, mut side) = (start, Side::Left);
        let limit = 2 * mesh.half_edge_count() + 2;
        loop {
            let corner = match side {
                Side::Left => h,
                Side::Right => mesh.prev(h.twin()),
            };
            if mesh.is_boundary_half_edge(corner) {
                return Err(TraceError::Boundary(h.edge()));
            }
            traced[corner.index()] = true;
            cycle.darts.push(h);
            cycle.sides.push(side);
            cycle.corners.push(corner);
            // Crossing h's edge the thread goes from the corner at h's origin to the
            // corner at its destination; it is over when the face holding the
            // destination corner is on h's right (a right step follows).
            cycle
                .over
                .push(twisted[h.edge().index()].then_some(side == Side::Right));
            let next = match side {
                Side::Left => mesh.next(h),
                Side::Right => mesh.prev(h.twin()).twin(),
            };
            let next_side = if twisted[next.edge().index()] {
                side.flipped()
            } else {
                side
            };
            h = next;
            side = next_side;
            if (h, side) == (start, Side::Left) || cycle.darts.len() > limit {
                break;
            }
        }
        cycles.push(cycle);
    }
    Ok(cycles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::tetrahedron;

    #[test]
    fn untwisted_cycles_are_the_faces() {
        let mesh = tetrahedron();
        let cycles = trace_cycles(&mesh, &vec![false; mesh.edge_count()]).unwrap();
        assert_eq!(cycles.len(), 4);
        assert!(cycles.iter().all(|c| c.len() == 3));
        assert!(cycles.iter().all(|c| c.over.iter().all(Option::is_none)));
    }

    #[test]
    fn twisted_tetrahedron_weaves_three_cycles_of_four() {
        let mesh = tetrahedron();
        let cycles = trace_cycles(&mesh, &vec![true; mesh.edge_count()]).unwrap();
        let mut lengths: Vec<usize> = cycles.iter().map(WeaveCycle::len).collect();
        lengths.sort();
        assert_eq!(lengths, vec![4, 4, 4]);
    }

    #[test]
    fn wrong_twist_count_is_an_error() {
        let mesh = tetrahedron();
        assert!(trace_cycles(&mesh, &[true]).is_err());
    }
}
