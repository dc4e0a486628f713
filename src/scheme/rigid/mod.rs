//! Rigid sheet: panels of a material that does not bend, for the schemes whose panels
//! can be flat parts (half-edge, net). Not a scheme: those schemes build their rigid
//! output here.
//!
//! `sheet` holds that output (options, names, labels, report, refusal), `cutback` the
//! faces cut back square so that no two panels pass through each other, `bracket` the
//! flat parts that hold them.

pub mod bracket;
pub mod cutback;
pub mod sheet;
