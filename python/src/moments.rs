//! `termid.Moments`: one equation's sufficient statistics over runs, merged, pickled and
//! identified from.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use termid::identify::EquationMoments;

use crate::convert::{fail, Run};
use crate::model::PyModel;

/// The sufficient statistics of one equation's candidates over runs: merged associatively,
/// written as JSON, pickled. Made by `Moments.from_frame` or `Model.moments`; a model is
/// identified from them by `Model.identify_from_moments`. `a + b` merges (as `a.merge(b)`);
/// `a == b` when of the same equation, target and candidates with the same runs' numbers.
///
/// >>> ship = termid.Model.default()
/// >>> termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
/// termid.Moments("r_dot": 29 candidates, 1 runs, 2501 rows)
#[pyclass(module = "termid._termid", name = "Moments")]
#[derive(Clone)]
pub(crate) struct PyMoments {
    pub(crate) inner: EquationMoments,
}

#[pymethods]
impl PyMoments {
    /// The statistics read from `text`, the JSON `to_json` wrote; errors name `origin`.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> termid.Moments.from_json(m.to_json()) == m
    /// True
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<moments>"))]
    fn from_json(text: &str, origin: &str) -> PyResult<Self> {
        Ok(PyMoments { inner: EquationMoments::from_json(text, origin).map_err(fail)? })
    }

    /// The statistics of `equation` of `model` over runs (a DataFrame, dict of arrays, pyarrow
    /// Table, or a list of them): one pass over the rows, where the rows are. `data`: the
    /// runs; `derivative` and `target` as for `Model.identify`.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.equation
    /// 'r_dot'
    #[staticmethod]
    #[pyo3(signature = (data, model, equation, derivative = None, target = None))]
    fn from_frame(
        py: Python<'_>,
        data: &Bound<'_, PyAny>,
        model: &Bound<'_, PyAny>,
        equation: &str,
        derivative: Option<&str>,
        target: Option<&str>,
    ) -> PyResult<PyMoments> {
        // the Python side's conversions (pandas, pyarrow → float64 arrays; the target's
        // columns as asked), and its Model
        let termid = py.import("termid")?;
        let native = if model.hasattr("_native")? { model.getattr("_native")? } else { model.clone() };
        let runs = termid.getattr("_runs")?.call1((data,))?;
        let runs: Vec<Run<'_>> = termid
            .getattr("_targeted")?
            .call1((&native, runs, derivative, target, vec![equation]))?
            .extract()?;
        let model: PyRef<'_, PyModel> = native.extract()?;
        Ok(model.moments(py, vec![equation.to_string()], runs, derivative)?.remove(0))
    }

    /// The statistics as JSON text (exact: every number round-trips).
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.to_json().startswith("{")
    /// True
    fn to_json(&self) -> String {
        self.inner.to_json()
    }

    /// The statistics of both, this and `other` (refused for another equation, target or
    /// candidate list).
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.merge(m).rows == 2 * m.rows
    /// True
    fn merge(&self, other: &PyMoments) -> PyResult<PyMoments> {
        Ok(PyMoments { inner: self.inner.clone().merge(other.inner.clone()).map_err(fail)? })
    }

    /// `a + b` is `a.merge(b)` (so `sum(parts[1:], parts[0])` merges a list); `other` the
    /// statistics added.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> len((m + m).runs)
    /// 2
    fn __add__(&self, other: &PyMoments) -> PyResult<PyMoments> {
        self.merge(other)
    }

    /// Equal to `other` when of the same equation, target and candidates with the same runs'
    /// numbers.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m == termid.Moments.from_bytes(m.to_bytes()), m == m + m
    /// (True, False)
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.extract::<PyRef<'_, PyMoments>>().is_ok_and(|o| o.inner == self.inner)
    }

    /// The equation the statistics are of.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.equation
    /// 'r_dot'
    #[getter]
    fn equation(&self) -> String {
        self.inner.equation.clone()
    }

    /// What the equation explained: a column (`r_dot`) or an estimated derivative (`dr/dt`).
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.target
    /// 'r_dot'
    #[getter]
    fn target(&self) -> String {
        self.inner.target.clone()
    }

    /// The candidate terms, in the model file's order.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> 'u*v' in m.candidates
    /// True
    #[getter]
    fn candidates(&self) -> Vec<String> {
        self.inner.candidates.clone()
    }

    /// The runs' names, one entry per run (kept apart for leave-one-run-out).
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.runs
    /// ['zigzag 20°/20° starboard']
    #[getter]
    fn runs(&self) -> Vec<String> {
        self.inner.runs.iter().map(|r| r.run.clone()).collect()
    }

    /// The rows the statistics summarise, over all runs.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> m.rows > 1000
    /// True
    #[getter]
    fn rows(&self) -> usize {
        self.inner.runs.iter().map(|r| r.moments.count()).sum()
    }

    /// The statistics as compact bytes (exact; what pickling sends).
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> len(m.to_bytes()) < len(m.to_json())
    /// True
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.to_bytes())
    }

    /// The statistics read from `data`, the bytes `to_bytes` wrote; errors name `origin`.
    ///
    /// >>> ship = termid.Model.default()
    /// >>> m = termid.Moments.from_frame(ship.simulate("zigzag:20/20"), ship, "r_dot")
    /// >>> termid.Moments.from_bytes(m.to_bytes()) == m
    /// True
    #[staticmethod]
    #[pyo3(signature = (data, origin = "<moments>"))]
    fn from_bytes(data: &[u8], origin: &str) -> PyResult<Self> {
        Ok(PyMoments { inner: EquationMoments::from_bytes(data, origin).map_err(fail)? })
    }

    /// Pickling: the compact bytes (every number exact).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let make = py.get_type::<PyMoments>().getattr("from_bytes")?;
        Ok((make, PyTuple::new(py, [self.to_bytes(py)])?))
    }

    fn __repr__(&self) -> String {
        format!(
            "termid.Moments({:?}: {} candidates, {} runs, {} rows)",
            self.inner.equation,
            self.inner.candidates.len(),
            self.inner.runs.len(),
            self.rows()
        )
    }
}
