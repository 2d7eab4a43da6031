"""Documented spellings work: back-end settings are discoverable, any Arrow stream is a run
(every docstring example runs in test_reference.py)."""

import numpy as np
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
