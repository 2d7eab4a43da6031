"""The plotting helpers draw what they say, on shared axes and at equal scale."""
import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import termid  # noqa: E402
import termid.plot  # noqa: E402


def test_a_run_against_its_simulation_shares_one_time_axis(ship, zigzags):
    run = zigzags[0]
    again = ship.replay(run)[0]
    fig = termid.plot.run(run, again, columns=["r", "ψ", "δ"])
    axes = fig.get_axes()
    assert len(axes) == 3 and all(ax.get_shared_x_axes().joined(axes[0], ax) for ax in axes)
    assert [ax.get_ylabel() for ax in axes] == ["r", "ψ", "δ"] and axes[-1].get_xlabel() == "t [s]"
    # the same colour for a series in every panel
    assert len({ax.get_lines()[0].get_color() for ax in axes}) == 1
    with pytest.raises(ValueError):
        termid.plot.run(run[["t"]])
    # a time named by its unit is in it, not seconds
    days = run[["t", "r"]].rename(columns={"t": "day"})
    assert termid.plot.run(days, time="day").get_axes()[-1].get_xlabel() == "day"


def test_a_track_at_equal_scale_and_the_step_table(ship, hald):
    turn = ship.simulate("turning:35")
    fig = termid.plot.track(turn)
    ax = fig.get_axes()[0]
    assert ax.get_aspect() == 1.0 and ax.get_xlabel() == "y0 [m]"
    fitted = termid.fit(hald, "y", ["x1", "x2", "x3", "x4"])
    fig = termid.plot.steps(fitted)
    assert "y" in fig.get_axes()[0].get_title()
