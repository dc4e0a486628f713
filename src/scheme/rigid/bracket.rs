//! Brackets that hold rigid panels together: a flat part cut from the same sheet,
//! standing square to an edge inside the model, whose two arms lie against the inner
//! faces of the edge's two panels at the edge's angle. A tab on each arm passes through
//! a slot in its panel to the panel's outer face. The slot is the tab's size plus a
//! clearance; a collar of panel material stays around it, so the slot is an
//! inner cut of the panel.

use glam::{DVec2, DVec3};

use super::cutback::{
    interior_angle, outline_prisms, overlap, Prism, RigidOutline, OVERLAP_TOLERANCE,
};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::panel::{Covers, IdKind, Label, LabelKind, Loops, Name, Panel, Source};

/// The kind of id a bracket gets: `B12.1` is the first bracket of edge 12.
pub static BRACKET: IdKind = IdKind {
    letter: "B",
    legend: "bracket (edge.bracket)",
    noun: "bracket",
    part_noun: "bracket",
    layer: "",
};

/// The kind of mark engraved on a bracket: the angle between its arms, in degrees
/// (`135.3`: 135 and 3 tenths).
pub static ANGLE: IdKind = IdKind {
    letter: "",
    legend: "bracket angle (degrees)",
    noun: "angle",
    part_noun: "tenth",
    layer: "",
};

/// The length of an arm where its panel has room (mm): enough for its labels.
const ARM_LENGTH: f64 = 40.0;

/// An edge gets one bracket per this length of it (mm), at least one.
const BRACKET_SPACING: f64 = 250.0;

/// What brackets are made of and how they fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BracketSizes {
    /// Material thickness (mm).
    pub thickness: f64,
    /// Play of a tab in its slot (mm): the slot is this much wider and longer.
    pub clearance: f64,
}

impl BracketSizes {
    /// How wide an arm is, from the panel it lies on inward (mm).
    fn arm_width(&self) -> f64 {
        (3.0 * self.thickness).max(8.0)
    }

    /// How long a tab is along its arm (mm).
    fn tab_length(&self) -> f64 {
        (2.0 * self.thickness).max(6.0)
    }

    /// Material kept between a slot and any cut edge of its panel (mm).
    fn margin(&self) -> f64 {
        self.thickness.max(2.0)
    }
}

/// A slot through a panel, in the frame of the panel's side along the bracket's edge:
/// `x` along the side's half-edge from its origin vertex, `y` inward from the edge's
/// line (mm). The slot is `x0..x1` by `y0..y1`; its collar adds the margin on three
/// sides and reaches out to the panel's side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot {
    /// The face's half-edge along the bracket's edge.
    pub side: HalfedgeId,
    /// Along the side.
    pub x: [f64; 2],
    /// Inward from the edge line.
    pub y: [f64; 2],
    /// Panel material around the slot, to the collar's sides.
    pub margin: f64,
}

/// One bracket.
#[derive(Clone, Debug, PartialEq)]
pub struct Bracket {
    /// Its edge.
    pub edge: EdgeId,
    /// Its number along the edge, from 1.
    pub part: u32,
    /// Its outline on its outer face (square to the edge), counter-clockwise seen from
    /// outside (`normal`).
    pub points: Vec<DVec3>,
    /// Along the edge: the side of the bracket its outline lies on.
    pub normal: DVec3,
    /// Where its id goes and which way it reads, on the first arm.
    pub id_at: (DVec3, DVec3),
    /// Where each arm's panel id goes and which way it reads.
    pub arm_labels: [(FaceId, DVec3, DVec3); 2],
    /// Where the angle goes and which way it reads.
    pub angle_at: (DVec3, DVec3),
    /// How far each arm's labels may slide along it to find room (mm).
    pub slides: [f64; 2],
    /// The interior angle between the arms (radians): the edge's.
    pub angle: f64,
    /// The slot its tab needs in each of the two panels.
    pub slots: [Slot; 2],
    /// Its two arms without their tabs, each a convex quadrilateral through the
    /// bracket's middle (to check that they stay clear of other parts).
    pub arms: [[DVec3; 4]; 2],
}

/// Arm lengths tried, longest first (mm): long arms hold better and carry the labels,
/// shorter ones stay clear of the panels bent down at a face's other edges; zero
/// stands for the shortest that holds the tab.
const ARM_LENGTHS: [f64; 4] = [ARM_LENGTH, 30.0, 20.0, 0.0];

/// Every bracket place of a rigid build: per interior edge, one per
/// [`BRACKET_SPACING`] of its length, each as the brackets that fit there, at the
/// middle of its stretch of the edge or off to a side, with arms from long to short.
pub fn bracket_places(
    mesh: &Mesh,
    outlines: &[RigidOutline],
    sizes: BracketSizes,
) -> Vec<Vec<Bracket>> {
    let mut places = Vec::new();
    for e in mesh.edges() {
        let h = e.half_edge();
        if mesh.face(h).is_none() || mesh.face(h.twin()).is_none() {
            continue;
        }
        let length = mesh.edge_length(e);
        let count = (length / BRACKET_SPACING).ceil().max(1.0) as u32;
        let step = length / count as f64;
        for k in 0..count {
            // The middle of its stretch of the edge first, then off to either side.
            let spots = [0.5, 0.3, 0.7].map(|f| (k as f64 + f) * step);
            let mut tried: Vec<Bracket> = spots
                .iter()
                .flat_map(|&at| ARM_LENGTHS.iter().map(move |&arm| (at, arm)))
                .filter_map(|(at, arm)| bracket_at(mesh, outlines, h, at, arm, sizes))
                .collect();
            // Short arms come out the same when the long ones do not fit.
            tried.dedup_by(|a, b| a.points == b.points);
            places.push(tried);
        }
    }
    places
}

/// The bracket of edge `h` at `at` mm from its origin, or `None` when a panel has no
/// room for its slot there.
fn bracket_at(
    mesh: &Mesh,
    outlines: &[RigidOutline],
    h: HalfedgeId,
    at: f64,
    arm_length: f64,
    sizes: BracketSizes,
) -> Option<Bracket> {
    let (fa, fb) = (mesh.face(h)?, mesh.face(h.twin())?);
    let t = sizes.thickness;
    let a = mesh.position(mesh.origin(h));
    let along = (mesh.position(mesh.dest(h)) - a).normalize_or_zero();
    let base = a + at * along;
    let (na, nb) = (mesh.face_normal(fa), mesh.face_normal(fb));
    // Into each face, square to the edge.
    let (ua, ub) = (na.cross(along), along.cross(nb));
    let c = na.dot(nb);
    if c <= -0.99 {
        // Faces folded almost flat onto each other: no bracket fits between.
        return None;
    }
    // The arms' outer corner P lies on both panels' inner faces; Q, the inner one, a
    // width further in.
    let w = sizes.arm_width();
    let p = base - t / (1.0 + c) * (na + nb);
    let q = base - (t + w) / (1.0 + c) * (na + nb);
    let arm = |u: DVec3, n: DVec3, face: FaceId, side: HalfedgeId| {
        let place = ArmPlace { base, p, q, u, n };
        arm_plan(mesh, outlines, face, side, &place, arm_length, sizes)
    };
    let (arm_a, arm_b) = (arm(ua, na, fa, h)?, arm(ub, nb, fb, h.twin())?);
    // The outline at the middle of the bracket: P, out along arm A (its tab on the
    // way), back along its inner side to Q, out along arm B's inner side and back along
    // its outer side (its tab on the way) to P.
    let mut middle = vec![p];
    middle.extend(arm_a.outer_side.iter().copied());
    middle.push(q);
    middle.extend(arm_b.outer_side.iter().rev().copied());
    let normal = along;
    let mut points: Vec<DVec3> = middle.iter().map(|&x| x + 0.5 * t * normal).collect();
    let area = crate::mesh::geometry::vector_area(points.iter().copied());
    if area.dot(normal) < 0.0 {
        points.reverse();
    }
    let angle = interior_angle(mesh, h);
    let label_at =
        |plan: &ArmPlan, u: DVec3, n: DVec3, f: f64| p + f * plan.length * u - 0.5 * w * n;
    Some(Bracket {
        edge: h.edge(),
        part: 0,
        points,
        normal,
        id_at: (label_at(&arm_a, ua, na, 0.35) + 0.5 * t * normal, ua),
        arm_labels: [
            (fa, label_at(&arm_a, ua, na, 0.8) + 0.5 * t * normal, ua),
            (fb, label_at(&arm_b, ub, nb, 0.35) + 0.5 * t * normal, ub),
        ],
        angle_at: (label_at(&arm_b, ub, nb, 0.8) + 0.5 * t * normal, ub),
        slides: [0.3 * arm_a.length, 0.3 * arm_b.length],
        angle,
        slots: [arm_a.slot, arm_b.slot],
        arms: [
            [p, p + arm_a.length * ua, p + arm_a.length * ua - w * na, q],
            [q, p + arm_b.length * ub - w * nb, p + arm_b.length * ub, p],
        ],
    })
}

/// Where an arm goes: the point of the edge at the bracket's middle, the arms' outer
/// and inner corners P and Q, into the panel along it, and the panel's normal.
#[derive(Clone, Copy, Debug)]
struct ArmPlace {
    base: DVec3,
    p: DVec3,
    q: DVec3,
    u: DVec3,
    n: DVec3,
}

/// One arm of a bracket.
struct ArmPlan {
    /// Its outer side from P outward: the tab's four corners, then the arm's end,
    /// then the end of its inner side.
    outer_side: Vec<DVec3>,
    /// From P to its end (mm).
    length: f64,
    /// The slot for its tab.
    slot: Slot,
}

/// The arm along `u` on the panel of `face` (normal `n`, side `side` along the edge):
/// its tab placed clear of the panel's cut edge and the slot it needs, or `None` when
/// the panel has no room for the slot's collar.
fn arm_plan(
    mesh: &Mesh,
    outlines: &[RigidOutline],
    face: FaceId,
    side: HalfedgeId,
    place: &ArmPlace,
    arm_length: f64,
    sizes: BracketSizes,
) -> Option<ArmPlan> {
    let ArmPlace { base, p, q, u, n } = *place;
    let (t, m, tab) = (sizes.thickness, sizes.margin(), sizes.tab_length());
    let outline = &outlines[face.0 as usize];
    let k = outline.along.iter().position(|&s| s == Some(side))?;
    let corner = outline.points[k];
    // Depths inward from the edge line: of the panel's side, of P, of Q.
    let origin = mesh.position(mesh.origin(side));
    let side_depth = (corner - origin).dot(u);
    let (p_depth, q_depth) = ((p - base).dot(u), (q - base).dot(u));
    let play = 0.5 * sizes.clearance;
    let start = side_depth.max(p_depth) + m + play;
    let at = (base - origin).dot((mesh.position(mesh.dest(side)) - origin).normalize_or_zero());
    let half = 0.5 * t + play;
    let slot = Slot {
        side,
        x: [at - half, at + half],
        y: [start - play, start + tab + play],
        margin: m,
    };
    if !collar_fits(mesh, outline, k, &slot) {
        return None;
    }
    // Long arms hold better and carry the labels; the arm must end over its panel.
    let needed = (start + tab + m - p_depth).max(q_depth - p_depth + m);
    let length = needed.max(arm_length);
    let end = p + length * u;
    if ![-0.5, 0.5]
        .iter()
        .all(|&s| over_outline(outline, end + s * t * n.cross(u)))
    {
        return None;
    }
    let on_arm = |depth: f64| p + (depth - p_depth) * u;
    let outer_side = vec![
        on_arm(start),
        on_arm(start) + t * n,
        on_arm(start + tab) + t * n,
        on_arm(start + tab),
        p + length * u,
        p + length * u - sizes.arm_width() * n,
    ];
    Some(ArmPlan {
        outer_side,
        length,
        slot,
    })
}

/// `point`, projected on the outline's plane, lies inside the outline or on its border.
fn over_outline(outline: &RigidOutline, point: DVec3) -> bool {
    let normal =
        crate::mesh::geometry::vector_area(outline.points.iter().copied()).normalize_or_zero();
    let x = normal.any_orthonormal_vector();
    let y = normal.cross(x);
    let flat = |p: DVec3| DVec2::new(p.dot(x), p.dot(y));
    let poly: Vec<DVec2> = outline.points.iter().map(|&p| flat(p)).collect();
    let q = flat(point);
    crate::plane::contains(&poly, q) || crate::plane::distance_to_border(&poly, q) < 1e-9
}

/// The slot's collar lies inside the panel's outline, its base on side `k`.
fn collar_fits(mesh: &Mesh, outline: &RigidOutline, k: usize, slot: &Slot) -> bool {
    let Some(side) = outline.along[k] else {
        return false;
    };
    let origin = mesh.position(mesh.origin(side));
    let dir = (mesh.position(mesh.dest(side)) - origin).normalize_or_zero();
    let m = outline.points.len();
    let (from, to) = (outline.points[k], outline.points[(k + 1) % m]);
    let (x_from, x_to) = ((from - origin).dot(dir), (to - origin).dot(dir));
    if slot.x[0] - slot.margin < x_from + slot.margin
        || slot.x[1] + slot.margin > x_to - slot.margin
    {
        return false;
    }
    // The collar's far corners inside the outline (a convex polygon: inside every side).
    let normal =
        crate::mesh::geometry::vector_area(outline.points.iter().copied()).normalize_or_zero();
    let inward = normal.cross(dir);
    let depth = slot.y[1] + slot.margin;
    let side_depth = (from - origin).dot(inward);
    let far = [slot.x[0] - slot.margin, slot.x[1] + slot.margin]
        .map(|x| from + (x - x_from) * dir + (depth - side_depth) * inward);
    // A region's outline need not be convex: no corner of it may reach into the
    // collar either.
    let (x_lo, x_hi) = (slot.x[0] - slot.margin, slot.x[1] + slot.margin);
    let corner_inside = outline.points.iter().any(|&c| {
        let (x, y) = ((c - origin).dot(dir), (c - origin).dot(inward));
        x_lo < x && x < x_hi && side_depth + 1e-9 < y && y < depth
    });
    !corner_inside && far.iter().all(|&c| over_outline(outline, c))
}

/// The box around some prisms.
fn prisms_box(prisms: &[Prism]) -> (DVec3, DVec3) {
    crate::mesh::geometry::bounding_box(prisms.iter().flat_map(|p| p.corners.iter().copied()))
}

/// Two brackets' collars on one face would meet.
fn collars_meet(mesh: &Mesh, a: &Bracket, b: &Bracket) -> bool {
    let footprint = |slot: &Slot| {
        let origin = mesh.position(mesh.origin(slot.side));
        let dir = (mesh.position(mesh.dest(slot.side)) - origin).normalize_or_zero();
        let face = mesh.face(slot.side);
        let normal = face.map_or(DVec3::Z, |f| mesh.face_normal(f));
        let inward = normal.cross(dir);
        // The collar: the panel's facets around two slots must not meet (the arms
        // are checked in 3D, against every part).
        let reach = slot.y[1] + slot.margin;
        let (x0, x1) = (slot.x[0] - slot.margin, slot.x[1] + slot.margin);
        (
            face,
            [
                origin + x0 * dir,
                origin + x1 * dir,
                origin + x1 * dir + reach * inward,
                origin + x0 * dir + reach * inward,
            ],
        )
    };
    a.slots.iter().any(|sa| {
        b.slots.iter().any(|sb| {
            let (fa, pa) = footprint(sa);
            let (fb, pb) = footprint(sb);
            fa == fb && quads_meet(&pa, &pb)
        })
    })
}

/// Two convex quadrilaterals in one plane overlap (separating axes on their sides).
fn quads_meet(a: &[DVec3; 4], b: &[DVec3; 4]) -> bool {
    let normal = (a[1] - a[0]).cross(a[3] - a[0]).normalize_or_zero();
    let axes = a
        .iter()
        .zip(a.iter().cycle().skip(1))
        .chain(b.iter().zip(b.iter().cycle().skip(1)));
    for (p, q) in axes {
        let axis = normal.cross(*q - *p);
        let span = |quad: &[DVec3; 4]| {
            quad.iter()
                .map(|x| x.dot(axis))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                })
        };
        let ((a_lo, a_hi), (b_lo, b_hi)) = (span(a), span(b));
        if a_hi <= b_lo || b_hi <= a_lo {
            return false;
        }
    }
    true
}

/// The panel of a bracket: its outline, its id (naming `edge`, the edge's number in the
/// user's model) and its two panels' ids on its arms (`panel_id` of their faces), the
/// angle between the arms engraved.
pub fn bracket_panel(
    bracket: &Bracket,
    label_height: f64,
    edge: u32,
    panel_id: &dyn Fn(FaceId) -> Name,
) -> Panel {
    let label =
        |text: Name, (anchor, direction): (DVec3, DVec3), kind: LabelKind, arm: usize| Label {
            text,
            anchor,
            direction,
            height: label_height,
            facet: 0,
            kind,
            on_edge: false,
            slide: bracket.slides[arm],
        };
    let tenths = (bracket.angle.to_degrees() * 10.0).round() as u32;
    let mut labels = vec![label(
        Name::with_part(&BRACKET, edge, bracket.part),
        bracket.id_at,
        LabelKind::Panel,
        0,
    )];
    for (arm, (face, anchor, direction)) in bracket.arm_labels.into_iter().enumerate() {
        let at = (anchor, direction);
        labels.push(label(panel_id(face), at, LabelKind::Partner, arm));
    }
    labels.push(label(
        Name::with_part(&ANGLE, tenths / 10, tenths % 10),
        bracket.angle_at,
        LabelKind::Mark,
        1,
    ));
    let facet: Loops = std::iter::once(0..bracket.points.len() as u32).collect();
    let source = Source {
        id: Name::with_part(&BRACKET, edge, bracket.part),
        covers: Covers::Inside(edge),
    };
    Panel::new(source, bracket.points.clone(), facet, Vec::new(), labels)
}

/// A rigid panel's corners and facets with its slots cut: the outline's corners first
/// (in order), then per slot its collar and its own corners. Facet 0 is the panel less
/// the collars; each collar is four facets round its slot, which is so an inner cut.
pub fn slotted_facets(mesh: &Mesh, outline: &RigidOutline, slots: &[Slot]) -> (Vec<DVec3>, Loops) {
    let mut vertices = outline.points.clone();
    let normal =
        crate::mesh::geometry::vector_area(outline.points.iter().copied()).normalize_or_zero();
    let m = outline.points.len();
    let mut main = Vec::with_capacity(m + 4 * slots.len());
    let mut rings: Vec<[u32; 16]> = Vec::new();
    for k in 0..m {
        main.push(k as u32);
        let Some(side) = outline.along[k] else {
            continue;
        };
        let mut here: Vec<&Slot> = slots.iter().filter(|s| s.side == side).collect();
        here.sort_by(|a, b| a.x[0].total_cmp(&b.x[0]));
        let from = outline.points[k];
        let dir = (outline.points[(k + 1) % m] - from).normalize_or_zero();
        let inward = normal.cross(dir);
        let origin = mesh.position(mesh.origin(side));
        let (x_from, y_from) = ((from - origin).dot(dir), (from - origin).dot(inward));
        for slot in here {
            let at = |x: f64, y: f64| from + (x - x_from) * dir + (y - y_from) * inward;
            let (x0, x1, y0, y1, g) = (slot.x[0], slot.x[1], slot.y[0], slot.y[1], slot.margin);
            let base = vertices.len() as u32;
            vertices.extend([
                at(x0 - g, y_from),
                at(x0 - g, y1 + g),
                at(x1 + g, y1 + g),
                at(x1 + g, y_from),
                at(x0, y0),
                at(x1, y0),
                at(x1, y1),
                at(x0, y1),
            ]);
            let [c00, c01, c11, c10, s00, s10, s11, s01] = std::array::from_fn(|i| base + i as u32);
            main.extend([c00, c01, c11, c10]);
            rings.push([
                c00, c10, s10, s00, // toward the panel's side
                c10, c11, s11, s10, // after the slot
                c11, c01, s01, s11, // beyond it
                c01, c00, s00, s01, // before it
            ]);
        }
    }
    let mut facets = Loops::new();
    facets.push(main);
    for ring in rings {
        for quad in ring.chunks(4) {
            facets.push(quad.iter().copied());
        }
    }
    (vertices, facets)
}

/// The brackets of a rigid build that stay clear of every panel and of each other
/// (in edge order, a later one yielding; at each place the longest arms that do), and
/// the interior edges left without one.
pub fn clear_brackets(
    mesh: &Mesh,
    outlines: &[RigidOutline],
    sizes: BracketSizes,
) -> (Vec<Bracket>, Vec<EdgeId>) {
    let t = sizes.thickness;
    let panels: Vec<Vec<Prism>> = outlines
        .iter()
        .zip(mesh.faces())
        .map(|(o, f)| outline_prisms(o, mesh.face_normal(f), t))
        .collect();
    let arm_prisms = |b: &Bracket| -> Vec<Prism> {
        b.arms
            .iter()
            .map(|quad| {
                let mut outer: Vec<DVec3> = quad.iter().map(|&p| p + 0.5 * t * b.normal).collect();
                if crate::mesh::geometry::vector_area(outer.iter().copied()).dot(b.normal) < 0.0 {
                    outer.reverse();
                }
                Prism::new(outer, b.normal, t)
            })
            .collect()
    };
    let boxes = |prisms: &[Prism]| prisms_box(prisms);
    let panel_boxes: Vec<(DVec3, DVec3)> = panels.iter().map(|p| boxes(p)).collect();
    let mut kept: Vec<(Bracket, Vec<Prism>, (DVec3, DVec3))> = Vec::new();
    // The brackets kept on each face, whose collars a new one there must keep clear of.
    let mut on_face: Vec<Vec<usize>> = vec![Vec::new(); mesh.face_count()];
    let faces_of = |b: &Bracket| {
        b.slots
            .map(|s| mesh.face(s.side).map_or(0, |f| f.0 as usize))
    };
    for place in bracket_places(mesh, outlines, sizes) {
        let chosen = place.into_iter().find_map(|bracket| {
            let arms = arm_prisms(&bracket);
            let reach = boxes(&arms);
            let meets = |other: &(DVec3, DVec3)| {
                reach.0.cmple(other.1).all() && other.0.cmple(reach.1).all()
            };
            let collars_clear = faces_of(&bracket)
                .iter()
                .flat_map(|&f| &on_face[f])
                .all(|&k| !collars_meet(mesh, &kept[k].0, &bracket));
            let clear = collars_clear
                && panels
                    .iter()
                    .zip(&panel_boxes)
                    .filter(|(_, b)| meets(b))
                    .all(|(p, _)| overlap(p, &arms) <= OVERLAP_TOLERANCE)
                && kept
                    .iter()
                    .filter(|(_, _, b)| meets(b))
                    .all(|(_, other, _)| overlap(other, &arms) <= OVERLAP_TOLERANCE);
            clear.then_some((bracket, arms, reach))
        });
        if let Some((mut bracket, arms, reach)) = chosen {
            bracket.part = 1 + kept
                .iter()
                .filter(|(b, _, _)| b.edge == bracket.edge)
                .count() as u32;
            for f in faces_of(&bracket) {
                on_face[f].push(kept.len());
            }
            kept.push((bracket, arms, reach));
        }
    }
    let kept: Vec<Bracket> = kept.into_iter().map(|(b, _, _)| b).collect();
    let bare = mesh
        .edges()
        .filter(|&e| !mesh.is_boundary_edge(e))
        .filter(|&e| !kept.iter().any(|b| b.edge == e))
        .collect();
    (kept, bare)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::rigid::cutback::rigid_panels;

    fn cube() -> Mesh {
        crate::mesh::build::cube(200.0)
    }

    #[test]
    fn a_cube_edge_gets_a_right_angled_bracket_with_slots_t_plus_the_clearance_wide() {
        let mesh = cube();
        let sizes = BracketSizes {
            thickness: 3.0,
            clearance: 0.1,
        };
        let rigid = rigid_panels(&mesh, &mesh, 3.0).expect("3 mm fits");
        let (brackets, bare) = clear_brackets(&mesh, &rigid.outlines, sizes);
        assert!(bare.is_empty(), "{bare:?}");
        assert_eq!(brackets.len(), 12, "one per edge under 250 mm");
        for b in &brackets {
            assert!((b.angle.to_degrees() - 90.0).abs() < 1e-9);
            // The arms' outer sides lie on the two panels' inner faces, 3 mm in.
            let h = b.edge.half_edge();
            for (k, f) in [mesh.face(h), mesh.face(h.twin())].into_iter().enumerate() {
                let f = f.expect("interior edge");
                let (n, c) = (mesh.face_normal(f), mesh.face_centre(f));
                let [p, end, ..] = b.arms[k];
                let [p, end] = if k == 0 {
                    [p, end]
                } else {
                    [b.arms[1][3], b.arms[1][2]]
                };
                for x in [p, end] {
                    assert!(((x - c).dot(n) + 3.0).abs() < 1e-9, "{:?}", b.edge);
                }
            }
            for slot in b.slots {
                assert!((slot.x[1] - slot.x[0] - 3.1).abs() < 1e-9);
                assert!((slot.y[1] - slot.y[0] - 6.1).abs() < 1e-9);
            }
        }
        // The outline runs round both tabs: 6 corners of an L and 4 for each tab.
        assert_eq!(brackets[0].points.len(), 14);
    }

    #[test]
    fn a_slotted_panel_is_its_outline_less_the_collars_and_four_facets_round_each_slot() {
        let mesh = cube();
        let sizes = BracketSizes {
            thickness: 3.0,
            clearance: 0.1,
        };
        let rigid = rigid_panels(&mesh, &mesh, 3.0).expect("3 mm fits");
        let (brackets, _) = clear_brackets(&mesh, &rigid.outlines, sizes);
        let face = FaceId(1);
        let slots: Vec<Slot> = brackets
            .iter()
            .flat_map(|b| b.slots)
            .filter(|s| mesh.face(s.side) == Some(face))
            .collect();
        assert_eq!(slots.len(), 4);
        let outline = &rigid.outlines[1];
        let (vertices, facets) = slotted_facets(&mesh, outline, &slots);
        assert_eq!(facets.len(), 1 + 4 * 4);
        assert_eq!(vertices.len(), outline.points.len() + 8 * 4);
        // The facets tile the panel less its slots: their areas add up.
        let area = |lp: &[u32]| {
            crate::mesh::geometry::vector_area(lp.iter().map(|&i| vertices[i as usize])).length()
        };
        let facets_area: f64 = facets.iter().map(area).sum();
        let outline_area =
            crate::mesh::geometry::vector_area(outline.points.iter().copied()).length();
        let slots_area: f64 = slots
            .iter()
            .map(|s| (s.x[1] - s.x[0]) * (s.y[1] - s.y[0]))
            .sum();
        assert!((facets_area - (outline_area - slots_area)).abs() < 1e-6);
    }
}
