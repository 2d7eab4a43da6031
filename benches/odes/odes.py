"""termid's defaults against pysindy's on published ODE systems (benches/odes/README.md).

Each model file in systems/ is the truth: its states, initial state and coefficients. This
script simulates it with scipy (DOP853, rtol = atol = 1e-12), independently of termid, and
identifies it three ways, equation by equation, with every monomial to degree 3 (sin and cos
of each state added where the truth has them) as candidates:

  exact    the states and their exact rates (columns `x_dot`) as targets
  samples  the states alone, noise-free, about 100 samples per characteristic period
  noisy    the same with 1 % Gaussian noise (σ = 0.01 × the state's standard deviation)

termid runs as a user would: `termid identify --data run.csv --target x_dot|dx/dt
--terms-file library.txt` and nothing else. pysindy runs with its defaults (STLSQ with
threshold 0.1, finite differences) and the same library. A system is recovered when every
equation has the true support and every coefficient lies within 0.1 % (exact), 1 % (samples)
or 10 % (noisy) of the truth.
"""

import argparse
import itertools
import json
import math
import subprocess
import sys
import time
import zlib
import tomllib
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

MODES = {"exact": 1e-3, "samples": 1e-2, "noisy": 1e-1}
PERIODS = 40  # length of a record, in characteristic periods
PER_PERIOD = 100  # samples per characteristic period


def library(states, trig):
    """Every monomial to degree 3 in termid's spelling (`x^2*y`), the constant first."""
    out = ["1"]
    for degree in (1, 2, 3):
        for combo in itertools.combinations_with_replacement(states, degree):
            parts = []
            for s in states:
                k = combo.count(s)
                if k:
                    parts.append(s if k == 1 else f"{s}^{k}")
            out.append("*".join(parts))
    if trig:
        for s in states:
            out += [f"sin({s})", f"cos({s})"]
    return out


def canonical(term, states):
    """A term as (exponents, function) whatever its spelling: `x^2*y`, `x0^2 x1`, `sin(1 x0)`."""
    term = term.strip()
    for fn in ("sin", "cos"):
        if term.startswith(fn + "("):
            arg = term[len(fn) + 1 : -1].split()[-1]
            return (fn, arg if arg in states else states[int(arg[1:])])
    exps = [0] * len(states)
    if term != "1":
        for factor in term.replace("*", " ").split():
            name, _, power = factor.partition("^")
            index = states.index(name) if name in states else int(name[1:])
            exps[index] += int(power or 1)
    return ("monomial", tuple(exps))


class System:
    def __init__(self, path):
        spec = tomllib.loads(path.read_text())
        self.name = path.stem
        self.title = spec["model"]["name"]
        self.states = [s["name"] for s in spec["states"]]
        self.initial = np.array([s["initial"] for s in spec["states"]], float)
        self.truth = {}
        for eq in spec["equations"].values():
            self.truth[eq["state"]] = {canonical(t, self.states): c for t, c in eq["coefficients"].items()}
        self.trig = any(k[0] != "monomial" for e in self.truth.values() for k in e)
        self.terms = library(self.states, self.trig)
        # the right-hand side as one Python expression per state (rows of `u`: samples)
        body = ", ".join(
            "(" + " + ".join(f"({c!r})*({t.replace('^', '**')})" for t, c in eq["coefficients"].items()) + ") + 0*_u0"
            for s in self.states
            for eq in spec["equations"].values()
            if eq["state"] == s
        )
        args = ", ".join(self.states)
        self.rhs = eval(f"lambda {args}, _u0: ({body})", {"sin": np.sin, "cos": np.cos})

    def rates(self, u):
        """The truth's right-hand side at the states `u` (rows: samples)."""
        u = np.atleast_2d(u)
        return np.column_stack(self.rhs(*u.T, u[:, 0]))

    def simulate(self, t, rtol=1e-12):
        f = lambda _t, x: self.rhs(*x, 0.0)
        sol = solve_ivp(f, (t[0], t[-1]), self.initial, method="DOP853", rtol=rtol, atol=rtol, t_eval=t)
        if sol.status != 0:
            raise RuntimeError(f"{self.name}: scipy stopped at t = {sol.t[-1]}: {sol.message}")
        return sol.y.T

    def period(self):
        """The characteristic period 2π·σ(x)/σ(ẋ) (a sinusoid's own period), the median over
        the states, on a first run of 300 time units."""
        u = self.simulate(np.linspace(0.0, 300.0, 30001), rtol=1e-9)
        return float(np.median(2 * np.pi * u.std(axis=0) / self.rates(u).std(axis=0)))


def write_csv(path, t, u, states, rates=None):
    cols = [t[:, None], u] + ([rates] if rates is not None else [])
    names = ["t"] + states + ([f"{s}_dot" for s in states] if rates is not None else [])
    np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(names), comments="", fmt="%.17g")


def recovered(found, truth, tol):
    """True support and every coefficient within `tol` (relative) of the truth."""
    if set(found) != set(truth):
        return False
    return all(abs(found[k] - c) <= tol * abs(c) for k, c in truth.items())


def termid_fit(termid, csv, target, terms_file, states, extra):
    out = subprocess.run(
        [termid, "identify", "--data", str(csv), "--target", target, "--terms-file", str(terms_file), "--format", "json"]
        + extra,
        capture_output=True,
        text=True,
    )
    if out.returncode != 0:
        return None, out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "failed"
    return found_terms(json.loads(out.stdout), states), None


def found_terms(fit, states, about=None, tol=0.0):
    """One equation's fit report as its nonzero coefficients by canonical term, an intercept
    as the constant's. `about` maps a derived name to (state, reference) where termid wrote
    its library about a reference value (`Δz = z - z0`, a state far from 0): such terms are
    multiplied out into the states' monomials, and a monomial whose contributions cancel to
    within `tol` of their size is no term."""
    about = about or {}
    if not any(name in t["term"] for t in fit["terms"] for name in about):
        found = {canonical(t["term"], states): t["coefficient"] for t in fit["terms"]}
        if fit.get("intercept") is not None:
            found[canonical("1", states)] = found.get(canonical("1", states), 0.0) + fit["intercept"]
        return {k: v for k, v in found.items() if v != 0.0}
    total, size = {}, {}

    def add(exps, c):
        key = ("monomial", tuple(exps))
        total[key] = total.get(key, 0.0) + c
        size[key] = size.get(key, 0.0) + abs(c)

    terms = [(t["term"], t["coefficient"]) for t in fit["terms"]]
    if fit.get("intercept") is not None:
        terms.append(("1", fit["intercept"]))
    for term, c in terms:
        # the term as a polynomial {exponents: coefficient}, factor by factor
        poly = {tuple([0] * len(states)): c}
        for factor in ([] if term == "1" else term.split("*")):
            name, _, power = factor.partition("^")
            k = int(power or 1)
            state, shift = about.get(name, (name, 0.0))
            i = states.index(state)
            # (s - shift)^k = Σ C(k, j) s^j (−shift)^(k−j)
            nxt = {}
            for exps, value in poly.items():
                for j in range(k + 1):
                    e = list(exps)
                    e[i] += j
                    nxt[tuple(e)] = nxt.get(tuple(e), 0.0) + value * math.comb(k, j) * (-shift) ** (k - j)
            poly = nxt
        for exps, value in poly.items():
            add(exps, value)
    return {k: v for k, v in total.items() if abs(v) > tol * size[k]}


def references(model_path):
    """The derived names termid wrote a library about (`Δz = z - z0`): {name: (state, z0)}."""
    spec = tomllib.loads(model_path.read_text())
    values = {n: p["value"] for n, p in spec.get("parameters", {}).items()}
    out = {}
    for d in spec.get("derived", []):
        state, _, ref = (part.strip() for part in d["definition"].partition(" - "))
        if ref in values:
            out[d["name"]] = (state, values[ref])
    return out


def termid_whole(termid, csv, states, terms_file, exact, extra, tol):
    """Every equation at once, as a user without a model file would: `identify --states`,
    its default library (the polynomial to degree 3) unless the system needs more (the
    pendulum's sin and cos: its library file). A library written about a state's reference
    value is multiplied out (`found_terms`)."""
    model = csv.with_suffix(".identified.toml")
    args = [termid, "identify", "--data", str(csv), "--states", ",".join(states), "--inputs", "--format", "json"]
    args += ["--terms-file", str(terms_file)] if terms_file else []
    args += ["--out", str(model), "--keep-unphysical"]
    model.unlink(missing_ok=True)
    out = subprocess.run(args + ([] if exact else extra), capture_output=True, text=True)
    failed = out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "failed"
    if out.returncode != 0 and "fails its checks" not in out.stderr:
        return None, failed
    if "fails its checks" in out.stderr:
        # refused (it was written, --keep-unphysical, to read its references): a failure
        return None, next((l for l in out.stderr.splitlines() if "FAIL" in l), failed)
    report = json.loads(out.stdout)
    about = references(model) if model.exists() else {}
    return {s: found_terms(report[f"{s}_dot"], states, about, tol) for s in states}, None


def pysindy_fit(system, t, u, rates):
    import pysindy as ps

    lib = ps.PolynomialLibrary(degree=3)
    if system.trig:
        lib = ps.ConcatLibrary([lib, ps.FourierLibrary()])
    model = ps.SINDy(feature_library=lib)
    model.fit(u, t=t[1] - t[0], x_dot=rates)
    names = model.get_feature_names()
    out = {}
    for s, row in zip(system.states, model.coefficients()):
        out[s] = {canonical(n, system.states): c for n, c in zip(names, row) if c != 0.0}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--termid", required=True)
    ap.add_argument("--work", required=True, type=Path)
    ap.add_argument("--systems", default="", help="comma-separated names (default: all)")
    ap.add_argument("--no-pysindy", action="store_true")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument(
        "--whole",
        action="store_true",
        help="termid identifies each system whole (`identify --states`, its default library) "
        "instead of one equation at a time with the library file",
    )
    ap.add_argument(
        "--termid-args",
        default="",
        help="more arguments to termid identify where the rates are estimated (samples, noisy), "
        "e.g. '--derivative central' to compare with the defaults",
    )
    args = ap.parse_args()
    here = Path(__file__).parent
    paths = sorted((here / "systems").glob("*.toml"))
    if args.systems:
        paths = [p for p in paths if p.stem in args.systems.split(",")]
    args.work.mkdir(parents=True, exist_ok=True)
    rows = []
    for path in paths:
        sys_ = System(path)
        period = sys_.period()
        dt = period / PER_PERIOD
        t = np.arange(PERIODS * PER_PERIOD + 1) * dt
        u = sys_.simulate(t)
        rates = sys_.rates(u)
        # noise of its own per system, so a subset run sees the same data
        rng = np.random.default_rng([args.seed, zlib.crc32(sys_.name.encode())])
        noisy = u + rng.normal(size=u.shape) * 0.01 * u.std(axis=0)
        folder = args.work / sys_.name
        folder.mkdir(exist_ok=True)
        (folder / "library.txt").write_text("\n".join(sys_.terms) + "\n")
        write_csv(folder / "exact.csv", t, u, sys_.states, rates)
        write_csv(folder / "samples.csv", t, u, sys_.states)
        write_csv(folder / "noisy.csv", t, noisy, sys_.states)
        row = {"system": sys_.name, "title": sys_.title, "states": len(sys_.states), "period": period}
        for mode, tol in MODES.items():
            start = time.perf_counter()
            ok, why = True, ""
            extra = [] if mode == "exact" else args.termid_args.split()
            whole, whole_err = (None, None)
            if args.whole:
                library = folder / "library.txt" if sys_.trig else None
                whole, whole_err = termid_whole(
                    args.termid, folder / f"{mode}.csv", sys_.states, library, mode == "exact", extra, tol
                )
            for s in sys_.states:
                target = f"{s}_dot" if mode == "exact" else f"d{s}/dt"
                if args.whole:
                    found, err = (whole[s], None) if whole is not None else (None, whole_err)
                else:
                    found, err = termid_fit(
                        args.termid, folder / f"{mode}.csv", target, folder / "library.txt", sys_.states, extra
                    )
                if found is None:
                    ok, why = False, f"{s}: {err}"
                    break
                if not recovered(found, sys_.truth[s], tol):
                    ok = False
                    off = set(found) ^ set(sys_.truth[s])
                    why = why or (f"{s}: {len(off)} terms off the support" if off else f"{s}: coefficients off")
            row[f"termid_{mode}"] = ok
            row[f"termid_{mode}_why"] = why
            row[f"termid_{mode}_s"] = time.perf_counter() - start
            if not args.no_pysindy:
                data = {"exact": (u, rates), "samples": (u, None), "noisy": (noisy, None)}[mode]
                start = time.perf_counter()
                try:
                    fits = pysindy_fit(sys_, t, *data)
                    row[f"pysindy_{mode}"] = all(recovered(fits[s], sys_.truth[s], tol) for s in sys_.states)
                except Exception as e:  # a peer's failure is a result, not a crash of the script
                    print(f"pysindy on {sys_.name} ({mode}): {e}", file=sys.stderr)
                    row[f"pysindy_{mode}"] = False
                row[f"pysindy_{mode}_s"] = time.perf_counter() - start
        rows.append(row)
        print(
            f"{sys_.name:22s} T={period:7.3f}  "
            + "  ".join(
                f"{m}: termid {'✓' if row[f'termid_{m}'] else '✗'}"
                + ("" if args.no_pysindy else f" pysindy {'✓' if row[f'pysindy_{m}'] else '✗'}")
                for m in MODES
            )
            + "".join(f"  [{m}: {row[f'termid_{m}_why']}]" for m in MODES if row[f"termid_{m}_why"]),
            file=sys.stderr,
            flush=True,
        )
    (args.work / "results.json").write_text(json.dumps(rows, indent=1))
    report(rows, not args.no_pysindy)


def report(rows, peer):
    n = len(rows)
    print(f"# ODE benchmark: {n} systems, every monomial to degree 3 as candidates\n")
    print(f"Recovered: true support in every equation, coefficients within {', '.join(f'{tol:.1%} ({m})' for m, tol in MODES.items())}.\n")
    head = "| mode | termid (defaults) |" + (" pysindy 2 (defaults) |" if peer else "")
    print(head)
    print("|---|---|" + ("---|" if peer else ""))
    for m in MODES:
        k = sum(r[f"termid_{m}"] for r in rows)
        line = f"| {m} | {k}/{n} ({k / n:.0%}) |"
        if peer:
            p = sum(r[f"pysindy_{m}"] for r in rows)
            line += f" {p}/{n} ({p / n:.0%}) |"
        print(line)
    print("\nTime per system (all equations, in process; termid as one process per equation):\n")
    print("| mode | termid median [s] | termid max [s] |" + (" pysindy median [s] | pysindy max [s] |" if peer else ""))
    print("|---|---|---|" + ("---|---|" if peer else ""))
    for m in MODES:
        ts = [r[f"termid_{m}_s"] for r in rows]
        line = f"| {m} | {np.median(ts):.3f} | {max(ts):.3f} |"
        if peer:
            ps_ = [r[f"pysindy_{m}_s"] for r in rows]
            line += f" {np.median(ps_):.3f} | {max(ps_):.3f} |"
        print(line)
    print("\n| system | states | T | " + " | ".join(f"{m}" for m in MODES) + " |")
    print("|---|---|---|" + "---|" * len(MODES))
    for r in rows:
        cells = []
        for m in MODES:
            c = ("✓" if r[f"termid_{m}"] else "✗") + (f" / {'✓' if r[f'pysindy_{m}'] else '✗'}" if peer else "")
            cells.append(c)
        print(f"| {r['system']} | {r['states']} | {r['period']:.3g} | " + " | ".join(cells) + " |")
    if peer:
        print("\n(cells: termid / pysindy)")


if __name__ == "__main__":
    main()
