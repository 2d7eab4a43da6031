# %% [markdown]
# # Identifying a system that is not a ship
#
# A notebook in plain text (open it with Jupytext, or run it as a script). The Lorenz system is
# simulated and measured with 1 % noise; termid identifies its three equations from the
# samples alone (the integral form: no derivative is estimated) with every monomial to degree
# 2 as candidates, and the identified system is simulated again.

# %%
import numpy as np

import termid
from termid import plot

lorenz = termid.Model.builtin("lorenz")
truth = lorenz.simulate(duration=20.0, sample=0.01)
rng = np.random.default_rng(0)
measured = truth[["t", "x", "y", "z"]].copy()
for c in "xyz":
    measured[c] += 0.01 * measured[c].std() * rng.standard_normal(len(measured))
measured.head()

# %% [markdown]
# The model file lists the candidates and asks for sequential thresholding (``stlsq``); the
# defaults choose the threshold by BIC along the threshold path.

# %%
found = lorenz.identify(measured)
print(found.targets)
for eq in found.model.equations:
    print(eq, dict(zip(found.model.coefficients(eq)["term"], found.model.coefficients(eq)["value"].round(3))))

# %% [markdown]
# The identified system from the same initial state, over one Lyapunov time or so.

# %%
again = found.model.simulate(duration=2.0, sample=0.01)
short = truth[truth["t"] <= 2.0 + 1e-9]
fig = plot.run(short, again, ["x", "y", "z"])
print("largest difference over 2 s:", float(np.abs(again["x"].to_numpy() - short["x"].to_numpy()).max()))

# %% [markdown]
# The same regression without a model file: ``termid.fit`` on a DataFrame, statsmodels-style,
# here on the true rates (``Model.predict``) beside the states.

# %%
rates = truth.join(lorenz.predict(truth))
fitted = termid.fit(rates, "z_dot", ["x", "y", "z", "x*y", "x*z", "y*z"], "stepwise", step_rule="last")
fitted.summary()
