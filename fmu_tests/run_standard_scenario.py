"""Simulate the standard scenario (see scenarios.py) through FMPy.

usage: python fmu_tests/run_standard_scenario.py [dist/JetPipeActuator.fmu] [--out-dir dist]

Prints a short summary and writes standard_scenario.csv and standard_scenario.png next to the
FMU (or into --out-dir).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fmpy  # noqa: E402

import scenarios  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("fmu", nargs="?", default=str(Path(__file__).resolve().parent.parent / "dist" / "JetPipeActuator.fmu"))
    parser.add_argument("--out-dir", default=None)
    args = parser.parse_args(argv)

    fmu = Path(args.fmu)
    if not fmu.is_file():
        print(f"FMU not found: {fmu}", file=sys.stderr)
        return 1
    out_dir = Path(args.out_dir) if args.out_dir else fmu.parent
    out_dir.mkdir(parents=True, exist_ok=True)

    signal = scenarios.input_signal()
    t0 = time.perf_counter()
    result = fmpy.simulate_fmu(
        str(fmu),
        start_time=0.0,
        stop_time=scenarios.T_END,
        input=signal,
        output=list(scenarios.OUTPUTS),
        output_interval=scenarios.SAMPLE,
    )
    wall = time.perf_counter() - t0

    t = np.asarray(result["time"])
    # the input samples as applied from each instant on (held until the next 10 ms sample)
    v_da = np.array([scenarios.held_input(x)[0] for x in t])
    x_s = np.array([scenarios.held_input(x)[1] for x in t])
    columns = {"time_s": t, "v_da_V": v_da, "x_s_m": x_s}
    units = {"F_act": "N", "P1": "Pa", "P2": "Pa", "i": "A", "x_jp": "m"}
    for name in scenarios.OUTPUTS:
        columns[f"{name}_{units[name]}"] = np.asarray(result[name])

    csv = out_dir / "standard_scenario.csv"
    np.savetxt(csv, np.column_stack(list(columns.values())), delimiter=",", header=",".join(columns), comments="", fmt="%.10g")

    F, P1, P2 = (np.asarray(result[n]) for n in ("F_act", "P1", "P2"))
    print(f"standard scenario: {scenarios.T_END:g} s, inputs held every {scenarios.SAMPLE * 1e3:g} ms, "
          f"{len(t)} output points, wall time {wall:.2f} s")
    print(f"  F_act  final {F[-1]:10.4f} N   min {F.min():10.4f} N   max {F.max():10.4f} N")
    print(f"  P1     final {P1[-1] / 1e3:10.3f} kPa min {P1.min() / 1e3:10.3f} kPa max {P1.max() / 1e3:10.3f} kPa")
    print(f"  P2     final {P2[-1] / 1e3:10.3f} kPa min {P2.min() / 1e3:10.3f} kPa max {P2.max() / 1e3:10.3f} kPa")
    print(f"  wrote {csv}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(4, 1, sharex=True, figsize=(9, 9))
    ax[0].step(t, v_da, where="post")
    ax[0].set_ylabel("v_DA [V]")
    ax[1].step(t, x_s * 1e3, where="post")
    ax[1].set_ylabel("x_s [mm]")
    ax[2].plot(t, F)
    ax[2].set_ylabel("F_act [N]")
    ax[3].plot(t, P1 / 1e3, label="P1")
    ax[3].plot(t, P2 / 1e3, label="P2")
    ax[3].set_ylabel("pressure [kPa abs]")
    ax[3].legend()
    ax[3].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.suptitle("JetPipeActuator FMU, standard scenario")
    fig.tight_layout()
    png = out_dir / "standard_scenario.png"
    fig.savefig(png, dpi=110)
    print(f"  wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
