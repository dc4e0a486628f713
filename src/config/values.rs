//! The values of the options that choose among named ways (`--labels`, `--nonplanar`,
//! `--nester`, `--simplify-mode`) and of `--target-edges` (a number or `auto`), as the
//! command line and the configuration file read them.

use serde::Deserialize;

use crate::nest::NesterName;

/// `--simplify-mode`'s values (the mesh layer knows nothing of the command line).
pub(super) fn simplify_modes(
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
pub(super) fn nesters() -> impl clap::builder::TypedValueParser<Value = NesterName> {
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

/// The face labels read on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LabelSide {
    /// The outside of the model (the side facing up on the sheet).
    Outside,
    /// The inside: labels mirrored.
    Inside,
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
