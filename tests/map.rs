//! The assembly map (`NAME-map.svg`), read back as a builder would use it: it names
//! nearly every panel, each id where its panel is seen — checked by casting a ray
//! into the model (the scheme's mesh, from the library's pipeline) at the id's place
//! on the page, through the view's own projection written on the view's group — and
//! `--no-map` turns it off.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::build::{build, count, model, options, resolve, shared_models};
use glam::{DVec2, DVec3};
use serde_json::Value;
use tempfile::TempDir;
use unfold::mesh::{EdgeId, FaceId, Mesh};

/// One view of the map: its projection and the ids written in it.
struct MapView {
    name: String,
    toward: DVec3,
    up: DVec3,
    scale: f64,
    origin: DVec2,
    ids: Vec<(String, DVec2)>,
}

fn attribute<'a>(tag: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let start = tag
        .find(&key)
        .unwrap_or_else(|| panic!("{name} missing in {tag}"))
        + key.len();
    let end = tag[start..].find('"').unwrap() + start;
    &tag[start..end]
}

fn numbers(text: &str) -> Vec<f64> {
    text.split_whitespace()
        .map(|n| n.parse().unwrap_or_else(|_| panic!("number {n}")))
        .collect()
}

fn vector(text: &str) -> DVec3 {
    let n = numbers(text);
    DVec3::new(n[0], n[1], n[2])
}

/// The views of a map and the panel ids in each (the `<text>`s centred on a point).
fn read_map(svg: &str) -> Vec<MapView> {
    let mut views = Vec::new();
    for chunk in svg.split("<g id=\"view-").skip(1) {
        let head_end = chunk.find('>').unwrap();
        let head = &chunk[..head_end];
        let body = &chunk[head_end..chunk.find("</g>").unwrap()];
        let origin = numbers(attribute(head, "data-origin"));
        let mut ids = Vec::new();
        for text in body.split("<text").skip(1) {
            let tag_end = text.find('>').unwrap();
            let tag = &text[..tag_end];
            if !tag.contains("text-anchor=\"middle\"") {
                continue;
            }
            let content = &text[tag_end + 1..text.find("</text>").unwrap()];
            let at = DVec2::new(
                attribute(tag, "x").parse().unwrap(),
                attribute(tag, "y").parse().unwrap(),
            );
            ids.push((content.to_string(), at));
        }
        views.push(MapView {
            name: attribute(head, "data-view").to_string(),
            toward: vector(attribute(head, "data-toward")),
            up: vector(attribute(head, "data-up")),
            scale: attribute(head, "data-scale").parse().unwrap(),
            origin: DVec2::new(origin[0], origin[1]),
            ids,
        });
    }
    views
}

/// The face a ray from the viewer meets first, cast at a page point of a view.
fn face_seen(mesh: &Mesh, view: &MapView, at: DVec2) -> Option<u32> {
    let right = (-view.toward).cross(view.up);
    let u = (at.x - view.origin.x) / view.scale;
    let v = -(at.y - view.origin.y) / view.scale;
    let start = u * right + v * view.up + 1e7 * view.toward;
    let dir = -view.toward;
    let mut best: Option<(f64, u32)> = None;
    for f in mesh.faces() {
        let pts: Vec<DVec3> = mesh.face_positions(f).collect();
        for k in 1..pts.len() - 1 {
            if let Some(t) = ray_triangle(start, dir, pts[0], pts[k], pts[k + 1]) {
                if best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, f.0));
                }
            }
        }
    }
    best.map(|(_, f)| f)
}

/// Möller–Trumbore: the distance along the ray to the triangle, if it meets it.
fn ray_triangle(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) / det;
    (t > 0.0).then_some(t)
}

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
