//! Topology of a polygon soup before it is a half-edge mesh: corners grouped by edge,
//! vertex fans, and the facts of the input exactly as the file gives it.

use rayon::slice::ParallelSliceMut;

use super::polygons::Polygons;
use crate::union_find::UnionFind;

/// Face corners grouped by undirected edge. Corner `c` is the corner at `indices[c]`;
/// its edge runs to the next corner of the same face.
pub(crate) struct CornerEdges {
    /// The face of every corner.
    pub corner_face: Vec<u32>,
    /// Corners sorted by (undirected edge key, corner index).
    pub sorted: Vec<(u64, u32)>,
}

impl CornerEdges {
    /// Groups the corners of `polys` by the undirected edge leaving them: one sort,
    /// O(n log n), deterministic.
    pub fn new(polys: &Polygons) -> Self {
        let corner_count = polys.indices.len();
        let mut corner_face = Vec::with_capacity(corner_count);
        for f in 0..polys.face_count() {
            let n = polys.offsets[f + 1] - polys.offsets[f];
            corner_face.extend(std::iter::repeat_n(f as u32, n as usize));
        }
        let mut sorted: Vec<(u64, u32)> = (0..corner_count as u32)
            .map(|c| {
                let (a, b) = corner_edge(polys, &corner_face, c);
                (edge_key(a, b), c)
            })
            .collect();
        // Keys are unique (corner index breaks ties): parallel sort stays deterministic.
        sorted.par_sort_unstable();
        Self {
            corner_face,
            sorted,
        }
    }

    /// The runs of `sorted` that share one undirected edge.
    pub fn groups(&self) -> impl Iterator<Item = &[(u64, u32)]> + '_ {
        self.sorted.chunk_by(|x, y| x.0 == y.0)
    }
}

/// The key of an undirected edge: both vertex indices, smaller first.
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// The corner after `c` in its face.
pub(crate) fn next_corner(polys: &Polygons, corner_face: &[u32], c: u32) -> u32 {
    let f = corner_face[c as usize] as usize;
    if c + 1 == polys.offsets[f + 1] {
        polys.offsets[f]
    } else {
        c + 1
    }
}

/// The directed edge (from, to) leaving corner `c`.
pub(crate) fn corner_edge(polys: &Polygons, corner_face: &[u32], c: u32) -> (u32, u32) {
    let n = next_corner(polys, corner_face, c);
    (polys.indices[c as usize], polys.indices[n as usize])
}

/// The fan of every corner: corners at one vertex are in the same fan when a chain of
/// faces sharing edges at that vertex joins them. Returns, per corner, the smallest
/// corner index of its fan. Works whatever the orientation of the faces.
pub(crate) fn corner_fans(polys: &Polygons, edges: &CornerEdges) -> Vec<u32> {
    let mut fans = UnionFind::new(polys.indices.len());
    for group in edges.groups() {
        let Some(&(_, first)) = group.first() else {
            continue;
        };
        for &(_, other) in &group[1..] {
            // The edge touches two vertices; join the corners at each end.
            for end in [0, 1] {
                let a = corner_at_end(polys, &edges.corner_face, first, end);
                let b = corner_at(polys, &edges.corner_face, other, polys.indices[a as usize]);
                fans.union(a, b);
            }
        }
    }
    fans.roots()
}

/// The number of fans at every vertex: 0 for a vertex no face uses, 1 for a manifold
/// vertex, more for a bow-tie.
pub(crate) fn fan_counts(polys: &Polygons, edges: &CornerEdges) -> Vec<u32> {
    let fans = corner_fans(polys, edges);
    let mut roots: Vec<(u32, u32)> = polys
        .indices
        .iter()
        .zip(&fans)
        .map(|(&v, &root)| (v, root))
        .collect();
    roots.sort_unstable();
    roots.dedup();
    let mut counts = vec![0u32; polys.positions.len()];
    for (v, _) in roots {
        counts[v as usize] += 1;
    }
    counts
}

/// The corner at the start (`end = 0`) or end (`end = 1`) of the edge leaving `c`.
fn corner_at_end(polys: &Polygons, corner_face: &[u32], c: u32, end: u32) -> u32 {
    if end == 0 {
        c
    } else {
        next_corner(polys, corner_face, c)
    }
}

/// Of the two corners of the edge leaving `c`, the one at vertex `v`.
fn corner_at(polys: &Polygons, corner_face: &[u32], c: u32, v: u32) -> u32 {
    if polys.indices[c as usize] == v {
        c
    } else {
        next_corner(polys, corner_face, c)
    }
}

/// Facts of a polygon soup exactly as given (no welding, no repair).
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SoupFacts {
    /// Vertices in the file.
    pub vertices_in_file: usize,
    /// Vertices used by at least one face.
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Faces.
    pub faces: usize,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with three or more faces.
    pub non_manifold_edges: usize,
    /// Vertices whose faces form more than one fan (bow-ties).
    pub non_manifold_vertices: usize,
    /// Edges that two faces run through in the same direction.
    pub misoriented_edges: usize,
    /// V − E + F.
    pub euler_characteristic: i64,
}

/// Counts the facts of a soup whose indices are in range.
pub fn soup_facts(polys: &Polygons) -> SoupFacts {
    let edges = CornerEdges::new(polys);
    let mut facts = SoupFacts {
        vertices_in_file: polys.positions.len(),
        faces: polys.face_count(),
        ..SoupFacts::default()
    };
    for group in edges.groups() {
        facts.edges += 1;
        match group.len() {
            1 => facts.boundary_edges += 1,
            2 => {
                let a = corner_edge(polys, &edges.corner_face, group[0].1);
                let b = corner_edge(polys, &edges.corner_face, group[1].1);
                if a == b {
                    facts.misoriented_edges += 1;
                }
            }
            _ => facts.non_manifold_edges += 1,
        }
    }
    let fans = fan_counts(polys, &edges);
    facts.vertices = fans.iter().filter(|&&n| n > 0).count();
    facts.non_manifold_vertices = fans.iter().filter(|&&n| n > 1).count();
    facts.euler_characteristic = facts.vertices as i64 - facts.edges as i64 + facts.faces as i64;
    facts
}
