//! Broken inputs and absurd options through the real `unfold inspect` binary.
//!
//! Every input is generated inside the test, in a temporary directory. Errors must be
//! one line on stderr, `unfold: error: FILE[:LINE]: …`, with the right exit code (3 for
//! a bad model, 2 for bad options), nothing on stdout and never a panic. Repairs must
//! succeed (exit 0) and be listed under `notes:` in the report.

use crate::common;

use std::path::{Path, PathBuf};

use tempfile::TempDir;

use common::build::{finish, unfold_command, Run};
use common::corpus::{
    assert_clean_error, binary_stl, moebius_obj, random_bytes, CUBE, TWO_TRIANGLES,
};

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// Writes `bytes` to `dir/name` and returns the path.
fn write(dir: &TempDir, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).expect("write test input");
    path
}

/// Runs `unfold inspect MODEL ARGS…`.
fn inspect(model: &Path, args: &[&str]) -> Run {
    finish(unfold_command().arg("inspect").arg(model).args(args))
}

/// Asserts a clean one-line error with exit code `code` that names the model file,
/// the line when `line` is given, and contains every fragment of `says`.
fn assert_error(case: &str, run: &Run, code: i32, model: &Path, line: Option<u64>, says: &[&str]) {
    assert_clean_error(case, run, code, says);
    let err = &run.stderr;
    let name = model.display().to_string();
    assert!(err.contains(&name), "{case}: does not name {name}: {err}");
    if let Some(line) = line {
        let at = format!("{name}:{line}: ");
        assert!(err.contains(&at), "{case}: does not point at {at:?}: {err}");
    }
}

/// Asserts a clean one-line usage error (exit 2) containing every fragment of `says`.
fn assert_usage_error(case: &str, run: &Run, says: &[&str]) {
    assert_clean_error(case, run, 2, says);
}

/// Asserts success with an empty stderr; returns the `notes:` section of the report.
fn assert_ok_notes(case: &str, run: &Run) -> String {
    assert!(
        !run.stderr.contains("panicked"),
        "{case}: panic: {}",
        run.stderr
    );
    assert_eq!(
        run.code,
        Some(0),
        "{case}: exit code; stderr: {}",
        run.stderr
    );
    assert!(run.stderr.is_empty(), "{case}: stderr: {}", run.stderr);
    let at = run
        .stdout
        .find("\nnotes:")
        .unwrap_or_else(|| panic!("{case}: no notes section in:\n{}", run.stdout));
    run.stdout[at + 1..].to_string()
}

/// Four vertices of a unit square in z = 0 (OBJ lines 1–4).
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";

// ---------------------------------------------------------------------------------------
// Files that cannot be read at all
// ---------------------------------------------------------------------------------------

#[test]
fn missing_file() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("missing.obj");
    let run = inspect(&path, &[]);
    assert_error("missing file", &run, 3, &path, None, &["no such file"]);
}

#[test]
fn directory_named_like_a_model() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("x.obj");
    std::fs::create_dir(&path).unwrap();
    let run = inspect(&path, &[]);
    assert_error("directory x.obj", &run, 3, &path, None, &["directory"]);
}

#[test]
fn empty_file() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "empty.obj", "");
    let run = inspect(&path, &[]);
    assert_error("empty file", &run, 3, &path, None, &["empty"]);
}

#[test]
fn whitespace_only_file() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "blank.obj", " \n\t\r\n   \n");
    let run = inspect(&path, &[]);
    assert_error("whitespace-only file", &run, 3, &path, None, &["empty"]);
}

#[test]
fn unknown_extension() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "model.ply", "ply\nformat ascii 1.0\nend_header\n");
    let run = inspect(&path, &[]);
    assert_error("unknown extension .ply", &run, 3, &path, None, &["format"]);
}

// ---------------------------------------------------------------------------------------
// OBJ syntax and values
// ---------------------------------------------------------------------------------------

#[test]
fn obj_malformed_number() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "number.obj", "v 0 0 0\nv 1 0 0\nv 0 1.x 0\nf 1 2 3\n");
    let run = inspect(&path, &[]);
    assert_error(
        "malformed number",
        &run,
        3,
        &path,
        Some(3),
        &["'1.x'", "not a number"],
    );
}

#[test]
fn obj_index_zero() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 2 3\n");
    let run = inspect(&path, &[]);
    assert_error("index 0", &run, 3, &path, Some(4), &["index 0"]);
}

#[test]
fn obj_index_out_of_range_positive() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "past.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    );
    let run = inspect(&path, &[]);
    assert_error(
        "index 4 of 3",
        &run,
        3,
        &path,
        Some(5),
        &["vertex 4", "3 vertices"],
    );
}

#[test]
fn obj_index_out_of_range_negative() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "negative.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
    );
    let run = inspect(&path, &[]);
    assert_error(
        "index -4 of 3",
        &run,
        3,
        &path,
        Some(4),
        &["-4", "out of range"],
    );
}

#[test]
fn obj_nan_coordinate() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "nan.obj", "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n");
    let run = inspect(&path, &[]);
    assert_error(
        "NaN coordinate",
        &run,
        3,
        &path,
        Some(2),
        &["NaN", "not a finite number"],
    );
}

#[test]
fn obj_infinite_coordinate() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n");
    let run = inspect(&path, &[]);
    assert_error(
        "inf coordinate",
        &run,
        3,
        &path,
        Some(3),
        &["-inf", "not a finite number"],
    );
}

#[test]
fn obj_comments_only_million_lines() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "comments.obj",
        "# nothing but a comment\n".repeat(1_000_000),
    );
    let run = inspect(&path, &[]);
    assert_error(
        "1,000,000 comment lines",
        &run,
        3,
        &path,
        None,
        &["no faces"],
    );
}

// ---------------------------------------------------------------------------------------
// OBJ topology: errors
// ---------------------------------------------------------------------------------------

#[test]
fn obj_non_manifold_edge() {
    // Three triangles on the edge between OBJ vertices 2 and 3.
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "fin.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0.5 0.5 1\nf 2 3 1\nf 3 2 4\nf 2 3 5\n",
    );
    let run = inspect(&path, &[]);
    assert_error(
        "non-manifold edge",
        &run,
        3,
        &path,
        Some(6),
        &["non-manifold edge", "vertices 2 and 3", "3 faces"],
    );
}

#[test]
fn obj_moebius_strip_is_non_orientable() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "moebius.obj", moebius_obj(6));
    let run = inspect(&path, &[]);
    // Faces start at line 13, after 12 vertices; the message points at a face line.
    assert_error("Möbius strip", &run, 3, &path, None, &["non-orientable"]);
    let line: u64 = run.stderr["unfold: error: ".len() + path.display().to_string().len() + 1..]
        .split(':')
        .next()
        .unwrap()
        .parse()
        .expect("a line number after the file name");
    assert!((13..=18).contains(&line), "Möbius strip: line {line}");
}

// ---------------------------------------------------------------------------------------
// OBJ: repairs (exit 0, listed under notes)
// ---------------------------------------------------------------------------------------

#[test]
fn obj_two_corner_face_is_dropped_and_noted() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "two.obj", format!("{SQUARE}f 1 2 3\nf 3 4\n"));
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("face of 2 corners", &run);
    assert!(
        notes.contains("fewer than 3 distinct corners") && notes.contains("line 6"),
        "face of 2 corners: notes:\n{notes}"
    );
}

#[test]
fn obj_vertex_of_dropped_face_is_named_in_note() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "two.obj", format!("{SQUARE}f 1 2 3\nf 3 4\n"));
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("vertex only on a dropped face", &run);
    assert!(
        notes.contains("1 vertices are used by no face and were dropped: vertex 4"),
        "vertex only on a dropped face: notes:\n{notes}"
    );
}

#[test]
fn obj_repeated_corner_is_collapsed() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "repeat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2 3\n");
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("f 1 2 2 3", &run);
    assert!(
        notes.contains("repeat a corner") && notes.contains("line 4"),
        "f 1 2 2 3: notes:\n{notes}"
    );
    assert!(run.stdout.contains("3-gons 1"), "f 1 2 2 3: {}", run.stdout);
}

#[test]
fn obj_bow_tie_is_split() {
    // Two triangles that share only OBJ vertex 1.
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "bowtie.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n",
    );
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("bow-tie", &run);
    assert!(
        notes.contains("bow-tie") && notes.contains("split") && notes.contains("vertex 1 "),
        "bow-tie: notes:\n{notes}"
    );
    assert!(
        run.stdout.contains("mesh:        vertices 6 "),
        "bow-tie: {}",
        run.stdout
    );
}

#[test]
fn obj_inconsistent_orientation_is_flipped() {
    // Both triangles run through the edge 2→3.
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "flip.obj", format!("{SQUARE}f 1 2 3\nf 2 3 4\n"));
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("inconsistent orientation", &run);
    assert!(
        notes.contains("flipped") && notes.contains("line 6"),
        "inconsistent orientation: notes:\n{notes}"
    );
    assert!(run.stdout.contains("misoriented edges 1"), "{}", run.stdout);
}

// ---------------------------------------------------------------------------------------
// Binary data
// ---------------------------------------------------------------------------------------

#[test]
fn binary_garbage_obj() {
    // Random bytes (this seed puts a NUL on the first line).
    let dir = TempDir::new().unwrap();
    let mut bytes = random_bytes(4096, 0x9E37_79B9_7F4A_7C15);
    bytes[3] = 0;
    assert!(bytes.contains(&0));
    let path = write(&dir, "garbage.obj", &bytes);
    let run = inspect(&path, &[]);
    assert_error(
        "binary garbage .obj",
        &run,
        3,
        &path,
        None,
        &["binary", "byte 3"],
    );
}

#[test]
fn binary_file_without_nul_on_first_line() {
    // A PNG renamed .obj: the first line is "\x89PNG\r", invalid UTF-8 and NUL-free.
    let dir = TempDir::new().unwrap();
    let mut bytes = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
    bytes.extend(random_bytes(1024, 7));
    let path = write(&dir, "picture.obj", &bytes);
    let run = inspect(&path, &[]);
    assert_error("PNG renamed .obj", &run, 3, &path, None, &["binary"]);
}

// ---------------------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------------------

#[test]
fn stl_binary_truncated() {
    let dir = TempDir::new().unwrap();
    let bytes = binary_stl(
        b"",
        10,
        &[TWO_TRIANGLES[0], TWO_TRIANGLES[1], TWO_TRIANGLES[0]],
    );
    let path = write(&dir, "cut.stl", bytes);
    let run = inspect(&path, &[]);
    assert_error(
        "truncated binary STL",
        &run,
        3,
        &path,
        None,
        &["truncated", "10 triangles"],
    );
}

#[test]
fn stl_binary_truncated_with_solid_header() {
    // Many exporters start the binary header with "solid"; the size then decides.
    let dir = TempDir::new().unwrap();
    let bytes = binary_stl(b"solid exported by CAD", 10, &[TWO_TRIANGLES[0]; 3]);
    let path = write(&dir, "cut-solid.stl", bytes);
    let run = inspect(&path, &[]);
    assert_error(
        "truncated binary STL, 'solid' header",
        &run,
        3,
        &path,
        None,
        &["truncated"],
    );
}

#[test]
fn stl_binary_two_triangles_is_valid() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "two.stl", binary_stl(b"binary", 2, &TWO_TRIANGLES));
    let run = inspect(&path, &[]);
    let notes = assert_ok_notes("binary STL of 2 triangles", &run);
    assert!(notes.contains("welded"), "binary STL: notes:\n{notes}");
    assert!(
        run.stdout
            .contains("mesh:        vertices 4  edges 5  faces 2"),
        "binary STL: {}",
        run.stdout
    );
}

#[test]
fn stl_binary_with_solid_header_is_valid() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "solid.stl", binary_stl(b"solid x", 2, &TWO_TRIANGLES));
    let run = inspect(&path, &[]);
    assert_ok_notes("binary STL with 'solid' header", &run);
}

#[test]
fn stl_ascii_facet_with_four_vertices() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "quad.stl",
        "solid q\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  \
         vertex 1 1 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid q\n",
    );
    let run = inspect(&path, &[]);
    assert_error("ASCII facet of 4", &run, 3, &path, Some(2), &["4 vertices"]);
}

// ---------------------------------------------------------------------------------------
// OFF
// ---------------------------------------------------------------------------------------

#[test]
fn off_missing_face_line() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "short.off",
        "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n",
    );
    let run = inspect(&path, &[]);
    assert_error(
        "OFF missing a face line",
        &run,
        3,
        &path,
        Some(7),
        &["ends after 1 of 2 faces", "truncated"],
    );
}

#[test]
fn off_wrong_header() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "header.off",
        "OFX\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let run = inspect(&path, &[]);
    assert_error(
        "OFF wrong header",
        &run,
        3,
        &path,
        Some(1),
        &["'OFF' header", "'OFX'"],
    );
}

// ---------------------------------------------------------------------------------------
// Options
// ---------------------------------------------------------------------------------------

fn good_model(dir: &TempDir) -> PathBuf {
    write(dir, "cube.obj", CUBE)
}

#[test]
fn size_zero() {
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--size", "0ft"]);
    assert_usage_error("--size 0ft", &run, &["--size", "0ft", "positive"]);
}

#[test]
fn size_without_unit() {
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--size", "4"]);
    assert_usage_error("--size 4", &run, &["--size", "no unit"]);
}

#[test]
fn negative_scale_with_equals() {
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--scale=-1"]);
    assert_usage_error("--scale=-1", &run, &["--scale", "-1", "positive"]);
}

#[test]
fn negative_scale() {
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--scale", "-1"]);
    assert_usage_error("--scale -1", &run, &["--scale", "-1"]);
}

#[test]
fn scale_that_builds_the_model_beyond_a_kilometre() {
    // inspect refuses what the main command refuses: it reports the built size.
    let dir = TempDir::new().unwrap();
    let model = good_model(&dir);
    let run = inspect(&model, &["--scale", "1e300"]);
    assert_usage_error(
        "--scale 1e300",
        &run,
        &["--scale", "1.000e300", "more than 1 km"],
    );
}

#[test]
fn planarity_tolerance_above_one() {
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--planarity-tol", "2"]);
    assert_usage_error("--planarity-tol 2", &run, &["--planarity-tol", "2"]);
}

#[test]
fn unknown_config_key() {
    let dir = TempDir::new().unwrap();
    let config = write(&dir, "unfold.toml", "size = \"4ft\"\nsheeet = \"A2\"\n");
    let config_arg = config.display().to_string();
    let run = inspect(&good_model(&dir), &["--config", &config_arg]);
    assert_usage_error("unknown config key", &run, &["sheeet", &config_arg]);
}

#[test]
fn bad_option_wins_over_json() {
    // --json changes stdout, not the error path.
    let dir = TempDir::new().unwrap();
    let run = inspect(&good_model(&dir), &["--json", "--size", "4"]);
    assert_usage_error("--json --size 4", &run, &["no unit"]);
    let bad = write(&dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 2 3\n");
    let run = inspect(&bad, &["--json"]);
    assert_error("--json on index 0", &run, 3, &bad, Some(4), &["index 0"]);
}

#[test]
fn nesting_options_out_of_range_are_usage_errors_and_write_nothing() {
    let dir = TempDir::new().unwrap();
    let model = good_model(&dir);
    let out = dir.path().join("out");
    for (args, says) in [
        (&["--time-limit", "1e300"][..], "--time-limit"),
        (&["--time-limit", "0"], "--time-limit"),
        (&["--time-limit=-2"], "--time-limit"),
        (&["--time-limit", "nan"], "--time-limit"),
        (&["--effort", "0"], "--effort"),
        (&["--effort", "101"], "--effort"),
    ] {
        let run = finish(
            unfold_command()
                .arg(&model)
                .args(["--size", "100mm", "--out"])
                .arg(&out)
                .args(args),
        );
        assert_usage_error(&format!("{args:?}"), &run, &[says]);
        assert!(!out.exists(), "{args:?}: the output folder was created");
    }
}

// ---------------------------------------------------------------------------------------
// A good model
// ---------------------------------------------------------------------------------------

#[test]
fn json_of_a_good_model() {
    let dir = TempDir::new().unwrap();
    let path = good_model(&dir);
    let run = inspect(&path, &["--json"]);
    assert_eq!(run.code, Some(0), "--json: stderr: {}", run.stderr);
    assert!(run.stderr.is_empty(), "--json: stderr: {}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(&run.stdout).expect("valid JSON");
    assert_eq!(json["input"]["vertices"], 8, "{json}");
    assert_eq!(json["input"]["faces"], 6, "{json}");
    assert_eq!(json["mesh"]["vertices"], 8, "{json}");
    assert_eq!(json["mesh"]["genus"], 0, "{json}");
    assert_eq!(json["format"], "obj", "{json}");
    assert_eq!(json["notes"], serde_json::json!([]), "{json}");
}
