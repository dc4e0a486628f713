//! The woven scheme (thesis ch. 5, paper 002): every edge twisted, the traced cycles
//! of the extended graph rotation system become ribbons that go alternately over and
//! under each other.
//!
//! Geometry of one ribbon (SPEC.md §2, woven). A cycle passes face corners; at corner w
//! of face f it runs from one side of f's face band (the corners moved toward the
//! centre, `s·v + (1−s)·c`) to the next, cutting the corner. Its end on a band side
//! (U′, W′), measured from the far corner U′ toward the strand's corner W′, covers the
//! fractions `[0.6 − 0.6t, 0.6 + 0.4t]` (`t` = `--band-scale`): a segment parallel to
//! the edge, shifted toward W′ and inset from it. The face piece joins two such ends;
//! it is a trapezoid. Across an edge e = (u, w) between faces f and g the strand from
//! corner (f, w) goes to corner (g, u), and the other strand from (f, u) to (g, w), like
//! an X: each edge piece joins two parallel segments, so it is a planar trapezoid, and
//! both edge pieces at e lie in one plane (through f's and g's band sides).
//!
//! Thickness: at e the strand that goes over is lifted by r/2 along that plane's
//! normal, the other lowered by r/2, so the two are exactly `--thickness` r apart. The
//! face piece between two ends at different heights is no longer planar: it is split
//! into two triangles along the diagonal that folds least (a score line).
//!
//! A ring cannot be unrolled in one piece; it is cut into segments that each fit the
//! largest panel the layout can take and do not overlap themselves when unrolled. Two
//! segments meet at a lap joint: the face piece where they meet belongs to both, with
//! fastener holes at the same 3D points.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::ergs::{trace_cycles, WeaveCycle};
use super::kit::thickness::{thickness, thickness_default};
use super::{args_of, Configured, OptionValues, PanelDefaults, PanelOptions};
use super::{ConnectionName, PanelLimit, Scheme, SchemeError, SchemeOutput};
use crate::mesh::geometry::{planarity_error, vector_area};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh, VertexId};
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::{
    Covers, FacetFrame, Hole, IdKind, Label, LabelKind, Loops, Name, Panel, Panels, Source,
};
use crate::plane::{
    clip_convex, contains, convex_hull, counter_clockwise, distance_to_border, fits_rotated,
    segment_distance, smallest_box,
};
use crate::record::{round4, Params};
use crate::units::fraction;

/// The woven scheme: plain-weaving ribbons from the extended graph rotation system.
pub struct Woven;

/// `--band-scale`.
const BAND_SCALE: f64 = 0.4;
/// `--curl-limit`.
const CURL_LIMIT: f64 = 3.0;
/// `--thickness`.
pub(super) const THICKNESS: &str = "0.1in";

/// The woven options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct WovenArgs {
    /// Strand width: a strand's end covers this fraction of the face band's side,
    /// below 1.
    #[arg(long, value_name = "T")]
    band_scale: Option<f64>,

    /// Curl limit: a ribbon segment's convex hull is at most this many times its area.
    /// Smaller cuts ribbons into more, straighter segments that nest on fewer sheets;
    /// larger gives fewer joints.
    #[arg(long, value_name = "R")]
    curl_limit: Option<f64>,

    /// Material thickness, with a unit: the two strands at a crossing are this far
    /// apart, one lifted and one lowered by half of it; 0 for flat ribbons.
    #[arg(long, value_name = "LENGTH")]
    thickness: Option<String>,
}

/// The woven scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct WovenOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Strand width as a fraction of the band side.
    pub band_scale: f64,
    /// Material thickness (mm): strands cross this far apart.
    pub thickness: f64,
    /// A segment's convex hull is at most this many times its area: curling ribbons
    /// are cut into pieces that nest.
    pub curl_limit: f64,
}

impl Scheme for Woven {
    fn name(&self) -> &'static str {
        "woven"
    }

    fn about(&self) -> &'static str {
        "plain-weaving ribbons from the extended graph rotation system"
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<WovenArgs>(),
            &[
                OptionDefault::value("band-scale", BAND_SCALE),
                OptionDefault::value("curl-limit", CURL_LIMIT),
                thickness_default(),
            ],
        )
    }

    fn defaults(&self) -> PanelDefaults {
        PanelDefaults {
            // Below 1: the crossings lie between the face bands.
            face_scale: 0.8,
            holes: 2,
            holes_allowed: &[0, 1, 2],
        }
    }

    fn needs_convex_faces(&self) -> bool {
        // A strand cuts each face corner between two band sides.
        true
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --curl-limit (shorter, straighter segments)"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: WovenArgs = values.parse()?;
        if panel.face_scale >= 1.0 {
            return Err("--face-scale: woven needs a face scale below 1: the strands cross in the gap between the face bands".to_string());
        }
        let band_scale = fraction("band-scale", args.band_scale, BAND_SCALE)?;
        if band_scale >= 1.0 {
            return Err("--band-scale: woven needs a band scale below 1: a strand's end must stay clear of the band corner".to_string());
        }
        let curl_limit = args.curl_limit.unwrap_or(CURL_LIMIT);
        if !(curl_limit.is_finite() && curl_limit >= 1.5) {
            return Err(format!(
                "--curl-limit: {curl_limit} must be at least 1.5 (a straight strip's hull is about its own area)"
            ));
        }
        let thickness = thickness("thickness", args.thickness.as_deref(), THICKNESS, &panel)?;
        Ok(Box::new(WovenOptions {
            panel,
            band_scale,
            thickness,
            curl_limit,
        }))
    }
}

impl Configured for WovenOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        panels(mesh, self)
    }

    fn accepts(&self, mesh: &Mesh) -> Result<(), SchemeError> {
        // Every cycle walks across every edge twice: a hole's rim has one side only.
        match mesh.boundary_loops().len() {
            0 => Ok(()),
            holes => Err(SchemeError::Options(format!(
                "the woven scheme needs a closed mesh and this one has {}: close them (--fill-holes) or use another --scheme",
                crate::units::count_of(holes, "hole")
            ))),
        }
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("band_scale", self.band_scale);
        params.push("thickness", round4(self.thickness));
        params.push("curl_limit", self.curl_limit);
        params
    }
}

/// Fraction of the band side (from the far corner) where a strand's end starts and
/// ends, for band scale `t`.
fn end_fractions(t: f64) -> (f64, f64) {
    (0.6 - 0.6 * t, 0.6 + 0.4 * t)
}

/// Parts of a ribbon closer than this (mm) when unrolled, that share no corner, are
/// treated as touching: the segment is cut before them.
const CLEARANCE: f64 = 0.5;

/// Two facets sharing a corner overlap when their intersection exceeds this (mm²).
const OVERLAP_AREA: f64 = 1e-4;

/// The ends of a segment fit the sheet with this much to spare (mm), for the nester's
/// rounding.
const FIT_SLACK: f64 = 0.5;

/// Smallest cosine between a face normal and an edge piece's normal used to scale a
/// lift (a fold sharper than about 78° from flat lifts by at most five times r/2).
const MIN_LIFT_COSINE: f64 = 0.2;

/// Most start positions tried when cutting a ring into segments.
const MAX_STARTS: usize = 64;

/// What a piece of a ribbon is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceKind {
    /// In a face, cutting the corner at the destination of this face half-edge: a
    /// landing (at one end's height) or the turn between the two heights.
    Face {
        /// The face half-edge ending at the corner.
        corner: HalfedgeId,
    },
    /// Across an edge.
    Edge {
        /// The edge crossed.
        edge: EdgeId,
        /// Over (lifted) or under (lowered) the other strand at this edge.
        over: bool,
        /// The cycle (index) of the other strand crossing this edge.
        crossing: u32,
    },
}

/// One cycle's ribbon, as a closed ring of planar pieces in 3D (mm).
///
/// Line `k` is the fold line between piece `k − 1` and piece `k`; piece `k` joins line
/// `k` to line `k + 1` (indices modulo the ring length). Each line is `[near, far]`:
/// near is the end on the side of the corner the strand cuts in that face. Each face
/// corner passed is a run of face pieces (entry landing, turn, exit landing; the
/// landings only where a neighbouring strand overlaps) followed by one edge piece.
#[derive(Clone, Debug, PartialEq)]
pub struct Ribbon {
    /// Index of the cycle (0-based; printed 1-based).
    pub cycle: u32,
    /// Fold lines.
    pub lines: Vec<[DVec3; 2]>,
    /// What each piece is.
    pub pieces: Vec<PieceKind>,
    /// Each piece's facets: loops of corner references (see [`Corner`]), counter-
    /// clockwise seen from the outside. One quad, or two triangles for a turn whose
    /// ends sit at different heights.
    pub facets: Vec<Vec<Vec<Corner>>>,
    /// The first piece of each face corner passed (its entry line has the same index).
    pub corner_start: Vec<usize>,
}

/// A corner of a piece: `line` 0 (the piece's first line) or 1 (its second), and
/// `end` 0 (near) or 1 (far).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Corner {
    /// 0: the piece's first line; 1: its second.
    pub line: u8,
    /// 0: near; 1: far.
    pub end: u8,
}

const A0: Corner = Corner { line: 0, end: 0 };
const A1: Corner = Corner { line: 0, end: 1 };
const B0: Corner = Corner { line: 1, end: 0 };
const B1: Corner = Corner { line: 1, end: 1 };

impl Ribbon {
    /// Number of mesh edges the cycle crosses (= face corners passed).
    pub fn edge_count(&self) -> usize {
        self.corner_start.len()
    }

    /// The pieces of face corner `i` (its face pieces, then its edge piece), as ring
    /// indices in order.
    pub fn corner_pieces(&self, i: usize) -> std::ops::Range<usize> {
        let n = self.corner_start.len();
        let start = self.corner_start[i % n];
        let end = if i % n + 1 < n {
            self.corner_start[i % n + 1]
        } else {
            self.pieces.len()
        };
        start..end
    }

    /// The 3D point of a corner of piece `k`.
    pub fn point(&self, k: usize, c: Corner) -> DVec3 {
        let line = (k + c.line as usize) % self.lines.len();
        self.lines[line][c.end as usize]
    }

    /// The facets of piece `k` as 3D polygons.
    pub fn facet_points(&self, k: usize) -> Vec<Vec<DVec3>> {
        self.facets[k]
            .iter()
            .map(|f| f.iter().map(|&c| self.point(k, c)).collect())
            .collect()
    }

    /// Length (mm) of the centre line: the distance between the midpoints of each
    /// piece's two fold lines, summed.
    pub fn length(&self) -> f64 {
        let n = self.lines.len();
        (0..n)
            .map(|k| {
                let a = self.lines[k];
                let b = self.lines[(k + 1) % n];
                (0.5 * (a[0] + a[1])).distance(0.5 * (b[0] + b[1]))
            })
            .sum()
    }
}

/// A cycle's summary for the report and the manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleSummary {
    /// 1-based id (`C3`).
    pub id: u32,
    /// Mesh edges crossed.
    pub edges: usize,
    /// Ribbon centre-line length (mm).
    pub length: f64,
    /// Segments it was cut into.
    pub segments: usize,
}

/// The report's line about the cycles.
fn cycle_report(cycles: &[CycleSummary]) -> Vec<String> {
    let edges = cycles.iter().map(|c| c.edges);
    let (lo, hi) = (edges.clone().min().unwrap_or(0), edges.max().unwrap_or(0));
    // Rounded as the manifest has them, so the report's total is the manifest's.
    let length: f64 = cycles.iter().map(|c| round4(c.length)).sum();
    let segments: usize = cycles.iter().map(|c| c.segments).sum();
    vec![format!(
        "weave: {} cycles of {lo} to {hi} edges, {length:.0} mm of ribbon in all, cut into {segments} segments",
        cycles.len()
    )]
}

/// The manifest's `cycles` list: id, edges crossed, ribbon length (mm), segments.
fn cycle_manifest(cycles: &[CycleSummary]) -> Params {
    let list: Vec<Params> = cycles
        .iter()
        .map(|c| {
            let mut entry = Params::default();
            entry.push("id", format!("C{}", c.id));
            entry.push("edges", c.edges);
            entry.push("length", round4(c.length));
            entry.push("segments", c.segments);
            entry
        })
        .collect();
    let mut manifest = Params::default();
    manifest.push_records("cycles", list);
    manifest
}

/// Woven cycles: `C3`, and their segments, `C3.2` (both numbered from 1).
pub static CYCLE: IdKind = IdKind {
    letter: "C",
    legend: "woven cycle (C3.2: its segment 2)",
    noun: "cycle",
    part_noun: "segment",
    layer: "",
};

/// The printed id of a cycle.
pub fn cycle_id(cycle: u32) -> Name {
    Name::new(&CYCLE, cycle + 1)
}

/// The printed id of a segment (both 1-based).
pub fn segment_id(cycle: u32, segment: usize) -> Name {
    Name::with_part(&CYCLE, cycle + 1, segment as u32 + 1)
}

/// The face bands' geometry the strands are cut from.
struct Strands<'a> {
    mesh: &'a Mesh,
    centres: Vec<DVec3>,
    scale: f64,
    lo: f64,
    hi: f64,
}

impl Strands<'_> {
    fn band(&self, f: FaceId, v: VertexId) -> DVec3 {
        self.scale * self.mesh.position(v) + (1.0 - self.scale) * self.centres[f.index()]
    }

    /// The end `[near, far]` of the strand at corner (f, w) on the band side toward
    /// the neighbour u.
    fn end(&self, f: FaceId, w: VertexId, u: VertexId) -> [DVec3; 2] {
        let (far_corner, corner) = (self.band(f, u), self.band(f, w));
        [
            far_corner.lerp(corner, self.hi),
            far_corner.lerp(corner, self.lo),
        ]
    }

    /// The strand region at the corner ending face half-edge `c`, in its face plane.
    fn region(&self, c: HalfedgeId) -> [DVec3; 4] {
        let f = self.mesh.face(c).expect("a face half-edge");
        let w = self.mesh.dest(c);
        let a = self.end(f, w, self.mesh.origin(c));
        let b = self.end(f, w, self.mesh.dest(self.mesh.next(c)));
        [a[0], a[1], b[1], b[0]]
    }

    /// The face half-edge of `f` ending at `v`.
    fn corner_at(&self, f: FaceId, v: VertexId) -> HalfedgeId {
        self.mesh
            .face_half_edges(f)
            .find(|&h| self.mesh.dest(h) == v)
            .expect("the vertex is a corner of the face")
    }
}

/// Where the landings of the strand at a corner end, as a ruling parameter of its
/// trapezoid (the line from the near side's point at fraction p to the far side's
/// point at p; 0 is the entry line, 1 the exit line): `[entry landing, exit landing]`
/// with the exit's measured from the exit line, 0 where no neighbour overlaps. The
/// second value is true when the two landings had to be shortened to leave room for
/// the turn between them (a corner too tight for the band scale).
fn landings(
    strands: &Strands,
    f: FaceId,
    entry: [DVec3; 2],
    exit: [DVec3; 2],
    neighbours: [HalfedgeId; 2],
) -> ([f64; 2], bool) {
    let n = strands.mesh.face_normal(f);
    let x = n.any_orthonormal_vector();
    let y = n.cross(x);
    let o = entry[0];
    let flat = |p: DVec3| DVec2::new((p - o).dot(x), (p - o).dot(y));
    let (entry2, exit2) = (entry.map(flat), exit.map(flat));
    let own = counter_clockwise(&[entry2[0], entry2[1], exit2[1], exit2[0]]);
    let mut reach = [0.0f64; 2];
    for side in 0..2 {
        let theirs = counter_clockwise(&strands.region(neighbours[side]).map(flat));
        let overlap = clip_convex(&theirs, &own);
        if crate::plane::area(&overlap) <= 1e-9 {
            continue;
        }
        let (from, to) = if side == 0 {
            (entry2, exit2)
        } else {
            (exit2, entry2)
        };
        let ruling = |p: f64| (from[0].lerp(to[0], p), from[1].lerp(to[1], p));
        // The side of a ruling the `from` line lies on.
        let side_of = |p: f64, v: DVec2| {
            let (a, b) = ruling(p);
            (b - a).perp_dot(v - a)
        };
        let home = side_of(0.5, 0.5 * (from[0] + from[1])).signum();
        for &v in &overlap {
            // The smallest ruling with v on the `from` side (bisection: the rulings
            // sweep the trapezoid monotonically).
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if side_of(mid, v) * home >= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            reach[side] = reach[side].max(1.02 * hi);
        }
    }
    let total = reach[0] + reach[1];
    if total > MAX_LANDINGS {
        let shrink = MAX_LANDINGS / total;
        ([reach[0] * shrink, reach[1] * shrink], true)
    } else {
        (reach, false)
    }
}

/// The two landings of a corner take at most this fraction of its rulings, leaving
/// the rest for the turn between the heights.
const MAX_LANDINGS: f64 = 0.9;

/// What [`ribbons`] found besides the ribbons.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RibbonNotes {
    /// Face corners where a strand's landings would meet (no room to turn between
    /// the heights outside the crossings).
    pub tight_corners: usize,
}

/// The ribbons of a closed mesh with every edge twisted, in cycle order.
pub fn ribbons(
    mesh: &Mesh,
    options: &WovenOptions,
) -> Result<(Vec<Ribbon>, RibbonNotes), SchemeError> {
    let cycles = trace_cycles(mesh, &vec![true; mesh.edge_count()]).map_err(|e| {
        SchemeError::Options(format!(
            "the woven scheme cannot weave this mesh: {e}; close its holes (--fill-holes) or use another --scheme"
        ))
    })?;
    // The cycles crossing each edge (twice each).
    let mut visits: Vec<Vec<u32>> = vec![Vec::new(); mesh.edge_count()];
    for (c, cycle) in cycles.iter().enumerate() {
        for e in cycle.edges() {
            visits[e.index()].push(c as u32);
        }
    }
    let (lo, hi) = end_fractions(options.band_scale);
    let strands = Strands {
        mesh,
        centres: mesh.faces().map(|f| mesh.face_centre(f)).collect(),
        scale: options.panel.face_scale,
        lo,
        hi,
    };
    let normals: Vec<DVec3> = (0..mesh.edge_count() as u32)
        .map(|e| edge_piece_normal(mesh, EdgeId(e), &|f, v| strands.band(f, v)))
        .collect();
    let weave = Weave {
        mesh,
        strands,
        normals,
        visits,
        half: 0.5 * options.thickness,
    };
    let mut notes = RibbonNotes::default();
    let ribbons = cycles
        .iter()
        .enumerate()
        .map(|(c, cycle)| cycle_ribbon(&weave, c as u32, cycle, &mut notes))
        .collect();
    Ok((ribbons, notes))
}

/// What every cycle's ribbon is cut from.
struct Weave<'a> {
    mesh: &'a Mesh,
    strands: Strands<'a>,
    /// Each edge piece's plane normal.
    normals: Vec<DVec3>,
    /// The cycles crossing each edge (twice each).
    visits: Vec<Vec<u32>>,
    /// Half the material thickness (mm).
    half: f64,
}

/// The ribbon of cycle `c`: at each of its face corners the entry and exit lines,
/// lifted or lowered as the strand crosses, with the landings between; then the edge
/// piece to the next corner. Corners too tight to turn are counted in `notes`.
fn cycle_ribbon(weave: &Weave, c: u32, cycle: &WeaveCycle, notes: &mut RibbonNotes) -> Ribbon {
    let Weave {
        mesh,
        strands,
        normals,
        visits,
        half,
    } = weave;
    let (mesh, half) = (*mesh, *half);
    let n = cycle.len();
    let mut lines = Vec::with_capacity(4 * n);
    let mut pieces = Vec::with_capacity(4 * n);
    let mut refs = Vec::with_capacity(4 * n);
    let mut corner_start = Vec::with_capacity(n);
    for i in 0..n {
        let (h, corner) = (cycle.darts[i], cycle.corners[i]);
        let next = cycle.darts[(i + 1) % n];
        let f = mesh
            .face(corner)
            .expect("traced corners are face half-edges");
        let (u, w, q) = (mesh.origin(h), mesh.dest(h), mesh.dest(next));
        // Entry: the side along h's edge, lifted or lowered as the strand crosses
        // that edge; exit: the side along the next dart's edge.
        // The line moves along the face normal, so the face pieces stay in
        // planes parallel to the face, by as much as puts it half the thickness
        // off the edge pieces' plane (both strands' edge pieces stay parallel,
        // the thickness apart).
        let face_normal = mesh.face_normal(f);
        let lift = |dart: HalfedgeId, over: Option<bool>| {
            let sign = if over.unwrap_or(true) { 1.0 } else { -1.0 };
            let m = normals[dart.edge().index()];
            sign * half / face_normal.dot(m).max(MIN_LIFT_COSINE) * face_normal
        };
        let (entry_lift, exit_lift) = (lift(h, cycle.over[i]), lift(next, cycle.over[(i + 1) % n]));
        let entry = strands.end(f, w, u);
        let exit = strands.end(f, w, q);
        let neighbours = [strands.corner_at(f, u), strands.corner_at(f, q)];
        let (depth, tight) = landings(strands, f, entry, exit, neighbours);
        notes.tight_corners += usize::from(tight);
        corner_start.push(pieces.len());
        lines.push(entry.map(|p| p + entry_lift));
        if depth[0] > 0.0 {
            let line = [0, 1].map(|e| entry[e].lerp(exit[e], depth[0]) + entry_lift);
            pieces.push(PieceKind::Face { corner });
            refs.push(face_normal);
            lines.push(line);
        }
        if depth[1] > 0.0 {
            let line = [0, 1].map(|e| exit[e].lerp(entry[e], depth[1]) + exit_lift);
            pieces.push(PieceKind::Face { corner });
            refs.push(face_normal);
            lines.push(line);
        }
        pieces.push(PieceKind::Face { corner });
        refs.push(face_normal);
        lines.push(exit.map(|p| p + exit_lift));
        let e = next.edge();
        pieces.push(PieceKind::Edge {
            edge: e,
            over: cycle.over[(i + 1) % n].unwrap_or(true),
            crossing: other_visit(&visits[e.index()], c),
        });
        refs.push(normals[e.index()]);
    }
    let mut ribbon = Ribbon {
        cycle: c,
        lines,
        pieces,
        facets: Vec::new(),
        corner_start,
    };
    let flips = ring_flips(&ribbon, &refs);
    ribbon.facets = (0..ribbon.pieces.len())
        .map(|k| piece_facets(&ribbon, k, flips[k]))
        .collect();
    ribbon
}

/// The other cycle crossing an edge (the cycle itself when it crosses twice).
fn other_visit(visits: &[u32], cycle: u32) -> u32 {
    match visits {
        [a, b] if *a == cycle => *b,
        [a, _] => *a,
        _ => cycle,
    }
}

/// Unit normal of the plane holding both edge pieces at `e` (through the two band
/// sides along it), pointing to the outside.
fn edge_piece_normal(mesh: &Mesh, e: EdgeId, band: &dyn Fn(FaceId, VertexId) -> DVec3) -> DVec3 {
    let h = e.half_edge();
    let (Some(f), Some(g)) = (mesh.face(h), mesh.face(h.twin())) else {
        return DVec3::Z;
    };
    let outward = mesh.face_normal(f) + mesh.face_normal(g);
    let (u, w) = (mesh.origin(h), mesh.dest(h));
    let along = mesh.position(w) - mesh.position(u);
    let across = band(g, u) - band(f, u);
    let n = along.cross(across);
    if n.length_squared() <= 1e-24 * along.length_squared() * across.length_squared() {
        return mesh.face_normal(f);
    }
    let n = n.normalize();
    let reference = if outward.length_squared() > 1e-18 {
        outward
    } else {
        mesh.face_normal(f)
    };
    if n.dot(reference) < 0.0 {
        -n
    } else {
        n
    }
}

/// The loop of piece `k` before orienting: face pieces join near to near (both near
/// ends are on the corner's side); an edge piece crosses diagonally, so the near end
/// of one line faces the far end of the other.
fn base_loop(ribbon: &Ribbon, k: usize) -> [Corner; 4] {
    match ribbon.pieces[k] {
        PieceKind::Face { .. } => [A0, A1, B1, B0],
        PieceKind::Edge { .. } => [A0, A1, B0, B1],
    }
}

/// Whether each piece's base loop is reversed so that the ring is consistently
/// oriented with the outside up. Neighbouring pieces must run their shared line in
/// opposite directions: a face piece's base loop runs its second line far to near and
/// the next piece's runs its first near to far, so they agree; an edge piece's runs
/// its second line near to far, so the flip toggles after every edge piece (a woven
/// ring crosses an even number of edges, so it closes). Which of the two consistent
/// choices faces outward is a vote of all pieces, weighted by their area.
fn ring_flips(ribbon: &Ribbon, outward: &[DVec3]) -> Vec<bool> {
    let mut parity = Vec::with_capacity(ribbon.pieces.len());
    let mut toggle = false;
    let mut vote = 0.0;
    for (k, reference) in outward.iter().enumerate() {
        parity.push(toggle);
        let area = vector_area(base_loop(ribbon, k).iter().map(|&c| ribbon.point(k, c)));
        let agree = area.dot(*reference);
        vote += if toggle { -agree } else { agree };
        if matches!(ribbon.pieces[k], PieceKind::Edge { .. }) {
            toggle = !toggle;
        }
    }
    let flip_first = vote < 0.0;
    parity.into_iter().map(|p| p != flip_first).collect()
}

/// The facets of piece `k`, its base loop reversed when `flip`.
fn piece_facets(ribbon: &Ribbon, k: usize, flip: bool) -> Vec<Vec<Corner>> {
    let p = |c: Corner| ribbon.point(k, c);
    let quad = base_loop(ribbon, k);
    let pts: Vec<DVec3> = quad.iter().map(|&c| p(c)).collect();
    let orient = |mut loop_: Vec<Corner>| {
        if flip {
            loop_.reverse();
        }
        loop_
    };
    if planarity_error(&pts) <= 1e-9 {
        return vec![orient(quad.to_vec())];
    }
    // Two triangles along the diagonal with the smaller fold.
    let fold = |t1: [usize; 3], t2: [usize; 3]| {
        let n = |t: [usize; 3]| vector_area(t.iter().map(|&i| pts[i])).normalize_or_zero();
        n(t1).angle_between(n(t2))
    };
    let (d02, d13) = (fold([0, 1, 2], [0, 2, 3]), fold([0, 1, 3], [1, 2, 3]));
    let tris = if d02 <= d13 {
        [[0, 1, 2], [0, 2, 3]]
    } else {
        [[0, 1, 3], [1, 2, 3]]
    };
    tris.iter()
        .map(|t| orient(t.iter().map(|&i| quad[i]).collect()))
        .collect()
}

/// A chain of pieces unrolled into the plane, one piece at a time.
struct Unrolled {
    /// 2D positions of the lines placed so far.
    lines: Vec<[DVec2; 2]>,
    /// Placed facets.
    facets: Vec<FlatFacet>,
    /// Their total area (mm²).
    area: f64,
    /// Frames of the placed facets (for holes and labels).
    frames: Vec<FacetFrame>,
}

impl Unrolled {
    /// Starts with the first line of piece `k`, placed as [`crate::flatten::flatten`]
    /// places a panel whose first facet is piece `k`'s first facet (its first corner
    /// at the origin, its first edge along +x), so that rotations tried here are the
    /// ones the nester tries.
    fn new(ribbon: &Ribbon, k: usize) -> Self {
        let facet = &ribbon.facets[k][0];
        let pts: Vec<DVec3> = facet.iter().map(|&c| ribbon.point(k, c)).collect();
        let normal = vector_area(pts.iter().copied()).normalize_or_zero();
        let frame = FacetFrame::on_hinge(pts[0], pts[1], normal, DVec2::ZERO, DVec2::X);
        let line = ribbon.lines[k % ribbon.lines.len()];
        Self {
            lines: vec![line.map(|p| frame.to_2d(p))],
            facets: Vec::new(),
            area: 0.0,
            frames: Vec::new(),
        }
    }

    /// Unrolls piece `k` across the last placed line. Returns `false` (and leaves the
    /// chain unusable) when a new facet overlaps or touches an earlier one.
    fn push(&mut self, ribbon: &Ribbon, k: usize) -> bool {
        let first_line = self.lines.len() - 1;
        let mut placed: [[Option<DVec2>; 2]; 2] = [[None; 2]; 2];
        placed[0] = self.lines[first_line].map(Some);
        let before = self.facets.len();
        for facet in &ribbon.facets[k] {
            let pts3: Vec<DVec3> = facet.iter().map(|&c| ribbon.point(k, c)).collect();
            let normal = vector_area(pts3.iter().copied()).normalize_or_zero();
            // A hinge: two consecutive corners already placed.
            let m = facet.len();
            let Some(i) = (0..m).find(|&i| {
                let (c, d) = (facet[i], facet[(i + 1) % m]);
                placed[c.line as usize][c.end as usize].is_some()
                    && placed[d.line as usize][d.end as usize].is_some()
            }) else {
                return false;
            };
            let (c, d) = (facet[i], facet[(i + 1) % m]);
            let frame = FacetFrame::on_hinge(
                ribbon.point(k, c),
                ribbon.point(k, d),
                normal,
                placed[c.line as usize][c.end as usize].unwrap_or_default(),
                placed[d.line as usize][d.end as usize].unwrap_or_default(),
            );
            for (j, &corner) in facet.iter().enumerate() {
                let slot = &mut placed[corner.line as usize][corner.end as usize];
                if slot.is_none() {
                    *slot = Some(frame.to_2d(pts3[j]));
                }
            }
            let poly: Vec<DVec2> = facet
                .iter()
                .map(|c| placed[c.line as usize][c.end as usize].unwrap_or_default())
                .collect();
            self.area += crate::plane::area(&poly);
            self.facets
                .push(FlatFacet::new(counter_clockwise(&poly), first_line));
            self.frames.push(frame);
        }
        self.lines.push([
            placed[1][0].unwrap_or_default(),
            placed[1][1].unwrap_or_default(),
        ]);
        // The new facets against all earlier ones.
        (before..self.facets.len())
            .all(|new| (0..before).all(|old| apart(&self.facets[new], &self.facets[old])))
    }

    /// All corner points placed so far.
    fn points(&self) -> Vec<DVec2> {
        self.lines.iter().flatten().copied().collect()
    }
}

/// A facet of an unrolled chain: its polygon (counter-clockwise) and the position of
/// its piece in the chain.
struct FlatFacet {
    poly: Vec<DVec2>,
    piece: usize,
    /// Corners of the polygon's bounding box.
    lo: DVec2,
    hi: DVec2,
}

impl FlatFacet {
    fn new(poly: Vec<DVec2>, piece: usize) -> FlatFacet {
        let lo = poly.iter().fold(DVec2::INFINITY, |m, &p| m.min(p));
        let hi = poly.iter().fold(DVec2::NEG_INFINITY, |m, &p| m.max(p));
        FlatFacet {
            poly,
            piece,
            lo,
            hi,
        }
    }
}

/// Pieces this close in a chain may come as close as they like (they meet at fold
/// lines and turn around one corner).
const NEAR_PIECES: usize = 4;

/// Two unrolled facets do not overlap, and if they are not near each other along the
/// chain, they are at least [`CLEARANCE`] apart (the cut between them must not merge).
fn apart(a: &FlatFacet, b: &FlatFacet) -> bool {
    // Boxes at least the clearance apart hold facets that are (the common case, cheap).
    let box_gap = (a.lo - b.hi).max(b.lo - a.hi);
    if box_gap.x >= CLEARANCE || box_gap.y >= CLEARANCE {
        return true;
    }
    if crate::plane::area(&clip_convex(&a.poly, &b.poly)) > OVERLAP_AREA {
        return false;
    }
    if a.piece.abs_diff(b.piece) <= NEAR_PIECES {
        return true;
    }
    let (p, q) = (&a.poly, &b.poly);
    let gap = (0..p.len())
        .flat_map(|i| (0..q.len()).map(move |j| (i, j)))
        .map(|(i, j)| segment_distance(p[i], p[(i + 1) % p.len()], q[j], q[(j + 1) % q.len()]))
        .fold(f64::INFINITY, f64::min);
    gap >= CLEARANCE && !contains(p, q[0]) && !contains(q, p[0])
}

/// True when the points fit the panel limit in one of its orientations, and their
/// most compact bounding box (over those orientations) lies along the sheet: a
/// segment that only fits across the sheet's diagonal would take a sheet of its own.
fn fits(points: &[DVec2], limit: &PanelLimit) -> bool {
    let hull = convex_hull(points);
    let steps = limit.rotations.max(1);
    let (w, h) = (limit.width - FIT_SLACK, limit.height - FIT_SLACK);
    let compact = smallest_box(&hull, steps);
    fits_rotated(&hull, steps, w, h)
        && ((compact.x <= w && compact.y <= h) || (compact.x <= h && compact.y <= w))
}

/// What a segment must respect besides not overlapping itself.
struct Limits {
    /// The largest panel a sheet takes.
    panel: Option<PanelLimit>,
    /// Largest ratio of its convex hull to its area.
    curl: f64,
}

/// A ribbon facet whose area is below this fraction of its crossing's squared
/// diameter has no direction to unroll in.
const DEGENERATE_AREA: f64 = 1e-9;

/// The face pieces of corner `i` (without its edge piece), as ring indices.
fn face_part(ribbon: &Ribbon, i: usize) -> std::ops::Range<usize> {
    let all = ribbon.corner_pieces(i);
    all.start..all.end - 1
}

/// The longest run of corners from `start` (at most `most`) that unrolls without
/// overlap and fits: the segment holds corners `start ..= start + len` (all of their
/// face pieces, and the edge pieces between them). `0` when not even one edge
/// crossing fits.
fn longest_run(ribbon: &Ribbon, start: usize, most: usize, limits: &Limits) -> usize {
    let limit = limits.panel.as_ref();
    let n = ribbon.edge_count();
    let first = face_part(ribbon, start);
    let mut chain = Unrolled::new(ribbon, first.start);
    if !first.clone().all(|k| chain.push(ribbon, k)) {
        return 0;
    }
    let mut len = 0;
    while len < most {
        let edge_piece = ribbon.corner_pieces(start + len).end - 1;
        let next = face_part(ribbon, (start + len + 1) % n);
        if !chain.push(ribbon, edge_piece) || !next.clone().all(|k| chain.push(ribbon, k)) {
            break;
        }
        let points = chain.points();
        let curls = len > 0 && crate::plane::area(&convex_hull(&points)) > limits.curl * chain.area;
        if curls || limit.is_some_and(|l| !fits(&points, l)) {
            break;
        }
        len += 1;
    }
    len
}

/// Cuts a ring into segments: `(first corner, corners spanned)` each, fewest segments
/// over the start positions tried (ties: the earliest start). `Err(corner)` when the
/// crossing after that corner alone does not fit.
fn plan_segments(ribbon: &Ribbon, limits: &Limits) -> Result<Vec<(usize, usize)>, usize> {
    let n = ribbon.edge_count();
    let greedy = |start: usize| -> Result<Vec<(usize, usize)>, usize> {
        let mut plan = Vec::new();
        let mut done = 0;
        while done < n {
            let corner = (start + done) % n;
            let len = longest_run(ribbon, corner, n - done, limits);
            if len == 0 {
                return Err(corner);
            }
            plan.push((corner, len));
            done += len;
        }
        Ok(plan)
    };
    let first = greedy(0)?;
    if first.len() == 1 {
        return Ok(first);
    }
    let tries = first[0].1.min(MAX_STARTS);
    let mut best = first;
    for start in 1..=tries {
        if let Ok(plan) = greedy(start % n) {
            if plan.len() < best.len() {
                best = plan;
            }
        }
    }
    Ok(best)
}

/// The error for a ribbon whose crossing after `corner` cannot be cut as a segment:
/// one over a face of almost no area, or one larger than the sheet.
fn crossing_error(r: &Ribbon, corner: usize) -> SchemeError {
    // The crossing: this corner's pieces and the next corner's face pieces.
    let ring = r.lines.len();
    let pieces = r.corner_pieces(corner).len() + face_part(r, corner + 1).len();
    let start = r.corner_start[corner];
    let points: Vec<DVec3> = (start..=start + pieces)
        .flat_map(|l| r.lines[l % ring])
        .collect();
    let across = crate::mesh::geometry::diameter(&points);
    let flat_facet = (start..start + pieces).any(|k| {
        let k = k % ring;
        r.facets[k].iter().any(|facet| {
            let corners = facet.iter().map(|&c| r.point(k, c));
            vector_area(corners).length() <= DEGENERATE_AREA * across * across
        })
    });
    let cycle = cycle_id(r.cycle);
    if flat_facet {
        SchemeError::Model(format!(
            "cycle {cycle}: one edge crossing of its ribbon crosses a face of almost no area (three corners in a line), which cannot be unrolled; simplify the model (--target-edges) or mend that face"
        ))
    } else {
        // Like a panel larger than the sheet: the size and the sheet asked for are
        // what does not go together (exit 2).
        SchemeError::Options(format!(
            "cycle {cycle}: one edge crossing of its ribbon is {across:.1} mm across and does not fit the sheet; use a larger --sheet or a smaller --size"
        ))
    }
}

/// Builds the woven panels: one per segment of every cycle's ribbon.
pub fn panels(mesh: &Mesh, options: &WovenOptions) -> Result<SchemeOutput, SchemeError> {
    let (ribbons, ribbon_notes) = ribbons(mesh, options)?;
    let limits = Limits {
        panel: options.panel.panel_limit,
        curl: options.curl_limit,
    };
    let plans: Vec<Vec<(usize, usize)>> = ribbons
        .par_iter()
        .map(|r| plan_segments(r, &limits).map_err(|corner| crossing_error(r, corner)))
        .collect::<Vec<_>>()
        // Collected in cycle order first, so that the error names the first cycle
        // that fails whatever the thread count.
        .into_iter()
        .collect::<Result<_, _>>()?;

    let mut panels = Panels::new();
    let mut cycles = Vec::new();
    let mut joint = 0u32;
    let mut joints_short = 0;
    let mut unfastened = Vec::new();
    for (ribbon, plan) in ribbons.iter().zip(&plans) {
        let m = plan.len();
        for (s, &(start, len)) in plan.iter().enumerate() {
            // Joint s is at the start of segment s, joint s + 1 at its end.
            let joints = [joint + s as u32, joint + ((s + 1) % m) as u32];
            let partners = [(s + m - 1) % m, (s + 1) % m];
            let (panel, at_start) = segment_panel(ribbon, s, start, len, joints, partners, options);
            // Both segments of a joint carry the same holes: count each joint at the
            // start of the segment after it.
            let wanted = options.panel.holes as usize;
            if wanted > 0 && at_start == 0 {
                let PieceKind::Face { corner } = ribbon.pieces[ribbon.corner_start[start]] else {
                    unreachable!("a face corner's pieces start in the face");
                };
                unfastened.push(ConnectionName {
                    panels: [
                        segment_id(ribbon.cycle, partners[0]),
                        segment_id(ribbon.cycle, s),
                    ],
                    at: Name::vertex(mesh.dest(corner).0),
                });
            } else if at_start < wanted {
                joints_short += 1;
            }
            panels.push(panel.view());
        }
        joint += m as u32;
        cycles.push(CycleSummary {
            id: ribbon.cycle + 1,
            edges: ribbon.edge_count(),
            length: ribbon.length(),
            segments: m,
        });
    }
    let mut notes = Vec::new();
    if joints_short > 0 {
        notes.push(format!(
            "{joints_short} of {joint} lap joints have fewer than {} fastener holes (but at least one): the strand is too narrow there for more; a smaller --hole-diameter or --hole-margin, or a larger --size, helps",
            options.panel.holes
        ));
    }
    if ribbon_notes.tight_corners > 0 {
        notes.push(format!(
            "{} face corners are too tight to turn between the crossing heights: strands may touch there; a smaller --band-scale gives them room",
            ribbon_notes.tight_corners
        ));
    }
    panels.shrink_to_fit();
    Ok(SchemeOutput {
        panels,
        connections: joint as usize,
        notes,
        report: cycle_report(&cycles),
        manifest: cycle_manifest(&cycles),
        unfastened,
        ..SchemeOutput::default()
    })
}

/// The panel of one segment: corners `start ..= start + len` of the ring (their face
/// pieces) and the edge pieces between them. Returns it with the number of holes of
/// the joint at its start.
fn segment_panel(
    ribbon: &Ribbon,
    segment: usize,
    start: usize,
    len: usize,
    joints: [u32; 2],
    partners: [usize; 2],
    options: &WovenOptions,
) -> (Panel, usize) {
    let ring = ribbon.pieces.len();
    let n = ribbon.edge_count();
    let first = ribbon.corner_start[start];
    let last_face = face_part(ribbon, (start + len) % n);
    // Pieces in chain order (ring indices): whole corners, then the last face part.
    let count = (start..start + len)
        .map(|i| ribbon.corner_pieces(i % n).len())
        .sum::<usize>()
        + last_face.len();
    let chain: Vec<usize> = (0..count).map(|j| (first + j) % ring).collect();
    let vertices: Vec<DVec3> = (0..=chain.len())
        .flat_map(|j| ribbon.lines[(first + j) % ring])
        .collect();
    let mut facets = Loops::new();
    let mut facet_start = Vec::new();
    for (j, &k) in chain.iter().enumerate() {
        facet_start.push(facets.len());
        for facet in &ribbon.facets[k] {
            facets.push(
                facet
                    .iter()
                    .map(|c| (2 * (j + c.line as usize) + c.end as usize) as u32),
            );
        }
    }
    let id = segment_id(ribbon.cycle, segment);
    let mut holes = Vec::new();
    let mut labels = Vec::new();
    let mut at_start = 0;

    // Lap joints at both ends: holes through the shared corner, and the id of the
    // segment joined there.
    let first_part = face_part(ribbon, start);
    let ends = [
        (0..first_part.len()).collect::<Vec<usize>>(),
        (chain.len() - last_face.len()..chain.len()).collect(),
    ];
    for (end, js) in ends.iter().enumerate() {
        let ks: Vec<usize> = js.iter().map(|&j| chain[j]).collect();
        let points = joint_holes(ribbon, &ks, options);
        if end == 0 {
            at_start = points.len();
        }
        let facet_index = |piece: usize, local: usize| facet_start[js[piece]] + local;
        for (p, piece, local) in points {
            holes.push(Hole {
                position: p,
                diameter: options.panel.hole_diameter,
                connection: joints[end],
                facet: facet_index(piece, local) as u32,
            });
        }
        let (piece, local) = largest_facet(ribbon, &ks);
        labels.push(strand_label(
            ribbon,
            ks[piece],
            local,
            facet_index(piece, local),
            segment_id(ribbon.cycle, partners[end]),
            LabelKind::Partner,
            options,
        ));
    }
    // At every crossing, the cycle that crosses there; the segment's id on the middle
    // crossing.
    let crossings: Vec<usize> = (0..chain.len())
        .filter(|&j| matches!(ribbon.pieces[chain[j]], PieceKind::Edge { .. }))
        .collect();
    for (c, &j) in crossings.iter().enumerate() {
        let k = chain[j];
        let PieceKind::Edge { crossing, .. } = ribbon.pieces[k] else {
            continue;
        };
        if c == crossings.len() / 2 {
            labels.push(strand_label(
                ribbon,
                k,
                0,
                facet_start[j],
                id,
                LabelKind::Panel,
                options,
            ));
        }
        labels.push(strand_label(
            ribbon,
            k,
            0,
            facet_start[j],
            cycle_id(crossing),
            LabelKind::Partner,
            options,
        ));
    }
    (
        Panel::new(
            Source {
                id: segment_id(ribbon.cycle, segment),
                covers: Covers::Itself,
            },
            vertices,
            facets,
            holes,
            labels,
        ),
        at_start,
    )
}

/// The largest facet among pieces `ks`: (position in `ks`, index within the piece).
fn largest_facet(ribbon: &Ribbon, ks: &[usize]) -> (usize, usize) {
    let mut best = (0, 0, -1.0);
    for (i, &k) in ks.iter().enumerate() {
        for (local, f) in ribbon.facet_points(k).iter().enumerate() {
            let area = vector_area(f.iter().copied()).length();
            if area > best.2 {
                best = (i, local, area);
            }
        }
    }
    (best.0, best.1)
}

/// A label on facet `local` of piece `k`, at the facet's centroid, reading along the
/// strand.
fn strand_label(
    ribbon: &Ribbon,
    k: usize,
    local: usize,
    facet: usize,
    text: Name,
    kind: LabelKind,
    options: &WovenOptions,
) -> Label {
    let pts = &ribbon.facet_points(k)[local];
    let centre = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
    let normal = vector_area(pts.iter().copied()).normalize_or_zero();
    let mid = |l: usize| {
        let [a, b] = ribbon.lines[l % ribbon.lines.len()];
        0.5 * (a + b)
    };
    let along = mid(k + 1) - mid(k);
    let direction = (along - along.dot(normal) * normal).normalize_or_zero();
    let length = along.length();
    Label {
        text,
        anchor: centre,
        direction,
        height: options.panel.label_height,
        facet: facet as u32,
        kind,
        on_edge: false,
        slide: 0.3 * length,
    }
}

/// Fastener holes of a lap joint on the face pieces `ks` of one corner: 3D points
/// with the piece (position in `ks`) and facet within it they go through, on the
/// strand's centre line (one at the middle, two at a third and two thirds), those
/// that fit.
fn joint_holes(
    ribbon: &Ribbon,
    ks: &[usize],
    options: &WovenOptions,
) -> Vec<(DVec3, usize, usize)> {
    let wanted = options.panel.holes as usize;
    if wanted == 0 || ks.is_empty() {
        return Vec::new();
    }
    let mut local = Unrolled::new(ribbon, ks[0]);
    let mut owner = Vec::new();
    for (i, &k) in ks.iter().enumerate() {
        local.push(ribbon, k);
        owner.extend((0..ribbon.facets[k].len()).map(|f| (i, f)));
    }
    let (a, b) = (local.lines[0], local.lines[local.lines.len() - 1]);
    let (ma, mb) = (0.5 * (a[0] + a[1]), 0.5 * (b[0] + b[1]));
    // The corner's outline: near ends along one side, far ends back along the other.
    let mut outline: Vec<DVec2> = local.lines.iter().map(|l| l[0]).collect();
    outline.extend(local.lines.iter().rev().map(|l| l[1]));
    let outline = counter_clockwise(&outline);
    let fractions: &[f64] = if wanted == 1 {
        &[0.5]
    } else {
        &[1.0 / 3.0, 2.0 / 3.0]
    };
    let radius = 0.5 * options.panel.hole_diameter;
    let mut points = Vec::new();
    let mut centres: Vec<DVec2> = Vec::new();
    for &f in fractions {
        let q = ma.lerp(mb, f);
        // The margin of material around the hole, and a diameter between holes.
        if !contains(&outline, q)
            || distance_to_border(&outline, q) < radius + options.panel.hole_margin
            || centres.iter().any(|c| c.distance(q) < 4.0 * radius)
        {
            continue;
        }
        let Some(i) = (0..local.facets.len()).find(|&i| contains(&local.facets[i].poly, q)) else {
            continue;
        };
        centres.push(q);
        let (piece, facet) = owner[i];
        points.push((local.frames[i].to_3d(q), piece, facet));
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strand_ends_stay_inside_the_band_side() {
        for t in [0.1, 0.5, 0.9] {
            let (lo, hi) = end_fractions(t);
            assert!(lo > 0.0 - 1e-12 && hi < 1.0 && lo < hi);
            assert!((hi - lo - t).abs() < 1e-12, "the end covers t of the side");
        }
    }

    #[test]
    fn the_other_visit_is_the_other_cycle() {
        assert_eq!(other_visit(&[3, 5], 3), 5);
        assert_eq!(other_visit(&[3, 5], 5), 3);
        assert_eq!(other_visit(&[4, 4], 4), 4);
    }
}
