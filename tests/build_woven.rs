//! End-to-end tests of the woven scheme (SPEC.md §2, woven): the cycle facts of the
//! platonic solids and tori in the manifest, every sheet through the independent
//! checker, the two strands at every crossing exactly the material thickness apart
//! (over above, under below), over and under alternating along every ribbon, the holes
//! of every lap joint meeting in 3D, no two ribbons passing through each other,
//! byte-identical output on 1 and 2 threads, and golden files of the tetrahedron.
//!
//! `UNFOLD_UPDATE_GOLDEN=1 cargo test --test build_woven golden` rewrites
//! `tests/golden/tetrahedron-woven/`.

use crate::common;

use std::collections::BTreeMap;

use glam::DVec3;
use tempfile::TempDir;

use common::build::{
    assert_same_bytes_on_one_and_two_threads, build, check_output, count, frames_of, golden_build,
    model, options, pipeline, resolve, DxfCheck,
};
use unfold::mesh::geometry::vector_area;
use unfold::scheme::woven::options::WovenOptions;
use unfold::scheme::woven::ribbon::{ribbons, PieceKind};
use unfold::scheme::OptionValues;

/// Model, number of cycles, edges per cycle (all equal here).
const WEAVES: [(&str, usize, usize); 7] = [
    ("tetrahedron", 3, 4),
    ("hexahedron", 4, 6),
    ("octahedron", 4, 6),
    ("icosahedron", 6, 10),
    ("dodecahedron", 6, 10),
    // n×m quad tori: 2·gcd(n, m) cycles crossing 2nm/cycles edges each.
    ("torus-6x4", 4, 24),
    ("torus-8x6", 4, 48),
];

fn woven_job(name: &str, size: &str, out: &std::path::Path) -> unfold::Job {
    resolve(options("woven", size, 2, out), &model(name))
}

#[test]
fn the_weave_facts_hold_and_every_sheet_checks() {
    let tmp = TempDir::new().unwrap();
    for (name, cycles, edges) in WEAVES {
        let out = tmp.path().join(name);
        let m = build(
            "woven",
            &model(name),
            "200mm",
            &out,
            &["--format", "svg,dxf"],
        );
        let list = m["cycles"].as_array().expect("a cycle list");
        assert_eq!(list.len(), cycles, "{name}: cycle list");
        let mut segments = 0;
        for (k, cycle) in list.iter().enumerate() {
            assert_eq!(cycle["id"], format!("C{}", k + 1).as_str());
            assert_eq!(count(cycle, "edges"), edges, "{name}: edges per cycle");
            assert!(cycle["length"].as_f64().unwrap() > 0.0);
            segments += count(cycle, "segments");
        }
        // Every edge is crossed twice.
        assert_eq!(cycles * edges, 2 * count(&m, "input.edges"), "{name}");
        // One panel per segment, one lap joint per segment.
        assert_eq!(count(&m, "counts.panels"), segments, "{name}: panels");
        assert_eq!(count(&m, "counts.connections"), segments, "{name}: joints");
        check_output(&model(name), &out, &m, name, DxfCheck::FirstAndLast, |p| {
            format!("C{}.{}", p["source"]["cycle"], p["source"]["segment"])
        });
        let max = m["max_developability_error"].as_f64().unwrap();
        assert!(max < 1e-9 * 200.0, "{name}: developability {max}");
    }
}

#[test]
fn strands_cross_the_thickness_apart_and_alternate() {
    let tmp = TempDir::new().unwrap();
    for (name, _, _) in WEAVES {
        let job = woven_job(name, "200mm", tmp.path());
        let p = pipeline(&job);
        // The job takes the woven defaults.
        let woven = &WovenOptions::resolve(&OptionValues::default(), job.scheme.panel().clone())
            .expect("woven options");
        let r = woven.thickness;
        assert!((r - 2.54).abs() < 1e-12, "default thickness 0.1 in");
        let (rings, _) = ribbons(&p.mesh, woven).unwrap();
        // Per edge: (over, the edge piece's corners) for both strands.
        let mut at_edge: BTreeMap<u32, Vec<(bool, Vec<DVec3>)>> = BTreeMap::new();
        for ring in &rings {
            let mut overs = Vec::new();
            for (k, piece) in ring.pieces.iter().enumerate() {
                if let PieceKind::Edge { edge, over, .. } = *piece {
                    let points: Vec<DVec3> = ring.facet_points(k).concat();
                    at_edge.entry(edge.0).or_default().push((over, points));
                    overs.push(over);
                }
            }
            assert_eq!(overs.len() % 2, 0, "{name}: an even number of crossings");
            for k in 0..overs.len() {
                assert_ne!(
                    overs[k],
                    overs[(k + 1) % overs.len()],
                    "{name}: C{}: over and under alternate",
                    ring.cycle + 1
                );
            }
        }
        assert_eq!(at_edge.len(), p.mesh.edge_count(), "{name}: every edge");
        for (edge, strands) in &at_edge {
            assert_eq!(strands.len(), 2, "{name}: edge {edge} crossed twice");
            let over = strands.iter().find(|s| s.0).expect("one strand over");
            let under = strands.iter().find(|s| !s.0).expect("one strand under");
            // The under piece's plane, its normal toward the outside.
            let e = unfold::mesh::EdgeId(*edge);
            let h = e.half_edge();
            let outward = p.mesh.face_normal(p.mesh.face(h).unwrap())
                + p.mesh.face_normal(p.mesh.face(h.twin()).unwrap());
            let mut normal = vector_area(under.1.iter().copied()).normalize();
            if normal.dot(outward) < 0.0 {
                normal = -normal;
            }
            let base = under.1[0];
            for q in &under.1 {
                assert!((*q - base).dot(normal).abs() < 1e-9, "{name}: planar");
            }
            for q in &over.1 {
                let height = (*q - base).dot(normal);
                assert!(
                    (height - r).abs() < 1e-9 * 200.0,
                    "{name}: edge {edge}: the over strand is {height} mm above the under one, not {r}"
                );
            }
        }
    }
}

#[test]
fn the_holes_of_a_lap_joint_meet_in_3d() {
    let tmp = TempDir::new().unwrap();
    for name in ["tetrahedron", "hexahedron", "icosahedron", "torus-6x4"] {
        let job = woven_job(name, "200mm", tmp.path());
        let p = pipeline(&job);
        let mut by_joint: BTreeMap<u32, Vec<(String, u32, DVec3)>> = BTreeMap::new();
        for (flat, frames) in p.flat.iter().zip(frames_of(&p.panels)) {
            for hole in &flat.holes {
                let back = frames[hole.facet as usize].to_3d(hole.center);
                by_joint.entry(hole.connection).or_default().push((
                    flat.id().to_string(),
                    hole.facet,
                    back,
                ));
            }
        }
        assert!(!by_joint.is_empty(), "{name}: joints with holes");
        for (joint, holes) in &by_joint {
            assert_eq!(holes.len() % 2, 0, "{name}: joint {joint}: holes in pairs");
            for (id, facet, a) in holes {
                let partner = holes.iter().find(|(other, other_facet, b)| {
                    (other != id || other_facet != facet) && a.distance(*b) < 1e-9 * 200.0
                });
                assert!(
                    partner.is_some(),
                    "{name}: joint {joint}: a hole of {id} has no partner at the same 3D point"
                );
            }
        }
    }
}

/// True when segment p–q passes through the interior of triangle abc.
fn segment_crosses_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let (dp, dq) = ((p - t[0]).dot(n), (q - t[0]).dot(n));
    if dp * dq > 0.0 || (dp - dq).abs() < 1e-15 {
        return false;
    }
    let s = dp / (dp - dq);
    if !(1e-7..=1.0 - 1e-7).contains(&s) {
        return false;
    }
    let x = p + s * (q - p);
    let (v0, v1, v2) = (t[1] - t[0], t[2] - t[0], x - t[0]);
    let (d00, d01, d11, d20, d21) = (v0.dot(v0), v0.dot(v1), v1.dot(v1), v2.dot(v0), v2.dot(v1));
    let den = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    v > 1e-7 && w > 1e-7 && 1.0 - v - w > 1e-7
}

/// A lap joint without a hole is an unfastened connection like any other: the
/// scheme lists it (the two segments, the vertex of its corner), the manifest counts
/// it under 0 holes, the build warns, and `--strict` refuses it without writing
/// anything. At 1 ft the 6 × 4 torus holds both holes at every joint; at 180 mm the
/// strands of its inner corners are too narrow for a 1/8 in hole.
#[test]
fn lap_joints_without_a_hole_are_unfastened() {
    let tmp = TempDir::new().unwrap();
    let fastened = woven_job("torus-6x4", "1ft", tmp.path());
    let p = pipeline(&fastened);
    assert!(p.output.unfastened.is_empty(), "{:?}", p.output.unfastened);
    let m = build(
        "woven",
        &model("torus-6x4"),
        "1ft",
        &tmp.path().join("1ft"),
        &[],
    );
    let joints = count(&m, "counts.connections");
    assert_eq!(
        m["counts"]["connections_by_holes"],
        serde_json::json!({ "2": joints })
    );

    let narrow = woven_job("torus-6x4", "180mm", tmp.path());
    let p = pipeline(&narrow);
    let bare = &p.output.unfastened;
    let out = tmp.path().join("180mm");
    let m = build("woven", &model("torus-6x4"), "180mm", &out, &[]);
    let by_holes = &m["counts"]["connections_by_holes"];
    assert!(!bare.is_empty() && bare.len() < joints, "{bare:?}");
    assert_eq!(count(by_holes, "0"), bare.len(), "{by_holes}");
    // The holes the joints do have are in pairs on the two segments' panels.
    let holes: usize = p.flat.iter().map(|f| f.holes.len()).sum();
    assert_eq!(holes, count(&m, "counts.holes"));
    assert_eq!(
        holes,
        2 * 2 * count(by_holes, "2") + 2 * by_holes["1"].as_u64().unwrap_or(0) as usize
    );
    let segments: std::collections::BTreeSet<String> =
        p.flat.iter().map(|f| f.id().to_string()).collect();
    for c in bare {
        for panel in &c.panels {
            assert!(
                segments.contains(&panel.to_string()),
                "{c}: no panel {panel}"
            );
        }
        assert!(c.at.to_string().starts_with('V'), "{c}");
        // The two segments share that joint (and the other one too when they are all
        // of their cycle): no hole of theirs goes through both but the other's.
        let ids = |name: &unfold::panel::Name| -> std::collections::BTreeSet<u32> {
            let flat = p
                .flat
                .iter()
                .find(|f| f.id().to_string() == name.to_string());
            flat.into_iter()
                .flat_map(|f| &f.holes)
                .map(|h| h.connection)
                .collect()
        };
        let shared = ids(&c.panels[0]).intersection(&ids(&c.panels[1])).count();
        let cycle = c.panels[0].to_string();
        let cycle = cycle.split('.').next().unwrap();
        let of_cycle = segments
            .iter()
            .filter(|s| s.split('.').next() == Some(cycle))
            .count();
        assert!(
            shared < if of_cycle == 2 { 2 } else { 1 },
            "{c}: {shared} shared joints hold holes"
        );
    }
    let warnings = m["warnings"].to_string();
    assert!(warnings.contains("fastener hole"), "{warnings}");

    let strict = tmp.path().join("strict");
    let run = common::build::unfold([
        model("torus-6x4").to_str().unwrap(),
        "--scheme",
        "woven",
        "--size",
        "180mm",
        "--strict",
        "--out",
        strict.to_str().unwrap(),
    ]);
    // A third of the joints without a hole: the build stops before the nest.
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains("stopped before laying out the sheets"),
        "{}",
        run.stderr
    );
    assert!(!strict.exists(), "--strict wrote {}", strict.display());
}

#[test]
fn ribbons_do_not_pass_through_each_other() {
    let tmp = TempDir::new().unwrap();
    for name in [
        "tetrahedron",
        "hexahedron",
        "octahedron",
        "icosahedron",
        "torus-8x6",
    ] {
        let job = woven_job(name, "200mm", tmp.path());
        let p = pipeline(&job);
        let mut triangles: Vec<[DVec3; 3]> = Vec::new();
        for panel in &p.panels {
            for facet in &panel.facets {
                let v = |i: u32| panel.vertices[i as usize];
                for k in 1..facet.len() - 1 {
                    triangles.push([v(facet[0]), v(facet[k]), v(facet[k + 1])]);
                }
            }
        }
        let bounds: Vec<(DVec3, DVec3)> = triangles
            .iter()
            .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
            .collect();
        let mut crossings = 0;
        for i in 0..triangles.len() {
            for j in i + 1..triangles.len() {
                let (a, b) = (bounds[i], bounds[j]);
                if a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any() {
                    continue;
                }
                let (s, t) = (triangles[i], triangles[j]);
                // The two copies of a lap joint coincide; that is not a crossing.
                if s.iter().all(|p| t.iter().any(|q| p.distance(*q) < 1e-9)) {
                    continue;
                }
                let crosses = (0..3).any(|k| segment_crosses_triangle(s[k], s[(k + 1) % 3], t))
                    || (0..3).any(|k| segment_crosses_triangle(t[k], t[(k + 1) % 3], s));
                crossings += usize::from(crosses);
            }
        }
        assert_eq!(
            crossings, 0,
            "{name}: ribbon triangles pass through each other"
        );
    }
}

#[test]
fn output_is_the_same_on_one_and_two_threads() {
    assert_same_bytes_on_one_and_two_threads(
        &model("torus-6x4"),
        &["--scheme", "woven", "--size", "200mm"],
    );
}

#[test]
fn a_mesh_with_holes_or_bad_woven_options_are_refused() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let refused = |name: &str, extra: &[&str]| {
        let model = model(name);
        let mut args = vec![
            model.to_string_lossy().into_owned(),
            "--scheme".into(),
            "woven".into(),
            "--size".into(),
            "200mm".into(),
            "--out".into(),
            out.to_string_lossy().into_owned(),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        common::build::unfold(&args)
    };
    let run = refused("open-cylinder", &[]);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("open-cylinder.obj"), "{}", run.stderr);
    assert!(run.stderr.contains("closed mesh"), "{}", run.stderr);
    assert!(!out.exists(), "no output folder");
    for (option, value) in [
        ("--face-scale", "1"),
        ("--band-scale", "1"),
        ("--band-scale", "0"),
        ("--thickness", "-1mm"),
        ("--thickness", "1e300mm"),
        ("--holes", "4"),
        ("--curl-limit", "1"),
    ] {
        let arg = format!("{option}={value}");
        let run = refused("tetrahedron", &[&arg]);
        assert_eq!(run.code, Some(2), "{arg}: {}", run.stderr);
        assert!(run.stderr.contains(&option[2..]), "{arg}: {}", run.stderr);
        assert!(!out.exists(), "{arg}: no output folder");
    }
}

#[test]
fn flat_ribbons_without_thickness_have_no_turns() {
    let tmp = TempDir::new().unwrap();
    let mut o = options("woven", "200mm", 2, tmp.path());
    o.scheme_values.set("thickness", "0mm");
    let job = resolve(o, &model("hexahedron"));
    let p = pipeline(&job);
    for panel in &p.panels {
        assert!(
            panel.facets.iter().all(|f| f.len() == 4),
            "{}: with no thickness every piece is one planar quad",
            panel.id()
        );
    }
}

#[test]
fn a_tighter_curl_limit_cuts_straighter_segments() {
    let tmp = TempDir::new().unwrap();
    let mut segments = Vec::new();
    for limit in ["3", "1.5"] {
        let out = tmp.path().join(limit);
        let arg = format!("--curl-limit={limit}");
        let m = build("woven", &model("torus-8x6"), "12in", &out, &[&arg]);
        assert_eq!(
            m["scheme"]["params"]["curl_limit"].as_f64(),
            Some(limit.parse().unwrap())
        );
        segments.push(count(&m, "counts.panels"));
    }
    assert!(
        segments[1] > segments[0],
        "curl limit 1.5 gives more segments than 3: {segments:?}"
    );
}

#[test]
fn golden_tetrahedron() {
    let Some((_tmp, _out, m)) = golden_build(
        "build_woven",
        "tetrahedron-woven",
        "tetrahedron",
        &["--scheme", "woven", "--size", "200mm"],
    ) else {
        return;
    };
    assert_eq!(m["cycles"].as_array().map(Vec::len), Some(3));
}
