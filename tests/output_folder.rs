//! The output folder through the real binary: a folder holding files unfold did not
//! write is refused (exit 2) and left byte-identical; a folder of an earlier run is
//! replaced whole; `--force` writes into a folder while keeping every foreign file; the
//! home folder (a temporary `HOME`) is never emptied; the model is never replaced; a
//! file in the way of `--out` is named.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tempfile::TempDir;

use common::build::{
    assert_refusal, entry_names, finish, model, read_manifest, unfold_command, Run,
};

/// Every entry under `root` (files with their bytes, folders and links marked), by
/// path relative to `root`.
fn tree(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut found = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let entry = entry.unwrap();
            let path = entry.path();
            let rel = path.strip_prefix(root).unwrap().to_path_buf();
            let kind = entry.file_type().unwrap();
            if kind.is_symlink() {
                let target = std::fs::read_link(&path).unwrap();
                found.insert(rel, format!("link -> {}", target.display()).into_bytes());
            } else if kind.is_dir() {
                found.insert(rel, b"folder".to_vec());
                stack.push(path);
            } else {
                found.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    found
}

/// Every entry of `kept` is in `after` with the same bytes.
fn assert_kept(kept: &BTreeMap<PathBuf, Vec<u8>>, after: &BTreeMap<PathBuf, Vec<u8>>) {
    for (path, bytes) in kept {
        assert_eq!(after.get(path), Some(bytes), "{} changed", path.display());
    }
}

/// Names of the entries directly in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    entry_names(dir).into_iter().collect()
}

/// A folder holding a model, a document, a dotfile and a subfolder with a file.
fn user_folder(root: &Path) -> PathBuf {
    let dir = root.join("work");
    std::fs::create_dir_all(dir.join("drawings")).unwrap();
    std::fs::copy(model("tetrahedron"), dir.join("tetrahedron.obj")).unwrap();
    std::fs::write(dir.join("notes.txt"), "the client's brief\n").unwrap();
    std::fs::write(dir.join(".settings"), "hidden=1\n").unwrap();
    std::fs::write(dir.join("drawings/plan.svg"), "<svg/>\n").unwrap();
    dir
}

fn build(model: &Path, out: &Path, extra: &[&str]) -> Run {
    finish(
        unfold_command()
            .arg(model)
            .args(["--size", "300mm", "--quiet", "--out"])
            .arg(out)
            .args(extra),
    )
}

/// A clean refusal: exit 2, nothing on stdout, one error line holding every fragment.
fn assert_refused(case: &str, run: &Run, says: &[&str]) {
    assert_refusal(case, run, 2, says);
    assert_eq!(run.stderr.lines().count(), 1, "{case}: {}", run.stderr);
}

/// The manifest's `files`, in its order.
fn listed_files(out: &Path) -> Vec<String> {
    read_manifest(out)["files"]
        .as_array()
        .expect("files in the manifest")
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_folder_of_foreign_files_is_refused_and_left_as_it_was() {
    let tmp = TempDir::new().unwrap();
    let dir = user_folder(tmp.path());
    let before = tree(tmp.path());
    for (case, out) in [
        ("--out the folder", dir.clone()),
        ("--out the folder/", dir.join("")),
        ("--out the folder/.", dir.join(".")),
    ] {
        let run = build(&dir.join("tetrahedron.obj"), &out, &[]);
        assert_refused(
            case,
            &run,
            &[
                ".settings",
                "unfold did not write",
                "Choose another --out",
                "--force",
            ],
        );
        assert_eq!(tree(tmp.path()), before, "{case}: something changed");
    }
    // Run from inside the folder, as a user would: `--out .`.
    let run = finish(unfold_command().current_dir(&dir).args([
        "tetrahedron.obj",
        "--size",
        "300mm",
        "--out",
        ".",
    ]));
    assert_refused("--out .", &run, &["unfold did not write"]);
    assert_eq!(tree(tmp.path()), before, "--out .: something changed");
}

#[test]
fn a_foreign_manifest_does_not_make_a_folder_ours() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("manifest.json"), "{\"name\": \"my-web-app\"}\n").unwrap();
    std::fs::write(out.join("index.html"), "<html></html>\n").unwrap();
    let before = tree(tmp.path());
    let run = build(&model("tetrahedron"), &out, &[]);
    assert_refused("foreign manifest", &run, &["unfold did not write"]);
    assert_eq!(tree(tmp.path()), before);
    let run = build(&model("tetrahedron"), &out, &["--force"]);
    assert_refused(
        "foreign manifest, --force",
        &run,
        &["manifest.json", "not written by unfold"],
    );
    assert_eq!(tree(tmp.path()), before);
}

#[test]
fn an_earlier_runs_folder_is_replaced_whole() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let model = model("tetrahedron");
    let first = build(&model, &out, &["--format", "svg,dxf"]);
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    let listed = listed_files(&out);
    let mut sorted = listed.clone();
    sorted.sort();
    assert_eq!(sorted, names(&out), "the manifest lists every file written");
    assert_eq!(listed.last().map(String::as_str), Some("manifest.json"));
    assert!(listed.iter().any(|f| f.ends_with(".dxf")));

    // The second run writes SVG only: the earlier DXF files go with the old folder.
    let second = build(&model, &out, &[]);
    assert_eq!(second.code, Some(0), "{}", second.stderr);
    let now = names(&out);
    assert!(now.iter().all(|f| !f.ends_with(".dxf")), "{now:?}");
    let mut listed = listed_files(&out);
    listed.sort();
    assert_eq!(listed, now);
    // Nothing is left beside the folder: no staging or old folder.
    assert_eq!(names(tmp.path()), vec!["out".to_string()]);

    // An empty folder is used as it is.
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let run = build(&model, &empty, &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(names(&empty).contains(&"manifest.json".to_string()));
}

#[test]
fn force_keeps_every_foreign_file() {
    let tmp = TempDir::new().unwrap();
    let dir = user_folder(tmp.path());
    let foreign = tree(&dir);
    let model = dir.join("tetrahedron.obj");
    let run = build(&model, &dir, &["--force", "--format", "svg,dxf"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_kept(&foreign, &tree(&dir));
    let first_output: Vec<String> = names(&dir)
        .into_iter()
        .filter(|n| !foreign.contains_key(Path::new(n)))
        .collect();
    assert!(first_output.contains(&"manifest.json".to_string()));
    assert!(first_output.iter().any(|n| n.ends_with(".dxf")));

    // Again with SVG only: the earlier run's DXF files go, every foreign file stays.
    let run = build(&model, &dir, &["--force"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_kept(&foreign, &tree(&dir));
    assert!(
        names(&dir).iter().all(|n| !n.ends_with(".dxf")),
        "{:?}",
        names(&dir)
    );
    // Without --force the folder is still refused: it holds foreign files.
    let before = tree(tmp.path());
    let run = build(&model, &dir, &[]);
    assert_refused(
        "no --force",
        &run,
        &[".settings, drawings, notes.txt", "--force"],
    );
    assert_eq!(tree(tmp.path()), before);
}

#[test]
fn force_never_overwrites_a_foreign_file_of_an_output_name() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(
        out.join("tetrahedron-01.svg"),
        "<svg>my own drawing</svg>\n",
    )
    .unwrap();
    let before = tree(tmp.path());
    let run = build(&model("tetrahedron"), &out, &["--force"]);
    assert_refused(
        "same name",
        &run,
        &["tetrahedron-01.svg", "was not written by unfold"],
    );
    assert_eq!(tree(tmp.path()), before);
}

#[test]
fn the_home_folder_is_never_emptied() {
    let home = TempDir::new().unwrap();
    std::fs::write(home.path().join(".bashrc"), "export EDITOR=vi\n").unwrap();
    std::fs::create_dir(home.path().join("Documents")).unwrap();
    std::fs::write(
        home.path().join("Documents/thesis.tex"),
        "\\begin{document}\n",
    )
    .unwrap();
    let before = tree(home.path());
    let home_run = |out: &str, extra: &[&str]| {
        finish(
            unfold_command()
                .env("HOME", home.path())
                .current_dir(home.path())
                .arg(model("tetrahedron"))
                .args(["--size", "300mm", "--quiet", "--out", out])
                .args(extra),
        )
    };
    // `~` as a config file or a quoting shell passes it, and the path a shell expands.
    let expanded = format!("{}/", home.path().display());
    for out in ["~", "~/", expanded.as_str()] {
        let run = home_run(out, &[]);
        assert_refused(out, &run, &["unfold did not write", "--force"]);
        assert_eq!(
            tree(home.path()),
            before,
            "--out {out}: the home folder changed"
        );
    }
    // `~/build` is a new folder in the home folder, beside everything else.
    let run = home_run("~/build", &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(home.path().join("build/manifest.json").is_file());
    assert!(!home.path().join("~").exists());
    assert_kept(&before, &tree(home.path()));
}

#[test]
fn the_model_is_never_replaced() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(&model("tetrahedron"), &out, &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // The assembled model of that run, given as the model of a run into its folder.
    let assembled = out.join("tetrahedron-assembled.obj");
    let before = tree(tmp.path());
    for extra in [&[][..], &["--force"][..]] {
        let run = build(&assembled, &out, extra);
        assert_refused(
            "assembled model",
            &run,
            &[
                "the model tetrahedron-assembled.obj",
                "copy the model elsewhere",
            ],
        );
        assert_eq!(tree(tmp.path()), before);
    }
}

#[test]
fn a_file_in_the_way_of_out_is_named() {
    let tmp = TempDir::new().unwrap();
    let file = tmp.path().join("afile");
    std::fs::write(&file, "not a folder\n").unwrap();
    let before = tree(tmp.path());
    let run = build(&model("tetrahedron"), &file, &[]);
    assert_refused(
        "--out afile",
        &run,
        &["afile", "a file of that name is in the way"],
    );
    let run = build(&model("tetrahedron"), &file.join("sub"), &[]);
    assert_refused(
        "--out afile/sub",
        &run,
        &[&format!("{} is a file, not a folder", file.display())],
    );
    assert_eq!(tree(tmp.path()), before);
}

#[test]
fn an_older_manifest_does_not_make_the_users_dxf_files_ours() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(&model("tetrahedron"), &out, &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // A manifest of an older unfold lists only the sheets' SVG files; older runs wrote
    // no DXF by default, so a DXF beside a sheet may be the user's own.
    let path = out.join("manifest.json");
    let mut manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    manifest.as_object_mut().unwrap().remove("files");
    for sheet in manifest["sheets"].as_array_mut().unwrap() {
        let sheet = sheet.as_object_mut().unwrap();
        let svg = sheet.remove("files").unwrap()[0].clone();
        sheet.insert("file".into(), svg);
    }
    std::fs::write(&path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    // Nor did they draw an assembly map or a preview page.
    std::fs::remove_file(out.join("tetrahedron-map.svg")).unwrap();
    std::fs::remove_file(out.join("tetrahedron.html")).unwrap();
    std::fs::write(out.join("tetrahedron-01.dxf"), "my own drawing\n").unwrap();
    let before = tree(tmp.path());
    let run = build(&model("tetrahedron"), &out, &[]);
    assert_refused(
        "user's DXF",
        &run,
        &["tetrahedron-01.dxf", "unfold did not write"],
    );
    assert_eq!(tree(tmp.path()), before);
    // Without it the older folder is unfold's (its assembled model carries unfold's
    // first line) and is replaced.
    std::fs::remove_file(out.join("tetrahedron-01.dxf")).unwrap();
    let run = build(&model("tetrahedron"), &out, &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(read_manifest(&out)["files"].is_array());
}

#[cfg(unix)]
#[test]
fn a_replaced_folder_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o2750)).unwrap();
    for _ in 0..2 {
        let run = build(&model("tetrahedron"), &out, &[]);
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o2750, "mode {mode:o}");
    }
}

#[test]
fn force_with_a_case_variant_of_an_output_name_is_refused() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("Tetrahedron-01.SVG"), "<svg>mine</svg>\n").unwrap();
    let before = tree(tmp.path());
    let run = build(&model("tetrahedron"), &out, &["--force"]);
    assert_refused("case variant", &run, &["tetrahedron-01.svg"]);
    assert_eq!(tree(tmp.path()), before);
}
