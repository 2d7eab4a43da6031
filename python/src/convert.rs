//! Between Python's values and termid's: numpy arrays to frames, settings from JSON, errors
//! as `TermidError` with their causes.

use std::borrow::Cow;

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use termid::data::Frame;
use termid::select::Backend;
use termid::sim::{Integrator, Trajectory};

use crate::TermidError;

/// An error with its causes, as the command line prints it (`{:#}`).
pub(crate) fn fail(e: impl std::error::Error) -> PyErr {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let more = c.to_string();
        if !text.contains(&more) {
            text = format!("{text}: {more}");
        }
        cause = c.source();
    }
    TermidError::new_err(text)
}

pub(crate) fn refuse(text: impl Into<String>) -> PyErr {
    TermidError::new_err(text.into())
}

/// What the command line says on standard error, as a `UserWarning` a notebook shows, pointed
/// at the user's line that called the package (the package's `_outside`), not at its own.
pub(crate) fn warn(py: Python<'_>, note: String) -> PyResult<()> {
    let message = std::ffi::CString::new(format!("termid: {note}")).unwrap_or_default();
    let level = py.import("termid")?.getattr("_outside")?.call0()?.extract::<i32>()?;
    PyErr::warn(py, &py.get_type::<pyo3::exceptions::PyUserWarning>(), &message, level)
}

/// A run handed over from Python: its name, and its columns as float64 arrays.
pub(crate) type Run<'py> = (String, Bound<'py, PyDict>);

/// One column as a float64 array (the Python side makes it so).
pub(crate) fn column<'py>(
    origin: &str,
    name: &str,
    value: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray1<'py, f64>> {
    value
        .extract()
        .map_err(|_| refuse(format!("{origin}: column `{name}` is not a one-dimensional float64 array")))
}

/// The arrays' values where they lie; a strided one (a view across a row-major block) is
/// copied, the others are not.
pub(crate) fn in_place<'a>(arrays: &'a [PyReadonlyArray1<'_, f64>]) -> Vec<Cow<'a, [f64]>> {
    arrays
        .iter()
        .map(|a| a.as_slice().map_or_else(|_| Cow::Owned(a.as_array().to_vec()), Cow::Borrowed))
        .collect()
}

/// A run as a frame over its time column `time` (every value checked as a file's would be).
pub(crate) fn frame_of(origin: &str, time: &str, columns: &Bound<'_, PyDict>) -> PyResult<Frame> {
    let names: Vec<String> = columns.keys().iter().map(|k| k.extract()).collect::<PyResult<_>>()?;
    let Some(t) = columns.get_item(time)? else {
        return Err(refuse(format!("{origin}: no time column `{time}` (columns: {})", names.join(", "))));
    };
    let t = column(origin, time, &t)?;
    let mut frame =
        Frame::new(origin, time, termid::data::in_seconds(time, t.as_array().to_vec())).map_err(fail)?;
    for (name, value) in names.iter().zip(columns.values().iter()) {
        if name != time {
            frame.push(name, column(origin, name, &value)?.as_array().to_vec()).map_err(fail)?;
        }
    }
    Ok(frame)
}

/// A back-end from its JSON settings (`{"method": "stepwise", "f_in": 4.0}`).
pub(crate) fn backend_of(json: &str) -> PyResult<Backend> {
    let backend: Backend = serde_json::from_str(json).map_err(|e| {
        refuse(format!("back-end settings {json}: {e} (back-ends: {})", Backend::NAMES.join(", ")))
    })?;
    backend.validate().map_err(fail)?;
    Ok(backend)
}

/// The method and control step asked for (`dt` in the model's unit of time), else the model
/// file's `[simulation]`, else the adaptive Dormand-Prince method at the recorded `runs`'
/// sample interval, or at 0.04 where there are none.
pub(crate) fn method_of(
    model: &termid::model::Model,
    integrator: Option<&str>,
    dt: Option<f64>,
    runs: &[termid::data::Frame],
) -> PyResult<(Integrator, f64)> {
    let method = integrator.map(Integrator::by_name).transpose().map_err(fail)?;
    Ok(model.resimulation(method, dt, runs))
}

pub(crate) fn to_json(value: &impl serde::Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| refuse(format!("could not serialise: {e}")))
}

/// Columns as (name, array) pairs, in order.
pub(crate) fn arrays<'py>(
    py: Python<'py>,
    columns: Vec<(String, Vec<f64>)>,
) -> Vec<(String, Bound<'py, PyArray1<f64>>)> {
    columns.into_iter().map(|(n, v)| (n, v.into_pyarray(py))).collect()
}

/// A frame's columns, time first (in the unit its name says, `Time (ms)`, as it is read back).
pub(crate) fn frame_columns(f: &Frame) -> Vec<(String, Vec<f64>)> {
    let mut out: Vec<(String, Vec<f64>)> =
        f.names().iter().filter_map(|n| f.column(n).map(|c| (n.clone(), c.to_vec()))).collect();
    if let Some((name, t)) = out.first_mut() {
        *t = termid::data::from_seconds(name, std::mem::take(t));
    }
    out
}

/// A simulated run as columns: time (in the unit its name says), states, inputs.
pub(crate) fn trajectory_columns(time: &str, t: Trajectory) -> Vec<(String, Vec<f64>)> {
    let mut out = vec![(time.to_string(), termid::data::from_seconds(time, t.time))];
    out.extend(t.state_names.into_iter().zip(t.states));
    out.extend(t.input_names.into_iter().zip(t.inputs));
    out
}
