//! Welding vertices that share a position.
//!
//! STL soups are welded outright (their triangles share nothing otherwise). OBJ and OFF
//! keep coincident vertices apart unless `--weld` is given, because a seam may be
//! intentional; `--weld` then merges only where the result stays a 2-manifold.

use glam::DVec3;

use rayon::slice::ParallelSliceMut;

use super::polygons::Polygons;
use super::soup::{fan_counts, CornerEdges};
use crate::union_find::UnionFind;

/// The welding tolerance for a set of points: a ten-millionth of the bounding-box
/// diagonal. Single-precision files repeat a shared vertex bit for bit, and double
/// precision files agree far closer than this; real features are far larger.
pub fn weld_tolerance(points: &[DVec3]) -> f64 {
    let (lo, hi) = super::geometry::bounding_box(points.iter().copied());
    let diagonal = (hi - lo).length();
    if diagonal.is_finite() {
        diagonal * 1e-7
    } else {
        0.0
    }
}

/// Groups points closer than `tolerance` (transitively). Returns, for every point,
/// the index of its cluster's representative: the cluster's lowest index, so the result
/// does not depend on processing order.
///
/// Points are bucketed in a grid of cells much larger than the tolerance, sorted by
/// cell; a point looks into a neighbouring cell only along the axes where it lies
/// within the tolerance of its cell's border, so almost every point searches one cell.
pub fn cluster_positions(points: &[DVec3], tolerance: f64) -> Vec<u32> {
    if points.is_empty() {
        return Vec::new();
    }
    let mut clusters = UnionFind::new(points.len());
    let (lo, hi) = super::geometry::bounding_box(points.iter().copied());
    let diagonal = (hi - lo).length();
    if diagonal.is_nan() || diagonal <= 0.0 {
        // Every point at one position (or none finite): one cluster.
        return vec![0; points.len()];
    }
    // At most 2^20 cells per axis, so a cell packs into 63 bits exactly.
    let cell = (tolerance * 1024.0).max(diagonal / f64::from(1u32 << 20));
    let cell_of = |p: DVec3| -> [i64; 3] {
        let q = ((p - lo) / cell).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    };
    let pack = |c: [i64; 3]| -> Option<u64> {
        let limit = 1i64 << 21;
        c.iter()
            .all(|&k| (0..limit).contains(&k))
            .then(|| ((c[0] as u64) << 42) | ((c[1] as u64) << 21) | c[2] as u64)
    };
    let mut sorted: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .filter_map(|(i, &p)| pack(cell_of(p)).map(|k| (k, i as u32)))
        .collect();
    sorted.par_sort_unstable();
    let keys: Vec<u64> = sorted.iter().map(|&(k, _)| k).collect();
    let close = |a: DVec3, b: DVec3| {
        if tolerance > 0.0 {
            a.distance(b) <= tolerance
        } else {
            a == b
        }
    };
    for (i, &p) in points.iter().enumerate() {
        let home = cell_of(p);
        let frac = (p - lo) / cell - DVec3::new(home[0] as f64, home[1] as f64, home[2] as f64);
        let near = tolerance / cell;
        // Per axis: the home cell, plus the neighbour on the side the point is near.
        let steps = |f: f64| -> [i64; 2] {
            if f < near {
                [0, -1]
            } else if f > 1.0 - near {
                [0, 1]
            } else {
                [0, 0]
            }
        };
        let (sx, sy, sz) = (steps(frac.x), steps(frac.y), steps(frac.z));
        let mut visited: [Option<u64>; 8] = [None; 8];
        let mut n = 0;
        for dx in sx {
            for dy in sy {
                for dz in sz {
                    let Some(key) = pack([home[0] + dx, home[1] + dy, home[2] + dz]) else {
                        continue;
                    };
                    if visited[..n].contains(&Some(key)) {
                        continue;
                    }
                    visited[n] = Some(key);
                    n += 1;
                    let start = keys.partition_point(|&k| k < key);
                    for &(k, j) in &sorted[start..] {
                        if k != key {
                            break;
                        }
                        if (j as usize) < i && close(points[j as usize], p) {
                            clusters.union(i as u32, j);
                        }
                    }
                }
            }
        }
    }
    clusters.roots()
}

/// What a manifold-aware weld did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WeldReport {
    /// Vertices merged into another vertex.
    pub merged: usize,
    /// Groups of coincident vertices left apart because merging them would break the
    /// manifold: each is the list of vertex indices (soup numbering), lowest first.
    pub skipped: Vec<Vec<u32>>,
}

/// Merges coincident vertices wherever the merged mesh stays manifold: no face loses a
/// corner, no edge gets a third face, no merge adds a bow-tie (a merged vertex may
/// have no more surplus fans than its members had: a bow-tie already in the input is
/// not the weld's doing and is split later like any other). Merging everything
/// first and then undoing the clusters that broke a rule (until nothing breaks) is what
/// lets a seam weld: merging a seam one vertex at a time would make a bow-tie at every
/// step. Returns the new soup (unused vertices keep their index) and the map from old to
/// new vertex.
pub fn weld_where_manifold(polys: &Polygons, tolerance: f64) -> (Polygons, WeldReport) {
    let representative = cluster_positions(&polys.positions, tolerance);
    let fans_before = fan_counts(polys, &CornerEdges::new(polys));
    let mut merged: Vec<u32> = representative.clone();
    let mut undone = vec![false; polys.positions.len()];
    loop {
        let remapped = remap(polys, &merged);
        let broken = broken_clusters(&remapped, &merged, &fans_before);
        if broken.is_empty() {
            let mut report = WeldReport {
                merged: merged
                    .iter()
                    .enumerate()
                    .filter(|&(i, &m)| m as usize != i)
                    .count(),
                skipped: Vec::new(),
            };
            let mut groups: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
            for (i, &r) in representative.iter().enumerate() {
                if undone[r as usize] {
                    groups.entry(r).or_default().push(i as u32);
                }
            }
            report.skipped = groups.into_values().filter(|g| g.len() > 1).collect();
            return (remapped, report);
        }
        for r in broken {
            undone[r as usize] = true;
        }
        for (i, m) in merged.iter_mut().enumerate() {
            if undone[representative[i] as usize] {
                *m = i as u32;
            }
        }
    }
}

fn remap(polys: &Polygons, merged: &[u32]) -> Polygons {
    Polygons {
        positions: polys.positions.clone(),
        offsets: polys.offsets.clone(),
        indices: polys.indices.iter().map(|&v| merged[v as usize]).collect(),
    }
}

/// Representatives of merged clusters that break a manifold rule in `polys`.
fn broken_clusters(polys: &Polygons, merged: &[u32], fans_before: &[u32]) -> Vec<u32> {
    // Which vertices are representatives of a real (multi-vertex) cluster.
    let mut cluster_size = vec![0u32; polys.positions.len()];
    for &m in merged {
        cluster_size[m as usize] += 1;
    }
    let in_cluster = |v: u32| cluster_size[v as usize] > 1;
    let mut broken = Vec::new();
    // A face that visits a vertex twice.
    for face in polys.faces() {
        let mut sorted = face.to_vec();
        sorted.sort_unstable();
        for w in sorted.windows(2) {
            if w[0] == w[1] && in_cluster(w[0]) {
                broken.push(w[0]);
            }
        }
    }
    let edges = CornerEdges::new(polys);
    // An edge with three or more faces.
    for group in edges.groups() {
        if group.len() > 2 {
            let key = group[0].0;
            for v in [(key >> 32) as u32, key as u32] {
                if in_cluster(v) {
                    broken.push(v);
                }
            }
        }
    }
    if broken.is_empty() {
        // A merge that adds a bow-tie: more surplus fans after than its members had.
        let mut surplus_before = vec![0u32; polys.positions.len()];
        for (v, &m) in merged.iter().enumerate() {
            surplus_before[m as usize] += fans_before[v].saturating_sub(1);
        }
        let fans_after = fan_counts(polys, &edges);
        for (v, &after) in fans_after.iter().enumerate() {
            if in_cluster(v as u32) && after.saturating_sub(1) > surplus_before[v] {
                broken.push(v as u32);
            }
        }
    }
    broken.sort_unstable();
    broken.dedup();
    broken
}
