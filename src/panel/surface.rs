//! Where each panel sits on the model: the piece of surface it covers and the point its
//! id is shown at, for the assembly map, from what its [`Covers`] says.

use glam::DVec3;

use super::{Covers, FaceGroup, Panels};
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
    /// Where each panel's id is shown (see [`Covers`]).
    pub anchors: Vec<DVec3>,
    /// The model has no boundary: its inside is never seen.
    pub closed: bool,
}

/// Where the `panels` the scheme built from `mesh` sit on it; `face_groups` lists the
/// faces of each panel that covers a group of faces (`Covers::Faces(k)`: entry k).
pub fn panel_surface(mesh: &Mesh, panels: &Panels, face_groups: &[FaceGroup]) -> PanelSurface {
    let group = |k: u32| face_groups.get(k as usize);
    let faces = |k: u32| group(k).map_or(&[][..], |g| g.faces.as_slice());
    PanelSurface {
        patches: patches(mesh, panels, faces),
        anchors: panels
            .iter()
            .map(|p| match p.source.covers {
                Covers::Faces(k) => group(k).map_or(DVec3::ZERO, |g| g.anchor),
                covers => anchor(mesh, covers, p.vertices, p.facets.iter().collect()),
            })
            .collect(),
        closed: mesh.edges().all(|e| !mesh.is_boundary_edge(e)),
    }
}

/// The surface each panel covers (see the module's doc).
fn patches<'a>(mesh: &Mesh, panels: &Panels, group: impl Fn(u32) -> &'a [u32]) -> Vec<Patch> {
    let mut patches = Vec::new();
    let face_patch = |f: FaceId, k: usize| Patch {
        points: mesh.face_positions(f).collect(),
        normal: mesh.face_normal(f),
        panel: k,
    };
    for (k, panel) in panels.iter().enumerate() {
        match panel.source.covers {
            Covers::Face(f) => patches.push(face_patch(FaceId(f), k)),
            Covers::Faces(i) => {
                patches.extend(group(i).iter().map(|&f| face_patch(FaceId(f), k)));
            }
            Covers::Edge(e) => {
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
            // Inside the model: nothing of the surface is its.
            Covers::Inside(_) => {}
            Covers::Itself => {
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

/// A place for the id of a group of faces: the centre of its face nearest the middle
/// of their centres (on the surface, where the middle itself may not be).
pub fn group_anchor(mesh: &Mesh, faces: &[u32]) -> DVec3 {
    let centres: Vec<DVec3> = faces.iter().map(|&f| mesh.face_centre(FaceId(f))).collect();
    let middle = centres.iter().copied().sum::<DVec3>() / centres.len().max(1) as f64;
    centres
        .into_iter()
        .min_by(|a, b| a.distance(middle).total_cmp(&b.distance(middle)))
        .unwrap_or(DVec3::ZERO)
}

/// Where a panel's id goes: its face's centre, its edge's midpoint (also for a part
/// inside at an edge), the centre of its own middle facet.
fn anchor(mesh: &Mesh, covers: Covers, vertices: &[DVec3], facets: Vec<&[u32]>) -> DVec3 {
    match covers {
        Covers::Face(f) => mesh.face_centre(FaceId(f)),
        Covers::Edge(e) | Covers::Inside(e) => {
            let (a, b) = mesh.edge_vertices(EdgeId(e));
            0.5 * (mesh.position(a) + mesh.position(b))
        }
        // A group of faces is placed where its scheme said.
        Covers::Itself | Covers::Faces(_) => {
            let Some(facet) = facets.get(facets.len() / 2) else {
                return DVec3::ZERO;
            };
            facet.iter().map(|&i| vertices[i as usize]).sum::<DVec3>() / facet.len() as f64
        }
    }
}
