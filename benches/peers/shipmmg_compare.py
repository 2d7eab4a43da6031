"""termid's MMG model file (models/mmg_kvlcc2.toml) against the shipmmg package (its KVLCC2 L7
parameter set), the independent implementation of the same MMG equations.

termid simulates each manoeuvre (RK4, 0.01 s) from the straight run at the self-propulsion
point (the propeller's rate that holds u0) and writes its run; the rudder angle and propeller
rate series of that run are given to shipmmg (scipy's RK45 with tight tolerances) from the same initial state,
and both trajectories are measured by the same functions here: advance and tactical diameter
of turning circles, first and second overshoots of zigzags. Python serves only this
comparison, never the product.

Usage: shipmmg_compare.py --termid PATH [--model models/mmg_kvlcc2.toml] [--work DIR]
"""

import argparse
import os
import subprocess
import sys

import numpy as np
from shipmmg.mmg_3dof import Mmg3DofBasicParams, Mmg3DofManeuveringParams, simulate_mmg_3dof


def kvlcc2_l7():
    """shipmmg's own KVLCC2 L7 test case (tests/test_mmg_3dof.py of the package)."""
    rho, L, d, nabla = 1025.0, 7.00, 0.46, 3.27
    D_p, H_R = 0.216, 0.345
    basic = Mmg3DofBasicParams(
        L_pp=L, B=1.27, d=d, x_G=0.25, D_p=D_p, m=rho * nabla,
        I_zG=rho * nabla * (0.25 * L) ** 2, A_R=0.0539, η=D_p / H_R,
        m_x=0.5 * rho * L**2 * d * 0.022, m_y=0.5 * rho * L**2 * d * 0.223,
        J_z=0.5 * rho * L**4 * d * 0.011, f_α=2.747, ϵ=1.09, t_R=0.387,
        x_R=-0.500 * L, a_H=0.312, x_H=-0.464 * L, γ_R_minus=0.395, γ_R_plus=0.640,
        l_R=-0.710, κ=0.50, t_P=0.220, w_P0=0.40, x_P=-0.690,
    )
    man = Mmg3DofManeuveringParams(
        k_0=0.2931, k_1=-0.2753, k_2=-0.1385, R_0_dash=0.022, X_vv_dash=-0.040,
        X_vr_dash=0.002, X_rr_dash=0.011, X_vvvv_dash=0.771, Y_v_dash=-0.315,
        Y_r_dash=0.083, Y_vvv_dash=-1.607, Y_vvr_dash=0.379, Y_vrr_dash=-0.391,
        Y_rrr_dash=0.008, N_v_dash=-0.137, N_r_dash=-0.049, N_vvv_dash=-0.030,
        N_vvr_dash=-0.294, N_vrr_dash=0.055, N_rrr_dash=-0.013,
    )
    return basic, man


U0 = 2.29 * 0.512  # shipmmg's approach speed in its test case, m/s


def read_run(path):
    data = np.genfromtxt(path, delimiter=",", names=True, encoding="utf-8")
    names = data.dtype.names
    col = lambda n: np.asarray(data[n], dtype=float)
    return {"t": col("t"), "u": col("u"), "v": col("v"), "r": col("r"), "psi": col(names[4]),
            "x": col("x0"), "y": col("y0"), "delta": col(names[7]), "n": col("n")}


def shipmmg_run(t, delta, n):
    basic, man = kvlcc2_l7()
    sol = simulate_mmg_3dof(basic, man, t, delta, n, u0=U0,
                            method="RK45", rtol=1e-9, atol=1e-11, max_step=0.05)
    u, v, r, x, y, psi = sol.sol(t)[:6]
    return {"t": t, "u": u, "v": v, "r": r, "psi": psi, "x": x, "y": y, "delta": delta}


def crossing(t, s, level):
    """First time s reaches level (linear interpolation), with the other columns there."""
    i = int(np.argmax(s >= level))
    if s[i] < level:
        return None
    if i == 0:
        return 0.0
    w = (level - s[i - 1]) / (s[i] - s[i - 1])
    return i - 1 + w


def at(series, k):
    i = int(np.floor(k))
    w = k - i
    return series[i] if w == 0 else (1 - w) * series[i] + w * series[i + 1]


def turning_metrics(run):
    """Advance (along the approach course at 90° heading change) and tactical diameter
    (across it at 180°), measured from the rudder execute at t = 0, in metres."""
    turned = np.abs(run["psi"] - run["psi"][0])
    k90, k180 = crossing(run["t"], turned, np.pi / 2), crossing(run["t"], turned, np.pi)
    return {"advance_m": at(run["x"], k90) - run["x"][0],
            "tactical_diameter_m": abs(at(run["y"], k180) - run["y"][0])}


def zigzag_metrics(run, heading_deg):
    """First and second overshoot angles, degrees: the heading's extremes beyond ±ψ_check
    after the first and second rudder reversals."""
    psi = np.degrees(run["psi"] - run["psi"][0])
    side = np.sign(psi[np.argmax(np.abs(psi) > 1.0)])
    out = {}
    s = side * psi
    k = crossing(run["t"], s, heading_deg)
    i = int(np.ceil(k))
    j = i + int(np.argmax(np.diff(s[i:]) < 0))  # first maximum after the check
    out["first_overshoot_deg"] = s[j] - heading_deg
    s2 = -s[j:]
    k2 = crossing(run["t"][j:], s2, heading_deg)
    i2 = int(np.ceil(k2))
    j2 = i2 + int(np.argmax(np.diff(s2[i2:]) < 0))
    out["second_overshoot_deg"] = s2[j2] - heading_deg
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--termid", required=True)
    ap.add_argument("--model", default="models/mmg_kvlcc2.toml")
    ap.add_argument("--work", default="benches/peers/work/mmg")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    cases = [("turning:35", None), ("turning:-35", None), ("turning:20", None), ("turning:-20", None),
             ("zigzag:10/10", 10.0), ("zigzag:20/20", 20.0)]
    from importlib.metadata import version
    print(f"# termid's MMG model file ({a.model}) against shipmmg {version('shipmmg')}\n")
    print("Same rudder and propeller series, same initial state; both trajectories measured here.\n")
    print("| manoeuvre | quantity | termid | shipmmg | difference |")
    print("|---|---|---:|---:|---:|")
    worst = {"turning": 0.0, "zigzag": 0.0}
    for manoeuvre, heading in cases:
        path = os.path.join(a.work, manoeuvre.replace(":", "_").replace("/", "_") + ".csv")
        subprocess.run([a.termid, "simulate", "--model", a.model, "-m", manoeuvre, "--integrator", "rk4",
                        "--dt", "0.01", "--sample", "0.01", "--out", path], check=True,
                       stdout=subprocess.DEVNULL)
        ours = read_run(path)
        theirs = shipmmg_run(ours["t"], ours["delta"], ours["n"])
        if heading is None:
            m1, m2 = turning_metrics(ours), turning_metrics(theirs)
            for q in m1:
                rel = 100 * (m1[q] / m2[q] - 1)
                worst["turning"] = max(worst["turning"], abs(rel))
                print(f"| {manoeuvre} | {q} | {m1[q]:.3f} | {m2[q]:.3f} | {rel:+.3f} % |")
        else:
            m1, m2 = zigzag_metrics(ours, heading), zigzag_metrics(theirs, heading)
            for q in m1:
                diff = m1[q] - m2[q]
                worst["zigzag"] = max(worst["zigzag"], abs(diff))
                print(f"| {manoeuvre} | {q} | {m1[q]:.3f} | {m2[q]:.3f} | {diff:+.3f}° |")
        dpsi = np.degrees(np.max(np.abs(ours["psi"] - theirs["psi"])))
        dpos = np.max(np.hypot(ours["x"] - theirs["x"], ours["y"] - theirs["y"]))
        print(f"| {manoeuvre} | largest gap over the run | ψ {dpsi:.3f}° | position {dpos:.3f} m | |")
    print(f"\nlargest turning difference {worst['turning']:.3f} % (target 0.5 %), "
          f"largest overshoot difference {worst['zigzag']:.3f}° (target 0.2°)")
    return 0 if worst["turning"] <= 0.5 and worst["zigzag"] <= 0.2 else 1


if __name__ == "__main__":
    sys.exit(main())
