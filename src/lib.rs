//! `unfold` turns a 3D polygon mesh into developable flat panels for laser cutting.
//!
//! The pipeline is a chain of plain functions over plain data:
//!
//! ```text
//! read (OBJ, OFF, STL) -> prepare (validate, weld, orient) -> half-edge mesh
//!   -> scheme -> 3D panels -> flatten -> nest -> export
//! ```
//!
//! This crate is the library; the `unfold` binary only parses options and calls it.

pub mod cli;
pub mod config;
pub mod error;
pub mod export;
pub mod flatten;
pub mod font;
pub mod inspect;
pub mod internal;
pub mod kerf;
pub mod labels;
pub mod load;
pub mod memory;
pub mod mesh;
pub mod nest;
pub mod option_default;
pub mod panel;
pub mod plane;
pub mod record;
pub mod rng;
pub mod run;
pub mod sanity;
pub mod scheme;
pub mod union_find;
pub mod units;

pub use config::{BuildOptions, Job, ModelOptions, ModelSettings, NonPlanar};
pub use error::{Error, InputError, Result};
pub use inspect::{inspect, Inspection};
pub use load::load_model;
pub use run::{report_text, run, run_observed, Outcome};
