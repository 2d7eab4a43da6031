//! Terms chosen by re-simulation where the regression's choice loses its runs: the rates of a
//! record sampled coarsely (a census read once a year) carry the quadrature's error, which a
//! regression explains with spurious terms; the equations then fit the rates and lose the
//! run. The regression's terms and the best subsets of each size per equation are each
//! re-simulated (refined by output error first where the rows are coarse) and scored by the
//! Bayesian information criterion of their re-simulation's error; the best is kept where it
//! follows the runs as long as its own motion allows, and twice as long as the regression's.

use crate::data::Frame;
use crate::identify::{identify_model, store_fit, Fit, IdentifiedModel, ModelIdentification};
use crate::model::Model;
use crate::plugin::Check;
use crate::select::{Backend, BestSubset, Selection};

use super::retrace::retraced;

/// The most combinations re-simulated, fewest terms first: each is a re-simulation of every
/// run (where the rows are coarse, after an identification and a refinement: 0.1 s for the
/// 36 of a census of 61 years), so the search stays within some hundred of them.
const MOST_COMBINATIONS: usize = 200;

/// How many times the share of each rate the regression's terms leave unexplained the kept
/// ones may leave (a census read yearly: 3.7 and 6.7 times, the regression's spurious terms
/// explaining the quadrature's error; terms that followed the hyperchaotic Rössler's noisy run
/// by chance, ẏ's two of R² 0.935 for the regression's three true ones, were kept without it).
const EXPLAINED: f64 = 10.0;

/// How many times as long as the regression's terms the kept ones must follow the runs.
const LONGER: f64 = 2.0;

/// The most seconds the best-subset search of each equation takes (the sizes beyond are the
/// best found, not proven best, and still re-simulated).
const SEARCH_SECONDS: f64 = 5.0;

/// The largest size of one equation's subsets that [`MOST_COMBINATIONS`] can reach among
/// `equations`: the combinations of up to T terms in all, each equation at least one, are
/// C(T, equations).
fn largest_size(equations: usize) -> usize {
    if equations == 0 {
        return 1;
    }
    let combinations =
        |total: usize| -> f64 { (0..equations).map(|i| (total - i) as f64 / (i + 1) as f64).product() };
    let mut total = equations;
    while combinations(total + 1) <= MOST_COMBINATIONS as f64 {
        total += 1;
    }
    (total + 1).saturating_sub(equations).max(1)
}

/// Each identified equation's best subset of every size: its candidates' names, and per size
/// the fit that keeps that size.
struct Path {
    name: String,
    fit: Fit,
    /// The largest size with a fit (the steps of the best-subset search).
    sizes: usize,
}

impl Path {
    /// The fit with the best subset of `size` terms.
    fn at(&self, size: usize) -> Fit {
        let s = &self.fit.selection;
        let mut fit = self.fit.clone();
        fit.selection = Selection::from_steps(
            &s.backend,
            s.rows,
            &s.candidates,
            s.steps.clone(),
            size,
            s.stop.clone(),
            vec![],
        );
        fit
    }
}

/// What the search re-simulated and what it kept.
pub(crate) struct Search {
    /// The combination kept where it is not the regression's: identified with its terms forced.
    pub kept: Option<IdentifiedModel>,
    /// The combinations tried.
    pub tried: usize,
    /// The most terms of a combination tried.
    pub most_terms: usize,
    /// Whether each combination was judged refined (rows too coarse for their rates).
    pub refined: bool,
    /// Whether the best-scored combination is the regression's own terms.
    pub own_best: bool,
}

/// One combination scored: its fits per equation, its criterion, the model scored and, where
/// it was made for the score, its identification with its terms forced.
struct Scored {
    fits: Vec<Fit>,
    criterion: f64,
    model: Model,
    forced: Option<IdentifiedModel>,
}

/// Whether `checks` (a system's) say the equations lose their runs: a retrace check failed.
fn lose_their_runs(checks: &[Check]) -> bool {
    checks.iter().any(|c| super::retrace::is_retrace(c) && !c.passed)
}

/// Where `identified` (from `model`, on `frames` as `how` prepared them) loses its runs
/// (`checks`): among the regression's own terms and the best subsets of each size per
/// equation (fewest terms first, up to [`MOST_COMBINATIONS`]), the combination of the lowest
/// information criterion of its re-simulation's error; kept, identified again with its terms
/// forced and the others excluded (so the model written re-identifies as chosen), where it
/// is not the regression's and follows the runs as long as its own motion allows and twice as
/// long as the regression's terms. Where the
/// rows are too coarse for the rates, whose quadrature biases every coefficient (a yearly
/// census's by 2 %: the right terms then lose the run too), each combination is judged
/// refined by output error. `None` where the checks pass or the search cannot be made.
pub(crate) fn by_resimulation(
    model: &Model,
    identified: &IdentifiedModel,
    frames: &[Frame],
    how: &ModelIdentification<'_>,
    checks: &[Check],
) -> Option<Search> {
    if !lose_their_runs(checks) || identified.fits.is_empty() {
        return None;
    }
    let names: Vec<&String> = identified.fits.iter().map(|(n, _)| n).collect();
    let states: Vec<String> =
        names.iter().filter_map(|n| identified.model.equation(n).map(|e| e.state.clone())).collect();
    let refined = !crate::identify::coarsely_sampled(frames, &states).is_empty();
    // every size proven best, so that each combination is of the best subsets; none larger
    // than the budget reaches (a library of 84 cubic terms per equation is searched to 9
    // terms for three equations), within seconds
    let search = Backend::BestSubset(BestSubset {
        max_size: Some(largest_size(names.len())),
        time_limit: SEARCH_SECONDS,
        ..BestSubset::default()
    });
    let path_model = model
        .edit(|file| {
            for name in &names {
                if let Some(e) = file.equations.get_mut(*name) {
                    e.backend = Some(search.clone());
                }
            }
        })
        .ok()?;
    let paths: Vec<Path> = identify_model(&path_model, frames, how, &mut |_| {})
        .ok()?
        .fits
        .into_iter()
        .map(|(name, fit)| {
            let sizes = fit.selection.steps.len();
            Path { name, fit, sizes }
        })
        .collect();
    if paths.iter().any(|p| p.sizes == 0) {
        return None;
    }
    let own: Vec<Fit> = identified.fits.iter().map(|(_, f)| f.clone()).collect();
    let own_total: usize = own.iter().map(|f| f.selection.terms.len()).sum();
    let same = |fits: &[Fit]| fits.iter().zip(&own).all(|(a, b)| terms_of(a) == terms_of(b));
    // terms that leave much more of a rate unexplained than the regression's trade the rates
    // for runs they follow only by chance (a chaotic record, which any bounded motion
    // re-simulates about as badly after its first seconds): not re-simulated
    let bound: Vec<f64> = own.iter().map(|f| EXPLAINED * unexplained(f).max(1e-4)).collect();
    let explains = |fits: &[Fit]| fits.iter().zip(&bound).all(|(f, b)| unexplained(f) <= *b);
    let score = |fits: Vec<Fit>| {
        explains(&fits).then(|| score(model, identified, &paths, fits, how, frames, refined)).flatten()
    };
    let mut scored: Vec<Scored> = Vec::new();
    let (mut tried, mut most_terms) = (0, 0);
    let largest: usize = paths.iter().map(|p| p.sizes).sum();
    let mut own_scored = false;
    for total in paths.len()..=largest {
        let combinations = sizes_totalling(&paths, total);
        if tried + combinations.len() > MOST_COMBINATIONS {
            break;
        }
        tried += combinations.len();
        most_terms = total;
        for sizes in combinations {
            let fits: Vec<Fit> = paths.iter().zip(sizes).map(|(p, size)| p.at(size)).collect();
            own_scored |= same(&fits);
            scored.extend(score(fits));
        }
    }
    // the regression's own terms, where no best subset is the same (or the budget ended first)
    if !own_scored {
        tried += 1;
        most_terms = most_terms.max(own_total);
        scored.extend(score(own.clone()));
    }
    let best = scored.into_iter().min_by(|a, b| a.criterion.total_cmp(&b.criterion));
    let own_best = best.as_ref().is_some_and(|b| same(&b.fits));
    // only the best is asked whether it follows the runs, and at least twice as long as the
    // regression's terms: a worse one that does is no choice, and a model whose own motion
    // loses itself at once passes the checks however soon it loses the runs (a cubic's
    // pendulum near its false top: 0.61 s of 30, where the regression's four terms follow
    // 0.58 s)
    let follows = |b: &Scored| {
        let (checks, share) = retraced(&b.model, frames);
        checks.iter().all(|c| c.passed) && share >= LONGER * retraced(&identified.model, frames).1
    };
    let kept = match best {
        // identified with its terms forced once: for its score where it was refined
        Some(b) if !own_best && follows(&b) => match b.forced {
            Some(kept) => Some(kept),
            None => Some(forced(model, &paths, &b.fits, how, frames)?),
        },
        _ => None,
    };
    Some(Search { kept, tried, most_terms, refined, own_best })
}

/// `fits` (one per path) as a model, and scored: the Bayesian information criterion
/// n·ln(S/n) + k·ln(n) of its re-simulation's scaled sum of squares S over its n compared
/// samples (at least a thousandth of each state's spread, RMS), with k coefficients. Where
/// `refined`, identified with the terms forced (its coefficients' covariance the refinement's
/// prior, so that what is scored is what is kept) and refined by output error; else the
/// regression's coefficients as they are. `None` where it cannot be identified or
/// re-simulated (it runs away).
fn score(
    model: &Model,
    identified: &IdentifiedModel,
    paths: &[Path],
    fits: Vec<Fit>,
    how: &ModelIdentification<'_>,
    frames: &[Frame],
    refined: bool,
) -> Option<Scored> {
    let (candidate, forced) = if refined {
        let forced = forced(model, paths, &fits, how, frames)?;
        let options = super::RefineOptions::of_coarse_rows();
        let refined = super::start::refine(&forced.model, frames, None, &options, how.intercept).ok()?;
        (refined.model, Some(forced))
    } else {
        let mut candidate = identified.model.clone();
        for (path, fit) in paths.iter().zip(&fits) {
            store_fit(&mut candidate, &path.name, fit).ok()?;
        }
        (candidate, None)
    };
    let runs = super::start::output_error_runs(&candidate, frames, None, how.intercept).ok()?;
    let sims = runs.simulate(&candidate, &[], &[]).ok()?;
    let cost = runs.gap(&sims).cost;
    let n = runs.residual_count() as f64;
    let k: usize =
        candidate.equations().iter().map(|e| e.coefficients.len() + usize::from(e.intercept.is_some())).sum();
    if !(cost.is_finite() && n > 0.0) {
        return None;
    }
    // errors below a thousandth of each state's spread (RMS) are the integration's, not the
    // terms': fitting them takes terms that no record asks for
    let floor = n * super::RESOLVED.powi(2);
    let criterion = n * (cost.max(floor) / n).ln() + k as f64 * n.ln();
    Some(Scored { fits, criterion, model: candidate, forced })
}

/// The share of a fit's target its chosen terms leave unexplained, 1 − R².
fn unexplained(fit: &Fit) -> f64 {
    fit.selection.chosen_r2().map_or(1.0, |r2| 1.0 - r2)
}

/// A fit's chosen terms, sorted.
fn terms_of(fit: &Fit) -> Vec<&str> {
    let mut terms: Vec<&str> = fit.selection.terms.iter().map(|t| t.term.as_str()).collect();
    terms.sort_unstable();
    terms
}

/// Every combination of one size per path (each from 1 to its largest) adding up to `total`.
fn sizes_totalling(paths: &[Path], total: usize) -> Vec<Vec<usize>> {
    fn fill(paths: &[Path], left: usize, prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        let Some((first, rest)) = paths.split_first() else {
            if left == 0 {
                out.push(prefix.clone());
            }
            return;
        };
        // the rest need at least one term each and hold at most their largest sizes
        let rest_most: usize = rest.iter().map(|p| p.sizes).sum();
        for size in 1..=first.sizes.min(left.saturating_sub(rest.len())) {
            if left - size > rest_most {
                continue;
            }
            prefix.push(size);
            fill(rest, left - size, prefix, out);
            prefix.pop();
        }
    }
    let mut out = Vec::new();
    fill(paths, total, &mut Vec::new(), &mut out);
    out
}

/// `model` identified with the terms of `fits` (one per path) forced and each equation's other
/// candidates excluded.
fn forced(
    model: &Model,
    paths: &[Path],
    fits: &[Fit],
    how: &ModelIdentification<'_>,
    frames: &[Frame],
) -> Option<IdentifiedModel> {
    let chosen: Vec<(String, Vec<String>, Vec<String>)> = paths
        .iter()
        .zip(fits)
        .map(|(p, fit)| {
            let terms: Vec<String> = fit.selection.terms.iter().map(|t| t.term.clone()).collect();
            let others = p.fit.candidates.iter().filter(|c| !terms.contains(c)).cloned().collect();
            (p.name.clone(), terms, others)
        })
        .collect();
    let edited = model
        .edit(|file| {
            for (name, terms, others) in &chosen {
                if let Some(e) = file.equations.get_mut(name) {
                    e.forced = terms.clone();
                    e.excluded = others.clone();
                }
            }
        })
        .ok()?;
    identify_model(&edited, frames, how, &mut |_| {}).ok()
}

/// What the search did, for each equation's notes: the regression's terms, the kept ones and
/// how many combinations were re-simulated.
pub(crate) fn note(before: &IdentifiedModel, search: &Search) -> String {
    let sizes = |m: &IdentifiedModel| -> String {
        m.fits
            .iter()
            .map(|(n, f)| format!("{} of `{n}`", f.selection.terms.len()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let judged = if search.refined { ", each refined by output error" } else { "" };
    let tried = format!(
        "{} combination(s) of the regression's terms and the best subsets of each size per equation re-simulated{judged}, up to {} terms, scored by the information criterion of their re-simulation's error",
        search.tried, search.most_terms
    );
    match &search.kept {
        Some(kept) => format!(
            "terms chosen by re-simulation: the regression's ({}) fit the rates but lose the runs; the best re-simulated terms, {}, follow them as long as their own motion allows ({tried}); written forced, the other candidates excluded",
            sizes(before),
            sizes(kept)
        ),
        None if search.own_best => format!(
            "the regression's terms ({}) lose the runs, and re-simulate them best of all the terms tried ({tried}): kept",
            sizes(before)
        ),
        None => format!(
            "the regression's terms ({}) lose the runs, and the terms that re-simulate them best do not follow them twice as long ({tried}): the regression's kept; the candidates or the records lack what the motion needs",
            sizes(before)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(sizes: usize) -> Path {
        let selection =
            Selection::from_steps("best-subset", 0, &[], vec![], 0, crate::select::Stop::AllEntered, vec![]);
        let fit = Fit {
            target: String::new(),
            candidates: vec![],
            selection,
            covariance: None,
            correlation_time: None,
            residual_growth: None,
            rivals: vec![],
        };
        Path { name: String::new(), fit, sizes }
    }

    #[test]
    fn the_budget_bounds_each_equation_s_size() {
        // one equation: all 200 sizes; two: C(20, 2) = 190 combinations of up to 20 terms,
        // 19 for one; three: C(11, 3) = 165, 9 for one
        assert_eq!(largest_size(1), 200);
        assert_eq!(largest_size(2), 19);
        assert_eq!(largest_size(3), 9);
        assert_eq!(largest_size(0), 1);
        let up_to = |m: usize, total: usize| -> usize {
            let paths: Vec<Path> = (0..m).map(|_| path(total)).collect();
            (m..=total).map(|t| sizes_totalling(&paths, t).len()).sum()
        };
        assert_eq!(up_to(2, 20), 190);
        assert_eq!(up_to(3, 11), 165);
        assert!(up_to(3, 12) > MOST_COMBINATIONS);
    }

    #[test]
    fn combinations_of_sizes_add_up_to_their_total() {
        let paths = [path(2), path(3)];
        assert_eq!(sizes_totalling(&paths, 2), [[1, 1]]);
        assert_eq!(sizes_totalling(&paths, 4), [[1, 3], [2, 2]]);
        assert_eq!(sizes_totalling(&paths, 5), [[2, 3]]);
        assert!(sizes_totalling(&paths, 6).is_empty());
        assert!(sizes_totalling(&paths, 1).is_empty());
        // every total of 1..=p per path, each combination once
        let all: usize = (2..=5).map(|t| sizes_totalling(&paths, t).len()).sum();
        assert_eq!(all, 6);
    }
}
