//! `NAME-assembled.obj`: the 3D panels as one mesh (one object per panel), to check
//! the construction in any viewer. Millimetres, fixed number format.

use std::fmt::Write;

use super::fmt_mm;
use crate::panel::Panels;

/// The OBJ text of the panels as they sit in the model.
pub fn assembled_obj(panels: &Panels) -> String {
    let mut out = format!("{} (mm)\n", super::folder::ASSEMBLED_HEADER);
    let mut base = 1usize;
    for panel in panels {
        let _ = writeln!(out, "o {}", panel.id());
        for v in panel.vertices {
            let _ = writeln!(out, "v {} {} {}", fmt_mm(v.x), fmt_mm(v.y), fmt_mm(v.z));
        }
        for facet in panel.facets {
            out.push('f');
            for &i in facet {
                let _ = write!(out, " {}", base + i as usize);
            }
            out.push('\n');
        }
        base += panel.vertices.len();
    }
    out
}
