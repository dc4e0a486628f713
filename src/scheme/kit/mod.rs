//! What several schemes share and none of them owns: the glue tab, the labels of a panel
//! cut from one flat outline, the material thickness option.

pub(super) mod labels;
pub(super) mod tab;
pub(super) mod thickness;
