//! SVG per sheet (LASER.md): physical size with a millimetre viewBox, one group per
//! kind in the order engrave, score, valley score, cut, hairline strokes in pure colours, no fills,
//! no text, no styles, fixed number format.

use std::fmt::Write;

use glam::DVec2;

use super::sink::{fmt_mm, Kind, Layers, SheetSink};

/// Collects one sheet's elements; [`SvgSheet::finish`] writes the document.
pub struct SvgSheet {
    width: f64,
    height: f64,
    layers: Layers,
    groups: [String; 4],
}

impl SvgSheet {
    /// A sheet of `width` × `height` mm.
    pub fn new(width: f64, height: f64, layers: &Layers) -> Self {
        Self {
            width,
            height,
            layers: layers.clone(),
            groups: Default::default(),
        }
    }

    fn attributes(&self, kind: Kind) -> String {
        let style = self.layers.of(kind);
        format!(
            "fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"",
            style.color,
            fmt_mm(style.stroke_width)
        )
    }

    /// SVG's y axis points down.
    fn xy(&self, p: DVec2) -> String {
        format!("{} {}", fmt_mm(p.x), fmt_mm(self.height - p.y))
    }

    /// The document.
    pub fn finish(self) -> String {
        let mut out = String::new();
        out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" version=\"1.1\" width=\"{w}mm\" height=\"{h}mm\" viewBox=\"0 0 {w} {h}\">",
            w = fmt_mm(self.width),
            h = fmt_mm(self.height)
        );
        for (kind, body) in Kind::ALL.iter().zip(&self.groups) {
            let _ = writeln!(
                out,
                "<g id=\"{}\" inkscape:groupmode=\"layer\" inkscape:label=\"{}\">",
                kind.layer().to_ascii_lowercase(),
                self.layers.of(*kind).name
            );
            out.push_str(body);
            out.push_str("</g>\n");
        }
        out.push_str("</svg>\n");
        out
    }

    fn group(&mut self, kind: Kind) -> &mut String {
        &mut self.groups[kind as usize]
    }
}

impl SheetSink for SvgSheet {
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool) {
        if points.len() < 2 {
            return;
        }
        let mut d = format!("M {}", self.xy(points[0]));
        for &p in &points[1..] {
            let _ = write!(d, " L {}", self.xy(p));
        }
        if closed {
            d.push_str(" Z");
        }
        let line = format!("<path d=\"{d}\" {}/>\n", self.attributes(kind));
        self.group(kind).push_str(&line);
    }

    fn circle(&mut self, kind: Kind, center: DVec2, radius: f64) {
        let (x, y) = (fmt_mm(center.x), fmt_mm(self.height - center.y));
        let line = format!(
            "<circle cx=\"{x}\" cy=\"{y}\" r=\"{}\" {}/>\n",
            fmt_mm(radius),
            self.attributes(kind)
        );
        self.group(kind).push_str(&line);
    }
}
