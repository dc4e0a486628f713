//! Labels a builder can read: on the panels of a shared model, the engraved glyphs of
//! two labels never come nearer than the gap between labels, a panel's own id is
//! framed (its frame clear of its text; only a sliver's lone id goes unframed), and labels of one kind on a panel share one
//! height on nearly every panel. The glyph boxes are measured from the strokes the
//! exporters draw, not from the boxes label fitting used.

use crate::common;

use common::build::{inside, options, resolve, segment_distance, shared_models};
use glam::DVec2;
use tempfile::TempDir;
use unfold::font::text_strokes;
use unfold::labels::LABEL_GAP;
use unfold::panel::{FlatLabel, LabelKind};

/// The corners of a label's engraved glyphs (and of its frame, if framed), in the
/// panel's plane: the extent of its strokes in its own reading frame, drawn as the
/// exporters draw them (origin at the lower-left of the text box).
fn glyph_box(label: &FlatLabel) -> [DVec2; 4] {
    let strokes = text_strokes(label.text);
    let h = label.height;
    let d = label.direction;
    let up = d.perp();
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for q in strokes.polylines.iter().flatten() {
        lo = lo.min(*q * h);
        hi = hi.max(*q * h);
    }
    if label.frame > 0.0 {
        let pad = label.frame * h;
        // The frame keeps clear of the text's own strokes.
        assert!(
            lo.min_element() >= -1e-9 && hi.y <= h + 1e-9,
            "{}",
            label.text
        );
        lo = DVec2::new(-pad, -pad);
        hi = DVec2::new(strokes.width * h + pad, h + pad);
    }
    let origin = label.center - 0.5 * strokes.width * h * d - 0.5 * h * up;
    let at = |x: f64, y: f64| origin + x * d + y * up;
    [
        at(lo.x, lo.y),
        at(hi.x, lo.y),
        at(hi.x, hi.y),
        at(lo.x, hi.y),
    ]
}

/// The distance between two convex quadrilaterals (0 when they overlap).
fn box_distance(p: &[DVec2; 4], q: &[DVec2; 4]) -> f64 {
    if inside(p, q[0]) || inside(q, p[0]) {
        return 0.0;
    }
    (0..4)
        .flat_map(|i| (0..4).map(move |j| (i, j)))
        .map(|(i, j)| segment_distance(p[i], p[(i + 1) % 4], q[j], q[(j + 1) % 4]))
        .fold(f64::MAX, f64::min)
}

/// What the labels of one build look like.
#[derive(Debug, Default)]
struct Survey {
    panels: usize,
    labels: usize,
    /// Panel ids drawn without a frame (no room for it, and no other label there).
    unframed_ids: usize,
    /// Panels on which some kind of label comes in more than one height.
    uneven_panels: usize,
    /// The smallest gap between glyph boxes, in cap heights of the taller label.
    smallest_gap: f64,
    /// Panels with a label larger than their own id, by name.
    outgrown_ids: Vec<String>,
}

/// The flat panels with their labels fitted: `model` built through the library's
/// stages at `size`, simplified to `target_edges`. `None` when the scheme cannot build
/// the model at this size (a crossing larger than the sheet).
fn fitted(
    model: &std::path::Path,
    scheme: &str,
    size: &str,
    target_edges: Option<usize>,
) -> Option<unfold::panel::FlatPanels> {
    let tmp = TempDir::new().unwrap();
    let mut o = options(scheme, size, 0, &tmp.path().join("out"));
    o.holes = None;
    o.model.target_edges = target_edges.map(unfold::config::TargetEdges::Count);
    // The woven scheme weaves only a closed mesh.
    o.model.fill_holes = scheme == "woven";
    let job = resolve(o, model);
    let loaded = unfold::run::load(&job).expect("loads");
    let prepared = unfold::run::prepare(&job, loaded).expect("prepares");
    let output = unfold::run::scheme(&job, &prepared).ok()?;
    let flat = unfold::run::flatten(&job, &prepared, &output).expect("flattens");
    Some(flat.panels)
}

/// Builds `model` through the library's stages up to the fitted labels and checks
/// every pair of labels on every panel.
fn survey(
    model: &std::path::Path,
    scheme: &str,
    size: &str,
    target_edges: Option<usize>,
) -> Survey {
    let panels = fitted(model, scheme, size, target_edges).expect("builds");
    let mut s = Survey {
        smallest_gap: f64::MAX,
        ..Survey::default()
    };
    for panel in panels.iter() {
        s.panels += 1;
        s.labels += panel.labels.len();
        let boxes: Vec<[DVec2; 4]> = panel.labels.iter().map(glyph_box).collect();
        for (i, a) in panel.labels.iter().enumerate() {
            if a.kind == LabelKind::Panel {
                assert_eq!(a.text, panel.id(), "a panel's own id");
                if a.frame <= 0.0 {
                    // Only a sliver too small for any frame: then it is the panel's
                    // one label, so it cannot be taken for a partner's.
                    assert_eq!(panel.labels.len(), 1, "{}: unframed beside others", a.text);
                    s.unframed_ids += 1;
                }
            } else {
                assert_eq!(
                    a.frame,
                    0.0,
                    "{}: only the panel's id is framed",
                    panel.id()
                );
            }
            for (j, b) in panel.labels.iter().enumerate().skip(i + 1) {
                let taller = a.height.max(b.height);
                let gap = box_distance(&boxes[i], &boxes[j]) / taller;
                s.smallest_gap = s.smallest_gap.min(gap);
                assert!(
                    gap >= LABEL_GAP * (1.0 - 1e-6),
                    "{}: labels {} and {} are {:.2} cap heights apart",
                    panel.id(),
                    a.text,
                    b.text,
                    gap
                );
            }
        }
        let uneven = LabelKind::ALL.into_iter().any(|kind| {
            let heights = panel
                .labels
                .iter()
                .filter(|l| l.kind == kind)
                .map(|l| l.height);
            let lo = heights.clone().fold(f64::MAX, f64::min);
            let hi = heights.fold(0.0, f64::max);
            hi > lo * (1.0 + 1e-9)
        });
        s.uneven_panels += usize::from(uneven);
        if outgrows_its_id(panel.labels) {
            s.outgrown_ids.push(panel.id().to_string());
        }
    }
    s
}

/// Whether some label is larger than the panel's own id.
fn outgrows_its_id(labels: &[FlatLabel]) -> bool {
    let id = labels
        .iter()
        .filter(|l| l.kind == LabelKind::Panel)
        .map(|l| l.height)
        .fold(f64::INFINITY, f64::min);
    labels.iter().any(|l| l.height > id * (1.0 + 1e-9))
}

fn check(name: &str, s: &Survey, max_uneven_percent: usize) {
    eprintln!("{name}: {s:?}");
    assert!(
        s.outgrown_ids.is_empty(),
        "{name}: panels with a label larger than their own id: {:?}",
        s.outgrown_ids
    );
    assert!(s.labels > 2 * s.panels, "{name}: labels were fitted");
    assert!(
        s.unframed_ids * 100 <= s.panels,
        "{name}: {} of {} panel ids unframed",
        s.unframed_ids,
        s.panels
    );
    assert!(
        s.uneven_panels * 100 <= max_uneven_percent * s.panels,
        "{name}: {} of {} panels have labels of one kind in different heights",
        s.uneven_panels,
        s.panels
    );
}

#[test]
fn labels_of_the_thesis_bunny_keep_apart_and_its_ids_are_framed() {
    let Some(shared) =
        shared_models("labels_of_the_thesis_bunny_keep_apart_and_its_ids_are_framed")
    else {
        return;
    };
    let bunny = shared.join("stanford-bunny.obj");
    let s = survey(&bunny, "quad-edge", "4ft", Some(625));
    check("bunny quad-edge", &s, 5);
}

#[test]
fn labels_of_spot_half_edge_keep_apart_and_its_ids_are_framed() {
    let Some(shared) = shared_models("labels_of_spot_half_edge_keep_apart_and_its_ids_are_framed")
    else {
        return;
    };
    let spot = shared.join("spot.obj");
    // At 2 m spot's triangles hold their ids (at 4 ft a few hundred are too small).
    let s = survey(&spot, "half-edge", "2m", None);
    check("spot half-edge", &s, 5);
}

#[test]
fn no_label_is_larger_than_its_panels_own_id_on_the_first_half_of_the_shared_models() {
    let test = "no_label_is_larger_than_its_panels_own_id_on_the_first_half_of_the_shared_models";
    if let Some(models) = common::build::half_of_the_shared_models(test, false) {
        no_label_is_larger_than_its_panels_own_id(&models);
    }
}

/// The same on the second half of the shared models.
#[test]
fn no_label_is_larger_than_its_panels_own_id_on_the_second_half_of_the_shared_models() {
    let test = "no_label_is_larger_than_its_panels_own_id_on_the_second_half_of_the_shared_models";
    if let Some(models) = common::build::half_of_the_shared_models(test, true) {
        no_label_is_larger_than_its_panels_own_id(&models);
    }
}

/// Every scheme on `models` at 2 ft and 4 ft: no label is larger than its panel's own id.
fn no_label_is_larger_than_its_panels_own_id(models: &[std::path::PathBuf]) {
    let tmp = TempDir::new().unwrap();
    // The README's build: 4 ft at the thesis budget of 625 edges; and 2 ft, where the
    // panels are small and the labels compete for room.
    let mut surveyed = 0;
    for model in models {
        // The woven scheme weaves only a closed mesh.
        let simplified =
            [false, true].map(|fill| common::build::simplified_obj(model, 625, fill, tmp.path()));
        for scheme in ["half-edge", "quad-edge", "winged-edge", "woven", "net"] {
            let simplified = &simplified[usize::from(scheme == "woven")];
            for size in ["2ft", "4ft"] {
                let name = format!("{} {scheme} {size}", model.display());
                let Some(panels) = fitted(simplified, scheme, size, None) else {
                    eprintln!("{name}: not built (larger than the sheet)");
                    continue;
                };
                surveyed += 1;
                let outgrown: Vec<String> = panels
                    .iter()
                    .filter(|p| outgrows_its_id(p.labels))
                    .map(|p| p.id().to_string())
                    .collect();
                eprintln!("{name}: {} panels", panels.len());
                assert!(
                    outgrown.is_empty(),
                    "{name}: panels with a label larger than their own id: {outgrown:?}"
                );
            }
        }
    }
    // Only the cube's woven ribbons are larger than the sheet.
    assert!(
        surveyed + 2 >= 10 * models.len(),
        "{surveyed} builds surveyed"
    );
}
