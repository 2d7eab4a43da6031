//! The native half of the Python package `termid`: thin wrappers that turn numpy arrays into
//! termid's frames, call the library and hand back plain values (arrays, lists, JSON text).
//! The pandas and pyarrow conversions and the friendly signatures are in `termid/__init__.py`.

use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use termid::select::Backend;

mod convert;
mod fitted;
mod model;
mod moments;

use convert::{fail, to_json};
use fitted::PyFit;
use model::PyModel;
use moments::PyMoments;

// named as the package exports it, so that it pickles (a process pool, Dask) and
// `isinstance(e, termid.TermidError)` holds wherever it is unpickled
pyo3::create_exception!(
    termid,
    TermidError,
    PyException,
    "termid refused the input; the message locates it (file, row, column, or a caret under a term).\n\n>>> try:\n...     termid.fit({\"x\": [1.0, 2.0], \"y\": [2.0, 4.0]}, \"y\", \"x^^2\")\n... except termid.TermidError as e:\n...     print(type(e).__name__)\nTermidError"
);

/// The back-ends by name, the derivative methods with their options.
#[pyfunction]
fn methods() -> (Vec<&'static str>, Vec<String>) {
    let derivatives = termid::data::DIFFERENTIATORS.iter().map(|(n, o, _)| format!("{n}{o}")).collect();
    (Backend::NAMES.to_vec(), derivatives)
}

/// A back-end's settings with their defaults (JSON, `method` included).
#[pyfunction]
fn default_settings(name: &str) -> PyResult<String> {
    let backend = Backend::by_name(name).map_err(fail)?;
    to_json(&backend)
}

/// The version of termid inside.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// Why no spread may be made of `ran` of `draws` drawn models (`None` where it may): the
/// command line's rule and words.
#[pyfunction]
fn monte_carlo_refusal(draws: usize, ran: usize, first_failure: Option<&str>) -> Option<String> {
    termid::uncertainty::refusal(draws, ran, first_failure)
}

/// The first of `names` that says it holds the time (`time`, `Time [s]`, `timestamp`, …), and
/// whether it is the only one (then taken for the time, as the command line takes it).
#[pyfunction]
fn time_like(names: Vec<String>) -> Option<(String, bool)> {
    let mut like = names.into_iter().filter(|n| termid::data::looks_like_time(n));
    let first = like.next()?;
    Some((first, like.next().is_none()))
}

/// The columns whose names carry their unit, read by their bare names (in SI where termid
/// knows the unit): (place, bare name, unit, factor to SI) each ([`termid::data::headers_in_si`]).
#[pyfunction]
fn headers_in_si(names: Vec<String>) -> Vec<(usize, String, String, f64)> {
    termid::data::headers_in_si(&names)
}

/// How a header that carries its unit is read, as it is said ([`termid::data::read_as`]); a
/// time column's `unit` is empty.
#[pyfunction]
fn read_as(header: &str, bare: &str, unit: &str, factor: f64) -> String {
    termid::data::read_as(header, bare, unit, factor)
}

/// Where the time column `time` is among `names`: that name, else that name with a unit of
/// time (`t [s]`), as a file's time is found ([`termid::data::time_position`]).
#[pyfunction]
fn time_position(names: Vec<String>, time: &str) -> Option<usize> {
    termid::data::time_position(&names, time)
}

/// A check as one line a person reads: `ok`, `FLAG` or `FAIL`, the check and its numbers
/// ([`termid::plugin::Check::line`], as the command line prints it).
#[pyfunction]
fn check_line(name: String, passed: bool, refuses: bool, detail: String) -> String {
    termid::plugin::Check { name, passed, refuses, detail, measure: None }.line()
}

/// The factor to seconds of a time column whose header says another unit of time
/// (`Time [ms]`: 0.001), as a run's time is read.
#[pyfunction]
fn seconds_per(name: &str) -> Option<f64> {
    termid::data::seconds_per(name).filter(|f| *f != 1.0)
}

/// What to say of a time whose own name is a unit of time's (`day`, `time_ms`): read in
/// seconds all the same, as the command line reads it.
#[pyfunction]
fn time_in_seconds(time: &str) -> Option<String> {
    termid::data::time_in_seconds(time)
}

/// Candidate terms as a user lists them: each text split at its commas outside parentheses
/// (the command line's `--terms x,x*y`).
#[pyfunction]
fn listed(texts: Vec<String>) -> Vec<String> {
    termid::term::listed(&texts)
}

/// Whether rows labelled `labels` (each row's value as an index) are several runs
/// interleaved, the readings `columns` far smoother along each value's rows: the number of
/// runs and of changes where they are (the command line's rule).
#[pyfunction]
fn interleaved(
    labels: Vec<u32>,
    columns: Vec<numpy::PyReadonlyArray1<'_, f64>>,
) -> PyResult<Option<(usize, usize)>> {
    let columns: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect::<Result<_, _>>()?;
    Ok(termid::data::interleaved(&labels, &columns))
}

#[pymodule]
fn _termid(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("TermidError", m.py().get_type::<TermidError>())?;
    m.add_class::<PyModel>()?;
    m.add_class::<PyMoments>()?;
    m.add_class::<PyFit>()?;
    m.add_function(wrap_pyfunction!(fitted::fit, m)?)?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(default_settings, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(monte_carlo_refusal, m)?)?;
    m.add_function(wrap_pyfunction!(time_like, m)?)?;
    m.add_function(wrap_pyfunction!(seconds_per, m)?)?;
    m.add_function(wrap_pyfunction!(time_in_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(headers_in_si, m)?)?;
    m.add_function(wrap_pyfunction!(read_as, m)?)?;
    m.add_function(wrap_pyfunction!(time_position, m)?)?;
    m.add_function(wrap_pyfunction!(check_line, m)?)?;
    m.add_function(wrap_pyfunction!(listed, m)?)?;
    m.add_function(wrap_pyfunction!(interleaved, m)?)?;
    Ok(())
}
