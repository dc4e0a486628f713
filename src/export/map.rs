//! The assembly map (`NAME-map.svg`): the model seen from six sides, orthographic,
//! every visible panel tinted by its sheet and named where it sits, so a builder with
//! hundreds of cut panels finds where each one goes. It is a picture for people, not
//! a laser file: fills and text are fine here.
//!
//! Each panel covers a part of the surface ([`PanelSurface`]). Those patches are drawn far to near (the painter's order) and rasterized
//! into an owner buffer per view; a panel's id is written at its anchor (the face
//! centre, the edge's midpoint, the middle of the ribbon) only where the buffer says
//! the panel itself is seen there, so no id sits over a hidden face. Ids go in a view
//! in the order of how much of the panel it shows, and one that would collide with an
//! id already written waits for another view.

use std::fmt::Write;

use glam::{DVec2, DVec3};

use super::fmt_mm;
use crate::nest::Layout;
use crate::panel::surface::{PanelSurface, Patch};
use crate::panel::{IdKind, Panels};

/// A direction the model is seen from.
struct View {
    name: &'static str,
    /// The axis it is seen from and the way it turns off it, for the caption.
    axis: &'static str,
    turn: &'static str,
    /// From the model toward the viewer (unit).
    toward: DVec3,
    /// Up on the page (unit, square to `toward`).
    up: DVec3,
}

impl View {
    /// A view from `axis` turned a little toward `side`, up on the page as near
    /// `up` as the turn allows.
    fn new(name: &'static str, axis: [&'static str; 2], side: DVec3, up: DVec3) -> View {
        let main = axis_vector(axis[0]);
        let toward = (main + TILT * side.normalize()).normalize();
        let up = (up - up.dot(toward) * toward).normalize();
        View {
            name,
            axis: axis[0],
            turn: axis[1],
            toward,
            up,
        }
    }

    /// Right on the page: the viewing direction crossed with up.
    fn right(&self) -> DVec3 {
        (-self.toward).cross(self.up)
    }
}

/// How far each view turns off its axis (the tangent of 20°): a little from the side
/// and above or below, so walls square to the axis (the inside of a hole through the
/// model, the sides of a box) are seen too. Opposite views turn opposite ways, so
/// between them every side of such a wall shows.
const TILT: f64 = 0.364;

/// The unit vector of an axis named `+X`, `-Y`…
fn axis_vector(axis: &str) -> DVec3 {
    match axis {
        "+X" => DVec3::X,
        "-X" => DVec3::NEG_X,
        "+Y" => DVec3::Y,
        "-Y" => DVec3::NEG_Y,
        "+Z" => DVec3::Z,
        _ => DVec3::NEG_Z,
    }
}

/// The six views, in the order they are laid out (the model's +Y is up, +Z toward
/// the front).
fn views() -> [View; 6] {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    [
        View::new("front", ["+Z", "+X and +Y"], x + y, y),
        View::new("back", ["-Z", "-X and -Y"], -x - y, y),
        View::new("left", ["-X", "+Z and +Y"], z + y, y),
        View::new("right", ["+X", "-Z and -Y"], -z - y, y),
        View::new("top", ["+Y", "+X and +Z"], x + z, -z),
        View::new("bottom", ["-Y", "-X and -Z"], -x - z, z),
    ]
}

/// Raster cells per millimetre of paper for the owner buffers.
const RASTER_PER_MM: f64 = 4.0;

/// Id text heights on paper (mm): large enough to read printed, small enough that
/// neighbouring panels' ids fit.
const TEXT_MIN: f64 = 1.8;
const TEXT_MAX: f64 = 3.0;

/// Width of an id's text per character, in text heights (sans-serif digits and
/// capitals), for the collision test.
const CHAR_WIDTH: f64 = 0.62;

/// Page furniture (mm): the outer border, the title's line, the legend's line, and
/// the strip at the top of each view's cell for its caption (the drawing keeps as much
/// free below it).
const BORDER: f64 = 8.0;
const TITLE: f64 = 10.0;
const LEGEND: f64 = 16.0;
const CAPTION: f64 = 3.0;

/// What the map is drawn from.
pub struct MapInput<'a> {
    /// Where each panel sits on the model.
    pub surface: &'a PanelSurface,
    /// The scheme's 3D panels.
    pub panels: &'a Panels,
    /// Where each panel was laid out (its sheet gives its tint).
    pub layout: &'a Layout,
    /// The model's name, for the title.
    pub name: &'a str,
}

/// The assembly map as an SVG document, on a page of the sheet's size.
pub fn assembly_map(input: &MapInput) -> String {
    let patches = &input.surface.patches;
    let mut sheet_of = vec![0; input.panels.len()];
    for p in &input.layout.placements {
        sheet_of[p.part] = p.sheet;
    }
    let mut panel_patches = vec![Vec::new(); input.panels.len()];
    for (i, patch) in patches.iter().enumerate() {
        panel_patches[patch.panel].push(i);
    }
    let views = views();
    // Extents of each view in model mm.
    let extents: Vec<(DVec2, DVec2)> = views
        .iter()
        .map(|v| bounds(patches.iter().flat_map(|p| &p.points), v))
        .collect();
    let grid = Grid::largest(input, &extents);
    let map = MapContext {
        input,
        sheet_of,
        panel_patches,
        text: text_height(input, grid.scale),
        grid,
    };

    let mut out = String::new();
    page_head(&mut out, input);
    let mut named = vec![false; input.panels.len()];
    for (k, view) in views.iter().enumerate() {
        draw_view(&mut out, &map, k, view, extents[k], &mut named);
    }
    let (_, page_h) = page_size(input);
    legend(
        &mut out,
        input,
        page_h,
        named.iter().filter(|&&n| n).count(),
    );
    out.push_str("</svg>\n");
    out
}

/// What every view of a map is drawn with.
struct MapContext<'a> {
    input: &'a MapInput<'a>,
    /// Each panel's sheet (its tint).
    sheet_of: Vec<usize>,
    /// Each panel's patches, as indices into the surface's.
    panel_patches: Vec<Vec<usize>>,
    grid: Grid,
    /// The ids' text height (mm).
    text: f64,
}

/// The page's grid of views and the one scale they share.
struct Grid {
    cols: usize,
    /// Page mm per model mm.
    scale: f64,
    cell_w: f64,
    cell_h: f64,
}

impl Grid {
    /// The grid of views (columns x rows) that draws the model largest, one scale for
    /// all views so they compare.
    fn largest(input: &MapInput, extents: &[(DVec2, DVec2)]) -> Grid {
        let (page_w, page_h) = page_size(input);
        let area_w = page_w - 2.0 * BORDER;
        let area_h = page_h - 2.0 * BORDER - TITLE - LEGEND;
        let (cols, rows, scale) = [(2usize, 3usize), (3, 2), (1, 6), (6, 1)]
            .into_iter()
            .map(|(c, r)| {
                let (cw, ch) = (area_w / c as f64, area_h / r as f64 - 2.0 * CAPTION);
                let s = extents
                    .iter()
                    .map(|(lo, hi)| {
                        let size = (*hi - *lo).max(DVec2::splat(1e-9));
                        (0.92 * cw / size.x).min(0.92 * ch / size.y)
                    })
                    .fold(f64::INFINITY, f64::min);
                (c, r, s)
            })
            .max_by(|a, b| a.2.total_cmp(&b.2))
            .unwrap_or((2, 3, 1.0));
        Grid {
            cols,
            scale: if scale.is_finite() && scale > 0.0 {
                scale
            } else {
                1.0
            },
            cell_w: area_w / cols as f64,
            cell_h: area_h / rows as f64,
        }
    }
}

/// The page: the sheet's width and height (mm).
fn page_size(input: &MapInput) -> (f64, f64) {
    (input.layout.sheet.width, input.layout.sheet.height)
}

/// The SVG header, the white page and the title.
fn page_head(out: &mut String, input: &MapInput) {
    let (page_w, page_h) = page_size(input);
    let _ = writeln!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{w}mm\" height=\"{h}mm\" viewBox=\"0 0 {w} {h}\" font-family=\"Helvetica, Arial, sans-serif\">",
        w = fmt_mm(page_w),
        h = fmt_mm(page_h)
    );
    let _ = writeln!(
        out,
        "<rect width=\"{}\" height=\"{}\" fill=\"#FFFFFF\"/>",
        fmt_mm(page_w),
        fmt_mm(page_h)
    );
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"6\">{}: assembly map, {} panels on {} sheets (tint: sheet; text: panel id)</text>",
        fmt_mm(BORDER),
        fmt_mm(BORDER + 6.0),
        escape(input.name),
        input.panels.len(),
        input.layout.sheets
    );
}

/// View `k` in its cell: its group (with the projection, for readers that map page
/// points back to the model), caption, patches far to near and the panel ids where
/// their panels are seen; `named` marks the panels named so far.
fn draw_view(
    out: &mut String,
    map: &MapContext,
    k: usize,
    view: &View,
    (lo, hi): (DVec2, DVec2),
    named: &mut [bool],
) {
    let grid = &map.grid;
    let (col, row) = (k % grid.cols, k / grid.cols);
    let cell_lo = DVec2::new(
        BORDER + col as f64 * grid.cell_w,
        BORDER + TITLE + row as f64 * grid.cell_h,
    );
    let centre = 0.5 * (lo + hi);
    // Page point of a model point: the view's (right, up) scaled, y down.
    let scale = grid.scale;
    let origin = cell_lo + DVec2::new(0.5 * grid.cell_w, 0.5 * (grid.cell_h + CAPTION))
        - scale * DVec2::new(centre.x, -centre.y);
    let to_page = |p: DVec3| {
        let q = project(p, view);
        origin + scale * DVec2::new(q.x, -q.y)
    };
    let _ = writeln!(
        out,
        "<g id=\"view-{name}\" data-view=\"{name}\" data-toward=\"{}\" data-up=\"{}\" data-scale=\"{}\" data-origin=\"{} {}\">",
        vec3(view.toward),
        vec3(view.up),
        scale,
        origin.x,
        origin.y,
        name = view.name
    );
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"4.5\">{} (from {}, turned {:.0}° toward {})</text>",
        fmt_mm(cell_lo.x + 2.0),
        fmt_mm(cell_lo.y + 5.0),
        view.name,
        view.axis,
        TILT.atan().to_degrees(),
        view.turn
    );
    let order = far_to_near(map.input.surface, view);
    draw_patches(out, map, &order, view, &to_page);
    let raster = Raster::new(cell_lo, DVec2::new(grid.cell_w, grid.cell_h));
    let owners = raster.owners(&map.input.surface.patches, &order, view, &to_page);
    let seen = SeenPanels {
        raster: &raster,
        owners: &owners,
        to_page: &to_page,
    };
    name_panels(out, map, &seen, named);
    out.push_str("</g>\n");
}

/// The patches a view may see, far to near (depth, index); back faces of a closed
/// model are never seen.
fn far_to_near(surface: &PanelSurface, view: &View) -> Vec<(f64, usize)> {
    let mut order: Vec<(f64, usize)> = surface
        .patches
        .iter()
        .enumerate()
        .filter(|(_, p)| !surface.closed || p.normal.dot(view.toward) > 1e-9)
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
    order: &[(f64, usize)],
    view: &View,
    to_page: &dyn Fn(DVec3) -> DVec2,
) {
    for &(_, i) in order {
        let patch = &map.input.surface.patches[i];
        let facing = patch.normal.dot(view.toward);
        let fill = sheet_colour(map.sheet_of[patch.panel], facing);
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

/// Which panel a view shows where, and where a model point lands on the page.
struct SeenPanels<'a> {
    raster: &'a Raster,
    owners: &'a [Option<u32>],
    to_page: &'a dyn Fn(DVec3) -> DVec2,
}

/// Writes the id of every panel the view shows, where its own panel is seen and no
/// other id is: panels not yet named in an earlier view first, then the best seen.
fn name_panels(out: &mut String, map: &MapContext, seen: &SeenPanels, named: &mut [bool]) {
    let (panels, patches) = (map.input.panels, &map.input.surface.patches);
    let text = map.text;
    let mut cells = vec![0usize; panels.len()];
    for &o in seen.owners.iter().flatten() {
        cells[o as usize] += 1;
    }
    let mut candidates: Vec<usize> = (0..panels.len()).filter(|&p| cells[p] > 0).collect();
    candidates.sort_by(|&a, &b| (named[a], cells[b], a).cmp(&(named[b], cells[a], b)));
    let mut placed = Placed::new(text * 4.0);
    for p in candidates {
        let id = panels.get(p).id().to_string();
        let half = 0.5 * DVec2::new(CHAR_WIDTH * text * id.len() as f64, text);
        // The anchor, or where it is crowded, a point nearer the middle of one of
        // the panel's patches: always on the panel itself as seen.
        let spot = spots(map.input.surface.anchors[p], &map.panel_patches[p], patches)
            .map(seen.to_page)
            .find(|&at| {
                seen.raster.owner_at(seen.owners, at) == Some(p as u32)
                    && placed.try_add(at - half, at + half, 0.25 * text)
            });
        let Some(at) = spot else {
            continue;
        };
        named[p] = true;
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" dy=\"0.35em\" stroke=\"#FFFFFF\" stroke-width=\"{}\" paint-order=\"stroke\">{id}</text>",
            fmt_mm(at.x),
            fmt_mm(at.y),
            fmt_mm(text),
            fmt_mm(0.25 * text)
        );
    }
}

/// Where a panel's id may go, best first: its anchor, then points a third and two
/// thirds of the way from it to the centre of each of its patches.
fn spots<'a>(
    anchor: DVec3,
    own: &'a [usize],
    patches: &'a [Patch],
) -> impl Iterator<Item = DVec3> + 'a {
    let centres = own.iter().map(|&i| {
        let p = &patches[i].points;
        p.iter().copied().sum::<DVec3>() / p.len() as f64
    });
    let near = centres.clone().map(move |c| anchor.lerp(c, 1.0 / 3.0));
    let far = centres.map(move |c| anchor.lerp(c, 2.0 / 3.0));
    std::iter::once(anchor).chain(near).chain(far)
}

/// A model point in a view's (right, up) coordinates (mm).
fn project(p: DVec3, view: &View) -> DVec2 {
    DVec2::new(p.dot(view.right()), p.dot(view.up))
}

fn bounds<'a>(points: impl Iterator<Item = &'a DVec3>, view: &View) -> (DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for &p in points {
        let q = project(p, view);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if lo.x > hi.x {
        (DVec2::ZERO, DVec2::ZERO)
    } else {
        (lo, hi)
    }
}

/// The id text height: a fifth of a typical panel's size on the page, within
/// [`TEXT_MIN`]..[`TEXT_MAX`].
fn text_height(input: &MapInput, scale: f64) -> f64 {
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

/// The tint of a sheet: hues spread by the golden angle (neighbouring sheet numbers
/// look different), light enough for black text, shaded by how squarely the patch
/// faces the viewer.
fn sheet_colour(sheet: usize, facing: f64) -> String {
    let hue = (sheet as f64 * 137.508) % 360.0;
    let light = 0.62 + 0.2 * facing.abs().clamp(0.0, 1.0);
    let rgb = hsl(hue, 0.55, light);
    format!("#{:02X}{:02X}{:02X}", rgb[0], rgb[1], rgb[2])
}

fn hsl(hue: f64, s: f64, l: f64) -> [u8; 3] {
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    let h = hue / 60.0;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - 0.5 * c;
    [r, g, b].map(|v| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8)
}

/// The sheets' tints and the id letters, along the page's foot.
fn legend(out: &mut String, input: &MapInput, page_h: f64, named: usize) {
    let y = page_h - BORDER - LEGEND;
    let mut x = BORDER;
    let _ = writeln!(out, "<g id=\"legend\">");
    for sheet in 0..input.layout.sheets {
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"4\" height=\"4\" fill=\"{}\" stroke=\"#606060\" stroke-width=\"0.1\"/><text x=\"{}\" y=\"{}\" font-size=\"3.5\">sheet {}</text>",
            fmt_mm(x),
            fmt_mm(y),
            sheet_colour(sheet, 1.0),
            fmt_mm(x + 5.0),
            fmt_mm(y + 3.5),
            sheet + 1
        );
        x += 24.0;
        if x > input.layout.sheet.width - BORDER - 24.0 {
            break;
        }
    }
    let _ = writeln!(
        out,
        "<text x=\"{}\" y=\"{}\" font-size=\"3.5\">Ids: {}. {named} of {} panels named; one crowded out of a view is named in another.</text>",
        fmt_mm(BORDER),
        fmt_mm(y + 11.0),
        escape(&id_legend(input.panels)),
        input.panels.len()
    );
    out.push_str("</g>\n");
}

/// What each kind of id on the panels means, in the schemes' own words: the panels'
/// kinds first, then those only labels use, each in the order first met.
fn id_legend(panels: &Panels) -> String {
    let mut kinds: Vec<&'static IdKind> = Vec::new();
    let mut meet = |kind: &'static IdKind| {
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    };
    for panel in panels.iter() {
        meet(panel.id().kind);
    }
    for panel in panels.iter() {
        for label in panel.labels {
            meet(label.text.kind);
        }
    }
    let words: Vec<String> = kinds
        .iter()
        .map(|k| match k.letter {
            "" => k.legend.to_string(),
            letter => format!("{letter} {}", k.legend),
        })
        .collect();
    words.join(", ")
}

fn vec3(v: DVec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A view's owner buffer: which panel is seen at each raster cell of its page cell.
struct Raster {
    lo: DVec2,
    width: usize,
    height: usize,
}

impl Raster {
    fn new(lo: DVec2, size: DVec2) -> Raster {
        Raster {
            lo,
            width: (size.x * RASTER_PER_MM).ceil().max(1.0) as usize,
            height: (size.y * RASTER_PER_MM).ceil().max(1.0) as usize,
        }
    }

    /// Rasterizes the patches far to near (`order`), each cell keeping the nearest.
    fn owners(
        &self,
        patches: &[Patch],
        order: &[(f64, usize)],
        view: &View,
        to_page: &dyn Fn(DVec3) -> DVec2,
    ) -> Vec<Option<u32>> {
        let mut owner = vec![None; self.width * self.height];
        let mut depth = vec![f64::NEG_INFINITY; self.width * self.height];
        for &(_, i) in order {
            let patch = &patches[i];
            let pts: Vec<(DVec2, f64)> = patch
                .points
                .iter()
                .map(|&p| ((to_page(p) - self.lo) * RASTER_PER_MM, p.dot(view.toward)))
                .collect();
            for k in 1..pts.len().saturating_sub(1) {
                self.triangle(
                    [pts[0], pts[k], pts[k + 1]],
                    patch.panel as u32,
                    &mut owner,
                    &mut depth,
                );
            }
        }
        owner
    }

    fn triangle(
        &self,
        t: [(DVec2, f64); 3],
        id: u32,
        owner: &mut [Option<u32>],
        depth: &mut [f64],
    ) {
        let [(a, za), (b, zb), (c, zc)] = t;
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = a.min(b).min(c).floor().max(DVec2::ZERO);
        let hi = a.max(b).max(c).ceil();
        let x1 = (hi.x as usize).min(self.width);
        let y1 = (hi.y as usize).min(self.height);
        for y in lo.y as usize..y1 {
            for x in lo.x as usize..x1 {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let wa = (b - p).perp_dot(c - p) / area;
                let wb = (c - p).perp_dot(a - p) / area;
                let wc = 1.0 - wa - wb;
                if wa < -1e-9 || wb < -1e-9 || wc < -1e-9 {
                    continue;
                }
                let z = wa * za + wb * zb + wc * zc;
                let cell = y * self.width + x;
                if z >= depth[cell] {
                    depth[cell] = z;
                    owner[cell] = Some(id);
                }
            }
        }
    }

    /// The panel seen at a page point and all round it (the raster cell there and its
    /// eight neighbours), so an id's centre is never at the edge of what is seen.
    fn owner_at(&self, owners: &[Option<u32>], at: DVec2) -> Option<u32> {
        let q = (at - self.lo) * RASTER_PER_MM;
        if q.x < 1.0 || q.y < 1.0 {
            return None;
        }
        let (x, y) = (q.x as usize, q.y as usize);
        if x + 1 >= self.width || y + 1 >= self.height {
            return None;
        }
        let owner = owners[y * self.width + x];
        let around =
            (y - 1..=y + 1).all(|j| (x - 1..=x + 1).all(|i| owners[j * self.width + i] == owner));
        owner.filter(|_| around)
    }
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
