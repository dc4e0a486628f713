//! Placing flat panels on sheets. The nester sees only outlines (polygons in mm) and
//! the sheet; it knows nothing of meshes or schemes.
//!
//! Coordinates on a sheet: millimetres, origin at the lower-left corner, y up (the
//! exporters flip y for SVG).

pub mod grid;
pub mod layout;
pub mod shelf;
pub mod true_shape;

use glam::DVec2;

#[cfg(test)]
pub(crate) use layout::test_rectangle;
pub use layout::{Layout, NestProgress, Placement, SheetSpec, TooLarge};

use true_shape::NestOptions;

/// Nesters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NesterName {
    /// True shapes: sampled bottom-left placement, then emptying the emptiest sheet.
    TrueShape,
    /// Bounding boxes in rows.
    Shelf,
}

impl NesterName {
    /// The name used on the command line and in the manifest.
    pub fn as_str(self) -> &'static str {
        match self {
            NesterName::TrueShape => "true-shape",
            NesterName::Shelf => "shelf",
        }
    }
}

/// Nesting settings of a job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NestSettings {
    /// Which nester.
    pub nester: NesterName,
    /// Rotations, mirroring and the true-shape search's effort, seed and time cap
    /// (the shelf uses the rotations only).
    pub search: NestOptions,
}

/// The layout of a job and how it was reached.
#[derive(Clone, Debug)]
pub struct Nested {
    /// The sheets, fullest first.
    pub layout: Layout,
    /// The nester whose layout this is.
    pub nester: NesterName,
    /// Sheets of the shelf baseline for the same parts.
    pub shelf_sheets: usize,
    /// The true-shape search's sheets after each phase, when it ran (its result is
    /// dropped for the shelf's when that takes fewer sheets).
    pub search_phases: Option<true_shape::PhaseSheets>,
    /// The lower bound that counts the spacing ([`spacing_lower_bound`]).
    pub spacing_bound: usize,
}

/// Lays out parts (outer outlines in mm, with their areas for the sheet order) with
/// the chosen nester. The shelf baseline is always computed: it is what the report
/// compares with, and the true-shape search, being a heuristic, never hands out more
/// sheets than it.
pub fn lay_out(
    outlines: &[Vec<DVec2>],
    areas: &[f64],
    sheet: SheetSpec,
    settings: &NestSettings,
) -> Result<Nested, TooLarge> {
    lay_out_observed(
        outlines,
        areas,
        sheet,
        settings,
        &NestProgress::new(&|_| {}),
    )
}

/// [`lay_out`], telling `progress` how far the search has got.
pub fn lay_out_observed(
    outlines: &[Vec<DVec2>],
    areas: &[f64],
    sheet: SheetSpec,
    settings: &NestSettings,
    progress: &NestProgress,
) -> Result<Nested, TooLarge> {
    let shelf = shelf::shelf_layout(outlines, sheet, settings.search.rotations)?;
    let shelf_sheets = shelf.sheets;
    let (mut layout, nester, search_phases) = match settings.nester {
        NesterName::Shelf => (shelf, NesterName::Shelf, None),
        NesterName::TrueShape => {
            let (searched, phases) = true_shape::true_shape_layout_observed(
                outlines,
                sheet,
                &settings.search,
                progress,
            )?;
            if shelf.sheets < searched.sheets {
                (shelf, NesterName::Shelf, Some(phases))
            } else {
                (searched, NesterName::TrueShape, Some(phases))
            }
        }
    };
    layout.fullest_first(areas);
    Ok(Nested {
        layout,
        nester,
        shelf_sheets,
        search_phases,
        spacing_bound: spacing_lower_bound(outlines, sheet),
    })
}

/// The sheets needed if the outlines, each grown by half the spacing, filled the usable
/// sheet grown by half the spacing without a gap: `ceil(total grown area / grown usable
/// area)`. Every layout needs at least this many sheets, and unlike the plain area
/// bound it counts the spacing, which is most of the waste when parts are small.
///
/// The grown area of an outline is that of its offset polygon less the most its
/// rounded corners can add over true arcs (`(8 tan 22.5° - pi) r^2`), so the figure
/// stays a lower bound; an outline whose offset overlaps itself (a concavity narrower
/// than the spacing) counts its plain area.
pub fn spacing_lower_bound(outlines: &[Vec<DVec2>], sheet: SheetSpec) -> usize {
    use crate::plane::{area, is_simple, offset_outline};
    use std::f64::consts::PI;
    let r = 0.5 * sheet.spacing.max(0.0);
    let corner_excess = (8.0 * (PI / 8.0).tan() - PI) * r * r;
    let grown: f64 = outlines
        .iter()
        .map(|outline| {
            let bare = area(outline);
            let offset = offset_outline(outline, r);
            if r > 0.0 && is_simple(&offset) {
                (area(&offset) - corner_excess).max(bare)
            } else {
                bare
            }
        })
        .sum();
    let usable = (sheet.usable_width() + 2.0 * r) * (sheet.usable_height() + 2.0 * r);
    (grown / usable).ceil() as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spacing_bound_counts_the_grown_squares() {
        // Usable 100 x 100 mm, spacing 2 mm: the grown sheet is 102 x 102 = 10404 mm²
        // and a grown 10 mm square 100 + 4·10·1 + π·1² = 143.14 mm², so 72 squares
        // (10306 mm²) fit one sheet's area and 73 (10449 mm²) do not, while the bare
        // area bound stays at one sheet up to 100 squares.
        let sheet = SheetSpec {
            width: 110.0,
            height: 110.0,
            margin: 5.0,
            spacing: 2.0,
        };
        let squares = |n: usize| vec![test_rectangle(10.0, 10.0); n];
        assert_eq!(spacing_lower_bound(&squares(72), sheet), 1);
        assert_eq!(spacing_lower_bound(&squares(73), sheet), 2);
        assert_eq!(spacing_lower_bound(&squares(100), sheet), 2);
        // Without spacing it is the area bound.
        let touching = SheetSpec {
            spacing: 0.0,
            ..sheet
        };
        assert_eq!(spacing_lower_bound(&squares(100), touching), 1);
        assert_eq!(spacing_lower_bound(&squares(101), touching), 2);
    }
}
