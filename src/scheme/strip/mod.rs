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
mod distance;
mod field;
mod patch;
mod sectors;
mod slices;
mod surface;
#[cfg(test)]
mod test_shapes;

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::{IdKind, Name};
use crate::record::{round4, Params};
use crate::scheme::half_edge::{tab_defaults, TabArgs, TAB_DEFAULTS};
use crate::scheme::net::{
    islands_along, FlatFoldArgs, IslandNames, IslandNet, NetOptions, OwnNet, FLAT_FOLD_DEG,
};
use crate::scheme::{
    args_of, Configured, OptionValues, PanelDefaults, PanelOptions, Scheme, SchemeError,
    SchemeOutput,
};

use band::{strip_soup, Strip};
use conform::{conform, runs_back};
use distance::{distance_beyond, has_area, one_way_distance};
use field::{closed_part, evened, field_of, ridged, Closed};
use patch::{Cover, Patch, RunsBack};
use sectors::Sectors;
use slices::{Region, Slices};
use surface::{rims, Triangles};

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
/// ([`strips_within`](strips_within)), welded into one surface; where the
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

/// Strip pieces: `S3.2`, piece 2 of strip 3; `S3` for a strip in one piece.
pub static STRIP: IdKind = IdKind {
    letter: "S",
    legend: "strip piece (strip.piece)",
    noun: "strip",
    part_noun: "piece",
    layer: "",
};

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

/// The edge faces `a` and `b` share, if they are neighbours.
fn shared_edge(mesh: &Mesh, a: FaceId, b: FaceId) -> Option<EdgeId> {
    mesh.face_half_edges(a)
        .find(|h| mesh.face(h.twin()) == Some(b))
        .map(|h| h.edge())
}

/// Strips covering a surface, each within the distance asked of the part of the
/// surface it covers, both ways.
struct Banded {
    /// The strips, their outlines meeting point for point.
    strips: Vec<Strip>,
    /// The largest distance measured between a strip and the part it covers, either way.
    deviation: f64,
}

/// The part of the bound a curve's points may stray from it: the rest is the width of
/// the bands. (Along a sphere of radius R, a strip w wide between points a apart
/// strays about (a² + w²) / 8R.)
const SIMPLIFY: f64 = 0.15;

/// How many bands are tried for each band grown.
const MOST_TRIES: usize = 12;

/// How many times a part of the surface is split before the bound is given up on.
const MOST_SPLITS: usize = 40;

/// How [`Cover::strips`] ends the error of a band that strays from the surface however
/// narrow it is split: the one failure a larger bound can mend.
const STAYS_OFF: &str = "mm from the surface";

/// The strips of `surface` between levels of `field`, each within `tolerance` of the
/// part it covers (either way, measured at points `tolerance / 3` apart, allowing for
/// the points between). From one band over each part of the surface, a band whose
/// strip strays is cut across into sectors about `sector_length` long if it is longer
/// (a ring round a body strays where the body is sharpest, and the rest of it need not
/// be split with it), grown in bands from its lower curve up where it is a sector or a
/// cap round a pole, else split in halves (quarters where no one strip could be built,
/// as on a closed part); each sector and band on its own, until none strays.
#[cfg_attr(not(test), allow(dead_code))]
fn strips_within(
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

/// [`strips_within`], where the field has ridges (a distance's,
/// [`field_of`](field::field_of)) or not.
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

/// `level`, moved up past any value of the field exactly at it (a cut must cross
/// edges between their ends, never at a corner).
fn off_values(mut level: f64, sorted: &[f64]) -> f64 {
    while sorted.binary_search_by(|v| v.total_cmp(&level)).is_ok() {
        level = level.next_up();
    }
    level
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::band::Strip;
    use crate::scheme::strip::field::two_pole_field;
    use crate::scheme::strip::test_shapes::{
        self, along, check_strips, check_strips_cut, sphere, tube,
    };

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
        let cone = test_shapes::tube(32, 6, 120.0, |h| 60.0 - 0.3 * h);
        assert_eq!(check_strips(&cone, &two_pole_field(&cone).unwrap(), 1.0), 1);
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
}
