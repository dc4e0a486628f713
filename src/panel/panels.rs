//! A job's panels, 3D ([`Panels`]) and flat ([`FlatPanels`]), each in one arena: one
//! buffer per kind of item and a small head per panel saying where its items start.
//! The two arenas are laid out alike, side by side here, each knowing its own fields.

use glam::{DVec2, DVec3};

use super::arena::{arena_len, collect_arena, fill_arena, Arena, ArenaIter, Views};
use super::label::{Label, LeftOut};
use super::loops::LoopsRef;
use super::shape::{FlatHole, FlatLabel, FlatPanel, FlatPanelRef, Fold, Hole, Panel, PanelRef};
use super::source::Source;

/// Where one panel's items start in each buffer of a [`Panels`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct PanelStarts {
    vertices: u32,
    facet_indices: u32,
    facet_ends: u32,
    holes: u32,
    labels: u32,
}

/// What a [`Panels`] keeps of one panel beside its buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PanelHead {
    source: Source,
    starts: PanelStarts,
    labels_dropped: LeftOut,
}

/// The 3D panels of a job, all in one arena, as [`FlatPanels`] keeps the flat ones:
/// one buffer per kind of item and a small head per panel. Panels are handed out as
/// [`PanelRef`]s.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Panels {
    heads: Vec<PanelHead>,
    vertices: Vec<DVec3>,
    facet_indices: Vec<u32>,
    facet_ends: Vec<u32>,
    holes: Vec<Hole>,
    labels: Vec<Label>,
}

/// The panels of a [`Panels`], in order.
pub type PanelsIter<'a> = ArenaIter<'a, Panels>;

/// The panels of a [`FlatPanels`], in order.
pub type FlatPanelsIter<'a> = ArenaIter<'a, FlatPanels>;

impl Panels {
    /// No panels.
    pub fn new() -> Self {
        Self::default()
    }

    /// Panels `make(0)`, …, `make(count - 1)`, made in parallel a chunk at a time and
    /// stored in that order (so the thread count changes nothing).
    pub fn build(count: usize, make: impl Fn(usize) -> Panel + Sync) -> Self {
        let built: Result<Panels, std::convert::Infallible> = fill_arena(count, |i| Ok(make(i)));
        let Ok(mut all) = built;
        all.shrink_to_fit();
        all
    }

    /// Number of panels.
    pub fn len(&self) -> usize {
        self.heads.len()
    }

    /// No panels at all.
    pub fn is_empty(&self) -> bool {
        self.heads.is_empty()
    }

    /// Appends a copy of a panel.
    ///
    /// # Panics
    /// When a buffer would pass 2³² items (about 100 GB of vertices alone).
    pub fn push(&mut self, panel: PanelRef<'_>) {
        let starts = self.lens();
        self.vertices.extend_from_slice(panel.vertices);
        self.facet_indices.extend_from_slice(panel.facets.indices);
        self.facet_ends.extend_from_slice(panel.facets.ends);
        self.holes.extend_from_slice(panel.holes);
        self.labels.extend_from_slice(panel.labels);
        self.lens();
        self.heads.push(PanelHead {
            source: panel.source,
            starts,
            labels_dropped: panel.labels_dropped,
        });
    }

    /// The length of every buffer: where the next panel's items start.
    ///
    /// # Panics
    /// When a buffer has passed 2³² items.
    fn lens(&self) -> PanelStarts {
        PanelStarts {
            vertices: arena_len(self.vertices.len()),
            facet_indices: arena_len(self.facet_indices.len()),
            facet_ends: arena_len(self.facet_ends.len()),
            holes: arena_len(self.holes.len()),
            labels: arena_len(self.labels.len()),
        }
    }

    /// Gives back spare capacity (the arena is filled once and kept).
    pub fn shrink_to_fit(&mut self) {
        self.heads.shrink_to_fit();
        self.vertices.shrink_to_fit();
        self.facet_indices.shrink_to_fit();
        self.facet_ends.shrink_to_fit();
        self.holes.shrink_to_fit();
        self.labels.shrink_to_fit();
    }

    /// Panel `i`.
    ///
    /// # Panics
    /// When there is no panel `i`, as indexing does.
    pub fn get(&self, i: usize) -> PanelRef<'_> {
        let head = &self.heads[i];
        let start = head.starts;
        let end = self
            .heads
            .get(i + 1)
            .map_or_else(|| self.lens(), |next| next.starts);
        let range = |a: u32, b: u32| a as usize..b as usize;
        PanelRef {
            source: head.source,
            vertices: &self.vertices[range(start.vertices, end.vertices)],
            facets: LoopsRef {
                indices: &self.facet_indices[range(start.facet_indices, end.facet_indices)],
                ends: &self.facet_ends[range(start.facet_ends, end.facet_ends)],
            },
            holes: &self.holes[range(start.holes, end.holes)],
            labels: &self.labels[range(start.labels, end.labels)],
            labels_dropped: head.labels_dropped,
        }
    }

    /// The panels in order.
    pub fn iter(&self) -> PanelsIter<'_> {
        ArenaIter::new(self)
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
        let offset = self.lens();
        self.vertices.extend_from_slice(&other.vertices);
        self.facet_indices.extend_from_slice(&other.facet_indices);
        self.facet_ends.extend_from_slice(&other.facet_ends);
        self.holes.extend_from_slice(&other.holes);
        self.labels.extend_from_slice(&other.labels);
        // Checked before the shift: no shifted start can pass the new lengths.
        self.lens();
        self.heads.extend(other.heads.iter().map(|head| {
            let s = head.starts;
            PanelHead {
                starts: PanelStarts {
                    vertices: s.vertices + offset.vertices,
                    facet_indices: s.facet_indices + offset.facet_indices,
                    facet_ends: s.facet_ends + offset.facet_ends,
                    holes: s.holes + offset.holes,
                    labels: s.labels + offset.labels,
                },
                ..*head
            }
        }));
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

/// Where one panel's items start in each buffer of a [`FlatPanels`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct FlatStarts {
    points: u32,
    loop_indices: u32,
    loop_ends: u32,
    folds: u32,
    holes: u32,
    labels: u32,
}

/// What a [`FlatPanels`] keeps of one panel beside its buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FlatHead {
    source: Source,
    starts: FlatStarts,
    developability_error: f64,
    area: f64,
}

/// The flat panels of a job, all in one arena: one buffer per kind of item (points,
/// outline indices, folds, holes, labels) and a small head per panel saying where
/// its items start. A big job has millions of flat panels of a dozen points each; as
/// separate [`FlatPanel`]s they cost four allocations and a 176-byte struct apiece,
/// more than their points. Panels are handed out as [`FlatPanelRef`]s.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatPanels {
    heads: Vec<FlatHead>,
    points: Vec<DVec2>,
    loop_indices: Vec<u32>,
    loop_ends: Vec<u32>,
    folds: Vec<Fold>,
    holes: Vec<FlatHole>,
    labels: Vec<FlatLabel>,
}

impl FlatPanels {
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

    /// Appends a copy of a panel.
    ///
    /// # Panics
    /// When a buffer would pass 2³² items (about 70 GB of points alone).
    pub fn push(&mut self, panel: FlatPanelRef<'_>) {
        let starts = self.lens();
        self.points.extend_from_slice(panel.points);
        self.loop_indices.extend_from_slice(panel.outline.indices);
        self.loop_ends.extend_from_slice(panel.outline.ends);
        self.folds.extend_from_slice(panel.folds);
        self.holes.extend_from_slice(panel.holes);
        self.labels.extend_from_slice(panel.labels);
        self.lens();
        self.heads.push(FlatHead {
            source: panel.source,
            starts,
            developability_error: panel.developability_error,
            area: panel.area,
        });
    }

    /// The length of every buffer: where the next panel's items start.
    ///
    /// # Panics
    /// When a buffer has passed 2³² items.
    fn lens(&self) -> FlatStarts {
        FlatStarts {
            points: arena_len(self.points.len()),
            loop_indices: arena_len(self.loop_indices.len()),
            loop_ends: arena_len(self.loop_ends.len()),
            folds: arena_len(self.folds.len()),
            holes: arena_len(self.holes.len()),
            labels: arena_len(self.labels.len()),
        }
    }

    /// Gives back spare capacity (the arena is filled once and kept).
    pub fn shrink_to_fit(&mut self) {
        self.heads.shrink_to_fit();
        self.points.shrink_to_fit();
        self.loop_indices.shrink_to_fit();
        self.loop_ends.shrink_to_fit();
        self.folds.shrink_to_fit();
        self.holes.shrink_to_fit();
        self.labels.shrink_to_fit();
    }

    /// Panel `i`.
    ///
    /// # Panics
    /// When there is no panel `i`, as indexing does.
    pub fn get(&self, i: usize) -> FlatPanelRef<'_> {
        let head = &self.heads[i];
        let start = head.starts;
        let end = self
            .heads
            .get(i + 1)
            .map_or_else(|| self.lens(), |next| next.starts);
        let range = |a: u32, b: u32| a as usize..b as usize;
        FlatPanelRef {
            source: head.source,
            points: &self.points[range(start.points, end.points)],
            outline: LoopsRef {
                indices: &self.loop_indices[range(start.loop_indices, end.loop_indices)],
                ends: &self.loop_ends[range(start.loop_ends, end.loop_ends)],
            },
            folds: &self.folds[range(start.folds, end.folds)],
            holes: &self.holes[range(start.holes, end.holes)],
            labels: &self.labels[range(start.labels, end.labels)],
            developability_error: head.developability_error,
            area: head.area,
        }
    }

    /// The panels in order.
    pub fn iter(&self) -> FlatPanelsIter<'_> {
        ArenaIter::new(self)
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
        let offset = self.lens();
        self.points.extend_from_slice(&other.points);
        self.loop_indices.extend_from_slice(&other.loop_indices);
        self.loop_ends.extend_from_slice(&other.loop_ends);
        self.folds.extend_from_slice(&other.folds);
        self.holes.extend_from_slice(&other.holes);
        self.labels.extend_from_slice(&other.labels);
        // Checked before the shift: no shifted start can pass the new lengths.
        self.lens();
        self.heads.extend(other.heads.iter().map(|head| {
            let s = head.starts;
            FlatHead {
                starts: FlatStarts {
                    points: s.points + offset.points,
                    loop_indices: s.loop_indices + offset.loop_indices,
                    loop_ends: s.loop_ends + offset.loop_ends,
                    folds: s.folds + offset.folds,
                    holes: s.holes + offset.holes,
                    labels: s.labels + offset.labels,
                },
                ..*head
            }
        }));
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
        assert_eq!(std::mem::size_of::<PanelHead>(), 72);
        assert_eq!(std::mem::size_of::<FlatHead>(), 64);
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
