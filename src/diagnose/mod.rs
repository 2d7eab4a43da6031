//! The discrepancy workflow (`termid diagnose`): re-simulate measured runs with their
//! recorded inputs, find where model and measurement part, test a library of candidate
//! effects against the gap by output error (each hypothesis's few new parameters fitted by
//! Levenberg-Marquardt with the rest of the model held), rank them by the error left and an
//! information criterion, add the winner to a new model, and show the gap shrink. Generic:
//! the library holds constants, missing candidate terms and input offsets and scales; a
//! plug-in (the ship's) adds named hypotheses.

mod choose;
mod estimate;
mod fit;
mod hypotheses;
mod medium;
mod refine;
mod sensitivity;

/// Models the tests of this module and of the recipe share.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::model::Model;

    /// ẋ = u + b·`term` (candidates u and `term`): a first-order lag where `term` is x.
    pub(crate) fn lag(term: &str, b: f64) -> Model {
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
candidates = ["u", "{term}"]
coefficients = {{ "u" = 1.0, "{term}" = {b} }}
"#
        );
        Model::parse(&text, "lag.toml").unwrap()
    }
}

use serde::Serialize;

pub use choose::{choose_by_prediction, Chosen, Configuration, Prediction};
pub use estimate::{
    estimate, Estimate, EstimateSettings, EstimatedParameter, FromRecords, HeldAgain, InitialValues, Move,
    RunSpread, Segmented, SourceParameter, FOLLOWS, LEANS, MOST_STEPS_PER_SAMPLE, RUNS_DIFFER, SEGMENTS,
    STEP_RESOLVES,
};
pub use fit::{
    in_segments, simulate_runs, EstimateError, PartlyRecorded, Runs, PARTED, PERTURBATION, SEGMENT_SAMPLES,
};
pub use medium::medium;
pub use refine::{refine, RefineSettings, Refined, RefinedCoefficient};

pub use hypotheses::{beyond_candidates, generic_hypotheses, Effect, Hypothesis};

use crate::data::{DataError, Frame};
use crate::model::Model;
use crate::sim::SimError;

/// Why a diagnosis failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// Data.
    #[error(transparent)]
    Data(#[from] DataError),
    /// Simulation of the unchanged model.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// Setup.
    #[error("{0}")]
    Setup(String),
    /// The output-error refinement's estimate failed (the reason is its only content, so it
    /// is printed here rather than kept as a source that would print it twice).
    #[error("output-error refinement: the re-simulation {0}")]
    Refinement(fit::EstimateError),
    /// A hypothesis's term that does not parse in the model's vocabulary.
    #[error(transparent)]
    Term(#[from] crate::term::TermError),
}

/// The gap between simulation and measurement, per state: RMS and max of (sim − meas).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Gap {
    /// (state, unit, RMS, max |·|) over all runs.
    pub states: Vec<(String, String, f64, f64)>,
    /// The same per run.
    pub runs: Vec<RunGap>,
    /// Scaled sum of squares (each state by its spread in the data) over all runs and samples.
    pub cost: f64,
}

/// One run's gap: (run, [(state, RMS, max |·|)]).
pub type RunGap = (String, Vec<(String, f64, f64)>);

/// Where the disagreement is.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Location {
    /// The state with the largest scaled gap.
    pub leading_state: String,
    /// First time its gap exceeds 10 % of its largest value, per run.
    pub onset: Vec<(String, f64)>,
    /// Ratio of the gap's RMS in the second half of the runs to the first half (> 1: it grows).
    pub growth: f64,
    /// The measured quantity whose magnitude goes with the gap's growth rate most, and the
    /// correlation (where the gap grows fastest).
    pub regime: (String, f64),
    /// The same in words.
    pub words: String,
}

/// The most of a gap taken for the records' noise ([`Diagnosis::noise`]).
pub const NOISE_AT_MOST: f64 = 0.5;

/// One tested hypothesis.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    /// Its name.
    pub name: String,
    /// What it adds.
    pub effect: Effect,
    /// Estimated parameters (coefficients; input offsets in the input's unit; scales as factors).
    pub estimate: Vec<f64>,
    /// Their standard errors (from the Gauss-Newton approximation at the optimum).
    pub std_error: Vec<f64>,
    /// Scaled cost left.
    pub cost: f64,
    /// Share of the gap's cost it removes.
    pub explained: f64,
    /// BIC change against the unchanged model (negative: better).
    pub delta_bic: f64,
    /// Made of declared candidate terms (see [`Hypothesis::declared`]).
    pub declared: bool,
    /// A term beyond the candidates: the share of the gap beyond the records' noise it
    /// removes beyond its equation's coefficients refitted alone. Below `min_explained` it may not win: the refit does the
    /// work, and the term only fits what is left (on a model whose structure is right, the
    /// re-simulation's round-off: 3 % of a gap of 0.03 % of the signal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beyond_refit: Option<f64>,
}

/// Settings.
#[derive(Clone, Debug, Serialize)]
pub struct Settings {
    /// Integration step.
    pub dt: f64,
    /// Integrator of the re-simulations (use the one the model is meant for).
    pub integrator: crate::sim::Integrator,
    /// Hypotheses refined by Levenberg-Marquardt after screening (the rest keep one step).
    pub refine: usize,
    /// An effect is significant if it removes at least this share of the gap …
    pub min_explained: f64,
    /// … and lowers BIC by at least this much.
    pub min_bic_drop: f64,
    /// Hypotheses within this share of the best one's explained gap count as tied; among them
    /// those made of the model's declared candidate terms come first.
    pub tie: f64,
    /// Simulate with the equations' stored intercepts b0.
    pub with_intercepts: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            dt: 0.04,
            integrator: crate::sim::Integrator::ModifiedEuler,
            refine: 8,
            min_explained: 0.3,
            min_bic_drop: 10.0,
            tie: 0.01,
            with_intercepts: false,
        }
    }
}

/// What `diagnose` found.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    /// Where.
    pub location: Location,
    /// The share of the gap that is the records' white noise (at most half), which no effect
    /// closes: a term beyond the candidates is measured against the rest.
    pub noise: f64,
    /// The gap with the model as it is.
    pub gap_before: Gap,
    /// With the winner added (equal to before when nothing is significant).
    pub gap_after: Gap,
    /// Every hypothesis, best first.
    pub candidates: Vec<Candidate>,
    /// Index of the significant winner in `candidates`, if any.
    pub winner: Option<usize>,
    /// The model with the winner added: only where it shrinks the gap it was meant to close
    /// (the leading state's error) on every run; else None and `rejected` says why.
    #[serde(skip)]
    pub model: Option<Model>,
    /// Why the winner's model was not kept: the runs on which it made the leading state's
    /// error grow (run, before, after).
    pub rejected: Option<Vec<(String, f64, f64)>>,
    /// The nuisances the model file declares of each run or source (a rudder indicator's
    /// zero, `nuisance = "run"`), estimated first with the rest of the model held: the runs
    /// are diagnosed each with its own values (empty where the file declares none).
    pub own_values: Vec<SourceParameter>,
    /// Those nuisances whose runs agreed, estimated once for all runs instead (the model's
    /// value, the runs' spread and the test).
    pub one_value: Vec<RunSpread>,
    /// The re-simulations before (and after) the winner, for figures.
    #[serde(skip)]
    pub before: Vec<crate::sim::Trajectory>,
    /// After.
    #[serde(skip)]
    pub after: Vec<crate::sim::Trajectory>,
}

/// The nuisances `model`'s file declares of each run or source, estimated from the `frames`
/// with every other parameter held and each run started from its record (as the diagnosis
/// re-simulates it; one RK4 step a sample, as `termid estimate` fits): the estimate, `model`
/// holding the nuisances' new values (their runs' mean, or the one value where the runs
/// agreed; its other parameters as they were, free where they were), and `data`, the runs
/// as diagnosed, each with its own values. `None` where it declares none.
#[allow(clippy::type_complexity)]
fn own_nuisances(
    model: &Model,
    frames: &[Frame],
    data: Runs,
) -> Result<(Option<(Estimate, Model)>, Runs), DiagnoseError> {
    let free = model.free_parameters();
    if !free.iter().any(|p| p.nuisance.is_some()) {
        return Ok((None, data));
    }
    let mut held = model.clone();
    for p in free.iter().filter(|p| p.nuisance.is_none()) {
        held.hold(&p.name);
    }
    let settings = EstimateSettings { initial_values: InitialValues::Recorded, ..Default::default() };
    let sampled = Runs::new(&held, frames, crate::data::sample_step(frames), crate::sim::Integrator::Rk4)?;
    let fit = estimate::estimate(&held, &sampled, &settings).map_err(|e| {
        let names: Vec<&str> = free.iter().filter(|p| p.nuisance.is_some()).map(|p| p.name.as_str()).collect();
        DiagnoseError::Setup(format!(
            "estimating each run's own {} first (the model file declares them of each run or source), the rest of the model held: {e}",
            names.join(", ")
        ))
    })?;
    let mut with_values = model.clone();
    let values = fit.model.parameter_values();
    for p in free.iter().filter(|p| p.nuisance.is_some()) {
        if let Some(v) = values.get(&p.name) {
            with_values.set_parameter(&p.name, *v);
        }
    }
    let data = data.with_initial(&[], &fit.own_values());
    Ok((Some((fit, with_values)), data))
}

/// Whether a term beyond the candidates is, along the runs, a combination of the coefficients
/// refitted with it but for rounding (within 10⁻²⁴ of its sum of squares): `sign(X)` of a
/// population that never reaches 0 is the constant. Tested, its coefficient and theirs trade
/// without bound, and the Gauss-Newton step lands on a model whose re-simulation takes
/// minutes. A law a cubic follows to 10⁻⁵ over the runs (√h for h from 2 to 4) is tested: its
/// re-simulation tells them apart.
fn refitted_already(h: &Hypothesis, model: &Model, runs: &[Frame]) -> bool {
    let Effect::Beyond { term, refitted, .. } = &h.effect else { return false };
    let parse = |text: &str| model.vocabulary.parse(text).ok();
    let (Some(term), Some(refitted)) =
        (parse(term), refitted.iter().map(|t| parse(t)).collect::<Option<Vec<_>>>())
    else {
        return false;
    };
    if refitted.is_empty() {
        return false;
    }
    let parameters = model.parameter_values();
    let (mut rows, mut y) = (Vec::new(), Vec::new());
    for f in runs {
        for k in 0..f.len() {
            let value = |name: &str| match f.column(name) {
                Some(c) => c[k],
                None if name == f.time_name() => f.time()[k],
                None => parameters.get(name).copied().unwrap_or(f64::NAN),
            };
            y.push(term.eval(&value));
            rows.extend(refitted.iter().map(|t| t.eval(&value)));
        }
    }
    if y.is_empty() || !y.iter().chain(&rows).all(|v| v.is_finite()) {
        return false;
    }
    let a = nalgebra::DMatrix::from_row_slice(y.len(), refitted.len(), &rows);
    let b = nalgebra::DVector::from_vec(y);
    let Some(Ok(x)) = crate::linalg::svd(a.clone()).map(|svd| svd.solve(&b, 1e-12)) else { return false };
    (&a * x - &b).norm_squared() <= 1e-24 * b.norm_squared()
}

/// Runs the workflow on measured runs (time column = the model's; states and inputs by name).
pub fn diagnose(
    model: &Model,
    runs: &[Frame],
    hypotheses: &[Hypothesis],
    settings: &Settings,
) -> Result<Diagnosis, DiagnoseError> {
    let data =
        Runs::new(model, runs, settings.dt, settings.integrator)?.with_intercepts(settings.with_intercepts);
    // Each run with its own nuisances: re-simulated with their mean instead, the runs' own
    // offsets are the gap, and an effect that mimics them "explains" it (on SIMMAN's HSVA runs
    // a propeller asymmetry, 80 % of a gap the runs' own rudder zeros close).
    let (nuisances, data) = own_nuisances(model, runs, data)?;
    let with_values = nuisances.as_ref().map(|(_, m)| m);
    let model = with_values.unwrap_or(model);
    let base = data.simulate(model, &[], &[])?;
    let gap_before = data.gap(&base);
    let location = data.locate(&base);
    let n = data.residual_count() as f64;
    // the records' own noise, which no effect closes (at most half the gap, lest a misread
    // make much of little)
    let noise = data.white_noise_cost().min(NOISE_AT_MOST * gap_before.cost);
    let mut candidates: Vec<Candidate> = Vec::new();
    // screening: one Gauss-Newton step from zero for every hypothesis
    let mut screened: Vec<(usize, Vec<f64>, f64)> = Vec::new();
    for (i, h) in hypotheses.iter().enumerate().filter(|(_, h)| !refitted_already(h, model, runs)) {
        if let Ok((theta, cost)) = fit::gauss_newton(&data, model, h, 1) {
            screened.push((i, theta, cost));
        }
    }
    screened.sort_by(|a, b| a.2.total_cmp(&b.2));
    for (rank, (i, theta, cost)) in screened.into_iter().enumerate() {
        let h = &hypotheses[i];
        let (theta, cost, se) = if rank < settings.refine || h.needs_refining() {
            match fit::levenberg_marquardt(&data, model, h, theta.clone()) {
                Ok(e) => {
                    let se = e.std_errors();
                    (e.theta, e.cost, se)
                }
                Err(_) => (theta, cost, vec![f64::NAN; h.parameters()]),
            }
        } else {
            (theta, cost, vec![f64::NAN; h.parameters()])
        };
        let k = h.parameters() as f64;
        let delta_bic = n * (cost.max(1e-300) / gap_before.cost.max(1e-300)).ln() + k * n.ln();
        candidates.push(Candidate {
            name: h.name.clone(),
            effect: h.effect.clone(),
            estimate: h.natural(&theta),
            std_error: se,
            cost,
            explained: 1.0 - cost / gap_before.cost.max(1e-300),
            delta_bic,
            declared: h.declared(model),
            beyond_refit: None,
        });
    }
    // a term beyond the candidates is measured against its equation's refit alone, in the
    // share of the gap beyond the records' noise (1 % noise was half a Coulomb oscillator's
    // gap: the dry friction that closed the rest, 19 % of the whole beyond the refit's 32 %,
    // was passed over)
    let explainable = (1.0 - noise / gap_before.cost.max(1e-300)).max(1e-300);
    for i in 0..candidates.len() {
        if let Effect::Beyond { equation, .. } = &candidates[i].effect {
            let refit = candidates
                .iter()
                .find(|c| matches!(&c.effect, Effect::Refit { equation: e, .. } if e == equation));
            let excess = (candidates[i].explained - refit.map_or(0.0, |r| r.explained)) / explainable;
            candidates[i].beyond_refit = Some(excess);
        }
    }
    candidates.sort_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic).then(a.cost.total_cmp(&b.cost)));
    // a catch-all (a constant, an input error) that only ties with the model's own physics
    // does not win: among near-ties, declared candidate terms come first
    if let Some(best) = candidates.first().map(|c| c.explained) {
        let tied = candidates.iter().take_while(|c| best - c.explained <= settings.tie).count();
        candidates[..tied]
            .sort_by(|a, b| b.declared.cmp(&a.declared).then(a.delta_bic.total_cmp(&b.delta_bic)));
    }
    // a term beyond the candidates that only adds to its equation's refit is passed over
    let winner = candidates
        .iter()
        .position(|c| c.beyond_refit.is_none_or(|b| b >= settings.min_explained))
        .filter(|&w| {
            let c = &candidates[w];
            c.explained >= settings.min_explained && c.delta_bic <= -settings.min_bic_drop
        });
    let mut after_sims = Vec::new();
    let (gap_after, new_model) = match winner {
        Some(w) => {
            let h = hypotheses
                .iter()
                .find(|h| h.name == candidates[w].name)
                .ok_or_else(|| DiagnoseError::Setup("lost hypothesis".into()))?;
            let theta = h.internal(&candidates[w].estimate);
            let m = fit::apply(model, h, &theta)?;
            let after = data.simulate(&m, &h.input_offsets(&theta, model), &h.input_scales(&theta, model))?;
            let mut m = m;
            m.add_note(format!(
                "termid diagnose added {} ({}), explaining {:.0} % of the gap (ΔBIC {:.1})",
                candidates[w].name,
                candidates[w].estimate.iter().map(|v| format!("{v:.6}")).collect::<Vec<_>>().join(", "),
                100.0 * candidates[w].explained,
                candidates[w].delta_bic
            ));
            let gap = data.gap(&after);
            after_sims = after;
            (gap, Some(m))
        }
        None => (gap_before.clone(), None),
    };
    // a repair is kept only where it closes the gap it was found for: the leading state's
    // error may not grow on any run (by more than round-off)
    let rms = |g: &Gap, run: usize| {
        g.runs
            .get(run)
            .and_then(|(_, states)| states.iter().find(|(s, _, _)| *s == location.leading_state))
            .map(|x| x.1)
    };
    let worse: Vec<(String, f64, f64)> = (0..gap_before.runs.len())
        .filter_map(|k| match (rms(&gap_before, k), rms(&gap_after, k)) {
            (Some(b), Some(a)) if a > b * (1.0 + 1e-6) + 1e-12 => Some((gap_before.runs[k].0.clone(), b, a)),
            _ => None,
        })
        .collect();
    let (new_model, rejected) =
        if new_model.is_some() && !worse.is_empty() { (None, Some(worse)) } else { (new_model, None) };
    Ok(Diagnosis {
        location,
        noise: noise / gap_before.cost.max(1e-300),
        gap_before,
        gap_after,
        candidates,
        winner,
        model: new_model,
        rejected,
        own_values: nuisances.as_ref().map_or_else(Vec::new, |(fit, _)| fit.per_source.clone()),
        one_value: nuisances.map_or_else(Vec::new, |(fit, _)| fit.one_value),
        before: base,
        after: after_sims,
    })
}

/// A run's file name without its folder, as a report names it (a table's column stays
/// narrow).
pub fn file_name(origin: &str) -> String {
    std::path::Path::new(origin).file_name().map_or(origin.to_string(), |n| n.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sign(X)` of a population that never reaches 0 is the constant its equation refits: not
    /// tested (its Gauss-Newton step from the two together took 84 s to re-simulate); of a
    /// velocity that swings through 0 it is a law of its own.
    #[test]
    fn a_law_that_is_a_refitted_term_along_the_runs_is_not_tested() {
        let model = Model::parse(
            "[model]\nname = \"growth\"\n[[states]]\nname = \"X\"\n[equations.X_dot]\nstate = \"X\"\ncandidates = [\"1\", \"X\"]\ncoefficients = { \"1\" = 0.1, \"X\" = 0.2 }\n",
            "growth.toml",
        )
        .unwrap();
        let run = |f: fn(f64) -> f64| {
            let t: Vec<f64> = (0..200).map(|k| 0.05 * k as f64).collect();
            let mut frame = Frame::new("run.csv", "t", t.clone()).unwrap();
            frame.push("X", t.iter().map(|t| f(*t)).collect()).unwrap();
            frame
        };
        let law = |term: &str| Hypothesis {
            name: term.into(),
            effect: Effect::Beyond {
                equation: "X_dot".into(),
                term: term.into(),
                refitted: vec!["1".into(), "X".into()],
            },
        };
        let growing = [run(|t| 0.1 * (0.3 * t).exp())];
        assert!(refitted_already(&law("sign(X)"), &model, &growing));
        assert!(!refitted_already(&law("X*abs(X)"), &model, &growing));
        let swinging = [run(|t| t.sin())];
        assert!(!refitted_already(&law("sign(X)"), &model, &swinging));
    }
}
