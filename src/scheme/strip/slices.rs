//! The surface cut along levels of the field into regions between neighbouring levels,
//! and the strip of each region between its curves (its loops bridged into one where
//! it has more than one on a level).

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;

use super::band::{band_facing, ring_facing, Strip};
use super::patch::Patch;
use super::surface::{boundary_loops, chains, cycle_pairs, kept_points, renumbered, Triangles};
use crate::union_find::UnionFind;

/// Where a point of the sliced surface comes from: a corner of the surface, or where
/// a level crosses one of its edges (the edge by its corners, lower first).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Origin {
    Corner(u32),
    Crossing { edge: (u32, u32), level: u32 },
}

impl Origin {
    /// Whether the point lies on the surface's edge `(a, b)` (lower first).
    fn on_edge(&self, edge: (u32, u32)) -> bool {
        match *self {
            Origin::Corner(v) => v == edge.0 || v == edge.1,
            Origin::Crossing { edge: e, .. } => e == edge,
        }
    }
}

/// The surface cut along the levels of a field: each triangle split into the convex
/// pieces between neighbouring levels, the pieces' corners shared.
pub(super) struct Slices {
    /// The levels, increasing; band `k` lies between `levels[k]` and `levels[k + 1]`.
    levels: Vec<f64>,
    points: Vec<DVec3>,
    origins: Vec<Origin>,
    /// The field's value at each point.
    values: Vec<f64>,
    /// Each piece: its band and its corners (indices into `points`), counter-clockwise.
    pieces: Vec<(usize, Vec<u32>)>,
    /// The field's values the first and last levels stand for, where the surface is a
    /// patch whose outline lies on them (its corners there are on those levels).
    held: Option<[f64; 2]>,
}

/// A region of one band: the pieces of the band joined across their shared edges.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Region {
    pub(super) band: usize,
    /// Its boundary loops, each with the region on its left seen from outside, as
    /// indices into the slices' points.
    loops: Vec<Vec<u32>>,
    /// Its pieces' triangles (fans of the convex pieces), for measuring.
    pub(super) triangles: Vec<[DVec3; 3]>,
    /// Its pieces, as indices into the slices'.
    pieces: Vec<usize>,
}

impl Slices {
    /// `surface` cut along `levels` (increasing, none equal to a value of `field` at a
    /// corner, so every cut crosses edges between their ends). On a patch, its corners
    /// at the values `held` (below the second level and above the last but one) lie on
    /// the first and last levels.
    pub(super) fn new(
        surface: &Triangles,
        field: &[f64],
        levels: Vec<f64>,
        held: Option<[f64; 2]>,
    ) -> Slices {
        let mut slices = Slices {
            levels,
            points: Vec::new(),
            origins: Vec::new(),
            values: Vec::new(),
            pieces: Vec::new(),
            held,
        };
        // Looked up only: points are numbered in the order they are first met.
        let mut ids: HashMap<Origin, u32> = HashMap::new();
        for corners in &surface.corners {
            // The triangle as (origin, value, position) corners.
            let start: Vec<(Origin, f64, DVec3)> = corners
                .iter()
                .map(|&v| {
                    (
                        Origin::Corner(v),
                        field[v as usize],
                        surface.points[v as usize],
                    )
                })
                .collect();
            let lo = start.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
            let hi = start.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
            for band in 0..slices.levels.len().saturating_sub(1) {
                let (below, above) = (slices.levels[band], slices.levels[band + 1]);
                if hi < below || lo > above {
                    continue;
                }
                let piece = clip(
                    &clip(&start, band as u32, below, true),
                    band as u32 + 1,
                    above,
                    false,
                );
                if piece.len() < 3 {
                    continue;
                }
                let corners = piece
                    .iter()
                    .map(|&(origin, value, position)| {
                        *ids.entry(origin).or_insert_with(|| {
                            slices.points.push(position);
                            slices.origins.push(origin);
                            slices.values.push(value);
                            slices.points.len() as u32 - 1
                        })
                    })
                    .collect();
                slices.pieces.push((band, corners));
            }
        }
        slices
    }

    /// The position of point `id`.
    fn point(&self, id: u32) -> DVec3 {
        self.points[id as usize]
    }

    /// The level point `id` lies on, if it is a crossing.
    fn level_of(&self, id: u32) -> Option<usize> {
        match self.origins[id as usize] {
            Origin::Crossing { level, .. } => Some(level as usize),
            Origin::Corner(_) => {
                let [below, above] = self.held?;
                let value = self.values[id as usize];
                match (value == below, value == above) {
                    (true, _) => Some(0),
                    (_, true) => Some(self.levels.len() - 1),
                    _ => None,
                }
            }
        }
    }

    /// Whether point `id` is where a level crosses an edge of the surface.
    fn is_crossing(&self, id: u32) -> bool {
        matches!(self.origins[id as usize], Origin::Crossing { .. })
    }

    /// The regions: per band, its pieces joined across shared edges, in band order
    /// and then by their first piece.
    pub(super) fn regions(&self) -> Vec<Region> {
        self.regions_where(|_| true)
    }

    /// The regions of `band` alone (as [`Slices::regions`] gives them), without
    /// building the others.
    pub(super) fn regions_of(&self, band: usize) -> Vec<Region> {
        self.regions_where(|b| b == band)
    }

    /// The regions of the bands `wanted` takes, in band order and then by their first
    /// piece.
    fn regions_where(&self, wanted: impl Fn(usize) -> bool) -> Vec<Region> {
        let mut sets = UnionFind::new(self.pieces.len());
        let mut first_by_edge: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for (k, (band, corners)) in self.pieces.iter().enumerate() {
            if !wanted(*band) {
                continue;
            }
            for (a, b) in cycle_pairs(corners) {
                match first_by_edge.entry((a.min(b), a.max(b))) {
                    std::collections::btree_map::Entry::Vacant(e) => {
                        e.insert(k);
                    }
                    std::collections::btree_map::Entry::Occupied(e) => {
                        let other = *e.get();
                        if self.pieces[other].0 == *band {
                            sets.union(other as u32, k as u32);
                        }
                    }
                }
            }
        }
        let mut members: BTreeMap<(usize, u32), Vec<usize>> = BTreeMap::new();
        for k in (0..self.pieces.len()).filter(|&k| wanted(self.pieces[k].0)) {
            let r = sets.find(k as u32);
            members.entry((self.pieces[k].0, r)).or_default().push(k);
        }
        members
            .into_iter()
            .map(|((band, _), pieces)| self.region(band, &pieces))
            .collect()
    }

    /// The region of `band` made of `pieces`: its boundary (the piece edges no other
    /// of its pieces shares) chained into loops, and its triangles.
    fn region(&self, band: usize, pieces: &[usize]) -> Region {
        let loops = boundary_loops(pieces.iter().flat_map(|&k| cycle_pairs(&self.pieces[k].1)));
        let triangles = self
            .fans(pieces)
            .map(|t| t.map(|i| self.point(i)))
            .collect();
        Region {
            band,
            loops,
            triangles,
            pieces: pieces.to_vec(),
        }
    }

    /// The triangles of `pieces`, each convex piece fanned from its first corner.
    fn fans<'a>(&'a self, pieces: &'a [usize]) -> impl Iterator<Item = [u32; 3]> + 'a {
        pieces.iter().flat_map(|&k| {
            let c = &self.pieces[k].1;
            (1..c.len() - 1).map(move |i| [c[0], c[i], c[i + 1]])
        })
    }
}

impl Slices {
    /// Which points the strips keep: the surface's corners `corner_kept` says, and of
    /// each level's curves the fewest points within `tolerance` of them
    /// ([`kept_points`]), the same for the regions on either side of the curve.
    pub(super) fn kept(&self, tolerance: f64, corner_kept: &dyn Fn(u32) -> bool) -> Vec<bool> {
        let mut keep: Vec<bool> = self
            .origins
            .iter()
            .map(|o| match *o {
                Origin::Corner(v) => corner_kept(v),
                Origin::Crossing { .. } => false,
            })
            .collect();
        // Each level's curves, from the edges of the pieces above it that lie on it.
        let mut next: BTreeMap<u32, u32> = BTreeMap::new();
        for (band, corners) in &self.pieces {
            for (a, b) in cycle_pairs(corners) {
                let on = |i: u32| self.is_crossing(i) && self.level_of(i) == Some(*band);
                if on(a) && on(b) {
                    next.insert(a, b);
                }
            }
        }
        for (ids, closed) in chains(&next) {
            let points: Vec<DVec3> = ids.iter().map(|&i| self.point(i)).collect();
            for (&id, k) in ids.iter().zip(kept_points(&points, closed, tolerance)) {
                keep[id as usize] |= k;
            }
        }
        keep
    }

    /// `region` as a patch of its own: its pieces fanned into triangles, keeping the
    /// points `kept`, between its band's levels (or the values they stand for).
    pub(super) fn patch(&self, region: &Region, kept: &[bool]) -> Patch {
        let fans: Vec<[u32; 3]> = self.fans(&region.pieces).collect();
        let (ids, corners) = renumbered(&fans);
        let last = self.levels.len() - 1;
        let end = |level: usize| match (self.held, level) {
            (Some(held), 0) => held[0],
            (Some(held), l) if l == last => held[1],
            _ => self.levels[level],
        };
        Patch {
            surface: Triangles {
                points: ids.iter().map(|&i| self.point(i)).collect(),
                corners,
            },
            values: ids.iter().map(|&i| self.values[i as usize]).collect(),
            kept: ids.iter().map(|&i| kept[i as usize]).collect(),
            ends: [end(region.band), end(region.band + 1)],
        }
    }

    /// The strip of `region`, its corners the points `kept`: between its two loops
    /// (one on each level), or, for a region with one loop, between the run of that
    /// loop on its lower level (or half of it) and the rest.
    /// With `facing`, no triangle faces away from the surface ([`band_facing`]).
    pub(super) fn strip(
        &self,
        region: &Region,
        kept: &[bool],
        facing: bool,
    ) -> Result<Strip, String> {
        let loops: Vec<Vec<u32>> = region
            .loops
            .iter()
            .map(|l| l.iter().copied().filter(|&i| kept[i as usize]).collect())
            .collect();
        let positions = |ids: &[u32]| ids.iter().map(|&i| self.point(i)).collect::<Vec<_>>();
        // A loop is on a level if all its points are: crossings of the level, or a rim
        // where the field is held at one value (a pole's) nearer that level.
        let on = |ids: &[u32], level: usize| {
            let rim = ids.iter().all(|&i| self.level_of(i).is_none())
                && ids
                    .windows(2)
                    .all(|w| self.values[w[0] as usize] == self.values[w[1] as usize]);
            let middle = 0.5 * (self.levels[region.band] + self.levels[region.band + 1]);
            match ids.first() {
                Some(&first) if rim => {
                    (self.values[first as usize] < middle) == (level == region.band)
                }
                _ => ids.iter().all(|&i| self.level_of(i) == Some(level)),
            }
        };
        let lower: Vec<Vec<u32>> = loops
            .iter()
            .filter(|l| on(l, region.band))
            .cloned()
            .collect();
        let upper: Vec<Vec<u32>> = loops
            .iter()
            .filter(|l| on(l, region.band + 1))
            .cloned()
            .collect();
        let unjoined = || {
            format!(
                "the {} boundary loops of a region between levels {} and {} are not joined \
                 by its pieces",
                loops.len(),
                region.band,
                region.band + 1
            )
        };
        if loops.is_empty() {
            return Err(format!(
                "a region between levels {} and {} has no boundary (a closed part)",
                region.band,
                region.band + 1
            ));
        }
        if !lower.is_empty() && !upper.is_empty() && lower.len() + upper.len() == loops.len() {
            // Loops on both levels (a saddle's region has two on one of them): the
            // loops of each level joined into one through the region, and the band
            // between the two.
            let below = self.bridged(region, &lower, kept).ok_or_else(unjoined)?;
            let mut above = self.bridged(region, &upper, kept).ok_or_else(unjoined)?;
            above.reverse();
            let normals = facing.then(|| self.normals(region));
            let along = |ids: &[u32], normals: &BTreeMap<u32, DVec3>| {
                ids.iter().map(|i| normals[i]).collect::<Vec<_>>()
            };
            let normals = normals.map(|n| (along(&below, &n), along(&above, &n)));
            let strip = ring_facing(
                &positions(&below),
                &positions(&above),
                normals.as_ref().map(|(b, a)| (&b[..], &a[..])),
            );
            return Ok(strip);
        }
        let one = self.bridged(region, &loops, kept).ok_or_else(unjoined)?;
        let normals = facing.then(|| self.normals(region));
        Ok(self.disk_strip(&one, region.band, normals.as_ref()))
    }

    /// Whether a triangle of `strip` (of `region`) faces away from the surface.
    pub(super) fn folds(&self, region: &Region, strip: &Strip) -> bool {
        let normals = self.normals(region);
        let by_position: HashMap<[u64; 3], DVec3> = normals
            .iter()
            .map(|(&i, &n)| (self.point(i).to_array().map(f64::to_bits), n))
            .collect();
        let normal = |p: DVec3| by_position.get(&p.to_array().map(f64::to_bits)).copied();
        strip.triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| strip.points[i as usize]);
            let sum: Option<DVec3> = [a, b, c].into_iter().map(normal).sum();
            sum.is_some_and(|n| (b - a).cross(c - a).dot(n) < 0.0)
        })
    }

    /// The surface's normal at each corner of `region`'s pieces: the sum of its
    /// pieces' normals there, each as long as twice the piece's area.
    fn normals(&self, region: &Region) -> BTreeMap<u32, DVec3> {
        let mut normals: BTreeMap<u32, DVec3> = BTreeMap::new();
        for &k in &region.pieces {
            let normal: DVec3 = self
                .fans(std::slice::from_ref(&k))
                .map(|t| {
                    let [a, b, d] = t.map(|v| self.point(v));
                    (b - a).cross(d - a)
                })
                .sum();
            for &v in &self.pieces[k].1 {
                *normals.entry(v).or_insert(DVec3::ZERO) += normal;
            }
        }
        normals
    }

    /// The loops of `region` joined into one by bridges (the region then a disk, its
    /// bridges slits run out and back): each time the shortest path through the
    /// region's pieces from the loop joined so far to another loop, keeping of its
    /// corners those inside the region and the loops' kept points only (so that a
    /// neighbouring region meets the same points on their curve).
    fn bridged(&self, region: &Region, loops: &[Vec<u32>], kept: &[bool]) -> Option<Vec<u32>> {
        let mut loop_of: BTreeMap<u32, usize> = BTreeMap::new();
        for (k, l) in loops.iter().enumerate() {
            for &i in l {
                loop_of.insert(i, k);
            }
        }
        let boundary: std::collections::BTreeSet<u32> =
            region.loops.iter().flatten().copied().collect();
        // A bridge keeps the corners inside the region and the loops' kept points; it
        // passes the others of the boundary by.
        let stays =
            |i: u32| loop_of.contains_key(&i) || (!boundary.contains(&i) && kept[i as usize]);
        // Every two corners of a convex piece see each other inside it.
        let mut links: BTreeMap<u32, Vec<(u32, f64)>> = BTreeMap::new();
        for &k in &region.pieces {
            let corners = &self.pieces[k].1;
            for &a in corners {
                for &b in corners {
                    if a != b {
                        links
                            .entry(a)
                            .or_default()
                            .push((b, self.point(a).distance(self.point(b))));
                    }
                }
            }
        }
        let mut merged = loops.first()?.clone();
        let mut joined = vec![false; loops.len()];
        joined[0] = true;
        while joined.iter().any(|j| !j) {
            let (path, other) = shortest_bridge(&merged, &links, |i| {
                loop_of.get(&i).copied().filter(|&k| !joined[k])
            })?;
            joined[other] = true;
            let path: Vec<u32> = path.into_iter().filter(|&i| stays(i)).collect();
            let (from, to) = (path[0], path[path.len() - 1]);
            let at = merged.iter().position(|&i| i == from)?;
            let target = &loops[other];
            let start = target.iter().position(|&i| i == to)?;
            // Out along the bridge, round the other loop, back along the bridge.
            let mut insert: Vec<u32> = path[1..].to_vec();
            insert.extend(target[start + 1..].iter().chain(&target[..start]));
            insert.extend(path.iter().rev());
            merged.splice(at + 1..at + 1, insert);
        }
        Some(merged)
    }

    /// The strip of a region bounded by one loop (region on its left): from the ends of
    /// the loop's longest run on the lower level (or, on a loop with none or all of
    /// it, from its first point to the point halfway round), one side against the other.
    fn disk_strip(
        &self,
        ring_ids: &[u32],
        lower: usize,
        normals: Option<&BTreeMap<u32, DVec3>>,
    ) -> Strip {
        let n = ring_ids.len();
        let low = |k: usize| self.level_of(ring_ids[k % n]) == Some(lower);
        // The longest cyclic run of lower-level points: its start and length.
        let mut best = (0, 0);
        for start in (0..n).filter(|&k| low(k) && !low(k + n - 1)) {
            let length = (0..n).take_while(|&d| low(start + d)).count();
            if length > best.1 {
                best = (start, length);
            }
        }
        let (start, end) = if best.1 >= 2 && best.1 < n {
            (best.0, best.0 + best.1 - 1)
        } else {
            (0, n / 2)
        };
        let p: Vec<u32> = (start..=end).map(|k| ring_ids[k % n]).collect();
        // The other side, from before `start` back round to after `end`.
        let q: Vec<u32> = (1..n - (end - start))
            .map(|d| ring_ids[(start + n - d) % n])
            .collect();
        let facing: Option<Vec<DVec3>> =
            normals.map(|normals| p.iter().chain(&q).map(|i| normals[i]).collect());
        let at = |ids: &[u32]| ids.iter().map(|&i| self.point(i)).collect::<Vec<_>>();
        band_facing(&at(&p), &at(&q), facing.as_deref())
    }
}

/// The shortest path along `links` from any point of `from` to a point `target`
/// names a loop for, with that loop.
pub(super) fn shortest_bridge(
    from: &[u32],
    links: &BTreeMap<u32, Vec<(u32, f64)>>,
    target: impl Fn(u32) -> Option<usize>,
) -> Option<(Vec<u32>, usize)> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let mut best: BTreeMap<u32, (f64, Option<u32>)> = BTreeMap::new();
    let mut queue = BinaryHeap::new();
    for &i in from {
        best.insert(i, (0.0, None));
        queue.push(Reverse((Distance(0.0), i)));
    }
    while let Some(Reverse((Distance(d), i))) = queue.pop() {
        if best.get(&i).is_some_and(|&(b, _)| d > b) {
            continue;
        }
        if let Some(other) = target(i) {
            let mut path = vec![i];
            let mut at = i;
            while let Some(&(_, Some(previous))) = best.get(&at) {
                path.push(previous);
                at = previous;
            }
            path.reverse();
            return Some((path, other));
        }
        for &(j, length) in links.get(&i).into_iter().flatten() {
            let through = d + length;
            if best.get(&j).is_none_or(|&(b, _)| through < b) {
                best.insert(j, (through, Some(i)));
                queue.push(Reverse((Distance(through), j)));
            }
        }
    }
    None
}

/// A path length ordered totally, for the search's queue.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Distance(f64);

impl Eq for Distance {}

impl PartialOrd for Distance {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Distance {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The convex polygon `polygon` (corners with their field value) cut to the side of
/// `value` (level number `level`) above it (`keep_above`) or below it; new corners are
/// crossings of the surface's edges.
fn clip(
    polygon: &[(Origin, f64, DVec3)],
    level: u32,
    value: f64,
    keep_above: bool,
) -> Vec<(Origin, f64, DVec3)> {
    let inside = |f: f64| if keep_above { f > value } else { f < value };
    let mut out = Vec::with_capacity(polygon.len() + 2);
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        if inside(a.1) {
            out.push(a);
        }
        if inside(a.1) != inside(b.1) {
            let edge = surface_edge(a.0, b.0);
            // From the end first by position, so that two patches sharing the edge
            // find the same point to the bit.
            let key = |c: &(Origin, f64, DVec3)| c.2.to_array().map(f64::to_bits);
            let (from, to) = if key(&a) <= key(&b) { (a, b) } else { (b, a) };
            let t = (value - from.1) / (to.1 - from.1);
            out.push((
                Origin::Crossing { edge, level },
                value,
                from.2.lerp(to.2, t),
            ));
        }
    }
    out
}

/// The surface edge both points lie on: a cut crosses only edges of the triangle
/// (a level's own cut is never crossed by another level).
fn surface_edge(a: Origin, b: Origin) -> (u32, u32) {
    let ends = |o: Origin| match o {
        Origin::Corner(v) => [v, v],
        Origin::Crossing { edge, .. } => [edge.0, edge.1],
    };
    let candidates = ends(a).into_iter().chain(ends(b));
    let mut best = (0, 0);
    for x in candidates.clone() {
        for y in candidates.clone() {
            let edge = (x.min(y), x.max(y));
            if x != y && a.on_edge(edge) && b.on_edge(edge) {
                best = edge;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::test_shapes::{
        along, check_strips, check_strips_cut, heights, torus, tube,
    };

    /// The crossings of `field`'s level `level` on `surface` that [`Slices::kept`]
    /// keeps with a tolerance no curve strays beyond: each closed curve's first point
    /// and two more, each open curve's ends.
    fn kept_crossings(surface: &Triangles, field: &[f64], level: f64) -> Vec<DVec3> {
        let slices = Slices::new(surface, field, vec![-1e3, level, 1e3], None);
        let kept = slices.kept(1e9, &|_| false);
        (0..slices.points.len() as u32)
            .filter(|&i| kept[i as usize])
            .map(|i| {
                assert_eq!(slices.level_of(i), Some(1), "a point off the level kept");
                slices.point(i)
            })
            .collect()
    }

    #[test]
    fn a_level_round_a_tube_is_one_loop_and_across_it_two_curves_from_rim_to_rim() {
        let tube = tube(24, 4, 100.0, |_| 50.0);
        let round = kept_crossings(&tube, &heights(&tube), 37.5);
        assert_eq!(round.len(), 3, "one loop: {round:?}");
        assert!(round.iter().all(|p| (p.z - 37.5).abs() < 1e-9));
        let across: Vec<f64> = tube.points.iter().map(|p| p.x).collect();
        let ends = kept_crossings(&tube, &across, 10.0);
        assert_eq!(ends.len(), 4, "two open curves: {ends:?}");
        for p in &ends {
            assert!((p.x - 10.0).abs() < 1e-9, "{p}");
            let off = p.z.abs().min((p.z - 100.0).abs());
            assert!(off < 1e-9, "an end off the rims: {p}");
        }
    }

    #[test]
    fn strips_of_a_torus_bridge_its_saddles() {
        // Along an axis in its plane the field has two saddles, where a band's
        // region has three loops.
        let torus = torus(100.0, 40.0, 48, 24);
        let field = along(&torus, DVec3::new(1.0, 0.2, 0.1));
        check_strips(&torus, &field, 2.0);
        check_strips_cut(&torus, &field, 2.0, 150.0);
    }
}
