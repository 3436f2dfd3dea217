#!/usr/bin/env bash
# Right-hand-side evaluations per second of Model Exchange through the exported C functions, as an
# importer's solver calls them: fmi2SetContinuousStates + fmi2GetDerivatives (FMI 2.0) and
# fmi3SetContinuousStates + fmi3GetContinuousStateDerivatives (FMI 3.0), for the thesis model and
# with a gas volume and a lagging stopper mount; the two versions in alternating rounds, the best
# of three rounds of 200000 evaluations each. Prints figures; checks only that both versions give
# the same derivatives. The figures depend on the machine and its load (printed with them).
set -euo pipefail
cd "$(dirname "$0")/.."
echo "==> $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
cargo test --release --test model_exchange -- --ignored --nocapture right_hand_side_evaluations_per_second 2>&1 \
    | grep -E "right-hand-side evaluations per second|test result|panicked|error"
