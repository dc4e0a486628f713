//! The true-shape nester (SPEC.md §4): exact clearances between random outlines
//! checked here with our own polygon distance, fewer sheets than the shelf baseline
//! where true shapes can interlock, sheets ordered fullest first, mirrored placements,
//! and byte-identical output for a seed whatever the thread count.

use crate::common;

use std::path::Path;

use glam::DVec2;
use serde_json::Value;
use tempfile::TempDir;

use common::build::{
    build, build_run, check_sheets, count, finish, folder_files, model, num, shared_models,
    unfold_command, DxfCheck,
};
use unfold::nest::true_shape::{true_shape_layout, NestOptions};
use unfold::nest::{Layout, SheetSpec};
use unfold::plane::{contains, segment_distance, signed_area};

const TOL: f64 = 1e-6;

fn options(seed: u64) -> NestOptions {
    NestOptions {
        rotations: 16,
        mirror: false,
        effort: 2,
        seed,
        time_limit: None,
    }
}

/// A deterministic mix of triangles, thin slivers, L shapes and rectangles (mm).
fn random_parts(n: usize, seed: u64) -> Vec<Vec<DVec2>> {
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|i| {
            let s = 10.0 + 60.0 * next();
            let t = 5.0 + 40.0 * next();
            match i % 4 {
                0 => vec![DVec2::ZERO, DVec2::new(s, 0.0), DVec2::new(s * next(), t)],
                1 => vec![
                    DVec2::ZERO,
                    DVec2::new(s, 0.0),
                    DVec2::new(s, 1.5),
                    DVec2::new(0.0, 1.0),
                ],
                2 => vec![
                    DVec2::ZERO,
                    DVec2::new(s, 0.0),
                    DVec2::new(s, 0.3 * t),
                    DVec2::new(0.3 * s, 0.3 * t),
                    DVec2::new(0.3 * s, t),
                    DVec2::new(0.0, t),
                ],
                _ => vec![
                    DVec2::ZERO,
                    DVec2::new(s, 0.0),
                    DVec2::new(s, t),
                    DVec2::new(0.0, t),
                ],
            }
        })
        .collect()
}

/// Every part inside the margin, every two parts on a sheet at least the spacing
/// apart (edge distance) and neither inside the other.
fn assert_valid(parts: &[Vec<DVec2>], layout: &Layout) {
    let spec = layout.sheet;
    let placed: Vec<Vec<DVec2>> = layout
        .placements
        .iter()
        .map(|p| parts[p.part].iter().map(|&q| p.apply(q)).collect())
        .collect();
    for (i, poly) in placed.iter().enumerate() {
        assert!(layout.placements[i].sheet < layout.sheets);
        for q in poly {
            assert!(
                q.x >= spec.margin - TOL
                    && q.y >= spec.margin - TOL
                    && q.x <= spec.width - spec.margin + TOL
                    && q.y <= spec.height - spec.margin + TOL,
                "part {i} leaves the usable area at {q}"
            );
        }
    }
    for a in 0..placed.len() {
        for b in a + 1..placed.len() {
            if layout.placements[a].sheet != layout.placements[b].sheet {
                continue;
            }
            let (pa, pb) = (&placed[a], &placed[b]);
            let mut d = f64::INFINITY;
            for i in 0..pa.len() {
                for j in 0..pb.len() {
                    d = d.min(segment_distance(
                        pa[i],
                        pa[(i + 1) % pa.len()],
                        pb[j],
                        pb[(j + 1) % pb.len()],
                    ));
                }
            }
            assert!(
                d >= spec.spacing - TOL,
                "parts {a} and {b} are {d} mm apart"
            );
            assert!(
                !contains(pa, pb[0]) && !contains(pb, pa[0]),
                "part {a} or {b} inside the other"
            );
        }
    }
}

#[test]
fn random_outlines_keep_the_spacing_and_the_margin() {
    let sheet = SheetSpec {
        width: 300.0,
        height: 200.0,
        margin: 5.0,
        spacing: 3.0,
    };
    for seed in [1, 2] {
        let parts = random_parts(60, seed);
        let layout = true_shape_layout(&parts, sheet, &options(seed)).unwrap();
        assert_valid(&parts, &layout);
        let area: f64 = parts.iter().map(|p| unfold::plane::area(p)).sum();
        let usable = sheet.usable_width() * sheet.usable_height();
        assert!(layout.sheets >= (area / usable).ceil() as usize);
        // Same seed, same layout.
        assert_eq!(
            layout,
            true_shape_layout(&parts, sheet, &options(seed)).unwrap()
        );
    }
}

#[test]
fn mirrored_placements_are_valid_and_used() {
    let sheet = SheetSpec {
        width: 200.0,
        height: 200.0,
        margin: 2.0,
        spacing: 1.0,
    };
    let parts = random_parts(40, 5);
    let layout = true_shape_layout(
        &parts,
        sheet,
        &NestOptions {
            mirror: true,
            ..options(5)
        },
    )
    .unwrap();
    assert_valid(&parts, &layout);
    assert!(layout.placements.iter().any(|p| p.mirrored));
    // A mirrored placement turns a counter-clockwise outline clockwise.
    let p = layout.placements.iter().find(|p| p.mirrored).unwrap();
    let turned: Vec<DVec2> = parts[p.part].iter().map(|&q| p.apply(q)).collect();
    assert!(signed_area(&parts[p.part]).signum() != signed_area(&turned).signum());
}

#[test]
fn a_part_larger_than_the_sheet_is_refused() {
    let sheet = SheetSpec {
        width: 100.0,
        height: 100.0,
        margin: 5.0,
        spacing: 2.0,
    };
    let parts = vec![
        vec![DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(0.0, 10.0)],
        vec![DVec2::ZERO, DVec2::new(120.0, 0.0), DVec2::new(0.0, 30.0)],
    ];
    let e = true_shape_layout(&parts, sheet, &options(0)).unwrap_err();
    assert_eq!(e.part, 1);
    // A 110 mm sliver is longer than the usable 90 mm side but fits turned 45°.
    let parts = vec![vec![
        DVec2::ZERO,
        DVec2::new(110.0, 0.0),
        DVec2::new(110.0, 2.0),
    ]];
    let layout = true_shape_layout(&parts, sheet, &options(0)).unwrap();
    assert_valid(&parts, &layout);
}

/// An 18 × 24 in sheet with the SPEC's margin and a 1 mm spacing: 444.5 × 596.9 mm
/// usable, so eleven rows of 50 mm parts.
const ROW_SHEET: SheetSpec = SheetSpec {
    width: 457.2,
    height: 609.6,
    margin: 6.35,
    spacing: 1.0,
};

/// `n` copies of a quadrilateral (mm).
fn copies(n: usize, corners: [(f64, f64); 4]) -> Vec<Vec<DVec2>> {
    let outline: Vec<DVec2> = corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
    vec![outline; n]
}

/// Parallelograms 100 mm long and 50 mm tall, slanted 30 mm: side by side they
/// interlock, four to a 444.5 mm row (4 × 101 + 30 = 434 mm), 44 to a sheet, so 88
/// fill two sheets, the area bound. Packed by their 130 mm bounding boxes, three
/// fit a row and 88 take three sheets. (The whole nester, whichever construction
/// wins; the rows alone are pinned by the unit tests in `true_shape/rows.rs`.)
#[test]
fn slanted_ends_interlock() {
    let parts = copies(88, [(0.0, 0.0), (100.0, 0.0), (130.0, 50.0), (30.0, 50.0)]);
    let layout = true_shape_layout(&parts, ROW_SHEET, &options(0)).unwrap();
    assert_valid(&parts, &layout);
    assert_eq!(layout.sheets, 2);
}

/// Isosceles trapezoids 100 mm at the base, 60 mm at the top, 50 mm tall: turned
/// half a turn every other one, each adds 81 mm to a row, five to a row (100 + 4 × 81
/// = 424 mm), 55 to a sheet, so 110 fill two sheets, the area bound. All one way up,
/// four fit a row and 110 take three sheets (first-fit alone did).
#[test]
fn trapezoids_alternate() {
    let parts = copies(110, [(0.0, 0.0), (100.0, 0.0), (80.0, 50.0), (20.0, 50.0)]);
    let layout = true_shape_layout(&parts, ROW_SHEET, &options(0)).unwrap();
    assert_valid(&parts, &layout);
    assert_eq!(layout.sheets, 2);
    let turned = layout
        .placements
        .iter()
        .filter(|p| p.apply_direction(DVec2::X).x < 0.0)
        .count();
    assert!(turned >= 40, "{turned} of 110 turned half a turn");
}

#[test]
fn true_shapes_need_fewer_sheets_than_shelves_on_small_models() {
    let tmp = TempDir::new().unwrap();
    let mut saved = false;
    for name in ["icosahedron", "concave"] {
        let shelf_out = tmp.path().join(format!("{name}-shelf"));
        let shelf = build(
            "half-edge",
            &model(name),
            "12in",
            &shelf_out,
            &["--nester", "shelf"],
        );
        let out = tmp.path().join(name);
        let (m, run) = build_run("half-edge", &model(name), "12in", &out, &[]);
        check_sheets(&out, &m, DxfCheck::All);
        check_sheets(&shelf_out, &shelf, DxfCheck::All);
        let (sheets, lower) = (
            count(&m, "counts.sheets"),
            count(&m, "counts.sheets_lower_bound"),
        );
        assert!(
            sheets < count(&shelf, "counts.sheets"),
            "{name}: {sheets} sheets"
        );
        assert!(sheets >= lower);
        assert_eq!(m["nesting"]["nester"], "true-shape");
        assert_eq!(
            count(&m, "nesting.shelf_sheets"),
            count(&shelf, "counts.sheets")
        );
        assert!(run.stderr.contains("each sheet filled"), "{}", run.stderr);
        // The search's sheets after each phase: the last is the layout's, and a
        // phase that saved sheets is in the report.
        assert!(shelf["nesting"].get("search_sheets").is_none());
        let phase = |p: &str| count(&m, &format!("nesting.search_sheets.{p}"));
        let (placed, moved, squeezed) = (phase("placed"), phase("moved"), phase("squeezed"));
        assert_eq!(squeezed, sheets, "{name}");
        assert!(
            placed >= moved && moved >= squeezed,
            "{name}: {placed} {moved} {squeezed}"
        );
        let said = run.stderr.contains("after moving parts");
        assert_eq!(said, squeezed < placed, "{name}: {}", run.stderr);
        let line = format!(
            "{placed} sheets placed, {moved} after moving parts, {squeezed} after squeezing;"
        );
        assert!(!said || run.stderr.contains(&line), "{}", run.stderr);
        saved |= squeezed < placed;
    }
    assert!(saved, "no model's search saved a sheet after placing");
}

#[test]
fn sheets_come_fullest_first_and_their_fills_add_up() {
    let tmp = TempDir::new().unwrap();
    for scheme in ["half-edge", "quad-edge", "winged-edge"] {
        let out = tmp.path().join(scheme);
        let m = build(scheme, &model("torus-8x6"), "12in", &out, &["--holes", "0"]);
        check_sheets(&out, &m, DxfCheck::All);
        let fills: Vec<f64> = m["sheets"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["fill"].as_f64().unwrap())
            .collect();
        assert_eq!(fills.len(), count(&m, "counts.sheets"));
        assert!(
            fills.windows(2).all(|w| w[0] >= w[1]),
            "{scheme}: {fills:?}"
        );
        let sheet_area = num(&m, "sheet.width") * num(&m, "sheet.height");
        let total: f64 = fills.iter().sum::<f64>() * sheet_area;
        let panel_area = num(&m, "panel_area");
        assert!(
            (total - panel_area).abs() < 1e-3 * panel_area,
            "{total} vs {panel_area}"
        );
    }
}

/// Builds `model` with `args` into `out` on `threads` threads, checks every sheet,
/// and returns the manifest.
fn build_on_threads(model: &Path, args: &[&str], out: &Path, threads: &str) -> Value {
    let mut cmd = unfold_command();
    cmd.arg(model)
        .args(args)
        .arg("--out")
        .arg(out)
        .env("RAYON_NUM_THREADS", threads);
    let run = finish(&mut cmd);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let m = common::build::read_manifest(out);
    check_sheets(out, &m, DxfCheck::FirstAndLast);
    m
}

#[test]
fn a_seed_gives_the_same_bytes_with_one_or_two_threads() {
    let tmp = TempDir::new().unwrap();
    let mut outputs = Vec::new();
    for (label, seed, threads) in [("a", "7", "1"), ("b", "7", "2"), ("c", "8", "2")] {
        let out = tmp.path().join(label);
        let args = [
            "--scheme",
            "quad-edge",
            "--size",
            "12in",
            "--seed",
            seed,
            "--effort",
            "2",
            "--format",
            "svg,dxf",
        ];
        let m = build_on_threads(&model("genus3"), &args, &out, threads);
        assert_eq!(count(&m, "nesting.seed"), seed.parse::<usize>().unwrap());
        outputs.push(folder_files(&out));
    }
    assert!(
        outputs[0] == outputs[1],
        "seed 7 differs between 1 and 2 threads"
    );
    assert!(
        outputs[0] != outputs[2],
        "seeds 7 and 8 gave the same layout"
    );
}

#[test]
fn mirror_from_the_command_line_records_mirrored_panels() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("m");
    let m = build(
        "quad-edge",
        &model("icosahedron"),
        "12in",
        &out,
        &["--mirror", "--holes", "2"],
    );
    check_sheets(&out, &m, DxfCheck::All);
    assert_eq!(m["nesting"]["mirror"], true);
    let mirrored = m["panels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["mirrored"] == true)
        .count();
    assert!(mirrored > 0);
}

#[test]
fn spot_at_four_feet_beats_the_shelf_baseline() {
    let Some(dir) = shared_models("spot_at_four_feet_beats_the_shelf_baseline") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("spot");
    let m = build(
        "half-edge",
        &dir.join("spot.obj"),
        "4ft",
        &out,
        &["--effort", "1"],
    );
    check_sheets(&out, &m, DxfCheck::FirstAndLast);
    let sheets = count(&m, "counts.sheets");
    let shelf = count(&m, "nesting.shelf_sheets");
    assert!(
        sheets + 2 <= shelf,
        "{sheets} sheets against the shelf's {shelf}"
    );
}

/// The decimated knight at 4 ft (half-edge): both constructions (rows and first-fit
/// decreasing), each improved, run side by side and the better is kept; 13 sheets
/// (the bound counting the spacing is 10), every sheet passes the independent check,
/// and the same bytes come out on one thread as on two.
#[test]
fn the_knight_gives_the_same_bytes_on_one_thread_and_two() {
    let Some(dir) = shared_models("the_knight_gives_the_same_bytes_on_one_thread_and_two") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out = tmp.path().join(threads);
        let args = ["--scheme", "half-edge", "--size", "4ft"];
        let m = build_on_threads(&dir.join("decimated-knight.off"), &args, &out, threads);
        let sheets = count(&m, "counts.sheets");
        assert!(sheets <= 13, "{sheets} sheets");
        outputs.push(folder_files(&out));
    }
    assert!(
        outputs[0] == outputs[1],
        "the knight differs between 1 and 2 threads"
    );
}

#[test]
fn one_sheet_is_one_sheet_in_the_report() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("tet");
    let run = common::build::unfold([
        model("tetrahedron").as_os_str(),
        "--size".as_ref(),
        "4in".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("laying bounding boxes in rows would take 1 sheet\n"),
        "{}",
        run.stderr
    );
}
