#!/usr/bin/env bash
# Build the FMU and simulate the standard scenario through FMPy:
# prints a summary and writes dist/standard_scenario.csv and dist/standard_scenario.png.
set -euo pipefail
cd "$(dirname "$0")/.."

run() {
    echo
    echo "==> $*"
    "$@"
}

run bash scripts/package.sh
run bash scripts/venv.sh
run .venv/bin/python fmu_tests/run_standard_scenario.py dist/JetPipeActuator.fmu
run cargo run --release -p antagonistic -- package
run .venv/bin/python fmu_tests/antagonistic/run_example.py --out dist/antagonistic_joint.png
