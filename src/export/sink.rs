//! What a sheet is drawn into: the kinds of laser geometry and their layers, the
//! [`SheetSink`] that the SVG and DXF writers and the [`Lengths`] measure implement,
//! and the one way a length is written.

use glam::DVec2;
use serde::Serialize;

use crate::panel::FoldKind;
use crate::record::round4;

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

/// How one kind of geometry is drawn: its layer's name (SVG group label, DXF layer),
/// its colour and its stroke width.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerStyle {
    /// Layer name.
    pub name: String,
    /// Pure RGB colour, `#RRGGBB` (drivers match colours exactly).
    pub color: String,
    /// SVG stroke width (mm).
    pub stroke_width: f64,
}

/// The style of every kind, in [`Kind::ALL`] order.
#[derive(Clone, Debug, PartialEq)]
pub struct Layers(pub [LayerStyle; 4]);

impl Layers {
    /// LASER.md's layers (ENGRAVE black, SCORE blue, SCORE-VALLEY green, CUT red),
    /// every stroke `stroke_width` mm wide.
    pub fn standard(stroke_width: f64) -> Layers {
        Layers(Kind::ALL.map(|kind| {
            LayerStyle {
                name: kind.layer().to_string(),
                color: match kind {
                    Kind::Engrave => "#000000",
                    Kind::Score => "#0000FF",
                    Kind::ScoreValley => "#00FF00",
                    Kind::Cut => "#FF0000",
                }
                .to_string(),
                stroke_width,
            }
        }))
    }

    /// The style of `kind`.
    pub fn of(&self, kind: Kind) -> &LayerStyle {
        &self.0[kind as usize]
    }

    /// The style of `kind`, to change.
    pub fn of_mut(&mut self, kind: Kind) -> &mut LayerStyle {
        &mut self.0[kind as usize]
    }

    /// The AutoCAD colour index of `kind` in a DXF file: the nearest of the seven
    /// standard colours to its RGB colour (R12 files have no true colour).
    pub fn aci(&self, kind: Kind) -> u8 {
        nearest_aci(&self.of(kind).color)
    }
}

/// The nearest of ACI colours 1 to 7 (red, yellow, green, cyan, blue, magenta, and 7,
/// black or white by the background) to `#RRGGBB`; 7 for anything unreadable.
pub fn nearest_aci(color: &str) -> u8 {
    let channel = |k: usize| {
        color
            .get(1 + 2 * k..3 + 2 * k)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .map(f64::from)
    };
    let (Some(r), Some(g), Some(b)) = (channel(0), channel(1), channel(2)) else {
        return 7;
    };
    let standard: [(u8, [f64; 3]); 8] = [
        (1, [255.0, 0.0, 0.0]),
        (2, [255.0, 255.0, 0.0]),
        (3, [0.0, 255.0, 0.0]),
        (4, [0.0, 255.0, 255.0]),
        (5, [0.0, 0.0, 255.0]),
        (6, [255.0, 0.0, 255.0]),
        (7, [0.0, 0.0, 0.0]),
        (7, [255.0, 255.0, 255.0]),
    ];
    standard
        .iter()
        .min_by(|(_, p), (_, q)| {
            let d = |c: &[f64; 3]| (c[0] - r).powi(2) + (c[1] - g).powi(2) + (c[2] - b).powi(2);
            d(p).total_cmp(&d(q))
        })
        .map_or(7, |(aci, _)| *aci)
}

/// How sheets are drawn: the layers, and which face the labels read on.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetStyle {
    /// Every kind's layer.
    pub layers: Layers,
    /// Labels mirrored, to read on the inside face (`--labels inside`).
    pub labels_inside: bool,
}

/// Receives sheet geometry in sheet coordinates (mm, origin lower-left, y up).
pub trait SheetSink {
    /// A polyline; `closed` joins the last point to the first.
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool);
    /// A circle.
    fn circle(&mut self, kind: Kind, center: DVec2, radius: f64);
}

/// Lengths of what a sheet (or a run) draws, per kind (mm), as measured and, rounded,
/// as the manifest records them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Lengths {
    /// Cut length.
    pub cut: f64,
    /// Score length of mountain folds (as the sheets lie) and rulings: the SCORE layer.
    pub score: f64,
    /// Score length of valley folds (as the sheets lie): the SCORE-VALLEY layer.
    pub score_valley: f64,
    /// Engrave length.
    pub engrave: f64,
    /// Travel with the beam off, between the end of one path and the start of the
    /// next, in the order they were drawn.
    pub travel: f64,
    /// Where the last path drawn ended.
    #[serde(skip)]
    pub last_end: Option<DVec2>,
}

impl Lengths {
    /// The lengths rounded to 4 decimals, as the manifest records them.
    pub fn rounded(&self) -> Lengths {
        Lengths {
            cut: round4(self.cut),
            score: round4(self.score),
            score_valley: round4(self.score_valley),
            engrave: round4(self.engrave),
            travel: round4(self.travel),
            last_end: self.last_end,
        }
    }

    /// The beam moves to `start` and leaves at `end`.
    fn run(&mut self, start: DVec2, end: DVec2) {
        if let Some(at) = self.last_end {
            self.travel += at.distance(start);
        }
        self.last_end = Some(end);
    }

    /// These lengths and `other`'s, added (the travel between them not counted).
    pub fn add(&mut self, other: &Lengths) {
        self.cut += other.cut;
        self.score += other.score;
        self.score_valley += other.score_valley;
        self.engrave += other.engrave;
        self.travel += other.travel;
    }
}

/// A sink that only measures.
impl SheetSink for Lengths {
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool) {
        let mut length: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
        if closed && points.len() > 2 {
            length += points[points.len() - 1].distance(points[0]);
        }
        *self.slot(kind) += length;
        if let (Some(&first), Some(&last)) = (points.first(), points.last()) {
            self.run(first, if closed { first } else { last });
        }
    }
    fn circle(&mut self, kind: Kind, center: DVec2, radius: f64) {
        *self.slot(kind) += std::f64::consts::TAU * radius;
        let start = center + DVec2::new(radius, 0.0);
        self.run(start, start);
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
