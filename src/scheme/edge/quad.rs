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
//! panel is its one flap. The bend and the panel assembly live in [`super::flaps`] and
//! [`super::panels`], shared with the winged-edge scheme.

use glam::DVec2;

use super::flaps::{
    band, band_defaults, corner_half_edges, notch_flap, place_pins, BandArgs, EdgeOptions,
    FaceFlaps, EDGE_DEFAULTS,
};
use super::panels::{edge_scheme, WidenFor};
use crate::mesh::{FaceId, Mesh};
use crate::option_default::state_defaults;
use crate::plane::{clip_half_plane, contains, distance_to_border};
use crate::record::Params;
use crate::scheme::{
    args_of, Configured, Configuring, OptionValues, PanelOptions, Scheme, SchemeInfo,
};
use crate::scheme::{SchemeError, SchemeOutput};

pub use super::flaps::panel_id;

/// The quad-edge scheme: one panel per edge, joined at face corners.
pub struct QuadEdge;

const INFO: SchemeInfo = SchemeInfo {
    name: "quad-edge",
    about: "one panel per edge: Bézier edge bands with flaps, joined at face corners",
    defaults: EDGE_DEFAULTS,
    // The flaps follow the neighbouring band edges, which bound a flap only inside
    // a convex face.
    needs_convex_faces: true,
    overlap_fix: "a smaller --flap-scale",
};

impl Scheme for QuadEdge {
    fn info(&self) -> &SchemeInfo {
        &INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(args_of::<BandArgs>(), &band_defaults())
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        Ok(Box::new(values.parse::<BandArgs>()?.resolve(panel)?))
    }
}

impl Configured for EdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        panels(mesh, self)
    }

    fn params(&self) -> Params {
        EdgeOptions::params(self)
    }
}

/// Builds the edge panels of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &EdgeOptions) -> Result<SchemeOutput, SchemeError> {
    edge_scheme(mesh, options, WidenFor::Short, flaps_in_band)
}

/// The deepest a flap grows, in units of its band edge's distance from the face centre
/// (1 reaches the centre, 3 a triangle's far corner): beyond [`SHALLOW_FLAP_SCALE`], a
/// triangle's flaps cover the third flap's corners, and are notched round the pins
/// there.
pub const MAX_FLAP_SCALE: f64 = 2.5;

/// The deepest a flap grows without reaching a triangle's other corners, where a model
/// is too detailed for its fasteners (`EdgeOptions::deep_flaps` off).
pub const SHALLOW_FLAP_SCALE: f64 = 1.5;

/// The step in depth (same units) between the depths tried when a corner's overlap is
/// too small for its holes.
const FLAP_STEP: f64 = 1.0 / 16.0;

/// A face corner's plan: how deep its two flaps go, its label point and its pins.
#[derive(Clone)]
struct Corner {
    depth: f64,
    centre: DVec2,
    pins: Vec<DVec2>,
}

/// Band, flaps and corner overlaps of one face, computed in its plane. Each band edge's
/// flap starts at `--flap-scale`; where a corner's overlap cannot hold its holes, the
/// two flaps meeting there grow (to the smallest depth that holds the most holes that
/// fit by [`MAX_FLAP_SCALE`]), so every connection gets its fasteners where the face has
/// room for them; the scheme widens the band itself where corners still need room
/// ([`edge_scheme`]).
fn flaps_in_band(mesh: &Mesh, f: FaceId, options: &EdgeOptions) -> FaceFlaps {
    let (band3, b, frame) = band(mesh, f, options);
    let half_edges = corner_half_edges(mesh, f);
    let face = FlatBand::new(b, options);
    let corners = face.corners();
    let flaps = face
        .flaps_for(&corners)
        .expect("every step of `corners` kept flaps that can be cut");

    let (n, panel) = (face.b.len(), &options.panel);
    let mut parts = FaceFlaps::new(&band3, flaps.iter().map(|f| f.len() - 2).sum());
    for flap in &flaps {
        parts.push_flap(flap.iter().skip(2).map(|&q| frame.lift(q)));
    }
    for (k, corner) in corners.into_iter().enumerate() {
        let prev = (k + n - 1) % n;
        parts.set_corner_label(k, frame.lift(corner.centre));
        parts.grown += usize::from(corner.depth > options.flap_scale);
        let pins = corner.pins;
        parts.reduced += usize::from((pins.len() as u32) < panel.holes);
        // The connection at corner k is named by the half-edge leaving it; both flaps
        // meeting there carry its holes.
        if panel.holes > 0 && pins.is_empty() {
            parts.bare.push(half_edges[k]);
        }
        let connection = half_edges[k].0;
        for pin in pins {
            parts.add_hole([prev, k], frame.lift(pin), connection);
        }
    }
    parts.shrink_to_fit();
    parts
}

/// A face's band in its own plane (centre at the origin) with the flap depths its
/// corners may try, shallowest first.
struct FlatBand<'a> {
    /// Band corners.
    b: Vec<DVec2>,
    options: &'a EdgeOptions,
    /// From `--flap-scale` to the deepest allowed, in steps of [`FLAP_STEP`].
    depths: Vec<f64>,
}

impl<'a> FlatBand<'a> {
    fn new(b: Vec<DVec2>, options: &'a EdgeOptions) -> Self {
        let deepest = if options.deep_flaps {
            MAX_FLAP_SCALE
        } else {
            SHALLOW_FLAP_SCALE
        };
        let range = (deepest - options.flap_scale).max(0.0);
        let steps = (range / FLAP_STEP).ceil().max(1.0) as u32;
        let depths = (0..steps + 1)
            .map(|i| options.flap_scale + range * f64::from(i) / f64::from(steps))
            .collect();
        FlatBand { b, options, depths }
    }

    /// Inner line of band edge k at depth `depth`: parallel to the edge and directed
    /// like it, through band corner k moved `depth` of the way to the centre (beyond
    /// it for depths over 1). The flap is the band clipped to the strip between its
    /// edge and that line: the same as running its sides along the neighbouring band
    /// edges, and it never leaves the band when a neighbouring edge is nearly parallel
    /// (sliver triangles).
    fn inner_line(&self, k: usize, depth: f64) -> (DVec2, DVec2) {
        let b = &self.b;
        let p = (1.0 - depth) * b[k];
        (p, p + (b[(k + 1) % b.len()] - b[k]))
    }

    /// Band edge k's flap at `depth`, starting at B_k, B_k+1.
    fn flap_at(&self, k: usize, depth: f64) -> Vec<DVec2> {
        let (p, q) = self.inner_line(k, depth);
        // Left of q → p is between the edge and the inner line.
        let clipped = clip_half_plane(&self.b, q, p);
        // Start the loop at B_k, B_k+1 (both kept exactly by the clip).
        let start = clipped.iter().position(|&x| x == self.b[k]).unwrap_or(0);
        (0..clipped.len())
            .map(|i| clipped[(start + i) % clipped.len()])
            .collect()
    }

    /// The overlap at corner k with both flaps at `depth` (the previous edge's flap
    /// clipped by this edge's strip): its centre and the most pins, up to `wanted`,
    /// that it holds.
    fn corner_pins(&self, k: usize, depth: f64, wanted: u32) -> (DVec2, Vec<DVec2>) {
        let (b, n, panel) = (&self.b, self.b.len(), &self.options.panel);
        let prev = (k + n - 1) % n;
        let (p, q) = self.inner_line(k, depth);
        let overlap = clip_half_plane(&self.flap_at(prev, depth), q, p);
        let centre = if overlap.is_empty() {
            b[k]
        } else {
            overlap.iter().copied().sum::<DVec2>() / overlap.len() as f64
        };
        // At --flap-scale pins sit about the overlap's centre, with the most material
        // around them; in grown flaps, or where they do not fit there, they hug the
        // corner along its bisector, as near as the margins let them (far from the
        // face's other flaps, which grow too).
        let (e1, e2) = (
            (b[(k + 1) % n] - b[k]).normalize_or_zero(),
            (b[prev] - b[k]).normalize_or_zero(),
        );
        let u = (e1 + e2).normalize_or_zero();
        let sin_half = e1.perp_dot(u).abs().max(1e-6);
        let clear = 0.5 * panel.hole_diameter + panel.hole_margin;
        let hug = |pins: u32| {
            // The inner of two pins along the bisector is `hole_diameter` nearer the
            // corner than their centre (see `place_pins`).
            let offset = if pins >= 2 { panel.hole_diameter } else { 0.0 };
            b[k] + u * ((clear * 1.0001) / sin_half + offset)
        };
        let tries = if depth > self.options.flap_scale {
            [hug(wanted.min(2)), hug(1), centre]
        } else {
            [centre, hug(wanted.min(2)), hug(1)]
        };
        // Two pins lie along the bisector, or, in an overlap long along one of its
        // band edges (a thin face), about its centre along that edge.
        let tries = tries
            .into_iter()
            .map(|c| (c, u))
            .chain([(centre, e1), (centre, e2)]);
        let best = tries
            .map(|(c, along)| (c, place_pins(&overlap, c, along, wanted, panel).0))
            .fold((centre, Vec::new()), |best, tried| {
                // The first of the most wins ties.
                if tried.1.len() > best.1.len() {
                    tried
                } else {
                    best
                }
            });
        (centre, best.1)
    }

    /// Corner k's plan for `wanted` pins: the shallowest depth at which its two flaps
    /// hold them, with the pins (placed for that depth, they stay valid when the flaps
    /// grow deeper: only their inner lines move, away from the pins).
    fn plan(&self, k: usize, wanted: u32) -> Option<Corner> {
        self.depths.iter().find_map(|&depth| {
            let (centre, pins) = self.corner_pins(k, depth, wanted);
            (pins.len() as u32 >= wanted).then_some(Corner {
                depth,
                centre,
                pins,
            })
        })
    }

    /// Corner k with the shallowest flaps and no pins.
    fn bare_corner(&self, k: usize) -> Corner {
        let (centre, _) = self.corner_pins(k, self.depths[0], 0);
        Corner {
            depth: self.depths[0],
            centre,
            pins: Vec::new(),
        }
    }

    /// The flaps of a plan. A pin goes through the two flaps of its corner only: the
    /// face's other flaps, which grow too in small faces, must stay clear of it,
    /// notched round it where they would not (see `notch_flap`). `None` where a notch
    /// cannot be cut or would come too near a flap's own pins.
    fn flaps_for(&self, corners: &[Corner]) -> Option<Vec<Vec<DVec2>>> {
        let (n, panel) = (self.b.len(), &self.options.panel);
        let clear = 0.5 * panel.hole_diameter + panel.hole_margin;
        let apart = |pin: DVec2, flap: &[DVec2]| {
            !contains(flap, pin) && distance_to_border(flap, pin) >= clear
        };
        (0..n)
            .map(|j| {
                // A flap is as deep as the deeper of its two corners needs.
                let depth = corners[j].depth.max(corners[(j + 1) % n].depth);
                let flap = self.flap_at(j, depth);
                let own = [j, (j + 1) % n];
                let foreign: Vec<DVec2> = (0..n)
                    .filter(|k| !own.contains(k))
                    .flat_map(|k| corners[k].pins.iter().copied())
                    .filter(|&pin| !apart(pin, &flap))
                    .collect();
                if foreign.is_empty() {
                    return Some(flap);
                }
                let notched = notch_flap(&flap, &foreign, clear, panel.hole_margin)?;
                let holds_own = own.iter().flat_map(|&k| &corners[k].pins).all(|&pin| {
                    contains(&notched, pin) && distance_to_border(&notched, pin) >= clear
                });
                holds_own.then_some(notched)
            })
            .collect()
    }

    /// Every corner's plan. First one pin at every corner that can hold one, with the
    /// shallowest flaps; where those clash, corner by corner in order, each kept only
    /// if the flaps can still be cut with it (a corner left without keeps the
    /// shallowest flaps). Then corner by corner the wanted count, where the deeper
    /// flaps it takes still can.
    fn corners(&self) -> Vec<Corner> {
        let (n, holes) = (self.b.len(), self.options.panel.holes);
        let planned: Vec<Corner> = (0..n)
            .map(|k| {
                self.plan(k, holes.min(1))
                    .unwrap_or_else(|| self.bare_corner(k))
            })
            .collect();
        let mut corners = planned.clone();
        if self.flaps_for(&corners).is_none() {
            corners = (0..n).map(|k| self.bare_corner(k)).collect();
            for (k, corner) in planned.into_iter().enumerate() {
                let mut tried = corners.clone();
                tried[k] = corner;
                if self.flaps_for(&tried).is_some() {
                    corners = tried;
                }
            }
        }
        if holes > 1 {
            for k in 0..n {
                if let Some(full) = self.plan(k, holes) {
                    let mut tried = corners.clone();
                    tried[k] = full;
                    if self.flaps_for(&tried).is_some() {
                        corners = tried;
                    }
                }
            }
        }
        corners
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::build::{tetrahedron, two_triangles};
    use crate::scheme::assert_points;

    /// Face 1 of [`two_triangles`] stood up at a right angle to face 0: (0,0,0),
    /// (60,0,0), (30,0,30) in y = 0. Its band (face scale 0.5 about its centre
    /// (30,0,10)) is (15,0,5), (45,0,5), (30,0,20): face 0's band (15,−5,0),
    /// (30,−20,0), (45,−5,0) with y turned into −z.
    const FOLDED: DVec3 = DVec3::new(30.0, 0.0, 30.0);

    /// Edge options at face scale 0.5, bridge scale 0.5, 4 bend strips, flaps
    /// `flap_scale` deep, and `holes` 1 mm holes per corner with `hole_margin` mm of
    /// material round each.
    fn options(holes: u32, hole_margin: f64, flap_scale: f64) -> EdgeOptions {
        EdgeOptions {
            panel: PanelOptions {
                face_scale: 0.5,
                holes,
                hole_diameter: 1.0,
                hole_margin,
                label_height: 2.0,
                panel_limit: None,
                scale: 1.0,
            },
            bridge_scale: 0.5,
            flap_scale,
            samples: 4,
            deep_flaps: true,
            sandwich: None,
        }
    }

    /// A panel's facets as index lists.
    fn facets(panel: crate::panel::PanelRef<'_>) -> Vec<Vec<u32>> {
        panel.facets.iter().map(<[u32]>::to_vec).collect()
    }

    #[test]
    fn a_flap_runs_along_the_neighbouring_band_edges_to_its_inner_line() {
        let flaps = flaps_in_band(&two_triangles(FOLDED), FaceId(0), &options(0, 0.5, 0.5));
        // Face 0's centre is (30,−10,0); each corner moves halfway to it.
        assert_points(
            flaps.band(),
            &[[15.0, -5.0, 0.0], [30.0, -20.0, 0.0], [45.0, -5.0, 0.0]],
        );
        // Band edge 2 (y = −5) is 5 mm from the centre: its inner line lies 0.5·5 mm in,
        // at y = −7.5, where it meets the band edges x − y = 20 and x + y = 50.
        assert_points(flaps.flap_rest(2), &[[17.5, -7.5, 0.0], [42.5, -7.5, 0.0]]);
        // In a triangle the inner line at depth F is where the far corner's barycentric
        // weight is F/3 = 1/6: (5/6)·B1 + (1/6)·B2 and (1/6)·B2 + (5/6)·B0 for edge 0.
        assert_points(flaps.flap_rest(0), &[[32.5, -17.5, 0.0], [20.0, -5.0, 0.0]]);
        assert_eq!((flaps.grown, flaps.reduced, flaps.bare.len()), (0, 0, 0));
    }

    #[test]
    fn a_flap_of_scale_one_reaches_the_face_centre() {
        let flaps = flaps_in_band(&two_triangles(FOLDED), FaceId(0), &options(0, 0.5, 1.0));
        // The inner line of band edge 2 passes through the centre (30,−10,0): it meets
        // the band edges at (2/3)·B0 + (1/3)·B1 and (1/3)·B1 + (2/3)·B2.
        assert_points(
            flaps.flap_rest(2),
            &[[20.0, -10.0, 0.0], [40.0, -10.0, 0.0]],
        );
    }

    #[test]
    fn a_corner_pin_sits_at_the_middle_of_the_two_flaps_overlap() {
        let flaps = flaps_in_band(&two_triangles(FOLDED), FaceId(0), &options(1, 0.5, 0.5));
        // Corner 0's overlap is the parallelogram (15,−5), (20,−5), (22.5,−7.5),
        // (17.5,−7.5), centred at (18.75,−6.25): 1.25 mm from y = −5 and y = −7.5, more
        // than the 0.5 + 0.5 mm a hole needs. It goes through flaps 2 and 0 for
        // connection 0 (the half-edge leaving the corner); corner 2's mirror image at
        // x = 60 − 18.75 through flaps 1 and 2 for connection 4.
        let holes = |k: usize| flaps.flap_holes(k).collect::<Vec<_>>();
        let positions = |k: usize| holes(k).iter().map(|h| h.0).collect::<Vec<_>>();
        let connections = |k: usize| holes(k).iter().map(|h| h.1).collect::<Vec<_>>();
        assert_points(&positions(2), &[[18.75, -6.25, 0.0], [41.25, -6.25, 0.0]]);
        assert_eq!(connections(2), [0, 4]);
        assert_points(&positions(0)[..1], &[[18.75, -6.25, 0.0]]);
        assert_eq!((flaps.grown, flaps.reduced, flaps.bare.len()), (0, 0, 0));
    }

    #[test]
    fn a_corner_too_small_for_its_pin_grows_its_flaps_in_sixteenths() {
        // A 1 mm hole with 1 mm of margin needs 1.5 mm all round; the 45° corners'
        // overlaps at depth 0.5 are only 2.5 mm deep (1.25 mm from the middle).
        let flaps = flaps_in_band(&two_triangles(FOLDED), FaceId(0), &options(1, 1.0, 0.5));
        // Hugging corner 0 on its bisector (22.5° to y = −5), 1.5·1.0001 mm from both
        // band edges, the pin needs a strip 3.0002 mm deep: depth 0.6 of the 5 mm, so
        // 0.625, the first step of 1/16 past it. Both 45° corners grow; the right-angled
        // one holds its pin at depth 0.5 (1.77 mm from every side).
        assert_eq!((flaps.grown, flaps.reduced, flaps.bare.len()), (2, 0, 0));
        // Flap 2 is 0.625·5 = 3.125 mm deep, its inner line meeting the band edges at
        // (1 − 0.625/3)·B0 + (0.625/3)·B1 and the same from B2.
        assert_points(
            flaps.flap_rest(2),
            &[[18.125, -8.125, 0.0], [41.875, -8.125, 0.0]],
        );
        let clear = 1.5 * 1.0001;
        let reach = clear * (1.0 + 2f64.sqrt()); // clear / tan 22.5°
        let pin = flaps.flap_holes(2).next().unwrap().0;
        assert_points(&[pin], &[[15.0 + reach, -5.0 - clear, 0.0]]);
    }

    #[test]
    fn an_interior_edge_panel_is_a_flap_a_developable_bend_and_a_flap() {
        let out =
            panels(&two_triangles(FOLDED), &options(1, 0.5, 0.5)).expect("single panels build");
        let panel = out.panels.get(2);
        assert_eq!(panel.id().to_string(), "E2");
        // Rails at v1 and v0 from face 0's band corner through b·v + (1 − b)·m
        // (m = (30,0,0)) to face 1's: (x, −5(1 − t)², 5t²) for x = 45 and 15, at
        // t = 0, 1/4, 1/2, 3/4, 1; so every ruling is 30 mm, half the edge. Then each
        // flap's inner corners (face 1's: face 0's with y turned into −z).
        let mut expected = Vec::new();
        for i in 0..=4 {
            let t = f64::from(i) / 4.0;
            let (y, z) = (-5.0 * (1.0 - t) * (1.0 - t), 5.0 * t * t);
            expected.push([45.0, y, z]);
            expected.push([15.0, y, z]);
        }
        expected.extend([
            [17.5, -7.5, 0.0],
            [42.5, -7.5, 0.0],
            [42.5, 0.0, 7.5],
            [17.5, 0.0, 7.5],
        ]);
        assert_points(panel.vertices, &expected);
        assert_eq!(
            facets(panel),
            vec![
                vec![0, 1, 10, 11],
                vec![1, 0, 2, 3],
                vec![3, 2, 4, 5],
                vec![5, 4, 6, 7],
                vec![7, 6, 8, 9],
                vec![9, 8, 12, 13],
            ]
        );
        // Each flap carries the pins of both its corners: face 0's on facet 0 for
        // connections 0 and 4, face 1's on facet 5 for connections 5 and 6 (the
        // half-edges leaving (0,0,0) and (60,0,0) in face 1).
        let holes: Vec<(u32, u32)> = panel
            .holes
            .iter()
            .map(|h| (h.facet, h.connection))
            .collect();
        assert_eq!(holes, [(0, 0), (0, 4), (5, 5), (5, 6)]);
        let positions: Vec<DVec3> = panel.holes.iter().map(|h| h.position).collect();
        assert_points(
            &positions,
            &[
                [18.75, -6.25, 0.0],
                [41.25, -6.25, 0.0],
                [18.75, 0.0, 6.25],
                [41.25, 0.0, 6.25],
            ],
        );
    }

    #[test]
    fn a_boundary_edge_panel_is_its_one_flap_sharing_the_corner_pin() {
        let out =
            panels(&two_triangles(FOLDED), &options(1, 0.5, 0.5)).expect("single panels build");
        let panel = out.panels.get(0);
        assert_eq!(panel.id().to_string(), "E0");
        // Band edge 0 of face 0 and its flap's inner corners.
        assert_points(
            panel.vertices,
            &[
                [15.0, -5.0, 0.0],
                [30.0, -20.0, 0.0],
                [32.5, -17.5, 0.0],
                [20.0, -5.0, 0.0],
            ],
        );
        assert_eq!(facets(panel), vec![vec![0, 1, 2, 3]]);
        // Corner 0's pin, at the same point as on E2, for the same connection.
        let pin = &panel.holes[0];
        assert_points(&[pin.position], &[[18.75, -6.25, 0.0]]);
        assert_eq!(pin.connection, 0);
    }

    #[test]
    fn there_is_a_panel_per_edge_and_a_connection_per_face_corner() {
        let out =
            panels(&two_triangles(FOLDED), &options(1, 0.5, 0.5)).expect("single panels build");
        // 5 edges; 2 triangles have 6 corners.
        assert_eq!((out.panels.len(), out.connections), (5, 6));
        let ids: Vec<String> = out.panels.iter().map(|p| p.id().to_string()).collect();
        assert_eq!(ids, ["E0", "E1", "E2", "E3", "E4"]);
        assert_eq!(
            out.notes,
            ["4 boundary edges have a panel with a single flap and no bend"]
        );
        // The closed tetrahedron: 6 edges, 4 triangles of 3 corners, no note.
        let mut mesh = tetrahedron();
        mesh.scale(20.0);
        let out = panels(&mesh, &options(0, 0.5, 0.5)).expect("single panels build");
        assert_eq!((out.panels.len(), out.connections), (6, 12));
        assert!(out.notes.is_empty(), "{:?}", out.notes);
    }
}
