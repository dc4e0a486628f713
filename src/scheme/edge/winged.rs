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

use super::flaps::{
    band, band_defaults, corner_half_edges, place_pins, BandArgs, EdgeOptions, FaceFlaps,
    EDGE_DEFAULTS,
};
use super::panels::{edge_scheme, WidenFor};
use crate::mesh::{FaceId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::record::Params;
use crate::scheme::{
    args_of, Configured, Configuring, OptionValues, PanelOptions, Scheme, SchemeInfo,
};
use crate::scheme::{SchemeError, SchemeOutput};

/// The winged-edge scheme: quad-edge panels with wings along the neighbouring edges.
pub struct WingedEdge;

/// `--shift`: a half-length wing on each side.
const SHIFT: i32 = 0;

/// The winged-edge options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct WingedEdgeArgs {
    #[command(flatten)]
    band: BandArgs,

    /// Wings: 0 = a half-length wing on each side, 1 = one full-length wing over the
    /// next edge's flap, -1 = over the previous edge's.
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

const INFO: SchemeInfo = SchemeInfo {
    name: "winged-edge",
    about: "quad-edge panels with wings along the neighbouring face edges",
    defaults: EDGE_DEFAULTS,
    // As quad-edge: flaps and wings follow the neighbouring band edges.
    needs_convex_faces: true,
    overlap_fix: "a smaller --flap-scale",
};

impl Scheme for WingedEdge {
    fn info(&self) -> &SchemeInfo {
        &INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        let mut defaults = band_defaults().to_vec();
        defaults.push(OptionDefault::value("shift", SHIFT));
        state_defaults(args_of::<WingedEdgeArgs>(), &defaults)
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        Ok(Box::new(resolve(values, panel)?))
    }
}

/// Checks the winged-edge options' `values` and fills in their defaults.
fn resolve(values: &OptionValues, panel: PanelOptions) -> Result<WingedEdgeOptions, String> {
    let args: WingedEdgeArgs = values.parse()?;
    let shift = args.shift.unwrap_or(SHIFT);
    if !(-1..=1).contains(&shift) {
        return Err(format!("--shift: {shift} must be -1, 0 or 1"));
    }
    let edge = args.band.resolve(panel)?;
    if shift != 0 && edge.sandwich.is_some() {
        // A full wing covers the whole of the next sector, so in one of the two
        // layers a flap would keep only its wing, which hangs on nothing.
        return Err(format!("--shift {shift}: in the two-layer sandwich (--layers 2) the wings lap only as half wings; leave --shift at 0"));
    }
    Ok(WingedEdgeOptions { edge, shift })
}

impl Configured for WingedEdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.edge.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        panels(mesh, self)
    }

    fn params(&self) -> Params {
        let mut params = self.edge.params();
        params.push("shift", self.shift);
        params
    }
}

/// Builds the winged edge panels of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &WingedEdgeOptions) -> Result<SchemeOutput, SchemeError> {
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
        parts.push_flap(r.iter().map(|&q| frame.lift(q)));
    }
    for k in 0..n {
        parts.set_corner_label(k, frame.lift(0.5 * (at(k) + inner(k))));
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
            parts.add_hole([*e1, *e2], frame.lift(pin), connection);
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

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::build::two_triangles;
    use crate::scheme::assert_points;

    /// Face 1 of [`two_triangles`] stood up at a right angle to face 0, as in the
    /// quad-edge tests: its band is face 0's (15,−5,0), (30,−20,0), (45,−5,0) about the
    /// centre (30,−10,0), with y turned into −z.
    const FOLDED: DVec3 = DVec3::new(30.0, 0.0, 30.0);

    /// Winged-edge options at face scale 0.5, bridge scale 0.5, 4 bend strips, flaps
    /// and wings 0.5 deep, `holes` 1 mm holes with 0.5 mm of margin per shared region.
    fn options(holes: u32, shift: i32) -> WingedEdgeOptions {
        WingedEdgeOptions {
            edge: EdgeOptions {
                panel: PanelOptions {
                    face_scale: 0.5,
                    holes,
                    hole_diameter: 1.0,
                    hole_margin: 0.5,
                    label_height: 2.0,
                    panel_limit: None,
                    scale: 1.0,
                },
                bridge_scale: 0.5,
                flap_scale: 0.5,
                samples: 4,
                deep_flaps: true,
                sandwich: None,
            },
            shift,
        }
    }

    /// Face 0's flaps and wings at `--flap-scale` 0.5.
    fn face_0(holes: u32, shift: i32) -> FaceFlaps {
        let options = options(holes, shift);
        face_flaps_at(&two_triangles(FOLDED), FaceId(0), &options.edge, shift, 0.5)
    }

    /// The centres and connections of the holes through flap `k`.
    fn holes(flaps: &FaceFlaps, k: usize) -> (Vec<DVec3>, Vec<u32>) {
        flaps.flap_holes(k).unzip()
    }

    #[test]
    fn half_wings_reach_the_middle_of_both_neighbouring_edges() {
        let flaps = face_0(0, 0);
        // The inner polygon is the band halved about the centre: I0 = (22.5,−7.5),
        // I1 = (30,−15), I2 = (37.5,−7.5). Edge 2's main flap B2, B0, I0, I2 has sides
        // toward the centre (where quad-edge's run along the band edges to (17.5,−7.5)
        // and (42.5,−7.5)); its wings cover half of each neighbouring sector, out to
        // the band edges' middles (22.5,−12.5) and (37.5,−12.5).
        assert_points(
            flaps.flap_rest(2),
            &[
                [22.5, -12.5, 0.0],
                [26.25, -11.25, 0.0],
                [22.5, -7.5, 0.0],
                [37.5, -7.5, 0.0],
                [33.75, -11.25, 0.0],
                [37.5, -12.5, 0.0],
            ],
        );
        // Each corner's mark lies halfway between its band corner and inner corner.
        assert_points(&[flaps.corner_label(0)], &[[18.75, -6.25, 0.0]]);
    }

    #[test]
    fn a_full_wing_covers_the_next_or_the_previous_sector() {
        // Shift 1: edge 2's wing covers all of sector 0 (B0, B1, I1, I0), out to B1.
        assert_points(
            face_0(0, 1).flap_rest(2),
            &[
                [30.0, -20.0, 0.0],
                [30.0, -15.0, 0.0],
                [22.5, -7.5, 0.0],
                [37.5, -7.5, 0.0],
            ],
        );
        // Shift −1: all of sector 1 (B1, B2, I2, I1), reached from the other side.
        assert_points(
            face_0(0, -1).flap_rest(2),
            &[
                [22.5, -7.5, 0.0],
                [37.5, -7.5, 0.0],
                [30.0, -15.0, 0.0],
                [30.0, -20.0, 0.0],
            ],
        );
    }

    #[test]
    fn half_wings_give_a_corner_two_shared_regions_and_twice_the_holes() {
        let flaps = face_0(1, 0);
        // Corner 0's regions: (30,−5), B0, I0, (30,−7.5) centred at (24.375,−6.25),
        // 1.25 mm from y = −5 and y = −7.5; and B0, (22.5,−12.5), (26.25,−11.25), I0
        // centred at (21.5625,−9.0625), 1.77 mm from x + y = 10 and x + y = 15. Corner 2's
        // are their mirror images in x = 30. Flap 2 carries all four (connections 0
        // and 4), where quad-edge's carries one per corner.
        let (centres, connections) = holes(&flaps, 2);
        assert_points(
            &centres,
            &[
                [24.375, -6.25, 0.0],
                [21.5625, -9.0625, 0.0],
                [38.4375, -9.0625, 0.0],
                [35.625, -6.25, 0.0],
            ],
        );
        assert_eq!(connections, [0, 0, 4, 4]);
        assert_eq!((flaps.reduced, flaps.bare.len()), (0, 0));
    }

    #[test]
    fn a_full_wing_gives_a_corner_one_shared_region() {
        let flaps = face_0(1, 1);
        // Corner 0's region is sector 0, B0, B1, I1, I0, centred at (24.375,−11.875);
        // corner 2's is sector 2, B2, B0, I0, I2, centred at (30,−6.25).
        let (centres, connections) = holes(&flaps, 2);
        assert_points(&centres, &[[24.375, -11.875, 0.0], [30.0, -6.25, 0.0]]);
        assert_eq!(connections, [0, 4]);
    }

    #[test]
    fn the_hinge_panel_has_the_quad_edge_bend_and_winged_flaps() {
        let out = panels(&two_triangles(FOLDED), &options(1, 0)).expect("single panels build");
        // A panel per edge, a connection per face corner, as quad-edge.
        assert_eq!((out.panels.len(), out.connections), (5, 6));
        let panel = out.panels.get(2);
        assert_eq!(panel.id().to_string(), "E2");
        // 2·5 rail points, then 6 points for each flap; 1 + 4 + 1 facets.
        assert_eq!((panel.vertices.len(), panel.facets.len()), (22, 6));
        // The bend's middle ruling, as quad-edge's: (x, −5/4, 5/4) for x = 45, 15.
        assert_points(
            &panel.vertices[4..6],
            &[[45.0, -1.25, 1.25], [15.0, -1.25, 1.25]],
        );
        // Four holes per flap (two regions at each of two corners), eight in all.
        let per_facet: Vec<u32> = panel.holes.iter().map(|h| h.facet).collect();
        assert_eq!(per_facet, [0, 0, 0, 0, 5, 5, 5, 5]);
    }

    #[test]
    fn shift_is_one_of_minus_one_zero_and_one() {
        let panel = options(2, 0).edge.panel;
        let with_shift = |text: &str| {
            let mut values = OptionValues::default();
            values.set("shift", text);
            resolve(&values, panel.clone())
        };
        assert_eq!(
            with_shift("2").unwrap_err(),
            "--shift: 2 must be -1, 0 or 1"
        );
        assert_eq!(with_shift("-1").map(|o| o.shift), Ok(-1));
    }
}
