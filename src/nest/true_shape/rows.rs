//! Construction in rows: parts lie flat (their long side along the sheet's width),
//! tallest first, and each is dropped from the top of the sheet at the end of the
//! current row and slid down and left until it rests (the bottom-left "gravity" of
//! Jakobs' BL, on true shapes). At each step the part to place is chosen among the
//! next few in height order by how little of the row it claims per unit of its own
//! area, so slanted ends interlock (a trapezoid turned half a turn fills its
//! neighbour's slant) and parts of one height share a row.
//!
//! A part wider than what is left of the row's bounds starts at the sheet's right
//! edge on the row's floor and slides left first, so the last part of a row can
//! reach under its neighbour's slanted end. The slides test where each step ends,
//! halving the step on a collision: a long step may pass a part into free space
//! beyond it, so "rests" means that no step of at least [`MIN_STEP`] down or left is
//! free, not that the part touches whatever it passed.

use jagua_rs::geometry::primitives::{Point, SPolygon};
use rayon::prelude::*;

use super::nester::{Candidate, Nester, EDGE_GAP, MIN_STEP};
use super::part::Part;

/// Parts, next in height order, that compete for each place in a row.
const ROW_CANDIDATES: usize = 12;

/// Parts, next in height order among those narrow enough, tried at a row's end
/// when none of the row candidates fits there.
const ROW_END_CANDIDATES: usize = 48;

/// Rounds of dropping and sliding left before a part is taken to rest.
const SETTLE_ROUNDS: usize = 4;

/// Where a part came to rest in a row: its pose, the right side, bottom and height
/// of its bounds there, and the score.
#[derive(Clone, Copy)]
struct Rest {
    pose: Candidate,
    right: f32,
    bottom: f32,
    height: f32,
    score: f32,
}

/// The row being filled: where it ends, the bottom of its first part's bounds (its
/// floor) and that part's height; no height yet for a new row.
#[derive(Clone, Copy)]
struct Row {
    end: f32,
    floor: f32,
    height: f32,
}

impl Nester<'_> {
    /// Places every part in rows (see the module documentation), opening sheets as
    /// needed. `Err(part)` names a part that fits no empty sheet.
    pub(super) fn construct_in_rows(&mut self) -> Result<(), usize> {
        let parts = self.parts;
        let flat: Vec<Vec<usize>> = parts.iter().map(flat_orientations).collect();
        // The least width and height of a part's bounds over its flat orientations.
        let extent = |p: usize, axis: fn(Point) -> f32| {
            flat[p]
                .iter()
                .map(|&o| axis(parts[p].orientations[o].hi) - axis(parts[p].orientations[o].lo))
                .fold(f32::INFINITY, f32::min)
        };
        let height = |p: usize| extent(p, |q| q.1);
        let width = |p: usize| extent(p, |q| q.0);
        let mut left: Vec<usize> = (0..parts.len()).collect();
        left.sort_by(|&a, &b| {
            height(b)
                .total_cmp(&height(a))
                .then(parts[b].area.total_cmp(&parts[a].area))
                .then(a.cmp(&b))
        });
        if left.is_empty() {
            return Ok(());
        }
        let mut s = self.open_sheet();
        let x_min = self.bounds.x_min;
        let new_row = Row {
            end: x_min,
            floor: self.bounds.y_min,
            height: 0.0,
        };
        let mut row = new_row;
        while !left.is_empty() {
            let tried: Vec<usize> = (0..left.len().min(ROW_CANDIDATES)).collect();
            let mut best = self.best_rest(s, &left, &tried, &flat, row);
            if best.is_none() && row.end > x_min {
                // The row's end: the next parts narrow enough for what is left (twice
                // that, as a slanted end may reach under its neighbour's).
                let room = self.bounds.x_max - row.end;
                let tried: Vec<usize> = (ROW_CANDIDATES.min(left.len())..left.len())
                    .filter(|&i| width(left[i]) <= 2.0 * room)
                    .take(ROW_END_CANDIDATES)
                    .collect();
                best = self.best_rest(s, &left, &tried, &flat, row);
            }
            match best {
                Some((i, rest)) => {
                    let part = left.remove(i);
                    self.put(s, part, rest.pose);
                    self.report_construction(parts.len() - left.len());
                    if row.height == 0.0 {
                        row.height = rest.height;
                        row.floor = rest.bottom;
                    }
                    row.end = row.end.max(rest.right);
                }
                None if row.end > x_min => row = new_row,
                None if self.sheets[s].parts.is_empty() => {
                    // No flat pose fits an empty sheet: the tallest part may still
                    // fit turned, which the sampled search also tries.
                    let part = left[0];
                    let pose = self.search(s, part, self.samples.max(64)).ok_or(part)?;
                    self.put(s, part, pose);
                    left.remove(0);
                    self.report_construction(parts.len() - left.len());
                }
                None => {
                    s = self.open_sheet();
                    row = new_row;
                }
            }
        }
        Ok(())
    }

    /// The best resting pose on sheet `s` at the end of `row` among the parts
    /// `left[i]` for `i` in `tried`, each in its flat orientations (see
    /// [`Nester::rest_in_row`]): the index into `left` and the rest. Candidates are
    /// settled in parallel and compared in order (the earlier wins ties).
    fn best_rest(
        &mut self,
        s: usize,
        left: &[usize],
        tried: &[usize],
        flat: &[Vec<usize>],
        row: Row,
    ) -> Option<(usize, Rest)> {
        let tasks: Vec<(usize, usize)> = tried
            .iter()
            .flat_map(|&i| flat[left[i]].iter().map(move |&o| (i, o)))
            .collect();
        let this = &*self;
        let rests: Vec<(Option<Rest>, u64)> = tasks
            .par_iter()
            .with_min_len(1)
            .map(|&(i, o)| this.rest_in_row(s, left[i], o, row))
            .collect();
        let mut best: Option<(usize, Rest)> = None;
        for (&(i, _), (rest, checks)) in tasks.iter().zip(rests) {
            self.checks += checks;
            if let Some(rest) = rest {
                if best.is_none_or(|(_, b)| rest.score < b.score) {
                    best = Some((i, rest));
                }
            }
        }
        best
    }

    /// Where `part` in orientation `o` comes to rest when dropped at the row's end
    /// (or, wider than what is left of the row's bounds, slid in from the sheet's
    /// right edge on the row's floor), and how much of the row it claims per unit of
    /// its area (lower is better), or `None` when it does not fit there; with the
    /// checks made.
    fn rest_in_row(&self, s: usize, part: usize, o: usize, row: Row) -> (Option<Rest>, u64) {
        let p = &self.parts[part];
        let or = p.orientations[o];
        let mut scratch = self.scratch_for(part);
        // A hair right of the row's end (a part touching its neighbour's bounds in
        // f32 counts as colliding, and could not drop past it), at the top.
        let mut start = self.clamp(part, o, row.end + EDGE_GAP - or.lo.0, f32::INFINITY);
        let wider_than_left = start.x + or.lo.0 < row.end;
        if wider_than_left {
            if row.height == 0.0 {
                return (None, 0);
            }
            // Wider than what is left of the row's bounds, it may still fit by
            // reaching under or over its neighbour's slanted end: start at the
            // sheet's right edge on the row's floor, and slide left first.
            start = self.clamp(part, o, f32::INFINITY, row.floor + EDGE_GAP - or.lo.1);
        }
        let mut checks = 1;
        if !self.is_free(s, part, start, &mut scratch) {
            return (None, checks);
        }
        let mut c = start;
        if wider_than_left {
            c = self.slide(s, part, c, (-1.0, 0.0), &mut scratch, &mut checks);
        }
        for _ in 0..SETTLE_ROUNDS {
            let before = (c.x, c.y);
            c = self.slide(s, part, c, (0.0, -1.0), &mut scratch, &mut checks);
            c = self.slide(s, part, c, (-1.0, 0.0), &mut scratch, &mut checks);
            if before == (c.x, c.y) {
                break;
            }
        }
        let right = c.x + or.hi.0;
        let own_height = or.hi.1 - or.lo.1;
        let claimed = (right - row.end).max(0.0) * row.height.max(own_height);
        let grown = p.item.shape_cd().area();
        // Ties (parts resting in earlier gaps claim nothing) go to the lower pose.
        let score = claimed / grown + 1e-6 * (c.y + or.hi.1);
        (
            Some(Rest {
                pose: c,
                right,
                bottom: c.y + or.lo.1,
                height: own_height,
                score,
            }),
            checks,
        )
    }

    /// Moves a free pose in direction `dir` as far as it stays free: steps halve from
    /// half the sheet's size down to [`MIN_STEP`].
    fn slide(
        &self,
        s: usize,
        part: usize,
        mut c: Candidate,
        dir: (f32, f32),
        scratch: &mut SPolygon,
        checks: &mut u64,
    ) -> Candidate {
        let b = self.bounds;
        let mut step = 0.5 * (b.x_max - b.x_min).max(b.y_max - b.y_min);
        while step > MIN_STEP {
            let next = self.clamp(part, c.orientation, c.x + dir.0 * step, c.y + dir.1 * step);
            if (next.x, next.y) == (c.x, c.y) {
                step *= 0.5;
                continue;
            }
            *checks += 1;
            if self.is_free(s, part, next, scratch) {
                c = next;
            } else {
                step *= 0.5;
            }
        }
        c
    }
}

/// The orientations of a part that lie square to its axis with its long side along
/// the sheet's width (all four quarter turns for a part about as tall as wide); the
/// quarter turns standing when none lying fits the sheet; every orientation when no
/// quarter turn fits.
fn flat_orientations(p: &Part) -> Vec<usize> {
    let size = |o: usize| {
        let or = p.orientations[o];
        (or.hi.0 - or.lo.0, or.hi.1 - or.lo.1)
    };
    let flat: Vec<usize> = p
        .square
        .iter()
        .copied()
        .filter(|&o| {
            let (w, h) = size(o);
            w >= 0.9 * h
        })
        .collect();
    if !flat.is_empty() {
        flat
    } else if !p.square.is_empty() {
        p.square.clone()
    } else {
        (0..p.orientations.len()).collect()
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::super::nester::Nester;
    use super::super::options::NestOptions;
    use super::super::part::prepare;
    use crate::nest::SheetSpec;

    /// Sheets the construction in rows alone (no improvement) takes for `n` copies of
    /// a quadrilateral on an 18 × 24 in sheet with the SPEC's margin and a 1 mm
    /// spacing (444.5 × 596.9 mm usable: eleven rows of 50 mm parts).
    fn rows_sheets(corners: [(f64, f64); 4], n: usize) -> usize {
        let sheet = SheetSpec {
            width: 457.2,
            height: 609.6,
            margin: 6.35,
            spacing: 1.0,
        };
        let options = NestOptions {
            rotations: 16,
            mirror: false,
            effort: 2,
            seed: 0,
            time_limit: None,
        };
        let outline: Vec<DVec2> = corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
        let (parts, container) = prepare(&vec![outline; n], sheet, &options).expect("fits");
        let mut nester = Nester::new(&parts, container, &options);
        nester.construct_in_rows().expect("fits");
        assert_eq!(
            nester.sheets.iter().map(|s| s.parts.len()).sum::<usize>(),
            n
        );
        nester.sheets.len()
    }

    /// Parallelograms 100 × 50 mm slanted 30 mm: four to a row (4 × 101 + 30 = 434
    /// mm), the fourth reaching under the third's slant, so 88 fill two sheets; by
    /// their 130 mm bounds only three fit a row (three sheets).
    #[test]
    fn parallelograms_interlock_four_to_a_row() {
        let corners = [(0.0, 0.0), (100.0, 0.0), (130.0, 50.0), (30.0, 50.0)];
        assert_eq!(rows_sheets(corners, 88), 2);
    }

    /// Isosceles trapezoids (100 mm base, 60 mm top, 50 mm tall): turned half a turn
    /// every other one, five to a row (100 + 4 × 81 = 424 mm), so 110 fill two sheets;
    /// all one way up, four to a row (three sheets).
    #[test]
    fn trapezoids_alternate_five_to_a_row() {
        let corners = [(0.0, 0.0), (100.0, 0.0), (80.0, 50.0), (20.0, 50.0)];
        assert_eq!(rows_sheets(corners, 110), 2);
    }
}
