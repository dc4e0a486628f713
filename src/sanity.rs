//! Checks of a build's size, made before the nest (the long stage), that catch a
//! user's likely mistakes: a forgotten `--size` (a scan in metres read as
//! millimetres), a model far too large for the sheets, or one so detailed for its size
//! that its panels cannot carry their ids. Each gives a warning naming the fix with
//! computed values; `--strict` turns warnings into refusals. A build whose typical edge
//! is below [`MIN_MEDIAN_EDGE_MM`] is refused outright: no part of it could be cut. A
//! model too detailed for its size stops ([`Error::TooDetailed`]) with a budget that
//! was tried ([`clean_budget`]), unless `--build-anyway`.

use std::path::Path;

use glam::DVec3;

use crate::config::{Job, LengthUnit};
use crate::error::{Error, Result};
use crate::labels::LabelOptions;
use crate::mesh::read::{parse_model, Format};
use crate::mesh::{prepare, Mesh, PrepareOptions};
use crate::scheme::{SchemeOutput, MOST_UNFASTENED};
use crate::units::fmt_num;

/// A build whose median edge is shorter than this (mm) is refused: a laser's kerf is a
/// tenth of it and the smallest legible label (1.5 mm) does not fit.
pub const MIN_MEDIAN_EDGE_MM: f64 = 1.0;

/// A model whose longest side is below this fraction of the usable sheet's shorter side
/// is reported as small for the sheet (a forgotten `--size` builds scans in metres a
/// few tenths of a millimetre across).
const SMALL_FOR_SHEET: f64 = 0.1;

/// A model whose surface alone covers more sheets than this is reported as large.
const LARGE_SHEETS: f64 = 200.0;

/// The sheets a suggested `--size` for a large model covers: a build of a day or two.
const FEW_SHEETS: f64 = 20.0;

/// Panels are too small for their labels when more than this fraction of their ids is
/// left out: a builder cannot place a panel without its id.
const IDS_LEFT_OUT: f64 = 0.01;

/// A suggested budget is first tried with triangles this many times the smallest at
/// which the scheme's panels on a regular mesh carry their ids: a simplified scan
/// keeps a tenth of its edges below two thirds of the median, and those must still
/// carry their ids (the budget is then tried, and lowered until it builds clean).
const SPREAD_MARGIN: f64 = 2.25;

/// The fraction of the shortest edges a suggested `--size` lets fall below the
/// smallest buildable edge.
const SHORT_TAIL: f64 = 0.05;

/// What the checks found: warnings for the report, in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SizeCheck {
    /// One sentence each, naming the fix.
    pub warnings: Vec<String>,
}

/// Checks the scaled `mesh` of `job` against the sheet. Errors when the build is
/// hopeless, or with `--strict` when anything was found.
pub fn check_size(job: &Job, mesh: &Mesh) -> Result<SizeCheck> {
    let lengths = mesh.sorted_edge_lengths();
    if lengths.is_empty() {
        return Ok(SizeCheck::default());
    }
    let median = lengths[lengths.len() / 2];
    let longest = mesh.longest_side();
    let model = job.model_path.display();
    let across = format!("{} across", length_text(longest));
    let forgot_size = job.model.scaling.size.is_none();
    let units_hint = || units_hint(job, longest);

    if median < MIN_MEDIAN_EDGE_MM {
        let why = if forgot_size {
            format!(
                "no --size was given, so one model unit is {} mm; {}",
                short(job.model.scaling.unit_mm * job.model.scaling.scale),
                units_hint()
            )
        } else {
            "give a larger --size or simplify the model (--target-edges)".to_string()
        };
        return Err(Error::Usage(format!(
            "{model} would be built {across} with a median edge of {} mm, too small for any laser part to be cut; {why}",
            short(median)
        )));
    }

    let mut warnings = Vec::new();
    let usable_w = job.sheet.width - 2.0 * job.margin;
    let usable_h = job.sheet.height - 2.0 * job.margin;
    if forgot_size && longest < SMALL_FOR_SHEET * usable_w.min(usable_h) {
        warnings.push(format!(
            "{model} is built only {across} (no --size was given, so one model unit is {} mm); {}",
            short(job.model.scaling.unit_mm * job.model.scaling.scale),
            units_hint()
        ));
    }
    if let Some(thickness) = flat_within(mesh) {
        warnings.push(format!(
            "{model} is flat: every vertex lies within {} mm of one plane, so its panels lie flat beside each other and meet at folds of almost nothing; build a solid model (a closed surface), or cut the flat shape directly",
            short(thickness)
        ));
    }
    let area: f64 = mesh.faces().map(|f| mesh.face_area(f)).sum();
    let sheets = area / (usable_w * usable_h);
    if sheets > LARGE_SHEETS {
        let size = longest * (FEW_SHEETS / sheets).sqrt();
        let fix = if forgot_size {
            "give the size to build with --size"
        } else {
            "give a smaller --size"
        };
        warnings.push(format!(
            "{model} is built {across}: its surface alone covers {:.0} sheets of {}; {fix} (at --size {} it covers about {FEW_SHEETS:.0}) or use a larger --sheet",
            sheets.ceil(),
            job.sheet.name,
            length_text(size)
        ));
    }
    strict(job, &warnings)?;
    Ok(SizeCheck { warnings })
}

/// A model whose vertices all lie within this fraction of its longest side of one
/// plane is flat: a scan of a relief, or a drawing exported as a mesh.
const FLAT_FRACTION: f64 = 0.01;

/// The largest distance (mm) of a vertex of `mesh` from its best-fit plane, when the
/// model is flat ([`FLAT_FRACTION`]).
fn flat_within(mesh: &Mesh) -> Option<f64> {
    let points = mesh.positions();
    let (centre, normal) = crate::mesh::geometry::best_fit_plane(points);
    let thickness = points
        .iter()
        .map(|&p| (p - centre).dot(normal).abs())
        .fold(0.0, f64::max);
    (thickness <= FLAT_FRACTION * mesh.longest_side()).then_some(thickness)
}

/// With `--strict`, the first warning as a refusal.
fn strict(job: &Job, warnings: &[String]) -> Result<()> {
    match warnings.first() {
        Some(first) if job.strict => Err(Error::Usage(format!("{first} (refused by --strict)"))),
        _ => Ok(()),
    }
}

/// Checks, after the labels were fitted and before the nest, that the panels carry
/// their ids: more than `IDS_LEFT_OUT` of them left out means the model is too
/// detailed for its size, and the build stops ([`too_detailed`]) naming the budget
/// (and the size) at which the scheme's panels carry them.
pub fn check_labels(
    job: &Job,
    mesh: &Mesh,
    unsimplified: Option<&[[DVec3; 3]]>,
    panels: usize,
    left_out: &crate::labels::LeftOut,
    budget: &dyn Fn() -> Option<Suggestion>,
) -> Result<Option<String>> {
    if panels == 0 || (left_out.panel as f64) <= IDS_LEFT_OUT * panels as f64 {
        return Ok(None);
    }
    let what = format!(
        "{} of {panels} {} panels have no room for their id and {} partner ids are left out",
        left_out.panel,
        job.scheme.name(),
        left_out.partner
    );
    if !job.scheme.panels_follow_faces() {
        let fits = |output: &SchemeOutput| ids_mostly_fit(job, output);
        return panels_too_small(job, mesh, unsimplified, &what, &fits).map(Some);
    }
    let most = 2 * left_out.panel > panels;
    too_detailed(job, mesh, &what, most, budget).map(Some)
}

/// What a scheme that shapes its panels itself gets when they are too small: a
/// warning (a refusal under `--strict`) naming the options that make them large
/// enough for what `fits` asks, found by building them
/// ([`crate::scheme::Configured::larger_panels`]), or its fix in words.
fn panels_too_small(
    job: &Job,
    mesh: &Mesh,
    unsimplified: Option<&[[DVec3; 3]]>,
    what: &str,
    fits: &dyn Fn(&SchemeOutput) -> bool,
) -> Result<String> {
    let fix = match job.scheme.larger_panels(mesh, unsimplified, fits) {
        Some(options) => format!("{options} gives them room"),
        None => format!("try {}", job.scheme.larger_panels_fix()),
    };
    let warning = format!(
        "the {} panels are too small for this size: {what}; {fix}",
        job.scheme.name()
    );
    strict(job, std::slice::from_ref(&warning))?;
    Ok(warning)
}

/// Whether all but [`IDS_LEFT_OUT`] of the panels of `output`, unrolled, hold their id
/// (what the label check asks).
fn ids_mostly_fit(job: &Job, output: &SchemeOutput) -> bool {
    let panels = output.panels.len();
    ids_left_out(job, output).is_some_and(|n| n as f64 <= IDS_LEFT_OUT * panels as f64)
}

/// How many panels of `output`, unrolled, have no room for their id (`None` when they
/// do not unroll).
fn ids_left_out(job: &Job, output: &SchemeOutput) -> Option<usize> {
    let least_fold = job.scheme.least_scored_fold();
    crate::flatten::unroll_all(&output.panels, LabelOptions::default(), least_fold)
        .ok()
        .map(|(_, left_out)| left_out.panel)
}

/// Stops, before the scheme makes a panel, a model whose median edge is shorter than
/// the smallest at which the scheme's panels hold their ids on an even mesh: most of
/// them would have none, and the long stages would take minutes to make them
/// ([`too_detailed`]). A build with `--build-anyway` goes on; the later checks warn.
pub fn check_detail(job: &Job, mesh: &Mesh, budget: &dyn Fn() -> Option<Suggestion>) -> Result<()> {
    if job.build_anyway || !job.scheme.panels_follow_faces() {
        return Ok(());
    }
    let Some((median, buildable)) = median_too_short(job, mesh) else {
        return Ok(());
    };
    let what = format!(
        "its median edge would be {} mm, shorter than the {} mm at which {} panels hold their ids",
        short(median),
        short(buildable),
        job.scheme.name()
    );
    too_detailed(job, mesh, &what, true, budget).map(|_| ())
}

/// The median edge of `mesh` (mm) and the smallest at which the job's panels hold
/// their ids, when the median is the shorter.
fn median_too_short(job: &Job, mesh: &Mesh) -> Option<(f64, f64)> {
    let lengths = mesh.sorted_edge_lengths();
    let median = *lengths.get(lengths.len() / 2)?;
    let buildable = smallest_buildable_edge(job, mesh).filter(|&b| median < b)?;
    Some((median, buildable))
}

/// The fix named beside a refusal of a scheme that cannot build an open mesh: when
/// the model closed (`closed`, at full resolution) would not build clean, the budget
/// tried with its holes closed, e.g. "; closed, it builds clean at fewer edges: try
/// --fill-holes --target-edges 600 (or --fill-holes --target-edges auto)". Empty
/// otherwise. A model whose median edge is already too short is not built closed
/// first: that build would take long to say so.
pub fn closed_fix(
    job: &Job,
    mesh: &Mesh,
    closed: &dyn Fn() -> Option<Mesh>,
    budget: &dyn Fn() -> Option<Suggestion>,
) -> String {
    let open = !mesh.boundary_loops().is_empty();
    if !open || job.model.fill_holes || job.build_anyway {
        return String::new();
    }
    let clean_closed = || closed().is_some_and(|m| trial(job, &m) == Trial::Clean);
    if median_too_short(job, mesh).is_none() && clean_closed() {
        return String::new();
    }
    match budget().filter(|s| s.repairs.fill_holes) {
        Some(suggestion) => {
            let (flags, edges) = (suggestion.flags(), suggestion.edges);
            format!(
                "; closed, it builds clean at fewer edges: try {flags}--target-edges {edges} (or {flags}--target-edges auto)"
            )
        }
        None => String::new(),
    }
}

/// What a model too detailed for its size gets: a stop before the long stages (exit
/// 2, nothing written) naming the budget that was tried and builds clean, the size at
/// which the model's own edges carry the labels, `--target-edges auto` and
/// `--build-anyway`. A build with `--build-anyway`, or with a `--target-edges` the
/// user chose where not `most` panels or connections go without, gets the same as a
/// warning (a refusal under `--strict`).
fn too_detailed(
    job: &Job,
    mesh: &Mesh,
    what: &str,
    most: bool,
    budget: &dyn Fn() -> Option<Suggestion>,
) -> Result<String> {
    let suggestion = budget();
    let fixes = detail_fixes(job, mesh, suggestion);
    if job.build_anyway || (job.model.budget.is_some() && !most) {
        let warning = format!("the model is too detailed for its size: {what}; {fixes}");
        strict(job, std::slice::from_ref(&warning))?;
        return Ok(warning);
    }
    let auto = match suggestion {
        Some(suggestion) => format!(" (or {}--target-edges auto)", suggestion.flags()),
        None => String::new(),
    };
    Err(Error::TooDetailed {
        message: format!(
            "{} is too detailed for its size: {what}; stopped before laying out the sheets (nothing written): {fixes}{auto}; --build-anyway builds it as it is",
            job.model_path.display()
        ),
        // `auto` takes only a budget that needs no other option.
        budget: suggestion
            .filter(|s| s.repairs == Repairs::default() && s.size.is_none())
            .map(|s| s.edges),
    })
}

/// A fix that was tried: the model, repaired as `repairs` say, simplified to `edges`
/// (and built at `size`, where given) builds clean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Suggestion {
    /// The `--target-edges` budget.
    pub edges: usize,
    /// The repairs it needs that the job did not ask for.
    pub repairs: Repairs,
    /// The `--size` (mm) it needs, when no budget builds the model clean at the job's.
    pub size: Option<f64>,
}

impl Suggestion {
    /// The options besides the budget, each followed by a space (empty for none).
    pub fn flags(&self) -> String {
        let size = self
            .size
            .map_or(String::new(), |mm| format!("--size {} ", length_text(mm)));
        size + &self.repairs.flags()
    }
}

/// Repairs a suggested budget may need beyond the job's own options: the rims of a
/// model's holes and its open seams keep edges too short at any budget.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Repairs {
    /// `--weld`: join the parts that share vertex positions.
    pub weld: bool,
    /// `--fill-holes`: close every hole.
    pub fill_holes: bool,
}

impl Repairs {
    /// The options, each followed by a space (empty for none).
    pub fn flags(&self) -> String {
        let mut flags = String::new();
        if self.weld {
            flags += "--weld ";
        }
        if self.fill_holes {
            flags += "--fill-holes ";
        }
        flags
    }

    /// Why a budget alone would not do.
    fn reason(&self) -> &'static str {
        match (self.weld, self.fill_holes) {
            (true, _) => " (its open seams and holes keep edges too short at any budget)",
            (false, true) => " (the rims of its holes keep edges too short at any budget)",
            (false, false) => "",
        }
    }
}

/// The fixes of a model too detailed for its size: the `budget` that was tried and
/// builds clean, and the size at which all but the shortest [`SHORT_TAIL`] of its
/// edges reach the smallest edge at which the scheme's panels carry their labels.
fn detail_fixes(job: &Job, mesh: &Mesh, suggestion: Option<Suggestion>) -> String {
    let mut fixes = Vec::new();
    if let Some(suggestion) = suggestion {
        let why = match suggestion.size {
            Some(_) => " (at the size asked, no budget gives every panel its id and holes)",
            None => suggestion.repairs.reason(),
        };
        fixes.push(format!(
            "{}--target-edges {}{why}",
            suggestion.flags(),
            suggestion.edges,
        ));
    }
    let lengths = mesh.sorted_edge_lengths();
    if let (Some(buildable), false) = (smallest_buildable_edge(job, mesh), lengths.is_empty()) {
        // Or build it larger: the short edges grow with the model.
        let short = lengths[(lengths.len() as f64 * SHORT_TAIL) as usize];
        if short < buildable {
            let size = mesh.longest_side() * buildable / short;
            fixes.push(format!("--size {}", length_text(size)));
        }
    }
    if fixes.is_empty() {
        "simplify the model (--target-edges) or build it larger (--size)".to_string()
    } else {
        format!("try {}", fixes.join(" or "))
    }
}

/// The smallest edge length (mm) at which the job's scheme, on a regular mesh of the
/// job's kind of faces, gives every panel its id (what the label check asks; partner
/// ids on short flaps may still be left out); found by building that mesh at trial
/// sizes with the job's own options. `None` when no trial size up to 2 m fits them.
/// Holes are not asked for: the fasteners check reports the connections without.
pub fn smallest_buildable_edge(job: &Job, mesh: &Mesh) -> Option<f64> {
    let mut degrees: Vec<usize> = mesh.faces().map(|f| mesh.face_degree(f)).collect();
    degrees.sort_unstable();
    let typical = degrees.get(degrees.len() / 2).copied().unwrap_or(3);
    smallest_edge(job, typical, |output| ids_fit(job, output))
}

/// Whether every panel of `output`, unrolled, holds its id.
fn ids_fit(job: &Job, output: &SchemeOutput) -> bool {
    ids_left_out(job, output) == Some(0)
}

/// The smallest edge length (mm) at which the job's scheme, on a regular mesh of
/// triangles (what a `--target-edges` budget makes), gives every connection a
/// fastener hole; `None` when no trial size up to 2 m does.
pub fn smallest_fastened_edge(job: &Job) -> Option<f64> {
    smallest_edge(job, 3, |output| output.unfastened.is_empty())
}

/// The smallest edge length (mm), between 0.5 mm and 2 m to 2 %, at which the job's
/// scheme built on a regular probe mesh of `degree`-sided faces makes an output that
/// `fits` (searched on a log scale: larger faces fit what smaller ones do, up to the
/// size where a panel no longer fits the sheet, so the search starts from the largest
/// size, halved, that fits).
fn smallest_edge(job: &Job, degree: usize, fits: impl Fn(&SchemeOutput) -> bool) -> Option<f64> {
    let text: &[u8] = match degree {
        3 => include_bytes!("../models/icosahedron.obj"),
        4 => include_bytes!("../models/hexahedron.obj"),
        _ => include_bytes!("../models/dodecahedron.obj"),
    };
    let raw = parse_model(Path::new("probe.obj"), Format::Obj, text).ok()?;
    let probe = prepare(&raw, &PrepareOptions { weld: false }).ok()?.mesh;
    let edge = probe.edges().next().map(|e| probe.edge_length(e))?;
    let fits_at = |length: f64| -> bool {
        let mut scaled = probe.clone();
        scaled.scale(length / edge);
        job.scheme.build(&scaled).is_ok_and(|output| fits(&output))
    };
    let mut hi = PROBE_LARGEST;
    while !fits_at(hi) {
        hi /= 2.0;
        if hi < PROBE_SMALLEST {
            return None;
        }
    }
    let mut lo = hi / 2.0;
    while fits_at(lo) {
        hi = lo;
        lo /= 2.0;
        if lo < PROBE_SMALLEST {
            return Some(hi);
        }
    }
    while hi / lo > 1.02 {
        let mid = (lo * hi).sqrt();
        if fits_at(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The largest probe edge (mm) tried.
const PROBE_LARGEST: f64 = 2000.0;

/// The smallest probe edge (mm) tried: a panel of smaller edges is below any laser's
/// detail.
const PROBE_SMALLEST: f64 = 0.5;

/// The job's model repaired as the [`Repairs`] say (on top of its own options) and
/// simplified to a number of edges as `--target-edges` would, scaled and split as the
/// scheme needs (`None` when that fails).
pub type MeshAt<'a> = dyn Fn(&Job, usize, Repairs) -> Option<Mesh> + Sync + 'a;

/// Budgets a warning tries ([`checked_budget`]) before it gives up naming one.
const BUDGET_TRIALS: usize = 10;

/// Each budget tried is this fraction of the one before: near budgets differ in the
/// few sliver faces a simplification leaves, so the steps are small.
const BUDGET_STEP: f64 = 0.9;

/// The fix the warnings suggest, tried: a budget at the job's size
/// ([`budget_at_size`]), or where none builds clean (at the fewest edges its topology
/// allows, some faces are still too thin for a hole), a larger size with the budget
/// that builds it clean there: one and a half, two, then three times the size. A model
/// of more than [`SIZE_SEARCH_EDGES`] edges, or built with `--scale`, is not searched
/// at larger sizes.
pub fn clean_budget(
    job: &Job,
    mesh: &Mesh,
    can_weld: bool,
    mesh_at: &MeshAt,
) -> Option<Suggestion> {
    if let Some(suggestion) = budget_at_size(job, mesh, can_weld, mesh_at) {
        return Some(suggestion);
    }
    if mesh.edge_count() > SIZE_SEARCH_EDGES || job.model.scaling.scale != 1.0 {
        return None;
    }
    let built = mesh.longest_side();
    LARGER_SIZES.iter().find_map(|&factor| {
        // The size as the message prints it, so that the fix tried is the one named.
        let size = crate::units::parse_length(&length_text(built * factor)).ok()?;
        let mut larger = job.clone();
        larger.model.scaling.size = Some(size);
        let mut scaled = mesh.clone();
        scaled.scale(size / built);
        budget_at_size(&larger, &scaled, can_weld, mesh_at).map(|found| Suggestion {
            size: Some(size),
            ..found
        })
    })
}

/// Factors of the job's size tried when no budget builds the model clean at it.
const LARGER_SIZES: [f64; 3] = [1.5, 2.0, 3.0];

/// The most edges of a model searched at larger sizes: each search simplifies it
/// again, and a scan of hundreds of thousands of edges would take seconds a trial.
const SIZE_SEARCH_EDGES: usize = 50_000;

/// The budget the warnings suggest at the job's size, tried: the model simplified to it builds clean
/// ([`trial`]). A budget makes even triangles, so the first tried is the number
/// of edges whose triangles, [`SPREAD_MARGIN`] times the smallest that hold every
/// panel's id (and every fastener hole), cover the model's area.
///
/// When no budget builds the model as it is, it is tried again repaired: its holes
/// closed (`--fill-holes`), then, when it has parts that share vertex positions, its
/// parts welded as well (`--weld`). A model with a hole whose rim is shorter than
/// three edges that hold ids is tried with its holes closed straight away: no budget
/// could build it open. `can_weld` says whether welding would join anything.
fn budget_at_size(job: &Job, mesh: &Mesh, can_weld: bool, mesh_at: &MeshAt) -> Option<Suggestion> {
    let edges = mesh.edge_count();
    let area: f64 = mesh.faces().map(|f| mesh.face_area(f)).sum();
    let covering = |edge: f64| area / (AREA_PER_EDGE * (SPREAD_MARGIN * edge).powi(2));
    let ids_edge = smallest_edge(job, 3, |output| ids_fit(job, output));
    let estimate = [ids_edge, smallest_fastened_edge(job)]
        .into_iter()
        .flatten()
        .map(covering)
        .fold(f64::INFINITY, f64::min);
    let estimate = round_down_2(estimate);
    let rims = rim_lengths(mesh);
    let can_fill = !job.model.fill_holes && !rims.is_empty();
    let rim_too_short = ids_edge.is_some_and(|edge| rims.iter().any(|&rim| rim < RIM_EDGES * edge));
    let can_weld = can_weld && !job.model.weld;
    // A scheme that cannot build the model open (woven) is tried on it closed only.
    let open_refused = can_fill && job.scheme.accepts(mesh).is_err();
    let mut tries = Vec::new();
    if !(can_fill && (rim_too_short || open_refused)) {
        tries.push(Repairs::default());
    }
    if can_fill {
        tries.push(Repairs {
            weld: false,
            fill_holes: true,
        });
    }
    if can_weld {
        tries.push(Repairs {
            weld: true,
            fill_holes: can_fill,
        });
    }
    tries.into_iter().find_map(|repairs| {
        checked_budget(job, estimate, edges, &|n| mesh_at(job, n, repairs)).map(|edges| {
            Suggestion {
                edges,
                repairs,
                size: None,
            }
        })
    })
}

/// The fewest edges a hole's rim keeps at any budget: a triangle.
const RIM_EDGES: f64 = 3.0;

/// The length (mm) of the rim of each hole of `mesh`.
fn rim_lengths(mesh: &Mesh) -> Vec<f64> {
    mesh.boundary_loops()
        .into_iter()
        .map(|start| {
            mesh.loop_from(start)
                .map(|h| mesh.edge_length(h.edge()))
                .sum()
        })
        .collect()
}

/// A budget a warning may suggest because it was tried: the first at which the model,
/// simplified as `--target-edges` would do it (`mesh_at`), builds clean ([`trial`]).
/// The first tried is `estimate` (or a tenth below the model's `edges`, where that is
/// fewer); a budget too detailed is followed by a smaller one (by 30 % when more than
/// [`FAR_SHORT`] of the panels or connections go without, else by a tenth, by 19 % after
/// two such in a row, by 27 % after three, and so on), one too
/// coarse (a panel larger than the sheet, or below the fewest edges the topology
/// allows) by a larger one, and once both kinds were seen, by the budget halfway
/// between them on a log scale. `None` when none of [`BUDGET_TRIALS`] builds clean.
///
/// Each trial runs beside the one that follows it if it turns out as the last did
/// (too detailed, as near or as far): most of a trial is simplifying, on one core, so
/// the search takes about half the time on two. The budgets tried and the one named
/// are those of the trials one after the other, whatever the number of threads.
fn checked_budget(
    job: &Job,
    estimate: f64,
    edges: usize,
    mesh_at: &(dyn Fn(usize) -> Option<Mesh> + Sync),
) -> Option<usize> {
    let try_budget =
        |budget: f64| mesh_at(budget as usize).map_or(Trial::TooCoarse, |mesh| trial(job, &mesh));
    let in_range = |budget: f64| (6.0..edges as f64).contains(&budget);
    let mut budget = round_down_2(estimate.min(edges as f64 * BUDGET_STEP));
    let mut search = Search::default();
    // Before any trial, the guess is that the first budget is far from clean.
    let mut last = Trial::TooDetailed { far: true };
    let mut ahead: Option<(f64, Trial)> = None;
    for _ in 0..BUDGET_TRIALS {
        if !in_range(budget) {
            return None;
        }
        let verdict = match ahead.take() {
            Some((tried, verdict)) if tried == budget => verdict,
            _ => {
                let guess = match last {
                    Trial::TooCoarse => Trial::TooDetailed { far: false },
                    other => other,
                };
                let after = search.after(budget, guess).1.filter(|&b| in_range(b));
                let (verdict, ahead_verdict) =
                    rayon::join(|| try_budget(budget), || after.map(|b| (b, try_budget(b))));
                ahead = ahead_verdict;
                verdict
            }
        };
        if verdict == Trial::Clean {
            return Some(budget as usize);
        }
        let (next_search, next) = search.after(budget, verdict);
        search = next_search;
        last = verdict;
        budget = next?;
    }
    None
}

/// What a budget search has seen: the largest budget found too coarse, the smallest
/// found too detailed, and how many budgets in a row were found too detailed but
/// near clean.
#[derive(Clone, Copy, Default)]
struct Search {
    coarse: Option<f64>,
    detailed: Option<f64>,
    near_run: i32,
}

impl Search {
    /// The search after `budget` gave `verdict` (not clean), and the budget to try
    /// next (`None` when the search has nowhere left to go).
    fn after(self, budget: f64, verdict: Trial) -> (Search, Option<f64>) {
        let mut seen = self;
        let next = match verdict {
            Trial::Clean => return (seen, None),
            Trial::TooDetailed { far } => {
                seen.detailed = Some(budget);
                seen.near_run = if far { 0 } else { self.near_run + 1 };
                match self.coarse {
                    Some(low) => (low * budget).sqrt(),
                    None if far => budget * FAR_STEP,
                    // Each near budget in a row steps further: a model that stays
                    // near clean for a tenth fewer edges is seldom clean at the next.
                    None => budget * BUDGET_STEP.powi(seen.near_run),
                }
            }
            Trial::TooCoarse => {
                seen.near_run = 0;
                seen.coarse = Some(budget);
                match self.detailed {
                    Some(high) => (high * budget).sqrt(),
                    None => budget / FAR_STEP,
                }
            }
        };
        let next = round_down_2(next);
        let stuck = next == budget
            || seen.coarse.is_some_and(|c| next <= c)
            || seen.detailed.is_some_and(|d| next >= d);
        (seen, (!stuck).then_some(next))
    }
}

/// What one trial budget gave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Trial {
    /// Nothing to warn of.
    Clean,
    /// Panels without their ids or connections without holes: fewer edges help;
    /// `far` when more than [`FAR_SHORT`] of them go without.
    TooDetailed { far: bool },
    /// A panel larger than the sheet, or no build at all: more edges help.
    TooCoarse,
}

/// A trial budget with more than this fraction of its panels without an id (or its
/// connections without a hole) is far from clean.
const FAR_SHORT: f64 = 0.01;

/// The step from a budget far from clean.
const FAR_STEP: f64 = 0.7;

/// How the job's scheme builds `mesh`: clean when every panel holds its id, every
/// connection holds the fastener holes asked for and every panel fits the sheet (what
/// the build warns of; a partner id on a short flap may be left out, as the report
/// counts).
fn trial(job: &Job, mesh: &Mesh) -> Trial {
    let Ok(output) = job.scheme.build(mesh) else {
        return Trial::TooCoarse;
    };
    let least_fold = job.scheme.least_scored_fold();
    let Ok((flat, left_out)) =
        crate::flatten::unroll_all(&output.panels, LabelOptions::default(), least_fold)
    else {
        return Trial::TooCoarse;
    };
    let limit = job.scheme.panel().panel_limit;
    if !flat
        .iter()
        .all(|p| limit.is_none_or(|limit| limit.fits(&p.outer(), 0.0)))
    {
        return Trial::TooCoarse;
    }
    let connections = output.connections.max(1) as f64;
    let panels = flat.len().max(1) as f64;
    let short = (left_out.panel as f64 / panels).max(output.unfastened.len() as f64 / connections);
    if short == 0.0 {
        Trial::Clean
    } else {
        Trial::TooDetailed {
            far: short > FAR_SHORT,
        }
    }
}

/// Connections a warning names before it counts the rest.
const NAMED: usize = 5;

/// The area of an equilateral triangle mesh per edge, in squared edge lengths
/// (`√3/4` per face, 3/2 edges per face).
const AREA_PER_EDGE: f64 = 0.288_675;

/// Checks, after the scheme, that every connection holds a fastener hole when holes
/// were asked for. A few without (sliver faces) are named with the fix, a warning that
/// `--strict` makes a refusal ([`refuse_unfastened`]); most without means faces too
/// small for the fastener at this size, and the build stops ([`too_detailed`]).
pub fn check_fasteners(
    job: &Job,
    mesh: &Mesh,
    unsimplified: Option<&[[DVec3; 3]]>,
    output: &SchemeOutput,
    budget: &dyn Fn() -> Option<Suggestion>,
) -> Result<Option<String>> {
    let bare = &output.unfastened;
    if bare.is_empty() {
        return Ok(None);
    }
    let panel = job.scheme.panel();
    let hole = format!(
        "{} mm fastener hole (with {} mm of material round it)",
        fmt_num(panel.hole_diameter),
        fmt_num(panel.hole_margin)
    );
    let (n, connections) = (bare.len(), output.connections);
    if n as f64 > MOST_UNFASTENED * connections as f64 {
        let what = format!(
            "no {hole} fits at {n} of {connections} connections, their faces too small for it"
        );
        if !job.scheme.panels_follow_faces() {
            let fits = |output: &SchemeOutput| output.unfastened.is_empty();
            return panels_too_small(job, mesh, unsimplified, &what, &fits).map(Some);
        }
        return too_detailed(job, mesh, &what, 2 * n > connections, budget).map(Some);
    }
    let mut names: Vec<String> = bare.iter().take(NAMED).map(|c| c.to_string()).collect();
    if n > NAMED {
        names.push(format!("and {} more", n - NAMED));
    }
    Ok(Some(format!(
        "{n} of {connections} connections hold no {hole}, their faces too thin for it: {}; a smaller --hole-margin or --hole-diameter, or a --target-edges budget, gives them one",
        names.join(", ")
    )))
}

/// With `--strict`, the fasteners warning as a refusal (exit 1: the panels could not
/// be assembled as asked). Made after the label check, whose refusal (a model too
/// detailed for its size) names the more basic fix.
pub fn refuse_unfastened(job: &Job, warning: Option<&String>) -> Result<()> {
    match warning {
        Some(w) if job.strict => Err(Error::Build(format!("{w} (refused by --strict)"))),
        _ => Ok(()),
    }
}

/// How large the model would be in other units, for a forgotten `--size`.
fn units_hint(job: &Job, longest_mm: f64) -> String {
    let unit_mm = job.model.scaling.unit_mm * job.model.scaling.scale;
    let units = longest_mm / unit_mm;
    let plausible: Vec<String> = [
        (LengthUnit::M, "m"),
        (LengthUnit::Cm, "cm"),
        (LengthUnit::In, "in"),
        (LengthUnit::Ft, "ft"),
    ]
    .into_iter()
    .filter(|(unit, _)| unit.mm() > unit_mm)
    .filter_map(|(unit, name)| {
        let built = units * unit.mm() * job.model.scaling.scale;
        (50.0..=20_000.0)
            .contains(&built)
            .then(|| format!("--units {name} builds it {}", length_text(built)))
    })
    .collect();
    let mut hint = String::from("give the size to build it, like --size 4ft");
    if !plausible.is_empty() {
        hint.push_str(&format!(", or the model's units: {}", plausible.join(", ")));
    }
    hint
}

/// A length for a message: mm below 10 cm, cm below a metre, m above.
fn length_text(mm: f64) -> String {
    if mm < 100.0 {
        format!("{}mm", short(mm))
    } else if mm < 1000.0 {
        format!("{}cm", short(mm / 10.0))
    } else {
        format!("{}m", short(mm / 1000.0))
    }
}

/// Three significant digits, trailing zeros trimmed, never an exponent.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Rounds down to two significant digits (a budget to type, not a false precision).
fn round_down_2(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let step = 10f64.powi(x.log10().floor() as i32 - 1).max(1.0);
    (x / step).floor() * step
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_round_down_to_two_digits() {
        assert_eq!(round_down_2(1234.0), 1200.0);
        assert_eq!(round_down_2(99.9), 99.0);
        assert_eq!(round_down_2(7.5), 7.0);
    }

    #[test]
    fn a_budget_search_steps_down_from_detail_and_up_from_coarseness_then_halves() {
        let start = Search::default();
        let far = Trial::TooDetailed { far: true };
        let near = Trial::TooDetailed { far: false };
        assert_eq!(start.after(1000.0, far).1, Some(700.0));
        assert_eq!(start.after(1000.0, near).1, Some(900.0));
        assert_eq!(start.after(700.0, Trial::TooCoarse).1, Some(1000.0));
        // Too detailed at 1000, then too coarse at 640: the log midpoint, 800.
        let (seen, next) = start.after(1000.0, near);
        assert_eq!(next, Some(900.0));
        assert_eq!(seen.after(640.0, Trial::TooCoarse).1, Some(800.0));
        // Near budgets in a row step by a tenth, then by 19 %, then by 27 %.
        let (seen, next) = seen.after(900.0, near);
        assert_eq!(next, Some(720.0));
        assert_eq!(seen.after(720.0, near).1, Some(520.0));
        // A far budget ends the run.
        let (seen, _) = seen.after(720.0, far);
        assert_eq!(seen.after(500.0, near).1, Some(450.0));
        // Between two neighbouring budgets there is nowhere left to go.
        let (seen, _) = start.after(100.0, near);
        assert_eq!(seen.after(99.0, Trial::TooCoarse).1, None);
        assert_eq!(start.after(1000.0, Trial::Clean).1, None);
    }

    #[test]
    fn lengths_read_naturally() {
        assert_eq!(length_text(0.155), "0.155mm");
        assert_eq!(length_text(155.0), "15.5cm");
        assert_eq!(length_text(1219.2), "1.22m");
    }
}
