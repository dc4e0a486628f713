//! The glue tab of the schemes that glue faces edge to edge (half-edge, net, strip):
//! its outline on the neighbour face, the holes through it, its option and defaults.

use glam::{DVec2, DVec3};

use crate::mesh::{HalfedgeId, Mesh};
use crate::option_default::OptionDefault;
use crate::plane::{area, clip_convex, distance_to_border};
use crate::scheme::{face_band, PanelDefaults, PanelOptions};

/// A tab, in 3D: its base on the edge (inset from the corners) and the rest of its
/// outline, plus the fastener holes through it and the neighbour.
#[derive(Clone, Debug)]
pub(in crate::scheme) struct Tab {
    /// Owner half-edge (a → b in the owner face).
    pub(in crate::scheme) owner: HalfedgeId,
    /// Base points on the edge: a' near a, b' near b.
    pub(in crate::scheme) base: [DVec3; 2],
    /// The tab outline after b', a' (so the tab facet is b', a', top…).
    pub(in crate::scheme) top: Vec<DVec3>,
    /// Hole centres (in the neighbour's plane).
    pub(in crate::scheme) holes: Vec<DVec3>,
    /// The tab is lower than wanted.
    pub(in crate::scheme) shortened: bool,
    /// Fewer holes than wanted fit (perhaps none).
    pub(in crate::scheme) holes_skipped: bool,
}

/// `--tab-height`.
const TAB_HEIGHT: &str = "8mm";

/// The default of the tab option, for the `options()` of the schemes that glue tabs.
pub(in crate::scheme) fn tab_defaults() -> OptionDefault {
    OptionDefault::value("tab-height", TAB_HEIGHT)
}

/// The tab option of the schemes that glue tabs (half-edge, net), as given.
#[derive(Clone, Debug, Default, clap::Args)]
pub(in crate::scheme) struct TabArgs {
    /// Wanted overlap of a tab on its neighbour panel, with a unit; tabs are shortened
    /// where the neighbour is smaller.
    #[arg(long, value_name = "LENGTH")]
    tab_height: Option<String>,
}

impl TabArgs {
    /// The tab height (mm), checked, or its default.
    pub(in crate::scheme) fn height(&self) -> Result<f64, String> {
        crate::units::positive_length("tab-height", self.tab_height.as_deref(), TAB_HEIGHT)
    }
}

/// The defaults of the schemes that glue whole faces with tabs (half-edge, net): faces
/// whole, no holes unless asked (glue holds), up to two through each tab.
pub(in crate::scheme) const TAB_DEFAULTS: PanelDefaults = PanelDefaults {
    face_scale: 1.0,
    holes: 0,
    holes_allowed: &[0, 1, 2],
};

/// What a tab is made to (lengths in mm): its wanted height, the fastener holes through
/// it, and the face scale of the panels it joins (a tab first spans the gap to a
/// shrunk panel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::scheme) struct TabOptions {
    /// Face band scale `s` of the panels.
    face_scale: f64,
    /// Wanted height of the tab's overlap with its neighbour (mm).
    height: f64,
    /// Fastener holes per tab.
    holes: u32,
    /// Hole diameter (mm).
    hole_diameter: f64,
    /// Material kept between a hole's rim and any cut edge (mm).
    hole_margin: f64,
}

impl TabOptions {
    /// The tab of a scheme with the shared options `panel`, `height` high.
    pub(in crate::scheme) fn new(panel: &PanelOptions, height: f64) -> TabOptions {
        TabOptions {
            face_scale: panel.face_scale,
            height,
            holes: panel.holes,
            hole_diameter: panel.hole_diameter,
            hole_margin: panel.hole_margin,
        }
    }
}

/// The tab that the face of `owner` (a → b) folds onto the neighbour across it, or
/// `None` when the neighbour cannot hold one.
pub(in crate::scheme) fn make_tab(
    mesh: &Mesh,
    owner: HalfedgeId,
    options: &TabOptions,
) -> Option<Tab> {
    let g = mesh.face(owner.twin())?;
    let (a, b) = (
        mesh.position(mesh.origin(owner)),
        mesh.position(mesh.dest(owner)),
    );
    let length = a.distance(b);
    let x = (b - a) / length;
    let n_g = mesh.face_normal(g);
    // Inward direction of the neighbour at this edge, in its plane.
    let y = x.cross(n_g).normalize();
    let to2 = |p: DVec3| DVec2::new((p - a).dot(x), (p - a).dot(y));
    let to3 = |q: DVec2| a + q.x * x + q.y * y;
    let centre = to2(mesh.face_centre(g));
    if centre.y <= 0.0 {
        return None;
    }
    let s = options.face_scale;
    let gap = (1.0 - s) * centre.y;
    let wanted = gap + options.height;
    // Inset the base a little from the corners so tabs from neighbouring edges that
    // arrive on the same face do not touch.
    let inset = (0.05 * length).min(0.5);
    let (lo, hi) = (inset, length - inset);
    let trapezoid = if hi - lo > 2.0 * wanted {
        vec![
            DVec2::new(lo, 0.0),
            DVec2::new(hi, 0.0),
            DVec2::new(hi - wanted, wanted),
            DVec2::new(lo + wanted, wanted),
        ]
    } else {
        let h = 0.5 * (hi - lo);
        vec![
            DVec2::new(lo, 0.0),
            DVec2::new(hi, 0.0),
            DVec2::new(0.5 * (lo + hi), h),
        ]
    };
    let sector = [DVec2::ZERO, DVec2::new(length, 0.0), centre];
    let tab = clip_convex(&trapezoid, &sector);
    let top_height = tab.iter().map(|q| q.y).fold(0.0, f64::max);
    let overlap = top_height - gap;
    if tab.len() < 3 || area(&tab) <= 0.0 || overlap < (0.5 * options.height).min(1.0) {
        return None;
    }
    // The tab facet runs b', a', then the rest: the clipped polygon is
    // counter-clockwise in (x, y) starting at a' = (lo, 0), b' = (hi, 0).
    let start = tab
        .iter()
        .position(|q| q.distance(DVec2::new(lo, 0.0)) < 1e-9)?;
    let ccw: Vec<DVec2> = (0..tab.len())
        .map(|k| tab[(start + k) % tab.len()])
        .collect();
    if ccw[1].distance(DVec2::new(hi, 0.0)) > 1e-9 {
        return None;
    }
    let top: Vec<DVec3> = ccw[2..].iter().rev().map(|&q| to3(q)).collect();

    let (holes, holes_skipped) =
        place_holes(&ccw, gap, top_height, &face_band(mesh, g, s), &to2, options);
    Some(Tab {
        owner,
        base: [to3(DVec2::new(lo, 0.0)), to3(DVec2::new(hi, 0.0))],
        top,
        holes: holes.into_iter().map(to3).collect(),
        shortened: top_height < wanted - 1e-9,
        holes_skipped,
    })
}

/// Hole centres along the middle of the tab's overlap with the neighbour band, each
/// with the hole margin of material to the tab's and the band's outline: as many as
/// asked, or as many as fit; and whether fewer than asked fit.
fn place_holes(
    tab: &[DVec2],
    gap: f64,
    top_height: f64,
    neighbour_band: &[DVec3],
    to2: &dyn Fn(DVec3) -> DVec2,
    options: &TabOptions,
) -> (Vec<DVec2>, bool) {
    let count = options.holes;
    if count == 0 {
        return (Vec::new(), false);
    }
    let r = 0.5 * options.hole_diameter;
    // The hole's radius and the margin of material to the tab's and the face's edges.
    let clearance = r + options.hole_margin;
    let v = 0.5 * (gap + top_height);
    // The tab's extent at height v (it is convex: two crossings).
    let mut xs = Vec::new();
    for i in 0..tab.len() {
        let (p, q) = (tab[i], tab[(i + 1) % tab.len()]);
        if (p.y - v) * (q.y - v) <= 0.0 && p.y != q.y {
            xs.push(p.x + (v - p.y) / (q.y - p.y) * (q.x - p.x));
        }
    }
    let (Some(u0), Some(u1)) = (
        xs.iter().copied().reduce(f64::min),
        xs.iter().copied().reduce(f64::max),
    ) else {
        return (Vec::new(), true);
    };
    let band: Vec<DVec2> = neighbour_band.iter().map(|&p| to2(p)).collect();
    // `count` holes evenly along the middle of the tab, if they all fit.
    let along = |count: u32| -> Option<Vec<DVec2>> {
        let centres: Vec<DVec2> = (1..=count)
            .map(|k| DVec2::new(u0 + (u1 - u0) * k as f64 / (count + 1) as f64, v))
            .collect();
        let fits = centres.iter().all(|&c| {
            distance_to_border(tab, c) >= clearance
                && crate::plane::contains(&band, c)
                && distance_to_border(&band, c) >= clearance
        }) && centres
            .windows(2)
            .all(|w| w[0].distance(w[1]) >= 2.0 * r + options.hole_diameter);
        fits.then_some(centres)
    };
    // The wanted count, or as many as fit.
    (1..=count)
        .rev()
        .find_map(|n| along(n).map(|centres| (centres, n < count)))
        .unwrap_or((Vec::new(), true))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::build::two_triangles;
    use crate::scheme::assert_points;

    /// Face 1 of [`two_triangles`] with its centre 40 mm from the hinge: high enough
    /// for a full tab of a few mm.
    const TALL: DVec3 = DVec3::new(30.0, 120.0, 0.0);

    /// A tab `height` high between faces shrunk by `face_scale`, with `holes` holes of
    /// 1 mm with 0.5 mm of margin.
    fn options(face_scale: f64, holes: u32, height: f64) -> TabOptions {
        TabOptions {
            face_scale,
            height,
            holes,
            hole_diameter: 1.0,
            hole_margin: 0.5,
        }
    }

    /// The tab face 0 of `two_triangles(apex)` folds onto face 1 across the hinge.
    fn hinge_tab(apex: DVec3, options: &TabOptions) -> Option<Tab> {
        make_tab(&two_triangles(apex), HalfedgeId(4), options)
    }

    #[test]
    fn a_tab_is_a_trapezoid_of_the_wanted_height_inset_from_the_corners() {
        let tab = hinge_tab(TALL, &options(1.0, 0, 4.0)).unwrap();
        assert_eq!(tab.owner, HalfedgeId(4));
        // Half-edge 4 runs a = (60,0,0) → b = (0,0,0); the base is inset min(5% of 60,
        // 0.5) = 0.5 mm from each end.
        assert_points(&tab.base, &[[59.5, 0.0, 0.0], [0.5, 0.0, 0.0]]);
        // 45° sides: the top at y = 4 runs from x = 0.5 + 4 to x = 59.5 − 4, listed
        // after a' (so from the a end).
        assert_points(&tab.top, &[[55.5, 4.0, 0.0], [4.5, 4.0, 0.0]]);
        assert!(!tab.shortened && !tab.holes_skipped && tab.holes.is_empty());
    }

    #[test]
    fn a_tab_stays_inside_the_triangle_of_the_edge_and_the_neighbour_centre() {
        // Face 1's centre is (30,10,0): the sector's sides y = x/3 and y = (60 − x)/3
        // cut the trapezoid's sides x = 0.5 + y and x = 59.5 − y at y = 0.25, and its
        // top y = 4 at x = 12 and x = 48.
        let tab = hinge_tab(DVec3::new(30.0, 30.0, 0.0), &options(1.0, 0, 4.0)).unwrap();
        assert_points(&tab.base, &[[59.5, 0.0, 0.0], [0.5, 0.0, 0.0]]);
        assert_points(
            &tab.top,
            &[
                [59.25, 0.25, 0.0],
                [48.0, 4.0, 0.0],
                [12.0, 4.0, 0.0],
                [0.75, 0.25, 0.0],
            ],
        );
        // Its full height is still reached.
        assert!(!tab.shortened);
    }

    #[test]
    fn a_tab_higher_than_half_its_base_is_a_shortened_triangle() {
        // 40 mm wanted over a 59 mm base: the 45° sides meet at x = 30, y = 59/2.
        let tab = hinge_tab(TALL, &options(1.0, 0, 40.0)).unwrap();
        assert_points(&tab.top, &[[30.0, 29.5, 0.0]]);
        assert!(tab.shortened);
    }

    #[test]
    fn no_tab_onto_a_neighbour_too_small_to_hold_one() {
        // A neighbour 0.3 mm high: its centre is 0.1 mm from the hinge, and a tab
        // overlapping it by less than min(4/2, 1) = 1 mm is no tab.
        assert!(hinge_tab(DVec3::new(30.0, 0.3, 0.0), &options(1.0, 0, 4.0)).is_none());
        // Nor across a boundary edge (edge 0's twin has no face).
        let mesh = two_triangles(TALL);
        assert!(make_tab(&mesh, HalfedgeId(0), &options(1.0, 0, 4.0)).is_none());
    }

    #[test]
    fn holes_lie_evenly_along_the_middle_of_the_overlap() {
        // The overlap's middle is y = 4/2 = 2, where the tab runs from x = 2.5 to
        // 57.5: two holes at 1/3 and 2/3 of that, 55/3 mm apart, from the a end.
        let tab = hinge_tab(TALL, &options(1.0, 2, 4.0)).unwrap();
        let third = 55.0 / 3.0;
        assert_points(
            &tab.holes,
            &[[57.5 - third, 2.0, 0.0], [57.5 - 2.0 * third, 2.0, 0.0]],
        );
        assert!(!tab.holes_skipped);
    }
}
