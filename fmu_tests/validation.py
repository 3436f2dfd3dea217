"""Scenarios of the thesis's chapters 3 and 4 run on the packaged FMU through FMPy (issue 3).

Shared by the tests (fmu_tests/test_validation_*.py) and the report generator
(fmu_tests/validation_report.py). Everything here drives dist/JetPipeActuator.fmu through FMI
(fmi2SetReal / fmi2SetRealInputDerivatives / fmi2DoStep / fmi2GetReal); the only other source of
numbers is the `jetpipe linearize` command of scenario 6.

Every scenario is a function `scenario_N(ctx, ...)` returning a dict: scalar results under their
names, arrays for the plots. The `fast` flag (tests) uses coarser grids than the report.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import fmpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from jetpipe_fmu import default_fmu_path, initialize, make_slave, release, vr_map  # noqa: E402
from scenarios import spring_force  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TWO_PI = 2.0 * math.pi

# Thesis values (MODEL.md, table "What the thesis reports, to reproduce").
THESIS = {
    "omega_cd": 7050.0,
    "f_cd_Hz": 1122.0,
    "omega_1": 973.9,
    "omega_2": 1856.7,
    "zeta_2": 0.019,
    "rise_s": 0.002,
    "settle5_s": 0.07,
    "poles_45N": [-7049.7, -973.9, complex(-35.3, 1856.3), -5.0, -14.5],
    "zero_45N": -7.1,
    "open_loop_corner_Hz": 2.3,
    "open_loop_bw_range_Hz": (0.8, 2.8),
    "F_rated": 111.25,
    "k_spring": 88.14,
    "k_p": 0.044,
    "k_static": 550.0,
    "cl_linear_Hz": 55.0,
    "cl_5N_Hz": 80.0,
    "cl_1N_Hz": 25.0,
}

PRESET_PATH = ROOT / "presets" / "thesis_measured.json"


def load_preset(path=PRESET_PATH) -> dict:
    """The FMU start values of a preset file (a JSON object of parameter names and numbers)."""
    with open(path) as f:
        return {name: float(value) for name, value in json.load(f).items()}


K_CD = 0.04  # A/V, default current driver gain
V_MAX = 10.0  # D/A range
F_SAMPLE = 500.0  # Hz, the thesis's controller rate (§4.1)
T_SAMPLE = 1.0 / F_SAMPLE


# --------------------------------------------------------------------------------------------
# FMU access
# --------------------------------------------------------------------------------------------


class FmuContext:
    """The FMU extracted once; `instance(...)` makes initialised instances.

    `preset` (a dict of FMU start values, e.g. presets/thesis_measured.json) is set in every
    instance before the scenario's own parameters, and `param`/`defaults` read it: every
    scenario then runs on the actuator with those values."""

    def __init__(self, path=None, preset=None):
        env = os.environ.get("JETPIPE_FMU")
        self.path = Path(path or env or default_fmu_path()).resolve()
        if not self.path.is_file():
            raise FileNotFoundError(f"FMU not found at {self.path}: run `cargo run --release --bin jetpipe -- package`")
        self.model_description = fmpy.read_model_description(str(self.path))
        self._tmp = tempfile.mkdtemp(prefix="jetpipe_validation_")
        self.unzipdir = fmpy.extract(str(self.path), self._tmp)
        self.vrs = vr_map(self.model_description)
        self.defaults = {
            v.name: float(v.start)
            for v in self.model_description.modelVariables
            if v.causality == "parameter" and v.type == "Real"
        }
        self.preset = dict(preset or {})
        unknown = sorted(set(self.preset) - set(self.defaults))
        if unknown:
            raise ValueError(f"preset names no real parameter of the FMU: {unknown}")
        self.defaults.update({k: float(v) for k, v in self.preset.items()})
        self.live = []

    def instance(self, v_DA=0.0, x_s=0.054, parameters=None, booleans=None, tolerance=None) -> "Plant":
        fmu = make_slave(self.unzipdir, self.model_description)
        plant = Plant(self, fmu)
        self.live.append(plant)
        merged = dict(self.preset, **(parameters or {}))
        initialize(fmu, self.vrs, inputs=(v_DA, x_s), parameters=merged, booleans=booleans, tolerance=tolerance)
        plant.v_DA, plant.x_s = float(v_DA), float(x_s)
        return plant

    def param(self, name, parameters=None):
        return float((parameters or {}).get(name, self.defaults[name]))

    def close(self):
        for p in self.live:
            p.close()
        self.live = []
        shutil.rmtree(self._tmp, ignore_errors=True)


class Plant:
    """One initialised FMU instance stepped by a Python master."""

    def __init__(self, ctx: FmuContext, fmu):
        self.ctx, self.fmu, self.vrs = ctx, fmu, ctx.vrs
        self.t = 0.0
        self.v_DA = 0.0
        self.x_s = 0.054

    def get(self, *names):
        vals = self.fmu.getReal([self.vrs[n] for n in names])
        return vals[0] if len(names) == 1 else tuple(vals)

    def set_inputs(self, v_DA=None, x_s=None):
        names, vals = [], []
        if v_DA is not None:
            self.v_DA = float(v_DA)
            names.append("v_DA")
            vals.append(self.v_DA)
        if x_s is not None:
            self.x_s = float(x_s)
            names.append("x_s")
            vals.append(self.x_s)
        if names:
            self.fmu.setReal([self.vrs[n] for n in names], vals)

    def step(self, h, v_DA=None, x_s=None, dv=None, dx=None):
        """Set the inputs (held, or moving linearly with slope dv/dx over this step) and doStep."""
        self.set_inputs(v_DA, x_s)
        names, rates = [], []
        if dv is not None:
            names.append("v_DA")
            rates.append(float(dv))
        if dx is not None:
            names.append("x_s")
            rates.append(float(dx))
        if names:
            self.fmu.setRealInputDerivatives([self.vrs[n] for n in names], [1] * len(names), rates)
        self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=h)
        self.t += h
        if dv is not None:
            self.v_DA += dv * h
        if dx is not None:
            self.x_s += dx * h

    def close(self):
        release(self.fmu)


def v_for_current(i_cmd, i_offset=0.0, k_cd=K_CD):
    """D/A voltage for a commanded current, clipped to the D/A range."""
    return float(np.clip((i_cmd - i_offset) / k_cd, -V_MAX, V_MAX))


# --------------------------------------------------------------------------------------------
# Signal helpers
# --------------------------------------------------------------------------------------------


def phasor(t, y, f):
    """Complex amplitude A of y ≈ c + Re(A exp(j 2π f t)), least squares over the samples."""
    w = TWO_PI * f
    M = np.column_stack([np.ones_like(t), np.cos(w * t), -np.sin(w * t)])
    c, re, im = np.linalg.lstsq(M, y, rcond=None)[0]
    return complex(re, im), c


def sine_dwell(plant, f, mean, amp, outputs, settle, periods=3, per_period=64, h_max=None, drive="v_DA"):
    """Drive v_DA = mean + amp sin(2π f t) (held over each step at its mid-step value), wait
    `settle` seconds rounded up to whole periods, then record `periods` periods.

    Returns {name: phasor} for the outputs and for the drive, plus the records themselves.
    """
    T = 1.0 / f
    n = per_period
    if h_max is not None:
        n = max(n, int(math.ceil(T / h_max)))
    h = T / n
    n_settle = int(math.ceil(settle / T)) * n
    n_rec = periods * n
    t0 = plant.t
    w = TWO_PI * f
    rec_t, rec = [], []
    u = lambda tt: mean + amp * math.sin(w * (tt - t0))  # noqa: E731
    for k in range(n_settle + n_rec):
        ta, tb = t0 + k * h, t0 + (k + 1) * h
        # Mid-step hold, not fmi2SetRealInputDerivatives: a v_DA rate makes the FMU's steps ~100x slower.
        plant.step(h, v_DA=u(0.5 * (ta + tb)))
        if k >= n_settle - 1:
            rec_t.append(tb - t0)
            rec.append(plant.get(*outputs) if len(outputs) > 1 else (plant.get(*outputs),))
    rec_t = np.array(rec_t[1:])  # one full record of `periods` periods (drop the duplicate end point)
    arr = np.array(rec[1:])
    out = {"t": rec_t}
    for j, name in enumerate(outputs):
        out[name] = phasor(rec_t, arr[:, j], f)[0]
        out[name + "_rec"] = arr[:, j]
    out["drive"] = complex(0.0, -amp)  # amp sin(wt) = Re(-j amp e^{jwt})
    return out


def crossing_3db(freqs, mag_db, ref_db):
    """First frequency (log-interpolated) where mag_db falls 3 dB below ref_db; nan if never."""
    target = ref_db - 3.0103
    for k in range(1, len(freqs)):
        if mag_db[k] < target <= mag_db[k - 1]:
            a = (mag_db[k - 1] - target) / (mag_db[k - 1] - mag_db[k])
            return float(math.exp(math.log(freqs[k - 1]) + a * (math.log(freqs[k]) - math.log(freqs[k - 1]))))
    return float("nan")


def db(x):
    return 20.0 * np.log10(np.abs(x))


# --------------------------------------------------------------------------------------------
# Scenario 1: current driver step and frequency response (§3.1.2, Fig. 3.2)
# --------------------------------------------------------------------------------------------


def scenario_1(ctx: FmuContext, fast=True):
    k_cd = ctx.defaults["k_cd"]
    # Step: v_DA 0 -> 1 V at t = 0, recorded every 5 µs over 2 ms.
    p = ctx.instance(v_DA=0.0)
    h = 5e-6
    ts, i_s = [0.0], [p.get("i")]
    for _ in range(400):
        p.step(h, v_DA=1.0)
        ts.append(p.t)
        i_s.append(p.get("i"))
    ts, i_s = np.array(ts), np.array(i_s)
    i_final = k_cd * 1.0
    # First-order fit: ln(1 - i/i_final) = -t/tau on the part above 1 % of the remaining error.
    frac = 1.0 - i_s / i_final
    mask = (frac > 0.01) & (ts > 0)
    slope = np.polyfit(ts[mask], np.log(frac[mask]), 1)[0]
    tau = -1.0 / slope
    model_first_order = i_final * (1.0 - np.exp(-ts / tau))
    fit_residual = float(np.max(np.abs(i_s - model_first_order)) / i_final)
    overshoot = float(np.max(i_s) / i_final - 1.0)
    # Frequency response I/V_DA by sine dwell (amplitude 1 V about 0).
    freqs = np.array([50, 200, 500, 800, 1122, 1500, 2500, 4000] if fast else np.geomspace(20, 5000, 25))
    resp = []
    for f in freqs:
        d = sine_dwell(p, f, 0.0, 1.0, ("i",), settle=5.0 / ctx.defaults["omega_cd"] * 4, periods=2, per_period=512)
        resp.append(d["i"] / d["drive"])
    resp = np.array(resp)
    mag = db(resp / k_cd)
    f_corner = crossing_3db(freqs, mag, 0.0)
    p.close()
    return {
        "t": ts, "i": i_s, "i_fit": model_first_order, "tau": tau, "f_corner_step_Hz": 1.0 / (TWO_PI * tau),
        "omega_step": 1.0 / tau, "fit_residual": fit_residual, "overshoot": overshoot,
        "freqs": freqs, "resp": resp, "f_corner_sweep_Hz": f_corner, "k_cd": k_cd,
    }


# --------------------------------------------------------------------------------------------
# Scenario 2: jet pipe step and frequency response (§3.2.3, Figs. 3.10, 3.11)
# --------------------------------------------------------------------------------------------


def third_order(s, K, w1, w2, z2):
    return K * w1 / (s + w1) * w2**2 / (s**2 + 2 * z2 * w2 * s + w2**2)


def fit_third_order(freqs, G):
    """Least squares on the complex response (relative error) for K, ω1, ω2, ζ2."""
    from scipy.optimize import least_squares

    s = 1j * TWO_PI * np.asarray(freqs)

    def res(p):
        K, w1, w2, z2 = p
        e = third_order(s, K, w1, w2, z2) / G - 1.0
        return np.concatenate([e.real, e.imag])

    K0 = abs(G[0])
    f_peak = freqs[int(np.argmax(np.abs(G)))]
    p0 = [K0, 600.0, TWO_PI * f_peak, 0.05]
    sol = least_squares(res, p0, x_scale=[K0, 100.0, 100.0, 0.01], xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return sol.x, float(np.sqrt(np.mean(sol.fun**2)))


def step_metrics(t, x, x0, x1):
    """10-90 % rise time and 5 % settling time of a step from x0 to x1 (time from the step at t=0)."""
    y = (x - x0) / (x1 - x0)
    t10 = t[np.argmax(y >= 0.1)]
    t90 = t[np.argmax(y >= 0.9)]
    outside = np.nonzero(np.abs(y - 1.0) > 0.05)[0]
    t_settle = t[outside[-1] + 1] if len(outside) else 0.0
    return float(t90 - t10), float(t_settle), float(np.max(y) - 1.0)


def linear_step_reference(d, t):
    """Unit step response of ω_cd/(s+ω_cd) · third-order jet pipe, with the FMU's parameters."""
    from scipy import signal

    wcd, w1, w2, z2 = d["omega_cd"], d["omega_1"], d["omega_2"], d["zeta_2"]
    den = np.polymul(np.polymul([1.0, wcd], [1.0, w1]), [1.0, 2 * z2 * w2, w2**2])
    _, y = signal.step(([wcd * w1 * w2**2], den), T=t)
    return y


def scenario_2(ctx: FmuContext, fast=True):
    d = ctx.defaults
    v_step = 0.5  # V: 20 mA, 0.039 N on the tip, tanh argument 0.087: linear to 0.25 %
    # Step response from rest.
    p = ctx.instance(v_DA=0.0)
    h = 2e-5
    ts, xs, is_ = [0.0], [p.get("x_jp")], [p.get("i")]
    for _ in range(int(round(0.15 / h))):
        p.step(h, v_DA=v_step)
        ts.append(p.t)
        x, i = p.get("x_jp", "i")
        xs.append(x)
        is_.append(i)
    ts, xs = np.array(ts), np.array(xs)
    x_final = d["x_jp_sat"] * math.tanh(d["k_m"] * d["k_cd"] * v_step / d["F_jp_sat"])
    if ctx.preset:
        # An effect between f3 and the dynamics (the hysteresis) moves the final value: the run's own.
        x_final = float(np.mean(xs[ts >= ts[-1] - 0.01]))
    rise, settle, overshoot = step_metrics(ts, xs, 0.0, x_final)
    t100 = float(ts[np.argmax(xs >= x_final)])  # first crossing of the final value (0-100 % rise)
    # The same step through the linear current driver + third-order jet pipe (thesis parameters).
    ref = linear_step_reference(d, ts) * x_final
    rise_ref, settle_ref, _ = step_metrics(ts, ref, 0.0, x_final)
    p.close()

    # Sine dwell of 0.25 V (10 mA) about 0; the ratio X_jp/I removes the current driver.
    if fast:
        freqs = np.array([20, 60, 120, 180, 230, 260, 280, 290, 295, 300, 310, 330, 380, 450, 550, 700.0])
    else:
        freqs = np.unique(np.concatenate([np.geomspace(10, 700, 30), np.linspace(270, 320, 21)]))
    p = ctx.instance(v_DA=0.0)
    G = []
    for f in freqs:
        r = sine_dwell(p, f, 0.0, 0.25, ("x_jp", "i"), settle=0.3, periods=4, per_period=256)
        G.append(r["x_jp"] / r["i"])
    p.close()
    G = np.array(G)
    (K, w1, w2, z2), rms = fit_third_order(freqs, G)
    K_expected = d["x_jp_sat"] * d["k_m"] / d["F_jp_sat"]  # slope of f3 at 0 times k_m
    return {
        "t": ts, "x_jp": xs, "i": np.array(is_), "x_final": x_final, "rise_s": rise, "settle5_s": settle,
        "rise100_s": t100, "x_ref": ref, "rise_ref_s": rise_ref, "settle5_ref_s": settle_ref,
        "rise100_ref_s": float(ts[np.argmax(ref >= x_final)]),
        "overshoot": overshoot, "freqs": freqs, "G": G, "K": K, "K_expected": K_expected,
        "omega_1": w1, "omega_2": w2, "zeta_2": z2, "fit_rms": rms,
    }


# --------------------------------------------------------------------------------------------
# Scenario 3: static force/current major loop at several stopper positions (§3.3.1, Fig. 3.13)
# --------------------------------------------------------------------------------------------


def piston_area(ctx, parameters=None):
    return math.pi * ctx.param("D_cyl", parameters) ** 2 / 4.0


def static_force(ctx, v_grid, x_s=0.054, parameters=None):
    """Equilibrium force (and P1, P2, i) for each v_DA: one initialisation per point."""
    rows = []
    for v in v_grid:
        p = ctx.instance(v_DA=float(v), x_s=x_s, parameters=parameters)
        rows.append(p.get("F_act", "P1", "P2", "i"))
        p.close()
        ctx.live.remove(p)
    a = np.array(rows)
    return {"v": np.asarray(v_grid, float), "F": a[:, 0], "P1": a[:, 1], "P2": a[:, 2], "i": a[:, 3]}


def ramp_loop(ctx, x_s, t_ramp, h=0.01, v_lo=-10.0, v_hi=10.0):
    """Slow triangle of v_DA: v_lo -> v_hi -> v_lo, each leg t_ramp seconds (linear inputs)."""
    p = ctx.instance(v_DA=v_lo, x_s=x_s)
    n = int(round(t_ramp / h))
    rate = (v_hi - v_lo) / t_ramp
    out = {"up": [], "down": []}
    for leg, sgn, v0 in (("up", 1.0, v_lo), ("down", -1.0, v_hi)):
        for k in range(n):
            p.step(h, v_DA=v0 + sgn * rate * (k + 0.5) * h)  # mid-step hold
            out[leg].append(p.get("i", "F_act", "x_jp"))
    p.close()
    return {leg: np.array(v) for leg, v in out.items()}


STOPPERS_3 = (0.040, 0.054, 0.070)


def scenario_3(ctx: FmuContext, fast=True):
    v_grid = np.linspace(-10, 10, 81 if fast else 201)
    t_ramp = 40.0
    res = {"x_s": STOPPERS_3, "static": {}, "ramp": {}, "t_ramp": t_ramp}
    for xs in STOPPERS_3:
        res["static"][xs] = static_force(ctx, v_grid, xs)
        res["ramp"][xs] = ramp_loop(ctx, xs, t_ramp)
    A_p = piston_area(ctx)
    res["A_p"] = A_p
    res["F_ideal"] = A_p * (ctx.defaults["P_s"] - ctx.defaults["P_r"])
    res["F_max"] = {xs: float(res["static"][xs]["F"].max()) for xs in STOPPERS_3}
    res["floor"] = {xs: float(res["static"][xs]["F"].min()) for xs in STOPPERS_3}
    res["spring"] = {xs: float(spring_force(xs)) for xs in STOPPERS_3}
    # Without leakage past the piston the chambers reach supply and return pressure.
    no_leak = {"C_db_A_lpp": 0.0, "C_dm_A_lpp": 0.0}
    res["F_max_no_leak"] = float(static_force(ctx, [10.0], 0.054, no_leak)["F"][0])
    # Static slope dF/di about 45 N (the k of §4.2.1).
    s = res["static"][0.054]
    res["k_static_45N"] = float(np.interp(45.0, s["F"][40:], np.gradient(s["F"], s["i"])[40:]))
    res["loops"] = loop_separations(res["ramp"][0.054])
    return res


def loop_separations(ramp):
    """Separations of the falling and rising branches of a slow ramp (columns i, F_act, x_jp):
    the jet pipe's at i = 0 (m), and the current between the branches at 45 N (A)."""
    up, down = ramp["up"], ramp["down"]
    x_up = float(np.interp(0.0, up[:, 0], up[:, 2]))
    x_down = float(np.interp(0.0, down[::-1, 0], down[::-1, 2]))

    def current_at(branch, F):
        k = int(np.nonzero(branch[:, 1] > branch[:, 1].min() + 1e-6)[0][0])  # above the spring floor
        Fs, i_s = branch[k:, 1], branch[k:, 0]
        order = np.argsort(Fs)
        return float(np.interp(F, Fs[order], i_s[order]))

    return {"x_jp_m": x_down - x_up, "i_at_45N_A": current_at(up, 45.0) - current_at(down[::-1], 45.0)}


# --------------------------------------------------------------------------------------------
# Scenario 4: unpressurised rod force = spring law (§3.3.1)
# --------------------------------------------------------------------------------------------


# Beyond x_s = L_spring0 + L_s + L_p = 84.1 mm the spring law (2.37) turns negative: the spring is
# free and the unpressurised force is max(0, F_spring) by (2.36).
SPRING_FREE_X_S = 0.0691 + 0.007 + 0.008


def scenario_4(ctx: FmuContext, fast=True):
    unpress = {"P_s": 101325.0, "P_r": 101325.0}
    xs_grid = np.linspace(0.030, 0.090, 13 if fast else 61)
    rows = []
    for xs in xs_grid:
        for v in (-10.0, 0.0, 10.0):
            p = ctx.instance(v_DA=v, x_s=xs, parameters=unpress)
            rows.append((xs, v) + p.get("F_act", "P1", "P2"))
            p.close()
            ctx.live.remove(p)
    grid = np.array(rows)
    # Slow stopper strokes 30 -> 80 mm in 5 s and back, centred (0 V) and fully deflected (10 V) jet pipe.
    moving = []
    h, rate = 0.01, 0.010  # m/s
    for v in (0.0, 10.0):
        p = ctx.instance(v_DA=v, x_s=0.030, parameters=unpress)
        for leg in (1.0, -1.0):
            for _ in range(500):
                p.step(h, dx=leg * rate)
                moving.append((p.x_s, v) + p.get("F_act", "P1", "P2"))
        p.close()
        ctx.live.remove(p)
    moving = np.array(moving)
    compressed = grid[:, 0] < SPRING_FREE_X_S
    slope = np.polyfit(grid[compressed, 0], grid[compressed, 2], 1)[0]
    return {"grid": grid, "moving": moving, "slope": float(-slope), "xs_grid": xs_grid, "P_atm": unpress["P_r"]}


# --------------------------------------------------------------------------------------------
# Scenario 5: open-loop force/current frequency response at 54 mm (§3.3.2, Figs. 3.15, 3.16)
# --------------------------------------------------------------------------------------------

MEANS_5 = (0.03, 0.05, 0.07, 0.09)  # A, at amplitude 0.01 A
AMPS_5 = (0.005, 0.01, 0.02, 0.04)  # A, at mean 0.05 A


def open_loop_response(ctx, i_mean, i_amp, freqs, x_s=0.054):
    p = ctx.instance(v_DA=i_mean / K_CD, x_s=x_s)
    H = []
    for f in freqs:
        r = sine_dwell(p, f, i_mean / K_CD, i_amp / K_CD, ("F_act", "i"), settle=max(2.0, 1.0 / f), periods=2,
                       per_period=100)
        H.append(r["F_act"] / r["i"])
    p.close()
    ctx.live.remove(p)
    H = np.array(H)
    mag = db(H)
    return {"H": H, "bw_Hz": crossing_3db(freqs, mag, mag[0])}


def scenario_5(ctx: FmuContext, fast=True):
    freqs = np.geomspace(0.05, 20.0, 12 if fast else 30)
    res = {"freqs": freqs, "means": {}, "amps": {}}
    for m in MEANS_5:
        res["means"][m] = open_loop_response(ctx, m, 0.01, freqs)
    for a in AMPS_5:
        res["amps"][a] = open_loop_response(ctx, 0.05, a, freqs)
    # The static force at each mean (what a reader of Fig. 3.15 would call the operating point).
    res["F_mean"] = {m: float(static_force(ctx, [m / K_CD])["F"][0]) for m in MEANS_5}
    return res


# --------------------------------------------------------------------------------------------
# Scenario 6: linearisation (§4.2.2, Table 4.1, Fig. 4.12)
# --------------------------------------------------------------------------------------------

FORCES_6 = (20.0, 45.0, 80.0)


def jetpipe_cli():
    if os.environ.get("JETPIPE_CLI"):
        return [os.environ["JETPIPE_CLI"]]
    exe = ROOT / "target" / "release" / "jetpipe"
    if exe.is_file():
        return [str(exe)]
    return ["cargo", "run", "--quiet", "--release", "--bin", "jetpipe", "--"]


def linearize(force=45.0, x_s=0.054):
    """`jetpipe linearize --force F --x-s X --json`, parsed; poles/zeros as complex arrays."""
    out = subprocess.run(jetpipe_cli() + ["linearize", "--force", repr(force), "--x-s", repr(x_s), "--json"],
                         cwd=ROOT, check=True, capture_output=True, text=True).stdout
    d = json.loads(out)
    d["poles_c"] = np.array([complex(re, im) for re, im in d["poles"]])
    d["zeros_c"] = np.array([complex(re, im) for re, im in d["zeros"]])
    for k in ("A", "B", "C", "D"):
        d[k] = np.array(d[k], dtype=float)
    return d


def chamber_lengths(ctx, x_s, parameters=None):
    """V1/A_p and V2/A_p from (2.30)-(2.32)."""
    g = lambda n: ctx.param(n, parameters)  # noqa: E731
    x_p = x_s - (g("L_p") + g("L_s") + g("L_sup"))
    return x_p, g("L_cyl") - x_p - g("L_p")


def fluid_analysis(ctx, lin, x_s):
    """Fluid block of A: chamber rates r_i = -A_ii, the volume-free products κ_i = r_i V_i/A_p,
    the two fluid poles and which chamber's pressure dominates each pole's eigenvector."""
    J = lin["A"][4:6, 4:6]
    L1, L2 = chamber_lengths(ctx, x_s)
    w, v = np.linalg.eig(J)
    order = np.argsort(np.abs(w.real))
    w, v = w[order].real, v[:, order]
    dominant = [1 if abs(v[0, k]) > abs(v[1, k]) else 2 for k in range(2)]
    zeros = np.sort(lin["zeros_c"].real)[::-1]
    z = float(zeros[0]) if len(zeros) else float("nan")
    # Thesis's definition (§4.2.2): the zero cancels the nearer fluid pole; the other sets the corner.
    near = int(np.argmin(np.abs(w - z)))
    remaining = float(w[1 - near])
    return {
        "J": J, "r1": -J[0, 0], "r2": -J[1, 1], "kappa1": -J[0, 0] * L1, "kappa2": -J[1, 1] * L2, "L1": L1, "L2": L2,
        "slow": float(w[0]), "fast": float(w[1]), "dominant": dominant, "zero": z,
        "remaining_pole": remaining, "bw_remaining_Hz": abs(remaining) / TWO_PI, "bw_3dB_Hz": lin["bandwidth_Hz"],
    }


def fluid_jacobian_fmu(ctx, v_DA, x_s, P1, P2, parameters=None, dP=200.0, h=1e-6):
    """The 2x2 fluid Jacobian of the FMU by finite differences through FMI: start instances with
    start_at_equilibrium = false at (P1 ± dP, P2) and (P1, P2 ± dP), take one step of h and read
    the pressure rates. Used with parameters the CLI cannot change (e.g. L_cyl)."""
    J = np.zeros((2, 2))
    for j in range(2):
        rates = []
        for sgn in (1.0, -1.0):
            P = [P1, P2]
            P[j] += sgn * dP
            par = dict(parameters or {}, P1_start=P[0], P2_start=P[1])
            p = ctx.instance(v_DA=v_DA, x_s=x_s, parameters=par, booleans={"start_at_equilibrium": False})
            p.step(h)
            q = p.get("P1", "P2")
            rates.append(((q[0] - P[0]) / h, (q[1] - P[1]) / h))
            p.close()
            ctx.live.remove(p)
        J[:, j] = (np.array(rates[0]) - np.array(rates[1])) / (2 * dP)
    return J


def scenario_6(ctx: FmuContext, fast=True):
    res = {"lin45": linearize(45.0, 0.054)}
    res["fluid45"] = fluid_analysis(ctx, res["lin45"], 0.054)
    xs_grid = np.round(np.linspace(0.030, 0.090, 7 if fast else 25), 4)
    res["xs_grid"] = xs_grid
    res["grid"] = {}
    for F in FORCES_6:
        for xs in xs_grid:
            res["grid"][(F, float(xs))] = fluid_analysis(ctx, linearize(F, float(xs)), float(xs))
    # One volume at a time: L_cyl changes V2 only (FMU Jacobian by finite differences), at 80 N, 54 mm.
    op = linearize(80.0, 0.054)["operating_point"]
    res["op80"] = op
    res["L_cyl"] = {}
    for L in (0.070, 0.078, 0.090):
        par = {"L_cyl": L}
        J = fluid_jacobian_fmu(ctx, op["v_DA"], 0.054, op["P1"], op["P2"], par)
        ev = np.sort(np.linalg.eigvals(J).real)[::-1]
        res["L_cyl"][L] = {"J": J, "slow": float(ev[0]), "fast": float(ev[1]),
                           "L2": chamber_lengths(ctx, 0.054, par)[1]}
    return res


# --------------------------------------------------------------------------------------------
# Scenarios 7 and 8: digital force control with the 500 Hz controller as co-simulation master
# --------------------------------------------------------------------------------------------

K_P = 0.044  # A/N (§4.1.1)


class InverseStatic:
    """f^{-1} of (4.2): current for a static force, from the FMU's own equilibria at 54 mm."""

    def __init__(self, ctx, x_s=0.054, n=241):
        s = static_force(ctx, np.linspace(-2.0, 10.0, n), x_s)
        # The branch above the spring floor, where F(i) is strictly increasing.
        start = int(np.nonzero(s["F"] > s["F"].min() + 1e-6)[0][0])
        self.F, self.i = s["F"][start:], s["i"][start:]
        assert np.all(np.diff(self.F) > 0)

    def __call__(self, F):
        return float(np.interp(F, self.F, self.i))

    def slope(self, F):
        """dF/di of the static curve at force F."""
        return float(np.interp(F, self.F, np.gradient(self.F, self.i)))


def run_controller(ctx, Fd, t_end, x_s=0.054, k_p=K_P, ff=None, warmup=2.0, record_from=0.0):
    """Force control at 500 Hz: at each tick t_k read F_act, set v_DA = i_cmd/k_cd (clipped) with
    i_cmd = k_p (F_d(t_k) - F_act) [+ f^{-1}(F_d(t_k))], hold it for 2 ms (doStep).
    The run starts `warmup` seconds earlier with F_d held at F_d(0). Returns the ticks from record_from."""
    F0 = Fd(0.0)
    v0 = (ff(F0) if ff else 0.0) / K_CD
    p = ctx.instance(v_DA=v0, x_s=x_s)
    n_w = int(round(warmup / T_SAMPLE))
    n = int(round(t_end / T_SAMPLE))
    rec = []
    for k in range(-n_w, n):
        t = k * T_SAMPLE
        fd = Fd(max(t, 0.0))
        F = p.get("F_act")
        i_cmd = k_p * (fd - F) + (ff(fd) if ff else 0.0)
        v = v_for_current(i_cmd)
        if t >= record_from - 1e-12:
            rec.append((t, fd, F, i_cmd, v))
        p.step(T_SAMPLE, v_DA=v)
    p.close()
    ctx.live.remove(p)
    a = np.array(rec)
    return {"t": a[:, 0], "Fd": a[:, 1], "F": a[:, 2], "i_cmd": a[:, 3], "v": a[:, 4]}


def closed_loop_point(ctx, f, amp, mean=45.0, x_s=0.054, ff=None):
    """Sine dwell of F_d = mean + amp sin(2π f t): phasor ratio F/F_d at the sample instants."""
    settle = max(0.6, 3.0 / f)
    rec_len = max(0.4, 4.0 / f)
    Fd = lambda t: mean + amp * math.sin(TWO_PI * f * t)  # noqa: E731
    r = run_controller(ctx, Fd, settle + rec_len, x_s=x_s, ff=ff, warmup=1.0, record_from=settle)
    a_F, c_F = phasor(r["t"], r["F"], f)
    a_d, _ = phasor(r["t"], r["Fd"], f)
    return a_F / a_d, c_F - mean


def linear_closed_loop(lin, freqs, k_p=K_P, k_cd=K_CD, ts=T_SAMPLE):
    """Closed loop of the linearised plant F/v_DA (ZOH at 500 Hz) with i_cmd = k_p (F_d - F)."""
    from scipy import signal

    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((lin["A"], lin["B"], lin["C"], lin["D"]), ts, method="zoh")
    z = np.exp(1j * TWO_PI * np.asarray(freqs) * ts)
    n = Ad.shape[0]
    P = np.array([(Cd @ np.linalg.solve(zk * np.eye(n) - Ad, Bd))[0, 0] + Dd[0, 0] for zk in z])
    L = k_p / k_cd * P
    return L / (1 + L)


CL_CASES = ((1.0, 0.054), (5.0, 0.054), (1.0, 0.040), (5.0, 0.040))
CL_FREQS_FAST = np.array([1, 5, 10, 20, 30, 40, 50, 60, 70, 80, 100, 125, 160, 200.0])


def closed_loop_response(ctx, amp, x_s, freqs):
    """Sine dwells of the P loop at each frequency about 45 N; the -3 dB point relative to the
    lowest frequency's magnitude (bw_rel_Hz) and relative to 1 (bw_abs_Hz)."""
    H, off = zip(*[closed_loop_point(ctx, f, amp, x_s=x_s) for f in freqs])
    H = np.array(H)
    mag = db(H)
    return {"H": H, "offset": np.array(off), "bw_rel_Hz": crossing_3db(freqs, mag, mag[0]),
            "bw_abs_Hz": crossing_3db(freqs, mag, 0.0), "peak_dB": float(mag.max()), "low_dB": float(mag[0])}


def scenario_7(ctx: FmuContext, fast=True):
    inv = InverseStatic(ctx)
    res = {"inv": inv}
    # Tracking of 45 ± 20 N sines at 2, 5 and 20 Hz.
    res["track"] = {}
    for f in (2.0, 5.0, 20.0):
        Fd = lambda t, f=f: 45.0 + 20.0 * math.sin(TWO_PI * f * t)  # noqa: E731
        r = run_controller(ctx, Fd, 1.0)
        n_per = int(round(F_SAMPLE / f))
        last = slice(len(r["t"]) - n_per * int(max(1, f * 0.5)), None)  # whole periods of the last 0.5 s
        ratio = phasor(r["t"][last], r["F"][last], f)[0] / phasor(r["t"][last], r["Fd"][last], f)[0]
        r["offset"] = float(np.mean(r["F"][last] - r["Fd"][last]))
        r["gain"], r["phase_deg"] = abs(ratio), float(np.degrees(np.angle(ratio)))
        res["track"][f] = r
    # Predicted steady offset of the P controller at 45 N: k_p (45 - F) = f^{-1}(F).
    from scipy.optimize import brentq

    F_ss = brentq(lambda F: K_P * (45.0 - F) - inv(F), 30.0, 45.0)
    res["offset_predicted_45N"] = F_ss - 45.0
    # Closed-loop frequency response.
    freqs = (CL_FREQS_FAST if fast else np.unique(np.concatenate([np.geomspace(1, 220, 30), [25, 55, 80]])))
    res["freqs"] = freqs
    res["cl"] = {(amp, xs): closed_loop_response(ctx, amp, xs, freqs) for amp, xs in CL_CASES}
    # Linear estimates: §4.2.1 first-order formula and the full linearisation at 500 Hz.
    lin = linearize(45.0, 0.054)
    fa = fluid_analysis(ctx, lin, 0.054)
    k = inv.slope(45.0)
    res["k_static"] = k
    for name, a in (("remaining_pole", abs(fa["remaining_pole"])), ("bw_3dB", TWO_PI * fa["bw_3dB_Hz"])):
        res["wcl_" + name] = a * (1 + K_P * k) / TWO_PI
    res["wcl_thesis"] = 13.8 * (1 + 0.044 * 550) / TWO_PI
    fl = np.geomspace(0.5, 249, 300)
    res["lin_freqs"] = fl
    res["lin"] = {}
    for xs in (0.054, 0.040):
        Hl = linear_closed_loop(linearize(45.0, xs), fl)
        ml = db(Hl)
        res["lin"][xs] = {"H": Hl, "bw_rel_Hz": crossing_3db(fl, ml, ml[0]), "bw_abs_Hz": crossing_3db(fl, ml, 0.0)}
    return res


def square(f, lo=40.0, hi=50.0):
    return lambda t: hi if (t * f) % 1.0 < 0.5 else lo


def plateau_errors(r, f, lo=40.0, hi=50.0, tail=0.25):
    """Mean F - F_d over the last `tail` of each half period (after the first period), high and low."""
    ph = (r["t"] * f) % 1.0
    late = r["t"] >= 1.0 / f
    hi_m = late & (ph >= 0.5 * (1 - tail)) & (ph < 0.5)
    lo_m = late & (ph >= 1.0 - 0.5 * tail)
    return float(np.mean(r["F"][hi_m] - hi)), float(np.mean(r["F"][lo_m] - lo))


def scenario_8(ctx: FmuContext, fast=True, inv=None):
    inv = inv or InverseStatic(ctx)
    res = {"runs": {}}
    for f in (2.0, 5.0, 20.0):
        t_end = max(1.0, 4.0 / f)
        for name, ff in (("P", None), ("P+FF", inv)):
            r = run_controller(ctx, square(f), t_end, ff=ff)
            r["err_hi"], r["err_lo"] = plateau_errors(r, f)
            res["runs"][(f, name)] = r
    return res


# --------------------------------------------------------------------------------------------
# Scenario 9: stopper motion under constant command
# --------------------------------------------------------------------------------------------

# No orifice flow (the four areas C_d A times 0: C_d itself must be > 0) and no leakage.
NO_VALVE = {"supply_area_scale_1": 0.0, "supply_area_scale_2": 0.0, "return_area_scale_1": 0.0, "return_area_scale_2": 0.0}
SEALED = dict(NO_VALVE, C_db_A_lpp=0.0, C_dm_A_lpp=0.0)


def stopper_sine(x0, amp, f):
    """x_s(t) = x0 + amp sin(2π f t) and its derivative."""
    return (lambda t: x0 + amp * math.sin(TWO_PI * f * t)), (lambda t: amp * TWO_PI * f * math.cos(TWO_PI * f * t))


def move_stopper(plant, x_fun, t_end, h):
    """Move the stopper along x_fun with linear segments (input derivatives); record every step."""
    rec = [(plant.t, plant.x_s) + plant.get("P1", "P2", "F_act")]
    for k in range(int(round(t_end / h))):
        ta, tb = k * h, (k + 1) * h
        xa, xb = x_fun(ta), x_fun(tb)
        plant.step(h, x_s=xa, dx=(xb - xa) / h)
        rec.append((plant.t, xb) + plant.get("P1", "P2", "F_act"))
    a = np.array(rec)
    return {"t": a[:, 0], "x_s": a[:, 1], "P1": a[:, 2], "P2": a[:, 3], "F": a[:, 4]}


def scenario_9(ctx: FmuContext, fast=True):
    g = ctx.defaults["gamma"]
    A_p = piston_area(ctx)
    res = {"A_p": A_p, "gamma": g}
    x_fun, _ = stopper_sine(0.054, 0.015, 1.0)
    # (a) Sealed chambers: no orifice flow, no leakage -> P V^gamma constant in each chamber.
    p = ctx.instance(v_DA=2.0, x_s=0.054, parameters=dict(SEALED, P1_start=5.0e5, P2_start=3.0e5),
                     booleans={"start_at_equilibrium": False})
    r = move_stopper(p, x_fun, 2.0, 0.005)
    L1, L2 = chamber_lengths(ctx, r["x_s"])
    r["inv1"], r["inv2"] = r["P1"] * L1**g, r["P2"] * L2**g
    r["F_law"] = np.maximum(A_p * (r["P1"] - r["P2"]), spring_force(r["x_s"]))
    res["sealed"] = r
    p.close()
    # (b) Leakage only (no orifice flow): air moves from chamber 1 to 2 past the piston, the total is kept.
    #     With the model's (2.26)-(2.29), R T dm_i = V_i dP_i / gamma + P_i dV_i.
    p = ctx.instance(v_DA=2.0, x_s=0.054, parameters=dict(NO_VALVE, P1_start=6.0e5, P2_start=2.0e5),
                     booleans={"start_at_equilibrium": False})
    r = move_stopper(p, x_fun, 2.0, 0.001)
    L1, L2 = chamber_lengths(ctx, r["x_s"])
    V1, V2 = A_p * L1, A_p * L2

    def mass_rt(P, V):  # cumulative R T Δm by the trapezoidal rule on the samples
        dm = 0.5 * (V[1:] + V[:-1]) / g * np.diff(P) + 0.5 * (P[1:] + P[:-1]) * np.diff(V)
        return np.concatenate([[0.0], np.cumsum(dm)])

    r["m1"], r["m2"] = mass_rt(r["P1"], V1), mass_rt(r["P2"], V2)
    res["leak"] = r
    p.close()
    # (c) Normal parameters at the 45 N equilibrium: a quick 2 mm stroke in 10 ms, then 3 s held.
    op = linearize(45.0, 0.054)["operating_point"]
    p = ctx.instance(v_DA=op["v_DA"], x_s=0.054)
    P10, P20, F0 = p.get("P1", "P2", "F_act")
    quick = move_stopper(p, lambda t: 0.054 + 0.002 * min(t / 0.01, 1.0), 0.01, 0.001)
    hold = move_stopper(p, lambda t: 0.056, 3.0, 0.01)
    L1a, L2a = chamber_lengths(ctx, 0.054)
    L1b, L2b = chamber_lengths(ctx, 0.056)
    res["quick"] = {
        "P10": P10, "P20": P20, "F0": F0, "run": quick, "hold": hold,
        "P1_adiabatic": P10 * (L1a / L1b) ** g, "P2_adiabatic": P20 * (L2a / L2b) ** g,
        "P1_after": quick["P1"][-1], "P2_after": quick["P2"][-1],
    }
    p.close()
    # (d) Normal parameters, slow stopper sine ±15 mm at 1 Hz about 54 mm at the 45 N command.
    p = ctx.instance(v_DA=op["v_DA"], x_s=0.054)
    res["sine"] = move_stopper(p, x_fun, 3.0, 0.005)
    p.close()
    ctx.live = [q for q in ctx.live if q.fmu.component is not None]
    return res
