//! The pipeline for one job as named stages, each returning a plain struct the next
//! takes: [`load`] (read, repair, simplify) → [`prepare`] (scale, split, size checks)
//! → [`scheme`] → [`flatten`] (unroll, fit labels) → [`nest`] → [`export`] (sheets in
//! every format, the manifest). [`run_observed`] composes them, times them and writes
//! the output folder; the tests, benches and examples call the same stages.

use std::path::Path;
use std::time::Duration;

mod manifest;
mod output;
mod progress;
mod stages;

use crate::config::Job;
use crate::error::{Error, Result};
use crate::export::folder::check_output_folder;
use crate::export::manifest::Manifest;
pub use output::{export, Exported};
use progress::{Progress, Stopwatch};
pub use stages::{
    flatten, load, nest, planarize_faces, prepare, scheme, scheme_mesh, Flat, Loaded, Nested,
    Prepared, SchemeMesh,
};
use stages::{repaired, scheme_error};

/// What a finished run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The manifest written to `manifest.json`.
    pub manifest: Manifest,
    /// File names written into the output folder, in order.
    pub files: Vec<String>,
    /// Observations for the report (repairs, shortened tabs, split faces…).
    pub notes: Vec<String>,
    /// The scheme's own report lines (the woven cycles).
    pub scheme_report: Vec<String>,
    /// Wall time per stage.
    pub times: Vec<(&'static str, Duration)>,
}

/// Runs a job and writes its output folder (replaced whole by a swap, so on any error
/// the folder is left as it was; see [`crate::export::folder`] for the cases written
/// in place).
pub fn run(job: &Job) -> Result<Outcome> {
    run_observed(job, &mut |_| {})
}

/// [`run`], handing each warning about the build to `warn` as soon as it is known
/// (before the long stages), so a user can stop a build that is not what they meant.
pub fn run_observed(job: &Job, warn: &mut dyn FnMut(&str)) -> Result<Outcome> {
    if !job.model.auto_budget {
        return build(job, warn);
    }
    // `--target-edges auto`: a model too detailed for its size stops with the budget
    // that was tried and builds clean; it is built again at that budget. The first
    // attempt's warnings are held until it is known whether that build is the one
    // kept: a rebuild at the budget makes them moot.
    let mut held: Vec<String> = Vec::new();
    let first = build(job, &mut |w: &str| {
        if !held.iter().any(|s| s == w) {
            held.push(w.to_string());
        }
    });
    match first {
        Err(Error::TooDetailed {
            budget: Some(budget),
            ..
        }) => {
            let mut chosen = job.clone();
            chosen.model.auto_budget = false;
            chosen.model.budget = Some(crate::mesh::simplify::Budget::Edges(budget));
            let mut outcome = build(&chosen, warn)?;
            outcome.notes.insert(
                0,
                format!("--target-edges auto: the model is too detailed for its size as it is, so it was simplified to {budget} edges, the budget at which every panel was tried and holds its id and fastener holes"),
            );
            Ok(outcome)
        }
        Ok(mut outcome) => {
            held.iter().for_each(|w| warn(w));
            outcome.notes.insert(
                0,
                "--target-edges auto: the model builds as it is at this size, so it was not simplified".to_string(),
            );
            Ok(outcome)
        }
        Err(e) => {
            held.iter().for_each(|w| warn(w));
            Err(e)
        }
    }
}

/// Builds the sheets of `job` ([`run_observed`] without `--target-edges auto`).
fn build(job: &Job, warn: &mut dyn FnMut(&str)) -> Result<Outcome> {
    let mut clock = Stopwatch::new();
    let progress = Progress::new(job);
    let mut warn = |w: &str| progress.suspend(|| warn(w));
    // Refused before the long stages: a folder given as the model, and an output
    // folder that holds files unfold did not write.
    crate::mesh::read::model_format(&job.model_path)?;
    let folder = check_output_folder(&job.out, &job.model_path, job.force)?;
    progress.stage("reading the model");
    let loaded = load(job)?;
    clock.lap("load");
    progress.stage(if job.model.budget.is_some() {
        "simplifying and repairing the mesh"
    } else {
        "repairing the mesh"
    });
    let prepared = prepare(job, loaded)?;
    for warning in &prepared.warnings {
        warn(warning);
    }
    clock.lap("split");
    // A mesh the scheme can never build is refused before the long stages, naming
    // the budget tried with its holes closed where closing them alone would not do.
    let budget = || prepared.clean_budget(job);
    if let Err(e) = job.scheme.accepts(&prepared.scheme_mesh.mesh) {
        let closed = || {
            let fill = crate::sanity::Repairs {
                weld: false,
                fill_holes: true,
            };
            repaired(job.clone(), fill)
        };
        let fix = crate::sanity::closed_fix(job, &prepared.scheme_mesh.mesh, &closed, &budget);
        return Err(match scheme_error(job, e) {
            Error::Usage(message) => Error::Usage(message + &fix),
            Error::Build(message) => Error::Build(message + &fix),
            other => other,
        });
    }
    crate::sanity::check_detail(job, &prepared.scheme_mesh.mesh, &budget)?;
    progress.stage("making the panels");
    let output = scheme(job, &prepared)?;
    crate::internal::name_panels(output.panels.iter().map(|p| p.id().to_string()));
    let mesh = &prepared.scheme_mesh.mesh;
    let unsimplified = prepared.unsimplified.as_deref();
    let fastening = crate::sanity::check_fasteners(job, mesh, unsimplified, &output, &budget)?;
    // Under --strict it is a refusal after the label check (which may refuse first).
    if let (Some(warning), false) = (&fastening, job.strict) {
        warn(warning);
    }
    clock.lap("scheme");
    progress.stage("unrolling the panels and fitting their labels");
    let flat = flatten(job, &prepared, &output)?;
    if let Some(warning) = &flat.warning {
        warn(warning);
    }
    crate::sanity::refuse_unfastened(job, fastening.as_ref())?;
    clock.lap("flatten");
    progress.bar(&format!("nesting {} panels on sheets", flat.panels.len()));
    let nested = nest(job, &flat, &|done| progress.set(done))?;
    progress.set(1.0);
    clock.lap("nest");
    progress.bar(&format!(
        "writing {}",
        crate::units::count_of(nested.layout.sheets, "sheet")
    ));
    let warnings: Vec<String> = prepared
        .warnings
        .iter()
        .chain(&fastening)
        .chain(&flat.warning)
        .cloned()
        .collect();
    let Exported { files, manifest } =
        export(job, &prepared, &output, &flat, &nested, warnings, &|done| {
            progress.set(done)
        })?;
    let mut notes = prepared.notes.clone();
    notes.extend(output.notes.iter().cloned());
    notes.extend(flat.notes.iter().cloned());
    notes.extend(nested.notes.iter().cloned());
    notes.extend(folder.write(&files, &job.model_path)?);
    clock.lap("export");
    drop(progress);
    Ok(Outcome {
        manifest,
        files: files.into_iter().map(|(n, _)| n).collect(),
        notes,
        scheme_report: output.report,
        times: clock.times,
    })
}

/// The short report printed on stderr (written by [`crate::export::report`]).
pub fn report_text(outcome: &Outcome, out: &Path) -> String {
    crate::export::report::text(
        &outcome.manifest,
        &crate::export::report::Extras {
            notes: &outcome.notes,
            scheme_report: &outcome.scheme_report,
            times: &outcome.times,
            files: &outcome.files,
        },
        out,
    )
}
