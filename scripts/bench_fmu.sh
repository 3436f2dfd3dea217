#!/usr/bin/env bash
# Performance figures of issue 6: builds the FMU, sets up .venv, then prints
#   1. fmu_tests/bench_fmu.py: CPU per simulated second through FMPy and from C, FMPy's share,
#      doStep/s, for the standard scenario and a 500 Hz closed loop; bytes per instance;
#   2. examples/dask_sweep.py: an FMPy sweep on a 2-worker LocalCluster, runs/s and speed-up;
#   3. jetpipe sweep: an in-process sweep on all cores, runs/s and speed-up over one thread.
# It checks only that every run succeeds; the figures depend on the machine and its load
# (printed with them). Extra arguments go to bench_fmu.py (e.g. --repeat 5 --lockstep 32).
set -euo pipefail
cd "$(dirname "$0")/.."

run() {
    echo
    echo "==> $*"
    "$@"
}

echo "==> $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
run cargo run --release --bin jetpipe -- package
run bash scripts/venv.sh
run .venv/bin/python fmu_tests/bench_fmu.py "$@"
run .venv/bin/python examples/dask_sweep.py --param C_d=0.6:0.75:8
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
run ./target/release/jetpipe sweep --param C_d=0.6:0.75:8 --param P_s=600000,652925 --out "$work/sweep.csv"
