//! The pipeline for one job as named stages, each returning a plain struct the next
//! takes: [`load`] (read, repair, simplify) → [`prepare`] (scale, split, size checks)
//! → [`scheme`] → [`flatten`] (unroll, fit labels) → [`nest`] → [`export`] (sheets in
//! every format, the manifest). [`run_observed`] composes them, times them and writes
//! the output folder; the tests, benches and examples call the same stages.

use std::path::Path;
use std::time::{Duration, Instant};

use glam::DVec2;
use rayon::prelude::*;

use crate::config::{Job, NonPlanar};
use crate::error::{Error, InputError, Result};
use crate::export::folder::{check_output_folder, MANIFEST};
use crate::export::manifest::{self, round4, Manifest};
use crate::export::{draw_sheet, obj::assembled_obj, Lengths, PathOrder};
use crate::flatten::unroll_all;
use crate::labels::{LabelOptions, LeftOut};
use crate::mesh::planarize::{planarize, PlanarizeOptions, PlanarizeReport};
use crate::mesh::split::{faces_to_split, split_faces};
use crate::mesh::FaceId;

use crate::nest::{lay_out_observed, Layout, NesterName, SheetSpec};
use crate::panel::{Covers, FlatPanelRef, FlatPanels, FoldKind};
use crate::plane::is_simple;
use crate::scheme::SchemeOutput;

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

/// One sheet's files, path lengths and manifest entry.
struct DrawnSheet {
    files: Vec<(String, Vec<u8>)>,
    lengths: Lengths,
    /// Travel with the paths as placed, for the travel the order saves.
    travel_as_placed: f64,
    entry: manifest::SheetEntry,
}

/// A spinner on stderr naming the running stage with its time so far, a bar for the
/// stages that say how far they have got (the nest, the sheets' drawing): only when
/// stderr is a terminal and the job is not `--quiet`, so Make and CI logs stay as they
/// were. Cleared when dropped, whatever the outcome.
struct Progress(Option<indicatif::ProgressBar>);

/// Steps of a progress bar.
const BAR_STEPS: u64 = 1000;

impl Progress {
    fn new(job: &Job) -> Self {
        use std::io::IsTerminal;
        if job.quiet || !std::io::stderr().is_terminal() {
            return Progress(None);
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(Duration::from_millis(120));
        Progress(Some(bar))
    }

    /// Names the stage now running, with a spinner (and for an internal error's
    /// message).
    fn stage(&self, what: &str) {
        crate::internal::enter_stage(what);
        if let Some(bar) = &self.0 {
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            {
                bar.set_style(style);
            }
            bar.reset_elapsed();
            bar.set_message(what.to_string());
        }
    }

    /// Names the stage now running, with a bar that [`Progress::set`] fills.
    fn bar(&self, what: &str) {
        crate::internal::enter_stage(what);
        if let Some(bar) = &self.0 {
            // In this order, so no frame mixes the old stage's name or style with the
            // new one's.
            bar.set_length(BAR_STEPS);
            bar.set_position(0);
            let template = "{spinner} {msg} [{bar:30}] {percent:>3} % ({elapsed})";
            if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.reset_elapsed();
            bar.set_message(what.to_string());
        }
    }

    /// The bar's stage has done `done` (0 to 1) of its work.
    fn set(&self, done: f64) {
        if let Some(bar) = &self.0 {
            bar.set_position((done.clamp(0.0, 1.0) * BAR_STEPS as f64) as u64);
        }
    }

    /// Runs `f` (which prints) with the spinner off the screen.
    fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.0 {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

struct Stopwatch {
    last: Instant,
    times: Vec<(&'static str, Duration)>,
}

impl Stopwatch {
    fn new() -> Self {
        Self {
            last: Instant::now(),
            times: Vec::new(),
        }
    }

    fn lap(&mut self, stage: &'static str) {
        let now = Instant::now();
        self.times.push((stage, now - self.last));
        self.last = now;
    }
}

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
/// pointing at its line in `raw`. Shared by [`run`] and the tests that check the
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
        job.scheme.scheme.needs_convex_faces(),
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
fn repaired(mut trial: Job, repairs: crate::sanity::Repairs) -> Option<crate::mesh::Mesh> {
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
fn scheme_error(job: &Job, e: crate::scheme::SchemeError) -> Error {
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
            format!("try {}", job.scheme.scheme.overlap_fix())
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

/// The files of a run and its manifest.
pub struct Exported {
    /// Name and bytes of every file, the manifest last.
    pub files: Vec<(String, Vec<u8>)>,
    /// The manifest (also the last file).
    pub manifest: Manifest,
}

/// Stage 6, export: draws every sheet in every format, telling `done` the share of the
/// sheets drawn as each one is, and builds the manifest: the output folder's files,
/// which [`run_observed`] writes.
pub fn export(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    flat: &Flat,
    nested: &Nested,
    warnings: Vec<String>,
    done: &(dyn Fn(f64) + Sync),
) -> Result<Exported> {
    let drawn_sheets = std::sync::atomic::AtomicUsize::new(0);
    let layout = &nested.layout;
    let panels = &flat.panels;
    let name = job
        .model_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    let digits = layout.sheets.to_string().len().max(2);
    // Sheets are independent: drawn in parallel, collected in sheet order.
    let drawn: Vec<DrawnSheet> = (0..layout.sheets)
        .into_par_iter()
        .map(|index| {
            let stem = format!("{name}-{:0digits$}", index + 1);
            let sheet = draw_one_sheet(job, layout, panels, index, &stem);
            let count = drawn_sheets.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            done(count as f64 / layout.sheets as f64);
            sheet
        })
        .collect();
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut lengths = Lengths::default();
    let mut travel_as_placed = 0.0;
    let mut sheet_entries = Vec::new();
    for sheet in drawn {
        files.extend(sheet.files);
        // Summed in sheet order, so the totals do not depend on the thread count.
        lengths.add(&sheet.lengths);
        travel_as_placed += sheet.travel_as_placed;
        sheet_entries.push(sheet.entry);
    }
    let laser = manifest::Laser {
        speeds: manifest::Speeds {
            cut: job.speeds.cut,
            score: job.speeds.score,
            engrave: job.speeds.engrave,
            travel: job.speeds.travel,
        },
        time_s: round4(job.speeds.seconds(&lengths)),
        travel_as_placed: round4(travel_as_placed),
    };
    let mut manifest = build_manifest(
        job,
        prepared,
        output,
        flat,
        nested,
        (lengths, laser),
        sheet_entries,
    );
    let map = model_files(job, prepared, output, layout, &name, &mut files);
    manifest.warnings = warnings;
    if job.preview {
        let page = preview(job, layout, panels, &name, &manifest, &map);
        files.push((format!("{name}.html"), page.into_bytes()));
    }
    manifest.files = files
        .iter()
        .map(|(n, _)| n.clone())
        .chain([MANIFEST.to_string()])
        .collect();
    let json = serde_json::to_string_pretty(&manifest)
        .map_err(|e| Error::internal("writing the manifest", e))?;
    files.push((MANIFEST.into(), (json + "\n").into_bytes()));
    Ok(Exported { files, manifest })
}

/// The assembled model and the pages of the assembly map, added to `files`; returns
/// the map's pages (none with `--no-map`).
fn model_files(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    layout: &Layout,
    name: &str,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Vec<String> {
    // Where each panel sits on the model: for the map, and for the assembled model of
    // a scheme that builds on a surface of its own (its pieces there, without tabs).
    let surface = (job.map || output.surface.is_some()).then(|| {
        crate::panel::surface::panel_surface(
            output
                .surface
                .as_ref()
                .unwrap_or(&prepared.scheme_mesh.mesh),
            &output.panels,
            &output.face_groups,
        )
    });
    let assembled = match (&output.surface, &surface) {
        (Some(_), Some(surface)) => crate::export::obj::surface_obj(&output.panels, surface),
        _ if output.thickness > 0.0 => {
            crate::export::obj::solid_obj(&output.panels, output.thickness)
        }
        _ => assembled_obj(&output.panels),
    };
    files.push((format!("{name}-assembled.obj"), assembled.into_bytes()));
    let map = surface.as_ref().filter(|_| job.map).map(|surface| {
        crate::export::map::assembly_map(&crate::export::map::MapInput {
            surface,
            panels: &output.panels,
            layout,
            name,
        })
    });
    let map = map.unwrap_or_default();
    for (k, page) in map.iter().enumerate() {
        files.push((map_file(name, k), page.clone().into_bytes()));
    }
    map
}

/// The file of page `k` (from 0) of the assembly map: `NAME-map.svg`, then
/// `NAME-map-2.svg`…
fn map_file(name: &str, k: usize) -> String {
    match k {
        0 => format!("{name}-map.svg"),
        _ => format!("{name}-map-{}.svg", k + 1),
    }
}

/// The preview page ([`crate::export::preview`]): every sheet drawn again with strokes
/// wide enough to see, beside the map and the manifest's figures.
fn preview(
    job: &Job,
    layout: &Layout,
    panels: &FlatPanels,
    name: &str,
    manifest: &Manifest,
    map: &[String],
) -> String {
    let mut style = job.style.clone();
    let stroke = crate::export::preview::preview_stroke(layout.sheet.width);
    for layer in style.layers.0.iter_mut() {
        layer.stroke_width = layer.stroke_width.max(stroke);
    }
    let sheets: Vec<String> = (0..layout.sheets)
        .into_par_iter()
        .map(|index| {
            let svg = crate::export::Format::Svg.write_sheet(layout, index, panels, &style);
            String::from_utf8_lossy(&svg).into_owned()
        })
        .collect();
    crate::export::preview::preview_page(&crate::export::preview::PreviewInput {
        name,
        manifest,
        sheets: &sheets,
        map,
    })
}

/// Sheet `index` of `layout` in every format of the job, its files named `stem`.ext,
/// with its path lengths (nearest first, and as placed for the travel) and its
/// manifest entry.
fn draw_one_sheet(
    job: &Job,
    layout: &Layout,
    panels: &FlatPanels,
    index: usize,
    stem: &str,
) -> DrawnSheet {
    let sheet = layout.sheet;
    let sheet_files: Vec<(String, Vec<u8>)> = job
        .formats
        .iter()
        .map(|format| {
            (
                format!("{stem}.{}", format.extension()),
                format.write_sheet(layout, index, panels, &job.style),
            )
        })
        .collect();
    let mut lengths = Lengths::default();
    draw_sheet(
        layout,
        index,
        panels,
        false,
        PathOrder::Shortest,
        &mut lengths,
    );
    let mut as_placed = Lengths::default();
    draw_sheet(
        layout,
        index,
        panels,
        false,
        PathOrder::AsPlaced,
        &mut as_placed,
    );
    let on_sheet: Vec<FlatPanelRef> = layout
        .placements
        .iter()
        .filter(|p| p.sheet == index)
        .map(|p| panels.get(p.part))
        .collect();
    let area: f64 = on_sheet.iter().map(|p| p.area).sum();
    let entry = manifest::SheetEntry {
        sheet: index + 1,
        files: sheet_files.iter().map(|(n, _)| n.clone()).collect(),
        panels: on_sheet.len(),
        fill: round4(area / (sheet.width * sheet.height)),
        lengths: manifest::Lengths::of(&lengths),
        time_s: round4(job.speeds.seconds(&lengths)),
    };
    DrawnSheet {
        files: sheet_files,
        lengths,
        travel_as_placed: as_placed.travel,
        entry,
    }
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

/// Score lines of every panel that fold as `kind`.
fn folds_of(flat: &FlatPanels, kind: FoldKind) -> usize {
    flat.iter()
        .map(|p| p.folds.iter().filter(|f| f.kind == kind).count())
        .sum()
}

fn build_manifest(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    flat: &Flat,
    nested: &Nested,
    (lengths, laser): (Lengths, manifest::Laser),
    sheets: Vec<manifest::SheetEntry>,
) -> Manifest {
    let SchemeMesh {
        mesh,
        split,
        mm_per_unit,
        ..
    } = &prepared.scheme_mesh;
    let (topology, layout, labels_left_out) =
        (&prepared.topology, &nested.layout, &flat.labels_left_out);
    let flat = &flat.panels;
    let sheet = &layout.sheet;
    let panel_area: f64 = flat.iter().map(|p| p.area).sum();
    let usable = sheet.usable_width() * sheet.usable_height();
    let lower_bound = (panel_area / usable).ceil() as usize;
    // Faces made by splitting or simplification, or of a scheme's own surface, have no
    // face in the input file.
    let input_face = |f: u32| {
        let source = output
            .surface
            .is_none()
            .then(|| mesh.face_source(FaceId(f)));
        source.filter(|&s| s != u32::MAX)
    };
    let panels = manifest::panel_entries(flat, layout, input_face, &output.face_groups);
    Manifest {
        tool: manifest::Tool {
            name: "unfold",
            version: env!("CARGO_PKG_VERSION"),
        },
        input: manifest::Input {
            path: job.model_path.display().to_string(),
            vertices: topology.vertices,
            edges: topology.edges,
            faces: topology.faces,
            boundary_loops: topology.boundary_loops,
            components: topology.components.len(),
            genus: topology.genus,
            faces_split: manifest::FacesSplit {
                non_planar: split.non_planar.len(),
                not_star_shaped: split.not_star_shaped.len(),
            },
        },
        scheme: manifest::Scheme {
            name: job.scheme.name().to_string(),
            params: {
                let mut params = job.scheme.params();
                params.push("mm_per_model_unit", *mm_per_unit);
                params
            },
        },
        units: "mm",
        sheet: manifest::Sheet {
            name: job.sheet.name.clone(),
            width: round4(sheet.width),
            height: round4(sheet.height),
            margin: round4(sheet.margin),
            spacing: round4(sheet.spacing),
            kerf: round4(job.kerf),
        },
        counts: manifest::Counts {
            panels: flat.len(),
            sheets: layout.sheets,
            sheets_lower_bound: lower_bound,
            sheets_spacing_bound: nested.spacing_bound.max(lower_bound), // both hold: the larger
            holes: flat.iter().map(|p| p.holes.len()).sum(),
            connections: output.connections,
            connections_by_holes: manifest::connections_by_holes(flat, output.connections),
            fasteners: flat.iter().map(|p| p.holes.len()).sum::<usize>() / 2,
            folds_mountain: folds_of(flat, FoldKind::Mountain),
            folds_valley: folds_of(flat, FoldKind::Valley),
            labels_left_out: labels_left_out.total(),
            panel_ids_left_out: labels_left_out.panel,
            partner_ids_left_out: labels_left_out.partner,
        },
        nesting: nested.nesting.clone(),
        panel_area: round4(panel_area),
        utilization: round4(panel_area / (layout.sheets as f64 * sheet.width * sheet.height)),
        lengths: manifest::Lengths::of(&lengths),
        laser,
        scheme_sections: output.manifest.clone(),
        max_developability_error: manifest::round_nm(
            flat.iter()
                .map(|p| p.developability_error)
                .fold(0.0, f64::max),
        ),
        sheets,
        warnings: Vec::new(),
        files: Vec::new(),
        panels,
    }
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
