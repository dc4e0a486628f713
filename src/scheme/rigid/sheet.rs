//! Rigid sheet as a scheme's output, for the schemes whose panels can be flat parts
//! (half-edge: one per face; net: one per flat region): the options, the panels cut
//! back by [`super::cutback`] and held by [`super::bracket`]s, their labels, the report
//! and the refusal of a thickness the model cannot take.

use glam::DVec3;

use super::bracket::{bracket_panel, clear_brackets, slotted_facets, BracketSizes, Slot};
use super::cutback::{rigid_panels, thickest, RigidError};
use crate::mesh::{FaceId, Mesh};
use crate::option_default::OptionDefault;
use crate::panel::{Name, Panel, Panels, Source};
use crate::record::{round4, Params};
use crate::scheme::kit::labels::outline_labels;
use crate::scheme::kit::thickness::{thickness, thickness_default};
use crate::scheme::{PanelOptions, SchemeError, SchemeOutput};
use crate::units::fmt_num;

/// Connector kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Connectors {
    /// A glue or pin tab on one of the two panels.
    Tab,
    /// Rigid sheet only: a flat bracket inside the model square to each edge, held in
    /// slots through both panels.
    Bracket,
    /// Nothing: panels meet edge to edge.
    None,
}

/// `--connectors` as `--help` states its default.
const CONNECTORS_WORDS: &str = "tab, or bracket in rigid sheet (--thickness above zero)";
/// `--slot-clearance`.
const SLOT_CLEARANCE: &str = "0.1mm";

/// The rigid sheet options (half-edge, net), as given.
#[derive(Clone, Debug, Default, clap::Args)]
pub(in crate::scheme) struct RigidArgs {
    /// Connectors on interior edges: tab, bracket (rigid sheet) or none.
    #[arg(long, value_name = "KIND")]
    connectors: Option<Connectors>,

    /// Material thickness, with a unit: above zero the panels are rigid sheet, each
    /// cut back from its edges and corners so that no two pass through each other.
    #[arg(long, value_name = "LENGTH")]
    thickness: Option<String>,

    /// Play of a bracket's tab in its slot, with a unit: the slot is the thickness plus
    /// this wide (and the tab's length plus this long).
    #[arg(long, value_name = "LENGTH")]
    slot_clearance: Option<String>,
}

/// The defaults of the rigid sheet options, for the `options()` of the schemes that
/// take them.
pub(in crate::scheme) fn rigid_defaults() -> [OptionDefault; 3] {
    [
        OptionDefault::words("connectors", CONNECTORS_WORDS),
        thickness_default(),
        OptionDefault::value("slot-clearance", SLOT_CLEARANCE),
    ]
}

/// The rigid sheet options, resolved (lengths in mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidSheet {
    /// Material thickness (mm); above zero the panels are rigid.
    pub thickness: f64,
    /// What joins the panels.
    pub connectors: Connectors,
    /// Brackets between rigid panels, if wanted.
    pub brackets: Option<BracketSizes>,
}

impl RigidArgs {
    /// The options, checked: tabs only in card, brackets only in rigid sheet.
    pub(in crate::scheme) fn resolve(&self, panel: &PanelOptions) -> Result<RigidSheet, String> {
        let thickness = thickness("thickness", self.thickness.as_deref(), "0mm", panel)?;
        let connectors = match (self.connectors, thickness > 0.0) {
            (Some(Connectors::Tab), true) => {
                return Err("--connectors tab: tabs cannot fold in rigid sheet (--thickness above zero); give --connectors bracket or none".to_string())
            }
            (Some(Connectors::Bracket), false) => {
                return Err("--connectors bracket: brackets hold rigid panels; give the material's --thickness (3mm plywood: --thickness 3mm), or --connectors tab".to_string())
            }
            (Some(kind), _) => kind,
            (None, true) => Connectors::Bracket,
            (None, false) => Connectors::Tab,
        };
        let clearance =
            crate::units::parse_length(self.slot_clearance.as_deref().unwrap_or(SLOT_CLEARANCE))
                .map_err(|e| format!("--slot-clearance: {e}"))?;
        if !(0.0..10.0).contains(&clearance) {
            return Err(format!("--slot-clearance: {clearance} mm must be at least 0 and below 10 mm (a tab's play in its slot)"));
        }
        if thickness > 0.0 && panel.face_scale != 1.0 {
            return Err("--face-scale: rigid panels (--thickness above zero) meet at the faces' edges; leave --face-scale at 1".to_string());
        }
        Ok(RigidSheet {
            thickness,
            connectors,
            brackets: (connectors == Connectors::Bracket).then_some(BracketSizes {
                thickness,
                clearance,
            }),
        })
    }
}

impl RigidSheet {
    /// Card: no thickness, tabs.
    pub const CARD: RigidSheet = RigidSheet {
        thickness: 0.0,
        connectors: Connectors::Tab,
        brackets: None,
    };

    /// `--connectors` as the manifest records it.
    pub(in crate::scheme) fn connectors_name(&self) -> &'static str {
        match self.connectors {
            Connectors::Tab => "tab",
            Connectors::Bracket => "bracket",
            Connectors::None => "none",
        }
    }

    /// The thickness and, with brackets, the slot clearance, as the manifest records
    /// them.
    pub(in crate::scheme) fn sheet_params(&self, params: &mut Params) {
        params.push("thickness", round4(self.thickness));
        if let Some(sizes) = self.brackets {
            params.push("slot_clearance", round4(sizes.clearance));
        }
    }
}

/// What the panels of a rigid build's faces are called and where their ids go.
pub(in crate::scheme) struct PanelNames {
    /// Each face's panel.
    pub sources: Vec<Source>,
    /// Where each face's panel id goes (a point inside the face), or `None` for the
    /// middle of its cut-back outline's corners.
    pub anchors: Vec<Option<DVec3>>,
    /// Each edge's number in the user's model (brackets and notes name it).
    pub edge_numbers: Vec<u32>,
    /// What a panel is called in messages ("face", "island").
    pub noun: &'static str,
}

impl PanelNames {
    /// A panel per face, `F<f>` at its centre; edges as they are.
    pub(in crate::scheme) fn of_faces(mesh: &Mesh) -> PanelNames {
        PanelNames {
            sources: mesh.faces().map(|f| Source::face(f.0)).collect(),
            anchors: vec![None; mesh.face_count()],
            edge_numbers: mesh.edges().map(|e| e.0).collect(),
            noun: "face",
        }
    }

    fn id(&self, f: FaceId) -> Name {
        self.sources[f.index()].id
    }
}

/// The panels of `mesh`'s faces in rigid sheet, kept inside `surface` (the model's
/// own faces): each face's outline cut back so that no two panels pass through each
/// other, meeting edge to edge, with brackets if asked.
pub(in crate::scheme) fn rigid_output(
    mesh: &Mesh,
    surface: &Mesh,
    sheet: &RigidSheet,
    panel: &PanelOptions,
    names: &PanelNames,
) -> Result<SchemeOutput, SchemeError> {
    let t = sheet.thickness;
    let rigid = rigid_panels(mesh, surface, t)
        .map_err(|e| too_thick(mesh, surface, t, panel.scale, &e, names))?;
    let (brackets, bare) = match sheet.brackets {
        Some(sizes) => clear_brackets(mesh, &rigid.outlines, sizes),
        None => (Vec::new(), Vec::new()),
    };
    let mut slots: Vec<Vec<Slot>> = vec![Vec::new(); mesh.face_count()];
    for slot in brackets.iter().flat_map(|b| b.slots) {
        if let Some(f) = mesh.face(slot.side) {
            slots[f.0 as usize].push(slot);
        }
    }
    let mut panels = Panels::build(mesh.face_count(), |f| {
        let outline = &rigid.outlines[f];
        let partners = outline
            .along
            .iter()
            .enumerate()
            .filter_map(|(k, h)| Some((k, names.id(mesh.face((*h)?.twin())?))));
        let middle = || outline.points.iter().copied().sum::<DVec3>() / outline.points.len() as f64;
        let labels = outline_labels(
            names.sources[f].id,
            names.anchors[f].unwrap_or_else(middle),
            &outline.points,
            partners,
            panel.label_height,
        );
        let (vertices, facets) = slotted_facets(mesh, outline, &slots[f]);
        Panel::new(names.sources[f], vertices, facets, Vec::new(), labels)
    });
    for bracket in &brackets {
        let edge = names.edge_numbers[bracket.edge.index()];
        let id = |f: FaceId| names.id(f);
        panels.push(bracket_panel(bracket, panel.label_height, edge, &id).view());
    }
    let widest_corner = rigid.vertices_cut.iter().map(|c| c.1).fold(0.0, f64::max);
    let mut report = vec![format!(
        "rigid panels {} mm thick: {} edges cut back (up to {} mm), corners cut back at {} vertices (up to {} mm from the vertex)",
        fmt_num(t),
        rigid.edges_cut,
        fmt_num(rigid.widest_edge_cut),
        rigid.vertices_cut.len(),
        fmt_num(widest_corner)
    )];
    let mut notes = Vec::new();
    if let Some(sizes) = sheet.brackets {
        report.push(format!(
            "brackets: {} (ids B<edge>.<n>, the angle between the arms engraved), slots {} mm wide",
            brackets.len(),
            fmt_num(t + sizes.clearance)
        ));
        if !bare.is_empty() {
            let named: Vec<String> = bare
                .iter()
                .take(5)
                .map(|e| Name::edge(names.edge_numbers[e.index()]).to_string())
                .collect();
            notes.push(format!(
                "{} interior edges have no bracket ({}{}): their panels have no room for a slot's collar there, or an arm would meet another part; glue them, or build larger",
                bare.len(),
                named.join(", "),
                if bare.len() > 5 { ", …" } else { "" }
            ));
        }
    }
    let mut section = serde_json::Map::new();
    section.insert("thickness".into(), round4(t).into());
    section.insert("edges_cut".into(), rigid.edges_cut.into());
    section.insert(
        "widest_edge_cut".into(),
        round4(rigid.widest_edge_cut).into(),
    );
    section.insert("vertices_cut".into(), rigid.vertices_cut.len().into());
    section.insert("widest_vertex_cut".into(), round4(widest_corner).into());
    if sheet.brackets.is_some() {
        section.insert("brackets".into(), brackets.len().into());
        section.insert("edges_without_bracket".into(), bare.len().into());
    }
    let mut manifest = Params::default();
    manifest.push("rigid", serde_json::Value::Object(section));
    Ok(SchemeOutput {
        panels,
        connections: brackets.len(),
        notes,
        report,
        manifest,
        thickness: t,
        ..SchemeOutput::default()
    })
}

/// The refusal of a thickness the model cannot take at its size, naming the thickness
/// that fits and the size that takes this one.
fn too_thick(
    mesh: &Mesh,
    surface: &Mesh,
    thickness: f64,
    scale: f64,
    error: &RigidError,
    names: &PanelNames,
) -> SchemeError {
    let what = match error {
        RigidError::NoRoom { face } => format!(
            "{} {} has no panel left once cut back from its edges and corners",
            names.noun,
            names.id(*face)
        ),
        RigidError::SticksOut { face, depth } => format!(
            "the panel of {} would stick out of the model by {} mm",
            names.id(*face),
            fmt_num(*depth)
        ),
        RigidError::Overlap { faces, depth } => format!(
            "the panels of {} and {} would pass {} mm into each other",
            names.id(faces[0]),
            names.id(faces[1]),
            fmt_num(*depth)
        ),
    };
    let fits = thickest(mesh, surface, thickness);
    if fits < 1e-3 * thickness {
        // Insets and cuts grow with the thickness: what fails at every thickness is
        // the shape itself.
        return SchemeError::Options(format!(
            "--thickness {}mm: {what}, and would at any thickness (the faces meet too sharply there for square-cut panels); a simpler model (--target-edges) or another scheme may build",
            fmt_num(thickness)
        ));
    }
    // Scaling the model up by k takes k times the thickness (`--size` comes before
    // `--scale`).
    let size = mesh.longest_side() * thickness / fits / scale;
    SchemeError::Options(format!(
        "--thickness {}mm is too thick for this model at this size: {what}; --thickness {}mm fits, or --size {}mm takes it",
        fmt_num(thickness),
        fmt_num((fits * 1e3).floor() / 1e3),
        (size * 1.001).ceil()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::cube;

    /// Options every scheme takes, at `face_scale`, on no sheet.
    fn panel(face_scale: f64) -> PanelOptions {
        PanelOptions {
            face_scale,
            holes: 0,
            hole_diameter: 3.0,
            hole_margin: 1.0,
            label_height: 3.0,
            panel_limit: None,
            scale: 1.0,
        }
    }

    fn args(connectors: Option<Connectors>, thickness: &str) -> RigidArgs {
        RigidArgs {
            connectors,
            thickness: Some(thickness.to_string()),
            slot_clearance: None,
        }
    }

    #[test]
    fn card_takes_tabs_and_sheet_takes_brackets() {
        assert_eq!(
            RigidArgs::default().resolve(&panel(0.8)),
            Ok(RigidSheet::CARD)
        );
        let sheet = args(None, "3mm").resolve(&panel(1.0)).unwrap();
        assert_eq!(sheet.connectors, Connectors::Bracket);
        assert_eq!(
            sheet.brackets,
            Some(BracketSizes {
                thickness: 3.0,
                clearance: 0.1
            })
        );
        let bare = args(Some(Connectors::None), "3mm").resolve(&panel(1.0));
        assert_eq!(bare.map(|s| s.brackets), Ok(None));
    }

    #[test]
    fn mismatched_options_name_their_fix() {
        let refused = |a: RigidArgs, face_scale: f64| a.resolve(&panel(face_scale)).unwrap_err();
        assert!(refused(args(Some(Connectors::Tab), "3mm"), 1.0)
            .starts_with("--connectors tab: tabs cannot fold in rigid sheet"));
        assert!(
            refused(args(Some(Connectors::Bracket), "0mm"), 1.0).starts_with(
                "--connectors bracket: brackets hold rigid panels; give the material's --thickness"
            )
        );
        assert!(refused(args(None, "3mm"), 0.8).starts_with("--face-scale: rigid panels"));
        let loose = RigidArgs {
            slot_clearance: Some("10mm".to_string()),
            ..args(None, "3mm")
        };
        assert!(refused(loose, 1.0).starts_with("--slot-clearance: 10 mm must be"));
    }

    /// A 200 mm cube in 3 mm sheet, with brackets.
    fn cube_in_sheet(side: f64, thickness: f64) -> Result<SchemeOutput, SchemeError> {
        let mesh = cube(side);
        let sheet = args(None, &format!("{thickness}mm"))
            .resolve(&panel(1.0))
            .unwrap();
        rigid_output(
            &mesh,
            &mesh,
            &sheet,
            &panel(1.0),
            &PanelNames::of_faces(&mesh),
        )
    }

    #[test]
    fn a_cube_is_six_panels_held_by_a_bracket_on_every_edge() {
        let output = cube_in_sheet(200.0, 3.0).unwrap();
        let ids: Vec<String> = output
            .panels
            .iter()
            .map(|p| p.source.id.to_string())
            .collect();
        let faces = ids.iter().filter(|id| id.starts_with('F')).count();
        let brackets = ids.iter().filter(|id| id.starts_with('B')).count();
        assert_eq!((faces, brackets), (6, 12), "{ids:?}");
        assert_eq!(output.connections, 12);
        assert_eq!(output.thickness, 3.0);
        let manifest = serde_json::to_value(&output.manifest).unwrap();
        let rigid = &manifest["rigid"];
        assert_eq!(rigid["edges_cut"], 12);
        // At a right angle one panel keeps the edge and the other stops t short.
        assert_eq!(rigid["widest_edge_cut"], 3.0);
        assert_eq!(rigid["brackets"], 12);
        assert_eq!(rigid["edges_without_bracket"], 0);
        assert!(output.notes.is_empty(), "{:?}", output.notes);
    }

    #[test]
    fn too_thick_names_a_thickness_and_a_size_that_build() {
        let Err(SchemeError::Options(message)) = cube_in_sheet(20.0, 12.0) else {
            panic!("12 mm sheet on a 20 mm cube is refused");
        };
        assert!(
            message.starts_with("--thickness 12mm is too thick for this model at this size"),
            "{message}"
        );
        let number_after = |key: &str| -> f64 {
            let rest = &message[message.find(key).expect(key) + key.len()..];
            let end = rest.find("mm").expect("a length in mm");
            rest[..end].parse().expect("a number")
        };
        let fits = number_after("; --thickness ");
        let size = number_after("--size ");
        assert!(fits > 0.0 && fits < 12.0, "{message}");
        assert!(
            cube_in_sheet(20.0, fits).is_ok(),
            "the advised {fits} mm builds"
        );
        // The cube's side is its longest side, so the advised size is the side at which
        // 12 mm takes: it builds, and is at least 20 mm.
        assert!(size > 20.0, "{message}");
        assert!(
            cube_in_sheet(size, 12.0).is_ok(),
            "the advised size {size} mm builds"
        );
    }
}
