//! The surface the strips cover, as triangles over shared corners, and what is read
//! off it: its rims and edges, and its curves chained from their links and simplified.

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

/// Which of the points of the polyline `p` (a loop where `closed`) to keep: those
/// Douglas–Peucker keeps so that every point dropped lies within `tolerance` of the
/// polyline kept. A loop keeps its first point, the point farthest from it and the
/// point farthest from those two.
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

    #[test]
    fn simplifying_keeps_every_point_within_the_tolerance() {
        // A loop of 128 points round a circle of radius 100 mm, as a level of a tube.
        let circle: Vec<DVec3> = (0..128)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 128.0;
                DVec3::new(100.0 * a.cos(), 100.0 * a.sin(), 5.0)
            })
            .collect();
        let keep = kept_points(&circle, true, 2.0);
        let coarse: Vec<DVec3> = circle
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&p, _)| p)
            .collect();
        assert!(coarse.len() < circle.len() / 2, "{}", coarse.len());
        let n = coarse.len();
        for p in &circle {
            let d = (0..n)
                .map(|k| segment_distance(*p, coarse[k], coarse[(k + 1) % n]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 2.0 + 1e-9, "{d}");
        }
    }
}
