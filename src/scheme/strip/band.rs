//! A strip: the band of triangles between two curves, or two loops, that bends least
//! (the dynamic programme of the strip paper).

use glam::DVec3;

/// A band of triangles between two curves, each triangle sharing a rung (an edge from
/// one curve to the other) with the next: its corners, those of the first curve
/// first, and its triangles in order, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Strip {
    pub(super) points: Vec<DVec3>,
    pub(super) triangles: Vec<[u32; 3]>,
}

/// The triangles of `strips` by their corners' positions.
pub(super) fn strip_soup(strips: &[Strip]) -> Vec<[DVec3; 3]> {
    strips
        .iter()
        .flat_map(|s| s.triangles.iter().map(|t| t.map(|i| s.points[i as usize])))
        .collect()
}

/// What a triangle facing away from the surface costs, in radians of bending: more
/// than any band bends.
const FOLD_COST: f64 = 1e4;

/// How much a rung's length counts against a radian of bending, per band width: the
/// rungs go across the band, not along it (in a narrow band a triangle's normal says
/// little about the surface, and bending alone would fan far along it), and among
/// bands that bend alike (a flat band bends nowhere) the one of shorter rungs wins.
const RUNG_WEIGHT: f64 = 0.25;

/// The band between the open polylines `p` (below, running with the band on its
/// left) and `q` (above, running the same way), from rung `p[0]q[0]` to the last
/// points' rung, that bends least: the dynamic programme over the triangles that
/// advance along one curve or the other, the cost of each the angle between its
/// normal and the previous triangle's.
pub(super) fn band(p: &[DVec3], q: &[DVec3]) -> Strip {
    band_facing(p, q, None)
}

/// [`band`], with no triangle facing away from the surface where `facing` gives the
/// surface's normal at each point (of `p`, then of `q`): a band between curves that
/// bend (a sector's cut edges) could otherwise fold a triangle over a concave corner,
/// onto its neighbour. Where no band keeps to that, the one with fewest such.
pub(super) fn band_facing(p: &[DVec3], q: &[DVec3], facing: Option<&[DVec3]>) -> Strip {
    let (n, m) = (p.len(), q.len());
    let points: Vec<DVec3> = p.iter().chain(q).copied().collect();
    if n == 0 || m == 0 || n + m < 3 {
        return Strip {
            points,
            triangles: Vec::new(),
        };
    }
    // The band's width: how far, on average, a point of one curve is from the other.
    let width = p
        .iter()
        .map(|a| {
            q.iter()
                .map(|b| a.distance(*b))
                .fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        / n as f64;
    let rungs = Rungs {
        width: width.max(1e-12),
        points: &points,
        n,
        m,
        facing,
    };
    let cost = rungs.costs();
    let triangles = rungs.trace_back(&cost);
    Strip { points, triangles }
}

/// The grid of rungs (i, j) from point i of the lower curve to point j of the upper
/// one, for the dynamic programme of [`band`].
struct Rungs<'a> {
    /// The lower curve's `n` points, then the upper curve's `m`.
    points: &'a [DVec3],
    n: usize,
    m: usize,
    /// The band's mean width, the unit of rung length.
    width: f64,
    /// The surface's normal at each point, if no triangle may face away from it.
    facing: Option<&'a [DVec3]>,
}

impl Rungs<'_> {
    /// The triangle reaching rung (i, j) from the previous rung: along the lower
    /// curve (`k` = 0, advancing i) or the upper one (`k` = 1, advancing j).
    fn triangle(&self, i: usize, j: usize, k: usize) -> [usize; 3] {
        let n = self.n;
        match k {
            0 => [i - 1, i, n + j],
            _ => [i, n + j, n + j - 1],
        }
    }

    /// The rung before (i, j) on the way `k`, if there is one.
    fn before(&self, i: usize, j: usize, k: usize) -> Option<(usize, usize)> {
        match k {
            0 => i.checked_sub(1).map(|i| (i, j)),
            _ => j.checked_sub(1).map(|j| (i, j)),
        }
    }

    /// Whether triangle `t` faces away from the surface at its corners.
    fn faces_away(&self, t: [usize; 3]) -> bool {
        self.facing
            .is_some_and(|normals| self.normal(t).dot(t.map(|i| normals[i]).iter().sum()) < 0.0)
    }

    fn normal(&self, t: [usize; 3]) -> DVec3 {
        let p = self.points;
        (p[t[1]] - p[t[0]])
            .cross(p[t[2]] - p[t[0]])
            .normalize_or_zero()
    }

    /// The bending between two triangles sharing a rung: the angle between their
    /// normals (a half turn where one has no area).
    fn bend(&self, a: [usize; 3], b: [usize; 3]) -> f64 {
        let (x, y) = (self.normal(a), self.normal(b));
        if x == DVec3::ZERO || y == DVec3::ZERO {
            std::f64::consts::PI
        } else {
            x.dot(y).clamp(-1.0, 1.0).acos()
        }
    }

    /// The cost of reaching rung (pi, pj) the way `h` and then going on with triangle
    /// `next`: its cost so far and the bend between the two triangles.
    fn through(
        &self,
        cost: &[[f64; 2]],
        (pi, pj): (usize, usize),
        h: usize,
        next: [usize; 3],
    ) -> f64 {
        let so_far = cost[pi * self.m + pj][h];
        if pi == 0 && pj == 0 {
            so_far
        } else {
            so_far + self.bend(self.triangle(pi, pj, h), next)
        }
    }

    /// `cost[i·m + j][k]`: the least cost of a band from rung (0, 0) to rung (i, j)
    /// whose last triangle went the way `k`.
    fn costs(&self) -> Vec<[f64; 2]> {
        let (n, m) = (self.n, self.m);
        let mut cost = vec![[f64::INFINITY; 2]; n * m];
        cost[0] = [0.0, 0.0];
        for i in 0..n {
            for j in 0..m {
                let length = self.points[i].distance(self.points[n + j]);
                for k in 0..2 {
                    let Some(from) = self.before(i, j, k) else {
                        continue;
                    };
                    let next = self.triangle(i, j, k);
                    let fold = match self.faces_away(next) {
                        true => FOLD_COST,
                        false => 0.0,
                    };
                    let best = (0..2)
                        .filter(|&h| cost[from.0 * m + from.1][h].is_finite())
                        .map(|h| self.through(&cost, from, h, next))
                        .fold(f64::INFINITY, f64::min);
                    cost[i * m + j][k] = best + fold + RUNG_WEIGHT * length / self.width;
                }
            }
        }
        cost
    }

    /// The band's triangles, in order: back from the last rung, each step the way
    /// that gave the rung its cost.
    fn trace_back(&self, cost: &[[f64; 2]]) -> Vec<[u32; 3]> {
        let (mut i, mut j) = (self.n - 1, self.m - 1);
        let last = cost[i * self.m + j];
        let mut k = usize::from(last[1] < last[0]);
        let mut triangles = Vec::with_capacity(self.n + self.m - 2);
        while let Some(from) = self.before(i, j, k) {
            let t = self.triangle(i, j, k);
            triangles.push(t.map(|v| v as u32));
            k = (0..2)
                .filter(|&h| cost[from.0 * self.m + from.1][h].is_finite())
                .min_by(|&a, &b| {
                    let (x, y) = (
                        self.through(cost, from, a, t),
                        self.through(cost, from, b, t),
                    );
                    x.total_cmp(&y)
                })
                .unwrap_or(0);
            (i, j) = from;
        }
        triangles.reverse();
        triangles
    }
}

/// The band between two loops, `p` below and `q` above, running the same way round:
/// cut open at the rung from `p`'s first point to the nearest point of `q`, which
/// then starts and ends both curves. With `normals`, the surface's normal at each
/// point of `p` and `q`, as [`band_facing`] takes them.
pub(super) fn ring_facing(
    p: &[DVec3],
    q: &[DVec3],
    normals: Option<(&[DVec3], &[DVec3])>,
) -> Strip {
    let Some(first) = p.first() else {
        return band(p, q);
    };
    let start = (0..q.len())
        .min_by(|&a, &b| q[a].distance(*first).total_cmp(&q[b].distance(*first)))
        .unwrap_or(0);
    // Both loops opened and closed again: `p` from its first point, `q` from `start`.
    let open = |p: &[DVec3], start: usize| -> Vec<DVec3> {
        p[start..]
            .iter()
            .chain(&p[..start])
            .chain(p.get(start))
            .copied()
            .collect()
    };
    let facing = normals.map(|(np, nq)| {
        let mut both = open(np, 0);
        both.extend(open(nq, start));
        both
    });
    band_facing(&open(p, 0), &open(q, start), facing.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::conform::outline_of;
    use crate::scheme::strip::distance::one_way_distance;
    use crate::scheme::strip::test_shapes::{tube, two_lines, unroll};

    #[test]
    fn the_band_between_a_cylinders_rims_is_its_surface_and_unrolls_to_its_rectangle() {
        let around = 16;
        let tube = tube(around, 1, 80.0, |_| 30.0);
        let rims: Vec<Vec<DVec3>> = [0.0, 80.0]
            .iter()
            .map(|&h| tube.points.iter().copied().filter(|p| p.z == h).collect())
            .collect();
        let strip = ring_facing(&rims[0], &rims[1], None);
        assert_eq!(strip.triangles.len(), 2 * around);
        // Every corner on the outline: no vertex inside the band.
        let outline = outline_of(&strip);
        for v in strip.triangles.iter().flatten() {
            assert!(
                outline.iter().any(|&(_, a, b)| a == *v || b == *v),
                "{v} inside"
            );
        }
        // The band is the tube itself, both ways.
        let (band_soup, tube_soup) = (strip_soup(std::slice::from_ref(&strip)), tube.soup());
        assert!(one_way_distance(&band_soup, &tube_soup, 1.0) < 1e-9);
        assert!(one_way_distance(&tube_soup, &band_soup, 1.0) < 1e-9);
        // Unrolled, every edge keeps its length, and the band is a rectangle as long as
        // the rim's polygon.
        let flat = unroll(&strip);
        for t in &strip.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let d3 = strip.points[a].distance(strip.points[b]);
                assert!((flat[a].distance(flat[b]) - d3).abs() < 1e-9 * 80.0);
            }
        }
        // The rim below (the first around + 1 corners, its first point again at the
        // end) lies on one line as long as the rim's polygon, the rim above on the line
        // parallel to it 80 mm away.
        let side = 2.0 * 30.0 * (std::f64::consts::PI / around as f64).sin();
        let (start, end) = (flat[0], flat[around]);
        assert!((start.distance(end) - around as f64 * side).abs() < 1e-9);
        let along = (end - start).normalize();
        for (k, p) in flat.iter().enumerate() {
            let off = along.perp_dot(*p - start);
            let expected = if k <= around { 0.0 } else { 80.0 };
            assert!((off - expected).abs() < 1e-9, "corner {k}: {off}");
        }
    }

    #[test]
    fn a_band_between_straight_lines_in_a_plane_does_not_bend() {
        let (p, q) = two_lines();
        let strip = band(&p, &q);
        assert_eq!(strip.triangles.len(), p.len() + q.len() - 2);
        for t in &strip.triangles {
            let [a, b, c] = t.map(|i| strip.points[i as usize]);
            let normal = (b - a).cross(c - a);
            assert!(normal.z > 0.0, "counter-clockwise: {normal}");
        }
    }
}
