//! `manifest.json`: the machine-readable record of a run (SPEC.md §5). Only facts
//! that depend on the input and the options: no times, dates, hosts or absolute paths
//! the user did not give. Lengths in millimetres, rounded to 4 decimals.

use serde::Serialize;

use crate::nest::Layout;
use crate::panel::{Covers, FaceGroup, FlatPanels, Source};
use crate::record::Params;

pub use crate::record::round4;

/// Rounds to the nanometre: developability errors of exact panels are float noise
/// (1e-14 mm) that would change with the last bit of a sine; real errors stay visible.
pub fn round_nm(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// The tool.
#[derive(Clone, Debug, Serialize)]
pub struct Tool {
    /// "unfold".
    pub name: &'static str,
    /// Crate version.
    pub version: &'static str,
}

/// The input model's facts (after preparation).
#[derive(Clone, Debug, Serialize)]
pub struct Input {
    /// The model path as given.
    pub path: String,
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Faces.
    pub faces: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// Connected components.
    pub components: usize,
    /// Genus (sum over components).
    pub genus: i64,
    /// Faces split into triangles before building panels, by reason.
    pub faces_split: FacesSplit,
}

/// Faces split before building panels.
#[derive(Clone, Debug, Serialize)]
pub struct FacesSplit {
    /// Not planar within the tolerance.
    pub non_planar: usize,
    /// Not star-shaped from their centre.
    pub not_star_shaped: usize,
}

/// Scheme name and parameters.
#[derive(Clone, Debug, Serialize)]
pub struct Scheme {
    /// Scheme name.
    pub name: String,
    /// Parameters as used (lengths in mm): the options every scheme takes, the
    /// scheme's own, and the scale.
    pub params: Params,
}

/// The sheet.
#[derive(Clone, Debug, Serialize)]
pub struct Sheet {
    /// As given ("18x24in").
    pub name: String,
    /// Width (mm).
    pub width: f64,
    /// Height (mm).
    pub height: f64,
    /// Margin (mm).
    pub margin: f64,
    /// Spacing between parts (mm).
    pub spacing: f64,
    /// Kerf compensation applied (mm): 0 = nominal geometry.
    pub kerf: f64,
}

/// The layout search and what the baseline would have needed.
#[derive(Clone, Debug, Serialize)]
pub struct Nesting {
    /// "true-shape" or "shelf" (what produced the sheets).
    pub nester: &'static str,
    /// Search effort.
    pub effort: u32,
    /// Search seed.
    pub seed: u64,
    /// Rotation steps per turn.
    pub rotations: u32,
    /// Mirrored placements allowed.
    pub mirror: bool,
    /// Wall-clock cap in seconds, if any.
    pub time_limit: Option<f64>,
    /// Sheets the shelf baseline needs for the same panels.
    pub shelf_sheets: usize,
    /// The true-shape search's sheets after its construction, its moves and its
    /// squeeze; absent when it did not run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub search_sheets: Option<crate::nest::true_shape::PhaseSheets>,
}

/// Counts.
#[derive(Clone, Debug, Serialize)]
pub struct Counts {
    /// Panels.
    pub panels: usize,
    /// Sheets.
    pub sheets: usize,
    /// ceil(total panel area / usable sheet area).
    pub sheets_lower_bound: usize,
    /// ceil(total area of the outlines grown by half the spacing / usable sheet area
    /// grown by half the spacing): the lower bound that counts the spacing.
    pub sheets_spacing_bound: usize,
    /// Holes in the files.
    pub holes: usize,
    /// Connections between panels.
    pub connections: usize,
    /// Connections by the number of fastener holes each has ("0", "1", "2", "4").
    pub connections_by_holes: std::collections::BTreeMap<String, usize>,
    /// Fasteners needed: one per pair of holes (a hole through both panels).
    pub fasteners: usize,
    /// Score lines that fold as mountains, seen from the outside of the model.
    pub folds_mountain: usize,
    /// Score lines that fold as valleys, seen from the outside of the model.
    pub folds_valley: usize,
    /// Labels left out because no legible size fits (all kinds).
    pub labels_left_out: usize,
    /// Of those, panel ids.
    pub panel_ids_left_out: usize,
    /// Of those, partner ids at connections.
    pub partner_ids_left_out: usize,
}

/// The laser time estimate.
#[derive(Clone, Debug, Serialize)]
pub struct Laser {
    /// Speeds used (mm/s).
    pub speeds: Speeds,
    /// Estimated time of every sheet together (seconds).
    pub time_s: f64,
    /// Travel of every sheet with the paths part by part as placed, for comparison
    /// with `lengths.travel` (mm).
    pub travel_as_placed: f64,
}

/// Laser speeds (mm/s).
#[derive(Clone, Debug, Serialize)]
pub struct Speeds {
    /// Cut.
    pub cut: f64,
    /// Score (both fold kinds).
    pub score: f64,
    /// Engrave.
    pub engrave: f64,
    /// Travel, beam off.
    pub travel: f64,
}

/// One output sheet.
#[derive(Clone, Debug, Serialize)]
pub struct SheetEntry {
    /// 1-based sheet number.
    pub sheet: usize,
    /// Its files, one per output format (`NAME-01.svg`, `NAME-01.dxf`).
    pub files: Vec<String>,
    /// Panels on it.
    pub panels: usize,
    /// Panel area / sheet area.
    pub fill: f64,
    /// Its laser path lengths, rounded.
    pub lengths: super::Lengths,
    /// Its estimated laser time (seconds).
    pub time_s: f64,
}

/// Where a panel came from (`{"face": 12, "input_face": 12}`), written by
/// [`panel_source`].
pub type PanelSource = Params;

/// One panel.
#[derive(Clone, Debug, Serialize)]
pub struct PanelEntry {
    /// Printed id.
    pub id: String,
    /// 1-based sheet number.
    pub sheet: usize,
    /// Area (mm²).
    pub area: f64,
    /// Provenance.
    pub source: PanelSource,
    /// Translation on the sheet (mm, origin lower-left, y up).
    pub x: f64,
    /// Translation on the sheet.
    pub y: f64,
    /// Rotation (degrees counter-clockwise).
    pub rotation_deg: f64,
    /// Mirrored (cut face down; only with --mirror).
    pub mirrored: bool,
    /// Largest change of a facet edge length when unrolled (mm).
    pub developability_error: f64,
}

/// The whole manifest.
#[derive(Clone, Debug, Serialize)]
pub struct Manifest {
    /// Tool.
    pub tool: Tool,
    /// Input facts.
    pub input: Input,
    /// Scheme.
    pub scheme: Scheme,
    /// Always "mm".
    pub units: &'static str,
    /// Sheet.
    pub sheet: Sheet,
    /// Counts.
    pub counts: Counts,
    /// How the sheets were laid out.
    pub nesting: Nesting,
    /// Total panel area (mm²).
    pub panel_area: f64,
    /// panel_area / (sheets × sheet area).
    pub utilization: f64,
    /// Laser path lengths, rounded.
    pub lengths: super::Lengths,
    /// The laser time estimate.
    pub laser: Laser,
    /// Largest developability error of any panel (mm).
    pub max_developability_error: f64,
    /// Warnings about the build's size (a forgotten --size, panels too small for
    /// their labels), each naming its fix.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// What only the scheme makes (the woven scheme's `cycles`).
    #[serde(flatten)]
    pub scheme_sections: Params,
    /// The output sheets.
    pub sheets: Vec<SheetEntry>,
    /// Every file the run wrote into the output folder, this manifest last: a later
    /// run replaces exactly these and keeps any other file.
    pub files: Vec<String>,
    /// Every panel.
    pub panels: Vec<PanelEntry>,
}

/// Every panel's entry: id, sheet, area, source (see [`panel_source`]), placement and
/// developability error, in panel order.
pub fn panel_entries(
    flat: &FlatPanels,
    layout: &Layout,
    input_face: impl Fn(u32) -> Option<u32>,
    face_groups: &[FaceGroup],
) -> Vec<PanelEntry> {
    flat.iter()
        .zip(&layout.placements)
        .map(|(p, placement)| PanelEntry {
            id: p.id().to_string(),
            sheet: placement.sheet + 1,
            area: round4(p.area),
            source: panel_source(p.source, face_groups, &input_face),
            x: round4(placement.translation.x),
            y: round4(placement.translation.y),
            rotation_deg: round4(placement.rotation.to_degrees()),
            mirrored: placement.mirrored,
            developability_error: round_nm(p.developability_error),
        })
        .collect()
}

/// A panel's source for the manifest: its number under its kind's noun (`"edge": 7`),
/// its part's number under the kind's part noun (`"segment": 2`), its layer
/// (`"layer": "inner"`) for a kind that names one, then the mesh
/// elements it covers (`face` and `input_face`, `edge`, or `faces` and `input_faces`:
/// the face in the input file is `null` for one made by splitting or simplification),
/// each field written once: a face panel named after its face gives `"face"` once.
pub fn panel_source(
    source: Source,
    face_groups: &[FaceGroup],
    input_face: impl Fn(u32) -> Option<u32>,
) -> PanelSource {
    let mut fields = Params::default();
    let mut push = |name: &str, value: serde_json::Value| {
        if !fields.0.iter().any(|(n, _)| n == name) {
            fields.push(name, value);
        }
    };
    let id = source.id;
    push(id.kind.noun, id.number.into());
    if id.part > 0 {
        push(id.kind.part_noun, id.part.into());
    }
    if !id.kind.layer.is_empty() {
        push("layer", id.kind.layer.into());
    }
    match source.covers {
        Covers::Face(f) => {
            push("face", f.into());
            push("input_face", input_face(f).into());
        }
        Covers::Edge(e) | Covers::Inside(e) => push("edge", e.into()),
        Covers::Faces(k) => {
            let faces = face_groups
                .get(k as usize)
                .map(|g| g.faces.clone())
                .unwrap_or_default();
            let inputs: Vec<Option<u32>> = faces.iter().map(|&f| input_face(f)).collect();
            push("faces", faces.into());
            push("input_faces", inputs.into());
        }
        Covers::Itself => {}
    }
    fields
}

/// How many connections have 0, 1, 2 … fastener holes: each hole goes through both
/// panels of its connection, so a connection's holes are half the flat holes naming it.
pub fn connections_by_holes(
    flat: &FlatPanels,
    connections: usize,
) -> std::collections::BTreeMap<String, usize> {
    let mut holes_of: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for p in flat.iter() {
        for hole in p.holes {
            *holes_of.entry(hole.connection).or_default() += 1;
        }
    }
    let mut by_holes = std::collections::BTreeMap::new();
    let bare = connections.saturating_sub(holes_of.len());
    if bare > 0 || holes_of.is_empty() {
        by_holes.insert("0".to_string(), bare);
    }
    for count in holes_of.values() {
        *by_holes.entry((count / 2).to_string()).or_default() += 1;
    }
    by_holes
}
