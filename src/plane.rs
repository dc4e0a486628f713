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

/// Twice the signed area (positive counter-clockwise).
fn twice_area(poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
        .sum()
}

/// Area of a polygon (absolute).
pub fn area(poly: &[DVec2]) -> f64 {
    0.5 * twice_area(poly).abs()
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

/// Distance from a point to a segment.
pub fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

/// Distance from a point to a polygon's border.
pub fn distance_to_border(poly: &[DVec2], p: DVec2) -> f64 {
    (0..poly.len())
        .map(|i| distance_to_segment(p, poly[i], poly[(i + 1) % poly.len()]))
        .fold(f64::INFINITY, f64::min)
}

/// True when segments ab and cd share a point (touching counts).
pub fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
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
