//! An edge scheme end to end: every face's flaps (deeper, or in a wider band, where
//! corners need room for their pins), then one panel per edge, or both layers of the
//! sandwich, with the scheme's notes and its unfastened connections.

use glam::DVec3;
use rayon::prelude::*;

use super::flaps::{
    bend_id_label, bezier, corners_of, flap_labels, panel_id, EdgeOptions, FaceFlaps, FLAP_LABELS,
};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::panel::{Hole, Loops, Name, Panel, Panels, Source};
use crate::scheme::{ConnectionName, SchemeError, SchemeOutput, MOST_UNFASTENED};

/// The widest face band a face gets where a corner cannot hold a hole otherwise.
pub const MAX_FACE_SCALE: f64 = 0.9;

/// Steps from `--face-scale` to [`MAX_FACE_SCALE`] tried for such a face.
const BAND_STEPS: u32 = 4;

/// Which corners make an edge scheme widen a face's band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WidenFor {
    /// Corners that hold no hole.
    Bare,
    /// Corners that hold fewer holes than wanted (none included).
    Short,
}

/// A face's flaps `first` (at the options' face scale); where a corner cannot hold a
/// hole (with [`WidenFor::Short`], all its holes) even so, the face's band widened (its
/// corners nearer the face's own), step by step with `flaps_in_band`, kept where it
/// leaves fewer corners bare, or as many bare and fewer short of holes. The bends stay
/// developable: each band edge stays parallel to its mesh edge whatever the scale.
fn widened_band(
    options: &EdgeOptions,
    widen: WidenFor,
    first: FaceFlaps,
    flaps_in_band: impl Fn(&EdgeOptions) -> FaceFlaps,
) -> FaceFlaps {
    let scale = options.panel.face_scale;
    let shortfall = |f: &FaceFlaps| {
        let short = if widen == WidenFor::Short {
            f.reduced
        } else {
            0
        };
        (f.bare.len(), short)
    };
    if shortfall(&first) == (0, 0) || scale >= MAX_FACE_SCALE {
        return first;
    }
    let mut best = first;
    for i in 1..=BAND_STEPS {
        let mut wider = options.clone();
        wider.panel.face_scale =
            scale + (MAX_FACE_SCALE - scale) * f64::from(i) / f64::from(BAND_STEPS);
        let mut tried = flaps_in_band(&wider);
        if shortfall(&tried) < shortfall(&best) {
            tried.widened = true;
            best = tried;
        }
        if shortfall(&best) == (0, 0) {
            break;
        }
    }
    best
}

/// An edge scheme end to end: each face's flaps from `face_flaps` (in parallel, in
/// face order), widened where corners need it (`widen_bands`), then the panels, the
/// connection count (one per face corner) and the report lines; with `--layers 2`
/// both layers of every panel ([`super::sandwich`]), or the refusal of a bend too tight
/// for the card.
pub fn edge_scheme(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync,
) -> Result<SchemeOutput, SchemeError> {
    let faces = all_flaps(mesh, options, widen, &face_flaps);
    let connections: usize = faces.iter().map(FaceFlaps::corners).sum();
    let mut notes = edge_scheme_notes(mesh, &faces, connections, options);
    let panels = match options.sandwich {
        Some(t) => {
            // A bend too tight for the card is refused with a size or face scale that
            // this scheme, rebuilt so, finds round enough.
            let tightest = |m: &Mesh, o: &EdgeOptions| {
                super::sandwich::tightest_bend(m, &all_flaps(m, o, widen, &face_flaps), o, t)
            };
            let sandwich = super::sandwich::sandwich_panels(mesh, &faces, options, t, tightest)?;
            notes.extend(sandwich.notes);
            sandwich.panels
        }
        None => edge_panels(mesh, &faces, options),
    };
    Ok(SchemeOutput {
        panels,
        connections,
        notes,
        unfastened: unfastened(mesh, &faces),
        ..SchemeOutput::default()
    })
}

/// Every face's flaps: no deeper than the face's other corners first; then, for the
/// faces whose corners are short of holes, flaps that may grow past them
/// (`keep_if_fastened`); then bands widened where corners still need room.
fn all_flaps(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: &(impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync),
) -> Vec<FaceFlaps> {
    let shallow = EdgeOptions {
        deep_flaps: false,
        ..options.clone()
    };
    let mut faces: Vec<FaceFlaps> = (0..mesh.face_count() as u32)
        .into_par_iter()
        .map(|f| face_flaps(mesh, FaceId(f), &shallow))
        .collect();
    // Deep flaps are notched round the pins they pass; lapped into two layers, a
    // notch can pinch a flap to a thread, so the sandwich keeps flaps shallow.
    if options.deep_flaps && options.sandwich.is_none() {
        let deeper: Vec<(usize, FaceFlaps)> = (0..faces.len())
            .into_par_iter()
            .filter(|&k| !faces[k].bare.is_empty() || faces[k].reduced > 0)
            .map(|k| (k, face_flaps(mesh, FaceId(k as u32), options)))
            .collect();
        keep_if_fastened(&mut faces, deeper);
    }
    widen_bands(mesh, options, widen, face_flaps, &mut faces);
    faces
}

/// Widens the bands of the faces whose corners need room ([`widened_band`]), where
/// [`keep_if_fastened`] lets it.
fn widen_bands(
    mesh: &Mesh,
    options: &EdgeOptions,
    widen: WidenFor,
    face_flaps: &(impl Fn(&Mesh, FaceId, &EdgeOptions) -> FaceFlaps + Sync),
    faces: &mut [FaceFlaps],
) {
    let needs = |f: &FaceFlaps| !f.bare.is_empty() || (widen == WidenFor::Short && f.reduced > 0);
    let widened: Vec<(usize, FaceFlaps)> = (0..faces.len())
        .into_par_iter()
        .filter(|&k| needs(&faces[k]))
        .map(|k| {
            let f = FaceId(k as u32);
            let first = faces[k].clone();
            (
                k,
                widened_band(options, widen, first, |o| face_flaps(mesh, f, o)),
            )
        })
        .collect();
    keep_if_fastened(faces, widened);
}

/// Puts the flaps `tried` (a face's index, its flaps) in place of those faces', unless
/// the model stays too detailed for its fasteners even with them: more than
/// [`MOST_UNFASTENED`] of the corners bare (the build then warns with a budget,
/// and the larger flaps would cost sheets for a panel set that cannot be assembled as
/// asked anyway).
fn keep_if_fastened(faces: &mut [FaceFlaps], tried: Vec<(usize, FaceFlaps)>) {
    let corners: usize = faces.iter().map(FaceFlaps::corners).sum();
    let bare_before: usize = faces.iter().map(|f| f.bare.len()).sum();
    let fastened = tried
        .iter()
        .map(|(k, t)| faces[*k].bare.len() as isize - t.bare.len() as isize)
        .sum::<isize>()
        .max(0) as usize;
    if (bare_before.saturating_sub(fastened) as f64) <= MOST_UNFASTENED * corners as f64 {
        for (k, flaps) in tried {
            faces[k] = flaps;
        }
    }
}

/// The connections without a hole, face by face: the edge panels before and after
/// each bare corner, at its vertex.
pub fn unfastened(mesh: &Mesh, faces: &[FaceFlaps]) -> Vec<ConnectionName> {
    faces
        .iter()
        .flat_map(|f| &f.bare)
        .map(|&h| ConnectionName {
            panels: [panel_id(mesh.prev(h).edge()), panel_id(h.edge())],
            at: Name::vertex(mesh.origin(h).0),
        })
        .collect()
}

/// Report lines shared by the edge schemes: holes that did not fit, boundary panels.
pub fn edge_scheme_notes(
    mesh: &Mesh,
    faces: &[FaceFlaps],
    connections: usize,
    options: &EdgeOptions,
) -> Vec<String> {
    let bare: usize = faces.iter().map(|f| f.bare.len()).sum();
    // Connections without any hole are reported by the build (the fasteners check).
    let reduced = faces.iter().map(|f| f.reduced).sum::<usize>() - bare;
    let grown: usize = faces.iter().map(|f| f.grown).sum();
    let panel = &options.panel;
    let mut notes = Vec::new();
    if grown > 0 {
        notes.push(format!(
            "{grown} of {connections} connections have deeper flaps than --flap-scale {} to hold their fastener holes",
            options.flap_scale
        ));
    }
    let widened = faces.iter().filter(|f| f.widened).count();
    if widened > 0 {
        notes.push(format!(
            "{widened} of {} faces have a wider band than --face-scale {} to hold their fastener holes",
            faces.len(),
            panel.face_scale
        ));
    }
    if reduced > 0 {
        notes.push(format!(
            "{reduced} of {connections} connections hold fewer fastener holes than asked (--holes {} in each of a corner's flap overlaps) but at least one: their flap overlaps cannot hold more {} mm holes with {} mm of material around each; a larger --size, a smaller --hole-diameter or --hole-margin, or fewer panels (--target-edges) helps",
            panel.holes,
            crate::units::fmt_num(panel.hole_diameter),
            crate::units::fmt_num(panel.hole_margin)
        ));
    }
    let boundary = mesh.edges().filter(|&e| mesh.is_boundary_edge(e)).count();
    if boundary > 0 {
        notes.push(format!(
            "{boundary} boundary edges have a panel with a single flap and no bend"
        ));
    }
    notes
}

/// Builds every edge panel from the faces' flaps. Returns the panels (in edge order).
pub fn edge_panels(mesh: &Mesh, faces: &[FaceFlaps], options: &EdgeOptions) -> Panels {
    let corner_of = corners_of(mesh);
    Panels::build(mesh.edge_count(), |e| {
        edge_panel(mesh, EdgeId(e as u32), faces, &corner_of, options)
    })
}

/// The panel of edge `e`: flap in f, bend strips, flap in f′ (or the flap alone on the
/// boundary). Every buffer is sized exactly before it is filled: a big job builds
/// millions of panels, and none should grow twice.
fn edge_panel(
    mesh: &Mesh,
    e: EdgeId,
    faces: &[FaceFlaps],
    corner_of: &[u32],
    options: &EdgeOptions,
) -> Panel {
    // Work from a half-edge that has a face (boundary edges have one).
    let h = if mesh.is_boundary_half_edge(e.half_edge()) {
        e.half_edge().twin()
    } else {
        e.half_edge()
    };
    let f = mesh.face(h).expect("an edge has a face on one side");
    let part = &faces[f.index()];
    let k = corner_of[h.index()] as usize;
    // The face across, its flaps and the corner the twin leaves from.
    let across = mesh
        .face(h.twin())
        .map(|g| (g, &faces[g.index()], corner_of[h.twin().index()] as usize));
    // Bend strips (none on the boundary).
    let n = if across.is_some() {
        options.samples.max(1) as usize
    } else {
        0
    };
    let rest_f = part.flap_rest(k);
    let rest_g = across.map_or(&[][..], |(_, other, k2)| other.flap_rest(k2));

    let mut vertices: Vec<DVec3> = Vec::with_capacity(2 * (n + 1) + rest_f.len() + rest_g.len());
    push_rails(
        mesh,
        h,
        (part, k),
        across.map(|(_, o, k2)| (o, k2)),
        n,
        options,
        &mut vertices,
    );
    let (rail_v, rail_w) = (|i: usize| 2 * i as u32, |i: usize| 2 * i as u32 + 1);

    // One flap on a boundary edge, two otherwise; each flap is its two rail ends and
    // its rest, each bend strip a quad.
    let flaps = 1 + usize::from(across.is_some());
    let mut facets =
        Loops::with_capacity(flaps + n, 2 * flaps + rest_f.len() + rest_g.len() + 4 * n);
    let hole_count = part.flap_holes(k).count()
        + across.map_or(0, |(_, other, k2)| other.flap_holes(k2).count());
    let mut holes = Vec::with_capacity(hole_count);
    let mut add_flap = |part: &FaceFlaps,
                        edge: usize,
                        start: u32,
                        end: u32,
                        vertices: &mut Vec<DVec3>,
                        facets: &mut Loops| {
        let first = vertices.len() as u32;
        let rest = part.flap_rest(edge);
        vertices.extend_from_slice(rest);
        let facet = facets.len() as u32;
        facets.push(
            [start, end]
                .into_iter()
                .chain(first..first + rest.len() as u32),
        );
        holes.extend(part.flap_holes(edge).map(|(p, connection)| Hole {
            position: p,
            diameter: options.panel.hole_diameter,
            connection,
            facet,
        }));
        facet
    };
    add_flap(part, k, rail_v(0), rail_w(0), &mut vertices, &mut facets);
    let flap_g = across.map(|(g, other, k2)| {
        for i in 0..n {
            facets.push([rail_w(i), rail_v(i), rail_v(i + 1), rail_w(i + 1)]);
        }
        let facet = add_flap(other, k2, rail_w(n), rail_v(n), &mut vertices, &mut facets);
        (g, other, k2, facet)
    });

    let mut labels = Vec::with_capacity(1 + FLAP_LABELS * (1 + usize::from(n > 0)));
    // On the bend's middle strip (the flap is facet 0; a boundary panel has only it).
    let (id, height) = (panel_id(e), options.panel.label_height);
    labels.push(bend_id_label(id, &vertices, &facets, 1 + n / 2, n, height));
    flap_labels(mesh, part, f, h, k, 0, options, &mut labels);
    if let Some((g, other, k2, facet)) = flap_g {
        flap_labels(mesh, other, g, h.twin(), k2, facet, options, &mut labels);
    }

    Panel::new(Source::edge(e.0), vertices, facets, holes, labels)
}

/// The rails at v and at v′ of half-edge `h`'s panel, pushed onto `vertices` in pairs
/// sampled at the same t on both (so rulings stay parallel to the edge): rail point i
/// is vertex 2i at v, 2i + 1 at v′. The rails run in `n` strips from band corner k of
/// its face (`own`) to the corners of the face across (`across`: its flaps and the
/// corner the twin leaves from); on the boundary they are the band edge's two ends.
fn push_rails(
    mesh: &Mesh,
    h: HalfedgeId,
    (part, k): (&FaceFlaps, usize),
    across: Option<(&FaceFlaps, usize)>,
    n: usize,
    options: &EdgeOptions,
    vertices: &mut Vec<DVec3>,
) {
    let band_f = part.band();
    let k1 = (k + 1) % part.corners();
    let Some((other, k2)) = across else {
        vertices.extend([band_f[k], band_f[k1]]);
        return;
    };
    let (v, w) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
    let m = 0.5 * (v + w);
    let b = options.bridge_scale;
    let (cv, cw) = (b * v + (1.0 - b) * m, b * w + (1.0 - b) * m);
    // In g the twin runs w → v: band corner k2 is at w, k2 + 1 at v.
    let band_g = other.band();
    let (gv, gw) = (band_g[(k2 + 1) % band_g.len()], band_g[k2]);
    for i in 0..=n {
        let t = i as f64 / n as f64;
        vertices.push(bezier(band_f[k], cv, gv, t));
        vertices.push(bezier(band_f[k1], cw, gw, t));
    }
}
