//! A ribbon cut into segments: each unrolled piece by piece, as long as it neither
//! overlaps itself nor curls past the limit, and fits the sheet.

use glam::{DVec2, DVec3};

use super::ribbon::Ribbon;
use crate::mesh::geometry::vector_area;
use crate::panel::FacetFrame;
use crate::plane::{
    clip_convex, contains, convex_hull, counter_clockwise, segment_distance, smallest_box,
};
use crate::scheme::{PanelLimit, FIT_SLACK};

/// Parts of a ribbon closer than this (mm) when unrolled, that share no corner, are
/// treated as touching: the segment is cut before them.
const CLEARANCE: f64 = 0.5;

/// Two facets sharing a corner overlap when their intersection exceeds this (mm²).
const OVERLAP_AREA: f64 = 1e-4;

/// Most start positions tried when cutting a ring into segments.
const MAX_STARTS: usize = 64;

/// A chain of pieces unrolled into the plane, one piece at a time.
pub(super) struct Unrolled {
    /// 2D positions of the lines placed so far.
    pub(super) lines: Vec<[DVec2; 2]>,
    /// Placed facets.
    pub(super) facets: Vec<FlatFacet>,
    /// Their total area (mm²).
    area: f64,
    /// Frames of the placed facets (for holes and labels).
    pub(super) frames: Vec<FacetFrame>,
}

impl Unrolled {
    /// Starts with the first line of piece `k`, placed as [`crate::flatten::flatten`]
    /// places a panel whose first facet is piece `k`'s first facet (its first corner
    /// at the origin, its first edge along +x), so that rotations tried here are the
    /// ones the nester tries.
    pub(super) fn new(ribbon: &Ribbon, k: usize) -> Self {
        let facet = &ribbon.facets[k][0];
        let pts: Vec<DVec3> = facet.iter().map(|&c| ribbon.point(k, c)).collect();
        let normal = vector_area(pts.iter().copied()).normalize_or_zero();
        let frame = FacetFrame::on_hinge(pts[0], pts[1], normal, DVec2::ZERO, DVec2::X);
        let line = ribbon.lines[k % ribbon.lines.len()];
        Self {
            lines: vec![line.map(|p| frame.to_2d(p))],
            facets: Vec::new(),
            area: 0.0,
            frames: Vec::new(),
        }
    }

    /// Unrolls piece `k` across the last placed line. Returns `false` (and leaves the
    /// chain unusable) when a new facet overlaps or touches an earlier one.
    pub(super) fn push(&mut self, ribbon: &Ribbon, k: usize) -> bool {
        let first_line = self.lines.len() - 1;
        let mut placed: [[Option<DVec2>; 2]; 2] = [[None; 2]; 2];
        placed[0] = self.lines[first_line].map(Some);
        let before = self.facets.len();
        for facet in &ribbon.facets[k] {
            let pts3: Vec<DVec3> = facet.iter().map(|&c| ribbon.point(k, c)).collect();
            let normal = vector_area(pts3.iter().copied()).normalize_or_zero();
            // A hinge: two consecutive corners already placed.
            let m = facet.len();
            let Some(i) = (0..m).find(|&i| {
                let (c, d) = (facet[i], facet[(i + 1) % m]);
                placed[c.line as usize][c.end as usize].is_some()
                    && placed[d.line as usize][d.end as usize].is_some()
            }) else {
                return false;
            };
            let (c, d) = (facet[i], facet[(i + 1) % m]);
            let frame = FacetFrame::on_hinge(
                ribbon.point(k, c),
                ribbon.point(k, d),
                normal,
                placed[c.line as usize][c.end as usize].unwrap_or_default(),
                placed[d.line as usize][d.end as usize].unwrap_or_default(),
            );
            for (j, &corner) in facet.iter().enumerate() {
                let slot = &mut placed[corner.line as usize][corner.end as usize];
                if slot.is_none() {
                    *slot = Some(frame.to_2d(pts3[j]));
                }
            }
            let poly: Vec<DVec2> = facet
                .iter()
                .map(|c| placed[c.line as usize][c.end as usize].unwrap_or_default())
                .collect();
            self.area += crate::plane::area(&poly);
            self.facets
                .push(FlatFacet::new(counter_clockwise(&poly), first_line));
            self.frames.push(frame);
        }
        self.lines.push([
            placed[1][0].unwrap_or_default(),
            placed[1][1].unwrap_or_default(),
        ]);
        // The new facets against all earlier ones.
        (before..self.facets.len())
            .all(|new| (0..before).all(|old| apart(&self.facets[new], &self.facets[old])))
    }

    /// All corner points placed so far.
    fn points(&self) -> Vec<DVec2> {
        self.lines.iter().flatten().copied().collect()
    }
}

/// A facet of an unrolled chain: its polygon (counter-clockwise) and the position of
/// its piece in the chain.
pub(super) struct FlatFacet {
    pub(super) poly: Vec<DVec2>,
    piece: usize,
    /// Corners of the polygon's bounding box.
    lo: DVec2,
    hi: DVec2,
}

impl FlatFacet {
    fn new(poly: Vec<DVec2>, piece: usize) -> FlatFacet {
        let lo = poly.iter().fold(DVec2::INFINITY, |m, &p| m.min(p));
        let hi = poly.iter().fold(DVec2::NEG_INFINITY, |m, &p| m.max(p));
        FlatFacet {
            poly,
            piece,
            lo,
            hi,
        }
    }
}

/// Pieces this close in a chain may come as close as they like (they meet at fold
/// lines and turn around one corner).
const NEAR_PIECES: usize = 4;

/// Two unrolled facets do not overlap, and if they are not near each other along the
/// chain, they are at least [`CLEARANCE`] apart (the cut between them must not merge).
fn apart(a: &FlatFacet, b: &FlatFacet) -> bool {
    // Boxes at least the clearance apart hold facets that are (the common case, cheap).
    let box_gap = (a.lo - b.hi).max(b.lo - a.hi);
    if box_gap.x >= CLEARANCE || box_gap.y >= CLEARANCE {
        return true;
    }
    if crate::plane::area(&clip_convex(&a.poly, &b.poly)) > OVERLAP_AREA {
        return false;
    }
    if a.piece.abs_diff(b.piece) <= NEAR_PIECES {
        return true;
    }
    let (p, q) = (&a.poly, &b.poly);
    let gap = (0..p.len())
        .flat_map(|i| (0..q.len()).map(move |j| (i, j)))
        .map(|(i, j)| segment_distance(p[i], p[(i + 1) % p.len()], q[j], q[(j + 1) % q.len()]))
        .fold(f64::INFINITY, f64::min);
    gap >= CLEARANCE && !contains(p, q[0]) && !contains(q, p[0])
}

/// True when the points fit the panel limit in one of its orientations, and their
/// most compact bounding box (over those orientations) lies along the sheet: a
/// segment that only fits across the sheet's diagonal would take a sheet of its own.
fn fits(points: &[DVec2], limit: &PanelLimit) -> bool {
    let hull = convex_hull(points);
    let (w, h) = (limit.width - FIT_SLACK, limit.height - FIT_SLACK);
    let compact = smallest_box(&hull, limit.rotations.max(1));
    limit.fits(&hull, 0.0)
        && ((compact.x <= w && compact.y <= h) || (compact.x <= h && compact.y <= w))
}

/// What a segment must respect besides not overlapping itself.
pub(super) struct Limits {
    /// The largest panel a sheet takes.
    pub(super) panel: Option<PanelLimit>,
    /// Largest ratio of its convex hull to its area.
    pub(super) curl: f64,
}

/// The face pieces of corner `i` (without its edge piece), as ring indices.
pub(super) fn face_part(ribbon: &Ribbon, i: usize) -> std::ops::Range<usize> {
    let all = ribbon.corner_pieces(i);
    all.start..all.end - 1
}

/// The longest run of corners from `start` (at most `most`) that unrolls without
/// overlap and fits: the segment holds corners `start ..= start + len` (all of their
/// face pieces, and the edge pieces between them). `0` when not even one edge
/// crossing fits.
fn longest_run(ribbon: &Ribbon, start: usize, most: usize, limits: &Limits) -> usize {
    let limit = limits.panel.as_ref();
    let n = ribbon.edge_count();
    let first = face_part(ribbon, start);
    let mut chain = Unrolled::new(ribbon, first.start);
    if !first.clone().all(|k| chain.push(ribbon, k)) {
        return 0;
    }
    let mut len = 0;
    while len < most {
        let edge_piece = ribbon.corner_pieces(start + len).end - 1;
        let next = face_part(ribbon, (start + len + 1) % n);
        if !chain.push(ribbon, edge_piece) || !next.clone().all(|k| chain.push(ribbon, k)) {
            break;
        }
        let points = chain.points();
        let curls = len > 0 && crate::plane::area(&convex_hull(&points)) > limits.curl * chain.area;
        if curls || limit.is_some_and(|l| !fits(&points, l)) {
            break;
        }
        len += 1;
    }
    len
}

/// Cuts a ring into segments: `(first corner, corners spanned)` each, fewest segments
/// over the start positions tried (ties: the earliest start). `Err(corner)` when the
/// crossing after that corner alone does not fit.
pub(super) fn plan_segments(
    ribbon: &Ribbon,
    limits: &Limits,
) -> Result<Vec<(usize, usize)>, usize> {
    let n = ribbon.edge_count();
    let greedy = |start: usize| -> Result<Vec<(usize, usize)>, usize> {
        let mut plan = Vec::new();
        let mut done = 0;
        while done < n {
            let corner = (start + done) % n;
            let len = longest_run(ribbon, corner, n - done, limits);
            if len == 0 {
                return Err(corner);
            }
            plan.push((corner, len));
            done += len;
        }
        Ok(plan)
    };
    let first = greedy(0)?;
    if first.len() == 1 {
        return Ok(first);
    }
    let tries = first[0].1.min(MAX_STARTS);
    let mut best = first;
    for start in 1..=tries {
        if let Ok(plan) = greedy(start % n) {
            if plan.len() < best.len() {
                best = plan;
            }
        }
    }
    Ok(best)
}
