"""One equation from columns: termid.fit against published numbers and closed forms."""
import inspect
import os
import warnings

import numpy as np
import pandas as pd
import pytest

import termid


def test_hald_stepwise_follows_draper_and_smith(hald):
    fit = termid.fit(hald, "y", ["x1", "x2", "x3", "x4"], "stepwise", min_proportion=0.0)
    # the order in which the terms enter (Draper & Smith, Applied Regression Analysis)
    assert list(fit.steps["term"]) == ["x4", "x1", "x2", "x3"]
    first = termid.fit(hald, "y", ["x4"], "stepwise")
    # y = 117.57 − 0.7382 x4
    assert first.coefficients["x4"] == pytest.approx(-0.738162, abs=1e-5)
    assert first.intercept == pytest.approx(117.5679, abs=1e-3)


def test_exact_relation_is_recovered_and_predicted():
    rng = np.random.default_rng(1)
    x1, x2 = rng.normal(size=200), rng.normal(size=200)
    df = pd.DataFrame({"x1": x1, "x2": x2, "y": 2.0 + 3.0 * x1 * x2 - 0.5 * x2**3})
    fit = termid.fit(df, "y", ["x1", "x2", "x1*x2", "x2^3", "x1^2"], "best-subset")
    coefficients = fit.coefficients
    assert set(coefficients.index) == {"x1*x2", "x2^3"}
    assert coefficients["x1*x2"] == pytest.approx(3.0, abs=1e-9)
    assert coefficients["x2^3"] == pytest.approx(-0.5, abs=1e-9)
    new = {"x1": np.array([1.0, 2.0]), "x2": np.array([0.5, -1.0])}
    np.testing.assert_allclose(fit.predict(new), 2.0 + 3.0 * new["x1"] * new["x2"] - 0.5 * new["x2"] ** 3)


def test_dict_dataframe_and_arrow_give_the_same_fit(hald):
    pa = pytest.importorskip("pyarrow")
    as_frame = termid.fit(hald, "y", backend="stepwise")
    as_dict = termid.fit({c: hald[c].to_numpy() for c in hald.columns}, "y", backend="stepwise")
    as_arrow = termid.fit(pa.Table.from_pandas(hald), "y", backend="stepwise")
    pd.testing.assert_series_equal(as_frame.coefficients, as_dict.coefficients)
    pd.testing.assert_series_equal(as_frame.coefficients, as_arrow.coefficients)


def test_every_back_end_by_name(hald):
    for name in termid.backends():
        fit = termid.fit(hald, "y", ["x1", "x2", "x3", "x4"], name)
        assert len(fit.coefficients) >= 1, name


def test_a_typo_in_a_term_shows_a_caret(hald):
    with pytest.raises(termid.TermidError) as e:
        termid.fit(hald, "y", ["x1*", "x2"])
    assert "^" in str(e.value)


def test_nan_is_refused_with_its_row(hald):
    bad = hald.copy()
    bad.loc[3, "x2"] = np.nan
    with pytest.raises(termid.TermidError, match=r"row 4.*x2"):
        termid.fit(bad, "y")


def test_unknown_back_end_and_setting_are_refused(hald):
    with pytest.raises(termid.TermidError, match="stepwise"):
        termid.fit(hald, "y", backend="lasso-of-dreams")
    with pytest.raises(termid.TermidError, match="f_in"):
        termid.fit(hald, "y", backend="stepwise", f_in=4.0)


def test_frame_columns_are_read_in_place_and_mixed_types_converted(hald):
    frame = hald.astype("float64")
    columns = termid._columns(frame)
    assert list(columns) == [str(c) for c in frame.columns]
    # float64 columns are the frame's own memory, not copies
    assert all(np.shares_memory(columns[str(c)], frame[c].to_numpy()) for c in frame.columns)
    mixed = frame.assign(x1=frame["x1"].astype("int64"))
    converted = termid._columns(mixed)
    assert converted["x1"].dtype == np.float64
    a = termid.fit(frame, "y", ["x1", "x2", "x3", "x4"])
    b = termid.fit(mixed, "y", ["x1", "x2", "x3", "x4"])
    pd.testing.assert_series_equal(a.coefficients, b.coefficients)


def test_one_term_as_a_string_is_one_term(hald):
    # a string is one term, not its characters ("unknown variable `x`" before)
    assert list(termid.fit(hald, "y", "x1").coefficients.index) == ["x1"]
    # commas list several, as the command line's --terms x1,x2 (a call's own commas kept)
    listed = termid.fit(hald, "y", "x1, x2,atan2(x3, x4)", backend="best-subset")
    assert listed.report["candidates"] == ["x1", "x2", "atan2(x3, x4)"]


def test_a_column_named_twice_is_refused(hald):
    twice = pd.concat([hald[["y", "x1"]], hald[["x2"]].rename(columns={"x2": "x1"})], axis=1)
    with pytest.raises(termid.TermidError, match="`x1` appears twice"):
        termid.fit(twice, "y", ["x1"])


def test_a_label_column_is_left_out_unless_a_term_needs_it(hald):
    labelled = hald.assign(batch=[f"b{k}" for k in range(len(hald))])
    plain = termid.fit(hald, "y", ["x1", "x2"]).coefficients
    pd.testing.assert_series_equal(termid.fit(labelled, "y", ["x1", "x2"]).coefficients, plain)
    with pytest.raises(termid.TermidError, match=r"`batch` holds (str|object|string), not numbers"):
        termid.fit(labelled, "y", ["x1", "batch"])
    with pytest.raises(termid.TermidError, match="not numbers: it cannot be fitted"):
        termid.fit(labelled, "batch", ["x1"])
    # a categorical column is named by its own type, with how a term can use its levels
    kiln = hald.assign(kiln=pd.Categorical(["a", "b"] * (len(hald) // 2) + ["a"] * (len(hald) % 2)))
    with pytest.raises(termid.TermidError, match=r"`kiln` holds category, not numbers: .*pd.get_dummies\(df, columns=\['kiln'\]"):
        termid.fit(kiln, "y", ["x1", "kiln"])
    dummies = pd.get_dummies(kiln, columns=["kiln"], dtype=float)
    assert "kiln_b" in termid.fit(dummies, "y", ["x1", "kiln_b"], "stepwise", step_rule="last").coefficients.index


def test_predictions_keep_the_index_and_errors_are_floats(hald, ship, zigzags):
    indexed = hald.set_index(pd.Index([f"row{k}" for k in range(len(hald))]))
    fit = termid.fit(indexed, "y", ["x1", "x2"])
    predicted = fit.predict(indexed)
    assert isinstance(predicted, pd.Series) and predicted.name == "y"
    assert list(predicted.index) == list(indexed.index)
    run = zigzags[0].set_index(zigzags[0].t * 1000.0)
    predicted = ship.predict(run)
    assert list(predicted.index) == list(run.index)
    # named as the equations are (`psi_dot`, not `ψ_dot`)
    assert list(predicted.columns) == ship.equations
    assert ship.coefficients("r_dot")["std_error"].dtype == np.float64


def test_summary_as_statsmodels_reports_it(hald):
    from termid import _t_two_sided, _t_quantile

    # Student's t in closed form: df = 1 (Cauchy) and df = 2
    for t in [0.1, 1.0, 3.0, 25.0]:
        assert _t_two_sided(t, 1) == pytest.approx(1 - 2 / np.pi * np.arctan(t), rel=1e-10)
        assert _t_two_sided(t, 2) == pytest.approx(1 - t / np.sqrt(2 + t * t), rel=1e-10)
    assert _t_quantile(0.05, 2) == pytest.approx(4.302652729911275, rel=1e-9)
    fitted = termid.fit(hald, "y", ["x1", "x2"], "stepwise", step_rule="last")
    s = fitted.summary()
    # ordinary least squares by numpy, as statsmodels' OLS computes it
    X = np.column_stack([np.ones(len(hald)), hald.x1, hald.x2])
    beta, rss, *_ = np.linalg.lstsq(X, hald.y, rcond=None)
    n, p = X.shape
    sigma2 = rss[0] / (n - p)
    se = np.sqrt(np.diag(sigma2 * np.linalg.inv(X.T @ X)))
    llf = -0.5 * n * (np.log(2 * np.pi) + np.log(rss[0] / n) + 1)
    r2 = 1 - rss[0] / ((hald.y - hald.y.mean()) ** 2).sum()
    assert s.stats["r2"] == pytest.approx(r2, rel=1e-10)
    assert s.stats["adj_r2"] == pytest.approx(1 - (1 - r2) * (n - 1) / (n - p), rel=1e-10)
    assert s.stats["aic"] == pytest.approx(-2 * llf + 2 * p, rel=1e-10)
    assert s.stats["bic"] == pytest.approx(-2 * llf + p * np.log(n), rel=1e-10)
    terms = s.terms.loc[["(intercept)", "x1", "x2"]]
    np.testing.assert_allclose(terms.coefficient, beta, rtol=1e-10)
    np.testing.assert_allclose(terms.std_error, se, rtol=1e-8)
    assert terms.loc["x1", "ci_0.025"] == pytest.approx(beta[1] - 2.2281388519649385 * se[1], rel=1e-8)
    assert 0 < terms.loc["x1", "p"] < 1e-6
    assert "y = " in str(s) and "x1" in repr(fitted)


def _fit_in_a_worker(frame):
    return termid.fit(frame, "y", ["x1", "x2", "x1*x2"])


def _refuse_in_a_worker(frame):
    return termid.fit(frame, "y", ["x1*"])


def test_fits_and_errors_cross_a_process_pool(hald):
    import pickle
    from concurrent.futures import ProcessPoolExecutor

    here = _fit_in_a_worker(hald)
    again = pickle.loads(pickle.dumps(here))
    pd.testing.assert_series_equal(again.coefficients, here.coefficients)
    pd.testing.assert_series_equal(again.predict(hald), here.predict(hald))
    with ProcessPoolExecutor(max_workers=1) as pool:
        there = pool.submit(_fit_in_a_worker, hald).result()
        pd.testing.assert_series_equal(there.predict(hald), here.predict(hald))
        with pytest.raises(termid.TermidError, match=r"\^"):
            pool.submit(_refuse_in_a_worker, hald).result()


def test_tab_completion_offers_the_public_names_alone():
    names = dir(termid)
    assert set(termid.__all__) <= set(names)
    assert not {"np", "pd", "json", "os", "Dict", "Optional", "warnings"} & set(names), names
    # every name offered is there to be read
    assert all(hasattr(termid, n) for n in names)


def test_a_target_that_is_not_a_number_is_named_with_its_row():
    df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4, 5], "y": [1.0, 3.1, np.nan, 7.0, 9.0, 11.2]})
    with pytest.raises(termid.TermidError, match=r"row 3 \(index 2\): the target `y` evaluates to NaN \(check the data there\)"):
        termid.fit(df, "y", "x")
    # the row's index label beside its number, as a DataFrame's user finds it (df.loc[...])
    stamped = df.set_index(pd.Index([1000, 1001, 1002, 1003, 1004, 1005]))
    with pytest.raises(termid.TermidError, match=r"row 3 \(index 1002\): the target `y`"):
        termid.fit(stamped, "y", "x")


def _lorenz(t_end=20.0, dt=0.001, every=10):
    """Lorenz (σ = 10, ρ = 28, β = 8/3) by RK4 at 1 ms, sampled every 10 ms."""
    def rate(s):
        x, y, z = s
        return np.array([10.0 * (y - x), x * (28.0 - z) - y, x * y - 8.0 / 3.0 * z])

    s = np.array([-8.0, 7.0, 27.0])
    rows = [s]
    for _ in range(int(round(t_end / dt))):
        k1 = rate(s)
        k2 = rate(s + 0.5 * dt * k1)
        k3 = rate(s + 0.5 * dt * k2)
        k4 = rate(s + dt * k3)
        s = s + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        rows.append(s)
    states = np.array(rows)[::every]
    return np.arange(len(states)) * dt * every, states


def test_noise_that_biases_a_rates_terms_is_said():
    # Lorenz with 5 % noise on its states: the weak form averages it out of the rate but not
    # out of a candidate nonlinear in the states (errors in variables); measured off the
    # records and said in the fit's notes, as the command line does; at 0.5 % nothing is said
    t, s = _lorenz()
    rng = np.random.default_rng(4)
    library = ["x", "y", "z", "x*x", "x*y", "x*z", "y*y", "y*z", "z*z"]
    for share, said in ((0.05, True), (0.005, False)):
        noisy = s + share * s.std(axis=0) * rng.standard_normal(s.shape)
        df = pd.DataFrame({"t": t, "x": noisy[:, 0], "y": noisy[:, 1], "z": noisy[:, 2]})
        notes = " ".join(termid.fit(df, "dy/dt", library).notes)
        assert ("the records' noise may bias the terms: white noise of `x` " in notes) == said, notes


def test_a_rate_is_an_equation_of_motion_with_the_command_lines_defaults():
    # the closed form: Lorenz's own coefficients, from its states alone, the time as a column,
    # as the index (seconds), or as date-times; the constant a candidate, stlsq, the weak form
    t, s = _lorenz()
    library = ["x", "y", "z", "x*x", "x*y", "x*z", "y*y", "y*z", "z*z"]
    df = pd.DataFrame({"t": t, "x": s[:, 0], "y": s[:, 1], "z": s[:, 2]})
    fitted = termid.fit(df, "dy/dt", library)
    assert fitted.raw["selection"]["backend"] == "stlsq"
    assert "1" in fitted.raw["candidates"] and fitted.intercept is None
    assert fitted.coefficients.sort_index().round(2).to_dict() == {"x": 28.0, "x*z": -1.0, "y": -1.0}
    by_index = termid.fit(df.set_index("t"), "dz/dt", library)
    assert by_index.coefficients.sort_index().round(3).to_dict() == {"x*y": 1.0, "z": -2.667}
    stamped = df.drop(columns="t").set_index(pd.Timestamp("2026-11-28") + pd.to_timedelta(t, unit="s"))
    with pytest.warns(UserWarning, match="read as seconds"):
        by_clock = termid.fit(stamped, "dx/dt", library)
    assert by_clock.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    # a logger's clock in its time zone, across the change to summer time (02:00 → 03:00 on
    # 2026-03-29 in Berlin): read in UTC, the hour that never was is no gap
    zoned = stamped.set_index(pd.date_range("2026-03-29 01:59:59", periods=len(t), freq="10ms", tz="Europe/Berlin"))
    assert zoned.index[-1].hour == 3
    with pytest.warns(UserWarning, match="read as seconds"):
        by_zone = termid.fit(zoned, "dx/dt", library)
    assert by_zone.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    # the one column of date-times is the rows' time, said
    logged = zoned.reset_index(names="logged")
    with pytest.warns(UserWarning) as said:
        by_column = termid.fit(logged, "dx/dt", library)
    assert "the rows' time is column `logged`" in " ".join(str(w.message) for w in said)
    assert by_column.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    # a derivative method named: five-point differences, the same terms (central ones' error
    # of O(h²), smooth in the states, buys x·z and y·z: the weak form is the default)
    five = termid.fit(df, "dx/dt", library, derivative="five-point")
    assert five.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    central = termid.fit(df, "dx/dt", library, derivative="central")
    assert "x*z" in central.coefficients.index
    # what it needs, said
    with pytest.raises(termid.TermidError, match="needs the rows' time"):
        termid.fit(df.drop(columns="t"), "dx/dt", library)
    # the one column named like time is the time, said (as the command line takes a file's);
    # beside another it is named; row labels (a filtered frame's integers) are no time
    with pytest.warns(UserWarning, match="the rows' time is column `Time`, the one whose name says so"):
        timed = termid.fit(df.rename(columns={"t": "Time"}), "dx/dt", library)
    assert timed.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    with pytest.raises(termid.TermidError, match="`Time` looks like time: time='Time'"):
        termid.fit(df.rename(columns={"t": "Time"}).assign(seconds=df["t"]), "dx/dt", library)
    with pytest.raises(termid.TermidError, match="needs the rows' time"):
        termid.fit(df.drop(columns="t").iloc[::2], "dx/dt", library)
    with pytest.raises(termid.TermidError, match="no column `w`"):
        termid.fit(df, "dw/dt", library)
    with pytest.raises(termid.TermidError, match="are for a rate"):
        termid.fit(df, "x", ["y"], derivative="central")


def _decay(x0, v0, t):
    """ẍ = −4x − 0.3ẋ from (x0, v0), in closed form: a damped oscillation."""
    sigma, omega = 0.15, np.sqrt(4.0 - 0.15**2)
    b = (v0 + sigma * x0) / omega
    x = np.exp(-sigma * t) * (x0 * np.cos(omega * t) + b * np.sin(omega * t))
    v = np.exp(-sigma * t) * ((omega * b - sigma * x0) * np.cos(omega * t) - (omega * x0 + sigma * b) * np.sin(omega * t))
    return pd.DataFrame({"t": t, "x": x, "v": v})


_OSCILLATOR = """
[model]
name = "damped oscillator"
intercept = false
[[states]]
name = "x"
[[states]]
name = "v"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "v" = 1.0 }
[equations.v_dot]
state = "v"
candidates = ["x", "v", "x^2", "x*v"]
"""


def test_several_runs_are_fitted_together_never_across_their_seams():
    # three experiments of one oscillator from other starts: as a list, or one frame told
    # apart by a label column; the rate is integrated along each run, not from one to the next
    t = np.arange(0.0, 15.0, 0.01)
    runs = [_decay(x0, v0, t).assign(experiment=name) for x0, v0, name in [(1.0, 0.0, "a"), (-2.0, 1.0, "b"), (0.5, -3.0, "c")]]
    truth = {"v": -0.3, "x": -4.0}
    listed = termid.fit([r.drop(columns="experiment") for r in runs], "dv/dt", ["x", "v", "x^2", "x*v"])
    assert listed.coefficients.sort_index().round(6).to_dict() == truth
    long = pd.concat(runs, ignore_index=True)
    grouped = termid.fit(long, "dv/dt", ["x", "v", "x^2", "x*v"], by="experiment")
    assert grouped.coefficients.sort_index().round(6).to_dict() == truth
    assert grouped.raw["selection"]["rows"] == listed.raw["selection"]["rows"]
    # a row that names no run belongs to none: refused with its row, as the command line does
    unlabelled = long.assign(experiment=long.experiment.where(long.index != 1600))
    with pytest.raises(termid.TermidError, match=r"row 1601 \(index 1600\), column `experiment`: no label"):
        termid.fit(unlabelled, "dv/dt", ["x", "v"], by="experiment")
    # one frame whose time starts again is refused, the remedy named with its label column
    with pytest.raises(termid.TermidError, match="row 1501.*by='experiment'"):
        termid.fit(long, "dv/dt", ["x", "v"])
    # a pandas grouping is runs named by its values, for fit and for a model alike
    assert termid.fit(long.groupby("experiment"), "dv/dt", ["x", "v", "x^2"]).coefficients.sort_index().round(6).to_dict() == truth
    model = termid.Model.from_toml(_OSCILLATOR)
    found = model.identify(long.groupby("experiment")).model.coefficients("v_dot")
    assert dict(zip(found["term"], found["value"].round(6))) == {"x": -4.0, "v": -0.3}
    gaps = model.identify(long.groupby("experiment")).model.validate(long.groupby("experiment"))
    assert sorted(gaps.index.get_level_values("run").unique()) == ["experiment=a", "experiment=b", "experiment=c"]
    # or told apart by their column, `by=`, as for fit (a model's every method on runs)
    found = model.identify(long, by="experiment").model
    assert dict(zip(found.coefficients("v_dot")["term"], found.coefficients("v_dot")["value"].round(6))) == truth
    assert found.validate(long, by="experiment").equals(gaps)
    assert "by" in str(inspect.signature(termid.Model.recipe))
    with pytest.raises(termid.TermidError, match="no column `vessel` to tell the runs apart"):
        model.identify(long, by="vessel")
    # two runs logged in turn, their time increasing throughout, would read as one run whose
    # readings leap at every row: refused, the label column named
    turns = pd.concat([runs[0], runs[1].assign(t=runs[1].t + 0.005)]).sort_values("t", ignore_index=True)
    with pytest.raises(termid.TermidError, match=r"2 runs interleaved \(`experiment` changes at 2999 of 3000 rows.*df.groupby\('experiment'\)"):
        termid.fit(turns, "dv/dt", ["x", "v"])
    assert termid.fit(turns.groupby("experiment"), "dv/dt", ["x", "v", "x^2"]).coefficients.sort_index().round(6).to_dict() == truth
    for method in (model.identify, model.validate):
        with pytest.raises(termid.TermidError, match=r"row 1501.*df.groupby\('experiment'\), or by='experiment'"):
            method(long)
    # a run without a column the first has is refused by name
    with pytest.raises(termid.TermidError, match="run `run2` has other columns than `run1`: without `v`"):
        termid.fit([runs[0], runs[1].drop(columns="v")], "dv/dt", ["x"])
    # a column explained by the rows of every run together (rows need no order)
    rows = termid.fit([r.assign(y=3 * r.x - r.v) for r in runs], "y", ["x", "v"])
    assert rows.coefficients.sort_index().round(6).to_dict() == {"v": -1.0, "x": 3.0}
    assert rows.raw["selection"]["rows"] == 3 * len(t)


def test_a_glitch_is_mended_with_a_warning():
    # one sample of x 30 off: as recorded it buys terms; mended (the default) Lorenz's own
    t, s = _lorenz()
    library = ["x", "y", "z", "x*x", "x*y", "x*z", "y*y", "y*z", "z*z"]
    df = pd.DataFrame({"t": t, "x": s[:, 0], "y": s[:, 1], "z": s[:, 2]})
    df.loc[len(df) // 2, "x"] += 30.0
    with pytest.warns(UserWarning, match=f"`x` leaps away and straight back by .* at row {len(df) // 2 + 1} "):
        fitted = termid.fit(df, "dx/dt", library)
    assert fitted.coefficients.sort_index().round(3).to_dict() == {"x": -10.0, "y": 10.0}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kept = termid.fit(df, "dx/dt", library, keep_spikes=True)
    assert len(kept.coefficients) > 2


def test_residuals_that_grow_with_the_rate_are_said_and_weights_mend_them():
    # a 1 % error on x = exp(t/2) over 30 s: the largest rows decide the plain fit; weighted by
    # 1/x² the weak form gives the rate 0.5
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 30.0, 0.1)
    x = np.exp(0.5 * t) * (1.0 + 0.01 * rng.standard_normal(t.size))
    df = pd.DataFrame({"t": t, "x": x, "w": 1.0 / x**2})
    plain = termid.fit(df, "dx/dt", ["x", "x^2"])
    assert any("grow with the size of `dx/dt`" in n for n in plain.notes)
    weighted = termid.fit(df, "dx/dt", ["x", "x^2"], weights="w")
    assert list(weighted.coefficients.index) == ["x"]
    assert abs(weighted.coefficients["x"] - 0.5) < 0.005


def _driven_oscillator(late=0, levels=None):
    """ẍ = −4x − 0.3ẋ + 2F with F held for 50 samples at a time (a controller's command), or
    at ``levels`` (one a sample), felt ``late`` samples after it is recorded, in closed form
    from sample to sample."""
    if levels is None:
        levels = np.random.default_rng(4).uniform(-2.0, 2.0, 61)[np.arange(3001) // 50]
    h = 0.01
    x, v, rows = 1.0, 0.0, []
    for k in range(3001):
        rows.append((h * k, x, v, levels[k]))
        x, v = _advance(x, v, levels[max(k - late, 0)], h)
    return pd.DataFrame(rows, columns=["t", "x", "v", "F"])


def _advance(x, v, force, dt):
    """The oscillator's (x, v) after ``dt`` s under a constant ``force``: x − F/2 a damped
    oscillation, α = 0.15, ω_d² = 4 − α²."""
    alpha = 0.15
    wd = np.sqrt(4.0 - alpha**2)
    y = x - force / 2.0
    c, s, e = np.cos(wd * dt), np.sin(wd * dt), np.exp(-alpha * dt)
    return force / 2.0 + e * (y * c + (v + alpha * y) / wd * s), e * (v * c - (alpha * v + 4.0 * y) / wd * s)


def _relay_oscillator(noise=0.0):
    """The oscillator on a relay, F = ±1 switched at random instants 0.3-1.5 s apart, anywhere
    between two samples (solved up to each switch and on from it); F recorded with ``noise``."""
    rng = np.random.default_rng(6)
    h, x, v, level, rows = 0.01, 1.0, 0.0, 1.0, []
    switch = rng.uniform(0.3, 1.5)
    for k in range(3001):
        t = h * k
        rows.append((t, x, v, level + noise * rng.standard_normal()))
        at = t
        while switch < t + h:
            x, v = _advance(x, v, level, switch - at)
            at, level = switch, -level
            switch += rng.uniform(0.3, 1.5)
        x, v = _advance(x, v, level, t + h - at)
    return pd.DataFrame(rows, columns=["t", "x", "v", "F"])


def test_a_relay_switched_between_samples_is_left_out_of_the_windows():
    # the instants of a relay's switches are not in the rows: the windows that hold one are
    # left out (with a warning and a note), and the true terms come out; as a line across
    # each switch the damping is off
    df = _relay_oscillator()
    library = ["x", "v", "F", "x^2", "x*F"]
    with pytest.warns(UserWarning, match="`F` stays put .* on no clock"):
        fit = termid.fit(df, "dv/dt", library)
    assert fit.coefficients.sort_index().round(6).to_dict() == {"F": 2.0, "v": -0.3, "x": -4.0}
    assert any("windows of the weak or integral form" in n and "left out" in n for n in fit.notes)
    linear = termid.fit(df, "dv/dt", library, intersample="linear")
    assert abs(linear.coefficients["v"] + 0.3) > 1e-3
    # measured with its noise, each switch is a step of the input: not cut, left out the same
    with pytest.warns(UserWarning, match="a step of the input"):
        noisy = termid.fit(_relay_oscillator(noise=0.01), "dv/dt", library)
    assert noisy.coefficients.sort_index().to_dict() == pytest.approx({"F": 2.0, "v": -0.3, "x": -4.0}, rel=2e-3)


def test_a_force_held_between_samples_is_integrated_as_held():
    # held (the default, with a warning) the true terms; as a line between samples the
    # damping is off by over 1 %
    df = _driven_oscillator()
    library = ["x", "v", "F", "x^2", "x*F"]
    with pytest.warns(UserWarning, match="`F` stays put .* on a clock of 50 samples"):
        held = termid.fit(df, "dv/dt", library)
    assert held.coefficients.sort_index().round(5).to_dict() == {"F": 2.0, "v": -0.3, "x": -4.0}
    linear = termid.fit(df, "dv/dt", library, intersample="linear")
    assert abs(linear.coefficients["v"] + 0.3) > 0.003
    with pytest.raises(termid.TermidError, match="intersample"):
        termid.fit(df, "dv/dt", library, intersample="zoh")


def test_a_force_a_generator_steps_at_every_sample_is_held():
    # white excitation, a new level every sample: held with a warning, the true terms (as a
    # line between the samples the damping was 2 % off), no noise said of the exact records
    df = _driven_oscillator(levels=np.random.default_rng(8).uniform(-2.0, 2.0, 3001))
    library = ["x", "v", "F", "x^2", "x*F"]
    with pytest.warns(UserWarning, match="`F` changes at every sample by as much as its spread"):
        held = termid.fit(df, "dv/dt", library)
    assert held.coefficients.sort_index().round(4).to_dict() == {"F": 2.0, "v": -0.3, "x": -4.0}
    assert not any("noise" in n for n in held.notes), held.notes
    linear = termid.fit(df, "dv/dt", library, intersample="linear")
    assert abs(linear.coefficients["v"] + 0.3) > 0.003


def test_an_array_without_column_names_is_refused_with_the_remedy():
    with pytest.raises(TypeError, match=r"2-D numpy array, whose columns have no names: name them, pd.DataFrame"):
        termid.Model.from_states(["x"]).identify(np.zeros((50, 2)))


def test_a_command_slower_than_the_rows_is_held():
    # a smooth command computed every 10 samples and held between: it moves by a little at
    # every tick, as a slower sensor's readings would; the oscillator's rate steps where it
    # changes, so it is held (with a warning) and the true terms come out
    tick = 0.1 * (np.arange(3001) // 10)
    levels = np.sin(0.7 * tick) + 0.5 * np.sin(1.9 * tick + 0.3) + 0.3 * np.sin(3.1 * tick)
    df = _driven_oscillator(levels=levels)
    with pytest.warns(UserWarning, match="the rate of `v` steps where it changes"):
        fit = termid.fit(df, "dv/dt", ["x", "v", "F", "x^2", "x*F"])
    assert fit.coefficients.sort_index().round(5).to_dict() == {"F": 2.0, "v": -0.3, "x": -4.0}


def test_a_force_acting_late_is_said_and_fitted_with_its_delay():
    # the force felt 20 samples (0.2 s) after it is recorded: said in the notes; read 0.2 s
    # earlier (delays=) the true terms
    df = _driven_oscillator(late=20)
    library = ["x", "v", "F", "x^2", "x*F"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = termid.fit(df, "dv/dt", library)
        late = termid.fit(df, "dv/dt", library, delays={"F": 0.2})
    assert any("`F` acts on dv/dt about 0.200 s later than the rows have it" in n for n in plain.notes)
    assert late.coefficients.sort_index().round(5).to_dict() == {"F": 2.0, "v": -0.3, "x": -4.0}
    assert not any("acts on" in n for n in late.notes)


def test_a_smooth_input_declared_late_is_read_as_it_acts():
    # ẋ = −0.5x + 0.8u(t − 0.5), u three sines logged every 0.05 s: judged as logged, u reads
    # as a DAC's hold (a hold reads half a sample late, as the delay does), 1 % off with a
    # spurious x³; judged as it acts (delays=), a line between its samples and the true terms
    def u(t):
        return 1.5 * np.sin(0.31 * t) + np.sin(0.83 * t + 1.0) + 0.5 * np.sin(2.1 * t + 2.0)

    def rate(t, x):
        return -0.5 * x + (0.8 * u(t - 0.5) if t >= 0.5 else 0.0)

    h, x, rows = 0.005, 0.0, []
    for k in range(4000):
        rows.append((0.05 * k, x, u(0.05 * k)))
        for j in range(10):
            t = 0.05 * k + h * j
            k1 = rate(t, x)
            k2 = rate(t + h / 2, x + h / 2 * k1)
            k3 = rate(t + h / 2, x + h / 2 * k2)
            k4 = rate(t + h, x + h * k3)
            x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    df = pd.DataFrame(rows, columns=["t", "x", "u"])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        late = termid.fit(df, "dx/dt", ["x", "u", "x^3"], delays={"u": 0.5})
    assert late.coefficients.sort_index().round(3).to_dict() == {"u": 0.8, "x": -0.5}
    assert not any("taken as held" in str(w.message) for w in said), [str(w.message) for w in said]


def test_an_input_through_a_first_order_lag_is_said_and_fitted_through_it():
    # ẋ = −0.5x + 0.8y, ẏ = (u − y)/0.5 (an actuator's lag), u three sines logged every
    # 0.05 s, the actuator starting from 0: the notes say the lag (better than a dead time
    # over the same rows) and how to fit it; read through it (lags=), the true terms
    def u(t):
        return 1.5 * np.sin(0.31 * t) + np.sin(0.83 * t + 1.0) + 0.5 * np.sin(2.1 * t + 2.0)

    def rate(t, s):
        return np.array([-0.5 * s[0] + 0.8 * s[1], (u(t) - s[1]) / 0.5])

    h, s, rows = 0.005, np.zeros(2), []
    for k in range(4000):
        rows.append((0.05 * k, s[0], u(0.05 * k)))
        for j in range(10):
            t = 0.05 * k + h * j
            k1 = rate(t, s)
            k2 = rate(t + h / 2, s + h / 2 * k1)
            k3 = rate(t + h / 2, s + h / 2 * k2)
            k4 = rate(t + h, s + h * k3)
            s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    df = pd.DataFrame(rows, columns=["t", "x", "u"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = termid.fit(df, "dx/dt", ["x", "u", "x^3"])
        lagged = termid.fit(df, "dx/dt", ["x", "u", "x^3"], lags={"u": 0.5})
    assert any("a first-order lag of 0.500 s" in n and 'lags={"u": 0.500}' in n for n in plain.notes), plain.notes
    assert lagged.coefficients.sort_index().round(3).to_dict() == {"u": 0.8, "x": -0.5}
    assert not any("acts on" in n for n in lagged.notes)


def _lorenz_log(repeated, start=(-8.0, 7.0, 27.0), rows=10_001):
    # Lorenz every 1 ms from `start` (RK4), the columns `repeated` read every 10th row and
    # written again until the next reading (a slower sensor merged and filled forward)
    def rate(s):
        x, y, z = s
        return np.array([10.0 * (y - x), x * (28.0 - z) - y, x * y - 8.0 / 3.0 * z])

    h, s, out = 0.001, np.array(start), []
    for _ in range(rows):
        out.append(s)
        k1 = rate(s)
        k2 = rate(s + 0.5 * h * k1)
        k3 = rate(s + 0.5 * h * k2)
        k4 = rate(s + h * k3)
        s = s + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    df = pd.DataFrame(out, columns=["x", "y", "z"])
    df.insert(0, "t", 0.001 * np.arange(len(df)))
    for name in repeated:
        df[name] = df[name].iloc[::10].reindex(df.index).ffill()
    return df


_QUADRATIC = ["x", "y", "z", "x*y", "x*z", "y*z", "x^2", "y^2", "z^2"]


def _lorenz_y_within(fit, share):
    # whether a fit of dy/dt chose Lorenz's three terms, each within `share` of 28, -1, -1
    want = {"x": 28.0, "x*z": -1.0, "y": -1.0}
    got = fit.coefficients.to_dict()
    return got.keys() == want.keys() and all(abs(got[k] - w) < share * abs(w) for k, w in want.items())


def test_a_state_repeated_between_its_readings_is_read_at_them():
    # x read every 10th row: said, and dy/dt's three true terms within 0.1 %; taken as the
    # rows have it (intersample="linear"), not
    df = _lorenz_log("x")
    with pytest.warns(UserWarning, match="`x` changes only every 10 rows"):
        assert _lorenz_y_within(termid.fit(df, "dy/dt", _QUADRATIC), 1e-3)
    assert not _lorenz_y_within(termid.fit(df, "dy/dt", _QUADRATIC, intersample="linear"), 1e-2)


def test_a_column_blank_between_readings_is_refused_with_the_remedy():
    # sensors merged without filling: NaN between a slower sensor's readings is refused at
    # its row, saying to fill it forward (which the test above reads right)
    df = _lorenz_log("", rows=300)
    df.loc[df.index % 10 != 0, "x"] = np.nan
    with pytest.raises(termid.TermidError, match=r"row 2 \(index 1\), column `x`: value NaN .* fill it forward"):
        termid.fit(df, "dy/dt", ["x", "y", "x*z"])
    # a model's runs alike, each run's rows by its own index
    runs = [_lorenz_log("", rows=300), df.set_index(df.index + 5000)]
    with pytest.raises(termid.TermidError, match=r"run2: row 2 \(index 5001\), column `x`"):
        termid.Model.from_states(["x", "y", "z"]).identify(runs)


def test_records_joined_in_one_frame_are_cut_into_runs():
    # two runs from different starts one after the other on one clock: cut where every
    # state leaps, with a warning, and dy/dt's true terms within 0.01 %
    first = _lorenz_log("", rows=3000)
    second = _lorenz_log("", start=(5.0, -5.0, 10.0), rows=3000)
    second["t"] += 3.0
    df = pd.concat([first, second], ignore_index=True)
    with pytest.warns(UserWarning, match="leap from row 3000 to row 3001 .* the run is cut there"):
        assert _lorenz_y_within(termid.fit(df, "dy/dt", _QUADRATIC), 1e-4)


def test_a_loggers_dropouts_cut_the_rows_into_runs():
    # rows 2000-2400 and 4000-4200 missing (0.4 s and 0.2 s without a sample): integrated
    # across as a line before, with nothing said; now cut there, with a warning
    df = _lorenz_log("", rows=6000)
    df = df.drop(index=list(range(2000, 2401)) + list(range(4000, 4201))).reset_index(drop=True)
    with pytest.warns(UserWarning, match="`t` jumps at 2 rows .* a gap in the record .* cut there"):
        assert _lorenz_y_within(termid.fit(df, "dy/dt", _QUADRATIC), 1e-4)


def test_the_rows_that_cannot_choose_are_said():
    """Hald's cement against Draper & Smith's sums of squares of its pairs: forward stepping's
    {x4, x1} leaves 74.76, {x2, x1} 57.90, so x2 in x4's place is 2.25 residual variances
    better (within the noise: a note), and x3 is x1's closest rival ({x4, x3}: 175.74)."""
    hald = pd.read_csv(os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "hald.csv"))
    fitted = termid.fit(hald, "y", ["x1", "x2", "x3", "x4"])
    rivals = fitted.rivals
    assert rivals.loc["x4", "instead"] == "x2" and rivals.loc["x1", "instead"] == "x3"
    assert rivals.loc["x4", "rise"] == pytest.approx((57.90 - 74.76) / 7.476, abs=2e-3)
    assert rivals.loc["x1", "rise"] == pytest.approx((175.74 - 74.76) / 7.476, abs=2e-3)
    assert any("hardly tell `x4` from `x2`" in n for n in fitted.notes)
    assert "Notes:\n[1] the rows hardly tell" in str(fitted.summary())


def test_the_empty_column_of_a_trailing_comma_is_no_column(tmp_path):
    # a spreadsheet's export ends every row with a comma: pandas reads an empty `Unnamed: 3`,
    # whose name refused the run; it holds nothing and is left out (one that holds numbers,
    # pandas' own index written to the file, is a column as before)
    t = np.arange(0.0, 10.0, 0.01)
    lines = ["t,x,u,"] + [f"{a},{np.exp(-a) + 0.1 * np.sin(a)},{np.sin(a)}," for a in t]
    path = tmp_path / "export.csv"
    path.write_text("\n".join(lines) + "\n")
    df = pd.read_csv(path)
    assert list(df.columns) == ["t", "x", "u", "Unnamed: 3"]
    fitted = termid.fit(df, "dx/dt", ["x", "u"])
    assert "x" in fitted.coefficients.index
    with pytest.raises(termid.TermidError, match="Unnamed: 3"):
        termid.fit(df.assign(**{"Unnamed: 3": np.arange(len(df), dtype=float)}), "dx/dt", ["x", "u", "Unnamed: 3"])


def test_a_series_is_one_named_column_and_a_formula_s_sum_is_said():
    # a Series over an index of times (one signal) failed deep in Arrow ("Cannot import
    # schema"); it is the one-column frame it is. `"x + x^2"`, a formula's two terms in
    # statsmodels or R, is one candidate here, their sum: fitted, and said with the list
    t = np.arange(0.0, 20.0, 0.01)
    x = pd.Series(np.exp(-0.3 * t), index=pd.Index(t, name="t"), name="x")
    assert termid.fit(x, "dx/dt", ["x"]).coefficients.to_dict() == pytest.approx({"x": -0.3}, rel=1e-6)
    found = termid.Model.from_states(["x"]).identify(x)
    assert found.model.coefficients("x_dot").set_index("term")["value"].to_dict() == pytest.approx({"x": -0.3}, rel=1e-6)
    with pytest.raises(termid.TermidError, match="a Series without a name is no column"):
        termid.fit(x.rename(None), "dx/dt", ["x"])
    with pytest.warns(UserWarning, match=r"terms 'x \+ x\^2' is one candidate, their sum with one coefficient; for a coefficient each, list them: \['x', 'x\^2'\]"):
        summed = termid.fit(x, "dx/dt", "x + x^2")
    assert list(summed.coefficients.index) != ["x", "x^2"]


def test_a_fit_is_scored_on_held_out_rows_as_scikit_learn_scores():
    # R² on rows not fitted to, against numbers worked by hand; a rate is no column
    fitted = termid.fit(pd.DataFrame({"x": [0.0, 1, 2, 3], "y": [1.0, 3, 5, 7]}), "y", "x")
    held = pd.DataFrame({"x": [4.0, 5.0, 6.0], "y": [9.0, 11.0, 14.0]})
    # predictions 9, 11, 13: residuals 0, 0, 1; about the mean 34/3 the squares sum to 38/3
    assert fitted.score(held) == pytest.approx(1.0 - 1.0 / 12.666666666666666)
    t = np.arange(0.0, 10.0, 0.01)
    rate = termid.fit(pd.DataFrame({"t": t, "x": np.exp(-0.3 * t)}), "dx/dt", ["x"])
    with pytest.raises(termid.TermidError, match="a rate's fit is judged by re-simulating its runs"):
        rate.score(pd.DataFrame({"t": t, "x": np.exp(-0.3 * t)}))
