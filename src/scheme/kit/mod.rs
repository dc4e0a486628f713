//! What several schemes share and none of them owns: the glue tab and the labels of a
//! panel cut from one flat outline.

pub(super) mod labels;
pub(super) mod tab;
