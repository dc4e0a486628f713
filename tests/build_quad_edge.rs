//! End-to-end tests of the build pipeline with the quad-edge scheme (SPEC §2): one panel
//! per edge (a flap in each of its two faces joined by a bend of planar strips), one
//! connection per face corner joining the panels of the two edges that meet there.
//!
//! As in `tests/build_half_edge.rs`, the real binary writes its output folder into a
//! temporary directory and the independent sheet checker of `tests/common` reads it
//! back (every SVG; every DXF read back, only the first and the last for
//! fertility and horse_quad unless `UNFOLD_FULL_DXF=1`); the geometric facts are
//! checked at library level on the pipeline of `src/run/` (`common::build::pipeline`),
//! with the mesh the scheme used: counts against the mesh, holes followed back to 3D,
//! bend strips planar with rulings parallel to the edge and on the rails of the spec's
//! formula, flaps in their face, outlines simple, unrolling isometric.
//!
//! Tests that use `../shared/models` skip with a message when that folder is absent.
//!
//! `UNFOLD_UPDATE_GOLDEN=1 cargo test --test build_quad_edge golden` rewrites
//! `tests/golden/hexahedron-quad-edge/`.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use glam::{DVec2, DVec3};
use serde_json::Value;
use tempfile::TempDir;

use common::build::{
    build, check_output, check_sheets, connections_without_holes, count, distance_to_border,
    frames_of, golden_build, inside, inspect_json, model, num, number_after, pipeline,
    point_segment, read_simple_obj, resolve, segment_distance, shared_models, DxfCheck, Pipeline,
    Run,
};
use common::svg_circles;
use unfold::config::{BuildOptions, Job};
use unfold::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use unfold::panel::{Covers, FlatPanel, Fold, Panel};
use unfold::record::Field;
use unfold::scheme::edge::flaps::{BandArgs, EdgeOptions};
use unfold::scheme::edge::quad::MAX_FLAP_SCALE;

// =======================================================================================
// Helpers
// =======================================================================================

/// `unfold MODEL --scheme quad-edge --size SIZE --out OUT EXTRA…`: the manifest and the
/// run (its report is on stderr).
fn build_run(model: &Path, size: &str, out: &Path, extra: &[&str]) -> (Value, Run) {
    common::build::build_run("quad-edge", model, size, out, extra)
}

/// Build options of the quad-edge scheme, to adjust before `resolve`.
fn quad_options(size: &str, holes: u32, out: &Path) -> BuildOptions {
    common::build::options("quad-edge", size, holes, out)
}

/// The library-level twin of `unfold MODEL --scheme quad-edge --size SIZE --holes H
/// [--hole-diameter D] [--samples N]`.
fn quad_job(
    model: &Path,
    size: &str,
    holes: u32,
    hole_diameter: Option<&str>,
    samples: Option<u32>,
) -> Job {
    let mut options = quad_options(size, holes, Path::new("unused"));
    options.hole_diameter = hole_diameter.map(str::to_string);
    if let Some(n) = samples {
        options.scheme_values.set("samples", &n.to_string());
    }
    resolve(options, model)
}

/// The quad-edge job's own options, resolved again from what the job records of them
/// (the manifest's `scheme.params`).
fn edge_options(job: &Job) -> EdgeOptions {
    let params = job.scheme.options.params();
    let number = |key: &str| {
        params
            .0
            .iter()
            .find(|(k, _)| k == key)
            .and_then(|(_, f)| match f {
                Field::Value(v) => v.as_f64(),
                Field::Records(_) => None,
            })
    };
    BandArgs {
        bridge_scale: number("bridge_scale"),
        flap_scale: number("flap_scale"),
        samples: number("samples").map(|n| n as u32),
        ..BandArgs::default()
    }
    .resolve(job.scheme.panel().clone())
    .expect("quad-edge options")
}

/// Σ face degrees of a mesh (its face corners).
fn face_corners(mesh: &Mesh) -> usize {
    mesh.faces().map(|f| mesh.face_degree(f)).sum()
}

/// The edge a panel was made from.
fn edge_of(p: &FlatPanel) -> EdgeId {
    match p.source.covers {
        Covers::Edge(e) => EdgeId(e),
        other => panic!("{}: a quad-edge panel made from {other:?}", p.id()),
    }
}

/// Average of a face's corners (the spec's face centre c), computed here.
fn centre(mesh: &Mesh, f: FaceId) -> DVec3 {
    let corners: Vec<DVec3> = mesh.face_positions(f).collect();
    corners.iter().copied().sum::<DVec3>() / corners.len() as f64
}

/// Unit normal of a (planar) face from its corners (Newell).
fn normal(mesh: &Mesh, f: FaceId) -> DVec3 {
    let corners: Vec<DVec3> = mesh.face_positions(f).collect();
    let n = corners.len();
    (0..n)
        .map(|i| corners[i].cross(corners[(i + 1) % n]))
        .sum::<DVec3>()
        .normalize()
}

/// The spec's face band corner of vertex position `v` in face `f`, `s·v + (1−s)·c`,
/// projected onto the face's plane (through c, normal to the face): the edge schemes
/// put band corners in the plane so that flaps are flat on faces that are planar only
/// within the tolerance; on planar faces the projection moves nothing.
fn band_corner(mesh: &Mesh, f: FaceId, v: DVec3, s: f64) -> DVec3 {
    let c = centre(mesh, f);
    let n = normal(mesh, f);
    let p = s * v + (1.0 - s) * c;
    p - (p - c).dot(n) * n
}

/// The band scale of every face: `--face-scale`, or for a face whose corners could not
/// hold a hole otherwise a wider one, in four even steps up to 0.9 (the scheme's
/// documented widening). Read from the panels: the allowed scale whose band corner at
/// the origin of the face's first half-edge is a vertex of that edge's panel (the
/// panels are in edge order).
fn face_scales(p: &Pipeline, o: &EdgeOptions, tol: f64) -> Vec<f64> {
    let mesh = &p.mesh;
    let s0 = o.panel.face_scale;
    let allowed: Vec<f64> = (0..=4)
        .map(|i| s0 + (0.9 - s0).max(0.0) * f64::from(i) / 4.0)
        .collect();
    mesh.faces()
        .map(|f| {
            let h = mesh.face_half_edge(f);
            let v = mesh.position(mesh.origin(h));
            let panel = &p.panels[h.edge().0 as usize];
            let miss = |s: f64| {
                let b = band_corner(mesh, f, v, s);
                panel
                    .vertices
                    .iter()
                    .map(|q| q.distance(b))
                    .fold(f64::MAX, f64::min)
            };
            let best = allowed
                .iter()
                .copied()
                .min_by(|&a, &b| miss(a).total_cmp(&miss(b)))
                .unwrap();
            assert!(
                miss(best) <= tol,
                "face {}: its band corner is at no allowed scale ({:e} mm off)",
                f.0,
                miss(best)
            );
            best
        })
        .collect()
}

/// Largest distance between two of the points.
fn diameter<T: Copy>(points: &[T], dist: impl Fn(T, T) -> f64) -> f64 {
    let mut best = 0.0f64;
    for (i, &a) in points.iter().enumerate() {
        for &b in &points[i + 1..] {
            best = best.max(dist(a, b));
        }
    }
    best
}

fn signed_area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
        * 0.5
}

/// Why a closed polygon is not simple (edges that are not neighbours closer than `eps`,
/// or neighbours folding back onto each other), or `None`.
fn not_simple(poly: &[DVec2], eps: f64) -> Option<String> {
    let n = poly.len();
    if n < 3 {
        return Some(format!("{n} corners"));
    }
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        // The neighbour after: its far end must not lie on this edge, nor this edge's
        // start on it.
        let c = poly[(i + 2) % n];
        if n > 3 && (point_segment(c, a, b) < eps || point_segment(a, b, c) < eps) {
            return Some(format!("edges {i} and {} fold back at {b}", (i + 1) % n));
        }
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (c, d) = (poly[j], poly[(j + 1) % n]);
            let gap = segment_distance(a, b, c, d);
            if gap < eps {
                return Some(format!(
                    "edges {i} ({a} → {b}) and {j} ({c} → {d}) meet (gap {gap:e})"
                ));
            }
        }
    }
    None
}

/// The rulings of an interior-edge panel with `n` strips: the vertex pairs shared by
/// facets k and k + 1, k = 0..=n (flap | strip 1 | … | strip n | flap).
fn rulings(panel: &Panel, n: usize) -> Vec<[u32; 2]> {
    (0..=n)
        .map(|k| {
            let next: BTreeSet<u32> = panel.facets[k + 1].iter().copied().collect();
            let shared: Vec<u32> = panel.facets[k]
                .iter()
                .copied()
                .filter(|i| next.contains(i))
                .collect();
            assert_eq!(
                shared.len(),
                2,
                "{}: facets {k} and {} share {shared:?}, not one edge",
                panel.id(),
                k + 1
            );
            [shared[0], shared[1]]
        })
        .collect()
}

/// Quadratic Bézier point, written here.
fn bezier(p0: DVec3, p1: DVec3, p2: DVec3, t: f64) -> DVec3 {
    (1.0 - t) * (1.0 - t) * p0 + 2.0 * (1.0 - t) * t * p1 + t * t * p2
}

// =======================================================================================
// Facts checked on the flat panels of every model
// =======================================================================================

/// Every panel comes from its own edge (all edges once), the connections are the face
/// corners, interior-edge panels have `samples + 2` facets and boundary-edge panels one;
/// every flat outline is simple and counter-clockwise (outside up) and the facets tile it
/// (Σ facet areas = outline area, each facet counter-clockwise): no panel overlaps
/// itself.
fn check_panels(p: &Pipeline, job: &Job, what: &str) {
    let mesh = &p.mesh;
    let n = edge_options(job).samples as usize;
    assert_eq!(
        p.flat.len(),
        mesh.edge_count(),
        "{what}: one panel per edge"
    );
    let edges: BTreeSet<u32> = p.flat.iter().map(|fp| edge_of(fp).0).collect();
    assert_eq!(
        edges,
        (0..mesh.edge_count() as u32).collect(),
        "{what}: every edge has its panel"
    );
    assert_eq!(
        p.output.connections,
        face_corners(mesh),
        "{what}: connections = face corners"
    );
    for (panel, fp) in p.panels.iter().zip(&p.flat) {
        let e = edge_of(fp);
        assert_eq!(fp.id().to_string(), format!("E{}", e.0), "{what}: panel id");
        let facets = if mesh.is_boundary_edge(e) { 1 } else { n + 2 };
        assert_eq!(
            panel.facets.len(),
            facets,
            "{what}: {} ({}) has {} facets",
            fp.id(),
            if facets == 1 {
                "boundary edge"
            } else {
                "interior edge"
            },
            panel.facets.len()
        );
        assert_eq!(fp.outline.len(), 1, "{what}: {} has inner cuts", fp.id());
        let outer = fp.outer();
        let size = diameter(&outer, DVec2::distance);
        if let Some(why) = not_simple(&outer, 1e-9 * size) {
            panic!("{what}: panel {} overlaps itself: {why}", fp.id());
        }
        let area = signed_area(&outer);
        assert!(area > 0.0, "{what}: {} is laid face down", fp.id());
        let mut facets_area = 0.0;
        for (k, facet) in panel.facets.iter().enumerate() {
            let a = signed_area(&fp.loop_points(facet));
            assert!(
                a > 0.0,
                "{what}: {} facet {k} is flipped ({a} mm²)",
                fp.id()
            );
            facets_area += a;
        }
        assert!(
            (facets_area - area).abs() <= 1e-9 * area,
            "{what}: {} facets cover {facets_area} mm² of a {area} mm² outline: they overlap",
            fp.id()
        );
    }
}

/// Unrolling keeps every facet edge length, to `rel` of the panel's size (computed here
/// from the 3D and the flat corners); the flattener's own figure agrees. Returns the
/// worst relative error.
fn check_developable(p: &Pipeline, what: &str, rel: f64) -> f64 {
    let mut worst = 0.0f64;
    for (panel, fp) in p.panels.iter().zip(&p.flat) {
        let size = diameter(&fp.outer(), DVec2::distance);
        let mut error = 0.0f64;
        for facet in &panel.facets {
            for k in 0..facet.len() {
                let (i, j) = (facet[k] as usize, facet[(k + 1) % facet.len()] as usize);
                let d3 = panel.vertices[i].distance(panel.vertices[j]);
                let d2 = fp.points[i].distance(fp.points[j]);
                error = error.max((d3 - d2).abs());
            }
        }
        assert!(
            error <= rel * size && fp.developability_error <= rel * size,
            "{what}: {} changes a facet edge by {error:e} mm (flattener says {:e}) on a {size} mm panel",
            fp.id(),
            fp.developability_error
        );
        worst = worst.max(error / size);
    }
    worst
}

/// Every hole of every panel by the face it lies in (its connection's), with the two
/// edges whose panels it goes through.
fn holes_by_face(p: &Pipeline) -> BTreeMap<FaceId, Vec<(DVec3, [EdgeId; 2])>> {
    let mut by_face: BTreeMap<FaceId, Vec<(DVec3, [EdgeId; 2])>> = BTreeMap::new();
    for panel in &p.panels {
        for hole in &panel.holes {
            let h = HalfedgeId(hole.connection);
            let face = p.mesh.face(h).expect("a connection is a face corner");
            by_face
                .entry(face)
                .or_default()
                .push((hole.position, [h.edge(), p.mesh.prev(h).edge()]));
        }
    }
    by_face
}

/// Every fastener hole stays r + margin clear of the face's flaps it does not go
/// through (the fastener's head sits flat on the two it holds), which are notched
/// round it where they grow past it; returns the holes checked.
fn check_foreign_flaps(p: &Pipeline, job: &Job, what: &str, size_mm: f64) -> usize {
    let mesh = &p.mesh;
    let o = &edge_options(job);
    let clear = 0.5 * o.panel.hole_diameter + o.panel.hole_margin;
    let tol = 1e-9 * size_mm;
    let holes = holes_by_face(p);
    let mut checked = 0;
    for (panel, fp) in p.panels.iter().zip(&p.flat) {
        let e = edge_of(fp);
        let last = panel.facets.len() - 1;
        for facet in [0, last] {
            let corners: Vec<DVec3> = panel.facets[facet]
                .iter()
                .map(|&i| panel.vertices[i as usize])
                .collect();
            let h = e.half_edge();
            // The flap's face: the one of the edge's faces whose plane it lies in.
            let off = |f: FaceId| {
                let (c, nrm) = (centre(mesh, f), normal(mesh, f));
                corners
                    .iter()
                    .map(|&q| (q - c).dot(nrm).abs())
                    .fold(0.0, f64::max)
            };
            let Some(face) = [h, h.twin()]
                .into_iter()
                .filter_map(|h| mesh.face(h))
                .min_by(|&a, &b| off(a).total_cmp(&off(b)))
            else {
                continue;
            };
            let (c, nrm) = (centre(mesh, face), normal(mesh, face));
            let ex = nrm.any_orthonormal_vector();
            let ey = nrm.cross(ex);
            let to2 = |q: DVec3| DVec2::new((q - c).dot(ex), (q - c).dot(ey));
            let flap: Vec<DVec2> = corners.iter().map(|&q| to2(q)).collect();
            for &(hole, edges) in holes.get(&face).into_iter().flatten() {
                if edges.contains(&e) {
                    continue;
                }
                let at = to2(hole);
                let gap = distance_to_border(&flap, at);
                assert!(
                    !inside(&flap, at) && gap >= clear - tol,
                    "{what}: {} flap {facet} comes {gap:.3} mm from a hole of {}/{} it does not hold (r + margin {clear})",
                    fp.id(),
                    edges[0].0,
                    edges[1].0
                );
                checked += 1;
            }
        }
    }
    checked
}

/// The bend of every interior-edge panel (SPEC §2): facets 1..=n are quads whose corners
/// are coplanar (each corner within 1e-9 of the strip's size of the plane through the
/// other three); the n + 1 rulings (the edges shared by consecutive facets) are parallel
/// to the mesh edge in 3D (|û × ê| < 1e-9) and to each other in the flat panel, and sit
/// on the rails `f-band(v) → b·v + (1−b)·m → f′-band(v)` (same at v′) at `t = k/n`
/// (within 1e-9 of the model size); the score lines are rulings. Flaps: on a planar
/// model each flap lies in the plane of its face, inside the face band, between the band
/// edge and the inner line (band corners moved F toward c), with every corner that is
/// not a band corner on the inner line or on a notch round another corner's hole. A
/// boundary-edge panel is one flap on its face's band edge.
fn check_bends(p: &Pipeline, job: &Job, what: &str, size_mm: f64, planar: bool) {
    let mesh = &p.mesh;
    let o = &edge_options(job);
    let n = o.samples as usize;
    let tol = 1e-9 * size_mm;
    // Bends are exact between planar faces. Between faces planar only within
    // --planarity-tol the band corners are moved onto their face's plane (so flaps are
    // flat and holes meet), and the bend is off by about that tolerance.
    let exact = if planar {
        1e-9
    } else {
        10.0 * job.model.planarity_tol
    };
    let mut strips = 0;
    let scales = face_scales(p, o, exact * size_mm);
    let scale = |f: FaceId| scales[f.0 as usize];
    let holes = holes_by_face(p);
    // A flap notched round another corner's hole has its corners on the notch: a
    // polygon round the hole and the band from it away from the flap's band edge,
    // between r + margin and that over cos(π/16) from the hole or that band's axis.
    let clear = 0.5 * o.panel.hole_diameter + o.panel.hole_margin;
    let notch_radius = clear / (std::f64::consts::PI / 16.0).cos();
    for (panel, fp) in p.panels.iter().zip(&p.flat) {
        let e = edge_of(fp);
        let h = e.half_edge();
        let at = |i: u32| panel.vertices[i as usize];
        let (v, w) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
        let along = (w - v).normalize();

        // The faces and the flap facet lying in each.
        let mut flaps: Vec<(FaceId, HalfedgeId, usize)> = Vec::new();
        if mesh.is_boundary_edge(e) {
            let h = if mesh.face(h).is_some() { h } else { h.twin() };
            flaps.push((mesh.face(h).unwrap(), h, 0));
        } else {
            let (f, g) = (mesh.face(h).unwrap(), mesh.face(h.twin()).unwrap());
            let (sf, sg) = (scale(f), scale(g));
            let b = o.bridge_scale;
            let m = 0.5 * (v + w);
            let rail = |t: f64| {
                [
                    bezier(
                        band_corner(mesh, f, v, sf),
                        b * v + (1.0 - b) * m,
                        band_corner(mesh, g, v, sg),
                        t,
                    ),
                    bezier(
                        band_corner(mesh, f, w, sf),
                        b * w + (1.0 - b) * m,
                        band_corner(mesh, g, w, sg),
                        t,
                    ),
                ]
            };
            assert_eq!(
                panel.facets.len(),
                n + 2,
                "{what}: {} is not flap + {n} strips + flap",
                fp.id()
            );
            let lines = rulings(panel, n);
            // Facet 0 is the flap in f or in g: the rulings run from that face's band
            // edge to the other's.
            let matches = |k: usize, t: f64| {
                let [a, b] = lines[k];
                let [rv, rw] = rail(t);
                (at(a).distance(rv) <= tol && at(b).distance(rw) <= tol)
                    || (at(a).distance(rw) <= tol && at(b).distance(rv) <= tol)
            };
            let forward = (0..=n).all(|k| matches(k, k as f64 / n as f64));
            let backward = (0..=n).all(|k| matches(k, 1.0 - k as f64 / n as f64));
            assert!(
                forward || backward,
                "{what}: {}: rulings {:?} are not on the rails of the spec at t = k/{n}",
                fp.id(),
                lines
                    .iter()
                    .map(|[a, b]| (at(*a), at(*b)))
                    .collect::<Vec<_>>()
            );
            let (first, last) = if forward { (f, g) } else { (g, f) };
            let he = |face: FaceId| {
                if mesh.face(h) == Some(face) {
                    h
                } else {
                    h.twin()
                }
            };
            flaps.push((first, he(first), 0));
            flaps.push((last, he(last), n + 1));

            for (k, [a, b]) in lines.iter().enumerate() {
                let ruling = at(*b) - at(*a);
                let cross = ruling.normalize().cross(along).length();
                assert!(
                    cross < exact,
                    "{what}: {} ruling {k} is not parallel to edge {} (|û × ê| = {cross:e})",
                    fp.id(),
                    e.0
                );
                let flat_first = fp.points[lines[0][1] as usize] - fp.points[lines[0][0] as usize];
                let flat = fp.points[*b as usize] - fp.points[*a as usize];
                let cross2 = flat.normalize().perp_dot(flat_first.normalize()).abs();
                assert!(
                    cross2 < exact,
                    "{what}: {} flat ruling {k} is not parallel to ruling 0 ({cross2:e})",
                    fp.id()
                );
            }
            let ruling_set: BTreeSet<(u32, u32)> =
                lines.iter().map(|[a, b]| (*a.min(b), *a.max(b))).collect();
            for Fold { ends: [a, b], .. } in &fp.folds {
                assert!(
                    ruling_set.contains(&(*a.min(b), *a.max(b))),
                    "{what}: {} scores {a}-{b}, which is not a ruling",
                    fp.id()
                );
            }
            for k in 1..=n {
                let q: Vec<DVec3> = panel.facets[k].iter().map(|&i| at(i)).collect();
                assert_eq!(q.len(), 4, "{what}: {} strip {k} is not a quad", fp.id());
                let size = diameter(&q, DVec3::distance);
                for i in 0..4 {
                    let (a, b, c) = (q[(i + 1) % 4], q[(i + 2) % 4], q[(i + 3) % 4]);
                    let nrm = (b - a).cross(c - a).normalize();
                    let off = (q[i] - a).dot(nrm).abs();
                    assert!(
                        off <= exact * size,
                        "{what}: {} strip {k} is not planar: corner {i} is {off:e} mm off the plane of the others (strip size {size} mm)",
                        fp.id()
                    );
                }
                strips += 1;
            }
        }

        // Flaps, on planar faces: in the face plane, inside its band, between the band
        // edge and the inner line.
        if !planar {
            continue;
        }
        for (face, he, facet) in flaps {
            let c = centre(mesh, face);
            let nrm = normal(mesh, face);
            let band: Vec<DVec3> = mesh
                .face_positions(face)
                .map(|p| band_corner(mesh, face, p, scale(face)))
                .collect();
            let ex = (band[1] - band[0]).normalize();
            let ey = nrm.cross(ex);
            let to2 = |p: DVec3| DVec2::new((p - c).dot(ex), (p - c).dot(ey));
            let band2: Vec<DVec2> = band.iter().map(|&p| to2(p)).collect();
            let (bv, bw) = (
                band_corner(mesh, face, mesh.position(mesh.origin(he)), scale(face)),
                band_corner(mesh, face, mesh.position(mesh.dest(he)), scale(face)),
            );
            // The flap is the band between its band edge and one inner line parallel to
            // it: its depth (in units of the band edge's distance from the centre)
            // is --flap-scale, or deeper, up to MAX_FLAP_SCALE, where a corner needs
            // room for its holes.
            let u = (to2(bw) - to2(bv)).normalize();
            // Distance inward from the band edge (the centre is at `reach`).
            let inward = |q2: DVec2| u.perp_dot(q2 - to2(bv)) * u.perp_dot(-to2(bv)).signum();
            let reach = inward(DVec2::ZERO);
            let corners: Vec<DVec3> = panel.facets[facet].iter().map(|&i| at(i)).collect();
            let mut inner_line: Option<f64> = None;
            for (k, &q) in corners.iter().enumerate() {
                let off = (q - c).dot(nrm).abs();
                assert!(
                    off <= tol,
                    "{what}: {} flap {facet} corner {k} is {off:e} mm off its face's plane",
                    fp.id()
                );
                let q2 = to2(q);
                assert!(
                    inside(&band2, q2) || distance_to_border(&band2, q2) <= tol,
                    "{what}: {} flap {facet} corner {k} leaves the face band",
                    fp.id()
                );
                let depth = inward(q2);
                assert!(
                    depth >= -tol && depth <= MAX_FLAP_SCALE * reach + tol,
                    "{what}: {} flap {facet} corner {k} is {depth} mm in from its band edge, beyond the deepest inner line",
                    fp.id()
                );
                let is_band_corner = band.iter().any(|&b| b.distance(q) <= tol);
                // A notch runs from its hole straight away from the band edge.
                let into = u.perp() * u.perp_dot(-to2(bv)).signum();
                let on_notch = holes
                    .get(&face)
                    .into_iter()
                    .flatten()
                    .any(|&(hole, edges)| {
                        let h2 = to2(hole);
                        let d = q2.distance(h2 + (q2 - h2).dot(into).max(0.0) * into);
                        !edges.contains(&e) && d >= clear - tol && d <= notch_radius + tol
                    });
                // The other corners are where the inner line meets the band, or a notch.
                if !is_band_corner && !on_notch && depth > tol {
                    let line = *inner_line.get_or_insert(depth);
                    assert!(
                        (depth - line).abs() <= tol,
                        "{what}: {} flap {facet} corner {k} is neither a band corner nor on the flap's inner line ({depth} vs {line} mm)",
                        fp.id()
                    );
                }
            }
            if let Some(line) = inner_line {
                assert!(
                    line >= o.flap_scale * reach - tol,
                    "{what}: {} flap {facet} is shallower ({line} mm) than --flap-scale",
                    fp.id()
                );
            }
            // The flap starts on the band edge of its edge.
            for b in [bv, bw] {
                assert!(
                    corners.iter().any(|&q| q.distance(b) <= tol),
                    "{what}: {} flap {facet} misses band corner {b}",
                    fp.id()
                );
            }
        }
    }
    let interior = mesh.edges().filter(|&e| !mesh.is_boundary_edge(e)).count();
    assert_eq!(strips, n * interior, "{what}: strips checked");
}

/// What [`check_holes`] found.
struct HoleFacts {
    /// Holes on all panels.
    holes: usize,
    /// Connections with holes.
    with_holes: usize,
    /// Connections with fewer holes than wanted (possibly none).
    fewer: usize,
    /// Connections without holes.
    none: usize,
    /// Largest 3D distance between partner holes (mm).
    worst_apart: f64,
}

/// Follows every flat hole back to 3D through its facet's frame. Every connection id is
/// a face corner (a half-edge with a face); its holes are on exactly two panels, the
/// panels of the two edges meeting at that corner (the half-edge's own edge and its
/// predecessor's), the same number on each (1, 2 or 4, at most `--holes`; exactly that
/// when `all`), at identical 3D points on both panels (within 1e-9 of the size) and,
/// unrolled and mapped back through the facet's frame (which lands on the projection of
/// the 3D point onto the facet's plane), pairing up at the same 3D point within
/// `rel_tol` × model size; they lie in the face's plane, nearest to that corner's band corner, on a flap
/// (never a strip)
/// with one diameter of material to the flap's border; the holes of one connection on
/// one panel are at least two diameters apart (one diameter of material between them)
/// and no two holes of a panel overlap (in the plane, within `rel_tol` × model size).
fn check_holes(
    p: &Pipeline,
    job: &Job,
    what: &str,
    size_mm: f64,
    rel_tol: f64,
    all: bool,
) -> HoleFacts {
    let mesh = &p.mesh;
    let o = &edge_options(job);
    let wanted = o.panel.holes as usize;
    let d = o.panel.hole_diameter;
    let r = 0.5 * d;
    let tol = rel_tol * size_mm;
    let n = o.samples as usize;
    let exact = 1e-9 * size_mm;
    let frames = frames_of(&p.panels);
    let scales = face_scales(p, o, 1e-3 * size_mm);

    // connection → [(panel index, unrolled point mapped back to 3D, the 3D hole)]
    let mut by_connection: BTreeMap<u32, Vec<(usize, DVec3, DVec3)>> = BTreeMap::new();
    let mut holes = 0;
    for (k, fp) in p.flat.iter().enumerate() {
        assert_eq!(
            fp.holes.len(),
            p.panels[k].holes.len(),
            "{what}: {}",
            fp.id()
        );
        let panel = &p.panels[k];
        let last = panel.facets.len() - 1;
        for (hole, hole3) in fp.holes.iter().zip(&panel.holes) {
            holes += 1;
            assert_eq!(
                (hole.connection, hole.facet),
                (hole3.connection, hole3.facet),
                "{what}: {} holes out of order",
                fp.id()
            );
            assert!(
                (hole.diameter - d).abs() < 1e-12,
                "{what}: {} hole diameter {}",
                fp.id(),
                hole.diameter
            );
            assert!(
                hole.facet == 0 || hole.facet as usize == last,
                "{what}: {} hole of connection {} on facet {} (a strip of its {n})",
                fp.id(),
                hole.connection,
                hole.facet
            );
            let facet = fp.loop_points(&panel.facets[hole.facet as usize]);
            assert!(
                inside(&facet, hole.center),
                "{what}: {} hole of connection {} outside its flap",
                fp.id(),
                hole.connection
            );
            let clear = distance_to_border(&facet, hole.center);
            let margin = o.panel.hole_margin;
            assert!(
                clear >= r + margin - tol,
                "{what}: {} hole of connection {} is {clear} mm from its flap's border: radius {r} + the margin {margin} wanted",
                fp.id(),
                hole.connection
            );
            let frame = frames[k][hole.facet as usize];
            let point = frame.to_3d(hole.center);
            let normal = frame.x3.cross(frame.y3);
            let foot = hole3.position - (hole3.position - frame.origin3).dot(normal) * normal;
            assert!(
                point.distance(foot) <= exact,
                "{what}: {} hole of connection {} unrolls to {point}, not onto its 3D point {} projected on the facet ({foot})",
                fp.id(),
                hole.connection,
                hole3.position
            );
            by_connection
                .entry(hole.connection)
                .or_default()
                .push((k, point, hole3.position));
        }
        for (i, a) in fp.holes.iter().enumerate() {
            for b in &fp.holes[i + 1..] {
                let gap = a.center.distance(b.center);
                assert!(
                    gap > d,
                    "{what}: {} holes of connections {} and {} overlap ({gap} mm apart)",
                    fp.id(),
                    a.connection,
                    b.connection
                );
                if a.connection == b.connection {
                    assert!(
                        gap >= 2.0 * d - tol,
                        "{what}: {} holes of connection {} are {gap} mm apart, less than two diameters",
                        fp.id(),
                        a.connection
                    );
                }
            }
        }
    }

    let mut worst_apart = 0.0f64;
    let mut fewer = 0;
    for (&c, list) in &by_connection {
        let h = HalfedgeId(c);
        assert!(
            h.index() < mesh.half_edge_count(),
            "{what}: connection {c} is no half-edge"
        );
        let f = mesh
            .face(h)
            .unwrap_or_else(|| panic!("{what}: connection {c} is a boundary half-edge"));
        let want: BTreeSet<u32> = [h.edge().0, mesh.prev(h).edge().0].into();
        let owners: BTreeSet<usize> = list.iter().map(|x| x.0).collect();
        let sources: BTreeSet<u32> = owners.iter().map(|&k| edge_of(&p.flat[k]).0).collect();
        assert_eq!(
            (owners.len(), &sources),
            (2, &want),
            "{what}: connection {c} (corner of face {} at vertex {}) has holes on panels {sources:?}, want the panels of edges {want:?}",
            f.0,
            mesh.origin(h).0
        );
        let [a, b]: [usize; 2] = owners.into_iter().collect::<Vec<_>>().try_into().unwrap();
        let on_a: Vec<(DVec3, DVec3)> = list
            .iter()
            .filter(|x| x.0 == a)
            .map(|x| (x.1, x.2))
            .collect();
        let on_b: Vec<(DVec3, DVec3)> = list
            .iter()
            .filter(|x| x.0 == b)
            .map(|x| (x.1, x.2))
            .collect();
        assert_eq!(
            on_a.len(),
            on_b.len(),
            "{what}: connection {c}: {} and {} holes on its two panels",
            on_a.len(),
            on_b.len()
        );
        let per = on_a.len();
        assert!(
            [1, 2, 4].contains(&per) && per <= wanted,
            "{what}: connection {c} has {per} holes per panel, --holes {wanted}"
        );
        if all {
            assert_eq!(per, wanted, "{what}: connection {c} has {per} holes");
        }
        if per < wanted {
            fewer += 1;
        }
        // Pair them in 3D: the unrolled holes mapped back, and the scheme's 3D holes.
        let pair_tol = tol;
        let mut matched = BTreeSet::new();
        for (qa, pa) in &on_a {
            let (nearest, j) = on_b
                .iter()
                .enumerate()
                .map(|(j, (qb, _))| (qa.distance(*qb), j))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap();
            assert!(
                nearest <= pair_tol,
                "{what}: connection {c}: hole of {} at {qa} has no partner on {} (nearest {nearest:e} mm, tolerance {pair_tol:e})",
                p.flat[a].id(),
                p.flat[b].id()
            );
            assert!(
                matched.insert(j),
                "{what}: connection {c}: two holes share one partner"
            );
            let apart3 = pa.distance(on_b[j].1);
            assert!(
                apart3 <= exact,
                "{what}: connection {c}: the 3D holes of partners are {apart3:e} mm apart"
            );
            worst_apart = worst_apart.max(nearest);
        }
        // In the corner's face, inside its band with the margin to the band's border
        // (the flat check above holds each hole to its own flap's outline, so to the
        // overlap of the two flaps).
        let cf = centre(mesh, f);
        let nf = normal(mesh, f);
        let ex = (mesh.position(mesh.dest(h)) - mesh.position(mesh.origin(h))).normalize();
        let ey = nf.cross(ex);
        let to2 = |q: DVec3| DVec2::new((q - cf).dot(ex), (q - cf).dot(ey));
        let band: Vec<DVec2> = mesh
            .face_positions(f)
            .map(|v| to2(band_corner(mesh, f, v, scales[f.0 as usize])))
            .collect();
        let margin = o.panel.hole_margin;
        for (_, q) in on_a.iter().chain(&on_b) {
            let off = (*q - cf).dot(nf).abs();
            assert!(
                off <= exact,
                "{what}: connection {c}: hole {off:e} mm off the plane of face {}",
                f.0
            );
            let q2 = to2(*q);
            let clear = if inside(&band, q2) {
                distance_to_border(&band, q2)
            } else {
                -distance_to_border(&band, q2)
            };
            assert!(
                clear >= r + margin - tol,
                "{what}: connection {c}: a hole is {clear} mm inside the band at corner {} of face {}, radius {r} + the margin {margin} wanted",
                mesh.origin(h).0,
                f.0
            );
        }
    }

    let corners: BTreeSet<u32> = mesh
        .half_edges()
        .filter(|&h| mesh.face(h).is_some())
        .map(|h| h.0)
        .collect();
    assert_eq!(corners.len(), p.output.connections, "{what}: connections");
    if all {
        assert_eq!(
            by_connection.keys().copied().collect::<BTreeSet<_>>(),
            corners,
            "{what}: every face corner has its holes"
        );
        assert_eq!(
            holes,
            2 * wanted * p.output.connections,
            "{what}: 2 × --holes × connections"
        );
    }
    let with_holes = by_connection.len();
    HoleFacts {
        holes,
        with_holes,
        fewer: fewer + (p.output.connections - with_holes),
        none: p.output.connections - with_holes,
        worst_apart,
    }
}

/// The report's figures on connections with fewer holes than wanted: the scheme's note
/// "X of Y connections hold fewer fastener holes than asked (--holes N in each …)" and the
/// fasteners warning on the Z with none ("Z of Y connections hold no …", or "no … fits
/// at Z of Y connections" when most have none), as (X + Z, Y, Z) if either is there.
/// The note's N must be `wanted`.
fn fewer_holes_note(report: &str, wanted: usize) -> Option<(usize, usize, usize)> {
    let figures = |line: &str, key: &str| -> Vec<usize> {
        let at = line.find(key).unwrap_or(0);
        line[at..]
            .split(|c: char| !c.is_ascii_digit())
            .filter(|w| !w.is_empty())
            .take(3)
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let note = report
        .lines()
        .find(|l| l.contains(" connections hold fewer fastener holes than asked "))
        .map(|l| {
            let n = figures(l, "note: ");
            assert_eq!(n[2], wanted, "the wanted holes in {l:?}");
            (n[0], n[1])
        });
    let bare = report.lines().find_map(|l| {
        if let Some(at) = l.find(" connections hold no ") {
            let n = figures(&l[..at], "warning: ");
            Some((n[0], n[1]))
        } else {
            l.find(" fits at ").map(|at| {
                let n = figures(&l[at..], " fits at ");
                (n[0], n[1])
            })
        }
    });
    match (note, bare) {
        (None, None) => None,
        (Some((x, y)), None) => Some((x, y, 0)),
        (None, Some((z, y))) => Some((z, y, z)),
        (Some((x, y)), Some((z, y2))) => {
            assert_eq!(y, y2, "connections in the note and the warning");
            Some((x + z, y, z))
        }
    }
}

/// The same holes in the files: `counts.holes` and `counts.connections` of a binary
/// run with the same options equal the library's; the SVG circles (checker's stats)
/// number `counts.holes`, each of radius d/2; the report's note on connections with
/// fewer holes than wanted gives the same figures, and is absent when every connection
/// has them all.
fn check_holes_in_files(
    facts: &HoleFacts,
    p: &Pipeline,
    job: &Job,
    model: &Path,
    size: &str,
    extra: &[&str],
    what: &str,
) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let holes = job.scheme.panel().holes.to_string();
    let mut args = vec!["--holes", &holes, "--format", "svg"];
    args.extend_from_slice(extra);
    let (m, run) = build_run(model, size, &out, &args);
    assert_eq!(
        count(&m, "counts.holes"),
        facts.holes,
        "{what}: counts.holes"
    );
    assert_eq!(
        count(&m, "counts.connections"),
        p.output.connections,
        "{what}: counts.connections"
    );
    let sheets = check_sheets(&out, &m, DxfCheck::All);
    assert_eq!(
        sheets.total().holes,
        facts.holes,
        "{what}: circles on the sheets"
    );
    let r = 0.5 * job.scheme.panel().hole_diameter;
    for file in &sheets.svg_files {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        for (layer, _, _, radius) in svg_circles(&text) {
            assert_eq!(layer, "CUT", "{what}: {file}: a circle on {layer}");
            assert!(
                (radius - r).abs() <= 1e-4,
                "{what}: {file}: hole radius {radius}, want {r}"
            );
        }
    }
    match fewer_holes_note(&run.stderr, job.scheme.panel().holes as usize) {
        None => assert_eq!(
            facts.fewer, 0,
            "{what}: {} connections have fewer holes than wanted and the report does not say so:\n{}",
            facts.fewer, run.stderr
        ),
        Some(figures) => assert_eq!(
            figures,
            (facts.fewer, p.output.connections, facts.none),
            "{what}: the report's note on holes: {}",
            run.stderr
        ),
    }
}

// =======================================================================================
// 1. Panels and connections: E panels, 2E connections on closed meshes
// =======================================================================================

/// Builds a model with `--sheet 18x24in --format svg,dxf EXTRA…`, checks its output
/// folder (every sheet through the checker, DXF as `dxf` says, manifest against the
/// sheets, panel ids `E<edge>`) and the counts against the library's mesh: panels = E =
/// input.edges, each edge once; connections = Σ face degrees (= 2E when closed); the
/// manifest's developability error per panel below 1e-9 of the panel's size when the
/// model is planar. Returns the manifest, the report, the pipeline and its job.
fn check_model(
    model: &Path,
    size: &str,
    extra: &[&str],
    dxf: DxfCheck,
    planar: bool,
) -> (Value, String, Pipeline, Job) {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let what = format!("{} at {size} (quad-edge)", model.display());
    let mut args = vec!["--sheet", "18x24in", "--format", "svg,dxf"];
    args.extend_from_slice(extra);
    let (m, run) = build_run(model, size, &out, &args);
    assert_eq!(m["scheme"]["name"], "quad-edge", "{what}");
    check_output(model, &out, &m, &what, dxf, |p| {
        format!("E{}", count(p, "source.edge"))
    });

    let mut options = quad_options(size, 2, &out);
    if let Some(i) = extra.iter().position(|a| *a == "--hole-diameter") {
        options.hole_diameter = Some(extra[i + 1].to_string());
    }
    let job = resolve(options, model);
    let p = pipeline(&job);
    let edges = count(&m, "input.edges");
    assert_eq!(edges, p.mesh.edge_count(), "{what}: input.edges");
    assert_eq!(
        count(&m, "input.faces"),
        p.mesh.face_count(),
        "{what}: input.faces"
    );
    assert_eq!(count(&m, "counts.panels"), edges, "{what}: panels = E");
    let list = m["panels"].as_array().unwrap();
    let sources: BTreeSet<usize> = list.iter().map(|p| count(p, "source.edge")).collect();
    assert_eq!(
        sources,
        (0..edges).collect(),
        "{what}: one panel per edge, from every edge"
    );
    let connections = count(&m, "counts.connections");
    assert_eq!(
        connections,
        face_corners(&p.mesh),
        "{what}: connections = Σ face degrees"
    );
    assert_eq!(connections, p.output.connections, "{what}: connections");
    if count(&m, "input.boundary_loops") == 0 {
        assert_eq!(connections, 2 * edges, "{what}: closed: connections = 2E");
    }
    let split =
        count(&m, "input.faces_split.non_planar") + count(&m, "input.faces_split.not_star_shaped");
    if split == 0 {
        // The file's own faces, counted without the tool.
        let (_, faces) = read_simple_obj(model);
        let degrees: usize = faces.iter().map(Vec::len).sum();
        assert_eq!(
            connections, degrees,
            "{what}: Σ degrees of the file's faces"
        );
    }
    check_panels(&p, &job, &what);

    if planar {
        let max = num(&m, "max_developability_error");
        let mut largest = 0.0f64;
        for (entry, fp) in list.iter().zip(&p.flat) {
            assert_eq!(
                entry["id"].as_str(),
                Some(fp.id().to_string().as_str()),
                "{what}: panel order"
            );
            let size = diameter(&fp.outer(), DVec2::distance);
            let e = num(entry, "developability_error");
            assert!(
                e <= 1e-9 * size,
                "{what}: {} developability error {e} mm on a {size} mm panel",
                fp.id()
            );
            largest = largest.max(e);
        }
        assert_eq!(max, largest, "{what}: max_developability_error");
    }
    (m, run.stderr, p, job)
}

/// The project's closed models (the open ones are `open-grid` and `open-cylinder`).
const CLOSED_MODELS: [&str; 9] = [
    "tetrahedron",
    "hexahedron",
    "octahedron",
    "dodecahedron",
    "icosahedron",
    "torus-8x6",
    "genus2",
    "genus3",
    "concave",
];

#[test]
fn closed_meshes_have_a_panel_per_edge_and_two_connections_per_edge() {
    for name in CLOSED_MODELS {
        let (m, report, p, _job) = check_model(&model(name), "300mm", &[], DxfCheck::All, true);
        let what = format!("{name} at 300mm");
        assert_eq!(count(&m, "input.boundary_loops"), 0, "{what}: closed");
        assert!(
            !report.contains("boundary edges"),
            "{what}: a closed mesh has no boundary panels:\n{report}"
        );
        check_developable(&p, &what, 1e-9);
    }
}

#[test]
fn open_meshes_give_boundary_edges_a_single_flap() {
    for name in ["open-grid", "open-cylinder"] {
        let path = model(name);
        let what = format!("{name} at 300mm");
        let (m, report, p, _job) = check_model(&path, "300mm", &[], DxfCheck::All, true);
        let facts = inspect_json(&path, &["--size", "300mm"]);
        let boundary = count(&facts, "mesh.boundary_edges");
        assert!(boundary > 0, "{what}: an open mesh");
        assert!(count(&m, "input.boundary_loops") > 0, "{what}");
        assert_eq!(
            count(&facts, "mesh.edges"),
            count(&m, "input.edges"),
            "{what}"
        );
        // The report: "note: B boundary edges have a panel with a single flap and no bend".
        let line = report
            .lines()
            .find(|l| l.contains("boundary edges have a panel with a single flap"))
            .unwrap_or_else(|| {
                panic!("{what}: the report does not mention boundary panels:\n{report}")
            });
        let said: usize = line
            .trim_start_matches("note: ")
            .split_whitespace()
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("{what}: no count in {line:?}"));
        assert_eq!(said, boundary, "{what}: {line}");
        // The single-flap panels are the boundary edges'.
        let single: Vec<&FlatPanel> = p
            .flat
            .iter()
            .zip(&p.panels)
            .filter(|(_, panel)| panel.facets.len() == 1)
            .map(|(fp, _)| fp)
            .collect();
        assert_eq!(single.len(), boundary, "{what}: single-flap panels");
        for fp in single {
            assert!(
                p.mesh.is_boundary_edge(edge_of(fp)),
                "{what}: {} has one facet but its edge is interior",
                fp.id()
            );
            assert!(
                fp.folds.is_empty(),
                "{what}: {} has no bend to score",
                fp.id()
            );
        }
        check_developable(&p, &what, 1e-9);
    }
}

/// Fertility and horse_quad at 4 ft (1 mm holes, so that some fit: at the default
/// 1/8 in none does): the counts, every SVG and the first and last DXF, outlines simple,
/// bends planar with rulings parallel to the edge (their quads are planar only within
/// --planarity-tol, so the flap checks and the isometry are left to the planar models),
/// holes of the connections that have them identical in 3D and, unrolled, within 1e-6
/// of the size (flaps lie exactly in their face's plane). Prints sheets, lower bound
/// and utilization (holes do not change the layout).
#[test]
fn fertility_has_a_panel_per_edge_and_paired_holes() {
    shared_model_has_a_panel_per_edge_and_paired_holes(
        "fertility_has_a_panel_per_edge_and_paired_holes",
        "fertility",
    );
}

/// The same on horse_quad, a test of its own so that it runs beside fertility.
#[test]
fn horse_quad_has_a_panel_per_edge_and_paired_holes() {
    shared_model_has_a_panel_per_edge_and_paired_holes(
        "horse_quad_has_a_panel_per_edge_and_paired_holes",
        "horse_quad",
    );
}

fn shared_model_has_a_panel_per_edge_and_paired_holes(test: &str, name: &str) {
    let Some(shared) = shared_models(test) else {
        return;
    };
    let path = shared.join(format!("{name}.obj"));
    let what = format!("{name} at 4ft");
    let what = what.as_str();
    let (m, report, p, job) = check_model(
        &path,
        "4ft",
        // Shelf layout: the panels and sheets are checked, not how tight they
        // are (that is the nesting tests' and the bench's job).
        &["--hole-diameter", "1mm", "--nester", "shelf"],
        DxfCheck::FirstAndLast,
        false,
    );
    assert_eq!(count(&m, "input.boundary_loops"), 0, "{what}: closed");
    check_bends(&p, &job, what, 1219.2, false);
    let facts = check_holes(&p, &job, what, 1219.2, 1e-6, false);
    assert!(
        facts.with_holes > 0,
        "{what}: no connection has room for a 1 mm hole"
    );
    assert_eq!(
        count(&m, "counts.holes"),
        facts.holes,
        "{what}: counts.holes"
    );
    match fewer_holes_note(&report, 2) {
        Some(note) => assert_eq!(
            note,
            (facts.fewer, p.output.connections, facts.none),
            "{what}: {report}"
        ),
        None => assert_eq!(facts.fewer, 0, "{what}: {report}"),
    }
    eprintln!(
        "{what}: {} of {} connections have holes ({} holes); partner holes at most {:.1e} mm apart",
        facts.with_holes, p.output.connections, facts.holes, facts.worst_apart
    );
    eprintln!(
        "{name}, quad-edge, 4 ft on 18x24in: {} panels, {} sheets, area lower bound {}, utilization {:.1}%",
        count(&m, "counts.panels"),
        count(&m, "counts.sheets"),
        count(&m, "counts.sheets_lower_bound"),
        100.0 * num(&m, "utilization")
    );
}

// =======================================================================================
// 2. Holes of a connection meet in 3D
// =======================================================================================

/// Library level with `check_holes` (every connection gets all its holes), then the same
/// options through the binary with `check_holes_in_files`.
fn holes_everywhere(name: &str, size: &str, size_mm: f64, holes: u32, extra: &[&str]) {
    let path = model(name);
    let what = format!(
        "{name} at {size} --holes {holes}{}",
        extra.iter().map(|a| format!(" {a}")).collect::<String>()
    );
    let diameter = extra
        .iter()
        .position(|a| *a == "--hole-diameter")
        .map(|i| extra[i + 1]);
    let job = quad_job(&path, size, holes, diameter, None);
    let p = pipeline(&job);
    let facts = check_holes(&p, &job, &what, size_mm, 1e-9, true);
    assert_eq!(facts.with_holes, p.output.connections, "{what}");
    check_holes_in_files(&facts, &p, &job, &path, size, extra, &what);
    eprintln!(
        "{what}: {} holes on {} connections; partner holes at most {:.1e} mm apart",
        facts.holes, p.output.connections, facts.worst_apart
    );
}

/// At the defaults, the platonic solids and the 6 × 4 torus at 1 ft get two holes at
/// every connection (the flaps grow where a corner needs the room), partner holes
/// meeting in 3D; the manifest counts them by connection.
#[test]
fn solids_at_one_foot_get_two_holes_at_every_connection() {
    let tmp = TempDir::new().unwrap();
    for name in [
        "tetrahedron",
        "hexahedron",
        "octahedron",
        "dodecahedron",
        "icosahedron",
        "torus-6x4",
        "torus-8x6",
    ] {
        holes_everywhere(name, "1ft", 304.8, 2, &[]);
        let m = build(
            "quad-edge",
            &model(name),
            "1ft",
            &tmp.path().join(name),
            &[],
        );
        let connections = count(&m, "counts.connections");
        assert_eq!(
            m["counts"]["connections_by_holes"],
            serde_json::json!({ "2": connections }),
            "{name}"
        );
        assert_eq!(count(&m, "counts.fasteners"), 2 * connections, "{name}");
        assert_eq!(count(&m, "counts.holes"), 4 * connections, "{name}");
    }
}

#[test]
fn holes_of_a_connection_meet_in_3d() {
    // The scheme's note says which sizes have room: the platonic solids at 300 mm do;
    // genus2 needs 600 mm and genus3 1 mm holes at 300 mm.
    holes_everywhere("icosahedron", "300mm", 300.0, 2, &[]);
    holes_everywhere("hexahedron", "300mm", 300.0, 2, &[]);
    holes_everywhere("genus2", "600mm", 600.0, 2, &[]);
    holes_everywhere("genus3", "300mm", 300.0, 2, &["--hole-diameter", "1mm"]);
    holes_everywhere("hexahedron", "300mm", 300.0, 4, &[]);
    holes_everywhere("icosahedron", "300mm", 300.0, 1, &[]);
}

/// Where the overlap is too small the scheme places fewer holes (4 → 2 → 1 → 0), still
/// paired, and says how many connections got fewer.
#[test]
fn fewer_holes_where_the_overlap_is_small() {
    // Sizes at which even the deepest flaps in the widest bands cannot hold every
    // wanted hole (at 80 mm the icosahedron holds all four, at 200 mm genus3 both).
    for (name, size, size_mm, holes) in [
        ("icosahedron", "70mm", 70.0, 4),
        ("genus3", "150mm", 150.0, 2),
    ] {
        let path = model(name);
        let what = format!("{name} at {size} --holes {holes}");
        let job = quad_job(&path, size, holes, None, None);
        let p = pipeline(&job);
        let facts = check_holes(&p, &job, &what, size_mm, 1e-9, false);
        assert!(
            facts.fewer > 0,
            "{what}: every connection has all its holes"
        );
        assert!(facts.with_holes > 0, "{what}: no connection has holes");
        check_holes_in_files(&facts, &p, &job, &path, size, &[], &what);
    }
}

// =======================================================================================
// 3. Bends: planar strips, rulings parallel to the edge, isometric unrolling
// =======================================================================================

#[test]
fn bend_strips_are_planar_and_ruled_parallel_to_the_edge() {
    let tmp = TempDir::new().unwrap();
    for name in CLOSED_MODELS
        .into_iter()
        .chain(["open-grid", "open-cylinder"])
    {
        let path = model(name);
        let job = quad_job(&path, "300mm", 2, None, None);
        let p = pipeline(&job);
        let what = format!("{name} at 300mm");
        check_panels(&p, &job, &what);
        check_bends(&p, &job, &what, 300.0, true);
    }
    // Other sample counts, through the binary too: every ruling of a convex solid folds,
    // so each panel has n + 1 score lines.
    for (name, samples) in [
        ("icosahedron", 1),
        ("icosahedron", 7),
        ("genus2", 1),
        ("genus2", 7),
    ] {
        let path = model(name);
        let what = format!("{name} at 300mm --samples {samples}");
        let job = quad_job(&path, "300mm", 2, None, Some(samples));
        let p = pipeline(&job);
        check_panels(&p, &job, &what);
        check_bends(&p, &job, &what, 300.0, true);
        check_developable(&p, &what, 1e-9);
        let out = tmp.path().join(format!("{name}-{samples}"));
        let n = samples.to_string();
        let (m, _) = build_run(&path, "300mm", &out, &["--samples", &n]);
        assert!(
            num(&m, "max_developability_error") <= 1e-9 * 300.0,
            "{what}: max_developability_error {}",
            m["max_developability_error"]
        );
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        let scores: usize = p.flat.iter().map(|fp| fp.folds.len()).sum();
        assert_eq!(
            sheets.total().score_paths,
            scores,
            "{what}: score lines drawn"
        );
        if name == "icosahedron" {
            for fp in &p.flat {
                assert_eq!(fp.folds.len(), samples as usize + 1, "{what}: {}", fp.id());
            }
        }
    }
}

// =======================================================================================
// 5. Golden files
// =======================================================================================

#[test]
fn golden_files_of_a_small_model() {
    let args = ["--size", "150mm", "--scheme", "quad-edge", "--holes", "2"];
    let Some((_tmp, out, manifest)) = golden_build(
        "build_quad_edge",
        "hexahedron-quad-edge",
        "hexahedron",
        &args,
    ) else {
        return;
    };
    // The golden sheets themselves pass the independent check: 12 panels, 2 holes on
    // each side of each of the 24 corners, 5 score lines (4 strips) per panel.
    let sheets = check_sheets(&out, &manifest, DxfCheck::All);
    let total = sheets.total();
    assert_eq!(total.panels, 12);
    assert_eq!(count(&manifest, "counts.connections"), 24);
    assert_eq!(total.holes, 2 * 2 * 24);
    assert_eq!(total.holes, count(&manifest, "counts.holes"));
    assert_eq!(total.score_paths, 12 * 5);
    // Every ruling is a band edge's length: s · 150 mm.
    assert!((total.score_length - 60.0 * 75.0).abs() < 1e-3);
}

// =======================================================================================
// Known bug
// =======================================================================================

/// Faces planar only within --planarity-tol (a cube with one corner lifted 0.5%, and
/// fertility's nearly planar n-gons): the flaps lie exactly in their face's plane, so
/// the holes of a connection meet in 3D through the flat panels' maps as strictly as on
/// planar faces. The bend between a nearly planar face and its neighbour cannot be
/// exactly developable; its error stays within the planarity tolerance.
#[test]
fn holes_meet_and_panels_unroll_isometrically_on_nearly_planar_faces() {
    let tmp = TempDir::new().unwrap();
    let path = tmp.path().join("bent-cube.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1.005\nv 0 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let what = "cube with a corner lifted 0.5% at 300mm";
    let job = quad_job(&path, "300mm", 2, None, None);
    let p = pipeline(&job);
    assert_eq!(p.split.count(), 0, "{what}: no face split");
    check_holes(&p, &job, what, 300.0, 1e-6, true);
    check_developable(&p, what, job.model.planarity_tol);
    if let Some(shared) =
        shared_models("holes_meet_and_panels_unroll_isometrically_on_nearly_planar_faces")
    {
        let job = quad_job(&shared.join("fertility.obj"), "4ft", 2, Some("1mm"), None);
        let p = pipeline(&job);
        check_holes(&p, &job, "fertility at 4ft", 1219.2, 1e-6, false);
    }
}

// =======================================================================================
// Connections that cannot hold a fastener
// =======================================================================================

/// The radius of the largest circle inside a face's polygon, from below: twice its
/// area over its perimeter (exact for triangles, at most the inradius of any convex
/// polygon).
fn face_inradius(mesh: &Mesh, f: FaceId) -> f64 {
    let pts: Vec<DVec3> = mesh.face_positions(f).collect();
    let perimeter: f64 = (0..pts.len())
        .map(|i| pts[i].distance(pts[(i + 1) % pts.len()]))
        .sum();
    2.0 * mesh.face_area(f) / perimeter
}

/// At the thesis-like budgets, at the defaults (1/8 in holes), every connection of
/// horse_quad and fertility holds its fastener on both panels: the sheets' circles
/// (counted by the checker) number at least two per connection, the manifest counts
/// none without, partner holes meet in 3D, every hole keeps its margin on its flap
/// and stays clear of the face's other flaps (notched round it where they grow past
/// it), and every flap corner is a band corner, on its inner line or on a notch.
#[test]
fn thesis_budgets_fasten_every_connection() {
    let Some(shared) = shared_models("thesis_budgets_fasten_every_connection") else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    for name in ["horse_quad.obj", "fertility.obj"] {
        let path = shared.join(name);
        let out = tmp.path().join(name);
        let args = ["--target-edges", "1000", "--nester", "shelf"];
        let (m, run) = build_run(&path, "4ft", &out, &args);
        let connections = count(&m, "counts.connections");
        assert_eq!(connections_without_holes(&m), 0, "{name}:\n{}", run.stderr);
        assert!(
            !run.stderr.contains("fastener hole ("),
            "{name}: warns of connections without a hole:\n{}",
            run.stderr
        );
        let sheets = check_sheets(&out, &m, DxfCheck::Skip);
        let circles = sheets.total().holes;
        assert!(
            circles >= 2 * connections,
            "{name}: {circles} holes on the sheets for {connections} connections"
        );
        let mut options = quad_options("4ft", 2, &out);
        options.holes = None;
        options.model.target_edges = Some(unfold::config::TargetEdges::Count(1000));
        let job = resolve(options, &path);
        let p = pipeline(&job);
        assert!(p.output.unfastened.is_empty(), "{name}: the scheme's list");
        let what = format!("{name} at 1000 edges");
        check_bends(&p, &job, &what, 1219.2, true);
        let facts = check_holes(&p, &job, &what, 1219.2, 1e-6, false);
        assert_eq!(facts.with_holes, connections, "{what}");
        let clear_of = check_foreign_flaps(&p, &job, &what, 1219.2);
        eprintln!(
            "{what}: {connections} connections, {} holes ({circles} circles on {} sheets), {} of them with fewer than 2; {clear_of} hole-flap pairs clear",
            facts.holes,
            count(&m, "counts.sheets"),
            facts.fewer
        );
    }
}

/// With a fastener too large for the smallest faces, the few connections left without
/// a hole are named in a warning, counted in the manifest, and sit on small faces: no
/// circle of 2.5 times a hole's radius plus its margin fits in the face (the hole must
/// fit in the corner's overlap of two flaps, with its margin to every side of both).
#[test]
fn only_small_faces_leave_a_connection_without_a_fastener() {
    let Some(shared) = shared_models("only_small_faces_leave_a_connection_without_a_fastener")
    else {
        return;
    };
    let tmp = TempDir::new().unwrap();
    for name in ["horse_quad.obj", "fertility.obj"] {
        let path = shared.join(name);
        let out = tmp.path().join(name);
        let args = [
            "--target-edges",
            "1000",
            "--hole-diameter",
            HOLE_FOR_SMALL_FACES,
            "--nester",
            "shelf",
        ];
        let (m, run) = build_run(&path, "4ft", &out, &args);
        let bare = connections_without_holes(&m);
        let connections = count(&m, "counts.connections");
        assert!(
            bare * 100 <= connections,
            "{name}: {bare} of {connections} without a hole"
        );
        let mut options = quad_options("4ft", 2, &out);
        options.holes = None;
        options.hole_diameter = Some(HOLE_FOR_SMALL_FACES.to_string());
        options.model.target_edges = Some(unfold::config::TargetEdges::Count(1000));
        let job = resolve(options, &path);
        let p = pipeline(&job);
        assert_eq!(p.output.unfastened.len(), bare, "{name}: the scheme's list");
        if bare > 0 {
            let line = run
                .stderr
                .lines()
                .find(|l| l.contains(" connections hold no "))
                .unwrap_or_else(|| panic!("{name}: no warning:\n{}", run.stderr));
            assert!(
                line.starts_with(&format!("unfold: warning: {bare} of {connections} ")),
                "{line}"
            );
            assert!(line.contains(&p.output.unfastened[0].to_string()), "{line}");
            assert!(line.contains("--hole-margin"), "{line}");
        }
        let r = 0.5 * job.scheme.panel().hole_diameter;
        let margin = job.scheme.panel().hole_margin;
        for c in &p.output.unfastened {
            let edges = c.panels.map(|n| match n {
                n if n.kind == &unfold::panel::EDGE => EdgeId(n.number),
                other => panic!("{other}: not an edge panel"),
            });
            let faces = |e: EdgeId| -> Vec<FaceId> {
                let h = e.half_edge();
                [h, h.twin()]
                    .into_iter()
                    .filter_map(|h| p.mesh.face(h))
                    .collect()
            };
            let face = faces(edges[0])
                .into_iter()
                .find(|f| faces(edges[1]).contains(f))
                .unwrap_or_else(|| panic!("{c}: the two edges share no face"));
            let inradius = face_inradius(&p.mesh, face);
            assert!(
                inradius < 2.5 * (r + margin),
                "{name}: {c}: face {} has inradius {inradius:.2} mm, room for a hole",
                face.0
            );
        }
        eprintln!(
            "{name} at 1000 edges, {HOLE_FOR_SMALL_FACES} holes: {bare} of {connections} connections without a hole"
        );
    }
}

/// A fastener that the smallest faces of horse_quad and fertility at 1000 edges cannot
/// hold at 4 ft.
const HOLE_FOR_SMALL_FACES: &str = "5mm";

/// A model far too detailed for its fasteners gets one line with a budget instead of a
/// name per connection; that budget, built, gives every connection a hole; and without
/// `--build-anyway` such a build stops (exit 2) without writing anything.
#[test]
fn too_small_for_fasteners_gets_a_budget_and_strict_refuses() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let torus = model("torus-8x6");
    // At 1 ft the inner quads of the torus hold their labels but no 1/2 in hole.
    let big = ["--hole-diameter", "0.5in", "--nester", "shelf"];
    let (m, run) = build_run(&torus, "1ft", &out, &big);
    let lines: Vec<&str> = run
        .stderr
        .lines()
        .filter(|l| l.contains("fastener hole"))
        .collect();
    let warning = lines
        .iter()
        .find(|l| l.contains(" fits at "))
        .unwrap_or_else(|| panic!("no one-line warning:\n{}", run.stderr));
    assert!(!warning.contains(" at V"), "names connections: {warning}");
    // The budget named was tried: the torus simplified to it holds a hole at every
    // connection (its fewest edges, 27, leave 44 of 54 bare; a few more do not).
    let budget = number_after(warning, "--target-edges ")
        .unwrap_or_else(|| panic!("no budget: {warning}"))
        .to_string();
    let tried = tmp.path().join("tried");
    let mut at_budget = big.to_vec();
    at_budget.extend(["--target-edges", &budget]);
    let (tried_manifest, tried_run) = build_run(&torus, "1ft", &tried, &at_budget);
    assert_eq!(
        connections_without_holes(&tried_manifest),
        0,
        "torus at {budget} edges: {}",
        tried_run.stderr
    );
    assert!(
        !tried_run.stderr.contains("warning:"),
        "{}",
        tried_run.stderr
    );
    assert!(
        m["warnings"].to_string().contains(" fits at "),
        "{}",
        m["warnings"]
    );

    let strict = tmp.path().join("strict");
    let run = common::build::unfold([
        torus.to_str().unwrap(),
        "--scheme",
        "quad-edge",
        "--size",
        "1ft",
        "--hole-diameter",
        "0.5in",
        "--strict",
        "--out",
        strict.to_str().unwrap(),
    ]);
    // Faces too small for any hole stop the build before the nest, --strict or not.
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains(" fits at ")
            && run
                .stderr
                .contains("stopped before laying out the sheets (nothing written)"),
        "{}",
        run.stderr
    );
    assert!(!strict.exists(), "--strict wrote {}", strict.display());

    // A scan has a budget that builds clean: tried before it is named.
    let Some(shared) = shared_models("too_small_for_fasteners_gets_a_budget_and_strict_refuses")
    else {
        return;
    };
    let horse = shared.join("horse_quad.obj");
    let full = tmp.path().join("full");
    let (_, run) = build_run(&horse, "4ft", &full, &["--nester", "shelf"]);
    let warning = run
        .stderr
        .lines()
        .find(|l| l.contains(" fits at "))
        .unwrap_or_else(|| panic!("horse_quad: no one-line warning:\n{}", run.stderr));
    assert!(
        !run.stderr.contains(" connections hold no "),
        "one line, not names"
    );
    let budget = number_after(warning, "--target-edges ")
        .expect("a budget")
        .to_string();
    let fitted = tmp.path().join("fitted");
    let (m, run) = build_run(
        &horse,
        "4ft",
        &fitted,
        &["--target-edges", &budget, "--nester", "shelf"],
    );
    let bare = connections_without_holes(&m);
    let connections = count(&m, "counts.connections");
    eprintln!("horse_quad at the suggested {budget} edges: {bare} of {connections} without a hole");
    assert_eq!(
        bare, 0,
        "horse_quad at {budget} edges: {bare} of {connections} without a hole"
    );
    assert!(m.get("warnings").is_none(), "{}", run.stderr);
}
