//! The assembly map (`NAME-map.svg`), read back as a builder would use it: it names
//! nearly every panel, each id where its panel is seen — checked by casting a ray
//! into the model (the scheme's mesh, from the library's pipeline) at the id's place
//! on the page, through the view's own projection written on the view's group — and
//! `--no-map` turns it off.

use crate::common;

use std::collections::BTreeSet;
use std::path::Path;

use common::build::{build, count, model, options, resolve, shared_models};
use common::map::{face_seen, read_map};
use serde_json::Value;
use tempfile::TempDir;
use unfold::mesh::{EdgeId, FaceId, Mesh};

/// The faces a panel id stands for: a face panel's face, an edge panel's two faces.
fn faces_of(mesh: &Mesh, id: &str) -> BTreeSet<u32> {
    let number: u32 = id[1..].parse().unwrap_or_else(|_| panic!("id {id}"));
    match &id[..1] {
        "F" => [number].into(),
        "E" => {
            let h = EdgeId(number).half_edge();
            [h, h.twin()]
                .into_iter()
                .filter_map(|h| mesh.face(h))
                .map(|f: FaceId| f.0)
                .collect()
        }
        _ => panic!("unexpected id {id}"),
    }
}

/// Builds `model` with `args`, reads its map, and checks that at least `share` of the
/// panels are named and that every id sits over a face of its own panel as seen.
fn check_map(model: &Path, scheme: &str, size: &str, target_edges: Option<usize>, share: f64) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let mut args = vec!["--nester", "shelf"];
    let budget = target_edges.map(|t| t.to_string());
    if let Some(b) = &budget {
        args.extend(["--target-edges", b]);
    }
    let manifest = build(scheme, model, size, &out, &args);
    let stem = model.file_stem().unwrap().to_string_lossy();
    let map_name = format!("{stem}-map.svg");
    let files: Vec<&str> = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert!(files.contains(&map_name.as_str()), "{files:?}");
    let svg = std::fs::read_to_string(out.join(&map_name)).unwrap();
    let views = read_map(&svg);
    let names: Vec<&str> = views.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["front", "back", "left", "right", "top", "bottom"]);

    let panel_ids: BTreeSet<String> = manifest["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p: &Value| p["id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(panel_ids.len(), count(&manifest, "counts.panels"));

    let mut o = options(scheme, size, 0, &out);
    o.holes = None;
    o.model.target_edges = target_edges.map(unfold::config::TargetEdges::Count);
    let mesh = common::build::pipeline(&resolve(o, model)).mesh;

    let mut named = BTreeSet::new();
    let mut checked = 0;
    for view in &views {
        for (id, at) in &view.ids {
            assert!(panel_ids.contains(id), "{}: {id} is no panel", view.name);
            let seen = face_seen(&mesh, view, *at);
            let own = faces_of(&mesh, id);
            assert!(
                seen.is_some_and(|f| own.contains(&f)),
                "{} view: {id} at {at} is drawn over face {seen:?}, not its own {own:?}",
                view.name
            );
            named.insert(id.clone());
            checked += 1;
        }
    }
    eprintln!(
        "{stem}: {} of {} panels named, {checked} ids checked",
        named.len(),
        panel_ids.len()
    );
    assert!(
        named.len() as f64 >= share * panel_ids.len() as f64,
        "{stem}: {} of {} panels named",
        named.len(),
        panel_ids.len()
    );
}

#[test]
fn the_map_of_genus3_names_its_faces_where_they_are_seen() {
    check_map(&model("genus3"), "half-edge", "300mm", None, 0.95);
}

#[test]
fn the_map_of_the_thesis_bunny_names_its_edges_where_they_are_seen() {
    let Some(shared) =
        shared_models("the_map_of_the_thesis_bunny_names_its_edges_where_they_are_seen")
    else {
        return;
    };
    check_map(
        &shared.join("stanford-bunny.obj"),
        "quad-edge",
        "4ft",
        Some(625),
        0.95,
    );
}

#[test]
fn woven_segments_are_named_along_their_ribbons() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let manifest = build(
        "woven",
        &model("torus-6x4"),
        "1ft",
        &out,
        &["--nester", "shelf"],
    );
    let svg = std::fs::read_to_string(out.join("torus-6x4-map.svg")).unwrap();
    let named: BTreeSet<String> = read_map(&svg)
        .into_iter()
        .flat_map(|v| v.ids.into_iter().map(|(id, _)| id))
        .collect();
    let panels = count(&manifest, "counts.panels");
    assert!(named.iter().all(|id| id.starts_with('C')), "{named:?}");
    assert!(
        named.len() * 100 >= 95 * panels,
        "{} of {panels}",
        named.len()
    );
}

#[test]
fn no_map_writes_none() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let manifest = build(
        "half-edge",
        &model("tetrahedron"),
        "200mm",
        &out,
        &["--no-map"],
    );
    assert!(!out.join("tetrahedron-map.svg").exists());
    assert!(
        !manifest["files"].to_string().contains("map.svg"),
        "{}",
        manifest["files"]
    );
}
