//! Checks of a build's size, made before the nest (the long stage), that catch a
//! user's likely mistakes: a forgotten `--size` (a scan in metres read as
//! millimetres), a model far too large for the sheets, or one so detailed for its size
//! that its panels cannot carry their ids. Each gives a warning naming the fix with
//! computed values; `--strict` turns warnings into refusals. A build whose typical edge
//! is below [`MIN_MEDIAN_EDGE_MM`] is refused outright: no part of it could be cut.

use std::path::Path;

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

/// A suggested budget aims the median edge this many times the smallest edge at which
/// the scheme's panels on a regular mesh carry their labels: a simplified scan keeps a
/// tenth of its edges below two thirds of the median, and those must still carry their
/// ids (on spot at 3 ft the budgets this gives carry every panel id, half-edge and
/// quad-edge: tests/size_checks.rs).
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
    let mut lengths: Vec<f64> = mesh.edges().map(|e| mesh.edge_length(e)).collect();
    if lengths.is_empty() {
        return Ok(SizeCheck::default());
    }
    lengths.sort_by(f64::total_cmp);
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

/// With `--strict`, the first warning as a refusal.
fn strict(job: &Job, warnings: &[String]) -> Result<()> {
    match warnings.first() {
        Some(first) if job.strict => Err(Error::Usage(format!("{first} (refused by --strict)"))),
        _ => Ok(()),
    }
}

/// Checks, after the labels were fitted and before the nest, that the panels carry
/// their ids: more than `IDS_LEFT_OUT` of them left out means the model is too
/// detailed for its size. The warning gives the budget (and the size) at which the
/// scheme's panels carry them. With `--strict` it is a refusal.
pub fn check_labels(
    job: &Job,
    mesh: &Mesh,
    panels: usize,
    left_out: &crate::labels::LeftOut,
    budget: &dyn Fn() -> Option<usize>,
) -> Result<Option<String>> {
    if panels == 0 || (left_out.panel as f64) <= IDS_LEFT_OUT * panels as f64 {
        return Ok(None);
    }
    let mut lengths: Vec<f64> = mesh.edges().map(|e| mesh.edge_length(e)).collect();
    lengths.sort_by(f64::total_cmp);
    let buildable = smallest_buildable_edge(job, mesh);
    let warning = too_detailed(job, mesh, &lengths, buildable, panels, left_out, budget);
    strict(job, std::slice::from_ref(&warning))?;
    Ok(Some(warning))
}

/// The warning for panels too small for their labels, with the budget (and the size)
/// that makes them carry their ids.
fn too_detailed(
    job: &Job,
    mesh: &Mesh,
    lengths: &[f64],
    buildable: Option<f64>,
    panels: usize,
    left_out: &crate::labels::LeftOut,
    budget: &dyn Fn() -> Option<usize>,
) -> String {
    format!(
        "the model is too detailed for its size: {} of {panels} {} panels have no room for their id and {} partner ids are left out; {}",
        left_out.panel,
        job.scheme.name(),
        left_out.partner,
        detail_fixes(mesh, lengths, buildable, budget)
    )
}

/// The fixes of a model too detailed for its size: the budget that was tried and
/// builds clean, and the size at which all but the shortest [`SHORT_TAIL`] of its
/// edges (`lengths`, sorted) reach the `buildable` edge.
fn detail_fixes(
    mesh: &Mesh,
    lengths: &[f64],
    buildable: Option<f64>,
    budget: &dyn Fn() -> Option<usize>,
) -> String {
    let mut fixes = Vec::new();
    if let Some(budget) = budget() {
        fixes.push(format!("--target-edges {budget}"));
    }
    if let (Some(buildable), false) = (buildable, lengths.is_empty()) {
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
/// job's kind of faces, gives every panel its id and every connection its partner ids;
/// found by building that mesh at trial sizes with the job's own options. `None` when
/// no trial size up to 2 m fits them. Holes are not asked for: where flaps are too
/// small for them the fasteners check reports the connections without.
pub fn smallest_buildable_edge(job: &Job, mesh: &Mesh) -> Option<f64> {
    let mut degrees: Vec<usize> = mesh.faces().map(|f| mesh.face_degree(f)).collect();
    degrees.sort_unstable();
    let typical = degrees.get(degrees.len() / 2).copied().unwrap_or(3);
    smallest_edge(job, typical, |output| labels_fit(output, true))
}

/// Whether every panel of `output`, unrolled, holds its id (and, with `partners`,
/// every partner id).
fn labels_fit(output: &SchemeOutput, partners: bool) -> bool {
    let flat_fold = output.flat_fold.unwrap_or(crate::flatten::FLAT_FOLD);
    crate::flatten::unroll_all(&output.panels, LabelOptions::default(), flat_fold)
        .is_ok_and(|(_, left_out)| left_out.panel == 0 && (!partners || left_out.partner == 0))
}

/// The smallest edge length (mm) at which the job's scheme, on a regular mesh of
/// triangles (what a `--target-edges` budget makes), gives every connection a
/// fastener hole; `None` when no trial size up to 2 m does.
pub fn smallest_fastened_edge(job: &Job) -> Option<f64> {
    smallest_edge(job, 3, |output| output.unfastened.is_empty())
}

/// The smallest edge length (mm), between 0.5 mm and 2 m to 2 %, at which the job's
/// scheme built on a regular probe mesh of `degree`-sided faces makes an output that
/// `fits` (searched on a log scale: larger faces fit what smaller ones do).
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
    let (mut lo, mut hi) = (0.5f64, 2000.0f64);
    if !fits_at(hi) {
        return None;
    }
    if fits_at(lo) {
        return Some(lo);
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

/// The job's model simplified to a number of edges as `--target-edges` would, scaled
/// and split as the scheme needs (`None` when that fails).
pub type MeshAt<'a> = dyn Fn(usize) -> Option<Mesh> + 'a;

/// Budgets a warning tries, from its estimate down, before it gives up naming one.
const BUDGET_TRIALS: usize = 6;

/// Each budget tried is this fraction of the one before.
const BUDGET_STEP: f64 = 0.8;

/// The budget the warnings suggest, tried: the model simplified to it builds clean
/// ([`builds_clean`]). The first tried is the fewer of two estimates: where the median
/// edge is [`SPREAD_MARGIN`] times the smallest edge at which the scheme's panels carry
/// their labels, and where the faces, of that many times the smallest edge at which
/// they hold their fastener holes, cover the model's area.
pub fn clean_budget(job: &Job, mesh: &Mesh, mesh_at: &MeshAt) -> Option<usize> {
    let mut lengths: Vec<f64> = mesh.edges().map(|e| mesh.edge_length(e)).collect();
    lengths.sort_by(f64::total_cmp);
    let median = *lengths.get(lengths.len() / 2)?;
    let edges = lengths.len();
    let area: f64 = mesh.faces().map(|f| mesh.face_area(f)).sum();
    // At a fixed surface the edge count goes with the inverse square of the edge
    // length.
    let for_labels = smallest_buildable_edge(job, mesh)
        .map(|edge| edges as f64 * (median / (SPREAD_MARGIN * edge)).powi(2));
    let for_holes = smallest_fastened_edge(job)
        .map(|edge| area / (AREA_PER_EDGE * (SPREAD_MARGIN * edge).powi(2)));
    let estimate = for_labels
        .into_iter()
        .chain(for_holes)
        .fold(f64::INFINITY, f64::min);
    checked_budget(job, round_down_2(estimate), edges, mesh_at)
}

/// A budget a warning may suggest because it was tried: from `estimate` down by a
/// fifth at a time, the first at which the model, simplified as `--target-edges` would
/// do it (`mesh_at`), builds clean ([`builds_clean`]); where a budget is below the
/// fewest edges the model's topology allows, up by a quarter until one simplifies.
/// `None` when a budget is not below the model's `edges`, or none of [`BUDGET_TRIALS`]
/// budgets builds clean.
fn checked_budget(job: &Job, estimate: f64, edges: usize, mesh_at: &MeshAt) -> Option<usize> {
    let mut budget = estimate.floor();
    let mut below_minimum = false;
    for _ in 0..BUDGET_TRIALS {
        if budget < 6.0 || budget >= edges as f64 {
            return None;
        }
        let asked = budget as usize;
        match mesh_at(asked) {
            None => {
                below_minimum = true;
                budget = (budget / BUDGET_STEP).ceil();
            }
            Some(mesh) if builds_clean(job, &mesh) => return Some(asked),
            // Fewer edges would be below the minimum again.
            Some(_) if below_minimum => return None,
            Some(_) => budget = round_down_2(budget * BUDGET_STEP),
        }
    }
    None
}

/// Whether the job's scheme builds `mesh` with nothing to warn of: every panel holds
/// its id, and every connection the fastener holes asked for.
fn builds_clean(job: &Job, mesh: &Mesh) -> bool {
    job.scheme
        .build(mesh)
        .is_ok_and(|output| output.unfastened.is_empty() && labels_fit(&output, false))
}

/// Connections a warning names before it counts the rest.
const NAMED: usize = 5;

/// The area of an equilateral triangle mesh per edge, in squared edge lengths
/// (`√3/4` per face, 3/2 edges per face).
const AREA_PER_EDGE: f64 = 0.288_675;

/// Checks, after the scheme, that every connection holds a fastener hole when holes
/// were asked for. A few without (sliver faces) are named with the fix; most without
/// (a model too detailed for the fastener) gives one line with the `--target-edges`
/// at which the faces hold one. [`refuse_unfastened`] makes either a refusal under
/// `--strict`.
pub fn check_fasteners(
    job: &Job,
    output: &SchemeOutput,
    budget: &dyn Fn() -> Option<usize>,
) -> Option<String> {
    let bare = &output.unfastened;
    if bare.is_empty() {
        return None;
    }
    let panel = job.scheme.panel();
    let hole = format!(
        "{} mm fastener hole (with {} mm of material round it)",
        fmt_num(panel.hole_diameter),
        fmt_num(panel.hole_margin)
    );
    let (n, connections) = (bare.len(), output.connections);
    let warning = if n as f64 > MOST_UNFASTENED * connections as f64 {
        let fix = match budget() {
            Some(b) => format!("--target-edges {b} makes faces large enough for one"),
            None => "simplify the model (--target-edges) or build it larger (--size)".into(),
        };
        format!(
            "no {hole} fits at {n} of {connections} connections: the faces are too small for it at this size; {fix}"
        )
    } else {
        let mut names: Vec<String> = bare.iter().take(NAMED).map(|c| c.to_string()).collect();
        if n > NAMED {
            names.push(format!("and {} more", n - NAMED));
        }
        format!(
            "{n} of {connections} connections hold no {hole}, their faces too thin for it: {}; a smaller --hole-margin or --hole-diameter, or a --target-edges budget, gives them one",
            names.join(", ")
        )
    };
    Some(warning)
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
    fn lengths_read_naturally() {
        assert_eq!(length_text(0.155), "0.155mm");
        assert_eq!(length_text(155.0), "15.5cm");
        assert_eq!(length_text(1219.2), "1.22m");
    }
}
