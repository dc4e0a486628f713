//! True-shape nesting: parts are placed by their real outlines (tabs and flaps
//! included), so small parts fill the gaps and concavities of large ones.
//!
//! Collision detection is jagua-rs (every part inflated by half the spacing, the sheet
//! grown by the same amount); the search is ours:
//! 1. constructive, twice, side by side: in rows (`rows`: parts lie flat, tallest
//!    first, each dropped at the end of the current row and slid down and left until
//!    it rests, the next part chosen among the next few by how little of the row it
//!    claims, so slanted ends interlock), and first-fit decreasing (parts largest
//!    first, each into the first sheet where a sampled, then slid, bottom-left
//!    position is free, poses that touch their neighbours scoring better
//!    (`CONTACT_WEIGHT`));
//! 2. improvement, of each construction: the emptiest sheet is emptied into the
//!    others, part by part, by the sampled pose search; a sheet left empty is dropped.
//!    Partial moves are kept: they only make the emptiest sheet emptier (the second
//!    objective). The better of the two layouts goes on;
//! 3. squeezing by overlap minimisation (`separate`): the emptiest sheet's parts,
//!    largest first, go one at a time to where they overlap least on one of the
//!    emptiest other sheets, which is then separated by a guided local search; a part
//!    stays only when that succeeds, and the squeeze stops at the first part that
//!    finds no room. A sheet left empty is dropped.
//!
//! Every random choice comes from a generator seeded by `seed` (one per construction
//! and what follows it), and the effort is a
//! number of samples and rounds, so the result depends on the input and the options
//! only. The sampled poses of a search are drawn in order and then tested in
//! parallel against a sheet that does not change meanwhile, and compared in order,
//! so the thread count changes the speed, never the result. `time_limit` is an
//! optional cap on the improvement and the squeeze, and the only source of
//! run-to-run differences when it is hit.

use std::time::Instant;

use glam::DVec2;

mod nester;
mod options;
mod part;
mod rows;
mod separate;

use crate::nest::layout::{Layout, NestProgress, SheetSpec, TooLarge};
use nester::Nester;
pub use options::NestOptions;
use part::{prepare, too_large};

/// Collision checks the squeeze may spend per unit of effort (an evaluation of a
/// pose's overlap counts as several: see `separate`): at the default effort, what a
/// job of about a thousand parts needs to take a last sheet of a few parts away.
const SQUEEZE_CHECKS: u64 = 5_000_000;

/// Parts the emptiest sheet may hold, per unit of effort, for the squeeze to try it:
/// squeezing one part into a full sheet costs about a second of separation, so the
/// squeeze pays where the last sheet holds a few parts, not hundreds.
const SQUEEZE_PARTS: usize = 2;

/// Separation rounds per squeezed part and sheet tried, per unit of effort.
const SEPARATION_ROUNDS: usize = 100;

/// The sheets of the kept search after each phase: what moving parts and squeezing
/// saved, for the manifest and the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PhaseSheets {
    /// After its construction.
    pub placed: usize,
    /// After the moves that empty the emptiest sheet.
    pub moved: usize,
    /// After the squeeze (the search's result).
    pub squeezed: usize,
}

/// Lays out parts (outer outlines in mm) by their true shapes.
pub fn true_shape_layout(
    outlines: &[Vec<DVec2>],
    sheet: SheetSpec,
    options: &NestOptions,
) -> Result<Layout, TooLarge> {
    true_shape_layout_observed(outlines, sheet, options, &NestProgress::new(&|_| {}))
        .map(|(layout, _)| layout)
}

/// [`true_shape_layout`], telling `progress` how far each search has got, with the
/// sheets after each phase.
pub fn true_shape_layout_observed(
    outlines: &[Vec<DVec2>],
    sheet: SheetSpec,
    options: &NestOptions,
    progress: &NestProgress,
) -> Result<(Layout, PhaseSheets), TooLarge> {
    let (parts, container) = prepare(outlines, sheet, options)?;
    // Two constructions, each improved on its own, and the better kept: rows of
    // interlocking parts win on alike parts and long strips, first-fit decreasing on
    // short wavy strips (docs/nesting.md has the measured cases). Each has its own
    // generator from the same seed, so the result does not depend on which finishes
    // first.
    //
    // One clock, started before the constructions (which always finish), for both
    // improvements and the squeeze: `time_limit` caps them together, on one thread
    // (where the two improvements run one after the other) as on two.
    let started = Instant::now();
    let built = |in_rows: bool| -> Result<(Nester, usize), usize> {
        let mut nester = Nester::new(&parts, container.clone(), options);
        nester.progress = Some((progress, usize::from(in_rows)));
        if in_rows {
            nester.construct_in_rows()?;
        } else {
            nester.construct_first_fit()?;
        }
        let placed = nester.sheets.len();
        nester.improve(options, started);
        Ok((nester, placed))
    };
    let (first_fit, rows) = rayon::join(|| built(false), || built(true));
    let too_large_part = |p: usize| too_large(p, &outlines[p], sheet, options.rotations);
    let (first_fit, rows) = (
        first_fit.map_err(too_large_part)?,
        rows.map_err(too_large_part)?,
    );
    let (mut nester, placed) = if rows.0.better_than(&first_fit.0) {
        rows
    } else {
        first_fit
    };
    let moved = nester.sheets.len();
    let effort = options.effort.max(1) as usize;

    // Then squeeze the emptiest sheet's parts into the others by overlap
    // minimisation, with an allowance of its own: unlike the improvement's, it does
    // not grow with the number of parts, because the squeeze only ever moves one
    // sheet's parts (the sheets it separates are full ones, though, and there an
    // evaluation costs up to twice what it counts).
    // A sheet of more parts is not tried: each part squeezed into a full sheet sets
    // off a cascade of moves there, and a hundred parts would take minutes.
    nester.progress = Some((progress, 2));
    nester.start_budget(SQUEEZE_CHECKS * u64::from(options.effort.max(1)), 0, 1000);
    while nester.sheets.len() >= 2
        && !nester.out_of_budget()
        && nester.sheets[nester.emptiest()].parts.len() <= SQUEEZE_PARTS * effort
        && nester.squeeze_emptiest(SEPARATION_ROUNDS * effort)
    {}
    nester.report(0, 1000, 1, 1);

    let phases = PhaseSheets {
        placed,
        moved,
        squeezed: nester.sheets.len(),
    };
    Ok((nester.finish(outlines.len(), sheet), phases))
}
