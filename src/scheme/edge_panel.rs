//! What the edge schemes (quad-edge, winged-edge) share: a panel per edge made of a flap
//! in each face plane joined by a Bézier bend (thesis ch. 4.2, steps 1–3), the face
//! frames the flaps are drawn in, pin placement in an overlap, and the labels.
//!
//! A scheme describes each face by a [`FaceFlaps`]: the band, each band edge's flap
//! outline and the holes on each flap. [`edge_panels`] turns those into panels.

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::OutlineStyle;
use rayon::prelude::*;

use super::kit::thickness::{thickness, thickness_default};
use super::{face_band, PanelDefaults, PanelOptions};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::OptionDefault;
use crate::panel::{Hole, Label, LabelKind, Loops, Name, Panel, Panels, Source};
use crate::plane::{contains, distance_to_border};
use crate::record::Params;
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
    /// pins); not for a model too detailed for its fasteners (see [`edge_scheme`]).
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

/// A 2D frame in a face's plane, centred on the face centre.
#[derive(Clone, Copy, Debug)]
pub struct FaceFrame {
    /// Face centre.
    pub centre: DVec3,
    /// In-plane axes.
    pub ex: DVec3,
    /// In-plane axes.
    pub ey: DVec3,
}

impl FaceFrame {
    /// The frame of face `f`.
    pub fn new(mesh: &Mesh, f: FaceId) -> Self {
        let normal = mesh.face_normal(f);
        let ex = normal.any_orthonormal_vector();
        Self {
            centre: mesh.face_centre(f),
            ex,
            ey: normal.cross(ex),
        }
    }

    /// Into the plane (the face centre is the origin).
    pub fn to2(&self, p: DVec3) -> DVec2 {
        DVec2::new(
            (p - self.centre).dot(self.ex),
            (p - self.centre).dot(self.ey),
        )
    }

    /// Back to 3D.
    pub fn to3(&self, q: DVec2) -> DVec3 {
        self.centre + q.x * self.ex + q.y * self.ey
    }
}

/// The face band of `f` in 3D and in its frame. The band corners are projected onto
/// the face's plane (through its centre, normal to its vector area), so every flap is
/// an exactly planar facet and the holes of a corner lie on both flaps even when the
/// face is planar only within the tolerance; on a planar face nothing moves.
pub fn band(mesh: &Mesh, f: FaceId, options: &EdgeOptions) -> (Vec<DVec3>, Vec<DVec2>, FaceFrame) {
    let frame = FaceFrame::new(mesh, f);
    let normal = frame.ex.cross(frame.ey);
    let band: Vec<DVec3> = face_band(mesh, f, options.panel.face_scale)
        .into_iter()
        .map(|p| p - (p - frame.centre).dot(normal) * normal)
        .collect();
    let flat = band.iter().map(|&p| frame.to2(p)).collect();
    (band, flat, frame)
}

/// The widest face band a face gets where a corner cannot hold a hole otherwise.
pub const MAX_FACE_SCALE: f64 = 0.9;

/// Steps from `--face-scale` to [`MAX_FACE_SCALE`] tried for such a face.
const BAND_STEPS: u32 = 4;

/// Which corners make an edge scheme widen a face's band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WidenFor {
    /// Corners that hold no hole.
    Bare,
    /// Corners that hold fewer holes than wanted (none included).
    Short,
}

/// A face's flaps `first` (at the options' face scale); where a corner cannot hold a
/// hole (with [`WidenFor::Short`], all its holes) even so, the face's band widened (its
/// corners nearer the face's own), step by step with `flaps_in_band`, kept where it
/// leaves fewer corners bare, or as many bare and fewer short of holes. The bends stay
/// developable: each band edge stays parallel to its mesh edge whatever the scale.
fn widened_band(
    options: &EdgeOptions,
    widen: WidenFor,
    first: FaceFlaps,
    flaps_in_band: impl Fn(&EdgeOptions) -> FaceFlaps,
) -> FaceFlaps {
    let scale = options.panel.face_scale;
    let shortfall = |f: &FaceFlaps| {
        let short = if widen == WidenFor::Short {
            f.reduced
        } else {
            0
        };
        (f.bare.len(), short)
    };
    if shortfall(&first) == (0, 0) || scale >= MAX_FACE_SCALE {
        return first;
    }
    let mut best = first;
    for i in 1..=BAND_STEPS {
        let mut wider = options.clone();
        wider.panel.face_scale =
            scale + (MAX_FACE_SCALE - scale) * f64::from(i) / f64::from(BAND_STEPS);
        let mut tried = flaps_in_band(&wider);
        if shortfall(&tried) < shortfall(&best) {
            tried.widened = true;
            best = tried;
        }
        if shortfall(&best) == (0, 0) {
            break;
        }
    }
    best
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

/// An edge scheme end to end: each face's flaps from `face_flaps` (in parallel, in
/// face order), widened where corners need it (`widen_bands`), then the panels, the
/// connection count (one per face corner) and the report lines; with `--layers 2`
/// both layers of every panel ([`super::sandwich`]), or the refusal of a bend too tight
/// for the card.
pub fn edge_scheme(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync,
) -> Result<super::SchemeOutput, super::SchemeError> {
    let faces = all_flaps(mesh, options, widen, &face_flaps);
    let connections: usize = faces.iter().map(FaceFlaps::corners).sum();
    let mut notes = edge_scheme_notes(mesh, &faces, connections, options);
    let panels = match options.sandwich {
        Some(t) => {
            // A bend too tight for the card is refused with a size or face scale that
            // this scheme, rebuilt so, finds round enough.
            let tightest = |m: &Mesh, o: &EdgeOptions| {
                super::sandwich::tightest_bend(m, &all_flaps(m, o, widen, &face_flaps), o, t)
            };
            let sandwich = super::sandwich::sandwich_panels(mesh, &faces, options, t, tightest)?;
            notes.extend(sandwich.notes);
            sandwich.panels
        }
        None => edge_panels(mesh, &faces, options),
    };
    Ok(super::SchemeOutput {
        panels,
        connections,
        notes,
        unfastened: unfastened(mesh, &faces),
        ..super::SchemeOutput::default()
    })
}

/// Every face's flaps: no deeper than the face's other corners first; then, for the
/// faces whose corners are short of holes, flaps that may grow past them
/// (`keep_if_fastened`); then bands widened where corners still need room.
fn all_flaps(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: &(impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync),
) -> Vec<FaceFlaps> {
    let shallow = EdgeOptions {
        deep_flaps: false,
        ..options.clone()
    };
    let mut faces: Vec<FaceFlaps> = (0..mesh.face_count() as u32)
        .into_par_iter()
        .map(|f| face_flaps(mesh, FaceId(f), &shallow))
        .collect();
    // Deep flaps are notched round the pins they pass; lapped into two layers, a
    // notch can pinch a flap to a thread, so the sandwich keeps flaps shallow.
    if options.deep_flaps && options.sandwich.is_none() {
        let deeper: Vec<(usize, FaceFlaps)> = (0..faces.len())
            .into_par_iter()
            .filter(|&k| !faces[k].bare.is_empty() || faces[k].reduced > 0)
            .map(|k| (k, face_flaps(mesh, FaceId(k as u32), options)))
            .collect();
        keep_if_fastened(&mut faces, deeper);
    }
    widen_bands(mesh, options, widen, face_flaps, &mut faces);
    faces
}

/// Widens the bands of the faces whose corners need room ([`widened_band`]), where
/// [`keep_if_fastened`] lets it.
fn widen_bands(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: &(impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync),
    faces: &mut [FaceFlaps],
) {
    let needs = |f: &FaceFlaps| !f.bare.is_empty() || (widen == WidenFor::Short && f.reduced > 0);
    let widened: Vec<(usize, FaceFlaps)> = (0..faces.len())
        .into_par_iter()
        .filter(|&k| needs(&faces[k]))
        .map(|k| {
            let f = FaceId(k as u32);
            let first = faces[k].clone();
            (
                k,
                widened_band(options, widen, first, |o| face_flaps(mesh, f, o)),
            )
        })
        .collect();
    keep_if_fastened(faces, widened);
}

/// Puts the flaps `tried` (a face's index, its flaps) in place of those faces', unless
/// the model stays too detailed for its fasteners even with them: more than
/// [`super::MOST_UNFASTENED`] of the corners bare (the build then warns with a budget,
/// and the larger flaps would cost sheets for a panel set that cannot be assembled as
/// asked anyway).
fn keep_if_fastened(faces: &mut [FaceFlaps], tried: Vec<(usize, FaceFlaps)>) {
    let corners: usize = faces.iter().map(FaceFlaps::corners).sum();
    let bare_before: usize = faces.iter().map(|f| f.bare.len()).sum();
    let fastened = tried
        .iter()
        .map(|(k, t)| faces[*k].bare.len() as isize - t.bare.len() as isize)
        .sum::<isize>()
        .max(0) as usize;
    if (bare_before.saturating_sub(fastened) as f64) <= super::MOST_UNFASTENED * corners as f64 {
        for (k, flaps) in tried {
            faces[k] = flaps;
        }
    }
}

/// The connections without a hole, face by face: the edge panels before and after
/// each bare corner, at its vertex.
pub fn unfastened(mesh: &Mesh, faces: &[FaceFlaps]) -> Vec<super::ConnectionName> {
    faces
        .iter()
        .flat_map(|f| &f.bare)
        .map(|&h| super::ConnectionName {
            panels: [panel_id(mesh.prev(h).edge()), panel_id(h.edge())],
            at: Name::vertex(mesh.origin(h).0),
        })
        .collect()
}

/// Report lines shared by the edge schemes: holes that did not fit, boundary panels.
pub fn edge_scheme_notes(
    mesh: &Mesh,
    faces: &[FaceFlaps],
    connections: usize,
    options: &EdgeOptions,
) -> Vec<String> {
    let bare: usize = faces.iter().map(|f| f.bare.len()).sum();
    // Connections without any hole are reported by the build (the fasteners check).
    let reduced = faces.iter().map(|f| f.reduced).sum::<usize>() - bare;
    let grown: usize = faces.iter().map(|f| f.grown).sum();
    let panel = &options.panel;
    let mut notes = Vec::new();
    if grown > 0 {
        notes.push(format!(
            "{grown} of {connections} connections have deeper flaps than --flap-scale {} to hold their fastener holes",
            options.flap_scale
        ));
    }
    let widened = faces.iter().filter(|f| f.widened).count();
    if widened > 0 {
        notes.push(format!(
            "{widened} of {} faces have a wider band than --face-scale {} to hold their fastener holes",
            faces.len(),
            panel.face_scale
        ));
    }
    if reduced > 0 {
        notes.push(format!(
            "{reduced} of {connections} connections hold fewer fastener holes than asked (--holes {} in each of a corner's flap overlaps) but at least one: their flap overlaps cannot hold more {} mm holes with {} mm of material around each; a larger --size, a smaller --hole-diameter or --hole-margin, or fewer panels (--target-edges) helps",
            panel.holes,
            crate::units::fmt_num(panel.hole_diameter),
            crate::units::fmt_num(panel.hole_margin)
        ));
    }
    let boundary = mesh.edges().filter(|&e| mesh.is_boundary_edge(e)).count();
    if boundary > 0 {
        notes.push(format!(
            "{boundary} boundary edges have a panel with a single flap and no bend"
        ));
    }
    notes
}

/// Builds every edge panel from the faces' flaps. Returns the panels (in edge order).
pub fn edge_panels(mesh: &Mesh, faces: &[FaceFlaps], options: &EdgeOptions) -> Panels {
    let corner_of = corners_of(mesh);
    Panels::build(mesh.edge_count(), |e| {
        edge_panel(mesh, EdgeId(e as u32), faces, &corner_of, options)
    })
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

/// The panel of edge `e`: flap in f, bend strips, flap in f′ (or the flap alone on the
/// boundary). Every buffer is sized exactly before it is filled: a big job builds
/// millions of panels, and none should grow twice.
fn edge_panel(
    mesh: &Mesh,
    e: EdgeId,
    faces: &[FaceFlaps],
    corner_of: &[u32],
    options: &EdgeOptions,
) -> Panel {
    // Work from a half-edge that has a face (boundary edges have one).
    let h = if mesh.is_boundary_half_edge(e.half_edge()) {
        e.half_edge().twin()
    } else {
        e.half_edge()
    };
    let f = mesh.face(h).expect("an edge has a face on one side");
    let part = &faces[f.index()];
    let k = corner_of[h.index()] as usize;
    // The face across, its flaps and the corner the twin leaves from.
    let across = mesh
        .face(h.twin())
        .map(|g| (g, &faces[g.index()], corner_of[h.twin().index()] as usize));
    // Bend strips (none on the boundary).
    let n = if across.is_some() {
        options.samples.max(1) as usize
    } else {
        0
    };
    let rest_f = part.flap_rest(k);
    let rest_g = across.map_or(&[][..], |(_, other, k2)| other.flap_rest(k2));

    let mut vertices: Vec<DVec3> = Vec::with_capacity(2 * (n + 1) + rest_f.len() + rest_g.len());
    push_rails(
        mesh,
        h,
        (part, k),
        across.map(|(_, o, k2)| (o, k2)),
        n,
        options,
        &mut vertices,
    );
    let (rail_v, rail_w) = (|i: usize| 2 * i as u32, |i: usize| 2 * i as u32 + 1);

    // One flap on a boundary edge, two otherwise; each flap is its two rail ends and
    // its rest, each bend strip a quad.
    let flaps = 1 + usize::from(across.is_some());
    let mut facets =
        Loops::with_capacity(flaps + n, 2 * flaps + rest_f.len() + rest_g.len() + 4 * n);
    let hole_count = part.flap_holes(k).count()
        + across.map_or(0, |(_, other, k2)| other.flap_holes(k2).count());
    let mut holes = Vec::with_capacity(hole_count);
    let mut add_flap = |part: &FaceFlaps,
                        edge: usize,
                        start: u32,
                        end: u32,
                        vertices: &mut Vec<DVec3>,
                        facets: &mut Loops| {
        let first = vertices.len() as u32;
        let rest = part.flap_rest(edge);
        vertices.extend_from_slice(rest);
        let facet = facets.len() as u32;
        facets.push(
            [start, end]
                .into_iter()
                .chain(first..first + rest.len() as u32),
        );
        holes.extend(part.flap_holes(edge).map(|(p, connection)| Hole {
            position: p,
            diameter: options.panel.hole_diameter,
            connection,
            facet,
        }));
        facet
    };
    add_flap(part, k, rail_v(0), rail_w(0), &mut vertices, &mut facets);
    let flap_g = across.map(|(g, other, k2)| {
        for i in 0..n {
            facets.push([rail_w(i), rail_v(i), rail_v(i + 1), rail_w(i + 1)]);
        }
        let facet = add_flap(other, k2, rail_w(n), rail_v(n), &mut vertices, &mut facets);
        (g, other, k2, facet)
    });

    let mut labels = Vec::with_capacity(1 + FLAP_LABELS * (1 + usize::from(n > 0)));
    // On the bend's middle strip (the flap is facet 0; a boundary panel has only it).
    let (id, height) = (panel_id(e), options.panel.label_height);
    labels.push(bend_id_label(id, &vertices, &facets, 1 + n / 2, n, height));
    flap_labels(mesh, part, f, h, k, 0, options, &mut labels);
    if let Some((g, other, k2, facet)) = flap_g {
        flap_labels(mesh, other, g, h.twin(), k2, facet, options, &mut labels);
    }

    Panel::new(Source::edge(e.0), vertices, facets, holes, labels)
}

/// The rails at v and at v′ of half-edge `h`'s panel, pushed onto `vertices` in pairs
/// sampled at the same t on both (so rulings stay parallel to the edge): rail point i
/// is vertex 2i at v, 2i + 1 at v′. The rails run in `n` strips from band corner k of
/// its face (`own`) to the corners of the face across (`across`: its flaps and the
/// corner the twin leaves from); on the boundary they are the band edge's two ends.
fn push_rails(
    mesh: &Mesh,
    h: HalfedgeId,
    (part, k): (&FaceFlaps, usize),
    across: Option<(&FaceFlaps, usize)>,
    n: usize,
    options: &EdgeOptions,
    vertices: &mut Vec<DVec3>,
) {
    let band_f = part.band();
    let k1 = (k + 1) % part.corners();
    let Some((other, k2)) = across else {
        vertices.extend([band_f[k], band_f[k1]]);
        return;
    };
    let (v, w) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
    let m = 0.5 * (v + w);
    let b = options.bridge_scale;
    let (cv, cw) = (b * v + (1.0 - b) * m, b * w + (1.0 - b) * m);
    // In g the twin runs w → v: band corner k2 is at w, k2 + 1 at v.
    let band_g = other.band();
    let (gv, gw) = (band_g[(k2 + 1) % band_g.len()], band_g[k2]);
    for i in 0..=n {
        let t = i as f64 / n as f64;
        vertices.push(bezier(band_f[k], cv, gv, t));
        vertices.push(bezier(band_f[k1], cw, gw, t));
    }
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
const FLAP_LABELS: usize = 5;

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
