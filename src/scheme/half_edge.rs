//! The half-edge scheme: one panel per face (its face band), and on every interior edge
//! a tab on one of the two panels that folds along the edge onto the neighbour.
//!
//! The tab lies in the neighbour's plane, inside the triangle (edge, neighbour centre):
//! those triangles tile a star-shaped face, so tabs arriving on one face never overlap
//! each other and never leave it. Its sides lean in at 45° (so tabs of one panel do not
//! meet when unrolled around a corner); where the triangle is lower than the wanted
//! height the tab is shortened. With a face scale `s < 1` the panels are smaller than
//! the faces and the tab first spans the gap in its own face's plane (a bridge facet).

use glam::{DVec2, DVec3};

use super::{
    args_of, face_band, Configured, OptionValues, PanelDefaults, PanelOptions, Scheme, SchemeError,
    SchemeOutput,
};
use crate::mesh::{EdgeId, FaceId, HalfedgeId, Mesh};
use crate::panel::{fill_arena, Arena, Hole, Label, LabelKind, Loops, Name, Panel, Panels, Source};
use crate::plane::{area, clip_convex, distance_to_border};
use crate::record::{round4, Params};

/// A tab, in 3D: its base on the edge (inset from the corners) and the rest of its
/// outline, plus the fastener holes through it and the neighbour.
#[derive(Clone, Debug)]
pub(super) struct Tab {
    /// Owner half-edge (a → b in the owner face).
    pub(super) owner: HalfedgeId,
    /// Base points on the edge: a' near a, b' near b.
    pub(super) base: [DVec3; 2],
    /// The tab outline after b', a' (so the tab facet is b', a', top…).
    pub(super) top: Vec<DVec3>,
    /// Hole centres (in the neighbour's plane).
    pub(super) holes: Vec<DVec3>,
    /// The tab is lower than wanted.
    pub(super) shortened: bool,
    /// Fewer holes than wanted fit (perhaps none).
    pub(super) holes_skipped: bool,
}

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

/// Connector kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Connectors {
    /// A glue or pin tab on one of the two panels.
    Tab,
    /// Nothing: panels meet edge to edge.
    None,
}

/// The half-edge options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct HalfEdgeArgs {
    /// Connectors on interior edges: tab or none. [default: tab]
    #[arg(long, value_name = "KIND")]
    connectors: Option<Connectors>,

    #[command(flatten)]
    tab: TabArgs,
}

/// The tab option of the schemes that glue tabs (half-edge, net), as given.
#[derive(Clone, Debug, Default, clap::Args)]
pub(super) struct TabArgs {
    /// Wanted overlap of a tab on its neighbour panel, with a unit; tabs are shortened
    /// where the neighbour is smaller. [default: 8mm]
    #[arg(long, value_name = "LENGTH")]
    tab_height: Option<String>,
}

impl TabArgs {
    /// The tab height (mm), checked, or its default.
    pub(super) fn height(&self) -> Result<f64, String> {
        crate::units::positive_length("tab-height", self.tab_height.as_deref(), "8mm")
    }
}

/// The defaults of the schemes that glue whole faces with tabs (half-edge, net): faces
/// whole, no holes unless asked (glue holds), up to two through each tab.
pub(super) const TAB_DEFAULTS: PanelDefaults = PanelDefaults {
    face_scale: 1.0,
    holes: 0,
    holes_allowed: &[0, 1, 2],
};

/// The half-edge scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct HalfEdgeOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Tabs on interior edges.
    pub tabs: bool,
    /// Wanted height of a tab's overlap with its neighbour (mm).
    pub tab_height: f64,
}

impl Scheme for HalfEdge {
    fn name(&self) -> &'static str {
        "half-edge"
    }

    fn about(&self) -> &'static str {
        "one panel per face, tabs on interior edges"
    }

    fn options(&self) -> Vec<clap::Arg> {
        args_of::<HalfEdgeArgs>()
    }

    fn defaults(&self) -> PanelDefaults {
        TAB_DEFAULTS
    }

    fn needs_convex_faces(&self) -> bool {
        // A tab lies in the neighbour face along one edge: star-shaped faces suffice.
        false
    }

    fn overlap_fix(&self) -> &'static str {
        "a smaller --tab-height"
    }

    fn configure(
        &self,
        values: &OptionValues,
        panel: PanelOptions,
    ) -> Result<Box<dyn Configured>, String> {
        let args: HalfEdgeArgs = values.parse()?;
        Ok(Box::new(HalfEdgeOptions {
            panel,
            tabs: args.connectors.unwrap_or(Connectors::Tab) == Connectors::Tab,
            tab_height: args.tab.height()?,
        }))
    }
}

impl Configured for HalfEdgeOptions {
    fn panel(&self) -> &PanelOptions {
        &self.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        Ok(panels(mesh, self))
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("connectors", if self.tabs { "tab" } else { "none" });
        params.push("tab_height", round4(self.tab_height));
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
        Ok(make_tab(mesh, owner, options))
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
    let half_edges: Vec<HalfedgeId> = mesh.face_half_edges(f).collect();
    let n = half_edges.len();
    let tab_of = |h: HalfedgeId| tabs.of_edge(h.edge());
    let mut labels = Vec::with_capacity(n + 1);
    let longest = (0..n)
        .max_by(|&i, &j| {
            let li = band[i].distance(band[(i + 1) % n]);
            let lj = band[j].distance(band[(j + 1) % n]);
            li.total_cmp(&lj).then(j.cmp(&i))
        })
        .unwrap_or(0);
    let centre = band.iter().copied().sum::<DVec3>() / n as f64;
    labels.push(Label {
        text: panel_id(f),
        anchor: centre,
        direction: (band[(longest + 1) % n] - band[longest]).normalize(),
        height: options.panel.label_height,
        facet: 0,
        kind: LabelKind::Panel,
        on_edge: false,
        slide: 0.0,
    });
    for (k, &h) in half_edges.iter().enumerate() {
        let Some(g) = mesh.face(h.twin()) else {
            continue;
        };
        if options.tabs && tab_of(h).is_none() {
            continue;
        }
        let (a, b) = (band[k], band[(k + 1) % n]);
        labels.push(Label {
            text: panel_id(g),
            anchor: 0.5 * (a + b),
            direction: (b - a).normalize(),
            height: options.panel.label_height,
            facet: 0,
            kind: LabelKind::Partner,
            on_edge: true,
            // Room to dodge the holes of a tab arriving on this edge.
            slide: 0.3 * a.distance(b),
        });
    }
    labels
}

/// The tab that the face of `owner` (a → b) folds onto the neighbour across it, or
/// `None` when the neighbour cannot hold one.
pub(super) fn make_tab(mesh: &Mesh, owner: HalfedgeId, options: &HalfEdgeOptions) -> Option<Tab> {
    let g = mesh.face(owner.twin())?;
    let (a, b) = (
        mesh.position(mesh.origin(owner)),
        mesh.position(mesh.dest(owner)),
    );
    let length = a.distance(b);
    let x = (b - a) / length;
    let n_g = mesh.face_normal(g);
    // Inward direction of the neighbour at this edge, in its plane.
    let y = x.cross(n_g).normalize();
    let to2 = |p: DVec3| DVec2::new((p - a).dot(x), (p - a).dot(y));
    let to3 = |q: DVec2| a + q.x * x + q.y * y;
    let centre = to2(mesh.face_centre(g));
    if centre.y <= 0.0 {
        return None;
    }
    let s = options.panel.face_scale;
    let gap = (1.0 - s) * centre.y;
    let wanted = gap + options.tab_height;
    // Inset the base a little from the corners so tabs from neighbouring edges that
    // arrive on the same face do not touch.
    let inset = (0.05 * length).min(0.5);
    let (lo, hi) = (inset, length - inset);
    let trapezoid = if hi - lo > 2.0 * wanted {
        vec![
            DVec2::new(lo, 0.0),
            DVec2::new(hi, 0.0),
            DVec2::new(hi - wanted, wanted),
            DVec2::new(lo + wanted, wanted),
        ]
    } else {
        let h = 0.5 * (hi - lo);
        vec![
            DVec2::new(lo, 0.0),
            DVec2::new(hi, 0.0),
            DVec2::new(0.5 * (lo + hi), h),
        ]
    };
    let sector = [DVec2::ZERO, DVec2::new(length, 0.0), centre];
    let tab = clip_convex(&trapezoid, &sector);
    let top_height = tab.iter().map(|q| q.y).fold(0.0, f64::max);
    let overlap = top_height - gap;
    if tab.len() < 3 || area(&tab) <= 0.0 || overlap < (0.5 * options.tab_height).min(1.0) {
        return None;
    }
    // The tab facet runs b', a', then the rest: the clipped polygon is
    // counter-clockwise in (x, y) starting at a' = (lo, 0), b' = (hi, 0).
    let start = tab
        .iter()
        .position(|q| q.distance(DVec2::new(lo, 0.0)) < 1e-9)?;
    let ccw: Vec<DVec2> = (0..tab.len())
        .map(|k| tab[(start + k) % tab.len()])
        .collect();
    if ccw[1].distance(DVec2::new(hi, 0.0)) > 1e-9 {
        return None;
    }
    let top: Vec<DVec3> = ccw[2..].iter().rev().map(|&q| to3(q)).collect();

    let (holes, holes_skipped) =
        place_holes(&ccw, gap, top_height, &face_band(mesh, g, s), &to2, options);
    Some(Tab {
        owner,
        base: [to3(DVec2::new(lo, 0.0)), to3(DVec2::new(hi, 0.0))],
        top,
        holes: holes.into_iter().map(to3).collect(),
        shortened: top_height < wanted - 1e-9,
        holes_skipped,
    })
}

/// Hole centres along the middle of the tab's overlap with the neighbour band, each
/// with the hole margin of material to the tab's and the band's outline: as many as
/// asked, or as many as fit; and whether fewer than asked fit.
fn place_holes(
    tab: &[DVec2],
    gap: f64,
    top_height: f64,
    neighbour_band: &[DVec3],
    to2: &dyn Fn(DVec3) -> DVec2,
    options: &HalfEdgeOptions,
) -> (Vec<DVec2>, bool) {
    let count = options.panel.holes;
    if count == 0 {
        return (Vec::new(), false);
    }
    let r = 0.5 * options.panel.hole_diameter;
    // The hole's radius and the margin of material to the tab's and the face's edges.
    let clearance = r + options.panel.hole_margin;
    let v = 0.5 * (gap + top_height);
    // The tab's extent at height v (it is convex: two crossings).
    let mut xs = Vec::new();
    for i in 0..tab.len() {
        let (p, q) = (tab[i], tab[(i + 1) % tab.len()]);
        if (p.y - v) * (q.y - v) <= 0.0 && p.y != q.y {
            xs.push(p.x + (v - p.y) / (q.y - p.y) * (q.x - p.x));
        }
    }
    let (Some(u0), Some(u1)) = (
        xs.iter().copied().reduce(f64::min),
        xs.iter().copied().reduce(f64::max),
    ) else {
        return (Vec::new(), true);
    };
    let band: Vec<DVec2> = neighbour_band.iter().map(|&p| to2(p)).collect();
    // `count` holes evenly along the middle of the tab, if they all fit.
    let along = |count: u32| -> Option<Vec<DVec2>> {
        let centres: Vec<DVec2> = (1..=count)
            .map(|k| DVec2::new(u0 + (u1 - u0) * k as f64 / (count + 1) as f64, v))
            .collect();
        let fits = centres.iter().all(|&c| {
            distance_to_border(tab, c) >= clearance
                && crate::plane::contains(&band, c)
                && distance_to_border(&band, c) >= clearance
        }) && centres
            .windows(2)
            .all(|w| w[0].distance(w[1]) >= 2.0 * r + options.panel.hole_diameter);
        fits.then_some(centres)
    };
    // The wanted count, or as many as fit.
    (1..=count)
        .rev()
        .find_map(|n| along(n).map(|centres| (centres, n < count)))
        .unwrap_or((Vec::new(), true))
}
