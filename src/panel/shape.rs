//! One panel, as it sits in the model ([`Panel`]) and unrolled into the plane
//! ([`FlatPanel`]), each owned or borrowed from its arena, with what it carries: facets,
//! fastener holes, labels, folds, and the isometry of each facet between the two.

use glam::{DVec2, DVec3};
use serde::Serialize;

use super::label::{drop_unfittable, Label, LabelKind, LeftOut};
use super::loops::{Loops, LoopsRef};
use super::source::{Name, Source};

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
    /// panels are copied into a [`Panels`](super::Panels) arena as they are made.)
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

/// A 3D panel borrowed from a [`Panels`](super::Panels) arena (or from a [`Panel`]): the same
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

/// A flat panel borrowed from a [`FlatPanels`](super::FlatPanels) arena (or from a [`FlatPanel`]): the
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
