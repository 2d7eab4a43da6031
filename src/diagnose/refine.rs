//! Output-error refinement of identified coefficients: all of them adjusted together by
//! Levenberg-Marquardt so that the runs, re-simulated from their initial states with their
//! recorded inputs, match the measured states. The regression (equation error) is biased
//! when its regressors are noisy measured states; the simulation takes only the inputs and
//! the initial state from the data, so this fit is not. The terms stay those the back-end
//! chose. Which states are compared matters: integrals such as positions add the drift of
//! every error before them, and a noisy initial state then dominates them.

use serde::Serialize;

use super::fit::{apply, levenberg_marquardt};
use super::{DiagnoseError, Effect, Hypothesis, Runs};
use crate::model::{Covariance, Model};

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
    /// Integrated autocorrelation time of the re-simulation residuals, in samples.
    pub correlation_time: Option<f64>,
    /// Per coefficient: equation, term, regression value, refined value, standard error
    /// (√τ-corrected).
    pub coefficients: Vec<(String, String, f64, f64, f64)>,
}

/// Refines every coefficient of the model's identified equations against `runs`.
pub fn refine(model: &Model, runs: &Runs) -> Result<Refined, DiagnoseError> {
    let entries: Vec<(String, String, f64)> = model
        .equations()
        .iter()
        .filter(|e| e.identify)
        .flat_map(|e| e.coefficients.iter().map(|(t, v, _)| (e.name.clone(), t.to_string(), *v)))
        .collect();
    if entries.is_empty() {
        return Err(DiagnoseError::Setup("no identified coefficients to refine".into()));
    }
    let hypothesis = Hypothesis {
        name: "output-error refinement".into(),
        effect: Effect::Terms { terms: entries.iter().map(|(e, t, _)| (e.clone(), t.clone())).collect() },
    };
    let before = runs.gap(&runs.simulate(model, &[], &[])?).cost;
    let fit = levenberg_marquardt(runs, model, &hypothesis, vec![0.0; entries.len()])
        .map_err(DiagnoseError::Refinement)?;
    let mut refined = apply(model, &hypothesis, &fit.theta)?;
    // σ²(JᵀJ)⁻¹ assumes independent residuals; re-simulation residuals are strongly
    // correlated in time, so the covariance is widened by their correlation time τ
    let tau = crate::uncertainty::correlation_time(&runs.series(&fit.residuals));
    let widen = tau.unwrap_or(1.0).max(1.0);
    let std_errors: Vec<f64> = fit.std_errors().iter().map(|s| s * widen.sqrt()).collect();
    let mut k = 0;
    for e in model.equations().iter().filter(|e| e.identify) {
        let first = k;
        let eq = refined.equation(&e.name).ok_or_else(|| DiagnoseError::Setup(e.name.clone()))?;
        let intercept = eq.intercept;
        let coefficients: Vec<_> = eq
            .coefficients
            .iter()
            .map(|(t, v, _)| {
                let se = std_errors[k];
                k += 1;
                (t.clone(), *v, se.is_finite().then_some(se))
            })
            .collect();
        let terms = coefficients.iter().map(|c| c.0.clone()).collect();
        refined.set_coefficients(&e.name, coefficients, intercept);
        if let Some(c) = &fit.covariance {
            let matrix =
                (first..k).map(|i| (first..k).map(|j| 0.5 * (c[(i, j)] + c[(j, i)])).collect()).collect();
            // a singular direction (a term the runs do not excite) leaves no usable covariance
            let _ = refined.set_covariance(&e.name, Covariance { terms, matrix, correlation_time: widen });
        }
    }
    let coefficients = entries
        .iter()
        .zip(fit.theta.iter().zip(&std_errors))
        .map(|((e, t, v), (d, se))| (e.clone(), t.clone(), *v, v + d, *se))
        .collect();
    Ok(Refined {
        model: refined,
        cost_before: before,
        cost_after: fit.cost,
        correlation_time: tau,
        coefficients,
    })
}

impl Refined {
    /// The refinement as a person reads it: the cost before and after and, per coefficient,
    /// the regression's value, the refined one, its standard error and the change.
    pub fn text(&self) -> String {
        let r = self;
        use crate::identify::num;
        let mut out = format!(
        "== output-error refinement ==\nre-simulation cost (scaled sum of squares) {} → {}; residual correlation time {} samples\n{:<8} {:<18} {:>13} {:>13} {:>12} {:>8}\n",
        num(r.cost_before),
        num(r.cost_after),
        r.correlation_time.map_or("--".into(), |t| format!("{t:.0}")),
        "equation",
        "term",
        "regression",
        "refined",
        "std. error",
        "change"
    );
        for (eq, term, before, after, se) in &r.coefficients {
            out += &format!(
                "{eq:<8} {term:<18} {:>13} {:>13} {:>12} {:>7.1}%\n",
                num(*before),
                num(*after),
                num(*se),
                100.0 * (after / before - 1.0)
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
        let text = format!(
            r#"
[model]
name = "lag"
[[states]]
name = "x"
[[inputs]]
name = "u"
[equations.x_dot]
state = "x"
candidates = ["u", "x"]
coefficients = {{ "u" = 1.0, "x" = {b} }}
"#
        );
        Model::parse(&text, "lag.toml").unwrap()
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
        let r = refine(&model, &runs).unwrap();
        let b = r.coefficients.iter().find(|c| c.1 == "x").unwrap().3;
        let a = r.coefficients.iter().find(|c| c.1 == "u").unwrap().3;
        assert!((b + 0.5).abs() < 1e-4 && (a - 1.0).abs() < 1e-4, "a = {a}, b = {b}");
        assert!(r.cost_after < 1e-6 * r.cost_before, "{} → {}", r.cost_before, r.cost_after);
        assert!(r.text().contains("output-error refinement"));
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

    #[test]
    fn a_model_without_identified_coefficients_is_refused() {
        let text = "[model]\nname = \"fixed\"\n[[states]]\nname = \"x\"\n[equations.x_dot]\nstate = \"x\"\nidentify = false\ncoefficients = { \"x\" = -1.0 }\n";
        let model = Model::parse(text, "fixed.toml").unwrap();
        let runs = Runs::new(&model, &[step_response()], 0.01, Integrator::Rk4).unwrap();
        assert!(matches!(refine(&model, &runs), Err(DiagnoseError::Setup(_))));
    }
}
