//! Simplification never refuses a budget the topology allows: a corpus of meshes made
//! here (bow-tie vertices, thin handles, nearly touching sheets, high genus, holes)
//! and the shared models, simplified to 50, 300, 600 and 1,200 edges in both modes,
//! keep their genus, boundary loops and parts, reach the budget within 2 %, and pass
//! the half-edge validator.

use crate::common;

use std::f64::consts::TAU;
use std::fmt::Write;
use std::path::Path;

use glam::DVec3;
use unfold::mesh::read::{parse_model, Format};
use unfold::mesh::simplify::{simplify, Budget, SimplifyError, SimplifyMode};
use unfold::mesh::{prepare, Mesh, PrepareOptions};

use common::build::shared_models;

/// An OBJ of triangles (1-based corners).
fn obj(positions: &[DVec3], triangles: &[[usize; 3]]) -> String {
    let mut text = String::new();
    for p in positions {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in triangles {
        writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    text
}

/// A torus of `n` × `m` quads split in two, tube radius `r` about a ring of radius 1,
/// centred at `at`; `(positions, triangles)` appended to the given ones.
fn torus(mesh: &mut (Vec<DVec3>, Vec<[usize; 3]>), n: usize, m: usize, r: f64, at: DVec3) {
    let base = mesh.0.len();
    for i in 0..n {
        let u = TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = TAU * j as f64 / m as f64;
            let ring = 1.0 + r * v.cos();
            mesh.0
                .push(at + DVec3::new(ring * u.cos(), ring * u.sin(), r * v.sin()));
        }
    }
    let id = |i: usize, j: usize| base + (i % n) * m + (j % m);
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            mesh.1.push([a, b, c]);
            mesh.1.push([a, c, d]);
        }
    }
}

/// A sphere of `n` rings × `2n` segments about `at` with radius `r`.
fn sphere(mesh: &mut (Vec<DVec3>, Vec<[usize; 3]>), n: usize, r: f64, at: DVec3) {
    let base = mesh.0.len();
    let m = 2 * n;
    mesh.0.push(at + DVec3::new(0.0, 0.0, -r));
    for i in 1..n {
        let theta = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..m {
            let phi = TAU * j as f64 / m as f64;
            mesh.0.push(
                at + r * DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    -theta.cos(),
                ),
            );
        }
    }
    mesh.0.push(at + DVec3::new(0.0, 0.0, r));
    let top = mesh.0.len() - 1;
    let ring = |i: usize, j: usize| base + 1 + (i - 1) * m + (j % m);
    for j in 0..m {
        mesh.1.push([base, ring(1, j + 1), ring(1, j)]);
        mesh.1.push([top, ring(n - 1, j), ring(n - 1, j + 1)]);
    }
    for i in 1..n - 1 {
        for j in 0..m {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            );
            mesh.1.push([a, b, c]);
            mesh.1.push([a, c, d]);
        }
    }
}

/// A wavy grid of `n` × `n` squares split in two, without the squares `hole` names.
fn grid(n: usize, hole: impl Fn(usize, usize) -> bool) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let mut positions = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            positions.push(DVec3::new(x, y, 0.1 * (5.0 * x).sin() * (4.0 * y).cos()));
        }
    }
    let id = |i: usize, j: usize| i * (n + 1) + j;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            if !hole(i, j) {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    (positions, triangles)
}

/// The corpus: name and OBJ text.
fn corpus() -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    // Two spheres sharing one vertex (a bow-tie, which the reader splits): the two
    // copies must never be glued back through the surface.
    let mut bow = (Vec::new(), Vec::new());
    sphere(&mut bow, 16, 1.0, DVec3::new(0.0, 0.0, 0.0));
    sphere(&mut bow, 16, 1.0, DVec3::new(0.0, 0.0, 2.0));
    let (upper_bottom, lower_top) = (bow.0.len() / 2, bow.0.len() / 2 - 1);
    for t in &mut bow.1 {
        for v in t.iter_mut() {
            if *v == upper_bottom {
                *v = lower_top;
            }
        }
    }
    out.push(("bow-tie spheres", obj(&bow.0, &bow.1)));
    // A torus with a thin tube: its handle is the first thing a careless collapse cuts.
    let mut thin = (Vec::new(), Vec::new());
    torus(&mut thin, 64, 8, 0.04, DVec3::ZERO);
    out.push(("thin handle", obj(&thin.0, &thin.1)));
    // Two sheets a thousandth apart (two flat spheres nearly touching).
    let mut near = (Vec::new(), Vec::new());
    sphere(&mut near, 16, 1.0, DVec3::ZERO);
    sphere(&mut near, 16, 1.0, DVec3::new(0.0, 0.0, 2.001));
    out.push(("nearly touching", obj(&near.0, &near.1)));
    // Genus 5: five tori linked in a row, each its own part.
    let mut five = (Vec::new(), Vec::new());
    for k in 0..5 {
        torus(&mut five, 24, 8, 0.3, DVec3::new(3.0 * k as f64, 0.0, 0.0));
    }
    out.push(("five tori", obj(&five.0, &five.1)));
    // An open grid with three holes.
    let (p, t) = grid(40, |i, j| {
        (8..12).contains(&i) && (8..12).contains(&j)
            || (20..26).contains(&i) && (25..28).contains(&j)
            || (30..33).contains(&i) && (5..15).contains(&j)
    });
    out.push(("grid with holes", obj(&p, &t)));
    out
}

/// Faces with their corners counted once: every edge in one or two faces, each way
/// round at most once, and the half-edge validator's checks.
fn assert_manifold(case: &str, mesh: &Mesh) {
    mesh.validate()
        .unwrap_or_else(|e| panic!("{case}: not a valid mesh: {e}"));
    let mut directed: Vec<(u32, u32)> = Vec::new();
    for f in mesh.faces() {
        let corners: Vec<u32> = mesh.face_vertices(f).map(|v| v.0).collect();
        for k in 0..corners.len() {
            directed.push((corners[k], corners[(k + 1) % corners.len()]));
        }
    }
    let total = directed.len();
    directed.sort_unstable();
    directed.dedup();
    assert_eq!(
        directed.len(),
        total,
        "{case}: an edge used twice the same way"
    );
}

fn check(case: &str, mesh: &Mesh, budgets: &[usize]) {
    let before = mesh.topology();
    for &budget in budgets {
        if budget >= before.edges {
            continue;
        }
        for mode in [SimplifyMode::Regular, SimplifyMode::Accurate] {
            let what = format!("{case} to {budget} edges, {mode} mode");
            let (simplified, report) = match simplify(mesh, Budget::Edges(budget), mode) {
                Ok(done) => done,
                // Below the topological minimum (a tetrahedron per part, a torus of 7
                // vertices per handle, a little more in practice): the fewest is named.
                Err(SimplifyError::BelowMinimum { fewest, .. })
                    if fewest > budget
                        && fewest <= 30 * (before.components.len() + before.genus as usize) =>
                {
                    continue;
                }
                Err(e) => panic!("{what}: refused: {e}"),
            };
            let after = simplified.topology();
            assert_eq!(after.genus, before.genus, "{what}: genus");
            assert_eq!(after.boundary_loops, before.boundary_loops, "{what}: loops");
            assert_eq!(
                after.components.len(),
                before.components.len(),
                "{what}: parts"
            );
            // Within 2 %, or the three edges one collapse removes.
            assert!(
                after.edges.abs_diff(budget) <= (budget / 50).max(3),
                "{what}: {} edges",
                after.edges
            );
            assert_eq!(report.after, (after.faces, after.edges), "{what}");
            assert_manifold(&what, &simplified);
        }
    }
}

fn prepared(name: &str, text: &[u8], format: Format) -> Mesh {
    let raw = parse_model(Path::new(name), format, text).expect("parses");
    prepare(&raw, &PrepareOptions { weld: false })
        .expect("prepares")
        .mesh
}

#[test]
fn the_corpus_keeps_its_topology_at_every_budget() {
    for (name, text) in corpus() {
        let mesh = prepared(name, text.as_bytes(), Format::Obj);
        let topology = mesh.topology();
        eprintln!(
            "{name}: {} edges, genus {}, {} loops, {} parts",
            topology.edges,
            topology.genus,
            topology.boundary_loops,
            topology.components.len()
        );
        check(name, &mesh, &[50, 300, 600, 1200]);
    }
}

#[test]
fn the_shared_models_keep_their_topology_at_every_budget() {
    let Some(dir) = shared_models("the_shared_models_keep_their_topology_at_every_budget") else {
        return;
    };
    for file in [
        "cube.obj",
        "decimated-knight.off",
        "fertility.obj",
        "horse_quad.obj",
        "spot.obj",
        "stanford-bunny.obj",
        "suzanne.obj",
        "teapot.obj",
    ] {
        let path = dir.join(file);
        let format = Format::from_path(&path).expect("a known format");
        let mesh = prepared(file, &std::fs::read(&path).unwrap(), format);
        check(file, &mesh, &[300, 600, 1200]);
    }
}

#[test]
fn a_budget_below_the_topology_names_the_fewest_edges() {
    let mut five = (Vec::new(), Vec::new());
    for k in 0..5 {
        torus(&mut five, 24, 8, 0.3, DVec3::new(3.0 * k as f64, 0.0, 0.0));
    }
    let mesh = prepared("five tori", obj(&five.0, &five.1).as_bytes(), Format::Obj);
    let error = simplify(&mesh, Budget::Edges(20), SimplifyMode::Regular)
        .expect_err("20 edges cannot hold five tori");
    let text = error.to_string();
    assert!(
        text.contains("genus 5, 0 boundary loops and 5 parts"),
        "{text}"
    );
    let SimplifyError::BelowMinimum { fewest, .. } = error else {
        panic!("{text}");
    };
    // The fewest named is reached, and is a real minimum: a torus needs at least 21
    // edges (7 vertices).
    assert!((5 * 21..=5 * 30).contains(&fewest), "{fewest}");
    let (simplified, _) = simplify(&mesh, Budget::Edges(fewest), SimplifyMode::Regular)
        .expect("the fewest named works");
    assert_eq!(simplified.topology().genus, 5);
}
