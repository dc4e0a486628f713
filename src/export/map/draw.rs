//! Drawing a view: its patches far to near, tinted by sheet and shaded by how they face
//! the viewer, then the ids of the panels it shows, each where its own panel is seen
//! and clear of the ids already written.

use std::fmt::Write;

use glam::{DVec2, DVec3};

use super::layout::{text_lines, MapContext, MapInput, GAP};
use super::page::text_width;
use super::raster::Raster;
use super::view::{project, View};
use crate::export::fmt_mm;
use crate::panel::surface::Patch;

/// Id text heights on paper (mm): large enough to read printed, small enough that
/// neighbouring panels' ids fit.
const TEXT_MIN: f64 = 1.8;
const TEXT_MAX: f64 = 3.0;

/// The fill of a closed model's inside where a close-up cuts it open.
const INSIDE: &str = "#D0D0D0";

/// View `k` in its cell: its group (with the projection, for readers that map page
/// points back to the model), caption, patches far to near and the panel ids where
/// their panels are seen; `named` marks the panels named so far.
pub(super) fn draw_view(
    out: &mut String,
    map: &MapContext,
    k: usize,
    view: &View,
    (lo, hi): (DVec2, DVec2),
    named: &mut [bool],
) {
    let grid = &map.grid;
    let (col, row) = (k % grid.cols, k / grid.cols);
    let cell_lo = grid.lo + DVec2::new(col as f64 * grid.cell_w, row as f64 * grid.cell_h);
    let centre = 0.5 * (lo + hi);
    // The model's centre in the middle of the cell below its caption.
    let scale = grid.scale;
    let drawing_mid = grid.caption_h + 0.5 * (grid.cell_h - grid.caption_h - GAP);
    let frame = Frame {
        view,
        origin: cell_lo + DVec2::new(0.5 * grid.cell_w, drawing_mid)
            - scale * DVec2::new(centre.x, -centre.y),
        scale,
        area: (cell_lo, DVec2::new(grid.cell_w, grid.cell_h)),
        contain: false,
        cut_open: false,
    };
    let _ = writeln!(
        out,
        "<g id=\"view-{name}\" data-view=\"{name}\" {}>",
        frame.projection(),
        name = view.name
    );
    text_lines(out, &grid.captions[k], cell_lo + DVec2::new(2.0, 0.0));
    let surface = map.input.surface;
    draw_frame(out, map, &frame, &surface.patches, named, None);
    out.push_str("</g>\n");
}

/// A view in its place on the page.
pub(super) struct Frame<'a> {
    pub view: &'a View,
    /// The page point of the model's origin.
    pub origin: DVec2,
    /// Page mm per model mm.
    pub scale: f64,
    /// Where on the page ids may go: top-left corner and size.
    pub area: (DVec2, DVec2),
    /// Ids must lie wholly inside `area` (a close-up's drawing runs past it).
    pub contain: bool,
    /// The model in front is cut away (a close-up's), so a closed model's inside
    /// shows.
    pub cut_open: bool,
}

impl Frame<'_> {
    /// Where a model point lands on the page: the view's (right, up) scaled, y down.
    pub fn to_page(&self, p: DVec3) -> DVec2 {
        let q = project(p, self.view);
        self.origin + self.scale * DVec2::new(q.x, -q.y)
    }

    /// The projection's attributes, for readers that map page points back.
    pub fn projection(&self) -> String {
        format!(
            "data-toward=\"{}\" data-up=\"{}\" data-scale=\"{}\" data-origin=\"{} {}\"",
            vec3(self.view.toward),
            vec3(self.view.up),
            self.scale,
            self.origin.x,
            self.origin.y
        )
    }
}

/// `patches` (the model's, or a close-up's cut from them) drawn in `frame` far to
/// near, `first` outlined, then the ids of the panels seen, `first` before any other;
/// returns whether `first` was named.
pub(super) fn draw_frame(
    out: &mut String,
    map: &MapContext,
    frame: &Frame,
    patches: &[Patch],
    named: &mut [bool],
    first: Option<usize>,
) -> bool {
    let to_page = |p: DVec3| frame.to_page(p);
    let closed = map.input.surface.closed;
    // A closed model cut open shows its inside: the backs of its faces, drawn grey,
    // hide what lies behind them and name no panel.
    let inside = |p: &Patch| closed && frame.cut_open && p.normal.dot(frame.view.toward) <= 1e-9;
    let order = far_to_near(patches, closed && !frame.cut_open, frame.view);
    draw_patches(out, map, patches, &order, frame.view, &to_page, &inside);
    if let Some(first) = first {
        outline(out, patches, &order, first, &to_page);
    }
    let raster = Raster::new(frame.area.0, frame.area.1);
    let owners = raster.owners(patches, &order, frame.view, &to_page, &inside);
    let seen = SeenPanels {
        raster: &raster,
        owners: &owners,
        to_page: &to_page,
        contain: frame.contain.then_some(frame.area),
    };
    name_panels(out, map, &seen, named, first)
}

/// The patches a view may see, far to near (depth, index); back faces of a closed
/// model are never seen.
fn far_to_near(patches: &[Patch], closed: bool, view: &View) -> Vec<(f64, usize)> {
    let mut order: Vec<(f64, usize)> = patches
        .iter()
        .enumerate()
        .filter(|(_, p)| !closed || p.normal.dot(view.toward) > 1e-9)
        .map(|(i, p)| {
            let depth =
                p.points.iter().map(|q| q.dot(view.toward)).sum::<f64>() / p.points.len() as f64;
            (depth, i)
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    order
}

/// Each patch in `order` as a path tinted by its panel's sheet, shaded by how much it
/// faces the viewer.
fn draw_patches(
    out: &mut String,
    map: &MapContext,
    patches: &[Patch],
    order: &[(f64, usize)],
    view: &View,
    to_page: &dyn Fn(DVec3) -> DVec2,
    inside: &dyn Fn(&Patch) -> bool,
) {
    for &(_, i) in order {
        let patch = &patches[i];
        let facing = patch.normal.dot(view.toward);
        let fill = if inside(patch) {
            INSIDE.to_string()
        } else {
            map.palette.colour(map.sheet_of[patch.panel], facing)
        };
        let mut d = String::new();
        for (j, &p) in patch.points.iter().enumerate() {
            let q = to_page(p);
            let _ = write!(
                d,
                "{}{} {}",
                if j == 0 { "M" } else { " L" },
                fmt_mm(q.x),
                fmt_mm(q.y)
            );
        }
        let _ = writeln!(
            out,
            "<path d=\"{d} Z\" fill=\"{fill}\" stroke=\"#606060\" stroke-width=\"0.05\"/>"
        );
    }
}

/// The drawn patches of `panel` outlined, so a close-up's own panel stands out.
fn outline(
    out: &mut String,
    patches: &[Patch],
    order: &[(f64, usize)],
    panel: usize,
    to_page: &dyn Fn(DVec3) -> DVec2,
) {
    for &(_, i) in order.iter().filter(|&&(_, i)| patches[i].panel == panel) {
        let d: Vec<String> = patches[i]
            .points
            .iter()
            .map(|&p| {
                let q = to_page(p);
                format!("{} {}", fmt_mm(q.x), fmt_mm(q.y))
            })
            .collect();
        let _ = writeln!(
            out,
            "<path d=\"M{} Z\" fill=\"none\" stroke=\"#202020\" stroke-width=\"0.4\" stroke-linejoin=\"round\"/>",
            d.join(" L")
        );
    }
}

/// Which panel a view shows where, and where a model point lands on the page.
struct SeenPanels<'a> {
    raster: &'a Raster,
    owners: &'a [Option<u32>],
    to_page: &'a dyn Fn(DVec3) -> DVec2,
    /// The box ids must lie in (top-left corner and size), if any.
    contain: Option<(DVec2, DVec2)>,
}

impl SeenPanels<'_> {
    /// Whether an id's box `lo..hi` may go here.
    fn contains(&self, lo: DVec2, hi: DVec2) -> bool {
        self.contain
            .is_none_or(|(corner, size)| lo.cmpge(corner).all() && hi.cmple(corner + size).all())
    }
}

/// Writes the id of every panel the view shows, where its own panel is seen and no
/// other id is: `first`, then panels not yet named in an earlier view, then the best
/// seen. Returns whether `first` was named.
fn name_panels(
    out: &mut String,
    map: &MapContext,
    seen: &SeenPanels,
    named: &mut [bool],
    first: Option<usize>,
) -> bool {
    let (panels, patches) = (map.input.panels, &map.input.surface.patches);
    let text = map.text;
    let mut cells = vec![0usize; panels.len()];
    for &o in seen.owners.iter().flatten() {
        cells[o as usize] += 1;
    }
    let mut candidates: Vec<usize> = (0..panels.len()).filter(|&p| cells[p] > 0).collect();
    let later = |p: usize| Some(p) != first;
    candidates.sort_by(|&a, &b| {
        (later(a), named[a], cells[b], a).cmp(&(later(b), named[b], cells[a], b))
    });
    let mut first_named = false;
    let mut placed = Placed::new(text * 4.0);
    for p in candidates {
        let id = panels.get(p).id().to_string();
        let half = 0.5 * DVec2::new(text_width(&id, text), text);
        // The anchor, or where it is crowded, a point nearer the middle of one of
        // the panel's patches: always on the panel itself as seen.
        let spot = spots(map.input.surface.anchors[p], &map.panel_patches[p], patches)
            .map(seen.to_page)
            .find(|&at| {
                seen.raster.owner_at(seen.owners, at) == Some(p as u32)
                    && seen.contains(at - half, at + half)
                    && placed.try_add(at - half, at + half, 0.25 * text)
            });
        let Some(at) = spot else {
            continue;
        };
        named[p] = true;
        first_named |= !later(p);
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" dy=\"0.35em\" stroke=\"#FFFFFF\" stroke-width=\"{}\" paint-order=\"stroke\">{id}</text>",
            fmt_mm(at.x),
            fmt_mm(at.y),
            fmt_mm(text),
            fmt_mm(0.25 * text)
        );
    }
    first_named
}

/// Where a panel's id may go, best first: its anchor, then points a third and two
/// thirds of the way from it to the centre of each of its patches, then those centres,
/// then points halfway from each centre to its patch's corners.
fn spots<'a>(
    anchor: DVec3,
    own: &'a [usize],
    patches: &'a [Patch],
) -> impl Iterator<Item = DVec3> + 'a {
    let centre = |i: usize| {
        let p = &patches[i].points;
        p.iter().copied().sum::<DVec3>() / p.len() as f64
    };
    let centres = own.iter().map(move |&i| centre(i));
    let near = centres.clone().map(move |c| anchor.lerp(c, 1.0 / 3.0));
    let far = centres.clone().map(move |c| anchor.lerp(c, 2.0 / 3.0));
    let toward_corners = own.iter().flat_map(move |&i| {
        let c = centre(i);
        patches[i].points.iter().map(move |&q| c.lerp(q, 0.5))
    });
    std::iter::once(anchor)
        .chain(near)
        .chain(far)
        .chain(centres)
        .chain(toward_corners)
}

/// The id text height: a fifth of a typical panel's size on the page, within
/// [`TEXT_MIN`]..[`TEXT_MAX`].
pub(super) fn text_height(input: &MapInput, scale: f64) -> f64 {
    let mut sizes: Vec<f64> = input
        .panels
        .iter()
        .map(|p| {
            let lo = p.vertices.iter().copied().fold(DVec3::INFINITY, DVec3::min);
            let hi = p
                .vertices
                .iter()
                .copied()
                .fold(DVec3::NEG_INFINITY, DVec3::max);
            (hi - lo).max_element()
        })
        .filter(|s| s.is_finite())
        .collect();
    if sizes.is_empty() {
        return TEXT_MAX;
    }
    sizes.sort_by(f64::total_cmp);
    (0.2 * sizes[sizes.len() / 2] * scale).clamp(TEXT_MIN, TEXT_MAX)
}

fn vec3(v: DVec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

/// Text boxes already written in a view, bucketed on a grid for the collision test.
struct Placed {
    cell: f64,
    buckets: std::collections::HashMap<(i64, i64), Vec<(DVec2, DVec2)>>,
}

impl Placed {
    fn new(cell: f64) -> Placed {
        Placed {
            cell,
            buckets: Default::default(),
        }
    }

    /// Adds the box `lo..hi` unless it comes within `gap` of one already added.
    fn try_add(&mut self, lo: DVec2, hi: DVec2, gap: f64) -> bool {
        let (glo, ghi) = (lo - DVec2::splat(gap), hi + DVec2::splat(gap));
        let key = |p: DVec2| {
            (
                (p.x / self.cell).floor() as i64,
                (p.y / self.cell).floor() as i64,
            )
        };
        let (k0, k1) = (key(glo), key(ghi));
        for i in k0.0 - 1..=k1.0 + 1 {
            for j in k0.1 - 1..=k1.1 + 1 {
                if let Some(boxes) = self.buckets.get(&(i, j)) {
                    if boxes
                        .iter()
                        .any(|(a, b)| glo.x < b.x && a.x < ghi.x && glo.y < b.y && a.y < ghi.y)
                    {
                        return false;
                    }
                }
            }
        }
        let (k0, k1) = (key(lo), key(hi));
        for i in k0.0..=k1.0 {
            for j in k0.1..=k1.1 {
                self.buckets.entry((i, j)).or_default().push((lo, hi));
            }
        }
        true
    }
}
