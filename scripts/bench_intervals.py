"""Coverage of the diagnosis's 95 % intervals, run by scripts/bench_intervals.sh.

Each case is one effect whose form the model holds exactly, so that its true value is a value
of the model's own constants: benchgen (the project's independent bench simulator) writes it at
a known size, with fresh noise for every recording, and the diagnosis reports the amount with a
95 % interval. Over many recordings, an interval that is honest holds the truth on about 95 % of
them: far fewer means it is too narrow, all of them with room to spare means it is too wide.

    python3 scripts/bench_intervals.py WORKDIR SEED RECORDINGS_PER_CASE

WORKDIR holds copies of `jetpipe` and `benchgen`; the recordings and reports go there too.
Prints a Markdown table per recording and amount, the coverage per amount and overall, and a
last line `TOTALS: ...` for the results file's history.
"""

import json
import math
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

MULTISINE = ["--protocol", "multisine", "--duration", "30", "--sample-rate", "500"]
SHAKEN = MULTISINE + ["--stopper", "sine:0.066:0.003:1.4"]

# (case, benchgen's flags, protocol, the truth: model constant -> value, or
# (constant, offset from its start value) for a constant the effect shifts).
CASES = [
    ("sensor_offset_gain", ["--force-sensor-offset", "0.7", "--force-sensor-gain", "1.02"], MULTISINE,
     {"force_sensor_offset": 0.7, "force_sensor_gain": 1.02}),
    ("transport_delay", ["--command-delay", "0.002"], MULTISINE, {"command_delay": 0.002}),
    ("smooth_piston_friction", ["--friction-coulomb", "2.3", "--friction-smoothing-velocity", "0.01"], SHAKEN,
     {"friction_coulomb": 2.3, "friction_velocity": 0.01}),
    ("viscous_friction", ["--viscous-friction", "60"], SHAKEN, {"viscous_friction": 60.0}),
    ("force_sensor_lag", ["--force-sensor-lag", "0.01"], MULTISINE, {"force_sensor_lag": 0.01}),
    ("p1_sensor_offset", ["--pressure-sensor-offset-1", "8000"], MULTISINE, {"p1_sensor_offset": 8000.0}),
    ("return_back_pressure", ["--return-back-pressure", "40000"], MULTISINE, {"P_r": ("P_r", 40000.0)}),
    ("receiver_offset", ["--receiver-offset", "1e-5"], MULTISINE, {"x_jp_offset": ("x_jp_offset", 1e-5)}),
    ("chamber_1_leak", ["--chamber-leak-1", "1e-8"], MULTISINE, {"chamber_vent_1": 1e-8}),
    ("contact_compliance", ["--contact-stiffness", "2e4"], MULTISINE, {"stopper_compliance": 1.0 / 2e4}),
]


def start_values(jetpipe):
    """The model's start value of every constant, from `jetpipe parameters`."""
    values = {}
    table = subprocess.run([jetpipe, "parameters"], capture_output=True, text=True, check=True).stdout
    for line in table.splitlines():
        cells = [c.strip() for c in line.split("|")]
        if len(cells) > 4 and cells[1].startswith("`"):
            try:
                values[cells[1].strip("`")] = float(cells[4])
            except ValueError:
                pass
    return values


def run(work, case, flags, protocol, seed):
    name = f"{case}_{seed}"
    csv = os.path.join(work, name + ".csv")
    report = os.path.join(work, name + ".json")
    subprocess.run([os.path.join(work, "benchgen"), "--out", csv, "--seed", str(seed), *protocol, *flags],
                   capture_output=True, check=True)
    subprocess.run([os.path.join(work, "jetpipe"), "diagnose", csv, "--report", report, "--no-html", "--jobs", "1"],
                   capture_output=True)
    return name, report


def amounts(report):
    """Every amount the report added with its interval: name -> (value, interval, method, place)."""
    found = {}
    for entry in report.get("effects", []) + report.get("discovered", []):
        place = entry.get("name") or f'{entry["location"]} {entry["family"]}'
        for key, value in entry["parameters"].items():
            interval = (entry.get("intervals_95") or {}).get(key)
            method = (entry.get("interval_method") or {}).get(key)
            found[key] = (value, interval, method, place)
    return found


def main():
    work, seed, per_case = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    jetpipe = os.path.join(work, "jetpipe")
    starts = start_values(jetpipe)
    jobs = []
    for index, (case, flags, protocol, truth) in enumerate(CASES):
        for k in range(per_case):
            jobs.append((case, flags, protocol, truth, seed + 1000 * index + k))
    with ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1)) as pool:
        done = list(pool.map(lambda j: (j, run(work, j[0], j[1], j[2], j[4])), jobs))

    print("| recording | verdict | amount | truth | reported | 95 % interval | method | half-width / truth | error / standard error | holds |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    tally = {}  # amount -> [held, with interval, reported, recordings]
    scores = {}  # amount -> the errors in standard errors (half-width / 1.96)
    for (case, _flags, _protocol, truth, noise_seed), (name, path) in done:
        try:
            report = json.load(open(path))
            verdict = report["verdict"]
            found = amounts(report)
        except (OSError, ValueError, KeyError):
            verdict, found = "error", {}
        for key, spec in truth.items():
            true = starts[spec[0]] + spec[1] if isinstance(spec, tuple) else spec
            t = tally.setdefault(key, [0, 0, 0, 0])
            t[3] += 1
            if key not in found:
                print(f"| {name} | {verdict} | {key} | {true:.6g} | not added | — | — | — | — | — |")
                continue
            value, interval, method, _place = found[key]
            t[2] += 1
            if not interval:
                print(f"| {name} | {verdict} | {key} | {true:.6g} | {value:.6g} | none | — | — | — | — |")
                continue
            low, high = interval
            held = low <= true <= high
            t[1] += 1
            t[0] += held
            width = (high - low) / 2 / abs(true) if true else math.nan
            score = (value - true) / ((high - low) / 2 / 1.96) if high > low else math.nan
            scores.setdefault(key, []).append(score)
            side = "yes" if held else ("no (truth above)" if true > high else "no (truth below)")
            print(f"| {name} | {verdict} | {key} | {true:.6g} | {value:.6g} | [{low:.6g}, {high:.6g}] | {method} | {width:.2%} | {score:+.2f} | {side} |")
    print()
    print("Error / standard error: (reported − truth) over the interval's half-width / 1.96. Honest")
    print("intervals give a mean near 0 (no bias) and a spread near 1 over the noise seeds.")
    print()
    print("| amount | recordings | added | with an interval | interval holds the truth | error / standard error: mean, spread |")
    print("|---|---|---|---|---|---|")
    held = with_interval = 0
    for key, (h, w, a, n) in tally.items():
        share = f"{h}/{w} ({h / w:.0%})" if w else "—"
        z = scores.get(key, [])
        mean = sum(z) / len(z) if z else math.nan
        spread = math.sqrt(sum((v - mean) ** 2 for v in z) / (len(z) - 1)) if len(z) > 1 else math.nan
        print(f"| {key} | {n} | {a} | {w} | {share} | {mean:+.2f}, {spread:.2f} |")
        held += h
        with_interval += w
    recordings = len(done)
    share = held / with_interval if with_interval else math.nan
    print()
    print(f"Over {recordings} recordings ({per_case} noise seeds for each of {len(CASES)} effects), "
          f"the 95 % intervals held the truth {held} times in {with_interval} ({share:.1%}); "
          "the target is 90-98 %.")
    print(f"TOTALS: {recordings} recordings, {with_interval} intervals, {held} hold the truth ({share:.1%})")


if __name__ == "__main__":
    main()
