#!/usr/bin/env bash
# Benchmark of the diagnosis's 95 % intervals: do they hold the truth on about 95 % of
# recordings? benchgen, the project's own bench simulator, writes RECORDINGS_PER_CASE recordings
# (fresh noise each, seeds from SEED) of each of ten effects whose form the model holds exactly
# (30 s of a multisine at 500 Hz, the stopper shaken for the frictions); each is diagnosed
# (`--jobs 1`, as many at once as there are cores) and every amount with a known truth is
# checked against its interval. Writes docs/results/intervals.md; the last line, `TOTALS: ...`,
# goes into its history table.
#
#   bash scripts/bench_intervals.sh [SEED] [RECORDINGS_PER_CASE]     (defaults 1 and 5: 50 recordings)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results intervals "Coverage of the diagnosis's 95 % intervals (benchgen)" "$@"
seed="${1:-1}"
per_case="${2:-5}"
cargo build --release --bin jetpipe --bin benchgen >&2
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Copies of the programs: a build during the run (cargo in another shell) does not change them.
cp target/release/jetpipe target/release/benchgen "$work/"
python3 scripts/bench_intervals.py "$work" "$seed" "$per_case"
