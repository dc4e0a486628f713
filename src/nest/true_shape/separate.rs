//! Overlap minimisation, after sparrow (Gardeyn and Wauters, 2025): to take a sheet
//! away, its parts go one at a time, largest first, to where they overlap least on one
//! of the emptiest other sheets; that sheet is then separated: every overlapping part
//! is moved to its pose of least weighted overlap, and the weight of every pair still
//! overlapping grows (a guided local search), until nothing overlaps, or until the
//! rounds, strikes or budget run out, when the squeeze puts the sheet back as it was.
//!
//! The separation's cost is in evaluating overlap: collecting the collisions of a
//! pose (until their weighted sum reaches the best pose's, where the constructive
//! search stops at the first) and weighing the disc pairs. The effort budget counts
//! each evaluation as [`OVERLAP_CHECK_COST`] checks plus one per
//! [`DISC_PAIRS_PER_CHECK`] disc pairs: the cost of an evaluation relative to a
//! constructive check, as measured on the bunny and the knight. On sheets holding
//! hundreds of parts (horse_quad quad-edge) an evaluation costs about twice what it
//! counts.

use rayon::prelude::*;
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use jagua_rs::collision_detection::hazards::filter::NoFilter;
use jagua_rs::collision_detection::hazards::{BasicHazardEntity, PItemKey};
use jagua_rs::geometry::geo_traits::TransformableFrom;

use super::nester::{Candidate, Nester, MIN_STEP};

/// Cost of a pose outside the sheet (never chosen while any other pose exists).
const OUTSIDE: f32 = 1e12;

/// Growth of a pair's weight per round it keeps overlapping: the most overlapping pair
/// by the factor `1 + WEIGHT_GROWTH.1`, the others proportionally less, down to
/// `1 + WEIGHT_GROWTH.0` (sparrow's 1.2 to 2).
const WEIGHT_GROWTH: (f32, f32) = (0.2, 1.0);

/// Decay of a pair's weight per round it does not overlap (down to 1).
const WEIGHT_DECAY: f32 = 0.95;

/// Most weight of a pair: far above what separations reach (about 10 on the bunny),
/// and far below the cost of a pose outside the sheet, which it must never outweigh.
const WEIGHT_CAP: f32 = 1e6;

/// Rounds without a new least total overlap after which the separation goes back to
/// the least-overlap state it saw (a strike).
const ROUNDS_PER_STRIKE: u32 = 50;

/// Strikes in a row that did not lower the least total overlap by 2 % (against the
/// least at the strike before: the first strike only sets that mark) before a sheet
/// is given up.
const STRIKES: u32 = 3;

/// Other sheets, emptiest first, that a part squeezed out of the emptiest sheet tries.
const SQUEEZE_SHEETS: usize = 2;

/// Collision checks one evaluation of a pose's overlap counts for in the effort
/// budget, besides its disc pairs (see the module documentation).
const OVERLAP_CHECK_COST: u64 = 8;

/// Disc pairs of the overlap measure that cost one collision check of the budget.
const DISC_PAIRS_PER_CHECK: usize = 128;

/// Sampled poses per move, before the local descent.
const MOVE_SAMPLES: usize = 48;

/// Overlapping pairs of parts on a sheet (by part index, smaller first) and their
/// overlap.
type Pairs = BTreeMap<(usize, usize), f32>;

/// Weights of overlapping pairs of parts (by part index, smaller first); 1 when absent.
#[derive(Default)]
pub(super) struct Weights(HashMap<(usize, usize), f32>);

impl Weights {
    fn get(&self, a: usize, b: usize) -> f32 {
        self.0.get(&(a.min(b), a.max(b))).copied().unwrap_or(1.0)
    }
}

impl Nester<'_> {
    /// Moves the overlapping parts of sheet `s`, whose overlapping pairs are `pairs`,
    /// until none overlaps (`true`), or until `rounds` rounds, the strikes or the
    /// budget run out (`false`, the sheet left overlapping: the caller puts it back).
    /// The pairs are kept up to date for the parts that move; the sheet is scanned
    /// only when they run out and the whole-sheet check still finds a collision. A
    /// sheet of a large job holds hundreds of parts, and scanning them all every round
    /// cost more than the moves themselves.
    fn separate(&mut self, s: usize, rounds: usize, mut pairs: Pairs) -> bool {
        let mut weights = Weights::default();
        // The least total overlap seen, and the poses and pairs in that state.
        let mut least = f32::INFINITY;
        let mut least_state: Option<(Vec<Candidate>, Pairs)> = None;
        let mut since_least = 0;
        let mut strike_start = f32::INFINITY;
        let mut strikes = 0;
        for _ in 0..rounds {
            // Confirmed on the whole sheet: only the pairs of the parts that moved
            // are kept up to date, and a pair missed there would leave parts
            // overlapping. The fail-fast check costs a fraction of a full scan.
            if pairs.is_empty() {
                self.checks += self.sheets[s].parts.len() as u64;
                if self.sheets[s].layout.is_collision_free() {
                    self.refill_grid(s);
                    return true;
                }
                pairs = self.overlapping_pairs(s);
                if pairs.is_empty() {
                    // What collides is a part with the sheet's edge, which moves
                    // do not track: give up rather than scan again every round.
                    return false;
                }
            }
            if self.out_of_budget() {
                break;
            }
            let total: f32 = pairs.values().sum();
            if total < least {
                least = total;
                least_state = Some((self.poses_on(s), pairs.clone()));
                since_least = 0;
            } else {
                since_least += 1;
                if since_least >= ROUNDS_PER_STRIKE {
                    // A strike: back to the least-overlap state, weights kept.
                    if least > 0.98 * strike_start {
                        strikes += 1;
                        if strikes >= STRIKES {
                            break;
                        }
                    } else {
                        strikes = 0;
                    }
                    strike_start = least;
                    since_least = 0;
                    if let Some((poses, saved)) = &least_state {
                        self.restore_poses(s, poses);
                        pairs = saved.clone();
                    }
                    continue;
                }
            }
            let largest = pairs.values().copied().fold(0.0, f32::max);
            for w in weights.0.values_mut() {
                *w = (*w * WEIGHT_DECAY).max(1.0);
            }
            let (grow_least, grow_most) = WEIGHT_GROWTH;
            for (&(a, b), &overlap) in &pairs {
                let w = weights.0.entry((a, b)).or_insert(1.0);
                let growth = grow_least + (grow_most - grow_least) * overlap / largest;
                // Undo this round's decay, then grow.
                *w = ((*w / WEIGHT_DECAY).max(1.0) * (1.0 + growth)).min(WEIGHT_CAP);
            }
            let mut movers: Vec<usize> = pairs.keys().flat_map(|&(a, b)| [a, b]).collect();
            movers.sort_unstable();
            movers.dedup();
            // Fisher–Yates with the seeded generator.
            for i in (1..movers.len()).rev() {
                let j = self.rng.below(i + 1);
                movers.swap(i, j);
            }
            for part in movers {
                if !pairs.keys().any(|&(a, b)| a == part || b == part) {
                    continue;
                }
                pairs.retain(|&(a, b), _| a != part && b != part);
                self.move_part(s, part, &weights);
                self.record_overlaps(s, part, &mut pairs);
            }
        }
        false
    }

    /// The poses of the parts on sheet `s`, slot by slot.
    fn poses_on(&self, s: usize) -> Vec<Candidate> {
        self.sheets[s].parts.iter().map(|e| e.2).collect()
    }

    /// Puts the parts on sheet `s` back in `poses` (slot by slot, as
    /// [`Nester::poses_on`] gave them), moving only the parts whose pose differs.
    fn restore_poses(&mut self, s: usize, poses: &[Candidate]) {
        for (slot, &c) in poses.iter().enumerate() {
            let (part, key, now) = self.sheets[s].parts[slot];
            if (now.orientation, now.x, now.y) == (c.orientation, c.x, c.y) {
                continue;
            }
            self.sheets[s].layout.remove_item(key);
            self.place_in_slot(s, slot, part, c);
        }
    }

    /// Places `part`, taken out of the layout of sheet `s`, back at `c`, and records
    /// its new key and pose in its slot.
    fn place_in_slot(&mut self, s: usize, slot: usize, part: usize, c: Candidate) {
        let pose = self.pose(part, c);
        let key = self.sheets[s]
            .layout
            .place_item(&self.parts[part].item, pose);
        self.sheets[s].parts[slot] = (part, key, c);
    }

    /// The slot of `part` on sheet `s`, where it is placed.
    fn slot_of(&self, s: usize, part: usize) -> usize {
        self.sheets[s]
            .parts
            .iter()
            .position(|e| e.0 == part)
            .expect("the part is on the sheet")
    }

    /// Squeezes the parts of the emptiest sheet, largest first, into the others one at
    /// a time: each goes to its pose of least overlap on one of the emptiest other
    /// sheets, which is then separated, and stays there only when that succeeds. Stops
    /// at the first part that finds no room (the sheet cannot be emptied then, and the
    /// parts after it would only spend effort). Returns whether the sheet went away.
    pub(super) fn squeeze_emptiest(&mut self, rounds: usize) -> bool {
        if self.sheets.len() < 2 {
            return false;
        }
        let target = self.emptiest();
        let parts = self.parts;
        let mut moving: Vec<usize> = self.sheets[target].parts.iter().map(|e| e.0).collect();
        moving.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area).then(a.cmp(&b)));
        for part in moving {
            if self.out_of_budget() || !self.squeeze_part(target, part, rounds) {
                return false;
            }
        }
        self.sheets.remove(target);
        true
    }

    /// Moves `part` from sheet `from` into one of the emptiest other sheets by overlap
    /// minimisation (see [`Nester::squeeze_emptiest`]); `false` leaves it where it was.
    ///
    /// The sheets are tried at once, each on its own copy of the search from the same
    /// state: the first, emptiest first, whose separation succeeds is kept, and the
    /// checks count as if they had been tried one after the other up to it. The result
    /// is the same on one thread as on several.
    fn squeeze_part(&mut self, from: usize, part: usize, rounds: usize) -> bool {
        let parts = self.parts;
        let mut by_fill: Vec<(f32, usize)> = (0..self.sheets.len())
            .filter(|&s| s != from)
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
        if self.out_of_budget() {
            return false;
        }
        // A trial gives up once one before it has succeeded: its outcome would not count.
        let succeeded: Vec<Arc<AtomicBool>> = (0..SQUEEZE_SHEETS)
            .map(|_| Arc::new(AtomicBool::new(false)))
            .collect();
        let trials: Vec<(usize, Nester)> = by_fill
            .iter()
            .take(SQUEEZE_SHEETS)
            .enumerate()
            .map(|(k, &(_, s))| {
                let mut trial = self.trial();
                trial.given_up = succeeded[..k].to_vec();
                (s, trial)
            })
            .collect();
        let tried: Vec<(usize, Nester, bool)> = trials
            .into_par_iter()
            .enumerate()
            .map(|(k, (s, mut trial))| {
                let fits = trial.squeeze_into(s, part, rounds);
                if fits {
                    succeeded[k].store(true, Ordering::Relaxed);
                }
                (s, trial, fits)
            })
            .collect();
        let start = self.checks;
        for (s, mut trial, fits) in tried {
            self.checks += trial.checks - start;
            self.rng = trial.rng;
            if fits {
                std::mem::swap(&mut self.sheets[s], &mut trial.sheets[s]);
                let slot = self.slot_of(from, part);
                self.take_off(from, vec![slot]);
                return true;
            }
        }
        false
    }

    /// Puts `part` (still on its own sheet too) on sheet `s` at its pose of least
    /// overlap and separates that sheet; whether it came free of overlaps.
    fn squeeze_into(&mut self, s: usize, part: usize, rounds: usize) -> bool {
        let c = self.least_overlap_pose(s, part, None, &Weights::default());
        self.put(s, part, c);
        // The sheet was free of overlaps: the part's own are all there are.
        let mut pairs = Pairs::new();
        self.record_overlaps(s, part, &mut pairs);
        self.separate(s, rounds, pairs)
    }

    /// Whether the current phase (improvement or squeeze) has spent its collision
    /// checks, or the improvement and squeeze together their time.
    pub(super) fn out_of_budget(&self) -> bool {
        let (before, weight, first, spend) = self.budget_share;
        self.report(before, weight, self.checks - first, spend);
        self.checks >= self.budget
            || self.started.elapsed() >= self.time_limit
            || self.given_up.iter().any(|g| g.load(Ordering::Relaxed))
    }

    /// Every overlapping pair on sheet `s`, with its overlap.
    fn overlapping_pairs(&mut self, s: usize) -> Pairs {
        let mut pairs = Pairs::new();
        for slot in 0..self.sheets[s].parts.len() {
            let (part, key, _) = self.sheets[s].parts[slot];
            for (other, overlap) in self.overlaps_of(s, part, key) {
                if part < other {
                    pairs.insert((part, other), overlap);
                }
            }
        }
        pairs
    }

    /// Adds the pairs that `part` (placed on sheet `s`) overlaps in.
    fn record_overlaps(&mut self, s: usize, part: usize, pairs: &mut Pairs) {
        let key = self.sheets[s].parts[self.slot_of(s, part)].1;
        for (other, overlap) in self.overlaps_of(s, part, key) {
            pairs.insert((part.min(other), part.max(other)), overlap);
        }
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
        scratch.discs.pose_mine(parts, part, &transform);
        let mut found = Vec::new();
        let mut disc_pairs = 0;
        for (_, entity) in scratch.collector.iter() {
            if let BasicHazardEntity::PlacedItem { id, dt, pk } = entity {
                if *pk != key {
                    let loss = scratch
                        .discs
                        .loss_with(parts, part, *id, dt, &mut disc_pairs);
                    found.push((*id, loss));
                }
            }
        }
        self.count_evaluation(disc_pairs);
        found
    }

    /// Counts one evaluation of overlap that weighed `disc_pairs` disc pairs in the
    /// effort budget (see the module documentation).
    fn count_evaluation(&mut self, disc_pairs: usize) {
        self.checks += OVERLAP_CHECK_COST + (disc_pairs / DISC_PAIRS_PER_CHECK) as u64;
    }

    /// Weighted overlap of `part` at `c` on sheet `s` (where it is not placed);
    /// stops looking for collisions once the sum reaches `cap`.
    fn weighted_overlap(
        &mut self,
        s: usize,
        part: usize,
        c: Candidate,
        weights: &Weights,
        cap: f32,
    ) -> f32 {
        let parts = self.parts;
        let transform = self.pose(part, c).compose();
        let shape = parts[part].item.shape_cd();
        if self.scratch_part != part {
            self.scratch = shape.as_ref().clone();
            self.scratch_part = part;
        }
        self.scratch.transform_from(shape, &transform);
        let super::part::OverlapScratch { collector, discs } = &mut self.overlap;
        collector.clear();
        // Each collision weighed as it is found, and the search stopped once the sum
        // reaches the cap: the pose is then rejected whatever else it collides with.
        let mut disc_pairs = 0;
        let mut posed = false;
        let mut total = 0.0;
        let _stopped = self.sheets[s].layout.cde().collect_poly_collisions_until(
            &self.scratch,
            &NoFilter,
            collector,
            |entity| {
                total += match entity {
                    BasicHazardEntity::PlacedItem { id, dt, .. } => {
                        if !posed {
                            discs.pose_mine(parts, part, &transform);
                            posed = true;
                        }
                        let loss = discs.loss_with(parts, part, id, &dt, &mut disc_pairs);
                        weights.get(part, id) * loss
                    }
                    _ => OUTSIDE,
                };
                total >= cap
            },
        );
        self.count_evaluation(disc_pairs);
        total
    }

    /// Moves a placed part of sheet `s` to its pose of least weighted overlap.
    fn move_part(&mut self, s: usize, part: usize, weights: &Weights) {
        let slot = self.slot_of(s, part);
        let (_, key, current) = self.sheets[s].parts[slot];
        self.sheets[s].layout.remove_item(key);
        let c = self.least_overlap_pose(s, part, Some(current), weights);
        self.place_in_slot(s, slot, part, c);
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
    use super::super::options::test_options as options;
    use super::super::part::prepare;
    use super::*;
    use crate::nest::SheetSpec;

    /// Eight 80 mm squares on a 300 mm sheet, the middle row of two placed so that
    /// no 80 mm square is free; the ninth is alone on a second sheet. Squeezing it
    /// into the first needs the middle row rearranged.
    #[test]
    fn squeezing_a_sheet_away_rearranges_a_blocked_one() {
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

        assert!(nester.squeeze_emptiest(500));
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
