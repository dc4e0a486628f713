//! The surface the strips cover, as triangles over shared corners, and what is read
//! off it: its rims and edges, and the level curves of a field on it, simplified.

use std::collections::BTreeMap;

use glam::DVec3;

use crate::mesh::distance::segment_distance;
use crate::mesh::Mesh;

/// A surface as triangles over shared corners, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Triangles {
    pub(super) points: Vec<DVec3>,
    pub(super) corners: Vec<[u32; 3]>,
}

impl Triangles {
    /// The faces of `mesh`, each fanned from its first corner (the faces are convex).
    pub(super) fn from_mesh(mesh: &Mesh) -> Triangles {
        let mut corners = Vec::new();
        for f in mesh.faces() {
            let ids: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
            for k in 1..ids.len().saturating_sub(1) {
                corners.push([ids[0], ids[k], ids[k + 1]]);
            }
        }
        Triangles {
            points: mesh.positions().to_vec(),
            corners,
        }
    }

    /// The surface with every edge that joins two rim points across it (not along a
    /// rim) split at its middle, the triangles beside it fanned from there: a distance
    /// from the rims is 0 all along such an edge, and no level curve could run
    /// between the rims it joins (a coarse model's holes, a triangle with its three
    /// corners on a rim). The same surface, with more corners.
    pub(super) fn rims_apart(&self) -> Triangles {
        let on_rim: std::collections::BTreeSet<u32> = rims(self).into_iter().flatten().collect();
        let uses = edge_uses(&self.corners);
        let mut points = self.points.clone();
        let mut middles: BTreeMap<(u32, u32), u32> = BTreeMap::new();
        for (&(a, b), &n) in &uses {
            if n == 2 && on_rim.contains(&a) && on_rim.contains(&b) {
                middles.insert((a, b), points.len() as u32);
                points.push(0.5 * (self.points[a as usize] + self.points[b as usize]));
            }
        }
        let mut corners = Vec::with_capacity(self.corners.len());
        for t in &self.corners {
            // The triangle's outline with its middles, fanned from its first middle.
            let mut outline = Vec::with_capacity(6);
            for (a, b) in cycle_pairs(t) {
                outline.push(a);
                outline.extend(middles.get(&(a.min(b), a.max(b))));
            }
            match outline
                .iter()
                .position(|&i| i as usize >= self.points.len())
            {
                None => corners.push(*t),
                Some(first) => {
                    outline.rotate_left(first);
                    corners.extend(
                        (1..outline.len() - 1).map(|k| [outline[0], outline[k], outline[k + 1]]),
                    );
                }
            }
        }
        Triangles { points, corners }
    }

    /// The triangles by their corners' positions.
    pub(super) fn soup(&self) -> Vec<[DVec3; 3]> {
        self.corners
            .iter()
            .map(|c| c.map(|i| self.points[i as usize]))
            .collect()
    }
}

/// A curve on the surface: a polyline, closed (its last point joins its first) or
/// open (its ends on the surface's boundary).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Curve {
    pub(super) points: Vec<DVec3>,
    pub(super) closed: bool,
}

/// The curves where `field` (a value per point of `surface`, linear over each
/// triangle) equals `level`, each running with the side above the level on its left
/// seen from outside. A point exactly at the level counts as above, so every curve
/// crosses edges between a point below and one above, never a corner.
#[cfg_attr(not(test), allow(dead_code))]
pub(super) fn level_curves(surface: &Triangles, field: &[f64], level: f64) -> Vec<Curve> {
    let above = |v: u32| field[v as usize] >= level;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // In a counter-clockwise triangle, the curve runs from the edge leaving the lone
    // corner above to the edge entering it (the corner on its left), and the other
    // way round a lone corner below.
    let mut next: BTreeMap<(u32, u32), (u32, u32)> = BTreeMap::new();
    for &[a, b, c] in &surface.corners {
        for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b)] {
            if above(x) != above(y) && above(x) != above(z) {
                let (leaving, entering) = (key(x, y), key(z, x));
                if above(x) {
                    next.insert(leaving, entering);
                } else {
                    next.insert(entering, leaving);
                }
            }
        }
    }
    let crossing = |(a, b): (u32, u32)| {
        let (fa, fb) = (field[a as usize], field[b as usize]);
        let t = ((level - fa) / (fb - fa)).clamp(0.0, 1.0);
        surface.points[a as usize].lerp(surface.points[b as usize], t)
    };
    chains(&next)
        .into_iter()
        .map(|(edges, closed)| Curve {
            points: edges.into_iter().map(crossing).collect(),
            closed,
        })
        .collect()
}

/// The chains of `next` (each key to the one after it): the open ones from the keys
/// nothing leads to, then the loops, each as its keys and whether it closes.
pub(super) fn chains<K: Ord + Copy>(next: &BTreeMap<K, K>) -> Vec<(Vec<K>, bool)> {
    let entered: std::collections::BTreeSet<K> = next.values().copied().collect();
    let starts: Vec<K> = next
        .keys()
        .filter(|k| !entered.contains(k))
        .chain(next.keys())
        .copied()
        .collect();
    let mut done = std::collections::BTreeSet::new();
    let mut chains = Vec::new();
    for start in starts {
        if !done.insert(start) {
            continue;
        }
        let mut keys = vec![start];
        let mut at = start;
        let mut closed = false;
        while let Some(&n) = next.get(&at) {
            if n == start {
                closed = true;
                break;
            }
            if !done.insert(n) {
                break;
            }
            keys.push(n);
            at = n;
        }
        chains.push((keys, closed));
    }
    chains
}

/// `curve` with the fewest points (Douglas–Peucker) that keep every dropped point
/// within `tolerance` of the polyline kept; a loop keeps its first point and the
/// point farthest from it.
#[cfg_attr(not(test), allow(dead_code))]
pub(super) fn simplify(curve: &Curve, tolerance: f64) -> Curve {
    let keep = kept_points(&curve.points, curve.closed, tolerance);
    Curve {
        points: curve
            .points
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&q, _)| q)
            .collect(),
        closed: curve.closed,
    }
}

/// Which of the polyline's points [`simplify`] keeps.
pub(super) fn kept_points(p: &[DVec3], closed: bool, tolerance: f64) -> Vec<bool> {
    if p.len() < 3 {
        return vec![true; p.len()];
    }
    let mut keep = vec![false; p.len()];
    keep[0] = true;
    if closed {
        let far = (1..p.len())
            .max_by(|&a, &b| p[a].distance(p[0]).total_cmp(&p[b].distance(p[0])))
            .unwrap_or(1);
        keep[far] = true;
        // And the point farthest from those two, so that a loop keeps an area.
        let third = (1..p.len()).filter(|&k| k != far).max_by(|&a, &b| {
            let d = |k: usize| segment_distance(p[k], p[0], p[far]);
            d(a).total_cmp(&d(b))
        });
        if let Some(third) = third {
            keep[third] = true;
        }
        keep_within(p, 0, far, tolerance, &mut keep);
        // The second half, round to the first point again.
        let mut round: Vec<DVec3> = p[far..].to_vec();
        round.push(p[0]);
        let mut kept = vec![false; round.len()];
        keep_within(&round, 0, round.len() - 1, tolerance, &mut kept);
        for (k, &flag) in kept.iter().enumerate().take(round.len() - 1) {
            keep[far + k] |= flag;
        }
    } else {
        let last = p.len() - 1;
        keep[last] = true;
        keep_within(p, 0, last, tolerance, &mut keep);
    }
    keep
}

/// Marks in `keep` the points between `from` and `to` that the polyline needs to stay
/// within `tolerance` of every point of `p` there.
fn keep_within(p: &[DVec3], from: usize, to: usize, tolerance: f64, keep: &mut [bool]) {
    let mut spans = vec![(from, to)];
    while let Some((a, b)) = spans.pop() {
        let far = (a + 1..b)
            .map(|k| (k, segment_distance(p[k], p[a], p[b])))
            .max_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((k, d)) = far {
            if d > tolerance {
                keep[k] = true;
                spans.push((a, k));
                spans.push((k, b));
            }
        }
    }
}

/// The rims of `surface`: loops of the edges only one triangle uses, each as its
/// points.
pub(super) fn rims(surface: &Triangles) -> Vec<Vec<u32>> {
    boundary_loops(surface.corners.iter().flat_map(|t| cycle_pairs(t)))
}

/// The loops of the directed edges (each a face's side, faces counter-clockwise)
/// whose reverse is not among them: a surface's boundary, the surface on each loop's
/// left, the loops from their least point.
pub(super) fn boundary_loops(edges: impl Iterator<Item = (u32, u32)>) -> Vec<Vec<u32>> {
    let directed: std::collections::BTreeSet<(u32, u32)> = edges.collect();
    let mut next: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            next.entry(a).or_default().push(b);
        }
    }
    let mut loops = Vec::new();
    while let Some((&start, _)) = next.iter().find(|(_, to)| !to.is_empty()) {
        let mut ring = vec![start];
        let mut at = start;
        while let Some(to) = next.get_mut(&at).and_then(|to| to.pop()) {
            if to == start {
                break;
            }
            ring.push(to);
            at = to;
        }
        loops.push(ring);
    }
    loops
}

/// The consecutive pairs of a loop's corners, the last with the first.
pub(super) fn cycle_pairs(corners: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    corners
        .iter()
        .copied()
        .zip(corners.iter().copied().cycle().skip(1))
}

/// How many of `triangles` use each edge (by its corners, lower first).
pub(super) fn edge_uses(triangles: &[[u32; 3]]) -> BTreeMap<(u32, u32), u32> {
    let mut uses: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for t in triangles {
        for (a, b) in cycle_pairs(t) {
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    uses
}

/// The points `corners` use, increasing, and the corners as indices into them.
pub(super) fn renumbered(corners: &[[u32; 3]]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut ids: Vec<u32> = corners.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let index = |i: u32| ids.binary_search(&i).unwrap_or(0) as u32;
    let corners = corners.iter().map(|t| t.map(index)).collect();
    (ids, corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::test_shapes::{heights, tube};

    #[test]
    fn a_level_of_a_tube_is_one_loop_round_it_with_the_top_on_its_left() {
        let tube = tube(24, 4, 100.0, |_| 50.0);
        let curves = level_curves(&tube, &heights(&tube), 37.5);
        assert_eq!(curves.len(), 1);
        let loop_ = &curves[0];
        assert!(loop_.closed);
        assert_eq!(loop_.points.len(), 48, "one point per crossed edge");
        for p in &loop_.points {
            assert!((p.z - 37.5).abs() < 1e-9);
        }
        // Running counter-clockwise seen from above (+z): the top on its left seen
        // from outside.
        let turn: f64 = loop_
            .points
            .iter()
            .zip(loop_.points.iter().cycle().skip(1))
            .map(|(a, b)| a.x * b.y - a.y * b.x)
            .sum();
        assert!(turn > 0.0, "{turn}");
    }

    #[test]
    fn a_level_across_an_open_tube_is_two_curves_from_rim_to_rim() {
        let tube = tube(24, 4, 100.0, |_| 50.0);
        let across: Vec<f64> = tube.points.iter().map(|p| p.x).collect();
        let curves = level_curves(&tube, &across, 10.0);
        assert_eq!(curves.len(), 2, "{curves:?}");
        for c in &curves {
            assert!(!c.closed);
            let ends = [c.points[0].z, c.points[c.points.len() - 1].z];
            assert!(ends == [0.0, 100.0] || ends == [100.0, 0.0], "{ends:?}");
            assert!(c.points.iter().all(|p| (p.x - 10.0).abs() < 1e-9));
        }
    }

    #[test]
    fn simplifying_keeps_every_point_within_the_tolerance() {
        let tube = tube(64, 1, 10.0, |_| 100.0);
        let loop_ = &level_curves(&tube, &heights(&tube), 5.0)[0];
        let coarse = simplify(loop_, 2.0);
        assert!(
            coarse.points.len() < loop_.points.len() / 2,
            "{}",
            coarse.points.len()
        );
        let n = coarse.points.len();
        for p in &loop_.points {
            let d = (0..n)
                .map(|k| segment_distance(*p, coarse.points[k], coarse.points[(k + 1) % n]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 2.0 + 1e-9, "{d}");
        }
    }
}
