//! Edge-collapse decimation of a triangle mesh that keeps its topology by construction.
//!
//! Edges collapse cheapest first: Garland–Heckbert quadric error, and in regular mode
//! a price on long edges and thin triangles. Candidates wait in a binary heap; entries
//! gone stale are recognised by per-vertex version stamps. Before every collapse the
//! link condition is checked, with a virtual vertex joined to every boundary vertex
//! standing for the outside, so no edge ever gets a third face, no boundary opens or
//! closes, and genus, boundary loops and components stay (a closed component ends as a
//! tetrahedron at the least). Boundary vertices only move along their boundary and
//! locked vertices never move. A collapse that would turn a triangle over or make a
//! sliver waits until no other collapse is left.
//!
//! It works on raw arrays, not on [`super::Mesh`], so any triangle list can use it.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::{DMat3, DVec3};

/// What the decimator favours when it chooses which edges to collapse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Goal {
    /// The closest surface for the budget: quadric error only, each new vertex at the
    /// point of least error.
    Accurate,
    /// Edges of one length and round triangles (every edge becomes a panel), at some
    /// cost in closeness: short edges go first, thin triangles are priced and new
    /// vertices stay near the middle of their edge.
    Regular,
}

/// A decimated triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Decimated {
    /// Positions of the vertices still used.
    pub positions: Vec<DVec3>,
    /// Triangles indexing `positions`, oriented as the input's.
    pub triangles: Vec<[u32; 3]>,
    /// For each vertex, the input vertex it continues (the one that stayed in every
    /// collapse into it).
    pub source: Vec<u32>,
    /// Edges collapsed.
    pub collapses: usize,
    /// Collapses made although they turned a triangle over or made a sliver, because
    /// no other collapse was left.
    pub forced: usize,
    /// Edges left.
    pub edges: usize,
}

/// Weight of the plane through a boundary edge, perpendicular to its triangle, per
/// edge length times the side of a reference triangle (against each triangle's own
/// plane per area): moving a border costs as much as moving a band of the surface one
/// final triangle wide, so borders keep their shape at any budget.
const BOUNDARY_WEIGHT: f64 = 1.0;

/// Triangle quality (see [`quality`]) below which a triangle is a sliver: about a
/// third of a degree for its smallest angle.
const SLIVER_QUALITY: f64 = 0.01;

/// What a collapse costs, in units of the reference triangle area (the mean area of
/// a triangle at the end), so the terms stay comparable on any model and budget.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Weights {
    /// Price of the edge's squared length.
    length: f64,
    /// Pull of the new vertex toward the edge's middle, priced per squared distance.
    anchor: f64,
    /// Price of the thinnest triangle made, per squared edge length: times one minus
    /// its quality.
    shape: f64,
}

impl Weights {
    fn of(goal: Goal) -> Self {
        match goal {
            // A faint pull to the middle only settles where the quadric does not
            // care (along flat regions and ridges), where it gives rounder triangles.
            Goal::Accurate => Self {
                length: 0.0,
                anchor: 1e-3,
                shape: 0.0,
            },
            Goal::Regular => Self {
                length: 0.3,
                anchor: 0.3,
                shape: 0.3,
            },
        }
    }
}

/// Decimates a triangle mesh to about `target_edges` edges (within two of it), or as
/// far as its topology allows.
///
/// `triangles` index `positions` and must form an oriented manifold: every edge in at
/// most two triangles (in opposite directions), every vertex one fan of triangles
/// (boundaries and several components are fine, unused vertices are dropped).
/// `locked[v]` vertices neither move nor disappear. The result has the same genus,
/// boundary loops and components, and no edge in more than two triangles.
/// Deterministic.
pub fn decimate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    locked: &[bool],
    target_edges: usize,
    goal: Goal,
) -> Decimated {
    assert_eq!(locked.len(), positions.len(), "one lock flag per vertex");
    let weights = Weights::of(goal);
    let mut decimator = Decimator::new(positions, triangles, locked, target_edges, weights);
    while decimator.edges > target_edges && decimator.step() {}
    decimator.finish()
}

/// A Garland–Heckbert quadric: the error at `p` is `pᵀAp + 2b·p + c`.
#[derive(Clone, Copy, Debug, Default)]
struct Quadric {
    /// The symmetric matrix A: xx, xy, xz, yy, yz, zz.
    a: [f64; 6],
    b: DVec3,
    c: f64,
}

impl Quadric {
    /// `weight` times the squared distance to the plane through `point` with unit
    /// `normal`.
    fn plane(normal: DVec3, point: DVec3, weight: f64) -> Self {
        let (n, d) = (normal, -normal.dot(point));
        let w = n * weight;
        Self {
            a: [
                w.x * n.x,
                w.x * n.y,
                w.x * n.z,
                w.y * n.y,
                w.y * n.z,
                w.z * n.z,
            ],
            b: w * d,
            c: weight * d * d,
        }
    }

    /// `weight` times the squared distance to `point`.
    fn point(point: DVec3, weight: f64) -> Self {
        Self {
            a: [weight, 0.0, 0.0, weight, 0.0, weight],
            b: -weight * point,
            c: weight * point.length_squared(),
        }
    }

    fn add(&self, other: &Self) -> Self {
        Self {
            a: std::array::from_fn(|k| self.a[k] + other.a[k]),
            b: self.b + other.b,
            c: self.c + other.c,
        }
    }

    fn matrix(&self) -> DMat3 {
        let [xx, xy, xz, yy, yz, zz] = self.a;
        DMat3::from_cols_array(&[xx, xy, xz, xy, yy, yz, xz, yz, zz])
    }

    fn error(&self, p: DVec3) -> f64 {
        p.dot(self.matrix() * p) + 2.0 * self.b.dot(p) + self.c
    }

    /// The point of least error, `None` when the matrix is too close to singular for
    /// it to mean anything.
    fn minimum(&self) -> Option<DVec3> {
        let m = self.matrix();
        let trace = self.a[0] + self.a[3] + self.a[5];
        // A is positive semi-definite, so its determinant against the cube of its
        // trace measures how flat its flattest direction is.
        (m.determinant() > 1e-12 * trace.powi(3))
            .then(|| m.inverse() * -self.b)
            .filter(|p| p.is_finite())
    }

    /// The parameter in [0, 1] of the least error on the segment from `p` to `q` (the
    /// middle where the error does not change along it).
    fn segment_minimum(&self, p: DVec3, q: DVec3) -> f64 {
        let d = q - p;
        let m = self.matrix();
        let curvature = d.dot(m * d);
        let slope = d.dot(m * p + self.b);
        if curvature > 0.0 {
            (-slope / curvature).clamp(0.0, 1.0)
        } else if slope < 0.0 {
            1.0
        } else if slope > 0.0 {
            0.0
        } else {
            0.5
        }
    }
}

/// 4√3 · area / (sum of the squared sides): 1 for an equilateral triangle, 0 for a
/// degenerate one, about √3 times the smallest angle (radians) for a thin one.
fn quality(t: [DVec3; 3]) -> f64 {
    let sides =
        t[0].distance_squared(t[1]) + t[1].distance_squared(t[2]) + t[2].distance_squared(t[0]);
    if sides > 0.0 {
        2.0 * 3f64.sqrt() * (t[1] - t[0]).cross(t[2] - t[0]).length() / sides
    } else {
        0.0
    }
}

/// Whether triangle `t` runs from `u` straight to `v`.
fn follows(t: [u32; 3], u: u32, v: u32) -> bool {
    (t[0] == u && t[1] == v) || (t[1] == u && t[2] == v) || (t[2] == u && t[0] == v)
}

/// A possible collapse in the heap. The smallest (tier, cost, a, b) comes out first.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    cost: f64,
    /// The edge's endpoints, `a < b`.
    a: u32,
    b: u32,
    /// The endpoints' versions when the entry was made: any change around either
    /// endpoint bumps them and so retires the entry.
    versions: [u32; 2],
    /// 1 once the collapse was found to turn a triangle over or make a sliver.
    tier: u8,
    /// Whether `cost` includes the price of the triangles' shapes (otherwise it is a
    /// lower bound, the shapes being priced when the entry comes out).
    priced: bool,
}

impl Candidate {
    /// Whether both endpoints are still there and unchanged since the entry was made.
    fn current(&self, version: &[u32], removed: &[bool]) -> bool {
        let (a, b) = (self.a as usize, self.b as usize);
        !removed[a]
            && !removed[b]
            && version[a] == self.versions[0]
            && version[b] == self.versions[1]
    }
}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed, so the max-heap yields the smallest key.
        other
            .tier
            .cmp(&self.tier)
            .then(other.cost.total_cmp(&self.cost))
            .then(other.a.cmp(&self.a))
            .then(other.b.cmp(&self.b))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Candidate {}

/// How one edge would collapse.
#[derive(Clone, Copy, Debug)]
struct Plan {
    /// The endpoint that stays (moved to `position`) and the one that goes.
    keep: u32,
    gone: u32,
    position: DVec3,
    /// Quadric error plus the length and anchor prices.
    cost: f64,
    /// The triangles on the edge (one is `None` on the boundary).
    faces: [Option<u32>; 2],
}

impl Plan {
    fn on_boundary(&self) -> bool {
        self.faces.contains(&None)
    }
}

/// The mesh being decimated: triangles with, for each vertex, the triangles around it.
struct Decimator<'a> {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    dead: Vec<bool>,
    /// The live triangles around each vertex.
    faces: Vec<Vec<u32>>,
    quadrics: Vec<Quadric>,
    /// Vertices on a boundary loop (a legal collapse never changes this).
    boundary: Vec<bool>,
    removed: Vec<bool>,
    locked: &'a [bool],
    version: Vec<u32>,
    heap: BinaryHeap<Candidate>,
    weights: Weights,
    /// The mean area of a triangle at the end: the unit of every price.
    area: f64,
    edges: usize,
    collapses: usize,
    forced: usize,
    /// Scratch: vertex marks and neighbour lists.
    mark: Vec<bool>,
    scratch: [Vec<u32>; 2],
}

impl<'a> Decimator<'a> {
    fn new(
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        locked: &'a [bool],
        target_edges: usize,
        weights: Weights,
    ) -> Self {
        let n = positions.len();
        let mut faces = vec![Vec::new(); n];
        for (f, t) in triangles.iter().enumerate() {
            debug_assert!(
                t[0] != t[1] && t[1] != t[2] && t[2] != t[0],
                "degenerate triangle {f}"
            );
            for &v in t {
                faces[v as usize].push(f as u32);
            }
        }
        let mut quadrics = vec![Quadric::default(); n];
        let mut boundary = vec![false; n];
        let mut boundary_edges = 0;
        let mut total_area = 0.0;
        for t in triangles {
            let p = t.map(|v| positions[v as usize]);
            let cross = (p[1] - p[0]).cross(p[2] - p[0]);
            let Some(normal) = cross.try_normalize() else {
                continue;
            };
            let area = 0.5 * cross.length();
            total_area += area;
            let plane = Quadric::plane(normal, p[0], area);
            for &v in t {
                quadrics[v as usize] = quadrics[v as usize].add(&plane);
            }
        }
        // The mean triangle at the end (a triangle mesh has 3F = 2E − b, b being
        // small): the unit of every price.
        let area = total_area / (2 * target_edges / 3).max(1) as f64;
        let reference_length = area.sqrt();
        for &t in triangles {
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                let runs = |from: u32, to: u32| {
                    faces[from as usize]
                        .iter()
                        .filter(|&&g| follows(triangles[g as usize], from, to))
                        .count()
                };
                // Every later step counts on each edge being in at most two
                // triangles, once each way.
                let twins = runs(v, u);
                assert!(
                    runs(u, v) == 1 && twins <= 1,
                    "not an oriented manifold: edge {u}-{v} is in more than two triangles or twice the same way"
                );
                if twins == 1 {
                    continue;
                }
                boundary_edges += 1;
                boundary[u as usize] = true;
                boundary[v as usize] = true;
                let p = t.map(|w| positions[w as usize]);
                let normal = (p[1] - p[0]).cross(p[2] - p[0]);
                let (pu, pv) = (positions[u as usize], positions[v as usize]);
                if let Some(side) = (pv - pu).cross(normal).try_normalize() {
                    let plane = Quadric::plane(
                        side,
                        pu,
                        BOUNDARY_WEIGHT * pu.distance(pv) * reference_length,
                    );
                    quadrics[u as usize] = quadrics[u as usize].add(&plane);
                    quadrics[v as usize] = quadrics[v as usize].add(&plane);
                }
            }
        }
        let edges = (3 * triangles.len() + boundary_edges) / 2;
        let mut decimator = Self {
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            dead: vec![false; triangles.len()],
            faces,
            quadrics,
            boundary,
            removed: vec![false; n],
            locked,
            version: vec![0; n],
            heap: BinaryHeap::new(),
            weights,
            area,
            edges,
            collapses: 0,
            forced: 0,
            mark: vec![false; n],
            scratch: [Vec::new(), Vec::new()],
        };
        if edges > target_edges {
            let mut around = Vec::new();
            for v in 0..n as u32 {
                decimator.neighbours(v, &mut around);
                for &w in around.iter().filter(|&&w| w > v) {
                    decimator.push(v, w);
                }
            }
        }
        decimator
    }

    /// The vertices sharing a triangle with `v`, ascending, into `out`.
    fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &f in &self.faces[v as usize] {
            out.extend(self.triangles[f as usize].iter().filter(|&&u| u != v));
        }
        out.sort_unstable();
        out.dedup();
    }

    /// The triangles on edge ab: the one running from a to b, and the one from b to a.
    fn edge_faces(&self, a: u32, b: u32) -> [Option<u32>; 2] {
        let mut found = [None, None];
        for &f in &self.faces[a as usize] {
            let t = self.triangles[f as usize];
            if follows(t, a, b) {
                found[0] = Some(f);
            } else if follows(t, b, a) {
                found[1] = Some(f);
            }
        }
        found
    }

    /// The corner of triangle `f` that is neither `a` nor `b`.
    fn third(&self, f: u32, a: u32, b: u32) -> u32 {
        let t = self.triangles[f as usize];
        t.into_iter()
            .find(|&v| v != a && v != b)
            .expect("a triangle has three corners")
    }

    fn is_boundary_edge(&self, u: u32, v: u32) -> bool {
        self.edge_faces(u, v).contains(&None)
    }

    fn has_triangle(&self, a: u32, c: u32, d: u32) -> bool {
        self.faces[a as usize].iter().any(|&f| {
            let t = self.triangles[f as usize];
            t.contains(&c) && t.contains(&d)
        })
    }

    /// Where edge ab would collapse to and what that costs, or `None` when its
    /// constraints leave no place: both ends locked, an interior edge between two
    /// boundary vertices (the surface would pinch there), or two ends that must both
    /// stay put.
    fn plan(&self, a: u32, b: u32) -> Option<Plan> {
        let faces = self.edge_faces(a, b);
        if faces == [None, None] {
            return None;
        }
        let on_boundary = faces.contains(&None);
        let (ia, ib) = (a as usize, b as usize);
        let (ba, bb) = (self.boundary[ia], self.boundary[ib]);
        if !on_boundary && ba && bb {
            return None;
        }
        // Boundary vertices only move along their boundary: the boundary end of an
        // interior edge stays where it is.
        let fixed_a = self.locked[ia] || (ba && !bb);
        let fixed_b = self.locked[ib] || (bb && !ba);
        if fixed_a && fixed_b {
            return None;
        }
        let (pa, pb) = (self.positions[ia], self.positions[ib]);
        let middle = pa.midpoint(pb);
        let length2 = pa.distance_squared(pb);
        let q = self.quadrics[ia]
            .add(&self.quadrics[ib])
            .add(&Quadric::point(middle, self.weights.anchor * self.area));
        let (keep, gone, position) = if fixed_a {
            (a, b, pa)
        } else if fixed_b {
            (b, a, pb)
        } else {
            // A boundary edge's new vertex stays on it; an interior one goes to the
            // quadric's optimum unless that is ill-defined or further from the middle
            // than the edge is long.
            let optimum = (!on_boundary)
                .then(|| q.minimum())
                .flatten()
                .filter(|p| p.distance_squared(middle) <= length2);
            let position = optimum.unwrap_or_else(|| pa.lerp(pb, q.segment_minimum(pa, pb)));
            if position.distance_squared(pa) <= position.distance_squared(pb) {
                (a, b, position)
            } else {
                (b, a, position)
            }
        };
        let cost = q.error(position).max(0.0) + self.weights.length * self.area * length2;
        Some(Plan {
            keep,
            gone,
            position,
            cost,
            faces,
        })
    }

    /// The link condition for the plan's edge ab, the outside counting as one more
    /// vertex joined to every boundary vertex: the common neighbours of a and b are
    /// exactly the third corners of the edge's triangles (plus the outside for a
    /// boundary edge, so an interior edge may not join two boundary vertices), and no
    /// edge joins two of those in the links of both (a closed tetrahedron, or a lone
    /// triangle).
    fn keeps_topology(&mut self, plan: &Plan) -> bool {
        let (a, b) = (plan.keep, plan.gone);
        let (ia, ib) = (a as usize, b as usize);
        if !plan.on_boundary() && self.boundary[ia] && self.boundary[ib] {
            return false;
        }
        let mut thirds = [u32::MAX; 2];
        let mut count = 0;
        for f in plan.faces.into_iter().flatten() {
            thirds[count] = self.third(f, a, b);
            count += 1;
        }
        let thirds = &thirds[..count];
        let [mut around_a, mut around_b] = std::mem::take(&mut self.scratch);
        self.neighbours(a, &mut around_a);
        self.neighbours(b, &mut around_b);
        let mut common = 0;
        let mut expected = true;
        let (mut i, mut j) = (0, 0);
        while i < around_a.len() && j < around_b.len() {
            match around_a[i].cmp(&around_b[j]) {
                Ordering::Less => i += 1,
                Ordering::Greater => j += 1,
                Ordering::Equal => {
                    common += 1;
                    expected &= thirds.contains(&around_a[i]);
                    i += 1;
                    j += 1;
                }
            }
        }
        self.scratch = [around_a, around_b];
        if !expected || common != thirds.len() {
            return false;
        }
        match *thirds {
            [c, d] => c != d && !(self.has_triangle(a, c, d) && self.has_triangle(b, c, d)),
            [c] => !(self.is_boundary_edge(a, c) && self.is_boundary_edge(b, c)),
            _ => false,
        }
    }

    /// What moving `a` and `b` to `p` does to their other triangles: whether one
    /// turns by a quarter turn or more or becomes a sliver it was not, and the lowest
    /// quality among them.
    fn shape(&self, a: u32, b: u32, p: DVec3) -> (bool, f64) {
        let mut bad = false;
        let mut lowest = 1.0f64;
        for &f in self.faces[a as usize].iter().chain(&self.faces[b as usize]) {
            let t = self.triangles[f as usize];
            if t.contains(&a) && t.contains(&b) {
                continue;
            }
            let before = t.map(|v| self.positions[v as usize]);
            let after = t.map(|v| {
                if v == a || v == b {
                    p
                } else {
                    self.positions[v as usize]
                }
            });
            let n0 = (before[1] - before[0]).cross(before[2] - before[0]);
            let n1 = (after[1] - after[0]).cross(after[2] - after[0]);
            let turned = n0 != DVec3::ZERO && n0.dot(n1) <= 0.0;
            let q = quality(after);
            bad |= turned || (q < SLIVER_QUALITY && q < quality(before));
            lowest = lowest.min(q);
        }
        (bad, lowest)
    }

    /// Queues edge uw with its current cost as a lower bound.
    fn push(&mut self, u: u32, w: u32) {
        let (a, b) = (u.min(w), u.max(w));
        if let Some(plan) = self.plan(a, b) {
            self.heap.push(Candidate {
                cost: plan.cost,
                a,
                b,
                versions: [self.version[a as usize], self.version[b as usize]],
                tier: 0,
                priced: false,
            });
        }
    }

    /// Takes the next candidate: collapses it, prices its shapes and queues it again,
    /// or drops it. False once the heap is empty.
    fn step(&mut self) -> bool {
        let Some(c) = self.heap.pop() else {
            return false;
        };
        // Stale entries pile up: drop them once they outnumber the live ones well.
        if self.heap.len() > 4 * self.edges + 1024 {
            let (version, removed) = (&self.version, &self.removed);
            self.heap.retain(|c| c.current(version, removed));
        }
        if !c.current(&self.version, &self.removed) {
            return true;
        }
        // Nothing around the edge changed since it was queued (that would have bumped
        // a version), so the plan is the one priced.
        let Some(plan) = self.plan(c.a, c.b) else {
            return true;
        };
        // An edge failing the link condition comes back when its surroundings change.
        if !self.keeps_topology(&plan) {
            return true;
        }
        let (bad, lowest) = self.shape(plan.keep, plan.gone, plan.position);
        let tier = u8::from(bad);
        let length2 = self.positions[c.a as usize].distance_squared(self.positions[c.b as usize]);
        let cost = plan.cost + self.weights.shape * self.area * length2 * (1.0 - lowest);
        if tier > c.tier || (!c.priced && cost > c.cost) {
            self.heap.push(Candidate {
                cost,
                tier,
                priced: true,
                ..c
            });
            return true;
        }
        self.collapse(&plan);
        self.forced += usize::from(bad);
        true
    }

    /// Collapses the plan's edge: its triangles go, `gone`'s triangles pass to `keep`,
    /// which moves to the plan's position and takes on both quadrics.
    fn collapse(&mut self, plan: &Plan) {
        let (keep, gone) = (plan.keep as usize, plan.gone as usize);
        for f in plan.faces.into_iter().flatten() {
            self.dead[f as usize] = true;
            for v in self.triangles[f as usize] {
                self.faces[v as usize].retain(|&g| g != f);
            }
        }
        let moved = std::mem::take(&mut self.faces[gone]);
        for &f in &moved {
            for v in &mut self.triangles[f as usize] {
                if *v == plan.gone {
                    *v = plan.keep;
                }
            }
        }
        self.faces[keep].extend(moved);
        self.positions[keep] = plan.position;
        self.quadrics[keep] = self.quadrics[keep].add(&self.quadrics[gone]);
        self.removed[gone] = true;
        self.edges -= if plan.on_boundary() { 2 } else { 3 };
        self.collapses += 1;
        self.refresh(plan.keep);
    }

    /// Queues again every edge at `v` or at one of its neighbours: the edges whose
    /// cost, link or surrounding triangles the collapse into `v` may have changed.
    fn refresh(&mut self, v: u32) {
        let mut ring = std::mem::take(&mut self.scratch[0]);
        let mut around = std::mem::take(&mut self.scratch[1]);
        self.neighbours(v, &mut ring);
        ring.push(v);
        for &u in &ring {
            self.version[u as usize] = self.version[u as usize].wrapping_add(1);
            self.mark[u as usize] = true;
        }
        for &u in &ring {
            self.neighbours(u, &mut around);
            for &w in &around {
                // An edge inside the ring is queued once, from its lower end.
                if !(self.mark[w as usize] && w < u) {
                    self.push(u, w);
                }
            }
        }
        for &u in &ring {
            self.mark[u as usize] = false;
        }
        self.scratch = [ring, around];
    }

    /// The live vertices (in input order) and triangles, renumbered.
    fn finish(self) -> Decimated {
        let mut index = vec![u32::MAX; self.positions.len()];
        let mut positions = Vec::new();
        let mut source = Vec::new();
        for (v, faces) in self.faces.iter().enumerate() {
            if !faces.is_empty() {
                index[v] = positions.len() as u32;
                positions.push(self.positions[v]);
                source.push(v as u32);
            }
        }
        let triangles = self
            .triangles
            .iter()
            .zip(&self.dead)
            .filter(|(_, &dead)| !dead)
            .map(|(t, _)| t.map(|v| index[v as usize]))
            .collect();
        Decimated {
            positions,
            triangles,
            source,
            collapses: self.collapses,
            forced: self.forced,
            edges: self.edges,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, BTreeSet};

    use super::*;

    type Soup = (Vec<DVec3>, Vec<[u32; 3]>);

    /// The regular icosahedron, corners on the unit sphere, faces outward.
    fn icosahedron() -> Soup {
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let positions = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .map(|p| DVec3::from_array(p).normalize())
        .to_vec();
        let triangles = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        (positions, triangles)
    }

    /// The icosahedron with every triangle split into four `levels` times, corners
    /// on the sphere of `radius` around `centre`.
    fn icosphere(levels: usize, centre: DVec3, radius: f64) -> Soup {
        let (mut positions, mut triangles) = icosahedron();
        for _ in 0..levels {
            let mut middles = BTreeMap::new();
            let mut middle = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
                *middles.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let p = positions[a as usize].midpoint(positions[b as usize]);
                    positions.push(p.normalize());
                    positions.len() as u32 - 1
                })
            };
            let mut out = Vec::new();
            for &[a, b, c] in &triangles {
                let ab = middle(a, b, &mut positions);
                let bc = middle(b, c, &mut positions);
                let ca = middle(c, a, &mut positions);
                out.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            triangles = out;
        }
        let positions = positions.iter().map(|&p| centre + radius * p).collect();
        (positions, triangles)
    }

    /// A torus of `n` × `m` quads, each split in two, faces outward.
    fn torus(n: u32, m: u32) -> Soup {
        let (big, small) = (2.0, 0.7);
        let mut positions = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    std::f64::consts::TAU * i as f64 / n as f64,
                    std::f64::consts::TAU * j as f64 / m as f64,
                );
                let r = big + small * v.cos();
                positions.push(DVec3::new(r * u.cos(), r * u.sin(), small * v.sin()));
            }
        }
        let at = |i: u32, j: u32| (i % n) * m + j % m;
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                triangles.extend([[a, b, c], [a, c, d]]);
            }
        }
        (positions, triangles)
    }

    /// A bumpy height field over an `n` × `n` grid of unit squares, without the
    /// squares `hole` says are missing, each square split in two.
    fn grid(n: u32, hole: impl Fn(u32, u32) -> bool) -> Soup {
        let mut positions = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64, j as f64);
                positions.push(DVec3::new(x, y, 0.6 * (0.4 * x).sin() * (0.3 * y).cos()));
            }
        }
        let at = |i: u32, j: u32| i * (n + 1) + j;
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if !hole(i, j) {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    triangles.extend([[a, b, c], [a, c, d]]);
                }
            }
        }
        drop_unused((positions, triangles))
    }

    /// A closed plate over an `n` × `n` grid with the squares `hole` says are missing
    /// cut through: genus is the number of holes. Holes must not touch each other or
    /// the rim, even at a corner.
    fn plate(n: u32, hole: impl Fn(u32, u32) -> bool) -> Soup {
        let corner = |i: u32, j: u32| i * (n + 1) + j;
        let count = (n + 1) * (n + 1);
        let mut positions = Vec::new();
        for z in [1.0, 0.0] {
            for i in 0..=n {
                for j in 0..=n {
                    positions.push(DVec3::new(i as f64, j as f64, z));
                }
            }
        }
        let mut top = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if !hole(i, j) {
                    let (a, b) = (corner(i, j), corner(i + 1, j));
                    let (c, d) = (corner(i + 1, j + 1), corner(i, j + 1));
                    top.extend([[a, b, c], [a, c, d]]);
                }
            }
        }
        let mut triangles = top.clone();
        triangles.extend(
            top.iter()
                .map(|&[a, b, c]| [a + count, c + count, b + count]),
        );
        // A wall down from every boundary edge of the top to the bottom's copy.
        let directed: std::collections::BTreeSet<(u32, u32)> = top
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .collect();
        for &(u, v) in &directed {
            if !directed.contains(&(v, u)) {
                triangles.extend([[v, u, u + count], [v, u + count, v + count]]);
            }
        }
        drop_unused((positions, triangles))
    }

    /// A closed cone: apex, a ring of `n` corners and the centre of its base.
    fn cone(apex: DVec3, axis: DVec3, n: u32) -> Soup {
        let (x, y) = axis.any_orthonormal_pair();
        let mut positions = vec![apex, apex + axis];
        for k in 0..n {
            let angle = std::f64::consts::TAU * k as f64 / n as f64;
            positions.push(apex + axis + 0.5 * (x * angle.cos() + y * angle.sin()));
        }
        let mut triangles = Vec::new();
        for k in 0..n {
            let (a, b) = (2 + k, 2 + (k + 1) % n);
            triangles.extend([[0, b, a], [1, a, b]]);
        }
        (positions, triangles)
    }

    /// Two soups side by side as one.
    fn join((mut positions, mut triangles): Soup, (more, faces): Soup) -> Soup {
        let offset = positions.len() as u32;
        positions.extend(more);
        triangles.extend(faces.iter().map(|t| t.map(|v| v + offset)));
        (positions, triangles)
    }

    fn drop_unused((positions, triangles): Soup) -> Soup {
        let mut index = vec![u32::MAX; positions.len()];
        let mut kept = Vec::new();
        for t in &triangles {
            for &v in t {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = kept.len() as u32;
                    kept.push(positions[v as usize]);
                }
            }
        }
        let triangles = triangles
            .iter()
            .map(|t| t.map(|v| index[v as usize]))
            .collect();
        (kept, triangles)
    }

    /// Counts of a triangle soup.
    #[derive(Debug, PartialEq, Eq)]
    struct Facts {
        vertices: usize,
        edges: usize,
        faces: usize,
        boundary_loops: usize,
        components: usize,
    }

    impl Facts {
        fn euler(&self) -> i64 {
            self.vertices as i64 - self.edges as i64 + self.faces as i64
        }
    }

    /// The soup's counts, after checking it is an oriented manifold: every directed
    /// edge once (so every edge in one or two triangles), every vertex one fan.
    fn facts(triangles: &[[u32; 3]]) -> Facts {
        try_facts(triangles).unwrap()
    }

    fn try_facts(triangles: &[[u32; 3]]) -> Result<Facts, String> {
        let mut directed = BTreeSet::new();
        let mut corners = BTreeSet::new();
        for t in triangles {
            let mut sorted = *t;
            sorted.sort_unstable();
            if sorted[0] == sorted[1] || sorted[1] == sorted[2] {
                return Err(format!("degenerate triangle {t:?}"));
            }
            // Two triangles on the same corners close a pocket of nothing.
            if !corners.insert(sorted) {
                return Err(format!("triangle {t:?} twice"));
            }
            for k in 0..3 {
                if !directed.insert((t[k], t[(k + 1) % 3])) {
                    return Err(format!("directed edge {:?} twice", (t[k], t[(k + 1) % 3])));
                }
            }
        }
        let edges = directed
            .iter()
            .filter(|&&(u, v)| u < v || !directed.contains(&(v, u)))
            .count();
        // Around v, triangle (v, u, w) leads from u to w: one fan is one chain or one
        // cycle of these steps.
        let mut fans: BTreeMap<u32, BTreeMap<u32, u32>> = BTreeMap::new();
        for t in triangles {
            for k in 0..3 {
                fans.entry(t[k])
                    .or_default()
                    .insert(t[(k + 1) % 3], t[(k + 2) % 3]);
            }
        }
        for (v, fan) in &fans {
            let ends: BTreeSet<u32> = fan.values().copied().collect();
            let starts: Vec<u32> = fan.keys().filter(|u| !ends.contains(u)).copied().collect();
            let first = match starts[..] {
                [] => *fan.keys().next().unwrap(),
                [start] => start,
                _ => return Err(format!("vertex {v} has {} fans", starts.len())),
            };
            let (mut at, mut steps) = (first, 0);
            while let Some(&next) = fan.get(&at) {
                steps += 1;
                at = next;
                if at == first {
                    break;
                }
            }
            if steps != fan.len() {
                return Err(format!("vertex {v} is not one fan"));
            }
        }
        // Each boundary vertex starts one boundary edge: follow them into loops.
        let outgoing: BTreeMap<u32, u32> = directed
            .iter()
            .filter(|&&(u, v)| !directed.contains(&(v, u)))
            .map(|&(u, v)| (v, u))
            .collect();
        let mut boundary_loops = 0;
        let mut seen = BTreeSet::new();
        for &start in outgoing.keys() {
            if seen.insert(start) {
                boundary_loops += 1;
                let mut at = outgoing[&start];
                while seen.insert(at) {
                    at = outgoing[&at];
                }
            }
        }
        // Components: union-find over the triangles' corners.
        let mut parent: BTreeMap<u32, u32> = fans.keys().map(|&v| (v, v)).collect();
        fn root(parent: &BTreeMap<u32, u32>, mut v: u32) -> u32 {
            while parent[&v] != v {
                v = parent[&v];
            }
            v
        }
        for t in triangles {
            for k in 1..3 {
                let (a, b) = (root(&parent, t[0]), root(&parent, t[k]));
                parent.insert(a.max(b), a.min(b));
            }
        }
        let components = fans.keys().filter(|&&v| root(&parent, v) == v).count();
        Ok(Facts {
            vertices: fans.len(),
            edges,
            faces: triangles.len(),
            boundary_loops,
            components,
        })
    }

    /// Whether some edge of the soup could still collapse keeping it a manifold of
    /// the same topology (tried one by one).
    fn collapse_left(triangles: &[[u32; 3]]) -> Option<(u32, u32)> {
        let before = facts(triangles);
        let edges: BTreeSet<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(u, v)| (u.min(v), u.max(v)))
            .collect();
        edges.into_iter().find(|&(u, v)| {
            let collapsed: Vec<[u32; 3]> = triangles
                .iter()
                .filter(|t| !(t.contains(&u) && t.contains(&v)))
                .map(|t| t.map(|w| if w == v { u } else { w }))
                .collect();
            try_facts(&collapsed).is_ok_and(|after| {
                (after.euler(), after.boundary_loops, after.components)
                    == (before.euler(), before.boundary_loops, before.components)
            })
        })
    }

    fn boundary_length(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
        let directed: std::collections::BTreeSet<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .collect();
        directed
            .iter()
            .filter(|&&(u, v)| !directed.contains(&(v, u)))
            .map(|&(u, v)| positions[u as usize].distance(positions[v as usize]))
            .sum()
    }

    /// Decimates `soup` to `target` edges with both goals and checks each result: a
    /// manifold of the same topology, at the target (within 2 %) or where no collapse
    /// is left that keeps the topology, the same twice over. Returns the results,
    /// accurate then regular.
    fn check(soup: &Soup, target: usize) -> [Decimated; 2] {
        let (positions, triangles) = soup;
        let before = facts(triangles);
        let locked = vec![false; positions.len()];
        [Goal::Accurate, Goal::Regular].map(|goal| {
            let out = decimate(positions, triangles, &locked, target, goal);
            let after = facts(&out.triangles);
            assert_eq!(after.edges, out.edges, "{goal:?}: edges counted");
            let topology = |f: &Facts| (f.euler(), f.boundary_loops, f.components);
            assert_eq!(topology(&after), topology(&before), "{goal:?} to {target}");
            let wanted = target.min(before.edges);
            let off = after.edges.abs_diff(wanted);
            if off * 50 > wanted && off > 2 {
                assert_eq!(
                    collapse_left(&out.triangles),
                    None,
                    "{goal:?}: stopped at {} edges for {target}",
                    after.edges
                );
            }
            assert_eq!(
                out.positions.len(),
                after.vertices,
                "{goal:?}: unused vertices"
            );
            assert_eq!(out.source.len(), after.vertices);
            assert!(out.positions.iter().all(|p| p.is_finite()));
            assert!(out.source.windows(2).all(|w| w[0] < w[1]));
            let again = decimate(positions, triangles, &locked, target, goal);
            assert_eq!(out, again, "{goal:?}: deterministic");
            out
        })
    }

    /// Whether every triangle of a mesh around the origin faces away from it.
    fn outward(out: &Decimated) -> bool {
        out.triangles.iter().all(|t| {
            let [a, b, c] = t.map(|v| out.positions[v as usize]);
            (b - a).cross(c - a).dot(a + b + c) > 0.0
        })
    }

    #[test]
    fn tetrahedron_stays() {
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        for out in check(&(positions.clone(), triangles.clone()), 0) {
            assert_eq!(out.collapses, 0);
            assert_eq!((&out.positions, &out.triangles), (&positions, &triangles));
        }
    }

    #[test]
    fn lone_triangle_stays() {
        let soup = (vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        for out in check(&soup, 0) {
            assert_eq!(out.collapses, 0);
        }
    }

    #[test]
    fn sphere_goes_down_to_a_tetrahedron() {
        let sphere = icosphere(3, DVec3::ZERO, 1.0);
        assert_eq!(facts(&sphere.1).edges, 1920);
        for target in [1200, 600, 300, 50, 30] {
            for out in check(&sphere, target) {
                // Every collapse takes three edges: the budget is met to within two.
                assert!(target - out.edges < 3);
                assert_eq!(out.forced, 0);
                assert!(outward(&out), "a triangle turned over at {target}");
            }
        }
        for out in check(&sphere, 0) {
            assert_eq!((out.positions.len(), out.triangles.len()), (4, 4));
        }
    }

    #[test]
    fn torus_keeps_its_genus() {
        let torus = torus(48, 24);
        for target in [1200, 600, 300, 60, 50] {
            check(&torus, target);
        }
        // The smallest triangulated torus has 7 vertices and 21 edges.
        for out in check(&torus, 0) {
            assert!((21..=30).contains(&out.edges), "{} edges", out.edges);
        }
    }

    #[test]
    fn plate_with_three_holes_keeps_genus_three() {
        let holes = |i: u32, j: u32| {
            [2, 6, 10]
                .iter()
                .any(|&a| (a..a + 2).contains(&i) && (3..9).contains(&j))
        };
        let plate = plate(13, holes);
        let before = facts(&plate.1);
        assert_eq!((before.euler(), before.boundary_loops), (2 - 2 * 3, 0));
        for target in [1200, 600, 300, 50, 0] {
            check(&plate, target);
        }
    }

    #[test]
    fn open_grid_keeps_its_border() {
        let grid = grid(40, |_, _| false);
        let length = boundary_length(&grid.0, &grid.1);
        for target in [1200, 600, 300, 50] {
            for out in check(&grid, target) {
                let kept = boundary_length(&out.positions, &out.triangles);
                assert!(
                    kept > 0.95 * length && kept <= length + 1e-9,
                    "border {kept} of {length} at {target}"
                );
            }
        }
    }

    #[test]
    fn grid_with_holes_keeps_them() {
        let grid = grid(30, |i, j| {
            (i, j) == (7, 7) || ((18..22).contains(&i) && (15..20).contains(&j))
        });
        assert_eq!(facts(&grid.1).boundary_loops, 3);
        for target in [1200, 600, 300, 50, 0] {
            check(&grid, target);
        }
    }

    #[test]
    fn spheres_almost_touching_stay_apart() {
        let two = join(
            icosphere(3, DVec3::ZERO, 1.0),
            icosphere(3, DVec3::new(2.001, 0.0, 0.0), 1.0),
        );
        for target in [1200, 600, 300, 50, 0] {
            check(&two, target);
        }
    }

    #[test]
    fn cones_touching_at_their_tips_stay_apart() {
        let tip = DVec3::new(0.3, 0.2, 0.1);
        let two = join(cone(tip, DVec3::Z, 40), cone(tip, -DVec3::Z, 40));
        assert_eq!(two.0[0], two.0[42]);
        for target in [200, 50, 0] {
            check(&two, target);
        }
    }

    #[test]
    fn split_vertex_on_a_border_stays_split() {
        // Two holes meeting at a corner, the corner split in two, one per fan.
        let (mut positions, mut triangles) = grid(12, |i, j| (i, j) == (5, 5) || (i, j) == (6, 6));
        let corner = positions
            .iter()
            .position(|p| p.x == 6.0 && p.y == 6.0)
            .unwrap() as u32;
        positions.push(positions[corner as usize]);
        let copy = positions.len() as u32 - 1;
        for t in &mut triangles {
            let centre = t.iter().map(|&v| positions[v as usize]).sum::<DVec3>() / 3.0;
            if centre.x > 6.0 && centre.y < 6.0 {
                for v in t.iter_mut().filter(|v| **v == corner) {
                    *v = copy;
                }
            }
        }
        let soup = (positions, triangles);
        assert_eq!(facts(&soup.1).boundary_loops, 2);
        for target in [300, 50, 0] {
            check(&soup, target);
        }
    }

    #[test]
    fn locked_vertices_stay() {
        let (positions, triangles) = torus(24, 12);
        let locked: Vec<bool> = (0..positions.len()).map(|v| v % 17 == 0).collect();
        for goal in [Goal::Accurate, Goal::Regular] {
            let out = decimate(&positions, &triangles, &locked, 100, goal);
            for v in (0..positions.len()).filter(|&v| locked[v]) {
                let k = out.source.iter().position(|&s| s as usize == v);
                assert_eq!(k.map(|k| out.positions[k]), Some(positions[v]));
            }
            facts(&out.triangles);
        }
    }

    #[test]
    #[should_panic(expected = "not an oriented manifold")]
    fn three_triangles_on_an_edge_are_refused() {
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Y];
        let triangles = [[0, 1, 2], [1, 0, 3], [1, 0, 4]];
        decimate(&positions, &triangles, &[false; 5], 0, Goal::Accurate);
    }

    #[test]
    fn target_above_the_count_keeps_everything() {
        let (positions, triangles) = icosphere(1, DVec3::ZERO, 1.0);
        let locked = vec![false; positions.len()];
        let out = decimate(&positions, &triangles, &locked, 1000, Goal::Accurate);
        assert_eq!(out.collapses, 0);
        assert_eq!((out.positions, out.triangles), (positions, triangles));
    }
}
