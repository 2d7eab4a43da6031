//! Grey-box identification: the model file's free parameters (named parameters anywhere in
//! derived variables and equations, nonlinear in them: a rudder's ε, a Nomoto K and T,
//! Lorenz's σ) estimated by output error, alone or together with the identified equations'
//! term coefficients. Levenberg-Marquardt on the runs' re-simulation residuals, the Jacobian
//! from forward sensitivities, each parameter's prior and bounds from the model file, and the
//! covariance widened by the residuals' correlation time.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::fit::{apply, cost as sum_of_squares};
use super::refine::RefinedCoefficient;
use super::sensitivity::{fit_failure, linearise, Free, Linearised};
use super::{DiagnoseError, Effect, EstimateError, Hypothesis, Runs};
use crate::model::{FreeParameter, Model, Nuisance, ParameterCovarianceSpec};
use crate::term::Term;

/// What an estimate changes and how long it may try.
#[derive(Clone, Debug)]
pub struct EstimateSettings {
    /// Also every term coefficient of the identified equations (each pulled towards its
    /// stored value with its standard error as the prior's, scaled by `prior_weight`).
    pub coefficients: bool,
    /// The weight of the coefficients' priors (1: as stored; as the refinement's).
    pub prior_weight: f64,
    /// Most Levenberg-Marquardt iterations in each of the two rounds.
    pub iterations: usize,
    /// A round ends at a step that lowers its objective by less than this fraction: 1e-10 (the
    /// default) runs to the minimum the simulation's precision allows; the identify recipe
    /// stops at 1e-3, as its refinement does (on SIMMAN's KVLCC2 56 iterations instead of 95,
    /// every predicted overshoot the same to 0.02°).
    pub converged: f64,
    /// How each run's initial values of the compared states enter (nuisance parameters: a
    /// run is re-simulated from its first sample, and the noise in that sample would
    /// otherwise bias every estimate; a speed error persists for the whole run).
    pub initial_values: InitialValues,
    /// The source (basin, campaign) of each run, by index (empty: one source).
    pub sources: Vec<usize>,
    /// Free parameters estimated once per source (nuisances: a basin's rudder indicator
    /// zero, its propeller rate's calibration), the rest once for all.
    pub per_source: Vec<String>,
    /// Free parameters estimated once per run (nuisances that change between runs of one
    /// basin: the rudder's zero as the indicator drifts, a current across the tank).
    pub per_run: Vec<String>,
    /// Fit at the coarsest step, of up to `.1` samples, at which the start re-simulates the runs
    /// as at their samples (each compared state within `.0` of its scale: [`Runs::coarsest`]),
    /// as the identify recipe's refinement does; the costs and the initial values' moves are
    /// still reported at every sample. `None`: fit at every sample.
    pub coarsest: Option<(f64, usize)>,
}

impl Default for EstimateSettings {
    fn default() -> Self {
        EstimateSettings {
            coefficients: false,
            prior_weight: 1e-4,
            iterations: 50,
            converged: 1e-10,
            initial_values: InitialValues::Auto,
            sources: Vec::new(),
            per_source: Vec::new(),
            per_run: Vec::new(),
            coarsest: None,
        }
    }
}

impl SourceParameter {
    /// Whose value this is, as a report names it: the run's file name without its folder, or
    /// the source's number.
    pub fn whose(&self) -> String {
        match &self.run {
            Some(run) => format!("run {}", super::file_name(run)),
            None => format!("source {}", self.source + 1),
        }
    }
}

/// How an estimate treats each run's initial values of the compared states.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum InitialValues {
    /// Free; where the fit leans on them ([`FromRecords::leans`]), estimated again held as
    /// [`InitialValues::Measured`] holds them, and that fit kept where it predicts the runs
    /// from their recorded first samples better. Free initial values are the efficient
    /// estimate where the model's structure holds; where it does not, they absorb what the
    /// model does not explain, and a prediction (which starts from the record) pays for it.
    #[default]
    Auto,
    /// Estimated, each held to its recorded first sample by a prior of the record's noise
    /// there ([`Runs::noise`]): the first sample is a measurement of the initial state.
    Measured,
    /// Estimated without a prior (the fit may lean on them: [`FromRecords::leans`]).
    Free,
    /// Not estimated: every run starts at its recorded first sample.
    Recorded,
}

impl InitialValues {
    /// Every way, as its name reads on a command line.
    pub const NAMES: [(&'static str, InitialValues); 4] = [
        ("auto", InitialValues::Auto),
        ("measured", InitialValues::Measured),
        ("free", InitialValues::Free),
        ("recorded", InitialValues::Recorded),
    ];

    /// The way of a name ([`InitialValues::NAMES`]); Err: why not, naming every way.
    pub fn parse(name: &str) -> Result<InitialValues, String> {
        Self::NAMES.iter().find(|(n, _)| *n == name).map(|(_, v)| *v).ok_or_else(|| {
            let names: Vec<&str> = Self::NAMES.iter().map(|(n, _)| *n).collect();
            format!("`{name}` is none of {}", names.join(", "))
        })
    }
}

/// A parameter estimated for one source, or for one run.
#[derive(Clone, Debug, Serialize)]
pub struct SourceParameter {
    /// The parameter.
    pub name: String,
    /// The source (index, as [`EstimateSettings::sources`] numbers them).
    pub source: usize,
    /// The run (its origin), where the parameter is estimated per run.
    pub run: Option<String>,
    /// The runs (indices) that share this value.
    pub runs: Vec<usize>,
    /// The estimate.
    pub value: f64,
    /// Its standard error.
    pub std_error: f64,
}

/// The estimated model from each run's recorded first sample (its estimated initial values
/// set aside), as `termid validate` and every prediction start it.
#[derive(Clone, Debug, Serialize)]
pub struct FromRecords {
    /// The scaled sum of squares from there (`None`: the simulation left its bounds).
    pub cost: Option<f64>,
    /// How far the estimated initial values moved from the recorded first samples, in units
    /// of each record's noise there ([`Runs::noise`]): the root mean square over them.
    pub moved: Option<f64>,
    /// The largest such move.
    pub largest: Option<Move>,
    /// Whether the fit leans on its initial values: they moved by more than [`LEANS`] times
    /// the records' noise (root mean square). A noisy first sample moves its initial value by
    /// about its noise; far beyond it the initial values absorb what the model does not
    /// explain, and the fit's cost overstates how well the model predicts the runs.
    pub leans: bool,
}

/// One estimated initial value's move from its recorded first sample.
#[derive(Clone, Debug, Serialize)]
pub struct Move {
    /// In units of the record's noise, signed.
    pub z: f64,
    /// The run (its origin).
    pub run: String,
    /// The state.
    pub state: String,
}

/// How far (root mean square, in units of the records' noise) the estimated initial values may
/// move from the recorded first samples before the fit is said to lean on them.
pub const LEANS: f64 = 3.0;

/// One estimated parameter.
#[derive(Clone, Debug, Serialize)]
pub struct EstimatedParameter {
    /// Its name.
    pub name: String,
    /// Where the estimate started (the model file's value).
    pub start: f64,
    /// The estimate.
    pub value: f64,
    /// Its standard error (from the covariance; NaN without one).
    pub std_error: f64,
    /// The prior (mean, sd), if the file gave one.
    pub prior: Option<(f64, f64)>,
    /// Whether the estimate sits on one of its bounds (its standard error then understates).
    pub at_bound: bool,
    /// The share of its precision the runs gave, 1 − (std. error / prior sd)², where it has a
    /// prior: near 0 the runs do not show it and the estimate is the prior's.
    pub from_runs: Option<f64>,
}

/// A pair of free parameters whose estimates the runs tie together (|correlation| ≥
/// [`CORRELATED`]): the runs fix a combination of the two, not each.
#[derive(Clone, Debug, Serialize)]
pub struct Correlated {
    /// The one parameter.
    pub a: String,
    /// The other.
    pub b: String,
    /// Their estimates' correlation.
    pub correlation: f64,
}

/// The correlation beyond which two estimates are reported as tied ([`Correlated`]).
pub const CORRELATED: f64 = 0.95;

/// Below this share of its precision from the runs an estimate is reported as its prior's.
pub const MOSTLY_PRIOR: f64 = 0.5;

/// Beyond this share of the records' variance left ([`Estimate::unexplained`]) besides their
/// noise a fit does not follow them: a minimum of the output error that is not the system's,
/// or a structure that is not.
pub const FOLLOWS: f64 = 0.1;

/// The integration step's error an estimate accepts ([`Runs::step_error`]): a thousandth of
/// each compared quantity's scale (RMS over the runs), far below any fit's residual.
pub const STEP_RESOLVES: f64 = 1e-3;

/// The most integration steps an estimate takes a sample by itself to resolve a motion.
pub const MOST_STEPS_PER_SAMPLE: usize = 64;

/// Into how many segments the search for a start cuts each run, where the fit from the file's
/// values does not follow its records ([`Segmented`]; fewer where a run is short).
pub const SEGMENTS: usize = 16;

/// The fit again from a start found on segments of the runs, where the fit from the model
/// file's values did not follow the records.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Segmented {
    /// How many segments the runs were cut into (0: the segments' fit failed).
    pub segments: usize,
    /// Their mean length, s.
    pub seconds: f64,
    /// Whether the fit from the segments' start is the one kept (its cost is the lower).
    pub kept: bool,
    /// The cost of the fit not kept.
    pub other_cost: Option<f64>,
    /// The share of the records' variance it leaves.
    pub other_unexplained: Option<f64>,
    /// The share of the segments' variance their own fit left: where it follows them and no
    /// fit of the whole runs does, the motion's errors grow over a run (a chaotic or unstable
    /// system) and shorter runs are what can be fitted.
    pub segments_unexplained: Option<f64>,
    /// Why the file's values did not re-simulate whole runs, where they did not (the search
    /// then started from the segments alone).
    pub start_failed: Option<String>,
    /// Why the segments' fit, or the fit from its start, failed.
    pub failed: Option<String>,
    /// Where the model fitted on the segments parts from itself within a run (a twin started
    /// off by the records' noise, [`Runs::horizon_from`]): the shortest such time, s, and that
    /// run's length, s. A chaotic or unstable motion, which no fit follows over a whole run
    /// from its first sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predictable_for: Option<(f64, f64)>,
}

/// An output-error estimate's result.
#[derive(Clone, Debug, Serialize)]
pub struct Estimate {
    /// The model with the estimates, their standard errors and covariance.
    #[serde(skip)]
    pub model: Model,
    /// Scaled sum of squares of the re-simulation over all runs, before.
    pub cost_before: f64,
    /// The same after.
    pub cost_after: f64,
    /// The share of the records' variance the fit leaves: its cost per compared sample, each
    /// quantity scaled by its spread over the runs (1: no better than each quantity's mean).
    pub unexplained: f64,
    /// The share of the records' variance that is their noise, as their second differences
    /// show it ([`Runs::noise`]): what a fit that holds leaves.
    pub noise: f64,
    /// How many runs' noise is not read (sampled on a schedule, evened between their samples:
    /// [`crate::data::Frame::recorded`]): their noise counts as none.
    pub noise_unread: usize,
    /// Where the fit from the model file's values did not follow the records ([`FOLLOWS`]):
    /// the fit again from a start found on segments of the runs, and which was kept.
    pub segmented: Option<Segmented>,
    /// Why it stopped.
    pub stopped: String,
    /// Levenberg-Marquardt iterations taken, both rounds.
    pub iterations: usize,
    /// Integrated autocorrelation time of the re-simulation residuals, in samples.
    pub correlation_time: Option<f64>,
    /// Every free parameter.
    pub parameters: Vec<EstimatedParameter>,
    /// Every term coefficient estimated with them (empty unless asked).
    pub coefficients: Vec<RefinedCoefficient>,
    /// The parameters' covariance (rows as `parameters`), if the information matrix has an
    /// inverse.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// How many runs' initial values were estimated with them.
    pub initial_values: usize,
    /// How many of them are of states the runs do not record that the motion depends on (a
    /// lag, an engine), started where they are steady at each run's first sample or at the
    /// model file's value, whichever re-simulates the run better (free
    /// initial values only: held, they stay there).
    pub hidden_initial_values: usize,
    /// Those estimated initial values: (run, state index in the model's system, value).
    #[serde(skip)]
    pub initial_states: Vec<(usize, usize, f64)>,
    /// Where initial values were estimated: the estimated model re-simulated from each run's
    /// recorded first sample instead, as a prediction starts.
    pub from_records: Option<FromRecords>,
    /// The parameters estimated per source or per run, each value (a per-source value is not
    /// written to the model; a per-run parameter's mean is: [`Estimate::per_run`]).
    pub per_source: Vec<SourceParameter>,
    /// Each parameter estimated per run, over its runs: the model holds their mean.
    pub per_run: Vec<RunSpread>,
    /// Each parameter estimated per source, over its sources (where there are two or more):
    /// the test that their values differ (the model keeps its file's value).
    pub per_source_spread: Vec<RunSpread>,
    /// The parameters the model file declares per run or per source whose runs' (sources')
    /// values agreed within their uncertainty ([`RunSpread::agree`]): estimated once for every
    /// run instead (this is that fit); each with the first fit's spread and test.
    pub one_value: Vec<RunSpread>,
    /// Where free initial values leaned ([`InitialValues::Auto`]): the other fit, with them
    /// held by the records' noise, and which of the two this is.
    pub held_again: Option<HeldAgain>,
    /// How many times finer than asked the runs were integrated, their step halved until it
    /// resolved the motion of the start and of the estimates ([`STEP_RESOLVES`]): 1 where it did.
    pub finer: usize,
    /// The step the fit re-simulated the runs at, in samples: 1, or the coarsest step that
    /// resolves them ([`EstimateSettings::coarsest`]); the costs are at every sample either way.
    pub step_samples: usize,
    /// The compared states and derived variables some runs do not record: compared in those
    /// that do.
    pub partly_recorded: Vec<super::PartlyRecorded>,
    /// The pairs of free parameters the runs tie together.
    pub correlated: Vec<Correlated>,
}

/// A parameter estimated once per run (or per source), over the runs (sources): a new run's
/// value is as uncertain as they scatter.
#[derive(Clone, Debug, Serialize)]
pub struct RunSpread {
    /// The parameter.
    pub name: String,
    /// Whether its values are the runs' or the sources'.
    pub per: Nuisance,
    /// How many runs (or sources).
    pub runs: usize,
    /// The runs' (sources') mean; a per-run parameter's is written to the model, a new run's
    /// best guess.
    pub mean: f64,
    /// The runs' standard deviation.
    pub sd: f64,
    /// Wald's χ² of the values' differences from run to run with the fit's covariance, on
    /// `runs` − 1 degrees of freedom (none where the covariance could not be formed): how far
    /// the runs differ beyond what their values' uncertainty allows.
    pub chi_square: Option<f64>,
    /// P(a χ² as large) where the runs' values were equal.
    pub p_value: Option<f64>,
    /// A velocity of the medium (a current): the runs', so the model keeps its file's value
    /// instead of their mean.
    pub medium: bool,
}

/// Below this probability of a χ² as large, the runs' values differ: a parameter the file
/// declares per run stays per run; above it the runs agree and it is estimated once.
pub const RUNS_DIFFER: f64 = 0.05;

impl RunSpread {
    /// Whether the runs' values agree within their uncertainty (a p-value at least
    /// [`RUNS_DIFFER`]).
    pub fn agree(&self) -> bool {
        self.p_value.is_some_and(|p| p >= RUNS_DIFFER)
    }

    /// The spread of each parameter estimated `per` run or per source among `values` (per
    /// source where there are two sources or more).
    fn of(values: &[SourceParameter], per: Nuisance) -> Vec<RunSpread> {
        let ours = |p: &SourceParameter| p.run.is_some() == (per == Nuisance::Run);
        let mut names: Vec<&str> = values.iter().filter(|p| ours(p)).map(|p| p.name.as_str()).collect();
        names.dedup();
        names
            .into_iter()
            .filter_map(|name| {
                let v: Vec<f64> =
                    values.iter().filter(|p| ours(p) && p.name == name).map(|p| p.value).collect();
                let s = crate::uncertainty::spread_of(&v).filter(|s| per == Nuisance::Run || s.count > 1)?;
                Some(RunSpread {
                    name: name.to_string(),
                    per,
                    runs: s.count,
                    mean: s.mean,
                    sd: s.sd,
                    chi_square: None,
                    p_value: None,
                    medium: false,
                })
            })
            .collect()
    }

    /// What its values are of: "runs" or "sources".
    fn whose(&self) -> &'static str {
        match self.per {
            Nuisance::Run => "runs",
            Nuisance::Source => "sources",
        }
    }

    /// The test in words: "χ² 97.6 on 3 degrees of freedom, p < 0.001".
    fn test(&self) -> String {
        match (self.chi_square, self.p_value) {
            (Some(q), Some(p)) => {
                let p = if p < 0.001 { "p < 0.001".to_string() } else { format!("p = {p:.3}") };
                let df = self.runs - 1;
                format!("χ² {q:.1} on {df} degree{} of freedom, {p}", if df == 1 { "" } else { "s" })
            }
            _ => "not tested: the fit's covariance could not be formed".into(),
        }
    }
}

/// Wald's χ² that the values θ[i], i in `values`, are equal: the differences d from the last,
/// dᵀ (C Σ Cᵀ)⁻¹ d with the full covariance Σ. Not each value's own standard error: what the
/// runs share (a mean zero that trades against a propeller's moment) makes each value
/// uncertain, but not their differences.
fn differences(theta: &[f64], covariance: &DMatrix<f64>, values: &[usize]) -> Option<f64> {
    let (&last, rest) = values.split_last()?;
    if rest.is_empty() {
        return None;
    }
    let c = covariance;
    let d = DVector::from_iterator(rest.len(), rest.iter().map(|&i| theta[i] - theta[last]));
    let s = DMatrix::from_fn(rest.len(), rest.len(), |a, b| {
        let (i, j) = (rest[a], rest[b]);
        c[(i, j)] - c[(i, last)] - c[(last, j)] + c[(last, last)]
    });
    let q = d.dot(&(s.try_inverse()? * &d));
    q.is_finite().then_some(q.max(0.0))
}

/// The two fits of [`InitialValues::Auto`] where the free one leaned on its initial values.
#[derive(Clone, Debug, Serialize)]
pub struct HeldAgain {
    /// Whether the fit with the initial values held was kept (it predicts the runs from
    /// their recorded first samples better than the free one).
    pub kept: bool,
    /// The fit not kept, from the recorded first samples.
    pub other: FromRecords,
}

/// The runs an estimate fits (`fit`, perhaps at a coarser step) and the same runs at every
/// sample (`every`), where its costs and the records' noise are read.
#[derive(Clone, Copy)]
struct Scales<'r> {
    fit: &'r Runs,
    every: &'r Runs,
    /// `fit`'s step in samples of `every`.
    samples: usize,
}

/// The unknowns: the free parameters (absolute values), then the coefficients (changes).
struct Unknowns {
    entries: Vec<Free>,
    parameters: Vec<FreeParameter>,
    /// (equation, term, stored value, prior sd) of each coefficient.
    coefficients: Vec<(String, Term, f64, f64)>,
    /// (parameter, source, its runs, start) of each per-source unknown.
    groups: Vec<(FreeParameter, usize, Vec<usize>)>,
    /// The parameters estimated once per run.
    per_run: Vec<String>,
    /// (run, state index) of each free initial value.
    initial: Vec<(usize, usize)>,
    hypothesis: Hypothesis,
    /// Prior precision and mean per unknown (0 precision: no prior).
    precision: Vec<f64>,
    mean: Vec<f64>,
    bounds: Vec<(f64, f64)>,
}

impl Unknowns {
    fn of(
        model: &Model,
        scales: &Scales<'_>,
        settings: &EstimateSettings,
        held: bool,
        one: &[String],
    ) -> Result<Unknowns, DiagnoseError> {
        let runs = scales.fit;
        let all = model.free_parameters();
        for (names, per) in [(&settings.per_source, "source"), (&settings.per_run, "run")] {
            if let Some(n) = names.iter().find(|n| !all.iter().any(|p| &p.name == *n)) {
                return Err(DiagnoseError::Setup(format!(
                    "`{n}` is to be estimated per {per}, but it is no free parameter of {}",
                    model.path
                )));
            }
        }
        if let Some(n) = settings.per_run.iter().find(|n| settings.per_source.contains(n)) {
            return Err(DiagnoseError::Setup(format!(
                "`{n}` is to be estimated per source and per run: choose one"
            )));
        }
        // the command's word first, then the file's (`nuisance = "run"`) unless its runs agreed
        let scope = |p: &FreeParameter, asked: &[String], declared: Nuisance, other: &[String]| {
            asked.contains(&p.name)
                || (p.nuisance == Some(declared) && !other.contains(&p.name) && !one.contains(&p.name))
        };
        let per_run: Vec<String> = all
            .iter()
            .filter(|p| scope(p, &settings.per_run, Nuisance::Run, &settings.per_source))
            .map(|p| p.name.clone())
            .collect();
        let per_source: Vec<String> = all
            .iter()
            .filter(|p| scope(p, &settings.per_source, Nuisance::Source, &settings.per_run))
            .map(|p| p.name.clone())
            .collect();
        let (grouped, parameters): (Vec<FreeParameter>, Vec<FreeParameter>) =
            all.into_iter().partition(|p| per_source.contains(&p.name) || per_run.contains(&p.name));
        let source = |r: usize| settings.sources.get(r).copied().unwrap_or(0);
        let count = (0..runs.len()).map(|r| source(r) + 1).max().unwrap_or(1);
        let groups: Vec<(FreeParameter, usize, Vec<usize>)> = grouped
            .iter()
            .flat_map(|p| -> Vec<(FreeParameter, usize, Vec<usize>)> {
                if per_run.contains(&p.name) {
                    (0..runs.len()).map(|r| (p.clone(), source(r), vec![r])).collect()
                } else {
                    (0..count)
                        .filter_map(|s| {
                            let members: Vec<usize> = (0..runs.len()).filter(|&r| source(r) == s).collect();
                            (!members.is_empty()).then(|| (p.clone(), s, members))
                        })
                        .collect()
                }
            })
            .collect();
        let mut coefficients = Vec::new();
        if settings.coefficients {
            for e in model.equations().iter().filter(|e| e.identify) {
                let tau = e.covariance.as_ref().map_or(1.0, |c| c.correlation_time.max(1.0));
                for (t, v, se) in &e.coefficients {
                    // as the refinement: no standard error, a tenth of the value
                    let sd = se.map_or(0.1 * v.abs(), |s| s * tau.sqrt()).max(1e-6 * v.abs()).max(1e-300);
                    coefficients.push((e.name.clone(), t.clone(), *v, sd));
                }
            }
        }
        // each run's compared states, and where they are free the states it does not record
        // that the motion depends on (started steady or at the file's value: `Runs::new`); held, those
        // stay there, as the records' steady approach says (free, with nothing to hold them,
        // they absorb what the model does not explain as the recorded ones do)
        let initial: Vec<(usize, usize)> = if settings.initial_values != InitialValues::Recorded {
            (0..runs.len())
                .flat_map(|r| {
                    // a compared state this run does not record is one of its hidden ones
                    let frame = &runs.frames()[r];
                    let compared =
                        runs.compared().iter().filter(|(_, n)| frame.column(n).is_some()).map(|(i, _)| *i);
                    let hidden = runs.hidden[r].iter().copied().filter(|_| !held);
                    compared.chain(hidden).map(move |i| (r, i))
                })
                .collect()
        } else {
            Vec::new()
        };
        let entries = parameters
            .iter()
            .map(|p| Free::Parameter(p.name.clone()))
            .chain(coefficients.iter().map(|(e, t, _, _)| Free::Term(e.clone(), t.clone())))
            .chain(
                groups
                    .iter()
                    .map(|(p, _, members)| Free::Group { name: p.name.clone(), runs: members.clone() }),
            )
            .chain(initial.iter().map(|&(run, state)| Free::Initial { run, state }))
            .collect();
        let hypothesis = Hypothesis {
            name: "grey-box estimate".into(),
            effect: Effect::Terms {
                terms: coefficients.iter().map(|(e, t, _, _)| (e.clone(), t.to_string())).collect(),
            },
        };
        let mut precision = Vec::new();
        let mut mean = Vec::new();
        let mut bounds = Vec::new();
        for p in &parameters {
            let (m, prec) = p.prior.map_or((p.value, 0.0), |(m, sd)| (m, 1.0 / (sd * sd)));
            precision.push(prec);
            mean.push(m);
            bounds.push(p.bounds);
        }
        for (_, _, _, sd) in &coefficients {
            precision.push(settings.prior_weight / (sd * sd));
            mean.push(0.0);
            bounds.push((f64::NEG_INFINITY, f64::INFINITY));
        }
        for (p, _, _) in &groups {
            let (m, prec) = p.prior.map_or((p.value, 0.0), |(m, sd)| (m, 1.0 / (sd * sd)));
            precision.push(prec);
            mean.push(m);
            bounds.push(p.bounds);
        }
        for &(r, i) in &initial {
            // a record without a noise estimate (constant, too short) leaves its value free
            // the record's noise at its own rate (a coarser resampling averages it down)
            let noise = held.then(|| scales.every.noise(r, i)).flatten();
            precision.push(noise.map_or(0.0, |s| 1.0 / (s * s)));
            mean.push(runs.initial(r, i));
            bounds.push((f64::NEG_INFINITY, f64::INFINITY));
        }
        Ok(Unknowns {
            entries,
            parameters,
            coefficients,
            groups,
            per_run,
            initial,
            hypothesis,
            precision,
            mean,
            bounds,
        })
    }

    fn start(&self, runs: &Runs) -> Vec<f64> {
        self.parameters
            .iter()
            .map(|p| p.value)
            .chain(self.coefficients.iter().map(|_| 0.0))
            .chain(self.groups.iter().map(|(p, _, _)| p.value))
            .chain(self.initial.iter().map(|&(r, i)| runs.initial(r, i)))
            .collect()
    }

    /// Where the per-source unknowns start in θ.
    fn first_group(&self) -> usize {
        self.parameters.len() + self.coefficients.len()
    }

    /// The runs at θ: from the initial values θ holds, with their sources' values.
    fn runs_at(&self, runs: &Runs, theta: &[f64]) -> Runs {
        let g = self.first_group();
        let first = g + self.groups.len();
        let values: Vec<(usize, usize, f64)> =
            self.initial.iter().zip(&theta[first..]).map(|(&(r, i), v)| (r, i, *v)).collect();
        let own: Vec<(usize, &str, f64)> = self
            .groups
            .iter()
            .zip(&theta[g..first])
            .flat_map(|((p, _, members), v)| members.iter().map(move |&r| (r, p.name.as_str(), *v)))
            .collect();
        runs.with_initial(&values, &own)
    }

    /// The model at θ.
    fn at(&self, model: &Model, theta: &[f64]) -> Result<Model, DiagnoseError> {
        let k = self.parameters.len();
        let mut m = apply(model, &self.hypothesis, &theta[k..k + self.coefficients.len()])?;
        for (p, v) in self.parameters.iter().zip(theta) {
            m.set_parameter(&p.name, *v);
        }
        Ok(m)
    }

    fn prior_cost(&self, theta: &[f64]) -> f64 {
        theta.iter().zip(&self.mean).zip(&self.precision).map(|((t, m), p)| p * (t - m) * (t - m)).sum()
    }

    fn clamp(&self, theta: &mut [f64]) {
        for (t, (lo, hi)) in theta.iter_mut().zip(&self.bounds) {
            *t = t.clamp(*lo, *hi);
        }
    }
}

/// Estimates the model file's free parameters (and, if asked, the term coefficients) from
/// `runs` by output error, each run's initial values as [`EstimateSettings::initial_values`]
/// says.
///
/// The data's sum of squares is weighted by 1/(s²τ), s² the residuals' variance and τ their
/// correlation time, so that a prior counts against the runs as it should: a first round
/// starts with s² and τ from the start's residuals, a second from the first's end.
///
/// A parameter the file declares per run (`nuisance = "run"`) whose runs' values agree within
/// their uncertainty ([`RunSpread::agree`]) is estimated again as one value for all runs: where
/// the runs share it (a basin's indicator that holds its zero), the values the runs do not need
/// only take up noise the other parameters would have used; one declared per source likewise,
/// over two or more sources. Asked for per run or per source (the settings' `per_run`,
/// `per_source`), it stays so.
///
/// The runs are integrated at a step that resolves the motion, of the start and of the
/// estimates alike ([`Runs::step_error`] within [`STEP_RESOLVES`]): their own halved until it
/// does (up to [`MOST_STEPS_PER_SAMPLE`] steps a sample). A step too long for a fast rate (a
/// reaction's, a stiff spring's) biases every estimate towards what the integrator can follow.
pub fn estimate(model: &Model, runs: &Runs, settings: &EstimateSettings) -> Result<Estimate, DiagnoseError> {
    let finest =
        |runs: &Runs| runs.settings.iter().all(|s| s.dt * MOST_STEPS_PER_SAMPLE as f64 <= s.sample * 1.0001);
    let unresolved = |runs: &Runs, model: &Model| runs.step_error(model).is_some_and(|e| e > STEP_RESOLVES);
    let mut finer = 1;
    loop {
        let at;
        (finer, at) = runs.resolving(model, finer, STEP_RESOLVES, MOST_STEPS_PER_SAMPLE);
        let mut fit = at_step(model, &at, settings)?;
        if !finest(&at) && unresolved(&at.with_initial(&fit.initial_states, &fit.own_values()), &fit.model) {
            finer *= 2;
            continue;
        }
        fit.finer = finer;
        return Ok(fit);
    }
}

/// [`estimate`] at the runs' step.
fn at_step(model: &Model, runs: &Runs, settings: &EstimateSettings) -> Result<Estimate, DiagnoseError> {
    // a start that does not re-simulate the runs is fitted at every sample, where the fit says
    // where it diverges
    let coarse = settings.coarsest.and_then(|(tolerance, most)| {
        let fine = runs.simulate(model, &[], &[]).ok()?;
        let (factor, coarse) = runs.coarsest(model, &fine, tolerance, most);
        (factor > 1).then_some((factor, coarse))
    });
    let scales = &match &coarse {
        Some((samples, fit)) => Scales { fit, every: runs, samples: *samples },
        None => Scales { fit: runs, every: runs, samples: 1 },
    };
    let each = searched(model, scales, settings, &[])?;
    // the file's declarations are tested; what the command asks for stays
    let asked = |name: &String| settings.per_run.contains(name) || settings.per_source.contains(name);
    let agree: Vec<RunSpread> = each
        .per_run
        .iter()
        .chain(&each.per_source_spread)
        .filter(|r| r.agree() && !asked(&r.name) && !r.medium)
        .cloned()
        .collect();
    if agree.is_empty() {
        return Ok(each);
    }
    let names: Vec<String> = agree.iter().map(|r| r.name.clone()).collect();
    let mut one = searched(model, scales, settings, &names)?;
    one.one_value = agree;
    Ok(one)
}

/// [`with_initial_values`] from the model file's values and, where that fit does not follow
/// the records ([`Estimate::follows`]) or the file's values do not re-simulate whole runs
/// (they leave their bounds within one), again from a start found on segments of the runs
/// ([`segmented_start`]); the fit of the lower cost is kept and says what the other gave. An
/// output error's cost has minima that are not the system's wherever the start's phase drifts
/// off the record's (an oscillator, a predator and its prey): a fit from there stops in one and
/// reports it as converged.
fn searched(
    model: &Model,
    scales: &Scales<'_>,
    settings: &EstimateSettings,
    one: &[String],
) -> Result<Estimate, DiagnoseError> {
    let first = match with_initial_values(model, scales, settings, one) {
        Ok(first) if first.follows() => return Ok(first),
        Ok(first) => Ok(first),
        Err(DiagnoseError::Refinement(EstimateError::StartNotFinite(why))) => Err(why),
        Err(e) => return Err(e),
    };
    let again =
        segmented_start(model, scales.every, settings, one).and_then(|(start, segments, seconds, left)| {
            let mut again = with_initial_values(&start, scales, settings, one)?;
            // the report's start is the file's value, where the search began
            let file = model.parameter_values();
            for p in &mut again.parameters {
                p.start = file.get(&p.name).copied().unwrap_or(p.start);
            }
            let search = Segmented {
                segments,
                seconds,
                kept: true,
                segments_unexplained: Some(left),
                // from its recorded start a run is as uncertain as the records' noise, which
                // the segments' fit leaves
                predictable_for: predictable_for(&start, scales.every, left.sqrt()),
                ..Default::default()
            };
            Ok((again, search))
        });
    match (first, again) {
        (Ok(first), Ok((mut again, mut search))) => {
            again.cost_before = first.cost_before;
            search.kept = again.cost_after < first.cost_after;
            let (mut fit, other) = if search.kept { (again, first) } else { (first, again) };
            search.other_cost = Some(other.cost_after);
            search.other_unexplained = Some(other.unexplained);
            fit.segmented = Some(search);
            Ok(fit)
        }
        // the cost before is the segments' start's, the file's values having none
        (Err(why), Ok((mut again, mut search))) => {
            search.start_failed = Some(why);
            again.segmented = Some(search);
            Ok(again)
        }
        (Ok(mut first), Err(e)) => {
            first.segmented = Some(Segmented { failed: Some(e.to_string()), ..Default::default() });
            Ok(first)
        }
        (Err(why), Err(e)) => {
            let e = match e {
                DiagnoseError::Refinement(EstimateError::StartNotFinite(inner)) => inner,
                e => e.to_string(),
            };
            Err(DiagnoseError::Refinement(EstimateError::StartNotFinite(format!(
                "{why}; nor do the runs cut into {} segments re-simulate from them: {e}",
                4 * SEGMENTS
            ))))
        }
    }
}

/// The shortest time over which `model` stays predictable on a run of `runs` from a start
/// `offset` of each state's spread off ([`Runs::horizon_from`]), s, with that run's length;
/// `None` where it stays so throughout every run.
fn predictable_for(model: &Model, runs: &Runs, offset: f64) -> Option<(f64, f64)> {
    let sims = runs.simulate(model, &[], &[]).ok()?;
    runs.horizon_from(model, &sims, offset)
        .iter()
        .zip(&runs.frames)
        .filter_map(|(k, f)| k.map(|k| (f.since_start(k), f.duration())))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The free parameters' values fitted on the runs cut into [`SEGMENTS`] pieces each (four
/// times as many, down to 5 samples, where the start leaves its bounds within one), every
/// piece from its own free initial values (multiple shooting without the pieces joined: Bock
/// 1981; a parameter per run is one per piece here, one per source stays so), set in `model`
/// as a start: over a piece the start's simulation stays near the record, and the fit's cost
/// is nearly the equation error's, without its minima that are not the system's. With the
/// pieces' number, their mean length (s) and the share of their variance the fit left.
fn segmented_start(
    model: &Model,
    runs: &Runs,
    settings: &EstimateSettings,
    one: &[String],
) -> Result<(Model, usize, f64, f64), DiagnoseError> {
    // shorter pieces where the start leaves its bounds within one (a start far off)
    let mut tries = [(SEGMENTS, 20), (4 * SEGMENTS, 5)].into_iter().peekable();
    let (pieces, fitted) = loop {
        let (count, shortest) = tries.next().unwrap_or((SEGMENTS, 20));
        let (pieces, of) = runs.segments(model, count, shortest)?;
        let sources = of.iter().map(|&r| settings.sources.get(r).copied().unwrap_or(0)).collect();
        let settings = EstimateSettings {
            initial_values: InitialValues::Free,
            sources,
            coarsest: None,
            ..settings.clone()
        };
        let scales = Scales { fit: &pieces, every: &pieces, samples: 1 };
        match fit(model, &scales, &settings, false, one) {
            Err(DiagnoseError::Refinement(EstimateError::StartNotFinite(_))) if tries.peek().is_some() => {
                continue
            }
            outcome => break (pieces, outcome?),
        }
    };
    let mut start = model.clone();
    for p in &fitted.parameters {
        start.set_parameter(&p.name, p.value);
    }
    let seconds = pieces.settings.iter().map(|s| s.duration).sum::<f64>() / pieces.len() as f64;
    Ok((start, pieces.len(), seconds, fitted.unexplained))
}

/// [`estimate`] with the parameters `one` once for all runs, each run's initial values as
/// [`EstimateSettings::initial_values`] says.
fn with_initial_values(
    model: &Model,
    scales: &Scales<'_>,
    settings: &EstimateSettings,
    one: &[String],
) -> Result<Estimate, DiagnoseError> {
    let first = fit(model, scales, settings, settings.initial_values == InitialValues::Measured, one)?;
    let leaned = first.from_records.as_ref().filter(|f| f.leans);
    let (Some(leaned), InitialValues::Auto) = (leaned, settings.initial_values) else {
        return Ok(first);
    };
    let free = &first;
    let mut held = fit(model, scales, settings, true, one)?;
    let cost = |e: &Estimate| e.from_records.as_ref().and_then(|f| f.cost).unwrap_or(f64::INFINITY);
    if cost(&held) < cost(free) {
        held.held_again = Some(HeldAgain { kept: true, other: leaned.clone() });
        Ok(held)
    } else {
        let mut free = first;
        free.held_again = held.from_records.map(|other| HeldAgain { kept: false, other });
        Ok(free)
    }
}

/// One output-error fit, each run's initial values free or `held` by the records' noise.
fn fit(
    model: &Model,
    scales: &Scales<'_>,
    settings: &EstimateSettings,
    held: bool,
    one: &[String],
) -> Result<Estimate, DiagnoseError> {
    check(settings)?;
    let Scales { fit: runs, every, samples } = *scales;
    let u = Unknowns::of(model, scales, settings, held, one)?;
    if u.parameters.is_empty() && u.coefficients.is_empty() && u.groups.is_empty() {
        return Err(DiagnoseError::Setup(format!(
            "{} declares no free parameter (`free = true` under [parameters.NAME])",
            model.path
        )));
    }
    let k = u.entries.len();
    let residuals_on = |runs: &Runs, theta: &[f64]| -> Option<Vec<f64>> {
        let m = u.at(model, theta).ok()?;
        let runs = u.runs_at(runs, theta);
        let r = runs.residuals(&runs.simulate(&m, &[], &[]).ok()?);
        r.iter().all(|v| v.is_finite()).then_some(r)
    };
    let cost_on = |runs: &Runs, theta: &[f64]| residuals_on(runs, theta).map(|r| sum_of_squares(&r));
    // costs as reported: at every sample, where the fit is at a coarser step
    let coarse = !std::ptr::eq(runs, every);
    let linearised = |theta: &[f64]| -> Result<Linearised, DiagnoseError> {
        linearise(&u.runs_at(runs, theta), &u.at(model, theta)?, &u.entries)
            .map_err(|e| fit_failure(e, "at an iterate"))
    };
    let theta = u.start(runs);
    let Some(cost_before) = cost_on(runs, &theta) else {
        let why = u.runs_at(runs, &theta).not_finite(&u.at(model, &theta)?);
        return Err(DiagnoseError::Refinement(EstimateError::StartNotFinite(
            why.unwrap_or_else(|| "a residual is not finite".into()),
        )));
    };
    let cost_before = if coarse { cost_on(every, &theta).unwrap_or(f64::NAN) } else { cost_before };
    let start = linearised(&theta)?;
    let Minimum { theta, lin, stopped, iterations } =
        minimise(&u, settings, runs, (theta, start), |t| cost_on(runs, t), linearised);
    let from_records = from_records(&u, scales, &theta, |runs, t| cost_on(runs, t));
    let (weight, tau) = data_weight(runs, &lin.residuals, k);
    // the residuals' cost and correlation time at every sample (at the coarse step a white
    // residual is still correlated over one step)
    let (cost_after, tau) = match coarse.then(|| residuals_on(every, &theta)) {
        None => (sum_of_squares(&lin.residuals), tau),
        Some(Some(r)) => (sum_of_squares(&r), crate::uncertainty::correlation_time(&every.series(&r))),
        Some(None) => (f64::NAN, None),
    };
    let mut info = &lin.jtj * weight;
    for i in 0..k {
        info[(i, i)] += u.precision[i];
    }
    let covariance: Option<DMatrix<f64>> = info.try_inverse();
    let std_errors: Vec<f64> =
        (0..k).map(|i| covariance.as_ref().map_or(f64::NAN, |c| c[(i, i)].max(0.0).sqrt())).collect();
    let parameters = u.estimated_parameters(&theta, &std_errors);
    let np = parameters.len();
    let matrix = covariance.as_ref().map(|c| {
        (0..np)
            .map(|i| (0..np).map(|j| 0.5 * (c[(i, j)] + c[(j, i)])).collect::<Vec<f64>>())
            .collect::<Vec<_>>()
    });
    let correlated = matrix.as_ref().map_or_else(Vec::new, |m| correlated_pairs(&parameters, m));
    let per_source = u.source_parameters(runs, &theta, &std_errors);
    let (per_run, per_source_spread) = u.spreads(&per_source, &theta, covariance.as_ref());
    Ok(Estimate {
        model: u.written(model, &theta, &parameters, matrix.as_ref(), &per_run)?,
        cost_before,
        cost_after,
        unexplained: cost_after / every.residual_count().max(1) as f64,
        noise: every.noise_share(),
        noise_unread: every.frames().iter().filter(|f| f.recorded().is_some()).count(),
        segmented: None,
        finer: 1,
        stopped,
        iterations,
        correlation_time: tau,
        coefficients: u.estimated_coefficients(&theta, &std_errors),
        parameters,
        covariance: matrix,
        initial_values: u.initial.len(),
        hidden_initial_values: u.initial.iter().filter(|&&(r, i)| runs.hidden[r].contains(&i)).count(),
        initial_states: {
            let first = u.first_group() + u.groups.len();
            u.initial.iter().zip(&theta[first..]).map(|(&(r, i), &v)| (r, i, v)).collect()
        },
        from_records,
        per_source,
        per_run,
        per_source_spread,
        one_value: Vec::new(),
        held_again: None,
        step_samples: samples,
        partly_recorded: runs.partly_recorded(),
        correlated,
    })
}

/// The pairs of `parameters` whose estimates correlate beyond [`CORRELATED`] in `covariance`
/// (rows as `parameters`), the most correlated first.
fn correlated_pairs(parameters: &[EstimatedParameter], covariance: &[Vec<f64>]) -> Vec<Correlated> {
    let mut pairs = Vec::new();
    for i in 0..parameters.len() {
        for j in i + 1..parameters.len() {
            let rho = covariance[i][j] / (covariance[i][i] * covariance[j][j]).sqrt();
            if rho.abs() >= CORRELATED {
                let (a, b) = (parameters[i].name.clone(), parameters[j].name.clone());
                pairs.push(Correlated { a, b, correlation: rho });
            }
        }
    }
    pairs.sort_by(|x, y| y.correlation.abs().total_cmp(&x.correlation.abs()));
    pairs
}

/// The settings no fit can run with, refused with why.
fn check(settings: &EstimateSettings) -> Result<(), DiagnoseError> {
    if settings.iterations == 0 {
        return Err(DiagnoseError::Setup("the estimate needs at least one iteration".into()));
    }
    if !(settings.converged.is_finite() && (0.0..1.0).contains(&settings.converged)) {
        return Err(DiagnoseError::Setup(format!(
            "the estimate's stopping fraction {} must be a number from 0 to below 1",
            settings.converged
        )));
    }
    if !(settings.prior_weight.is_finite() && settings.prior_weight >= 0.0) {
        return Err(DiagnoseError::Setup(format!(
            "the coefficients' prior weight {} must be a number ≥ 0",
            settings.prior_weight
        )));
    }
    Ok(())
}

/// Where [`minimise`] ends: the unknowns, the output error linearised there, why it stopped
/// and the iterations it took.
struct Minimum {
    theta: Vec<f64>,
    lin: Linearised,
    stopped: String,
    iterations: usize,
}

/// Levenberg-Marquardt on the data's weighted sum of squares (`data_cost` of θ) and the
/// unknowns' priors, from `start` (θ and the output error linearised there). Two rounds, each
/// weighting the data as its start's residuals say ([`data_weight`]): a prior counts against
/// the runs only once their residuals' variance and correlation time are those of a fit.
fn minimise(
    u: &Unknowns,
    settings: &EstimateSettings,
    runs: &Runs,
    start: (Vec<f64>, Linearised),
    data_cost: impl Fn(&[f64]) -> Option<f64>,
    linearised: impl Fn(&[f64]) -> Result<Linearised, DiagnoseError>,
) -> Minimum {
    let k = u.entries.len();
    let (mut theta, mut lin) = start;
    let (mut stopped, mut iterations) = (String::new(), 0);
    for _round in 0..2 {
        let (weight, _) = data_weight(runs, &lin.residuals, k);
        let objective = |data: f64, theta: &[f64]| weight * data + u.prior_cost(theta);
        let mut cost = objective(sum_of_squares(&lin.residuals), &theta);
        let mut lambda = 1e-3;
        stopped = format!("{} iterations", settings.iterations);
        for _ in 0..settings.iterations {
            iterations += 1;
            let mut a = &lin.jtj * weight;
            let mut g = &lin.jtr * weight;
            for i in 0..k {
                a[(i, i)] += u.precision[i];
                g[i] += u.precision[i] * (theta[i] - u.mean[i]);
            }
            let mut damped = a.clone();
            for i in 0..k {
                damped[(i, i)] += lambda * a[(i, i)].max(1e-300);
            }
            let Some(step) = damped.lu().solve(&g) else {
                stopped = "singular normal equations (a free parameter the runs do not excite?)".into();
                break;
            };
            let mut trial: Vec<f64> = theta.iter().zip(step.iter()).map(|(t, d)| t - d).collect();
            u.clamp(&mut trial);
            match data_cost(&trial).map(|c| objective(c, &trial)) {
                Some(c) if c < cost => {
                    let improvement = (cost - c) / cost.max(1e-300);
                    let Ok(next) = linearised(&trial) else {
                        lambda *= 10.0;
                        continue;
                    };
                    let moved = trial
                        .iter()
                        .zip(&theta)
                        .map(|(a, b)| (a - b).abs() / (1e-12 + b.abs()))
                        .fold(0.0, f64::max);
                    (theta, lin, cost) = (trial, next, c);
                    lambda = (lambda / 10.0).max(1e-12);
                    if improvement < settings.converged || moved < 1e-9 {
                        stopped = "converged".into();
                        break;
                    }
                }
                _ => {
                    lambda *= 10.0;
                    if lambda > 1e10 {
                        // no step lowers the cost any more: a minimum to the precision the
                        // simulation gives
                        stopped = "converged (no step lowers the cost)".into();
                        break;
                    }
                }
            }
        }
    }
    Minimum { theta, lin, stopped, iterations }
}

/// The fit at θ re-simulated from the records as they were measured (every sample), where a
/// prediction starts, and how far its initial values moved from them in the records' noise;
/// `None` where no initial value was estimated. `cost_on` is the data's cost of θ on runs.
fn from_records(
    u: &Unknowns,
    scales: &Scales<'_>,
    theta: &[f64],
    cost_on: impl Fn(&Runs, &[f64]) -> Option<f64>,
) -> Option<FromRecords> {
    let Scales { fit: runs, every, .. } = *scales;
    if u.initial.is_empty() {
        return None;
    }
    let mut recorded = theta.to_vec();
    let first = u.first_group() + u.groups.len();
    for (v, &(r, i)) in recorded[first..].iter_mut().zip(&u.initial) {
        *v = every.initial(r, i);
    }
    let cost = cost_on(every, &recorded);
    let moves: Vec<(f64, usize, usize)> = u
        .initial
        .iter()
        .zip(&theta[first..])
        .filter_map(|(&(r, i), v)| every.noise(r, i).map(|s| ((v - every.initial(r, i)) / s, r, i)))
        .collect();
    let moved = (!moves.is_empty())
        .then(|| (moves.iter().map(|(z, _, _)| z * z).sum::<f64>() / moves.len() as f64).sqrt());
    let largest = moves.iter().max_by(|a, b| a.0.abs().total_cmp(&b.0.abs())).map(|&(z, r, i)| Move {
        z,
        run: runs.frames[r].origin().to_string(),
        state: runs.compared().iter().find(|(j, _)| *j == i).map_or_else(String::new, |(_, n)| n.clone()),
    });
    Some(FromRecords { cost, moved, largest, leans: moved.is_some_and(|m| m > LEANS) })
}

impl Unknowns {
    /// Each free parameter at θ with its standard error.
    fn estimated_parameters(&self, theta: &[f64], std_errors: &[f64]) -> Vec<EstimatedParameter> {
        self.parameters
            .iter()
            .enumerate()
            .map(|(i, p)| EstimatedParameter {
                name: p.name.clone(),
                start: p.value,
                value: theta[i],
                std_error: std_errors[i],
                prior: p.prior,
                at_bound: theta[i] <= p.bounds.0 || theta[i] >= p.bounds.1,
                from_runs: p
                    .prior
                    .map(|(_, sd)| (1.0 - (std_errors[i] / sd).powi(2)).clamp(0.0, 1.0))
                    .filter(|share| share.is_finite()),
            })
            .collect()
    }

    /// Each term coefficient at θ (the stored value and θ's change) with its standard error.
    fn estimated_coefficients(&self, theta: &[f64], std_errors: &[f64]) -> Vec<RefinedCoefficient> {
        let np = self.parameters.len();
        self.coefficients
            .iter()
            .enumerate()
            .map(|(j, (e, t, v, sd))| RefinedCoefficient {
                equation: e.clone(),
                term: t.to_string(),
                regression: *v,
                refined: v + theta[np + j],
                std_error: std_errors[np + j],
                prior_sd: *sd,
            })
            .collect()
    }

    /// Each per-source (per-run) unknown at θ with its standard error, named by its runs.
    fn source_parameters(&self, runs: &Runs, theta: &[f64], std_errors: &[f64]) -> Vec<SourceParameter> {
        let g = self.first_group();
        self.groups
            .iter()
            .enumerate()
            .map(|(k, (p, source, members))| SourceParameter {
                name: p.name.clone(),
                source: *source,
                run: self.per_run.contains(&p.name).then(|| runs.frames[members[0]].origin().to_string()),
                runs: members.clone(),
                value: theta[g + k],
                std_error: std_errors[g + k],
            })
            .collect()
    }

    /// The spread over the runs of each parameter estimated per run and over the sources of
    /// each estimated per source, with Wald's test that their values differ (θ's `covariance`).
    fn spreads(
        &self,
        per_source: &[SourceParameter],
        theta: &[f64],
        covariance: Option<&DMatrix<f64>>,
    ) -> (Vec<RunSpread>, Vec<RunSpread>) {
        let mut per_run = RunSpread::of(per_source, Nuisance::Run);
        let mut per_source_spread = RunSpread::of(per_source, Nuisance::Source);
        for r in per_run.iter_mut().chain(per_source_spread.iter_mut()) {
            let values: Vec<usize> = (0..self.groups.len())
                .filter(|&g| self.groups[g].0.name == r.name)
                .map(|g| self.first_group() + g)
                .collect();
            r.chi_square = covariance.and_then(|c| differences(theta, c, &values));
            r.p_value = r.chi_square.map(|q| crate::select::chi_square_pvalue(q, (r.runs - 1) as f64));
            r.medium = self.groups.iter().any(|(p, _, _)| p.name == r.name && p.medium);
        }
        (per_run, per_source_spread)
    }

    /// The model at θ as a file writes it: the parameters' estimates with their standard
    /// errors and covariance (`matrix`, rows as `parameters`), and each per-run parameter's
    /// mean.
    ///
    /// A per-source value belongs to its source's records (a basin's indicator), so the
    /// file's value stays; runs are a sample of one basin's drift, and their mean is a new
    /// run's guess.
    fn written(
        &self,
        model: &Model,
        theta: &[f64],
        parameters: &[EstimatedParameter],
        matrix: Option<&Vec<Vec<f64>>>,
        per_run: &[RunSpread],
    ) -> Result<Model, DiagnoseError> {
        let np = parameters.len();
        // a new run's value of a per-run parameter: the runs' mean, as uncertain as the runs
        // scatter (sd², and the mean's own sd²/n), independent of the ship's parameters;
        // written with them, so that Monte-Carlo draws of a new run vary it as a new run would
        let new_run: Vec<(String, f64, f64)> = per_run
            .iter()
            .filter(|r| r.runs > 1 && !r.medium)
            .map(|r| (r.name.clone(), r.mean, r.sd * r.sd * (1.0 + 1.0 / r.runs as f64)))
            .collect();
        let mut estimated = self.at(model, theta)?;
        estimated.set_parameter_estimates(
            &parameters
                .iter()
                .map(|p| (p.name.clone(), p.value, p.std_error.is_finite().then_some(p.std_error)))
                .chain(new_run.iter().map(|(name, mean, var)| (name.clone(), *mean, Some(var.sqrt()))))
                .collect::<Vec<_>>(),
            matrix.map(|matrix| {
                let n = np + new_run.len();
                let rows = (0..n)
                    .map(|i| {
                        (0..n)
                            .map(|j| match (i < np, j < np) {
                                (true, true) => matrix[i][j],
                                (false, false) if i == j => new_run[i - np].2,
                                _ => 0.0,
                            })
                            .collect()
                    })
                    .collect();
                ParameterCovarianceSpec {
                    names: parameters
                        .iter()
                        .map(|p| p.name.clone())
                        .chain(new_run.iter().map(|r| r.0.clone()))
                        .collect(),
                    matrix: rows,
                }
            }),
        );
        for r in per_run.iter().filter(|r| !r.medium) {
            estimated.set_parameter(&r.name, r.mean);
        }
        Ok(estimated)
    }
}

/// 1/(s²τ): the weight of the data's sum of squares against the priors, s² the residuals'
/// variance (k unknowns spent) and τ their correlation time (correlated samples carry less
/// information than their number says); and τ.
fn data_weight(runs: &Runs, residuals: &[f64], k: usize) -> (f64, Option<f64>) {
    let tau = crate::uncertainty::correlation_time(&runs.series(residuals));
    // counted at the samples: a schedule's rows between them are compared as none
    let n = runs.residual_count().min(residuals.len());
    let s2 = sum_of_squares(residuals) / (n as f64 - k as f64).max(1.0);
    (1.0 / (s2.max(1e-300) * tau.unwrap_or(1.0).max(1.0)), tau)
}

impl Estimate {
    /// `runs` (those fitted, at every sample) re-simulated as the fit has them: with the
    /// estimates, each run with its own values of what was estimated per run or per source, from
    /// its estimated initial state (its recorded first sample where that was not estimated), at
    /// the step the fit integrated them at ([`Estimate::finer`]).
    pub fn re_simulated(&self, runs: &Runs) -> Result<Vec<crate::sim::Trajectory>, crate::sim::SimError> {
        runs.finer(self.finer).with_initial(&self.initial_states, &self.own_values()).simulate(
            &self.model,
            &[],
            &[],
        )
    }

    /// Each run's own value of every parameter estimated per run or per source, (run,
    /// parameter, value), as [`Runs::with_initial`] takes them.
    pub fn own_values(&self) -> Vec<(usize, &str, f64)> {
        self.per_source
            .iter()
            .flat_map(|p| p.runs.iter().map(move |&r| (r, p.name.as_str(), p.value)))
            .collect()
    }

    /// Whether the fit follows its records: it leaves at most [`FOLLOWS`] of their variance
    /// beyond their noise.
    pub fn follows(&self) -> bool {
        self.unexplained <= FOLLOWS + self.noise
    }

    /// Whether any value was estimated per source (the report numbers the sources, so a
    /// caller names them).
    pub fn per_source_values(&self) -> bool {
        self.per_source.iter().any(|p| p.run.is_none())
    }

    /// The estimate as a person reads it: the cost before and after and, per parameter, the
    /// start, the estimate, its standard error and, where given, the prior.
    pub fn text(&self) -> String {
        use crate::identify::{num, sig};
        let mut out = format!(
            "== output-error estimate of the free parameters ==\nre-simulation cost (scaled sum of squares) {} → {} ({} % of the records' variance left, their noise {}); {} iterations; residual correlation time {} samples; stopped: {}\n",
            sig(self.cost_before, 4),
            sig(self.cost_after, 4),
            sig(100.0 * self.unexplained, 2),
            match self.noise_unread {
                0 => format!("{} %", sig(100.0 * self.noise, 2)),
                n => format!(
                    "{} %, not read in the {n} run(s) sampled on a schedule, too sparse for it to show",
                    sig(100.0 * self.noise, 2)
                ),
            },
            self.iterations,
            self.correlation_time.map_or("—".into(), |t| format!("{t:.0}")),
            self.stopped
        );
        let share = |u: f64| format!("{} %", sig(100.0 * u, 2));
        match &self.segmented {
            Some(Segmented { failed: Some(why), .. }) => out.push_str(&format!(
                "the fit from the file's values left {} of the records' variance; a start fitted on segments of the runs failed: {why}\n",
                share(self.unexplained)
            )),
            Some(s) => {
                let other = s.other_unexplained.map_or("—".into(), share);
                let cost = s.other_cost.map_or("—".into(), |c| sig(c, 4));
                let pieces = format!(
                    "the runs cut into {} segments of {} s, each from its own initial values (multiple shooting)",
                    s.segments,
                    sig(s.seconds, 3)
                );
                out.push_str(&if let Some(why) = &s.start_failed {
                    format!("the file's values do not re-simulate the runs ({why}): this fit starts from the parameters fitted on {pieces}, and leaves {}\n", share(self.unexplained))
                } else if s.kept {
                    format!("the fit from the file's values did not follow the records (cost {cost}, {other} of their variance left): this one starts from the parameters fitted on {pieces}, and leaves {}\n", share(self.unexplained))
                } else {
                    format!("the fit leaves {} of the records' variance; started again from the parameters fitted on {pieces}, it reached cost {cost} ({other} left): no better, this one is kept\n", share(self.unexplained))
                });
            }
            None => {}
        }
        let segments_follow = self
            .segmented
            .as_ref()
            .and_then(|s| s.segments_unexplained)
            .filter(|u| *u <= FOLLOWS + self.noise);
        let chaotic = self.segmented.as_ref().and_then(|s| s.predictable_for);
        if let (false, Some(left), Some((parts, run))) = (self.follows(), segments_follow, chaotic) {
            // segments of at most half the time it stays predictable
            let count = (2.0 * run / parts).ceil().max(2.0);
            out.push_str(&format!(
                "FLAG the fit does not follow the records: it leaves {} of their variance, where fitted on segments of {} s the same model follows them ({} left); fitted so, the model parts from itself within a run (started off by the records' noise, after {} s of the run's {} s): a chaotic or unstable motion, which no fit follows over a whole run from its first sample, only over pieces shorter than that (`--segments {count}` or more, Python `segments={count}`); read these estimates as failed\n",
                share(self.unexplained),
                sig(self.segmented.as_ref().map_or(0.0, |s| s.seconds), 3),
                share(left),
                sig(parts, 3),
                sig(run, 3)
            ));
        } else if let (false, Some(left), Some(s)) = (self.follows(), segments_follow, &self.segmented) {
            out.push_str(&format!(
                "FLAG the fit does not follow the records: it leaves {} of their variance, where fitted on segments of {} s the same model follows them ({} left): its errors build up over a run, from an effect the model lacks that accumulates (an offset, a drift) or from a chaotic or unstable motion, which only segments of its runs can fit (`--segments N`, Python `segments=`); read the estimates as failed\n",
                share(self.unexplained),
                sig(s.seconds, 3),
                share(left)
            ));
        } else if !self.follows() {
            out.push_str(&format!(
                "FLAG the fit does not follow the records: it leaves {} of their variance (each compared quantity scaled by its spread over the runs; their noise is {}, and a fit that holds leaves at most {:.0} % more): a minimum of the output error that is not the system's, or a structure that is not; read the estimates as failed, see the runs re-simulated (`--svg`), start elsewhere (`--param`)\n",
                share(self.unexplained),
                share(self.noise),
                100.0 * FOLLOWS
            ));
        }
        if self.finer > 1 {
            out.push_str(&format!(
                "integrated at 1/{} of the runs' step: the step asked for did not resolve the motion (the start's or the estimates'; a fast rate), and a step too long biases the estimates towards what it can follow\n",
                self.finer
            ));
        }
        if self.step_samples > 1 {
            out.push_str(&format!(
                "fitted at a step of {} samples (the coarsest at which the start re-simulates the runs as at every sample, or the step asked for); costs at every sample\n",
                self.step_samples
            ));
        }
        for p in &self.partly_recorded {
            out.push_str(&format!("{}\n", p.line()));
        }
        out.push_str(&format!(
            "{:<12} {:>14} {:>14} {:>12} {:>22} {:>9}\n",
            "parameter", "start", "estimate", "std. error", "prior (mean ± sd)", "from runs"
        ));
        for p in &self.parameters {
            let prior = p.prior.map_or("—".into(), |(m, sd)| format!("{} ± {}", num(m), num(sd)));
            out.push_str(&format!(
                "{:<12} {:>14} {:>14} {:>12} {:>22} {:>9}{}\n",
                p.name,
                num(p.start),
                num(p.value),
                sig(p.std_error, 3),
                prior,
                p.from_runs.map_or("—".into(), |s| format!("{:.0} %", 100.0 * s)),
                if p.at_bound { "  at its bound: the standard error understates" } else { "" }
            ));
        }
        // what the runs did not decide: a parameter they do not show, a pair they tie
        let prior_s: Vec<String> = self
            .parameters
            .iter()
            .filter_map(|p| {
                p.from_runs.filter(|s| *s < MOSTLY_PRIOR).map(|s| format!("{} ({:.0} %)", p.name, 100.0 * s))
            })
            .collect();
        if !prior_s.is_empty() {
            out.push_str(&format!(
                "the runs gave less than half the precision of {}: those estimates are mostly their priors' (the runs hardly show them)\n",
                prior_s.join(", ")
            ));
        }
        if !self.correlated.is_empty() {
            let pairs: Vec<String> = self
                .correlated
                .iter()
                .map(|c| format!("{} and {} ({:+.2})", c.a, c.b, c.correlation))
                .collect();
            out.push_str(&format!(
                "estimates correlated beyond ±{CORRELATED} (the runs fix a combination of each pair, not each alone): {}\n",
                pairs.join(", ")
            ));
        }
        if !self.coefficients.is_empty() {
            out.push_str(&format!("and {} term coefficients with them\n", self.coefficients.len()));
        }
        for p in &self.per_source {
            out.push_str(&format!(
                "{:<12} {:>14} {:>14} {:>12}   ({})\n",
                p.name,
                "",
                num(p.value),
                sig(p.std_error, 3),
                p.whose()
            ));
        }
        // the written model keeps the file's value of a per-source parameter (a source's value
        // is a nuisance of its records): a prediction for one source must set it
        if let Some(last) = self.per_source.iter().rfind(|p| p.run.is_none()) {
            let of_last: Vec<&SourceParameter> =
                self.per_source.iter().filter(|p| p.run.is_none() && p.source == last.source).collect();
            let names: Vec<String> = of_last.iter().map(|p| format!("`{}`", p.name)).collect();
            let values: Vec<String> =
                of_last.iter().map(|p| format!("{}={}", p.name, num(p.value))).collect();
            out.push_str(&format!(
                "  (each source's own value, not written: the model keeps its file's {}; predict source {}'s runs with `--param {}`)\n",
                names.join(", "),
                last.source + 1,
                values.join(" ")
            ));
        }
        for r in &self.per_run {
            let holds = if r.medium {
                format!(
                    "the model keeps its file's `{}`, a velocity of the medium being the runs' and not the body's; their mean {} over the {} runs, sd {}",
                    r.name,
                    num(r.mean),
                    r.runs,
                    sig(r.sd, 3)
                )
            } else {
                format!(
                    "the model holds their mean {} over the {} runs, sd {}: a new run's value is that uncertain",
                    num(r.mean),
                    r.runs,
                    sig(r.sd, 3)
                )
            };
            out.push_str(&format!(
                "  (each run's own value; {holds}; the runs' values {}: {})\n",
                if r.agree() { "agree" } else { "differ" },
                r.test()
            ));
        }
        for r in &self.per_source_spread {
            out.push_str(&format!(
                "  (the {} sources' values of `{}` {}: {})\n",
                r.runs,
                r.name,
                if r.agree() { "agree" } else { "differ" },
                r.test()
            ));
        }
        for r in &self.one_value {
            let per = if r.per == Nuisance::Run { "run" } else { "source" };
            let whose = r.whose();
            out.push_str(&format!(
                "  (`{}` one value for every run: declared per {per}, but the {} {whose}' values agreed within their uncertainty ({}; mean {}, sd {}))\n",
                r.name,
                r.runs,
                r.test(),
                num(r.mean),
                sig(r.sd, 3)
            ));
        }
        if self.initial_values > 0 {
            out.push_str(&format!(
                "and {} initial values (each run's compared states at its start{}, nuisance parameters)\n",
                self.initial_values,
                match self.hidden_initial_values {
                    0 => String::new(),
                    n => format!(
                        "; {n} of states the runs do not record that the motion depends on, started where they are steady or at the file's value, whichever re-simulates the run better"
                    ),
                }
            ));
        }
        if let Some(f) = &self.from_records {
            let cost = f.cost.map_or("— (the simulation leaves its bounds)".to_string(), |c| sig(c, 4));
            out.push_str(&format!(
                "from each run's recorded first sample instead (as a prediction starts): cost {cost}\n"
            ));
            if let (Some(moved), Some(m)) = (f.moved, &f.largest) {
                out.push_str(&format!(
                    "the estimated initial values moved {} times the records' noise from their first samples (root mean square; at most {} times, {} of {})\n",
                    sig(moved, 2),
                    // signed, at the root mean square's precision (a move of −2e-5 is not −0.0)
                    if m.z > 0.0 { format!("+{}", sig(m.z, 2)) } else { sig(m.z, 2) },
                    m.state,
                    m.run
                ));
            }
            if f.leans {
                out.push_str(&format!(
                    "FLAG the fit leans on its estimated initial values: they moved far beyond the first samples' noise, so they absorb what the model does not explain (a missing effect, a structure that does not hold) and the cost {} overstates how well it predicts these runs (from their first samples: {cost}); read the estimates with care, see the runs as predicted (`--svg`, `termid validate`)\n",
                    sig(self.cost_after, 4)
                ));
            }
        }
        if let Some(h) = &self.held_again {
            let cost =
                h.other.cost.map_or("— (the simulation leaves its bounds)".to_string(), |c| sig(c, 4));
            if h.kept {
                out.push_str(&format!(
                    "the initial values held to the first samples' noise: estimated free, they leaned on them (moved {} times the records' noise; from the records cost {cost}), and held they predict the runs from their records better (`--initial-values free` gives the free fit)\n",
                    h.other.moved.map_or("—".into(), |m| sig(m, 2))
                ));
            } else {
                out.push_str(&format!(
                    "held to the first samples' noise, the initial values give a fit that predicts the runs from their records no better (cost {cost}): the free fit is kept\n"
                ));
            }
        }
        out
    }
}
