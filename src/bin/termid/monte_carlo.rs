//! Monte-Carlo prediction uncertainty for `simulate` and `validate`: models drawn from the
//! stored coefficient covariance (library: `termid::uncertainty`), each simulated by the
//! command's own closure, with a progress bar, failures counted rather than fatal, and a table
//! of the spread of every metric.

use std::collections::BTreeMap;

use anyhow::{bail, Result};
use termid::model::Model;
use termid::uncertainty::{spread, uncertain_equations, Normal, Sampler, Spread};

/// The results of simulating drawn models.
pub struct Draws<T> {
    /// Draws asked for.
    pub draws: usize,
    /// The seed.
    pub seed: u64,
    /// The equations whose coefficients were drawn.
    pub equations: Vec<String>,
    /// What each draw that ran produced.
    pub results: Vec<T>,
    /// Draws that failed (e.g. diverged).
    pub failed: usize,
    /// Why the first failure failed.
    pub first_failure: Option<String>,
}

impl<T> Draws<T> {
    /// Simulates `n` models drawn from `model`'s covariance (seeded) with `simulate`, each
    /// keeping about `values` numbers (refused before the first draw if all would not fit).
    pub fn run(
        model: &Model,
        n: usize,
        seed: u64,
        values: usize,
        simulate: impl Fn(&Model) -> Result<T>,
    ) -> Result<Draws<T>> {
        termid::budget::check_values(
            n as f64 * values as f64,
            || {
                format!(
                    "{} Monte-Carlo draws of {} values each",
                    termid::budget::count(n as f64),
                    termid::budget::count(values as f64)
                )
            },
            "ask for fewer draws (a few hundred give a 90 % band)",
        )?;
        let equations = uncertain_equations(model);
        if equations.is_empty() {
            bail!(
                "{}: no coefficient covariance stored, so there is nothing to draw from; `termid identify --model … --out FILE` writes one",
                model.path
            );
        }
        let mut normal = Normal::new(seed);
        let sampler = Sampler::new(model);
        let mut out = Draws { draws: n, seed, equations, results: vec![], failed: 0, first_failure: None };
        let bar = crate::progress::counter(n as u64, "Monte-Carlo draws");
        for _ in 0..n {
            match simulate(&sampler.draw(&mut normal)) {
                Ok(r) => out.results.push(r),
                Err(e) => {
                    out.failed += 1;
                    out.first_failure.get_or_insert(format!("{e:#}"));
                }
            }
            bar.inc(1);
        }
        bar.finish_and_clear();
        Ok(out)
    }

    /// Whether the draws that ran describe the model: no more than
    /// [`MAX_FAILED`](termid::uncertainty::MAX_FAILED) of them
    /// failed. Survivors of a set that mostly failed are the draws that happened to stay
    /// stable, not a sample of the model's uncertainty.
    pub fn usable(&self) -> bool {
        termid::uncertainty::usable(self.draws, self.results.len())
    }

    /// The results to draw as a band: all of them where [`Draws::usable`], none otherwise.
    pub fn shown(&self) -> &[T] {
        if self.usable() {
            &self.results
        } else {
            &[]
        }
    }

    /// The spread of the metrics each result gives (one JSON record per result); empty where
    /// the draws are not [`Draws::usable`].
    pub fn spread(&self, metrics: impl Fn(&T) -> Vec<serde_json::Value>) -> BTreeMap<String, Spread> {
        spread(&self.shown().iter().flat_map(metrics).collect::<Vec<_>>())
    }

    /// Why the spread is not shown, and what helps (None where it is).
    pub fn refusal(&self) -> Option<String> {
        termid::uncertainty::refusal(self.draws, self.results.len(), self.first_failure.as_deref())
    }

    /// JSON summary: draws, failures and the spread of every metric (null where not usable,
    /// with the reason).
    pub fn summary(&self, spread: &BTreeMap<String, Spread>) -> serde_json::Value {
        serde_json::json!({
            "draws": self.draws,
            "seed": self.seed,
            "equations": self.equations,
            "failed": self.failed,
            "first_failure": self.first_failure,
            "usable": self.usable(),
            "refused": self.refusal(),
            "spread": if self.usable() { serde_json::to_value(spread).unwrap_or_default() } else { serde_json::Value::Null },
        })
    }

    /// One line: how many models were drawn from what, how many ran.
    pub fn headline(&self) -> String {
        // `parameters` stands for the free parameters' covariance, the rest are equations
        let (params, equations): (Vec<&String>, Vec<&String>) =
            self.equations.iter().partition(|e| e.as_str() == "parameters");
        let mut what = Vec::new();
        if !equations.is_empty() {
            what.push(format!(
                "{} coefficients",
                equations.iter().map(|e| e.as_str()).collect::<Vec<_>>().join(", ")
            ));
        }
        if !params.is_empty() {
            what.push("the free parameters".to_string());
        }
        format!(
            "Monte Carlo: {} models with {} drawn from their covariance × correlation time (seed {}); {} ran, {} failed",
            self.draws,
            what.join(" and "),
            self.seed,
            self.results.len(),
            self.failed
        )
    }

    /// A table of each metric: nominal value, mean, sd and the 5-95 % range over the draws.
    pub fn text(&self, spread: &BTreeMap<String, Spread>, nominal: &serde_json::Value) -> String {
        let mut out = format!("\n{}\n", self.headline());
        if let Some(why) = self.refusal() {
            return out + &format!("  warning: {why}\n");
        }
        if let Some(why) = &self.first_failure {
            out += &format!("  first failure: {why}\n");
        }
        out += &format!(
            "  {:<28} {:>10} {:>10} {:>10} {:>23}\n",
            "metric", "nominal", "mean", "sd", "5 % … 95 %"
        );
        for (k, s) in spread {
            let nom = k.split('.').try_fold(nominal, |v, key| v.get(key)).and_then(serde_json::Value::as_f64);
            // the metric in words with its unit, each number at the decimals its unit supports
            // (the sd one more)
            let (name, unit, d) = termid::plugin::metric_label(k);
            let label = termid::plot::labelled(&name, unit);
            let e = d + 1;
            out += &format!(
                "  {label:<28} {:>10} {:>10.d$} {:>10.e$} {:>10.d$} … {:<10.d$}\n",
                nom.map_or("--".into(), |v| format!("{v:.d$}")),
                s.mean,
                s.sd,
                s.p05,
                s.p95
            );
        }
        out
    }
}

/// Each free parameter's effect on the numbers `predict` makes of a model, one sd up and down
/// (with a progress bar), where draws were made (`drawn`) and the model holds the free
/// parameters' covariance; empty otherwise.
pub fn parameter_effects(
    model: &Model,
    drawn: bool,
    predict: impl Fn(&Model) -> Result<serde_json::Value>,
) -> Vec<termid::uncertainty::ParameterEffect> {
    let Some(c) = model.spec().parameter_covariance.as_ref().filter(|_| drawn) else { return Vec::new() };
    let bar = crate::progress::counter(2 * c.names.len() as u64, "each parameter ±1 sd");
    let effects = termid::uncertainty::parameter_effects(model, |m| {
        bar.inc(1);
        predict(m).map_err(|e| format!("{e:#}"))
    });
    bar.finish_and_clear();
    effects
}

/// The JSON of what the spread of each number of `nominal` comes from: each parameter's
/// effects and each number's attribution (`parameter_effects`, `spread_from`).
pub fn effects_json(
    model: &Model,
    effects: &[termid::uncertainty::ParameterEffect],
    nominal: &serde_json::Value,
) -> (serde_json::Value, serde_json::Value) {
    let from: serde_json::Map<String, serde_json::Value> = termid::uncertainty::numbers(nominal)
        .keys()
        .filter_map(|k| {
            let a = termid::uncertainty::attribution(model, effects, k)?;
            Some((k.clone(), serde_json::to_value(a).ok()?))
        })
        .collect();
    (serde_json::to_value(effects).unwrap_or_default(), from.into())
}

/// What the spread of each metric comes from: the free parameters whose exact values would
/// remove most of its variance (linearised, one sd of each up and down; the three largest
/// shares), with the linearised sd beside the draws' (near each other where the prediction is
/// about linear in the parameters); a parameter one sd away from which the manoeuvre fails,
/// named. Empty without effects.
pub fn effects_text(
    model: &Model,
    effects: &[termid::uncertainty::ParameterEffect],
    spread: &BTreeMap<String, Spread>,
) -> String {
    if effects.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "\nwhat the spread comes from: the share of each metric's variance that knowing a free parameter exactly would remove (linearised from each parameter one sd up and down; correlated parameters share theirs), the three largest, and the linearised sd beside the draws'\n",
    );
    for (key, s) in spread {
        let (name, unit, d) = termid::plugin::metric_label(key);
        let e = d + 1;
        let line = match termid::uncertainty::attribution(model, effects, key) {
            Some(a) => {
                let top: Vec<String> = a
                    .explained
                    .iter()
                    .take(3)
                    .map(|(p, share)| format!("{p} {:.0} %", 100.0 * share))
                    .collect();
                format!("{}   (linearised sd {:.e$}; draws {:.e$})", top.join(", "), a.linearised_sd, s.sd)
            }
            None => "--".to_string(),
        };
        out += &format!("  {:<28} {line}\n", termid::plot::labelled(&name, unit));
    }
    for e in effects {
        if let Some(why) = &e.failed {
            out += &format!(
                "  warning: one sd from its estimate ({}), `{}` leaves no prediction: {why}\n",
                termid::identify::num(e.sd),
                e.parameter
            );
        }
    }
    out
}
