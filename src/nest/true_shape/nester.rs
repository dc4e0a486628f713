//! The search state ([`Nester`]): the parts, the sheets open so far, the random stream
//! and the budget of collision checks, with the sampled pose search, first-fit
//! construction and the moves that empty the emptiest sheet. The construction in rows
//! and the squeeze add their own moves (`rows`, `separate`).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::DVec2;
use jagua_rs::collision_detection::hazards::filter::NoFilter;
use jagua_rs::entities::{Container, Layout as JLayout, PItemKey};
use jagua_rs::geometry::geo_traits::TransformableFrom;
use jagua_rs::geometry::primitives::{Rect, SPolygon};
use jagua_rs::geometry::DTransformation;
use rayon::prelude::*;

use super::options::NestOptions;
use super::part::{OverlapScratch, Part};
use crate::nest::grid::Grid;
use crate::nest::layout::{Layout, NestProgress, Placement, SheetSpec};
use crate::rng::SplitMix64;

/// Weight of the x coordinate in the bottom-left score (y counts 1): with the contact
/// bonus, half weight packs tighter than smaller ones.
const LEFT_WEIGHT: f32 = 0.5;

/// Bonus in the placement score for an outline that touches placed parts or the
/// sheet's edge, per part size (square root of its area) at full contact. Bottom-left
/// alone leaves a part wherever its top is lowest, often in a corner that leaves a
/// gap no other part fills; preferring poses that hug their neighbours packs tighter,
/// and weight 1 packs best of the weights tried (0.5 to 2).
const CONTACT_WEIGHT: f32 = 1.0;

/// How far (mm) inside the sheet's bounds a clamped candidate stays.
pub(super) const EDGE_GAP: f32 = 0.01;

/// Consecutive parts that may fail on a sheet before the constructive phase stops
/// trying it.
const CLOSE_AFTER_FAILURES: u32 = 40;

/// Cells of the occupancy grid along the longer side of a sheet.
const GRID_CELLS: usize = 200;

/// A pose under search: orientation index and translation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    pub(super) orientation: usize,
    pub(super) x: f32,
    pub(super) y: f32,
}

/// How many of the best samples get the local search: six packs tighter than fewer,
/// and more cost about a third more time for little.
const REFINED: usize = 6;

/// Fewest samples one parallel task tests (fewer would cost more to hand out).
const SAMPLES_PER_TASK: usize = 16;

/// Smallest step of the local search (mm).
pub(super) const MIN_STEP: f32 = 0.05;

/// One sheet being filled.
#[derive(Clone)]
pub(super) struct Sheet {
    pub(super) layout: JLayout,
    /// Cells covered by the placed parts.
    grid: Grid,
    /// (part, key in the layout, pose).
    pub(super) parts: Vec<(usize, PItemKey, Candidate)>,
    area: f64,
    failures: u32,
}

/// The search state: parts, open sheets and scratch space.
pub(super) struct Nester<'a> {
    pub(super) parts: &'a [Part],
    container: Container,
    pub(super) bounds: Rect,
    pub(super) rng: SplitMix64,
    pub(super) samples: usize,
    /// The separator's buffer for a posed shape (the free-pose search makes its own
    /// per thread with [`Nester::scratch_for`]).
    pub(super) scratch: SPolygon,
    /// The part `scratch` was cloned from (its surrogate and cached facts match).
    pub(super) scratch_part: usize,
    pub(super) sheets: Vec<Sheet>,
    /// Collision checks made so far (the unit of the effort budget).
    pub(super) checks: u64,
    /// Area of the largest part.
    largest_area: f64,
    /// Buffers of the overlap measure.
    pub(super) overlap: OverlapScratch,
    /// Collision checks the current phase may reach.
    pub(super) budget: u64,
    /// When the improvements started (both constructions' share one start), and how
    /// long they and the squeeze may run together.
    pub(super) started: Instant,
    pub(super) time_limit: Duration,
    /// Where to say how far this search has got, and which phase it is in.
    pub(super) progress: Option<(&'a NestProgress<'a>, usize)>,
    /// The budgeted phase's share of the progress display: thousandths before it and
    /// its own, from how many checks it spends from which.
    pub(super) budget_share: (u32, u32, u64, u64),
    /// Set when a trial move tried before this copy's succeeded: this copy stops.
    pub(super) given_up: Vec<Arc<AtomicBool>>,
}

/// The share of a search's progress display (thousandths) its construction takes, the
/// improvement the rest: about their shares of its time at the default effort.
const CONSTRUCTION_SHARE: u32 = 400;

/// Share of a posed shape's outline that has a placed part or the sheet's edge within
/// one grid cell outside it: probes one cell apart along every edge, one cell out,
/// looked up in the occupancy grid (coarse, but it only ranks free poses). jagua-rs
/// keeps every polygon counter-clockwise, mirrored poses included (it reverses their
/// corners), so the outside is always on the right of an edge.
fn contact_share(grid: &Grid, shape: &SPolygon) -> f32 {
    let v = shape.vertices();
    let n = v.len();
    let d = grid.cell();
    let (mut hits, mut total) = (0u32, 0u32);
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 {
            continue;
        }
        // The outward normal of a counter-clockwise loop is (dy, -dx).
        let (nx, ny) = (dy / len * d, -dx / len * d);
        let k = (len / d).ceil().max(1.0) as u32;
        for j in 0..k {
            let t = (j as f32 + 0.5) / k as f32;
            let (x, y) = (a.0 + t * dx + nx, a.1 + t * dy + ny);
            total += 1;
            hits += grid.blocked(x, y) as u32;
        }
    }
    if total == 0 {
        0.0
    } else {
        hits as f32 / total as f32
    }
}

/// Marks the cells under a placed part.
fn fill_grid(grid: &mut Grid, layout: &JLayout, key: PItemKey) {
    let shape = layout.placed_items()[key].shape();
    let points: Vec<(f32, f32)> = shape.vertices().iter().map(|p| (p.0, p.1)).collect();
    grid.fill_polygon(&points);
}

impl<'a> Nester<'a> {
    /// A search with no sheet open yet.
    pub(super) fn new(parts: &'a [Part], container: Container, options: &NestOptions) -> Self {
        let bounds = container.outer_cd().bbox();
        Nester {
            parts,
            container,
            bounds,
            rng: SplitMix64::new(options.seed),
            samples: 24 * options.effort.max(1) as usize,
            scratch: parts.first().map_or_else(
                || SPolygon::from(bounds),
                |p| p.item.shape_cd().as_ref().clone(),
            ),
            scratch_part: 0,
            sheets: Vec::new(),
            checks: 0,
            largest_area: parts.iter().map(|p| p.area).fold(0.0, f64::max),
            overlap: OverlapScratch::default(),
            budget: u64::MAX,
            started: Instant::now(),
            time_limit: options.time_limit.unwrap_or(Duration::MAX),
            progress: None,
            budget_share: (0, 0, 0, 1),
            given_up: Vec::new(),
        }
    }

    /// A copy of the search to try a move on: the same sheets, random stream, checks
    /// and budget, with buffers of its own.
    pub(super) fn trial(&self) -> Nester<'a> {
        Nester {
            parts: self.parts,
            container: self.container.clone(),
            bounds: self.bounds,
            rng: self.rng.clone(),
            samples: self.samples,
            scratch: self.scratch.clone(),
            scratch_part: self.scratch_part,
            sheets: self.sheets.clone(),
            checks: self.checks,
            largest_area: self.largest_area,
            overlap: OverlapScratch::default(),
            budget: self.budget,
            started: self.started,
            time_limit: self.time_limit,
            progress: self.progress,
            budget_share: self.budget_share,
            given_up: Vec::new(),
        }
    }

    /// Starts a phase that may spend `spend` more collision checks, worth `weight`
    /// thousandths of the progress display after `before`.
    pub(super) fn start_budget(&mut self, spend: u64, before: u32, weight: u32) {
        self.budget = self.checks.saturating_add(spend);
        self.budget_share = (before, weight, self.checks, spend);
    }

    /// Tells the progress display that the construction has placed `placed` parts.
    pub(super) fn report_construction(&self, placed: usize) {
        let of = self.parts.len() as u64;
        self.report(0, CONSTRUCTION_SHARE, placed as u64, of);
    }

    /// Tells the progress display that this search has done `done` of `of` parts of
    /// a phase worth `weight` thousandths, after `before` thousandths.
    pub(super) fn report(&self, before: u32, weight: u32, done: u64, of: u64) {
        if let Some((progress, search)) = self.progress {
            let share = (u64::from(weight) * done.min(of) / of.max(1)) as u32;
            progress.set(search, before + share);
        }
    }

    /// Opens an empty sheet.
    pub(super) fn open_sheet(&mut self) -> usize {
        let b = self.bounds;
        self.sheets.push(Sheet {
            layout: JLayout::new(self.container.clone()),
            grid: Grid::new(b.x_min, b.y_min, b.x_max, b.y_max, GRID_CELLS),
            parts: Vec::new(),
            area: 0.0,
            failures: 0,
        });
        self.sheets.len() - 1
    }

    /// Places a part in the first open sheet with room, or on a new sheet. `false`
    /// only when it does not fit an empty sheet.
    fn place_anywhere(&mut self, part: usize) -> bool {
        for s in 0..self.sheets.len() {
            if self.sheets[s].failures >= CLOSE_AFTER_FAILURES {
                continue;
            }
            if let Some(pose) = self.search(s, part, self.samples_for(part)) {
                self.put(s, part, pose);
                self.sheets[s].failures = 0;
                return true;
            }
            self.sheets[s].failures += 1;
        }
        let s = self.open_sheet();
        match self.search(s, part, self.samples.max(64)) {
            Some(pose) => {
                self.put(s, part, pose);
                true
            }
            None => {
                self.sheets.pop();
                false
            }
        }
    }

    /// Samples for a part: large parts shape a sheet more and are few, so they get
    /// up to four times as many.
    fn samples_for(&self, part: usize) -> usize {
        let ratio = self.parts[part].area / self.largest_area.max(f64::MIN_POSITIVE);
        (self.samples as f64 * (1.0 + 3.0 * ratio)) as usize
    }

    /// First-fit decreasing: parts largest first (ties by index), each into the first
    /// open sheet where the pose search finds room, or onto a new sheet. `Err(part)`
    /// names a part that fits no empty sheet.
    pub(super) fn construct_first_fit(&mut self) -> Result<(), usize> {
        let parts = self.parts;
        let mut order: Vec<usize> = (0..parts.len()).collect();
        order.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area).then(a.cmp(&b)));
        for (k, &p) in order.iter().enumerate() {
            if !self.place_anywhere(p) {
                return Err(p);
            }
            self.report_construction(k + 1);
        }
        Ok(())
    }

    /// Empties the emptiest sheet into the others while moves succeed, within
    /// `effort / 2` times the collision checks of the construction (bounded work,
    /// whatever the machine) and the time limit counted from `started`.
    pub(super) fn improve(&mut self, options: &NestOptions, started: Instant) {
        self.started = started;
        let spend = self.checks * u64::from(options.effort.max(1)) / 2;
        self.start_budget(spend, CONSTRUCTION_SHARE, 1000 - CONSTRUCTION_SHARE);
        let effort = options.effort.max(1) as usize;
        let mut stalled = 0;
        for _ in 0..40 * effort {
            if self.sheets.len() < 2 || self.out_of_budget() {
                break;
            }
            // Move what fits out of the emptiest sheet; when nothing does, make room
            // for its largest part on another sheet by ejecting the parts in one
            // window there.
            if self.empty_emptiest_sheet() || self.eject_and_insert() {
                stalled = 0;
            } else {
                stalled += 1;
                if stalled >= 4 * effort {
                    break;
                }
            }
        }
        self.report(0, 1000, 1, 1);
    }

    /// Fewer sheets, or as many with an emptier emptiest sheet (the objective).
    pub(super) fn better_than(&self, other: &Nester) -> bool {
        let least = |n: &Nester| {
            n.sheets
                .iter()
                .map(|s| s.area)
                .fold(f64::INFINITY, f64::min)
        };
        (self.sheets.len(), least(self)) < (other.sheets.len(), least(other))
    }

    pub(super) fn put(&mut self, s: usize, part: usize, c: Candidate) {
        let pose = self.pose(part, c);
        let sheet = &mut self.sheets[s];
        let key = sheet.layout.place_item(&self.parts[part].item, pose);
        sheet.parts.push((part, key, c));
        sheet.area += self.parts[part].area;
        fill_grid(&mut sheet.grid, &sheet.layout, key);
    }

    /// The sheet with the least part area (the later one on ties).
    pub(super) fn emptiest(&self) -> usize {
        (0..self.sheets.len())
            .min_by(|&a, &b| {
                self.sheets[a]
                    .area
                    .total_cmp(&self.sheets[b].area)
                    .then(b.cmp(&a))
            })
            .expect("at least one sheet")
    }

    /// Marks the grid of sheet `s` again from its parts.
    pub(super) fn refill_grid(&mut self, s: usize) {
        let sheet = &mut self.sheets[s];
        sheet.grid.clear();
        for &(_, key, _) in &sheet.parts {
            fill_grid(&mut sheet.grid, &sheet.layout, key);
        }
    }

    /// Takes parts (by slot) off sheet `s`, returning their part indices.
    pub(super) fn take_off(&mut self, s: usize, mut slots: Vec<usize>) -> Vec<usize> {
        slots.sort_unstable();
        let parts = self.parts;
        let sheet = &mut self.sheets[s];
        let mut taken = Vec::with_capacity(slots.len());
        for &slot in slots.iter().rev() {
            let (part, key, _) = sheet.parts.remove(slot);
            sheet.layout.remove_item(key);
            sheet.area -= parts[part].area;
            taken.push(part);
        }
        self.refill_grid(s);
        taken
    }

    /// A large-neighbourhood move: the largest part of the emptiest sheet goes onto
    /// another sheet after the parts in a window there (about its size, at a random
    /// place) are taken off; those then go back into any sheet but the emptiest. All
    /// or nothing: on any failure the sheets are restored.
    fn eject_and_insert(&mut self) -> bool {
        if self.sheets.len() < 2 {
            return false;
        }
        let target = self.emptiest();
        let parts = self.parts;
        let Some(slot) = (0..self.sheets[target].parts.len()).max_by(|&a, &b| {
            let (pa, pb) = (
                self.sheets[target].parts[a].0,
                self.sheets[target].parts[b].0,
            );
            parts[pa].area.total_cmp(&parts[pb].area).then(pb.cmp(&pa))
        }) else {
            return false;
        };
        let part = self.sheets[target].parts[slot].0;
        let mut host = self.rng.below(self.sheets.len() - 1);
        if host >= target {
            host += 1;
        }
        let reach = 0.75 * parts[part].item.shape_cd().diameter();
        let b = self.bounds;
        let cx = b.x_min + (b.x_max - b.x_min) * self.rng.unit() as f32;
        let cy = b.y_min + (b.y_max - b.y_min) * self.rng.unit() as f32;
        let window: Vec<usize> = self.sheets[host]
            .parts
            .iter()
            .enumerate()
            .filter(|(_, &(_, key, _))| {
                let bb = self.sheets[host].layout.placed_items()[key].shape().bbox();
                bb.x_max >= cx - reach
                    && bb.x_min <= cx + reach
                    && bb.y_max >= cy - reach
                    && bb.y_min <= cy + reach
            })
            .map(|(k, _)| k)
            .collect();
        let backup = self.sheets.clone();
        let mut ejected = self.take_off(host, window);
        let placed = match self.search(host, part, 4 * self.samples) {
            Some(pose) => {
                self.put(host, part, pose);
                true
            }
            None => false,
        };
        ejected.sort_by(|&a, &b| parts[b].area.total_cmp(&parts[a].area).then(a.cmp(&b)));
        let all_back = placed
            && ejected.iter().all(|&q| {
                (0..self.sheets.len()).filter(|&s| s != target).any(|s| {
                    match self.search(s, q, 2 * self.samples) {
                        Some(pose) => {
                            self.put(s, q, pose);
                            true
                        }
                        None => false,
                    }
                })
            });
        if !all_back {
            self.sheets = backup;
            return false;
        }
        self.take_off(target, vec![slot]);
        if self.sheets[target].parts.is_empty() {
            self.sheets.remove(target);
        }
        true
    }

    /// Moves parts out of the emptiest sheet into the others. `true` when at least
    /// one part moved.
    fn empty_emptiest_sheet(&mut self) -> bool {
        let target = self.emptiest();
        let mut on_target: Vec<usize> = (0..self.sheets[target].parts.len()).collect();
        let parts = self.parts;
        on_target.sort_by(|&a, &b| {
            let (pa, pb) = (
                self.sheets[target].parts[a].0,
                self.sheets[target].parts[b].0,
            );
            parts[pb].area.total_cmp(&parts[pa].area).then(pa.cmp(&pb))
        });
        let mut moved_slots = Vec::new();
        for slot in on_target {
            let part = self.sheets[target].parts[slot].0;
            for s in 0..self.sheets.len() {
                if s == target {
                    continue;
                }
                if let Some(pose) = self.search(s, part, 2 * self.samples) {
                    self.put(s, part, pose);
                    moved_slots.push(slot);
                    break;
                }
            }
        }
        if moved_slots.is_empty() {
            return false;
        }
        self.take_off(target, moved_slots);
        if self.sheets[target].parts.is_empty() {
            self.sheets.remove(target);
        }
        true
    }

    /// The best free pose of `part` on sheet `s`: `samples` random positions drawn
    /// from free cells, the best few refined by a local search.
    ///
    /// The positions are drawn in order from the one generator, then tested in
    /// parallel against the sheet (which does not change meanwhile), and the refined
    /// candidates are compared in order: the result and the checks counted do not
    /// depend on the thread count.
    pub(super) fn search(&mut self, s: usize, part: usize, samples: usize) -> Option<Candidate> {
        let parts = self.parts;
        let p = &parts[part];
        if p.item.shape_cd().area() > 1.05 * self.sheets[s].grid.free_area() {
            return None;
        }
        let mut drawn: Vec<Candidate> = Vec::with_capacity(samples);
        for _ in 0..samples {
            // Half the samples lie square to the part's axis.
            let o = if !p.square.is_empty() && self.rng.unit() < 0.5 {
                p.square[self.rng.below(p.square.len())]
            } else {
                self.rng.below(p.orientations.len())
            };
            let rng = &mut self.rng;
            let Some((px, py)) = self.sheets[s].grid.free_point(|| rng.unit(), 32) else {
                continue;
            };
            drawn.push(self.clamp(
                part,
                o,
                px - p.orientations[o].poi.0,
                py - p.orientations[o].poi.1,
            ));
        }
        // An empty sheet: also its bottom-left corner in each orientation.
        if self.sheets[s].parts.is_empty() {
            for o in 0..p.orientations.len() {
                drawn.push(self.clamp(part, o, f32::NEG_INFINITY, f32::NEG_INFINITY));
            }
        }
        self.checks += drawn.len() as u64;
        let this = &*self;
        let scores: Vec<Option<f32>> = drawn
            .par_iter()
            .with_min_len(SAMPLES_PER_TASK)
            .map_init(
                || this.scratch_for(part),
                |scratch, &c| this.score_if_free(s, part, c, scratch),
            )
            .collect();
        // The best few, earliest first on ties.
        let mut found: Vec<(f32, Candidate)> = Vec::with_capacity(REFINED + 1);
        for (&c, score) in drawn.iter().zip(scores) {
            if let Some(score) = score {
                found.push((score, c));
                found.sort_by(|a, b| a.0.total_cmp(&b.0));
                found.truncate(REFINED);
            }
        }
        let refined: Vec<(f32, Candidate, u64)> = found
            .par_iter()
            .with_min_len(1)
            .map(|&(score, c)| this.refine(s, part, score, c, &mut this.scratch_for(part)))
            .collect();
        let mut best: Option<(f32, Candidate)> = None;
        for (score, c, checks) in refined {
            self.checks += checks;
            if best.is_none_or(|(b, _)| score < b) {
                best = Some((score, c));
            }
        }
        best.map(|(_, c)| c)
    }

    /// A candidate in orientation `o` with its bounds moved inside the sheet.
    pub(super) fn clamp(&self, part: usize, o: usize, x: f32, y: f32) -> Candidate {
        let or = self.parts[part].orientations[o];
        let b = self.bounds;
        // A hair inside the sheet's bounds: a part touching the container's edge in
        // f32 counts as colliding with it.
        let gap = EDGE_GAP;
        Candidate {
            orientation: o,
            x: x.max(b.x_min - or.lo.0 + gap).min(b.x_max - or.hi.0 - gap),
            y: y.max(b.y_min - or.lo.1 + gap).min(b.y_max - or.hi.1 - gap),
        }
    }

    pub(super) fn pose(&self, part: usize, c: Candidate) -> DTransformation {
        let o = self.parts[part].orientations[c.orientation];
        DTransformation::new(o.rotation, (c.x, c.y)).with_reflection(o.mirrored)
    }

    /// Greedy local search from a free candidate: moves in eight directions and turns
    /// by one rotation step, keeping any change that lowers the score, halving the
    /// step when none does. Returns the score, the pose and the checks made.
    fn refine(
        &self,
        s: usize,
        part: usize,
        mut score: f32,
        mut c: Candidate,
        scratch: &mut SPolygon,
    ) -> (f32, Candidate, u64) {
        const D: f32 = std::f32::consts::FRAC_1_SQRT_2;
        const DIRECTIONS: [(f32, f32); 8] = [
            (0.0, -1.0),
            (-1.0, 0.0),
            (-D, -D),
            (D, -D),
            (-D, D),
            (1.0, 0.0),
            (0.0, 1.0),
            (D, D),
        ];
        let n_orient = self.parts[part].orientations.len();
        let mut step = 0.25 * self.parts[part].item.shape_cd().diameter();
        let mut checks = 0;
        while step > MIN_STEP {
            let mut improved = false;
            for (dx, dy) in DIRECTIONS {
                let next = self.clamp(part, c.orientation, c.x + dx * step, c.y + dy * step);
                checks += 1;
                if let Some(v) = self.score_if_free(s, part, next, scratch) {
                    if v < score - 1e-4 {
                        (score, c) = (v, next);
                        improved = true;
                    }
                }
            }
            if n_orient > 1 {
                for turn in [1, n_orient - 1] {
                    let o = (c.orientation + turn) % n_orient;
                    let next = self.clamp(part, o, c.x, c.y);
                    checks += 1;
                    if let Some(v) = self.score_if_free(s, part, next, scratch) {
                        if v < score - 1e-4 {
                            (score, c) = (v, next);
                            improved = true;
                        }
                    }
                }
            }
            if !improved {
                step *= 0.5;
            }
        }
        (score, c, checks)
    }

    /// A buffer for [`Self::score_if_free`]: `transform_from` needs one cloned from
    /// the same part (it keeps the buffer's surrogate layout and cached facts).
    pub(super) fn scratch_for(&self, part: usize) -> SPolygon {
        self.parts[part].item.shape_cd().as_ref().clone()
    }

    /// The placement score of a pose (bottom-left, less the contact bonus), or `None`
    /// when it collides. `scratch` must come from [`Self::scratch_for`] of the same
    /// part; the caller counts the check.
    fn score_if_free(
        &self,
        s: usize,
        part: usize,
        c: Candidate,
        scratch: &mut SPolygon,
    ) -> Option<f32> {
        if !self.is_free(s, part, c, scratch) {
            return None;
        }
        let bb = scratch.bbox();
        let contact = contact_share(&self.sheets[s].grid, scratch);
        Some(bb.y_max + LEFT_WEIGHT * bb.x_max - CONTACT_WEIGHT * contact * scratch.area().sqrt())
    }

    /// Whether a pose collides with nothing on sheet `s`; `scratch` (from
    /// [`Self::scratch_for`] of the same part) holds the posed shape when it is free.
    pub(super) fn is_free(
        &self,
        s: usize,
        part: usize,
        c: Candidate,
        scratch: &mut SPolygon,
    ) -> bool {
        let cde = self.sheets[s].layout.cde();
        let transform = self.pose(part, c).compose();
        let shape = self.parts[part].item.shape_cd();
        if cde.detect_surrogate_collision(shape.surrogate(), &transform, &NoFilter) {
            return false;
        }
        scratch.transform_from(shape, &transform);
        !cde.detect_poly_collision(scratch, &NoFilter)
    }

    /// Placements in part order; sheets fullest first (ties by the order they opened).
    pub(super) fn finish(self, n: usize, sheet: SheetSpec) -> Layout {
        let mut placements = vec![Placement::default(); n];
        for (s, on_sheet) in self.sheets.iter().enumerate() {
            for &(part, _, c) in &on_sheet.parts {
                let pose = self.pose(part, c);
                let (tx, ty) = pose.translation();
                let mut placement = Placement {
                    part,
                    sheet: s,
                    rotation: f64::from(pose.rotation()),
                    translation: DVec2::new(f64::from(tx), f64::from(ty)),
                    mirrored: pose.reflected,
                };
                // The collision shape was centred on `center`: shift it back.
                placement.translation -= placement.apply_direction(self.parts[part].center);
                placements[part] = placement;
            }
        }
        let mut layout = Layout {
            sheet,
            sheets: self.sheets.len(),
            placements,
        };
        let areas: Vec<f64> = self.parts.iter().map(|p| p.area).collect();
        layout.fullest_first(&areas);
        layout
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jagua_rs::geometry::primitives::Point;

    #[test]
    fn contact_share_counts_the_outline_near_parts_and_edges() {
        let mut grid = Grid::new(0.0, 0.0, 100.0, 100.0, 100);
        let square = |x: f32, y: f32, side: f32| {
            SPolygon::new(vec![
                Point(x, y),
                Point(x + side, y),
                Point(x + side, y + side),
                Point(x, y + side),
            ])
            .expect("a square")
        };
        // Alone in the middle: nothing near.
        assert_eq!(contact_share(&grid, &square(40.0, 40.0, 20.0)), 0.0);
        // In the corner: two of four sides on the sheet's edge.
        let corner = contact_share(&grid, &square(0.1, 0.1, 20.0));
        assert!((corner - 0.5).abs() < 0.01, "{corner}");
        // A placed part right of it covers a third side.
        let right: Vec<(f32, f32)> = square(20.3, 0.0, 30.0)
            .vertices()
            .iter()
            .map(|p| (p.0, p.1))
            .collect();
        grid.fill_polygon(&right);
        let hugged = contact_share(&grid, &square(0.1, 0.1, 20.0));
        assert!((hugged - 0.75).abs() < 0.01, "{hugged}");
        // A mirrored pose still probes outside: mirrored about y = 10.1 (the engine
        // reflects y, then translates), the corner square lands on itself and touches
        // the same edges and part.
        let reference = square(0.1, 0.1, 20.0);
        let mut mirrored = reference.clone();
        let mirror = DTransformation::new(0.0, (0.0, 20.2)).with_reflection(true);
        mirrored.transform_from(&reference, &mirror.compose());
        assert!(mirrored.vertices().iter().all(|p| p.1 > 0.0 && p.1 < 20.2));
        let share = contact_share(&grid, &mirrored);
        assert!((share - 0.75).abs() < 0.01, "{share}");
    }
}
