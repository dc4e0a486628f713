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
//!
//! [`PanelSurface`]: crate::panel::surface::PanelSurface

use glam::DVec2;

mod closeup;
mod draw;
mod layout;
mod legend;
pub mod page;
mod raster;
mod view;

use crate::panel::Covers;
use draw::{draw_view, text_height};
pub use layout::MapInput;
use layout::{page_head, CloseUpCells, Grid, MapContext, Page, CLOSE_UP_CELL_LEAST};
use legend::{close_up_key, close_up_title, key_text, legend, title_text};
use page::Palette;
use view::{bounds, views};

/// The assembly map as SVG pages of the sheet's size: the overview (six views), then,
/// where the overview has no room for some ids, pages of close-ups until every panel
/// is named ([`closeup`]).
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
    let drawn = closeup::close_ups(map, &cells, named);
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
