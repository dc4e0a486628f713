//! End-to-end tests of the strip scheme (SPEC.md §2, strip): strips without an interior
//! vertex that unroll exactly, within `--max-deviation` of the model both ways (sampled
//! here, with exact point–triangle distances of the test's own), welded along their
//! shared curves into one surface, pieces named by strip and piece that fit the sheet
//! and pass the independent sheet check, the same bytes on one and two threads.

use crate::common;

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::Value;
use tempfile::TempDir;

use common::build::*;
use unfold::mesh::{FaceId, Mesh};
use unfold::scheme::island::MATCH;

/// An OBJ of `points` and `faces` (0-based), written to `dir/name.obj`.
fn write_model(dir: &Path, name: &str, points: &[DVec3], faces: &[Vec<u32>]) -> PathBuf {
    let mut text = String::new();
    for p in points {
        text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for f in faces {
        let ids: Vec<String> = f.iter().map(|i| (i + 1).to_string()).collect();
        text.push_str(&format!("f {}\n", ids.join(" ")));
    }
    let path = dir.join(format!("{name}.obj"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A surface of revolution about z: `around` × `along` quads through the profile
/// points (radius, height), open at its ends unless a profile point has radius 0 (a
/// pole, closed by triangles).
fn revolved(dir: &Path, name: &str, profile: &[(f64, f64)], around: usize) -> PathBuf {
    let mut points = Vec::new();
    let mut first = Vec::new();
    for &(r, z) in profile {
        first.push(points.len() as u32);
        let ring = if r == 0.0 { 1 } else { around };
        for i in 0..ring {
            let a = TAU * i as f64 / around as f64;
            points.push(DVec3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    let at = |k: usize, i: usize| {
        let ring = if profile[k].0 == 0.0 { 1 } else { around };
        first[k] + (i % around % ring) as u32
    };
    let mut faces = Vec::new();
    for k in 0..profile.len() - 1 {
        for i in 0..around {
            // Counter-clockwise seen from outside, the profile running upward.
            let quad = [at(k, i), at(k, i + 1), at(k + 1, i + 1), at(k + 1, i)];
            let mut face: Vec<u32> = Vec::new();
            for v in quad {
                if !face.contains(&v) {
                    face.push(v);
                }
            }
            faces.push(face);
        }
    }
    write_model(dir, name, &points, &faces)
}

/// A torus of radii `big` and `small` in `around` × `across` quads.
fn torus(dir: &Path, around: usize, across: usize, big: f64, small: f64) -> PathBuf {
    let mut points = Vec::new();
    for i in 0..around {
        let a = TAU * i as f64 / around as f64;
        for j in 0..across {
            let b = TAU * j as f64 / across as f64;
            let r = big + small * b.cos();
            points.push(DVec3::new(r * a.cos(), r * a.sin(), small * b.sin()));
        }
    }
    let at = |i: usize, j: usize| ((i % around) * across + j % across) as u32;
    let mut faces = Vec::new();
    for i in 0..around {
        for j in 0..across {
            faces.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    write_model(dir, "torus", &points, &faces)
}

/// A sphere's profile: `rings` steps from the south pole to the north.
fn sphere_profile(radius: f64, rings: usize) -> Vec<(f64, f64)> {
    (0..=rings)
        .map(|k| {
            let polar = std::f64::consts::PI * k as f64 / rings as f64;
            let r = radius * polar.sin();
            (
                if k == 0 || k == rings { 0.0 } else { r },
                -radius * polar.cos(),
            )
        })
        .collect()
}

/// The largest distance from points of `from` (each triangle sampled on a grid of
/// about `spacing`, corners included) to the nearest triangle of `to`, searched among
/// the triangles whose box comes within `reach` (beyond it, `reach` is returned).
///
/// A point whose nearest triangle is no farther than the largest distance so far
/// cannot raise it, so its search stops at the first triangle that close, starting
/// with the previous point's nearest: the result is the full search's, in a fraction
/// of the time.
fn one_way(from: &[[DVec3; 3]], to: &[[DVec3; 3]], spacing: f64, reach: f64) -> f64 {
    let cell = reach.max(1e-6);
    let key = |p: DVec3| (p / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<usize>> = HashMap::new();
    for (t, tri) in to.iter().enumerate() {
        let lo = tri[0].min(tri[1]).min(tri[2]) - DVec3::splat(reach);
        let hi = tri[0].max(tri[1]).max(tri[2]) + DVec3::splat(reach);
        let (a, b) = (key(lo), key(hi));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    grid.entry([x, y, z]).or_default().push(t);
                }
            }
        }
    }
    let mut worst: f64 = 0.0;
    // The triangle nearest the previous point: a triangle within `worst <= reach` of
    // a point is in that point's cell, so testing it first never changes the answer.
    let mut previous = None;
    for tri in from {
        let longest = (0..3)
            .map(|k| tri[k].distance(tri[(k + 1) % 3]))
            .fold(0.0, f64::max);
        let n = (longest / spacing).ceil().max(1.0) as usize;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let p = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
                let distance = |t: usize| closest_on_triangle(p, to[t]).distance(p);
                if worst >= reach || previous.is_some_and(|t| distance(t) <= worst) {
                    continue;
                }
                let mut nearest = reach;
                for &t in grid.get(&key(p)).map_or(&[][..], Vec::as_slice) {
                    let d = distance(t);
                    if d < nearest {
                        (nearest, previous) = (d, Some(t));
                        if nearest <= worst {
                            break;
                        }
                    }
                }
                worst = worst.max(nearest);
            }
        }
    }
    worst
}

/// Checks the strip facts of one build through the library: every piece and every
/// strip without an interior vertex, the strips' surface within `bound` of the model
/// both ways, closed where the model is closed, each strip's pieces a run of it; the
/// flat pieces keep their edge lengths. Returns (strips, pieces).
fn check_strips(what: &str, p: &Pipeline, bound: f64) -> (usize, usize) {
    let surface = p.output.surface.as_ref().expect("the strips' surface");
    let size = {
        let (lo, hi) = surface
            .positions()
            .iter()
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &q| {
                (lo.min(q), hi.max(q))
            });
        (hi - lo).max_element()
    };
    // The faces of other strips that pieces with no room for their id joined to them.
    let joined: BTreeMap<u32, u32> = strip_section(&p.output.manifest)["joined"]
        .as_array()
        .expect("strip.joined")
        .iter()
        .flat_map(|j| {
            let strip = j["strip"].as_u64().unwrap() as u32;
            let faces = j["faces"].as_array().unwrap().iter();
            faces.map(move |f| (f.as_u64().unwrap() as u32, strip))
        })
        .collect();
    // Faces by strip and pieces; every face in one piece.
    let mut strips: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    let mut covered = BTreeSet::new();
    for (panel, group) in p.panels.iter().zip(&p.output.face_groups) {
        let id = panel.id();
        assert_eq!(id.to_string().chars().next(), Some('S'), "{what}: {id}");
        assert_no_interior_vertex(what, &format!("piece {id}"), surface, &group.faces);
        // A piece is a run of its strip, and of each strip joined to it.
        let mut runs: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for &f in &group.faces {
            assert!(covered.insert(f), "{what}: face {f} in two pieces");
            let strip = joined.get(&f).copied().unwrap_or(id.number);
            strips.entry(strip).or_default().push(f);
            runs.entry(strip).or_default().push(f);
        }
        for (strip, faces) in &runs {
            assert!(
                faces.windows(2).all(|w| w[1] == w[0] + 1),
                "{what}: {id}'s faces of S{strip} are not one run"
            );
        }
        assert!(
            runs.contains_key(&id.number),
            "{what}: {id} has no face of its strip"
        );
    }
    assert_eq!(
        covered.len(),
        surface.face_count(),
        "{what}: faces in pieces"
    );
    for (strip, all) in &strips {
        assert_no_interior_vertex(what, &format!("S{strip}"), surface, all);
        // A strip's faces are numbered along it: its pieces are runs.
        let mut sorted = all.clone();
        sorted.sort_unstable();
        assert!(
            sorted.windows(2).all(|w| w[1] == w[0] + 1),
            "{what}: S{strip} is not one run of faces"
        );
    }
    check_seam_numbers(what, p, surface);
    // Welded along shared curves: closed where the model is.
    assert_eq!(
        surface.boundary_loops().is_empty(),
        p.mesh.boundary_loops().is_empty(),
        "{what}: the strips' surface is closed where the model is"
    );
    for flat in &p.flat {
        assert!(
            flat.developability_error <= 1e-9 * size,
            "{what}: {} unrolls with error {}",
            flat.source.id,
            flat.developability_error
        );
    }
    let (model, strip) = (triangles(&p.mesh), triangles(surface));
    let spacing = bound / 4.0;
    let out = one_way(&strip, &model, spacing, 2.0 * bound);
    let back = one_way(&model, &strip, spacing, 2.0 * bound);
    eprintln!(
        "{what}: {} strips in {} pieces, {out:.3} mm out and {back:.3} mm back (bound {bound:.3} mm)",
        strips.len(),
        p.panels.len()
    );
    assert!(
        out <= bound * (1.0 + 1e-9),
        "{what}: strips {out} mm from the model"
    );
    assert!(
        back <= bound * (1.0 + 1e-9),
        "{what}: model {back} mm from the strips"
    );
    (strips.len(), p.panels.len())
}

/// One match number for each seam between two pieces (a run of cut edges end to end
/// between the same two pieces, found here from the pieces' faces), numbered from 1,
/// on two labels on the seam's two pieces (unless one has no room).
fn check_seam_numbers(what: &str, p: &Pipeline, surface: &Mesh) {
    let mut piece_of = vec![usize::MAX; surface.face_count()];
    for (k, group) in p.output.face_groups.iter().enumerate() {
        for &f in &group.faces {
            piece_of[f as usize] = k;
        }
    }
    // Cut edges joined at a vertex where they lie between the same two pieces.
    let mut seam: Vec<usize> = Vec::new();
    let mut pieces_of_seam: Vec<(usize, usize)> = Vec::new();
    let mut at: HashMap<(u32, (usize, usize)), usize> = HashMap::new();
    for e in surface.edges() {
        let h = e.half_edge();
        let (Some(f), Some(g)) = (surface.face(h), surface.face(h.twin())) else {
            continue;
        };
        let (a, b) = (piece_of[f.index()], piece_of[g.index()]);
        if a == b {
            continue;
        }
        let pair = (a.min(b), a.max(b));
        let root = |seam: &Vec<usize>, mut k: usize| {
            while seam[k] != k {
                k = seam[k];
            }
            k
        };
        let k = seam.len();
        seam.push(k);
        pieces_of_seam.push(pair);
        for v in [surface.origin(h), surface.dest(h)] {
            match at.get(&(v.0, pair)) {
                Some(&other) => {
                    let (r, s) = (root(&seam, other), root(&seam, k));
                    seam[r.max(s)] = r.min(s);
                }
                None => {
                    at.insert((v.0, pair), k);
                }
            }
        }
    }
    let seams = (0..seam.len()).filter(|&k| seam[k] == k).count();
    let mut labels: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    let mut dropped = 0;
    for (k, panel) in p.panels.iter().enumerate() {
        for label in panel.labels.iter().filter(|l| l.text.kind == &MATCH) {
            labels.entry(label.text.number).or_default().push(k);
        }
        dropped += panel.labels_dropped.partner;
    }
    // Numbers 1 to n, two labels each: the labels kept and those with no room.
    let kept: usize = labels.values().map(Vec::len).sum();
    assert_eq!((kept + dropped) % 2, 0, "{what}: two labels per number");
    let numbers = (kept + dropped) / 2;
    assert!(
        labels.keys().all(|&n| n >= 1 && n as usize <= numbers),
        "{what}: numbers 1 to {numbers}"
    );
    // A number on one piece twice is a seam of a piece with itself (where a ring is
    // cut open), which the pieces' faces alone do not tell from a fold.
    let pairs: BTreeSet<(usize, usize)> = pieces_of_seam.into_iter().collect();
    let mut between = 0;
    for (number, on) in &labels {
        assert!(on.len() <= 2, "{what}: match number {number} on {on:?}");
        let [a, b] = on[..] else {
            continue;
        };
        if a != b {
            between += 1;
            assert!(
                pairs.contains(&(a.min(b), a.max(b))),
                "{what}: match number {number} on two pieces with no seam between them"
            );
        }
    }
    eprintln!("{what}: {numbers} match numbers, {seams} seams between pieces, {between} numbered on both, {dropped} labels with no room");
    // At most one seam of a piece with itself: a ring cut open once.
    assert!(
        between <= seams && seams <= numbers && numbers <= seams + p.panels.len(),
        "{what}: one match number per seam"
    );
}

/// The scheme's `strip` section of the manifest.
fn strip_section(manifest: &unfold::record::Params) -> &Value {
    manifest
        .0
        .iter()
        .find_map(|(name, field)| match field {
            unfold::record::Field::Value(v) if name == "strip" => Some(v),
            _ => None,
        })
        .expect("a strip section")
}

/// Every corner of `faces` (of `surface`, numbered along their strip) lies on their
/// outline as cut: an edge not joining two consecutive faces (a rung joins them; a
/// strip that runs on both sides of a slit, where two curves touch, is cut along it).
fn assert_no_interior_vertex(what: &str, name: &str, surface: &Mesh, faces: &[u32]) {
    let mut users: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
    let mut corners = BTreeSet::new();
    for &f in faces {
        let v: Vec<u32> = surface.face_vertices(FaceId(f)).map(|v| v.0).collect();
        for k in 0..v.len() {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            users.entry((a.min(b), a.max(b))).or_default().push(f);
            corners.insert(a);
        }
    }
    let rung = |f: &[u32]| f.len() == 2 && f[0].abs_diff(f[1]) == 1;
    let on_outline: BTreeSet<u32> = users
        .iter()
        .filter(|(_, f)| !rung(f))
        .flat_map(|(&(a, b), _)| [a, b])
        .collect();
    let inside: Vec<&u32> = corners.difference(&on_outline).collect();
    assert!(
        inside.is_empty(),
        "{what}: {name} has interior vertices {inside:?}"
    );
}

/// The job of `unfold MODEL --scheme strip --size SIZE --max-deviation DEVIATION`.
fn strip_job(model: &Path, size: &str, deviation: &str, out: &Path) -> unfold::config::Job {
    let mut o = options("strip", size, 0, out);
    o.scheme_values.set("max-deviation", deviation);
    resolve(o, model)
}

/// Builds from the command line with `--format svg,dxf` and checks every sheet.
fn strip_build(model: &Path, size: &str, deviation: &str, out: &Path) -> Value {
    strip_build_with(model, size, deviation, out, &[])
}

/// [`strip_build`] with more arguments.
fn strip_build_with(
    model: &Path,
    size: &str,
    deviation: &str,
    out: &Path,
    extra: &[&str],
) -> Value {
    let mut args = vec!["--format", "svg,dxf", "--max-deviation", deviation];
    args.extend(extra);
    let m = build("strip", model, size, out, &args);
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    check_output(model, out, &m, &name, DxfCheck::FirstAndLast, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    m
}

/// The build of [`strip_build_with`] (its options, the default holes) made once
/// through the library: the sheets checked as there, and the pipeline for the strip
/// facts with the manifest.
fn strip_built_once(
    model: &Path,
    size: &str,
    deviation: &str,
    out: &Path,
    shelf: bool,
) -> (Pipeline, Value) {
    let mut o = options("strip", size, 0, out);
    o.holes = None;
    o.scheme_values.set("max-deviation", deviation);
    o.format = Some("svg,dxf".to_string());
    if shelf {
        o.nester = Some(unfold::nest::NesterName::Shelf);
    } else {
        o.effort = Some(1);
    }
    let (p, m) = built_once(&resolve(o, model));
    let name = model.file_stem().unwrap().to_string_lossy().into_owned();
    check_output(model, out, &m, &name, DxfCheck::FirstAndLast, |e| {
        e["id"].as_str().unwrap().to_string()
    });
    (p, m)
}

#[test]
fn an_open_cylinder_is_one_strip_in_one_piece() {
    let tmp = TempDir::new().unwrap();
    let profile: Vec<(f64, f64)> = (0..=4).map(|k| (50.0, 25.0 * k as f64)).collect();
    let model = revolved(tmp.path(), "cylinder", &profile, 32);
    let job = strip_job(&model, "100mm", "0.5mm", &tmp.path().join("job"));
    assert_eq!(check_strips("cylinder", &pipeline(&job), 0.5), (1, 1));
    let m = strip_build(&model, "100mm", "0.5mm", &tmp.path().join("out"));
    assert_eq!(count(&m, "strip.strips"), 1);
    assert_eq!(count(&m, "strip.pieces"), 1);
    // Not simplified: one bound, to the model as given.
    assert!(m["strip"].get("simplified_bound").is_none());
    let ids: Vec<&str> = m["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["id"].as_str().unwrap())
        .collect();
    assert_eq!(ids, ["S1"]);
    assert!(num(&m, "strip.measured_deviation") <= 0.5);
}

#[test]
fn cones_spheres_and_tori_are_strips_within_the_bound() {
    let tmp = TempDir::new().unwrap();
    let cone: Vec<(f64, f64)> = (0..=6)
        .map(|k| (60.0 - 7.0 * k as f64, 15.0 * k as f64))
        .collect();
    let models = [
        ("cone", revolved(tmp.path(), "cone", &cone, 32), "1%"),
        (
            "sphere",
            revolved(tmp.path(), "sphere", &sphere_profile(100.0, 16), 32),
            "1%",
        ),
        ("torus", torus(tmp.path(), 32, 16, 80.0, 30.0), "1%"),
    ];
    for (name, model, deviation) in &models {
        let out = tmp.path().join(name);
        let (p, m) = strip_built_once(model, "200mm", deviation, &out, false);
        let model_triangles = triangles(&p.mesh);
        let (lo, hi) = model_triangles
            .iter()
            .flatten()
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &q| {
                (lo.min(q), hi.max(q))
            });
        let bound = 0.01 * (hi - lo).length();
        let (strips, pieces) = check_strips(name, &p, bound);
        // An open cone unrolls whole, rim to rim; a sphere or a torus takes several.
        let least = if *name == "cone" { 1 } else { 2 };
        assert!(
            strips >= least && pieces >= strips,
            "{name}: {strips} strips, {pieces} pieces"
        );
        if *name == "cone" {
            assert_eq!(strips, 1, "an open cone is one strip");
        }
        assert_eq!(count(&m, "strip.strips"), strips, "{name}");
        assert!(num(&m, "strip.measured_deviation") <= bound, "{name}");
        // The assembled model is the strips' surface, without tabs: triangles only,
        // within the bound of the model both ways (its numbers rounded to 1e-4 mm).
        let (points, faces) = read_simple_obj(&out.join(format!("{name}-assembled.obj")));
        assert!(
            faces.iter().all(|f| f.len() == 3),
            "{name}: a tab in the OBJ"
        );
        let assembled: Vec<[DVec3; 3]> = faces
            .iter()
            .map(|f| [points[f[0]], points[f[1]], points[f[2]]])
            .collect();
        let spacing = bound / 4.0;
        let out_d = one_way(&assembled, &model_triangles, spacing, 2.0 * bound);
        let back = one_way(&model_triangles, &assembled, spacing, 2.0 * bound);
        assert!(
            out_d.max(back) <= bound + 1e-3,
            "{name}: OBJ {out_d} and {back} mm off"
        );
    }
}

/// A band whose sectors' strips fold onto each other is mended on its own (cut into
/// longer sectors, or covered whole): on the faceted torus two bands are, and the rest
/// of the model keeps its sectors.
#[test]
fn sectors_that_overlap_are_mended_in_their_own_band() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let (m, run) = build_run(
        "strip",
        &model("torus-8x6"),
        "1ft",
        &out,
        &["--sheet", "18x24in", "--format", "svg,dxf"],
    );
    assert!(run.stderr.contains("strip: "), "no report:\n{}", run.stderr);
    assert!(
        !run.stderr.contains("bands run whole"),
        "every band went whole:\n{}",
        run.stderr
    );
    check_output(
        &model("torus-8x6"),
        &out,
        &m,
        "torus-8x6",
        DxfCheck::FirstAndLast,
        |e| e["id"].as_str().unwrap().to_string(),
    );
}

/// Round genus2's saddles a piece's faces can wrap round a corner of its strip's side
/// until two of their edges lie on one line (its outline would meet itself): such a
/// piece is cut at a rung, and the model builds at every size.
#[test]
fn a_piece_that_would_wrap_onto_itself_is_cut_in_two() {
    for size in ["300mm", "350mm"] {
        let tmp = TempDir::new().unwrap();
        let out = tmp.path().join("out");
        let extra = ["--sheet", "18x24in", "--format", "svg,dxf"];
        let (m, run) = build_run("strip", &model("genus2"), size, &out, &extra);
        assert!(
            run.stderr.contains("strip: "),
            "no report at {size}:\n{}",
            run.stderr
        );
        check_output(
            &model("genus2"),
            &out,
            &m,
            "genus2",
            DxfCheck::FirstAndLast,
            |e| e["id"].as_str().unwrap().to_string(),
        );
    }
}

#[test]
fn the_bunny_is_strips_within_the_bound() {
    let Some(shared) = shared_models("the_bunny_is_strips_within_the_bound") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let bunny = simplified_obj(&shared.join("stanford-bunny.obj"), 1500, true, tmp.path());
    let (p, _) = strip_built_once(&bunny, "2ft", "1%", &tmp.path().join("out"), false);
    let pts = p.mesh.positions();
    let (lo, hi) = pts.iter().fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &q| {
        (lo.min(q), hi.max(q))
    });
    check_strips("bunny", &p, 0.01 * (hi - lo).length());
}

#[test]
fn models_with_holes_are_strips_within_the_bound() {
    let Some(shared) = shared_models("models_with_holes_are_strips_within_the_bound") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    // The teapot as given has rims round its spout, its lid and its body, some close
    // together; the bunny as given, five ragged scan holes side by side in its base.
    for file in ["teapot.obj", "stanford-bunny.obj"] {
        strips_at_four_feet(file, &shared.join(file), &tmp.path().join(file));
    }
}

#[test]
fn simplified_models_with_holes_are_strips_within_the_bound() {
    let Some(shared) = shared_models("simplified_models_with_holes_are_strips_within_the_bound")
    else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    // The bunny simplified with its holes kept: its distance from them has bumps
    // (ears, back) inside bands, and simplified further, a strip allowed to fold round
    // a ridge between two holes runs back over itself (split, not welded).
    let bunny = shared.join("stanford-bunny.obj");
    let simplified = simplified_obj(&bunny, 20_000, false, tmp.path());
    let coarser = simplified_obj(&bunny, 10_000, false, tmp.path());
    for path in [simplified, coarser] {
        let model = &path.file_name().unwrap().to_string_lossy().into_owned();
        strips_at_four_feet(model, &path, &tmp.path().join(format!("{model}.out")));
    }
}

/// Builds `model` at 4 ft within 0.5 % once (every sheet checked; laid out by the shelf
/// nester, since the strips are tested here, not how tightly they pack) and checks its
/// strips: more than one, within the bound both ways, the pieces the manifest counts.
fn strips_at_four_feet(what: &str, model: &Path, out: &Path) {
    let (p, m) = strip_built_once(model, "4ft", "0.5%", out, true);
    let (strips, pieces) = check_strips(what, &p, num(&m, "strip.max_deviation"));
    assert!(strips > 1, "{what}: {strips} strips");
    assert_eq!(count(&m, "strip.pieces"), pieces, "{what}: the same pieces");
}

#[test]
fn a_model_with_legs_is_strips_within_the_bound() {
    // Between its two points farthest apart, a harmonic field stays level along the
    // horse's legs, too flat to split; the distance from one of them rises along them.
    let Some(shared) = shared_models("a_model_with_legs_is_strips_within_the_bound") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let horse = shared.join("horse_quad.obj");
    strips_at_four_feet("horse", &horse, &tmp.path().join("out"));
    // Simplified to 400 edges its legs are stubs no strips cover: the refusal names
    // the simplification, which is the cause, and what mends it.
    let coarse = tmp.path().join("coarse");
    let mut cmd = unfold_command();
    cmd.arg(&horse).args([
        "--scheme",
        "strip",
        "--size",
        "4ft",
        "--target-edges",
        "400",
    ]);
    let run = finish(cmd.arg("--out").arg(&coarse));
    assert_refusal(
        "horse simplified to 400 edges",
        &run,
        2,
        &[
            "from the model as given",
            "--target-edges",
            "allow at least",
        ],
    );
    assert!(!coarse.exists(), "nothing written");
}

#[test]
fn pins_go_through_every_tab_that_holds_them_and_the_face_it_folds_onto() {
    // A tab carries its holes whether or not its edge carries its seam's number: most
    // do not.
    let tmp = TempDir::new().unwrap();
    let model = torus(tmp.path(), 24, 12, 80.0, 30.0);
    let p = pipeline(&job("strip", &model, "2ft", 1, &tmp.path().join("out")));
    let mut by_connection: BTreeMap<u32, Vec<DVec3>> = BTreeMap::new();
    for panel in &p.panels {
        for hole in &panel.holes {
            by_connection
                .entry(hole.connection)
                .or_default()
                .push(hole.position);
        }
    }
    for (connection, holes) in &by_connection {
        let [tab, face] = holes[..] else {
            panic!("connection {connection}: {} holes", holes.len());
        };
        assert!(
            tab.distance(face) < 1e-6,
            "connection {connection}: its holes meet {} mm apart",
            tab.distance(face)
        );
    }
    // Every connection is pinned but those the build says have no room for a hole.
    let (pinned, cuts) = (by_connection.len(), p.output.connections);
    let unfastened = p.output.unfastened.len();
    assert!(pinned > 0, "no connection pinned");
    assert_eq!(
        pinned + unfastened,
        cuts,
        "{pinned} pinned and {unfastened} without room of {cuts} connections"
    );
}

#[test]
fn strips_are_the_same_bytes_on_one_and_two_threads() {
    let tmp = TempDir::new().unwrap();
    let model = torus(tmp.path(), 24, 12, 80.0, 30.0);
    assert_same_bytes_on_one_and_two_threads(
        &model,
        &[
            "--scheme",
            "strip",
            "--size",
            "200mm",
            "--max-deviation",
            "1%",
        ],
    );
}

#[test]
fn a_bound_of_zero_or_below_is_a_usage_error() {
    for bad in ["0mm", "-1%", "0%", "abc", "5"] {
        let tmp = TempDir::new().unwrap();
        let flag = format!("--max-deviation={bad}");
        let run = unfold([
            model("torus-8x6").to_str().unwrap(),
            "--scheme",
            "strip",
            "--size",
            "200mm",
            &flag,
            "--out",
            tmp.path().join("out").to_str().unwrap(),
        ]);
        assert_refusal(bad, &run, 2, &["--max-deviation"]);
        assert!(!tmp.path().join("out").exists(), "{bad}: nothing written");
    }
}

#[test]
fn strips_too_narrow_for_their_ids_warn_with_a_bound_that_gives_them_room() {
    let tmp = TempDir::new().unwrap();
    let model = torus(tmp.path(), 48, 24, 80.0, 30.0);
    let out = tmp.path().join("out");
    // The shelf nester: the warning, the joined pieces and the refusal are tested
    // here, not the layout.
    let args = [
        "--scheme", "strip", "--size", "9in", "--quiet", "--nester", "shelf",
    ];
    // Warned (built), and refused under --strict with nothing written.
    let run = unfold_command()
        .arg(&model)
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(0));
    let manifest = read_manifest(&out);
    let warning = manifest["warnings"][0]
        .as_str()
        .expect("a warning")
        .to_string();
    assert!(
        warning.contains("strip panels have no room for their id"),
        "{warning}"
    );
    // A strip's end with no room for its id is joined to a neighbour piece, which
    // keeps its own name and unrolls exactly.
    let joined = manifest["strip"]["joined"]
        .as_array()
        .expect("strip.joined");
    assert!(!joined.is_empty(), "no piece joined to a neighbour");
    for j in joined {
        let piece = j["piece"].as_str().unwrap();
        let panel = manifest["panels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["id"] == piece)
            .unwrap_or_else(|| panic!("{piece} is no piece"));
        let strip = j["strip"].as_u64().unwrap();
        assert_ne!(panel["source"]["strip"].as_u64(), Some(strip), "{piece}");
        let faces: Vec<&Value> = panel["source"]["faces"]
            .as_array()
            .unwrap()
            .iter()
            .collect();
        for f in j["faces"].as_array().unwrap() {
            assert!(faces.contains(&f), "{piece} lacks face {f} of S{strip}");
        }
        assert!(
            panel["developability_error"].as_f64().unwrap() <= 1e-9,
            "{piece}"
        );
    }
    let bound = warning
        .split("--max-deviation ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("no bound named: {warning}"))
        .to_string();
    let strict = tmp.path().join("strict");
    let strict_run = |extra: &[&str]| {
        let mut cmd = unfold_command();
        cmd.arg(&model).args(args).args(extra);
        finish(cmd.arg("--strict").arg("--out").arg(&strict))
    };
    let run = strict_run(&[]);
    assert_refusal(
        "--strict",
        &run,
        2,
        &["--max-deviation", "refused by --strict"],
    );
    assert!(!strict.exists(), "nothing written");
    // The bound named builds clean under --strict.
    let run = strict_run(&["--max-deviation", &bound]);
    assert_eq!(run.code, Some(0), "--max-deviation {bound}: {}", run.stderr);
    assert_eq!(
        count(&read_manifest(&strict), "counts.panel_ids_left_out"),
        0,
        "--max-deviation {bound}"
    );
}

#[test]
fn a_simplified_model_keeps_the_bound_to_the_model_as_given() {
    // A fine torus simplified to 5,000 edges lies about a millimetre from the torus
    // as given: strips within 1 % of the simplified mesh would stray beyond 1 % of
    // the torus as given, so they are kept within less of the simplified mesh.
    let tmp = TempDir::new().unwrap();
    let model = torus(tmp.path(), 96, 48, 80.0, 30.0);
    let out = tmp.path().join("out");
    let args = ["--target-edges", "5000", "--max-deviation", "1%"];
    let m = build("strip", &model, "2ft", &out, &args);
    let bound = num(&m, "strip.max_deviation");
    // Measured here: the assembled strips against the file as given, both ways.
    let mm = num(&m, "scheme.params.mm_per_model_unit");
    let (points, faces) = read_simple_obj(&model);
    let fans = |points: &[DVec3], faces: &[Vec<usize>], scale: f64| -> Vec<[DVec3; 3]> {
        faces
            .iter()
            .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
            .map(|t| t.map(|i| points[i] * scale))
            .collect()
    };
    let given = fans(&points, &faces, mm);
    let (points, faces) = read_simple_obj(&out.join("torus-assembled.obj"));
    let strips = fans(&points, &faces, 1.0);
    let spacing = bound / 4.0;
    let away = one_way(&strips, &given, spacing, 2.0 * bound);
    let back = one_way(&given, &strips, spacing, 2.0 * bound);
    eprintln!("simplified torus: strips {away:.3} mm from it, it {back:.3} mm from them (bound {bound:.3} mm)");
    assert!(away <= bound, "strips {away} mm from the torus as given");
    assert!(
        back <= bound,
        "the torus as given {back} mm from the strips"
    );
    let within = num(&m, "strip.simplified_bound");
    assert!(
        within < bound,
        "the strips are kept within {within} mm of the simplified mesh, not less than the bound {bound} mm"
    );
    assert!(num(&m, "strip.simplified_deviation") <= within);
    assert!(num(&m, "strip.measured_deviation") <= bound);
    // Simplified to 600 edges it lies further from itself than strips could make up
    // for: a usage error naming the fixes, nothing written.
    let coarse = tmp.path().join("coarse");
    let run = unfold([
        model.to_str().unwrap(),
        "--scheme",
        "strip",
        "--size",
        "2ft",
        "--target-edges",
        "600",
        "--max-deviation",
        "1%",
        "--out",
        coarse.to_str().unwrap(),
    ]);
    assert_refusal(
        "simplified to 600 edges",
        &run,
        2,
        &[
            "from the model as given",
            "--target-edges",
            "allow at least",
        ],
    );
    assert!(!coarse.exists(), "nothing written");
}

/// A band whose strip folds over its outline however narrow it is split (round the
/// sharp corners of a coarse model, or round holes) is not a matter of the bound: the
/// refusal says a larger --max-deviation does not change it and names what builds,
/// closing the holes where the model has any, and the net scheme. Where the
/// simplification itself leaves the strips too little of the bound, that is named
/// first, without a larger bound.
#[test]
fn strips_that_fold_at_any_bound_name_what_builds() {
    let Some(shared) = shared_models("strips_that_fold_at_any_bound_name_what_builds") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let coarse = ["--target-edges", "100", "--size", "1ft"];
    let strips = |model: &str, bound: &str| {
        let mut cmd = unfold_command();
        cmd.arg(shared.join(model)).args(coarse);
        cmd.args(["--scheme", "strip", "--max-deviation", bound]);
        finish(cmd.arg("--out").arg(&out))
    };
    let cases = [
        // (model, the fix named, whether it has holes)
        ("fertility.obj", "use --scheme net", false),
    ];
    for (model, fix, holes) in cases {
        // At 5 % the simplification is named first: it lies further from the model
        // than the bound leaves the strips, and less of it is the fix, not a larger
        // bound (at ten times the bound the strips still fold).
        let run = strips(model, "5%");
        let case = format!("{model} at 5%");
        assert_refusal(
            &case,
            &run,
            2,
            &["from the model as given", "--target-edges"],
        );
        for never in ["allow at least", "may reach"] {
            assert!(!run.stderr.contains(never), "{case}: {}", run.stderr);
        }
        assert!(!out.exists(), "{case}: nothing written");
        // At ten times the bound the simplification is within it and the strips fold:
        // the advice is not to raise it.
        let run = strips(model, "50%");
        let case = format!("{model} at 50%");
        assert_refusal(
            &case,
            &run,
            1,
            &["folds over its outline", "does not change that", fix],
        );
        assert!(!run.stderr.contains("may reach"), "{case}: {}", run.stderr);
        assert_eq!(
            run.stderr.contains("--fill-holes"),
            holes,
            "{case}: {}",
            run.stderr
        );
        assert!(!out.exists(), "{case}: nothing written");
        // What the refusal names builds.
        let m = build("net", &shared.join(model), "1ft", &out, &coarse[..2]);
        assert!(count(&m, "counts.panels") > 0, "{model}: net islands");
        std::fs::remove_dir_all(&out).unwrap();
    }
}
