//! Panel schemes: each takes a read-only mesh (in millimetres) and its options and
//! returns 3D panels with provenance. A scheme knows nothing of sheets or files.
//!
//! A scheme is one file here or in its family's folder (`edge/`, `woven/`): a
//! [`SchemeInfo`] (its name, help, defaults, whether it needs convex faces, the fix
//! for a panel that overlaps itself), a type implementing [`Scheme`] (that info, its
//! own command-line and config options with their defaults and checks) and the
//! [`Configured`] value it resolves to (the build, and what it adds to the manifest
//! and the report). [`SCHEMES`] lists them; everything above this module reaches the
//! schemes only through a [`Registry`]. What several schemes share is in `kit/` or in
//! their family's folder; `rigid/` holds the rigid sheet output of the schemes that
//! take it.

pub mod edge;
pub mod half_edge;
pub mod island;
mod kit;
pub mod net;
pub mod registry;
pub mod rigid;
pub mod strip;
pub mod woven;

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use glam::DVec3;

pub use registry::{Registry, SCHEMES};

use crate::mesh::{FaceId, Mesh};
use crate::panel::{FaceGroup, Name, Panels};
use crate::record::{round4, Params};

/// A panel scheme: what the command line, the config file and the pipeline need of it.
pub trait Scheme: Send + Sync {
    /// Its name, help line and the facts the pipeline reads before a build.
    fn info(&self) -> &SchemeInfo;
    /// Its own options (clap arguments with long names; the config file takes the same
    /// keys). Schemes may share an option by declaring the same argument.
    fn options(&self) -> Vec<clap::Arg> {
        Vec::new()
    }
    /// Checks its own option `values` and fills in their defaults. An error is a usage
    /// message naming the option (`--bridge-scale: ...`).
    fn configure(&self, values: &OptionValues, panel: PanelOptions) -> Configuring;
}

impl dyn Scheme + '_ {
    /// Its name for `--scheme`, as its [`SchemeInfo`] states it.
    pub fn name(&self) -> &'static str {
        self.info().name
    }
}

/// What a scheme is: one constant per scheme, read by `--help`, the defaults table
/// and the checks before a build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchemeInfo {
    /// Its name for `--scheme` (kebab-case).
    pub name: &'static str,
    /// One sentence for `--help`.
    pub about: &'static str,
    /// Its defaults for the options every scheme takes.
    pub defaults: PanelDefaults,
    /// True when its faces must be convex (the rest are split into triangles first).
    pub needs_convex_faces: bool,
    /// What a user changes when one of its panels overlaps itself when unrolled (the
    /// option that makes its connectors smaller, or its pieces shorter).
    pub overlap_fix: &'static str,
}

/// A scheme with its options resolved, or the usage message that refuses them.
pub type Configuring = Result<Box<dyn Configured>, String>;

/// A scheme with its options resolved, ready to build panels.
pub trait Configured: fmt::Debug + Send + Sync {
    /// The options every scheme takes, as resolved.
    fn panel(&self) -> &PanelOptions;
    /// Builds the panels of `mesh` (millimetres, faces as the scheme needs them).
    fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError>;
    /// Refuses, before any size check or simplification trial, a mesh the scheme can
    /// never build at any size or budget (its shape, not its detail), with the error
    /// [`Configured::build`] would give. Accepts every mesh unless the scheme says.
    fn accepts(&self, _mesh: &Mesh) -> Result<(), SchemeError> {
        Ok(())
    }
    /// Its own options as used, for the manifest's `scheme.params` (lengths in mm).
    fn params(&self) -> Params;
    /// The least fold (radians) scored on its panels: flatter hinges are left as they
    /// are. Only exactly flat hinges unless the scheme says otherwise.
    fn least_scored_fold(&self) -> f64 {
        crate::flatten::LEAST_SCORED_FOLD
    }
    /// True when its panels follow the mesh's faces, so that a mesh too detailed for
    /// its size makes panels too small for their ids (checked before the build). A
    /// scheme that shapes its panels itself (the strip scheme) says false.
    fn panels_follow_faces(&self) -> bool {
        true
    }
    /// For a scheme whose panels do not follow the faces: the fix that makes them
    /// large enough for their labels and fasteners, named in the warning when they are
    /// not ("a larger --max-deviation (wider strips) or a larger --size").
    fn larger_panels_fix(&self) -> &'static str {
        "a larger --size"
    }
    /// For a scheme whose panels do not follow the faces: its options that make the
    /// panels of `mesh` large enough for what `fits` asks (their ids, their
    /// fasteners), found by building them as the job does (near `unsimplified`, the
    /// model before simplifying, where it was kept), as the command line writes them
    /// ("--max-deviation 2%"); `None` where none it tries does.
    fn larger_panels(
        &self,
        _mesh: &Mesh,
        _unsimplified: Option<&[[DVec3; 3]]>,
        _fits: &dyn Fn(&SchemeOutput) -> bool,
    ) -> Option<String> {
        None
    }
    /// True when the scheme keeps its panels within a distance of the model (the strip
    /// scheme's `--max-deviation`): a model simplified for it keeps its surface as it
    /// was, and [`Configured::build_near`] measures the distance to that.
    fn bounds_distance(&self) -> bool {
        false
    }
    /// Builds the panels of `mesh`, simplified from `unsimplified` (the model's surface
    /// before simplifying, triangles in millimetres): a scheme with a distance bound
    /// keeps it to the model as given, not only to the simplified mesh. Others build
    /// `mesh`.
    fn build_near(
        &self,
        mesh: &Mesh,
        _unsimplified: &[[DVec3; 3]],
    ) -> Result<SchemeOutput, SchemeError> {
        self.build(mesh)
    }
}

/// Defaults a scheme gives the options every scheme takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelDefaults {
    /// `--face-scale`.
    pub face_scale: f64,
    /// `--holes`.
    pub holes: u32,
    /// The hole counts per connection it can place.
    pub holes_allowed: &'static [u32],
}

/// Options every scheme takes (lengths in mm, fractions as fractions).
#[derive(Clone, Debug, PartialEq)]
pub struct PanelOptions {
    /// Face band scale `s`: corners move toward the face centre, `s·v + (1−s)·c`.
    pub face_scale: f64,
    /// Fastener holes per connection.
    pub holes: u32,
    /// Hole diameter (mm).
    pub hole_diameter: f64,
    /// Material kept between a hole's rim and any cut edge of the panels it goes
    /// through (mm); two holes of a connection keep one diameter between their rims.
    pub hole_margin: f64,
    /// Wanted label cap height (mm).
    pub label_height: f64,
    /// The largest panel the layout can take; schemes that can cut long panels
    /// (woven ribbons) cut them to fit. `None`: no limit.
    pub panel_limit: Option<PanelLimit>,
    /// `--scale`, applied after `--size`: a scheme that names a `--size` divides the
    /// built size by it.
    pub scale: f64,
}

/// The largest panel a sheet takes: its bounding box in one of `rotations` equal
/// rotation steps must fit `width` × `height` (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelLimit {
    /// Usable width (mm).
    pub width: f64,
    /// Usable height (mm).
    pub height: f64,
    /// Rotation steps allowed (360°/N each).
    pub rotations: u32,
}

/// Room (mm) kept between a part and the usable sheet when a scheme checks that the
/// part fits: the nester sees the outline flattened again from 3D and written to
/// 0.0001 mm, and a part that fitted only to the last micrometre would be refused.
pub const FIT_SLACK: f64 = 0.5;

impl PanelLimit {
    /// True when `outline` fits the usable sheet less `room` on every side's total
    /// (and the [`FIT_SLACK`]) in one of the nesters' rotations: the one check every
    /// scheme makes before it hands a part on.
    pub fn fits(&self, outline: &[glam::DVec2], room: f64) -> bool {
        let spare = room + FIT_SLACK;
        crate::plane::fits_rotated(
            outline,
            self.rotations,
            self.width - spare,
            self.height - spare,
        )
    }
}

/// Option values as the user wrote them, by long option name (`"bridge-scale"` →
/// `"0.4"`; a switch is `"true"` or `"false"`). The command line and the config file
/// both fill it, so a scheme parses its options in one place.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OptionValues {
    values: BTreeMap<String, String>,
    /// Names whose value came from a config file, which may hold options of several
    /// schemes; the others were asked for explicitly.
    from_file: std::collections::BTreeSet<String>,
}

impl OptionValues {
    /// Sets `name` (a long option name without dashes) to `text`, as asked for on the
    /// command line.
    pub fn set(&mut self, name: &str, text: &str) {
        self.values.insert(name.to_string(), text.to_string());
        self.from_file.remove(name);
    }

    /// Sets `name` to `text` from a config file.
    pub fn set_from_file(&mut self, name: &str, text: &str) {
        self.values.insert(name.to_string(), text.to_string());
        self.from_file.insert(name.to_string());
    }

    /// The value of `name`, if given.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.values.get(name).map(String::as_str)
    }

    /// The names asked for explicitly (not from a config file).
    pub fn asked(&self) -> impl Iterator<Item = &str> {
        self.values
            .keys()
            .filter(|n| !self.from_file.contains(*n))
            .map(String::as_str)
    }

    /// These values, with `other`'s where this has none.
    pub fn or(mut self, other: OptionValues) -> OptionValues {
        for (name, text) in other.values {
            if !self.values.contains_key(&name) {
                if other.from_file.contains(&name) {
                    self.from_file.insert(name.clone());
                }
                self.values.insert(name, text);
            }
        }
        self
    }

    /// Parses the values of `T`'s arguments with `T`'s own definitions (values of
    /// other schemes' options are not `T`'s business and are skipped).
    pub fn parse<T: clap::Args + clap::FromArgMatches>(&self) -> Result<T, String> {
        let command = T::augment_args(clap::Command::new("unfold").no_binary_name(true));
        let mut argv: Vec<String> = Vec::new();
        for arg in command.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            let Some(text) = self.get(long) else { continue };
            if matches!(arg.get_action(), clap::ArgAction::SetTrue) {
                if text == "true" {
                    argv.push(format!("--{long}"));
                }
            } else {
                argv.push(format!("--{long}={text}"));
            }
        }
        let matches = command.try_get_matches_from(argv).map_err(|e| {
            e.to_string()
                .trim()
                .trim_start_matches("error: ")
                .to_string()
        })?;
        T::from_arg_matches(&matches).map_err(|e| e.to_string())
    }
}

/// The arguments of an options type, for [`Scheme::options`].
pub fn args_of<T: clap::Args>() -> Vec<clap::Arg> {
    T::augment_args(clap::Command::new("unfold"))
        .get_arguments()
        .cloned()
        .collect()
}

/// A scheme with its options resolved: what a job runs.
#[derive(Clone)]
pub struct ConfiguredScheme {
    /// The scheme.
    pub scheme: &'static dyn Scheme,
    /// Its resolved options.
    pub options: Arc<dyn Configured>,
}

impl ConfiguredScheme {
    /// The scheme's name.
    pub fn name(&self) -> &'static str {
        self.scheme.name()
    }

    /// The options every scheme takes.
    pub fn panel(&self) -> &PanelOptions {
        self.options.panel()
    }

    /// Refuses a mesh the scheme can never build ([`Configured::accepts`]).
    pub fn accepts(&self, mesh: &Mesh) -> Result<(), SchemeError> {
        self.options.accepts(mesh)
    }

    /// Builds the panels of `mesh`.
    pub fn build(&self, mesh: &Mesh) -> Result<SchemeOutput, SchemeError> {
        self.options.build(mesh)
    }

    /// Builds the panels of `mesh`, simplified from `unsimplified`
    /// ([`Configured::build_near`]).
    pub fn build_near(
        &self,
        mesh: &Mesh,
        unsimplified: &[[DVec3; 3]],
    ) -> Result<SchemeOutput, SchemeError> {
        self.options.build_near(mesh, unsimplified)
    }

    /// The least fold (radians) scored on its panels.
    pub fn least_scored_fold(&self) -> f64 {
        self.options.least_scored_fold()
    }

    /// True when its panels follow the mesh's faces ([`Configured::panels_follow_faces`]).
    pub fn panels_follow_faces(&self) -> bool {
        self.options.panels_follow_faces()
    }

    /// What makes its panels larger ([`Configured::larger_panels_fix`]).
    pub fn larger_panels_fix(&self) -> &'static str {
        self.options.larger_panels_fix()
    }

    /// Its options that make its panels large enough ([`Configured::larger_panels`]).
    pub fn larger_panels(
        &self,
        mesh: &Mesh,
        unsimplified: Option<&[[DVec3; 3]]>,
        fits: &dyn Fn(&SchemeOutput) -> bool,
    ) -> Option<String> {
        self.options.larger_panels(mesh, unsimplified, fits)
    }

    /// The manifest's `scheme.params`: the shared options, then the scheme's own.
    pub fn params(&self) -> Params {
        let panel = self.panel();
        let mut params = Params::default();
        params.push("face_scale", panel.face_scale);
        params.push("holes", panel.holes);
        params.push("hole_diameter", round4(panel.hole_diameter));
        params.push("hole_margin", round4(panel.hole_margin));
        params.push("label_height", round4(panel.label_height));
        params.extend(self.options.params());
        params
    }
}

impl fmt::Debug for ConfiguredScheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {:?}", self.name(), self.options)
    }
}

impl PartialEq for ConfiguredScheme {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
            && self.panel() == other.panel()
            && self.params() == other.params()
    }
}

/// What a scheme produced.
#[derive(Clone, Debug, Default)]
pub struct SchemeOutput {
    /// The panels, in a deterministic order.
    pub panels: Panels,
    /// Number of connections (links between two panels).
    pub connections: usize,
    /// Observations for the report (tabs shortened or left out, holes skipped).
    pub notes: Vec<String>,
    /// Lines the report prints about what only this scheme makes (the woven cycles).
    pub report: Vec<String>,
    /// Sections the manifest gets about them, after its warnings.
    pub manifest: Params,
    /// Connections that hold no fastener hole although holes were asked for (no room
    /// for one), in a deterministic order.
    pub unfastened: Vec<ConnectionName>,
    /// The mesh faces of each panel that covers a group of faces (`Covers::Faces(k)`
    /// is entry k), each list in increasing order.
    pub face_groups: Vec<FaceGroup>,
    /// The surface the panels are built on, where the scheme makes its own (the strip
    /// scheme's strips): face groups name its faces, and the map shows it instead of
    /// the scheme's mesh.
    pub surface: Option<Mesh>,
    /// Above zero, the panels are rigid sheet this thick (mm): each lies with its outer
    /// face on its facet and its material inward, and the assembled model gives them as
    /// solids.
    pub thickness: f64,
}

/// A build where more than this fraction of the connections holds no fastener hole
/// has faces too small for its fasteners: the build warns with the budget that fits
/// them, and the edge schemes do not widen face bands for it.
pub const MOST_UNFASTENED: f64 = 0.1;

/// A connection as a builder finds it: the two panels it joins and where they meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConnectionName {
    /// The panels' ids.
    pub panels: [Name; 2],
    /// The mesh element they meet at (a vertex for the edge schemes).
    pub at: Name,
}

impl std::fmt::Display for ConnectionName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{} at {}", self.panels[0], self.panels[1], self.at)
    }
}

/// Errors a scheme reports, each message naming its fix (the scheme's file writes
/// them).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SchemeError {
    /// The job's options do not suit the model (exit code 2).
    #[error("{0}")]
    Options(String),
    /// The model cannot be built by the scheme at this size (exit code 1).
    #[error("{0}")]
    Model(String),
}

impl SchemeError {
    /// True when the job's options are at fault (exit code 2).
    pub fn is_usage(&self) -> bool {
        matches!(self, SchemeError::Options(_))
    }
}

/// The face band of a face: each corner moved toward the face centre,
/// `s·v + (1−s)·c` (thesis: "face centre" = average of the corners).
pub fn face_band(mesh: &Mesh, f: FaceId, s: f64) -> Vec<DVec3> {
    let c = mesh.face_centre(f);
    mesh.face_positions(f)
        .map(|v| s * v + (1.0 - s) * c)
        .collect()
}

/// Asserts that `actual` are the points `expected`, in order, within 1e-9 mm: the
/// schemes' unit tests compare their constructions with numbers worked out by hand.
#[cfg(test)]
pub(crate) fn assert_points(actual: &[DVec3], expected: &[[f64; 3]]) {
    assert_eq!(actual.len(), expected.len(), "{actual:?}");
    for (p, q) in actual.iter().zip(expected) {
        assert!(
            p.distance(DVec3::from(*q)) < 1e-9,
            "{actual:?} is not {expected:?}"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every option a scheme's advice names is one of that scheme's own options.
    #[test]
    fn each_scheme_advises_its_own_options() {
        for scheme in SCHEMES {
            let own: Vec<String> = scheme
                .options()
                .iter()
                .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
                .collect();
            let named: Vec<&str> = scheme
                .info()
                .overlap_fix
                .split(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == ',')
                .filter(|w| w.starts_with("--"))
                .collect();
            assert!(!named.is_empty(), "{}: no option named", scheme.name());
            for option in named {
                assert!(
                    own.iter().any(|o| o == option),
                    "{}: {option} is not among {own:?}",
                    scheme.name()
                );
            }
        }
    }
}
