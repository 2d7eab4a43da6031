//! `termid.fit` and `termid.Fit`: one equation fitted to columns by a back-end, its chosen
//! terms compiled for `predict`, the compiled candidates kept for the next call.

use std::collections::BTreeMap;

use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use termid::identify::{Fit, Identification};
use termid::term::{parse_terms, Library, Source, Term, Vocabulary};

use crate::convert::{backend_of, column, fail, frame_of, in_place, refuse, to_json, warn};

/// One equation fitted to columns: the back-end's steps and chosen terms (JSON) and the
/// compiled chosen terms for `predict`.
#[pyclass(module = "termid._termid", name = "Fit")]
pub(crate) struct PyFit {
    fit: Fit,
    chosen: Library,
    coefficients: Vec<f64>,
    intercept: f64,
    parameters: BTreeMap<String, f64>,
    /// The variables the terms were written over (for pickling: the terms are compiled again).
    variables: Vec<String>,
}

/// What a pickled fit holds: its JSON, the variables and the parameters of its terms.
type FitState = (String, Vec<String>, BTreeMap<String, f64>);

impl PyFit {
    /// A fit with its chosen terms compiled over `variables` and `parameters`.
    fn compiled(fit: Fit, variables: Vec<String>, parameters: BTreeMap<String, f64>) -> PyResult<PyFit> {
        let mut vocabulary = Vocabulary::new();
        for name in &variables {
            vocabulary.variable(name).map_err(fail)?;
        }
        for name in parameters.keys() {
            vocabulary.parameter(name).map_err(fail)?;
        }
        let texts: Vec<String> = fit.selection.terms.iter().map(|t| t.term.clone()).collect();
        let chosen = parse_terms(&texts, &vocabulary).map_err(fail)?;
        Ok(PyFit {
            chosen: Library::compile(&chosen, &vocabulary).map_err(fail)?,
            coefficients: fit.selection.terms.iter().map(|t| t.coefficient).collect(),
            intercept: fit.selection.intercept.as_ref().map_or(0.0, |b| b.value),
            parameters,
            variables,
            fit,
        })
    }
}

#[pymethods]
impl PyFit {
    /// Pickled as its JSON and the names its terms are written over (a process pool, Dask).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, FitState)> {
        let this = slf.borrow();
        let restore = slf.get_type().getattr("_restore")?;
        Ok((restore, (to_json(&this.fit)?, this.variables.clone(), this.parameters.clone())))
    }

    /// The fit `__reduce__` wrote.
    #[staticmethod]
    fn _restore(json: &str, variables: Vec<String>, parameters: BTreeMap<String, f64>) -> PyResult<PyFit> {
        let fit: Fit =
            serde_json::from_str(json).map_err(|e| refuse(format!("not a pickled termid fit: {e}")))?;
        PyFit::compiled(fit, variables, parameters)
    }

    /// The fit as JSON: target, candidates, the back-end's steps and chosen terms, covariance.
    fn to_json(&self) -> PyResult<String> {
        to_json(&self.fit)
    }

    /// The report's numbers (steps with SSE and F, chosen terms with standard errors) as JSON.
    fn report_json(&self) -> PyResult<String> {
        to_json(&self.fit.report())
    }

    /// Σ cⱼ·termⱼ + b0 on columns (float64 arrays, read in place).
    fn predict<'py>(
        &self,
        py: Python<'py>,
        columns: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        // each input a column, or a parameter's value where there is no column of its name
        let mut arrays = Vec::with_capacity(self.chosen.inputs().len());
        let mut given = Vec::with_capacity(self.chosen.inputs().len());
        for name in self.chosen.inputs() {
            match (columns.get_item(name)?, self.parameters.get(name)) {
                (Some(v), _) => {
                    arrays.push(column("predict", name, &v)?);
                    given.push(true);
                }
                (None, Some(_)) => given.push(false),
                (None, None) => return Err(refuse(format!("predict: no column `{name}`"))),
            }
        }
        let values = in_place(&arrays);
        let mut next = values.iter();
        let slices: Vec<Option<&[f64]>> =
            given.iter().map(|g| if *g { next.next().map(|v| &**v) } else { None }).collect();
        let n = slices.iter().flatten().map(|s| s.len()).next().unwrap_or(0);
        if let Some(bad) = slices.iter().flatten().find(|s| s.len() != n) {
            return Err(refuse(format!("predict: columns of {} and {n} rows", bad.len())));
        }
        let sources: Vec<Source<'_>> = self
            .chosen
            .inputs()
            .iter()
            .zip(&slices)
            .map(|(name, s)| s.map_or_else(|| Source::Constant(self.parameters[name]), Source::Column))
            .collect();
        let mut out = vec![self.intercept; n];
        self.chosen.for_each_block(&sources, 0..n, |start, block| {
            for (c, values) in self.coefficients.iter().zip(block) {
                for (o, v) in out[start..start + values.len()].iter_mut().zip(*values) {
                    *o += c * v;
                }
            }
        });
        Ok(out.into_pyarray(py))
    }
}

/// The texts `fit` compiles: the target, the column names, the terms and the parameters'
/// names. Equal texts compile to equal terms.
#[derive(PartialEq)]
struct CompileKey {
    target: String,
    names: Vec<String>,
    terms: Vec<String>,
    forced: Vec<String>,
    excluded: Vec<String>,
    parameters: Vec<String>,
    weights: Option<String>,
    time: Option<String>,
}

/// What `fit` compiles from the texts alone: the columns' vocabulary, the parsed terms and
/// their compiled design (~15 µs of a 0.15 ms fit of 29 terms). The last one is kept for a
/// next call with the same texts: fits of the same candidates to new rows (resampling,
/// rolling windows, shards) compile once, as the command line does.
struct Compiled {
    key: CompileKey,
    vocabulary: Vocabulary,
    candidates: Vec<Term>,
    forced: Vec<Term>,
    excluded: Vec<Term>,
    design: termid::identify::Design,
}

static LAST_COMPILED: std::sync::Mutex<Option<std::sync::Arc<Compiled>>> = std::sync::Mutex::new(None);

impl Compiled {
    fn of(key: CompileKey) -> PyResult<std::sync::Arc<Compiled>> {
        let mut last = LAST_COMPILED.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(c) = last.as_ref().filter(|c| c.key == key) {
            return Ok(c.clone());
        }
        let mut vocabulary = Vocabulary::new();
        for name in &key.names {
            if *name != key.target && Some(name) != key.weights.as_ref() && Some(name) != key.time.as_ref() {
                vocabulary.variable(name).map_err(fail)?;
            }
        }
        for name in &key.parameters {
            vocabulary.parameter(name).map_err(fail)?;
        }
        let parse = |texts: &[String]| parse_terms(texts, &vocabulary).map_err(fail);
        let (candidates, forced, excluded) = (parse(&key.terms)?, parse(&key.forced)?, parse(&key.excluded)?);
        let design = termid::identify::Design::new(&candidates, &vocabulary).map_err(fail)?;
        let compiled =
            std::sync::Arc::new(Compiled { key, vocabulary, candidates, forced, excluded, design });
        *last = Some(compiled.clone());
        Ok(compiled)
    }
}

/// One equation from columns: `target` explained by the candidate `terms` (text in termid's
/// term language over the column names) with a back-end given as JSON settings. A rate
/// (`dx/dt`) is an equation of motion of the rows as a time series over the column `time`,
/// by the `derivative` method (`integral` where none is named, as the command line does),
/// over `runs` (by name, each with the columns of `columns`, the first) where there are
/// several; a column is explained by the rows of `columns` alone.
#[pyfunction]
#[pyo3(signature = (target, columns, terms, backend = "{\"method\": \"stepwise\"}", intercept = true, forced = vec![], excluded = vec![], parameters = BTreeMap::new(), weights = None, time = None, derivative = None, keep_spikes = false, intersample = "auto", delays = BTreeMap::new(), lags = BTreeMap::new(), runs = vec![]))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit(
    py: Python<'_>,
    target: &str,
    columns: &Bound<'_, PyDict>,
    terms: Vec<String>,
    backend: &str,
    intercept: bool,
    forced: Vec<String>,
    excluded: Vec<String>,
    parameters: BTreeMap<String, f64>,
    weights: Option<String>,
    time: Option<String>,
    derivative: Option<String>,
    keep_spikes: bool,
    intersample: &str,
    delays: BTreeMap<String, f64>,
    lags: BTreeMap<String, f64>,
    runs: Vec<(String, Bound<'_, PyDict>)>,
) -> PyResult<PyFit> {
    let intersample = match intersample {
        "auto" => termid::data::Intersample::Auto,
        "linear" => termid::data::Intersample::Linear,
        "held" => termid::data::Intersample::Held,
        other => {
            return Err(refuse(format!(
                "intersample = {other:?}: \"auto\" (held where a column shows a controller's command), \"linear\" or \"held\""
            )))
        }
    };
    let backend = backend_of(backend)?;
    let names: Vec<String> = columns.keys().iter().map(|k| k.extract()).collect::<PyResult<_>>()?;
    let variables: Vec<String> = names
        .iter()
        .filter(|n| *n != target && Some(*n) != weights.as_ref() && Some(*n) != time.as_ref())
        .cloned()
        .collect();
    // the arrays used where they lie: read-only views, no copy (the rows are checked as
    // they are accumulated: a value that is not finite is refused with its row and term)
    let arrays = names
        .iter()
        .zip(columns.values().iter())
        .map(|(name, value)| column("data", name, &value))
        .collect::<PyResult<Vec<_>>>()?;
    let values = in_place(&arrays);
    let slices: Vec<(&str, &[f64])> =
        names.iter().map(String::as_str).zip(values.iter().map(|v| &**v)).collect();
    let key = CompileKey {
        target: target.into(),
        names: names.clone(),
        terms,
        forced,
        excluded,
        parameters: parameters.keys().cloned().collect(),
        weights: weights.clone(),
        time: time.clone(),
    };
    let compiled = Compiled::of(key)?;
    let Compiled { vocabulary, candidates, forced, excluded, design, .. } = &*compiled;
    let rules =
        parameters.iter().map(|(n, v)| (n.clone(), termid::identify::ParamValue::Value(*v))).collect();
    let rate = termid::identify::Target::parse(target);
    let method = match (&rate, derivative.as_deref()) {
        (termid::identify::Target::Derivative(_), name) => {
            termid::recipe::derivative_method(name.unwrap_or(termid::recipe::ANY_SYSTEM_DERIVATIVE))
                .map_err(fail)?
        }
        (_, Some(name)) => {
            return Err(refuse(format!(
                "derivative = {name:?} estimates a rate: the target is one (`d{target}/dt`)"
            )))
        }
        (_, None) => Box::new(termid::data::CentralDifference),
    };
    let how = Identification {
        vocabulary,
        parameters: &rules,
        differentiator: method.as_ref(),
        intercept,
        weights,
    };
    let selector = backend.build();
    let fit = match &rate {
        termid::identify::Target::Derivative(state) => {
            // the rows as one run in time: a rate is estimated (or integrated) along it
            let time =
                time.as_deref().ok_or_else(|| refuse(format!("`{target}` is a rate: it needs the time")))?;
            if state == time {
                return Err(refuse(format!("`{target}`: `{time}` is the time, whose rate is 1")));
            }
            let mut pieces = Vec::new();
            let whole: Vec<termid::data::Frame> = if runs.is_empty() {
                vec![frame_of("data", time, columns)?]
            } else {
                runs.iter().map(|(name, run)| frame_of(name, time, run)).collect::<PyResult<_>>()?
            };
            for run in whole {
                // a logger's dropout: each piece a run (integrated across, the motion in the
                // gap would be taken as a line), as the command line cuts a file it reads
                let (cut, notes) = termid::data::cut_at_gaps(run, 0).map_err(fail)?;
                for note in notes {
                    warn(py, note)?;
                }
                pieces.extend(cut);
            }
            let all: Vec<&str> = variables.iter().map(String::as_str).collect();
            let mut despiked = Vec::new();
            for mut frame in pieces {
                if !keep_spikes {
                    // a time series whose rate is taken: a glitch would be one (the command
                    // line's default too)
                    if let Some((mended, notes)) = termid::data::despiked_all(&frame).map_err(fail)? {
                        frame = mended;
                        for note in notes {
                            warn(py, note)?;
                        }
                    }
                }
                despiked.push(frame);
            }
            // every column but the state may be an input held between samples (a late one
            // judged as it acts); any column a slower sensor's readings; the state's leap a cut
            // between runs joined
            let late: Vec<(&str, f64)> = delays.iter().map(|(n, s)| (n.as_str(), *s)).collect();
            let lagging: Vec<(&str, f64)> = lags.iter().map(|(n, s)| (n.as_str(), *s)).collect();
            let (mut frames, notes) =
                termid::data::runs_of_rate(despiked, state, &all, &late, &lagging, intersample)
                    .map_err(fail)?;
            for note in notes {
                warn(py, note)?;
            }
            // columns acting later than recorded, read back (after the marking: a held column
            // sample for sample)
            for (name, seconds) in &delays {
                for frame in &mut frames {
                    *frame = termid::data::delayed(frame, name, *seconds, 0.0).map_err(fail)?;
                }
            }
            // and through their lags, from where the lags' start at rest has died away
            if !lagging.is_empty() {
                for frame in &mut frames {
                    *frame = termid::data::lagged(frame, &lagging, 0.0).map_err(fail)?;
                }
            }
            let others: Vec<String> = all.iter().filter(|c| **c != state).map(|c| c.to_string()).collect();
            py.detach(|| -> Result<Fit, termid::identify::IdentifyError> {
                let mut fit = how.fit_design(&rate, design, forced, excluded, &frames, selector.as_ref())?;
                // rows of a time series are not independent: the honest standard errors' factor
                how.describe_residuals(&rate, candidates, &frames, &mut fit)?;
                // and a column acting later than recorded leaves its mark on them
                how.say_delays(&rate, candidates, &frames, &others, &mut fit, &|l| l.plain_remedy())?;
                // and noise on a variable a candidate holds nonlinearly biases the fit itself
                let chosen: Vec<String> = fit.selection.terms.iter().map(|t| t.term.clone()).collect();
                fit.selection
                    .notes
                    .extend(termid::identify::noise_note(candidates, &chosen, vocabulary, &frames));
                Ok(fit)
            })
            .map_err(fail)?
        }
        termid::identify::Target::Column(_) => py
            .detach(|| how.fit_columns("data", &slices, target, design, forced, excluded, selector.as_ref()))
            .map_err(fail)?,
    };
    let chosen: Vec<Term> = fit.selection.terms.iter().map(|t| candidates[t.index].clone()).collect();
    Ok(PyFit {
        chosen: Library::compile(&chosen, vocabulary).map_err(fail)?,
        coefficients: fit.selection.terms.iter().map(|t| t.coefficient).collect(),
        intercept: fit.selection.intercept.as_ref().map_or(0.0, |b| b.value),
        parameters,
        variables,
        fit,
    })
}
