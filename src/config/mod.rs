//! Options in two stages (as ripgrep does): raw options as the user wrote them (command
//! line or TOML, every field optional), then a resolved [`Job`] with units converted to
//! millimetres, defaults filled in and every value checked. The command line wins over
//! the configuration file.

pub mod defaults;
mod file;
mod job;
mod layers;
mod model;
mod options;
mod sheet;
mod values;

pub use crate::units::{parse_length, LengthUnit, MAX_LENGTH_MM, MM_PER_INCH};
pub use file::load_config;
pub use job::Job;
pub use layers::{check_layer_color, check_layer_name, LayerSetting, LayerSettings};
pub use model::{ModelOptions, ModelSettings, Scaling, MIN_BUILT_MM};
pub use options::BuildOptions;
pub use sheet::{parse_sheet, SheetSize};
pub use values::{LabelSide, NonPlanar, TargetEdges};
