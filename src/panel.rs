//! 3D panels and flat panels.
//!
//! A panel is a small polygon mesh of planar facets (3D polygons) with shared corner
//! vertices. An edge shared by two facets is a hinge (a fold, scored when its fold angle
//! is not zero); an edge of one facet only is part of the cut outline. Every scheme
//! produces panels in this form, so one unroller and one exporter serve them all.

use glam::{DVec2, DVec3};
use serde::Serialize;

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
    /// ASCII text.
    pub text: String,
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

/// A panel in 3D, as it sits in the assembled model (millimetres).
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// The id printed for users (`F12`, `E123`, `C3.2`).
    pub id: String,
    /// Provenance.
    pub source: Source,
    /// Corner positions shared by the facets.
    pub vertices: Vec<DVec3>,
    /// Planar facets as vertex index loops, counter-clockwise seen from the outside.
    pub facets: Vec<Vec<u32>>,
    /// Fastener holes.
    pub holes: Vec<Hole>,
    /// Labels.
    pub labels: Vec<Label>,
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
    /// ASCII text.
    pub text: String,
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
#[derive(Clone, Debug, PartialEq)]
pub struct FlatPanel {
    /// The id printed for users.
    pub id: String,
    /// Provenance.
    pub source: Source,
    /// Corner positions in the plane (same indices as the 3D panel's vertices).
    pub points: Vec<DVec2>,
    /// Facets (same as the 3D panel's).
    pub facets: Vec<Vec<u32>>,
    /// The isometry of every facet (for mapping holes and labels back to 3D).
    pub frames: Vec<FacetFrame>,
    /// Cut loops: the outer outline first (counter-clockwise), then inner cuts
    /// (clockwise).
    pub outline: Vec<Vec<u32>>,
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
