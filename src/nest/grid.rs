//! A coarse occupancy grid of one sheet: which cells have their centre inside a placed
//! part. The nester draws candidate positions from free cells (so samples on a nearly
//! full sheet are not wasted on occupied space) and skips sheets whose free area is
//! smaller than the part. It is a guide only: every candidate is still checked
//! exactly by the collision engine.

/// Occupancy of a rectangle split into square cells.
#[derive(Clone, Debug)]
pub struct Grid {
    x0: f32,
    y0: f32,
    cell: f32,
    cols: usize,
    rows: usize,
    occupied: Vec<bool>,
    free: usize,
}

impl Grid {
    /// An empty grid over [x0, x1] × [y0, y1] with about `target_cells` cells along
    /// the longer side.
    pub fn new(x0: f32, y0: f32, x1: f32, y1: f32, target_cells: usize) -> Self {
        let cell = (x1 - x0).max(y1 - y0) / target_cells.max(1) as f32;
        let cols = (((x1 - x0) / cell).ceil() as usize).max(1);
        let rows = (((y1 - y0) / cell).ceil() as usize).max(1);
        Grid {
            x0,
            y0,
            cell,
            cols,
            rows,
            occupied: vec![false; cols * rows],
            free: cols * rows,
        }
    }

    /// Area of the free cells.
    pub fn free_area(&self) -> f32 {
        self.free as f32 * self.cell * self.cell
    }

    /// Marks the cells whose centre lies inside a simple polygon (even-odd scanlines).
    pub fn fill_polygon(&mut self, points: &[(f32, f32)]) {
        let (lo, hi) = points
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.1), hi.max(p.1))
            });
        let first_row = (((lo - self.y0) / self.cell - 0.5).ceil().max(0.0)) as usize;
        let mut crossings: Vec<f32> = Vec::new();
        for row in first_row..self.rows {
            let y = self.y0 + (row as f32 + 0.5) * self.cell;
            if y > hi {
                break;
            }
            crossings.clear();
            for (i, &a) in points.iter().enumerate() {
                let b = points[(i + 1) % points.len()];
                if (a.1 <= y) != (b.1 <= y) {
                    crossings.push(a.0 + (y - a.1) / (b.1 - a.1) * (b.0 - a.0));
                }
            }
            crossings.sort_by(f32::total_cmp);
            for pair in crossings.chunks_exact(2) {
                let c0 = (((pair[0] - self.x0) / self.cell - 0.5).ceil().max(0.0)) as usize;
                let c1 = ((pair[1] - self.x0) / self.cell - 0.5).floor();
                if c1 < 0.0 {
                    continue;
                }
                let c1 = (c1 as usize).min(self.cols - 1);
                for col in c0..=c1 {
                    let k = row * self.cols + col;
                    if !self.occupied[k] {
                        self.occupied[k] = true;
                        self.free -= 1;
                    }
                }
            }
        }
    }

    /// Whether a point lies outside the grid or in an occupied cell.
    pub fn blocked(&self, x: f32, y: f32) -> bool {
        let (cx, cy) = ((x - self.x0) / self.cell, (y - self.y0) / self.cell);
        if !(cx >= 0.0 && cy >= 0.0) {
            return true;
        }
        let (col, row) = (cx as usize, cy as usize);
        col >= self.cols || row >= self.rows || self.occupied[row * self.cols + col]
    }

    /// Side of a cell.
    pub fn cell(&self) -> f32 {
        self.cell
    }

    /// Empties the grid.
    pub fn clear(&mut self) {
        self.occupied.fill(false);
        self.free = self.occupied.len();
    }

    /// A point in a free cell chosen from `random` (a source of numbers in [0, 1)),
    /// by rejection with at most `tries` draws; `None` when every draw hit an
    /// occupied cell.
    pub fn free_point(&self, mut random: impl FnMut() -> f64, tries: usize) -> Option<(f32, f32)> {
        if self.free == 0 {
            return None;
        }
        for _ in 0..tries {
            let k = ((random() * self.occupied.len() as f64) as usize).min(self.occupied.len() - 1);
            if !self.occupied[k] {
                let (row, col) = (k / self.cols, k % self.cols);
                let x = self.x0 + (col as f32 + random() as f32) * self.cell;
                let y = self.y0 + (row as f32 + random() as f32) * self.cell;
                return Some((x, y));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_fills_its_cells_and_the_rest_stays_free() {
        let mut g = Grid::new(0.0, 0.0, 100.0, 100.0, 10);
        assert_eq!(g.free_area(), 10_000.0);
        g.fill_polygon(&[(0.0, 0.0), (50.0, 0.0), (50.0, 50.0), (0.0, 50.0)]);
        assert_eq!(g.free_area(), 7_500.0);
        // Half the sheet as a triangle: 45 cell centres lie strictly inside, 10 on
        // the diagonal, which may count either way.
        let mut t = Grid::new(0.0, 0.0, 100.0, 100.0, 10);
        t.fill_polygon(&[(0.0, 0.0), (100.0, 0.0), (100.0, 100.0)]);
        assert!(
            (4_500.0..=5_500.0).contains(&t.free_area()),
            "{}",
            t.free_area()
        );
        let mut calls = 0u32;
        let p = g.free_point(
            || {
                calls += 1;
                0.1
            },
            4,
        );
        // Cell 10 of 100 (row 1, col 0) is occupied by the square: every draw misses.
        assert!(p.is_none());
        // Blocked: occupied cells and anything off the grid.
        assert!(g.blocked(25.0, 25.0));
        assert!(!g.blocked(75.0, 25.0));
        assert!(g.blocked(-0.1, 25.0) && g.blocked(25.0, 100.5) && g.blocked(f32::NAN, 1.0));
        g.clear();
        assert_eq!(g.free_area(), 10_000.0);
    }
}
