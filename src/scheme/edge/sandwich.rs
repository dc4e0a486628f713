//! The thesis' two-layer sandwich for the edge schemes (ch. 7; `--thickness T
//! --layers 2`): every edge panel is cut twice, and the two are glued into one shell
//! of uniform thickness.
//!
//! - The outer layer lies on the model's surface; the inner layer is the same surface
//!   offset T inward: each flap moved T along its face's inward normal, each bend
//!   offset T along its own normal at every ruling. A bend is a cylinder over a plane
//!   quadratic curve (its rulings are parallel to the edge), so the inner bend is a
//!   cylinder over the offset curve: exactly developable, and narrower by T·θ on a
//!   convex edge (θ its turning; wider on a concave one).
//! - The rulings stand at equal steps of turning, close enough (see [`max_strip_turn`])
//!   that the flat strips, chords of the curves, keep the layers T apart and their
//!   widths T·θ apart within hundredths of a millimetre.
//! - At a face corner the flaps of two panels overlap. In the outer layer the flap of
//!   the face's earlier band edge (a boundary edge's before any other) keeps the
//!   overlap and the later one gives it up; in the inner layer the reverse (where three
//!   overlap, the earliest keeps the outer and the latest the inner). So every covered point of a face has one outer and one
//!   inner layer over it: the shell is 2T thick everywhere, each pin goes through both
//!   layers, and the seams of the two layers are staggered, a lap joint.
//! - A convex bend whose curve turns tighter than 2T (the inner card's inside face) would
//!   fold back on itself there: refused, with the size or face scale that rounds it.

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
use rayon::prelude::*;

use super::flaps::{bend_id_label, bezier, corners_of, flap_labels, EdgeOptions, FaceFlaps};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::panel::{Covers, Hole, IdKind, Label, Loops, Name, Panel, Panels, Source};
use crate::plane::{contains, signed_area};
use crate::scheme::SchemeError;
use crate::units::fmt_num;

/// The outer layer of an edge panel: `E12`, on the model's surface.
pub static OUTER: IdKind = IdKind {
    letter: "E",
    legend: "edge panel (outer layer)",
    noun: "edge",
    part_noun: "",
    layer: "outer",
};

/// The inner layer of an edge panel: `I12`, glued behind `E12`.
pub static INNER: IdKind = IdKind {
    letter: "I",
    legend: "inner layer of the edge panel of the same number",
    noun: "edge",
    part_noun: "",
    layer: "inner",
};

/// How much thinner than T (mm) the shell may get between a bend's flat strips: the
/// strips are chords of the curves, and a chord turning α sits T·cos(α/2) from the
/// other layer's.
const LAYER_GAP_SLACK: f64 = 0.01;

/// The most a bend strip may turn (radians) in a sandwich of card `t` thick, so the
/// layers stay within [`LAYER_GAP_SLACK`] of `t` apart.
pub fn max_strip_turn(t: f64) -> f64 {
    2.0 * (1.0 - LAYER_GAP_SLACK / t).clamp(-1.0, 1.0).acos()
}

/// Most strips in one bend (as `--samples` allows).
const MAX_STRIPS: usize = 64;

/// A bend's cross-section in the plane square to its edge: the quadratic curve from the
/// band edge in face f over the mesh edge to the band edge in face g, with legs `a`
/// (f's band edge to the mesh edge) and `b` (on to g's band edge).
#[derive(Clone, Copy, Debug)]
pub struct Bend {
    a: DVec3,
    b: DVec3,
    /// Inward normals of f and g: the curve's inward normal at its two ends.
    inward: [DVec3; 2],
}

impl Bend {
    /// The bend of control points `p0` (in f), `p1` (on the edge), `p2` (in g), its
    /// edge along `u`, faces of outward normals `nf`, `ng`.
    pub fn new([p0, p1, p2]: [DVec3; 3], u: DVec3, nf: DVec3, ng: DVec3) -> Self {
        let square = |v: DVec3| v - v.dot(u) * u;
        Bend {
            a: square(p1 - p0),
            b: square(p2 - p1),
            inward: [-nf, -ng],
        }
    }

    /// The turning (radians), positive where the curve turns inward (a convex edge).
    pub fn turning(&self) -> f64 {
        let angle = self.a.cross(self.b).length().atan2(self.a.dot(self.b));
        if self.b.dot(self.inward[0]) >= 0.0 {
            angle
        } else {
            -angle
        }
    }

    /// The smallest radius of curvature along the curve (mm): for B′(t) = 2((1−t)a + tb)
    /// and B″ = 2(b − a), ρ = |B′|³ / |B′ × B″| = 2|(1−t)a + tb|³ / |a × b|, least where
    /// (1−t)a + tb is shortest.
    pub fn tightest_radius(&self) -> f64 {
        let cross = self.a.cross(self.b).length();
        if cross <= 1e-12 * self.a.length() * self.b.length() {
            return f64::INFINITY;
        }
        let d = self.b - self.a;
        let t = (-self.a.dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
        let shortest = (self.a + t * d).length();
        2.0 * shortest.powi(3) / cross
    }

    /// Strips for card `t` thick: at least `samples`, and at least one per
    /// [`max_strip_turn`].
    pub fn strips(&self, samples: u32, t: f64) -> usize {
        let needed = (self.turning().abs() / max_strip_turn(t) - 1e-9).ceil() as usize;
        needed.max(samples as usize).clamp(1, MAX_STRIPS)
    }

    /// The `n + 1` rulings at equal steps of turning: each one's curve parameter and
    /// the curve's inward unit normal there (the ends' exactly the faces').
    pub fn rulings(&self, n: usize) -> Vec<(f64, DVec3)> {
        let theta = self.turning().abs();
        let (la, lb) = (self.a.length(), self.b.length());
        let along = self.a / la.max(1e-300);
        let across = self.b - self.b.dot(along) * along;
        let straight = theta < 1e-9 || la < 1e-12 || lb < 1e-12 || across.length() < 1e-12;
        (0..=n)
            .map(|i| {
                let (t, normal) = if i == 0 {
                    (0.0, self.inward[0])
                } else if i == n {
                    (1.0, self.inward[1])
                } else if straight {
                    (i as f64 / n as f64, self.inward[0])
                } else {
                    let w = across.normalize();
                    // In the plane (along, w): a = (la, 0), b = (b·along, b·w).
                    let (a2, b2) = (
                        DVec2::new(la, 0.0),
                        DVec2::new(self.b.dot(along), self.b.dot(w)),
                    );
                    let phi = theta * i as f64 / n as f64;
                    let d = DVec2::from_angle(phi);
                    let t = (a2.perp_dot(d) / (a2 - b2).perp_dot(d)).clamp(0.0, 1.0);
                    // The normal square to the tangent, on the side the ends' are.
                    let normal = -phi.sin() * along + phi.cos() * w;
                    let sign = if w.dot(self.inward[0]) >= 0.0 {
                        1.0
                    } else {
                        -1.0
                    };
                    (t, sign * normal)
                };
                (t, normal)
            })
            .collect()
    }
}

/// One layer's flap of a band edge: its outline (3D, on the outer surface) from the
/// fold's two ends on, counter-clockwise, the fold's ends as fractions of the band
/// edge (0 at band corner k, 1 at k + 1), and the holes through it.
#[derive(Clone, Debug)]
struct LayerFlap {
    outline: Vec<DVec3>,
    fold: [f64; 2],
    holes: Vec<(DVec3, u32)>,
}

/// A face's flaps shared out to the two layers, `[outer, inner]` per band edge (`None`
/// where a layer keeps nothing of a flap), and the area of flap that hangs on no fold
/// once shared out (mm²; left out).
struct FaceLayers {
    flaps: Vec<[Option<LayerFlap>; 2]>,
    normal: DVec3,
    dropped: f64,
}

/// Rounds of [`face_layers`] at most: each takes from both layers what one of them
/// left hanging on no fold.
const LAP_ROUNDS: usize = 8;

/// Shares face `f`'s flaps out to the layers: in the outer layer a flap gives up what
/// the flaps before it cover, in the inner layer what the flaps after it cover (in band
/// edge order, boundary edges first). A piece
/// so cut off its fold is left out, and then from the other layer too, so the two
/// layers still cover the same ground.
fn face_layers(mesh: &Mesh, f: FaceId, part: &FaceFlaps) -> FaceLayers {
    let frame = mesh.face_frame(f);
    let n = part.corners();
    let band = part.band();
    let flat: Vec<Vec<DVec2>> = (0..n)
        .map(|k| {
            [band[k], band[(k + 1) % n]]
                .iter()
                .chain(part.flap_rest(k))
                .map(|&p| frame.flat(p))
                .collect()
        })
        .collect();
    // A boundary edge's panel is its flap alone, with nothing else to hold it: its flap
    // comes first, keeping the outer layer of every overlap (and the pins there).
    let boundary: Vec<bool> = mesh
        .face_half_edges(f)
        .map(|h| mesh.face(h.twin()).is_none())
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&k| (!boundary[k], k));
    let mut gone: Vec<Vec<DVec2>> = Vec::new();
    let mut kept = Vec::new();
    for _ in 0..LAP_ROUNDS {
        let mut cut_off = Vec::new();
        kept = (0..n)
            .map(|k| {
                let mut layer = |others: &[usize]| {
                    let clips = others
                        .iter()
                        .map(|&j| &flat[j][..])
                        .chain(gone.iter().map(|g| &g[..]));
                    let (piece, off) = lap(&flat[k], clips);
                    cut_off.extend(off);
                    piece
                };
                let at = order
                    .iter()
                    .position(|&j| j == k)
                    .expect("every flap is ranked");
                [layer(&order[..at]), layer(&order[at + 1..])]
            })
            .collect::<Vec<_>>();
        if cut_off.is_empty() {
            break;
        }
        gone.extend(cut_off);
    }
    let flaps = kept
        .into_iter()
        .enumerate()
        .map(|(k, layers)| {
            layers.map(|piece| {
                piece.map(|(outline, fold)| {
                    let (a, b) = (band[k], band[(k + 1) % n]);
                    let holes = part
                        .flap_holes(k)
                        .filter(|(p, _)| contains(&outline, frame.flat(*p)))
                        .collect();
                    let outline = [a.lerp(b, fold[0]), a.lerp(b, fold[1])]
                        .into_iter()
                        .chain(outline[2..].iter().map(|&q| frame.lift(q)))
                        .collect();
                    LayerFlap {
                        outline,
                        fold,
                        holes,
                    }
                })
            })
        })
        .collect();
    FaceLayers {
        flaps,
        normal: frame.x.cross(frame.y),
        dropped: gone.iter().map(|g| signed_area(g).abs()).sum(),
    }
}

/// A flap (counter-clockwise, from its fold's two ends) less the `others`: the piece
/// that hangs on the fold, from the fold's ends on, with the fold's ends as fractions of
/// the fold, and any other pieces (which hang on nothing).
#[allow(clippy::type_complexity)]
fn lap<'a>(
    flap: &[DVec2],
    others: impl Iterator<Item = &'a [DVec2]>,
) -> (Option<(Vec<DVec2>, [f64; 2])>, Vec<Vec<DVec2>>) {
    let clips: Vec<Vec<[f64; 2]>> = others
        .map(|o| o.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    if clips.is_empty() {
        return (Some((flap.to_vec(), [0.0, 1.0])), Vec::new());
    }
    let shapes = overlay(&[flap.to_vec()], &clips, OverlayRule::Difference);
    let (start, end) = (flap[0], flap[1]);
    let span = flap.iter().map(|p| p.distance(start)).fold(0.0, f64::max);
    let tolerance = 1e-7 * (1.0 + span);
    let (piece, mut off) = fold_piece(&shapes, start, end, tolerance, span);
    let Some((outline, fold)) = piece else {
        return (None, off);
    };
    // A piece pinched to a neck narrower than 2·NECK is opened there: what a disc of
    // radius NECK cannot reach is cut off with the rest.
    let as_arrays = |p: &[DVec2]| p.iter().map(|q| [q.x, q.y]).collect::<Vec<[f64; 2]>>();
    let shrunk = vec![vec![as_arrays(&outline)]].outline_as::<i64>(&OutlineStyle::new(-NECK));
    if shrunk.len() <= 1 {
        return (Some((outline, fold)), off);
    }
    let grown = shrunk.outline_as::<i64>(&OutlineStyle::new(NECK).line_join(LineJoin::Round(0.1)));
    let grown: Vec<Vec<[f64; 2]>> = grown.into_iter().flatten().collect();
    let opened = overlay(
        std::slice::from_ref(&outline),
        &grown,
        OverlayRule::Intersect,
    );
    // Everything of the piece outside what stays is cut off, the opened pieces that
    // hang on nothing included (once: the cut-off area is reported).
    let (piece, _) = fold_piece(&opened, start, end, tolerance, span);
    if let Some((kept, _)) = &piece {
        let rest = overlay(&[outline], &[as_arrays(kept)], OverlayRule::Difference);
        off.extend(
            rest.iter()
                .map(|shape| to_points(&shape[0]))
                .filter(|p| signed_area(p).abs() > 1e-6 * span * span),
        );
    } else {
        off.push(outline);
    }
    (piece, off)
}

/// Necks of a lapped flap narrower than twice this (mm) are cut through.
const NECK: f64 = 0.5;

/// Removes the corners where an outline turns straight back on itself (a spike of no
/// width, which the overlay can leave where a cut runs along a side).
fn remove_spikes(outline: &mut Vec<DVec2>, tolerance: f64) {
    let mut k = 0;
    while outline.len() >= 3 && k < outline.len() {
        let n = outline.len();
        let (a, b, c) = (outline[(k + n - 1) % n], outline[k], outline[(k + 1) % n]);
        let (u, v) = (b - a, c - b);
        let back = u.dot(v) < 0.0 && u.perp_dot(v).abs() <= tolerance * (u.length() + v.length());
        if back {
            outline.remove(k);
            k = k.saturating_sub(1);
        } else {
            k += 1;
        }
    }
}

/// The points of an overlay contour.
fn to_points(contour: &[[f64; 2]]) -> Vec<DVec2> {
    contour.iter().map(|&[x, y]| DVec2::new(x, y)).collect()
}

/// `subjects` combined with `clips` by `rule` (OGC-valid shapes).
fn overlay(
    subjects: &[Vec<DVec2>],
    clips: &[Vec<[f64; 2]>],
    rule: OverlayRule,
) -> Vec<Vec<Vec<[f64; 2]>>> {
    let subjects: Vec<Vec<[f64; 2]>> = subjects
        .iter()
        .map(|s| s.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    FloatOverlay::<[f64; 2], i64>::from_subj_and_clip_custom(
        &subjects,
        clips,
        OverlayOptions::ogc(),
        Solver::default(),
    )
    .overlay(rule, FillRule::NonZero)
}

/// Of overlay `shapes`, the one that hangs on the fold `start → end` along the longest
/// run ([`on_fold`]), and the others; slivers of rounding are dropped.
#[allow(clippy::type_complexity)]
fn fold_piece(
    shapes: &[Vec<Vec<[f64; 2]>>],
    start: DVec2,
    end: DVec2,
    tolerance: f64,
    span: f64,
) -> (Option<(Vec<DVec2>, [f64; 2])>, Vec<Vec<DVec2>>) {
    let mut best: Option<((Vec<DVec2>, [f64; 2]), Vec<DVec2>)> = None;
    let mut off = Vec::new();
    for shape in shapes {
        let mut outline = to_points(&shape[0]);
        if signed_area(&outline) < 0.0 {
            outline.reverse();
        }
        // The overlay can repeat a corner within rounding; a facet needs real sides.
        outline.dedup_by(|p, q| p.distance(*q) <= tolerance);
        while outline.len() > 1 && outline[0].distance(outline[outline.len() - 1]) <= tolerance {
            outline.pop();
        }
        remove_spikes(&mut outline, tolerance);
        if outline.len() < 3 || signed_area(&outline) <= 1e-6 * span * span {
            // A sliver the overlay leaves along a shared side is rounding, not flap.
            continue;
        }
        let fold_length = |b: &(Vec<DVec2>, [f64; 2])| b.1[1] - b.1[0];
        match on_fold(&outline, start, end, tolerance) {
            Some(piece)
                if best
                    .as_ref()
                    .is_none_or(|b| fold_length(&b.0) < fold_length(&piece)) =>
            {
                if let Some((_, before)) = best.replace((piece, outline)) {
                    off.push(before);
                }
            }
            _ => off.push(outline),
        }
    }
    (best.map(|b| b.0), off)
}

/// `outline` (counter-clockwise) rotated to start with its run along the fold
/// `start → end`, the run's ends put exactly on the fold, with their fractions of it;
/// `None` where it does not touch the fold along a length.
fn on_fold(
    outline: &[DVec2],
    start: DVec2,
    end: DVec2,
    tolerance: f64,
) -> Option<(Vec<DVec2>, [f64; 2])> {
    let fold = end - start;
    let length = fold.length();
    let along = |p: DVec2| (p - start).dot(fold) / (length * length);
    let on = |p: DVec2| {
        fold.perp_dot(p - start).abs() <= tolerance * length
            && (-tolerance..=1.0 + tolerance).contains(&along(p))
    };
    let n = outline.len();
    // A side along the fold, going its way; the run is the longest chain of them.
    let side = |i: usize| {
        let (p, q) = (outline[i], outline[(i + 1) % n]);
        on(p) && on(q) && along(q) > along(p)
    };
    let first = (0..n).find(|&i| side(i) && !side((i + n - 1) % n))?;
    let mut last = first;
    while side((last + 1) % n) && (last + 1) % n != first {
        last = (last + 1) % n;
    }
    let snap = |s: f64| {
        if s.abs() <= tolerance {
            0.0
        } else if (s - 1.0).abs() <= tolerance {
            1.0
        } else {
            s.clamp(0.0, 1.0)
        }
    };
    let fold_ends = [
        snap(along(outline[first])),
        snap(along(outline[(last + 1) % n])),
    ];
    if fold_ends[1] - fold_ends[0] <= tolerance {
        return None;
    }
    let rest = (last + 2..first + n).map(|i| outline[i % n]);
    let rotated = [start.lerp(end, fold_ends[0]), start.lerp(end, fold_ends[1])]
        .into_iter()
        .chain(rest)
        .collect();
    Some((rotated, fold_ends))
}

/// The bend of interior half-edge `h` (from face f, band corner k, to the face across
/// at band corner k2), and its v rail's three control points.
fn bend_of(
    mesh: &Mesh,
    h: HalfedgeId,
    (part, k): (&FaceFlaps, usize),
    (other, k2): (&FaceFlaps, usize),
    options: &EdgeOptions,
) -> (Bend, [DVec3; 3], [DVec3; 3]) {
    let (v, w) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
    let m = 0.5 * (v + w);
    let b = options.bridge_scale;
    let band_f = part.band();
    let band_g = other.band();
    let rail_v = [
        band_f[k],
        b * v + (1.0 - b) * m,
        band_g[(k2 + 1) % band_g.len()],
    ];
    let rail_w = [
        band_f[(k + 1) % part.corners()],
        b * w + (1.0 - b) * m,
        band_g[k2],
    ];
    let f = mesh.face(h).expect("h has a face");
    let g = mesh.face(h.twin()).expect("h's twin has a face");
    let bend = Bend::new(
        rail_v,
        (w - v).normalize(),
        mesh.face_normal(f),
        mesh.face_normal(g),
    );
    (bend, rail_v, rail_w)
}

/// What a sandwich build makes of the faces' flaps: both layers of every edge panel
/// (outer, then inner, in edge order; a boundary panel whose flap is lapped away in a
/// layer has no part there) and the report lines.
pub struct Sandwich {
    /// The panels.
    pub panels: Panels,
    /// Report lines.
    pub notes: Vec<String>,
}

/// Both layers of every edge panel of card `t` thick, or the refusal of a bend too
/// tight for the card.
/// `tightest(mesh, options)` is the scheme's [`tightest_bend`] rebuilt for another
/// mesh or options, to find the fixes a refusal names.
pub fn sandwich_panels(
    mesh: &Mesh,
    faces: &[FaceFlaps],
    options: &EdgeOptions,
    t: f64,
    tightest: impl Fn(&Mesh, &EdgeOptions) -> Option<(usize, f64)>,
) -> Result<Sandwich, SchemeError> {
    if let Some(bend) = tightest_bend(mesh, faces, options, t) {
        return Err(too_tight(mesh, options, t, bend, tightest));
    }
    let ctx = Context::new(mesh, faces, options, t);
    let bends: Vec<Option<Bend>> = (0..mesh.edge_count() as u32)
        .into_par_iter()
        .map(|e| ctx.bend(EdgeId(e)).map(|(bend, _, _)| bend))
        .collect();
    let layers: Vec<FaceLayers> = (0..faces.len())
        .into_par_iter()
        .map(|f| face_layers(mesh, FaceId(f as u32), &faces[f]))
        .collect();
    // A boundary edge's panel is its flap alone: where lapping gives that flap's
    // ground in one layer to its neighbours, the panel has no part in that layer.
    let layer_panels: Vec<Option<Panel>> = (0..2 * mesh.edge_count())
        .into_par_iter()
        .map(|i| ctx.layer_panel(EdgeId((i / 2) as u32), i % 2 == 1, &layers))
        .collect();
    let single = layer_panels.iter().filter(|p| p.is_none()).count();
    let mut panels = Panels::new();
    for panel in layer_panels.iter().flatten() {
        panels.push(panel.view());
    }
    drop(layer_panels);
    let strips: Vec<usize> = bends
        .iter()
        .flatten()
        .map(|b| b.strips(options.samples, t))
        .collect();
    let mut notes = vec![format!(
        "two-layer sandwich: every edge panel cut twice, outer layer E and inner layer I (glued behind the E of the same number), {} mm apart; flaps lapped at the face corners, one panel's outer layer over the other's inner, so the laps are two layers thick like the rest",
        fmt_num(t)
    )];
    let finer = strips
        .iter()
        .filter(|&&n| n > options.samples as usize)
        .count();
    if finer > 0 {
        notes.push(format!(
            "{finer} of {} bends have more strips than --samples {} (up to {}): one per {}° of turning keeps the layers {} mm apart",
            strips.len(),
            options.samples,
            strips.iter().max().unwrap_or(&0),
            fmt_num((max_strip_turn(t).to_degrees() * 10.0).floor() / 10.0),
            fmt_num(t)
        ));
    }
    if single > 0 {
        notes.push(format!(
            "{single} boundary panels are cut in one layer only: the neighbouring flaps cover their flap's ground in the other"
        ));
    }
    let dropped: f64 = layers.iter().map(|l| l.dropped).sum();
    if dropped > 1e-6 {
        notes.push(format!(
            "{} mm² of flap is in neither layer: lapping the flaps cut it off its fold (it would hang on nothing), so the other layer leaves it out too",
            fmt_num((dropped * 10.0).round() / 10.0)
        ));
    }
    Ok(Sandwich { panels, notes })
}

/// The convex bend that turns tightest, as its edge and radius, where that radius is
/// below 2T: the inner card's inside face lies 2T under the surface, and a curve
/// offset past its radius folds back on itself.
pub fn tightest_bend(
    mesh: &Mesh,
    faces: &[FaceFlaps],
    options: &EdgeOptions,
    t: f64,
) -> Option<(usize, f64)> {
    let ctx = Context::new(mesh, faces, options, t);
    (0..mesh.edge_count())
        .filter_map(|e| {
            let (bend, _, _) = ctx.bend(EdgeId(e as u32))?;
            (bend.turning() > 0.0).then(|| (e, bend.tightest_radius()))
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .filter(|&(_, r)| r < 2.0 * t)
}

/// Rebuilds at most this many times to find a size or face scale round enough.
const FIX_TRIES: usize = 8;

/// The refusal of bend `edge` of `radius` mm: names the face scale and the size with
/// which `tightest` (the scheme rebuilt) finds every bend round enough, each tried
/// from the radii found (a bend's radius grows with the model's size and with
/// (1 − face scale), but a band widened to hold holes moves too).
fn too_tight(
    mesh: &Mesh,
    options: &EdgeOptions,
    t: f64,
    (edge, radius): (usize, f64),
    tightest: impl Fn(&Mesh, &EdgeOptions) -> Option<(usize, f64)>,
) -> SchemeError {
    let need = 2.0 * t;
    let mut factor = 1.0;
    let mut r = radius;
    let mut size = None;
    for _ in 0..FIX_TRIES {
        factor *= need / r.max(1e-9) * 1.001;
        let mut scaled = mesh.clone();
        scaled.scale(factor);
        match tightest(&scaled, options) {
            None => {
                size = Some((mesh.longest_side() * factor / options.panel.scale).ceil());
                break;
            }
            Some((_, tighter)) => r = tighter,
        }
    }
    let mut face_scale = None;
    let (mut s, mut r) = (options.panel.face_scale, radius);
    for _ in 0..FIX_TRIES {
        s = ((1.0 - (1.0 - s) * need / r.max(1e-9) * 1.001) * 100.0).floor() / 100.0;
        if s < 0.05 {
            break;
        }
        let mut tried = options.clone();
        tried.panel.face_scale = s;
        match tightest(mesh, &tried) {
            None => {
                face_scale = Some(s);
                break;
            }
            Some((_, tighter)) => r = tighter,
        }
    }
    let fixes = match (face_scale, size) {
        (Some(s), Some(size)) => format!(
            "; --face-scale {} or --size {size}mm rounds every bend enough",
            fmt_num(s)
        ),
        (Some(s), None) => format!("; --face-scale {} rounds every bend enough", fmt_num(s)),
        (None, Some(size)) => format!("; --size {size}mm rounds every bend enough"),
        (None, None) => "; a simpler model (--target-edges) or thinner card may build".to_string(),
    };
    SchemeError::Options(format!(
        "--thickness {}mm: the bend of {} turns tighter (radius {} mm) than the two layers are thick ({} mm), so the inner layer would fold back on itself{fixes}",
        fmt_num(t),
        Name::new(&OUTER, edge as u32),
        fmt_num((radius * 1000.0).round() / 1000.0),
        fmt_num(need)
    ))
}

/// Partner ids name the panels as the builder finds them: by their outer layer.
fn outer_partners(labels: &mut [Label]) {
    for label in labels {
        if *label.text.kind == crate::panel::EDGE {
            label.text = Name::new(&OUTER, label.text.number);
        }
    }
}

/// The `n` bend strips between rails 2i (at v) and 2i + 1 (at v′), the first and the
/// last with the fold points a lapped flap adds on their outer rulings.
fn strip_loops(n: usize, inserted_f: &[u32], inserted_g: &[u32]) -> Vec<Vec<u32>> {
    let (rail_v, rail_w) = (|i: usize| 2 * i as u32, |i: usize| 2 * i as u32 + 1);
    (0..n)
        .map(|i| {
            let mut facet = vec![rail_w(i)];
            if i == 0 {
                facet.extend(inserted_f);
            }
            facet.extend([rail_v(i), rail_v(i + 1)]);
            if i + 1 == n {
                facet.extend(inserted_g);
            }
            facet.push(rail_w(i + 1));
            facet
        })
        .collect()
}

/// What every layer panel of a sandwich build reads.
struct Context<'a> {
    mesh: &'a Mesh,
    faces: &'a [FaceFlaps],
    corner_of: Vec<u32>,
    options: &'a EdgeOptions,
    t: f64,
}

impl<'a> Context<'a> {
    fn new(mesh: &'a Mesh, faces: &'a [FaceFlaps], options: &'a EdgeOptions, t: f64) -> Self {
        Context {
            mesh,
            faces,
            corner_of: corners_of(mesh),
            options,
            t,
        }
    }

    /// Edge `e`'s half-edge with a face, that face and its band corner.
    fn side(&self, e: EdgeId) -> (HalfedgeId, FaceId, usize) {
        let h = if self.mesh.is_boundary_half_edge(e.half_edge()) {
            e.half_edge().twin()
        } else {
            e.half_edge()
        };
        let f = self.mesh.face(h).expect("an edge has a face on one side");
        (h, f, self.corner_of[h.index()] as usize)
    }

    /// Edge `e`'s bend and rails (`None` on the boundary).
    fn bend(&self, e: EdgeId) -> Option<(Bend, [DVec3; 3], [DVec3; 3])> {
        let (h, f, k) = self.side(e);
        let g = self.mesh.face(h.twin())?;
        let k2 = self.corner_of[h.twin().index()] as usize;
        Some(bend_of(
            self.mesh,
            h,
            (&self.faces[f.index()], k),
            (&self.faces[g.index()], k2),
            self.options,
        ))
    }

    /// One layer of edge `e`'s panel: flap in f, bend strips, flap in the face across.
    fn layer_panel(&self, e: EdgeId, inner: bool, layers: &[FaceLayers]) -> Option<Panel> {
        let (h, f, k) = self.side(e);
        let depth = if inner { self.t } else { 0.0 };
        let shift_f = -depth * layers[f.index()].normal;
        let across = self.mesh.face(h.twin()).map(|g| {
            let k2 = self.corner_of[h.twin().index()] as usize;
            (g, k2)
        });
        let (mut vertices, n) = self.rails(e, depth, shift_f);
        let (rail_v, rail_w) = (|i: usize| 2 * i as u32, |i: usize| 2 * i as u32 + 1);
        let layer = usize::from(inner);
        let mut holes = Vec::new();
        let mut labels = Vec::new();
        let id = Name::new(if inner { &INNER } else { &OUTER }, e.0);

        let flap_f = layers[f.index()].flaps[k][layer].as_ref();
        let far = across.and_then(|(g, k2)| {
            let shift_g = -depth * layers[g.index()].normal;
            let flap = layers[g.index()].flaps[k2][layer].as_ref()?;
            Some((g, k2, shift_g, flap))
        });
        // Facets: the near flap, the strips, the far flap.
        let first_strip = usize::from(flap_f.is_some()) as u32;
        let far_facet = first_strip + n as u32;
        let (near_loop, inserted_f) = flap_f.map_or((None, Vec::new()), |flap| {
            let (lp, inserted) = self.attach(
                flap,
                shift_f,
                [rail_v(0), rail_w(0)],
                0,
                &mut vertices,
                &mut holes,
            );
            (Some(lp), inserted)
        });
        let (far_loop, inserted_g) = far.map_or((None, Vec::new()), |(_, _, shift_g, flap)| {
            let ends = [rail_w(n), rail_v(n)];
            let (lp, inserted) =
                self.attach(flap, shift_g, ends, far_facet, &mut vertices, &mut holes);
            (Some(lp), inserted)
        });
        let mut facets = Loops::new();
        if let Some(lp) = near_loop {
            facets.push(lp);
            flap_labels(
                self.mesh,
                &self.faces[f.index()],
                f,
                h,
                k,
                0,
                self.options,
                &mut labels,
            );
            labels.iter_mut().for_each(|l| l.anchor += shift_f);
        }
        for facet in strip_loops(n, &inserted_f, &inserted_g) {
            facets.push(facet);
        }
        if let (Some(lp), Some((g, k2, shift_g, _))) = (far_loop, far) {
            facets.push(lp);
            let first = labels.len();
            let part = &self.faces[g.index()];
            flap_labels(
                self.mesh,
                part,
                g,
                h.twin(),
                k2,
                far_facet,
                self.options,
                &mut labels,
            );
            labels[first..].iter_mut().for_each(|l| l.anchor += shift_g);
        }
        if facets.is_empty() {
            return None;
        }
        let strip_facets: Vec<u32> = (first_strip..far_facet).collect();
        outer_partners(&mut labels);
        let facet = strip_facets.get(n / 2).copied().unwrap_or(0) as usize;
        let height = self.options.panel.label_height;
        labels.insert(0, bend_id_label(id, &vertices, &facets, facet, n, height));
        let covers = if inner {
            Covers::Inside(e.0)
        } else {
            Covers::Edge(e.0)
        };
        Some(Panel::new(
            Source { id, covers },
            vertices,
            facets,
            holes,
            labels,
        ))
    }

    /// Edge `e`'s rails `depth` inside the surface (vertex 2i at v, 2i + 1 at v′, at the
    /// bend's rulings) and its strip count; on the boundary the band edge moved by
    /// `shift` and no strip.
    fn rails(&self, e: EdgeId, depth: f64, shift: DVec3) -> (Vec<DVec3>, usize) {
        let mut vertices = Vec::new();
        match self.bend(e) {
            Some((bend, rail_v, rail_w)) => {
                let n = bend.strips(self.options.samples, self.t);
                for (t, normal) in bend.rulings(n) {
                    let offset = depth * normal;
                    vertices.push(bezier(rail_v[0], rail_v[1], rail_v[2], t) + offset);
                    vertices.push(bezier(rail_w[0], rail_w[1], rail_w[2], t) + offset);
                }
                (vertices, n)
            }
            None => {
                let (_, f, k) = self.side(e);
                let band = self.faces[f.index()].band();
                let k1 = (k + 1) % band.len();
                vertices.extend([band[k] + shift, band[k1] + shift]);
                (vertices, 0)
            }
        }
    }

    /// A layer's flap moved by `shift`: its loop from the fold ends `ends` (the rail
    /// vertices at fractions 0 and 1 of the fold) on, for facet `facet`, with its holes
    /// added; and the fold points it adds between the rails, in order from `ends[1]` to
    /// `ends[0]`, for the bend strip beside it.
    fn attach(
        &self,
        flap: &LayerFlap,
        shift: DVec3,
        ends: [u32; 2],
        facet: u32,
        vertices: &mut Vec<DVec3>,
        holes: &mut Vec<Hole>,
    ) -> (Vec<u32>, Vec<u32>) {
        let mut push = |p: DVec3| {
            vertices.push(p + shift);
            vertices.len() as u32 - 1
        };
        let p = if flap.fold[0] == 0.0 {
            ends[0]
        } else {
            push(flap.outline[0])
        };
        let q = if flap.fold[1] == 1.0 {
            ends[1]
        } else {
            push(flap.outline[1])
        };
        let lp = [p, q]
            .into_iter()
            .chain(flap.outline[2..].iter().map(|&x| push(x)))
            .collect();
        holes.extend(flap.holes.iter().map(|&(position, connection)| Hole {
            position: position + shift,
            diameter: self.options.panel.hole_diameter,
            connection,
            facet,
        }));
        let inserted = [(q, ends[1]), (p, ends[0])]
            .into_iter()
            .filter(|(x, end)| x != end)
            .map(|(x, _)| x)
            .collect();
        (lp, inserted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A right-angled bend: legs of 10 mm along x then down z, faces up (+z) and out (+x).
    fn square_bend() -> Bend {
        Bend::new(
            [
                DVec3::new(-10.0, 0.0, 0.0),
                DVec3::ZERO,
                DVec3::new(0.0, 0.0, -10.0),
            ],
            DVec3::Y,
            DVec3::Z,
            DVec3::X,
        )
    }

    #[test]
    fn a_bend_turns_its_angle_and_is_tightest_at_its_middle() {
        let bend = square_bend();
        assert!((bend.turning() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // At t = 1/2, B′ = (a + b) of length 10·√2, so ρ = 2·(5√2)³/100 = 5√2.
        assert!((bend.tightest_radius() - 5.0 * 2f64.sqrt()).abs() < 1e-9);
        // The other way round (a concave edge) the turning is negative.
        let concave = Bend::new(
            [
                DVec3::new(-10.0, 0.0, 0.0),
                DVec3::ZERO,
                DVec3::new(0.0, 0.0, 10.0),
            ],
            DVec3::Y,
            DVec3::Z,
            -DVec3::X,
        );
        assert!((concave.turning() + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn rulings_turn_in_equal_steps_with_their_normals_square_to_the_curve() {
        let bend = square_bend();
        let rulings = bend.rulings(6);
        let curve = |t: f64| {
            bezier(
                DVec3::new(-10.0, 0.0, 0.0),
                DVec3::ZERO,
                DVec3::new(0.0, 0.0, -10.0),
                t,
            )
        };
        for (i, &(t, normal)) in rulings.iter().enumerate() {
            let tangent = (curve(t + 1e-7) - curve(t - 1e-7)).normalize();
            // The tangent has turned i steps of 15° from +x toward −z.
            let phi = (i as f64 * 15.0).to_radians();
            assert!(
                tangent.distance(DVec3::new(phi.cos(), 0.0, -phi.sin())) < 1e-6,
                "{i}: {tangent}"
            );
            assert!(normal.dot(tangent).abs() < 1e-6 && (normal.length() - 1.0).abs() < 1e-12);
        }
        assert_eq!(rulings[0].1, -DVec3::Z);
        assert_eq!(rulings[6].1, -DVec3::X);
        // Offset inward by 1 mm, the polyline is shorter by about 1·θ.
        let length = |depth: f64| {
            rulings
                .windows(2)
                .map(|w| (curve(w[1].0) + depth * w[1].1).distance(curve(w[0].0) + depth * w[0].1))
                .sum::<f64>()
        };
        let shorter = length(0.0) - length(1.0);
        assert!(
            (shorter - std::f64::consts::FRAC_PI_2).abs() < 0.01,
            "{shorter}"
        );
    }

    #[test]
    fn thick_card_takes_more_strips() {
        let bend = square_bend();
        assert_eq!(bend.strips(4, 0.5), 4);
        // 3 mm: at most 2·acos(1 − 0.01/3) ≈ 9.4° a strip, so 10 for 90°.
        assert_eq!(bend.strips(4, 3.0), 10);
    }

    #[test]
    fn a_lapped_flap_gives_up_the_corner_it_shares() {
        // A 40 × 10 flap from its fold (0,0)–(40,0), and a neighbour's flap over its
        // first 8 mm.
        let flap =
            [(0.0, 0.0), (40.0, 0.0), (40.0, 10.0), (0.0, 10.0)].map(|(x, y)| DVec2::new(x, y));
        let other =
            [(-5.0, 0.0), (8.0, 0.0), (8.0, 10.0), (-5.0, 10.0)].map(|(x, y)| DVec2::new(x, y));
        let (kept, off) = lap(&flap, [&other[..]].into_iter());
        let (outline, fold) = kept.expect("a piece on the fold");
        assert!(off.is_empty());
        assert!((fold[0] - 0.2).abs() < 1e-9 && fold[1] == 1.0, "{fold:?}");
        assert_eq!(outline[0], DVec2::new(8.0, 0.0));
        assert_eq!(outline[1], DVec2::new(40.0, 0.0));
        assert!((signed_area(&outline) - 320.0).abs() < 1e-6);
    }

    #[test]
    fn a_neck_narrower_than_a_millimetre_is_cut_through() {
        // A 40 × 10 flap less a block over x 10..30 above y 0.4: two squares joined
        // along the fold by a strip 0.4 mm deep.
        let flap =
            [(0.0, 0.0), (40.0, 0.0), (40.0, 10.0), (0.0, 10.0)].map(|(x, y)| DVec2::new(x, y));
        let block =
            [(10.0, 0.4), (30.0, 0.4), (30.0, 20.0), (10.0, 20.0)].map(|(x, y)| DVec2::new(x, y));
        let (kept, off) = lap(&flap, [&block[..]].into_iter());
        let (outline, fold) = kept.expect("a piece on the fold");
        // One square stays (its corners rounded by the opening's disc), the other
        // square and the strip are cut off.
        let area = signed_area(&outline);
        assert!(area > 99.0 && area < 100.0 + 1e-6, "{area}");
        let run = fold[1] - fold[0];
        let at_an_end = fold[0] < 0.02 || fold[1] > 0.98;
        assert!(at_an_end && run > 0.22 && run <= 0.25 + 1e-9, "{fold:?}");
        let cut: f64 = off.iter().map(|p| signed_area(p).abs()).sum();
        assert!(
            (cut + area - (100.0 + 100.0 + 20.0 * 0.4)).abs() < 0.5,
            "{cut}"
        );
    }
}
