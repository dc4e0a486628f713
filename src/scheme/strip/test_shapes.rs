//! Shapes and checks the strip scheme's unit tests share: tubes, spheres and tori as
//! triangles, fields along an axis, strips laid flat, and the check that strips cover
//! a surface within a tolerance, unroll exactly and meet point for point.

use std::collections::BTreeMap;
use std::f64::consts::TAU;

use glam::{DVec2, DVec3};

use super::band::{strip_soup, Strip};
use super::conform::outline_of;
use super::cover::{strips_ridged, Cover};
use super::distance::one_way_distance;
use super::field::{ridged, Closed};
use super::patch::RunsBack;
use super::surface::{cycle_pairs, rims, Triangles};

/// A tube of `around` × `along` quads split into triangles, radius `r(h)` at
/// height `h` in 0..=height, open at both ends (a cylinder or a cone).
pub(super) fn tube(around: usize, along: usize, height: f64, r: impl Fn(f64) -> f64) -> Triangles {
    let mut points = Vec::new();
    for k in 0..=along {
        let h = height * k as f64 / along as f64;
        for i in 0..around {
            let a = TAU * i as f64 / around as f64;
            points.push(DVec3::new(r(h) * a.cos(), r(h) * a.sin(), h));
        }
    }
    let id = |k: usize, i: usize| (k * around + i % around) as u32;
    let mut corners = Vec::new();
    for k in 0..along {
        for i in 0..around {
            // Counter-clockwise seen from outside (normals away from the axis).
            corners.push([id(k, i), id(k, i + 1), id(k + 1, i + 1)]);
            corners.push([id(k, i), id(k + 1, i + 1), id(k + 1, i)]);
        }
    }
    Triangles { points, corners }
}

pub(super) fn heights(surface: &Triangles) -> Vec<f64> {
    surface.points.iter().map(|p| p.z).collect()
}

/// Two parallel lines 20 apart in the plane z = 0, of 5 and 8 points.
pub(super) fn two_lines() -> (Vec<DVec3>, Vec<DVec3>) {
    let p = (0..5).map(|i| DVec3::new(i as f64 * 10.0, 0.0, 0.0));
    let q = (0..8).map(|i| DVec3::new(i as f64 * 6.0, 20.0, 0.0));
    (p.collect(), q.collect())
}

/// A sphere of `radius` from a `around` × `rings` grid of latitudes, a point at
/// each pole.
pub(super) fn sphere(radius: f64, around: usize, rings: usize) -> Triangles {
    let mut points = vec![DVec3::new(0.0, 0.0, -radius)];
    for k in 1..rings {
        let lat = std::f64::consts::PI * (k as f64 / rings as f64 - 0.5);
        for i in 0..around {
            let a = TAU * i as f64 / around as f64;
            points.push(radius * DVec3::new(lat.cos() * a.cos(), lat.cos() * a.sin(), lat.sin()));
        }
    }
    points.push(DVec3::new(0.0, 0.0, radius));
    let top = points.len() as u32 - 1;
    let id = |k: usize, i: usize| (1 + (k - 1) * around + i % around) as u32;
    let mut corners = Vec::new();
    for i in 0..around {
        corners.push([0, id(1, i + 1), id(1, i)]);
        corners.push([top, id(rings - 1, i), id(rings - 1, i + 1)]);
    }
    for k in 1..rings - 1 {
        for i in 0..around {
            corners.push([id(k, i), id(k, i + 1), id(k + 1, i + 1)]);
            corners.push([id(k, i), id(k + 1, i + 1), id(k + 1, i)]);
        }
    }
    Triangles { points, corners }
}

/// Strips of `surface` along `axis` within `tolerance`: within it both ways
/// (measured again more finely over the whole), every corner on a strip's outline,
/// edge lengths kept unrolled, the strips on either side of each level meeting at
/// the same points. Returns how many strips.
pub(super) fn check_strips(surface: &Triangles, field: &[f64], tolerance: f64) -> usize {
    check_strips_cut(surface, field, tolerance, f64::INFINITY)
}

/// [`check_strips`] with bands cut into sectors `sector_length` long; every
/// outline edge of a strip is the surface's rim or another strip's outline edge,
/// run the other way.
pub(super) fn check_strips_cut(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
) -> usize {
    let clock = std::time::Instant::now();
    let cover = cover(surface, field, tolerance, sector_length).unwrap();
    eprintln!(
        "{} strips, deviation {:.3} in {:?}",
        cover.strips.len(),
        cover.deviation,
        clock.elapsed()
    );
    let soup = strip_soup(&cover.strips);
    let whole = surface.soup();
    let out = one_way_distance(&soup, &whole, tolerance / 10.0);
    let back = one_way_distance(&whole, &soup, tolerance / 10.0);
    assert!(out <= tolerance && back <= tolerance, "{out} {back}");
    let size = extent_of(&surface.points);
    for strip in &cover.strips {
        let outline = outline_of(strip);
        for v in strip.triangles.iter().flatten() {
            assert!(
                outline.iter().any(|&(_, a, b)| a == *v || b == *v),
                "{v} inside"
            );
        }
        let flat = unroll(strip);
        for t in &strip.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let d3 = strip.points[a].distance(strip.points[b]);
                assert!((flat[a].distance(flat[b]) - d3).abs() < 1e-9 * size);
            }
        }
    }
    // Outline edges by their ends' positions, as the triangles run.
    let key = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut outlines: BTreeMap<([u64; 3], [u64; 3]), usize> = BTreeMap::new();
    for (s, strip) in cover.strips.iter().enumerate() {
        for (_, a, b) in outline_of(strip) {
            let edge = (key(strip.points[a as usize]), key(strip.points[b as usize]));
            assert!(
                outlines.insert(edge, s).is_none(),
                "strip {s} repeats an edge"
            );
        }
    }
    // No edge has more than two triangles: the strips do not overlap.
    let mut uses: BTreeMap<([u64; 3], [u64; 3]), usize> = BTreeMap::new();
    for strip in &cover.strips {
        for t in &strip.triangles {
            for (a, b) in cycle_pairs(t) {
                let (a, b) = (key(strip.points[a as usize]), key(strip.points[b as usize]));
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
    }
    assert!(uses.values().all(|&n| n <= 2), "strips overlap");
    let rim: std::collections::BTreeSet<([u64; 3], [u64; 3])> = rims(surface)
        .iter()
        .flat_map(|r| cycle_pairs(r).collect::<Vec<_>>())
        .map(|(a, b)| {
            (
                key(surface.points[a as usize]),
                key(surface.points[b as usize]),
            )
        })
        .collect();
    for (&(a, b), &s) in &outlines {
        // A ring strip meets itself at the rung it is opened at.
        let from = |k: [u64; 3]| DVec3::from_array(k.map(f64::from_bits));
        assert!(
            rim.contains(&(a, b)) || outlines.contains_key(&(b, a)),
            "an outline edge {} {} of strip {s} meets no other strip",
            from(a),
            from(b)
        );
    }
    cover.strips.len()
}

/// The strips of `surface` within `tolerance`, as the scheme covers a surface whose
/// closed parts have a harmonic field, bands cut into sectors `sector_length` long.
pub(super) fn cover(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
) -> Result<Cover, String> {
    let ridged = ridged(surface, Closed::Harmonic);
    strips_ridged(
        surface,
        field,
        tolerance,
        sector_length,
        ridged,
        RunsBack::Welded,
    )
}

/// The strip laid flat: a point per corner, each triangle placed against the rung it
/// shares with the one before, counter-clockwise as seen from outside, so every edge
/// keeps its length.
pub(super) fn unroll(strip: &Strip) -> Vec<DVec2> {
    let mut flat: Vec<Option<DVec2>> = vec![None; strip.points.len()];
    let length = |a: u32, b: u32| strip.points[a as usize].distance(strip.points[b as usize]);
    for (n, t) in strip.triangles.iter().enumerate() {
        if n == 0 {
            let [a, b, _] = *t;
            flat[a as usize] = Some(DVec2::ZERO);
            flat[b as usize] = Some(DVec2::new(length(a, b), 0.0));
        }
        // Turn the triangle so that its corner not yet placed comes last.
        let Some(r) = (0..3).find(|&r| flat[t[(r + 2) % 3] as usize].is_none()) else {
            continue;
        };
        let [a, b, c] = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
        let (Some(pa), Some(pb)) = (flat[a as usize], flat[b as usize]) else {
            continue;
        };
        flat[c as usize] = Some(apex(pa, pb, length(a, c), length(b, c)));
    }
    flat.into_iter().map(Option::unwrap_or_default).collect()
}

/// The point at distances `ac` from `a` and `bc` from `b`, to the left of `a`→`b`.
fn apex(a: DVec2, b: DVec2, ac: f64, bc: f64) -> DVec2 {
    let ab = b.distance(a);
    if ab == 0.0 {
        return a;
    }
    let along = (ac * ac - bc * bc + ab * ab) / (2.0 * ab);
    let across = (ac * ac - along * along).max(0.0).sqrt();
    let x = (b - a) / ab;
    a + along * x + across * x.perp()
}

/// The height of each point along `axis`.
pub(super) fn along(surface: &Triangles, axis: DVec3) -> Vec<f64> {
    let axis = axis.normalize();
    surface.points.iter().map(|p| p.dot(axis)).collect()
}

pub(super) fn extent_of(points: &[DVec3]) -> f64 {
    let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
    let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
    lo.distance(hi)
}

/// A torus about the z axis: `around` × `across` quads split into triangles.
pub(super) fn torus(big: f64, small: f64, around: usize, across: usize) -> Triangles {
    let mut points = Vec::new();
    for i in 0..around {
        let a = TAU * i as f64 / around as f64;
        for j in 0..across {
            let b = TAU * j as f64 / across as f64;
            let r = big + small * b.cos();
            points.push(DVec3::new(r * a.cos(), r * a.sin(), small * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % around) * across + j % across) as u32;
    let mut corners = Vec::new();
    for i in 0..around {
        for j in 0..across {
            corners.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            corners.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Triangles { points, corners }
}
