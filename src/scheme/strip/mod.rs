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

mod band;
mod conform;
mod cover;
mod distance;
mod field;
mod patch;
mod sectors;
mod slices;
mod surface;
#[cfg(test)]
mod test_shapes;
mod welded;

use std::collections::BTreeMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::record::{round4, Params};
use crate::scheme::half_edge::{tab_defaults, TabArgs, TAB_DEFAULTS};
use crate::scheme::net::{
    islands_along, FlatFoldArgs, IslandNames, IslandNet, NetOptions, OwnNet, FLAT_FOLD_DEG,
};
use crate::scheme::{
    args_of, Configured, OptionValues, PanelDefaults, PanelOptions, Scheme, SchemeError,
    SchemeOutput,
};

use band::strip_soup;
use cover::{strips_ridged, Banded, STAYS_OFF};
use distance::{distance_beyond, one_way_distance};
use field::{closed_part, evened, field_of, ridged, Closed};
use patch::RunsBack;
use surface::{rims, Triangles};
use welded::{shared_edge, Welded};

pub use welded::STRIP;

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
enum Deviation {
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
    fn length(self, diagonal: f64) -> f64 {
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
struct StripOptions {
    /// The tabs, the sheet and the folds, as the net scheme takes them.
    net: NetOptions,
    /// `--max-deviation`.
    max_deviation: Deviation,
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
                rigid: crate::scheme::rigid_sheet::RigidSheet::CARD,
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

/// The strips of `surface` within `tolerance`
/// ([`strips_within`](cover::strips_within)), welded into one surface; where the
/// sectors' strips of neighbouring bands overlap, every band whole.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::band::Strip;

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
}
