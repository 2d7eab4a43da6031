//! Model files (TOML): the states, inputs, parameters, derived variables and aliases of a
//! system, and per equation its candidate terms, forced terms, back-end and identified
//! coefficients. One format serves identification and simulation; `docs/reference/model-file.md`
//! documents every key. Errors name the file, the line and the key, and for a bad term the
//! caret inside it.

mod covariance;
pub mod dimension;
mod file;
mod locate;
mod outline;
mod param;
mod rhs;

pub use covariance::{Covariance, CovarianceError};

pub use param::{ParamError, ParamValue};

pub use file::{
    CoefficientSpec, CovarianceSpec, EquationSpec, InputSpec, Meta, ModelFile, Nuisance,
    ParameterCovarianceSpec, ParameterSpec, PriorSpec, StateSpec,
};
pub use locate::line_of_key;
pub use outline::{Outline, DEFAULT_DEGREE, MOST_MONOMIALS, OFFSET_SPREADS};

use std::collections::BTreeMap;
use std::path::Path;

use crate::select::{Backend, Candidate};
use crate::term::{Library, Term, TermError, Vocabulary};

/// A model file that could not be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// Unreadable file (the reason is the source: `{:#}` or the chain prints it).
    #[error("{file}")]
    Io {
        /// The file.
        file: String,
        /// Why it could not be read.
        #[source]
        error: crate::budget::ReadError,
    },
    /// TOML syntax or a wrong type (toml's message carries line and column).
    #[error("{file}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// toml's message.
        message: String,
    },
    /// A key whose value does not make sense.
    #[error("{file}:{line}: `{key}`: {message}")]
    Key {
        /// The file.
        file: String,
        /// 1-based line of the key (0 if unknown).
        line: usize,
        /// The key's dotted path.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A system named by its columns ([`Outline`]) that cannot be one.
    #[error("{origin}: {message}")]
    Outline {
        /// What stands for the system (`--states x,y,z`).
        origin: String,
        /// What is wrong.
        message: String,
    },
    /// A term to force or leave out that no identified equation has among its candidates.
    #[error(
        "{file}: `{term}` is no candidate of an equation identified ({role}; their candidates: {candidates})"
    )]
    NotACandidate {
        /// The model file (or what stands for it).
        file: String,
        /// The term.
        term: String,
        /// What it was to be: forced or excluded.
        role: String,
        /// The candidates of the identified equations, a few.
        candidates: String,
    },
    /// A term inside a key.
    #[error("{file}:{line}: `{key}`:\n{term}")]
    Term {
        /// The file.
        file: String,
        /// 1-based line of the key.
        line: usize,
        /// The key.
        key: String,
        /// The term error with its caret (in the message, so not also a source that would
        /// print the caret block twice).
        term: Box<TermError>,
    },
}

/// One equation of a loaded model.
#[derive(Clone, Debug)]
pub struct Equation {
    /// Its name in the file (`u_dot`).
    pub name: String,
    /// The state whose derivative it gives.
    pub state: String,
    /// Candidate terms for identification.
    pub candidates: Vec<Term>,
    /// Terms that always enter.
    pub forced: Vec<Term>,
    /// Terms that never enter.
    pub excluded: Vec<Term>,
    /// Back-end for identification.
    pub backend: Backend,
    /// Identified (or true) coefficients: term, value, standard error.
    pub coefficients: Vec<(Term, f64, Option<f64>)>,
    /// Constant term b0 of the regression, if stored.
    pub intercept: Option<f64>,
    /// Whether `termid identify` fits it (kinematic equations are fixed).
    pub identify: bool,
    /// Covariance of the coefficients, if stored.
    pub covariance: Option<Covariance>,
}

impl Equation {
    /// The right-hand side Σ cⱼ·termⱼ (+ b0 if `with_intercept`) as one canonical term.
    pub fn rhs(&self, with_intercept: bool) -> Result<Term, TermError> {
        let mut sum = Term::constant(if with_intercept { self.intercept.unwrap_or(0.0) } else { 0.0 });
        for (t, c, _) in &self.coefficients {
            let scaled = t.scale(*c).map_err(TermError::Declaration)?;
            sum = sum.add(&scaled).map_err(TermError::Declaration)?;
        }
        Ok(sum)
    }

    /// The coefficient of a term (0 if absent).
    pub fn coefficient(&self, term: &Term) -> f64 {
        self.coefficients.iter().find(|(t, _, _)| t == term).map_or(0.0, |(_, c, _)| *c)
    }
}

/// What [`Model::admitted`] did to a run, for the caller to say.
#[derive(Clone, Debug, Default)]
pub struct Admitted {
    /// Columns renamed, a run resampled, angles unwrapped.
    pub notes: Vec<String>,
    /// Spikes mended, one line per column.
    pub spikes: Vec<String>,
}

/// A loaded, checked model.
#[derive(Clone, Debug)]
///
/// The file ([`Model::spec`]) is the one source of truth; the checked equations are derived
/// from it when it is read, and every change goes through a method that keeps both in step
/// ([`Model::set_coefficients`], [`Model::set_covariance`], [`Model::set_parameter`],
/// [`Model::set_plugin_table`], [`Model::edit`] for anything else).
pub struct Model {
    /// Where it came from.
    pub path: String,
    /// The parsed file.
    spec: ModelFile,
    /// Names usable in terms.
    pub vocabulary: Vocabulary,
    /// The equations, in the order of the states they integrate.
    equations: Vec<Equation>,
    /// The outline it was made from, where it was ([`Outline::model`]) and its polynomial
    /// library is not yet written about the runs' reference values
    /// ([`Model::about_references`]). Not in the file.
    outline: Option<std::sync::Arc<Outline>>,
}

/// The control step when neither the command nor the model file gives one, s.
pub const DEFAULT_DT: f64 = 0.04;

/// A free parameter's keys make sense: a start within its bounds, a prior with sd > 0, and
/// not also set per run. Err: (the key under `parameters.NAME`, why).
/// How many times its median an estimated rate's standard error may be at a run's ends
/// ([`Model::estimated_rates`]): beyond, the rows are left out.
const ENDS: f64 = 2.0;

/// The first and last sample of a run whose estimated rate's standard error (`errors`) is
/// within [`ENDS`] times its median: the rows between them are kept.
fn settled(errors: &[f64]) -> (usize, usize) {
    let mut sorted = errors.to_vec();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else { return (0, 0) };
    let within = |e: &f64| *e <= ENDS * median;
    (errors.iter().position(within).unwrap_or(0), errors.iter().rposition(within).unwrap_or(0))
}

fn check_free(name: &str, p: &ParameterSpec) -> Result<(), (String, String)> {
    let finite = |v: f64| v.is_finite();
    if let Some([lo, hi]) = p.bounds {
        if lo >= hi || lo.is_nan() || hi.is_nan() {
            return Err((
                ".bounds".into(),
                format!("[{lo}, {hi}] is no interval: write [lower, upper] with lower < upper"),
            ));
        }
        if !(lo..=hi).contains(&p.value) {
            return Err((".value".into(), format!("{} lies outside the bounds [{lo}, {hi}]", p.value)));
        }
    }
    if let Some(prior) = &p.prior {
        if !(finite(prior.value) && finite(prior.sd) && prior.sd > 0.0) {
            return Err((
                ".prior".into(),
                format!("value {} and sd {} must be numbers, sd > 0", prior.value, prior.sd),
            ));
        }
    }
    if p.free && p.per_run.is_some() {
        return Err((
            ".free".into(),
            format!("`{name}` is set per run (`per_run`): one estimate cannot stand for every run's value"),
        ));
    }
    Ok(())
}

/// A parameter an output-error estimate may change, as the model file declares it.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeParameter {
    /// Its name.
    pub name: String,
    /// Its value now (where an estimate starts).
    pub value: f64,
    /// Its prior (mean, sd), if any.
    pub prior: Option<(f64, f64)>,
    /// Its bounds (±∞ where none).
    pub bounds: (f64, f64),
    /// Estimated once per run or per source by default (`nuisance`), if the file says so; a
    /// velocity of the medium, which is the runs' and not the body's, per source unless so.
    pub nuisance: Option<Nuisance>,
    /// A velocity of the medium (`medium = true`: a current): the model keeps its file's value.
    pub medium: bool,
}

impl Model {
    /// The parameters declared `free`, in the file's (alphabetical) order.
    pub fn free_parameters(&self) -> Vec<FreeParameter> {
        self.spec
            .parameters
            .iter()
            .filter(|(_, p)| p.free)
            .map(|(n, p)| FreeParameter {
                name: n.clone(),
                value: p.value,
                prior: p.prior.as_ref().map(|q| (q.value, q.sd)),
                bounds: p.bounds.map_or((f64::NEG_INFINITY, f64::INFINITY), |[lo, hi]| (lo, hi)),
                nuisance: p.nuisance.or(p.medium.then_some(Nuisance::Source)),
                medium: p.medium,
            })
            .collect()
    }

    /// Writes an output-error estimate: each parameter's value and standard error, and their
    /// covariance (`None`: none could be formed, any stored one is dropped).
    pub fn set_parameter_estimates(
        &mut self,
        estimates: &[(String, f64, Option<f64>)],
        covariance: Option<ParameterCovarianceSpec>,
    ) {
        for (name, value, se) in estimates {
            if let Some(p) = self.spec.parameters.get_mut(name) {
                p.value = *value;
                p.std_error = *se;
            }
        }
        self.spec.parameter_covariance = covariance;
    }

    /// The method and control step the model is simulated with: what a command asks for,
    /// else the model's `[simulation]` table, else the adaptive Dormand-Prince method at
    /// Δt = 0.04 in the model's unit of time ([`Model::seconds_per_time`]: 0.04 d for an
    /// epidemic counted in days, not 0.04 s).
    pub fn simulation(
        &self,
        method: Option<crate::sim::Integrator>,
        dt: Option<f64>,
    ) -> (crate::sim::Integrator, f64) {
        let own = self.spec.simulation.as_ref();
        (
            method.or(own.map(|s| s.method)).unwrap_or_default(),
            dt.or(own.and_then(|s| s.dt)).unwrap_or(DEFAULT_DT * self.seconds_per_time()),
        )
    }

    /// The method and control step recorded `runs` are re-simulated with: as
    /// [`Model::simulation`], the command's step `dt` in the model's unit of time
    /// ([`Model::seconds_per_time`]); but where neither the command nor the model file gives
    /// a step the adaptive methods take the records' sample interval. Their accuracy is their
    /// tolerances', and recorded inputs are known only at the samples: a ship's 0.04 s is a
    /// thousand control steps a sample for an epidemic counted daily, and longer than a
    /// circuit's whole run sampled every 10 ns.
    pub fn resimulation(
        &self,
        method: Option<crate::sim::Integrator>,
        dt: Option<f64>,
        runs: &[crate::data::Frame],
    ) -> (crate::sim::Integrator, f64) {
        let dt = dt.map(|dt| dt * self.seconds_per_time());
        let (method, step) = self.simulation(method, dt);
        let given = dt.or(self.spec.simulation.as_ref().and_then(|s| s.dt)).is_some();
        let sampled = crate::data::sample_step(runs);
        match !given && method.is_adaptive() && sampled.is_finite() && sampled > 0.0 {
            true => (method, sampled),
            false => (method, step),
        }
    }

    /// Seconds in one unit of the model's time where its name is a unit's (`day`, `t_ms`: a
    /// run's time column is read in seconds and written back in it), else 1. A simulation's
    /// duration, output interval and step given by its user are in that unit, as its run's
    /// time column is.
    pub fn seconds_per_time(&self) -> f64 {
        crate::data::seconds_per(&self.spec.model.time).filter(|f| f.is_finite() && *f > 0.0).unwrap_or(1.0)
    }

    /// What to say where the model's time is not in seconds ([`Model::seconds_per_time`]):
    /// a simulation's times are given in its unit, its rates stay per second.
    /// A file written by hand in that unit (an epidemic's β per day) would be read 86 400 times
    /// too fast: said with the remedy.
    pub fn time_note(&self) -> Option<String> {
        let per = self.seconds_per_time();
        let time = &self.spec.model.time;
        let by_hand = !self.spec.model.provenance.starts_with("identified by termid");
        (per != 1.0).then(|| {
            format!(
                "{}: the model's time `{time}` is counted in units of {per:.6e} s: a simulation's duration, output interval and step are given in it, as its run's `{time}` column; its rates are per second{}",
                self.path,
                if by_hand {
                    format!(" (its equations' coefficients and parameters too: where this file writes them per `{time}`, name its time `t`, whose values are taken as they are)")
                } else {
                    String::new()
                }
            )
        })
    }

    /// What to say of a model as it is loaded: its time counted in another unit than seconds
    /// ([`Model::time_note`]) and each name declared in a unit that counts time otherwise
    /// ([`Model::unit_notes`]).
    pub fn load_notes(&self) -> Vec<String> {
        self.time_note().into_iter().chain(self.unit_notes()).collect()
    }

    /// A parameter, state or input declared in a unit that counts time in hours, minutes or
    /// days (a pharmacokinetic rate's `1/h`): a model file's values are SI and its rates per
    /// second, so ka = 0.5 in `1/h` is read as 0.5 per second, 3600 times too fast, and an
    /// estimate started there fails or lands on another minimum. Said with the value to write.
    pub fn unit_notes(&self) -> Vec<String> {
        let spec = &self.spec;
        let mut notes = Vec::new();
        for (name, p) in &spec.parameters {
            let Some((factor, si)) = dimension::time_in_seconds(&p.unit) else { continue };
            notes.push(format!(
                "{}: parameter `{name}` is declared in `{}`, but a model file's values are SI, time in seconds: its value {} is read in `{si}`; where it is {} {}, write `value = {}` and `unit = \"{si}\"` (estimates are written in `{si}`)",
                self.path,
                p.unit,
                crate::output::sig(p.value, 6),
                crate::output::sig(p.value, 6),
                p.unit,
                crate::output::sig(p.value * factor, 6),
            ));
        }
        let declared = spec
            .states
            .iter()
            .map(|s| ("state", &s.name, &s.unit))
            .chain(spec.inputs.iter().map(|i| ("input", &i.name, &i.unit)));
        for (what, name, unit) in declared {
            let Some((_, si)) = dimension::time_in_seconds(unit) else { continue };
            notes.push(format!(
                "{}: {what} `{name}` is declared in `{unit}`, but a model file's values are SI, time in seconds: it is read in `{si}` (a record's column headed with its unit is converted to it)",
                self.path
            ));
        }
        notes
    }

    /// The sizes each state's default absolute tolerance is counted in
    /// ([`crate::sim::System::sizes`]), from how large the states run (`magnitudes` in state
    /// order: the records' largest, or the initial values; [`crate::sim::sizes_of`]), so that
    /// concentrations of 1e-6 mol/L are followed as closely as metres; none where the model
    /// file (or a command) sets its own `atol`, kept as given in the states' own units.
    pub fn sizes(&self, magnitudes: &[f64]) -> Vec<f64> {
        match self.spec.simulation.as_ref().and_then(|s| s.atol) {
            Some(_) => Vec::new(),
            None => crate::sim::sizes_of(magnitudes),
        }
    }

    /// The adaptive method's tolerances set where given (a command's `--rtol`, `--atol`), into
    /// the model's `[simulation]` table; refused where no step control can work with them.
    pub fn set_tolerances(
        &mut self,
        rtol: Option<f64>,
        atol: Option<f64>,
    ) -> Result<(), crate::sim::SimError> {
        if rtol.is_none() && atol.is_none() {
            return Ok(());
        }
        let own = crate::sim::RightHandSide::tolerances(self);
        crate::sim::Tolerances { rtol: rtol.unwrap_or(own.rtol), atol: atol.unwrap_or(own.atol) }.check()?;
        let sim = self.spec.simulation.get_or_insert_with(|| file::SimulationSpec {
            method: Default::default(),
            dt: None,
            rtol: None,
            atol: None,
        });
        sim.rtol = rtol.or(sim.rtol);
        sim.atol = atol.or(sim.atol);
        Ok(())
    }

    /// The model file as read (and as changed through the setters).
    pub fn spec(&self) -> &ModelFile {
        &self.spec
    }

    /// The checked equations, in the order of the states they integrate.
    pub fn equations(&self) -> &[Equation] {
        &self.equations
    }

    /// The model with `backend` in every identified equation (the file's back-ends replaced).
    pub fn with_backend(&self, backend: &Backend) -> Result<Model, ModelError> {
        self.edit(|file| {
            for e in file.equations.values_mut().filter(|e| e.identify) {
                e.backend = Some(backend.clone());
            }
        })
    }

    /// The model with `forced` terms entering first and `excluded` ones never, in every
    /// identified equation that has them among its candidates (added to the file's own lists);
    /// a term that no identified equation has is refused (a misspelt one would change nothing).
    pub fn with_terms(&self, forced: &[Term], excluded: &[Term]) -> Result<Model, ModelError> {
        let identified: Vec<&Equation> = self.equations.iter().filter(|e| e.identify).collect();
        for (terms, role) in [(forced, "forced"), (excluded, "excluded")] {
            if let Some(t) = terms.iter().find(|t| !identified.iter().any(|e| e.candidates.contains(t))) {
                // the candidates, each once, in order: the first twelve
                let mut all: Vec<String> = Vec::new();
                for c in identified.iter().flat_map(|e| &e.candidates).map(|c| format!("`{c}`")) {
                    if !all.contains(&c) {
                        all.push(c);
                    }
                }
                let more = if all.len() > 12 { ", …" } else { "" };
                return Err(ModelError::NotACandidate {
                    file: self.path.clone(),
                    term: t.to_string(),
                    role: role.into(),
                    candidates: format!("{}{more}", all[..all.len().min(12)].join(", ")),
                });
            }
        }
        let lists: Vec<(String, Vec<String>, Vec<String>)> = identified
            .iter()
            .map(|e| {
                // the terms the equation has, in their canonical spelling
                let own = |terms: &[Term]| -> Vec<String> {
                    terms.iter().filter(|t| e.candidates.contains(t)).map(Term::to_string).collect()
                };
                (e.name.clone(), own(forced), own(excluded))
            })
            .collect();
        self.edit(|file| {
            for (name, forced, excluded) in lists {
                if let Some(e) = file.equations.get_mut(&name) {
                    for (list, add) in [(&mut e.forced, forced), (&mut e.excluded, excluded)] {
                        add.into_iter().for_each(|t| {
                            if !list.contains(&t) {
                                list.push(t)
                            }
                        });
                    }
                }
            }
        })
    }

    /// The model with its file edited by `change` and checked again as a file is (errors
    /// located in the edited file's text).
    pub fn edit(&self, change: impl FnOnce(&mut ModelFile)) -> Result<Model, ModelError> {
        let mut spec = self.spec.clone();
        change(&mut spec);
        let text = toml::to_string_pretty(&spec)
            .map_err(|e| ModelError::Syntax { file: self.path.clone(), message: e.to_string() })?;
        let model = Model::from_spec(spec, &text, &self.path)?;
        Ok(Model { outline: self.outline.clone(), ..model })
    }

    /// Sets a parameter's value (`false`: the model has no such parameter).
    pub fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        match self.spec.parameters.get_mut(name) {
            Some(p) => {
                p.value = value;
                true
            }
            None => false,
        }
    }

    /// Frees a held parameter (`free = true`): an estimate then changes it, from its value,
    /// with the file's prior and bounds where it gives them, and per run or per source where
    /// its `nuisance` says so (a sea trial's current). `false`: the model has no such
    /// parameter, or sets it per run (`per_run`), which no one estimate can stand for.
    pub fn free(&mut self, name: &str) -> bool {
        match self.spec.parameters.get_mut(name) {
            Some(p) if p.per_run.is_none() => {
                p.free = true;
                true
            }
            _ => false,
        }
    }

    /// The model for one estimate: `free` freed, `hold` held (`--free`, `--hold`). `Err` says
    /// which name it cannot take.
    pub fn freed(&self, free: &[String], hold: &[String]) -> Result<Model, String> {
        if let Some(name) = hold.iter().find(|n| free.contains(n)) {
            return Err(format!("`{name}` is both to be freed and held: choose one"));
        }
        let mut model = self.clone();
        for name in free {
            if !model.free(name) {
                return Err(format!(
                    "{} has no parameter `{name}` that one estimate can stand for (its parameters: {})",
                    self.path,
                    self.spec.parameters.keys().cloned().collect::<Vec<_>>().join(", ")
                ));
            }
        }
        for name in hold {
            if !model.hold(name) {
                return Err(format!("{} has no parameter `{name}`", self.path));
            }
        }
        Ok(model)
    }

    /// The model for one estimate of runs tracked over ground or not: as [`Model::freed`], and
    /// where `over_ground`, every held velocity of the medium that `hold` does not name freed
    /// too (their velocities carry it); those names beside.
    pub fn freed_over_ground(
        &self,
        free: &[String],
        hold: &[String],
        over_ground: bool,
    ) -> Result<(Model, Vec<String>), String> {
        let medium: Vec<String> = match over_ground {
            true => {
                self.held_medium().into_iter().filter(|n| !hold.contains(n) && !free.contains(n)).collect()
            }
            false => vec![],
        };
        let all: Vec<String> = free.iter().chain(&medium).cloned().collect();
        Ok((self.freed(&all, hold)?, medium))
    }

    /// `estimated` as this model (the file) declares it: each parameter free or held as here
    /// (what [`Model::freed`] changed was for one estimate), and each velocity of the medium
    /// (`medium = true`) at this model's value: a current belongs to the day's runs, not to
    /// the body (a per-run estimate's mean is no more the model's than one run's value).
    pub fn as_declared(&self, estimated: &Model) -> Model {
        let mut out = estimated.clone();
        for (name, p) in &self.spec.parameters {
            if let Some(q) = out.spec.parameters.get_mut(name) {
                q.free = p.free;
                if p.medium {
                    q.value = p.value;
                    q.std_error = p.std_error;
                }
            }
        }
        out
    }

    /// The held parameters that are a velocity of the medium (`medium = true`: a current):
    /// what runs tracked over ground ask to be estimated.
    pub fn held_medium(&self) -> Vec<String> {
        self.spec.parameters.iter().filter(|(_, p)| p.medium && !p.free).map(|(n, _)| n.clone()).collect()
    }

    /// Holds a free parameter at its value (`free = false`): what an estimate leaves alone.
    /// `false`: the model has no such parameter.
    pub fn hold(&mut self, name: &str) -> bool {
        match self.spec.parameters.get_mut(name) {
            Some(p) => {
                p.free = false;
                true
            }
            None => false,
        }
    }

    /// Sets a plug-in's table (the plug-in checks what it reads).
    pub fn set_plugin_table(&mut self, name: &str, table: toml::Value) {
        self.spec.plugins.insert(name.into(), table);
    }

    /// Adds a note to the file's `[model] notes` (kept on write).
    pub fn add_note(&mut self, note: String) {
        self.spec.model.notes.push(note);
    }

    /// Sets the file's provenance line (`[model] provenance`).
    pub fn set_provenance(&mut self, provenance: String) {
        self.spec.model.provenance = provenance;
    }

    /// Marks the model as identified from `sources` (its data files, dataset or statistics
    /// files): named so, with its former name and provenance kept in the provenance, so that
    /// whatever simulates it is not titled as the model its candidates came from.
    pub fn mark_identified(&mut self, sources: &str) {
        let (name, provenance) = (&self.spec.model.name, &self.spec.model.provenance);
        self.spec.model.provenance =
            format!("identified by termid from {sources}, with the candidates of {name} ({provenance})");
        self.spec.model.name = format!("identified from {sources}");
    }

    /// Reads and checks a model file. Plug-in tables (`[ship]`) are kept unread:
    /// `crate::plugins::load` also checks them.
    pub fn load(path: &Path) -> Result<Model, ModelError> {
        let file = path.display().to_string();
        let text =
            crate::budget::read_text(path).map_err(|error| ModelError::Io { file: file.clone(), error })?;
        Model::parse(&text, &file)
    }

    /// Parses and checks model text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Model, ModelError> {
        // old Mac line ends: TOML reads the whole file as one line and every error as line 1
        if let Some(at) = text.find('\r').filter(|&i| text.as_bytes().get(i + 1) != Some(&b'\n')) {
            let line = text[..at].matches('\r').count() + text[..at].matches('\n').count() + 1;
            return Err(ModelError::Syntax {
                file: file.into(),
                message: format!("line {line} ends in a bare carriage return (CR, old Mac line ends): save the file with LF or CRLF line ends"),
            });
        }
        let spec: ModelFile = toml::from_str(text).map_err(|e| ModelError::Syntax {
            file: file.into(),
            message: crate::contain::toml_message(&e, text),
        })?;
        Model::from_spec(spec, text, file)
    }

    /// Checks a parsed file and resolves its terms.
    pub fn from_spec(spec: ModelFile, text: &str, file: &str) -> Result<Model, ModelError> {
        let line_of = |key: &str| locate::line_of_key(text, key);
        let key_err = |key: &str, message: String| ModelError::Key {
            file: file.into(),
            line: line_of(key),
            key: key.into(),
            message,
        };
        // other tables belong to plug-ins (`crate::plugin` checks that one reads each)
        for (name, value) in &spec.plugins {
            if !value.is_table() {
                return Err(key_err(
                    name,
                    "not a key of a model file (a plug-in's settings are a table)".into(),
                ));
            }
        }
        if let Some(sim) = &spec.simulation {
            if let Some(dt) = sim.dt.filter(|d| !(d.is_finite() && *d > 0.0)) {
                return Err(key_err("simulation.dt", format!("{dt:?} is no step: give seconds > 0")));
            }
            let t = crate::sim::Tolerances {
                rtol: sim.rtol.unwrap_or(crate::sim::Tolerances::default().rtol),
                atol: sim.atol.unwrap_or(crate::sim::Tolerances::default().atol),
            };
            if let Err(e) = t.check() {
                return Err(key_err(
                    if sim.rtol.is_some() { "simulation.rtol" } else { "simulation.atol" },
                    e.to_string(),
                ));
            }
        }
        let time = &spec.model.time;
        let states = spec.states.iter().map(|s| &s.name);
        let inputs = spec.inputs.iter().map(|s| &s.name);
        for (what, names) in [("states", states.collect::<Vec<_>>()), ("inputs", inputs.collect())] {
            if let Some(i) = names.iter().position(|s| *s == time) {
                return Err(key_err(
                    &format!("{what}[{i}].name"),
                    format!("`{time}` is also the time variable (`model.time`): name one of them otherwise"),
                ));
            }
        }
        let mut vocab = Vocabulary::new();
        vocab.with_time(time);
        for (i, s) in spec.states.iter().enumerate() {
            vocab.variable(&s.name).map_err(|e| key_err(&format!("states[{i}].name"), e.to_string()))?;
            if let Some(rule) = &s.per_run {
                ParamValue::Rule(rule.clone())
                    .check_rule(&s.name)
                    .map_err(|m| key_err(&format!("states[{i}].per_run"), m.to_string()))?;
            }
            if let Some(of) = &s.rate_of {
                let recorded = spec.states.iter().find(|o| o.name == *of && o.name != s.name);
                if recorded.is_none_or(|o| o.rate_of.is_some()) {
                    return Err(key_err(
                        &format!("states[{i}].rate_of"),
                        format!("`{of}` is no other state recorded: `{}` can be estimated as the rate of a state whose record the runs hold (a position's), not of itself or of another estimated rate", s.name),
                    ));
                }
                if let Some(other) = spec.states[..i].iter().find(|o| o.rate_of.as_ref() == Some(of)) {
                    return Err(key_err(
                        &format!("states[{i}].rate_of"),
                        format!("`{of}`'s rate is `{}` already: one state is its rate", other.name),
                    ));
                }
            }
            if let (Some(lo), Some(hi)) = (s.min, s.max) {
                if lo >= hi {
                    return Err(key_err(
                        &format!("states[{i}].min"),
                        format!("min {lo} is not below max {hi}"),
                    ));
                }
            }
        }
        for (i, s) in spec.inputs.iter().enumerate() {
            vocab.variable(&s.name).map_err(|e| key_err(&format!("inputs[{i}].name"), e.to_string()))?;
            if !(s.delay >= 0.0 && s.delay.is_finite()) {
                return Err(key_err(
                    &format!("inputs[{i}].delay"),
                    format!("{} is no dead time: give seconds, 0 or more", s.delay),
                ));
            }
            if !(s.lag >= 0.0 && s.lag.is_finite()) {
                return Err(key_err(
                    &format!("inputs[{i}].lag"),
                    format!("{} is no first-order lag's time constant: give seconds, 0 or more", s.lag),
                ));
            }
        }
        for (name, p) in &spec.parameters {
            vocab.parameter(name).map_err(|e| key_err(&format!("parameters.{name}"), e.to_string()))?;
            if let Some(rule) = &p.per_run {
                ParamValue::Rule(rule.clone())
                    .check_rule(name)
                    .map_err(|m| key_err(&format!("parameters.{name}.per_run"), m.to_string()))?;
            }
            check_free(name, p).map_err(|(key, m)| key_err(&format!("parameters.{name}{key}"), m))?;
        }
        if let Some(c) = &spec.parameter_covariance {
            let k = c.names.len();
            if let Some(n) = c.names.iter().find(|n| !spec.parameters.contains_key(*n)) {
                return Err(key_err(
                    "parameter_covariance.names",
                    format!("`{n}` is not a parameter of the file"),
                ));
            }
            if c.matrix.len() != k
                || c.matrix.iter().any(|row| row.len() != k || row.iter().any(|v| !v.is_finite()))
            {
                return Err(key_err(
                    "parameter_covariance.matrix",
                    format!("must be {k} rows of {k} finite numbers, one per name"),
                ));
            }
        }
        for (i, d) in spec.derived.iter().enumerate() {
            vocab.derive(&d.name, &d.definition).map_err(|e| ModelError::Term {
                term: Box::new(e),
                file: file.into(),
                line: line_of(&format!("derived[{i}].definition")),
                key: format!("derived[{i}].definition"),
            })?;
        }
        for (alias, target) in &spec.aliases {
            vocab.alias(alias, target).map_err(|e| key_err(&format!("aliases.{alias}"), e.to_string()))?;
        }
        let mut equations = Vec::new();
        for (name, eq) in &spec.equations {
            let state = vocab.canonical(&eq.state).filter(|s| vocab.variables().contains(s));
            let Some(state) = state.filter(|s| spec.states.iter().any(|st| &st.name == s)) else {
                let like = vocab.look_alike(&eq.state).map_or(String::new(), |l| {
                    format!(
                        ": it looks like `{l}` but is spelt with other characters ({} against {})",
                        crate::term::code_points(&eq.state),
                        crate::term::code_points(&l)
                    )
                });
                return Err(key_err(
                    &format!("equations.{name}.state"),
                    format!("`{}` is not a declared state{like}", eq.state),
                ));
            };
            let parse_list = |list: &[String], what: &str| -> Result<Vec<Term>, ModelError> {
                let mut out: Vec<Term> = Vec::new();
                for (i, text) in list.iter().enumerate() {
                    let t = vocab.parse(text).map_err(|e| ModelError::Term {
                        term: Box::new(e),
                        file: file.into(),
                        line: line_of(&format!("equations.{name}.{what}[{i}]")),
                        key: format!("equations.{name}.{what}[{i}]"),
                    })?;
                    if let Some(j) = out.iter().position(|o| *o == t) {
                        return Err(key_err(
                            &format!("equations.{name}.{what}[{i}]"),
                            format!("`{text}` is the same term as `{}` (both `{t}`)", list[j]),
                        ));
                    }
                    out.push(t);
                }
                Ok(out)
            };
            let candidates = parse_list(&eq.candidates, "candidates")?;
            let forced = parse_list(&eq.forced, "forced")?;
            let excluded = parse_list(&eq.excluded, "excluded")?;
            for (what, list) in [("forced", &forced), ("excluded", &excluded)] {
                if let Some((i, t)) = list.iter().enumerate().find(|(_, t)| !candidates.contains(t)) {
                    return Err(key_err(
                        &format!("equations.{name}.{what}[{i}]"),
                        format!("`{t}` is not among the candidates"),
                    ));
                }
            }
            let mut coefficients: Vec<(Term, f64, Option<f64>)> = Vec::new();
            for (text, c) in &eq.coefficients {
                let key = format!("equations.{name}.coefficients.\"{text}\"");
                let t = vocab.parse(text).map_err(|e| ModelError::Term {
                    term: Box::new(e),
                    file: file.into(),
                    line: line_of(&key),
                    key: key.clone(),
                })?;
                let (value, se) = c.value_and_error();
                if !value.is_finite() || se.is_some_and(|s| !s.is_finite() || s < 0.0) {
                    return Err(key_err(&key, "value and std_error must be finite (std_error ≥ 0)".into()));
                }
                if coefficients.iter().any(|(o, _, _)| *o == t) {
                    return Err(key_err(&key, format!("term `{t}` has two coefficients")));
                }
                coefficients.push((t, value, se));
            }
            let covariance = match &eq.covariance {
                None => None,
                Some(c) => {
                    let key = format!("equations.{name}.covariance");
                    let bad = |m: String| key_err(&key, m);
                    let terms = c
                        .terms
                        .iter()
                        .map(|text| {
                            vocab.parse(text).map_err(|e| ModelError::Term {
                                term: Box::new(e),
                                file: file.into(),
                                line: line_of(&format!("{key}.terms")),
                                key: format!("{key}.terms"),
                            })
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    let c =
                        Covariance { terms, matrix: c.matrix.clone(), correlation_time: c.correlation_time };
                    covariance::check(&coefficients, &c).map_err(|e| bad(e.to_string()))?;
                    Some(c)
                }
            };
            let mut backend = eq.backend.clone().unwrap_or_else(Backend::for_rates);
            backend.validate().map_err(|e| key_err(&format!("equations.{name}.backend"), e.to_string()))?;
            if let Backend::Sparse(fit) = &mut backend {
                // constraints name candidates: each must be one, and is kept by its canonical text
                let key = format!("equations.{name}.backend");
                let canonical = |c: &mut Candidate, at: String| -> Result<(), ModelError> {
                    let term = match &*c {
                        Candidate::Column(j) => candidates.get(*j).cloned(),
                        Candidate::Term(text) => {
                            let t = vocab.parse(text).map_err(|e| ModelError::Term {
                                term: Box::new(e),
                                file: file.into(),
                                line: line_of(&at),
                                key: at.clone(),
                            })?;
                            candidates.contains(&t).then_some(t)
                        }
                    };
                    let term = term.ok_or_else(|| {
                        key_err(
                            &at,
                            format!(
                                "{c} is not one of the {} candidates of `{name}` (name the term as in `candidates`)",
                                candidates.len()
                            ),
                        )
                    })?;
                    *c = Candidate::Term(term.to_string());
                    Ok(())
                };
                for (i, (c, _)) in fit.fixed.iter_mut().enumerate() {
                    canonical(c, format!("{key}.fixed[{i}]"))?;
                }
                for (i, (c, _)) in fit.signs.iter_mut().enumerate() {
                    canonical(c, format!("{key}.signs[{i}]"))?;
                }
                for (i, e) in fit.equalities.iter_mut().enumerate() {
                    for (k, (c, _)) in e.terms.iter_mut().enumerate() {
                        canonical(c, format!("{key}.equalities[{i}].terms[{k}]"))?;
                    }
                }
                for (c, _) in fit.fixed.iter().chain(&fit.signs) {
                    if excluded.iter().any(|t| Candidate::Term(t.to_string()) == *c) {
                        return Err(key_err(&key, format!("a constraint names {c}, which is excluded")));
                    }
                }
            }
            equations.push(Equation {
                name: name.clone(),
                state,
                candidates,
                forced,
                excluded,
                backend,
                coefficients,
                intercept: eq.intercept,
                identify: eq.identify,
                covariance,
            });
        }
        // integrate in the order the states are declared
        equations.sort_by_key(|e| spec.states.iter().position(|s| s.name == e.state));
        for w in equations.windows(2) {
            if w[0].state == w[1].state {
                return Err(key_err(
                    &format!("equations.{}.state", w[1].name),
                    format!("state `{}` already has equation `{}`", w[1].state, w[0].name),
                ));
            }
        }
        Ok(Model { path: file.into(), spec, vocabulary: vocab, equations, outline: None })
    }

    /// The unit the file declares for a state, input or parameter (empty where none or
    /// unknown).
    pub fn unit(&self, name: &str) -> &str {
        let s = &self.spec;
        s.states
            .iter()
            .map(|x| (&x.name, &x.unit))
            .chain(s.inputs.iter().map(|x| (&x.name, &x.unit)))
            .chain(s.parameters.iter().map(|(n, x)| (n, &x.unit)))
            .find(|(n, _)| *n == name)
            .map_or("", |(_, u)| u.as_str())
    }

    /// The names of the equations `identify` fits (identifiable, with candidates).
    pub fn identifiable(&self) -> Vec<String> {
        self.equations
            .iter()
            .filter(|e| e.identify && !e.candidates.is_empty())
            .map(|e| e.name.clone())
            .collect()
    }

    /// An equation by name.
    pub fn equation(&self, name: &str) -> Option<&Equation> {
        self.equations.iter().find(|e| e.name == name)
    }

    /// Parameter values of the model file (their `value`s).
    pub fn parameter_values(&self) -> BTreeMap<String, f64> {
        self.spec.parameters.iter().map(|(n, p)| (n.clone(), p.value)).collect()
    }

    /// Per-run parameter rules for identification: `per_run` where given, else the value.
    pub fn parameter_rules(&self) -> BTreeMap<String, ParamValue> {
        self.spec
            .parameters
            .iter()
            .map(|(n, p)| {
                let v = match &p.per_run {
                    Some(rule) => ParamValue::Rule(rule.clone()),
                    None => ParamValue::Value(p.value),
                };
                (n.clone(), v)
            })
            .collect()
    }

    /// Compiles every equation's right-hand side into one evaluator (one output per equation).
    pub fn compile_rhs(&self, with_intercept: bool) -> Result<Library, TermError> {
        let rhs = self.equations.iter().map(|e| e.rhs(with_intercept)).collect::<Result<Vec<_>, _>>()?;
        Library::compile(&rhs, &self.vocabulary)
    }

    /// Adds `term` to `equation`'s candidates (a term found beyond them: re-identifying the
    /// model written keeps it among what it selects from); nothing where it is one already.
    pub fn add_candidate(&mut self, equation: &str, term: Term) {
        let text = term.to_string();
        if let Some(eq) = self.equations.iter_mut().find(|e| e.name == equation) {
            if eq.candidates.contains(&term) {
                return;
            }
            eq.candidates.push(term);
        }
        if let Some(spec) = self.spec.equations.get_mut(equation) {
            spec.candidates.push(text);
        }
    }

    /// Replaces an equation's coefficients (e.g. with an identification's result).
    pub fn set_coefficients(
        &mut self,
        equation: &str,
        coefficients: Vec<(Term, f64, Option<f64>)>,
        intercept: Option<f64>,
    ) {
        if let Some(eq) = self.equations.iter_mut().find(|e| e.name == equation) {
            eq.coefficients = coefficients;
            eq.intercept = intercept;
            // a covariance belongs to the coefficients it was estimated with
            eq.covariance = None;
        }
        if let Some(spec) = self.spec.equations.get_mut(equation) {
            let eq = self.equations.iter().find(|e| e.name == equation).expect("same names");
            spec.coefficients = eq
                .coefficients
                .iter()
                .map(|(t, v, se)| {
                    let c = match se {
                        Some(s) => CoefficientSpec::WithError { value: *v, std_error: *s },
                        None => CoefficientSpec::Value(*v),
                    };
                    (t.to_string(), c)
                })
                .collect();
            spec.intercept = intercept;
            spec.covariance = None;
        }
    }

    /// The model with its runs' spikes kept as recorded where `keep` (a command line's
    /// `--keep-spikes`), else as its file says.
    pub fn keeping_spikes(mut self, keep: bool) -> Model {
        self.spec.model.keep_spikes |= keep;
        self
    }

    /// The inputs that act late, each with its dead time in seconds (`delay` in its
    /// `[[inputs]]` entry, where above 0).
    pub fn dead_times(&self) -> Vec<(&str, f64)> {
        self.spec.inputs.iter().filter(|i| i.delay > 0.0).map(|i| (i.name.as_str(), i.delay)).collect()
    }

    /// The inputs that act through a first-order lag, each with its time constant in seconds
    /// (`lag` in its `[[inputs]]` entry, where above 0).
    pub fn first_order_lags(&self) -> Vec<(&str, f64)> {
        self.spec.inputs.iter().filter(|i| i.lag > 0.0).map(|i| (i.name.as_str(), i.lag)).collect()
    }

    /// Runs as the model's equations see them: each input with a dead time (`delay` in its
    /// `[[inputs]]` entry) read that much earlier against the rest, every run from its
    /// longest delay on ([`crate::data::delayed`]), and then each with a first-order lag (`lag`)
    /// read through it, from five of the slowest lag's time constants on
    /// ([`crate::data::lagged`]); the runs themselves where none has either.
    pub fn acting<'a>(
        &self,
        frames: &'a [crate::data::Frame],
    ) -> Result<std::borrow::Cow<'a, [crate::data::Frame]>, crate::data::DataError> {
        let (late, lags) = (self.dead_times(), self.first_order_lags());
        if late.is_empty() && lags.is_empty() {
            return Ok(std::borrow::Cow::Borrowed(frames));
        }
        let longest = late.iter().map(|(_, d)| *d).fold(0.0, f64::max);
        let mut out = frames.to_vec();
        for f in &mut out {
            for (name, delay) in &late {
                if f.column(name).is_some() {
                    *f = crate::data::delayed(f, name, *delay, longest)?;
                }
            }
            // (each from the run's start, where a lag's start at rest is put, every run from
            // five of the slowest lag's time constants on, whatever its own inputs)
            let slowest = lags.iter().map(|(_, t)| *t).fold(0.0, f64::max);
            let own: Vec<(&str, f64)> = lags.iter().copied().filter(|(n, _)| f.column(n).is_some()).collect();
            *f = crate::data::lagged(f, &own, crate::data::SETTLED * slowest)?;
        }
        Ok(std::borrow::Cow::Owned(out))
    }

    /// The model fed as [`Model::acting`] reads `frames`: its inputs' dead times and lags taken
    /// out of the model and put in the runs, each run from its longest dead time (and five of
    /// its slowest lag's time constants) on. Re-simulated so,
    /// a run starts where every input's history is recorded (fed from the run's start, an input
    /// acting 0.5 s late is guessed at its first value for 0.5 s).
    pub fn as_acting<'a>(
        &'a self,
        frames: &'a [crate::data::Frame],
    ) -> Result<
        (std::borrow::Cow<'a, Model>, std::borrow::Cow<'a, [crate::data::Frame]>),
        crate::data::DataError,
    > {
        let frames = self.acting(frames)?;
        if matches!(frames, std::borrow::Cow::Borrowed(_)) {
            return Ok((std::borrow::Cow::Borrowed(self), frames));
        }
        let mut model = self.clone();
        model.spec.inputs.iter_mut().for_each(|i| (i.delay, i.lag) = (0.0, 0.0));
        Ok((std::borrow::Cow::Owned(model), frames))
    }

    /// The model with its runs' inputs taken between samples as `intersample` says where
    /// given (a command line's `--intersample`), else as its file says.
    pub fn with_intersample(mut self, intersample: Option<crate::data::Intersample>) -> Model {
        if let Some(i) = intersample {
            self.spec.model.intersample = i;
        }
        self
    }

    /// Makes a measured run fit for this model, the checks every caller of a model needs (the
    /// CLI, the Python package): a plain file's ASCII column names that are the model's aliases
    /// (`delta`, `psi`) are read as the names they stand for, an input declared in rad that
    /// goes beyond a full turn is refused (it can only be degrees), and the run must agree with
    /// the model's known kinematics ([`Model::check_kinematics`]); a run whose samples are not
    /// evenly spaced (a dropped sample) is resampled onto its median step, as a re-simulation
    /// compares it sample by sample ([`crate::data::evened`]), and a state in rad that wraps at
    /// a full turn (a compass's 359° → 0°) is made one continuous angle
    /// ([`crate::data::unwrapped`]); a spike in a variable's record (a sample or three that leap
    /// away and straight back) is replaced by the line through its neighbours
    /// ([`crate::data::despiked`]) unless the file says `keep_spikes`; an input that stays put
    /// between samples and jumps at isolated ones is marked held ([`crate::data::mark_held`],
    /// as the file's `intersample` says), and a column that repeats a slower sensor's readings
    /// between them is read at its readings ([`crate::data::read_at_readings`]). Returns what
    /// was renamed, resampled, unwrapped, marked, re-read or mended, for the caller to say.
    /// Records joined in one run are cut into runs after, over all runs
    /// ([`Model::cut_at_breaks`]: one run may become several).
    pub fn admit(&self, frame: &mut crate::data::Frame) -> Result<Vec<String>, crate::data::DataError> {
        let admitted = self.admitted(frame)?;
        Ok(admitted.notes.into_iter().chain(admitted.spikes).collect())
    }

    /// Admitted runs ([`Model::admit`]) cut where a recorded state leaps at one sample and stays
    /// ([`crate::data::cut_at_breaks`]: records joined in one file, a sensor re-zeroed), and
    /// around the stretches where one rests pinned at an end of its range
    /// ([`crate::data::cut_at_clips`]: a sensor clipped at full scale), each piece a run of its
    /// own, with what to say (an input that leaps alone is a step of it).
    pub fn cut_at_breaks(
        &self,
        frames: Vec<crate::data::Frame>,
    ) -> Result<(Vec<crate::data::Frame>, Vec<String>), crate::data::DataError> {
        let (states, inputs) = self.recorded_motion();
        let (mut out, mut notes) = (Vec::new(), Vec::new());
        for frame in frames {
            let (pieces, said) = crate::data::cut_at_breaks(frame, &states, &inputs)?;
            notes.extend(said);
            for piece in pieces {
                let (pieces, said) = crate::data::cut_at_clips(piece, &states)?;
                out.extend(pieces);
                notes.extend(said);
            }
        }
        Ok((out, notes))
    }

    /// The runs with each state the model declares the rate of another (`rate_of`: a velocity
    /// beside a position measured alone) estimated where a run does not record it: the rate of
    /// the other state's record by the Kalman smoother ([`crate::data::KalmanSmoother`], its
    /// noise ratio by maximum likelihood), whose white-jerk model follows a motion's turns
    /// without the end effects of a spline's (a twentieth of the spline's error at the first
    /// sample of a damped oscillator read with 1 % noise). Each run whole, after its cuts
    /// ([`Model::cut_at_breaks`]): a leap across a break would be a rate. With what to say.
    pub fn estimated_rates(
        &self,
        mut frames: Vec<crate::data::Frame>,
    ) -> Result<(Vec<crate::data::Frame>, Vec<String>), crate::data::DataError> {
        let rates: Vec<(&str, &str)> =
            self.spec.states.iter().filter_map(|s| Some((s.name.as_str(), s.rate_of.as_deref()?))).collect();
        let mut estimated = vec![0; rates.len()];
        let mut trimmed = 0;
        for frame in &mut frames {
            let mut found = Vec::new();
            for (k, &(name, of)) in rates.iter().enumerate() {
                if frame.column(name).is_some() {
                    continue;
                }
                let x = frame.require(of)?;
                let (rate, errors) = crate::data::KalmanSmoother::default()
                    .rate_with_errors(frame.time(), x)
                    .map_err(|e| e.in_run(frame.origin(), Some(of)))?;
                found.push((name, rate, errors));
                estimated[k] += 1;
            }
            // the smoother sees one side only at a run's ends, its rate there up to four times
            // as uncertain: those rows are left out (a run cut around a pinned sensor has
            // many ends, which chose u·x² and put x's coefficient 2.9 % off at 1 % noise)
            if found.is_empty() {
                continue;
            }
            let rows = frame.len();
            let (mut first, mut last) = (0, rows - 1);
            for (_, _, errors) in &found {
                let (a, b) = settled(errors);
                (first, last) = (first.max(a), last.min(b));
            }
            if first >= last {
                (first, last) = (0, rows - 1);
            }
            if first > 0 || last + 1 < rows {
                *frame = frame.slice(first..last + 1);
                trimmed += first + (rows - 1 - last);
            }
            for (name, rate, errors) in found {
                let kept = &errors[first..=last];
                let error = (kept.iter().map(|e| e * e).sum::<f64>() / kept.len() as f64).sqrt();
                frame.push_estimated(name, rate[first..=last].to_vec(), error)?;
            }
        }
        let mut notes = Vec::new();
        for (&(name, of), &count) in rates.iter().zip(&estimated).filter(|(_, &c)| c > 0) {
            notes.push(format!(
                "`{name}` is not recorded: estimated as `{of}`'s rate in {count} of {} run(s) by a Kalman smoother \
                 (white jerk, its noise ratio by maximum likelihood); d{of}/dt = {name} is kinematics, and the checks \
                 compare re-simulations with the recorded states alone",
                frames.len(),
            ));
        }
        if trimmed > 0 {
            notes.push(format!(
                "{trimmed} row(s) at the runs' ends left out, where an estimated rate's standard error is over {ENDS} times its median (the smoother sees one side only there)"
            ));
        }
        Ok((frames, notes))
    }

    /// The states a run's column of which may be estimated rather than recorded
    /// ([`Model::estimated_rates`]): a re-simulation is not judged by them.
    pub fn estimated_states(&self) -> Vec<&str> {
        self.spec.states.iter().filter(|s| s.rate_of.is_some()).map(|s| s.name.as_str()).collect()
    }

    /// The columns of a run that record a motion: the states, and the inputs.
    pub fn recorded_motion(&self) -> (Vec<&str>, Vec<&str>) {
        (
            self.spec.states.iter().map(|s| s.name.as_str()).collect(),
            self.spec.inputs.iter().map(|i| i.name.as_str()).collect(),
        )
    }

    /// [`Model::admit`], the spikes mended said apart (a streamed chunk's are its own, where
    /// the rest every chunk would repeat).
    pub fn admitted(&self, frame: &mut crate::data::Frame) -> Result<Admitted, crate::data::DataError> {
        let mut notes = Vec::new();
        notes.extend(
            frame
                .time()
                .first()
                .and_then(|&first| crate::data::epoch_note(frame.origin(), frame.time_name(), first)),
        );
        if let Some((even, note)) = crate::data::evened(frame)? {
            *frame = even;
            notes.push(note);
        }
        for (alias, name) in &self.spec.aliases {
            if frame.column(alias).is_some() && frame.column(name).is_none() {
                frame.rename(alias, name)?;
                notes.push(format!(
                    "{}: column `{alias}` read as `{name}` (an alias of the model)",
                    frame.origin()
                ));
            }
        }
        // a heading recorded as a compass reads it (0-360°, or atan2's ±180°) wraps where the
        // model's angle turns on
        let angles: Vec<&str> =
            self.spec.states.iter().filter(|s| s.unit == "rad").map(|s| s.name.as_str()).collect();
        if let Some((whole, said)) = crate::data::unwrapped(frame, &angles)? {
            *frame = whole;
            notes.extend(said);
        }
        // so does any column of unknown units that reads like an angle on a dial (a pendulum
        // over the top by atan2, a wind direction): a polynomial of it, its rate, would see
        // a full turn's leap at every wrap
        let unknown: Vec<&str> = (self.spec.states.iter().map(|s| (&s.name, &s.unit)))
            .chain(self.spec.inputs.iter().map(|i| (&i.name, &i.unit)))
            .filter(|(_, unit)| unit.is_empty())
            .map(|(name, _)| name.as_str())
            .collect();
        if let Some((whole, said)) = crate::data::unwrapped_dials(frame, &unknown)? {
            *frame = whole;
            notes.extend(said);
        }
        let mut spikes = Vec::new();
        if !self.spec.model.keep_spikes {
            let rates: Vec<String> = self.spec.states.iter().map(|s| format!("{}_dot", s.name)).collect();
            let columns: Vec<&str> =
                self.vocabulary.variables().iter().chain(&rates).map(String::as_str).collect();
            if let Some((mended, said)) = crate::data::despiked(frame, &columns)? {
                *frame = mended;
                spikes = said;
            }
        }
        let inputs: Vec<&str> = self.spec.inputs.iter().map(|i| i.name.as_str()).collect();
        let states: Vec<&str> = self.spec.states.iter().map(|s| s.name.as_str()).collect();
        // an input with a dead time judged as the equations read it, that much late; one with a
        // lag by its record
        let late = self.dead_times();
        notes.extend(crate::data::mark_held_acting(
            frame,
            &inputs,
            &late,
            &self.first_order_lags(),
            &states,
            self.spec.model.intersample,
        )?);
        // a state, its rate or an input (not a held command) that repeats a slower sensor's
        // readings between them is read at them
        let rates: Vec<String> = self.spec.states.iter().map(|s| format!("{}_dot", s.name)).collect();
        let columns: Vec<&str> = self
            .vocabulary
            .variables()
            .iter()
            .chain(&rates)
            .map(String::as_str)
            .chain(inputs.iter().copied())
            .collect();
        notes.extend(crate::data::read_at_readings(frame, &columns, self.spec.model.intersample)?);
        for input in self.spec.inputs.iter().filter(|i| i.unit == "rad") {
            let beyond = frame
                .column(&input.name)
                .and_then(|c| c.iter().enumerate().find(|(_, v)| v.abs() > 2.0 * std::f64::consts::PI));
            if let Some((row, v)) = beyond {
                return Err(crate::data::DataError::Unit {
                    file: frame.origin().into(),
                    row: row + 1,
                    column: input.name.clone(),
                    message: format!(
                        "{v} is beyond a full turn, but {} declares `{}` in rad: that can only be degrees; give radians, or map the file with a dataset file (--dataset) that declares the column [deg]",
                        self.path, input.name
                    ),
                });
            }
        }
        self.check_kinematics(frame)?;
        Ok(Admitted { notes, spikes })
    }

    /// Checks measured runs against the model's known kinematics: where an equation that is
    /// not identified says ẋ = c·y for a state x and a variable y (ψ̇ = r), the run's own dx/dt
    /// must match c·y. A ratio near π/180 or 180/π means one of the two columns is in degrees
    /// where radians were declared (or assumed), which would otherwise pass silently and
    /// give coefficients in mixed units.
    pub fn check_kinematics(&self, frame: &crate::data::Frame) -> Result<(), crate::data::DataError> {
        for eq in self.equations.iter().filter(|e| !e.identify && e.coefficients.len() == 1) {
            let (term, c, _) = &eq.coefficients[0];
            let names = term.variables();
            let [y] = names.as_slice() else { continue };
            if *term != Term::var(y) || *c == 0.0 {
                continue;
            }
            let (Some(x), Some(yv)) = (frame.column(&eq.state), frame.column(y)) else { continue };
            let t = frame.time();
            if t.len() < 3 {
                continue;
            }
            // central differences against c·y at the inner samples: k = Σ ẋ·cy / Σ (cy)²
            let (mut num, mut den) = (0.0, 0.0);
            for i in 1..t.len() - 1 {
                let dx = (x[i + 1] - x[i - 1]) / (t[i + 1] - t[i - 1]);
                let cy = c * yv[i];
                num += dx * cy;
                den += cy * cy;
            }
            if !(den > 0.0 && num.is_finite()) {
                continue;
            }
            let k = num / den;
            let degree = 180.0 / std::f64::consts::PI;
            let near = |target: f64| (k / target - 1.0).abs() < 0.3;
            let time = &self.spec.model.time;
            // a time column in other units scales every rate alike: minutes (×60) sit close to
            // the degree's 57.3, so a ratio that matches 60 better, and closely, is minutes
            let close = |target: f64| (k / target - 1.0).abs();
            let message = if close(60.0) < 0.02 && close(60.0) < close(degree) {
                format!("`{}` rises {k:.2} × as fast as `{y}` says ({} = {c}·{y}): the time column `{time}` looks like minutes; give it in seconds", eq.state, eq.name)
            } else if close(3600.0) < 0.05 {
                format!("`{}` rises {k:.0} × as fast as `{y}` says ({} = {c}·{y}): the time column `{time}` looks like hours; give it in seconds", eq.state, eq.name)
            } else if close(1e-3) < 0.05 {
                format!("`{}` rises {k:.5} × as fast as `{y}` says ({} = {c}·{y}): the time column `{time}` looks like milliseconds; give it in seconds", eq.state, eq.name)
            } else if close(1e-3 / degree) < 0.05 || close(1e-3 * degree) < 0.05 {
                format!("`{}` rises {k:.3e} × as fast as `{y}` says ({} = {c}·{y}): the time column `{time}` looks like milliseconds and one of the angles like degrees; give seconds and radians", eq.state, eq.name)
            } else if near(1.0 / degree) {
                format!("`{}` rises {k:.4} × as fast as `{y}` says ({} = {c}·{y}): `{y}` looks like degrees (per s) where `{}` is in radians; give both in radians (a dataset file converts: [deg/s])", eq.state, eq.name, eq.state)
            } else if near(degree) {
                format!("`{}` rises {k:.1} × as fast as `{y}` says ({} = {c}·{y}): `{}` looks like degrees where `{y}` is in radians; give both in radians (a dataset file converts: [deg])", eq.state, eq.name, eq.state)
            } else {
                continue;
            };
            return Err(crate::data::DataError::Unit {
                file: frame.origin().into(),
                row: 0,
                column: y.clone(),
                message,
            });
        }
        Ok(())
    }

    /// The names a data column may carry for this model: its states, inputs, parameters,
    /// derived variables and aliases, and `<state>_dot` for measured rates.
    pub fn data_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.vocabulary.variables().to_vec();
        names.extend(self.vocabulary.parameters().iter().cloned());
        names.extend(self.spec.derived.iter().map(|d| d.name.clone()));
        names.extend(self.spec.aliases.keys().cloned());
        names.extend(self.spec.states.iter().map(|s| format!("{}_dot", s.name)));
        names.push(self.spec.model.time.clone());
        names
    }

    /// The model as TOML text (what `identify --out` writes and `simulate` reads back).
    pub fn to_toml(&self) -> String {
        let body =
            toml::to_string_pretty(&self.spec).unwrap_or_else(|e| format!("# could not serialise: {e}\n"));
        format!("# written by termid {}\n{body}", env!("CARGO_PKG_VERSION"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DECAY: &str = r#"
[model]
name = "decay"
[[states]]
name = "x"
[equations.x_dot]
state = "x"
candidates = ["x", "x^2"]
coefficients = { "x" = -0.5 }
[vehicle]
mass = 2.0
"#;

    #[test]
    fn plug_in_tables_are_kept_as_data_and_written_back() {
        let m = Model::parse(DECAY, "decay.toml").unwrap();
        assert_eq!(m.spec.plugins["vehicle"]["mass"].as_float(), Some(2.0));
        let again = Model::parse(&m.to_toml(), "again.toml").unwrap();
        assert_eq!(again.spec, m.spec);
        assert_eq!(m.equation("x_dot").unwrap().candidates.len(), 2);
    }

    /// A velocity of the medium is held in the file and freed for one estimate; the model
    /// written keeps the file's word on which parameters are free.
    #[test]
    fn an_estimate_frees_and_holds_parameters_for_itself_alone() {
        let text = format!(
            "{DECAY}[parameters.a]\nvalue = 1.0\nfree = true\n[parameters.c]\nvalue = 0.0\nunit = \"m/s\"\nnuisance = \"source\"\nmedium = true\n[parameters.k]\nvalue = 2.0\nper_run = \"first:x\"\n"
        );
        let file = Model::parse(&text, "decay.toml").unwrap();
        assert_eq!(file.held_medium(), ["c"]);
        let names = |m: &Model| m.free_parameters().into_iter().map(|p| p.name).collect::<Vec<_>>();
        let one = file.freed(&["c".into()], &["a".into()]).unwrap();
        assert_eq!(names(&one), ["c"]);
        assert_eq!(one.free_parameters()[0].nuisance, Some(Nuisance::Source));
        assert!(one.held_medium().is_empty());
        // runs tracked over ground free the medium unless held
        let (over, freed) = file.freed_over_ground(&[], &[], true).unwrap();
        assert_eq!((names(&over), freed), (vec!["a".to_string(), "c".to_string()], vec!["c".to_string()]));
        let (held, freed) = file.freed_over_ground(&[], &["c".into()], true).unwrap();
        assert_eq!((names(&held), freed.len()), (vec!["a".to_string()], 0));
        let mut estimated = one.clone();
        estimated.set_parameter("c", 0.3);
        let written = file.as_declared(&estimated);
        assert_eq!(names(&written), ["a"]);
        assert_eq!(written.parameter_values()["c"], 0.0);
        for (free, hold, says) in [
            (&["x"][..], &[][..], "no parameter `x`"),
            (&["k"], &[], "no parameter `k` that one estimate can stand for"),
            (&["c"], &["c"], "both to be freed and held"),
            (&[], &["x"], "no parameter `x`"),
        ] {
            let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
            let e = file.freed(&strings(free), &strings(hold)).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn a_top_level_value_that_is_no_table_is_refused_with_its_line() {
        let text = format!("mass = 2.0\n{DECAY}");
        let e = Model::parse(&text, "decay.toml").unwrap_err().to_string();
        assert!(e.starts_with("decay.toml:1: `mass`: not a key"), "{e}");
    }
}
