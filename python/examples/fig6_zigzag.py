# %% [markdown]
# # Oltmann (1973), Abb. 6 from Python
#
# The paper's Fig. 6: the "modified" 30°/10° Z-manoeuvre of HSVA model 1512 — the original
# manoeuvre's rudder history replayed with the coefficients averaged over the single-run
# regressions ("Mittelwert", Table 2 column 7) — δ(t), ψ(t) and U(t)/U0, the original
# (smooth lines) against the re-simulation (markers). Run it as a script
# (`python fig6_zigzag.py [OUT.png]`) or cell by cell in a notebook.

# %%
import sys

import numpy as np
import pandas as pd

import termid

ship = termid.Model.default()  # Table 2's "Ausgangswerte": the true coefficients
runs = {m: ship.simulate(m) for m in
        ["zigzag:15/10", "zigzag:20/10:port", "zigzag:30/10", "zigzag:20/20:port", "zigzag:25/10"]}

# %% [markdown]
# Each Z-manoeuvre regressed alone (stepwise, the model file's candidates), then a term's
# coefficients averaged where it was found in every run (NOTES.md §7, "Mittelwert").

# %%
singles = [ship.identify(run, target="column", names=[name]).model for name, run in runs.items()]
mean = termid.Model.from_toml(ship.to_toml(), "Mittelwert")
for eq in ship.identifiable:
    tables = [m.coefficients(eq).set_index("term")["value"] for m in singles]
    everywhere = set.intersection(*(set(t.index) for t in tables))
    averaged = pd.concat([t[sorted(everywhere)] for t in tables], axis=1).mean(axis=1)
    mean.set_coefficients(eq, averaged)
    print(f"{eq}: {len(averaged)} terms found in all five runs")

# %% [markdown]
# The 30°/10° manoeuvre re-simulated with the averaged coefficients, its rudder replayed.

# %%
original = runs["zigzag:30/10"]
replayed = mean.replay(original)[0]
u0 = original["u"].iloc[0]
speed = lambda f: np.hypot(f["u"], f["v"]) / u0
error = np.degrees(replayed["ψ"] - original["ψ"]).abs().max()
print(f"largest heading difference {error:.2f}°")

# %%
def figure(path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, height_ratios=[2, 1])
    t = original["t"]
    top.plot(t, np.degrees(original["ψ"]), "k-", label="ψ original")
    top.plot(t, np.degrees(original["δ"]), "k--", label="δ")
    top.plot(replayed["t"][::20], np.degrees(replayed["ψ"][::20]), "D", ms=4, mfc="none", label="ψ Mittelwert coefficients")
    top.set_ylabel("angle [°]")
    top.set_ylim(-40, 48)  # room for the legend above the data
    top.legend(loc="upper center", ncol=3, fontsize=8, frameon=False)
    bottom.plot(t, speed(original), "k-", label="original")
    bottom.plot(replayed["t"][::20], speed(replayed)[::20], "D", ms=4, mfc="none", label="Mittelwert coefficients")
    bottom.set_ylabel("U/U0 [-]")
    bottom.set_xlabel("t [s]")
    fig.suptitle("HSVA model 1512, modified 30°/10° Z-manoeuvre (Oltmann 1973, Abb. 6)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    figure(sys.argv[1] if len(sys.argv) > 1 else "fig6_zigzag.png")
