//! Rigid panels (`--thickness` with the half-edge scheme): the parts are rebuilt in 3D
//! from what is cut (each flat outline mapped back onto its face plane by its unrolling
//! and moved inward by the thickness) and checked with this file's own geometry: no two
//! parts pass into each other, none sticks out of the model, and the outer surface left
//! open along each edge is no wider than the angle there makes necessary.

use crate::common;

use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec2, DVec3};
use tempfile::TempDir;

use common::build::*;
use unfold::mesh::{FaceId, Mesh};
use unfold::panel::Covers;

/// Material thickness of the tests (mm).
const T: f64 = 3.0;

/// How far two parts may pass into each other, or one out of the model (mm).
const OVERLAP: f64 = 0.01;

/// A part rebuilt in 3D: its outer polygon on its face plane and the same moved inward.
struct Part {
    face: u32,
    outer: Vec<DVec3>,
    normal: DVec3,
}

impl Part {
    fn corners(&self) -> Vec<DVec3> {
        let inner = self.outer.iter().map(|&p| p - T * self.normal);
        self.outer.iter().copied().chain(inner).collect()
    }

    fn sides(&self) -> Vec<DVec3> {
        let n = self.outer.len();
        (0..n)
            .map(|k| (self.outer[(k + 1) % n] - self.outer[k]).normalize())
            .collect()
    }
}

/// The job of `unfold MODEL --size SIZE --thickness 3mm`.
fn rigid_job(model: &Path, size: &str, out: &Path) -> unfold::config::Job {
    let mut o = options("half-edge", size, 0, out);
    o.scheme_values.set("thickness", &format!("{T}mm"));
    resolve(o, model)
}

/// The parts of a rigid build, rebuilt from the flat panels, and the mesh they cover.
fn rebuilt_parts(model: &Path, size: &str, out: &Path) -> (Mesh, Vec<Part>) {
    let job = rigid_job(model, size, out);
    let p = pipeline(&job);
    let frames = frames_of(&p.panels);
    let mut parts = Vec::new();
    for ((panel, flat), frames) in p.panels.iter().zip(&p.flat).zip(&frames) {
        let Covers::Face(face) = panel.source.covers else {
            panic!("{}: a rigid panel covers one face", panel.id());
        };
        assert_eq!(panel.facets.len(), 1, "{}: one flat facet", panel.id());
        assert_eq!(
            flat.outline.len(),
            1,
            "{}: one outline, no inner cut",
            panel.id()
        );
        let outer: Vec<DVec3> = flat.outline[0]
            .iter()
            .map(|&i| frames[0].to_3d(flat.points[i as usize]))
            .collect();
        // What is cut is the panel: every corner maps back onto the 3D corner.
        for (&i, q) in flat.outline[0].iter().zip(&outer) {
            let want = panel.vertices[i as usize];
            assert!(
                q.distance(want) < 1e-6,
                "{}: corner {i} maps to {q}, not {want}",
                panel.id()
            );
        }
        let normal = p.mesh.face_normal(FaceId(face));
        let area = vector_area(&outer);
        assert!(
            area.dot(normal) > 0.0,
            "{}: its outer face looks inward",
            panel.id()
        );
        let on_plane = outer
            .iter()
            .map(|&q| (q - p.mesh.face_centre(FaceId(face))).dot(normal).abs())
            .fold(0.0, f64::max);
        assert!(
            on_plane < 1e-6,
            "{}: {on_plane} mm off its face plane",
            panel.id()
        );
        let part = Part {
            face,
            outer,
            normal,
        };
        assert!(
            is_convex(&part),
            "{}: the faces are convex, so is each part",
            panel.id()
        );
        parts.push(part);
    }
    assert_eq!(parts.len(), p.mesh.face_count());
    (p.mesh, parts)
}

fn vector_area(points: &[DVec3]) -> DVec3 {
    let n = points.len();
    (0..n)
        .map(|k| points[k].cross(points[(k + 1) % n]))
        .sum::<DVec3>()
        * 0.5
}

fn is_convex(part: &Part) -> bool {
    let sides = part.sides();
    let n = sides.len();
    (0..n).all(|k| sides[k].cross(sides[(k + 1) % n]).dot(part.normal) > -1e-9)
}

/// How deep two convex parts pass into each other (mm): the least overlap of their
/// projections over the separating-axis candidates (face normals and cross products of
/// edge directions); zero when an axis separates them.
fn penetration(a: &Part, b: &Part) -> f64 {
    let axes_of = |p: &Part| {
        let mut normals: Vec<DVec3> = p.sides().iter().map(|s| s.cross(p.normal)).collect();
        normals.push(p.normal);
        normals
    };
    let edges_of = |p: &Part| {
        let mut edges = p.sides();
        edges.push(p.normal);
        edges
    };
    let mut axes = axes_of(a);
    axes.extend(axes_of(b));
    for e in edges_of(a) {
        for f in edges_of(b) {
            let c = e.cross(f);
            if c.length() > 1e-6 {
                axes.push(c.normalize());
            }
        }
    }
    let (ca, cb) = (a.corners(), b.corners());
    let span = |c: &[DVec3], axis: DVec3| {
        c.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.dot(axis)), hi.max(p.dot(axis)))
        })
    };
    let mut least = f64::MAX;
    for axis in axes {
        let (a_lo, a_hi) = span(&ca, axis);
        let (b_lo, b_hi) = span(&cb, axis);
        let overlap = (a_hi - b_lo).min(b_hi - a_lo);
        if overlap <= 0.0 {
            return 0.0;
        }
        least = least.min(overlap);
    }
    least
}

/// How many times the closed mesh winds around `p` (1 inside, 0 outside), by the
/// solid angles of its triangles.
fn winding(triangles: &[[DVec3; 3]], p: DVec3) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|q| q - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * PI)
}

/// Distance from `p` to a 2D convex polygon (zero inside).
fn outside_by(poly: &[DVec2], p: DVec2) -> f64 {
    if inside(poly, p) {
        0.0
    } else {
        distance_to_border(poly, p)
    }
}

/// Checks the parts of a rigid build of `model` at `size`; returns how many edges have
/// a groove (obtuse), are acute, and are concave.
fn check_rigid(model: &Path, size: &str, tmp: &Path) -> [usize; 3] {
    let (mesh, parts) = rebuilt_parts(model, size, &tmp.join("job"));
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();

    // No two parts pass into each other, near or far in the mesh.
    let mut deepest = (0.0, 0, 0);
    for i in 0..parts.len() {
        for j in i + 1..parts.len() {
            let d = penetration(&parts[i], &parts[j]);
            if d > deepest.0 {
                deepest = (d, parts[i].face, parts[j].face);
            }
        }
    }
    assert!(
        deepest.0 <= OVERLAP,
        "{name}: the parts of F{} and F{} pass {} mm into each other",
        deepest.1,
        deepest.2,
        deepest.0
    );

    // No inner corner lies outside the model (or it lies within 0.01 mm of it).
    let triangles = triangles(&mesh);
    for part in &parts {
        for q in part.outer.iter().map(|&p| p - T * part.normal) {
            if winding(&triangles, q) < 0.5 {
                let gap = triangles
                    .iter()
                    .map(|&t| q.distance(closest_on_triangle(q, t)))
                    .fold(f64::MAX, f64::min);
                assert!(
                    gap <= OVERLAP,
                    "{name}: F{} sticks out {gap} mm at {q}",
                    part.face
                );
            }
        }
    }

    // Along each edge, the outer surface left open at its middle is no wider than the
    // edge's angle needs: T·sin δ at an obtuse edge, T·(cot δ + cot δ/2) at an acute
    // one, nothing at a concave one.
    let mut kinds = [0; 3];
    for e in mesh.edges() {
        let h = e.half_edge();
        let (Some(fa), Some(fb)) = (mesh.face(h), mesh.face(h.twin())) else {
            continue;
        };
        let (a, b) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
        let (na, nb) = (mesh.face_normal(fa), mesh.face_normal(fb));
        let turn = na.cross(nb).dot((b - a).normalize()).atan2(na.dot(nb));
        let delta = PI - turn;
        let middle = 0.5 * (a + b);
        let open: f64 = [fa, fb]
            .iter()
            .map(|&f| {
                let part = &parts[f.0 as usize];
                let x = (part.outer[1] - part.outer[0]).normalize();
                let y = part.normal.cross(x);
                let flat =
                    |p: DVec3| DVec2::new((p - part.outer[0]).dot(x), (p - part.outer[0]).dot(y));
                let poly: Vec<DVec2> = part.outer.iter().map(|&p| flat(p)).collect();
                outside_by(&poly, flat(middle))
            })
            .sum();
        let (allowed, kind) = if delta >= PI - 1e-9 {
            (0.0, 2)
        } else if delta >= PI / 2.0 {
            (T * delta.sin(), 0)
        } else {
            (T / delta.tan() + T / (delta / 2.0).tan(), 1)
        };
        kinds[kind] += 1;
        assert!(
            open <= allowed + 0.05,
            "{name}: E{} (δ {:.2}°) is open {open} mm on the outside, more than {allowed}",
            e.0,
            delta.to_degrees()
        );
    }

    // The command line cuts them: every sheet passes the independent check, and the
    // assembled model holds one closed solid per part.
    let out = tmp.join("out");
    let m = build(
        "half-edge",
        model,
        size,
        &out,
        &["--format", "svg,dxf", "--thickness", "3mm"],
    );
    check_output(model, &out, &m, &name, DxfCheck::FirstAndLast, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    assert_eq!(count(&m, "counts.panels"), mesh.face_count());
    assert_eq!(m["rigid"]["thickness"].as_f64(), Some(T));
    assert_closed_solids(&out.join(format!("{name}-assembled.obj")), parts.len());
    kinds
}

/// The assembled OBJ: `count` objects, each a closed solid (every edge of its faces
/// used once each way).
fn assert_closed_solids(path: &Path, count: usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut objects: Vec<Vec<Vec<usize>>> = Vec::new();
    for line in text.lines() {
        if line.starts_with("o ") {
            objects.push(Vec::new());
        } else if let Some(rest) = line.strip_prefix("f ") {
            let face = rest
                .split_whitespace()
                .map(|i| i.parse().unwrap())
                .collect();
            objects
                .last_mut()
                .expect("faces after an object")
                .push(face);
        }
    }
    assert_eq!(objects.len(), count, "{}", path.display());
    for faces in &objects {
        let mut directed = std::collections::BTreeMap::new();
        for f in faces {
            for k in 0..f.len() {
                *directed.entry((f[k], f[(k + 1) % f.len()])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(
                (n, directed.get(&(b, a))),
                (1, Some(&1)),
                "{}: edge {a}-{b}",
                path.display()
            );
        }
    }
}

#[test]
fn the_platonic_solids_in_3mm_sheet_fit_without_overlap() {
    let tmp = TempDir::new().unwrap();
    // Tetrahedron: acute edges only; cube: right angles; icosahedron: five faces at
    // each corner, whose corners must be cut back.
    let tetra = check_rigid(&model("tetrahedron"), "200mm", &tmp.path().join("tetra"));
    assert_eq!(tetra, [0, 6, 0]);
    let cube = check_rigid(&model("hexahedron"), "200mm", &tmp.path().join("cube"));
    assert_eq!(cube, [12, 0, 0]);
    let ico = check_rigid(&model("icosahedron"), "200mm", &tmp.path().join("ico"));
    assert_eq!(ico, [30, 0, 0]);
}

#[test]
fn a_torus_in_3mm_sheet_fits_without_overlap() {
    let tmp = TempDir::new().unwrap();
    let [obtuse, acute, concave] = check_rigid(&model("torus-8x6"), "300mm", tmp.path());
    assert_eq!(obtuse + acute + concave, 8 * 6 * 2);
    assert!(concave > 0 && obtuse > 0, "{obtuse} {acute} {concave}");
    assert_same_bytes_on_one_and_two_threads(
        &model("torus-8x6"),
        &["--size", "300mm", "--thickness", "3mm"],
    );
}

#[test]
fn a_simplified_shared_model_in_3mm_sheet_fits_without_overlap() {
    let Some(shared) = shared_models("rigid panels") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    // About 300 faces: 450 edges of a closed triangle mesh.
    let simple = simplified_obj(&shared.join("spot.obj"), 450, true, tmp.path());
    check_rigid(&simple, "700mm", &tmp.path().join("spot"));
}

#[test]
fn too_thick_is_refused_with_the_thickness_and_size_that_work() {
    let tmp = TempDir::new().unwrap();
    let cube = model("hexahedron");
    let out = tmp.path().join("out");
    let run = unfold([
        cube.to_str().unwrap(),
        "--size",
        "40mm",
        "--thickness",
        "25mm",
        "--build-anyway",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_refusal(
        "25 mm on a 40 mm cube",
        &run,
        2,
        &["--thickness", "--size", "F"],
    );
    assert!(!out.exists(), "nothing written");
    let said = |key: &str| -> String {
        let at = run.stderr.find(key).unwrap() + key.len();
        run.stderr[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .trim_end_matches([',', ';'])
            .to_string()
    };
    let (fits, size) = (said("; --thickness "), said("or --size "));
    // The thickness named builds at this size, and the size named takes 25 mm.
    for (size, t) in [("40mm", fits.as_str()), (size.as_str(), "25mm")] {
        let run = unfold([
            cube.to_str().unwrap(),
            "--size",
            size,
            "--thickness",
            t,
            "--build-anyway",
            "--out",
            tmp.path().join(format!("ok-{size}-{t}")).to_str().unwrap(),
        ]);
        assert_eq!(
            run.code,
            Some(0),
            "--size {size} --thickness {t}: {}",
            run.stderr
        );
    }
}

#[test]
fn tabs_and_shrunk_faces_are_refused_in_rigid_sheet() {
    let tmp = TempDir::new().unwrap();
    let cube = model("hexahedron");
    for (extra, says) in [
        (["--connectors", "tab"], "--connectors tab"),
        (["--face-scale", "0.9"], "--face-scale"),
    ] {
        let out = tmp.path().join("out");
        let mut args = vec![
            cube.to_str().unwrap(),
            "--size",
            "200mm",
            "--thickness",
            "3mm",
        ];
        args.extend(extra);
        args.extend(["--out", out.to_str().unwrap()]);
        let run = unfold(args);
        assert_refusal(says, &run, 2, &[says]);
        assert!(!out.exists());
    }
}
