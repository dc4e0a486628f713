//! Labels: what a panel's engraved texts say and where they go in 3D, the text boxes and
//! frames they engrave, and the count of those left out for want of room (some dropped
//! as the panel is made, when no facet could ever hold them).

use glam::{DVec2, DVec3};
use serde::Serialize;

use super::loops::LoopsRef;
use super::source::Name;
use crate::font::text_width;
use crate::mesh::geometry::vector_area;

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

/// Smallest cap height worth engraving (mm).
pub const MIN_HEIGHT: f64 = 1.5;

/// Takes out of `labels` (of a 3D panel with these vertices and facets) those that
/// cannot fit at any height fitting would try: the wanted height is below
/// [`MIN_HEIGHT`], or the text box at [`MIN_HEIGHT`] has more area than the label's
/// facet (than the largest facet for a panel id, which may move to another). A box
/// inside a facet has less area than it, and a facet's area in the plane is at most
/// its 3D vector area, so these labels would be left out anyway: dropping them early
/// changes no output. Returns how many of each kind were dropped.
pub(super) fn drop_unfittable(
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
