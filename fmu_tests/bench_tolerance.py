"""The tolerance sweep of Model Exchange through FMPy's CVODE (issue 80). Not a test: a script
(`bash scripts/bench_tolerance.sh`); `test_tolerance_sweep.py` runs a subset.

    .venv/bin/python fmu_tests/bench_tolerance.py [--seconds 1.0] [--tolerances 1e-4,1e-6,1e-8,1e-10]
        [--archives fmi2,fmi3] [--inputs slow_sine,...] [--modes held,interpolated,smooth]

For each archive, input (`tolerance_sweep.SIGNALS`, sampled every 0.1 ms), way of giving it
and relative tolerance: whether CVODE reaches the end, the RMS of F_act against Co-Simulation
(communication step 0.1 ms, the inputs held) at its instants, CVODE's accepted steps and
right-hand sides (`fmi2GetDerivatives` calls, the difference-quotient Jacobian's included) per
simulated second, its restarts (events) and the wall time. The ways (see `tolerance_sweep.py`):

* held: each sample held, an input event at each change (FMPy as it is);
* interpolated: one row per sample, interpolated by FMPy, which sets the inputs only in its
  root function (FMPy as it is, the issue's configuration);
* smooth: the input's law set at the time of each right-hand side, as a Modelica tool
  computes a source in its equations (no input event, no kink).

Outputs every 1 ms, compared at those instants with Co-Simulation of the inputs held every
0.1 ms: for the interpolated runs the difference includes the hold (a linear interpolation
against a zero-order hold); the smooth runs take the law delayed by half the hold, a zero-order
hold's delay to first order (`tolerance_sweep.delayed`). The full-scale steps and the measured
preset's sine with steps run held only (a step is not interpolated).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import tolerance_sweep as ts  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
ARCHIVES = {"fmi2": ROOT / "dist" / "JetPipeActuator.fmu", "fmi3": ROOT / "dist" / "JetPipeActuator-fmi3.fmu"}
HELD_ONLY = {"full_steps", "measured_preset"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--tolerances", default="1e-4,1e-6,1e-8,1e-10")
    ap.add_argument("--archives", default="fmi2,fmi3")
    ap.add_argument("--inputs", default=",".join(ts.SIGNALS))
    ap.add_argument("--modes", default="held,interpolated,smooth")
    args = ap.parse_args()
    tolerances = [float(x) for x in args.tolerances.split(",")]
    t_end = args.seconds
    load = os.getloadavg()
    print(f"{os.cpu_count()} cores, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; "
          f"{t_end:g} s simulated per run, inputs every 0.1 ms")
    print(f"{'archive':7s} {'input':22s} {'inputs':12s} {'rtol':>6s} {'result':>8s} {'F RMS (N)':>10s} "
          f"{'steps/s':>9s} {'RHS/s':>9s} {'restarts':>8s} {'wall (s)':>8s}")
    failures = 0
    for archive in args.archives.split(","):
        fmu = ARCHIVES[archive]
        for name in args.inputs.split(","):
            start = ts.start_values(name)
            held = ts.signal(name, t_end, 1e-4, hold=True)
            cs = ts.co_simulation(fmu, held, t_end, 1e-4, start)
            for mode in args.modes.split(","):
                if mode != "held" and name in HELD_ONLY:
                    continue
                law, reference = None, cs[::10]
                if mode == "held":
                    inputs = held
                elif mode == "interpolated":
                    inputs = ts.signal(name, t_end, 1e-4, hold=False)
                else:
                    inputs, law = None, ts.delayed(ts.SIGNALS[name])
                for rtol in tolerances:
                    me, error, work, wall = ts.model_exchange(fmu, inputs, t_end, rtol, interval=1e-3, start=start,
                                                              law=law)
                    if me is None:
                        failures += mode != "interpolated"
                        reason = "mxstep" if "mxstep" in error else error[-60:]
                        result, rms = f"FAILED ({reason})", float("nan")
                    else:
                        result, rms = "ok", ts.force_rms(reference, me)
                    print(f"{archive:7s} {name:22s} {mode:12s} {rtol:6.0e} {result:>8s} {rms:10.2e} "
                          f"{work.steps / t_end:9.0f} {work.rhs / t_end:9.0f} {work.restarts:8d} {wall:8.1f}",
                          flush=True)
    print(f"{failures} failed runs with held or smooth inputs")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
