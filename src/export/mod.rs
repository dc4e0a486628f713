//! Writing finished sheets. One routine ([`draw_sheet`]) walks a sheet in the order
//! lasers want (engrave, score, valley score, cut; within cut, each part's holes and inner cuts before
//! its outline) and feeds a [`SheetSink`]; the SVG and DXF writers are sinks, so both
//! files carry exactly the same geometry.

pub mod dxf;
pub mod folder;
pub mod manifest;
pub mod map;
pub mod obj;
pub mod report;
pub mod svg;

use glam::DVec2;

use crate::font::text_strokes;
use crate::nest::{Layout, Placement};
use crate::panel::{label_box, label_extent, FlatPanelRef, FlatPanels, Fold, FoldKind};

/// The kinds of laser geometry, in the order a sheet is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// Marks: labels.
    Engrave,
    /// Partial depth: mountain folds as the sheet lies (and Bézier rulings).
    Score,
    /// Partial depth: valley folds as the sheet lies (the operator gives them other
    /// power or scores them from the back).
    ScoreValley,
    /// Through: outlines and holes.
    Cut,
}

impl Kind {
    /// Every kind, in drawing order.
    pub const ALL: [Kind; 4] = [Kind::Engrave, Kind::Score, Kind::ScoreValley, Kind::Cut];

    /// Layer name.
    pub fn layer(self) -> &'static str {
        match self {
            Kind::Engrave => "ENGRAVE",
            Kind::Score => "SCORE",
            Kind::ScoreValley => "SCORE-VALLEY",
            Kind::Cut => "CUT",
        }
    }

    /// The layer of a fold of `kind` on a part placed `mirrored` (cut face down, its
    /// mountains are valleys from the top of the sheet, where the laser scores).
    pub fn of_fold(kind: FoldKind, mirrored: bool) -> Kind {
        match (kind, mirrored) {
            (FoldKind::Mountain, false) | (FoldKind::Valley, true) => Kind::Score,
            (FoldKind::Valley, false) | (FoldKind::Mountain, true) => Kind::ScoreValley,
        }
    }
}

/// Receives sheet geometry in sheet coordinates (mm, origin lower-left, y up).
pub trait SheetSink {
    /// A polyline; `closed` joins the last point to the first.
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool);
    /// A circle.
    fn circle(&mut self, kind: Kind, center: DVec2, radius: f64);
}

/// The sheet file formats: each is a sink with its file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// One SVG per sheet, in millimetres (the laser's own vector format).
    Svg,
    /// One R12 DXF per sheet, in millimetres.
    Dxf,
}

impl Format {
    /// Every format, in the order files are written.
    pub const ALL: [Format; 2] = [Format::Svg, Format::Dxf];

    /// Its name for `--format`, also the file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Svg => "svg",
            Format::Dxf => "dxf",
        }
    }

    /// Parses a `--format` list ("svg,dxf") into formats in [`Format::ALL`] order.
    pub fn parse_list(text: &str) -> Result<Vec<Format>, String> {
        let mut chosen = Vec::new();
        for part in text.split(',') {
            let name = part.trim().to_ascii_lowercase();
            let format = Format::ALL
                .into_iter()
                .find(|f| f.extension() == name)
                .ok_or_else(|| format!("unknown format '{name}'; use svg, dxf or svg,dxf"))?;
            chosen.push(format);
        }
        Ok(Format::ALL
            .into_iter()
            .filter(|f| chosen.contains(f))
            .collect())
    }

    /// Sheet `index` of `layout` in this format.
    pub fn write_sheet(
        self,
        layout: &Layout,
        index: usize,
        panels: &FlatPanels,
        stroke_width: f64,
    ) -> Vec<u8> {
        let sheet = &layout.sheet;
        match self {
            Format::Svg => {
                let style = svg::SvgStyle {
                    stroke_width,
                    ..svg::SvgStyle::default()
                };
                let mut sink = svg::SvgSheet::new(sheet.width, sheet.height, style);
                draw_sheet(layout, index, panels, &mut sink);
                sink.finish().into_bytes()
            }
            Format::Dxf => {
                let mut sink = dxf::DxfSheet::new(sheet.width, sheet.height);
                draw_sheet(layout, index, panels, &mut sink);
                sink.finish().into_bytes()
            }
        }
    }
}

/// Lengths of what a sheet (or a run) draws, per kind (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lengths {
    /// Cut length.
    pub cut: f64,
    /// Score length of mountain folds (as the sheets lie) and rulings.
    pub score: f64,
    /// Score length of valley folds (as the sheets lie).
    pub score_valley: f64,
    /// Engrave length.
    pub engrave: f64,
}

/// A sink that only measures.
impl SheetSink for Lengths {
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool) {
        let mut length: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
        if closed && points.len() > 2 {
            length += points[points.len() - 1].distance(points[0]);
        }
        *self.slot(kind) += length;
    }
    fn circle(&mut self, kind: Kind, _center: DVec2, radius: f64) {
        *self.slot(kind) += std::f64::consts::TAU * radius;
    }
}

impl Lengths {
    fn slot(&mut self, kind: Kind) -> &mut f64 {
        match kind {
            Kind::Cut => &mut self.cut,
            Kind::Score => &mut self.score,
            Kind::ScoreValley => &mut self.score_valley,
            Kind::Engrave => &mut self.engrave,
        }
    }
}

/// Draws sheet `index` of `layout` into `sink`.
pub fn draw_sheet(layout: &Layout, index: usize, panels: &FlatPanels, sink: &mut dyn SheetSink) {
    let on_sheet: Vec<&Placement> = layout
        .placements
        .iter()
        .filter(|p| p.sheet == index)
        .collect();
    for p in &on_sheet {
        draw_labels(panels.get(p.part), p, sink);
    }
    for p in &on_sheet {
        let panel = panels.get(p.part);
        for fold in panel
            .folds
            .iter()
            .filter(|f| Kind::of_fold(f.kind, p.mirrored) == Kind::Score)
        {
            draw_fold(panel, p, fold, sink);
        }
    }
    for p in &on_sheet {
        let panel = panels.get(p.part);
        for fold in panel
            .folds
            .iter()
            .filter(|f| Kind::of_fold(f.kind, p.mirrored) == Kind::ScoreValley)
        {
            draw_fold(panel, p, fold, sink);
        }
    }
    for p in &on_sheet {
        let panel = panels.get(p.part);
        for hole in panel.holes {
            sink.circle(Kind::Cut, p.apply(hole.center), 0.5 * hole.diameter);
        }
        for lp in panel.outline.iter().skip(1) {
            let points: Vec<DVec2> = lp
                .iter()
                .map(|&i| p.apply(panel.points[i as usize]))
                .collect();
            sink.polyline(Kind::Cut, &points, true);
        }
        let outer: Vec<DVec2> = panel.outline[0]
            .iter()
            .map(|&i| p.apply(panel.points[i as usize]))
            .collect();
        sink.polyline(Kind::Cut, &outer, true);
    }
}

/// A fold's score line, on its kind's layer.
fn draw_fold(panel: FlatPanelRef, placement: &Placement, fold: &Fold, sink: &mut dyn SheetSink) {
    let line = fold.ends.map(|i| placement.apply(panel.points[i as usize]));
    sink.polyline(Kind::of_fold(fold.kind, placement.mirrored), &line, false);
}

/// A label's strokes: scaled to its cap height, its box centred on the label centre,
/// reading along its direction; a panel's own id framed.
fn draw_labels(panel: FlatPanelRef, placement: &Placement, sink: &mut dyn SheetSink) {
    for label in panel.labels {
        let strokes = text_strokes(label.text);
        let h = label.height;
        // Read left to right on the sheet: turning the text half a turn about its box
        // centre keeps it in the same box.
        let mut d = placement.apply_direction(label.direction);
        if d.x < -1e-9 || (d.x.abs() <= 1e-9 && d.y < 0.0) {
            d = -d;
        }
        let up = d.perp();
        let origin = placement.apply(label.center) - 0.5 * strokes.width * h * d - 0.5 * h * up;
        for line in &strokes.polylines {
            let points: Vec<DVec2> = line
                .iter()
                .map(|q| origin + q.x * h * d + q.y * h * up)
                .collect();
            sink.polyline(Kind::Engrave, &points, false);
        }
        if label.frame > 0.0 {
            let (w, across) = label_extent(label.frame, strokes.width, h);
            let frame = label_box(placement.apply(label.center), d, w, across);
            sink.polyline(Kind::Engrave, &frame, true);
        }
    }
}

/// A length in mm with at most 4 decimals, trailing zeros trimmed, never `-0`, never
/// an exponent: identical input gives identical bytes. Rounds through an integer count
/// of ten-thousandths (half away from zero), which is exact and far faster than
/// `format!("{:.4}")` on the hundreds of thousands of numbers a sheet set holds.
pub fn fmt_mm(x: f64) -> String {
    let scaled = (x * 1e4).round();
    if !scaled.is_finite() || scaled.abs() >= 9.0e15 {
        // Beyond exact integers in f64 (over 900 km): fall back to the slow path.
        let s = format!("{x:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return if s == "-0" { "0".into() } else { s.into() };
    }
    let units = scaled as i64;
    if units == 0 {
        return "0".to_string();
    }
    let sign = if units < 0 { "-" } else { "" };
    let magnitude = units.unsigned_abs();
    let (whole, frac) = (magnitude / 10_000, magnitude % 10_000);
    if frac == 0 {
        return format!("{sign}{whole}");
    }
    let digits = format!("{frac:04}");
    format!("{sign}{whole}.{}", digits.trim_end_matches('0'))
}

#[cfg(test)]
mod tests {
    use super::fmt_mm;

    #[test]
    fn numbers_are_fixed_and_trimmed() {
        assert_eq!(fmt_mm(457.2), "457.2");
        assert_eq!(fmt_mm(1.0 / 3.0), "0.3333");
        assert_eq!(fmt_mm(-0.00001), "0");
        assert_eq!(fmt_mm(12.0), "12");
        assert_eq!(fmt_mm(1e-12), "0");
        assert_eq!(fmt_mm(123456789.0), "123456789");
        assert_eq!(fmt_mm(-2.50004), "-2.5");
        assert_eq!(fmt_mm(0.00005), "0.0001");
        assert_eq!(fmt_mm(-0.00005), "-0.0001");
        assert_eq!(fmt_mm(609.6), "609.6");
        assert_eq!(fmt_mm(0.0254), "0.0254");
        assert_eq!(fmt_mm(1e300), format!("{:.0}", 1e300));
    }
}
