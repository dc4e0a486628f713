//! The winged-edge scheme (thesis ch. 4.3): quad-edge panels whose flaps have parallel
//! sides and carry wings along the neighbouring face edges.
//!
//! In a face, band edge k owns the sector R_k of the ring between the band and the
//! inner polygon (the band corners moved `F` toward the centre): B_k, B_k+1, I_k+1, I_k.
//! Its main flap is R_k. Wings cover neighbouring sectors:
//!
//! - `--shift 0`: half of R_k+1 next to corner k+1 and half of R_k−1 next to corner k;
//! - `--shift 1`: all of R_k+1; `--shift -1`: all of R_k−1.
//!
//! Every sector is then covered by exactly two panels (its owner's main flap and a
//! neighbour's wing), and each such shared region is part of the connection at the face
//! corner it touches; its holes go through both panels at the same 3D points. With
//! shift 0 a corner has two shared regions (2 × holes per connection), with ±1 one.

use glam::DVec2;

use super::edge_panel::{
    band, corner_half_edges, edge_scheme, place_pins, BandArgs, EdgeOptions, FaceFlaps, WidenFor,
    EDGE_DEFAULTS,
};
use super::{args_of, Configured, OptionValues, PanelDefaults, PanelOptions, Scheme};
use super::{SchemeError, SchemeOutput};
use crate::mesh::{FaceId, Mesh};
use crate::record::Params;

/// The winged-edge scheme: quad-edge panels with wings along the neighbouring edges.
pub struct WingedEdge;

/// The winged-edge options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct WingedEdgeArgs {
    #[command(flatten)]
    band: BandArgs,

    /// Wings: 0 = a half-length wing on each side, 1 = one full-length wing over the
    /// next edge's flap, -1 = over the previous edge's. [default: 0]
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    shift: Option<i32>,
}

/// The winged-edge scheme's options, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct WingedEdgeOptions {
    /// The edge band and the shared options.
    pub edge: EdgeOptions,
    /// 0: both wings half-length; 1: one full-length wing on the next edge; −1 on the
    /// previous edge.
    pub shift: i32,
}

impl Scheme for WingedEdge {
    fn name(&self) -> &'static str {
        "winged-edge"
    }

    fn about(&self) -> &'static str {
        "quad-edge panels with wings along the neighbouring face edges"
    }

    fn options(&self) -> Vec<clap::Arg> {
        args_of::<WingedEdgeArgs>()
    }

    fn defaults(&self) -> PanelDefaults {
        EDGE_DEFAULTS
    }

    fn needs_convex_faces(&self) -> bool {
        // As quad-edge: flaps and wings follow the neighbouring band edges.
        true
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --flap-scale"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: WingedEdgeArgs = values.parse()?;
        let shift = args.shift.unwrap_or(0);
        if !(-1..=1).contains(&shift) {
            return Err(format!("--shift: {shift} must be -1, 0 or 1"));
        }
        Ok(Box::new(WingedEdgeOptions {
            edge: args.band.resolve(panel)?,
            shift,
        }))
    }
}

impl Configured for WingedEdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.edge.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        Ok(panels(mesh, self))
    }

    fn params(&self) -> Params {
        let mut params = self.edge.params();
        params.push("shift", self.shift);
        params
    }
}

/// Builds the winged edge panels of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &WingedEdgeOptions) -> SchemeOutput {
    let shift = options.shift;
    // Where a corner holds no hole, the face's band widens as in quad-edge (the
    // wings do not grow); not for fewer holes than wanted, which the two shared
    // regions of a corner usually are, and wider bands there cost sheets.
    edge_scheme(mesh, &options.edge, WidenFor::Bare, |mesh, f, edge| {
        face_flaps(mesh, f, edge, shift)
    })
}

/// The deepest the flaps and wings of a face grow, as a fraction of the way from the
/// band to the face centre: the inner polygon keeps a little of the face round the
/// centre, so the sectors stay four-sided.
const MAX_FLAP_SCALE: f64 = 0.9;

/// Steps from `--flap-scale` to [`MAX_FLAP_SCALE`] tried for a face whose corners hold
/// fewer holes than wanted.
const FLAP_STEPS: u32 = 8;

/// A face's flaps and wings at `--flap-scale`, or, where its corners hold fewer holes
/// than wanted there, at the shallowest deeper scale that holds the most (the face's
/// sectors all grow together, so they still tile the ring between band and inner
/// polygon).
fn face_flaps(mesh: &Mesh, f: FaceId, options: &EdgeOptions, shift: i32) -> FaceFlaps {
    let shortfall = |flaps: &FaceFlaps| (flaps.bare.len(), flaps.reduced);
    let mut best = face_flaps_at(mesh, f, options, shift, options.flap_scale);
    let from = options.flap_scale;
    for i in 1..=FLAP_STEPS {
        if shortfall(&best) == (0, 0) || from >= MAX_FLAP_SCALE {
            break;
        }
        let depth = from + (MAX_FLAP_SCALE - from) * f64::from(i) / f64::from(FLAP_STEPS);
        let mut tried = face_flaps_at(mesh, f, options, shift, depth);
        if shortfall(&tried) < shortfall(&best) {
            tried.grown = tried.corners();
            best = tried;
        }
    }
    best
}

/// A face's flaps and wings with the inner polygon at `flap_scale`.
fn face_flaps_at(
    mesh: &Mesh,
    f: FaceId,
    options: &EdgeOptions,
    shift: i32,
    flap_scale: f64,
) -> FaceFlaps {
    let (band3, b, frame) = band(mesh, f, options);
    let n = b.len();
    let half_edges = corner_half_edges(mesh, f);
    let at = |k: usize| b[k % n];
    // Inner corners (the centre is the frame's origin) and edge midpoints.
    let inner = |k: usize| (1.0 - flap_scale) * at(k);
    let mid = |k: usize| 0.5 * (at(k) + at(k + 1));
    let inner_mid = |k: usize| 0.5 * (inner(k) + inner(k + 1));

    // The flap outline of edge k after B_k, B_k+1 (counter-clockwise).
    let rest: Vec<Vec<DVec2>> = (0..n)
        .map(|k| match shift {
            0 => vec![
                mid(k + 1),
                inner_mid(k + 1),
                inner(k + 1),
                inner(k),
                inner_mid(k + n - 1),
                mid(k + n - 1),
            ],
            s if s > 0 => vec![at(k + 2), inner(k + 2), inner(k + 1), inner(k)],
            _ => vec![inner(k + 1), inner(k), inner(k + n - 1), at(k + n - 1)],
        })
        .collect();

    // Shared regions, each with the corner (connection) it belongs to, and the two
    // band edges whose flaps cover it.
    let sector = |k: usize| vec![at(k), at(k + 1), inner(k + 1), inner(k)];
    let mut shared: Vec<(usize, [usize; 2], Vec<DVec2>)> = Vec::new();
    for k in 0..n {
        let prev = (k + n - 1) % n;
        match shift {
            0 => {
                // Half of R_prev next to corner k, and half of R_k next to corner k.
                shared.push((
                    k,
                    [prev, k],
                    vec![mid(prev), at(k), inner(k), inner_mid(prev)],
                ));
                shared.push((k, [prev, k], vec![at(k), mid(k), inner_mid(k), inner(k)]));
            }
            // Edge prev's wing covers all of R_k.
            s if s > 0 => shared.push((k, [prev, k], sector(k))),
            // Edge k's wing covers all of R_prev.
            _ => shared.push((k, [prev, k], sector(prev))),
        }
    }

    let mut parts = FaceFlaps::new(&band3, rest.iter().map(Vec::len).sum());
    for r in &rest {
        parts.push_flap(r.iter().map(|&q| frame.to3(q)));
    }
    for k in 0..n {
        parts.set_corner_label(k, frame.to3(0.5 * (at(k) + inner(k))));
    }
    let mut placed_at_corner = vec![0usize; n];
    let mut short_at_corner = vec![false; n];
    for (corner, [e1, e2], region) in &shared {
        let centre = region.iter().copied().sum::<DVec2>() / region.len() as f64;
        // Pins along the band edge the region lies on.
        let along = region[1] - region[0];
        let (pins, fewer) = place_pins(region, centre, along, options.panel.holes, &options.panel);
        short_at_corner[*corner] |= fewer;
        placed_at_corner[*corner] += pins.len();
        let connection = half_edges[*corner].0;
        for pin in pins {
            parts.add_hole([*e1, *e2], frame.to3(pin), connection);
        }
    }
    if options.panel.holes > 0 {
        parts.bare = (0..n)
            .filter(|&k| placed_at_corner[k] == 0)
            .map(|k| half_edges[k])
            .collect();
    }
    // A bare corner is short of holes too (the notes count the short ones with at
    // least one hole as `reduced - bare`).
    parts.reduced = (0..n)
        .filter(|&k| short_at_corner[k] || (options.panel.holes > 0 && placed_at_corner[k] == 0))
        .count();
    parts.shrink_to_fit();
    parts
}
