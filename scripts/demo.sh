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
    local step_started=$SECONDS
    "$@"
    echo "<== $(( SECONDS - step_started )) s"
}

# The Python environment (mostly downloads) is made while cargo builds the command-line tool.
mkdir -p target
venv_log=target/demo-venv.log
echo "==> bash scripts/venv.sh (beside the build; output in $venv_log)"
bash scripts/venv.sh >"$venv_log" 2>&1 </dev/null &
venv_pid=$!
trap 'kill "$venv_pid" 2>/dev/null || true' EXIT
run cargo build --release --bin jetpipe
if ! wait "$venv_pid"; then
    cat "$venv_log" >&2
    echo "demo.sh: scripts/venv.sh failed" >&2
    exit 1
fi
trap - EXIT
cat "$venv_log"
run bash scripts/package.sh
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
