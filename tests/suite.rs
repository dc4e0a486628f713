//! The integration tests, one test binary: each file beside this one is a module, so
//! the whole suite links once and the harness runs every test across the cores.

mod common;

mod architecture;
mod bad_builds;
mod bad_inputs;
mod build_half_edge;
mod build_net;
mod build_quad_edge;
mod build_rigid;
mod build_sandwich;
mod build_strip;
mod build_winged_edge;
mod build_woven;
mod folds;
mod halfedge_properties;
mod inspect_models;
mod kerf;
mod labels;
mod map;
mod nesting;
mod options_table;
mod output_folder;
mod planarize;
mod preview;
mod progress;
mod sheet_checker_selftest;
mod sheet_style;
mod simplify;
mod simplify_corpus;
mod size_checks;
mod sweep;
mod toy_scheme;
mod usage_errors;
mod woven_cycles;
