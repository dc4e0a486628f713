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

use crate::mesh::geometry::vector_area;
use crate::mesh::Mesh;
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::{Covers, Hole, IdKind, Label, LabelKind, Loops, Name, Panel, Panels, Source};
use crate::plane::{contains, counter_clockwise, distance_to_border};
use crate::record::{round4, Params};
use crate::scheme::kit::thickness::{thickness, thickness_default};
use crate::scheme::{args_of, Configured, Configuring, OptionValues, PanelDefaults};
use crate::scheme::{ConnectionName, Scheme, SchemeError, SchemeOutput};
use crate::scheme::{PanelOptions, SchemeInfo};
use crate::units::fraction;

pub mod ergs;
pub mod options;
pub mod ribbon;
mod segments;

use options::{WovenArgs, WovenOptions, BAND_SCALE, CURL_LIMIT, THICKNESS};
use ribbon::{ribbons, PieceKind, Ribbon};
use segments::{face_part, plan_segments, Limits, Unrolled};

/// The woven scheme: plain-weaving ribbons from the extended graph rotation system.
pub struct Woven;

const INFO: SchemeInfo = SchemeInfo {
    name: "woven",
    about: "plain-weaving ribbons from the extended graph rotation system",
    defaults: PanelDefaults {
        // Below 1: the crossings lie between the face bands.
        face_scale: 0.8,
        holes: 2,
        holes_allowed: &[0, 1, 2],
    },
    // A strand cuts each face corner between two band sides.
    needs_convex_faces: true,
    overlap_fix: "a smaller --curl-limit (shorter, straighter segments)",
};

impl Scheme for Woven {
    fn info(&self) -> &SchemeInfo {
        &INFO
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

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        Ok(Box::new(WovenOptions::resolve(values, panel)?))
    }
}

impl WovenOptions {
    /// Checks the woven options' `values` and fills in their defaults. An error is a
    /// usage message naming the option.
    pub fn resolve(values: &OptionValues, panel: PanelOptions) -> Result<WovenOptions, String> {
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
        Ok(WovenOptions {
            panel,
            band_scale,
            thickness,
            curl_limit,
        })
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

/// A ribbon facet whose area is below this fraction of its crossing's squared
/// diameter has no direction to unroll in.
const DEGENERATE_AREA: f64 = 1e-9;

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
