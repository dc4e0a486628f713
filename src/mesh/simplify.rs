//! Simplification to a panel budget through meshoptimizer's edge-collapse simplifier
//! (faces with more than three corners are triangulated first). Border vertices only
//! collapse along their border, so holes stay holes; the result is rebuilt by the
//! ordinary half-edge builder and refused if it is not a manifold of the same genus
//! with the same number of boundary loops (in regular mode, once the lighter
//! regularization and no regularization have been tried as well). In regular mode the
//! result is then relaxed toward even edges ([`super::relax`]), and kept relaxed only
//! if its deviation from the original surface, measured again, did not grow.

use super::build::build_mesh;
use super::halfedge::Mesh;
use super::polygons::Polygons;
use super::relax::{relax, Surface};
use super::topology::Topology;

/// What to aim for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    /// About this many faces.
    Faces(usize),
    /// About this many edges (within 2 % when the simplifier can reach it).
    Edges(usize),
}

/// What the simplifier favours when it chooses which edges to collapse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SimplifyMode {
    /// Even triangle sizes and shapes, at some cost in closeness to the original
    /// surface: every edge becomes a panel, so panels come out of one size, assemble
    /// alike and lose less to the spacing.
    #[default]
    Regular,
    /// The closest surface for the budget: flat regions keep few, large triangles and
    /// curved ones many small ones (panels from slivers to half a sheet long).
    Accurate,
}

impl std::fmt::Display for SimplifyMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SimplifyMode::Regular => "regular",
            SimplifyMode::Accurate => "accurate",
        })
    }
}

/// What simplification did.
#[derive(Clone, Debug, PartialEq)]
pub struct SimplifyReport {
    /// Faces and edges before.
    pub before: (usize, usize),
    /// Faces and edges after.
    pub after: (usize, usize),
    /// The largest distance (model units) from the original surface to the simplified
    /// one, measured at every original vertex and triangle centre.
    pub deviation: f64,
    /// The mean of those distances (model units).
    pub mean_deviation: f64,
    /// Vertex moves kept by the relaxation of regular mode (0 in accurate mode).
    pub relaxed_moves: usize,
    /// Edges flipped by that relaxation toward rounder triangles.
    pub relaxed_flips: usize,
    /// The longest edge over the median edge after simplification: how far the
    /// largest panel is from a typical one.
    pub edge_spread: f64,
    /// The 95th-percentile edge over the median edge: how alike most panels are.
    pub edge_spread_95: f64,
    /// In regular mode, the simplification used instead when regularizing did not keep
    /// the topology or did not build (`None`: as asked).
    pub fallback: Option<&'static str>,
}

/// Why a mesh cannot be simplified as asked.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SimplifyError {
    /// The simplified mesh changed topology.
    #[error("simplifying to {faces} faces would change the topology (genus {genus_before} -> {genus_after}, boundary loops {loops_before} -> {loops_after})")]
    Topology {
        faces: usize,
        genus_before: i64,
        genus_after: i64,
        loops_before: usize,
        loops_after: usize,
    },
    /// The simplified triangles do not build into a valid mesh.
    #[error("simplifying that far does not give a valid manifold ({0})")]
    Invalid(String),
}

/// After `asked` was refused: the smallest budget of the same kind found to simplify
/// `mesh` while keeping its topology, searched by growing the budget by half until one
/// works, then bisecting down to 2 %. `None` when no budget below the mesh's own
/// count works.
pub fn smallest_working_budget(mesh: &Mesh, asked: Budget, mode: SimplifyMode) -> Option<Budget> {
    let (asked, make, limit): (usize, fn(usize) -> Budget, usize) = match asked {
        Budget::Edges(n) => (n, Budget::Edges, mesh.edge_count()),
        Budget::Faces(n) => (n, Budget::Faces, mesh.face_count()),
    };
    let works = |n: usize| simplify(mesh, make(n), mode).is_ok();
    let (mut failed, mut next) = (asked, asked);
    let mut worked = loop {
        next = (next + next / 2).max(next + 1);
        if next >= limit {
            return None;
        }
        if works(next) {
            break next;
        }
        failed = next;
    };
    while worked - failed > (worked / 50).max(1) {
        let mid = failed + (worked - failed) / 2;
        if works(mid) {
            worked = mid;
        } else {
            failed = mid;
        }
    }
    Some(make(worked))
}

/// Simplifies a triangle mesh toward `budget`. Deterministic: meshoptimizer is
/// single-threaded and deterministic for the same input.
pub fn simplify(
    mesh: &Mesh,
    budget: Budget,
    mode: SimplifyMode,
) -> Result<(Mesh, SimplifyReport), SimplifyError> {
    let before = mesh.topology();
    let positions: Vec<f32> = mesh
        .positions()
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let bytes: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    let adapter = meshopt::VertexDataAdapter::new(&bytes, 12, 0)
        .map_err(|e| SimplifyError::Invalid(e.to_string()))?;
    // The simplifier works on triangles: larger faces are split first (the same
    // triangulation the schemes use for non-planar faces).
    let mut indices: Vec<u32> = Vec::with_capacity(3 * mesh.face_count());
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        if corners.len() == 3 {
            indices.extend_from_slice(&corners);
        } else {
            let points: Vec<glam::DVec3> = mesh.face_positions(f).collect();
            for t in super::split::triangulate(&points) {
                indices.extend(t.map(|k| corners[k]));
            }
        }
    }

    // Three evenly spaced vertices of every boundary loop stay put, so no hole can
    // shrink to nothing; the rest of a border still simplifies along itself.
    let mut locked = vec![false; mesh.vertex_count()];
    for start in mesh.boundary_loops() {
        let ring: Vec<u32> = mesh.loop_from(start).map(|h| mesh.origin(h).0).collect();
        for k in 0..3 {
            locked[ring[k * ring.len() / 3] as usize] = true;
        }
    }
    // Edges of a triangle mesh: 3F = 2E − b, so aim F at (2E − b) / 3 and correct a few
    // times with what the simplifier really produced.
    let boundary = before.boundary_edges;
    // Faces and edges as the simplifier sees them (after triangulation).
    let triangles = indices.len() / 3;
    let target = match budget {
        Budget::Faces(f) => f,
        Budget::Edges(e) => (2 * e).saturating_sub(boundary) / 3,
    };
    if target >= triangles {
        // Already within the budget: nothing to collapse.
        let spread = edge_spread(mesh);
        return Ok((
            mesh.clone(),
            SimplifyReport {
                before: (before.faces, before.edges),
                after: (before.faces, before.edges),
                deviation: 0.0,
                mean_deviation: 0.0,
                relaxed_moves: 0,
                relaxed_flips: 0,
                edge_spread: spread.0,
                edge_spread_95: spread.1,
                fallback: None,
            },
        ));
    }
    // The original surface, built once for every attempt: where the deviation is
    // measured, and (regular mode) a grid of its triangles for the relaxation.
    let samples = surface_samples(mesh.positions(), &indices);
    let regular = mode == SimplifyMode::Regular;
    let original_triangles: Vec<[glam::DVec3; 3]> = if regular {
        indices
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|k| mesh.positions()[t[k] as usize]))
            .collect()
    } else {
        Vec::new()
    };
    let original_grid = regular.then(|| super::distance::TriangleGrid::new(&original_triangles));
    let input = Input {
        mesh,
        before,
        indices: &indices,
        adapter: &adapter,
        locked: &locked,
        budget,
        target,
        samples: &samples,
        relax_onto: original_grid.as_ref().map(|grid| Surface {
            grid,
            samples: &samples,
        }),
    };
    // Regularizing collapses across thin handles more readily (fertility at 600
    // edges loses one of its four): when its result changes the topology or does not
    // build into a manifold, the lighter regularization and then none are tried, and
    // the report says so.
    let attempts: &[(meshopt::SimplifyOptions, Option<&'static str>)] = match mode {
        SimplifyMode::Regular => &[
            (meshopt::SimplifyOptions::Regularize, None),
            (
                meshopt::SimplifyOptions::RegularizeLight,
                Some("light regularization"),
            ),
            (meshopt::SimplifyOptions::empty(), Some("no regularization")),
        ],
        SimplifyMode::Accurate => &[(meshopt::SimplifyOptions::empty(), None)],
    };
    let mut failure = None;
    for &(options, fallback) in attempts {
        match input.attempt(options) {
            Ok((simplified, mut report)) => {
                report.fallback = fallback;
                return Ok((simplified, report));
            }
            Err(e) => failure = Some(e),
        }
    }
    Err(failure.expect("at least one attempt"))
}

/// The triangles to simplify and what to aim for.
struct Input<'a> {
    mesh: &'a Mesh,
    /// The mesh's topology, which the result must keep.
    before: Topology,
    indices: &'a [u32],
    adapter: &'a meshopt::VertexDataAdapter<'a>,
    locked: &'a [bool],
    budget: Budget,
    /// First guess at the number of triangles.
    target: usize,
    /// Where the deviation from the original surface is measured.
    samples: &'a [glam::DVec3],
    /// The original surface that regular mode relaxes the result onto.
    relax_onto: Option<Surface<'a>>,
}

impl Input<'_> {
    /// One simplification with meshoptimizer's `options`, checked.
    fn attempt(
        &self,
        options: meshopt::SimplifyOptions,
    ) -> Result<(Mesh, SimplifyReport), SimplifyError> {
        self.rebuild(&self.simplified_triangles(options))
    }

    /// The simplifier's triangles for `options`, its target corrected a few times
    /// toward an edge budget.
    fn simplified_triangles(&self, options: meshopt::SimplifyOptions) -> Vec<u32> {
        let (indices, budget) = (self.indices, self.budget);
        let triangles = indices.len() / 3;
        // meshoptimizer asserts (aborting the process) if asked for more triangles
        // than it has: never ask.
        let run = |target_faces: usize| {
            let target_faces = target_faces.clamp(1, triangles);
            meshopt::simplify_with_locks(
                indices,
                self.adapter,
                self.locked,
                3 * target_faces,
                1.0,
                options,
                None,
            )
        };
        let mut target = self.target;
        let mut out = run(target);
        if let Budget::Edges(wanted) = budget {
            for _ in 0..6 {
                let got = edge_count(&out);
                if got.abs_diff(wanted) * 100 <= 2 * wanted || got == 0 {
                    break;
                }
                let scaled = (target as f64 * wanted as f64 / got as f64).round() as usize;
                if scaled == target {
                    break;
                }
                target = scaled;
                out = run(target);
            }
        }
        out
    }

    /// The mesh of the simplifier's triangles `out`, refused unless it is a manifold
    /// of the same topology, with its report.
    fn rebuild(&self, out: &[u32]) -> Result<(Mesh, SimplifyReport), SimplifyError> {
        let (mesh, indices, before) = (self.mesh, self.indices, &self.before);
        // A collapse can fold two triangles onto each other (the same three vertices, once
        // each way round): that pocket encloses nothing and gives its edges four faces.
        // Remove both copies, and any triangle that lost a corner.
        let out = drop_folded_pairs(out);
        // Compact the vertices the simplified triangles still use.
        let mut new_index = vec![u32::MAX; mesh.vertex_count()];
        let mut polys = Polygons::new();
        let mut source = Vec::new();
        for &v in &out {
            if new_index[v as usize] == u32::MAX {
                new_index[v as usize] = polys.positions.len() as u32;
                polys.positions.push(mesh.positions()[v as usize]);
                source.push(mesh.vertex_source(super::ids::VertexId(v)));
            }
        }
        for tri in out.chunks_exact(3) {
            polys.push_face(
                &tri.iter()
                    .map(|&v| new_index[v as usize])
                    .collect::<Vec<_>>(),
            );
        }
        let face_source: Vec<u32> = vec![u32::MAX; polys.face_count()];
        let build = |polys: &Polygons| {
            build_mesh(polys, Some(&source), Some(&face_source))
                .map(|(m, _)| m)
                .map_err(|e| SimplifyError::Invalid(e.to_string()))
        };
        let mut simplified = build(&polys)?;
        let after = simplified.topology();
        if after.genus != before.genus || after.boundary_loops != before.boundary_loops {
            return Err(SimplifyError::Topology {
                faces: after.faces,
                genus_before: before.genus,
                genus_after: after.genus,
                loops_before: before.boundary_loops,
                loops_after: after.boundary_loops,
            });
        }
        let samples = self.samples;
        let mut relaxed_moves = 0;
        let mut relaxed_flips = 0;
        let mut measured = deviation(samples, &simplified);
        if let Some(surface) = &self.relax_onto {
            // Relaxing moves vertices and flips edges between two faces into a diagonal
            // not yet joined: the mesh stays a manifold of the topology just checked.
            let mut triangles: Vec<[u32; 3]> = polys.faces().map(|f| [f[0], f[1], f[2]]).collect();
            let mut positions = polys.positions.clone();
            let relaxed = relax(&mut positions, &mut triangles, surface);
            if relaxed.moves + relaxed.flips > 0 {
                let polys = Polygons::from_faces(positions, &triangles);
                // The relaxation's bounds hold up to the rounding of its running sums
                // (and of the grid's search): keep its result only if the deviation,
                // measured again, really did not grow (otherwise the unrelaxed mesh
                // built above stays).
                let kept = build(&polys).ok().and_then(|m| {
                    let again = deviation(samples, &m);
                    (again.0 <= measured.0 && again.1 <= measured.1).then_some((m, again))
                });
                if let Some((m, again)) = kept {
                    simplified = m;
                    measured = again;
                    relaxed_moves = relaxed.moves;
                    relaxed_flips = relaxed.flips;
                }
            }
        }
        let (deviation, mean_deviation) = (measured.0, measured.1 / samples.len().max(1) as f64);
        let spread = edge_spread(&simplified);
        let report = SimplifyReport {
            before: (indices.len() / 3, edge_count(indices)),
            after: (after.faces, after.edges),
            deviation,
            mean_deviation,
            relaxed_moves,
            relaxed_flips,
            edge_spread: spread.0,
            edge_spread_95: spread.1,
            fallback: None,
        };
        Ok((simplified, report))
    }
}

/// The longest edge length and the 95th-percentile one, each over the median.
fn edge_spread(mesh: &Mesh) -> (f64, f64) {
    let mut lengths: Vec<f64> = mesh.edges().map(|e| mesh.edge_length(e)).collect();
    lengths.sort_unstable_by(f64::total_cmp);
    let at = |share: f64| {
        let k = ((lengths.len() as f64 - 1.0) * share).round() as usize;
        lengths.get(k).copied().unwrap_or(0.0)
    };
    let median = at(0.5);
    if median > 0.0 {
        (at(1.0) / median, at(0.95) / median)
    } else {
        (0.0, 0.0)
    }
}

/// Where closeness to the original surface (`positions` and its triangles `indices`)
/// is measured: every vertex the triangles use, then every triangle centre.
fn surface_samples(positions: &[glam::DVec3], indices: &[u32]) -> Vec<glam::DVec3> {
    let mut used = vec![false; positions.len()];
    for &v in indices {
        used[v as usize] = true;
    }
    let corners = positions
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(&p, _)| p);
    let centres = indices.chunks_exact(3).map(|t| {
        (positions[t[0] as usize] + positions[t[1] as usize] + positions[t[2] as usize]) / 3.0
    });
    corners.chain(centres).collect()
}

/// The largest distance and the sum of the distances from the `samples` of the
/// original surface to the simplified triangle mesh (the sum in sample order). In
/// parallel; the results do not depend on the thread count.
fn deviation(samples: &[glam::DVec3], simplified: &Mesh) -> (f64, f64) {
    use rayon::prelude::*;
    let triangles: Vec<[glam::DVec3; 3]> = simplified
        .faces()
        .map(|f| {
            // The simplified mesh is built from the simplifier's triangles.
            let corners: Vec<glam::DVec3> = simplified.face_positions(f).collect();
            [corners[0], corners[1], corners[2]]
        })
        .collect();
    let grid = super::distance::TriangleGrid::new(&triangles);
    let distances: Vec<f64> = samples.par_iter().map(|&p| grid.distance(p)).collect();
    let largest = distances.iter().copied().fold(0.0, f64::max);
    (largest, distances.iter().sum())
}

/// Triangles of `indices` without degenerate ones and without pairs that use the same
/// three vertices (both copies go).
fn drop_folded_pairs(indices: &[u32]) -> Vec<u32> {
    let key = |t: &[u32]| {
        let mut k = [t[0], t[1], t[2]];
        k.sort_unstable();
        k
    };
    let mut seen: std::collections::HashMap<[u32; 3], usize> = std::collections::HashMap::new();
    for t in indices.chunks_exact(3) {
        *seen.entry(key(t)).or_insert(0) += 1;
    }
    indices
        .chunks_exact(3)
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && seen[&key(t)] == 1)
        .flatten()
        .copied()
        .collect()
}

/// Undirected edges of a triangle index list.
fn edge_count(indices: &[u32]) -> usize {
    let mut edges: Vec<(u32, u32)> = indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges.len()
}
