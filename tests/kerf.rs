//! Kerf compensation, measured on the sheets: every closed cut loop moves half the kerf
//! into the waste (outlines out, inner cuts and holes in), the parts' own geometry keeps
//! at least that distance from every cut, score and engrave lines do not move, the
//! spacing holds between the offset outlines and the manifest records the kerf. The
//! nominal panels come from the library's own pipeline for the same job; the sheets are
//! read with the tests' independent checker.

use crate::common;

use std::path::Path;

use common::build::*;
use common::svg_circles;
use common::svg_geometry;
use glam::DVec2;
use serde_json::Value;
use tempfile::TempDir;
use unfold::panel::FlatPanel;
use unfold::plane::signed_area;

const KERF: f64 = 0.2;

/// What one sheet holds, in layout coordinates (y up, as placements map panels).
#[derive(Default)]
struct Sheet {
    cuts: Vec<Vec<DVec2>>,
    holes: Vec<(DVec2, f64)>,
    scores: Vec<[DVec2; 2]>,
}

fn read_sheet(path: &Path, height: f64) -> Sheet {
    let text = std::fs::read_to_string(path).unwrap();
    let at = |(x, y): (f64, f64)| DVec2::new(x, height - y);
    let mut sheet = Sheet::default();
    for (layer, closed, points) in svg_geometry(&text) {
        let points: Vec<DVec2> = points.into_iter().map(at).collect();
        match layer.as_str() {
            "CUT" => {
                assert!(closed, "{}: an open cut", path.display());
                sheet.cuts.push(points);
            }
            "SCORE" | "SCORE-VALLEY" => {
                assert_eq!(points.len(), 2, "{}: a score polyline", path.display());
                sheet.scores.push([points[0], points[1]]);
            }
            _ => {}
        }
    }
    for (layer, x, y, r) in svg_circles(&text) {
        assert_eq!(layer, "CUT");
        sheet.holes.push((at((x, y)), r));
    }
    sheet
}

/// A panel's point on its sheet, from the manifest's placement.
fn placed(entry: &Value) -> impl Fn(DVec2) -> DVec2 {
    let (x, y) = (num(entry, "x"), num(entry, "y"));
    let angle = num(entry, "rotation_deg").to_radians();
    let mirrored = entry["mirrored"].as_bool().unwrap();
    move |p: DVec2| {
        let p = if mirrored { DVec2::new(p.x, -p.y) } else { p };
        DVec2::from_angle(angle).rotate(p) + DVec2::new(x, y)
    }
}

fn perimeter(poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|i| poly[i].distance(poly[(i + 1) % poly.len()]))
        .sum()
}

/// How the loops of the kerf build relate to the nominal panels.
#[derive(Default, Debug)]
struct Measured {
    panels: usize,
    inner_cuts: usize,
    holes: usize,
    /// Length of the nominal cut loops, and of their places that are narrower than the
    /// kerf (the path there less than half the kerf from them).
    perimeter: f64,
    narrow_length: f64,
    /// Worst relative difference between a panel's growth in area and its perimeter ×
    /// K/2, over the panels with no narrow place and over the others (their narrow
    /// places' length taken off the perimeter).
    worst_growth: f64,
    worst_narrow_growth: f64,
}

/// What a loop's corners add to its material's growth beyond its perimeter × `h` when
/// it is offset by `h` into the waste (`outer`: outward): a mitred corner turning by φ
/// adds h² tan(φ/2), one sharper than 15° is bevelled and adds h² sin(φ)/2, a corner
/// turning the other way takes h² tan(|φ|/2) off.
fn corner_growth(lp: &[DVec2], outer: bool, h: f64) -> f64 {
    let n = lp.len();
    let part_side = signed_area(lp).signum() * if outer { 1.0 } else { -1.0 };
    (0..n)
        .map(|i| {
            let (a, v, b) = (lp[(i + n - 1) % n], lp[i], lp[(i + 1) % n]);
            let (u, w) = (v - a, b - v);
            let turn = part_side * u.perp_dot(w).atan2(u.dot(w));
            if turn < 0.0 {
                -h * h * (-0.5 * turn).tan()
            } else if std::f64::consts::PI - turn < std::f64::consts::PI / 12.0 {
                0.5 * h * h * turn.sin()
            } else {
                h * h * (0.5 * turn).tan()
            }
        })
        .sum()
}

/// The flat panels of a job without a kerf, from the pipeline's own stages.
fn nominal_panels(job: &unfold::Job) -> Vec<FlatPanel> {
    assert_eq!(job.kerf, 0.0);
    let loaded = unfold::run::load(job).expect("model loads");
    let prepared = unfold::run::prepare(job, loaded).expect("scheme mesh");
    let output = unfold::run::scheme(job, &prepared).expect("scheme");
    let flat = unfold::run::flatten(job, &prepared, &output).expect("flatten");
    flat.panels.iter().map(|p| p.to_flat_panel()).collect()
}

/// Builds `model` with `--kerf` and checks every panel against its nominal twin.
fn check_kerf(test: &str, scheme: &str, model: &Path, size: &str, holes: u32) -> Measured {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("kerf");
    let holes_arg = holes.to_string();
    let kerf_arg = format!("{KERF}mm");
    let (manifest, run) = build_run(
        scheme,
        model,
        size,
        &out,
        &[
            "--holes", &holes_arg, "--kerf", &kerf_arg, "--format", "svg,dxf",
        ],
    );
    assert_eq!(num(&manifest, "sheet.kerf"), KERF, "{test}: manifest kerf");
    assert!(
        run.stderr
            .contains("kerf 0.2 mm: every cut loop is offset 0.1 mm"),
        "{test}: the report names the kerf:\n{}",
        run.stderr
    );
    // The independent checker: closed cuts, inside the margin, the spacing held
    // between the outlines as cut (the offset ones), no overlaps; the DXF its twin.
    check_sheets(&out, &manifest, DxfCheck::FirstAndLast);

    let nominal = nominal_panels(&job(scheme, model, size, holes, &tmp.path().join("n")));
    let height = num(&manifest, "sheet.height");
    let sheets: Vec<Sheet> = manifest["sheets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| read_sheet(&out.join(s["files"][0].as_str().unwrap()), height))
        .collect();
    let entries = manifest["panels"].as_array().unwrap();
    assert_eq!(entries.len(), nominal.len(), "{test}: panel count");
    let half = KERF / 2.0;
    let mut m = Measured::default();
    let mut loops_used = vec![0usize; sheets.len()];
    for (entry, flat) in entries.iter().zip(&nominal) {
        let id = entry["id"].as_str().unwrap();
        assert_eq!(id, flat.id().to_string(), "{test}: panel order");
        let sheet = &sheets[count(entry, "sheet") - 1];
        let at = placed(entry);
        let loops: Vec<Vec<DVec2>> = flat
            .outline
            .iter()
            .map(|lp| lp.iter().map(|&i| at(flat.points[i as usize])).collect())
            .collect();
        let outer = &loops[0];
        // The cut outline: the one sheet loop around (most of) the nominal outline;
        // where cut edges run closer than the kerf the cut stays on them.
        let around: Vec<&Vec<DVec2>> = sheet
            .cuts
            .iter()
            .filter(|c| 2 * outer.iter().filter(|&&p| inside(c, p)).count() > outer.len())
            .collect();
        assert_eq!(around.len(), 1, "{test}: {id}: loops around its outline");
        let cut_outer = around[0];
        // Its inner cuts: every other loop inside it.
        let cut_inner: Vec<&Vec<DVec2>> = sheet
            .cuts
            .iter()
            .filter(|c| !std::ptr::eq(*c, cut_outer) && inside(cut_outer, c[0]))
            .collect();
        loops_used[count(entry, "sheet") - 1] += 1 + cut_inner.len();
        assert!(
            cut_inner.len() >= loops.len() - 1,
            "{test}: {id}: {} inner cuts on the sheet for {} nominal ones",
            cut_inner.len(),
            loops.len() - 1
        );

        // Every point of the part's edge is cut (the beam, half the kerf wide either
        // side of its path, reaches it), and away from narrow places the path keeps
        // half the kerf from the part.
        let cuts: Vec<&Vec<DVec2>> = std::iter::once(cut_outer)
            .chain(cut_inner.iter().copied())
            .collect();
        let to_cut = |p: DVec2| {
            cuts.iter()
                .map(|c| distance_to_border(c, p))
                .fold(f64::INFINITY, f64::min)
        };
        // A round beam leaves a fillet in the part's inside corners (and lets the
        // last tenths of a millimetre of a sharp notch tear): not checked near them.
        let inside_corners: Vec<DVec2> = loops
            .iter()
            .enumerate()
            .flat_map(|(k, lp)| {
                let part_side = signed_area(lp).signum() * if k == 0 { 1.0 } else { -1.0 };
                (0..lp.len()).filter_map(move |i| {
                    let (a, v, b) = (
                        lp[(i + lp.len() - 1) % lp.len()],
                        lp[i],
                        lp[(i + 1) % lp.len()],
                    );
                    ((v - a).perp_dot(b - v) * part_side < 0.0).then_some(v)
                })
            })
            .collect();
        let mut narrow = 0.0;
        for lp in &loops {
            for (i, &a) in lp.iter().enumerate() {
                let b = lp[(i + 1) % lp.len()];
                const SAMPLES: usize = 4;
                for k in 0..SAMPLES {
                    let p = a.lerp(b, k as f64 / SAMPLES as f64);
                    let d = to_cut(p);
                    let near_corner = inside_corners.iter().any(|c| c.distance(p) < 5.0 * KERF);
                    assert!(
                        d < half + 2e-3 || near_corner,
                        "{test}: {id}: the part's edge at {p} is {d:.4} mm from every cut: the beam does not reach it"
                    );
                    if d < half - 2e-3 {
                        narrow += a.distance(b) / SAMPLES as f64;
                    }
                }
            }
        }
        m.narrow_length += narrow;

        // Areas: the outline grows by its perimeter × K/2, and the material (outline
        // less inner cuts) by the perimeter of every loop × K/2, up to the corners and
        // but for the narrow places, which stay as they are.
        let area = |c: &[DVec2]| signed_area(c).abs();
        let perimeters = loops.iter().map(|c| perimeter(c)).sum::<f64>();
        m.perimeter += perimeters;
        let nominal_material = area(outer) - loops[1..].iter().map(|c| area(c)).sum::<f64>();
        let cut_material = area(cut_outer) - cut_inner.iter().map(|c| area(c)).sum::<f64>();
        let growth = cut_material - nominal_material;
        let corners: f64 = loops
            .iter()
            .enumerate()
            .map(|(k, lp)| corner_growth(lp, k == 0, half))
            .sum();
        let want = (perimeters - narrow) * half + if narrow == 0.0 { corners } else { 0.0 };
        let error = (growth - want).abs() / want;
        if narrow == 0.0 {
            m.worst_growth = m.worst_growth.max(error);
        } else {
            m.worst_narrow_growth = m.worst_narrow_growth.max(error);
        }

        // Holes: at their nominal centres, the diameter less the kerf.
        for hole in &flat.holes {
            let c = at(hole.center);
            let found = sheet
                .holes
                .iter()
                .find(|(p, _)| p.distance(c) < 2e-3)
                .unwrap_or_else(|| panic!("{test}: {id}: no hole at {c}"));
            assert!(
                (found.1 - (hole.diameter / 2.0 - half)).abs() < 1e-3,
                "{test}: {id}: a hole of radius {} for a nominal {}",
                found.1,
                hole.diameter / 2.0
            );
        }
        // Fold lines: where the nominal panel has them.
        for fold in &flat.folds {
            let [a, b] = fold.ends.map(|i| at(flat.points[i as usize]));
            assert!(
                sheet.scores.iter().any(|[p, q]| {
                    (p.distance(a) < 2e-3 && q.distance(b) < 2e-3)
                        || (p.distance(b) < 2e-3 && q.distance(a) < 2e-3)
                }),
                "{test}: {id}: no score line from {a} to {b}"
            );
        }
        m.panels += 1;
        m.inner_cuts += loops.len() - 1;
        m.holes += flat.holes.len();
    }
    // Nothing else is cut: every loop on a sheet belongs to a panel.
    for (s, sheet) in sheets.iter().enumerate() {
        assert_eq!(
            loops_used[s],
            sheet.cuts.len(),
            "{test}: sheet {} loops",
            s + 1
        );
    }
    m
}

/// The same job without a kerf: score and engrave lines are the same in all.
fn assert_same_marks(scheme: &str, model: &Path, size: &str, holes: u32) {
    let tmp = TempDir::new().unwrap();
    let holes_arg = holes.to_string();
    let stats = |kerf: &str| {
        let out = tmp.path().join(kerf);
        let (manifest, _) = build_run(
            scheme,
            model,
            size,
            &out,
            &["--holes", &holes_arg, "--kerf", kerf],
        );
        check_sheets(&out, &manifest, DxfCheck::Skip).total()
    };
    let (nominal, kerf) = (stats("0mm"), stats("0.2mm"));
    assert_eq!(kerf.score_paths, nominal.score_paths);
    assert_eq!(kerf.valley_paths, nominal.valley_paths);
    assert_eq!(kerf.engrave_paths, nominal.engrave_paths);
    assert_eq!(kerf.holes, nominal.holes);
    for (a, b) in [
        (kerf.score_length, nominal.score_length),
        (kerf.valley_length, nominal.valley_length),
        (kerf.engrave_length, nominal.engrave_length),
    ] {
        assert!((a - b).abs() < 1e-2 * (1.0 + b / 1000.0), "{a} vs {b}");
    }
}

#[test]
fn quad_edge_panels_grow_and_their_holes_shrink() {
    let dodecahedron = model("dodecahedron");
    let m = check_kerf("dodecahedron", "quad-edge", &dodecahedron, "1ft", 2);
    eprintln!("{m:?}");
    assert_eq!((m.panels, m.holes), (30, 240), "{m:?}");
    assert_eq!(m.narrow_length, 0.0, "{m:?}");
    assert!(m.worst_growth < 0.01, "{m:?}");
    assert_same_marks("quad-edge", &dodecahedron, "1ft", 2);
    assert_same_bytes_on_one_and_two_threads(
        &dodecahedron,
        &["--scheme", "quad-edge", "--size", "1ft", "--kerf", "0.2mm"],
    );
}

#[test]
fn a_kerf_the_holes_cannot_take_is_refused() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    for (kerf, says) in [
        ("4mm", "below the 3.175 mm --hole-diameter"),
        ("-0.1mm", "must be at least 0"),
        ("0.2", "no unit"),
    ] {
        let option = format!("--kerf={kerf}");
        let run = unfold([
            model("hexahedron").as_os_str(),
            "--size".as_ref(),
            "6in".as_ref(),
            option.as_ref(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        assert_refusal(&format!("--kerf {kerf}"), &run, 2, &["--kerf", says]);
        assert!(!out.exists(), "--kerf {kerf}: nothing written");
    }
}

#[test]
fn shared_models_grow_by_their_perimeter() {
    let Some(dir) = shared_models("shared_models_grow_by_their_perimeter") else {
        return;
    };
    // A shared model with holes: the libigl cube's 18 edges, quad-edge.
    let m = check_kerf("cube", "quad-edge", &dir.join("cube.obj"), "1ft", 2);
    eprintln!("{m:?}");
    assert_eq!((m.panels, m.narrow_length), (18, 0.0), "{m:?}");
    assert!(m.holes > 0 && m.worst_growth < 0.01, "{m:?}");
    let knight = dir.join("decimated-knight.off");
    let m = check_kerf("knight", "net", &knight, "2ft", 0);
    eprintln!("{m:?}");
    assert!(m.panels > 10, "{m:?}");
    assert!(m.narrow_length < 0.2 * m.perimeter, "{m:?}");
    assert!(m.worst_growth < 0.01, "{m:?}");
    assert!(m.worst_narrow_growth < 0.05, "{m:?}");
}

#[test]
fn islands_with_inner_cuts_keep_them() {
    let m = check_kerf("genus3", "net", &model("genus3"), "1ft", 0);
    eprintln!("{m:?}");
    assert!(m.inner_cuts > 0, "{m:?}");
    assert!(m.worst_growth < 0.01, "{m:?}");
    assert!(m.worst_narrow_growth < 0.05, "{m:?}");
}

#[test]
fn half_edge_panels_with_shortened_tabs_take_a_kerf() {
    let Some(dir) = shared_models("half_edge_panels_with_shortened_tabs_take_a_kerf") else {
        return;
    };
    // Tabs cut back where they would meet their panel leave short edges beside reflex
    // corners: grown for the spacing, such an outline folds back on itself unless the
    // nester repairs it.
    for (name, file) in [
        ("knight", "decimated-knight.off"),
        ("suzanne", "suzanne.obj"),
    ] {
        let m = check_kerf(name, "half-edge", &dir.join(file), "2ft", 0);
        eprintln!("{name}: {m:?}");
        assert!(m.panels > 400, "{name}: {m:?}");
        // Small triangles whose cut-back tabs leave edges shorter than a mitre beside
        // sharp corners: neighbouring mitres overlap, which the corner terms do not
        // count (up to 2 % of a 5 mm² growth here).
        assert!(m.worst_growth < 0.03, "{name}: {m:?}");
        assert!(m.worst_narrow_growth < 0.05, "{name}: {m:?}");
    }
}
