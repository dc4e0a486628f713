//! Property tests of the half-edge builder and the prepare stage on generated polygon
//! meshes whose topology is known by construction:
//!
//! - grids of quads and triangles (random diagonals), with separated interior holes,
//!   optionally wrapped into a cylinder or a torus;
//! - fans and strips of n-gons (3..9 corners), several per mesh, optionally glued at one
//!   vertex (a bow-tie the builder must split);
//! - random subsets of those with random faces flipped, written as OBJ and sent through
//!   `read_model` + `prepare`, which must restore a consistent orientation.

use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::io::Write as _;

use glam::DVec3;
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

use unfold::mesh::{
    build_from_faces, build_mesh, prepare, read_model, FaceId, HalfedgeId, Mesh, Polygons,
    PrepareOptions, VertexId,
};

// ---------------------------------------------------------------------------------------
// Generated meshes and what we know about them
// ---------------------------------------------------------------------------------------

/// A polygon soup and its topology, known from the construction.
#[derive(Clone, Debug)]
struct Soup {
    positions: Vec<DVec3>,
    faces: Vec<Vec<u32>>,
    /// (genus, boundary loops) of every connected component, in no particular order.
    components: Vec<(i64, usize)>,
    /// Vertices of the built mesh (after bow-tie splits).
    mesh_vertices: usize,
    /// Soup vertices the builder must split, with their number of fans.
    split_vertices: Vec<(u32, u32)>,
}

impl Soup {
    fn euler(&self) -> i64 {
        self.components
            .iter()
            .map(|&(g, b)| 2 - 2 * g - b as i64)
            .sum()
    }
    fn genus(&self) -> i64 {
        self.components.iter().map(|&(g, _)| g).sum()
    }
    fn boundary_loops(&self) -> usize {
        self.components.iter().map(|&(_, b)| b).sum()
    }
}

/// A grid of `m × n` cells; `cells[j * m + i]` is 0 (quad), 1 or 2 (two triangles split
/// along one diagonal or the other); `holes` marks cells to delete where allowed.
#[derive(Clone, Debug)]
struct GridSpec {
    m: usize,
    n: usize,
    wrap_x: bool,
    wrap_y: bool,
    cells: Vec<u8>,
    holes: Vec<bool>,
}

impl GridSpec {
    /// Holes only at cells with both coordinates odd and a cell to spare on every side:
    /// no two holes touch (not even at a corner), no hole touches the border, so every
    /// hole is its own boundary loop and no vertex becomes a bow-tie.
    fn hole_allowed(&self, i: usize, j: usize) -> bool {
        i % 2 == 1 && j % 2 == 1 && i + 2 <= self.m && j + 2 <= self.n
    }

    fn is_hole(&self, i: usize, j: usize) -> bool {
        self.holes[j * self.m + i] && self.hole_allowed(i, j)
    }

    fn soup(&self) -> Soup {
        let (m, n) = (self.m, self.n);
        let wx = if self.wrap_x { m } else { m + 1 };
        let wy = if self.wrap_y { n } else { n + 1 };
        let vid = |i: usize, j: usize| ((i % wx) + (j % wy) * wx) as u32;
        let mut positions = Vec::with_capacity(wx * wy);
        for j in 0..wy {
            for i in 0..wx {
                let a = TAU * i as f64 / m as f64;
                let b = TAU * j as f64 / n as f64;
                positions.push(match (self.wrap_x, self.wrap_y) {
                    (false, false) => DVec3::new(i as f64, j as f64, 0.0),
                    (true, false) => DVec3::new(2.0 * a.cos(), 2.0 * a.sin(), j as f64),
                    (false, true) => DVec3::new(i as f64, 2.0 * b.cos(), 2.0 * b.sin()),
                    (true, true) => {
                        let r = 3.0 + b.cos();
                        DVec3::new(r * a.cos(), r * a.sin(), b.sin())
                    }
                });
            }
        }
        let mut faces = Vec::new();
        let mut holes = 0;
        for j in 0..n {
            for i in 0..m {
                if self.is_hole(i, j) {
                    holes += 1;
                    continue;
                }
                let (a, b, c, d) = (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1));
                match self.cells[j * m + i] {
                    0 => faces.push(vec![a, b, c, d]),
                    1 => {
                        faces.push(vec![a, b, c]);
                        faces.push(vec![a, c, d]);
                    }
                    _ => {
                        faces.push(vec![a, b, d]);
                        faces.push(vec![b, c, d]);
                    }
                }
            }
        }
        let (genus, border_loops) = match (self.wrap_x, self.wrap_y) {
            (false, false) => (0, 1), // a disk
            (true, true) => (1, 0),   // a torus
            _ => (0, 2),              // a cylinder
        };
        Soup {
            positions,
            faces,
            components: vec![(genus, border_loops + holes)],
            mesh_vertices: wx * wy,
            split_vertices: Vec::new(),
        }
    }
}

fn grid_spec() -> impl Strategy<Value = GridSpec> {
    (
        1usize..12,
        1usize..12,
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_flat_map(|(m, n, wrap_x, wrap_y, with_holes)| {
            (
                Just(m),
                Just(n),
                // A wrapped dimension needs at least 3 cells, or edges would repeat.
                Just(wrap_x && m >= 3),
                Just(wrap_y && n >= 3),
                vec(0u8..3, m * n),
                vec(any::<bool>().prop_map(move |h| h && with_holes), m * n),
            )
        })
        .prop_map(|(m, n, wrap_x, wrap_y, cells, holes)| GridSpec {
            m,
            n,
            wrap_x,
            wrap_y,
            cells,
            holes,
        })
}

/// One disk-shaped piece made of n-gons.
#[derive(Clone, Debug)]
enum Piece {
    /// Polygons all around a centre vertex (the centre is interior).
    ClosedFan(Vec<usize>),
    /// Polygons around a centre vertex, not closing up (the centre is on the boundary).
    OpenFan(Vec<usize>),
    /// Polygons glued in a chain, each to an edge of the one before it, chosen at random.
    Strip(Vec<(usize, usize)>),
}

/// Vertex 0 of every piece is at the origin (the fan centre, the strip's first corner).
/// Returns (positions, faces), indices local to the piece. Every piece is a disk.
fn piece_polygons(piece: &Piece) -> (Vec<DVec3>, Vec<Vec<u32>>) {
    let mut positions = vec![DVec3::ZERO];
    let mut faces = Vec::new();
    match piece {
        Piece::ClosedFan(sizes) | Piece::OpenFan(sizes) => {
            let closed = matches!(piece, Piece::ClosedFan(_));
            let sectors = sizes.len();
            let ring = if closed { sectors } else { sectors + 1 };
            let span = if closed { TAU } else { 0.75 * TAU };
            let angle = |k: f64| span * k / sectors as f64;
            for k in 0..ring {
                let a = angle(k as f64);
                positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
            }
            for (s, &size) in sizes.iter().enumerate() {
                let r0 = 1 + s as u32;
                let r1 = 1 + ((s + 1) % ring) as u32;
                let mut face = vec![0, r0];
                let fresh = size - 3;
                for k in 0..fresh {
                    let a = angle(s as f64 + (k + 1) as f64 / (fresh + 1) as f64);
                    face.push(positions.len() as u32);
                    positions.push(DVec3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.0));
                }
                face.push(r1);
                faces.push(face);
            }
        }
        Piece::Strip(polygons) => {
            // Points on the moment curve: no three are collinear, so no face has zero
            // area whatever the corners.
            let point = |positions: &mut Vec<DVec3>| {
                let t = positions.len() as f64 * 0.25;
                positions.push(DVec3::new(t, t * t, t * t * t));
                positions.len() as u32 - 1
            };
            let (first, _) = polygons[0];
            let mut face = vec![0];
            for _ in 1..first {
                face.push(point(&mut positions));
            }
            faces.push(face);
            // The edge of the previous polygon glued to the next one: never the edge
            // it was itself glued by (its first edge, for every polygon but the first).
            for &(size, choice) in &polygons[1..] {
                let prev = faces.last().unwrap().clone();
                let k = 1 + choice % (prev.len() - 1);
                let (p, q) = (prev[k], prev[(k + 1) % prev.len()]);
                let mut face = vec![q, p];
                for _ in 2..size {
                    face.push(point(&mut positions));
                }
                faces.push(face);
            }
        }
    }
    (positions, faces)
}

fn piece() -> impl Strategy<Value = Piece> {
    let size = 3usize..10;
    prop_oneof![
        vec(size.clone(), 3..8).prop_map(Piece::ClosedFan),
        vec(size.clone(), 1..8).prop_map(Piece::OpenFan),
        vec((size, 0usize..64), 1..10).prop_map(Piece::Strip),
    ]
}

/// Several pieces, disjoint or all glued at their vertex 0 (a bow-tie vertex).
#[derive(Clone, Debug)]
struct PiecesSpec {
    pieces: Vec<Piece>,
    glued: bool,
}

impl PiecesSpec {
    fn soup(&self) -> Soup {
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        let mut mesh_vertices = 0;
        for (k, piece) in self.pieces.iter().enumerate() {
            let (local_positions, local_faces) = piece_polygons(piece);
            mesh_vertices += local_positions.len();
            // Turn and scale each piece differently about vertex 0 and, when not glued,
            // move it away, so that no two vertices share a position (`--weld` would
            // merge them).
            let (s, c) = (k as f64 * 0.7).sin_cos();
            let scale = 1.0 + 0.37 * k as f64;
            let shift = if self.glued { 0.0 } else { 10.0 * k as f64 };
            let place = |p: DVec3| {
                scale * DVec3::new(p.x, c * p.y - s * p.z, s * p.y + c * p.z)
                    + DVec3::new(0.0, 0.0, shift)
            };
            let glue = self.glued && k > 0;
            let base = positions.len() as u32;
            let index = |v: u32| {
                if glue {
                    if v == 0 {
                        0
                    } else {
                        base + v - 1
                    }
                } else {
                    base + v
                }
            };
            let skip = usize::from(glue);
            positions.extend(local_positions.into_iter().skip(skip).map(place));
            faces.extend(
                local_faces
                    .into_iter()
                    .map(|f| f.into_iter().map(index).collect::<Vec<u32>>()),
            );
        }
        let split_vertices = if self.glued && self.pieces.len() > 1 {
            vec![(0, self.pieces.len() as u32)]
        } else {
            Vec::new()
        };
        Soup {
            positions,
            faces,
            components: vec![(0, 1); self.pieces.len()],
            mesh_vertices,
            split_vertices,
        }
    }
}

fn pieces_spec() -> impl Strategy<Value = PiecesSpec> {
    (vec(piece(), 1..4), any::<bool>()).prop_map(|(pieces, glued)| PiecesSpec { pieces, glued })
}

/// Either kind of generated mesh.
fn any_soup() -> impl Strategy<Value = Soup> {
    prop_oneof![
        grid_spec().prop_map(|g| g.soup()),
        pieces_spec().prop_map(|p| p.soup()),
    ]
}

// ---------------------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------------------

/// True when `b` is a cyclic rotation of `a`.
fn same_cycle(a: &[u32], b: &[u32]) -> bool {
    a.len() == b.len()
        && (a.is_empty()
            || (0..a.len()).any(|r| (0..a.len()).all(|i| a[(i + r) % a.len()] == b[i])))
}

/// The corners of face `f` as input vertex indices (through `vertex_source`).
fn face_sources(mesh: &Mesh, f: FaceId) -> Vec<u32> {
    mesh.face_vertices(f)
        .map(|v| mesh.vertex_source(v))
        .collect()
}

/// The face's half-edges, walked by `next` with a step limit (a broken loop cannot hang
/// the test), checking that every one of them belongs to the face.
fn walk_face(mesh: &Mesh, f: FaceId) -> Result<Vec<HalfedgeId>, TestCaseError> {
    let start = mesh.face_half_edge(f);
    let mut loop_ = vec![start];
    let mut h = mesh.next(start);
    while h != start {
        prop_assert!(
            loop_.len() <= mesh.half_edge_count(),
            "the loop of {f} does not close"
        );
        loop_.push(h);
        h = mesh.next(h);
    }
    for &h in &loop_ {
        prop_assert_eq!(mesh.face(h), Some(f), "{} is in the loop of {}", h, f);
    }
    Ok(loop_)
}

/// Every connectivity invariant of a built mesh against the polygons it came from
/// (`input[mesh.face_source(f)]`). With `exact_orientation`, each face must have its
/// input's cyclic corner order; otherwise that order or its reverse.
fn check_mesh(
    mesh: &Mesh,
    input: &[Vec<u32>],
    exact_orientation: bool,
) -> Result<(), TestCaseError> {
    prop_assert_eq!(mesh.validate(), Ok(()));
    prop_assert_eq!(mesh.half_edge_count(), 2 * mesh.edge_count());
    for h in mesh.half_edges() {
        prop_assert_eq!(mesh.twin(mesh.twin(h)), h);
        prop_assert_ne!(mesh.twin(h), h);
        prop_assert_eq!(mesh.next(mesh.prev(h)), h);
        prop_assert_eq!(mesh.prev(mesh.next(h)), h);
        prop_assert_eq!(mesh.origin(mesh.next(h)), mesh.dest(h));
        prop_assert_eq!(mesh.dest(h), mesh.origin(mesh.twin(h)));
        prop_assert_ne!(mesh.origin(h), mesh.dest(h));
        // Every edge has a face on at least one side.
        prop_assert!(mesh.face(h).is_some() || mesh.face(mesh.twin(h)).is_some());
    }

    prop_assert_eq!(mesh.face_count(), input.len());
    let mut degree_sum = 0;
    for f in mesh.faces() {
        let loop_ = walk_face(mesh, f)?;
        let source = &input[mesh.face_source(f) as usize];
        prop_assert_eq!(loop_.len(), source.len(), "degree of {}", f);
        prop_assert_eq!(mesh.face_degree(f), source.len());
        let corners = face_sources(mesh, f);
        let reversed: Vec<u32> = source.iter().rev().copied().collect();
        if exact_orientation {
            prop_assert!(
                same_cycle(source, &corners),
                "{f}: corners {corners:?}, input {source:?}"
            );
        } else {
            prop_assert!(
                same_cycle(source, &corners) || same_cycle(&reversed, &corners),
                "{f}: corners {corners:?}, input {source:?} in either direction"
            );
        }
        degree_sum += source.len();
    }

    let face_half_edges = mesh
        .half_edges()
        .filter(|&h| mesh.face(h).is_some())
        .count();
    let boundary_half_edges = mesh
        .half_edges()
        .filter(|&h| mesh.is_boundary_half_edge(h))
        .count();
    prop_assert_eq!(face_half_edges, degree_sum);
    prop_assert_eq!(mesh.edge_count(), (degree_sum + boundary_half_edges) / 2);
    prop_assert_eq!((degree_sum + boundary_half_edges) % 2, 0);

    // A vertex is a boundary vertex exactly when one of its half-edges is, and turning
    // around it visits each outgoing half-edge once.
    let mut outgoing = vec![0usize; mesh.vertex_count()];
    for h in mesh.half_edges() {
        outgoing[mesh.origin(h).index()] += 1;
    }
    for v in mesh.vertices() {
        let fan: Vec<HalfedgeId> = mesh.vertex_outgoing(v).collect();
        prop_assert_eq!(fan.len(), outgoing[v.index()], "fan of {}", v);
        prop_assert!(fan.iter().all(|&h| mesh.origin(h) == v));
        prop_assert_eq!(
            mesh.is_boundary_vertex(v),
            fan.iter().any(|&h| mesh.is_boundary_half_edge(h)),
            "boundary status of {}",
            v
        );
    }
    Ok(())
}

/// Counts, Euler characteristic and `topology()` against the construction.
fn check_topology(mesh: &Mesh, soup: &Soup) -> Result<(), TestCaseError> {
    let v = mesh.vertex_count() as i64;
    let e = mesh.edge_count() as i64;
    let f = mesh.face_count() as i64;
    prop_assert_eq!(mesh.vertex_count(), soup.mesh_vertices);
    prop_assert_eq!(v - e + f, soup.euler(), "V - E + F");

    let t = mesh.topology();
    prop_assert_eq!(t.vertices, mesh.vertex_count());
    prop_assert_eq!(t.edges, mesh.edge_count());
    prop_assert_eq!(t.faces, mesh.face_count());
    prop_assert_eq!(t.euler_characteristic, soup.euler());
    prop_assert_eq!(t.genus, soup.genus());
    prop_assert_eq!(t.boundary_loops, soup.boundary_loops());
    prop_assert_eq!(mesh.boundary_loops().len(), soup.boundary_loops());
    prop_assert_eq!(
        t.boundary_edges,
        mesh.edges().filter(|&e| mesh.is_boundary_edge(e)).count()
    );
    prop_assert_eq!(t.components.len(), soup.components.len());
    let mut found: Vec<(i64, usize)> = t
        .components
        .iter()
        .map(|c| (c.genus, c.boundary_loops))
        .collect();
    let mut expected = soup.components.clone();
    found.sort_unstable();
    expected.sort_unstable();
    prop_assert_eq!(found, expected);
    for c in &t.components {
        prop_assert_eq!(c.closed, c.boundary_loops == 0);
        prop_assert_eq!(
            c.euler_characteristic,
            2 - 2 * c.genus - c.boundary_loops as i64
        );
    }
    let sizes: usize = t.face_sizes.values().sum();
    prop_assert_eq!(sizes, mesh.face_count());
    Ok(())
}

/// Everything observable through the public API, for comparing two builds.
fn fingerprint(mesh: &Mesh) -> impl PartialEq + std::fmt::Debug {
    let faces: Vec<Vec<VertexId>> = mesh
        .faces()
        .map(|f| mesh.face_vertices(f).collect())
        .collect();
    let half_edges: Vec<_> = mesh
        .half_edges()
        .map(|h| (mesh.next(h), mesh.prev(h), mesh.origin(h), mesh.face(h)))
        .collect();
    let vertices: Vec<_> = mesh
        .vertices()
        .map(|v| {
            (
                mesh.position(v),
                mesh.vertex_half_edge(v),
                mesh.vertex_source(v),
            )
        })
        .collect();
    let face_data: Vec<_> = mesh
        .faces()
        .map(|f| (mesh.face_half_edge(f), mesh.face_source(f)))
        .collect();
    (
        mesh.half_edge_count(),
        faces,
        half_edges,
        vertices,
        face_data,
    )
}

/// Writes positions and faces as OBJ text (1-based indices).
fn obj_text(positions: &[DVec3], faces: &[Vec<u32>]) -> String {
    let mut s = String::from("# generated by tests/halfedge_properties.rs\n");
    for p in positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for face in faces {
        s.push('f');
        for &v in face {
            let _ = write!(s, " {}", v + 1);
        }
        s.push('\n');
    }
    s
}

/// The number at the start of the note of `kind`, 0 when there is no such note.
fn note_count(notes: &[unfold::mesh::Note], kind: &str) -> usize {
    notes
        .iter()
        .find(|n| n.kind == kind)
        .map(|n| {
            let digits: String = n.message.chars().take_while(char::is_ascii_digit).collect();
            digits.parse().expect("a note starts with its count")
        })
        .unwrap_or(0)
}

/// Six times the signed volume enclosed by the given faces.
fn signed_volume(mesh: &Mesh, faces: &[FaceId]) -> f64 {
    faces
        .iter()
        .map(|&f| {
            let p: Vec<DVec3> = mesh.face_positions(f).collect();
            (1..p.len() - 1)
                .map(|k| p[0].dot(p[k].cross(p[k + 1])))
                .sum::<f64>()
        })
        .sum()
}

// ---------------------------------------------------------------------------------------
// Properties
// ---------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Grids, cylinders and tori with holes: every invariant, and the topology the
    /// construction predicts.
    #[test]
    fn grid_meshes_build_valid_with_known_topology(spec in grid_spec()) {
        let soup = spec.soup();
        let mesh = build_from_faces(soup.positions.clone(), &soup.faces)
            .map_err(|e| TestCaseError::fail(format!("build failed: {e}")))?;
        check_mesh(&mesh, &soup.faces, true)?;
        check_topology(&mesh, &soup)?;
        // No bow-ties in a grid: vertex ids are the input's own.
        for v in mesh.vertices() {
            prop_assert_eq!(mesh.vertex_source(v), v.0);
        }
    }

    /// Fans and strips of 3..9-gons, several per mesh, possibly glued at one vertex:
    /// every invariant, the topology, and the bow-tie split in the build report.
    #[test]
    fn fans_and_strips_build_valid_with_known_topology(spec in pieces_spec()) {
        let soup = spec.soup();
        let polys = Polygons::from_faces(soup.positions.clone(), &soup.faces);
        let (mesh, report) = build_mesh(&polys, None, None)
            .map_err(|e| TestCaseError::fail(format!("build failed: {e}")))?;
        check_mesh(&mesh, &soup.faces, true)?;
        check_topology(&mesh, &soup)?;
        prop_assert_eq!(&report.split_vertices, &soup.split_vertices);
        // Split copies are appended after the soup's own vertices, at the same position.
        for v in mesh.vertices() {
            let source = mesh.vertex_source(v);
            prop_assert_eq!(mesh.position(v), soup.positions[source as usize]);
            if v.index() < soup.positions.len() {
                prop_assert_eq!(source, v.0);
            }
        }
    }

    /// Building the same polygons twice gives the same mesh, handle for handle.
    #[test]
    fn building_is_deterministic(soup in any_soup()) {
        let a = build_from_faces(soup.positions.clone(), &soup.faces)
            .map_err(|e| TestCaseError::fail(format!("build failed: {e}")))?;
        let b = build_from_faces(soup.positions.clone(), &soup.faces)
            .map_err(|e| TestCaseError::fail(format!("build failed: {e}")))?;
        prop_assert_eq!(fingerprint(&a), fingerprint(&b));
    }

    /// A random subset of faces, some flipped, through OBJ text, `read_model` and
    /// `prepare`: it never panics; it fails (with an `InputError`) only when no face is
    /// left; otherwise the mesh is valid, keeps every face with its degree, and each
    /// component has the input's orientation up to one flip of the whole component.
    #[test]
    fn prepare_restores_orientation_of_flipped_subsets(
        (soup, keep, flip, weld) in any_soup().prop_flat_map(|soup| {
            let n = soup.faces.len();
            (
                Just(soup),
                vec(prop::bool::weighted(0.85), n),
                vec(prop::bool::weighted(0.3), n),
                any::<bool>(),
            )
        })
    ) {
        let mut original = Vec::new();
        let mut in_file = Vec::new();
        let mut flipped_in_file = Vec::new();
        for (f, face) in soup.faces.iter().enumerate() {
            if !keep[f] {
                continue;
            }
            original.push(face.clone());
            let mut written = face.clone();
            if flip[f] {
                written.reverse();
            }
            in_file.push(written);
            flipped_in_file.push(flip[f]);
        }
        let mut file = tempfile::Builder::new()
            .suffix(".obj")
            .tempfile()
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        file.write_all(obj_text(&soup.positions, &in_file).as_bytes())
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        file.flush().map_err(|e| TestCaseError::fail(e.to_string()))?;

        let result = read_model(file.path()).and_then(|raw| prepare(&raw, &PrepareOptions { weld }));
        let prepared = match result {
            Ok(p) => p,
            Err(e) => {
                prop_assert!(original.is_empty(), "prepare failed on {} faces: {}", original.len(), e);
                prop_assert!(e.to_string().contains("no faces"), "{}", e);
                return Ok(());
            }
        };
        prop_assert!(!original.is_empty());
        let mesh = &prepared.mesh;
        check_mesh(mesh, &original, false)?;
        prop_assert_eq!(prepared.input.faces, original.len());

        // One orientation per component: all faces as in the input, or all reversed.
        let (component, count) = mesh.face_components();
        let mut as_input: Vec<Option<bool>> = vec![None; count];
        let mut members: Vec<Vec<FaceId>> = vec![Vec::new(); count];
        for f in mesh.faces() {
            let c = component[f.index()] as usize;
            members[c].push(f);
            let same = same_cycle(&original[mesh.face_source(f) as usize], &face_sources(mesh, f));
            match as_input[c] {
                None => as_input[c] = Some(same),
                Some(s) => prop_assert_eq!(
                    s, same,
                    "{} (input face {}) is oriented unlike the rest of its component",
                    f, mesh.face_source(f)
                ),
            }
        }

        // prepare flips the minority of each component (inside-out turns aside).
        let expected_flips: usize = members
            .iter()
            .map(|faces| {
                let flipped = faces
                    .iter()
                    .filter(|&&f| flipped_in_file[mesh.face_source(f) as usize])
                    .count();
                flipped.min(faces.len() - flipped)
            })
            .sum();
        prop_assert_eq!(note_count(&prepared.notes, "flipped-faces"), expected_flips);

        // Closed components end up facing outward.
        let topology = mesh.topology();
        for faces in &members {
            let closed = faces.iter().all(|&f| {
                mesh.face_half_edges(f).all(|h| !mesh.is_boundary_half_edge(h.twin()))
            });
            if closed {
                prop_assert!(signed_volume(mesh, faces) > 0.0, "a closed part faces inward");
            }
        }
        prop_assert_eq!(topology.components.len(), count);
        prop_assert_eq!(topology.faces, original.len());
    }
}

// ---------------------------------------------------------------------------------------
// Fixed cases
// ---------------------------------------------------------------------------------------

#[test]
fn same_polygons_twice_give_identical_meshes() {
    let spec = GridSpec {
        m: 6,
        n: 4,
        wrap_x: true,
        wrap_y: true,
        cells: (0..24).map(|k| (k % 3) as u8).collect(),
        holes: vec![true; 24],
    };
    let soup = spec.soup();
    let a = build_from_faces(soup.positions.clone(), &soup.faces).unwrap();
    let b = build_from_faces(soup.positions.clone(), &soup.faces).unwrap();
    let faces = |m: &Mesh| -> Vec<Vec<VertexId>> {
        m.faces().map(|f| m.face_vertices(f).collect()).collect()
    };
    assert_eq!(faces(&a), faces(&b));
    assert_eq!(a.half_edge_count(), b.half_edge_count());
    assert_eq!(fingerprint(&a), fingerprint(&b));
    // A torus with holes at cells (1,1) and (3,1): genus 1, two boundary loops.
    let t = a.topology();
    assert_eq!((t.genus, t.boundary_loops, t.components.len()), (1, 2, 1));
    assert_eq!(t.euler_characteristic, -2);
}

#[test]
fn generators_cover_the_cases_they_claim() {
    // A disk with two separated holes.
    let spec = GridSpec {
        m: 5,
        n: 5,
        wrap_x: false,
        wrap_y: false,
        cells: vec![0; 25],
        holes: vec![true; 25],
    };
    let soup = spec.soup();
    assert_eq!(soup.faces.len(), 25 - 4); // holes at (1,1), (3,1), (1,3), (3,3)
    assert_eq!(soup.components, vec![(0, 5)]);
    let mesh = build_from_faces(soup.positions.clone(), &soup.faces).unwrap();
    assert_eq!(mesh.topology().boundary_loops, 5);

    // A strip glued at its first corner to a closed fan: one bow-tie split into two.
    let spec = PiecesSpec {
        pieces: vec![
            Piece::ClosedFan(vec![3, 4, 9]),
            Piece::Strip(vec![(3, 0), (5, 1)]),
        ],
        glued: true,
    };
    let soup = spec.soup();
    let polys = Polygons::from_faces(soup.positions.clone(), &soup.faces);
    let (mesh, report) = build_mesh(&polys, None, None).unwrap();
    assert_eq!(report.split_vertices, vec![(0, 2)]);
    assert_eq!(mesh.vertex_count(), soup.positions.len() + 1);
    assert_eq!(mesh.topology().components.len(), 2);
}
