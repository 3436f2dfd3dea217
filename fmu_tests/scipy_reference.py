"""A plain SciPy implementation of the thesis model (MODEL.md, no effects), for work–precision
comparisons with the Rust integrator (issue 6). Not a test: run it as a script.

    .venv/bin/python fmu_tests/scipy_reference.py [--seconds 1.0]

It integrates the six-state model (4.1) with solve_ivp (LSODA and Radau) over the first
seconds of the standard scenario (inputs held every 10 ms, restarting at each change),
measures the force error against a tight-tolerance run of `jetpipe simulate`, and prints
error and CPU time per method and tolerance, next to the Rust integrator's.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenarios  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

# MODEL.md defaults
P_S, P_R, T, GAMMA, R = 652925.0, 101325.0, 293.15, 1.4, 287.0
K_CD, I_OFF, W_CD = 0.04, 0.0, 7050.0
K_M, W1, W2, Z2 = 1.946, 973.9, 1856.7, 0.019
X_SAT, F_SAT, X_OFF = 0.5e-3, 0.45, 0.099e-3
D_JP, C_D, C_DM, C_DB = 0.9652e-3, 0.696, -0.0475e-6, 0.0971e-6
L_CYL, L_P, L_S, L_SUP, L_SPRING0, D_CYL, K_SPRING = 0.078, 0.008, 0.007, 0.011, 0.0691, 0.015875, 88.14
A_P = math.pi * D_CYL ** 2 / 4
R_C = (2 / (GAMMA + 1)) ** (GAMMA / (GAMMA - 1))
C1 = math.sqrt(GAMMA / R * (2 / (GAMMA + 1)) ** ((GAMMA + 1) / (GAMMA - 1)))
C2 = math.sqrt(GAMMA / R * 2 / (GAMMA - 1))
BAND = 1e-5  # same regularisation as the Rust model (orifice_flow.rs)


def lens(r1, r2, d):
    d = abs(d)
    if d >= r1 + r2:
        return 0.0
    if d <= abs(r1 - r2):
        return math.pi * min(r1, r2) ** 2
    kite = (-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2)
    h = 0.5 * math.sqrt(max(kite, 0.0)) / d
    a1 = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    a2 = d - a1
    return r1 * r1 * math.atan2(h, a1) - a1 * h + r2 * r2 * math.atan2(h, a2) - a2 * h


def f2(r):
    return math.sqrt(max(r ** (2 / GAMMA) - r ** ((GAMMA + 1) / GAMMA), 0.0))


F2_EDGE = f2(1 - BAND)


def flow(cda, p_from, p_to):
    sign = 1.0
    pu, pd = p_from, p_to
    if pd > pu:
        pu, pd, sign = p_to, p_from, -1.0
    if pu <= 0 or cda == 0:
        return 0.0
    r = pd / pu
    scale = cda * pu / math.sqrt(T)
    if r <= R_C:
        return sign * scale * C1
    s = (1 - r) / BAND
    g = f2(r) if s >= 1 else F2_EDGE * (1.25 * max(s, 0) - 0.25 * max(s, 0) ** 3)
    return sign * scale * C2 * g


def rhs(_t, y, v_da, x_s):
    i, x, xd, xdd, p1, p2 = y
    r = D_JP / 2
    x_bar = X_SAT * math.tanh(K_M * i / F_SAT)
    c2 = 2 * Z2 * W2 + W1
    c3 = W2 * W2 + 2 * Z2 * W1 * W2
    c4 = W1 * W2 * W2
    xa = x + X_OFF
    a_jp = math.pi * r * r
    a_s1 = lens(r, r, xa - D_JP)
    a_s2 = lens(r, r, -xa - D_JP)
    a_r1 = max(a_jp - lens(r, 3 * r, xa - D_JP), 0.0)
    a_r2 = max(a_jp - lens(r, 3 * r, -xa - D_JP), 0.0)
    pu, pd = max(p1, p2), min(p1, p2)
    leak_area = max(C_DM * pd / pu + C_DB, 0.0) if pu > 0 else 0.0
    m_lpp = flow(leak_area, p1, p2)
    m1 = flow(C_D * a_s1, P_S, p1) - flow(C_D * a_r1, p1, P_R) - m_lpp
    m2 = flow(C_D * a_s2, P_S, p2) - flow(C_D * a_r2, p2, P_R) + m_lpp
    x_p = x_s - (L_P + L_S + L_SUP)
    v1, v2 = A_P * x_p, A_P * (L_CYL - x_p - L_P)
    return [
        W_CD * (K_CD * v_da + I_OFF - i),
        xd,
        xdd,
        c4 * (x_bar - x) - c2 * xdd - c3 * xd,
        GAMMA / v1 * R * T * m1,
        GAMMA / v2 * R * T * m2,
    ]


def force(y, x_s):
    spring = K_SPRING * (L_SPRING0 - (x_s - L_S - L_P))
    return max(A_P * (y[4] - y[5]), spring)


def run(method, rtol, seconds, y0):
    y = np.array(y0, dtype=float)
    forces = [force(y, scenarios.held_input(0.0)[1])]
    previous_x = scenarios.held_input(0.0)[1]
    evaluations = 0
    started = time.process_time()
    for k in range(int(round(seconds / 0.01))):
        v, x = scenarios.held_input(0.01 * k)
        # a stopper jump between samples conserves the air: P V^gamma constant
        if x != previous_x:
            xp0, xp1 = previous_x - (L_P + L_S + L_SUP), x - (L_P + L_S + L_SUP)
            y[4] *= (xp0 / xp1) ** GAMMA
            y[5] *= ((L_CYL - xp0 - L_P) / (L_CYL - xp1 - L_P)) ** GAMMA
            previous_x = x
        atol = rtol * np.array([0.1, 1e-4, 1e-4 * W2, 1e-4 * W2 * W2, 1e5, 1e5])
        sol = solve_ivp(rhs, (0.01 * k, 0.01 * (k + 1)), y, method=method, rtol=rtol, atol=atol, args=(v, x))
        if not sol.success:
            raise RuntimeError(f"{method} failed at t = {0.01 * k}: {sol.message}")
        evaluations += sol.nfev
        y = sol.y[:, -1]
        forces.append(force(y, x))
    return np.array(forces), time.process_time() - started, evaluations


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=1.0)
    args = parser.parse_args()
    jetpipe = ROOT / "target" / "release" / "jetpipe"
    with tempfile.TemporaryDirectory() as tmp:
        ref_csv = Path(tmp) / "reference.csv"
        subprocess.run([str(jetpipe), "simulate", "--tolerance", "1e-10", "--step", "1e-4", "--csv", str(ref_csv)],
                       check=True, capture_output=True)
        reference = np.loadtxt(ref_csv, delimiter=",", skiprows=1)
        n = int(round(args.seconds / 0.01)) + 1
        ref_force = reference[:n, 1]
        # the same equilibrium start as the FMU: take it from the reference's first row
        y0 = [reference[0, 4], reference[0, 5], 0.0, 0.0, reference[0, 2], reference[0, 3]]
        print(f"first {args.seconds} s of the standard scenario; error = max |F - F_ref| at 10 ms instants")
        for rtol in (1e-4, 1e-6):
            out = subprocess.run([str(jetpipe), "simulate", "--tolerance", str(rtol), "--csv", str(Path(tmp) / "r.csv")],
                                 check=True, capture_output=True, text=True).stdout
            rust = np.loadtxt(Path(tmp) / "r.csv", delimiter=",", skiprows=1)[:n, 1]
            line = next(l for l in out.splitlines() if "work:" in l)
            print(f"  rust SDIRK4 split   rtol {rtol:.0e}: error {np.max(np.abs(rust - ref_force)):.2e} N  ({line.strip()} for 10 s)")
            for method in ("LSODA", "Radau"):
                try:
                    f, cpu, nfev = run(method, rtol, args.seconds, y0)
                except RuntimeError as e:
                    print(f"  scipy {method:<6}        rtol {rtol:.0e}: failed: {e}")
                    continue
                print(f"  scipy {method:<6}        rtol {rtol:.0e}: error {np.max(np.abs(f - ref_force)):.2e} N, "
                      f"{cpu:.2f} s CPU for {args.seconds} s ({nfev} evaluations)")


if __name__ == "__main__":
    main()
