//! How close the strips keep to the model: within the bound of the mesh they cover,
//! narrowed where that mesh was simplified from the model as given, and what to try
//! where no strips keep within it.

use glam::DVec3;

use super::band::strip_soup;
use super::cover::{strips_ridged, Cover, STAYS_OFF};
use super::distance::{distance_beyond, one_way_distance};
use super::field::{evened, field_of, ridged, Closed};
use super::patch::RunsBack;
use super::surface::{rims, Triangles};
use super::welded::Welded;
use crate::scheme::SchemeError;

/// The strips of `surface` within `bound` of the model (of `unsimplified`, where the
/// surface was simplified from it), with `closed` parts' field, and the largest
/// distance measured.
pub(super) fn cover_within(
    surface: &Triangles,
    closed: Closed,
    bound: f64,
    unsimplified: Option<&[[DVec3; 3]]>,
    sector_length: f64,
) -> Result<(WeldedCover, f64), SchemeError> {
    let ridged = ridged(surface, closed);
    let surface = match ridged {
        true => surface.rims_apart(),
        false => surface.clone(),
    };
    let field = evened(
        &surface,
        &field_of(&surface, closed).map_err(SchemeError::Model)?,
    );
    let cover = |tolerance: f64| welded_cover(&surface, &field, tolerance, sector_length, ridged);
    match unsimplified {
        None => {
            let covered = cover(bound)?;
            let measured = covered.cover.deviation;
            Ok((covered, measured))
        }
        Some(unsimplified) => within_unsimplified(bound, &surface.soup(), unsimplified, &cover),
    }
}

/// The strips of a surface within a tolerance, welded.
pub(super) struct WeldedCover {
    pub(super) cover: Cover,
    pub(super) welded: Welded,
    /// Bands were kept whole: their sectors' strips overlapped.
    pub(super) whole_bands: bool,
    /// The tolerance the strips were kept within.
    pub(super) tolerance: f64,
}

/// The strips of `surface` within `tolerance` ([`strips_ridged`]), welded into one
/// surface; where the sectors' strips of neighbouring bands overlap, every band whole.
fn welded_cover(
    surface: &Triangles,
    field: &[f64],
    tolerance: f64,
    sector_length: f64,
    ridged: bool,
) -> Result<WeldedCover, SchemeError> {
    let within = |sector_length: f64, runs_back: RunsBack| {
        strips_ridged(surface, field, tolerance, sector_length, ridged, runs_back).map_err(|e| {
            let fix = cover_fix(surface, &e);
            SchemeError::Model(format!(
                "no strips within {tolerance:.3} mm of the model: {e}; {fix}"
            ))
        })
    };
    let mut cover = within(sector_length, RunsBack::Welded)?;
    let mut welded = Welded::new(&cover.strips);
    // Each band's sectors were checked to join as they were cut; where strips of
    // neighbouring bands still overlap, every band is kept whole instead, and where
    // they still do not join, a strip that runs back over itself is split as it is
    // made. The first failure is the one told.
    let mut whole_bands = false;
    let mut tries = Vec::new();
    if sector_length.is_finite() {
        tries.push((f64::INFINITY, RunsBack::Welded));
    }
    tries.push((sector_length, RunsBack::Made));
    for (length, runs_back) in tries {
        if welded.is_ok() {
            break;
        }
        let Ok(again) = within(length, runs_back) else {
            continue;
        };
        if let Ok(joined) = Welded::new(&again.strips) {
            whole_bands = length > sector_length;
            (cover, welded) = (again, Ok(joined));
        }
    }
    Ok(WeldedCover {
        welded: welded.map_err(SchemeError::Model)?,
        cover,
        whole_bands,
        tolerance,
    })
}

/// What to do where no strips cover `surface`, given the reason `why`: a larger bound where
/// a band strays however narrow; elsewhere (a band whose strip folds over its outline
/// round a sharp corner however narrow, as on coarse or holed models) a larger bound
/// changes nothing, and the net scheme's islands build.
fn cover_fix(surface: &Triangles, why: &str) -> &'static str {
    match (why.ends_with(STAYS_OFF), rims(surface).is_empty()) {
        (true, _) => "a larger --max-deviation may reach",
        (false, true) => "a larger --max-deviation does not change that: use --scheme net",
        (false, false) => {
            "a larger --max-deviation does not change that: close the model's holes (--fill-holes) or use --scheme net"
        }
    }
}

/// How much further than the estimate of what the strips strayed a narrower try
/// narrows them: the narrower strips' worst point moves.
const NARROWER_MARGIN: f64 = 1.5;

/// How many narrower tries are made before the strips are kept within what the
/// simplification leaves of the bound (which holds, but makes them much narrower).
const MOST_NARROWER: usize = 3;

/// The least share of the bound the strips may be kept within of a simplified mesh:
/// narrower, they would be more than twice as many, and a simplification that leaves
/// them less is named as the fault.
const LEAST_SHARE: f64 = 0.25;

/// Strips within `bound` of `unsimplified` both ways, with the largest distance
/// measured. They are first kept within `bound` of the simplified mesh (`cover`); the
/// simplification's own error adds to theirs, so where they stray further from the
/// model as given, they are kept within less by what they strayed (sampled finely,
/// with a margin), and where that is not enough, within the bound less the largest
/// distance between `simplified` and `unsimplified`, which the triangle inequality
/// makes enough.
fn within_unsimplified(
    bound: f64,
    simplified: &[[DVec3; 3]],
    unsimplified: &[[DVec3; 3]],
    cover: &dyn Fn(f64) -> Result<WeldedCover, SchemeError>,
) -> Result<(WeldedCover, f64), SchemeError> {
    let spacing = bound / 3.0;
    // A bound that holds at every point, refined until settled against `within`.
    let beyond = |a: Soup, b: Soup, within: f64| {
        both_ways(a, b, &|from, to| {
            distance_beyond(from, to, spacing, within, f64::INFINITY)
        })
    };
    // The largest distance at samples a quarter as far apart: at most the true one.
    let sampled =
        |a: Soup, b: Soup| both_ways(a, b, &|from, to| one_way_distance(from, to, spacing / 4.0));
    let to_model =
        |covered: &WeldedCover| beyond(&strip_soup(&covered.cover.strips), unsimplified, bound);
    // A narrower try that finds no strips says why it was narrower.
    let narrowed = |tolerance: f64| {
        cover(tolerance).map_err(|e| match e {
            SchemeError::Model(why) => {
                // `welded_cover` names the mesh it covered "the model"; here it is the
                // simplified one.
                let why = why.replacen("of the model:", "of the simplified model:", 1);
                SchemeError::Model(format!(
                    "{why}, or less simplification (more --target-edges or --target-faces, or none): the strips were kept within {tolerance:.3} mm of the simplified model, not {bound:.3} mm, because it strays from the model as given"
                ))
            }
            other => other,
        })
    };
    let first = cover(bound)?;
    let measured = to_model(&first);
    if measured <= bound {
        return Ok((first, measured));
    }
    // Narrower tries, each by what the one before strayed beyond the bound (where the
    // finer samples find no point beyond it, the bound's own measure does): a band's
    // worst point moves with its width, so one narrowing may not be enough.
    let strayed = |covered: &WeldedCover, measured: f64| match sampled(
        &strip_soup(&covered.cover.strips),
        unsimplified,
    ) {
        finer if finer > bound => finer,
        _ => measured,
    };
    let mut tolerance = bound;
    let mut beyond_by = strayed(&first, measured) - bound;
    drop(first);
    let mut last_try = None;
    for _ in 0..MOST_NARROWER {
        let narrower = tolerance - NARROWER_MARGIN * beyond_by;
        if narrower < LEAST_SHARE * bound {
            break;
        }
        let covered = narrowed(narrower)?;
        let measured = to_model(&covered);
        if measured <= bound {
            return Ok((covered, measured));
        }
        beyond_by = strayed(&covered, measured) - bound;
        tolerance = narrower;
        last_try = Some((covered, measured));
    }
    let simplification = simplification_distance(bound, simplified, unsimplified);
    let assured = bound - simplification;
    // Strips within `assured` of the simplified mesh keep the bound to the model as
    // given (the triangle inequality), even where the measured bound, which adds the
    // samples' reach, says a little more.
    let kept = |covered: WeldedCover, measured: f64| {
        let measured = measured.min(covered.cover.deviation + simplification);
        (covered, measured)
    };
    match last_try {
        Some((covered, measured)) if covered.cover.deviation <= assured => {
            return Ok(kept(covered, measured));
        }
        _ => {}
    }
    if let Some(refusal) = too_simplified(bound, simplification, true) {
        return Err(refusal);
    }
    let last = narrowed(assured)?;
    let measured = to_model(&last);
    Ok(kept(last, measured))
}

/// Triangles, by their corners.
type Soup<'a> = &'a [[DVec3; 3]];

/// The larger of `one_way` from `a` to `b` and from `b` to `a`, each on its own thread.
fn both_ways(a: Soup, b: Soup, one_way: &(dyn Fn(Soup, Soup) -> f64 + Sync)) -> f64 {
    let (out, back) = rayon::join(|| one_way(a, b), || one_way(b, a));
    out.max(back)
}

/// How far `simplified` and `unsimplified` lie apart, both ways: a bound that holds at
/// every point (samples a third of `bound` apart), refined against what samples a
/// quarter as far apart find, so that it comes close to it.
pub(super) fn simplification_distance(bound: f64, simplified: Soup, unsimplified: Soup) -> f64 {
    let spacing = bound / 3.0;
    let sampled = both_ways(simplified, unsimplified, &|from, to| {
        one_way_distance(from, to, spacing / 4.0)
    });
    both_ways(simplified, unsimplified, &|from, to| {
        distance_beyond(from, to, spacing, 1.05 * sampled, f64::INFINITY)
    })
}

/// The refusal of a simplification that lies `simplification` from the model as given,
/// where that leaves the strips less than [`LEAST_SHARE`] of `bound`; with the bound
/// that would leave them enough where `larger_bound_helps`.
pub(super) fn too_simplified(
    bound: f64,
    simplification: f64,
    larger_bound_helps: bool,
) -> Option<SchemeError> {
    let larger = match larger_bound_helps {
        true => format!(
            " or allow at least {:.2} mm",
            simplification / (1.0 - LEAST_SHARE)
        ),
        false => String::new(),
    };
    (bound - simplification < LEAST_SHARE * bound).then(|| {
        SchemeError::Options(format!(
            "the simplified model lies up to {simplification:.2} mm from the model as given, which leaves the strips too little of --max-deviation ({bound:.2} mm): simplify less (more --target-edges or --target-faces, or none){larger}"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::strip::band::Strip;

    /// A 25 mm square at height `z`, as two triangles.
    fn square_at(z: f64) -> Vec<[DVec3; 3]> {
        let p =
            [(0.0, 0.0), (25.0, 0.0), (25.0, 25.0), (0.0, 25.0)].map(|(x, y)| DVec3::new(x, y, z));
        vec![[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    }

    /// Strips over a model as given (a square at height 0) built for a simplified
    /// one (the square 4 mm up), each try's strips `strays(tolerance)` above that:
    /// the tolerances the strips were asked to keep, the one they were kept within
    /// and the distance measured to the model as given.
    fn narrowed_tries(strays: impl Fn(f64) -> f64 + Sync) -> (Vec<f64>, f64, f64) {
        let asked = std::sync::Mutex::new(Vec::new());
        let cover = |tolerance: f64| {
            asked.lock().unwrap().push(tolerance);
            let deviation = strays(tolerance);
            assert!(deviation <= tolerance, "{deviation} within {tolerance}");
            let square = square_at(4.0 + deviation);
            let strips = vec![Strip {
                points: vec![square[0][0], square[0][1], square[0][2], square[1][2]],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            }];
            Ok(WeldedCover {
                welded: Welded::new(&strips).unwrap(),
                cover: Cover { strips, deviation },
                whole_bands: false,
                tolerance,
            })
        };
        let (covered, measured) =
            within_unsimplified(10.0, &square_at(4.0), &square_at(0.0), &cover).unwrap();
        (asked.into_inner().unwrap(), covered.tolerance, measured)
    }

    #[test]
    fn strips_that_stray_from_the_model_as_given_are_narrowed_up_to_three_times() {
        // Each try narrower by 1.5 times what the one before strayed beyond 10 mm:
        // 7 + 4 strays by 1, 6.5 + 4 by 0.5, 6.2 + 4 by 0.2, and 5.8 + 4 is within.
        let table = |t: f64| match t {
            t if t > 9.0 => 7.0,
            t if t > 8.0 => 6.5,
            t if t > 7.6 => 6.2,
            _ => 5.8,
        };
        let (asked, kept, measured) = narrowed_tries(table);
        let expected = [10.0, 8.5, 7.75, 7.45];
        assert_eq!(asked.len(), expected.len(), "{asked:?}");
        for (a, e) in asked.iter().zip(expected) {
            assert!((a - e).abs() < 1e-9, "{asked:?}");
        }
        assert!(
            (kept - 7.45).abs() < 1e-9 && measured <= 10.0,
            "{kept} {measured}"
        );
        // Where the third narrower try strays too, the strips are kept within the
        // bound less the simplification's 4 mm (and a little for its measure).
        let (asked, kept, measured) = narrowed_tries(|t| table(t).max(6.5).min(t - 0.3));
        assert_eq!(asked.len(), 5, "{asked:?}");
        assert!(kept < 6.0 && kept > 5.7, "{asked:?}");
        assert!(measured <= 10.0, "{measured}");
    }
}
