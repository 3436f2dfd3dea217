#!/usr/bin/env bash
# The project's test command: Rust unit tests, FMU packaging, then the FMPy/C test suite
# in fmu_tests/ against dist/JetPipeActuator.fmu. Exits non-zero on the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."

run() {
    echo
    echo "==> $*"
    local started=$SECONDS
    "$@"
    echo "<== $(( SECONDS - started )) s: $*"
}

# Debian's Chromium, in which a test renders the diagnosis's HTML pages.
run bash scripts/install_chromium.sh
mkdir -p target
# The Python environment (pip's downloads and unpacking, little CPU) is made beside the
# release build and the Rust tests, then FMI++, the second Model Exchange importer (one core
# for about 80 s); package.sh and pytest need them.
venv_log=target/venv.log
echo
echo "==> bash scripts/venv.sh && bash scripts/fmipp.sh (beside cargo test; output in $venv_log)"
venv_started=$SECONDS
{ bash scripts/venv.sh && bash scripts/fmipp.sh; } >"$venv_log" 2>&1 </dev/null &
venv_pid=$!
background=("$venv_pid")
trap 'kill "${background[@]}" 2>/dev/null || true' EXIT
run cargo test --release
if ! wait "$venv_pid"; then
    cat "$venv_log" >&2
    echo "test.sh: scripts/venv.sh or scripts/fmipp.sh failed" >&2
    exit 1
fi
cat "$venv_log"
echo "<== $(( SECONDS - venv_started )) s: bash scripts/venv.sh && bash scripts/fmipp.sh"
# Lints: clippy with warnings as errors, on every crate and target (the component is
# installed when the toolchain lacks it).
cargo clippy --version >/dev/null 2>&1 || run rustup component add clippy
# The Windows DLL is built by Debian's rustc one crate at a time, on one core: beside the
# lints and the docs, which leave the other core idle much of the time.
win64_log=target/build_win64.log
echo
echo "==> bash scripts/build_win64.sh (beside clippy and the docs; output in $win64_log)"
win64_started=$SECONDS
bash scripts/build_win64.sh >"$win64_log" 2>&1 &
win64_pid=$!
background+=("$win64_pid")
run cargo clippy --workspace --all-targets --release -- -D warnings
RUSTDOCFLAGS="-D warnings" run cargo doc --no-deps --workspace --release
if ! wait "$win64_pid"; then
    cat "$win64_log" >&2
    echo "test.sh: scripts/build_win64.sh failed" >&2
    exit 1
fi
cat "$win64_log"
echo "<== $(( SECONDS - win64_started )) s: bash scripts/build_win64.sh"
JETPIPE_WIN64=1 run bash scripts/package.sh
# The host build, linked against this machine's glibc: the platform test's counter-example.
# With jetpipe-cli in the same invocation cargo unifies the features as for package.sh's
# `cargo run --bin jetpipe` (plotters turns on num-traits' `default`), which has just built
# this library: it is reused. `-p jetpipe-fmu` alone resolved them anew and rebuilt nalgebra,
# the model and the FMU for the same code (14 s).
run cargo build --release --lib -p jetpipe-fmu -p jetpipe-cli
if [ ! -f dist/JetPipeActuator.fmu ]; then
    echo "test.sh: dist/JetPipeActuator.fmu was not written" >&2
    exit 1
fi
# The other FMUs, on the FMI layer alone, in the same target directory (nothing of the actuator
# is built twice). The antagonistic packager links the three models without their `exports`
# feature, their own tests and FMUs need it on: two invocations, so cargo does not unify them.
run cargo test --release -p fmu_common -p tendon -p finger_joint -p joint_controller
run cargo test --release -p antagonistic
run cargo run --release -p antagonistic -- package
# pytest-xdist: the suite on every core (its diagnoses and simulations are independent; each
# worker extracts the FMU into its own temporary folder).
run .venv/bin/python -m pytest fmu_tests -q -n auto --dist worksteal
echo
echo "==> all tests passed in $SECONDS s"
