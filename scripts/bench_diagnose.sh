#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose` (issue 4's speed target: an 80 s, 1 kHz recording in under
# 60 s on a 2-core machine). Generates a synthetic 80 s recording with one undeclared effect
# and prints the wall time of its diagnosis, then of each bench recording if present.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --bin jetpipe --bin benchgen
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
./target/release/benchgen --out "$work/friction.csv" --seed 7 --friction-coulomb 2.0 >/dev/null
for rec in "$work/friction.csv" ../shared/bench/rec_0*.csv; do
    [ -f "$rec" ] || continue
    start=$(date +%s%N)
    ./target/release/jetpipe diagnose "$rec" --report "$work/report.json" 2>/dev/null | tail -n 1
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    echo "diagnose $(basename "$rec"): $((ms / 1000)).$(( (ms % 1000) / 100 )) s wall on $(nproc) cores"
done
