//! Tests of the independent sheet checker (`tests/common/mod.rs`) on hand-written SVG and
//! DXF files: a valid sheet passes with hand-computed stats, and every kind of defect is
//! rejected with a message that names it.
//!
//! The DXF tests read every file with the Rust reader of `tests/common/dxf_read.rs` and,
//! when python3 has ezdxf (`pip install ezdxf`; required with `UNFOLD_REQUIRE_EZDXF=1`),
//! with `tests/check_dxf.py` as well: every defect must be caught by each.

use crate::common;

use std::f64::consts::PI;
use std::time::Instant;

use common::dxf_read::{ezdxf_wanted, read_dxf, read_dxf_with_ezdxf, DEFAULT_LAYERS};
use common::{
    check_dxf_matches_svg, check_dxf_matches_svg_read_by, check_svg_sheet, svg_circles,
    svg_geometry, DxfReader, SheetSpec,
};

const SPEC: SheetSpec = SheetSpec {
    width: 100.0,
    height: 80.0,
    margin: 5.0,
    spacing: 3.0,
};

const RED: &str = "#FF0000";
const BLUE: &str = "#0000FF";
const BLACK: &str = "#000000";

fn path(d: &str, colour: &str) -> String {
    format!(r#"<path d="{d}" fill="none" stroke="{colour}" stroke-width="0.0254"/>"#)
}

fn circle(cx: &str, cy: &str, r: &str, colour: &str) -> String {
    format!(
        r#"<circle cx="{cx}" cy="{cy}" r="{r}" fill="none" stroke="{colour}" stroke-width="0.0254"/>"#
    )
}

/// One sheet in the exporter's layout.
fn sheet(w: &str, h: &str, engrave: &[String], score: &[String], cut: &[String]) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str(&format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" version=\"1.1\" width=\"{w}mm\" height=\"{h}mm\" viewBox=\"0 0 {w} {h}\">\n"
    ));
    for (id, label, items) in [
        ("engrave", "ENGRAVE", engrave),
        ("score", "SCORE", score),
        ("cut", "CUT", cut),
    ] {
        s.push_str(&format!(
            "<g id=\"{id}\" inkscape:groupmode=\"layer\" inkscape:label=\"{label}\">\n"
        ));
        for it in items {
            s.push_str(it);
            s.push('\n');
        }
        s.push_str("</g>\n");
    }
    s.push_str("</svg>\n");
    s
}

/// The valid sheet, as (engrave, score, cut) element lists.
///
/// Panel A: square 10..40 × 10..40 (area 900, perimeter 120) with a hole (r 2 at 20,20)
/// and an inner square cut 25..35 (area 100, perimeter 40), a score line (12,15)–(38,15)
/// (length 26). Panel B: triangle (50,10) (90,10) (50,40) (area 600, perimeter
/// 40 + 30 + 50 = 120) with an engraved polyline (55,15) (60,15) (60,20) (length 10).
/// A and B are 10 mm apart.
fn valid_parts() -> (Vec<String>, Vec<String>, Vec<String>) {
    (
        vec![path("M 55 15 L 60 15 L 60 20", BLACK)],
        vec![path("M 12 15 L 38 15", BLUE)],
        vec![
            circle("20", "20", "2", RED),
            path("M 25 25 L 35 25 L 35 35 L 25 35 Z", RED),
            path("M 10 10 L 40 10 L 40 40 L 10 40 Z", RED),
            path("M 50 10 L 90 10 L 50 40 Z", RED),
        ],
    )
}

fn valid_sheet() -> String {
    let (e, s, c) = valid_parts();
    sheet("100", "80", &e, &s, &c)
}

/// Sheet from the valid parts with CUT element `i` replaced.
fn with_cut(i: usize, item: String) -> String {
    let (e, s, mut c) = valid_parts();
    c[i] = item;
    sheet("100", "80", &e, &s, &c)
}

#[track_caller]
fn assert_rejected(svg: &str, spec: &SheetSpec, words: &[&str]) {
    match check_svg_sheet(svg, spec) {
        Ok(stats) => panic!("checker accepted a bad sheet ({stats:?}):\n{svg}"),
        Err(msg) => {
            eprintln!("rejected as expected: {msg}");
            let lower = msg.to_lowercase();
            for w in words {
                assert!(
                    lower.contains(&w.to_lowercase()),
                    "message should mention {w:?}, got: {msg}"
                );
            }
        }
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

// ---------------------------------------------------------------------------------------
// SVG: the valid sheet
// ---------------------------------------------------------------------------------------

#[test]
fn valid_sheet_passes_with_hand_computed_stats() {
    let stats = check_svg_sheet(&valid_sheet(), &SPEC).expect("valid sheet");
    assert_eq!(stats.panels, 2);
    assert_eq!(stats.holes, 1);
    assert_eq!(stats.cut_paths, 3);
    assert_eq!(stats.score_paths, 1);
    assert_eq!(stats.engrave_paths, 1);
    assert!(close(stats.panel_area, 900.0 - 100.0 + 600.0), "{stats:?}");
    assert!(
        close(stats.cut_length, 120.0 + 40.0 + 120.0 + 4.0 * PI),
        "{stats:?}"
    );
    assert!(close(stats.score_length, 26.0), "{stats:?}");
    assert!(close(stats.engrave_length, 10.0), "{stats:?}");
}

#[test]
fn geometry_accessors() {
    let g = svg_geometry(&valid_sheet());
    assert_eq!(g.len(), 5);
    assert_eq!(
        g[0],
        (
            "ENGRAVE".to_string(),
            false,
            vec![(55.0, 15.0), (60.0, 15.0), (60.0, 20.0)]
        )
    );
    assert_eq!(g[1].0, "SCORE");
    assert_eq!(
        g[3],
        (
            "CUT".to_string(),
            true,
            vec![(10.0, 10.0), (40.0, 10.0), (40.0, 40.0), (10.0, 40.0)]
        )
    );
    assert_eq!(
        svg_circles(&valid_sheet()),
        vec![("CUT".to_string(), 20.0, 20.0, 2.0)]
    );
}

#[test]
fn empty_and_absent_groups_are_fine() {
    let s = sheet("100", "80", &[], &[], &[]);
    let stats = check_svg_sheet(&s, &SPEC).expect("empty sheet");
    assert_eq!(stats.panels, 0);
    let only_cut = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100mm\" height=\"80mm\" viewBox=\"0 0 100 80\">\n<g id=\"cut\">\n<path d=\"M 10 10 L 40 10 L 40 40 Z\" fill=\"none\" stroke=\"#FF0000\" stroke-width=\"0.0254\"/>\n</g>\n</svg>\n";
    assert_eq!(
        check_svg_sheet(only_cut, &SPEC).expect("cut only").panels,
        1
    );
}

// ---------------------------------------------------------------------------------------
// SVG: each defect is rejected and named
// ---------------------------------------------------------------------------------------

#[test]
fn rejects_overlapping_panels() {
    let s = with_cut(3, path("M 35 20 L 70 20 L 35 45 Z", RED));
    assert_rejected(&s, &SPEC, &["overlapping panels"]);
}

#[test]
fn rejects_panels_closer_than_spacing() {
    // B moved to x = 42: 2 mm from A, spacing 3 mm
    let s = with_cut(3, path("M 42 10 L 82 10 L 42 40 Z", RED));
    assert_rejected(&s, &SPEC, &["closer than the spacing", "2.0000"]);
    // exactly at the spacing is fine
    let s = with_cut(3, path("M 43 10 L 83 10 L 43 40 Z", RED));
    check_svg_sheet(&s, &SPEC).expect("spacing exactly 3");
}

#[test]
fn rejects_point_outside_margin() {
    let s = with_cut(3, path("M 50 10 L 97 10 L 50 40 Z", RED));
    assert_rejected(&s, &SPEC, &["outside the margin", "(97.0000, 10.0000)"]);
    let s = with_cut(0, circle("11", "20", "2", RED)); // reaches x = 9 ... inside margin 5
    check_svg_sheet(&s, &SPEC).expect_err("circle crosses outline at x = 10");
    let (e, sc, _) = valid_parts();
    let c = vec![
        circle("6", "20", "2", RED),
        path("M 4 10 L 40 10 L 40 40 L 4 40 Z", RED),
    ];
    assert_rejected(&sheet("100", "80", &e, &sc, &c), &SPEC, &["margin"]);
}

#[test]
fn rejects_open_cut_path() {
    let s = with_cut(3, path("M 50 10 L 90 10 L 50 40", RED));
    assert_rejected(&s, &SPEC, &["open CUT path"]);
}

#[test]
fn rejects_self_intersecting_outline() {
    // bow tie
    let s = with_cut(3, path("M 50 10 L 90 40 L 90 10 L 50 40 Z", RED));
    assert_rejected(&s, &SPEC, &["not a simple polygon", "self-intersection"]);
    // a vertex touching a non-adjacent edge
    let s = with_cut(3, path("M 50 10 L 90 10 L 70 30 L 70 10 L 50 40 Z", RED));
    assert_rejected(&s, &SPEC, &["not a simple polygon"]);
    // folding back along itself
    let s = with_cut(3, path("M 50 10 L 90 10 L 70 10 L 50 40 Z", RED));
    assert_rejected(&s, &SPEC, &["not a simple polygon"]);
}

#[test]
fn rejects_score_line_outside_every_panel() {
    let (e, _, c) = valid_parts();
    let s = sheet("100", "80", &e, &[path("M 12 50 L 38 50", BLUE)], &c);
    assert_rejected(&s, &SPEC, &["SCORE path #1", "outside every panel"]);
    // a score line on the outline itself is "inside or on"
    let s = sheet("100", "80", &e, &[path("M 10 12 L 10 30", BLUE)], &c);
    check_svg_sheet(&s, &SPEC).expect("on the outline");
    // in a cut-out
    let s = sheet("100", "80", &e, &[path("M 27 30 L 33 30", BLUE)], &c);
    assert_rejected(&s, &SPEC, &["cut-out"]);
}

#[test]
fn rejects_hole_after_its_outline() {
    let (e, s, mut c) = valid_parts();
    let hole = c.remove(0);
    c.insert(2, hole);
    assert_rejected(
        &sheet("100", "80", &e, &s, &c),
        &SPEC,
        &["hole", "comes after the outline"],
    );
    let (e, s, mut c) = valid_parts();
    c.swap(1, 2); // inner cut after the outline
    assert_rejected(
        &sheet("100", "80", &e, &s, &c),
        &SPEC,
        &["inner cut", "comes after the outline"],
    );
}

#[test]
fn rejects_wrong_colour() {
    let s = with_cut(0, circle("20", "20", "2", "#ff0000"));
    assert_rejected(&s, &SPEC, &["wrong stroke colour"]);
    let (e, _, c) = valid_parts();
    let s = sheet("100", "80", &e, &[path("M 12 15 L 38 15", RED)], &c);
    assert_rejected(&s, &SPEC, &["wrong stroke colour", "SCORE"]);
}

#[test]
fn rejects_text_element() {
    let (_, s, c) = valid_parts();
    let e = vec![r#"<text x="55" y="15">B</text>"#.to_string()];
    assert_rejected(&sheet("100", "80", &e, &s, &c), &SPEC, &["<text>"]);
}

#[test]
fn rejects_negative_zero() {
    let s = valid_sheet().replace("M 12 15 L 38 15", "M 12 15 L 38 15 L -0 15");
    assert_rejected(&s, &SPEC, &["negative zero"]);
    let s = with_cut(0, circle("20", "-0.0", "2", RED));
    assert_rejected(&s, &SPEC, &["negative zero"]);
}

#[test]
fn rejects_exponent() {
    let s = with_cut(0, circle("2e1", "20", "2", RED));
    assert_rejected(&s, &SPEC, &["exponent"]);
    let s = valid_sheet().replace("M 12 15", "M 1.2E1 15");
    assert_rejected(&s, &SPEC, &["exponent"]);
}

#[test]
fn rejects_five_decimals() {
    let s = with_cut(0, circle("20.00001", "20", "2", RED));
    assert_rejected(&s, &SPEC, &["5 decimals"]);
    // four are fine, trailing zeros are not
    let s = with_cut(0, circle("20.0001", "20", "2", RED));
    check_svg_sheet(&s, &SPEC).expect("4 decimals");
    let s = with_cut(0, circle("20.50", "20", "2", RED));
    assert_rejected(&s, &SPEC, &["trailing zero"]);
}

#[test]
fn rejects_wrong_width_height() {
    let (e, s, c) = valid_parts();
    assert_rejected(&sheet("101", "80", &e, &s, &c), &SPEC, &["width"]);
    let bad = valid_sheet().replace("height=\"80mm\"", "height=\"80\"");
    assert_rejected(&bad, &SPEC, &["height", "mm"]);
    let bad = valid_sheet().replace("viewBox=\"0 0 100 80\"", "viewBox=\"0 0 100 81\"");
    assert_rejected(&bad, &SPEC, &["viewBox"]);
}

#[test]
fn rejects_other_syntax_problems() {
    let v = valid_sheet();
    let cases: Vec<(String, &str)> = vec![
        (
            v.replacen("<path d", "<path style=\"stroke:#000\" d", 1),
            "style=",
        ),
        (
            v.replacen("<path d", "<path transform=\"scale(2)\" d", 1),
            "transform=",
        ),
        (
            v.replacen("<path d", "<path stroke-dasharray=\"1 1\" d", 1),
            "stroke-dasharray",
        ),
        (
            v.replacen("<svg", "<style>path{}</style><svg", 1),
            "<style>",
        ),
        (
            v.replacen("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", "", 1),
            "XML declaration",
        ),
        (v.replace("</svg>", "</svg>\n<svg></svg>"), "exactly one"),
        (
            v.replacen("stroke-width=\"0.0254\"", "stroke-width=\"0.1\"", 1),
            "stroke-width",
        ),
        (v.replacen("fill=\"none\"", "fill=\"#FF0000\"", 1), "fill"),
        (
            v.replace("M 12 15 L 38 15", "M 12 15 l 26 0"),
            "path command \"l\"",
        ),
        (
            v.replace("M 12 15 L 38 15", "M 12 15 L 38 15 M 12 16 L 38 16"),
            "path command \"M\"",
        ),
        (v.replace("M 12 15 L 38 15", "M 12,15 L 38,15"), "commas"),
        (v.replace("<g id=\"score\"", "<g id=\"scor\""), "group id"),
        (
            // CUT group before ENGRAVE
            v.replace("</svg>", "<g id=\"engrave\"></g>\n</svg>"),
            "order",
        ),
        (
            v.replacen("<path d=\"M 12 15", "<rect x=\"1\"/><path d=\"M 12 15", 1),
            "<rect>",
        ),
    ];
    for (svg, word) in cases {
        assert_rejected(&svg, &SPEC, &[word]);
    }
}

#[test]
fn rejects_line_drawn_twice() {
    let (e, _, c) = valid_parts();
    let s = sheet(
        "100",
        "80",
        &e,
        &[path("M 12 15 L 38 15", BLUE), path("M 38 15 L 12 15", BLUE)],
        &c,
    );
    assert_rejected(&s, &SPEC, &["drawn twice"]);
    let (e, s, mut c) = valid_parts();
    c.insert(0, circle("20", "20", "2", RED));
    assert_rejected(&sheet("100", "80", &e, &s, &c), &SPEC, &["drawn twice"]);
}

#[test]
fn rejects_hole_outside_or_crossing_panel() {
    let s = with_cut(0, circle("45", "50", "2", RED));
    assert_rejected(&s, &SPEC, &["outside every panel"]);
    let s = with_cut(0, circle("39", "20", "2", RED));
    assert_rejected(&s, &SPEC, &["crosses"]);
}

// ---------------------------------------------------------------------------------------
// Speed: 300 panels of 20 vertices
// ---------------------------------------------------------------------------------------

/// Formats like the exporter: 4 decimals, trailing zeros trimmed, never -0.
fn num(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

#[test]
fn big_sheet_checks_quickly() {
    let (cols, rows, pitch, margin) = (20, 15, 25.0, 6.0);
    let spec = SheetSpec {
        width: 2.0 * margin + cols as f64 * pitch,
        height: 2.0 * margin + rows as f64 * pitch,
        margin,
        spacing: 3.175,
    };
    let (mut e, mut s, mut c) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..cols {
        for j in 0..rows {
            let cx = margin + pitch * (i as f64 + 0.5);
            let cy = margin + pitch * (j as f64 + 0.5);
            let pts: Vec<String> = (0..20)
                .map(|k| {
                    let a = 2.0 * PI * k as f64 / 20.0;
                    format!("{} {}", num(cx + 10.0 * a.cos()), num(cy + 10.0 * a.sin()))
                })
                .collect();
            c.push(circle(&num(cx), &num(cy), "1.5", RED));
            c.push(path(&format!("M {} Z", pts.join(" L ")), RED));
            s.push(path(
                &format!(
                    "M {} {} L {} {}",
                    num(cx - 8.0),
                    num(cy - 2.0),
                    num(cx + 8.0),
                    num(cy - 2.0)
                ),
                BLUE,
            ));
            e.push(path(
                &format!(
                    "M {} {} L {} {} L {} {}",
                    num(cx - 3.0),
                    num(cy + 4.0),
                    num(cx + 3.0),
                    num(cy + 4.0),
                    num(cx + 3.0),
                    num(cy + 6.0)
                ),
                BLACK,
            ));
        }
    }
    let svg = sheet(&num(spec.width), &num(spec.height), &e, &s, &c);
    let t = Instant::now();
    let stats = check_svg_sheet(&svg, &spec).expect("big sheet");
    eprintln!(
        "checked a sheet of {} panels ({} bytes) in {:.3} s",
        stats.panels,
        svg.len(),
        t.elapsed().as_secs_f64()
    );
    assert_eq!(stats.panels, 300);
    assert_eq!(stats.holes, 300);
    // regular 20-gon of circumradius 10: area 0.5·20·100·sin(2π/20)
    let area = 300.0 * 0.5 * 20.0 * 100.0 * (2.0 * PI / 20.0).sin();
    assert!((stats.panel_area - area).abs() < 300.0 * 0.01, "{stats:?}");
}

// ---------------------------------------------------------------------------------------
// DXF
// ---------------------------------------------------------------------------------------

/// The minimal R12 file used here: HEADER with $ACADVER only, TABLES with LTYPE
/// CONTINUOUS and the three layers, no BLOCKS, no handles.
fn dxf(entities: &str) -> String {
    let head = "0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n0\nENDSEC\n\
0\nSECTION\n2\nTABLES\n\
0\nTABLE\n2\nLTYPE\n70\n1\n\
0\nLTYPE\n2\nCONTINUOUS\n70\n0\n3\nSolid line\n72\n65\n73\n0\n40\n0.0\n\
0\nENDTAB\n\
0\nTABLE\n2\nLAYER\n70\n4\n\
0\nLAYER\n2\nCUT\n70\n0\n62\n1\n6\nCONTINUOUS\n\
0\nLAYER\n2\nSCORE\n70\n0\n62\n5\n6\nCONTINUOUS\n\
0\nLAYER\n2\nSCORE-VALLEY\n70\n0\n62\n3\n6\nCONTINUOUS\n\
0\nLAYER\n2\nENGRAVE\n70\n0\n62\n7\n6\nCONTINUOUS\n\
0\nENDTAB\n\
0\nENDSEC\n\
0\nSECTION\n2\nENTITIES\n";
    format!("{head}{entities}0\nENDSEC\n0\nEOF\n")
}

fn polyline(layer: &str, colour: u8, closed: bool, pts: &[(f64, f64)]) -> String {
    let mut s = format!(
        "0\nPOLYLINE\n8\n{layer}\n62\n{colour}\n66\n1\n10\n0.0\n20\n0.0\n30\n0.0\n70\n{}\n",
        u8::from(closed)
    );
    for (x, y) in pts {
        s.push_str(&format!(
            "0\nVERTEX\n8\n{layer}\n10\n{x}\n20\n{y}\n30\n0.0\n"
        ));
    }
    s.push_str(&format!("0\nSEQEND\n8\n{layer}\n"));
    s
}

fn dxf_circle(layer: &str, colour: u8, c: (f64, f64), r: f64) -> String {
    format!(
        "0\nCIRCLE\n8\n{layer}\n62\n{colour}\n10\n{}\n20\n{}\n30\n0.0\n40\n{r}\n",
        c.0, c.1
    )
}

/// Sheet 100 × 80: square (10..40)², hole r 2 at (20, 20), score (12,15)–(38,15), engrave
/// (12,30)–(20,30) (a LINE in the DXF); in the DXF y' = 80 − y.
fn round_trip_pair() -> (String, String) {
    let svg = sheet(
        "100",
        "80",
        &[path("M 12 30 L 20 30", BLACK)],
        &[path("M 12 15 L 38 15", BLUE)],
        &[
            circle("20", "20", "2", RED),
            path("M 10 10 L 40 10 L 40 40 L 10 40 Z", RED),
        ],
    );
    let ents = [
        polyline(
            "CUT",
            1,
            true,
            &[(10.0, 70.0), (40.0, 70.0), (40.0, 40.0), (10.0, 40.0)],
        ),
        dxf_circle("CUT", 1, (20.0, 60.0), 2.0),
        polyline("SCORE", 5, false, &[(12.0, 65.0), (38.0, 65.0)]),
        "0\nLINE\n8\nENGRAVE\n62\n7\n10\n12.0\n20\n50.0\n30\n0.0\n11\n20.0\n21\n50.0\n31\n0.0\n"
            .to_string(),
    ]
    .concat();
    (svg, dxf(&ents))
}

#[test]
fn dxf_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let (svg, text) = round_trip_pair();
    check_svg_sheet(&svg, &SPEC).expect("the SVG of the round trip is a valid sheet");
    let good = dir.path().join("sheet-01.dxf");
    std::fs::write(&good, &text).unwrap();
    let t = Instant::now();
    check_dxf_matches_svg(&good, &svg, 80.0).expect("matching DXF");
    eprintln!("DXF check took {:.3} s", t.elapsed().as_secs_f64());

    // The group codes as unfold writes them, right-aligned in three columns.
    let padded: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i % 2 == 0 {
                format!("{l:>3}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let padded_path = dir.path().join("padded.dxf");
    std::fs::write(&padded_path, &padded).unwrap();
    check_dxf_matches_svg(&padded_path, &svg, 80.0).expect("right-aligned group codes");

    let rust = read_dxf(&good, &DEFAULT_LAYERS).expect("the Rust reader reads the sheet");
    assert_eq!(rust.entities.len(), 4);
    let mut readers = vec![DxfReader::Rust];
    if ezdxf_wanted().expect("ezdxf when required") {
        // Both readers see the same entities.
        assert_eq!(
            rust.entities,
            read_dxf_with_ezdxf(&good).expect("ezdxf reads the sheet")
        );
        readers.push(DxfReader::Ezdxf);
    }

    for reader in readers {
        let check = |path: &std::path::Path, svg: &str, height: f64| {
            check_dxf_matches_svg_read_by(reader, path, svg, height)
        };
        check(&good, &svg, 80.0).unwrap_or_else(|e| panic!("{reader:?}: matching DXF: {e}"));
        // geometry differs
        let moved = svg.replace("M 12 15 L 38 15", "M 12 16 L 38 16");
        let err = check(&good, &moved, 80.0).expect_err("moved score line");
        assert!(err.contains("does not match"), "{reader:?}: {err}");
        assert!(
            err.contains("only in SVG: SCORE open polyline"),
            "{reader:?}: {err}"
        );
        assert!(
            err.contains("only in DXF: SCORE open polyline"),
            "{reader:?}: {err}"
        );
        // y not flipped
        let err = check(&good, &svg, 0.0).expect_err("wrong height");
        assert!(err.contains("does not match"), "{reader:?}: {err}");
        // a missing circle
        let no_hole = svg.replace(&circle("20", "20", "2", RED), "");
        let err = check(&good, &no_hole, 80.0).expect_err("extra circle");
        assert!(err.contains("only in DXF: CUT circle"), "{reader:?}: {err}");

        // files the DXF checker itself must reject
        let score_end = "10\n38\n20\n65\n30\n0.0\n";
        assert!(text.contains(score_end));
        let engrave_line = "0\nLINE\n8\nENGRAVE\n62\n7\n";
        assert!(text.contains(engrave_line));
        let bad_files = [
            (
                text.replace("0\nSEQEND\n8\nSCORE\n", ""),
                "not ended by SEQEND",
            ),
            (
                text.replace(
                    "0\nENDSEC\n0\nEOF",
                    "0\nTEXT\n8\nENGRAVE\n62\n7\n10\n1.0\n20\n1.0\n40\n2.0\n1\nA\n0\nENDSEC\n0\nEOF",
                ),
                "unexpected entity type TEXT",
            ),
            (text.replace("AC1009", "AC1015"), "AC1009"),
            (
                text.replace("2\nSCORE\n70\n0\n62\n5", "2\nSCORE\n70\n0\n62\n3"),
                "colour",
            ),
            (
                text.replace("2\nSCORE\n70\n0\n62\n5", "2\nSCORE\n70\n0\n62\n-5"),
                "layer SCORE has colour -5, expected 5",
            ),
            (text.replace("0\nEOF\n", ""), "EOF"),
            (
                text.replace(
                    "0\nENDSEC\n0\nSECTION\n2\nENTITIES\n",
                    "0\nSECTION\n2\nENTITIES\n",
                ),
                "ENDSEC",
            ),
            (
                text.replacen("62\n1\n66", "62\n3\n66", 1),
                "has colour 3, expected 1",
            ),
            (
                text.replace(engrave_line, "0\nLINE\n8\nENGRAVE\n"),
                "no colour of its own",
            ),
            (
                text.replace(engrave_line, "0\nLINE\n8\nMARK\n62\n7\n"),
                "not defined in the LAYER table",
            ),
            (
                text.replace(engrave_line, "0\nLINE\n8\nENGRAVE\n67\n1\n62\n7\n"),
                "paper space",
            ),
            (
                text.replace(score_end, &format!("{score_end}42\n0.5\n")),
                "bulge",
            ),
            (
                text.replacen("70\n0\n0\nVERTEX", "70\n16\n0\nVERTEX", 1),
                "polyface/mesh",
            ),
            (
                text.replace("2\nENGRAVE\n70\n0", "2\nENGRAVE\n100\nAcDbSymbolTableRecord\n70\n0"),
                "subclass marker",
            ),
            (text.replace("Solid line", "Solid l\u{e9}ne"), "non-ASCII"),
        ];
        for (i, (bad, word)) in bad_files.iter().enumerate() {
            assert_ne!(bad, &text, "{word}: the defect is in the file");
            let p = dir.path().join(format!("bad-{i}.dxf"));
            std::fs::write(&p, bad).unwrap();
            let err = check(&p, &svg, 80.0).expect_err(word);
            assert!(
                err.contains(word),
                "{reader:?}: expected {word:?} in: {err}"
            );
        }
    }
}
