//! Filling arenas in parallel and in order, and walking them. A big job makes
//! millions of panels: each is made as an owned value on some worker and copied into
//! an arena (one buffer per kind of item) without a full vector of owned values ever
//! being held. The arenas themselves ([`super::Panels`], [`super::FlatPanels`]) know
//! their fields; this module knows only the order.

/// Items made at a time by [`fill_arena`]: enough to keep the cores busy, few enough
/// that the runs waiting to be appended stay a small part of the whole.
pub(super) const CHUNK: usize = 1 << 14;

/// A buffer length as an arena's u32 start.
///
/// # Panics
/// When it passes 2³² items: about 100 GB of 3D vertices or 70 GB of flat points,
/// far beyond what the machines the tool runs on hold.
pub(super) fn arena_len(len: usize) -> u32 {
    u32::try_from(len).expect("an arena buffer of fewer than 2^32 items")
}

/// Something items are copied into as they are made (see [`fill_arena`]): the panel
/// arenas, what gathers flat panels with a tally, the half-edge scheme's sparse tabs.
pub trait Arena: Default + Send {
    /// What one item is made as.
    type Made;
    /// Copies one made item in.
    fn take(&mut self, made: Self::Made);
    /// Appends another one's items after this one's.
    fn append(&mut self, other: Self);
}

/// An arena that hands its panels out as views ([`crate::panel::Panels`], [`crate::panel::FlatPanels`]).
pub trait Views {
    /// How a panel is handed out.
    type View<'a>
    where
        Self: 'a;
    /// Number of panels.
    fn count(&self) -> usize;
    /// Panel `i` (panics when there is none, as indexing does).
    fn view(&self, i: usize) -> Self::View<'_>;
}

/// An arena of the items `made`, in order.
pub(super) fn collect_arena<A: Arena>(made: impl IntoIterator<Item = A::Made>) -> A {
    let mut all = A::default();
    for panel in made {
        all.take(panel);
    }
    all
}

/// The panels of an arena, in order.
#[derive(Clone, Debug)]
pub struct ArenaIter<'a, A> {
    arena: &'a A,
    range: std::ops::Range<usize>,
}

impl<'a, A: Views> ArenaIter<'a, A> {
    pub(super) fn new(arena: &'a A) -> Self {
        ArenaIter {
            arena,
            range: 0..arena.count(),
        }
    }
}

impl<'a, A: Views> Iterator for ArenaIter<'a, A> {
    type Item = A::View<'a>;
    fn next(&mut self) -> Option<A::View<'a>> {
        self.range.next().map(|i| self.arena.view(i))
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.range.size_hint()
    }
}

impl<A: Views> DoubleEndedIterator for ArenaIter<'_, A> {
    fn next_back(&mut self) -> Option<Self::Item> {
        self.range.next_back().map(|i| self.arena.view(i))
    }
}

impl<A: Views> ExactSizeIterator for ArenaIter<'_, A> {}

/// Makes `make(0)`, …, `make(count - 1)` in parallel and copies them into one arena in
/// that order: each worker copies its own run of items into a small arena of its
/// own, as it makes them, and the runs are appended in order (bulk copies), so the
/// copying is parallel and the thread count changes nothing. Works a chunk at a time,
/// so the runs waiting to be appended stay small. On failure the error is the first
/// one in order.
pub fn fill_arena<A: Arena, E: Send>(
    count: usize,
    make: impl Fn(usize) -> Result<A::Made, E> + Sync,
) -> Result<A, E> {
    use rayon::prelude::*;
    let mut all = A::default();
    for start in (0..count).step_by(CHUNK) {
        let runs: Vec<Result<A, E>> = (start..(start + CHUNK).min(count))
            .into_par_iter()
            .fold(
                || Ok(A::default()),
                |run, i| {
                    let mut run = run?;
                    run.take(make(i)?);
                    Ok(run)
                },
            )
            .collect();
        for run in runs {
            all.append(run?);
        }
    }
    Ok(all)
}
