#!/usr/bin/env bash
# Performance figures of the Rust core (issue 6), in a few minutes on a 2-core machine:
#   1. criterion benchmarks (benches/core.rs): one right-hand side, 10 s of each scenario;
#   2. examples/perf_report.rs: CPU time, integrator work and memory per scenario, with the
#      target (10 s of any scenario in < 10 ms CPU at rtol 1e-6) marked PASS or MISS;
#   3. fmu_tests/work_precision.py: error against CPU time, Rust vs SciPy LSODA and Radau,
#      with the target (>= 300x SciPy at equal accuracy) marked PASS or MISS.
# Timings depend on the machine's load, printed with each part: compare figures taken on an
# idle machine. BENCH_MEASUREMENT_TIME (s per criterion benchmark, default 3) and
# BENCH_RUNS (best-of for perf_report, default 5) trade time for precision;
# BENCH_PLOT=path also writes the work-precision diagram.
set -euo pipefail
cd "$(dirname "$0")/.."

run() {
    echo
    echo "==> $*"
    "$@"
}

echo "load: $(uptime)"
run cargo bench --bench core -- --measurement-time "${BENCH_MEASUREMENT_TIME:-3}" --warm-up-time 1
run cargo run --release --quiet --example perf_report -- --runs "${BENCH_RUNS:-5}"
run bash scripts/venv.sh
plot=()
if [ -n "${BENCH_PLOT:-}" ]; then
    plot=(--plot "$BENCH_PLOT")
fi
run .venv/bin/python fmu_tests/work_precision.py --seconds 1 "${plot[@]}"
run cargo run --release --quiet -p diffsol_compare --target-dir target/tools
echo "load: $(uptime)"
