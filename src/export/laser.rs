//! The laser's time: speeds per kind, the travel between paths, and the order that
//! keeps it short. [`super::draw_sheet`] hands the paths of each kind to [`order`],
//! which runs them nearest first (a part's holes and inner cuts still before its
//! outline); the [`super::sink::Lengths`] sink measures the travel of whatever order it is
//! given.

use glam::DVec2;

/// Laser speeds (mm/s): cutting, scoring (both fold kinds), engraving, and moving
/// with the beam off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speeds {
    /// Cut speed.
    pub cut: f64,
    /// Score speed.
    pub score: f64,
    /// Engrave (vector line) speed.
    pub engrave: f64,
    /// Travel speed, beam off.
    pub travel: f64,
}

impl Default for Speeds {
    /// For 300 gsm card on a 40 W CO2 laser: cut through at 15 mm/s, score at low
    /// power at 50 mm/s, engrave lines at 100 mm/s, travel at 300 mm/s.
    fn default() -> Self {
        Speeds {
            cut: 15.0,
            score: 50.0,
            engrave: 100.0,
            travel: 300.0,
        }
    }
}

impl Speeds {
    /// Parses `cut=10,score=40,engrave=80,travel=300` (any of them; the rest keep
    /// their defaults).
    pub fn parse(text: &str) -> Result<Speeds, String> {
        let mut speeds = Speeds::default();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let Some((name, value)) = part.split_once('=') else {
                return Err(format!(
                    "--speeds: \"{part}\" is not KIND=MM_PER_S; write like cut=10,score=40,engrave=80,travel=300"
                ));
            };
            let number: f64 = value
                .trim()
                .trim_end_matches("mm/s")
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| {
                    format!("--speeds: {name}={value}: a speed is a positive number of mm/s, like {name}=20")
                })?;
            match name.trim() {
                "cut" => speeds.cut = number,
                "score" => speeds.score = number,
                "engrave" => speeds.engrave = number,
                "travel" => speeds.travel = number,
                other => {
                    return Err(format!(
                        "--speeds: unknown kind \"{other}\"; the kinds are cut, score, engrave and travel"
                    ))
                }
            }
        }
        Ok(speeds)
    }

    /// Seconds to run `lengths` (mm) at these speeds.
    pub fn seconds(&self, lengths: &super::sink::Lengths) -> f64 {
        lengths.cut / self.cut
            + (lengths.score + lengths.score_valley) / self.score
            + lengths.engrave / self.engrave
            + lengths.travel / self.travel
    }
}

/// One path to run: a polyline (closed or open) or a circle.
#[derive(Clone, Debug, PartialEq)]
pub enum Path {
    /// Points; a closed one ends where it starts.
    Polyline {
        /// Its points.
        points: Vec<DVec2>,
        /// Joined back to the first point.
        closed: bool,
    },
    /// A circle, started on its rightmost point.
    Circle {
        /// Centre.
        center: DVec2,
        /// Radius.
        radius: f64,
    },
}

impl Path {
    /// Where the beam starts it.
    pub fn start(&self) -> DVec2 {
        match self {
            Path::Polyline { points, .. } => points.first().copied().unwrap_or(DVec2::ZERO),
            Path::Circle { center, radius } => *center + DVec2::new(*radius, 0.0),
        }
    }

    /// Where the beam leaves it.
    pub fn end(&self) -> DVec2 {
        match self {
            Path::Polyline { points, closed } => {
                if *closed {
                    self.start()
                } else {
                    points.last().copied().unwrap_or(DVec2::ZERO)
                }
            }
            Path::Circle { .. } => self.start(),
        }
    }

    /// An open polyline can be run from either end.
    fn reversible(&self) -> bool {
        matches!(self, Path::Polyline { closed: false, .. })
    }

    fn reverse(&mut self) {
        if let Path::Polyline { points, .. } = self {
            points.reverse();
        }
    }
}

/// Paths that run together, in their own order, and how they end: a part's cut paths
/// (holes and inner cuts, then the outline last), a label's strokes, a fold.
#[derive(Clone, Debug)]
pub struct Group {
    /// Its paths. With `last_fixed`, the last one runs last; the rest are run nearest
    /// first.
    pub paths: Vec<Path>,
    /// The last path must run last (a part's outline: the part drops out when cut).
    pub last_fixed: bool,
    /// The paths keep their order (a label's strokes).
    pub keep_order: bool,
}

/// The groups of one kind, nearest first from `at`, each group's free paths nearest
/// first too (open ones entered at their nearer end). Returns the paths in running
/// order and where the beam ends. Ties go to the earlier group or path, so the order
/// is the same on every run.
pub fn order(groups: Vec<Group>, mut at: DVec2) -> (Vec<Path>, DVec2) {
    let entries = Entries::new(&groups);
    let mut left: Vec<Option<Group>> = groups.into_iter().map(Some).collect();
    let mut out = Vec::new();
    for _ in 0..left.len() {
        let Some(i) = entries.nearest(at, &left) else {
            break;
        };
        let group = left[i].take().expect("chosen groups are present");
        let (paths, end) = order_group(group, at);
        out.extend(paths);
        at = end;
    }
    (out, at)
}

/// Where each group can be entered ([`entry_points`]), in square cells, so that the
/// nearest group is found among the cells round the beam instead of among all groups
/// (a sheet's labels and folds run to thousands of groups).
struct Entries {
    origin: DVec2,
    cell: f64,
    columns: usize,
    rows: usize,
    /// Per cell, its entry points and their groups, in group order.
    cells: Vec<Vec<(usize, DVec2)>>,
}

impl Entries {
    fn new(groups: &[Group]) -> Entries {
        let points: Vec<(usize, DVec2)> = groups
            .iter()
            .enumerate()
            .flat_map(|(i, g)| entry_points(g).map(move |p| (i, p)))
            .collect();
        let (lo, hi) = crate::plane::bounds(points.iter().map(|&(_, p)| p));
        let size = (hi - lo).max(DVec2::splat(1e-9));
        // About one point a cell.
        let cell = (size.x * size.y / points.len().max(1) as f64)
            .sqrt()
            .max(size.x.max(size.y) / 1024.0);
        let columns = ((size.x / cell) as usize + 1).max(1);
        let rows = ((size.y / cell) as usize + 1).max(1);
        let mut entries = Entries {
            origin: lo,
            cell,
            columns,
            rows,
            cells: vec![Vec::new(); if points.is_empty() { 0 } else { columns * rows }],
        };
        for (i, p) in points {
            let (c, r) = entries.cell_of(p);
            entries.cells[r * columns + c].push((i, p));
        }
        entries
    }

    /// The column and row of the cell `p` falls in (clamped to the grid).
    fn cell_of(&self, p: DVec2) -> (usize, usize) {
        let q = (p - self.origin) / self.cell;
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        (clamp(q.x, self.columns), clamp(q.y, self.rows))
    }

    /// The cells of the grid at Chebyshev distance `ring` from cell (`c`, `r`).
    fn ring_cells(&self, c: i64, r: i64, ring: i64) -> impl Iterator<Item = (usize, usize)> {
        let (columns, rows) = (self.columns as i64, self.rows as i64);
        let across = (c - ring).max(0)..=(c + ring).min(columns - 1);
        ((r - ring).max(0)..=(r + ring).min(rows - 1)).flat_map(move |y| {
            // The ring's top and bottom rows whole, its other rows at both ends.
            let xs: Vec<i64> = match (y - r).abs() == ring {
                true => across.clone().collect(),
                false => [c - ring, c + ring]
                    .into_iter()
                    .filter(|&x| x >= 0 && x < columns)
                    .collect(),
            };
            xs.into_iter().map(move |x| (x as usize, y as usize))
        })
    }

    /// The group still `left` whose entry is nearest `at`, the earliest on a tie:
    /// rings of cells are searched outward until no cell beyond can hold a nearer
    /// entry (or as near, which keeps the tie to the earliest group exact).
    fn nearest(&self, at: DVec2, left: &[Option<Group>]) -> Option<usize> {
        if self.cells.is_empty() {
            return None;
        }
        let far = self.origin + self.cell * DVec2::new(self.columns as f64, self.rows as f64);
        let inner = at.clamp(self.origin, far);
        let (c, r) = self.cell_of(inner);
        let (c, r) = (c as i64, r as i64);
        let mut best: Option<(f64, usize)> = None;
        let most = self.columns.max(self.rows) as i64;
        // Rounding in the cells' bounds, far below any distance that matters.
        let slack = 1e-9 * (far - self.origin).abs().max_element().max(1.0);
        for ring in 0..=most {
            for (x, y) in self.ring_cells(c, r, ring) {
                for &(i, p) in &self.cells[y * self.columns + x] {
                    if left[i].is_none() {
                        continue;
                    }
                    // An entry at no number is as far as can be (as every group with
                    // only such entries is).
                    let d = match p.distance(at) {
                        d if d.is_nan() => f64::INFINITY,
                        d => d,
                    };
                    if best.is_none_or(|(b, j)| d < b || (d == b && i < j)) {
                        best = Some((d, i));
                    }
                }
            }
            // Every entry outside the searched square lies at least as far from `at`
            // as from `inner` (`at` moved into the grid's box, which is convex), and
            // that is at least `inner`'s distance to the square's sides.
            let square = |k: i64| self.cell * k as f64;
            let beyond = DVec2::new(
                (inner.x - self.origin.x - square(c - ring))
                    .min(self.origin.x + square(c + ring + 1) - inner.x),
                (inner.y - self.origin.y - square(r - ring))
                    .min(self.origin.y + square(r + ring + 1) - inner.y),
            );
            if best.is_some_and(|(b, _)| b < beyond.x.min(beyond.y) - slack) {
                break;
            }
        }
        best.map(|(_, i)| i)
    }
}

/// The points the beam can enter `group` at: the starts of the paths it may run
/// first, and the ends of those that run either way.
fn entry_points(group: &Group) -> impl Iterator<Item = DVec2> + '_ {
    let free = if group.last_fixed {
        &group.paths[..group.paths.len().saturating_sub(1)]
    } else {
        &group.paths[..]
    };
    let candidates = if group.keep_order || free.is_empty() {
        &group.paths[..group.paths.len().min(1)]
    } else {
        free
    };
    candidates.iter().flat_map(|p| {
        let end = p.reversible().then(|| p.end());
        std::iter::once(p.start()).chain(end)
    })
}

/// A group's paths in running order from `at`, and where the beam ends.
fn order_group(group: Group, mut at: DVec2) -> (Vec<Path>, DVec2) {
    let Group {
        mut paths,
        last_fixed,
        keep_order,
    } = group;
    if keep_order {
        let end = paths.last().map_or(at, Path::end);
        return (paths, end);
    }
    let fixed = if last_fixed { paths.pop() } else { None };
    let mut left: Vec<Option<Path>> = paths.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(left.len() + 1);
    for _ in 0..left.len() {
        let mut best: Option<(f64, usize, bool)> = None;
        for (i, p) in left.iter().enumerate() {
            let Some(p) = p else { continue };
            let forward = p.start().distance(at);
            if best.is_none_or(|(b, _, _)| forward < b) {
                best = Some((forward, i, false));
            }
            if p.reversible() {
                let backward = p.end().distance(at);
                if best.is_none_or(|(b, _, _)| backward < b) {
                    best = Some((backward, i, true));
                }
            }
        }
        let Some((_, i, reversed)) = best else { break };
        let mut path = left[i].take().expect("chosen paths are present");
        if reversed {
            path.reverse();
        }
        at = path.end();
        out.push(path);
    }
    if let Some(path) = fixed {
        at = path.end();
        out.push(path);
    }
    (out, at)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(a: (f64, f64), b: (f64, f64)) -> Path {
        Path::Polyline {
            points: vec![DVec2::new(a.0, a.1), DVec2::new(b.0, b.1)],
            closed: false,
        }
    }

    fn single(p: Path) -> Group {
        Group {
            paths: vec![p],
            last_fixed: false,
            keep_order: false,
        }
    }

    #[test]
    fn nearest_first_and_open_paths_turn_round() {
        let groups = vec![
            single(line((100.0, 0.0), (90.0, 0.0))),
            single(line((10.0, 0.0), (20.0, 0.0))),
            single(line((50.0, 0.0), (40.0, 0.0))),
        ];
        let (paths, end) = order(groups, DVec2::ZERO);
        let starts: Vec<DVec2> = paths.iter().map(Path::start).collect();
        assert_eq!(
            starts,
            [
                DVec2::new(10.0, 0.0),
                DVec2::new(40.0, 0.0),
                DVec2::new(90.0, 0.0)
            ]
        );
        assert_eq!(end, DVec2::new(100.0, 0.0));
    }

    /// The nearest group by measuring every one, the earliest on a tie: what the
    /// cells must find.
    fn nearest_by_every_group(groups: &[Option<Group>], at: DVec2) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        for (i, g) in groups.iter().enumerate() {
            let Some(g) = g else { continue };
            let d = entry_points(g)
                .map(|p| p.distance(at))
                .fold(f64::INFINITY, f64::min);
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, i));
            }
        }
        best.map(|(_, i)| i)
    }

    /// Groups of paths with corners on a lattice (so that equal distances, ties, are
    /// common), on one line when `flat`, some without paths and one at no number.
    fn lattice_groups(rng: &mut crate::rng::SplitMix64, count: usize, flat: bool) -> Vec<Group> {
        let point = |rng: &mut crate::rng::SplitMix64| {
            let x = rng.below(400) as f64 * 0.25;
            let y = if flat {
                3.0
            } else {
                rng.below(400) as f64 * 0.25
            };
            DVec2::new(x, y)
        };
        (0..count)
            .map(|k| {
                let paths: Vec<Path> = match k % 11 {
                    10 => Vec::new(),
                    9 if k == 9 => vec![Path::Circle {
                        center: DVec2::new(f64::NAN, 1.0),
                        radius: 1.0,
                    }],
                    _ => (0..1 + k % 3)
                        .map(|j| Path::Polyline {
                            points: vec![point(rng), point(rng)],
                            closed: (k + j) % 4 == 0,
                        })
                        .collect(),
                };
                Group {
                    paths,
                    last_fixed: k % 5 == 1,
                    keep_order: k % 7 == 3,
                }
            })
            .collect()
    }

    #[test]
    fn the_cells_find_the_group_every_group_measured_finds() {
        let mut rng = crate::rng::SplitMix64::new(7);
        for trial in 0..60 {
            let count = 1 + (trial % 30) * 7;
            let groups = lattice_groups(&mut rng, count, trial >= 30);
            let entries = Entries::new(&groups);
            let mut left: Vec<Option<Group>> = groups.into_iter().map(Some).collect();
            // From outside the groups' box first, then from where each group ends.
            let mut at = DVec2::new(-50.0, 130.0);
            while let Some(expected) = nearest_by_every_group(&left, at) {
                let found = entries.nearest(at, &left);
                match found {
                    // Groups without paths are never entered: nothing is left to run.
                    None => {
                        assert!(left.iter().flatten().all(|g| g.paths.is_empty()));
                        break;
                    }
                    Some(i) => assert_eq!(i, expected, "trial {trial} from {at}"),
                }
                let group = left[expected].take().unwrap();
                at = group.paths.first().map_or(at, |p| p.end());
            }
        }
    }

    #[test]
    fn an_outline_runs_after_its_holes() {
        let outline = Path::Polyline {
            points: vec![DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(10.0, 10.0)],
            closed: true,
        };
        let hole = Path::Circle {
            center: DVec2::new(6.0, 3.0),
            radius: 1.0,
        };
        let group = Group {
            paths: vec![hole.clone(), outline.clone()],
            last_fixed: true,
            keep_order: false,
        };
        let (paths, _) = order(vec![group], DVec2::ZERO);
        assert_eq!(paths, [hole, outline]);
    }

    #[test]
    fn speeds_parse_with_defaults_for_the_rest() {
        let s = Speeds::parse("cut=10, engrave=80").unwrap();
        assert_eq!(
            (s.cut, s.score, s.engrave, s.travel),
            (10.0, 50.0, 80.0, 300.0)
        );
        assert!(Speeds::parse("cut=0").is_err());
        assert!(Speeds::parse("fold=3")
            .unwrap_err()
            .contains("unknown kind"));
    }
}
