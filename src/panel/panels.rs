//! A job's panels, 3D ([`Panels`]) and flat ([`FlatPanels`]), each in one arena: one
//! buffer per kind of item and a small head per panel saying where its items start.
//! Both are one generic [`PanelArena`] over buffers declared by `buffers!`; each
//! knows only how its panels map onto its buffers.

use glam::{DVec2, DVec3};

use super::arena::{arena_len, collect_arena, fill_arena, Arena, ArenaIter, Views};
use super::label::{Label, LeftOut};
use super::loops::LoopsRef;
use super::shape::{FlatHole, FlatLabel, FlatPanel, FlatPanelRef, Fold, Hole, Panel, PanelRef};
use super::source::Source;

/// An arena's buffers, one per kind of item, grown, measured and cut into panels
/// together: the `N` buffers behind a [`PanelArena`].
pub trait Buffers<const N: usize>: Default {
    /// One panel's items in each buffer.
    type Slices<'a>
    where
        Self: 'a;
    /// The length of every buffer: where the next panel's items start.
    ///
    /// # Panics
    /// When a buffer has passed 2³² items.
    fn lens(&self) -> [u32; N];
    /// The items from `start` to `end` in each buffer.
    fn slices(&self, start: [u32; N], end: [u32; N]) -> Self::Slices<'_>;
    /// Appends one panel's items.
    fn extend(&mut self, items: Self::Slices<'_>);
    /// Appends all of `other`'s items.
    fn append(&mut self, other: &Self);
    /// Gives back spare capacity.
    fn shrink_to_fit(&mut self);
}

/// Declares an arena's buffers (one `Vec` per kind of item), a struct of one panel's
/// slices of them, and their [`Buffers`] implementation, field by field.
macro_rules! buffers {
    ($(#[$doc:meta])* $name:ident, $slices:ident, $n:literal { $($field:ident: $item:ty,)* }) => {
        $(#[$doc])*
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct $name {
            $($field: Vec<$item>,)*
        }

        /// One panel's items in each buffer of a
        #[doc = concat!("[`", stringify!($name), "`].")]
        #[derive(Clone, Copy)]
        pub struct $slices<'a> {
            $($field: &'a [$item],)*
        }

        impl Buffers<$n> for $name {
            type Slices<'a> = $slices<'a>;

            fn lens(&self) -> [u32; $n] {
                [$(arena_len(self.$field.len()),)*]
            }

            fn slices(&self, start: [u32; $n], end: [u32; $n]) -> $slices<'_> {
                // Fields are initialised in the order written, one range each.
                let mut ranges = start.into_iter().zip(end);
                let mut next = || {
                    let (a, b) = ranges.next().expect("one start per buffer");
                    a as usize..b as usize
                };
                $slices {
                    $($field: &self.$field[next()],)*
                }
            }

            fn extend(&mut self, items: $slices<'_>) {
                $(self.$field.extend_from_slice(items.$field);)*
            }

            fn append(&mut self, other: &Self) {
                $(self.$field.extend_from_slice(&other.$field);)*
            }

            fn shrink_to_fit(&mut self) {
                $(self.$field.shrink_to_fit();)*
            }
        }
    };
}

buffers! {
    /// The buffers of a [`Panels`].
    PanelBuffers, PanelSlices, 5 {
        vertices: DVec3,
        facet_indices: u32,
        facet_ends: u32,
        holes: Hole,
        labels: Label,
    }
}

buffers! {
    /// The buffers of a [`FlatPanels`]: points, outline indices, folds, holes, labels.
    FlatBuffers, FlatSlices, 6 {
        points: DVec2,
        loop_indices: u32,
        loop_ends: u32,
        folds: Fold,
        holes: FlatHole,
        labels: FlatLabel,
    }
}

/// What an arena keeps of one panel beside its items, and where they start in each
/// of its `N` buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Head<H, const N: usize> {
    info: H,
    starts: [u32; N],
}

/// Panels in one arena: the buffers `B` and a small head per panel, keeping what `H`
/// holds of it beside its items and where they start in each of the `N` buffers. A
/// big job has millions of flat panels of a dozen points each; as separate
/// [`FlatPanel`]s they cost four allocations and a 184-byte struct apiece, more than
/// their points.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelArena<H, B, const N: usize> {
    heads: Vec<Head<H, N>>,
    buffers: B,
}

impl<H, B: Default, const N: usize> Default for PanelArena<H, B, N> {
    fn default() -> Self {
        PanelArena {
            heads: Vec::new(),
            buffers: B::default(),
        }
    }
}

impl<H: Copy, B: Buffers<N>, const N: usize> PanelArena<H, B, N> {
    /// No panels.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of panels.
    pub fn len(&self) -> usize {
        self.heads.len()
    }

    /// No panels at all.
    pub fn is_empty(&self) -> bool {
        self.heads.is_empty()
    }

    /// Gives back spare capacity (the arena is filled once and kept).
    pub fn shrink_to_fit(&mut self) {
        self.heads.shrink_to_fit();
        self.buffers.shrink_to_fit();
    }

    /// The panels in order.
    pub fn iter(&self) -> ArenaIter<'_, Self>
    where
        Self: Views,
    {
        ArenaIter::new(self)
    }

    /// Appends a panel's head and a copy of its items.
    ///
    /// # Panics
    /// When a buffer would pass 2³² items (about 100 GB of vertices alone).
    fn push_parts(&mut self, info: H, items: B::Slices<'_>) {
        let starts = self.buffers.lens();
        self.buffers.extend(items);
        // Checked after the copy: no buffer may pass what a u32 start can index.
        self.buffers.lens();
        self.heads.push(Head { info, starts });
    }

    /// Panel `i`'s head and items.
    ///
    /// # Panics
    /// When there is no panel `i`, as indexing does.
    fn parts(&self, i: usize) -> (H, B::Slices<'_>) {
        let head = self.heads[i];
        let end = self
            .heads
            .get(i + 1)
            .map_or_else(|| self.buffers.lens(), |next| next.starts);
        (head.info, self.buffers.slices(head.starts, end))
    }

    /// Appends `other`'s panels after these.
    fn join(&mut self, other: Self) {
        let offset = self.buffers.lens();
        self.buffers.append(&other.buffers);
        // Checked before the shift: no shifted start can pass the new lengths.
        self.buffers.lens();
        self.heads.extend(other.heads.iter().map(|head| Head {
            starts: std::array::from_fn(|k| head.starts[k] + offset[k]),
            ..*head
        }));
    }
}

/// What a [`Panels`] keeps of one panel beside its buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelInfo {
    source: Source,
    labels_dropped: LeftOut,
}

/// What a [`FlatPanels`] keeps of one panel beside its buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatInfo {
    source: Source,
    developability_error: f64,
    area: f64,
}

/// The 3D panels of a job, all in one arena, as [`FlatPanels`] keeps the flat ones.
/// Panels are handed out as [`PanelRef`]s.
pub type Panels = PanelArena<PanelInfo, PanelBuffers, 5>;

/// The flat panels of a job, all in one arena. Panels are handed out as
/// [`FlatPanelRef`]s.
pub type FlatPanels = PanelArena<FlatInfo, FlatBuffers, 6>;

/// The panels of a [`Panels`], in order.
pub type PanelsIter<'a> = ArenaIter<'a, Panels>;

/// The panels of a [`FlatPanels`], in order.
pub type FlatPanelsIter<'a> = ArenaIter<'a, FlatPanels>;

impl Panels {
    /// Panels `make(0)`, …, `make(count - 1)`, made in parallel a chunk at a time and
    /// stored in that order (so the thread count changes nothing).
    pub fn build(count: usize, make: impl Fn(usize) -> Panel + Sync) -> Self {
        let built: Result<Panels, std::convert::Infallible> = fill_arena(count, |i| Ok(make(i)));
        let Ok(mut all) = built;
        all.shrink_to_fit();
        all
    }

    /// Appends a copy of a panel.
    ///
    /// # Panics
    /// When a buffer would pass 2³² items (about 100 GB of vertices alone).
    pub fn push(&mut self, panel: PanelRef<'_>) {
        let info = PanelInfo {
            source: panel.source,
            labels_dropped: panel.labels_dropped,
        };
        self.push_parts(
            info,
            PanelSlices {
                vertices: panel.vertices,
                facet_indices: panel.facets.indices,
                facet_ends: panel.facets.ends,
                holes: panel.holes,
                labels: panel.labels,
            },
        );
    }

    /// Panel `i`.
    ///
    /// # Panics
    /// When there is no panel `i`, as indexing does.
    pub fn get(&self, i: usize) -> PanelRef<'_> {
        let (info, items) = self.parts(i);
        PanelRef {
            source: info.source,
            vertices: items.vertices,
            facets: LoopsRef {
                indices: items.facet_indices,
                ends: items.facet_ends,
            },
            holes: items.holes,
            labels: items.labels,
            labels_dropped: info.labels_dropped,
        }
    }
}

impl Views for Panels {
    type View<'a> = PanelRef<'a>;

    fn count(&self) -> usize {
        self.len()
    }

    fn view(&self, i: usize) -> PanelRef<'_> {
        self.get(i)
    }
}

impl Arena for Panels {
    type Made = Panel;

    fn take(&mut self, made: Panel) {
        self.push(made.view());
    }

    fn append(&mut self, other: Panels) {
        self.join(other);
    }
}

impl FromIterator<Panel> for Panels {
    fn from_iter<I: IntoIterator<Item = Panel>>(panels: I) -> Self {
        let mut all: Panels = collect_arena(panels);
        all.shrink_to_fit();
        all
    }
}

impl<'a> IntoIterator for &'a Panels {
    type Item = PanelRef<'a>;
    type IntoIter = PanelsIter<'a>;
    fn into_iter(self) -> PanelsIter<'a> {
        self.iter()
    }
}

impl FlatPanels {
    /// Appends a copy of a panel.
    ///
    /// # Panics
    /// When a buffer would pass 2³² items (about 70 GB of points alone).
    pub fn push(&mut self, panel: FlatPanelRef<'_>) {
        let info = FlatInfo {
            source: panel.source,
            developability_error: panel.developability_error,
            area: panel.area,
        };
        self.push_parts(
            info,
            FlatSlices {
                points: panel.points,
                loop_indices: panel.outline.indices,
                loop_ends: panel.outline.ends,
                folds: panel.folds,
                holes: panel.holes,
                labels: panel.labels,
            },
        );
    }

    /// Panel `i`.
    ///
    /// # Panics
    /// When there is no panel `i`, as indexing does.
    pub fn get(&self, i: usize) -> FlatPanelRef<'_> {
        let (info, items) = self.parts(i);
        FlatPanelRef {
            source: info.source,
            points: items.points,
            outline: LoopsRef {
                indices: items.loop_indices,
                ends: items.loop_ends,
            },
            folds: items.folds,
            holes: items.holes,
            labels: items.labels,
            developability_error: info.developability_error,
            area: info.area,
        }
    }
}

impl<'a> IntoIterator for &'a FlatPanels {
    type Item = FlatPanelRef<'a>;
    type IntoIter = FlatPanelsIter<'a>;
    fn into_iter(self) -> FlatPanelsIter<'a> {
        self.iter()
    }
}

impl Views for FlatPanels {
    type View<'a> = FlatPanelRef<'a>;

    fn count(&self) -> usize {
        self.len()
    }

    fn view(&self, i: usize) -> FlatPanelRef<'_> {
        self.get(i)
    }
}

/// Flat panels gathered with a tally of something about each (labels left out,
/// narrow places), summed as [`fill_arena`] gathers them.
#[derive(Default)]
pub struct Tallied<T> {
    /// The panels, in order.
    pub panels: FlatPanels,
    /// The sum of their tallies.
    pub tally: T,
}

impl<T: Default + Send + std::ops::Add<Output = T>> Arena for Tallied<T> {
    type Made = (FlatPanel, T);

    fn take(&mut self, (panel, tally): (FlatPanel, T)) {
        self.panels.take(panel);
        self.tally = std::mem::take(&mut self.tally) + tally;
    }

    fn append(&mut self, other: Tallied<T>) {
        self.panels.append(other.panels);
        self.tally = std::mem::take(&mut self.tally) + other.tally;
    }
}

impl Arena for FlatPanels {
    type Made = FlatPanel;

    fn take(&mut self, made: FlatPanel) {
        self.push(made.view());
    }

    fn append(&mut self, other: FlatPanels) {
        self.join(other);
    }
}

impl FromIterator<FlatPanel> for FlatPanels {
    fn from_iter<I: IntoIterator<Item = FlatPanel>>(panels: I) -> Self {
        let mut all: FlatPanels = collect_arena(panels);
        all.shrink_to_fit();
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::arena::CHUNK;
    use crate::panel::label::LabelKind;
    use crate::panel::loops::Loops;
    use crate::panel::shape::FoldKind;
    use crate::panel::source::Name;

    /// A panel of `k + 1` triangles fanned around vertex 0, with `k % 3` holes and
    /// `k % 2` labels: panels of different sizes, some with nothing of a kind.
    fn fan(k: u32) -> Panel {
        let vertices: Vec<DVec3> = (0..k + 3)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, k as f64))
            .collect();
        let facets: Loops = (0..=k).map(|i| [0, i + 1, i + 2]).collect();
        let holes = (0..k % 3)
            .map(|i| Hole {
                position: DVec3::splat(i as f64),
                diameter: 3.0,
                connection: k + i,
                facet: i,
            })
            .collect();
        let labels = (0..k % 2)
            .map(|_| Label {
                text: Name::edge(k),
                anchor: DVec3::ZERO,
                direction: DVec3::X,
                height: 0.0,
                facet: 0,
                kind: LabelKind::Panel,
                on_edge: false,
                slide: 0.0,
            })
            .collect();
        Panel {
            source: Source::edge(k),
            vertices,
            facets,
            holes,
            labels,
            labels_dropped: LeftOut {
                panel: k as usize,
                partner: 0,
                mark: 1,
            },
        }
    }

    /// The flat counterpart of [`fan`]: points, an outline with an inner loop on odd
    /// panels, folds on every other.
    fn flat_fan(k: u32) -> FlatPanel {
        let panel = fan(k);
        let mut outline = Loops::new();
        outline.push(0..k + 3);
        if k % 2 == 1 {
            outline.push([2, 1, 0]);
        }
        FlatPanel {
            source: panel.source,
            points: panel.vertices.iter().map(|v| v.truncate()).collect(),
            outline,
            folds: (0..k % 2)
                .map(|i| Fold {
                    ends: [0, i + 2],
                    kind: FoldKind::Valley,
                })
                .collect(),
            holes: (0..k % 3)
                .map(|i| FlatHole {
                    center: DVec2::splat(i as f64),
                    diameter: 3.0,
                    connection: k + i,
                    facet: i,
                })
                .collect(),
            labels: Vec::new(),
            developability_error: 1e-12 * k as f64,
            area: k as f64,
        }
    }

    #[test]
    fn arenas_hand_back_every_panel_as_it_went_in() {
        let owned: Vec<Panel> = (0..7).map(fan).collect();
        let arena: Panels = owned.iter().cloned().collect();
        assert_eq!(arena.len(), 7);
        for (k, (got, want)) in arena.iter().zip(&owned).enumerate() {
            assert_eq!(got, want.view(), "panel {k}");
            assert_eq!(&got.to_panel(), want, "panel {k}");
            assert_eq!(got.facets.len(), k + 1);
        }
        assert_eq!(
            arena.iter().next_back().map(|p| p.id()),
            Some(Name::edge(6))
        );

        let flat_owned: Vec<FlatPanel> = (0..7).map(flat_fan).collect();
        let flat: FlatPanels = flat_owned.iter().cloned().collect();
        assert_eq!(flat.len(), 7);
        for (k, (got, want)) in flat.iter().zip(&flat_owned).enumerate() {
            assert_eq!(got, want.view(), "flat panel {k}");
            assert_eq!(&got.to_flat_panel(), want, "flat panel {k}");
            assert_eq!(got.outer(), want.outer());
            assert_eq!(got.outline.len(), 1 + k % 2);
        }
        assert!(Panels::new().is_empty() && FlatPanels::new().is_empty());
        // What a panel costs beside its items, against an owned panel's struct (the
        // figures in docs/DESIGN.md).
        assert_eq!(std::mem::size_of::<Head<PanelInfo, 5>>(), 72);
        assert_eq!(std::mem::size_of::<Head<FlatInfo, 6>>(), 64);
        assert_eq!(std::mem::size_of::<Panel>(), 168);
        assert_eq!(std::mem::size_of::<FlatPanel>(), 184);
    }

    #[test]
    fn built_arenas_keep_the_order_across_chunks() {
        // More than two chunks, so the order is kept where chunks meet.
        let count = 2 * CHUNK + 5;
        let arena = Panels::build(count, |i| fan(i as u32 % 5));
        assert_eq!(arena.len(), count);
        for (i, panel) in arena.iter().enumerate() {
            assert_eq!(panel, fan(i as u32 % 5).view(), "panel {i}");
        }
        let flat: Result<FlatPanels, ()> = fill_arena(count, |i| Ok(flat_fan(i as u32 % 7)));
        let flat = flat.expect("no errors");
        assert_eq!(flat.len(), count);
        for (i, panel) in flat.iter().enumerate() {
            assert_eq!(panel, flat_fan(i as u32 % 7).view(), "flat panel {i}");
        }
        // The first error in order wins, whichever worker met it first.
        let fails_late = |i: usize| i % 1000 == 999 && i > CHUNK;
        let failed: Result<Panels, usize> =
            fill_arena(count, |i| if fails_late(i) { Err(i) } else { Ok(fan(0)) });
        assert_eq!(failed.err(), Some(16_999));
    }
}
