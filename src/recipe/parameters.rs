//! The model file's free parameters (a rudder indicator's zero per run or per basin, a
//! grey-box model's derivatives) estimated by output error together with every coefficient
//! of a start: the start's refinement where the file declares any. A regression cannot
//! estimate them (they sit inside the terms); kept only where the checks the model passed
//! still pass.

use crate::data::Frame;
use crate::diagnose::{estimate, Estimate, EstimateSettings, InitialValues};
use crate::model::Model;
use crate::plugin::Check;

use super::Start;

/// How the parameter stage runs.
#[derive(Clone, Debug)]
pub struct ParameterOptions {
    /// The source (basin, campaign) of each training run, by index (empty: one source).
    pub sources: Vec<usize>,
    /// Free parameters estimated once per source (each basin's rudder zero), the others once
    /// for all.
    pub per_source: Vec<String>,
    /// Free parameters estimated once per run (a rudder zero that drifts from run to run).
    pub per_run: Vec<String>,
    /// Most Levenberg-Marquardt iterations in each of the estimate's two rounds.
    pub iterations: usize,
    /// A round ends at a step that lowers the cost by less than this fraction (as the
    /// refinement's: no prediction that matters moves by then).
    pub converged: f64,
    /// Run because the model file declares free parameters, not because the caller asked:
    /// where validation runs stop the refinement, they are not overruled by an estimate
    /// after it that they cannot stop.
    pub by_default: bool,
    /// How each run's initial values are estimated: by default held to the records' first
    /// samples by their noise, as the refinement before this stage started every run from its
    /// record. A library's structure is not the ship's, and free initial values then lean on
    /// what it does not explain (on HSVA's KVLCC2 they moved 515 times the records' noise):
    /// `Auto` would fit them free first only to fit again held, the same estimate at twice the
    /// time.
    pub initial_values: InitialValues,
}

impl Default for ParameterOptions {
    fn default() -> Self {
        ParameterOptions {
            sources: vec![],
            per_source: vec![],
            per_run: vec![],
            iterations: 50,
            converged: 1e-3,
            by_default: false,
            initial_values: InitialValues::Measured,
        }
    }
}

impl ParameterOptions {
    /// The stage as a caller asks for it: `Some(true)` or any parameter to be estimated per
    /// source or per run (which is asking for it) runs it, `Some(false)` does not, `None` runs
    /// it where the starts are `refined` and `model` declares a free parameter: a value the
    /// file leaves to the runs is refined with the coefficients, not held at its first value.
    pub fn asked(
        model: &Model,
        asked: Option<bool>,
        refined: bool,
        sources: Vec<usize>,
        per_source: Vec<String>,
        per_run: Vec<String>,
    ) -> Option<ParameterOptions> {
        let named = !per_source.is_empty() || !per_run.is_empty();
        let (run, by_default) = match asked {
            Some(asked) => (asked || named, false),
            None if named => (true, false),
            None => (refined && !model.free_parameters().is_empty(), true),
        };
        run.then(|| ParameterOptions { sources, per_source, per_run, by_default, ..Default::default() })
    }
}

/// What the parameter stage did to a start.
#[derive(Debug)]
pub enum ParameterStage {
    /// Kept: the start's model holds the estimates (the per-source ones are reported, the
    /// file's value stays).
    Kept(Estimate),
    /// Rejected: the estimate fails the named checks the model passed; the model is as before.
    Rejected(Estimate, Vec<String>),
    /// Failed, why; the model is as before.
    Failed(String),
}

impl ParameterStage {
    /// The stage as text.
    pub fn text(&self) -> String {
        match self {
            ParameterStage::Kept(e) => e.text(),
            ParameterStage::Rejected(e, _) => {
                format!("{}{}\n\n", e.text(), self.warning().unwrap_or_default())
            }
            ParameterStage::Failed(_) => format!(
                "== output-error estimate of the free parameters ==\n{}\n\n",
                self.warning().unwrap_or_default()
            ),
        }
    }

    /// The estimate, where the stage ran (kept or rejected).
    pub fn estimate(&self) -> Option<&Estimate> {
        match self {
            ParameterStage::Kept(e) | ParameterStage::Rejected(e, _) => Some(e),
            ParameterStage::Failed(_) => None,
        }
    }

    /// Where the estimate was not kept, why, in a sentence (a caller's warning).
    pub fn warning(&self) -> Option<String> {
        match self {
            ParameterStage::Kept(_) => None,
            ParameterStage::Rejected(_, lost) => Some(format!(
                "the parameter estimate is rejected: the model would fail checks it passes ({}); the model stays as it was",
                lost.join("; ")
            )),
            ParameterStage::Failed(why) => {
                Some(format!("the parameter estimate failed: {why}; the model stays as it was"))
            }
        }
    }
}

/// Runs the stage on `start` with the training runs `frames` (as read: each run's initial
/// state is estimated with the parameters), comparing `states` (`None`: all), re-simulated at
/// `step` samples (`None`: the coarsest that resolves the runs, as the refinement's).
pub(super) fn estimate_parameters(
    start: &mut Start,
    frames: &[Frame],
    states: Option<&[String]>,
    intercept: bool,
    step: Option<usize>,
    options: &ParameterOptions,
) -> ParameterStage {
    let settings = EstimateSettings {
        coefficients: true,
        iterations: options.iterations,
        converged: options.converged,
        initial_values: options.initial_values,
        sources: options.sources.clone(),
        per_source: options.per_source.clone(),
        per_run: options.per_run.clone(),
        // a step that is asked for holds whatever the runs' resolution (no tolerance fails it)
        coarsest: Some(step.map_or((super::RESOLVED, super::MOST_SAMPLES_PER_STEP), |f| (f64::INFINITY, f))),
        ..Default::default()
    };
    let fit = super::start::output_error_runs(&start.model, frames, states, intercept)
        .and_then(|runs| estimate(&start.model, &runs, &settings));
    let fit = match fit {
        Ok(fit) => fit,
        Err(e) => return ParameterStage::Failed(e.to_string()),
    };
    // as for the refinement: an estimate must not make the model fail what its field knows
    // it passed
    let checks = checks_with_own_values(&fit, &start.prepared);
    let lost = super::start::lost_checks(&start.checks, &checks);
    if !lost.is_empty() {
        return ParameterStage::Rejected(fit, lost);
    }
    start.model = fit.model.clone();
    start.checks = checks;
    ParameterStage::Kept(fit)
}

/// The plug-in's checks of the estimated model as written (with the file's values). Where
/// parameters were estimated per source or per run (a basin's rudder zero), a check that reads
/// the runs (steering them as recorded) holds only with their own values: those checks are
/// made again with each run steered by the model that holds its own values.
fn checks_with_own_values(fit: &Estimate, prepared: &[Frame]) -> Vec<Check> {
    let Some(plugin) = crate::plugins::of(&fit.model) else { return vec![] };
    let written = plugin.checks(&fit.model, prepared);
    if fit.per_source.is_empty() {
        return written;
    }
    let own: Vec<Model> = (0..prepared.len())
        .map(|r| {
            let mut model = fit.model.clone();
            for p in fit.per_source.iter().filter(|p| p.runs.contains(&r)) {
                model.set_parameter(&p.name, p.value);
            }
            model
        })
        .collect();
    let each: Vec<(&Model, &Frame)> = own.iter().zip(prepared).collect();
    let mut again = plugin.run_checks(&each);
    // the checks of the model alone (its turning circles) are the written model's
    written
        .into_iter()
        .map(|c| match again.iter().position(|o| o.name == c.name) {
            Some(k) => again.swap_remove(k),
            None => c,
        })
        .collect()
}
