//! End-to-end tests of the build pipeline with the half-edge scheme: the real binary
//! (`CARGO_BIN_EXE_unfold`) writes its output folder into a temporary directory and the
//! independent sheet checker of `tests/common` reads it back; a few checks call the
//! library stages directly (scheme → flatten) to follow holes and labels back to 3D.
//!
//! Tests that use `../shared/models` skip with a message when that folder is absent.
//! The DXF check (ezdxf through `tests/check_dxf.py`) costs about a second per sheet, a
//! few seconds for the big sheets of spot and fertility: for those two models only the
//! first and the last sheet's DXF are checked (every SVG still is), unless
//! `UNFOLD_FULL_DXF=1`.
//!
//! `UNFOLD_UPDATE_GOLDEN=1 cargo test --test build_half_edge golden` rewrites
//! `tests/golden/tetrahedron-half-edge/`.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{DVec2, DVec3};
use serde_json::Value;
use tempfile::TempDir;

use common::{check_dxf_matches_svg, check_svg_sheet, SheetSpec, SheetStats};
use unfold::config::{BuildOptions, Job, ModelOptions, SchemeName};
use unfold::flatten::flatten;
use unfold::mesh::split::{faces_to_split, split_faces};
use unfold::mesh::{EdgeId, Mesh};
use unfold::panel::{FlatPanel, LabelKind, Panel, Source};
use unfold::scheme::build_panels;

// =======================================================================================
// Helpers
// =======================================================================================

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A model of the project's own `models/` folder.
fn model(name: &str) -> PathBuf {
    crate_dir().join("models").join(format!("{name}.obj"))
}

/// The shared models folder, or `None` (with a message) when this checkout has none.
fn shared_models(test: &str) -> Option<PathBuf> {
    let dir = crate_dir().join("../shared/models");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "{test}: skipping the shared models: {} is absent",
            dir.display()
        );
        None
    }
}

/// What one run of the binary did.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

fn unfold_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
}

fn finish(cmd: &mut Command) -> Run {
    let output = cmd.output().expect("the unfold binary runs");
    Run {
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

fn unfold<I, S>(args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    finish(unfold_command().args(args))
}

/// Runs `unfold MODEL --scheme half-edge --size SIZE --out OUT EXTRA…`, asserts success
/// and returns the parsed `manifest.json`.
fn build(model: &Path, size: &str, out: &Path, extra: &[&str]) -> Value {
    let mut args: Vec<&OsStr> = vec![
        model.as_os_str(),
        OsStr::new("--scheme"),
        OsStr::new("half-edge"),
        OsStr::new("--size"),
        OsStr::new(size),
        OsStr::new("--out"),
        out.as_os_str(),
    ];
    args.extend(extra.iter().map(OsStr::new));
    let run = unfold(&args);
    assert_eq!(run.code, Some(0), "unfold {args:?} failed:\n{}", run.stderr);
    read_manifest(out)
}

fn read_manifest(out: &Path) -> Value {
    let text = std::fs::read_to_string(out.join("manifest.json"))
        .unwrap_or_else(|e| panic!("{}/manifest.json: {e}", out.display()));
    serde_json::from_str(&text).expect("manifest.json is JSON")
}

/// The value at a dotted path, as a number (panics naming the key otherwise).
fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_f64()
        .unwrap_or_else(|| panic!("{path} is not a number: {cur}"))
}

fn count(v: &Value, path: &str) -> usize {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_u64()
        .unwrap_or_else(|| panic!("{path} is not a count: {cur}")) as usize
}

/// Every file of a folder (no subfolders expected) with its bytes, by name.
fn folder_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let entry = entry.unwrap();
        assert!(
            entry.file_type().unwrap().is_file(),
            "{} is not a plain file",
            entry.path().display()
        );
        let name = entry.file_name().to_string_lossy().into_owned();
        files.insert(name, std::fs::read(entry.path()).unwrap());
    }
    files
}

/// Names of the entries of a folder.
fn entry_names(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Faces of an OBJ file as written (`f` statements), counted without the tool.
fn obj_face_count(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| l.trim_start().starts_with("f "))
        .count()
}

/// Positions and faces (0-based) of a simple OBJ file (`v x y z`, `f a b c…` with
/// optional `/…` suffixes and positive indices), read without the tool.
fn read_simple_obj(path: &Path) -> (Vec<DVec3>, Vec<Vec<usize>>) {
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for line in std::fs::read_to_string(path).unwrap().lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map(|w| w.parse().unwrap()).collect();
                positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => faces.push(
                words
                    .map(|w| w.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    (positions, faces)
}

/// Area of a planar 3D polygon (Newell's vector area).
fn polygon_area_3d(points: &[DVec3]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| points[i].cross(points[(i + 1) % n]))
        .sum::<DVec3>()
        .length()
        * 0.5
}

/// Even-odd point in polygon, written here rather than taken from `unfold::plane`.
fn inside(poly: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

fn distance_to_border(poly: &[DVec2], p: DVec2) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a))
        })
        .fold(f64::INFINITY, f64::min)
}

fn sheet_spec(manifest: &Value) -> SheetSpec {
    SheetSpec {
        width: num(manifest, "sheet.width"),
        height: num(manifest, "sheet.height"),
        margin: num(manifest, "sheet.margin"),
        spacing: num(manifest, "sheet.spacing"),
    }
}

/// Which DXF files of a folder to run through ezdxf.
#[derive(Clone, Copy, PartialEq)]
enum DxfCheck {
    /// Every one.
    All,
    /// The first and the last sheet (every one with `UNFOLD_FULL_DXF=1`).
    FirstAndLast,
}

/// The sheets of an output folder after the independent check.
struct Sheets {
    /// SVG file names, in order.
    svg_files: Vec<String>,
    /// Stats of every SVG sheet, in the same order.
    stats: Vec<SheetStats>,
}

impl Sheets {
    fn total(&self) -> SheetStats {
        let mut t = SheetStats::default();
        for s in &self.stats {
            t.panels += s.panels;
            t.holes += s.holes;
            t.cut_paths += s.cut_paths;
            t.score_paths += s.score_paths;
            t.engrave_paths += s.engrave_paths;
            t.panel_area += s.panel_area;
            t.cut_length += s.cut_length;
            t.score_length += s.score_length;
            t.engrave_length += s.engrave_length;
        }
        t
    }
}

/// Checks every SVG of `out` with `check_svg_sheet` (sheet spec from the manifest) and
/// the DXF files chosen by `dxf` with `check_dxf_matches_svg` against their SVG.
fn check_sheets(out: &Path, manifest: &Value, dxf: DxfCheck) -> Sheets {
    let spec = sheet_spec(manifest);
    let names = entry_names(out);
    let svg_files: Vec<String> = names
        .iter()
        .filter(|n| n.ends_with(".svg"))
        .cloned()
        .collect();
    let dxf_files: Vec<String> = names
        .iter()
        .filter(|n| n.ends_with(".dxf"))
        .cloned()
        .collect();
    let mut stats = Vec::new();
    for name in &svg_files {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        let s = check_svg_sheet(&text, &spec)
            .unwrap_or_else(|e| panic!("{}: sheet check failed:\n{e}", out.join(name).display()));
        stats.push(s);
    }
    for name in &dxf_files {
        let svg = name.trim_end_matches(".dxf").to_string() + ".svg";
        assert!(svg_files.contains(&svg), "{name} has no SVG twin");
    }
    let full = std::env::var("UNFOLD_FULL_DXF").is_ok_and(|v| v == "1");
    let chosen: Vec<&String> = if dxf == DxfCheck::All || full || dxf_files.len() <= 2 {
        dxf_files.iter().collect()
    } else {
        vec![&dxf_files[0], &dxf_files[dxf_files.len() - 1]]
    };
    // ezdxf runs in child processes: check a few at once.
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    let chunk = chosen.len().div_ceil(workers).max(1);
    let failures: Vec<String> = std::thread::scope(|scope| {
        let handles: Vec<_> = chosen
            .chunks(chunk)
            .map(|names| {
                scope.spawn(move || {
                    names
                        .iter()
                        .filter_map(|name| {
                            let svg_name = name.trim_end_matches(".dxf").to_string() + ".svg";
                            let svg = std::fs::read_to_string(out.join(svg_name)).unwrap();
                            check_dxf_matches_svg(&out.join(name), &svg, spec.height).err()
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("DXF check thread"))
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} DXF files fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
    Sheets { svg_files, stats }
}

/// The pipeline of `src/run.rs` up to the flat panels: read, prepare, scale, split,
/// scheme, flatten. Returns the mesh the scheme used, the 3D and the flat panels.
fn panels_of(job: &Job) -> (Mesh, usize, Vec<Panel>, Vec<FlatPanel>) {
    let (_raw, prepared) = unfold::load_model(&job.model_path, &job.model).expect("model loads");
    let mut mesh = prepared.mesh;
    let geometry = mesh.geometry_facts(job.model.planarity_tol);
    let mm_per_unit = job.model.scaling.mm_per_unit(geometry.longest_side());
    mesh.scale(mm_per_unit);
    let split = faces_to_split(&mesh, job.model.planarity_tol);
    if split.count() > 0 {
        mesh = split_faces(&mesh, &split).expect("split faces");
    }
    let output = build_panels(job.scheme, &mesh, &job.scheme_options).expect("scheme");
    let flat = output
        .panels
        .iter()
        .map(|p| flatten(p).unwrap_or_else(|e| panic!("{}: {e}", p.id)))
        .collect();
    (mesh, output.connections, output.panels, flat)
}

fn half_edge_job(model: &Path, size: &str, holes: u32, out: &Path) -> Job {
    BuildOptions {
        scheme: Some(SchemeName::HalfEdge),
        holes: Some(holes),
        out: Some(out.to_path_buf()),
        model: ModelOptions {
            size: Some(size.to_string()),
            ..Default::default()
        },
        ..Default::default()
    }
    .resolve(model)
    .expect("options resolve")
}

// =======================================================================================
// 1. Every sheet passes the independent check, and the manifest adds up
// =======================================================================================

/// Builds one model with `--sheet 18x24in --format svg,dxf`, checks every sheet and
/// the manifest's counts against the sheets.
fn check_build(model: &Path, size: &str, dxf: DxfCheck) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let what = format!("{} at {size}", model.display());
    let m = build(
        model,
        size,
        &out,
        &["--sheet", "18x24in", "--format", "svg,dxf"],
    );
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    let panels = count(&m, "counts.panels");
    let sheets = count(&m, "counts.sheets");
    assert!(sheets >= 1, "{what}: no sheets");

    // The files: one SVG and one DXF per sheet, the manifest and the assembled model.
    let digits = sheets.to_string().len().max(2);
    let mut expected =
        BTreeSet::from(["manifest.json".to_string(), format!("{name}-assembled.obj")]);
    for k in 1..=sheets {
        expected.insert(format!("{name}-{k:0digits$}.svg"));
        expected.insert(format!("{name}-{k:0digits$}.dxf"));
    }
    assert_eq!(entry_names(&out), expected, "{what}: output files");

    let checked = check_sheets(&out, &m, dxf);
    let total = checked.total();

    // Panels: one per face of the mesh the scheme used (after splits).
    let faces = count(&m, "input.faces");
    assert_eq!(panels, faces, "{what}: one panel per face");
    let own_faces = obj_face_count(model);
    let split =
        count(&m, "input.faces_split.non_planar") + count(&m, "input.faces_split.not_star_shaped");
    if split == 0 {
        assert_eq!(
            faces, own_faces,
            "{what}: nothing split, so the model's own faces"
        );
    } else {
        assert!(
            faces >= own_faces + split,
            "{what}: {split} faces split into triangles, yet only {faces} faces from {own_faces}"
        );
    }

    // Sheets against the manifest.
    assert_eq!(
        checked.svg_files.len(),
        sheets,
        "{what}: SVG files = counts.sheets"
    );
    assert_eq!(total.panels, panels, "{what}: panels on the sheets");
    assert_eq!(
        total.holes,
        count(&m, "counts.holes"),
        "{what}: holes on the sheets"
    );
    let panel_area = num(&m, "panel_area");
    assert!(
        close(total.panel_area, panel_area, 1e-4),
        "{what}: outlines on the sheets enclose {} mm², manifest panel_area {panel_area}",
        total.panel_area
    );
    for (kind, drawn) in [
        ("cut", total.cut_length),
        ("score", total.score_length),
        ("engrave", total.engrave_length),
    ] {
        let said = num(&m, &format!("lengths.{kind}"));
        assert!(
            close(drawn, said, 1e-4),
            "{what}: {kind} length drawn {drawn} mm, manifest says {said} mm"
        );
    }
    let entries = m["sheets"].as_array().expect("manifest sheets list");
    assert_eq!(entries.len(), sheets, "{what}: manifest sheets list");
    for (k, (entry, (file, stats))) in entries
        .iter()
        .zip(checked.svg_files.iter().zip(&checked.stats))
        .enumerate()
    {
        assert_eq!(count(entry, "sheet"), k + 1, "{what}: sheet numbers");
        assert_eq!(
            entry["file"].as_str(),
            Some(file.as_str()),
            "{what}: sheet file"
        );
        assert_eq!(
            count(entry, "panels"),
            stats.panels,
            "{what}: panels on {file}"
        );
    }

    // The per-panel list: one entry per panel, ids F<face>, on the sheet that holds it.
    let list = m["panels"].as_array().expect("manifest panels list");
    assert_eq!(list.len(), panels, "{what}: manifest panels list");
    let mut ids = BTreeSet::new();
    let mut per_sheet = vec![0usize; sheets];
    let mut area_sum = 0.0;
    for p in list {
        let id = p["id"].as_str().unwrap();
        let face = count(p, "source.face");
        assert_eq!(id, format!("F{face}"), "{what}: panel id names its face");
        assert!(ids.insert(id.to_string()), "{what}: panel id {id} twice");
        let sheet = count(p, "sheet");
        assert!(
            (1..=sheets).contains(&sheet),
            "{what}: {id} on sheet {sheet}"
        );
        per_sheet[sheet - 1] += 1;
        area_sum += num(p, "area");
    }
    let on_sheets: Vec<usize> = checked.stats.iter().map(|s| s.panels).collect();
    assert_eq!(per_sheet, on_sheets, "{what}: panels per sheet");
    assert!(
        close(area_sum, panel_area, 1e-6) || (area_sum - panel_area).abs() < 1e-4 * panels as f64,
        "{what}: Σ panel areas {area_sum} vs panel_area {panel_area}"
    );

    // Layout figures.
    let lower = count(&m, "counts.sheets_lower_bound");
    assert!(
        sheets >= lower,
        "{what}: {sheets} sheets below the lower bound {lower}"
    );
    let spec = sheet_spec(&m);
    let usable = (spec.width - 2.0 * spec.margin) * (spec.height - 2.0 * spec.margin);
    let ratio = panel_area / usable;
    if (ratio - ratio.round()).abs() > 1e-6 {
        assert_eq!(lower, ratio.ceil() as usize, "{what}: sheets_lower_bound");
    }
    let utilization = num(&m, "utilization");
    let wanted = panel_area / (sheets as f64 * spec.width * spec.height);
    assert!(
        (utilization - wanted).abs() <= 1e-4,
        "{what}: utilization {utilization}, panel_area / sheet area = {wanted}"
    );
    eprintln!(
        "{what}: {panels} panels on {sheets} sheets (lower bound {lower}), {} holes",
        total.holes
    );
}

#[test]
fn every_sheet_passes_the_independent_check() {
    for name in [
        "tetrahedron",
        "hexahedron",
        "octahedron",
        "dodecahedron",
        "icosahedron",
        "torus-8x6",
    ] {
        check_build(&model(name), "12in", DxfCheck::All);
    }
    for name in ["genus2", "concave", "open-grid"] {
        check_build(&model(name), "300mm", DxfCheck::All);
    }
}

/// The same on the big shared models (a separate test so that it runs beside the
/// project models).
#[test]
fn every_sheet_of_the_shared_models_passes_the_independent_check() {
    let test = "every_sheet_of_the_shared_models_passes_the_independent_check";
    if let Some(shared) = shared_models(test) {
        for name in ["fertility.obj", "spot.obj"] {
            check_build(&shared.join(name), "4ft", DxfCheck::FirstAndLast);
        }
    }
}

// =======================================================================================
// 2. Without tabs the panels are the faces: same area as the surface
// =======================================================================================

#[test]
fn face_areas_equal_the_model_surface_area() {
    for (name, size, size_mm) in [
        ("hexahedron", "12in", 304.8),
        ("dodecahedron", "12in", 304.8),
        ("torus-8x6", "12in", 304.8),
        ("genus2", "300mm", 300.0),
        ("concave", "300mm", 300.0),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);

        let tmp = TempDir::new().unwrap();
        let bare = build(
            &path,
            size,
            &tmp.path().join("bare"),
            &["--connectors", "none", "--face-scale", "1"],
        );
        let area = num(&bare, "panel_area");
        assert!(
            close(area, surface, 1e-6),
            "{name}: panel area without tabs {area} mm², surface area {surface} mm²"
        );
        assert_eq!(
            count(&bare, "counts.connections"),
            0,
            "{name}: no connectors"
        );
        let error = num(&bare, "max_developability_error");
        assert!(
            error < 1e-9 * size_mm,
            "{name}: developability error {error} mm on a {size_mm} mm model"
        );

        // Panel by panel: the area of its face in the file, scaled to millimetres.
        let (positions, faces) = read_simple_obj(&path);
        let mm = num(&bare, "scheme.params.mm_per_model_unit");
        for p in bare["panels"].as_array().unwrap() {
            let face = &faces[count(p, "source.input_face")];
            let points: Vec<DVec3> = face.iter().map(|&v| positions[v] * mm).collect();
            let want = polygon_area_3d(&points);
            let got = num(p, "area");
            assert!(
                (got - want).abs() <= 1e-4 + 1e-9 * want,
                "{name}: panel {} has area {got} mm², its face {want} mm²",
                p["id"]
            );
        }

        let tabs = build(&path, size, &tmp.path().join("tabs"), &[]);
        let with_tabs = num(&tabs, "panel_area");
        assert!(
            with_tabs > area * (1.0 + 1e-6),
            "{name}: tabs add area: {with_tabs} mm² with tabs, {area} mm² without"
        );
        assert!(
            count(&tabs, "counts.connections") > 0,
            "{name}: tabs are connections"
        );
    }
}

/// `unfold inspect MODEL --json --size SIZE`: the built surface area in mm².
fn surface_area_mm2(path: &Path, size: &str) -> f64 {
    let inspect = finish(
        unfold_command()
            .arg("inspect")
            .arg(path)
            .args(["--json", "--size", size]),
    );
    assert_eq!(
        inspect.code,
        Some(0),
        "inspect {}: {}",
        path.display(),
        inspect.stderr
    );
    let facts: Value = serde_json::from_str(&inspect.stdout).expect("inspect --json");
    num(&facts, "physical.surface_area_mm2")
}

#[test]
fn face_scale_shrinks_every_panel_by_its_square() {
    // Without connectors a panel is its face scaled by s about the face centre.
    for (name, size, s) in [
        ("hexahedron", "12in", 0.8),
        ("genus2", "300mm", 0.7),
        ("concave", "300mm", 0.5),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);
        let tmp = TempDir::new().unwrap();
        let out = tmp.path().join("out");
        let scale = s.to_string();
        let m = build(
            &path,
            size,
            &out,
            &["--connectors", "none", "--face-scale", &scale],
        );
        let area = num(&m, "panel_area");
        assert!(
            close(area, s * s * surface, 1e-6),
            "{name}: --face-scale {s}: panel area {area} mm², want {s}² × {surface} mm²"
        );
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        assert_eq!(sheets.total().panels, count(&m, "counts.panels"));
    }
}

/// With `s < 1` each tab first spans the gap between its panel and the mesh edge (a
/// bridge facet in the panel's plane). `face_panel` gives every bridge its own copies
/// of the two mesh corners, so two tabs on adjacent edges of one face have bridges
/// that share the mitre from the band corner to the mesh corner: unrolled, the outline
/// runs along that segment twice and the run stops with "panel F1 overlaps itself
/// when unrolled; try a smaller --tab-height" (no tab height helps).
#[test]

fn face_scale_below_one_with_tabs_builds_valid_sheets() {
    for (name, size) in [
        ("tetrahedron", "12in"),
        ("hexahedron", "12in"),
        ("genus2", "300mm"),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);
        let tmp = TempDir::new().unwrap();
        let out = tmp.path().join("out");
        let m = build(
            &path,
            size,
            &out,
            &["--face-scale", "0.8", "--holes", "1", "--format", "svg,dxf"],
        );
        assert_eq!(count(&m, "counts.panels"), obj_face_count(&path), "{name}");
        assert!(
            num(&m, "panel_area") > 0.64 * surface,
            "{name}: bridges and tabs add to the 0.8² face bands"
        );
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        assert_eq!(sheets.total().panels, count(&m, "counts.panels"));
        assert_eq!(sheets.total().holes, count(&m, "counts.holes"));
    }
}

// =======================================================================================
// 3. Holes of a connection meet in 3D
// =======================================================================================

/// Follows every flat hole back to 3D through its facet's frame and checks that the
/// holes of each connection pair up between the two faces of its edge.
/// `rel_tol`: how close (relative to the model size) partner holes must be on the
/// band's plane: 1e-9 for exact geometry.
fn check_holes(model: &Path, size: &str, size_mm: f64, holes: u32, rel_tol: f64) {
    let what = format!("{} at {size}, --holes {holes}", model.display());
    let tmp = TempDir::new().unwrap();
    let job = half_edge_job(model, size, holes, &tmp.path().join("out"));
    let (mesh, connections, panels, flat) = panels_of(&job);
    let tol = rel_tol * size_mm;
    let r = 0.5 * job.scheme_options.hole_diameter;

    // How far a facet's 3D corners are from the plane of its frame: 0 (rounding) for
    // planar faces; faces planar only within --planarity-tol are kept as one facet,
    // and a point mapped back through the frame lands on the frame's plane.
    let flatness = |k: usize, facet: u32| -> f64 {
        let frame = flat[k].frames[facet as usize];
        let normal = frame.x3.cross(frame.y3);
        panels[k].facets[facet as usize]
            .iter()
            .map(|&i| {
                (panels[k].vertices[i as usize] - frame.origin3)
                    .dot(normal)
                    .abs()
            })
            .fold(0.0, f64::max)
    };
    let mut worst_apart = 0.0f64;

    // connection → [(panel index, facet, 3D point)]
    let mut by_connection: BTreeMap<u32, Vec<(usize, u32, DVec3)>> = BTreeMap::new();
    let mut total = 0;
    for (k, fp) in flat.iter().enumerate() {
        assert_eq!(fp.holes.len(), panels[k].holes.len(), "{what}: {}", fp.id);
        for hole in &fp.holes {
            total += 1;
            let facet: Vec<DVec2> = fp.facets[hole.facet as usize]
                .iter()
                .map(|&i| fp.points[i as usize])
                .collect();
            assert!(
                inside(&facet, hole.center),
                "{what}: {} hole of connection {} at {} is outside its facet {}",
                fp.id,
                hole.connection,
                hole.center,
                hole.facet
            );
            let clear = distance_to_border(&facet, hole.center);
            assert!(
                clear >= r - 1e-9,
                "{what}: {} hole of connection {} is {clear} mm from its facet's edge, radius {r}",
                fp.id,
                hole.connection
            );
            let p = fp.frames[hole.facet as usize].to_3d(hole.center);
            by_connection
                .entry(hole.connection)
                .or_default()
                .push((k, hole.facet, p));
        }
    }
    assert!(!by_connection.is_empty(), "{what}: no connection has holes");
    assert!(
        by_connection.len() <= connections,
        "{what}: more connections with holes than connections"
    );

    let per = holes as usize;
    for (&c, list) in &by_connection {
        assert_eq!(
            list.len(),
            2 * per,
            "{what}: connection {c} has {} holes, want {}",
            list.len(),
            2 * per
        );
        let owners: BTreeSet<usize> = list.iter().map(|h| h.0).collect();
        assert_eq!(
            owners.len(),
            2,
            "{what}: connection {c} holes on panels {owners:?}"
        );
        // The two panels are the two faces of edge c.
        let e = EdgeId(c);
        let faces: BTreeSet<u32> = [e.half_edge(), e.half_edge().twin()]
            .iter()
            .map(|&h| mesh.face(h).expect("a connection joins two faces").0)
            .collect();
        let sources: BTreeSet<u32> = owners
            .iter()
            .map(|&k| match flat[k].source {
                Source::Face(f) => f,
                other => panic!("{what}: half-edge panel from {other:?}"),
            })
            .collect();
        assert_eq!(
            sources, faces,
            "{what}: connection {c} joins the faces of edge {c}"
        );
        let [a, b]: [usize; 2] = owners
            .iter()
            .copied()
            .collect::<Vec<_>>()
            .try_into()
            .unwrap();
        let on_a: Vec<&(usize, u32, DVec3)> = list.iter().filter(|h| h.0 == a).collect();
        let on_b: Vec<&(usize, u32, DVec3)> = list.iter().filter(|h| h.0 == b).collect();
        assert_eq!(
            (on_a.len(), on_b.len()),
            (per, per),
            "{what}: connection {c}"
        );
        // One panel carries the tab (a facet other than its face band 0), the other
        // takes the holes through its face band.
        let band_a = on_a.iter().all(|h| h.1 == 0);
        let band_b = on_b.iter().all(|h| h.1 == 0);
        let tab_a = on_a.iter().all(|h| h.1 != 0);
        let tab_b = on_b.iter().all(|h| h.1 != 0);
        assert!(
            (band_a && tab_b) || (tab_a && band_b),
            "{what}: connection {c}: holes on facets {:?} and {:?}",
            on_a.iter().map(|h| h.1).collect::<Vec<_>>(),
            on_b.iter().map(|h| h.1).collect::<Vec<_>>()
        );
        // Pair every hole through the face band with one tab hole. Mapped back through
        // their facets they are the same 3D point, exactly when the face is planar; a
        // face planar only within --planarity-tol stays one facet, and the band's frame
        // puts the point on the facet's plane: compare on that plane, and check the
        // plain distance against the facet's flatness.
        let (tab_side, band_side, band_panel) = if band_a {
            (&on_b, &on_a, a)
        } else {
            (&on_a, &on_b, b)
        };
        let frame = flat[band_panel].frames[0];
        let normal = frame.x3.cross(frame.y3);
        let slack = 2.0 * flatness(band_panel, 0);
        let mut matched = BTreeSet::new();
        for hb in band_side.iter() {
            let (nearest, j) = tab_side
                .iter()
                .enumerate()
                .map(|(j, ht)| {
                    let q = ht.2 - (ht.2 - frame.origin3).dot(normal) * normal;
                    (q.distance(hb.2), j)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap();
            assert!(
                nearest <= tol,
                "{what}: connection {c}: hole of {} at {} has no partner hole on the tab (nearest {nearest} mm)",
                flat[band_panel].id,
                hb.2
            );
            assert!(
                matched.insert(j),
                "{what}: connection {c}: two holes share one partner"
            );
            let apart = tab_side[j].2.distance(hb.2);
            worst_apart = worst_apart.max(apart);
            assert!(
                apart <= tol + slack,
                "{what}: connection {c}: partner holes {apart} mm apart in 3D (facet flat within {slack} mm)"
            );
        }
        if per == 2 {
            let gap = on_a[0].2.distance(on_a[1].2);
            assert!(
                gap > 2.0 * r,
                "{what}: connection {c}: two holes {gap} mm apart"
            );
        }
    }

    // The manifest reports the same holes and connections.
    let outcome = unfold::run(&job).expect("the job runs");
    assert_eq!(outcome.manifest.counts.holes, total, "{what}: counts.holes");
    assert_eq!(
        outcome.manifest.counts.connections, connections,
        "{what}: counts.connections"
    );
    eprintln!(
        "{what}: {} of {connections} connections have holes, {total} holes; partner holes at most {worst_apart:.1e} mm apart",
        by_connection.len()
    );
}

#[test]
fn holes_of_a_connection_meet_in_3d() {
    for (name, size, size_mm) in [
        ("hexahedron", "12in", 304.8),
        ("dodecahedron", "12in", 304.8),
        ("torus-8x6", "12in", 304.8),
        ("genus2", "300mm", 300.0),
    ] {
        check_holes(&model(name), size, size_mm, 2, 1e-9);
    }
    check_holes(&model("genus2"), "300mm", 300.0, 1, 1e-9);
    if let Some(shared) = shared_models("holes_of_a_connection_meet_in_3d") {
        // Fertility keeps quads that are planar only within --planarity-tol, and the
        // unroller's frames of such facets are not orthonormal (see the ignored test
        // below): partner holes miss by ~2e-6 mm. Check them at 1e-6 of the size here.
        check_holes(&shared.join("fertility.obj"), "4ft", 1219.2, 2, 1e-6);
    }
}

/// The frames of facets that are planar only within the tolerance: `flatten` takes the
/// first facet edge (or the hinge) as the x axis without projecting it onto the plane
/// normal to the facet's normal, so x3 is not in that plane and y3 = normal × x3 is
/// shorter than 1; `to_3d(to_2d(p))` is then not the projection of p onto the facet's
/// plane, and holes mapped back through the two panels' frames miss each other.
#[test]

fn holes_of_a_connection_meet_in_3d_on_near_planar_faces() {
    let Some(shared) = shared_models("holes_of_a_connection_meet_in_3d_on_near_planar_faces")
    else {
        return;
    };
    let fertility = shared.join("fertility.obj");
    let tmp = TempDir::new().unwrap();
    let job = half_edge_job(&fertility, "4ft", 2, &tmp.path().join("out"));
    let (_mesh, _connections, _panels, flat) = panels_of(&job);
    for fp in &flat {
        for (k, f) in fp.frames.iter().enumerate() {
            assert!(
                (f.x3.length() - 1.0).abs() < 1e-12
                    && (f.y3.length() - 1.0).abs() < 1e-12
                    && f.x3.dot(f.y3).abs() < 1e-12,
                "{} facet {k}: frame axes |x3| = {}, |y3| = {}, x3·y3 = {:e}",
                fp.id,
                f.x3.length(),
                f.y3.length(),
                f.x3.dot(f.y3)
            );
        }
    }
    check_holes(&fertility, "4ft", 1219.2, 2, 1e-9);
}

// =======================================================================================
// 4. Determinism
// =======================================================================================

#[test]
fn output_is_byte_identical_across_runs_and_threads() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let runs: [(&str, Option<&str>); 4] = [
        ("default-a", None),
        ("default-b", None),
        ("threads-1", Some("1")),
        ("threads-2", Some("2")),
    ];
    let mut outputs = Vec::new();
    for (label, threads) in runs {
        let out = tmp.path().join(label);
        let mut cmd = unfold_command();
        cmd.arg(&path)
            .args(["--scheme", "half-edge", "--size", "300mm", "--holes", "1"])
            .args(["--format", "svg,dxf", "--out"])
            .arg(&out);
        cmd.env_remove("RAYON_NUM_THREADS");
        if let Some(n) = threads {
            cmd.env("RAYON_NUM_THREADS", n);
        }
        let run = finish(&mut cmd);
        assert_eq!(run.code, Some(0), "{label}: {}", run.stderr);
        outputs.push((label, folder_files(&out)));
    }
    let (first_label, first) = &outputs[0];
    assert!(first.keys().any(|n| n.ends_with(".dxf")) && first.keys().any(|n| n.ends_with(".svg")));
    for (label, files) in &outputs[1..] {
        assert_eq!(
            files.keys().collect::<Vec<_>>(),
            first.keys().collect::<Vec<_>>(),
            "{label} and {first_label} wrote different files"
        );
        for (name, bytes) in files {
            assert!(
                bytes == &first[name],
                "{name} differs between {first_label} and {label}"
            );
        }
    }
}

// =======================================================================================
// 5. Golden files
// =======================================================================================

/// The first line where two texts differ, for the failure message.
fn first_difference(want: &[u8], got: &[u8]) -> String {
    let (want, got) = (String::from_utf8_lossy(want), String::from_utf8_lossy(got));
    for (k, (a, b)) in want.lines().zip(got.lines()).enumerate() {
        if a != b {
            return format!("line {}:\n  golden: {a}\n  now:    {b}", k + 1);
        }
    }
    format!(
        "one is a prefix of the other ({} and {} lines)",
        want.lines().count(),
        got.lines().count()
    )
}

#[test]
fn golden_files_of_a_small_model() {
    let golden = crate_dir().join("tests/golden/tetrahedron-half-edge");
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("tetrahedron");
    // A model path relative to the crate root: the manifest's input.path is the same
    // on every machine.
    let run = finish(
        unfold_command()
            .current_dir(crate_dir())
            .arg("models/tetrahedron.obj")
            .args(["--size", "150mm", "--scheme", "half-edge", "--holes", "1"])
            .args(["--format", "svg,dxf", "--out"])
            .arg(&out),
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let now = folder_files(&out);
    let manifest = read_manifest(&out);
    assert_eq!(manifest["input"]["path"], "models/tetrahedron.obj");
    for (name, bytes) in &now {
        let text = String::from_utf8_lossy(bytes);
        assert!(
            !text.contains(&*tmp.path().to_string_lossy()),
            "{name} names the temporary folder"
        );
    }

    if std::env::var("UNFOLD_UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
        if golden.exists() {
            std::fs::remove_dir_all(&golden).unwrap();
        }
        std::fs::create_dir_all(&golden).unwrap();
        for (name, bytes) in &now {
            std::fs::write(golden.join(name), bytes).unwrap();
        }
        eprintln!("UNFOLD_UPDATE_GOLDEN=1: rewrote {}", golden.display());
        return;
    }
    assert!(
        golden.is_dir(),
        "{} is missing; create it with UNFOLD_UPDATE_GOLDEN=1 cargo test --test build_half_edge golden",
        golden.display()
    );
    let want = folder_files(&golden);
    assert_eq!(
        now.keys().collect::<Vec<_>>(),
        want.keys().collect::<Vec<_>>(),
        "the output files differ from the golden ones"
    );
    for (name, bytes) in &want {
        assert!(
            &now[name] == bytes,
            "{name} differs from {}; if the change is intended, rerun with UNFOLD_UPDATE_GOLDEN=1\nfirst difference at {}",
            golden.join(name).display(),
            first_difference(bytes, &now[name])
        );
    }
    // The golden sheets themselves pass the independent check.
    let sheets = check_sheets(&out, &manifest, DxfCheck::All);
    assert_eq!(sheets.total().panels, 4);
    assert_eq!(sheets.total().holes, count(&manifest, "counts.holes"));
}

// =======================================================================================
// 6. Non-planar faces
// =======================================================================================

#[test]
fn non_planar_faces_are_triangulated_or_refused() {
    let Some(shared) = shared_models("non_planar_faces_are_triangulated_or_refused") else {
        return;
    };
    let suzanne = shared.join("suzanne.obj");
    let tmp = TempDir::new().unwrap();

    let out = tmp.path().join("suzanne");
    let m = build(&suzanne, "4ft", &out, &["--format", "svg"]);
    let non_planar = count(&m, "input.faces_split.non_planar");
    assert!(non_planar > 0, "suzanne has non-planar quads");
    let own = obj_face_count(&suzanne);
    // Every split quad becomes two triangles (or a fan of four).
    assert!(
        count(&m, "input.faces") >= own + non_planar,
        "{} faces after splitting {non_planar} of {own}",
        count(&m, "input.faces")
    );
    assert_eq!(count(&m, "counts.panels"), count(&m, "input.faces"));
    let sheets = check_sheets(&out, &m, DxfCheck::All);
    assert_eq!(sheets.svg_files.len(), count(&m, "counts.sheets"));
    assert_eq!(sheets.total().panels, count(&m, "counts.panels"));

    let refused = tmp.path().join("refused");
    let run = unfold([
        suzanne.as_os_str(),
        OsStr::new("--scheme"),
        OsStr::new("half-edge"),
        OsStr::new("--size"),
        OsStr::new("4ft"),
        OsStr::new("--nonplanar"),
        OsStr::new("error"),
        OsStr::new("--out"),
        refused.as_os_str(),
    ]);
    assert_eq!(run.code, Some(3), "--nonplanar error: {}", run.stderr);
    let lines: Vec<&str> = run.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line of error: {:?}", run.stderr);
    let line = lines[0];
    assert!(line.starts_with("unfold: error: "), "{line}");
    let at = line
        .find("suzanne.obj:")
        .unwrap_or_else(|| panic!("the error names suzanne.obj: {line}"));
    let rest = &line[at + "suzanne.obj:".len()..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    assert!(
        !digits.is_empty() && rest[digits.len()..].starts_with(':'),
        "the error gives a :LINE: location: {line}"
    );
    // The line named is a face of the file.
    let number: usize = digits.parse().unwrap();
    let text = std::fs::read_to_string(&suzanne).unwrap();
    let named = text.lines().nth(number - 1).unwrap_or("");
    assert!(
        named.starts_with("f "),
        "line {number} of suzanne.obj is not a face: {named:?}"
    );
    assert!(!refused.exists(), "a refused model leaves no output folder");
    assert!(
        !tmp.path().join(".refused.unfold-new").exists(),
        "no staging folder is left"
    );
}

// =======================================================================================
// 7. Atomic output folder
// =======================================================================================

#[test]
fn output_folder_is_replaced_atomically() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("hexa");
    let path = model("hexahedron");
    build(&path, "12in", &out, &["--format", "svg,dxf"]);
    let before = folder_files(&out);
    assert!(before.len() > 2);

    let fail = |dir: &Path| {
        unfold([
            path.as_os_str(),
            OsStr::new("--scheme"),
            OsStr::new("half-edge"),
            OsStr::new("--size"),
            OsStr::new("12in"),
            OsStr::new("--sheet"),
            OsStr::new("60x60mm"),
            OsStr::new("--out"),
            dir.as_os_str(),
        ])
    };
    let run = fail(&out);
    assert_eq!(
        run.code,
        Some(1),
        "a panel larger than the sheet: {}",
        run.stderr
    );
    let lines: Vec<&str> = run.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line of error: {:?}", run.stderr);
    let line = lines[0];
    assert!(line.starts_with("unfold: error: "), "{line}");
    // "panel F<k> is W x H mm": a face panel, at least the 304.8 mm face.
    let at = line
        .find("panel F")
        .unwrap_or_else(|| panic!("names the panel: {line}"));
    let rest = &line[at + "panel F".len()..];
    let face: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    assert!(face.parse::<usize>().is_ok_and(|f| f < 6), "{line}");
    let size: Vec<f64> = rest[face.len()..]
        .trim_start_matches(" is ")
        .split(" mm")
        .next()
        .unwrap()
        .split(" x ")
        .map(|w| w.trim().parse().unwrap_or(f64::NAN))
        .collect();
    assert_eq!(size.len(), 2, "gives the panel's size in mm: {line}");
    for side in &size {
        assert!(
            (304.8 - 0.1..=304.8 + 2.0 * 8.0 + 0.1).contains(side),
            "a 304.8 mm face with 8 mm tabs measures {side} mm? {line}"
        );
    }

    assert_eq!(
        folder_files(&out),
        before,
        "the failed job changed the output folder"
    );
    let siblings = entry_names(tmp.path());
    assert_eq!(
        siblings,
        BTreeSet::from(["hexa".to_string()]),
        "left next to OUT"
    );

    let fresh = tmp.path().join("fresh");
    let run = fail(&fresh);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(
        !fresh.exists(),
        "a failed job into a new folder leaves no folder"
    );
    assert_eq!(
        entry_names(tmp.path()),
        BTreeSet::from(["hexa".to_string()])
    );
}

// =======================================================================================
// 8. --json and --quiet
// =======================================================================================

#[test]
fn json_summary_on_stdout() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let args = |out: &Path, extra: &[&str]| {
        let mut cmd = unfold_command();
        cmd.arg(&path)
            .args(["--scheme", "half-edge", "--size", "300mm", "--out"])
            .arg(out)
            .args(extra);
        finish(&mut cmd)
    };

    let plain = args(&tmp.path().join("plain"), &[]);
    assert_eq!(plain.code, Some(0), "{}", plain.stderr);
    assert!(
        plain.stdout.is_empty(),
        "without --json stdout is empty: {}",
        plain.stdout
    );
    assert!(
        plain.stderr.contains("panels"),
        "the report goes to stderr: {}",
        plain.stderr
    );

    let out = tmp.path().join("json");
    let run = args(&out, &["--json"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.is_empty(), "the report still goes to stderr");
    let summary: Value = serde_json::from_str(&run.stdout)
        .unwrap_or_else(|e| panic!("--json prints JSON ({e}):\n{}", run.stdout));
    assert!(count(&summary, "counts.panels") == 50);
    assert!(count(&summary, "counts.sheets") >= 1);
    assert!(count(&summary, "counts.sheets_lower_bound") >= 1);
    let u = num(&summary, "utilization");
    assert!(u > 0.0 && u <= 1.0, "utilization {u}");
    let times = summary["times"].as_object().expect("a times object");
    assert!(!times.is_empty());
    for (stage, t) in times {
        assert!(t.as_f64().is_some_and(|t| t >= 0.0), "time {stage} = {t}");
    }
    assert!(
        summary.get("panels").is_none(),
        "no per-panel list in the summary"
    );
    // The summary is the manifest without its panel list, plus the times.
    let mut manifest = read_manifest(&out);
    manifest.as_object_mut().unwrap().remove("panels");
    let mut without_times = summary.clone();
    without_times.as_object_mut().unwrap().remove("times");
    assert_eq!(
        without_times, manifest,
        "--json summary = manifest.json − panels"
    );

    let quiet = args(&tmp.path().join("quiet"), &["--json", "--quiet"]);
    assert_eq!(quiet.code, Some(0));
    assert_eq!(quiet.stderr, "", "--quiet prints nothing on stderr");
    let again: Value =
        serde_json::from_str(&quiet.stdout).expect("--quiet --json still prints JSON");
    assert_eq!(again["counts"], summary["counts"]);

    let silent = args(&tmp.path().join("silent"), &["--quiet"]);
    assert_eq!(silent.code, Some(0));
    assert_eq!((silent.stdout.as_str(), silent.stderr.as_str()), ("", ""));
}

// =======================================================================================
// 9. Labels
// =======================================================================================

#[test]
fn labels_are_inside_their_panels() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let out = tmp.path().join("out");
    let m = build(&path, "300mm", &out, &["--format", "svg"]);
    assert_eq!(
        count(&m, "counts.labels_left_out"),
        0,
        "genus2 at 300 mm has room for every label"
    );
    assert!(num(&m, "lengths.engrave") > 0.0);
    let sheets = check_sheets(&out, &m, DxfCheck::All);
    for (file, stats) in sheets.svg_files.iter().zip(&sheets.stats) {
        assert!(stats.engrave_paths > 0, "{file}: empty ENGRAVE group");
    }

    // Library level: every panel carries its own id and, with tabs, the partner's id at
    // each connection: 50 panel ids + 2 × 100 partner ids, none left out.
    let job = half_edge_job(&path, "300mm", 0, &out);
    let (mesh, connections, _panels, mut flat) = panels_of(&job);
    assert_eq!(connections, 100);
    let mut left_out = 0;
    for fp in &mut flat {
        left_out += unfold::labels::fit_labels(fp, Default::default());
    }
    assert_eq!(left_out, 0);
    let mut partner_labels = 0;
    for fp in &flat {
        let own: Vec<&str> = fp
            .labels
            .iter()
            .filter(|l| l.kind == LabelKind::Panel)
            .map(|l| l.text.as_str())
            .collect();
        assert_eq!(own, [fp.id.as_str()], "{}: its own id once", fp.id);
        let Source::Face(f) = fp.source else {
            panic!("{}: not a face panel", fp.id)
        };
        // Partner labels name the neighbours across the face's edges.
        let neighbours: BTreeSet<String> = mesh
            .face_half_edges(unfold::mesh::FaceId(f))
            .filter_map(|h| mesh.face(h.twin()))
            .map(|g| format!("F{}", g.0))
            .collect();
        for l in fp.labels.iter().filter(|l| l.kind == LabelKind::Partner) {
            assert!(
                neighbours.contains(&l.text),
                "{}: partner label {} is not a neighbour",
                fp.id,
                l.text
            );
            partner_labels += 1;
        }
        // Every label's centre is inside the outline.
        for l in &fp.labels {
            assert!(
                inside(&fp.outer(), l.center),
                "{}: label {} outside",
                fp.id,
                l.text
            );
        }
    }
    assert_eq!(partner_labels, 2 * connections);
    assert_eq!(flat.len(), 50);
}
