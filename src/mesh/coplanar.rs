//! Flat regions: neighbouring faces that lie in one plane, merged into one polygon face
//! each, for panels that cannot fold (rigid sheet). A region grows only while it stays
//! a disk (its faces meet it along one run of edges and touch it nowhere else), so its
//! outline is one simple polygon. A corner where the outline runs straight on between
//! the same two regions is dropped, so a seam between two regions is one edge.

use std::collections::VecDeque;

use glam::DVec2;

use super::geometry::PlaneFrame;
use super::{build_mesh, FaceId, HalfedgeId, Mesh, Polygons, VertexId};

/// A mesh's flat regions as a mesh of their own.
#[derive(Clone, Debug)]
pub struct FlatRegions {
    /// The merged mesh: face k is region k, its corners the regions' outline corners.
    pub mesh: Mesh,
    /// Each region's faces of the source mesh, increasing; the regions in the order of
    /// their lowest face.
    pub faces: Vec<Vec<u32>>,
    /// For each edge of the merged mesh, the lowest-numbered source edge along it.
    pub edge_source: Vec<u32>,
}

/// What a region may grow to.
pub struct RegionRules<'a> {
    /// Every corner of a region lies this close to the plane of its first face (mm).
    pub tolerance: f64,
    /// Most faces in one region.
    pub max_faces: usize,
    /// A region's corners, given in its plane, when they still fit (the sheet): the
    /// points that stand for them from then on (their convex hull, say); `None` when
    /// they do not fit.
    pub fits: &'a dyn Fn(&[DVec2]) -> Option<Vec<DVec2>>,
}

/// The flat regions of `mesh`, grown from its faces in order, each taking its
/// neighbours breadth first while they keep to the rules.
pub fn flat_regions(mesh: &Mesh, rules: &RegionRules<'_>) -> Result<FlatRegions, String> {
    let region = grow_regions(mesh, rules);
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for f in mesh.faces() {
        let k = region[f.index()] as usize;
        if k == faces.len() {
            faces.push(Vec::new());
        }
        faces[k].push(f.0);
    }
    let loops: Vec<Vec<HalfedgeId>> = (0..faces.len())
        .map(|k| outline_loop(mesh, &region, k as u32, &faces[k]))
        .collect::<Result<_, _>>()?;
    let dropped = straight_corners(mesh, &region, rules.tolerance, &loops);
    merged_mesh(mesh, faces, &loops, &dropped)
}

/// The region of every face, numbered in the order of their first face.
fn grow_regions(mesh: &Mesh, rules: &RegionRules<'_>) -> Vec<u32> {
    let mut growth = Growth {
        region: vec![u32::MAX; mesh.face_count()],
        touched: vec![
            u32::MAX;
            mesh.vertices()
                .map(|v| mesh.vertex_source(v) as usize + 1)
                .max()
                .unwrap_or(0)
        ],
        queue: VecDeque::new(),
    };
    let mut count = 0u32;
    for seed in mesh.faces() {
        if growth.region[seed.index()] != u32::MAX {
            continue;
        }
        let k = count;
        count += 1;
        // A region's plane is its first face's.
        let plane = mesh.face_frame(seed);
        let mut corners: Vec<DVec2> = mesh.face_positions(seed).map(|p| plane.flat(p)).collect();
        let mut size = 1;
        growth.join(mesh, seed, k);
        while let Some(f) = growth.queue.pop_front() {
            if growth.region[f.index()] != u32::MAX || size >= rules.max_faces {
                continue;
            }
            if !holds(&plane, mesh, f, rules.tolerance) || !growth.keeps_disk(mesh, f, k) {
                continue;
            }
            let mut grown = corners.clone();
            grown.extend(mesh.face_positions(f).map(|p| plane.flat(p)));
            let Some(grown) = (rules.fits)(&grown) else {
                continue;
            };
            corners = grown;
            size += 1;
            growth.join(mesh, f, k);
        }
    }
    growth.region
}

/// Regions as they grow.
struct Growth {
    /// Each face's region, or `u32::MAX`.
    region: Vec<u32>,
    /// The last region touching each input vertex: the copies of a vertex split where
    /// two fans met at it are one point, where a region must not touch itself either.
    touched: Vec<u32>,
    /// Faces to try next.
    queue: VecDeque<FaceId>,
}

impl Growth {
    /// Face `f` joins region `k`; its free neighbours are to be tried.
    fn join(&mut self, mesh: &Mesh, f: FaceId, k: u32) {
        self.region[f.index()] = k;
        for v in mesh.face_vertices(f) {
            self.touched[mesh.vertex_source(v) as usize] = k;
        }
        for h in mesh.face_half_edges(f) {
            if let Some(g) = mesh.face(h.twin()) {
                if self.region[g.index()] == u32::MAX {
                    self.queue.push_back(g);
                }
            }
        }
    }

    /// Region `k` with face `f` added is still a disk: `f` shares one run of its edges
    /// with the region (not all of them) and touches it at no other corner.
    fn keeps_disk(&self, mesh: &Mesh, f: FaceId, k: u32) -> bool {
        let sides: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
        let shared: Vec<bool> = sides
            .iter()
            .map(|&h| {
                mesh.face(h.twin())
                    .is_some_and(|g| self.region[g.index()] == k)
            })
            .collect();
        let n = sides.len();
        let changes = (0..n).filter(|&i| shared[i] != shared[(i + 1) % n]).count();
        if changes != 2 {
            return false;
        }
        // A corner off the run (its sides on either hand not shared) must be new to
        // the region, or the region would pinch there.
        (0..n).all(|i| {
            let before = (i + n - 1) % n;
            let v = mesh.origin(sides[i]);
            shared[i] || shared[before] || self.touched[mesh.vertex_source(v) as usize] != k
        })
    }
}

/// Face `f` faces the same way as `plane` (a region's) and its corners lie within
/// `tolerance` of it.
fn holds(plane: &PlaneFrame, mesh: &Mesh, f: FaceId, tolerance: f64) -> bool {
    mesh.face_normal(f).dot(plane.normal) > 0.0
        && mesh
            .face_positions(f)
            .all(|p| (p - plane.origin).dot(plane.normal).abs() <= tolerance)
}

/// Region `k`'s outline: its boundary half-edges in order round it, from the lowest.
fn outline_loop(
    mesh: &Mesh,
    region: &[u32],
    k: u32,
    faces: &[u32],
) -> Result<Vec<HalfedgeId>, String> {
    let inside = |h: HalfedgeId| mesh.face(h).is_some_and(|g| region[g.index()] == k);
    let mut boundary: Vec<HalfedgeId> = faces
        .iter()
        .flat_map(|&f| mesh.face_half_edges(FaceId(f)))
        .filter(|&h| !inside(h.twin()))
        .collect();
    boundary.sort_unstable();
    let Some(&start) = boundary.first() else {
        return Err(format!("flat region {k} has no outline"));
    };
    let mut outline = vec![start];
    let mut h = start;
    loop {
        // Round the corner at h's end, past the region's own faces.
        let mut next = mesh.next(h);
        while inside(next.twin()) {
            next = mesh.next(next.twin());
        }
        if next == start {
            break;
        }
        if outline.len() > boundary.len() {
            return Err(format!("flat region {k}'s outline does not close"));
        }
        outline.push(next);
        h = next;
    }
    if outline.len() != boundary.len() {
        return Err(format!("flat region {k} has more than one outline"));
    }
    Ok(outline)
}

/// The vertices to drop: where exactly two seams (edges between two regions, or on the
/// mesh's border) meet and run straight on within `tolerance`, unless a region would
/// keep fewer than three corners.
fn straight_corners(
    mesh: &Mesh,
    region: &[u32],
    tolerance: f64,
    loops: &[Vec<HalfedgeId>],
) -> Vec<bool> {
    let side = |h: HalfedgeId| mesh.face(h).map(|f| region[f.index()]);
    let mut dropped: Vec<bool> = mesh
        .vertices()
        .map(|v| {
            let seams: Vec<VertexId> = mesh
                .vertex_outgoing(v)
                .filter(|&h| side(h) != side(h.twin()))
                .map(|h| mesh.dest(h))
                .collect();
            let [a, b] = seams[..] else {
                return false;
            };
            let (p, a, b) = (mesh.position(v), mesh.position(a), mesh.position(b));
            let along = b - a;
            (p - a).dot(along) > 0.0
                && (b - p).dot(along) > 0.0
                && (p - a).reject_from(along).length() <= tolerance
        })
        .collect();
    // Each run of dropped corners must lie within `tolerance` of the chord that
    // replaces it (small turns add up along a finely cut curve), and every region
    // keeps three corners; keeping a corner shortens chords, so until both hold.
    let mut changed = true;
    while changed {
        changed = false;
        for lp in loops {
            let corners: Vec<VertexId> = lp.iter().map(|&h| mesh.origin(h)).collect();
            let kept = corners.iter().filter(|v| !dropped[v.index()]).count();
            if kept < 3 {
                // A third of the way round each: the chords refine from there.
                let n = corners.len();
                for v in [corners[0], corners[n / 3], corners[2 * n / 3]] {
                    changed |= std::mem::replace(&mut dropped[v.index()], false);
                }
                continue;
            }
            if let Some(v) = farthest_off_chord(mesh, &corners, &dropped, tolerance) {
                dropped[v.index()] = false;
                changed = true;
            }
        }
    }
    dropped
}

/// The dropped corner of an outline farthest from the chord between the kept corners
/// round it, when that is more than `tolerance`.
fn farthest_off_chord(
    mesh: &Mesh,
    corners: &[VertexId],
    dropped: &[bool],
    tolerance: f64,
) -> Option<VertexId> {
    let n = corners.len();
    let first = (0..n).find(|&i| !dropped[corners[i].index()])?;
    let mut worst: Option<(f64, VertexId)> = None;
    let mut from = first;
    for step in 1..=n {
        let i = (first + step) % n;
        if dropped[corners[i].index()] {
            continue;
        }
        let (a, b) = (mesh.position(corners[from]), mesh.position(corners[i]));
        let mut k = (from + 1) % n;
        while k != i {
            let p = mesh.position(corners[k]);
            let off = super::distance::segment_distance(p, a, b);
            if off > tolerance && worst.is_none_or(|(d, _)| off > d) {
                worst = Some((off, corners[k]));
            }
            k = (k + 1) % n;
        }
        from = i;
    }
    worst.map(|(_, v)| v)
}

/// The mesh of the regions' outlines less the dropped corners, and each new edge's
/// lowest source edge.
fn merged_mesh(
    mesh: &Mesh,
    faces: Vec<Vec<u32>>,
    loops: &[Vec<HalfedgeId>],
    dropped: &[bool],
) -> Result<FlatRegions, String> {
    let mut index = vec![u32::MAX; mesh.vertex_count()];
    let mut positions = Vec::new();
    let mut vertex_source = Vec::new();
    let mut outlines: Vec<Vec<u32>> = Vec::with_capacity(loops.len());
    // Per region, per corner: the lowest source edge of the side it starts.
    let mut side_sources: Vec<Vec<(u32, u32)>> = Vec::with_capacity(loops.len());
    for lp in loops {
        let first = lp
            .iter()
            .position(|&h| !dropped[mesh.origin(h).index()])
            .unwrap_or(0);
        let mut corners = Vec::new();
        let mut sides: Vec<(u32, u32)> = Vec::new();
        for step in 0..lp.len() {
            let h = lp[(first + step) % lp.len()];
            let v = mesh.origin(h);
            if !dropped[v.index()] {
                if index[v.index()] == u32::MAX {
                    index[v.index()] = positions.len() as u32;
                    positions.push(mesh.position(v));
                    vertex_source.push(mesh.vertex_source(v));
                }
                corners.push(index[v.index()]);
                sides.push((index[v.index()], h.edge().0));
            } else if let Some(last) = sides.last_mut() {
                last.1 = last.1.min(h.edge().0);
            }
        }
        outlines.push(corners);
        side_sources.push(sides);
    }
    let face_source: Vec<u32> = faces
        .iter()
        .map(|f| mesh.face_source(FaceId(f[0])))
        .collect();
    let polys = Polygons::from_faces(positions.clone(), &outlines);
    let (merged, _) = build_mesh(&polys, Some(&vertex_source), Some(&face_source))
        .map_err(|e| format!("flat regions do not make a mesh: {e}"))?;
    if merged.vertex_count() != positions.len() {
        return Err("flat regions meet at a corner only".into());
    }
    let mut edge_source = vec![u32::MAX; merged.edge_count()];
    for (k, sides) in side_sources.iter().enumerate() {
        for h in merged.face_half_edges(FaceId(k as u32)) {
            let at = merged.origin(h).0;
            let source = sides.iter().find(|s| s.0 == at).map_or(u32::MAX, |s| s.1);
            let slot = &mut edge_source[h.edge().index()];
            *slot = (*slot).min(source);
        }
    }
    Ok(FlatRegions {
        mesh: merged,
        faces,
        edge_source,
    })
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::build_from_faces;

    fn rules(fits: &dyn Fn(&[DVec2]) -> Option<Vec<DVec2>>) -> RegionRules<'_> {
        RegionRules {
            tolerance: 1e-6,
            max_faces: usize::MAX,
            fits,
        }
    }

    /// A unit cube of 12 triangles.
    fn triangulated_cube() -> Mesh {
        let (p, quads) = crate::mesh::build::cube_faces(1.0);
        let tris: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        build_from_faces(p, &tris).unwrap()
    }

    /// An n × n grid of unit squares in z = 0, each cut into two triangles.
    fn triangulated_grid(n: u32) -> Mesh {
        let p: Vec<DVec3> = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| DVec3::new(x as f64, y as f64, 0.0)))
            .collect();
        let at = |x: u32, y: u32| y * (n + 1) + x;
        let tris: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| (0..n).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                [
                    [at(x, y), at(x + 1, y), at(x + 1, y + 1)],
                    [at(x, y), at(x + 1, y + 1), at(x, y + 1)],
                ]
            })
            .collect();
        build_from_faces(p, &tris).unwrap()
    }

    #[test]
    fn a_triangulated_cube_becomes_six_squares_with_its_twelve_edges() {
        let cube = triangulated_cube();
        let regions = flat_regions(&cube, &rules(&|p| Some(p.to_vec()))).unwrap();
        assert_eq!(regions.mesh.face_count(), 6);
        assert_eq!(regions.mesh.vertex_count(), 8);
        assert_eq!(regions.mesh.edge_count(), 12);
        assert!(regions
            .mesh
            .faces()
            .all(|f| regions.mesh.face_degree(f) == 4));
        assert_eq!(regions.faces[0], vec![0, 1]);
        // Each new edge is one of the cube's own edges, not a diagonal.
        for e in regions.mesh.edges() {
            let source = crate::mesh::EdgeId(regions.edge_source[e.index()]);
            assert!((cube.edge_length(source) - 1.0).abs() < 1e-12);
            assert!((regions.mesh.edge_length(e) - 1.0).abs() < 1e-12);
        }
        let area: f64 = regions
            .mesh
            .faces()
            .map(|f| regions.mesh.face_area(f))
            .sum();
        assert!((area - 6.0).abs() < 1e-12);
    }

    #[test]
    fn a_flat_grid_is_one_square_without_its_straight_border_corners() {
        let grid = triangulated_grid(4);
        let regions = flat_regions(&grid, &rules(&|p| Some(p.to_vec()))).unwrap();
        assert_eq!(regions.faces.len(), 1);
        assert_eq!(regions.faces[0].len(), 32);
        assert_eq!(regions.mesh.face_degree(FaceId(0)), 4);
        assert!((regions.mesh.face_area(FaceId(0)) - 16.0).abs() < 1e-12);
    }

    #[test]
    fn regions_stop_where_the_sheet_ends_and_keep_their_seam_corners() {
        let grid = triangulated_grid(4);
        // At most 2.5 units wide in the plane's axes, whichever way they turn.
        let fits = |p: &[DVec2]| {
            let (lo, hi) = p.iter().fold(
                (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
                |(lo, hi), &q| (lo.min(q), hi.max(q)),
            );
            ((hi - lo).length() <= 2.5 * 2f64.sqrt() + 1e-9).then(|| p.to_vec())
        };
        let regions = flat_regions(&grid, &rules(&fits)).unwrap();
        assert!(regions.faces.len() > 1);
        let area: f64 = regions
            .mesh
            .faces()
            .map(|f| regions.mesh.face_area(f))
            .sum();
        assert!((area - 16.0).abs() < 1e-9);
        let all: usize = regions.faces.iter().map(Vec::len).sum();
        assert_eq!(all, 32);
        // Every region is a disk: its corners each once in its outline.
        for f in regions.mesh.faces() {
            let mut corners: Vec<VertexId> = regions.mesh.face_vertices(f).collect();
            let n = corners.len();
            corners.sort_unstable();
            corners.dedup();
            assert_eq!(corners.len(), n);
        }
    }

    #[test]
    fn a_ring_of_faces_is_never_one_region_with_a_hole() {
        // A 3 × 3 grid less its middle square: the ring closes round the hole, so its
        // last face, which would touch the region at both ends, starts a new region.
        let p: Vec<DVec3> = (0..4)
            .flat_map(|y| (0..4).map(move |x| DVec3::new(x as f64, y as f64, 0.0)))
            .collect();
        let at = |x: u32, y: u32| y * 4 + x;
        let squares: Vec<[u32; 4]> = (0..3)
            .flat_map(|y| (0..3).map(move |x| (x, y)))
            .filter(|&(x, y)| (x, y) != (1, 1))
            .map(|(x, y)| [at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)])
            .collect();
        let ring = build_from_faces(p, &squares).unwrap();
        let regions = flat_regions(&ring, &rules(&|p| Some(p.to_vec()))).unwrap();
        assert_eq!(regions.faces.len(), 2);
        let area: f64 = regions
            .mesh
            .faces()
            .map(|f| regions.mesh.face_area(f))
            .sum();
        assert!((area - 8.0).abs() < 1e-12);
    }

    #[test]
    fn a_finely_cut_round_border_keeps_its_corners() {
        // A flat fan disc of 2000 border points: each bends its border by far less
        // than the tolerance, but together they are a circle, not a chord.
        let n = 2000;
        let mut p = vec![DVec3::ZERO];
        p.extend((0..n).map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            DVec3::new(100.0 * a.cos(), 100.0 * a.sin(), 0.0)
        }));
        let tris: Vec<[u32; 3]> = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
        let disc = build_from_faces(p, &tris).unwrap();
        let rules = RegionRules {
            tolerance: 0.005,
            max_faces: usize::MAX,
            fits: &|p| Some(p.to_vec()),
        };
        let regions = flat_regions(&disc, &rules).unwrap();
        assert_eq!(regions.faces.len(), 1);
        let exact: f64 = disc.faces().map(|f| disc.face_area(f)).sum();
        let merged = regions.mesh.face_area(FaceId(0));
        // Within the tolerance along the whole border, and fewer corners than given.
        assert!(
            exact - merged < 0.005 * 2.0 * std::f64::consts::PI * 100.0,
            "{merged} of {exact}"
        );
        assert!(regions.mesh.face_degree(FaceId(0)) < n as usize);
    }

    #[test]
    fn a_bent_pair_stays_two_faces() {
        let two = crate::mesh::build::two_triangles(DVec3::new(30.0, 20.0, 5.0));
        let regions = flat_regions(&two, &rules(&|p| Some(p.to_vec()))).unwrap();
        assert_eq!(regions.faces, vec![vec![0], vec![1]]);
        assert_eq!(regions.mesh.edge_count(), two.edge_count());
    }
}
