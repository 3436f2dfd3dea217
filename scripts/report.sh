#!/usr/bin/env bash
# Regenerate the validation report docs/validation.md and its plots docs/validation/*.png
# (issue 3): build the FMU, set up the venv, run fmu_tests/validation_report.py.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --bin jetpipe
cargo run --release --bin jetpipe -- package
bash scripts/venv.sh
.venv/bin/python fmu_tests/validation_report.py
