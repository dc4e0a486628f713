//! Rigid panels: sheet material of thickness T that does not bend. Each panel's outer
//! face lies on its face plane and its material goes inward. A laser cuts square to
//! the sheet, so along a convex edge one panel, or both, is cut back from the edge
//! until the two no longer pass through each other: at an obtuse edge of interior
//! angle δ the larger face gives up T·sin δ (a V-groove that wide stays open on the
//! outside), at an acute edge the two give up T·cot δ and T·cot(δ/2); concave edges
//! need nothing. Where corners still collide (more than three faces at a vertex),
//! every panel there is cut back from the vertex, across its corner, until no two
//! overlap. Every claim is checked: the panels, as square-cut prisms, are tested
//! pairwise for overlap before they are returned.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DVec2, DVec3};

use crate::mesh::distance::{cell_table, TriangleGrid};
use crate::mesh::geometry::PlaneFrame;
use crate::mesh::{FaceId, HalfedgeId, Mesh, VertexId};

/// Two parts may overlap by this much (mm): rounding, not material.
pub(super) const OVERLAP_TOLERANCE: f64 = 1e-6;

/// Shortest side a cut-back outline may keep along a face edge (mm).
const SHORTEST_SIDE: f64 = 1e-3;

/// Halvings when searching the cut-back of a vertex (to below a millionth of T).
const SEARCH_STEPS: u32 = 24;

/// A face's panel outline on its face plane, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidOutline {
    /// The corners.
    pub points: Vec<DVec3>,
    /// For side `k` (from corner k to corner k + 1) the half-edge of the face it lies
    /// along (cut back or not); `None` for a cut across a corner.
    pub along: Vec<Option<HalfedgeId>>,
}

/// The rigid panels of a mesh and what cutting them back took.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidPanels {
    /// Each face's outline, in face order.
    pub outlines: Vec<RigidOutline>,
    /// Interior edges along which a panel is cut back.
    pub edges_cut: usize,
    /// The widest cut back from an edge (mm).
    pub widest_edge_cut: f64,
    /// Vertices whose corners are cut back, each with how far (mm from the vertex).
    pub vertices_cut: Vec<(VertexId, f64)>,
}

/// Why rigid panels of a thickness cannot be made.
#[derive(Clone, Debug, PartialEq)]
pub enum RigidError {
    /// A face has no panel left once cut back from its edges and corners.
    NoRoom {
        /// The face.
        face: FaceId,
    },
    /// A panel would stick out of the model (at a saddle, through a neighbour face).
    SticksOut {
        /// The face.
        face: FaceId,
        /// How far (mm).
        depth: f64,
    },
    /// Two panels would pass through each other inside the model.
    Overlap {
        /// The two faces.
        faces: [FaceId; 2],
        /// How deep (mm).
        depth: f64,
    },
}

/// How far the two panels at an edge of interior angle `delta` (radians) are cut back
/// from it: (the panel that keeps most, the other).
pub fn edge_cut_back(thickness: f64, delta: f64) -> (f64, f64) {
    if delta >= PI {
        (0.0, 0.0)
    } else if delta >= FRAC_PI_2 {
        (0.0, thickness * delta.sin())
    } else {
        (thickness / delta.tan(), thickness / (0.5 * delta).tan())
    }
}

/// The interior angle between the faces of `h` and of its twin (radians): below π at
/// a convex edge, above at a concave one.
pub fn interior_angle(mesh: &Mesh, h: HalfedgeId) -> f64 {
    let (Some(a), Some(b)) = (mesh.face(h), mesh.face(h.twin())) else {
        return PI;
    };
    let (na, nb) = (mesh.face_normal(a), mesh.face_normal(b));
    let along = (mesh.position(mesh.dest(h)) - mesh.position(mesh.origin(h))).normalize_or_zero();
    PI - na.cross(nb).dot(along).atan2(na.dot(nb))
}

/// The rigid panels of every face of `mesh` in material `thickness` mm thick, kept
/// inside `surface` (the model's own faces, which `mesh` may merge into larger ones).
pub fn rigid_panels(
    mesh: &Mesh,
    surface: &Mesh,
    thickness: f64,
) -> Result<RigidPanels, RigidError> {
    let insets = edge_insets(mesh, thickness);
    let frames: Vec<PlaneFrame> = mesh.faces().map(|f| first_side_frame(mesh, f)).collect();
    let mut outlines = Vec::with_capacity(mesh.face_count());
    for f in mesh.faces() {
        let outline = inset_outline(mesh, f, &frames[f.0 as usize], &insets)
            .ok_or(RigidError::NoRoom { face: f })?;
        outlines.push(outline);
    }
    let solid = Solid::of(surface);
    let nearest = TriangleGrid::new(&solid.triangles);
    let mut vertices_cut = Vec::new();
    for v in mesh.vertices() {
        let at = Corner {
            mesh,
            v,
            thickness,
            frames: &frames,
            solid: &solid,
            nearest: &nearest,
        };
        if let Some(r) = at.cut_back(&mut outlines)? {
            vertices_cut.push((v, r));
        }
    }
    check_apart(thickness, &frames, &outlines)?;
    let cut: Vec<f64> = mesh
        .edges()
        .map(|e| insets[e.half_edge().0 as usize].max(insets[e.half_edge().twin().0 as usize]))
        .filter(|&d| d > 0.0)
        .collect();
    Ok(RigidPanels {
        outlines: outlines
            .iter()
            .zip(&frames)
            .map(|(o, frame)| RigidOutline {
                points: o.points.iter().map(|&p| frame.lift(p)).collect(),
                along: o.along.clone(),
            })
            .collect(),
        edges_cut: cut.len(),
        widest_edge_cut: cut.iter().copied().fold(0.0, f64::max),
        vertices_cut,
    })
}

/// The largest thickness up to `thickness` for which [`rigid_panels`] succeeds,
/// found by halving (to a thousandth of `thickness`).
pub fn thickest(mesh: &Mesh, surface: &Mesh, thickness: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, thickness);
    while hi - lo > 1e-3 * thickness {
        let mid = 0.5 * (lo + hi);
        if rigid_panels(mesh, surface, mid).is_ok() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// How far each half-edge's face is cut back along it (mm), by half-edge index: the
/// larger face gives up the strip, so small faces keep their size.
fn edge_insets(mesh: &Mesh, thickness: f64) -> Vec<f64> {
    let mut insets = vec![0.0; mesh.half_edge_count()];
    for e in mesh.edges() {
        let h = e.half_edge();
        let (Some(a), Some(b)) = (mesh.face(h), mesh.face(h.twin())) else {
            continue;
        };
        let (keeper, other) = edge_cut_back(thickness, interior_angle(mesh, h));
        let a_keeps = mesh
            .face_area(a)
            .total_cmp(&mesh.face_area(b))
            .then(a.0.cmp(&b.0))
            .is_lt();
        let (at_a, at_b) = if a_keeps {
            (keeper, other)
        } else {
            (other, keeper)
        };
        insets[h.0 as usize] = at_a;
        insets[h.twin().0 as usize] = at_b;
    }
    insets
}

/// A face's plane with axes, x along its first side.
fn first_side_frame(mesh: &Mesh, f: FaceId) -> PlaneFrame {
    let normal = mesh.face_normal(f);
    let h = mesh.face_half_edge(f);
    let side = mesh.position(mesh.dest(h)) - mesh.position(mesh.origin(h));
    let x = side.reject_from_normalized(normal).normalize_or_zero();
    PlaneFrame::with_x(mesh.face_centre(f), normal, x)
}

/// An outline in its face's frame.
#[derive(Clone, Debug)]
struct FlatOutline {
    points: Vec<DVec2>,
    along: Vec<Option<HalfedgeId>>,
}

/// Face `f`'s outline with each side moved inward by its inset, corners where the
/// moved sides meet; `None` when a side vanishes or the outline crosses itself.
fn inset_outline(
    mesh: &Mesh,
    f: FaceId,
    frame: &PlaneFrame,
    insets: &[f64],
) -> Option<FlatOutline> {
    let sides: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
    let n = sides.len();
    let corner: Vec<DVec2> = sides
        .iter()
        .map(|&h| frame.flat(mesh.position(mesh.origin(h))))
        .collect();
    let dir: Vec<DVec2> = (0..n)
        .map(|k| (corner[(k + 1) % n] - corner[k]).normalize_or_zero())
        .collect();
    // A point of side k moved inward (to its left) by its inset.
    let moved = |k: usize| corner[k] + insets[sides[k].0 as usize] * dir[k].perp();
    let mut outline = FlatOutline {
        points: Vec::with_capacity(n + 2),
        along: Vec::with_capacity(n + 2),
    };
    for k in 0..n {
        let before = (k + n - 1) % n;
        let (a, b) = (
            moved(before),
            corner[k] + insets[sides[k].0 as usize] * dir[k].perp(),
        );
        let turn = dir[before].perp_dot(dir[k]);
        if turn.abs() < 1e-9 {
            // Straight on: the two sides may be moved by different amounts, a step.
            let a = a + (corner[k] - corner[before]).dot(dir[before]) * dir[before];
            outline.points.push(a);
            if a.distance(b) > 1e-9 {
                outline.along.push(None);
                outline.points.push(b);
            }
        } else {
            let s = (b - a).perp_dot(dir[k]) / turn;
            outline.points.push(a + s * dir[before]);
        }
        outline.along.push(Some(sides[k]));
    }
    outline_is_sound(&outline, &sides, &dir).then_some(outline)
}

/// Every side along a face edge keeps its direction and some length, and the outline
/// does not cross itself.
fn outline_is_sound(outline: &FlatOutline, sides: &[HalfedgeId], dir: &[DVec2]) -> bool {
    let m = outline.points.len();
    let keeps_sides = (0..m).all(|i| match outline.along[i] {
        Some(h) => {
            let k = sides.iter().position(|&s| s == h).unwrap_or(0);
            (outline.points[(i + 1) % m] - outline.points[i]).dot(dir[k]) > SHORTEST_SIDE
        }
        None => true,
    });
    keeps_sides
        && crate::plane::signed_area(&outline.points) > 0.0
        && crate::plane::is_simple(&outline.points)
}

/// The panels at one vertex, to cut back.
struct Corner<'a> {
    mesh: &'a Mesh,
    v: VertexId,
    thickness: f64,
    frames: &'a [PlaneFrame],
    solid: &'a Solid,
    /// The solid's triangles, for how far a point lies outside it.
    nearest: &'a TriangleGrid<'a>,
}

impl Corner<'_> {
    /// Cuts back the corners of the panels at the vertex until no two of them overlap
    /// and none sticks out of the model; how far (mm from the vertex), or `None` when
    /// nothing needed cutting.
    fn cut_back(&self, outlines: &mut [FlatOutline]) -> Result<Option<f64>, RigidError> {
        let faces: Vec<(FaceId, CornerFrame)> = self
            .mesh
            .vertex_faces(self.v)
            .filter_map(|f| {
                Some((
                    f,
                    CornerFrame::of(self.mesh, f, self.v, &self.frames[f.0 as usize])?,
                ))
            })
            .collect();
        let now: Vec<FlatOutline> = faces
            .iter()
            .map(|(f, _)| outlines[f.0 as usize].clone())
            .collect();
        if self.worst(&faces, &now).is_none() {
            return Ok(None);
        }
        // Widen until clear (a cut that leaves a face no room ends the search), then
        // narrow down to the least cut that clears them.
        // A cut reaches at most to the middle of a corner's shorter side.
        let deepest = 0.999
            * faces
                .iter()
                .map(|(_, c)| c.reach)
                .fold(f64::INFINITY, f64::min);
        let mut hi = self.thickness.min(deepest);
        loop {
            let trial = self.cut(&faces, hi, outlines)?;
            match self.worst(&faces, &trial) {
                None => break,
                Some(error) if hi >= deepest || hi > 1e3 * self.thickness => return Err(error),
                Some(_) => hi = (2.0 * hi).min(deepest),
            }
        }
        let mut lo = 0.0;
        for _ in 0..SEARCH_STEPS {
            let mid = 0.5 * (lo + hi);
            match self.cut(&faces, mid, outlines) {
                Ok(trial) if self.worst(&faces, &trial).is_none() => hi = mid,
                _ => lo = mid,
            }
        }
        for (&(f, _), outline) in faces.iter().zip(self.cut(&faces, hi, outlines)?) {
            outlines[f.0 as usize] = outline;
        }
        Ok(Some(hi))
    }

    /// The outlines of `faces` with their corners at the vertex cut `r` mm in.
    fn cut(
        &self,
        faces: &[(FaceId, CornerFrame)],
        r: f64,
        outlines: &[FlatOutline],
    ) -> Result<Vec<FlatOutline>, RigidError> {
        faces
            .iter()
            .map(|(f, corner)| {
                let frame = &self.frames[f.0 as usize];
                cut_corner(self.mesh, *f, corner, frame, &outlines[f.0 as usize], r)
                    .ok_or(RigidError::NoRoom { face: *f })
            })
            .collect()
    }

    /// The worst fault near the vertex of the panels of `faces` with outlines `cut`:
    /// two overlapping, or a corner sticking out of the model; `None` when there is
    /// none. (Faults elsewhere are the other vertices' to cut back.)
    fn worst(&self, faces: &[(FaceId, CornerFrame)], cut: &[FlatOutline]) -> Option<RigidError> {
        let near: Vec<FlatOutline> = faces.iter().zip(cut).map(|((_, c), o)| c.near(o)).collect();
        let faces: Vec<FaceId> = faces.iter().map(|&(f, _)| f).collect();
        let cut = &near;
        let t = self.thickness;
        let mut worst: Option<(f64, RigidError)> = None;
        let mut note = |depth: f64, error: RigidError| {
            if depth > OVERLAP_TOLERANCE && worst.as_ref().is_none_or(|(d, _)| depth > *d) {
                worst = Some((depth, error));
            }
        };
        let prisms: Vec<Vec<Prism>> = faces
            .iter()
            .zip(cut)
            .map(|(&f, o)| prisms_of(&self.frames[f.0 as usize], o, t))
            .collect();
        for i in 0..faces.len() {
            for j in i + 1..faces.len() {
                let depth = overlap(&prisms[i], &prisms[j]);
                note(
                    depth,
                    RigidError::Overlap {
                        faces: [faces[i], faces[j]],
                        depth,
                    },
                );
            }
            let frame = &self.frames[faces[i].0 as usize];
            for &p in &cut[i].points {
                let q = frame.lift(p) - t * frame.normal;
                // Below every face plane at the vertex is inside the model there; only
                // the other points need the whole surface's word.
                let below_all = faces.iter().all(|g| {
                    let plane = &self.frames[g.0 as usize];
                    (q - plane.origin).dot(plane.normal) <= 0.0
                });
                if !below_all {
                    let depth = self.solid.outside_by(q, self.nearest);
                    note(
                        depth,
                        RigidError::SticksOut {
                            face: faces[i],
                            depth,
                        },
                    );
                }
            }
        }
        worst.map(|(_, error)| error)
    }
}

/// The model as a solid, where it is closed: which points lie outside it, by casting
/// a ray along +z and counting the surface's crossings (odd: inside). The triangles are
/// binned by their shadow on the xy plane, so a ray meets only those over its cell.
struct Solid {
    /// Its faces as triangles; empty when the model is open (no inside to keep to).
    triangles: Vec<[DVec3; 3]>,
    /// The grid's corner, cell side and cells across and down.
    lo: DVec2,
    cell: f64,
    dims: [usize; 2],
    /// The triangles over each cell (CSR: cell k's are `entries[starts[k]..starts[k + 1]]`).
    starts: Vec<u32>,
    entries: Vec<u32>,
}

impl Solid {
    fn of(mesh: &Mesh) -> Solid {
        let closed = mesh.edges().all(|e| !mesh.is_boundary_edge(e));
        let mut triangles = Vec::new();
        for f in mesh.faces().filter(|_| closed) {
            let p: Vec<DVec3> = mesh.face_positions(f).collect();
            triangles.extend((1..p.len() - 1).map(|k| [p[0], p[k], p[k + 1]]));
        }
        let shadow = |t: &[DVec3; 3]| {
            let xy = t.map(|p| p.truncate());
            (xy[0].min(xy[1]).min(xy[2]), xy[0].max(xy[1]).max(xy[2]))
        };
        let (lo, hi) = triangles.iter().map(shadow).fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
        let mut extents: Vec<f64> = triangles
            .iter()
            .map(|t| {
                let (a, b) = shadow(t);
                (b - a).max_element()
            })
            .collect();
        extents.sort_by(f64::total_cmp);
        let size = (hi - lo).max(DVec2::splat(1e-9));
        let typical = extents.get(extents.len() / 2).copied().unwrap_or(1.0);
        let cell = typical.max(size.max_element() / 1024.0).max(1e-9);
        let dims = [size.x, size.y].map(|s| (s / cell) as usize + 1);
        let index = |p: DVec2| {
            let k = ((p - lo) / cell).floor();
            [
                (k.x.max(0.0) as usize).min(dims[0] - 1),
                (k.y.max(0.0) as usize).min(dims[1] - 1),
            ]
        };
        let ranges: Vec<([usize; 2], [usize; 2])> = triangles
            .iter()
            .map(|t| {
                let (a, b) = shadow(t);
                (index(a), index(b))
            })
            .collect();
        let (starts, entries) = cell_table(dims[0] * dims[1], ranges.len(), |t| {
            let (a, b) = ranges[t];
            (a[1]..=b[1]).flat_map(move |y| (a[0]..=b[0]).map(move |x| x + dims[0] * y))
        });
        Solid {
            triangles,
            lo,
            cell,
            dims,
            starts,
            entries,
        }
    }

    /// `q` lies inside the closed surface: the ray from it along +z crosses it an odd
    /// number of times. A crossing on an edge or corner shared by triangles counts
    /// once: each edge belongs to the one triangle on its top-left side.
    fn contains(&self, q: DVec3) -> bool {
        let p = q.truncate();
        let k = ((p - self.lo) / self.cell).floor();
        if k.x < 0.0 || k.y < 0.0 || k.x as usize >= self.dims[0] || k.y as usize >= self.dims[1] {
            return false;
        }
        let c = k.x as usize + self.dims[0] * k.y as usize;
        let mut crossings = 0;
        for &t in &self.entries[self.starts[c] as usize..self.starts[c + 1] as usize] {
            let [a, mut b, mut c] = self.triangles[t as usize];
            let mut area = (b - a).truncate().perp_dot((c - a).truncate());
            if area == 0.0 {
                continue;
            }
            if area < 0.0 {
                std::mem::swap(&mut b, &mut c);
                area = -area;
            }
            let owns = |u: DVec3, v: DVec3| {
                let w = (v - u).truncate().perp_dot(p - u.truncate());
                let e = (v - u).truncate();
                w > 0.0 || (w == 0.0 && (e.y < 0.0 || (e.y == 0.0 && e.x < 0.0)))
            };
            if owns(a, b) && owns(b, c) && owns(c, a) {
                let weight = |u: DVec3, v: DVec3| (v - u).truncate().perp_dot(p - u.truncate());
                let z = (weight(b, c) * a.z + weight(c, a) * b.z + weight(a, b) * c.z) / area;
                if z > q.z {
                    crossings += 1;
                }
            }
        }
        crossings % 2 == 1
    }

    /// How far `q` lies outside the solid (mm), measured to `nearest`, the grid of its
    /// triangles; zero inside, or when the model is open.
    fn outside_by(&self, q: DVec3, nearest: &TriangleGrid) -> f64 {
        if self.triangles.is_empty() || self.contains(q) {
            return 0.0;
        }
        nearest.distance(q)
    }
}

/// A face's corner at a vertex, in the face's frame.
#[derive(Clone, Copy, Debug)]
struct CornerFrame {
    /// The vertex.
    at: DVec2,
    /// Into the face along the corner's bisector.
    inward: DVec2,
    /// How far along the bisector the corner's own neighbourhood reaches: to the middle
    /// of its shorter side, so that neighbourhoods of one face never meet.
    reach: f64,
}

impl CornerFrame {
    fn of(mesh: &Mesh, f: FaceId, v: VertexId, frame: &PlaneFrame) -> Option<CornerFrame> {
        let out = mesh.face_half_edges(f).find(|&h| mesh.origin(h) == v)?;
        let into = mesh.prev(out);
        let at = frame.flat(mesh.position(v));
        let onward = frame.flat(mesh.position(mesh.dest(out))) - at;
        let back = frame.flat(mesh.position(mesh.origin(into))) - at;
        let shorter = onward.length().min(back.length());
        let (onward, back) = (onward.normalize_or_zero(), back.normalize_or_zero());
        let inward = (onward + back).normalize_or_zero();
        if inward == DVec2::ZERO || back.perp_dot(onward) > 0.0 {
            // A corner running straight on or reflex: a cut across it would take
            // both its sides; its panel is left whole there (the last check, of
            // every pair, still covers it).
            return None;
        }
        let reach = 0.5 * shorter * inward.dot(onward).abs();
        Some(CornerFrame { at, inward, reach })
    }

    /// The part of `outline` near this corner.
    fn near(&self, outline: &FlatOutline) -> FlatOutline {
        if is_convex(&outline.points) {
            return clip_outline(outline, self.at + self.reach * self.inward, -self.inward);
        }
        let side = |p: DVec2| (p - self.at).dot(self.inward) - self.reach;
        if outline.points.iter().all(|&p| side(p) <= 0.0) {
            return outline.clone();
        }
        match side_run(outline, self.at, |p| side(p) <= 0.0) {
            Some((from, to)) => keep_between(outline, from, to, side),
            None => FlatOutline {
                points: Vec::new(),
                along: Vec::new(),
            },
        }
    }
}

/// Face `f`'s outline with its corner at `v` cut off square to the corner's bisector,
/// `r` mm in from the vertex; `None` when the cut takes a whole side.
fn cut_corner(
    mesh: &Mesh,
    f: FaceId,
    corner: &CornerFrame,
    frame: &PlaneFrame,
    outline: &FlatOutline,
    r: f64,
) -> Option<FlatOutline> {
    let cut = if is_convex(&outline.points) {
        clip_outline(outline, corner.at + r * corner.inward, corner.inward)
    } else {
        // The corner's own points inside the cut go; the rest of the outline stays,
        // however far round it comes back (a region's outline need not be convex).
        let side = |p: DVec2| (p - corner.at).dot(corner.inward) - r;
        match side_run(outline, corner.at, |p| side(p) < 0.0) {
            Some((from, to)) => {
                let m = outline.points.len();
                keep_between(outline, (to + 1) % m, (from + m - 1) % m, side)
            }
            None => outline.clone(),
        }
    };
    let sides_kept = outline
        .along
        .iter()
        .flatten()
        .all(|h| cut.along.contains(&Some(*h)));
    let sides: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
    let dir: Vec<DVec2> = sides
        .iter()
        .map(|&h| {
            (frame.flat(mesh.position(mesh.dest(h))) - frame.flat(mesh.position(mesh.origin(h))))
                .normalize_or_zero()
        })
        .collect();
    (r < corner.reach
        && sides_kept
        && cut.points.len() >= 3
        && outline_is_sound(&cut, &sides, &dir))
    .then_some(cut)
}

/// The part of an outline where `(p - at)·inward >= 0`, the cut a side of its own.
fn clip_outline(outline: &FlatOutline, at: DVec2, inward: DVec2) -> FlatOutline {
    let m = outline.points.len();
    let side = |p: DVec2| (p - at).dot(inward);
    let mut clipped = FlatOutline {
        points: Vec::with_capacity(m + 1),
        along: Vec::with_capacity(m + 1),
    };
    for i in 0..m {
        let (p, q) = (outline.points[i], outline.points[(i + 1) % m]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            clipped.points.push(p);
            clipped.along.push(outline.along[i]);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let crossing = p + (q - p) * (sp / (sp - sq));
            clipped.points.push(crossing);
            // Leaving the kept part, the cut runs on to where the outline comes back.
            clipped
                .along
                .push(if sp >= 0.0 { None } else { outline.along[i] });
        }
    }
    clipped
}

/// The run of outline points, from the one nearest `vertex` on both ways round, for
/// which `inside` holds: (first, last) in outline order, the whole outline when all
/// hold; `None` when the nearest point is not inside (or all are, for no run to end).
fn side_run(
    outline: &FlatOutline,
    vertex: DVec2,
    inside: impl Fn(DVec2) -> bool,
) -> Option<(usize, usize)> {
    let m = outline.points.len();
    let nearest = (0..m).min_by(|&i, &j| {
        let (a, b) = (outline.points[i], outline.points[j]);
        a.distance(vertex)
            .total_cmp(&b.distance(vertex))
            .then(i.cmp(&j))
    })?;
    if !inside(outline.points[nearest]) {
        return None;
    }
    let (mut from, mut to) = (nearest, nearest);
    let mut count = 1;
    while count < m && inside(outline.points[(from + m - 1) % m]) {
        from = (from + m - 1) % m;
        count += 1;
    }
    while count < m && inside(outline.points[(to + 1) % m]) {
        to = (to + 1) % m;
        count += 1;
    }
    (count < m).then_some((from, to))
}

/// The outline's points `from..=to` (in order round it), closed by a cut where the
/// outline crosses `side` = 0 after `to` and before `from`; the cut is a side of its
/// own.
fn keep_between(
    outline: &FlatOutline,
    from: usize,
    to: usize,
    side: impl Fn(DVec2) -> f64,
) -> FlatOutline {
    let m = outline.points.len();
    let crossing = |i: usize| {
        let (p, q) = (outline.points[i], outline.points[(i + 1) % m]);
        let (sp, sq) = (side(p), side(q));
        p + (q - p) * (sp / (sp - sq))
    };
    let mut kept = FlatOutline {
        points: Vec::with_capacity(m + 2),
        along: Vec::with_capacity(m + 2),
    };
    let mut i = from;
    loop {
        kept.points.push(outline.points[i]);
        kept.along.push(outline.along[i]);
        if i == to {
            break;
        }
        i = (i + 1) % m;
    }
    let before = (from + m - 1) % m;
    kept.points.push(crossing(to));
    kept.along.push(None);
    kept.points.push(crossing(before));
    kept.along.push(outline.along[before]);
    kept
}

/// No two panels overlap anywhere, the ones far apart in the mesh included (a wall
/// thinner than two thicknesses).
fn check_apart(
    thickness: f64,
    frames: &[PlaneFrame],
    outlines: &[FlatOutline],
) -> Result<(), RigidError> {
    let prisms: Vec<Vec<Prism>> = outlines
        .iter()
        .zip(frames)
        .map(|(o, frame)| prisms_of(frame, o, thickness))
        .collect();
    let boxes: Vec<(DVec3, DVec3)> = prisms
        .iter()
        .map(|ps| {
            crate::mesh::geometry::bounding_box(ps.iter().flat_map(|p| p.corners.iter().copied()))
        })
        .collect();
    // Sweep along x: only boxes that overlap are compared.
    let mut order: Vec<usize> = (0..prisms.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x).then(a.cmp(&b)));
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            if boxes[j].0.x > boxes[i].1.x {
                break;
            }
            let (a, b) = (boxes[i], boxes[j]);
            if a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any() {
                continue;
            }
            let depth = overlap(&prisms[i], &prisms[j]);
            if depth > OVERLAP_TOLERANCE {
                let mut faces = [FaceId(i as u32), FaceId(j as u32)];
                faces.sort();
                return Err(RigidError::Overlap { faces, depth });
            }
        }
    }
    Ok(())
}

/// A convex part of a panel: a convex polygon on the face plane moved inward by the
/// thickness.
#[derive(Clone, Debug)]
pub(super) struct Prism {
    /// The outer polygon's corners, then the inner one's.
    pub(super) corners: Vec<DVec3>,
    /// Directions whose planes bound it (its faces' normals).
    normals: Vec<DVec3>,
    /// Directions of its edges.
    edges: Vec<DVec3>,
}

/// An outline as convex prisms: itself when convex, else its triangles.
fn prisms_of(frame: &PlaneFrame, outline: &FlatOutline, thickness: f64) -> Vec<Prism> {
    let outer: Vec<DVec3> = outline.points.iter().map(|&p| frame.lift(p)).collect();
    if is_convex(&outline.points) {
        return vec![Prism::new(outer, frame.normal, thickness)];
    }
    crate::mesh::split::triangulate(&outer)
        .into_iter()
        .map(|t| Prism::new(t.map(|k| outer[k]).to_vec(), frame.normal, thickness))
        .collect()
}

impl Prism {
    /// The convex polygon `outer` (counter-clockwise about `normal`) moved
    /// `thickness` against `normal`.
    pub(super) fn new(outer: Vec<DVec3>, normal: DVec3, thickness: f64) -> Prism {
        let mut corners = outer.clone();
        corners.extend(outer.iter().map(|&p| p - thickness * normal));
        let sides: Vec<DVec3> = (0..outer.len())
            .map(|k| (outer[(k + 1) % outer.len()] - outer[k]).normalize_or_zero())
            .collect();
        let mut normals: Vec<DVec3> = sides.iter().map(|s| s.cross(normal)).collect();
        normals.push(normal);
        let mut edges = sides;
        edges.push(normal);
        Prism {
            corners,
            normals,
            edges,
        }
    }
}

/// A panel of `outline` on a plane of `normal`, as convex prisms.
pub(super) fn outline_prisms(outline: &RigidOutline, normal: DVec3, thickness: f64) -> Vec<Prism> {
    let origin = outline.points.first().copied().unwrap_or(DVec3::ZERO);
    let x = outline
        .points
        .get(1)
        .map_or(DVec3::X, |&p| (p - origin).normalize_or_zero());
    let frame = PlaneFrame::with_x(origin, normal, x);
    let flat = FlatOutline {
        points: outline.points.iter().map(|&p| frame.flat(p)).collect(),
        along: outline.along.clone(),
    };
    prisms_of(&frame, &flat, thickness)
}

/// Every turn of a closed polygon is to the left (or straight on).
fn is_convex(poly: &[DVec2]) -> bool {
    let n = poly.len();
    (0..n).all(|k| {
        let (a, b, c) = (poly[k], poly[(k + 1) % n], poly[(k + 2) % n]);
        (b - a).perp_dot(c - b) >= -1e-12 * (b - a).length() * (c - b).length()
    })
}

/// How deep two sets of convex prisms overlap (mm): the deepest pair.
pub(super) fn overlap(a: &[Prism], b: &[Prism]) -> f64 {
    a.iter()
        .flat_map(|p| b.iter().map(move |q| prism_overlap(p, q)))
        .fold(0.0, f64::max)
}

/// How deep two convex prisms overlap (mm), by separating axes: the least overlap of
/// their projections on every face normal and every cross product of two edges; zero
/// when one of them separates the two.
fn prism_overlap(a: &Prism, b: &Prism) -> f64 {
    let span = |corners: &[DVec3], axis: DVec3| {
        corners
            .iter()
            .map(|p| p.dot(axis))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    };
    let mut least = f64::INFINITY;
    let mut test = |axis: DVec3| {
        let (a_lo, a_hi) = span(&a.corners, axis);
        let (b_lo, b_hi) = span(&b.corners, axis);
        least = least.min((a_hi - b_lo).min(b_hi - a_lo));
        least > 0.0
    };
    let crosses = a
        .edges
        .iter()
        .flat_map(|&e| b.edges.iter().map(move |&f| e.cross(f)))
        .filter(|c| c.length_squared() > 1e-12)
        .map(|c| c.normalize());
    let apart = a
        .normals
        .iter()
        .chain(&b.normals)
        .copied()
        .chain(crosses)
        .any(|axis| !test(axis));
    if apart {
        0.0
    } else {
        least.max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::cube;

    #[test]
    fn cut_backs_follow_the_angle() {
        let t = 3.0;
        assert_eq!(edge_cut_back(t, PI), (0.0, 0.0));
        assert_eq!(edge_cut_back(t, 1.5 * PI), (0.0, 0.0));
        let (keep, other) = edge_cut_back(t, FRAC_PI_2);
        assert!(keep.abs() < 1e-12 && (other - t).abs() < 1e-12);
        let (keep, other) = edge_cut_back(t, 0.75 * PI);
        assert!(keep == 0.0 && (other - t * (0.75 * PI).sin()).abs() < 1e-12);
        // 60°: cot 60° and cot 30°.
        let (keep, other) = edge_cut_back(t, PI / 3.0);
        assert!((keep - t / 3f64.sqrt()).abs() < 1e-12);
        assert!((other - t * 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn a_cube_has_right_angles_and_panels_that_do_not_overlap() {
        let mesh = cube(100.0);
        for e in mesh.edges() {
            let delta = interior_angle(&mesh, e.half_edge());
            assert!((delta - FRAC_PI_2).abs() < 1e-9, "{delta}");
        }
        let rigid = rigid_panels(&mesh, &mesh, 3.0).expect("a 100 mm cube takes 3 mm");
        assert_eq!(rigid.edges_cut, 12);
        assert!((rigid.widest_edge_cut - 3.0).abs() < 1e-9);
        assert!(rigid.vertices_cut.is_empty(), "{:?}", rigid.vertices_cut);
        // Each edge: one panel keeps it, the other stops 3 mm short; every panel is a
        // rectangle on its face.
        let area: f64 = rigid
            .outlines
            .iter()
            .map(|o| crate::mesh::geometry::vector_area(o.points.iter().copied()).length())
            .sum();
        // 12 edges each take a 100 x 3 strip, less a 3 x 3 square where two strips of
        // one face meet (24 face corners at most).
        let stripped = 6.0 * 100.0 * 100.0 - 12.0 * 300.0;
        assert!(
            area > stripped - 1e-6 && area < stripped + 24.0 * 9.0 + 1e-6,
            "{area}"
        );
    }

    #[test]
    fn too_thick_for_a_small_cube_is_refused_and_the_thickest_found() {
        let mesh = cube(10.0);
        assert!(matches!(
            rigid_panels(&mesh, &mesh, 6.0),
            Err(RigidError::NoRoom { .. })
        ));
        let t = thickest(&mesh, &mesh, 6.0);
        assert!(t > 4.0 && t < 5.0, "{t}");
        assert!(rigid_panels(&mesh, &mesh, t).is_ok());
    }

    #[test]
    fn rays_find_the_inside_even_through_shared_edges() {
        let mesh = cube(100.0);
        let solid = Solid::of(&mesh);
        let nearest = TriangleGrid::new(&solid.triangles);
        assert!(solid.contains(DVec3::splat(50.0)));
        for q in [
            DVec3::new(50.0, 50.0, 101.0),
            DVec3::new(50.0, 50.0, -1.0),
            DVec3::new(150.0, 50.0, 50.0),
        ] {
            assert!(!solid.contains(q), "{q}");
        }
        assert!((solid.outside_by(DVec3::new(50.0, 50.0, 101.0), &nearest) - 1.0).abs() < 1e-9);
        assert!((solid.outside_by(DVec3::new(150.0, 50.0, 50.0), &nearest) - 50.0).abs() < 1e-9);
        assert_eq!(solid.outside_by(DVec3::splat(50.0), &nearest), 0.0);
        // Rays through the diagonal the top and bottom faces' triangles share cross
        // each face once, not twice.
        for t in [10.0, 25.0, 50.0, 75.0, 90.0] {
            assert!(solid.contains(DVec3::new(t, t, 50.0)), "{t}");
            assert!(solid.contains(DVec3::new(t, 100.0 - t, 50.0)), "{t}");
        }
    }

    #[test]
    fn separating_axes_measure_overlap() {
        let frame = PlaneFrame {
            origin: DVec3::ZERO,
            x: DVec3::X,
            y: DVec3::Y,
            normal: DVec3::Z,
        };
        let square = |x0: f64| FlatOutline {
            points: vec![
                DVec2::new(x0, 0.0),
                DVec2::new(x0 + 10.0, 0.0),
                DVec2::new(x0 + 10.0, 10.0),
                DVec2::new(x0, 10.0),
            ],
            along: vec![None; 4],
        };
        let a = prisms_of(&frame, &square(0.0), 2.0);
        let b = prisms_of(&frame, &square(9.5), 2.0);
        assert!((overlap(&a, &b) - 0.5).abs() < 1e-12);
        let c = prisms_of(&frame, &square(10.0), 2.0);
        assert_eq!(overlap(&a, &c), 0.0);
    }
}
