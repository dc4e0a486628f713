//! What covering a surface with strips works on and with: a patch of the surface
//! between two values of the field, and the cover's settings, shared by the
//! slicing, the sectors and the covering.

use super::surface::Triangles;

/// A connected part of the surface between two values of the field, covered by
/// strips on its own.
pub(super) struct Patch {
    pub(super) surface: Triangles,
    /// The field at each point.
    pub(super) values: Vec<f64>,
    /// Whether the strips must keep each point (its neighbours beyond the patch do).
    pub(super) kept: Vec<bool>,
    /// The values of the curves it lies between; its points there are on them.
    pub(super) ends: [f64; 2],
}

/// How [`strips_ridged`](super::cover::strips_ridged) covers the surface.
#[derive(Clone, Copy)]
pub(super) struct CoverSettings {
    /// The field is a distance from rims, its saddles ridges
    /// ([`field_of`](super::field::field_of)).
    pub(super) ridged: bool,
    /// The distance a strip may lie from its part, at any point.
    pub(super) within: f64,
    /// Each curve keeps the fewest points within this of it.
    pub(super) simplify: f64,
    /// Samples for measuring lie no further apart than this.
    pub(super) spacing: f64,
    /// Bands longer than this are cut into sectors before they are split.
    pub(super) sector_length: f64,
    /// The field's span over the whole surface.
    pub(super) span: f64,
    /// Where a strip that may fold runs back over its own triangles, it is found out.
    pub(super) runs_back: RunsBack,
}

/// Where a strip allowed to fold (round a saddle or a ridge) running back over its own
/// triangles is found out: such a strip cannot be welded to its neighbours.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum RunsBack {
    /// When its band's strips are welded: a band cut into sectors is then cut into
    /// longer ones, which mends more of them than splitting them narrower does.
    Welded,
    /// When it is made: its part of the surface is split as if it strayed.
    Made,
}
