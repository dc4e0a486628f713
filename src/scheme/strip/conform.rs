//! The strips made to meet point for point: their points a rounding apart welded into
//! one, and each point on another strip's outline edge made a corner of that edge.

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;

use super::band::Strip;
use super::distance::has_area;
use super::surface::{cycle_pairs, edge_uses, renumbered};
use crate::mesh::distance::segment_distance;
use crate::union_find::UnionFind;

/// How far a point may be from an outline edge and count as on it (mm).
const ON_EDGE: f64 = 1e-6;

/// Every point of a strip's outline that lies inside an outline edge of another
/// strip (where a band split on its own meets one that is not) made a corner of that
/// edge too, its triangle fanned from the opposite corner, so the strips meet point
/// for point.
pub(super) fn conform(strips: &mut [Strip]) {
    weld_near(strips);
    let outlines: Vec<Vec<(usize, u32, u32)>> = strips.iter().map(outline_of).collect();
    let mut lengths: Vec<f64> = Vec::new();
    let mut points: BTreeMap<[u64; 3], DVec3> = BTreeMap::new();
    for (strip, outline) in strips.iter().zip(&outlines) {
        for &(_, a, b) in outline {
            let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
            lengths.push(pa.distance(pb));
            points.insert(pa.to_array().map(f64::to_bits), pa);
        }
    }
    if lengths.is_empty() {
        return;
    }
    let cell = (lengths.iter().sum::<f64>() / lengths.len() as f64).max(1e-6);
    let at = |p: DVec3| (p / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<DVec3>> = HashMap::new();
    for p in points.values() {
        grid.entry(at(*p)).or_default().push(*p);
    }
    for (strip, outline) in strips.iter_mut().zip(outlines) {
        for (_, a, b) in outline {
            let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
            let inside = points_inside(pa, pb, cell, &|c| {
                grid.get(&at(c)).map_or(&[][..], |v| &v[..])
            });
            if !inside.is_empty() {
                split_outline_edge(strip, a, b, &inside);
            }
        }
    }
}

/// How close two points of the strips are taken for one (mm): the same crossing found
/// from levels a rounding apart.
const SAME_POINT: f64 = 1e-7;

/// The strips' points within [`SAME_POINT`] of each other moved onto one of them (the
/// least by its bits), so that strips meeting there share it.
fn weld_near(strips: &mut [Strip]) {
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let cell = 1e3 * SAME_POINT;
    let at = |p: DVec3| (p / cell).floor().as_ivec3().to_array();
    let mut grid: HashMap<[i32; 3], Vec<DVec3>> = HashMap::new();
    let mut all: BTreeMap<[u64; 3], DVec3> = BTreeMap::new();
    for p in strips.iter().flat_map(|s| s.points.iter()) {
        all.insert(key(*p), *p);
    }
    for p in all.values() {
        grid.entry(at(*p)).or_default().push(*p);
    }
    let mut moved: HashMap<[u64; 3], DVec3> = HashMap::new();
    for p in all.values() {
        let mut least = *p;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let [x, y, z] = at(*p);
                    for &q in grid.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                        if q.distance(*p) < SAME_POINT && key(q) < key(least) {
                            least = q;
                        }
                    }
                }
            }
        }
        if least != *p {
            moved.insert(key(*p), least);
        }
    }
    for strip in strips.iter_mut() {
        for p in &mut strip.points {
            if let Some(&q) = moved.get(&key(*p)) {
                *p = q;
            }
        }
        collapse_short_edges(strip);
    }
}

/// `strip` with the ends of each of its outline edges that welding left without
/// length made one point, and the triangles left without area dropped (a crossing
/// welded onto the corner of its own edge). Its neighbours on either side of such a
/// triangle share the rung it had, so the strip still runs triangle by triangle. A
/// rung without length (where its two curves touch) stays: its two triangles are the
/// strip's only link there.
fn collapse_short_edges(strip: &mut Strip) {
    let mut sets = UnionFind::new(strip.points.len());
    let mut any = false;
    let uses = edge_uses(&strip.triangles);
    for t in &strip.triangles {
        for (a, b) in cycle_pairs(t) {
            let outline = uses[&(a.min(b), a.max(b))] == 1;
            if outline && strip.points[a as usize] == strip.points[b as usize] {
                sets.union(a, b);
                any = true;
            }
        }
    }
    if !any {
        return;
    }
    let corners: Vec<[u32; 3]> = strip
        .triangles
        .iter()
        .map(|t| t.map(|v| sets.find(v)))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    let (ids, corners) = renumbered(&corners);
    strip.points = ids.iter().map(|&i| strip.points[i as usize]).collect();
    strip.triangles = corners;
}

/// The points `near` gives (by the cell of a point) that lie inside segment `a`–`b`,
/// from `a`.
fn points_inside<'a>(
    a: DVec3,
    b: DVec3,
    cell: f64,
    near: &dyn Fn(DVec3) -> &'a [DVec3],
) -> Vec<DVec3> {
    let length = a.distance(b);
    let steps = (2.0 * length / cell).ceil() as usize + 1;
    let mut found: Vec<(f64, DVec3)> = Vec::new();
    let mut seen: std::collections::BTreeSet<[u64; 3]> = Default::default();
    for k in 0..=steps {
        let sample = a.lerp(b, k as f64 / steps as f64);
        for dx in [-1.0, 0.0, 1.0] {
            for dy in [-1.0, 0.0, 1.0] {
                for dz in [-1.0, 0.0, 1.0] {
                    for &p in near(sample + cell * DVec3::new(dx, dy, dz)) {
                        if p == a || p == b || !seen.insert(p.to_array().map(f64::to_bits)) {
                            continue;
                        }
                        let t = (p - a).dot(b - a) / (length * length);
                        if t > 0.0 && t < 1.0 && segment_distance(p, a, b) < ON_EDGE {
                            found.push((t, p));
                        }
                    }
                }
            }
        }
    }
    found.sort_by(|x, y| x.0.total_cmp(&y.0));
    found.into_iter().map(|f| f.1).collect()
}

/// Whether an edge of `strip` (its corners taken by position, as the strips are
/// welded) is a side of more than two of its triangles that cover something.
pub(super) fn runs_back(strip: &Strip) -> bool {
    let mut id: HashMap<[u64; 3], u32> = HashMap::new();
    let welded: Vec<u32> = strip
        .points
        .iter()
        .map(|p| {
            let next = id.len() as u32;
            *id.entry(p.to_array().map(f64::to_bits)).or_insert(next)
        })
        .collect();
    let covering: Vec<[u32; 3]> = strip
        .triangles
        .iter()
        .filter(|t| has_area(t.map(|i| strip.points[i as usize])))
        .map(|t| t.map(|i| welded[i as usize]))
        .collect();
    edge_uses(&covering).values().any(|&n| n > 2)
}

/// The outline edges of `strip`: each triangle's side (index, from, to, as the
/// triangle runs) no other of its triangles has.
pub(super) fn outline_of(strip: &Strip) -> Vec<(usize, u32, u32)> {
    let uses = edge_uses(&strip.triangles);
    let mut outline = Vec::new();
    for (k, t) in strip.triangles.iter().enumerate() {
        for (a, b) in cycle_pairs(t) {
            if uses[&(a.min(b), a.max(b))] == 1 {
                outline.push((k, a, b));
            }
        }
    }
    outline
}

/// `strip` with `inside` (points on its outline edge `a`→`b`, from `a`) made corners:
/// the edge's triangle fanned from its third corner, in the order that keeps each
/// triangle sharing a side with the next.
fn split_outline_edge(strip: &mut Strip, a: u32, b: u32, inside: &[DVec3]) {
    let Some(k) = strip
        .triangles
        .iter()
        .position(|t| cycle_pairs(t).any(|e| e == (a, b)))
    else {
        return;
    };
    let t = strip.triangles[k];
    let r = t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
    let first = strip.points.len() as u32;
    strip.points.extend_from_slice(inside);
    let chain: Vec<u32> = std::iter::once(a)
        .chain(first..first + inside.len() as u32)
        .chain(std::iter::once(b))
        .collect();
    let mut fan: Vec<[u32; 3]> = chain.windows(2).map(|w| [w[0], w[1], r]).collect();
    let has = |t: &[u32; 3], u: u32, v: u32| t.contains(&u) && t.contains(&v);
    let from_b = match k.checked_sub(1) {
        Some(before) => has(&strip.triangles[before], b, r),
        None => strip
            .triangles
            .get(k + 1)
            .is_some_and(|next| has(next, a, r)),
    };
    if from_b {
        fan.reverse();
    }
    strip.triangles.splice(k..k + 1, fan);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::band::band;
    use crate::scheme::strip::test_shapes::{check_strips_cut, cover, heights, tube, two_lines};

    #[test]
    fn a_strip_that_comes_back_over_a_triangle_runs_back_and_a_band_does_not() {
        let (p, q) = two_lines();
        let strip = band(&p, &q);
        assert!(!runs_back(&strip));
        // Back over its first triangle, through a second point at the same place as
        // one of its corners (as a bridge between two loops is walked both ways).
        let mut back = strip.clone();
        let [a, b, c] = back.triangles[0];
        back.points.push(back.points[a as usize]);
        let again = back.points.len() as u32 - 1;
        back.triangles.push([again, c, b]);
        assert!(runs_back(&back));
        // A triangle with no area (its corners welded) is not counted.
        let mut flat = strip.clone();
        flat.points.push(flat.points[a as usize]);
        flat.triangles.push([a, flat.points.len() as u32 - 1, b]);
        assert!(!runs_back(&flat));
    }

    #[test]
    fn a_barrel_cut_into_sectors_has_no_edge_of_no_length() {
        // A level of its grown bands lands a rounding away from its middle row of
        // points: the crossings there are welded onto the points they sit on.
        let barrel = tube(48, 24, 120.0, |h| {
            40.0 + 20.0 * (std::f64::consts::PI * h / 120.0).sin()
        });
        let strips = cover(&barrel, &heights(&barrel), 1.0, 200.0)
            .unwrap()
            .strips;
        for strip in &strips {
            for t in &strip.triangles {
                for (a, b) in cycle_pairs(t) {
                    let (pa, pb) = (strip.points[a as usize], strip.points[b as usize]);
                    assert!(pa.distance(pb) > SAME_POINT, "an edge of no length at {pa}");
                }
            }
        }
        check_strips_cut(&barrel, &heights(&barrel), 1.0, 200.0);
    }
}
