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

/// The OBJ text of rigid panels `thickness` mm thick as they sit in the model: each a
/// closed solid (its facets, the same moved inward and turned over, and a square-cut
/// side along every cut edge, slots included), one object per panel.
pub fn solid_obj(panels: &Panels, thickness: f64) -> String {
    let mut out = format!("{} (mm)\n", super::folder::ASSEMBLED_HEADER);
    let mut base = 1usize;
    for panel in panels {
        let _ = writeln!(out, "o {}", panel.id());
        let Some(first) = panel.facets.first() else {
            continue;
        };
        // Every facet of a rigid panel lies in one plane.
        let corners: Vec<glam::DVec3> = first.iter().map(|&i| panel.vertices[i as usize]).collect();
        let normal = vector_area(&corners).normalize_or_zero();
        let n = panel.vertices.len();
        let inner = panel.vertices.iter().map(|&p| p - thickness * normal);
        for v in panel.vertices.iter().copied().chain(inner) {
            let _ = writeln!(out, "v {} {} {}", fmt_mm(v.x), fmt_mm(v.y), fmt_mm(v.z));
        }
        let mut used = std::collections::BTreeSet::new();
        for facet in panel.facets {
            let top: Vec<String> = facet
                .iter()
                .map(|&i| (base + i as usize).to_string())
                .collect();
            let _ = writeln!(out, "f {}", top.join(" "));
            let bottom: Vec<String> = facet
                .iter()
                .rev()
                .map(|&i| (base + n + i as usize).to_string())
                .collect();
            let _ = writeln!(out, "f {}", bottom.join(" "));
            for k in 0..facet.len() {
                used.insert((facet[k], facet[(k + 1) % facet.len()]));
            }
        }
        // A side wall along every edge that only one facet uses: the cut edges.
        for &(i, j) in used.iter().filter(|&&(i, j)| !used.contains(&(j, i))) {
            let (i, j) = (base + i as usize, base + j as usize);
            let _ = writeln!(out, "f {j} {i} {} {}", i + n, j + n);
        }
        base += 2 * n;
    }
    out
}

/// The vector area of a planar loop (its normal times its area).
fn vector_area(corners: &[glam::DVec3]) -> glam::DVec3 {
    let n = corners.len();
    (0..n)
        .map(|k| corners[k].cross(corners[(k + 1) % n]))
        .sum::<glam::DVec3>()
        * 0.5
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
