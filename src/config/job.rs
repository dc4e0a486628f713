//! A resolved build job ([`Job`]): the main command's options checked in turn, units
//! converted to millimetres and defaults filled in, the scheme chosen and configured.

use std::path::{Path, PathBuf};

use super::defaults;
use super::model::ModelSettings;
use super::options::BuildOptions;
use super::sheet::{parse_sheet, SheetSize};
use super::values::{LabelSide, NonPlanar};
use crate::error::{Error, Result};
use crate::export::laser::Speeds;
use crate::export::{Format, SheetStyle};
use crate::nest::true_shape::NestOptions;
use crate::nest::NestSettings;
use crate::scheme::{ConfiguredScheme, PanelLimit, PanelOptions, Registry, Scheme};
use crate::units::{fraction, parse_length, positive_length};

/// A fully resolved build job: every length in millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    /// The model file.
    pub model_path: PathBuf,
    /// Model options.
    pub model: ModelSettings,
    /// Panel scheme, with its options resolved (lengths in mm).
    pub scheme: ConfiguredScheme,
    /// Sheet size.
    pub sheet: SheetSize,
    /// Sheet margin, mm.
    pub margin: f64,
    /// Part spacing, mm (between the kerf-compensated outlines).
    pub spacing: f64,
    /// Laser kerf, mm: cut loops move half of it outward.
    pub kerf: f64,
    /// Output folder.
    pub out: PathBuf,
    /// Write into an output folder holding other files, keeping them.
    pub force: bool,
    /// Write the assembly map beside the sheets.
    pub map: bool,
    /// Write the preview page beside the sheets.
    pub preview: bool,
    /// Refuse instead of warning about the build's size.
    pub strict: bool,
    /// Build a model too detailed for its size instead of stopping.
    pub build_anyway: bool,
    /// Print the summary as JSON on stdout.
    pub json: bool,
    /// Print nothing on stderr but errors.
    pub quiet: bool,
    /// Sheet file formats, in the order their files are written.
    pub formats: Vec<Format>,
    /// Non-planar face policy.
    pub nonplanar: NonPlanar,
    /// Layout settings.
    pub nest: NestSettings,
    /// How the sheets are drawn: layers, and the face labels read on.
    pub style: SheetStyle,
    /// Laser speeds for the time estimate.
    pub speeds: Speeds,
}

impl BuildOptions {
    /// Checks every value, converts units and fills in defaults, with the built-in
    /// schemes.
    pub fn resolve(&self, model_path: &Path) -> Result<Job> {
        self.resolve_with(model_path, &Registry::default())
    }

    /// [`BuildOptions::resolve`] choosing the scheme from `registry`. Each part checks
    /// its options in turn, so the first mistake reported is the first in this order.
    pub fn resolve_with(&self, model_path: &Path, registry: &Registry) -> Result<Job> {
        let sheet = self.sheet_settings()?;
        let formats = Format::parse_list(self.format.as_deref().unwrap_or(defaults::FORMAT))
            .map_err(|e| usage("format", e))?;
        let scheme = self.chosen_scheme(registry)?;
        let (face_scale, holes) = self.connections(scheme)?;
        let nest = self.nest_settings()?;
        let cuts = self.hole_and_kerf()?;
        let panel = PanelOptions {
            face_scale,
            holes,
            hole_diameter: cuts.hole_diameter,
            hole_margin: cuts.hole_margin,
            label_height: length_option(
                "label-height",
                &self.label_height,
                defaults::LABEL_HEIGHT,
            )?,
            panel_limit: Some(sheet.panel_limit(nest.search.rotations, cuts.kerf)),
            scale: self
                .model
                .scale
                .filter(|s| s.is_finite() && *s > 0.0)
                .unwrap_or(defaults::SCALE),
        };
        let options = scheme
            .configure(&self.scheme_values, panel)
            .map_err(Error::Usage)?;
        Ok(Job {
            nonplanar: self.nonplanar.unwrap_or(defaults::NONPLANAR),
            nest,
            style: self.sheet_style()?,
            speeds: match &self.speeds {
                Some(text) => Speeds::parse(text).map_err(Error::Usage)?,
                None => Speeds::default(),
            },
            model_path: model_path.to_path_buf(),
            model: ModelSettings {
                keep_unsimplified: options.bounds_distance(),
                ..self.model.resolve()?
            },
            scheme: ConfiguredScheme {
                scheme,
                options: options.into(),
            },
            sheet: sheet.sheet,
            margin: sheet.margin,
            spacing: sheet.spacing,
            kerf: cuts.kerf,
            out: self.out_folder(model_path),
            force: self.force,
            map: !self.no_map,
            preview: !self.no_preview,
            strict: self.strict,
            build_anyway: self.build_anyway,
            json: self.json,
            quiet: self.quiet,
            formats,
        })
    }

    /// The sheet, its margin and the spacing between parts, checked together (the
    /// margins must leave room on the sheet).
    fn sheet_settings(&self) -> Result<SheetSettings> {
        let margin_text = self.margin.as_deref().unwrap_or(defaults::MARGIN);
        let sheet = parse_sheet(self.sheet.as_deref().unwrap_or(defaults::SHEET))
            .map_err(|e| usage("sheet", e))?;
        let margin = parse_length(margin_text).map_err(|e| usage("margin", e))?;
        let spacing = parse_length(self.spacing.as_deref().unwrap_or(defaults::SPACING))
            .map_err(|e| usage("spacing", e))?;
        if margin < 0.0 || spacing < 0.0 {
            return Err(Error::Usage(
                "--margin and --spacing cannot be negative".to_string(),
            ));
        }
        if 2.0 * margin >= sheet.width.min(sheet.height) {
            return Err(Error::Usage(format!(
                "--margin {} leaves no room on a {} sheet ({:.1} x {:.1} mm)",
                margin_text, sheet.name, sheet.width, sheet.height
            )));
        }
        Ok(SheetSettings {
            sheet,
            margin,
            spacing,
        })
    }

    /// `--out`, or a folder named after the model in the working folder.
    fn out_folder(&self, model_path: &Path) -> PathBuf {
        match &self.out {
            Some(dir) => dir.clone(),
            None => PathBuf::from(
                model_path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "unfold-out".to_string()),
            ),
        }
    }

    /// The scheme `--scheme` names (or the registry's default), refusing an option of
    /// another scheme given on the command line.
    fn chosen_scheme(&self, registry: &Registry) -> Result<&'static dyn Scheme> {
        let scheme = match self.scheme.as_deref() {
            None => registry.default_scheme(),
            Some(name) => registry.get(name).ok_or_else(|| {
                usage(
                    "scheme",
                    format!(
                        "unknown scheme '{name}'; use one of {}",
                        registry.names().join(", ")
                    ),
                )
            })?,
        };
        // An option of another scheme on the command line is a mistake worth naming
        // (a config file may serve several schemes, so its keys are not checked).
        let own: Vec<clap::Arg> = scheme.options();
        if let Some(name) = self
            .scheme_values
            .asked()
            .find(|name| !own.iter().any(|a| a.get_long() == Some(*name)))
        {
            let takers: Vec<&str> = registry
                .schemes()
                .iter()
                .filter(|s| s.options().iter().any(|a| a.get_long() == Some(name)))
                .map(|s| s.name())
                .collect();
            return Err(usage(
                name,
                format!(
                    "the {} scheme does not take this option; it is an option of {}, chosen with --scheme",
                    scheme.name(),
                    takers.join(", ")
                ),
            ));
        }
        Ok(scheme)
    }

    /// `--face-scale` and `--holes`, whose defaults and allowed values are `scheme`'s.
    fn connections(&self, scheme: &dyn Scheme) -> Result<(f64, u32)> {
        let scheme_defaults = scheme.info().defaults;
        let face_scale = fraction("face-scale", self.face_scale, scheme_defaults.face_scale)
            .map_err(Error::Usage)?;
        let holes = self.holes.unwrap_or(scheme_defaults.holes);
        if !scheme_defaults.holes_allowed.contains(&holes) {
            return Err(usage(
                "holes",
                format!(
                    "{holes} holes per connection; the {} scheme takes {:?}",
                    scheme.name(),
                    scheme_defaults.holes_allowed
                ),
            ));
        }
        Ok((face_scale, holes))
    }

    /// The nester and its search: `--nester`, `--rotations`, `--mirror`, `--effort`,
    /// `--seed` and `--time-limit`.
    fn nest_settings(&self) -> Result<NestSettings> {
        let rotations = self.rotations.unwrap_or(defaults::ROTATIONS);
        if !(1..=3600).contains(&rotations) {
            return Err(usage(
                "rotations",
                format!("{rotations} must be between 1 and 3600"),
            ));
        }
        let effort = self.effort.unwrap_or(defaults::EFFORT);
        if !(1..=100).contains(&effort) {
            return Err(usage(
                "effort",
                format!("{effort} must be between 1 and 100"),
            ));
        }
        // Duration::from_secs_f64 panics on values it cannot hold (1e300): convert
        // with the fallible form and refuse those like zero or negative ones.
        let time_limit = self
            .time_limit
            .map(|t| {
                std::time::Duration::try_from_secs_f64(t)
                    .ok()
                    .filter(|d| !d.is_zero())
                    .ok_or_else(|| {
                        usage(
                            "time-limit",
                            format!("{t:?} must be a positive number of seconds, below 1e18"),
                        )
                    })
            })
            .transpose()?;
        Ok(NestSettings {
            nester: self.nester.unwrap_or(defaults::NESTER),
            search: NestOptions {
                rotations,
                mirror: self.mirror,
                effort,
                seed: self.seed.unwrap_or(defaults::SEED),
                time_limit,
            },
        })
    }

    /// `--hole-diameter`, `--kerf` (which must leave the holes open) and
    /// `--hole-margin` (half the diameter unless given).
    fn hole_and_kerf(&self) -> Result<HoleAndKerf> {
        let hole_diameter = length_option(
            "hole-diameter",
            &self.hole_diameter,
            defaults::HOLE_DIAMETER,
        )?;
        let kerf_text = self.kerf.as_deref().unwrap_or(defaults::KERF);
        let kerf = parse_length(kerf_text).map_err(|e| usage("kerf", e))?;
        if kerf < 0.0 || kerf >= hole_diameter {
            return Err(usage(
                "kerf",
                format!(
                    "'{kerf_text}' must be at least 0 and below the {hole_diameter:.3} mm --hole-diameter, which it shrinks by its width"
                ),
            ));
        }
        let hole_margin = match &self.hole_margin {
            Some(text) => {
                let mm = parse_length(text).map_err(|e| usage("hole-margin", e))?;
                if mm < 0.0 {
                    return Err(usage("hole-margin", format!("'{text}' cannot be negative")));
                }
                mm
            }
            None => 0.5 * hole_diameter,
        };
        Ok(HoleAndKerf {
            hole_diameter,
            hole_margin,
            kerf,
        })
    }

    /// How the sheets are drawn: `--stroke-width`, the config file's layers and
    /// `--labels`.
    fn sheet_style(&self) -> Result<SheetStyle> {
        let stroke_width =
            length_option("stroke-width", &self.stroke_width, defaults::STROKE_WIDTH)?;
        Ok(SheetStyle {
            layers: self.layers.resolve(stroke_width)?,
            labels_inside: self.labels.unwrap_or(defaults::LABELS) == LabelSide::Inside,
        })
    }
}

/// A usage error of `--option`.
fn usage(option: &str, why: String) -> Error {
    Error::Usage(format!("--{option}: {why}"))
}

/// A positive length option: `value` or else `default`, in mm.
fn length_option(option: &str, value: &Option<String>, default: &str) -> Result<f64> {
    positive_length(option, value.as_deref(), default).map_err(Error::Usage)
}

/// The sheet and the room kept on it, resolved (mm).
struct SheetSettings {
    /// The sheet.
    sheet: SheetSize,
    /// Empty border on every sheet edge.
    margin: f64,
    /// Smallest gap between parts.
    spacing: f64,
}

impl SheetSettings {
    /// The largest panel the sheet takes inside its margins, in `rotations` steps,
    /// before the kerf compensation grows it by half the `kerf` on every side.
    fn panel_limit(&self, rotations: u32, kerf: f64) -> PanelLimit {
        PanelLimit {
            width: self.sheet.width - 2.0 * self.margin - kerf,
            height: self.sheet.height - 2.0 * self.margin - kerf,
            rotations,
        }
    }
}

/// The fastener hole sizes and the kerf that shrinks them, resolved (mm).
struct HoleAndKerf {
    /// Hole diameter.
    hole_diameter: f64,
    /// Material between a hole's rim and any cut edge.
    hole_margin: f64,
    /// Laser kerf.
    kerf: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn command_line_wins_over_config() {
        let cli = BuildOptions {
            sheet: Some("A2".into()),
            ..Default::default()
        };
        let text = "sheet = \"18x24in\"\nscheme = \"woven\"\nsize = \"4ft\"\n";
        let file = BuildOptions {
            model: toml::from_str(text).unwrap(),
            ..toml::from_str(text).unwrap()
        };
        let job = cli.or(file).resolve(Path::new("bunny.obj")).unwrap();
        assert_eq!(job.sheet.name, "A2");
        assert_eq!(job.scheme.name(), "woven");
        assert!(close(job.model.scaling.size.unwrap(), 1219.2));
        assert_eq!(job.out, PathBuf::from("bunny"));
    }
}
