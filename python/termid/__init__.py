"""termid: identify equations of motion from time series.

Candidate terms are written as text (``u*Δu``, ``r*v^2/u``, ``abs(v)*v``); termid compiles
them, selects the terms that matter with a regression back-end (stepwise as in IBM SSP's
STPRG, best subset, sparse, Efroymson, ...) and writes the identified model as a file that it
can simulate. This package calls termid's Rust library in the same process.

    >>> import termid
    >>> ship = termid.Model.default()            # Oltmann (1973), HSVA 1512
    >>> run = ship.simulate("zigzag:20/20")      # a pandas DataFrame, SI units
    >>> fitted = ship.identify([run])            # every equation, from the run's rates
    >>> fitted.targets["r_dot"]                  # what it explained: the column r_dot
    'r_dot'
    >>> table = fitted.model.coefficients("r_dot")
    >>> list(table.columns)                      # a DataFrame: term, value, std_error
    ['term', 'value', 'std_error']

Data is given as pandas DataFrames, dicts of numpy arrays or pyarrow Tables (columns named
as the model's variables, SI units, angles in radians; a name that carries a unit termid knows,
``x [m]``, ``psi [deg]``, is read as ``x``, ``psi`` in SI, warned); several runs as a list of them, or a
pandas grouping of one long frame (``df.groupby("experiment")``: each value's rows a run of
their own, named ``experiment=e1``). Errors are :class:`TermidError`
carrying termid's located message (file, row, column, or a caret under a term).
"""

from __future__ import annotations

import contextvars
import errno
import functools
import inspect
import json
import math
import os
import re
import sys
import warnings
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import pandas as pd
from pandas.core.groupby import DataFrameGroupBy

try:
    from . import _termid
except ImportError as e:  # the source folder, found before the installed package
    raise ImportError(
        f"termid's native module is not beside {os.path.dirname(__file__)}: that is the source "
        "folder, not the installed package (pip install ./python); run from another folder"
    ) from e
from ._termid import TermidError

__all__ = [
    "Model",
    "Moments",
    "Fit",
    "Identified",
    "Recipe",
    "Summary",
    "TermidError",
    "fit",
    "backends",
    "settings",
    "derivatives",
    "__version__",
]

__version__ = _termid.version()


def __dir__() -> List[str]:
    """What ``dir(termid)`` and tab completion offer: the public names and the submodules
    imported so far, not the modules this one imports for itself (``np``, ``pd``, ``typing``).

    >>> "fit" in dir(termid) and "np" not in dir(termid)
    True
    """
    loaded = [m for m in ("plot", "sklearn") if m in globals()]
    return sorted(set(__all__) | {"Data"} | set(loaded))

#: What a run may be: a DataFrame, a dict of arrays, a pyarrow Table (or anything with
#: ``to_pandas``).
Data = Any


_F64 = np.dtype(np.float64)


def _frame_in_place(data: pd.DataFrame) -> Optional[Dict[str, np.ndarray]]:
    """A DataFrame's float64 columns where they lie, without copying: pandas keeps the
    columns of one type in 2-D blocks (``_mgr.blocks``, each with the positions of its
    columns, ``mgr_locs``), one column a row of the block. These are pandas' internals
    (stable since 1.x); where they are not as expected, or a column is not float64, None, and
    the public conversion serves."""
    blocks = getattr(getattr(data, "_mgr", None), "blocks", None)
    if blocks is None:
        return None
    arrays: List[Any] = [None] * data.shape[1]
    found = 0
    try:
        for block in blocks:
            values = block.values
            if type(values) is not np.ndarray or values.dtype != _F64 or values.ndim != 2:
                return None
            for at, column in zip(block.mgr_locs.as_array.tolist(), values):
                arrays[at] = column
                found += 1
    except (AttributeError, IndexError, TypeError):
        return None
    if found != len(arrays):
        return None
    return dict(zip(map(str, data.columns.tolist()), arrays))


def _outside() -> int:
    """The ``stacklevel`` of a warning that points at the user's line calling this package, however
    deep inside it the warning is raised."""
    level, frame = 1, sys._getframe(1)
    while frame is not None and frame.f_code.co_filename == __file__:
        level, frame = level + 1, frame.f_back
    return level


def _naive(values: Any) -> Any:
    """Date-times with a time zone (pandas' ``datetime64[ns, tz]``, a column or an index) as
    plain date-times in UTC: their differences are then the seconds that passed, a change to
    or from daylight saving time no jump. Other values pass unchanged."""
    if getattr(getattr(values, "dtype", None), "tz", None) is None:
        return values
    return pd.DatetimeIndex(values).tz_convert("UTC").tz_localize(None).to_numpy()


def _seconds(what: str, values: Any) -> Any:
    """A column of durations (timedelta64) in seconds, or of instants (datetime64, with a time
    zone or without) in seconds since its first; termid reads times in seconds, and the raw
    numbers would be nanoseconds. Other columns pass unchanged; ``what`` names them in the
    warning and an error (``column `t` ``, ``the index``)."""
    array = np.asarray(_naive(values))
    if array.dtype.kind not in "mM":
        return values
    kind = "durations" if array.dtype.kind == "m" else "date-times"
    if array.dtype.kind == "M":
        array = array - array[0] if len(array) else array.astype("timedelta64[ns]")
    if np.isnat(array).any():
        raise TermidError(f"{what}: a missing time (NaT) at row {int(np.argmax(np.isnat(array))) + 1}")
    warnings.warn(
        f"termid: {what} holds {kind}; read as seconds"
        + (" since its first value" if kind == "date-times" else ""),
        stacklevel=_outside(),
    )
    return array.astype("timedelta64[ns]").astype(np.int64) / 1e9


def _is_time(values: Any) -> bool:
    """Whether values (a column, an index) are instants or durations."""
    return getattr(getattr(values, "dtype", None), "kind", "O") in "mM"


def _once(names: Sequence[Any]) -> None:
    """Refuses column names given twice (a dict would keep the last without a word)."""
    seen = set()
    twice = []
    for n in map(str, names):
        if n in seen and n not in twice:
            twice.append(n)
        seen.add(n)
    if twice:
        raise TermidError(
            f"column {', '.join(f'`{n}`' for n in twice)} appears twice: which one is meant is not clear; rename or drop one"
        )


class _Columns(Dict[str, np.ndarray]):
    """Columns by name; ``left_out`` names the columns that hold no numbers (a run id, a
    label) with their type: no term can use them, and an error that needs one says so;
    ``times`` the columns that held instants or durations (now seconds)."""

    left_out: Dict[str, str] = {}
    times: List[str] = []


# The index of each DataFrame run being read, by its name in messages: an error's "row 38" is
# the 38th row, which a DataFrame's user finds by its index label (``df.loc[1037]``).
_INDEXES: "contextvars.ContextVar[Dict[str, pd.Index]]" = contextvars.ContextVar("termid_indexes")


def _note_index(name: str, run: Any) -> None:
    """Keeps the index of run ``name`` (a DataFrame) for :func:`_located`."""
    if isinstance(run, pd.DataFrame):
        indexes = _INDEXES.get(None)
        if indexes is not None:
            indexes[name] = run.index


def _located(error: TermidError) -> TermidError:
    """The error with the index label beside each row it names of a DataFrame run read in the
    call (``run1: row 38`` → ``run1: row 38 (index 1037)``); the error itself where it names
    none."""
    text = str(error)
    for name, index in sorted((_INDEXES.get(None) or {}).items(), key=lambda kv: -len(kv[0])):

        def label(found: "re.Match[str]") -> str:
            row = int(found.group(1))
            if not 1 <= row <= len(index):
                return found.group(0)
            return f"{found.group(0)} (index {index[row - 1]})"

        text = re.sub(rf"(?<![\w=]){re.escape(name)}: row (\d+)(?! \(index)", label, text)
    return error if text == str(error) else TermidError(text)


def _runs_told_apart(method: Any) -> Any:
    """A method on runs takes them as :func:`fit` does: ``by="run"`` names the column that
    tells the runs of one table apart (its ``runs``, and a recipe's ``held_out``). Its error
    on a frame's time that starts again (runs one after another in one frame) says how to
    hand them over: a list, grouped, or ``by`` the frame's label column (its first column that
    holds no numbers)."""
    signature = inspect.signature(method)

    @functools.wraps(method)
    def told(*args: Any, by: Optional[str] = None, **kwargs: Any) -> Any:
        if by is not None:
            bound = signature.bind_partial(*args, **kwargs)
            for name in ("runs", "held_out"):
                if bound.arguments.get(name) is not None and (name == "runs" or isinstance(bound.arguments[name], pd.DataFrame)):
                    bound.arguments[name] = _split_by(bound.arguments[name], by)
            args, kwargs = bound.args, bound.kwargs
        token = _INDEXES.set({})
        try:
            return method(*args, **kwargs)
        except TermidError as e:
            if "starts again" not in str(e):
                located = _located(e)
                if located is e:
                    raise
                raise located from None
            frames = [a for a in (*args, *kwargs.values()) if isinstance(a, pd.DataFrame)]
            label = next((str(c) for f in frames for c in f.columns if not pd.api.types.is_numeric_dtype(f[c])), "run")
            raise TermidError(
                f"{e}: give them as a list of runs, grouped by the column that names each row's run, "
                f"df.groupby('{label}'), or by='{label}'"
            ) from None
        finally:
            _INDEXES.reset(token)

    # `by` shown in the method's signature, before its keywords of any name
    parameters = list(signature.parameters.values())
    at = next((k for k, p in enumerate(parameters) if p.kind is inspect.Parameter.VAR_KEYWORD), len(parameters))
    parameters.insert(at, inspect.Parameter("by", inspect.Parameter.KEYWORD_ONLY, default=None, annotation="Optional[str]"))
    told.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    said = "``by``: the column that tells apart the runs of one table (as for :func:`fit`)."
    doc = method.__doc__ or ""
    example = re.search(r"^( *)>>>", doc, re.M)
    told.__doc__ = (
        doc[: example.start()] + f"{example.group(1)}{said}\n\n" + doc[example.start() :]
        if example
        else f"{doc}\n\n{said}"
    )
    return told


def _explained(error: TermidError, left_out: Mapping[str, str]) -> TermidError:
    """The error, with the type of a non-numeric column it names and how a term can use its
    levels (one column of 0 and 1 per level)."""
    named = [f"`{n}` holds {kind}, not numbers" for n, kind in left_out.items() if f"`{n}`" in str(error)]
    if not named:
        return error
    levels = [n for n in left_out if f"`{n}`" in str(error)]
    return TermidError(
        f"{error} (column {'; '.join(named)}: a term uses its levels as columns of 0 and 1, "
        f"pd.get_dummies(df, columns={levels!r}, dtype=float))"
    )


def _numeric(items: Any) -> "_Columns":
    out = _Columns()
    out.left_out = {}
    for name, values in items:
        values = _seconds(f"column `{name}`", values)
        try:
            out[name] = np.ascontiguousarray(values, dtype=np.float64)
        except (TypeError, ValueError):
            out.left_out[name] = str(getattr(values, "dtype", type(values).__name__))
    return out


def _stamps_parsed(data: Data) -> Data:
    """A DataFrame's columns of ISO 8601 date-times held as text (``pd.read_csv`` without
    ``parse_dates``) as the date-times they are, as the command line reads a file's stamps;
    anything else as it is."""
    if not isinstance(data, pd.DataFrame):
        return data
    parsed = {}
    # (pandas before 2.0 reads no "ISO8601" format: its stamps stay text, left out as before)
    for j in range(data.shape[1]):
        values = data.iloc[:, j]
        if values.dtype.kind in "biufcmM":
            continue
        first = values.dropna()
        if first.empty or not re.match(r"\d{4}-\d{2}-\d{2}[T ]\d", str(first.iloc[0])):
            continue
        try:
            stamps = pd.to_datetime(values, format="ISO8601")
        except (ValueError, TypeError):
            continue
        if not stamps.isna().any():
            parsed[j] = stamps
    if not parsed:
        return data
    # column by column, by place (pandas 1.3 has no `isetitem`; names may repeat until `_once`)
    out = pd.concat([parsed.get(j, data.iloc[:, j]) for j in range(data.shape[1])], axis=1)
    out.columns = data.columns
    out.attrs = dict(data.attrs)
    return out


def _columns(data: Data) -> "_Columns":
    """Columns as contiguous float64 arrays, without copying where the layout allows; time
    columns (timedelta64, datetime64, ISO 8601 stamps as text) in seconds, named in
    ``times``; columns that hold no numbers left out."""
    data = _stamps_parsed(data)
    found = _columns_of(data)
    if isinstance(data, pd.DataFrame):
        found.times = [str(c) for c, dt in zip(data.columns, data.dtypes) if getattr(dt, "kind", "O") in "mM"]
    elif isinstance(data, Mapping):
        found.times = [str(k) for k, v in data.items() if _is_time(np.asarray(_naive(v)))]
    elif hasattr(data, "column_names") and hasattr(data, "schema"):  # pyarrow Table
        found.times = [f.name for f in data.schema if str(f.type).startswith(("timestamp", "duration"))]
    if isinstance(data, pd.DataFrame) and found.left_out:
        _refuse_interleaved(data, found)
    return _in_si(found)


def _in_si(found: "_Columns") -> "_Columns":
    """The columns whose names carry their unit (``x [m]``, ``psi [deg]``, ``i [A]``, as
    ``pd.read_csv`` names a logger's columns) by their bare names, in SI where termid knows the
    unit and as written where not (``w [rpm]``), warned, as the command line reads a file's; a
    time column keeps its name (``time="Time [ms]"`` reads its unit)."""
    renamed = {i: (bare, unit, f) for i, bare, unit, f in _termid.headers_in_si(list(found))}
    if not renamed:
        return found
    out = _Columns()
    out.left_out, out.times = found.left_out, found.times
    said = []
    for i, (name, values) in enumerate(found.items()):
        if i not in renamed:
            out[name] = values
            continue
        bare, unit, factor = renamed[i]
        out[bare] = values if factor == 1.0 else values * factor
        said.append(_termid.read_as(name, bare, unit, factor))
    warnings.warn(f"termid: read by their bare names: {', '.join(said)}", stacklevel=_outside())
    return out


def _refuse_interleaved(data: pd.DataFrame, found: "_Columns") -> None:
    """Refuses the rows of several runs interleaved in one frame (two vessels logged in turn,
    time increasing throughout), which would read as one run whose readings leap at every row:
    a column left out that names each row's run (the command line's rule,
    :func:`_termid.interleaved`)."""
    readings = [np.ascontiguousarray(v, dtype=np.float64) for v in found.values()]
    for name in found.left_out:
        codes, values = pd.factorize(data[name])
        if len(values) < 2 or (codes < 0).any():
            continue
        told = _termid.interleaved(codes.astype(np.uint32).tolist(), readings)
        if told is not None:
            runs, changes = told
            raise TermidError(
                f"the rows are those of {runs} runs interleaved (`{name}` changes at {changes} of {len(codes)} rows, "
                f"and the readings run smoothly along each value's rows, not along the frame's): give them as a list of "
                f"runs, or grouped, df.groupby('{name}')"
            )


def _as_frame(data: Any) -> Any:
    """A pandas Series (one signal over its index of times) as the one-column DataFrame it
    is, named by its name; anything else as it is."""
    if not isinstance(data, pd.Series):
        return data
    if data.name is None:
        raise TermidError("a Series without a name is no column: name it, series.rename('x'), or give a DataFrame")
    return data.to_frame()


def _columns_of(data: Data) -> "_Columns":
    data = _as_frame(data)
    if isinstance(data, pd.DataFrame):
        # pandas' name for the empty column after a trailing comma on every row (a spreadsheet's
        # export), which holds nothing: no column (its name refused the run)
        blank = [c for c in data.columns if re.fullmatch(r"Unnamed: \d+", str(c)) and data[c].isna().all()]
        if blank:
            data = data.drop(columns=blank)
        _once(data.columns)
        if any(getattr(dt, "kind", "O") in "mM" for dt in data.dtypes):
            data = pd.DataFrame(
                {str(c): _seconds(f"column `{c}`", data.iloc[:, j]) for j, c in enumerate(data.columns)},
                index=data.index,
            )
        in_place = _frame_in_place(data)
        if in_place is not None:
            found = _Columns(in_place)
            found.left_out = {}
            return found
        # one column-major copy of the whole frame is faster than a conversion per column
        # (pandas' column access costs ~15 µs each); its columns are then contiguous views
        try:
            block = np.asfortranarray(data.to_numpy(dtype=np.float64))
        except (TypeError, ValueError):
            block = None
        if block is not None:
            found = _Columns((str(c), block[:, j]) for j, c in enumerate(data.columns))
            found.left_out = {}
            return found
        # each column as pandas keeps it, so that a left-out one is named by its own type
        # (`category`, `string`), not numpy's `object`
        items = ((str(c), data.iloc[:, j]) for j, c in enumerate(data.columns))
    elif isinstance(data, Mapping):
        items = ((str(k), v) for k, v in data.items())
    elif hasattr(data, "column_names") and hasattr(data, "column"):  # pyarrow Table
        _once(data.column_names)
        items = ((n, data.column(j).to_numpy()) for j, n in enumerate(data.column_names))
    elif hasattr(data, "to_pandas"):
        return _columns(data.to_pandas())
    elif hasattr(data, "__arrow_c_stream__"):  # any Arrow PyCapsule producer (polars, ...)
        import pyarrow

        return _columns(pyarrow.table(data))
    elif hasattr(data, "collect") and callable(data.collect):  # a lazy frame (polars)
        return _columns(data.collect())
    elif isinstance(data, np.ndarray) and data.dtype.names:  # a numpy record array
        items = ((str(n), data[n]) for n in data.dtype.names)
    elif isinstance(data, np.ndarray):
        # (pysindy's `fit(X, t=dt)` takes the columns by position; termid reads them by name)
        raise TypeError(
            f"a run must be a pandas DataFrame, a dict of arrays or a pyarrow Table, not a {data.ndim}-D "
            "numpy array, whose columns have no names: name them, "
            "pd.DataFrame(X, columns=['x', 'y']).assign(t=t) (the time a column, or the index), "
            "or {'t': t, 'x': X[:, 0], 'y': X[:, 1]}"
        )
    else:
        raise TypeError(
            f"a run must be a pandas DataFrame, a dict of arrays or a pyarrow Table, not {type(data).__name__}"
        )
    return _numeric(items)


def _run_name(run: Data, k: int) -> str:
    """The name of the ``k``-th run (from 0) in messages: a DataFrame's ``attrs["name"]``, else
    ``run1``, ``run2``, ..."""
    return str(getattr(run, "attrs", {}).get("name", f"run{k + 1}"))


def _grouped(runs: Any) -> Optional[List[Tuple[str, pd.DataFrame]]]:
    """A pandas grouping's groups as runs (``df.groupby("experiment")``: the rows of each value
    a run of their own), named ``experiment=e1``, the columns grouped by left out; ``None``
    for anything but a grouping."""
    if not isinstance(runs, DataFrameGroupBy):
        return None
    keys = runs.keys
    by = [keys] if isinstance(keys, str) else [k for k in keys if isinstance(k, str)] if isinstance(keys, (list, tuple)) else []
    label = ",".join(by) or "group"
    out = []
    for value, rows in runs:
        value = value[0] if isinstance(value, tuple) and len(value) == 1 else value
        shown = ",".join(map(str, value)) if isinstance(value, tuple) else str(value)
        out.append((f"{label}={shown}", rows.drop(columns=[k for k in by if k in rows.columns])))
    if not out:
        raise TermidError("no runs: the grouping has no groups (no rows)")
    return out


def _runs(
    runs: Union[Data, Sequence[Data]], names: Optional[Sequence[str]] = None, time: Optional[str] = None
) -> List[Tuple[str, Dict[str, np.ndarray]]]:
    """Runs as (name, columns); one run may be given alone. A DataFrame's ``attrs["name"]``
    names it in messages, else ``run1``, ``run2``, ... A run without the column ``time`` (a
    model's) has it from its index where that holds times (:func:`_index_time`)."""
    grouped = _grouped(runs)
    if grouped is not None:
        names = names or [name for name, _ in grouped]
        runs = [run for _, run in grouped]
    if _is_table(runs) or isinstance(runs, (Mapping, np.ndarray)):
        runs = [runs]
    out = []
    for k, run in enumerate(runs):
        name = names[k] if names else _run_name(run, k)
        _note_index(str(name), run)
        columns = _columns(run)
        if time is not None and time not in columns:
            _time_from(str(name), run, columns, time)
        out.append((str(name), columns))
    # a time named by its unit (`day`, an epidemic's day count) is read in seconds: said once
    said = _termid.time_in_seconds(time) if time is not None and out else None
    if said:
        warnings.warn(f"termid: {said}", stacklevel=_outside())
    return out


def _time_headed(columns: "_Columns", time: str) -> bool:
    """Whether ``columns`` hold the time ``time``: under that name, or under it with a unit of
    time (``t [s]``, ``Time (ms)``: renamed ``time``, in seconds, warned), as the command line
    finds a file's time column."""
    place = _termid.time_position(list(columns), time)
    if place is None:
        return False
    header = list(columns)[place]
    if header != time:
        factor = _termid.seconds_per(header)
        values = columns.pop(header)
        columns[time] = values * factor if factor else values
        warnings.warn(f"termid: read by their bare names: {_termid.read_as(header, time, '', factor or 1.0)}", stacklevel=_outside())
    return True


def _time_from(name: str, run: Data, columns: "_Columns", time: str) -> None:
    """A run without its model's time column ``time`` takes it from a column of that name with
    a unit of time (:func:`_time_headed`), else from its index where that holds times
    (:func:`_index_time`), else from its one column of date-times or durations (said); else it
    is refused, a column that looks like time named (as :func:`fit` does)."""
    if _time_headed(columns, time):
        return
    index = _index_time(run)
    if index is not None:
        columns[time] = index
    elif len(columns.times) == 1:
        warnings.warn(
            f"termid: {name}: the rows' time `{time}` is column `{columns.times[0]}`, the one of date-times or durations",
            stacklevel=_outside(),
        )
        columns[time] = columns.pop(columns.times[0])
    else:
        like, only = _termid.time_like(list(columns)) or (None, False)
        factor = _termid.seconds_per(like) if like else None
        if only:
            # the one column whose name says it holds the time (`time`, `Time [s]`, `day`), as
            # the command line takes a file's: a dataframe's `time` needs no renaming
            said = f"; {_termid.read_as(like, time, '', factor)}" if factor and factor != 1.0 else ""
            warnings.warn(
                f"termid: {name}: the rows' time `{time}` is column `{like}`, the one whose name says so{said}",
                stacklevel=_outside(),
            )
            values = columns.pop(like)
            columns[time] = values * factor if factor else values
            return
        raise TermidError(
            f"{name}: no time column `{time}` (columns: {', '.join(columns)})"
            + (
                f"; `{like}` looks like time: name it `{time}`, "
                + (
                    f"in seconds: df.assign({time}=df['{like}'] * {factor:g})"
                    if factor
                    else f"df.rename(columns={{'{like}': '{time}'}})"
                )
                if like
                else ""
            )
        )


def _frame(columns: Sequence[Tuple[str, np.ndarray]]) -> pd.DataFrame:
    return pd.DataFrame({name: values for name, values in columns})


def _backend(backend: Optional[str], settings: Mapping[str, Any]) -> Optional[str]:
    if backend is None:
        if settings:
            raise TypeError(f"back-end settings {sorted(settings)} given without a back-end")
        return None
    return _settings_text(backend, settings)


def backends() -> List[str]:
    """The regression back-ends by name (``stepwise``, ``best-subset``, ``sparse``, ...).

    >>> "stepwise" in termid.backends() and "stlsq" in termid.backends()
    True
    """
    return list(_termid.methods()[0])


def settings(backend: str) -> Dict[str, Any]:
    """The settings of the back-end ``backend`` and their defaults, as keywords of
    :func:`fit` and :meth:`Model.identify` take them.

    >>> termid.settings("stlsq")["floor"]
    0.01
    """
    found = json.loads(_termid.default_settings(backend))
    found.pop("method", None)
    return found


def derivatives() -> List[str]:
    """The derivative methods with their options (``central``, ``savitzky-golay:W:O``, ...).

    >>> [d.split("[")[0] for d in termid.derivatives()][:2]
    ['central', 'five-point']
    """
    return list(_termid.methods()[1])


def _t_two_sided(t: float, df: float) -> float:
    """P(|T| ≥ |t|) for Student's t with ``df`` degrees of freedom: the regularized
    incomplete beta I_x(df/2, 1/2) at x = df/(df + t²) (continued fraction, Lentz)."""
    if not np.isfinite(t):
        return 0.0 if not np.isnan(t) else float("nan")
    x = df / (df + t * t)
    a, b = df / 2.0, 0.5
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    front = math.exp(math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x))
    if x > (a + 1.0) / (a + b + 2.0):  # the symmetric side converges faster
        return 1.0 - front * _beta_fraction(b, a, 1.0 - x) / b
    return front * _beta_fraction(a, b, x) / a


def _beta_fraction(a: float, b: float, x: float) -> float:
    tiny = 1e-300
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 300):
        for num in (m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)), -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + num / c
            c = c if abs(c) > tiny else tiny
            h *= d * c
        if abs(d * c - 1.0) < 1e-15:
            break
    return h


def _t_quantile(p_two_sided: float, df: float) -> float:
    """The t for which P(|T| ≥ t) = ``p_two_sided`` (bisection on the tail)."""
    lo, hi = 0.0, 1.0
    while _t_two_sided(hi, df) > p_two_sided:
        hi *= 2.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _t_two_sided(mid, df) > p_two_sided else (lo, mid)
    return 0.5 * (lo + hi)


def _rivals_frame(report: Mapping[str, Any]) -> pd.DataFrame:
    """A fit report's rivals as a DataFrame indexed by the chosen term (instead, rise)."""
    rows = [{"term": w["chosen"], "instead": w["instead"], "rise": w["rise"]} for w in report.get("rivals", [])]
    return pd.DataFrame(rows, columns=["term", "instead", "rise"]).set_index("term")


class Summary:
    """A fit as statsmodels' ``summary()`` shows one: ``stats`` (rows, terms, R², adjusted R²,
    F, AIC, BIC, the residuals' correlation time τ), ``terms``, a DataFrame of each
    coefficient with its standard error, the √τ-corrected one, t, p and confidence interval,
    and ``notes``, what the numbers do not show (printed last, as statsmodels does).

    >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4], "y": [1.0, 3.1, 4.9, 7.0, 9.0]})
    >>> s = termid.fit(df, "y", "x").summary()
    >>> round(s.stats["r2"], 4), list(s.terms.index)
    (0.9995, ['(intercept)', 'x'])
    """

    def __init__(self, stats: Dict[str, Any], terms: pd.DataFrame, equation: str, notes: Sequence[str] = ()):
        self.stats = stats
        self.terms = terms
        self.equation = equation
        self.notes = list(notes)

    def __str__(self) -> str:
        head = "  ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in self.stats.items())
        text = f"{self.equation}\n{head}\n{self.terms.to_string(float_format=lambda v: f'{v:.6g}')}"
        # as statsmodels closes its summary: what the numbers above do not show
        if self.notes:
            text += "\n\nNotes:\n" + "\n".join(f"[{i}] {n}" for i, n in enumerate(self.notes, 1))
        return text

    __repr__ = __str__


class Fit:
    """One equation fitted by a back-end: its steps, chosen terms and coefficients.

    ``steps`` is the back-end's table (one row per step: term entered or removed, SSE, F),
    ``coefficients`` the chosen terms' values with standard errors, ``chosen_step`` the step
    the back-end stopped at; ``predict`` evaluates the chosen terms, compiled, on new data.
    Made by :func:`fit`.

    >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]})
    >>> termid.fit(df, "y", "x")
    termid.Fit(y = 1 + 2 x)
    """

    def __init__(self, native: Any, target: str):
        self._native = native
        self.target = target
        self._report: Optional[Dict[str, Any]] = None
        self._raw: Optional[Dict[str, Any]] = None

    @property
    def report(self) -> Dict[str, Any]:
        """The fit's report (steps, terms, chosen step, stop) as plain values; read on first use.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.report["chosen_step"]
        1
        """
        if self._report is None:
            self._report = json.loads(self._native.report_json())
        return self._report

    @property
    def raw(self) -> Dict[str, Any]:
        """The whole fit (selection, candidates, covariance) as plain values.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> sorted(fitted.raw)[:2]
        ['candidates', 'correlation_time']
        """
        if self._raw is None:
            self._raw = json.loads(self._native.to_json())
        return self._raw

    @property
    def steps(self) -> pd.DataFrame:
        """The back-end's table, one row per step (the term entered or removed, SSE, R², F).

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.steps[["step", "term"]].to_dict("records")
        [{'step': 1, 'term': 'x'}]
        """
        return pd.DataFrame(self.report.get("steps", []))

    @property
    def coefficients(self) -> pd.Series:
        """The chosen terms' coefficients, a Series indexed by term (the intercept apart).

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.coefficients.round(9).to_dict()
        {'x': 2.0}
        """
        terms = self.report.get("terms", [])
        return pd.Series({t["term"]: t["coefficient"] for t in terms}, name=self.target, dtype=float)

    @property
    def standard_errors(self) -> pd.Series:
        """The chosen terms' standard errors, a float64 Series indexed by term.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.standard_errors.dtype
        dtype('float64')
        """
        terms = self.report.get("terms", [])
        return pd.Series({t["term"]: t.get("std_error") for t in terms}, name=self.target, dtype=float)

    @property
    def intercept(self) -> Optional[float]:
        """The constant b0, or None when fitted without one.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> round(fitted.intercept, 9)
        1.0
        """
        b0 = self.raw["selection"].get("intercept")
        return None if b0 is None else b0["value"]

    @property
    def notes(self) -> List[str]:
        """What the numbers do not show: terms the rows cannot tell from a candidate left out,
        collinear or offset candidates, coarse samples (:meth:`summary` prints them last).

        >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4, 5], "w": [0.1, 0.9, 2.1, 2.9, 4.1, 5.0],
        ...                    "y": [0.4, 1.7, 3.8, 6.1, 8.4, 9.7]})
        >>> [n[:33] for n in termid.fit(df, "y", ["x", "w"]).notes]
        ['the rows hardly tell `w` from `x`']
        """
        return list(self.report.get("notes", []))

    @property
    def rivals(self) -> pd.DataFrame:
        """How firmly each chosen term was chosen: its closest rival among the candidates left
        out (``instead``) and the rise of the residual sum of squares with the rival in its
        place (``rise``, in residual variances s²; negative: the rival fits better). A rise
        within about 4·τ is the noise's choice, and :attr:`notes` says so.

        >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4, 5], "w": [0.1, 0.9, 2.1, 2.9, 4.1, 5.0],
        ...                    "y": [0.4, 1.7, 3.8, 6.1, 8.4, 9.7]})
        >>> termid.fit(df, "y", ["x", "w"]).rivals.round(2).to_dict("index")
        {'w': {'instead': 'x', 'rise': 1.11}}
        """
        return _rivals_frame(self.report)

    @property
    def chosen_step(self) -> Optional[int]:
        """The step the back-end's rule chose (1-based), None for back-ends without steps.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.chosen_step
        1
        """
        return self.report.get("chosen_step")

    def predict(self, data: Data) -> pd.Series:
        """Σ cⱼ·termⱼ + b0 on ``data`` (the compiled evaluator; numpy arrays read in place), a
        Series on the data's index (a DataFrame's) named as the target.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.predict({"x": np.array([10.0])}).round(9).tolist()
        [21.0]
        """
        values = self._native.predict(_columns(data))
        index = data.index if isinstance(data, pd.DataFrame) else None
        return pd.Series(values, index=index, name=self.target)

    def score(self, data: Data) -> float:
        """R² of the fitted equation on ``data`` (rows it was not fitted to, say), as
        scikit-learn's ``score`` gives it: 1 − Σ(y − ŷ)² / Σ(y − ȳ)², the target a column of
        ``data``. A rate (``dx/dt``) is no column: a column of measured rates (``x_dot``) is
        scored as one, else a model of the rates is judged by re-simulating its runs
        (:meth:`Model.validate`).

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> round(fitted.score(pd.DataFrame({"x": [4.0, 5.0], "y": [9.0, 11.5]})), 6)
        0.92
        """
        columns = _columns(data)
        if self.target not in columns:
            raise TermidError(
                f"`{self.target}` is not a column of the data ({', '.join(columns)}): a fit is scored against its "
                "target's values; a rate's fit is judged by re-simulating its runs (Model.validate)"
            )
        y = np.asarray(columns[self.target], dtype=np.float64)
        residual = y - self.predict(data).to_numpy()
        spread = float(np.sum((y - y.mean()) ** 2))
        if spread == 0.0:
            raise TermidError(f"`{self.target}` is the same in every row: R² is not defined")
        return 1.0 - float(np.sum(residual**2)) / spread

    def equation(self, precision: int = 6) -> str:
        """The fitted equation as text, ``y = 62.4 + 1.55 x1 + ...``, each number to
        ``precision`` significant digits.

        >>> fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
        >>> fitted.equation(3)
        'y = 1 + 2 x'
        >>> termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", ["1", "x - 1"]).equation(3)
        'y = 3 + 2 (x - 1)'
        """
        return _equation_text(self.target, self.intercept, self.coefficients.items(), precision)

    def summary(self, alpha: float = 0.05) -> Summary:
        """R², adjusted R², F, AIC and BIC of the chosen step, and every coefficient with its
        standard error (and the one corrected for the residuals' correlation, ×√τ, where
        the rows are a time series), t, two-sided p and the (1 − ``alpha``) interval.

        >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4], "y": [1.0, 3.1, 4.9, 7.0, 9.0]})
        >>> termid.fit(df, "y", "x").summary(alpha=0.1).terms.columns[-2:].tolist()
        ['ci_0.05', 'ci_0.95']
        """
        r = self.report
        n = int(r.get("rows", 0))
        steps = r.get("steps", [])
        chosen = next((st for st in steps if st.get("step") == r.get("chosen_step")), steps[-1] if steps else {})
        has_b0 = r.get("intercept") is not None
        rows = [(t["term"], t["coefficient"], t["std_error"], t["t"]) for t in r.get("terms", [])]
        if has_b0:
            b0, se0 = r["intercept"], r.get("intercept_std_error") or float("nan")
            rows.insert(0, ("(intercept)", b0, se0, b0 / se0 if se0 else float("nan")))
        p = len(rows)
        dof = max(n - p, 1)
        # a step table may hold null (F of an exact fit): NaN, as statsmodels shows it
        r2 = float(chosen.get("r2") if chosen.get("r2") is not None else float("nan"))
        s = float(chosen.get("standard_error") if chosen.get("standard_error") is not None else float("nan"))
        rss = s * s * dof
        llf = -0.5 * n * (math.log(2 * math.pi) + math.log(rss / n) + 1.0) if n and rss > 0 else float("nan")
        tau = r.get("correlation_time")
        stretch = math.sqrt(tau) if tau and tau > 1.0 else 1.0
        q = _t_quantile(alpha, dof)
        table = pd.DataFrame(
            [
                {
                    "term": term,
                    "coefficient": b,
                    "std_error": se,
                    "std_error_tau": se * stretch,
                    "t": t,
                    "p": _t_two_sided(t, dof),
                    f"ci_{alpha / 2:g}": b - q * se,
                    f"ci_{1 - alpha / 2:g}": b + q * se,
                }
                for term, b, se, t in rows
            ]
        ).set_index("term")
        stats = {
            "rows": n,
            "terms": p,
            "r2": r2,
            "adj_r2": 1.0 - (1.0 - r2) * ((n - 1) if has_b0 else n) / dof,
            "f": float(chosen.get("f") if chosen.get("f") is not None else float("nan")),
            "aic": -2.0 * llf + 2.0 * p,
            "bic": -2.0 * llf + p * math.log(n) if n else float("nan"),
            "tau": float(tau) if tau else float("nan"),
        }
        return Summary(stats, table, self.equation(), self.notes)

    def __repr__(self) -> str:
        return f"termid.Fit({self.equation(4)})"


@functools.lru_cache(maxsize=64)
def _settings_cached(backend: str, items: Tuple[Tuple[str, Any], ...]) -> str:
    return json.dumps({"method": backend, **dict(items)})


def _settings_text(backend: str, settings: Mapping[str, Any]) -> str:
    """A back-end and its settings as the JSON the native side reads (the same settings,
    once: repeated fits pass the same text). ``step_rule="last"`` is short for
    ``step_rule={"rule": "last"}``."""
    if isinstance(settings.get("step_rule"), str):
        settings = {**settings, "step_rule": {"rule": settings["step_rule"]}}
    try:
        return _settings_cached(backend, tuple(settings.items()))
    except TypeError:  # a setting that cannot be hashed (a list)
        return json.dumps({"method": backend, **settings})


_RATE = re.compile(r"^\s*d(.+)/dt\s*$")


def _index_time(data: Data) -> Optional[np.ndarray]:
    """A DataFrame's index as the rows' time in seconds where it holds times: date-times (in a
    time zone or not; seconds from the first), durations, floats, or integers under a name (an
    unnamed integer index is row labels, as a filtered frame keeps); else None."""
    data = _as_frame(data)
    index = getattr(data, "index", None)
    if not isinstance(data, pd.DataFrame) or isinstance(index, pd.RangeIndex):
        return None
    if not (_is_time(index) or index.dtype.kind in "f" + ("iu" if index.name is not None else "")):
        return None
    seconds = np.ascontiguousarray(_seconds("the index" + (f" `{index.name}`" if index.name is not None else ""), index), dtype=np.float64)
    # numbers under a name that says its unit of time (`Time (ms)`), as a time column's are read
    factor = _termid.seconds_per(str(index.name)) if index.name is not None and not _is_time(index) else None
    return seconds * factor if factor else seconds


def _time_of(data: Data, columns: "_Columns", time: Optional[str], target: str) -> str:
    """The name of the time of rows whose rate is fitted: ``time``, else a column ``t`` (or
    ``t [s]``, :func:`_time_headed`), else
    the DataFrame's index where it holds times (:func:`_index_time`, added to ``columns`` as
    ``t``), else the one column of date-times or durations, with a warning."""
    if time is not None:
        if not _time_headed(columns, time):
            raise TermidError(f"no time column `{time}` (columns: {', '.join(columns)})")
        return time
    if _time_headed(columns, "t"):
        return "t"
    index = _index_time(data)
    if index is not None:
        columns["t"] = index
        return "t"
    if len(columns.times) == 1:
        warnings.warn(
            f"termid: `{target}` is a rate: the rows' time is column `{columns.times[0]}`, the one of date-times or "
            f"durations (time='name' names another)",
            stacklevel=_outside(),
        )
        return columns.times[0]
    like, only = _termid.time_like(list(columns)) or (None, False)
    if only:
        warnings.warn(
            f"termid: `{target}` is a rate: the rows' time is column `{like}`, the one whose name says so "
            f"(time='name' names another)",
            stacklevel=_outside(),
        )
        return like
    raise TermidError(
        f"`{target}` is a rate: it needs the rows' time, a column `t`, time='name', or a DataFrame indexed by time"
        + (f"; `{like}` looks like time: time='{like}'" if like else "")
    )


def fit(
    data: Data,
    target: str,
    terms: Union[str, Sequence[str], None] = None,
    backend: Optional[str] = None,
    *,
    intercept: Optional[bool] = None,
    forced: Sequence[str] = (),
    excluded: Sequence[str] = (),
    parameters: Optional[Mapping[str, float]] = None,
    weights: Optional[str] = None,
    time: Optional[str] = None,
    derivative: Optional[str] = None,
    keep_spikes: bool = False,
    intersample: str = "auto",
    delays: Optional[Mapping[str, float]] = None,
    lags: Optional[Mapping[str, float]] = None,
    by: Optional[str] = None,
    **settings: Any,
) -> Fit:
    """Fits ``target`` (a column of ``data``) by the candidate ``terms`` (text over the other
    columns; default: every other column) with a back-end and its settings as keywords, e.g.
    ``fit(df, "y", ["x1", "x2", "x1*x2"], "stepwise", step_rule="last")`` (a back-end's
    settings: ``termid.settings(backend)``). A single string is one term.

    A rate, ``fit(df, "dx/dt", terms)``, is an equation of motion of the rows as a time
    series, with the command line's defaults for one: no derivative estimated (the weak
    form) unless ``derivative`` names a method (:func:`derivatives`), the back-end
    ``"stlsq"``, and the constant a candidate (``"1"``) rather than a forced intercept.

    Parameters: ``data`` a DataFrame, dict of arrays, Arrow table or record array, or a list
    of them, one per run (experiments recorded apart: a rate is integrated along each, never
    from one's end to the next's start; a DataFrame's ``attrs["name"]`` names it in warnings);
    ``target`` the column explained, or ``"dX/dt"`` the rate of column X; ``terms`` the
    candidates (a list, or one text listing them with commas: ``"x*y, z"``); ``backend`` the selection (:func:`backends`; default ``"stepwise"``, for a
    rate ``"stlsq"``); ``intercept`` whether a constant b0 is fitted (default: for a column
    yes, for a rate no, ``"1"`` a candidate instead); ``forced`` terms kept whatever their
    significance; ``excluded`` candidates left out; ``parameters`` values of names the terms
    use that are not columns; ``weights`` a column of row weights; ``time`` the column of the
    rows' time for a rate (default: ``t``, else a DataFrame's index of times: seconds,
    durations, date-times in a time zone or not, integers only under a name; else the one
    column of date-times, with a warning); ``derivative``
    how a rate is estimated (default: none, the weak form); ``keep_spikes`` keeps a rate's
    rows as recorded, where by default a sample or three of a column that leap away from their
    neighbours and straight back (a glitch, not a motion) are replaced by the line through the
    neighbours, with a warning; ``intersample`` says how a rate's other columns behave between
    samples: ``"auto"`` (default) takes a column that stays put and jumps at isolated samples
    on a clock (a controller's command) as held from each sample to the next, integrated
    piece by piece between its jumps, with a warning, one that jumps off any clock (a relay) as
    switched somewhere between two samples, the windows that hold a jump left out of the fit,
    with a warning, ``"linear"`` as a line between samples,
    ``"held"`` held wherever a column jumps at isolated samples, on a clock or not; under
    ``"auto"`` and ``"held"`` a column (the state too) that changes only every few rows on a
    clock, at most of its ticks (a slower sensor's readings filled forward), is read at its
    readings and interpolated between them by cubics, with a warning (but a column whose
    changes step the rate of another there, or with which held the others' rates fit clearly
    better, is a controller's command slower than the rows, held; under ``"held"`` every column that changes at isolated rows is); a rate's rows where
    its state leaps at one row and stays (records joined) are cut there into runs of their
    own, with a warning (another column's leap alone is a step of it: not cut, its windows
    left out, with a warning);
    ``delays`` columns that act later than recorded (a dead time), in seconds, e.g.
    ``{"F": 0.2}``: read that much earlier against the rest, the rows' first seconds left out
    (without it, a rate's ``notes`` say a delay the residuals show, or a first-order lag where
    one explains them better); ``lags`` columns that act through a first-order lag (an
    actuator that follows its command as ẏ = (u − y)/T), its time constant in seconds, e.g.
    ``{"u": 0.5}``: read through it, at rest at the first value, the rows' first five time
    constants left out (after ``delays`` where both name a column); ``by`` a column that
    tells the runs of ``data`` apart (runs one after another in one frame, the long format):
    the rows of each of its values are a run of their own, as a list of runs would be.

    >>> import pandas as pd
    >>> df = pd.DataFrame({"x1": [1.0, 2, 3, 4, 5], "x2": [2.0, 1, 4, 3, 6]}).eval("y = x1 + 2*x2")
    >>> fitted = termid.fit(df, "y", ["x1", "x2"], "stepwise", step_rule="last")
    >>> fitted.coefficients.round(6).to_dict()
    {'x2': 2.0, 'x1': 1.0}
    >>> t = np.linspace(0.0, 10.0, 1001)
    >>> decay = pd.DataFrame({"x": 3.0 * np.exp(-0.5 * t)}, index=pd.Index(t, name="t"))
    >>> termid.fit(decay, "dx/dt", ["x", "x^2"]).coefficients.round(4).to_dict()
    {'x': -0.5}
    """
    rate = _RATE.match(target)
    runs = _fit_runs(data, by)
    every = [_columns(run) for _, run in runs]
    time_name = None
    if rate:
        names = {_time_of(run, columns, time, target) for (_, run), columns in zip(runs, every)}
        if len(names) > 1:
            raise TermidError(f"`{target}`: the runs keep their time in different columns ({', '.join(sorted(names))}): name it, time='name'")
        time_name = names.pop()
    _alike(runs, every)
    columns = every[0] if rate else _rows_of(every)
    if rate:
        state = rate.group(1).strip()
        if state not in columns:
            raise TermidError(f"`{target}`: no column `{state}` (columns: {', '.join(c for c in columns if c != time_name)})")
        target = f"d{state}/dt"
    elif time is not None or derivative is not None:
        raise TermidError(
            f"`{target}` is a column: `time` and `derivative` are for a rate (`d{target}/dt`)"
        )
    else:
        if target in columns.left_out:
            raise TermidError(f"column `{target}` holds {columns.left_out[target]}, not numbers: it cannot be fitted")
        if target not in columns:
            raise TermidError(f"no column `{target}` to fit (columns: {', '.join(columns)})")
    if isinstance(terms, str):
        # one term, not its characters; several where commas list them ("x*y, z")
        listed = _termid.listed([terms])
        # a formula's `x + u` (statsmodels', R's) is one candidate here, their sum: said
        summed = [t for t in listed if "+" in re.sub(r"\([^()]*\)", "", re.sub(r"\([^()]*\)", "", t))]
        if summed:
            parts = [p.strip() for p in summed[0].split("+")]
            warnings.warn(
                f"termid: terms {summed[0]!r} is one candidate, their sum with one coefficient; for a "
                f"coefficient each, list them: {parts!r} or {', '.join(parts)!r}",
                stacklevel=_outside(),
            )
        terms = listed
    if terms is None:
        terms = [c for c in columns if c not in (target, weights, time_name)]
    terms = list(terms)
    if backend is None:
        backend = "stlsq" if rate else "stepwise"
    if intercept is None:
        intercept = not rate
        # for a rate the constant is a candidate like any other, as on the command line
        if rate and "1" not in (t.strip() for t in terms):
            terms.append("1")
    try:
        native = _termid.fit(
            target,
            dict(columns),
            terms,
            _settings_text(backend, settings),
            intercept,
            list(forced),
            list(excluded),
            dict(parameters or {}),
            weights,
            time_name,
            derivative,
            keep_spikes,
            intersample,
            dict(delays or {}),
            dict(lags or {}),
            [(name, dict(c)) for (name, _), c in zip(runs, every)] if rate and len(runs) > 1 else [],
        )
    except TermidError as e:
        if rate and len(runs) == 1 and "starts again" in str(e):
            # runs one after another in one frame (a label column its tell)
            label = next(iter(columns.left_out), "run")
            raise TermidError(
                f"{e}: give them as a list, fit([run1, run2], ...), or name the column that tells them apart, by='{label}'"
            ) from None
        token = _INDEXES.set({name: run.index for name, run in runs if isinstance(run, pd.DataFrame)})
        try:
            located = _located(_explained(e, columns.left_out))
        finally:
            _INDEXES.reset(token)
        raise located from None
    return Fit(native, target)


def _is_table(data: Any) -> bool:
    """Whether ``data`` is one table of named columns: a pandas DataFrame, a pyarrow Table,
    anything with ``to_pandas`` or the Arrow PyCapsule interface (a polars DataFrame), or a
    lazy frame (polars'); a named pandas Series, one column. Such a table is one run, never a
    sequence of runs (a polars DataFrame iterates over its columns)."""
    return (
        isinstance(data, (pd.DataFrame, pd.Series))
        or hasattr(data, "column_names")
        or hasattr(data, "to_pandas")
        or hasattr(data, "__arrow_c_stream__")
        or (hasattr(data, "collect") and callable(data.collect))
    )


def _is_record(inputs: Any) -> bool:
    """Whether :meth:`Model.simulate`'s ``inputs`` change in time (a table, columns of arrays)
    rather than being constants by name."""
    if _is_table(inputs):
        return True
    return isinstance(inputs, Mapping) and any(np.ndim(v) > 0 for v in inputs.values())


def _split_by(data: Any, by: str) -> DataFrameGroupBy:
    """The rows of ``data`` (a DataFrame, a dict of arrays, a table) grouped by the values of
    column ``by``, each a run, in the order they first appear (as the command line's
    ``--by``); a row that names no run is refused."""
    if _grouped(data) is not None:
        raise TypeError("`by` tells apart the runs of one DataFrame; the grouping has told them apart already")
    if isinstance(data, pd.DataFrame):
        frame = data
    elif isinstance(data, Mapping):
        frame = pd.DataFrame(dict(data))
    elif hasattr(data, "to_pandas"):
        frame = data.to_pandas()
    elif hasattr(data, "collect") and callable(data.collect):  # a lazy frame (polars)
        return _split_by(data.collect(), by)
    elif hasattr(data, "__arrow_c_stream__"):
        import pyarrow

        frame = pyarrow.table(data).to_pandas()
    else:
        raise TypeError(f"`by` tells apart the runs of a DataFrame, a dict of arrays or a table, not {type(data).__name__}")
    if by not in frame.columns:
        raise TermidError(f"no column `{by}` to tell the runs apart (columns: {', '.join(map(str, frame.columns))})")
    blank = np.flatnonzero(frame[by].isna().to_numpy())
    if len(blank):
        # as the command line's --by: a row that names no run belongs to none
        raise TermidError(
            f"row {blank[0] + 1} (index {frame.index[blank[0]]!r}), column `{by}`: no label, so no run to put "
            f"the row in (every row of a table of several runs names its run; {len(blank)} rows so): drop or label them"
        )
    return frame.groupby(by, sort=False)


def _fit_runs(data: Union[Data, Sequence[Data]], by: Optional[str]) -> List[Tuple[str, Data]]:
    """The runs of :func:`fit`'s ``data`` by name: one run (``data``), a list of runs (each
    DataFrame's ``attrs["name"]``, else ``run1``, ...), or the rows of each value of column
    ``by`` (``run=3``), in the order they first appear, or a pandas grouping's groups."""
    if by is not None:
        return _grouped(_split_by(data, by)) or []
    grouped = _grouped(data)
    if grouped is not None:
        return grouped
    if isinstance(data, (list, tuple)):
        if not data:
            raise TermidError("no runs to fit: the list is empty")
        return [(_run_name(run, k), run) for k, run in enumerate(data)]
    return [("data", data)]


def _alike(runs: List[Tuple[str, Data]], every: List["_Columns"]) -> None:
    """Refuses runs whose columns differ from the first's, saying which."""
    first = set(every[0])
    for (name, _), columns in zip(runs[1:], every[1:]):
        missing, extra = sorted(first - set(columns)), sorted(set(columns) - first)
        if missing or extra:
            said = [f"without {', '.join(f'`{c}`' for c in missing)}"] if missing else []
            said += [f"with {', '.join(f'`{c}`' for c in extra)} besides"] if extra else []
            raise TermidError(f"run `{name}` has other columns than `{runs[0][0]}`: {'; '.join(said)}")


def _rows_of(every: List["_Columns"]) -> "_Columns":
    """The runs' rows one after another (a column explained by rows, which need no order)."""
    if len(every) == 1:
        return every[0]
    out = _Columns((name, np.concatenate([c[name] for c in every])) for name in every[0])
    out.left_out, out.times = every[0].left_out, every[0].times
    return out


def _gap_frame(gap: Mapping[str, Any]) -> pd.DataFrame:
    """A gap (per run and state: RMS and largest error) as a DataFrame indexed by run and
    state, each state's unit beside; ``attrs["cost"]`` the scaled sum of squares."""
    units = {name: unit for name, unit, *_ in gap.get("states", [])}
    rows = [
        {"run": run, "state": state, "unit": units.get(state, ""), "rms": float(rms), "max": float(largest)}
        for run, states in gap.get("runs", [])
        for state, rms, largest in states
    ]
    frame = pd.DataFrame(rows, columns=["run", "state", "unit", "rms", "max"]).set_index(["run", "state"])
    frame.attrs["cost"] = gap.get("cost")
    return frame


def _targeted(
    native: Any, data: List[Tuple[str, Any]], derivative: Optional[str], target: Optional[str], equations: List[str]
) -> List[Tuple[str, Any]]:
    """The runs as the target asks: ``"derivative"`` (or a named ``derivative`` without a
    target) leaves out the states' rate columns, which would otherwise be the targets;
    ``"column"`` requires them."""
    if target not in (None, "column", "derivative"):
        raise ValueError(f"target must be 'column', 'derivative' or None, not {target!r}")
    rates = [f"{s}_dot" for s in native.states]
    if target == "derivative" or (target is None and derivative is not None):
        kept = []
        for n, cols in data:
            less = _Columns((k, v) for k, v in cols.items() if k not in rates)
            less.left_out = getattr(cols, "left_out", {})
            kept.append((n, less))
        return kept
    if target == "column":
        wanted = equations or list(native.identifiable)
        for n, cols in data:
            missing = [r for r in rates if r in wanted and r not in cols]
            if missing:
                raise TermidError(f"{n}: target='column' but the run has no column {', '.join(missing)}")
    return data


class Identified:
    """What ``Model.identify`` returns: the identified model, each equation's fit report
    (``steps`` and ``terms`` as DataFrames) and, for a model of no field's, its ``checks``
    (name, passed, refuses, detail): that the equations retrace the runs without running away,
    and how long they follow them, that they follow them as long as their own motion from a
    nudged start follows itself (and within the records' noise where it follows itself
    throughout), that their terms hold on each half of the runs, that the
    runs' noise leaves them unbiased, and with several runs, that each alone gives the
    coefficients alike (a ship's are :meth:`Model.checks`). Where the equations
    lose their runs, their terms are chosen again by re-simulation, as :meth:`notes` says.

    >>> lorenz = termid.Model.builtin("lorenz")
    >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
    >>> found
    termid.Identified('Lorenz system (σ = 10, ρ = 28, β = 8/3)': x_dot ← dx/dt, y_dot ← dy/dt, z_dot ← dz/dt)
    >>> bool(found.checks["passed"].all())
    True
    """

    def __init__(self, model: "Model", fits: Sequence[Tuple[str, str]], checks: Sequence[Mapping[str, Any]] = ()):
        self.model = model
        self.reports: Dict[str, Dict[str, Any]] = {name: json.loads(text) for name, text in fits}
        self.checks = pd.DataFrame(list(checks), columns=["name", "passed", "refuses", "detail"])

    def steps(self, equation: str) -> pd.DataFrame:
        """The step table of ``equation``'s fit, one row per step.

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
        >>> len(found.steps("z_dot")) >= 2
        True
        """
        return pd.DataFrame(self.reports[equation].get("steps", []))

    def terms(self, equation: str) -> pd.DataFrame:
        """The terms chosen for ``equation`` with coefficient, standard error and t.

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
        >>> sorted(found.terms("z_dot")["term"])
        ['x*y', 'z']
        """
        return pd.DataFrame(self.reports[equation].get("terms", []))

    def notes(self, equation: str) -> List[str]:
        """What ``equation``'s numbers do not show (as :attr:`Fit.notes`): terms the rows
        cannot tell from a candidate left out, collinear or conserved variables, coarse samples.

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> lorenz.identify(lorenz.simulate(duration=5.0)).notes("z_dot")
        []
        """
        return list(self.reports[equation].get("notes", []))

    def rivals(self, equation: str) -> pd.DataFrame:
        """Each term chosen for ``equation`` with its closest rival among the candidates left
        out and the rise of the residual sum of squares in its place (as :attr:`Fit.rivals`).

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> sorted(lorenz.identify(lorenz.simulate(duration=5.0)).rivals("z_dot").index)
        ['x*y', 'z']
        """
        return _rivals_frame(self.reports[equation])

    def chosen_step(self, equation: str) -> Optional[int]:
        """The step the back-end chose for ``equation`` (None for back-ends without steps).

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
        >>> found.chosen_step("z_dot") is None or found.chosen_step("z_dot") >= 1
        True
        """
        return self.reports[equation].get("chosen_step")

    @property
    def targets(self) -> Dict[str, str]:
        """What each equation explained: a column of the runs (``r_dot``) or a derivative
        estimated from them (``dr/dt``).

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
        >>> found.targets["z_dot"]
        'dz/dt'
        """
        return {name: str(r.get("target", "")) for name, r in self.reports.items()}

    def __repr__(self) -> str:
        told = ", ".join(f"{name} ← {t}" for name, t in self.targets.items())
        return f"termid.Identified({self.model.name!r}: {told})"

    def __str__(self) -> str:
        """What ``print`` (and a notebook) shows: the identified equations and the checks, each
        as the command line writes it (``ok``, ``FLAG``, ``FAIL``)."""
        lines = [str(self.model)]
        if len(self.checks):
            lines.append("checks:")
            for _, c in self.checks.iterrows():
                lines.append("  " + _termid.check_line(c["name"], bool(c["passed"]), bool(c["refuses"]), c["detail"]))
        return "\n".join(lines)

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        # IPython and notebooks show what print shows; repr() stays the one-line summary
        printer.text(repr(self) if cycle else str(self))


class Recipe:
    """What :meth:`Model.recipe` returns: the kept ``model``, a DataFrame of the ``starts``
    (derivative, refused checks, re-simulation cost, which is kept, and ``parameters``: whether
    its estimate with the model file's free parameters was ``"kept"``, ``"rejected"`` by the
    checks or ``"failed"``, None where not run), the kept model's
    ``checks`` (with the starts' agreement: a failing one flags a prediction the runs
    cannot pin down), ``refusals`` (why it must not be written, if any), ``warnings`` (what
    the recipe warned about: failed starts, disagreeing starts, a refinement rejected or
    failed, the kept model's flags), ``failed`` (each failed start and why), the ``report`` as
    plain values and as ``text``, and the kept start's estimate of the model file's free
    ``parameters`` (the report's ``parameter_estimate``: each parameter, and under
    ``per_source`` each source's or run's; None where not run or not kept).

    >>> ship = termid.Model.default()
    >>> runs = [ship.simulate(m) for m in ("zigzag:20/20", "zigzag:10/10")]
    >>> found = ship.recipe(runs, ["central"], smooth=False, intercept=True, refine=None)
    >>> found.refusals, bool(found.checks["passed"].all())
    ([], True)
    """

    def __init__(self, model: "Model", report: Mapping[str, Any], text: str):
        self.model = model
        self.starts = pd.DataFrame(report["starts"])
        self.checks = pd.DataFrame(report["checks"])
        self.refusals: List[str] = list(report["refusals"])
        self.failed = list(report["failed"])
        self.warnings: List[str] = list(report["warnings"])
        self.report = report["report"]
        self.parameters: Optional[Mapping[str, Any]] = self.report.get("parameter_estimate")
        self.text = text

    def __str__(self) -> str:
        return self.text

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        # IPython and notebooks show the report, as the command line prints it
        printer.text(repr(self) if cycle else str(self))

    def __repr__(self) -> str:
        kept = self.starts.loc[self.starts["kept"], "derivative"].tolist()
        flags = int((~self.checks["passed"]).sum()) if len(self.checks) else 0
        return f"termid.Recipe(kept {kept[0] if kept else None!r} of {len(self.starts)} starts, {flags} checks not passed)"



def _equation_text(target: str, intercept: Optional[float], terms: Iterable[Tuple[str, float]], precision: int) -> str:
    """``target = b0 + c1 term1 + ...``, each number to ``precision`` significant digits: the
    constant candidate ``1`` its coefficient alone (it read ``-9.81 1``), a sum one term in
    parentheses."""
    parts = [] if intercept is None else [f"{intercept:.{precision}g}"]
    for term, value in terms:
        if term == "1":
            parts.append(f"{value:.{precision}g}")
        else:
            shown = f"({term})" if re.search(r".[+-] ", term) else term
            parts.append(f"{value:.{precision}g} {shown}")
    return f"{target} = " + (" + ".join(parts) if parts else "0").replace("+ -", "- ")


def _particulars(particulars: Union[Mapping[str, Any], str, os.PathLike]) -> Tuple[Any, str, List[str]]:
    """The native model, estimates (JSON) and cautions for a particulars file or dict."""
    if isinstance(particulars, Mapping):
        return _termid.Model.from_particulars(json.dumps(dict(particulars)), True, "<dict>")
    path = os.fspath(particulars)
    if not os.path.exists(path):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), path)
    with open(path, encoding="utf-8") as f:
        return _termid.Model.from_particulars(f.read(), False, path)

def _unpickled(text: str, path: str, from_states: bool, outline: Optional[str] = None) -> "Model":
    """A pickled :class:`Model` read back: its file's text, whether it was made from states,
    and the outline it was made from (its library not yet about the runs' reference values)."""
    native = _termid.Model.parse(text, path)
    if outline is not None:
        native = native.with_outline(outline)
    return Model(native, from_states)


class Model:
    """A termid model file: states, inputs, parameters, derived variables and equations.

    Load one (``Model.load``), take the default ship (``Model.default()``), identify its
    equations from runs, simulate it and write it back (``save``, ``to_toml``).

    >>> termid.Model.builtin("lorenz")
    termid.Model("Lorenz system (σ = 10, ρ = 28, β = 8/3)": 3 equations, 3 states)
    """

    def __init__(self, native: Any, from_states: bool = False):
        self._native = native
        # made by from_states: identify starts its states where the first run starts
        self._from_states = from_states

    # ---- files
    @staticmethod
    def load(path: Union[str, os.PathLike]) -> "Model":
        """Reads a model file; errors name the file, line and key (a missing file is
        FileNotFoundError, as for ``open``).

        Parameters: ``path`` the TOML model file.

        >>> import os, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "lorenz.toml")
        >>> termid.Model.builtin("lorenz").save(path)
        >>> termid.Model.load(path).states
        ['x', 'y', 'z']
        """
        path = os.fspath(path)
        if not os.path.exists(path):
            raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), path)
        return Model(_termid.Model.load(path))

    @staticmethod
    def from_toml(text: str, name: str = "<text>") -> "Model":
        """A model from the TOML ``text`` of a model file; errors name ``name`` as the file.

        >>> text = termid.Model.builtin("lorenz").to_toml()
        >>> termid.Model.from_toml(text, "lorenz.toml").equations
        ['x_dot', 'y_dot', 'z_dot']
        """
        return Model(_termid.Model.parse(text, name))

    @staticmethod
    def from_states(
        states: Sequence[str],
        inputs: Sequence[str] = (),
        terms: Optional[Sequence[str]] = None,
        *,
        degree: Optional[int] = None,
        time: str = "t",
        name: Optional[str] = None,
    ) -> "Model":
        """A model of a system known only by its columns, to identify whole (as SINDy fits a
        system): an equation for each state's rate, each over the same candidates — ``terms``
        (text in termid's term language over the states and inputs), or every monomial of the
        states and ``inputs`` to ``degree``, the constant among them — selected by sequential
        thresholding (or :meth:`identify`'s ``backend``), as ``termid identify --states`` makes
        it. ``inputs`` are the columns that drive the states (a force, a setpoint), known from
        the runs. A state the runs do not record, the rate of one they do, is written ``"v=dx/dt"``
        (a position recorded alone: ``["x", "v=dx/dt"]``): each run gets it estimated from ``x``'s
        record by the Kalman smoother (a warning says so), ``x``'s equation is the kinematic
        ẋ = v, and v's is identified. :meth:`identify` (and :meth:`recipe`) starts the identified model's states where the
        first run starts, so that :meth:`simulate` retraces that run's beginning; :meth:`save` writes it.
        A state or input the runs hold more than 10 spreads from 0 (a temperature in kelvin) is
        written about a round reference value in the library, as the paper's Δu = u - u0: a
        parameter ``T0``, a derived ``ΔT = T - T0`` and the monomials of ``ΔT`` (a note says so).

        Parameters: ``states`` the state columns; ``inputs`` the input columns; ``terms`` the
        candidates (default: the polynomial library); ``degree`` the polynomial library's (default 3, as the ODE benchmark that chose termid's
        defaults; not with ``terms``);
        ``time`` the time column; ``name`` the model's (default: the states).

        >>> truth = termid.Model.builtin("lorenz").simulate(duration=10.0, sample=0.01)
        >>> found = termid.Model.from_states(["x", "y", "z"]).identify(truth[["t", "x", "y", "z"]])
        >>> found.model.coefficients("z_dot")[["term", "value"]].round(3).values.tolist()
        [['x*y', 1.0], ['z', -2.667]]
        >>> again = found.model.simulate(duration=1.0, sample=0.01)
        >>> float(abs(again["x"].iloc[-1] - truth["x"].iloc[100])) < 1e-3
        True
        """
        if isinstance(states, str) or isinstance(inputs, str) or isinstance(terms, str):
            raise TypeError("states, inputs and terms are lists of names (['x', 'y']), not one string")
        if degree is not None and (isinstance(degree, bool) or int(degree) != degree or degree < 0):
            raise TermidError(f"Model.from_states: degree {degree!r} is no degree: give a whole number, 1 or more")
        # a state the runs do not record, written as another's rate (`v=dx/dt`), by its name
        named = [str(s).split("=")[0].strip() for s in states]
        for column in [*named, *inputs]:
            # a dataframe's `tank level`: the remedy in pandas, not in a dataset file
            fixed = re.sub(r"\W", "_", str(column))
            if not str(column).isidentifier() and fixed.isidentifier():
                raise TermidError(
                    f"Model.from_states: `{column}` is not a valid name (a name is letters, digits and `_`, not a "
                    f"digit first): rename its column, df.rename(columns={{'{column}': '{fixed}'}}), and call it `{fixed}`"
                )
        native = _termid.Model.from_states(
            list(states),
            list(inputs),
            list(terms or []),
            None if degree is None else int(degree),
            time,
            name or ", ".join(states),
        )
        return Model(native, from_states=True)

    @staticmethod
    def builtin(name: str) -> "Model":
        """A model file shipped inside the package: ``oltmann1973``, ``lorenz``, ``duffing``,
        ``mmg_kvlcc2`` (KVLCC2 in the MMG standard model), ``nomoto`` (Nomoto's steering model
        with K and T free, for :meth:`estimate`), ``robertson`` (Robertson's stiff chemical
        kinetics, rate constants ``k1``, ``k2``, ``k3``) or ``new_ship`` (the template), by
        ``name`` (:meth:`builtin_names`).

        >>> termid.Model.builtin("lorenz").states
        ['x', 'y', 'z']
        """
        return Model(_termid.Model.builtin(name))

    @staticmethod
    def from_particulars(particulars: Union[Mapping[str, Any], str, os.PathLike]) -> "Model":
        """A grey-box MMG model for a ship nobody has tested yet, from its main particulars:
        the hull's derivatives from Kijima et al. (1990) and Clarke et al. (1982), the rudder's
        and propeller's from the MMG formulas (Yasukawa & Yoshimura 2015), each free with a
        prior for :meth:`estimate` (as ``termid new-ship`` writes it). A warning says where the
        proportions lie outside the formulas' merchant hulls.

        Parameters: ``particulars`` a particulars file (TOML: ``name``, ``lpp``, ``beam``,
        ``draught``, ``block_coefficient``, ``x_g``, ``rudder_area``, ``rudder_span``,
        ``propeller_diameter``, ``u0``, ``rudder_rate``, ``rudder_limit``, ``density``,
        optionally ``kt``; SI units, degrees) or a dict of the same keys. Each estimate with
        its prior and source: :meth:`particulars_table`.

        >>> ship = {"name": "KVLCC2", "lpp": 7.0, "beam": 1.27, "draught": 0.46,
        ...         "block_coefficient": 0.81, "x_g": 0.25, "rudder_area": 0.0539,
        ...         "rudder_span": 0.345, "propeller_diameter": 0.216, "u0": 1.17,
        ...         "rudder_rate": 15.8, "rudder_limit": 35.0, "density": 1025.0}
        >>> model = termid.Model.from_particulars(ship)
        >>> model.states[:3], len(model.free_parameters) > 20
        (['u', 'v', 'r'], True)
        """
        native, _, cautions = _particulars(particulars)
        for caution in cautions:
            warnings.warn(f"termid: {caution}", stacklevel=_outside())
        return Model(native)

    @staticmethod
    def particulars_table(particulars: Union[Mapping[str, Any], str, os.PathLike]) -> pd.DataFrame:
        """Each parameter :meth:`from_particulars` sets for a ship: its estimate, the prior's
        sd (NaN where the value is fixed), its unit and the formula's source, by parameter.

        Parameters: ``particulars`` as for :meth:`from_particulars`.

        >>> ship = {"name": "KVLCC2", "lpp": 7.0, "beam": 1.27, "draught": 0.46,
        ...         "block_coefficient": 0.81, "x_g": 0.25, "rudder_area": 0.0539,
        ...         "rudder_span": 0.345, "propeller_diameter": 0.216, "u0": 1.17,
        ...         "rudder_rate": 15.8, "rudder_limit": 35.0, "density": 1025.0}
        >>> table = termid.Model.particulars_table(ship)
        >>> round(float(table.loc["Y_v", "value"]), 3), table.loc["Y_v", "source"].startswith("Kijima")
        (-0.412, True)
        """
        _, estimates, _ = _particulars(particulars)
        table = pd.DataFrame(json.loads(estimates), columns=["name", "value", "prior_sd", "unit", "source"])
        table["prior_sd"] = table["prior_sd"].astype(float)
        return table.set_index("name")

    @staticmethod
    def builtin_names() -> List[str]:
        """The names of the model files shipped inside the package.

        >>> "oltmann1973" in termid.Model.builtin_names()
        True
        """
        return list(_termid.Model.builtin_names())

    @staticmethod
    def default() -> "Model":
        """Oltmann's (1973) HSVA 1512 with the coefficients of his Table 2.

        >>> termid.Model.default().states
        ['u', 'v', 'r', 'ψ', 'x0', 'y0']
        """
        return Model(_termid.Model.default_model())

    def to_toml(self) -> str:
        """The model file's text (what :meth:`save` writes).

        >>> "[model]" in termid.Model.builtin("lorenz").to_toml()
        True
        """
        return self._native.to_toml()

    def _identified(self, native: Any, runs: List[Tuple[str, Dict[str, np.ndarray]]]) -> "Model":
        """The model ``native`` identified from ``runs`` by this one: made from states, it
        starts where the first run starts."""
        if self._from_states and runs:
            native = native.starting_as(runs[0])
        return Model(native, self._from_states)

    def __reduce__(self) -> Tuple[Any, Tuple[str, str, bool, Optional[str]]]:
        # pickled as its file's text (a process pool, Dask), read back as it was written
        return (_unpickled, (self.to_toml(), self._native.path, self._from_states, self._native.outline_json()))

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the model file to ``path`` (identified coefficients with their standard
        errors and covariance).

        >>> import os, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "ship.toml")
        >>> termid.Model.default().save(path)
        >>> os.path.getsize(path) > 1000
        True
        """
        self._native.save(os.fspath(path))

    # ---- what it is
    @property
    def name(self) -> str:
        """The model's name (``[model] name``).

        >>> termid.Model.builtin("duffing").name
        'Forced Duffing oscillator (ζ = 0.05, ω = 1, α = 0.2)'
        """
        return self._native.name

    @property
    def path(self) -> str:
        """The file the model was read from (``<builtin>``-like names for the shipped ones).

        >>> isinstance(termid.Model.builtin("lorenz").path, str)
        True
        """
        return self._native.path

    @property
    def time(self) -> str:
        """The name of the time column runs carry (``[model] time``).

        >>> termid.Model.builtin("lorenz").time
        't'
        """
        return self._native.time

    @property
    def states(self) -> List[str]:
        """The states, in the model file's order.

        >>> termid.Model.builtin("lorenz").states
        ['x', 'y', 'z']
        """
        return list(self._native.states)

    @property
    def inputs(self) -> List[str]:
        """The inputs (recorded, not simulated: a rudder angle, a forcing).

        >>> termid.Model.default().inputs
        ['δ']
        """
        return list(self._native.inputs)

    @property
    def equations(self) -> List[str]:
        """The equations by name, one per state.

        >>> termid.Model.builtin("lorenz").equations
        ['x_dot', 'y_dot', 'z_dot']
        """
        return list(self._native.equations)

    @property
    def identifiable(self) -> List[str]:
        """The equations that have candidate terms (those :meth:`identify` fits).

        >>> termid.Model.default().identifiable
        ['u_dot', 'v_dot', 'r_dot']
        """
        return list(self._native.identifiable)

    def candidates(self, equation: str) -> List[str]:
        """The candidate terms of ``equation`` that :meth:`identify` selects from.

        Parameters: ``equation`` its name (``x_dot``).

        >>> termid.Model.from_states(["x"], degree=2).candidates("x_dot")
        ['1', 'x', 'x^2']
        """
        return list(self._native.candidates(equation))

    def with_terms(self, forced: Sequence[str] = (), excluded: Sequence[str] = ()) -> "Model":
        """The model with ``forced`` terms entering first and ``excluded`` ones never, in every
        identified equation that has them among its candidates (as ``termid identify
        --forced``/``--exclude``); a term that no such equation has raises ``TermidError``.
        Where the runs keep a law (an epidemic's S + I + R, said in the fit's notes,
        ``found.reports["I_dot"]["notes"]``, when noise blurs it), leaving out the candidates in one of its variables writes the
        rates in the others.

        Parameters: ``forced`` terms that always enter; ``excluded`` terms that never do.

        >>> sir = termid.Model.from_states(["S", "I", "R"], degree=2).with_terms(excluded=["R", "I*R", "R*S", "R^2"])
        >>> "excluded" in sir.to_toml() and "excluded" not in termid.Model.from_states(["S"]).to_toml()
        True
        """
        if isinstance(forced, str) or isinstance(excluded, str):
            raise TypeError("forced and excluded are lists of terms (['x*y']), not one string")
        return Model(self._native.with_terms(list(forced), list(excluded)), self._from_states)

    @property
    def parameters(self) -> Dict[str, float]:
        """The named parameters and their values.

        >>> termid.Model.builtin("lorenz").parameters
        {}
        """
        return dict(self._native.parameters)

    @property
    def free_parameters(self) -> List[str]:
        """The parameters the model file declares free (``free = true``): those
        :meth:`estimate` fits.

        >>> termid.Model.builtin("nomoto").free_parameters
        ['K', 'T']
        """
        return list(self._native.free_parameters)

    def set_parameter(self, name: str, value: Union[float, str]) -> None:
        """A parameter's value, or as text how each run sets it for identification
        (``ship.set_parameter("u0", "mean:u:4")``: the mean of u over a record's first 4 s).

        Parameters: ``name`` the parameter; ``value`` a number, or the per-run rule as text.

        >>> ship = termid.Model.default()
        >>> ship.set_parameter("u0", 1.2)
        >>> ship.parameters["u0"]
        1.2
        """
        if isinstance(value, str):
            self._native.set_per_run(name, value)
        else:
            self._native.set_parameter(name, float(value))

    def set_tolerances(self, rtol: Optional[float] = None, atol: Optional[float] = None) -> None:
        """The adaptive integrator's tolerances for this model's simulations, each where
        given (defaults: the model file's ``[simulation]`` table, else ``rtol`` 1e-6 and
        ``atol`` 1e-7, in each state's unit); raises ``TermidError`` where no step control
        works with them (``rtol`` outside (0, 1), ``atol`` below 0).

        Parameters: ``rtol`` the relative tolerance; ``atol`` the absolute tolerance.

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> lorenz.set_tolerances(rtol=1e-10, atol=1e-12)
        >>> round(float(lorenz.simulate(duration=1.0, sample=0.5)["x"].iloc[-1]), 6)
        5.523677
        """
        self._native.set_tolerances(rtol, atol)

    def coefficients(self, equation: str) -> pd.DataFrame:
        """The stored terms of ``equation`` with value and standard error (float64, NaN where
        none is stored).

        >>> termid.Model.builtin("lorenz").coefficients("z_dot")["term"].tolist()
        ['x*y', 'z']
        """
        rows = self._native.coefficients(equation)
        # a missing standard error is NaN, so the column stays float64 (not object)
        return pd.DataFrame(rows, columns=["term", "value", "std_error"]).astype({"value": float, "std_error": float})

    def intercept(self, equation: str) -> Optional[float]:
        """The stored constant of ``equation``, or None.

        >>> termid.Model.builtin("lorenz").intercept("x_dot") is None
        True
        """
        return self._native.intercept(equation)

    def set_coefficients(
        self, equation: str, coefficients: Union[Mapping[str, float], pd.Series, pd.DataFrame], intercept: Optional[float] = None
    ) -> None:
        """Replaces an equation's terms and coefficients: ``{"u*v": -0.23, ...}``, a Series
        indexed by term, or a DataFrame like ``coefficients()`` returns.

        Parameters: ``equation`` its name; ``coefficients`` the new terms and values;
        ``intercept`` the new constant (None: none).

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> lorenz.set_coefficients("z_dot", {"x*y": 1.0, "z": -2.5})
        >>> lorenz.coefficients("z_dot")["value"].tolist()
        [1.0, -2.5]
        """
        if isinstance(coefficients, pd.DataFrame):
            rows = [(str(t), float(v), None if pd.isna(s) else float(s))
                    for t, v, s in zip(coefficients["term"], coefficients["value"], coefficients.get("std_error", [None] * len(coefficients)))]
        else:
            rows = [(str(t), float(v), None) for t, v in dict(coefficients).items()]
        self._native.set_coefficients(equation, rows, intercept)

    # ---- identification
    @_runs_told_apart
    def identify(
        self,
        runs: Union[Data, Sequence[Data]],
        derivative: Optional[str] = None,
        *,
        target: Optional[str] = None,
        equations: Sequence[str] = (),
        intercept: Optional[bool] = None,
        backend: Optional[str] = None,
        names: Optional[Sequence[str]] = None,
        laws: bool = True,
        random_force: bool = True,
        dead_times: bool = True,
        **settings: Any,
    ) -> Identified:
        """Every identifiable equation (or ``equations``) from ``runs`` (one run or a list:
        DataFrames, dicts of arrays, Arrow tables), with the model's
        candidates, forced terms and back-end (or ``backend`` with its settings as keywords).
        A model of no field's (``from_states``, a file of no plug-in) is identified as
        ``termid identify`` identifies it, by :meth:`recipe` with one start: a power that stands
        in for a law of a state or an input tried with the laws (``laws``), a random force
        (``random_force``), inputs found late identified again so (``dead_times``); False keeps
        each as the regression has it.

        ``target``: ``"column"`` explains the runs' rate columns (``r_dot``), ``"derivative"``
        the states' derivatives estimated by ``derivative``; by default the rate columns where
        the runs have them and no ``derivative`` is named, else the derivatives
        (:attr:`Identified.targets` says which). ``derivative`` defaults to ``weak`` (the
        weak form: no derivative estimated; central differences for a ship, as the
        paper); ``intercept`` to the model file's (``[model] intercept``); ``names`` name the
        runs (default: each DataFrame's ``attrs["name"]``, else ``run1``, ...).

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> found = lorenz.identify(lorenz.simulate(duration=5.0))
        >>> found.targets["z_dot"], found.model.coefficients("z_dot")["value"].round(2).tolist()
        ('dz/dt', [1.0, -2.67])
        """
        data = _targeted(self._native, _runs(runs, names, self.time), derivative, target, list(equations))
        try:
            native, fits, checks = self._native.identify(
                data,
                derivative,
                list(equations),
                intercept,
                _backend(backend, settings),
                laws,
                random_force,
                dead_times,
            )
        except TermidError as e:
            left_out = {n: k for _, cols in data for n, k in getattr(cols, "left_out", {}).items()}
            raise _explained(e, left_out) from None
        return Identified(self._identified(native, data), fits, json.loads(checks))

    @_runs_told_apart
    def moments(
        self,
        equation: Union[str, Sequence[str]],
        runs: Union[Data, Sequence[Data]],
        derivative: Optional[str] = None,
        names: Optional[Sequence[str]] = None,
        *,
        target: Optional[str] = None,
    ) -> Any:
        """The sufficient statistics of ``equation`` over ``runs`` (see :class:`Moments`); given a
        list of equations, a dict of each one's, the runs read once for all. ``derivative``
        and ``target`` as for :meth:`identify`, ``names`` the runs' names.

        >>> ship = termid.Model.default()
        >>> m = ship.moments("r_dot", ship.simulate("zigzag:20/20"))
        >>> m.equation, m.rows > 1000
        ('r_dot', True)
        """
        wanted = [equation] if isinstance(equation, str) else list(equation)
        data = _targeted(self._native, _runs(runs, names, self.time), derivative, target, wanted)
        found = self._native.moments(wanted, data, derivative)
        return found[0] if isinstance(equation, str) else dict(zip(wanted, found))

    def identify_from_moments(self, moments: Union["Moments", Sequence["Moments"]], intercept: Optional[bool] = None) -> Identified:
        """The model identified from statistics, merged per equation in the order given:
        the same model as from the rows together. ``moments``: one or a list (of several
        equations, or of parts to merge); ``intercept`` as for :meth:`identify`. A model of no
        field's is checked as statistics allow (``checks``: its terms on each half of the runs,
        the runs' noise; failed checks warned of); whether it retraces the runs needs them
        (:meth:`checks`).

        >>> ship = termid.Model.default()
        >>> parts = [ship.moments("r_dot", ship.simulate(z)) for z in ("zigzag:20/20", "zigzag:10/10")]
        >>> found = ship.identify_from_moments(parts[0] + parts[1])
        >>> found.targets["r_dot"]
        'r_dot'
        """
        if isinstance(moments, _termid.Moments):
            moments = [moments]
        native, fits, checks = self._native.identify_from_moments(list(moments), intercept)
        return Identified(Model(native), fits, json.loads(checks))

    # ---- prediction and simulation
    def predict(self, run: Data, with_intercept: bool = False) -> pd.DataFrame:
        """ẋ of every state on every row of a run (columns named as the equations, else
        ``<state>_dot``), on the run's index (a DataFrame's). ``run`` holds the states and
        inputs; ``with_intercept`` adds the identified constants.

        >>> lorenz = termid.Model.builtin("lorenz")
        >>> lorenz.predict(pd.DataFrame({"t": [0.0], "x": [1.0], "y": [2.0], "z": [3.0]}))
           x_dot  y_dot  z_dot
        0   10.0   23.0   -6.0
        """
        frame = _frame(self._native.predict(_runs(run, time=self.time)[0], with_intercept))
        if isinstance(run, pd.DataFrame):
            frame.index = run.index
        return frame

    def simulate(
        self,
        scenario: Optional[str] = None,
        *,
        dt: Optional[float] = None,
        duration: Optional[float] = None,
        sample: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        inputs: Union[Mapping[str, float], Data, None] = None,
        initial: Optional[Mapping[str, float]] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
    ) -> pd.DataFrame:
        """A plug-in's ``scenario`` (``zigzag:20/20``, ``turning:35``, ``spiral``): the run as a
        DataFrame (SI, radians), its metrics in ``df.attrs["metrics"]``. Without a scenario,
        any model (Lorenz, a pendulum): from its initial states (or ``initial``) with constant
        ``inputs`` for ``duration`` seconds, or under ``inputs`` that change in time: a
        DataFrame (or table) of the inputs over its time (a column ``t``, the model's time, or
        an index of times), replayed as :meth:`replay` replays a run's (held where the record
        shows a controller's command), at its rows, for its span (or the first ``duration``
        seconds of it). A model whose time is named by its unit (``day``, an epidemic's day
        count) takes ``duration``, ``sample`` and ``dt`` in that unit, as its run's time column.

        Parameters: ``dt`` the integration step (default: the model file's method, else
        adaptive Dormand-Prince 5(4) with output every ``sample`` seconds); ``integrator``
        ``dopri5`` (linearly implicit where it finds the model stiff, with a warning),
        ``rosenbrock`` (stiff models), ``rk4`` or ``b8``; ``with_intercept`` adds the identified
        constants;
        ``rtol``, ``atol`` the adaptive method's tolerances for this run (else the model's:
        :meth:`set_tolerances`).

        >>> run = termid.Model.default().simulate("zigzag:20/20")
        >>> round(run.attrs["metrics"]["first_overshoot_deg"], 1)
        11.2
        >>> termid.Model.builtin("lorenz").simulate(duration=1.0, sample=0.5)["t"].tolist()
        [0.0, 0.5, 1.0]
        """
        if rtol is not None or atol is not None:
            # this run's tolerances on a copy: the model keeps its own
            model = Model.from_toml(self.to_toml(), self._native.path)
            model.set_tolerances(rtol, atol)
            return model.simulate(
                scenario,
                dt=dt,
                duration=duration,
                sample=sample,
                integrator=integrator,
                with_intercept=with_intercept,
                inputs=inputs,
                initial=initial,
            )
        if inputs is not None and _is_record(inputs):
            if scenario is not None:
                raise TypeError("inputs and initial apply without a scenario; a scenario sets its own")
            if sample is not None:
                raise TypeError("inputs that change in time are simulated at their own rows: `sample` does not apply")
            return self._under(inputs, initial, duration, dt, integrator, with_intercept)
        if scenario is None:
            if duration is None:
                raise TypeError("simulate without a scenario needs a duration (seconds)")
            columns = self._native.simulate_free(
                duration, dict(inputs or {}), dict(initial or {}), dt, sample, integrator, with_intercept
            )
            return _frame(columns)
        if inputs or initial:
            raise TypeError("inputs and initial apply without a scenario; a scenario sets its own")
        columns, metrics, label, text = self._native.simulate(scenario, dt, duration, sample, integrator, with_intercept)
        frame = _frame(columns)
        frame.attrs.update(name=label, metrics=json.loads(metrics), report=list(text))
        return frame

    def _under(
        self,
        inputs: Data,
        initial: Optional[Mapping[str, float]],
        duration: Optional[float],
        dt: Optional[float],
        integrator: Optional[str],
        with_intercept: bool,
    ) -> pd.DataFrame:
        """:meth:`simulate` under a record of inputs: a run of them with the states at their
        initial values, replayed from there."""
        (name, columns), = _runs(inputs)
        if self.time not in columns:
            try:
                _time_from(name, inputs, columns, self.time)
            except TermidError as e:
                raise TermidError(
                    f"inputs that change in time need their time, a column `{self.time}` or an index of times: {e}"
                ) from None
        unknown = [c for c in columns if c != self.time and c not in self.inputs]
        if unknown:
            raise TermidError(
                f"{', '.join(f'`{c}`' for c in unknown)}: not an input of the model ({', '.join(self.inputs)})"
            )
        start = {**self._native.initial, **(initial or {})}
        wrong = [s for s in start if s not in self.states]
        if wrong:
            raise TermidError(f"initial `{wrong[0]}`: not a state of the model ({', '.join(self.states)})")
        frame = pd.DataFrame(dict(columns))
        if duration is not None:
            frame = frame[frame[self.time] <= frame[self.time].iloc[0] + duration]
        frame = frame.assign(**{s: start[s] for s in self.states})
        frame.attrs["name"] = name
        return self.replay(frame, dt=dt, integrator=integrator, with_intercept=with_intercept)[0]

    def draws(self, n: int, *, seed: int = 1) -> List["Model"]:
        """``n`` models drawn from the stored covariances (seeded by ``seed``), as ``simulate
        --monte-carlo`` draws them: each identified equation's coefficients from its
        covariance widened by the residuals' correlation time, and the free parameters from
        theirs (a per-run parameter with a new run's spread). Raises where the model stores no
        covariance, and where ``n`` models would not fit in memory (a model takes about seven
        times its file's length). For the spread of a scenario's metrics see :meth:`monte_carlo`.

        >>> truth = termid.Model.builtin("nomoto"); truth.set_parameter("K", 0.15)
        >>> run = truth.simulate(duration=30.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]]
        >>> run["ψ"] += np.random.default_rng(1).normal(0.0, 0.002, len(run))
        >>> _, found = termid.Model.builtin("nomoto").estimate(run)
        >>> ks = [m.parameters["K"] for m in found.draws(50)]
        >>> bool(abs(np.mean(ks) - 0.15) < 0.01 and np.std(ks) > 0)
        True
        """
        return [Model(native) for native in self._native.draws(n, seed)]

    def monte_carlo(self, scenario: str, n: int = 100, *, seed: int = 1, **simulate: Any) -> pd.DataFrame:
        """The spread of a plug-in ``scenario``'s metrics over ``n`` drawn models
        (:meth:`draws` with ``seed``, each simulated as :meth:`simulate` with ``simulate``'s keywords): a
        DataFrame of the metrics, a row per draw that ran (``describe()`` gives mean, sd and
        percentiles); ``attrs``: ``nominal`` (the model's own metrics), ``draws``, ``failed``,
        ``first_failure``; where the model holds its free parameters' covariance (an
        :meth:`estimate`'s), what the spread comes from, each parameter one sd up and down, the
        others at their estimates: ``parameter_effects`` (a parameter per row, the half change of
        each metric), ``spread_from`` (a metric per row, the share of its variance that knowing
        each parameter exactly would remove, linearised; correlated parameters share theirs)
        and ``linearised_sd`` (each metric's sd from them together, near the draws' where the
        metric is about linear in the parameters). Where more than 5 % of the draws fail, the rest are
        those that happened to stay stable, not a sample of the model's uncertainty: it raises
        :class:`TermidError` saying so instead of returning them (``draws`` gives them to
        whoever wants them still).

        >>> ship = termid.Model.default()
        >>> found = ship.identify([ship.record("zigzag:20/20", seed=1), ship.record("zigzag:20/20:port", seed=2)], "kalman")
        >>> spread = found.model.monte_carlo("zigzag:20/20", 20)
        >>> len(spread), spread.attrs["failed"]
        (20, 0)
        """
        nominal = self.simulate(scenario, **simulate).attrs.get("metrics", {})
        rows, failed, first = [], 0, None
        for model in self.draws(n, seed=seed):
            try:
                rows.append(model.simulate(scenario, **simulate).attrs.get("metrics", {}))
            except TermidError as e:
                failed += 1
                first = first or str(e)
        refusal = _termid.monte_carlo_refusal(n, len(rows), first)
        if refusal is not None:
            raise TermidError(refusal)
        table = pd.DataFrame(rows)
        table.attrs = {"nominal": nominal, "draws": n, "failed": failed, "first_failure": first}
        # what the spread comes from: each free parameter one sd up and down (where the model
        # holds the free parameters' covariance)
        def predict(native: Any) -> str:
            return json.dumps(Model(native).simulate(scenario, **simulate).attrs.get("metrics", {}))

        found = json.loads(self._native.spread_from(predict))
        effects = {e["parameter"]: e["effects"] for e in found["effects"] if e["failed"] is None}
        table.attrs["parameter_effects"] = pd.DataFrame.from_dict(effects, orient="index")
        table.attrs["spread_from"] = pd.DataFrame.from_dict(
            {k: dict(a["explained"]) for k, a in found["attribution"].items()}, orient="index"
        )
        table.attrs["linearised_sd"] = pd.Series(
            {k: a["linearised_sd"] for k, a in found["attribution"].items()}, dtype=float
        )
        for e in found["effects"]:
            if e["failed"] is not None:
                warnings.warn(
                    f"termid: one sd from its estimate, `{e['parameter']}` leaves no prediction: {e['failed']}",
                    stacklevel=_outside(),
                )
        return table

    def record(
        self,
        manoeuvre: str,
        *,
        speed: float = 1.0,
        duration: float = 100.0,
        seed: int = 0,
        tracked: bool = False,
        truth: bool = False,
    ) -> pd.DataFrame:
        """A ship's ``manoeuvre`` recorded as in termid's synthetic basin: 20 Hz, a straight
        approach, sensor noise fixed by ``seed``, approach speed ``speed`` × u0 (``tracked``:
        u and v from an optical track, a rudder offset, the rudder back at midship). The
        measured run, or with ``truth`` the noise-free one; ``duration`` in seconds.

        >>> run = termid.Model.default().record("zigzag:20/20", seed=3)
        >>> float(run["t"].diff().iloc[1])
        0.05
        """
        measured, exact = self._native.record(manoeuvre, speed, duration, seed, tracked)
        frame = _frame(exact if truth else measured)
        frame.attrs["name"] = f"{manoeuvre}#{seed}"
        return frame

    @_runs_told_apart
    def about_references(self, runs: Union[Data, Sequence[Data]], names: Optional[Sequence[str]] = None) -> "Model":
        """The model made from states (:meth:`from_states`) with its polynomial library written
        about round reference values where ``runs`` hold a state or input more than 10 spreads
        from 0 (``T0``, ``ΔT = T - T0``; a note as a warning), as :meth:`identify` and
        :meth:`recipe` write it by themselves; either way the library is decided, not again
        on later runs. For statistics
        gathered in parts (:meth:`moments` on shards, Dask), which keep the library as it is
        written: decide it once, on a sample, before the parts are sent out.

        Parameters: ``runs`` the runs (or a sample of them) the references are taken from;
        ``names`` name the runs.

        >>> import warnings
        >>> t = np.arange(0.0, 20.0, 0.05)
        >>> run = pd.DataFrame({"t": t, "T": 300 + np.sin(t), "P": np.cos(t)})
        >>> with warnings.catch_warnings():
        ...     warnings.simplefilter("ignore")
        ...     about = termid.Model.from_states(["T"], ["P"], degree=2).about_references(run)
        >>> about.parameters, about.candidates("T_dot")[:4]
        ({'T0': 300.0}, ['1', 'ΔT', 'P', 'ΔT^2'])
        """
        native, note = self._native.about_references(_runs(runs, names, self.time))
        if note is not None:
            warnings.warn(f"termid: {note}", stacklevel=_outside())
        return Model(native, self._from_states)

    @_runs_told_apart
    def replay(self, runs: Union[Data, Sequence[Data]], *, dt: Optional[float] = None, integrator: Optional[str] = None, with_intercept: bool = False) -> List[pd.DataFrame]:
        """Each of ``runs`` re-simulated from its recorded initial state with its recorded
        inputs (``dt``, ``integrator``, ``with_intercept`` as for :meth:`simulate`).

        >>> ship = termid.Model.default()
        >>> again = ship.replay(ship.simulate("zigzag:20/20"))[0]
        >>> len(again) == len(ship.simulate("zigzag:20/20"))
        True
        """
        return [_frame(c) for c in self._native.replay(_runs(runs, time=self.time), dt, integrator, with_intercept)]

    @_runs_told_apart
    def validate(
        self,
        runs: Union[Data, Sequence[Data]],
        *,
        dt: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        raw: bool = False,
        monte_carlo: int = 0,
        seed: int = 1,
        over_ground: bool = False,
    ) -> Any:
        """Held-out ``runs`` against the model: a DataFrame of every run's and state's RMS and
        largest error (index run, state; the unit beside), ``attrs["cost"]`` the scaled sum of
        squares, and for a ship ``attrs["metrics"]`` (overshoots, tactical diameter, ...)
        measured and simulated, a DataFrame indexed by run and source. ``raw``: the
        report as plain values; ``dt``, ``integrator``, ``with_intercept`` as for
        :meth:`simulate`. ``attrs["predictable_for"]``: per run, the seconds after which a start a
        millionth of each state's spread off parts from the model's own run by a tenth of a
        spread (a chaotic motion such as Lorenz's), ``None`` where it never does; errors after
        that are of that size whatever the model, and a warning says so.

        ``monte_carlo``: every run simulated also with that many models drawn from the stored
        covariances (:meth:`draws` with ``seed``), as ``termid validate --monte-carlo`` does:
        ``attrs["band"]``, a DataFrame indexed by run and metric with each metric measured,
        its mean, sd, 5 % and 95 % over the draws and whether the measured value lies
        ``outside`` that range, and ``attrs["within_band"]`` (``within``, ``metrics``,
        ``outside``: one measurement in ten falls outside by chance). Where more than 5 % of
        the draws fail it raises :class:`TermidError` saying why, as :meth:`monte_carlo` does.

        ``over_ground``: the runs are tracked by a satellite receiver, so their velocities carry
        the day's current: the model's velocity of the medium (``medium = true``, a model from
        :meth:`from_particulars` declares ``c_N``, ``c_E``) is estimated alone from them first,
        the model held, and each run simulated in it (``attrs["medium"]``: name, source, value,
        std_error), as ``termid validate`` does for a dataset tracked by latitude and longitude.

        >>> ship = termid.Model.default()
        >>> gap = ship.validate(ship.record("zigzag:20/20", truth=True))
        >>> gap.loc[("zigzag:20/20#0", "ψ"), "unit"], bool(gap.loc[("zigzag:20/20#0", "ψ"), "rms"] < 0.01)
        ('rad', True)
        >>> found = ship.identify([ship.record("zigzag:20/20", seed=1), ship.record("zigzag:20/20:port", seed=2)], "kalman")
        >>> checked = found.model.validate(ship.record("zigzag:20/20", seed=3), monte_carlo=20)
        >>> list(checked.attrs["band"].columns)
        ['measured', 'mean', 'sd', 'p05', 'p95', 'outside']
        """
        given = _runs(runs, time=self.time)
        report = json.loads(self._native.validate(given, dt, integrator, with_intercept, over_ground))
        band = None
        if monte_carlo:
            band = json.loads(self._native.validate_monte_carlo(given, monte_carlo, seed, dt, integrator, with_intercept, over_ground))
            if band["refused"] is not None:
                raise TermidError(band["refused"])
            report["monte_carlo"] = band
        if raw:
            return report
        frame = _gap_frame(report["gap"])
        frame.attrs["predictable_for"] = {p["run"]: p["seconds"] for p in report.get("predictable_for", [])}
        for p in report.get("predictable_for", []):
            if p["seconds"] is not None:
                warnings.warn(
                    f"termid: {p['run']} is predictable for {p['seconds']:.3g} s of its {p['of']:.3g} s: a start a "
                    "millionth of each state's spread off parts from the model's own run there (a chaotic or "
                    "strongly unstable motion), so later errors are of that size whatever the model",
                    UserWarning,
                    stacklevel=_outside(),
                )
        rows = [
            {"run": m["run"], "source": source, **(m.get(source) or {})}
            for m in report.get("metrics", [])
            for source in ("measured", "simulated")
            if m.get(source) is not None
        ]
        frame.attrs["metrics"] = pd.DataFrame(rows).set_index(["run", "source"]) if rows else pd.DataFrame()
        medium = report.get("medium") or []
        frame.attrs["medium"] = pd.DataFrame(
            [{"name": p["name"], "source": p["source"], "value": p["value"], "std_error": p["std_error"]} for p in medium],
            columns=["name", "source", "value", "std_error"],
        )
        if band is not None:
            rows = [
                {
                    "run": r["run"],
                    "metric": m["key"],
                    "name": m["name"],
                    "measured": m["measured"],
                    **{k: (m["spread"] or {}).get(k) for k in ("mean", "sd", "p05", "p95")},
                    "outside": m["outside"],
                }
                for r in band["runs"]
                for m in r["metrics"]
                if m["spread"] is not None
            ]
            columns = ["run", "metric", "name", "measured", "mean", "sd", "p05", "p95", "outside"]
            table = pd.DataFrame(rows, columns=columns).set_index(["run", "metric"])
            judged = table.dropna(subset=["outside"])
            frame.attrs["band"] = table.drop(columns="name")
            frame.attrs["within_band"] = {
                "within": int((~judged["outside"].astype(bool)).sum()),
                "metrics": int(len(judged)),
                "outside": [f"{name} of {run}" for (run, _), name, off in zip(judged.index, judged["name"], judged["outside"]) if off],
            }
        return frame

    @_runs_told_apart
    def diagnose(
        self,
        runs: Union[Data, Sequence[Data]],
        *,
        dt: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        raw: bool = False,
        over_ground: bool = False,
    ) -> Tuple[Any, Optional["Model"]]:
        """Where model and ``runs`` disagree, which effect explains it, and the model with it:
        a DataFrame of every run's and state's error before and after the effect (columns
        ``rms_before``, ``max_before``, ``rms_after``, ``max_after``), with ``attrs`` holding
        ``location`` (its words, leading state, onset), ``effect`` and ``candidates`` (a
        DataFrame of the effects tried); and the model with the effect, or None. Where the
        model file declares nuisances of each run or source (a rudder indicator's zero,
        ``nuisance = "run"``), each run is diagnosed with its own values, estimated first with
        the rest of the model held: ``attrs["own_values"]`` (a DataFrame of ``name``, ``run``,
        ``value``, ``std_error``; empty where none) and ``noise`` (the share of the gap that is
        the records' white noise, at most half). ``raw``: the report as plain values;
        ``dt``, ``integrator``, ``with_intercept`` as for :meth:`simulate`. ``over_ground``: the
        runs are tracked by a satellite receiver, so the model's velocity of the medium (a
        current, ``medium = true``) is estimated among those own values; the model returned
        keeps the file's (still water).

        >>> ship = termid.Model.default()
        >>> gaps, repaired = ship.diagnose(ship.record("zigzag:20/20", truth=True))
        >>> list(gaps.columns[:3])
        ['unit', 'rms_before', 'max_before']
        """
        text, native = self._native.diagnose(_runs(runs, time=self.time), dt, integrator, with_intercept, over_ground)
        report = json.loads(text)
        model = Model(native) if native is not None else None
        if raw:
            return report, model
        before = _gap_frame(report["gap_before"]).rename(columns={"rms": "rms_before", "max": "max_before"})
        if report.get("gap_after"):
            after = _gap_frame(report["gap_after"])[["rms", "max"]]
            before = before.join(after.rename(columns={"rms": "rms_after", "max": "max_after"}))
        before.attrs = {
            "location": report.get("location"),
            "effect": report.get("effect"),
            "candidates": pd.DataFrame(
                [{k: v for k, v in c.items() if k in ("name", "explained", "delta_bic", "cost", "declared")} for c in report.get("candidates", [])]
            ),
            "own_values": pd.DataFrame(report.get("own_values", []), columns=["name", "run", "value", "std_error"]),
            # the share of the gap that is the records' white noise, which no effect closes
            "noise": report.get("noise"),
        }
        return before, model

    @_runs_told_apart
    def recipe(
        self,
        runs: Union[Data, Sequence[Data]],
        derivatives: Optional[Sequence[str]] = None,
        *,
        smooth: Optional[bool] = None,
        intercept: Optional[bool] = False,
        choose: Sequence[str] = (),
        compare: Sequence[str] = (),
        refine: Union[Sequence[str], str, None] = "auto",
        refine_iterations: int = 100,
        refine_prior: float = 1e-4,
        held_out: Union[Data, Sequence[Data], None] = None,
        refine_step: Optional[float] = None,
        parameters: Optional[bool] = None,
        sources: Optional[Sequence[int]] = None,
        per_source: Sequence[str] = (),
        per_run: Sequence[str] = (),
        laws: bool = True,
        random_force: bool = True,
        dead_times: bool = True,
    ) -> "Recipe":
        """The command line's recipe for a model from runs (``termid identify --model`` with
        several ``--derivative`` starts) from ``runs``: each start prepares them by one derivative method
        in ``derivatives`` (``smooth``: states smoothed by it), identified (or chosen among the
        back-ends ``choose`` by leave-one-run-out prediction of the states ``compare``),
        refined by output error on the states ``refine`` (None: no refinement; ``"all"`` or an
        empty list: every state) with ``refine_iterations`` (in each of two rounds where the free parameters
        are refined too) and the regression as a prior of weight
        ``refine_prior``, re-simulated at ``refine_step`` seconds (None: the coarsest step, up
        to 8 samples, at which the runs still hold their compared states and inputs; the costs
        are reported at every sample), stopped by ``held_out`` runs where given, checked by the model's
        plug-in; the start kept that passes the checks and re-simulates best, and a flag where
        the plausible starts disagree on a turning circle. ``intercept`` as for
        :meth:`identify` (None: the model file's). ``parameters`` estimates the model file's
        free parameters with every coefficient of each start and each run's initial state, in
        place of the refinement (with ``held_out`` runs, which stop only the refinement, after it
        and only where asked with True), kept where the
        checks the start passed still pass, else the start is refined without them (a
        regression cannot estimate a parameter inside its terms, such as the new-ship
        template's rudder zero ``δ_0``, its own in every run): None (the default) where
        ``refine`` is given and the model file declares free parameters, True also without
        ``refine`` (implied by ``per_source`` and ``per_run``), False not; ``per_source`` names
        those estimated once per source, ``sources`` numbering each run's source (basin),
        ``per_run`` those estimated once per run; the kept start's estimate in ``parameters``
        of the result. A model :meth:`from_states` with the polynomial library whose terms
        fail the checks a stand-in fails (the halves, the re-simulation), or that hold a
        state's or an input's power alone (v³, n³), is identified again with each state's
        and input's laws among the candidates (sign, x·|x|, √|x|, sin x), kept where they pass every check in no more
        terms (and fit the rows clearly better where the polynomials passed too), and said; where none holds, with
        the saturating rates x/(x + K), x·y/(x + K), x²/(x² + K²) of each variable positive in every row and
        tanh(x/K) of one of either sign, K found by a scan, kept so too; ``laws`` False keeps the polynomials.
        One start, not refined, whose runs show a state moved by a random force (process noise:
        another state's record holds its roughness, so it is motion, not a sensor's noise) is
        identified again by Itô's steps (the ``ito`` method, whose terms the force does not
        bias), and said; ``random_force`` False keeps the start's method. A system of no
        field's whose fit finds an input acting later than recorded (a dead time, said in its
        notes, or a first-order lag where one explains the rates better) is identified again
        with the input read so (its ``delay`` or ``lag`` in the model), kept
        where it fails no check the inputs as recorded pass, and said; ``dead_times`` False keeps
        the inputs as recorded.

        ``derivatives``, ``smooth`` and ``refine`` (``"auto"``) left out are the model's
        field's: for a ship the new-ship recipe's (``kinematic``, ``kalman``,
        ``savitzky-golay`` and ``central`` starts, smoothed, refined on u, v, r, ψ); for any
        other system one start by the weak form, neither smoothed nor refined (as
        ``termid identify`` does). A start that fails, starts that disagree, a refinement
        rejected by the checks or failed, a check that flags the kept model, and a model that
        fails its checks (``refusals``) are each warned about.

        >>> ship = termid.Model.default()
        >>> ship.set_parameter("u0", "mean:u:4")
        >>> runs = [ship.record(m, seed=k) for k, m in enumerate(["zigzag:20/20", "zigzag:10/10:port", "zigzag:30/10"])]
        >>> found = ship.recipe(runs, ["kinematic", "central"], refine=("u", "v", "r", "ψ"), refine_iterations=10)
        >>> list(found.starts["derivative"]), int(found.starts["kept"].sum())
        (['kinematic', 'central'], 1)
        >>> stepped = ship.recipe(runs, ["central"], refine=("u", "v", "r", "ψ"), refine_iterations=5, refine_step=0.2)
        >>> "re-simulated at a step of 0.2" in stepped.text
        True
        """
        held = _runs(held_out, time=self.time) if held_out is not None else []
        data = _runs(runs, time=self.time)
        field_derivatives, field_smooth, field_refine = self._native.recipe_defaults()
        if isinstance(refine, str):
            refine = field_refine if refine == "auto" else [] if refine == "all" else [s.strip() for s in refine.split(",") if s.strip()]
        text_json, text, native = self._native.recipe(
            data,
            list(field_derivatives if derivatives is None else derivatives),
            field_smooth if smooth is None else smooth,
            intercept,
            list(choose),
            list(compare),
            None if refine is None else list(refine),
            refine_iterations,
            refine_prior,
            held,
            refine_step,
            parameters,
            [int(s) for s in sources or []],
            list(per_source),
            list(per_run),
            laws,
            random_force,
            dead_times,
        )
        found = Recipe(self._identified(native, data), json.loads(text_json), text)
        # what the command line prints as warnings (or refuses to write) is said here too
        for why in found.warnings:
            warnings.warn(f"termid: {why}", stacklevel=_outside())
        if found.refusals:
            warnings.warn(
                "termid: the identified model fails its checks (Recipe.refusals):\n  " + "\n  ".join(found.refusals),
                stacklevel=_outside(),
            )
        return found

    @_runs_told_apart
    def estimate(
        self,
        runs: Union[Data, Sequence[Data]],
        *,
        coefficients: bool = False,
        states: Optional[Sequence[str]] = None,
        initial_values: str = "auto",
        dt: Optional[float] = None,
        iterations: int = 50,
        sources: Optional[Sequence[int]] = None,
        per_source: Sequence[str] = (),
        per_run: Sequence[str] = (),
        coarse: bool = False,
        segments: Optional[int] = None,
        free: Sequence[str] = (),
        hold: Sequence[str] = (),
        over_ground: bool = False,
    ) -> Tuple[pd.DataFrame, "Model"]:
        """The model file's free parameters (``free = true`` under ``[parameters.NAME]``, with an
        optional ``prior`` and ``bounds``) estimated from ``runs`` by output error: grey-box
        identification. Returns a DataFrame of each parameter's start, estimate, standard
        error, prior and ``from_runs``, the share of its precision the runs gave (1 − (std.
        error / prior sd)²: near 0 the estimate is the prior's) (``attrs``: the cost before and
        after, why it stopped, the parameters' covariance, and ``attrs["correlated"]`` the
        pairs whose estimates correlate beyond ±0.95: the runs fix a combination of each, not
        each alone) and the model holding the estimates.

        Parameters: ``coefficients`` also estimates the identified equations' term
        coefficients; ``states`` the states compared (default: every state the runs have),
        and beside them any derived variable of the model (``[[derived]]``, a propeller's
        thrust) to compare with the runs' column of its name, evaluated along the
        re-simulation; each state and derived variable is compared in the runs that have its
        column (``attrs["partly_recorded"]``: each that some runs lack, with how many ``runs``
        record it ``of`` how many);
        ``initial_values`` how each run's initial state enters (a noisy first sample would
        bias the rest): ``"auto"`` (estimated free; where the fit leans on them, estimated
        again held to the recorded first samples by the records' noise, and that fit kept
        where it predicts the runs from their records better; ``attrs["held_again"]``),
        ``"measured"`` (held so from the start), ``"free"`` (without a prior: they may absorb
        what the model does not explain) or ``"recorded"`` (the first sample as it is); ``dt`` the RK4 step
        (default: the runs' sample interval); ``iterations`` the most Levenberg-Marquardt
        iterations per round; ``sources`` the source (basin, campaign) of each run by number,
        ``per_source`` the free parameters estimated once per source (nuisances such as a
        basin's rudder zero) and ``per_run`` those estimated once per run (a rudder zero that
        drifts from run to run); both in ``attrs["per_source"]``, a DataFrame (its ``run``
        column names the run where estimated per run). A per-source value is not written to
        the model; a per-run parameter's mean over the runs is (``attrs["per_run"]``: its mean
        and sd, how uncertain a new run's value is, and Wald's ``chi_square`` and ``p_value``
        that the runs' values are equal). A parameter the model file declares per run
        (``nuisance = "run"``) whose runs' values agree (p ≥ 0.05) is estimated once for all
        runs instead (``attrs["one_value"]``: the per-run fit's spread and test); asked for in
        ``per_run``, it stays per run. One declared per source (``nuisance = "source"``) is
        tested alike over two or more sources (``attrs["per_source_spread"]``) and merged where
        they agree (``per`` in ``attrs["one_value"]`` says which). ``attrs["from_records"]``
        holds the estimated model's cost from the recorded first samples and how far the
        estimated initial values moved in units of the records' noise; beyond 3 times a warning
        says the fit leans on them (the model does not explain everything the runs show).
        ``coarse`` fits at the coarsest step (up to 8 samples) at which the model's start
        re-simulates the runs as at every sample, as the recipe's refinement does: on
        finely sampled records several times faster (SIMMAN's 13 HSVA runs at 20 Hz: 21 s →
        4.5 s, every estimate within 0.32 standard errors); costs still at every sample, the
        fit's step in ``attrs["step_samples"]``. For a ship, ``attrs["metrics"]`` sets what
        its plug-in reads off each run (first and second overshoot, tactical diameter) as
        measured beside the fit's re-simulation (the estimates, each run's own values and
        estimated initial state): a DataFrame of ``run``, ``metric``, ``measured`` and
        ``simulated``, empty for other models. A structure that fits the time series in the
        mean may still miss the numbers a manoeuvre is judged by: ``attrs["metric_checks"]``
        holds the field's check of them (a ship's first overshoots within 1°), and a warning
        says where one fails.

        ``attrs["unexplained"]`` is the share of the records' variance the fit leaves (each
        compared quantity scaled by its spread over the runs), ``attrs["noise"]`` the share
        that is their noise (from their second differences); more than 0.1 beyond the noise
        the fit does not follow the records and a warning says so. Where the fit from the model file's values
        leaves that much, it is made again from the parameters fitted on the runs cut into 16
        segments, each from its own initial values (multiple shooting), and the better kept
        (``attrs["segmented"]``: the segments, whether that fit was ``kept``, the other's
        cost and share left): an output error has minima that are not the system's wherever
        the start's phase drifts off the record's. ``segments`` cuts each run into that many
        segments to fit (each reported as a run): where a motion's errors grow over a run (a
        chaotic system) no whole-run fit follows it and the warning says to. The runs are
        integrated at a step that resolves the motion of the start and of the estimates (their
        step halved until that holds, ``attrs["finer"]`` times): a step too long for a fast rate
        biases the estimates towards what the integrator can follow.

        ``free`` names held parameters to estimate too and ``hold`` free ones to hold, for
        this estimate only (the model returned keeps the file's word on each): a sea trial
        tracked by satellite fixes gives velocities over ground, which carry the current the
        ship moves in; a model from ``new_ship`` declares that current (``c_N``, ``c_E``, m/s
        towards north and east, ``medium = true``, held at 0 for simulation) and
        ``free=["c_N", "c_E"]`` estimates it once per source; ``over_ground`` (true) frees every
        velocity of the medium the model declares (``medium = true``) but those in ``hold``, as
        ``termid estimate`` does by itself for a dataset file whose track is latitude and
        longitude.

        >>> nomoto = termid.Model.builtin("nomoto")
        >>> truth = termid.Model.builtin("nomoto")
        >>> truth.set_parameter("K", 0.15); truth.set_parameter("T", 8.0)
        >>> run = truth.simulate(duration=60.0, inputs={"δ": 0.1}, sample=0.1)
        >>> table, found = nomoto.estimate(run)
        >>> table["estimate"].round(4).to_dict()
        {'K': 0.15, 'T': 8.0}
        """
        text, native = self._native.estimate(
            _runs(runs, time=self.time),
            coefficients,
            None if states is None else list(states),
            initial_values,
            dt,
            iterations,
            [int(s) for s in sources or []],
            list(per_source),
            list(per_run),
            coarse,
            None if segments is None else int(segments),
            list(free),
            list(hold),
            over_ground,
        )
        report = json.loads(text)
        table = pd.DataFrame(
            [
                {
                    "parameter": p["name"],
                    "start": p["start"],
                    "estimate": p["value"],
                    "std_error": float("nan") if p["std_error"] is None else float(p["std_error"]),
                    "prior_mean": float("nan") if p["prior"] is None else p["prior"][0],
                    "prior_sd": float("nan") if p["prior"] is None else p["prior"][1],
                    "at_bound": p["at_bound"],
                    "from_runs": float("nan") if p.get("from_runs") is None else p["from_runs"],
                }
                for p in report["parameters"]
            ]
        ).set_index("parameter")
        names = list(table.index)
        table.attrs = {
            "cost_before": report["cost_before"],
            "cost_after": report["cost_after"],
            "stopped": report["stopped"],
            "unexplained": report["unexplained"],
            "noise": report["noise"],
            "finer": report["finer"],
            "segmented": report.get("segmented"),
            "covariance": None if report["covariance"] is None else pd.DataFrame(report["covariance"], index=names, columns=names),
            "per_source": pd.DataFrame(report.get("per_source", []), columns=["name", "source", "run", "value", "std_error"]),
            "from_records": report.get("from_records"),
            "per_run": pd.DataFrame(report.get("per_run", []), columns=["name", "runs", "mean", "sd", "chi_square", "p_value"]),
            "per_source_spread": pd.DataFrame(report.get("per_source_spread", []), columns=["name", "runs", "mean", "sd", "chi_square", "p_value"]),
            "one_value": pd.DataFrame(report.get("one_value", []), columns=["name", "per", "runs", "mean", "sd", "chi_square", "p_value"]),
            "held_again": report.get("held_again"),
            "step_samples": report.get("step_samples", 1),
            "correlated": pd.DataFrame(report.get("correlated", []), columns=["a", "b", "correlation"]),
            "partly_recorded": pd.DataFrame(report.get("partly_recorded", []), columns=["name", "runs", "of"]),
            "metrics": pd.DataFrame(report.get("metrics", []), columns=["run", "metric", "measured", "simulated"]),
            "metric_checks": pd.DataFrame(report.get("metric_checks", []), columns=["name", "passed", "refuses", "detail"]),
        }
        for check in report.get("metric_checks", []):
            if not check["passed"]:
                # the fit misses what the field judges its runs by (a ship's overshoots): said as
                # the CLI says it
                warnings.warn(f"termid: FLAG {check['name']}: {check['detail']}", stacklevel=_outside())
        if report.get("metrics_failed"):
            warnings.warn(
                f"termid: no metrics of the fit: the estimates do not re-simulate every run: {report['metrics_failed']}",
                stacklevel=_outside(),
            )
        if report["unexplained"] > 0.1 + report["noise"]:
            # a minimum that is not the system's, or a structure that is not: the CLI flags it
            searched = report.get("segmented") or {}
            left = searched.get("segments_unexplained")
            why = (
                f"; fitted on segments of {searched['seconds']:.3g} s the model follows them "
                f"({100 * left:.2g} % left): its errors build up over a run, from an effect the model "
                "lacks that accumulates (an offset, a drift) or from a chaotic or unstable motion, "
                "which only segments of its runs can fit (segments=N)"
                if left is not None and left <= 0.1 + report["noise"]
                else ": a minimum that is not the system's, or a structure that is not"
            )
            warnings.warn(
                f"termid: the fit does not follow the records: it leaves {100 * report['unexplained']:.2g} % "
                f"of their variance (attrs['unexplained']; their noise {100 * report['noise']:.2g} %){why}; "
                "read the estimates as failed",
                stacklevel=_outside(),
            )
        leaning = report.get("from_records") or {}
        if leaning.get("leans"):
            # a fit whose initial values absorb what the model does not explain: its cost says
            # more than the model predicts (the CLI flags it in its report)
            cost = leaning.get("cost")
            warnings.warn(
                f"termid: the fit leans on its estimated initial values: they moved {leaning['moved']:.3g} times "
                f"the records' noise from the first samples; from those the cost is "
                f"{'beyond bounds' if cost is None else f'{cost:.4g}'} against {report['cost_after']:.4g} "
                "(attrs['from_records']); the model does not explain everything the runs show",
                stacklevel=_outside(),
            )
        return table, Model(native)

    @_runs_told_apart
    def checks(self, runs: Union[Data, Sequence[Data], None] = None) -> pd.DataFrame:
        """The plug-in's physical checks (stability, damping signs, turning circles), with
        ``runs`` to compare against where a check needs them; for a model of no field's, with
        ``runs``, that its equations retrace them without running away (and how long they
        follow them), that they follow them as long as their own motion allows (and within
        the records' noise where that motion follows itself throughout), and that their noise
        leaves its terms unbiased.

        >>> checks = termid.Model.default().checks()
        >>> {"name", "passed"} <= set(checks.columns)
        True
        """
        return pd.DataFrame(json.loads(self._native.checks(_runs(runs, time=self.time) if runs is not None else [])))

    @_runs_told_apart
    def steering_gear(self, runs: Union[Data, Sequence[Data]]) -> Optional[Dict[str, float]]:
        """The steering gear a ship model's zigzag ``runs`` show: ``delay_s`` (the dead time from
        the heading passing the check angle to the rudder starting back), ``acceleration_deg_s2``
        (how fast its rate builds up), ``rate_deg_s`` and the ``reversals`` read (medians over
        them); ``None`` for another model or runs without a rudder reversal. Set them as
        ``rudder_delay``, ``rudder_acceleration`` and ``rudder_rate`` in the model file's
        ``[ship]`` table to steer its zigzags as the basin did.

        >>> ship = termid.Model.default()
        >>> gear = ship.steering_gear(ship.simulate("zigzag:20/20", dt=0.04, sample=0.04))
        >>> abs(gear["rate_deg_s"] - 12.65) < 0.1, gear["delay_s"] < 0.05
        (True, True)
        """
        text = self._native.steering_gear(_runs(runs, time=self.time))
        return None if text is None else json.loads(text)

    def sway_yaw(self, speed: Optional[float] = None) -> Optional[Dict[str, Any]]:
        """A ship model's linear sway and yaw at its straight run, at ``speed`` (m/s; ``None``:
        the model's own u0): ``yv`` = ∂v̇/∂v and ``nr`` = ∂ṙ/∂r (1/s, the damping; negative on
        every hull), ``yr`` = ∂v̇/∂r, ``nv`` = ∂ṙ/∂v, ``n_delta`` = ∂ṙ/∂δ (1/s², the rudder's
        yaw moment per radian), ``time_constants_s`` (the fast and the slow mode, s; a negative
        one is course-unstable; ``None`` for an oscillating pair), ``largest_eigenvalue`` (1/s),
        ``course_stable``, ``u0`` and ``delta0_deg`` of the straight run; ``None`` for another
        model. What a model carries into the turns beyond what its zigzags bound.

        >>> s = termid.Model.default().sway_yaw()
        >>> s["course_stable"], s["yv"] < 0, s["nr"] < 0, s["time_constants_s"][0] > 0
        (True, True, True, True)
        """
        text = self._native.sway_yaw(speed)
        return None if text is None else json.loads(text)

    def __repr__(self) -> str:
        return repr(self._native)

    def __str__(self) -> str:
        # what print() shows: the name and each equation with its stored coefficients (six
        # significant digits), as Fit.equation writes one; repr() stays the one-line summary
        lines = [self.name]
        for equation in self.equations:
            terms = zip(*(self.coefficients(equation)[c] for c in ("term", "value")))
            lines.append("  " + _equation_text(equation, self.intercept(equation), terms, 6))
        return "\n".join(lines)


#: Sufficient statistics of one equation: ``Moments.from_frame(df, model, "r_dot")``,
#: ``a.merge(b)``, ``pickle.dumps(m)``, ``model.identify_from_moments([a, b])``.
Moments = _termid.Moments
