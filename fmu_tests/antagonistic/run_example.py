"""Example (not a test): one finger joint of the Utah/MIT hand driven by two jet-pipe actuators
through two tendons, simulated from dist/AntagonisticJoint.ssp by FMPy's SSP master.

The reference: at rest for 0.2 s, a step to 0.5 rad, then from 1.2 s a 2 Hz sine of 0.3 rad about
0.5 rad. Writes docs/antagonistic_joint.png (or the path given) and prints the figures.

    .venv/bin/python fmu_tests/antagonistic/run_example.py [--ssp dist/AntagonisticJoint.ssp] [--out PNG]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ssp_sim  # noqa: E402

T_STEP, THETA_STEP, T_SINE, AMPLITUDE, FREQUENCY, STOP = 0.2, 0.5, 1.2, 0.3, 2.0, 3.2


def reference(t):
    if t < T_STEP:
        return 0.0
    if t < T_SINE:
        return THETA_STEP
    return THETA_STEP + AMPLITUDE * np.sin(2 * np.pi * FREQUENCY * (t - T_SINE))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ssp", type=Path, default=ssp_sim.default_ssp_path())
    parser.add_argument("--out", type=Path, default=ssp_sim.REPO / "docs" / "antagonistic_joint.png")
    args = parser.parse_args()
    if not args.ssp.is_file():
        sys.exit(f"{args.ssp} not found: build it with "
                 "`cargo run --release -p antagonistic -- package`")

    r, seconds = ssp_sim.simulate(reference, STOP, ssp=args.ssp)
    t = ssp_sim.output_time(r)
    theta = r["joint.theta"]
    ref = np.array([reference(x) for x in t])

    step = ssp_sim.step_metrics(t[t < T_SINE], theta[t < T_SINE], T_STEP + ssp_sim.STEP_SIZE, 0.0, THETA_STEP)
    settle = T_SINE + 1.0
    a, p, _ = ssp_sim.sine_response(t, theta, FREQUENCY, settle)
    a_ref, p_ref, _ = ssp_sim.sine_response(t, ref, FREQUENCY, settle)
    phase = (np.degrees(p - p_ref) + 180) % 360 - 180
    t_min = min(r["tendon_flexor.T"].min(), r["tendon_extensor.T"].min())
    print(f"simulated {STOP} s in {seconds:.2f} s (FMPy simulate_ssp, 1 ms Jacobi steps, 6 FMUs)")
    print(f"step 0 -> {THETA_STEP} rad: overshoot {step['overshoot_pct']:.1f} %, rise {step['rise_s'] * 1e3:.0f} ms, "
          f"5 % settling {step['settling_s'] * 1e3:.0f} ms, final error {step['final_error_rad'] * 1e3:.1f} mrad")
    print(f"{FREQUENCY:g} Hz sine of {AMPLITUDE} rad: amplitude ratio {a / a_ref:.3f}, phase {phase:.1f} deg")
    print(f"minimum tendon tension {t_min:.1f} N (the controller's T_min is 8 N); "
          f"slack time {max(r['tendon_flexor.slack_time'][-1], r['tendon_extensor.slack_time'][-1]):g} s")

    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    ax = axes[0]
    ax.plot(t, ref, "k--", lw=1, label=r"$\theta_{ref}$")
    ax.plot(t, theta, "C0", label=r"$\theta$ (joint FMU)")
    ax.set_ylabel("joint angle (rad)")
    ax.set_title("Antagonistic finger joint: 2 jet-pipe actuators, 2 tendons, FMPy SSP master")
    ax.legend(loc="lower right")
    ax = axes[1]
    for side, c in (("flexor", "C3"), ("extensor", "C2")):
        ax.plot(t, r[f"tendon_{side}.T"], c, label=f"tendon tension, {side}")
        ax.plot(t, r[f"controller.T_{side}_ref"], c, ls=":", lw=1, label=f"tension asked, {side}")
    ax.axhline(8.0, color="grey", lw=0.8, ls="--")
    ax.text(t[-1], 8.0, "T_min ", ha="right", va="bottom", color="grey", fontsize=8)
    ax.set_ylabel("tension (N)")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper right", fontsize=8, ncol=2)
    ax = axes[2]
    for side, c in (("flexor", "C3"), ("extensor", "C2")):
        ax.plot(t, r[f"controller.v_DA_{side}"], c, label=f"v_DA {side}")
    ax.set_ylabel("actuator command (V)")
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[3]
    for side, c in (("flexor", "C3"), ("extensor", "C2")):
        ax.plot(t, r[f"actuator_{side}.x_s"] * 1e3, c, label=f"stopper x_s {side}")
    ax.set_ylabel("stopper position (mm)")
    ax.set_xlabel("time (s)")
    ax.legend(loc="upper right", fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=90)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
