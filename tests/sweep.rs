//! No panic, ever: every project and shared model with every scheme, with and without
//! a kerf and mirroring, ends in a build or in a refusal with its message (never exit
//! 101); and a panic, injected on purpose, is one line with exit code 1 and leaves the
//! output folder as it was.

use crate::common;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use common::build::*;
use tempfile::TempDir;

const SCHEMES: [&str; 6] = [
    "half-edge",
    "quad-edge",
    "winged-edge",
    "woven",
    "net",
    "strip",
];
/// Each kerf at least once, and mirroring both without a kerf and with the largest one
/// (mirroring reverses the outlines the kerf offsets). Each model and scheme runs one of
/// them, the next on the next model: every scheme meets every case on a quarter of the
/// models, in a quarter of the time.
const KERF_MIRROR: [(&str, bool); 4] = [
    ("0mm", false),
    ("0.3mm", true),
    ("0mm", true),
    ("0.1mm", false),
];

/// Shared models larger than this many edges are simplified once, before the sweep,
/// so that each run takes a second or two.
const SWEEP_EDGES: usize = 100;

/// `model` as the sweep builds it: itself when small, else simplified to about
/// [`SWEEP_EDGES`] edges (or the first of a few larger budgets that works).
fn sweep_model(model: &Path, dir: &Path) -> PathBuf {
    let out = dir.join("unused");
    let plain = job("half-edge", model, "1ft", 0, &out);
    let loaded = unfold::run::load(&plain).expect("model loads");
    let edges = loaded.prepared.mesh.edge_count();
    if edges <= SWEEP_EDGES {
        return model.to_path_buf();
    }
    for budget in [1, 2, 4, 8].map(|k| k * SWEEP_EDGES) {
        let mut options = options("half-edge", "1ft", 0, &out);
        options.model.target_edges = Some(unfold::config::TargetEdges::Count(budget));
        let job = resolve(options, model);
        let prepared = unfold::run::load(&job).and_then(|l| unfold::run::prepare(&job, l));
        if let Ok(prepared) = prepared {
            let name = model.file_stem().unwrap().to_string_lossy().into_owned();
            let path = dir.join(format!("{name}-{budget}.obj"));
            write_obj(&prepared.scheme_mesh.mesh, &path);
            return path;
        }
    }
    panic!(
        "{}: no budget up to {} edges works",
        model.display(),
        8 * SWEEP_EDGES
    );
}

#[test]
fn every_model_scheme_kerf_and_mirror_builds_or_refuses_without_a_panic() {
    let models: Vec<PathBuf> = std::fs::read_dir(crate_dir().join("models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    sweep(models, &TempDir::new().unwrap());
}

/// The same on the shared models, a test of its own so that it runs beside the
/// project's models (each takes both cores only part of the time).
#[test]
fn every_shared_model_scheme_kerf_and_mirror_builds_or_refuses_without_a_panic() {
    let tmp = TempDir::new().unwrap();
    let Some(dir) = shared_models("every_shared_model_scheme_kerf_and_mirror_builds") else {
        return;
    };
    let shared = common::build::shared_model_files(&dir);
    sweep(
        shared.iter().map(|m| sweep_model(m, tmp.path())).collect(),
        &tmp,
    );
}

/// Builds every model of `models` with every scheme, each with one of the kerf and
/// mirror cases in turn, two runs at a time; checks that none panics and that most
/// build.
fn sweep(mut models: Vec<PathBuf>, tmp: &TempDir) {
    models.sort();
    let mut cases = Vec::new();
    for (m, model) in models.iter().enumerate() {
        for (s, scheme) in SCHEMES.iter().enumerate() {
            let (kerf, mirror) = KERF_MIRROR[(m + s) % KERF_MIRROR.len()];
            cases.push((model.clone(), scheme, kerf, mirror));
        }
    }
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some((model, scheme, kerf, mirror)) = cases.get(k) else {
                    break;
                };
                let out = tmp.path().join(format!("run{k}"));
                let mut cmd = unfold_command();
                cmd.arg(model)
                    .args(["--scheme", scheme, "--size", "1ft", "--kerf", kerf])
                    .args(["--effort", "1", "--format", "svg", "--quiet"])
                    // Every stage is to run, on models too detailed for 1 ft too.
                    .arg("--build-anyway")
                    .arg("--out")
                    .arg(&out)
                    .env_remove("RUST_BACKTRACE");
                if *mirror {
                    cmd.arg("--mirror");
                }
                // Strips on faceted models: a bound the sweep reaches in a second.
                if **scheme == "strip" {
                    cmd.args(["--max-deviation", "5%"]);
                }
                let started = std::time::Instant::now();
                let run = finish(&mut cmd);
                let took = started.elapsed().as_secs_f64();
                let _ = std::fs::remove_dir_all(&out);
                let case = format!(
                    "{} --scheme {scheme} --kerf {kerf}{}",
                    model.file_name().unwrap().to_string_lossy(),
                    if *mirror { " --mirror" } else { "" }
                );
                results.lock().unwrap().push((case, run, took));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    // Slowest first, to see where the sweep's time goes.
    results.sort_by(|a, b| b.2.total_cmp(&a.2));
    for (case, _, took) in results.iter().take(5) {
        eprintln!("  {took:.1} s: {case}");
    }
    let mut built = 0;
    let mut refused = std::collections::BTreeSet::new();
    for (case, run, _) in &results {
        assert_ne!(run.code, Some(101), "{case} panicked:\n{}", run.stderr);
        assert!(
            !run.stderr.contains("panicked") && !run.stderr.contains("internal error"),
            "{case}:\n{}",
            run.stderr
        );
        match run.code {
            Some(0) => built += 1,
            Some(code @ 1..=3) => {
                let first = run.stderr.lines().next().unwrap_or_default();
                assert!(
                    first.starts_with("unfold: error: ") && first.len() > 30,
                    "{case}: exit {code} without a message:\n{}",
                    run.stderr
                );
                refused.insert(first.to_string());
            }
            other => panic!("{case}: exit {other:?}:\n{}", run.stderr),
        }
    }
    eprintln!(
        "{} runs: {built} built, {} refused with a message:",
        results.len(),
        results.len() - built
    );
    for line in &refused {
        eprintln!("  {line}");
    }
    // Refusals are for what cannot be built (a woven scheme on an open mesh, a panel
    // larger than the sheet): most of the sweep builds.
    assert!(
        built * 10 >= results.len() * 8,
        "{built} of {}",
        results.len()
    );
}

#[test]
fn a_panic_is_one_line_with_exit_code_1_and_an_untouched_output_folder() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    for (stage, says) in [
        ("unrolling", "internal error while unrolling the panels"),
        ("nesting", "internal error while nesting 6 panels on sheets"),
    ] {
        let run = finish(
            unfold_command()
                .arg(model("hexahedron"))
                .args(["--size", "6in", "--force", "--out"])
                .arg(&out)
                .env("UNFOLD_INJECT_PANIC", stage)
                .env_remove("RUST_BACKTRACE"),
        );
        assert_refusal(stage, &run, 1, &[says, "(panel F0)", "please report"]);
        assert_eq!(run.stderr.lines().count(), 1, "{stage}: {}", run.stderr);
        assert!(!run.stderr.contains("backtrace"), "{stage}: {}", run.stderr);
        assert_eq!(
            entry_names(&out),
            ["notes.txt".to_string()].into_iter().collect(),
            "{stage}: the output folder is as it was"
        );
        assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
    }
    // Asked for, the backtrace is there too.
    let run = finish(
        unfold_command()
            .arg(model("hexahedron"))
            .args(["--size", "6in", "--out"])
            .arg(tmp.path().join("other"))
            .env("UNFOLD_INJECT_PANIC", "nesting")
            .env("RUST_BACKTRACE", "1"),
    );
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("panicked at"), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("unfold: error: internal error while nesting"),
        "{}",
        run.stderr
    );
    assert!(!tmp.path().join("other").exists());
}
