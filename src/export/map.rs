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

use super::map_page::{fit, text_width, wrap, Lines, Palette, LINE};
use super::{escape, fmt_mm};
use crate::nest::Layout;
use crate::panel::surface::{PanelSurface, Patch};
use crate::panel::{Covers, IdKind, Panels};

/// A direction the model is seen from.
pub(super) struct View {
    pub name: &'static str,
    /// The axis it is seen from and the way it turns off it, for the caption.
    pub axis: &'static str,
    pub turn: &'static str,
    /// From the model toward the viewer (unit).
    pub toward: DVec3,
    /// Up on the page (unit, square to `toward`).
    pub up: DVec3,
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
pub(super) fn views() -> [View; 6] {
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

/// Most raster cells of one view: a page metres across gets coarser cells rather than
/// buffers of gigabytes.
const RASTER_MAX_CELLS: f64 = 4.0e6;

/// Id text heights on paper (mm): large enough to read printed, small enough that
/// neighbouring panels' ids fit.
const TEXT_MIN: f64 = 1.8;
const TEXT_MAX: f64 = 3.0;

/// The fill of a closed model's inside where a close-up cuts it open.
const INSIDE: &str = "#D0D0D0";

/// The page's outer border (mm).
const BORDER: f64 = 8.0;

/// Text heights (mm) of the page furniture: the largest each is set at, and the
/// smallest it shrinks to before it wraps onto more lines.
const TITLE_TEXT: [f64; 2] = [6.0, 3.0];
pub(super) const CAPTION_TEXT: [f64; 2] = [4.5, 2.2];
const LEGEND_TEXT: [f64; 2] = [3.5, 2.5];

/// A legend row of sheet swatches (mm).
const SWATCH_ROW: f64 = 5.5;

/// Space (mm) below a block of text before what follows it.
pub(super) const GAP: f64 = 1.5;

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

/// The assembly map as SVG pages of the sheet's size: the overview (six views), then,
/// where the overview has no room for some ids, pages of close-ups until every panel
/// is named ([`super::map_closeup`]).
pub fn assembly_map(input: &MapInput) -> Vec<String> {
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
    let all = input.panels.len();
    // Parts inside the model (brackets) are not drawn: their ids name their edge.
    let is_inside: Vec<bool> = input
        .panels
        .iter()
        .map(|p| matches!(p.source.covers, Covers::Inside(_)))
        .collect();
    let inside = is_inside.iter().filter(|&&n| n).count();
    let page = Page::new(
        input,
        &title_text(input),
        &key_text(input.panels, [all, all, all, inside], all + 1),
        true,
    );
    let grid = Grid::largest(&page, &views, &extents);
    let map = MapContext {
        input,
        sheet_of,
        panel_patches,
        text: text_height(input, grid.scale),
        palette: Palette::new(input.layout.sheets),
        grid,
    };

    let mut out = String::new();
    page_head(&mut out, &page);
    let mut named = is_inside;
    for (k, view) in views.iter().enumerate() {
        draw_view(&mut out, &map, k, view, extents[k], &mut named);
    }
    let count = |named: &[bool]| named.iter().filter(|&&n| n).count();
    let on_overview = count(&named) - inside;
    let close_ups = close_up_pages(&map, &mut named);
    let closer = count(&named) - inside - on_overview;
    let unnamed = input.panels.len() - count(&named);
    let key = key_text(
        input.panels,
        [on_overview, closer, unnamed, inside],
        close_ups.len() + 1,
    );
    legend(&mut out, &map, &page, &key);
    out.push_str("</svg>\n");
    std::iter::once(out).chain(close_ups).collect()
}

/// The pages of close-ups of the panels the overview left unnamed, each page laid out
/// like the overview: title, cells of close-ups, the sheets' tints and a key.
fn close_up_pages(map: &MapContext, named: &mut [bool]) -> Vec<String> {
    if named.iter().all(|&n| n) {
        return Vec::new();
    }
    let input = map.input;
    let key = close_up_key(input.panels);
    // Laid out for the longest title a page can have.
    let most = input.panels.len() + 1;
    let page = Page::new(input, &close_up_title(input, most, most), &key, false);
    let cells = CloseUpCells::new(&page);
    if cells.cell.min_element() < CLOSE_UP_CELL_LEAST {
        // The paper has no room for a close-up (the legend takes it): the key says
        // how many panels are left unnamed.
        return Vec::new();
    }
    let drawn = super::map_closeup::close_ups(map, &cells, named);
    let count = drawn.len().div_ceil(cells.per_page());
    drawn
        .chunks(cells.per_page())
        .enumerate()
        .map(|(k, chunk)| {
            let page = page.retitled(&close_up_title(input, k + 2, count + 1));
            let mut out = String::new();
            page_head(&mut out, &page);
            for cell in chunk {
                out.push_str(cell);
            }
            legend(&mut out, map, &page, &key);
            out.push_str("</svg>\n");
            out
        })
        .collect()
}

/// Where a page of close-ups puts them: a grid of cells over the views' area, each at
/// least [`CLOSE_UP_CELL`] on a side where the paper allows.
pub(super) struct CloseUpCells {
    pub lo: DVec2,
    pub cols: usize,
    pub rows: usize,
    pub cell: DVec2,
}

/// The smallest side (mm) of a close-up's cell, paper allowing: room for a region of
/// a few panels around the one it shows.
const CLOSE_UP_CELL: f64 = 80.0;

/// The least side (mm) of a close-up's cell: below it, none is drawn.
const CLOSE_UP_CELL_LEAST: f64 = 30.0;

impl CloseUpCells {
    fn new(page: &Page) -> CloseUpCells {
        let (lo, area) = page.views_area();
        let count = |length: f64| ((length / CLOSE_UP_CELL).floor() as usize).clamp(1, 3);
        let (cols, rows) = (count(area.x), count(area.y));
        CloseUpCells {
            lo,
            cols,
            rows,
            cell: DVec2::new(area.x / cols as f64, area.y / rows as f64),
        }
    }

    pub fn per_page(&self) -> usize {
        self.cols * self.rows
    }

    /// The top-left corner of close-up `k`'s cell on its page.
    pub fn corner(&self, k: usize) -> DVec2 {
        let k = k % self.per_page();
        self.lo + DVec2::new((k % self.cols) as f64, (k / self.cols) as f64) * self.cell
    }
}

/// The page and its furniture, measured: the title at the top, the legend at the foot
/// (swatch rows and the id key), and the area between them for the views.
struct Page {
    width: f64,
    height: f64,
    title: Lines,
    /// Sheet swatches per legend row, and rows.
    swatches_per_row: usize,
    swatch_rows: usize,
    /// The id key's text size and the most lines it may take.
    key: Lines,
}

impl Page {
    /// The page for `input` with `title`, and room for `key` (or any shorter text)
    /// and, if `swatches`, a swatch per sheet.
    fn new(input: &MapInput, title: &str, key: &str, swatches: bool) -> Page {
        let (width, height) = page_size(input);
        let text_w = width - 2.0 * BORDER;
        let title = fit(title, text_w, TITLE_TEXT[0], TITLE_TEXT[1], 2);
        let sheets = input.layout.sheets.max(1);
        let entry = swatch_width(sheets);
        let room = text_w - text_width(SHEETS_WORD, LEGEND_TEXT[0]);
        let swatches_per_row = ((room / entry).floor() as usize).max(1);
        let key = fit(key, text_w, LEGEND_TEXT[0], LEGEND_TEXT[1], 3);
        Page {
            width,
            height,
            title,
            swatches_per_row,
            swatch_rows: if swatches {
                sheets.div_ceil(swatches_per_row)
            } else {
                0
            },
            key,
        }
    }

    /// This page with `title` (no longer than the one it was laid out for) at the
    /// size it was laid out for.
    fn retitled(&self, title: &str) -> Page {
        Page {
            title: Lines {
                size: self.title.size,
                lines: wrap(title, self.width - 2.0 * BORDER, self.title.size),
            },
            key: self.key.clone(),
            ..*self
        }
    }

    /// The height of the title's block (mm).
    fn title_height(&self) -> f64 {
        self.title.height() + GAP
    }

    /// The height of the legend's block (mm).
    fn legend_height(&self) -> f64 {
        self.swatch_rows as f64 * SWATCH_ROW + GAP + self.key.height()
    }

    /// Where the views go: the top-left corner and size (mm).
    fn views_area(&self) -> (DVec2, DVec2) {
        let lo = DVec2::new(BORDER, BORDER + self.title_height());
        let size = DVec2::new(
            self.width - 2.0 * BORDER,
            self.height - 2.0 * BORDER - self.title_height() - self.legend_height(),
        );
        (lo, size.max(DVec2::splat(1.0)))
    }
}

/// The legend's word before the sheet swatches.
const SHEETS_WORD: &str = "Sheets: ";

/// The width (mm) of one sheet's swatch and number in the legend, for `sheets` sheets.
fn swatch_width(sheets: usize) -> f64 {
    4.0 + 1.0 + text_width(&sheets.to_string(), LEGEND_TEXT[0]) + 3.0
}

/// The map's title.
fn title_text(input: &MapInput) -> String {
    format!(
        "{}: assembly map, {} on {} (tint: sheet; text: panel id)",
        input.name,
        crate::units::count_of(input.panels.len(), "panel"),
        crate::units::count_of(input.layout.sheets, "sheet")
    )
}

/// A view's caption.
fn caption_text(view: &View) -> String {
    format!(
        "{} (from {}, turned {:.0}° toward {})",
        view.name,
        view.axis,
        TILT.atan().to_degrees(),
        view.turn
    )
}

/// What every view of a map is drawn with.
pub(super) struct MapContext<'a> {
    pub input: &'a MapInput<'a>,
    /// Each panel's sheet (its tint).
    sheet_of: Vec<usize>,
    /// Each panel's patches, as indices into the surface's.
    pub panel_patches: Vec<Vec<usize>>,
    pub grid: Grid,
    /// The ids' text height (mm).
    pub text: f64,
    /// The sheets' tints.
    palette: Palette,
}

/// The page's grid of views and the one scale they share.
pub(super) struct Grid {
    cols: usize,
    /// Page mm per model mm.
    pub scale: f64,
    /// The top-left corner of the views' area.
    lo: DVec2,
    cell_w: f64,
    cell_h: f64,
    /// Each view's caption, fitted to the cell's width, and the caption strip's height.
    captions: Vec<Lines>,
    caption_h: f64,
}

impl Grid {
    /// The grid of views (columns x rows) that draws the model largest, one scale for
    /// all views so they compare, each view's caption fitted to its cell.
    fn largest(page: &Page, views: &[View], extents: &[(DVec2, DVec2)]) -> Grid {
        let (lo, area) = page.views_area();
        [(2usize, 3usize), (3, 2), (1, 6), (6, 1)]
            .into_iter()
            .map(|(cols, rows)| {
                let (cell_w, cell_h) = (area.x / cols as f64, area.y / rows as f64);
                let captions: Vec<Lines> = views
                    .iter()
                    .map(|v| {
                        let [largest, smallest] = CAPTION_TEXT;
                        fit(&caption_text(v), cell_w - 4.0, largest, smallest, 2)
                    })
                    .collect();
                let caption_h = captions.iter().map(Lines::height).fold(0.0, f64::max) + GAP;
                let draw_h = (cell_h - caption_h - GAP).max(1e-3);
                let scale = extents
                    .iter()
                    .map(|(lo, hi)| {
                        let size = (*hi - *lo).max(DVec2::splat(1e-9));
                        (0.92 * cell_w / size.x).min(0.92 * draw_h / size.y)
                    })
                    .fold(f64::INFINITY, f64::min);
                Grid {
                    cols,
                    scale: if scale.is_finite() && scale > 0.0 {
                        scale
                    } else {
                        1.0
                    },
                    lo,
                    cell_w,
                    cell_h,
                    captions,
                    caption_h,
                }
            })
            .fold(None, |best: Option<Grid>, grid| match best {
                Some(b) if b.scale >= grid.scale => Some(b),
                _ => Some(grid),
            })
            .expect("four grids are tried")
    }
}

/// The page: the sheet's width and height (mm).
fn page_size(input: &MapInput) -> (f64, f64) {
    (input.layout.sheet.width, input.layout.sheet.height)
}

/// The SVG header, the white page and the title.
fn page_head(out: &mut String, page: &Page) {
    let (page_w, page_h) = (page.width, page.height);
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
    text_lines(out, &page.title, DVec2::new(BORDER, BORDER));
}

/// Writes `lines` left-aligned, the first line's top at `top_left`.
pub(super) fn text_lines(out: &mut String, lines: &Lines, top_left: DVec2) {
    for (i, line) in lines.lines.iter().enumerate() {
        // A line's baseline sits a cap height and a little below its top.
        let baseline = top_left.y + (i as f64 * LINE + 1.0) * lines.size;
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\">{}</text>",
            fmt_mm(top_left.x),
            fmt_mm(baseline),
            fmt_mm(lines.size),
            escape(line)
        );
    }
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

/// A model point in a view's (right, up) coordinates (mm).
pub(super) fn project(p: DVec3, view: &View) -> DVec2 {
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

/// The sheets' tints (rows of numbered swatches) and the id key, along the page's
/// foot.
fn legend(out: &mut String, map: &MapContext, page: &Page, key: &str) {
    let input = map.input;
    let top = page.height - BORDER - page.legend_height();
    let _ = writeln!(out, "<g id=\"legend\">");
    let size = LEGEND_TEXT[0];
    if page.swatch_rows > 0 {
        let _ = writeln!(
            out,
            "<text x=\"{}\" y=\"{}\" font-size=\"{}\">{}</text>",
            fmt_mm(BORDER),
            fmt_mm(top + 3.5),
            fmt_mm(size),
            SHEETS_WORD.trim_end()
        );
    }
    let entry = swatch_width(input.layout.sheets.max(1));
    let first_x = BORDER + text_width(SHEETS_WORD, size);
    let swatches = if page.swatch_rows > 0 {
        input.layout.sheets
    } else {
        0
    };
    for sheet in 0..swatches {
        let (row, col) = (sheet / page.swatches_per_row, sheet % page.swatches_per_row);
        let (x, y) = (first_x + col as f64 * entry, top + row as f64 * SWATCH_ROW);
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"4\" height=\"4\" fill=\"{}\" stroke=\"#606060\" stroke-width=\"0.1\"/><text x=\"{}\" y=\"{}\" font-size=\"{}\">{}</text>",
            fmt_mm(x),
            fmt_mm(y),
            map.palette.colour(sheet, 1.0),
            fmt_mm(x + 5.0),
            fmt_mm(y + 3.5),
            fmt_mm(size),
            sheet + 1
        );
    }
    // The key at the size the page was laid out for (the text is never longer).
    let key = Lines {
        size: page.key.size,
        lines: wrap(key, page.width - 2.0 * BORDER, page.key.size),
    };
    let key_top = top + page.swatch_rows as f64 * SWATCH_ROW + GAP;
    text_lines(out, &key, DVec2::new(BORDER, key_top));
    out.push_str("</g>\n");
}

/// The overview's key: what the ids mean and how many panels are named here, in the
/// close-ups on the map's later pages (`pages` in all), and not at all.
fn key_text(panels: &Panels, [named, closer, unnamed, inside]: [usize; 4], pages: usize) -> String {
    let ids = id_legend(panels);
    let total = panels.len() - inside.min(panels.len());
    let later = match pages {
        0 | 1 => String::new(),
        2 => format!(", {closer} more in the close-ups on page 2"),
        _ => format!(", {closer} more in the close-ups on pages 2 to {pages}"),
    };
    let within = match inside {
        0 => String::new(),
        n => format!(
            " {n} parts inside the model are not drawn: each stands at the edge its id names."
        ),
    };
    let named = match unnamed {
        0 if pages <= 1 => format!(
            "Ids: {ids}. {named} of {total} panels named; one crowded out of a view is named in another."
        ),
        0 => format!("Ids: {ids}. {named} of {total} panels named here{later}."),
        _ => format!(
            "Ids: {ids}. {named} of {total} panels named here{later}; {unnamed} not named: this paper has no room for their close-ups (a larger --sheet has)."
        ),
    };
    named + &within
}

/// The key of a page of close-ups.
fn close_up_key(panels: &Panels) -> String {
    format!(
        "Ids: {}. Each close-up shows the region around one panel (outlined) larger, seen from the side its caption names, with the ids page 1 cannot show and, where there is room, their neighbours' ids; where the region is hidden, the model in front of it is cut away. Tints as on page 1.",
        id_legend(panels)
    )
}

/// The title of page `page` of `pages`, a page of close-ups.
fn close_up_title(input: &MapInput, page: usize, pages: usize) -> String {
    format!(
        "{}: assembly map, page {page} of {pages}: close-ups of the panels page 1 cannot name",
        input.name
    )
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

/// A view's owner buffer: which panel is seen at each raster cell of its page cell.
struct Raster {
    lo: DVec2,
    /// Cells per millimetre of paper.
    per_mm: f64,
    width: usize,
    height: usize,
}

impl Raster {
    fn new(lo: DVec2, size: DVec2) -> Raster {
        let area = (size.x * size.y).max(1e-9);
        let per_mm = RASTER_PER_MM.min((RASTER_MAX_CELLS / area).sqrt());
        Raster {
            lo,
            per_mm,
            width: (size.x * per_mm).ceil().max(1.0) as usize,
            height: (size.y * per_mm).ceil().max(1.0) as usize,
        }
    }

    /// Rasterizes the patches far to near (`order`), each cell keeping the nearest.
    fn owners(
        &self,
        patches: &[Patch],
        order: &[(f64, usize)],
        view: &View,
        to_page: &dyn Fn(DVec3) -> DVec2,
        inside: &dyn Fn(&Patch) -> bool,
    ) -> Vec<Option<u32>> {
        let mut owner = vec![None; self.width * self.height];
        let mut depth = vec![f64::NEG_INFINITY; self.width * self.height];
        for &(_, i) in order {
            let patch = &patches[i];
            let id = (!inside(patch)).then_some(patch.panel as u32);
            let pts: Vec<(DVec2, f64)> = patch
                .points
                .iter()
                .map(|&p| ((to_page(p) - self.lo) * self.per_mm, p.dot(view.toward)))
                .collect();
            for k in 1..pts.len().saturating_sub(1) {
                self.triangle([pts[0], pts[k], pts[k + 1]], id, &mut owner, &mut depth);
            }
        }
        owner
    }

    fn triangle(
        &self,
        t: [(DVec2, f64); 3],
        id: Option<u32>,
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
            // Only the cells whose centres the row's span may hold are tested: a thin
            // triangle's box is mostly outside it.
            let Some((from, to)) = row_span(t.map(|c| c.0), area, y as f64 + 0.5) else {
                continue;
            };
            let from = (from.floor() - 1.0).max(lo.x) as usize;
            let to = ((to.ceil() + 2.0).max(0.0) as usize).min(x1);
            for x in from..to {
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
                    owner[cell] = id;
                }
            }
        }
    }

    /// The panel seen at a page point and all round it (the raster cell there and its
    /// eight neighbours), so an id's centre is never at the edge of what is seen.
    fn owner_at(&self, owners: &[Option<u32>], at: DVec2) -> Option<u32> {
        let q = (at - self.lo) * self.per_mm;
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

/// The cells of the row whose centres lie at height `y` that triangle `t` (of signed
/// area `area`, doubled) may cover, as a range of cell indices found with an allowance
/// looser than the cells' own test (the caller pads it by a cell as well); `None`
/// where it covers none. Each barycentric weight is linear along the row, so each
/// side bounds the range from one end.
fn row_span(t: [DVec2; 3], area: f64, y: f64) -> Option<(f64, f64)> {
    let [a, b, c] = t;
    let weight = |p: DVec2, q: DVec2, x: f64| {
        let at = DVec2::new(x, y);
        (p - at).perp_dot(q - at) / area
    };
    let (mut from, mut to) = (f64::NEG_INFINITY, f64::INFINITY);
    for (p, q) in [(b, c), (c, a), (a, b)] {
        // The weight at the centres of cells 0 and 1, and the x (a cell index) where it
        // falls to the test's allowance.
        let w0 = weight(p, q, 0.5);
        let slope = weight(p, q, 1.5) - w0;
        if slope == 0.0 {
            if w0 < -1e-6 {
                return None;
            }
            continue;
        }
        let edge = (-1e-6 - w0) / slope;
        if slope > 0.0 {
            from = from.max(edge);
        } else {
            to = to.min(edge);
        }
    }
    (from <= to + 1.0).then_some((from, to))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell whose centre a triangle holds, tested one by one over its box.
    fn cells_by_box(raster: &Raster, t: [DVec2; 3]) -> Vec<usize> {
        let [a, b, c] = t;
        let area = (b - a).perp_dot(c - a);
        let mut cells = Vec::new();
        for y in 0..raster.height {
            for x in 0..raster.width {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let wa = (b - p).perp_dot(c - p) / area;
                let wb = (c - p).perp_dot(a - p) / area;
                if wa >= -1e-9 && wb >= -1e-9 && 1.0 - wa - wb >= -1e-9 {
                    cells.push(y * raster.width + x);
                }
            }
        }
        cells
    }

    #[test]
    fn a_triangle_covers_the_cells_its_box_test_finds_thin_or_not() {
        let raster = Raster::new(DVec2::ZERO, DVec2::new(30.0, 20.0));
        let size = DVec2::new(raster.width as f64, raster.height as f64);
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut point = || DVec2::new(rng.unit(), rng.unit()) * size * 1.2 - 0.1 * size;
        let mut covered = 0;
        for k in 0..400 {
            let (a, b) = (point(), point());
            // Every other triangle a sliver: its third corner a hair off the side ab.
            let c = match k % 2 {
                0 => point(),
                _ => a.lerp(b, 0.37) + (b - a).perp().normalize() * 0.3,
            };
            let t = [a, b, c];
            let mut owner = vec![None; raster.width * raster.height];
            let mut depth = vec![f64::NEG_INFINITY; owner.len()];
            raster.triangle(t.map(|p| (p, 0.0)), Some(1), &mut owner, &mut depth);
            let cells: Vec<usize> = (0..owner.len()).filter(|&i| owner[i].is_some()).collect();
            let expected = match (b - a).perp_dot(c - a).abs() < 1e-12 {
                true => Vec::new(),
                false => cells_by_box(&raster, t),
            };
            assert_eq!(cells, expected, "triangle {k}: {t:?}");
            covered += cells.len();
        }
        assert!(covered > 10_000, "{covered} cells covered in all");
    }
}
