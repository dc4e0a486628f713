//! The map's page laid out: what the map is drawn from, the page and its furniture
//! measured (title, legend, the views' area), the grid of the six views, the cells of
//! a page of close-ups, and the context every view is drawn with.

use std::fmt::Write;

use glam::DVec2;

use super::page::{fit, text_width, wrap, Lines, Palette, LINE};
use super::view::{caption_text, View};
use crate::export::{escape, fmt_mm};
use crate::nest::Layout;
use crate::panel::surface::PanelSurface;
use crate::panel::Panels;

/// The page's outer border (mm).
pub(super) const BORDER: f64 = 8.0;

/// Text heights (mm) of the page furniture: the largest each is set at, and the
/// smallest it shrinks to before it wraps onto more lines.
const TITLE_TEXT: [f64; 2] = [6.0, 3.0];
pub(super) const CAPTION_TEXT: [f64; 2] = [4.5, 2.2];
pub(super) const LEGEND_TEXT: [f64; 2] = [3.5, 2.5];

/// A legend row of sheet swatches (mm).
pub(super) const SWATCH_ROW: f64 = 5.5;

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
pub(super) const CLOSE_UP_CELL_LEAST: f64 = 30.0;

impl CloseUpCells {
    pub(super) fn new(page: &Page) -> CloseUpCells {
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
pub(super) struct Page {
    pub(super) width: f64,
    pub(super) height: f64,
    title: Lines,
    /// Sheet swatches per legend row, and rows.
    pub(super) swatches_per_row: usize,
    pub(super) swatch_rows: usize,
    /// The id key's text size and the most lines it may take.
    pub(super) key: Lines,
}

impl Page {
    /// The page for `input` with `title`, and room for `key` (or any shorter text)
    /// and, if `swatches`, a swatch per sheet.
    pub(super) fn new(input: &MapInput, title: &str, key: &str, swatches: bool) -> Page {
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
    pub(super) fn retitled(&self, title: &str) -> Page {
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
    pub(super) fn legend_height(&self) -> f64 {
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
pub(super) const SHEETS_WORD: &str = "Sheets: ";

/// The width (mm) of one sheet's swatch and number in the legend, for `sheets` sheets.
pub(super) fn swatch_width(sheets: usize) -> f64 {
    4.0 + 1.0 + text_width(&sheets.to_string(), LEGEND_TEXT[0]) + 3.0
}

/// What every view of a map is drawn with.
pub(super) struct MapContext<'a> {
    pub input: &'a MapInput<'a>,
    /// Each panel's sheet (its tint).
    pub(super) sheet_of: Vec<usize>,
    /// Each panel's patches, as indices into the surface's.
    pub panel_patches: Vec<Vec<usize>>,
    pub grid: Grid,
    /// The ids' text height (mm).
    pub text: f64,
    /// The sheets' tints.
    pub(super) palette: Palette,
}

/// The page's grid of views and the one scale they share.
pub(super) struct Grid {
    pub(super) cols: usize,
    /// Page mm per model mm.
    pub scale: f64,
    /// The top-left corner of the views' area.
    pub(super) lo: DVec2,
    pub(super) cell_w: f64,
    pub(super) cell_h: f64,
    /// Each view's caption, fitted to the cell's width, and the caption strip's height.
    pub(super) captions: Vec<Lines>,
    pub(super) caption_h: f64,
}

impl Grid {
    /// The grid of views (columns x rows) that draws the model largest, one scale for
    /// all views so they compare, each view's caption fitted to its cell.
    pub(super) fn largest(page: &Page, views: &[View], extents: &[(DVec2, DVec2)]) -> Grid {
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
pub(super) fn page_head(out: &mut String, page: &Page) {
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
