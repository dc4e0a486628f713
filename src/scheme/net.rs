//! The net scheme: islands of many faces joined along folds, the way paper modellers
//! unfold a mesh. Every face is in one island; an edge inside an island is a fold and
//! every other interior edge a cut, glued by one tab.
//!
//! Islands grow greedily over the edges in order of their fold angle (flattest first,
//! so the cuts fall on the sharp edges): an edge joins the islands of its two faces when
//! the smaller one, turned about that edge into the larger one's plane, overlaps none of
//! its faces, the union still fits the sheet and stays compact (its convex hull at most
//! `--island-spread` times its area: sprawling islands waste the sheet between their
//! arms; a join that makes a whole connected part one island is made whatever its
//! shape). A second pass lets islands of a few faces join a neighbour whatever shape
//! that makes. Faces of an island that meet at a
//! folded corner may touch there; any other two keep [`ISLAND_GAP`] apart, so the
//! outline stays a simple polygon with room for the laser. Each island is a tree of
//! faces, so it unrolls exactly.
//!
//! Each cut edge then gets a tab on one side, made like the half-edge scheme's (in the
//! partner face's plane, inside the triangle of the edge and the partner's centre, so
//! tabs under one face never meet). Laid flat, a tab must keep clear of its island's
//! other faces and tabs: where it does not, the other side is tried and the tab is
//! lowered, and only where no height fits is it left out (and counted). Both sides of a
//! cut carry the same match number (or, where the scheme asks for seams, the faces on
//! both sides of one edge of each seam: a run of cut edges end to end between two
//! islands).

use std::collections::{BTreeMap, HashMap};

use glam::{DVec2, DVec3};

use super::kit::tab::{make_tab, tab_defaults, Tab, TabArgs, TabOptions, TAB_DEFAULTS};
use super::rigid::sheet::{
    rigid_defaults, rigid_output, Connectors, PanelNames, RigidArgs, RigidSheet,
};
use super::{args_of, Configured, OptionValues, PanelDefaults, PanelOptions};
use super::{ConnectionName, Scheme, SchemeError, SchemeOutput};
use crate::mesh::coplanar::{flat_regions, RegionRules};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::panel::surface::group_anchor;
use crate::panel::{
    Covers, FaceGroup, FoldKind, Hole, IdKind, Label, LabelKind, Loops, Name, Panel, Source,
};
use crate::plane::{convex_hull, fits_rotated};
use crate::record::{round4, Params};
use crate::union_find::UnionFind;
use crate::units::fmt_path_length;

/// The default `--island-spread`: islands whose convex hull is at most one and a half
/// times their area pack on fewer sheets than sprawling ones, at the cost of more
/// (smaller) islands.
pub const ISLAND_SPREAD: f64 = 1.5;

/// Least distance (mm) between two faces or tabs of one island that are not joined:
/// the laser needs room between two cuts, and an outline that touches itself is not
/// one loop.
pub const ISLAND_GAP: f64 = 0.5;

/// Slack (mm) kept when checking that an island fits the usable sheet.
const FIT_SLACK: f64 = 4.0;

/// Islands of at most this many faces join a neighbour whatever the shape they make:
/// a handful of faces on their own are more to find and glue than they save on the
/// sheets.
const SMALL_ISLAND: usize = 6;

/// Tab heights tried, as fractions of `--tab-height`, before a tab is left out.
const TAB_STEPS: [f64; 3] = [1.0, 0.5, 0.25];

/// Islands: `N4`, numbered from 1; the manifest lists an island's faces.
pub static ISLAND: IdKind = IdKind {
    letter: "N",
    legend: "net island",
    noun: "island",
    part_noun: "",
    layer: "",
};

/// Match numbers: `17`, the same on both sides of a cut, so its two sides are found.
pub static MATCH: IdKind = IdKind {
    letter: "",
    legend: "a bare number marks the two sides of one cut",
    noun: "match",
    part_noun: "",
    layer: "",
};

/// The net scheme: islands of faces joined along folds, glue tabs on the cuts.
pub struct Net;

/// `--flat-fold` (degrees).
pub(super) const FLAT_FOLD_DEG: f64 = 1.0;

/// `--flat-fold`, shared with the strip scheme.
#[derive(Clone, Debug, Default, clap::Args)]
pub(super) struct FlatFoldArgs {
    /// Folds flatter than this angle in degrees are not scored.
    #[arg(long, value_name = "DEGREES")]
    flat_fold: Option<f64>,
}

impl FlatFoldArgs {
    /// The angle (radians), checked, or its default.
    pub(super) fn angle(&self) -> Result<f64, String> {
        let flat_fold = self.flat_fold.unwrap_or(FLAT_FOLD_DEG);
        if !(0.0..90.0).contains(&flat_fold) {
            return Err(format!(
                "--flat-fold: {flat_fold} must be an angle in degrees from 0 to below 90"
            ));
        }
        Ok(flat_fold.to_radians())
    }
}

/// The net scheme's options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct NetArgs {
    #[command(flatten)]
    tab: TabArgs,

    #[command(flatten)]
    rigid: RigidArgs,

    /// Most faces in one island (net scheme), for builders who want small pieces.
    #[arg(long, value_name = "N")]
    max_island_faces: Option<usize>,

    #[command(flatten)]
    flat_fold: FlatFoldArgs,

    /// Largest ratio of an island's convex hull to its area (net scheme, at least 1):
    /// smaller keeps islands compact so they pack on fewer sheets, larger makes fewer
    /// islands.
    #[arg(long, value_name = "R")]
    island_spread: Option<f64>,
}

/// The net scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct NetOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Wanted tab height (mm).
    pub tab_height: f64,
    /// Most faces in one island.
    pub max_island_faces: Option<usize>,
    /// Folds flatter than this (radians) are not scored.
    pub flat_fold: f64,
    /// Largest ratio of an island's convex hull to its area.
    pub island_spread: f64,
    /// Rigid sheet: above zero thickness nothing folds, and each island is a flat
    /// region of the model.
    pub rigid: RigidSheet,
}

impl Scheme for Net {
    fn name(&self) -> &'static str {
        "net"
    }

    fn about(&self) -> &'static str {
        "islands of many faces joined along folds, glue tabs on the cuts"
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<NetArgs>(),
            &[
                tab_defaults(),
                OptionDefault::words("max-island-faces", "no limit"),
                OptionDefault::value("flat-fold", FLAT_FOLD_DEG),
                OptionDefault::value("island-spread", ISLAND_SPREAD),
            ]
            .into_iter()
            .chain(rigid_defaults())
            .collect::<Vec<_>>(),
        )
    }

    fn defaults(&self) -> PanelDefaults {
        TAB_DEFAULTS
    }

    fn needs_convex_faces(&self) -> bool {
        // The overlap test separates convex polygons.
        true
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --island-spread or --max-island-faces (smaller islands)"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: NetArgs = values.parse()?;
        if panel.face_scale != 1.0 {
            return Err(format!(
                "--face-scale: the net scheme keeps its faces whole (1), not {}; leave it out",
                panel.face_scale
            ));
        }
        if args.max_island_faces == Some(0) {
            return Err("--max-island-faces: an island holds at least 1 face".into());
        }
        let island_spread = args.island_spread.unwrap_or(ISLAND_SPREAD);
        if !(island_spread >= 1.0 && island_spread.is_finite()) {
            return Err(format!(
                "--island-spread: {island_spread} must be a number of at least 1 (a convex island has 1)"
            ));
        }
        let rigid = args.rigid.resolve(&panel)?;
        if rigid.connectors == Connectors::None && rigid.thickness == 0.0 {
            return Err("--connectors none: the net scheme glues its cuts with tabs in card; none is for rigid sheet (--thickness)".into());
        }
        if rigid.thickness > 0.0 && args.island_spread.is_some() {
            return Err("--island-spread: in rigid sheet (--thickness) nothing folds, so each island is a flat region of the model, whatever its shape; leave --island-spread out".into());
        }
        Ok(Box::new(NetOptions {
            island_spread,
            panel,
            tab_height: args.tab.height()?,
            max_island_faces: args.max_island_faces,
            flat_fold: args.flat_fold.angle()?,
            rigid,
        }))
    }
}

impl Configured for NetOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        if self.rigid.thickness > 0.0 {
            rigid_panels(mesh, self)
        } else {
            Ok(panels(mesh, self))
        }
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("tab_height", round4(self.tab_height));
        match self.max_island_faces {
            Some(n) => params.push("max_island_faces", n),
            None => params.push("max_island_faces", "none"),
        }
        params.push("flat_fold_deg", round4(self.flat_fold.to_degrees()));
        params.push("island_spread", self.island_spread);
        params.push("connectors", self.rigid.connectors_name());
        self.rigid.sheet_params(&mut params);
        params
    }

    fn least_scored_fold(&self) -> f64 {
        self.flat_fold
    }
}

/// The angle between the normals of an interior edge's two faces (0: flat).
fn fold_angle(mesh: &Mesh, e: EdgeId) -> Option<f64> {
    let h = e.half_edge();
    let (f, g) = (mesh.face(h)?, mesh.face(h.twin())?);
    Some(mesh.face_normal(f).angle_between(mesh.face_normal(g)))
}

/// A bucket grid over an island's flat faces and tabs, for overlap queries.
struct Grid {
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
    fn near(&self, poly: &[DVec2]) -> Vec<u32> {
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

/// The largest gap between two counter-clockwise convex polygons along the edge
/// normals of either: at least their distance apart when positive, and never positive
/// when they overlap.
fn separation(p: &[DVec2], q: &[DVec2]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    for (a, b) in [(p, q), (q, p)] {
        for i in 0..a.len() {
            let e = a[(i + 1) % a.len()] - a[i];
            let Some(n) = DVec2::new(e.y, -e.x).try_normalize() else {
                continue;
            };
            let reach = a
                .iter()
                .map(|&v| n.dot(v))
                .fold(f64::NEG_INFINITY, f64::max);
            let start = b.iter().map(|&v| n.dot(v)).fold(f64::INFINITY, f64::min);
            best = best.max(start - reach);
        }
    }
    best
}

/// Two polygons that may touch: they overlap by less than this (mm).
const TOUCH: f64 = 1e-6;

/// Least distance (mm) between a tab and a face folded to its own face at the tab's
/// end (the two sides of a notch): clear of the files' rounding to 0.0001 mm, so the
/// outline never touches itself there.
const NOTCH_GAP: f64 = 0.05;

/// The islands as they grow: every face's corners laid flat in its island's frame.
struct Islands {
    /// The island of each face (an index into `faces`).
    of_face: Vec<u32>,
    /// Each island's faces (empty once merged into another).
    faces: Vec<Vec<u32>>,
    /// Flat position of each half-edge's origin in its face's island frame.
    corner: Vec<DVec2>,
    /// Which corners are one vertex of their island: a union-find over the corners
    /// of the faces (a corner is named by the half-edge that leaves it).
    joined: UnionFind,
    /// Each island's convex hull.
    hull: Vec<Vec<DVec2>>,
    /// Each island's area (its faces').
    area: Vec<f64>,
    /// Each island's faces by place.
    grid: Vec<Grid>,
    /// The edges folded so far.
    fold: Vec<bool>,
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
    fn of_faces(mesh: &Mesh, lengths: &[f64]) -> Self {
        let median = lengths.get(lengths.len() / 2).copied().unwrap_or(1.0);
        Islands::new(mesh, 2.0 * median.max(1e-3))
    }

    /// Face `f`'s flat polygon in its island's frame.
    fn polygon(&self, mesh: &Mesh, f: FaceId) -> Vec<DVec2> {
        mesh.face_half_edges(f)
            .map(|h| self.corner[h.index()])
            .collect()
    }

    /// True when face `x` has a corner joined to corner `c` (the same island vertex).
    fn meets_at(&self, mesh: &Mesh, x: u32, c: HalfedgeId) -> bool {
        let root = self.joined.root(c.0);
        mesh.face_half_edges(FaceId(x))
            .any(|h| self.joined.root(h.0) == root)
    }

    /// Joins the islands of edge `e`'s faces along it when the smaller one, turned
    /// about the edge, keeps clear of the larger and the union fits the sheet (with
    /// room for a tab's depth) and `rules`. Every other edge between the two that
    /// then lies where both its faces put it (a flat region closing up) is folded
    /// too. Returns whether it joined them.
    fn try_join(&mut self, mesh: &Mesh, e: EdgeId, rules: &JoinRules<'_>) -> bool {
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
        if !fits_sheet(&hull, options, options.tab_height + FIT_SLACK) {
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
        options: &NetOptions,
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
struct JoinRules<'a> {
    /// The options: the sheet, the island size cap, the tabs.
    options: &'a NetOptions,
    /// The model's largest edge (for "the same point").
    scale: f64,
    /// Largest ratio of the joined island's convex hull to its area.
    spread: f64,
    /// Join only when the smaller island has at most this many faces.
    small: usize,
    /// The number of faces of each face's connected part of the mesh.
    component_faces: &'a [usize],
}

/// The options for a tab of height `height`.
fn tab_options(options: &NetOptions, height: f64) -> TabOptions {
    TabOptions::new(&options.panel, height)
}

/// The map between a tab's 3D plane (the partner face's) and its island's flat frame,
/// for a tab on half-edge `h` (a → b in its face): unfolded about the edge, the tab
/// lies right of a → b in the flat, where its face lies left.
struct TabFrame {
    a: DVec3,
    x: DVec3,
    y: DVec3,
    pa: DVec2,
    dx: DVec2,
    right: DVec2,
}

impl TabFrame {
    fn new(mesh: &Mesh, islands: &Islands, h: HalfedgeId) -> Self {
        let ends = (
            islands.corner[h.index()],
            islands.corner[mesh.next(h).index()],
        );
        Self::on(mesh, h, ends)
    }

    /// The frame of a tab on `h` whose edge lies flat from `pa` to `pb`.
    fn on(mesh: &Mesh, h: HalfedgeId, (pa, pb): (DVec2, DVec2)) -> Self {
        let a = mesh.position(mesh.origin(h));
        let x = (mesh.position(mesh.dest(h)) - a).normalize();
        let n_g = mesh
            .face(h.twin())
            .map_or(DVec3::Z, |g| mesh.face_normal(g));
        let dx = (pb - pa).normalize();
        TabFrame {
            a,
            x,
            y: x.cross(n_g).normalize(),
            pa,
            dx,
            right: DVec2::new(dx.y, -dx.x),
        }
    }

    fn flat(&self, p: DVec3) -> DVec2 {
        let d = p - self.a;
        self.pa + d.dot(self.x) * self.dx + d.dot(self.y) * self.right
    }

    fn back(&self, q: DVec2) -> DVec3 {
        let d = q - self.pa;
        self.a + d.dot(self.dx) * self.x + d.dot(self.right) * self.y
    }

    /// Distance of a flat point from the edge's line, toward the tab.
    fn depth(&self, q: DVec2) -> f64 {
        (q - self.pa).dot(self.right)
    }
}

/// A polygon already in an island, and how far a new tab must stay from it.
struct Obstacle<'a> {
    outline: std::borrow::Cow<'a, [DVec2]>,
    need: f64,
}

/// The least step between two corners of a tab cut back (mm).
const TAB_STEP: f64 = 1e-3;

/// The points of `top` (from `from` round to `to`) more than [`TAB_STEP`] from the one
/// before and from `to`: a point the clipping left within a micron of its neighbour
/// is that one, for written to the sheet, so short a step could turn the outline back
/// on itself.
fn stepped(top: impl Iterator<Item = DVec2>, from: DVec2, to: DVec2) -> Vec<DVec2> {
    let mut kept: Vec<DVec2> = Vec::new();
    for q in top {
        if q.distance(*kept.last().unwrap_or(&from)) > TAB_STEP {
            kept.push(q);
        }
    }
    while kept.last().is_some_and(|&q| q.distance(to) <= TAB_STEP) {
        kept.pop();
    }
    kept
}

/// `tab` cut back to keep clear of `obstacles`: each one it comes too near is cut
/// away along that obstacle's side that leaves the most of the tab. `None` when less
/// than half its base or under a third of its area is left. The tab's flat outline
/// (counter-clockwise) comes with it; a tab cut back is marked shortened.
fn clear_tab(
    tab: &Tab,
    frame: &TabFrame,
    obstacles: &[Obstacle],
    options: &NetOptions,
) -> Option<(Tab, Vec<DVec2>)> {
    // Facet order b', a', top…: counter-clockwise, face up.
    let mut poly: Vec<DVec2> = [tab.base[1], tab.base[0]]
        .iter()
        .chain(&tab.top)
        .map(|&p| frame.flat(p))
        .collect();
    let full_area = crate::plane::area(&poly);
    let base_length = tab.base[0].distance(tab.base[1]);
    let mut cut = false;
    for obstacle in obstacles {
        let other = &obstacle.outline;
        if separation(other, &poly) >= obstacle.need {
            continue;
        }
        // The obstacle's side beyond which most of the tab lies.
        let side = (0..other.len())
            .filter_map(|i| {
                let e = other[(i + 1) % other.len()] - other[i];
                let n = DVec2::new(e.y, -e.x).try_normalize()?;
                let start = poly.iter().map(|&q| n.dot(q)).fold(f64::INFINITY, f64::min);
                Some((start - n.dot(other[i]), i, n, e))
            })
            .max_by(|p, q| p.0.total_cmp(&q.0).then(q.1.cmp(&p.1)))?;
        let (_, i, n, e) = side;
        let on = other[i] + obstacle.need * n;
        poly = crate::plane::clip_half_plane(&poly, on + e, on);
        cut = true;
        if poly.len() < 3 {
            return None;
        }
    }
    if !cut {
        return Some((tab.clone(), poly));
    }
    if crate::plane::area(&poly) < full_area / 3.0 {
        return None;
    }
    // The base: the points left on the edge's line, from b' (far along) to a'.
    let scale = base_length.max(1.0);
    let on_base = |q: DVec2| frame.depth(q).abs() <= 1e-9 * scale;
    let along = |q: DVec2| (q - frame.pa).dot(frame.dx);
    let base: Vec<usize> = (0..poly.len()).filter(|&k| on_base(poly[k])).collect();
    let b_end = *base
        .iter()
        .max_by(|&&i, &&j| along(poly[i]).total_cmp(&along(poly[j])))?;
    let a_end = *base
        .iter()
        .min_by(|&&i, &&j| along(poly[i]).total_cmp(&along(poly[j])))?;
    if along(poly[b_end]) - along(poly[a_end]) < 0.5 * base_length {
        return None;
    }
    // Counter-clockwise from a' round the top back to b'.
    let n = poly.len();
    let top = stepped(
        (1..n)
            .map(|k| poly[(a_end + k) % n])
            .take_while(|&q| !on_base(q) || q != poly[b_end])
            .filter(|&q| !on_base(q)),
        poly[a_end],
        poly[b_end],
    );
    if top.is_empty() {
        return None;
    }
    let outline: Vec<DVec2> = [poly[b_end], poly[a_end]]
        .into_iter()
        .chain(top.iter().copied())
        .collect();
    let clearance = 0.5 * options.panel.hole_diameter + options.panel.hole_margin;
    let holes: Vec<DVec3> = tab
        .holes
        .iter()
        .copied()
        .filter(|&p| {
            let q = frame.flat(p);
            crate::plane::contains(&outline, q)
                && crate::plane::distance_to_border(&outline, q) >= clearance
        })
        .collect();
    let cleared = Tab {
        owner: tab.owner,
        base: [frame.back(poly[a_end]), frame.back(poly[b_end])],
        top: top.iter().map(|&q| frame.back(q)).collect(),
        holes_skipped: tab.holes_skipped || holes.len() < tab.holes.len(),
        holes,
        shortened: true,
    };
    Some((cleared, outline))
}

/// True when `hull` fits the usable sheet less `room` in one of the nesters'
/// rotations (always, without a sheet).
fn fits_sheet(hull: &[DVec2], options: &NetOptions, room: f64) -> bool {
    options.panel.panel_limit.is_none_or(|limit| {
        fits_rotated(
            hull,
            limit.rotations,
            limit.width - room,
            limit.height - room,
        )
    })
}

/// The tabs of every cut edge, by edge (`None`: no room for one). The island's hull,
/// tabs included, must still fit the sheet.
fn place_tabs(
    mesh: &Mesh,
    islands: &Islands,
    cuts: &[EdgeId],
    options: &NetOptions,
    first: &dyn Fn(EdgeId) -> bool,
) -> Vec<Option<Tab>> {
    let mut placed: Vec<Option<Tab>> = (0..mesh.edge_count()).map(|_| None).collect();
    // Tabs already placed, per island: (owner face, flat outline); and the hulls.
    let mut island_tabs: HashMap<u32, Vec<(u32, Vec<DVec2>)>> = HashMap::new();
    let mut hulls: Vec<Vec<DVec2>> = islands.hull.clone();
    for &e in cuts {
        let h = e.half_edge();
        let sides = if first(e) {
            [h, h.twin()]
        } else {
            [h.twin(), h]
        };
        'found: for step in TAB_STEPS {
            for owner in sides {
                let Some(f) = mesh.face(owner) else { continue };
                let wanted = tab_options(options, step * options.tab_height);
                let Some(tab) = make_tab(mesh, owner, &wanted) else {
                    continue;
                };
                let frame = TabFrame::new(mesh, islands, owner);
                let island = islands.of_face[f.index()];
                // The faces folded to this one round the tab's ends come nearest its
                // inset base: they only have to stay clear of it.
                let need = |x: u32| {
                    if islands.meets_at(mesh, x, owner)
                        || islands.meets_at(mesh, x, mesh.next(owner))
                    {
                        NOTCH_GAP
                    } else {
                        ISLAND_GAP
                    }
                };
                let probe: Vec<DVec2> = [tab.base[1], tab.base[0]]
                    .iter()
                    .chain(&tab.top)
                    .map(|&p| frame.flat(p))
                    .collect();
                let mut obstacles: Vec<Obstacle> = islands.grid[island as usize]
                    .near(&probe)
                    .into_iter()
                    .filter(|&x| x != f.0)
                    .map(|x| Obstacle {
                        outline: islands.polygon(mesh, FaceId(x)).into(),
                        need: need(x),
                    })
                    .collect();
                // Tabs on other edges of the same face lie beyond different edges of a
                // convex polygon: they never meet.
                let others = island_tabs.entry(island).or_default();
                obstacles.extend(others.iter().filter(|(face, _)| *face != f.0).map(
                    |(face, outline)| Obstacle {
                        outline: outline.as_slice().into(),
                        need: need(*face),
                    },
                ));
                let Some((mut tab, outline)) = clear_tab(&tab, &frame, &obstacles, options) else {
                    continue;
                };
                let mut hull = hulls[island as usize].clone();
                hull.extend_from_slice(&outline);
                let hull = convex_hull(&hull);
                if !fits_sheet(&hull, options, FIT_SLACK) {
                    continue;
                }
                hulls[island as usize] = hull;
                others.push((f.0, outline));
                // Lower than asked for, or cut back (`clear_tab` says so).
                tab.shortened |= step < 1.0;
                placed[e.index()] = Some(tab);
                break 'found;
            }
        }
    }
    placed
}

/// Builds the islands of a mesh whose faces are planar and convex.
pub fn panels(mesh: &Mesh, options: &NetOptions) -> SchemeOutput {
    let (islands, order) = grow_islands(mesh, options);
    let net = island_net(mesh, options, islands, &order, &IslandNames::Numbered);
    let mut output = net.output;
    output.report = net.summary.report("net", "islands");
    output.manifest.push("net", net.summary.section("islands"));
    output
}

/// How far (mm) a face's corners may lie off the plane of its flat region in rigid
/// sheet: the panel is flat, so this is how far it may stand off the model.
const FLAT_REGION_TOLERANCE: f64 = 0.005;

/// The net in rigid sheet: nothing folds, so each island is a flat region of the model
/// (neighbouring faces in one plane), cut back and held like the half-edge scheme's
/// faces.
fn rigid_panels(mesh: &Mesh, options: &NetOptions) -> Result<SchemeOutput, SchemeError> {
    let fits = |corners: &[DVec2]| {
        let hull = convex_hull(corners);
        fits_sheet(&hull, options, FIT_SLACK).then_some(hull)
    };
    let rules = RegionRules {
        tolerance: FLAT_REGION_TOLERANCE,
        max_faces: options.max_island_faces.unwrap_or(usize::MAX),
        fits: &fits,
    };
    let regions = flat_regions(mesh, &rules).map_err(|e| {
        SchemeError::Model(format!(
            "the net scheme could not merge the model's flat regions ({e}); --scheme half-edge builds each face on its own"
        ))
    })?;
    let anchors: Vec<DVec3> = regions
        .faces
        .iter()
        .enumerate()
        .map(|(k, faces)| region_anchor(&regions.mesh, FaceId(k as u32), mesh, faces))
        .collect();
    let names = PanelNames {
        sources: (0..regions.faces.len() as u32)
            .map(|k| Source {
                id: Name::new(&ISLAND, k + 1),
                covers: Covers::Faces(k),
            })
            .collect(),
        anchors: anchors.iter().copied().map(Some).collect(),
        edge_numbers: regions.edge_source.clone(),
        noun: "island",
    };
    let mut output = rigid_output(&regions.mesh, mesh, &options.rigid, &options.panel, &names)?;
    let mut sizes: Vec<usize> = regions.faces.iter().map(Vec::len).collect();
    sizes.sort_unstable();
    let merged = regions.faces.iter().filter(|f| f.len() > 1).count();
    output.report.insert(
        0,
        format!(
            "net in rigid sheet: {} islands, each a flat region of the model ({} of several faces, largest {} faces)",
            regions.faces.len(),
            merged,
            sizes.last().copied().unwrap_or(0)
        ),
    );
    output.manifest.push(
        "net",
        serde_json::json!({
            "islands": regions.faces.len(),
            "largest_island_faces": sizes.last().copied().unwrap_or(0),
            "median_island_faces": sizes.get(sizes.len() / 2).copied().unwrap_or(0),
        }),
    );
    output.face_groups = regions
        .faces
        .into_iter()
        .zip(anchors)
        .map(|(faces, anchor)| FaceGroup { anchor, faces })
        .collect();
    Ok(output)
}

/// Where a flat region's id goes: the centroid of its polygon (face `k` of `merged`)
/// when that lies inside it, else the centre of its middle face.
fn region_anchor(merged: &Mesh, k: FaceId, mesh: &Mesh, faces: &[u32]) -> DVec3 {
    let corners: Vec<DVec3> = merged.face_positions(k).collect();
    let normal = merged.face_normal(k);
    let x = normal.any_orthonormal_vector();
    let y = normal.cross(x);
    let flat: Vec<DVec2> = corners
        .iter()
        .map(|&p| DVec2::new((p - corners[0]).dot(x), (p - corners[0]).dot(y)))
        .collect();
    let (mut weighted, mut total) = (DVec2::ZERO, 0.0);
    for i in 1..flat.len().saturating_sub(1) {
        let area = (flat[i] - flat[0]).perp_dot(flat[i + 1] - flat[0]);
        weighted += area * (flat[0] + flat[i] + flat[i + 1]) / 3.0;
        total += area;
    }
    let centroid = weighted / total;
    if total > 0.0 && crate::plane::contains(&flat, centroid) {
        corners[0] + centroid.x * x + centroid.y * y
    } else {
        group_anchor(mesh, faces)
    }
}

/// How a net's islands are named and what of the model they cover.
pub enum IslandNames<'a> {
    /// `N1`, `N2`, … in the order of their lowest face; each covers its faces.
    Numbered,
    /// Named by the scheme ([`OwnNet`]).
    Own(OwnNet<'a>),
}

/// What a scheme that grows a net its own way says of its islands and tabs.
pub struct OwnNet<'a> {
    /// The islands' names from every island's faces (in the order of their lowest
    /// face, each list increasing).
    pub names: &'a dyn Fn(&[Vec<u32>]) -> Vec<Name>,
    /// True when the face of half-edge `h` is to own its edge's tab, rather than the
    /// face across (that side is tried first).
    pub tab_first: &'a dyn Fn(HalfedgeId) -> bool,
    /// One match number for each seam (a run of cut edges end to end between the same
    /// two islands), inside the faces on both sides of the edge with the most room
    /// beside it, rather than one at every cut edge: along a strip's curve the edges
    /// are many and short.
    pub seams: bool,
}

/// A net and what its report says of it.
pub struct IslandNet {
    /// Its panels, connections and notes (no report or manifest lines yet).
    pub output: SchemeOutput,
    /// Its counts, for the scheme's report and manifest.
    pub summary: Summary,
}

/// Islands grown only along `folds`, in that order, each join still keeping the
/// island clear of itself and on the sheet with room for its tabs; every other
/// interior edge is cut and gets a tab. For a scheme that chooses its folds itself
/// (the strip scheme's rungs).
pub fn islands_along(
    mesh: &Mesh,
    options: &NetOptions,
    folds: &[EdgeId],
    names: &IslandNames,
) -> IslandNet {
    let lengths = mesh.sorted_edge_lengths();
    let mut islands = Islands::of_faces(mesh, &lengths);
    let component_faces = vec![usize::MAX; mesh.face_count()];
    let rules = JoinRules {
        options,
        scale: lengths.last().copied().unwrap_or(1.0),
        spread: f64::INFINITY,
        small: usize::MAX,
        component_faces: &component_faces,
    };
    for &e in folds {
        islands.try_join(mesh, e, &rules);
    }
    let interior: Vec<EdgeId> = mesh
        .edges()
        .filter(|&e| fold_angle(mesh, e).is_some())
        .collect();
    island_net(mesh, options, islands, &interior, names)
}

/// The panels of grown islands: tabs on the interior edges of `order` left cut, the
/// islands numbered in the order of their lowest face.
fn island_net(
    mesh: &Mesh,
    options: &NetOptions,
    islands: Islands,
    order: &[EdgeId],
    names: &IslandNames,
) -> IslandNet {
    let cuts: Vec<EdgeId> = order
        .iter()
        .filter(|e| !islands.fold[e.index()])
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let first = |e: EdgeId| match names {
        // Even edges try the face of half-edge 2e first, odd ones the other.
        IslandNames::Numbered => e.0.is_multiple_of(2),
        IslandNames::Own(own) => (own.tab_first)(e.half_edge()),
    };
    let tabs = place_tabs(mesh, &islands, &cuts, options, &first);

    // Islands in the order of their lowest face, numbered from 1.
    let mut members: Vec<Vec<u32>> = islands
        .faces
        .iter()
        .filter(|f| !f.is_empty())
        .map(|f| {
            let mut f = f.clone();
            f.sort_unstable();
            f
        })
        .collect();
    members.sort();
    let ids: Vec<Name> = match names {
        IslandNames::Numbered => (1..=members.len() as u32)
            .map(|k| Name::new(&ISLAND, k))
            .collect(),
        IslandNames::Own(own) => (own.names)(&members),
    };
    let mut number = vec![0u32; mesh.face_count()];
    let mut facet_of = vec![0u32; mesh.face_count()];
    for (k, faces) in members.iter().enumerate() {
        for (i, &f) in faces.iter().enumerate() {
            number[f as usize] = k as u32 + 1;
            facet_of[f as usize] = i as u32;
        }
    }
    let seams = matches!(names, IslandNames::Own(OwnNet { seams: true, .. }));
    let net = BuiltNet {
        mesh,
        islands: &islands,
        tabs: &tabs,
        match_of: match_numbers(mesh, &cuts, &number, seams),
        seams,
        facet_of,
        options,
    };
    let built: Vec<Panel> = members
        .iter()
        .enumerate()
        .map(|(k, faces)| {
            let covers = Covers::Faces(k as u32);
            island_panel(&net, Source { id: ids[k], covers }, faces)
        })
        .collect();

    let tab_count = tabs.iter().flatten().count();
    let shortened = tabs.iter().flatten().filter(|t| t.shortened).count();
    let summary = Summary::of(
        mesh, &islands, &members, &cuts, tab_count, shortened, options,
    );
    let face_groups = members
        .into_iter()
        .map(|faces| FaceGroup {
            anchor: group_anchor(mesh, &faces),
            faces,
        })
        .collect();
    IslandNet {
        output: SchemeOutput {
            panels: built.into_iter().collect(),
            connections: cuts.len(),
            notes: tab_notes(cuts.len(), tab_count, shortened),
            unfastened: unfastened(mesh, &cuts, &tabs, (&number, &ids), options),
            face_groups,
            ..SchemeOutput::default()
        },
        summary,
    }
}

/// Joins faces into islands along the flattest edges first, under the join rules,
/// then lets small islands join a neighbour whatever its shape; also the interior
/// edges in that order (the sharp ones, left to be cut, last).
fn grow_islands(mesh: &Mesh, options: &NetOptions) -> (Islands, Vec<EdgeId>) {
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

/// The report's notes on cut edges left without a tab and tabs shortened.
fn tab_notes(cuts: usize, tabs: usize, shortened: usize) -> Vec<String> {
    let mut notes = Vec::new();
    if tabs < cuts {
        notes.push(format!(
            "{} of {cuts} cut edges have no tab: no room for one beside their island's other faces (glue them edge to edge, or try a smaller --tab-height)",
            cuts - tabs
        ));
    }
    if shortened > 0 {
        notes.push(format!(
            "{shortened} tabs were shortened to stay inside their neighbour face and clear of their island"
        ));
    }
    notes
}

/// The cuts whose tab holds no fastener hole although holes were asked for, named by
/// their two islands (`number` of each face) and the edge.
fn unfastened(
    mesh: &Mesh,
    cuts: &[EdgeId],
    tabs: &[Option<Tab>],
    (number, ids): (&[u32], &[Name]),
    options: &NetOptions,
) -> Vec<ConnectionName> {
    if options.panel.holes == 0 {
        return Vec::new();
    }
    cuts.iter()
        .filter(|e| tabs[e.index()].as_ref().is_none_or(|t| t.holes.is_empty()))
        .filter_map(|&e| {
            let h = e.half_edge();
            let (f, g) = (mesh.face(h)?, mesh.face(h.twin())?);
            Some(ConnectionName {
                panels: [
                    ids[number[f.index()] as usize - 1],
                    ids[number[g.index()] as usize - 1],
                ],
                at: Name::edge(e.0),
            })
        })
        .collect()
}

/// A match number's width per unit of its height, about (three digits).
const NUMBER_WIDTH: f64 = 2.5;

/// Each cut edge's match number, from 1 in the order of `cuts`: one for each cut, or
/// with `seams`, one for each seam, only at the edge with the most room beside it (the
/// first of equals). `number` is each face's island.
fn match_numbers(mesh: &Mesh, cuts: &[EdgeId], number: &[u32], seams: bool) -> HashMap<u32, u32> {
    if !seams {
        return (cuts.iter().enumerate())
            .map(|(k, e)| (e.0, k as u32 + 1))
            .collect();
    }
    // The two islands a cut edge lies between, lower first.
    let islands = |e: EdgeId| {
        let h = e.half_edge();
        let of = |h: HalfedgeId| mesh.face(h).map_or(0, |f| number[f.index()]);
        let (a, b) = (of(h), of(h.twin()));
        (a.min(b), a.max(b))
    };
    // Cut edges meeting at a vertex between the same two islands are one seam.
    let mut seam_sets = UnionFind::new(cuts.len());
    let mut at_vertex: BTreeMap<(u32, (u32, u32)), u32> = BTreeMap::new();
    for (k, &e) in cuts.iter().enumerate() {
        let h = e.half_edge();
        for v in [mesh.origin(h), mesh.dest(h)] {
            match at_vertex.entry((v.0, islands(e))) {
                std::collections::btree_map::Entry::Vacant(slot) => {
                    slot.insert(k as u32);
                }
                std::collections::btree_map::Entry::Occupied(slot) => {
                    seam_sets.union(*slot.get(), k as u32);
                }
            }
        }
    }
    // The largest number an edge has room for beside it, about: its length over a
    // number's width per unit of height, or the height of the faces over it.
    let room = |e: EdgeId| {
        let h = e.half_edge();
        let length = mesh
            .position(mesh.origin(h))
            .distance(mesh.position(mesh.dest(h)));
        let height = |h: HalfedgeId| {
            mesh.face(h)
                .map_or(0.0, |f| 2.0 * mesh.face_area(f) / length)
        };
        (length / NUMBER_WIDTH).min(height(h)).min(height(h.twin()))
    };
    // Each seam's roomiest edge, seams in the order of their first edge.
    let mut roomiest: BTreeMap<u32, (u32, usize)> = BTreeMap::new();
    for (k, &e) in cuts.iter().enumerate() {
        let seam = seam_sets.find(k as u32);
        let first = roomiest.entry(seam).or_insert((k as u32, k));
        if room(e) > room(cuts[first.1]) {
            first.1 = k;
        }
    }
    let mut firsts: Vec<(u32, usize)> = roomiest.into_values().collect();
    firsts.sort_unstable();
    (firsts.iter().enumerate())
        .map(|(m, &(_, k))| (cuts[k].0, m as u32 + 1))
        .collect()
}

/// What every island's panel is built from.
struct BuiltNet<'a> {
    mesh: &'a Mesh,
    islands: &'a Islands,
    /// The tab of each cut edge, where one fits.
    tabs: &'a [Option<Tab>],
    /// Each cut edge's match number (from 1), where it carries one.
    match_of: HashMap<u32, u32>,
    /// Numbered once per seam ([`OwnNet::seams`]).
    seams: bool,
    /// Each face's facet in its island's panel.
    facet_of: Vec<u32>,
    options: &'a NetOptions,
}

/// A panel under construction: corners, facets, holes and labels.
#[derive(Default)]
struct PanelParts {
    vertices: Vec<DVec3>,
    facets: Loops,
    holes: Vec<Hole>,
    labels: Vec<Label>,
}

/// Builds island `number`'s panel: its faces (facets in face order, corners shared
/// along folds), then the tabs its faces own; the island id on a central face, match
/// numbers on both sides of every cut edge that carries one.
fn island_panel(net: &BuiltNet, source: Source, faces: &[u32]) -> Panel {
    let mut parts = PanelParts::default();
    let tab_bases = island_faces(net, faces, &mut parts);
    tab_facets(net, tab_bases, &mut parts);
    folded_holes(net, faces, &mut parts);
    parts.labels.push(island_label(net, source.id, faces));
    Panel::new(
        source,
        parts.vertices,
        parts.facets,
        parts.holes,
        parts.labels,
    )
}

/// The island's faces as facets, one vertex per fan of corners joined by folds, each
/// tab's base corners in the facet of the face that owns it, and the match number
/// inside each face at a cut edge whose tab is not its own; returns the owned tabs'
/// edges and base corners.
fn island_faces(net: &BuiltNet, faces: &[u32], parts: &mut PanelParts) -> Vec<(EdgeId, u32, u32)> {
    let (mesh, tabs) = (net.mesh, net.tabs);
    let height = net.options.panel.label_height;
    let mut vertex_of: HashMap<u32, u32> = HashMap::new();
    let mut tab_bases = Vec::new();
    for &f in faces {
        let f = FaceId(f);
        let mut facet = Vec::new();
        for h in mesh.face_half_edges(f) {
            let key = net.islands.joined.root(h.0);
            facet.push(*vertex_of.entry(key).or_insert_with(|| {
                parts.vertices.push(mesh.position(mesh.origin(h)));
                (parts.vertices.len() - 1) as u32
            }));
            let e = h.edge();
            let own_tab = tabs[e.index()].as_ref().filter(|t| t.owner == h);
            if let Some(tab) = own_tab {
                parts.vertices.extend(tab.base);
                let n = parts.vertices.len() as u32;
                facet.extend([n - 2, n - 1]);
                tab_bases.push((e, n - 2, n - 1));
            }
            // The match number inside this face at a cut edge, unless its tab carries it.
            // Numbered once per seam, the number goes inside the face on both sides,
            // where there is more room than on a tab.
            let inside = own_tab.is_none() || net.seams;
            if let (Some(&m), true) = (net.match_of.get(&e.0), inside) {
                let (a, b) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
                parts.labels.push(Label {
                    text: Name::new(&MATCH, m),
                    anchor: 0.5 * (a + b),
                    direction: (b - a).normalize(),
                    height,
                    facet: net.facet_of[f.index()],
                    kind: LabelKind::Partner,
                    on_edge: true,
                    slide: 0.3 * a.distance(b),
                });
            }
        }
        parts.facets.push(facet);
    }
    tab_bases
}

/// Each owned tab as a facet from its base corners (`tab_bases`) through its top, with
/// its match number and fastener holes.
fn tab_facets(net: &BuiltNet, tab_bases: Vec<(EdgeId, u32, u32)>, parts: &mut PanelParts) {
    for (e, a_base, b_base) in tab_bases {
        let Some(placed) = net.tabs[e.index()].as_ref() else {
            continue;
        };
        let facet_index = parts.facets.len() as u32;
        let mut facet = vec![b_base, a_base];
        for &p in &placed.top {
            parts.vertices.push(p);
            facet.push((parts.vertices.len() - 1) as u32);
        }
        parts.facets.push(facet);
        let (a, b) = (placed.base[0], placed.base[1]);
        if let (Some(&m), true) = (net.match_of.get(&e.0), !net.seams) {
            parts.labels.push(Label {
                text: Name::new(&MATCH, m),
                anchor: 0.5 * (a + b),
                direction: (a - b).normalize(),
                height: net.options.panel.label_height,
                facet: facet_index,
                kind: LabelKind::Partner,
                on_edge: true,
                slide: 0.2 * a.distance(b),
            });
        }
        parts.holes.extend(placed.holes.iter().map(|&p| Hole {
            position: p,
            diameter: net.options.panel.hole_diameter,
            connection: e.0,
            facet: facet_index,
        }));
    }
}

/// The holes of tabs other islands (or this one) fold onto the island's faces.
fn folded_holes(net: &BuiltNet, faces: &[u32], parts: &mut PanelParts) {
    for &f in faces {
        for h in net.mesh.face_half_edges(FaceId(f)) {
            let Some(placed) = net.tabs[h.edge().index()]
                .as_ref()
                .filter(|t| t.owner == h.twin())
            else {
                continue;
            };
            parts.holes.extend(placed.holes.iter().map(|&p| Hole {
                position: p,
                diameter: net.options.panel.hole_diameter,
                connection: h.edge().0,
                facet: net.facet_of[f as usize],
            }));
        }
    }
}

/// The island's id on the largest face near its middle, along that face's longest
/// edge.
fn island_label(net: &BuiltNet, id: Name, faces: &[u32]) -> Label {
    let mesh = net.mesh;
    let label_face = central_face(mesh, net.islands, faces);
    let corners: Vec<DVec3> = mesh.face_positions(FaceId(label_face)).collect();
    let longest = (0..corners.len())
        .max_by(|&i, &j| {
            let li = corners[i].distance(corners[(i + 1) % corners.len()]);
            let lj = corners[j].distance(corners[(j + 1) % corners.len()]);
            li.total_cmp(&lj).then(j.cmp(&i))
        })
        .unwrap_or(0);
    Label {
        text: id,
        anchor: mesh.face_centre(FaceId(label_face)),
        direction: (corners[(longest + 1) % corners.len()] - corners[longest]).normalize(),
        height: net.options.panel.label_height,
        facet: net.facet_of[label_face as usize],
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.0,
    }
}

/// The face that shows an island's id: the largest among those whose centre lies in
/// the inner half of the island (flat), or the largest of all when none does.
fn central_face(mesh: &Mesh, islands: &Islands, faces: &[u32]) -> u32 {
    let centre_of = |f: u32| {
        let poly = islands.polygon(mesh, FaceId(f));
        poly.iter().copied().sum::<DVec2>() / poly.len() as f64
    };
    let middle = faces.iter().map(|&f| centre_of(f)).sum::<DVec2>() / faces.len() as f64;
    let reach = faces
        .iter()
        .map(|&f| centre_of(f).distance(middle))
        .fold(0.0, f64::max);
    let largest = |pool: &mut dyn Iterator<Item = u32>| {
        pool.max_by(|&x, &y| {
            mesh.face_area(FaceId(x))
                .total_cmp(&mesh.face_area(FaceId(y)))
                .then(y.cmp(&x))
        })
    };
    largest(
        &mut faces
            .iter()
            .copied()
            .filter(|&f| centre_of(f).distance(middle) <= 0.5 * reach),
    )
    .or_else(|| largest(&mut faces.iter().copied()))
    .unwrap_or(faces[0])
}

/// What the report and the manifest say of the islands.
pub struct Summary {
    islands: usize,
    largest: usize,
    median: usize,
    folds: [usize; 3],
    fold_length: f64,
    cuts: usize,
    cut_length: f64,
    tabs: usize,
    shortened: usize,
}

impl Summary {
    fn of(
        mesh: &Mesh,
        islands: &Islands,
        members: &[Vec<u32>],
        cuts: &[EdgeId],
        tabs: usize,
        shortened: usize,
        options: &NetOptions,
    ) -> Summary {
        let mut sizes: Vec<usize> = members.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        // Mountain, valley, flat (not scored).
        let mut folds = [0usize; 3];
        let mut fold_length = 0.0;
        for e in mesh.edges().filter(|e| islands.fold[e.index()]) {
            fold_length += mesh.edge_length(e);
            let h = e.half_edge();
            let (Some(f), Some(g)) = (mesh.face(h), mesh.face(h.twin())) else {
                continue;
            };
            let (nf, ng) = (mesh.face_normal(f), mesh.face_normal(g));
            let along = mesh.position(mesh.dest(h)) - mesh.position(mesh.origin(h));
            // Scored as the flatten stage scores them.
            let slot = if nf.angle_between(ng) <= options.flat_fold {
                2
            } else {
                match FoldKind::between(nf, ng, along) {
                    FoldKind::Mountain => 0,
                    FoldKind::Valley => 1,
                }
            };
            folds[slot] += 1;
        }
        Summary {
            islands: members.len(),
            largest: sizes.last().copied().unwrap_or(0),
            median: sizes.get(sizes.len() / 2).copied().unwrap_or(0),
            folds,
            fold_length,
            cuts: cuts.len(),
            cut_length: cuts.iter().map(|&e| mesh.edge_length(e)).sum(),
            tabs,
            shortened,
        }
    }

    /// The report's line, headed `scheme` and calling the islands `islands`.
    pub fn report(&self, scheme: &str, islands: &str) -> Vec<String> {
        vec![format!(
            "{scheme}: {} {islands} (largest {} faces, median {}); folds {} mountain, {} valley, {} too flat to score, {} in all; {} cut edges, {} in all, with {} tabs",
            self.islands,
            self.largest,
            self.median,
            self.folds[0],
            self.folds[1],
            self.folds[2],
            fmt_path_length(self.fold_length),
            self.cuts,
            fmt_path_length(self.cut_length),
            self.tabs
        )]
    }

    /// The manifest's section of the islands, counting them as `islands`.
    pub fn section(&self, islands: &str) -> serde_json::Value {
        let singular = islands.trim_end_matches('s');
        let mut section = serde_json::json!({
                "folds_mountain": self.folds[0],
                "folds_valley": self.folds[1],
                "folds_flat": self.folds[2],
                "fold_length": round4(self.fold_length),
                "cuts": self.cuts,
                "cut_length": round4(self.cut_length),
                "tabs": self.tabs,
                "tabs_shortened": self.shortened,
        });
        section[islands] = self.islands.into();
        section[format!("largest_{singular}_faces")] = self.largest.into();
        section[format!("median_{singular}_faces")] = self.median.into();
        section
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build_from_faces;

    /// Squares 40 mm on a side: room for a full 5 mm tab on every edge.
    const SIDE: f64 = 40.0;

    /// Net options: whole faces, no holes, 5 mm tabs, at most `max_island_faces` faces
    /// an island, folds under 1° unscored, the default spread, no sheet limit.
    fn options(max_island_faces: Option<usize>) -> NetOptions {
        NetOptions {
            panel: PanelOptions {
                face_scale: 1.0,
                holes: 0,
                hole_diameter: 1.0,
                hole_margin: 0.5,
                label_height: 2.0,
                panel_limit: None,
                scale: 1.0,
            },
            tab_height: 5.0,
            max_island_faces,
            flat_fold: 1f64.to_radians(),
            island_spread: ISLAND_SPREAD,
            rigid: crate::scheme::rigid::sheet::RigidSheet::CARD,
        }
    }

    /// A closed cube of side [`SIDE`], faces bottom, top, front, back, left, right.
    fn cube() -> Mesh {
        let p = (0..8)
            .map(|i| SIDE * DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
            .collect();
        let faces = [
            [0u32, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [3, 2, 6, 7],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        build_from_faces(p, &faces).unwrap()
    }

    /// Flat squares of side [`SIDE`] in z = 0, face k on cell `cells[k]` (column, row).
    fn squares(cells: &[(u32, u32)]) -> Mesh {
        let mut index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut p = Vec::new();
        let mut corner = |c: u32, r: u32| {
            *index.entry((c, r)).or_insert_with(|| {
                p.push(SIDE * DVec3::new(f64::from(c), f64::from(r), 0.0));
                (p.len() - 1) as u32
            })
        };
        let faces: Vec<[u32; 4]> = cells
            .iter()
            .map(|&(c, r)| {
                [
                    corner(c, r),
                    corner(c + 1, r),
                    corner(c + 1, r + 1),
                    corner(c, r + 1),
                ]
            })
            .collect();
        build_from_faces(p, &faces).unwrap()
    }

    /// A flat grid of `cols` × `rows` squares, faces row by row.
    fn grid(cols: u32, rows: u32) -> Mesh {
        let cells: Vec<(u32, u32)> = (0..rows)
            .flat_map(|r| (0..cols).map(move |c| (c, r)))
            .collect();
        squares(&cells)
    }

    /// A flat L: faces 0 to 6 in a row along x, faces 7 to 15 in a column up from
    /// face 0.
    fn ell() -> Mesh {
        let cells: Vec<(u32, u32)> = (0..7)
            .map(|c| (c, 0))
            .chain((1..10).map(|r| (0, r)))
            .collect();
        squares(&cells)
    }

    /// Two squares side by side in z = 0 (faces 0 and 1, flat across edge 1) and a
    /// third standing up from face 1's far side (face 2, at 90° across edge 5).
    fn step() -> Mesh {
        let s = SIDE;
        let p = vec![
            DVec3::ZERO,
            DVec3::new(s, 0.0, 0.0),
            DVec3::new(2.0 * s, 0.0, 0.0),
            DVec3::new(0.0, s, 0.0),
            DVec3::new(s, s, 0.0),
            DVec3::new(2.0 * s, s, 0.0),
            DVec3::new(2.0 * s, 0.0, s),
            DVec3::new(2.0 * s, s, s),
        ];
        build_from_faces(p, &[[0u32, 1, 4, 3], [1, 2, 5, 4], [5, 2, 6, 7]]).unwrap()
    }

    /// The faces of each island of `out`.
    fn islands(out: &SchemeOutput) -> Vec<Vec<u32>> {
        out.face_groups.iter().map(|g| g.faces.clone()).collect()
    }

    /// Every match label: (match number, panel index).
    fn match_labels(out: &SchemeOutput) -> Vec<(u32, usize)> {
        let mut found = Vec::new();
        for (k, panel) in out.panels.iter().enumerate() {
            for label in panel.labels {
                if label.text.kind == &MATCH {
                    found.push((label.text.number, k));
                }
            }
        }
        found.sort_unstable();
        found
    }

    /// The interior edges whose faces lie in different islands of `out`.
    fn edges_between_islands(mesh: &Mesh, out: &SchemeOutput) -> usize {
        let mut island = vec![0usize; mesh.face_count()];
        for (k, faces) in islands(out).iter().enumerate() {
            for &f in faces {
                island[f as usize] = k + 1;
            }
        }
        mesh.edges()
            .filter_map(|e| Some((mesh.face(e.half_edge())?, mesh.face(e.half_edge().twin())?)))
            .filter(|(f, g)| island[f.index()] != island[g.index()])
            .count()
    }

    #[test]
    fn a_flat_grid_is_one_island_with_no_cut() {
        let out = panels(&grid(3, 3), &options(None));
        // Every edge is flat: all nine faces join, each interior edge a fold.
        assert_eq!(islands(&out), vec![(0..9).collect::<Vec<u32>>()]);
        assert_eq!((out.panels.len(), out.connections), (1, 0));
        assert_eq!(out.panels.get(0).id().to_string(), "N1");
        // 12 interior edges (2 rows of 3 plus 2 columns of 3), all folds; nothing to
        // score.
        assert_eq!(
            out.report,
            ["net: 1 islands (largest 9 faces, median 9); folds 0 mountain, 0 valley, 12 too flat to score, 480 mm in all; 0 cut edges, 0 mm in all, with 0 tabs"]
        );
    }

    #[test]
    fn the_flattest_edges_fold_first_and_the_sharp_one_is_cut() {
        let mesh = step();
        // With two faces an island, the flat edge 1 joins faces 0 and 1 before the
        // 90° edge 5 is looked at; edge 5 is cut.
        let out = panels(&mesh, &options(Some(2)));
        assert_eq!(islands(&out), vec![vec![0, 1], vec![2]]);
        assert_eq!(out.connections, 1);
        // Both sides of the cut carry match number 1: N1 on face 1, N2 on its tab.
        assert_eq!(match_labels(&out), [(1, 0), (1, 1)]);
        assert_eq!(out.panels.get(1).facets.len(), 2, "face 2 and its tab");
        // Without the cap the 90° edge folds too, as the join completes the part.
        let out = panels(&mesh, &options(None));
        assert_eq!(islands(&out), vec![vec![0, 1, 2]]);
        assert_eq!(out.connections, 0);
    }

    #[test]
    fn a_sprawling_join_waits_unless_it_completes_the_part() {
        let mesh = ell();
        // Edge ids follow the faces, so the row joins first, with face 7 (above face
        // 0): hull (0,0), (7,0), (7,1), (1,2), (0,2) in sides, area 11 over 8 faces,
        // 1.375 ≤ 1.5. Face 8 would make it (0,0), (7,0), (7,1), (1,3), (0,3), area 15
        // over 9 faces, 1.67 > 1.5: faces 8 to 15 grow a second island, and 8 + 8
        // faces pass the cap of 15.
        let out = panels(&mesh, &options(Some(15)));
        assert_eq!(
            islands(&out),
            vec![(0..8).collect::<Vec<u32>>(), (8..16).collect()]
        );
        assert_eq!(out.connections, 1);
        // Uncapped, joining the two makes the whole part one island: made whatever its
        // shape.
        let out = panels(&mesh, &options(None));
        assert_eq!(islands(&out), vec![(0..16).collect::<Vec<u32>>()]);
        assert_eq!(out.connections, 0);
    }

    #[test]
    fn the_island_cap_is_honoured_and_every_other_edge_is_cut() {
        let mesh = grid(3, 3);
        for cap in [1, 2, 3, 4] {
            let out = panels(&mesh, &options(Some(cap)));
            assert!(
                islands(&out).iter().all(|f| f.len() <= cap),
                "cap {cap}: {:?}",
                islands(&out)
            );
            let mut all: Vec<u32> = islands(&out).concat();
            all.sort_unstable();
            assert_eq!(all, (0..9).collect::<Vec<u32>>(), "cap {cap}");
            // At most `cap` faces each: at least ⌈9 / cap⌉ islands.
            assert!(islands(&out).len() >= 9usize.div_ceil(cap), "cap {cap}");
            assert_eq!(
                out.connections,
                edges_between_islands(&mesh, &out),
                "cap {cap}"
            );
        }
        // One face an island: every one of the 12 interior edges is a cut.
        let out = panels(&mesh, &options(Some(1)));
        assert_eq!((islands(&out).len(), out.connections), (9, 12));
    }

    #[test]
    fn islands_are_numbered_from_1_in_the_order_of_their_lowest_face() {
        let out = panels(&cube(), &options(Some(1)));
        // One face an island: face k is island k + 1.
        let expected: Vec<Vec<u32>> = (0..6).map(|f| vec![f]).collect();
        assert_eq!(islands(&out), expected);
        let ids: Vec<String> = out.panels.iter().map(|p| p.id().to_string()).collect();
        assert_eq!(ids, ["N1", "N2", "N3", "N4", "N5", "N6"]);
    }

    #[test]
    fn both_sides_of_every_cut_carry_its_match_number() {
        let mesh = cube();
        let out = panels(&mesh, &options(Some(1)));
        // All 12 edges are cuts, numbered 1 to 12 in edge order.
        assert_eq!(out.connections, 12);
        let found = match_labels(&out);
        assert_eq!(found.len(), 24);
        for m in 1..=12u32 {
            let e = EdgeId(m - 1);
            let h = e.half_edge();
            let sides = [mesh.face(h).unwrap().0, mesh.face(h.twin()).unwrap().0];
            // Panel k is face k's island: the label is on the two faces of edge m − 1.
            let mut on: Vec<u32> = found
                .iter()
                .filter(|(n, _)| *n == m)
                .map(|&(_, k)| k as u32)
                .collect();
            on.sort_unstable();
            let mut sides = sides.to_vec();
            sides.sort_unstable();
            assert_eq!(on, sides, "match {m}");
        }
        // The 12 tabs fit: a 40 mm face's centre is 20 mm from each edge.
        assert!(out.notes.is_empty(), "{:?}", out.notes);
    }

    #[test]
    fn a_closed_cube_unfolds_into_one_net_of_five_folds() {
        let out = panels(&cube(), &options(None));
        // A net of 6 faces is a tree: 5 of the 12 edges fold, 7 are cut.
        assert_eq!(islands(&out), vec![(0..6).collect::<Vec<u32>>()]);
        assert_eq!(out.connections, 7);
    }

    #[test]
    fn the_options_refuse_an_empty_island_and_shrunk_faces() {
        let panel = options(None).panel;
        let mut values = OptionValues::default();
        values.set("max-island-faces", "0");
        let refused = Net.configure(&values, panel.clone()).unwrap_err();
        assert_eq!(
            refused,
            "--max-island-faces: an island holds at least 1 face"
        );
        values.set("max-island-faces", "7");
        let configured = Net.configure(&values, panel.clone()).unwrap();
        let net = crate::scheme::AsAny::as_any(&*configured).downcast_ref::<NetOptions>();
        assert_eq!(net.and_then(|n| n.max_island_faces), Some(7));
        let shrunk = PanelOptions {
            face_scale: 0.5,
            ..panel
        };
        assert!(Net
            .configure(&OptionValues::default(), shrunk)
            .unwrap_err()
            .starts_with("--face-scale: the net scheme keeps its faces whole"));
    }
}
