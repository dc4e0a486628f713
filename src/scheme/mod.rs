//! Panel schemes: each takes a read-only mesh (in millimetres) and its options and
//! returns 3D panels with provenance. A scheme knows nothing of sheets or files.
//!
//! Adding a scheme: one file here and one arm in [`build_panels`].

pub mod edge_panel;
pub mod half_edge;
pub mod quad_edge;
pub mod winged_edge;

use glam::DVec3;

use crate::config::SchemeName;
use crate::mesh::{FaceId, Mesh};
use crate::panel::Panel;

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
}

/// What a scheme produced.
#[derive(Clone, Debug, Default)]
pub struct SchemeOutput {
    /// The panels, in a deterministic order.
    pub panels: Vec<Panel>,
    /// Number of connections (links between two panels).
    pub connections: usize,
    /// Observations for the report (tabs shortened or left out, holes skipped).
    pub notes: Vec<String>,
}

/// Errors a scheme reports (options it cannot honour).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SchemeError {
    /// The scheme exists in the command line but not yet in the tool.
    #[error("the {0} scheme is not implemented yet in this version; use --scheme half-edge, quad-edge or winged-edge")]
    NotImplemented(SchemeName),
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
        other => Err(SchemeError::NotImplemented(other)),
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
