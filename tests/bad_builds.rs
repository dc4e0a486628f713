//! Broken models and absurd options through the real binary's main command,
//! `unfold MODEL --out DIR …` (`tests/bad_inputs.rs` does the same for
//! `unfold inspect`).
//!
//! Every input is generated here, in a temporary folder that also holds the output
//! folder. Before a run, DIR holds an earlier run's output: a sentinel file and the
//! manifest listing it. A refused run must end with
//! exactly one line on stderr, `unfold: error: …`, naming the model file or the option,
//! exit code 2 (options) or 3 (model), nothing on stdout, no panic, DIR holding only the
//! unchanged sentinel and no new entry beside DIR (the atomic writer's staging folders).
//! A DIR that did not exist must not be created. Repairs must succeed, note the repair
//! and replace DIR (sentinel gone, manifest in).
//!
//! The binary runs under `ulimit -v` (4 GiB) and is killed after 120 s: a hang guard,
//! not a timing check. Each test runs all its cases, then fails naming every case that
//! failed (each case's own message is printed above).

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::io::{BufWriter, Read, Write};
use std::ops::RangeInclusive;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use tempfile::TempDir;

use common::build::{unfold_command, Run};
use common::corpus::{
    assert_clean_error, binary_stl, head, moebius_obj, random_bytes, CUBE, TWO_TRIANGLES,
};

// ---------------------------------------------------------------------------------------
// Running the binary
// ---------------------------------------------------------------------------------------

/// A run that takes longer than this is a hang.
const HANG_GUARD: Duration = Duration::from_secs(120);

/// Virtual memory allowed to the binary, in KiB (4 GiB).
const MEMORY_LIMIT_KIB: u64 = 4 * 1024 * 1024;

/// Runs `unfold ARGS…` through `sh -c 'ulimit -v …; exec …'`; kills it and fails the
/// case with "hang" if it has not finished after [`HANG_GUARD`].
fn run_guarded(case: &str, args: &[&OsStr]) -> Run {
    let binary = unfold_command().get_program().to_owned();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {MEMORY_LIMIT_KIB}; exec \"$0\" \"$@\""))
        .arg(binary)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    // Read both pipes while waiting: a panic's backtrace can fill a pipe's buffer.
    let drain = |mut pipe: Box<dyn Read + Send>| {
        thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for unfold") {
            break status;
        }
        if start.elapsed() > HANG_GUARD {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{case}: hang: unfold {args:?} did not finish within {HANG_GUARD:?}");
        }
        thread::sleep(Duration::from_millis(10));
    };
    Run {
        code: status.code(),
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// `unfold MODEL --out OUT EXTRA…`.
fn build(case: &str, model: &Path, out: &Path, extra: &[&str]) -> Run {
    let mut args = vec![model.as_os_str(), OsStr::new("--out"), out.as_os_str()];
    args.extend(extra.iter().map(OsStr::new));
    run_guarded(case, &args)
}

/// Runs every case, then fails naming each case that failed.
fn run_cases<T>(
    cases: impl IntoIterator<Item = T>,
    name: impl Fn(&T) -> String,
    check: impl Fn(&T),
) {
    let failed: Vec<String> = cases
        .into_iter()
        .filter_map(|case| {
            let name = name(&case);
            catch_unwind(AssertUnwindSafe(|| check(&case)))
                .err()
                .map(|_| name)
        })
        .collect();
    assert!(
        failed.is_empty(),
        "{} case(s) failed (messages above): {failed:#?}",
        failed.len()
    );
}

// ---------------------------------------------------------------------------------------
// The temporary folder, the output folder and its sentinel
// ---------------------------------------------------------------------------------------

const SENTINEL_NAME: &str = "keep.txt";
const SENTINEL: &str = "sentinel: a refused run must leave this folder alone\n";
/// The manifest of an earlier run that wrote the sentinel: the folder is unfold's own,
/// so a successful run replaces it and a refused one must leave it alone.
const SENTINEL_MANIFEST: &str =
    "{\"tool\": {\"name\": \"unfold\"}, \"files\": [\"keep.txt\", \"manifest.json\"]}\n";

/// A temporary folder holding a case's model and the output folder `out`.
struct Sandbox {
    dir: TempDir,
}

impl Sandbox {
    fn new() -> Self {
        Sandbox {
            dir: TempDir::new().expect("temporary folder"),
        }
    }

    /// Writes `bytes` to `NAME` in the folder and returns the path.
    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let path = self.path(name);
        std::fs::write(&path, bytes).expect("write test input");
        path
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// The output folder, beside the inputs.
    fn out(&self) -> PathBuf {
        self.path("out")
    }

    /// Creates the output folder of an earlier run: the sentinel file and a manifest
    /// listing it.
    fn plant_sentinel(&self) -> PathBuf {
        let out = self.out();
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join(SENTINEL_NAME), SENTINEL).unwrap();
        std::fs::write(out.join("manifest.json"), SENTINEL_MANIFEST).unwrap();
        out
    }

    /// Names of the folder's entries (the output folder's parent).
    fn entries(&self) -> BTreeSet<String> {
        entry_names(self.dir.path())
    }
}

fn entry_names(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// The plain files of a folder with their contents; fails on a subfolder.
fn folder_files(case: &str, dir: &Path) -> BTreeMap<String, String> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{case}: {}: {e}", dir.display()))
        .map(|entry| {
            let entry = entry.unwrap();
            let name = entry.file_name().to_string_lossy().into_owned();
            assert!(
                entry.file_type().unwrap().is_file(),
                "{case}: {}/{name} is not a plain file",
                dir.display()
            );
            let bytes = std::fs::read(entry.path()).unwrap();
            (name, String::from_utf8_lossy(&bytes).into_owned())
        })
        .collect()
}

/// The output folder holds only the unchanged earlier output and nothing appeared
/// beside it.
fn assert_untouched(case: &str, sandbox: &Sandbox, before: &BTreeSet<String>) {
    let files = folder_files(case, &sandbox.out());
    let expected = BTreeMap::from([
        (SENTINEL_NAME.to_string(), SENTINEL.to_string()),
        ("manifest.json".to_string(), SENTINEL_MANIFEST.to_string()),
    ]);
    assert_eq!(files, expected, "{case}: the output folder was touched");
    assert_eq!(
        &sandbox.entries(),
        before,
        "{case}: entries appeared or vanished beside the output folder"
    );
}

// ---------------------------------------------------------------------------------------
// What a refused run prints
// ---------------------------------------------------------------------------------------

/// Where a model error must point.
#[derive(Clone)]
enum At {
    /// It names the file (`FILE: …`, any location).
    File,
    /// `FILE:N: …`.
    Line(u64),
    /// `FILE:N: …` with N in the range.
    LineIn(RangeInclusive<u64>),
}

/// The message names the model file and points where `at` says.
fn assert_points_at(case: &str, run: &Run, model: &Path, at: &At) {
    let err = &run.stderr;
    let name = model.display().to_string();
    let after = format!("unfold: error: {name}");
    assert!(
        err.starts_with(&after),
        "{case}: does not start by naming {name}: {err}"
    );
    let line = err[after.len()..]
        .strip_prefix(':')
        .and_then(|rest| rest.split(':').next())
        .and_then(|n| n.parse::<u64>().ok());
    let range = match at {
        At::File => return,
        At::Line(n) => *n..=*n,
        At::LineIn(range) => range.clone(),
    };
    assert!(
        line.is_some_and(|n| range.contains(&n)),
        "{case}: does not point at a line in {range:?} ({name}:N: …): {err}"
    );
}

// ---------------------------------------------------------------------------------------
// The checks of a case
// ---------------------------------------------------------------------------------------

/// Runs `unfold MODEL --out DIR EXTRA…` with DIR holding only the sentinel; asserts a
/// clean refusal with `code` and that DIR and its parent were left as they were.
fn assert_refused(
    case: &str,
    sandbox: &Sandbox,
    model: &Path,
    extra: &[&str],
    code: i32,
    says: &[&str],
) -> Run {
    let out = sandbox.plant_sentinel();
    let before = sandbox.entries();
    let run = build(case, model, &out, extra);
    assert_clean_error(case, &run, code, says);
    assert_untouched(case, sandbox, &before);
    run
}

/// A broken model: exit 3, naming the file at `at`.
struct BadModel {
    file: &'static str,
    /// `None`: the file is not written at all.
    bytes: Option<Vec<u8>>,
    at: At,
    says: &'static [&'static str],
}

fn bad_model(
    file: &'static str,
    bytes: impl Into<Vec<u8>>,
    at: At,
    says: &'static [&'static str],
) -> BadModel {
    BadModel {
        file,
        bytes: Some(bytes.into()),
        at,
        says,
    }
}

fn check_bad_model(case: &BadModel) {
    let sandbox = Sandbox::new();
    let model = match &case.bytes {
        Some(bytes) => sandbox.write(case.file, bytes),
        None => sandbox.path(case.file),
    };
    let run = assert_refused(case.file, &sandbox, &model, &[], 3, case.says);
    assert_points_at(case.file, &run, &model, &case.at);
}

fn check_bad_models(cases: Vec<BadModel>) {
    run_cases(cases, |c| c.file.to_string(), check_bad_model);
}

/// A good model with absurd options: exit 2, the message saying every fragment.
fn check_absurd_option(args: &[&str], says: &[&str]) {
    let case = format!("unfold cube.obj {}", args.join(" "));
    let sandbox = Sandbox::new();
    let model = sandbox.write("cube.obj", CUBE);
    assert_refused(&case, &sandbox, &model, args, 2, says);
}

/// Runs a model that the tool repairs: exit 0, stderr has the `note:` (if any) and no
/// error, and the output folder was replaced: sentinel gone, `manifest.json` in, no
/// staging folder left beside it.
fn check_repaired(file: &str, bytes: &[u8], note: Option<&str>) {
    let sandbox = Sandbox::new();
    let model = sandbox.write(file, bytes);
    let out = sandbox.plant_sentinel();
    let before = sandbox.entries();
    let run = build(file, &model, &out, &["--build-anyway"]);
    let err = &run.stderr;
    assert!(!err.contains("panicked"), "{file}: panic:\n{}", head(err));
    assert_eq!(run.code, Some(0), "{file}: exit code; stderr:\n{err}");
    assert!(!err.contains("unfold: error"), "{file}: stderr: {err}");
    assert!(run.stdout.is_empty(), "{file}: stdout: {}", run.stdout);
    if let Some(note) = note {
        let line = format!("note: {note}\n");
        assert!(err.contains(&line), "{file}: no {line:?} in:\n{err}");
    }
    let files = folder_files(file, &out);
    assert!(
        !files.contains_key(SENTINEL_NAME),
        "{file}: the sentinel survived: {:?}",
        files.keys()
    );
    let manifest = files
        .get("manifest.json")
        .unwrap_or_else(|| panic!("{file}: no manifest.json in {:?}", files.keys()));
    serde_json::from_str::<serde_json::Value>(manifest)
        .unwrap_or_else(|e| panic!("{file}: manifest.json is not JSON: {e}"));
    assert_eq!(
        sandbox.entries(),
        before,
        "{file}: entries appeared or vanished beside the output folder"
    );
}

// ---------------------------------------------------------------------------------------
// Generators
// ---------------------------------------------------------------------------------------

/// The cube with every coordinate 1 written as `one` ("1e300").
fn cube_scaled(one: &str) -> String {
    CUBE.lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(xyz) => {
                let xyz: Vec<&str> = xyz
                    .split(' ')
                    .map(|c| if c == "1" { one } else { c })
                    .collect();
                format!("v {}\n", xyz.join(" "))
            }
            None => format!("{line}\n"),
        })
        .collect()
}

/// Two closed cones of `n` sides touching at their apex, OBJ vertex 1: a non-manifold
/// vertex where two fans of faces meet.
fn two_cones_obj(n: usize) -> String {
    let mut vertices = vec![[0.0; 3]];
    let mut faces = Vec::new();
    for z in [1.0, -1.0] {
        let ring = vertices.len() + 1;
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            vertices.push([a.cos(), a.sin(), z]);
        }
        vertices.push([0.0, 0.0, z]);
        let centre = vertices.len();
        for k in 0..n {
            let (i, j) = (ring + k, ring + (k + 1) % n);
            // Outward: the lower cone is the mirror image of the upper one.
            let (i, j) = if z > 0.0 { (i, j) } else { (j, i) };
            faces.push([1, j, i]);
            faces.push([centre, i, j]);
        }
    }
    let mut s = String::new();
    for [x, y, z] in vertices {
        s += &format!("v {x} {y} {z}\n");
    }
    for [a, b, c] in faces {
        s += &format!("f {a} {b} {c}\n");
    }
    s
}

// ---------------------------------------------------------------------------------------
// Broken models (exit 3)
// ---------------------------------------------------------------------------------------

#[test]
fn empty_missing_and_unknown_models_are_refused() {
    check_bad_models(vec![
        BadModel {
            file: "missing.obj",
            bytes: None,
            at: At::File,
            says: &["no such file"],
        },
        bad_model("empty.obj", "", At::File, &["the file is empty"]),
        bad_model(
            "blank.obj",
            " \n\t\r\n   \n",
            At::File,
            &["the file is empty"],
        ),
        bad_model(
            "model.ply",
            "ply\nformat ascii 1.0\nend_header\n",
            At::File,
            &["unknown model format"],
        ),
        bad_model("cube", CUBE, At::File, &["unknown model format"]),
    ]);
}

#[test]
fn obj_syntax_and_values_are_refused() {
    check_bad_models(vec![
        // Cut in the middle of a vertex line.
        bad_model(
            "cut-vertex.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1",
            At::Line(3),
            &["vertex has 2 coordinates"],
        ),
        // Cut in the vertex list: a face refers past its end.
        bad_model(
            "cut-vertices.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            At::Line(4),
            &["face refers to vertex 4 but the file defines only 3 vertices"],
        ),
        bad_model(
            "number.obj",
            "v 0 0 0\nv 1 x 2\nv 0 1 0\nf 1 2 3\n",
            At::Line(2),
            &["'x' is not a number"],
        ),
        bad_model(
            "nan.obj",
            "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
            At::Line(2),
            &["'NaN' is not a finite number"],
        ),
        bad_model(
            "inf.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 inf\nf 1 2 3\n",
            At::Line(3),
            &["'inf' is not a finite number"],
        ),
        bad_model(
            "minus-inf.obj",
            "v 0 0 0\nv 1 0 -inf\nv 0 1 0\nf 1 2 3\n",
            At::Line(2),
            &["'-inf' is not a finite number"],
        ),
        bad_model(
            "overflow.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 1e999\nf 1 2 3\n",
            At::Line(3),
            &["'1e999' is not a finite number"],
        ),
        // Beyond ±1e15 areas would overflow: refused where it is read.
        bad_model(
            "huge.obj",
            cube_scaled("1e300"),
            At::Line(2),
            &["vertex coordinate '1e300' is too large", "within ±1e15"],
        ),
        bad_model(
            "one-huge-coordinate.obj",
            CUBE.replacen("v 0 1 1\n", "v 0 1 1e300\n", 1),
            At::LineIn(1..=8),
            &["vertex coordinate '1e300' is too large"],
        ),
        bad_model(
            "index-zero.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 2 3\n",
            At::Line(4),
            &["vertex index 0 in a face"],
        ),
        bad_model(
            "index-past.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
            At::Line(5),
            &["face refers to vertex 4 but the file defines only 3 vertices"],
        ),
        bad_model(
            "index-negative.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            At::Line(4),
            &["vertex index -4 is out of range (3 vertices defined so far)"],
        ),
    ]);
}

#[test]
fn obj_topology_that_cannot_be_built_is_refused() {
    check_bad_models(vec![
        bad_model(
            "collinear.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
            At::File,
            &["no usable faces are left after removing degenerate ones"],
        ),
        bad_model(
            "one-vertex-faces.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 1\nf 2 2 3\n",
            At::File,
            &["no usable faces are left after removing degenerate ones"],
        ),
        bad_model(
            "all-degenerate.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 4 4 4\nf 1 1 4\n",
            At::File,
            &["no usable faces are left after removing degenerate ones"],
        ),
        // Three triangles on the edge between OBJ vertices 2 and 3.
        bad_model(
            "fin.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0.5 0.5 1\nf 2 3 1\nf 3 2 4\nf 2 3 5\n",
            At::Line(6),
            &[
                "non-manifold edge between vertices 2 and 3",
                "shared by 3 faces",
            ],
        ),
        // Which face the orientation walk stops at is its business: any face line.
        bad_model(
            "moebius.obj",
            moebius_obj(6),
            At::LineIn(13..=18),
            &["non-orientable (like a Möbius strip)"],
        ),
    ]);
}

#[test]
fn binary_stl_and_off_breakage_is_refused() {
    let mut garbage = random_bytes(4096, 0x9E37_79B9_7F4A_7C15);
    garbage[3] = 0;
    let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
    png.extend(random_bytes(1024, 7));
    let three = [TWO_TRIANGLES[0], TWO_TRIANGLES[1], TWO_TRIANGLES[0]];
    let mut cut_in_a_record = binary_stl(b"binary", 2, &TWO_TRIANGLES);
    cut_in_a_record.truncate(84 + 50 + 20);
    check_bad_models(vec![
        bad_model("garbage.obj", garbage, At::File, &["byte 3: binary data"]),
        bad_model("picture.obj", png, At::File, &["byte 8: binary data"]),
        bad_model(
            "stl-renamed.obj",
            binary_stl(b"binary", 2, &TWO_TRIANGLES),
            At::File,
            &["byte 81: binary data"],
        ),
        bad_model(
            "cut.stl",
            binary_stl(b"", 10, &three),
            At::File,
            &["truncated binary STL: the header announces 10 triangles (584 bytes) but the file has 234 bytes"],
        ),
        bad_model(
            "cut-record.stl",
            cut_in_a_record,
            At::File,
            &["truncated binary STL: the header announces 2 triangles (184 bytes) but the file has 154 bytes"],
        ),
        bad_model(
            "quad.stl",
            "solid q\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  \
             vertex 1 1 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid q\n",
            At::Line(2),
            &["facet has 4 vertices"],
        ),
        bad_model(
            "header.off",
            "OFX\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            At::Line(1),
            &["expected an 'OFF' header, found 'OFX'"],
        ),
        bad_model(
            "short.off",
            "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n",
            At::Line(7),
            &["the file ends after 1 of 2 faces"],
        ),
        bad_model(
            "no-faces.off",
            "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n",
            At::Line(6),
            &["the file ends after 0 of 2 faces"],
        ),
    ]);
}

#[test]
fn ten_million_comment_lines_are_refused() {
    let sandbox = Sandbox::new();
    let model = sandbox.path("comments.obj");
    let mut file = BufWriter::new(std::fs::File::create(&model).unwrap());
    for _ in 0..10_000_000 {
        file.write_all(b"#\n").unwrap();
    }
    file.into_inner().unwrap().sync_all().unwrap();
    let case = "10,000,000 comment lines";
    let run = assert_refused(case, &sandbox, &model, &[], 3, &["the file has no faces"]);
    assert_points_at(case, &run, &model, &At::File);
}

// ---------------------------------------------------------------------------------------
// Repairs (exit 0; the output folder is replaced)
// ---------------------------------------------------------------------------------------

#[test]
fn repaired_models_replace_the_output_folder() {
    let dropped_face = "1 faces repeat an earlier face's corners and were dropped: face 6 (line 15) repeats face 0";
    let bow_tie = "1 vertices are bow-ties (separate fans of faces meet there) and were split into one vertex per fan: vertex 1 with 2 fans";
    let cases: Vec<(&str, Vec<u8>, Option<&str>)> = vec![
        // The control: a good model replaces the sentinel folder.
        ("cube.obj", CUBE.into(), None),
        (
            "duplicate-face.obj",
            format!("{CUBE}f 1 4 3 2\n").into(),
            Some(dropped_face),
        ),
        (
            "duplicate-face-rotated.obj",
            format!("{CUBE}f 3 2 1 4\n").into(),
            Some(dropped_face),
        ),
        (
            "duplicate-face-reversed.obj",
            format!("{CUBE}f 1 2 3 4\n").into(),
            Some(dropped_face),
        ),
        ("two-cones.obj", two_cones_obj(6).into(), Some(bow_tie)),
        (
            "bow-tie.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n".into(),
            Some(bow_tie),
        ),
        // Cut in the middle of the last face line ("f 4 1"): an open box.
        (
            "cut-face.obj",
            CUBE.as_bytes()[..CUBE.len() - 5].to_vec(),
            Some("1 faces have fewer than 3 distinct corners and were dropped: face 5 (line 14)"),
        ),
    ];
    run_cases(
        cases,
        |c| c.0.to_string(),
        |(file, bytes, note)| check_repaired(file, bytes, *note),
    );
}

// ---------------------------------------------------------------------------------------
// Absurd options on a good model (exit 2)
// ---------------------------------------------------------------------------------------

/// Arguments and what the message must say.
type OptionCase = (&'static [&'static str], &'static [&'static str]);

const ABSURD_OPTIONS: &[OptionCase] = &[
    (
        &["--sheet", "0x0in"],
        &["--sheet: sheet '0x0in' must have a positive width and height"],
    ),
    (
        &["--sheet=-18x24in"],
        &["--sheet: sheet '-18x24in' must have a positive width and height"],
    ),
    // Smaller than the default margin: the margin is what is refused.
    (
        &["--sheet", "0.1x0.1in"],
        &["--margin 0.25in leaves no room on a 0.1x0.1in sheet"],
    ),
    (
        &["--sheet", "18x24in", "--margin", "20in"],
        &["--margin 20in leaves no room on a 18x24in sheet"],
    ),
    (
        &["--spacing=-1mm"],
        &["--margin and --spacing cannot be negative"],
    ),
    (
        &["--face-scale", "0"],
        &["--face-scale: 0 must be greater than 0 and at most 1"],
    ),
    (
        &["--face-scale", "2"],
        &["--face-scale: 2 must be greater than 0 and at most 1"],
    ),
    (
        &["--scheme", "quad-edge", "--face-scale", "1"],
        &["--face-scale: the edge schemes' bends run between the face bands and the edges, so a band must be smaller than its face: below 1, not 1"],
    ),
    (
        &["--samples", "8"],
        &["--samples: the half-edge scheme does not take this option; it is an option of quad-edge, winged-edge, chosen with --scheme"],
    ),
    (
        &["--scheme", "quad-edge", "--samples", "1000000000"],
        &["--samples: 1000000000 must be between 1 and 64"],
    ),
    (
        &["--scheme", "winged-edge", "--samples", "0"],
        &["--samples: 0 must be between 1 and 64"],
    ),
    (
        &["--scheme", "winged-edge", "--shift", "2"],
        &["--shift: 2 must be -1, 0 or 1"],
    ),
    (
        &["--scheme", "woven", "--curl-limit", "1"],
        &["--curl-limit: 1 must be at least 1.5"],
    ),
    (&["--size", "0mm"], &["--size: '0mm' must be positive"]),
    (
        &["--rotations", "0"],
        &["--rotations: 0 must be between 1 and 3600"],
    ),
    (
        &["--holes", "9"],
        &["--holes: 9 holes per connection; the half-edge scheme takes [0, 1, 2]"],
    ),
    (
        &["--scheme", "quad-edge", "--holes", "9"],
        &["--holes: 9 holes per connection; the quad-edge scheme takes [0, 1, 2, 4]"],
    ),
    (
        &["--hole-diameter", "0mm"],
        &["--hole-diameter: '0mm' must be positive"],
    ),
    (
        &["--label-height=-1mm"],
        &["--label-height: '-1mm' must be positive"],
    ),
    (
        &["--scheme", "quad-edge", "--bridge-scale", "2"],
        &["--bridge-scale: 2 must be greater than 0 and at most 1"],
    ),
    (
        &["--stroke-width", "0mm"],
        &["--stroke-width: '0mm' must be positive"],
    ),
    (
        &["--format", "png"],
        &["--format: unknown format 'png'; use svg, dxf or svg,dxf"],
    ),
    (
        &["--scale", "nan"],
        &["--scale: NaN must be a positive number"],
    ),
];

#[test]
fn absurd_options_are_refused() {
    run_cases(
        ABSURD_OPTIONS,
        |(args, _)| format!("unfold cube.obj {}", args.join(" ")),
        |(args, says)| check_absurd_option(args, says),
    );
}

// ---------------------------------------------------------------------------------------
// A missing output folder stays missing
// ---------------------------------------------------------------------------------------

/// A refused run whose `--out` folder does not exist.
struct NoOutFolder {
    case: &'static str,
    model: &'static str,
    /// `--out`, below the sandbox.
    out: &'static str,
    extra: &'static [&'static str],
    code: i32,
    says: &'static str,
}

#[test]
fn refused_runs_do_not_create_the_output_folder() {
    let cases = [
        NoOutFolder {
            case: "empty model",
            model: "",
            out: "out",
            extra: &[],
            code: 3,
            says: "the file is empty",
        },
        NoOutFolder {
            case: "empty model, nested --out",
            model: "",
            out: "a/b/out",
            extra: &[],
            code: 3,
            says: "the file is empty",
        },
        NoOutFolder {
            case: "--format png",
            model: CUBE,
            out: "out",
            extra: &["--format", "png"],
            code: 2,
            says: "--format: unknown format 'png'",
        },
        NoOutFolder {
            case: "--size 0mm, nested --out",
            model: CUBE,
            out: "a/b/out",
            extra: &["--size", "0mm"],
            code: 2,
            says: "--size: '0mm' must be positive",
        },
    ];
    run_cases(
        cases,
        |c| c.case.to_string(),
        |c| {
            let sandbox = Sandbox::new();
            let model = sandbox.write("model.obj", c.model);
            let out = sandbox.path(c.out);
            let before = sandbox.entries();
            let run = build(c.case, &model, &out, c.extra);
            assert_clean_error(c.case, &run, c.code, &[c.says]);
            assert!(!out.exists(), "{}: {} was created", c.case, out.display());
            assert_eq!(
                sandbox.entries(),
                before,
                "{}: entries appeared beside the model",
                c.case
            );
        },
    );
}

// ---------------------------------------------------------------------------------------
// Huge lengths and models: lengths are bounded to 1 km and coordinates to ±1e15, so
// none of these reaches the geometry
// ---------------------------------------------------------------------------------------

/// Huge lengths that should be refused as options (exit 2, naming the option).
const HUGE_LENGTHS: &[OptionCase] = &[
    // Would overflow the collision engine's f32 geometry (a NaN diameter).
    (&["--size", "1e300mm"], &["--size"]),
    (&["--scale", "1e300"], &["--scale"]),
    // A model built a nanometre across.
    (&["--scale", "1e-9"], &["--scale", "smaller than 0.1 mm"]),
    (&["--size", "1e-6mm"], &["--size", "smaller than 0.1 mm"]),
    (&["--sheet", "1e300x1e300in"], &["--sheet"]),
    (&["--spacing", "1e300mm"], &["--spacing"]),
    // Would make facets whose area overflows to no area.
    (&["--size", "1e30mm"], &["--size"]),
    // A tab taller than any neighbour face is a typo, not a wish.
    (&["--tab-height", "1e300mm"], &["--tab-height"]),
    // A hole larger than the model; its note would print 301 digits.
    (
        &[
            "--size",
            "100mm",
            "--holes",
            "1",
            "--hole-diameter",
            "1e300mm",
        ],
        &["--hole-diameter"],
    ),
    // A 301-digit stroke-width in the SVG.
    (&["--stroke-width", "1e300mm"], &["--stroke-width"]),
];

#[test]
fn huge_lengths_are_refused() {
    run_cases(
        HUGE_LENGTHS,
        |(args, _)| format!("unfold cube.obj {}", args.join(" ")),
        |(args, says)| check_absurd_option(args, says),
    );
}

#[test]
fn huge_models_are_refused() {
    let cases = ["1e14", "1e150", "1e308"].map(|one| (format!("cube-{one}.obj"), cube_scaled(one)));
    run_cases(
        cases,
        |c| c.0.clone(),
        |(file, text)| {
            let sandbox = Sandbox::new();
            let model = sandbox.write(file, text);
            let run = assert_refused(file, &sandbox, &model, &[], 3, &[]);
            assert_points_at(file, &run, &model, &At::File);
            let longest = run
                .stderr
                .split(|c: char| !c.is_ascii_digit())
                .map(str::len)
                .max()
                .unwrap_or(0);
            assert!(
                longest <= 20,
                "{file}: a {longest}-digit number: {}",
                run.stderr
            );
        },
    );
}
