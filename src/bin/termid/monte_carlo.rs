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

    /// The spread of the metrics each result gives (one JSON record per result).
    pub fn spread(&self, metrics: impl Fn(&T) -> Vec<serde_json::Value>) -> BTreeMap<String, Spread> {
        spread(&self.results.iter().flat_map(metrics).collect::<Vec<_>>())
    }

    /// JSON summary: draws, failures and the spread of every metric.
    pub fn summary(&self, spread: &BTreeMap<String, Spread>) -> serde_json::Value {
        serde_json::json!({
            "draws": self.draws,
            "seed": self.seed,
            "equations": self.equations,
            "failed": self.failed,
            "first_failure": self.first_failure,
            "spread": spread,
        })
    }

    /// One line: how many models were drawn from what, how many ran.
    pub fn headline(&self) -> String {
        format!(
            "Monte Carlo: {} models with {} coefficients drawn from their covariance × correlation time (seed {}); {} ran, {} failed",
            self.draws,
            self.equations.join(", "),
            self.seed,
            self.results.len(),
            self.failed
        )
    }

    /// A table of each metric: nominal value, mean, sd and the 5-95 % range over the draws.
    pub fn text(&self, spread: &BTreeMap<String, Spread>, nominal: &serde_json::Value) -> String {
        let mut out = format!("\n{}\n", self.headline());
        if let Some(why) = &self.first_failure {
            out += &format!("  first failure: {why}\n");
        }
        out += &format!(
            "  {:<28} {:>10} {:>10} {:>10} {:>23}\n",
            "metric", "nominal", "mean", "sd", "5 % … 95 %"
        );
        for (k, s) in spread {
            let nom = k.split('.').try_fold(nominal, |v, key| v.get(key)).and_then(serde_json::Value::as_f64);
            out += &format!(
                "  {k:<28} {:>10} {:>10.4} {:>10.4} {:>10.4} … {:<10.4}\n",
                nom.map_or("--".into(), |v| format!("{v:.4}")),
                s.mean,
                s.sd,
                s.p05,
                s.p95
            );
        }
        out
    }
}
