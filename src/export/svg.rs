//! SVG per sheet (LASER.md): physical size with a millimetre viewBox, one group per
//! kind in the order engrave, score, valley score, cut, hairline strokes in pure colours, no fills,
//! no text, no styles, fixed number format.

use std::fmt::Write;

use glam::DVec2;

use super::{fmt_mm, Kind, SheetSink};

/// Stroke colours and width.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgStyle {
    /// CUT colour.
    pub cut: String,
    /// SCORE colour.
    pub score: String,
    /// SCORE-VALLEY colour.
    pub score_valley: String,
    /// ENGRAVE colour.
    pub engrave: String,
    /// Stroke width (mm).
    pub stroke_width: f64,
}

impl Default for SvgStyle {
    fn default() -> Self {
        Self {
            cut: "#FF0000".into(),
            score: "#0000FF".into(),
            score_valley: "#00FF00".into(),
            engrave: "#000000".into(),
            stroke_width: 0.0254,
        }
    }
}

/// Collects one sheet's elements; [`SvgSheet::finish`] writes the document.
pub struct SvgSheet {
    width: f64,
    height: f64,
    style: SvgStyle,
    groups: [String; 4],
}

impl SvgSheet {
    /// A sheet of `width` × `height` mm.
    pub fn new(width: f64, height: f64, style: SvgStyle) -> Self {
        Self {
            width,
            height,
            style,
            groups: Default::default(),
        }
    }

    fn attributes(&self, kind: Kind) -> String {
        let colour = match kind {
            Kind::Cut => &self.style.cut,
            Kind::Score => &self.style.score,
            Kind::ScoreValley => &self.style.score_valley,
            Kind::Engrave => &self.style.engrave,
        };
        format!(
            "fill=\"none\" stroke=\"{colour}\" stroke-width=\"{}\"",
            fmt_mm(self.style.stroke_width)
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
                kind.layer()
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
