//! Reading and building the half-edge mesh: a generated 1M-face quad torus and the
//! shared models when present, and simplifying the shared models. Run with
//! `cargo bench --bench mesh_build`.

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;

use unfold::mesh::simplify::{
    decimate_to, simplify, Budget, SimplifyError, SimplifyMode, SimplifyReport,
};
use unfold::mesh::{build_mesh, prepare, read_model, Mesh, Polygons, PrepareOptions};

/// An n × m quad torus as polygons (radii 100 and 40).
fn torus(n: usize, m: usize) -> Polygons {
    let mut positions = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = std::f64::consts::TAU * j as f64 / m as f64;
            let r = 100.0 + 40.0 * v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), 40.0 * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut polys = Polygons {
        positions,
        ..Polygons::new()
    };
    for i in 0..n {
        for j in 0..m {
            polys.push_face(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    polys
}

fn write_obj(polys: &Polygons, path: &Path) {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(polys.face_count() * 60);
    for p in &polys.positions {
        let _ = writeln!(s, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z);
    }
    for face in polys.faces() {
        let _ = writeln!(
            s,
            "f {} {} {} {}",
            face[0] + 1,
            face[1] + 1,
            face[2] + 1,
            face[3] + 1
        );
    }
    std::fs::write(path, s).unwrap();
}

fn mesh_build(c: &mut Criterion) {
    let polys = torus(1000, 1000);
    let mut group = c.benchmark_group("million-quads");
    group.sample_size(10);
    group.bench_function("build_mesh", |b| {
        b.iter(|| build_mesh(&polys, None, None).unwrap())
    });
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus-1M.obj");
    write_obj(&polys, &path);
    group.bench_function("read_model+prepare", |b| {
        b.iter(|| {
            let raw = read_model(&path).unwrap();
            prepare(&raw, &PrepareOptions::default()).unwrap()
        })
    });
    group.finish();

    let shared = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/models");
    if !shared.is_dir() {
        eprintln!("skipping shared models: {} is absent", shared.display());
        return;
    }
    let mut group = c.benchmark_group("shared-models");
    group.sample_size(10);
    for name in ["spot.obj", "stanford-bunny.obj"] {
        let path = shared.join(name);
        group.bench_function(name, |b| {
            b.iter(|| {
                let raw = read_model(&path).unwrap();
                prepare(&raw, &PrepareOptions::default()).unwrap()
            })
        });
    }
    group.finish();
    simplification(c, &shared);
}

/// The models and edge budgets of the simplification table.
const SIMPLIFIED: [(&str, &[usize]); 4] = [
    ("stanford-bunny.obj", &[625]),
    ("spot.obj", &[290, 600, 1000, 1400]),
    ("fertility.obj", &[300, 600]),
    ("horse_quad.obj", &[300, 600]),
];

/// Each shared model to its budgets in both modes, by the pipeline (meshoptimizer's
/// result where it keeps the topology) and by the decimator alone: the edges, the
/// deviation and the spread of the edge lengths of each are printed beside the time of
/// one run; the bunny to the thesis' 625 edges is also timed by criterion.
fn simplification(c: &mut Criterion, shared: &Path) {
    let mut group = c.benchmark_group("simplify-bunny-625");
    group.sample_size(10);
    for (name, budgets) in SIMPLIFIED {
        let Ok(raw) = read_model(&shared.join(name)) else {
            eprintln!("skipping {name}: not in {}", shared.display());
            continue;
        };
        let mesh = prepare(&raw, &PrepareOptions::default()).unwrap().mesh;
        for &edges in budgets {
            let budget = Budget::Edges(edges);
            for mode in [SimplifyMode::Regular, SimplifyMode::Accurate] {
                let ways: [(&str, SimplifyFn); 2] =
                    [("pipeline", simplify), ("decimator", decimate_to)];
                for (way, run) in ways {
                    let start = std::time::Instant::now();
                    let result = run(&mesh, budget, mode);
                    let time = start.elapsed().as_secs_f64();
                    match result {
                        Ok((_, r)) => eprintln!(
                            "{name} to {edges} edges, {mode}, {way}: {} edges in {time:.3} s, deviation {:.3e} at most, {:.3e} mean (model units), longest edge {:.2} and 95 % within {:.2} times the median{}",
                            r.after.1,
                            r.deviation,
                            r.mean_deviation,
                            r.edge_spread,
                            r.edge_spread_95,
                            r.fallback.map(|f| format!(" ({f})")).unwrap_or_default()
                        ),
                        Err(e) => eprintln!("{name} to {edges} edges, {mode}, {way}: {e}"),
                    }
                    if name == "stanford-bunny.obj" {
                        group.bench_function(format!("{mode}/{way}"), |b| {
                            b.iter(|| run(&mesh, budget, mode).unwrap())
                        });
                    }
                }
            }
        }
    }
    group.finish();
}

type SimplifyFn = fn(&Mesh, Budget, SimplifyMode) -> Result<(Mesh, SimplifyReport), SimplifyError>;

criterion_group!(benches, mesh_build);
criterion_main!(benches);
