//! `unfold inspect` on real models, through the real binary: the facts must equal the
//! independently computed ones (shared models, `../shared/models/README.md`) and the
//! construction facts of the project's own generated models.

use crate::common;

use serde_json::Value;

use common::build::{
    crate_dir, finish, inspect_json as inspect, read_manifest, shared_models, unfold_command,
};

fn int(v: &Value, path: &str) -> i64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_i64()
        .unwrap_or_else(|| panic!("{path} is not an integer: {cur}"))
}

fn notes(v: &Value) -> Vec<(String, String)> {
    v["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            (
                n["kind"].as_str().unwrap().to_string(),
                n["message"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// V, E, F, boundary edges and genus of the file as given, from the shared README.
const SHARED_FACTS: &[(&str, i64, i64, i64, i64, i64)] = &[
    ("cube.obj", 8, 18, 12, 0, 0),
    ("decimated-knight.off", 502, 1500, 1000, 0, 0),
    ("fertility.obj", 3730, 5784, 2048, 0, 4),
    ("horse_quad.obj", 2400, 4796, 2398, 0, 0),
    ("spot.obj", 2930, 8784, 5856, 0, 0),
    ("stanford-bunny.obj", 34834, 104288, 69451, 223, 0),
    ("suzanne.obj", 507, 1005, 500, 42, 0),
    ("teapot.obj", 3644, 9998, 6320, 1036, 0),
];

#[test]
fn shared_models_match_their_reference_facts() {
    let Some(dir) = shared_models("inspect_models") else {
        return;
    };
    for &(name, v, e, f, boundary, genus) in SHARED_FACTS {
        let report = inspect(&dir.join(name), &[]);
        assert_eq!(int(&report, "input.vertices"), v, "{name} V");
        assert_eq!(int(&report, "input.edges"), e, "{name} E");
        assert_eq!(int(&report, "input.faces"), f, "{name} F");
        assert_eq!(
            int(&report, "input.boundary_edges"),
            boundary,
            "{name} boundary"
        );
        assert_eq!(int(&report, "input.non_manifold_edges"), 0, "{name}");
        // The built mesh keeps every face and edge; only bow-ties add vertices.
        assert_eq!(int(&report, "mesh.faces"), f, "{name} mesh F");
        assert_eq!(int(&report, "mesh.edges"), e, "{name} mesh E");
        assert_eq!(int(&report, "mesh.boundary_edges"), boundary, "{name}");
        if name != "teapot.obj" {
            // The teapot is a patch soup: its genus per patch says little; the
            // reference gives only its Euler characteristic (tested below).
            assert_eq!(int(&report, "mesh.genus"), genus, "{name} genus");
        }
    }
}

#[test]
fn fertility_is_genus_four_with_ngons() {
    let Some(dir) = shared_models("inspect_models") else {
        return;
    };
    let report = inspect(&dir.join("fertility.obj"), &[]);
    assert_eq!(int(&report, "mesh.genus"), 4);
    assert_eq!(int(&report, "mesh.euler_characteristic"), -6);
    let sizes = report["mesh"]["face_sizes"].as_object().unwrap();
    let smallest: usize = sizes.keys().map(|k| k.parse().unwrap()).min().unwrap();
    let largest: usize = sizes.keys().map(|k| k.parse().unwrap()).max().unwrap();
    assert_eq!((smallest, largest), (3, 9));
    let total: i64 = sizes.values().map(|n| n.as_i64().unwrap()).sum();
    assert_eq!(total, 2048);
    // Many faces are not exactly planar; inspect measures and reports them.
    assert!(report["geometry"]["non_planar_faces"].as_i64().unwrap() > 0);
}

#[test]
fn bunny_unreferenced_vertices_are_reported_and_dropped() {
    let Some(dir) = shared_models("inspect_models") else {
        return;
    };
    let report = inspect(&dir.join("stanford-bunny.obj"), &[]);
    assert_eq!(int(&report, "input.vertices_in_file"), 35947);
    assert_eq!(int(&report, "mesh.vertices"), 34834);
    let unreferenced = notes(&report)
        .into_iter()
        .find(|(k, _)| k == "unreferenced-vertices")
        .expect("a note about unreferenced vertices");
    assert!(
        unreferenced.1.starts_with("1113 vertices"),
        "{}",
        unreferenced.1
    );
    // χ = −3 with 5 holes in the base: a disc-like surface, genus 0.
    assert_eq!(int(&report, "mesh.boundary_loops"), 5);
    assert_eq!(int(&report, "mesh.euler_characteristic"), -3);
}

#[test]
fn suzanne_has_several_components_and_welding_skips_the_eyes() {
    let Some(dir) = shared_models("inspect_models") else {
        return;
    };
    let report = inspect(&dir.join("suzanne.obj"), &[]);
    assert_eq!(report["mesh"]["components"].as_array().unwrap().len(), 3);
    let shared = notes(&report)
        .into_iter()
        .find(|(k, _)| k == "shared-positions")
        .expect("coincident vertices are reported");
    assert!(shared.1.starts_with("2 vertices"), "{}", shared.1);

    // Welding the eyes to the head would make bow-ties: both merges are skipped.
    let welded = inspect(&dir.join("suzanne.obj"), &["--weld"]);
    assert_eq!(int(&welded, "welded.vertices"), 507);
    let skipped = notes(&welded)
        .into_iter()
        .find(|(k, _)| k == "weld-skipped")
        .expect("skipped merges are reported");
    assert!(skipped.1.starts_with("2 groups"), "{}", skipped.1);
    assert!(skipped.1.contains("vertices 15 and 114"), "{}", skipped.1);
}

#[test]
fn teapot_seams_are_reported_and_weld_where_manifold() {
    let Some(dir) = shared_models("inspect_models") else {
        return;
    };
    let report = inspect(&dir.join("teapot.obj"), &[]);
    assert_eq!(int(&report, "input.euler_characteristic"), -34);
    let kinds: Vec<String> = notes(&report).into_iter().map(|(k, _)| k).collect();
    assert!(kinds.contains(&"shared-positions".to_string()), "{kinds:?}");
    assert!(kinds.contains(&"split-vertices".to_string()), "{kinds:?}");
    assert_eq!(int(&report, "input.non_manifold_vertices"), 38);

    let welded = inspect(&dir.join("teapot.obj"), &["--weld"]);
    assert_eq!(int(&welded, "welded.vertices"), 3241);
    assert_eq!(int(&welded, "welded.edges"), 9560);
    assert_eq!(int(&welded, "welded.boundary_edges"), 160);
}

/// Project models: (file, V, E, F, boundary edges, boundary loops, genus).
const PROJECT_FACTS: &[(&str, i64, i64, i64, i64, i64, i64)] = &[
    ("tetrahedron.obj", 4, 6, 4, 0, 0, 0),
    ("hexahedron.obj", 8, 12, 6, 0, 0, 0),
    ("octahedron.obj", 6, 12, 8, 0, 0, 0),
    ("dodecahedron.obj", 20, 30, 12, 0, 0, 0),
    ("icosahedron.obj", 12, 30, 20, 0, 0, 0),
    ("torus-8x6.obj", 48, 96, 48, 0, 0, 1),
    ("torus-6x4.obj", 24, 48, 24, 0, 0, 1),
    ("genus2.obj", 48, 100, 50, 0, 0, 2),
    ("genus3.obj", 64, 136, 68, 0, 0, 3),
    ("concave.obj", 20, 30, 12, 0, 0, 0),
    ("open-grid.obj", 35, 58, 24, 20, 1, 0),
    ("open-cylinder.obj", 32, 56, 24, 16, 2, 0),
];

#[test]
fn project_models_have_their_construction_facts() {
    for &(name, v, e, f, boundary, loops, genus) in PROJECT_FACTS {
        let report = inspect(&crate_dir().join("models").join(name), &[]);
        assert_eq!(int(&report, "mesh.vertices"), v, "{name} V");
        assert_eq!(int(&report, "mesh.edges"), e, "{name} E");
        assert_eq!(int(&report, "mesh.faces"), f, "{name} F");
        assert_eq!(int(&report, "mesh.boundary_edges"), boundary, "{name}");
        assert_eq!(int(&report, "mesh.boundary_loops"), loops, "{name}");
        assert_eq!(int(&report, "mesh.genus"), genus, "{name} genus");
        assert_eq!(
            report["mesh"]["components"].as_array().unwrap().len(),
            1,
            "{name}"
        );
        // Generated models are clean and exactly planar.
        assert!(notes(&report).is_empty(), "{name}: {:?}", notes(&report));
        assert!(report["geometry"]["max_planarity_error"].as_f64().unwrap() < 1e-9);
    }
}

#[test]
fn size_scales_the_longest_side() {
    let report = inspect(&crate_dir().join("models/genus2.obj"), &["--size", "4ft"]);
    let size: Vec<f64> = report["physical"]["size_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let longest = size.iter().cloned().fold(0.0, f64::max);
    assert!((longest - 1219.2).abs() < 1e-6, "{size:?}");
    // genus2 is 100 x 60 x 20 model units: the other sides scale alike.
    assert!((size[1] / longest - 0.6).abs() < 1e-9, "{size:?}");

    let by_units = inspect(
        &crate_dir().join("models/genus2.obj"),
        &["--units", "cm", "--scale", "2"],
    );
    let mm = by_units["physical"]["mm_per_unit"].as_f64().unwrap();
    assert!((mm - 20.0).abs() < 1e-12);
    // Area scales with the square of the factor.
    let area = by_units["geometry"]["surface_area"].as_f64().unwrap();
    let area_mm2 = by_units["physical"]["surface_area_mm2"].as_f64().unwrap();
    assert!((area_mm2 - area * 400.0).abs() < 1e-6 * area_mm2);
}

#[test]
fn surface_area_of_the_generated_hexahedron() {
    // A cube whose longest side is 100 model units: six 100 x 100 faces.
    let report = inspect(&crate_dir().join("models/hexahedron.obj"), &[]);
    let area = report["geometry"]["surface_area"].as_f64().unwrap();
    assert!((area - 60000.0).abs() < 1e-6, "{area}");
}

#[test]
fn config_file_gives_options_and_the_command_line_wins() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("unfold.toml");
    std::fs::write(&config, "size = \"1m\"\nunits = \"cm\"\n").unwrap();
    let model = crate_dir().join("models/genus2.obj");
    let config_arg = config.to_str().unwrap();
    let from_file = inspect(&model, &["--config", config_arg]);
    let mm = from_file["physical"]["mm_per_unit"].as_f64().unwrap();
    assert!((mm - 10.0).abs() < 1e-12, "size 1m over 100 units: {mm}");
    let overridden = inspect(&model, &["--config", config_arg, "--size", "2m"]);
    let mm = overridden["physical"]["mm_per_unit"].as_f64().unwrap();
    assert!((mm - 20.0).abs() < 1e-12, "{mm}");
}

#[test]
fn inspect_text_is_the_same_on_every_run() {
    let model = crate_dir().join("models/concave.obj");
    let run = || finish(unfold_command().arg("inspect").arg(&model)).stdout;
    let first = run();
    assert!(first.contains("genus 0"));
    assert_eq!(first, run());
}

#[test]
fn inspect_lists_what_preparation_would_split_and_builds_agree() {
    // The star prism's caps are star-shaped from their centre (half-edge keeps them)
    // but not convex (the edge schemes split them).
    let concave = crate_dir().join("models/concave.obj");
    let report = inspect(&concave, &[]);
    let preparation = |scheme: &str| -> serde_json::Value {
        report["preparation"]
            .as_array()
            .expect("a list")
            .iter()
            .find(|p| p["scheme"] == scheme)
            .unwrap_or_else(|| panic!("{scheme} in {report}"))
            .clone()
    };
    // Every registered scheme is listed, in the registry's order.
    let listed: Vec<&str> = report["preparation"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["scheme"].as_str().unwrap())
        .collect();
    assert_eq!(
        listed,
        [
            "half-edge",
            "quad-edge",
            "winged-edge",
            "woven",
            "net",
            "strip"
        ]
    );
    assert_eq!(preparation("half-edge")["faces"], "star-shaped");
    assert_eq!(preparation("half-edge")["misshapen"], 0);
    for scheme in ["quad-edge", "winged-edge", "woven", "net", "strip"] {
        assert_eq!(preparation(scheme)["faces"], "convex", "{scheme}");
        assert_eq!(preparation(scheme)["misshapen"], 2, "{scheme}");
    }
    for scheme in ["half-edge", "quad-edge"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("o");
        let run = finish(
            unfold_command()
                .arg(&concave)
                .args([
                    "--scheme",
                    scheme,
                    "--size",
                    "300mm",
                    "--quiet",
                    "--build-anyway",
                ])
                .arg("--out")
                .arg(&out),
        );
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        let manifest = read_manifest(&out);
        let split = &manifest["input"]["faces_split"];
        let preview = preparation(scheme);
        assert_eq!(split["non_planar"], preview["non_planar"], "{scheme}");
        assert_eq!(split["not_star_shaped"], preview["misshapen"], "{scheme}");
    }
}
