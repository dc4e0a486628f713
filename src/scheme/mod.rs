//! Panel schemes: each takes a read-only mesh (in millimetres) and its options and
//! returns 3D panels with provenance. A scheme knows nothing of sheets or files.
//!
//! Adding a scheme: one file here and one arm in [`build_panels`].

pub mod edge_panel;
pub mod half_edge;
pub mod quad_edge;
pub mod winged_edge;
pub mod woven;

use glam::DVec3;

use crate::config::SchemeName;
use crate::mesh::{FaceId, Mesh};
use crate::panel::Panels;

/// Options shared by the schemes (lengths in mm, fractions as fractions).
#[derive(Clone, Debug, PartialEq)]
pub struct SchemeOptions {
    /// Face band scale `s`: corners move toward the face centre, `s·v + (1−s)·c`.
    pub face_scale: f64,
    /// Edge band control points `b·v + (1−b)·m` (quad-edge).
    pub bridge_scale: f64,
    /// Flap inner line at this fraction toward the face centre (quad-edge).
    pub flap_scale: f64,
    /// Strips of the Bézier bend (quad-edge).
    pub samples: u32,
    /// Winged-edge wings: 0 both half-length, 1 one full-length wing on the next edge,
    /// −1 on the previous edge.
    pub shift: i32,
    /// Tabs on interior edges (half-edge scheme).
    pub tabs: bool,
    /// Wanted height of a tab's overlap with its neighbour (mm).
    pub tab_height: f64,
    /// Fastener holes per connection.
    pub holes: u32,
    /// Hole diameter (mm).
    pub hole_diameter: f64,
    /// Wanted label cap height (mm).
    pub label_height: f64,
    /// Strand width as a fraction of the band side (woven).
    pub band_scale: f64,
    /// Material thickness (mm): woven strands cross this far apart.
    pub thickness: f64,
    /// A woven segment's convex hull is at most this many times its area: curling
    /// ribbons are cut into pieces that nest.
    pub curl_limit: f64,
    /// The largest panel the layout can take; schemes that can cut long panels
    /// (woven ribbons) cut them to fit. `None`: no limit.
    pub panel_limit: Option<PanelLimit>,
}

/// The largest panel a sheet takes: its bounding box in one of `rotations` equal
/// rotation steps must fit `width` × `height` (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelLimit {
    /// Usable width (mm).
    pub width: f64,
    /// Usable height (mm).
    pub height: f64,
    /// Rotation steps allowed (360°/N each).
    pub rotations: u32,
}

/// What a scheme produced.
#[derive(Clone, Debug, Default)]
pub struct SchemeOutput {
    /// The panels, in a deterministic order.
    pub panels: Panels,
    /// Number of connections (links between two panels).
    pub connections: usize,
    /// Observations for the report (tabs shortened or left out, holes skipped).
    pub notes: Vec<String>,
    /// Woven cycles (empty for the other schemes).
    pub cycles: Vec<woven::CycleSummary>,
}

/// Errors a scheme reports (options it cannot honour).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SchemeError {
    /// The weave cannot be traced (a mesh with boundary).
    #[error("the woven scheme cannot weave this mesh: {0}; close the holes of the mesh or use another --scheme")]
    Weave(String),
    /// A ribbon piece larger than the largest panel the sheet takes.
    #[error("cycle {cycle}: one edge crossing of its ribbon is {size:.1} mm across and does not fit the sheet; use a larger --sheet or a smaller --size")]
    TooLarge { cycle: String, size: f64 },
}

impl SchemeError {
    /// True when the job's options are at fault (exit code 2); otherwise the model
    /// does not suit the scheme at this size.
    pub fn is_usage(&self) -> bool {
        matches!(self, SchemeError::Weave(_))
    }
}

/// True when the scheme needs convex faces (its flaps follow the neighbouring band
/// edges, which only bound a flap inside a convex face).
pub fn needs_convex_faces(name: SchemeName) -> bool {
    !matches!(name, SchemeName::HalfEdge)
}

/// Runs the named scheme.
pub fn build_panels(
    name: SchemeName,
    mesh: &Mesh,
    options: &SchemeOptions,
) -> Result<SchemeOutput, SchemeError> {
    match name {
        SchemeName::HalfEdge => Ok(half_edge::panels(mesh, options)),
        SchemeName::QuadEdge => Ok(quad_edge::panels(mesh, options)),
        SchemeName::WingedEdge => Ok(winged_edge::panels(mesh, options)),
        SchemeName::Woven => woven::panels(mesh, options),
    }
}

/// The face band of a face: each corner moved toward the face centre,
/// `s·v + (1−s)·c` (thesis: "face centre" = average of the corners).
pub fn face_band(mesh: &Mesh, f: FaceId, s: f64) -> Vec<DVec3> {
    let c = mesh.face_centre(f);
    mesh.face_positions(f)
        .map(|v| s * v + (1.0 - s) * c)
        .collect()
}
