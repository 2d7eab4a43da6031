"""Mergeable statistics: shards of runs merged give the fit of all rows together."""
import pickle
import warnings

import pytest

import termid


def test_merged_moments_fit_as_the_rows_do(ship, zigzags):
    whole = ship.identify(zigzags, target="column", equations=["r_dot"])
    parts = [termid.Moments.from_frame(run, ship, "r_dot") for run in zigzags]
    merged = parts[0]
    for p in parts[1:]:
        merged = merged.merge(p)
    assert merged.rows == sum(len(r) for r in zigzags)
    from_moments = ship.identify_from_moments(merged)
    a = whole.model.coefficients("r_dot").set_index("term")["value"]
    b = from_moments.model.coefficients("r_dot").set_index("term")["value"]
    assert list(a.index) == list(b.index)
    for term in a.index:
        assert b[term] == pytest.approx(a[term], rel=1e-10, abs=1e-14)
    # merging is associative: the same statistics in another grouping
    other = parts[0].merge(parts[1].merge(parts[2]).merge(parts[3])).merge(parts[4])
    assert other.to_json() == merged.to_json()


def test_moments_pickle_exactly(ship, zigzags):
    m = termid.Moments.from_frame(zigzags[:2], ship, "v_dot")
    again = pickle.loads(pickle.dumps(m))
    assert again.to_json() == m.to_json()
    assert again.runs == m.runs and again.candidates == m.candidates


def test_statistics_of_other_equations_do_not_merge(ship, zigzags):
    a = termid.Moments.from_frame(zigzags[0], ship, "v_dot")
    b = termid.Moments.from_frame(zigzags[0], ship, "r_dot")
    with pytest.raises(termid.TermidError, match="cannot be merged"):
        a.merge(b)


def test_moments_add_and_compare(ship, zigzags):
    parts = [termid.Moments.from_frame(run, ship, "r_dot") for run in zigzags[:3]]
    merged = parts[0].merge(parts[1]).merge(parts[2])
    assert parts[0] + parts[1] + parts[2] == merged
    assert sum(parts[1:], parts[0]) == merged
    assert merged != parts[0] and parts[0] == termid.Moments.from_frame(zigzags[0], ship, "r_dot")
    assert (parts[0] == "statistics") is False


def test_statistics_carry_the_noise_that_biases_the_terms():
    """Lorenz with white noise of 5 % of each state's spread, its statistics gathered in two
    shards and sent between processes (pickled): the terms identified from them are flagged
    as biased by the noise (warned of), as from the rows; at 0.5 % they are not."""
    import numpy as np

    lorenz = termid.Model.builtin("lorenz")
    run = lorenz.simulate(duration=20.0, sample=0.01)
    rng = np.random.default_rng(5)
    for share, said in [(0.05, True), (0.005, False)]:
        noisy = run.copy()
        for c in "xyz":
            noisy[c] += share * run[c].std() * rng.standard_normal(len(run))
        halves = [noisy.iloc[: len(noisy) // 2], noisy.iloc[len(noisy) // 2 :]]
        parts = [pickle.loads(pickle.dumps(termid.Moments.from_frame(h, lorenz, "y_dot"))) for h in halves]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            checks = lorenz.identify_from_moments(parts).checks.set_index("name")
        noise = checks.loc["the records' noise leaves the terms unbiased"]
        assert (not noise["passed"]) == said and "white noise of `x` " in noise["detail"], noise["detail"]
        assert any("the records' noise" in str(w.message) for w in caught) == said


def test_statistics_carry_the_halves_the_terms_must_hold_on():
    """ẋ = −x + u with u acting over the first 8 s of 20 only: statistics of two shards (each a
    run), merged and identified, flag `u` as chosen from all the rows but not from the second
    halves (warned of), as a fit of the rows does; with u throughout, the check passes."""
    import numpy as np
    import pandas as pd

    def run(u, x):
        t = np.arange(400) * 0.05
        xs, fine = [], 200
        for k in range(400):
            xs.append(x)
            for j in range(fine):
                s = t[k] + j * 0.05 / fine
                x += 0.05 / fine * (-x + u(s))
        return pd.DataFrame({"t": t, "x": xs, "u": [u(s) for s in t]})

    model = termid.Model.from_states(["x"], inputs=["u"])
    early = lambda s: np.sin(0.7 * s) * (1 - s / 8) if s < 8 else 0.0
    throughout = lambda s: np.sin(0.7 * s) + 0.3 * np.cos(1.9 * s)
    for u, passed in [(early, False), (throughout, True)]:
        shards = [model.moments("x_dot", run(u, x0), derivative="central") for x0 in (0.5, -0.3)]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            found = model.identify_from_moments(shards[0] + shards[1])
        halves = found.checks.set_index("name").loc["the terms hold on each half of the runs"]
        assert bool(halves["passed"]) == passed, halves["detail"]
        assert passed or "`x_dot`: `u`" in halves["detail"], halves["detail"]
        assert any("each half" in str(w.message) for w in caught) != passed
