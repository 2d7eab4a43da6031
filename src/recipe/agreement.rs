//! Whether the runs tell one system: each run identified alone with the terms all the rows
//! chose, and their coefficients compared. Runs made under different conditions (a load, a
//! speed, a temperature changed between them) are fitted by all the rows as a compromise that
//! fits none, and the other checks then say only that the equations miss their runs.

use crate::data::Frame;
use crate::identify::{identify_model, IdentifiedModel, ModelIdentification};
use crate::plugin::Check;

/// The check's name.
pub(super) const NAME: &str = "the runs tell one system";

/// How many honest standard errors (the residuals' correlation counted) two runs' estimates
/// of a coefficient must be apart to disagree: beyond chance by far (10⁻⁶ for Gaussian
/// errors), so that a bias the rows' noise makes, which the errors do not count, is not taken
/// for a change.
const APART: f64 = 5.0;

/// How far apart, as a share of the larger, two runs' estimates of a coefficient must be to
/// disagree besides: the bias noise in the states makes (errors in variables) differs with
/// each run's excitation by a few percent at 1 % noise.
const SHARE: f64 = 0.1;

/// The fewest rows of a run identified alone.
const FEWEST_ROWS: usize = 50;

/// A run's estimates: its origin, and each coefficient's equation, term, estimate and honest
/// standard error.
type Estimates = (String, Vec<(String, String, f64, f64)>);

/// One coefficient's estimates from two runs that differ most: the equation, the term, and
/// each run's origin, estimate and honest standard error; with how many standard errors
/// apart they are.
struct Apart {
    equation: String,
    term: String,
    runs: [(String, f64, f64); 2],
    apart: f64,
}

/// The check that each of two or more runs (of [`FEWEST_ROWS`] at least; of one run, its two
/// halves: a system that drifts within it) identified alone with the terms of `identified`
/// (each equation's chosen terms forced, but those of a variable the run holds constant, its
/// other candidates excluded) gives each coefficient within [`APART`] honest standard errors or
/// [`SHARE`] of the others': flagged (not refusing) where two estimates differ by both, naming
/// the coefficient and the two runs. `None` with too few rows, or where fewer than two can be
/// identified alone.
pub(super) fn agreement_check(
    identified: &IdentifiedModel,
    frames: &[Frame],
    how: &ModelIdentification<'_>,
) -> Option<Check> {
    if identified.fits.is_empty() {
        return None;
    }
    let long: Vec<&Frame> = frames.iter().filter(|f| f.len() >= FEWEST_ROWS).collect();
    let halves;
    let (runs, split): (Vec<(String, &Frame)>, Option<&str>) = match long.as_slice() {
        [one] if frames.len() == 1 && one.len() >= 2 * FEWEST_ROWS => {
            let middle = one.len() / 2;
            halves = [one.slice(0..middle), one.slice(middle..one.len())];
            let origin = one.origin();
            (
                vec![
                    (format!("the first half of {origin}"), &halves[0]),
                    (format!("the second half of {origin}"), &halves[1]),
                ],
                Some(origin),
            )
        }
        [] | [_] => return None,
        many => (many.iter().map(|f| (f.origin().to_string(), *f)).collect(), None),
    };
    // each run's model: the chosen terms forced, but those of a variable the run holds
    // constant (a free decay beside a forced run: its input 0 throughout), which it cannot tell
    let vocabulary = &identified.model.vocabulary;
    let forced = |run: &Frame| {
        let moves = |name: &String| run.column(name).is_none_or(|x| x.iter().any(|v| *v != x[0]));
        let told = |term: &String| vocabulary.parse(term).is_ok_and(|t| t.variables().iter().all(moves));
        identified.model.edit(|file| {
            for (name, fit) in &identified.fits {
                let Some(e) = file.equations.get_mut(name) else { continue };
                let terms: Vec<String> =
                    fit.selection.terms.iter().map(|t| t.term.clone()).filter(told).collect();
                e.excluded = fit.candidates.iter().filter(|c| !terms.contains(c)).cloned().collect();
                e.forced = terms;
            }
        })
    };
    let kept = super::halves::windows_kept(how.differentiator, frames);
    let how = super::halves::keeping(how, &kept);
    let alone: Vec<Estimates> = runs
        .iter()
        .filter_map(|(origin, run)| {
            let model = forced(run).ok()?;
            let found = identify_model(&model, std::slice::from_ref(*run), &how, &mut |_| {}).ok()?;
            let estimates = found
                .fits
                .iter()
                .flat_map(|(name, fit)| {
                    let honest = fit.correlation_time.unwrap_or(1.0).max(1.0).sqrt();
                    fit.selection
                        .terms
                        .iter()
                        .map(move |t| (name.clone(), t.term.clone(), t.coefficient, t.std_error * honest))
                })
                .collect();
            Some((origin.clone(), estimates))
        })
        .collect();
    if alone.len() < 2 {
        return None;
    }
    let mut worst: Option<Apart> = None;
    for (i, (a, of_a)) in alone.iter().enumerate() {
        for (b, of_b) in &alone[i + 1..] {
            for (equation, term, x, sx) in of_a {
                let Some((_, _, y, sy)) = of_b.iter().find(|(e, t, _, _)| e == equation && t == term) else {
                    continue;
                };
                let apart = (x - y).abs() / (sx * sx + sy * sy).sqrt();
                let far = (x - y).abs() > SHARE * x.abs().max(y.abs());
                if far && apart.is_finite() && worst.as_ref().is_none_or(|w| apart > w.apart) {
                    worst = Some(Apart {
                        equation: equation.clone(),
                        term: term.clone(),
                        runs: [(a.clone(), *x, *sx), (b.clone(), *y, *sy)],
                        apart,
                    });
                }
            }
        }
    }
    let check = |passed: bool, detail: String| Check {
        name: NAME.into(),
        passed,
        refuses: false,
        detail,
        measure: None,
    };
    let sig = |v: f64| crate::output::sig(v, 3);
    let (which, changed) = match split {
        Some(origin) => (
            format!("the halves of {origin}"),
            "a parameter that drifted within the run (a load, a temperature, a sensor's gain or zero)",
        ),
        None => (
            "the runs".to_string(),
            "a parameter that changed between the runs (a load, a speed, a temperature)",
        ),
    };
    Some(match worst.filter(|w| w.apart > APART) {
        Some(Apart { equation, term, runs: [(a, x, sx), (b, y, sy)], apart }) => check(
            false,
            format!(
                "identified alone with the terms all the rows chose, {which} disagree: `{equation}`'s `{term}` is {} (± {}) from {a} and {} (± {}) from {b}, {} standard errors apart (honest ones, the residuals' correlation counted): {changed}, terms standing in for a law the candidates lack over ranges the rows cover differently, or terms the rows hardly tell from others (a fast state that follows the others), which trade against each other; the equations of all the rows are a compromise between them: identify the parts apart, or record what changed as an input",
                sig(x),
                sig(sx),
                sig(y),
                sig(sy),
                sig(apart)
            ),
        ),
        None => check(
            true,
            format!(
                "{} identified alone with the terms all the rows chose give each coefficient within {APART} honest standard errors or {} % of the others'",
                match split {
                    Some(_) => "the run's two halves".to_string(),
                    None => format!("{} runs", alone.len()),
                },
                100.0 * SHARE
            ),
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The agreement check of the tests' lag model identified from `frames` in the integral form.
    fn agreement_of(frames: &[Frame]) -> Option<Check> {
        let model = super::super::lag_model();
        let diff = super::super::derivative_method("integral").unwrap();
        let how = ModelIdentification {
            equations: vec![],
            differentiator: diff.as_ref(),
            intercept: false,
            target: None,
        };
        let identified = identify_model(&model, frames, &how, &mut |_| {}).unwrap();
        agreement_check(&identified, frames, &how)
    }

    /// One run of ẋ = −a·x + sin t whose lag steps from 0.5 to 1.5 at 15 s (a load changed in
    /// the middle of a run), by fine Euler steps: its halves tell the two lags, −0.5 and −1.5;
    /// the same run without the step agrees with itself.
    #[test]
    fn a_lag_that_changes_within_a_run_is_named() {
        let run = |step: bool| {
            super::super::lag_run(0.0, 600, &|t| if step && t >= 15.0 { 1.5 } else { 0.5 }, &f64::sin)
        };
        let check = |frame: Frame| agreement_of(&[frame]).unwrap();
        let steady = check(run(false));
        assert!(steady.passed, "{}", steady.detail);
        let stepped = check(run(true));
        assert!(!stepped.passed, "{}", stepped.detail);
        assert!(
            stepped.detail.contains("the halves of run.csv disagree: `x_dot`'s `x` is -0.50")
                && stepped.detail.contains("from the first half of run.csv and -1.5")
                && stepped.detail.contains("a parameter that drifted within the run"),
            "{}",
            stepped.detail
        );
    }

    /// ẋ = −a·x + u under u = sin t from rest, in closed form: x = (a sin t − cos t + e^(−at))
    /// / (a² + 1), sampled every 0.05 s for 30 s.
    fn lag(name: &str, a: f64) -> Frame {
        let t: Vec<f64> = (0..600).map(|k| k as f64 * 0.05).collect();
        let mut f = Frame::new(name, "t", t.clone()).unwrap();
        let x = t.iter().map(|&t| (a * t.sin() - t.cos() + (-a * t).exp()) / (a * a + 1.0)).collect();
        f.push("x", x).unwrap();
        f.push("u", t.iter().map(|t| t.sin()).collect()).unwrap();
        f
    }

    /// Two runs of ẋ = −x/2 + u agree; a run of ẋ = −3x/2 + u beside one of them (its lag
    /// changed between the runs) is flagged, naming `x`'s two estimates (−0.5 and −1.5) and
    /// the runs; so is a free decay of the other lag beside the driven run.
    #[test]
    fn runs_of_two_systems_are_told_apart() {
        let check = agreement_of;
        let one = check(&[lag("a.csv", 0.5), lag("b.csv", 0.5).slice(100..600)]).unwrap();
        assert!(one.passed && one.detail.starts_with("2 runs identified alone"), "{}", one.detail);
        let two = check(&[lag("a.csv", 0.5), lag("b.csv", 1.5)]).unwrap();
        assert!(!two.passed && !two.refuses, "{}", two.detail);
        assert!(
            two.detail.contains("`x_dot`'s `x` is -0.500 (± ")
                && two.detail.contains(") from a.csv and -1.50 (± ")
                && two.detail.contains(") from b.csv"),
            "{}",
            two.detail
        );
        // one run: its halves agree
        let halves = check(&[lag("a.csv", 0.5)]).unwrap();
        assert!(
            halves.passed && halves.detail.starts_with("the run's two halves identified alone"),
            "{}",
            halves.detail
        );
        assert!(check(&[lag("a.csv", 0.5).slice(0..99)]).is_none());
        // a free decay (u = 0 throughout, x = e^(−at)) beside the driven run: its `u` cannot be
        // told, its lag can (the run was left out, and nothing said)
        let decay = |a: f64| {
            let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.05).collect();
            let mut f = Frame::new("decay.csv", "t", t.clone()).unwrap();
            f.push("x", t.iter().map(|&t| (-a * t).exp()).collect()).unwrap();
            f.push("u", vec![0.0; t.len()]).unwrap();
            f
        };
        let same = check(&[lag("a.csv", 0.5), decay(0.5)]).unwrap();
        assert!(same.passed, "{}", same.detail);
        let other = check(&[lag("a.csv", 0.5), decay(1.5)]).unwrap();
        assert!(
            !other.passed && other.detail.contains("-1.50 (± ") && other.detail.contains("from decay.csv"),
            "{}",
            other.detail
        );
    }
}
