//! True-shape nesting: parts are placed by their real outlines (tabs and flaps
//! included), so small parts fill the gaps and concavities of large ones.
//!
//! Collision detection is jagua-rs (every part inflated by half the spacing, the sheet
//! grown by the same amount); the search is ours:
//! 1. constructive, twice, side by side: in rows (`rows`: parts lie flat, tallest
//!    first, each dropped at the end of the current row and slid down and left until
//!    it rests, the next part chosen among the next few by how little of the row it
//!    claims, so slanted ends interlock), and first-fit decreasing (parts largest
//!    first, each into the first sheet where a sampled, then slid, bottom-left
//!    position is free, poses that touch their neighbours scoring better
//!    (`CONTACT_WEIGHT`));
//! 2. improvement, of each construction: the emptiest sheet is emptied into the
//!    others, part by part, by the sampled pose search; a sheet left empty is dropped.
//!    Partial moves are kept: they only make the emptiest sheet emptier (the second
//!    objective). The better of the two layouts goes on;
//! 3. squeezing by overlap minimisation (`separate`): the emptiest sheet's parts,
//!    largest first, go one at a time to where they overlap least on one of the
//!    emptiest other sheets, which is then separated by a guided local search; a part
//!    stays only when that succeeds, and the squeeze stops at the first part that
//!    finds no room. A sheet left empty is dropped.
//!
//! Every random choice comes from a generator seeded by `seed` (one per construction
//! and what follows it), and the effort is a
//! number of samples and rounds, so the result depends on the input and the options
//! only. The sampled poses of a search are drawn in order and then tested in
//! parallel against a sheet that does not change meanwhile, and compared in order,
//! so the thread count changes the speed, never the result. `time_limit` is an
//! optional cap on the improvement and the squeeze, and the only source of
//! run-to-run differences when it is hit.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::DVec2;
use jagua_rs::collision_detection::hazards::filter::NoFilter;
use jagua_rs::collision_detection::CDEConfig;
use jagua_rs::entities::{Container, Item, Layout as JLayout, PItemKey};
use jagua_rs::geometry::fail_fast::SPSurrogateConfig;
use jagua_rs::geometry::geo_enums::RotationRange;
use jagua_rs::geometry::geo_traits::TransformableFrom;
use jagua_rs::geometry::primitives::{Circle, Point, Rect, SPolygon};
use jagua_rs::geometry::shape_modification::{ShapeModifyConfig, ShapeModifyMode};
use jagua_rs::geometry::{AllowedOrientations, DTransformation, OriginalShape};
use rayon::prelude::*;

mod rows;
mod separate;

use super::grid::Grid;
use super::{Layout, NestProgress, Placement, SheetSpec, TooLarge};
use crate::plane::{bounds, convex_hull, grown_outline, is_clear};
use crate::rng::SplitMix64;

/// Search settings of the true-shape nester.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NestOptions {
    /// Rotation steps per turn (at least 1).
    pub rotations: u32,
    /// Also try every part mirrored.
    pub mirror: bool,
    /// Search effort (1 = quick); samples and rounds grow linearly with it.
    pub effort: u32,
    /// Seed of the search.
    pub seed: u64,
    /// Optional wall-clock cap on the improvement and squeeze phases.
    pub time_limit: Option<Duration>,
}

/// Extra inflation (mm) on top of half the spacing: covers the f32 arithmetic of the
/// collision engine and the chords of its round offset joins.
const SAFETY: f64 = 0.02;

/// Largest share of area the collision engine may add to a part's collision shape when
/// it drops corners (the shape only grows, so the spacing holds): 0.1 % removes most
/// corners of the round offset joins and the Bézier rails, which cost collision time,
/// without costing a sheet.
const SIMPLIFY: f32 = 0.001;

/// Edges of a part's collision shape that do not share a corner keep at least this far
/// apart (mm), and so do a corner's edges' far ends: f32 rounding of coordinates up to
/// a few metres moves a corner by less than a tenth of it.
const CLEARANCE: f64 = 1e-3;

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
const EDGE_GAP: f32 = 0.01;

/// Consecutive parts that may fail on a sheet before the constructive phase stops
/// trying it.
const CLOSE_AFTER_FAILURES: u32 = 40;

/// Collision checks the squeeze may spend per unit of effort (an evaluation of a
/// pose's overlap counts as several: see `separate`): at the default effort, what a
/// job of about a thousand parts needs to take a last sheet of a few parts away.
const SQUEEZE_CHECKS: u64 = 5_000_000;

/// Parts the emptiest sheet may hold, per unit of effort, for the squeeze to try it:
/// squeezing one part into a full sheet costs about a second of separation, so the
/// squeeze pays where the last sheet holds a few parts, not hundreds.
const SQUEEZE_PARTS: usize = 2;

/// Separation rounds per squeezed part and sheet tried, per unit of effort.
const SEPARATION_ROUNDS: usize = 100;

/// Cells of the occupancy grid along the longer side of a sheet.
const GRID_CELLS: usize = 200;

/// One part as the search sees it.
struct Part {
    item: Arc<Item>,
    /// The outline point that the collision shape's origin corresponds to.
    center: DVec2,
    /// Area of the outline (mm²), what the sheet fill counts.
    area: f64,
    /// Allowed orientations with the collision shape's bounds at each (no translation).
    orientations: Vec<Orientation>,
    /// Which of them lie square to the part's axis (quarter turns from it, either side).
    square: Vec<usize>,
    /// Discs inside the collision shape that measure its overlap with others.
    discs: Vec<Circle>,
    /// What the overlap loss weighs the discs' overlap by.
    scale: separate::LossScale,
}

#[derive(Clone, Copy)]
struct Orientation {
    rotation: f32,
    mirrored: bool,
    lo: Point,
    hi: Point,
    /// The shape's pole of inaccessibility in this orientation: a point well inside
    /// it, put on a free cell when sampling.
    poi: Point,
}

/// A pose under search: orientation index and translation.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    orientation: usize,
    x: f32,
    y: f32,
}

/// How many of the best samples get the local search: six packs tighter than fewer,
/// and more cost about a third more time for little.
const REFINED: usize = 6;

/// Fewest samples one parallel task tests (fewer would cost more to hand out).
const SAMPLES_PER_TASK: usize = 16;

/// Smallest step of the local search (mm).
const MIN_STEP: f32 = 0.05;

/// One sheet being filled.
#[derive(Clone)]
struct Sheet {
    layout: JLayout,
    /// Cells covered by the placed parts.
    grid: Grid,
    /// (part, key in the layout, pose).
    parts: Vec<(usize, PItemKey, Candidate)>,
    area: f64,
    failures: u32,
}

/// The search state: parts, open sheets and scratch space.
struct Nester<'a> {
    parts: &'a [Part],
    container: Container,
    bounds: Rect,
    rng: SplitMix64,
    samples: usize,
    /// The separator's buffer for a posed shape (the free-pose search makes its own
    /// per thread with [`Nester::scratch_for`]).
    scratch: SPolygon,
    /// The part `scratch` was cloned from (its surrogate and cached facts match).
    scratch_part: usize,
    sheets: Vec<Sheet>,
    /// Collision checks made so far (the unit of the effort budget).
    checks: u64,
    /// Area of the largest part.
    largest_area: f64,
    /// Buffers of the overlap measure.
    overlap: separate::OverlapScratch,
    /// Collision checks the current phase may reach.
    budget: u64,
    /// When the improvements started (both constructions' share one start), and how
    /// long they and the squeeze may run together.
    started: Instant,
    time_limit: Duration,
    /// Where to say how far this search has got, and which phase it is in.
    progress: Option<(&'a NestProgress<'a>, usize)>,
    /// The budgeted phase's share of the progress display: thousandths before it and
    /// its own, from how many checks it spends from which.
    budget_share: (u32, u32, u64, u64),
    /// Set when a trial move tried before this copy's succeeded: this copy stops.
    given_up: Vec<Arc<AtomicBool>>,
}

/// The share of a search's progress display (thousandths) its construction takes, the
/// improvement the rest: about their shares of its time at the default effort.
const CONSTRUCTION_SHARE: u32 = 400;

/// The sheets of the kept search after each phase: what moving parts and squeezing
/// saved, for the manifest and the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PhaseSheets {
    /// After its construction.
    pub placed: usize,
    /// After the moves that empty the emptiest sheet.
    pub moved: usize,
    /// After the squeeze (the search's result).
    pub squeezed: usize,
}

/// Lays out parts (outer outlines in mm) by their true shapes.
pub fn true_shape_layout(
    outlines: &[Vec<DVec2>],
    sheet: SheetSpec,
    options: &NestOptions,
) -> Result<Layout, TooLarge> {
    true_shape_layout_observed(outlines, sheet, options, &NestProgress::new(&|_| {}))
        .map(|(layout, _)| layout)
}

/// [`true_shape_layout`], telling `progress` how far each search has got, with the
/// sheets after each phase.
pub fn true_shape_layout_observed(
    outlines: &[Vec<DVec2>],
    sheet: SheetSpec,
    options: &NestOptions,
    progress: &NestProgress,
) -> Result<(Layout, PhaseSheets), TooLarge> {
    let (parts, container) = prepare(outlines, sheet, options)?;
    // Two constructions, each improved on its own, and the better kept: rows of
    // interlocking parts win on alike parts and long strips, first-fit decreasing on
    // short wavy strips (docs/nesting.md has the measured cases). Each has its own
    // generator from the same seed, so the result does not depend on which finishes
    // first.
    //
    // One clock, started before the constructions (which always finish), for both
    // improvements and the squeeze: `time_limit` caps them together, on one thread
    // (where the two improvements run one after the other) as on two.
    let started = Instant::now();
    let built = |in_rows: bool| -> Result<(Nester, usize), usize> {
        let mut nester = Nester::new(&parts, container.clone(), options);
        nester.progress = Some((progress, usize::from(in_rows)));
        if in_rows {
            nester.construct_in_rows()?;
        } else {
            nester.construct_first_fit()?;
        }
        let placed = nester.sheets.len();
        nester.improve(options, started);
        Ok((nester, placed))
    };
    let (first_fit, rows) = rayon::join(|| built(false), || built(true));
    let too_large_part = |p: usize| too_large(p, &outlines[p], sheet, options.rotations);
    let (first_fit, rows) = (
        first_fit.map_err(too_large_part)?,
        rows.map_err(too_large_part)?,
    );
    let (mut nester, placed) = if rows.0.better_than(&first_fit.0) {
        rows
    } else {
        first_fit
    };
    let moved = nester.sheets.len();
    let effort = options.effort.max(1) as usize;

    // Then squeeze the emptiest sheet's parts into the others by overlap
    // minimisation, with an allowance of its own: unlike the improvement's, it does
    // not grow with the number of parts, because the squeeze only ever moves one
    // sheet's parts (the sheets it separates are full ones, though, and there an
    // evaluation costs up to twice what it counts).
    // A sheet of more parts is not tried: each part squeezed into a full sheet sets
    // off a cascade of moves there, and a hundred parts would take minutes.
    nester.progress = Some((progress, 2));
    nester.start_budget(SQUEEZE_CHECKS * u64::from(options.effort.max(1)), 0, 1000);
    while nester.sheets.len() >= 2
        && !nester.out_of_budget()
        && nester.sheets[nester.emptiest()].parts.len() <= SQUEEZE_PARTS * effort
        && nester.squeeze_emptiest(SEPARATION_ROUNDS * effort)
    {}
    nester.report(0, 1000, 1, 1);

    let phases = PhaseSheets {
        placed,
        moved,
        squeezed: nester.sheets.len(),
    };
    Ok((nester.finish(outlines.len(), sheet), phases))
}

/// The collision container of a sheet and the collision items of the parts, or the
/// first part (in part order, whatever the thread count) too large for the sheet.
fn prepare(
    outlines: &[Vec<DVec2>],
    sheet: SheetSpec,
    options: &NestOptions,
) -> Result<(Vec<Part>, Container), TooLarge> {
    let cde_config = CDEConfig {
        // Only the speed depends on the depth, never a collision's answer. Measured
        // (2 cores, same layouts): spot half-edge nests in 5.9 s at depth 3 and 4,
        // 8.6-11.4 s at 6, 13-14 s at 7-8; depth 2 is no faster than 3. Sheets hold
        // tens to hundreds of parts, so deep trees mostly add nodes to walk.
        quadtree_depth: 3,
        cd_threshold: 16,
        item_surrogate_config: SPSurrogateConfig {
            n_pole_limits: [(6, 0.0), (4, 0.8), (2, 0.9)],
            ff_pole_area_ratio: 0.05,
            n_ff_piers: 0,
        },
    };
    let half_gap = 0.5 * sheet.spacing.max(0.0);
    // The sheet is grown by half the spacing, the parts by half the spacing plus the
    // safety, so a part's true outline stays inside the margin and two outlines stay
    // the spacing apart.
    let container = {
        let (x0, y0) = (sheet.margin - half_gap, sheet.margin - half_gap);
        let (x1, y1) = (
            sheet.width - sheet.margin + half_gap,
            sheet.height - sheet.margin + half_gap,
        );
        let rect = Rect::try_new(x0 as f32, y0 as f32, x1 as f32, y1 as f32)
            .expect("the usable area of a validated sheet is not empty");
        let shape = OriginalShape {
            shape: SPolygon::from(rect),
            pre_transform: DTransformation::empty(),
            modify_mode: ShapeModifyMode::Deflate,
            modify_config: ShapeModifyConfig {
                offset: None,
                simplify_tolerance: None,
                narrow_concavity_cutoff: None,
            },
        };
        Container::new(shape, vec![], cde_config).expect("a rectangle is a valid container")
    };
    let bounds_rect = container.outer_cd().bbox();
    let parts = outlines
        .par_iter()
        .enumerate()
        .map(|(i, outline)| {
            crate::internal::for_panel(i, || {
                prepare_part(
                    i,
                    outline,
                    half_gap + SAFETY,
                    options,
                    &cde_config,
                    bounds_rect,
                )
            })
            .ok_or_else(|| too_large(i, outline, sheet, options.rotations))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<_, _>>()?;
    Ok((parts, container))
}

/// The collision item of a part, or `None` when no allowed orientation fits the sheet.
fn prepare_part(
    index: usize,
    outline: &[DVec2],
    inflate: f64,
    options: &NestOptions,
    cde_config: &CDEConfig,
    sheet_bounds: Rect,
) -> Option<Part> {
    let (lo, hi) = bounds(outline.iter().copied());
    let center = 0.5 * (lo + hi);
    // The grown outline is clear of itself by far more than f32 rounding moves a
    // corner, so the engine's own checks and simplification see a simple polygon;
    // where the engine still refuses it, the grown convex hull only covers more.
    let grown: Vec<DVec2> = grown_outline(outline, inflate, CLEARANCE)
        .into_iter()
        .map(|p| p - center)
        .collect();
    let item = make_item(index, &grown, options, cde_config)
        .or_else(|| {
            let hull = grown_outline(&convex_hull(&grown), 0.0, CLEARANCE);
            make_item(index, &hull, options, cde_config)
        })
        .or_else(|| {
            // A box round it: four corners far apart, whatever the outline.
            let (lo, hi) = bounds(grown.iter().copied());
            let (lo, hi) = (lo - DVec2::splat(CLEARANCE), hi + DVec2::splat(CLEARANCE));
            let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
            make_item(index, &corners, options, cde_config)
        })?;
    let shape = item.shape_cd().as_ref().clone();
    let mut turned = shape.clone();
    let steps = options.rotations.max(1);
    // Steps are counted from the part's own axis (its smallest bounding rectangle laid
    // flat): the flattened frame means nothing, and straight sides along the sheet's
    // axes pack in rows.
    let axis = crate::plane::smallest_box_rotation(outline);
    let mut orientations = Vec::new();
    let mut square = Vec::new();
    for mirrored in [false, true] {
        if mirrored && !options.mirror {
            continue;
        }
        for k in 0..steps {
            let rotation = (axis + std::f64::consts::TAU * f64::from(k) / f64::from(steps))
                .rem_euclid(std::f64::consts::TAU) as f32;
            let pose = DTransformation::new(rotation, (0.0, 0.0)).with_reflection(mirrored);
            turned.transform_from(&shape, &pose.compose());
            let bb = turned.bbox();
            let fits = bb.x_max - bb.x_min <= sheet_bounds.x_max - sheet_bounds.x_min
                && bb.y_max - bb.y_min <= sheet_bounds.y_max - sheet_bounds.y_min;
            if fits {
                if (4 * k).is_multiple_of(steps) {
                    square.push(orientations.len());
                }
                orientations.push(Orientation {
                    rotation,
                    mirrored,
                    lo: Point(bb.x_min, bb.y_min),
                    hi: Point(bb.x_max, bb.y_max),
                    poi: turned.poi().center,
                });
            }
        }
    }
    if orientations.is_empty() {
        return None;
    }
    Some(Part {
        discs: separate::overlap_discs(item.shape_cd()),
        scale: separate::LossScale {
            diameter: item.shape_cd().diameter(),
            hull_root: item.shape_cd().surrogate().convex_hull_area.sqrt(),
        },
        item,
        center,
        area: crate::plane::area(outline),
        orientations,
        square,
    })
}

/// The jagua-rs item of an outline already grown and centred, or `None` when it is not
/// clear of itself in f32 (the engine's simplification would then panic).
fn make_item(
    index: usize,
    outline: &[DVec2],
    options: &NestOptions,
    cde_config: &CDEConfig,
) -> Option<Arc<Item>> {
    let points: Vec<Point> = outline
        .iter()
        .map(|p| Point(p.x as f32, p.y as f32))
        .collect();
    let rounded: Vec<DVec2> = points
        .iter()
        .map(|p| DVec2::new(f64::from(p.0), f64::from(p.1)))
        .collect();
    if !is_clear(&rounded, 0.5 * CLEARANCE) {
        return None;
    }
    let shape = SPolygon::new(points).ok()?;
    let original = OriginalShape {
        shape,
        pre_transform: DTransformation::empty(),
        modify_mode: ShapeModifyMode::Inflate,
        modify_config: ShapeModifyConfig {
            offset: None,
            simplify_tolerance: Some(SIMPLIFY),
            narrow_concavity_cutoff: None,
        },
    };
    let reflections = if options.mirror { vec![0.0] } else { vec![] };
    let orientations = AllowedOrientations::new(RotationRange::Continuous, reflections).ok()?;
    Item::new(
        index,
        index as u64,
        original,
        orientations,
        None,
        cde_config.item_surrogate_config,
    )
    .ok()
    .map(Arc::new)
}

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

fn too_large(part: usize, outline: &[DVec2], sheet: SheetSpec, rotations: u32) -> TooLarge {
    let size = crate::plane::smallest_box(outline, rotations);
    TooLarge {
        part,
        width: size.x,
        height: size.y,
        usable_width: sheet.usable_width(),
        usable_height: sheet.usable_height(),
    }
}

impl<'a> Nester<'a> {
    /// A search with no sheet open yet.
    fn new(parts: &'a [Part], container: Container, options: &NestOptions) -> Self {
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
            overlap: separate::OverlapScratch::default(),
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
    fn trial(&self) -> Nester<'a> {
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
            overlap: separate::OverlapScratch::default(),
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
    fn start_budget(&mut self, spend: u64, before: u32, weight: u32) {
        self.budget = self.checks.saturating_add(spend);
        self.budget_share = (before, weight, self.checks, spend);
    }

    /// Tells the progress display that the construction has placed `placed` parts.
    fn report_construction(&self, placed: usize) {
        let of = self.parts.len() as u64;
        self.report(0, CONSTRUCTION_SHARE, placed as u64, of);
    }

    /// Tells the progress display that this search has done `done` of `of` parts of
    /// a phase worth `weight` thousandths, after `before` thousandths.
    fn report(&self, before: u32, weight: u32, done: u64, of: u64) {
        if let Some((progress, search)) = self.progress {
            let share = (u64::from(weight) * done.min(of) / of.max(1)) as u32;
            progress.set(search, before + share);
        }
    }

    /// Opens an empty sheet.
    fn open_sheet(&mut self) -> usize {
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
    fn construct_first_fit(&mut self) -> Result<(), usize> {
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
    fn improve(&mut self, options: &NestOptions, started: Instant) {
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
    fn better_than(&self, other: &Nester) -> bool {
        let least = |n: &Nester| {
            n.sheets
                .iter()
                .map(|s| s.area)
                .fold(f64::INFINITY, f64::min)
        };
        (self.sheets.len(), least(self)) < (other.sheets.len(), least(other))
    }

    fn put(&mut self, s: usize, part: usize, c: Candidate) {
        let pose = self.pose(part, c);
        let sheet = &mut self.sheets[s];
        let key = sheet.layout.place_item(&self.parts[part].item, pose);
        sheet.parts.push((part, key, c));
        sheet.area += self.parts[part].area;
        fill_grid(&mut sheet.grid, &sheet.layout, key);
    }

    /// The sheet with the least part area (the later one on ties).
    fn emptiest(&self) -> usize {
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
    fn refill_grid(&mut self, s: usize) {
        let sheet = &mut self.sheets[s];
        sheet.grid.clear();
        for &(_, key, _) in &sheet.parts {
            fill_grid(&mut sheet.grid, &sheet.layout, key);
        }
    }

    /// Takes parts (by slot) off sheet `s`, returning their part indices.
    fn take_off(&mut self, s: usize, mut slots: Vec<usize>) -> Vec<usize> {
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
    fn search(&mut self, s: usize, part: usize, samples: usize) -> Option<Candidate> {
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
    fn clamp(&self, part: usize, o: usize, x: f32, y: f32) -> Candidate {
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

    fn pose(&self, part: usize, c: Candidate) -> DTransformation {
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
    fn scratch_for(&self, part: usize) -> SPolygon {
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
    fn is_free(&self, s: usize, part: usize, c: Candidate, scratch: &mut SPolygon) -> bool {
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
    fn finish(self, n: usize, sheet: SheetSpec) -> Layout {
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

    /// The rotation of each square orientation, relative to the first, in quarter turns
    /// (and whether it is mirrored).
    fn square_turns(
        outline: &[DVec2],
        sheet: SheetSpec,
        options: &NestOptions,
    ) -> Vec<(i64, bool)> {
        let (parts, _) = prepare(&[outline.to_vec()], sheet, options).expect("fits");
        let part = &parts[0];
        let first = part.orientations[0].rotation as f64;
        part.square
            .iter()
            .map(|&o| {
                let or = part.orientations[o];
                let turn = (or.rotation as f64 - first).rem_euclid(std::f64::consts::TAU);
                let quarters = turn / std::f64::consts::FRAC_PI_2;
                assert!((quarters - quarters.round()).abs() < 1e-5, "{quarters}");
                ((quarters.round() as i64) % 4, or.mirrored)
            })
            .collect()
    }

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

    #[test]
    fn square_orientations_are_the_quarter_turns_of_each_side() {
        let options = |rotations, mirror| NestOptions {
            rotations,
            mirror,
            effort: 1,
            seed: 0,
            time_limit: None,
        };
        let sheet = SheetSpec {
            width: 600.0,
            height: 300.0,
            margin: 5.0,
            spacing: 2.0,
        };
        let bar = super::super::test_rectangle(40.0, 10.0);
        let all = |mirrored| (0..4).map(move |q| (q, mirrored));
        assert_eq!(
            square_turns(&bar, sheet, &options(32, false)),
            all(false).collect::<Vec<_>>()
        );
        // Mirrored orientations follow the plain ones: their quarter turns too, not the
        // 0 and 180 degrees of each side that every n/4-th index would give.
        let both: Vec<_> = all(false).chain(all(true)).collect();
        assert_eq!(square_turns(&bar, sheet, &options(32, true)), both);
        // Six steps: only 0 and 180 degrees are quarter turns.
        assert_eq!(
            square_turns(&bar, sheet, &options(6, false)),
            [(0, false), (2, false)]
        );
        // A bar longer than the sheet is tall (440 mm on 300): upright and steep
        // orientations are dropped, and the square ones are still the lying ones.
        let long: Vec<DVec2> = bar.iter().map(|p| DVec2::new(p.x * 11.0, p.y)).collect();
        assert_eq!(
            square_turns(&long, sheet, &options(32, false)),
            [(0, false), (2, false)]
        );
    }
}
