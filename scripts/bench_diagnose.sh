#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose`: wall time of the diagnosis of 80 s, 1 kHz recordings
# with pressure channels (target: at most 30 s on a 2-core machine, every candidate fitted).
# Prints one Markdown table row per recording: the synthetic ones benchgen writes (named
# effects, then every undeclared mechanism of its table), then recorded ones.
# JETPIPE_BENCH_UNDECLARED=0 leaves the undeclared set out.
#
# The recorded ones are the .csv files of JETPIPE_BENCH_RECORDINGS=DIR and of DIR/undeclared.
# By default they are the project's development recordings in ../shared/bench, beside the
# repository, which are not shipped with it; where that folder is missing, the repository's
# own examples/recordings/ stand in, and the table says which set ran. The last line,
# `TOTALS: ...`, goes into the results file's history table.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results diagnosis_recordings "Diagnosis of the synthetic bench's recordings, 80 s at 1 kHz" "$@"
if [ -n "${JETPIPE_BENCH_RECORDINGS:-}" ]; then
    recorded="$JETPIPE_BENCH_RECORDINGS"
    [ -d "$recorded" ] || { echo "bench_diagnose.sh: JETPIPE_BENCH_RECORDINGS=$recorded is not a folder" >&2; exit 2; }
    recorded_words="the recordings of JETPIPE_BENCH_RECORDINGS"
elif [ -d ../shared/bench ]; then
    recorded=../shared/bench
    recorded_words="the project's development recordings (not shipped with the repository)"
else
    recorded=examples/recordings
    recorded_words="the repository's examples/recordings/ (the project's development recordings are not shipped with it)"
    echo "bench_diagnose.sh: no ../shared/bench beside the repository: diagnosing examples/recordings/ instead" >&2
fi
cargo build --release --bin jetpipe --bin benchgen
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Copies of the programs: a build during the run (cargo in another shell) does not change them.
cp target/release/jetpipe target/release/benchgen "$work/"
"$work/benchgen" --out "$work/friction.csv" --seed 7 --friction-coulomb 2.0 >/dev/null
"$work/benchgen" --out "$work/supply.csv" --seed 107 --supply-resistance 5e8 >/dev/null
"$work/benchgen" --out "$work/hysteresis_and_friction.csv" --seed 109 --hysteresis-width 0.12e-3 --friction-coulomb 2 >/dev/null
if [ "${JETPIPE_BENCH_UNDECLARED:-1}" != 0 ]; then
    "$work/benchgen" --out "$work/list.txt" --list-undeclared > "$work/names.txt"
    for name in $(awk '{print $1}' "$work/names.txt"); do
        "$work/benchgen" --out "$work/u_$name.csv" --seed 7 --undeclared "$name" >/dev/null
    done
fi
mkdir -p "$work/reports"
echo "| recording | verdict | named | discovered (location, family: parameters) | held-out before → after (N) | wall (s) on $(nproc) cores |"
echo "|---|---|---|---|---|---|"
total_ms=0
count=0
for rec in "$work"/*.csv "$recorded"/*.csv "$recorded"/undeclared/*.csv; do
    [ -f "$rec" ] || continue
    start=$(date +%s%N)
    report="$work/reports/$(basename "$(dirname "$rec")")_$(basename "$rec" .csv).json"
    "$work/jetpipe" diagnose "$rec" --report "$report" >/dev/null 2>&1
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    total_ms=$((total_ms + ms))
    count=$((count + 1))
    row=$(python3 - "$report" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
names = ", ".join(e["name"] for e in d["effects"]) or "—"
found = "; ".join(
    f'{t["location"]}, {t["family"]}: ' + ", ".join(f"{k} = {v:.4g}" for k, v in t["parameters"].items())
    for t in d["discovered"]) or "—"
if "unexplained" in d and not d["discovered"]:
    u = d["unexplained"]
    found = f'placed at {u["location"]} ({u["family"]})'
print(f'{d["verdict"]} | {names} | {found} | {d["heldout"]["before_rms_N"]:.3f} → {d["heldout"]["after_rms_N"]:.3f}')
PY
) || row="error | — | — | —"
    echo "| $(basename "$rec" .csv) | $row | $((ms / 1000)).$(( (ms % 1000) / 100 )) |"
done
echo
echo "Beside benchgen's recordings: $recorded_words."
echo
python3 scripts/never_worse.py "$work"/reports/*.json
# The totals, for the history table of docs/results/diagnosis_recordings.md.
python3 - "$count" "$total_ms" "$work"/reports/*.json <<'PY'
import json, sys
sys.path.insert(0, "scripts")
from never_worse import ALLOWANCE_SHARE_OF_NOISE, excesses
reports = [json.load(open(p)) for p in sys.argv[3:]]
explained = sum(1 for d in reports if d["verdict"] == "explained")
worse = sum(1 for d in reports if max(excesses(d)) > ALLOWANCE_SHARE_OF_NOISE)
print(f"TOTALS: explained {explained} of {sys.argv[1]} recordings; worse than the start {worse}; "
      f"{int(sys.argv[2]) / 60000:.1f} min of diagnosis")
PY
