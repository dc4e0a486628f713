//! One cycle's ribbon: the strands cut from the face bands, lifted or lowered where
//! they cross, as a closed ring of planar pieces in 3D.

use glam::{DVec2, DVec3};

use super::ergs::{trace_cycles, WeaveCycle};
use super::options::WovenOptions;
use crate::mesh::geometry::{planarity_error, vector_area};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh, VertexId};
use crate::plane::{clip_convex, counter_clockwise};
use crate::scheme::SchemeError;

/// Fraction of the band side (from the far corner) where a strand's end starts and
/// ends, for band scale `t`.
fn end_fractions(t: f64) -> (f64, f64) {
    (0.6 - 0.6 * t, 0.6 + 0.4 * t)
}

/// Smallest cosine between a face normal and an edge piece's normal used to scale a
/// lift (a fold sharper than about 78° from flat lifts by at most five times r/2).
const MIN_LIFT_COSINE: f64 = 0.2;

/// What a piece of a ribbon is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceKind {
    /// In a face, cutting the corner at the destination of this face half-edge: a
    /// landing (at one end's height) or the turn between the two heights.
    Face {
        /// The face half-edge ending at the corner.
        corner: HalfedgeId,
    },
    /// Across an edge.
    Edge {
        /// The edge crossed.
        edge: EdgeId,
        /// Over (lifted) or under (lowered) the other strand at this edge.
        over: bool,
        /// The cycle (index) of the other strand crossing this edge.
        crossing: u32,
    },
}

/// One cycle's ribbon, as a closed ring of planar pieces in 3D (mm).
///
/// Line `k` is the fold line between piece `k − 1` and piece `k`; piece `k` joins line
/// `k` to line `k + 1` (indices modulo the ring length). Each line is `[near, far]`:
/// near is the end on the side of the corner the strand cuts in that face. Each face
/// corner passed is a run of face pieces (entry landing, turn, exit landing; the
/// landings only where a neighbouring strand overlaps) followed by one edge piece.
#[derive(Clone, Debug, PartialEq)]
pub struct Ribbon {
    /// Index of the cycle (0-based; printed 1-based).
    pub cycle: u32,
    /// Fold lines.
    pub lines: Vec<[DVec3; 2]>,
    /// What each piece is.
    pub pieces: Vec<PieceKind>,
    /// Each piece's facets: loops of corner references (see [`Corner`]), counter-
    /// clockwise seen from the outside. One quad, or two triangles for a turn whose
    /// ends sit at different heights.
    pub facets: Vec<Vec<Vec<Corner>>>,
    /// The first piece of each face corner passed (its entry line has the same index).
    pub corner_start: Vec<usize>,
}

/// A corner of a piece: `line` 0 (the piece's first line) or 1 (its second), and
/// `end` 0 (near) or 1 (far).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Corner {
    /// 0: the piece's first line; 1: its second.
    pub line: u8,
    /// 0: near; 1: far.
    pub end: u8,
}

const A0: Corner = Corner { line: 0, end: 0 };
const A1: Corner = Corner { line: 0, end: 1 };
const B0: Corner = Corner { line: 1, end: 0 };
const B1: Corner = Corner { line: 1, end: 1 };

impl Ribbon {
    /// Number of mesh edges the cycle crosses (= face corners passed).
    pub fn edge_count(&self) -> usize {
        self.corner_start.len()
    }

    /// The pieces of face corner `i` (its face pieces, then its edge piece), as ring
    /// indices in order.
    pub fn corner_pieces(&self, i: usize) -> std::ops::Range<usize> {
        let n = self.corner_start.len();
        let start = self.corner_start[i % n];
        let end = if i % n + 1 < n {
            self.corner_start[i % n + 1]
        } else {
            self.pieces.len()
        };
        start..end
    }

    /// The 3D point of a corner of piece `k`.
    pub fn point(&self, k: usize, c: Corner) -> DVec3 {
        let line = (k + c.line as usize) % self.lines.len();
        self.lines[line][c.end as usize]
    }

    /// The facets of piece `k` as 3D polygons.
    pub fn facet_points(&self, k: usize) -> Vec<Vec<DVec3>> {
        self.facets[k]
            .iter()
            .map(|f| f.iter().map(|&c| self.point(k, c)).collect())
            .collect()
    }

    /// Length (mm) of the centre line: the distance between the midpoints of each
    /// piece's two fold lines, summed.
    pub fn length(&self) -> f64 {
        let n = self.lines.len();
        (0..n)
            .map(|k| {
                let a = self.lines[k];
                let b = self.lines[(k + 1) % n];
                (0.5 * (a[0] + a[1])).distance(0.5 * (b[0] + b[1]))
            })
            .sum()
    }
}

/// The face bands' geometry the strands are cut from.
struct Strands<'a> {
    mesh: &'a Mesh,
    centres: Vec<DVec3>,
    scale: f64,
    lo: f64,
    hi: f64,
}

impl Strands<'_> {
    fn band(&self, f: FaceId, v: VertexId) -> DVec3 {
        self.scale * self.mesh.position(v) + (1.0 - self.scale) * self.centres[f.index()]
    }

    /// The end `[near, far]` of the strand at corner (f, w) on the band side toward
    /// the neighbour u.
    fn end(&self, f: FaceId, w: VertexId, u: VertexId) -> [DVec3; 2] {
        let (far_corner, corner) = (self.band(f, u), self.band(f, w));
        [
            far_corner.lerp(corner, self.hi),
            far_corner.lerp(corner, self.lo),
        ]
    }

    /// The strand region at the corner ending face half-edge `c`, in its face plane.
    fn region(&self, c: HalfedgeId) -> [DVec3; 4] {
        let f = self.mesh.face(c).expect("a face half-edge");
        let w = self.mesh.dest(c);
        let a = self.end(f, w, self.mesh.origin(c));
        let b = self.end(f, w, self.mesh.dest(self.mesh.next(c)));
        [a[0], a[1], b[1], b[0]]
    }

    /// The face half-edge of `f` ending at `v`.
    fn corner_at(&self, f: FaceId, v: VertexId) -> HalfedgeId {
        self.mesh
            .face_half_edges(f)
            .find(|&h| self.mesh.dest(h) == v)
            .expect("the vertex is a corner of the face")
    }
}

/// Where the landings of the strand at a corner end, as a ruling parameter of its
/// trapezoid (the line from the near side's point at fraction p to the far side's
/// point at p; 0 is the entry line, 1 the exit line): `[entry landing, exit landing]`
/// with the exit's measured from the exit line, 0 where no neighbour overlaps. The
/// second value is true when the two landings had to be shortened to leave room for
/// the turn between them (a corner too tight for the band scale).
fn landings(
    strands: &Strands,
    f: FaceId,
    entry: [DVec3; 2],
    exit: [DVec3; 2],
    neighbours: [HalfedgeId; 2],
) -> ([f64; 2], bool) {
    let n = strands.mesh.face_normal(f);
    let x = n.any_orthonormal_vector();
    let y = n.cross(x);
    let o = entry[0];
    let flat = |p: DVec3| DVec2::new((p - o).dot(x), (p - o).dot(y));
    let (entry2, exit2) = (entry.map(flat), exit.map(flat));
    let own = counter_clockwise(&[entry2[0], entry2[1], exit2[1], exit2[0]]);
    let mut reach = [0.0f64; 2];
    for side in 0..2 {
        let theirs = counter_clockwise(&strands.region(neighbours[side]).map(flat));
        let overlap = clip_convex(&theirs, &own);
        if crate::plane::area(&overlap) <= 1e-9 {
            continue;
        }
        let (from, to) = if side == 0 {
            (entry2, exit2)
        } else {
            (exit2, entry2)
        };
        let ruling = |p: f64| (from[0].lerp(to[0], p), from[1].lerp(to[1], p));
        // The side of a ruling the `from` line lies on.
        let side_of = |p: f64, v: DVec2| {
            let (a, b) = ruling(p);
            (b - a).perp_dot(v - a)
        };
        let home = side_of(0.5, 0.5 * (from[0] + from[1])).signum();
        for &v in &overlap {
            // The smallest ruling with v on the `from` side (bisection: the rulings
            // sweep the trapezoid monotonically).
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if side_of(mid, v) * home >= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            reach[side] = reach[side].max(1.02 * hi);
        }
    }
    let total = reach[0] + reach[1];
    if total > MAX_LANDINGS {
        let shrink = MAX_LANDINGS / total;
        ([reach[0] * shrink, reach[1] * shrink], true)
    } else {
        (reach, false)
    }
}

/// The two landings of a corner take at most this fraction of its rulings, leaving
/// the rest for the turn between the heights.
const MAX_LANDINGS: f64 = 0.9;

/// What [`ribbons`] found besides the ribbons.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RibbonNotes {
    /// Face corners where a strand's landings would meet (no room to turn between
    /// the heights outside the crossings).
    pub tight_corners: usize,
}

/// The ribbons of a closed mesh with every edge twisted, in cycle order.
pub fn ribbons(
    mesh: &Mesh,
    options: &WovenOptions,
) -> Result<(Vec<Ribbon>, RibbonNotes), SchemeError> {
    let cycles = trace_cycles(mesh, &vec![true; mesh.edge_count()]).map_err(|e| {
        SchemeError::Options(format!(
            "the woven scheme cannot weave this mesh: {e}; close its holes (--fill-holes) or use another --scheme"
        ))
    })?;
    // The cycles crossing each edge (twice each).
    let mut visits: Vec<Vec<u32>> = vec![Vec::new(); mesh.edge_count()];
    for (c, cycle) in cycles.iter().enumerate() {
        for e in cycle.edges() {
            visits[e.index()].push(c as u32);
        }
    }
    let (lo, hi) = end_fractions(options.band_scale);
    let strands = Strands {
        mesh,
        centres: mesh.faces().map(|f| mesh.face_centre(f)).collect(),
        scale: options.panel.face_scale,
        lo,
        hi,
    };
    let normals: Vec<DVec3> = (0..mesh.edge_count() as u32)
        .map(|e| edge_piece_normal(mesh, EdgeId(e), &|f, v| strands.band(f, v)))
        .collect();
    let weave = Weave {
        mesh,
        strands,
        normals,
        visits,
        half: 0.5 * options.thickness,
    };
    let mut notes = RibbonNotes::default();
    let ribbons = cycles
        .iter()
        .enumerate()
        .map(|(c, cycle)| cycle_ribbon(&weave, c as u32, cycle, &mut notes))
        .collect();
    Ok((ribbons, notes))
}

/// What every cycle's ribbon is cut from.
struct Weave<'a> {
    mesh: &'a Mesh,
    strands: Strands<'a>,
    /// Each edge piece's plane normal.
    normals: Vec<DVec3>,
    /// The cycles crossing each edge (twice each).
    visits: Vec<Vec<u32>>,
    /// Half the material thickness (mm).
    half: f64,
}

/// The ribbon of cycle `c`: at each of its face corners the entry and exit lines,
/// lifted or lowered as the strand crosses, with the landings between; then the edge
/// piece to the next corner. Corners too tight to turn are counted in `notes`.
fn cycle_ribbon(weave: &Weave, c: u32, cycle: &WeaveCycle, notes: &mut RibbonNotes) -> Ribbon {
    let Weave {
        mesh,
        strands,
        normals,
        visits,
        half,
    } = weave;
    let (mesh, half) = (*mesh, *half);
    let n = cycle.len();
    let mut lines = Vec::with_capacity(4 * n);
    let mut pieces = Vec::with_capacity(4 * n);
    let mut refs = Vec::with_capacity(4 * n);
    let mut corner_start = Vec::with_capacity(n);
    for i in 0..n {
        let (h, corner) = (cycle.darts[i], cycle.corners[i]);
        let next = cycle.darts[(i + 1) % n];
        let f = mesh
            .face(corner)
            .expect("traced corners are face half-edges");
        let (u, w, q) = (mesh.origin(h), mesh.dest(h), mesh.dest(next));
        // Entry: the side along h's edge, lifted or lowered as the strand crosses
        // that edge; exit: the side along the next dart's edge.
        // The line moves along the face normal, so the face pieces stay in
        // planes parallel to the face, by as much as puts it half the thickness
        // off the edge pieces' plane (both strands' edge pieces stay parallel,
        // the thickness apart).
        let face_normal = mesh.face_normal(f);
        let lift = |dart: HalfedgeId, over: Option<bool>| {
            let sign = if over.unwrap_or(true) { 1.0 } else { -1.0 };
            let m = normals[dart.edge().index()];
            sign * half / face_normal.dot(m).max(MIN_LIFT_COSINE) * face_normal
        };
        let (entry_lift, exit_lift) = (lift(h, cycle.over[i]), lift(next, cycle.over[(i + 1) % n]));
        let entry = strands.end(f, w, u);
        let exit = strands.end(f, w, q);
        let neighbours = [strands.corner_at(f, u), strands.corner_at(f, q)];
        let (depth, tight) = landings(strands, f, entry, exit, neighbours);
        notes.tight_corners += usize::from(tight);
        corner_start.push(pieces.len());
        lines.push(entry.map(|p| p + entry_lift));
        if depth[0] > 0.0 {
            let line = [0, 1].map(|e| entry[e].lerp(exit[e], depth[0]) + entry_lift);
            pieces.push(PieceKind::Face { corner });
            refs.push(face_normal);
            lines.push(line);
        }
        if depth[1] > 0.0 {
            let line = [0, 1].map(|e| exit[e].lerp(entry[e], depth[1]) + exit_lift);
            pieces.push(PieceKind::Face { corner });
            refs.push(face_normal);
            lines.push(line);
        }
        pieces.push(PieceKind::Face { corner });
        refs.push(face_normal);
        lines.push(exit.map(|p| p + exit_lift));
        let e = next.edge();
        pieces.push(PieceKind::Edge {
            edge: e,
            over: cycle.over[(i + 1) % n].unwrap_or(true),
            crossing: other_visit(&visits[e.index()], c),
        });
        refs.push(normals[e.index()]);
    }
    let mut ribbon = Ribbon {
        cycle: c,
        lines,
        pieces,
        facets: Vec::new(),
        corner_start,
    };
    let flips = ring_flips(&ribbon, &refs);
    ribbon.facets = (0..ribbon.pieces.len())
        .map(|k| piece_facets(&ribbon, k, flips[k]))
        .collect();
    ribbon
}

/// The other cycle crossing an edge (the cycle itself when it crosses twice).
fn other_visit(visits: &[u32], cycle: u32) -> u32 {
    match visits {
        [a, b] if *a == cycle => *b,
        [a, _] => *a,
        _ => cycle,
    }
}

/// Unit normal of the plane holding both edge pieces at `e` (through the two band
/// sides along it), pointing to the outside.
fn edge_piece_normal(mesh: &Mesh, e: EdgeId, band: &dyn Fn(FaceId, VertexId) -> DVec3) -> DVec3 {
    let h = e.half_edge();
    let (Some(f), Some(g)) = (mesh.face(h), mesh.face(h.twin())) else {
        return DVec3::Z;
    };
    let outward = mesh.face_normal(f) + mesh.face_normal(g);
    let (u, w) = (mesh.origin(h), mesh.dest(h));
    let along = mesh.position(w) - mesh.position(u);
    let across = band(g, u) - band(f, u);
    let n = along.cross(across);
    if n.length_squared() <= 1e-24 * along.length_squared() * across.length_squared() {
        return mesh.face_normal(f);
    }
    let n = n.normalize();
    let reference = if outward.length_squared() > 1e-18 {
        outward
    } else {
        mesh.face_normal(f)
    };
    if n.dot(reference) < 0.0 {
        -n
    } else {
        n
    }
}

/// The loop of piece `k` before orienting: face pieces join near to near (both near
/// ends are on the corner's side); an edge piece crosses diagonally, so the near end
/// of one line faces the far end of the other.
fn base_loop(ribbon: &Ribbon, k: usize) -> [Corner; 4] {
    match ribbon.pieces[k] {
        PieceKind::Face { .. } => [A0, A1, B1, B0],
        PieceKind::Edge { .. } => [A0, A1, B0, B1],
    }
}

/// Whether each piece's base loop is reversed so that the ring is consistently
/// oriented with the outside up. Neighbouring pieces must run their shared line in
/// opposite directions: a face piece's base loop runs its second line far to near and
/// the next piece's runs its first near to far, so they agree; an edge piece's runs
/// its second line near to far, so the flip toggles after every edge piece (a woven
/// ring crosses an even number of edges, so it closes). Which of the two consistent
/// choices faces outward is a vote of all pieces, weighted by their area.
fn ring_flips(ribbon: &Ribbon, outward: &[DVec3]) -> Vec<bool> {
    let mut parity = Vec::with_capacity(ribbon.pieces.len());
    let mut toggle = false;
    let mut vote = 0.0;
    for (k, reference) in outward.iter().enumerate() {
        parity.push(toggle);
        let area = vector_area(base_loop(ribbon, k).iter().map(|&c| ribbon.point(k, c)));
        let agree = area.dot(*reference);
        vote += if toggle { -agree } else { agree };
        if matches!(ribbon.pieces[k], PieceKind::Edge { .. }) {
            toggle = !toggle;
        }
    }
    let flip_first = vote < 0.0;
    parity.into_iter().map(|p| p != flip_first).collect()
}

/// The facets of piece `k`, its base loop reversed when `flip`.
fn piece_facets(ribbon: &Ribbon, k: usize, flip: bool) -> Vec<Vec<Corner>> {
    let p = |c: Corner| ribbon.point(k, c);
    let quad = base_loop(ribbon, k);
    let pts: Vec<DVec3> = quad.iter().map(|&c| p(c)).collect();
    let orient = |mut loop_: Vec<Corner>| {
        if flip {
            loop_.reverse();
        }
        loop_
    };
    if planarity_error(&pts) <= 1e-9 {
        return vec![orient(quad.to_vec())];
    }
    // Two triangles along the diagonal with the smaller fold.
    let fold = |t1: [usize; 3], t2: [usize; 3]| {
        let n = |t: [usize; 3]| vector_area(t.iter().map(|&i| pts[i])).normalize_or_zero();
        n(t1).angle_between(n(t2))
    };
    let (d02, d13) = (fold([0, 1, 2], [0, 2, 3]), fold([0, 1, 3], [1, 2, 3]));
    let tris = if d02 <= d13 {
        [[0, 1, 2], [0, 2, 3]]
    } else {
        [[0, 1, 3], [1, 2, 3]]
    };
    tris.iter()
        .map(|t| orient(t.iter().map(|&i| quad[i]).collect()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strand_ends_stay_inside_the_band_side() {
        for t in [0.1, 0.5, 0.9] {
            let (lo, hi) = end_fractions(t);
            assert!(lo > 0.0 - 1e-12 && hi < 1.0 && lo < hi);
            assert!((hi - lo - t).abs() < 1e-12, "the end covers t of the side");
        }
    }

    #[test]
    fn the_other_visit_is_the_other_cycle() {
        assert_eq!(other_visit(&[3, 5], 3), 5);
        assert_eq!(other_visit(&[3, 5], 5), 3);
        assert_eq!(other_visit(&[4, 4], 4), 4);
    }
}
