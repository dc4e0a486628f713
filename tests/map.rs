//! The assembly map (`NAME-map.svg` and its close-up pages), read back as a builder
//! would use it: it names every panel, each id where its panel is seen — checked by casting a ray
//! into the model (the scheme's mesh, from the library's pipeline) at the id's place
//! on the page, through the view's own projection written on the view's group — and
//! `--no-map` turns it off.

use crate::common;

use std::collections::BTreeSet;
use std::path::Path;

use common::build::{build, count, listed_files, model, options, resolve, shared_models};
use common::map::{face_seen, map_pages, read_map, MapView};
use glam::DVec2;
use serde_json::Value;
use tempfile::TempDir;
use unfold::mesh::{EdgeId, FaceId, Mesh};

/// The faces a panel id stands for: a face panel's face, an edge panel's two faces.
fn faces_of(mesh: &Mesh, manifest: &Value, id: &str) -> BTreeSet<u32> {
    // A panel that covers a group of faces lists them in the manifest.
    let entry = manifest["panels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["id"] == id);
    if let Some(faces) = entry.and_then(|p| p["source"]["faces"].as_array()) {
        return faces.iter().map(|f| f.as_u64().unwrap() as u32).collect();
    }
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

/// Builds `model` with `args`, reads every page of its map, and checks that every
/// panel is named and that every id sits over a face of its own panel as seen: the
/// overview's six views, then the close-ups, each id inside its close-up's frame.
fn check_map(model: &Path, scheme: &str, size: &str, target_edges: Option<usize>, args: &[&str]) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let mut all = vec!["--nester", "shelf"];
    all.extend(args);
    let budget = target_edges.map(|t| t.to_string());
    if let Some(b) = &budget {
        all.extend(["--target-edges", b]);
    }
    let manifest = build(scheme, model, size, &out, &all);
    let stem = model.file_stem().unwrap().to_string_lossy();
    let files = listed_files(&manifest);
    assert!(
        files.contains(&format!("{stem}-map.svg").as_str()),
        "{files:?}"
    );
    let pages = map_pages(&out, &files);
    // The preview page shows every page of the map.
    let html = std::fs::read_to_string(out.join(format!("{stem}.html"))).unwrap();
    assert_eq!(html.matches("class=\"map\"").count(), pages.len());
    let views: Vec<MapView> = pages.iter().flat_map(|svg| read_map(svg)).collect();
    let names: Vec<&str> = views.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names[..6],
        ["front", "back", "left", "right", "top", "bottom"]
    );
    for (k, name) in names[6..].iter().enumerate() {
        assert_eq!(*name, format!("close-up {}", k + 1));
    }
    let frames: Vec<(DVec2, DVec2)> = pages.iter().flat_map(|svg| close_up_frames(svg)).collect();
    assert_eq!(frames.len(), views.len() - 6, "a frame for every close-up");

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
    // A scheme with a surface of its own (strips) is drawn, and its faces named, there.
    let built = common::build::pipeline(&resolve(o, model));
    let mesh = built.output.surface.unwrap_or(built.mesh);

    let mut named = BTreeSet::new();
    let mut checked = 0;
    for (k, view) in views.iter().enumerate() {
        for (id, at) in &view.ids {
            assert!(panel_ids.contains(id), "{}: {id} is no panel", view.name);
            let seen = face_seen(&mesh, view, *at);
            let own = faces_of(&mesh, &manifest, id);
            assert!(
                seen.is_some_and(|f| own.contains(&f)),
                "{} view: {id} at {at} is drawn over face {seen:?}, not its own {own:?}",
                view.name
            );
            if let Some((lo, hi)) = k.checked_sub(6).map(|c| frames[c]) {
                assert!(
                    at.cmpge(lo).all() && at.cmple(hi).all(),
                    "{}: {id} at {at} is outside its frame",
                    view.name
                );
            }
            named.insert(id.clone());
            checked += 1;
        }
    }
    eprintln!(
        "{stem} {scheme}: {} of {} panels named, {checked} ids checked, {} close-ups on {} pages",
        named.len(),
        panel_ids.len(),
        views.len() - 6,
        pages.len()
    );
    let unnamed: Vec<&String> = panel_ids.difference(&named).collect();
    assert!(
        unnamed.is_empty(),
        "{stem} {scheme}: not on the map: {unnamed:?}"
    );
}

/// The frame of each close-up on a page (its clip rectangle), in order.
fn close_up_frames(svg: &str) -> Vec<(DVec2, DVec2)> {
    svg.split("<clipPath id=\"clip-close-up-")
        .skip(1)
        .map(|chunk| {
            let rect = &chunk[chunk.find("<rect").unwrap()..chunk.find("/>").unwrap()];
            let n = |name: &str| -> f64 { common::map::attribute(rect, name).parse().unwrap() };
            let lo = DVec2::new(n("x"), n("y"));
            (lo, lo + DVec2::new(n("width"), n("height")))
        })
        .collect()
}

#[test]
fn the_map_of_genus3_names_its_faces_where_they_are_seen() {
    check_map(&model("genus3"), "half-edge", "300mm", None, &[]);
}

#[test]
fn a_sheet_forty_metres_across_gets_its_map() {
    // Its views get coarser raster cells rather than buffers of gigabytes (the build
    // had aborted on allocation).
    check_map(
        &model("genus3"),
        "half-edge",
        "300mm",
        None,
        &["--sheet", "40000x40000mm"],
    );
}

/// The README's bunny (quad-edge, 4 ft, 625 edges) with `args`, checked by `test`.
fn check_thesis_bunny(test: &str, args: &[&str]) {
    if let Some(shared) = shared_models(test) {
        let bunny = shared.join("stanford-bunny.obj");
        check_map(&bunny, "quad-edge", "4ft", Some(625), args);
    }
}

#[test]
fn the_map_of_the_thesis_bunny_names_its_edges_where_they_are_seen() {
    check_thesis_bunny(
        "the_map_of_the_thesis_bunny_names_its_edges_where_they_are_seen",
        &[],
    );
}

/// The first half of the shared models at a thesis-like budget, edge and face panels:
/// the overview names most panels and the close-ups the rest (the cube's faces are larger than any
/// listed sheet at 4 ft, so it goes on a 1.5 m sheet).
#[test]
fn every_panel_of_the_first_half_of_the_shared_models_is_on_the_map() {
    let test = "every_panel_of_the_first_half_of_the_shared_models_is_on_the_map";
    if let Some(models) = common::build::half_of_the_shared_models(test, false) {
        every_panel_is_on_the_map(&models);
    }
}

/// The same on the second half of the shared models.
#[test]
fn every_panel_of_the_second_half_of_the_shared_models_is_on_the_map() {
    let test = "every_panel_of_the_second_half_of_the_shared_models_is_on_the_map";
    if let Some(models) = common::build::half_of_the_shared_models(test, true) {
        every_panel_is_on_the_map(&models);
    }
}

/// Each of `models` in quad-edge and half-edge at 4 ft and 1,000 edges: every panel on
/// the map. Each model is simplified once, for both schemes and for both the build and
/// the mesh the ids are looked up on.
fn every_panel_is_on_the_map(models: &[std::path::PathBuf]) {
    assert!(models.len() >= 4, "{models:?}");
    let tmp = TempDir::new().unwrap();
    for model in models {
        let cube = model.file_stem().is_some_and(|s| s == "cube");
        let args: &[&str] = if cube {
            &["--sheet", "1500x1500mm"]
        } else {
            &[]
        };
        let simplified = common::build::simplified_obj(model, 1000, false, tmp.path());
        for scheme in ["quad-edge", "half-edge"] {
            check_map(&simplified, scheme, "4ft", None, args);
        }
    }
}

/// Strip pieces are drawn, and named, on the strips' own surface.
#[test]
fn strip_pieces_are_named_where_they_lie() {
    check_map(&model("torus-8x6"), "strip", "12in", None, &[]);
}

/// On A4 the overview of the thesis bunny has room for about two thirds of its ids;
/// close-up pages name the rest.
#[test]
fn on_a4_close_ups_name_what_the_overview_has_no_room_for() {
    check_thesis_bunny(
        "on_a4_close_ups_name_what_the_overview_has_no_room_for",
        &["--sheet", "A4"],
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
    let named: BTreeSet<String> = map_pages(&out, &listed_files(&manifest))
        .iter()
        .flat_map(|svg| read_map(svg))
        .flat_map(|v| v.ids.into_iter().map(|(id, _)| id))
        .collect();
    let panels = count(&manifest, "counts.panels");
    assert!(named.iter().all(|id| id.starts_with('C')), "{named:?}");
    assert_eq!(named.len(), panels);
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

/// A text of the map: its box on the page (mm) and its words.
#[derive(Debug)]
struct TextBox {
    lo: glam::DVec2,
    hi: glam::DVec2,
    text: String,
    /// A panel id written in a view (centred), not page furniture.
    id: bool,
}

/// Every `<text>` of the map with its box, measured with Arial's advance widths as the
/// map measures them: from the baseline up a cap height and down a descender.
fn text_boxes(svg: &str) -> Vec<TextBox> {
    use common::map::attribute;
    svg.split("<text")
        .skip(1)
        .map(|chunk| {
            let tag = &chunk[..chunk.find('>').unwrap()];
            let text = chunk[tag.len() + 1..chunk.find("</text>").unwrap()]
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&quot;", "\"")
                .replace("&amp;", "&");
            let x: f64 = attribute(tag, "x").parse().unwrap();
            let y: f64 = attribute(tag, "y").parse().unwrap();
            let size: f64 = attribute(tag, "font-size").parse().unwrap();
            let width = unfold::export::map::page::text_width(&text, size);
            let id = tag.contains("text-anchor=\"middle\"");
            // Ids are centred, their baseline 0.35 em below their point.
            let (left, baseline) = if id {
                (x - 0.5 * width, y + 0.35 * size)
            } else {
                (x, y)
            };
            TextBox {
                lo: glam::DVec2::new(left, baseline - 0.75 * size),
                hi: glam::DVec2::new(left + width, baseline + 0.2 * size),
                text,
                id,
            }
        })
        .collect()
}

fn overlap(a: (glam::DVec2, glam::DVec2), b: (glam::DVec2, glam::DVec2)) -> bool {
    a.0.x < b.1.x && b.0.x < a.1.x && a.0.y < b.1.y && b.0.y < a.1.y
}

/// CIELAB (D65) of an `#RRGGBB` colour.
fn lab(hex: &str) -> [f64; 3] {
    let channel = |i: usize| {
        let c = u8::from_str_radix(&hex[1 + 2 * i..3 + 2 * i], 16).unwrap() as f64 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let (r, g, b) = (channel(0), channel(1), channel(2));
    let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
    let f = |t: f64| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    [
        116.0 * f(y) - 16.0,
        500.0 * (f(x) - f(y)),
        200.0 * (f(y) - f(z)),
    ]
}

/// Least CIE76 colour difference between any two sheets' tints on the map: well
/// beyond the 2.3 at which two colours side by side are told apart at all.
const TINT_DIFFERENCE: f64 = 12.0;

/// Checks a map page of `width` x `height` mm for `sheets` sheets: every text inside
/// the page, no two text boxes overlapping, every view's drawing clear of the other
/// views and of the page's text, a swatch and its number for every sheet, and tints
/// that differ by at least [`TINT_DIFFERENCE`].
fn check_page(case: &str, svg: &str, width: f64, height: f64, sheets: usize) {
    let texts = text_boxes(svg);
    for t in &texts {
        assert!(
            t.lo.x >= 0.0 && t.lo.y >= 0.0 && t.hi.x <= width && t.hi.y <= height,
            "{case}: {:?} leaves the page",
            t
        );
    }
    for (i, a) in texts.iter().enumerate() {
        for b in &texts[i + 1..] {
            assert!(
                !overlap((a.lo, a.hi), (b.lo, b.hi)),
                "{case}: {:?} and {:?} overlap",
                a.text,
                b.text
            );
        }
    }
    // Each view's drawing (its patches' corners, or a close-up's frame, which clips
    // it), against the others and the page's text (its caption included).
    let frames = close_up_frames(svg);
    let frames_page = !frames.is_empty();
    let overview: Vec<(glam::DVec2, glam::DVec2)> = svg
        .split("<g id=\"view-")
        .skip(1)
        .map(|chunk| {
            let body = &chunk[..chunk.find("</g>").unwrap()];
            let mut lo = glam::DVec2::splat(f64::INFINITY);
            let mut hi = -lo;
            for path in body.split("<path d=\"").skip(1) {
                let d = &path[..path.find('"').unwrap()];
                let n: Vec<f64> = d
                    .split(|c: char| c == ' ' || c.is_ascii_alphabetic())
                    .filter(|s| !s.is_empty())
                    .map(|s| s.parse().unwrap())
                    .collect();
                for p in n.chunks(2) {
                    lo = lo.min(glam::DVec2::new(p[0], p[1]));
                    hi = hi.max(glam::DVec2::new(p[0], p[1]));
                }
            }
            (lo, hi)
        })
        .collect();
    let drawings = if frames.is_empty() {
        assert_eq!(overview.len(), 6, "{case}");
        overview
    } else {
        assert_eq!(frames.len(), overview.len(), "{case}: a frame per close-up");
        frames
    };
    for (i, &a) in drawings.iter().enumerate() {
        assert!(
            a.0.x >= 0.0 && a.0.y >= 0.0 && a.1.x <= width && a.1.y <= height,
            "{case}: view {i} leaves the page"
        );
        for &b in &drawings[i + 1..] {
            assert!(!overlap(a, b), "{case}: two views overlap");
        }
        for t in texts.iter().filter(|t| !t.id) {
            assert!(
                !overlap(a, (t.lo, t.hi)),
                "{case}: view {i} runs into {:?}",
                t.text
            );
        }
    }
    // The legend: every sheet's swatch and number.
    let legend = &svg[svg.find("<g id=\"legend\">").expect("a legend")..];
    let swatches: Vec<&str> = legend
        .split("<rect ")
        .skip(1)
        .map(|r| {
            let at = r.find("fill=\"").unwrap() + 6;
            &r[at..at + 7]
        })
        .collect();
    if !frames_page {
        assert_eq!(swatches.len(), sheets, "{case}: swatches");
    } else {
        assert!(
            swatches.is_empty(),
            "{case}: close-ups leave the tints to page 1"
        );
        return;
    }
    let numbers: Vec<String> = texts
        .iter()
        .filter(|t| t.text.chars().all(|c| c.is_ascii_digit()))
        .map(|t| t.text.clone())
        .collect();
    for sheet in 1..=sheets {
        assert!(
            numbers.contains(&sheet.to_string()),
            "{case}: sheet {sheet}"
        );
    }
    for (i, a) in swatches.iter().enumerate() {
        for b in &swatches[i + 1..] {
            let (p, q) = (lab(a), lab(b));
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            assert!(
                d >= TINT_DIFFERENCE,
                "{case}: tints {a} and {b} differ by {d:.1}"
            );
        }
    }
}

#[test]
fn the_map_fits_every_paper_for_any_number_of_sheets() {
    let tmp = TempDir::new().unwrap();
    let mut o = options("quad-edge", "300mm", 0, &tmp.path().join("out"));
    o.holes = None;
    let p = common::build::pipeline(&resolve(o, &model("torus-8x6")));
    let surface =
        unfold::panel::surface::panel_surface(&p.mesh, &p.output.panels, &p.output.face_groups);
    let parts = p.output.panels.len();
    for paper in ["A5", "A4", "A3", "letter", "18x24in"] {
        let size = unfold::config::parse_sheet(paper).unwrap();
        for sheets in [1, 3, 12, 40] {
            // The panels dealt out over the sheets: the map reads only their sheet.
            let layout = unfold::nest::Layout {
                sheet: unfold::nest::SheetSpec {
                    width: size.width,
                    height: size.height,
                    margin: 5.0,
                    spacing: 2.0,
                },
                sheets,
                placements: (0..parts)
                    .map(|part| unfold::nest::Placement {
                        part,
                        sheet: part % sheets,
                        rotation: 0.0,
                        translation: glam::DVec2::ZERO,
                        mirrored: false,
                    })
                    .collect(),
            };
            let pages = unfold::export::map::assembly_map(&unfold::export::map::MapInput {
                surface: &surface,
                panels: &p.output.panels,
                layout: &layout,
                name: "torus-8x6-as-downloaded-from-a-public-collection",
            });
            for (k, svg) in pages.iter().enumerate() {
                check_page(
                    &format!("{paper}, {sheets} sheets, page {}", k + 1),
                    svg,
                    size.width,
                    size.height,
                    sheets,
                );
            }
        }
    }
}

#[test]
fn map_pages_are_told_from_sheets_whatever_the_models_name() {
    use common::build::map_page_number;
    assert_eq!(map_page_number("x-map", "x-map-map.svg"), Some(1));
    assert_eq!(map_page_number("x-map", "x-map-01.svg"), None);
    assert_eq!(
        map_page_number("road-map-v2", "road-map-v2-map-3.svg"),
        Some(3)
    );
    assert_eq!(map_page_number("a", "a-map-+3.svg"), None);
    assert_eq!(map_page_number("a", "a-map-1.svg"), None);
    assert_eq!(map_page_number("a", "b-map.svg"), None);
}
