//! An island's panel: its faces as facets with corners shared along folds, the tabs its
//! faces own, the fastener holes, its id and the match numbers of its cuts.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use super::grow::Islands;
use super::options::{IslandOptions, MATCH};
use crate::mesh::{EdgeId, FaceId, Mesh};
use crate::panel::{Hole, Label, LabelKind, Loops, Name, Panel, Source};
use crate::scheme::kit::labels::longest_side_direction;
use crate::scheme::kit::tab::Tab;

/// What every island's panel is built from.
pub(super) struct BuiltNet<'a> {
    pub(super) mesh: &'a Mesh,
    pub(super) islands: &'a Islands,
    /// The tab of each cut edge, where one fits.
    pub(super) tabs: &'a [Option<Tab>],
    /// Each cut edge's match number (from 1), where it carries one.
    pub(super) match_of: HashMap<u32, u32>,
    /// Numbered once per seam (`OwnNet::seams`).
    pub(super) seams: bool,
    /// Each face's facet in its island's panel.
    pub(super) facet_of: Vec<u32>,
    pub(super) options: &'a IslandOptions,
}

/// A panel under construction: corners, facets, holes and labels.
#[derive(Default)]
struct PanelParts {
    vertices: Vec<DVec3>,
    facets: Loops,
    holes: Vec<Hole>,
    labels: Vec<Label>,
}

/// Builds island `number`'s panel: its faces (facets in face order, corners shared
/// along folds), then the tabs its faces own; the island id on a central face, match
/// numbers on both sides of every cut edge that carries one.
pub(super) fn island_panel(net: &BuiltNet, source: Source, faces: &[u32]) -> Panel {
    let mut parts = PanelParts::default();
    let tab_bases = island_faces(net, faces, &mut parts);
    tab_facets(net, tab_bases, &mut parts);
    folded_holes(net, faces, &mut parts);
    parts.labels.push(island_label(net, source.id, faces));
    Panel::new(
        source,
        parts.vertices,
        parts.facets,
        parts.holes,
        parts.labels,
    )
}

/// The island's faces as facets, one vertex per fan of corners joined by folds, each
/// tab's base corners in the facet of the face that owns it, and the match number
/// inside each face at a cut edge whose tab is not its own; returns the owned tabs'
/// edges and base corners.
fn island_faces(net: &BuiltNet, faces: &[u32], parts: &mut PanelParts) -> Vec<(EdgeId, u32, u32)> {
    let (mesh, tabs) = (net.mesh, net.tabs);
    let height = net.options.panel.label_height;
    let mut vertex_of: HashMap<u32, u32> = HashMap::new();
    let mut tab_bases = Vec::new();
    for &f in faces {
        let f = FaceId(f);
        let mut facet = Vec::new();
        for h in mesh.face_half_edges(f) {
            let key = net.islands.joined.root(h.0);
            facet.push(*vertex_of.entry(key).or_insert_with(|| {
                parts.vertices.push(mesh.position(mesh.origin(h)));
                (parts.vertices.len() - 1) as u32
            }));
            let e = h.edge();
            let own_tab = tabs[e.index()].as_ref().filter(|t| t.owner == h);
            if let Some(tab) = own_tab {
                parts.vertices.extend(tab.base);
                let n = parts.vertices.len() as u32;
                facet.extend([n - 2, n - 1]);
                tab_bases.push((e, n - 2, n - 1));
            }
            // The match number inside this face at a cut edge, unless its tab carries it.
            // Numbered once per seam, the number goes inside the face on both sides,
            // where there is more room than on a tab.
            let inside = own_tab.is_none() || net.seams;
            if let (Some(&m), true) = (net.match_of.get(&e.0), inside) {
                let (a, b) = (mesh.position(mesh.origin(h)), mesh.position(mesh.dest(h)));
                parts.labels.push(Label {
                    text: Name::new(&MATCH, m),
                    anchor: 0.5 * (a + b),
                    direction: (b - a).normalize(),
                    height,
                    facet: net.facet_of[f.index()],
                    kind: LabelKind::Partner,
                    on_edge: true,
                    slide: 0.3 * a.distance(b),
                });
            }
        }
        parts.facets.push(facet);
    }
    tab_bases
}

/// Each owned tab as a facet from its base corners (`tab_bases`) through its top, with
/// its match number and fastener holes.
fn tab_facets(net: &BuiltNet, tab_bases: Vec<(EdgeId, u32, u32)>, parts: &mut PanelParts) {
    for (e, a_base, b_base) in tab_bases {
        let Some(placed) = net.tabs[e.index()].as_ref() else {
            continue;
        };
        let facet_index = parts.facets.len() as u32;
        let mut facet = vec![b_base, a_base];
        for &p in &placed.top {
            parts.vertices.push(p);
            facet.push((parts.vertices.len() - 1) as u32);
        }
        parts.facets.push(facet);
        let (a, b) = (placed.base[0], placed.base[1]);
        if let (Some(&m), true) = (net.match_of.get(&e.0), !net.seams) {
            parts.labels.push(Label {
                text: Name::new(&MATCH, m),
                anchor: 0.5 * (a + b),
                direction: (a - b).normalize(),
                height: net.options.panel.label_height,
                facet: facet_index,
                kind: LabelKind::Partner,
                on_edge: true,
                slide: 0.2 * a.distance(b),
            });
        }
        parts.holes.extend(placed.holes.iter().map(|&p| Hole {
            position: p,
            diameter: net.options.panel.hole_diameter,
            connection: e.0,
            facet: facet_index,
        }));
    }
}

/// The holes of tabs other islands (or this one) fold onto the island's faces.
fn folded_holes(net: &BuiltNet, faces: &[u32], parts: &mut PanelParts) {
    for &f in faces {
        for h in net.mesh.face_half_edges(FaceId(f)) {
            let Some(placed) = net.tabs[h.edge().index()]
                .as_ref()
                .filter(|t| t.owner == h.twin())
            else {
                continue;
            };
            parts.holes.extend(placed.holes.iter().map(|&p| Hole {
                position: p,
                diameter: net.options.panel.hole_diameter,
                connection: h.edge().0,
                facet: net.facet_of[f as usize],
            }));
        }
    }
}

/// The island's id on the largest face near its middle, along that face's longest
/// edge.
fn island_label(net: &BuiltNet, id: Name, faces: &[u32]) -> Label {
    let mesh = net.mesh;
    let label_face = central_face(mesh, net.islands, faces);
    let corners: Vec<DVec3> = mesh.face_positions(FaceId(label_face)).collect();
    Label {
        text: id,
        anchor: mesh.face_centre(FaceId(label_face)),
        direction: longest_side_direction(&corners),
        height: net.options.panel.label_height,
        facet: net.facet_of[label_face as usize],
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.0,
    }
}

/// The face that shows an island's id: the largest among those whose centre lies in
/// the inner half of the island (flat), or the largest of all when none does.
fn central_face(mesh: &Mesh, islands: &Islands, faces: &[u32]) -> u32 {
    let centre_of = |f: u32| {
        let poly = islands.polygon(mesh, FaceId(f));
        poly.iter().copied().sum::<DVec2>() / poly.len() as f64
    };
    let middle = faces.iter().map(|&f| centre_of(f)).sum::<DVec2>() / faces.len() as f64;
    let reach = faces
        .iter()
        .map(|&f| centre_of(f).distance(middle))
        .fold(0.0, f64::max);
    let largest = |pool: &mut dyn Iterator<Item = u32>| {
        pool.max_by(|&x, &y| {
            mesh.face_area(FaceId(x))
                .total_cmp(&mesh.face_area(FaceId(y)))
                .then(y.cmp(&x))
        })
    };
    largest(
        &mut faces
            .iter()
            .copied()
            .filter(|&f| centre_of(f).distance(middle) <= 0.5 * reach),
    )
    .or_else(|| largest(&mut faces.iter().copied()))
    .unwrap_or(faces[0])
}
