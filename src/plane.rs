//! Small 2D geometry used in face planes (schemes), in flat panels (labels) and on
//! sheets (layout): clipping, containment, intersection, distances.

use glam::DVec2;

/// Keeps the part of a convex polygon on the left of the directed line a → b (the
/// line itself included). Points of the polygon on the kept side stay exact.
pub fn clip_half_plane(poly: &[DVec2], a: DVec2, b: DVec2) -> Vec<DVec2> {
    let side = |p: DVec2| (b - a).perp_dot(p - a);
    let mut out = Vec::with_capacity(poly.len() + 1);
    for j in 0..poly.len() {
        let (p, q) = (poly[j], poly[(j + 1) % poly.len()]);
        let (dp, dq) = (side(p), side(q));
        if dp >= 0.0 {
            out.push(p);
        }
        if (dp >= 0.0) != (dq >= 0.0) {
            out.push(p + dp / (dp - dq) * (q - p));
        }
    }
    out
}

/// Clips a polygon by a convex counter-clockwise polygon (Sutherland–Hodgman). The
/// result is the intersection, counter-clockwise when the subject is; points of the
/// subject inside (or on the border of) the clip polygon are kept exactly.
pub fn clip_convex(subject: &[DVec2], clip: &[DVec2]) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = subject.to_vec();
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        out = clip_half_plane(&out, clip[i], clip[(i + 1) % clip.len()]);
    }
    out
}

/// Signed area of a polygon (positive when counter-clockwise).
pub fn signed_area(poly: &[DVec2]) -> f64 {
    0.5 * (0..poly.len())
        .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
        .sum::<f64>()
}

/// `signed_area` of the polygon whose corners are `points[i]` for `i` in `indices`
/// (the same sum in the same order, without collecting the corners).
pub fn loop_signed_area(points: &[DVec2], indices: &[u32]) -> f64 {
    let n = indices.len();
    0.5 * (0..n)
        .map(|i| points[indices[i] as usize].perp_dot(points[indices[(i + 1) % n] as usize]))
        .sum::<f64>()
}

/// Axis-aligned bounds of points: (lower corner, upper corner).
pub fn bounds(points: impl IntoIterator<Item = DVec2>) -> (DVec2, DVec2) {
    points.into_iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// The polygon's corners in counter-clockwise order (reversed when clockwise).
pub fn counter_clockwise(poly: &[DVec2]) -> Vec<DVec2> {
    if signed_area(poly) < 0.0 {
        poly.iter().rev().copied().collect()
    } else {
        poly.to_vec()
    }
}

/// Area of a polygon (absolute).
pub fn area(poly: &[DVec2]) -> f64 {
    signed_area(poly).abs()
}

/// Even-odd point-in-polygon test (points on the border may go either way).
pub fn contains(poly: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Length of a closed polygon's border.
pub fn perimeter(poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|i| poly[i].distance(poly[(i + 1) % poly.len()]))
        .sum()
}

/// Distance from a point to a segment.
pub fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    squared_distance_to_segment(p, a, b).sqrt()
}

/// The square of [`distance_to_segment`].
fn squared_distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance_squared(a + t * ab)
}

/// Distance from a point to a polygon's border. (One square root of the least
/// square: the root is rounded correctly and never decreases, so this is the least
/// of the sides' distances to the bit.)
pub fn distance_to_border(poly: &[DVec2], p: DVec2) -> f64 {
    (0..poly.len())
        .map(|i| squared_distance_to_segment(p, poly[i], poly[(i + 1) % poly.len()]))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// True when segments ab and cd share a point (touching counts).
pub fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    // Segments whose boxes are apart cannot meet; this also keeps two pieces of one
    // straight line, apart on it, from crossing by the rounding of their orientations.
    if a.max(b).cmplt(c.min(d)).any() || c.max(d).cmplt(a.min(b)).any() {
        return false;
    }
    let o = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (d1, d2) = (o(c, d, a), o(c, d, b));
    let (d3, d4) = (o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// Smallest distance between two segments.
pub fn segment_distance(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> f64 {
    if segments_intersect(a, b, c, d) {
        return 0.0;
    }
    distance_to_segment(a, c, d)
        .min(distance_to_segment(b, c, d))
        .min(distance_to_segment(c, a, b))
        .min(distance_to_segment(d, a, b))
}

/// True when a closed polygon's edges cross only at shared corners of neighbouring
/// edges (no self-intersection). O(n²), for panel outlines of modest size.
pub fn is_simple(poly: &[DVec2]) -> bool {
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        for j in i + 1..n {
            // Neighbouring edges share a corner; skip them.
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (c, d) = (poly[j], poly[(j + 1) % n]);
            if segments_intersect(a, b, c, d) {
                return false;
            }
        }
    }
    true
}

/// True when a closed polygon is simple with room to spare: every two edges that do not
/// share a corner stay more than `gap` apart, and at every corner each edge's far end
/// stays more than `gap` from the other edge (no spike folding back on its edge, no
/// corner on a neighbouring edge). A polygon that passes stays simple when its
/// coordinates are rounded by less than half of `gap`. Edges are swept in order of
/// their left end, so long outlines cost little more than their length.
pub fn is_clear(poly: &[DVec2], gap: f64) -> bool {
    let n = poly.len();
    if n < 3 || poly.iter().any(|p| !p.is_finite()) {
        return false;
    }
    for i in 0..n {
        let (a, v, b) = (poly[(i + n - 1) % n], poly[i], poly[(i + 1) % n]);
        if distance_to_segment(b, a, v) <= gap || distance_to_segment(a, v, b) <= gap {
            return false;
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    let left = |i: usize| poly[i].x.min(poly[(i + 1) % n].x);
    order.sort_by(|&i, &j| left(i).total_cmp(&left(j)).then(i.cmp(&j)));
    for (k, &i) in order.iter().enumerate() {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let right = a.x.max(b.x) + gap;
        for &j in &order[k + 1..] {
            if left(j) > right {
                break;
            }
            let neighbours = j == (i + 1) % n || i == (j + 1) % n;
            if !neighbours && segment_distance(a, b, poly[j], poly[(j + 1) % n]) <= gap {
                return false;
            }
        }
    }
    true
}

/// True when the two polygons' interiors or borders meet.
pub fn polygons_touch(p: &[DVec2], q: &[DVec2]) -> bool {
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        for j in 0..q.len() {
            if segments_intersect(a, b, q[j], q[(j + 1) % q.len()]) {
                return true;
            }
        }
    }
    contains(p, q[0]) || contains(q, p[0])
}

/// A part's chosen rotation and bounding box at that rotation.
#[derive(Clone, Copy, Debug)]
pub struct Oriented {
    /// Rotation (radians counter-clockwise).
    pub rotation: f64,
    /// Lower-left corner of the rotated outline's bounding box.
    pub lo: DVec2,
    /// Its width and height.
    pub size: DVec2,
}

/// The smallest bounding box of an outline among `steps` rotations (width, height).
pub fn smallest_box(outline: &[DVec2], steps: u32) -> DVec2 {
    orient(outline, steps, f64::INFINITY, f64::INFINITY).map_or(DVec2::ZERO, |o| o.size)
}

/// True when the outline's bounding box fits `max_w` × `max_h` in one of `steps`
/// rotations.
pub fn fits_rotated(outline: &[DVec2], steps: u32, max_w: f64, max_h: f64) -> bool {
    orient(outline, steps, max_w, max_h).is_some()
}

/// The rotation (among `steps` equal steps) with the smallest bounding box that fits
/// `max_w` × `max_h`, turned to lie flat when that also fits. Steps are counted from
/// the outline's own axis (its smallest bounding rectangle laid flat), as the
/// true-shape nester counts them: the frame an outline comes in means nothing.
pub fn orient(outline: &[DVec2], steps: u32, max_w: f64, max_h: f64) -> Option<Oriented> {
    let steps = steps.max(1);
    let axis = smallest_box_rotation(outline);
    let mut best: Option<(f64, Oriented)> = None;
    for k in 0..steps {
        let rotation = (axis + std::f64::consts::TAU * k as f64 / steps as f64)
            .rem_euclid(std::f64::consts::TAU);
        let turn = DVec2::from_angle(rotation);
        let (lo, hi) = bounds(outline.iter().map(|&p| turn.rotate(p)));
        let size = hi - lo;
        if size.x > max_w || size.y > max_h {
            continue;
        }
        // Smallest area first; among equals prefer flat (wide) boxes.
        let score = size.x * size.y + if size.y > size.x { 1e-9 } else { 0.0 };
        if best.is_none_or(|(b, _)| score < b - 1e-12) {
            best = Some((score, Oriented { rotation, lo, size }));
        }
    }
    best.map(|(_, o)| o)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, s: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x, y),
            DVec2::new(x + s, y),
            DVec2::new(x + s, y + s),
            DVec2::new(x, y + s),
        ]
    }

    #[test]
    fn clipping_two_squares_gives_their_overlap() {
        let clipped = clip_convex(&square(0.0, 0.0, 2.0), &square(1.0, 1.0, 2.0));
        assert!((area(&clipped) - 1.0).abs() < 1e-12);
        assert!(clip_convex(&square(0.0, 0.0, 1.0), &square(5.0, 5.0, 1.0)).is_empty());
    }

    #[test]
    fn containment_distance_and_simplicity() {
        let s = square(0.0, 0.0, 2.0);
        assert!(contains(&s, DVec2::new(1.0, 1.0)));
        assert!(!contains(&s, DVec2::new(3.0, 1.0)));
        assert!((distance_to_border(&s, DVec2::new(1.0, 0.5)) - 0.5).abs() < 1e-12);
        assert!(is_simple(&s));
        let bow = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(!is_simple(&bow));
        assert!(polygons_touch(&s, &square(1.0, 1.0, 2.0)));
        assert!(polygons_touch(&s, &square(0.5, 0.5, 0.5)));
        assert!(!polygons_touch(&s, &square(3.0, 0.0, 1.0)));
        let d = segment_distance(
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 2.0),
            DVec2::new(1.0, 3.0),
        );
        assert!((d - 2.0).abs() < 1e-12);
    }
}

/// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
/// Fewer than three distinct points give those points.
pub fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = points.to_vec();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The rotation (radians) that turns `points` so that their smallest-area bounding
/// rectangle is axis-aligned and at least as wide as it is tall: a side of the convex
/// hull then lies along x. Zero for fewer than three distinct points. Ties keep the
/// first hull edge, so the answer is deterministic.
pub fn smallest_box_rotation(points: &[DVec2]) -> f64 {
    let hull = convex_hull(points);
    if hull.len() < 3 {
        return 0.0;
    }
    let mut best: Option<(f64, f64)> = None;
    for (i, &a) in hull.iter().enumerate() {
        let edge = hull[(i + 1) % hull.len()] - a;
        if edge.length_squared() == 0.0 {
            continue;
        }
        // Turning by -angle(edge) lays the edge along +x.
        let mut rotation = -edge.y.atan2(edge.x);
        let turn = DVec2::from_angle(rotation);
        let (lo, hi) = bounds(hull.iter().map(|&p| turn.rotate(p)));
        let size = hi - lo;
        if size.y > size.x {
            rotation += std::f64::consts::FRAC_PI_2;
        }
        let area = size.x * size.y;
        if best.is_none_or(|(b, _)| area < b * (1.0 - 1e-9)) {
            best = Some((area, rotation));
        }
    }
    best.map_or(0.0, |(_, r)| r.rem_euclid(std::f64::consts::TAU))
}

/// The outline of a simple polygon grown by `r` (r ≥ 0): every edge moved out by `r`,
/// convex corners rounded by a circumscribed polyline of at most 45° per segment (so
/// the result contains the true r-neighbourhood and adds at most four points per
/// corner), reflex corners mitred. Counter-clockwise. The result can overlap itself
/// where a concavity is narrower than 2r; callers check it.
pub fn offset_outline(poly: &[DVec2], r: f64) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = Vec::with_capacity(poly.len());
    for &p in poly {
        if pts.last().is_none_or(|q: &DVec2| q.distance(p) > 1e-9) {
            pts.push(p);
        }
    }
    while pts.len() > 1 && pts[0].distance(pts[pts.len() - 1]) <= 1e-9 {
        pts.pop();
    }
    if signed_area(&pts) < 0.0 {
        pts.reverse();
    }
    let n = pts.len();
    if n < 3 || r <= 0.0 {
        return pts;
    }
    let normal = |a: DVec2, b: DVec2| {
        let e = (b - a).normalize();
        DVec2::new(e.y, -e.x)
    };
    let mut out = Vec::with_capacity(3 * n);
    for i in 0..n {
        let (prev, p, next) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
        let (n1, n2) = (normal(prev, p), normal(p, next));
        let turn = n1.perp_dot(n2).atan2(n1.dot(n2));
        if turn >= 0.0 {
            let segments = (turn / std::f64::consts::FRAC_PI_4).ceil().max(1.0);
            let half = 0.5 * turn / segments;
            let reach = r / half.cos();
            let start = n1.y.atan2(n1.x);
            for j in 0..segments as usize {
                let angle = start + (2.0 * j as f64 + 1.0) * half;
                out.push(p + reach * DVec2::from_angle(angle));
            }
        } else {
            let denominator = (1.0 + n1.dot(n2)).max(0.05);
            out.push(p + r * (n1 + n2) / denominator);
        }
    }
    out
}

/// Segments of the exact offset's round corners, as a share of the radius: their
/// chords fall at most r/800 inside the true arc, which the nester's safety covers.
const ROUND_OFFSET_STEP: f64 = 0.1;

/// The outline of a simple polygon grown by `r` (r ≥ 0), as a polygon that is
/// [`is_clear`] by `gap`: the quick [`offset_outline`] where that is clear; otherwise,
/// where it would fold back or overlap itself (a concavity narrower than 2r, a reflex
/// corner between edges shorter than r), the outer contour of the exact offset region
/// (round corners, on i_overlay's integer grid); and where even that is not clear, the
/// grown convex hull, which only covers more.
pub fn grown_outline(poly: &[DVec2], r: f64, gap: f64) -> Vec<DVec2> {
    let quick = merge_close_corners(offset_outline(poly, r), gap);
    if is_clear(&quick, gap) {
        return quick;
    }
    if let Some(exact) = exact_offset(poly, r)
        .map(|c| merge_close_corners(c, gap))
        .filter(|c| is_clear(c, gap))
    {
        return exact;
    }
    merge_close_corners(offset_outline(&convex_hull(poly), r), gap)
}

/// A closed polygon without the corners that lie within `gap` of the corner kept
/// before them (the first corner is kept).
fn merge_close_corners(poly: Vec<DVec2>, gap: f64) -> Vec<DVec2> {
    let mut kept: Vec<DVec2> = Vec::with_capacity(poly.len());
    for p in poly {
        if kept.last().is_none_or(|q| q.distance(p) > gap) {
            kept.push(p);
        }
    }
    while kept.len() > 1 && kept[0].distance(kept[kept.len() - 1]) <= gap {
        kept.pop();
    }
    kept
}

/// The outer contour of the region within `r` of a polygon (the polygon alone when
/// `r` is 0), counter-clockwise, holes filled: the contour of the largest piece.
fn exact_offset(poly: &[DVec2], r: f64) -> Option<Vec<DVec2>> {
    use i_overlay::core::fill_rule::FillRule;
    use i_overlay::float::simplify::SimplifyShape;
    use i_overlay::mesh::float::outline::offset::OutlineOffset;
    use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
    let contour: Vec<[f64; 2]> = counter_clockwise(poly).iter().map(|p| [p.x, p.y]).collect();
    let region = contour.simplify_shape_as::<i64>(FillRule::NonZero);
    let shapes = if r > 0.0 {
        let mut style = OutlineStyle::new(r);
        style.join = LineJoin::Round(ROUND_OFFSET_STEP);
        region.outline_as::<i64>(&style)
    } else {
        region
    };
    shapes
        .into_iter()
        .filter_map(|shape| shape.into_iter().next())
        .map(|outer| {
            outer
                .into_iter()
                .map(|[x, y]| DVec2::new(x, y))
                .collect::<Vec<_>>()
        })
        .max_by(|a, b| area(a).total_cmp(&area(b)))
        .map(|outer| counter_clockwise(&outer))
}

#[cfg(test)]
mod offset_tests {
    use super::*;

    #[test]
    fn a_spike_or_a_touch_is_not_clear() {
        let square =
            [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)].map(|(x, y)| DVec2::new(x, y));
        assert!(is_clear(&square, 1e-3));
        // A spike folding back along its own edge: simple by `is_simple`, not clear.
        let spiked = [
            (0.0, 0.0),
            (10.0, 0.0),
            (12.0, 2.0),
            (11.0, 1.0001),
            (10.0, 10.0),
            (0.0, 10.0),
        ]
        .map(|(x, y)| DVec2::new(x, y));
        assert!(is_simple(&spiked) && !is_clear(&spiked, 1e-3));
        // A corner within the gap of an edge that does not share it.
        let pinched = [
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 10.0),
            (5.0, 0.0005),
            (0.0, 10.0),
        ]
        .map(|(x, y)| DVec2::new(x, y));
        assert!(!is_clear(&pinched, 1e-3) && is_clear(&pinched, 1e-4));
    }

    #[test]
    fn a_tab_cut_back_beside_a_reflex_corner_grows_into_a_clear_outline() {
        // A half-edge panel of the decimated knight (2 ft, kerf 0.2 mm): its cut-back
        // tab leaves edges a few tenths of a millimetre long beside a reflex corner,
        // which the quick offset by 1.6 mm folds back over.
        let outline: Vec<DVec2> = [
            (-18.61452, -8.88697),
            (-18.73436, -9.04693),
            (-18.07591, -9.04693),
            (-17.57531, -9.54753),
            (-17.56425, -9.55859),
            (-17.55035, -9.56574),
            (-3.03152, -17.03585),
            (-3.00999, -17.04693),
            (-2.98577, -17.04693),
            (-1.74663, -17.04693),
            (-1.72763, -17.04693),
            (-1.70995, -17.03996),
            (17.75562, -9.36540),
            (17.77496, -9.35778),
            (17.78966, -9.34308),
            (18.08581, -9.04693),
            (18.73436, -9.04693),
            (18.62682, -8.89032),
            (0.89459, 16.93204),
            (0.81570, 17.04693),
            (0.73213, 16.93539),
            (0.45716, 16.56839),
            (-0.24829, 16.46725),
            (-0.26370, 16.46504),
            (-0.27772, 16.45825),
            (-14.92864, 9.35629),
            (-14.95049, 9.34569),
            (-14.96505, 9.32626),
            (-17.00072, 6.60921),
            (-17.01729, 6.58709),
            (-17.02015, 6.55961),
            (-18.48367, -7.49351),
            (-18.48495, -7.50582),
            (-18.48319, -7.51806),
            (-18.33955, -8.51997),
        ]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
        assert!(is_clear(&outline, 1e-3));
        let r = 1.6075;
        assert!(!is_clear(&offset_outline(&outline, r), 1e-3));
        let grown = grown_outline(&outline, r, 1e-3);
        assert!(is_clear(&grown, 1e-3) && signed_area(&grown) > 0.0);
        // It holds the whole r-neighbourhood (but for the round corners' chords) and
        // no more than the convex hull's.
        for &p in &outline {
            assert!(contains(&grown, p));
        }
        for (i, &a) in outline.iter().enumerate() {
            let b = outline[(i + 1) % outline.len()];
            let out = DVec2::new(b.y - a.y, a.x - b.x).normalize();
            let mid = 0.5 * (a + b) + (r - 1e-2) * out;
            assert!(contains(&grown, mid), "edge {i}");
        }
        let hull = offset_outline(&convex_hull(&outline), r);
        assert!(area(&grown) <= area(&hull));
    }

    #[test]
    fn a_grown_square_contains_the_neighbourhood_and_stays_close_to_it() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        let grown = offset_outline(&square, 1.0);
        assert!(is_simple(&grown));
        // Each corner turns 90°: two segments of 45°.
        assert_eq!(grown.len(), 8);
        // The exact neighbourhood has area 100 + 4·10 + π; the circumscribed corners
        // add a little, never remove.
        let a = area(&grown);
        let exact = 140.0 + std::f64::consts::PI;
        assert!(a >= exact && a < exact + 0.4, "{a}");
        // Every point at distance 1 from the square is inside or on the result.
        for k in 0..360 {
            let d = DVec2::from_angle(f64::from(k).to_radians());
            let p = DVec2::new(10.0, 10.0) + 0.999 * d;
            assert!(d.x < 0.0 || d.y < 0.0 || contains(&grown, p));
        }
    }

    #[test]
    fn a_reflex_corner_is_mitred_and_clockwise_input_is_turned() {
        // An L shape, clockwise.
        let mut l = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 2.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(2.0, 4.0),
            DVec2::new(0.0, 4.0),
        ];
        l.reverse();
        let grown = offset_outline(&l, 0.5);
        assert!(signed_area(&grown) > 0.0 && is_simple(&grown));
        assert!(grown
            .iter()
            .any(|p| p.distance(DVec2::new(2.5, 2.5)) < 1e-12));
        assert!(convex_hull(&grown).len() < grown.len());
    }

    #[test]
    fn the_smallest_box_rotation_lays_a_turned_rectangle_flat() {
        // A 40 x 10 rectangle turned by 0.6 rad (and its points in a shuffled
        // order): turning it back must give a 40 x 10 box, wide side along x.
        let turn = DVec2::from_angle(0.6);
        let rect: Vec<DVec2> = [(40.0, 10.0), (0.0, 0.0), (0.0, 10.0), (40.0, 0.0)]
            .iter()
            .map(|&(x, y)| turn.rotate(DVec2::new(x, y) + DVec2::new(3.0, -7.0)))
            .collect();
        let back = DVec2::from_angle(smallest_box_rotation(&rect));
        let (lo, hi) = bounds(rect.iter().map(|&p| back.rotate(p)));
        assert!(((hi - lo) - DVec2::new(40.0, 10.0)).abs().max_element() < 1e-9);
        // A right triangle's smallest box has its legs along the axes.
        let triangle = [DVec2::ZERO, DVec2::new(30.0, 0.0), DVec2::new(0.0, 20.0)];
        let quarter = std::f64::consts::FRAC_PI_2;
        let off_axis = smallest_box_rotation(&triangle).rem_euclid(quarter);
        assert!(off_axis.min(quarter - off_axis) < 1e-9);
        assert_eq!(smallest_box_rotation(&triangle[..2]), 0.0);
    }
}
