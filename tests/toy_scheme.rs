//! A scheme added through the registry alone: the toy scheme below is this one file
//! and one registry line (`Registry::default().with(&TOY)`), with no change to any
//! source file of the tool. It has its own option, its own defaults and checks, and
//! its own manifest parameter; the command line (`unfold::cli::main`, the binary's own
//! entry point), the config file, the report and the sheets all take it as they take
//! the built-in schemes.
//!
//! The toy scheme: one panel per face, the face shrunk toward its centre by
//! `--toy-shrink` (its face band), with the face id engraved on it.
//!
//! The pairs scheme makes its own kind of panel: two faces joined across an edge,
//! folding along it, named `P1`, `P2`… with its own letter, its own manifest entry
//! (`"pair"` and the faces) and section (`pairs`), its own words in the map legend and
//! its own anchor on the map (the middle of the fold), all from this file.

use crate::common;

use std::ffi::OsString;
use std::path::Path;
use std::process::ExitCode;

use tempfile::TempDir;

use common::build::{
    check_sheets, count, model, options, pipeline, read_manifest, resolve, DxfCheck,
};
use common::map::{face_seen, read_map};
use glam::DVec3;
use unfold::mesh::{FaceId, HalfedgeId, Mesh};
use unfold::panel::{
    Covers, FaceGroup, IdKind, Label, LabelKind, Loops, Name, Panel, Panels, Source,
};
use unfold::record::Params;
use unfold::scheme::{
    face_band, Configured, Configuring, OptionValues, PanelDefaults, PanelOptions, Registry,
    Scheme, SchemeError, SchemeInfo, SchemeOutput,
};

// =======================================================================================
// The toy scheme
// =======================================================================================

struct Toy;

/// `--toy-shrink`, written once: `configure` falls back on it and `--help` states it.
const TOY_SHRINK: f64 = 0.9;

static TOY: Toy = Toy;

#[derive(clap::Args)]
struct ToyArgs {
    /// How far each face shrinks toward its centre (toy): 1 keeps it whole.
    #[arg(long, value_name = "S")]
    toy_shrink: Option<f64>,
}

#[derive(Debug)]
struct ToyOptions {
    panel: PanelOptions,
    shrink: f64,
}

const TOY_INFO: SchemeInfo = SchemeInfo {
    name: "toy",
    about: "one shrunk panel per face (a test of the registry)",
    defaults: PanelDefaults {
        face_scale: 1.0,
        holes: 0,
        holes_allowed: &[0],
    },
    needs_convex_faces: false,
    overlap_fix: "a smaller --toy-shrink",
};

impl Scheme for Toy {
    fn info(&self) -> &SchemeInfo {
        &TOY_INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        unfold::option_default::state_defaults(
            unfold::scheme::args_of::<ToyArgs>(),
            &[unfold::option_default::OptionDefault::value(
                "toy-shrink",
                TOY_SHRINK,
            )],
        )
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        let args: ToyArgs = values.parse()?;
        let shrink = unfold::units::fraction("toy-shrink", args.toy_shrink, TOY_SHRINK)?;
        Ok(Box::new(ToyOptions { panel, shrink }))
    }
}

impl Configured for ToyOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        let panels = Panels::build(mesh.face_count(), |f| {
            let f = FaceId(f as u32);
            let band = face_band(mesh, f, self.shrink);
            let mut facets = Loops::new();
            facets.push(0..band.len() as u32);
            let centre = band.iter().copied().sum::<glam::DVec3>() / band.len() as f64;
            let label = Label {
                text: Name::face(f.0),
                anchor: centre,
                direction: (band[1] - band[0]).normalize(),
                height: self.panel.label_height,
                facet: 0,
                kind: LabelKind::Panel,
                on_edge: false,
                slide: 0.0,
            };
            Panel::new(Source::face(f.0), band, facets, Vec::new(), vec![label])
        });
        Ok(SchemeOutput {
            panels,
            ..SchemeOutput::default()
        })
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("toy_shrink", self.shrink);
        params
    }
}

// =======================================================================================
// The pairs scheme
// =======================================================================================

struct Pairs;

static PAIRS: Pairs = Pairs;

/// Pairs of faces: `P3`.
static PAIR: IdKind = IdKind {
    letter: "P",
    legend: "pair of faces (folds along its middle)",
    noun: "pair",
    part_noun: "",
    layer: "",
};

#[derive(Debug)]
struct PairOptions {
    panel: PanelOptions,
}

const PAIRS_INFO: SchemeInfo = SchemeInfo {
    name: "pairs",
    about: "faces joined in pairs across an edge (a test of a new kind of panel)",
    defaults: PanelDefaults {
        face_scale: 1.0,
        holes: 0,
        holes_allowed: &[0],
    },
    needs_convex_faces: false,
    overlap_fix: "a model with convex faces",
};

impl Scheme for Pairs {
    fn info(&self) -> &SchemeInfo {
        &PAIRS_INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        Vec::new()
    }

    fn configure(&self, _values: &OptionValues, panel: PanelOptions) -> Configuring {
        Ok(Box::new(PairOptions { panel }))
    }
}

/// The faces of `mesh` in pairs: each face, in order, with its first neighbour (in its
/// own edge order) not yet taken, across the half-edge they share; a face with none
/// stays alone.
fn pair_faces(mesh: &Mesh) -> Vec<(FaceId, Option<HalfedgeId>)> {
    let mut taken = vec![false; mesh.face_count()];
    let mut pairs = Vec::new();
    for f in mesh.faces() {
        if taken[f.index()] {
            continue;
        }
        taken[f.index()] = true;
        let across = mesh.face_half_edges(f).find(|&h| {
            mesh.face(mesh.twin(h))
                .is_some_and(|g| !std::mem::replace(&mut taken[g.index()], true))
        });
        pairs.push((f, across));
    }
    pairs
}

/// The panel of a pair: `f`'s corners, then the corners of the face across `h` but
/// the two on the fold, which the facets share.
fn pair_panel(mesh: &Mesh, number: u32, f: FaceId, h: Option<HalfedgeId>, height: f64) -> Panel {
    let mut corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
    let mut facets = Loops::new();
    facets.push(0..corners.len() as u32);
    if let Some(g) = h.and_then(|h| mesh.face(mesh.twin(h))) {
        let mut facet = Vec::new();
        for v in mesh.face_vertices(g) {
            let at = corners.iter().position(|&c| c == v.0).unwrap_or_else(|| {
                corners.push(v.0);
                corners.len() - 1
            });
            facet.push(at as u32);
        }
        facets.push(facet);
    }
    let vertices: Vec<DVec3> = corners
        .iter()
        .map(|&v| mesh.position(unfold::mesh::VertexId(v)))
        .collect();
    let label = Label {
        text: Name::new(&PAIR, number),
        anchor: mesh.face_centre(f),
        direction: (vertices[1] - vertices[0]).normalize(),
        height,
        facet: 0,
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.0,
    };
    let source = Source {
        id: Name::new(&PAIR, number),
        covers: Covers::Faces(number - 1),
    };
    Panel::new(source, vertices, facets, Vec::new(), vec![label])
}

impl Configured for PairOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        let pairs = pair_faces(mesh);
        let mut groups = Vec::new();
        let mut section = Vec::new();
        let mut panels = Vec::new();
        for (k, &(f, h)) in pairs.iter().enumerate() {
            let number = k as u32 + 1;
            let mut faces: Vec<u32> = [Some(f), h.and_then(|h| mesh.face(mesh.twin(h)))]
                .into_iter()
                .flatten()
                .map(|f| f.0)
                .collect();
            faces.sort_unstable();
            // Its id shows on the map at the middle of its fold (a lone face's centre).
            let anchor = h.map_or(mesh.face_centre(f), |h| {
                0.5 * (mesh.position(mesh.origin(h)) + mesh.position(mesh.dest(h)))
            });
            let mut record = Params::default();
            record.push("id", format!("P{number}"));
            record.push("faces", faces.clone());
            section.push(record);
            groups.push(FaceGroup { faces, anchor });
            panels.push(pair_panel(mesh, number, f, h, self.panel.label_height));
        }
        let mut manifest = Params::default();
        manifest.push_records("pairs", section);
        Ok(SchemeOutput {
            panels: panels.into_iter().collect(),
            connections: mesh.edge_count() - groups.iter().filter(|g| g.faces.len() == 2).count(),
            manifest,
            face_groups: groups,
            ..SchemeOutput::default()
        })
    }

    fn params(&self) -> Params {
        Params::default()
    }
}

// =======================================================================================
// Tests
// =======================================================================================

/// `unfold ARGS…` through the binary's entry point with the toy scheme registered.
fn unfold_with_toy(args: &[&dyn AsRef<std::ffi::OsStr>]) -> ExitCode {
    let registry = Registry::default().with(&TOY).with(&PAIRS);
    let argv: Vec<OsString> = std::iter::once(OsString::from("unfold"))
        .chain(args.iter().map(|a| a.as_ref().to_os_string()))
        .collect();
    unfold::cli::main(&registry, argv)
}

fn panel_area(out: &Path) -> f64 {
    read_manifest(out)["panel_area"].as_f64().unwrap()
}

#[test]
fn a_scheme_added_through_the_registry_builds_end_to_end() {
    let tmp = TempDir::new().unwrap();
    let model = model("icosahedron");
    let toy = tmp.path().join("toy");
    let code = unfold_with_toy(&[
        &model,
        &"--scheme",
        &"toy",
        &"--toy-shrink",
        &"0.5",
        &"--size",
        &"300mm",
        &"--format",
        &"svg,dxf",
        &"--out",
        &toy,
        &"--quiet",
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let m = read_manifest(&toy);
    assert_eq!(m["scheme"]["name"], "toy");
    assert_eq!(m["scheme"]["params"]["toy_shrink"], 0.5);
    // One panel per face of the icosahedron, every sheet valid.
    assert_eq!(count(&m, "counts.panels"), 20);
    assert_eq!(count(&m, "input.faces"), 20);
    let sheets = check_sheets(&toy, &m, DxfCheck::All);
    assert_eq!(sheets.svg_files.len(), count(&m, "counts.sheets"));
    assert_eq!(
        sheets.stats.iter().map(|s| s.panels).sum::<usize>(),
        20,
        "every panel on a sheet"
    );

    // Shrunk by 0.5, each panel has a quarter of its face's area: the half-edge
    // scheme without tabs lays out the faces themselves.
    let faces = tmp.path().join("faces");
    let code = unfold_with_toy(&[
        &model,
        &"--connectors",
        &"none",
        &"--size",
        &"300mm",
        &"--out",
        &faces,
        &"--quiet",
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let (shrunk, whole) = (panel_area(&toy), panel_area(&faces));
    assert!(
        (shrunk - 0.25 * whole).abs() < 1e-3 * whole,
        "toy area {shrunk} mm², a quarter of the faces' {whole} mm²"
    );
}

#[test]
fn the_toy_option_is_a_config_key_and_is_checked() {
    let tmp = TempDir::new().unwrap();
    let model = model("tetrahedron");
    let config = tmp.path().join("toy.toml");
    std::fs::write(
        &config,
        "scheme = \"toy\"\ntoy-shrink = 0.25\nsize = \"200mm\"\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let code = unfold_with_toy(&[&model, &"--config", &config, &"--out", &out, &"--quiet"]);
    assert_eq!(code, ExitCode::SUCCESS);
    assert_eq!(read_manifest(&out)["scheme"]["params"]["toy_shrink"], 0.25);

    // Its own check, and its option refused for a scheme that does not take it:
    // both usage errors, and nothing written.
    for (args, what) in [
        (
            &["--scheme", "toy", "--toy-shrink", "2"][..],
            "out of range",
        ),
        (
            &["--scheme", "quad-edge", "--toy-shrink", "0.5"][..],
            "another scheme's",
        ),
        (
            &["--scheme", "toy", "--holes", "2"][..],
            "holes it cannot place",
        ),
    ] {
        let refused = tmp.path().join("refused");
        let mut argv: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&model, &"--size", &"200mm"];
        argv.extend(args.iter().map(|a| a as &dyn AsRef<std::ffi::OsStr>));
        argv.extend([
            &"--out" as &dyn AsRef<std::ffi::OsStr>,
            &refused,
            &"--quiet",
        ]);
        assert_eq!(unfold_with_toy(&argv), ExitCode::from(2), "{what}");
        assert!(!refused.exists(), "{what}: nothing written");
    }

    // The scheme and its option are on the command line's own definition.
    let command = unfold::config::BuildOptions::command(&Registry::default().with(&TOY));
    let arg = command
        .get_arguments()
        .find(|a| a.get_long() == Some("toy-shrink"))
        .expect("--toy-shrink is an option");
    assert_eq!(
        arg.get_help_heading(),
        Some("Options of toy"),
        "under its scheme's heading"
    );
    let help = arg.get_help().unwrap().to_string();
    assert!(help.ends_with("[default: 0.9]"), "{help}");
    let scheme = command
        .get_arguments()
        .find(|a| a.get_long() == Some("scheme"))
        .unwrap();
    assert!(scheme
        .get_possible_values()
        .iter()
        .any(|v| v.get_name() == "toy"));
}

#[test]
fn a_scheme_with_its_own_kind_of_panel_is_named_in_the_manifest_and_on_the_map() {
    let tmp = TempDir::new().unwrap();
    let model = model("icosahedron");
    let out = tmp.path().join("pairs");
    let code = unfold_with_toy(&[
        &model,
        &"--scheme",
        &"pairs",
        &"--size",
        &"300mm",
        &"--out",
        &out,
        &"--quiet",
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let m = read_manifest(&out);

    // The 20 faces of the icosahedron, each in exactly one panel of its own kind:
    // a pair, or a face the greedy pairing left alone.
    let panels = m["panels"].as_array().unwrap();
    let mut covered = Vec::new();
    let mut pairs = 0;
    for (k, p) in panels.iter().enumerate() {
        let number = k as u64 + 1;
        assert_eq!(p["id"], format!("P{number}"));
        let source = &p["source"];
        assert_eq!(source["pair"], number, "{source}");
        let faces: Vec<u64> = source["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_u64().unwrap())
            .collect();
        assert!((1..=2).contains(&faces.len()), "{source}");
        pairs += usize::from(faces.len() == 2);
        // The icosahedron's faces are the input's: no split, no simplification.
        assert_eq!(source["input_faces"], source["faces"], "{source}");
        covered.extend(faces);
    }
    assert_eq!(panels.len(), 20 - pairs);
    assert!(pairs >= 8, "{pairs} pairs");
    covered.sort_unstable();
    assert_eq!(covered, (0..20).collect::<Vec<u64>>());
    // Its own manifest section, beside the shared ones.
    let section = m["pairs"].as_array().expect("a pairs section");
    assert_eq!(section.len(), panels.len());
    assert_eq!(section[3]["id"], "P4");
    assert_eq!(section[3]["faces"], panels[3]["source"]["faces"]);
    check_sheets(&out, &m, DxfCheck::All);

    // The map: the legend in the scheme's words, every id at its own place.
    let svg = std::fs::read_to_string(out.join("icosahedron-map.svg")).unwrap();
    assert!(
        svg.contains("Ids: P pair of faces (folds along its middle)."),
        "the legend names the pairs"
    );
    let mut o = options("half-edge", "300mm", 0, &out);
    o.holes = None;
    let mesh = pipeline(&resolve(o, &model)).mesh;
    // Two whole faces per panel, unrolled: the panels' area is the model's.
    let area: f64 = mesh.faces().map(|f| mesh.face_area(f)).sum();
    let panel_area = m["panel_area"].as_f64().unwrap();
    assert!(
        (panel_area - area).abs() < 1e-6 * area,
        "{panel_area} mm², {area} mm²"
    );
    let faces_of = |id: &str| -> Vec<u32> {
        let k: usize = id[1..].parse().unwrap();
        panels[k - 1]["source"]["faces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_u64().unwrap() as u32)
            .collect()
    };
    let (mut named, mut at_fold, mut shown) = (std::collections::BTreeSet::new(), 0, 0);
    for view in read_map(&svg) {
        for (id, at) in &view.ids {
            let own = faces_of(id);
            let seen = face_seen(&mesh, &view, *at);
            assert!(
                seen.is_some_and(|f| own.contains(&f)),
                "{}: {id} drawn over face {seen:?}, not its own {own:?}",
                view.name
            );
            // The anchor the scheme chose: the middle of the edge its faces share (a
            // lone face's centre).
            let fold = match own[..] {
                [f, g] => {
                    let h = mesh
                        .face_half_edges(FaceId(f))
                        .find(|&h| mesh.face(mesh.twin(h)) == Some(FaceId(g)))
                        .unwrap();
                    0.5 * (mesh.position(mesh.origin(h)) + mesh.position(mesh.dest(h)))
                }
                _ => mesh.face_centre(FaceId(own[0])),
            };
            if view.page_point(fold).distance(*at) < 1e-3 {
                at_fold += 1;
            }
            shown += 1;
            named.insert(id.clone());
        }
    }
    assert_eq!(named.len(), panels.len(), "every panel named on the map");
    // An id crowded at its anchor moves nearer the middle of its panel: most stay.
    assert!(
        2 * at_fold > shown,
        "{at_fold} of {shown} ids at their anchor"
    );
}
