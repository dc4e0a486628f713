//! Topological and geometric facts of a half-edge mesh: counts, components, boundary
//! loops, Euler characteristic and genus, area, bounding box, planarity.

use std::collections::BTreeMap;

use rayon::prelude::*;
use serde::Serialize;

use super::geometry::planarity_error;
use super::halfedge::Mesh;
use super::ids::{FaceId, HalfedgeId};

/// Facts of one connected component.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ComponentFacts {
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Faces.
    pub faces: usize,
    /// Boundary loops (holes).
    pub boundary_loops: usize,
    /// V − E + F.
    pub euler_characteristic: i64,
    /// Genus from χ = 2 − 2g − b (orientable surfaces).
    pub genus: i64,
    /// True when the component has no boundary.
    pub closed: bool,
    /// The lowest face index in the component (to name it).
    pub first_face: u32,
}

/// Facts of the whole mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Topology {
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Faces.
    pub faces: usize,
    /// Edges with a face on one side only.
    pub boundary_edges: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// V − E + F of the whole mesh.
    pub euler_characteristic: i64,
    /// Sum of the components' genus.
    pub genus: i64,
    /// Number of faces of each size (corners → faces).
    pub face_sizes: BTreeMap<usize, usize>,
    /// Connected components, largest first (ties by first face).
    pub components: Vec<ComponentFacts>,
}

/// Geometric facts, in model units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GeometryFacts {
    /// Sum of face areas.
    pub surface_area: f64,
    /// Lower corner of the bounding box.
    pub bbox_min: [f64; 3],
    /// Upper corner of the bounding box.
    pub bbox_max: [f64; 3],
    /// Largest planarity error of any face (corner distance to the best-fit plane over
    /// face diameter).
    pub max_planarity_error: f64,
    /// The face with the largest planarity error.
    pub least_planar_face: Option<u32>,
    /// Faces whose planarity error exceeds the tolerance given.
    pub non_planar_faces: usize,
    /// The tolerance used for `non_planar_faces`.
    pub planarity_tolerance: f64,
}

impl GeometryFacts {
    /// The longest side of the bounding box.
    pub fn longest_side(&self) -> f64 {
        longest_side(self.bbox_min, self.bbox_max)
    }
}

fn longest_side(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

impl Mesh {
    /// The longest side of the bounding box of the positions (what `--size` sets),
    /// without the per-face facts of [`Mesh::geometry_facts`].
    pub fn longest_side(&self) -> f64 {
        let (lo, hi) = super::geometry::bounding_box(self.positions.iter().copied());
        longest_side(lo.to_array(), hi.to_array())
    }

    /// The connected component of every face (numbered from 0 in order of each
    /// component's lowest face) and the number of components.
    pub fn face_components(&self) -> (Vec<u32>, usize) {
        let mut component = vec![u32::MAX; self.face_count()];
        let mut count = 0u32;
        let mut stack: Vec<FaceId> = Vec::new();
        for seed in self.faces() {
            if component[seed.index()] != u32::MAX {
                continue;
            }
            component[seed.index()] = count;
            stack.push(seed);
            while let Some(f) = stack.pop() {
                for h in self.face_half_edges(f) {
                    if let Some(g) = self.face(h.twin()) {
                        if component[g.index()] == u32::MAX {
                            component[g.index()] = count;
                            stack.push(g);
                        }
                    }
                }
            }
            count += 1;
        }
        (component, count as usize)
    }

    /// One boundary half-edge of every boundary loop, in index order.
    pub fn boundary_loops(&self) -> Vec<HalfedgeId> {
        let mut seen = vec![false; self.half_edge_count()];
        let mut loops = Vec::new();
        for h in self.half_edges() {
            if !self.is_boundary_half_edge(h) || seen[h.index()] {
                continue;
            }
            loops.push(h);
            for g in self.loop_from(h) {
                seen[g.index()] = true;
            }
        }
        loops
    }

    /// Counts, components, boundary loops, Euler characteristic and genus.
    pub fn topology(&self) -> Topology {
        let (component_of_face, count) = self.face_components();
        let mut components: Vec<ComponentFacts> = (0..count)
            .map(|_| ComponentFacts {
                vertices: 0,
                edges: 0,
                faces: 0,
                boundary_loops: 0,
                euler_characteristic: 0,
                genus: 0,
                closed: true,
                first_face: u32::MAX,
            })
            .collect();
        let component_of_half_edge = |h: HalfedgeId| {
            let f = self.face(h).or_else(|| self.face(h.twin()));
            f.map(|f| component_of_face[f.index()] as usize)
        };
        let mut face_sizes = BTreeMap::new();
        for f in self.faces() {
            let c = &mut components[component_of_face[f.index()] as usize];
            c.faces += 1;
            c.first_face = c.first_face.min(f.0);
            *face_sizes.entry(self.face_degree(f)).or_insert(0) += 1;
        }
        for v in self.vertices() {
            if let Some(c) = component_of_half_edge(self.vertex_half_edge(v)) {
                components[c].vertices += 1;
            }
        }
        let mut boundary_edges = 0;
        for e in self.edges() {
            if let Some(c) = component_of_half_edge(e.half_edge()) {
                components[c].edges += 1;
            }
            if self.is_boundary_edge(e) {
                boundary_edges += 1;
            }
        }
        let loops = self.boundary_loops();
        for &h in &loops {
            if let Some(c) = component_of_half_edge(h) {
                components[c].boundary_loops += 1;
                components[c].closed = false;
            }
        }
        for c in &mut components {
            c.euler_characteristic = c.vertices as i64 - c.edges as i64 + c.faces as i64;
            c.genus = (2 - c.euler_characteristic - c.boundary_loops as i64) / 2;
        }
        components.sort_by(|a, b| b.faces.cmp(&a.faces).then(a.first_face.cmp(&b.first_face)));
        Topology {
            vertices: self.vertex_count(),
            edges: self.edge_count(),
            faces: self.face_count(),
            boundary_edges,
            boundary_loops: loops.len(),
            euler_characteristic: self.vertex_count() as i64 - self.edge_count() as i64
                + self.face_count() as i64,
            genus: components.iter().map(|c| c.genus).sum(),
            face_sizes,
            components,
        }
    }

    /// The planarity error of every face (see [`super::geometry::planarity_error`]).
    /// Computed in parallel; results are collected in face order.
    pub fn face_planarity_errors(&self) -> Vec<f64> {
        (0..self.face_count() as u32)
            .into_par_iter()
            .map_init(Vec::new, |corners, f| {
                corners.clear();
                corners.extend(self.face_positions(FaceId(f)));
                planarity_error(corners)
            })
            .collect()
    }

    /// Area, bounding box and planarity, with faces above `planarity_tolerance` counted.
    pub fn geometry_facts(&self, planarity_tolerance: f64) -> GeometryFacts {
        let (lo, hi) = super::geometry::bounding_box(self.positions.iter().copied());
        let errors = self.face_planarity_errors();
        let (least_planar_face, max_planarity_error) =
            errors
                .iter()
                .enumerate()
                .fold((None, 0.0f64), |(best_f, best), (f, &e)| {
                    if e > best {
                        (Some(f as u32), e)
                    } else {
                        (best_f, best)
                    }
                });
        GeometryFacts {
            surface_area: self.faces().map(|f| self.face_area(f)).sum(),
            bbox_min: lo.to_array(),
            bbox_max: hi.to_array(),
            max_planarity_error,
            least_planar_face,
            non_planar_faces: errors.iter().filter(|&&e| e > planarity_tolerance).count(),
            planarity_tolerance,
        }
    }
}
