"""Model files from Python: load, write, identify, predict, simulate, validate."""
import math
import os
import pickle
import re
import warnings

import numpy as np
import pandas as pd
import pytest

import termid


def test_default_ship_round_trips_through_toml(ship, tmp_path):
    path = tmp_path / "ship.toml"
    ship.save(path)
    again = termid.Model.load(path)
    assert again.equations == ship.equations
    pd.testing.assert_frame_equal(again.coefficients("r_dot"), ship.coefficients("r_dot"))
    assert termid.Model.from_toml(ship.to_toml()).states == ["u", "v", "r", "ψ", "x0", "y0"]


def test_a_model_file_error_names_file_and_key(ship, tmp_path):
    text = ship.to_toml().replace('"u*r",', '"u*r*",', 1)
    path = tmp_path / "typo.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(termid.TermidError) as e:
        termid.Model.load(path)
    message = str(e.value)
    assert "typo.toml" in message and "^" in message


def test_identify_from_exact_zigzags_gives_table_2(ship, zigzags):
    identified = ship.identify(zigzags, target="column")
    # the paper's Table 2 (the default model's own coefficients) comes back from exact runs
    truth = ship.coefficients("r_dot").set_index("term")["value"]
    found = identified.model.coefficients("r_dot").set_index("term")["value"]
    for term in ["r*u", "u*v", "u^2*δ"]:
        assert found[term] == pytest.approx(truth[term], rel=2e-2), term
    steps = identified.steps("r_dot")
    assert {"term", "f", "r2"} <= set(steps.columns)


def test_predict_is_the_model_right_hand_side(ship, zigzags):
    run = zigzags[0]
    predicted = ship.predict(run)
    # the simulation's own ẋ columns at its samples (the same equations)
    np.testing.assert_allclose(predicted["r_dot"], run["r_dot"], atol=1e-12)
    np.testing.assert_allclose(predicted["v_dot"], run["v_dot"], atol=1e-12)


def test_simulate_zigzag_metrics(ship):
    run = ship.simulate("zigzag:20/20", dt=0.01)
    assert list(run.columns[:3]) == ["t", "u", "v"]
    metrics = run.attrs["metrics"]
    # the first overshoot read off the run's own heading: its largest excursion beyond the
    # 20° check between the first and the second rudder reversal
    psi, delta = np.degrees(run["ψ"].to_numpy()), np.degrees(run["δ"].to_numpy())
    first = np.argmax(psi >= 20.0)
    second = first + np.argmax(psi[first:] <= -20.0)
    assert metrics["first_overshoot_deg"] == pytest.approx(psi[first:second].max() - 20.0, abs=0.05)
    assert np.abs(delta).max() == pytest.approx(20.0, abs=1.0)


def test_replay_and_validate_of_the_models_own_run(ship, zigzags):
    replayed = ship.replay(zigzags[0])[0]
    np.testing.assert_allclose(replayed["r"].to_numpy(), zigzags[0]["r"].to_numpy(), atol=1e-9)
    report = ship.validate(zigzags[:1])
    # per run and state: unit, RMS error, largest error, as a DataFrame
    assert list(report.columns) == ["unit", "rms", "max"] and report.index.names == ["run", "state"]
    assert (report["rms"] < 1e-9).all() and (report["max"] < 1e-9).all()
    assert report.loc[(zigzags[0].attrs["name"], "u"), "unit"] == "m/s"
    metrics = report.attrs["metrics"]
    assert metrics.loc[(zigzags[0].attrs["name"], "simulated"), "first_overshoot_deg"] > 0
    raw = ship.validate(zigzags[:1], raw=True)
    for name, unit, rms, largest in raw["gap"]["states"]:
        assert rms < 1e-9 and largest < 1e-9, name


def test_plain_ascii_columns_are_read_as_aliases(ship, zigzags):
    run = zigzags[0].rename(columns={"δ": "delta", "ψ": "psi"})
    with pytest.warns(UserWarning, match="alias"):
        predicted = ship.predict(run)
    assert "r_dot" in predicted


def test_degrees_in_a_radian_column_are_refused(ship, zigzags):
    run = zigzags[0].copy()
    run["δ"] = np.degrees(run["δ"]) * 10.0
    with pytest.raises(termid.TermidError, match="degrees"):
        ship.predict(run)


def test_checks_and_diagnose(ship, zigzags):
    checks = ship.checks()
    assert {"name", "passed", "refuses", "detail"} <= set(checks.columns)
    assert checks["passed"].all()
    report, improved = ship.diagnose(zigzags[:2])
    assert {"unit", "rms_before", "max_before"} <= set(report.columns)
    assert "leading_state" in report.attrs["location"]
    raw, _ = ship.diagnose(zigzags[:2], raw=True)
    assert "gap_before" in raw


# Nomoto's model with its rudder indicator's zero declared a nuisance of each run
with open(os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "nomoto_zero.toml"), encoding="utf-8") as _file:
    NOMOTO_ZERO = _file.read()


def test_diagnose_each_run_with_its_own_nuisances():
    """A Nomoto ship whose rudder indicator's zero, declared a nuisance of each run, is 1.5°
    off one way in one run and the other way in the next: diagnosed with each run's own zero,
    found first (``attrs["own_values"]``), and nothing claimed for what the zeros explain."""
    declared = termid.Model.from_toml(NOMOTO_ZERO)
    t = np.arange(0.0, 120.0, 0.1)
    rudder = np.where((t // 20) % 2 == 0, 0.2, -0.2)
    rng = np.random.default_rng(5)
    runs = []
    for offset in (1.5, -1.5):
        truth = termid.Model.from_toml(NOMOTO_ZERO)
        truth.set_parameter("δ_0", np.radians(offset))
        run = truth.replay(pd.DataFrame({"t": t, "ψ": 0.0, "r": 0.0, "δ": rudder}))[0][["t", "ψ", "r"]].assign(δ=rudder)
        run["ψ"] += np.radians(0.1) * rng.standard_normal(len(run))
        runs.append(run)
    gaps, repaired = declared.diagnose(runs)
    own = np.degrees(gaps.attrs["own_values"]["value"].to_numpy())
    assert len(own) == 2 and abs(own[0] - 1.5) < 0.1 and abs(own[1] + 1.5) < 0.1, gaps.attrs["own_values"]
    assert gaps.attrs["effect"] is None and repaired is None
    # the Nomoto file declares no nuisance: none estimated
    plain, _ = termid.Model.builtin("nomoto").diagnose(runs[0])
    assert plain.attrs["own_values"].empty


def test_basin_records_are_noisy_and_seeded(ship):
    a = ship.record("zigzag:20/20", seed=3, duration=40.0)
    b = ship.record("zigzag:20/20", seed=3, duration=40.0)
    exact = ship.record("zigzag:20/20", seed=3, duration=40.0, truth=True)
    pd.testing.assert_frame_equal(a, b)
    assert 0 < (a["r"] - exact["r"]).std() < 1e-2


def test_per_run_rule_is_set_and_checked(zigzags):
    ship = termid.Model.default()
    ship.set_parameter("u0", "mean:u:4")
    assert 'per_run = "mean:u:4"' in ship.to_toml()
    with pytest.raises(termid.TermidError, match="per_run"):
        ship.set_parameter("u0", "middle:u")
    with pytest.raises(termid.TermidError, match="not a parameter"):
        ship.set_parameter("w0", 1.0)


def _fall_back(seconds: pd.Series) -> pd.DatetimeIndex:
    """The times in Berlin from ten seconds before the clocks went back an hour (2026-10-25)."""
    return (pd.Timestamp("2026-10-25 00:59:50", tz="UTC") + pd.to_timedelta(seconds.to_numpy(), unit="s")).tz_convert("Europe/Berlin")


def test_a_time_column_of_durations_or_dates_is_read_in_seconds(ship, zigzags):
    run = zigzags[0]
    base = ship.identify([run], target="column").model.coefficients("r_dot").set_index("term")["value"]
    for t in [pd.to_timedelta(run.t, unit="s"), pd.Timestamp("2026-11-25 12:00") + pd.to_timedelta(run.t, unit="s")]:
        with pytest.warns(UserWarning, match="read as seconds"):
            again = ship.identify([run.assign(t=t)], target="column")
        found = again.model.coefficients("r_dot").set_index("term")["value"]
        pd.testing.assert_series_equal(found, base)
    # or the run's index holds the time, as in `fit` (in a time zone: read in UTC)
    for index in [run.t, _fall_back(run.t)]:
        again = ship.identify([run.drop(columns="t").set_index(index)], target="column")
        found = again.model.coefficients("r_dot").set_index("term")["value"]
        pd.testing.assert_series_equal(found, base)


def test_the_target_is_the_callers_choice_and_said(ship, zigzags):
    run = zigzags[0]
    doubled = run.assign(r_dot=2 * run.r_dot)
    truth = ship.coefficients("r_dot").set_index("term")["value"]
    # a named derivative method is used, whatever rate columns the run carries
    by_derivative = ship.identify([doubled], "central", equations=["r_dot"])
    assert by_derivative.targets == {"r_dot": "dr/dt"}
    found = by_derivative.model.coefficients("r_dot").set_index("term")["value"]
    assert found["r*u"] == pytest.approx(truth["r*u"], rel=0.05)
    # the columns when asked for (or when no method is named): twice the rate, twice the coefficients
    by_column = ship.identify([doubled], target="column", equations=["r_dot"])
    assert by_column.targets == {"r_dot": "r_dot"} and "r_dot ← r_dot" in repr(by_column)
    found = by_column.model.coefficients("r_dot").set_index("term")["value"]
    assert found["r*u"] == pytest.approx(2 * truth["r*u"], rel=1e-3)
    with pytest.raises(termid.TermidError, match="no column r_dot"):
        ship.identify([run.drop(columns=["r_dot"])], target="column", equations=["r_dot"])
    # statistics likewise: a named method is used, else the columns
    for derivative, factor in [("central", 1.0), (None, 2.0)]:
        m = termid.Moments.from_frame(doubled, ship, "r_dot", derivative)
        b = ship.identify_from_moments(m).model.coefficients("r_dot").set_index("term")["value"]
        assert b["r*u"] == pytest.approx(factor * truth["r*u"], rel=0.05), derivative
    with pytest.raises(ValueError):
        ship.identify([run], target="rates")


def test_errors_and_models_pickle_and_a_missing_file_is_file_not_found(ship, tmp_path):
    import pickle

    e = pickle.loads(pickle.dumps(termid.TermidError("row 3, column `u`: NaN")))
    assert isinstance(e, termid.TermidError) and "row 3" in str(e)
    again = pickle.loads(pickle.dumps(ship))
    assert again.to_toml() == ship.to_toml()
    with pytest.raises(FileNotFoundError):
        termid.Model.load(tmp_path / "nope.toml")


def test_a_run_id_column_does_not_break_identification(ship, zigzags):
    run = zigzags[0]
    base = ship.identify([run], target="column").model.coefficients("r_dot")
    tagged = ship.identify([run.assign(run_id="Z15/10")], target="column").model.coefficients("r_dot")
    pd.testing.assert_frame_equal(tagged, base)


def test_states_of_a_millionth_are_simulated_as_closely_as_states_of_one():
    # A → B in mol/L from 1e-6 (k = 0.5/s): an absolute tolerance of 1e-7, a tenth of the
    # state, ended A a hundredfold off; it is counted in how large the states start
    chain = termid.Model.from_toml(
        """
        [model]
        name = "A to B"
        [[states]]
        name = "A"
        initial = 1e-6
        [[states]]
        name = "B"
        [equations.A_dot]
        state = "A"
        coefficients = { "A" = -0.5 }
        [equations.B_dot]
        state = "B"
        coefficients = { "A" = 0.5 }
        """,
        "chain.toml",
    )
    run = chain.simulate(duration=20.0, sample=0.5)
    assert run.A.iloc[-1] == pytest.approx(1e-6 * math.exp(-10.0), rel=1e-3)
    assert run.B.iloc[-1] == pytest.approx(1e-6 * (1 - math.exp(-10.0)), rel=1e-6)


def test_lorenz_simulated_and_identified_with_the_defaults():
    # a model without a plug-in simulates from Python (it said "use replay"), and the
    # generic defaults hold here too (central differences and a forced intercept gave
    # z_dot = −57.72 + 0.698·y²)
    path = os.path.join(os.path.dirname(__file__), "..", "..", "models", "lorenz.toml")
    lorenz = termid.Model.load(path)
    run = lorenz.simulate(duration=20.0, sample=0.01)
    assert list(run.columns) == ["t", "x", "y", "z"] and len(run) == 2001
    found = lorenz.identify(run)
    assert found.targets["z_dot"] == "dz/dt"
    z = found.model.coefficients("z_dot").set_index("term")["value"]
    assert sorted(z.index) == ["x*y", "z"]
    assert z["x*y"] == pytest.approx(1.0, rel=1e-3) and z["z"] == pytest.approx(-8 / 3, rel=1e-3)
    moved = lorenz.simulate(duration=1.0, initial={"x": 1.0, "y": 1.0, "z": 1.0})
    assert moved.x.iloc[0] == 1.0
    with pytest.raises(termid.TermidError, match="not a state"):
        lorenz.simulate(duration=1.0, initial={"w": 1.0})
    # validated on its own run, the right model is predictable for about ln(1e5)/0.906 s
    # (Lorenz's largest Lyapunov exponent), and that is said
    with pytest.warns(UserWarning, match="is predictable for"):
        gap = found.model.validate(run)
    (seconds,) = gap.attrs["predictable_for"].values()
    assert 0.5 * 12.7 < seconds < 1.5 * 12.7
    # with 5 % noise y*z is y's close rival in dy/dt (z's mean is 2.8 times its spread): a
    # swap raises the residual sum of squares by some residual variances, where a swap of a
    # term the rows hold firmly raises it by thousands
    noisy = run.copy()
    rng = np.random.default_rng(3)
    for c in "xyz":
        noisy[c] += 0.05 * run[c].std() * rng.standard_normal(len(run))
    found = lorenz.identify(noisy)
    rivals = found.rivals("y_dot")
    assert rivals.loc["y", "instead"] == "y*z" and abs(rivals.loc["y", "rise"]) < 50, rivals
    assert rivals.loc["x", "rise"] > 1000 and rivals.loc["x*z", "rise"] > 1000, rivals

    assert found.rivals("y_dot").loc["x*z", "rise"] > 100


def test_tolerances_set_from_python_are_the_simulations():
    # Lorenz after 1 s against scipy's DOP853 at 1e-13 (x, y, z = 5.52368, 9.51880, 13.58350):
    # within 1e-9 at tight tolerances, within 1e-4 at the defaults; refused where no step
    # control works
    lorenz = termid.Model.builtin("lorenz")
    want = np.array([5.523676640069421, 9.518798956834514, 13.583499714528173])
    default = lorenz.simulate(duration=1.0, sample=0.5)[["x", "y", "z"]].iloc[-1].to_numpy()
    lorenz.set_tolerances(rtol=1e-11, atol=1e-12)
    tight = lorenz.simulate(duration=1.0, sample=0.5)[["x", "y", "z"]].iloc[-1].to_numpy()
    assert np.max(np.abs(tight - want) / want) < 1e-9
    assert 1e-9 < np.max(np.abs(default - want) / want) < 1e-4
    # for one run: the model keeps its own
    fresh = termid.Model.builtin("lorenz")
    once = fresh.simulate(duration=1.0, sample=0.5, rtol=1e-11, atol=1e-12)[["x", "y", "z"]].iloc[-1].to_numpy()
    assert np.max(np.abs(once - want) / want) < 1e-9
    again = fresh.simulate(duration=1.0, sample=0.5)[["x", "y", "z"]].iloc[-1].to_numpy()
    assert np.array_equal(again, default)
    for bad in [dict(rtol=2.0), dict(atol=-1.0), dict(rtol=float("nan"))]:
        with pytest.raises(termid.TermidError, match="rtol lies in"):
            lorenz.set_tolerances(**bad)




def test_a_stiff_model_is_simulated_right_and_said_to_be():
    # Robertson's kinetics at t = 40 against Hairer & Wanner's reference; the default method
    # turns linearly implicit and warns, the asked-for Rosenbrock method does not warn
    want = np.array([0.7158270687, 9.185534764e-6, 0.2841637457])
    robertson = termid.Model.builtin("robertson")
    with pytest.warns(UserWarning, match="stiff from t ="):
        run = robertson.simulate(duration=40.0, sample=1.0)
    assert np.max(np.abs(run[["a", "b", "c"]].iloc[-1].to_numpy() - want) / want) < 2e-5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = robertson.simulate(duration=40.0, sample=1.0, integrator="rosenbrock")
    assert np.max(np.abs(run[["a", "b", "c"]].iloc[-1].to_numpy() - want) / want) < 2e-5


def test_a_stiff_model_is_estimated_at_a_stable_step():
    # Robertson's k1 from a run sampled every 0.5 s: RK4 at the samples diverges whatever k1
    # is (|λ| up to 4200 /s); re-simulated at a whole fraction of the interval, with a warning
    truth = termid.Model.builtin("robertson")
    with pytest.warns(UserWarning, match="stiff from t ="):
        run = truth.simulate(duration=100.0, sample=0.5)[["t", "a", "b", "c"]]
    start = termid.Model.from_toml(truth.to_toml().replace("value = 0.04", "value = 0.06"))
    with pytest.warns(UserWarning, match="stiff against the runs' step"):
        table, _ = start.estimate(run, free=["k1"])
    assert abs(table.loc["k1", "estimate"] / 0.04 - 1) < 1e-4, table


def test_identification_releases_the_gil(ship, zigzags):
    # while the Rust side works, a Python thread keeps running (it ran at 4 % before)
    import threading
    import time

    runs = list(zigzags) * 4
    done = threading.Event()
    spent = []

    def work():
        start = time.perf_counter()
        ship.identify(runs, target="column")
        ship.moments("r_dot", runs)
        spent.append(time.perf_counter() - start)
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    wakeups = 0
    while not done.is_set():
        time.sleep(0.001)
        wakeups += 1
    worker.join()
    # a wake-up a millisecond or so while the work runs, not one at its end
    assert wakeups > 0.2 * spent[0] / 0.001, (wakeups, spent)


def test_the_model_files_ship_inside_the_package(ship):
    assert termid.Model.builtin_names() == ["oltmann1973", "lorenz", "duffing", "mmg_kvlcc2", "new_ship", "nomoto", "robertson"]
    assert termid.Model.builtin("oltmann1973").to_toml() == ship.to_toml()
    path = os.path.join(os.path.dirname(__file__), "..", "..", "models", "lorenz.toml")
    assert termid.Model.builtin("lorenz").to_toml() == termid.Model.load(path).to_toml()
    assert termid.Model.builtin("mmg_kvlcc2").simulate("turning:35").attrs["metrics"]["tactical_diameter_m"] > 0
    with pytest.raises(termid.TermidError, match="no built-in model `kvlcc3`"):
        termid.Model.builtin("kvlcc3")


def test_estimate_recovers_nomoto_k_and_t_from_a_noisy_run():
    """Grey-box: K and T of the shipped Nomoto file (free, started at 0.1 and 10) from a
    step response with gyro noise; the truth within three standard errors."""
    truth = termid.Model.builtin("nomoto")
    truth.set_parameter("K", 0.15)
    truth.set_parameter("T", 8.0)
    run = truth.simulate(duration=80.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]]
    rng = np.random.default_rng(4)
    run["ψ"] += np.radians(0.1) * rng.standard_normal(len(run))
    run["r"] += np.radians(0.05) * rng.standard_normal(len(run))
    table, found = termid.Model.builtin("nomoto").estimate(run)
    assert list(table.index) == ["K", "T"] and table["std_error"].dtype == np.float64
    for name, value in [("K", 0.15), ("T", 8.0)]:
        row = table.loc[name]
        assert abs(row["estimate"] - value) < max(3 * row["std_error"], 1e-3 * value), table
    assert found.parameters["K"] == table.loc["K", "estimate"]
    assert table.attrs["covariance"].shape == (2, 2) and table.attrs["cost_after"] < table.attrs["cost_before"]
    # at the coarsest step that resolves the run: said, and the same within the standard errors
    coarse, _ = termid.Model.builtin("nomoto").estimate(run, coarse=True)
    assert table.attrs["step_samples"] == 1 and coarse.attrs["step_samples"] > 1
    assert ((coarse["estimate"] - table["estimate"]).abs() < table["std_error"]).all(), coarse
    # the structure holds: the initial values move by about the gyro's noise, and no warning
    assert table.attrs["from_records"]["moved"] < 3 and not table.attrs["from_records"]["leans"]
    # a ship whose rudder holds its course at −3° fitted without that offset: the fit leans on
    # its initial values, and says so
    t = np.arange(0.0, 120.0, 0.1)
    rudder = np.where((t // 20) % 2 == 0, 0.2, -0.2)  # reversed every 20 s
    laid = pd.DataFrame({"t": t, "ψ": 0.0, "r": 0.0, "δ": rudder + np.radians(3)})
    biased = truth.replay(laid)[0][["t", "ψ", "r"]].assign(δ=rudder)
    biased["ψ"] += np.radians(0.1) * rng.standard_normal(len(biased))
    biased["r"] += np.radians(0.05) * rng.standard_normal(len(biased))
    with pytest.warns(UserWarning, match="leans on its estimated initial values"):
        termid.Model.builtin("nomoto").estimate(biased, initial_values="free")
    # by default the lean is seen, the fit made again with the initial values held to the
    # records' noise and kept: it predicts the run from its record better; it does not lean,
    # and a warning says that it does not follow the record (the missing offset builds up)
    with pytest.warns(UserWarning, match="does not follow the records") as caught:
        held, _ = termid.Model.builtin("nomoto").estimate(biased)
    assert not any("leans" in str(w.message) for w in caught)
    assert held.attrs["held_again"]["kept"] and held.attrs["held_again"]["other"]["leans"]
    assert not held.attrs["from_records"]["leans"]
    with pytest.raises(ValueError, match="none of auto, measured, free, recorded"):
        termid.Model.builtin("nomoto").estimate(biased, initial_values="fixed")
    with pytest.raises(termid.TermidError, match="free"):
        termid.Model.builtin("lorenz").estimate(run.rename(columns={"ψ": "x", "r": "y", "δ": "z"}))


def test_a_compass_heading_through_north_is_read_as_one_angle():
    """A heading recorded as a compass reads it, in [0, 2π), wraps where the ship turns through
    north: the estimate reads it as one continuous angle, warns that it did, and fits K and T
    as from the continuous record."""
    truth = termid.Model.builtin("nomoto")
    truth.set_parameter("K", 0.15)
    truth.set_parameter("T", 8.0)
    t = np.arange(0.0, 90.0, 0.1)
    laid = pd.DataFrame({"t": t, "ψ": 0.0, "r": 0.0, "δ": np.where((t // 15) % 2 == 0, 0.1, -0.1)})
    run = truth.replay(laid)[0][["t", "ψ", "r", "δ"]]
    rng = np.random.default_rng(5)
    run["ψ"] += np.radians(0.1) * rng.standard_normal(len(run))
    run["r"] += np.radians(0.05) * rng.standard_normal(len(run))
    compass = run.assign(ψ=np.mod(run["ψ"], 2 * np.pi))
    assert compass["ψ"].diff().abs().max() > np.pi
    plain, _ = termid.Model.builtin("nomoto").estimate(run)
    with pytest.warns(UserWarning, match="`ψ` jumps by a full turn"):
        read, _ = termid.Model.builtin("nomoto").estimate(compass)
    assert np.allclose(read["estimate"], plain["estimate"], rtol=1e-9), (read, plain)
    assert abs(read.loc["K", "estimate"] / 0.15 - 1) < 0.05, read


LOAD_CELL = """
[model]
name = "a forced spring on a load cell"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "F"
[parameters.k]
value = K
free = true
[parameters.b]
value = B
free = true
[parameters.g]
value = G
free = true
[[derived]]
name = "cell"
definition = "g*(k*x + 0.3*x^3)"
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0 }
[equations.w_dot]
state = "w"
identify = false
coefficients = { "-k*x - 0.3*x^3 - b*w + F" = 1.0 }
"""


def test_estimate_compares_a_derived_variable_with_its_record():
    """A load cell's reading (a derived variable of the model, ``g`` its gain, which the motion
    does not show) compared beside the motion: the gain and the spring from a start 30 % off."""
    cell = lambda k, b, g: LOAD_CELL.replace("K", str(k)).replace("B", str(b)).replace("G", str(g))
    truth = termid.Model.from_toml(cell(1.4, 0.2, 0.8))
    run = truth.simulate(duration=30.0, inputs={"F": 0.5}, sample=0.05)[["t", "x", "w", "F"]]
    run["cell"] = 0.8 * (1.4 * run["x"] + 0.3 * run["x"] ** 3)
    start = termid.Model.from_toml(cell(1.0, 0.14, 1.1))
    table, found = start.estimate(run, states=["x", "w", "cell"])
    for name, value in [("k", 1.4), ("b", 0.2), ("g", 0.8)]:
        assert abs(table.loc[name, "estimate"] / value - 1) < 0.01, table
    with pytest.raises(termid.TermidError, match="its derived variables cell"):
        start.estimate(run, states=["x", "torque"])
    # beside a run without the cell's record, the cell is compared in the run that has it
    other = truth.simulate(duration=20.0, inputs={"F": -0.3}, sample=0.05)[["t", "x", "w", "F"]]
    table, _ = start.estimate([run, other], states=["x", "w", "cell"])
    assert table["from_runs"].isna().all(), table  # no priors: no share to tell
    assert abs(table.loc["g", "estimate"] / 0.8 - 1) < 0.01, table
    assert table.attrs["partly_recorded"].to_dict("records") == [{"name": "cell", "runs": 1, "of": 2}]
    assert table.attrs["partly_recorded"].columns.tolist() == ["name", "runs", "of"]


def test_estimate_says_what_the_runs_decide():
    """``from_runs``: the share of a parameter's precision the runs gave; the cell's gain,
    with a prior and not compared, gets none of it and stays at its prior's mean; no pair of
    estimates is tied (``attrs["correlated"]`` empty)."""
    cell = lambda k, b, g: LOAD_CELL.replace("K", str(k)).replace("B", str(b)).replace("G", str(g))
    truth = termid.Model.from_toml(cell(1.4, 0.2, 0.8))
    run = truth.simulate(duration=30.0, inputs={"F": 0.5}, sample=0.05)[["t", "x", "w", "F"]]
    text = cell(1.0, 0.14, 1.1).replace("value = 1.1\nfree = true", "value = 1.1\nfree = true\nprior = { value = 1.1, sd = 0.2 }")
    table, _ = termid.Model.from_toml(text).estimate(run, states=["x", "w"])
    assert table.loc["g", "from_runs"] < 0.01 and abs(table.loc["g", "estimate"] - 1.1) < 1e-6, table
    assert abs(table.loc["g", "std_error"] - 0.2) < 1e-3, table
    assert table[["from_runs"]].loc[["k", "b"]].isna().all().all(), table
    assert table.attrs["correlated"].empty and list(table.attrs["correlated"].columns) == ["a", "b", "correlation"]


PREDATORS = """
[model]
name = "Lotka-Volterra, a prey x and its predator y"
[[states]]
name = "x"
initial = 10.0
[[states]]
name = "y"
initial = 5.0
[parameters.a]
value = A
free = true
[parameters.b]
value = B
free = true
[parameters.c]
value = C
free = true
[parameters.d]
value = D
free = true
[equations.x_dot]
state = "x"
identify = false
coefficients = { "a*x" = 1.0, "b*x*y" = -1.0 }
[equations.y_dot]
state = "y"
identify = false
coefficients = { "d*x*y" = 1.0, "c*y" = -1.0 }
"""


def test_estimate_searches_where_the_fit_does_not_follow_its_records():
    """A predator and its prey started 33-47 % off: from the file's values the fit's cycles
    drift out of phase and stop in a minimum that is not the system's; ``attrs["segmented"]``
    says the fit from a start found on segments of the run was kept, and it is the truth's.
    Cut into segments by ``segments=``, the same comes back; a warning where no fit follows."""
    text = lambda a, b, c, d: PREDATORS.replace("A", str(a)).replace("B", str(b)).replace("C", str(c)).replace("D", str(d))
    truth = termid.Model.from_toml(text(1.0, 0.1, 1.5, 0.075))
    run = truth.simulate(duration=30.0, sample=0.1)[["t", "x", "y"]]
    start = termid.Model.from_toml(text(0.6, 0.15, 2.2, 0.05))
    table, _ = start.estimate(run)
    searched = table.attrs["segmented"]
    assert searched["kept"] and searched["other_unexplained"] > 0.1, searched
    assert table.attrs["unexplained"] < 0.01, table.attrs["unexplained"]
    for name, value in [("a", 1.0), ("b", 0.1), ("c", 1.5), ("d", 0.075)]:
        assert abs(table.loc[name, "estimate"] / value - 1) < 0.01, table
    table, _ = start.estimate(run, segments=10)
    assert abs(table.loc["c", "estimate"] / 1.5 - 1) < 0.01, table
    with pytest.raises(ValueError, match="segments"):
        start.estimate(run, segments=1)
    # a prey limited by its own numbers, not eaten: no fit follows the cycles
    wrong = termid.Model.from_toml(text(0.6, 0.15, 2.2, 0.05).replace('"b*x*y" = -1.0', '"b*x^2" = -1.0'))
    with pytest.warns(UserWarning, match="does not follow the records"):
        wrong.estimate(run)


def test_estimate_reads_a_ships_metrics_off_its_fit():
    """For a ship, ``attrs["metrics"]``: each run's overshoots measured beside the fit's
    re-simulation; the MMG model's rudder wake ratio ε started 25 % low and estimated from
    its own noise-free zigzag: the fit's overshoots are the record's."""
    truth = termid.Model.builtin("mmg_kvlcc2")
    run = truth.record("zigzag:20/20", truth=True, duration=80.0)
    text = truth.to_toml().replace('[parameters."ε"]\nvalue = 1.09\n', '[parameters."ε"]\nvalue = 0.82\nfree = true\n')
    table, _ = termid.Model.from_toml(text).estimate(run)
    assert abs(table.loc["ε", "estimate"] - 1.09) < 0.01, table
    metrics = table.attrs["metrics"].set_index("metric")
    assert {"first_overshoot_deg", "second_overshoot_deg"} <= set(metrics.index), metrics
    assert ((metrics["simulated"] - metrics["measured"]).abs() < 0.05).all(), metrics
    assert table.attrs["metric_checks"]["passed"].all(), table.attrs["metric_checks"]
    # no plug-in owns the Nomoto model: no metrics
    nomoto = termid.Model.builtin("nomoto")
    step = nomoto.simulate(duration=20.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]]
    assert nomoto.estimate(step)[0].attrs["metrics"].empty


def test_estimate_per_run():
    """A parameter estimated once per run: each run's own value in ``attrs["per_source"]``
    (named by its run), the model holding their mean, ``attrs["per_run"]`` their spread."""
    runs = []
    for k in (0.15, 0.17):
        truth = termid.Model.builtin("nomoto")
        truth.set_parameter("K", k)
        truth.set_parameter("T", 8.0)
        runs.append(truth.simulate(duration=60.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]])
    table, found = termid.Model.builtin("nomoto").estimate(runs, per_run=["K"])
    own = table.attrs["per_source"]
    assert list(own["name"]) == ["K", "K"] and own["run"].notna().all()
    assert np.allclose(own["value"], [0.15, 0.17], rtol=1e-3), own
    spread = table.attrs["per_run"].set_index("name").loc["K"]
    assert spread["runs"] == 2 and abs(spread["mean"] - 0.16) < 1e-4 and abs(spread["sd"] - 0.01414) < 1e-4
    assert abs(found.parameters["K"] - spread["mean"]) < 1e-12
    assert abs(table.loc["T", "estimate"] - 8.0) < 0.01


def test_estimate_one_value_where_the_runs_agree():
    """A parameter the model file declares per run (``nuisance = "run"``): where the runs'
    values differ it stays per run with the test in ``attrs["per_run"]``; where they agree
    (one K, noisy records) one value is estimated for all and ``attrs["one_value"]`` says so."""
    text = termid.Model.builtin("nomoto").to_toml().replace(
        "[parameters.K]\n", '[parameters.K]\nnuisance = "run"\n', 1
    )
    declared = termid.Model.from_toml(text)
    rng = np.random.default_rng(7)

    def records(ks):
        runs = []
        for k in ks:
            truth = termid.Model.builtin("nomoto")
            truth.set_parameter("K", k)
            truth.set_parameter("T", 8.0)
            run = truth.simulate(duration=60.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]]
            run["ψ"] += rng.normal(0.0, 0.002, len(run))
            run["r"] += rng.normal(0.0, 0.0005, len(run))
            runs.append(run)
        return runs

    table, _ = declared.estimate(records([0.15, 0.17]))
    spread = table.attrs["per_run"].set_index("name").loc["K"]
    assert spread["p_value"] < 1e-3 and table.attrs["one_value"].empty
    table, found = declared.estimate(records([0.16, 0.16, 0.16]))
    agreed = table.attrs["one_value"].set_index("name").loc["K"]
    assert agreed["runs"] == 3 and agreed["p_value"] >= 0.05 and table.attrs["per_run"].empty
    assert abs(table.loc["K", "estimate"] - 0.16) < 0.002 and found.parameters["K"] == table.loc["K", "estimate"]


def test_recipe_estimates_each_basins_rudder_zero():
    """The new-ship template from two basins whose rudder indicators read +0.3° and −0.5°
    off: the recipe's parameter stage estimates each basin's zero with the coefficients; their
    difference comes back (the common part trades against the template's asymmetry terms)."""
    truth = termid.Model.builtin("mmg_kvlcc2")
    runs, sources = [], []
    for source, (offset, seed) in enumerate([(0.3, 41), (-0.5, 51)]):
        for k, manoeuvre in enumerate(["zigzag:20/20", "zigzag:20/20:port", "zigzag:10/10"]):
            run = truth.record(manoeuvre, duration=60.0, seed=seed + k)
            run["δ"] += np.radians(offset)
            runs.append(run)
            sources.append(source)
    found = termid.Model.builtin("new_ship").recipe(
        runs, ["kalman"], refine=None, per_source=["δ_0"], sources=sources
    )
    zeros = {p["source"]: p["value"] for p in found.parameters["per_source"]}
    assert abs(np.degrees(zeros[0] - zeros[1]) - 0.8) < 0.1, found.text
    assert found.model.parameters["δ_0"] == 0.0
    with pytest.raises(termid.TermidError, match="no parameter is free"):
        ship = termid.Model.default()
        ship.recipe([ship.simulate("zigzag:20/20")], ["central"], refine=None, parameters=True)


def test_recipe_refines_with_the_templates_free_parameters_by_default():
    """With ``refine``, the new-ship template's rudder zero (free, each run's own) is refined
    with the coefficients of every start by default; ``parameters=False`` refines the
    coefficients alone and keeps the file's zero."""
    truth = termid.Model.builtin("mmg_kvlcc2")
    runs = [truth.record(m, duration=60.0, seed=k) for k, m in enumerate(["zigzag:20/20", "zigzag:20/20:port", "zigzag:10/10"])]
    template = termid.Model.builtin("new_ship")
    found = template.recipe(runs, ["kalman"], refine=("u", "v", "r", "ψ"), refine_iterations=20)
    assert found.parameters is not None and "free parameters" in found.text, found.text
    assert list(found.starts["parameters"]) == ["kept"], found.starts
    plain = template.recipe(runs, ["kalman"], refine=("u", "v", "r", "ψ"), refine_iterations=20, parameters=False)
    assert plain.parameters is None and "output-error refinement" in plain.text
    assert plain.model.parameters["δ_0"] == 0.0


def test_print_shows_each_equation_with_its_coefficients():
    lorenz = termid.Model.builtin("lorenz")
    text = str(lorenz)
    assert text.splitlines()[0] == lorenz.name
    assert "  z_dot = 1 x*y - 2.66667 z" in text, text
    assert repr(lorenz).startswith("termid.Model(")


def test_monte_carlo_spread_and_its_refusal():
    """``Model.monte_carlo``: the metrics of drawn models, a row per draw, the model's own
    among them; where more than 5 % of the draws fail (a covariance widened a billion times)
    it raises saying so rather than return the draws that happened to stay stable."""
    ship = termid.Model.default()
    runs = [ship.record(m, seed=k) for k, m in enumerate(["zigzag:20/20", "zigzag:20/20:port", "zigzag:10/10"])]
    found = ship.identify(runs, "kalman").model
    spread = found.monte_carlo("zigzag:20/20", 30)
    assert len(spread) == 30 and spread.attrs["failed"] == 0 and spread.attrs["draws"] == 30
    overshoot = spread["first_overshoot_deg"]
    assert overshoot.quantile(0.05) <= spread.attrs["nominal"]["first_overshoot_deg"] <= overshoot.quantile(0.95)
    assert overshoot.std() > 0
    # the same seed, the same draws
    assert found.monte_carlo("zigzag:20/20", 5, seed=4).equals(found.monte_carlo("zigzag:20/20", 5, seed=4))
    wide = termid.Model.from_toml(re.sub(r"correlation_time = [0-9.e+]+", "correlation_time = 1e9", found.to_toml()))
    with pytest.raises(termid.TermidError, match="draws failed .* more than the 5 %"):
        wide.monte_carlo("turning:35", 20)
    with pytest.raises(termid.TermidError, match="no covariance"):
        termid.Model.default().draws(3)
    # more models than memory holds are refused before the first is drawn
    with pytest.raises(termid.TermidError, match="10000000 drawn models would take .* of memory"):
        found.draws(10_000_000)


def test_validate_with_monte_carlo_marks_what_falls_outside_the_band():
    """``validate(monte_carlo=n)``: each held-out run's metrics over drawn models, the
    measured value beside its 5-95 % range and whether it falls outside; a run whose heading
    and yaw rate are doubled (a ship turning twice as far) falls outside on every metric; a
    covariance widened a billion times is refused, as the command refuses it."""
    ship = termid.Model.default()
    runs = [ship.record(m, seed=k) for k, m in enumerate(["zigzag:20/20", "zigzag:20/20:port", "zigzag:10/10"])]
    found = ship.identify(runs, "kalman").model
    held = ship.record("zigzag:20/20", seed=7)
    gap = found.validate(held, monte_carlo=40)
    band = gap.attrs["band"]
    row = band.loc[("zigzag:20/20#7", "first_overshoot_deg")]
    assert row["p05"] <= row["mean"] <= row["p95"] and row["sd"] > 0, band
    measured = gap.attrs["metrics"].loc[("zigzag:20/20#7", "measured"), "first_overshoot_deg"]
    assert row["measured"] == measured and row["outside"] == (not row["p05"] <= measured <= row["p95"])
    within = gap.attrs["within_band"]
    assert within["within"] + len(within["outside"]) == within["metrics"] == band["outside"].notna().sum()
    doubled = held.assign(ψ=2 * held["ψ"], r=2 * held["r"])
    far = found.validate(doubled, monte_carlo=40).attrs["within_band"]
    assert far["within"] == 0 and far["metrics"] >= 2, far
    assert all(o.endswith("of zigzag:20/20#7") for o in far["outside"]), far
    wide = termid.Model.from_toml(re.sub(r"correlation_time = [0-9.e+]+", "correlation_time = 1e9", found.to_toml()))
    with pytest.raises(termid.TermidError, match="draws failed .* more than the 5 %"):
        wide.validate(held, monte_carlo=20)
    with pytest.raises(termid.TermidError, match="would take .* of memory"):
        found.validate(held, monte_carlo=10**10)


KVLCC2_PARTICULARS = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "kvlcc2_particulars.toml")


def test_a_new_ship_from_its_particulars():
    """``Model.from_particulars``: the grey-box model ``termid new-ship`` writes, from the
    particulars file or a dict of its keys alike; its estimates with their priors and sources
    (Kijima's Y'_v for KVLCC2, -0.4121 worked by hand from the paper's expression, and the
    fixed K_T coefficients without a prior); unusual proportions warned of; a value no ship has,
    a missing key and a missing file refused by name."""
    from_file = termid.Model.from_particulars(KVLCC2_PARTICULARS)
    ship = {
        "name": "KVLCC2", "lpp": 7.0, "beam": 1.27, "draught": 0.46, "block_coefficient": 0.81,
        "x_g": 0.25, "rudder_area": 0.0539, "rudder_span": 0.345, "propeller_diameter": 0.216,
        "u0": 1.17248, "rudder_rate": 15.8, "rudder_limit": 35.0, "density": 1025.0,
    }
    from_dict = termid.Model.from_particulars(ship)
    assert from_dict.to_toml() == from_file.to_toml()
    assert {"Y_v", "N_r", "ε", "κ", "γ_Rp", "δ_0"} <= set(from_dict.free_parameters), from_dict.free_parameters
    table = termid.Model.particulars_table(ship)
    assert abs(table.loc["Y_v", "value"] / -0.4121 - 1) < 0.005, table
    assert table.loc["Y_v", "prior_sd"] > 0 and table.loc["Y_v", "source"].startswith("Kijima"), table
    assert np.isnan(table.loc["k_0", "prior_sd"]), table
    assert list(table.columns) == ["value", "prior_sd", "unit", "source"]
    with pytest.warns(UserWarning, match="L/B = 10.000"):
        termid.Model.from_particulars({**ship, "beam": 0.7, "block_coefficient": 0.45})
    with pytest.raises(termid.TermidError, match="`lpp`"):
        termid.Model.from_particulars({**ship, "lpp": -7.0})
    with pytest.raises(termid.TermidError, match="missing field `beam`"):
        termid.Model.from_particulars({k: v for k, v in ship.items() if k != "beam"})
    with pytest.raises(FileNotFoundError):
        termid.Model.from_particulars("no_such_particulars.toml")


def test_monte_carlo_says_what_its_spread_comes_from():
    """``monte_carlo`` on a model with its free parameters' covariance: KVLCC2's MMG model with
    ε uncertain (sd 0.1) and γ_R+ all but known. ε moves the tactical diameter by half the
    difference of the model at ε ± 0.1, all its variance is ε's, and the linearised sd is that
    effect's size."""
    text = termid.Model.builtin("mmg_kvlcc2").to_toml()
    text += '\n[parameter_covariance]\nnames = ["ε", "γ_Rp"]\nmatrix = [[0.01, 0.0], [0.0, 1e-8]]\n'
    model = termid.Model.from_toml(text, "mmg.toml")
    spread = model.monte_carlo("turning:35", 20)

    def diameter(epsilon):
        shifted = termid.Model.from_toml(text, "mmg.toml")
        shifted.set_parameter("ε", epsilon)
        return shifted.simulate("turning:35").attrs["metrics"]["tactical_diameter_m"]

    effect = 0.5 * (diameter(1.09 + 0.1) - diameter(1.09 - 0.1))
    effects = spread.attrs["parameter_effects"]
    assert abs(effects.loc["ε", "tactical_diameter_m"] / effect - 1) < 1e-9, effects
    shares = spread.attrs["spread_from"].loc["tactical_diameter_m"]
    assert shares["ε"] > 0.999 and shares["γ_Rp"] < 0.001, shares
    # with γ_R+'s (sd 1e-4) too small to show beyond the sixth digit
    assert abs(spread.attrs["linearised_sd"]["tactical_diameter_m"] / abs(effect) - 1) < 1e-6
    # a model without the parameters' covariance: nothing to attribute, empty frames
    plain = termid.Model.default()
    found = plain.identify([plain.record("zigzag:20/20", seed=1), plain.record("zigzag:20/20:port", seed=2)], "kalman")
    assert found.model.monte_carlo("zigzag:20/20", 5).attrs["spread_from"].empty


def test_estimate_frees_and_holds_parameters_for_itself_alone():
    """``hold`` keeps a free parameter at the file's value for one estimate, ``free`` estimates
    a held one (a sea trial's current); the model returned keeps the file's word on each."""
    truth = termid.Model.builtin("nomoto")
    truth.set_parameter("K", 0.15)
    truth.set_parameter("T", 8.0)
    run = truth.simulate(duration=80.0, inputs={"δ": 0.1}, sample=0.1)[["t", "ψ", "r", "δ"]]
    start = termid.Model.builtin("nomoto")
    start.set_parameter("T", 8.0)
    table, found = start.estimate(run, hold=["T"])
    assert list(table.index) == ["K"] and abs(table.loc["K", "estimate"] - 0.15) < 1e-3, table
    assert found.parameters["T"] == 8.0 and found.free_parameters == ["K", "T"]
    with pytest.raises(termid.TermidError, match="both to be freed and held"):
        start.estimate(run, free=["K"], hold=["K"])
    with pytest.raises(termid.TermidError, match="no parameter `c_N`"):
        start.estimate(run, free=["c_N"])


DRIFTER = """
[model]
name = "drifter"
[[states]]
name = "x"
[[states]]
name = "w"
[[inputs]]
name = "v"
[parameters."τ"]
value = 2.0
free = true
[parameters.c]
value = 0.0
unit = "m/s"
nuisance = "source"
medium = true
[equations.x_dot]
state = "x"
identify = false
coefficients = { "w" = 1.0, "c" = 1.0 }
[equations.w_dot]
state = "w"
identify = false
coefficients = { "v/τ" = 1.0, "w/τ" = -1.0 }
"""


def test_runs_tracked_over_ground_get_the_days_current():
    """A body whose track a stream of 0.4 m/s carries (``c``, ``medium = true``, held at 0):
    ``over_ground=True`` estimates the stream alone before validating, and with the body's
    τ in ``estimate``; the model returned stays in still water."""
    truth = termid.Model.from_toml(DRIFTER.replace("value = 2.0", "value = 3.0"), "truth.toml")
    truth.set_parameter("c", 0.4)
    runs = [truth.simulate(duration=20.0, inputs={"v": v}, sample=0.1)[["t", "x", "w", "v"]] for v in (1.0, -0.5)]
    start = termid.Model.from_toml(DRIFTER, "drifter.toml")
    start.set_parameter("τ", 3.0)
    still = start.validate(runs)
    carried = start.validate(runs, over_ground=True)
    assert list(carried.attrs["medium"]["name"]) == ["c"] and still.attrs["medium"].empty
    assert abs(carried.attrs["medium"]["value"][0] - 0.4) < 1e-6, carried.attrs["medium"]
    assert carried["rms"].max() < 1e-6 < 0.1 < still["rms"].max(), (carried, still)
    start.set_parameter("τ", 2.0)
    table, found = start.estimate(runs, over_ground=True)
    assert abs(table.loc["τ", "estimate"] - 3.0) < 1e-4, table
    current = table.attrs["per_source"]
    assert abs(current.loc[current["name"] == "c", "value"].iloc[0] - 0.4) < 1e-4, current
    assert found.parameters["c"] == 0.0 and found.free_parameters == ["τ"]
    # diagnosed in the day's stream: nothing left to explain
    gaps, _ = found.diagnose(runs, over_ground=True)
    own = gaps.attrs["own_values"]
    assert abs(own.loc[own["name"] == "c", "value"].iloc[0] - 0.4) < 1e-4, own
    assert gaps["rms_before"].max() < 1e-3, gaps


def test_simulate_under_inputs_that_change_in_time():
    # Nomoto's T·ṙ + r = K·δ under δ = a·sin(ωt) from rest, in closed form:
    # r = K·a·(sin ωt − ωT·cos ωt + ωT·e^(−t/T)) / (1 + ω²T²)
    nomoto = termid.Model.builtin("nomoto")
    k, big_t = nomoto.parameters["K"], nomoto.parameters["T"]
    a, w = 0.2, 0.3
    t = np.arange(0.0, 60.0, 0.05)
    rudder = pd.DataFrame({"δ": a * np.sin(w * t)}, index=pd.Index(t, name="t"))
    run = nomoto.simulate(inputs=rudder)
    exact = k * a * (np.sin(w * t) - w * big_t * np.cos(w * t) + w * big_t * np.exp(-t / big_t)) / (1 + (w * big_t) ** 2)
    assert len(run) == len(t) and np.abs(run["r"].to_numpy() - exact).max() < 1e-6
    # from other initial states, for the first seconds of the record; a dict of arrays too
    again = nomoto.simulate(inputs={"t": t, "δ": rudder["δ"].to_numpy()}, initial={"ψ": 1.0}, duration=10.0)
    assert again["t"].iloc[-1] == pytest.approx(10.0) and again["ψ"].iloc[0] == 1.0
    # what does not fit is refused by name
    with pytest.raises(termid.TermidError, match="need their time"):
        nomoto.simulate(inputs=rudder.reset_index(drop=True))
    with pytest.raises(termid.TermidError, match="`rpm`: not an input of the model"):
        nomoto.simulate(inputs=rudder.assign(rpm=1.0))


def test_a_system_from_its_columns():
    # Duffing's ẍ + 2ζω ẋ + ω² x + α x³ = F with ζ = 0.05, ω = 1, α = 0.2 (the shipped
    # model file's truth), driven by a force that changes in time, identified whole from its
    # columns: every monomial of x, v and F to degree 3
    duffing = termid.Model.builtin("duffing")
    t = np.arange(0.0, 60.0, 0.01)
    force = pd.DataFrame({"t": t, "F": 0.8 * np.sin(0.7 * t) + 0.5 * np.sin(1.9 * t + 1.0)})
    run = duffing.simulate(inputs=force, initial={"x": 1.0, "v": 0.5})
    model = termid.Model.from_states(["x", "v"], ["F"], degree=3)
    assert model.equations == ["x_dot", "v_dot"] and len(model.coefficients("v_dot")) == 0
    found = model.identify(run[["t", "x", "v", "F"]])
    v_dot = found.model.coefficients("v_dot").set_index("term")["value"]
    assert sorted(v_dot.index) == ["F", "v", "x", "x^3"]
    for term, truth in {"F": 1.0, "v": -0.1, "x": -1.0, "x^3": -0.2}.items():
        assert v_dot[term] == pytest.approx(truth, rel=1e-3)
    x_dot = found.model.coefficients("x_dot").set_index("term")["value"]
    assert list(x_dot.index) == ["v"] and x_dot["v"] == pytest.approx(1.0, rel=1e-4)
    # it starts where the run starts, and survives a pickle as a model made from states
    again = found.model.simulate(inputs=force, duration=5.0)
    assert again["x"].iloc[0] == 1.0 and np.abs(again["x"].to_numpy() - run["x"].to_numpy()[: len(again)]).max() < 1e-3
    assert pickle.loads(pickle.dumps(found.model))._from_states
    # the whole recipe too, by any system's defaults (the weak form, neither smoothed nor
    # refined), its checks those of any system (that the equations retrace the run)
    recipe = model.recipe(run[["t", "x", "v", "F"]])
    assert list(recipe.starts["derivative"]) == ["weak"] and recipe.warnings == []
    assert recipe.model.simulate(inputs=force, duration=1.0)["x"].iloc[0] == 1.0
    assert "ok   the equations retrace their runs without running away" in recipe.text
    v_dot = recipe.model.coefficients("v_dot").set_index("term")["value"]
    assert v_dot["x"] == pytest.approx(-1.0, rel=1e-3) and v_dot["F"] == pytest.approx(1.0, rel=1e-3)
    # a ship's starts and states are refused or warned about by name, not run as failures
    with pytest.raises(termid.TermidError, match="refine: `u` is neither a state"):
        model.recipe(run[["t", "x", "v", "F"]], refine=["u", "v"])
    with pytest.warns(UserWarning, match="the start from derivative `kinematic` fails") as said:
        both = model.recipe(run[["t", "x", "v", "F"]], ["kinematic", "integral"], refine="all", refine_iterations=3)
    assert list(both.starts["derivative"]) == ["integral"] and both.failed[0][0] == "kinematic"
    assert {w.filename for w in said} == {__file__}
    # what cannot be a system is refused by name
    with pytest.raises(termid.TermidError, match="`F` is named twice"):
        termid.Model.from_states(["x", "F"], ["F"])
    with pytest.raises(termid.TermidError, match="candidate `x\\*G`"):
        termid.Model.from_states(["x"], terms=["x", "x*G"])
    with pytest.raises(TypeError):
        termid.Model.from_states("xv")
    with pytest.raises(termid.TermidError, match="the candidates are named"):
        termid.Model.from_states(["x"], terms=["x"], degree=2)
    for degree in (-1, 2.5, True):
        with pytest.raises(termid.TermidError, match="is no degree: give a whole number"):
            termid.Model.from_states(["x"], degree=degree)


_THERMAL = """[model]
name = "a heated body"
intercept = false
[[states]]
name = "T"
initial = 301.0
[[inputs]]
name = "P"
[parameters.Ta]
value = 300.0
[[derived]]
name = "rise"
definition = "T - Ta"
[equations.T_dot]
state = "T"
coefficients = { "rise" = -0.5, "P" = 2.0 }
"""


def test_a_system_far_from_zero_is_identified_about_a_reference_value():
    # a temperature in kelvin read to 0.01 K: T, T^2 and 1 are collinear about 300 K, and the
    # library of a model made from columns is written about a round reference value instead
    # (T0 = 300, ΔT = T - T0, as the paper's Δu), also after a pickle
    t = np.arange(0.0, 60.0, 0.02)
    power = pd.DataFrame({"t": t, "P": np.sin(0.7 * t) + 0.6 * np.sin(1.9 * t + 0.5)})
    run = termid.Model.from_toml(_THERMAL).simulate(inputs=power)[["t", "T"]]
    run["T"] += 0.01 * np.random.default_rng(5).standard_normal(len(run))
    run["P"] = power["P"].to_numpy()[: len(run)]
    model = pickle.loads(pickle.dumps(termid.Model.from_states(["T"], ["P"], degree=2)))
    found = model.identify(run)
    assert "written about reference values" in " ".join(found.notes("T_dot"))
    coefficients = found.model.coefficients("T_dot").set_index("term")["value"]
    assert sorted(coefficients.index) == ["P", "ΔT"]
    assert coefficients["ΔT"] == pytest.approx(-0.5, rel=2e-3) and coefficients["P"] == pytest.approx(2.0, rel=2e-3)
    assert found.model.parameters == {"T0": 300.0}
    recipe = model.recipe(run)
    assert sorted(recipe.model.coefficients("T_dot")["term"]) == ["P", "ΔT"]
    # statistics gathered in parts keep the library as written: decided once, on a sample
    with pytest.warns(UserWarning, match="ΔT = T - T0, T0 = 300"):
        about = model.about_references(run.iloc[:500])
    assert about.candidates("T_dot")[:3] == ["1", "ΔT", "P"]
    parts = [about.moments("T_dot", run.iloc[k : k + 1500]) for k in (0, 1500)]
    merged = about.identify_from_moments(parts).model.coefficients("T_dot").set_index("term")["value"]
    assert sorted(merged.index) == ["P", "ΔT"] and merged["ΔT"] == pytest.approx(-0.5, rel=5e-3)
    assert model.moments("T_dot", run).candidates[:3] == ["1", "T", "P"]


_LOTKA_VOLTERRA = """[model]
name = "Lotka-Volterra"
intercept = false
[simulation]
rtol = 1e-10
atol = 1e-10
[[states]]
name = "x"
initial = 4.0
[[states]]
name = "z"
initial = 1.0
[equations.x_dot]
state = "x"
coefficients = { "x" = 1.0, "x*z" = -0.5 }
[equations.z_dot]
state = "z"
coefficients = { "z" = -1.5, "x*z" = 0.25 }
"""


def test_equations_that_run_away_from_a_coarse_run_are_chosen_again():
    # Lotka-Volterra sampled ten times a period, noise-free: the cubic library's rates fit the
    # rows with spurious terms that cancel on the samples, and the system they make runs away
    # from the run's start within 5 s; their terms are chosen again by re-simulation (the
    # truth's, said); sampled five times faster, the truth comes back from the regression itself
    truth = termid.Model.from_toml(_LOTKA_VOLTERRA)
    coarse = truth.simulate(duration=19.5, sample=0.5)[["t", "x", "z"]]
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        found = termid.Model.from_states(["x", "z"]).identify(coarse)
    assert not any("FAIL" in str(w.message) for w in said)
    assert sorted(found.model.coefficients("x_dot")["term"]) == ["x", "x*z"]
    assert sorted(found.model.coefficients("z_dot")["term"]) == ["x*z", "z"]
    assert any(n.startswith("terms chosen by re-simulation: the regression's (9 of `x_dot`, 9 of `z_dot`)") for n in found.notes("x_dot"))
    # its 40 rows too few to halve, said at the user's line, not at the package's
    halves = [w for w in said if "FLAG the terms hold on each half of the runs: not checked: the runs' " in str(w.message)]
    assert halves and {w.filename for w in halves} == {__file__}
    fine = truth.simulate(duration=19.9, sample=0.1)[["t", "x", "z"]]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = termid.Model.from_states(["x", "z"]).identify(fine)
    x_dot = found.model.coefficients("x_dot").set_index("term")["value"]
    assert x_dot.to_dict() == pytest.approx({"x": 1.0, "x*z": -0.5}, rel=1e-3)
    # the check is kept with the fit, and asked of the model again with any runs
    assert list(found.checks["passed"]) == [True] * 6 and found.checks["detail"][0].endswith("throughout")
    # followed as long as its own motion from a nudged start follows itself, and within the
    # records' noise
    assert found.checks["name"][1] == "the equations follow their runs as long as their own motion allows"
    assert found.checks["name"][2] == "the equations re-simulate their runs within the records' noise"
    assert found.checks["name"][3] == "the terms hold on each half of the runs"
    # noise-free: the records' noise is bounded far below the 2 % that biases the terms
    assert found.checks["name"][4] == "the records' noise leaves the terms unbiased"
    # the run's halves, each identified alone with the terms, give them alike
    assert found.checks["name"][5] == "the runs tell one system"
    again = found.model.checks(coarse)
    assert list(again["passed"])[:3] == [True, True, True]
    # ten samples a cycle: the motion shows through the fourth differences, whose bound is
    # over 2 %: the noise is not told (it passed as "under 2.0 %")
    assert not again["passed"][3] and again["detail"][3].startswith("not told: white noise of `x` at most")


def test_a_run_without_its_model_s_time_column():
    # a model's runs take their time from a time index or from their one column of date-times
    # (said), as `fit` does; a column that only looks like time is named in the refusal
    lorenz = termid.Model.builtin("lorenz")
    run = lorenz.simulate(duration=5.0, dt=0.01)[["t", "x", "y", "z"]]
    model = termid.Model.from_states(["x", "y", "z"])
    stamped = run.assign(stamp=pd.Timestamp("2024-03-01 12:00") + pd.to_timedelta(run["t"], unit="s")).drop(columns="t")
    with pytest.warns(UserWarning, match="run1: the rows' time `t` is column `stamp`"):
        found = model.identify(stamped)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # the one column whose name says it is the time is taken for it, said (a dataframe's
    # `time` was refused, to be renamed); one in milliseconds is read in seconds
    with pytest.warns(UserWarning, match="run1: the rows' time `t` is column `time`, the one whose name says so"):
        found = model.identify(run.rename(columns={"t": "time"}))
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    in_ms = run.assign(t=run["t"] * 1000.0).rename(columns={"t": "Time (ms)"})
    with pytest.warns(UserWarning, match=r"`Time \(ms\)` as t in SI \(× 1.000000e-3\)"):
        found = model.identify(in_ms)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # beside another such column, neither is taken: the refusal names the first
    with pytest.raises(termid.TermidError, match=r"name it `t`, in seconds: df.assign\(t=df\['Time \(ms\)'\] \* 0.001\)"):
        model.identify(in_ms.assign(seconds=run["t"]))


def test_a_time_column_in_milliseconds_is_read_in_seconds():
    # `fit` with time='Time (ms)' (as a logger heads it): the header's unit read, the rates per
    # second, not per millisecond (it was: every rate's coefficient a thousand times too small)
    lorenz = termid.Model.builtin("lorenz")
    run = lorenz.simulate(duration=5.0, dt=0.01)[["t", "x", "y", "z"]]
    in_ms = run.assign(t=run["t"] * 1000.0).rename(columns={"t": "Time (ms)"})
    fitted = termid.fit(in_ms, "dz/dt", ["x*y", "z", "x", "y"], time="Time (ms)")
    assert fitted.coefficients.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # so is an index of milliseconds under that name, for a fit and for a model's runs
    indexed = in_ms.set_index("Time (ms)")
    fitted = termid.fit(indexed, "dz/dt", ["x*y", "z", "x", "y"])
    assert fitted.coefficients.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    found = termid.Model.from_states(["x", "y", "z"]).identify(indexed)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # a model whose time is so named simulates in its unit (it gave seconds under the header
    # of milliseconds, read back a thousand times too fast), is given its times in it, and
    # identifies from what it gives
    in_ms_model = termid.Model.from_toml(lorenz.to_toml().replace('time = "t"', 'time = "Time (ms)"', 1))
    simulated = in_ms_model.simulate(duration=5000.0, dt=10.0)
    assert list(simulated["Time (ms)"][:3]) == pytest.approx([0.0, 10.0, 20.0])
    again = in_ms_model.identify(simulated[["Time (ms)", "x", "y", "z"]])
    z_dot = again.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # a logger's unit after the name, an index of epoch milliseconds: read in seconds too
    logged = in_ms.rename(columns={"Time (ms)": "timestamp_ms"})
    logged = logged.assign(timestamp_ms=logged["timestamp_ms"] + 1.7e12).set_index("timestamp_ms")
    found = termid.Model.from_states(["x", "y", "z"]).identify(logged)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)


def test_columns_whose_names_carry_their_unit_are_read_by_their_bare_names_in_si():
    # `pd.read_csv` of a logger's file names its columns `x [m]`: read as x, in SI, warned (a
    # Model of x, y, z found no column `x`), as the command line reads the file itself
    lorenz = termid.Model.builtin("lorenz")
    run = lorenz.simulate(duration=5.0, dt=0.01)[["t", "x", "y", "z"]]
    headed = run.assign(z=run["z"] * 3.6).rename(columns={"x": "x [m]", "y": "y [m]", "z": "z [km/h]"})
    with pytest.warns(UserWarning, match=r"read by their bare names: `x \[m\]` as x, .*`z \[km/h\]` as z in SI") as said:
        found = termid.Model.from_states(["x", "y", "z"]).identify(headed)
    assert {w.filename for w in said} == {__file__}
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    with pytest.warns(UserWarning, match="read by their bare names"):
        fitted = termid.fit(headed, "dz/dt", ["x*y", "z", "x", "y"])
    assert fitted.coefficients.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    # a unit termid does not convert (a bench logger's `[rpm]`, a lab's `[mg/L]`) is read as
    # written and said (it was refused: no column `x`); SI's own (`[A]`) as it is
    other = run.rename(columns={"x": "x [A]", "y": "y [rpm]", "z": "z [mg/L]"})
    with pytest.warns(UserWarning, match=r"`x \[A\]` as x, `y \[rpm\]` as y in rpm as written \(a unit termid does not convert\)"):
        found = termid.Model.from_states(["x", "y", "z"]).identify(other)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)


def test_terms_the_halves_of_a_run_do_not_choose_are_flagged():
    # Lorenz with 5 % noise on its states: the regression keeps terms the system lacks (errors
    # in the states bias the regressors) at t-values of 3.5 to 6; identified again from each
    # half of the run they do not come back, and both identify and the recipe say so
    lorenz = termid.Model.builtin("lorenz")
    run = lorenz.simulate(duration=20.0, dt=0.01)[["t", "x", "y", "z"]]
    rng = np.random.default_rng(3)
    for c in "xyz":
        run[c] = run[c] + 0.05 * run[c].std() * rng.standard_normal(len(run))
    model = termid.Model.from_states(["x", "y", "z"])
    with pytest.warns(UserWarning, match=r"FLAG the terms hold on each half of the runs: .*`x_dot`: ") as said:
        found = model.identify(run)
    assert {w.filename for w in said} == {__file__}
    halves = found.checks.set_index("name").loc["the terms hold on each half of the runs"]
    assert not halves["passed"] and not halves["refuses"]
    # the system's own terms of x_dot are held, the others named
    x_dot = set(found.model.coefficients("x_dot")["term"])
    assert {"x", "y"} <= x_dot and len(x_dot) > 2
    named = halves["detail"].split("`x_dot`: ")[1].split(";")[0]
    # with noise measured, noise is the first cause named
    assert "; terms the noise chose" in halves["detail"] and "next to no noise" not in halves["detail"]
    assert all(f"`{t}`" in named for t in x_dot - {"x", "y"}) and "`x`" not in named.replace("`x*", "")
    with pytest.warns(UserWarning, match="FLAG the terms hold on each half"):
        recipe = model.recipe(run)
    assert any(w.startswith("FLAG the terms hold") for w in recipe.warnings)
    # and the noise that made them is measured and said: 5 % of each state's spread, over 2 %
    noise = found.checks.set_index("name").loc["the records' noise leaves the terms unbiased"]
    assert not noise["passed"] and not noise["refuses"]
    shares = [float(noise["detail"].split(f"`{c}` ")[1].split(" %")[0]) for c in "xyz"]
    assert all(4.5 < s < 5.5 for s in shares), noise["detail"]
    assert any(w.startswith("FLAG the records' noise") for w in recipe.warnings)


def test_terms_left_out_of_every_rate_write_a_blurred_law_in_the_rest():
    # an epidemic, S + I + R = 1, recorded with 1 % noise on each: the fit says the law holds
    # but for the noise; leaving out the candidates in R writes dI/dt = 0.5·I·S − 0.1·I
    beta, gamma, h = 0.5, 0.1, 0.1
    rate = lambda x: np.array([-beta * x[0] * x[1], beta * x[0] * x[1] - gamma * x[1], gamma * x[1]])
    x, rows = np.array([0.99, 0.01, 0.0]), []
    for _ in range(1000):
        rows.append(x)
        for _ in range(10):
            k1 = rate(x); k2 = rate(x + 0.005 * k1); k3 = rate(x + 0.005 * k2); k4 = rate(x + 0.01 * k3)
            x = x + 0.01 / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    rows = np.array(rows)
    noisy = rows + 0.01 * rows.std(axis=0) * np.random.default_rng(3).normal(size=rows.shape)
    run = pd.DataFrame({"t": h * np.arange(1000), "S": noisy[:, 0], "I": noisy[:, 1], "R": noisy[:, 2]})
    model = termid.Model.from_states(["S", "I", "R"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = model.identify(run)
    said = " ".join(found.reports["I_dot"]["notes"])
    assert "the same in every row but for the records' noise" in said and "the candidates in `R` left out" in said
    in_r = [t for t in model.candidates("I_dot") if "R" in t]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        written = model.with_terms(excluded=in_r).identify(run)
    i_dot = written.model.coefficients("I_dot").set_index("term")["value"]
    assert sorted(i_dot.index) == ["I", "I*S"]
    assert i_dot["I*S"] == pytest.approx(beta, rel=0.01) and i_dot["I"] == pytest.approx(-gamma, rel=0.01)
    with pytest.raises(termid.TermidError, match="`I\\^3\\*R` is no candidate of an equation identified"):
        model.with_terms(excluded=["I^3*R"])
    with pytest.raises(TypeError):
        model.with_terms(excluded="R")


def test_a_time_column_whose_name_carries_its_unit_is_the_time():
    # `t [ms]` where the model's time is `t` (as pd.read_csv names a logger's column): read as
    # t in seconds and said, for a model's runs and for fit (it was refused, naming the column)
    truth = termid.Model.builtin("lorenz").simulate(duration=5.0, sample=0.01)
    headed = truth[["t", "x", "y", "z"]].assign(t=truth["t"] * 1e3).rename(columns={"t": "t [ms]"})
    with pytest.warns(UserWarning, match=r"`t \[ms\]` as t in SI \(× 1.000000e-3\)"):
        found = termid.Model.from_states(["x", "y", "z"]).identify(headed)
    z_dot = found.model.coefficients("z_dot").set_index("term")["value"]
    assert z_dot.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)
    with pytest.warns(UserWarning, match=r"`t \[ms\]` as t"):
        fitted = termid.fit(headed, "dz/dt", ["x*y", "z", "x", "y"])
    assert fitted.coefficients.to_dict() == pytest.approx({"x*y": 1.0, "z": -8.0 / 3.0}, rel=1e-3)


def test_rows_newest_first_are_said_to_be():
    # a database export sorted descending: time decreases at every row; it was refused as a
    # time that "starts again" at row 2, with the remedy for runs one after another
    truth = termid.Model.builtin("lorenz").simulate(duration=2.0, sample=0.01)[["t", "x", "y", "z"]]
    with pytest.raises(termid.TermidError, match=r"time decreases at every row, from 2 to 0: the rows are newest first") as e:
        termid.Model.from_states(["x", "y", "z"]).identify(truth.iloc[::-1])
    assert "starts again" not in str(e.value)


def test_an_identification_prints_its_equations_and_checks():
    # print(found), and a notebook's display (IPython's _repr_pretty_), show the equations and
    # each check as the command line writes it; repr stays one line
    truth = termid.Model.builtin("lorenz").simulate(duration=5.0, sample=0.01)[["t", "x", "y", "z"]]
    found = termid.Model.from_states(["x", "y", "z"]).identify(truth)
    text = str(found)
    assert text.splitlines()[1].startswith("  x_dot = ") and "\nchecks:\n  ok   the equations retrace" in text
    assert text.count("\n  ok   ") == len(found.checks) and "\n" not in repr(found)

    class Printer:
        said = ""

        def text(self, t):
            Printer.said += t

    found._repr_pretty_(Printer(), False)
    assert Printer.said == text


def test_a_bouncing_ball_is_identified_between_its_bounces_and_printed_as_such():
    # a ball dropped from 2 m bouncing back at 0.8 of its speed: its speed leaps at each
    # bounce, moving between them as much; the run is cut there (warned once) and the flights
    # hold h' = v, v' = -9.81, which print shows as "v_dot = -9.81" (it read "-9.81 1")
    g, v1 = 9.81, math.sqrt(2 * 9.81 * 2.0)
    bounces = [(v1 / g, 0.8 * v1)]
    while bounces[-1][0] < 5.0:
        t, v = bounces[-1]
        bounces.append((t + 2 * v / g, 0.8 * v))
    t = np.arange(501) * 0.01
    h, v = np.empty_like(t), np.empty_like(t)
    for k, tk in enumerate(t):
        past = [b for b in bounces if b[0] <= tk]
        if past:
            tb, vb = past[-1]
            h[k], v[k] = vb * (tk - tb) - 0.5 * g * (tk - tb) ** 2, vb - g * (tk - tb)
        else:
            h[k], v[k] = 2.0 - 0.5 * g * tk**2, -g * tk
    with pytest.warns(UserWarning, match=r"`v` leaps at 9 rows and stays .* a motion reset at each"):
        found = termid.Model.from_states(["h", "v"]).identify(pd.DataFrame({"t": t, "h": h, "v": v}))
    assert found.model.coefficients("v_dot")["term"].tolist() == ["1"]
    assert "\n  v_dot = -9.81\n" in str(found) and bool(found.checks["passed"].all())


def test_a_time_named_by_its_unit_is_read_in_seconds_and_said():
    # an epidemic's day count: the command line reads `day` in seconds; Python did too,
    # silently (the native reading), where it now warns as the command line notes it
    day = np.arange(61.0)
    run = pd.DataFrame({"day": day, "x": 100.0 * np.exp(-0.1 * day)})
    with pytest.warns(UserWarning, match=r"the time `day` read in seconds \(× 8\.640000e4\): every rate is per second"):
        found = termid.Model.from_states(["x"], time="day").identify(run)
    x = found.model.coefficients("x_dot").set_index("term")["value"]
    assert x["x"] * 86400.0 == pytest.approx(-0.1, rel=1e-3)


def test_a_model_counted_in_days_is_simulated_for_days():
    # `duration=60` of a model whose time is `day` ran 60 seconds, its `day` column ending at
    # 6.9e-4; the run's times are the model's unit's, and so are the times given for it
    day = np.arange(61.0)
    run = pd.DataFrame({"day": day, "x": 100.0 * np.exp(-0.1 * day)})
    with pytest.warns(UserWarning):
        model = termid.Model.from_states(["x"], time="day").identify(run).model
    sim = model.simulate(duration=60.0, sample=1.0)
    assert sim["day"].iloc[-1] == pytest.approx(60.0)
    assert sim["x"].iloc[-1] == pytest.approx(100.0 * np.exp(-6.0), rel=1e-4)
    # a record of it re-simulated at its own daily step, not 0.04 s (two million a day)
    with pytest.warns(UserWarning):
        again = model.replay(run)[0]
    assert again["x"].iloc[-1] == pytest.approx(run["x"].iloc[-1], rel=1e-3)


def test_a_column_whose_name_is_no_name_is_refused_with_its_pandas_remedy():
    # `tank level` was refused with a dataset file's mapping as the remedy; a dataframe's is
    # a rename, named with the name to call it, which then identifies
    t = np.arange(0.0, 20.0, 0.1)
    run = pd.DataFrame({"t": t, "tank level": np.exp(-0.3 * t)})
    with pytest.raises(termid.TermidError, match=r"df.rename\(columns=\{'tank level': 'tank_level'\}\), and call it `tank_level`"):
        termid.Model.from_states(["tank level"])
    found = termid.Model.from_states(["tank_level"]).identify(run.rename(columns={"tank level": "tank_level"}))
    level = found.model.coefficients("tank_level_dot").set_index("term")["value"]
    assert level.to_dict() == pytest.approx({"tank_level": -0.3}, rel=1e-4)


def test_a_law_a_cubic_stands_in_for_is_diagnosed_and_identified_again():
    # a tank draining through an orifice, dh/dt = -0.1*sqrt(h) in closed form: identify
    # tries the laws where the cubic library's powers stand alone, and finds it; kept to the
    # polynomials (laws=False), the cubic library follows it with every check ok; diagnose
    # names the law, and the model it returns, identified again, keeps it
    t = np.arange(0.0, 35.0, 0.1)
    run = pd.DataFrame({"t": t, "h": (2.0 - 0.05 * t) ** 2})
    law = termid.Model.from_states(["h"]).identify(run).model.coefficients("h_dot").set_index("term")["value"]
    assert law.to_dict() == pytest.approx({"sqrt(abs(h))": -0.1}, rel=1e-4)
    found = termid.Model.from_states(["h"]).identify(run, laws=False)
    gaps, repaired = found.model.diagnose(run)
    assert gaps.attrs["effect"]["name"] == "`sqrt(abs(h))` in h_dot, beyond the candidates"
    assert gaps.attrs["effect"]["coefficients"][0] == pytest.approx(-0.1, rel=1e-3)
    assert 0.0 <= gaps.attrs["noise"] < 0.05
    again = repaired.identify(run).model.coefficients("h_dot").set_index("term")["value"]
    assert again.to_dict() == pytest.approx({"sqrt(abs(h))": -0.1}, rel=1e-4)


def test_iso_stamps_read_as_text_are_the_rows_time():
    # `pd.read_csv` leaves a logger's ISO stamps as text: the run was "no time column `t`
    # (columns: x)", the stamps left out unsaid; the command line reads them, and so does this
    hours = pd.date_range("2024-01-01", periods=200, freq="h")
    text = pd.DataFrame({"time": hours.strftime("%Y-%m-%dT%H:%M:%S"), "x": 100.0 * np.exp(-0.05 * np.arange(200))})
    with pytest.warns(UserWarning, match="holds date-times; read as seconds since its first value"):
        found = termid.Model.from_states(["x"]).identify(text)
    x = found.model.coefficients("x_dot").set_index("term")["value"]
    assert x["x"] * 3600.0 == pytest.approx(-0.05, rel=1e-4)
    # text that is no date is left out as before (a run's label, a year as text)
    labelled = text.assign(run="a", year="2024")
    again = termid.Model.from_states(["x"]).identify(labelled).model.coefficients("x_dot").set_index("term")["value"]
    assert again.to_dict() == pytest.approx(x.to_dict())


def test_a_dose_in_a_state_nobody_measures_and_rates_declared_per_hour():
    # an oral dose: the gut's amount A starts at each subject's dose (`per_run`), only the
    # plasma's C is measured, on a schedule in hours; ka = 1.2 /h and ke = 0.15 /h come back
    # from C alone. The same file with its rates declared `1/h` is told they are read per
    # second, with the value to write.
    ka, ke = 1.2, 0.15
    hours = np.array([0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0])
    runs = [
        pd.DataFrame({
            "t [h]": hours,
            "C": dose * ka / (ka - ke) * (np.exp(-ke * hours) - np.exp(-ka * hours)),
            "dose": dose,
        })
        for dose in (100.0, 200.0, 400.0)
    ]
    text = """
[model]
name = "one compartment, oral"

[[states]]
name = "A"
per_run = "first:dose"

[[states]]
name = "C"

[[inputs]]
name = "dose"

[parameters.ka]
value = {ka}
unit = "{unit}"
free = true
bounds = [0.0, 100.0]

[parameters.ke]
value = {ke}
unit = "{unit}"
free = true
bounds = [0.0, 100.0]

[equations.A_dot]
state = "A"
identify = false
coefficients = {{ "ka*A" = -1.0 }}

[equations.C_dot]
state = "C"
identify = false
coefficients = {{ "ka*A" = 1.0, "ke*C" = -1.0 }}
"""
    with pytest.warns(UserWarning, match=r"parameter `ka` is declared in `1/h`.*write `value = 1.38889e-4`"):
        termid.Model.from_toml(text.format(ka=0.5, ke=0.06, unit="1/h"))
    model = termid.Model.from_toml(text.format(ka=0.5 / 3600, ke=0.06 / 3600, unit="1/s"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table, _ = model.estimate(runs, states=["C"])
    per_hour = table["estimate"] * 3600.0
    assert per_hour.to_dict() == pytest.approx({"ka": ka, "ke": ke}, rel=0.01)


def test_a_law_the_polynomials_stand_in_for_is_found_by_the_recipe():
    # a pendulum swung to 2.8 rad: the cubic library stands in for its sine (a false top near
    # 2.84 rad, the run lost within half a second); the recipe identifies it again with each
    # state's laws among the candidates and keeps sin θ, said; laws=False keeps the cubic, flagged
    dt, n = 0.01, 3001
    rate = lambda s: np.array([s[1], -9.81 * np.sin(s[0]) - 0.1 * s[1]])
    rows = [np.array([2.8, 0.0])]
    for _ in range(n - 1):
        s = rows[-1]
        for _ in range(10):
            h = dt / 10
            k1 = rate(s); k2 = rate(s + 0.5 * h * k1); k3 = rate(s + 0.5 * h * k2); k4 = rate(s + h * k3)
            s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        rows.append(s)
    rows = np.array(rows)
    run = pd.DataFrame({"t": np.arange(n) * dt, "theta": rows[:, 0], "omega": rows[:, 1]})
    model = termid.Model.from_states(["theta", "omega"], [])
    found = model.recipe(run)
    omega = found.model.coefficients("omega_dot").set_index("term")["value"]
    assert sorted(omega.index) == ["omega", "sin(theta)"]
    assert omega["sin(theta)"] == pytest.approx(-9.81, rel=1e-4) and omega["omega"] == pytest.approx(-0.1, rel=1e-3)
    assert "kept, the polynomials having stood in for a law" in found.text and "FLAG" not in found.text
    with pytest.warns(UserWarning, match="FLAG the equations follow their runs"):
        cubic = model.recipe(run, laws=False)
    assert "sin(theta)" not in cubic.model.coefficients("omega_dot")["term"].tolist()
    assert "FLAG the equations follow their runs" in cubic.text


def test_a_rate_that_saturates_is_found_with_its_constant_by_the_recipe():
    # an enzyme's turnover under a stepped feed, x' = u - 2x/(0.5 + x), noise-free: the cubic
    # library stands in, flagged, the four laws no better; x is positive in every row, so its
    # saturating forms are tried with K scanned, and x/(x + 0.5) is found, every check ok
    dt, n = 0.05, 4001
    feed = lambda t: [0.6, 1.2, 0.3, 1.5, 0.9, 0.45, 1.3, 0.7][int(t // 25.0) % 8]
    x, t, rows = 0.3, 0.0, []
    for k in range(n):
        rows.append(x)
        for _ in range(20):
            h = dt / 20
            rate = lambda x, t: feed(t) - 2.0 * x / (0.5 + x)
            k1 = rate(x, t); k2 = rate(x + 0.5 * h * k1, t + 0.5 * h)
            k3 = rate(x + 0.5 * h * k2, t + 0.5 * h); k4 = rate(x + h * k3, t + h)
            x, t = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h
    times = np.arange(n) * dt
    run = pd.DataFrame({"t": times, "x": rows, "u": [feed(t) for t in times]})
    model = termid.Model.from_states(["x"], ["u"])
    found = model.recipe(run)
    rate = found.model.coefficients("x_dot").set_index("term")["value"]
    assert sorted(rate.index) == ["u", "x/(x + 0.5)"], rate
    assert rate["x/(x + 0.5)"] == pytest.approx(-2.0, rel=1e-3) and rate["u"] == pytest.approx(1.0, rel=1e-3)
    assert "saturating rates among the candidates" in found.text and "FLAG" not in found.text
    with pytest.warns(UserWarning, match="FLAG"):
        cubic = model.recipe(run, laws=False)
    assert not any("/(x + " in t for t in cubic.model.coefficients("x_dot")["term"])


def test_a_law_the_noise_lets_a_cubic_stand_in_for_is_found_by_the_recipe():
    # quadratic drag, v' = -0.5 v|v| + F, F held at random levels, v read with 1 % noise: the
    # cubic's -0.24v - 0.24v^3 passes every check (kept with nothing said); its v^3, a state's
    # power alone, has the laws tried, and v|v| fits the rows clearly better in fewer terms
    rng = np.random.default_rng(11)
    dt, n = 0.02, 6000
    levels = rng.uniform(-2.0, 2.0, n // 250 + 1)
    force = np.array([levels[k // 250] for k in range(n)])
    v, rows = 0.0, []
    for k in range(n):
        rows.append(v)
        for _ in range(20):
            h = dt / 20
            rate = lambda v: -0.5 * v * abs(v) + force[k]
            k1 = rate(v); k2 = rate(v + 0.5 * h * k1); k3 = rate(v + 0.5 * h * k2); k4 = rate(v + h * k3)
            v = v + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    rows = np.array(rows)
    noisy = rows + 0.01 * rows.std() * rng.standard_normal(n)
    run = pd.DataFrame({"t": np.arange(n) * dt, "v": noisy, "F": force})
    found = termid.Model.from_states(["v"], ["F"]).recipe(run)
    rate = found.model.coefficients("v_dot").set_index("term")["value"]
    assert sorted(rate.index) == ["F", "v*abs(v)"]
    assert rate["v*abs(v)"] == pytest.approx(-0.5, rel=0.02) and rate["F"] == pytest.approx(1.0, rel=0.02)
    assert "a variable's power alone" in found.text and "kept, the polynomials having stood in for a law" in found.text


def test_an_input_acting_late_is_found_by_the_recipe_and_written_as_its_delay():
    # a first-order plant whose command acts 0.5 s late, x' = -0.5x + 0.8u(t - 0.5), u a square
    # wave read every 0.05 s: the recipe identifies it again with u read 0.5 s earlier (the two
    # true terms, the delay in the model written); dead_times=False keeps u as recorded, biased
    dt, n = 0.05, 4000
    u = lambda t: 1.0 if (t % 20.0) < 10.0 else -1.0
    x, rows = 0.0, []
    for k in range(n):
        rows.append(x)
        for j in range(10):
            h, t = dt / 10, k * dt + j * dt / 10
            rate = lambda t, x: -0.5 * x + 0.8 * u(t - 0.5)
            k1 = rate(t, x); k2 = rate(t + h / 2, x + h / 2 * k1); k3 = rate(t + h / 2, x + h / 2 * k2)
            k4 = rate(t + h, x + h * k3)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    t = np.arange(n) * dt
    run = pd.DataFrame({"t": t, "x": rows, "u": [u(s) for s in np.round(t, 9)]})
    model = termid.Model.from_states(["x"], ["u"])
    found = model.recipe(run)
    rate = found.model.coefficients("x_dot").set_index("term")["value"]
    assert sorted(rate.index) == ["u", "x"]
    assert rate["x"] == pytest.approx(-0.5, rel=1e-3) and rate["u"] == pytest.approx(0.8, rel=1e-3)
    assert "read as acting late, `u` by 0.500 s" in found.text and "delay = 0.5" in found.model.to_toml()
    recorded = model.recipe(run, dead_times=False)
    assert "read as acting late" not in recorded.text and "delay = " not in recorded.model.to_toml()
    assert "`u` acts on dx/dt about 0.500 s later" in recorded.text
    # identify, as `termid identify --states`, runs the same stage; dead_times=False keeps u
    found = model.identify(run)
    rate = found.model.coefficients("x_dot").set_index("term")["value"]
    assert sorted(rate.index) == ["u", "x"] and rate["u"] == pytest.approx(0.8, rel=1e-3)
    assert "delay = 0.5" in found.model.to_toml()
    assert "delay = " not in model.identify(run, dead_times=False).model.to_toml()


def test_a_model_made_from_columns_is_named_by_its_states():
    # (the name was the last column checked: `F` for a model of x and v)
    assert termid.Model.from_states(["x", "v"], ["F"]).name == "x, v"
    assert termid.Model.from_states(["x"], ["F"], name="spring").name == "spring"


def test_a_random_force_is_found_by_the_recipe_and_its_damping_identified_unbiased():
    # an oscillator under a random force (process noise, Euler-Maruyama at 1 ms), read every
    # 0.02 s for 200 s: its velocity's roughness is in the position's record too, so the recipe
    # identifies it by Itô's steps (the damping within three standard errors of -0.4), said;
    # random_force=False keeps the weak form, whose windows take in the force (the damping biased)
    rng = np.random.default_rng(5)
    h, every, steps = 0.001, 20, 200_000
    kicks = 0.3 * np.sqrt(h) * rng.standard_normal(steps)
    x, v, rows = 1.0, 0.0, []
    for k in range(steps):
        if k % every == 0:
            rows.append((k * h, x, v))
        x, v = x + h * v, v + h * (-4.0 * x - 0.4 * v) + kicks[k]
    rows = np.array(rows)
    run = pd.DataFrame({"t": rows[:, 0], "x": rows[:, 1], "v": rows[:, 2]})
    model = termid.Model.from_states(["x", "v"], [])
    with pytest.warns(UserWarning, match="a random force moves `v`"):
        found = model.recipe(run)
    v = found.model.coefficients("v_dot").set_index("term")["value"]
    assert v["v"] == pytest.approx(-0.4, abs=0.15) and v["x"] == pytest.approx(-4.0, abs=0.3)
    assert "a random force moves `v`" in found.text
    weak = model.recipe(run, random_force=False)
    assert "a random force moves" not in weak.text
    v = weak.model.coefficients("v_dot").set_index("term")["value"]
    assert v.get("v", 0.0) > -0.3


def test_a_position_recorded_alone_is_identified_with_its_rate_estimated():
    # a pendulum swinging from 2.8 rad, θ'' = -9.81 sin θ - 0.1 θ', read as its angle alone
    # with noise of 1 % of its spread: "omega=dtheta/dt" names the rate the record lacks, which
    # the runs get estimated from the angle (said); the angle's equation is the kinematic
    # θ' = ω, and ω's comes back as the law within half a percent
    def rate(s):
        return np.array([s[1], -9.81 * np.sin(s[0]) - 0.1 * s[1]])

    h, s, rows = 0.005, np.array([2.8, 0.0]), []
    for k in range(6000):
        if k % 2 == 0:
            rows.append((k * h, s[0]))
        k1 = rate(s)
        k2 = rate(s + 0.5 * h * k1)
        k3 = rate(s + 0.5 * h * k2)
        k4 = rate(s + h * k3)
        s = s + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    rows = np.array(rows)
    noise = 0.01 * rows[:, 1].std() * np.random.default_rng(3).standard_normal(len(rows))
    run = pd.DataFrame({"t": rows[:, 0], "theta": rows[:, 1] + noise})
    model = termid.Model.from_states(["theta", "omega=dtheta/dt"])
    with pytest.warns(UserWarning, match="`omega` is not recorded: estimated as `theta`'s rate"):
        found = model.recipe(run)
    omega = found.model.coefficients("omega_dot").set_index("term")["value"]
    assert sorted(omega.index) == ["omega", "sin(theta)"]
    assert omega["sin(theta)"] == pytest.approx(-9.81, rel=0.005)
    assert omega["omega"] == pytest.approx(-0.1, rel=0.1)
    assert found.model.coefficients("theta_dot")["term"].tolist() == ["omega"]


def test_a_sensor_pinned_at_the_end_of_its_range_is_cut_around():
    # a damped oscillator driven by a switched force, x and v read with noise of 1 %, x by a
    # sensor clipped at ±0.8 after its noise: the pinned stretches are said (a warning) and
    # cut out, and the pieces between give the truth within 1 % (the light damping within 2 %)
    def rate(s, u):
        return np.array([s[1], -4.0 * s[0] - 0.4 * s[1] + 2.0 * u])

    h, s, rows = 0.005, np.array([0.3, 0.0]), []
    for k in range(12000):
        u = 1.0 if (k // 2000) % 2 == 0 else -1.0
        if k % 4 == 0:
            rows.append((k * h, s[0], s[1], u))
        k1 = rate(s, u)
        k2 = rate(s + 0.5 * h * k1, u)
        k3 = rate(s + 0.5 * h * k2, u)
        k4 = rate(s + h * k3, u)
        s = s + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    rows = np.array(rows)
    rng = np.random.default_rng(9)
    x = np.clip(rows[:, 1] + 0.0055 * rng.standard_normal(len(rows)), -0.8, 0.8)
    run = pd.DataFrame({"t": rows[:, 0], "x": x, "v": rows[:, 2] + 0.011 * rng.standard_normal(len(rows)), "u": rows[:, 3]})
    with pytest.warns(UserWarning, match="`x` rests at its largest value, 0.800"):
        found = termid.Model.from_states(["x", "v"], ["u"]).recipe(run)
    v = found.model.coefficients("v_dot").set_index("term")["value"]
    assert sorted(v.index) == ["u", "v", "x"]
    assert v["x"] == pytest.approx(-4.0, rel=0.01) and v["v"] == pytest.approx(-0.4, rel=0.02)
    assert v["u"] == pytest.approx(2.0, rel=0.01)


def test_runs_of_two_systems_are_said_to_disagree():
    # ẋ = −a·x + u under u = sin t from rest, in closed form; a lag of 0.5 in one run and 1.5
    # in the other (a parameter that changed between them): all the rows fit a compromise,
    # each run alone tells its own, and the check names both
    t = np.arange(600) * 0.05

    def lag(a):
        x = (a * np.sin(t) - np.cos(t) + np.exp(-a * t)) / (a * a + 1.0)
        return pd.DataFrame({"t": t, "x": x, "u": np.sin(t)})

    model = termid.Model.from_states(["x"], ["u"])
    with pytest.warns(UserWarning, match="FLAG the runs tell one system"):
        found = model.identify([lag(0.5), lag(1.5)])
    apart = found.checks.set_index("name").loc["the runs tell one system"]
    assert not apart["passed"] and not apart["refuses"]
    assert "`x_dot`'s `x` is -0.500 (± " in apart["detail"] and "and -1.50 (± " in apart["detail"]
    # two runs of one system agree
    found = model.identify([lag(0.5), lag(0.5).iloc[100:]])
    assert found.checks.set_index("name").loc["the runs tell one system"]["passed"]
