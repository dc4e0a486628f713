//! The field whose level curves the strips follow: harmonic between two poles, or the
//! distance from the rims (the heat method), evened so that equal steps are about
//! equally wide on the surface.

use std::collections::BTreeMap;

use glam::DVec3;

use super::surface::{rims, Triangles};
use crate::union_find::UnionFind;

/// What the field is on a closed part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Closed {
    /// Harmonic between its two points farthest apart.
    Harmonic,
    /// The distance from the first of them ([`distance_from`]).
    Distance,
}

/// The field of each connected part of `surface`, from 0 to 1. On an open tube or an
/// annulus (two rims no point of the part lies farther from than they lie apart), the
/// harmonic field between its rims (0 at one, 1 at the other, the cotangent
/// Laplacian's zero elsewhere; faer's sparse Cholesky): level curves that run round
/// the part like parallels between its ends, with saddles only where its shape needs
/// them. On a closed part, as `closed` asks: the harmonic field between its two points
/// farthest apart, or the distance from one of them. On a part with other rims (one,
/// or holes, like a scan's), the distance from them all ([`distance_from`]): a
/// harmonic field crowds its levels along a ragged rim or between two rims close
/// together, too close for a strip between them.
pub(super) fn field_of(surface: &Triangles, closed: Closed) -> Result<Vec<f64>, String> {
    let n = surface.points.len();
    let weights = cotangent_weights(surface);
    let rims = rims(surface);
    let mut field = vec![0.0; n];
    for part in parts(surface) {
        let values = match pole_values(&surface.points, &part, &rims, closed) {
            Held::Poles(fixed) => solve_on(n, &part, &weights, &fixed, &|_| 0.0, &|_| 0.0)?,
            Held::Distance(from) => distance_from(surface, &part, &weights, &from)?,
        };
        for (&v, x) in part.iter().zip(values) {
            field[v as usize] = x;
        }
    }
    Ok(field)
}

/// The values at the points of `part` (in its order) that solve
/// `(K + diag(extra)) x = source` where they are free, `K` the Laplacian of `weights`,
/// with the values `fixed` held (faer's sparse Cholesky).
fn solve_on(
    n: usize,
    part: &[u32],
    weights: &[(u32, u32, f64)],
    fixed: &BTreeMap<u32, f64>,
    extra: &dyn Fn(u32) -> f64,
    source: &dyn Fn(u32) -> f64,
) -> Result<Vec<f64>, String> {
    let mut index = vec![usize::MAX; n];
    let free: Vec<u32> = part
        .iter()
        .copied()
        .filter(|v| !fixed.contains_key(v))
        .collect();
    for (k, &v) in free.iter().enumerate() {
        index[v as usize] = k;
    }
    let mut lower = Vec::new();
    let mut rhs: Vec<f64> = free.iter().map(|&v| source(v)).collect();
    let mut diagonal: Vec<f64> = free.iter().map(|&v| extra(v)).collect();
    for &(a, b, w) in weights {
        let (ia, ib) = (index[a as usize], index[b as usize]);
        for (i, j, other) in [(ia, ib, b), (ib, ia, a)] {
            if i == usize::MAX {
                continue;
            }
            diagonal[i] += w;
            if j != usize::MAX {
                if j < i {
                    lower.push(faer::sparse::Triplet::new(i, j, -w));
                }
            } else if let Some(value) = fixed.get(&other) {
                rhs[i] += w * value;
            }
        }
    }
    // A hair on the diagonal keeps the system definite where weights vanish.
    for (i, d) in diagonal.iter().enumerate() {
        lower.push(faer::sparse::Triplet::new(
            i,
            i,
            d + 1e-12 * d.abs().max(1.0),
        ));
    }
    let solution = solve_lower(free.len(), &lower, &rhs)?;
    let mut values = vec![0.0; n];
    for (&v, x) in free.iter().zip(solution) {
        values[v as usize] = x;
    }
    for (&v, &value) in fixed {
        values[v as usize] = value;
    }
    Ok(part.iter().map(|&v| values[v as usize]).collect())
}

/// How many screening lengths the heat of [`distance_from`] crosses a part in: more,
/// and it would fade below the solve's precision far from the rims.
const HEAT_REACH: f64 = 25.0;

/// The distance over `part` from its points `from` (its rims, or a pole), by the heat
/// method: heat held on them spreads a short way, its flow's direction, made unit, is
/// the distance's gradient, and a Poisson solve with them at 0 gives the distance,
/// scaled to 1 at its farthest point. Its levels near a rim run along it at a constant
/// distance however the rim is ragged or near another, where a harmonic field's crowd,
/// and they rise along every branch of a part, where a harmonic field between two
/// poles stays level along a dead end.
fn distance_from(
    surface: &Triangles,
    part: &[u32],
    weights: &[(u32, u32, f64)],
    from: &[u32],
) -> Result<Vec<f64>, String> {
    let n = surface.points.len();
    let at = |v: u32| surface.points[v as usize];
    let in_part = {
        let mut flags = vec![false; n];
        for &v in part {
            flags[v as usize] = true;
        }
        flags
    };
    let triangles: Vec<[u32; 3]> = surface
        .corners
        .iter()
        .copied()
        .filter(|t| in_part[t[0] as usize])
        .collect();
    let (lo, hi) = crate::mesh::geometry::bounding_box(part.iter().map(|&v| at(v)));
    let screening = (hi - lo).length() / HEAT_REACH;
    let mut mass = vec![0.0; n];
    for t in &triangles {
        let [a, b, c] = t.map(at);
        let third = (b - a).cross(c - a).length() / 6.0;
        for &v in t {
            mass[v as usize] += third;
        }
    }
    let hot: BTreeMap<u32, f64> = from.iter().map(|&v| (v, 1.0)).collect();
    let heat = solve_on(
        n,
        part,
        weights,
        &hot,
        &|v| mass[v as usize] / (screening * screening),
        &|_| 0.0,
    )?;
    let mut u = vec![0.0; n];
    for (&v, x) in part.iter().zip(heat) {
        u[v as usize] = x;
    }
    // The divergence at each point of the unit field pointing away from the heat.
    let mut divergence = vec![0.0; n];
    for t in &triangles {
        let Some((gradient, _)) = gradient_on(t.map(at), t.map(|v| u[v as usize])) else {
            continue;
        };
        let away = -gradient.normalize_or_zero();
        for k in 0..3 {
            let (i, j, l) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let [pi, pj, pl] = [i, j, l].map(at);
            divergence[i as usize] += 0.5
                * (cotangent(pl, pi, pj) * (pj - pi).dot(away)
                    + cotangent(pj, pl, pi) * (pl - pi).dot(away));
        }
    }
    let cold: BTreeMap<u32, f64> = from.iter().map(|&v| (v, 0.0)).collect();
    // The Laplacian of the distance is the divergence: K, the negative Laplacian,
    // takes its negative.
    let distance = solve_on(n, part, weights, &cold, &|_| 0.0, &|v| {
        -divergence[v as usize]
    })?;
    let far = distance.iter().copied().fold(0.0, f64::max);
    Ok(match far > 0.0 {
        true => distance.iter().map(|d| d.max(0.0) / far).collect(),
        false => distance,
    })
}

/// Bins of field values over which [`evened`] measures the surface's width per value.
const EVEN_BINS: usize = 512;

/// `field` remapped, by a function that only grows, so that equal steps of value are
/// about equally wide on the surface: a band of values [v, v + dv] is dv / |∇f| wide
/// where it crosses a triangle, and its width at v is the mean of that over the level
/// set (each triangle's area in the band over its area times its gradient). A
/// harmonic field crowds its levels near point poles; evened, bands split into equal
/// parts split into strips of equal width. The level curves are the same curves.
pub(super) fn evened(surface: &Triangles, field: &[f64]) -> Vec<f64> {
    let (lo, hi) = field
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if hi.is_nan() || hi <= lo {
        return field.to_vec();
    }
    let step = (hi - lo) / EVEN_BINS as f64;
    let bin = |v: f64| (((v - lo) / step) as usize).min(EVEN_BINS - 1);
    // Per bin: the area of the triangles in it, and that area times their gradient.
    let mut area = vec![0.0; EVEN_BINS];
    let mut area_gradient = vec![0.0; EVEN_BINS];
    for t in &surface.corners {
        let [fa, fb, fc] = t.map(|i| field[i as usize]);
        let Some((gradient, twice)) =
            gradient_on(t.map(|i| surface.points[i as usize]), [fa, fb, fc])
        else {
            continue;
        };
        let g = gradient.length();
        let (first, last) = (bin(fa.min(fb).min(fc)), bin(fa.max(fb).max(fc)));
        let share = 0.5 * twice / (last - first + 1) as f64;
        for k in first..=last {
            area[k] += share;
            area_gradient[k] += share * g;
        }
    }
    // Widths per unit of value; bins no triangle reaches keep a sliver of width, so the
    // remap still grows there.
    let widths: Vec<f64> = (0..EVEN_BINS)
        .map(|k| match area_gradient[k] > 0.0 {
            true => area[k] / area_gradient[k],
            false => 0.0,
        })
        .collect();
    let floor = 1e-6 * widths.iter().copied().fold(0.0, f64::max).max(1e-300);
    let mut at = vec![0.0; EVEN_BINS + 1];
    for k in 0..EVEN_BINS {
        at[k + 1] = at[k] + step * widths[k].max(floor);
    }
    field
        .iter()
        .map(|&v| {
            let k = bin(v);
            let t = ((v - lo) / step - k as f64).clamp(0.0, 1.0);
            at[k] + t * (at[k + 1] - at[k])
        })
        .collect()
}

/// How the field is held on a part.
enum Held {
    /// At these values at these points, harmonic between.
    Poles(BTreeMap<u32, f64>),
    /// At 0 at these points (rims, or a pole), the distance from them elsewhere.
    Distance(Vec<u32>),
}

/// How the field is held on `part`: at 0 and 1 at its two points farthest apart on a
/// closed part, or on its two rims on an open tube or an annulus; else at 0 on all its
/// rims, the distance from them elsewhere.
fn pole_values(points: &[DVec3], part: &[u32], rims: &[Vec<u32>], closed: Closed) -> Held {
    let in_part: Vec<&Vec<u32>> = rims
        .iter()
        .filter(|r| part.binary_search(&r[0]).is_ok())
        .collect();
    let at = |v: u32| points[v as usize];
    let held = |zero: &[u32], one: &[u32]| {
        let zeros = zero.iter().map(|&v| (v, 0.0));
        Held::Poles(zeros.chain(one.iter().map(|&v| (v, 1.0))).collect())
    };
    // The distance from point `v` to the nearest point of `rims`.
    let nearest = |rims: &[&Vec<u32>], v: u32| {
        rims.iter()
            .flat_map(|r| r.iter())
            .map(|&r| at(r).distance(at(v)))
            .fold(f64::INFINITY, f64::min)
    };
    // The distance from every rim (one rim, or holes in one side of the part, like a
    // scan's base).
    let from_rims =
        |rims: &[&Vec<u32>]| Held::Distance(rims.iter().flat_map(|r| r.iter().copied()).collect());
    match in_part.as_slice() {
        [] => match (poles(points, part), closed) {
            ([one, other], Closed::Harmonic) => held(&[one], &[other]),
            ([one, _], Closed::Distance) => Held::Distance(vec![one]),
        },
        [_] => from_rims(&in_part),
        // Several rims: the two whose centres lie farthest apart, where no point of the
        // part lies farther from both than they lie from each other (an open tube's
        // ends, an annulus's edges). Rims closer together than the rest of the part
        // reaches are held as one: held apart, they would leave the field flat there.
        rims => {
            let centre = |r: &[u32]| r.iter().map(|&v| at(v)).sum::<DVec3>() / r.len() as f64;
            let mut best = (0, 1, f64::NEG_INFINITY);
            for i in 0..rims.len() {
                for j in i + 1..rims.len() {
                    let d = centre(rims[i]).distance(centre(rims[j]));
                    if d > best.2 {
                        best = (i, j, d);
                    }
                }
            }
            let (one, other) = (rims[best.0], rims[best.1]);
            let gap = one
                .iter()
                .map(|&v| nearest(&[other], v))
                .fold(f64::INFINITY, f64::min);
            let reach = part
                .iter()
                .map(|&v| nearest(&[one, other], v))
                .fold(0.0, f64::max);
            match reach <= gap {
                true => held(one, other),
                false => from_rims(rims),
            }
        }
    }
}

/// Whether [`field_of`] gives some part of `surface` a distance.
pub(super) fn ridged(surface: &Triangles, closed: Closed) -> bool {
    let rims = rims(surface);
    parts(surface).iter().any(|part| {
        matches!(
            pole_values(&surface.points, part, &rims, closed),
            Held::Distance(_)
        )
    })
}

/// Whether some part of `surface` has no rim.
pub(super) fn closed_part(surface: &Triangles) -> bool {
    let rims = rims(surface);
    parts(surface)
        .iter()
        .any(|part| !rims.iter().any(|r| part.binary_search(&r[0]).is_ok()))
}

/// Solves the symmetric system given by its lower triangle's entries.
fn solve_lower(
    n: usize,
    lower: &[faer::sparse::Triplet<usize, usize, f64>],
    rhs: &[f64],
) -> Result<Vec<f64>, String> {
    use faer::linalg::solvers::Solve;
    if n == 0 {
        return Ok(Vec::new());
    }
    let matrix = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, lower)
        .map_err(|e| format!("the field's system: {e:?}"))?;
    let llt = matrix
        .sp_cholesky(faer::Side::Lower)
        .map_err(|e| format!("the field's system: {e:?}"))?;
    let x = llt.solve(&faer::Mat::from_fn(n, 1, |i, _| rhs[i]));
    let solution: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    if solution.iter().all(|x| x.is_finite()) {
        Ok(solution)
    } else {
        Err("the field's system has no finite solution".into())
    }
}

/// The least weight an edge keeps in the field's system.
const LEAST_WEIGHT: f64 = 1e-6;

/// The cotangent of the angle at `apex` between `p` and `q`, kept within ±1000 (a
/// needle triangle's would swamp the rest).
fn cotangent(apex: DVec3, p: DVec3, q: DVec3) -> f64 {
    let (u, v) = (p - apex, q - apex);
    (u.dot(v) / u.cross(v).length().max(1e-300)).clamp(-1e3, 1e3)
}

/// The gradient over the triangle `[a, b, c]` (counter-clockwise) of the linear
/// function with values `f` at its corners, and twice its area; `None` where it has
/// none. ∇f = Σ f_i (n × e_i) / 2A, e_i the side opposite corner i.
fn gradient_on([a, b, c]: [DVec3; 3], [fa, fb, fc]: [f64; 3]) -> Option<(DVec3, f64)> {
    let normal = (b - a).cross(c - a);
    let twice = normal.length();
    if twice <= 0.0 {
        return None;
    }
    let n = normal / twice;
    let gradient = (fa * n.cross(c - b) + fb * n.cross(a - c) + fc * n.cross(b - a)) / twice;
    Some((gradient, twice))
}

/// Each edge of `surface` (once, lower corner first) with its cotangent weight: half
/// the sum of the cotangents of the angles facing it, each kept within ±1000 (a
/// needle triangle's would swamp the rest), the sum at least [`LEAST_WEIGHT`].
fn cotangent_weights(surface: &Triangles) -> Vec<(u32, u32, f64)> {
    let mut weights: BTreeMap<(u32, u32), f64> = BTreeMap::new();
    for t in &surface.corners {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let [pa, pb, pc] = [a, b, c].map(|i| surface.points[i as usize]);
            *weights.entry((a.min(b), a.max(b))).or_insert(0.0) += 0.5 * cotangent(pc, pa, pb);
        }
    }
    // Negative weights (obtuse angles) kept a hair above zero: the system stays
    // definite, and the field has no extremum but its poles.
    weights
        .into_iter()
        .map(|((a, b), w)| (a, b, w.max(LEAST_WEIGHT)))
        .collect()
}

/// The points of each connected part of `surface` (joined by triangles), each in
/// increasing order, the parts by their first point.
fn parts(surface: &Triangles) -> Vec<Vec<u32>> {
    let n = surface.points.len();
    let mut sets = UnionFind::new(n);
    let mut used = vec![false; n];
    for t in &surface.corners {
        for k in 0..3 {
            used[t[k] as usize] = true;
            sets.union(t[k], t[(k + 1) % 3]);
        }
    }
    let mut groups: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for v in (0..n as u32).filter(|&v| used[v as usize]) {
        let r = sets.find(v);
        groups.entry(r).or_default().push(v);
    }
    groups.into_values().collect()
}

/// Two points of `part` far apart: the farthest from its first point, and the
/// farthest from that.
fn poles(points: &[DVec3], part: &[u32]) -> [u32; 2] {
    let farthest = |from: u32| {
        part.iter()
            .copied()
            .max_by(|&a, &b| {
                let d = |v: u32| points[v as usize].distance_squared(points[from as usize]);
                d(a).total_cmp(&d(b)).then(b.cmp(&a))
            })
            .unwrap_or(from)
    };
    let one = farthest(part[0]);
    [one, farthest(one)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::surface::cycle_pairs;
    use crate::scheme::strip::test_shapes::{check_strips, sphere, tube};

    /// The harmonic field of a wide cone between its rims crowds toward the narrow
    /// rim (it goes as the log of the radius); evened, it runs evenly along the slant.
    #[test]
    fn an_evened_field_steps_evenly_along_the_surface() {
        let cone = tube(48, 40, 100.0, |h| 10.0 + 1.5 * h);
        let field = field_of(&cone, Closed::Harmonic).unwrap();
        let even = evened(&cone, &field);
        let (lo, hi) = (
            even.iter().copied().fold(f64::INFINITY, f64::min),
            even.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let mut worst_raw: f64 = 0.0;
        let mut worst_even: f64 = 0.0;
        for (k, p) in cone.points.iter().enumerate() {
            let along = p.z / 100.0;
            let raw = (field[k] - field[0]) / (field[field.len() - 1] - field[0]);
            worst_raw = worst_raw.max((raw - along).abs());
            worst_even = worst_even.max(((even[k] - lo) / (hi - lo) - along).abs());
        }
        assert!(
            worst_raw > 0.2,
            "the raw field is far from even: {worst_raw}"
        );
        assert!(worst_even < 0.02, "evened: {worst_even}");
    }

    #[test]
    fn holes_close_together_are_one_pole_and_the_field_spans_the_rest() {
        // A sphere with two holes 60 degrees apart round its lower part.
        let mut holed = sphere(100.0, 24, 16);
        let hole = |i: u32| [1 + 24 * 2 + i, 1 + 24 * 2 + i + 1, 1 + 24 * 3 + i + 1];
        let removed = [hole(0), hole(4)];
        holed
            .corners
            .retain(|t| !removed.iter().any(|h| h.iter().all(|v| t.contains(v))));
        assert_eq!(rims(&holed).len(), 2);
        let field = field_of(&holed, Closed::Harmonic).unwrap();
        let far = field.iter().position(|&f| f == 1.0).expect("a pole at 1");
        assert!(
            holed.points[far].z > 50.0,
            "the pole at 1 is across from the holes"
        );
        for rim in rims(&holed) {
            assert!(rim.iter().all(|&v| field[v as usize] == 0.0));
        }
        // Held apart, the two holes would leave the upper half flat.
        let upper: Vec<f64> = (0..holed.points.len())
            .filter(|&v| holed.points[v].z > 0.0)
            .map(|v| field[v])
            .collect();
        let (lo, hi) = upper
            .iter()
            .fold((1.0f64, 0.0f64), |(lo, hi), &f| (lo.min(f), hi.max(f)));
        assert!(hi - lo > 0.25, "the upper half spans {lo}..{hi}");
        check_strips(&holed, &evened(&holed, &field), 2.0);
    }

    #[test]
    fn the_field_of_a_part_with_holes_runs_at_even_distances_along_their_rims() {
        // Three ragged holes side by side in a sphere's base, 11 mm apart at their
        // nearest: a field held at 0 on them must rise as fast all round each rim.
        let mut holed = sphere(100.0, 96, 48);
        let centres =
            [-35.0, 0.0, 35.0].map(|x: f64| DVec3::new(x, 0.0, -(100.0f64 * 100.0 - x * x).sqrt()));
        let points = holed.points.clone();
        holed.corners.retain(|t| {
            let middle = t.iter().map(|&v| points[v as usize]).sum::<DVec3>() / 3.0;
            centres.iter().all(|c| middle.distance(*c) > 12.0)
        });
        let holed = holed.rims_apart();
        assert_eq!(rims(&holed).len(), 3);
        let field = field_of(&holed, Closed::Harmonic).unwrap();
        let segments: Vec<(DVec3, DVec3)> = rims(&holed)
            .iter()
            .flat_map(|r| {
                cycle_pairs(r)
                    .map(|(a, b)| (holed.points[a as usize], holed.points[b as usize]))
                    .collect::<Vec<_>>()
            })
            .collect();
        let to_rims = |p: DVec3| {
            segments
                .iter()
                .map(|&(a, b)| {
                    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    p.distance(a + t * (b - a))
                })
                .fold(f64::INFINITY, f64::min)
        };
        // How much faster the field rises than the distance, 8 to 20 mm out, at its
        // fastest over its slowest.
        let used: std::collections::BTreeSet<u32> =
            holed.corners.iter().flatten().copied().collect();
        let spread = |field: &[f64]| {
            let ratios: Vec<f64> = used
                .iter()
                .filter_map(|&v| {
                    let d = to_rims(holed.points[v as usize]);
                    (8.0..20.0).contains(&d).then(|| field[v as usize] / d)
                })
                .collect();
            assert!(ratios.len() > 100, "{} points near the rims", ratios.len());
            let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
                (lo.min(r), hi.max(r))
            });
            hi / lo
        };
        // The harmonic field from the rims to the point farthest from them crowds its
        // levels by a factor of three here; the distance keeps within two, its
        // smoothing slowing it between two holes.
        let part = &parts(&holed)[0];
        let on_rims: Vec<u32> = rims(&holed).into_iter().flatten().collect();
        let far = *used
            .iter()
            .max_by(|&&a, &&b| {
                let d = |v: u32| to_rims(holed.points[v as usize]);
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let held: BTreeMap<u32, f64> = on_rims
            .iter()
            .map(|&v| (v, 0.0))
            .chain([(far, 1.0)])
            .collect();
        let n = holed.points.len();
        let weights = cotangent_weights(&holed);
        let values = solve_on(n, part, &weights, &held, &|_| 0.0, &|_| 0.0).unwrap();
        let mut harmonic = vec![0.0; n];
        for (&v, x) in part.iter().zip(values) {
            harmonic[v as usize] = x;
        }
        let (distance, crowded) = (spread(&field), spread(&harmonic));
        assert!(
            distance < 2.0,
            "the distance rises {distance} times faster in places"
        );
        assert!(
            crowded > 3.0,
            "the harmonic field rises {crowded} times faster"
        );
        check_strips(&holed, &evened(&holed, &field), 2.0);
    }
}
