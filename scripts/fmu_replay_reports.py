"""Replay every diagnosis report of a folder through the packaged FMU and compare the force
error it gives with the one the report claims.

    python scripts/fmu_replay_reports.py FMU RECORDINGS REPORTS [--jobs N]

For each REPORTS/NAME.json (a `jetpipe diagnose` report on RECORDINGS/NAME.csv) the FMU is set
to the report's `fmu_start_values` and driven by the recording as the diagnosis drove its model
(fmu_tests/test_diagnose_fmu.replay_through_fmu: the command held between samples, the stopper
positions as the report's `stopper_positions` says, its acceleration where the report fed it).
Prints one Markdown row per report (the reported force RMS error after, the FMU's, their
ratio) and a last line `FMU: K of N within 10 % of the reported force error; largest departure
X % (NAME)`. A report the FMU cannot be set to (a refused parameter) counts as outside, with
the FMU's message in its row.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "fmu_tests"))

WITHIN = 0.10


def replay_one(args):
    fmu_path, csv_path, report_path = args
    import fmpy
    from jetpipe_fmu import vr_map
    from test_diagnose_fmu import replay_through_fmu

    name = Path(report_path).stem
    report = json.loads(Path(report_path).read_text())
    reported = report["after"]["force_rms_N"]
    try:
        model_description = fmpy.read_model_description(fmu_path)
        unzipdir = fmpy.extract(fmu_path, tempfile.mkdtemp())
        recording = np.genfromtxt(csv_path, delimiter=",", names=True)
        force = replay_through_fmu(unzipdir, model_description, vr_map(model_description), recording,
                                   report["fmu_start_values"],
                                   report["stopper_positions_smoothing_residual_limit_m2"],
                                   acceleration=report.get("stopper_acceleration_input"))
        rms = float(np.sqrt(np.mean((recording["force_N"] - force) ** 2)))
        return name, reported, rms, ""
    except Exception as error:  # the row says what the FMU refused
        return name, reported, None, str(error).splitlines()[0][:200]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu")
    parser.add_argument("recordings")
    parser.add_argument("reports")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    work = []
    for report_path in sorted(Path(args.reports).glob("*.json")):
        csv_path = Path(args.recordings) / f"{report_path.stem}.csv"
        if csv_path.exists():
            work.append((args.fmu, str(csv_path), str(report_path)))
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(replay_one, work))
    print("| report | reported force RMS after (N) | FMU replay (N) | FMU / reported |")
    print("|---|---|---|---|")
    within, worst = 0, (0.0, "")
    for name, reported, rms, error in results:
        if rms is None:
            print(f"| {name} | {reported:.5f} | refused: {error} | — |")
            worst = max(worst, (float("inf"), name))
            continue
        ratio = rms / reported if reported > 0 else float("inf")
        within += abs(ratio - 1.0) <= WITHIN
        worst = max(worst, (abs(ratio - 1.0), name))
        print(f"| {name} | {reported:.5f} | {rms:.5f} | {ratio:.3f} |")
    print()
    print(f"FMU: {within} of {len(results)} within {WITHIN:.0%} of the reported force error; "
          f"largest departure {100 * worst[0]:.1f} % ({worst[1] or 'none'})")


if __name__ == "__main__":
    main()
