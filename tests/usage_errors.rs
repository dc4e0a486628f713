//! A user's ordinary mistakes on the command line and in the config file, through the
//! real binary: each is refused with exit 2 and a message that keeps the help the
//! parser had (the similar option, the values an option takes, the missing argument),
//! or for the config file the line and column, the key, the nearest valid key and what
//! the value should look like. Repeated options: the last one wins.

use crate::common;

use std::path::Path;

use tempfile::TempDir;

use common::build::{
    assert_refusal, entry_names, finish, model, read_manifest, unfold_command, Run,
};

fn run_in(dir: &Path, args: &[&str]) -> Run {
    finish(unfold_command().current_dir(dir).args(args))
}

/// Exit 2, nothing on stdout, `unfold: error: ` first, every fragment in the message.
fn assert_usage(case: &str, run: &Run, says: &[&str]) {
    assert_refusal(case, run, 2, says);
}

/// A folder holding the tetrahedron; returns it and the model's path.
fn sandbox() -> (TempDir, String) {
    let dir = TempDir::new().unwrap();
    std::fs::copy(model("tetrahedron"), dir.path().join("tetrahedron.obj")).unwrap();
    (dir, "tetrahedron.obj".to_string())
}

fn entries(dir: &Path) -> Vec<String> {
    entry_names(dir).into_iter().collect()
}

#[test]
fn parser_errors_keep_the_parsers_help() {
    let (dir, model) = sandbox();
    let before = entries(dir.path());
    let cases: &[(&str, Vec<&str>, &[&str])] = &[
        (
            "misspelt option",
            vec![&model, "--szie", "4ft"],
            &[
                "unexpected argument '--szie'",
                "a similar argument exists: '--size'",
            ],
        ),
        (
            "unknown value",
            vec![&model, "--scheme", "quadedge"],
            &[
                "invalid value 'quadedge' for '--scheme <SCHEME>'",
                "possible values: half-edge, quad-edge, winged-edge, woven",
                "a similar value exists: 'quad-edge'",
            ],
        ),
        (
            "unknown nester",
            vec![&model, "--nester", "tight"],
            &["possible values: true-shape, shelf"],
        ),
        (
            "a length split from its unit",
            vec![&model, "--size", "4", "ft"],
            &["--size 4 ft: write a length without a space before its unit: --size 4ft"],
        ),
        (
            "missing model",
            vec!["--size", "4ft"],
            &["required arguments were not provided", "<MODEL>", "Usage:"],
        ),
        (
            "inspect, misspelt option",
            vec!["inspect", &model, "--target-edgs", "600"],
            &["a similar argument exists: '--target-edges'"],
        ),
        (
            "inspect with a budget only a build can find",
            vec!["inspect", &model, "--target-edges", "auto"],
            &[
                "--target-edges auto: the budget is found by a build",
                "give inspect a number",
            ],
        ),
        (
            "a budget that is neither a number nor auto",
            vec![&model, "--target-edges", "lots"],
            &["'lots' is not a number of edges or auto (like 600 or auto)"],
        ),
        (
            "a number that is not one",
            vec![&model, "--target-faces", "lots"],
            &[
                "invalid value 'lots' for '--target-faces <N>'",
                "invalid digit",
            ],
        ),
    ];
    for (case, args, says) in cases {
        let run = run_in(dir.path(), args);
        assert_usage(case, &run, says);
    }
    assert_eq!(entries(dir.path()), before, "something was written");
}

#[test]
fn a_repeated_option_takes_its_last_value() {
    let (dir, model) = sandbox();
    let run = run_in(
        dir.path(),
        &[
            &model,
            "--size",
            "4ft",
            "--size",
            "300mm",
            "--quiet",
            "--quiet",
            "--scheme",
            "quad-edge",
            "--scheme",
            "half-edge",
            "--out",
            "a",
            "--out",
            "b",
        ],
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(run.stderr.is_empty(), "--quiet twice: {}", run.stderr);
    assert!(!dir.path().join("a").exists(), "the first --out was used");
    let manifest = read_manifest(&dir.path().join("b"));
    assert_eq!(manifest["scheme"]["name"], "half-edge");
    // The project's tetrahedron spans 100 model units: the last --size makes that
    // 300 mm.
    let per_unit = manifest["scheme"]["params"]["mm_per_model_unit"]
        .as_f64()
        .unwrap();
    assert!((per_unit - 3.0).abs() < 1e-9, "{per_unit} mm per unit");
}

/// Writes `text` as `unfold.toml` and runs the tetrahedron with it.
fn with_config(text: &str, extra: &[&str]) -> (TempDir, Run) {
    let (dir, model) = sandbox();
    std::fs::write(dir.path().join("unfold.toml"), text).unwrap();
    let mut args = vec![model.as_str(), "--config", "unfold.toml"];
    args.extend(extra);
    let run = run_in(dir.path(), &args);
    (dir, run)
}

#[test]
fn config_errors_name_the_line_the_key_and_the_fix() {
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "key with underscores",
            "sheet = \"18x24in\"\ntarget_edges = 900\n",
            &[
                "unfold.toml:2:1:",
                "unknown key 'target_edges'",
                "did you mean 'target-edges'?",
            ],
        ),
        (
            "misspelt key",
            "# a comment\n\n  sheeet = \"A2\"\n",
            &[
                "unfold.toml:3:3:",
                "unknown key 'sheeet'",
                "did you mean 'sheet'?",
            ],
        ),
        (
            "a length without its unit",
            "sheet = \"A2\"\nsize = 3\n",
            &[
                "unfold.toml:2:8:",
                "size = 3",
                "a length needs a unit",
                "size = \"3mm\"",
            ],
        ),
        (
            "a length string without its unit",
            "size = \"3\"\n",
            &["unfold.toml:1:8:", "'3' has no unit"],
        ),
        (
            "an unknown scheme",
            "sheet = \"A2\"\nscheme = \"quadedge\"\n",
            &[
                "unfold.toml:2:10:",
                "scheme = \"quadedge\"",
                "half-edge, quad-edge, winged-edge, woven",
            ],
        ),
        (
            "a count in quotes",
            "holes = \"two\"\n",
            &["unfold.toml:1:9:", "a whole number"],
        ),
        (
            "a switch as text",
            "quiet = \"yes\"\n",
            &["unfold.toml:1:9:", "quiet = true or quiet = false"],
        ),
        (
            "a sheet without a unit",
            "sheet = \"18x24\"\n",
            &["unfold.toml:1:9:", "not a sheet size"],
        ),
        (
            "a sheet without quotes",
            "sheet = 18x24in\n",
            &[
                "unfold.toml:1:9:",
                "sheet = 18x24in",
                "write sheet = \"18x24in\"",
            ],
        ),
        (
            "a length without quotes",
            "scheme = \"net\"\nsize = 4ft # tall\n",
            &["unfold.toml:2:", "size = 4ft", "write size = \"4ft\""],
        ),
        (
            "TOML syntax",
            "sheet = [18\n",
            &["unfold.toml:1:", "not valid TOML"],
        ),
        (
            "the first mistake in the file is reported",
            "size = 3\nholes = \"two\"\n",
            &["unfold.toml:1:8:", "size = 3"],
        ),
    ];
    for (case, text, says) in cases {
        let (dir, run) = with_config(text, &[]);
        assert_usage(case, &run, says);
        assert_eq!(
            run.stderr.lines().count(),
            1,
            "{case}: not one line: {}",
            run.stderr
        );
        assert_eq!(
            entries(dir.path()),
            vec!["tetrahedron.obj".to_string(), "unfold.toml".to_string()],
            "{case}: something was written"
        );
    }
}

#[test]
fn every_option_is_a_config_key() {
    // quiet and json are options, so they are keys; the command line still wins.
    let (dir, run) = with_config(
        "quiet = true\njson = true\nsize = \"300mm\"\nout = \"built\"\nforce = false\n",
        &["--size", "200mm"],
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(run.stderr.is_empty(), "quiet = true: {}", run.stderr);
    let summary: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(summary["tool"]["name"], "unfold", "json = true");
    assert!(dir.path().join("built/manifest.json").is_file());
    // Every long option of --help is accepted as a key (the values come from the
    // option's own definition; a switch is true or false).
    let help = run_in(dir.path(), &["--help"]).stdout;
    let mut checked = 0;
    for line in help.lines() {
        let Some(at) = line.find("--") else { continue };
        let option: String = line[at + 2..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect();
        if option.is_empty() || ["help", "version", "config"].contains(&option.as_str()) {
            continue;
        }
        // An inline table is never a valid value: the key is known, so the message
        // is about the value, not the key. (`layers` is also the table of laser
        // kinds, so a string is its wrong value.)
        let wrong = if option == "layers" { "\"x\"" } else { "{}" };
        let (_, run) = with_config(&format!("{option} = {wrong}\n"), &[]);
        let said = if option == "layers" {
            "layers = 2".to_string()
        } else {
            format!("{option} = {{}}")
        };
        assert_usage(&option, &run, &[&said]);
        assert!(
            !run.stderr.contains("unknown key"),
            "{option}: {}",
            run.stderr
        );
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} options read off --help");
}

#[test]
fn a_folder_as_the_model_is_named_with_the_models_in_it() {
    let (dir, _) = sandbox();
    let before = entries(dir.path());
    for args in [vec!["."], vec!["inspect", "."]] {
        let run = run_in(dir.path(), &args);
        assert_eq!(run.code, Some(3), "{args:?}: {}", run.stderr);
        assert!(
            run.stderr.contains("is a directory, not a model file")
                && run.stderr.contains("tetrahedron.obj"),
            "{args:?}: {}",
            run.stderr
        );
    }
    assert_eq!(entries(dir.path()), before);
}
