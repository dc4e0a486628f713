//! The woven scheme's options: as given on the command line, their defaults, and
//! resolved.

use crate::scheme::PanelOptions;

/// `--band-scale`.
pub(super) const BAND_SCALE: f64 = 0.4;
/// `--curl-limit`.
pub(super) const CURL_LIMIT: f64 = 3.0;
/// `--thickness`.
pub(super) const THICKNESS: &str = "0.1in";

/// The woven options as given.
#[derive(Clone, Debug, Default, clap::Args)]
pub(super) struct WovenArgs {
    /// Strand width: a strand's end covers this fraction of the face band's side,
    /// below 1.
    #[arg(long, value_name = "T")]
    pub(super) band_scale: Option<f64>,

    /// Curl limit: a ribbon segment's convex hull is at most this many times its area.
    /// Smaller cuts ribbons into more, straighter segments that nest on fewer sheets;
    /// larger gives fewer joints.
    #[arg(long, value_name = "R")]
    pub(super) curl_limit: Option<f64>,

    /// Material thickness, with a unit: the two strands at a crossing are this far
    /// apart, one lifted and one lowered by half of it; 0 for flat ribbons.
    #[arg(long, value_name = "LENGTH")]
    pub(super) thickness: Option<String>,
}

/// The woven scheme's options, resolved (lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct WovenOptions {
    /// The options every scheme takes.
    pub panel: PanelOptions,
    /// Strand width as a fraction of the band side.
    pub band_scale: f64,
    /// Material thickness (mm): strands cross this far apart.
    pub thickness: f64,
    /// A segment's convex hull is at most this many times its area: curling ribbons
    /// are cut into pieces that nest.
    pub curl_limit: f64,
}
