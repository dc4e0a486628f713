//! What the report and the manifest say of a net's islands: their sizes, folds by
//! kind, cuts and tabs.

use super::grow::Islands;
use super::options::IslandOptions;
use crate::mesh::{EdgeId, Mesh};
use crate::panel::FoldKind;
use crate::record::round4;
use crate::units::fmt_path_length;

/// What the report and the manifest say of the islands.
pub struct Summary {
    islands: usize,
    largest: usize,
    median: usize,
    folds: [usize; 3],
    fold_length: f64,
    cuts: usize,
    cut_length: f64,
    tabs: usize,
    shortened: usize,
}

impl Summary {
    pub(super) fn of(
        mesh: &Mesh,
        islands: &Islands,
        members: &[Vec<u32>],
        cuts: &[EdgeId],
        tabs: usize,
        shortened: usize,
        options: &IslandOptions,
    ) -> Summary {
        let mut sizes: Vec<usize> = members.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        // Mountain, valley, flat (not scored).
        let mut folds = [0usize; 3];
        let mut fold_length = 0.0;
        for e in mesh.edges().filter(|e| islands.fold[e.index()]) {
            fold_length += mesh.edge_length(e);
            let h = e.half_edge();
            let (Some(f), Some(g)) = (mesh.face(h), mesh.face(h.twin())) else {
                continue;
            };
            let (nf, ng) = (mesh.face_normal(f), mesh.face_normal(g));
            let along = mesh.position(mesh.dest(h)) - mesh.position(mesh.origin(h));
            // Scored as the flatten stage scores them.
            let slot = if nf.angle_between(ng) <= options.flat_fold {
                2
            } else {
                match FoldKind::between(nf, ng, along) {
                    FoldKind::Mountain => 0,
                    FoldKind::Valley => 1,
                }
            };
            folds[slot] += 1;
        }
        Summary {
            islands: members.len(),
            largest: sizes.last().copied().unwrap_or(0),
            median: sizes.get(sizes.len() / 2).copied().unwrap_or(0),
            folds,
            fold_length,
            cuts: cuts.len(),
            cut_length: cuts.iter().map(|&e| mesh.edge_length(e)).sum(),
            tabs,
            shortened,
        }
    }

    /// The report's line, headed `scheme` and calling the islands `islands`.
    pub fn report(&self, scheme: &str, islands: &str) -> Vec<String> {
        vec![format!(
            "{scheme}: {} {islands} (largest {} faces, median {}); folds {} mountain, {} valley, {} too flat to score, {} in all; {} cut edges, {} in all, with {} tabs",
            self.islands,
            self.largest,
            self.median,
            self.folds[0],
            self.folds[1],
            self.folds[2],
            fmt_path_length(self.fold_length),
            self.cuts,
            fmt_path_length(self.cut_length),
            self.tabs
        )]
    }

    /// The manifest's section of the islands, counting them as `islands`.
    pub fn section(&self, islands: &str) -> serde_json::Value {
        let singular = islands.trim_end_matches('s');
        let mut section = serde_json::json!({
                "folds_mountain": self.folds[0],
                "folds_valley": self.folds[1],
                "folds_flat": self.folds[2],
                "fold_length": round4(self.fold_length),
                "cuts": self.cuts,
                "cut_length": round4(self.cut_length),
                "tabs": self.tabs,
                "tabs_shortened": self.shortened,
        });
        section[islands] = self.islands.into();
        section[format!("largest_{singular}_faces")] = self.largest.into();
        section[format!("median_{singular}_faces")] = self.median.into();
        section
    }
}
