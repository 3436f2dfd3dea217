#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose` against the recording's length: wall time, CPU time and peak
# resident memory (/usr/bin/time -v) of one diagnosis of a synthetic 1 kHz recording with
# pressure channels (a random staircase, the stopper fixed, an exhaust back pressure), at each
# length of JETPIPE_SCALE_DURATIONS (s; default "80 600 3600") and with `--jobs 2`. Prints one
# Markdown table row per length, and writes them into docs/results/diagnosis_scale.md.
# JETPIPE_SCALE_JETPIPE=PATH times another build of the CLI (e.g. an older commit's). The last
# line, `TOTALS: ...` (per length: wall time, CPU time, peak memory, verdict), goes into the
# results file's history table.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results diagnosis_scale "Diagnosis time and memory against the recording's length" "$@"
cargo build --release --bin jetpipe --bin benchgen
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Copies of the programs: a build during the run (cargo in another shell) does not change them.
cp target/release/jetpipe target/release/benchgen "$work/"
jetpipe="${JETPIPE_SCALE_JETPIPE:-$work/jetpipe}"
echo "| length (s) | samples | rows fitted | wall (s) | CPU (s) | peak memory (MB) | verdict | held-out after / noise floor |"
echo "|---|---|---|---|---|---|---|---|"
for duration in ${JETPIPE_SCALE_DURATIONS:-80 600 3600}; do
    rec="$work/staircase_${duration}s.csv"
    "$work/benchgen" --out "$rec" --protocol staircase --duration "$duration" --seed 3 \
        --undeclared return_back_pressure >/dev/null
    /usr/bin/time -v "$jetpipe" diagnose "$rec" --report "$work/report.json" --jobs 2 \
        >/dev/null 2>"$work/time.txt"
    python3 - "$work/report.json" "$work/time.txt" "$duration" <<'PY'
import json, re, sys
report = json.load(open(sys.argv[1]))
text = open(sys.argv[2]).read()
def field(name):
    return re.search(re.escape(name) + r":\s*(.+)", text).group(1).strip()
wall = field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")
seconds = sum(float(p) * 60 ** i for i, p in enumerate(reversed(wall)))
cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
peak = int(field("Maximum resident set size (kbytes)")) / 1024
samples = report["samples"]
thinned = re.search(r"The fits use (\d+) of the", text)
rows = thinned.group(1) if thinned else str(samples)
after = report["heldout"]["after_rms_N"] / report["noise_floor_N"]
print(f"| {sys.argv[3]} | {samples} | {rows} | {seconds:.0f} | {cpu:.0f} | {peak:.0f} | {report['verdict']} | {after:.2f} |")
PY
done | tee "$work/rows.md"
echo
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
# The totals, for the history table of docs/results/diagnosis_scale.md.
python3 - "$work/rows.md" <<'PY'
import sys
rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in open(sys.argv[1]) if line.startswith("| ")]
print("TOTALS: " + "; ".join(f"{r[0]} s: {r[3]} s wall, {r[4]} s CPU, {r[5]} MB, {r[6]}" for r in rows))
PY
