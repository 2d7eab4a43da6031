//! The check that the records' noise is small enough to leave a system's terms unbiased
//! ([`crate::identify::noise_note`] says it of one equation's fit).

use crate::data::{Frame, NoiseTally};
use crate::identify::noise::{flagged, held_nonlinearly, measured, shares, tallies, Share, SHARE};
use crate::identify::EquationMoments;
use crate::model::Model;
use crate::plugin::Check;

/// The check's name.
pub(super) const NAME: &str = "the records' noise leaves the terms unbiased";

/// The check on `model`'s identified rate equations over `runs`: for each recorded variable
/// that a chosen term holds nonlinearly, its white noise ([`crate::data::white_noise`], pooled
/// over the runs) against its spread over all rows; flagged (never refusing) where one is
/// measured above 2 % of its spread. `None` where no chosen term is nonlinear in a recorded
/// variable or no such variable is in the runs.
pub fn noise_check(model: &Model, runs: &[Frame]) -> Option<Check> {
    noise_check_of(&model_tallies(model, runs))
}

/// The recorded variables that the terms `model`'s identified equations chose hold
/// nonlinearly: noise in a variable only terms left out hold biases nothing kept (a logger's
/// unrelated channels taken for inputs were flagged, the equations exact).
fn chosen_nonlinearly(model: &Model) -> Vec<String> {
    let chosen =
        model.equations().iter().filter(|e| e.identify).flat_map(|e| e.coefficients.iter().map(|c| &c.0));
    held_nonlinearly(chosen, &model.vocabulary)
}

/// The noise tallies over `runs` of the variables [`chosen_nonlinearly`] by `model`.
pub(super) fn model_tallies(model: &Model, runs: &[Frame]) -> Vec<(String, NoiseTally)> {
    tallies(&chosen_nonlinearly(model), runs)
}

/// [`noise_check`] of equations identified from their statistics: the noise tallied with
/// them ([`crate::identify::RunMoments::noise`]), each variable's from the first equation
/// whose candidates hold it (the others tallied the same rows).
pub fn noise_check_of_moments(moments: &[EquationMoments], model: &Model) -> Option<Check> {
    noise_check_of(&moments_tallies(moments, model))
}

/// The noise tallies the statistics hold of the variables [`chosen_nonlinearly`] by `model`
/// (identified from them), each variable's from the first equation whose candidates hold it.
pub(super) fn moments_tallies(moments: &[EquationMoments], model: &Model) -> Vec<(String, NoiseTally)> {
    let chosen = chosen_nonlinearly(model);
    let mut pooled: Vec<(String, NoiseTally)> = Vec::new();
    for m in moments {
        let variables: std::collections::BTreeSet<&String> =
            m.runs.iter().flat_map(|r| r.noise.keys()).collect();
        for v in variables {
            if !pooled.iter().any(|(p, _)| p == v) {
                let all = NoiseTally::pooled(m.runs.iter().filter_map(|r| r.noise.get(v)).cloned());
                pooled.push((v.clone(), all));
            }
        }
    }
    pooled.retain(|(v, _)| chosen.contains(v));
    pooled
}

/// Below this share of its spread a variable's noise is next to none: rounding to six digits
/// or so, where the noise check reads at most 1e-6 %.
const QUIET: f64 = 1e-4;

/// Whether the records hold next to no noise, by the `tallies` of the variables the chosen
/// terms hold nonlinearly: each measured, or bounded, under [`QUIET`] of its spread (none
/// correlated from sample to sample, which reads less than it is). Terms the halves do not
/// both choose then stand in for a form the candidates lack or miss the excitation of a half:
/// noise did not choose them.
pub(super) fn quiet(tallies: &[(String, NoiseTally)]) -> bool {
    let shares = shares(tallies);
    !shares.is_empty() && shares.iter().all(|s| !s.at_least && s.share < QUIET)
}

/// The check on the noise `tallies` of the variables the chosen terms hold nonlinearly.
pub(super) fn noise_check_of(tallies: &[(String, NoiseTally)]) -> Option<Check> {
    let shares = shares(tallies);
    if shares.is_empty() {
        return None;
    }
    let over: Vec<&Share> = shares.iter().filter(|s| s.over()).collect();
    let untold: Vec<&Share> = shares.iter().filter(|s| s.untold()).collect();
    let (passed, detail) = if over.is_empty() && !untold.is_empty() {
        // "at most" more than the limit passed as if under it (a yearly census's populations,
        // noise-free, "at most 6.7 %, under 2 %")
        let all: Vec<&Share> = shares.iter().collect();
        let detail = format!(
            "not told: {}; a bound over {} %, not a measure: the motion shows through the differences of a record sampled this coarsely, and the noise under it may be over the limit or none (sampled faster, it would show)",
            measured(&all),
            crate::output::sig(100.0 * SHARE, 2)
        );
        (false, detail)
    } else if over.is_empty() {
        let all: Vec<&Share> = shares.iter().collect();
        // what the reading cannot see, said where it passes (and not said twice where the
        // reading found such noise)
        let unseen = if all.iter().any(|s| s.at_least) {
            ""
        } else {
            " (noise correlated over more than two samples, a filtered sensor's, reads less than it is)"
        };
        let detail = format!("{}, under {} %{unseen}", measured(&all), crate::output::sig(100.0 * SHARE, 2));
        (true, detail)
    } else {
        (false, flagged(&over))
    };
    Some(Check { name: NAME.into(), passed, refuses: false, detail, measure: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::noise::nonlinear_in;

    const SYSTEM: &str = "[model]\nname = \"pair\"\nintercept = false\n[[states]]\nname = \"x\"\n\
        [[states]]\nname = \"y\"\n[[inputs]]\nname = \"u\"\n[parameters]\nx0 = { value = 2.0 }\n\
        [[derived]]\nname = \"dx\"\ndefinition = \"x - x0\"\n\
        [equations.x_dot]\nstate = \"x\"\ncandidates = [\"x\", \"y\", \"u\"]\n\
        [equations.y_dot]\nstate = \"y\"\ncandidates = [\"CANDIDATE\"]\n";

    fn model(candidate: &str) -> Model {
        Model::parse(&SYSTEM.replace("CANDIDATE", candidate), "pair.toml").unwrap()
    }

    /// [`model`] as identified: its one candidate chosen, at 1.
    fn chose(candidate: &str) -> Model {
        let text =
            SYSTEM.replace("CANDIDATE", candidate) + &format!("coefficients = {{ \"{candidate}\" = 1.0 }}\n");
        Model::parse(&text, "pair.toml").unwrap()
    }

    /// Which variables a candidate holds nonlinearly: through powers, products, functions and
    /// derived variables; a parameter is no variable.
    #[test]
    fn a_candidate_is_nonlinear_in_what_its_derivative_varies_with() {
        let held = |candidate: &str| -> Vec<&str> {
            let m = model(candidate);
            let t = m.equation("y_dot").unwrap().candidates[0].clone();
            ["x", "y", "u"].into_iter().filter(|v| nonlinear_in(&t, v, &m.vocabulary)).collect()
        };
        assert_eq!(held("x"), Vec::<&str>::new());
        assert_eq!(held("x0*x"), Vec::<&str>::new());
        assert_eq!(held("x^2"), ["x"]);
        assert_eq!(held("x*y"), ["x", "y"]);
        assert_eq!(held("u*dx"), ["x", "u"]);
        assert_eq!(held("dx^2"), ["x"]);
        assert_eq!(held("dx"), Vec::<&str>::new());
        assert_eq!(held("sin(y)"), ["y"]);
        assert_eq!(held("1/(x + y)"), ["x", "y"]);
    }

    /// Two states with white noise of 0.5 % and of 5 % of their spread, both held by x·y:
    /// flagged for y alone; a library linear in them is not checked, nor a nonlinear
    /// candidate the identification left out (noise in its variables biases nothing kept).
    #[test]
    fn noisy_variables_of_nonlinear_candidates_are_flagged() {
        let mut state = 99u64;
        let mut gauss = || {
            let mut u = || {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            (-2.0 * u().ln()).sqrt() * (2.0 * std::f64::consts::PI * u()).cos()
        };
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 0.01).collect();
        let mut run = Frame::new("run.csv", "t", t.clone()).unwrap();
        // sines of amplitude √2: spread 1
        let wave = |t: f64, w: f64| std::f64::consts::SQRT_2 * (w * t).sin();
        run.push("x", t.iter().map(|&t| wave(t, 1.0) + 0.005 * gauss()).collect()).unwrap();
        run.push("y", t.iter().map(|&t| wave(t, 0.7) + 0.05 * gauss()).collect()).unwrap();
        run.push("u", t.iter().map(|&t| wave(t, 0.3)).collect()).unwrap();
        let check = noise_check(&chose("x*y"), std::slice::from_ref(&run)).unwrap();
        assert!(!check.passed && !check.refuses, "{}", check.detail);
        assert!(check.detail.contains("`y` 5.") && !check.detail.contains("`x`"), "{}", check.detail);
        assert!(noise_check(&model("x*y"), std::slice::from_ref(&run)).is_none());
        let check = noise_check(&chose("x^2"), std::slice::from_ref(&run)).unwrap();
        assert!(
            check.passed && ["`x` 0.4", "`x` 0.5"].iter().any(|s| check.detail.contains(s)),
            "{}",
            check.detail
        );
        assert!(noise_check(&chose("u"), &[run]).is_none());
    }
}
