#!/usr/bin/env bash
# Model Exchange through FMPy's CVODE at relative tolerances 1e-4 to 1e-10 (issue 80): for both
# archives and every input of fmu_tests/tolerance_sweep.py, whether the run finishes, its F_act
# RMS against Co-Simulation, and CVODE's steps and right-hand sides per simulated second
# (fmu_tests/bench_tolerance.py says how the inputs are given). Builds the FMUs, sets up .venv.
# Extra arguments go to bench_tolerance.py (e.g. --seconds 0.2 --archives fmi2).
# Exits non-zero when a run with held or smooth inputs fails (the interpolated runs are
# FMPy's own limit, reported).
set -euo pipefail
cd "$(dirname "$0")/.."

echo "==> $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
cargo run --release --bin jetpipe -- package
bash scripts/venv.sh
.venv/bin/python fmu_tests/bench_tolerance.py "$@"
