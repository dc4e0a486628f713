//! One part as the search sees it: its collision item (the outline grown by half the
//! spacing), the orientations it may take on the sheet, and the discs that measure its
//! overlap with others.
//!
//! Overlap between two parts is measured on discs inside their collision shapes (the
//! engine's poles and a lattice of inscribed discs), as sparrow does: for every pair of
//! discs, the penetration depth times the smaller radius, where a depth below a small
//! epsilon (1 % of the larger part's diameter) decays smoothly instead of dropping to
//! zero, so that two discs about to touch still count a little. The loss of a pair of
//! parts is the square root of π times that sum plus epsilon squared (so every
//! collision costs something, tab tips included), times the geometric mean of the
//! square roots of their convex hulls' areas (large parts left overlapping cost more).

use std::sync::Arc;

use glam::DVec2;
use jagua_rs::collision_detection::hazards::collector::BasicHazardCollector;
use jagua_rs::collision_detection::CDEConfig;
use jagua_rs::entities::{Container, Item};
use jagua_rs::geometry::fail_fast::SPSurrogateConfig;
use jagua_rs::geometry::geo_enums::RotationRange;
use jagua_rs::geometry::geo_traits::{CollidesWith, DistanceTo, Transformable, TransformableFrom};
use jagua_rs::geometry::primitives::{Circle, Point, Rect, SPolygon};
use jagua_rs::geometry::shape_modification::{ShapeModifyConfig, ShapeModifyMode};
use jagua_rs::geometry::{AllowedOrientations, DTransformation, OriginalShape, Transformation};
use rayon::prelude::*;

use super::options::NestOptions;
use crate::nest::layout::{SheetSpec, TooLarge};
use crate::plane::{bounds, convex_hull, grown_outline, is_clear};

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

/// One part as the search sees it.
pub(super) struct Part {
    pub(super) item: Arc<Item>,
    /// The outline point that the collision shape's origin corresponds to.
    pub(super) center: DVec2,
    /// Area of the outline (mm²), what the sheet fill counts.
    pub(super) area: f64,
    /// Allowed orientations with the collision shape's bounds at each (no translation).
    pub(super) orientations: Vec<Orientation>,
    /// Which of them lie square to the part's axis (quarter turns from it, either side).
    pub(super) square: Vec<usize>,
    /// Discs inside the collision shape that measure its overlap with others.
    discs: Vec<Circle>,
    /// What the overlap loss weighs the discs' overlap by.
    scale: LossScale,
}

#[derive(Clone, Copy)]
pub(super) struct Orientation {
    pub(super) rotation: f32,
    pub(super) mirrored: bool,
    pub(super) lo: Point,
    pub(super) hi: Point,
    /// The shape's pole of inaccessibility in this orientation: a point well inside
    /// it, put on a free cell when sampling.
    pub(super) poi: Point,
}

/// The collision container of a sheet and the collision items of the parts, or the
/// first part (in part order, whatever the thread count) too large for the sheet.
pub(super) fn prepare(
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
        discs: overlap_discs(item.shape_cd()),
        scale: LossScale {
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

pub(super) fn too_large(
    part: usize,
    outline: &[DVec2],
    sheet: SheetSpec,
    rotations: u32,
) -> TooLarge {
    let size = crate::plane::smallest_box(outline, rotations);
    TooLarge {
        part,
        width: size.x,
        height: size.y,
        usable_width: sheet.usable_width(),
        usable_height: sheet.usable_height(),
    }
}

/// Most lattice points of a part's bounds tried as disc centres.
const LATTICE_POINTS: usize = 400;

/// Discs kept per part (the largest).
const MAX_DISCS: usize = 32;

/// Epsilon of the overlap measure, as a share of the larger part's diameter.
const EPSILON_SHARE: f32 = 0.01;

/// Inscribed discs of a collision shape (in its own frame), largest first: the
/// engine's poles, then lattice points by decreasing clearance, each kept when no
/// kept disc holds its centre, so that long thin parts are covered end to end.
fn overlap_discs(shape: &SPolygon) -> Vec<Circle> {
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

/// Facts of a part that its overlap loss uses besides its discs.
#[derive(Clone, Copy, Debug)]
struct LossScale {
    /// Largest distance across the collision shape (mm).
    pub diameter: f32,
    /// Square root of the area of its convex hull (mm).
    pub hull_root: f32,
}

/// Overlap loss of two posed parts (their discs and scales): see the module
/// documentation. Every pair of discs counts, however far apart: the decayed terms of
/// discs that are close but apart are what tells two parts that only touch at their
/// outlines how to move apart.
fn pair_loss(a: &[Circle], b: &[Circle], sa: LossScale, sb: LossScale) -> f32 {
    let eps = EPSILON_SHARE * sa.diameter.max(sb.diameter);
    let mut total = 0.0;
    for p in a {
        for q in b {
            let depth = p.radius + q.radius - p.center.distance_to(&q.center);
            let decayed = if depth >= eps {
                depth
            } else {
                eps * eps / (2.0 * eps - depth)
            };
            total += decayed * p.radius.min(q.radius);
        }
    }
    (std::f32::consts::PI * total + eps * eps).sqrt() * (sa.hull_root * sb.hull_root).sqrt()
}

/// Buffers of the overlap measure.
#[derive(Default)]
pub(super) struct OverlapScratch {
    pub(super) collector: BasicHazardCollector,
    pub(super) discs: PosedDiscs,
}

/// The discs of the part being evaluated and of one it collides with, posed.
#[derive(Default)]
pub(super) struct PosedDiscs {
    mine: Vec<Circle>,
    theirs: Vec<Circle>,
}

impl PosedDiscs {
    /// Poses the discs of `part` (the one evaluated) by `transform`.
    pub(super) fn pose_mine(&mut self, parts: &[Part], part: usize, transform: &Transformation) {
        pose_discs(&parts[part].discs, transform, &mut self.mine);
    }

    /// Overlap loss of `part`, whose discs [`PosedDiscs::pose_mine`] posed, with
    /// `other` placed at `placed`; adds the disc pairs weighed to `disc_pairs`.
    pub(super) fn loss_with(
        &mut self,
        parts: &[Part],
        part: usize,
        other: usize,
        placed: &DTransformation,
        disc_pairs: &mut usize,
    ) -> f32 {
        pose_discs(&parts[other].discs, &placed.compose(), &mut self.theirs);
        *disc_pairs += self.mine.len() * self.theirs.len();
        pair_loss(
            &self.mine,
            &self.theirs,
            parts[part].scale,
            parts[other].scale,
        )
    }
}

fn pose_discs(discs: &[Circle], transform: &Transformation, out: &mut Vec<Circle>) {
    out.clear();
    out.extend(discs.iter().map(|d| d.transform_clone(transform)));
}

#[cfg(test)]
mod tests {
    use super::super::options::test_options as options;
    use super::*;
    use crate::nest::test_rectangle as rectangle;

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
        let scale = LossScale {
            diameter: 28.0,
            hull_root: 20.0,
        };
        let a = square(0.0);
        let mut last = f32::INFINITY;
        // Overlapping, then apart: the loss keeps shrinking, so a part that only
        // touches its neighbour still knows which way is out.
        for step in 0..30 {
            let loss = pair_loss(&a, &square(2.0 * step as f32), scale, scale);
            assert!(loss < last, "not shrinking at step {step}: {loss}");
            last = loss;
        }
        // Never below the floor of epsilon (0.28 mm) times the hull factor.
        assert!(last > 0.28 * 20.0, "{last}");
        // Symmetric, so a pair's overlap does not depend on which part was moved.
        let b = square(7.0);
        assert_eq!(
            pair_loss(&a, &b, scale, scale),
            pair_loss(&b, &a, scale, scale)
        );
    }

    #[test]
    fn square_orientations_are_the_quarter_turns_of_each_side() {
        let options = |rotations, mirror| NestOptions {
            rotations,
            mirror,
            ..options()
        };
        let sheet = SheetSpec {
            width: 600.0,
            height: 300.0,
            margin: 5.0,
            spacing: 2.0,
        };
        let bar = rectangle(40.0, 10.0);
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
