//! The checks of a build's size through the real binary: a forgotten `--size` on a
//! model in metres is refused at once with the units that would make sense; a model
//! small or large for the sheet warns (and `--strict` refuses, writing nothing); a
//! model too detailed for its size warns with a `--target-edges` value that, run, gives
//! panels that carry their ids.

use crate::common;

use std::path::Path;

use tempfile::TempDir;

use common::build::{
    assert_refusal, count, finish, model, number_after, read_manifest, shared_models,
    unfold_command, Run,
};

fn build(model: &Path, out: &Path, args: &[&str]) -> Run {
    finish(unfold_command().arg(model).arg("--out").arg(out).args(args))
}

/// The project's tetrahedron (100 units across) with every coordinate times `k`.
fn scaled_tetrahedron(dir: &Path, k: f64) -> std::path::PathBuf {
    let text = std::fs::read_to_string(model("tetrahedron")).unwrap();
    let scaled: String = text
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(coords) => {
                let xyz: Vec<String> = coords
                    .split_whitespace()
                    .map(|c| (c.parse::<f64>().unwrap() * k).to_string())
                    .collect();
                format!("v {}\n", xyz.join(" "))
            }
            None => format!("{line}\n"),
        })
        .collect();
    let path = dir.join("tetrahedron.obj");
    std::fs::write(&path, scaled).unwrap();
    path
}

/// Exit 2 with every fragment, and the output folder not written.
fn assert_refused(case: &str, run: &Run, out: &Path, says: &[&str]) {
    assert_refusal(case, run, 2, says);
    assert!(!out.exists(), "{case}: {} was written", out.display());
}

/// Runs the fix a refusal named, `repairs` then `--target-edges N` (N read from the
/// refusal after them), on top of `args`, and asserts that it builds with no warning.
/// Returns the run.
fn assert_named_fix_builds_clean(
    model: &Path,
    out: &Path,
    args: &[&str],
    refusal: &Run,
    repairs: &[&str],
) -> Run {
    let named = format!(
        "{}--target-edges ",
        repairs.iter().map(|r| format!("{r} ")).collect::<String>()
    );
    let budget = number_after(&refusal.stderr, &named)
        .unwrap_or_else(|| panic!("no `{named}N` in: {}", refusal.stderr))
        .to_string();
    let mut fixed = args.to_vec();
    fixed.extend(repairs);
    fixed.extend(["--target-edges", &budget]);
    let run = build(model, out, &fixed);
    assert_eq!(run.code, Some(0), "at {budget}: {}", run.stderr);
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
    run
}

#[test]
fn a_model_in_metres_without_size_is_refused_with_the_units_that_fit() {
    let tmp = TempDir::new().unwrap();
    // 20 cm across in metres: read as millimetres it is 0.2 mm, edges of 0.28 mm.
    let metres = scaled_tetrahedron(tmp.path(), 0.002);
    let out = tmp.path().join("out");
    let run = build(&metres, &out, &[]);
    assert_refused(
        "tetrahedron in metres",
        &run,
        &out,
        &[
            "too small for any laser part to be cut",
            "no --size was given",
            "--size 4ft",
            "--units m builds it 20cm",
        ],
    );
    // With the units it names, the same model builds.
    let run = build(&metres, &out, &["--units", "m", "--quiet"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
}

#[test]
fn the_forgotten_size_of_shared_scans_is_refused_at_once() {
    let Some(shared) = shared_models("the_forgotten_size_of_shared_scans_is_refused_at_once")
    else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(&shared.join("stanford-bunny.obj"), &out, &[]);
    assert_refused(
        "bunny without --size",
        &run,
        &out,
        &[
            "0.156mm across",
            "no --size was given",
            "--units m builds it 15.6cm",
        ],
    );
    let run = build(
        &shared.join("horse_quad.obj"),
        &out,
        &["--scheme", "quad-edge"],
    );
    assert_refused("horse_quad without --size", &run, &out, &["--size 4ft"]);
}

#[test]
fn a_model_small_for_the_sheet_warns_and_strict_refuses() {
    let tmp = TempDir::new().unwrap();
    // 30 mm across on an 18x24in sheet, no --size: a warning, then the build.
    let small = scaled_tetrahedron(tmp.path(), 0.3);
    let out = tmp.path().join("out");
    let run = build(&small, &out, &["--strict"]);
    assert_refused(
        "--strict",
        &run,
        &out,
        &[
            "is built only 30mm across",
            "--size 4ft",
            "refused by --strict",
        ],
    );
    let run = build(&small, &out, &[]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr.starts_with("unfold: warning: ")
            && run.stderr.contains("is built only 30mm across"),
        "{}",
        run.stderr
    );
    let manifest = read_manifest(&out);
    let warnings = manifest["warnings"]
        .as_array()
        .expect("warnings in the manifest");
    assert!(warnings[0].as_str().unwrap().contains("30mm across"));
    // --quiet silences the warning on stderr, not in the manifest.
    let run = build(&small, &out, &["--quiet"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(run.stderr.is_empty(), "{}", run.stderr);
    assert!(read_manifest(&out)["warnings"].is_array());
}

#[test]
fn a_model_large_for_the_sheet_is_refused_under_strict() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(&model("tetrahedron"), &out, &["--size", "100m", "--strict"]);
    assert_refused(
        "100 m tetrahedron",
        &run,
        &out,
        &[
            "is built 100m across",
            "sheets of 18x24in",
            "it covers about 20)",
            "or use a larger --sheet",
            // The size was given: the fix is a smaller one.
            "give a smaller --size (at --size",
        ],
    );
    assert!(
        !run.stderr.contains("give the size to build"),
        "{}",
        run.stderr
    );
}

#[test]
fn a_model_too_detailed_for_quad_edge_panels_gets_a_budget_that_builds() {
    too_detailed_for_its_size_gets_a_budget_that_builds(
        "a_model_too_detailed_for_quad_edge_panels_gets_a_budget_that_builds",
        "quad-edge",
    );
}

/// The same with half-edge panels, a test of its own so that it runs beside quad-edge.
#[test]
fn a_model_too_detailed_for_half_edge_panels_gets_a_budget_that_builds() {
    too_detailed_for_its_size_gets_a_budget_that_builds(
        "a_model_too_detailed_for_half_edge_panels_gets_a_budget_that_builds",
        "half-edge",
    );
}

/// Spot at 3 ft in `scheme`: stopped naming a budget (the same on one thread), the
/// budget builds every id with no warning, `auto` picks it, `--build-anyway` warns.
fn too_detailed_for_its_size_gets_a_budget_that_builds(test: &str, scheme: &str) {
    let Some(shared) = shared_models(test) else {
        return;
    };
    let spot = shared.join("spot.obj");
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join(scheme);
    let args = ["--scheme", scheme, "--size", "3ft", "--effort", "1"];
    // Without a budget the build stops before the nest, naming one.
    let run = build(&spot, &out, &args);
    assert_refused(
        scheme,
        &run,
        &out,
        &[
            "too detailed for its size",
            "stopped before laying out the sheets (nothing written)",
            "--target-edges ",
            "--target-edges auto",
            "--build-anyway builds it as it is",
        ],
    );
    // The search runs two trials at a time; on one thread it names the same (the
    // search is the same code for every scheme: checked on one).
    if scheme == "quad-edge" {
        let one_thread = finish(
            unfold_command()
                .arg(&spot)
                .arg("--out")
                .arg(&out)
                .args(args)
                .env("RAYON_NUM_THREADS", "1"),
        );
        assert_eq!(one_thread.stderr, run.stderr, "{scheme} on one thread");
    }
    let budget_edges = number_after(&run.stderr, "--target-edges ").unwrap();
    let budget = budget_edges.to_string();
    assert!(
        budget_edges < 8784,
        "{scheme}: {budget_edges} edges suggested"
    );
    // The named budget, run, carries every panel's id, with no warning.
    let mut suggested = args.to_vec();
    suggested.extend(["--target-edges", &budget, "--strict", "--quiet"]);
    let run = build(&spot, &out, &suggested);
    assert_eq!(
        run.code,
        Some(0),
        "{scheme} at {budget} edges: {}",
        run.stderr
    );
    let manifest = read_manifest(&out);
    let panels = count(&manifest, "counts.panels");
    let ids_out = count(&manifest, "counts.panel_ids_left_out");
    assert_eq!(
        ids_out, 0,
        "{scheme} at {budget} edges: {ids_out} of {panels} panel ids left out"
    );
    assert!(manifest.get("warnings").is_none(), "{scheme}: {manifest}");

    // `--target-edges auto` builds at that budget and says so.
    let mut auto = args.to_vec();
    auto.extend(["--target-edges", "auto", "--force"]);
    let run = build(&spot, &out, &auto);
    assert_eq!(run.code, Some(0), "{scheme} auto: {}", run.stderr);
    assert!(
        !run.stderr.contains("warning:"),
        "{scheme} auto: {}",
        run.stderr
    );
    let said = format!("--target-edges auto: the model is too detailed for its size as it is, so it was simplified to {budget} edges");
    assert!(run.stderr.contains(&said), "{scheme} auto: {}", run.stderr);
    let manifest = read_manifest(&out);
    assert_eq!(count(&manifest, "counts.panel_ids_left_out"), 0);

    // `--build-anyway` builds the full model with the warning: the same code for
    // every scheme, checked on the one whose full build is the quicker.
    if scheme != "half-edge" {
        return;
    }
    let mut anyway = args.to_vec();
    anyway.extend(["--build-anyway", "--force", "--nester", "shelf"]);
    let run = build(&spot, &out, &anyway);
    assert_eq!(run.code, Some(0), "{scheme} anyway: {}", run.stderr);
    assert!(
        run.stderr
            .contains("warning: the model is too detailed for its size")
            && run.stderr.contains(&format!("--target-edges {budget}")),
        "{scheme} anyway: {}",
        run.stderr
    );
}

/// A model whose median edge is far below what the scheme's panels need stops before
/// the scheme makes a panel, even with a `--target-edges` the user chose, and `auto`
/// keeps a model that builds clean as it is.
#[test]
fn a_hopeless_budget_stops_and_auto_keeps_a_model_that_builds() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let genus2 = model("genus2");
    let run = build(
        &genus2,
        &out,
        &[
            "--scheme",
            "quad-edge",
            "--size",
            "40mm",
            "--target-edges",
            "100",
        ],
    );
    assert_refused(
        "genus2 at 40 mm",
        &run,
        &out,
        &[
            "too detailed for its size: its median edge would be",
            "--build-anyway",
        ],
    );
    let run = build(
        &genus2,
        &out,
        &["--size", "300mm", "--target-edges", "auto"],
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("--target-edges auto: the model builds as it is at this size"),
        "{}",
        run.stderr
    );
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
}

/// A panel larger than the usable sheet is a mistake in the options (exit 2), named
/// with its size and the fix, and nothing is written.
#[test]
fn a_panel_larger_than_the_sheet_is_a_usage_error() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(
        &model("tetrahedron"),
        &out,
        &["--size", "1m", "--sheet", "A5"],
    );
    assert_refused(
        "1 m tetrahedron on A5",
        &run,
        &out,
        &[
            "panel F",
            " mm and does not fit on the A5 sheet",
            "use a larger --sheet or a smaller --size",
        ],
    );
    // A woven ribbon whose every crossing is larger than the sheet: the same.
    let run = build(
        &model("hexahedron"),
        &out,
        &["--scheme", "woven", "--size", "400mm", "--sheet", "A5"],
    );
    assert_refused(
        "400 mm cube woven on A5",
        &run,
        &out,
        &[
            "one edge crossing of its ribbon is ",
            " mm across and does not fit the sheet; use a larger --sheet or a smaller --size",
        ],
    );
}

/// A flat model (every vertex on one plane) is named as such: its panels would lie
/// side by side with folds of nothing between them.
#[test]
fn a_flat_model_is_named_as_such() {
    let tmp = TempDir::new().unwrap();
    let obj = common::build::flat_grid_obj(3);
    let flat = tmp.path().join("flat.obj");
    std::fs::write(&flat, obj).unwrap();
    let out = tmp.path().join("out");
    let run = build(&flat, &out, &["--size", "300mm"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("flat.obj is flat: every vertex lies within 0 mm of one plane"),
        "{}",
        run.stderr
    );
    // A curved open model is not flat.
    let run = build(&model("open-grid"), &out, &["--size", "300mm", "--force"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains(" is flat"), "{}", run.stderr);
}

/// A new user's first build of a shared model, in every scheme, without a budget:
/// it builds with no warning, or it stops naming a budget that, run, builds with no
/// warning (scripts/first-build runs every shared model at 2 ft and 4 ft).
#[test]
fn a_first_build_builds_clean_or_names_a_budget_that_does() {
    let Some(shared) = shared_models("a_first_build_builds_clean_or_names_a_budget_that_does")
    else {
        return;
    };
    let spot = shared.join("spot.obj");
    let tmp = TempDir::new().unwrap();
    for scheme in ["half-edge", "quad-edge", "winged-edge", "woven", "net"] {
        let out = tmp.path().join(scheme);
        let args = ["--scheme", scheme, "--size", "2ft", "--nester", "shelf"];
        let run = build(&spot, &out, &args);
        if run.code == Some(0) {
            assert!(!run.stderr.contains("warning:"), "{scheme}: {}", run.stderr);
            continue;
        }
        assert_refused(
            scheme,
            &run,
            &out,
            &[
                "too detailed for its size",
                "stopped before laying out the sheets",
            ],
        );
        let budget = number_after(&run.stderr, "--target-edges ")
            .unwrap_or_else(|| panic!("{scheme}: no budget named: {}", run.stderr))
            .to_string();
        let mut suggested = args.to_vec();
        suggested.extend(["--target-edges", &budget]);
        let run = build(&spot, &out, &suggested);
        assert_eq!(run.code, Some(0), "{scheme} at {budget}: {}", run.stderr);
        assert!(
            !run.stderr.contains("warning:"),
            "{scheme} at {budget}: {}",
            run.stderr
        );
    }
}

/// An open dome of `n` × `n` quads (a height field over a square), as OBJ text.
fn open_dome(n: usize) -> String {
    let mut text = String::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (i as f64 / n as f64 - 0.5, j as f64 / n as f64 - 0.5);
            text += &format!("v {x} {y} {}\n", 0.5 - x * x - y * y);
        }
    }
    let at = |i: usize, j: usize| i * (n + 1) + j + 1;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            text += &format!("f {a} {b} {c} {d}\n");
        }
    }
    text
}

#[test]
fn a_scheme_that_cannot_build_the_shape_says_so_and_names_the_closed_fix() {
    // Open, and far too detailed for woven panels at 2 ft: the refusal names the
    // holes, and the budget that, tried with them closed, weaves it clean.
    let tmp = TempDir::new().unwrap();
    let dome = tmp.path().join("dome.obj");
    std::fs::write(&dome, open_dome(120)).unwrap();
    let out = tmp.path().join("out");
    let args = ["--scheme", "woven", "--size", "2ft"];
    let run = build(&dome, &out, &args);
    assert_refused(
        "open dome, woven",
        &run,
        &out,
        &[
            "needs a closed mesh and this one has 1 hole",
            "(--fill-holes)",
            "closed, it builds clean at fewer edges: try --fill-holes --target-edges ",
            "(or --fill-holes --target-edges auto)",
        ],
    );
    let shelf: Vec<&str> = args.iter().copied().chain(["--nester", "shelf"]).collect();
    assert_named_fix_builds_clean(&dome, &out, &shelf, &run, &["--fill-holes"]);
    // The same dome with the half-edge scheme is only too detailed: a budget is named.
    let out = tmp.path().join("half-edge");
    let run = build(&dome, &out, &["--scheme", "half-edge", "--size", "2ft"]);
    assert_refused(
        "open dome, half-edge",
        &run,
        &out,
        &["too detailed", "--target-edges "],
    );
    assert!(!run.stderr.contains("--fill-holes"), "{}", run.stderr);
}

/// A UV sphere of `rings` × `segments` whose northmost ring lies `hole` (radians) from
/// the north pole, with no faces beyond it: a closed ball but for one small hole, as
/// OBJ text.
fn sphere_with_a_small_hole(rings: usize, segments: usize, hole: f64) -> String {
    use std::f64::consts::PI;
    let mut text = String::from("v 0 0 -1\n");
    // Polar angles from the south pole: even steps, then the hole's rim.
    let thetas: Vec<f64> = (1..rings)
        .map(|k| k as f64 * PI / rings as f64)
        .chain([PI - hole])
        .collect();
    for theta in &thetas {
        for j in 0..segments {
            let phi = j as f64 * 2.0 * PI / segments as f64;
            let (x, y, z) = (
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                -theta.cos(),
            );
            text += &format!("v {x} {y} {z}\n");
        }
    }
    let at = |k: usize, j: usize| 2 + k * segments + j % segments;
    for j in 0..segments {
        text += &format!("f 1 {} {}\n", at(0, j + 1), at(0, j));
    }
    for k in 0..thetas.len() - 1 {
        for j in 0..segments {
            let (a, b) = (at(k, j), at(k, j + 1));
            let (c, d) = (at(k + 1, j + 1), at(k + 1, j));
            text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    text
}

#[test]
fn a_hole_too_small_for_any_budget_gets_a_fix_that_closes_it() {
    // At 2 ft the hole's rim is about 29 mm round: three quad-edge panels that hold
    // their ids need more than that, so no budget builds the ball open.
    let tmp = TempDir::new().unwrap();
    let ball = tmp.path().join("ball.obj");
    std::fs::write(&ball, sphere_with_a_small_hole(40, 40, 0.015)).unwrap();
    let out = tmp.path().join("out");
    let args = [
        "--scheme",
        "quad-edge",
        "--size",
        "2ft",
        "--nester",
        "shelf",
    ];
    let run = build(&ball, &out, &args);
    assert_refused(
        "ball",
        &run,
        &out,
        &[
            "too detailed for its size",
            "try --fill-holes --target-edges ",
            "the rims of its holes keep edges too short at any budget",
            "(or --fill-holes --target-edges auto)",
        ],
    );
    // The fix named, run, builds with no warning; its note says what was closed.
    let run = assert_named_fix_builds_clean(&ball, &out, &args, &run, &["--fill-holes"]);
    assert!(
        run.stdout
            .contains("--fill-holes closed 1 hole with one face each")
            || run
                .stderr
                .contains("--fill-holes closed 1 hole with one face each"),
        "{}{}",
        run.stdout,
        run.stderr
    );
    // `auto` alone cannot add the repair: it stops naming it; with it, it builds.
    let run = build(
        &ball,
        &out,
        &[&args[..], &["--target-edges", "auto", "--force"]].concat(),
    );
    assert_refusal("auto", &run, 2, &["--fill-holes --target-edges auto"]);
    let run = build(
        &ball,
        &out,
        &[
            &args[..],
            &["--fill-holes", "--target-edges", "auto", "--force"],
        ]
        .concat(),
    );
    assert_eq!(run.code, Some(0), "auto: {}", run.stderr);
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
    // Closed, the ball has no boundary left.
    let run = finish(
        unfold_command()
            .args(["inspect", "--fill-holes"])
            .arg(&ball),
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("boundary loops 0"), "{}", run.stdout);
}

#[test]
fn the_teapot_stops_naming_the_repairs_its_open_seams_need() {
    let Some(shared) = shared_models("the_teapot_stops_naming_the_repairs_its_open_seams_need")
    else {
        return;
    };
    let teapot = shared.join("teapot.obj");
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let args = [
        "--scheme",
        "quad-edge",
        "--size",
        "2ft",
        "--nester",
        "shelf",
    ];
    let run = build(&teapot, &out, &args);
    assert_refused(
        "teapot",
        &run,
        &out,
        &["try --weld --fill-holes --target-edges "],
    );
    assert_named_fix_builds_clean(&teapot, &out, &args, &run, &["--weld", "--fill-holes"]);
}

#[test]
fn the_teapots_open_seams_are_joined_shut_and_auto_weaves_it() {
    let Some(shared) = shared_models("the_teapots_open_seams_are_joined_shut_and_auto_weaves_it")
    else {
        return;
    };
    // The teapot's patches meet along open seams: rims that run out and back along
    // one line. Capped with one face each, they gave the woven ribbons crossings of
    // no area; joined where the rims meet, the teapot weaves at the budget auto picks.
    let teapot = shared.join("teapot.obj");
    let run = finish(
        unfold_command()
            .args(["inspect", "--fill-holes"])
            .arg(&teapot),
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    for fact in [
        "boundary loops 0",
        "--fill-holes closed 25 holes (the largest has 98 edges): 11 of them open seams whose rims meet themselves, joined where they meet",
        "genus 0  euler 38  components 19",
    ] {
        assert!(run.stdout.contains(fact), "{fact}: {}", run.stdout);
    }
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let run = build(
        &teapot,
        &out,
        &[
            "--scheme",
            "woven",
            "--size",
            "4ft",
            "--nester",
            "shelf",
            "--fill-holes",
            "--target-edges",
            "auto",
        ],
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
    assert!(
        run.stderr.contains("--target-edges auto: the model is too detailed for its size as it is, so it was simplified to "),
        "{}",
        run.stderr
    );
}

#[test]
fn where_no_budget_builds_at_the_size_asked_a_larger_size_is_named_with_its_budget() {
    let Some(shared) = shared_models(
        "where_no_budget_builds_at_the_size_asked_a_larger_size_is_named_with_its_budget",
    ) else {
        return;
    };
    // fertility's winged-edge panels at 2 ft: at the fewest edges its genus allows
    // some faces are too thin for a hole, above that too small for their ids.
    let fertility = shared.join("fertility.obj");
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let args = [
        "--scheme",
        "winged-edge",
        "--size",
        "2ft",
        "--nester",
        "shelf",
    ];
    let run = build(&fertility, &out, &args);
    assert_refused(
        "fertility",
        &run,
        &out,
        &[
            "try --size 1.22m --target-edges ",
            "(at the size asked, no budget gives every panel its id and holes)",
            "(or --size 1.22m --target-edges auto)",
        ],
    );
    assert_named_fix_builds_clean(&fertility, &out, &args, &run, &["--size", "1.22m"]);
    let auto = [
        &args[..],
        &["--size", "1.22m", "--target-edges", "auto", "--force"],
    ]
    .concat();
    let run = build(&fertility, &out, &auto);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
}

#[test]
fn auto_shows_only_the_warnings_of_the_build_it_keeps() {
    let Some(shared) = shared_models("auto_shows_only_the_warnings_of_the_build_it_keeps") else {
        return;
    };
    // As it is, suzanne at 4 ft warns of connections without holes before its label
    // check stops it; simplified to the budget auto picks, it builds clean.
    let suzanne = shared.join("suzanne.obj");
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let args = [
        "--scheme",
        "quad-edge",
        "--size",
        "4ft",
        "--nester",
        "shelf",
    ];
    let run = build(&suzanne, &out, &args);
    assert!(
        run.code == Some(2) && run.stderr.contains("warning: "),
        "{}",
        run.stderr
    );
    let run = build(
        &suzanne,
        &out,
        &[&args[..], &["--target-edges", "auto"]].concat(),
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.contains("warning:"), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("--target-edges auto: the model is too detailed"),
        "{}",
        run.stderr
    );
}
