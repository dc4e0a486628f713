//! The map's words: its title, the legend along each page's foot (the sheets' tints and
//! the id key), and the titles and key of the pages of close-ups.

use std::fmt::Write;

use glam::DVec2;

use super::layout::{
    swatch_width, text_lines, MapContext, MapInput, Page, BORDER, GAP, LEGEND_TEXT, SHEETS_WORD,
    SWATCH_ROW,
};
use super::page::{text_width, wrap, Lines};
use crate::export::fmt_mm;
use crate::panel::{IdKind, Panels};

/// The map's title.
pub(super) fn title_text(input: &MapInput) -> String {
    format!(
        "{}: assembly map, {} on {} (tint: sheet; text: panel id)",
        input.name,
        crate::units::count_of(input.panels.len(), "panel"),
        crate::units::count_of(input.layout.sheets, "sheet")
    )
}

/// The sheets' tints (rows of numbered swatches) and the id key, along the page's
/// foot.
pub(super) fn legend(out: &mut String, map: &MapContext, page: &Page, key: &str) {
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
pub(super) fn key_text(
    panels: &Panels,
    [named, closer, unnamed, inside]: [usize; 4],
    pages: usize,
) -> String {
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
pub(super) fn close_up_key(panels: &Panels) -> String {
    format!(
        "Ids: {}. Each close-up shows the region around one panel (outlined) larger, seen from the side its caption names, with the ids page 1 cannot show and, where there is room, their neighbours' ids; where the region is hidden, the model in front of it is cut away. Tints as on page 1.",
        id_legend(panels)
    )
}

/// The title of page `page` of `pages`, a page of close-ups.
pub(super) fn close_up_title(input: &MapInput, page: usize, pages: usize) -> String {
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
