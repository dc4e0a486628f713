//! The first stage of every job and of `inspect`: read a model and prepare it
//! (repairs, `--min-component`, `--fill-holes`, simplification to a panel budget).

use std::path::Path;

use crate::config::ModelSettings;
use crate::error::{self, InputError, Result};
use crate::mesh::{self, components::SmallComponents, Note, PrepareOptions, PreparedModel};

/// What to do when a simplification budget was refused: the fewest edges or faces the
/// topology allows, or building without simplification.
fn refused_budget_fix(error: &mesh::simplify::SimplifyError) -> String {
    use mesh::simplify::SimplifyError;
    match error {
        SimplifyError::BelowMinimum { what, fewest, .. } => format!(
            "give --target-{what} {fewest} or more"
        ),
        _ => "build it without --target-edges; this is a bug in unfold: please report it with the model file".to_string(),
    }
}

/// Reads and prepares a model: the first two stages of every job. Simplification (with
/// `--target-edges` / `--target-faces`) is part of preparation.
pub fn load_model(
    path: &Path,
    settings: &ModelSettings,
) -> Result<(mesh::RawModel, PreparedModel)> {
    let raw = mesh::read_model(path)?;
    let mut prepared = mesh::prepare(
        &raw,
        &PrepareOptions {
            weld: settings.weld,
        },
    )?;
    if settings.min_component > 1 {
        drop_small_components(path, settings.min_component, &mut prepared)?;
    }
    if settings.fill_holes {
        fill_holes(&mut prepared)?;
    }
    if let Some(budget) = settings.budget {
        let (simplified, report) =
            mesh::simplify::simplify(&prepared.mesh, budget, settings.simplify_mode).map_err(
                |e| {
                    let fix = refused_budget_fix(&e);
                    InputError::new(path, error::Location::File, e.to_string(), fix)
                },
            )?;
        let mode = match report.fallback {
            None => format!("{} mode", settings.simplify_mode),
            Some(used) => format!(
                "{} mode; meshoptimizer's result did not keep the topology or the budget, so {used} were used",
                settings.simplify_mode
            ),
        };
        // Deviations in millimetres of the built model, as the build scales it.
        let mm_per_unit = settings.scaling.mm_per_unit(simplified.longest_side());
        let message = if report.before == report.after {
            format!(
                "{} faces and {} edges are already within the budget; not simplified",
                report.before.0, report.before.1
            )
        } else {
            format!(
                "simplified from {} faces and {} edges to {} faces and {} edges ({}; longest edge {:.1} times the median, 95 % within {:.2}){}; deviation from the original surface {} mm at most, {} mm on average when built (measured at every original vertex and triangle centre)",
                report.before.0, report.before.1, report.after.0, report.after.1, mode,
                report.edge_spread, report.edge_spread_95,
                if report.relaxed_moves + report.relaxed_flips > 0 {
                    format!("; vertices relaxed toward even edges in {} moves and {} edge flips toward rounder triangles, without increasing the largest or mean deviation", report.relaxed_moves, report.relaxed_flips)
                } else {
                    String::new()
                },
                crate::units::short_number(report.deviation * mm_per_unit),
                crate::units::short_number(report.mean_deviation * mm_per_unit)
            )
        };
        prepared.notes.push(Note {
            kind: "simplified",
            message,
        });
        if settings.keep_unsimplified && report.before != report.after {
            prepared.unsimplified = Some(mesh::simplify::surface_triangles(&prepared.mesh));
        }
        prepared.mesh = simplified;
    }
    Ok((raw, prepared))
}

/// `--fill-holes`: every boundary loop closed ([`mesh::holes::fill_holes`]), with a note.
fn fill_holes(prepared: &mut PreparedModel) -> Result<()> {
    let filled = mesh::holes::fill_holes(&prepared.mesh)
        .map_err(|e| error::Error::internal("closing the holes", e))?;
    if let Some((closed, filled)) = filled {
        prepared.notes.push(Note {
            kind: "filled-holes",
            message: match filled.joined {
                0 => format!(
                    "--fill-holes closed {} with one face each (the largest has {} edges)",
                    crate::units::count_of(filled.holes, "hole"),
                    filled.largest
                ),
                joined => format!(
                    "--fill-holes closed {} (the largest has {} edges): {joined} of them open seams whose rims meet themselves, joined where they meet and capped only where they enclose area, the others with one face each",
                    crate::units::count_of(filled.holes, "hole"),
                    filled.largest
                ),
            },
        });
        prepared.mesh = closed;
    }
    Ok(())
}

/// `--min-component`: removes the components of fewer than `min_faces` faces, with a
/// note; refuses a model where nothing would be left.
fn drop_small_components(
    path: &Path,
    min_faces: usize,
    prepared: &mut PreparedModel,
) -> Result<()> {
    let refuse = |problem: String| {
        InputError::new(
            path,
            error::Location::File,
            problem,
            "lower --min-component",
        )
    };
    match mesh::components::drop_small_components(&prepared.mesh, min_faces)
        .map_err(|e| refuse(e.to_string()))?
    {
        SmallComponents::NoneSmall => Ok(()),
        SmallComponents::AllSmall { largest } => Err(refuse(format!(
            "every component has fewer than --min-component {min_faces} faces (the largest has {largest})"
        ))
        .into()),
        SmallComponents::Dropped(kept, report) => {
            let faces: usize = report.sizes.iter().sum();
            let sizes: Vec<String> = report.sizes.iter().map(|n| n.to_string()).collect();
            prepared.notes.push(Note {
                kind: "small-components",
                message: format!(
                    "removed {} components with fewer than {min_faces} faces ({faces} faces; sizes {}); {} components kept",
                    report.sizes.len(),
                    sizes.join(", "),
                    report.kept
                ),
            });
            prepared.mesh = *kept;
            Ok(())
        }
    }
}
