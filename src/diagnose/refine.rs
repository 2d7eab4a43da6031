//! Output-error refinement of identified coefficients: all of them adjusted together by
//! Levenberg-Marquardt so that the runs, re-simulated from their initial states with their
//! recorded inputs, match the measured states. The regression (equation error) is biased
//! when its regressors are noisy measured states; the simulation takes only the inputs and
//! the initial state from the data, so this fit is not. The terms stay those the back-end
//! chose. Which states are compared matters: integrals such as positions add the drift of
//! every error before them, and a noisy initial state then dominates them.

use nalgebra::DMatrix;
use serde::Serialize;

use super::fit::{apply, cost as sum_of_squares, residuals};
use super::sensitivity::{fit_failure, linearise, Free, Linearised};
use super::{DiagnoseError, Effect, EstimateError, Hypothesis, Runs};
use crate::model::{Covariance, Model};
use crate::term::Term;

/// How a refinement is held to the regression it starts from.
#[derive(Clone, Copy)]
pub struct RefineSettings<'a> {
    /// Weight of the regression's estimates as a prior: each coefficient is pulled towards its
    /// regression value with that value's standard error (widened by the residuals'
    /// correlation time) as the prior's standard deviation; 1 is that prior as it is, 0 none
    /// (an unbounded refinement, free to wander where the runs do not hold a coefficient).
    pub prior_weight: f64,
    /// Runs the refinement does not fit but is stopped by: of its iterates, the one that
    /// predicts these best is kept.
    pub validation: Option<&'a Runs>,
    /// Most Levenberg-Marquardt iterations.
    pub iterations: usize,
}

impl Default for RefineSettings<'_> {
    fn default() -> Self {
        RefineSettings { prior_weight: 1e-4, validation: None, iterations: 30 }
    }
}

/// One refined coefficient.
#[derive(Clone, Debug, Serialize)]
pub struct RefinedCoefficient {
    /// Its equation.
    pub equation: String,
    /// Its term.
    pub term: String,
    /// The regression's value.
    pub regression: f64,
    /// The refined value.
    pub refined: f64,
    /// The refined value's standard error (√τ-corrected).
    pub std_error: f64,
    /// The prior's standard deviation (the regression's widened standard error).
    pub prior_sd: f64,
}

impl RefinedCoefficient {
    /// The change in units of the prior's standard deviation.
    pub fn shift(&self) -> f64 {
        (self.refined - self.regression) / self.prior_sd
    }
}

/// An output-error refinement's result.
#[derive(Clone, Debug, Serialize)]
pub struct Refined {
    /// The model with the refined coefficients, their standard errors and covariance (per
    /// equation, from the refinement's Jacobian, with the residuals' correlation time).
    #[serde(skip)]
    pub model: Model,
    /// Scaled sum of squares of the re-simulation over all runs, before.
    pub cost_before: f64,
    /// The same after.
    pub cost_after: f64,
    /// The validation runs' scaled sum of squares before and after, where there are any.
    pub validation: Option<(f64, f64)>,
    /// Why it stopped.
    pub stopped: String,
    /// The step the runs were re-simulated at where a caller coarsened them
    /// ([`Runs::coarser`], `resampled`) or integrated them in finer steps than their samples
    /// (to resolve the motion); the costs are then the runs' at every sample, the correlation
    /// time in coarse steps where resampled.
    pub step: Option<f64>,
    /// Whether the runs were resampled to `step` (coarser than their samples).
    pub resampled: bool,
    /// Levenberg-Marquardt iterations taken (each one re-simulation; an accepted step also
    /// one linearisation).
    pub iterations: usize,
    /// Integrated autocorrelation time of the re-simulation residuals, in samples.
    pub correlation_time: Option<f64>,
    /// Every refined coefficient.
    pub coefficients: Vec<RefinedCoefficient>,
}

/// Refines every coefficient of the model's identified equations against `runs`: Levenberg-
/// Marquardt on the re-simulation's scaled residuals, its Jacobian from forward sensitivities,
/// with the regression's estimates as a prior and, where given, validation runs that stop it.
pub fn refine(model: &Model, runs: &Runs, settings: &RefineSettings<'_>) -> Result<Refined, DiagnoseError> {
    // a prior weight that is no number would make every step's cost NaN: no step is taken and
    // the "refined" model is the regression's, silently
    if !(settings.prior_weight.is_finite() && (0.0..=1e12).contains(&settings.prior_weight)) {
        return Err(DiagnoseError::Setup(format!(
            "the refinement's prior weight {} must be a number from 0 (no prior) to 1e12 (1 holds each coefficient within its standard error; the default is 1e-4)",
            settings.prior_weight
        )));
    }
    if settings.iterations == 0 {
        return Err(DiagnoseError::Setup("the refinement needs at least one iteration".into()));
    }
    // (equation, term, regression value, prior sd)
    let mut entries: Vec<(String, Term, f64, f64)> = Vec::new();
    for e in model.equations().iter().filter(|e| e.identify) {
        let tau = e.covariance.as_ref().map_or(1.0, |c| c.correlation_time.max(1.0));
        for (t, v, se) in &e.coefficients {
            // no standard error: a tenth of the value
            let sd = se.map_or(0.1 * v.abs(), |s| s * tau.sqrt()).max(1e-6 * v.abs()).max(1e-300);
            entries.push((e.name.clone(), t.clone(), *v, sd));
        }
    }
    if entries.is_empty() {
        return Err(DiagnoseError::Setup("no identified coefficients to refine".into()));
    }
    let terms: Vec<Free> = entries.iter().map(|(e, t, _, _)| Free::Term(e.clone(), t.clone())).collect();
    let hypothesis = Hypothesis {
        name: "output-error refinement".into(),
        effect: Effect::Terms {
            terms: entries.iter().map(|(e, t, _, _)| (e.clone(), t.to_string())).collect(),
        },
    };
    let k = entries.len();
    let prior: Vec<f64> = entries.iter().map(|(_, _, _, sd)| settings.prior_weight / (sd * sd)).collect();
    let prior_cost = |theta: &[f64]| theta.iter().zip(&prior).map(|(t, p)| p * t * t).sum::<f64>();
    let simulate_cost =
        |runs: &Runs, theta: &[f64]| residuals(runs, model, &hypothesis, theta).map(|r| sum_of_squares(&r));
    let before = runs.gap(&runs.simulate(model, &[], &[])?).cost;
    let mut theta = vec![0.0; k];
    let mut lin = linearise(runs, model, &terms).map_err(|e| fit_failure(e, "at the start"))?;
    let mut cost = sum_of_squares(&lin.residuals) + prior_cost(&theta);
    let validation_before = settings.validation.and_then(|v| simulate_cost(v, &theta));
    let mut best = (theta.clone(), validation_before.unwrap_or(f64::NAN));
    let mut rises = 0;
    let mut lambda = 1e-3;
    let mut stopped = "at the most iterations".to_string();
    let mut iterations = 0;
    for _ in 0..settings.iterations {
        iterations += 1;
        let (mut a, mut g) = (lin.jtj.clone(), lin.jtr.clone());
        for i in 0..k {
            a[(i, i)] += prior[i];
            g[i] += prior[i] * theta[i];
        }
        let mut damped = a.clone();
        for i in 0..k {
            damped[(i, i)] += lambda * a[(i, i)].max(1e-300);
        }
        let Some(step) = damped.lu().solve(&g) else {
            stopped = "singular normal equations".into();
            break;
        };
        let trial: Vec<f64> = theta.iter().zip(step.iter()).map(|(t, d)| t - d).collect();
        match simulate_cost(runs, &trial).map(|c| c + prior_cost(&trial)) {
            Some(c) if c < cost => {
                let improvement = (cost - c) / cost.max(1e-300);
                let applied = apply(model, &hypothesis, &trial)?;
                let Ok(next) = linearise(runs, &applied, &terms) else {
                    lambda *= 10.0;
                    continue;
                };
                (theta, lin, cost) = (trial, next, c);
                lambda = (lambda / 10.0).max(1e-12);
                if let Some(v) = settings.validation {
                    // the validation runs stop it: keep the iterate that predicts them best
                    match simulate_cost(v, &theta) {
                        Some(vc) if best.1.is_nan() || vc < best.1 => {
                            best = (theta.clone(), vc);
                            rises = 0;
                        }
                        _ => rises += 1,
                    }
                    if rises >= 3 {
                        stopped = "the validation runs' error rose three times".into();
                        break;
                    }
                }
                // a step that lowers the cost by less than 0.1 % changes no prediction that
                // matters (the steps shrink geometrically by then)
                if improvement < 1e-3 {
                    stopped = "converged".into();
                    break;
                }
            }
            _ => {
                lambda = (lambda * 10.0).max(1e-6);
                if lambda > 1e10 {
                    stopped = "no step lowers the error".into();
                    break;
                }
            }
        }
    }
    if settings.validation.is_some() && best.0 != theta {
        theta = best.0.clone();
        let applied = apply(model, &hypothesis, &theta)?;
        lin = linearise(runs, &applied, &terms)
            .map_err(|_| DiagnoseError::Refinement(EstimateError::Diverges("on the way")))?;
    }
    let Linearised { residuals: r, jtj, .. } = lin;
    let mut refined = apply(model, &hypothesis, &theta)?;
    let data_cost = sum_of_squares(&r);
    // σ²(JᵀJ + P)⁻¹ assumes independent residuals; re-simulation residuals are strongly
    // correlated in time, so the covariance is widened by their correlation time τ
    let tau = crate::uncertainty::correlation_time(&runs.series(&r));
    let widen = tau.unwrap_or(1.0).max(1.0);
    let samples = runs.residual_count().min(r.len());
    let sigma2 = data_cost / (samples as f64 - k as f64).max(1.0);
    let mut info = jtj;
    for i in 0..k {
        info[(i, i)] += prior[i];
    }
    let covariance: Option<DMatrix<f64>> = info.try_inverse().map(|inv| inv * sigma2 * widen);
    let std_errors: Vec<f64> =
        (0..k).map(|i| covariance.as_ref().map_or(f64::NAN, |c| c[(i, i)].max(0.0).sqrt())).collect();
    let mut at = 0;
    for e in model.equations().iter().filter(|e| e.identify) {
        let first = at;
        let eq = refined.equation(&e.name).ok_or_else(|| DiagnoseError::Setup(e.name.clone()))?;
        let intercept = eq.intercept;
        let coefficients: Vec<_> = eq
            .coefficients
            .iter()
            .map(|(t, v, _)| {
                let se = std_errors[at];
                at += 1;
                (t.clone(), *v, se.is_finite().then_some(se))
            })
            .collect();
        let terms = coefficients.iter().map(|c| c.0.clone()).collect();
        refined.set_coefficients(&e.name, coefficients, intercept);
        if let Some(c) = &covariance {
            let matrix =
                (first..at).map(|i| (first..at).map(|j| 0.5 * (c[(i, j)] + c[(j, i)])).collect()).collect();
            // a singular direction (a term the runs do not excite) leaves no usable covariance
            let _ = refined.set_covariance(&e.name, Covariance { terms, matrix, correlation_time: widen });
        }
    }
    let coefficients = entries
        .iter()
        .zip(theta.iter().zip(&std_errors))
        .map(|((e, t, v, sd), (d, se))| RefinedCoefficient {
            equation: e.clone(),
            term: t.to_string(),
            regression: *v,
            refined: v + d,
            std_error: *se,
            prior_sd: *sd,
        })
        .collect();
    let validation = match (validation_before, settings.validation) {
        (Some(b), Some(v)) => simulate_cost(v, &theta).map(|a| (b, a)),
        _ => None,
    };
    Ok(Refined {
        model: refined,
        cost_before: before,
        cost_after: data_cost,
        validation,
        stopped,
        step: None,
        resampled: false,
        iterations,
        correlation_time: tau,
        coefficients,
    })
}

impl Refined {
    /// The refinement as a person reads it: the cost before and after and, per coefficient,
    /// the regression's value, the refined one, its standard error, the change, and the change
    /// in units of the prior's standard deviation (where it is large, why).
    pub fn text(&self) -> String {
        use crate::identify::{num, sig};
        let r = self;
        let mut out = format!(
            "== output-error refinement ==\nre-simulation cost (scaled sum of squares) {} → {}; residual correlation time {} {}; stopped: {} ({} iterations)\n",
            sig(r.cost_before, 4),
            sig(r.cost_after, 4),
            r.correlation_time.map_or("--".into(), |t| format!("{t:.0}")),
            if r.resampled { "steps" } else { "samples" },
            r.stopped,
            r.iterations
        );
        match r.step {
            Some(step) if r.resampled => out += &format!(
                "re-simulated at a step of {} s (the runs resampled, anti-aliased; there the regression's model and the refined one re-simulate them as at their samples); the costs at every sample\n",
                sig(step, 3)
            ),
            Some(step) => out += &format!(
                "integrated at a step of {} s, finer than the samples: the step that resolves the motion (the regression's model's and the refined one's)\n",
                sig(step, 3)
            ),
            None => {}
        }
        if let Some((b, a)) = r.validation {
            out += &format!("validation runs (not fitted): {} → {}\n", sig(b, 4), sig(a, 4));
        }
        out += &format!(
            "{:<8} {:<18} {:>13} {:>13} {:>12} {:>8} {:>8}\n",
            "equation", "term", "regression", "refined", "std. error", "change", "shift/σ"
        );
        for c in &r.coefficients {
            let why = if c.shift().abs() > 2.0 {
                "  the runs pull it beyond 2 σ of the regression: the prior holds it back"
            } else {
                ""
            };
            out += &format!(
                "{:<8} {:<18} {:>13} {:>13} {:>12} {:>7.1}% {:>8.2}{why}\n",
                c.equation,
                c.term,
                num(c.regression),
                num(c.refined),
                sig(c.std_error, 3),
                100.0 * (c.refined / c.regression - 1.0),
                c.shift()
            );
        }
        out + "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Frame;
    use crate::sim::Integrator;

    /// ẋ = a·u + b·x: identified as a = 1, b = −0.3; the runs come from a = 1, b = −0.5.
    fn lag(b: f64) -> Model {
        crate::diagnose::fixtures::lag("x", b)
    }

    /// A step of u = 1 from x = 0: x(t) = (1 − e^(−kt))/k, k = 0.5, in closed form.
    fn step_response() -> Frame {
        let t: Vec<f64> = (0..=100).map(|i| 0.1 * i as f64).collect();
        let x = t.iter().map(|t| (1.0 - (-0.5 * t).exp()) / 0.5).collect();
        let mut f = Frame::new("step", "t", t.clone()).unwrap();
        f.push("x", x).unwrap();
        f.push("u", vec![1.0; t.len()]).unwrap();
        f
    }

    #[test]
    fn refinement_finds_the_coefficients_of_the_closed_form() {
        let model = lag(-0.3);
        let runs = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap();
        let r = refine(&model, &runs, &RefineSettings { prior_weight: 0.0, ..Default::default() }).unwrap();
        let b = r.coefficients.iter().find(|c| c.term == "x").unwrap().refined;
        let a = r.coefficients.iter().find(|c| c.term == "u").unwrap().refined;
        assert!((b + 0.5).abs() < 1e-4 && (a - 1.0).abs() < 1e-4, "a = {a}, b = {b}");
        assert!(r.cost_after < 1e-6 * r.cost_before, "{} → {}", r.cost_before, r.cost_after);
        assert!(r.text().contains("output-error refinement"));
    }

    /// A run sampled far faster than the model moves may be coarsened, up to the most asked
    /// for; one whose model moves within a few samples, or whose input does, may not.
    #[test]
    fn runs_are_coarsened_as_far_as_the_model_and_the_inputs_allow() {
        let sampled = |dt: f64, input: &dyn Fn(f64) -> f64| {
            let t: Vec<f64> = (0..=1000).map(|i| dt * i as f64).collect();
            let mut f = Frame::new("run", "t", t.clone()).unwrap();
            // from x = 1, away from where the input holds it: the model's own mode is excited
            f.push("x", t.iter().map(|&t| (-0.5 * t).exp()).collect()).unwrap();
            f.push("u", t.iter().map(|&t| input(t)).collect()).unwrap();
            f
        };
        let coarsest = |b: f64, frame: Frame| {
            let model = lag(b);
            let runs = Runs::new(&model, &[frame], 0.01, Integrator::Rk4).unwrap();
            let fine = runs.simulate(&model, &[], &[]).unwrap();
            runs.coarsest(&model, &fine, 1e-3, 8).0
        };
        let slow = |t: f64| (0.5 * t).sin();
        // time constant 2 s, sampled every 0.01 s: RK4 at 0.08 s re-simulates it as at 0.01 s
        assert_eq!(coarsest(-0.5, sampled(0.01, &slow)), 8);
        // time constant 0.01 s: one sample per time constant already
        assert_eq!(coarsest(-100.0, sampled(0.01, &slow)), 1);
        // a slow model driven at 10 Hz: a coarser sampling filters the input the model follows
        let fast = |t: f64| (2.0 * std::f64::consts::PI * 10.0 * t).sin();
        let factor = coarsest(-0.5, sampled(0.01, &fast));
        assert!(factor < 4, "{factor}");
        // the coarsened runs keep what a re-simulation reads, at the coarse step
        let runs = Runs::new(&lag(-0.5), &[sampled(0.01, &slow)], 0.01, Integrator::Rk4).unwrap();
        let coarse = runs.coarser(4).unwrap();
        assert_eq!(coarse.frames[0].len(), 251);
        assert!(
            (coarse.settings[0].dt - 0.04).abs() < 1e-12 && (coarse.settings[0].sample - 0.04).abs() < 1e-12
        );
        // coarsened runs are refined to the same coefficients
        let model = lag(-0.3);
        let runs = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap().coarser(2).unwrap();
        let r = refine(&model, &runs, &RefineSettings { prior_weight: 0.0, ..Default::default() }).unwrap();
        let b = r.coefficients.iter().find(|c| c.term == "x").unwrap().refined;
        assert!((b + 0.5).abs() < 1e-3, "b = {b}");
    }

    #[test]
    fn the_true_model_has_no_gap_and_a_wrong_one_has() {
        let runs = Runs::new(&lag(-0.5), &[step_response()], 0.01, Integrator::Rk4).unwrap();
        let gap = |b: f64| runs.gap(&runs.simulate(&lag(b), &[], &[]).unwrap());
        assert!(gap(-0.5).cost < 1e-10, "{:?}", gap(-0.5));
        let wrong = gap(-0.3);
        // x(10) is 1.98 for k = 0.5 and 3.17 for k = 0.3: the largest gap is at the end
        assert!((wrong.states[0].3 - (0.95021 / 0.3 - 0.99326 / 0.5)).abs() < 1e-3, "{wrong:?}");
    }

    /// The prior holds: at a huge weight the coefficients stay at the regression's values;
    /// validation runs keep the iterate that predicts them best.
    #[test]
    fn the_prior_holds_and_validation_runs_stop() {
        let model = lag(-0.3);
        let runs = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap();
        let held =
            refine(&model, &runs, &RefineSettings { prior_weight: 1e12, ..Default::default() }).unwrap();
        let b = held.coefficients.iter().find(|c| c.term == "x").unwrap();
        assert!((b.refined + 0.3).abs() < 1e-3, "{b:?}");
        // validation: the same step response, so the best iterate on it is the converged one
        let validation = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap();
        let r = refine(
            &model,
            &runs,
            &RefineSettings { prior_weight: 0.0, validation: Some(&validation), ..Default::default() },
        )
        .unwrap();
        let (before, after) = r.validation.unwrap();
        assert!(after < 1e-6 * before, "{before} → {after}");
        assert!(r.text().contains("validation runs (not fitted)"));
    }

    #[test]
    fn a_model_without_identified_coefficients_is_refused() {
        let text = "[model]\nname = \"fixed\"\n[[states]]\nname = \"x\"\n[equations.x_dot]\nstate = \"x\"\nidentify = false\ncoefficients = { \"x\" = -1.0 }\n";
        let model = Model::parse(text, "fixed.toml").unwrap();
        let runs = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap();
        assert!(matches!(refine(&model, &runs, &RefineSettings::default()), Err(DiagnoseError::Setup(_))));
    }
}
