//! The report printed on stderr after a run: the manifest's facts in plain words, the
//! notes of every stage and the time of each.

use std::path::Path;
use std::time::Duration;

use super::manifest::Manifest;
use crate::units::{fmt_num, fmt_path_length};

/// What the report says beyond the manifest.
pub struct Extras<'a> {
    /// Observations of the stages (repairs, shortened tabs, split faces…).
    pub notes: &'a [String],
    /// The scheme's own lines (the woven cycles).
    pub scheme_report: &'a [String],
    /// Wall time per stage.
    pub times: &'a [(&'static str, Duration)],
    /// The files written.
    pub files: &'a [String],
}

/// A time as a person says it: "42 s", "12 min", "5 h 40 min".
pub(super) fn duration(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min", (s + 30) / 60)
    } else {
        let minutes = (s + 30) / 60;
        format!("{} h {} min", minutes / 60, minutes % 60)
    }
}

/// " 28 sheets placed, 27 after moving parts, 26 after squeezing;" when the true-shape
/// search's later phases saved sheets (whether more effort may pay); else nothing.
fn search_savings(nesting: &super::manifest::Nesting) -> String {
    use crate::nest::NesterName::TrueShape;
    match nesting.search_sheets {
        Some(p) if nesting.nester == TrueShape.as_str() && p.squeezed < p.placed => format!(
            " {} placed, {} after moving parts, {} after squeezing;",
            crate::units::count_of(p.placed, "sheet"),
            p.moved,
            p.squeezed
        ),
        _ => String::new(),
    }
}

/// The report's lines on the laser: path lengths and folds, the kerf, the time.
fn laser_lines(s: &mut String, m: &Manifest) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "laser paths: cut {}, score {}, valley score {}, engrave {}; {} mountain and {} valley folds",
        fmt_path_length(m.lengths.cut),
        fmt_path_length(m.lengths.score),
        fmt_path_length(m.lengths.score_valley),
        fmt_path_length(m.lengths.engrave),
        m.counts.folds_mountain,
        m.counts.folds_valley
    );
    if m.sheet.kerf > 0.0 {
        let _ = writeln!(
            s,
            "kerf {} mm: every cut loop is offset {} mm into the waste (outlines out, holes and inner cuts in); the parts come out at their nominal size",
            fmt_num(m.sheet.kerf),
            fmt_num(m.sheet.kerf / 2.0)
        );
    }
    let times: Vec<f64> = m.sheets.iter().map(|s| s.time_s).collect();
    let (fastest, slowest) = (
        times.iter().copied().fold(f64::INFINITY, f64::min),
        times.iter().copied().fold(0.0, f64::max),
    );
    let v = &m.laser.speeds;
    let _ = writeln!(
        s,
        "laser time: about {} at cut {}, score {}, engrave {}, travel {} mm/s ({} to {} a sheet); nearest-first order: travel {} instead of {}",
        duration(m.laser.time_s),
        fmt_num(v.cut),
        fmt_num(v.score),
        fmt_num(v.engrave),
        fmt_num(v.travel),
        duration(fastest),
        duration(slowest),
        fmt_path_length(m.lengths.travel),
        fmt_path_length(m.laser.travel_as_placed)
    );
}

/// The short report of a run: its manifest in plain words, then `extras`.
pub fn text(m: &Manifest, extras: &Extras, out: &Path) -> String {
    use std::fmt::Write;
    let c = &m.counts;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: {} scheme, {} panels, {} connections, {} fastener holes",
        m.input.path, m.scheme.name, c.panels, c.connections, c.holes
    );
    if c.holes > 0 {
        let by: Vec<String> = c
            .connections_by_holes
            .iter()
            .map(|(holes, n)| format!("{n} with {holes}"))
            .collect();
        let _ = writeln!(
            s,
            "fasteners: {} (one per pair of holes); connections by holes: {}",
            c.fasteners,
            by.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "sheets: {} of {} ({:.1} x {:.1} mm), {:.1} % of their area used; at least {} needed for this panel area at this spacing",
        c.sheets,
        m.sheet.name,
        m.sheet.width,
        m.sheet.height,
        100.0 * m.utilization,
        c.sheets_spacing_bound
    );
    for line in extras.scheme_report {
        let _ = writeln!(s, "{line}");
    }
    let fills: Vec<String> = m
        .sheets
        .iter()
        .map(|e| format!("{:.0}%", 100.0 * e.fill))
        .collect();
    let _ = writeln!(
        s,
        "layout: {} (effort {}, seed {}),{} each sheet filled {}; laying bounding boxes in rows would take {}",
        m.nesting.nester,
        m.nesting.effort,
        m.nesting.seed,
        search_savings(&m.nesting),
        fills.join(" "),
        crate::units::count_of(m.nesting.shelf_sheets, "sheet")
    );
    laser_lines(&mut s, m);
    // Exact panels carry only float noise, rounded away in the manifest.
    let error = m.max_developability_error;
    if error == 0.0 {
        let _ = writeln!(s, "flat panels: every panel unrolls exactly");
    } else if error < 1e-3 {
        let _ = writeln!(
            s,
            "flat panels: unrolling changes a facet edge by less than 0.001 mm"
        );
    } else {
        let _ = writeln!(
            s,
            "flat panels: unrolling changes a facet edge by {error:.3} mm at most"
        );
    }
    if c.labels_left_out > 0 {
        let marks = c.labels_left_out - c.panel_ids_left_out - c.partner_ids_left_out;
        let _ = writeln!(
            s,
            "labels left out (no room for a 1.5 mm cap height): {} panel ids, {} partner ids, {} vertex and face marks",
            c.panel_ids_left_out, c.partner_ids_left_out, marks
        );
    }
    for note in extras.notes {
        let _ = writeln!(s, "note: {note}");
    }
    let times: Vec<String> = extras
        .times
        .iter()
        .map(|(stage, t)| format!("{stage} {:.0} ms", t.as_secs_f64() * 1e3))
        .collect();
    let _ = writeln!(s, "time: {}", times.join(", "));
    let dxf = extras.files.iter().any(|f| f.ends_with(".dxf"));
    let _ = writeln!(
        s,
        "wrote {} files to {}{}",
        extras.files.len(),
        out.display(),
        if dxf { " (DXF in millimetres)" } else { "" }
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_naturally() {
        assert_eq!(duration(44.2), "44 s");
        assert_eq!(duration(1080.0), "18 min");
        assert_eq!(duration(6.0 * 3600.0 + 20.0 * 60.0), "6 h 20 min");
    }
}
