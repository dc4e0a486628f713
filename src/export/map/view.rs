//! The map's views: the six directions the model is seen from, each turned a little
//! off its axis, and the projection of model points into a view's plane.

use glam::{DVec2, DVec3};

/// A direction the model is seen from.
pub(super) struct View {
    pub name: &'static str,
    /// The axis it is seen from and the way it turns off it, for the caption.
    pub axis: &'static str,
    pub turn: &'static str,
    /// From the model toward the viewer (unit).
    pub toward: DVec3,
    /// Up on the page (unit, square to `toward`).
    pub up: DVec3,
}

impl View {
    /// A view from `axis` turned a little toward `side`, up on the page as near
    /// `up` as the turn allows.
    fn new(name: &'static str, axis: [&'static str; 2], side: DVec3, up: DVec3) -> View {
        let main = axis_vector(axis[0]);
        let toward = (main + TILT * side.normalize()).normalize();
        let up = (up - up.dot(toward) * toward).normalize();
        View {
            name,
            axis: axis[0],
            turn: axis[1],
            toward,
            up,
        }
    }

    /// Right on the page: the viewing direction crossed with up.
    fn right(&self) -> DVec3 {
        (-self.toward).cross(self.up)
    }
}

/// How far each view turns off its axis (the tangent of 20°): a little from the side
/// and above or below, so walls square to the axis (the inside of a hole through the
/// model, the sides of a box) are seen too. Opposite views turn opposite ways, so
/// between them every side of such a wall shows.
const TILT: f64 = 0.364;

/// The unit vector of an axis named `+X`, `-Y`…
fn axis_vector(axis: &str) -> DVec3 {
    match axis {
        "+X" => DVec3::X,
        "-X" => DVec3::NEG_X,
        "+Y" => DVec3::Y,
        "-Y" => DVec3::NEG_Y,
        "+Z" => DVec3::Z,
        _ => DVec3::NEG_Z,
    }
}

/// The six views, in the order they are laid out (the model's +Y is up, +Z toward
/// the front).
pub(super) fn views() -> [View; 6] {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    [
        View::new("front", ["+Z", "+X and +Y"], x + y, y),
        View::new("back", ["-Z", "-X and -Y"], -x - y, y),
        View::new("left", ["-X", "+Z and +Y"], z + y, y),
        View::new("right", ["+X", "-Z and -Y"], -z - y, y),
        View::new("top", ["+Y", "+X and +Z"], x + z, -z),
        View::new("bottom", ["-Y", "-X and -Z"], -x - z, z),
    ]
}

/// A view's caption.
pub(super) fn caption_text(view: &View) -> String {
    format!(
        "{} (from {}, turned {:.0}° toward {})",
        view.name,
        view.axis,
        TILT.atan().to_degrees(),
        view.turn
    )
}

/// A model point in a view's (right, up) coordinates (mm).
pub(super) fn project(p: DVec3, view: &View) -> DVec2 {
    DVec2::new(p.dot(view.right()), p.dot(view.up))
}

pub(super) fn bounds<'a>(points: impl Iterator<Item = &'a DVec3>, view: &View) -> (DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for &p in points {
        let q = project(p, view);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if lo.x > hi.x {
        (DVec2::ZERO, DVec2::ZERO)
    } else {
        (lo, hi)
    }
}
