//! Options in two stages (as ripgrep does): raw options as the user wrote them (command
//! line or TOML, every field optional), then a resolved [`Job`] with units converted to
//! millimetres, defaults filled in and every value checked. The command line wins over
//! the configuration file.

use crate::nest::true_shape::NestOptions;
use crate::nest::{NestSettings, NesterName};
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{Error, Result};
use crate::export::laser::Speeds;
use crate::export::{Format, Kind, Layers, SheetStyle};
use crate::scheme::{ConfiguredScheme, OptionValues, PanelLimit, PanelOptions, Registry, Scheme};

pub mod defaults;
mod file;
pub use file::load_config;

use crate::units::{fraction, parse_length_unbounded, positive_length, split_number};
pub use crate::units::{parse_length, LengthUnit, MAX_LENGTH_MM, MM_PER_INCH};

/// A sheet of material.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetSize {
    /// Width in mm.
    pub width: f64,
    /// Height in mm.
    pub height: f64,
    /// As the user wrote it ("18x24in", "A2").
    pub name: String,
}

/// Parses a sheet size: `WxH` with a unit (`18x24in`, `600x400mm`, `18in x 24in`), or
/// a name: `A0`..`A5` (portrait, ISO 216), `letter` (8.5×11 in), `legal` (8.5×14 in),
/// `tabloid` (11×17 in).
pub fn parse_sheet(text: &str) -> std::result::Result<SheetSize, String> {
    let named = match text.trim().to_ascii_lowercase().as_str() {
        "a0" => Some((841.0, 1189.0)),
        "a1" => Some((594.0, 841.0)),
        "a2" => Some((420.0, 594.0)),
        "a3" => Some((297.0, 420.0)),
        "a4" => Some((210.0, 297.0)),
        "a5" => Some((148.0, 210.0)),
        "letter" => Some((8.5 * MM_PER_INCH, 11.0 * MM_PER_INCH)),
        "legal" => Some((8.5 * MM_PER_INCH, 14.0 * MM_PER_INCH)),
        "tabloid" => Some((11.0 * MM_PER_INCH, 17.0 * MM_PER_INCH)),
        _ => None,
    };
    let (width, height) = match named {
        Some(size) => size,
        None => {
            let bad = || {
                format!(
                    "'{text}' is not a sheet size; write WxH with a unit (18x24in, 600x400mm) or a name (A0..A5, letter, legal, tabloid)"
                )
            };
            let lower = text.to_ascii_lowercase();
            let (w, h) = lower.split_once('x').ok_or_else(bad)?;
            let (h_number, h_unit) = split_number(h);
            if h_number.is_empty() {
                return Err(bad());
            }
            // "18x24in": the unit after the height serves both; "18in x 24in" also works.
            let (w_number, w_unit) = split_number(w);
            let w_text = if w_unit.trim().is_empty() {
                format!("{w_number}{h_unit}")
            } else {
                w.to_string()
            };
            let width = parse_length_unbounded(&w_text).map_err(|_| bad())?;
            let height = parse_length_unbounded(h).map_err(|_| bad())?;
            (width, height)
        }
    };
    if width <= 0.0 || height <= 0.0 {
        return Err(format!(
            "sheet '{text}' must have a positive width and height"
        ));
    }
    if width > MAX_LENGTH_MM || height > MAX_LENGTH_MM {
        return Err(format!(
            "sheet '{text}' is larger than 1 km, the longest length unfold takes"
        ));
    }
    Ok(SheetSize {
        width,
        height,
        name: text.trim().to_string(),
    })
}

/// `--simplify-mode`'s values (the mesh layer knows nothing of the command line).
fn simplify_modes(
) -> impl clap::builder::TypedValueParser<Value = crate::mesh::simplify::SimplifyMode> {
    use crate::mesh::simplify::SimplifyMode;
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new([
        PossibleValue::new("regular").help(
            "Even triangle sizes and shapes, at some cost in closeness to the original surface: every edge becomes a panel, so panels come out of one size, assemble alike and lose less to the spacing",
        ),
        PossibleValue::new("accurate").help(
            "The closest surface for the budget: flat regions keep few, large triangles and curved ones many small ones (panels from slivers to half a sheet long)",
        ),
    ])
    .map(|name| match name.as_str() {
        "accurate" => SimplifyMode::Accurate,
        _ => SimplifyMode::Regular,
    })
}

/// `--nester`'s values (the nest layer knows nothing of the command line).
fn nesters() -> impl clap::builder::TypedValueParser<Value = NesterName> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new([
        PossibleValue::new("true-shape")
            .help("True shapes: sampled bottom-left placement, then emptying the emptiest sheet"),
        PossibleValue::new("shelf").help("Bounding boxes in rows"),
    ])
    .map(|name| match name.as_str() {
        "shelf" => NesterName::Shelf,
        _ => NesterName::TrueShape,
    })
}

/// Options that describe the model and its physical size (shared by `inspect` and the
/// main command). Every field is optional so that the command line and the TOML file
/// can be merged; [`ModelOptions::resolve`] fills in the defaults.
#[derive(Clone, Debug, Default, Deserialize, clap::Args)]
#[serde(rename_all = "kebab-case")]
pub struct ModelOptions {
    /// Longest side of the model's bounding box when built, with a unit: 4ft, 1.2m,
    /// 48in, 600mm. Overrides --units.
    #[arg(long, value_name = "LENGTH")]
    pub size: Option<String>,

    /// What one model unit is, when --size is not given.
    #[arg(long, value_name = "UNIT")]
    pub units: Option<LengthUnit>,

    /// Extra factor applied after --size or --units.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub scale: Option<f64>,

    /// Merge vertices that share a position where the mesh stays manifold (OBJ and OFF
    /// keep them apart by default; STL is always welded).
    #[arg(long)]
    #[serde(default)]
    pub weld: bool,

    /// Faces whose planarity error (largest corner distance from the best-fit plane,
    /// divided by the face's diameter) exceeds this are non-planar.
    #[arg(long, value_name = "FRACTION")]
    pub planarity_tol: Option<f64>,

    /// Simplify a triangle mesh to about this many edges (within 2 %), keeping its
    /// holes and genus; `auto` simplifies only a model too detailed for its size, to
    /// the budget at which every panel holds its id and holes (tried, and named in the
    /// report).
    #[arg(long, value_name = "N|auto", conflicts_with = "target_faces")]
    pub target_edges: Option<TargetEdges>,

    /// Simplify a triangle mesh to about this many faces, keeping its holes and genus.
    #[arg(long, value_name = "N")]
    pub target_faces: Option<usize>,

    /// What simplification favours: regular (even triangle sizes and shapes, so
    /// panels of one size) or accurate (the closest surface: few
    /// large triangles where the model is flat, many small ones where it curves).
    #[arg(long, value_name = "MODE", value_parser = simplify_modes())]
    pub simplify_mode: Option<crate::mesh::simplify::SimplifyMode>,

    /// Remove connected components with fewer than N faces (stray fragments of a scan,
    /// loose parts too small to build).
    #[arg(long, value_name = "N")]
    pub min_component: Option<usize>,

    /// Close every hole of the mesh with a face along its rim (a scan's open base, a
    /// patch model's open rims), joining open seams shut: short rim edges no longer
    /// limit simplification, and the woven scheme can weave the model.
    #[arg(long)]
    #[serde(default)]
    pub fill_holes: bool,
}

/// A `--target-edges` value: a number of edges, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetEdges {
    /// The budget a model too detailed for its size needs, found by trial builds.
    Auto,
    /// About this many edges.
    Count(usize),
}

impl std::str::FromStr for TargetEdges {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        if text.trim().eq_ignore_ascii_case("auto") {
            return Ok(TargetEdges::Auto);
        }
        text.trim()
            .parse()
            .map(TargetEdges::Count)
            .map_err(|_| format!("'{text}' is not a number of edges or auto (like 600 or auto)"))
    }
}

impl<'de> Deserialize<'de> for TargetEdges {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Written {
            Count(usize),
            Text(String),
        }
        match Written::deserialize(d)? {
            Written::Count(n) => Ok(TargetEdges::Count(n)),
            Written::Text(text) => text.parse().map_err(serde::de::Error::custom),
        }
    }
}

/// How model units become millimetres.
#[derive(Clone, Debug, PartialEq)]
pub struct Scaling {
    /// `Some(mm)`: the longest bounding-box side becomes this many millimetres.
    pub size: Option<f64>,
    /// Millimetres per model unit when `size` is not given.
    pub unit_mm: f64,
    /// Extra factor.
    pub scale: f64,
}

impl Scaling {
    /// Millimetres per model unit for a model whose longest bounding-box side is
    /// `longest_side` model units.
    pub fn mm_per_unit(&self, longest_side: f64) -> f64 {
        let base = match self.size {
            Some(mm) if longest_side > 0.0 => mm / longest_side,
            _ => self.unit_mm,
        };
        base * self.scale
    }
}

/// The smallest model, longest side when built (mm), worth unfolding: below it every
/// panel is smaller than the laser's kerf.
pub const MIN_BUILT_MM: f64 = 0.1;

impl ModelSettings {
    /// Millimetres per model unit for a model whose longest side is `longest_side`
    /// model units, refusing a build smaller than [`MIN_BUILT_MM`] or longer than
    /// [`MAX_LENGTH_MM`]: at such sizes the geometry degenerates or overflows
    /// downstream, where no message could name the cause. The error names what made
    /// the size: `--scale` (when not 1) or `--size` as usage errors, otherwise the
    /// model's own coordinates in `--units` as an input error.
    pub fn checked_mm_per_unit(&self, model: &Path, longest_side: f64) -> Result<f64> {
        let scaling = &self.scaling;
        let mm_per_unit = scaling.mm_per_unit(longest_side);
        let built_mm = longest_side * mm_per_unit;
        if built_mm.is_finite() && (MIN_BUILT_MM..=MAX_LENGTH_MM).contains(&built_mm) {
            return Ok(mm_per_unit);
        }
        let bound = if built_mm.is_finite() && built_mm < MIN_BUILT_MM {
            format!("smaller than {MIN_BUILT_MM} mm")
        } else {
            "more than 1 km".to_string()
        };
        let built = format!("{} mm across", crate::units::short_number(built_mm));
        if scaling.scale != 1.0 {
            return Err(Error::Usage(format!(
                "--scale: {} makes {} {built}, {bound}; use a scale nearer 1 or give --size",
                crate::units::short_number(scaling.scale),
                model.display()
            )));
        }
        if let Some(size) = scaling.size {
            return Err(Error::Usage(format!(
                "--size: {} mm is {bound}; give a size between 0.1 mm and 1 km",
                crate::units::short_number(size)
            )));
        }
        Err(crate::error::InputError::new(
            model,
            crate::error::Location::File,
            format!(
                "the model is {built} when built (one model unit = {} mm), {bound}",
                scaling.unit_mm
            ),
            "give --size with a unit (like --size 4ft) or the right --units",
        )
        .into())
    }
}

/// Resolved model options.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSettings {
    /// Physical scaling.
    pub scaling: Scaling,
    /// Weld coincident vertices where manifold.
    pub weld: bool,
    /// Planarity tolerance (fraction of face diameter).
    pub planarity_tol: f64,
    /// Simplification budget, if any.
    pub budget: Option<crate::mesh::simplify::Budget>,
    /// `--target-edges auto`: a model too detailed for its size is simplified to the
    /// budget its build finds (`budget` is then `None`).
    pub auto_budget: bool,
    /// What simplification favours.
    pub simplify_mode: crate::mesh::simplify::SimplifyMode,
    /// Components with fewer faces than this are removed (0 keeps all).
    pub min_component: usize,
    /// Close every boundary loop (a face along its rim; open seams joined shut).
    pub fill_holes: bool,
    /// Keep the surface as it was before simplifying
    /// ([`crate::mesh::PreparedModel::unsimplified`]): the job's scheme keeps a
    /// distance to the model as given.
    pub keep_unsimplified: bool,
}

impl ModelOptions {
    /// Fills fields missing here from `other` (the configuration file).
    pub fn or(self, other: ModelOptions) -> ModelOptions {
        ModelOptions {
            size: self.size.or(other.size),
            units: self.units.or(other.units),
            scale: self.scale.or(other.scale),
            weld: self.weld || other.weld,
            planarity_tol: self.planarity_tol.or(other.planarity_tol),
            target_edges: self.target_edges.or(other.target_edges),
            target_faces: self.target_faces.or(other.target_faces),
            simplify_mode: self.simplify_mode.or(other.simplify_mode),
            min_component: self.min_component.or(other.min_component),
            fill_holes: self.fill_holes || other.fill_holes,
        }
    }

    /// Checks every value and fills in defaults.
    pub fn resolve(&self) -> Result<ModelSettings> {
        let size = match &self.size {
            Some(text) => {
                let mm = parse_length(text).map_err(|e| Error::Usage(format!("--size: {e}")))?;
                if mm <= 0.0 {
                    return Err(Error::Usage(format!("--size: '{text}' must be positive")));
                }
                Some(mm)
            }
            None => None,
        };
        let scale = self.scale.unwrap_or(defaults::SCALE);
        if !(scale.is_finite() && scale > 0.0) {
            return Err(Error::Usage(format!(
                "--scale: {scale} must be a positive number"
            )));
        }
        let planarity_tol = self.planarity_tol.unwrap_or(defaults::PLANARITY_TOL);
        if !(planarity_tol.is_finite() && planarity_tol > 0.0 && planarity_tol < 1.0) {
            return Err(Error::Usage(format!(
                "--planarity-tol: {planarity_tol} must be between 0 and 1 (a fraction of the face size)"
            )));
        }
        let budget = match (self.target_edges, self.target_faces) {
            (Some(_), Some(_)) => {
                return Err(Error::Usage(
                    "give --target-edges or --target-faces, not both".to_string(),
                ))
            }
            (Some(TargetEdges::Count(0)), _) | (_, Some(0)) => {
                return Err(Error::Usage(
                    "--target-edges and --target-faces must be positive".to_string(),
                ))
            }
            (Some(TargetEdges::Auto), None) => None,
            (Some(TargetEdges::Count(e)), None) => Some(crate::mesh::simplify::Budget::Edges(e)),
            (None, Some(f)) => Some(crate::mesh::simplify::Budget::Faces(f)),
            (None, None) => None,
        };
        Ok(ModelSettings {
            budget,
            auto_budget: self.target_edges == Some(TargetEdges::Auto),
            simplify_mode: self.simplify_mode.unwrap_or_default(),
            min_component: self.min_component.unwrap_or(defaults::MIN_COMPONENT),
            scaling: Scaling {
                size,
                unit_mm: self.units.unwrap_or(defaults::UNITS).mm(),
                scale,
            },
            weld: self.weld,
            planarity_tol,
            fill_holes: self.fill_holes,
            keep_unsimplified: false,
        })
    }
}

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

    /// The model options, read from the same table by [`load_config`].
    #[command(flatten)]
    #[serde(skip)]
    pub model: ModelOptions,

    /// The schemes' own options as given (their arguments come from the registry,
    /// not from this type; the command line and [`load_config`] fill them in).
    #[arg(skip)]
    #[serde(skip)]
    pub scheme_values: OptionValues,

    /// Layer names, colours and stroke widths per kind (config file only: the
    /// `[layers.cut]` tables).
    #[arg(skip)]
    #[serde(skip)]
    pub layers: LayerSettings,
}

/// The face labels read on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LabelSide {
    /// The outside of the model (the side facing up on the sheet).
    Outside,
    /// The inside: labels mirrored.
    Inside,
}

/// One kind's layer as a config file gives it (`[layers.score-valley]`), each field
/// optional.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerSetting {
    /// Layer name.
    pub name: Option<String>,
    /// Colour, `#RRGGBB`.
    pub color: Option<String>,
    /// Stroke width, a length with a unit.
    pub stroke_width: Option<String>,
}

/// Every kind's layer settings, in [`Kind::ALL`] order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayerSettings(pub [LayerSetting; 4]);

impl LayerSettings {
    /// The config keys of the kinds, in [`Kind::ALL`] order.
    pub const KEYS: [&'static str; 4] = ["engrave", "score", "score-valley", "cut"];

    /// These settings, with `other`'s where a field is missing.
    fn or(self, other: LayerSettings) -> LayerSettings {
        let LayerSettings(mut mine) = self;
        for (m, o) in mine.iter_mut().zip(other.0) {
            m.name = m.name.take().or(o.name);
            m.color = m.color.take().or(o.color);
            m.stroke_width = m.stroke_width.take().or(o.stroke_width);
        }
        LayerSettings(mine)
    }

    /// The layers drawn: LASER.md's, every stroke `stroke_width` mm, with these
    /// settings applied.
    fn resolve(&self, stroke_width: f64) -> Result<Layers> {
        let mut layers = Layers::standard(stroke_width);
        for ((setting, kind), key) in self.0.iter().zip(Kind::ALL).zip(Self::KEYS) {
            let style = layers.of_mut(kind);
            if let Some(name) = &setting.name {
                check_layer_name(name)
                    .map_err(|why| Error::Usage(format!("layers.{key}.name: {why}")))?;
                style.name = name.clone();
            }
            if let Some(color) = &setting.color {
                style.color = check_layer_color(color)
                    .map_err(|why| Error::Usage(format!("layers.{key}.color: {why}")))?;
            }
            if let Some(width) = &setting.stroke_width {
                style.stroke_width = parse_length(width)
                    .map_err(|why| Error::Usage(format!("layers.{key}.stroke-width: {why}")))?;
            }
        }
        for (i, a) in layers.0.iter().enumerate() {
            if layers.0[..i].iter().any(|b| b.name == a.name) {
                return Err(Error::Usage(format!(
                    "layers: two kinds are both named {}; give each kind its own layer name",
                    a.name
                )));
            }
        }
        Ok(layers)
    }
}

/// Says why `name` cannot be a layer name (DXF R12: letters, digits, `-`, `_`, `$`, at
/// most 31).
pub fn check_layer_name(name: &str) -> std::result::Result<(), String> {
    let fine = !name.is_empty()
        && name.len() <= 31
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '$'));
    if fine {
        Ok(())
    } else {
        Err(format!(
            "\"{name}\" is not a layer name DXF R12 takes: use 1 to 31 letters, digits, -, _ or $, like \"CUT\""
        ))
    }
}

/// The colour `text` names, as `#RRGGBB` in capitals, or why it names none.
pub fn check_layer_color(text: &str) -> std::result::Result<String, String> {
    let hex = text.strip_prefix('#').unwrap_or("");
    if hex.len() == 6 && hex.chars().all(|c| c.is_ascii_hexdigit()) {
        Ok(format!("#{}", hex.to_ascii_uppercase()))
    } else {
        Err(format!(
            "\"{text}\" is not a colour: write it as pure RGB, like \"#FF0000\" (drivers match colours exactly)"
        ))
    }
}

/// What to do with non-planar faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum NonPlanar {
    /// Split them into triangles.
    Triangulate,
    /// Move vertices until every face is planar (guided projection).
    Planarize,
    /// Refuse the model.
    Error,
}

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
    /// Completes a command holding these options with `registry`: the `--scheme`
    /// values, every option's default at the end of its help (its subcommands' too),
    /// and every scheme's own options.
    pub fn with_registry(command: clap::Command, registry: &Registry) -> clap::Command {
        let schemes: Vec<clap::builder::PossibleValue> = registry
            .schemes()
            .iter()
            .map(|s| clap::builder::PossibleValue::new(s.name()).help(s.about()))
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
            panel_limit: Some(sheet.panel_limit(nest.search.rotations)),
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
        let scheme_defaults = scheme.defaults();
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
    /// The largest panel the sheet takes inside its margins, in `rotations` steps.
    fn panel_limit(&self, rotations: u32) -> PanelLimit {
        PanelLimit {
            width: self.sheet.width - 2.0 * self.margin,
            height: self.sheet.height - 2.0 * self.margin,
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
    fn lengths_in_every_unit() {
        for (text, mm) in [
            ("4ft", 1219.2),
            ("1.2m", 1200.0),
            ("48in", 1219.2),
            ("0.25 in", 6.35),
            ("600mm", 600.0),
            ("12.5cm", 125.0),
            ("1e3mm", 1000.0),
        ] {
            assert!(close(parse_length(text).unwrap(), mm), "{text}");
        }
        assert!(parse_length("4").unwrap_err().contains("no unit"));
        assert!(parse_length("4yd").unwrap_err().contains("unknown unit"));
        assert!(parse_length("ft").is_err());
    }

    #[test]
    fn sheet_sizes() {
        let s = parse_sheet("18x24in").unwrap();
        assert!((s.width - 457.2).abs() < 1e-9 && (s.height - 609.6).abs() < 1e-9);
        let s = parse_sheet("600x400mm").unwrap();
        assert_eq!((s.width, s.height), (600.0, 400.0));
        let s = parse_sheet("18in x 24in").unwrap();
        assert!((s.height - 609.6).abs() < 1e-9);
        assert_eq!(parse_sheet("A0").unwrap().width, 841.0);
        assert_eq!(parse_sheet("a4").unwrap().height, 297.0);
        assert!((parse_sheet("letter").unwrap().width - 215.9).abs() < 1e-9);
        assert!((parse_sheet("tabloid").unwrap().height - 431.8).abs() < 1e-9);
        assert!(parse_sheet("18x24").is_err());
        assert!(parse_sheet("0x24in").is_err());
        assert!(parse_sheet("huge").is_err());
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

    #[test]
    fn scaling_by_size_and_units() {
        let by_size = Scaling {
            size: Some(1219.2),
            unit_mm: 1.0,
            scale: 1.0,
        };
        assert!((by_size.mm_per_unit(2.0) - 609.6).abs() < 1e-9);
        let by_units = Scaling {
            size: None,
            unit_mm: LengthUnit::Cm.mm(),
            scale: 2.0,
        };
        assert_eq!(by_units.mm_per_unit(123.0), 20.0);
    }
}
