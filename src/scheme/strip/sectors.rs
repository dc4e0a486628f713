//! A patch cut across into sectors about as long as the sheet, from its lower curve to
//! its upper one, so that each sector is covered by strips on its own.

use std::collections::BTreeMap;

use super::patch::{CoverSettings, Patch};
use super::slices::shortest_bridge;
use super::surface::{boundary_loops, cycle_pairs, edge_uses, renumbered, Triangles};
use crate::union_find::UnionFind;

/// What cutting a patch across gives.
pub(super) enum Sectors {
    /// The sectors.
    Cut(Vec<Patch>),
    /// None: the patch is no longer than a sector.
    Short,
    /// None: the patch is a cap, one loop round a pole.
    Cap,
    /// None: the patch is not a band between one run of each curve, or has no way across.
    Unfit,
}

impl CoverSettings {
    /// `patch` cut across, from its lower curve to its upper one, into sectors about
    /// [`CoverSettings::sector_length`] long; `None` where it is shorter or has no way across.
    pub(super) fn sectors(&self, patch: &Patch) -> Sectors {
        let corners = &patch.surface.corners;
        let [lo, hi] = patch.ends;
        let value = |i: u32| patch.values[i as usize];
        let loops = boundary_loops(corners.iter().flat_map(|t| cycle_pairs(t)));
        let lower: Vec<(Vec<u32>, bool)> = loops
            .iter()
            .flat_map(|l| runs(l, |i| value(i) == lo))
            .collect();
        let upper = loops
            .iter()
            .flat_map(|l| runs(l, |i| value(i) == hi))
            .count();
        match (loops.len(), lower.as_slice(), upper) {
            (1, [], 1) | (1, [(_, true)], 0) => return Sectors::Cap,
            _ => {}
        }
        let [(run, closed)] = lower.as_slice() else {
            return Sectors::Unfit;
        };
        let sources = self.cut_points(patch, run, *closed);
        if sources.is_empty() {
            return Sectors::Short;
        }
        // Only a ring between its two curves, or a disk with one run on each: round a
        // saddle the sectors would not be bands.
        let ring = loops.len() == 2 && *closed && upper == 1;
        let disk = loops.len() == 1 && upper == 1;
        if !ring && !disk || inner_extremum(patch, &loops) {
            return Sectors::Unfit;
        }
        let across = Across::new(patch, &loops);
        let mut cut: std::collections::BTreeSet<(u32, u32)> = Default::default();
        let mut on_cut = vec![false; patch.values.len()];
        for source in sources {
            let Some((path, _)) = shortest_bridge(&[source], &across.links, |i| {
                (value(i) == hi && patch.kept[i as usize]).then_some(0)
            }) else {
                continue;
            };
            for w in path.windows(2) {
                cut.insert((w[0].min(w[1]), w[0].max(w[1])));
            }
            for &i in &path {
                on_cut[i as usize] = true;
            }
        }
        let groups = joined_triangles(corners, &cut);
        if groups.len() < 2 {
            return Sectors::Unfit;
        }
        let kept = |i: u32| patch.kept[i as usize] || on_cut[i as usize];
        Sectors::Cut(groups.iter().map(|g| sub_patch(patch, g, &kept)).collect())
    }

    /// Where to cut a run of a patch's outline on its lower curve: its kept points
    /// nearest even steps of [`CoverSettings::sector_length`] or less along it (from its first
    /// point on a closed run, between its ends on an open one); none on a run too
    /// short to cut.
    fn cut_points(&self, patch: &Patch, run: &[u32], closed: bool) -> Vec<u32> {
        let at = |i: u32| patch.surface.points[i as usize];
        let mut along = vec![0.0];
        for w in run.windows(2) {
            along.push(along[along.len() - 1] + at(w[0]).distance(at(w[1])));
        }
        let total = match (closed, run.first(), run.last()) {
            (true, Some(&first), Some(&last)) => {
                along[along.len() - 1] + at(last).distance(at(first))
            }
            _ => along[along.len() - 1],
        };
        let sectors = (total / self.sector_length).ceil() as usize;
        if sectors < 2 {
            return Vec::new();
        }
        let steps = if closed { 0..sectors } else { 1..sectors };
        let mut points: Vec<u32> = steps
            .filter_map(|k| {
                let target = total * k as f64 / sectors as f64;
                (0..run.len())
                    .filter(|&j| patch.kept[run[j] as usize])
                    .min_by(|&a, &b| {
                        (along[a] - target)
                            .abs()
                            .total_cmp(&(along[b] - target).abs())
                    })
                    .map(|j| run[j])
            })
            .collect();
        points.dedup();
        points
    }
}

/// Whether the field has an extremum at a point of `patch` inside its outline `loops`
/// (the top of a bump, in a distance field): the patch is then no band, for its levels
/// ring the bump too and meet the band's at a saddle.
fn inner_extremum(patch: &Patch, loops: &[Vec<u32>]) -> bool {
    let outline: std::collections::BTreeSet<u32> = loops.iter().flatten().copied().collect();
    let n = patch.values.len();
    let (mut higher, mut lower) = (vec![false; n], vec![false; n]);
    for t in &patch.surface.corners {
        for (a, b) in cycle_pairs(t) {
            let (va, vb) = (patch.values[a as usize], patch.values[b as usize]);
            higher[a as usize] |= vb > va;
            lower[a as usize] |= vb < va;
        }
    }
    let used: std::collections::BTreeSet<u32> =
        patch.surface.corners.iter().flatten().copied().collect();
    used.iter()
        .any(|&v| !outline.contains(&v) && (!higher[v as usize] || !lower[v as usize]))
}

/// The ways across a patch: its edges between two of its triangles, each upward into
/// a point inside it or onto its outline's upper curve (so a cut runs from the lower
/// curve to the upper one without running along the outline or back down).
struct Across {
    links: BTreeMap<u32, Vec<(u32, f64)>>,
}

impl Across {
    fn new(patch: &Patch, loops: &[Vec<u32>]) -> Across {
        let outline: std::collections::BTreeSet<u32> = loops.iter().flatten().copied().collect();
        let uses = edge_uses(&patch.surface.corners);
        let upper = |i: u32| patch.values[i as usize] == patch.ends[1];
        let mut links: BTreeMap<u32, Vec<(u32, f64)>> = BTreeMap::new();
        for (&(a, b), &n) in &uses {
            if n != 2 {
                continue;
            }
            let length =
                patch.surface.points[a as usize].distance(patch.surface.points[b as usize]);
            for (from, to) in [(a, b), (b, a)] {
                // Only upward, so that each level between crosses the cut once; an edge
                // costs its length over its rise (the field's values are lengths),
                // times its length: a cut goes straight up rather than zigzag.
                let rise = patch.values[to as usize] - patch.values[from as usize];
                if rise > 0.0 && (!outline.contains(&to) || upper(to)) {
                    links
                        .entry(from)
                        .or_default()
                        .push((to, length * length / rise));
                }
            }
        }
        Across { links }
    }
}

/// The maximal runs of `outline` (a loop) whose points are `on`, each with whether
/// it is the whole loop.
fn runs(outline: &[u32], on: impl Fn(u32) -> bool) -> Vec<(Vec<u32>, bool)> {
    let n = outline.len();
    let Some(off) = (0..n).find(|&k| !on(outline[k])) else {
        return vec![(outline.to_vec(), true)];
    };
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for k in 1..=n {
        let i = outline[(off + k) % n];
        if on(i) {
            run.push(i);
        } else if !run.is_empty() {
            runs.push((std::mem::take(&mut run), false));
        }
    }
    runs
}

/// The triangles of `corners` joined across their shared edges but those of `cut`:
/// each group's triangles in order, the groups by their first.
fn joined_triangles(
    corners: &[[u32; 3]],
    cut: &std::collections::BTreeSet<(u32, u32)>,
) -> Vec<Vec<usize>> {
    let mut sets = UnionFind::new(corners.len());
    let mut first: BTreeMap<(u32, u32), u32> = BTreeMap::new();
    for (k, t) in corners.iter().enumerate() {
        for (a, b) in cycle_pairs(t) {
            let edge = (a.min(b), a.max(b));
            if cut.contains(&edge) {
                continue;
            }
            match first.get(&edge) {
                Some(&other) => {
                    sets.union(other, k as u32);
                }
                None => {
                    first.insert(edge, k as u32);
                }
            }
        }
    }
    let mut groups: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for k in 0..corners.len() {
        let root = sets.find(k as u32);
        groups.entry(root).or_default().push(k);
    }
    let mut groups: Vec<Vec<usize>> = groups.into_values().collect();
    groups.sort_by_key(|g| g[0]);
    groups
}

/// The patch of `patch`'s `triangles`, its points renumbered in their order, keeping
/// those `kept` says, between the same ends.
fn sub_patch(patch: &Patch, triangles: &[usize], kept: &dyn Fn(u32) -> bool) -> Patch {
    let corners: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&k| patch.surface.corners[k])
        .collect();
    let (ids, corners) = renumbered(&corners);
    Patch {
        surface: Triangles {
            points: ids
                .iter()
                .map(|&i| patch.surface.points[i as usize])
                .collect(),
            corners,
        },
        values: ids.iter().map(|&i| patch.values[i as usize]).collect(),
        kept: ids.iter().map(|&i| kept(i)).collect(),
        ends: patch.ends,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_bump_inside_a_patch_is_an_extremum_and_its_outline_is_not() {
        // A 5 x 5 grid rising along x, its middle point raised above its neighbours.
        let points: Vec<DVec3> = (0..25)
            .map(|k| DVec3::new((k % 5) as f64, (k / 5) as f64, 0.0))
            .collect();
        let mut corners = Vec::new();
        for y in 0..4u32 {
            for x in 0..4u32 {
                let k = 5 * y + x;
                corners.extend([[k, k + 1, k + 6], [k, k + 6, k + 5]]);
            }
        }
        let rising: Vec<f64> = points.iter().map(|p| p.x).collect();
        let patch = |values: Vec<f64>| Patch {
            surface: Triangles {
                points: points.clone(),
                corners: corners.clone(),
            },
            values,
            kept: vec![true; 25],
            ends: [0.0, 4.0],
        };
        let loops =
            |p: &Patch| boundary_loops(p.surface.corners.iter().flat_map(|t| cycle_pairs(t)));
        let plain = patch(rising.clone());
        assert!(
            !inner_extremum(&plain, &loops(&plain)),
            "the outline's ends are no bump"
        );
        let mut bumped = rising;
        bumped[12] = 3.5;
        let bumped = patch(bumped);
        assert!(inner_extremum(&bumped, &loops(&bumped)));
    }
}
