//! Islands as they grow: faces laid flat in their island's frame, joined along an edge
//! when the turned island keeps clear of the other, fits the sheet and leaves its cuts
//! room for a tab.

use std::collections::HashMap;

use glam::DVec2;

use super::options::IslandOptions;
use super::tabs::{
    clear_tab, fits_sheet, separation, tab_options, Obstacle, TabFrame, ISLAND_GAP, NOTCH_GAP,
    TAB_STEPS,
};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::plane::convex_hull;
use crate::scheme::kit::tab::make_tab;
use crate::union_find::UnionFind;

/// Islands of at most this many faces join a neighbour whatever the shape they make:
/// a handful of faces on their own are more to find and glue than they save on the
/// sheets.
const SMALL_ISLAND: usize = 6;

/// The angle between the normals of an interior edge's two faces (0: flat).
pub(super) fn fold_angle(mesh: &Mesh, e: EdgeId) -> Option<f64> {
    let h = e.half_edge();
    let (f, g) = (mesh.face(h)?, mesh.face(h.twin())?);
    Some(mesh.face_normal(f).angle_between(mesh.face_normal(g)))
}

/// A bucket grid over an island's flat faces and tabs, for overlap queries.
pub(super) struct Grid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl Grid {
    fn new(cell: f64) -> Self {
        Grid {
            cell,
            cells: HashMap::new(),
        }
    }

    fn range(&self, poly: &[DVec2], pad: f64) -> (i64, i64, i64, i64) {
        let (lo, hi) = crate::plane::bounds(poly.iter().copied());
        let c = |v: f64| (v / self.cell).floor() as i64;
        (c(lo.x - pad), c(lo.y - pad), c(hi.x + pad), c(hi.y + pad))
    }

    fn insert(&mut self, id: u32, poly: &[DVec2]) {
        let (x0, y0, x1, y1) = self.range(poly, ISLAND_GAP);
        for x in x0..=x1 {
            for y in y0..=y1 {
                self.cells.entry((x, y)).or_default().push(id);
            }
        }
    }

    /// Ids of everything near `poly`, each once, in increasing order.
    pub(super) fn near(&self, poly: &[DVec2]) -> Vec<u32> {
        let (x0, y0, x1, y1) = self.range(poly, ISLAND_GAP);
        let mut ids = Vec::new();
        for x in x0..=x1 {
            for y in y0..=y1 {
                if let Some(list) = self.cells.get(&(x, y)) {
                    ids.extend_from_slice(list);
                }
            }
        }
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

/// Two polygons that may touch: they overlap by less than this (mm).
const TOUCH: f64 = 1e-6;

/// The islands as they grow: every face's corners laid flat in its island's frame.
pub(in crate::scheme) struct Islands {
    /// The island of each face (an index into `faces`).
    pub(super) of_face: Vec<u32>,
    /// Each island's faces (empty once merged into another).
    pub(super) faces: Vec<Vec<u32>>,
    /// Flat position of each half-edge's origin in its face's island frame.
    pub(super) corner: Vec<DVec2>,
    /// Which corners are one vertex of their island: a union-find over the corners
    /// of the faces (a corner is named by the half-edge that leaves it).
    pub(super) joined: UnionFind,
    /// Each island's convex hull.
    pub(super) hull: Vec<Vec<DVec2>>,
    /// Each island's area (its faces').
    pub(super) area: Vec<f64>,
    /// Each island's faces by place.
    pub(super) grid: Vec<Grid>,
    /// The edges folded so far.
    pub(super) fold: Vec<bool>,
}

/// Two corners laid at the same flat point (relative to the faces' size).
fn same_point(p: DVec2, q: DVec2, scale: f64) -> bool {
    p.distance(q) <= 1e-9 * scale
}

impl Islands {
    /// Every face its own island, laid in its own plane.
    fn new(mesh: &Mesh, cell: f64) -> Self {
        let mut corner = vec![DVec2::ZERO; mesh.half_edge_count()];
        let mut hull = Vec::with_capacity(mesh.face_count());
        let mut grid = Vec::with_capacity(mesh.face_count());
        for f in mesh.faces() {
            let hs: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
            let o = mesh.position(mesh.origin(hs[0]));
            let x = (mesh.position(mesh.dest(hs[0])) - o).normalize();
            let y = mesh.face_normal(f).cross(x);
            for &h in &hs {
                let p = mesh.position(mesh.origin(h)) - o;
                corner[h.index()] = DVec2::new(p.dot(x), p.dot(y));
            }
            let poly: Vec<DVec2> = hs.iter().map(|h| corner[h.index()]).collect();
            let mut g = Grid::new(cell);
            g.insert(f.0, &poly);
            grid.push(g);
            hull.push(convex_hull(&poly));
        }
        let area = mesh.faces().map(|f| mesh.face_area(f)).collect();
        Islands {
            area,
            of_face: (0..mesh.face_count() as u32).collect(),
            faces: (0..mesh.face_count() as u32).map(|f| vec![f]).collect(),
            corner,
            joined: UnionFind::new(mesh.half_edge_count()),
            hull,
            grid,
            fold: vec![false; mesh.edge_count()],
        }
    }

    /// Every face its own island, bucketed in cells twice the median of the edge
    /// `lengths` (sorted).
    pub(super) fn of_faces(mesh: &Mesh, lengths: &[f64]) -> Self {
        let median = lengths.get(lengths.len() / 2).copied().unwrap_or(1.0);
        Islands::new(mesh, 2.0 * median.max(1e-3))
    }

    /// Face `f`'s flat polygon in its island's frame.
    pub(super) fn polygon(&self, mesh: &Mesh, f: FaceId) -> Vec<DVec2> {
        mesh.face_half_edges(f)
            .map(|h| self.corner[h.index()])
            .collect()
    }

    /// True when face `x` has a corner joined to corner `c` (the same island vertex).
    pub(super) fn meets_at(&self, mesh: &Mesh, x: u32, c: HalfedgeId) -> bool {
        let root = self.joined.root(c.0);
        mesh.face_half_edges(FaceId(x))
            .any(|h| self.joined.root(h.0) == root)
    }

    /// Joins the islands of edge `e`'s faces along it when the smaller one, turned
    /// about the edge, keeps clear of the larger and the union fits the sheet (with
    /// room for a tab's depth) and `rules`. Every other edge between the two that
    /// then lies where both its faces put it (a flat region closing up) is folded
    /// too. Returns whether it joined them.
    pub(super) fn try_join(&mut self, mesh: &Mesh, e: EdgeId, rules: &JoinRules<'_>) -> bool {
        let JoinRules {
            options,
            scale,
            spread,
            small,
            component_faces,
        } = *rules;
        let h = e.half_edge();
        let (Some(f), Some(g)) = (mesh.face(h), mesh.face(h.twin())) else {
            return false;
        };
        let (ia, ib) = (self.of_face[f.index()], self.of_face[g.index()]);
        if ia == ib {
            return false;
        }
        let (size_a, size_b) = (self.faces[ia as usize].len(), self.faces[ib as usize].len());
        let total = size_a + size_b;
        // A join that makes the whole object (or a whole part of it) one net is made
        // whatever the shape, as a modeller would.
        let completes = total == component_faces[f.index()];
        if options.max_island_faces.is_some_and(|m| total > m)
            || (size_a.min(size_b) > small && !completes)
        {
            return false;
        }
        // The larger island (a) stays put; ties keep the lower index.
        let big_first = (size_a, std::cmp::Reverse(ia)) >= (size_b, std::cmp::Reverse(ib));
        let (a, b, ha, hb) = if big_first {
            (ia, ib, h, h.twin())
        } else {
            (ib, ia, h.twin(), h)
        };
        // hb runs the edge the other way: its origin sits at ha's destination.
        let turn = Turn::onto(
            (self.corner[mesh.next(hb).index()], self.corner[hb.index()]),
            (self.corner[ha.index()], self.corner[mesh.next(ha).index()]),
        );

        let mut hull: Vec<DVec2> = self.hull[a as usize].clone();
        hull.extend(self.hull[b as usize].iter().map(|&x| turn.apply(x)));
        let hull = convex_hull(&hull);
        let area = self.area[a as usize] + self.area[b as usize];
        if crate::plane::area(&hull) > spread * area && total > 2 && !completes {
            return false;
        }
        // Room for a tab's depth: tabs that would still stick out are cut back.
        if !fits_sheet(&hull, options, options.tab_height) {
            return false;
        }

        let joins = self.landing_edges(mesh, (a, b), hb, &turn, scale);
        // The corner classes these joins merge.
        let mut pending = PendingCorners::default();
        for &hy in &joins {
            let hx = hy.twin();
            pending.join(self.joined.root(hy.0), self.joined.root(mesh.next(hx).0));
            pending.join(self.joined.root(mesh.next(hy).0), self.joined.root(hx.0));
        }
        if !self.cuts_left_have_room(mesh, (a, b), &joins, &turn, &pending, options)
            || !self.keeps_clear(mesh, (a, b), &turn, &pending)
        {
            return false;
        }

        // Join: move b's corners into a's frame.
        let moved_faces = std::mem::take(&mut self.faces[b as usize]);
        for &y in &moved_faces {
            for c in mesh.face_half_edges(FaceId(y)) {
                self.corner[c.index()] = turn.apply(self.corner[c.index()]);
            }
            let poly = self.polygon(mesh, FaceId(y));
            self.grid[a as usize].insert(y, &poly);
            self.of_face[y as usize] = a;
        }
        for (p, q) in pending.pairs {
            self.joined.union(p, q);
        }
        for hy in joins {
            self.fold[hy.edge().index()] = true;
        }
        self.grid[b as usize] = Grid::new(1.0);
        self.faces[a as usize].extend(moved_faces);
        self.hull[a as usize] = hull;
        self.hull[b as usize] = Vec::new();
        self.area[a as usize] = area;
        true
    }

    /// The half-edges of island `b`'s faces (`hb`, the joining one, first) whose edge
    /// lies where island `a`'s face across it puts it once `b` is turned: the edges
    /// the join folds.
    fn landing_edges(
        &self,
        mesh: &Mesh,
        (a, b): (u32, u32),
        hb: HalfedgeId,
        turn: &Turn,
        scale: f64,
    ) -> Vec<HalfedgeId> {
        let mut joins = vec![hb];
        for (hy, hx) in self.between(mesh, a, b) {
            if hy == hb {
                continue;
            }
            let lands = same_point(
                turn.apply(self.corner[hy.index()]),
                self.corner[mesh.next(hx).index()],
                scale,
            ) && same_point(
                turn.apply(self.corner[mesh.next(hy).index()]),
                self.corner[hx.index()],
                scale,
            );
            if lands {
                joins.push(hy);
            }
        }
        joins
    }

    /// The pairs (half-edge in a face of island `b`, its twin in a face of island `a`).
    fn between<'m>(
        &'m self,
        mesh: &'m Mesh,
        a: u32,
        b: u32,
    ) -> impl Iterator<Item = (HalfedgeId, HalfedgeId)> + 'm {
        self.faces[b as usize].iter().flat_map(move |&y| {
            mesh.face_half_edges(FaceId(y))
                .filter(move |hy| {
                    mesh.face(hy.twin())
                        .is_some_and(|x| self.of_face[x.index()] == a)
                })
                .map(|hy| (hy, hy.twin()))
        })
    }

    /// True when every cut the join leaves between islands `a` and `b` has room for
    /// the lowest tab on one of its sides, clear of the other side's face: a notch
    /// (one end of the two copies of its edge is one island vertex) or a slit.
    fn cuts_left_have_room(
        &self,
        mesh: &Mesh,
        (a, b): (u32, u32),
        joins: &[HalfedgeId],
        turn: &Turn,
        pending: &PendingCorners,
        options: &IslandOptions,
    ) -> bool {
        let low = tab_options(options, TAB_STEPS[TAB_STEPS.len() - 1] * options.tab_height);
        let joined_corner = |c: HalfedgeId, d: HalfedgeId| {
            pending.root(self.joined.root(c.0)) == pending.root(self.joined.root(d.0))
        };
        self.between(mesh, a, b)
            .filter(|(hy, _)| !joins.contains(hy))
            .all(|(hy, hx)| {
                let (y0, y1) = (
                    turn.apply(self.corner[hy.index()]),
                    turn.apply(self.corner[mesh.next(hy).index()]),
                );
                let (x0, x1) = (self.corner[mesh.next(hx).index()], self.corner[hx.index()]);
                // y0 and x0 are the same 3D vertex, and so are y1 and x1.
                let notch = joined_corner(hy, mesh.next(hx)) || joined_corner(mesh.next(hy), hx);
                let need = if notch { NOTCH_GAP } else { ISLAND_GAP };
                let face = |h: HalfedgeId| mesh.face(h).map_or(FaceId(0), |f| f);
                let poly_y: Vec<DVec2> = self
                    .polygon(mesh, face(hy))
                    .into_iter()
                    .map(|p| turn.apply(p))
                    .collect();
                let poly_x = self.polygon(mesh, face(hx));
                let fits = [(hy, (y0, y1), &poly_x), (hx, (x1, x0), &poly_y)]
                    .into_iter()
                    .any(|(owner, ends, other)| {
                        let Some(tab) = make_tab(mesh, owner, &low) else {
                            return false;
                        };
                        let obstacle = Obstacle {
                            outline: other.as_slice().into(),
                            need,
                        };
                        let frame = TabFrame::on(mesh, owner, ends);
                        clear_tab(&tab, &frame, &[obstacle], options).is_some()
                    });
                fits
            })
    }

    /// True when island `b`, turned, keeps clear of island `a`'s faces: faces that will
    /// share an island vertex may touch, any other two keep [`ISLAND_GAP`] apart.
    fn keeps_clear(
        &self,
        mesh: &Mesh,
        (a, b): (u32, u32),
        turn: &Turn,
        pending: &PendingCorners,
    ) -> bool {
        let may_touch = |x: u32, y: u32| {
            mesh.face_half_edges(FaceId(y)).any(|cy| {
                let ry = pending.root(self.joined.root(cy.0));
                mesh.face_half_edges(FaceId(x))
                    .any(|cx| pending.root(self.joined.root(cx.0)) == ry)
            })
        };
        let grid = &self.grid[a as usize];
        self.faces[b as usize].iter().all(|&y| {
            let poly: Vec<DVec2> = self
                .polygon(mesh, FaceId(y))
                .into_iter()
                .map(|p| turn.apply(p))
                .collect();
            grid.near(&poly).into_iter().all(|x| {
                let need = if may_touch(x, y) { -TOUCH } else { ISLAND_GAP };
                separation(&self.polygon(mesh, FaceId(x)), &poly) >= need
            })
        })
    }
    /// The flat frame of a tab on `h`, its edge where the island lays it.
    pub(super) fn tab_frame(&self, mesh: &Mesh, h: HalfedgeId) -> TabFrame {
        let ends = (self.corner[h.index()], self.corner[mesh.next(h).index()]);
        TabFrame::on(mesh, h, ends)
    }
}

/// The rigid motion that lays one flat segment onto another (same length): an
/// island turned about the edge it joins along.
struct Turn {
    from: DVec2,
    to: DVec2,
    rotation: DVec2,
}

impl Turn {
    /// The motion taking segment `from` (q0, q1) onto `to` (p0, p1).
    fn onto((q0, q1): (DVec2, DVec2), (p0, p1): (DVec2, DVec2)) -> Turn {
        let (dp, dq) = ((p1 - p0).normalize(), (q1 - q0).normalize());
        Turn {
            from: q0,
            to: p0,
            rotation: DVec2::new(dq.dot(dp), dq.perp_dot(dp)),
        }
    }

    fn apply(&self, x: DVec2) -> DVec2 {
        self.to + self.rotation.rotate(x - self.from)
    }
}

/// Corner classes a join would merge, before it is made: a small union-find over
/// their roots in the islands' corner union-find, so the checks can ask which corners become one vertex.
#[derive(Default)]
struct PendingCorners {
    parent: HashMap<u32, u32>,
    /// The pairs of roots to join when the join is made.
    pairs: Vec<(u32, u32)>,
}

impl PendingCorners {
    fn root(&self, mut c: u32) -> u32 {
        while let Some(&p) = self.parent.get(&c) {
            c = p;
        }
        c
    }

    fn join(&mut self, p: u32, q: u32) {
        self.pairs.push((p, q));
        let (rp, rq) = (self.root(p), self.root(q));
        if rp != rq {
            self.parent.insert(rp.max(rq), rp.min(rq));
        }
    }
}

/// What a join must respect.
#[derive(Clone, Copy)]
pub(super) struct JoinRules<'a> {
    /// The options: the sheet, the island size cap, the tabs.
    pub(super) options: &'a IslandOptions,
    /// The model's largest edge (for "the same point").
    pub(super) scale: f64,
    /// Largest ratio of the joined island's convex hull to its area.
    pub(super) spread: f64,
    /// Join only when the smaller island has at most this many faces.
    pub(super) small: usize,
    /// The number of faces of each face's connected part of the mesh.
    pub(super) component_faces: &'a [usize],
}

/// Joins faces into islands along the flattest edges first, under the join rules,
/// then lets small islands join a neighbour whatever its shape; also the interior
/// edges in that order (the sharp ones, left to be cut, last).
pub(in crate::scheme) fn grow_islands(
    mesh: &Mesh,
    options: &IslandOptions,
) -> (Islands, Vec<EdgeId>) {
    let lengths = mesh.sorted_edge_lengths();
    let mut islands = Islands::of_faces(mesh, &lengths);
    let mut order: Vec<(f64, EdgeId)> = mesh
        .edges()
        .filter_map(|e| fold_angle(mesh, e).map(|a| (a, e)))
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1 .0.cmp(&y.1 .0)));
    let component_faces: Vec<usize> = {
        let (component, count) = mesh.face_components();
        let mut sizes = vec![0usize; count];
        for &c in &component {
            sizes[c as usize] += 1;
        }
        component.iter().map(|&c| sizes[c as usize]).collect()
    };
    let mut rules = JoinRules {
        options,
        scale: lengths.last().copied().unwrap_or(1.0),
        spread: options.island_spread,
        small: usize::MAX,
        component_faces: &component_faces,
    };
    for &(_, e) in &order {
        islands.try_join(mesh, e, &rules);
    }
    rules.spread = f64::INFINITY;
    rules.small = SMALL_ISLAND;
    for &(_, e) in &order {
        islands.try_join(mesh, e, &rules);
    }
    (islands, order.into_iter().map(|(_, e)| e).collect())
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use glam::DVec3;

    use super::*;
    use crate::mesh::build::{cube, two_triangles};

    /// The test options with islands of at most `max_faces` and a spread of 3.
    fn options(max_faces: Option<usize>) -> IslandOptions {
        crate::scheme::island::test_options(max_faces, 3.0)
    }

    #[test]
    fn fold_angles_are_flat_square_or_none_on_the_rim() {
        let flat = two_triangles(DVec3::new(30.0, 30.0, 0.0));
        let upright = two_triangles(DVec3::new(30.0, 0.0, 30.0));
        assert!(fold_angle(&flat, EdgeId(2)).unwrap().abs() < 1e-12);
        assert!((fold_angle(&upright, EdgeId(2)).unwrap() - FRAC_PI_2).abs() < 1e-12);
        for rim in [0, 1, 3, 4] {
            assert_eq!(fold_angle(&flat, EdgeId(rim)), None, "edge {rim}");
        }
    }

    #[test]
    fn the_grid_names_what_lies_near_each_once_in_order() {
        let mut grid = Grid::new(10.0);
        let square = |x: f64| -> Vec<DVec2> {
            [(0.0, 0.0), (25.0, 0.0), (25.0, 25.0), (0.0, 25.0)]
                .map(|(u, v)| DVec2::new(x + u, v))
                .to_vec()
        };
        grid.insert(7, &square(0.0));
        grid.insert(3, &square(100.0));
        grid.insert(5, &square(20.0));
        assert_eq!(grid.near(&square(10.0)), [5, 7]);
        assert_eq!(grid.near(&square(60.0)), Vec::<u32>::new());
        assert_eq!(grid.near(&square(85.0)), [3]);
    }

    /// A cube unfolds into one island of its six faces: five folds, each face laid flat
    /// with its own area, none over another.
    #[test]
    fn a_cube_grows_into_one_island_of_six_faces_none_over_another() {
        let mesh = cube(40.0);
        let (islands, order) = grow_islands(&mesh, &options(None));
        assert_eq!(order.len(), 12, "every interior edge, in fold order");
        let live: Vec<&Vec<u32>> = islands.faces.iter().filter(|f| !f.is_empty()).collect();
        assert_eq!(live.len(), 1);
        assert_eq!(live[0].len(), 6);
        let folds = islands.fold.iter().filter(|&&f| f).count();
        assert_eq!(folds, 5, "a tree over six faces has five folds");
        let polygons: Vec<Vec<DVec2>> = mesh.faces().map(|f| islands.polygon(&mesh, f)).collect();
        for (f, poly) in polygons.iter().enumerate() {
            assert!(
                (crate::plane::area(poly).abs() - 1600.0).abs() < 1e-9,
                "face {f}"
            );
            for (g, other) in polygons.iter().enumerate().skip(f + 1) {
                assert!(
                    separation(poly, other) >= -TOUCH,
                    "faces {f} and {g} overlap"
                );
            }
        }
    }

    #[test]
    fn an_island_cap_of_one_face_leaves_every_face_alone() {
        let mesh = cube(40.0);
        let (islands, _) = grow_islands(&mesh, &options(Some(1)));
        let live = islands.faces.iter().filter(|f| !f.is_empty()).count();
        assert_eq!(live, 6);
        assert!(islands.fold.iter().all(|&f| !f));
    }
}
