//! The strip scheme: the model covered by developable strips within a distance of it,
//! both ways, each strip cut into pieces that fit the sheet, glue tabs on the curves
//! between strips.
//!
//! The strips follow the level curves of a field between two poles of each part of
//! the model, or from its holes' rims (`two_pole_field`); between two neighbouring curves, the band of
//! triangles that bends least (every corner on one of the two curves, so no vertex is
//! inside the band and it unrolls exactly; the dynamic programme of the strip paper,
//! `003`). A band whose strip strays from the model further than `--max-deviation`,
//! measured both ways, is cut across into sectors about as long as the sheet (along
//! the field's rise, from one curve to the other), and each sector is covered from its
//! lower curve up by bands as wide as keep their strips within, so that a sharp part
//! of a ring (an ear) does not narrow the strips round the rest (`strips_within`).
//! Where a sector meets one split differently, each point of one on the other's edge
//! becomes a corner of both. The strips are welded into one surface where they share
//! their curves' points; the net scheme's islands then grow along each strip's rungs
//! in order, so a piece is a run of its strip, as long as keeps it clear of itself
//! and on the sheet, and every curve between strips (and the rung between two
//! pieces) gets a tab with match numbers.

use std::collections::{BTreeMap, HashMap};

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::kit::tab::{tab_defaults, TabArgs, TAB_DEFAULTS};
use super::net::{
    islands_along, FlatFoldArgs, IslandNames, IslandNet, NetOptions, OwnNet, FLAT_FOLD_DEG,
};
use super::{args_of, Configured, OptionValues, PanelDefaults, PanelOptions};
use super::{Scheme, SchemeError, SchemeOutput};
use crate::mesh::distance::{segment_distance, TriangleGrid};
use crate::mesh::soup::{find, union};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::{IdKind, Name};
use crate::record::{round4, Params};

/// Strip pieces: `S3.2`, piece 2 of strip 3; `S3` for a strip in one piece.
pub static STRIP: IdKind = IdKind {
    letter: "S",
    legend: "strip piece (strip.piece)",
    noun: "strip",
    part_noun: "piece",
    layer: "",
};

/// The default `--max-deviation`: a percentage of the built model's bounding-box
/// diagonal, about what the eye takes for smooth at arm's length.
const MAX_DEVIATION_PERCENT: f64 = 0.5;

/// The strip scheme: developable strips within a distance of the model.
pub struct Strips;

/// The strip scheme's options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct StripArgs {
    #[command(flatten)]
    tab: TabArgs,

    #[command(flatten)]
    flat_fold: FlatFoldArgs,

    /// Largest distance between the strips and the model as given (before any
    /// simplifying), both ways (strip scheme): a length with a unit, or a percentage of
    /// the built model's bounding-box diagonal.
    #[arg(long, value_name = "LENGTH|P%")]
    max_deviation: Option<String>,
}

/// How far the strips may stray from the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Deviation {
    /// A length (mm).
    Length(f64),
    /// A fraction of the built model's bounding-box diagonal.
    Fraction(f64),
}

impl Deviation {
    /// Parses `--max-deviation`: `2mm`, `0.1in` or `0.5%`.
    fn parse(text: &str) -> Result<Deviation, String> {
        let fix = "write a length with a unit (2mm) or a percentage of the model's diagonal (0.5%)";
        let deviation = match text.trim().strip_suffix('%') {
            Some(percent) => percent
                .trim()
                .parse::<f64>()
                .map(|p| Deviation::Fraction(p / 100.0))
                .map_err(|_| format!("--max-deviation: '{text}' is not a percentage; {fix}"))?,
            None => crate::units::parse_length(text)
                .map(Deviation::Length)
                .map_err(|e| format!("--max-deviation: {e}"))?,
        };
        let value = match deviation {
            Deviation::Length(v) | Deviation::Fraction(v) => v,
        };
        if !(value > 0.0 && value.is_finite()) {
            return Err(format!(
                "--max-deviation: '{text}' must be above zero; {fix}"
            ));
        }
        Ok(deviation)
    }

    /// This bound `k` times over.
    fn times(self, k: f64) -> Deviation {
        match self {
            Deviation::Length(mm) => Deviation::Length(k * mm),
            Deviation::Fraction(f) => Deviation::Fraction(k * f),
        }
    }

    /// The distance (mm) for a model of bounding-box diagonal `diagonal` (mm).
    pub fn length(self, diagonal: f64) -> f64 {
        match self {
            Deviation::Length(mm) => mm,
            Deviation::Fraction(f) => f * diagonal,
        }
    }
}

/// As `--max-deviation` takes it: `2.5mm` or `1%`.
impl std::fmt::Display for Deviation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Deviation::Length(mm) => write!(f, "{}mm", round4(mm)),
            Deviation::Fraction(x) => write!(f, "{}%", round4(100.0 * x)),
        }
    }
}

/// The strip scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct StripOptions {
    /// The tabs, the sheet and the folds, as the net scheme takes them.
    pub net: NetOptions,
    /// `--max-deviation`.
    pub max_deviation: Deviation,
}

impl Scheme for Strips {
    fn name(&self) -> &'static str {
        "strip"
    }

    fn about(&self) -> &'static str {
        "developable strips within --max-deviation of the model, cut into pieces that fit the sheet, glue tabs between them"
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<StripArgs>(),
            &[
                tab_defaults(),
                OptionDefault::value("flat-fold", FLAT_FOLD_DEG),
                OptionDefault::words("max-deviation", "0.5%"),
            ],
        )
    }

    fn defaults(&self) -> PanelDefaults {
        TAB_DEFAULTS
    }

    fn needs_convex_faces(&self) -> bool {
        // Faces are fanned into triangles from their first corner.
        true
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --tab-height (shorter tabs)"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: StripArgs = values.parse()?;
        if panel.face_scale != 1.0 {
            return Err(format!(
                "--face-scale: the strip scheme keeps its strips whole (1), not {}; leave it out",
                panel.face_scale
            ));
        }
        let max_deviation = match args.max_deviation.as_deref() {
            Some(text) => Deviation::parse(text)?,
            None => Deviation::Fraction(MAX_DEVIATION_PERCENT / 100.0),
        };
        Ok(Box::new(StripOptions {
            net: NetOptions {
                rigid: super::rigid::sheet::RigidSheet::CARD,
                panel,
                tab_height: args.tab.height()?,
                max_island_faces: None,
                flat_fold: args.flat_fold.angle()?,
                island_spread: f64::INFINITY,
            },
            max_deviation,
        }))
    }
}

impl Configured for StripOptions {
    fn panel(&self) -> &PanelOptions {
        &self.net.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        strip_panels(mesh, self, None)
    }

    fn bounds_distance(&self) -> bool {
        true
    }

    fn build_near(
        &self,
        mesh: &Mesh,
        unsimplified: &[[DVec3; 3]],
    ) -> Result<SchemeOutput, SchemeError> {
        strip_panels(mesh, self, Some(unsimplified))
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("tab_height", round4(self.net.tab_height));
        params.push("flat_fold_deg", round4(self.net.flat_fold.to_degrees()));
        match self.max_deviation {
            Deviation::Length(mm) => params.push("max_deviation", round4(mm)),
            fraction => params.push("max_deviation", fraction.to_string()),
        }
        params
    }

    fn least_scored_fold(&self) -> f64 {
        self.net.flat_fold
    }

    fn panels_follow_faces(&self) -> bool {
        // Strips follow the field's levels, their width set by --max-deviation.
        false
    }

    fn larger_panels_fix(&self) -> &'static str {
        "a larger --max-deviation (wider strips) or a larger --size"
    }

    fn larger_panels(
        &self,
        mesh: &Mesh,
        unsimplified: Option<&[[DVec3; 3]]>,
        fits: &dyn Fn(&SchemeOutput) -> bool,
    ) -> Option<String> {
        // Strips widen about as the root of the bound: doubling it three times makes
        // them nearly three times wider.
        [2.0, 4.0, 8.0].into_iter().find_map(|k| {
            let wider = StripOptions {
                max_deviation: self.max_deviation.times(k),
                ..self.clone()
            };
            let output = strip_panels(mesh, &wider, unsimplified).ok()?;
            fits(&output).then(|| format!("--max-deviation {}", wider.max_deviation))
        })
    }
}

/// The strips of `mesh` within the bound, welded into one surface and cut into pieces
/// with tabs. When `mesh` was simplified from `unsimplified`, the bound holds to that.
fn strip_panels(
    mesh: &Mesh,
    options: &StripOptions,
    unsimplified: Option<&[[DVec3; 3]]>,
) -> Result<SchemeOutput, SchemeError> {
    let (lo, hi) = crate::mesh::geometry::bounding_box(mesh.positions().iter().copied());
    let bound = options.max_deviation.length((hi - lo).length());
    let surface = Triangles::from_mesh(mesh);
    let limit = options.net.panel.panel_limit;
    // Bands are cut across into sectors about as long as the sheet's shorter side: an
    // unrolled sector is an arc, and shorter arcs nest closer (docs/benchmarks.md).
    let sector_length = limit.map_or(f64::INFINITY, |l| l.width.min(l.height));
    // A strip longer than the sheet's longer side is cut into equal pieces no longer.
    let piece_length = limit.map_or(f64::INFINITY, |l| l.width.max(l.height));
    let covered_with =
        |closed: Closed| covered_with(&surface, closed, bound, unsimplified, sector_length);
    // A harmonic field between two poles stays nearly level along a dead end (a
    // horse's legs), too flat to split into bands; the distance from one pole rises
    // along every branch. The first failure is the one told.
    let covered = match covered_with(Closed::Harmonic) {
        Err(SchemeError::Model(why)) if closed_part(&surface) => {
            covered_with(Closed::Distance).map_err(|_| SchemeError::Model(why))
        }
        other => other,
    };
    // Where no strips cover a simplified mesh, a simplification that strays too far
    // is the cause to name first; a larger bound only where a band strayed (a strip
    // that folds round a coarse corner folds at any bound).
    let (covered, measured) = match (covered, unsimplified) {
        (Err(SchemeError::Model(why)), Some(given)) => {
            let apart = simplification_distance(bound, &surface.soup(), given);
            let refusal = too_simplified(bound, apart, why.contains(STAYS_OFF));
            return Err(refusal.unwrap_or(SchemeError::Model(why)));
        }
        (other, _) => other?,
    };
    let Covering {
        banded,
        welded,
        whole_bands,
        tolerance,
    } = covered;
    // Each curve's tabs on the strip below it: the strip above is glued over them.
    let tab_first = |h: HalfedgeId| {
        let strip = |h: HalfedgeId| welded.mesh.face(h).map(|f| welded.strip_of_face[f.index()]);
        strip(h) <= strip(h.twin())
    };
    let (net, members) = clear_pieces(&welded, &options.net, piece_length, &tab_first);
    let joined = welded.joined(&members);
    let mut output = net.output;
    let pieces = output.panels.len();
    output.report = vec![match unsimplified {
        None => format!(
            "strip: {} strips in {pieces} pieces, at most {measured:.2} mm from the model both ways as measured (bound {bound:.2} mm); each piece unrolls exactly",
            welded.strips
        ),
        Some(_) => format!(
            "strip: {} strips in {pieces} pieces, at most {measured:.2} mm from the model as given (before simplifying) both ways as measured (bound {bound:.2} mm; within {:.2} mm of the simplified model); each piece unrolls exactly",
            welded.strips, banded.deviation
        ),
    }];
    if tolerance < bound {
        output.notes.push(format!(
            "the strips are kept within {tolerance:.2} mm of the simplified model, not {bound:.2}: the simplification strays from the model too, and the bound holds to the model as given (a larger --target-edges, or none, gives wider strips)"
        ));
    }
    if whole_bands {
        output.report.push(format!(
            "strip: bands run whole round the model, not cut into sectors {sector_length:.0} mm long (strips of neighbouring bands overlapped)"
        ));
    }
    output
        .report
        .extend(net.summary.report("strip pieces", "pieces"));
    let mut section = net.summary.section("pieces");
    section["strips"] = welded.strips.into();
    section["max_deviation"] = round4(bound).into();
    section["measured_deviation"] = round4(measured).into();
    section["joined"] = joined
        .iter()
        .map(|(k, strip, faces)| {
            serde_json::json!({
                "piece": output.panels.get(*k).id().to_string(),
                "strip": strip,
                "faces": faces,
            })
        })
        .collect::<Vec<_>>()
        .into();
    if unsimplified.is_some() {
        section["simplified_bound"] = round4(tolerance).into();
        section["simplified_deviation"] = round4(banded.deviation).into();
    }
    output.manifest.push("strip", section);
    output.surface = Some(welded.mesh);
    Ok(output)
}

/// The strips of `surface` within `bound` of the model (of `unsimplified`, where the
/// surface was simplified from it), with `closed` parts' field, and the largest
/// distance measured.
fn covered_with(
    surface: &Triangles,
    closed: Closed,
    bound: f64,
    unsimplified: Option<&[[DVec3; 3]]>,
    sector_length: f64,
) -> Result<(Covering, f64), SchemeError> {
    let ridged = ridged(surface, closed);
    let surface = match ridged {
        true => surface.rims_apart(),
        false => surface.clone(),
    };
    let field = evened(
        &surface,
        &field_of(&surface, closed).map_err(SchemeError::Model)?,
    );
    let cover = |tolerance: f64| covering(&surface, &field, tolerance, sector_length, ridged);
    match unsimplified {
        None => {
            let covered = cover(bound)?;
            let measured = covered.banded.deviation;
            Ok((covered, measured))
        }
        Some(unsimplified) => within_unsimplified(bound, &surface.soup(), unsimplified, &cover),
    }
}

/// The strips of a surface within a tolerance, welded.
struct Covering {
    banded: Banded,
    welded: Welded,
    /// Bands were kept whole: their sectors' strips overlapped.
    whole_bands: bool,
    /// The tolerance the strips were kept within.
    tolerance: f64,
}

/// The strips of `surface` within `tolerance` ([`strips_within`]), welded into one
/// surface; where the sectors' strips of neighbouring bands overlap, every band whole.
fn covering(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
    ridged: bool,
) -> Result<Covering, SchemeError> {
    let within = |sector_length: f64, runs_back: RunsBack| {
        strips_ridged(surface, field, tolerance, sector_length, ridged, runs_back).map_err(|e| {
            let fix = covering_fix(surface, &e);
            SchemeError::Model(format!(
                "no strips within {tolerance:.3} mm of the model: {e}; {fix}"
            ))
        })
    };
    let mut banded = within(sector_length, RunsBack::Welded)?;
    let mut welded = Welded::new(&banded.strips);
    // Each band's sectors were checked to join as they were cut; where strips of
    // neighbouring bands still overlap, every band is kept whole instead, and where
    // they still do not join, a strip that runs back over itself is split as it is
    // made. The first failure is the one told.
    let mut whole_bands = false;
    let mut tries = Vec::new();
    if sector_length.is_finite() {
        tries.push((f64::INFINITY, RunsBack::Welded));
    }
    tries.push((sector_length, RunsBack::Made));
    for (length, runs_back) in tries {
        if welded.is_ok() {
            break;
        }
        let Ok(again) = within(length, runs_back) else {
            continue;
        };
        if let Ok(joined) = Welded::new(&again.strips) {
            whole_bands = length > sector_length;
            (banded, welded) = (again, Ok(joined));
        }
    }
    Ok(Covering {
        welded: welded.map_err(SchemeError::Model)?,
        banded,
        whole_bands,
        tolerance,
    })
}

/// How [`Cover::strips`] ends the error of a band that strays from the surface however
/// narrow it is split: the one failure a larger bound can mend.
const STAYS_OFF: &str = "mm from the surface";

/// What to do where no strips cover `surface`, given the reason `why`: a larger bound where
/// a band strays however narrow; elsewhere (a band whose strip folds over its outline
/// round a sharp corner however narrow, as on coarse or holed models) a larger bound
/// changes nothing, and the net scheme's islands build.
fn covering_fix(surface: &Triangles, why: &str) -> &'static str {
    match (why.ends_with(STAYS_OFF), rims(surface).is_empty()) {
        (true, _) => "a larger --max-deviation may reach",
        (false, true) => "a larger --max-deviation does not change that: use --scheme net",
        (false, false) => {
            "a larger --max-deviation does not change that: close the model's holes (--fill-holes) or use --scheme net"
        }
    }
}

/// How much further than the estimate of what the strips strayed a narrower try
/// narrows them: the narrower strips' worst point moves.
const NARROWER_MARGIN: f64 = 1.5;

/// How many narrower tries are made before the strips are kept within what the
/// simplification leaves of the bound (which holds, but makes them much narrower).
const MOST_NARROWER: usize = 3;

/// The least share of the bound the strips may be kept within of a simplified mesh:
/// narrower, they would be more than twice as many, and a simplification that leaves
/// them less is named as the fault.
const LEAST_SHARE: f64 = 0.25;

/// Strips within `bound` of `unsimplified` both ways, with the largest distance
/// measured. They are first kept within `bound` of the simplified mesh (`cover`); the
/// simplification's own error adds to theirs, so where they stray further from the
/// model as given, they are kept within less by what they strayed (sampled finely,
/// with a margin), and where that is not enough, within the bound less the largest
/// distance between `simplified` and `unsimplified`, which the triangle inequality
/// makes enough.
fn within_unsimplified(
    bound: f64,
    simplified: &[[DVec3; 3]],
    unsimplified: &[[DVec3; 3]],
    cover: &dyn Fn(f64) -> Result<Covering, SchemeError>,
) -> Result<(Covering, f64), SchemeError> {
    let spacing = bound / 3.0;
    // A bound that holds at every point, refined until settled against `within`.
    let beyond = |a: Soup, b: Soup, within: f64| {
        both_ways(a, b, &|from, to| {
            distance_beyond(from, to, spacing, within, f64::INFINITY)
        })
    };
    // The largest distance at samples a quarter as far apart: at most the true one.
    let sampled =
        |a: Soup, b: Soup| both_ways(a, b, &|from, to| one_way_distance(from, to, spacing / 4.0));
    let to_model =
        |covered: &Covering| beyond(&strip_soup(&covered.banded.strips), unsimplified, bound);
    // A narrower try that finds no strips says why it was narrower.
    let narrowed = |tolerance: f64| {
        cover(tolerance).map_err(|e| match e {
            SchemeError::Model(why) => {
                // `covering` names the mesh it covered "the model"; here it is the
                // simplified one.
                let why = why.replacen("of the model:", "of the simplified model:", 1);
                SchemeError::Model(format!(
                    "{why}, or less simplification (more --target-edges or --target-faces, or none): the strips were kept within {tolerance:.3} mm of the simplified model, not {bound:.3} mm, because it strays from the model as given"
                ))
            }
            other => other,
        })
    };
    let first = cover(bound)?;
    let measured = to_model(&first);
    if measured <= bound {
        return Ok((first, measured));
    }
    // Narrower tries, each by what the one before strayed beyond the bound (where the
    // finer samples find no point beyond it, the bound's own measure does): a band's
    // worst point moves with its width, so one narrowing may not be enough.
    let strayed = |covered: &Covering, measured: f64| match sampled(
        &strip_soup(&covered.banded.strips),
        unsimplified,
    ) {
        finer if finer > bound => finer,
        _ => measured,
    };
    let mut tolerance = bound;
    let mut beyond_by = strayed(&first, measured) - bound;
    drop(first);
    let mut last_try = None;
    for _ in 0..MOST_NARROWER {
        let narrower = tolerance - NARROWER_MARGIN * beyond_by;
        if narrower < LEAST_SHARE * bound {
            break;
        }
        let covered = narrowed(narrower)?;
        let measured = to_model(&covered);
        if measured <= bound {
            return Ok((covered, measured));
        }
        beyond_by = strayed(&covered, measured) - bound;
        tolerance = narrower;
        last_try = Some((covered, measured));
    }
    let simplification = simplification_distance(bound, simplified, unsimplified);
    let assured = bound - simplification;
    // Strips within `assured` of the simplified mesh keep the bound to the model as
    // given (the triangle inequality), even where the measured bound, which adds the
    // samples' reach, says a little more.
    let kept = |covered: Covering, measured: f64| {
        let measured = measured.min(covered.banded.deviation + simplification);
        (covered, measured)
    };
    match last_try {
        Some((covered, measured)) if covered.banded.deviation <= assured => {
            return Ok(kept(covered, measured));
        }
        _ => {}
    }
    if let Some(refusal) = too_simplified(bound, simplification, true) {
        return Err(refusal);
    }
    let last = narrowed(assured)?;
    let measured = to_model(&last);
    Ok(kept(last, measured))
}

/// Triangles, by their corners.
type Soup<'a> = &'a [[DVec3; 3]];

/// The larger of `one_way` from `a` to `b` and from `b` to `a`, each on its own thread.
fn both_ways(a: Soup, b: Soup, one_way: &(dyn Fn(Soup, Soup) -> f64 + Sync)) -> f64 {
    let (out, back) = rayon::join(|| one_way(a, b), || one_way(b, a));
    out.max(back)
}

/// How far `simplified` and `unsimplified` lie apart, both ways: a bound that holds at
/// every point (samples a third of `bound` apart), refined against what samples a
/// quarter as far apart find, so that it comes close to it.
fn simplification_distance(bound: f64, simplified: Soup, unsimplified: Soup) -> f64 {
    let spacing = bound / 3.0;
    let sampled = both_ways(simplified, unsimplified, &|from, to| {
        one_way_distance(from, to, spacing / 4.0)
    });
    both_ways(simplified, unsimplified, &|from, to| {
        distance_beyond(from, to, spacing, 1.05 * sampled, f64::INFINITY)
    })
}

/// The refusal of a simplification that lies `simplification` from the model as given,
/// where that leaves the strips less than [`LEAST_SHARE`] of `bound`; with the bound
/// that would leave them enough where `larger_bound_helps`.
fn too_simplified(
    bound: f64,
    simplification: f64,
    larger_bound_helps: bool,
) -> Option<SchemeError> {
    let larger = match larger_bound_helps {
        true => format!(
            " or allow at least {:.2} mm",
            simplification / (1.0 - LEAST_SHARE)
        ),
        false => String::new(),
    };
    (bound - simplification < LEAST_SHARE * bound).then(|| {
        SchemeError::Options(format!(
            "the simplified model lies up to {simplification:.2} mm from the model as given, which leaves the strips too little of --max-deviation ({bound:.2} mm): simplify less (more --target-edges or --target-faces, or none){larger}"
        ))
    })
}

/// The pieces: islands grown along the strips' rungs, in order, each strip longer than
/// `piece_length` first cut at rungs into equal pieces no longer. A piece whose outline,
/// tabs included, meets itself when unrolled (its faces wrap round a corner of its
/// strip's side until two of their edges lie on one line) is cut at its middle rung
/// and the pieces are grown again. A piece with no room for its id (a sliver where a
/// strip's two curves nearly touch, or a stub at a strip's end) is joined to the
/// neighbour piece it shares its longest edge with, or the next, as far as the join
/// keeps that piece clear of itself and on the sheet. Returns the net and each
/// piece's faces, in the order of its panels.
fn clear_pieces(
    welded: &Welded,
    options: &NetOptions,
    piece_length: f64,
    tab_first: &dyn Fn(HalfedgeId) -> bool,
) -> (IslandNet, Vec<Vec<u32>>) {
    // The faces of each piece, in the order of the panels, as the net names them.
    let members = std::cell::RefCell::new(Vec::new());
    let names = |faces: &[Vec<u32>]| {
        *members.borrow_mut() = faces.to_vec();
        welded.names(faces)
    };
    let mut folds = welded.shorter_than(piece_length);
    // Each piece without room for its id, by its lowest face: the edges it may join a
    // neighbour along, longest first, and which of them is tried.
    let mut joins: BTreeMap<u32, (Vec<EdgeId>, usize)> = BTreeMap::new();
    loop {
        let own = OwnNet {
            names: &names,
            tab_first,
            seams: true,
        };
        let mut along = folds.clone();
        along.extend(joins.values().filter_map(|(edges, k)| edges.get(*k)));
        let net = islands_along(&welded.mesh, options, &along, &IslandNames::Own(own));
        let faces_of = members.borrow();
        let cut = net.output.panels.iter().enumerate().find_map(|(k, panel)| {
            let flat = crate::flatten::flatten(panel).ok()?;
            if crate::plane::is_simple(&flat.outer()) {
                return None;
            }
            middle_rung(&welded.mesh, &faces_of[k], &folds)
        });
        if let Some(rung) = cut {
            folds.retain(|&e| e != rung);
            continue;
        }
        if !next_joins(
            &welded.mesh,
            &net.output,
            &faces_of,
            options.flat_fold,
            &mut joins,
        ) {
            drop(faces_of);
            return (net, members.take());
        }
    }
}

/// Updates the joins of pieces with no room for their id (`joins`, see
/// [`clear_pieces`]) after a net was grown with them (its ids fitted as the flatten
/// stage fits them, scoring folds over `least_fold`): a piece still without room
/// tries its next edge, a new one its first, and one whose last edge left it without
/// room drops that join, which only took its neighbour's room. False when nothing
/// changed.
fn next_joins(
    mesh: &Mesh,
    output: &SchemeOutput,
    faces_of: &[Vec<u32>],
    least_fold: f64,
    joins: &mut BTreeMap<u32, (Vec<EdgeId>, usize)>,
) -> bool {
    let labels = crate::labels::LabelOptions::default();
    let roomless: Vec<bool> = (0..output.panels.len())
        .into_par_iter()
        .map(|k| {
            crate::flatten::unroll_fit(output.panels.get(k), labels, least_fold)
                .is_ok_and(|(_, left)| left.panel > 0)
        })
        .collect();
    let mut piece_of = vec![usize::MAX; mesh.face_count()];
    for (k, faces) in faces_of.iter().enumerate() {
        for &f in faces {
            piece_of[f as usize] = k;
        }
    }
    let mut changed = false;
    for (k, faces) in faces_of.iter().enumerate() {
        if !roomless[k] {
            continue;
        }
        let tried = joins
            .iter_mut()
            .find(|(first, _)| piece_of[**first as usize] == k);
        match tried {
            // Past the last edge, no edge is tried (`edges.get` finds none).
            Some((_, (edges, next))) if *next < edges.len() => {
                *next += 1;
                changed = true;
            }
            Some(_) => {}
            None => {
                let piece = |f: u32| piece_of[f as usize];
                let edges = joining_edges(mesh, faces, &piece, &|k| !roomless[k]);
                changed |= !edges.is_empty();
                joins.insert(faces[0], (edges, 0));
            }
        }
    }
    changed
}

/// The longest edge between `faces` and each other piece that has room for its id
/// (`piece_of` a face, `roomy`), longest first: a join refused along one edge is
/// seldom made along a shorter one to the same piece.
fn joining_edges(
    mesh: &Mesh,
    faces: &[u32],
    piece_of: &dyn Fn(u32) -> usize,
    roomy: &dyn Fn(usize) -> bool,
) -> Vec<EdgeId> {
    let mut longest: BTreeMap<usize, (f64, EdgeId)> = BTreeMap::new();
    for h in faces.iter().flat_map(|&f| mesh.face_half_edges(FaceId(f))) {
        let Some(across) = mesh.face(h.twin()) else {
            continue;
        };
        let piece = piece_of(across.0);
        if faces.contains(&across.0) || !roomy(piece) {
            continue;
        }
        let edge = (mesh.edge_length(h.edge()), h.edge());
        let best = longest.entry(piece).or_insert(edge);
        if edge.0 > best.0 || (edge.0 == best.0 && edge.1 < best.1) {
            *best = edge;
        }
    }
    let mut edges: Vec<(f64, EdgeId)> = longest.into_values().collect();
    edges.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    edges.into_iter().map(|(_, e)| e).collect()
}

/// The fold between two faces of `faces` (a run of one strip) nearest its middle.
fn middle_rung(mesh: &Mesh, faces: &[u32], folds: &[EdgeId]) -> Option<EdgeId> {
    let mid = faces.len() / 2;
    let mut order: Vec<usize> = (1..faces.len()).collect();
    order.sort_by_key(|&k| k.abs_diff(mid));
    order.into_iter().find_map(|k| {
        shared_edge(mesh, FaceId(faces[k - 1]), FaceId(faces[k])).filter(|e| folds.contains(e))
    })
}

/// The edge faces `a` and `b` share, if they are neighbours.
fn shared_edge(mesh: &Mesh, a: FaceId, b: FaceId) -> Option<EdgeId> {
    mesh.face_half_edges(a)
        .find(|h| mesh.face(h.twin()) == Some(b))
        .map(|h| h.edge())
}

/// True when triangle `t` has an area above rounding noise (its height more than a
/// billionth of its longest side).
fn has_area(t: [DVec3; 3]) -> bool {
    let twice_area = (t[1] - t[0]).cross(t[2] - t[0]).length();
    let longest = longest_side(&t);
    twice_area > 2e-9 * longest * longest
}

/// The strips as one surface: a vertex per point they share (their curves' samples
/// are the same points on both sides), a face per triangle, strip after strip.
struct Welded {
    mesh: Mesh,
    /// The strip (from 0, counting strips with triangles) of each face.
    strip_of_face: Vec<u32>,
    /// The rungs between each strip's consecutive triangles, strip after strip.
    folds: Vec<EdgeId>,
    /// How many strips have triangles.
    strips: u32,
}

impl Welded {
    fn new(strips: &[Strip]) -> Result<Welded, String> {
        let mut vertex: HashMap<[u64; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::new();
        let mut strip_of_face = Vec::new();
        let mut count = 0;
        for strip in strips.iter().filter(|s| !s.triangles.is_empty()) {
            let ids: Vec<u32> = strip
                .points
                .iter()
                .map(|p| {
                    *vertex
                        .entry(p.to_array().map(f64::to_bits))
                        .or_insert_with(|| {
                            positions.push(*p);
                            positions.len() as u32 - 1
                        })
                })
                .collect();
            for t in &strip.triangles {
                // A triangle whose corners weld together or lie on a line (where two
                // curves touch) covers nothing; its strip goes on from the next one.
                if !has_area(t.map(|i| strip.points[i as usize])) {
                    continue;
                }
                faces.push(t.map(|i| ids[i as usize]));
                strip_of_face.push(count);
            }
            count += 1;
        }
        let mesh = crate::mesh::build::build_from_faces(positions, &faces).map_err(|e| {
            format!(
                "the strips do not join into one surface ({e}): a different --max-deviation may join them, or use --scheme net"
            )
        })?;
        let mut folds = Vec::new();
        for f in 1..faces.len() {
            if strip_of_face[f] != strip_of_face[f - 1] {
                continue;
            }
            folds.extend(shared_edge(&mesh, FaceId(f as u32 - 1), FaceId(f as u32)));
        }
        Ok(Welded {
            mesh,
            strip_of_face,
            folds,
            strips: count,
        })
    }

    /// The folds of the strips, less the rungs that cut each strip longer than
    /// `length` (along its faces' centres) into equal pieces no longer: a long ring
    /// unrolls into an arc that nests as badly as it is long.
    fn shorter_than(&self, length: f64) -> Vec<EdgeId> {
        if !length.is_finite() {
            return self.folds.clone();
        }
        // The middle of the rung between faces f - 1 and f (or of face f's corners).
        let centre = |f: usize| {
            let rung = (f > 0)
                .then(|| shared_edge(&self.mesh, FaceId(f as u32 - 1), FaceId(f as u32)))
                .flatten();
            match rung {
                Some(e) => {
                    let (a, b) = self.mesh.edge_vertices(e);
                    0.5 * (self.mesh.position(a) + self.mesh.position(b))
                }
                None => self.mesh.face_positions(FaceId(f as u32)).sum::<DVec3>() / 3.0,
            }
        };
        let mut cuts = std::collections::BTreeSet::new();
        let mut start = 0;
        while start < self.strip_of_face.len() {
            let strip = self.strip_of_face[start];
            let end = (start..self.strip_of_face.len())
                .find(|&f| self.strip_of_face[f] != strip)
                .unwrap_or(self.strip_of_face.len());
            let mut along = vec![0.0];
            for f in start + 1..end {
                along.push(along[along.len() - 1] + centre(f - 1).distance(centre(f)));
            }
            let total = along[along.len() - 1];
            let pieces = (total / length).ceil() as usize;
            for k in 1..pieces {
                let target = total * k as f64 / pieces as f64;
                let f = start + along.partition_point(|&a| a < target).max(1);
                if let Some(e) = shared_edge(&self.mesh, FaceId(f as u32 - 1), FaceId(f as u32)) {
                    cuts.insert(e);
                }
            }
            start = end;
        }
        self.folds
            .iter()
            .copied()
            .filter(|e| !cuts.contains(e))
            .collect()
    }

    /// The strip most of `faces` lie on (the lower on a tie): a piece with no room
    /// for its id that was joined to a neighbour goes by the neighbour's strip.
    fn strip_of(&self, faces: &[u32]) -> u32 {
        let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
        for &f in faces {
            *counts.entry(self.strip_of_face[f as usize]).or_default() += 1;
        }
        let most = counts.values().copied().max().unwrap_or(0);
        counts
            .into_iter()
            .find_map(|(strip, n)| (n == most).then_some(strip))
            .unwrap_or(0)
    }

    /// The pieces' names: `S<strip>.<piece>` along each strip (in the order of each
    /// piece's lowest face on it), `S<strip>` for a strip in one piece.
    fn names(&self, members: &[Vec<u32>]) -> Vec<Name> {
        let strips: Vec<u32> = members.iter().map(|faces| self.strip_of(faces)).collect();
        let first_on = |k: usize| {
            members[k]
                .iter()
                .copied()
                .find(|&f| self.strip_of_face[f as usize] == strips[k])
        };
        let mut order: Vec<usize> = (0..members.len()).collect();
        order.sort_by_key(|&k| (strips[k], first_on(k)));
        let mut pieces = vec![0u32; self.strips as usize];
        for &s in &strips {
            pieces[s as usize] += 1;
        }
        let mut names = vec![Name::new(&STRIP, 0); members.len()];
        let mut seen = vec![0u32; self.strips as usize];
        for k in order {
            let s = strips[k] as usize;
            seen[s] += 1;
            names[k] = match pieces[s] {
                1 => Name::new(&STRIP, s as u32 + 1),
                _ => Name::with_part(&STRIP, s as u32 + 1, seen[s]),
            };
        }
        names
    }

    /// The faces of each piece that lie on another strip than the one it is named
    /// after (pieces with no room for their id, joined to it), as (piece, strip from
    /// 1, faces).
    fn joined(&self, members: &[Vec<u32>]) -> Vec<(usize, u32, Vec<u32>)> {
        let mut joined = Vec::new();
        for (k, faces) in members.iter().enumerate() {
            let own = self.strip_of(faces);
            let mut others: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
            for &f in faces {
                let strip = self.strip_of_face[f as usize];
                if strip != own {
                    others.entry(strip).or_default().push(f);
                }
            }
            joined.extend(others.into_iter().map(|(s, faces)| (k, s + 1, faces)));
        }
        joined
    }
}

/// A surface as triangles over shared corners, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Triangles {
    pub points: Vec<DVec3>,
    pub corners: Vec<[u32; 3]>,
}

impl Triangles {
    /// The faces of `mesh`, each fanned from its first corner (the faces are convex).
    pub fn from_mesh(mesh: &Mesh) -> Triangles {
        let mut corners = Vec::new();
        for f in mesh.faces() {
            let ids: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
            for k in 1..ids.len().saturating_sub(1) {
                corners.push([ids[0], ids[k], ids[k + 1]]);
            }
        }
        Triangles {
            points: mesh.positions().to_vec(),
            corners,
        }
    }

    /// The surface with every edge that joins two rim points across it (not along a
    /// rim) split at its middle, the triangles beside it fanned from there: a distance
    /// from the rims is 0 all along such an edge, and no level curve could run
    /// between the rims it joins (a coarse model's holes, a triangle with its three
    /// corners on a rim). The same surface, with more corners.
    pub fn rims_apart(&self) -> Triangles {
        let on_rim: std::collections::BTreeSet<u32> = rims(self).into_iter().flatten().collect();
        let uses = edge_uses(&self.corners);
        let mut points = self.points.clone();
        let mut middles: BTreeMap<(u32, u32), u32> = BTreeMap::new();
        for (&(a, b), &n) in &uses {
            if n == 2 && on_rim.contains(&a) && on_rim.contains(&b) {
                middles.insert((a, b), points.len() as u32);
                points.push(0.5 * (self.points[a as usize] + self.points[b as usize]));
            }
        }
        let mut corners = Vec::with_capacity(self.corners.len());
        for t in &self.corners {
            // The triangle's outline with its middles, fanned from its first middle.
            let mut outline = Vec::with_capacity(6);
            for (a, b) in cycle_pairs(t) {
                outline.push(a);
                outline.extend(middles.get(&(a.min(b), a.max(b))));
            }
            match outline
                .iter()
                .position(|&i| i as usize >= self.points.len())
            {
                None => corners.push(*t),
                Some(first) => {
                    outline.rotate_left(first);
                    corners.extend(
                        (1..outline.len() - 1).map(|k| [outline[0], outline[k], outline[k + 1]]),
                    );
                }
            }
        }
        Triangles { points, corners }
    }

    /// The triangles by their corners' positions.
    pub fn soup(&self) -> Vec<[DVec3; 3]> {
        self.corners
            .iter()
            .map(|c| c.map(|i| self.points[i as usize]))
            .collect()
    }
}

/// A curve on the surface: a polyline, closed (its last point joins its first) or
/// open (its ends on the surface's boundary).
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub points: Vec<DVec3>,
    pub closed: bool,
}

/// The curves where `field` (a value per point of `surface`, linear over each
/// triangle) equals `level`, each running with the side above the level on its left
/// seen from outside. A point exactly at the level counts as above, so every curve
/// crosses edges between a point below and one above, never a corner.
pub fn level_curves(surface: &Triangles, field: &[f64], level: f64) -> Vec<Curve> {
    let above = |v: u32| field[v as usize] >= level;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // In a counter-clockwise triangle, the curve runs from the edge leaving the lone
    // corner above to the edge entering it (the corner on its left), and the other
    // way round a lone corner below.
    let mut next: BTreeMap<(u32, u32), (u32, u32)> = BTreeMap::new();
    for &[a, b, c] in &surface.corners {
        for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b)] {
            if above(x) != above(y) && above(x) != above(z) {
                let (leaving, entering) = (key(x, y), key(z, x));
                if above(x) {
                    next.insert(leaving, entering);
                } else {
                    next.insert(entering, leaving);
                }
            }
        }
    }
    let crossing = |(a, b): (u32, u32)| {
        let (fa, fb) = (field[a as usize], field[b as usize]);
        let t = ((level - fa) / (fb - fa)).clamp(0.0, 1.0);
        surface.points[a as usize].lerp(surface.points[b as usize], t)
    };
    chains(&next)
        .into_iter()
        .map(|(edges, closed)| Curve {
            points: edges.into_iter().map(crossing).collect(),
            closed,
        })
        .collect()
}

/// The chains of `next` (each key to the one after it): the open ones from the keys
/// nothing leads to, then the loops, each as its keys and whether it closes.
fn chains<K: Ord + Copy>(next: &BTreeMap<K, K>) -> Vec<(Vec<K>, bool)> {
    let entered: std::collections::BTreeSet<K> = next.values().copied().collect();
    let starts: Vec<K> = next
        .keys()
        .filter(|k| !entered.contains(k))
        .chain(next.keys())
        .copied()
        .collect();
    let mut done = std::collections::BTreeSet::new();
    let mut chains = Vec::new();
    for start in starts {
        if !done.insert(start) {
            continue;
        }
        let mut keys = vec![start];
        let mut at = start;
        let mut closed = false;
        while let Some(&n) = next.get(&at) {
            if n == start {
                closed = true;
                break;
            }
            if !done.insert(n) {
                break;
            }
            keys.push(n);
            at = n;
        }
        chains.push((keys, closed));
    }
    chains
}

/// `curve` with the fewest points (Douglas–Peucker) that keep every dropped point
/// within `tolerance` of the polyline kept; a loop keeps its first point and the
/// point farthest from it.
pub fn simplify(curve: &Curve, tolerance: f64) -> Curve {
    let keep = kept_points(&curve.points, curve.closed, tolerance);
    Curve {
        points: curve
            .points
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&q, _)| q)
            .collect(),
        closed: curve.closed,
    }
}

/// Which of the polyline's points [`simplify`] keeps.
fn kept_points(p: &[DVec3], closed: bool, tolerance: f64) -> Vec<bool> {
    if p.len() < 3 {
        return vec![true; p.len()];
    }
    let mut keep = vec![false; p.len()];
    keep[0] = true;
    if closed {
        let far = (1..p.len())
            .max_by(|&a, &b| p[a].distance(p[0]).total_cmp(&p[b].distance(p[0])))
            .unwrap_or(1);
        keep[far] = true;
        // And the point farthest from those two, so that a loop keeps an area.
        let third = (1..p.len()).filter(|&k| k != far).max_by(|&a, &b| {
            let d = |k: usize| segment_distance(p[k], p[0], p[far]);
            d(a).total_cmp(&d(b))
        });
        if let Some(third) = third {
            keep[third] = true;
        }
        keep_within(p, 0, far, tolerance, &mut keep);
        // The second half, round to the first point again.
        let mut round: Vec<DVec3> = p[far..].to_vec();
        round.push(p[0]);
        let mut kept = vec![false; round.len()];
        keep_within(&round, 0, round.len() - 1, tolerance, &mut kept);
        for (k, &flag) in kept.iter().enumerate().take(round.len() - 1) {
            keep[far + k] |= flag;
        }
    } else {
        let last = p.len() - 1;
        keep[last] = true;
        keep_within(p, 0, last, tolerance, &mut keep);
    }
    keep
}

/// Marks in `keep` the points between `from` and `to` that the polyline needs to stay
/// within `tolerance` of every point of `p` there.
fn keep_within(p: &[DVec3], from: usize, to: usize, tolerance: f64, keep: &mut [bool]) {
    let mut spans = vec![(from, to)];
    while let Some((a, b)) = spans.pop() {
        let far = (a + 1..b)
            .map(|k| (k, segment_distance(p[k], p[a], p[b])))
            .max_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((k, d)) = far {
            if d > tolerance {
                keep[k] = true;
                spans.push((a, k));
                spans.push((k, b));
            }
        }
    }
}

/// A band of triangles between two curves, each triangle sharing a rung (an edge from
/// one curve to the other) with the next: its corners, those of the first curve
/// first, and its triangles in order, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Strip {
    pub points: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// What a triangle facing away from the surface costs, in radians of bending: more
/// than any band bends.
const FOLD_COST: f64 = 1e4;

/// How much a rung's length counts against a radian of bending, per band width: the
/// rungs go across the band, not along it (in a narrow band a triangle's normal says
/// little about the surface, and bending alone would fan far along it), and among
/// bands that bend alike (a flat band bends nowhere) the one of shorter rungs wins.
const RUNG_WEIGHT: f64 = 0.25;

/// The band between the open polylines `p` (below, running with the band on its
/// left) and `q` (above, running the same way), from rung `p[0]q[0]` to the last
/// points' rung, that bends least: the dynamic programme over the triangles that
/// advance along one curve or the other, the cost of each the angle between its
/// normal and the previous triangle's.
pub fn band(p: &[DVec3], q: &[DVec3]) -> Strip {
    band_facing(p, q, None)
}

/// [`band`], with no triangle facing away from the surface where `facing` gives the
/// surface's normal at each point (of `p`, then of `q`): a band between curves that
/// bend (a sector's cut edges) could otherwise fold a triangle over a concave corner,
/// onto its neighbour. Where no band keeps to that, the one with fewest such.
fn band_facing(p: &[DVec3], q: &[DVec3], facing: Option<&[DVec3]>) -> Strip {
    let (n, m) = (p.len(), q.len());
    let points: Vec<DVec3> = p.iter().chain(q).copied().collect();
    if n == 0 || m == 0 || n + m < 3 {
        return Strip {
            points,
            triangles: Vec::new(),
        };
    }
    // The band's width: how far, on average, a point of one curve is from the other.
    let width = p
        .iter()
        .map(|a| {
            q.iter()
                .map(|b| a.distance(*b))
                .fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        / n as f64;
    let rungs = Rungs {
        width: width.max(1e-12),
        points: &points,
        n,
        m,
        facing,
    };
    let cost = rungs.costs();
    let triangles = rungs.trace_back(&cost);
    Strip { points, triangles }
}

/// The grid of rungs (i, j) from point i of the lower curve to point j of the upper
/// one, for the dynamic programme of [`band`].
struct Rungs<'a> {
    /// The lower curve's `n` points, then the upper curve's `m`.
    points: &'a [DVec3],
    n: usize,
    m: usize,
    /// The band's mean width, the unit of rung length.
    width: f64,
    /// The surface's normal at each point, if no triangle may face away from it.
    facing: Option<&'a [DVec3]>,
}

impl Rungs<'_> {
    /// The triangle reaching rung (i, j) from the previous rung: along the lower
    /// curve (`k` = 0, advancing i) or the upper one (`k` = 1, advancing j).
    fn triangle(&self, i: usize, j: usize, k: usize) -> [usize; 3] {
        let n = self.n;
        match k {
            0 => [i - 1, i, n + j],
            _ => [i, n + j, n + j - 1],
        }
    }

    /// The rung before (i, j) on the way `k`, if there is one.
    fn before(&self, i: usize, j: usize, k: usize) -> Option<(usize, usize)> {
        match k {
            0 => i.checked_sub(1).map(|i| (i, j)),
            _ => j.checked_sub(1).map(|j| (i, j)),
        }
    }

    /// Whether triangle `t` faces away from the surface at its corners.
    fn faces_away(&self, t: [usize; 3]) -> bool {
        self.facing
            .is_some_and(|normals| self.normal(t).dot(t.map(|i| normals[i]).iter().sum()) < 0.0)
    }

    fn normal(&self, t: [usize; 3]) -> DVec3 {
        let p = self.points;
        (p[t[1]] - p[t[0]])
            .cross(p[t[2]] - p[t[0]])
            .normalize_or_zero()
    }

    /// The bending between two triangles sharing a rung: the angle between their
    /// normals (a half turn where one has no area).
    fn bend(&self, a: [usize; 3], b: [usize; 3]) -> f64 {
        let (x, y) = (self.normal(a), self.normal(b));
        if x == DVec3::ZERO || y == DVec3::ZERO {
            std::f64::consts::PI
        } else {
            x.dot(y).clamp(-1.0, 1.0).acos()
        }
    }

    /// The cost of reaching rung (pi, pj) the way `h` and then going on with triangle
    /// `next`: its cost so far and the bend between the two triangles.
    fn through(
        &self,
        cost: &[[f64; 2]],
        (pi, pj): (usize, usize),
        h: usize,
        next: [usize; 3],
    ) -> f64 {
        let so_far = cost[pi * self.m + pj][h];
        if pi == 0 && pj == 0 {
            so_far
        } else {
            so_far + self.bend(self.triangle(pi, pj, h), next)
        }
    }

    /// `cost[i·m + j][k]`: the least cost of a band from rung (0, 0) to rung (i, j)
    /// whose last triangle went the way `k`.
    fn costs(&self) -> Vec<[f64; 2]> {
        let (n, m) = (self.n, self.m);
        let mut cost = vec![[f64::INFINITY; 2]; n * m];
        cost[0] = [0.0, 0.0];
        for i in 0..n {
            for j in 0..m {
                let length = self.points[i].distance(self.points[n + j]);
                for k in 0..2 {
                    let Some(from) = self.before(i, j, k) else {
                        continue;
                    };
                    let next = self.triangle(i, j, k);
                    let fold = match self.faces_away(next) {
                        true => FOLD_COST,
                        false => 0.0,
                    };
                    let best = (0..2)
                        .filter(|&h| cost[from.0 * m + from.1][h].is_finite())
                        .map(|h| self.through(&cost, from, h, next))
                        .fold(f64::INFINITY, f64::min);
                    cost[i * m + j][k] = best + fold + RUNG_WEIGHT * length / self.width;
                }
            }
        }
        cost
    }

    /// The band's triangles, in order: back from the last rung, each step the way
    /// that gave the rung its cost.
    fn trace_back(&self, cost: &[[f64; 2]]) -> Vec<[u32; 3]> {
        let (mut i, mut j) = (self.n - 1, self.m - 1);
        let last = cost[i * self.m + j];
        let mut k = usize::from(last[1] < last[0]);
        let mut triangles = Vec::with_capacity(self.n + self.m - 2);
        while let Some(from) = self.before(i, j, k) {
            let t = self.triangle(i, j, k);
            triangles.push(t.map(|v| v as u32));
            k = (0..2)
                .filter(|&h| cost[from.0 * self.m + from.1][h].is_finite())
                .min_by(|&a, &b| {
                    let (x, y) = (
                        self.through(cost, from, a, t),
                        self.through(cost, from, b, t),
                    );
                    x.total_cmp(&y)
                })
                .unwrap_or(0);
            (i, j) = from;
        }
        triangles.reverse();
        triangles
    }
}

/// The band between two loops, `p` below and `q` above, running the same way round:
/// cut open at the rung from `p`'s first point to the nearest point of `q`, which
/// then starts and ends both curves.
pub fn ring(p: &[DVec3], q: &[DVec3]) -> Strip {
    ring_facing(p, q, None)
}

/// [`ring`], with the surface's normal at each point of `p` and `q` as
/// [`band_facing`] takes them.
fn ring_facing(p: &[DVec3], q: &[DVec3], normals: Option<(&[DVec3], &[DVec3])>) -> Strip {
    let Some(first) = p.first() else {
        return band(p, q);
    };
    let start = (0..q.len())
        .min_by(|&a, &b| q[a].distance(*first).total_cmp(&q[b].distance(*first)))
        .unwrap_or(0);
    // Both loops opened and closed again: `p` from its first point, `q` from `start`.
    let open = |p: &[DVec3], start: usize| -> Vec<DVec3> {
        p[start..]
            .iter()
            .chain(&p[..start])
            .chain(p.get(start))
            .copied()
            .collect()
    };
    let facing = normals.map(|(np, nq)| {
        let mut both = open(np, 0);
        both.extend(open(nq, start));
        both
    });
    band_facing(&open(p, 0), &open(q, start), facing.as_deref())
}

/// The strip laid flat: a point per corner, each triangle placed against the rung it
/// shares with the one before, counter-clockwise as seen from outside, so every edge
/// keeps its length.
pub fn unroll(strip: &Strip) -> Vec<DVec2> {
    let mut flat: Vec<Option<DVec2>> = vec![None; strip.points.len()];
    let length = |a: u32, b: u32| strip.points[a as usize].distance(strip.points[b as usize]);
    for (n, t) in strip.triangles.iter().enumerate() {
        if n == 0 {
            let [a, b, _] = *t;
            flat[a as usize] = Some(DVec2::ZERO);
            flat[b as usize] = Some(DVec2::new(length(a, b), 0.0));
        }
        // Turn the triangle so that its corner not yet placed comes last.
        let Some(r) = (0..3).find(|&r| flat[t[(r + 2) % 3] as usize].is_none()) else {
            continue;
        };
        let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
        let (Some(pa), Some(pb)) = (flat[a as usize], flat[b as usize]) else {
            continue;
        };
        flat[c as usize] = Some(apex(pa, pb, length(a, c), length(b, c)));
    }
    flat.into_iter().map(Option::unwrap_or_default).collect()
}

/// The strip cut at rungs into pieces, each a run of its triangles (as ranges of
/// them), each as long as it can be while its unrolled shape (`flat`, from
/// [`unroll`]) `fits` and does not overlap itself. A lone triangle that does not fit
/// is a piece of its own.
pub fn pieces(
    strip: &Strip,
    flat: &[DVec2],
    fits: impl Fn(&[DVec2]) -> bool,
) -> Vec<std::ops::Range<usize>> {
    let corners = |t: usize| strip.triangles[t].map(|i| flat[i as usize]);
    let mut pieces = Vec::new();
    let mut start = 0;
    let mut points: Vec<DVec2> = Vec::new();
    for t in 0..strip.triangles.len() {
        let new = corners(t);
        let mut longer = points.clone();
        longer.extend(new);
        let overlaps = (start..t).any(|s| triangles_overlap(corners(s), new));
        if t > start && (overlaps || !fits(&longer)) {
            pieces.push(start..t);
            start = t;
            longer = new.to_vec();
        }
        points = longer;
    }
    if start < strip.triangles.len() {
        pieces.push(start..strip.triangles.len());
    }
    pieces
}

/// Whether `points` fit in a `width` × `height` rectangle turned by one of `steps`
/// equal steps of a half turn.
pub fn fits_turned(points: &[DVec2], width: f64, height: f64, steps: u32) -> bool {
    (0..steps.max(1)).any(|k| {
        let turn = DVec2::from_angle(std::f64::consts::PI * k as f64 / steps.max(1) as f64);
        let (lo, hi) = points.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| {
                let q = turn.rotate(p);
                (lo.min(q), hi.max(q))
            },
        );
        let size = hi - lo;
        (size.x <= width && size.y <= height) || (size.x <= height && size.y <= width)
    })
}

/// Whether the insides of two triangles overlap (touching along an edge or at a
/// corner does not count): no side of either separates them.
fn triangles_overlap(a: [DVec2; 3], b: [DVec2; 3]) -> bool {
    let scale = a
        .iter()
        .chain(&b)
        .map(|p| p.abs().max_element())
        .fold(1.0, f64::max);
    let slack = 1e-9 * scale;
    let separates = |t: [DVec2; 3], other: [DVec2; 3]| {
        (0..3).any(|k| {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            let edge = q - p;
            let inward = (t[(k + 2) % 3] - p).perp_dot(edge).signum();
            other
                .iter()
                .all(|&r| (r - p).perp_dot(edge) * inward <= slack * edge.length())
        })
    };
    !separates(a, b) && !separates(b, a)
}

/// The point at distances `ac` from `a` and `bc` from `b`, to the left of `a`→`b`.
fn apex(a: DVec2, b: DVec2, ac: f64, bc: f64) -> DVec2 {
    let ab = b.distance(a);
    if ab == 0.0 {
        return a;
    }
    let along = (ac * ac - bc * bc + ab * ab) / (2.0 * ab);
    let across = (ac * ac - along * along).max(0.0).sqrt();
    let x = (b - a) / ab;
    a + along * x + across * x.perp()
}

/// The largest distance from `from` to `to` (triangle sets), measured at points
/// spread over `from`'s triangles no further than `spacing` apart.
pub fn one_way_distance(from: &[[DVec3; 3]], to: &[[DVec3; 3]], spacing: f64) -> f64 {
    let grid = TriangleGrid::new(to);
    let mut hint = usize::MAX;
    from.iter().fold(0.0, |worst, t| {
        let k = subdivisions(longest_side(t), spacing);
        sampled_worst(&grid, t, k, worst, &mut hint)
    })
}

/// Samples along a side at the finest, where a triangle's samples leave open whether
/// it is within.
const FINEST_SUBDIVISIONS: usize = 256;

/// A bound of the largest distance from `from` to `to` that holds at every point:
/// the largest distance measured at samples no further than `spacing` apart, plus
/// how far a point can lie from its nearest sample. A triangle whose samples leave
/// open whether it is `within` is sampled finer; once the bound passes `limit`, some
/// bound beyond it.
fn distance_beyond(
    from: &[[DVec3; 3]],
    to: &[[DVec3; 3]],
    spacing: f64,
    within: f64,
    limit: f64,
) -> f64 {
    let grid = TriangleGrid::new(to);
    let mut bound: f64 = 0.0;
    // Neighbouring triangles of `from` mostly lie near the same triangle of `to`.
    let mut hint = usize::MAX;
    for t in from {
        let longest = longest_side(t);
        let mut k = subdivisions(longest, spacing);
        loop {
            // Every point of a triangle lies within its longest side over √3 of a
            // corner, and each sample triangle is this one shrunk k times.
            let reach = longest / k as f64 / 3f64.sqrt();
            let worst = sampled_worst(&grid, t, k, (bound - reach).max(0.0), &mut hint);
            let settled = worst + reach <= within || worst > within;
            if settled || k >= FINEST_SUBDIVISIONS {
                bound = bound.max(worst + reach);
                break;
            }
            k = (2 * k).min(FINEST_SUBDIVISIONS);
        }
        if bound > limit {
            break;
        }
    }
    bound
}

/// The longest side of triangle `t`.
fn longest_side(t: &[DVec3; 3]) -> f64 {
    [
        t[0].distance(t[1]),
        t[1].distance(t[2]),
        t[2].distance(t[0]),
    ]
    .into_iter()
    .fold(0.0, f64::max)
}

/// Samples along a side that put neighbouring samples no further than `spacing` apart
/// (at most 64).
fn subdivisions(longest: f64, spacing: f64) -> usize {
    ((longest / spacing.max(1e-12)).ceil() as usize).clamp(1, 64)
}

/// The largest of `floor` and the distances to `grid`'s triangles from the points
/// that divide `t`'s sides into `k`. Each point tries triangle `hint` first, and
/// leaves there the last found within the worst: neighbouring points mostly have the
/// same one within reach.
fn sampled_worst(
    grid: &TriangleGrid,
    t: &[DVec3; 3],
    k: usize,
    floor: f64,
    hint: &mut usize,
) -> f64 {
    let mut worst = floor;
    for i in 0..=k {
        for j in 0..=k - i {
            let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
            let point = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
            // A point with a triangle no further than the worst so far cannot raise
            // it: only the others are measured to their nearest.
            if !grid.reaches_near(point, worst, hint) {
                worst = worst.max(grid.distance(point));
            }
        }
    }
    worst
}

/// The triangles of `strips` by their corners' positions.
pub fn strip_soup(strips: &[Strip]) -> Vec<[DVec3; 3]> {
    strips
        .iter()
        .flat_map(|s| s.triangles.iter().map(|t| t.map(|i| s.points[i as usize])))
        .collect()
}

/// Where a point of the sliced surface comes from: a corner of the surface, or where
/// a level crosses one of its edges (the edge by its corners, lower first).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Origin {
    Corner(u32),
    Crossing { edge: (u32, u32), level: u32 },
}

impl Origin {
    /// Whether the point lies on the surface's edge `(a, b)` (lower first).
    fn on_edge(&self, edge: (u32, u32)) -> bool {
        match *self {
            Origin::Corner(v) => v == edge.0 || v == edge.1,
            Origin::Crossing { edge: e, .. } => e == edge,
        }
    }
}

/// The surface cut along the levels of a field: each triangle split into the convex
/// pieces between neighbouring levels, the pieces' corners shared.
pub struct Slices {
    /// The levels, increasing; band `k` lies between `levels[k]` and `levels[k + 1]`.
    pub levels: Vec<f64>,
    points: Vec<DVec3>,
    origins: Vec<Origin>,
    /// The field's value at each point.
    values: Vec<f64>,
    /// Each piece: its band and its corners (indices into `points`), counter-clockwise.
    pieces: Vec<(usize, Vec<u32>)>,
    /// The field's values the first and last levels stand for, where the surface is a
    /// patch whose outline lies on them (its corners there are on those levels).
    held: Option<[f64; 2]>,
}

/// A region of one band: the pieces of the band joined across their shared edges.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub band: usize,
    /// Its boundary loops, each with the region on its left seen from outside, as
    /// indices into the slices' points.
    pub loops: Vec<Vec<u32>>,
    /// Its pieces' triangles (fans of the convex pieces), for measuring.
    pub triangles: Vec<[DVec3; 3]>,
    /// Its pieces, as indices into the slices'.
    pieces: Vec<usize>,
}

impl Slices {
    /// `surface` cut along `levels` (increasing, none equal to a value of `field` at a
    /// corner, so every cut crosses edges between their ends). On a patch, its corners
    /// at the values `held` (below the second level and above the last but one) lie on
    /// the first and last levels.
    fn new(surface: &Triangles, field: &[f64], levels: Vec<f64>, held: Option<[f64; 2]>) -> Slices {
        let mut slices = Slices {
            levels,
            points: Vec::new(),
            origins: Vec::new(),
            values: Vec::new(),
            pieces: Vec::new(),
            held,
        };
        // Looked up only: points are numbered in the order they are first met.
        let mut ids: HashMap<Origin, u32> = HashMap::new();
        for corners in &surface.corners {
            // The triangle as (origin, value, position) corners.
            let start: Vec<(Origin, f64, DVec3)> = corners
                .iter()
                .map(|&v| {
                    (
                        Origin::Corner(v),
                        field[v as usize],
                        surface.points[v as usize],
                    )
                })
                .collect();
            let lo = start.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
            let hi = start.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
            for band in 0..slices.levels.len().saturating_sub(1) {
                let (below, above) = (slices.levels[band], slices.levels[band + 1]);
                if hi < below || lo > above {
                    continue;
                }
                let piece = clip(
                    &clip(&start, band as u32, below, true),
                    band as u32 + 1,
                    above,
                    false,
                );
                if piece.len() < 3 {
                    continue;
                }
                let corners = piece
                    .iter()
                    .map(|&(origin, value, position)| {
                        *ids.entry(origin).or_insert_with(|| {
                            slices.points.push(position);
                            slices.origins.push(origin);
                            slices.values.push(value);
                            slices.points.len() as u32 - 1
                        })
                    })
                    .collect();
                slices.pieces.push((band, corners));
            }
        }
        slices
    }

    /// The position of point `id`.
    pub fn point(&self, id: u32) -> DVec3 {
        self.points[id as usize]
    }

    /// The level point `id` lies on, if it is a crossing.
    pub fn level_of(&self, id: u32) -> Option<usize> {
        match self.origins[id as usize] {
            Origin::Crossing { level, .. } => Some(level as usize),
            Origin::Corner(_) => {
                let [below, above] = self.held?;
                let value = self.values[id as usize];
                match (value == below, value == above) {
                    (true, _) => Some(0),
                    (_, true) => Some(self.levels.len() - 1),
                    _ => None,
                }
            }
        }
    }

    /// Whether point `id` is where a level crosses an edge of the surface.
    fn is_crossing(&self, id: u32) -> bool {
        matches!(self.origins[id as usize], Origin::Crossing { .. })
    }

    /// The regions: per band, its pieces joined across shared edges, in band order
    /// and then by their first piece.
    pub fn regions(&self) -> Vec<Region> {
        self.regions_where(|_| true)
    }

    /// The regions of `band` alone (as [`Slices::regions`] gives them), without
    /// building the others.
    fn regions_of(&self, band: usize) -> Vec<Region> {
        self.regions_where(|b| b == band)
    }

    /// The regions of the bands `wanted` takes, in band order and then by their first
    /// piece.
    fn regions_where(&self, wanted: impl Fn(usize) -> bool) -> Vec<Region> {
        let mut parent: Vec<u32> = (0..self.pieces.len() as u32).collect();
        let mut first_by_edge: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for (k, (band, corners)) in self.pieces.iter().enumerate() {
            if !wanted(*band) {
                continue;
            }
            for (a, b) in cycle_pairs(corners) {
                match first_by_edge.entry((a.min(b), a.max(b))) {
                    std::collections::btree_map::Entry::Vacant(e) => {
                        e.insert(k);
                    }
                    std::collections::btree_map::Entry::Occupied(e) => {
                        let other = *e.get();
                        if self.pieces[other].0 == *band {
                            union(&mut parent, other as u32, k as u32);
                        }
                    }
                }
            }
        }
        let mut members: BTreeMap<(usize, u32), Vec<usize>> = BTreeMap::new();
        for k in (0..self.pieces.len()).filter(|&k| wanted(self.pieces[k].0)) {
            let r = find(&mut parent, k as u32);
            members.entry((self.pieces[k].0, r)).or_default().push(k);
        }
        members
            .into_iter()
            .map(|((band, _), pieces)| self.region(band, &pieces))
            .collect()
    }

    /// The region of `band` made of `pieces`: its boundary (the piece edges no other
    /// of its pieces shares) chained into loops, and its triangles.
    fn region(&self, band: usize, pieces: &[usize]) -> Region {
        let loops = boundary_loops(pieces.iter().flat_map(|&k| cycle_pairs(&self.pieces[k].1)));
        let triangles = self
            .fans(pieces)
            .map(|t| t.map(|i| self.point(i)))
            .collect();
        Region {
            band,
            loops,
            triangles,
            pieces: pieces.to_vec(),
        }
    }

    /// The triangles of `pieces`, each convex piece fanned from its first corner.
    fn fans<'a>(&'a self, pieces: &'a [usize]) -> impl Iterator<Item = [u32; 3]> + 'a {
        pieces.iter().flat_map(|&k| {
            let c = &self.pieces[k].1;
            (1..c.len() - 1).map(move |i| [c[0], c[i], c[i + 1]])
        })
    }
}

impl Slices {
    /// Which points the strips keep: the surface's corners `corner_kept` says, and of
    /// each level's curves the fewest points within `tolerance` of them
    /// ([`simplify`]), the same for the regions on either side of the curve.
    fn kept(&self, tolerance: f64, corner_kept: &dyn Fn(u32) -> bool) -> Vec<bool> {
        let mut keep: Vec<bool> = self
            .origins
            .iter()
            .map(|o| match *o {
                Origin::Corner(v) => corner_kept(v),
                Origin::Crossing { .. } => false,
            })
            .collect();
        // Each level's curves, from the edges of the pieces above it that lie on it.
        let mut next: BTreeMap<u32, u32> = BTreeMap::new();
        for (band, corners) in &self.pieces {
            for (a, b) in cycle_pairs(corners) {
                let on = |i: u32| self.is_crossing(i) && self.level_of(i) == Some(*band);
                if on(a) && on(b) {
                    next.insert(a, b);
                }
            }
        }
        for (ids, closed) in chains(&next) {
            let points: Vec<DVec3> = ids.iter().map(|&i| self.point(i)).collect();
            for (&id, k) in ids.iter().zip(kept_points(&points, closed, tolerance)) {
                keep[id as usize] |= k;
            }
        }
        keep
    }

    /// `region` as a patch of its own: its pieces fanned into triangles, keeping the
    /// points `kept`, between its band's levels (or the values they stand for).
    fn patch(&self, region: &Region, kept: &[bool]) -> Patch {
        let fans: Vec<[u32; 3]> = self.fans(&region.pieces).collect();
        let (ids, corners) = renumbered(&fans);
        let last = self.levels.len() - 1;
        let end = |level: usize| match (self.held, level) {
            (Some(held), 0) => held[0],
            (Some(held), l) if l == last => held[1],
            _ => self.levels[level],
        };
        Patch {
            surface: Triangles {
                points: ids.iter().map(|&i| self.point(i)).collect(),
                corners,
            },
            values: ids.iter().map(|&i| self.values[i as usize]).collect(),
            kept: ids.iter().map(|&i| kept[i as usize]).collect(),
            ends: [end(region.band), end(region.band + 1)],
        }
    }

    /// The strip of `region`, its corners the points `kept`: between its two loops
    /// (one on each level), or, for a region with one loop, between the run of that
    /// loop on its lower level (or half of it) and the rest.
    /// With `facing`, no triangle faces away from the surface ([`band_facing`]).
    fn strip(&self, region: &Region, kept: &[bool], facing: bool) -> Result<Strip, String> {
        let loops: Vec<Vec<u32>> = region
            .loops
            .iter()
            .map(|l| l.iter().copied().filter(|&i| kept[i as usize]).collect())
            .collect();
        let positions = |ids: &[u32]| ids.iter().map(|&i| self.point(i)).collect::<Vec<_>>();
        // A loop is on a level if all its points are: crossings of the level, or a rim
        // where the field is held at one value (a pole's) nearer that level.
        let on = |ids: &[u32], level: usize| {
            let rim = ids.iter().all(|&i| self.level_of(i).is_none())
                && ids
                    .windows(2)
                    .all(|w| self.values[w[0] as usize] == self.values[w[1] as usize]);
            let middle = 0.5 * (self.levels[region.band] + self.levels[region.band + 1]);
            match ids.first() {
                Some(&first) if rim => {
                    (self.values[first as usize] < middle) == (level == region.band)
                }
                _ => ids.iter().all(|&i| self.level_of(i) == Some(level)),
            }
        };
        let lower: Vec<Vec<u32>> = loops
            .iter()
            .filter(|l| on(l, region.band))
            .cloned()
            .collect();
        let upper: Vec<Vec<u32>> = loops
            .iter()
            .filter(|l| on(l, region.band + 1))
            .cloned()
            .collect();
        let unjoined = || {
            format!(
                "the {} boundary loops of a region between levels {} and {} are not joined \
                 by its pieces",
                loops.len(),
                region.band,
                region.band + 1
            )
        };
        if loops.is_empty() {
            return Err(format!(
                "a region between levels {} and {} has no boundary (a closed part)",
                region.band,
                region.band + 1
            ));
        }
        if !lower.is_empty() && !upper.is_empty() && lower.len() + upper.len() == loops.len() {
            // Loops on both levels (a saddle's region has two on one of them): the
            // loops of each level joined into one through the region, and the band
            // between the two.
            let below = self.bridged(region, &lower, kept).ok_or_else(unjoined)?;
            let mut above = self.bridged(region, &upper, kept).ok_or_else(unjoined)?;
            above.reverse();
            let normals = facing.then(|| self.normals(region));
            let along = |ids: &[u32], normals: &BTreeMap<u32, DVec3>| {
                ids.iter().map(|i| normals[i]).collect::<Vec<_>>()
            };
            let normals = normals.map(|n| (along(&below, &n), along(&above, &n)));
            let strip = ring_facing(
                &positions(&below),
                &positions(&above),
                normals.as_ref().map(|(b, a)| (&b[..], &a[..])),
            );
            return Ok(strip);
        }
        let one = self.bridged(region, &loops, kept).ok_or_else(unjoined)?;
        let normals = facing.then(|| self.normals(region));
        Ok(self.disk_strip(&one, region.band, normals.as_ref()))
    }

    /// Whether a triangle of `strip` (of `region`) faces away from the surface.
    fn folds(&self, region: &Region, strip: &Strip) -> bool {
        let normals = self.normals(region);
        let by_position: HashMap<[u64; 3], DVec3> = normals
            .iter()
            .map(|(&i, &n)| (self.point(i).to_array().map(f64::to_bits), n))
            .collect();
        let normal = |p: DVec3| by_position.get(&p.to_array().map(f64::to_bits)).copied();
        strip.triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| strip.points[i as usize]);
            let sum: Option<DVec3> = [a, b, c].into_iter().map(normal).sum();
            sum.is_some_and(|n| (b - a).cross(c - a).dot(n) < 0.0)
        })
    }

    /// The surface's normal at each corner of `region`'s pieces: the sum of its
    /// pieces' normals there, each as long as twice the piece's area.
    fn normals(&self, region: &Region) -> BTreeMap<u32, DVec3> {
        let mut normals: BTreeMap<u32, DVec3> = BTreeMap::new();
        for &k in &region.pieces {
            let normal: DVec3 = self
                .fans(std::slice::from_ref(&k))
                .map(|t| {
                    let [a, b, d] = t.map(|v| self.point(v));
                    (b - a).cross(d - a)
                })
                .sum();
            for &v in &self.pieces[k].1 {
                *normals.entry(v).or_insert(DVec3::ZERO) += normal;
            }
        }
        normals
    }

    /// The loops of `region` joined into one by bridges (the region then a disk, its
    /// bridges slits run out and back): each time the shortest path through the
    /// region's pieces from the loop joined so far to another loop, keeping of its
    /// corners those inside the region and the loops' kept points only (so that a
    /// neighbouring region meets the same points on their curve).
    fn bridged(&self, region: &Region, loops: &[Vec<u32>], kept: &[bool]) -> Option<Vec<u32>> {
        let mut loop_of: BTreeMap<u32, usize> = BTreeMap::new();
        for (k, l) in loops.iter().enumerate() {
            for &i in l {
                loop_of.insert(i, k);
            }
        }
        let boundary: std::collections::BTreeSet<u32> =
            region.loops.iter().flatten().copied().collect();
        // A bridge keeps the corners inside the region and the loops' kept points; it
        // passes the others of the boundary by.
        let stays =
            |i: u32| loop_of.contains_key(&i) || (!boundary.contains(&i) && kept[i as usize]);
        // Every two corners of a convex piece see each other inside it.
        let mut links: BTreeMap<u32, Vec<(u32, f64)>> = BTreeMap::new();
        for &k in &region.pieces {
            let corners = &self.pieces[k].1;
            for &a in corners {
                for &b in corners {
                    if a != b {
                        links
                            .entry(a)
                            .or_default()
                            .push((b, self.point(a).distance(self.point(b))));
                    }
                }
            }
        }
        let mut merged = loops.first()?.clone();
        let mut joined = vec![false; loops.len()];
        joined[0] = true;
        while joined.iter().any(|j| !j) {
            let (path, other) = shortest_bridge(&merged, &links, |i| {
                loop_of.get(&i).copied().filter(|&k| !joined[k])
            })?;
            joined[other] = true;
            let path: Vec<u32> = path.into_iter().filter(|&i| stays(i)).collect();
            let (from, to) = (path[0], path[path.len() - 1]);
            let at = merged.iter().position(|&i| i == from)?;
            let target = &loops[other];
            let start = target.iter().position(|&i| i == to)?;
            // Out along the bridge, round the other loop, back along the bridge.
            let mut insert: Vec<u32> = path[1..].to_vec();
            insert.extend(target[start + 1..].iter().chain(&target[..start]));
            insert.extend(path.iter().rev());
            merged.splice(at + 1..at + 1, insert);
        }
        Some(merged)
    }

    /// The strip of a region bounded by one loop (region on its left): from the ends of
    /// the loop's longest run on the lower level (or, on a loop with none or all of
    /// it, from its first point to the point halfway round), one side against the other.
    fn disk_strip(
        &self,
        ring_ids: &[u32],
        lower: usize,
        normals: Option<&BTreeMap<u32, DVec3>>,
    ) -> Strip {
        let n = ring_ids.len();
        let low = |k: usize| self.level_of(ring_ids[k % n]) == Some(lower);
        // The longest cyclic run of lower-level points: its start and length.
        let mut best = (0, 0);
        for start in (0..n).filter(|&k| low(k) && !low(k + n - 1)) {
            let length = (0..n).take_while(|&d| low(start + d)).count();
            if length > best.1 {
                best = (start, length);
            }
        }
        let (start, end) = if best.1 >= 2 && best.1 < n {
            (best.0, best.0 + best.1 - 1)
        } else {
            (0, n / 2)
        };
        let p: Vec<u32> = (start..=end).map(|k| ring_ids[k % n]).collect();
        // The other side, from before `start` back round to after `end`.
        let q: Vec<u32> = (1..n - (end - start))
            .map(|d| ring_ids[(start + n - d) % n])
            .collect();
        let facing: Option<Vec<DVec3>> =
            normals.map(|normals| p.iter().chain(&q).map(|i| normals[i]).collect());
        let at = |ids: &[u32]| ids.iter().map(|&i| self.point(i)).collect::<Vec<_>>();
        band_facing(&at(&p), &at(&q), facing.as_deref())
    }
}

/// Strips covering a surface, each within the distance asked of the part of the
/// surface it covers, both ways.
pub struct Banded {
    /// The strips, their outlines meeting point for point.
    pub strips: Vec<Strip>,
    /// The largest distance measured between a strip and the part it covers, either way.
    pub deviation: f64,
}

/// The part of the bound a curve's points may stray from it: the rest is the width of
/// the bands. (Along a sphere of radius R, a strip w wide between points a apart
/// strays about (a² + w²) / 8R.)
const SIMPLIFY: f64 = 0.15;

/// How many bands are tried for each band grown.
const MOST_TRIES: usize = 12;

/// How many times a part of the surface is split before the bound is given up on.
const MOST_SPLITS: usize = 40;

/// The strips of `surface` between levels of `field`, each within `tolerance` of the
/// part it covers (either way, measured at points `tolerance / 3` apart, allowing for
/// the points between). From one band over each part of the surface, a band whose
/// strip strays is cut across into sectors about `sector_length` long if it is longer
/// (a ring round a body strays where the body is sharpest, and the rest of it need not
/// be split with it), grown in bands from its lower curve up where it is a sector or a
/// cap round a pole, else split in halves (quarters where no one strip could be built,
/// as on a closed part); each sector and band on its own, until none strays.
pub fn strips_within(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
) -> Result<Banded, String> {
    let ridged = ridged(surface, Closed::Harmonic);
    strips_ridged(
        surface,
        field,
        tolerance,
        sector_length,
        ridged,
        RunsBack::Welded,
    )
}

/// [`strips_within`], where the field has ridges (a distance's, [`field_of`]) or not.
fn strips_ridged(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
    ridged: bool,
    runs_back: RunsBack,
) -> Result<Banded, String> {
    let (lo, hi) = field
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return Err("the surface has no points".into());
    }
    let span = (hi - lo).max(1e-9);
    let spacing = tolerance / 3.0;
    let cover = Cover {
        ridged,
        within: tolerance,
        simplify: SIMPLIFY * tolerance,
        spacing,
        sector_length,
        span,
        runs_back,
    };
    let whole = Patch {
        surface: surface.clone(),
        values: field.to_vec(),
        kept: vec![true; surface.points.len()],
        ends: [lo - 1e-3 * span, hi + 1e-3 * span],
    };
    let covered = cover.strips(&whole, Depth::default())?;
    let deviation = covered.iter().map(|c| c.1).fold(0.0, f64::max);
    let mut strips: Vec<Strip> = covered.into_iter().map(|c| c.0).collect();
    conform(&mut strips);
    Ok(Banded { strips, deviation })
}

/// How [`strips_within`] covers the surface.
#[derive(Clone, Copy)]
struct Cover {
    /// The field is a distance from rims, its saddles ridges ([`two_pole_field`]).
    ridged: bool,
    /// The distance a strip may lie from its part, at any point.
    within: f64,
    /// Each curve keeps the fewest points within this of it.
    simplify: f64,
    /// Samples for measuring lie no further apart than this.
    spacing: f64,
    /// Bands longer than this are cut into sectors before they are split.
    sector_length: f64,
    /// The field's span over the whole surface.
    span: f64,
    /// Where a strip that may fold runs back over its own triangles, it is found out.
    runs_back: RunsBack,
}

/// Where a strip allowed to fold (round a saddle or a ridge) running back over its own
/// triangles is found out: such a strip cannot be welded to its neighbours.
#[derive(Clone, Copy, PartialEq)]
enum RunsBack {
    /// When its band's strips are welded: a band cut into sectors is then cut into
    /// longer ones, which mends more of them than splitting them narrower does.
    Welded,
    /// When it is made: its part of the surface is split as if it strayed.
    Made,
}

/// A connected part of the surface between two values of the field, covered by
/// strips on its own.
struct Patch {
    surface: Triangles,
    /// The field at each point.
    values: Vec<f64>,
    /// Whether the strips must keep each point (its neighbours beyond the patch do).
    kept: Vec<bool>,
    /// The values of the curves it lies between; its points there are on them.
    ends: [f64; 2],
}

/// How deep a patch lies in the splitting, and whether its strips may fold over their
/// outline (where no band of it keeps from that).
#[derive(Clone, Copy, Debug, Default)]
struct Depth {
    splits: usize,
    folds: bool,
}

impl Depth {
    fn deeper(self) -> Depth {
        Depth {
            splits: self.splits + 1,
            ..self
        }
    }
}

/// A strip and the distance measured between it and its part of the surface.
type Covered = (Strip, f64);

impl Cover {
    /// The strips of `patch`: one if it is within, else those of its sectors or of
    /// the bands it is split into.
    fn strips(&self, patch: &Patch, depth: Depth) -> Result<Vec<Covered>, String> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let one = vec![lo - margin, hi + margin];
        let (whole, kept) = self.sliced(patch, one);
        let regions = whole.regions();
        if regions.len() > 1 {
            return self.each(&whole, &regions, &kept, depth.deeper());
        }
        let Some(region) = regions.first() else {
            return Ok(Vec::new());
        };
        let narrow = hi - lo < 1e-6 * self.span || depth.splits >= MOST_SPLITS;
        let deviation = match self.measured(&whole, region, &kept, depth.folds, f64::INFINITY) {
            Ok((strip, d)) if d <= self.within => return Ok(vec![(strip, d)]),
            Ok((_, d)) if narrow => {
                return Err(format!(
                    "a band of the field {lo}..{hi} stays {d:.3} {STAYS_OFF}"
                ))
            }
            Ok((_, d)) => d,
            Err(why) if narrow => return Err(why),
            Err(_) => f64::INFINITY,
        };
        // The first band grown's width, guessed from how far the patch's one strip
        // strayed: a strip's distance grows about as its width squared.
        let guess = match deviation.is_finite() {
            true => (hi - lo) * (self.within / deviation).sqrt(),
            false => 0.25 * (hi - lo),
        };
        let folding = Depth {
            folds: true,
            ..depth
        };
        match self.sectors(patch) {
            Sectors::Cut(sectors) => {
                let deeper = depth.deeper();
                let covered = flattened(sectors.par_iter().map(|s| self.strips(s, deeper)))?;
                if joined(&covered) {
                    return Ok(covered);
                }
                // A sector's strip folded over onto its neighbour (round a sharp tip):
                // this band is cut into sectors twice as long instead, and once they
                // would be longer than it, covered whole.
                let longer = Cover {
                    sector_length: 2.0 * self.sector_length,
                    ..*self
                };
                return longer.strips(patch, depth);
            }
            Sectors::Short => {
                if let Some(covered) = self.grown(patch, guess) {
                    return Ok(covered);
                }
                // Every strip of some band folds over its outline (round a saddle):
                // split it in two, taking such strips.
                return self.split(patch, deviation, folding);
            }
            // A cap grows from its pole (or up to it) in rings rather than being split:
            // split, its innermost band would be no wider than a cap can be.
            Sectors::Cap => {
                if let Some(covered) = self.grown(patch, guess) {
                    return Ok(covered);
                }
            }
            // Round a ridge of a distance field (where the rings round two rims meet)
            // the levels have corners, and a band's strip folds there however narrow.
            Sectors::Unfit if self.ridged => return self.split(patch, deviation, folding),
            Sectors::Unfit => {}
        }
        self.split(patch, deviation, depth)
    }

    /// The strips of `patch` split in equal bands: in two where its one strip was
    /// measured, four where no one strip could be built (a closed part, or one whose
    /// strip would fold over its outline). Only halves: a strip strays where the
    /// surface is sharpest, so more bands guessed from its distance would be as narrow
    /// everywhere else, and bands once split are never joined.
    fn split(&self, patch: &Patch, deviation: f64, depth: Depth) -> Result<Vec<Covered>, String> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let parts = match deviation.is_finite() {
            true => 2,
            false => 4,
        };
        let mut sorted = patch.values.clone();
        sorted.sort_by(f64::total_cmp);
        let mut levels = vec![lo - margin];
        levels.extend((1..parts).map(|k| {
            let t = k as f64 / parts as f64;
            off_values(lo + t * (hi - lo), &sorted)
        }));
        levels.push(hi + margin);
        let (split, kept) = self.sliced(patch, levels);
        self.each(&split, &split.regions(), &kept, depth.deeper())
    }

    /// `patch` cut along `levels` (its first and last outside it), and the points its
    /// strips keep: those its neighbours keep, and the fewest along each new curve.
    fn sliced(&self, patch: &Patch, levels: Vec<f64>) -> (Slices, Vec<bool>) {
        let slices = Slices::new(&patch.surface, &patch.values, levels, Some(patch.ends));
        let kept = slices.kept(self.simplify, &|v| patch.kept[v as usize]);
        (slices, kept)
    }

    /// The strips of each of `regions`, on its own (in parallel, in their order).
    fn each(
        &self,
        slices: &Slices,
        regions: &[Region],
        kept: &[bool],
        depth: Depth,
    ) -> Result<Vec<Covered>, String> {
        flattened(
            regions
                .par_iter()
                .map(|r| self.strips(&slices.patch(r, kept), depth)),
        )
    }

    /// The strip of `region` and the distance between them, either way (or, once it
    /// passes `limit`, some distance beyond it); an error for a strip that folds over
    /// its outline unless `folds`.
    fn measured(
        &self,
        slices: &Slices,
        region: &Region,
        kept: &[bool],
        folds: bool,
        limit: f64,
    ) -> Result<Covered, String> {
        let strip = slices.strip(region, kept, !folds)?;
        if strip.triangles.is_empty() {
            return Err(format!(
                "a region between levels {} and {} is too small for a triangle",
                region.band,
                region.band + 1
            ));
        }
        // Allowed to fold, a strip may still not run back over its own triangles
        // (round a bridge between two loops): it could not be welded to its neighbours.
        if folds && self.runs_back == RunsBack::Made && runs_back(&strip) {
            return Err(format!(
                "the strip of a region between levels {} and {} runs back over itself",
                region.band,
                region.band + 1
            ));
        }
        if !folds && slices.folds(region, &strip) {
            return Err(format!(
                "the strip of a region between levels {} and {} folds over its outline",
                region.band,
                region.band + 1
            ));
        }
        let soup = strip_soup(std::slice::from_ref(&strip));
        let measure = |from: &[[DVec3; 3]], to: &[[DVec3; 3]]| {
            distance_beyond(from, to, self.spacing, self.within, limit)
        };
        let out = measure(&soup, &region.triangles);
        if out > limit {
            return Ok((strip, out));
        }
        let back = measure(&region.triangles, &soup);
        Ok((strip, out.max(back)))
    }

    /// `patch` cut across, from its lower curve to its upper one, into sectors about
    /// [`Cover::sector_length`] long; `None` where it is shorter or has no way across.
    fn sectors(&self, patch: &Patch) -> Sectors {
        let corners = &patch.surface.corners;
        let [lo, hi] = patch.ends;
        let value = |i: u32| patch.values[i as usize];
        let loops = boundary_loops(corners.iter().flat_map(|t| cycle_pairs(t)));
        let lower: Vec<(Vec<u32>, bool)> = loops
            .iter()
            .flat_map(|l| runs(l, |i| value(i) == lo))
            .collect();
        let upper = loops
            .iter()
            .flat_map(|l| runs(l, |i| value(i) == hi))
            .count();
        match (loops.len(), lower.as_slice(), upper) {
            (1, [], 1) | (1, [(_, true)], 0) => return Sectors::Cap,
            _ => {}
        }
        let [(run, closed)] = lower.as_slice() else {
            return Sectors::Unfit;
        };
        let sources = self.cut_points(patch, run, *closed);
        if sources.is_empty() {
            return Sectors::Short;
        }
        // Only a ring between its two curves, or a disk with one run on each: round a
        // saddle the sectors would not be bands.
        let ring = loops.len() == 2 && *closed && upper == 1;
        let disk = loops.len() == 1 && upper == 1;
        if !ring && !disk || inner_extremum(patch, &loops) {
            return Sectors::Unfit;
        }
        let across = Across::new(patch, &loops);
        let mut cut: std::collections::BTreeSet<(u32, u32)> = Default::default();
        let mut on_cut = vec![false; patch.values.len()];
        for source in sources {
            let Some((path, _)) = shortest_bridge(&[source], &across.links, |i| {
                (value(i) == hi && patch.kept[i as usize]).then_some(0)
            }) else {
                continue;
            };
            for w in path.windows(2) {
                cut.insert((w[0].min(w[1]), w[0].max(w[1])));
            }
            for &i in &path {
                on_cut[i as usize] = true;
            }
        }
        let groups = joined_triangles(corners, &cut);
        if groups.len() < 2 {
            return Sectors::Unfit;
        }
        let kept = |i: u32| patch.kept[i as usize] || on_cut[i as usize];
        Sectors::Cut(groups.iter().map(|g| sub_patch(patch, g, &kept)).collect())
    }

    /// The strips of `patch` in bands from its lower curve up, each as wide as keeps
    /// its strips within (found by widening and halving the step from `first`, a
    /// guess), the last up to its upper curve.
    fn grown(&self, patch: &Patch, first: f64) -> Option<Vec<Covered>> {
        let [lo, hi] = patch.ends;
        let mut sorted = patch.values.clone();
        sorted.sort_by(f64::total_cmp);
        let least = 1e-6 * self.span;
        let mut covered = Vec::new();
        let mut from = lo;
        let mut step = first.max(least);
        while from < hi {
            // The widest band found within so far, and the narrowest found not.
            let mut within: Option<(f64, Vec<Covered>)> = None;
            let mut beyond = f64::INFINITY;
            for _ in 0..MOST_TRIES {
                let to = match from + step >= hi - 0.1 * step {
                    true => hi,
                    false => off_values(from + step, &sorted),
                };
                match self.band_within(patch, from, to) {
                    Some(strips) => within = Some((to, strips)),
                    None => beyond = beyond.min(to),
                }
                let reached = within.as_ref().map(|w| w.0);
                step = match (reached, beyond.is_finite()) {
                    (Some(to), _) if to >= hi => break,
                    (None, _) => 0.6 * (to - from),
                    (Some(to), false) => 1.5 * (to - from),
                    // Within a tenth of the widest band that can be: enough.
                    (Some(to), true) if beyond - to < 0.1 * (to - from) => break,
                    (Some(to), true) => 0.5 * (to - from + beyond - from),
                };
                if within.is_none() && step < least {
                    break;
                }
            }
            // A thin band left at the top: two bands of half the rest instead.
            let within = match within {
                Some((to, _)) if to < hi && hi - to < 0.5 * (to - from) => {
                    let half = off_values(0.5 * (from + hi), &sorted);
                    let balanced = self.band_within(patch, from, half);
                    balanced.map(|strips| (half, strips)).or(within)
                }
                within => within,
            };
            let (to, strips) = within?;
            step = to - from;
            covered.extend(strips);
            from = to;
        }
        Some(covered)
    }

    /// The strips of the band of `patch` between values `from` and `to`, if every one
    /// is within.
    fn band_within(&self, patch: &Patch, from: f64, to: f64) -> Option<Vec<Covered>> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let mut levels = vec![lo - margin];
        levels.extend([from, to].into_iter().filter(|&v| v > lo && v < hi));
        levels.push(hi + margin);
        let band = usize::from(from > lo);
        let (slices, kept) = self.sliced(patch, levels);
        let regions = slices.regions_of(band);
        let measured: Vec<Option<Covered>> = regions
            .par_iter()
            .map(|r| {
                let covered = self.measured(&slices, r, &kept, false, self.within).ok();
                covered.filter(|c| c.1 <= self.within)
            })
            .collect();
        measured.into_iter().collect()
    }
}

/// What cutting a patch across gives.
enum Sectors {
    /// The sectors.
    Cut(Vec<Patch>),
    /// None: the patch is no longer than a sector.
    Short,
    /// None: the patch is a cap, one loop round a pole.
    Cap,
    /// None: the patch is not a band between one run of each curve, or has no way across.
    Unfit,
}

impl Cover {
    /// Where to cut a run of a patch's outline on its lower curve: its kept points
    /// nearest even steps of [`Cover::sector_length`] or less along it (from its first
    /// point on a closed run, between its ends on an open one); none on a run too
    /// short to cut.
    fn cut_points(&self, patch: &Patch, run: &[u32], closed: bool) -> Vec<u32> {
        let at = |i: u32| patch.surface.points[i as usize];
        let mut along = vec![0.0];
        for w in run.windows(2) {
            along.push(along[along.len() - 1] + at(w[0]).distance(at(w[1])));
        }
        let total = match (closed, run.first(), run.last()) {
            (true, Some(&first), Some(&last)) => {
                along[along.len() - 1] + at(last).distance(at(first))
            }
            _ => along[along.len() - 1],
        };
        let sectors = (total / self.sector_length).ceil() as usize;
        if sectors < 2 {
            return Vec::new();
        }
        let steps = if closed { 0..sectors } else { 1..sectors };
        let mut points: Vec<u32> = steps
            .filter_map(|k| {
                let target = total * k as f64 / sectors as f64;
                (0..run.len())
                    .filter(|&j| patch.kept[run[j] as usize])
                    .min_by(|&a, &b| {
                        (along[a] - target)
                            .abs()
                            .total_cmp(&(along[b] - target).abs())
                    })
                    .map(|j| run[j])
            })
            .collect();
        points.dedup();
        points
    }
}

/// Whether the field has an extremum at a point of `patch` inside its outline `loops`
/// (the top of a bump, in a distance field): the patch is then no band, for its levels
/// ring the bump too and meet the band's at a saddle.
fn inner_extremum(patch: &Patch, loops: &[Vec<u32>]) -> bool {
    let outline: std::collections::BTreeSet<u32> = loops.iter().flatten().copied().collect();
    let n = patch.values.len();
    let (mut higher, mut lower) = (vec![false; n], vec![false; n]);
    for t in &patch.surface.corners {
        for (a, b) in cycle_pairs(t) {
            let (va, vb) = (patch.values[a as usize], patch.values[b as usize]);
            higher[a as usize] |= vb > va;
            lower[a as usize] |= vb < va;
        }
    }
    let used: std::collections::BTreeSet<u32> =
        patch.surface.corners.iter().flatten().copied().collect();
    used.iter()
        .any(|&v| !outline.contains(&v) && (!higher[v as usize] || !lower[v as usize]))
}

/// The ways across a patch: its edges between two of its triangles, each upward into
/// a point inside it or onto its outline's upper curve (so a cut runs from the lower
/// curve to the upper one without running along the outline or back down).
struct Across {
    links: BTreeMap<u32, Vec<(u32, f64)>>,
}

impl Across {
    fn new(patch: &Patch, loops: &[Vec<u32>]) -> Across {
        let outline: std::collections::BTreeSet<u32> = loops.iter().flatten().copied().collect();
        let uses = edge_uses(&patch.surface.corners);
        let upper = |i: u32| patch.values[i as usize] == patch.ends[1];
        let mut links: BTreeMap<u32, Vec<(u32, f64)>> = BTreeMap::new();
        for (&(a, b), &n) in &uses {
            if n != 2 {
                continue;
            }
            let length =
                patch.surface.points[a as usize].distance(patch.surface.points[b as usize]);
            for (from, to) in [(a, b), (b, a)] {
                // Only upward, so that each level between crosses the cut once; an edge
                // costs its length over its rise (the field's values are lengths),
                // times its length: a cut goes straight up rather than zigzag.
                let rise = patch.values[to as usize] - patch.values[from as usize];
                if rise > 0.0 && (!outline.contains(&to) || upper(to)) {
                    links
                        .entry(from)
                        .or_default()
                        .push((to, length * length / rise));
                }
            }
        }
        Across { links }
    }
}

/// Whether the strips of `covered` join into one surface where they meet (none folded
/// over onto another).
fn joined(covered: &[Covered]) -> bool {
    let mut strips: Vec<Strip> = covered.iter().map(|c| c.0.clone()).collect();
    conform(&mut strips);
    Welded::new(&strips).is_ok()
}

/// The results of `parts`, in order, each part's strips one after the other.
fn flattened(
    parts: impl IndexedParallelIterator<Item = Result<Vec<Covered>, String>>,
) -> Result<Vec<Covered>, String> {
    let parts: Vec<Result<Vec<Covered>, String>> = parts.collect();
    let mut all = Vec::new();
    for part in parts {
        all.extend(part?);
    }
    Ok(all)
}

/// The maximal runs of `outline` (a loop) whose points are `on`, each with whether
/// it is the whole loop.
fn runs(outline: &[u32], on: impl Fn(u32) -> bool) -> Vec<(Vec<u32>, bool)> {
    let n = outline.len();
    let Some(off) = (0..n).find(|&k| !on(outline[k])) else {
        return vec![(outline.to_vec(), true)];
    };
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for k in 1..=n {
        let i = outline[(off + k) % n];
        if on(i) {
            run.push(i);
        } else if !run.is_empty() {
            runs.push((std::mem::take(&mut run), false));
        }
    }
    runs
}

/// The triangles of `corners` joined across their shared edges but those of `cut`:
/// each group's triangles in order, the groups by their first.
fn joined_triangles(
    corners: &[[u32; 3]],
    cut: &std::collections::BTreeSet<(u32, u32)>,
) -> Vec<Vec<usize>> {
    let mut parent: Vec<u32> = (0..corners.len() as u32).collect();
    let mut first: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for (k, t) in corners.iter().enumerate() {
        for (a, b) in cycle_pairs(t) {
            let edge = (a.min(b), a.max(b));
            if cut.contains(&edge) {
                continue;
            }
            match first.get(&edge) {
                Some(&other) => union(&mut parent, other, k as u32),
                None => {
                    first.insert(edge, k as u32);
                }
            }
        }
    }
    let mut groups: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for k in 0..corners.len() {
        let root = find(&mut parent, k as u32);
        groups.entry(root).or_default().push(k);
    }
    let mut groups: Vec<Vec<usize>> = groups.into_values().collect();
    groups.sort_by_key(|g| g[0]);
    groups
}

/// The patch of `patch`'s `triangles`, its points renumbered in their order, keeping
/// those `kept` says, between the same ends.
fn sub_patch(patch: &Patch, triangles: &[usize], kept: &dyn Fn(u32) -> bool) -> Patch {
    let corners: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&k| patch.surface.corners[k])
        .collect();
    let (ids, corners) = renumbered(&corners);
    Patch {
        surface: Triangles {
            points: ids
                .iter()
                .map(|&i| patch.surface.points[i as usize])
                .collect(),
            corners,
        },
        values: ids.iter().map(|&i| patch.values[i as usize]).collect(),
        kept: ids.iter().map(|&i| kept(i)).collect(),
        ends: patch.ends,
    }
}

/// The points `corners` use, increasing, and the corners as indices into them.
fn renumbered(corners: &[[u32; 3]]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut ids: Vec<u32> = corners.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let index = |i: u32| ids.binary_search(&i).unwrap_or(0) as u32;
    let corners = corners.iter().map(|t| t.map(index)).collect();
    (ids, corners)
}

/// How far a point may be from an outline edge and count as on it (mm).
const ON_EDGE: f64 = 1e-6;

/// Every point of a strip's outline that lies inside an outline edge of another
/// strip (where a band split on its own meets one that is not) made a corner of that
/// edge too, its triangle fanned from the opposite corner, so the strips meet point
/// for point.
fn conform(strips: &mut [Strip]) {
    weld_near(strips);
    let outlines: Vec<Vec<(usize, u32, u32)>> = strips.iter().map(outline_of).collect();
    let mut lengths: Vec<f64> = Vec::new();
    let mut points: BTreeMap<[u64; 3], DVec3> = BTreeMap::new();
    for (strip, outline) in strips.iter().zip(&outlines) {
        for &(_, a, b) in outline {
            let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
            lengths.push(pa.distance(pb));
            points.insert(pa.to_array().map(f64::to_bits), pa);
        }
    }
    if lengths.is_empty() {
        return;
    }
    let cell = (lengths.iter().sum::<f64>() / lengths.len() as f64).max(1e-6);
    let at = |p: DVec3| (p / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<DVec3>> = HashMap::new();
    for p in points.values() {
        grid.entry(at(*p)).or_default().push(*p);
    }
    for (strip, outline) in strips.iter_mut().zip(outlines) {
        for (_, a, b) in outline {
            let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
            let inside = points_inside(pa, pb, cell, &|c| {
                grid.get(&at(c)).map_or(&[][..], |v| &v[..])
            });
            if !inside.is_empty() {
                split_outline_edge(strip, a, b, &inside);
            }
        }
    }
}

/// How close two points of the strips are taken for one (mm): the same crossing found
/// from levels a rounding apart.
const SAME_POINT: f64 = 1e-7;

/// The strips' points within [`SAME_POINT`] of each other moved onto one of them (the
/// least by its bits), so that strips meeting there share it.
fn weld_near(strips: &mut [Strip]) {
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let cell = 1e3 * SAME_POINT;
    let at = |p: DVec3| (p / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<DVec3>> = HashMap::new();
    let mut all: BTreeMap<[u64; 3], DVec3> = BTreeMap::new();
    for p in strips.iter().flat_map(|s| s.points.iter()) {
        all.insert(key(*p), *p);
    }
    for p in all.values() {
        grid.entry(at(*p)).or_default().push(*p);
    }
    let mut moved: HashMap<[u64; 3], DVec3> = HashMap::new();
    for p in all.values() {
        let mut least = *p;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let [x, y, z] = at(*p);
                    for &q in grid.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                        if q.distance(*p) < SAME_POINT && key(q) < key(least) {
                            least = q;
                        }
                    }
                }
            }
        }
        if least != *p {
            moved.insert(key(*p), least);
        }
    }
    for strip in strips.iter_mut() {
        for p in &mut strip.points {
            if let Some(&q) = moved.get(&key(*p)) {
                *p = q;
            }
        }
        collapse_short_edges(strip);
    }
}

/// `strip` with the ends of each of its outline edges that welding left without
/// length made one point, and the triangles left without area dropped (a crossing
/// welded onto the corner of its own edge). Its neighbours on either side of such a
/// triangle share the rung it had, so the strip still runs triangle by triangle. A
/// rung without length (where its two curves touch) stays: its two triangles are the
/// strip's only link there.
fn collapse_short_edges(strip: &mut Strip) {
    let mut parent: Vec<u32> = (0..strip.points.len() as u32).collect();
    let mut any = false;
    let uses = edge_uses(&strip.triangles);
    for t in &strip.triangles {
        for (a, b) in cycle_pairs(t) {
            let outline = uses[&(a.min(b), a.max(b))] == 1;
            if outline && strip.points[a as usize] == strip.points[b as usize] {
                union(&mut parent, a, b);
                any = true;
            }
        }
    }
    if !any {
        return;
    }
    let corners: Vec<[u32; 3]> = strip
        .triangles
        .iter()
        .map(|t| t.map(|v| find(&mut parent, v)))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    let (ids, corners) = renumbered(&corners);
    strip.points = ids.iter().map(|&i| strip.points[i as usize]).collect();
    strip.triangles = corners;
}

/// The points `near` gives (by the cell of a point) that lie inside segment `a`–`b`,
/// from `a`.
fn points_inside<'a>(
    a: DVec3,
    b: DVec3,
    cell: f64,
    near: &dyn Fn(DVec3) -> &'a [DVec3],
) -> Vec<DVec3> {
    let length = a.distance(b);
    let steps = (2.0 * length / cell).ceil() as usize + 1;
    let mut found: Vec<(f64, DVec3)> = Vec::new();
    let mut seen: std::collections::BTreeSet<[u64; 3]> = Default::default();
    for k in 0..=steps {
        let sample = a.lerp(b, k as f64 / steps as f64);
        for dx in [-1.0, 0.0, 1.0] {
            for dy in [-1.0, 0.0, 1.0] {
                for dz in [-1.0, 0.0, 1.0] {
                    for &p in near(sample + cell * DVec3::new(dx, dy, dz)) {
                        if p == a || p == b || !seen.insert(p.to_array().map(f64::to_bits)) {
                            continue;
                        }
                        let t = (p - a).dot(b - a) / (length * length);
                        if t > 0.0 && t < 1.0 && segment_distance(p, a, b) < ON_EDGE {
                            found.push((t, p));
                        }
                    }
                }
            }
        }
    }
    found.sort_by(|x, y| x.0.total_cmp(&y.0));
    found.into_iter().map(|f| f.1).collect()
}

/// Whether an edge of `strip` (its corners taken by position, as the strips are
/// welded) is a side of more than two of its triangles that cover something.
fn runs_back(strip: &Strip) -> bool {
    let mut id: HashMap<[u64; 3], u32> = HashMap::new();
    let welded: Vec<u32> = strip
        .points
        .iter()
        .map(|p| {
            let next = id.len() as u32;
            *id.entry(p.to_array().map(f64::to_bits)).or_insert(next)
        })
        .collect();
    let covering: Vec<[u32; 3]> = strip
        .triangles
        .iter()
        .filter(|t| has_area(t.map(|i| strip.points[i as usize])))
        .map(|t| t.map(|i| welded[i as usize]))
        .collect();
    edge_uses(&covering).values().any(|&n| n > 2)
}

/// How many of `triangles` use each edge (by its corners, lower first).
fn edge_uses(triangles: &[[u32; 3]]) -> BTreeMap<(u32, u32), u32> {
    let mut uses: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for t in triangles {
        for (a, b) in cycle_pairs(t) {
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    uses
}

/// The outline edges of `strip`: each triangle's side (index, from, to, as the
/// triangle runs) no other of its triangles has.
fn outline_of(strip: &Strip) -> Vec<(usize, u32, u32)> {
    let uses = edge_uses(&strip.triangles);
    let mut outline = Vec::new();
    for (k, t) in strip.triangles.iter().enumerate() {
        for (a, b) in cycle_pairs(t) {
            if uses[&(a.min(b), a.max(b))] == 1 {
                outline.push((k, a, b));
            }
        }
    }
    outline
}

/// `strip` with `inside` (points on its outline edge `a`→`b`, from `a`) made corners:
/// the edge's triangle fanned from its third corner, in the order that keeps each
/// triangle sharing a side with the next.
fn split_outline_edge(strip: &mut Strip, a: u32, b: u32, inside: &[DVec3]) {
    let Some(k) = strip
        .triangles
        .iter()
        .position(|t| cycle_pairs(t).any(|e| e == (a, b)))
    else {
        return;
    };
    let t = strip.triangles[k];
    let r = t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
    let first = strip.points.len() as u32;
    strip.points.extend_from_slice(inside);
    let chain: Vec<u32> = std::iter::once(a)
        .chain(first..first + inside.len() as u32)
        .chain(std::iter::once(b))
        .collect();
    let mut fan: Vec<[u32; 3]> = chain.windows(2).map(|w| [w[0], w[1], r]).collect();
    let has = |t: &[u32; 3], u: u32, v: u32| t.contains(&u) && t.contains(&v);
    let from_b = match k.checked_sub(1) {
        Some(before) => has(&strip.triangles[before], b, r),
        None => strip
            .triangles
            .get(k + 1)
            .is_some_and(|next| has(next, a, r)),
    };
    if from_b {
        fan.reverse();
    }
    strip.triangles.splice(k..k + 1, fan);
}

/// `level`, moved up past any value of the field exactly at it (a cut must cross
/// edges between their ends, never at a corner).
fn off_values(mut level: f64, sorted: &[f64]) -> f64 {
    while sorted.binary_search_by(|v| v.total_cmp(&level)).is_ok() {
        level = level.next_up();
    }
    level
}

/// The shortest path along `links` from any point of `from` to a point `target`
/// names a loop for, with that loop.
fn shortest_bridge(
    from: &[u32],
    links: &BTreeMap<u32, Vec<(u32, f64)>>,
    target: impl Fn(u32) -> Option<usize>,
) -> Option<(Vec<u32>, usize)> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let mut best: BTreeMap<u32, (f64, Option<u32>)> = BTreeMap::new();
    let mut queue = BinaryHeap::new();
    for &i in from {
        best.insert(i, (0.0, None));
        queue.push(Reverse((Distance(0.0), i)));
    }
    while let Some(Reverse((Distance(d), i))) = queue.pop() {
        if best.get(&i).is_some_and(|&(b, _)| d > b) {
            continue;
        }
        if let Some(other) = target(i) {
            let mut path = vec![i];
            let mut at = i;
            while let Some(&(_, Some(previous))) = best.get(&at) {
                path.push(previous);
                at = previous;
            }
            path.reverse();
            return Some((path, other));
        }
        for &(j, length) in links.get(&i).into_iter().flatten() {
            let through = d + length;
            if best.get(&j).is_none_or(|&(b, _)| through < b) {
                best.insert(j, (through, Some(i)));
                queue.push(Reverse((Distance(through), j)));
            }
        }
    }
    None
}

/// A path length ordered totally, for the search's queue.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Distance(f64);

impl Eq for Distance {}

impl PartialOrd for Distance {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Distance {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The consecutive pairs of a loop's corners, the last with the first.
fn cycle_pairs(corners: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    corners
        .iter()
        .copied()
        .zip(corners.iter().copied().cycle().skip(1))
}

/// The convex polygon `polygon` (corners with their field value) cut to the side of
/// `value` (level number `level`) above it (`keep_above`) or below it; new corners are
/// crossings of the surface's edges.
fn clip(
    polygon: &[(Origin, f64, DVec3)],
    level: u32,
    value: f64,
    keep_above: bool,
) -> Vec<(Origin, f64, DVec3)> {
    let inside = |f: f64| if keep_above { f > value } else { f < value };
    let mut out = Vec::with_capacity(polygon.len() + 2);
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        if inside(a.1) {
            out.push(a);
        }
        if inside(a.1) != inside(b.1) {
            let edge = surface_edge(a.0, b.0);
            // From the end first by position, so that two patches sharing the edge
            // find the same point to the bit.
            let key = |c: &(Origin, f64, DVec3)| c.2.to_array().map(f64::to_bits);
            let (from, to) = if key(&a) <= key(&b) { (a, b) } else { (b, a) };
            let t = (value - from.1) / (to.1 - from.1);
            out.push((
                Origin::Crossing { edge, level },
                value,
                from.2.lerp(to.2, t),
            ));
        }
    }
    out
}

/// The surface edge both points lie on: a cut crosses only edges of the triangle
/// (a level's own cut is never crossed by another level).
fn surface_edge(a: Origin, b: Origin) -> (u32, u32) {
    let ends = |o: Origin| match o {
        Origin::Corner(v) => [v, v],
        Origin::Crossing { edge, .. } => [edge.0, edge.1],
    };
    let candidates = ends(a).into_iter().chain(ends(b));
    let mut best = (0, 0);
    for x in candidates.clone() {
        for y in candidates.clone() {
            let edge = (x.min(y), x.max(y));
            if x != y && a.on_edge(edge) && b.on_edge(edge) {
                best = edge;
            }
        }
    }
    best
}

/// The field of each connected part of `surface`, from 0 to 1. On a closed part, or an
/// open tube, the harmonic field between two poles (0 at one, 1 at the other, the
/// cotangent Laplacian's zero elsewhere; faer's sparse Cholesky): level curves that
/// run round the part like parallels between its ends, with saddles only where its
/// shape needs them. The poles are the part's two points farthest apart, or the
/// tube's rims. On a part with other rims (holes, like a scan's), the distance from
/// them all ([`distance_from`]): a harmonic field crowds its levels along a ragged rim
/// or between two rims close together, too close for a strip between them.
pub fn two_pole_field(surface: &Triangles) -> Result<Vec<f64>, String> {
    field_of(surface, Closed::Harmonic)
}

/// What the field is on a closed part.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Closed {
    /// Harmonic between its two points farthest apart.
    Harmonic,
    /// The distance from the first of them ([`distance_from`]).
    Distance,
}

/// [`two_pole_field`], with `closed` parts' field as asked.
fn field_of(surface: &Triangles, closed: Closed) -> Result<Vec<f64>, String> {
    let n = surface.points.len();
    let weights = cotangent_weights(surface);
    let rims = rims(surface);
    let mut field = vec![0.0; n];
    for part in parts(surface) {
        let values = match pole_values(&surface.points, &part, &rims, closed) {
            Held::Poles(fixed) => solve_on(n, &part, &weights, &fixed, &|_| 0.0, &|_| 0.0)?,
            Held::Distance(from) => distance_from(surface, &part, &weights, &from)?,
        };
        for (&v, x) in part.iter().zip(values) {
            field[v as usize] = x;
        }
    }
    Ok(field)
}

/// The values at the points of `part` (in its order) that solve
/// `(K + diag(extra)) x = source` where they are free, `K` the Laplacian of `weights`,
/// with the values `fixed` held (faer's sparse Cholesky).
fn solve_on(
    n: usize,
    part: &[u32],
    weights: &[(u32, u32, f64)],
    fixed: &BTreeMap<u32, f64>,
    extra: &dyn Fn(u32) -> f64,
    source: &dyn Fn(u32) -> f64,
) -> Result<Vec<f64>, String> {
    let mut index = vec![usize::MAX; n];
    let free: Vec<u32> = part
        .iter()
        .copied()
        .filter(|v| !fixed.contains_key(v))
        .collect();
    for (k, &v) in free.iter().enumerate() {
        index[v as usize] = k;
    }
    let mut lower = Vec::new();
    let mut rhs: Vec<f64> = free.iter().map(|&v| source(v)).collect();
    let mut diagonal: Vec<f64> = free.iter().map(|&v| extra(v)).collect();
    for &(a, b, w) in weights {
        let (ia, ib) = (index[a as usize], index[b as usize]);
        for (i, j, other) in [(ia, ib, b), (ib, ia, a)] {
            if i == usize::MAX {
                continue;
            }
            diagonal[i] += w;
            if j != usize::MAX {
                if j < i {
                    lower.push(faer::sparse::Triplet::new(i, j, -w));
                }
            } else if let Some(value) = fixed.get(&other) {
                rhs[i] += w * value;
            }
        }
    }
    // A hair on the diagonal keeps the system definite where weights vanish.
    for (i, d) in diagonal.iter().enumerate() {
        lower.push(faer::sparse::Triplet::new(
            i,
            i,
            d + 1e-12 * d.abs().max(1.0),
        ));
    }
    let solution = solve_lower(free.len(), &lower, &rhs)?;
    let mut values = vec![0.0; n];
    for (&v, x) in free.iter().zip(solution) {
        values[v as usize] = x;
    }
    for (&v, &value) in fixed {
        values[v as usize] = value;
    }
    Ok(part.iter().map(|&v| values[v as usize]).collect())
}

/// How many screening lengths the heat of [`distance_from`] crosses a part in: more,
/// and it would fade below the solve's precision far from the rims.
const HEAT_REACH: f64 = 25.0;

/// The distance over `part` from its points `from` (its rims, or a pole), by the heat
/// method: heat held on them spreads a short way, its flow's direction, made unit, is
/// the distance's gradient, and a Poisson solve with them at 0 gives the distance,
/// scaled to 1 at its farthest point. Its levels near a rim run along it at a constant
/// distance however the rim is ragged or near another, where a harmonic field's crowd,
/// and they rise along every branch of a part, where a harmonic field between two
/// poles stays level along a dead end.
fn distance_from(
    surface: &Triangles,
    part: &[u32],
    weights: &[(u32, u32, f64)],
    from: &[u32],
) -> Result<Vec<f64>, String> {
    let n = surface.points.len();
    let at = |v: u32| surface.points[v as usize];
    let in_part = {
        let mut flags = vec![false; n];
        for &v in part {
            flags[v as usize] = true;
        }
        flags
    };
    let triangles: Vec<[u32; 3]> = surface
        .corners
        .iter()
        .copied()
        .filter(|t| in_part[t[0] as usize])
        .collect();
    let (lo, hi) = crate::mesh::geometry::bounding_box(part.iter().map(|&v| at(v)));
    let screening = (hi - lo).length() / HEAT_REACH;
    let mut mass = vec![0.0; n];
    for t in &triangles {
        let [a, b, c] = t.map(at);
        let third = (b - a).cross(c - a).length() / 6.0;
        for &v in t {
            mass[v as usize] += third;
        }
    }
    let hot: BTreeMap<u32, f64> = from.iter().map(|&v| (v, 1.0)).collect();
    let heat = solve_on(
        n,
        part,
        weights,
        &hot,
        &|v| mass[v as usize] / (screening * screening),
        &|_| 0.0,
    )?;
    let mut u = vec![0.0; n];
    for (&v, x) in part.iter().zip(heat) {
        u[v as usize] = x;
    }
    // The divergence at each point of the unit field pointing away from the heat.
    let mut divergence = vec![0.0; n];
    for t in &triangles {
        let Some((gradient, _)) = gradient_on(t.map(at), t.map(|v| u[v as usize])) else {
            continue;
        };
        let away = -gradient.normalize_or_zero();
        for k in 0..3 {
            let (i, j, l) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let [pi, pj, pl] = [i, j, l].map(at);
            divergence[i as usize] += 0.5
                * (cotangent(pl, pi, pj) * (pj - pi).dot(away)
                    + cotangent(pj, pl, pi) * (pl - pi).dot(away));
        }
    }
    let cold: BTreeMap<u32, f64> = from.iter().map(|&v| (v, 0.0)).collect();
    // The Laplacian of the distance is the divergence: K, the negative Laplacian,
    // takes its negative.
    let distance = solve_on(n, part, weights, &cold, &|_| 0.0, &|v| {
        -divergence[v as usize]
    })?;
    let far = distance.iter().copied().fold(0.0, f64::max);
    Ok(match far > 0.0 {
        true => distance.iter().map(|d| d.max(0.0) / far).collect(),
        false => distance,
    })
}

/// Bins of field values over which [`evened`] measures the surface's width per value.
const EVEN_BINS: usize = 512;

/// `field` remapped, by a function that only grows, so that equal steps of value are
/// about equally wide on the surface: a band of values [v, v + dv] is dv / |∇f| wide
/// where it crosses a triangle, and its width at v is the mean of that over the level
/// set (each triangle's area in the band over its area times its gradient). A
/// harmonic field crowds its levels near point poles; evened, bands split into equal
/// parts split into strips of equal width. The level curves are the same curves.
pub fn evened(surface: &Triangles, field: &[f64]) -> Vec<f64> {
    let (lo, hi) = field
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if hi.is_nan() || hi <= lo {
        return field.to_vec();
    }
    let step = (hi - lo) / EVEN_BINS as f64;
    let bin = |v: f64| (((v - lo) / step) as usize).min(EVEN_BINS - 1);
    // Per bin: the area of the triangles in it, and that area times their gradient.
    let mut area = vec![0.0; EVEN_BINS];
    let mut area_gradient = vec![0.0; EVEN_BINS];
    for t in &surface.corners {
        let [fa, fb, fc] = t.map(|i| field[i as usize]);
        let Some((gradient, twice)) =
            gradient_on(t.map(|i| surface.points[i as usize]), [fa, fb, fc])
        else {
            continue;
        };
        let g = gradient.length();
        let (first, last) = (bin(fa.min(fb).min(fc)), bin(fa.max(fb).max(fc)));
        let share = 0.5 * twice / (last - first + 1) as f64;
        for k in first..=last {
            area[k] += share;
            area_gradient[k] += share * g;
        }
    }
    // Widths per unit of value; bins no triangle reaches keep a sliver of width, so the
    // remap still grows there.
    let widths: Vec<f64> = (0..EVEN_BINS)
        .map(|k| match area_gradient[k] > 0.0 {
            true => area[k] / area_gradient[k],
            false => 0.0,
        })
        .collect();
    let floor = 1e-6 * widths.iter().copied().fold(0.0, f64::max).max(1e-300);
    let mut at = vec![0.0; EVEN_BINS + 1];
    for k in 0..EVEN_BINS {
        at[k + 1] = at[k] + step * widths[k].max(floor);
    }
    field
        .iter()
        .map(|&v| {
            let k = bin(v);
            let t = ((v - lo) / step - k as f64).clamp(0.0, 1.0);
            at[k] + t * (at[k + 1] - at[k])
        })
        .collect()
}

/// How the field is held on a part.
enum Held {
    /// At these values at these points, harmonic between.
    Poles(BTreeMap<u32, f64>),
    /// At 0 at these points (rims, or a pole), the distance from them elsewhere.
    Distance(Vec<u32>),
}

/// How the field is held on `part`: at 0 and 1 at its two points farthest apart on a
/// closed part, or on its two rims on an open tube or an annulus; else at 0 on all its
/// rims, the distance from them elsewhere.
fn pole_values(points: &[DVec3], part: &[u32], rims: &[Vec<u32>], closed: Closed) -> Held {
    let in_part: Vec<&Vec<u32>> = rims
        .iter()
        .filter(|r| part.binary_search(&r[0]).is_ok())
        .collect();
    let at = |v: u32| points[v as usize];
    let held = |zero: &[u32], one: &[u32]| {
        let zeros = zero.iter().map(|&v| (v, 0.0));
        Held::Poles(zeros.chain(one.iter().map(|&v| (v, 1.0))).collect())
    };
    // The distance from point `v` to the nearest point of `rims`.
    let nearest = |rims: &[&Vec<u32>], v: u32| {
        rims.iter()
            .flat_map(|r| r.iter())
            .map(|&r| at(r).distance(at(v)))
            .fold(f64::INFINITY, f64::min)
    };
    // The distance from every rim (one rim, or holes in one side of the part, like a
    // scan's base).
    let from_rims =
        |rims: &[&Vec<u32>]| Held::Distance(rims.iter().flat_map(|r| r.iter().copied()).collect());
    match in_part.as_slice() {
        [] => match (poles(points, part), closed) {
            ([one, other], Closed::Harmonic) => held(&[one], &[other]),
            ([one, _], Closed::Distance) => Held::Distance(vec![one]),
        },
        [_] => from_rims(&in_part),
        // Several rims: the two whose centres lie farthest apart, where no point of the
        // part lies farther from both than they lie from each other (an open tube's
        // ends, an annulus's edges). Rims closer together than the rest of the part
        // reaches are held as one: held apart, they would leave the field flat there.
        rims => {
            let centre = |r: &[u32]| r.iter().map(|&v| at(v)).sum::<DVec3>() / r.len() as f64;
            let mut best = (0, 1, f64::NEG_INFINITY);
            for i in 0..rims.len() {
                for j in i + 1..rims.len() {
                    let d = centre(rims[i]).distance(centre(rims[j]));
                    if d > best.2 {
                        best = (i, j, d);
                    }
                }
            }
            let (one, other) = (rims[best.0], rims[best.1]);
            let gap = one
                .iter()
                .map(|&v| nearest(&[other], v))
                .fold(f64::INFINITY, f64::min);
            let reach = part
                .iter()
                .map(|&v| nearest(&[one, other], v))
                .fold(0.0, f64::max);
            match reach <= gap {
                true => held(one, other),
                false => from_rims(rims),
            }
        }
    }
}

/// Whether [`field_of`] gives some part of `surface` a distance.
fn ridged(surface: &Triangles, closed: Closed) -> bool {
    let rims = rims(surface);
    parts(surface).iter().any(|part| {
        matches!(
            pole_values(&surface.points, part, &rims, closed),
            Held::Distance(_)
        )
    })
}

/// Whether some part of `surface` has no rim.
fn closed_part(surface: &Triangles) -> bool {
    let rims = rims(surface);
    parts(surface)
        .iter()
        .any(|part| !rims.iter().any(|r| part.binary_search(&r[0]).is_ok()))
}

/// The rims of `surface`: loops of the edges only one triangle uses, each as its
/// points.
fn rims(surface: &Triangles) -> Vec<Vec<u32>> {
    boundary_loops(surface.corners.iter().flat_map(|t| cycle_pairs(t)))
}

/// The loops of the directed edges (each a face's side, faces counter-clockwise)
/// whose reverse is not among them: a surface's boundary, the surface on each loop's
/// left, the loops from their least point.
fn boundary_loops(edges: impl Iterator<Item = (u32, u32)>) -> Vec<Vec<u32>> {
    let directed: std::collections::BTreeSet<(u32, u32)> = edges.collect();
    let mut next: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            next.entry(a).or_default().push(b);
        }
    }
    let mut loops = Vec::new();
    while let Some((&start, _)) = next.iter().find(|(_, to)| !to.is_empty()) {
        let mut ring = vec![start];
        let mut at = start;
        while let Some(to) = next.get_mut(&at).and_then(|to| to.pop()) {
            if to == start {
                break;
            }
            ring.push(to);
            at = to;
        }
        loops.push(ring);
    }
    loops
}

/// Solves the symmetric system given by its lower triangle's entries.
fn solve_lower(
    n: usize,
    lower: &[faer::sparse::Triplet<usize, usize, f64>],
    rhs: &[f64],
) -> Result<Vec<f64>, String> {
    use faer::linalg::solvers::Solve;
    if n == 0 {
        return Ok(Vec::new());
    }
    let matrix = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, lower)
        .map_err(|e| format!("the field's system: {e:?}"))?;
    let llt = matrix
        .sp_cholesky(faer::Side::Lower)
        .map_err(|e| format!("the field's system: {e:?}"))?;
    let x = llt.solve(&faer::Mat::from_fn(n, 1, |i, _| rhs[i]));
    let solution: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    if solution.iter().all(|x| x.is_finite()) {
        Ok(solution)
    } else {
        Err("the field's system has no finite solution".into())
    }
}

/// The least weight an edge keeps in the field's system.
const LEAST_WEIGHT: f64 = 1e-6;

/// The cotangent of the angle at `apex` between `p` and `q`, kept within ±1000 (a
/// needle triangle's would swamp the rest).
fn cotangent(apex: DVec3, p: DVec3, q: DVec3) -> f64 {
    let (u, v) = (p - apex, q - apex);
    (u.dot(v) / u.cross(v).length().max(1e-300)).clamp(-1e3, 1e3)
}

/// The gradient over the triangle `[a, b, c]` (counter-clockwise) of the linear
/// function with values `f` at its corners, and twice its area; `None` where it has
/// none. ∇f = Σ f_i (n × e_i) / 2A, e_i the side opposite corner i.
fn gradient_on([a, b, c]: [DVec3; 3], [fa, fb, fc]: [f64; 3]) -> Option<(DVec3, f64)> {
    let normal = (b - a).cross(c - a);
    let twice = normal.length();
    if twice <= 0.0 {
        return None;
    }
    let n = normal / twice;
    let gradient = (fa * n.cross(c - b) + fb * n.cross(a - c) + fc * n.cross(b - a)) / twice;
    Some((gradient, twice))
}

/// Each edge of `surface` (once, lower corner first) with its cotangent weight: half
/// the sum of the cotangents of the angles facing it, each kept within ±1000 (a
/// needle triangle's would swamp the rest), the sum at least [`LEAST_WEIGHT`].
fn cotangent_weights(surface: &Triangles) -> Vec<(u32, u32, f64)> {
    let mut weights: BTreeMap<(u32, u32), f64> = BTreeMap::new();
    for t in &surface.corners {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let [pa, pb, pc] = [a, b, c].map(|i| surface.points[i as usize]);
            *weights.entry((a.min(b), a.max(b))).or_insert(0.0) += 0.5 * cotangent(pc, pa, pb);
        }
    }
    // Negative weights (obtuse angles) kept a hair above zero: the system stays
    // definite, and the field has no extremum but its poles.
    weights
        .into_iter()
        .map(|((a, b), w)| (a, b, w.max(LEAST_WEIGHT)))
        .collect()
}

/// The points of each connected part of `surface` (joined by triangles), each in
/// increasing order, the parts by their first point.
fn parts(surface: &Triangles) -> Vec<Vec<u32>> {
    let n = surface.points.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut used = vec![false; n];
    for t in &surface.corners {
        for k in 0..3 {
            used[t[k] as usize] = true;
            union(&mut parent, t[k], t[(k + 1) % 3]);
        }
    }
    let mut groups: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for v in (0..n as u32).filter(|&v| used[v as usize]) {
        let r = find(&mut parent, v);
        groups.entry(r).or_default().push(v);
    }
    groups.into_values().collect()
}

/// Two points of `part` far apart: the farthest from its first point, and the
/// farthest from that.
fn poles(points: &[DVec3], part: &[u32]) -> [u32; 2] {
    let farthest = |from: u32| {
        part.iter()
            .copied()
            .max_by(|&a, &b| {
                let d = |v: u32| points[v as usize].distance_squared(points[from as usize]);
                d(a).total_cmp(&d(b)).then(b.cmp(&a))
            })
            .unwrap_or(from)
    };
    let one = farthest(part[0]);
    [one, farthest(one)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A tube of `around` × `along` quads split into triangles, radius `r(h)` at
    /// height `h` in 0..=height, open at both ends (a cylinder or a cone).
    fn tube(around: usize, along: usize, height: f64, r: impl Fn(f64) -> f64) -> Triangles {
        let mut points = Vec::new();
        for k in 0..=along {
            let h = height * k as f64 / along as f64;
            for i in 0..around {
                let a = TAU * i as f64 / around as f64;
                points.push(DVec3::new(r(h) * a.cos(), r(h) * a.sin(), h));
            }
        }
        let id = |k: usize, i: usize| (k * around + i % around) as u32;
        let mut corners = Vec::new();
        for k in 0..along {
            for i in 0..around {
                // Counter-clockwise seen from outside (normals away from the axis).
                corners.push([id(k, i), id(k, i + 1), id(k + 1, i + 1)]);
                corners.push([id(k, i), id(k + 1, i + 1), id(k + 1, i)]);
            }
        }
        Triangles { points, corners }
    }

    fn heights(surface: &Triangles) -> Vec<f64> {
        surface.points.iter().map(|p| p.z).collect()
    }

    #[test]
    fn a_measured_bound_holds_between_the_samples_and_is_sampled_finer_to_tell() {
        // An equilateral triangle whose corners touch three small triangles: the
        // farthest point from them is its centre, L/√3 away, which samples 10 to a
        // side miss.
        let side = 100.0;
        let corners = [
            DVec3::ZERO,
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.5 * side, 0.5 * 3f64.sqrt() * side, 0.0),
        ];
        // Each speck points away from the centre, so its nearest point to it is the corner.
        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        let speck = |c: DVec3| {
            let out = (c - centre).normalize();
            [c, c + 5.0 * out + DVec3::Z, c + 5.0 * out - DVec3::Z]
        };
        let specks = corners.map(speck).to_vec();
        let farthest = side / 3f64.sqrt();
        let spacing = side / 10.0;
        let sampled = one_way_distance(&[corners], &specks, spacing);
        assert!(sampled < farthest - 1.0, "{sampled} against {farthest}");
        // The bound holds at every point, measured coarsely or finely.
        let coarse = distance_beyond(&[corners], &specks, spacing, 0.0, f64::INFINITY);
        assert!(
            coarse >= farthest && coarse <= farthest + spacing,
            "{coarse}"
        );
        // Within 1 % of the true distance the samples leave it open; finer ones settle it.
        let within = 1.01 * farthest;
        assert!(sampled + spacing / 3f64.sqrt() > within);
        let settled = distance_beyond(&[corners], &specks, spacing, within, f64::INFINITY);
        assert!(settled >= farthest && settled <= within, "{settled}");
        // Just inside the true distance no sampling can settle it within.
        let short = 0.999 * farthest;
        assert!(distance_beyond(&[corners], &specks, spacing, short, f64::INFINITY) > short);
    }

    /// The harmonic field of a wide cone between its rims crowds toward the narrow
    /// rim (it goes as the log of the radius); evened, it runs evenly along the slant.
    #[test]
    fn an_evened_field_steps_evenly_along_the_surface() {
        let cone = tube(48, 40, 100.0, |h| 10.0 + 1.5 * h);
        let field = two_pole_field(&cone).unwrap();
        let even = evened(&cone, &field);
        let (lo, hi) = (
            even.iter().copied().fold(f64::INFINITY, f64::min),
            even.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let mut worst_raw: f64 = 0.0;
        let mut worst_even: f64 = 0.0;
        for (k, p) in cone.points.iter().enumerate() {
            let along = p.z / 100.0;
            let raw = (field[k] - field[0]) / (field[field.len() - 1] - field[0]);
            worst_raw = worst_raw.max((raw - along).abs());
            worst_even = worst_even.max(((even[k] - lo) / (hi - lo) - along).abs());
        }
        assert!(
            worst_raw > 0.2,
            "the raw field is far from even: {worst_raw}"
        );
        assert!(worst_even < 0.02, "evened: {worst_even}");
    }

    #[test]
    fn a_level_of_a_tube_is_one_loop_round_it_with_the_top_on_its_left() {
        let tube = tube(24, 4, 100.0, |_| 50.0);
        let curves = level_curves(&tube, &heights(&tube), 37.5);
        assert_eq!(curves.len(), 1);
        let loop_ = &curves[0];
        assert!(loop_.closed);
        assert_eq!(loop_.points.len(), 48, "one point per crossed edge");
        for p in &loop_.points {
            assert!((p.z - 37.5).abs() < 1e-9);
        }
        // Running counter-clockwise seen from above (+z): the top on its left seen
        // from outside.
        let turn: f64 = loop_
            .points
            .iter()
            .zip(loop_.points.iter().cycle().skip(1))
            .map(|(a, b)| a.x * b.y - a.y * b.x)
            .sum();
        assert!(turn > 0.0, "{turn}");
    }

    #[test]
    fn a_level_across_an_open_tube_is_two_curves_from_rim_to_rim() {
        let tube = tube(24, 4, 100.0, |_| 50.0);
        let across: Vec<f64> = tube.points.iter().map(|p| p.x).collect();
        let curves = level_curves(&tube, &across, 10.0);
        assert_eq!(curves.len(), 2, "{curves:?}");
        for c in &curves {
            assert!(!c.closed);
            let ends = [c.points[0].z, c.points[c.points.len() - 1].z];
            assert!(ends == [0.0, 100.0] || ends == [100.0, 0.0], "{ends:?}");
            assert!(c.points.iter().all(|p| (p.x - 10.0).abs() < 1e-9));
        }
    }

    #[test]
    fn simplifying_keeps_every_point_within_the_tolerance() {
        let tube = tube(64, 1, 10.0, |_| 100.0);
        let loop_ = &level_curves(&tube, &heights(&tube), 5.0)[0];
        let coarse = simplify(loop_, 2.0);
        assert!(
            coarse.points.len() < loop_.points.len() / 2,
            "{}",
            coarse.points.len()
        );
        let n = coarse.points.len();
        for p in &loop_.points {
            let d = (0..n)
                .map(|k| segment_distance(*p, coarse.points[k], coarse.points[(k + 1) % n]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 2.0 + 1e-9, "{d}");
        }
    }

    #[test]
    fn the_band_between_a_cylinders_rims_is_its_surface_and_unrolls_to_its_rectangle() {
        let around = 16;
        let tube = tube(around, 1, 80.0, |_| 30.0);
        let rims: Vec<Vec<DVec3>> = [0.0, 80.0]
            .iter()
            .map(|&h| tube.points.iter().copied().filter(|p| p.z == h).collect())
            .collect();
        let strip = ring(&rims[0], &rims[1]);
        assert_eq!(strip.triangles.len(), 2 * around);
        // Every corner on the outline: no vertex inside the band.
        let outline = outline_of(&strip);
        for v in strip.triangles.iter().flatten() {
            assert!(
                outline.iter().any(|&(_, a, b)| a == *v || b == *v),
                "{v} inside"
            );
        }
        // The band is the tube itself, both ways.
        let (band_soup, tube_soup) = (strip_soup(std::slice::from_ref(&strip)), tube.soup());
        assert!(one_way_distance(&band_soup, &tube_soup, 1.0) < 1e-9);
        assert!(one_way_distance(&tube_soup, &band_soup, 1.0) < 1e-9);
        // Unrolled, every edge keeps its length, and the band is a rectangle as long as
        // the rim's polygon.
        let flat = unroll(&strip);
        for t in &strip.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let d3 = strip.points[a].distance(strip.points[b]);
                assert!((flat[a].distance(flat[b]) - d3).abs() < 1e-9 * 80.0);
            }
        }
        // The rim below (the first around + 1 corners, its first point again at the
        // end) lies on one line as long as the rim's polygon, the rim above on the line
        // parallel to it 80 mm away.
        let side = 2.0 * 30.0 * (std::f64::consts::PI / around as f64).sin();
        let (start, end) = (flat[0], flat[around]);
        assert!((start.distance(end) - around as f64 * side).abs() < 1e-9);
        let along = (end - start).normalize();
        for (k, p) in flat.iter().enumerate() {
            let off = along.perp_dot(*p - start);
            let expected = if k <= around { 0.0 } else { 80.0 };
            assert!((off - expected).abs() < 1e-9, "corner {k}: {off}");
        }
    }

    /// Two parallel lines 20 apart in the plane z = 0, of 5 and 8 points.
    fn two_lines() -> (Vec<DVec3>, Vec<DVec3>) {
        let p = (0..5).map(|i| DVec3::new(i as f64 * 10.0, 0.0, 0.0));
        let q = (0..8).map(|i| DVec3::new(i as f64 * 6.0, 20.0, 0.0));
        (p.collect(), q.collect())
    }

    #[test]
    fn a_band_between_straight_lines_in_a_plane_does_not_bend() {
        let (p, q) = two_lines();
        let strip = band(&p, &q);
        assert_eq!(strip.triangles.len(), p.len() + q.len() - 2);
        for t in &strip.triangles {
            let [a, b, c] = t.map(|i| strip.points[i as usize]);
            let normal = (b - a).cross(c - a);
            assert!(normal.z > 0.0, "counter-clockwise: {normal}");
        }
    }

    #[test]
    fn a_strip_that_comes_back_over_a_triangle_runs_back_and_a_band_does_not() {
        let (p, q) = two_lines();
        let strip = band(&p, &q);
        assert!(!runs_back(&strip));
        // Back over its first triangle, through a second point at the same place as
        // one of its corners (as a bridge between two loops is walked both ways).
        let mut back = strip.clone();
        let [a, b, c] = back.triangles[0];
        back.points.push(back.points[a as usize]);
        let again = back.points.len() as u32 - 1;
        back.triangles.push([again, c, b]);
        assert!(runs_back(&back));
        // A triangle with no area (its corners welded) is not counted.
        let mut flat = strip.clone();
        flat.points.push(flat.points[a as usize]);
        flat.triangles.push([a, flat.points.len() as u32 - 1, b]);
        assert!(!runs_back(&flat));
    }

    /// A sphere of `radius` from a `around` × `rings` grid of latitudes, a point at
    /// each pole.
    fn sphere(radius: f64, around: usize, rings: usize) -> Triangles {
        let mut points = vec![DVec3::new(0.0, 0.0, -radius)];
        for k in 1..rings {
            let lat = std::f64::consts::PI * (k as f64 / rings as f64 - 0.5);
            for i in 0..around {
                let a = TAU * i as f64 / around as f64;
                points
                    .push(radius * DVec3::new(lat.cos() * a.cos(), lat.cos() * a.sin(), lat.sin()));
            }
        }
        points.push(DVec3::new(0.0, 0.0, radius));
        let top = points.len() as u32 - 1;
        let id = |k: usize, i: usize| (1 + (k - 1) * around + i % around) as u32;
        let mut corners = Vec::new();
        for i in 0..around {
            corners.push([0, id(1, i + 1), id(1, i)]);
            corners.push([top, id(rings - 1, i), id(rings - 1, i + 1)]);
        }
        for k in 1..rings - 1 {
            for i in 0..around {
                corners.push([id(k, i), id(k, i + 1), id(k + 1, i + 1)]);
                corners.push([id(k, i), id(k + 1, i + 1), id(k + 1, i)]);
            }
        }
        Triangles { points, corners }
    }

    /// Strips of `surface` along `axis` within `tolerance`: within it both ways
    /// (measured again more finely over the whole), every corner on a strip's outline,
    /// edge lengths kept unrolled, the strips on either side of each level meeting at
    /// the same points. Returns how many strips.
    fn check_strips(surface: &Triangles, field: &[f64], tolerance: f64) -> usize {
        check_strips_cut(surface, field, tolerance, f64::INFINITY)
    }

    /// [`check_strips`] with bands cut into sectors `sector_length` long; every
    /// outline edge of a strip is the surface's rim or another strip's outline edge,
    /// run the other way.
    fn check_strips_cut(
        surface: &Triangles,
        field: &[f64],
        tolerance: f64,
        sector_length: f64,
    ) -> usize {
        let clock = std::time::Instant::now();
        let banded = strips_within(surface, field, tolerance, sector_length).unwrap();
        eprintln!(
            "{} strips, deviation {:.3} in {:?}",
            banded.strips.len(),
            banded.deviation,
            clock.elapsed()
        );
        let soup = strip_soup(&banded.strips);
        let whole = surface.soup();
        let out = one_way_distance(&soup, &whole, tolerance / 10.0);
        let back = one_way_distance(&whole, &soup, tolerance / 10.0);
        assert!(out <= tolerance && back <= tolerance, "{out} {back}");
        let size = extent_of(&surface.points);
        for strip in &banded.strips {
            let outline = outline_of(strip);
            for v in strip.triangles.iter().flatten() {
                assert!(
                    outline.iter().any(|&(_, a, b)| a == *v || b == *v),
                    "{v} inside"
                );
            }
            let flat = unroll(strip);
            for t in &strip.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                    let d3 = strip.points[a].distance(strip.points[b]);
                    assert!((flat[a].distance(flat[b]) - d3).abs() < 1e-9 * size);
                }
            }
        }
        // Outline edges by their ends' positions, as the triangles run.
        let key = |p: DVec3| p.to_array().map(f64::to_bits);
        let mut outlines: BTreeMap<([u64; 3], [u64; 3]), usize> = BTreeMap::new();
        for (s, strip) in banded.strips.iter().enumerate() {
            for (_, a, b) in outline_of(strip) {
                let edge = (key(strip.points[a as usize]), key(strip.points[b as usize]));
                assert!(
                    outlines.insert(edge, s).is_none(),
                    "strip {s} repeats an edge"
                );
            }
        }
        // No edge has more than two triangles: the strips do not overlap.
        let mut uses: BTreeMap<([u64; 3], [u64; 3]), usize> = BTreeMap::new();
        for strip in &banded.strips {
            for t in &strip.triangles {
                for (a, b) in cycle_pairs(t) {
                    let (a, b) = (key(strip.points[a as usize]), key(strip.points[b as usize]));
                    *uses.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
        }
        assert!(uses.values().all(|&n| n <= 2), "strips overlap");
        let rim: std::collections::BTreeSet<([u64; 3], [u64; 3])> = rims(surface)
            .iter()
            .flat_map(|r| cycle_pairs(r).collect::<Vec<_>>())
            .map(|(a, b)| {
                (
                    key(surface.points[a as usize]),
                    key(surface.points[b as usize]),
                )
            })
            .collect();
        for (&(a, b), &s) in &outlines {
            // A ring strip meets itself at the rung it is opened at.
            let from = |k: [u64; 3]| DVec3::from_array(k.map(f64::from_bits));
            assert!(
                rim.contains(&(a, b)) || outlines.contains_key(&(b, a)),
                "an outline edge {} {} of strip {s} meets no other strip",
                from(a),
                from(b)
            );
        }
        banded.strips.len()
    }

    /// The height of each point along `axis`.
    fn along(surface: &Triangles, axis: DVec3) -> Vec<f64> {
        let axis = axis.normalize();
        surface.points.iter().map(|p| p.dot(axis)).collect()
    }

    #[test]
    fn an_open_tube_between_its_rims_is_one_strip_and_a_cone_too() {
        let tube = tube(32, 6, 120.0, |_| 40.0);
        let field = two_pole_field(&tube).unwrap();
        // Held at 0 and 1 on its rims (either way round), linear in between.
        let up = field[0] == 0.0;
        for (p, f) in tube.points.iter().zip(&field) {
            let linear = if up { p.z / 120.0 } else { 1.0 - p.z / 120.0 };
            assert!((f - linear).abs() < 1e-9, "{p} {f}");
        }
        assert_eq!(check_strips(&tube, &field, 1.0), 1);
        let cone = super::tests::tube(32, 6, 120.0, |h| 60.0 - 0.3 * h);
        assert_eq!(check_strips(&cone, &two_pole_field(&cone).unwrap(), 1.0), 1);
    }

    #[test]
    fn holes_close_together_are_one_pole_and_the_field_spans_the_rest() {
        // A sphere with two holes 60 degrees apart round its lower part.
        let mut holed = sphere(100.0, 24, 16);
        let hole = |i: u32| [1 + 24 * 2 + i, 1 + 24 * 2 + i + 1, 1 + 24 * 3 + i + 1];
        let removed = [hole(0), hole(4)];
        holed
            .corners
            .retain(|t| !removed.iter().any(|h| h.iter().all(|v| t.contains(v))));
        assert_eq!(rims(&holed).len(), 2);
        let field = two_pole_field(&holed).unwrap();
        let far = field.iter().position(|&f| f == 1.0).expect("a pole at 1");
        assert!(
            holed.points[far].z > 50.0,
            "the pole at 1 is across from the holes"
        );
        for rim in rims(&holed) {
            assert!(rim.iter().all(|&v| field[v as usize] == 0.0));
        }
        // Held apart, the two holes would leave the upper half flat.
        let upper: Vec<f64> = (0..holed.points.len())
            .filter(|&v| holed.points[v].z > 0.0)
            .map(|v| field[v])
            .collect();
        let (lo, hi) = upper
            .iter()
            .fold((1.0f64, 0.0f64), |(lo, hi), &f| (lo.min(f), hi.max(f)));
        assert!(hi - lo > 0.25, "the upper half spans {lo}..{hi}");
        check_strips(&holed, &evened(&holed, &field), 2.0);
    }

    #[test]
    fn the_field_of_a_part_with_holes_runs_at_even_distances_along_their_rims() {
        // Three ragged holes side by side in a sphere's base, 11 mm apart at their
        // nearest: a field held at 0 on them must rise as fast all round each rim.
        let mut holed = sphere(100.0, 96, 48);
        let centres =
            [-35.0, 0.0, 35.0].map(|x: f64| DVec3::new(x, 0.0, -(100.0f64 * 100.0 - x * x).sqrt()));
        let points = holed.points.clone();
        holed.corners.retain(|t| {
            let middle = t.iter().map(|&v| points[v as usize]).sum::<DVec3>() / 3.0;
            centres.iter().all(|c| middle.distance(*c) > 12.0)
        });
        let holed = holed.rims_apart();
        assert_eq!(rims(&holed).len(), 3);
        let field = two_pole_field(&holed).unwrap();
        let segments: Vec<(DVec3, DVec3)> = rims(&holed)
            .iter()
            .flat_map(|r| {
                cycle_pairs(r)
                    .map(|(a, b)| (holed.points[a as usize], holed.points[b as usize]))
                    .collect::<Vec<_>>()
            })
            .collect();
        let to_rims = |p: DVec3| {
            segments
                .iter()
                .map(|&(a, b)| {
                    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    p.distance(a + t * (b - a))
                })
                .fold(f64::INFINITY, f64::min)
        };
        // How much faster the field rises than the distance, 8 to 20 mm out, at its
        // fastest over its slowest.
        let used: std::collections::BTreeSet<u32> =
            holed.corners.iter().flatten().copied().collect();
        let spread = |field: &[f64]| {
            let ratios: Vec<f64> = used
                .iter()
                .filter_map(|&v| {
                    let d = to_rims(holed.points[v as usize]);
                    (8.0..20.0).contains(&d).then(|| field[v as usize] / d)
                })
                .collect();
            assert!(ratios.len() > 100, "{} points near the rims", ratios.len());
            let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
                (lo.min(r), hi.max(r))
            });
            hi / lo
        };
        // The harmonic field from the rims to the point farthest from them crowds its
        // levels by a factor of three here; the distance keeps within two, its
        // smoothing slowing it between two holes.
        let part = &parts(&holed)[0];
        let on_rims: Vec<u32> = rims(&holed).into_iter().flatten().collect();
        let far = *used
            .iter()
            .max_by(|&&a, &&b| {
                let d = |v: u32| to_rims(holed.points[v as usize]);
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let held: BTreeMap<u32, f64> = on_rims
            .iter()
            .map(|&v| (v, 0.0))
            .chain([(far, 1.0)])
            .collect();
        let n = holed.points.len();
        let weights = cotangent_weights(&holed);
        let values = solve_on(n, part, &weights, &held, &|_| 0.0, &|_| 0.0).unwrap();
        let mut harmonic = vec![0.0; n];
        for (&v, x) in part.iter().zip(values) {
            harmonic[v as usize] = x;
        }
        let (distance, crowded) = (spread(&field), spread(&harmonic));
        assert!(
            distance < 2.0,
            "the distance rises {distance} times faster in places"
        );
        assert!(
            crowded > 3.0,
            "the harmonic field rises {crowded} times faster"
        );
        check_strips(&holed, &evened(&holed, &field), 2.0);
    }

    #[test]
    fn a_bump_inside_a_patch_is_an_extremum_and_its_outline_is_not() {
        // A 5 x 5 grid rising along x, its middle point raised above its neighbours.
        let points: Vec<DVec3> = (0..25)
            .map(|k| DVec3::new((k % 5) as f64, (k / 5) as f64, 0.0))
            .collect();
        let mut corners = Vec::new();
        for y in 0..4u32 {
            for x in 0..4u32 {
                let k = 5 * y + x;
                corners.extend([[k, k + 1, k + 6], [k, k + 6, k + 5]]);
            }
        }
        let rising: Vec<f64> = points.iter().map(|p| p.x).collect();
        let patch = |values: Vec<f64>| Patch {
            surface: Triangles {
                points: points.clone(),
                corners: corners.clone(),
            },
            values,
            kept: vec![true; 25],
            ends: [0.0, 4.0],
        };
        let loops =
            |p: &Patch| boundary_loops(p.surface.corners.iter().flat_map(|t| cycle_pairs(t)));
        let plain = patch(rising.clone());
        assert!(
            !inner_extremum(&plain, &loops(&plain)),
            "the outline's ends are no bump"
        );
        let mut bumped = rising;
        bumped[12] = 3.5;
        let bumped = patch(bumped);
        assert!(inner_extremum(&bumped, &loops(&bumped)));
    }

    #[test]
    fn a_barrel_cut_into_sectors_has_no_edge_of_no_length() {
        // A level of its grown bands lands a rounding away from its middle row of
        // points: the crossings there are welded onto the points they sit on.
        let barrel = tube(48, 24, 120.0, |h| {
            40.0 + 20.0 * (std::f64::consts::PI * h / 120.0).sin()
        });
        let strips = strips_within(&barrel, &heights(&barrel), 1.0, 200.0)
            .unwrap()
            .strips;
        for strip in &strips {
            for t in &strip.triangles {
                for (a, b) in cycle_pairs(t) {
                    let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
                    assert!(pa.distance(pb) > SAME_POINT, "an edge of no length at {pa}");
                }
            }
        }
        check_strips_cut(&barrel, &heights(&barrel), 1.0, 200.0);
    }

    fn extent_of(points: &[DVec3]) -> f64 {
        let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        lo.distance(hi)
    }

    #[test]
    fn strips_of_a_sphere_stay_within_the_bound_unroll_exactly_and_share_their_curves() {
        // A field along a tilted axis: its levels cross the grid's edges anywhere.
        let sphere = sphere(100.0, 48, 24);
        let strips = check_strips(&sphere, &along(&sphere, DVec3::new(0.3, 0.2, 0.93)), 2.0);
        assert!(strips >= 3, "{strips}");
        // Between two poles, the same.
        let field = two_pole_field(&sphere).unwrap();
        let whole = check_strips(&sphere, &field, 2.0);
        // Rings longer than 200 mm cut across into sectors, each split on its own.
        let cut = check_strips_cut(&sphere, &field, 2.0, 200.0);
        assert!(cut > whole, "{cut} sectors and bands, {whole} rings");
    }

    /// A torus about the z axis: `around` × `across` quads split into triangles.
    fn torus(big: f64, small: f64, around: usize, across: usize) -> Triangles {
        let mut points = Vec::new();
        for i in 0..around {
            let a = TAU * i as f64 / around as f64;
            for j in 0..across {
                let b = TAU * j as f64 / across as f64;
                let r = big + small * b.cos();
                points.push(DVec3::new(r * a.cos(), r * a.sin(), small * b.sin()));
            }
        }
        let id = |i: usize, j: usize| ((i % around) * across + j % across) as u32;
        let mut corners = Vec::new();
        for i in 0..around {
            for j in 0..across {
                corners.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                corners.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Triangles { points, corners }
    }

    #[test]
    fn strips_of_a_torus_bridge_its_saddles() {
        // Along an axis in its plane the field has two saddles, where a band's
        // region has three loops.
        let torus = torus(100.0, 40.0, 48, 24);
        let field = along(&torus, DVec3::new(1.0, 0.2, 0.1));
        check_strips(&torus, &field, 2.0);
        check_strips_cut(&torus, &field, 2.0, 150.0);
    }

    #[test]
    fn a_long_strip_is_cut_into_pieces_that_fit_and_a_winding_one_where_it_would_overlap() {
        // A cylinder 300 mm round, 50 mm tall: unrolled, a band 1.88 m long.
        let tube = tube(64, 1, 50.0, |_| 300.0);
        let rims: Vec<Vec<DVec3>> = [0.0, 50.0]
            .iter()
            .map(|&h| tube.points.iter().copied().filter(|p| p.z == h).collect())
            .collect();
        let strip = ring(&rims[0], &rims[1]);
        let flat = unroll(&strip);
        let fits = |p: &[DVec2]| fits_turned(p, 600.0, 400.0, 36);
        let cut = pieces(&strip, &flat, fits);
        // Even laid along the sheet's diagonal (721 mm), a piece holds under 0.4 of it.
        assert!(cut.len() >= 3, "{cut:?}");
        assert_eq!(cut.first().map(|r| r.start), Some(0));
        assert_eq!(cut.last().map(|r| r.end), Some(strip.triangles.len()));
        for pair in cut.windows(2) {
            assert_eq!(pair[0].end, pair[1].start);
        }
        for piece in &cut {
            let points: Vec<DVec2> = strip.triangles[piece.clone()]
                .iter()
                .flatten()
                .map(|&i| flat[i as usize])
                .collect();
            assert!(fits(&points));
        }
        // A band one and a half times round a circle unrolls onto itself.
        let turn = |k: usize, r: f64| {
            let a = 3.0 * std::f64::consts::PI * k as f64 / 60.0;
            DVec3::new(r * a.cos(), r * a.sin(), 0.0)
        };
        let p: Vec<DVec3> = (0..=60).map(|k| turn(k, 100.0)).collect();
        let q: Vec<DVec3> = (0..=60).map(|k| turn(k, 110.0)).collect();
        let winding = band(&q, &p);
        let flat = unroll(&winding);
        let cut = pieces(&winding, &flat, |_| true);
        assert_eq!(cut.len(), 2, "{cut:?}");
        for piece in &cut {
            for s in piece.clone() {
                for t in piece.clone().filter(|&t| t > s) {
                    let corners = |k: usize| winding.triangles[k].map(|i| flat[i as usize]);
                    assert!(!triangles_overlap(corners(s), corners(t)), "{s} {t}");
                }
            }
        }
    }

    #[test]
    fn strips_folded_over_their_neighbour_do_not_join() {
        let at = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let strip = |points: Vec<DVec3>| -> Covered {
            let triangles = vec![[0, 1, 2]];
            (Strip { points, triangles }, 0.0)
        };
        let below = strip(vec![at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0)]);
        // Beyond their shared edge, and folded back over it onto the first strip.
        let beside = strip(vec![at(1.0, 1.0), at(1.0, 0.0), at(2.0, 0.5)]);
        let folded = strip(vec![at(1.0, 0.0), at(1.0, 1.0), at(0.5, 0.2)]);
        assert!(joined(&[below.clone(), beside]));
        assert!(!joined(&[below, folded]));
    }

    /// The band from height `y` to `y + 1`, from x = 0 to `length`, zigzagging along x with a rung
    /// at every unit: two triangles per unit.
    fn zigzag(length: u32, y: f64) -> Strip {
        let points = (0..=length)
            .flat_map(|i| {
                [
                    DVec3::new(i as f64, y, 0.0),
                    DVec3::new(i as f64, y + 1.0, 0.0),
                ]
            })
            .collect::<Vec<_>>();
        let triangles = (0..2 * length)
            .map(|i| match i % 2 {
                0 => [i, i + 2, i + 1],
                _ => [i, i + 1, i + 2],
            })
            .collect();
        Strip { points, triangles }
    }

    #[test]
    fn a_piece_goes_by_the_strip_most_of_it_lies_on() {
        // Two strips of six triangles each, side by side along y = 1: the band
        // 0 ≤ y ≤ 1 and the band 1 ≤ y ≤ 2, both zigzagging along x.
        let band = |y: f64| zigzag(3, y);
        let welded = Welded::new(&[band(0.0), band(1.0)]).expect("welded");
        assert_eq!(welded.strip_of_face, [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]);
        // A face of the first strip joined to a run of the second, after another run
        // of the second that comes first along it.
        let members = vec![vec![0, 8, 9, 10, 11], vec![1, 2, 3, 4, 5], vec![6, 7]];
        let names: Vec<String> = welded
            .names(&members)
            .iter()
            .map(|n| n.to_string())
            .collect();
        assert_eq!(names, ["S2.2", "S1", "S2.1"]);
        assert_eq!(welded.joined(&members), [(0, 1, vec![0])]);
    }

    /// A 25 mm square at height `z`, as two triangles.
    fn square_at(z: f64) -> Vec<[DVec3; 3]> {
        let p =
            [(0.0, 0.0), (25.0, 0.0), (25.0, 25.0), (0.0, 25.0)].map(|(x, y)| DVec3::new(x, y, z));
        vec![[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    }

    /// Strips over a model as given (a square at height 0) built for a simplified
    /// one (the square 4 mm up), each try's strips `strays(tolerance)` above that:
    /// the tolerances the strips were asked to keep, the one they were kept within
    /// and the distance measured to the model as given.
    fn narrowed_tries(strays: impl Fn(f64) -> f64 + Sync) -> (Vec<f64>, f64, f64) {
        let asked = std::sync::Mutex::new(Vec::new());
        let cover = |tolerance: f64| {
            asked.lock().unwrap().push(tolerance);
            let deviation = strays(tolerance);
            assert!(deviation <= tolerance, "{deviation} within {tolerance}");
            let square = square_at(4.0 + deviation);
            let strips = vec![Strip {
                points: vec![square[0][0], square[0][1], square[0][2], square[1][2]],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            }];
            Ok(Covering {
                welded: Welded::new(&strips).unwrap(),
                banded: Banded { strips, deviation },
                whole_bands: false,
                tolerance,
            })
        };
        let (covered, measured) =
            within_unsimplified(10.0, &square_at(4.0), &square_at(0.0), &cover).unwrap();
        (asked.into_inner().unwrap(), covered.tolerance, measured)
    }

    #[test]
    fn strips_that_stray_from_the_model_as_given_are_narrowed_up_to_three_times() {
        // Each try narrower by 1.5 times what the one before strayed beyond 10 mm:
        // 7 + 4 strays by 1, 6.5 + 4 by 0.5, 6.2 + 4 by 0.2, and 5.8 + 4 is within.
        let table = |t: f64| match t {
            t if t > 9.0 => 7.0,
            t if t > 8.0 => 6.5,
            t if t > 7.6 => 6.2,
            _ => 5.8,
        };
        let (asked, kept, measured) = narrowed_tries(table);
        let expected = [10.0, 8.5, 7.75, 7.45];
        assert_eq!(asked.len(), expected.len(), "{asked:?}");
        for (a, e) in asked.iter().zip(expected) {
            assert!((a - e).abs() < 1e-9, "{asked:?}");
        }
        assert!(
            (kept - 7.45).abs() < 1e-9 && measured <= 10.0,
            "{kept} {measured}"
        );
        // Where the third narrower try strays too, the strips are kept within the
        // bound less the simplification's 4 mm (and a little for its measure).
        let (asked, kept, measured) = narrowed_tries(|t| table(t).max(6.5).min(t - 0.3));
        assert_eq!(asked.len(), 5, "{asked:?}");
        assert!(kept < 6.0 && kept > 5.7, "{asked:?}");
        assert!(measured <= 10.0, "{measured}");
    }

    #[test]
    fn a_long_strip_is_cut_into_equal_pieces_no_longer_than_asked() {
        // A band 1 wide and 100 long, a rung at every unit: 200 triangles, 199 folds.
        let welded = Welded::new(&[zigzag(100, 0.0)]).expect("welded");
        assert_eq!(welded.folds.len(), 199);
        assert_eq!(welded.shorter_than(f64::INFINITY), welded.folds);
        assert_eq!(welded.shorter_than(100.0), welded.folds);
        // 100 long in pieces of at most 30: four, cut near 25, 50 and 75.
        let folds = welded.shorter_than(30.0);
        let cut: Vec<EdgeId> = welded
            .folds
            .iter()
            .copied()
            .filter(|e| !folds.contains(e))
            .collect();
        assert_eq!(cut.len(), 3);
        let mut at: Vec<f64> = cut
            .iter()
            .map(|&e| {
                let (a, b) = welded.mesh.edge_vertices(e);
                0.5 * (welded.mesh.position(a).x + welded.mesh.position(b).x)
            })
            .collect();
        at.sort_by(f64::total_cmp);
        for (x, target) in at.iter().zip([25.0, 50.0, 75.0]) {
            assert!((x - target).abs() <= 1.0, "cut at {x}, not near {target}");
        }
    }
}
