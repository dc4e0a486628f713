//! Plain-weaving cycles of the extended graph rotation system (SPEC.md §2, woven): the
//! counts and lengths the spec requires on the platonic solids and on quad tori, and
//! the weave invariants on every model.

use std::path::PathBuf;

use glam::DVec3;
use unfold::mesh::{build_from_faces, prepare, read_model, Mesh, PrepareOptions};
use unfold::scheme::woven::ergs::{trace_cycles, Side, WeaveCycle};

fn model(name: &str) -> Mesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name);
    let raw = read_model(&path).unwrap();
    prepare(&raw, &PrepareOptions::default()).unwrap().mesh
}

/// An n × m quad torus (n around the big circle, m around the tube).
fn torus(n: usize, m: usize) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let v = std::f64::consts::TAU * j as f64 / m as f64;
            let r = 3.0 + v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        .collect();
    build_from_faces(positions, &faces).unwrap()
}

fn all_twisted(mesh: &Mesh) -> Vec<WeaveCycle> {
    trace_cycles(mesh, &vec![true; mesh.edge_count()]).unwrap()
}

fn sorted_lengths(cycles: &[WeaveCycle]) -> Vec<usize> {
    let mut lengths: Vec<usize> = cycles.iter().map(WeaveCycle::len).collect();
    lengths.sort();
    lengths
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Every edge crossed exactly twice, once over and once under; every face corner
/// passed exactly once; over and under strictly alternate along each cycle (cycles of
/// odd length cannot alternate and must not occur); steps alternate sides.
fn assert_plain_weave(mesh: &Mesh, cycles: &[WeaveCycle], what: &str) {
    let mut crossings = vec![(0usize, 0usize); mesh.edge_count()];
    let mut corners = vec![0usize; mesh.half_edge_count()];
    for (k, cycle) in cycles.iter().enumerate() {
        assert_eq!(cycle.len() % 2, 0, "{what}: cycle {k} has odd length");
        for (i, (&h, over)) in cycle.darts.iter().zip(&cycle.over).enumerate() {
            let over = over.expect("every edge is twisted");
            let slot = &mut crossings[h.edge().index()];
            if over {
                slot.0 += 1;
            } else {
                slot.1 += 1;
            }
            let next_over = cycle.over[(i + 1) % cycle.len()].unwrap();
            assert_ne!(
                over, next_over,
                "{what}: cycle {k} does not alternate at step {i}"
            );
            let next_side = cycle.sides[(i + 1) % cycle.len()];
            assert_ne!(
                cycle.sides[i], next_side,
                "{what}: cycle {k} is not a zig-zag"
            );
            corners[cycle.corners[i].index()] += 1;
        }
    }
    for (e, &(over, under)) in crossings.iter().enumerate() {
        assert_eq!(
            (over, under),
            (1, 1),
            "{what}: edge {e} crossings (over, under)"
        );
    }
    for h in mesh.half_edges() {
        let expected = usize::from(!mesh.is_boundary_half_edge(h));
        assert_eq!(corners[h.index()], expected, "{what}: corner of {h}");
    }
    let total: usize = cycles.iter().map(WeaveCycle::len).sum();
    assert_eq!(total, 2 * mesh.edge_count(), "{what}: total length");
}

#[test]
fn platonic_solids_have_the_known_cycles() {
    for (name, count, length) in [
        ("tetrahedron.obj", 3, 4),
        ("hexahedron.obj", 4, 6),
        ("octahedron.obj", 4, 6),
        ("icosahedron.obj", 6, 10),
        ("dodecahedron.obj", 6, 10),
    ] {
        let mesh = model(name);
        let cycles = all_twisted(&mesh);
        assert_eq!(sorted_lengths(&cycles), vec![length; count], "{name}");
        assert_plain_weave(&mesh, &cycles, name);
    }
}

#[test]
fn quad_tori_have_two_gcd_cycles() {
    for (n, m) in [
        (8, 6),
        (6, 4),
        (5, 3),
        (6, 6),
        (12, 8),
        (7, 4),
        (9, 6),
        (3, 3),
    ] {
        let mesh = torus(n, m);
        let cycles = all_twisted(&mesh);
        assert_eq!(cycles.len(), 2 * gcd(n, m), "torus {n}x{m}");
        assert_plain_weave(&mesh, &cycles, &format!("torus {n}x{m}"));
    }
    // The project's own tori too.
    for (name, n, m) in [("torus-8x6.obj", 8, 6), ("torus-6x4.obj", 6, 4)] {
        let mesh = model(name);
        let cycles = all_twisted(&mesh);
        assert_eq!(cycles.len(), 2 * gcd(n, m), "{name}");
        assert_plain_weave(&mesh, &cycles, name);
    }
}

#[test]
fn higher_genus_and_concave_models_weave() {
    for name in ["genus2.obj", "genus3.obj", "concave.obj"] {
        let mesh = model(name);
        let cycles = all_twisted(&mesh);
        assert_plain_weave(&mesh, &cycles, name);
    }
}

#[test]
fn no_twist_gives_the_faces() {
    for name in ["hexahedron.obj", "dodecahedron.obj", "genus2.obj"] {
        let mesh = model(name);
        let cycles = trace_cycles(&mesh, &vec![false; mesh.edge_count()]).unwrap();
        assert_eq!(cycles.len(), mesh.face_count(), "{name}");
        for cycle in &cycles {
            assert!(cycle.sides.iter().all(|&s| s == Side::Left));
            let f = mesh.face(cycle.darts[0]).unwrap();
            assert_eq!(cycle.len(), mesh.face_degree(f), "{name}");
            assert!(cycle.darts.iter().all(|&h| mesh.face(h) == Some(f)));
        }
    }
}

#[test]
fn over_under_depends_on_orientation_not_on_the_start() {
    // A crossing joins two face corners; its over/under must not depend on where the
    // tracing starts or on the face numbering. Trace a renumbered copy (faces listed
    // in reverse order, so every walk starts elsewhere) and compare crossing by
    // crossing.
    type CornerKey = (u32, u32, u32);
    let corner_key = |mesh: &Mesh, c: unfold::mesh::HalfedgeId| -> CornerKey {
        // The corner at dest(c) between c and next(c): its vertex and its two
        // neighbours in the face identify it on a manifold mesh.
        let w = mesh.vertex_source(mesh.dest(c));
        let a = mesh.vertex_source(mesh.origin(c));
        let b = mesh.vertex_source(mesh.dest(mesh.next(c)));
        (w, a.min(b), a.max(b))
    };
    let crossings = |mesh: &Mesh| {
        let mut table = std::collections::BTreeMap::new();
        for cycle in all_twisted(mesh) {
            let n = cycle.len();
            for i in 0..n {
                let from = corner_key(mesh, cycle.corners[(i + n - 1) % n]);
                let to = corner_key(mesh, cycle.corners[i]);
                let key = if from < to { (from, to) } else { (to, from) };
                let previous = table.insert(key, cycle.over[i].unwrap());
                assert!(previous.is_none(), "crossing {key:?} walked twice");
            }
        }
        table
    };
    let mesh = model("icosahedron.obj");
    let mut faces: Vec<Vec<u32>> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).map(|v| v.0).collect())
        .collect();
    faces.reverse();
    let reordered = build_from_faces(mesh.positions().to_vec(), &faces).unwrap();
    let a = crossings(&mesh);
    let b = crossings(&reordered);
    assert_eq!(a.len(), 2 * mesh.edge_count());
    assert_eq!(a, b);
}

#[test]
fn open_meshes_are_refused() {
    let mesh = model("open-grid.obj");
    assert!(trace_cycles(&mesh, &vec![true; mesh.edge_count()]).is_err());
}
