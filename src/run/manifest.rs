//! The manifest of a job (`manifest.json`): what each stage produced, counted and
//! rounded as the manifest records it.

use super::stages::{Flat, Nested, Prepared, SchemeMesh};
use crate::config::Job;
use crate::export::manifest::{self, round4, Manifest};
use crate::export::Lengths;
use crate::mesh::FaceId;
use crate::panel::{FlatPanels, FoldKind};
use crate::scheme::SchemeOutput;

/// Score lines of every panel that fold as `kind`.
fn folds_of(flat: &FlatPanels, kind: FoldKind) -> usize {
    flat.iter()
        .map(|p| p.folds.iter().filter(|f| f.kind == kind).count())
        .sum()
}

pub(super) fn build_manifest(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    flat: &Flat,
    nested: &Nested,
    (lengths, laser): (Lengths, manifest::Laser),
    sheets: Vec<manifest::SheetEntry>,
) -> Manifest {
    let SchemeMesh {
        mesh,
        split,
        mm_per_unit,
        ..
    } = &prepared.scheme_mesh;
    let (topology, layout, labels_left_out) =
        (&prepared.topology, &nested.layout, &flat.labels_left_out);
    let flat = &flat.panels;
    let sheet = &layout.sheet;
    let panel_area: f64 = flat.iter().map(|p| p.area).sum();
    let usable = sheet.usable_width() * sheet.usable_height();
    let lower_bound = (panel_area / usable).ceil() as usize;
    // Faces made by splitting or simplification, or of a scheme's own surface, have no
    // face in the input file.
    let input_face = |f: u32| {
        let source = output
            .surface
            .is_none()
            .then(|| mesh.face_source(FaceId(f)));
        source.filter(|&s| s != u32::MAX)
    };
    let panels = manifest::panel_entries(flat, layout, input_face, &output.face_groups);
    Manifest {
        tool: manifest::Tool {
            name: "unfold",
            version: env!("CARGO_PKG_VERSION"),
        },
        input: manifest::Input {
            path: job.model_path.display().to_string(),
            vertices: topology.vertices,
            edges: topology.edges,
            faces: topology.faces,
            boundary_loops: topology.boundary_loops,
            components: topology.components.len(),
            genus: topology.genus,
            faces_split: manifest::FacesSplit {
                non_planar: split.non_planar.len(),
                not_star_shaped: split.not_star_shaped.len(),
            },
        },
        scheme: manifest::Scheme {
            name: job.scheme.name().to_string(),
            params: {
                let mut params = job.scheme.params();
                params.push("mm_per_model_unit", *mm_per_unit);
                params
            },
        },
        units: "mm",
        sheet: manifest::Sheet {
            name: job.sheet.name.clone(),
            width: round4(sheet.width),
            height: round4(sheet.height),
            margin: round4(sheet.margin),
            spacing: round4(sheet.spacing),
            kerf: round4(job.kerf),
        },
        counts: manifest::Counts {
            panels: flat.len(),
            sheets: layout.sheets,
            sheets_lower_bound: lower_bound,
            sheets_spacing_bound: nested.spacing_bound.max(lower_bound), // both hold: the larger
            holes: flat.iter().map(|p| p.holes.len()).sum(),
            connections: output.connections,
            connections_by_holes: manifest::connections_by_holes(flat, output.connections),
            fasteners: flat.iter().map(|p| p.holes.len()).sum::<usize>() / 2,
            folds_mountain: folds_of(flat, FoldKind::Mountain),
            folds_valley: folds_of(flat, FoldKind::Valley),
            labels_left_out: labels_left_out.total(),
            panel_ids_left_out: labels_left_out.panel,
            partner_ids_left_out: labels_left_out.partner,
        },
        nesting: nested.nesting.clone(),
        panel_area: round4(panel_area),
        utilization: round4(panel_area / (layout.sheets as f64 * sheet.width * sheet.height)),
        lengths: lengths.rounded(),
        laser,
        scheme_sections: output.manifest.clone(),
        max_developability_error: manifest::round_nm(
            flat.iter()
                .map(|p| p.developability_error)
                .fold(0.0, f64::max),
        ),
        sheets,
        warnings: Vec::new(),
        files: Vec::new(),
        panels,
    }
}
