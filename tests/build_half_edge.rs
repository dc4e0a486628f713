//! End-to-end tests of the build pipeline with the half-edge scheme: the real binary
//! (`CARGO_BIN_EXE_unfold`) writes its output folder into a temporary directory and the
//! independent sheet checker of `tests/common` reads it back; a few checks call the
//! library stages directly (scheme → flatten) to follow holes and labels back to 3D.
//!
//! Tests that use `../shared/models` skip with a message when that folder is absent.
//! The DXF check (read back in Rust, and by ezdxf through `tests/check_dxf.py` where
//! python3 has it) costs ezdxf about a second per sheet, a
//! few seconds for the big sheets of spot and fertility: for those two models only the
//! first and the last sheet's DXF are checked (every SVG still is), unless
//! `UNFOLD_FULL_DXF=1`.
//!
//! `UNFOLD_UPDATE_GOLDEN=1 cargo test --test build_half_edge golden` rewrites
//! `tests/golden/tetrahedron-half-edge/`.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::OsStr;
use std::path::Path;

use glam::{DVec2, DVec3};
use serde_json::Value;
use tempfile::TempDir;

use common::build::{
    check_output, check_sheets, close, count, distance_to_border, entry_names, finish,
    folder_files, frames_of, golden_build, inside, inspect_json, model, num, obj_face_count,
    panels_of, read_manifest, read_simple_obj, shared_models, unfold, unfold_command, DxfCheck,
};
use unfold::config::Job;
use unfold::mesh::{EdgeId, Mesh};
use unfold::panel::{Covers, FlatPanel, LabelKind, Panel};

// =======================================================================================
// Helpers (the shared ones are in tests/common/build.rs)
// =======================================================================================

/// Runs `unfold MODEL --scheme half-edge --size SIZE --out OUT EXTRA…`, asserts success
/// and returns the parsed `manifest.json`.
fn build(model: &Path, size: &str, out: &Path, extra: &[&str]) -> Value {
    common::build::build("half-edge", model, size, out, extra)
}

/// Area of a planar 3D polygon (Newell's vector area).
fn polygon_area_3d(points: &[DVec3]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| points[i].cross(points[(i + 1) % n]))
        .sum::<DVec3>()
        .length()
        * 0.5
}

fn half_edge_job(model: &Path, size: &str, holes: u32, out: &Path) -> Job {
    common::build::job("half-edge", model, size, holes, out)
}

// =======================================================================================
// 1. Every sheet passes the independent check, and the manifest adds up
// =======================================================================================

/// Builds one model with `--sheet 18x24in --format svg,dxf`, checks every sheet and
/// the manifest's counts against the sheets.
fn check_build(model: &Path, size: &str, dxf: DxfCheck, extra: &[&str]) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let what = format!("{} at {size}", model.display());
    let mut args = vec!["--sheet", "18x24in", "--format", "svg,dxf"];
    args.extend_from_slice(extra);
    let m = build(model, size, &out, &args);
    // Files, sheets against the manifest, panel list (ids F<face>), layout figures.
    check_output(model, &out, &m, &what, dxf, |p| {
        format!("F{}", count(p, "source.face"))
    });

    // Panels: one per face of the mesh the scheme used (after splits).
    let panels = count(&m, "counts.panels");
    let faces = count(&m, "input.faces");
    assert_eq!(panels, faces, "{what}: one panel per face");
    let own_faces = obj_face_count(model);
    let split =
        count(&m, "input.faces_split.non_planar") + count(&m, "input.faces_split.not_star_shaped");
    if split == 0 {
        assert_eq!(
            faces, own_faces,
            "{what}: nothing split, so the model's own faces"
        );
    } else {
        assert!(
            faces >= own_faces + split,
            "{what}: {split} faces split into triangles, yet only {faces} faces from {own_faces}"
        );
    }
}

#[test]
fn every_sheet_passes_the_independent_check() {
    for name in [
        "tetrahedron",
        "hexahedron",
        "octahedron",
        "dodecahedron",
        "icosahedron",
        "torus-8x6",
    ] {
        check_build(&model(name), "12in", DxfCheck::All, &[]);
    }
    for name in ["genus2", "concave", "open-grid"] {
        check_build(&model(name), "300mm", DxfCheck::All, &[]);
    }
}

/// The same on fertility (a test of its own so that it runs beside the project
/// models). Laid out by the shelf nester: this checks the panels and the
/// sheets, not how tightly they are packed (`tests/nesting.rs` and the bench check the
/// true-shape layout of such models), and it keeps the suite quick.
#[test]
fn every_sheet_of_fertility_passes_the_independent_check() {
    let test = "every_sheet_of_fertility_passes_the_independent_check";
    check_shared_build(test, "fertility.obj");
}

/// The same on spot, a test of its own so that it runs beside fertility.
#[test]
fn every_sheet_of_spot_passes_the_independent_check() {
    check_shared_build(
        "every_sheet_of_spot_passes_the_independent_check",
        "spot.obj",
    );
}

/// [`check_build`] on the shared model `name` at 4 ft on the shelf nester.
fn check_shared_build(test: &str, name: &str) {
    if let Some(shared) = shared_models(test) {
        check_build(
            &shared.join(name),
            "4ft",
            DxfCheck::FirstAndLast,
            &["--nester", "shelf"],
        );
    }
}

// =======================================================================================
// 2. Without tabs the panels are the faces: same area as the surface
// =======================================================================================

#[test]
fn face_areas_equal_the_model_surface_area() {
    for (name, size, size_mm) in [
        ("hexahedron", "12in", 304.8),
        ("dodecahedron", "12in", 304.8),
        ("torus-8x6", "12in", 304.8),
        ("genus2", "300mm", 300.0),
        ("concave", "300mm", 300.0),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);

        let tmp = TempDir::new().unwrap();
        let bare = build(
            &path,
            size,
            &tmp.path().join("bare"),
            &["--connectors", "none", "--face-scale", "1"],
        );
        let area = num(&bare, "panel_area");
        assert!(
            close(area, surface, 1e-6),
            "{name}: panel area without tabs {area} mm², surface area {surface} mm²"
        );
        assert_eq!(
            count(&bare, "counts.connections"),
            0,
            "{name}: no connectors"
        );
        let error = num(&bare, "max_developability_error");
        assert!(
            error < 1e-9 * size_mm,
            "{name}: developability error {error} mm on a {size_mm} mm model"
        );

        // Panel by panel: the area of its face in the file, scaled to millimetres.
        let (positions, faces) = read_simple_obj(&path);
        let mm = num(&bare, "scheme.params.mm_per_model_unit");
        for p in bare["panels"].as_array().unwrap() {
            let face = &faces[count(p, "source.input_face")];
            let points: Vec<DVec3> = face.iter().map(|&v| positions[v] * mm).collect();
            let want = polygon_area_3d(&points);
            let got = num(p, "area");
            assert!(
                (got - want).abs() <= 1e-4 + 1e-9 * want,
                "{name}: panel {} has area {got} mm², its face {want} mm²",
                p["id"]
            );
        }

        let tabs = build(&path, size, &tmp.path().join("tabs"), &[]);
        let with_tabs = num(&tabs, "panel_area");
        assert!(
            with_tabs > area * (1.0 + 1e-6),
            "{name}: tabs add area: {with_tabs} mm² with tabs, {area} mm² without"
        );
        assert!(
            count(&tabs, "counts.connections") > 0,
            "{name}: tabs are connections"
        );
    }
}

/// `unfold inspect MODEL --json --size SIZE`: the built surface area in mm².
fn surface_area_mm2(path: &Path, size: &str) -> f64 {
    num(
        &inspect_json(path, &["--size", size]),
        "physical.surface_area_mm2",
    )
}

#[test]
fn face_scale_shrinks_every_panel_by_its_square() {
    // Without connectors a panel is its face scaled by s about the face centre.
    for (name, size, s) in [
        ("hexahedron", "12in", 0.8),
        ("genus2", "300mm", 0.7),
        ("concave", "300mm", 0.5),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);
        let tmp = TempDir::new().unwrap();
        let out = tmp.path().join("out");
        let scale = s.to_string();
        let m = build(
            &path,
            size,
            &out,
            &["--connectors", "none", "--face-scale", &scale],
        );
        let area = num(&m, "panel_area");
        assert!(
            close(area, s * s * surface, 1e-6),
            "{name}: --face-scale {s}: panel area {area} mm², want {s}² × {surface} mm²"
        );
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        assert_eq!(sheets.total().panels, count(&m, "counts.panels"));
    }
}

/// With `s < 1` each tab first spans the gap between its panel and the mesh edge (a
/// bridge facet in the panel's plane). `face_panel` gives every bridge its own copies
/// of the two mesh corners, so two tabs on adjacent edges of one face have bridges
/// that share the mitre from the band corner to the mesh corner: unrolled, the outline
/// runs along that segment twice and the run stops with "panel F1 overlaps itself
/// when unrolled; try a smaller --tab-height" (no tab height helps).
#[test]

fn face_scale_below_one_with_tabs_builds_valid_sheets() {
    for (name, size) in [
        ("tetrahedron", "12in"),
        ("hexahedron", "12in"),
        ("genus2", "300mm"),
    ] {
        let path = model(name);
        let surface = surface_area_mm2(&path, size);
        let tmp = TempDir::new().unwrap();
        let out = tmp.path().join("out");
        let m = build(
            &path,
            size,
            &out,
            &["--face-scale", "0.8", "--holes", "1", "--format", "svg,dxf"],
        );
        assert_eq!(count(&m, "counts.panels"), obj_face_count(&path), "{name}");
        assert!(
            num(&m, "panel_area") > 0.64 * surface,
            "{name}: bridges and tabs add to the 0.8² face bands"
        );
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        assert_eq!(sheets.total().panels, count(&m, "counts.panels"));
        assert_eq!(sheets.total().holes, count(&m, "counts.holes"));
    }
}

// =======================================================================================
// 3. Holes of a connection meet in 3D
// =======================================================================================

/// Follows every flat hole back to 3D through its facet's frame and checks that the
/// holes of each connection pair up between the two faces of its edge.
/// `rel_tol`: how close (relative to the model size) partner holes must be on the
/// band's plane: 1e-9 for exact geometry.
fn check_holes(model: &Path, size: &str, size_mm: f64, holes: u32, rel_tol: f64) {
    let tmp = TempDir::new().unwrap();
    let job = half_edge_job(model, size, holes, &tmp.path().join("out"));
    check_holes_of(&job, panels_of(&job), size_mm, rel_tol);
}

/// [`check_holes`] on the panels of `job` built already (a test that checks more of
/// the same panels builds them once).
fn check_holes_of(
    job: &Job,
    (mesh, connections, panels, flat): (Mesh, usize, Vec<Panel>, Vec<FlatPanel>),
    size_mm: f64,
    rel_tol: f64,
) {
    let holes = job.scheme.panel().holes;
    let what = format!(
        "{} at {size_mm} mm, --holes {holes}",
        job.model_path.display()
    );
    let frames = frames_of(&panels);
    let tol = rel_tol * size_mm;
    let r = 0.5 * job.scheme.panel().hole_diameter;

    // How far a facet's 3D corners are from the plane of its frame: 0 (rounding) for
    // planar faces; faces planar only within --planarity-tol are kept as one facet,
    // and a point mapped back through the frame lands on the frame's plane.
    let flatness = |k: usize, facet: u32| -> f64 {
        let frame = frames[k][facet as usize];
        let normal = frame.x3.cross(frame.y3);
        panels[k].facets[facet as usize]
            .iter()
            .map(|&i| {
                (panels[k].vertices[i as usize] - frame.origin3)
                    .dot(normal)
                    .abs()
            })
            .fold(0.0, f64::max)
    };
    let mut worst_apart = 0.0f64;

    // connection → [(panel index, facet, 3D point)]
    let mut by_connection: BTreeMap<u32, Vec<(usize, u32, DVec3)>> = BTreeMap::new();
    let mut total = 0;
    for (k, fp) in flat.iter().enumerate() {
        assert_eq!(fp.holes.len(), panels[k].holes.len(), "{what}: {}", fp.id());
        for hole in &fp.holes {
            total += 1;
            let facet: Vec<DVec2> = panels[k].facets[hole.facet as usize]
                .iter()
                .map(|&i| fp.points[i as usize])
                .collect();
            assert!(
                inside(&facet, hole.center),
                "{what}: {} hole of connection {} at {} is outside its facet {}",
                fp.id(),
                hole.connection,
                hole.center,
                hole.facet
            );
            let clear = distance_to_border(&facet, hole.center);
            assert!(
                clear >= r - 1e-9,
                "{what}: {} hole of connection {} is {clear} mm from its facet's edge, radius {r}",
                fp.id(),
                hole.connection
            );
            let p = frames[k][hole.facet as usize].to_3d(hole.center);
            by_connection
                .entry(hole.connection)
                .or_default()
                .push((k, hole.facet, p));
        }
    }
    assert!(!by_connection.is_empty(), "{what}: no connection has holes");
    assert!(
        by_connection.len() <= connections,
        "{what}: more connections with holes than connections"
    );

    let per = holes as usize;
    for (&c, list) in &by_connection {
        // As many as asked, or as many as the tab holds: a pair per hole.
        assert!(
            list.len() % 2 == 0 && list.len() <= 2 * per,
            "{what}: connection {c} has {} holes, want {} or fewer pairs",
            list.len(),
            2 * per
        );
        let owners: BTreeSet<usize> = list.iter().map(|h| h.0).collect();
        assert_eq!(
            owners.len(),
            2,
            "{what}: connection {c} holes on panels {owners:?}"
        );
        // The two panels are the two faces of edge c.
        let e = EdgeId(c);
        let faces: BTreeSet<u32> = [e.half_edge(), e.half_edge().twin()]
            .iter()
            .map(|&h| mesh.face(h).expect("a connection joins two faces").0)
            .collect();
        let sources: BTreeSet<u32> = owners
            .iter()
            .map(|&k| match flat[k].source.covers {
                Covers::Face(f) => f,
                other => panic!("{what}: half-edge panel from {other:?}"),
            })
            .collect();
        assert_eq!(
            sources, faces,
            "{what}: connection {c} joins the faces of edge {c}"
        );
        let [a, b]: [usize; 2] = owners
            .iter()
            .copied()
            .collect::<Vec<_>>()
            .try_into()
            .unwrap();
        let on_a: Vec<&(usize, u32, DVec3)> = list.iter().filter(|h| h.0 == a).collect();
        let on_b: Vec<&(usize, u32, DVec3)> = list.iter().filter(|h| h.0 == b).collect();
        assert_eq!(
            (on_a.len(), on_b.len()),
            (list.len() / 2, list.len() / 2),
            "{what}: connection {c}: the same holes on both panels"
        );
        // One panel carries the tab (a facet other than its face band 0), the other
        // takes the holes through its face band.
        let band_a = on_a.iter().all(|h| h.1 == 0);
        let band_b = on_b.iter().all(|h| h.1 == 0);
        let tab_a = on_a.iter().all(|h| h.1 != 0);
        let tab_b = on_b.iter().all(|h| h.1 != 0);
        assert!(
            (band_a && tab_b) || (tab_a && band_b),
            "{what}: connection {c}: holes on facets {:?} and {:?}",
            on_a.iter().map(|h| h.1).collect::<Vec<_>>(),
            on_b.iter().map(|h| h.1).collect::<Vec<_>>()
        );
        // Pair every hole through the face band with one tab hole. Mapped back through
        // their facets they are the same 3D point, exactly when the face is planar; a
        // face planar only within --planarity-tol stays one facet, and the band's frame
        // puts the point on the facet's plane: compare on that plane, and check the
        // plain distance against the facet's flatness.
        let (tab_side, band_side, band_panel) = if band_a {
            (&on_b, &on_a, a)
        } else {
            (&on_a, &on_b, b)
        };
        let frame = frames[band_panel][0];
        let normal = frame.x3.cross(frame.y3);
        let slack = 2.0 * flatness(band_panel, 0);
        let mut matched = BTreeSet::new();
        for hb in band_side.iter() {
            let (nearest, j) = tab_side
                .iter()
                .enumerate()
                .map(|(j, ht)| {
                    let q = ht.2 - (ht.2 - frame.origin3).dot(normal) * normal;
                    (q.distance(hb.2), j)
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap();
            assert!(
                nearest <= tol,
                "{what}: connection {c}: hole of {} at {} has no partner hole on the tab (nearest {nearest} mm)",
                flat[band_panel].id(),
                hb.2
            );
            assert!(
                matched.insert(j),
                "{what}: connection {c}: two holes share one partner"
            );
            let apart = tab_side[j].2.distance(hb.2);
            worst_apart = worst_apart.max(apart);
            assert!(
                apart <= tol + slack,
                "{what}: connection {c}: partner holes {apart} mm apart in 3D (facet flat within {slack} mm)"
            );
        }
        if on_a.len() == 2 {
            let gap = on_a[0].2.distance(on_a[1].2);
            assert!(
                gap > 2.0 * r,
                "{what}: connection {c}: two holes {gap} mm apart"
            );
        }
    }

    // The manifest reports the same holes and connections. They do not depend on the
    // layout: the shelf nester lays the sheets out quickest.
    let mut counted = job.clone();
    counted.nest.nester = unfold::nest::NesterName::Shelf;
    let outcome = unfold::run(&counted).expect("the job runs");
    assert_eq!(outcome.manifest.counts.holes, total, "{what}: counts.holes");
    assert_eq!(
        outcome.manifest.counts.connections, connections,
        "{what}: counts.connections"
    );
    eprintln!(
        "{what}: {} of {connections} connections have holes, {total} holes; partner holes at most {worst_apart:.1e} mm apart",
        by_connection.len()
    );
}

#[test]
fn holes_of_a_connection_meet_in_3d() {
    for (name, size, size_mm) in [
        ("hexahedron", "12in", 304.8),
        ("dodecahedron", "12in", 304.8),
        ("torus-8x6", "12in", 304.8),
        ("genus2", "300mm", 300.0),
    ] {
        check_holes(&model(name), size, size_mm, 2, 1e-9);
    }
    check_holes(&model("genus2"), "300mm", 300.0, 1, 1e-9);
    // Fertility, whose quads are planar only within --planarity-tol, is the next test's.
}

/// Facets planar only within the tolerance (fertility's quads): each facet's frame must
/// be orthonormal, its x axis (a facet edge or the hinge) projected onto the facet's
/// plane, or `to_3d(to_2d(p))` is not the projection of p onto that plane and holes
/// mapped back through the two panels' frames miss each other.
#[test]
fn holes_of_a_connection_meet_in_3d_on_near_planar_faces() {
    let Some(shared) = shared_models("holes_of_a_connection_meet_in_3d_on_near_planar_faces")
    else {
        return;
    };
    let fertility = shared.join("fertility.obj");
    let tmp = TempDir::new().unwrap();
    let job = half_edge_job(&fertility, "4ft", 2, &tmp.path().join("out"));
    let built = panels_of(&job);
    let (_, _, panels, flat) = &built;
    for (fp, frames) in flat.iter().zip(frames_of(panels)) {
        for (k, f) in frames.iter().enumerate() {
            assert!(
                (f.x3.length() - 1.0).abs() < 1e-12
                    && (f.y3.length() - 1.0).abs() < 1e-12
                    && f.x3.dot(f.y3).abs() < 1e-12,
                "{} facet {k}: frame axes |x3| = {}, |y3| = {}, x3·y3 = {:e}",
                fp.id(),
                f.x3.length(),
                f.y3.length(),
                f.x3.dot(f.y3)
            );
        }
    }
    check_holes_of(&job, built, 1219.2, 1e-9);
}

// =======================================================================================
// 4. Determinism
// =======================================================================================

#[test]
fn output_is_byte_identical_across_runs_and_threads() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let runs: [(&str, Option<&str>); 4] = [
        ("default-a", None),
        ("default-b", None),
        ("threads-1", Some("1")),
        ("threads-2", Some("2")),
    ];
    let mut outputs = Vec::new();
    for (label, threads) in runs {
        let out = tmp.path().join(label);
        let mut cmd = unfold_command();
        cmd.arg(&path)
            .args(["--scheme", "half-edge", "--size", "300mm", "--holes", "1"])
            .args(["--format", "svg,dxf", "--out"])
            .arg(&out);
        cmd.env_remove("RAYON_NUM_THREADS");
        if let Some(n) = threads {
            cmd.env("RAYON_NUM_THREADS", n);
        }
        let run = finish(&mut cmd);
        assert_eq!(run.code, Some(0), "{label}: {}", run.stderr);
        outputs.push((label, folder_files(&out)));
    }
    let (first_label, first) = &outputs[0];
    assert!(first.keys().any(|n| n.ends_with(".dxf")) && first.keys().any(|n| n.ends_with(".svg")));
    for (label, files) in &outputs[1..] {
        assert_eq!(
            files.keys().collect::<Vec<_>>(),
            first.keys().collect::<Vec<_>>(),
            "{label} and {first_label} wrote different files"
        );
        for (name, bytes) in files {
            assert!(
                bytes == &first[name],
                "{name} differs between {first_label} and {label}"
            );
        }
    }
}

// =======================================================================================
// 5. Golden files
// =======================================================================================

#[test]
fn golden_files_of_a_small_model() {
    let args = ["--size", "150mm", "--scheme", "half-edge", "--holes", "1"];
    let Some((_tmp, out, manifest)) = golden_build(
        "build_half_edge",
        "tetrahedron-half-edge",
        "tetrahedron",
        &args,
    ) else {
        return;
    };
    // The golden sheets themselves pass the independent check.
    let sheets = check_sheets(&out, &manifest, DxfCheck::All);
    assert_eq!(sheets.total().panels, 4);
    assert_eq!(sheets.total().holes, count(&manifest, "counts.holes"));
}

// =======================================================================================
// 6. Non-planar faces
// =======================================================================================

#[test]
fn non_planar_faces_are_triangulated_or_refused() {
    let Some(shared) = shared_models("non_planar_faces_are_triangulated_or_refused") else {
        return;
    };
    let suzanne = shared.join("suzanne.obj");
    let tmp = TempDir::new().unwrap();

    let out = tmp.path().join("suzanne");
    let m = build(&suzanne, "4ft", &out, &["--format", "svg"]);
    let non_planar = count(&m, "input.faces_split.non_planar");
    assert!(non_planar > 0, "suzanne has non-planar quads");
    let own = obj_face_count(&suzanne);
    // Every split quad becomes two triangles (or a fan of four).
    assert!(
        count(&m, "input.faces") >= own + non_planar,
        "{} faces after splitting {non_planar} of {own}",
        count(&m, "input.faces")
    );
    assert_eq!(count(&m, "counts.panels"), count(&m, "input.faces"));
    let sheets = check_sheets(&out, &m, DxfCheck::All);
    assert_eq!(sheets.svg_files.len(), count(&m, "counts.sheets"));
    assert_eq!(sheets.total().panels, count(&m, "counts.panels"));

    let refused = tmp.path().join("refused");
    let run = unfold([
        suzanne.as_os_str(),
        OsStr::new("--scheme"),
        OsStr::new("half-edge"),
        OsStr::new("--size"),
        OsStr::new("4ft"),
        OsStr::new("--nonplanar"),
        OsStr::new("error"),
        OsStr::new("--out"),
        refused.as_os_str(),
    ]);
    assert_eq!(run.code, Some(3), "--nonplanar error: {}", run.stderr);
    // A 12 in cube covers 250 sheets of 60 mm: the size check warns before the error.
    let lines: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| !l.starts_with("unfold: warning: "))
        .collect();
    assert_eq!(lines.len(), 1, "one line of error: {:?}", run.stderr);
    let line = lines[0];
    assert!(line.starts_with("unfold: error: "), "{line}");
    let at = line
        .find("suzanne.obj:")
        .unwrap_or_else(|| panic!("the error names suzanne.obj: {line}"));
    let rest = &line[at + "suzanne.obj:".len()..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    assert!(
        !digits.is_empty() && rest[digits.len()..].starts_with(':'),
        "the error gives a :LINE: location: {line}"
    );
    // The line named is a face of the file.
    let number: usize = digits.parse().unwrap();
    let text = std::fs::read_to_string(&suzanne).unwrap();
    let named = text.lines().nth(number - 1).unwrap_or("");
    assert!(
        named.starts_with("f "),
        "line {number} of suzanne.obj is not a face: {named:?}"
    );
    assert!(!refused.exists(), "a refused model leaves no output folder");
    assert!(
        !tmp.path().join(".refused.unfold-new").exists(),
        "no staging folder is left"
    );
}

// =======================================================================================
// 7. Atomic output folder
// =======================================================================================

#[test]
fn output_folder_is_replaced_atomically() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("hexa");
    let path = model("hexahedron");
    build(&path, "12in", &out, &["--format", "svg,dxf"]);
    let before = folder_files(&out);
    assert!(before.len() > 2);

    let fail = |dir: &Path| {
        unfold([
            path.as_os_str(),
            OsStr::new("--scheme"),
            OsStr::new("half-edge"),
            OsStr::new("--size"),
            OsStr::new("12in"),
            OsStr::new("--sheet"),
            OsStr::new("60x60mm"),
            OsStr::new("--out"),
            dir.as_os_str(),
        ])
    };
    let run = fail(&out);
    assert_eq!(
        run.code,
        Some(2),
        "a panel larger than the sheet: {}",
        run.stderr
    );
    // A 12 in cube covers 250 sheets of 60 mm: the size check warns before the error.
    let lines: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| !l.starts_with("unfold: warning: "))
        .collect();
    assert_eq!(lines.len(), 1, "one line of error: {:?}", run.stderr);
    let line = lines[0];
    assert!(line.starts_with("unfold: error: "), "{line}");
    // "panel F<k> is W x H mm": a face panel, at least the 304.8 mm face.
    let at = line
        .find("panel F")
        .unwrap_or_else(|| panic!("names the panel: {line}"));
    let rest = &line[at + "panel F".len()..];
    let face: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    assert!(face.parse::<usize>().is_ok_and(|f| f < 6), "{line}");
    let size: Vec<f64> = rest[face.len()..]
        .trim_start_matches(" is ")
        .split(" mm")
        .next()
        .unwrap()
        .split(" x ")
        .map(|w| w.trim().parse().unwrap_or(f64::NAN))
        .collect();
    assert_eq!(size.len(), 2, "gives the panel's size in mm: {line}");
    for side in &size {
        assert!(
            (304.8 - 0.1..=304.8 + 2.0 * 8.0 + 0.1).contains(side),
            "a 304.8 mm face with 8 mm tabs measures {side} mm? {line}"
        );
    }

    assert_eq!(
        folder_files(&out),
        before,
        "the failed job changed the output folder"
    );
    let siblings = entry_names(tmp.path());
    assert_eq!(
        siblings,
        BTreeSet::from(["hexa".to_string()]),
        "left next to OUT"
    );

    let fresh = tmp.path().join("fresh");
    let run = fail(&fresh);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        !fresh.exists(),
        "a failed job into a new folder leaves no folder"
    );
    assert_eq!(
        entry_names(tmp.path()),
        BTreeSet::from(["hexa".to_string()])
    );
}

// =======================================================================================
// 8. --json and --quiet
// =======================================================================================

/// The manifest names the files each format wrote, sheet by sheet, and nothing else:
/// `--format dxf` writes no SVG and its manifest names none.
#[test]
fn the_manifest_names_the_files_of_each_format() {
    let tmp = TempDir::new().unwrap();
    for (format, extensions) in [
        ("svg", &["svg"][..]),
        ("dxf", &["dxf"][..]),
        ("svg,dxf", &["svg", "dxf"][..]),
        ("dxf,svg", &["svg", "dxf"][..]),
    ] {
        let out = tmp.path().join(format.replace(',', "-"));
        // genus2 at 300 mm lays out on two sheets.
        let m = build(&model("genus2"), "300mm", &out, &["--format", format]);
        let sheets = m["sheets"].as_array().unwrap();
        assert!(sheets.len() >= 2, "{format}: several sheets");
        let mut wanted: Vec<String> = Vec::new();
        for (k, sheet) in sheets.iter().enumerate() {
            let files: Vec<&str> = sheet["files"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_str().unwrap())
                .collect();
            let expected: Vec<String> = extensions
                .iter()
                .map(|ext| format!("genus2-{:02}.{ext}", k + 1))
                .collect();
            assert_eq!(files, expected, "--format {format}: sheet {}", k + 1);
            wanted.extend(expected);
        }
        wanted.push("genus2-assembled.obj".into());
        wanted.push("genus2-map.svg".into());
        wanted.push("genus2.html".into());
        wanted.push("manifest.json".into());
        let listed = common::build::listed_files(&m);
        assert_eq!(listed, wanted, "--format {format}: the manifest's files");
        assert_eq!(
            entry_names(&out),
            wanted.iter().cloned().collect::<BTreeSet<String>>(),
            "--format {format}: the folder"
        );
    }
}

#[test]
fn json_summary_on_stdout() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let args = |out: &Path, extra: &[&str]| {
        let mut cmd = unfold_command();
        cmd.arg(&path)
            .args(["--scheme", "half-edge", "--size", "300mm", "--out"])
            .arg(out)
            .args(extra);
        finish(&mut cmd)
    };

    let plain = args(&tmp.path().join("plain"), &[]);
    assert_eq!(plain.code, Some(0), "{}", plain.stderr);
    assert!(
        plain.stdout.is_empty(),
        "without --json stdout is empty: {}",
        plain.stdout
    );
    assert!(
        plain.stderr.contains("panels"),
        "the report goes to stderr: {}",
        plain.stderr
    );

    let out = tmp.path().join("json");
    let run = args(&out, &["--json"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(!run.stderr.is_empty(), "the report still goes to stderr");
    let summary: Value = serde_json::from_str(&run.stdout)
        .unwrap_or_else(|e| panic!("--json prints JSON ({e}):\n{}", run.stdout));
    assert!(count(&summary, "counts.panels") == 50);
    assert!(count(&summary, "counts.sheets") >= 1);
    assert!(count(&summary, "counts.sheets_lower_bound") >= 1);
    let u = num(&summary, "utilization");
    assert!(u > 0.0 && u <= 1.0, "utilization {u}");
    let times = summary["times"].as_object().expect("a times object");
    assert!(!times.is_empty());
    for (stage, t) in times {
        assert!(t.as_f64().is_some_and(|t| t >= 0.0), "time {stage} = {t}");
    }
    assert!(
        summary.get("panels").is_none(),
        "no per-panel list in the summary"
    );
    // The summary is the manifest without its panel list, plus the times.
    let mut manifest = read_manifest(&out);
    manifest.as_object_mut().unwrap().remove("panels");
    let mut without_times = summary.clone();
    without_times.as_object_mut().unwrap().remove("times");
    assert_eq!(
        without_times, manifest,
        "--json summary = manifest.json − panels"
    );

    let quiet = args(&tmp.path().join("quiet"), &["--json", "--quiet"]);
    assert_eq!(quiet.code, Some(0));
    assert_eq!(quiet.stderr, "", "--quiet prints nothing on stderr");
    let again: Value =
        serde_json::from_str(&quiet.stdout).expect("--quiet --json still prints JSON");
    assert_eq!(again["counts"], summary["counts"]);

    let silent = args(&tmp.path().join("silent"), &["--quiet"]);
    assert_eq!(silent.code, Some(0));
    assert_eq!((silent.stdout.as_str(), silent.stderr.as_str()), ("", ""));
}

// =======================================================================================
// 9. Labels
// =======================================================================================

#[test]
fn labels_are_inside_their_panels() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus2");
    let out = tmp.path().join("out");
    let m = build(&path, "300mm", &out, &["--format", "svg"]);
    assert_eq!(
        count(&m, "counts.labels_left_out"),
        0,
        "genus2 at 300 mm has room for every label"
    );
    assert!(num(&m, "lengths.engrave") > 0.0);
    let sheets = check_sheets(&out, &m, DxfCheck::All);
    for (file, stats) in sheets.svg_files.iter().zip(&sheets.stats) {
        assert!(stats.engrave_paths > 0, "{file}: empty ENGRAVE group");
    }

    // Library level: every panel carries its own id and, with tabs, the partner's id at
    // each connection: 50 panel ids + 2 × 100 partner ids, none left out.
    let job = half_edge_job(&path, "300mm", 0, &out);
    let (mesh, connections, panels, mut flat) = panels_of(&job);
    assert_eq!(connections, 100);
    let mut left_out = 0;
    for ((fp, panel), frames) in flat.iter_mut().zip(&panels).zip(frames_of(&panels)) {
        left_out +=
            unfold::labels::fit_labels(fp, panel.view(), &frames, Default::default()).total();
    }
    assert_eq!(left_out, 0);
    let mut partner_labels = 0;
    for fp in &flat {
        let own: Vec<String> = fp
            .labels
            .iter()
            .filter(|l| l.kind == LabelKind::Panel)
            .map(|l| l.text.to_string())
            .collect();
        assert_eq!(own, [fp.id().to_string()], "{}: its own id once", fp.id());
        let Covers::Face(f) = fp.source.covers else {
            panic!("{}: not a face panel", fp.id())
        };
        // Partner labels name the neighbours across the face's edges.
        let neighbours: BTreeSet<String> = mesh
            .face_half_edges(unfold::mesh::FaceId(f))
            .filter_map(|h| mesh.face(h.twin()))
            .map(|g| format!("F{}", g.0))
            .collect();
        for l in fp.labels.iter().filter(|l| l.kind == LabelKind::Partner) {
            assert!(
                neighbours.contains(&l.text.to_string()),
                "{}: partner label {} is not a neighbour",
                fp.id(),
                l.text
            );
            partner_labels += 1;
        }
        // Every label's centre is inside the outline.
        for l in &fp.labels {
            assert!(
                inside(&fp.outer(), l.center),
                "{}: label {} outside",
                fp.id(),
                l.text
            );
        }
    }
    assert_eq!(partner_labels, 2 * connections);
    assert_eq!(flat.len(), 50);
}
