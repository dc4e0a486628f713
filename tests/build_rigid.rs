//! Rigid panels (`--thickness` with the half-edge and net schemes): the parts are rebuilt in 3D
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
    /// Its id on the sheet.
    id: String,
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

/// The job of `unfold MODEL --scheme SCHEME --size SIZE --thickness 3mm`.
fn rigid_job(scheme: &str, model: &Path, size: &str, out: &Path) -> unfold::config::Job {
    let mut o = options(scheme, size, 0, out);
    o.scheme_values.set("thickness", &format!("{T}mm"));
    resolve(o, model)
}

/// A bracket rebuilt in 3D: its outline on its outer face and its thickness behind.
struct BracketPart {
    id: String,
    edge: u32,
    outer: Vec<DVec3>,
    normal: DVec3,
    /// The ids engraved on it.
    labels: Vec<String>,
}

impl BracketPart {
    fn corners(&self) -> Vec<DVec3> {
        let inner = self.outer.iter().map(|&p| p - T * self.normal);
        self.outer.iter().copied().chain(inner).collect()
    }
}

/// The rebuilt parts of a rigid build: the face panels (slots as their inner loops)
/// and the brackets.
struct Rebuilt {
    mesh: Mesh,
    parts: Vec<Part>,
    /// Each face's part.
    part_of: Vec<usize>,
    slots: Vec<Vec<Vec<DVec3>>>,
    brackets: Vec<BracketPart>,
}

impl Rebuilt {
    /// The part of face `f`.
    fn part(&self, f: FaceId) -> &Part {
        &self.parts[self.part_of[f.0 as usize]]
    }
}

/// The parts of a rigid build, rebuilt from the flat panels, and the mesh they cover.
/// A half-edge part covers one face; a net part a flat region of faces, whose corners
/// all lie within 0.01 mm of its plane.
fn rebuilt_parts(scheme: &str, model: &Path, size: &str, out: &Path) -> Rebuilt {
    let job = rigid_job(scheme, model, size, out);
    let p = pipeline(&job);
    let frames = frames_of(&p.panels);
    let mut rebuilt_parts = Vec::new();
    let mut rebuilt_slots = Vec::new();
    let mut rebuilt_brackets = Vec::new();
    let mut part_of = vec![usize::MAX; p.mesh.face_count()];
    for ((panel, flat), frames) in p.panels.iter().zip(&p.flat).zip(&frames) {
        // All facets of a rigid part lie in one plane: the first facet's frame maps
        // every point back.
        let loops: Vec<Vec<DVec3>> = flat
            .outline
            .iter()
            .map(|lp| {
                lp.iter()
                    .map(|&i| frames[0].to_3d(flat.points[i as usize]))
                    .collect()
            })
            .collect();
        // What is cut is the part: every corner maps back onto the 3D corner.
        for (lp, points) in flat.outline.iter().zip(&loops) {
            for (&i, q) in lp.iter().zip(points) {
                let want = panel.vertices[i as usize];
                assert!(
                    q.distance(want) < 1e-6,
                    "{}: corner {i} maps to {q}, not {want}",
                    panel.id()
                );
            }
        }
        let outer = loops[0].clone();
        if let Covers::Inside(edge) = panel.source.covers {
            let id = panel.id().to_string();
            assert!(id.starts_with('B'), "{id}: a part inside is a bracket");
            assert_eq!(panel.id().number, edge, "{id}: its id names its edge");
            assert_eq!(loops.len(), 1, "{id}: a bracket has no inner cut");
            let normal = polygon_vector_area(&outer).normalize();
            rebuilt_brackets.push(BracketPart {
                edge: panel.id().number,
                id,
                outer,
                normal,
                labels: panel.labels.iter().map(|l| l.text.to_string()).collect(),
            });
            continue;
        }
        let faces: Vec<u32> = match panel.source.covers {
            Covers::Face(face) => vec![face],
            Covers::Faces(k) => p.output.face_groups[k as usize].faces.clone(),
            _ => panic!("{}: a rigid panel covers faces", panel.id()),
        };
        let normal = polygon_vector_area(&outer).normalize();
        for &f in &faces {
            let f = FaceId(f);
            assert!(
                normal.dot(p.mesh.face_normal(f)) > 1.0 - 1e-9,
                "{}: its outer face looks away from F{}",
                panel.id(),
                f.0
            );
            // The part's plane holds its faces: its own corners and theirs.
            let on_plane = loops
                .iter()
                .flatten()
                .copied()
                .chain(p.mesh.face_positions(f))
                .map(|q| (q - p.mesh.face_centre(f)).dot(normal).abs())
                .fold(0.0, f64::max);
            assert!(
                on_plane < OVERLAP,
                "{}: {on_plane} mm off the plane of F{}",
                panel.id(),
                f.0
            );
            assert_eq!(part_of[f.0 as usize], usize::MAX, "F{} in two parts", f.0);
            part_of[f.0 as usize] = rebuilt_parts.len();
        }
        let part = Part {
            id: panel.id().to_string(),
            outer,
            normal,
        };
        if faces.len() == 1 {
            assert!(
                is_convex(&part),
                "{}: the faces are convex, so is each part of one",
                panel.id()
            );
        }
        rebuilt_parts.push(part);
        rebuilt_slots.push(loops[1..].to_vec());
    }
    assert!(
        part_of.iter().all(|&k| k != usize::MAX),
        "every face in a part"
    );
    Rebuilt {
        mesh: p.mesh,
        parts: rebuilt_parts,
        part_of,
        slots: rebuilt_slots,
        brackets: rebuilt_brackets,
    }
}

/// A part as convex parts: itself, or its triangles (the crate's ear clipping).
fn convex_pieces(part: &Part) -> Vec<Part> {
    if is_convex(part) {
        return vec![Part {
            id: part.id.clone(),
            outer: part.outer.clone(),
            normal: part.normal,
        }];
    }
    unfold::mesh::split::triangulate(&part.outer)
        .into_iter()
        .map(|t| Part {
            id: part.id.clone(),
            outer: t.map(|k| part.outer[k]).to_vec(),
            normal: part.normal,
        })
        .collect()
}

/// How deep two parts pass into each other (mm): the deepest pair of their convex
/// pieces.
fn part_penetration(a: &[Part], b: &[Part]) -> f64 {
    a.iter()
        .flat_map(|p| b.iter().map(move |q| penetration(p, q)))
        .fold(0.0, f64::max)
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

/// Checks the parts of a rigid build of `model` at `size` by `scheme`; returns how many
/// edges have a groove (obtuse), are acute, and are concave (or flat).
fn check_rigid(scheme: &str, model: &Path, size: &str, tmp: &Path) -> [usize; 3] {
    let rebuilt = rebuilt_parts(scheme, model, size, &tmp.join("job"));
    let (mesh, parts) = (&rebuilt.mesh, &rebuilt.parts);
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    check_brackets(&name, &rebuilt);

    // No two parts pass into each other, near or far in the mesh.
    let mut deepest = (0.0, 0, 0);
    let boxes: Vec<(DVec3, DVec3)> = parts.iter().map(|p| corners_box(&p.corners())).collect();
    let pieces: Vec<Vec<Part>> = parts.iter().map(convex_pieces).collect();
    for i in 0..parts.len() {
        for j in i + 1..parts.len() {
            if !boxes_meet(&boxes[i], &boxes[j]) {
                continue;
            }
            let d = part_penetration(&pieces[i], &pieces[j]);
            if d > deepest.0 {
                deepest = (d, i, j);
            }
        }
    }
    assert!(
        deepest.0 <= OVERLAP,
        "{name}: the parts {} and {} pass {} mm into each other",
        parts[deepest.1].id,
        parts[deepest.2].id,
        deepest.0
    );

    // No corner of a part lies outside the model (or it lies within 0.01 mm of it):
    // the panels' inner corners, and every corner of every bracket.
    let triangles = triangles(mesh);
    let panel_corners = parts.iter().flat_map(|part| {
        part.outer
            .iter()
            .map(move |&p| (part.id.clone(), p - T * part.normal))
    });
    let bracket_corners = rebuilt
        .brackets
        .iter()
        .flat_map(|b| b.corners().into_iter().map(|p| (b.id.clone(), p)));
    for (id, q) in panel_corners.chain(bracket_corners) {
        if winding(&triangles, q) < 0.5 {
            let gap = triangles
                .iter()
                .map(|&t| q.distance(closest_on_triangle(q, t)))
                .fold(f64::MAX, f64::min);
            assert!(gap <= OVERLAP, "{name}: {id} sticks out {gap} mm at {q}");
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
        let sides = [
            rebuilt.part_of[fa.0 as usize],
            rebuilt.part_of[fb.0 as usize],
        ];
        if sides[0] == sides[1] {
            // Inside one part (a flat region): no seam, nothing open.
            kinds[2] += 1;
            continue;
        }
        let open: f64 = sides
            .iter()
            .map(|&k| {
                let part = &parts[k];
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
        scheme,
        model,
        size,
        &out,
        &["--format", "svg,dxf", "--thickness", "3mm"],
    );
    check_output(model, &out, &m, &name, DxfCheck::FirstAndLast, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    let all = parts.len() + rebuilt.brackets.len();
    assert_eq!(count(&m, "counts.panels"), all);
    assert_eq!(m["rigid"]["thickness"].as_f64(), Some(T));
    assert_eq!(count(&m, "rigid.brackets"), rebuilt.brackets.len());
    assert_closed_solids(&out.join(format!("{name}-assembled.obj")), all);
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
    let tetra = check_rigid(
        "half-edge",
        &model("tetrahedron"),
        "200mm",
        &tmp.path().join("tetra"),
    );
    assert_eq!(tetra, [0, 6, 0]);
    let cube = check_rigid(
        "half-edge",
        &model("hexahedron"),
        "200mm",
        &tmp.path().join("cube"),
    );
    assert_eq!(cube, [12, 0, 0]);
    let ico = check_rigid(
        "half-edge",
        &model("icosahedron"),
        "200mm",
        &tmp.path().join("ico"),
    );
    assert_eq!(ico, [30, 0, 0]);
}

#[test]
fn a_torus_in_3mm_sheet_fits_without_overlap() {
    let tmp = TempDir::new().unwrap();
    let [obtuse, acute, concave] =
        check_rigid("half-edge", &model("torus-8x6"), "300mm", tmp.path());
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
    check_rigid("half-edge", &simple, "500mm", &tmp.path().join("spot"));
}

#[test]
fn the_net_in_3mm_sheet_makes_one_part_per_flat_region() {
    let tmp = TempDir::new().unwrap();
    let parts = |model: &Path, size: &str, dir: &str| {
        let out = tmp.path().join(dir);
        let kinds = check_rigid("net", model, size, &out);
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("out/manifest.json")).unwrap())
                .unwrap();
        (kinds, count(&m, "net.islands"))
    };
    // The star prism's two caps are split into triangles for the net; rigid, each cap
    // is one part again: twelve, as in the file.
    let (kinds, islands) = parts(&model("concave"), "200mm", "concave");
    // Caps at right angles (20 edges), five acute star points, five concave edges
    // and the fourteen diagonals the split drew in the caps.
    assert_eq!((kinds, islands), ([20, 5, 5 + 14], 12));
    // No two faces of the icosahedron lie in one plane: a part per face.
    let (kinds, islands) = parts(&model("icosahedron"), "200mm", "ico");
    assert_eq!((kinds, islands), ([30, 0, 0], 20));
    // The torus's top and bottom rings are flat: each ring of eight faces is one part
    // that stops short of closing round the hole (a C of seven faces, not convex) and
    // one more; the other 32 faces are parts of their own.
    let (_, islands) = parts(&model("torus-8x6"), "300mm", "torus");
    assert_eq!(islands, 32 + 2 * 2);
    assert_same_bytes_on_one_and_two_threads(
        &model("concave"),
        &["--scheme", "net", "--size", "200mm", "--thickness", "3mm"],
    );
    let Some(shared) = shared_models("the rigid net of a triangulated cube") else {
        return;
    };
    // A cube of twelve triangles: six square parts, its diagonals inside them.
    let (kinds, islands) = parts(&shared.join("cube.obj"), "200mm", "cube");
    assert_eq!((kinds, islands), ([12, 0, 6], 6));
}

#[test]
fn the_rigid_net_refuses_what_only_folds_need_and_names_islands() {
    let tmp = TempDir::new().unwrap();
    let cube = model("hexahedron");
    // 200 mm unless a case says otherwise; 25 mm on a 40 mm cube is too thick.
    for (extra, says) in [
        (
            vec![
                "--size",
                "200mm",
                "--thickness",
                "3mm",
                "--island-spread",
                "2",
            ],
            "--island-spread",
        ),
        (
            vec!["--size", "200mm", "--connectors", "none"],
            "--connectors none",
        ),
        (
            vec![
                "--size",
                "200mm",
                "--thickness",
                "3mm",
                "--connectors",
                "tab",
            ],
            "--connectors tab",
        ),
        (vec!["--size", "40mm", "--thickness", "25mm"], "N"),
    ] {
        let out = tmp.path().join("out");
        let mut args = vec![cube.to_str().unwrap(), "--scheme", "net"];
        args.extend(extra);
        args.extend(["--build-anyway", "--out", out.to_str().unwrap()]);
        let run = unfold(args);
        assert_refusal(says, &run, 2, &[says]);
        assert!(!out.exists());
    }
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
fn tabs_and_shrunk_faces_are_refused_in_rigid_sheet_and_brackets_in_card() {
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
    // Brackets hold rigid panels only: in card, the fix is the thickness.
    let out = tmp.path().join("card");
    let run = unfold([
        cube.to_str().unwrap(),
        "--size",
        "200mm",
        "--connectors",
        "bracket",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_refusal(
        "bracket in card",
        &run,
        2,
        &["--connectors bracket", "--thickness"],
    );
    assert!(!out.exists());
}

/// The bounding box of some points.
fn corners_box(points: &[DVec3]) -> (DVec3, DVec3) {
    points
        .iter()
        .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// Two boxes overlap (touching counts).
fn boxes_meet(a: &(DVec3, DVec3), b: &(DVec3, DVec3)) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

/// A polygon's part on the inner side of a plane (`(p - at)·normal <= 0`).
fn clip_below(poly: &[DVec3], at: DVec3, normal: DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for k in 0..poly.len() {
        let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
        let (sp, sq) = ((p - at).dot(normal), (q - at).dot(normal));
        if sp <= 0.0 {
            out.push(p);
        }
        if (sp <= 0.0) != (sq <= 0.0) {
            out.push(p + (q - p) * (sp / (sp - sq)));
        }
    }
    out
}

/// The brackets of a rigid build: each names its edge and both panels, its arms meet at
/// the edge's angle within 0.1°, what of it lies in the material of its two panels lies
/// in their slots, it passes into no other part, and every slot is T plus the
/// clearance wide.
fn check_brackets(name: &str, r: &Rebuilt) {
    let mesh = &r.mesh;
    for (part, slots) in r.parts.iter().zip(&r.slots) {
        for slot in slots {
            assert_eq!(
                slot.len(),
                4,
                "{name}: {}: a slot has four corners",
                part.id
            );
            let sides: Vec<f64> = (0..4)
                .map(|k| slot[k].distance(slot[(k + 1) % 4]))
                .collect();
            let narrow = sides.iter().copied().fold(f64::MAX, f64::min);
            assert!(
                (narrow - (T + 0.1)).abs() < 1e-6,
                "{name}: {}: a slot {narrow} mm wide",
                part.id
            );
            let diagonals = (slot[0].distance(slot[2]), slot[1].distance(slot[3]));
            assert!(
                (diagonals.0 - diagonals.1).abs() < 1e-6,
                "{name}: a slot is not a rectangle"
            );
        }
    }
    let pieces: Vec<Vec<Part>> = r
        .brackets
        .iter()
        .map(|b| {
            // The bracket as triangles (the crate's ear clipping), each a convex part.
            unfold::mesh::split::triangulate(&b.outer)
                .into_iter()
                .map(|t| Part {
                    id: b.id.clone(),
                    outer: t.map(|k| b.outer[k]).to_vec(),
                    normal: b.normal,
                })
                .collect()
        })
        .collect();
    for (k, b) in r.brackets.iter().enumerate() {
        let h = unfold::mesh::EdgeId(b.edge).half_edge();
        let (fa, fb) = (mesh.face(h).unwrap(), mesh.face(h.twin()).unwrap());
        assert!(
            b.id.starts_with(&format!("B{}.", b.edge)),
            "{name}: {}",
            b.id
        );
        for f in [fa, fb] {
            assert!(
                b.labels.contains(&r.part(f).id),
                "{name}: {} names {}: {:?}",
                b.id,
                r.part(f).id,
                b.labels
            );
        }
        // The arms lie on the two panels' inner faces and meet at the edge's angle.
        let (na, nb) = (mesh.face_normal(fa), mesh.face_normal(fb));
        let inner_a = |p: DVec3| (p - mesh.face_centre(fa)).dot(na) + T;
        let inner_b = |p: DVec3| (p - mesh.face_centre(fb)).dot(nb) + T;
        let (a, bb) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
        let along = (bb - a).normalize();
        let (into_a, into_b) = (na.cross(along), along.cross(nb));
        // The elbow: on both inner faces, nearest the edge's line.
        let off_line = |p: DVec3| (p - a).reject_from_normalized(along).length();
        let elbow = b
            .outer
            .iter()
            .copied()
            .filter(|&p| inner_a(p).abs() < 1e-6 && inner_b(p).abs() < 1e-6)
            .min_by(|p, q| off_line(*p).total_cmp(&off_line(*q)))
            .unwrap_or_else(|| panic!("{name}: {} has no corner on both inner faces", b.id));
        // Each arm's far end: the corner on its panel's inner face farthest from the
        // elbow on that panel's side.
        let far_end = |on: &dyn Fn(DVec3) -> f64, into: DVec3| {
            b.outer
                .iter()
                .copied()
                .filter(|&p| on(p).abs() < 1e-6 && (p - elbow).dot(into) > 0.0)
                .max_by(|p, q| p.distance(elbow).total_cmp(&q.distance(elbow)))
                .unwrap_or_else(|| panic!("{name}: {} has an arm off its panel", b.id))
        };
        let ua = (far_end(&inner_a, into_a) - elbow).normalize();
        let ub = (far_end(&inner_b, into_b) - elbow).normalize();
        let arms = ua.dot(ub).clamp(-1.0, 1.0).acos();
        let delta = PI - na.cross(nb).dot(along).atan2(na.dot(nb));
        // Two directions meet at most at 180°: at a concave edge the bracket wraps the
        // other way round, through 360° less that.
        let expected = if delta > PI { 2.0 * PI - delta } else { delta };
        assert!(
            (arms - expected).abs().to_degrees() < 0.1,
            "{name}: {}: arms at {:.3}°, edge at {:.3}°",
            b.id,
            arms.to_degrees(),
            delta.to_degrees()
        );
        // In each of its panels' material (less a hundredth either side), only its
        // tabs, and those in slots.
        for (f, part) in [fa, fb].map(|f| (f, r.part(f))) {
            let o = part.outer[0];
            let x = (part.outer[1] - o).normalize();
            let y = part.normal.cross(x);
            let flat = |p: DVec3| DVec2::new((p - o).dot(x), (p - o).dot(y));
            let outline: Vec<DVec2> = part.outer.iter().map(|&p| flat(p)).collect();
            let slots: Vec<Vec<DVec2>> = r.slots[r.part_of[f.0 as usize]]
                .iter()
                .map(|s| s.iter().map(|&p| flat(p)).collect())
                .collect();
            let inner: Vec<DVec3> = b.outer.iter().map(|&p| p - T * b.normal).collect();
            for face in [&b.outer, &inner] {
                let below_outer = clip_below(face, o - OVERLAP * part.normal, part.normal);
                let in_slab =
                    clip_below(&below_outer, o - (T - OVERLAP) * part.normal, -part.normal);
                for p in in_slab {
                    let q = flat(p);
                    let in_slot = slots.iter().any(|s| outside_by(s, q) < 1e-6);
                    assert!(
                        outside_by(&outline, q) > -1e-9 && (!inside(&outline, q) || in_slot),
                        "{name}: {} passes into {} at {p} outside its slots",
                        b.id,
                        part.id
                    );
                }
            }
        }
        // Clear of every other panel and every other bracket (where their boxes meet).
        let near = |c: &[DVec3]| boxes_meet(&corners_box(&b.corners()), &corners_box(c));
        let own = [r.part(fa).id.clone(), r.part(fb).id.clone()];
        for part in r.parts.iter().filter(|p| !own.contains(&p.id)) {
            if !near(&part.corners()) {
                continue;
            }
            let d = part_penetration(&convex_pieces(part), &pieces[k]);
            assert!(
                d <= OVERLAP,
                "{name}: {} passes {d} mm into {}",
                b.id,
                part.id
            );
        }
        for (j, other) in r.brackets.iter().enumerate().skip(k + 1) {
            if !near(&other.corners()) {
                continue;
            }
            for (p, q) in pieces[k]
                .iter()
                .flat_map(|p| pieces[j].iter().map(move |q| (p, q)))
            {
                let d = penetration(p, q);
                assert!(
                    d <= OVERLAP,
                    "{name}: {} passes {d} mm into {}",
                    b.id,
                    other.id
                );
            }
        }
    }
}
