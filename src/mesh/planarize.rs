//! Planarization of polygon faces by guided projection (Tang's thesis, `004_…`,
//! chapter 2.4): every face of four or more corners gets an auxiliary unit normal
//! `n_f`, and the hard constraints
//!
//! ```text
//! (v_i − v_j) · n_f = 0   for every edge (v_j, v_i) of f,      n_f · n_f = 1
//! ```
//!
//! are linearised at the current iterate and solved, together with soft terms that
//! keep the result close to the input (closeness `v − v⁰`) and the displacement smooth
//! (fairness: each vertex's displacement near the mean of its neighbours'), as one
//! sparse least-squares problem through its normal equations (faer's sparse Cholesky).
//! A small proximity term `δ(x − xᵏ)` keeps the system regular and the steps short.
//! The soft weights halve every iteration until only the constraints and the proximity
//! are left, so the constraints end up satisfied to round-off.
//!
//! Fairness acts on the displacement, not the positions: a mesh that is already planar
//! is a solution with zero displacement, so it does not move at all.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use glam::DVec3;

use super::geometry::planarity_error;
use super::{FaceId, Mesh};

/// Settings of [`planarize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarizeOptions {
    /// Largest planarity error (off-plane distance over face diameter) wanted.
    pub tolerance: f64,
    /// Iterations at most.
    pub max_iterations: usize,
}

impl Default for PlanarizeOptions {
    fn default() -> Self {
        PlanarizeOptions {
            tolerance: 1e-3,
            max_iterations: 60,
        }
    }
}

/// What planarization did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PlanarizeReport {
    /// Faces of four or more corners (the constrained ones).
    pub polygons: usize,
    /// Of them, faces over the tolerance before.
    pub non_planar_before: usize,
    /// Of them, faces over the tolerance after.
    pub non_planar_after: usize,
    /// Largest planarity error before.
    pub max_error_before: f64,
    /// Largest planarity error after (the input's when nothing moved).
    pub max_error_after: f64,
    /// Largest distance a vertex moved (mesh units).
    pub max_displacement: f64,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
}

/// Why planarization could not run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanarizeError {
    /// The normal equations were not positive definite (degenerate geometry).
    #[error("the planarization system could not be solved: {0}")]
    Solve(String),
}

/// Weight of the closeness term at the first iteration, relative to the constraints
/// (lengths are measured in mean edge lengths).
const CLOSENESS: f64 = 0.1;
/// Weight of the displacement fairness at the first iteration.
const FAIRNESS: f64 = 0.1;
/// Weight of the proximity term (every iteration).
const PROXIMITY: f64 = 1e-4;
/// The constraints are met when every face's planarity error is this small: far below
/// any tolerance, so that unrolled panels are exact (developability error ~1e-12).
/// Round-off keeps the error near 5e-13 on fertility at 4 ft, so not much lower.
const CONVERGED: f64 = 1e-11;

/// Moves the vertices of `mesh` so that every face of four or more corners becomes
/// planar, staying close to the input. Triangles constrain nothing (they are always
/// planar) but move with their vertices. Returns the report; the mesh is changed in
/// place only when the faces get flatter.
pub fn planarize(
    mesh: &mut Mesh,
    options: &PlanarizeOptions,
) -> Result<PlanarizeReport, PlanarizeError> {
    let polygons: Vec<FaceId> = mesh.faces().filter(|&f| mesh.face_degree(f) > 3).collect();
    let faces = ConstrainedFaces {
        corners: polygons
            .iter()
            .map(|&f| mesh.face_vertices(f).map(|v| v.index() as u32).collect())
            .collect(),
    };
    let before = faces.errors(mesh.positions());
    let mut report = PlanarizeReport {
        polygons: polygons.len(),
        non_planar_before: before.iter().filter(|&&e| e > options.tolerance).count(),
        max_error_before: before.iter().copied().fold(0.0, f64::max),
        ..Default::default()
    };
    if report.non_planar_before == 0 {
        report.max_error_after = report.max_error_before;
        return Ok(report);
    }

    // Work in units of the mean edge length so the weights mean the same on any model.
    let unit = mean_edge_length(mesh).max(f64::MIN_POSITIVE);
    let mut iterate = Iterate::new(mesh, &polygons, unit);
    report.iterations = iterate.run(&faces, options.max_iterations)?;
    let result: Vec<DVec3> = iterate.positions.iter().map(|&p| p * unit).collect();
    apply_if_flatter(mesh, result, &faces, options.tolerance, &mut report);
    Ok(report)
}

/// The faces of four or more corners, whose planarity is constrained.
struct ConstrainedFaces {
    /// The corners of each face, by vertex index.
    corners: Vec<Vec<u32>>,
}

impl ConstrainedFaces {
    /// The planarity error of every face at `positions`.
    fn errors(&self, positions: &[DVec3]) -> Vec<f64> {
        self.corners
            .iter()
            .map(|face| {
                let points: Vec<DVec3> = face.iter().map(|&v| positions[v as usize]).collect();
                planarity_error(&points)
            })
            .collect()
    }
}

/// The unknowns of the guided projection as the iterations move them, in units of the
/// mean edge length: vertex positions, then one auxiliary normal per constrained face.
struct Iterate {
    /// The input positions.
    original: Vec<DVec3>,
    /// The current positions.
    positions: Vec<DVec3>,
    /// The current normal of every constrained face.
    normals: Vec<DVec3>,
    /// The neighbours of every vertex, for the fairness term.
    neighbours: Vec<Vec<u32>>,
}

impl Iterate {
    /// The starting point: the mesh's positions divided by `unit` and the normals of
    /// the `polygons`.
    fn new(mesh: &Mesh, polygons: &[FaceId], unit: f64) -> Self {
        let original: Vec<DVec3> = mesh.positions().iter().map(|&p| p / unit).collect();
        let normals = polygons
            .iter()
            .map(|&f| mesh.face_normal(f).try_normalize().unwrap_or(DVec3::Z))
            .collect();
        let neighbours = mesh
            .vertices()
            .map(|v| {
                mesh.vertex_neighbours(v)
                    .map(|n| n.index() as u32)
                    .collect()
            })
            .collect();
        Iterate {
            positions: original.clone(),
            original,
            normals,
            neighbours,
        }
    }

    /// The index of the first normal variable, after the three coordinates of every
    /// vertex.
    fn vertex_vars(&self) -> usize {
        3 * self.positions.len()
    }

    /// Runs up to `max_iterations` steps, halving the soft weights after each, until
    /// every face is planar to [`CONVERGED`]; returns the number of steps run.
    fn run(
        &mut self,
        faces: &ConstrainedFaces,
        max_iterations: usize,
    ) -> Result<usize, PlanarizeError> {
        let mut iterations = 0;
        let mut soft = 1.0;
        for iteration in 0..max_iterations {
            self.step(faces, soft)?;
            iterations = iteration + 1;
            soft *= 0.5;
            let worst = faces
                .errors(&self.positions)
                .into_iter()
                .fold(0.0, f64::max);
            if worst < CONVERGED {
                break;
            }
        }
        Ok(iterations)
    }

    /// One Gauss–Newton step with the soft weights scaled by `soft`.
    fn step(&mut self, faces: &ConstrainedFaces, soft: f64) -> Result<(), PlanarizeError> {
        let unknowns = self.vertex_vars() + 3 * self.normals.len();
        let mut system = NormalEquations::new(unknowns);
        self.add_constraints(&mut system, faces);
        self.add_soft_terms(&mut system, soft);
        // Proximity to the current iterate.
        let current: Vec<f64> = self
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .chain(self.normals.iter().flat_map(|n| n.to_array()))
            .collect();
        for (i, &x) in current.iter().enumerate() {
            system.add(&Row::single(i, 1.0), x, PROXIMITY);
        }
        let solution = system.solve()?;
        for (v, p) in self.positions.iter_mut().enumerate() {
            *p = DVec3::new(solution[3 * v], solution[3 * v + 1], solution[3 * v + 2]);
        }
        let vertex_vars = self.vertex_vars();
        for (k, n) in self.normals.iter_mut().enumerate() {
            let at = vertex_vars + 3 * k;
            *n = DVec3::new(solution[at], solution[at + 1], solution[at + 2]);
        }
        Ok(())
    }

    /// Adds the hard constraints of every face, linearised at the current iterate.
    fn add_constraints(&self, system: &mut NormalEquations, faces: &ConstrainedFaces) {
        let vertex_vars = self.vertex_vars();
        // e·n with e = v_b − v_a is bilinear, so its linearisation is
        // nᵏ·(v_b − v_a) + eᵏ·n = eᵏ·nᵏ.
        for (k, face) in faces.corners.iter().enumerate() {
            let n = self.normals[k];
            let nv = vertex_vars + 3 * k;
            for i in 0..face.len() {
                let a = face[i] as usize;
                let b = face[(i + 1) % face.len()] as usize;
                let e = self.positions[b] - self.positions[a];
                let mut row = Row::default();
                for axis in 0..3 {
                    row.push(3 * b + axis, n[axis]);
                    row.push(3 * a + axis, -n[axis]);
                    row.push(nv + axis, e[axis]);
                }
                system.add(&row, e.dot(n), 1.0);
            }
            // n·n = 1, linearised: 2nᵏ·n = 1 + nᵏ·nᵏ.
            let mut row = Row::default();
            for axis in 0..3 {
                row.push(nv + axis, 2.0 * n[axis]);
            }
            system.add(&row, 1.0 + n.dot(n), 1.0);
        }
    }

    /// Adds the closeness and fairness terms, per coordinate, weighted by `soft`.
    fn add_soft_terms(&self, system: &mut NormalEquations, soft: f64) {
        let closeness = CLOSENESS * soft;
        let fairness = FAIRNESS * soft;
        let original = &self.original;
        for (v, (nbrs, home)) in self.neighbours.iter().zip(original).enumerate() {
            for (axis, &home_coordinate) in home.to_array().iter().enumerate() {
                if closeness > 0.0 {
                    let mut row = Row::default();
                    row.push(3 * v + axis, 1.0);
                    system.add(&row, home_coordinate, closeness);
                }
                if fairness > 0.0 && !nbrs.is_empty() {
                    // d_v − mean(d_nbrs) = 0 with d = x − x⁰.
                    let w = 1.0 / nbrs.len() as f64;
                    let mut row = Row::default();
                    row.push(3 * v + axis, 1.0);
                    let mut target = home_coordinate;
                    for &u in nbrs {
                        row.push(3 * u as usize + axis, -w);
                        target -= w * original[u as usize][axis];
                    }
                    system.add(&row, target, fairness);
                }
            }
        }
    }
}

/// Moves the mesh to `result` and completes the report when that makes the faces
/// flatter; otherwise leaves the mesh as it is and reports the input's errors.
fn apply_if_flatter(
    mesh: &mut Mesh,
    result: Vec<DVec3>,
    faces: &ConstrainedFaces,
    tolerance: f64,
    report: &mut PlanarizeReport,
) {
    let after = faces.errors(&result);
    let max_after = after.iter().copied().fold(0.0, f64::max);
    let flatter = max_after < report.max_error_before;
    if !flatter {
        // Never hand back a worse mesh (a diverged solve).
        report.non_planar_after = report.non_planar_before;
        report.max_error_after = report.max_error_before;
        return;
    }
    report.max_displacement = result
        .iter()
        .zip(mesh.positions())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    report.non_planar_after = after.iter().filter(|&&e| e > tolerance).count();
    report.max_error_after = max_after;
    mesh.set_positions(result);
}

/// Mean length of the mesh's edges.
fn mean_edge_length(mesh: &Mesh) -> f64 {
    let (sum, count) = mesh.edges().fold((0.0, 0usize), |(sum, count), e| {
        (sum + mesh.edge_length(e), count + 1)
    });
    if count == 0 {
        1.0
    } else {
        sum / count as f64
    }
}

/// One linear equation: (variable, coefficient) pairs.
#[derive(Default)]
struct Row {
    entries: Vec<(usize, f64)>,
}

impl Row {
    fn single(i: usize, c: f64) -> Row {
        Row {
            entries: vec![(i, c)],
        }
    }

    fn push(&mut self, i: usize, c: f64) {
        self.entries.push((i, c));
    }
}

/// The normal equations `AᵀA x = Aᵀb` of weighted rows, assembled as triplets (faer
/// sums duplicates) of the lower triangle.
struct NormalEquations {
    unknowns: usize,
    lower: Vec<Triplet<usize, usize, f64>>,
    rhs: Vec<f64>,
}

impl NormalEquations {
    fn new(unknowns: usize) -> Self {
        NormalEquations {
            unknowns,
            lower: Vec::new(),
            rhs: vec![0.0; unknowns],
        }
    }

    /// Adds the row `weight · (row · x − b)` to the least-squares sum.
    fn add(&mut self, row: &Row, b: f64, weight: f64) {
        let w2 = weight * weight;
        for &(i, ci) in &row.entries {
            self.rhs[i] += w2 * ci * b;
            for &(j, cj) in &row.entries {
                if j <= i {
                    self.lower.push(Triplet::new(i, j, w2 * ci * cj));
                }
            }
        }
    }

    fn solve(self) -> Result<Vec<f64>, PlanarizeError> {
        let n = self.unknowns;
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &self.lower)
            .map_err(|e| PlanarizeError::Solve(format!("{e:?}")))?;
        let llt = matrix
            .sp_cholesky(Side::Lower)
            .map_err(|e| PlanarizeError::Solve(format!("{e:?}")))?;
        let rhs = Mat::from_fn(n, 1, |i, _| self.rhs[i]);
        let x = llt.solve(&rhs);
        let solution: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
        if solution.iter().all(|x| x.is_finite()) {
            Ok(solution)
        } else {
            Err(PlanarizeError::Solve("the solution is not finite".into()))
        }
    }
}
