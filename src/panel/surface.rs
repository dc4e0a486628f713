//! Where each panel sits on the model: the piece of surface it covers and the point its
//! id is shown at, for the assembly map. A face panel covers its face; an edge panel
//! the two triangles between its edge and the centres of the edge's faces (so the
//! edge panels of a face share it like the slices of a cake); a woven segment its own
//! ribbon, which lies over the surface.

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

/// Where the `panels` the scheme built from `mesh` sit on it.
pub fn panel_surface(mesh: &Mesh, panels: &Panels) -> PanelSurface {
    PanelSurface {
        patches: patches(mesh, panels),
        anchors: panels
            .iter()
            .map(|p| anchor(mesh, p.source, p.vertices, p.facets.iter().collect()))
            .collect(),
        closed: mesh.edges().all(|e| !mesh.is_boundary_edge(e)),
    }
}

/// The surface each panel covers (see the module's doc).
fn patches(mesh: &Mesh, panels: &Panels) -> Vec<Patch> {
    let mut patches = Vec::new();
    for (k, panel) in panels.iter().enumerate() {
        match panel.source {
            Source::Face(f) => {
                let f = FaceId(f);
                patches.push(Patch {
                    points: mesh.face_positions(f).collect(),
                    normal: mesh.face_normal(f),
                    panel: k,
                });
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

/// Where a panel's id goes: its face's centre, its edge's midpoint, the centre of the
/// middle facet of its ribbon.
fn anchor(mesh: &Mesh, source: Source, vertices: &[DVec3], facets: Vec<&[u32]>) -> DVec3 {
    match source {
        Source::Face(f) => mesh.face_centre(FaceId(f)),
        Source::Edge(e) => {
            let (a, b) = mesh.edge_vertices(EdgeId(e));
            0.5 * (mesh.position(a) + mesh.position(b))
        }
        Source::Cycle { .. } => {
            let Some(facet) = facets.get(facets.len() / 2) else {
                return DVec3::ZERO;
            };
            facet.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / facet.len() as f64
        }
    }
}
