"""The validation report's column "with the measured effects" (issue 30): every scenario of
chapters 3 and 4 run again on the FMU with presets/thesis_measured.json, through the same code
(fmu_tests/validation.py). `measured_effects(pctx)` returns the table's cells, keyed by
(scenario, what) as validation_report.py's rows, the numbers its section 10 quotes, and the
section's figure."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import brentq

import validation as V


def pct(value, reference):
    return f"{100.0 * (value - reference) / abs(reference):+.0f} %"


def operating_point(ctx, force, x_s=0.054):
    """v_DA and pressures of the equilibrium with F_act = force (fresh instances, bisection)."""
    f = lambda v: V.static_force(ctx, [v], x_s)["F"][0] - force  # noqa: E731
    v = brentq(f, -2.0, 10.0, xtol=1e-6)
    s = V.static_force(ctx, [v], x_s)
    return v, float(s["P1"][0]), float(s["P2"][0])


def measured_effects(pctx, save):
    """Run scenarios 1-8 on the preset's FMU; `save(fig, name)` writes a figure and returns its path."""
    cells, x = {}, {"preset": dict(pctx.preset)}

    r = V.scenario_1(pctx, fast=False)
    cells[("1", "current driver corner")] = f"{r['f_corner_sweep_Hz']:.1f} Hz (sweep)"

    r = V.scenario_2(pctx, fast=False)
    x["s2"] = r
    cells[("2", "ω1 (fit)")] = f"{r['omega_1']:.1f} rad/s"
    cells[("2", "ω2 (fit)")] = f"{r['omega_2']:.1f} rad/s"
    cells[("2", "ζ2 (fit)")] = f"{r['zeta_2']:.5f}"
    cells[("2", "rise time")] = f"{r['rise100_s'] * 1e3:.2f} ms (0→100 %)"
    cells[("2", "5 % settling")] = f"{r['settle5_s']:.4f} s ({pct(r['settle5_s'], 0.07)}): not reproduced"

    r = V.scenario_3(pctx, fast=True)
    x["s3"] = r
    eq = np.array([r["static"][xs]["F"] for xs in V.STOPPERS_3])
    above = np.all(eq > np.array([r["floor"][xs] for xs in V.STOPPERS_3])[:, None] + 0.5, axis=0)
    spread = float(np.max(np.ptp(eq[:, above], axis=0)))
    cells[("3", "static force vs x_s")] = f"equilibria within {spread:.0e} N above the floor"
    cells[("3", "maximum force")] = f"{r['F_max'][0.054]:.1f} N at 0.4 A ({pct(r['F_max'][0.054], 111.25)})"
    cells[("3", "floor")] = "spring force ({:.2f}, {:.2f}, {:.2f} N)".format(*(r["floor"][xs] for xs in V.STOPPERS_3))
    cells[("3", "slope k near 45 N")] = f"{r['k_static_45N']:.0f} N/A ({pct(r['k_static_45N'], 550)})"
    loops = r["loops"]
    cells[("3", "jet-pipe loop, halves apart")] = (f"{loops['x_jp_m'] * 1e3:.3f} mm; force loop "
                                                   f"{loops['i_at_45N_A'] * 1e3:.0f} mA apart at 45 N")

    r = V.scenario_4(pctx, fast=True)
    cells[("4", "unpressurised force, spring rate")] = f"{r['slope']:.4f} N/m"

    r = V.scenario_5(pctx, fast=False)
    x["s5"] = r
    bws_m = [r["means"][m]["bw_Hz"] for m in V.MEANS_5]
    bws_a = [r["amps"][a]["bw_Hz"] for a in V.AMPS_5]
    x["bws_m"], x["bws_a"] = bws_m, bws_a
    cells[("5", "open-loop bandwidth, 54 mm")] = f"{min(bws_m + bws_a):.2f}–{max(bws_m + bws_a):.2f} Hz"
    def trend(b):
        word = "flat" if abs(b[-1] - b[0]) < 0.01 else "rises" if b[-1] > b[0] else "falls"
        return f"{word} ({b[0]:.2f} → {b[-1]:.2f} Hz)"

    cells[("5", "trend with amplitude")] = trend(bws_a) + ("" if bws_a[-1] > bws_a[0] + 0.01 else ": not reproduced")
    cells[("5", "trend with mean")] = trend(bws_m) + f", {r['F_mean'][V.MEANS_5[0]]:.0f} → {r['F_mean'][V.MEANS_5[-1]]:.0f} N"

    # Scenario 6 without `jetpipe linearize` (which knows no preset, and the hysteresis has no
    # linearisation): the fluid block from the FMU by finite differences at the preset's 45 N.
    v45, P1, P2 = operating_point(pctx, 45.0)
    J = V.fluid_jacobian_fmu(pctx, v45, 0.054, P1, P2)
    fluid = np.sort(np.linalg.eigvals(J).real)[::-1]
    x["fluid45"], x["v45"] = fluid, v45
    unchanged = "unchanged: the preset changes no constant of (2.1)–(2.7)"
    cells[("6", "current driver pole")] = unchanged
    cells[("6", "jet pipe poles")] = unchanged
    cells[("6", "fluid poles")] = f"{fluid[0]:.2f}, {fluid[1]:.2f} (FMU Jacobian)"
    no_linearisation = "— (the hysteresis has no linearisation)"
    for what in ("fluid zero", "open-loop corner 45 N, 54 mm", "bandwidth vs x_s", "bandwidth vs force"):
        cells[("6", what)] = no_linearisation

    freqs = np.unique(np.concatenate([np.geomspace(1, 220, 30), [25, 55, 80]]))
    cl = {(amp, xs): V.closed_loop_response(pctx, amp, xs, freqs) for amp, xs in V.CL_CASES}
    x["cl"], x["cl_freqs"] = cl, freqs
    inv = V.InverseStatic(pctx)
    track = V.run_controller(pctx, lambda t: 45.0 + 20.0 * math.sin(V.TWO_PI * 2.0 * t), 1.0)
    last = track["t"] >= 0.5
    x["offset_2Hz"] = float(np.mean(track["F"][last] - track["Fd"][last]))
    b = {k: d["bw_rel_Hz"] for k, d in cl.items()}
    cells[("7", "closed-loop bandwidth, linear theory")] = no_linearisation
    cells[("7", "closed loop, full linearisation at 500 Hz")] = no_linearisation
    cells[("7", "−3 dB at 5 N, 54 mm")] = f"{b[(5.0, 0.054)]:.0f} Hz ({pct(b[(5.0, 0.054)], 80)})"
    cells[("7", "−3 dB at 1 N, 54 mm")] = f"{b[(1.0, 0.054)]:.0f} Hz ({pct(b[(1.0, 0.054)], 25)})"
    cells[("7", "40 mm vs 54 mm")] = (f"{b[(1.0, 0.040)]:.0f} / {b[(5.0, 0.040)]:.0f} Hz "
                                     f"({pct(b[(1.0, 0.040)], b[(1.0, 0.054)])}, {pct(b[(5.0, 0.040)], b[(5.0, 0.054)])} on 54 mm)")
    cells[("7", "steady offset, P control")] = f"{x['offset_2Hz']:+.2f} N at 2 Hz"

    # Why the dead volume sits on chamber 1's side: the same volume split over both sides.
    half = 0.5 * pctx.preset["dead_volume_1"]
    probe = V.FmuContext(pctx.path, preset=dict(pctx.preset, dead_volume_1=half, dead_volume_2=half))
    x["probe"] = {k: V.closed_loop_response(probe, amp, xs, V.CL_FREQS_FAST)["bw_rel_Hz"]
                  for k in V.CL_CASES for amp, xs in [k]}
    probe.close()

    r8 = V.scenario_8(pctx, inv=inv)
    x["s8"] = r8
    worst_ff = max(max(abs(r8["runs"][(f, "P+FF")]["err_hi"]), abs(r8["runs"][(f, "P+FF")]["err_lo"])) for f in (2.0, 5.0, 20.0))
    worst_p = max(max(abs(r8["runs"][(f, "P")]["err_hi"]), abs(r8["runs"][(f, "P")]["err_lo"])) for f in (2.0, 5.0, 20.0))
    x["worst_ff"], x["worst_p"] = worst_ff, worst_p
    cells[("8", "offset with P + f⁻¹ (4.2)")] = f"\\|error\\| ≤ {worst_ff:.2f} N (P alone up to {worst_p:.2f} N): reduced, not removed"
    cells[("9", "stopper motion")] = "— (not a thesis figure)"

    fig, ax = plt.subplots(1, 2, figsize=(12, 3.8))
    for (amp, xs), c in zip(V.CL_CASES, ("C0", "C1", "C2", "C3")):
        d = cl[(amp, xs)]
        ax[0].semilogx(freqs, V.db(d["H"]), color=c, ls="-" if xs == 0.054 else "--",
                       label=f"{amp:.0f} N, {xs * 1e3:.0f} mm: {d['bw_rel_Hz']:.0f} Hz")
    for fx, lab in ((80, "measured 5 N: 80 Hz"), (25, "measured 1 N: 25 Hz")):
        ax[0].axvline(fx, color="gray", ls=":", lw=0.8)
        ax[0].text(fx, -14, lab, rotation=90, fontsize=7, va="bottom")
    ax[0].set(xlabel="f (Hz)", ylabel="|F/F_d| (dB)", ylim=(-15, 10), title="closed loop (Fig. 4.1) with the measured effects")
    ax[0].legend(fontsize=7)
    ramp = x["s3"]["ramp"][0.054]
    for leg, ls in (("up", "-"), ("down", "--")):
        ax[1].plot(ramp[leg][:, 0] * 1e3, ramp[leg][:, 2] * 1e3, ls, label=f"x_jp, {leg}")
    ax[1].set(xlabel="i (mA)", ylabel="x_jp (mm)", title=f"jet-pipe loop (Fig. 3.4): halves {loops['x_jp_m'] * 1e3:.3f} mm apart")
    ax[1].legend(fontsize=7)
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
    x["f10"] = save(fig, "s10_measured_effects.png")
    return cells, x
