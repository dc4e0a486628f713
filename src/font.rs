//! Single-stroke text (Hershey Roman simplex, through `vector-text`): labels engrave as
//! lines and need no fonts installed. Shared by label fitting (sizes) and the exporters
//! (strokes), so it sits below both.

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

/// The strokes of an ASCII text. Characters outside printable ASCII are skipped.
pub fn text_strokes(text: &str) -> TextStrokes {
    let ascii: String = text.chars().filter(|c| (' '..='~').contains(c)).collect();
    let points = render_text(&ascii, VectorFont::HersheyFont(HersheyFont::Romans));
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
    fn longer_text_is_wider() {
        assert!(text_strokes("F123").width > text_strokes("F12").width);
    }
}
