//! Welding vertices that share a position.
//!
//! STL soups are welded outright (their triangles share nothing otherwise). OBJ and OFF
//! keep coincident vertices apart unless `--weld` is given, because a seam may be
//! intentional; `--weld` then merges only where the result stays a 2-manifold.

use std::collections::HashMap;

use glam::DVec3;

use super::polygons::Polygons;
use super::soup::{fan_counts, CornerEdges};

/// The welding tolerance for a set of points: a ten-millionth of the bounding-box
/// diagonal. Single-precision files repeat a shared vertex bit for bit, and double
/// precision files agree far closer than this; real features are far larger.
pub fn weld_tolerance(points: &[DVec3]) -> f64 {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let diagonal = (hi - lo).length();
    if diagonal.is_finite() {
        diagonal * 1e-7
    } else {
        0.0
    }
}

/// Groups points closer than `tolerance`. Returns, for every point, the index of its
/// cluster's representative: the first point (in index order) of the cluster, so the
/// result is deterministic. A uniform grid with cells of the tolerance's size finds
/// neighbours in expected O(1).
pub fn cluster_positions(points: &[DVec3], tolerance: f64) -> Vec<u32> {
    let cell = if tolerance > 0.0 { tolerance } else { 1.0 };
    let key = |p: DVec3| -> [i64; 3] {
        let q = (p / cell).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut representative = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let k = key(p);
        let mut found: Option<u32> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(bucket) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else {
                        continue;
                    };
                    for &r in bucket {
                        let close = if tolerance > 0.0 {
                            points[r as usize].distance(p) <= tolerance
                        } else {
                            points[r as usize] == p
                        };
                        if close && found.is_none_or(|f| r < f) {
                            found = Some(r);
                        }
                    }
                }
            }
        }
        match found {
            Some(r) => representative.push(r),
            None => {
                grid.entry(k).or_default().push(i as u32);
                representative.push(i as u32);
            }
        }
    }
    representative
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
