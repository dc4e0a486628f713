//! The island engine the net and strip schemes build on: islands of many faces joined
//! along folds, every other interior edge a cut glued by one tab. It is no scheme of
//! its own.
//!
//! Islands grow greedily over the edges in order of their fold angle (flattest first,
//! so the cuts fall on the sharp edges): an edge joins the islands of its two faces when
//! the smaller one, turned about that edge into the larger one's plane, overlaps none of
//! its faces, the union still fits the sheet and stays compact (its convex hull at most
//! `--island-spread` times its area: sprawling islands waste the sheet between their
//! arms; a join that makes a whole connected part one island is made whatever its
//! shape). A second pass lets islands of a few faces join a neighbour whatever shape
//! that makes. Faces of an island that meet at a
//! folded corner may touch there; any other two keep [`ISLAND_GAP`] apart, so the
//! outline stays a simple polygon with room for the laser. Each island is a tree of
//! faces, so it unrolls exactly.
//!
//! Each cut edge then gets a tab on one side, made like the half-edge scheme's (in the
//! partner face's plane, inside the triangle of the edge and the partner's centre, so
//! tabs under one face never meet). Laid flat, a tab must keep clear of its island's
//! other faces and tabs: where it does not, the other side is tried and the tab is
//! lowered, and only where no height fits is it left out (and counted). Both sides of a
//! cut carry the same match number (or, where the scheme asks for seams, the faces on
//! both sides of one edge of each seam: a run of cut edges end to end between two
//! islands).

mod build;
mod grow;
mod options;
mod panel;
mod summary;
mod tabs;

pub(in crate::scheme) use build::island_net;
pub use build::{islands_along, IslandNames, IslandNet, OwnNet};
pub(in crate::scheme) use grow::grow_islands;
#[cfg(test)]
pub(in crate::scheme) use options::test_options;
pub(in crate::scheme) use options::{FlatFoldArgs, FLAT_FOLD_DEG};
pub use options::{IslandOptions, ISLAND, MATCH};
pub use summary::Summary;
pub(in crate::scheme) use tabs::fits_sheet;
pub use tabs::ISLAND_GAP;
