//! The edge schemes (quad-edge, winged-edge): a panel per edge made of a flap in each
//! face plane joined by a Bézier bend (thesis ch. 4.2, steps 1–3).
//!
//! What they share: a scheme describes each face by a [`flaps::FaceFlaps`]: the band,
//! each band edge's flap outline and the holes on each flap, drawn in the face frames
//! of [`flaps`] with its pin placement and labels. [`panels::edge_panels`] turns those
//! into panels, and [`sandwich`] into the two layers of the sandwich. `quad` and
//! `winged` import these, never each other.

pub mod flaps;
pub mod panels;
pub mod quad;
pub mod sandwich;
pub mod winged;
