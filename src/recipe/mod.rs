//! The recipe for a model identified from runs, as one call: several starts (one per
//! derivative preparation), each identified or chosen among configurations by what it
//! predicts, refined by output error (with the model file's free parameters, where it declares
//! any) and checked by its plug-in; the start kept that passes the checks and re-simulates
//! best; and, where the plausible starts disagree on a manoeuvre the runs did not cover, a flag
//! saying that prediction is uncertain.

mod agreement;
mod dead_times;
mod force;
mod halves;
mod laws;
mod noise;
mod parameters;
mod recorded;
mod report;
mod resimulated;
mod retrace;
mod saturation;
mod start;

pub use crate::plugin::RecipeDefaults;
pub use halves::{halves_check, halves_check_of_moments};
pub use noise::{noise_check, noise_check_of_moments};
pub use parameters::{ParameterOptions, ParameterStage};
pub use report::Primes;
pub use retrace::retrace_checks;
pub use start::{
    checks_of, default_derivative, derivative_method, prepare_runs, Start, ANY_SYSTEM_DERIVATIVE,
};

use rayon::prelude::*;

use crate::data::{Differentiator, Frame};
use crate::identify::{num, Target};
use crate::model::Model;
use crate::plugin::Check;

/// How the recipe identifies: plain data, as a command line or a Python call fills it in.
#[derive(Clone, Debug)]
pub struct RecipeSettings {
    /// The equations (empty: every identifiable one).
    pub equations: Vec<String>,
    /// One start per derivative method (`kinematic`, `kalman`, `central`, ...).
    pub derivatives: Vec<String>,
    /// Resample the runs to this step, s, before anything else.
    pub resample: Option<f64>,
    /// Smooth the states with the derivative method.
    pub smooth: bool,
    /// The prepared runs are wanted (for figures): prepared even where nothing else asks.
    pub figures: bool,
    /// Fit an intercept b0.
    pub intercept: bool,
    /// What to explain instead of the state's derivative (one equation only).
    pub target: Option<Target>,
    /// Configurations to choose among by leave-one-run-out prediction (empty: the model's
    /// own back-ends), each (label, model).
    pub choose: Vec<(String, Model)>,
    /// The states the choice compares (empty: every state of an identified equation).
    pub compare: Vec<String>,
    /// The output-error refinement of every start (none: no refinement).
    pub refine: Option<RefineOptions>,
    /// How far (relative) plausible starts may disagree on a measure of a manoeuvre the runs
    /// did not cover before the prediction is flagged.
    pub agree: f64,
    /// Each start's free parameters estimated with its coefficients, in place of its
    /// refinement (none: not; [`ParameterOptions::asked`] runs it where the model declares
    /// free parameters).
    pub parameters: Option<ParameterOptions>,
    /// A system made from its columns with the polynomial library, whose terms fail the checks
    /// a stand-in fails or hold a variable's power alone, is identified again with each state's
    /// and input's laws among the candidates and those kept where they hold (`laws.rs`).
    pub laws: bool,
    /// A system of one start, not refined, whose records show a state moved by a random force
    /// (process noise) is identified again by Itô's steps, and that kept (`force.rs`).
    pub random_force: bool,
    /// A system of no field's whose regression found an input acting later than recorded is
    /// identified again with it read so, and that kept where it holds (`dead_times.rs`).
    pub dead_times: bool,
}

impl RecipeSettings {
    /// Whether each start's free parameters are estimated with its coefficients in place of
    /// its refinement: where asked, but not with validation runs, which only the refinement
    /// is stopped by (the estimate follows it there where asked).
    pub(crate) fn parameters_in_place(&self, validated: bool) -> bool {
        self.parameters.is_some() && !validated
    }
}

impl Default for RecipeSettings {
    fn default() -> Self {
        RecipeSettings {
            equations: vec![],
            derivatives: vec!["central".into()],
            resample: None,
            smooth: false,
            figures: false,
            intercept: true,
            target: None,
            choose: vec![],
            compare: vec![],
            refine: None,
            agree: 0.10,
            parameters: None,
            laws: true,
            random_force: true,
            dead_times: true,
        }
    }
}

/// What the recipe does where its caller names no derivative starts, smoothing or refinement:
/// a field's own way (a plug-in's [`Plugin::recipe_defaults`](crate::plugin::Plugin::recipe_defaults):
/// a ship's four starts refined on its velocities and heading), else any system's: one start
/// by the weak form ([`ANY_SYSTEM_DERIVATIVE`]), not smoothed and not refined (an output error over a chaotic run has no one minimum).
impl RecipeDefaults {
    /// The defaults for `model`: its plug-in's, else any system's.
    pub fn of(model: &Model) -> RecipeDefaults {
        crate::plugins::of(model).and_then(|p| p.recipe_defaults(model)).unwrap_or_else(|| RecipeDefaults {
            derivatives: vec![ANY_SYSTEM_DERIVATIVE.into()],
            smooth: false,
            refine: None,
        })
    }
}

/// The output-error refinement of a start.
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// The compared states (`None`: all).
    pub states: Option<Vec<String>>,
    /// Weight of the regression's estimates as a prior.
    pub prior: f64,
    /// Most iterations.
    pub iterations: usize,
    /// The step the runs are re-simulated and compared at, s (resampled, anti-aliased, to
    /// the nearest whole number of samples); `None`: the coarsest, up to
    /// [`MOST_SAMPLES_PER_STEP`] samples, at which the regression's model re-simulates the runs
    /// as at their samples ([`Runs::coarsest`](crate::diagnose::Runs::coarsest) within
    /// [`RESOLVED`]). The costs reported are the runs' own, at every sample.
    pub step: Option<f64>,
}

impl RefineOptions {
    /// The refinement of terms chosen by re-simulation from rows too coarse for their rates
    /// (a census read yearly: the weak form's quadrature biases each coefficient by 2 %): every
    /// state compared, the command line's prior weight and iterations.
    pub fn of_coarse_rows() -> RefineOptions {
        RefineOptions { states: None, prior: 1e-4, iterations: 30, step: None }
    }

    /// The step asked for, in whole samples of `frames` (at least one); `None`: not asked.
    fn samples_per_step(&self, frames: &[Frame]) -> Option<usize> {
        let sample = crate::data::sample_step(frames);
        self.step.map(|step| (step / sample).round().max(1.0) as usize)
    }
}

/// How closely the model must re-simulate the runs at the refinement's step as at their
/// samples where the step is not given: a thousandth of each compared state's spread (RMS),
/// far below any re-simulation error a refinement is about.
pub const RESOLVED: f64 = 1e-3;

/// The coarsest step the refinement takes by itself, in samples.
pub const MOST_SAMPLES_PER_STEP: usize = 8;

/// Why the recipe could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RecipeError {
    /// Settings that cannot work together, or data that cannot be prepared.
    #[error("{0}")]
    Setup(String),
    /// Every start failed; the first failure.
    #[error("no start could be identified: {0}")]
    NoStart(String),
}

/// The recipe's outcome: every start and which is kept.
#[derive(Debug)]
pub struct Recipe {
    /// Every start that could be identified, in the order of the derivative methods.
    pub starts: Vec<Start>,
    /// The kept start's index: the fewest refusing checks, then the lowest re-simulation cost
    /// (the validation runs' where there are any).
    pub kept: usize,
    /// Whether the plausible starts agree on each measure of the kept start's checks (a
    /// failing one flags a prediction the runs cannot pin down).
    pub agreement: Vec<Check>,
    /// Starts that failed, with why.
    pub failed: Vec<(String, String)>,
    /// Whether costs are the validation runs'.
    pub validated: bool,
}

/// Identifies `model` from `frames` by the recipe; `held` are runs that stop each refinement
/// (prepared as the training runs are).
pub fn identify(
    model: &Model,
    frames: &[Frame],
    held: Option<&[Frame]>,
    settings: &RecipeSettings,
) -> Result<Recipe, RecipeError> {
    if settings.derivatives.len() > 1 && settings.refine.is_none() {
        return Err(RecipeError::Setup(format!(
            "derivative methods {}: several are several starts of the output-error refinement, judged by its cost: refine too",
            settings.derivatives.join(",")
        )));
    }
    if let Some(states) = settings.refine.as_ref().and_then(|r| r.states.as_ref()) {
        compared_known(model, "refine", states)?;
    }
    compared_known(model, "compare", &settings.compare)?;
    if let Some(options) = &settings.parameters {
        // said before any work
        let free: Vec<String> = model.free_parameters().iter().map(|p| p.name.clone()).collect();
        if free.is_empty() {
            return Err(RecipeError::Setup(format!(
                "{}: no parameter is free (`free = true` under [parameters.NAME]), so there is none to estimate",
                model.path
            )));
        }
        for (names, per) in [(&options.per_source, "source"), (&options.per_run, "run")] {
            if let Some(n) = names.iter().find(|n| !free.contains(n)) {
                return Err(RecipeError::Setup(format!(
                    "`{n}` is to be estimated per {per}, but it is no free parameter of {} (free: {})",
                    model.path,
                    free.join(", ")
                )));
            }
        }
        if !options.sources.is_empty() && options.sources.len() != frames.len() {
            return Err(RecipeError::Setup(format!(
                "{} sources for {} runs: give each run its source",
                options.sources.len(),
                frames.len()
            )));
        }
    }
    // a model made from columns of variables far from 0: its library about reference values,
    // decided once on the runs as recorded, so that every start and configuration has it
    let setup = |e: crate::model::ModelError| RecipeError::Setup(e.to_string());
    let (given, outline) = (model, model.outline().cloned());
    let (model, note) = model.about_references(frames).map_err(setup)?;
    let model = &model;
    let choose = settings
        .choose
        .iter()
        .map(|(name, m)| Ok((name.clone(), m.about_references(frames)?.0)))
        .collect::<Result<Vec<_>, crate::model::ModelError>>()
        .map_err(setup)?;
    let settings = &RecipeSettings { choose, ..settings.clone() };
    let mut starts = Vec::new();
    let mut failed = Vec::new();
    // the starts are independent: side by side, they fill the cores the per-run work leaves idle
    let results: Vec<_> = settings
        .derivatives
        .par_iter()
        .map(|method| start::identify_start(model, frames, held, settings, method))
        .collect();
    for (method, result) in settings.derivatives.iter().zip(results) {
        match result {
            Ok(mut s) => {
                for (_, fit) in &mut s.fits {
                    fit.selection.notes.extend(note.clone());
                }
                starts.push(s)
            }
            Err(e) if settings.derivatives.len() > 1 => failed.push((method.clone(), e.to_string())),
            Err(e) => return Err(e),
        }
    }
    let in_place = settings.parameters_in_place(held.is_some());
    let kept = |s: &Start| matches!(s.parameters, Some(ParameterStage::Kept(_)));
    if in_place && !starts.iter().any(kept) {
        // no start's free parameters could be kept: each is refined without them
        starts.par_iter_mut().for_each(|s| start::refine_instead(s, settings));
    }
    let recipe = Recipe::of(starts, failed, held.is_some(), settings.agree)?;
    // a random force read where one start of another method is neither refined nor chosen by
    // re-simulation (which no equation without the force follows for long)
    let ito = crate::data::Ito.name();
    let plain = settings.random_force
        && settings.derivatives.len() == 1
        && settings.derivatives[0] != ito
        && settings.refine.is_none();
    // the states whose roughness grows as a Brownian path's, read once for both stages
    let rough = match plain {
        true => force::rough_states(&recipe.kept().model, frames),
        false => Vec::new(),
    };
    if !rough.is_empty() && settings.choose.is_empty() {
        let forced = force::forced_states(&recipe.kept().model, frames, &rough);
        if !forced.is_empty() {
            let again = RecipeSettings {
                derivatives: vec![ito.into()],
                smooth: false,
                random_force: false,
                ..settings.clone()
            };
            return Ok(force::said(
                // the model as given: its outline, which the laws' stage reads, kept
                identify(given, frames, held, &again)?,
                &forced,
                &settings.derivatives[0],
            ));
        }
    }
    let recipe = force::untold(recipe, &rough);
    // inputs that act late: the system identified again with them read so (the laws' stage
    // within, on the delayed model), that kept where it holds
    let recipe =
        match settings.dead_times && settings.choose.is_empty() && crate::plugins::of(model).is_none() {
            true => {
                let again = |model: &Model, frames: &[Frame], dead_times: bool| {
                    identify(model, frames, held, &RecipeSettings { dead_times, ..settings.clone() })
                };
                match dead_times::stage(recipe, given, frames, &again) {
                    Ok(delayed) => return Ok(delayed),
                    Err(recorded) => recorded,
                }
            }
            false => recipe,
        };
    let flags = laws::stand_in_flags(&recipe);
    let powers = match (&outline, flags.is_empty()) {
        (Some(o), true) => laws::powers_held(&recipe, &[o.states.clone(), o.inputs.clone()].concat()),
        _ => Vec::new(),
    };
    let stand_in = !flags.is_empty() || !powers.is_empty();
    let extended = match settings.laws && stand_in && settings.choose.is_empty() {
        true => laws::with_laws(model, outline.as_ref()),
        false => None,
    };
    let again = RecipeSettings { laws: false, ..settings.clone() };
    let again = |extended: &Model| identify(extended, frames, held, &again);
    let recipe = match (extended, &outline) {
        (Some((extended, added)), Some(outline)) => {
            match laws::kept(recipe, again(&extended), &laws::Tried::laws(&added, &flags, &powers)) {
                // where no law holds and the polynomials fail, a rate that saturates may hold
                // (a predator's intake); where they pass, its scan of K is not worth its
                // time (a second for any system of a state's square, Lorenz-84's)
                (recipe, false) if !flags.is_empty() => {
                    saturation::stage(recipe, model, outline, frames, settings, &flags, &again)
                }
                (recipe, _) => recipe,
            }
        }
        _ => recipe,
    };
    Ok(match &outline {
        Some(o) => recorded::said(recipe, &o.inputs),
        None => recipe,
    })
}

/// The tests' record of a lag ẋ = −a(t)·x + u(t) from `x0`, `samples` samples at 0.05 s,
/// by fine Euler steps (200 a sample): `run.csv` of t, x and u.
#[cfg(test)]
fn lag_run(x0: f64, samples: usize, a: &dyn Fn(f64) -> f64, u: &dyn Fn(f64) -> f64) -> Frame {
    let (dt, fine) = (0.05, 200);
    let (mut x, mut t, mut ts, mut xs, mut us) = (x0, 0.0, vec![], vec![], vec![]);
    for _ in 0..samples {
        ts.push(t);
        xs.push(x);
        us.push(u(t));
        for _ in 0..fine {
            x += dt / fine as f64 * (-a(t) * x + u(t));
            t += dt / fine as f64;
        }
    }
    let mut f = Frame::new("run.csv", "t", ts).unwrap();
    f.push("x", xs).unwrap();
    f.push("u", us).unwrap();
    f
}

/// The tests' model of one state and one input: ẋ of candidates x, u and x² (a first-order
/// lag's, with one term it lacks).
#[cfg(test)]
fn lag_model() -> Model {
    Model::parse(
        "[model]\nname = \"lag\"\nintercept = false\n[[states]]\nname = \"x\"\n[[inputs]]\nname = \"u\"\n\
         [equations.x_dot]\nstate = \"x\"\ncandidates = [\"x\", \"u\", \"x^2\"]\n",
        "lag.toml",
    )
    .unwrap()
}

/// The checks of a system of no field's identified from `frames` by `how`: that its equations
/// retrace the runs without running away, that its terms hold on each half of them, that
/// the records' noise leaves them unbiased, and where there are several runs, that each gives
/// their coefficients alike.
pub fn system_checks(
    identified: &crate::identify::IdentifiedModel,
    frames: &[Frame],
    how: &crate::identify::ModelIdentification<'_>,
) -> Vec<Check> {
    // the noise tallied once: its check, and whether the halves' causes put noise first
    let tallies = noise::model_tallies(&identified.model, frames);
    retrace_checks(&identified.model, frames)
        .into_iter()
        .chain([halves_check(identified, frames, how, noise::quiet(&tallies))])
        .chain(noise::noise_check_of(&tallies))
        .chain(agreement::agreement_check(identified, frames, how))
        .collect()
}

/// A system of no field's identified from `frames` by `how` (`identified`, from `model`), with
/// its [`system_checks`]; where its equations lose their runs, their terms chosen again by
/// re-simulation (the fewest of the best subsets per equation that follow the runs), said in
/// each equation's notes, and the checks of what is kept; and whether the equations lost their
/// runs (so searched).
pub fn checked_system(
    model: &Model,
    identified: crate::identify::IdentifiedModel,
    frames: &[Frame],
    how: &crate::identify::ModelIdentification<'_>,
) -> (crate::identify::IdentifiedModel, Vec<Check>, bool) {
    let checks = system_checks(&identified, frames, how);
    let Some(search) = resimulated::by_resimulation(model, &identified, frames, how, &checks) else {
        return (identified, checks, false);
    };
    let note = resimulated::note(&identified, &search);
    let (mut kept, checks) = match search.kept {
        Some(kept) => {
            let checks = system_checks(&kept, frames, how);
            (kept, checks)
        }
        None => (identified, checks),
    };
    for (_, fit) in &mut kept.fits {
        fit.selection.notes.push(note.clone());
    }
    (kept, checks, true)
}

/// [`system_checks`] of equations identified from their statistics (runs read in pieces, or
/// gathered where the rows are): that they retrace the runs as kept (`runs`: a run read in
/// pieces averaged to at most 20 000 rows, [`crate::identify::Pieces::runs`]; none for
/// statistics alone, which hold no rows), that their terms hold on each half of the runs, and
/// that the records' noise leaves them unbiased.
pub fn moments_checks(
    identified: &crate::identify::IdentifiedModel,
    moments: &[crate::identify::EquationMoments],
    model: &Model,
    intercept: bool,
    runs: &[Frame],
) -> Vec<Check> {
    let retrace = if runs.is_empty() { Vec::new() } else { retrace_checks(&identified.model, runs) };
    let tallies = noise::moments_tallies(moments, &identified.model);
    retrace
        .into_iter()
        .chain(halves_check_of_moments(identified, moments, model, intercept, noise::quiet(&tallies)))
        .chain(noise::noise_check_of(&tallies))
        .collect()
}

/// Refuses, before any work, a name among the states a refinement or a choice compares
/// (`what`: which) that is neither a state nor a derived variable of `model` (compared with
/// the runs' column of its name: a propeller's thrust).
pub fn compared_known(model: &Model, what: &str, names: &[String]) -> Result<(), RecipeError> {
    let spec = model.spec();
    let known: Vec<&str> = spec
        .states
        .iter()
        .map(|s| s.name.as_str())
        .chain(spec.derived.iter().map(|d| d.name.as_str()))
        .collect();
    match names.iter().find(|n| !known.contains(&n.as_str())) {
        Some(name) => Err(RecipeError::Setup(format!(
            "{what}: `{name}` is neither a state nor a derived variable of the model ({})",
            known.join(", ")
        ))),
        None => Ok(()),
    }
}

/// Whether the plausible starts agree with the kept one (`kept`) on each measure of its checks.
fn agreement(starts: &[Start], kept: usize, agree: f64) -> Vec<Check> {
    // the starts that pass their checks are models the runs cannot tell apart: where
    // they disagree on a manoeuvre the runs did not cover, that prediction is that uncertain
    let plausible: Vec<(&str, &[Check])> = starts
        .iter()
        .enumerate()
        .filter(|(k, s)| *k == kept || s.refused() == 0)
        .map(|(_, s)| (s.derivative.as_str(), s.checks.as_slice()))
        .collect();
    let at = plausible.iter().position(|(d, _)| *d == starts[kept].derivative).unwrap_or(0);
    crate::plugin::disagreement(&plausible, at, agree, "the starts")
}

impl Recipe {
    /// The recipe's verdict on identified starts: the kept one and the agreement of the
    /// plausible ones.
    pub fn of(
        starts: Vec<Start>,
        failed: Vec<(String, String)>,
        validated: bool,
        agree: f64,
    ) -> Result<Recipe, RecipeError> {
        let kept = (0..starts.len())
            .min_by(|&a, &b| {
                let (x, y) = (&starts[a], &starts[b]);
                x.refused().cmp(&y.refused()).then(x.cost().total_cmp(&y.cost()))
            })
            .ok_or_else(|| {
                RecipeError::NoStart(
                    failed.first().map_or("no derivative method given".into(), |(m, e)| format!("{m}: {e}")),
                )
            })?;
        let agreement = agreement(&starts, kept, agree);
        Ok(Recipe { starts, kept, agreement, failed, validated })
    }

    /// The kept start.
    pub fn kept(&self) -> &Start {
        &self.starts[self.kept]
    }

    /// Says `note` in the kept start's first fit (what a stage tried, and why it kept what it
    /// kept).
    pub(crate) fn say(&mut self, note: String) {
        if let Some((_, fit)) = self.starts[self.kept].fits.first_mut() {
            fit.selection.notes.push(note);
        }
    }

    /// The kept start's checks with the starts' agreement.
    pub fn checks(&self) -> Vec<Check> {
        self.kept().checks.iter().chain(&self.agreement).cloned().collect()
    }

    /// The table of starts: each derivative method's costs and checks, the kept one marked.
    pub fn starts_text(&self) -> String {
        // the free parameters the starts were refined with, where they were
        let free: Vec<String> = self
            .starts
            .iter()
            .filter_map(|s| s.parameters.as_ref().and_then(ParameterStage::estimate))
            .flat_map(|e| {
                e.parameters.iter().map(|p| p.name.clone()).chain(e.per_run.iter().map(|p| p.name.clone()))
            })
            .fold(Vec::new(), |mut all, name| {
                if !all.contains(&name) {
                    all.push(name);
                }
                all
            });
        let with = if free.is_empty() {
            String::new()
        } else {
            format!(" with the model file's free parameters ({})", free.join(", "))
        };
        let mut out = format!(
            "== starts: one identification per derivative method, each refined{with}; kept: the lowest {} re-simulation cost among those that pass the checks ==\n{:<22} {:>6} {:>16} {:>16} {:>8}\n",
            if self.validated { "validation runs'" } else { "training runs'" },
            "derivative",
            "terms",
            "regression cost",
            "refined cost",
            "refused"
        );
        for (k, s) in self.starts.iter().enumerate() {
            let terms: usize =
                s.model.equations().iter().filter(|e| e.identify).map(|e| e.coefficients.len()).sum();
            let (before, after) = s.costs();
            let after = after.map_or_else(|| "rejected".to_string(), num);
            let mark = if k == self.kept { "  ← kept" } else { "" };
            out += &format!(
                "{:<22} {terms:>6} {:>16} {after:>16} {:>8}{mark}\n",
                s.derivative,
                num(before),
                s.refused()
            );
        }
        for s in &self.starts {
            let lines: Vec<String> = s.checks.iter().map(|c| c.line()).collect();
            out += &format!("{}:\n  {}\n", s.derivative, lines.join("\n  "));
        }
        out.push('\n');
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lorenz() -> Model {
        crate::plugins::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/models/lorenz.toml")))
            .unwrap()
    }

    #[test]
    fn defaults_are_the_field_s_else_any_system_s() {
        // a ship: the new-ship recipe's four starts, smoothed, refined on velocities and heading
        let ship = RecipeDefaults::of(&crate::plugins::default_model());
        assert_eq!(ship.derivatives, ["kinematic", "kalman", "savitzky-golay", "central"]);
        assert!(ship.smooth);
        assert_eq!(ship.refine.as_deref(), Some(&["u".to_string(), "v".into(), "r".into(), "ψ".into()][..]));
        // any other system: the integral form, one start, neither smoothed nor refined
        let any = RecipeDefaults::of(&lorenz());
        assert_eq!(any, RecipeDefaults { derivatives: vec!["weak".into()], smooth: false, refine: None });
    }

    #[test]
    fn a_compared_name_the_model_lacks_is_refused_before_any_work() {
        let model = lorenz();
        let settings = RecipeSettings {
            refine: Some(RefineOptions {
                states: Some(vec!["u".into()]),
                prior: 0.0,
                iterations: 1,
                step: None,
            }),
            ..Default::default()
        };
        // no runs at all: the names are refused before the runs are looked at
        let e = identify(&model, &[], None, &settings).unwrap_err().to_string();
        assert!(
            e.contains("refine: `u` is neither a state nor a derived variable of the model (x, y, z)"),
            "{e}"
        );
        let settings = RecipeSettings { compare: vec!["x".into(), "psi".into()], ..Default::default() };
        let e = identify(&model, &[], None, &settings).unwrap_err().to_string();
        assert!(e.starts_with("compare: `psi`"), "{e}");
        assert!(compared_known(&model, "refine", &["x".into(), "z".into()]).is_ok());
    }
}
