//! Choosing a model by what it predicts: each candidate configuration (a back-end, a
//! candidate library, a step rule: any variant of the model file) is identified on all runs
//! but one and re-simulated on the one left out, from its recorded initial state with its
//! recorded inputs; the configuration whose held-out runs it predicts best is chosen and then
//! identified on all runs. A regression's own fit (R², F) says how well an equation explains
//! the accelerations it was given; only a simulation of runs it has not seen says how well
//! the model will predict a manoeuvre, which is what it is for.

use serde::Serialize;

use super::{DiagnoseError, Runs};
use crate::data::Frame;
use crate::identify::{identify_model, IdentifiedModel, ModelIdentification};
use crate::model::Model;
use crate::sim::Integrator;

/// How held-out runs are re-simulated and compared.
#[derive(Clone, Debug)]
pub struct Prediction {
    /// The states compared (each scaled by its spread in the held-out run); empty: every
    /// state of an identified equation.
    pub states: Vec<String>,
    /// Integration step, s (the runs' own sampling is kept for the comparison).
    pub dt: f64,
    /// Integrator.
    pub integrator: Integrator,
    /// Simulate with the identified intercepts.
    pub intercepts: bool,
}

impl Default for Prediction {
    fn default() -> Self {
        Prediction { states: vec![], dt: 0.01, integrator: Integrator::Rk4, intercepts: false }
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
    /// Runs whose prediction failed (diverged or could not be identified).
    pub failed: usize,
}

/// The table chosen from and the chosen model.
#[derive(Clone, Debug)]
pub struct Chosen {
    /// Every configuration's record, in the order given.
    pub candidates: Vec<Configuration>,
    /// Index of the chosen configuration (lowest score among those with no failed run, else
    /// fewest failures).
    pub best: usize,
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
        let mut folds = Vec::with_capacity(frames.len());
        let mut mean_squares = Vec::with_capacity(frames.len());
        for k in 0..frames.len() {
            let training: Vec<Frame> =
                frames.iter().enumerate().filter(|(i, _)| *i != k).map(|(_, f)| f.clone()).collect();
            let held = &frames[k];
            let cost = identify_model(model, &training, how, &mut |_| {})
                .ok()
                .and_then(|id| held_out_cost(&id.model, held, prediction, how).ok());
            let rows = (held.len() * compared(model, prediction).len()).max(1) as f64;
            folds.push((held.origin().to_string(), cost.unwrap_or(f64::INFINITY)));
            mean_squares.push(cost.map_or(f64::INFINITY, |c| c / rows));
        }
        let failed = mean_squares.iter().filter(|c| !c.is_finite()).count();
        let finite: Vec<f64> = mean_squares.iter().copied().filter(|c| c.is_finite()).collect();
        let score = if finite.is_empty() {
            f64::INFINITY
        } else if failed > 0 {
            // a configuration that fails a run ranks after every one that fails none
            f64::INFINITY
        } else {
            finite.iter().sum::<f64>() / finite.len() as f64
        };
        candidates.push(Configuration { label: label.clone(), folds, score, failed });
    }
    let best = (0..candidates.len())
        .min_by(|&a, &b| {
            let (x, y) = (&candidates[a], &candidates[b]);
            x.failed.cmp(&y.failed).then(x.score.total_cmp(&y.score))
        })
        .unwrap_or(0);
    progress(&format!("{} on all runs", candidates[best].label));
    let identified = identify_model(&configurations[best].1, frames, how, &mut |_| {})
        .map_err(|e| DiagnoseError::Setup(format!("the chosen `{}`: {e}", candidates[best].label)))?;
    Ok(Chosen { candidates, best, identified })
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
    let runs = Runs::new(model, std::slice::from_ref(run), prediction.dt, prediction.integrator)?
        .with_intercepts(intercepts)
        .comparing(&compared(model, prediction))?;
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
        out += &format!(
            "{:<28} {:>14} {:>14}  {}\n",
            "configuration", "mean error", "worst run", "(error: mean square of the compared states, each scaled by its spread; 1 = as large as the signal)"
        );
        for (i, c) in self.candidates.iter().enumerate() {
            let worst = c.folds.iter().max_by(|a, b| a.1.total_cmp(&b.1));
            let score =
                if c.failed > 0 { format!("{} failed", c.failed) } else { crate::identify::num(c.score) };
            out += &format!(
                "{:<28} {:>14} {:>14}{}\n",
                c.label,
                score,
                worst.map_or("--".to_string(), |w| w.0.clone()),
                if i == self.best { "  ← chosen" } else { "" }
            );
        }
        out + "\n"
    }
}
