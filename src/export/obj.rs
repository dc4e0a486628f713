//! `NAME-assembled.obj`: the 3D panels as one mesh (one object per panel), to check
//! the construction in any viewer. Millimetres, fixed number format.

use std::collections::HashMap;
use std::fmt::Write;

use super::fmt_mm;
use crate::panel::surface::PanelSurface;
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

/// The OBJ text of a scheme's own surface (the strip scheme's strips), one object per
/// panel holding the patches it covers there, without its tabs: the surface the build
/// makes, so its distance to the model can be measured. Corners a panel's patches
/// share are one vertex.
pub fn surface_obj(panels: &Panels, surface: &PanelSurface) -> String {
    let mut out = format!("{} (mm)\n", super::folder::ASSEMBLED_HEADER);
    let mut base = 1usize;
    for (k, panel) in panels.iter().enumerate() {
        let _ = writeln!(out, "o {}", panel.id());
        let mut index: HashMap<[u64; 3], usize> = HashMap::new();
        let mut faces = String::new();
        for patch in surface.patches.iter().filter(|p| p.panel == k) {
            faces.push('f');
            for p in &patch.points {
                let next = index.len();
                let i = *index
                    .entry(p.to_array().map(f64::to_bits))
                    .or_insert_with(|| {
                        let _ = writeln!(out, "v {} {} {}", fmt_mm(p.x), fmt_mm(p.y), fmt_mm(p.z));
                        next
                    });
                let _ = write!(faces, " {}", base + i);
            }
            faces.push('\n');
        }
        out.push_str(&faces);
        base += index.len();
    }
    out
}
