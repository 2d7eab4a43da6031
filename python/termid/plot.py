"""Figures a notebook shows (matplotlib, an optional extra: ``pip install ./python[plot]``):
a run against its simulation, a ship's track at equal scale, a fit's step table. Each
returns the matplotlib Figure; nothing is shown or saved unless the caller does."""

from __future__ import annotations

from typing import Any, Optional, Sequence

import pandas as pd

from . import _termid

#: One colour per series, kept across panels and figures (measured, simulated).
COLOURS = {"measured": "#1f77b4", "simulated": "#d62728"}


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # the optional extra
        raise ImportError("termid.plot needs matplotlib: pip install matplotlib") from e
    return plt


def run(
    measured: pd.DataFrame,
    simulated: Optional[pd.DataFrame] = None,
    columns: Optional[Sequence[str]] = None,
    time: str = "t",
) -> Any:
    """Stacked panels on one time axis: each column of ``measured`` (every column but the
    time by default) and, where given, the same column of ``simulated``; ``columns`` the
    columns drawn, ``time`` the time column (seconds, or the unit its name says: ``day``).

    >>> from termid import plot
    >>> ship = termid.Model.default()
    >>> fig = plot.run(ship.record("zigzag:20/20"), ship.simulate("zigzag:20/20"), ["ψ", "δ", "r"])
    >>> len(fig.axes)
    3
    """
    plt = _pyplot()
    names = list(columns) if columns is not None else [c for c in measured.columns if c != time]
    if not names:
        raise ValueError("no columns to draw")
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(8, 1.8 * len(names) + 0.6), squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        ax.plot(measured[time], measured[name], color=COLOURS["measured"], label="measured")
        if simulated is not None and name in simulated:
            ax.plot(simulated[time], simulated[name], color=COLOURS["simulated"], linestyle="--", label="simulated")
        ax.set_ylabel(name)
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="upper right")
    # a time named by its unit (`day`, `Time (ms)`) is in it, as a model's run writes it
    per = _termid.seconds_per(time)
    axes[-1, 0].set_xlabel(time if per is not None and per != 1.0 else f"{time} [s]")
    fig.tight_layout()
    return fig


def track(
    measured: pd.DataFrame,
    simulated: Optional[pd.DataFrame] = None,
    x: str = "x0",
    y: str = "y0",
) -> Any:
    """A ship's track, north up and at equal scale (x0 forward at the start, y0 to
    starboard, as termid's ship model writes them), ``measured`` and ``simulated``; ``x`` and
    ``y`` the position columns (metres).

    >>> from termid import plot
    >>> fig = plot.track(termid.Model.default().simulate("turning:35"))
    >>> fig.axes[0].get_xlabel()
    'y0 [m]'
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot(measured[y], measured[x], color=COLOURS["measured"], label="measured")
    if simulated is not None:
        ax.plot(simulated[y], simulated[x], color=COLOURS["simulated"], linestyle="--", label="simulated")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{y} [m]")
    ax.set_ylabel(f"{x} [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    fig.tight_layout()
    return fig


def steps(fit: Any) -> Any:
    """A fit's step table: R² and F against the step, the term entered at each, the chosen
    step marked; ``fit`` a :class:`termid.Fit`.

    >>> from termid import plot
    >>> df = pd.DataFrame({"x": [0.0, 1, 2, 3, 4], "y": [1.0, 3.1, 4.9, 7.0, 9.0]})
    >>> plot.steps(termid.fit(df, "y", "x")).axes[0].get_title()
    'y: 1 steps'
    """
    plt = _pyplot()
    table = fit.steps
    if table.empty:
        raise ValueError("the fit has no steps to draw")
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(table["step"], table["r2"], marker="o", color=COLOURS["measured"], label="R²")
    ax.set_xlabel("step")
    ax.set_ylabel("R²")
    ax.set_xticks(table["step"])
    ax.set_xticklabels([f"{s}\n{t}" for s, t in zip(table["step"], table["term"])], fontsize=7)
    right = ax.twinx()
    right.plot(table["step"], table["f"], marker="s", color=COLOURS["simulated"], label="F")
    right.set_ylabel("F")
    chosen = fit.chosen_step
    if chosen is not None:
        ax.axvline(chosen, color="grey", linestyle=":", label=f"chosen: step {chosen}")
    lines = ax.get_legend_handles_labels()
    more = right.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], loc="lower right")
    ax.set_title(f"{fit.target}: {len(table)} steps")
    fig.tight_layout()
    return fig
