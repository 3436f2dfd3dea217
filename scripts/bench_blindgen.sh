#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose` on recordings drawn by blindgen, an independent simulator of
# the actuator with randomly drawn mechanisms, protocols, rates and noise, whose truth stays
# sealed until its scorer reads the reports. Writes docs/results/blindgen.md: one row per draw
# (rate, length, pressure channels, verdict, what was found, the held-out error after in noise
# floors, wall time per sample), the FMU's replay of each report (its force error against the
# reported one), then the scorer's lines and totals (honest, located, explained; by class, by
# rate and with or without pressures).
#
#   JETPIPE_BLINDGEN=DIR bash scripts/bench_blindgen.sh SEED COUNT
#
# DIR is blindgen's folder (blindgen.py). blindgen is kept with the project's development data
# and is not shipped with the repository: without it this benchmark cannot run (the other
# benchmarks, scripts/bench_diagnose.sh and scripts/bench_protocols.sh, need only the
# repository). Use a seed never used before for every measurement: a seed whose truth has been
# read is spent. The simulator runs in target/blindgen-venv (numpy and numba from PyPI, made on
# first use). The last line, `TOTALS: ...` (honest / located / explained of the draws, the
# median wall time per recorded sample and the batch's wall time), goes into the results
# file's history table. JETPIPE_DIAGNOSE_ARGS adds options to every diagnosis (for example
# `--flexible`); JETPIPE_RESULTS=0 prints the table without writing the file.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
source scripts/blindgen_setup.sh
record_results blindgen "Diagnosis of recordings drawn by an independent simulator (blindgen)" "$@"
if [ $# -ne 2 ] || [ -z "${JETPIPE_BLINDGEN:-}" ]; then
    echo "usage: JETPIPE_BLINDGEN=DIR bash scripts/bench_blindgen.sh SEED COUNT" >&2
    echo "DIR is the folder of blindgen.py, the project's independent simulator, which is not" >&2
    echo "shipped with the repository: this benchmark needs it." >&2
    exit 2
fi
seed="$1"
count="$2"
# JETPIPE_BLINDGEN_REPORTS=DIR keeps the reports in DIR (for `jetpipe propose` on them).
blindgen_prepare bench_blindgen.sh "$seed" "$count"
mkdir -p "$work/reports"
# The FMU of the same commit, packaged now (a build during the run does not change it), and
# the Python environment that replays the reports through it.
cargo build --release -p jetpipe-fmu --lib >&2
"$work/jetpipe" package --out "$work/JetPipeActuator.fmu" --out-fmi3 "$work/JetPipeActuator-fmi3.fmu" \
    --library target/release/libjetpipe.so >&2
bash scripts/venv.sh >&2
echo "| draw | rate (Hz) | length (s) | pressures | verdict | found (location, family) | held-out after / noise floor | wall (s) | wall per sample (ms) |"
echo "|---|---|---|---|---|---|---|---|---|"
for rec in "$draws"/bg_"$seed"_*.csv; do
    name="$(basename "$rec" .csv)"
    start=$(date +%s%N)
    # shellcheck disable=SC2086 # JETPIPE_DIAGNOSE_ARGS is a list of options.
    "$work/jetpipe" diagnose "$rec" --report "$work/reports/$name.json" --no-html --jobs 2 \
        ${JETPIPE_DIAGNOSE_ARGS:-} >"$work/$name.log" 2>&1 || true
    if [ -n "${JETPIPE_BLINDGEN_REPORTS:-}" ] && [ -f "$work/reports/$name.json" ]; then
        mkdir -p "$JETPIPE_BLINDGEN_REPORTS"
        cp "$work/reports/$name.json" "$JETPIPE_BLINDGEN_REPORTS/"
    fi
    end=$(date +%s%N)
    python3 - "$rec" "$work/reports/$name.json" "$(( (end - start) / 1000000 ))" <<'PY'
import csv, json, os, sys
path, report_path, ms = sys.argv[1], sys.argv[2], int(sys.argv[3])
with open(path) as f:
    reader = csv.reader(f)
    header = next(reader)
    times = [float(row[0]) for row in reader]
samples = len(times)
rate = round((samples - 1) / (times[-1] - times[0])) if samples > 1 else 0
pressures = "yes" if "p1_Pa" in header else "no"
name = os.path.basename(path)[:-4]
if not os.path.exists(report_path):
    print(f"| {name} | {rate} | {times[-1]:.0f} | {pressures} | error | — | — | {ms / 1000:.1f} | {ms / samples:.2f} |")
    sys.exit()
d = json.load(open(report_path))
places = [f'{t["location"]}, {t["family"]}' for t in d["discovered"]]
places += [f'named: {e["name"]}' for e in d["effects"]]
if "unexplained" in d:
    places.append(f'remainder at {d["unexplained"]["location"]}')
ratio = d["heldout"]["after_rms_N"] / d["noise_floor_N"]
print(f'| {name} | {rate} | {times[-1]:.0f} | {pressures} | {d["verdict"]} | {"; ".join(places) or "nothing"} '
      f'| {ratio:.2f} | {ms / 1000:.1f} | {ms / samples:.2f} |')
PY
done | tee "$work/rows.md"
echo
python3 - "$work/reports" <<'PY'
import glob, json, sys
reports = [json.load(open(p)) for p in sorted(glob.glob(sys.argv[1] + "/*.json"))]
withdrawn = [d["withdrawn"] for d in reports if d.get("withdrawn")]
kept = sum(1 for w in withdrawn if w.get("kept"))
finals = [d["fast_replay"].get("final_force_departure_ratio_to_noise") for d in reports]
finals = [r for r in finals if r is not None]
parted = [r for r in finals if r > 0.2]
print(f"Additions withdrawn on {len(withdrawn)} of {len(reports)} draws ({kept} keeping an earlier round's model). "
      f"The final model's fixed-step replay departed from its accurate one by more than a fifth of the "
      f"force's noise floor on {len(parted)} of the {len(finals)} draws with additions"
      + (f" (largest {max(finals):.2f} noise floors)." if finals else "."))
PY
python3 scripts/never_worse.py "$work"/reports/*.json
echo
echo "The FMU set to each report's start values and driven by its recording as the diagnosis drove"
echo "its model (scripts/fmu_replay_reports.py):"
echo
.venv/bin/python scripts/fmu_replay_reports.py "$work/JetPipeActuator.fmu" "$draws" "$work/reports" --jobs 2 \
    | tee "$work/fmu.txt"
echo
echo "The scorer's account (truth revealed only here):"
echo
echo '```'
"$venv/bin/python" "$blindgen" score "$draws" --reports "$work/reports" | tee "$work/score.txt"
echo '```'
# The totals, for the history table of docs/results/blindgen.md: the scorer's line for all
# draws, and the median of the table's wall time per recorded sample.
python3 - "$work/rows.md" "$work/score.txt" "$work/fmu.txt" <<'PY'
import re, statistics, sys
rows = [line.strip().strip("|").split("|") for line in open(sys.argv[1]) if line.startswith("| bg_")]
per_sample = [float(r[8]) for r in rows if r[8].strip() not in ("", "—")]
wall = [float(r[7]) for r in rows if r[7].strip() not in ("", "—")]
score = re.search(r"^\s*all\s+honest (\d+)/(\d+), located (\d+)/\d+, explained (\d+)/\d+",
                  open(sys.argv[2]).read(), re.M)
parts = [f"honest {score[1]} / located {score[3]} / explained {score[4]} of {score[2]}" if score
         else "the scorer gave no totals"]
if per_sample:
    parts.append(f"median {statistics.median(per_sample):.2f} ms a sample")
fmu = re.search(r"^FMU: (\d+) of (\d+) within", open(sys.argv[3]).read(), re.M)
if fmu:
    parts.append(f"FMU within 10 % on {fmu[1]} of {fmu[2]}")
parts.append(f"{len(rows)} draws in {sum(wall) / 60:.0f} min")
print("TOTALS: " + "; ".join(parts))
PY
