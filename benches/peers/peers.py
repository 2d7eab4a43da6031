"""Time termid's back-ends and the peers on the same data, the same way: each fit in its own
language's process, data already loaded, median of repeated fits (101 by default) after a
warm-up.

Data: the default model's five exact zigzags (written by `termid reproduce`), the 29
candidate terms of v-dot and r-dot (Oltmann 1973), combined (2 505 rows); and a 10^6 x 100
synthetic problem for the pass over the rows. Prints a Markdown table.
"""
import argparse
import glob
import json
import os
import platform
import statistics
import subprocess
import time

import numpy as np

TERMS = ["u^2", "u*v", "u*r", "u^2*delta", "v^3/u", "v^2*r/u", "v*r^2/u", "r^3/u", "v^2*delta",
         "u*v*delta^2", "r^2*delta", "u*r*delta^2", "u^2*delta^3", "v*du", "r*du", "u*du*delta",
         "v*du^2/u", "r*du^2/u", "delta*du^2", "v*r*delta", "v*r", "v^2", "r^2", "u^2*delta^2",
         "u*v*delta", "u*r*delta", "v*r*du/u", "r*du*delta", "v*du*delta"]


def design(files):
    """The 29 candidates' matrix, the targets, and the variables the terms are written in."""
    cols, ys, variables = [], {"v_dot": [], "r_dot": []}, []
    for f in sorted(files):
        d = np.genfromtxt(f, delimiter=",", names=True, encoding="utf-8", comments="#")
        u, v, r, delta = d["u"], d["v"], d["r"], d["δ"] if "δ" in d.dtype.names else d["delta"]
        du = u - u[0]
        env = {"u": u, "v": v, "r": r, "delta": delta, "du": du}
        cols.append(np.column_stack([eval(t.replace("^", "**"), {}, env) for t in TERMS]))
        variables.append(env)
        ys["v_dot"].append(d["v_dot"])
        ys["r_dot"].append(d["r_dot"])
    variables = {k: np.concatenate([e[k] for e in variables]) for k in variables[0]}
    return np.vstack(cols), {k: np.concatenate(v) for k, v in ys.items()}, variables


def timed(fn, repeat, warm_up=0.3):
    """Median of `repeat` calls after warming up for `warm_up` seconds (at least one call),
    the same protocol as `termid compare --warm-up`."""
    started = time.perf_counter()
    fn()
    while time.perf_counter() - started < warm_up:
        fn()
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def numpy_stepwise(X, y):
    """The same forward stepwise (STPRG) in numpy: corrected cross-products, sweeps."""
    Z = np.column_stack([X, y])
    Z = Z - Z.mean(axis=0)
    A = Z.T @ Z
    d = np.sqrt(np.diag(A))
    A = A / np.outer(d, d)
    p = X.shape[1]
    entered = []
    for _ in range(p):
        cand = [j for j in range(p) if j not in entered and A[j, j] > 1e-10]
        if not cand:
            break
        j = max(cand, key=lambda j: A[j, p] ** 2 / A[j, j])
        # Goodnight's sweep on j
        piv = A[j, j]
        row = A[j] / piv
        col = A[:, j].copy()
        A = A - np.outer(col, row)
        A[:, j] = -col / piv
        A[j] = row
        A[j, j] = 1.0 / piv
        entered.append(j)
        if A[p, p] < 1e-13:
            break
    return entered


def peers(X, y, repeat, slow_repeat):
    import pysindy as ps
    import statsmodels.api as sm
    from abess.linear import LinearRegression
    from sklearn.linear_model import LassoCV

    rows = []
    t, sel = timed(lambda: numpy_stepwise(X, y), repeat)
    rows.append(("numpy forward stepwise", t, len(sel)))
    Xc = sm.add_constant(X)
    t, _ = timed(lambda: sm.OLS(y, Xc).fit(), repeat)
    rows.append(("statsmodels OLS (all terms)", t, X.shape[1]))
    opt = lambda: ps.STLSQ(threshold=1e-6, normalize_columns=True).fit(X, y)
    t, o = timed(opt, repeat)
    rows.append(("pysindy STLSQ", t, int(np.count_nonzero(o.coef_))))
    t, o = timed(lambda: LinearRegression().fit(X, y), slow_repeat)
    rows.append(("abess best subset", t, int(np.count_nonzero(o.coef_))))
    t, o = timed(lambda: LassoCV(cv=5, max_iter=100000).fit(X, y), slow_repeat)
    rows.append(("scikit-learn LassoCV", t, int(np.count_nonzero(o.coef_))))
    return rows


def relative(base, t):
    """How a time compares with the numpy stepwise's: '2.4x faster' or '536x slower'."""
    return f"{base / t:.1f}x faster" if t <= base else f"{t / base:.1f}x slower"


def in_process(X, ys, variables, repeat):
    """termid called in this Python process (the package in python/): the stepwise from a
    pandas DataFrame of the finished matrix, timed with the call and the conversion, and
    `predict` of the 29 terms (compiled, all kept) on the 2 505 rows of the variables."""
    import pandas as pd
    import termid

    names = [f"c{j}" for j in range(X.shape[1])]
    out = {}
    for eq, y in ys.items():
        frame = pd.DataFrame(X, columns=names).assign(y=y)
        t, fit = timed(lambda: termid.fit(frame, "y", names, "stepwise"), repeat)
        out[("python-stepwise", eq)] = (t, len(fit.coefficients))
    data = pd.DataFrame(variables)
    # every one of the 29 terms kept (STLSQ with threshold 0 thresholds nothing away)
    fit = termid.fit(data.assign(y=ys["r_dot"]), "y", TERMS, "stlsq", threshold=0.0)
    columns = {k: np.ascontiguousarray(v) for k, v in variables.items()}
    t_dict, _ = timed(lambda: fit.predict(columns), repeat)
    t_frame, _ = timed(lambda: fit.predict(data), repeat)
    return out, (len(fit.coefficients), len(data), t_dict, t_frame)


def termid_times(binary, files, repeat, model=None):
    extra = ["--model", model] if model else []
    out = subprocess.run([binary, "compare", *extra, "--equation", "v_dot", "r_dot", "--repeat", str(repeat),
                          "--format", "json", "--data", *sorted(files)], check=True, capture_output=True, text=True)
    res = {}
    for e in json.loads(out.stdout):
        for eq in e["equations"]:
            res[(e["backend"], eq["equation"])] = (eq["time_ms"] / 1e3, len(eq["terms"]))
    return res


def finished_matrix(binary, X, ys, repeat, work):
    """termid's stepwise on the peers' own finished matrix: a generic model whose 29
    candidates are the matrix's columns, so that no term is evaluated (like for like)."""
    n, p = X.shape
    model = os.path.join(work, "finished_matrix.toml")
    with open(model, "w", encoding="utf-8") as f:
        f.write('[model]\nname = "the peers\' finished 29-column matrix"\n'
                'provenance = "benches/peers/peers.py"\ntime = "t"\n\n'
                '[[states]]\nname = "s"\nunit = "-"\ninitial = 0.0\n\n')
        for j in range(p):
            f.write(f'[[inputs]]\nname = "c{j}"\nunit = "-"\ninitial = 0.0\n\n')
        f.write('[equations.s_dot]\nstate = "s"\ncandidates = [' + ", ".join(f'"c{j}"' for j in range(p)) +
                ']\nbackend = { method = "stepwise" }\n')
    out = {}
    for eq, y in ys.items():
        path = os.path.join(work, f"finished_{eq}.csv")
        with open(path, "w", encoding="utf-8") as f:
            f.write("t,s_dot," + ",".join(f"c{j}" for j in range(p)) + "\n")
            for i in range(n):
                f.write(f"{0.2 * i:.1f},{float(y[i])!r}," + ",".join(repr(float(v)) for v in X[i]) + "\n")
        res = subprocess.run([binary, "compare", "--model", model, "--equation", "s_dot", "--repeat", str(repeat),
                              "--format", "json", "--data", path], check=True, capture_output=True, text=True)
        for e in json.loads(res.stdout):
            if e["backend"] == "stepwise":
                q = e["equations"][0]
                out[eq] = (q["time_ms"] / 1e3, len(q["terms"]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--termid", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--repeat", type=int, default=101)
    ap.add_argument("--quick", action="store_true", help="skip the 10^6 x 100 problem")
    a = ap.parse_args()
    files = [f for f in glob.glob(os.path.join(a.data, "z*.csv")) if "alt5" not in f]
    X, ys, variables = design(files)
    ours = termid_times(a.termid, files, a.repeat)
    # the sparse path with λ chosen by cross-validation (leave one run out), as LassoCV does
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "..", "..", "models", "oltmann1973.toml"), encoding="utf-8") as f:
        text = f.read().replace('backend = { method = "stepwise" }',
                                'backend = { method = "sparse", choice = "leave-one-run-out" }')
    cv_model = os.path.join(here, "work", "sparse_cv.toml")
    with open(cv_model, "w", encoding="utf-8") as f:
        f.write(text)
    cv = termid_times(a.termid, files, a.repeat, cv_model)
    for eq in ["v_dot", "r_dot"]:
        ours[("sparse-cv", eq)] = cv[("sparse", eq)]
    for eq, r in finished_matrix(a.termid, X, ys, a.repeat, os.path.join(here, "work")).items():
        ours[("stepwise-matrix", eq)] = r
    python, (n_terms, n_rows, t_dict, t_frame) = in_process(X, ys, variables, a.repeat)
    ours.update(python)
    print(f"# termid and its peers ({platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"numpy {np.__version__})\n")
    print(f"Combined data of the five zigzags: {X.shape[0]} rows x {X.shape[1]} candidates. "
          "termid's times include evaluating the terms and the one-pass statistics (the terms are "
          "compiled once per equation beforehand, as the peers' matrix is built beforehand); the peers get the "
          "finished 29-column matrix (termid's stepwise is also timed on that matrix, as a model whose "
          "candidates are its columns). Median of repeated fits after a warm-up.\n")
    for eq in ["v_dot", "r_dot"]:
        print(f"## {eq}\n\n| method | time [ms] | terms | ratio to numpy stepwise |\n|---|---|---|---|")
        rows = peers(X, ys[eq], a.repeat, max(3, a.repeat // 7))
        base = rows[0][1]
        labels = {"sparse": "sparse (λ by BIC)", "sparse-cv": "sparse (λ by leave-one-run-out CV)",
                  "stepwise": "stepwise (terms evaluated from the runs)",
                  "stepwise-matrix": "stepwise (the peers' finished matrix)"}
        labels["python-stepwise"] = "stepwise from Python: `termid.fit(DataFrame)` in this process, with the conversion"
        for name in ["stepwise", "stepwise-matrix", "python-stepwise", "efroymson", "best-subset", "sparse",
                     "sparse-cv"]:
            t, k = ours[(name, eq)]
            print(f"| termid {labels.get(name, name)} | {t * 1e3:.3f} | {k} | {relative(base, t)} |")
        for name, t, k in rows:
            print(f"| {name} | {t * 1e3:.3f} | {k} | {relative(base, t)} |")
        print()
    print(f"## predict from Python\n\n`Fit.predict` of the {n_terms} terms (compiled; `v^3/u`, `u*du*delta`, ...) "
          f"on {n_rows} rows, in this process: {t_dict * 1e6:.1f} µs from a dict of numpy arrays, "
          f"{t_frame * 1e6:.1f} µs from a pandas DataFrame (PySINDy's `predict`: ~5 ms for a similar size, "
          "its issue #653).\n")
    if not a.quick:
        rng = np.random.default_rng(7)
        n, p = 1_000_000, 100
        Xl = rng.random((n, p)) - 0.5
        yl = 2 * Xl[:, 0] - Xl[:, 3] + 0.5 * Xl[:, 50] + 0.1 * (rng.random(n) - 0.5)
        t_xtx, _ = timed(lambda: Xl.T @ Xl, 3)
        t_sw, _ = timed(lambda: numpy_stepwise(Xl, yl), 3)
        print("## 10^6 x 100 synthetic\n\n| method | time [ms] |\n|---|---|")
        print(f"| numpy X'X | {t_xtx * 1e3:.1f} |\n| numpy forward stepwise | {t_sw * 1e3:.1f} |")
        print("\ntermid on the same size: `cargo bench --bench selectors -- backends_1e6x100` (criterion).")


if __name__ == "__main__":
    main()
