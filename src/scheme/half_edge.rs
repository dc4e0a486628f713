//! The half-edge scheme: one panel per face (its face band), and on every interior edge
//! a tab on one of the two panels that folds along the edge onto the neighbour.
//!
//! The tab lies in the neighbour's plane, inside the triangle (edge, neighbour centre):
//! those triangles tile a star-shaped face, so tabs arriving on one face never overlap
//! each other and never leave it. Its sides lean in at 45° (so tabs of one panel do not
//! meet when unrolled around a corner); where the triangle is lower than the wanted
//! height the tab is shortened. With a face scale `s < 1` the panels are smaller than
//! the faces and the tab first spans the gap in its own face's plane (a bridge facet).
//!
//! In rigid sheet (`--thickness` above zero) nothing folds: each panel is its face cut
//! back where a neighbour's material needs the room ([`super::rigid::cutback`]), and the panels
//! meet edge to edge.

use glam::DVec3;

use super::kit::labels::outline_labels;
use super::kit::tab::{make_tab, tab_defaults, Tab, TabArgs, TabOptions, TAB_DEFAULTS};
use super::rigid::sheet::{
    rigid_defaults, rigid_output, Connectors, PanelNames, RigidArgs, RigidSheet,
};
use super::{
    args_of, face_band, Configured, Configuring, OptionValues, PanelOptions, Scheme, SchemeError,
    SchemeInfo, SchemeOutput,
};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::option_default::state_defaults;
use crate::panel::{fill_arena, Arena, Hole, Label, Loops, Name, Panel, Panels, Source};
use crate::record::{round4, Params};

/// The tabs of a mesh's edges, kept sparse: on a fine mesh most edges have none (the
/// neighbour face is too small to hold one), and a slot the size of a tab per edge
/// would cost more than the panels.
#[derive(Default)]
struct Tabs {
    /// Per edge, the index of its tab in `tabs`, or `NO_TAB`.
    slot: Vec<u32>,
    /// The tabs, in edge order.
    tabs: Vec<Tab>,
}

/// The slot of an edge without a tab.
const NO_TAB: u32 = u32::MAX;

impl Arena for Tabs {
    type Made = Option<Tab>;

    /// Appends the next edge's tab (or its lack of one).
    fn take(&mut self, tab: Option<Tab>) {
        match tab {
            Some(tab) => {
                // Fewer tabs than edges, and edge ids are u32.
                self.slot.push(self.tabs.len() as u32);
                self.tabs.push(tab);
            }
            None => self.slot.push(NO_TAB),
        }
    }

    fn append(&mut self, other: Tabs) {
        let offset = self.tabs.len() as u32;
        self.slot.extend(other.slot.iter().map(|&k| match k {
            NO_TAB => NO_TAB,
            k => k + offset,
        }));
        self.tabs.extend(other.tabs);
    }
}

impl Tabs {
    /// The tab of edge `e`, if it has one.
    fn of_edge(&self, e: EdgeId) -> Option<&Tab> {
        match self.slot[e.index()] {
            NO_TAB => None,
            k => Some(&self.tabs[k as usize]),
        }
    }
}

/// The half-edge scheme: one panel per face, tabs on interior edges.
pub struct HalfEdge;

/// The half-edge options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct HalfEdgeArgs {
    #[command(flatten)]
    rigid: RigidArgs,

    #[command(flatten)]
    tab: TabArgs,
}

/// The half-edge scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct HalfEdgeOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Tabs on interior edges.
    pub tabs: bool,
    /// Wanted height of a tab's overlap with its neighbour (mm).
    pub tab_height: f64,
    /// Rigid sheet: the thickness (zero for card) and what joins the panels.
    pub rigid: RigidSheet,
}

const INFO: SchemeInfo = SchemeInfo {
    name: "half-edge",
    about: "one panel per face, tabs on interior edges",
    defaults: TAB_DEFAULTS,
    // A tab lies in the neighbour face along one edge: star-shaped faces suffice.
    needs_convex_faces: false,
    overlap_fix: "a smaller --tab-height",
};

impl Scheme for HalfEdge {
    fn info(&self) -> &SchemeInfo {
        &INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<HalfEdgeArgs>(),
            &[rigid_defaults().as_slice(), &[tab_defaults()]].concat(),
        )
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        let args: HalfEdgeArgs = values.parse()?;
        let rigid = args.rigid.resolve(&panel)?;
        Ok(Box::new(HalfEdgeOptions {
            panel,
            tabs: rigid.connectors == Connectors::Tab,
            tab_height: args.tab.height()?,
            rigid,
        }))
    }
}

impl Configured for HalfEdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        if self.rigid.thickness > 0.0 {
            let names = PanelNames::of_faces(mesh);
            rigid_output(mesh, mesh, &self.rigid, &self.panel, &names)
        } else {
            Ok(panels(mesh, self))
        }
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("connectors", self.rigid.connectors_name());
        params.push("tab_height", round4(self.tab_height));
        self.rigid.sheet_params(&mut params);
        params
    }
}

/// The id printed for a face panel.
pub fn panel_id(f: FaceId) -> Name {
    Name::face(f.0)
}

/// Builds the face panels of a mesh whose faces are planar and star-shaped from their
/// centres (the split stage ensures both).
pub fn panels(mesh: &Mesh, options: &HalfEdgeOptions) -> SchemeOutput {
    let tab = TabOptions::new(&options.panel, options.tab_height);
    // Tabs per edge (interior edges only), computed independently in parallel and
    // collected in edge order.
    let made: Result<Tabs, std::convert::Infallible> = fill_arena(mesh.edge_count(), |e| {
        let e = EdgeId(e as u32);
        if !options.tabs || mesh.is_boundary_edge(e) {
            return Ok(None);
        }
        // The owner alternates with the edge index: even edges give the tab to the
        // face of half-edge 2e, odd edges to the face of 2e + 1.
        let owner = if e.0.is_multiple_of(2) {
            e.half_edge()
        } else {
            e.half_edge().twin()
        };
        Ok(make_tab(mesh, owner, &tab))
    });
    let Ok(mut tabs) = made;
    tabs.slot.shrink_to_fit();
    tabs.tabs.shrink_to_fit();

    let connections = tabs.tabs.len();
    let mut notes = Vec::new();
    let interior = mesh.edges().filter(|&e| !mesh.is_boundary_edge(e)).count();
    if options.tabs && connections < interior {
        notes.push(format!(
            "{} interior edges have no tab: their neighbour face is too small to hold one",
            interior - connections
        ));
    }
    let shortened = tabs.tabs.iter().filter(|t| t.shortened).count();
    if shortened > 0 {
        notes.push(format!(
            "{shortened} tabs were shortened to stay inside their neighbour face"
        ));
    }
    // Connections without any hole are reported by the build (the fasteners check).
    let fewer = tabs
        .tabs
        .iter()
        .filter(|t| t.holes_skipped && !t.holes.is_empty())
        .count();
    if fewer > 0 {
        notes.push(format!(
            "{fewer} of {connections} connections have fewer than {} fastener holes (but at least one): their tab cannot hold more {} mm holes with {} mm of material around each; a larger --tab-height or --size, or a smaller --hole-diameter or --hole-margin, helps",
            options.panel.holes,
            crate::units::fmt_num(options.panel.hole_diameter),
            crate::units::fmt_num(options.panel.hole_margin)
        ));
    }
    let unfastened = tabs
        .tabs
        .iter()
        .filter(|t| options.panel.holes > 0 && t.holes.is_empty())
        .filter_map(|t| {
            let neighbour = mesh.face(t.owner.twin())?;
            Some(super::ConnectionName {
                panels: [Name::face(mesh.face(t.owner)?.0), Name::face(neighbour.0)],
                at: Name::edge(t.owner.edge().0),
            })
        })
        .collect();

    let panels = Panels::build(mesh.face_count(), |f| {
        let f = FaceId(f as u32);
        face_panel(
            mesh,
            f,
            &face_band(mesh, f, options.panel.face_scale),
            &tabs,
            options,
        )
    });
    SchemeOutput {
        panels,
        connections,
        notes,
        unfastened,
        ..SchemeOutput::default()
    }
}

/// Builds the panel of face `f`.
fn face_panel(
    mesh: &Mesh,
    f: FaceId,
    band: &[DVec3],
    tabs: &Tabs,
    options: &HalfEdgeOptions,
) -> Panel {
    let s = options.panel.face_scale;
    let mut vertices: Vec<DVec3> = band.to_vec();
    let add = |p: DVec3, vertices: &mut Vec<DVec3>| {
        vertices.push(p);
        (vertices.len() - 1) as u32
    };
    let half_edges: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
    let n = half_edges.len();
    let mut band_facet: Vec<u32> = Vec::with_capacity(n + 4);
    let mut extra_facets: Vec<Vec<u32>> = Vec::new();
    let mut holes = Vec::new();
    // Facet 0 is the band; tab facets follow (indices known once pushed).
    let tab_of = |h: HalfedgeId| tabs.of_edge(h.edge());
    let mut pending_tabs: Vec<(&Tab, u32, u32)> = Vec::new();
    // With s < 1, the mesh corners where bridges meet: one vertex per corner, shared by
    // the bridges on both sides so that their common side is a (flat) hinge, not a
    // cut running there and back.
    let mut mesh_corner: Vec<Option<u32>> = vec![None; n];
    for (k, &h) in half_edges.iter().enumerate() {
        band_facet.push(k as u32);
        let Some(tab) = tab_of(h).filter(|t| t.owner == h) else {
            continue;
        };
        let a_base = add(tab.base[0], &mut vertices);
        let b_base = add(tab.base[1], &mut vertices);
        if s >= 1.0 {
            // The tab hinges on the face edge itself.
            band_facet.push(a_base);
            band_facet.push(b_base);
        } else {
            // Bridge across the gap in the face's own plane: band edge → mesh edge.
            let mut corner = |i: usize, vertices: &mut Vec<DVec3>| {
                *mesh_corner[i]
                    .get_or_insert_with(|| add(mesh.position(mesh.origin(half_edges[i])), vertices))
            };
            let a = corner(k, &mut vertices);
            let b = corner((k + 1) % n, &mut vertices);
            let (ka, kb) = (k as u32, ((k + 1) % n) as u32);
            extra_facets.push(vec![kb, ka, a, a_base, b_base, b]);
        }
        pending_tabs.push((tab, a_base, b_base));
    }
    let mut facets = Loops::new();
    facets.push(band_facet);
    for facet in extra_facets {
        facets.push(facet);
    }
    for (tab, a_base, b_base) in pending_tabs {
        let mut facet = vec![b_base, a_base];
        for &p in &tab.top {
            facet.push(add(p, &mut vertices));
        }
        let facet_index = facets.len() as u32;
        facets.push(facet);
        for &p in &tab.holes {
            holes.push(Hole {
                position: p,
                diameter: options.panel.hole_diameter,
                connection: tab.owner.edge().0,
                facet: facet_index,
            });
        }
    }
    // Holes of tabs other panels fold onto this face go through the band.
    for &h in &half_edges {
        if let Some(tab) = tab_of(h).filter(|t| t.owner != h) {
            for &p in &tab.holes {
                holes.push(Hole {
                    position: p,
                    diameter: options.panel.hole_diameter,
                    connection: tab.owner.edge().0,
                    facet: 0,
                });
            }
        }
    }

    let labels = face_labels(mesh, f, band, tabs, options);
    Panel::new(Source::face(f.0), vertices, facets, holes, labels)
}

/// The labels of face `f`'s panel: its id at the centre, along the longest band edge;
/// the partner id inside every interior edge (with tabs, only where a tab joins).
fn face_labels(
    mesh: &Mesh,
    f: FaceId,
    band: &[DVec3],
    tabs: &Tabs,
    options: &HalfEdgeOptions,
) -> Vec<Label> {
    let tab_of = |h: HalfedgeId| tabs.of_edge(h.edge());
    let partners = mesh
        .face_half_edges(f)
        .enumerate()
        .filter(|&(_, h)| !options.tabs || tab_of(h).is_some())
        .filter_map(|(k, h)| Some((k, panel_id(mesh.face(h.twin())?))));
    let centre = band.iter().copied().sum::<DVec3>() / band.len() as f64;
    outline_labels(
        panel_id(f),
        centre,
        band,
        partners,
        options.panel.label_height,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::{tetrahedron, two_triangles};
    use crate::panel::LabelKind;
    use crate::scheme::assert_points;

    /// Face 1 of [`two_triangles`] with its centre 40 mm from the hinge: high enough
    /// for a full tab of a few mm.
    const TALL: DVec3 = DVec3::new(30.0, 120.0, 0.0);

    /// Options with faces shrunk by `face_scale`, `holes` holes of 1 mm with 0.5 mm of
    /// margin per tab, and tabs `tab_height` high.
    fn options(face_scale: f64, holes: u32, tab_height: f64) -> HalfEdgeOptions {
        HalfEdgeOptions {
            panel: PanelOptions {
                face_scale,
                holes,
                hole_diameter: 1.0,
                hole_margin: 0.5,
                label_height: 2.0,
                panel_limit: None,
                scale: 1.0,
            },
            tabs: true,
            tab_height,
            rigid: crate::scheme::rigid::sheet::RigidSheet::CARD,
        }
    }

    /// The tab face 0 of `two_triangles(apex)` folds onto face 1 across the hinge.
    fn hinge_tab(apex: DVec3, options: &HalfEdgeOptions) -> Option<Tab> {
        let tab = TabOptions::new(&options.panel, options.tab_height);
        make_tab(&two_triangles(apex), HalfedgeId(4), &tab)
    }

    #[test]
    fn a_hole_without_its_margin_in_the_tab_is_left_out_and_reported() {
        // Radius 1.5 + margin 1 = 2.5 mm from every cut edge, but the 4 mm tab's middle
        // is 2 mm from its base and top.
        let mut options = options(1.0, 1, 4.0);
        options.panel.hole_diameter = 3.0;
        options.panel.hole_margin = 1.0;
        let tab = hinge_tab(TALL, &options).unwrap();
        assert!(tab.holes.is_empty() && tab.holes_skipped);
        let out = panels(&two_triangles(TALL), &options);
        let unfastened: Vec<String> = out.unfastened.iter().map(|c| c.to_string()).collect();
        assert_eq!(unfastened, ["F0/F1 at E2"]);
    }

    #[test]
    fn whole_faces_carry_their_tab_on_the_hinge_and_share_its_holes() {
        let out = panels(&two_triangles(TALL), &options(1.0, 1, 4.0));
        // One panel per face, one connection for the one interior edge.
        assert_eq!((out.panels.len(), out.connections), (2, 1));
        assert!(out.notes.is_empty(), "{:?}", out.notes);
        let (owner, partner) = (out.panels.get(0), out.panels.get(1));
        assert_eq!(
            (owner.id().to_string(), partner.id().to_string()),
            ("F0".to_string(), "F1".to_string())
        );
        // Face 0's corners (0,0,0), (30,−30,0), (60,0,0), whole (face scale 1); then
        // the tab's base a', b' and its top.
        assert_points(
            owner.vertices,
            &[
                [0.0, 0.0, 0.0],
                [30.0, -30.0, 0.0],
                [60.0, 0.0, 0.0],
                [59.5, 0.0, 0.0],
                [0.5, 0.0, 0.0],
                [55.5, 4.0, 0.0],
                [4.5, 4.0, 0.0],
            ],
        );
        // The band runs through the tab's base, so the tab hinges on the face edge.
        let facets: Vec<Vec<u32>> = owner.facets.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(facets, vec![vec![0, 1, 2, 3, 4], vec![4, 3, 5, 6]]);
        let facets: Vec<Vec<u32>> = partner.facets.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(facets, vec![vec![0, 1, 2]]);
        // The one hole, at (30, 2, 0) (the middle of 2.5…57.5 at y = 2), goes through
        // the tab (facet 1) and the neighbour's band (facet 0) at the same point.
        for (panel, facet) in [(owner, 1), (partner, 0)] {
            assert_eq!(panel.holes.len(), 1);
            let hole = &panel.holes[0];
            assert_points(&[hole.position], &[[30.0, 2.0, 0.0]]);
            assert_eq!(
                (hole.connection, hole.facet, hole.diameter),
                (2, facet, 1.0)
            );
        }
        // The owner names its partner along the hinge.
        let partners: Vec<Name> = owner
            .labels
            .iter()
            .filter(|l| l.kind == LabelKind::Partner)
            .map(|l| l.text)
            .collect();
        assert_eq!(partners, vec![Name::face(1)]);
    }

    #[test]
    fn a_shrunk_face_bridges_the_gap_to_its_tab() {
        let out = panels(&two_triangles(TALL), &options(0.5, 0, 4.0));
        let owner = out.panels.get(0);
        // Face 0's centre is (30,−10,0): each corner moves halfway to it. The gap to
        // face 1's band is half its centre's 40 mm height, so the tab rises 20 + 4 mm,
        // its 45° top from x = 0.5 + 24 to 59.5 − 24.
        assert_points(
            owner.vertices,
            &[
                [15.0, -5.0, 0.0],
                [30.0, -20.0, 0.0],
                [45.0, -5.0, 0.0],
                [59.5, 0.0, 0.0],
                [0.5, 0.0, 0.0],
                [60.0, 0.0, 0.0],
                [0.0, 0.0, 0.0],
                [35.5, 24.0, 0.0],
                [24.5, 24.0, 0.0],
            ],
        );
        // Band, then the bridge from band edge (45,−5)–(15,−5) to the mesh edge
        // through the tab's base, then the tab.
        let facets: Vec<Vec<u32>> = owner.facets.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(
            facets,
            vec![vec![0, 1, 2], vec![0, 2, 5, 3, 4, 6], vec![4, 3, 7, 8]]
        );
        assert!(out.notes.is_empty(), "{:?}", out.notes);
    }

    #[test]
    fn a_closed_mesh_has_a_panel_per_face_and_a_tab_per_edge() {
        let mut mesh = tetrahedron();
        // Edges 2√2·20 ≈ 56.6 mm: each face's centre is 56.6/(2√3) ≈ 16.3 mm from its
        // edges, room for a full 8 mm tab.
        mesh.scale(20.0);
        let out = panels(&mesh, &options(1.0, 0, 8.0));
        assert_eq!((out.panels.len(), out.connections), (4, 6));
        assert!(out.notes.is_empty(), "{:?}", out.notes);
        let ids: Vec<String> = out.panels.iter().map(|p| p.id().to_string()).collect();
        assert_eq!(ids, ["F0", "F1", "F2", "F3"]);
        // Each panel is its band and one facet per tab it owns: 4 + 6 facets.
        let facets: usize = out.panels.iter().map(|p| p.facets.len()).sum();
        assert_eq!(facets, 10);
    }

    #[test]
    fn connectors_none_makes_bare_faces() {
        let mut options = options(1.0, 0, 8.0);
        options.tabs = false;
        let out = panels(&two_triangles(TALL), &options);
        assert_eq!(out.connections, 0);
        assert!(out.panels.iter().all(|p| p.facets.len() == 1));
    }
}
