//! The true-shape nester's search settings, as the job resolves them from the options.

use std::time::Duration;

/// Search settings of the true-shape nester.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NestOptions {
    /// Rotation steps per turn (at least 1).
    pub rotations: u32,
    /// Also try every part mirrored.
    pub mirror: bool,
    /// Search effort (1 = quick); samples and rounds grow linearly with it.
    pub effort: u32,
    /// Seed of the search.
    pub seed: u64,
    /// Optional wall-clock cap on the improvement and squeeze phases.
    pub time_limit: Option<Duration>,
}

/// Quarter turns, no mirror, effort 5, seed 1 and no time limit: the search the
/// nester's unit tests run.
#[cfg(test)]
pub(super) fn test_options() -> NestOptions {
    NestOptions {
        rotations: 4,
        mirror: false,
        effort: 5,
        seed: 1,
        time_limit: None,
    }
}
