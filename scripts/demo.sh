#!/usr/bin/env bash
# The project's two main jobs on a fresh machine: build the FMU and simulate the standard
# scenario (and the antagonistic joint) through FMPy, then diagnose the example recordings of
# examples/recordings/ against the model. Writes dist/JetPipeActuator.fmu,
# dist/standard_scenario.{csv,png}, dist/antagonistic_joint.png and dist/diagnosis/ (a JSON
# report and an HTML page per recording, summary.csv and index.html), and ends with what to open.
set -euo pipefail
cd "$(dirname "$0")/.."
started=$SECONDS

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
# The diagnosis writes its pages anew: a page of an earlier run whose recording is gone would
# otherwise stay beside the new index.
rm -rf dist/diagnosis
run cargo run --release --bin jetpipe -- diagnose examples/recordings --out dist/diagnosis

echo
echo "==> the demo took $(( SECONDS - started )) s; open:"
echo "  $PWD/dist/diagnosis/index.html     the diagnoses of examples/recordings/ (one page each)"
echo "  $PWD/dist/standard_scenario.png    the standard scenario simulated through FMPy"
echo "  $PWD/dist/JetPipeActuator.fmu      the FMU, to import into your tool (README, \"Interface\")"
