//! Distances between sets of triangles, measured at samples, and bounds of them that
//! hold at every point: how far the strips stray from the model, and it from them.

use glam::DVec3;

use crate::mesh::distance::TriangleGrid;

/// The largest distance from `from` to `to` (triangle sets), measured at points
/// spread over `from`'s triangles no further than `spacing` apart.
pub(super) fn one_way_distance(from: &[[DVec3; 3]], to: &[[DVec3; 3]], spacing: f64) -> f64 {
    let grid = TriangleGrid::new(to);
    let mut hint = usize::MAX;
    from.iter().fold(0.0, |worst, t| {
        let k = subdivisions(longest_side(t), spacing);
        sampled_worst(&grid, t, k, worst, &mut hint)
    })
}

/// Samples along a side at the finest, where a triangle's samples leave open whether
/// it is within.
const FINEST_SUBDIVISIONS: usize = 256;

/// A bound of the largest distance from `from` to `to` that holds at every point:
/// the largest distance measured at samples no further than `spacing` apart, plus
/// how far a point can lie from its nearest sample. A triangle whose samples leave
/// open whether it is `within` is sampled finer; once the bound passes `limit`, some
/// bound beyond it.
pub(super) fn distance_beyond(
    from: &[[DVec3; 3]],
    to: &[[DVec3; 3]],
    spacing: f64,
    within: f64,
    limit: f64,
) -> f64 {
    let grid = TriangleGrid::new(to);
    let mut bound: f64 = 0.0;
    // Neighbouring triangles of `from` mostly lie near the same triangle of `to`.
    let mut hint = usize::MAX;
    for t in from {
        let longest = longest_side(t);
        let mut k = subdivisions(longest, spacing);
        loop {
            // Every point of a triangle lies within its longest side over √3 of a
            // corner, and each sample triangle is this one shrunk k times.
            let reach = longest / k as f64 / 3f64.sqrt();
            let worst = sampled_worst(&grid, t, k, (bound - reach).max(0.0), &mut hint);
            let settled = worst + reach <= within || worst > within;
            if settled || k >= FINEST_SUBDIVISIONS {
                bound = bound.max(worst + reach);
                break;
            }
            k = (2 * k).min(FINEST_SUBDIVISIONS);
        }
        if bound > limit {
            break;
        }
    }
    bound
}

/// The longest side of triangle `t`.
fn longest_side(t: &[DVec3; 3]) -> f64 {
    [
        t[0].distance(t[1]),
        t[1].distance(t[2]),
        t[2].distance(t[0]),
    ]
    .into_iter()
    .fold(0.0, f64::max)
}

/// Samples along a side that put neighbouring samples no further than `spacing` apart
/// (at most 64).
fn subdivisions(longest: f64, spacing: f64) -> usize {
    ((longest / spacing.max(1e-12)).ceil() as usize).clamp(1, 64)
}

/// The largest of `floor` and the distances to `grid`'s triangles from the points
/// that divide `t`'s sides into `k`. Each point tries triangle `hint` first, and
/// leaves there the last found within the worst: neighbouring points mostly have the
/// same one within reach.
fn sampled_worst(
    grid: &TriangleGrid,
    t: &[DVec3; 3],
    k: usize,
    floor: f64,
    hint: &mut usize,
) -> f64 {
    let mut worst = floor;
    for i in 0..=k {
        for j in 0..=k - i {
            let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
            let point = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
            // A point with a triangle no further than the worst so far cannot raise
            // it: only the others are measured to their nearest.
            if !grid.reaches_near(point, worst, hint) {
                worst = worst.max(grid.distance(point));
            }
        }
    }
    worst
}

/// True when triangle `t` has an area above rounding noise (its height more than a
/// billionth of its longest side).
pub(super) fn has_area(t: [DVec3; 3]) -> bool {
    let twice_area = (t[1] - t[0]).cross(t[2] - t[0]).length();
    let longest = longest_side(&t);
    twice_area > 2e-9 * longest * longest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_measured_bound_holds_between_the_samples_and_is_sampled_finer_to_tell() {
        // An equilateral triangle whose corners touch three small triangles: the
        // farthest point from them is its centre, L/√3 away, which samples 10 to a
        // side miss.
        let side = 100.0;
        let corners = [
            DVec3::ZERO,
            DVec3::new(side, 0.0, 0.0),
            DVec3::new(0.5 * side, 0.5 * 3f64.sqrt() * side, 0.0),
        ];
        // Each speck points away from the centre, so its nearest point to it is the corner.
        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        let speck = |c: DVec3| {
            let out = (c - centre).normalize();
            [c, c + 5.0 * out + DVec3::Z, c + 5.0 * out - DVec3::Z]
        };
        let specks = corners.map(speck).to_vec();
        let farthest = side / 3f64.sqrt();
        let spacing = side / 10.0;
        let sampled = one_way_distance(&[corners], &specks, spacing);
        assert!(sampled < farthest - 1.0, "{sampled} against {farthest}");
        // The bound holds at every point, measured coarsely or finely.
        let coarse = distance_beyond(&[corners], &specks, spacing, 0.0, f64::INFINITY);
        assert!(
            coarse >= farthest && coarse <= farthest + spacing,
            "{coarse}"
        );
        // Within 1 % of the true distance the samples leave it open; finer ones settle it.
        let within = 1.01 * farthest;
        assert!(sampled + spacing / 3f64.sqrt() > within);
        let settled = distance_beyond(&[corners], &specks, spacing, within, f64::INFINITY);
        assert!(settled >= farthest && settled <= within, "{settled}");
        // Just inside the true distance no sampling can settle it within.
        let short = 0.999 * farthest;
        assert!(distance_beyond(&[corners], &specks, spacing, short, f64::INFINITY) > short);
    }
}
