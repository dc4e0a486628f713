//! 3D panels and flat panels.
//!
//! A panel is a small polygon mesh of planar facets (3D polygons) with shared corner
//! vertices. An edge shared by two facets is a hinge (a fold, scored when its fold angle
//! is not zero); an edge of one facet only is part of the cut outline. Every scheme
//! produces panels in this form, so one unroller and one exporter serve them all.

use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::labels::LeftOut;

/// Which mesh element a panel was made from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// A face (half-edge scheme).
    Face(u32),
    /// An edge (quad-edge and winged-edge schemes).
    Edge(u32),
    /// A segment of a woven cycle.
    Cycle {
        /// The cycle.
        cycle: u32,
        /// The segment along it.
        segment: u32,
    },
}

impl Source {
    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn name(self) -> Name {
        match self {
            Source::Face(f) => Name::Face(f),
            Source::Edge(e) => Name::Edge(e),
            Source::Cycle { cycle, segment } => Name::Segment { cycle, segment },
        }
    }
}

/// A printed name: a panel's id, or what a label says. Kept as the element it names
/// and printed on demand, so a million panels carry no strings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Name {
    /// A face: `F12` (half-edge panel ids, face marks).
    Face(u32),
    /// An edge: `E123` (edge panel ids).
    Edge(u32),
    /// A vertex: `V7` (corner marks).
    Vertex(u32),
    /// A woven cycle: `C3` (1-based).
    Cycle(u32),
    /// A segment of a woven cycle: `C3.2` (both 1-based).
    Segment {
        /// The cycle (1-based).
        cycle: u32,
        /// The segment along it (1-based).
        segment: u32,
    },
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Name::Face(k) => write!(f, "F{k}"),
            Name::Edge(k) => write!(f, "E{k}"),
            Name::Vertex(k) => write!(f, "V{k}"),
            Name::Cycle(k) => write!(f, "C{k}"),
            Name::Segment { cycle, segment } => write!(f, "C{cycle}.{segment}"),
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
        let end = *self.ends.get(k)? as usize;
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        Some(&self.indices[start..end])
    }

    /// The first loop.
    pub fn first(&self) -> Option<&[u32]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> LoopsIter<'_> {
        LoopsIter {
            loops: self,
            range: 0..self.len(),
        }
    }

    /// Indices in all loops together.
    pub fn index_count(&self) -> usize {
        self.indices.len()
    }

    /// Gives back spare capacity (panels are built once and kept).
    pub fn shrink_to_fit(&mut self) {
        self.indices.shrink_to_fit();
        self.ends.shrink_to_fit();
    }
}

impl std::ops::Index<usize> for Loops {
    type Output = [u32];
    fn index(&self, k: usize) -> &[u32] {
        self.get(k)
            .unwrap_or_else(|| panic!("loop {k} of {}", self.len()))
    }
}

/// The loops of a [`Loops`], in order.
#[derive(Clone, Debug)]
pub struct LoopsIter<'a> {
    loops: &'a Loops,
    range: std::ops::Range<usize>,
}

impl<'a> Iterator for LoopsIter<'a> {
    type Item = &'a [u32];
    fn next(&mut self) -> Option<&'a [u32]> {
        self.range.next().map(|k| &self.loops[k])
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.range.size_hint()
    }
}

impl DoubleEndedIterator for LoopsIter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        self.range.next_back().map(|k| &self.loops[k])
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
    /// A panel from its parts, holding no spare capacity: the schemes build panels by
    /// pushing, and a big job keeps millions of them until the end. Labels whose text
    /// box at the smallest legible height has more area than any facet they may go on
    /// are dropped here (and counted): at a million panels they would take more memory
    /// than the panels' geometry, and fitting would leave them out anyway.
    pub fn new(
        source: Source,
        mut vertices: Vec<DVec3>,
        mut facets: Loops,
        mut holes: Vec<Hole>,
        mut labels: Vec<Label>,
    ) -> Self {
        let labels_dropped = crate::labels::drop_unfittable(&vertices, &facets, &mut labels);
        vertices.shrink_to_fit();
        facets.shrink_to_fit();
        holes.shrink_to_fit();
        labels.shrink_to_fit();
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
        self.source.name()
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
    pub scores: Vec<[u32; 2]>,
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
    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub fn id(&self) -> Name {
        self.source.name()
    }

    /// The points of an outline loop.
    pub fn loop_points(&self, lp: &[u32]) -> Vec<DVec2> {
        lp.iter().map(|&i| self.points[i as usize]).collect()
    }

    /// The outer outline's points.
    pub fn outer(&self) -> Vec<DVec2> {
        self.loop_points(&self.outline[0])
    }

    /// Largest distance between two points of the panel (its size).
    pub fn diameter(&self) -> f64 {
        let outer = self.outer();
        let mut best = 0.0f64;
        for (i, a) in outer.iter().enumerate() {
            for b in &outer[i + 1..] {
                best = best.max(a.distance_squared(*b));
            }
        }
        best.sqrt()
    }
}

#[cfg(test)]
mod tests {
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

    #[test]
    fn names_print_as_the_ids_users_read() {
        assert_eq!(Name::Face(12).to_string(), "F12");
        assert_eq!(Name::Edge(123).to_string(), "E123");
        assert_eq!(Name::Vertex(7).to_string(), "V7");
        assert_eq!(Name::Cycle(3).to_string(), "C3");
        assert_eq!(
            Name::Segment {
                cycle: 3,
                segment: 2
            }
            .to_string(),
            "C3.2"
        );
        let source = Source::Cycle {
            cycle: 3,
            segment: 2,
        };
        assert_eq!(
            source.name(),
            Name::Segment {
                cycle: 3,
                segment: 2
            }
        );
        assert_eq!(Source::Edge(5).name().to_string(), "E5");
    }
}
