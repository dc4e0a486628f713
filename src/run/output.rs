//! Stage 6 of a job, export: every sheet drawn in every format, the assembled model, the
//! pages of the assembly map, the preview page and the manifest, as the output
//! folder's files.

use rayon::prelude::*;

use super::manifest::build_manifest;
use super::stages::{Flat, Nested, Prepared};
use crate::config::Job;
use crate::error::{Error, Result};
use crate::export::folder::MANIFEST;
use crate::export::manifest::{self, round4, Manifest};
use crate::export::{draw_sheet, obj::assembled_obj, Lengths, PathOrder};
use crate::nest::Layout;
use crate::panel::{FlatPanelRef, FlatPanels};
use crate::scheme::SchemeOutput;

/// One sheet's files, path lengths and manifest entry.
struct DrawnSheet {
    files: Vec<(String, Vec<u8>)>,
    lengths: Lengths,
    /// Travel with the paths as placed, for the travel the order saves.
    travel_as_placed: f64,
    entry: manifest::SheetEntry,
}

/// The files of a run and its manifest.
pub struct Exported {
    /// Name and bytes of every file, the manifest last.
    pub files: Vec<(String, Vec<u8>)>,
    /// The manifest (also the last file).
    pub manifest: Manifest,
}

/// Stage 6, export: draws every sheet in every format, telling `done` the share of the
/// sheets drawn as each one is, and builds the manifest: the output folder's files,
/// which [`run_observed`](super::run_observed) writes.
pub fn export(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    flat: &Flat,
    nested: &Nested,
    warnings: Vec<String>,
    done: &(dyn Fn(f64) + Sync),
) -> Result<Exported> {
    let drawn_sheets = std::sync::atomic::AtomicUsize::new(0);
    let layout = &nested.layout;
    let panels = &flat.panels;
    let name = job
        .model_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    let digits = layout.sheets.to_string().len().max(2);
    // Sheets are independent: drawn in parallel, collected in sheet order.
    let drawn: Vec<DrawnSheet> = (0..layout.sheets)
        .into_par_iter()
        .map(|index| {
            let stem = format!("{name}-{:0digits$}", index + 1);
            let sheet = draw_one_sheet(job, layout, panels, index, &stem);
            let count = drawn_sheets.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            done(count as f64 / layout.sheets as f64);
            sheet
        })
        .collect();
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut lengths = Lengths::default();
    let mut travel_as_placed = 0.0;
    let mut sheet_entries = Vec::new();
    for sheet in drawn {
        files.extend(sheet.files);
        // Summed in sheet order, so the totals do not depend on the thread count.
        lengths.add(&sheet.lengths);
        travel_as_placed += sheet.travel_as_placed;
        sheet_entries.push(sheet.entry);
    }
    let laser = manifest::Laser {
        speeds: manifest::Speeds {
            cut: job.speeds.cut,
            score: job.speeds.score,
            engrave: job.speeds.engrave,
            travel: job.speeds.travel,
        },
        time_s: round4(job.speeds.seconds(&lengths)),
        travel_as_placed: round4(travel_as_placed),
    };
    let mut manifest = build_manifest(
        job,
        prepared,
        output,
        flat,
        nested,
        (lengths, laser),
        sheet_entries,
    );
    let map = model_files(job, prepared, output, layout, &name, &mut files);
    manifest.warnings = warnings;
    if job.preview {
        let page = preview(job, layout, panels, &name, &manifest, &map);
        files.push((format!("{name}.html"), page.into_bytes()));
    }
    manifest.files = files
        .iter()
        .map(|(n, _)| n.clone())
        .chain([MANIFEST.to_string()])
        .collect();
    let json = serde_json::to_string_pretty(&manifest)
        .map_err(|e| Error::internal("writing the manifest", e))?;
    files.push((MANIFEST.into(), (json + "\n").into_bytes()));
    Ok(Exported { files, manifest })
}

/// The assembled model and the pages of the assembly map, added to `files`; returns
/// the map's pages (none with `--no-map`).
fn model_files(
    job: &Job,
    prepared: &Prepared,
    output: &SchemeOutput,
    layout: &Layout,
    name: &str,
    files: &mut Vec<(String, Vec<u8>)>,
) -> Vec<String> {
    // Where each panel sits on the model: for the map, and for the assembled model of
    // a scheme that builds on a surface of its own (its pieces there, without tabs).
    let surface = (job.map || output.surface.is_some()).then(|| {
        crate::panel::surface::panel_surface(
            output
                .surface
                .as_ref()
                .unwrap_or(&prepared.scheme_mesh.mesh),
            &output.panels,
            &output.face_groups,
        )
    });
    let assembled = match (&output.surface, &surface) {
        (Some(_), Some(surface)) => crate::export::obj::surface_obj(&output.panels, surface),
        _ if output.thickness > 0.0 => {
            crate::export::obj::solid_obj(&output.panels, output.thickness)
        }
        _ => assembled_obj(&output.panels),
    };
    files.push((format!("{name}-assembled.obj"), assembled.into_bytes()));
    let map = surface.as_ref().filter(|_| job.map).map(|surface| {
        crate::export::map::assembly_map(&crate::export::map::MapInput {
            surface,
            panels: &output.panels,
            layout,
            name,
        })
    });
    let map = map.unwrap_or_default();
    for (k, page) in map.iter().enumerate() {
        files.push((map_file(name, k), page.clone().into_bytes()));
    }
    map
}

/// The file of page `k` (from 0) of the assembly map: `NAME-map.svg`, then
/// `NAME-map-2.svg`…
fn map_file(name: &str, k: usize) -> String {
    match k {
        0 => format!("{name}-map.svg"),
        _ => format!("{name}-map-{}.svg", k + 1),
    }
}

/// The preview page ([`crate::export::preview`]): every sheet drawn again with strokes
/// wide enough to see, beside the map and the manifest's figures.
fn preview(
    job: &Job,
    layout: &Layout,
    panels: &FlatPanels,
    name: &str,
    manifest: &Manifest,
    map: &[String],
) -> String {
    let mut style = job.style.clone();
    let stroke = crate::export::preview::preview_stroke(layout.sheet.width);
    for layer in style.layers.0.iter_mut() {
        layer.stroke_width = layer.stroke_width.max(stroke);
    }
    let sheets: Vec<String> = (0..layout.sheets)
        .into_par_iter()
        .map(|index| {
            let svg = crate::export::Format::Svg.write_sheet(layout, index, panels, &style);
            String::from_utf8_lossy(&svg).into_owned()
        })
        .collect();
    crate::export::preview::preview_page(&crate::export::preview::PreviewInput {
        name,
        manifest,
        sheets: &sheets,
        map,
    })
}

/// Sheet `index` of `layout` in every format of the job, its files named `stem`.ext,
/// with its path lengths (nearest first, and as placed for the travel) and its
/// manifest entry.
fn draw_one_sheet(
    job: &Job,
    layout: &Layout,
    panels: &FlatPanels,
    index: usize,
    stem: &str,
) -> DrawnSheet {
    let sheet = layout.sheet;
    let sheet_files: Vec<(String, Vec<u8>)> = job
        .formats
        .iter()
        .map(|format| {
            (
                format!("{stem}.{}", format.extension()),
                format.write_sheet(layout, index, panels, &job.style),
            )
        })
        .collect();
    let mut lengths = Lengths::default();
    draw_sheet(
        layout,
        index,
        panels,
        false,
        PathOrder::Shortest,
        &mut lengths,
    );
    let mut as_placed = Lengths::default();
    draw_sheet(
        layout,
        index,
        panels,
        false,
        PathOrder::AsPlaced,
        &mut as_placed,
    );
    let on_sheet: Vec<FlatPanelRef> = layout
        .placements
        .iter()
        .filter(|p| p.sheet == index)
        .map(|p| panels.get(p.part))
        .collect();
    let area: f64 = on_sheet.iter().map(|p| p.area).sum();
    let entry = manifest::SheetEntry {
        sheet: index + 1,
        files: sheet_files.iter().map(|(n, _)| n.clone()).collect(),
        panels: on_sheet.len(),
        fill: round4(area / (sheet.width * sheet.height)),
        lengths: lengths.rounded(),
        time_s: round4(job.speeds.seconds(&lengths)),
    };
    DrawnSheet {
        files: sheet_files,
        lengths,
        travel_as_placed: as_placed.travel,
        entry,
    }
}
