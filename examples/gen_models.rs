//! Writes the sample meshes in `models/` that `unfold` is exercised with.
//!
//! Run with `cargo run --example gen_models`, or standalone with
//! `rustc examples/gen_models.rs -o /tmp/gen && /tmp/gen` (then the files go
//! to `models/` under the current directory). Only the standard library is used.
//!
//! All coordinates are held as integer nanometres (1e-6 mm), i.e. exactly the
//! values the 6-decimal OBJ output can represent. Every shape is constructed so
//! that its faces are exactly planar *after* that quantisation, instead of
//! rounding an ideal shape and hoping the rounding keeps faces flat (it does
//! not: rounding alone leaves ~1e-8 relative warp on a dodecahedron or torus).

use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Nanometres per millimetre: one unit of the last printed decimal.
const NM_PER_MM: i64 = 1_000_000;

/// A point in integer nanometres.
type Point = [i64; 3];

struct Mesh {
    name: &'static str,
    verts: Vec<Point>,
    /// Vertex indices (0-based), counter-clockwise seen from outside.
    faces: Vec<Vec<usize>>,
}

/// Millimetres to the nearest nanometre (used where exactness is not needed).
fn nm(mm: f64) -> i64 {
    (mm * NM_PER_MM as f64).round() as i64
}

fn sub(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [i128; 3], b: [i128; 3]) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Faces of the convex hull of `verts`, found with exact integer arithmetic:
/// a vertex triple spans a face when no vertex lies strictly on both sides of
/// its plane, and every vertex exactly on that plane joins the face. So corners
/// merge into an n-gon only if they are exactly coplanar, which doubles as a
/// check of the constructions below. Brute force is fine for <= 20 vertices.
fn convex_hull_faces(verts: &[Point]) -> Vec<Vec<usize>> {
    let v: Vec<[i128; 3]> = verts.iter().map(|p| p.map(i128::from)).collect();
    let n = v.len();
    let mut seen = BTreeSet::new();
    let mut faces = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let normal = cross(sub(v[j], v[i]), sub(v[k], v[i]));
                if normal == [0; 3] {
                    continue; // collinear triple
                }
                let side: Vec<i128> = v.iter().map(|&p| dot(normal, sub(p, v[i]))).collect();
                let above = side.iter().any(|&s| s > 0);
                let below = side.iter().any(|&s| s < 0);
                if above && below {
                    continue; // plane cuts through the solid
                }
                let on: Vec<usize> = (0..n).filter(|&l| side[l] == 0).collect();
                if !seen.insert(on.clone()) {
                    continue;
                }
                // The outward normal points away from the rest of the solid.
                let outward = if above { normal.map(|c| -c) } else { normal };
                faces.push(order_ccw(verts, &on, outward.map(|c| c as f64)));
            }
        }
    }
    faces
}

/// Sorts the corners of a planar convex face counter-clockwise about `normal`
/// and starts the loop at the smallest index so the output is canonical.
fn order_ccw(verts: &[Point], idx: &[usize], normal: [f64; 3]) -> Vec<usize> {
    let p = |i: usize| verts[i].map(|c| c as f64);
    let k = idx.len() as f64;
    let c: [f64; 3] = std::array::from_fn(|a| idx.iter().map(|&i| p(i)[a]).sum::<f64>() / k);
    let d = |i: usize| -> [f64; 3] { std::array::from_fn(|a| p(i)[a] - c[a]) };
    let e1 = d(idx[0]);
    // e2 = normal x e1, so (e1, e2, normal) is right-handed: increasing angle is CCW.
    let e2 = [
        normal[1] * e1[2] - normal[2] * e1[1],
        normal[2] * e1[0] - normal[0] * e1[2],
        normal[0] * e1[1] - normal[1] * e1[0],
    ];
    let dotf = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut sorted: Vec<(f64, usize)> = idx
        .iter()
        .map(|&i| (dotf(d(i), e2).atan2(dotf(d(i), e1)), i))
        .collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<usize> = sorted.into_iter().map(|(_, i)| i).collect();
    let start = (0..out.len()).min_by_key(|&s| out[s]).unwrap();
    out.rotate_left(start);
    out
}

/// Cyclic permutations (x, y, z), (z, x, y), (y, z, x) of `p`, so that the
/// sets below keep the (pyrito-)hedral symmetry exactly.
fn cyclic(p: Point) -> [Point; 3] {
    [p, [p[2], p[0], p[1]], [p[1], p[2], p[0]]]
}

/// All sign combinations of the non-zero coordinates of `p`.
fn signs(p: Point) -> Vec<Point> {
    let mut out = vec![p];
    for a in 0..3 {
        if p[a] != 0 {
            out = out
                .into_iter()
                .flat_map(|q| {
                    let mut r = q;
                    r[a] = -r[a];
                    [q, r]
                })
                .collect();
        }
    }
    out
}

fn convex_solid(name: &'static str, verts: Vec<Point>) -> Mesh {
    let faces = convex_hull_faces(&verts);
    Mesh { name, verts, faces }
}

/// Half the longest bounding-box side: every model spans about 100 mm.
const HALF: i64 = 50 * NM_PER_MM;

fn tetrahedron() -> Mesh {
    // Alternate corners of the 100 mm cube.
    let verts = signs([HALF; 3])
        .into_iter()
        .filter(|p| p.iter().filter(|&&c| c < 0).count() % 2 == 0)
        .collect();
    convex_solid("tetrahedron", verts)
}

fn hexahedron() -> Mesh {
    convex_solid("hexahedron", signs([HALF; 3]))
}

fn octahedron() -> Mesh {
    let verts = cyclic([HALF, 0, 0])
        .iter()
        .flat_map(|&p| signs(p))
        .collect();
    convex_solid("octahedron", verts)
}

/// Icosahedron (0, ±1, ±φ) and cyclic permutations, scaled so φ -> 50 mm.
/// Its faces are triangles, so rounding to nanometres cannot warp them.
fn icosahedron() -> Mesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let s = nm(50.0 / phi);
    let verts = cyclic([0, s, HALF])
        .iter()
        .flat_map(|&p| signs(p))
        .collect();
    convex_solid("icosahedron", verts)
}

/// Dodecahedron as a pyritohedron: cube corners (±a, ±a, ±a) plus cyclic
/// permutations of (0, ±p, ±q) with p = a + d and q = a - d²/a. Its pentagons
/// are planar for every d, and regular when d/a = 1/φ. Taking a = g·u²,
/// d = g·u·v for consecutive Fibonacci numbers v = 987, u = 1597 (v/u is 1/φ
/// within 2e-7) and g = 12 nm makes a, p, q exact integers in nanometres
/// (q = g·(u - v)·(u + v), by Cassini's identity u² - (u - v)(u + v) = v²),
/// so the faces stay exactly planar and the solid spans 99.04 mm.
fn dodecahedron() -> Mesh {
    let (g, u, v) = (12, 1597, 987);
    let (a, p, q) = (g * u * u, g * u * (u + v), g * (u - v) * (u + v));
    assert_eq!(a * (a - q), (p - a) * (p - a), "pentagons must be planar");
    let mut verts = signs([a; 3]);
    verts.extend(cyclic([0, p, q]).iter().flat_map(|&p| signs(p)));
    convex_solid("dodecahedron", verts)
}

/// Directions of `n` equal steps around the z axis, quantised to 1e-6.
/// They need not be exactly unit length: see `revolve` for why any
/// directions keep the quads planar.
fn directions(n: usize) -> Vec<[i64; 2]> {
    (0..n)
        .map(|j| {
            let t = 2.0 * PI * j as f64 / n as f64;
            [nm(t.cos()), nm(t.sin())]
        })
        .collect()
}

/// Revolves a profile polyline of (radius in whole mm, z in nm) about the z
/// axis in `n` steps; `closed` joins the last profile point back to the first.
/// Vertex (i, j) is (r_i·u_j, z_i) with u_j from `directions`, an exact
/// nanometre integer because r_i is whole millimetres. The quad between profile
/// points i, i+1 and steps j, j+1 has the edges r_i·(u_{j+1} - u_j) and
/// r_{i+1}·(u_{j+1} - u_j), which are parallel, so it is an exactly planar
/// trapezoid whatever the rounding of u_j. Profiles that run counter-clockwise
/// in the (r, z) half-plane give outward-facing quads.
fn revolve(profile: &[(i64, i64)], n: usize, closed: bool) -> (Vec<Point>, Vec<Vec<usize>>) {
    let dirs = directions(n);
    let verts = profile
        .iter()
        .flat_map(|&(r, z)| dirs.iter().map(move |u| [r * u[0], r * u[1], z]))
        .collect();
    let m = profile.len();
    let rings = if closed { m } else { m - 1 };
    let idx = |i: usize, j: usize| (i % m) * n + j % n;
    let faces = (0..rings)
        .flat_map(|i| {
            (0..n).map(move |j| vec![idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j)])
        })
        .collect();
    (verts, faces)
}

/// Torus with `n` segments around the axis and an `m`-gon tube section of
/// circumradius 18 mm at 32 mm from the axis (outer diameter 100 mm). The
/// section radii 32 + 18·cos(2πi/m) are whole millimetres for m = 4 and 6.
fn torus(name: &'static str, n: usize, m: usize) -> Mesh {
    let profile: Vec<(i64, i64)> = (0..m)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / m as f64;
            let r = 32.0 + 18.0 * t.cos();
            assert!((r - r.round()).abs() < 1e-9, "torus radii must be whole mm");
            (r.round() as i64, nm(18.0 * t.sin()))
        })
        .collect();
    let (verts, faces) = revolve(&profile, n, true);
    Mesh { name, verts, faces }
}

/// Open barrel-shaped tube: 8 segments, 3 rings of quads, no caps.
fn open_cylinder() -> Mesh {
    let profile = [(40, -48), (50, -16), (50, 16), (40, 48)].map(|(r, z)| (r, z * NM_PER_MM));
    let (verts, faces) = revolve(&profile, 8, false);
    Mesh {
        name: "open-cylinder",
        verts,
        faces,
    }
}

/// Boundary of a one-cell-thick slab of `nx` × `ny` cubes with the `holes`
/// cells removed, one quad per exposed unit square so that neighbouring quads
/// share vertices. Holes must not touch each other or the rim, or the surface
/// would have non-manifold edges or vertices. Axis-aligned, hence exactly planar.
fn voxel_slab(name: &'static str, nx: i64, ny: i64, holes: &[(i64, i64)]) -> Mesh {
    let size = [nx, ny, 1];
    let solid = |c: [i64; 3]| {
        (0..3).all(|a| (0..size[a]).contains(&c[a])) && !holes.contains(&(c[0], c[1]))
    };
    let mut quads = Vec::new();
    for z in 0..size[2] {
        for y in 0..size[1] {
            for x in 0..size[0] {
                let cell = [x, y, z];
                if !solid(cell) {
                    continue;
                }
                for axis in 0..3 {
                    // (axis, a1, a2) is a cyclic frame, so corners 0, e_a1,
                    // e_a1 + e_a2, e_a2 wind counter-clockwise about +e_axis.
                    let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
                    for sign in [1, -1] {
                        let mut next = cell;
                        next[axis] += sign;
                        if solid(next) {
                            continue;
                        }
                        let mut base = cell;
                        if sign > 0 {
                            base[axis] += 1;
                        }
                        let corner = |d1: i64, d2: i64| {
                            let mut p = base;
                            p[a1] += d1;
                            p[a2] += d2;
                            p
                        };
                        let mut q = vec![corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if sign < 0 {
                            q.reverse();
                        }
                        quads.push(q);
                    }
                }
            }
        }
    }
    // Cell edge of about 100 mm / longest count, rounded to an even number
    // of nanometres so that the centring offset n·cell/2 is exact.
    let cell = 2 * nm(50.0 / nx.max(ny) as f64);
    let grid: BTreeSet<Point> = quads.iter().flatten().copied().collect();
    let index: BTreeMap<Point, usize> = grid.iter().enumerate().map(|(i, &p)| (p, i)).collect();
    let verts = grid
        .iter()
        .map(|g| std::array::from_fn(|a| (2 * g[a] - size[a]) * cell / 2))
        .collect();
    let faces = quads
        .iter()
        .map(|q| q.iter().map(|p| index[p]).collect())
        .collect();
    Mesh { name, verts, faces }
}

/// Prism over a 5-pointed star: the caps are single concave decagons and
/// the sides vertical rectangles (exactly planar: top and bottom corners
/// share their rounded x, y). The star is 100 mm wide, 20 mm thick.
fn concave() -> Mesh {
    let r_out = 50.0 / (PI / 10.0).cos(); // points at ±18° span 100 mm
    let r_in = 0.4 * r_out;
    let star: Vec<[f64; 2]> = (0..10)
        .map(|k| {
            let t = PI / 2.0 + k as f64 * PI / 5.0;
            let r = if k % 2 == 0 { r_out } else { r_in };
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    // Centre the bounding box (the star's own centre is not its middle).
    let mid = |a: usize| {
        let (lo, hi) = star
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[a]), h.max(p[a])));
        (lo + hi) / 2.0
    };
    let (cx, cy) = (mid(0), mid(1));
    let xy: Vec<[i64; 2]> = star
        .iter()
        .map(|p| [nm(p[0] - cx), nm(p[1] - cy)])
        .collect();
    let half_t = 10 * NM_PER_MM;
    let mut verts: Vec<Point> = xy.iter().map(|p| [p[0], p[1], -half_t]).collect();
    verts.extend(xy.iter().map(|p| [p[0], p[1], half_t]));
    let n = xy.len();
    let mut faces = vec![(n..2 * n).collect::<Vec<_>>(), (0..n).rev().collect()];
    faces.extend((0..n).map(|k| vec![k, (k + 1) % n, n + (k + 1) % n, n + k]));
    Mesh {
        name: "concave",
        verts,
        faces,
    }
}

/// 6 × 4 quads bent into an arch of radius 100 mm about an axis parallel to
/// y, 10° per column. Height depends on x only, so every quad is an exact
/// rectangle (its two y-parallel edges share rounded x and z). Normals point
/// up, away from the bend axis.
fn open_grid() -> Mesh {
    let (cols, rows, radius) = (6, 4, 100.0);
    let step = 10f64.to_radians();
    let angle = |i: usize| (i as f64 - cols as f64 / 2.0) * step;
    let z_mid = radius * (1.0 + (cols as f64 / 2.0 * step).cos()) / 2.0;
    let cell = radius * step; // arc length, so the grid flattens to squares
    let mut verts = Vec::new();
    for k in 0..=rows {
        for i in 0..=cols {
            let y = (k as f64 - rows as f64 / 2.0) * cell;
            verts.push([
                nm(radius * angle(i).sin()),
                nm(y),
                nm(radius * angle(i).cos() - z_mid),
            ]);
        }
    }
    let idx = |k: usize, i: usize| k * (cols + 1) + i;
    let faces = (0..rows)
        .flat_map(|k| {
            (0..cols).map(move |i| vec![idx(k, i), idx(k, i + 1), idx(k + 1, i + 1), idx(k + 1, i)])
        })
        .collect();
    Mesh {
        name: "open-grid",
        verts,
        faces,
    }
}

/// Exact fixed 6-decimal rendering of nanometres; never prints "-0.000000".
fn write_coord(out: &mut String, v: i64) {
    let sign = if v < 0 { "-" } else { "" };
    let a = v.unsigned_abs();
    let per = NM_PER_MM as u64;
    write!(out, "{sign}{}.{:06}", a / per, a % per).unwrap();
}

fn to_obj(mesh: &Mesh) -> String {
    let mut out = String::from("# generated by examples/gen_models.rs — do not edit\n");
    writeln!(out, "o {}", mesh.name).unwrap();
    for v in &mesh.verts {
        out.push('v');
        for &c in v {
            out.push(' ');
            write_coord(&mut out, c);
        }
        out.push('\n');
    }
    for f in &mesh.faces {
        out.push('f');
        for &i in f {
            write!(out, " {}", i + 1).unwrap();
        }
        out.push('\n');
    }
    out
}

/// Cheap guard against construction mistakes: counts must match the spec.
fn check_counts(mesh: &Mesh, (v, e, f): (usize, usize, usize)) {
    let edges: BTreeSet<(usize, usize)> = mesh
        .faces
        .iter()
        .flat_map(|f| {
            (0..f.len()).map(move |i| {
                (
                    f[i].min(f[(i + 1) % f.len()]),
                    f[i].max(f[(i + 1) % f.len()]),
                )
            })
        })
        .collect();
    let got = (mesh.verts.len(), edges.len(), mesh.faces.len());
    assert_eq!(got, (v, e, f), "{}: (V, E, F)", mesh.name);
}

fn main() {
    let root = option_env!("CARGO_MANIFEST_DIR").map_or_else(PathBuf::new, PathBuf::from);
    let dir = root.join("models");
    std::fs::create_dir_all(&dir).expect("create models/");
    let models = [
        (tetrahedron(), (4, 6, 4)),
        (hexahedron(), (8, 12, 6)),
        (octahedron(), (6, 12, 8)),
        (dodecahedron(), (20, 30, 12)),
        (icosahedron(), (12, 30, 20)),
        (torus("torus-8x6", 8, 6), (48, 96, 48)),
        (torus("torus-6x4", 6, 4), (24, 48, 24)),
        (voxel_slab("genus2", 5, 3, &[(1, 1), (3, 1)]), (48, 100, 50)),
        (
            voxel_slab("genus3", 7, 3, &[(1, 1), (3, 1), (5, 1)]),
            (64, 136, 68),
        ),
        (concave(), (20, 30, 12)),
        (open_grid(), (35, 58, 24)),
        (open_cylinder(), (32, 56, 24)),
    ];
    for (mesh, counts) in &models {
        check_counts(mesh, *counts);
        let path = dir.join(format!("{}.obj", mesh.name));
        std::fs::write(&path, to_obj(mesh)).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("wrote {}", path.display());
    }
}
