"""Documented spellings work: back-end settings are discoverable, any Arrow stream is a run
(every docstring example runs in test_reference.py)."""

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest

import termid


def test_settings_are_discoverable_and_step_rule_may_be_a_name(hald):
    s = termid.settings("stepwise")
    assert "step_rule" in s and "min_proportion" in s
    a = termid.fit(hald, "y", ["x1", "x2", "x4"], "stepwise", step_rule="last")
    b = termid.fit(hald, "y", ["x1", "x2", "x4"], "stepwise", step_rule={"rule": "last"})
    assert a.coefficients.equals(b.coefficients)
    with pytest.raises(termid.TermidError):
        termid.settings("lasso-ish")


def test_any_arrow_stream_and_record_arrays_are_runs(hald):
    base = termid.fit(hald, "y", ["x1", "x2"]).coefficients
    table = pa.Table.from_pandas(hald)

    class Stream:  # a producer of the Arrow PyCapsule interface and nothing else (as polars)
        def __arrow_c_stream__(self, requested_schema=None):
            return table.__arrow_c_stream__(requested_schema)

    assert termid.fit(Stream(), "y", ["x1", "x2"]).coefficients.equals(base)
    records = hald.to_records(index=False)
    assert isinstance(records, np.ndarray) and records.dtype.names
    assert termid.fit(records, "y", ["x1", "x2"]).coefficients.equals(base)


def test_a_polars_frame_is_one_run_wherever_runs_are_taken():
    # a polars DataFrame iterates over its columns: given to Model.identify it was taken for a
    # list of runs, each a column, and refused by pyarrow ("ArrowSchema describes non-struct
    # type double"); a LazyFrame was indexed as a list. Each is one run, as a pandas frame is.
    pl = pytest.importorskip("polars")
    truth = termid.Model.builtin("lorenz").simulate(duration=10.0, sample=0.01)[["t", "x", "y", "z"]]
    model = termid.Model.from_states(["x", "y", "z"])
    base = model.identify(truth).model.coefficients("z_dot")
    for run in (pl.from_pandas(truth), pl.from_pandas(truth).lazy()):
        found = model.identify(run).model.coefficients("z_dot")
        assert found.equals(base), found
        assert termid.fit(run, "dz/dt", ["x*y", "z"]).coefficients.round(6).to_dict() == {"x*y": 1.0, "z": -2.666667}
    # several runs in one polars frame, told apart by a column
    both = pl.concat([pl.from_pandas(truth.iloc[:500]).with_columns(pl.lit("a").alias("run")),
                      pl.from_pandas(truth.iloc[500:]).with_columns(pl.lit("b").alias("run"))])
    for table in (both, both.lazy()):
        fitted = termid.fit(table, "dz/dt", ["x*y", "z"], by="run")
        assert fitted.coefficients.round(6).to_dict() == {"x*y": 1.0, "z": -2.666667}
    # a polars frame of inputs is a record to replay, not constants by name
    forced = termid.Model.builtin("duffing")
    t = np.arange(0.0, 2.0001, 0.01)
    record = pd.DataFrame({"t": t, "F": 0.5 * np.sin(3.0 * t)})
    replayed = forced.simulate(inputs=record)
    again = forced.simulate(inputs=pl.from_pandas(record))
    assert again.equals(replayed) and replayed["x"].std() > 0
