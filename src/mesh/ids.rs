//! Typed element handles.
//!
//! A handle is only an index into the mesh's arrays: it never borrows the mesh, so any
//! number of handles can be held while the mesh is read (navigation lives on
//! [`crate::mesh::Mesh`]). `u32` keeps the arrays compact: 4 G elements is far beyond
//! anything a laser cutter will ever see.

use std::fmt;

macro_rules! handle {
    ($(#[$doc:meta])* $name:ident, $prefix:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
        #[repr(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The handle as an array index.
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }

            /// A handle from an array index. Panics past `u32::MAX`, which the mesh
            /// builder rules out before creating any element.
            #[inline]
            pub fn from_index(index: usize) -> Self {
                Self(u32::try_from(index).expect("mesh element index exceeds u32"))
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }
    };
}

handle!(
    /// A vertex of the half-edge mesh.
    VertexId,
    "v"
);
handle!(
    /// A directed half-edge. Half-edges come in pairs: the twin of `h` is `h ^ 1` and
    /// its edge is `h / 2`, so twin links cannot drift out of step.
    HalfedgeId,
    "h"
);
handle!(
    /// An undirected edge: the pair of half-edges `2e` and `2e + 1`.
    EdgeId,
    "e"
);
handle!(
    /// A face (a polygon with three or more corners).
    FaceId,
    "f"
);

impl HalfedgeId {
    /// The opposite half-edge of the same edge.
    #[inline]
    pub fn twin(self) -> HalfedgeId {
        HalfedgeId(self.0 ^ 1)
    }

    /// The undirected edge this half-edge belongs to.
    #[inline]
    pub fn edge(self) -> EdgeId {
        EdgeId(self.0 >> 1)
    }
}

impl EdgeId {
    /// The first half-edge of the edge (`2e`); its twin is `2e + 1`.
    #[inline]
    pub fn half_edge(self) -> HalfedgeId {
        HalfedgeId(self.0 << 1)
    }
}
