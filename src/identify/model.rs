//! A model's equations identified from runs: each equation's candidates, forced and excluded
//! terms and back-end come from the model file; [`identify_model`] fits them all and returns
//! the model with coefficients, intercepts, covariances and correlation times stored — what
//! `termid identify --model … --out …` writes, for any caller.

use super::{Design, Fit, Identification, IdentifyError, Target};
use crate::data::{Differentiator, Frame};
use crate::model::{Covariance, Equation, Model};
use crate::select::Moments;
use crate::term::{Term, Vocabulary};

/// How a model's equations are identified.
pub struct ModelIdentification<'a> {
    /// The equations to fit (empty: every identifiable one).
    pub equations: Vec<String>,
    /// Derivatives of the states where a run has no `<state>_dot` column.
    pub differentiator: &'a dyn Differentiator,
    /// Fit an intercept b0 (stored; simulated with `--with-intercept`).
    pub intercept: bool,
    /// What to explain instead of each equation's state derivative (one equation only).
    pub target: Option<Target>,
}

/// A model identified from runs.
#[derive(Clone, Debug)]
pub struct IdentifiedModel {
    /// The model with the identified coefficients, intercepts and covariances.
    pub model: Model,
    /// Each equation's fit (with its residuals' correlation time), in the order fitted.
    pub fits: Vec<(String, Fit)>,
}

/// Fits the chosen equations of `model` to `frames` and stores each in a copy of the model:
/// the chosen terms' coefficients (with standard errors) and intercept, and the coefficients'
/// covariance widened by the residuals' correlation time (for Monte-Carlo prediction bands).
/// `progress` is told which equation is being fitted.
pub fn identify_model(
    model: &Model,
    frames: &[Frame],
    how: &ModelIdentification<'_>,
    progress: &mut dyn FnMut(&str),
) -> Result<IdentifiedModel, IdentifyError> {
    let names = equations_of(model, how)?;
    // a model made from columns of variables far from 0: its library about reference values
    let (model, note) = model.about_references(frames).map_err(|e| IdentifyError::Setup(e.to_string()))?;
    let model = &model;
    let held = held_inputs(model, frames);
    let mut identified = model.clone();
    let mut fits = Vec::new();
    for name in &names {
        progress(name);
        let in_equation = |e: IdentifyError| e.in_equation(name);
        let mut fit =
            fit_equation(model, name, frames, how.differentiator, how.intercept, how.target.clone())
                .map_err(in_equation)?;
        let terms = store_fit(&mut identified, name, &fit).map_err(in_equation)?;
        describe_residuals_of(&identified, frames, how.differentiator, &mut fit).map_err(in_equation)?;
        if let Some(matrix) = &fit.covariance {
            let covariance = Covariance {
                terms,
                matrix: matrix.clone(),
                correlation_time: fit.correlation_time.unwrap_or(1.0).max(1.0),
            };
            identified
                .set_covariance(name, covariance)
                .map_err(|e| IdentifyError::Setup(format!("`{name}`: its coefficients' covariance {e}")))?;
        }
        fit.selection.notes.extend(note.clone());
        fit.selection.notes.extend(held_note(model, name, &held));
        fits.push((name.clone(), fit));
    }
    Ok(IdentifiedModel { model: identified, fits })
}

/// The selections [`identify_model`] makes of `model`'s equations that `how` names, alone:
/// each back-end on the runs' statistics, without the notes, rivals, covariances and
/// residuals' description a reader wants (a scan that judges many fits by their criterion:
/// the saturations' scan of K spent half its time on them).
pub fn select_model(
    model: &Model,
    frames: &[Frame],
    how: &ModelIdentification<'_>,
) -> Result<Vec<(String, crate::select::Selection)>, IdentifyError> {
    let names = equations_of(model, how)?;
    let (model, _) = model.about_references(frames).map_err(|e| IdentifyError::Setup(e.to_string()))?;
    let frames = &*model.acting(frames)?;
    with_identification(&model, how.differentiator, how.intercept, |identification| {
        names
            .iter()
            .map(|name| {
                let eq = model_equation(&model, name)?;
                let target = how.target.clone().unwrap_or_else(|| default_target(eq, frames));
                let design = Design::new(&eq.candidates, &model.vocabulary)?;
                let backend = eq.backend.build();
                identification
                    .select_design(&target, &design, &eq.forced, &eq.excluded, frames, backend.as_ref())
                    .map(|selection| (name.clone(), selection))
                    .map_err(|e| e.in_equation(name))
            })
            .collect()
    })
}

/// An input that holds one value through every run: its name, the value, and whether it
/// varies about it by its noise alone (recorded with a sensor's noise, not exactly).
pub(super) type Held = (String, f64, bool);

/// The share of an input's spread that its white noise may be and the input still be read
/// as held at its mean: what varies beyond the noise is then a tenth of its variance at most.
const NOISE_ALONE: f64 = 0.95;

/// Whether `tally` reads a variable that varies by its white noise alone (measured, not
/// correlated, at least 95 % of its spread): a value held steady, recorded with its noise.
pub(super) fn noise_alone(tally: &crate::data::NoiseTally) -> bool {
    tally.share().is_some_and(|(share, measured)| measured && share >= NOISE_ALONE) && !tally.correlated()
}

/// The inputs of `model` that hold one value through every run of `frames`: exactly, or
/// varying by their noise alone about their mean ([`noise_alone`]; a held input a record
/// follows reads no noise, [`crate::data::NoiseTally::of`], and is not so).
fn held_inputs(model: &Model, frames: &[Frame]) -> Vec<Held> {
    model
        .spec()
        .inputs
        .iter()
        .filter_map(|input| {
            let name = &input.name;
            let mut values = frames.iter().filter_map(|f| f.column(name)).flatten();
            let first = *values.next()?;
            if values.all(|v| *v == first) {
                return Some((name.clone(), first, false));
            }
            let tally = crate::data::NoiseTally::pooled(
                frames.iter().filter_map(|f| crate::data::NoiseTally::of(f, name, 0..f.len())),
            );
            noise_alone(&tally).then(|| (name.clone(), tally.mean, true))
        })
        .collect()
}

/// What equation `name` is told where its candidates use an input that holds one value in
/// every run ([`held_inputs`]): its effect cannot be told from a constant's. One step test
/// of ẋ = −x/τ + K·u/τ gave ẋ = 0.80 − 0.20 x, `u` left out as collinear and nothing said
/// about what that means: a model of no input, right at that u alone; recorded with its
/// noise (2 ± 0.5 %), the noise check's flag alone said anything.
pub(super) fn held_note(model: &Model, name: &str, held: &[Held]) -> Option<String> {
    let equation = model.equation(name)?;
    let used: Vec<&Held> = held
        .iter()
        .filter(|(input, ..)| {
            equation
                .candidates
                .iter()
                .any(|c| c.variables().iter().any(|v| model.vocabulary.depends_on(v, input)))
        })
        .collect();
    if used.is_empty() {
        return None;
    }
    let each: Vec<String> = used
        .iter()
        .map(|(input, v, noisy)| match noisy {
            false => format!("`{input}` = {v}"),
            true => format!("`{input}` ≈ {} (varying by its noise alone)", crate::output::sig(*v, 4)),
        })
        .collect();
    Some(format!(
        "{} in every run: what {} cannot be told from a constant (the terms in {}, or the constant \
         standing for them, hold at {} only); runs at other values tell it",
        each.join(", "),
        if used.len() == 1 { "it does" } else { "they do" },
        if used.len() == 1 { "it" } else { "them" },
        if used.len() == 1 { "that value" } else { "those values" },
    ))
}

/// The equations `how` identifies: those it names, else every identifiable one; a target
/// other than the state's derivative names one.
fn equations_of(model: &Model, how: &ModelIdentification<'_>) -> Result<Vec<String>, IdentifyError> {
    let names = if how.equations.is_empty() { model.identifiable() } else { how.equations.clone() };
    if how.target.is_some() && names.len() != 1 {
        return Err(IdentifyError::Setup(
            "a target other than the state's derivative applies to one equation: name it".into(),
        ));
    }
    Ok(names)
}

/// Stores a fit's coefficients and intercept as equation `name` of `model`; the terms stored.
pub(crate) fn store_fit(model: &mut Model, name: &str, fit: &Fit) -> Result<Vec<Term>, IdentifyError> {
    let coefficients = coefficients_of(fit, &model.vocabulary)?;
    let terms = coefficients.iter().map(|(t, _, _)| t.clone()).collect();
    model.set_coefficients(name, coefficients, fit.selection.intercept.as_ref().map(|b| b.value));
    Ok(terms)
}

/// A model's equations as each run's statistics: identified on all runs but one (a fold of a
/// choice by prediction) without another pass over their rows. A fold gives what
/// [`identify_model`] on those runs gives, to the bit (the same statistics of each run,
/// merged in the same order), without the residuals' correlation time and the covariance,
/// which a model that is only simulated does not need.
pub(crate) struct RunStatistics {
    equations: Vec<EquationRuns>,
    intercept: bool,
}

/// One equation's part of [`RunStatistics`].
struct EquationRuns {
    name: String,
    target: String,
    /// The candidates' names, in column order.
    names: Vec<String>,
    forced: Vec<usize>,
    excluded: Vec<usize>,
    /// Each run's statistics, in the runs' order.
    runs: Vec<Moments>,
}

impl RunStatistics {
    /// The statistics of the equations `how` identifies, over every run of `frames`.
    pub(crate) fn of(
        model: &Model,
        frames: &[Frame],
        how: &ModelIdentification<'_>,
    ) -> Result<RunStatistics, IdentifyError> {
        let names = equations_of(model, how)?;
        let rules = model.parameter_rules();
        let identification = Identification {
            vocabulary: &model.vocabulary,
            parameters: &rules,
            differentiator: how.differentiator,
            intercept: how.intercept,
            weights: None,
        };
        let mut equations = Vec::new();
        for name in &names {
            let in_equation = |e: IdentifyError| e.in_equation(name);
            let eq = model_equation(model, name).map_err(in_equation)?;
            let target = how.target.clone().unwrap_or_else(|| default_target(eq, frames));
            let design = Design::new(&eq.candidates, &model.vocabulary).map_err(in_equation)?;
            let forced = design.columns_of(&eq.forced, "forced").map_err(in_equation)?;
            let excluded = design.columns_of(&eq.excluded, "excluded").map_err(in_equation)?;
            let runs = identification
                .moments_of_runs(&design.library, design.candidates(), &target, frames)
                .map_err(in_equation)?;
            equations.push(EquationRuns {
                name: name.clone(),
                target: target.to_string(),
                names: design.names().to_vec(),
                forced,
                excluded,
                runs,
            });
        }
        Ok(RunStatistics { equations, intercept: how.intercept })
    }

    /// `model` (the one the statistics are of, its back-ends as the fold should select)
    /// identified on every run but `left_out`.
    pub(crate) fn identify_without(
        &self,
        model: &Model,
        left_out: usize,
    ) -> Result<IdentifiedModel, IdentifyError> {
        let mut identified = model.clone();
        let mut fits = Vec::new();
        for EquationRuns { name, target, names, forced, excluded, runs } in &self.equations {
            let in_equation = |e: IdentifyError| e.in_equation(name);
            let eq = model_equation(model, name).map_err(in_equation)?;
            let folds: Vec<Moments> =
                runs.iter().enumerate().filter(|(k, _)| *k != left_out).map(|(_, m)| m.clone()).collect();
            let backend = eq.backend.build();
            let fit =
                super::fit_folds(target, names, forced, excluded, self.intercept, &folds, backend.as_ref())
                    .map_err(in_equation)?;
            store_fit(&mut identified, name, &fit).map_err(in_equation)?;
            fits.push((name.clone(), fit));
        }
        Ok(IdentifiedModel { model: identified, fits })
    }
}

/// Identifies one equation of a model from runs: candidates, forced and excluded terms and
/// the back-end come from the model file; the target is the column `<state>_dot` where every
/// run has it, else the derivative of the state.
pub fn fit_equation(
    model: &Model,
    equation: &str,
    frames: &[Frame],
    differentiator: &dyn Differentiator,
    intercept: bool,
    target: Option<Target>,
) -> Result<Fit, IdentifyError> {
    fit_equation_design(model, equation, None, frames, differentiator, intercept, target)
}

/// The compiled candidates of a model's equation, for [`fit_equation_design`].
pub fn equation_design(model: &Model, equation: &str) -> Result<Design, IdentifyError> {
    let eq = model_equation(model, equation)?;
    Design::new(&eq.candidates, &model.vocabulary)
}

/// [`fit_equation`] with the equation's candidates compiled beforehand by [`equation_design`]
/// (`None`: compiled here).
pub fn fit_equation_design(
    model: &Model,
    equation: &str,
    design: Option<&Design>,
    frames: &[Frame],
    differentiator: &dyn Differentiator,
    intercept: bool,
    target: Option<Target>,
) -> Result<Fit, IdentifyError> {
    let eq = model_equation(model, equation)?;
    let target = target.unwrap_or_else(|| default_target(eq, frames));
    // inputs with a dead time read back as they act
    let frames = &*model.acting(frames)?;
    let backend = eq.backend.build();
    with_identification(model, differentiator, intercept, |identification| match design {
        Some(d) if d.candidates() != eq.candidates.as_slice() => Err(IdentifyError::Setup(format!(
            "{}: the compiled design given for `{equation}` is of other candidates",
            model.path
        ))),
        Some(d) => identification.fit_design(&target, d, &eq.forced, &eq.excluded, frames, backend.as_ref()),
        None => {
            identification.fit(&target, &eq.candidates, &eq.forced, &eq.excluded, frames, backend.as_ref())
        }
    })
}

/// An equation's target where none is named: the column `<state>_dot` where every run has
/// it, else the derivative of the state.
pub(super) fn default_target(eq: &Equation, frames: &[Frame]) -> Target {
    let column = format!("{}_dot", eq.state);
    if frames.iter().all(|f| f.column(&column).is_some()) {
        Target::Column(column)
    } else {
        Target::Derivative(eq.state.clone())
    }
}

/// The model's equation `equation`, which must have candidates.
pub(super) fn model_equation<'m>(model: &'m Model, equation: &str) -> Result<&'m Equation, IdentifyError> {
    let eq = model
        .equation(equation)
        .ok_or_else(|| IdentifyError::Setup(format!("{}: no equation `{equation}`", model.path)))?;
    if eq.candidates.is_empty() {
        return Err(IdentifyError::Setup(format!("{}: equation `{equation}` has no candidates", model.path)));
    }
    Ok(eq)
}

/// `run` given the identification of `model`'s equations as [`fit_equation`] makes it (its
/// vocabulary and per-run parameters) with `differentiator`, an intercept fitted where
/// `intercept` (the residual passes over a fit already made take it so).
fn with_identification<T>(
    model: &Model,
    differentiator: &dyn Differentiator,
    intercept: bool,
    run: impl FnOnce(&Identification<'_>) -> T,
) -> T {
    let rules = model.parameter_rules();
    run(&Identification {
        vocabulary: &model.vocabulary,
        parameters: &rules,
        differentiator,
        intercept,
        weights: None,
    })
}

/// The candidate terms of a fit of one of `model`'s equations, parsed again.
fn candidates_of(model: &Model, fit: &Fit) -> Result<Vec<Term>, IdentifyError> {
    Ok(fit.candidates.iter().map(|c| model.vocabulary.parse(c)).collect::<Result<_, _>>()?)
}

/// [`Identification::describe_residuals`] of an equation fitted by [`fit_equation`], with the
/// same runs and derivative method.
pub fn describe_residuals_of(
    model: &Model,
    frames: &[Frame],
    differentiator: &dyn Differentiator,
    fit: &mut Fit,
) -> Result<(), IdentifyError> {
    let candidates = candidates_of(model, fit)?;
    let frames = &*model.acting(frames)?;
    with_identification(model, differentiator, true, |how| {
        how.describe_residuals(&Target::parse(&fit.target), &candidates, frames, fit)
    })
}

/// Says in each of `identified`'s fits an input of its model that acts later than the file
/// declares ([`Identification::say_delays`] over the model's inputs, the same runs and
/// derivative method): once for an identification a user reads, not in every fold of a
/// cross-validation (the scan fits all candidates some 20 times). The lags said, each input's
/// once (the equation's that leaves the least of its residual), later than the file declares.
pub fn say_late_inputs(
    identified: &mut IdentifiedModel,
    frames: &[Frame],
    differentiator: &dyn Differentiator,
) -> Result<Vec<super::Lag>, IdentifyError> {
    let model = &identified.model;
    let frames = &*model.acting(frames)?;
    let inputs: Vec<String> = model.spec().inputs.iter().map(|i| i.name.clone()).collect();
    let remedy = |lag: &super::Lag| {
        let input = model.spec().inputs.iter().find(|i| i.name == lag.column);
        let (key, seconds) = match lag.first_order.filter(|_| input.is_none_or(|i| i.lag == 0.0)) {
            Some(t) => ("lag", t),
            None => ("delay", input.map_or(0.0, |i| i.delay) + lag.seconds),
        };
        let (s, name) = (crate::output::sig(seconds, 3), &lag.column);
        format!(
            "declare it in the model file: `{key} = {s}` in the [[inputs]] entry of `{name}` (a model made \
             from columns: identify --states … --{key} {name}={s})"
        )
    };
    let mut late: Vec<super::Lag> = Vec::new();
    with_identification(model, differentiator, true, |how| {
        for (name, fit) in &mut identified.fits {
            let candidates = candidates_of(model, fit)?;
            let target = Target::parse(&fit.target);
            for lag in how
                .say_delays(&target, &candidates, frames, &inputs, fit, &remedy)
                .map_err(|e| e.in_equation(name))?
            {
                match late.iter_mut().find(|l| l.column == lag.column) {
                    Some(l) if l.share <= lag.share => {}
                    Some(l) => *l = lag,
                    None => late.push(lag),
                }
            }
        }
        Ok::<_, IdentifyError>(())
    })?;
    Ok(late)
}

/// The identified coefficients of a fit, as a model stores them (term, value, std. error).
pub fn coefficients_of(
    fit: &Fit,
    vocabulary: &Vocabulary,
) -> Result<Vec<(Term, f64, Option<f64>)>, IdentifyError> {
    fit.selection
        .terms
        .iter()
        .map(|t| Ok((vocabulary.parse(&t.term)?, t.coefficient, Some(t.std_error))))
        .collect()
}
