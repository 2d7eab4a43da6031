//! Whether identified terms hold on each half of the runs: the equations identified again
//! from the first and from the second half of every run, the terms chosen from all the rows
//! but not from both halves named. Noise that biases the regressors (errors in the states
//! themselves) makes a regression choose terms the system lacks with t-values of 4 to 6;
//! they rarely come back from both halves, where the system's own terms do.

use std::collections::BTreeMap;

use crate::data::{Frame, TestFunction, WeakForm};
use crate::identify::{identify_model, EquationMoments, IdentifiedModel, ModelIdentification, RunMoments};
use crate::model::Model;
use crate::plugin::Check;

/// The check's name, by which a later stage keeps it (a refinement changes coefficients, not
/// which terms the rows chose).
pub(super) const NAME: &str = "the terms hold on each half of the runs";

/// The fewest rows of a half a run is cut for: below it a half cannot choose among a
/// library's candidates at all.
const FEWEST_ROWS: usize = 50;

/// How the rows are halved: each run cut in the middle, or, where a run is too short for
/// that, every other run against the rest (many short runs: each half still holds half of
/// the rows), or both (the long runs cut, the short ones given to the halves in turn).
#[derive(Clone, Copy, PartialEq)]
enum Halving {
    EachRun,
    EveryOtherRun,
    Both,
}

impl Halving {
    /// `frames` in two halves, and how they were cut: each run long enough to halve cut in
    /// the middle, the runs too short for that given to the halves in turn.
    fn of(frames: &[Frame]) -> (Halving, [Vec<Frame>; 2]) {
        let mut halves = [Vec::new(), Vec::new()];
        let (mut turn, mut cut, mut whole) = (0, false, false);
        for f in frames {
            if f.len() >= 2 * FEWEST_ROWS {
                let middle = f.len() / 2;
                halves[0].push(f.slice(0..middle));
                halves[1].push(f.slice(middle..f.len()));
                cut = true;
            } else {
                halves[turn].push(f.clone());
                turn = 1 - turn;
                whole = true;
            }
        }
        let halving = match (cut, whole) {
            (_, false) => Halving::EachRun,
            (false, true) => Halving::EveryOtherRun,
            (true, true) => Halving::Both,
        };
        (halving, halves)
    }
}

/// The check that each equation of `identified` (from `frames` by `how`) chooses its terms
/// from the first and from the second half of every run too (runs too short to halve: from
/// every other one of them and from the rest): flagged (not refusing) where a term is chosen
/// from all the rows but not from both halves. Where it cannot apply (too few rows in a half,
/// a half that cannot be identified) it is flagged as not checked: the terms are then
/// unconfirmed, which every check reading "ok" would hide (a dozen samples of a decay chose
/// two terms its truth lacks). `quiet`: the records hold next to no noise (the noise check
/// reads under 0.01 % of each spread), so a form the candidates lack is the first cause named.
pub fn halves_check(
    identified: &IdentifiedModel,
    frames: &[Frame],
    how: &ModelIdentification<'_>,
    quiet: bool,
) -> Check {
    let (halving, halves) = Halving::of(frames);
    // runs given whole to a half: a run's worth of rows in each, twice FEWEST_ROWS
    let rows = |half: &[Frame]| half.iter().map(Frame::len).sum::<usize>();
    let least = if halving == Halving::EachRun { FEWEST_ROWS } else { 2 * FEWEST_ROWS };
    if halves.iter().any(|h| rows(h) < least) {
        let (a, b) = (rows(&halves[0]), rows(&halves[1]));
        let why = format!(
            "the runs' {} rows are too few to halve: the halves would hold {a} and {b}, each needs {least}",
            a + b
        );
        return unchecked(&why);
    }
    let model: &Model = &identified.model;
    let kept = windows_kept(how.differentiator, frames);
    let how = &keeping(how, &kept);
    let half = |cut: &[Frame]| identify_model(model, cut, how, &mut |_| {});
    // side by side: each half is one run's worth of work per run, which leaves a core idle
    let (first, second) = rayon::join(|| half(&halves[0]), || half(&halves[1]));
    // a half's rows of independent evidence (a weak form's windows overlap) for an equation
    let overlap = how.differentiator.window().map_or(1.0, crate::data::row_overlap);
    let chosen = |found: IdentifiedModel| -> Chosen {
        found
            .fits
            .into_iter()
            .map(|(name, f)| {
                let terms = f.selection.terms.iter().map(|t| t.term.clone()).collect();
                (name, (terms, f.selection.rows as f64 / overlap))
            })
            .collect()
    };
    match (first, second) {
        (Ok(first), Ok(second)) => verdict(identified, halving, [chosen(first), chosen(second)], quiet),
        (Err(e), _) | (_, Err(e)) => unchecked(&format!("a half of the runs could not be identified ({e})")),
    }
}

/// The check where the halves could not be compared (`why`): flagged, since the terms are
/// then chosen from all the rows at once and confirmed by nothing.
fn unchecked(why: &str) -> Check {
    Check {
        name: NAME.into(),
        passed: false,
        refuses: false,
        detail: format!(
            "not checked: {why}: the terms rest on all the rows at once, unconfirmed (more or longer \
             runs confirm them)"
        ),
        measure: None,
    }
}

/// [`halves_check`] of equations identified from their statistics (runs read in pieces, or
/// gathered where the rows are: [`EquationMoments`]): each equation fitted again, with
/// `model`'s back-end, from the statistics of the first and of the second half of every run
/// ([`EquationMoments::halves`], pooled per shard: a back-end that leaves runs out leaves
/// shards out, and cannot fit halves of one shard). `None` for statistics without halves
/// (written before they were kept); flagged as not checked where a half has fewer rows than
/// runs read whole need, or cannot be fitted. `quiet` as for [`halves_check`].
pub fn halves_check_of_moments(
    identified: &IdentifiedModel,
    moments: &[EquationMoments],
    model: &Model,
    intercept: bool,
    quiet: bool,
) -> Option<Check> {
    let mut halves: [Chosen; 2] = Default::default();
    for m in moments {
        let shards = m.halves.as_ref()?;
        for (k, chosen) in halves.iter_mut().enumerate() {
            let mut part = m.clone_empty();
            part.runs = shards
                .iter()
                .enumerate()
                .map(|(s, h)| RunMoments {
                    run: format!("half {} of shard {}", k + 1, s + 1),
                    moments: h[k].clone(),
                    noise: BTreeMap::new(),
                })
                .collect();
            let rows: usize = part.runs.iter().map(|r| r.moments.count()).sum();
            if rows < FEWEST_ROWS {
                let why =
                    format!("a half of the runs holds {rows} rows, under the {FEWEST_ROWS} a half needs");
                return Some(unchecked(&why));
            }
            let fit = match part.fit(model, intercept) {
                Ok(fit) => fit,
                Err(e) => return Some(unchecked(&format!("a half of the runs could not be fitted ({e})"))),
            };
            let terms = fit.selection.terms.iter().map(|t| t.term.clone()).collect();
            let evidence = part.runs.iter().map(|r| r.moments.independent_rows()).sum();
            chosen.insert(m.equation.clone(), (terms, evidence));
        }
    }
    Some(verdict(identified, Halving::EachRun, halves, quiet))
}

/// What a half chose: each equation's terms, with the half's rows' worth of independent
/// evidence for it (a weak form's windows overlap).
type Chosen = BTreeMap<String, (Vec<String>, f64)>;

/// The check, from the terms each half chose: passed where every term chosen from all the
/// rows was chosen from both halves too. `quiet`: the records hold next to no noise
/// ([`super::noise::quiet`]), so that noise is no cause to name first.
fn verdict(identified: &IdentifiedModel, halving: Halving, halves: [Chosen; 2], quiet: bool) -> Check {
    let none = (Vec::new(), 0.0);
    let (mut unsteady, mut thin) = (Vec::new(), Vec::new());
    for (name, fit) in &identified.fits {
        let (a, b) = (halves[0].get(name).unwrap_or(&none), halves[1].get(name).unwrap_or(&none));
        let lost: Vec<String> = fit
            .selection
            .terms
            .iter()
            .filter(|t| !(a.0.contains(&t.term) && b.0.contains(&t.term)))
            .map(|t| format!("`{}`", t.term))
            .collect();
        if lost.is_empty() {
            continue;
        }
        // a half with fewer rows' worth than candidates cannot choose among them where the
        // rows are noisy (Lorenz-96's ten rates over 7 s at 1 %, 66 candidates: halves of 50
        // rows' worth chose 20 to 45 terms each, where the whole's 104 chose the four true
        // ones): what it left out says nothing (noise-free, such halves choose alike)
        let least = a.1.min(b.1);
        if least < fit.candidates.len() as f64 {
            thin.push((name.clone(), least, fit.candidates.len()));
        } else {
            unsteady.push(format!("`{name}`: {}", lost.join(", ")));
        }
    }
    let from = match halving {
        Halving::EachRun => "the first and from the second half of every run",
        Halving::EveryOtherRun => "every other run and from the rest (the runs too short to halve)",
        Halving::Both => {
            "the first and from the second half of every run long enough to halve, the shorter runs \
             given to the halves in turn"
        }
    };
    let not_confirmed = (!thin.is_empty()).then(|| {
        let names: Vec<String> = thin.iter().map(|(n, ..)| format!("`{n}`")).collect();
        let least = thin.iter().map(|t| t.1).fold(f64::INFINITY, f64::min);
        let most = thin.iter().map(|t| t.2).max().unwrap_or(0);
        format!(
            "{} not confirmed: their halves chose other terms, but a half holds {least:.0} rows' worth of \
             independent evidence for up to {most} candidates, too few to choose among them (longer runs \
             or fewer candidates)",
            names.join(", ")
        )
    });
    let detail = if unsteady.is_empty() {
        let which = if thin.is_empty() { "each equation" } else { "the other equations" };
        let same = format!(
            "{which} {} the same terms from {from}",
            if thin.is_empty() { "chooses" } else { "choose" }
        );
        match not_confirmed {
            Some(n) if thin.len() == identified.fits.len() => n,
            Some(n) => format!("{same}; {n}"),
            None => same,
        }
    } else {
        let causes = if quiet {
            // noise-free, such terms are the polynomials' stand-ins (Coulomb friction's sign(v),
            // Michaelis-Menten's x/(0.5 + x)) or what a half does not excite: the form first
            "the records hold next to no noise (the noise check's reading), so terms that stand in \
             for a form the candidates lack (Michaelis-Menten's x/(0.5 + x), friction's sign(v) from \
             polynomials), that one half does not excite, or that take up a system changing between \
             the halves (a coefficient drifting over the runs): read them as uncertain (the system's \
             own form among the candidates, more or longer runs)"
        } else {
            "terms the noise chose (errors in the states bias the regressors), that one half does \
             not excite, that stand in for a form the candidates lack (noise-free, Michaelis-Menten's \
             x/(0.5 + x) from polynomials), or that take up a system changing between the halves (a \
             coefficient drifting over the runs: a damping 0.2 to 0.6 over a minute chose five such): \
             read them as uncertain (more or longer runs, less noise, fewer candidates, the system's \
             own form)"
        };
        format!(
            "chosen from all the rows but not from both {}: {}; {causes}",
            match halving {
                Halving::EachRun => "halves of every run",
                Halving::EveryOtherRun => "every other run and the rest",
                Halving::Both => "halves of the runs (the shorter runs given to them in turn)",
            },
            unsteady.join("; ")
        ) + &not_confirmed.map(|n| format!("; {n}")).unwrap_or_default()
    };
    Check {
        name: NAME.into(),
        passed: unsteady.is_empty() && thin.is_empty(),
        refuses: false,
        detail,
        measure: None,
    }
}

/// The weak form the halves take where the whole runs took a default one's windows: each
/// half keeps them, where the default would turn to the integral form's on a half too short
/// for four windows and the halves would choose by another method than the whole. `None`:
/// the halves take `differentiator` as it is.
pub(super) fn windows_kept(
    differentiator: &dyn crate::data::Differentiator,
    frames: &[Frame],
) -> Option<WeakForm> {
    // (a run with switches may have taken the integral form's windows whole: the halves then
    // take the default as it is, and decide as the whole did)
    let whole = differentiator
        .window()
        .filter(|w| frames.iter().all(|f| f.len() > 4 * w.intervals && f.switched().is_empty()))?;
    match whole.test {
        TestFunction::Bump(power) if whole.shrinks => Some(WeakForm { window: Some(whole.intervals), power }),
        _ => None,
    }
}

/// `how` with the weak form's windows `kept` ([`windows_kept`]) where the whole runs took
/// them: a part of the runs identified as the whole was.
pub(super) fn keeping<'a>(
    how: &ModelIdentification<'a>,
    kept: &'a Option<WeakForm>,
) -> ModelIdentification<'a> {
    ModelIdentification {
        differentiator: kept.as_ref().map_or(how.differentiator, |k| k as &dyn crate::data::Differentiator),
        equations: how.equations.clone(),
        target: how.target.clone(),
        ..*how
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ẋ = −x + u from one run: where u drives the whole run the halves choose both terms
    /// again; where it acts in the first half only, the second cannot choose `u` (it does not
    /// excite it), and the check names it.
    #[test]
    fn a_term_one_half_does_not_choose_is_named() {
        let model = super::super::lag_model();
        // exact samples of ẋ = −x + u under u = sin(0.7 t) (+ a step), by fine Euler steps
        let run = |u: &dyn Fn(f64) -> f64| super::super::lag_run(0.5, 400, &|_| 1.0, u);
        let diff = super::super::derivative_method("integral").unwrap();
        let how = ModelIdentification {
            equations: vec![],
            differentiator: diff.as_ref(),
            intercept: false,
            target: None,
        };
        let check = |frame: Frame| {
            let frames = [frame];
            let identified = identify_model(&model, &frames, &how, &mut |_| {}).unwrap();
            halves_check(&identified, &frames, &how, false)
        };
        let whole = check(run(&|t| (0.7 * t).sin() + 1.0));
        assert!(whole.passed && !whole.refuses, "{}", whole.detail);
        let first_half = check(run(&|t| if t < 8.0 { (0.7 * t).sin() + 1.0 } else { 0.0 }));
        assert!(!first_half.passed && !first_half.refuses, "{}", first_half.detail);
        assert!(first_half.detail.contains("`x_dot`: `u`"), "{}", first_half.detail);
        // a run too short to halve is flagged as not checked (it was left out, every other
        // check reading "ok")
        let short = run(&|t| t).slice(0..60);
        let identified = identify_model(&model, std::slice::from_ref(&short), &how, &mut |_| {}).unwrap();
        let unchecked = halves_check(&identified, &[short], &how, false);
        assert!(!unchecked.passed && !unchecked.refuses, "{}", unchecked.detail);
        assert!(
            unchecked.detail.starts_with("not checked: the runs' 60 rows are too few to halve: the halves would hold 60 and 0, each needs 100"),
            "{}",
            unchecked.detail
        );
        // runs too short to halve, six of them: every other run against the rest
        let whole = run(&|t| (0.7 * t).sin() + 1.0);
        let pieces: Vec<Frame> = (0..6).map(|k| whole.slice(60 * k..60 * k + 60)).collect();
        let identified = identify_model(&model, &pieces, &how, &mut |_| {}).unwrap();
        let check = halves_check(&identified, &pieces, &how, false);
        assert!(
            check.passed && check.detail.contains("from every other run and from the rest"),
            "{}",
            check.detail
        );
        // where u drives every other run only (it is 0 in the rest), the rest cannot choose it
        let late: Vec<Frame> = (0..6)
            .map(|k| if k % 2 == 0 { whole.slice(60 * k..60 * k + 60) } else { run(&|_| 0.0).slice(0..60) })
            .collect();
        let identified = identify_model(&model, &late, &how, &mut |_| {}).unwrap();
        let check = halves_check(&identified, &late, &how, false);
        assert!(
            !check.passed && check.detail.contains("every other run and the rest: `x_dot`: `u`"),
            "{}",
            check.detail
        );
        // a long run beside a short one (it once left the check out): the long one halved, the
        // short one given to a half
        let mixed = [whole.clone(), whole.slice(0..30)];
        let identified = identify_model(&model, &mixed, &how, &mut |_| {}).unwrap();
        let check = halves_check(&identified, &mixed, &how, false);
        assert!(
            check.passed && check.detail.contains("the shorter runs given to the halves in turn"),
            "{}",
            check.detail
        );
    }

    /// Runs of 200 samples take the default weak form whole; their halves of 100 keep its
    /// windows of 32 instead of turning to the integral form; runs too short for them whole,
    /// or a window the user chose, leave the method as it is.
    #[test]
    fn the_halves_keep_the_whole_runs_windows() {
        let run = |n: usize| Frame::new("r.csv", "t", (0..n).map(|k| k as f64).collect()).unwrap();
        let default = crate::data::WeakForm::default();
        let kept = windows_kept(&default, &[run(200), run(300)]).unwrap();
        assert_eq!((kept.window, kept.power), (Some(32), 8));
        assert!(windows_kept(&default, &[run(200), run(120)]).is_none());
        let chosen = WeakForm { window: Some(16), power: 4 };
        assert!(windows_kept(&chosen, &[run(200)]).is_none());
        assert!(windows_kept(&crate::data::IntegralForm::default(), &[run(200)]).is_none());
    }
}
