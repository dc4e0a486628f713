//! Single-stroke text (Hershey Roman simplex, through `vector-text`): labels engrave as
//! lines and need no fonts installed. Shared by label fitting (sizes) and the exporters
//! (strokes), so it sits below both.

use std::sync::OnceLock;

use glam::DVec2;
use vector_text::{render_text, HersheyFont, VectorFont};

/// Hershey units from cap top (y = −12) to baseline (y = 9).
const CAP_UNITS: f64 = 21.0;
const BASELINE_UNITS: f64 = 9.0;

/// Text as stroke polylines, scaled to a cap height of 1: the baseline is y = 0, cap
/// tops at y = 1, the text starts at x = 0 and runs along +x (y up).
#[derive(Clone, Debug, PartialEq)]
pub struct TextStrokes {
    /// Pen-down polylines.
    pub polylines: Vec<Vec<DVec2>>,
    /// Extent along x.
    pub width: f64,
}

/// Where one character's strokes lie, in Hershey units relative to the pen position
/// where it starts, and how far it moves the pen (the renderer places each character
/// at the sum of the advances before it).
#[derive(Clone, Copy, Debug, Default)]
struct GlyphMetrics {
    /// Extent of its points along x (`None`: no points, like the space).
    extent: Option<(i32, i32)>,
    advance: i32,
}

fn render(text: &str) -> Vec<vector_text::Point> {
    render_text(text, VectorFont::HersheyFont(HersheyFont::Romans))
}

/// The characters the font draws (printable ASCII); others are skipped.
fn is_printable(c: &char) -> bool {
    (' '..='~').contains(c)
}

/// The metrics of every printable ASCII character, measured once from the renderer
/// itself: the extent from the character alone, the advance from where a following
/// `I` lands.
fn glyph_metrics() -> &'static [GlyphMetrics; 95] {
    static TABLE: OnceLock<[GlyphMetrics; 95]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let reference = render("I");
        let reference_x = reference.iter().map(|p| p.x as i32).min().unwrap_or(0);
        let mut table = [GlyphMetrics::default(); 95];
        for (slot, c) in table.iter_mut().zip(' '..='~') {
            let alone = render(&c.to_string());
            let xs = alone.iter().map(|p| p.x as i32);
            let extent = xs.clone().min().zip(xs.max());
            let pair = render(&format!("{c}I"));
            let advance = pair[alone.len()..]
                .iter()
                .map(|p| p.x as i32)
                .min()
                .map_or(0, |x| x - reference_x);
            *slot = GlyphMetrics { extent, advance };
        }
        table
    })
}

/// The width of a text at cap height 1: the same figure as `text_strokes(text).width`,
/// without rendering the strokes or building the string (label fitting needs only
/// this, for every label of every panel).
pub fn text_width(text: impl std::fmt::Display) -> f64 {
    use std::fmt::Write;
    let mut meter = WidthMeter {
        table: glyph_metrics(),
        pen: 0,
        lo: i32::MAX,
        hi: i32::MIN,
    };
    let _ = write!(meter, "{text}");
    if meter.lo > meter.hi {
        0.0
    } else {
        (meter.hi - meter.lo) as f64 / CAP_UNITS
    }
}

/// Lays characters out as the renderer does, keeping only the extent.
struct WidthMeter {
    table: &'static [GlyphMetrics; 95],
    pen: i32,
    lo: i32,
    hi: i32,
}

impl std::fmt::Write for WidthMeter {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for c in s.chars().filter(is_printable) {
            let glyph = self.table[c as usize - ' ' as usize];
            if let Some((a, b)) = glyph.extent {
                self.lo = self.lo.min(self.pen + a);
                self.hi = self.hi.max(self.pen + b);
            }
            self.pen += glyph.advance;
        }
        Ok(())
    }
}

/// The strokes of an ASCII text. Characters outside printable ASCII are skipped.
pub fn text_strokes(text: impl std::fmt::Display) -> TextStrokes {
    let ascii: String = text.to_string().chars().filter(is_printable).collect();
    let points = render(&ascii);
    let min_x = points.iter().map(|p| p.x).min().unwrap_or(0) as f64;
    let mut polylines: Vec<Vec<DVec2>> = Vec::new();
    let mut width = 0.0f64;
    for p in &points {
        let q = DVec2::new(
            (p.x as f64 - min_x) / CAP_UNITS,
            (BASELINE_UNITS - p.y as f64) / CAP_UNITS,
        );
        width = width.max(q.x);
        match polylines.last_mut() {
            Some(line) if p.pen => line.push(q),
            _ => polylines.push(vec![q]),
        }
    }
    polylines.retain(|l| l.len() >= 2);
    TextStrokes { polylines, width }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_height_is_one_and_text_starts_at_zero() {
        let s = text_strokes("E12");
        let ys = s.polylines.iter().flatten().map(|p| p.y);
        let (lo, hi) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
        assert!(
            (lo - 0.0).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        let min_x = s
            .polylines
            .iter()
            .flatten()
            .map(|p| p.x)
            .fold(f64::MAX, f64::min);
        assert_eq!(min_x, 0.0);
        assert!(s.width > 2.0 && s.width < 3.0, "{}", s.width);
        // 'E' is four strokes, '1' two... at least one polyline per character.
        assert!(s.polylines.len() >= 3);
    }

    #[test]
    fn width_without_strokes_matches_the_strokes() {
        let printable: Vec<char> = (' '..='~').collect();
        let mut texts: Vec<String> = printable.iter().map(|c| c.to_string()).collect();
        texts.extend(
            [
                "", " ", "  A ", "E12", "C3.2", "F1234567", "j_,|~", "W.W", "\u{e9}x",
            ]
            .map(String::from),
        );
        // Every pair, so each character's advance is exercised before every other.
        for a in &printable {
            for b in &printable {
                texts.push(format!("{a}{b}"));
            }
        }
        for text in &texts {
            assert_eq!(
                text_width(text.as_str()),
                text_strokes(text.as_str()).width,
                "{text:?}"
            );
        }
    }

    #[test]
    fn longer_text_is_wider() {
        assert!(text_strokes("F123").width > text_strokes("F12").width);
    }
}
