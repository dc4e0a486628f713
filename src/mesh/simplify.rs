//! Simplification to a panel budget (faces with more than three corners are
//! triangulated first). meshoptimizer's edge-collapse simplifier is tried first, in the
//! mode asked for; it does not check the link condition, so its result is rebuilt by
//! the ordinary half-edge builder and kept only if it is a manifold of the same genus,
//! boundary loops and components, within 2 % of an edge budget. Otherwise the
//! project's own decimator ([`super::decimate`]), which keeps the topology by
//! construction, makes the result: any budget down to the topological minimum is
//! reached. Border vertices only move along their border, so holes stay holes. In
//! regular mode the result is then relaxed toward even edges ([`super::relax`]), and
//! kept relaxed only if its deviation from the original surface, measured again, did
//! not grow.

use super::build::build_mesh;
use super::decimate::{decimate, Goal};
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
    /// The budget is below the fewest edges the topology allows.
    #[error("{asked} {what} is fewer than this model's topology allows: keeping its genus {genus}, {loops} boundary {} and {components} {} takes at least {fewest} {what}", if *loops == 1 { "loop" } else { "loops" }, if *components == 1 { "part" } else { "parts" })]
    BelowMinimum {
        /// "edges" or "faces".
        what: &'static str,
        /// The budget asked for.
        asked: usize,
        /// The fewest reached while keeping the topology.
        fewest: usize,
        /// The mesh's genus.
        genus: i64,
        /// Its boundary loops.
        loops: usize,
        /// Its connected parts.
        components: usize,
    },
}

/// Simplifies a triangle mesh toward `budget`. Deterministic: meshoptimizer is
/// single-threaded and deterministic for the same input.
pub fn simplify(
    mesh: &Mesh,
    budget: Budget,
    mode: SimplifyMode,
) -> Result<(Mesh, SimplifyReport), SimplifyError> {
    simplify_with(mesh, budget, mode, true)
}

/// [`simplify`] with the project's decimator alone, never meshoptimizer: what the
/// benchmarks compare meshoptimizer's results with.
pub fn decimate_to(
    mesh: &Mesh,
    budget: Budget,
    mode: SimplifyMode,
) -> Result<(Mesh, SimplifyReport), SimplifyError> {
    simplify_with(mesh, budget, mode, false)
}

/// [`simplify`], trying meshoptimizer first when `meshopt_first`.
fn simplify_with(
    mesh: &Mesh,
    budget: Budget,
    mode: SimplifyMode,
    meshopt_first: bool,
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
    let indices = triangle_indices(mesh);
    let locked = locked_border_vertices(mesh);
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
        return Ok(unchanged(mesh, &before));
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
    let options = match mode {
        SimplifyMode::Regular => meshopt::SimplifyOptions::Regularize,
        SimplifyMode::Accurate => meshopt::SimplifyOptions::empty(),
    };
    if meshopt_first {
        if let Ok(done) = input.rebuild(&input.simplified_triangles(options)) {
            if input.reached(&done.1) {
                return Ok(done);
            }
        }
    }
    // meshoptimizer glued the surface to itself, closed a hole, lost a part or stopped
    // short: decimate with the link condition instead.
    let (simplified, mut report) = input.decimated(mode)?;
    if !input.reached(&report) {
        let (what, asked, fewest) = match budget {
            Budget::Edges(n) => ("edges", n, report.after.1),
            Budget::Faces(n) => ("faces", n, report.after.0),
        };
        return Err(SimplifyError::BelowMinimum {
            what,
            asked,
            fewest,
            genus: input.before.genus,
            loops: input.before.boundary_loops,
            components: input.before.components.len(),
        });
    }
    if meshopt_first {
        report.fallback = Some("edge collapses that keep the topology");
    }
    Ok((simplified, report))
}

/// A mesh already within the budget, as it is: nothing to collapse.
fn unchanged(mesh: &Mesh, before: &Topology) -> (Mesh, SimplifyReport) {
    let spread = edge_spread(mesh);
    let report = SimplifyReport {
        before: (before.faces, before.edges),
        after: (before.faces, before.edges),
        deviation: 0.0,
        mean_deviation: 0.0,
        relaxed_moves: 0,
        relaxed_flips: 0,
        edge_spread: spread.0,
        edge_spread_95: spread.1,
        fallback: None,
    };
    (mesh.clone(), report)
}

/// The triangles of `mesh` as the simplifier sees them (its faces split as
/// [`triangle_indices`] splits them), by their corners' positions.
pub fn surface_triangles(mesh: &Mesh) -> Vec<[glam::DVec3; 3]> {
    let positions = mesh.positions();
    triangle_indices(mesh)
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| positions[t[k] as usize]))
        .collect()
}

/// The mesh's faces as a triangle index list, as the simplifier works on triangles:
/// larger faces are split (the same triangulation the schemes use for non-planar
/// faces).
fn triangle_indices(mesh: &Mesh) -> Vec<u32> {
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
    indices
}

/// Three evenly spaced vertices of every boundary loop, which stay put so no hole can
/// shrink to nothing; the rest of a border still simplifies along itself.
fn locked_border_vertices(mesh: &Mesh) -> Vec<bool> {
    let mut locked = vec![false; mesh.vertex_count()];
    for start in mesh.boundary_loops() {
        let ring: Vec<u32> = mesh.loop_from(start).map(|h| mesh.origin(h).0).collect();
        for k in 0..3 {
            locked[ring[k * ring.len() / 3] as usize] = true;
        }
    }
    locked
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

    /// Whether `report`'s result is within 2 % of the budget, or within the three
    /// edges (two faces) one collapse removes.
    fn reached(&self, report: &SimplifyReport) -> bool {
        match self.budget {
            Budget::Edges(n) => report.after.1.abs_diff(n) <= (n / 50).max(3),
            Budget::Faces(n) => report.after.0.abs_diff(n) <= (n / 50).max(2),
        }
    }

    /// The project's decimator's result for `mode`, checked and measured.
    fn decimated(&self, mode: SimplifyMode) -> Result<(Mesh, SimplifyReport), SimplifyError> {
        let mesh = self.mesh;
        let (positions, triangles) = manifold_triangles(mesh);
        let mut locked = self.locked.to_vec();
        locked.resize(positions.len(), false);
        let goal = match mode {
            SimplifyMode::Regular => Goal::Regular,
            SimplifyMode::Accurate => Goal::Accurate,
        };
        let target_edges = match self.budget {
            Budget::Edges(n) => n,
            // 3F = 2E − b for triangles.
            Budget::Faces(n) => (3 * n + self.before.boundary_edges).div_ceil(2),
        };
        let out = decimate(&positions, &triangles, &locked, target_edges, goal);
        // A centre added to a face continues the face's first corner.
        let first_corners: Vec<u32> = mesh
            .faces()
            .filter(|&f| mesh.face_degree(f) > 3)
            .map(|f| mesh.face_vertices(f).next().map_or(0, |v| v.0))
            .collect();
        let source: Vec<u32> = out
            .source
            .iter()
            .map(|&v| {
                let v = match (v as usize).checked_sub(mesh.vertex_count()) {
                    Some(centre) => first_corners.get(centre).copied().unwrap_or(0),
                    None => v,
                };
                mesh.vertex_source(super::ids::VertexId(v))
            })
            .collect();
        self.finish(Polygons::from_faces(out.positions, &out.triangles), &source)
    }

    /// The mesh of meshoptimizer's triangles `out` (indices into the input's
    /// vertices), refused unless it is a manifold of the same topology, with its
    /// report.
    fn rebuild(&self, out: &[u32]) -> Result<(Mesh, SimplifyReport), SimplifyError> {
        let mesh = self.mesh;
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
        self.finish(polys, &source)
    }

    /// The mesh of the simplified triangles `polys` (whose vertices came from the
    /// input's `source`), refused unless it is a manifold of the input's genus,
    /// boundary loops and parts; relaxed in regular mode; with its report.
    fn finish(
        &self,
        polys: Polygons,
        source: &[u32],
    ) -> Result<(Mesh, SimplifyReport), SimplifyError> {
        let (indices, before) = (self.indices, &self.before);
        let face_source: Vec<u32> = vec![u32::MAX; polys.face_count()];
        let build = |polys: &Polygons| {
            build_mesh(polys, Some(source), Some(&face_source))
                .map(|(m, _)| m)
                .map_err(|e| SimplifyError::Invalid(e.to_string()))
        };
        let mut simplified = build(&polys)?;
        let after = simplified.topology();
        if after.genus != before.genus
            || after.boundary_loops != before.boundary_loops
            || after.components.len() != before.components.len()
        {
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

/// The mesh's faces as triangles that form an oriented manifold, as the decimator
/// needs: a face of more than three corners is split along diagonals that are no edge
/// of the mesh and no diagonal of another face (its own triangulation, else a fan from
/// one of its corners); where every split would repeat an edge, it is fanned from a
/// new vertex at its centre (appended after the mesh's vertices, one slot for each face
/// of more than three corners, in face order, whether used or not).
fn manifold_triangles(mesh: &Mesh) -> (Vec<glam::DVec3>, Vec<[u32; 3]>) {
    use std::collections::HashSet;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut edges: HashSet<(u32, u32)> = mesh
        .edges()
        .map(|e| {
            let (a, b) = mesh.edge_vertices(e);
            key(a.0, b.0)
        })
        .collect();
    let mut positions = mesh.positions().to_vec();
    let mut triangles = Vec::with_capacity(2 * mesh.face_count());
    let mut centre_slot = mesh.vertex_count() as u32;
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        let n = corners.len();
        if n == 3 {
            triangles.push([corners[0], corners[1], corners[2]]);
            continue;
        }
        let points: Vec<glam::DVec3> = mesh.face_positions(f).collect();
        let own: Vec<[usize; 3]> = super::split::triangulate(&points);
        let fans = (0..n).map(|k| -> Vec<[usize; 3]> {
            (1..n - 1)
                .map(|j| [k, (k + j) % n, (k + j + 1) % n])
                .collect()
        });
        // A split is fresh when none of its diagonals is already an edge.
        let fresh = |split: &Vec<[usize; 3]>, edges: &HashSet<(u32, u32)>| {
            split.iter().all(|t| {
                (0..3).all(|i| {
                    let (a, b) = (t[i], t[(i + 1) % 3]);
                    let side = (a + 1) % n == b || (b + 1) % n == a;
                    side || !edges.contains(&key(corners[a], corners[b]))
                })
            })
        };
        let slot = centre_slot;
        centre_slot += 1;
        match std::iter::once(own).chain(fans).find(|s| fresh(s, &edges)) {
            Some(split) => {
                for t in &split {
                    for i in 0..3 {
                        edges.insert(key(corners[t[i]], corners[t[(i + 1) % 3]]));
                    }
                    triangles.push(t.map(|k| corners[k]));
                }
            }
            None => {
                positions.resize(slot as usize + 1, glam::DVec3::ZERO);
                positions[slot as usize] = points.iter().sum::<glam::DVec3>() / n as f64;
                for i in 0..n {
                    triangles.push([corners[i], corners[(i + 1) % n], slot]);
                }
            }
        }
    }
    // The slots of faces split along diagonals hold no vertex; the decimator drops
    // vertices no triangle uses.
    (positions, triangles)
}

/// The longest edge length and the 95th-percentile one, each over the median.
fn edge_spread(mesh: &Mesh) -> (f64, f64) {
    let lengths = mesh.sorted_edge_lengths();
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
