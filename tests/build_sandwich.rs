//! The two-layer sandwich of the edge schemes (`--thickness T --layers 2`): the layers
//! are rebuilt in 3D from what is cut (each flat facet mapped back by its unrolling)
//! and checked with this file's own geometry: each bend's inner layer is narrower by
//! T·θ, the layers stand T apart along every ruling, every covered point of a face has
//! one outer and one inner layer over it, and each pin goes through both.

use crate::common;

use std::path::Path;

use glam::{DVec2, DVec3};
use tempfile::TempDir;

use common::build::*;
use unfold::mesh::{EdgeId, FaceId, Mesh};
use unfold::panel::{Covers, FlatPanel, Panel};

/// The job of `unfold MODEL --scheme SCHEME --size SIZE --holes 2 --thickness T
/// --layers 2`.
fn sandwich_job(scheme: &str, model: &Path, size: &str, t: f64, out: &Path) -> unfold::config::Job {
    let mut o = options(scheme, size, 2, out);
    o.scheme_values.set("thickness", &format!("{t}mm"));
    o.scheme_values.set("layers", "2");
    resolve(o, model)
}

/// A layer rebuilt in 3D: its facets as 3D polygons, from the flat panel.
struct Layer {
    edge: u32,
    facets: Vec<Vec<DVec3>>,
    flat: FlatPanel,
    panel: Panel,
}

/// The signed turning of edge `e`'s bend: the angle between its faces' normals,
/// positive where the edge is convex.
fn turning(mesh: &Mesh, e: EdgeId) -> Option<f64> {
    let h = e.half_edge();
    let (f, g) = (mesh.face(h)?, mesh.face(h.twin())?);
    let (nf, ng) = (mesh.face_normal(f), mesh.face_normal(g));
    let angle = nf.cross(ng).length().atan2(nf.dot(ng));
    let convex = (mesh.face_centre(g) - mesh.face_centre(f)).dot(nf) < 0.0;
    Some(if convex { angle } else { -angle })
}

/// The bend's width as cut: the extent, across its fold lines (which all run along the
/// edge), of its strips, the facets in neither face's plane (a layer's flap may be
/// lapped away entirely, so its fold is not always there to measure from).
fn bend_width(mesh: &Mesh, layer: &Layer, depth: f64) -> f64 {
    let h = EdgeId(layer.edge).half_edge();
    let faces = [mesh.face(h).unwrap(), mesh.face(h.twin()).unwrap()];
    let in_face = |poly: &[DVec3]| {
        faces.iter().any(|&f| {
            let (n, c) = (
                mesh.face_normal(f),
                mesh.face_centre(f) - depth * mesh.face_normal(f),
            );
            poly.iter().all(|&q| (q - c).dot(n).abs() < 1e-6)
        })
    };
    let flat = &layer.flat;
    let fold = flat.folds.first().expect("a bend has folds");
    let (a, b) = (
        flat.points[fold.ends[0] as usize],
        flat.points[fold.ends[1] as usize],
    );
    let across = (b - a).normalize().perp();
    let offsets: Vec<f64> = layer
        .panel
        .facets
        .iter()
        .zip(&layer.facets)
        .filter(|(_, poly)| !in_face(poly))
        .flat_map(|(facet, _)| facet.iter().map(|&i| flat.points[i as usize].dot(across)))
        .collect();
    let max = offsets.iter().copied().fold(f64::MIN, f64::max);
    let min = offsets.iter().copied().fold(f64::MAX, f64::min);
    max - min
}

/// The distance from `p` to a planar polygon in 3D: its height over the plane, and
/// in the plane its distance to the polygon (none inside).
fn point_polygon(p: DVec3, poly: &[DVec3]) -> f64 {
    let normal = polygon_vector_area(poly).normalize();
    let ex = (poly[1] - poly[0]).normalize();
    let ey = normal.cross(ex);
    let to2 = |q: DVec3| DVec2::new((q - poly[0]).dot(ex), (q - poly[0]).dot(ey));
    let flat: Vec<DVec2> = poly.iter().map(|&q| to2(q)).collect();
    let height = (p - poly[0]).dot(normal);
    let across = if inside(&flat, to2(p)) {
        0.0
    } else {
        distance_to_border(&flat, to2(p))
    };
    height.hypot(across)
}

/// Builds both layers of every panel and checks the sandwich; returns the number of
/// bends checked, the largest width error and the largest gap error (mm).
fn check_sandwich(scheme: &str, model: &Path, size: &str, t: f64, tmp: &Path) -> (usize, f64, f64) {
    let name = format!(
        "{} ({scheme})",
        model.file_stem().unwrap().to_string_lossy()
    );
    let p = pipeline(&sandwich_job(scheme, model, size, t, &tmp.join("job")));
    let mesh = &p.mesh;
    assert_eq!(
        p.panels.len(),
        2 * mesh.edge_count(),
        "{name}: two layers per edge"
    );
    let frames = frames_of(&p.panels);
    let mut outer: Vec<Option<Layer>> = (0..mesh.edge_count()).map(|_| None).collect();
    let mut inner: Vec<Option<Layer>> = (0..mesh.edge_count()).map(|_| None).collect();
    for ((panel, flat), frames) in p.panels.iter().zip(&p.flat).zip(&frames) {
        // What is cut is the part: every facet maps back onto its 3D corners.
        let facets: Vec<Vec<DVec3>> = panel
            .facets
            .iter()
            .zip(frames)
            .map(|(facet, frame)| {
                facet
                    .iter()
                    .map(|&i| {
                        let q = frame.to_3d(flat.points[i as usize]);
                        let want = panel.vertices[i as usize];
                        assert!(q.distance(want) < 1e-6, "{}: {q} is not {want}", panel.id());
                        q
                    })
                    .collect()
            })
            .collect();
        let id = panel.id().to_string();
        let (slot, edge) = match panel.source.covers {
            Covers::Edge(e) => (&mut outer, e),
            Covers::Inside(e) => (&mut inner, e),
            other => panic!("{id}: a layer covers {other:?}"),
        };
        let letter = if matches!(panel.source.covers, Covers::Edge(_)) {
            "E"
        } else {
            "I"
        };
        assert_eq!(
            id,
            format!("{letter}{edge}"),
            "{name}: the id names the layer and edge"
        );
        slot[edge as usize] = Some(Layer {
            edge,
            facets,
            flat: flat.clone(),
            panel: panel.clone(),
        });
    }
    let outer: Vec<Layer> = outer
        .into_iter()
        .map(|l| l.expect("every outer layer"))
        .collect();
    let inner: Vec<Layer> = inner
        .into_iter()
        .map(|l| l.expect("every inner layer"))
        .collect();

    // Each bend's inner layer is narrower by T·θ (wider at a concave edge).
    let (mut bends, mut worst_width, mut worst_gap) = (0, 0.0f64, 0.0f64);
    for (o, i) in outer.iter().zip(&inner) {
        let Some(theta) = turning(mesh, EdgeId(o.edge)) else {
            continue;
        };
        if theta.abs() < 1e-6 {
            continue;
        }
        let (wo, wi) = (bend_width(mesh, o, 0.0), bend_width(mesh, i, t));
        let error = (wo - wi - t * theta).abs();
        assert!(
            error <= 0.02,
            "{name}: E{}: outer {wo} mm wide, inner {wi} mm, not T·θ = {} mm apart",
            o.edge,
            t * theta
        );
        worst_width = worst_width.max(error);
        bends += 1;
        // Along every ruling of the inner layer (its fold lines, mapped back), the
        // outer layer is T away.
        for fold in &i.flat.folds {
            for end in fold.ends {
                let q = i.panel.vertices[end as usize];
                let gap = o
                    .facets
                    .iter()
                    .map(|poly| point_polygon(q, poly))
                    .fold(f64::MAX, f64::min);
                assert!(
                    (gap - t).abs() <= 0.05,
                    "{name}: I{} stands {gap} mm from E{} at {q}",
                    o.edge,
                    o.edge
                );
                worst_gap = worst_gap.max((gap - t).abs());
            }
        }
    }

    check_laps(&name, mesh, &outer, &inner, t);
    check_pins(&name, &outer, &inner, t);

    // The command line cuts both layers: every sheet passes the independent check, the
    // manifest names each panel's layer and the assembled model holds both.
    let out = tmp.join("out");
    let thickness = format!("{t}mm");
    let extra = [
        "--format",
        "svg,dxf",
        "--thickness",
        &thickness,
        "--layers",
        "2",
    ];
    let m = build(scheme, model, size, &out, &extra);
    check_output(model, &out, &m, &name, DxfCheck::FirstAndLast, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    assert_eq!(count(&m, "counts.panels"), 2 * mesh.edge_count());
    for entry in m["panels"].as_array().unwrap() {
        let id = entry["id"].as_str().unwrap();
        let layer = if id.starts_with('E') {
            "outer"
        } else {
            "inner"
        };
        assert_eq!(entry["source"]["layer"], layer, "{name}: {id}");
    }
    let stem = model.file_stem().unwrap().to_string_lossy();
    let obj = std::fs::read_to_string(out.join(format!("{stem}-assembled.obj"))).unwrap();
    let objects = obj.lines().filter(|l| l.starts_with("o ")).count();
    assert_eq!(
        objects,
        2 * mesh.edge_count(),
        "{name}: both layers in the assembled model"
    );
    (bends, worst_width, worst_gap)
}

/// The flap facets of `layers` in face `f`'s plane moved `depth` inward, in the face's
/// 2D frame.
fn flaps_in(mesh: &Mesh, f: FaceId, layers: &[Layer], depth: f64) -> Vec<Vec<DVec2>> {
    let n = mesh.face_normal(f);
    let c = mesh.face_centre(f) - depth * n;
    let ex = n.any_orthonormal_vector();
    let ey = n.cross(ex);
    layers
        .iter()
        .flat_map(|l| &l.facets)
        .filter(|poly| {
            let normal = polygon_vector_area(poly).normalize();
            normal.dot(n) > 1.0 - 1e-9 && poly.iter().all(|&q| (q - c).dot(n).abs() < 1e-6)
        })
        .map(|poly| {
            poly.iter()
                .map(|&q| DVec2::new((q - c).dot(ex), (q - c).dot(ey)))
                .collect()
        })
        .collect()
}

/// Every point of a face that flaps cover has exactly one outer and one inner layer
/// over it (sampled on a grid off the flaps' borders).
fn check_laps(name: &str, mesh: &Mesh, outer: &[Layer], inner: &[Layer], t: f64) {
    for f in mesh.faces() {
        let (o, i) = (flaps_in(mesh, f, outer, 0.0), flaps_in(mesh, f, inner, t));
        assert!(
            !o.is_empty() && !i.is_empty(),
            "{name}: F{} has flaps in both layers",
            f.0
        );
        let all: Vec<DVec2> = o.iter().flatten().copied().collect();
        let lo = all.iter().copied().fold(DVec2::MAX, DVec2::min);
        let hi = all.iter().copied().fold(DVec2::MIN, DVec2::max);
        let steps = 60;
        let mut covered = 0;
        for a in 0..steps {
            for b in 0..steps {
                let q = lo
                    + (hi - lo)
                        * DVec2::new(
                            (a as f64 + 0.37) / steps as f64,
                            (b as f64 + 0.61) / steps as f64,
                        );
                let near_border = o
                    .iter()
                    .chain(&i)
                    .any(|poly| distance_to_border(poly, q) < 1e-6);
                if near_border {
                    continue;
                }
                let count =
                    |polys: &[Vec<DVec2>]| polys.iter().filter(|poly| inside(poly, q)).count();
                let (co, ci) = (count(&o), count(&i));
                assert!(
                    co == ci && co <= 1,
                    "{name}: at {q} in F{}, {co} outer and {ci} inner layers",
                    f.0
                );
                covered += co;
            }
        }
        assert!(covered > 0, "{name}: F{}: no flap sampled", f.0);
    }
}

/// Every pin goes through both layers and joins two panels: each hole of an outer
/// layer has one of an inner layer, of the same connection, T behind it along the
/// face's normal, in the other panel of the connection (the layers lap, so the pin
/// holds the two panels together), and the other way round.
fn check_pins(name: &str, outer: &[Layer], inner: &[Layer], t: f64) {
    let holes = |layers: &[Layer]| -> Vec<(DVec3, u32, DVec3, u32)> {
        layers
            .iter()
            .flat_map(|l| {
                l.panel.holes.iter().map(|h| {
                    let facet = &l.facets[h.facet as usize];
                    (
                        h.position,
                        h.connection,
                        polygon_vector_area(facet).normalize(),
                        l.edge,
                    )
                })
            })
            .collect()
    };
    let (ho, hi) = (holes(outer), holes(inner));
    assert!(!ho.is_empty(), "{name}: pins");
    assert_eq!(ho.len(), hi.len(), "{name}: as many holes in each layer");
    for (p, connection, normal, edge) in &ho {
        let behind = *p - t * *normal;
        let found: Vec<u32> = hi
            .iter()
            .filter(|(q, c, _, _)| c == connection && q.distance(behind) < 1e-6)
            .map(|h| h.3)
            .collect();
        assert_eq!(
            found.len(),
            1,
            "{name}: the pin at {p} (connection {connection}) meets no inner hole"
        );
        assert_ne!(
            found[0], *edge,
            "{name}: the pin at {p} holds E{edge} to its own inner layer only"
        );
    }
}

#[test]
fn sandwich_layers_are_t_apart_and_narrower_by_t_theta() {
    let tmp = TempDir::new().unwrap();
    for (scheme, model_name, size) in [
        ("quad-edge", "tetrahedron", "200mm"),
        ("quad-edge", "hexahedron", "200mm"),
        ("quad-edge", "icosahedron", "200mm"),
        ("quad-edge", "torus-8x6", "300mm"),
        ("winged-edge", "hexahedron", "200mm"),
        ("winged-edge", "torus-8x6", "300mm"),
    ] {
        let (bends, width, gap) = check_sandwich(scheme, &model(model_name), size, 3.0, tmp.path());
        eprintln!("{model_name} ({scheme}): {bends} bends, widths within {width:.4} mm of T·θ, layers within {gap:.4} mm of T");
        assert!(bends > 0);
    }
}

#[test]
fn a_simplified_shared_model_in_two_layers_of_card() {
    let Some(shared) = shared_models("two-layer sandwich") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    // About 300 faces: 450 edges of a closed triangle mesh; 0.3 mm card at 700 mm.
    let simple = simplified_obj(&shared.join("spot.obj"), 450, true, tmp.path());
    let (bends, width, gap) = check_sandwich("quad-edge", &simple, "700mm", 0.3, tmp.path());
    eprintln!(
        "spot: {bends} bends, widths within {width:.4} mm of T·θ, layers within {gap:.4} mm of T"
    );
    assert_eq!(bends, 450);
}

#[test]
fn a_sandwich_is_the_same_on_one_and_two_threads() {
    assert_same_bytes_on_one_and_two_threads(
        &model("torus-8x6"),
        &[
            "--scheme",
            "quad-edge",
            "--size",
            "300mm",
            "--thickness",
            "3mm",
            "--layers",
            "2",
        ],
    );
}

#[test]
fn a_bend_tighter_than_the_card_is_refused_with_what_rounds_it() {
    let tmp = TempDir::new().unwrap();
    let cube = model("hexahedron");
    let out = tmp.path().join("out");
    let run = |size: &str, extra: &[&str]| {
        let mut args = vec![
            cube.to_str().unwrap(),
            "--scheme",
            "quad-edge",
            "--size",
            size,
            "--thickness",
            "1mm",
            "--layers",
            "2",
            "--holes",
            "0",
            "--build-anyway",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        unfold(args)
    };
    // A 10 mm cube's bends turn on a radius of 1.8 mm, short of the 2 mm of two layers
    // of 1 mm card.
    let refused = run("10mm", &[]);
    assert_refusal(
        "1 mm card on a 10 mm cube",
        &refused,
        2,
        &["E0", "1.768 mm", "--face-scale", "--size"],
    );
    assert!(!out.exists(), "nothing written");
    let said = |key: &str| -> String {
        let at = refused.stderr.find(key).unwrap() + key.len();
        refused.stderr[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .to_string()
    };
    let (face_scale, size) = (said("--face-scale "), said("or --size "));
    for (size, extra) in [
        ("10mm", vec!["--face-scale", face_scale.as_str()]),
        (size.as_str(), vec![]),
    ] {
        let built = run(size, &extra);
        assert_eq!(built.code, Some(0), "{size} {extra:?}: {}", built.stderr);
        std::fs::remove_dir_all(&out).unwrap();
    }
}

#[test]
fn the_sandwich_options_are_checked() {
    let tmp = TempDir::new().unwrap();
    let cube = model("hexahedron");
    let out = tmp.path().join("out");
    for (extra, says) in [
        (vec!["--layers", "2"], "--thickness"),
        (vec!["--thickness", "1mm"], "--layers 2"),
        (
            vec!["--thickness", "1mm", "--layers", "3"],
            "must be 1 or 2",
        ),
        (vec!["--connectors", "bracket"], "half-edge"),
        (
            vec![
                "--scheme",
                "winged-edge",
                "--thickness",
                "1mm",
                "--layers",
                "2",
                "--shift",
                "1",
            ],
            "--shift",
        ),
    ] {
        let mut args = vec![
            cube.to_str().unwrap(),
            "--scheme",
            "quad-edge",
            "--size",
            "200mm",
        ];
        args.extend(extra.iter().copied());
        args.extend(["--out", out.to_str().unwrap()]);
        assert_refusal(says, &unfold(args), 2, &[says]);
        assert!(!out.exists());
    }
}

#[test]
fn an_open_mesh_in_two_layers_counts_the_boundary_panels_cut_once() {
    let tmp = TempDir::new().unwrap();
    let grid = model("open-grid");
    let out = tmp.path().join("out");
    let extra = ["--format", "svg,dxf", "--thickness", "1mm", "--layers", "2"];
    let m = build("winged-edge", &grid, "400mm", &out, &extra);
    check_output(
        &grid,
        &out,
        &m,
        "open grid (winged-edge)",
        DxfCheck::FirstAndLast,
        |e| e["id"].as_str().unwrap().to_string(),
    );
    // A boundary edge's panel is its flap alone; where the neighbouring flaps take its
    // ground in a layer, that layer has no part of it, and the report counts them.
    let (edges, panels) = (count(&m, "input.edges"), count(&m, "counts.panels"));
    let run = unfold([
        grid.to_str().unwrap(),
        "--scheme",
        "winged-edge",
        "--size",
        "400mm",
        "--thickness",
        "1mm",
        "--layers",
        "2",
        "--build-anyway",
        "--out",
        tmp.path().join("again").to_str().unwrap(),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let line = run
        .stderr
        .lines()
        .find(|l| l.contains("boundary panels are cut in one layer only"))
        .expect("the note of panels cut once");
    let once = number_after(line, "note: ").unwrap();
    assert!(once > 0, "{line}");
    assert_eq!(panels, 2 * edges - once);
}
