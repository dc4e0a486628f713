//! A view's owner buffer: the patches rasterized far to near, each cell keeping the
//! panel seen there, so an id is written only where its own panel shows.

use glam::{DVec2, DVec3};

use super::view::View;
use crate::panel::surface::Patch;

/// Raster cells per millimetre of paper for the owner buffers.
const RASTER_PER_MM: f64 = 4.0;

/// Most raster cells of one view: a page metres across gets coarser cells rather than
/// buffers of gigabytes.
const RASTER_MAX_CELLS: f64 = 4.0e6;

/// A view's owner buffer: which panel is seen at each raster cell of its page cell.
pub(super) struct Raster {
    lo: DVec2,
    /// Cells per millimetre of paper.
    per_mm: f64,
    width: usize,
    height: usize,
}

impl Raster {
    pub(super) fn new(lo: DVec2, size: DVec2) -> Raster {
        let area = (size.x * size.y).max(1e-9);
        let per_mm = RASTER_PER_MM.min((RASTER_MAX_CELLS / area).sqrt());
        Raster {
            lo,
            per_mm,
            width: (size.x * per_mm).ceil().max(1.0) as usize,
            height: (size.y * per_mm).ceil().max(1.0) as usize,
        }
    }

    /// Rasterizes the patches far to near (`order`), each cell keeping the nearest.
    pub(super) fn owners(
        &self,
        patches: &[Patch],
        order: &[(f64, usize)],
        view: &View,
        to_page: &dyn Fn(DVec3) -> DVec2,
        inside: &dyn Fn(&Patch) -> bool,
    ) -> Vec<Option<u32>> {
        let mut owner = vec![None; self.width * self.height];
        let mut depth = vec![f64::NEG_INFINITY; self.width * self.height];
        for &(_, i) in order {
            let patch = &patches[i];
            let id = (!inside(patch)).then_some(patch.panel as u32);
            let pts: Vec<(DVec2, f64)> = patch
                .points
                .iter()
                .map(|&p| ((to_page(p) - self.lo) * self.per_mm, p.dot(view.toward)))
                .collect();
            for k in 1..pts.len().saturating_sub(1) {
                self.triangle([pts[0], pts[k], pts[k + 1]], id, &mut owner, &mut depth);
            }
        }
        owner
    }

    fn triangle(
        &self,
        t: [(DVec2, f64); 3],
        id: Option<u32>,
        owner: &mut [Option<u32>],
        depth: &mut [f64],
    ) {
        let [(a, za), (b, zb), (c, zc)] = t;
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = a.min(b).min(c).floor().max(DVec2::ZERO);
        let hi = a.max(b).max(c).ceil();
        let x1 = (hi.x as usize).min(self.width);
        let y1 = (hi.y as usize).min(self.height);
        for y in lo.y as usize..y1 {
            // Only the cells whose centres the row's span may hold are tested: a thin
            // triangle's box is mostly outside it.
            let Some((from, to)) = row_span(t.map(|c| c.0), area, y as f64 + 0.5) else {
                continue;
            };
            let from = (from.floor() - 1.0).max(lo.x) as usize;
            let to = ((to.ceil() + 2.0).max(0.0) as usize).min(x1);
            for x in from..to {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let wa = (b - p).perp_dot(c - p) / area;
                let wb = (c - p).perp_dot(a - p) / area;
                let wc = 1.0 - wa - wb;
                if wa < -1e-9 || wb < -1e-9 || wc < -1e-9 {
                    continue;
                }
                let z = wa * za + wb * zb + wc * zc;
                let cell = y * self.width + x;
                if z >= depth[cell] {
                    depth[cell] = z;
                    owner[cell] = id;
                }
            }
        }
    }

    /// The panel seen at a page point and all round it (the raster cell there and its
    /// eight neighbours), so an id's centre is never at the edge of what is seen.
    pub(super) fn owner_at(&self, owners: &[Option<u32>], at: DVec2) -> Option<u32> {
        let q = (at - self.lo) * self.per_mm;
        if q.x < 1.0 || q.y < 1.0 {
            return None;
        }
        let (x, y) = (q.x as usize, q.y as usize);
        if x + 1 >= self.width || y + 1 >= self.height {
            return None;
        }
        let owner = owners[y * self.width + x];
        let around =
            (y - 1..=y + 1).all(|j| (x - 1..=x + 1).all(|i| owners[j * self.width + i] == owner));
        owner.filter(|_| around)
    }
}

/// The cells of the row whose centres lie at height `y` that triangle `t` (of signed
/// area `area`, doubled) may cover, as a range of cell indices found with an allowance
/// looser than the cells' own test (the caller pads it by a cell as well); `None`
/// where it covers none. Each barycentric weight is linear along the row, so each
/// side bounds the range from one end.
fn row_span(t: [DVec2; 3], area: f64, y: f64) -> Option<(f64, f64)> {
    let [a, b, c] = t;
    let weight = |p: DVec2, q: DVec2, x: f64| {
        let at = DVec2::new(x, y);
        (p - at).perp_dot(q - at) / area
    };
    let (mut from, mut to) = (f64::NEG_INFINITY, f64::INFINITY);
    for (p, q) in [(b, c), (c, a), (a, b)] {
        // The weight at the centres of cells 0 and 1, and the x (a cell index) where it
        // falls to the test's allowance.
        let w0 = weight(p, q, 0.5);
        let slope = weight(p, q, 1.5) - w0;
        if slope == 0.0 {
            if w0 < -1e-6 {
                return None;
            }
            continue;
        }
        let edge = (-1e-6 - w0) / slope;
        if slope > 0.0 {
            from = from.max(edge);
        } else {
            to = to.min(edge);
        }
    }
    (from <= to + 1.0).then_some((from, to))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell whose centre a triangle holds, tested one by one over its box.
    fn cells_by_box(raster: &Raster, t: [DVec2; 3]) -> Vec<usize> {
        let [a, b, c] = t;
        let area = (b - a).perp_dot(c - a);
        let mut cells = Vec::new();
        for y in 0..raster.height {
            for x in 0..raster.width {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let wa = (b - p).perp_dot(c - p) / area;
                let wb = (c - p).perp_dot(a - p) / area;
                if wa >= -1e-9 && wb >= -1e-9 && 1.0 - wa - wb >= -1e-9 {
                    cells.push(y * raster.width + x);
                }
            }
        }
        cells
    }

    #[test]
    fn a_triangle_covers_the_cells_its_box_test_finds_thin_or_not() {
        let raster = Raster::new(DVec2::ZERO, DVec2::new(30.0, 20.0));
        let size = DVec2::new(raster.width as f64, raster.height as f64);
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut point = || DVec2::new(rng.unit(), rng.unit()) * size * 1.2 - 0.1 * size;
        let mut covered = 0;
        for k in 0..400 {
            let (a, b) = (point(), point());
            // Every other triangle a sliver: its third corner a hair off the side ab.
            let c = match k % 2 {
                0 => point(),
                _ => a.lerp(b, 0.37) + (b - a).perp().normalize() * 0.3,
            };
            let t = [a, b, c];
            let mut owner = vec![None; raster.width * raster.height];
            let mut depth = vec![f64::NEG_INFINITY; owner.len()];
            raster.triangle(t.map(|p| (p, 0.0)), Some(1), &mut owner, &mut depth);
            let cells: Vec<usize> = (0..owner.len()).filter(|&i| owner[i].is_some()).collect();
            let expected = match (b - a).perp_dot(c - a).abs() < 1e-12 {
                true => Vec::new(),
                false => cells_by_box(&raster, t),
            };
            assert_eq!(cells, expected, "triangle {k}: {t:?}");
            covered += cells.len();
        }
        assert!(covered > 10_000, "{covered} cells covered in all");
    }
}
