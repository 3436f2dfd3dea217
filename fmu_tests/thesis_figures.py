"""The thesis's measured dynamic figures for one set of FMU parameters: what presets/thesis_measured.json
was fitted with (docs/model.md, "The thesis-measured preset").

    .venv/bin/python fmu_tests/thesis_figures.py '{"hysteresis_width": 0.16e-3, ...}' [--preset]

prints, as JSON, the closed-loop -3 dB bandwidths of §4.1.1 (P control at 500 Hz about 45 N,
1 N and 5 N, 54 and 40 mm; bw_*), their resonance peaks above the 1 Hz gain (peak_*) and the
open-loop bandwidths of §3.3.2 at 30 and 90 mA mean (ol_*). With --preset the parameters are
applied on top of presets/thesis_measured.json. One evaluation takes seconds to a minute.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import validation as V  # noqa: E402

CL_FREQS = np.array([1, 5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80, 90, 100, 125, 160, 200.0])
OL_MEANS = (0.03, 0.09)  # A


def figures(parameters: dict) -> dict:
    ctx = V.FmuContext(preset=parameters)
    out = {}
    try:
        for amp, xs in V.CL_CASES:
            d = V.closed_loop_response(ctx, amp, xs, CL_FREQS)
            key = f"{amp:.0f}N_{xs * 1e3:.0f}mm"
            out["bw_" + key] = round(d["bw_rel_Hz"], 1)
            out["peak_" + key] = round(d["peak_dB"] - d["low_dB"], 1)
        freqs = np.geomspace(0.05, 20.0, 12)
        for m in OL_MEANS:
            out[f"ol_{m * 1e3:.0f}mA"] = round(V.open_loop_response(ctx, m, 0.01, freqs)["bw_Hz"], 2)
    finally:
        ctx.close()
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("parameters", nargs="?", default="{}", help="JSON object of FMU parameter values")
    ap.add_argument("--preset", action="store_true", help="start from presets/thesis_measured.json")
    args = ap.parse_args()
    parameters = dict(V.load_preset() if args.preset else {}, **json.loads(args.parameters))
    t0 = time.time()
    out = figures(parameters)
    out["seconds"] = round(time.time() - t0, 1)
    print(json.dumps({"parameters": parameters, "figures": out}))


if __name__ == "__main__":
    main()
