"""Work-precision comparison of the Rust integrator with SciPy (issue 6). Not a test: a script.

    .venv/bin/python fmu_tests/work_precision.py [--seconds 1.0] [--scipy-budget 60] [--plot docs/work_precision.png]

Over the first `--seconds` of the standard scenario (inputs held every 10 ms):

* reference: the Rust model at relative tolerance 1e-10 with 0.1 ms communication steps;
* Rust: `examples/trajectory.rs` at a range of tolerances, CPU time measured in-process
  (best of 5 runs, the equilibrium start excluded);
* SciPy: `solve_ivp` LSODA and Radau on the same equations written independently in
  `scipy_reference.py` (restarted at every 10 ms input change, as the FMU sees them), CPU
  time by `time.process_time`, from the same initial state.

Error = max |F_act - F_ref| over the 10 ms instants. It prints each run, then the CPU time of
each method at equal accuracy (log-log interpolation along each curve's Pareto front) at
several error levels, the ratio SciPy / Rust against the best SciPy method, and the target
check of issue 6 (Rust at least 300x faster than SciPy at equal accuracy).

SciPy's tightest tolerances are skipped when the estimated cost would exceed `--scipy-budget`
seconds of CPU time in all. The machine's load is printed: timings on a busy machine are noisy.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scipy_reference  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
# Where cargo puts the example (CARGO_TARGET_DIR relative to the repository, as cargo reads it).
TRAJECTORY = ROOT / os.environ.get("CARGO_TARGET_DIR", "target") / "release" / "examples" / "trajectory"

RUST_TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
SCIPY_TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
ERROR_LEVELS = (1e-3, 1e-4, 1e-5, 1e-6)  # N
TARGET_RATIO = 300.0


def load() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "unknown"


def build() -> None:
    subprocess.run(["cargo", "build", "--release", "--quiet", "--example", "trajectory"], cwd=ROOT, check=True)


def rust(rtol: float, seconds: float, step: float = 0.01, runs: int = 5):
    """(forces at 10 ms instants, CPU s, right-hand sides, initial state) of one Rust setting."""
    out = subprocess.run(
        [str(TRAJECTORY), "--rtol", repr(rtol), "--seconds", repr(seconds), "--step", repr(step), "--runs", str(runs)],
        check=True, capture_output=True, text=True,
    ).stdout
    header, rows = {}, []
    for line in out.splitlines():
        if line.startswith("# "):
            key, _, value = line[2:].partition(" ")
            header[key] = value
        elif line and line[0].isdigit():
            rows.append(float(line.split(",")[1]))
    y0 = [float(v) for v in header["initial_state"].split()]
    return np.array(rows), float(header["cpu_seconds"]), int(header["rhs_evaluations"]), y0


def scipy_run(method: str, rtol: float, seconds: float, y0):
    """(forces, best CPU s, evaluations): runs under half a second are repeated (best of 3)."""
    best, forces, nfev = math.inf, None, 0
    for _ in range(3):
        forces, cpu, nfev = scipy_reference.run(method, rtol, seconds, y0)
        best = min(best, cpu)
        if cpu > 0.5:
            break
    return forces, best, nfev


def pareto(points):
    """The (error, cpu) points no other point beats on both, error ascending, cpu descending."""
    front = []
    for err, cpu in sorted(points):
        if not front or cpu < front[-1][1]:
            front.append((max(err, 1e-300), cpu))
    return front


def cost_at(points, level):
    """CPU time to reach max error `level` along a curve, and how it was found:
    '=' interpolated (log-log) between two runs, '<=' the loosest run is already more accurate
    (a looser tolerance might be cheaper), None if the curve never gets that accurate."""
    front = pareto(points)
    if not front or level < front[0][0]:
        return None, None
    if level >= front[-1][0]:
        return front[-1][1], "<="
    for (e0, c0), (e1, c1) in zip(front, front[1:]):
        if e0 <= level <= e1:
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + s * (math.log(c1) - math.log(c0))), "="
    return None, None


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=1.0, help="first seconds of the standard scenario")
    parser.add_argument("--scipy-budget", type=float, default=60.0, help="CPU seconds for all SciPy runs")
    parser.add_argument("--plot", type=Path, help="write the work-precision diagram (PNG) here")
    parser.add_argument("--no-build", action="store_true", help="use the existing examples/trajectory build")
    args = parser.parse_args()
    if not args.no_build:
        build()

    print(f"work-precision, first {args.seconds:g} s of the standard scenario; "
          f"error = max |F_act - F_ref| at the 10 ms instants")
    print(f"machine: {os.cpu_count()} cores, load average {load()} (before)")
    reference, ref_cpu, _, y0 = rust(1e-10, args.seconds, step=1e-4, runs=1)
    print(f"reference: Rust, rtol 1e-10, 0.1 ms communication steps ({ref_cpu:.3f} s CPU)\n")

    curves = {"Rust split DP5": [], "SciPy LSODA": [], "SciPy Radau": []}
    print(f"{'method':<18} {'rtol':>7} {'max |dF| N':>11} {'CPU s':>10} {'CPU s / sim s':>14} {'RHS evals':>10}")

    def report(name, rtol, forces, cpu, nfev):
        err = float(np.max(np.abs(forces - reference)))
        curves[name].append((err, cpu))
        print(f"{name:<18} {rtol:>7.0e} {err:>11.2e} {cpu:>10.4f} {cpu / args.seconds:>14.4f} {nfev:>10}")

    for rtol in RUST_TOLERANCES:
        forces, cpu, nfev, _ = rust(rtol, args.seconds)
        report("Rust split DP5", rtol, forces, cpu, nfev)

    spent = 0.0
    for method in ("LSODA", "Radau"):
        previous = None
        for rtol in SCIPY_TOLERANCES:
            # Each decade of tolerance costs SciPy about 1.5-2.5x more: skip what would overrun.
            if previous is not None and spent + 2.5 * previous > args.scipy_budget:
                print(f"SciPy {method:<12} {rtol:>7.0e}   skipped (CPU budget of {args.scipy_budget:g} s)")
                continue
            started = time.process_time()
            try:
                forces, cpu, nfev = scipy_run(method, rtol, args.seconds, y0)
            except RuntimeError as e:
                print(f"SciPy {method:<12} {rtol:>7.0e}   failed: {e}")
                continue
            finally:
                spent += time.process_time() - started
            previous = cpu
            report(f"SciPy {method}", rtol, forces, cpu, nfev)

    rust_curve = curves["Rust split DP5"]
    print("\nCPU time at equal accuracy (log-log interpolation; '<=' the loosest run already reaches it)")
    print(f"{'max |dF| N':>10} {'Rust s':>12} {'LSODA s':>12} {'Radau s':>12} {'SciPy best / Rust':>18}")
    ratios = []
    for level in ERROR_LEVELS:
        cells, best = [], (None, None)
        for name in curves:
            cost, how = cost_at(curves[name], level)
            cells.append("n/a" if cost is None else f"{'<=' if how == '<=' else ''}{cost:.4g}")
            if name.startswith("SciPy") and cost is not None and (best[0] is None or cost < best[0]):
                best = (cost, how)
        rust_cost, rust_how = cost_at(rust_curve, level)
        if rust_cost is None or best[0] is None:
            ratio_text = "n/a"
        else:
            ratio = best[0] / rust_cost
            ratios.append(ratio)
            # An upper bound on a cost turns into a bound on the ratio.
            if rust_how == "<=" and best[1] == "=":
                bound = ">="
            elif best[1] == "<=" and rust_how == "=":
                bound = "<="
            else:
                bound = "~"
            ratio_text = f"{bound}{ratio:.0f}x"
        print(f"{level:>10.0e} {cells[0]:>12} {cells[1]:>12} {cells[2]:>12} {ratio_text:>18}")

    if ratios:
        verdict = "PASS" if min(ratios) >= TARGET_RATIO else "MISS"
        print(f"\ntarget: Rust >= {TARGET_RATIO:.0f}x faster than SciPy at equal accuracy: {verdict} "
              f"(ratios {', '.join(f'{r:.0f}x' for r in ratios)}; smallest {min(ratios):.0f}x)")
    else:
        print("\ntarget: Rust >= 300x faster than SciPy at equal accuracy: no common error level")
    print(f"load average {load()} (after)")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        for name, marker in zip(curves, "osd"):
            pts = sorted(curves[name])
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] / args.seconds for p in pts], marker=marker, label=name)
        ax.set_xlabel("max |F_act - F_ref| (N)")
        ax.set_ylabel("CPU s per simulated s")
        ax.set_title(f"Work-precision, standard scenario, first {args.seconds:g} s")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(args.plot, dpi=110)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
