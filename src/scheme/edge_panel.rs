//! What the edge schemes (quad-edge, winged-edge) share: a panel per edge made of a flap
//! in each face plane joined by a Bézier bend (thesis ch. 4.2, steps 1–3), the face
//! frames the flaps are drawn in, pin placement in an overlap, and the labels.
//!
//! A scheme describes each face by a [`FaceFlaps`]: the band, each band edge's flap
//! outline and the holes on each flap. [`edge_panels`] turns those into panels.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::{face_band, SchemeOptions};
use crate::mesh::{EdgeId, FaceId, HalfEdgeId, Mesh};
use crate::panel::{Hole, Label, LabelKind, Loops, Name, Panel, Source};
use crate::plane::{contains, distance_to_border};

/// The id printed for an edge panel.
pub fn panel_id(e: EdgeId) -> Name {
    Name::Edge(e.0)
}

/// One face's share of the edge panels, in 3D.
#[derive(Clone, Debug, Default)]
pub struct FaceFlaps {
    /// Band corners B_k (corner k at the origin of the face's k-th half-edge).
    pub band: Vec<DVec3>,
    /// Per band edge k (B_k → B_k+1): the flap's outline after B_k, B_k+1,
    /// counter-clockwise.
    pub flap_rest: Vec<Vec<DVec3>>,
    /// Per band edge k: the holes through that flap, with their connection ids.
    pub flap_holes: Vec<Vec<(DVec3, u32)>>,
    /// Per corner k: where the vertex id goes (between the pins).
    pub corner_label: Vec<DVec3>,
    /// Connections (face corners) with fewer holes than wanted.
    pub reduced: usize,
    /// Connections with no hole at all although holes were wanted.
    pub bare: usize,
}

/// A 2D frame in a face's plane, centred on the face centre.
#[derive(Clone, Copy, Debug)]
pub struct FaceFrame {
    /// Face centre.
    pub centre: DVec3,
    /// In-plane axes.
    pub ex: DVec3,
    /// In-plane axes.
    pub ey: DVec3,
}

impl FaceFrame {
    /// The frame of face `f`.
    pub fn new(mesh: &Mesh, f: FaceId) -> Self {
        let normal = mesh.face_normal(f);
        let ex = normal.any_orthonormal_vector();
        Self {
            centre: mesh.face_centre(f),
            ex,
            ey: normal.cross(ex),
        }
    }

    /// Into the plane (the face centre is the origin).
    pub fn to2(&self, p: DVec3) -> DVec2 {
        DVec2::new(
            (p - self.centre).dot(self.ex),
            (p - self.centre).dot(self.ey),
        )
    }

    /// Back to 3D.
    pub fn to3(&self, q: DVec2) -> DVec3 {
        self.centre + q.x * self.ex + q.y * self.ey
    }
}

/// The face band of `f` in 3D and in its frame. The band corners are projected onto
/// the face's plane (through its centre, normal to its vector area), so every flap is
/// an exactly planar facet and the holes of a corner lie on both flaps even when the
/// face is planar only within the tolerance; on a planar face nothing moves.
pub fn band(
    mesh: &Mesh,
    f: FaceId,
    options: &SchemeOptions,
) -> (Vec<DVec3>, Vec<DVec2>, FaceFrame) {
    let frame = FaceFrame::new(mesh, f);
    let normal = frame.ex.cross(frame.ey);
    let band: Vec<DVec3> = face_band(mesh, f, options.face_scale)
        .into_iter()
        .map(|p| p - (p - frame.centre).dot(normal) * normal)
        .collect();
    let flat = band.iter().map(|&p| frame.to2(p)).collect();
    (band, flat, frame)
}

/// The half-edges of a face in loop order (corner k is the origin of the k-th).
pub fn corner_half_edges(mesh: &Mesh, f: FaceId) -> Vec<HalfEdgeId> {
    mesh.face_half_edges(f).collect()
}

/// Pin positions in an overlap: symmetric about `centre` along `along` (the overlap's
/// long direction) at the closest spacing that leaves one diameter of material between
/// pins, each with one diameter of material to the overlap's border (outlines and
/// score lines). When the wanted count does not fit, fewer pins (4 → 2 → 1 → 0).
/// Returns the centres and whether fewer than wanted were placed.
pub fn place_pins(
    overlap: &[DVec2],
    centre: DVec2,
    along: DVec2,
    wanted: u32,
    diameter: f64,
) -> (Vec<DVec2>, bool) {
    if wanted == 0 || overlap.len() < 3 {
        return (Vec::new(), wanted > 0);
    }
    let r = 0.5 * diameter;
    let u = along.normalize_or_zero();
    let w = u.perp();
    let half = 0.5 * (2.0 * r + diameter);
    let fits = |pins: &[DVec2]| {
        pins.iter()
            .all(|&p| contains(overlap, p) && distance_to_border(overlap, p) >= r + diameter)
    };
    for count in [4, 2, 1].into_iter().filter(|&c| c <= wanted) {
        let pins: Vec<DVec2> = match count {
            4 => vec![
                centre + half * (u + w),
                centre + half * (u - w),
                centre - half * (u + w),
                centre - half * (u - w),
            ],
            2 => vec![centre - half * u, centre + half * u],
            _ => vec![centre],
        };
        if fits(&pins) {
            return (pins, count < wanted);
        }
    }
    (Vec::new(), true)
}

/// An edge scheme end to end: each face's flaps from `face_flaps` (in parallel, in
/// face order), then the panels, the connection count (one per face corner) and the
/// report lines.
pub fn edge_scheme(
    mesh: &Mesh,
    options: &SchemeOptions,
    face_flaps: impl Fn(&Mesh, FaceId, &SchemeOptions) -> FaceFlaps + Sync,
) -> super::SchemeOutput {
    let faces: Vec<FaceFlaps> = (0..mesh.face_count() as u32)
        .into_par_iter()
        .map(|f| face_flaps(mesh, FaceId(f), options))
        .collect();
    let panels = edge_panels(mesh, &faces, options);
    let connections: usize = faces.iter().map(|f| f.band.len()).sum();
    super::SchemeOutput {
        panels,
        connections,
        notes: edge_scheme_notes(mesh, &faces, connections, options),
        cycles: Vec::new(),
    }
}

/// Report lines shared by the edge schemes: holes that did not fit, boundary panels.
pub fn edge_scheme_notes(
    mesh: &Mesh,
    faces: &[FaceFlaps],
    connections: usize,
    options: &SchemeOptions,
) -> Vec<String> {
    let reduced: usize = faces.iter().map(|f| f.reduced).sum();
    let bare: usize = faces.iter().map(|f| f.bare).sum();
    let mut notes = Vec::new();
    if reduced > 0 {
        notes.push(format!(
            "{reduced} of {connections} connections have fewer than {} fastener holes ({bare} have none): their flap overlap cannot hold more {} mm holes with one diameter of material around each; a larger --size, smaller --hole-diameter or larger --flap-scale helps",
            options.holes, options.hole_diameter
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
pub fn edge_panels(mesh: &Mesh, faces: &[FaceFlaps], options: &SchemeOptions) -> Vec<Panel> {
    let mut corner_of = vec![0u32; mesh.half_edge_count()];
    for f in mesh.faces() {
        for (k, h) in mesh.face_half_edges(f).enumerate() {
            corner_of[h.index()] = k as u32;
        }
    }
    (0..mesh.edge_count() as u32)
        .into_par_iter()
        .map(|e| edge_panel(mesh, EdgeId(e), faces, &corner_of, options))
        .collect()
}

/// Quadratic Bézier point.
fn bezier(p0: DVec3, p1: DVec3, p2: DVec3, t: f64) -> DVec3 {
    let s = 1.0 - t;
    s * s * p0 + 2.0 * s * t * p1 + t * t * p2
}

/// The panel of edge `e`: flap in f, bend strips, flap in f′ (or the flap alone on the
/// boundary).
fn edge_panel(
    mesh: &Mesh,
    e: EdgeId,
    faces: &[FaceFlaps],
    corner_of: &[u32],
    options: &SchemeOptions,
) -> Panel {
    // Work from a half-edge that has a face (boundary edges have one).
    let h = if mesh.is_boundary_half_edge(e.half_edge()) {
        e.half_edge().twin()
    } else {
        e.half_edge()
    };
    let f = mesh.face(h).expect("an edge has a face on one side");
    let twin_face = mesh.face(h.twin());
    let part = &faces[f.index()];
    let k = corner_of[h.index()] as usize;
    let k1 = (k + 1) % part.band.len();

    let mut vertices: Vec<DVec3> = Vec::new();
    let push = |p: DVec3, vertices: &mut Vec<DVec3>| {
        vertices.push(p);
        (vertices.len() - 1) as u32
    };
    let mut facets = Loops::new();
    let mut holes = Vec::new();
    let mut labels = Vec::new();

    // Rails (at v and at v′) sampled at the same t on both, so rulings stay parallel
    // to the edge.
    let (rail_v, rail_w): (Vec<u32>, Vec<u32>) = match twin_face {
        Some(g) => {
            let other = &faces[g.index()];
            let k2 = corner_of[h.twin().index()] as usize;
            let (v, w) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
            let m = 0.5 * (v + w);
            let b = options.bridge_scale;
            let (cv, cw) = (b * v + (1.0 - b) * m, b * w + (1.0 - b) * m);
            // In g the twin runs w → v: band corner k2 is at w, k2 + 1 at v.
            let (gv, gw) = (other.band[(k2 + 1) % other.band.len()], other.band[k2]);
            let n = options.samples.max(1);
            (0..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    let a = push(bezier(part.band[k], cv, gv, t), &mut vertices);
                    let b = push(bezier(part.band[k1], cw, gw, t), &mut vertices);
                    (a, b)
                })
                .unzip()
        }
        None => {
            let a = push(part.band[k], &mut vertices);
            let b = push(part.band[k1], &mut vertices);
            (vec![a], vec![b])
        }
    };

    let mut add_flap = |part: &FaceFlaps,
                        edge: usize,
                        start: u32,
                        end: u32,
                        vertices: &mut Vec<DVec3>,
                        facets: &mut Loops| {
        let mut flap = vec![start, end];
        for &p in &part.flap_rest[edge] {
            flap.push(push(p, vertices));
        }
        let facet = facets.len() as u32;
        facets.push(flap);
        for &(p, connection) in &part.flap_holes[edge] {
            holes.push(Hole {
                position: p,
                diameter: options.hole_diameter,
                connection,
                facet,
            });
        }
        facet
    };
    add_flap(part, k, rail_v[0], rail_w[0], &mut vertices, &mut facets);

    let n = rail_v.len() - 1;
    let mut flap_g = None;
    if let Some(g) = twin_face {
        for i in 0..n {
            facets.push(vec![rail_w[i], rail_v[i], rail_v[i + 1], rail_w[i + 1]]);
        }
        let k2 = corner_of[h.twin().index()] as usize;
        let facet = add_flap(
            &faces[g.index()],
            k2,
            rail_w[n],
            rail_v[n],
            &mut vertices,
            &mut facets,
        );
        flap_g = Some((g, k2, facet));
    }

    // The panel id: on the middle strip of the bend, along the edge (on the flap for a
    // boundary edge).
    let (a, b) = (
        vertices[rail_v[n / 2] as usize],
        vertices[rail_w[n / 2] as usize],
    );
    let id_facet = if n > 0 { 1 + n / 2 } else { 0 };
    let id_facet = id_facet.min(facets.len() - 1);
    let corners: Vec<DVec3> = facets[id_facet]
        .iter()
        .map(|&i| vertices[i as usize])
        .collect();
    labels.push(Label {
        text: panel_id(e),
        anchor: corners.iter().copied().sum::<DVec3>() / corners.len() as f64,
        direction: (b - a).normalize(),
        height: options.label_height,
        facet: id_facet as u32,
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.3 * a.distance(b),
    });
    flap_labels(mesh, part, f, h, k, 0, options, &mut labels);
    if let Some((g, k2, facet)) = flap_g {
        flap_labels(
            mesh,
            &faces[g.index()],
            g,
            h.twin(),
            k2,
            facet,
            options,
            &mut labels,
        );
    }

    Panel::new(Source::Edge(e.0), vertices, facets, holes, labels)
}

/// Labels on a flap: the partner panel's id toward each of its two corners, the vertex
/// id at each corner's pins, the face id in the middle (in that priority).
#[allow(clippy::too_many_arguments)]
fn flap_labels(
    mesh: &Mesh,
    part: &FaceFlaps,
    face: FaceId,
    he: HalfEdgeId,
    corner: usize,
    facet: u32,
    options: &SchemeOptions,
    labels: &mut Vec<Label>,
) {
    let next_corner = (corner + 1) % part.band.len();
    let (a, b) = (part.band[corner], part.band[next_corner]);
    let rest = &part.flap_rest[corner];
    let middle = (a + b + rest.iter().copied().sum::<DVec3>()) / (2 + rest.len()) as f64;
    let along = (b - a).normalize();
    let ends = [
        (mesh.prev(he), corner, mesh.origin(he)),
        (mesh.next(he), next_corner, mesh.dest(he)),
    ];
    for (partner, c, _) in ends {
        labels.push(Label {
            text: panel_id(partner.edge()),
            // Between the flap's middle and the pins at that corner.
            anchor: 0.5 * (middle + part.corner_label[c]),
            direction: along,
            height: options.label_height,
            facet,
            kind: LabelKind::Partner,
            on_edge: false,
            slide: 0.15 * a.distance(b),
        });
    }
    for (_, c, vertex) in ends {
        labels.push(Label {
            text: Name::Vertex(vertex.0),
            anchor: part.corner_label[c],
            direction: along,
            height: options.label_height,
            facet,
            kind: LabelKind::Mark,
            on_edge: false,
            slide: 0.0,
        });
    }
    labels.push(Label {
        text: Name::Face(face.0),
        anchor: middle,
        direction: along,
        height: options.label_height,
        facet,
        kind: LabelKind::Mark,
        on_edge: false,
        slide: 0.1 * a.distance(b),
    });
}
