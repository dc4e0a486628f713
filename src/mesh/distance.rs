//! Distance from points to a triangle surface, through a uniform grid of the
//! triangles' bounding boxes: what simplification reports as its deviation from the
//! original surface, measured rather than estimated.

use glam::DVec3;

/// The closest point of triangle `abc` to `p` (Ericson, *Real-Time Collision
/// Detection*, 5.1.5: the Voronoi regions of the corners, then the edges, then the
/// face).
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        // A degenerate triangle: the nearest of its corners and edges above.
        return [a, b, c]
            .into_iter()
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}

/// The distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

/// The distance from `p` to the nearest point of the box `lo..hi`: no point of a
/// triangle in the box lies nearer, so a search skips the triangle when this is
/// beyond the nearest distance found.
pub fn box_distance(p: DVec3, (lo, hi): (DVec3, DVec3)) -> f64 {
    (lo - p).max(p - hi).max(DVec3::ZERO).length()
}

/// Whether a triangle whose box lies `bound` from a point can be as near as `best`:
/// the bound is exact up to rounding, so `slack` (a hair of the model's size) keeps
/// every triangle that could tie.
pub fn may_reach(bound: f64, best: f64, slack: f64) -> bool {
    bound <= best + slack
}

/// Items filed by grid cell in a compressed table: `cells_of(i)` lists the cells
/// item `i` of `count` covers. Gives `starts`, one longer than `cells`, and `entries`:
/// cell `c` holds the items `entries[starts[c]..starts[c + 1]]`, in increasing order.
pub fn cell_table<C: IntoIterator<Item = usize>>(
    cells: usize,
    count: usize,
    cells_of: impl Fn(usize) -> C,
) -> (Vec<u32>, Vec<u32>) {
    let mut starts = vec![0u32; cells + 1];
    for i in 0..count {
        for c in cells_of(i) {
            starts[c + 1] += 1;
        }
    }
    for c in 1..starts.len() {
        starts[c] += starts[c - 1];
    }
    let mut fill = starts.clone();
    let mut entries = vec![0u32; starts[cells] as usize];
    for i in 0..count {
        for c in cells_of(i) {
            entries[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
    }
    (starts, entries)
}

/// Triangles bucketed by a uniform grid, for nearest-distance queries.
pub struct TriangleGrid<'a> {
    triangles: &'a [[DVec3; 3]],
    /// Each triangle's bounding box.
    boxes: Vec<(DVec3, DVec3)>,
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    /// Triangle indices per cell, cells in x-fastest order (CSR).
    starts: Vec<u32>,
    entries: Vec<u32>,
}

impl<'a> TriangleGrid<'a> {
    /// A grid of about one triangle per cell.
    pub fn new(triangles: &'a [[DVec3; 3]]) -> Self {
        let (lo, hi) = super::geometry::bounding_box(triangles.iter().flatten().copied());
        let (lo, hi) = if triangles.is_empty() {
            (DVec3::ZERO, DVec3::ZERO)
        } else {
            (lo, hi)
        };
        let size = (hi - lo).max(DVec3::splat(1e-12));
        let boxes: Vec<(DVec3, DVec3)> = triangles
            .iter()
            .map(|t| super::geometry::bounding_box(t.iter().copied()))
            .collect();
        // Cells of equal sides, about as many as triangles (at most 256 a side), and no
        // smaller than a typical triangle: a flat set of large triangles (a planar
        // strip) would otherwise fill thousands of cells each.
        let volume = size.x * size.y * size.z;
        let n = triangles.len().max(1) as f64;
        let mut cell = (volume / n).cbrt();
        let longest = size.max_element();
        let mut extents: Vec<f64> = boxes.iter().map(|(a, b)| (*b - *a).max_element()).collect();
        extents.sort_by(f64::total_cmp);
        let typical = extents.get(extents.len() / 2).copied().unwrap_or(0.0);
        cell = cell.max(longest / 256.0).max(0.5 * typical);
        if !cell.is_finite() || cell <= 0.0 {
            cell = longest.max(1e-12);
        }
        let dims = [size.x, size.y, size.z].map(|s| ((s / cell).floor() as usize + 1).min(257));
        let index = |p: DVec3, k: usize| cell_index(p, k, lo, cell, dims);
        let cells = dims[0] * dims[1] * dims[2];
        let ranges: Vec<[(usize, usize); 3]> = boxes
            .iter()
            .map(|&(tlo, thi)| [0, 1, 2].map(|k| (index(tlo, k), index(thi, k))))
            .collect();
        let (starts, entries) = cell_table(cells, ranges.len(), |t| {
            let [xs, ys, zs] = ranges[t];
            (zs.0..=zs.1).flat_map(move |z| {
                (ys.0..=ys.1)
                    .flat_map(move |y| (xs.0..=xs.1).map(move |x| x + dims[0] * (y + dims[1] * z)))
            })
        });
        TriangleGrid {
            triangles,
            boxes,
            lo,
            cell,
            dims,
            starts,
            entries,
        }
    }

    /// Distance from `p` to the nearest triangle (infinite when there is none).
    pub fn distance(&self, p: DVec3) -> f64 {
        self.nearest(p)
            .map_or(f64::INFINITY, |(_, q)| q.distance(p))
    }

    /// The nearest triangle to `p` and its closest point (among equally near ones, the
    /// lowest index of those the search visited), or `None` when there is no triangle.
    pub fn nearest(&self, p: DVec3) -> Option<(usize, DVec3)> {
        if self.triangles.is_empty() {
            return None;
        }
        let home = [0, 1, 2].map(|k| cell_index(p, k, self.lo, self.cell, self.dims));
        let mut best: Option<(usize, DVec3, f64)> = None;
        let max_ring = self.dims.iter().copied().max().unwrap_or(1);
        for ring in 0..=max_ring {
            // Every cell not yet visited lies outside the box of the rings visited, at
            // least as far from `p` as that box's nearest side (less a hair: a cell's
            // index and its sides are rounded separately).
            if ring > 0
                && best.is_some_and(|b| {
                    b.2 <= self.inside_distance(p, home, ring - 1) - 1e-9 * self.cell
                })
            {
                break;
            }
            let slack = 1e-9 * self.cell;
            self.visit_ring(home, ring, |t| {
                if best.is_some_and(|b| !may_reach(box_distance(p, self.boxes[t]), b.2, slack)) {
                    return;
                }
                let [a, b, c] = self.triangles[t];
                let q = closest_point_on_triangle(p, a, b, c);
                let d = q.distance(p);
                let closer = match best {
                    None => true,
                    Some((bt, _, bd)) => d < bd || (d == bd && t < bt),
                };
                if closer {
                    best = Some((t, q, d));
                }
            });
        }
        best.map(|(t, q, _)| (t, q))
    }

    /// Whether some triangle lies within `r` of `p`: found by the first such triangle,
    /// without looking for the nearest. (A triangle at a hair more or less than `r`
    /// may be missed or taken: callers use it to skip work, not to decide.)
    pub fn reaches(&self, p: DVec3, r: f64) -> bool {
        let mut no_hint = usize::MAX;
        self.reaches_near(p, r, &mut no_hint)
    }

    /// [`TriangleGrid::reaches`], trying triangle `hint` first and leaving there the
    /// triangle found: points asked one after the other along a surface mostly have
    /// the same triangle within reach.
    pub fn reaches_near(&self, p: DVec3, r: f64, hint: &mut usize) -> bool {
        if let Some(&[a, b, c]) = self.triangles.get(*hint) {
            if closest_point_on_triangle(p, a, b, c).distance(p) <= r {
                return true;
            }
        }
        if self.triangles.is_empty() {
            return false;
        }
        let home = [0, 1, 2].map(|k| cell_index(p, k, self.lo, self.cell, self.dims));
        let max_ring = self.dims.iter().copied().max().unwrap_or(1);
        for ring in 0..=max_ring {
            if ring > 0 && self.inside_distance(p, home, ring - 1) > r {
                return false;
            }
            let mut found = None;
            self.visit_ring(home, ring, |t| {
                if found.is_some() || box_distance(p, self.boxes[t]) > r {
                    return;
                }
                let [a, b, c] = self.triangles[t];
                if closest_point_on_triangle(p, a, b, c).distance(p) <= r {
                    found = Some(t);
                }
            });
            if let Some(t) = found {
                *hint = t;
                return true;
            }
        }
        false
    }

    /// How far `p` lies inside the box of the cells within Chebyshev distance `ring`
    /// of `home` (0 when outside it).
    fn inside_distance(&self, p: DVec3, home: [usize; 3], ring: usize) -> f64 {
        (0..3)
            .map(|k| {
                let lo = self.lo[k] + (home[k] as f64 - ring as f64) * self.cell;
                let hi = self.lo[k] + (home[k] + ring + 1) as f64 * self.cell;
                (p[k] - lo).min(hi - p[k])
            })
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    }

    /// Calls `f` with every triangle of the cells at Chebyshev distance `ring` from
    /// `home` (a triangle in several cells comes more than once).
    fn visit_ring(&self, home: [usize; 3], ring: usize, mut f: impl FnMut(usize)) {
        let r = ring as i64;
        let span = |k: usize| {
            let h = home[k] as i64;
            (h - r).max(0)..=(h + r).min(self.dims[k] as i64 - 1)
        };
        for z in span(2) {
            for y in span(1) {
                for x in span(0) {
                    let d = (x - home[0] as i64)
                        .abs()
                        .max((y - home[1] as i64).abs())
                        .max((z - home[2] as i64).abs());
                    if d != r {
                        continue;
                    }
                    let c = x as usize + self.dims[0] * (y as usize + self.dims[1] * z as usize);
                    for &t in &self.entries[self.starts[c] as usize..self.starts[c + 1] as usize] {
                        f(t as usize);
                    }
                }
            }
        }
    }
}

/// The cell of `p` along axis `k` of a grid from `lo` with cubic cells of side `cell`
/// (points outside go to the nearest border cell).
fn cell_index(p: DVec3, k: usize, lo: DVec3, cell: f64, dims: [usize; 3]) -> usize {
    (((p[k] - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_in_each_region_of_a_triangle() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let near = |p: DVec3| closest_point_on_triangle(p, a, b, c);
        assert_eq!(
            near(DVec3::new(0.25, 0.25, 3.0)),
            DVec3::new(0.25, 0.25, 0.0)
        );
        assert_eq!(near(DVec3::new(-1.0, -1.0, 0.0)), a);
        assert_eq!(near(DVec3::new(2.0, -0.5, 0.0)), b);
        assert_eq!(near(DVec3::new(-0.5, 3.0, 1.0)), c);
        assert_eq!(near(DVec3::new(0.5, -2.0, 0.0)), DVec3::new(0.5, 0.0, 0.0));
        assert_eq!(near(DVec3::new(-2.0, 0.5, 1.0)), DVec3::new(0.0, 0.5, 0.0));
        assert!(near(DVec3::new(1.0, 1.0, 0.0)).distance(DVec3::new(0.5, 0.5, 0.0)) < 1e-12);
    }

    #[test]
    fn the_grid_agrees_with_brute_force() {
        // A bumpy sheet of triangles and points above, below and far outside it.
        let mut triangles = Vec::new();
        let h = |x: f64, y: f64| 0.3 * (x * 1.7).sin() * (y * 1.3).cos();
        for i in 0..20 {
            for j in 0..20 {
                let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
                let p = |dx: f64, dy: f64| DVec3::new(x + dx, y + dy, h(x + dx, y + dy));
                triangles.push([p(0.0, 0.0), p(0.5, 0.0), p(0.5, 0.5)]);
                triangles.push([p(0.0, 0.0), p(0.5, 0.5), p(0.0, 0.5)]);
            }
        }
        let grid = TriangleGrid::new(&triangles);
        let mut rng = crate::rng::SplitMix64::new(7);
        let mut unit = || rng.unit();
        for _ in 0..300 {
            let p = DVec3::new(unit() * 14.0 - 2.0, unit() * 14.0 - 2.0, unit() * 6.0 - 3.0);
            let brute = triangles
                .iter()
                .map(|[a, b, c]| closest_point_on_triangle(p, *a, *b, *c).distance(p))
                .fold(f64::INFINITY, f64::min);
            assert!((grid.distance(p) - brute).abs() < 1e-12, "{p}");
            assert!(grid.reaches(p, brute + 1e-9), "{p}");
            assert!(!grid.reaches(p, brute - 1e-9), "{p}");
            // Whatever triangle it tries first, and leaves one within reach there.
            let mut hint = (unit() * triangles.len() as f64) as usize;
            assert!(!grid.reaches_near(p, brute - 1e-9, &mut hint), "{p}");
            assert!(grid.reaches_near(p, brute + 1e-9, &mut hint), "{p}");
            let [a, b, c] = triangles[hint];
            assert!(closest_point_on_triangle(p, a, b, c).distance(p) <= brute + 1e-9);
        }
    }
}
