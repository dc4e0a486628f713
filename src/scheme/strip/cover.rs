//! The strips of a surface within a tolerance: each patch covered by one strip where
//! that is within, else cut into sectors, grown in bands from its lower curve up, or
//! split, until no strip strays.

use glam::DVec3;
use rayon::prelude::*;

use super::band::{strip_soup, Strip};
use super::conform::{conform, runs_back};
use super::distance::distance_beyond;
use super::patch::{CoverSettings, Patch, RunsBack};
use super::sectors::Sectors;
use super::slices::{Region, Slices};
use super::surface::Triangles;
use super::welded::Welded;

/// Strips covering a surface, each within the distance asked of the part of the
/// surface it covers, both ways.
pub(super) struct Cover {
    /// The strips, their outlines meeting point for point.
    pub(super) strips: Vec<Strip>,
    /// The largest distance measured between a strip and the part it covers, either way.
    pub(super) deviation: f64,
}

/// The part of the bound a curve's points may stray from it: the rest is the width of
/// the bands. (Along a sphere of radius R, a strip w wide between points a apart
/// strays about (a² + w²) / 8R.)
const SIMPLIFY: f64 = 0.15;

/// How many bands are tried for each band grown.
const MOST_TRIES: usize = 12;

/// How many times a part of the surface is split before the bound is given up on.
const MOST_SPLITS: usize = 40;

/// How [`CoverSettings::strips`] ends the error of a band that strays from the surface however
/// narrow it is split: the one failure a larger bound can mend.
pub(super) const STAYS_OFF: &str = "mm from the surface";

/// The strips of `surface` between levels of `field`, each within `tolerance` of the
/// part it covers (either way, measured at points `tolerance / 3` apart, allowing for
/// the points between). From one band over each part of the surface, a band whose
/// strip strays is cut across into sectors about `sector_length` long if it is longer
/// (a ring round a body strays where the body is sharpest, and the rest of it need not
/// be split with it), grown in bands from its lower curve up where it is a sector or a
/// cap round a pole, else split in halves (quarters where no one strip could be built,
/// as on a closed part); each sector and band on its own, until none strays. `ridged`
/// tells whether the field has ridges (a distance's,
/// [`field_of`](super::field::field_of)), `runs_back` when a strip that may fold is
/// found running back over itself.
pub(super) fn strips_ridged(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
    ridged: bool,
    runs_back: RunsBack,
) -> Result<Cover, String> {
    let (lo, hi) = field
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return Err("the surface has no points".into());
    }
    let span = (hi - lo).max(1e-9);
    let spacing = tolerance / 3.0;
    let cover = CoverSettings {
        ridged,
        within: tolerance,
        simplify: SIMPLIFY * tolerance,
        spacing,
        sector_length,
        span,
        runs_back,
    };
    let whole = Patch {
        surface: surface.clone(),
        values: field.to_vec(),
        kept: vec![true; surface.points.len()],
        ends: [lo - 1e-3 * span, hi + 1e-3 * span],
    };
    let covered = cover.strips(&whole, Depth::default())?;
    let deviation = covered.iter().map(|c| c.1).fold(0.0, f64::max);
    let mut strips: Vec<Strip> = covered.into_iter().map(|c| c.0).collect();
    conform(&mut strips);
    Ok(Cover { strips, deviation })
}

/// How deep a patch lies in the splitting, and whether its strips may fold over their
/// outline (where no band of it keeps from that).
#[derive(Clone, Copy, Debug, Default)]
struct Depth {
    splits: usize,
    folds: bool,
}

impl Depth {
    fn deeper(self) -> Depth {
        Depth {
            splits: self.splits + 1,
            ..self
        }
    }
}

/// A strip and the distance measured between it and its part of the surface.
type MeasuredStrip = (Strip, f64);

impl CoverSettings {
    /// The strips of `patch`: one if it is within, else those of its sectors or of
    /// the bands it is split into.
    fn strips(&self, patch: &Patch, depth: Depth) -> Result<Vec<MeasuredStrip>, String> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let one = vec![lo - margin, hi + margin];
        let (whole, kept) = self.sliced(patch, one);
        let regions = whole.regions();
        if regions.len() > 1 {
            return self.each(&whole, &regions, &kept, depth.deeper());
        }
        let Some(region) = regions.first() else {
            return Ok(Vec::new());
        };
        let narrow = hi - lo < 1e-6 * self.span || depth.splits >= MOST_SPLITS;
        let deviation = match self.measured(&whole, region, &kept, depth.folds, f64::INFINITY) {
            Ok((strip, d)) if d <= self.within => return Ok(vec![(strip, d)]),
            Ok((_, d)) if narrow => {
                return Err(format!(
                    "a band of the field {lo}..{hi} stays {d:.3} {STAYS_OFF}"
                ))
            }
            Ok((_, d)) => d,
            Err(why) if narrow => return Err(why),
            Err(_) => f64::INFINITY,
        };
        // The first band grown's width, guessed from how far the patch's one strip
        // strayed: a strip's distance grows about as its width squared.
        let guess = match deviation.is_finite() {
            true => (hi - lo) * (self.within / deviation).sqrt(),
            false => 0.25 * (hi - lo),
        };
        let folding = Depth {
            folds: true,
            ..depth
        };
        match self.sectors(patch) {
            Sectors::Cut(sectors) => {
                let deeper = depth.deeper();
                let covered = flattened(sectors.par_iter().map(|s| self.strips(s, deeper)))?;
                if joined(&covered) {
                    return Ok(covered);
                }
                // A sector's strip folded over onto its neighbour (round a sharp tip):
                // this band is cut into sectors twice as long instead, and once they
                // would be longer than it, covered whole.
                let longer = CoverSettings {
                    sector_length: 2.0 * self.sector_length,
                    ..*self
                };
                return longer.strips(patch, depth);
            }
            Sectors::Short => {
                if let Some(covered) = self.grown(patch, guess) {
                    return Ok(covered);
                }
                // Every strip of some band folds over its outline (round a saddle):
                // split it in two, taking such strips.
                return self.split(patch, deviation, folding);
            }
            // A cap grows from its pole (or up to it) in rings rather than being split:
            // split, its innermost band would be no wider than a cap can be.
            Sectors::Cap => {
                if let Some(covered) = self.grown(patch, guess) {
                    return Ok(covered);
                }
            }
            // Round a ridge of a distance field (where the rings round two rims meet)
            // the levels have corners, and a band's strip folds there however narrow.
            Sectors::Unfit if self.ridged => return self.split(patch, deviation, folding),
            Sectors::Unfit => {}
        }
        self.split(patch, deviation, depth)
    }

    /// The strips of `patch` split in equal bands: in two where its one strip was
    /// measured, four where no one strip could be built (a closed part, or one whose
    /// strip would fold over its outline). Only halves: a strip strays where the
    /// surface is sharpest, so more bands guessed from its distance would be as narrow
    /// everywhere else, and bands once split are never joined.
    fn split(
        &self,
        patch: &Patch,
        deviation: f64,
        depth: Depth,
    ) -> Result<Vec<MeasuredStrip>, String> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let parts = match deviation.is_finite() {
            true => 2,
            false => 4,
        };
        let mut sorted = patch.values.clone();
        sorted.sort_by(f64::total_cmp);
        let mut levels = vec![lo - margin];
        levels.extend((1..parts).map(|k| {
            let t = k as f64 / parts as f64;
            off_values(lo + t * (hi - lo), &sorted)
        }));
        levels.push(hi + margin);
        let (split, kept) = self.sliced(patch, levels);
        self.each(&split, &split.regions(), &kept, depth.deeper())
    }

    /// `patch` cut along `levels` (its first and last outside it), and the points its
    /// strips keep: those its neighbours keep, and the fewest along each new curve.
    fn sliced(&self, patch: &Patch, levels: Vec<f64>) -> (Slices, Vec<bool>) {
        let slices = Slices::new(&patch.surface, &patch.values, levels, Some(patch.ends));
        let kept = slices.kept(self.simplify, &|v| patch.kept[v as usize]);
        (slices, kept)
    }

    /// The strips of each of `regions`, on its own (in parallel, in their order).
    fn each(
        &self,
        slices: &Slices,
        regions: &[Region],
        kept: &[bool],
        depth: Depth,
    ) -> Result<Vec<MeasuredStrip>, String> {
        flattened(
            regions
                .par_iter()
                .map(|r| self.strips(&slices.patch(r, kept), depth)),
        )
    }

    /// The strip of `region` and the distance between them, either way (or, once it
    /// passes `limit`, some distance beyond it); an error for a strip that folds over
    /// its outline unless `folds`.
    fn measured(
        &self,
        slices: &Slices,
        region: &Region,
        kept: &[bool],
        folds: bool,
        limit: f64,
    ) -> Result<MeasuredStrip, String> {
        let strip = slices.strip(region, kept, !folds)?;
        if strip.triangles.is_empty() {
            return Err(format!(
                "a region between levels {} and {} is too small for a triangle",
                region.band,
                region.band + 1
            ));
        }
        // Allowed to fold, a strip may still not run back over its own triangles
        // (round a bridge between two loops): it could not be welded to its neighbours.
        if folds && self.runs_back == RunsBack::Made && runs_back(&strip) {
            return Err(format!(
                "the strip of a region between levels {} and {} runs back over itself",
                region.band,
                region.band + 1
            ));
        }
        if !folds && slices.folds(region, &strip) {
            return Err(format!(
                "the strip of a region between levels {} and {} folds over its outline",
                region.band,
                region.band + 1
            ));
        }
        let soup = strip_soup(std::slice::from_ref(&strip));
        let measure = |from: &[[DVec3; 3]], to: &[[DVec3; 3]]| {
            distance_beyond(from, to, self.spacing, self.within, limit)
        };
        let out = measure(&soup, &region.triangles);
        if out > limit {
            return Ok((strip, out));
        }
        let back = measure(&region.triangles, &soup);
        Ok((strip, out.max(back)))
    }

    /// The strips of `patch` in bands from its lower curve up, each as wide as keeps
    /// its strips within (found by widening and halving the step from `first`, a
    /// guess), the last up to its upper curve.
    fn grown(&self, patch: &Patch, first: f64) -> Option<Vec<MeasuredStrip>> {
        let [lo, hi] = patch.ends;
        let mut sorted = patch.values.clone();
        sorted.sort_by(f64::total_cmp);
        let least = 1e-6 * self.span;
        let mut covered = Vec::new();
        let mut from = lo;
        let mut step = first.max(least);
        while from < hi {
            // The widest band found within so far, and the narrowest found not.
            let mut within: Option<(f64, Vec<MeasuredStrip>)> = None;
            let mut beyond = f64::INFINITY;
            for _ in 0..MOST_TRIES {
                let to = match from + step >= hi - 0.1 * step {
                    true => hi,
                    false => off_values(from + step, &sorted),
                };
                match self.band_within(patch, from, to) {
                    Some(strips) => within = Some((to, strips)),
                    None => beyond = beyond.min(to),
                }
                let reached = within.as_ref().map(|w| w.0);
                step = match (reached, beyond.is_finite()) {
                    (Some(to), _) if to >= hi => break,
                    (None, _) => 0.6 * (to - from),
                    (Some(to), false) => 1.5 * (to - from),
                    // Within a tenth of the widest band that can be: enough.
                    (Some(to), true) if beyond - to < 0.1 * (to - from) => break,
                    (Some(to), true) => 0.5 * (to - from + beyond - from),
                };
                if within.is_none() && step < least {
                    break;
                }
            }
            // A thin band left at the top: two bands of half the rest instead.
            let within = match within {
                Some((to, _)) if to < hi && hi - to < 0.5 * (to - from) => {
                    let half = off_values(0.5 * (from + hi), &sorted);
                    let balanced = self.band_within(patch, from, half);
                    balanced.map(|strips| (half, strips)).or(within)
                }
                within => within,
            };
            let (to, strips) = within?;
            step = to - from;
            covered.extend(strips);
            from = to;
        }
        Some(covered)
    }

    /// The strips of the band of `patch` between values `from` and `to`, if every one
    /// is within.
    fn band_within(&self, patch: &Patch, from: f64, to: f64) -> Option<Vec<MeasuredStrip>> {
        let [lo, hi] = patch.ends;
        let margin = 1e-3 * (hi - lo);
        let mut levels = vec![lo - margin];
        levels.extend([from, to].into_iter().filter(|&v| v > lo && v < hi));
        levels.push(hi + margin);
        let band = usize::from(from > lo);
        let (slices, kept) = self.sliced(patch, levels);
        let regions = slices.regions_of(band);
        let measured: Vec<Option<MeasuredStrip>> = regions
            .par_iter()
            .map(|r| {
                let covered = self.measured(&slices, r, &kept, false, self.within).ok();
                covered.filter(|c| c.1 <= self.within)
            })
            .collect();
        measured.into_iter().collect()
    }
}

/// Whether the strips of `covered` join into one surface where they meet (none folded
/// over onto another).
fn joined(covered: &[MeasuredStrip]) -> bool {
    let mut strips: Vec<Strip> = covered.iter().map(|c| c.0.clone()).collect();
    conform(&mut strips);
    Welded::new(&strips).is_ok()
}

/// The results of `parts`, in order, each part's strips one after the other.
fn flattened(
    parts: impl IndexedParallelIterator<Item = Result<Vec<MeasuredStrip>, String>>,
) -> Result<Vec<MeasuredStrip>, String> {
    let parts: Vec<Result<Vec<MeasuredStrip>, String>> = parts.collect();
    let mut all = Vec::new();
    for part in parts {
        all.extend(part?);
    }
    Ok(all)
}

/// `level`, moved up past any value of the field exactly at it (a cut must cross
/// edges between their ends, never at a corner).
fn off_values(mut level: f64, sorted: &[f64]) -> f64 {
    while sorted.binary_search_by(|v| v.total_cmp(&level)).is_ok() {
        level = level.next_up();
    }
    level
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::field::{field_of, Closed};
    use crate::scheme::strip::test_shapes::{
        self, along, check_strips, check_strips_cut, sphere, tube,
    };

    #[test]
    fn an_open_tube_between_its_rims_is_one_strip_and_a_cone_too() {
        let tube = tube(32, 6, 120.0, |_| 40.0);
        let field = field_of(&tube, Closed::Harmonic).unwrap();
        // Held at 0 and 1 on its rims (either way round), linear in between.
        let up = field[0] == 0.0;
        for (p, f) in tube.points.iter().zip(&field) {
            let linear = if up { p.z / 120.0 } else { 1.0 - p.z / 120.0 };
            assert!((f - linear).abs() < 1e-9, "{p} {f}");
        }
        assert_eq!(check_strips(&tube, &field, 1.0), 1);
        let cone = test_shapes::tube(32, 6, 120.0, |h| 60.0 - 0.3 * h);
        assert_eq!(
            check_strips(&cone, &field_of(&cone, Closed::Harmonic).unwrap(), 1.0),
            1
        );
    }

    #[test]
    fn strips_of_a_sphere_stay_within_the_bound_unroll_exactly_and_share_their_curves() {
        // A field along a tilted axis: its levels cross the grid's edges anywhere.
        let sphere = sphere(100.0, 48, 24);
        let strips = check_strips(&sphere, &along(&sphere, DVec3::new(0.3, 0.2, 0.93)), 2.0);
        assert!(strips >= 3, "{strips}");
        // Between two poles, the same.
        let field = field_of(&sphere, Closed::Harmonic).unwrap();
        let whole = check_strips(&sphere, &field, 2.0);
        // Rings longer than 200 mm cut across into sectors, each split on its own.
        let cut = check_strips_cut(&sphere, &field, 2.0, 200.0);
        assert!(cut > whole, "{cut} sectors and bands, {whole} rings");
    }

    #[test]
    fn strips_folded_over_their_neighbour_do_not_join() {
        let at = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let strip = |points: Vec<DVec3>| -> MeasuredStrip {
            let triangles = vec![[0, 1, 2]];
            (Strip { points, triangles }, 0.0)
        };
        let below = strip(vec![at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0)]);
        // Beyond their shared edge, and folded back over it onto the first strip.
        let beside = strip(vec![at(1.0, 1.0), at(1.0, 0.0), at(2.0, 0.5)]);
        let folded = strip(vec![at(1.0, 0.0), at(1.0, 1.0), at(0.5, 0.2)]);
        assert!(joined(&[below.clone(), beside]));
        assert!(!joined(&[below, folded]));
    }
}
