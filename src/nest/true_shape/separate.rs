//! Overlap minimisation, after sparrow (Gardeyn and Wauters, 2025): to take a sheet
//! away, its parts first go where they overlap least on the other sheets; then, sheet
//! by sheet, every overlapping part is moved to its pose of least weighted overlap,
//! and the weight of every pair still overlapping grows (a guided local search), until
//! nothing overlaps or the rounds run out. The sheets are separated one after the
//! other with the one seeded generator; a part moves off its sheet only when the last
//! few overlapping parts find a free place on another one.
//!
//! Overlap between two parts is measured on discs inside their collision shapes (the
//! engine's poles and a lattice of inscribed discs): the sum over disc pairs of the
//! penetration depth times the smaller radius, which shrinks smoothly as parts move
//! apart. Outlines that touch where no discs reach (tab tips) count a small floor, so
//! every collision costs something.

use std::collections::HashMap;

use jagua_rs::collision_detection::hazards::collector::BasicHazardCollector;
use jagua_rs::collision_detection::hazards::filter::NoFilter;
use jagua_rs::collision_detection::hazards::{BasicHazardEntity, PItemKey};
use jagua_rs::geometry::geo_traits::{CollidesWith, DistanceTo, Transformable, TransformableFrom};
use jagua_rs::geometry::primitives::{Circle, Point, SPolygon};
use jagua_rs::geometry::Transformation;

use super::{Candidate, Nester, MIN_STEP};

/// Most lattice points of a part's bounds tried as disc centres.
const LATTICE_POINTS: usize = 400;

/// Discs kept per part (the largest).
const MAX_DISCS: usize = 32;

/// Overlap counted for two outlines that collide where no discs overlap, as a share of
/// the smaller of their largest discs' squared radii.
const FLOOR: f32 = 0.05;

/// Cost of a pose outside the sheet (never chosen while any other pose exists).
const OUTSIDE: f32 = 1e12;

/// Growth of a pair's weight per round it keeps overlapping (the most overlapping
/// pair grows by the most, others proportionally less).
const WEIGHT_GROWTH: f32 = 0.6;

/// Decay of a pair's weight per round it does not overlap (down to 1).
const WEIGHT_DECAY: f32 = 0.95;

/// Rounds without a 2 % drop of the total overlap before a sheet is given up.
const STRIKES: u32 = 200;

/// Overlapping parts on a sheet below which each first looks for a free place on
/// another sheet.
const RELOCATE_BELOW: usize = 5;

/// Emptiest sheets a part of the sheet taken away may go to.
const INSERT_SHEETS: usize = 3;

/// Sampled poses per move, before the local descent.
const MOVE_SAMPLES: usize = 48;

/// Inscribed discs of a collision shape (in its own frame), largest first: the
/// engine's poles, then lattice points by decreasing clearance, each kept when no
/// kept disc holds its centre, so that long thin parts are covered end to end.
pub(super) fn overlap_discs(shape: &SPolygon) -> Vec<Circle> {
    let bb = shape.bbox();
    // A quarter of the shorter side, coarser where that would pass the point limit.
    let step = (0.25 * bb.width().min(bb.height()))
        .max((bb.width() * bb.height() / LATTICE_POINTS as f32).sqrt());
    let (cols, rows) = (
        (bb.width() / step).ceil().max(1.0) as usize,
        (bb.height() / step).ceil().max(1.0) as usize,
    );
    let mut candidates: Vec<Circle> = Vec::new();
    for i in 0..cols {
        for j in 0..rows {
            let p = Point(
                bb.x_min + (i as f32 + 0.5) / cols as f32 * bb.width(),
                bb.y_min + (j as f32 + 0.5) / rows as f32 * bb.height(),
            );
            if !shape.collides_with(&p) {
                continue;
            }
            let radius = shape
                .edge_iter()
                .map(|e| e.distance_to(&p))
                .fold(f32::INFINITY, f32::min);
            if radius > 0.0 {
                candidates.push(Circle { center: p, radius });
            }
        }
    }
    candidates.sort_by(|a, b| b.radius.total_cmp(&a.radius));
    let mut discs: Vec<Circle> = shape.surrogate().poles.clone();
    for c in candidates {
        if discs.len() >= MAX_DISCS {
            break;
        }
        if discs
            .iter()
            .all(|d| d.center.distance_to(&c.center) >= d.radius)
        {
            discs.push(c);
        }
    }
    discs.sort_by(|a, b| b.radius.total_cmp(&a.radius));
    discs
}

/// Overlap of two posed disc sets (mm²).
fn disc_overlap(a: &[Circle], b: &[Circle]) -> f32 {
    // Only the discs of `a` that reach the bounds of `b`'s discs.
    let (lo, hi) = b.iter().fold(
        (
            Point(f32::INFINITY, f32::INFINITY),
            Point(f32::NEG_INFINITY, f32::NEG_INFINITY),
        ),
        |(lo, hi), d| {
            (
                Point(
                    lo.0.min(d.center.0 - d.radius),
                    lo.1.min(d.center.1 - d.radius),
                ),
                Point(
                    hi.0.max(d.center.0 + d.radius),
                    hi.1.max(d.center.1 + d.radius),
                ),
            )
        },
    );
    let mut total = 0.0;
    for p in a {
        if p.center.0 + p.radius <= lo.0
            || p.center.0 - p.radius >= hi.0
            || p.center.1 + p.radius <= lo.1
            || p.center.1 - p.radius >= hi.1
        {
            continue;
        }
        for q in b {
            let depth = p.radius + q.radius - p.center.distance_to(&q.center);
            if depth > 0.0 {
                total += depth * p.radius.min(q.radius);
            }
        }
    }
    let floor = FLOOR * a[0].radius.min(b[0].radius).powi(2);
    total.max(floor)
}

/// Weights of overlapping pairs of parts (by part index, smaller first); 1 when absent.
#[derive(Default)]
pub(super) struct Weights(HashMap<(usize, usize), f32>);

impl Weights {
    fn get(&self, a: usize, b: usize) -> f32 {
        self.0.get(&(a.min(b), a.max(b))).copied().unwrap_or(1.0)
    }
}

/// Buffers of the overlap measure.
#[derive(Default)]
pub(super) struct OverlapScratch {
    collector: BasicHazardCollector,
    mine: Vec<Circle>,
    theirs: Vec<Circle>,
}

fn pose_discs(discs: &[Circle], transform: &Transformation, out: &mut Vec<Circle>) {
    out.clear();
    out.extend(discs.iter().map(|d| d.transform_clone(transform)));
}

impl Nester<'_> {
    /// Takes the emptiest sheet away: each of its parts, largest first, goes to its
    /// pose of least overlap on whichever of the three emptiest other sheets (by the
    /// area of their collision shapes) overlaps least, a free pose ending the search;
    /// the sheets given overlaps are then separated. All or nothing: `false` leaves
    /// the sheets as they were.
    pub(super) fn eliminate_emptiest(&mut self, rounds: usize) -> bool {
        if self.sheets.len() < 2 {
            return false;
        }
        let target = self.emptiest();
        let backup = self.sheets.clone();
        let parts = self.parts;
        let mut moving: Vec<usize> = self.sheets[target].parts.iter().map(|e| e.0).collect();
        moving.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area).then(a.cmp(&b)));
        self.sheets.remove(target);
        let mut crowded: Vec<usize> = Vec::new();
        for part in moving {
            // The emptiest sheets by the area of their collision shapes (spacing
            // included); the part goes where it overlaps least.
            let mut by_fill: Vec<(f32, usize)> = (0..self.sheets.len())
                .map(|s| {
                    let used: f32 = self.sheets[s]
                        .parts
                        .iter()
                        .map(|e| parts[e.0].item.shape_cd().area())
                        .sum();
                    (used, s)
                })
                .collect();
            by_fill.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut best: Option<(f32, usize, Candidate)> = None;
            for &(_, s) in by_fill.iter().take(INSERT_SHEETS) {
                let c = self.least_overlap_pose(s, part, None, &Weights::default());
                let cost = self.weighted_overlap(s, part, c, &Weights::default(), f32::INFINITY);
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, s, c));
                }
                if cost == 0.0 {
                    break;
                }
            }
            let (cost, s, c) = best.expect("at least one other sheet");
            if cost > 0.0 && !crowded.contains(&s) {
                crowded.push(s);
            }
            self.put(s, part, c);
        }
        crowded.sort_unstable();
        for s in crowded {
            if !self.separate(s, rounds) {
                self.sheets = backup;
                return false;
            }
        }
        true
    }

    /// Moves the overlapping parts of sheet `s` until none overlaps (`true`), or
    /// until `rounds` rounds or the strikes run out (`false`, the sheet overlapping).
    fn separate(&mut self, s: usize, rounds: usize) -> bool {
        let mut weights = Weights::default();
        let mut best_total = f32::INFINITY;
        let mut strikes = 0;
        for _ in 0..rounds {
            let pairs = self.overlapping_pairs(s);
            if pairs.is_empty() {
                self.refill_grid(s);
                return true;
            }
            if self.out_of_budget() {
                return false;
            }
            let total: f32 = pairs.iter().map(|p| p.2).sum();
            if total < 0.98 * best_total {
                best_total = total;
                strikes = 0;
            } else {
                strikes += 1;
                if strikes >= STRIKES {
                    return false;
                }
            }
            let largest = pairs.iter().map(|p| p.2).fold(0.0, f32::max);
            for w in weights.0.values_mut() {
                *w = (*w * WEIGHT_DECAY).max(1.0);
            }
            for &(a, b, overlap) in &pairs {
                let w = weights.0.entry((a, b)).or_insert(1.0);
                // Undo this round's decay, then grow.
                *w = (*w / WEIGHT_DECAY).max(1.0) * (1.0 + WEIGHT_GROWTH * overlap / largest);
            }
            let mut movers: Vec<usize> = pairs.iter().flat_map(|p| [p.0, p.1]).collect();
            movers.sort_unstable();
            movers.dedup();
            // Fisher–Yates with the seeded generator.
            for i in (1..movers.len()).rev() {
                let j = self.rng.below(i + 1);
                movers.swap(i, j);
            }
            // The last few overlapping parts may find a free place on another sheet.
            let relocate = movers.len() <= RELOCATE_BELOW;
            for part in movers {
                if self.overlaps_any(s, part) && !(relocate && self.relocate(s, part)) {
                    self.move_part(s, part, &weights);
                }
            }
        }
        false
    }

    /// Moves `part` from sheet `s` to a free pose on another sheet (emptiest first);
    /// `false` when there is none.
    fn relocate(&mut self, s: usize, part: usize) -> bool {
        let mut by_fill: Vec<usize> = (0..self.sheets.len()).filter(|&t| t != s).collect();
        by_fill.sort_by(|&a, &b| {
            self.sheets[a]
                .area
                .total_cmp(&self.sheets[b].area)
                .then(a.cmp(&b))
        });
        for t in by_fill {
            if let Some(c) = self.search(t, part, self.samples) {
                let slot = self.sheets[s]
                    .parts
                    .iter()
                    .position(|e| e.0 == part)
                    .expect("the part is on the sheet");
                self.take_off(s, vec![slot]);
                self.put(t, part, c);
                return true;
            }
        }
        false
    }

    /// Whether the improvement has spent its collision checks or time.
    pub(super) fn out_of_budget(&self) -> bool {
        self.checks >= self.budget || self.started.elapsed() >= self.time_limit
    }

    /// Every overlapping pair on sheet `s` as (part, part, overlap), smaller part first.
    fn overlapping_pairs(&mut self, s: usize) -> Vec<(usize, usize, f32)> {
        let mut pairs = Vec::new();
        for slot in 0..self.sheets[s].parts.len() {
            let (part, key, _) = self.sheets[s].parts[slot];
            for (other, overlap) in self.overlaps_of(s, part, key) {
                if part < other {
                    pairs.push((part, other, overlap));
                }
            }
        }
        pairs.sort_by_key(|p| (p.0, p.1));
        pairs
    }

    /// Whether `part` (placed on sheet `s`) overlaps another.
    fn overlaps_any(&mut self, s: usize, part: usize) -> bool {
        let Some(&(_, key, _)) = self.sheets[s].parts.iter().find(|e| e.0 == part) else {
            return false;
        };
        self.collect_collisions_of(s, key);
        self.overlap.collector.iter().any(|(_, e)| match e {
            BasicHazardEntity::PlacedItem { pk, .. } => *pk != key,
            _ => true,
        })
    }

    /// Fills the collector with what the part placed under `key` on sheet `s`
    /// collides with (itself included).
    fn collect_collisions_of(&mut self, s: usize, key: PItemKey) {
        let layout = &self.sheets[s].layout;
        let shape = layout.placed_items()[key].shape();
        self.overlap.collector.clear();
        layout
            .cde()
            .collect_poly_collisions(shape, &NoFilter, &mut self.overlap.collector);
    }

    /// The parts a placed part collides with, and the overlap with each.
    fn overlaps_of(&mut self, s: usize, part: usize, key: PItemKey) -> Vec<(usize, f32)> {
        let parts = self.parts;
        self.collect_collisions_of(s, key);
        let transform = self.sheets[s].layout.placed_items()[key]
            .d_transf()
            .compose();
        let scratch = &mut self.overlap;
        pose_discs(&parts[part].discs, &transform, &mut scratch.mine);
        let mut found = Vec::new();
        for (_, entity) in scratch.collector.iter() {
            if let BasicHazardEntity::PlacedItem { id, dt, pk } = entity {
                if *pk != key {
                    pose_discs(&parts[*id].discs, &dt.compose(), &mut scratch.theirs);
                    found.push((*id, disc_overlap(&scratch.mine, &scratch.theirs)));
                }
            }
        }
        found
    }

    /// Weighted overlap of `part` at `c` on sheet `s` (where it is not placed);
    /// stops adding once `cap` is reached.
    fn weighted_overlap(
        &mut self,
        s: usize,
        part: usize,
        c: Candidate,
        weights: &Weights,
        cap: f32,
    ) -> f32 {
        self.checks += 1;
        let parts = self.parts;
        let transform = self.pose(part, c).compose();
        let shape = parts[part].item.shape_cd();
        if self.scratch_part != part {
            self.scratch = shape.as_ref().clone();
            self.scratch_part = part;
        }
        self.scratch.transform_from(shape, &transform);
        let scratch = &mut self.overlap;
        scratch.collector.clear();
        self.sheets[s].layout.cde().collect_poly_collisions(
            &self.scratch,
            &NoFilter,
            &mut scratch.collector,
        );
        if scratch.collector.is_empty() {
            return 0.0;
        }
        pose_discs(&parts[part].discs, &transform, &mut scratch.mine);
        let mut total = 0.0;
        for (_, entity) in scratch.collector.iter() {
            total += match entity {
                BasicHazardEntity::PlacedItem { id, dt, .. } => {
                    pose_discs(&parts[*id].discs, &dt.compose(), &mut scratch.theirs);
                    weights.get(part, *id) * disc_overlap(&scratch.mine, &scratch.theirs)
                }
                _ => OUTSIDE,
            };
            if total >= cap {
                break;
            }
        }
        total
    }

    /// Moves a placed part of sheet `s` to its pose of least weighted overlap.
    fn move_part(&mut self, s: usize, part: usize, weights: &Weights) {
        let slot = self.sheets[s]
            .parts
            .iter()
            .position(|e| e.0 == part)
            .expect("the part is on the sheet");
        let (_, key, current) = self.sheets[s].parts[slot];
        self.sheets[s].layout.remove_item(key);
        let c = self.least_overlap_pose(s, part, Some(current), weights);
        let pose = self.pose(part, c);
        let key = self.sheets[s]
            .layout
            .place_item(&self.parts[part].item, pose);
        self.sheets[s].parts[slot] = (part, key, c);
    }

    /// The pose of least weighted overlap of `part` (not placed) on sheet `s`:
    /// the current pose if any, samples over the sheet and around the current pose,
    /// then a descent from the best.
    fn least_overlap_pose(
        &mut self,
        s: usize,
        part: usize,
        current: Option<Candidate>,
        weights: &Weights,
    ) -> Candidate {
        let n_orient = self.parts[part].orientations.len();
        let reach = 0.5 * self.parts[part].item.shape_cd().diameter();
        let b = self.bounds;
        let mut best: Option<(f32, Candidate)> =
            current.map(|c| (self.weighted_overlap(s, part, c, weights, f32::INFINITY), c));
        for k in 0..MOVE_SAMPLES {
            if best.is_some_and(|(cost, _)| cost == 0.0) {
                break;
            }
            let near = best.filter(|_| k % 2 == 1).map(|(_, c)| c);
            let c = match near {
                Some(at) => {
                    let o = if self.rng.below(2) == 0 {
                        at.orientation
                    } else {
                        self.rng.below(n_orient)
                    };
                    let dx = reach * (2.0 * self.rng.unit() as f32 - 1.0);
                    let dy = reach * (2.0 * self.rng.unit() as f32 - 1.0);
                    self.clamp(part, o, at.x + dx, at.y + dy)
                }
                None => {
                    let o = self.rng.below(n_orient);
                    let x = b.x_min + b.width() * self.rng.unit() as f32;
                    let y = b.y_min + b.height() * self.rng.unit() as f32;
                    self.clamp(part, o, x, y)
                }
            };
            let cap = best.map_or(f32::INFINITY, |(cost, _)| cost);
            let cost = self.weighted_overlap(s, part, c, weights, cap);
            if cost < cap {
                best = Some((cost, c));
            }
        }
        match best {
            Some((cost, c)) => self.descend(s, part, cost, c, weights),
            // Only when every sampled cost was infinite: any pose inside the sheet.
            None => self.clamp(
                part,
                0,
                0.5 * (b.x_min + b.x_max),
                0.5 * (b.y_min + b.y_max),
            ),
        }
    }

    /// Greedy descent of the weighted overlap: moves in four directions and turns by
    /// one step, halving the step when nothing improves.
    fn descend(
        &mut self,
        s: usize,
        part: usize,
        mut cost: f32,
        mut c: Candidate,
        weights: &Weights,
    ) -> Candidate {
        let n_orient = self.parts[part].orientations.len();
        let mut step = 0.1 * self.parts[part].item.shape_cd().diameter();
        while cost > 0.0 && step > MIN_STEP {
            let mut moves: Vec<Candidate> = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
                .iter()
                .map(|(dx, dy)| self.clamp(part, c.orientation, c.x + dx * step, c.y + dy * step))
                .collect();
            if n_orient > 1 {
                for turn in [1, n_orient - 1] {
                    moves.push(self.clamp(part, (c.orientation + turn) % n_orient, c.x, c.y));
                }
            }
            let mut improved = false;
            for next in moves {
                let v = self.weighted_overlap(s, part, next, weights, cost);
                if v < cost {
                    (cost, c) = (v, next);
                    improved = true;
                }
            }
            if !improved {
                step *= 0.5;
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::test_rectangle as rectangle;
    use super::super::{prepare, NestOptions, Nester, SheetSpec};
    use super::*;

    fn options() -> NestOptions {
        NestOptions {
            rotations: 4,
            mirror: false,
            effort: 5,
            seed: 1,
            time_limit: None,
        }
    }

    #[test]
    fn discs_lie_inside_and_cover_a_long_thin_part() {
        let sheet = SheetSpec {
            width: 400.0,
            height: 400.0,
            margin: 0.0,
            spacing: 0.0,
        };
        let (parts, _) = prepare(&[rectangle(150.0, 10.0)], sheet, &options()).unwrap();
        let shape = parts[0].item.shape_cd();
        let discs = &parts[0].discs;
        assert!(discs.len() >= 10, "{} discs", discs.len());
        for d in discs {
            assert!(shape.collides_with(&d.center));
            let clearance = shape
                .edge_iter()
                .map(|e| e.distance_to(&d.center))
                .fold(f32::INFINITY, f32::min);
            assert!(d.radius <= clearance + 1e-3, "{d:?} sticks out");
        }
        // Every point of the centre line, but the ends, is within 0.5 mm of a disc.
        for i in 0..=26 {
            let p = Point(-65.0 + 5.0 * i as f32, 0.0);
            assert!(
                discs
                    .iter()
                    .any(|d| d.center.distance_to(&p) <= d.radius + 0.5),
                "{p:?} is not covered"
            );
        }
    }

    #[test]
    fn overlap_shrinks_as_parts_move_apart() {
        let square = |x: f32| -> Vec<Circle> {
            let mut discs = vec![Circle {
                center: Point(x, 0.0),
                radius: 10.0,
            }];
            for (dx, dy) in [(-6.0, -6.0), (6.0, -6.0), (6.0, 6.0), (-6.0, 6.0)] {
                discs.push(Circle {
                    center: Point(x + dx, dy),
                    radius: 4.0,
                });
            }
            discs
        };
        let a = square(0.0);
        let mut last = f32::INFINITY;
        for step in 0..10 {
            let overlap = disc_overlap(&a, &square(2.0 * step as f32));
            assert!(overlap < last, "not shrinking at step {step}: {overlap}");
            last = overlap;
        }
        // Touching outlines with no overlapping discs still cost the floor.
        assert_eq!(disc_overlap(&a, &square(40.0)), FLOOR * 100.0);
    }

    /// Eight 80 mm squares on a 300 mm sheet, the middle row of two placed so that
    /// no 80 mm square is free; the ninth is alone on a second sheet. Taking that
    /// sheet away needs the middle row rearranged.
    #[test]
    fn eliminating_a_sheet_rearranges_a_blocked_one() {
        let sheet = SheetSpec {
            width: 300.0,
            height: 300.0,
            margin: 0.0,
            spacing: 2.0,
        };
        let outlines = vec![rectangle(80.0, 80.0); 9];
        let (parts, container) = prepare(&outlines, sheet, &options()).unwrap();
        let mut nester = Nester::new(&parts, container, &options());
        let full = nester.open_sheet();
        let corners = [
            (0.0, 0.0),
            (110.0, 0.0),
            (220.0, 0.0),
            (55.0, 110.0),
            (165.0, 110.0),
            (0.0, 220.0),
            (110.0, 220.0),
            (220.0, 220.0),
        ];
        for (part, (x, y)) in corners.into_iter().enumerate() {
            let c = nester.clamp(part, 0, x + 40.0, y + 40.0);
            nester.put(full, part, c);
        }
        assert!(nester.sheets[full].layout.is_collision_free());
        assert!(
            nester.search(full, 8, 5000).is_none(),
            "the ninth square should not fit the blocked sheet"
        );
        let alone = nester.open_sheet();
        let c = nester.clamp(8, 0, 150.0, 150.0);
        nester.put(alone, 8, c);

        assert!(nester.eliminate_emptiest(500));
        assert_eq!(nester.sheets.len(), 1);
        let layout = &nester.sheets[0].layout;
        assert_eq!(layout.placed_items().len(), 9);
        assert!(layout.is_collision_free());
        let b = nester.bounds;
        for (_, placed) in layout.placed_items() {
            let bb = placed.shape().bbox();
            assert!(bb.x_min >= b.x_min && bb.x_max <= b.x_max);
            assert!(bb.y_min >= b.y_min && bb.y_max <= b.y_max);
        }
    }
}
