#!/usr/bin/env bash
# Create (or refresh) the Python environment for the FMU tests in .venv at the repo root.
# Idempotent: when .venv already holds exactly fmu_tests/requirements.txt (checked through a
# stamp file with the requirements' hash and the interpreter version) nothing is reinstalled.
# Non-interactive: never reads standard input.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON="${PYTHON:-python3}"
VENV=".venv"
REQ="fmu_tests/requirements.txt"
STAMP="$VENV/.requirements.stamp"

export PIP_NO_INPUT=1
export PIP_DISABLE_PIP_VERSION_CHECK=1

if ! command -v "$PYTHON" >/dev/null 2>&1; then
    echo "venv.sh: $PYTHON not found (Python 3.11 or newer is needed)" >&2
    exit 1
fi
if ! "$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' </dev/null; then
    echo "venv.sh: $("$PYTHON" --version 2>&1) is too old, Python 3.11 or newer is needed" >&2
    exit 1
fi

want="$(sha256sum "$REQ" | cut -d' ' -f1) $("$PYTHON" -c 'import sys; print("%d.%d" % sys.version_info[:2])' </dev/null)"

if [ -x "$VENV/bin/python" ] && [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ] \
    && "$VENV/bin/python" -c 'import fmpy, pytest, numpy, scipy, matplotlib, dask, distributed' </dev/null >/dev/null 2>&1; then
    echo "==> $VENV is up to date with $REQ"
    exit 0
fi

if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c 'pass' </dev/null >/dev/null 2>&1; then
    echo "==> creating $VENV with $("$PYTHON" --version 2>&1)"
    rm -rf "$VENV"
    "$PYTHON" -m venv "$VENV" </dev/null
fi

echo "==> installing $REQ into $VENV"
rm -f "$STAMP"
"$VENV/bin/python" -m pip install --quiet -r "$REQ" </dev/null
echo "$want" > "$STAMP"
echo "==> $VENV ready"
