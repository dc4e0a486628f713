//! The preview page (`NAME.html`): the whole build at a glance in any browser, with
//! nothing loaded from the network. Every sheet is shown with strokes wide enough to
//! see on screen or on paper (the sheet files themselves keep their hairlines), with
//! its number, panels, fill and laser time; then the assembly map, the report's
//! figures and the warnings. Pictures are embedded as `data:` URIs, and the page's
//! content security policy forbids any other source.

use std::fmt::Write;

use super::escape;
use super::manifest::Manifest;
use super::report::duration;
use crate::units::count_of;

/// What the page shows.
pub struct PreviewInput<'a> {
    /// The model's name, for the title.
    pub name: &'a str,
    /// The build's figures.
    pub manifest: &'a Manifest,
    /// Each sheet as an SVG document with visible strokes, in sheet order.
    pub sheets: &'a [String],
    /// The assembly map's pages as SVG documents (none if no map was drawn).
    pub map: &'a [String],
}

/// The stroke width (mm) of a sheet on the preview page: a six-hundredth of the
/// sheet's width, at least a pixel wherever the sheet is shown 600 pixels wide.
pub fn preview_stroke(sheet_width: f64) -> f64 {
    sheet_width / 600.0
}

/// The preview page as an HTML document.
pub fn preview_page(input: &PreviewInput) -> String {
    let m = input.manifest;
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; style-src 'unsafe-inline'\">\n\
<title>{name}: unfold preview</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<h1>{name}</h1>\n",
        name = escape(input.name)
    );
    figures(&mut out, m);
    if !m.warnings.is_empty() {
        out.push_str("<h2>Warnings</h2>\n<ul class=\"warnings\">\n");
        for warning in &m.warnings {
            let _ = writeln!(out, "<li>{}</li>", escape(warning));
        }
        out.push_str("</ul>\n");
    }
    out.push_str("<h2>Sheets</h2>\n<div class=\"sheets\">\n");
    for (svg, entry) in input.sheets.iter().zip(&m.sheets) {
        let _ = writeln!(
            out,
            "<figure id=\"sheet-{n}\"><figcaption>Sheet {n}: {panels}, {fill:.0} % filled, laser about {time}</figcaption><img src=\"data:image/svg+xml;base64,{data}\" alt=\"sheet {n}\"></figure>",
            n = entry.sheet,
            panels = count_of(entry.panels, "panel"),
            fill = 100.0 * entry.fill,
            time = duration(entry.time_s),
            data = base64(svg.as_bytes())
        );
    }
    out.push_str("</div>\n");
    if !input.map.is_empty() {
        out.push_str("<h2>Assembly map</h2>\n");
    }
    for (k, page) in input.map.iter().enumerate() {
        let (id, alt) = match k {
            0 => ("map".to_string(), "assembly map".to_string()),
            _ => (
                format!("map-{}", k + 1),
                format!("assembly map, page {}", k + 1),
            ),
        };
        let _ = writeln!(
            out,
            "<figure id=\"{id}\" class=\"map\"><img src=\"data:image/svg+xml;base64,{}\" alt=\"{alt}\"></figure>",
            base64(page.as_bytes())
        );
    }
    out.push_str("</body>\n</html>\n");
    out
}

/// The page's look: sheets side by side as room allows, each on white with a border.
const STYLE: &str = "body { font-family: Helvetica, Arial, sans-serif; margin: 24px; color: #202020; background: #F4F4F4; }
table { border-collapse: collapse; }
td, th { text-align: left; padding: 2px 12px 2px 0; font-weight: normal; }
th { color: #606060; }
.warnings li { color: #A04000; }
.sheets { display: flex; flex-wrap: wrap; gap: 24px; }
figure { margin: 0; }
figure img { display: block; width: 600px; max-width: 100%; height: auto; background: #FFFFFF; border: 1px solid #B0B0B0; }
.map img { width: 900px; }
.map { margin-bottom: 24px; }
figcaption { margin: 6px 0; }
";

/// The report's figures as a table.
fn figures(out: &mut String, m: &Manifest) {
    let rows = [
        ("scheme", m.scheme.name.to_string()),
        ("panels", m.counts.panels.to_string()),
        ("connections", m.counts.connections.to_string()),
        ("fastener holes", m.counts.holes.to_string()),
        (
            "sheets",
            format!(
                "{} of {} ({} x {} mm), at least {} for this panel area",
                m.counts.sheets,
                escape(&m.sheet.name),
                m.sheet.width,
                m.sheet.height,
                m.counts.sheets_lower_bound
            ),
        ),
        ("area used", format!("{:.1} %", 100.0 * m.utilization)),
        ("laser time", format!("about {}", duration(m.laser.time_s))),
    ];
    out.push_str("<table class=\"figures\">\n");
    for (name, value) in rows {
        let _ = writeln!(out, "<tr><th>{name}</th><td>{value}</td></tr>");
    }
    out.push_str("</table>\n");
}

/// Standard base64 (RFC 4648) with padding.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_examples() {
        for (text, encoded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(text.as_bytes()), encoded);
        }
    }
}
