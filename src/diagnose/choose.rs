//! Choosing a model by what it predicts: each candidate configuration (a back-end, a
//! candidate library, a step rule: any variant of the model file) is identified on all runs
//! but one and re-simulated on the one left out, from its recorded initial state with its
//! recorded inputs; the configuration whose held-out runs it predicts best is chosen and then
//! identified on all runs. A regression's own fit (R², F) says how well an equation explains
//! the accelerations it was given; only a simulation of runs it has not seen says how well
//! the model will predict a manoeuvre, which is what it is for.
//!
//! Held-out errors are themselves estimates: configurations whose errors differ by less than
//! their standard error are not told apart by the runs. Among those within one standard error
//! of the lowest, the first in the caller's order is chosen (the one-standard-error rule of
//! Breiman et al. 1984, with the caller's order of preference in place of "the simplest").

use serde::Serialize;

use super::{DiagnoseError, Runs};
use crate::data::Frame;
use crate::identify::{identify_model, IdentifiedModel, ModelIdentification, RunStatistics};
use crate::model::Model;
use crate::select::Backend;
use crate::sim::Integrator;

/// How held-out runs are re-simulated and compared.
#[derive(Clone, Debug)]
pub struct Prediction {
    /// The states compared (each scaled by its spread in the held-out run); empty: every
    /// state of an identified equation.
    pub states: Vec<String>,
    /// Integration step, s (the runs' own sampling is kept for the comparison); `None`: the
    /// held-out run's sample step, one step per sample (its recorded inputs are known only
    /// at the samples, and the step scales with the system's own time).
    pub dt: Option<f64>,
    /// Integrator.
    pub integrator: Integrator,
    /// Simulate with the identified intercepts.
    pub intercepts: bool,
}

impl Default for Prediction {
    fn default() -> Self {
        Prediction { states: vec![], dt: None, integrator: Integrator::Rk4, intercepts: false }
    }
}

/// One configuration's leave-one-run-out record.
#[derive(Clone, Debug, Serialize)]
pub struct Configuration {
    /// What the configuration is, as the caller named it.
    pub label: String,
    /// Per held-out run: its name and the scaled sum of squares of the re-simulation (∞ where
    /// the identification failed or the simulation left its bounds).
    pub folds: Vec<(String, f64)>,
    /// Mean over the runs of the scaled mean square (each run's cost over its samples and
    /// states): 1 is an error the size of the signals' own spread.
    pub score: f64,
    /// Standard error of that mean (the spread of the runs' mean squares over √runs).
    pub standard_error: f64,
    /// Runs whose prediction failed (diverged or could not be identified).
    pub failed: usize,
}

/// The table chosen from and the chosen model.
#[derive(Clone, Debug)]
pub struct Chosen {
    /// Every configuration's record, in the order given.
    pub candidates: Vec<Configuration>,
    /// Index of the chosen configuration: the first in the given order whose score is within
    /// one standard error of the lowest (among those with no failed run, else fewest failures).
    pub best: usize,
    /// Index of the configuration with the lowest score.
    pub lowest: usize,
    /// The chosen configuration identified on all runs.
    pub identified: IdentifiedModel,
}

/// Leave-one-run-out prediction error of each `(label, model)` configuration on `frames`
/// (prepared runs: states and their derivatives), then the best identified on all of them.
pub fn choose_by_prediction(
    configurations: &[(String, Model)],
    frames: &[Frame],
    how: &ModelIdentification<'_>,
    prediction: &Prediction,
    progress: &mut dyn FnMut(&str),
) -> Result<Chosen, DiagnoseError> {
    if frames.len() < 2 {
        return Err(DiagnoseError::Setup(
            "choosing by prediction leaves one run out in turn: it needs at least two runs".into(),
        ));
    }
    if configurations.is_empty() {
        return Err(DiagnoseError::Setup("no configurations to choose from".into()));
    }
    let mut candidates = Vec::with_capacity(configurations.len());
    for (label, model) in configurations {
        progress(label);
        // the folds' models are only simulated: their back-ends need not prove what only a
        // report reads
        let fold_model = model
            .edit(|file| {
                for e in file.equations.values_mut() {
                    e.backend = e.backend.as_ref().map(Backend::for_prediction);
                }
            })
            .map_err(|e| DiagnoseError::Setup(e.to_string()))?;
        let mut folds = Vec::with_capacity(frames.len());
        let mut mean_squares = Vec::with_capacity(frames.len());
        // each run's statistics once; a fold merges all but its own
        let statistics = RunStatistics::of(&fold_model, frames, how);
        for k in 0..frames.len() {
            let held = &frames[k];
            let identified = match &statistics {
                Ok(s) => s.identify_without(&fold_model, k),
                // a run the statistics refused fails only the folds that train on it
                Err(_) => {
                    let training: Vec<Frame> =
                        frames.iter().enumerate().filter(|(i, _)| *i != k).map(|(_, f)| f.clone()).collect();
                    identify_model(&fold_model, &training, how, &mut |_| {})
                }
            };
            let cost = identified.ok().and_then(|id| held_out_cost(&id.model, held, prediction, how).ok());
            let rows = (held.len() * compared(model, prediction).len()).max(1) as f64;
            folds.push((held.origin().to_string(), cost.unwrap_or(f64::INFINITY)));
            mean_squares.push(cost.map_or(f64::INFINITY, |c| c / rows));
        }
        let failed = mean_squares.iter().filter(|c| !c.is_finite()).count();
        let finite: Vec<f64> = mean_squares.iter().copied().filter(|c| c.is_finite()).collect();
        // a configuration that fails a run ranks after every one that fails none
        let (score, standard_error) = if failed > 0 || finite.is_empty() {
            (f64::INFINITY, f64::INFINITY)
        } else {
            let k = finite.len() as f64;
            let mean = finite.iter().sum::<f64>() / k;
            let var = finite.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
            (mean, (var / k).sqrt())
        };
        candidates.push(Configuration { label: label.clone(), folds, score, standard_error, failed });
    }
    let lowest = (0..candidates.len())
        .min_by(|&a, &b| {
            let (x, y) = (&candidates[a], &candidates[b]);
            x.failed.cmp(&y.failed).then(x.score.total_cmp(&y.score))
        })
        .unwrap_or(0);
    let limit = candidates[lowest].score + candidates[lowest].standard_error;
    let best = (0..candidates.len())
        .find(|&i| candidates[i].failed == candidates[lowest].failed && candidates[i].score <= limit)
        .unwrap_or(lowest);
    progress(&format!("{} on all runs", candidates[best].label));
    let identified = identify_model(&configurations[best].1, frames, how, &mut |_| {})
        .map_err(|e| DiagnoseError::Setup(format!("the chosen `{}`: {e}", candidates[best].label)))?;
    Ok(Chosen { candidates, best, lowest, identified })
}

/// The states a prediction compares.
fn compared(model: &Model, prediction: &Prediction) -> Vec<String> {
    if !prediction.states.is_empty() {
        return prediction.states.clone();
    }
    model.identifiable().iter().filter_map(|e| model.equation(e).map(|eq| eq.state.clone())).collect()
}

/// Scaled sum of squares of `model` re-simulating `run`.
fn held_out_cost(
    model: &Model,
    run: &Frame,
    prediction: &Prediction,
    how: &ModelIdentification<'_>,
) -> Result<f64, DiagnoseError> {
    let intercepts = prediction.intercepts && how.intercept;
    let dt = prediction.dt.unwrap_or_else(|| crate::data::sample_step(std::slice::from_ref(run)));
    let runs = Runs::new(model, std::slice::from_ref(run), dt, prediction.integrator)?
        .with_intercepts(intercepts)
        .comparing(model, &compared(model, prediction))?;
    let sims = runs.simulate(model, &[], &[])?;
    Ok(runs.gap(&sims).cost)
}

impl Chosen {
    /// The table as a person reads it: per configuration its mean scaled error over the
    /// held-out runs and the worst run, the chosen one marked.
    pub fn text(&self) -> String {
        let mut out = String::from(
            "== chosen by prediction: each run re-simulated by a model identified on the others ==\n",
        );
        out += "error: mean square of the compared states over a held-out run, each state scaled by its\nspread (1 = as large as the signal), averaged over the runs, ± its standard error\n";
        out +=
            &format!("{:<28} {:>14} {:>12} {:>24}\n", "configuration", "mean error", "± s.e.", "worst run");
        for (i, c) in self.candidates.iter().enumerate() {
            let worst = c.folds.iter().max_by(|a, b| a.1.total_cmp(&b.1));
            let (score, se) = if c.failed > 0 {
                (format!("{} failed", c.failed), "--".to_string())
            } else {
                (crate::identify::num(c.score), crate::identify::num(c.standard_error))
            };
            let mark = if i == self.best {
                "  ← chosen"
            } else if i == self.lowest {
                "  (lowest)"
            } else {
                ""
            };
            out += &format!(
                "{:<28} {:>14} {:>12} {:>24}{mark}\n",
                c.label,
                score,
                se,
                worst.map_or("--".to_string(), |w| super::file_name(&w.0)),
            );
        }
        if self.best != self.lowest {
            out += &format!(
                "`{}` is within one standard error of the lowest, `{}`: the runs do not tell them apart, and it comes first in the order given\n",
                self.candidates[self.best].label, self.candidates[self.lowest].label
            );
        }
        out + "\n"
    }
}
