//! Progress on stderr: shown under a terminal, never in a log. `script` (util-linux)
//! gives the run a terminal; without it the terminal half is skipped with a message.

use crate::common;

use std::process::Command;

use tempfile::TempDir;

use common::build::*;

#[test]
fn progress_shows_on_a_terminal_and_never_in_a_log() {
    let tmp = TempDir::new().unwrap();
    let model = model("genus2");
    let out = tmp.path().join("log");
    // stderr is a pipe here, as under Make or CI.
    let (_, run) = build_run("half-edge", &model, "300mm", &out, &[]);
    for sign in ["nesting", "\r", "\u{1b}["] {
        assert!(
            !run.stderr.contains(sign),
            "{sign:?} in a log:\n{}",
            run.stderr
        );
    }

    // stderr a file, as `unfold … 2> build.log`.
    let log = tmp.path().join("build.log");
    let run = unfold_command()
        .arg(&model)
        .args(["--size", "300mm", "--out"])
        .arg(tmp.path().join("file"))
        .stderr(std::fs::File::create(&log).unwrap())
        .status()
        .unwrap();
    assert!(run.success());
    let logged = std::fs::read_to_string(&log).unwrap();
    assert!(logged.contains("wrote 6 files"), "{logged}");
    for sign in ["nesting", "\r", "\u{1b}["] {
        assert!(!logged.contains(sign), "{sign:?} in a file:\n{logged}");
    }

    let has_script = Command::new("script")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_script {
        eprintln!("progress: `script` is missing; the terminal half is skipped");
        return;
    }
    let out = tmp.path().join("terminal");
    let line = format!(
        "{} {} --size 300mm --out {}",
        env!("CARGO_BIN_EXE_unfold"),
        model.display(),
        out.display()
    );
    let run = Command::new("script")
        .args(["-qec", &line, "/dev/null"])
        .output()
        .expect("script runs");
    assert!(run.status.success());
    let shown = String::from_utf8_lossy(&run.stdout);
    assert!(shown.contains("nesting 50 panels on sheets"), "{shown}");
    // The nest and the drawing have bars that fill.
    let percents: Vec<u32> = shown
        .split(" % (")
        .filter_map(|before| before.rsplit(']').next()?.trim().parse().ok())
        .collect();
    assert!(
        percents.len() >= 2 && percents.iter().any(|&p| p > 0),
        "{percents:?} in {shown}"
    );
    assert!(shown.contains("writing 2 sheets ["), "{shown}");
    // The report still follows, and the spinner is cleared before it.
    assert!(shown.contains("wrote 6 files"), "{shown}");
    // --quiet shows nothing, terminal or not.
    let quiet = Command::new("script")
        .args(["-qec", &format!("{line}-quiet --quiet"), "/dev/null"])
        .output()
        .expect("script runs");
    assert!(!String::from_utf8_lossy(&quiet.stdout).contains("nesting"));
}
