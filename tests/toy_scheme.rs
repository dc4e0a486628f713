//! A scheme added through the registry alone: the toy scheme below is this one file
//! and one registry line (`Registry::default().with(&TOY)`), with no change to any
//! source file of the tool. It has its own option, its own defaults and checks, and
//! its own manifest parameter; the command line (`unfold::cli::main`, the binary's own
//! entry point), the config file, the report and the sheets all take it as they take
//! the built-in schemes.
//!
//! The toy scheme: one panel per face, the face shrunk toward its centre by
//! `--toy-shrink` (its face band), with the face id engraved on it.

mod common;

use std::ffi::OsString;
use std::path::Path;
use std::process::ExitCode;

use tempfile::TempDir;

use common::build::{check_sheets, count, model, read_manifest, DxfCheck};
use unfold::mesh::{FaceId, Mesh};
use unfold::panel::{Label, LabelKind, Loops, Name, Panel, Panels, Source};
use unfold::record::Params;
use unfold::scheme::{
    face_band, Configured, OptionValues, PanelDefaults, PanelOptions, Registry, Scheme,
    SchemeError, SchemeOutput,
};

// =======================================================================================
// The toy scheme
// =======================================================================================

struct Toy;

static TOY: Toy = Toy;

#[derive(clap::Args)]
struct ToyArgs {
    /// How far each face shrinks toward its centre (toy): 1 keeps it whole.
    /// [default: 0.9]
    #[arg(long, value_name = "S")]
    toy_shrink: Option<f64>,
}

#[derive(Debug)]
struct ToyOptions {
    panel: PanelOptions,
    shrink: f64,
}

impl Scheme for Toy {
    fn name(&self) -> &'static str {
        "toy"
    }

    fn about(&self) -> &'static str {
        "one shrunk panel per face (a test of the registry)"
    }

    fn options(&self) -> Vec<clap::Arg> {
        unfold::scheme::args_of::<ToyArgs>()
    }

    fn defaults(&self) -> PanelDefaults {
        PanelDefaults {
            face_scale: 1.0,
            holes: 0,
            holes_allowed: &[0],
        }
    }

    fn needs_convex_faces(&self) -> bool {
        false
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --toy-shrink"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: ToyArgs = values.parse()?;
        let shrink = unfold::units::fraction("toy-shrink", args.toy_shrink, 0.9)?;
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
                text: Name::Face(f.0),
                anchor: centre,
                direction: (band[1] - band[0]).normalize(),
                height: self.panel.label_height,
                facet: 0,
                kind: LabelKind::Panel,
                on_edge: false,
                slide: 0.0,
            };
            Panel::new(Source::Face(f.0), band, facets, Vec::new(), vec![label])
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
// Tests
// =======================================================================================

/// `unfold ARGS…` through the binary's entry point with the toy scheme registered.
fn unfold_with_toy(args: &[&dyn AsRef<std::ffi::OsStr>]) -> ExitCode {
    let registry = Registry::default().with(&TOY);
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
    let scheme = command
        .get_arguments()
        .find(|a| a.get_long() == Some("scheme"))
        .unwrap();
    assert!(scheme
        .get_possible_values()
        .iter()
        .any(|v| v.get_name() == "toy"));
}
