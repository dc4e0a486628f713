//! Where each panel sits on the model: the piece of surface it covers and the point its
//! id is shown at, for the assembly map. A face panel covers its face; an edge panel
//! the two triangles between its edge and the centres of the edge's faces (so the
//! edge panels of a face share it like the slices of a cake); a woven segment its own
//! ribbon, which lies over the surface; an island its faces.

use glam::DVec3;

use super::{Panels, Source};
use crate::mesh::geometry::vector_area;
use crate::mesh::{EdgeId, FaceId, Mesh};

/// A piece of surface owned by one panel: a planar convex polygon, counter-clockwise
/// seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Corners (mm).
    pub points: Vec<DVec3>,
    /// Outward unit normal.
    pub normal: DVec3,
    /// The panel's index.
    pub panel: usize,
}

/// The surface of every panel of a build.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelSurface {
    /// Every panel's patches, in panel order.
    pub patches: Vec<Patch>,
    /// Where each panel's id is shown: its face's centre, its edge's midpoint, the
    /// centre of the middle facet of its ribbon.
    pub anchors: Vec<DVec3>,
    /// The model has no boundary: its inside is never seen.
    pub closed: bool,
}

/// Where the `panels` the scheme built from `mesh` sit on it; `islands` lists the faces
/// of each island panel (`Source::Island(k)`: entry k − 1).
pub fn panel_surface(mesh: &Mesh, panels: &Panels, islands: &[Vec<u32>]) -> PanelSurface {
    let island = |k: u32| islands.get(k as usize - 1).map_or(&[][..], Vec::as_slice);
    PanelSurface {
        patches: patches(mesh, panels, island),
        anchors: panels
            .iter()
            .map(|p| match p.source {
                Source::Island(k) => island_anchor(mesh, island(k)),
                _ => anchor(mesh, p.source, p.vertices, p.facets.iter().collect()),
            })
            .collect(),
        closed: mesh.edges().all(|e| !mesh.is_boundary_edge(e)),
    }
}

/// The surface each panel covers (see the module's doc).
fn patches<'a>(mesh: &Mesh, panels: &Panels, island: impl Fn(u32) -> &'a [u32]) -> Vec<Patch> {
    let mut patches = Vec::new();
    let face_patch = |f: FaceId, k: usize| Patch {
        points: mesh.face_positions(f).collect(),
        normal: mesh.face_normal(f),
        panel: k,
    };
    for (k, panel) in panels.iter().enumerate() {
        match panel.source {
            Source::Face(f) => patches.push(face_patch(FaceId(f), k)),
            Source::Island(i) => {
                patches.extend(island(i).iter().map(|&f| face_patch(FaceId(f), k)));
            }
            Source::Edge(e) => {
                let h = EdgeId(e).half_edge();
                for h in [h, h.twin()] {
                    if let Some(f) = mesh.face(h) {
                        patches.push(Patch {
                            points: vec![
                                mesh.face_centre(f),
                                mesh.position(mesh.origin(h)),
                                mesh.position(mesh.dest(h)),
                            ],
                            normal: mesh.face_normal(f),
                            panel: k,
                        });
                    }
                }
            }
            Source::Cycle { .. } => {
                for facet in panel.facets.iter() {
                    let points: Vec<DVec3> =
                        facet.iter().map(|&i| panel.vertices[i as usize]).collect();
                    let normal = vector_area(points.iter().copied()).normalize_or_zero();
                    patches.push(Patch {
                        points,
                        normal,
                        panel: k,
                    });
                }
            }
        }
    }
    patches
}

/// Where an island's id goes: the centre of its face nearest the middle of their
/// centres.
fn island_anchor(mesh: &Mesh, faces: &[u32]) -> DVec3 {
    let centres: Vec<DVec3> = faces.iter().map(|&f| mesh.face_centre(FaceId(f))).collect();
    let middle = centres.iter().copied().sum::<DVec3>() / centres.len().max(1) as f64;
    centres
        .into_iter()
        .min_by(|a, b| a.distance(middle).total_cmp(&b.distance(middle)))
        .unwrap_or(DVec3::ZERO)
}

/// Where a panel's id goes: its face's centre, its edge's midpoint, the centre of the
/// middle facet of its ribbon.
fn anchor(mesh: &Mesh, source: Source, vertices: &[DVec3], facets: Vec<&[u32]>) -> DVec3 {
    match source {
        Source::Face(f) => mesh.face_centre(FaceId(f)),
        Source::Edge(e) => {
            let (a, b) = mesh.edge_vertices(EdgeId(e));
            0.5 * (mesh.position(a) + mesh.position(b))
        }
        // Islands are placed by `island_anchor`.
        Source::Cycle { .. } | Source::Island(_) => {
            let Some(facet) = facets.get(facets.len() / 2) else {
                return DVec3::ZERO;
            };
            facet.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / facet.len() as f64
        }
    }
}
