//! `--nonplanar planarize`: guided projection makes every face of four or more corners
//! planar within the tolerance, reports the largest vertex move truthfully, leaves a
//! planar mesh exactly as it was, and gives half-edge panels that unroll exactly.

use crate::common;

use std::path::Path;

use glam::DVec3;
use tempfile::TempDir;

use common::build::{
    build_run, check_sheets, inspect_json, model, options, shared_models, DxfCheck,
};
use unfold::config::{Job, NonPlanar};
use unfold::mesh::geometry::planarity_error;
use unfold::run::SchemeMesh;

fn job(model: &Path, nonplanar: NonPlanar, out: &Path) -> Job {
    let mut options = options("half-edge", "4ft", 0, out);
    options.nonplanar = Some(nonplanar);
    options.resolve(model).expect("options resolve")
}

fn mesh_for(job: &Job) -> SchemeMesh {
    let loaded = unfold::run::load(job).expect("model loads");
    unfold::run::prepare(job, loaded)
        .expect("scheme mesh")
        .scheme_mesh
}

/// Largest planarity error of the faces with four or more corners.
fn worst_planarity(mesh: &unfold::mesh::Mesh) -> f64 {
    mesh.faces()
        .filter(|&f| mesh.face_degree(f) > 3)
        .map(|f| planarity_error(&mesh.face_positions(f).collect::<Vec<DVec3>>()))
        .fold(0.0, f64::max)
}

/// Planarizes `name` and checks the faces, the report and the displacement against the
/// same mesh prepared without planarization (same vertex order, same scale).
fn check_planarized(path: &Path, what: &str) {
    let tmp = TempDir::new().unwrap();
    let before = mesh_for(&job(path, NonPlanar::Triangulate, tmp.path()));
    let planarize_job = job(path, NonPlanar::Planarize, tmp.path());
    let after = mesh_for(&planarize_job);
    // The input as the planarizer got it: prepared and scaled, not yet split.
    let mut input = unfold::load_model(path, &planarize_job.model)
        .expect("model loads")
        .1
        .mesh;
    input.scale(after.mm_per_unit);
    let report = after.planarized.clone().expect("a planarization report");
    let tolerance = 1e-3;

    assert!(
        report.non_planar_before > 0 && !before.split.non_planar.is_empty(),
        "{what}: the input has non-planar faces"
    );
    assert_eq!(report.non_planar_after, 0, "{what}: {report:?}");
    assert!(
        after.split.non_planar.is_empty(),
        "{what}: faces still split for planarity: {}",
        after.split.non_planar.len()
    );
    // The mesh itself, measured independently of the report.
    let worst = worst_planarity(&after.mesh);
    assert!(worst < tolerance, "{what}: worst planarity {worst:e}");
    assert!(worst < 1e-9, "{what}: not converged: {worst:e}");
    assert!(
        (worst - report.max_error_after).abs() < 1e-12,
        "{what}: reported {:e}, measured {worst:e}",
        report.max_error_after
    );
    // Only positions moved (planar faces are not split, so no vertex was added), and
    // the reported largest move is the measured one.
    assert_eq!(after.mesh.vertex_count(), input.vertex_count(), "{what}");
    let moved = input
        .positions()
        .iter()
        .zip(after.mesh.positions())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(moved > 0.0, "{what}: nothing moved");
    assert!(
        (moved - report.max_displacement).abs() < 1e-9,
        "{what}: reported move {} mm, measured {moved} mm",
        report.max_displacement
    );
    // Close to the input: no vertex moves more than 5 % of the model's size (4 ft).
    assert!(moved < 0.05 * 1219.2, "{what}: moved {moved} mm");
    eprintln!(
        "{what}: {} of {} polygons non-planar, worst {:.2e} -> {worst:.2e} in {} iterations, largest move {moved:.3} mm",
        report.non_planar_before, report.polygons, report.max_error_before, report.iterations
    );
}

#[test]
fn suzanne_quads_and_fertility_ngons_become_planar() {
    let Some(shared) = shared_models("planarize") else {
        return;
    };
    check_planarized(&shared.join("suzanne.obj"), "suzanne");
    check_planarized(&shared.join("fertility.obj"), "fertility");
}

#[test]
fn inspect_previews_the_planarization_the_build_does() {
    let Some(shared) = shared_models("planarize") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let path = shared.join("suzanne.obj");
    let build = mesh_for(&job(&path, NonPlanar::Planarize, tmp.path()))
        .planarized
        .expect("a report");
    let preview = inspect_json(&path, &["--size", "4ft", "--nonplanar", "planarize"]);
    let planarized = &preview["planarized"];
    assert_eq!(preview["nonplanar"], "planarize");
    for (key, value) in [
        ("polygons", build.polygons),
        ("non_planar_before", build.non_planar_before),
        ("non_planar_after", build.non_planar_after),
        ("iterations", build.iterations),
    ] {
        assert_eq!(planarized[key].as_u64(), Some(value as u64), "{key}");
    }
    // The same computation on the same scaled mesh: the same move (mm), not an estimate.
    assert_eq!(
        planarized["max_displacement"].as_f64(),
        Some(build.max_displacement)
    );
    assert!(build.max_displacement > 1.0, "suzanne's quads move at 4 ft");
    // After planarization nothing is split for planarity; without it, 440 faces are.
    assert_eq!(preview["preparation"][0]["scheme"], "half-edge");
    assert_eq!(preview["preparation"][0]["non_planar"], 0);
    let triangulate = inspect_json(&path, &["--size", "4ft"]);
    assert!(triangulate["planarized"].is_null());
    assert_eq!(triangulate["nonplanar"], "triangulate");
    assert_eq!(
        triangulate["preparation"][0]["non_planar"].as_u64(),
        Some(build.non_planar_before as u64)
    );
}

#[test]
fn inspect_reads_the_builds_config_file() {
    let Some(shared) = shared_models("planarize") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let path = shared.join("suzanne.obj");
    // A build's config: keys inspect does not use (scheme, sheet) are accepted.
    let config = tmp.path().join("build.toml");
    std::fs::write(
        &config,
        "scheme = \"quad-edge\"\nsheet = \"18x24in\"\nsize = \"4ft\"\nnonplanar = \"planarize\"\n",
    )
    .unwrap();
    let config = config.to_str().unwrap();
    let from_file = inspect_json(&path, &["--config", config]);
    let from_options = inspect_json(&path, &["--size", "4ft", "--nonplanar", "planarize"]);
    assert_eq!(from_file["nonplanar"], "planarize");
    assert!(from_file["planarized"]["non_planar_before"].as_u64() > Some(0));
    assert_eq!(from_file["planarized"], from_options["planarized"]);
    assert_eq!(from_file["preparation"], from_options["preparation"]);
    // The command line wins over the file.
    let overridden = inspect_json(&path, &["--config", config, "--nonplanar", "triangulate"]);
    assert_eq!(overridden["nonplanar"], "triangulate");
    assert!(overridden["planarized"].is_null());
}

#[test]
fn a_planar_mesh_does_not_move() {
    let tmp = TempDir::new().unwrap();
    for name in ["hexahedron", "torus-8x6", "genus2", "dodecahedron"] {
        let path = model(name);
        let plain = mesh_for(&job(&path, NonPlanar::Triangulate, tmp.path()));
        let planarized = mesh_for(&job(&path, NonPlanar::Planarize, tmp.path()));
        let report = planarized.planarized.expect("a report");
        assert_eq!(report.non_planar_before, 0, "{name}: {report:?}");
        assert_eq!(report.max_displacement, 0.0, "{name}");
        assert_eq!(
            plain.mesh.positions(),
            planarized.mesh.positions(),
            "{name}: positions changed"
        );
    }
}

#[test]
fn planarized_half_edge_panels_unroll_exactly_and_pass_the_sheet_check() {
    let Some(shared) = shared_models("planarize") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("suzanne");
    let (m, run) = build_run(
        "half-edge",
        &shared.join("suzanne.obj"),
        "4ft",
        &out,
        &["--nonplanar", "planarize", "--format", "svg,dxf"],
    );
    assert!(
        run.stderr.contains("note: planarized 440 non-planar faces"),
        "{}",
        run.stderr
    );
    // Planar faces are not split: one panel per face (500), where triangulating the
    // 440 non-planar quads gives 940.
    assert_eq!(m["counts"]["panels"], 500, "{m}");
    let error = m["max_developability_error"]
        .as_f64()
        .expect("developability error in the manifest");
    assert!(error < 1e-9, "developability error {error}");
    check_sheets(&out, &m, DxfCheck::FirstAndLast);

    // The flat panels themselves, not only the rounded manifest figure.
    let job = job(&shared.join("suzanne.obj"), NonPlanar::Planarize, &out);
    let (_, _, _, flat) = common::build::panels_of(&job);
    let worst = flat
        .iter()
        .map(|p| p.developability_error)
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "worst panel developability error {worst:e}");
}
