//! DXF R12 (AC1009) per sheet, written by hand (LASER.md: the `dxf` crate writes
//! R13-era markers, timestamps and random GUIDs). Closed and open POLYLINEs and
//! CIRCLEs on layers CUT, SCORE, SCORE-VALLEY, ENGRAVE, colour on the layer and on every entity.
//! DXF's y axis points up like the sheet's, so coordinates go out unchanged (which is
//! the SVG's `height − y`). Millimetres.

use std::fmt::Write;

use glam::DVec2;

use super::sink::{fmt_mm, Kind, Layers, SheetSink};

/// Collects one sheet's entities; [`DxfSheet::finish`] writes the file.
pub struct DxfSheet {
    width: f64,
    height: f64,
    entities: [String; 4],
    layers: Layers,
}

impl DxfSheet {
    /// A sheet of `width` × `height` mm.
    pub fn new(width: f64, height: f64, layers: &Layers) -> Self {
        Self {
            width,
            height,
            entities: Default::default(),
            layers: layers.clone(),
        }
    }

    /// The file, with CRLF-free ASCII group codes.
    pub fn finish(self) -> String {
        let mut out = String::new();
        let mut pair = |code: i32, value: &str| {
            let _ = write!(out, "{code:>3}\n{value}\n");
        };
        pair(0, "SECTION");
        pair(2, "HEADER");
        pair(9, "$ACADVER");
        pair(1, "AC1009");
        pair(9, "$INSBASE");
        for (code, v) in [(10, 0.0), (20, 0.0), (30, 0.0)] {
            pair(code, &fmt_mm(v));
        }
        pair(9, "$EXTMIN");
        for (code, v) in [(10, 0.0), (20, 0.0), (30, 0.0)] {
            pair(code, &fmt_mm(v));
        }
        pair(9, "$EXTMAX");
        for (code, v) in [(10, self.width), (20, self.height), (30, 0.0)] {
            pair(code, &fmt_mm(v));
        }
        pair(0, "ENDSEC");
        pair(0, "SECTION");
        pair(2, "TABLES");
        pair(0, "TABLE");
        pair(2, "LTYPE");
        pair(70, "1");
        pair(0, "LTYPE");
        pair(2, "CONTINUOUS");
        pair(70, "0");
        pair(3, "Solid line");
        pair(72, "65");
        pair(73, "0");
        pair(40, "0");
        pair(0, "ENDTAB");
        pair(0, "TABLE");
        pair(2, "LAYER");
        pair(70, &Kind::ALL.len().to_string());
        for kind in [Kind::Cut, Kind::Score, Kind::ScoreValley, Kind::Engrave] {
            pair(0, "LAYER");
            pair(2, &self.layers.of(kind).name);
            pair(70, "0");
            pair(62, &self.layers.aci(kind).to_string());
            pair(6, "CONTINUOUS");
        }
        pair(0, "ENDTAB");
        pair(0, "ENDSEC");
        pair(0, "SECTION");
        pair(2, "BLOCKS");
        pair(0, "ENDSEC");
        pair(0, "SECTION");
        pair(2, "ENTITIES");
        // Same order as the SVG: engrave, score, valley score, cut.
        let body: String = self.entities.concat();
        out.push_str(&body);
        let mut pair = |code: i32, value: &str| {
            let _ = write!(out, "{code:>3}\n{value}\n");
        };
        pair(0, "ENDSEC");
        pair(0, "EOF");
        out
    }

    fn entity(&mut self, kind: Kind) -> &mut String {
        &mut self.entities[kind as usize]
    }
}

fn push(out: &mut String, code: i32, value: &str) {
    let _ = write!(out, "{code:>3}\n{value}\n");
}

impl SheetSink for DxfSheet {
    fn polyline(&mut self, kind: Kind, points: &[DVec2], closed: bool) {
        if points.len() < 2 {
            return;
        }
        let layer = self.layers.of(kind).name.clone();
        let layer = layer.as_str();
        let c = self.layers.aci(kind).to_string();
        let mut s = String::new();
        push(&mut s, 0, "POLYLINE");
        push(&mut s, 8, layer);
        push(&mut s, 62, &c);
        push(&mut s, 66, "1");
        push(&mut s, 10, "0");
        push(&mut s, 20, "0");
        push(&mut s, 30, "0");
        push(&mut s, 70, if closed { "1" } else { "0" });
        for p in points {
            push(&mut s, 0, "VERTEX");
            push(&mut s, 8, layer);
            push(&mut s, 62, &c);
            push(&mut s, 10, &fmt_mm(p.x));
            push(&mut s, 20, &fmt_mm(p.y));
            push(&mut s, 30, "0");
        }
        push(&mut s, 0, "SEQEND");
        push(&mut s, 8, layer);
        self.entity(kind).push_str(&s);
    }

    fn circle(&mut self, kind: Kind, center: DVec2, radius: f64) {
        let mut s = String::new();
        push(&mut s, 0, "CIRCLE");
        push(&mut s, 8, &self.layers.of(kind).name);
        push(&mut s, 62, &self.layers.aci(kind).to_string());
        push(&mut s, 10, &fmt_mm(center.x));
        push(&mut s, 20, &fmt_mm(center.y));
        push(&mut s, 30, "0");
        push(&mut s, 40, &fmt_mm(radius));
        self.entity(kind).push_str(&s);
    }
}
