//! `termid.Model`: a model file read, written, simulated, identified, estimated and
//! diagnosed from runs handed over as numpy columns.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use termid::data::{differentiator, Frame};
use termid::identify::{EquationMoments, ModelIdentification};
use termid::model::Model;
use termid::select::Backend;
use termid::sim::{Settings, System, Trajectory};
use termid::term::parse_terms;

use crate::convert::{
    arrays, backend_of, fail, frame_columns, frame_of, method_of, refuse, to_json, trajectory_columns, warn,
    Run,
};
use crate::moments::PyMoments;

/// The repository's model files, inside the extension (no data files to install or find).
const BUILTIN: [(&str, &str); 7] = [
    ("oltmann1973", include_str!("../../models/oltmann1973.toml")),
    ("lorenz", include_str!("../../models/lorenz.toml")),
    ("duffing", include_str!("../../models/duffing.toml")),
    ("mmg_kvlcc2", include_str!("../../models/mmg_kvlcc2.toml")),
    ("new_ship", include_str!("../../models/new_ship.toml")),
    ("nomoto", include_str!("../../models/nomoto.toml")),
    ("robertson", include_str!("../../models/robertson.toml")),
];

/// Each identified equation's fit report (name, JSON).
type Fits = Vec<(String, String)>;

/// A model file: states, inputs, parameters and equations, as termid reads and writes it.
#[pyclass(module = "termid._termid", name = "Model")]
#[derive(Clone)]
pub(crate) struct PyModel {
    pub(crate) inner: Model,
}

impl PyModel {
    /// Runs as frames over the model's time column, each admitted by the model (aliases,
    /// units, kinematics); the notes say what was renamed.
    fn frames(&self, runs: Vec<Run<'_>>) -> PyResult<Vec<Frame>> {
        let time = &self.inner.spec().model.time;
        let mut frames = runs
            .iter()
            .map(|(origin, columns)| frame_of(origin, time, columns))
            .collect::<PyResult<Vec<_>>>()?;
        let Some((_, first)) = runs.first() else {
            return Err(refuse("no runs: give at least one"));
        };
        // the runs are Rust's from here: admitted (a search of every column) with the GIL free
        let mut notes = first
            .py()
            .detach(|| -> Result<Vec<String>, termid::data::DataError> {
                let mut notes = Vec::new();
                // a logger's dropout: each piece a run, as the command line cuts a file it reads
                let mut pieces = Vec::new();
                for frame in std::mem::take(&mut frames) {
                    let (cut, said) = termid::data::cut_at_gaps(frame, 0)?;
                    pieces.extend(cut);
                    notes.extend(said);
                }
                frames = pieces;
                for frame in &mut frames {
                    notes.extend(self.inner.admit(frame)?);
                }
                let (cut, more) = self.inner.cut_at_breaks(std::mem::take(&mut frames))?;
                notes.extend(more);
                let (estimated, more) = self.inner.estimated_rates(cut)?;
                frames = estimated;
                notes.extend(more);
                Ok(notes)
            })
            .map_err(fail)?;
        for (name, rule) in self.inner.parameter_rules() {
            if let Some(first) = frames.iter().find_map(|f| rule.noisy_first_sample(&name, f)) {
                notes.push(first);
            }
        }
        // what the command line says on standard error, a notebook shows as warnings
        let py = first.py();
        for note in notes {
            warn(py, note)?;
        }
        Ok(frames)
    }
}

impl PyModel {
    /// Runs re-simulated from their recorded initial states with their recorded inputs:
    /// the runs, their comparison and the simulations (replay, validate).
    fn resimulate(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
    ) -> PyResult<(Vec<Frame>, termid::diagnose::Runs, Vec<Trajectory>)> {
        let (frames, data) = self.replayable(runs, dt, integrator, with_intercept)?;
        let sims = py.detach(|| data.simulate(&self.inner, &[], &[])).map_err(fail)?;
        Ok((frames, data, sims))
    }

    /// `data` with each run in the velocity of the medium it moved in (a sea trial's current,
    /// the model's held `medium` parameters estimated alone from the runs, the model held),
    /// where `over_ground`; the estimates (JSON list: name, source, value, std_error; null
    /// where none).
    fn in_medium(
        &self,
        py: Python<'_>,
        frames: &[Frame],
        data: termid::diagnose::Runs,
        over_ground: bool,
    ) -> PyResult<(termid::diagnose::Runs, serde_json::Value)> {
        if !over_ground {
            return Ok((data, serde_json::Value::Null));
        }
        let names = self.inner.held_medium();
        let sources = vec![0; frames.len()];
        match py.detach(|| termid::diagnose::medium(&self.inner, &names, frames, &sources)).map_err(fail)? {
            Some(day) => {
                let values = serde_json::to_value(&day.per_source)
                    .map_err(|e| refuse(format!("could not serialise: {e}")))?;
                Ok((data.with_initial(&[], &day.own_values()), values))
            }
            None => Ok((data, serde_json::Value::Null)),
        }
    }

    /// Refused where the model stores no covariance to draw models from.
    fn drawable(&self) -> PyResult<()> {
        if termid::uncertainty::uncertain_equations(&self.inner).is_empty() {
            return Err(refuse(format!(
                "{}: nothing to draw from: the model stores no covariance (`identify` with --out, a refinement or `estimate` write one)",
                self.inner.path
            )));
        }
        Ok(())
    }

    /// The runs read, and ready to be re-simulated by this model's method (or `integrator`).
    fn replayable(
        &self,
        runs: Vec<Run<'_>>,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
    ) -> PyResult<(Vec<Frame>, termid::diagnose::Runs)> {
        let frames = self.frames(runs)?;
        let (integrator, dt) = method_of(&self.inner, integrator, dt, &frames)?;
        let data = termid::diagnose::Runs::new(&self.inner, &frames, dt, integrator)
            .map_err(fail)?
            .with_intercepts(with_intercept);
        Ok((frames, data))
    }
}

impl PyModel {
    /// A model read from a file or text, with what the command line says as it loads one (a
    /// rate declared per hour, read per second) warned of, as a notebook shows it.
    fn loaded(py: Python<'_>, inner: termid::model::Model) -> PyResult<Self> {
        for note in inner.load_notes() {
            warn(py, note)?;
        }
        Ok(PyModel { inner })
    }
}

#[pymethods]
impl PyModel {
    /// Reads a model file (TOML); errors name the file, line and key.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        PyModel::loaded(py, termid::plugins::load(&path).map_err(fail)?)
    }

    /// A model from TOML text; `name` stands for the file in messages.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<text>"))]
    fn parse(py: Python<'_>, text: &str, name: &str) -> PyResult<Self> {
        PyModel::loaded(py, termid::plugins::parse(text, name).map_err(fail)?)
    }

    /// The default model: Oltmann's (1973) HSVA 1512 with its Table 2 coefficients.
    #[staticmethod]
    fn default_model() -> Self {
        PyModel { inner: termid::plugins::default_model() }
    }

    /// A model file shipped inside the package, by name (`termid.Model.builtin_names()`).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        let Some((_, text)) = BUILTIN.iter().find(|(n, _)| *n == name) else {
            let names: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
            return Err(refuse(format!("no built-in model `{name}` (there are: {})", names.join(", "))));
        };
        Ok(PyModel { inner: termid::plugins::parse(text, &format!("{name}.toml")).map_err(fail)? })
    }

    /// A grey-box MMG model for a ship from its main particulars (`text` a particulars file's
    /// TOML, or JSON where `json`; `name` stands for it in messages), with each parameter's
    /// estimate (JSON list: name, value, prior_sd (null where fixed), unit, source) and the
    /// cautions where the proportions are unusual.
    #[staticmethod]
    #[pyo3(signature = (text, json = false, name = "<particulars>"))]
    fn from_particulars(text: &str, json: bool, name: &str) -> PyResult<(Self, String, Vec<String>)> {
        use termid::ship::particulars::Particulars;
        let particulars = if json {
            serde_json::from_str::<Particulars>(text).map_err(|e| refuse(format!("{name}: {e}")))?
        } else {
            Particulars::parse(text, name).map_err(fail)?
        };
        let model = particulars.model().map_err(|e| refuse(format!("{name}: {e}")))?;
        let free = model.free_parameters();
        let estimates: Vec<serde_json::Value> = particulars
            .estimates()
            .iter()
            .map(|e| {
                let sd = free.iter().find(|p| p.name == e.name).and_then(|p| p.prior).map(|(_, sd)| sd);
                serde_json::json!({ "name": e.name, "value": e.value, "prior_sd": sd, "unit": e.unit, "source": e.source })
            })
            .collect();
        Ok((PyModel { inner: model }, to_json(&estimates)?, particulars.cautions()))
    }

    /// The model of a system named by its columns (`termid::model::Outline`): an equation
    /// for each state's rate over the same `candidates`, or every monomial of the states and
    /// inputs to `degree` where none is named.
    #[staticmethod]
    #[pyo3(signature = (states, inputs, candidates, degree, time, name))]
    fn from_states(
        states: Vec<String>,
        inputs: Vec<String>,
        candidates: Vec<String>,
        degree: Option<u32>,
        time: String,
        name: String,
    ) -> PyResult<Self> {
        if degree.is_some() && !candidates.is_empty() {
            return Err(refuse(
                "Model.from_states: a degree is the polynomial library's, and the candidates are named (terms=...)",
            ));
        }
        let degree = degree.unwrap_or(termid::model::DEFAULT_DEGREE);
        let (states, rates) = termid::model::Outline::states_named(&states);
        let outline =
            termid::model::Outline { name, time, states, rates, inputs, candidates, degree, backend: None };
        let model = outline.model("Model.from_states").map_err(fail)?;
        Ok(PyModel { inner: model })
    }

    /// The model made from columns with its library written about the runs' reference values
    /// where they hold a variable far from 0 (`termid::model::Model::about_references`), and
    /// the sentence that says so (none where there is nothing to write anew); decided either way.
    fn about_references(&self, runs: Vec<Run<'_>>) -> PyResult<(PyModel, Option<String>)> {
        let frames = self.frames(runs)?;
        let (model, note) = self.inner.about_references(&frames).map_err(fail)?;
        Ok((PyModel { inner: model }, note))
    }

    /// The outline the model was made from (JSON), while its library may still be written
    /// about the runs' reference values; pickling keeps it.
    fn outline_json(&self) -> PyResult<Option<String>> {
        self.inner.outline().map(|o| serde_json::to_string(o).map_err(fail)).transpose()
    }

    /// The model with the outline `json` ([`PyModel::outline_json`]) it was made from.
    fn with_outline(&self, json: &str) -> PyResult<PyModel> {
        let outline: termid::model::Outline = serde_json::from_str(json).map_err(fail)?;
        Ok(PyModel { inner: self.inner.clone().with_outline(outline) })
    }

    /// The names of the model files shipped inside the package.
    #[staticmethod]
    fn builtin_names() -> Vec<&'static str> {
        BUILTIN.iter().map(|(n, _)| *n).collect()
    }

    fn to_toml(&self) -> String {
        self.inner.to_toml()
    }

    /// Writes the model file (atomically: a file that cannot be written loses nothing).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        termid::output::write_file(&path, self.inner.to_toml().as_bytes()).map_err(fail)
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.spec().model.name.clone()
    }

    #[getter]
    fn path(&self) -> String {
        self.inner.path.clone()
    }

    #[getter]
    fn time(&self) -> String {
        self.inner.spec().model.time.clone()
    }

    #[getter]
    fn states(&self) -> Vec<String> {
        self.inner.spec().states.iter().map(|s| s.name.clone()).collect()
    }

    /// The states' initial values (`[[states]] initial`), by name.
    #[getter]
    fn initial(&self) -> BTreeMap<String, f64> {
        self.inner.spec().states.iter().map(|s| (s.name.clone(), s.initial)).collect()
    }

    #[getter]
    fn inputs(&self) -> Vec<String> {
        self.inner.spec().inputs.iter().map(|s| s.name.clone()).collect()
    }

    #[getter]
    fn equations(&self) -> Vec<String> {
        self.inner.equations().iter().map(|e| e.name.clone()).collect()
    }

    #[getter]
    fn identifiable(&self) -> Vec<String> {
        self.inner.identifiable()
    }

    /// An equation's candidate terms, as the file spells them.
    fn candidates(&self, equation: &str) -> PyResult<Vec<String>> {
        let e = self.inner.equation(equation).ok_or_else(|| {
            refuse(format!("no equation `{equation}` (equations: {})", self.equations().join(", ")))
        })?;
        Ok(e.candidates.iter().map(|t| t.to_string()).collect())
    }

    #[getter]
    fn parameters(&self) -> BTreeMap<String, f64> {
        self.inner.parameter_values()
    }

    /// The parameters the file declares free (`estimate` fits them), in its order.
    #[getter]
    fn free_parameters(&self) -> Vec<String> {
        self.inner.free_parameters().into_iter().map(|p| p.name).collect()
    }

    /// The stored coefficients of an equation: (term, value, standard error).
    fn coefficients(&self, equation: &str) -> PyResult<Vec<(String, f64, Option<f64>)>> {
        let eq = self.inner.equation(equation).ok_or_else(|| {
            refuse(format!(
                "{}: no equation `{equation}` (equations: {})",
                self.inner.path,
                self.equations().join(", ")
            ))
        })?;
        Ok(eq.coefficients.iter().map(|(t, c, s)| (t.to_string(), *c, *s)).collect())
    }

    /// How a parameter is set in each run for identification (`first:u`, `mean:u:4`), or
    /// `None` for its fixed value; checked as a model file's `per_run` is.
    #[pyo3(signature = (name, rule))]
    fn set_per_run(&mut self, name: &str, rule: Option<String>) -> PyResult<()> {
        if !self.inner.spec().parameters.contains_key(name) {
            return Err(refuse(format!("{}: `{name}` is not a parameter", self.inner.path)));
        }
        self.inner = self
            .inner
            .edit(|spec| {
                if let Some(p) = spec.parameters.get_mut(name) {
                    p.per_run = rule;
                }
            })
            .map_err(fail)?;
        Ok(())
    }

    /// Replaces an equation's coefficients: (term text, value, standard error or None) in the
    /// model's term language, and the intercept b0 (simulated only when asked).
    #[pyo3(signature = (equation, coefficients, intercept = None))]
    fn set_coefficients(
        &mut self,
        equation: &str,
        coefficients: Vec<(String, f64, Option<f64>)>,
        intercept: Option<f64>,
    ) -> PyResult<()> {
        if self.inner.equation(equation).is_none() {
            return Err(refuse(format!(
                "{}: no equation `{equation}` (equations: {})",
                self.inner.path,
                self.equations().join(", ")
            )));
        }
        let texts: Vec<&String> = coefficients.iter().map(|(t, _, _)| t).collect();
        let terms = parse_terms(&texts, &self.inner.vocabulary).map_err(fail)?;
        if let Some((t, v, _)) = coefficients.iter().find(|(_, v, _)| !v.is_finite()) {
            return Err(refuse(format!("`{t}`: coefficient {v} is not finite")));
        }
        let values = terms.into_iter().zip(coefficients).map(|(t, (_, v, s))| (t, v, s)).collect();
        self.inner.set_coefficients(equation, values, intercept);
        Ok(())
    }

    fn intercept(&self, equation: &str) -> Option<f64> {
        self.inner.equation(equation).and_then(|e| e.intercept)
    }

    /// `n` models drawn from the stored covariances (seeded): each equation's coefficients
    /// and the free parameters, as `simulate --monte-carlo` draws them.
    fn draws(&self, n: usize, seed: u64) -> PyResult<Vec<PyModel>> {
        self.drawable()?;
        // a model in memory takes about seven times its file's length (measured: 55 kB for a
        // 7.6 kB file): n of them are refused before the first is drawn where they would not fit
        let each = 8.0 * self.inner.to_toml().len() as f64;
        termid::budget::check_bytes(
            n as f64 * each,
            || format!("{n} drawn models"),
            "draw fewer (a few hundred give a 90 % band), or draw them in batches",
        )
        .map_err(fail)?;
        let sampler = termid::uncertainty::Sampler::new(&self.inner);
        let mut normal = termid::uncertainty::Normal::new(seed);
        Ok((0..n).map(|_| PyModel { inner: sampler.draw(&mut normal) }).collect())
    }

    /// What the spread of a prediction comes from: each free parameter one sd up and down (the
    /// stored `[parameter_covariance]`), `predict` making the prediction's numbers of a model
    /// (a callable taking a model, returning JSON text; an exception counts as that
    /// parameter's failure). JSON: `effects` (each parameter's half changes) and
    /// `attribution` (each number's linearised sd and the share of its variance each
    /// parameter would remove); both empty without a covariance.
    fn spread_from(&self, predict: Bound<'_, PyAny>) -> PyResult<String> {
        let call = |m: &Model| -> Result<serde_json::Value, String> {
            let out = predict.call1((PyModel { inner: m.clone() },)).map_err(|e| e.to_string())?;
            let text: String = out.extract().map_err(|e: PyErr| e.to_string())?;
            serde_json::from_str(&text).map_err(|e| e.to_string())
        };
        let effects = termid::uncertainty::parameter_effects(&self.inner, call);
        let keys: std::collections::BTreeSet<&String> =
            effects.iter().flat_map(|e| e.effects.keys()).collect();
        let attribution: BTreeMap<&String, termid::uncertainty::Attribution> = keys
            .into_iter()
            .filter_map(|k| Some((k, termid::uncertainty::attribution(&self.inner, &effects, k)?)))
            .collect();
        to_json(&serde_json::json!({ "effects": effects, "attribution": attribution }))
    }

    /// Sets the adaptive method's tolerances where given; refused where no step control works
    /// with them.
    #[pyo3(signature = (rtol = None, atol = None))]
    fn set_tolerances(&mut self, rtol: Option<f64>, atol: Option<f64>) -> PyResult<()> {
        self.inner.set_tolerances(rtol, atol).map_err(|e| refuse(e.to_string()))
    }

    /// Sets a parameter, or a value of the plug-in's table (a ship's `u0`); unknown names are
    /// refused.
    fn set_parameter(&mut self, name: &str, value: f64) -> PyResult<()> {
        let mut known = self.inner.set_parameter(name, value);
        if let Some(plugin) = termid::plugins::of(&self.inner) {
            known |= plugin.set_parameter(&mut self.inner, name, value).map_err(fail)?;
        }
        if !known {
            return Err(refuse(format!("{}: `{name}` is not a parameter", self.inner.path)));
        }
        Ok(())
    }

    /// The defaults of `termid identify`: central differences for a plug-in's model (a ship,
    /// as the paper), the weak form for any other.
    fn default_derivative(&self) -> &'static str {
        termid::recipe::default_derivative(Some(&self.inner))
    }

    /// The recipe's derivative starts, smoothing and refined states (`None`: no refinement;
    /// empty: every state) where its caller names none: the model's field's, else any system's.
    fn recipe_defaults(&self) -> (Vec<String>, bool, Option<Vec<String>>) {
        let d = termid::recipe::RecipeDefaults::of(&self.inner);
        (d.derivatives, d.smooth, d.refine)
    }

    /// Every identifiable equation (or the named ones) from runs; returns the identified model
    /// and each fit as JSON. A model of no field's is identified as `termid identify --states`
    /// identifies it: by the library's recipe with one start, its stages (laws, a random force,
    /// dead times) as asked.
    #[pyo3(signature = (runs, derivative = None, equations = vec![], intercept = None, backend = None, laws = true, random_force = true, dead_times = true))]
    #[allow(clippy::too_many_arguments)]
    fn identify(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        derivative: Option<&str>,
        equations: Vec<String>,
        intercept: Option<bool>,
        backend: Option<&str>,
        laws: bool,
        random_force: bool,
        dead_times: bool,
    ) -> PyResult<(PyModel, Fits, String)> {
        // the defaults of `termid identify`: central differences for a plug-in's model (a
        // ship, as the paper), the weak form for any other; the model file's intercept
        let derivative = derivative.unwrap_or_else(|| self.default_derivative());
        let intercept = intercept.unwrap_or(self.inner.spec().model.intercept);
        let model = match backend {
            Some(json) => self.inner.with_backend(&backend_of(json)?).map_err(fail)?,
            None => self.inner.clone(),
        };
        let frames = self.frames(runs)?;
        // the work without the GIL: other Python threads run meanwhile
        let (identified, fits, checks) = match termid::plugins::of(&model) {
            // a field's model has its checks (`Model.checks`), which read more than the runs
            Some(_) => {
                let diff = differentiator(derivative).map_err(fail)?;
                let how =
                    ModelIdentification { equations, differentiator: diff.as_ref(), intercept, target: None };
                let identified = py
                    .detach(|| {
                        let mut identified =
                            termid::identify::identify_model(&model, &frames, &how, &mut |_| {})?;
                        termid::identify::say_late_inputs(&mut identified, &frames, diff.as_ref())?;
                        Ok::<_, termid::identify::IdentifyError>(identified)
                    })
                    .map_err(fail)?;
                (identified.model, identified.fits, vec![])
            }
            // any system: its equations must retrace the runs, its terms hold on each half of
            // them (chosen again by re-simulation where they lose their runs), its powers not
            // stand in for a law, its inputs read as they act
            None => {
                let settings = termid::recipe::RecipeSettings {
                    equations,
                    derivatives: vec![derivative.to_string()],
                    intercept,
                    laws,
                    random_force,
                    dead_times,
                    ..Default::default()
                };
                let mut recipe =
                    py.detach(|| termid::recipe::identify(&model, &frames, None, &settings)).map_err(fail)?;
                let kept = recipe.starts.swap_remove(recipe.kept);
                (kept.model, kept.fits, kept.checks)
            }
        };
        let fits =
            fits.iter().map(|(n, f)| Ok((n.clone(), to_json(&f.report())?))).collect::<PyResult<_>>()?;
        for c in checks.iter().filter(|c| !c.passed) {
            warn(py, c.line())?;
        }
        Ok((PyModel { inner: identified }, fits, to_json(&checks)?))
    }

    /// The model with `forced` terms entering first and `excluded` ones never, in every
    /// identified equation that has them among its candidates (`termid::model::Model::with_terms`).
    #[pyo3(signature = (forced, excluded))]
    fn with_terms(&self, forced: Vec<String>, excluded: Vec<String>) -> PyResult<PyModel> {
        let parse = |texts: &[String]| termid::term::parse_terms(texts, &self.inner.vocabulary).map_err(fail);
        let model = self.inner.with_terms(&parse(&forced)?, &parse(&excluded)?).map_err(fail)?;
        Ok(PyModel { inner: model })
    }

    /// The model with each state's initial value the run's first sample of it (a model made
    /// from columns: simulated from where its first run starts).
    fn starting_as(&self, run: Run<'_>) -> PyResult<PyModel> {
        let (origin, columns) = run;
        let frame = frame_of(&origin, &self.inner.spec().model.time, &columns)?;
        Ok(PyModel { inner: self.inner.starting_as(&frame).map_err(fail)? })
    }

    /// The sufficient statistics of each of `equations` over runs (mergeable, picklable); the
    /// runs are read once for all of them.
    #[pyo3(signature = (equations, runs, derivative = None))]
    pub(crate) fn moments(
        &self,
        py: Python<'_>,
        equations: Vec<String>,
        runs: Vec<Run<'_>>,
        derivative: Option<&str>,
    ) -> PyResult<Vec<PyMoments>> {
        let derivative = derivative.unwrap_or_else(|| self.default_derivative());
        let frames = self.frames(runs)?;
        let diff = differentiator(derivative).map_err(fail)?;
        let model = &self.inner;
        let all = py.detach(|| {
            equations
                .iter()
                .map(|eq| EquationMoments::of_runs(model, eq, &frames, diff.as_ref(), None))
                .collect::<Result<Vec<_>, _>>()
        });
        Ok(all.map_err(fail)?.into_iter().map(|inner| PyMoments { inner }).collect())
    }

    /// The model identified from statistics (merged per equation in the order given), with
    /// the checks statistics allow (a model of no field's: its terms on each half of the runs,
    /// the runs' noise), failed ones warned of.
    #[pyo3(signature = (moments, intercept = None))]
    fn identify_from_moments(
        &self,
        py: Python<'_>,
        moments: Vec<PyRef<'_, PyMoments>>,
        intercept: Option<bool>,
    ) -> PyResult<(PyModel, Fits, String)> {
        let intercept = intercept.unwrap_or(self.inner.spec().model.intercept);
        let parts = moments
            .iter()
            .enumerate()
            .map(|(k, m)| (format!("statistics {}", k + 1), m.inner.clone()))
            .collect();
        let model = &self.inner;
        let (identified, checks) = py
            .detach(|| {
                let merged = termid::identify::merged_by_equation(parts)?;
                let identified = termid::identify::identify_from_merged(model, &merged, intercept)?;
                let checks = match termid::plugins::of(&identified.model) {
                    Some(_) => vec![],
                    None => termid::recipe::moments_checks(&identified, &merged, model, intercept, &[]),
                };
                Ok::<_, termid::identify::IdentifyError>((identified, checks))
            })
            .map_err(fail)?;
        let fits = identified
            .fits
            .iter()
            .map(|(n, f)| Ok((n.clone(), to_json(&f.report())?)))
            .collect::<PyResult<_>>()?;
        for c in checks.iter().filter(|c| !c.passed) {
            warn(py, c.line())?;
        }
        Ok((PyModel { inner: identified.model }, fits, to_json(&checks)?))
    }

    /// ẋ of every state on every row of a run (the identified equations' one-step prediction).
    #[pyo3(signature = (run, with_intercept = false))]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        run: Run<'py>,
        with_intercept: bool,
    ) -> PyResult<Vec<(String, Bound<'py, PyArray1<f64>>)>> {
        let frames = self.frames(vec![run])?;
        let frame = &frames[0];
        let mut own = BTreeMap::new();
        for (name, rule) in self.inner.parameter_rules() {
            own.insert(name.clone(), rule.resolve(&name, frame).map_err(fail)?);
        }
        let system = System::new(&self.inner, &own, with_intercept).map_err(fail)?;
        let dx = py.detach(|| system.derivatives_on(frame)).map_err(fail)?;
        // each column named as the equation that gives it (`psi_dot` for ψ), else `<state>_dot`
        let equations = self.inner.equations();
        let names = system.state_names().iter().map(|s| {
            equations.iter().find(|e| &e.state == s).map_or_else(|| format!("{s}_dot"), |e| e.name.clone())
        });
        Ok(arrays(py, names.zip(dx).collect()))
    }

    /// Any model from its initial states (the file's, or `initial`) with constant `inputs`
    /// for `duration` seconds (or the unit the model's time is named by: `day`; `sample` and
    /// `dt` alike): the run's columns (time, states, inputs), as `termid simulate --input`
    /// gives them.
    #[pyo3(signature = (duration, inputs, initial, dt = None, sample = None, integrator = None, with_intercept = false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_free<'py>(
        &self,
        py: Python<'py>,
        duration: f64,
        inputs: BTreeMap<String, f64>,
        initial: BTreeMap<String, f64>,
        dt: Option<f64>,
        sample: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
    ) -> PyResult<Vec<(String, Bound<'py, PyArray1<f64>>)>> {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(refuse(format!(
                "duration {duration}: a simulation lasts a positive number of seconds"
            )));
        }
        let per = self.inner.seconds_per_time();
        let duration = duration * per;
        let mut system = System::new(&self.inner, &BTreeMap::new(), with_intercept).map_err(fail)?;
        let spec = self.inner.spec();
        for name in initial.keys() {
            if !spec.states.iter().any(|s| &s.name == name) {
                return Err(refuse(format!(
                    "initial `{name}`: not a state of the model ({})",
                    system.states.join(", ")
                )));
            }
        }
        for name in inputs.keys() {
            if !system.inputs.contains(name) {
                return Err(refuse(format!(
                    "input `{name}`: not an input of the model ({})",
                    system.inputs.join(", ")
                )));
            }
        }
        let x0: Vec<f64> =
            spec.states.iter().map(|s| initial.get(&s.name).copied().unwrap_or(s.initial)).collect();
        // the default absolute tolerance counted in how large the states start, as the command's
        system.sizes = self.inner.sizes(&x0.iter().map(|v| v.abs()).collect::<Vec<_>>());
        let u: Vec<f64> = system.inputs.iter().map(|n| inputs.get(n).copied().unwrap_or(0.0)).collect();
        let (integrator, step) = method_of(&self.inner, integrator, dt, &[])?;
        // as the command line: the adaptive method's output interval is free
        let sample = sample.map_or(step, |s| s * per);
        let step = if dt.is_none() && integrator.is_adaptive() && sample.is_finite() && sample > 0.0 {
            sample / (sample / step * (1.0 - 1e-9)).ceil().max(1.0)
        } else {
            step
        };
        let settings = Settings { integrator, dt: step, duration, sample };
        let run = py
            .detach(|| termid::sim::simulate(&system, &x0, &mut termid::sim::Constant(u), &settings))
            .map_err(fail)?;
        if let Some(note) = run.stiff_note() {
            warn(py, note)?;
        }
        Ok(arrays(py, trajectory_columns(&self.time(), run)))
    }

    /// A plug-in's scenario (`zigzag:20/20`, `turning:35`, `spiral`): the simulated run's
    /// columns, its metrics (JSON), its label and its report lines.
    #[pyo3(signature = (scenario, dt = None, duration = None, sample = None, integrator = None, with_intercept = false))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        scenario: &str,
        dt: Option<f64>,
        duration: Option<f64>,
        sample: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
    ) -> PyResult<(Vec<(String, Bound<'py, PyArray1<f64>>)>, String, String, Vec<String>)> {
        let plugin = termid::plugins::of(&self.inner).ok_or_else(|| {
            refuse(format!(
                "{} has no plug-in table, so `{scenario}` does not apply: give no scenario (a duration, constant inputs) or use replay",
                self.inner.path
            ))
        })?;
        let request = termid::plugin::ScenarioRequest {
            text: scenario,
            with_intercept,
            initial_given: false,
            inputs_given: false,
        };
        let scenario = plugin.scenario(&self.inner, &request).map_err(fail)?;
        let (integrator, dt) = method_of(&self.inner, integrator, dt, &[])?;
        let per = self.inner.seconds_per_time();
        let settings = Settings {
            integrator,
            dt,
            duration: duration.map_or_else(|| scenario.default_duration(), |d| d * per),
            sample: sample.map_or(dt, |s| s * per),
        };
        let (model, label) = (&self.inner, scenario.label());
        let outcome = py.detach(move || scenario.run(model, &settings)).map_err(fail)?;
        let frame = &outcome.frame;
        Ok((arrays(py, frame_columns(frame)), to_json(&outcome.metrics)?, label, outcome.text))
    }

    /// A ship's manoeuvre recorded as a model basin would (termid's synthetic basin): the
    /// measured run with sensor noise (seeded) and the noise-free truth, both in the model's
    /// names, SI and radians; the approach speed is `speed` × the model's u0. `tracked`:
    /// optical tracking (u, v from the track, a rudder offset, the rudder back at midship).
    #[pyo3(signature = (manoeuvre, speed = 1.0, duration = 100.0, seed = 0, tracked = false))]
    #[allow(clippy::type_complexity)]
    fn record<'py>(
        &self,
        py: Python<'py>,
        manoeuvre: &str,
        speed: f64,
        duration: f64,
        seed: u64,
        tracked: bool,
    ) -> PyResult<(Vec<(String, Bound<'py, PyArray1<f64>>)>, Vec<(String, Bound<'py, PyArray1<f64>>)>)> {
        use termid::ship::basin::Basin;
        let spec = termid::ship::ShipSpec::of(&self.inner).map_err(fail)?.ok_or_else(|| {
            refuse(format!("{}: no [ship] table: only a ship is recorded in the basin", self.inner.path))
        })?;
        let basin = if tracked { Basin::tracked() } else { Basin::default() };
        let m = termid::ship::Manoeuvre::parse(manoeuvre).map_err(fail)?;
        let name = format!("{}.dat", manoeuvre.replace([':', '/'], "_"));
        let rec = py
            .detach(|| basin.record(&self.inner, &m, speed * spec.u0, duration, seed, &name))
            .map_err(fail)?;
        Ok((arrays(py, frame_columns(&rec.measured)), arrays(py, frame_columns(&rec.truth))))
    }

    /// Each run re-simulated from its recorded initial state with its recorded inputs.
    #[pyo3(signature = (runs, dt = None, integrator = None, with_intercept = false))]
    #[allow(clippy::type_complexity)]
    fn replay<'py>(
        &self,
        py: Python<'py>,
        runs: Vec<Run<'py>>,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
    ) -> PyResult<Vec<Vec<(String, Bound<'py, PyArray1<f64>>)>>> {
        let (_, _, sims) = self.resimulate(py, runs, dt, integrator, with_intercept)?;
        let time = self.time();
        Ok(sims.into_iter().map(|t| arrays(py, trajectory_columns(&time, t))).collect())
    }

    /// The model against held-out runs: the error of every compared state, and for a
    /// plug-in's models its metrics measured and simulated (JSON).
    #[pyo3(signature = (runs, dt = None, integrator = None, with_intercept = false, over_ground = false))]
    fn validate(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
        over_ground: bool,
    ) -> PyResult<String> {
        let (frames, data) = self.replayable(runs, dt, integrator, with_intercept)?;
        let (data, medium) = self.in_medium(py, &frames, data, over_ground)?;
        let sims = py.detach(|| data.simulate(&self.inner, &[], &[])).map_err(fail)?;
        let plugin = termid::plugins::of(&self.inner);
        let observe = |f: &Frame, s: Option<&Trajectory>| {
            plugin.and_then(|p| p.observe(&self.inner, f, s)).map(|o| o.json)
        };
        let metrics: Vec<serde_json::Value> = frames
            .iter()
            .zip(&sims)
            .map(|(f, s)| serde_json::json!({"run": f.origin(), "measured": observe(f, None), "simulated": observe(f, Some(s))}))
            .collect();
        // how long each run is predictable at all (a chaotic model parts from itself)
        let horizon = py.detach(|| data.horizon(&self.inner, &sims));
        let predictable: Vec<serde_json::Value> = frames
            .iter()
            .zip(&horizon)
            .map(|(f, h)| serde_json::json!({"run": f.origin(), "seconds": h.map(|k| f.since_start(k)), "of": f.duration()}))
            .collect();
        to_json(
            &serde_json::json!({"gap": data.gap(&sims), "metrics": metrics, "medium": medium, "predictable_for": predictable}),
        )
    }

    /// The model's uncertainty against held-out runs: every run simulated as `validate`
    /// simulates it with each of `n` models drawn from the stored covariances (seeded), and per
    /// run each metric's spread over the draws and whether the measured value lies outside its
    /// 5-95 % range (JSON: draws, failed, first_failure, refused, runs). Where too many draws
    /// fail, `refused` says why and no spread is given.
    #[pyo3(signature = (runs, n, seed = 1, dt = None, integrator = None, with_intercept = false, over_ground = false))]
    #[allow(clippy::too_many_arguments)]
    fn validate_monte_carlo(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        n: usize,
        seed: u64,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
        over_ground: bool,
    ) -> PyResult<String> {
        self.drawable()?;
        let (frames, data) = self.replayable(runs, dt, integrator, with_intercept)?;
        let (data, _) = self.in_medium(py, &frames, data, over_ground)?;
        // each draw keeps every run's metrics (a few dozen numbers)
        termid::budget::check_values(
            n as f64 * frames.len() as f64 * 64.0,
            || format!("the metrics of {n} drawn models on {} runs", frames.len()),
            "ask for fewer draws (a few hundred give a 90 % band)",
        )
        .map_err(fail)?;
        let plugin = termid::plugins::of(&self.inner);
        let observe = |m: &termid::model::Model, f: &Frame, s: Option<&Trajectory>| {
            plugin.and_then(|p| p.observe(m, f, s)).map(|o| o.json)
        };
        // each draw that ran: every run's metrics as the drawn model steered it; the models
        // drawn one at a time, in the order `draws` draws them
        let sampler = termid::uncertainty::Sampler::new(&self.inner);
        let mut normal = termid::uncertainty::Normal::new(seed);
        let (seen, failed, first) = py.detach(|| {
            let (mut seen, mut failed, mut first) = (Vec::new(), 0usize, None::<String>);
            for _ in 0..n {
                let m = sampler.draw(&mut normal);
                match data.simulate(&m, &[], &[]) {
                    Ok(sims) => seen.push(
                        frames.iter().zip(&sims).map(|(f, s)| observe(&m, f, Some(s))).collect::<Vec<_>>(),
                    ),
                    Err(e) => {
                        failed += 1;
                        first.get_or_insert(e.to_string());
                    }
                }
            }
            (seen, failed, first)
        });
        let refused = termid::uncertainty::refusal(n, seen.len(), first.as_deref());
        // the metrics a table shows (as `termid validate` bands them), per run
        let per_run: Vec<serde_json::Value> = frames
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let records: Vec<serde_json::Value> =
                    seen.iter().filter_map(|draw: &Vec<Option<serde_json::Value>>| draw[k].clone()).collect();
                let spread = if refused.is_none() {
                    termid::uncertainty::spread(&records)
                } else {
                    Default::default()
                };
                let rows =
                    plugin.and_then(|p| p.observe(&self.inner, f, None)).map_or_else(Vec::new, |o| o.rows);
                let metrics: Vec<serde_json::Value> = rows
                    .into_iter()
                    .map(|(name, key, x)| {
                        let sp = spread.get(&key);
                        serde_json::json!({"name": name, "key": key, "measured": x, "spread": sp,
                                           "outside": sp.zip(x).map(|(sp, x)| sp.outside(x))})
                    })
                    .collect();
                serde_json::json!({"run": f.origin(), "metrics": metrics})
            })
            .collect();
        to_json(&serde_json::json!({
            "draws": n, "seed": seed, "failed": failed, "first_failure": first,
            "refused": refused, "runs": per_run,
        }))
    }

    /// Where model and runs disagree and which effect explains it (JSON), with the model that
    /// has the effect added (None when no effect explains enough).
    #[pyo3(signature = (runs, dt = None, integrator = None, with_intercept = false, over_ground = false))]
    fn diagnose(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        dt: Option<f64>,
        integrator: Option<&str>,
        with_intercept: bool,
        over_ground: bool,
    ) -> PyResult<(String, Option<PyModel>)> {
        let frames = self.frames(runs)?;
        // runs tracked over ground: the day's current estimated first with the runs' own values
        let medium = if over_ground { self.inner.held_medium() } else { vec![] };
        let model = self.inner.freed(&medium, &[]).map_err(refuse)?;
        let hypotheses = termid::plugins::hypotheses(&self.inner);
        let (integrator, dt) = method_of(&self.inner, integrator, dt, &frames)?;
        let settings = termid::diagnose::Settings {
            dt,
            integrator,
            with_intercepts: with_intercept,
            ..Default::default()
        };
        let d = py
            .detach(|| termid::diagnose::diagnose(&model, &frames, &hypotheses, &settings))
            .map_err(fail)?;
        let effect = d.winner.map(|w| {
            let c = &d.candidates[w];
            serde_json::json!({"name": c.name, "terms": c.effect, "coefficients": c.estimate,
                               "std_errors": c.std_error, "explained": c.explained, "delta_bic": c.delta_bic})
        });
        let json = serde_json::json!({
            "location": d.location, "effect": effect, "gap_before": d.gap_before,
            "gap_after": d.gap_after, "candidates": d.candidates,
            "own_values": d.own_values, "one_value": d.one_value, "noise": d.noise,
        });
        Ok((to_json(&json)?, d.model.map(|m| PyModel { inner: self.inner.as_declared(&m) })))
    }

    /// The library's recipe (several derivative starts, choice among back-ends by
    /// prediction, output-error refinement, checks, the starts' agreement): (JSON of every
    /// start and the kept one's report, the report as text, the kept model).
    #[pyo3(signature = (runs, derivatives, smooth = false, intercept = None, choose = vec![], compare = vec![], refine = None, refine_iterations = 100, refine_prior = 1e-4, held_out = vec![], refine_step = None, parameters = None, sources = vec![], per_source = vec![], per_run = vec![], laws = true, random_force = true, dead_times = true))]
    #[allow(clippy::too_many_arguments)]
    fn recipe(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        derivatives: Vec<String>,
        smooth: bool,
        intercept: Option<bool>,
        choose: Vec<String>,
        compare: Vec<String>,
        refine: Option<Vec<String>>,
        refine_iterations: usize,
        refine_prior: f64,
        held_out: Vec<Run<'_>>,
        refine_step: Option<f64>,
        parameters: Option<bool>,
        sources: Vec<usize>,
        per_source: Vec<String>,
        per_run: Vec<String>,
        laws: bool,
        random_force: bool,
        dead_times: bool,
    ) -> PyResult<(String, String, PyModel)> {
        let frames = self.frames(runs)?;
        let held = if held_out.is_empty() { None } else { Some(self.frames(held_out)?) };
        let choose = choose
            .iter()
            .map(|name| {
                let backend = Backend::by_name(name).map_err(fail)?;
                Ok((name.clone(), self.inner.with_backend(&backend).map_err(fail)?))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let refined = refine.is_some();
        let settings = termid::recipe::RecipeSettings {
            derivatives,
            smooth,
            intercept: intercept.unwrap_or(self.inner.spec().model.intercept),
            choose,
            compare,
            refine: refine.map(|states| termid::recipe::RefineOptions {
                states: (!states.is_empty()).then_some(states),
                prior: refine_prior,
                iterations: refine_iterations,
                step: refine_step,
            }),
            parameters: termid::recipe::ParameterOptions::asked(
                &self.inner,
                parameters,
                refined,
                sources,
                per_source,
                per_run,
            ),
            laws,
            random_force,
            dead_times,
            ..Default::default()
        };
        let recipe = py
            .detach(|| termid::recipe::identify(&self.inner, &frames, held.as_deref(), &settings))
            .map_err(fail)?;
        let starts: Vec<serde_json::Value> = recipe
            .starts
            .iter()
            .enumerate()
            .map(|(k, s)| {
                // how the start's free parameters fared, where they were refined with it
                let parameters = s.parameters.as_ref().map(|p| match p {
                    termid::recipe::ParameterStage::Kept(_) => "kept",
                    termid::recipe::ParameterStage::Rejected(..) => "rejected",
                    termid::recipe::ParameterStage::Failed(_) => "failed",
                });
                serde_json::json!({"derivative": s.derivative, "refused": s.refused(), "cost": s.cost(),
                                   "kept": k == recipe.kept, "refine_error": s.refine_error,
                                   "parameters": parameters})
            })
            .collect();
        // a refinement that failed leaves the regression's model, and a flag of the kept start
        // (the command line's report prints it) is warned of as `identify` warns: said with the rest
        let kept = recipe.kept();
        let flags = kept.checks.iter().filter(|c| !c.passed && !c.refuses).map(|c| c.line());
        let warnings: Vec<String> =
            recipe
                .warnings()
                .into_iter()
                .chain(flags)
                .chain(kept.refine_error.iter().map(|e| {
                    format!("the output-error refinement failed: {e}; the model is the regression's")
                }))
                .collect();
        let json = serde_json::json!({
            "starts": starts,
            "failed": recipe.failed,
            "warnings": warnings,
            "checks": recipe.checks(),
            "refusals": recipe.refusals(),
            "report": recipe.json().map_err(fail)?,
        });
        let text = format!(
            "{}{}",
            if recipe.starts.len() > 1 { recipe.starts_text() } else { String::new() },
            recipe.text()
        );
        Ok((to_json(&json)?, text, PyModel { inner: recipe.kept().model.clone() }))
    }

    /// The model file's free parameters estimated from runs by output error (JSON report),
    /// with the model holding the estimates.
    #[pyo3(signature = (runs, coefficients = false, states = None, initial_values = "auto".to_string(), dt = None, iterations = 50, sources = vec![], per_source = vec![], per_run = vec![], coarse = false, segments = None, free = vec![], hold = vec![], over_ground = false))]
    #[allow(clippy::too_many_arguments)]
    fn estimate(
        &self,
        py: Python<'_>,
        runs: Vec<Run<'_>>,
        coefficients: bool,
        states: Option<Vec<String>>,
        initial_values: String,
        dt: Option<f64>,
        iterations: usize,
        sources: Vec<usize>,
        per_source: Vec<String>,
        per_run: Vec<String>,
        coarse: bool,
        segments: Option<usize>,
        free: Vec<String>,
        hold: Vec<String>,
        over_ground: bool,
    ) -> PyResult<(String, PyModel)> {
        // runs tracked over ground: the model's held velocity of the medium estimated with it
        let (model, _) = self.inner.freed_over_ground(&free, &hold, over_ground).map_err(refuse)?;
        let initial_values = termid::diagnose::InitialValues::parse(&initial_values)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("initial_values {e}")))?;
        let frames = self.frames(runs)?;
        // multiple shooting: each segment a run of its own, of its run's source
        let (frames, sources) = match segments {
            Some(count) if count < 2 => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "segments {count}: cut each run into 2 or more, or leave it out"
                )))
            }
            Some(count) => termid::diagnose::in_segments(&frames, &sources, count),
            None => (frames, sources),
        };
        let settings = termid::diagnose::EstimateSettings {
            coefficients,
            iterations,
            initial_values,
            sources,
            per_source,
            per_run,
            coarsest: coarse.then_some((termid::recipe::RESOLVED, termid::recipe::MOST_SAMPLES_PER_STEP)),
            ..Default::default()
        };
        let (fit, metrics, stiff) = py
            .detach(|| -> Result<_, termid::diagnose::DiagnoseError> {
                // one RK4 step per sample by default, a whole fraction of it where the model is stiff
                let dt = dt.map(|dt| dt * model.seconds_per_time());
                let (mut runs, stiff) = termid::diagnose::Runs::for_output_error(&model, &frames, dt)?;
                if let Some(names) = &states {
                    runs = runs.comparing(&model, names)?;
                }
                let fit = termid::diagnose::estimate(&model, &runs, &settings)?;
                // a fit whose estimates do not re-simulate every run has no metrics, and says why
                let metrics = fit
                    .re_simulated(&runs)
                    .map(|sims| termid::plugins::fit_metrics(&fit.model, runs.frames(), &sims))
                    .map_err(|e| e.to_string());
                Ok((fit, metrics, stiff))
            })
            .map_err(fail)?;
        if let Some(note) = stiff {
            warn(py, note)?;
        }
        let serialise = |e: serde_json::Error| refuse(format!("could not serialise: {e}"));
        let mut report = serde_json::to_value(&fit).map_err(serialise)?;
        match metrics {
            Ok((metrics, checks)) => {
                report["metrics"] = serde_json::to_value(&metrics).map_err(serialise)?;
                report["metric_checks"] = serde_json::to_value(&checks).map_err(serialise)?;
            }
            Err(why) => report["metrics_failed"] = why.into(),
        }
        Ok((report.to_string(), PyModel { inner: self.inner.as_declared(&fit.model) }))
    }

    /// The plug-in's physical checks (JSON list: name, passed, refuses, detail).
    #[pyo3(signature = (runs = vec![]))]
    fn checks(&self, runs: Vec<Run<'_>>) -> PyResult<String> {
        let frames = if runs.is_empty() { Vec::new() } else { self.frames(runs)? };
        // a field's model has its field's checks; any other, that its equations retrace the runs
        to_json(&termid::recipe::checks_of(&self.inner, &frames))
    }

    /// The steering gear a ship model's zigzag runs show (JSON: delay_s, acceleration_deg_s2,
    /// rate_deg_s, reversals), `None` for another model or runs without a reversal.
    fn steering_gear(&self, runs: Vec<Run<'_>>) -> PyResult<Option<String>> {
        let frames = self.frames(runs)?;
        termid::ship::observed::SteeringGear::of_runs(&self.inner, &frames).map(|g| to_json(&g)).transpose()
    }

    /// A ship model's linear sway and yaw at its straight run, at `speed` (m/s) or its own u0
    /// (JSON), `None` for another model.
    #[pyo3(signature = (speed = None))]
    fn sway_yaw(&self, speed: Option<f64>) -> PyResult<Option<String>> {
        if termid::ship::ShipSpec::of(&self.inner).map_err(fail)?.is_none() {
            return Ok(None);
        }
        let model = speed.map_or(Cow::Borrowed(&self.inner), |u| {
            Cow::Owned(termid::ship::basin::at_approach_speed(&self.inner, u))
        });
        let ship = termid::ship::Ship::new(&model, false).map_err(fail)?;
        let start = ship.straight_run().map_err(fail)?;
        let s = termid::ship::stability::SwayYaw::of(&ship, &start);
        to_json(&serde_json::json!({
            "u0": s.u0, "delta0_deg": start.delta0_deg,
            "yv": s.yv, "yr": s.yr, "nv": s.nv, "nr": s.nr, "n_delta": s.n_delta,
            "time_constants_s": s.time_constants().map(|(fast, slow)| [fast, slow]),
            "largest_eigenvalue": s.largest_eigenvalue(), "course_stable": s.course_stable(),
        }))
        .map(Some)
    }

    /// Pickling (to a worker process): the model file's text and its name.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let make = py.get_type::<PyModel>().getattr("parse")?;
        Ok((make, (self.inner.to_toml(), self.inner.path.clone())))
    }

    fn __repr__(&self) -> String {
        format!(
            "termid.Model({:?}: {} equations, {} states)",
            self.name(),
            self.inner.equations().len(),
            self.states().len()
        )
    }
}
