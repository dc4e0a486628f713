//! Helpers for the end-to-end build tests of every scheme (`tests/build_*.rs`): running
//! the binary, reading its manifest, checking every sheet of an output folder with the
//! independent checker of this module's parent, running the library's pipeline up to the
//! flat panels the way `src/run/` does, golden-file comparison, and a little plane
//! geometry written here rather than taken from the crate under test.

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{DVec2, DVec3};
use serde_json::Value;

use super::{
    check_dxf_matches_svg, check_dxf_matches_svg_read_by, check_svg_sheet, DxfReader, SheetSpec,
    SheetStats,
};
use unfold::config::{BuildOptions, Job, ModelOptions};
use unfold::flatten::{facet_frames, flatten};
use unfold::mesh::split::SplitReport;
use unfold::mesh::Mesh;
use unfold::panel::{FacetFrame, FlatPanel, Panel};
use unfold::scheme::SchemeOutput;

// =======================================================================================
// Paths
// =======================================================================================

pub fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A model of the project's own `models/` folder.
pub fn model(name: &str) -> PathBuf {
    crate_dir().join("models").join(format!("{name}.obj"))
}

/// The shared models folder, or `None` (with a message) when this checkout has none.
pub fn shared_models(test: &str) -> Option<PathBuf> {
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

/// The model files in the shared models' folder (OBJ and OFF), in name order.
pub fn shared_model_files(shared: &Path) -> Vec<PathBuf> {
    let mut models: Vec<PathBuf> = std::fs::read_dir(shared)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj" || x == "off"))
        .collect();
    models.sort();
    models
}

/// The shared model files in name order, the first half or the second (`None`, with a
/// message, when this checkout has no shared models): a test over every shared model
/// split in two, so that the halves run on two cores.
pub fn half_of_the_shared_models(test: &str, second: bool) -> Option<Vec<PathBuf>> {
    let models = shared_model_files(&shared_models(test)?);
    let half = models.len().div_ceil(2);
    Some(if second {
        models[half..].to_vec()
    } else {
        models[..half].to_vec()
    })
}

// =======================================================================================
// Running the binary
// =======================================================================================

/// What one run of the binary did.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

pub fn unfold_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
}

pub fn finish(cmd: &mut Command) -> Run {
    let output = cmd.output().expect("the unfold binary runs");
    Run {
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// A clean refusal with exit code `code`: nothing on stdout, no panic, stderr starting
/// `unfold: error: ` and holding every fragment of `says`.
pub fn assert_refusal(case: &str, run: &Run, code: i32, says: &[&str]) {
    assert_eq!(
        run.code,
        Some(code),
        "{case}: exit code; stderr: {}",
        run.stderr
    );
    assert!(run.stdout.is_empty(), "{case}: stdout: {}", run.stdout);
    assert!(!run.stderr.contains("panicked"), "{case}: {}", run.stderr);
    assert!(
        run.stderr.starts_with("unfold: error: "),
        "{case}: stderr: {}",
        run.stderr
    );
    for fragment in says {
        assert!(
            run.stderr.contains(fragment),
            "{case}: no {fragment:?} in:\n{}",
            run.stderr
        );
    }
}

pub fn unfold<I, S>(args: I) -> Run
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    finish(unfold_command().args(args))
}

/// Runs `unfold MODEL --scheme SCHEME --size SIZE --out OUT EXTRA… --build-anyway` (with
/// `--effort 1` unless EXTRA names an effort or a nester), asserts success and returns
/// the parsed `manifest.json` with the run (for its report on stderr).
pub fn build_run(
    scheme: &str,
    model: &Path,
    size: &str,
    out: &Path,
    extra: &[&str],
) -> (Value, Run) {
    let mut args: Vec<&OsStr> = vec![
        model.as_os_str(),
        OsStr::new("--scheme"),
        OsStr::new(scheme),
        OsStr::new("--size"),
        OsStr::new(size),
        OsStr::new("--out"),
        out.as_os_str(),
    ];
    args.extend(extra.iter().map(OsStr::new));
    // Models more detailed than their size are built on purpose (size_checks.rs tests
    // the stop).
    args.push(OsStr::new("--build-anyway"));
    // The true-shape search at its quickest: these builds check the sheets, not how
    // tight they are (the nesting tests and the benchmarks judge that at the default).
    if !extra.iter().any(|a| *a == "--effort" || *a == "--nester") {
        args.extend([OsStr::new("--effort"), OsStr::new("1")]);
    }
    let run = unfold(&args);
    assert_eq!(run.code, Some(0), "unfold {args:?} failed:\n{}", run.stderr);
    (read_manifest(out), run)
}

/// Asserts that `unfold MODEL ARGS --out …` writes the same bytes on one thread and on
/// two.
pub fn assert_same_bytes_on_one_and_two_threads(model: &Path, args: &[&str]) {
    let tmp = tempfile::TempDir::new().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out = tmp.path().join(threads);
        let run = finish(
            unfold_command()
                .env("RAYON_NUM_THREADS", threads)
                .arg(model)
                .args(args)
                .arg("--build-anyway")
                .arg("--out")
                .arg(&out),
        );
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        outputs.push(folder_files(&out));
    }
    assert!(
        outputs[0] == outputs[1],
        "{model:?} {args:?}: output differs between 1 and 2 threads"
    );
}

/// [`build_run`] without the run.
pub fn build(scheme: &str, model: &Path, size: &str, out: &Path, extra: &[&str]) -> Value {
    build_run(scheme, model, size, out, extra).0
}

/// The files a manifest lists (`files`: every file the run wrote).
pub fn listed_files(manifest: &Value) -> Vec<&str> {
    manifest["files"]
        .as_array()
        .expect("the manifest lists its files")
        .iter()
        .map(|f| f.as_str().expect("a file name"))
        .collect()
}

pub fn read_manifest(out: &Path) -> Value {
    let text = std::fs::read_to_string(out.join("manifest.json"))
        .unwrap_or_else(|e| panic!("{}/manifest.json: {e}", out.display()));
    serde_json::from_str(&text).expect("manifest.json is JSON")
}

/// `unfold inspect MODEL --json EXTRA…`, parsed.
pub fn inspect_json(path: &Path, extra: &[&str]) -> Value {
    let inspect = finish(
        unfold_command()
            .arg("inspect")
            .arg(path)
            .arg("--json")
            .args(extra),
    );
    assert_eq!(
        inspect.code,
        Some(0),
        "inspect {}: {}",
        path.display(),
        inspect.stderr
    );
    serde_json::from_str(&inspect.stdout).expect("inspect --json")
}

// =======================================================================================
// JSON and files
// =======================================================================================

/// The value at a dotted path, as a number (panics naming the key otherwise).
pub fn num(v: &Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_f64()
        .unwrap_or_else(|| panic!("{path} is not a number: {cur}"))
}

pub fn count(v: &Value, path: &str) -> usize {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_u64()
        .unwrap_or_else(|| panic!("{path} is not a count: {cur}")) as usize
}

/// Every file of a folder (no subfolders expected) with its bytes, by name.
pub fn folder_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
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
pub fn entry_names(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Faces of an OBJ file as written (`f` statements), counted without the tool.
pub fn obj_face_count(path: &Path) -> usize {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| l.trim_start().starts_with("f "))
        .count()
}

/// Positions and faces (0-based) of a simple OBJ file (`v x y z`, `f a b c…` with
/// optional `/…` suffixes and positive indices), read without the tool.
pub fn read_simple_obj(path: &Path) -> (Vec<DVec3>, Vec<Vec<usize>>) {
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

// =======================================================================================
// Plane geometry, written here rather than taken from `unfold::plane`
// =======================================================================================

/// Even-odd point in polygon.
pub fn inside(poly: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// A 3D polygon's vector area: its length is the area, its direction the normal
/// (right-hand rule).
pub fn polygon_vector_area(points: &[DVec3]) -> DVec3 {
    let n = points.len();
    (0..n)
        .map(|k| points[k].cross(points[(k + 1) % n]))
        .sum::<DVec3>()
        * 0.5
}

pub fn distance_to_border(poly: &[DVec2], p: DVec2) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a))
        })
        .fold(f64::INFINITY, f64::min)
}

/// Distance from a point to a segment.
pub fn point_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    p.distance(a + t * (b - a))
}

/// Distance between two segments (0 when they cross).
pub fn segment_distance(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return 0.0;
    }
    point_segment(a, c, d)
        .min(point_segment(b, c, d))
        .min(point_segment(c, a, b))
        .min(point_segment(d, a, b))
}

/// The number written after `key` in `text` (`--target-edges 430` → 430), if any.
pub fn number_after(text: &str, key: &str) -> Option<usize> {
    let at = text.find(key)? + key.len();
    text[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect::<String>()
        .parse()
        .ok()
}

/// The manifest's count of connections without a fastener hole.
pub fn connections_without_holes(manifest: &Value) -> usize {
    manifest["counts"]["connections_by_holes"]["0"]
        .as_u64()
        .unwrap_or(0) as usize
}

// =======================================================================================
// Checking the sheets of an output folder
// =======================================================================================

pub fn sheet_spec(manifest: &Value) -> SheetSpec {
    SheetSpec {
        width: num(manifest, "sheet.width"),
        height: num(manifest, "sheet.height"),
        margin: num(manifest, "sheet.margin"),
        spacing: num(manifest, "sheet.spacing"),
    }
}

/// Which DXF files of a folder to read back and compare with their SVG (the Rust reader,
/// and ezdxf when python3 has it: about a second a sheet).
#[derive(Clone, Copy, PartialEq)]
pub enum DxfCheck {
    /// Every one.
    All,
    /// The first and the last sheet (every one with `UNFOLD_FULL_DXF=1`).
    FirstAndLast,
    /// None (every one with `UNFOLD_FULL_DXF=1`): for builds whose DXF writer input
    /// another build of the same test already reads.
    Skip,
}

/// The sheets of an output folder after the independent check.
pub struct Sheets {
    /// SVG file names, in order.
    pub svg_files: Vec<String>,
    /// Stats of every SVG sheet, in the same order.
    pub stats: Vec<SheetStats>,
}

impl Sheets {
    pub fn total(&self) -> SheetStats {
        let mut t = SheetStats::default();
        for s in &self.stats {
            t.panels += s.panels;
            t.holes += s.holes;
            t.cut_paths += s.cut_paths;
            t.score_paths += s.score_paths;
            t.valley_paths += s.valley_paths;
            t.engrave_paths += s.engrave_paths;
            t.panel_area += s.panel_area;
            t.cut_length += s.cut_length;
            t.score_length += s.score_length;
            t.valley_length += s.valley_length;
            t.engrave_length += s.engrave_length;
        }
        t
    }
}

/// Larger DXF files are read by the Rust reader only (unless `UNFOLD_FULL_DXF=1`).
const EZDXF_MAX_BYTES: u64 = 1 << 20;

/// The model's name the files of a build start with: that of its assembled model.
pub fn model_stem<S: AsRef<str>>(files: &[S]) -> String {
    files
        .iter()
        .find_map(|n| n.as_ref().strip_suffix("-assembled.obj"))
        .expect("an assembled model among the files")
        .to_string()
}

/// The page number of a page of the assembly map of the model `stem`
/// (`STEM-map.svg` is 1, `STEM-map-2.svg` 2…), or `None` for any other file.
pub fn map_page_number(stem: &str, name: &str) -> Option<usize> {
    let rest = name.strip_prefix(stem)?.strip_suffix(".svg")?;
    if rest == "-map" {
        return Some(1);
    }
    let k = rest.strip_prefix("-map-")?;
    let digits = !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit());
    digits.then(|| k.parse().ok()).flatten().filter(|&k| k >= 2)
}

/// Checks every SVG of `out` with `check_svg_sheet` (sheet spec from the manifest) and
/// the DXF files chosen by `dxf` against their SVG: each with the Rust reader, and with
/// ezdxf as well those up to [`EZDXF_MAX_BYTES`] (at least the smallest one).
pub fn check_sheets(out: &Path, manifest: &Value, dxf: DxfCheck) -> Sheets {
    let spec = sheet_spec(manifest);
    let names = entry_names(out);
    // The sheets are the SVG and DXF files of the folder but the assembly map (a
    // picture for people, checked in tests/map.rs).
    let stem = model_stem(&names.iter().collect::<Vec<_>>());
    let is_map = |n: &String| map_page_number(&stem, n).is_some();
    let svg_files: Vec<String> = names
        .iter()
        .filter(|n| n.ends_with(".svg") && !is_map(n))
        .cloned()
        .collect();
    let dxf_files: Vec<String> = names
        .iter()
        .filter(|n| n.ends_with(".dxf"))
        .cloned()
        .collect();
    let listed: BTreeSet<String> = manifest["sheets"]
        .as_array()
        .map(|sheets| {
            sheets
                .iter()
                .flat_map(|s| s["files"].as_array().cloned().unwrap_or_default())
                .filter_map(|f| f.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    for name in svg_files.iter().chain(&dxf_files) {
        assert!(
            listed.contains(name),
            "{name}: a sheet file the manifest's sheets do not list"
        );
    }
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
    let chosen: Vec<&String> = if dxf == DxfCheck::All || full {
        dxf_files.iter().collect()
    } else if dxf == DxfCheck::Skip {
        Vec::new()
    } else if dxf_files.len() <= 2 {
        dxf_files.iter().collect()
    } else {
        vec![&dxf_files[0], &dxf_files[dxf_files.len() - 1]]
    };
    // ezdxf, the independent reader, takes about 0.7 s per MB.
    let bytes = |name: &String| std::fs::metadata(out.join(name)).map_or(0, |m| m.len());
    let mut by_ezdxf: BTreeSet<&String> = chosen
        .iter()
        .copied()
        .filter(|n| full || bytes(n) <= EZDXF_MAX_BYTES)
        .collect();
    if by_ezdxf.is_empty() {
        by_ezdxf.extend(chosen.iter().copied().min_by_key(|n| (bytes(n), *n)));
    }
    let by_ezdxf = &by_ezdxf;
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
                            let path = out.join(name);
                            if by_ezdxf.contains(name) {
                                check_dxf_matches_svg(&path, &svg, spec.height).err()
                            } else {
                                let rust = DxfReader::Rust;
                                check_dxf_matches_svg_read_by(rust, &path, &svg, spec.height).err()
                            }
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

/// Checks the output folder of a run with `--format svg,dxf` against its manifest:
/// exactly one SVG and one DXF per sheet plus the manifest and the assembled model;
/// every sheet through the independent checker ([`check_sheets`]); the panels, holes,
/// panel area and cut/score/engrave lengths on the sheets equal the manifest's; the
/// manifest's sheet list names the files and their panel counts; its panel list has
/// one entry per panel with the id `panel_id(entry)` (unique), on the sheet that holds
/// it, areas adding up to `panel_area`; `sheets ≥ sheets_lower_bound = ceil(panel area /
/// usable sheet area)`, `utilization = panel_area / (sheets × sheet area)`.
pub fn check_output(
    model: &Path,
    out: &Path,
    m: &Value,
    what: &str,
    dxf: DxfCheck,
    panel_id: impl Fn(&Value) -> String,
) -> Sheets {
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    let panels = count(m, "counts.panels");
    let sheets = count(m, "counts.sheets");
    assert!(sheets >= 1, "{what}: no sheets");

    // The files: one SVG and one DXF per sheet, the manifest, the assembled model, the
    // assembly map and the preview page.
    let digits = sheets.to_string().len().max(2);
    let mut expected = BTreeSet::from([
        "manifest.json".to_string(),
        format!("{name}-assembled.obj"),
        format!("{name}-map.svg"),
        format!("{name}.html"),
    ]);
    // The map's close-up pages, numbered from 2 on.
    let map_pages = entry_names(out)
        .iter()
        .filter(|n| map_page_number(&name, n).is_some())
        .count();
    for k in 2..=map_pages {
        expected.insert(format!("{name}-map-{k}.svg"));
    }
    for k in 1..=sheets {
        expected.insert(format!("{name}-{k:0digits$}.svg"));
        expected.insert(format!("{name}-{k:0digits$}.dxf"));
    }
    assert_eq!(entry_names(out), expected, "{what}: output files");

    let checked = check_sheets(out, m, dxf);
    let total = checked.total();

    // Sheets against the manifest.
    assert_eq!(
        checked.svg_files.len(),
        sheets,
        "{what}: SVG files = counts.sheets"
    );
    assert_eq!(total.panels, panels, "{what}: panels on the sheets");
    assert_eq!(
        total.holes,
        count(m, "counts.holes"),
        "{what}: holes on the sheets"
    );
    let panel_area = num(m, "panel_area");
    assert!(
        close(total.panel_area, panel_area, 1e-4),
        "{what}: outlines on the sheets enclose {} mm², manifest panel_area {panel_area}",
        total.panel_area
    );
    for (kind, drawn) in [
        ("cut", total.cut_length),
        ("score", total.score_length - total.valley_length),
        ("score_valley", total.valley_length),
        ("engrave", total.engrave_length),
    ] {
        let said = num(m, &format!("lengths.{kind}"));
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
        let files: Vec<&str> = entry["files"]
            .as_array()
            .expect("a sheet's files")
            .iter()
            .filter_map(Value::as_str)
            .collect();
        let stem = file.trim_end_matches(".svg");
        let wanted: Vec<String> = ["svg", "dxf"]
            .iter()
            .map(|ext| format!("{stem}.{ext}"))
            .filter(|name| out.join(name).is_file())
            .collect();
        assert_eq!(files, wanted, "{what}: the files of sheet {}", k + 1);
        assert_eq!(
            count(entry, "panels"),
            stats.panels,
            "{what}: panels on {file}"
        );
    }

    // The per-panel list: one entry per panel, ids from their source, on the sheet that
    // holds it.
    let list = m["panels"].as_array().expect("manifest panels list");
    assert_eq!(list.len(), panels, "{what}: manifest panels list");
    let mut ids = BTreeSet::new();
    let mut per_sheet = vec![0usize; sheets];
    let mut area_sum = 0.0;
    for p in list {
        let id = p["id"].as_str().unwrap();
        assert_eq!(id, panel_id(p), "{what}: panel id names its source");
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
    let lower = count(m, "counts.sheets_lower_bound");
    assert!(
        sheets >= lower,
        "{what}: {sheets} sheets below the lower bound {lower}"
    );
    // The bound that counts the spacing: never below the area bound, never above
    // the sheets any layout uses.
    let spacing_bound = count(m, "counts.sheets_spacing_bound");
    assert!(
        lower <= spacing_bound && spacing_bound <= sheets,
        "{what}: area bound {lower}, spacing bound {spacing_bound}, {sheets} sheets"
    );
    let spec = sheet_spec(m);
    let usable = (spec.width - 2.0 * spec.margin) * (spec.height - 2.0 * spec.margin);
    let ratio = panel_area / usable;
    if (ratio - ratio.round()).abs() > 1e-6 {
        assert_eq!(lower, ratio.ceil() as usize, "{what}: sheets_lower_bound");
    }
    let utilization = num(m, "utilization");
    let wanted = panel_area / (sheets as f64 * spec.width * spec.height);
    assert!(
        (utilization - wanted).abs() <= 1e-4,
        "{what}: utilization {utilization}, panel_area / sheet area = {wanted}"
    );
    eprintln!(
        "{what}: {panels} panels on {sheets} sheets (lower bound {lower}, utilization {:.1}%), {} holes",
        100.0 * utilization,
        total.holes
    );
    checked
}

// =======================================================================================
// The library's pipeline up to the flat panels
// =======================================================================================

/// What [`pipeline`] produced.
pub struct Pipeline {
    /// The mesh the scheme used (scaled to mm, faces split).
    pub mesh: Mesh,
    /// The faces split before the scheme.
    pub split: SplitReport,
    /// The scheme's output (3D panels, connections, notes).
    pub output: SchemeOutput,
    /// The 3D panels as owned values, in the same order (the output keeps them in
    /// one arena; tests index and zip them).
    pub panels: Vec<Panel>,
    /// The panels unrolled, in the same order.
    pub flat: Vec<FlatPanel>,
}

/// The pipeline's stages (`unfold::run`) up to the scheme, then each panel flattened
/// on its own (the tests follow single panels back to 3D).
pub fn pipeline(job: &Job) -> Pipeline {
    let loaded = unfold::run::load(job).expect("model loads");
    let prepared = unfold::run::prepare(job, loaded).expect("scheme mesh");
    let output = unfold::run::scheme(job, &prepared).expect("scheme");
    each_flattened(prepared.scheme_mesh, output)
}

/// The scheme's mesh and output with each panel flattened on its own.
fn each_flattened(scheme_mesh: unfold::run::SchemeMesh, output: SchemeOutput) -> Pipeline {
    let unfold::run::SchemeMesh { mesh, split, .. } = scheme_mesh;
    let panels: Vec<Panel> = output.panels.iter().map(|p| p.to_panel()).collect();
    let flat = panels
        .iter()
        .map(|p| flatten(p).unwrap_or_else(|e| panic!("{}: {e}", p.id())))
        .collect();
    Pipeline {
        mesh,
        split,
        output,
        panels,
        flat,
    }
}

/// The whole job through the library's stages, once: its files written to the job's
/// output folder as the command line writes them (for the sheet checks), the manifest
/// read back, and the scheme's results as [`pipeline`] gives them (for the facts the
/// files do not hold). A test that needs both builds a large model once instead of
/// twice. The command line's checks before the build (size, detail) are not run, as
/// with `--build-anyway`, and the manifest lists no warnings.
pub fn built_once(job: &Job) -> (Pipeline, Value) {
    let loaded = unfold::run::load(job).expect("model loads");
    let prepared = unfold::run::prepare(job, loaded).expect("scheme mesh");
    let output = unfold::run::scheme(job, &prepared).expect("scheme");
    let flat = unfold::run::flatten(job, &prepared, &output).expect("flattens");
    let nested = unfold::run::nest(job, &flat, &|_| {}).expect("nests");
    let exported =
        unfold::run::export(job, &prepared, &output, &flat, &nested, Vec::new(), &|_| {})
            .expect("exports");
    std::fs::create_dir_all(&job.out).unwrap();
    for (name, bytes) in &exported.files {
        std::fs::write(job.out.join(name), bytes).unwrap();
    }
    (
        each_flattened(prepared.scheme_mesh, output),
        read_manifest(&job.out),
    )
}

/// The facet frames of each panel's unrolling (the flat panels' maps back to 3D).
pub fn frames_of(panels: &[Panel]) -> Vec<Vec<FacetFrame>> {
    panels
        .iter()
        .map(|p| facet_frames(p).unwrap_or_else(|e| panic!("{}: {e}", p.id())))
        .collect()
}

/// [`pipeline`] as a tuple: the mesh the scheme used, the number of connections, the 3D
/// and the flat panels.
pub fn panels_of(job: &Job) -> (Mesh, usize, Vec<Panel>, Vec<FlatPanel>) {
    let p = pipeline(job);
    (p.mesh, p.output.connections, p.panels, p.flat)
}

/// Build options for `scheme` at `--size size --holes holes --out out` (the rest at
/// their defaults), to adjust before [`resolve`].
pub fn options(scheme: &str, size: &str, holes: u32, out: &Path) -> BuildOptions {
    BuildOptions {
        scheme: Some(scheme.to_string()),
        holes: Some(holes),
        out: Some(out.to_path_buf()),
        // The geometry tests build models more detailed than their size on purpose;
        // the stop itself is tested in size_checks.rs.
        build_anyway: true,
        model: ModelOptions {
            size: Some(size.to_string()),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Resolves build options for a model, as the command line does.
pub fn resolve(options: BuildOptions, model: &Path) -> Job {
    options.resolve(model).expect("options resolve")
}

/// The job of `unfold MODEL --scheme SCHEME --size SIZE --holes HOLES --out OUT`.
pub fn job(scheme: &str, model: &Path, size: &str, holes: u32, out: &Path) -> Job {
    resolve(options(scheme, size, holes, out), model)
}

// =======================================================================================
// Golden files
// =======================================================================================

/// A golden build: runs `unfold models/MODEL.obj ARGS --format svg,dxf` from the crate
/// root (so the manifest's `input.path` is the same on every machine) and compares the
/// output folder with `tests/golden/DIR` ([`compare_with_golden`]). Returns the temporary
/// folder, the output folder and its manifest for further checks, or `None` when
/// `UNFOLD_UPDATE_GOLDEN=1` rewrote the golden files.
pub fn golden_build(
    test: &str,
    dir: &str,
    model: &str,
    args: &[&str],
) -> Option<(tempfile::TempDir, PathBuf, Value)> {
    let golden = crate_dir().join("tests/golden").join(dir);
    let tmp = tempfile::TempDir::new().unwrap();
    let out = tmp.path().join(model);
    let path = format!("models/{model}.obj");
    let run = finish(
        unfold_command()
            .current_dir(crate_dir())
            .arg(&path)
            .args(args)
            .args(["--format", "svg,dxf", "--out"])
            .arg(&out),
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let manifest = read_manifest(&out);
    assert_eq!(manifest["input"]["path"], path.as_str());
    match compare_with_golden(&out, &golden, tmp.path(), test) {
        Golden::Rewritten => None,
        Golden::Matched => Some((tmp, out, manifest)),
    }
}

/// The first line where two texts differ, for the failure message.
pub fn first_difference(want: &[u8], got: &[u8]) -> String {
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

/// What [`compare_with_golden`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Golden {
    /// The output equals the golden files.
    Matched,
    /// `UNFOLD_UPDATE_GOLDEN=1`: the golden folder was rewritten from the output.
    Rewritten,
}

/// Compares the output folder `out` with the golden folder byte for byte (after
/// checking that no file names the temporary folder `tmp`), or, with
/// `UNFOLD_UPDATE_GOLDEN=1`, rewrites the golden folder from it. `test` names the test
/// target for the update hint (`cargo test --test TEST golden`).
pub fn compare_with_golden(out: &Path, golden: &Path, tmp: &Path, test: &str) -> Golden {
    let now = folder_files(out);
    for (name, bytes) in &now {
        let text = String::from_utf8_lossy(bytes);
        assert!(
            !text.contains(&*tmp.to_string_lossy()),
            "{name} names the temporary folder"
        );
    }

    if std::env::var("UNFOLD_UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
        if golden.exists() {
            std::fs::remove_dir_all(golden).unwrap();
        }
        std::fs::create_dir_all(golden).unwrap();
        for (name, bytes) in &now {
            std::fs::write(golden.join(name), bytes).unwrap();
        }
        eprintln!("UNFOLD_UPDATE_GOLDEN=1: rewrote {}", golden.display());
        return Golden::Rewritten;
    }
    assert!(
        golden.is_dir(),
        "{} is missing; create it with UNFOLD_UPDATE_GOLDEN=1 cargo test --test {test} golden",
        golden.display()
    );
    let want = folder_files(golden);
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
    Golden::Matched
}

/// An OBJ of a flat `n` x `n` grid of unit squares in the plane z = 0.
pub fn flat_grid_obj(n: usize) -> String {
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            obj.push_str(&format!("v {i} {j} 0\n"));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |di: usize, dj: usize| (j + dj) * (n + 1) + i + di + 1;
            let corners = [v(0, 0), v(1, 0), v(1, 1), v(0, 1)];
            obj.push_str(&format!(
                "f {} {} {} {}\n",
                corners[0], corners[1], corners[2], corners[3]
            ));
        }
    }
    obj
}

/// The mesh a job's scheme would build, written as an OBJ.
pub fn write_obj(mesh: &Mesh, path: &Path) {
    let mut text = String::new();
    for p in mesh.positions() {
        text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for f in mesh.faces() {
        let corners: Vec<String> = mesh
            .face_vertices(f)
            .map(|v| (v.0 + 1).to_string())
            .collect();
        text.push_str(&format!("f {}\n", corners.join(" ")));
    }
    std::fs::write(path, text).unwrap();
}

/// `model` simplified to `edges` edges (its holes filled when `fill_holes`), as the
/// half-edge scheme builds it, written to `dir` as an OBJ: a test that builds one model
/// with many schemes or sizes simplifies it once.
pub fn simplified_obj(model: &Path, edges: usize, fill_holes: bool, dir: &Path) -> PathBuf {
    let mut o = options("half-edge", "1ft", 0, &dir.join("unused"));
    o.model.target_edges = Some(unfold::config::TargetEdges::Count(edges));
    o.model.fill_holes = fill_holes;
    let job = resolve(o, model);
    let loaded = unfold::run::load(&job).expect("loads");
    let prepared = unfold::run::prepare(&job, loaded).expect("prepares");
    let stem = model.file_stem().unwrap().to_string_lossy();
    let path = dir.join(format!(
        "{stem}-{edges}{}.obj",
        if fill_holes { "-filled" } else { "" }
    ));
    write_obj(&prepared.scheme_mesh.mesh, &path);
    path
}

/// The closest point to `p` on triangle `abc` (by its Voronoi regions: corners, then
/// sides, then the inside).
pub fn closest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The triangles of a mesh (faces fanned from their first corner).
pub fn triangles(mesh: &Mesh) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for f in mesh.faces() {
        let p: Vec<DVec3> = mesh.face_positions(f).collect();
        for k in 1..p.len() - 1 {
            out.push([p[0], p[k], p[k + 1]]);
        }
    }
    out
}
