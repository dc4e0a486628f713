//! End-to-end tests of the net scheme (SPEC.md §2, net): every face in exactly one
//! island, folds and cuts adding up to the interior edges, one tab and two matching
//! numbers per cut, tabs in their partner face's plane and inside it, islands that
//! unroll exactly and that the independent sheet checker finds free of overlaps, the
//! platonic solids as one island each, byte-identical output on 1 and 2 threads.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use glam::DVec3;
use serde_json::Value;
use tempfile::TempDir;

use common::build::*;
use unfold::mesh::Mesh;
use unfold::panel::Covers;
use unfold::scheme::island::{ISLAND, MATCH};

/// Interior edges of a mesh (edges with a face on both sides).
fn interior_edges(mesh: &Mesh) -> usize {
    mesh.edges().filter(|&e| !mesh.is_boundary_edge(e)).count()
}

/// Checks the island facts of one build against its own mesh and panels: every face
/// in one island (manifest and panels agree), folds + cuts = interior edges, one tab
/// per cut, each match number twice, every tab facet in its partner face's plane and
/// inside that face. Returns the number of islands.
fn check_islands(what: &str, m: &Value, p: &Pipeline) -> usize {
    let mesh = &p.mesh;
    let size = mesh
        .faces()
        .map(|f| mesh.face_area(f).sqrt())
        .fold(0.0, f64::max);
    // Every face in exactly one island, in the manifest and in the panels.
    let mut owner: BTreeMap<u32, String> = BTreeMap::new();
    for entry in m["panels"].as_array().unwrap() {
        let id = entry["id"].as_str().unwrap().to_string();
        assert!(id.starts_with('N'), "{what}: panel id {id}");
        for f in entry["source"]["faces"].as_array().expect("island faces") {
            let f = f.as_u64().unwrap() as u32;
            assert!(
                owner.insert(f, id.clone()).is_none(),
                "{what}: face {f} is in two islands"
            );
        }
    }
    assert_eq!(owner.len(), mesh.face_count(), "{what}: faces in islands");
    let islands = count(m, "net.islands");
    assert_eq!(islands, p.panels.len(), "{what}: islands");
    assert_eq!(count(m, "counts.panels"), islands, "{what}: panels");
    let folds =
        count(m, "net.folds_mountain") + count(m, "net.folds_valley") + count(m, "net.folds_flat");
    let cuts = count(m, "net.cuts");
    assert_eq!(folds + cuts, interior_edges(mesh), "{what}: folds + cuts");
    assert_eq!(count(m, "net.tabs"), cuts, "{what}: one tab per cut");
    assert_eq!(count(m, "counts.connections"), cuts, "{what}: connections");

    // Each cut's match number on both sides; each tab facet in its partner's plane.
    let mut matches: BTreeMap<u32, usize> = BTreeMap::new();
    let mut tab_facets = 0;
    for panel in &p.panels {
        for label in &panel.labels {
            if label.text.kind == &MATCH {
                *matches.entry(label.text.number).or_default() += 1;
            }
        }
        let Covers::Faces(k) = panel.source.covers else {
            panic!("{what}: {} is not an island", panel.id());
        };
        assert_eq!(
            panel.id().kind,
            &ISLAND,
            "{what}: {} is an island",
            panel.id()
        );
        let faces = &p.output.face_groups[k as usize].faces;
        // Facets past the island's faces are tabs.
        for facet in panel.facets.iter().skip(faces.len()) {
            tab_facets += 1;
            let pts: Vec<DVec3> = facet.iter().map(|&i| panel.vertices[i as usize]).collect();
            assert!(
                lies_on_a_face(mesh, &pts, size),
                "{what}: {} has a tab facet outside every face of the model",
                panel.id()
            );
        }
    }
    assert_eq!(tab_facets, cuts, "{what}: tab facets");
    assert_eq!(matches.len(), cuts, "{what}: match numbers");
    assert!(
        matches.values().all(|&n| n == 2),
        "{what}: a match number is not on exactly two sides"
    );
    islands
}

/// True when every point lies in one face's plane and inside that face (within a
/// millionth of the model's size).
fn lies_on_a_face(mesh: &Mesh, pts: &[DVec3], size: f64) -> bool {
    let tol = 1e-6 * size;
    mesh.faces().any(|f| {
        let n = mesh.face_normal(f);
        let corners: Vec<DVec3> = mesh.face_positions(f).collect();
        pts.iter().all(|&p| {
            (p - corners[0]).dot(n).abs() < tol
                && (0..corners.len()).all(|i| {
                    let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
                    (b - a).cross(p - a).dot(n) >= -tol * (b - a).length()
                })
        })
    })
}

/// Builds `name` with the net scheme through the binary (sheets checked, DXF too) and
/// through the library, with `sheet` and the net options `extra` (name, value);
/// returns the manifest and the pipeline.
fn net_build(
    tmp: &Path,
    model: &Path,
    size: &str,
    sheet: &str,
    extra: &[(&str, &str)],
) -> (Value, Pipeline) {
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    let out = tmp.join(&name);
    let flags: Vec<String> = extra.iter().map(|(k, _)| format!("--{k}")).collect();
    let mut args = vec!["--format", "svg,dxf", "--sheet", sheet];
    for (flag, (_, value)) in flags.iter().zip(extra) {
        args.push(flag);
        args.push(value);
    }
    let m = build("net", model, size, &out, &args);
    // A build of many sheets reads its first and last DXF (every one with
    // UNFOLD_FULL_DXF=1).
    let dxf = if count(&m, "counts.sheets") > 2 {
        DxfCheck::FirstAndLast
    } else {
        DxfCheck::All
    };
    check_output(model, &out, &m, &name, dxf, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    let max_error = num(&m, "max_developability_error");
    assert!(
        max_error <= 1e-9 * 2000.0,
        "{name}: developability {max_error}"
    );
    let mut options = options("net", size, 0, &tmp.join("job"));
    options.sheet = Some(sheet.to_string());
    for (k, v) in extra {
        options.scheme_values.set(k, v);
    }
    let p = pipeline(&resolve(options, model));
    (m, p)
}

#[test]
fn platonic_solids_at_six_inches_are_one_island_each() {
    let tmp = TempDir::new().unwrap();
    for name in [
        "tetrahedron",
        "hexahedron",
        "octahedron",
        "dodecahedron",
        "icosahedron",
    ] {
        // A 6 in cube's smallest nets span 18 x 24 in: the sheet must be larger.
        let (m, p) = net_build(tmp.path(), &model(name), "6in", "24x36in", &[]);
        let islands = check_islands(name, &m, &p);
        assert_eq!(islands, 1, "{name}: one island");
        if name == "tetrahedron" {
            assert_eq!(count(&m, "net.cuts"), 3);
            assert_eq!(count(&m, "net.tabs"), 3);
        }
    }
}

#[test]
fn tori_slabs_open_meshes_and_concave_faces_make_valid_nets() {
    let tmp = TempDir::new().unwrap();
    for name in [
        "torus-6x4",
        "torus-8x6",
        "genus2",
        "genus3",
        "open-grid",
        "open-cylinder",
        "concave",
    ] {
        let (m, p) = net_build(tmp.path(), &model(name), "1ft", "18x24in", &[]);
        check_islands(name, &m, &p);
    }
}

#[test]
fn a_shared_model_makes_valid_nets() {
    let Some(dir) = shared_models("build_net") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let (m, p) = net_build(
        tmp.path(),
        &dir.join("decimated-knight.off"),
        "4ft",
        "18x24in",
        &[],
    );
    let islands = check_islands("decimated-knight", &m, &p);
    eprintln!(
        "decimated-knight: {islands} islands on {} sheets",
        count(&m, "counts.sheets")
    );
}

#[test]
fn max_island_faces_caps_every_island() {
    let tmp = TempDir::new().unwrap();
    let (m, p) = net_build(
        tmp.path(),
        &model("icosahedron"),
        "6in",
        "18x24in",
        &[("max-island-faces", "5")],
    );
    check_islands("icosahedron, at most 5 faces", &m, &p);
    assert!(p.output.face_groups.iter().all(|g| g.faces.len() <= 5));
    assert!(p.output.face_groups.len() >= 4);
}

#[test]
fn nets_are_the_same_on_one_and_two_threads() {
    assert_same_bytes_on_one_and_two_threads(
        &model("genus3"),
        &["--scheme", "net", "--size", "1ft"],
    );
}

#[test]
fn faces_of_an_island_touch_only_where_they_are_folded_together() {
    // Every face's flat corners that share a 3D vertex and a flat point in one island
    // are one island vertex (no outline pinched at a point).
    let tmp = TempDir::new().unwrap();
    let p = pipeline(&job(
        "net",
        &model("genus2"),
        "1ft",
        0,
        &tmp.path().join("out"),
    ));
    for (panel, fp) in p.panels.iter().zip(&p.flat) {
        let mut seen: BTreeSet<(i64, i64)> = BTreeSet::new();
        for &i in fp.outline.iter().flatten() {
            let q = fp.points[i as usize];
            let key = ((q.x * 1e6).round() as i64, (q.y * 1e6).round() as i64);
            assert!(
                seen.insert(key),
                "{}: its outline passes twice through one point",
                panel.id()
            );
        }
    }
}
