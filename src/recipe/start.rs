//! One start of the recipe: the runs prepared by one derivative method, identified (or
//! chosen among configurations by prediction), refined by output error (with the model file's
//! free parameters where it declares any) and checked.

use crate::data::{differentiator, prepare, resample, CentralDifference, Differentiator, Frame, Preparation};
use crate::diagnose::{Prediction, RefineSettings, Refined, Runs, MOST_STEPS_PER_SAMPLE, STEP_RESOLVES};
use crate::identify::{Fit, ModelIdentification};
use crate::model::Model;
use crate::plugin::Check;

use super::parameters::{estimate_parameters, ParameterOptions, ParameterStage};
use super::{RecipeError, RecipeSettings, RefineOptions};

/// One start: what one derivative method's preparation identified.
#[derive(Debug)]
pub struct Start {
    /// The derivative method.
    pub derivative: String,
    /// The model as it will be written.
    pub model: Model,
    /// The regression's fits, per equation.
    pub fits: Vec<(String, Fit)>,
    /// The table the choice among configurations chose from.
    pub chosen_text: Option<String>,
    /// The refinement kept.
    pub refined: Option<Refined>,
    /// A refinement rejected by the checks, with the checks it lost.
    pub rejected: Option<(Refined, Vec<String>)>,
    /// A refinement that failed, why (the regression's model is kept).
    pub refine_error: Option<String>,
    /// The model file's free parameters estimated with the coefficients, where asked: in place
    /// of the refinement (which runs only where validation runs stop it, the estimate then
    /// after it where asked for explicitly, or where no start's stage is kept).
    pub parameters: Option<ParameterStage>,
    /// The inputs the regression found to act later than the model declares (said in the
    /// fits' notes; [`crate::identify::say_late_inputs`]).
    pub late: Vec<crate::identify::Lag>,
    /// The physical checks of `model`.
    pub checks: Vec<Check>,
    /// The runs as this start prepared them (for figures).
    pub prepared: Vec<Frame>,
}

impl Start {
    /// What the start is judged by: the re-simulation cost of the model it keeps, on the
    /// validation runs where there are any, else on the training runs.
    pub fn cost(&self) -> f64 {
        let (before, after) = self.costs();
        after.unwrap_or(before)
    }

    /// The regression's re-simulation cost and the refined one (`None`: no refinement kept),
    /// the validation runs' where there are any.
    pub fn costs(&self) -> (f64, Option<f64>) {
        let refined = |r: &Refined| r.validation.unwrap_or((r.cost_before, r.cost_after));
        // validation runs judge the refinement they stopped, which a stage after it cannot see
        let validated = self.refined.as_ref().is_some_and(|r| r.validation.is_some());
        match (&self.parameters, &self.refined, &self.rejected) {
            (Some(ParameterStage::Kept(e)), ..) if !validated => (e.cost_before, Some(e.cost_after)),
            (_, Some(r), _) => {
                let (before, after) = refined(r);
                (before, Some(after))
            }
            (_, None, Some((r, _))) => (refined(r).0, None),
            (Some(ParameterStage::Rejected(e, _)), None, None) => (e.cost_before, None),
            _ => (f64::INFINITY, None),
        }
    }

    /// How many of its checks refuse the model.
    pub fn refused(&self) -> usize {
        self.checks.iter().filter(|c| !c.passed && c.refuses).count()
    }
}

fn setup(e: impl std::fmt::Display) -> RecipeError {
    RecipeError::Setup(e.to_string())
}

/// The rate method of a system where none is named: the weak form, which recovers
/// polynomial systems from noise-free and noisy samples alike (benches/odes: 37, 37 and 34 of
/// 37 exact, coarse and noisy where the integral form recovers 37, 36 and 33).
pub const ANY_SYSTEM_DERIVATIVE: &str = "weak";

/// The rate method `termid identify` takes where none is named: a plug-in's model differences
/// centrally (a ship, as the paper: Oltmann 1973, §8 alternative 4), any other system takes
/// [`ANY_SYSTEM_DERIVATIVE`] (and so does a fit without a model).
pub fn default_derivative(model: Option<&Model>) -> &'static str {
    match model.and_then(crate::plugins::of) {
        Some(_) => "central",
        None => ANY_SYSTEM_DERIVATIVE,
    }
}

/// The derivative method by name. A plug-in's method (the ship's `kinematic` tracking filter)
/// writes every rate as a column in [`prepare_runs`], so central differences stand in for it:
/// nothing is left to differentiate then.
pub fn derivative_method(name: &str) -> Result<Box<dyn Differentiator>, RecipeError> {
    Ok(if crate::plugins::with_derivative(name).is_some() {
        Box::new(CentralDifference)
    } else {
        differentiator(name).map_err(setup)?
    })
}

/// The runs resampled and smoothed where asked for (or `always`, for figures of them): each
/// differentiated signal gets its rate as `<signal>_dot` (which identification then takes as
/// the target); a plug-in's method prepares all states of a run at once.
pub fn prepare_runs(
    frames: &[Frame],
    signals: &[String],
    model: Option<&Model>,
    derivative: &str,
    resample_to: Option<f64>,
    smooth: bool,
    always: bool,
) -> Result<Vec<Frame>, RecipeError> {
    let plugin = crate::plugins::with_derivative(derivative);
    if resample_to.is_none() && !smooth && plugin.is_none() && !always {
        return Ok(frames.to_vec());
    }
    if let Some(plugin) = plugin {
        let model = model.ok_or_else(|| setup(format!("--derivative {derivative} needs a --model")))?;
        return frames
            .iter()
            .map(|f| {
                let f = match resample_to {
                    Some(dt) => resample(f, dt).map_err(setup)?,
                    None => f.clone(),
                };
                plugin.prepare(derivative, model, &f, smooth).map_err(setup)
            })
            .collect();
    }
    let method = derivative_method(derivative)?;
    // an integral form (the default weak form) estimates no rate: its rows are the run's own,
    // resampled where asked (`--resample` was refused as if --smooth were given)
    let signals = match method.window().is_some() && !smooth && !always {
        true => &[][..],
        false => signals,
    };
    let how =
        Preparation { resample: resample_to, method: method.as_ref(), signals: signals.to_vec(), smooth };
    frames.iter().map(|f| prepare(f, &how).map_err(setup)).collect()
}

/// Said in each equation's notes where terms chosen by re-simulation were refined unasked.
const COARSE_REFINED: &str = "refined by output error over the runs (below), unasked: the rates of rows this coarse bias the regression's coefficients, a re-simulation at steps fine enough for the motion does not";

/// One start with `derivative`.
pub(super) fn identify_start(
    model: &Model,
    frames: &[Frame],
    held: Option<&[Frame]>,
    settings: &RecipeSettings,
    derivative: &str,
) -> Result<Start, RecipeError> {
    let names: Vec<String> =
        if settings.equations.is_empty() { model.identifiable() } else { settings.equations.clone() };
    if names.is_empty() {
        return Err(setup(format!("{}: no equation has candidate terms, so there is nothing to identify (an equation's `candidates` list them)", model.path)));
    }
    if settings.target.is_some() && names.len() != 1 {
        return Err(setup("a target applies to one equation: name it"));
    }
    let states: Vec<String> =
        names.iter().filter_map(|n| model.equation(n).map(|e| e.state.clone())).collect();
    let diff = derivative_method(derivative)?;
    let prep = |f: &[Frame]| {
        prepare_runs(
            f,
            &states,
            Some(model),
            derivative,
            settings.resample,
            settings.smooth,
            settings.figures,
        )
    };
    let prepared = prep(frames)?;
    // runs that stop the refinement, prepared as the training runs are
    let validation = held.map(prep).transpose()?;
    let how = ModelIdentification {
        equations: names,
        differentiator: diff.as_ref(),
        intercept: settings.intercept,
        target: settings.target.clone(),
    };
    let (mut identified, chosen_text) = if settings.choose.is_empty() {
        (crate::identify::identify_model(model, &prepared, &how, &mut |_| {}).map_err(setup)?, None)
    } else {
        let prediction = Prediction { states: settings.compare.clone(), ..Default::default() };
        let chosen = crate::diagnose::choose_by_prediction(
            &settings.choose,
            &prepared,
            &how,
            &prediction,
            &mut |_| {},
        )
        .map_err(setup)?;
        let text = chosen.text();
        (chosen.identified, Some(text))
    };
    // said once for the start (not in each fold the choice by prediction fitted)
    let late = crate::identify::say_late_inputs(&mut identified, &prepared, diff.as_ref()).map_err(setup)?;
    let (identified, checks, searched) = match crate::plugins::of(model) {
        Some(_) => {
            let checks = checks_of(&identified.model, &prepared);
            (identified, checks, false)
        }
        None => super::checked_system(model, identified, &prepared, &how),
    };
    // equations that lost their runs, from rows too coarse for their rates: the regression's
    // coefficients carry the quadrature's bias, which an output error over the runs does not
    let coarse = searched && !crate::identify::coarsely_sampled(&prepared, &states).is_empty();
    let of_coarse_rows = RefineOptions::of_coarse_rows();
    let refinement = match &settings.refine {
        None if coarse => Some(&of_coarse_rows),
        asked => asked.as_ref(),
    };
    let mut model = identified.model;
    let mut start = Start {
        derivative: derivative.to_string(),
        model: model.clone(),
        fits: identified.fits,
        chosen_text,
        refined: None,
        rejected: None,
        refine_error: None,
        parameters: None,
        late,
        checks: vec![],
        prepared: vec![],
    };
    let in_place = settings.parameters_in_place(validation.is_some());
    start.checks = checks;
    if !in_place {
        refine_start(
            &mut start,
            &mut model,
            &prepared,
            validation.as_deref(),
            refinement,
            settings.intercept,
        );
        if start.refined.is_some() && settings.refine.is_none() {
            for (_, fit) in &mut start.fits {
                fit.selection.notes.push(COARSE_REFINED.into());
            }
        }
    }
    start.model = model;
    start.prepared = prepared;
    // validation runs that stop the refinement are not overruled unasked
    let stage = settings.parameters.as_ref().filter(|o| in_place || !o.by_default);
    if let Some(options) = stage {
        let refine = settings.refine.as_ref();
        let states = refine.and_then(|r| r.states.as_deref());
        // at the refinement's step where it is given
        let step = refine.and_then(|r| r.samples_per_step(frames));
        // in place of the refinement, as many iterations a round as the refinement was given
        let iterations = match refine {
            Some(r) if in_place => r.iterations,
            _ => options.iterations,
        };
        let options = ParameterOptions { iterations, ..options.clone() };
        let stage = estimate_parameters(&mut start, frames, states, settings.intercept, step, &options);
        start.parameters = Some(stage);
    }
    Ok(start)
}

/// A start whose parameter stage, run in place of its refinement, was not kept, refined
/// without the free parameters (the recipe does so where no start's stage is kept: a start
/// refined with more free values re-simulates the runs better than one refined without).
pub(super) fn refine_instead(start: &mut Start, settings: &RecipeSettings) {
    let kept = matches!(start.parameters, Some(ParameterStage::Kept(_)));
    if kept || start.refined.is_some() || start.rejected.is_some() || start.refine_error.is_some() {
        return;
    }
    let (mut model, prepared) = (start.model.clone(), std::mem::take(&mut start.prepared));
    refine_start(start, &mut model, &prepared, None, settings.refine.as_ref(), settings.intercept);
    (start.model, start.prepared) = (model, prepared);
}

/// The output-error refinement of `start`'s `model` where asked: kept where it loses none of
/// the checks the model passed.
fn refine_start(
    start: &mut Start,
    model: &mut Model,
    prepared: &[Frame],
    validation: Option<&[Frame]>,
    options: Option<&RefineOptions>,
    intercept: bool,
) {
    let Some(options) = options else { return };
    // a refinement that fails loses nothing: the regression's model is kept
    match refine(model, prepared, validation, options, intercept) {
        Ok(r) => {
            // a refinement must not make a model fail what its field knows it passed
            let after = checks_of(&r.model, prepared);
            let lost = lost_checks(&start.checks, &after);
            if lost.is_empty() {
                *model = r.model.clone();
                // which terms the rows chose, checked before, a refinement leaves as it was
                let kept = start.checks.iter().filter(|c| c.name == super::halves::NAME).cloned();
                start.checks = after.into_iter().chain(kept).collect::<Vec<_>>();
                start.refined = Some(r);
            } else {
                start.rejected = Some((r, lost));
            }
        }
        Err(e) => start.refine_error = Some(e),
    }
}

/// What the field knows must hold: the plug-in's physical checks of a model on the runs as
/// prepared; for a system of no field's, that its equations retrace the runs and that the
/// runs' noise leaves its terms unbiased.
pub fn checks_of(model: &Model, prepared: &[Frame]) -> Vec<Check> {
    // a file's equation without coefficients is taken as one not identified yet, not re-simulated
    let identified = || model.equations().iter().all(|e| !e.coefficients.is_empty() || e.intercept.is_some());
    match crate::plugins::of(model) {
        Some(plugin) => plugin.checks(model, prepared),
        None => identified()
            .then(|| super::retrace::retrace_checks(model, prepared))
            .into_iter()
            .flatten()
            .chain(super::noise::noise_check(model, prepared))
            .collect(),
    }
}

/// The refusing checks that `after` fails and `before` passed: what a later stage (a
/// refinement, a parameter estimate) must not lose.
pub(super) fn lost_checks(before: &[Check], after: &[Check]) -> Vec<String> {
    let failing = |checks: &[Check]| -> Vec<String> {
        checks.iter().filter(|c| !c.passed && c.refuses).map(|c| c.name.clone()).collect()
    };
    let was = failing(before);
    failing(after).into_iter().filter(|c| !was.contains(c)).collect()
}

/// `frames` made ready for an output-error fit of `model`: one RK4 step per sample (the
/// recorded inputs are known only at the samples; a whole fraction of it where the model is
/// stiff there, [`Runs::stable`]), comparing `states` (`None`: all).
pub(super) fn output_error_runs(
    model: &Model,
    frames: &[Frame],
    states: Option<&[String]>,
    intercept: bool,
) -> Result<Runs, crate::diagnose::DiagnoseError> {
    let (runs, _) = Runs::for_output_error(model, frames, None)?;
    let runs = runs.with_intercepts(intercept);
    match states {
        Some(names) => runs.comparing(model, names),
        None => Ok(runs),
    }
}

/// Every identified coefficient refined by output error on the runs as they were prepared
/// for the regression (smoothed initial states: a noisy first sample of a rate would
/// otherwise drift through its integral), re-simulated at the refinement's step; the costs
/// reported are the runs' at every sample.
pub(super) fn refine(
    model: &Model,
    frames: &[Frame],
    held: Option<&[Frame]>,
    options: &RefineOptions,
    intercept: bool,
) -> Result<Refined, String> {
    let runs_of = |frames: &[Frame]| {
        output_error_runs(model, frames, options.states.as_deref(), intercept).map_err(|e| e.to_string())
    };
    let runs = runs_of(frames)?;
    let validation = held.map(runs_of).transpose()?;
    let sample = crate::data::sample_step(frames);
    let asked = options.samples_per_step(frames);
    // where no step is asked, one that resolves the motion of the regression's model and of
    // the refined one: a census read yearly, ten samples a cycle, drifts in phase at one RK4
    // step a sample, which the refinement makes up for with coefficients 2 % off
    let mut finer = 1;
    let mut coarsen = true;
    let (runs, validation, mut refined, factor) = loop {
        let runs = match asked {
            Some(_) => runs.clone(),
            None => {
                let at;
                (finer, at) = runs.resolving(model, finer, STEP_RESOLVES, MOST_STEPS_PER_SAMPLE);
                at
            }
        };
        let validation = validation.as_ref().map(|v| v.finer(finer));
        let refined =
            refine_at(model, (&runs, validation.as_ref()), options, (asked, finer, sample), coarsen)?;
        // a step coarser than the samples, chosen for the regression's model, must hold the
        // refined one too: runs coarsened average away a motion faster than the regression's
        // (a fast state's first samples, off the slow motion it then follows), which the
        // refinement then cannot fit
        let factor = refined.step.map_or(1, |step| (step / sample).round() as usize);
        if asked.is_none() && factor > 1 && !coarse_holds(&runs, &refined.model, factor) {
            coarsen = false;
            continue;
        }
        let finest = finer >= MOST_STEPS_PER_SAMPLE;
        if asked.is_none() && !finest && runs.step_error(&refined.model).is_some_and(|e| e > STEP_RESOLVES) {
            finer *= 2;
            continue;
        }
        break (runs, validation, refined, factor);
    };
    if factor > 1 || finer > 1 {
        // the costs the starts are judged by are the runs' own, at every sample
        let cost = |runs: &Runs, m: &Model| -> Result<f64, String> {
            let sims = runs.simulate(m, &[], &[]).map_err(|e| e.to_string())?;
            Ok(runs.gap(&sims).cost)
        };
        refined.cost_before = cost(&runs, model)?;
        refined.cost_after = cost(&runs, &refined.model)?;
        if let Some(v) = &validation {
            refined.validation = Some((cost(v, model)?, cost(v, &refined.model)?));
        }
    }
    if finer > 1 {
        refined.step = Some(sample / finer as f64);
    }
    Ok(refined)
}

/// Whether `model` re-simulates `runs` coarsened `factor` times as at their samples.
fn coarse_holds(runs: &Runs, model: &Model, factor: usize) -> bool {
    runs.simulate(model, &[], &[])
        .is_ok_and(|fine| runs.holding(model, &fine, factor, super::RESOLVED).is_some())
}

/// [`refine`] at the runs' step (`runs`, `validation`) where it is `finer` than a sample
/// (no coarser one resolves the motion) or where not to `coarsen`, else at the coarsest whole
/// number of samples at which the regression's model re-simulates them as at their samples,
/// or at the step `asked` (in samples of `sample`); its step set where that is coarser than a
/// sample.
fn refine_at(
    model: &Model,
    (runs, validation): (&Runs, Option<&Runs>),
    options: &RefineOptions,
    (asked, finer, sample): (Option<usize>, usize, f64),
    coarsen: bool,
) -> Result<Refined, String> {
    let (factor, coarse) = match asked {
        Some(factor) => (factor, runs.coarser(factor).map_err(|e| e.to_string())?),
        None if finer > 1 || !coarsen => (1, runs.clone()),
        None => {
            // the regression's model at every sample: what a coarser step is checked against
            let fine = runs.simulate(model, &[], &[]).map_err(|e| e.to_string())?;
            runs.coarsest(model, &fine, super::RESOLVED, super::MOST_SAMPLES_PER_STEP)
        }
    };
    let coarse_validation = validation.map(|v| v.coarser(factor).map_err(|e| e.to_string())).transpose()?;
    let settings = RefineSettings {
        prior_weight: options.prior,
        validation: coarse_validation.as_ref(),
        iterations: options.iterations,
    };
    let mut refined = crate::diagnose::refine(model, &coarse, &settings).map_err(|e| format!("{e:#}"))?;
    if factor > 1 {
        refined.step = Some(sample * factor as f64);
        refined.resampled = true;
    }
    Ok(refined)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The step response of ẋ = u + b·x (u = 1, from 0) sampled every `step` s for `samples`:
    /// x = (1 − e^(bt))/−b.
    fn step_response(b: f64, step: f64, samples: usize) -> Frame {
        let t: Vec<f64> = (0..=samples).map(|i| step * i as f64).collect();
        let mut f = Frame::new("step", "t", t.clone()).unwrap();
        f.push("x", t.iter().map(|t| (1.0 - (b * t).exp()) / -b).collect()).unwrap();
        f.push("u", vec![1.0; t.len()]).unwrap();
        f
    }

    /// Every coefficient refined freely, every state compared, at the step the refinement chooses.
    const FREE: RefineOptions = RefineOptions { states: None, prior: 0.0, iterations: 30, step: None };

    /// The refinement goes at the coarsest step the model allows, and its costs are the runs'
    /// at every sample: ẋ = u + b·x from b = −0.3 to the runs' −0.5.
    #[test]
    fn a_coarse_refinement_reports_the_costs_at_every_sample() {
        let model = crate::diagnose::fixtures::lag("x", -0.3);
        let f = step_response(-0.5, 0.01, 1000);
        let r = refine(&model, std::slice::from_ref(&f), None, &FREE, false).unwrap();
        assert!(r.step.is_some_and(|s| (s - 0.08).abs() < 1e-9), "{:?}", r.step);
        let b = r.coefficients.iter().find(|c| c.term == "x").unwrap().refined;
        assert!((b + 0.5).abs() < 1e-3, "b = {b}");
        let runs = Runs::new(&model, std::slice::from_ref(&f), 0.01, crate::sim::Integrator::Rk4).unwrap();
        let at_samples = |m: &Model| runs.gap(&runs.simulate(m, &[], &[]).unwrap()).cost;
        assert_eq!(r.cost_before, at_samples(&model));
        assert_eq!(r.cost_after, at_samples(&r.model));
        assert!(r.text().contains("re-simulated at a step of 0.08"), "{}", r.text());
        // a step given is taken, to the nearest whole number of samples
        let given = RefineOptions { step: Some(0.031), ..FREE };
        let r = refine(&model, &[f], None, &given, false).unwrap();
        assert!(r.step.is_some_and(|s| (s - 0.03).abs() < 1e-9), "{:?}", r.step);
    }

    /// A coarse step chosen for the regression's slow model does not hold a fast one: ẋ = u +
    /// b·x from b = −0.05 to the runs' −20 (time constant 0.05 s, sampled every 0.1 s), whose
    /// whole motion is in the first two samples. Coarsened eight times, the runs average it
    /// away and RK4 at 0.8 s cannot hold b below −3.5; refined at the samples, in steps that
    /// resolve it, b comes back.
    #[test]
    fn a_motion_faster_than_the_regression_s_is_refined_at_the_samples() {
        let model = crate::diagnose::fixtures::lag("x", -0.05);
        let r = refine(&model, &[step_response(-20.0, 0.1, 100)], None, &FREE, false).unwrap();
        let b = r.coefficients.iter().find(|c| c.term == "x").unwrap().refined;
        assert!((b + 20.0).abs() < 0.2, "b = {b}");
        assert!(!r.resampled && r.step.is_some_and(|s| s < 0.1), "{:?}", r.step);
        assert!(r.text().contains("finer than the samples"), "{}", r.text());
    }
}
