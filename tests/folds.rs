//! Fold kinds: every score line is a mountain or a valley seen from the outside of the
//! model, and the sheets put valleys on their own layer. The kinds are checked against
//! the model itself: the convexity of the mesh edge a fold lies on (from the faces'
//! planes) and the side of the fold's second facet from the first facet's plane, with
//! each facet's outside read off the mesh face it lies on.

use crate::common;

use std::collections::BTreeMap;

use common::build::*;
use glam::DVec3;
use tempfile::TempDir;
use unfold::config::{BuildOptions, ModelOptions};
use unfold::mesh::{EdgeId, FaceId, Mesh};
use unfold::panel::{Covers, FlatPanel, FoldKind, Panel};

/// The kind of an interior mesh edge from its faces: valley where the second face
/// rises above the first face's plane (the surface turns towards its outside).
fn edge_kind(mesh: &Mesh, e: EdgeId) -> Option<FoldKind> {
    let h = e.half_edge();
    let f = mesh.face(h)?;
    let g = mesh.face(mesh.twin(h))?;
    let n = mesh.face_normal(f);
    let on_f = mesh.position(mesh.origin(h));
    let rise = mesh
        .face_positions(g)
        .map(|p| n.dot(p - on_f))
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))?;
    let size = mesh.edge_length(e);
    if rise.abs() < 1e-9 * size {
        None
    } else if rise > 0.0 {
        Some(FoldKind::Valley)
    } else {
        Some(FoldKind::Mountain)
    }
}

/// The mesh face nearest a 3D point whose plane passes within `tol` of it, if any.
fn face_at(mesh: &Mesh, p: DVec3, tol: f64) -> Option<FaceId> {
    mesh.faces()
        .filter(|&f| mesh.face_normal(f).dot(p - mesh.face_centre(f)).abs() < tol)
        .min_by(|&a, &b| {
            p.distance(mesh.face_centre(a))
                .total_cmp(&p.distance(mesh.face_centre(b)))
        })
}

/// The facets of `panel` that use the edge `a`–`b`.
fn facets_on(panel: &Panel, a: u32, b: u32) -> Vec<usize> {
    panel
        .facets
        .iter()
        .enumerate()
        .filter(|(_, f)| f.contains(&a) && f.contains(&b))
        .map(|(k, _)| k)
        .collect()
}

/// The mesh edge that carries the segment `p`–`q` (within `tol`), if any.
fn edge_under(mesh: &Mesh, p: DVec3, q: DVec3, tol: f64) -> Option<EdgeId> {
    // Only edges at one of the fold's ends can carry it: those of the vertices
    // nearest its ends.
    let nearest = |x: DVec3| {
        mesh.vertices()
            .min_by(|&a, &b| {
                mesh.position(a)
                    .distance(x)
                    .total_cmp(&mesh.position(b).distance(x))
            })
            .expect("a mesh has vertices")
    };
    let near: Vec<EdgeId> = [nearest(p), nearest(q)]
        .into_iter()
        .flat_map(|v| {
            mesh.vertex_outgoing(v)
                .map(|h| h.edge())
                .collect::<Vec<_>>()
        })
        .collect();
    near.into_iter().find(|&e| {
        let (u, w) = mesh.edge_vertices(e);
        let (u, w) = (mesh.position(u), mesh.position(w));
        let d = (w - u).normalize();
        let on = |x: DVec3| {
            let t = d.dot(x - u);
            (x - u - d * t).length() < tol && t > -tol && t < u.distance(w) + tol
        };
        on(p) && on(q)
    })
}

/// Folds of each kind, and how many of them lie on a mesh edge.
#[derive(Default, Debug)]
struct FoldCounts {
    kinds: BTreeMap<FoldKind, usize>,
    on_edges: usize,
}

/// Checks every fold of `panels` against the model (see the module docs) and counts
/// them. Folds on a mesh edge must have the edge's kind (for the panel of that edge, for
/// a face's tab on one of its edges); every fold must have the kind its two facets make,
/// with the facets' outside checked against the mesh faces they lie in.
fn check_folds(
    what: &str,
    mesh: &Mesh,
    panels: &[Panel],
    flat: &[FlatPanel],
    size: f64,
) -> FoldCounts {
    let tol = 1e-7 * size;
    let mut counts = FoldCounts::default();
    for (panel, fp) in panels.iter().zip(flat) {
        let normal = |k: usize| {
            let pts: Vec<DVec3> = panel.facets[k]
                .iter()
                .map(|&i| panel.vertices[i as usize])
                .collect();
            let mut n = DVec3::ZERO;
            for i in 0..pts.len() {
                n += pts[i].cross(pts[(i + 1) % pts.len()]);
            }
            n.normalize()
        };
        for fold in &fp.folds {
            *counts.kinds.entry(fold.kind).or_default() += 1;
            let [a, b] = fold.ends;
            let (p, q) = (panel.vertices[a as usize], panel.vertices[b as usize]);
            let id = panel.id();
            // The two facets' own dihedral, as the assembled panel bends.
            let users = facets_on(panel, a, b);
            assert_eq!(users.len(), 2, "{what}: {id} fold {a}-{b} is not a hinge");
            let (f, g) = (users[0], users[1]);
            let nf = normal(f);
            let far = panel.facets[g]
                .iter()
                .map(|&i| nf.dot(panel.vertices[i as usize] - p))
                .max_by(|x, y| x.abs().total_cmp(&y.abs()))
                .unwrap();
            let facets_say = if far > 0.0 {
                FoldKind::Valley
            } else {
                FoldKind::Mountain
            };
            assert_eq!(
                fold.kind, facets_say,
                "{what}: {id} fold {a}-{b} against its facets' dihedral"
            );
            // Facet f's outside is the outside of the model where f lies on a face.
            let centre = panel.facets[f]
                .iter()
                .map(|&i| panel.vertices[i as usize])
                .sum::<DVec3>()
                / panel.facets[f].len() as f64;
            if let Some(face) = face_at(mesh, centre, tol) {
                assert!(
                    nf.dot(mesh.face_normal(face)) > 0.0,
                    "{what}: {id} facet {f} faces into the model"
                );
            }
            // And the mesh edge under the fold, where there is one.
            let edge = match panel.source.covers {
                Covers::Edge(e) => Some(EdgeId(e)),
                _ => edge_under(mesh, p, q, tol),
            };
            if let Some(e) = edge {
                if !matches!(panel.source.covers, Covers::Itself) {
                    counts.on_edges += 1;
                    assert_eq!(
                        Some(fold.kind),
                        edge_kind(mesh, e),
                        "{what}: {id} fold {a}-{b} against mesh edge E{}",
                        e.0
                    );
                }
            }
        }
    }
    counts
}

/// Interior mesh edges by kind (flat ones left out).
fn edge_kinds(mesh: &Mesh) -> BTreeMap<FoldKind, usize> {
    let mut kinds = BTreeMap::new();
    for e in mesh.edges() {
        if let Some(kind) = edge_kind(mesh, e) {
            *kinds.entry(kind).or_insert(0) += 1;
        }
    }
    kinds
}

#[test]
fn every_fold_of_genus3_has_the_kind_of_its_dihedral() {
    let tmp = TempDir::new().unwrap();
    for scheme in ["half-edge", "quad-edge", "winged-edge", "woven", "net"] {
        let job = job(scheme, &model("genus3"), "1ft", 0, &tmp.path().join(scheme));
        let p = pipeline(&job);
        let what = format!("genus3 {scheme}");
        let counts = check_folds(&what, &p.mesh, &p.panels, &p.flat, 304.8);
        let mesh_kinds = edge_kinds(&p.mesh);
        // The three square tunnels each have four concave corners.
        assert_eq!(mesh_kinds.get(&FoldKind::Valley), Some(&12), "{what}");
        let kinds = &counts.kinds;
        assert!(
            kinds.get(&FoldKind::Mountain).is_some() && kinds.get(&FoldKind::Valley).is_some(),
            "{what}: both kinds occur: {kinds:?}"
        );
        if scheme == "net" {
            // Every fold and every tab lies on a mesh edge.
            assert_eq!(counts.on_edges, kinds.values().sum::<usize>(), "{what}");
        }
        if scheme == "half-edge" {
            // One tab, so one fold, on every bent edge.
            assert_eq!(kinds, &mesh_kinds, "{what}");
            assert_eq!(counts.on_edges, kinds.values().sum::<usize>(), "{what}");
        }
        if scheme == "quad-edge" {
            // Every bent edge's panel scores its bend's rulings (samples + 1 lines).
            let rulings = 5;
            for kind in [FoldKind::Mountain, FoldKind::Valley] {
                assert_eq!(
                    kinds[&kind],
                    rulings * mesh_kinds[&kind],
                    "{what}: {kind:?}"
                );
            }
        }
    }
}

/// The pipeline of a shared model, with the options a user would give.
fn shared_pipeline(name: &str, scheme: &str, target_edges: Option<usize>) -> Option<Pipeline> {
    let dir = shared_models("folds")?;
    let tmp = TempDir::new().unwrap();
    let options = BuildOptions {
        scheme: Some(scheme.to_string()),
        out: Some(tmp.path().join("out")),
        model: ModelOptions {
            size: Some("4ft".into()),
            target_edges: target_edges.map(unfold::config::TargetEdges::Count),
            ..Default::default()
        },
        ..Default::default()
    };
    Some(pipeline(&resolve(options, &dir.join(name))))
}

#[test]
fn bunny_and_spot_have_mountain_and_valley_folds() {
    for (name, scheme, target) in [
        ("stanford-bunny.obj", "quad-edge", Some(625)),
        ("spot.obj", "half-edge", None),
    ] {
        let Some(p) = shared_pipeline(name, scheme, target) else {
            return;
        };
        let what = format!("{name} {scheme}");
        let counts = check_folds(&what, &p.mesh, &p.panels, &p.flat, 1219.2);
        let mountains = counts.kinds.get(&FoldKind::Mountain).copied().unwrap_or(0);
        let valleys = counts.kinds.get(&FoldKind::Valley).copied().unwrap_or(0);
        eprintln!("{what}: {mountains} mountain and {valleys} valley folds");
        assert!(mountains > 0 && valleys > 0, "{what}: both kinds occur");
        // Folds lie on mesh edges for these schemes: all were checked against them.
        assert_eq!(counts.on_edges, mountains + valleys, "{what}");
    }
}

#[test]
fn sheets_put_valleys_on_their_own_layer_and_mirroring_swaps_them() {
    let tmp = TempDir::new().unwrap();
    let path = model("genus3");
    for mirror in [false, true] {
        let out = tmp.path().join(format!("mirror-{mirror}"));
        let extra: &[&str] = if mirror { &["--mirror"] } else { &[] };
        let m = build("quad-edge", &path, "1ft", &out, extra);
        let sheets = check_sheets(&out, &m, DxfCheck::All);
        let total = sheets.total();
        // Valleys seen from the top of the sheet: a panel cut face down turns over.
        let p = pipeline(&job("quad-edge", &path, "1ft", 2, &tmp.path().join("job")));
        let by_id: BTreeMap<String, &FlatPanel> =
            p.flat.iter().map(|fp| (fp.id().to_string(), fp)).collect();
        let mut valleys_on_top = 0;
        let mut mirrored = 0;
        for entry in m["panels"].as_array().unwrap() {
            let fp = by_id[entry["id"].as_str().unwrap()];
            let flipped = entry["mirrored"].as_bool().unwrap();
            mirrored += usize::from(flipped);
            let seen = if flipped {
                FoldKind::Mountain
            } else {
                FoldKind::Valley
            };
            valleys_on_top += fp.folds.iter().filter(|f| f.kind == seen).count();
        }
        assert_eq!(total.valley_paths, valleys_on_top, "mirror {mirror}");
        assert!(total.valley_paths > 0, "mirror {mirror}");
        assert_eq!(
            count(&m, "counts.folds_valley"),
            p.flat
                .iter()
                .map(|fp| fp
                    .folds
                    .iter()
                    .filter(|f| f.kind == FoldKind::Valley)
                    .count())
                .sum::<usize>()
        );
        assert_eq!(
            count(&m, "counts.folds_mountain") + count(&m, "counts.folds_valley"),
            total.score_paths,
            "mirror {mirror}: every score line is a fold"
        );
        if mirror {
            assert!(mirrored > 0, "some panels are placed mirrored");
        }
    }
}
