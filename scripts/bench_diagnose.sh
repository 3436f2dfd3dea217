#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose`: wall time of the diagnosis of 80 s, 1 kHz recordings
# with pressure channels (target: at most 30 s on a 2-core machine, every candidate fitted).
# Prints one Markdown table row per recording: the synthetic ones benchgen writes (named
# effects, then every undeclared mechanism of its table), then the bench recordings beside
# the repository if they are there. JETPIPE_BENCH_UNDECLARED=0 leaves the undeclared set out.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results diagnosis_recordings "Diagnosis of the synthetic bench's recordings, 80 s at 1 kHz" "$@"
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
for rec in "$work"/*.csv ../shared/bench/rec_0*.csv ../shared/bench/undeclared/*.csv; do
    [ -f "$rec" ] || continue
    start=$(date +%s%N)
    report="$work/reports/$(basename "$(dirname "$rec")")_$(basename "$rec" .csv).json"
    "$work/jetpipe" diagnose "$rec" --report "$report" >/dev/null 2>&1
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
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
python3 scripts/never_worse.py "$work"/reports/*.json
