//! What the island engine reads: its options, the `--flat-fold` argument the net and
//! strip schemes share, and the kinds of id its panels carry.

use crate::panel::IdKind;
use crate::scheme::PanelOptions;

/// Islands: `N4`, numbered from 1; the manifest lists an island's faces.
pub static ISLAND: IdKind = IdKind {
    letter: "N",
    legend: "net island",
    noun: "island",
    part_noun: "",
    layer: "",
};

/// Match numbers: `17`, the same on both sides of a cut, so its two sides are found.
pub static MATCH: IdKind = IdKind {
    letter: "",
    legend: "a bare number marks the two sides of one cut",
    noun: "match",
    part_noun: "",
    layer: "",
};

/// `--flat-fold` (degrees).
pub(in crate::scheme) const FLAT_FOLD_DEG: f64 = 1.0;

/// `--flat-fold`, shared by the net and strip schemes.
#[derive(Clone, Debug, Default, clap::Args)]
pub(in crate::scheme) struct FlatFoldArgs {
    /// Folds flatter than this angle in degrees are not scored.
    #[arg(long, value_name = "DEGREES")]
    flat_fold: Option<f64>,
}

impl FlatFoldArgs {
    /// The angle (radians), checked, or its default.
    pub(in crate::scheme) fn angle(&self) -> Result<f64, String> {
        let flat_fold = self.flat_fold.unwrap_or(FLAT_FOLD_DEG);
        if !(0.0..90.0).contains(&flat_fold) {
            return Err(format!(
                "--flat-fold: {flat_fold} must be an angle in degrees from 0 to below 90"
            ));
        }
        Ok(flat_fold.to_radians())
    }
}

/// The island engine's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct IslandOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Wanted tab height (mm).
    pub tab_height: f64,
    /// Most faces in one island.
    pub max_island_faces: Option<usize>,
    /// Folds flatter than this (radians) are not scored.
    pub flat_fold: f64,
    /// Largest ratio of an island's convex hull to its area.
    pub island_spread: f64,
}

/// Options for unit tests of the engine and the schemes on it: whole faces, no holes,
/// 5 mm tabs, at most `max_island_faces` faces an island, folds under 1° unscored, hulls
/// up to `island_spread` times an island's area, no sheet.
#[cfg(test)]
pub(in crate::scheme) fn test_options(
    max_island_faces: Option<usize>,
    island_spread: f64,
) -> IslandOptions {
    IslandOptions {
        panel: PanelOptions {
            face_scale: 1.0,
            holes: 0,
            hole_diameter: 1.0,
            hole_margin: 0.5,
            label_height: 2.0,
            panel_limit: None,
            scale: 1.0,
        },
        tab_height: 5.0,
        max_island_faces,
        flat_fold: 1f64.to_radians(),
        island_spread,
    }
}
