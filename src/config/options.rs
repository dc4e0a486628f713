//! The main command's options as given (command line or configuration file, every field
//! optional), the command they make with the registry's schemes and defaults, and how
//! two sets of them merge.

use std::path::PathBuf;

use serde::Deserialize;

use super::defaults;
use super::layers::LayerSettings;
use super::model::ModelOptions;
use super::values::{nesters, LabelSide, NonPlanar};
use crate::nest::NesterName;
use crate::scheme::{OptionValues, Registry};

/// Options of the main command (building sheets). Like [`ModelOptions`], all optional.
#[derive(Clone, Debug, Default, Deserialize, clap::Args)]
#[serde(rename_all = "kebab-case")]
pub struct BuildOptions {
    /// Panel scheme (the values and the default are the registry's; see
    /// [`crate::scheme::Registry`]).
    #[arg(long, value_name = "SCHEME")]
    pub scheme: Option<String>,

    /// Sheet size: WxH with a unit (18x24in, 600x400mm) or a name (A0..A5, letter,
    /// legal, tabloid).
    #[arg(long, value_name = "SIZE")]
    pub sheet: Option<String>,

    /// Empty border kept on every sheet edge, with a unit.
    #[arg(long, value_name = "LENGTH")]
    pub margin: Option<String>,

    /// Smallest gap between two parts on a sheet, with a unit.
    #[arg(long, value_name = "LENGTH")]
    pub spacing: Option<String>,

    /// Laser kerf, the width of material the beam burns away, with a unit: every closed
    /// cut loop moves half of it into the waste (outlines out, holes and inner cuts in)
    /// so parts come out at their nominal size; score and engrave lines stay. Below the
    /// hole diameter.
    #[arg(long, value_name = "LENGTH")]
    pub kerf: Option<String>,

    /// Output folder, created if missing and replaced whole (never half-written). A
    /// folder holding files unfold did not write is refused.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Write into an --out folder that holds other files: replace only unfold's own
    /// earlier output there and keep every other file.
    #[arg(long)]
    #[serde(default)]
    pub force: bool,

    /// Write no assembly map (NAME-map.svg: the model from six sides, each panel's id
    /// where it sits, tinted by its sheet; NAME-map-2.svg…: close-ups naming the rest).
    #[arg(long)]
    #[serde(default)]
    pub no_map: bool,

    /// Write no preview page (NAME.html: every sheet with visible strokes, the map and
    /// the report's figures, for a browser).
    #[arg(long)]
    #[serde(default)]
    pub no_preview: bool,

    /// The face the labels read on: outside, or inside (mirrored, for models assembled
    /// inside out or cut face down).
    #[arg(long, value_name = "SIDE")]
    pub labels: Option<LabelSide>,

    /// Laser speeds in mm/s for the time estimate: any of cut, score, engrave and
    /// travel (beam off).
    #[arg(long, value_name = "LIST")]
    pub speeds: Option<String>,

    /// Output formats, comma separated: svg, dxf.
    #[arg(long, value_name = "LIST")]
    pub format: Option<String>,

    /// Face band scale s: each panel corner moves toward the face centre,
    /// s·v + (1−s)·c.
    #[arg(long, value_name = "S")]
    pub face_scale: Option<f64>,

    /// Fastener holes per connection.
    #[arg(long, value_name = "N")]
    pub holes: Option<u32>,

    /// Fastener hole diameter, with a unit.
    #[arg(long, value_name = "LENGTH")]
    pub hole_diameter: Option<String>,

    /// Material kept between a fastener hole's rim and every cut edge of the panels it
    /// goes through, with a unit; half a hole diameter lets a fastener head of twice
    /// the hole's diameter bear on material all round.
    #[arg(long, value_name = "LENGTH")]
    pub hole_margin: Option<String>,

    /// Cap height of engraved labels, with a unit; shrunk to fit each panel, left out
    /// below 1.5 mm.
    #[arg(long, value_name = "LENGTH")]
    pub label_height: Option<String>,

    /// What to do with faces that are not planar within --planarity-tol: triangulate
    /// (split along the diagonal that folds least), planarize (move vertices until every
    /// face is planar, staying close to the input; the report gives the largest move) or
    /// error.
    #[arg(long, value_name = "POLICY")]
    pub nonplanar: Option<NonPlanar>,

    /// Rotation steps tried when laying panels on sheets (360°/N each).
    #[arg(long, value_name = "N")]
    pub rotations: Option<u32>,

    /// Layout of panels on sheets: true-shape (outlines, tabs and flaps included;
    /// small parts fill the gaps of large ones) or shelf (bounding boxes in rows, the
    /// baseline other unfolders use).
    #[arg(long, value_name = "NESTER", value_parser = nesters())]
    pub nester: Option<NesterName>,

    /// Search effort of the true-shape nester, 1 to 100: samples per placement and
    /// improvement rounds grow with it, and so does the time.
    #[arg(long, value_name = "N")]
    pub effort: Option<u32>,

    /// Seed of the true-shape search; the same seed and options give the same sheets.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,

    /// Also place panels mirrored (cut face down). Only for material without a
    /// printed or finished side.
    #[arg(long)]
    #[serde(default)]
    pub mirror: bool,

    /// Wall-clock cap on the nester's improvement and squeeze, in seconds. Off by
    /// default, since a time cap makes the result depend on the machine.
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,

    /// Stroke width in the SVG files, with a unit. Laser drivers treat only hairlines
    /// as vector lines; a wider stroke is for previews.
    #[arg(long, value_name = "LENGTH")]
    pub stroke_width: Option<String>,

    /// Refuse (exit 2) instead of warning when the model looks too small or too large
    /// for the sheet, or too detailed for its panels to carry labels and holes.
    #[arg(long)]
    #[serde(default)]
    pub strict: bool,

    /// Build a model too detailed for its size (most panels without room for their
    /// ids, or faces too small for any fastener hole) as it is, with a warning, instead
    /// of stopping before the long stages with a budget that builds it.
    #[arg(long)]
    #[serde(default)]
    pub build_anyway: bool,

    /// Print the manifest summary (without the per-panel list) and stage times as
    /// JSON on stdout.
    #[arg(long)]
    #[serde(default)]
    pub json: bool,

    /// Print nothing on stderr but errors.
    #[arg(long)]
    #[serde(default)]
    pub quiet: bool,

    /// The model options, read from the same table by [`load_config`](super::load_config).
    #[command(flatten)]
    #[serde(skip)]
    pub model: ModelOptions,

    /// The schemes' own options as given (their arguments come from the registry,
    /// not from this type; the command line and [`load_config`](super::load_config) fill them in).
    #[arg(skip)]
    #[serde(skip)]
    pub scheme_values: OptionValues,

    /// Layer names, colours and stroke widths per kind (config file only: the
    /// `[layers.cut]` tables).
    #[arg(skip)]
    #[serde(skip)]
    pub layers: LayerSettings,
}

impl BuildOptions {
    /// Completes a command holding these options with `registry`: the `--scheme`
    /// values, every option's default at the end of its help (its subcommands' too),
    /// and every scheme's own options.
    pub fn with_registry(command: clap::Command, registry: &Registry) -> clap::Command {
        let schemes: Vec<clap::builder::PossibleValue> = registry
            .schemes()
            .iter()
            .map(|s| clap::builder::PossibleValue::new(s.name()).help(s.info().about))
            .collect();
        let scheme_help = format!("Panel scheme: {}", registry.names().join(", "));
        let command = command.mut_arg("scheme", |a| {
            a.value_parser(clap::builder::PossibleValuesParser::new(schemes))
                .help(scheme_help)
        });
        defaults::state_defaults_in(command, &defaults::option_defaults(registry))
            .args(registry.options())
    }

    /// The main command's options alone, for the config file's keys.
    pub fn command(registry: &Registry) -> clap::Command {
        use clap::Args;
        Self::with_registry(Self::augment_args(clap::Command::new("unfold")), registry)
    }

    /// The schemes' own options given on a command line parsed by a command from
    /// [`BuildOptions::with_registry`].
    pub fn scheme_values(matches: &clap::ArgMatches, registry: &Registry) -> OptionValues {
        let mut values = OptionValues::default();
        for arg in registry.options() {
            let id = arg.get_id().as_str();
            let (Some(long), Some(clap::parser::ValueSource::CommandLine)) =
                (arg.get_long(), matches.value_source(id))
            else {
                continue;
            };
            if matches!(arg.get_action(), clap::ArgAction::SetTrue) {
                values.set(long, "true");
            } else if let Some(text) = matches.get_raw(id).and_then(|mut raw| raw.next_back()) {
                values.set(long, &text.to_string_lossy());
            }
        }
        values
    }

    /// Fills fields missing here from `other` (the configuration file).
    pub fn or(self, other: BuildOptions) -> BuildOptions {
        BuildOptions {
            scheme: self.scheme.or(other.scheme),
            sheet: self.sheet.or(other.sheet),
            margin: self.margin.or(other.margin),
            spacing: self.spacing.or(other.spacing),
            kerf: self.kerf.or(other.kerf),
            out: self.out.or(other.out),
            force: self.force || other.force,
            no_map: self.no_map || other.no_map,
            no_preview: self.no_preview || other.no_preview,
            format: self.format.or(other.format),
            face_scale: self.face_scale.or(other.face_scale),
            holes: self.holes.or(other.holes),
            hole_diameter: self.hole_diameter.or(other.hole_diameter),
            hole_margin: self.hole_margin.or(other.hole_margin),
            label_height: self.label_height.or(other.label_height),
            nonplanar: self.nonplanar.or(other.nonplanar),
            rotations: self.rotations.or(other.rotations),
            nester: self.nester.or(other.nester),
            effort: self.effort.or(other.effort),
            seed: self.seed.or(other.seed),
            mirror: self.mirror || other.mirror,
            time_limit: self.time_limit.or(other.time_limit),
            stroke_width: self.stroke_width.or(other.stroke_width),
            strict: self.strict || other.strict,
            build_anyway: self.build_anyway || other.build_anyway,
            json: self.json || other.json,
            quiet: self.quiet || other.quiet,
            model: self.model.or(other.model),
            scheme_values: self.scheme_values.or(other.scheme_values),
            labels: self.labels.or(other.labels),
            speeds: self.speeds.or(other.speeds),
            layers: self.layers.or(other.layers),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::defaults::{find_default, option_defaults};

    #[test]
    fn every_option_of_the_command_has_one_default() {
        let registry = Registry::default();
        let defaults = option_defaults(&registry);
        let command = BuildOptions::command(&registry);
        let scheme_own: Vec<String> = registry
            .options()
            .iter()
            .filter_map(|a| a.get_long().map(str::to_string))
            .collect();
        for arg in command.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if scheme_own.iter().any(|s| s == long) {
                continue;
            }
            assert!(
                find_default(&defaults, Some(long)).is_some(),
                "--{long} has no default"
            );
            let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
            assert_eq!(help.matches("[default: ").count(), 1, "--{long}: {help}");
        }
        for (i, d) in defaults.iter().enumerate() {
            assert!(
                !defaults[..i].iter().any(|e| e.long == d.long),
                "--{} twice",
                d.long
            );
        }
    }
}
