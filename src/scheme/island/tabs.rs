//! A tab laid flat beside its island: the frame between its 3D plane and the island's,
//! cut back clear of the island's faces and tabs, and the sheet it must fit.

use glam::{DVec2, DVec3};

use super::options::IslandOptions;
use crate::mesh::{HalfedgeId, Mesh};
use crate::scheme::kit::tab::{Tab, TabOptions};

/// Least distance (mm) between two faces or tabs of one island that are not joined:
/// the laser needs room between two cuts, and an outline that touches itself is not
/// one loop.
pub const ISLAND_GAP: f64 = 0.5;

/// Tab heights tried, as fractions of `--tab-height`, before a tab is left out.
pub(super) const TAB_STEPS: [f64; 3] = [1.0, 0.5, 0.25];

/// Least distance (mm) between a tab and a face folded to its own face at the tab's
/// end (the two sides of a notch): clear of the files' rounding to 0.0001 mm, so the
/// outline never touches itself there.
pub(super) const NOTCH_GAP: f64 = 0.05;

/// The largest gap between two counter-clockwise convex polygons along the edge
/// normals of either: at least their distance apart when positive, and never positive
/// when they overlap.
pub(super) fn separation(p: &[DVec2], q: &[DVec2]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    for (a, b) in [(p, q), (q, p)] {
        for i in 0..a.len() {
            let e = a[(i + 1) % a.len()] - a[i];
            let Some(n) = DVec2::new(e.y, -e.x).try_normalize() else {
                continue;
            };
            let reach = a
                .iter()
                .map(|&v| n.dot(v))
                .fold(f64::NEG_INFINITY, f64::max);
            let start = b.iter().map(|&v| n.dot(v)).fold(f64::INFINITY, f64::min);
            best = best.max(start - reach);
        }
    }
    best
}

/// The options for a tab of height `height`.
pub(super) fn tab_options(options: &IslandOptions, height: f64) -> TabOptions {
    TabOptions::new(&options.panel, height)
}

/// The map between a tab's 3D plane (the partner face's) and its island's flat frame,
/// for a tab on half-edge `h` (a → b in its face): unfolded about the edge, the tab
/// lies right of a → b in the flat, where its face lies left.
pub(super) struct TabFrame {
    a: DVec3,
    x: DVec3,
    y: DVec3,
    pa: DVec2,
    dx: DVec2,
    right: DVec2,
}

impl TabFrame {
    /// The frame of a tab on `h` whose edge lies flat from `pa` to `pb`.
    pub(super) fn on(mesh: &Mesh, h: HalfedgeId, (pa, pb): (DVec2, DVec2)) -> Self {
        let a = mesh.position(mesh.origin(h));
        let x = (mesh.position(mesh.dest(h)) - a).normalize();
        let n_g = mesh
            .face(h.twin())
            .map_or(DVec3::Z, |g| mesh.face_normal(g));
        let dx = (pb - pa).normalize();
        TabFrame {
            a,
            x,
            y: x.cross(n_g).normalize(),
            pa,
            dx,
            right: DVec2::new(dx.y, -dx.x),
        }
    }

    pub(super) fn flat(&self, p: DVec3) -> DVec2 {
        let d = p - self.a;
        self.pa + d.dot(self.x) * self.dx + d.dot(self.y) * self.right
    }

    fn back(&self, q: DVec2) -> DVec3 {
        let d = q - self.pa;
        self.a + d.dot(self.dx) * self.x + d.dot(self.right) * self.y
    }

    /// Distance of a flat point from the edge's line, toward the tab.
    fn depth(&self, q: DVec2) -> f64 {
        (q - self.pa).dot(self.right)
    }
}

/// A polygon already in an island, and how far a new tab must stay from it.
pub(super) struct Obstacle<'a> {
    pub(super) outline: std::borrow::Cow<'a, [DVec2]>,
    pub(super) need: f64,
}

/// The least step between two corners of a tab cut back (mm).
const TAB_STEP: f64 = 1e-3;

/// The points of `top` (from `from` round to `to`) more than [`TAB_STEP`] from the one
/// before and from `to`: a point the clipping left within a micron of its neighbour
/// is that one, for written to the sheet, so short a step could turn the outline back
/// on itself.
fn stepped(top: impl Iterator<Item = DVec2>, from: DVec2, to: DVec2) -> Vec<DVec2> {
    let mut kept: Vec<DVec2> = Vec::new();
    for q in top {
        if q.distance(*kept.last().unwrap_or(&from)) > TAB_STEP {
            kept.push(q);
        }
    }
    while kept.last().is_some_and(|&q| q.distance(to) <= TAB_STEP) {
        kept.pop();
    }
    kept
}

/// `tab` cut back to keep clear of `obstacles`: each one it comes too near is cut
/// away along that obstacle's side that leaves the most of the tab. `None` when less
/// than half its base or under a third of its area is left. The tab's flat outline
/// (counter-clockwise) comes with it; a tab cut back is marked shortened.
pub(super) fn clear_tab(
    tab: &Tab,
    frame: &TabFrame,
    obstacles: &[Obstacle],
    options: &IslandOptions,
) -> Option<(Tab, Vec<DVec2>)> {
    // Facet order b', a', top…: counter-clockwise, face up.
    let mut poly: Vec<DVec2> = [tab.base[1], tab.base[0]]
        .iter()
        .chain(&tab.top)
        .map(|&p| frame.flat(p))
        .collect();
    let full_area = crate::plane::area(&poly);
    let base_length = tab.base[0].distance(tab.base[1]);
    let mut cut = false;
    for obstacle in obstacles {
        let other = &obstacle.outline;
        if separation(other, &poly) >= obstacle.need {
            continue;
        }
        // The obstacle's side beyond which most of the tab lies.
        let side = (0..other.len())
            .filter_map(|i| {
                let e = other[(i + 1) % other.len()] - other[i];
                let n = DVec2::new(e.y, -e.x).try_normalize()?;
                let start = poly.iter().map(|&q| n.dot(q)).fold(f64::INFINITY, f64::min);
                Some((start - n.dot(other[i]), i, n, e))
            })
            .max_by(|p, q| p.0.total_cmp(&q.0).then(q.1.cmp(&p.1)))?;
        let (_, i, n, e) = side;
        let on = other[i] + obstacle.need * n;
        poly = crate::plane::clip_half_plane(&poly, on + e, on);
        cut = true;
        if poly.len() < 3 {
            return None;
        }
    }
    if !cut {
        return Some((tab.clone(), poly));
    }
    if crate::plane::area(&poly) < full_area / 3.0 {
        return None;
    }
    // The base: the points left on the edge's line, from b' (far along) to a'.
    let scale = base_length.max(1.0);
    let on_base = |q: DVec2| frame.depth(q).abs() <= 1e-9 * scale;
    let along = |q: DVec2| (q - frame.pa).dot(frame.dx);
    let base: Vec<usize> = (0..poly.len()).filter(|&k| on_base(poly[k])).collect();
    let b_end = *base
        .iter()
        .max_by(|&&i, &&j| along(poly[i]).total_cmp(&along(poly[j])))?;
    let a_end = *base
        .iter()
        .min_by(|&&i, &&j| along(poly[i]).total_cmp(&along(poly[j])))?;
    if along(poly[b_end]) - along(poly[a_end]) < 0.5 * base_length {
        return None;
    }
    // Counter-clockwise from a' round the top back to b'.
    let n = poly.len();
    let top = stepped(
        (1..n)
            .map(|k| poly[(a_end + k) % n])
            .take_while(|&q| !on_base(q) || q != poly[b_end])
            .filter(|&q| !on_base(q)),
        poly[a_end],
        poly[b_end],
    );
    if top.is_empty() {
        return None;
    }
    let outline: Vec<DVec2> = [poly[b_end], poly[a_end]]
        .into_iter()
        .chain(top.iter().copied())
        .collect();
    let clearance = 0.5 * options.panel.hole_diameter + options.panel.hole_margin;
    let holes: Vec<DVec3> = tab
        .holes
        .iter()
        .copied()
        .filter(|&p| {
            let q = frame.flat(p);
            crate::plane::contains(&outline, q)
                && crate::plane::distance_to_border(&outline, q) >= clearance
        })
        .collect();
    let cleared = Tab {
        owner: tab.owner,
        base: [frame.back(poly[a_end]), frame.back(poly[b_end])],
        top: top.iter().map(|&q| frame.back(q)).collect(),
        holes_skipped: tab.holes_skipped || holes.len() < tab.holes.len(),
        holes,
        shortened: true,
    };
    Some((cleared, outline))
}

/// True when `hull` fits the usable sheet less `room` (always, without a sheet).
pub(in crate::scheme) fn fits_sheet(hull: &[DVec2], options: &IslandOptions, room: f64) -> bool {
    options
        .panel
        .panel_limit
        .is_none_or(|limit| limit.fits(hull, room))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The axis-aligned square `[x, x + 1] × [0, 1]`, counter-clockwise.
    fn unit_square(x: f64) -> Vec<DVec2> {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(u, v)| DVec2::new(x + u, v))
            .to_vec()
    }

    #[test]
    fn separation_is_the_gap_between_apart_squares_and_negative_when_they_overlap() {
        let p = unit_square(0.0);
        assert!((separation(&p, &unit_square(3.0)) - 2.0).abs() < 1e-12);
        assert!((separation(&unit_square(3.0), &p) - 2.0).abs() < 1e-12);
        assert!(separation(&p, &unit_square(1.0)).abs() < 1e-12, "touching");
        assert!((separation(&p, &unit_square(0.5)) + 0.5).abs() < 1e-12);
    }

    #[test]
    fn stepped_drops_points_within_a_micron_of_their_neighbour_or_the_end() {
        let (from, to) = (DVec2::ZERO, DVec2::new(10.0, 0.0));
        let top = [
            DVec2::new(0.0, 0.5 * TAB_STEP),
            DVec2::new(5.0, 5.0),
            DVec2::new(5.0, 5.0 + 0.5 * TAB_STEP),
            DVec2::new(9.0, 5.0),
            DVec2::new(10.0, 0.5 * TAB_STEP),
        ];
        assert_eq!(
            stepped(top.into_iter(), from, to),
            [DVec2::new(5.0, 5.0), DVec2::new(9.0, 5.0)]
        );
    }

    /// Every half-edge of a cube, its edge laid flat anywhere: the partner face lies
    /// on the tab's side of the edge, and its corners come back to 3D unchanged.
    #[test]
    fn a_tab_frame_lays_the_partner_face_beside_the_edge_and_back() {
        let mesh = crate::mesh::build::cube(40.0);
        let (pa, pb) = (DVec2::new(7.0, -3.0), DVec2::new(7.0, 37.0));
        for h in mesh.half_edges() {
            let frame = TabFrame::on(&mesh, h, (pa, pb));
            assert!(frame.flat(mesh.position(mesh.origin(h))).distance(pa) < 1e-9);
            assert!(frame.flat(mesh.position(mesh.dest(h))).distance(pb) < 1e-9);
            let partner = mesh.face(h.twin()).expect("a closed cube");
            for v in mesh.face_vertices(partner) {
                let p = mesh.position(v);
                let q = frame.flat(p);
                assert!(
                    frame.depth(q) >= -1e-9,
                    "{h:?}: {p} lies on the face's side"
                );
                assert!(frame.back(q).distance(p) < 1e-9, "{h:?}: {p} comes back");
            }
        }
    }

    #[test]
    fn an_island_fits_without_a_sheet_and_on_one_with_its_room_left() {
        let options = crate::scheme::island::test_options(None, 1.0);
        let huge = unit_square(0.0)
            .iter()
            .map(|&p| 1e6 * p)
            .collect::<Vec<_>>();
        assert!(fits_sheet(&huge, &options, 0.0));
        let limited = IslandOptions {
            panel: crate::scheme::PanelOptions {
                panel_limit: Some(crate::scheme::PanelLimit {
                    width: 100.0,
                    height: 50.0,
                    rotations: 4,
                }),
                ..options.panel.clone()
            },
            ..options
        };
        let tall = unit_square(0.0)
            .iter()
            .map(|&p| DVec2::new(40.0 * p.x, 90.0 * p.y))
            .collect::<Vec<_>>();
        assert!(
            fits_sheet(&tall, &limited, 0.0),
            "turned a quarter, 90 × 40"
        );
        assert!(!fits_sheet(&tall, &limited, 10.0), "less 10 mm of room");
    }
}
