//! The edge schemes' shared parts of a panel: the band options, each face's flaps and
//! the frame they are drawn in, pin placement in an overlap (notching a flap round the
//! pins it would cover), the Bézier bend and the labels on flaps and bends.

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::OutlineStyle;

use crate::mesh::geometry::PlaneFrame;
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::OptionDefault;
use crate::panel::{Label, LabelKind, Loops, Name};
use crate::plane::{contains, distance_to_border};
use crate::record::Params;
use crate::scheme::kit::thickness::{thickness, thickness_default};
use crate::scheme::{face_band, PanelDefaults, PanelOptions};
use crate::units::fraction;

/// The edge schemes' defaults for the shared options: bands halfway to the face
/// centre leave room for the flaps, and two pins per corner keep a connection from
/// turning.
pub const EDGE_DEFAULTS: PanelDefaults = PanelDefaults {
    face_scale: 0.5,
    holes: 2,
    holes_allowed: &[0, 1, 2, 4],
};

/// `--bridge-scale`.
const BRIDGE_SCALE: f64 = 0.5;
/// `--flap-scale`.
const FLAP_SCALE: f64 = 0.5;
/// `--samples`.
const SAMPLES: u32 = 4;

/// `--layers`.
const LAYERS: u32 = 1;

/// The defaults of the band options, for the edge schemes' `options()`.
pub fn band_defaults() -> [OptionDefault; 5] {
    [
        OptionDefault::value("bridge-scale", BRIDGE_SCALE),
        OptionDefault::value("flap-scale", FLAP_SCALE),
        OptionDefault::value("samples", SAMPLES),
        thickness_default(),
        OptionDefault::value("layers", LAYERS),
    ]
}

/// The options of the edge band, shared by the edge schemes, as given.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct BandArgs {
    /// Edge band control points: b·v + (1−b)·m toward the edge midpoint m; smaller b
    /// makes the bend rounder.
    #[arg(long, value_name = "B")]
    pub bridge_scale: Option<f64>,

    /// Flap depth: the flap's inner line joins the band corners moved this fraction
    /// toward the face centre.
    #[arg(long, value_name = "F")]
    pub flap_scale: Option<f64>,

    /// Strips of the Bézier bend; every ruling between two strips is a score line.
    #[arg(long, value_name = "N")]
    pub samples: Option<u32>,

    /// Card thickness, with a unit, for `--layers 2`: the inner layer lies this far
    /// inside the outer one.
    #[arg(long, value_name = "LENGTH")]
    pub thickness: Option<String>,

    /// 1, or 2 for the two-layer sandwich: every panel cut twice, an outer and an
    /// inner layer glued into one shell, their flaps lapped at the face corners.
    #[arg(long, value_name = "N")]
    pub layers: Option<u32>,
}

impl BandArgs {
    /// Checks the values and fills in the defaults.
    pub fn resolve(&self, panel: PanelOptions) -> Result<EdgeOptions, String> {
        if panel.face_scale >= 1.0 {
            // The bend runs from the band to the edge and back: a band as large as
            // the face leaves it no width.
            return Err(format!(
                "--face-scale: the edge schemes' bends run between the face bands and the edges, so a band must be smaller than its face: below 1, not {} (default 0.5)",
                panel.face_scale
            ));
        }
        let samples = self.samples.unwrap_or(SAMPLES);
        if !(1..=64).contains(&samples) {
            return Err(format!("--samples: {samples} must be between 1 and 64"));
        }
        let thickness = thickness("thickness", self.thickness.as_deref(), "0mm", &panel)?;
        let sandwich = match (self.layers.unwrap_or(LAYERS), thickness > 0.0) {
            (1, false) => None,
            (2, true) => Some(thickness),
            (1, true) => return Err("--thickness: the edge schemes take a thickness for the two-layer sandwich; add --layers 2 (or leave --thickness out for single panels)".to_string()),
            (2, false) => return Err("--layers 2: the sandwich needs the card's --thickness (--thickness 0.5mm)".to_string()),
            (layers, _) => return Err(format!("--layers: {layers} must be 1 or 2")),
        };
        Ok(EdgeOptions {
            panel,
            bridge_scale: fraction("bridge-scale", self.bridge_scale, BRIDGE_SCALE)?,
            flap_scale: fraction("flap-scale", self.flap_scale, FLAP_SCALE)?,
            samples,
            deep_flaps: true,
            sandwich,
        })
    }
}

/// The options of the edge schemes, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Edge band control points `b·v + (1−b)·m`.
    pub bridge_scale: f64,
    /// Flap inner line at this fraction toward the face centre.
    pub flap_scale: f64,
    /// Strips of the Bézier bend.
    pub samples: u32,
    /// Whether flaps may grow past the face's other corners (notched round their
    /// pins); not for a model too detailed for its fasteners (see
    /// [`super::panels::edge_scheme`]).
    pub deep_flaps: bool,
    /// The two-layer sandwich's card thickness (mm), or `None` for single panels.
    pub sandwich: Option<f64>,
}

impl EdgeOptions {
    /// The band's parameters for the manifest.
    pub fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("bridge_scale", self.bridge_scale);
        params.push("flap_scale", self.flap_scale);
        params.push("samples", self.samples);
        if let Some(thickness) = self.sandwich {
            params.push("thickness", crate::record::round4(thickness));
            params.push("layers", 2);
        }
        params
    }
}

/// The id printed for an edge panel.
pub fn panel_id(e: EdgeId) -> Name {
    Name::edge(e.0)
}

/// One face's share of the edge panels, in 3D: the band, each band edge's flap outline,
/// the holes through each flap and where each corner's vertex id goes. A big job holds
/// one per face until every panel is built, so it keeps everything in three buffers
/// rather than a vector per flap.
#[derive(Clone, Debug)]
pub struct FaceFlaps {
    /// The band corners B_k (corner k at the origin of the face's k-th half-edge), then
    /// each corner's label point, then the rest of every flap, one after the other.
    points: Vec<DVec3>,
    /// Number of band corners.
    corners: usize,
    /// Where the rest of each flap ends in `points`.
    rest_ends: Vec<u32>,
    /// Holes as (centre, connection, flap), in the order they were added.
    holes: Vec<(DVec3, u32, u32)>,
    /// Connections (face corners) with fewer holes than wanted.
    pub reduced: usize,
    /// Connections with no hole at all although holes were wanted: the half-edge
    /// leaving each one's corner.
    pub bare: Vec<HalfedgeId>,
    /// Connections whose flaps grew deeper than `--flap-scale` to hold their holes.
    pub grown: usize,
    /// The band is wider than `--face-scale`, to hold holes at corners that could not.
    pub widened: bool,
}

impl FaceFlaps {
    /// A face with these band corners and no flaps yet, with room for `flap_points`
    /// points of flap outline in all: push one flap per band edge in order, and set
    /// every corner's label point (until then it is NaN, so a forgotten one shows).
    pub fn new(band: &[DVec3], flap_points: usize) -> Self {
        let n = band.len();
        let mut points = Vec::with_capacity(2 * n + flap_points);
        points.extend_from_slice(band);
        points.resize(2 * n, DVec3::NAN);
        FaceFlaps {
            points,
            corners: n,
            rest_ends: Vec::with_capacity(n),
            holes: Vec::new(),
            reduced: 0,
            bare: Vec::new(),
            grown: 0,
            widened: false,
        }
    }

    /// Number of band corners (and edges, and flaps).
    pub fn corners(&self) -> usize {
        self.corners
    }

    /// Band corners.
    pub fn band(&self) -> &[DVec3] {
        &self.points[..self.corners]
    }

    /// Appends the next flap's outline after B_k, B_k+1 (counter-clockwise).
    pub fn push_flap(&mut self, rest: impl IntoIterator<Item = DVec3>) {
        self.points.extend(rest);
        self.rest_ends.push(self.points.len() as u32);
    }

    /// Sets where corner `k`'s vertex id goes (between its pins).
    pub fn set_corner_label(&mut self, k: usize, p: DVec3) {
        self.points[self.corners + k] = p;
    }

    /// Where corner `k`'s vertex id goes.
    pub fn corner_label(&self, k: usize) -> DVec3 {
        self.points[self.corners + k]
    }

    /// Flap `k`'s outline after B_k, B_k+1.
    pub fn flap_rest(&self, k: usize) -> &[DVec3] {
        let start = if k == 0 {
            2 * self.corners
        } else {
            self.rest_ends[k - 1] as usize
        };
        &self.points[start..self.rest_ends[k] as usize]
    }

    /// A hole through both flaps meeting at a connection.
    pub fn add_hole(&mut self, flaps: [usize; 2], p: DVec3, connection: u32) {
        for flap in flaps {
            self.holes.push((p, connection, flap as u32));
        }
    }

    /// The holes through flap `k` with their connection ids.
    pub fn flap_holes(&self, k: usize) -> impl Iterator<Item = (DVec3, u32)> + '_ {
        self.holes
            .iter()
            .filter(move |h| h.2 as usize == k)
            .map(|h| (h.0, h.1))
    }

    /// Frees what no more flap or hole will use (a big job keeps one per face).
    pub fn shrink_to_fit(&mut self) {
        self.points.shrink_to_fit();
        self.holes.shrink_to_fit();
    }
}

/// The face band of `f` in 3D and in its frame. The band corners are projected onto
/// the face's plane (through its centre, normal to its vector area), so every flap is
/// an exactly planar facet and the holes of a corner lie on both flaps even when the
/// face is planar only within the tolerance; on a planar face nothing moves.
pub fn band(mesh: &Mesh, f: FaceId, options: &EdgeOptions) -> (Vec<DVec3>, Vec<DVec2>, PlaneFrame) {
    let frame = mesh.face_frame(f);
    let normal = frame.x.cross(frame.y);
    let band: Vec<DVec3> = face_band(mesh, f, options.panel.face_scale)
        .into_iter()
        .map(|p| p - (p - frame.origin).dot(normal) * normal)
        .collect();
    let flat = band.iter().map(|&p| frame.flat(p)).collect();
    (band, flat, frame)
}

/// The half-edges of a face in loop order (corner k is the origin of the k-th).
pub fn corner_half_edges(mesh: &Mesh, f: FaceId) -> Vec<HalfedgeId> {
    mesh.face_half_edges(f).collect()
}

/// Pin positions in an overlap: symmetric about `centre` along `along` (the overlap's
/// long direction) at the closest spacing that leaves one diameter of material between
/// pins (so heads twice the hole's size do not overlap), each with `margin` of
/// material to the overlap's border (every side of an overlap is a cut edge of one of
/// the two panels). When the wanted count does not fit, fewer pins (4 → 2 → 1 → 0).
/// Returns the centres and whether fewer than wanted were placed.
pub fn place_pins(
    overlap: &[DVec2],
    centre: DVec2,
    along: DVec2,
    wanted: u32,
    panel: &PanelOptions,
) -> (Vec<DVec2>, bool) {
    if wanted == 0 || overlap.len() < 3 {
        return (Vec::new(), wanted > 0);
    }
    let diameter = panel.hole_diameter;
    let r = 0.5 * diameter;
    let u = along.normalize_or_zero();
    let w = u.perp();
    let half = 0.5 * (2.0 * r + diameter);
    let fits = |pins: &[DVec2]| {
        pins.iter().all(|&p| {
            contains(overlap, p) && distance_to_border(overlap, p) >= r + panel.hole_margin
        })
    };
    for count in [4, 2, 1].into_iter().filter(|&c| c <= wanted) {
        let pins: Vec<DVec2> = match count {
            4 => vec![
                centre + half * (u + w),
                centre + half * (u - w),
                centre - half * (u + w),
                centre - half * (u - w),
            ],
            2 => vec![centre - half * u, centre + half * u],
            _ => vec![centre],
        };
        if fits(&pins) {
            return (pins, count < wanted);
        }
    }
    (Vec::new(), true)
}

/// The gap between two convex polygons (0 where they overlap).
fn polygon_gap(a: &[DVec2], b: &[DVec2]) -> f64 {
    if crate::plane::contains(a, b[0]) || crate::plane::contains(b, a[0]) {
        return 0.0;
    }
    let edges = |p: &[DVec2]| {
        (0..p.len())
            .map(|i| (p[i], p[(i + 1) % p.len()]))
            .collect::<Vec<_>>()
    };
    let (ea, eb) = (edges(a), edges(b));
    ea.iter()
        .flat_map(|&(p, q)| {
            eb.iter()
                .map(move |&(r, t)| crate::plane::segment_distance(p, q, r, t))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The least material (mm) a notch leaves between itself and a flap's fold.
const MIN_KEEP: f64 = 1e-3;

/// Sides of the polygon a notch runs round a pin with: the notch clears the pin by
/// its full distance everywhere, its corners a little more.
const NOTCH_SIDES: usize = 16;

/// Flap `flap` (convex, counter-clockwise, starting at the two ends of its fold) with a
/// notch round each of `pins`, the pins of other corners of its face that it would
/// otherwise cover or come within `clear` of. Each notch is the band of width
/// 2·`clear` from its pin straight away from the fold, round at the fold's end, so the
/// flap keeps one outline without holes; a tip that a notch cuts off no longer hangs on
/// the fold and is left out. `None` where a notch would come nearer the fold than
/// `keep` (the flap must stay whole along it), or the flap would hang on a neck
/// narrower than that.
pub fn notch_flap(flap: &[DVec2], pins: &[DVec2], clear: f64, keep: f64) -> Option<Vec<DVec2>> {
    // Even with no margin asked for, a notch must not touch the fold.
    let keep = keep.max(MIN_KEEP);

    let (fold_start, fold_end) = (flap[0], flap[1]);
    let inward = (fold_end - fold_start).perp().normalize_or_zero();
    let reach = 4.0
        * flap
            .iter()
            .map(|p| p.distance(fold_start))
            .fold(clear, f64::max);
    let radius = clear / (std::f64::consts::PI / NOTCH_SIDES as f64).cos();
    let mut notches: Vec<Vec<DVec2>> = Vec::with_capacity(pins.len());
    for &pin in pins {
        let round: Vec<DVec2> = (0..NOTCH_SIDES)
            .map(|i| {
                let angle = std::f64::consts::TAU * (i as f64 + 0.5) / NOTCH_SIDES as f64;
                pin + radius * DVec2::from_angle(angle)
            })
            .collect();
        let far: Vec<DVec2> = round.iter().map(|&p| p + reach * inward).collect();
        notches.push(crate::plane::convex_hull(&[round, far].concat()));
    }
    // Notches nearer each other than `keep` become one: the flap between them would be
    // a finger too thin to hold.
    let mut k = 0;
    while k < notches.len() {
        let near = (k + 1..notches.len()).find(|&j| polygon_gap(&notches[k], &notches[j]) < keep);
        match near {
            Some(j) => {
                let other = notches.swap_remove(j);
                notches[k] = crate::plane::convex_hull(&[notches[k].clone(), other].concat());
            }
            None => k += 1,
        }
    }
    for hull in &notches {
        let near_fold = (0..hull.len()).any(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            crate::plane::segment_distance(a, b, fold_start, fold_end) < keep
        });
        if near_fold || crate::plane::contains(hull, fold_start) {
            return None;
        }
    }
    let notches: Vec<Vec<[f64; 2]>> = notches
        .iter()
        .map(|hull| hull.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    let subject: Vec<[f64; 2]> = flap.iter().map(|p| [p.x, p.y]).collect();
    // OGC-valid: a flap that a notch nearly cuts through comes back as two pieces,
    // not one outline touching itself.
    let shapes = FloatOverlay::<[f64; 2], i64>::from_subj_and_clip_custom(
        &[subject],
        &notches,
        OverlayOptions::ogc(),
        Solver::default(),
    )
    .overlay(OverlayRule::Difference, FillRule::NonZero);
    // A notch may cut off the flap's tip beyond its pin: that piece no longer hangs on
    // the fold and is left out. The fold's two ends come back exactly, first, as the
    // flap's other loops have them.
    let tolerance = 1e-6 * (1.0 + reach);
    let at_fold = |contour: &Vec<[f64; 2]>| {
        contour
            .iter()
            .position(|&[x, y]| DVec2::new(x, y).distance(fold_start) <= tolerance)
    };
    let shape = shapes.iter().find(|shape| at_fold(&shape[0]).is_some())?;
    let [contour] = shape.as_slice() else {
        return None;
    };
    // Nor may a notch nearly cut through it: shrunk by half of `keep`, the flap stays
    // one piece, so no part of it hangs on a neck narrower than `keep`.
    let shrunk = vec![vec![contour.clone()]].outline_as::<i64>(&OutlineStyle::new(-0.5 * keep));
    if shrunk.len() > 1 {
        return None;
    }
    let mut outline: Vec<DVec2> = contour.iter().map(|&[x, y]| DVec2::new(x, y)).collect();
    if crate::plane::signed_area(&outline) < 0.0 {
        outline.reverse();
    }
    let start = outline
        .iter()
        .position(|p| p.distance(fold_start) <= tolerance)?;
    outline.rotate_left(start);
    if outline.len() < 3 || outline[1].distance(fold_end) > tolerance {
        return None;
    }
    outline[0] = fold_start;
    outline[1] = fold_end;
    crate::plane::is_simple(&outline).then_some(outline)
}

/// The band corner each half-edge leaves from (its place in its face's loop), by
/// half-edge.
pub(super) fn corners_of(mesh: &Mesh) -> Vec<u32> {
    let mut corner_of = vec![0u32; mesh.half_edge_count()];
    for f in mesh.faces() {
        for (k, h) in mesh.face_half_edges(f).enumerate() {
            corner_of[h.index()] = k as u32;
        }
    }
    corner_of
}

/// Quadratic Bézier point.
pub(super) fn bezier(p0: DVec3, p1: DVec3, p2: DVec3, t: f64) -> DVec3 {
    let s = 1.0 - t;
    s * s * p0 + 2.0 * s * t * p1 + t * t * p2
}

/// A bend panel's id: on facet `facet` (clamped to the facets there are), along the
/// ruling in the middle of its `n`-strip bend (rails 2i at v, 2i + 1 at v′; the flap's
/// band edge for a boundary edge, `n` 0).
pub(super) fn bend_id_label(
    text: Name,
    vertices: &[DVec3],
    facets: &Loops,
    facet: usize,
    n: usize,
    height: f64,
) -> Label {
    let (a, b) = (vertices[2 * (n / 2)], vertices[2 * (n / 2) + 1]);
    let facet = facet.min(facets.len() - 1);
    let corners = &facets[facet];
    Label {
        text,
        anchor: corners.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / corners.len() as f64,
        direction: (b - a).normalize(),
        height,
        facet: facet as u32,
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.3 * a.distance(b),
    }
}

/// Labels [`flap_labels`] puts on a flap.
pub(super) const FLAP_LABELS: usize = 5;

/// Labels on a flap: the partner panel's id toward each of its two corners, the vertex
/// id at each corner's pins, the face id in the middle (in that priority).
#[allow(clippy::too_many_arguments)]
pub(super) fn flap_labels(
    mesh: &Mesh,
    part: &FaceFlaps,
    face: FaceId,
    he: HalfedgeId,
    corner: usize,
    facet: u32,
    options: &EdgeOptions,
    labels: &mut Vec<Label>,
) {
    let next_corner = (corner + 1) % part.corners();
    let (a, b) = (part.band()[corner], part.band()[next_corner]);
    let rest = part.flap_rest(corner);
    let middle = (a + b + rest.iter().copied().sum::<DVec3>()) / (2 + rest.len()) as f64;
    let along = (b - a).normalize();
    let ends = [
        (mesh.prev(he), corner, mesh.origin(he)),
        (mesh.next(he), next_corner, mesh.dest(he)),
    ];
    for (partner, c, _) in ends {
        labels.push(Label {
            text: panel_id(partner.edge()),
            // Between the flap's middle and the pins at that corner.
            anchor: 0.5 * (middle + part.corner_label(c)),
            direction: along,
            height: options.panel.label_height,
            facet,
            kind: LabelKind::Partner,
            on_edge: false,
            slide: 0.15 * a.distance(b),
        });
    }
    for (_, c, vertex) in ends {
        labels.push(Label {
            text: Name::vertex(vertex.0),
            anchor: part.corner_label(c),
            direction: along,
            height: options.panel.label_height,
            facet,
            kind: LabelKind::Mark,
            on_edge: false,
            slide: 0.0,
        });
    }
    labels.push(Label {
        text: Name::face(face.0),
        anchor: middle,
        direction: along,
        height: options.panel.label_height,
        facet,
        kind: LabelKind::Mark,
        on_edge: false,
        slide: 0.1 * a.distance(b),
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plane::{contains, distance_to_border, is_simple, signed_area};

    /// A flap 40 mm along its fold (the x axis) and 12 mm deep.
    fn flap() -> Vec<DVec2> {
        [(0.0, 0.0), (40.0, 0.0), (40.0, 12.0), (0.0, 12.0)]
            .map(|(x, y)| DVec2::new(x, y))
            .to_vec()
    }

    #[test]
    fn a_notch_clears_the_pin_and_keeps_the_fold() {
        let (clear, keep) = (3.175, 1.5875);
        // One pin inside the flap, one past its inner line but within `clear` of it.
        let pins = [DVec2::new(12.0, 7.0), DVec2::new(30.0, 14.0)];
        let notched = notch_flap(&flap(), &pins, clear, keep).expect("room for both notches");
        assert_eq!(
            (notched[0], notched[1]),
            (flap()[0], flap()[1]),
            "the fold first"
        );
        assert!(is_simple(&notched) && signed_area(&notched) > 0.0);
        for pin in pins {
            assert!(!contains(&notched, pin));
            assert!(distance_to_border(&notched, pin) >= clear * (1.0 - 1e-9));
        }
        // Each notch takes the strip from its pin to the inner line, round at the pin:
        // less than its bounding box, more than the strip beyond the pin.
        let taken = signed_area(&flap()) - signed_area(&notched);
        let boxes = 2.0 * clear * (12.0 - 7.0 + clear) + 2.0 * clear * (12.0 - 14.0 + clear);
        let strips = 2.0 * clear * (12.0 - 7.0);
        assert!(taken < boxes * 1.03 && taken > strips, "{taken} mm²");
    }

    #[test]
    fn no_notch_reaches_the_fold_and_near_notches_merge() {
        let (clear, keep) = (3.175, 1.5875);
        // Too near the fold: the flap would not stay whole along it.
        assert!(notch_flap(&flap(), &[DVec2::new(20.0, 4.0)], clear, keep).is_none());
        // Two pins whose notches leave a finger narrower than `keep` between them
        // become one notch.
        let pins = [
            DVec2::new(15.0, 8.0),
            DVec2::new(15.0 + 2.0 * clear + 0.5, 8.0),
        ];
        let merged = notch_flap(&flap(), &pins, clear, keep).expect("one wide notch");
        let between = DVec2::new(15.0 + clear + 0.25, 10.0);
        assert!(!contains(&merged, between), "the finger is cut away");
    }
}
