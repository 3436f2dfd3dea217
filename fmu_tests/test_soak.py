"""Issue 5, soak: random commands and stopper motion through FMPy for JETPIPE_SOAK_SECONDS simulated
seconds (default 60 in CI; 3600 for the full hour), 10 ms communication steps, prints its figures.

1. Sealed chambers (the four orifice areas scaled by 0, C_db_A_lpp = C_dm_A_lpp = 0; C_d itself
   must be > 0): no air enters or leaves a chamber, so P_i * V_i^gamma must stay at its initial
   value whatever the stopper does (jumps and ramps through fmi2SetRealInputDerivatives). The drift
   of that invariant is the mass-balance check: it must stay within 100 x the integrator tolerance
   (1e-6) over the whole run.
2. Normal parameters: outputs always finite; with the stopper moving the pressures may leave
   [P_r, P_s] (adiabatic compression), so they are checked against the adiabatic bound
   P_r * (V_min/V_max)^gamma <= P <= P_s * (V_max/V_min)^gamma over the stopper range used.
"""

import math
import os
import time

import numpy as np
import pytest

from jetpipe_fmu import initialize

SOAK_SECONDS = float(os.environ.get("JETPIPE_SOAK_SECONDS", "60"))
STEP = 0.01
X_LO, X_HI = 0.035, 0.085  # stopper range used (valid 0.026 < x_s < 0.096)
# No flow through the valve (its four orifice areas C_d A times 0) nor past the piston.
SEALED = {
    "supply_area_scale_1": 0.0,
    "supply_area_scale_2": 0.0,
    "return_area_scale_1": 0.0,
    "return_area_scale_2": 0.0,
    "C_db_A_lpp": 0.0,
    "C_dm_A_lpp": 0.0,
}


def volumes(x_s, p):
    A_p = math.pi * p["D_cyl"] ** 2 / 4
    # from docs/model.md (Chambers): V1 = A_p (x_s - 0.026), V2 = A_p (0.070 - (x_s - 0.026)) with the defaults
    lo = p["L_s"] + p["L_p"] + p["L_sup"]  # 0.026 m: the stopper's lower limit
    stroke = p["L_cyl"] - p["L_p"]  # 0.070 m
    return A_p * (x_s - lo), A_p * (stroke - (x_s - lo))


def soak(fmu, vrs, seconds, seed, check):
    """Random command every 50 ms, stopper jumps or ramps every 20-200 ms; check(t, y, x_s) per step."""
    rng = np.random.default_rng(seed)
    n = int(round(seconds / STEP))
    t, v, x = 0.0, 2.5, 0.054
    next_cmd, next_stop = 0, 0
    rate = 0.0
    out = [vrs[k] for k in ("F_act", "P1", "P2", "i", "x_jp")]
    for k in range(n):
        if k >= next_cmd:
            v = float(rng.uniform(-2.0, 10.0))
            fmu.setReal([vrs["v_DA"]], [v])
            next_cmd = k + 5
        if k >= next_stop:
            if rng.random() < 0.5:
                x = float(rng.uniform(X_LO, X_HI))  # a jump
                fmu.setReal([vrs["x_s"]], [x])
                rate = 0.0
            else:  # a ramp over the coming steps, staying inside [X_LO, X_HI]
                target = float(rng.uniform(X_LO, X_HI))
                rate = (target - x) / (STEP * int(rng.integers(2, 20)))
            next_stop = k + int(rng.integers(2, 20))
        if rate != 0.0:
            if not (X_LO <= x + rate * STEP <= X_HI):
                rate = 0.0
            fmu.setRealInputDerivatives([vrs["x_s"]], [1], [rate])
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=STEP)
        t = (k + 1) * STEP
        x = x + rate * STEP
        y = fmu.getReal(out)
        check(t, y, fmu.getReal([vrs["x_s"]])[0])
    return n


def test_soak_sealed_chambers_conserve_air(init_fmu, vrs, defaults):
    p = dict(defaults)
    gamma = p["gamma"]
    fmu = init_fmu(inputs=(2.5, 0.054), parameters=SEALED,
                   tolerance=1e-6)
    P1, P2 = fmu.getReal([vrs["P1"], vrs["P2"]])
    V1, V2 = volumes(0.054, p)
    inv0 = (P1 * V1 ** gamma, P2 * V2 ** gamma)
    worst = [0.0, 0.0]

    def check(t, y, x_s):
        assert all(math.isfinite(v) for v in y), f"non-finite output at t = {t}: {y}"
        v1, v2 = volumes(x_s, p)
        for i, (P, V) in enumerate(((y[1], v1), (y[2], v2))):
            drift = abs(P * V ** gamma / inv0[i] - 1.0)
            worst[i] = max(worst[i], drift)
            assert drift < 1e-4, f"chamber {i + 1}: P*V^gamma drifted by {drift:.2e} at t = {t} (x_s = {x_s})"

    t0 = time.perf_counter()
    n = soak(fmu, vrs, SOAK_SECONDS, 20240613, check)
    wall = time.perf_counter() - t0
    print(f"sealed soak: {SOAK_SECONDS:g} s simulated, {n} steps of {STEP} s, wall {wall:.1f} s; "
          f"max relative drift of P*V^gamma: chamber 1 {worst[0]:.2e}, chamber 2 {worst[1]:.2e}")


def test_soak_normal_parameters(init_fmu, vrs, defaults):
    p = dict(defaults)
    gamma = p["gamma"]
    fmu = init_fmu(inputs=(2.5, 0.054), tolerance=1e-6)
    v_lo = min(min(volumes(X_LO, p)), min(volumes(X_HI, p)))
    v_hi = max(max(volumes(X_LO, p)), max(volumes(X_HI, p)))
    ratio = (v_hi / v_lo) ** gamma
    lo, hi = p["P_r"] / ratio, p["P_s"] * ratio
    stats = {"min_P": math.inf, "max_P": -math.inf, "outside_supply_return": 0}

    def check(t, y, x_s):
        assert all(math.isfinite(v) for v in y), f"non-finite output at t = {t}: {y}"
        for P in (y[1], y[2]):
            assert lo <= P <= hi, f"pressure {P} Pa outside the adiabatic bound [{lo:.4g}, {hi:.4g}] at t = {t}"
            stats["min_P"] = min(stats["min_P"], P)
            stats["max_P"] = max(stats["max_P"], P)
            if not (p["P_r"] <= P <= p["P_s"]):
                stats["outside_supply_return"] += 1

    t0 = time.perf_counter()
    n = soak(fmu, vrs, SOAK_SECONDS, 7, check)
    wall = time.perf_counter() - t0
    print(f"normal soak: {SOAK_SECONDS:g} s simulated, {n} steps, wall {wall:.1f} s; pressures in "
          f"[{stats['min_P']:.6g}, {stats['max_P']:.6g}] Pa (adiabatic bound [{lo:.4g}, {hi:.4g}]); "
          f"{stats['outside_supply_return']} samples outside [P_r, P_s] (stopper compression)")
