//! Splitting faces the schemes cannot build as one panel piece: non-planar faces (a
//! panel facet must be flat) and faces that are not star-shaped from their centre (the
//! bands, tabs and flaps of every scheme are built toward the face centre and would
//! leave the face). Quads split along the diagonal with the smaller fold; larger
//! polygons are ear-clipped in their best-fit plane.

use glam::{DVec2, DVec3};

use super::build::{build_mesh, BuildError};
use super::geometry::{best_fit_plane, planarity_error};
use super::halfedge::Mesh;
use super::ids::FaceId;
use super::polygons::Polygons;

/// Why faces were split.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SplitReport {
    /// Faces split because they were not planar within the tolerance.
    pub non_planar: Vec<u32>,
    /// Faces split because they were not star-shaped from their centre (or, when the
    /// scheme needs it, not convex).
    pub not_star_shaped: Vec<u32>,
}

impl SplitReport {
    /// Number of faces split.
    pub fn count(&self) -> usize {
        self.non_planar.len() + self.not_star_shaped.len()
    }
}

/// True when every edge of the face sees the face centre strictly on its inner side,
/// so the triangles (edge, centre) tile the face without overlap.
pub fn is_star_shaped_from_centre(mesh: &Mesh, f: FaceId) -> bool {
    let c = mesh.face_centre(f);
    let n = mesh.face_normal(f);
    let corners: Vec<DVec3> = mesh.face_positions(f).collect();
    (0..corners.len()).all(|i| {
        let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
        (b - a).cross(c - a).dot(n) > 1e-12 * (b - a).length_squared()
    })
}

/// True when every corner of the face turns left (seen from outside).
pub fn is_convex(mesh: &Mesh, f: FaceId) -> bool {
    let n = mesh.face_normal(f);
    let corners: Vec<DVec3> = mesh.face_positions(f).collect();
    let m = corners.len();
    (0..m).all(|i| {
        let (a, b, c) = (corners[i], corners[(i + 1) % m], corners[(i + 2) % m]);
        (b - a).cross(c - b).dot(n) > 0.0
    })
}

/// The faces that need splitting: non-planar beyond `planarity_tol` (relative to face
/// size), or not star-shaped from their centre, or (with `convex`) not convex.
pub fn faces_to_split(mesh: &Mesh, planarity_tol: f64, convex: bool) -> SplitReport {
    let mut report = SplitReport::default();
    let errors = mesh.face_planarity_errors();
    for f in mesh.faces() {
        if mesh.face_degree(f) == 3 {
            continue;
        }
        if errors[f.index()] > planarity_tol {
            report.non_planar.push(f.0);
        } else if !is_star_shaped_from_centre(mesh, f) || (convex && !is_convex(mesh, f)) {
            report.not_star_shaped.push(f.0);
        }
    }
    report
}

/// Splits the listed faces into triangles and rebuilds the mesh. Vertices keep their
/// indices; faces keep their input provenance (every triangle of a split face names
/// the face it came from). A diagonal that is already an edge of the mesh (two quads
/// that share two opposite corners, say) would give that edge a third face, so such
/// diagonals are never used; where no split avoids them, the face becomes a fan around
/// a new vertex at its centre.
pub fn split_faces(mesh: &Mesh, report: &SplitReport) -> Result<Mesh, BuildError> {
    let mut existing: std::collections::HashSet<(u32, u32)> = mesh
        .edges()
        .map(|e| {
            let (a, b) = mesh.edge_vertices(e);
            (a.0.min(b.0), a.0.max(b.0))
        })
        .collect();
    let mut split = vec![false; mesh.face_count()];
    for &f in report.non_planar.iter().chain(&report.not_star_shaped) {
        split[f as usize] = true;
    }
    let mut polys = Polygons {
        positions: mesh.positions().to_vec(),
        ..Polygons::new()
    };
    let mut face_source = Vec::with_capacity(mesh.face_count());
    let mut vertex_source: Vec<u32> = mesh.vertices().map(|v| mesh.vertex_source(v)).collect();
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        if !split[f.index()] {
            polys.push_face(&corners);
            face_source.push(mesh.face_source(f));
            continue;
        }
        let points: Vec<DVec3> = corners
            .iter()
            .map(|&v| polys.positions[v as usize])
            .collect();
        let key = |a: u32, b: u32| (a.min(b), a.max(b));
        let triangles: Vec<[u32; 3]> = triangulate(&points)
            .into_iter()
            .map(|t| t.map(|k| corners[k]))
            .collect();
        // Diagonals are the triangle sides that are not sides of the face.
        let n = corners.len();
        let sides: std::collections::HashSet<(u32, u32)> = (0..n)
            .map(|i| key(corners[i], corners[(i + 1) % n]))
            .collect();
        let diagonals: Vec<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| [key(t[0], t[1]), key(t[1], t[2]), key(t[2], t[0])])
            .filter(|d| !sides.contains(d))
            .collect();
        if diagonals.iter().all(|d| !existing.contains(d)) {
            existing.extend(diagonals);
            for t in triangles {
                polys.push_face(&t);
                face_source.push(mesh.face_source(f));
            }
        } else {
            let centre = points.iter().copied().sum::<DVec3>() / n as f64;
            let c = polys.positions.len() as u32;
            polys.positions.push(centre);
            vertex_source.push(mesh.vertex_source(crate::mesh::VertexId(corners[0])));
            for i in 0..n {
                polys.push_face(&[corners[i], corners[(i + 1) % n], c]);
                face_source.push(mesh.face_source(f));
            }
        }
    }
    build_mesh(&polys, Some(&vertex_source), Some(&face_source)).map(|(m, _)| m)
}

/// Triangles (as corner positions' indices) covering a polygon. Quads: the diagonal
/// whose two triangles fold least. Otherwise ear clipping in the best-fit plane, which
/// handles concave polygons; if numerical trouble leaves no ear, a fan closes the rest.
pub fn triangulate(points: &[DVec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    if n == 4 {
        let fold = |a: usize, b: usize, c: usize, d: usize| {
            let n1 = (points[b] - points[a]).cross(points[c] - points[a]);
            let n2 = (points[c] - points[a]).cross(points[d] - points[a]);
            n1.normalize_or_zero().dot(n2.normalize_or_zero())
        };
        // Larger cosine = smaller fold. Diagonal 0-2 or 1-3.
        return if fold(0, 1, 2, 3) >= fold(1, 2, 3, 0) {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[1, 2, 3], [1, 3, 0]]
        };
    }
    let (centre, normal) = best_fit_plane(points);
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let flat: Vec<DVec2> = points
        .iter()
        .map(|&p| DVec2::new((p - centre).dot(u), (p - centre).dot(v)))
        .collect();
    let mut remaining: Vec<usize> = (0..n).collect();
    let mut triangles = Vec::with_capacity(n - 2);
    while remaining.len() > 3 {
        let m = remaining.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (
                remaining[(i + m - 1) % m],
                remaining[i],
                remaining[(i + 1) % m],
            );
            let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
            if (pb - pa).perp_dot(pc - pa) <= 0.0 {
                return false; // reflex or flat corner
            }
            remaining
                .iter()
                .all(|&k| k == a || k == b || k == c || !inside_triangle(flat[k], pa, pb, pc))
        });
        let Some(i) = ear else { break };
        let m = remaining.len();
        triangles.push([
            remaining[(i + m - 1) % m],
            remaining[i],
            remaining[(i + 1) % m],
        ]);
        remaining.remove(i);
    }
    for k in 1..remaining.len().saturating_sub(1) {
        triangles.push([remaining[0], remaining[k], remaining[k + 1]]);
    }
    triangles
}

fn inside_triangle(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    let d1 = (b - a).perp_dot(p - a);
    let d2 = (c - b).perp_dot(p - b);
    let d3 = (a - c).perp_dot(p - c);
    d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0
}

/// The planarity error of every triangle is zero; kept here so callers can check
/// their split result without recomputing faces by hand.
pub fn max_planarity_error(mesh: &Mesh) -> f64 {
    mesh.faces()
        .map(|f| planarity_error(&mesh.face_positions(f).collect::<Vec<_>>()))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build_from_faces;

    #[test]
    fn concave_polygon_is_ear_clipped_into_n_minus_2_triangles() {
        // An L-shaped hexagon (concave) in the plane z = 0.
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .map(|(x, y)| DVec3::new(x, y, 0.0));
        let tris = triangulate(&l);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris
            .iter()
            .map(|t| 0.5 * (l[t[1]] - l[t[0]]).cross(l[t[2]] - l[t[0]]).z)
            .sum();
        assert!(
            (area - 3.0).abs() < 1e-12,
            "triangles keep orientation and area"
        );
    }

    #[test]
    fn warped_quad_is_split_and_the_mesh_stays_valid() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.3),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.3),
        ];
        let mesh = build_from_faces(positions, &[[0u32, 1, 2, 3]]).unwrap();
        let report = faces_to_split(&mesh, 1e-3, false);
        assert_eq!(report.non_planar, vec![0]);
        let split = split_faces(&mesh, &report).unwrap();
        assert_eq!(split.face_count(), 2);
        assert_eq!(split.validate(), Ok(()));
        assert_eq!(max_planarity_error(&split), 0.0);
        assert!(split.faces().all(|f| split.face_source(f) == 0));
    }
}
