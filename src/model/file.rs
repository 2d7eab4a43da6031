//! The serde shape of a model file. `docs/reference/model-file.md` documents each key (a test checks it).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::select::Backend;

/// A whole model file. Tables the core does not know (`[ship]`) are kept as data for the
/// plug-in that reads them (`crate::plugin` checks that one does).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFile {
    /// Name and provenance.
    pub model: Meta,
    /// Integrated states, in order.
    #[serde(default)]
    pub states: Vec<StateSpec>,
    /// Inputs (controls), e.g. the rudder angle.
    #[serde(default)]
    pub inputs: Vec<InputSpec>,
    /// Constants, possibly set per run (`u0`).
    #[serde(default)]
    pub parameters: BTreeMap<String, ParameterSpec>,
    /// Derived variables, in order (each may use earlier ones).
    #[serde(default)]
    pub derived: Vec<DerivedSpec>,
    /// Other spellings of names (`du` → `Δu`).
    #[serde(default)]
    pub aliases: BTreeMap<String, String>,
    /// Equations by name.
    #[serde(default)]
    pub equations: BTreeMap<String, EquationSpec>,
    /// The free parameters' covariance, written by an output-error estimate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parameter_covariance: Option<ParameterCovarianceSpec>,
    /// How the model is simulated when a command does not say (`[simulation]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<SimulationSpec>,
    /// Plug-ins' tables by name (`ship`), as written; the core hands them on unread.
    #[serde(flatten)]
    pub plugins: BTreeMap<String, toml::Value>,
}

/// `[simulation]`: the method, control step and tolerances a model is simulated with by
/// default (a command's `--integrator` and `--dt` override them). Without the table: the
/// adaptive Dormand-Prince method at Δt = 0.04 with rtol 1e-6, atol 1e-7.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// `dopri5` (adaptive, the default), `rk4` or `b8` (Oltmann's eq. B8).
    #[serde(default)]
    pub method: crate::sim::Integrator,
    /// The control step Δt: inputs are taken at its grid; the fixed step of `rk4` and `b8`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Relative tolerance of `dopri5`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Absolute tolerance of `dopri5`, in each state's unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
}

/// `[model]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    /// Human-readable name.
    pub name: String,
    /// Where the model and its numbers come from.
    #[serde(default)]
    pub provenance: String,
    /// Free notes (kept on write).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Name of the time column in data and output.
    #[serde(default = "default_time")]
    pub time: String,
    /// Whether every equation fits a forced intercept b0 (the paper's ship does). false: the
    /// constant is a candidate term like any other (`"1"` in `candidates`), chosen only where
    /// it helps.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub intercept: bool,
    /// Whether the runs' spikes (a sample or three that leap away from their neighbours and
    /// straight back) are kept as recorded; by default each is replaced by the line through
    /// its neighbours, and said.
    #[serde(default, skip_serializing_if = "is_false")]
    pub keep_spikes: bool,
    /// How the runs' inputs behave between samples: `auto` (the default: held where the record
    /// shows a zero-order hold, [`crate::data::held`], else a line), `linear` or `held`.
    /// Taken by the integral form's quadrature and by every replay into a simulation. Under
    /// `auto` and `held` a column that repeats a slower sensor's readings between them is
    /// read at its readings ([`crate::data::read_at_readings`]), but an input whose changes
    /// step a state's rate, or with which held the states' rates fit clearly better (a
    /// controller's command: [`crate::data::kinks_at_changes`],
    /// [`crate::data::fits_better_held`]), or
    /// under `held` any input that changes at isolated rows, is held.
    #[serde(default, skip_serializing_if = "is_auto")]
    pub intersample: crate::data::Intersample,
}

fn is_auto(i: &crate::data::Intersample) -> bool {
    *i == crate::data::Intersample::Auto
}

fn is_true(b: &bool) -> bool {
    *b
}

fn default_time() -> String {
    "t".into()
}

/// `[[states]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateSpec {
    /// Name used in terms.
    pub name: String,
    /// Unit (documentation and output headers).
    #[serde(default)]
    pub unit: String,
    /// Initial value for simulation.
    #[serde(default)]
    pub initial: f64,
    /// Where the runs do not record it, its value at each run's start, read off the run as a
    /// parameter's `per_run` is (`first:dose`: a dose given at the start, of which only the
    /// concentration it makes is measured).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_run: Option<String>,
    /// The state whose rate this one is, where the runs do not record it (a velocity beside a
    /// measured position): each run's column estimated from that state's record by the
    /// Kalman smoother ([`crate::model::Model::estimated_rates`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_of: Option<String>,
    /// A simulation leaving [min, max] stops with an error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// See `min`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
}

/// `[[inputs]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// Name used in terms.
    pub name: String,
    /// Unit.
    #[serde(default)]
    pub unit: String,
    /// Value when nothing else is given.
    #[serde(default)]
    pub initial: f64,
    /// How much later than recorded it acts, s (a dead time): identification reads its
    /// column that much earlier against the rest, simulation feeds it that much later.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub delay: f64,
    /// The time constant of a first-order lag it acts through, s (an actuator that follows
    /// its command as ẏ = (u − y)/T): identification reads its column through the lag,
    /// simulation feeds it so, at rest at its first value at the start. After `delay` where
    /// both are given.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub lag: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// `[parameters.NAME]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// Value for simulation (and identification unless `per_run`).
    pub value: f64,
    /// Unit.
    #[serde(default)]
    pub unit: String,
    /// For identification, the value in each run: `first:u` (the run's first u) or `mean:u`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_run: Option<String>,
    /// Estimated by output error (`termid estimate`; grey-box identification): `value` is
    /// where the estimate starts.
    #[serde(default, skip_serializing_if = "is_false")]
    pub free: bool,
    /// What is known before the runs: the estimate is pulled towards `prior.value` with
    /// standard deviation `prior.sd` (a Gaussian prior; none: the runs alone decide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prior: Option<PriorSpec>,
    /// `[lower, upper]`: the estimate stays within them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounds: Option<[f64; 2]>,
    /// The estimate's standard error (written by `termid estimate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_error: Option<f64>,
    /// A parameter that belongs to the records, not to the system: estimated once per run or
    /// per source unless the command says otherwise (`--per-run`, `--per-source`). On a held
    /// parameter it says how the parameter is estimated where a command frees it (`--free`: a
    /// sea trial's current).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nuisance: Option<Nuisance>,
    /// A velocity of the medium the body moves through (a current, a wind): held at `value` in
    /// simulation (still water, calm air) and estimated, as its `nuisance` says, from runs whose
    /// track is over ground (satellite fixes), whose velocities carry it.
    #[serde(default, skip_serializing_if = "is_false")]
    pub medium: bool,
}

/// `nuisance = "run"` or `"source"` under `[parameters.NAME]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Nuisance {
    /// Its own value in every run (a rudder zero that drifts from run to run).
    Run,
    /// Its own value in every source (a basin's rudder indicator zero).
    Source,
}

/// `[parameters.NAME.prior]`: a Gaussian prior.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PriorSpec {
    /// Its mean.
    pub value: f64,
    /// Its standard deviation (> 0).
    pub sd: f64,
}

/// `[parameter_covariance]`: the free parameters' covariance from an output-error estimate,
/// rows and columns in the order of `names`; Monte-Carlo draws use it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterCovarianceSpec {
    /// The parameters, in matrix order.
    pub names: Vec<String>,
    /// Symmetric positive semi-definite matrix, one row per parameter, already widened by
    /// the residuals' correlation time.
    pub matrix: Vec<Vec<f64>>,
}

fn is_false(b: &bool) -> bool {
    !*b
}

/// `[[derived]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DerivedSpec {
    /// Its name.
    pub name: String,
    /// A term over earlier names.
    pub definition: String,
}

/// `[equations.NAME]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EquationSpec {
    /// The state whose time derivative this equation gives.
    pub state: String,
    /// Whether `identify` fits it (false for known kinematics).
    #[serde(default = "yes")]
    pub identify: bool,
    /// Candidate terms.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<String>,
    /// Terms that always enter first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub forced: Vec<String>,
    /// Terms that never enter.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub excluded: Vec<String>,
    /// Regression back-end and its settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<Backend>,
    /// Constant b0 of the regression.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intercept: Option<f64>,
    /// Coefficients by term.
    #[serde(default)]
    pub coefficients: BTreeMap<String, CoefficientSpec>,
    /// Covariance of the identified coefficients (for Monte-Carlo prediction bands).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<CovarianceSpec>,
}

/// `[equations.NAME.covariance]`: the coefficients' covariance matrix, rows and columns in
/// the order of `terms` (each a term of `coefficients`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CovarianceSpec {
    /// The terms, in matrix order.
    pub terms: Vec<String>,
    /// Symmetric positive semi-definite matrix, one row per term (s²(X'X)⁻¹: independent rows).
    pub matrix: Vec<Vec<f64>>,
    /// The residuals' integrated autocorrelation time in rows (≥ 1): Monte-Carlo draws use
    /// `matrix` × this, since correlated rows carry less information than their number says.
    #[serde(default = "one")]
    pub correlation_time: f64,
}

fn one() -> f64 {
    1.0
}

fn yes() -> bool {
    true
}

/// A coefficient: a number, or a table with its standard error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CoefficientSpec {
    /// Just the value.
    Value(f64),
    /// Value and standard error.
    WithError {
        /// The value.
        value: f64,
        /// Its standard error.
        std_error: f64,
    },
}

impl CoefficientSpec {
    /// (value, standard error).
    pub fn value_and_error(&self) -> (f64, Option<f64>) {
        match self {
            CoefficientSpec::Value(v) => (*v, None),
            CoefficientSpec::WithError { value, std_error } => (*value, Some(*std_error)),
        }
    }
}
