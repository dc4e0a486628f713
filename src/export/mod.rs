//! Writing finished sheets. One routine ([`draw_sheet`]) walks a sheet in the order
//! lasers want (engrave, score, valley score, cut; within cut, each part's holes and inner cuts before
//! its outline) and feeds a [`SheetSink`]; the SVG and DXF writers are sinks, so both
//! files carry exactly the same geometry.

pub mod dxf;
pub mod folder;
pub mod laser;
pub mod manifest;
pub mod map;
pub mod obj;
pub mod preview;
pub mod report;
pub mod sink;
pub mod svg;

use glam::DVec2;

pub use sink::{fmt_mm, nearest_aci, Kind, LayerStyle, Layers, Lengths, SheetSink, SheetStyle};

use crate::font::text_strokes;
use crate::nest::{Layout, Placement};
use crate::panel::{label_box, label_extent, FlatPanelRef, FlatPanels};

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
        style: &SheetStyle,
    ) -> Vec<u8> {
        let sheet = &layout.sheet;
        let inside = style.labels_inside;
        let order = PathOrder::Shortest;
        match self {
            Format::Svg => {
                let mut sink = svg::SvgSheet::new(sheet.width, sheet.height, &style.layers);
                draw_sheet(layout, index, panels, inside, order, &mut sink);
                sink.finish().into_bytes()
            }
            Format::Dxf => {
                let mut sink = dxf::DxfSheet::new(sheet.width, sheet.height, &style.layers);
                draw_sheet(layout, index, panels, inside, order, &mut sink);
                sink.finish().into_bytes()
            }
        }
    }
}

/// The order paths are drawn in, within the engrave, score, valley score, cut order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathOrder {
    /// Nearest first from the laser's home (the sheet's top-left corner), to keep the
    /// travel short: what the files get.
    Shortest,
    /// Part by part as the parts were placed: the baseline the travel saved is
    /// measured against.
    AsPlaced,
}

/// Draws sheet `index` of `layout` into `sink`, the labels mirrored when
/// `labels_inside`, the paths of each kind in `order` (a part's holes and inner cuts
/// always before its outline).
pub fn draw_sheet(
    layout: &Layout,
    index: usize,
    panels: &FlatPanels,
    labels_inside: bool,
    order: PathOrder,
    sink: &mut dyn SheetSink,
) {
    let on_sheet: Vec<&Placement> = layout
        .placements
        .iter()
        .filter(|p| p.sheet == index)
        .collect();
    let mut groups: [Vec<laser::Group>; 4] = Default::default();
    for p in &on_sheet {
        let panel = panels.get(p.part);
        groups[Kind::Engrave as usize].extend(label_groups(panel, p, labels_inside));
        for fold in panel.folds {
            let points = fold
                .ends
                .map(|i| p.apply(panel.points[i as usize]))
                .to_vec();
            groups[Kind::of_fold(fold.kind, p.mirrored) as usize].push(laser::Group {
                paths: vec![laser::Path::Polyline {
                    points,
                    closed: false,
                }],
                last_fixed: false,
                keep_order: false,
            });
        }
        let mut cut: Vec<laser::Path> = panel
            .holes
            .iter()
            .map(|hole| laser::Path::Circle {
                center: p.apply(hole.center),
                radius: 0.5 * hole.diameter,
            })
            .collect();
        // Inner cuts, then the outline last: the part drops out when it is cut.
        for lp in panel.outline.iter().skip(1).chain(panel.outline.first()) {
            cut.push(laser::Path::Polyline {
                points: lp
                    .iter()
                    .map(|&i| p.apply(panel.points[i as usize]))
                    .collect(),
                closed: true,
            });
        }
        groups[Kind::Cut as usize].push(laser::Group {
            paths: cut,
            last_fixed: true,
            keep_order: false,
        });
    }
    let mut at = DVec2::new(0.0, layout.sheet.height);
    for (kind, groups) in Kind::ALL.into_iter().zip(groups) {
        let paths: Vec<laser::Path> = match order {
            PathOrder::Shortest => {
                let (paths, end) = laser::order(groups, at);
                at = end;
                paths
            }
            PathOrder::AsPlaced => groups.into_iter().flat_map(|g| g.paths).collect(),
        };
        for path in paths {
            match path {
                laser::Path::Polyline { points, closed } => sink.polyline(kind, &points, closed),
                laser::Path::Circle { center, radius } => sink.circle(kind, center, radius),
            }
        }
    }
}

/// Each label's strokes as one group: scaled to its cap height, its box centred on the
/// label centre, reading along its direction (mirrored in its box when `inside`, so it
/// reads on the back of the sheet); a panel's own id framed.
fn label_groups(panel: FlatPanelRef, placement: &Placement, inside: bool) -> Vec<laser::Group> {
    let mut groups = Vec::with_capacity(panel.labels.len());
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
        let mut paths: Vec<laser::Path> = strokes
            .polylines
            .iter()
            .map(|line| laser::Path::Polyline {
                points: line
                    .iter()
                    .map(|q| {
                        let x = if inside { strokes.width - q.x } else { q.x };
                        origin + x * h * d + q.y * h * up
                    })
                    .collect(),
                closed: false,
            })
            .collect();
        if label.frame > 0.0 {
            let (w, across) = label_extent(label.frame, strokes.width, h);
            paths.push(laser::Path::Polyline {
                points: label_box(placement.apply(label.center), d, w, across).to_vec(),
                closed: true,
            });
        }
        groups.push(laser::Group {
            paths,
            last_fixed: false,
            keep_order: true,
        });
    }
    groups
}

/// Text made safe inside XML and HTML: the map's and the preview page's words.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nest::SheetSpec;
    use crate::panel::{FlatLabel, FlatPanel, LabelKind, Loops, Name, Source};

    /// Records every polyline drawn.
    #[derive(Default)]
    struct Recorder(Vec<(Kind, Vec<DVec2>)>);

    impl SheetSink for Recorder {
        fn polyline(&mut self, kind: Kind, points: &[DVec2], _closed: bool) {
            self.0.push((kind, points.to_vec()));
        }
        fn circle(&mut self, _kind: Kind, _center: DVec2, _radius: f64) {}
    }

    /// The engraved strokes of a square panel whose one label, "E7", reads along +x
    /// about x = 50.
    fn engraved(inside: bool) -> Vec<Vec<DVec2>> {
        let mut outline = Loops::new();
        outline.push(0..4);
        let panel = FlatPanel {
            source: Source::edge(7),
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(100.0, 0.0),
                DVec2::new(100.0, 100.0),
                DVec2::new(0.0, 100.0),
            ],
            outline,
            folds: Vec::new(),
            holes: Vec::new(),
            labels: vec![FlatLabel {
                text: Name::edge(7),
                center: DVec2::new(50.0, 50.0),
                direction: DVec2::X,
                height: 5.0,
                kind: LabelKind::Partner,
                frame: 0.0,
            }],
            developability_error: 0.0,
            area: 1e4,
        };
        let panels: FlatPanels = [panel].into_iter().collect();
        let layout = Layout {
            sheet: SheetSpec {
                width: 200.0,
                height: 200.0,
                margin: 5.0,
                spacing: 3.0,
            },
            sheets: 1,
            placements: vec![Placement::default()],
        };
        let mut sink = Recorder::default();
        draw_sheet(&layout, 0, &panels, inside, PathOrder::Shortest, &mut sink);
        sink.0
            .into_iter()
            .filter(|(k, _)| *k == Kind::Engrave)
            .map(|(_, p)| p)
            .collect()
    }

    #[test]
    fn inside_labels_are_the_mirror_image_of_outside_ones() {
        let (outside, inside) = (engraved(false), engraved(true));
        assert!(!outside.is_empty());
        assert_eq!(outside.len(), inside.len());
        for (o, i) in outside.iter().zip(&inside) {
            assert_eq!(o.len(), i.len());
            for (p, q) in o.iter().zip(i) {
                // Reflected about the label's upright axis, x = 50.
                assert!((q.x - (100.0 - p.x)).abs() < 1e-9 && (q.y - p.y).abs() < 1e-9);
            }
        }
        assert_ne!(outside, inside, "the glyphs of E7 are not symmetric");
    }

    #[test]
    fn standard_colours_have_their_dxf_colours() {
        let layers = Layers::standard(0.0254);
        let aci: Vec<u8> = Kind::ALL.iter().map(|&k| layers.aci(k)).collect();
        assert_eq!(aci, [7, 5, 3, 1]);
        assert_eq!(nearest_aci("#FF8000"), 2);
        assert_eq!(nearest_aci("#FFFFFF"), 7);
    }

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
