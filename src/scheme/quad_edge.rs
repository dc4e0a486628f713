//! The quad-edge scheme (thesis ch. 4.2): one panel per edge. For an interior edge
//! (v, v′) between faces f and f′ the panel is
//!
//! - a flap in f's plane: the strip of f's face band between the band edge and an inner
//!   line (the band corners moved `F` toward the face centre), its sides along the
//!   neighbouring band edges;
//! - a bend: the Bézier surface whose rails are the quadratic curves
//!   `f-band(v) → b·v + (1−b)·m → f′-band(v)` and the same at v′, sampled at the same
//!   `t = k/n` on both rails. All three control pairs are parallel to the edge, so every
//!   ruling is too and each strip between two rulings is a planar trapezoid: the bend is
//!   exactly developable;
//! - a flap in f′'s plane.
//!
//! At every face corner (f, v) the flaps of the two edges meeting there overlap; that
//! overlap is the connection between the two panels, and its fastener holes are placed
//! once, in f's plane, so both panels carry them at the same 3D points. A boundary edge's
//! panel is its one flap. The bend and the panel assembly live in
//! [`super::edge_panel`], shared with the winged-edge scheme.

use glam::DVec2;

use super::edge_panel::{
    band, corner_half_edges, edge_scheme, place_pins, BandArgs, EdgeOptions, FaceFlaps,
    EDGE_DEFAULTS,
};
use super::{args_of, Configured, OptionValues, PanelDefaults, PanelOptions, Scheme};
use super::{SchemeError, SchemeOutput};
use crate::mesh::{FaceId, Mesh};
use crate::plane::clip_half_plane;
use crate::record::Params;

pub use super::edge_panel::panel_id;

/// The quad-edge scheme: one panel per edge, joined at face corners.
pub struct QuadEdge;

impl Scheme for QuadEdge {
    fn name(&self) -> &'static str {
        "quad-edge"
    }

    fn about(&self) -> &'static str {
        "one panel per edge: Bézier edge bands with flaps, joined at face corners"
    }

    fn options(&self) -> Vec<clap::Arg> {
        args_of::<BandArgs>()
    }

    fn defaults(&self) -> PanelDefaults {
        EDGE_DEFAULTS
    }

    fn needs_convex_faces(&self) -> bool {
        // The flaps follow the neighbouring band edges, which bound a flap only inside
        // a convex face.
        true
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        Ok(Box::new(values.parse::<BandArgs>()?.resolve(panel)?))
    }
}

impl Configured for EdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        Ok(panels(mesh, self))
    }

    fn params(&self) -> Params {
        EdgeOptions::params(self)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// Builds the edge panels of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &EdgeOptions) -> SchemeOutput {
    edge_scheme(mesh, options, face_flaps)
}

/// Band, flaps and corner overlaps of one face, computed in its plane.
fn face_flaps(mesh: &Mesh, f: FaceId, options: &EdgeOptions) -> FaceFlaps {
    let (band3, b, frame) = band(mesh, f, options);
    let n = b.len();
    let half_edges = corner_half_edges(mesh, f);
    let flap = options.flap_scale;
    // Inner line of band edge k, directed like the edge, through the band corners moved
    // toward the centre (the frame's origin). The flap is the band clipped to the strip
    // between its edge and that line: the same as running its sides along the
    // neighbouring band edges, and it never leaves the band when a neighbouring edge is
    // nearly parallel (sliver triangles).
    let inner_line = |k: usize| ((1.0 - flap) * b[k], (1.0 - flap) * b[(k + 1) % n]);
    let flaps: Vec<Vec<DVec2>> = (0..n)
        .map(|k| {
            let (p, q) = inner_line(k);
            // Left of q → p is between the edge and the inner line.
            let clipped = clip_half_plane(&b, q, p);
            // Start the loop at B_k, B_k+1 (both kept exactly by the clip).
            let start = clipped.iter().position(|&x| x == b[k]).unwrap_or(0);
            (0..clipped.len())
                .map(|i| clipped[(start + i) % clipped.len()])
                .collect()
        })
        .collect();

    let mut parts = FaceFlaps::new(&band3, flaps.iter().map(|f| f.len() - 2).sum());
    for flap in &flaps {
        parts.push_flap(flap.iter().skip(2).map(|&q| frame.to3(q)));
    }
    for k in 0..n {
        let prev = (k + n - 1) % n;
        // The overlap at corner k: the previous edge's flap clipped by this edge's strip.
        let (p, q) = inner_line(k);
        let overlap = clip_half_plane(&flaps[prev], q, p);
        let centre = if overlap.is_empty() {
            b[k]
        } else {
            overlap.iter().copied().sum::<DVec2>() / overlap.len() as f64
        };
        parts.set_corner_label(k, frame.to3(centre));
        // Pins along the line from the corner through the overlap's centre.
        let (pins, fewer) = place_pins(
            &overlap,
            centre,
            centre - b[k],
            options.panel.holes,
            options.panel.hole_diameter,
        );
        parts.reduced += fewer as usize;
        parts.bare += (options.panel.holes > 0 && pins.is_empty()) as usize;
        // The connection at corner k is named by the half-edge leaving it; both flaps
        // meeting there carry its holes.
        let connection = half_edges[k].0;
        for pin in pins {
            parts.add_hole([prev, k], frame.to3(pin), connection);
        }
    }
    parts.shrink_to_fit();
    parts
}
