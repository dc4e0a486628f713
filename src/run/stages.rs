//! Stages 1 to 5 of a job, each returning a plain struct the next takes: [`load`] (read,
//! repair, simplify), [`prepare`] (scale, split, size checks), [`scheme`], [`flatten`]
//! (unroll, fit labels) and [`nest`].

use glam::DVec2;

use crate::config::{Job, NonPlanar};
use crate::error::{Error, InputError, Result};
use crate::export::manifest;
use crate::flatten::unroll_all;
use crate::labels::{LabelOptions, LeftOut};
use crate::mesh::planarize::{planarize, PlanarizeOptions, PlanarizeReport};
use crate::mesh::split::{faces_to_split, split_faces};
use crate::mesh::FaceId;
use crate::nest::{lay_out_observed, Layout, NesterName, SheetSpec};
use crate::panel::{Covers, FlatPanels};
use crate::plane::is_simple;
use crate::scheme::SchemeOutput;

/// The mesh a scheme works on, and how it was made from the prepared one.
#[derive(Clone, Debug)]
pub struct SchemeMesh {
    /// Scaled to millimetres, with the faces the scheme cannot build split.
    pub mesh: crate::mesh::Mesh,
    /// Which faces were split and why.
    pub split: crate::mesh::split::SplitReport,
    /// Millimetres per model unit.
    pub mm_per_unit: f64,
    /// What `--nonplanar planarize` did (displacements in mm).
    pub planarized: Option<PlanarizeReport>,
}

/// Scales the prepared mesh to millimetres and splits the faces the job's scheme
/// cannot build as one flat piece (non-planar; not star-shaped, or for the edge
/// schemes not convex). With `--nonplanar error` a non-planar face is an input error
/// pointing at its line in `raw`. Shared by [`run`](super::run) and the tests that check the
/// pipeline stage by stage.
pub fn scheme_mesh(
    job: &Job,
    raw: &crate::mesh::RawModel,
    mut mesh: crate::mesh::Mesh,
) -> Result<SchemeMesh> {
    // Only the size here: the planarity of every face is measured once, by
    // `faces_to_split` below, on the scaled mesh.
    let mm_per_unit = job
        .model
        .checked_mm_per_unit(&job.model_path, mesh.longest_side())?;
    mesh.scale(mm_per_unit);
    let planarized = if job.nonplanar == NonPlanar::Planarize {
        Some(planarize_faces(
            &job.model_path,
            &mut mesh,
            job.model.planarity_tol,
        )?)
    } else {
        None
    };
    let split = faces_to_split(
        &mesh,
        job.model.planarity_tol,
        job.scheme.scheme.info().needs_convex_faces,
    );
    if job.nonplanar == NonPlanar::Error && !split.non_planar.is_empty() {
        let worst = FaceId(split.non_planar[0]);
        let source = mesh.face_source(worst) as usize;
        return Err(InputError::new(
            &job.model_path,
            raw.face_location(source),
            format!(
                "{} faces are not planar within --planarity-tol {} (first: face {source})",
                split.non_planar.len(),
                job.model.planarity_tol
            ),
            "use --nonplanar triangulate, raise --planarity-tol, or flatten the faces in your modeller",
        )
        .into());
    }
    if split.count() > 0 {
        mesh = split_faces(&mesh, &split)
            .map_err(|e| Error::internal("splitting faces into triangles", e))?;
    }
    Ok(SchemeMesh {
        mesh,
        split,
        mm_per_unit,
        planarized,
    })
}

/// `--nonplanar planarize` on a mesh in millimetres: the build's step, shared with
/// `inspect` so its preview is the same computation.
pub fn planarize_faces(
    model_path: &std::path::Path,
    mesh: &mut crate::mesh::Mesh,
    planarity_tol: f64,
) -> Result<PlanarizeReport> {
    let options = PlanarizeOptions {
        tolerance: planarity_tol,
        ..PlanarizeOptions::default()
    };
    planarize(mesh, &options).map_err(|e| {
        Error::Build(format!(
            "{}: {e}; use --nonplanar triangulate",
            model_path.display()
        ))
    })
}

/// The model as read and prepared (repairs, simplification), in model units.
pub struct Loaded {
    /// The file as read, for messages that point at its lines.
    pub raw: crate::mesh::RawModel,
    /// The prepared mesh and the notes of its repairs.
    pub prepared: crate::mesh::PreparedModel,
}

/// The mesh the scheme builds, in millimetres, and what was found on the way.
pub struct Prepared {
    /// Scaled, split (and planarized) as the scheme needs.
    pub scheme_mesh: SchemeMesh,
    /// Its topology, for the manifest.
    pub topology: crate::mesh::Topology,
    /// Observations for the report (repairs, split faces, planarization).
    pub notes: Vec<String>,
    /// Findings about the build's size, each naming its fix.
    pub warnings: Vec<String>,
    /// The surface before simplifying, in millimetres, where the scheme keeps a
    /// distance to it ([`crate::mesh::PreparedModel::unsimplified`]).
    pub unsimplified: Option<Vec<[glam::DVec3; 3]>>,
    /// Whether `--weld` would join vertices the model keeps apart.
    can_weld: bool,
    /// The budget the warnings suggest, once one needed it.
    clean_budget: std::cell::OnceCell<Option<crate::sanity::Suggestion>>,
}

impl Prepared {
    /// The budget at which the model, simplified, builds with nothing to warn of:
    /// found (by trial builds) the first time a warning asks.
    pub fn clean_budget(&self, job: &Job) -> Option<crate::sanity::Suggestion> {
        *self.clean_budget.get_or_init(|| {
            crate::sanity::clean_budget(job, &self.scheme_mesh.mesh, self.can_weld, &model_at)
        })
    }
}

/// The flat panels with their labels fitted.
pub struct Flat {
    /// The panels, unrolled, in the scheme's order.
    pub panels: FlatPanels,
    /// Labels left out for want of room.
    pub labels_left_out: LeftOut,
    /// The finding when too many panel ids were left out.
    pub warning: Option<String>,
    /// What the kerf compensation could not do.
    pub notes: Vec<String>,
}

/// The panels laid out on sheets.
pub struct Nested {
    /// Where each panel lies.
    pub layout: Layout,
    /// The search as the manifest records it.
    pub nesting: manifest::Nesting,
    /// Sheets the panel area needs counting the spacing.
    pub spacing_bound: usize,
    /// Observations for the report.
    pub notes: Vec<String>,
}

/// The job's model repaired as `repairs` say and simplified to `edges` as
/// `--target-edges` would do it, scaled and split for the scheme: what a warning's
/// suggested budget is tried on.
fn model_at(job: &Job, edges: usize, repairs: crate::sanity::Repairs) -> Option<crate::mesh::Mesh> {
    let mut trial = job.clone();
    trial.model.budget = Some(crate::mesh::simplify::Budget::Edges(edges));
    trial.model.auto_budget = false;
    repaired(trial, repairs)
}

/// The model of `trial` repaired as `repairs` say (on top of its own options), scaled
/// and split for the scheme.
pub(super) fn repaired(
    mut trial: Job,
    repairs: crate::sanity::Repairs,
) -> Option<crate::mesh::Mesh> {
    // A trial builds from the mesh alone.
    trial.model.keep_unsimplified = false;
    trial.model.weld |= repairs.weld;
    trial.model.fill_holes |= repairs.fill_holes;
    let loaded = load(&trial).ok()?;
    let mesh = scheme_mesh(&trial, &loaded.raw, loaded.prepared.mesh).ok()?;
    Some(mesh.mesh)
}

/// Stage 1, load: reads and prepares the model.
pub fn load(job: &Job) -> Result<Loaded> {
    let (raw, prepared) = crate::load_model(&job.model_path, &job.model)?;
    Ok(Loaded { raw, prepared })
}

/// Stage 2, prepare: scales to millimetres, splits (or planarizes) the faces the
/// scheme cannot build, and checks the build's size (an error under `--strict`).
pub fn prepare(job: &Job, loaded: Loaded) -> Result<Prepared> {
    let mut notes: Vec<String> = loaded
        .prepared
        .notes
        .iter()
        .map(|n| n.message.clone())
        .collect();
    let can_weld = loaded
        .prepared
        .notes
        .iter()
        .any(|n| n.kind == "shared-positions");
    let unsimplified = loaded.prepared.unsimplified;
    let scheme_mesh = scheme_mesh(job, &loaded.raw, loaded.prepared.mesh)?;
    let mm_per_unit = scheme_mesh.mm_per_unit;
    let unsimplified = unsimplified.map(|triangles| {
        triangles
            .into_iter()
            .map(|t| t.map(|p| p * mm_per_unit))
            .collect()
    });
    let split = &scheme_mesh.split;
    if let Some(report) = scheme_mesh
        .planarized
        .as_ref()
        .filter(|r| r.non_planar_before > 0)
    {
        notes.push(format!(
            "planarized {} non-planar faces (of {} with four or more corners) in {} iterations: largest planarity error {:.2e} -> {:.2e}, largest vertex move {:.3} mm",
            report.non_planar_before,
            report.polygons,
            report.iterations,
            report.max_error_before,
            report.max_error_after,
            report.max_displacement
        ));
    }
    if !split.non_planar.is_empty() {
        notes.push(format!(
            "{} non-planar faces were split into triangles (planarity tolerance {})",
            split.non_planar.len(),
            job.model.planarity_tol
        ));
    }
    if !split.not_star_shaped.is_empty() {
        notes.push(format!(
            "{} concave faces were split into triangles: the scheme's bands, tabs or flaps would leave them",
            split.not_star_shaped.len()
        ));
    }
    let warnings = crate::sanity::check_size(job, &scheme_mesh.mesh)?.warnings;
    let topology = scheme_mesh.mesh.topology();
    Ok(Prepared {
        scheme_mesh,
        topology,
        notes,
        warnings,
        unsimplified,
        can_weld,
        clean_budget: std::cell::OnceCell::new(),
    })
}

/// Stage 3, scheme: the job's scheme builds the 3D panels.
pub fn scheme(job: &Job, prepared: &Prepared) -> Result<SchemeOutput> {
    let mesh = &prepared.scheme_mesh.mesh;
    let output = match &prepared.unsimplified {
        Some(unsimplified) => job.scheme.build_near(mesh, unsimplified),
        None => job.scheme.build(mesh),
    }
    .map_err(|e| scheme_error(job, e))?;
    crate::memory::release_freed();
    Ok(output)
}

/// A scheme's refusal of the job's model as the tool's error (a usage error when the
/// options are at fault).
pub(super) fn scheme_error(job: &Job, e: crate::scheme::SchemeError) -> Error {
    let message = format!("{}: {e}", job.model_path.display());
    if e.is_usage() {
        Error::Usage(message)
    } else {
        Error::Build(message)
    }
}

/// Stage 4, flatten: unrolls every panel and fits its labels; a panel that overlaps
/// itself is an error naming it. Then the cut loops move for the kerf.
pub fn flatten(job: &Job, prepared: &Prepared, output: &SchemeOutput) -> Result<Flat> {
    let mesh = &prepared.scheme_mesh.mesh;
    let least_fold = job.scheme.least_scored_fold();
    let (flat, labels_left_out) = unroll_all(&output.panels, LabelOptions::default(), least_fold)
        .map_err(|e| Error::internal("unrolling the panels", e))?;
    let unsimplified = prepared.unsimplified.as_deref();
    let budget = || prepared.clean_budget(job);
    let left_out = &labels_left_out;
    let warning =
        crate::sanity::check_labels(job, mesh, unsimplified, flat.len(), left_out, &budget)?;
    if let Some(bad) = flat.iter().find(|p| !is_simple(&p.outer())) {
        // Say why when a face far from planar was kept by a loose tolerance: its panel
        // is a projection of a warped polygon.
        let warped = match bad.source.covers {
            Covers::Face(f) => {
                let corners: Vec<glam::DVec3> = mesh.face_positions(FaceId(f)).collect();
                crate::mesh::geometry::planarity_error(&corners)
            }
            _ => 0.0,
        };
        let advice = if warped > 1e-3 {
            format!(
                "its face is far from planar (planarity error {warped:.3}): lower --planarity-tol so such faces are triangulated"
            )
        } else {
            format!("try {}", job.scheme.scheme.info().overlap_fix)
        };
        return Err(Error::Build(format!(
            "panel {} overlaps itself when unrolled; {advice}",
            bad.id()
        )));
    }
    let mut notes = Vec::new();
    let flat = if job.kerf > 0.0 {
        let compensated = crate::kerf::compensate_all(&flat, job.kerf);
        if compensated.narrow_panels > 0 {
            notes.push(format!(
                "{} panels have cut edges closer together than the {} mm kerf (a tab beside the face next to it, a narrow notch): there the cut stays on its nominal line and the part loses half the kerf",
                compensated.narrow_panels,
                crate::units::fmt_num(job.kerf)
            ));
        }
        compensated.panels
    } else {
        flat
    };
    Ok(Flat {
        panels: flat,
        labels_left_out,
        warning,
        notes,
    })
}

/// Stage 5, nest: lays the flat panels out on sheets, telling `done` the fraction of
/// the search done each time it grows.
pub fn nest(job: &Job, flat: &Flat, done: &(dyn Fn(f64) + Sync)) -> Result<Nested> {
    let flat = &flat.panels;
    let sheet = SheetSpec {
        width: job.sheet.width,
        height: job.sheet.height,
        margin: job.margin,
        spacing: job.spacing,
    };
    let outlines: Vec<Vec<DVec2>> = flat.iter().map(|p| p.outer()).collect();
    // The options do not fit the model: a usage error (exit 2), like any other.
    let too_large = |e: crate::nest::TooLarge| {
        Error::Usage(format!(
            "panel {} is {:.1} x {:.1} mm and does not fit on the {} sheet (usable {:.1} x {:.1} mm inside the margin); use a larger --sheet or a smaller --size",
            flat.get(e.part).id(), e.width, e.height, job.sheet.name, e.usable_width, e.usable_height
        ))
    };
    let areas: Vec<f64> = flat.iter().map(|p| p.area).collect();
    let progress = crate::nest::NestProgress::new(done);
    let nested =
        lay_out_observed(&outlines, &areas, sheet, &job.nest, &progress).map_err(too_large)?;
    let mut notes = Vec::new();
    // The search ran but the shelf layout was kept: it took fewer sheets.
    if let (NesterName::Shelf, Some(searched)) = (nested.nester, nested.search_phases) {
        notes.push(format!(
            "the true-shape search needed {} sheets and the shelf layout {}: the shelf layout is used",
            searched.squeezed, nested.shelf_sheets
        ));
    }
    let search = &job.nest.search;
    let nesting = manifest::Nesting {
        nester: nested.nester.as_str(),
        effort: search.effort,
        seed: search.seed,
        rotations: search.rotations,
        mirror: search.mirror,
        time_limit: search.time_limit.map(|t| t.as_secs_f64()),
        shelf_sheets: nested.shelf_sheets,
        search_sheets: nested.search_phases,
    };
    Ok(Nested {
        layout: nested.layout,
        nesting,
        spacing_bound: nested.spacing_bound,
        notes,
    })
}
