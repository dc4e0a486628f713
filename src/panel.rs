//! 3D panels and flat panels.
//!
//! A panel is a small polygon mesh of planar facets (3D polygons) with shared corner
//! vertices. An edge shared by two facets is a hinge (a fold, scored when its fold angle
//! is not zero); an edge of one facet only is part of the cut outline. Every scheme
//! produces panels in this form, so one unroller and one exporter serve them all.

use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::font::text_width;
use crate::mesh::geometry::vector_area;

mod arena;
pub mod surface;

use arena::{arena_len, collect_arena};
pub use arena::{fill_arena, Arena, ArenaIter, Views};

/// A kind of printed id: its letter, what the map legend says of it, and the manifest
/// fields of a panel so named. The kinds every scheme may use (faces, edges, vertices)
/// are defined here; a scheme that makes its own kind of panel or mark defines its own
/// as a `static` beside it, and labels, the map and the manifest read it as they read
/// these.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct IdKind {
    /// Printed before the number (`F`, `E`); empty for a bare number.
    pub letter: &'static str,
    /// What the map legend says an id of this kind is ("edge panel").
    pub legend: &'static str,
    /// The manifest field of a panel's number (`face` in `"face": 12`).
    pub noun: &'static str,
    /// The manifest field of a panel's part number, for ids with one (`C3.2`).
    pub part_noun: &'static str,
    /// The manifest's `layer` of a panel so named (`outer`, `inner`), or empty.
    pub layer: &'static str,
}

/// Faces: `F12`, a face panel's id or a face mark.
pub static FACE: IdKind = IdKind {
    letter: "F",
    legend: "face (a face panel, or the mark of a face)",
    noun: "face",
    part_noun: "",
    layer: "",
};

/// Edges: `E123`, an edge panel's id.
pub static EDGE: IdKind = IdKind {
    letter: "E",
    legend: "edge panel",
    noun: "edge",
    part_noun: "",
    layer: "",
};

/// Vertices: `V7`, a corner mark.
pub static VERTEX: IdKind = IdKind {
    letter: "V",
    legend: "vertex mark",
    noun: "vertex",
    part_noun: "",
    layer: "",
};

/// A printed name: a panel's id, or what a label says: a kind's letter, a number and,
/// for a part of a numbered whole, the part's number (`C3.2`). Kept as numbers and
/// printed on demand, so a million panels carry no strings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Name {
    /// What it names.
    pub kind: &'static IdKind,
    /// Its number.
    pub number: u32,
    /// The part's number (from 1), or 0 for a name without one.
    pub part: u32,
}

impl Name {
    /// The name `number` of `kind`.
    pub const fn new(kind: &'static IdKind, number: u32) -> Name {
        Name {
            kind,
            number,
            part: 0,
        }
    }

    /// Part `part` (from 1) of `number` of `kind`.
    pub const fn with_part(kind: &'static IdKind, number: u32, part: u32) -> Name {
        Name { kind, number, part }
    }

    /// Face `k`: `F12`.
    pub const fn face(k: u32) -> Name {
        Name::new(&FACE, k)
    }

    /// Edge `k`: `E123`.
    pub const fn edge(k: u32) -> Name {
        Name::new(&EDGE, k)
    }

    /// Vertex `k`: `V7`.
    pub const fn vertex(k: u32) -> Name {
        Name::new(&VERTEX, k)
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}{}", self.kind.letter, self.number)?;
        if self.part > 0 {
            write!(f, ".{}", self.part)?;
        }
        Ok(())
    }
}

/// What of the model a panel covers: the map draws it there and writes the panel's id
/// at its anchor, and the manifest lists the mesh elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Covers {
    /// One face, whole; the id at its centre.
    Face(u32),
    /// One edge: the two triangles between the edge and the centres of its faces (the
    /// edge panels of a face share it like the slices of a cake); the id at the edge's
    /// midpoint.
    Edge(u32),
    /// A group of faces, entry k of the scheme output's `face_groups`; the id at the
    /// group's anchor.
    Faces(u32),
    /// The panel's own facets, which lie over the surface (a ribbon); the id at the
    /// centre of its middle facet.
    Itself,
    /// No surface: a part inside the model at an edge (a bracket), which the map leaves
    /// out; its id names the edge.
    Inside(u32),
}

/// The faces a panel covers when it covers a group of them ([`Covers::Faces`]), and
/// where the map shows its id: the scheme's choice (for example
/// [`surface::group_anchor`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceGroup {
    /// The mesh faces, in increasing order.
    pub faces: Vec<u32>,
    /// Where its id shows on the map (mm).
    pub anchor: DVec3,
}

/// Where a panel comes from: its printed id and what of the model it covers. A scheme
/// writes it; flattening, the map and the manifest read it without knowing the scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source {
    /// The id printed for users.
    pub id: Name,
    /// What of the model it covers.
    pub covers: Covers,
}

impl Source {
    /// The panel of face `f`, named `F<f>`.
    pub const fn face(f: u32) -> Source {
        Source {
            id: Name::face(f),
            covers: Covers::Face(f),
        }
    }

    /// The panel of edge `e`, named `E<e>`.
    pub const fn edge(e: u32) -> Source {
        Source {
            id: Name::edge(e),
            covers: Covers::Edge(e),
        }
    }
}

/// A fastener hole: a circle at a 3D point on one facet, shared with the partner panel
/// of its connection (the partner has a hole at the same 3D point).
#[derive(Clone, Debug, PartialEq)]
pub struct Hole {
    /// Centre in 3D (mm).
    pub position: DVec3,
    /// Diameter (mm).
    pub diameter: f64,
    /// The connection it serves.
    pub connection: u32,
    /// The facet it goes through.
    pub facet: u32,
}

/// What a label says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LabelKind {
    /// The panel's own id.
    Panel,
    /// The id of the partner panel at a connection.
    Partner,
    /// Extra assembly marks: vertex and face ids (thesis software style).
    Mark,
}

impl LabelKind {
    /// Every kind, in fitting order.
    pub const ALL: [LabelKind; 3] = [LabelKind::Panel, LabelKind::Partner, LabelKind::Mark];
}

/// An engraved text: anchored at the centre of its text box, or, for `on_edge` labels,
/// at a point on the facet's edge with the box pushed inside along the left normal of
/// `direction` (so it sits just inside that edge whatever its final height).
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// What it says.
    pub text: Name,
    /// Anchor (mm).
    pub anchor: DVec3,
    /// Reading direction (unit, in the facet's plane).
    pub direction: DVec3,
    /// Wanted cap height (mm); fitting may shrink it.
    pub height: f64,
    /// Facet the label is engraved on.
    pub facet: u32,
    /// Panel id or partner id.
    pub kind: LabelKind,
    /// Anchored on an edge (see the type's doc).
    pub on_edge: bool,
    /// How far (mm) the anchor may slide along `direction` either way to find room
    /// (0: fixed).
    pub slide: f64,
}

/// Index loops (a panel's facets, a flat panel's cut loops) in one buffer. A panel has
/// a handful of short loops and a big job has millions of panels: one allocation per
/// loop would cost more memory than the indices themselves.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Loops {
    /// Every loop's indices, one loop after the other.
    indices: Vec<u32>,
    /// Where each loop ends in `indices`.
    ends: Vec<u32>,
}

impl Loops {
    /// No loops.
    pub fn new() -> Self {
        Self::default()
    }

    /// No loops, with room for `loops` loops of `indices` indices in all.
    pub fn with_capacity(loops: usize, indices: usize) -> Self {
        Loops {
            indices: Vec::with_capacity(indices),
            ends: Vec::with_capacity(loops),
        }
    }

    /// Appends a loop.
    pub fn push(&mut self, lp: impl IntoIterator<Item = u32>) {
        self.indices.extend(lp);
        self.ends.push(self.indices.len() as u32);
    }

    /// The same loops, borrowed.
    pub fn view(&self) -> LoopsRef<'_> {
        LoopsRef {
            indices: &self.indices,
            ends: &self.ends,
        }
    }

    /// Number of loops.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// No loops at all.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Loop `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&[u32]> {
        self.view().get(k)
    }

    /// The first loop.
    pub fn first(&self) -> Option<&[u32]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> LoopsIter<'_> {
        self.view().iter()
    }

    /// Indices in all loops together.
    pub fn index_count(&self) -> usize {
        self.indices.len()
    }
}

impl std::ops::Index<usize> for Loops {
    type Output = [u32];
    fn index(&self, k: usize) -> &[u32] {
        self.view().loop_at(k)
    }
}

/// Loops kept in buffers owned elsewhere: a [`Loops`] borrowed, or one panel's loops
/// in a [`FlatPanels`] arena. `ends` count from the start of `indices`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopsRef<'a> {
    indices: &'a [u32],
    ends: &'a [u32],
}

impl<'a> LoopsRef<'a> {
    /// Number of loops.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// No loops at all.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Loop `k`, if there is one.
    pub fn get(&self, k: usize) -> Option<&'a [u32]> {
        let end = *self.ends.get(k)? as usize;
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        Some(&self.indices[start..end])
    }

    /// The first loop.
    pub fn first(&self) -> Option<&'a [u32]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> LoopsIter<'a> {
        LoopsIter {
            loops: *self,
            range: 0..self.len(),
        }
    }

    /// Indices in all loops together.
    pub fn index_count(&self) -> usize {
        self.indices.len()
    }

    /// Loop `k`; panics when there is none, as indexing does.
    fn loop_at(&self, k: usize) -> &'a [u32] {
        self.get(k)
            .unwrap_or_else(|| panic!("loop {k} of {}", self.len()))
    }
}

impl std::ops::Index<usize> for LoopsRef<'_> {
    type Output = [u32];
    fn index(&self, k: usize) -> &[u32] {
        self.loop_at(k)
    }
}

impl<'a> IntoIterator for &LoopsRef<'a> {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

impl<'a> IntoIterator for LoopsRef<'a> {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

/// The loops of a [`Loops`] or [`LoopsRef`], in order.
#[derive(Clone, Debug)]
pub struct LoopsIter<'a> {
    loops: LoopsRef<'a>,
    range: std::ops::Range<usize>,
}

impl<'a> Iterator for LoopsIter<'a> {
    type Item = &'a [u32];
    fn next(&mut self) -> Option<&'a [u32]> {
        self.range.next().map(|k| self.loops.loop_at(k))
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.range.size_hint()
    }
}

impl DoubleEndedIterator for LoopsIter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        self.range.next_back().map(|k| self.loops.loop_at(k))
    }
}

impl ExactSizeIterator for LoopsIter<'_> {}

impl<'a> IntoIterator for &'a Loops {
    type Item = &'a [u32];
    type IntoIter = LoopsIter<'a>;
    fn into_iter(self) -> LoopsIter<'a> {
        self.iter()
    }
}

impl<L: IntoIterator<Item = u32>> FromIterator<L> for Loops {
    fn from_iter<I: IntoIterator<Item = L>>(loops: I) -> Self {
        let mut all = Loops::new();
        for lp in loops {
            all.push(lp);
        }
        all
    }
}

/// A panel in 3D, as it sits in the assembled model (millimetres).
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Provenance (and so the printed id).
    pub source: Source,
    /// Corner positions shared by the facets.
    pub vertices: Vec<DVec3>,
    /// Planar facets as vertex index loops, counter-clockwise seen from the outside.
    pub facets: Loops,
    /// Fastener holes.
    pub holes: Vec<Hole>,
    /// Labels that may fit (see [`Panel::new`]).
    pub labels: Vec<Label>,
    /// The labels the scheme wanted that cannot fit on any facet at a legible height,
    /// dropped when the panel was made; label fitting counts them as left out.
    pub labels_dropped: LeftOut,
}

impl Panel {
    /// A panel from its parts. Labels whose text box at the smallest legible height
    /// has more area than any facet they may go on are dropped here (and counted): at
    /// a million panels they would take more memory than the panels' geometry, and
    /// fitting would leave them out anyway. (Spare capacity is not trimmed: a job's
    /// panels are copied into a [`Panels`] arena as they are made.)
    pub fn new(
        source: Source,
        vertices: Vec<DVec3>,
        facets: Loops,
        holes: Vec<Hole>,
        mut labels: Vec<Label>,
    ) -> Self {
        let labels_dropped = drop_unfittable(&vertices, facets.view(), &mut labels);
        Panel {
            source,
            vertices,
            facets,
            holes,
            labels,
            labels_dropped,
        }
    }

    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn id(&self) -> Name {
        self.source.id
    }

    /// The same panel, borrowed as the arena hands panels out.
    pub fn view(&self) -> PanelRef<'_> {
        PanelRef {
            source: self.source,
            vertices: &self.vertices,
            facets: self.facets.view(),
            holes: &self.holes,
            labels: &self.labels,
            labels_dropped: self.labels_dropped,
        }
    }
}

/// A 3D panel borrowed from a [`Panels`] arena (or from a [`Panel`]): the same
/// fields, as slices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelRef<'a> {
    /// Provenance (and so the printed id).
    pub source: Source,
    /// Corner positions shared by the facets.
    pub vertices: &'a [DVec3],
    /// Planar facets as vertex index loops, counter-clockwise seen from the outside.
    pub facets: LoopsRef<'a>,
    /// Fastener holes.
    pub holes: &'a [Hole],
    /// Labels that may fit.
    pub labels: &'a [Label],
    /// Labels dropped when the panel was made (see [`Panel::labels_dropped`]).
    pub labels_dropped: LeftOut,
}

impl<'a> From<&'a Panel> for PanelRef<'a> {
    fn from(panel: &'a Panel) -> Self {
        panel.view()
    }
}

impl PanelRef<'_> {
    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn id(&self) -> Name {
        self.source.id
    }

    /// An owned copy.
    pub fn to_panel(&self) -> Panel {
        Panel {
            source: self.source,
            vertices: self.vertices.to_vec(),
            facets: self.facets.iter().map(|f| f.iter().copied()).collect(),
            holes: self.holes.to_vec(),
            labels: self.labels.to_vec(),
            labels_dropped: self.labels_dropped,
        }
    }
}

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

/// The isometry between a facet's plane in 3D and its place in the flat panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacetFrame {
    /// A point of the facet in 3D.
    pub origin3: DVec3,
    /// Unit x axis in 3D (in the facet plane).
    pub x3: DVec3,
    /// Unit y axis in 3D (in the facet plane, normal × x).
    pub y3: DVec3,
    /// Where `origin3` lies in the plane.
    pub origin2: DVec2,
    /// Unit x axis in the plane.
    pub x2: DVec2,
}

impl FacetFrame {
    /// The frame of a facet with unit normal `normal` whose edge `pa → pb` (3D) lies
    /// on `qa → qb` in the plane (the same length). The x axis is the edge projected
    /// into the facet's plane, so the frame is orthonormal even for a facet that is only
    /// nearly planar, and `to_3d(to_2d(p))` is the projection of p onto that plane.
    pub fn on_hinge(pa: DVec3, pb: DVec3, normal: DVec3, qa: DVec2, qb: DVec2) -> Self {
        let edge = pb - pa;
        let x3 = (edge - edge.dot(normal) * normal).normalize();
        FacetFrame {
            origin3: pa,
            x3,
            y3: normal.cross(x3),
            origin2: qa,
            x2: (qb - qa).normalize(),
        }
    }

    /// The y axis in the plane (x rotated by +90°: the unrolling keeps orientation).
    pub fn y2(&self) -> DVec2 {
        self.x2.perp()
    }

    /// A 3D point of the facet's plane, in the flat panel.
    pub fn to_2d(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin3;
        self.origin2 + d.dot(self.x3) * self.x2 + d.dot(self.y3) * self.y2()
    }

    /// A point of the flat panel, back on the facet in 3D.
    pub fn to_3d(&self, q: DVec2) -> DVec3 {
        let d = q - self.origin2;
        self.origin3 + d.dot(self.x2) * self.x3 + d.dot(self.y2()) * self.y3
    }

    /// A 3D direction in the facet plane, in the flat panel.
    pub fn direction_to_2d(&self, v: DVec3) -> DVec2 {
        v.dot(self.x3) * self.x2 + v.dot(self.y3) * self.y2()
    }
}

/// Which way a fold bends, seen from the outside of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FoldKind {
    /// The crease points out of the model (a convex edge): a ridge seen from outside.
    Mountain,
    /// The crease points into the model (a concave edge): a trough seen from outside.
    Valley,
}

impl FoldKind {
    /// The fold between two faces wound counter-clockwise seen from outside, with
    /// normals `nf` and `ng`, along an edge that runs `along` in the first: the
    /// normals turn about the edge the positive way exactly when it is convex.
    pub fn between(nf: DVec3, ng: DVec3, along: DVec3) -> FoldKind {
        if nf.cross(ng).dot(along) > 0.0 {
            FoldKind::Mountain
        } else {
            FoldKind::Valley
        }
    }
}

/// A fold line to score: a hinge between two facets that are not coplanar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fold {
    /// Its two ends (indices into the flat panel's points).
    pub ends: [u32; 2],
    /// Mountain or valley, seen from the outside.
    pub kind: FoldKind,
}

/// A hole in the flat panel.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatHole {
    /// Centre (mm, panel coordinates).
    pub center: DVec2,
    /// Diameter (mm).
    pub diameter: f64,
    /// The connection it serves.
    pub connection: u32,
    /// The facet it goes through.
    pub facet: u32,
}

/// A label in the flat panel, after fitting.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatLabel {
    /// What it says.
    pub text: Name,
    /// Centre of the text box.
    pub center: DVec2,
    /// Unit reading direction.
    pub direction: DVec2,
    /// Cap height (mm).
    pub height: f64,
    /// Panel id or partner id.
    pub kind: LabelKind,
    /// How far the frame engraved round it stands off its text, in cap heights (a
    /// panel's own id); 0: no frame.
    pub frame: f64,
}

/// A panel unrolled into the plane, outside face up (its facets counter-clockwise).
/// Its points have the 3D panel's vertex indices (so the 3D panel's facets index them)
/// and its holes are the 3D panel's, in order: that is its map back to 3D, and
/// [`crate::flatten::facet_frames`] gives the isometry of each facet for any other
/// point.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatPanel {
    /// Provenance (and so the printed id).
    pub source: Source,
    /// Corner positions in the plane (same indices as the 3D panel's vertices).
    pub points: Vec<DVec2>,
    /// Cut loops: the outer outline first (counter-clockwise), then inner cuts
    /// (clockwise).
    pub outline: Loops,
    /// Fold lines to score (hinges with a non-zero fold angle).
    pub folds: Vec<Fold>,
    /// Fastener holes.
    pub holes: Vec<FlatHole>,
    /// Labels after fitting.
    pub labels: Vec<FlatLabel>,
    /// Largest change of a facet edge length between 3D and the plane (mm).
    pub developability_error: f64,
    /// Area of the facets in the plane (mm²), holes not subtracted.
    pub area: f64,
}

impl FlatPanel {
    /// The same panel, borrowed as the arena hands panels out.
    pub fn view(&self) -> FlatPanelRef<'_> {
        FlatPanelRef {
            source: self.source,
            points: &self.points,
            outline: self.outline.view(),
            folds: &self.folds,
            holes: &self.holes,
            labels: &self.labels,
            developability_error: self.developability_error,
            area: self.area,
        }
    }

    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn id(&self) -> Name {
        self.source.id
    }

    /// The points of an outline loop.
    pub fn loop_points(&self, lp: &[u32]) -> Vec<DVec2> {
        self.view().loop_points(lp)
    }

    /// The outer outline's points.
    pub fn outer(&self) -> Vec<DVec2> {
        self.view().outer()
    }
}

/// A flat panel borrowed from a [`FlatPanels`] arena (or from a [`FlatPanel`]): the
/// same fields, as slices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatPanelRef<'a> {
    /// Provenance (and so the printed id).
    pub source: Source,
    /// Corner positions in the plane (same indices as the 3D panel's vertices).
    pub points: &'a [DVec2],
    /// Cut loops: the outer outline first (counter-clockwise), then inner cuts
    /// (clockwise).
    pub outline: LoopsRef<'a>,
    /// Fold lines to score.
    pub folds: &'a [Fold],
    /// Fastener holes.
    pub holes: &'a [FlatHole],
    /// Labels after fitting.
    pub labels: &'a [FlatLabel],
    /// Largest change of a facet edge length between 3D and the plane (mm).
    pub developability_error: f64,
    /// Area of the facets in the plane (mm²), holes not subtracted.
    pub area: f64,
}

impl FlatPanelRef<'_> {
    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn id(&self) -> Name {
        self.source.id
    }

    /// The points of an outline loop.
    pub fn loop_points(&self, lp: &[u32]) -> Vec<DVec2> {
        lp.iter().map(|&i| self.points[i as usize]).collect()
    }

    /// The outer outline's points.
    pub fn outer(&self) -> Vec<DVec2> {
        self.loop_points(&self.outline[0])
    }

    /// An owned copy.
    pub fn to_flat_panel(&self) -> FlatPanel {
        FlatPanel {
            source: self.source,
            points: self.points.to_vec(),
            outline: self.outline.iter().map(|lp| lp.iter().copied()).collect(),
            folds: self.folds.to_vec(),
            holes: self.holes.to_vec(),
            labels: self.labels.to_vec(),
            developability_error: self.developability_error,
            area: self.area,
        }
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

/// Smallest cap height worth engraving (mm).
pub const MIN_HEIGHT: f64 = 1.5;

/// Takes out of `labels` (of a 3D panel with these vertices and facets) those that
/// cannot fit at any height fitting would try: the wanted height is below
/// [`MIN_HEIGHT`], or the text box at [`MIN_HEIGHT`] has more area than the label's
/// facet (than the largest facet for a panel id, which may move to another). A box
/// inside a facet has less area than it, and a facet's area in the plane is at most
/// its 3D vector area, so these labels would be left out anyway: dropping them early
/// changes no output. Returns how many of each kind were dropped.
pub(crate) fn drop_unfittable(
    vertices: &[DVec3],
    facets: LoopsRef,
    labels: &mut Vec<Label>,
) -> LeftOut {
    let mut dropped = LeftOut::default();
    if labels.is_empty() {
        return dropped;
    }
    let areas: Vec<f64> = facets
        .iter()
        .map(|f| vector_area(f.iter().map(|&i| vertices[i as usize])).length())
        .collect();
    let largest = areas.iter().copied().fold(0.0, f64::max);
    labels.retain(|label| {
        let room = match label.kind {
            LabelKind::Panel => largest,
            _ => areas.get(label.facet as usize).copied().unwrap_or(largest),
        };
        // 1 % of slack for the rounding between the 3D and the flat areas.
        let fits = label.height >= MIN_HEIGHT
            && box_area(0.0, text_width(label.text), MIN_HEIGHT) <= 1.01 * room;
        if !fits {
            dropped.count(label.kind);
        }
        fits
    });
    dropped
}

/// The text box of a label: corners counter-clockwise (baseline first).
pub fn label_box(center: DVec2, direction: DVec2, width: f64, height: f64) -> [DVec2; 4] {
    let along = 0.5 * width * direction;
    let up = 0.5 * height * direction.perp();
    [
        center - along - up,
        center + along - up,
        center + along + up,
        center - along + up,
    ]
}

/// How far the frame engraved around a panel's own id stands off its text, in cap
/// heights: the frame tells the panel's id from the partner ids beside it.
pub const FRAME_PAD: f64 = 0.25;

/// The frame of a panel id on a panel too small for [`FRAME_PAD`]: nearer the text,
/// but still a frame.
pub const TIGHT_FRAME_PAD: f64 = 0.1;

/// The size (along the text, across it) of what a label engraves at cap height
/// `height`: its text, and the frame `frame` cap heights off it (0: none).
pub fn label_extent(frame: f64, text_width: f64, height: f64) -> (f64, f64) {
    let (w, h) = (text_width * height, height);
    (w + 2.0 * frame * h, h + 2.0 * frame * h)
}

/// The area of a label's box at cap height `height` ([`label_extent`]): what the
/// early drop and the height skip compare with a facet's area.
pub(crate) fn box_area(frame: f64, text_width: f64, height: f64) -> f64 {
    let (w, h) = label_extent(frame, text_width, height);
    w * h
}

/// How many labels of each kind were left out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeftOut {
    /// Panel ids.
    pub panel: usize,
    /// Partner ids at connections.
    pub partner: usize,
    /// Vertex and face marks.
    pub mark: usize,
}

impl LeftOut {
    /// All kinds together.
    pub fn total(&self) -> usize {
        self.panel + self.partner + self.mark
    }

    /// How many of one kind.
    pub fn of(&self, kind: LabelKind) -> usize {
        match kind {
            LabelKind::Panel => self.panel,
            LabelKind::Partner => self.partner,
            LabelKind::Mark => self.mark,
        }
    }

    pub(crate) fn count(&mut self, kind: LabelKind) {
        match kind {
            LabelKind::Panel => self.panel += 1,
            LabelKind::Partner => self.partner += 1,
            LabelKind::Mark => self.mark += 1,
        }
    }
}

impl std::ops::Add for LeftOut {
    type Output = LeftOut;
    fn add(self, o: LeftOut) -> LeftOut {
        LeftOut {
            panel: self.panel + o.panel,
            partner: self.partner + o.partner,
            mark: self.mark + o.mark,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::arena::CHUNK;
    use super::*;

    #[test]
    fn loops_keep_each_loop_apart_and_in_order() {
        let mut loops = Loops::new();
        assert!(loops.is_empty() && loops.first().is_none());
        loops.push([0, 1, 2]);
        loops.push(Vec::new());
        loops.push([3, 4, 5, 6]);
        assert_eq!(loops.len(), 3);
        assert_eq!(loops.index_count(), 7);
        assert_eq!(&loops[0], &[0, 1, 2]);
        assert_eq!(&loops[1], &[] as &[u32]);
        assert_eq!(loops.get(2), Some(&[3, 4, 5, 6][..]));
        assert_eq!(loops.get(3), None);
        let collected: Vec<Vec<u32>> = loops.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(collected, [vec![0, 1, 2], vec![], vec![3, 4, 5, 6]]);
        assert_eq!(loops.iter().next_back(), Some(&[3, 4, 5, 6][..]));
        let rebuilt: Loops = collected.into_iter().collect();
        assert_eq!(rebuilt, loops);
        assert_eq!((&loops).into_iter().count(), 3);
    }

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
        // figures in docs/architecture.md).
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

    #[test]
    fn names_print_as_the_ids_users_read() {
        assert_eq!(Name::face(12).to_string(), "F12");
        assert_eq!(Name::edge(123).to_string(), "E123");
        assert_eq!(Name::vertex(7).to_string(), "V7");
        static CYCLE: IdKind = IdKind {
            letter: "C",
            legend: "cycle",
            noun: "cycle",
            part_noun: "segment",
            layer: "",
        };
        assert_eq!(Name::new(&CYCLE, 3).to_string(), "C3");
        assert_eq!(Name::with_part(&CYCLE, 3, 2).to_string(), "C3.2");
        static BARE: IdKind = IdKind {
            letter: "",
            legend: "match number",
            noun: "match",
            part_noun: "",
            layer: "",
        };
        assert_eq!(Name::new(&BARE, 17).to_string(), "17");
        assert_eq!(Source::edge(5).id.to_string(), "E5");
        assert_eq!(Source::face(5).covers, Covers::Face(5));
    }
}
