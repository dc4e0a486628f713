//! 3D panels and flat panels.
//!
//! A panel is a small polygon mesh of planar facets (3D polygons) with shared corner
//! vertices. An edge shared by two facets is a hinge (a fold, scored when its fold angle
//! is not zero); an edge of one facet only is part of the cut outline. Every scheme
//! produces panels in this form, so one unroller and one exporter serve them all.

mod arena;
mod label;
mod loops;
mod panels;
mod shape;
mod source;
pub mod surface;

pub use arena::{fill_arena, Arena, ArenaIter, Views};
pub(crate) use label::box_area;
pub use label::{
    label_box, label_extent, Label, LabelKind, LeftOut, FRAME_PAD, MIN_HEIGHT, TIGHT_FRAME_PAD,
};
pub use loops::{Loops, LoopsIter, LoopsRef};
pub use panels::{FlatPanels, FlatPanelsIter, Panels, PanelsIter, Tallied};
pub use shape::{
    FacetFrame, FlatHole, FlatLabel, FlatPanel, FlatPanelRef, Fold, FoldKind, Hole, Panel, PanelRef,
};
pub use source::{Covers, FaceGroup, IdKind, Name, Source, EDGE, FACE, VERTEX};
