//! The strip scheme: the model covered by developable strips within a distance of it,
//! both ways, each strip cut into pieces that fit the sheet, glue tabs on the curves
//! between strips.
//!
//! The strips follow the level curves of a field between two poles of each part of
//! the model, or from its holes' rims (`field_of`); between two neighbouring curves,
//! the band of triangles that bends least (every corner on one of the two curves, so
//! no vertex is inside the band and it unrolls exactly; the dynamic programme of the
//! strip paper, `003`). A band whose strip strays from the model further than `--max-deviation`,
//! measured both ways, is cut across into sectors about as long as the sheet (along
//! the field's rise, from one curve to the other), and each sector is covered from its
//! lower curve up by bands as wide as keep their strips within, so that a sharp part
//! of a ring (an ear) does not narrow the strips round the rest (`strips_ridged`).
//! Where a sector meets one split differently, each point of one on the other's edge
//! becomes a corner of both. The strips are welded into one surface where they share
//! their curves' points; the island engine's islands then grow along each strip's rungs
//! in order, so a piece is a run of its strip, as long as keeps it clear of itself
//! and on the sheet, and every curve between strips (and the rung between two
//! pieces) gets a tab with match numbers.

mod band;
mod conform;
mod cover;
mod distance;
mod field;
mod patch;
mod pieces;
mod sectors;
mod slices;
mod surface;
#[cfg(test)]
mod test_shapes;
mod tolerance;
mod welded;

use glam::DVec3;

use crate::mesh::{HalfedgeId, Mesh};
use crate::option_default::{state_defaults, OptionDefault};
use crate::record::{round4, Params};
use crate::scheme::island::{FlatFoldArgs, IslandOptions, FLAT_FOLD_DEG};
use crate::scheme::kit::tab::{tab_defaults, TabArgs, TAB_DEFAULTS};
use crate::scheme::{args_of, Configured, Configuring, OptionValues, PanelOptions, SchemeInfo};
use crate::scheme::{Scheme, SchemeError, SchemeOutput};
use cover::STAYS_OFF;
use field::{closed_part, Closed};
use pieces::clear_pieces;
use surface::Triangles;
use tolerance::{cover_within, simplification_distance, too_simplified, WeldedCover};

pub use welded::STRIP;

/// The default `--max-deviation`: a percentage of the built model's bounding-box
/// diagonal, about what the eye takes for smooth at arm's length.
const MAX_DEVIATION_PERCENT: f64 = 0.5;

/// The strip scheme: developable strips within a distance of the model.
pub struct Strips;

/// The strip scheme's options as given.
#[derive(Clone, Debug, Default, clap::Args)]
struct StripArgs {
    #[command(flatten)]
    tab: TabArgs,

    #[command(flatten)]
    flat_fold: FlatFoldArgs,

    /// Largest distance between the strips and the model as given (before any
    /// simplifying), both ways (strip scheme): a length with a unit, or a percentage of
    /// the built model's bounding-box diagonal.
    #[arg(long, value_name = "LENGTH|P%")]
    max_deviation: Option<String>,
}

/// How far the strips may stray from the model.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Deviation {
    /// A length (mm).
    Length(f64),
    /// A fraction of the built model's bounding-box diagonal.
    Fraction(f64),
}

impl Deviation {
    /// Parses `--max-deviation`: `2mm`, `0.1in` or `0.5%`.
    fn parse(text: &str) -> Result<Deviation, String> {
        let fix = "write a length with a unit (2mm) or a percentage of the model's diagonal (0.5%)";
        let deviation = match text.trim().strip_suffix('%') {
            Some(percent) => percent
                .trim()
                .parse::<f64>()
                .map(|p| Deviation::Fraction(p / 100.0))
                .map_err(|_| format!("--max-deviation: '{text}' is not a percentage; {fix}"))?,
            None => crate::units::parse_length(text)
                .map(Deviation::Length)
                .map_err(|e| format!("--max-deviation: {e}"))?,
        };
        let value = match deviation {
            Deviation::Length(v) | Deviation::Fraction(v) => v,
        };
        if !(value > 0.0 && value.is_finite()) {
            return Err(format!(
                "--max-deviation: '{text}' must be above zero; {fix}"
            ));
        }
        Ok(deviation)
    }

    /// This bound `k` times over.
    fn times(self, k: f64) -> Deviation {
        match self {
            Deviation::Length(mm) => Deviation::Length(k * mm),
            Deviation::Fraction(f) => Deviation::Fraction(k * f),
        }
    }

    /// The distance (mm) for a model of bounding-box diagonal `diagonal` (mm).
    fn length(self, diagonal: f64) -> f64 {
        match self {
            Deviation::Length(mm) => mm,
            Deviation::Fraction(f) => f * diagonal,
        }
    }
}

/// As `--max-deviation` takes it: `2.5mm` or `1%`.
impl std::fmt::Display for Deviation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Deviation::Length(mm) => write!(f, "{}mm", round4(mm)),
            Deviation::Fraction(x) => write!(f, "{}%", round4(100.0 * x)),
        }
    }
}

/// The strip scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
struct StripOptions {
    /// The tabs, the sheet and the folds, as the island engine takes them.
    islands: IslandOptions,
    /// `--max-deviation`.
    max_deviation: Deviation,
}

const INFO: SchemeInfo = SchemeInfo {
    name: "strip",
    about: "developable strips within --max-deviation of the model, cut into pieces that fit the sheet, glue tabs between them",
    defaults: TAB_DEFAULTS,
    // Faces are fanned into triangles from their first corner.
    needs_convex_faces: true,
    overlap_fix: "a smaller --tab-height (shorter tabs)",
};

impl Scheme for Strips {
    fn info(&self) -> &SchemeInfo {
        &INFO
    }

    fn options(&self) -> Vec<clap::Arg> {
        state_defaults(
            args_of::<StripArgs>(),
            &[
                tab_defaults(),
                OptionDefault::value("flat-fold", FLAT_FOLD_DEG),
                OptionDefault::words("max-deviation", "0.5%"),
            ],
        )
    }

    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring {
        let args: StripArgs = values.parse()?;
        if panel.face_scale != 1.0 {
            return Err(format!(
                "--face-scale: the strip scheme keeps its strips whole (1), not {}; leave it out",
                panel.face_scale
            ));
        }
        let max_deviation = match args.max_deviation.as_deref() {
            Some(text) => Deviation::parse(text)?,
            None => Deviation::Fraction(MAX_DEVIATION_PERCENT / 100.0),
        };
        Ok(Box::new(StripOptions {
            islands: IslandOptions {
                panel,
                tab_height: args.tab.height()?,
                max_island_faces: None,
                flat_fold: args.flat_fold.angle()?,
                island_spread: f64::INFINITY,
            },
            max_deviation,
        }))
    }
}

impl Configured for StripOptions {
    fn panel(&self) -> &PanelOptions {
        &self.islands.panel
    }

    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        strip_panels(mesh, self, None)
    }

    fn bounds_distance(&self) -> bool {
        true
    }

    fn build_near(
        &self,
        mesh: &Mesh,
        unsimplified: &[[DVec3; 3]],
    ) -> Result<SchemeOutput, SchemeError> {
        strip_panels(mesh, self, Some(unsimplified))
    }

    fn params(&self) -> Params {
        let mut params = Params::default();
        params.push("tab_height", round4(self.islands.tab_height));
        params.push("flat_fold_deg", round4(self.islands.flat_fold.to_degrees()));
        match self.max_deviation {
            Deviation::Length(mm) => params.push("max_deviation", round4(mm)),
            fraction => params.push("max_deviation", fraction.to_string()),
        }
        params
    }

    fn least_scored_fold(&self) -> f64 {
        self.islands.flat_fold
    }

    fn panels_follow_faces(&self) -> bool {
        // Strips follow the field's levels, their width set by --max-deviation.
        false
    }

    fn larger_panels_fix(&self) -> &'static str {
        "a larger --max-deviation (wider strips) or a larger --size"
    }

    fn larger_panels(
        &self,
        mesh: &Mesh,
        unsimplified: Option<&[[DVec3; 3]]>,
        fits: &dyn Fn(&SchemeOutput) -> bool,
    ) -> Option<String> {
        // Strips widen about as the root of the bound: doubling it three times makes
        // them nearly three times wider.
        [2.0, 4.0, 8.0].into_iter().find_map(|k| {
            let wider = StripOptions {
                max_deviation: self.max_deviation.times(k),
                ..self.clone()
            };
            let output = strip_panels(mesh, &wider, unsimplified).ok()?;
            fits(&output).then(|| format!("--max-deviation {}", wider.max_deviation))
        })
    }
}

/// The strips of `mesh` within the bound, welded into one surface and cut into pieces
/// with tabs. When `mesh` was simplified from `unsimplified`, the bound holds to that.
fn strip_panels(
    mesh: &Mesh,
    options: &StripOptions,
    unsimplified: Option<&[[DVec3; 3]]>,
) -> Result<SchemeOutput, SchemeError> {
    let (lo, hi) = crate::mesh::geometry::bounding_box(mesh.positions().iter().copied());
    let bound = options.max_deviation.length((hi - lo).length());
    let surface = Triangles::from_mesh(mesh);
    let limit = options.islands.panel.panel_limit;
    // Bands are cut across into sectors about as long as the sheet's shorter side: an
    // unrolled sector is an arc, and shorter arcs nest closer (docs/benchmarks.md).
    let sector_length = limit.map_or(f64::INFINITY, |l| l.width.min(l.height));
    // A strip longer than the sheet's longer side is cut into equal pieces no longer.
    let piece_length = limit.map_or(f64::INFINITY, |l| l.width.max(l.height));
    let cover_within =
        |closed: Closed| cover_within(&surface, closed, bound, unsimplified, sector_length);
    // A harmonic field between two poles stays nearly level along a dead end (a
    // horse's legs), too flat to split into bands; the distance from one pole rises
    // along every branch. The first failure is the one told.
    let covered = match cover_within(Closed::Harmonic) {
        Err(SchemeError::Model(why)) if closed_part(&surface) => {
            cover_within(Closed::Distance).map_err(|_| SchemeError::Model(why))
        }
        other => other,
    };
    // Where no strips cover a simplified mesh, a simplification that strays too far
    // is the cause to name first; a larger bound only where a band strayed (a strip
    // that folds round a coarse corner folds at any bound).
    let (covered, measured) = match (covered, unsimplified) {
        (Err(SchemeError::Model(why)), Some(given)) => {
            let apart = simplification_distance(bound, &surface.soup(), given);
            let refusal = too_simplified(bound, apart, why.contains(STAYS_OFF));
            return Err(refusal.unwrap_or(SchemeError::Model(why)));
        }
        (other, _) => other?,
    };
    let WeldedCover {
        cover,
        welded,
        whole_bands,
        tolerance,
    } = covered;
    // Each curve's tabs on the strip below it: the strip above is glued over them.
    let tab_first = |h: HalfedgeId| {
        let strip = |h: HalfedgeId| welded.mesh.face(h).map(|f| welded.strip_of_face[f.index()]);
        strip(h) <= strip(h.twin())
    };
    let (net, members) = clear_pieces(&welded, &options.islands, piece_length, &tab_first);
    let joined = welded.joined(&members);
    let mut output = net.output;
    let pieces = output.panels.len();
    output.report = vec![match unsimplified {
        None => format!(
            "strip: {} strips in {pieces} pieces, at most {measured:.2} mm from the model both ways as measured (bound {bound:.2} mm); each piece unrolls exactly",
            welded.strips
        ),
        Some(_) => format!(
            "strip: {} strips in {pieces} pieces, at most {measured:.2} mm from the model as given (before simplifying) both ways as measured (bound {bound:.2} mm; within {:.2} mm of the simplified model); each piece unrolls exactly",
            welded.strips, cover.deviation
        ),
    }];
    if tolerance < bound {
        output.notes.push(format!(
            "the strips are kept within {tolerance:.2} mm of the simplified model, not {bound:.2}: the simplification strays from the model too, and the bound holds to the model as given (a larger --target-edges, or none, gives wider strips)"
        ));
    }
    if whole_bands {
        output.report.push(format!(
            "strip: bands run whole round the model, not cut into sectors {sector_length:.0} mm long (strips of neighbouring bands overlapped)"
        ));
    }
    output
        .report
        .extend(net.summary.report("strip pieces", "pieces"));
    let mut section = net.summary.section("pieces");
    section["strips"] = welded.strips.into();
    section["max_deviation"] = round4(bound).into();
    section["measured_deviation"] = round4(measured).into();
    section["joined"] = joined
        .iter()
        .map(|(k, strip, faces)| {
            serde_json::json!({
                "piece": output.panels.get(*k).id().to_string(),
                "strip": strip,
                "faces": faces,
            })
        })
        .collect::<Vec<_>>()
        .into();
    if unsimplified.is_some() {
        section["simplified_bound"] = round4(tolerance).into();
        section["simplified_deviation"] = round4(cover.deviation).into();
    }
    output.manifest.push("strip", section);
    output.surface = Some(welded.mesh);
    Ok(output)
}
