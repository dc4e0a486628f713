//! Every option's default, written once: the constants that resolution falls back on,
//! and the table that ends each option's `--help` with `[default: …]` read from those
//! same constants. README's option tables are checked against the table by
//! `tests/options_table.rs`.
//!
//! A scheme can state its own options' defaults the same way: a constant per option
//! that its `configure` falls back on, and [`OptionDefault::state_in`] applied to the
//! arguments its `options()` returns.

use crate::mesh::simplify::SimplifyMode;
use crate::nest::NesterName;
use crate::scheme::Registry;
use crate::units::LengthUnit;

use super::values::{LabelSide, NonPlanar};
use crate::export::laser::Speeds;
pub use crate::option_default::{
    find_default, state_defaults, state_defaults_in, OptionDefault, Stated,
};
use std::fmt::Display;

/// `--sheet`.
pub const SHEET: &str = "18x24in";
/// `--margin`.
pub const MARGIN: &str = "0.25in";
/// `--spacing`.
pub const SPACING: &str = "0.125in";
/// `--kerf`: none, so parts keep their nominal geometry.
pub const KERF: &str = "0mm";
/// `--format`.
pub const FORMAT: &str = "svg";
/// `--hole-diameter`.
pub const HOLE_DIAMETER: &str = "0.125in";
/// `--label-height`.
pub const LABEL_HEIGHT: &str = "4mm";
/// `--stroke-width`: a hairline, which laser drivers take as a vector line.
pub const STROKE_WIDTH: &str = "0.001in";
/// `--rotations`.
pub const ROTATIONS: u32 = 32;
/// `--effort`.
pub const EFFORT: u32 = 5;
/// `--seed`.
pub const SEED: u64 = 0;
/// `--nester`.
pub const NESTER: NesterName = NesterName::TrueShape;
/// `--nonplanar`, of the build and of `inspect`.
pub const NONPLANAR: NonPlanar = NonPlanar::Triangulate;
/// `--labels`.
pub const LABELS: LabelSide = LabelSide::Outside;
/// `--units`.
pub const UNITS: LengthUnit = LengthUnit::Mm;
/// `--scale`.
pub const SCALE: f64 = 1.0;
/// `--planarity-tol`.
pub const PLANARITY_TOL: f64 = 1e-3;
/// `--min-component`: 0 keeps every component.
pub const MIN_COMPONENT: usize = 0;

/// The name an enum's value has on the command line.
fn value_name(value: impl clap::ValueEnum) -> String {
    value
        .to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default()
}

/// `--speeds`' default as the option writes it (`cut=15,score=50,…`).
fn speeds_text(speeds: Speeds) -> String {
    format!(
        "cut={},score={},engrave={},travel={}",
        speeds.cut, speeds.score, speeds.engrave, speeds.travel
    )
}

/// A per-scheme default of the options every scheme takes.
fn per_scheme<T: PartialEq + Display>(
    long: &'static str,
    registry: &Registry,
    value: impl Fn(&crate::scheme::PanelDefaults) -> T,
) -> OptionDefault {
    OptionDefault {
        long,
        stated: Stated::PerScheme {
            values: registry
                .schemes()
                .iter()
                .map(|s| (s.name(), value(&s.info().defaults).to_string()))
                .collect(),
            sentence: registry.describe_defaults(value),
        },
    }
}

/// The default of every option of the main command and of `inspect` but the schemes'
/// own (an option both take has one default), in `--help` order.
pub fn option_defaults(registry: &Registry) -> Vec<OptionDefault> {
    type D = OptionDefault;
    vec![
        D::words("config", "none"),
        D::value("scheme", registry.default_scheme().name()),
        D::value("sheet", SHEET),
        D::value("margin", MARGIN),
        D::value("spacing", SPACING),
        D::noted("kerf", KERF, "nominal geometry"),
        D::words(
            "out",
            "./NAME, NAME being the model's file name without extension",
        ),
        D::words("force", "off"),
        D::words("no-map", "the map is written"),
        D::words("no-preview", "the preview page is written"),
        D::value("labels", value_name(LABELS)),
        D::value("speeds", speeds_text(Speeds::default())),
        D::value("format", FORMAT),
        per_scheme("face-scale", registry, |d| d.face_scale),
        per_scheme("holes", registry, |d| d.holes),
        D::value("hole-diameter", HOLE_DIAMETER),
        D::words("hole-margin", "half the --hole-diameter"),
        D::value("label-height", LABEL_HEIGHT),
        D::value("nonplanar", value_name(NONPLANAR)),
        D::value("rotations", ROTATIONS),
        D::value("nester", NESTER.as_str()),
        D::value("effort", EFFORT),
        D::value("seed", SEED),
        D::words("mirror", "off"),
        D::words("time-limit", "none"),
        D::value("stroke-width", STROKE_WIDTH),
        D::words("strict", "off"),
        D::words("build-anyway", "off"),
        D::words("json", "off"),
        D::words("quiet", "off"),
        D::words("size", "the model's own size in --units"),
        D::value("units", value_name(UNITS)),
        D::value("scale", SCALE),
        D::words("weld", "off"),
        D::value("planarity-tol", PLANARITY_TOL),
        D::words("target-edges", "no simplification"),
        D::words("target-faces", "no simplification"),
        D::value("simplify-mode", SimplifyMode::default()),
        D::noted("min-component", MIN_COMPONENT, "keep every component"),
        D::words("fill-holes", "off"),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_as_the_command_line_writes_them() {
        let defaults = option_defaults(&Registry::default());
        let shown = |long: &str| find_default(&defaults, Some(long)).unwrap().shown();
        assert_eq!(shown("margin"), "0.25in");
        assert_eq!(shown("kerf"), "0mm, nominal geometry");
        assert_eq!(shown("planarity-tol"), "0.001");
        assert_eq!(shown("scale"), "1");
        assert_eq!(shown("units"), "mm");
        assert_eq!(shown("nester"), "true-shape");
        assert_eq!(shown("simplify-mode"), "regular");
        assert_eq!(shown("speeds"), "cut=15,score=50,engrave=100,travel=300");
        assert_eq!(shown("scheme"), "half-edge");
    }

    #[test]
    fn a_scheme_states_its_own_defaults_the_same_way() {
        let arg = clap::Arg::new("tab_height")
            .long("tab-height")
            .help("Wanted overlap of a tab");
        let stated = state_defaults(vec![arg], &[OptionDefault::value("tab-height", "8mm")]);
        assert_eq!(
            stated[0].get_help().unwrap().to_string(),
            "Wanted overlap of a tab. [default: 8mm]"
        );
    }
}
