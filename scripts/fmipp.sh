#!/usr/bin/env bash
# FMI++ (PyPI `fmipp` 2.1.0, AIT's importer in C++), the tests' second Model Exchange importer
# beside FMPy: fmu_tests/test_fmipp.py runs the FMI 2.0 archive through it. Built from its
# source distribution into .venv (scripts/venv.sh makes .venv first); idempotent.
#
# Two changes to its setup.py, both checked: it is built without SUNDIALS (it wants 3.1.2,
# Debian has 6.4 with another API), so its variable-step integrators are Boost.Odeint's
# (Dormand–Prince, Cash–Karp, Fehlberg, Bulirsch–Stoer, Rosenbrock); and only the importer's
# wrapper is compiled, not its FMU-export libraries, which the tests do not use (the build
# takes half the time). Needs Debian's swig and Boost headers, installed when missing.
set -euo pipefail
cd "$(dirname "$0")/.."

VERSION=2.1.0
SHA256=c5ad7f656a19da2ffbd7b06e06fb3c7d94a7a771e6704d1a1a47d8401dfc0b6b
VENV=.venv
WORK=target/fmipp

export PIP_NO_INPUT=1
export PIP_DISABLE_PIP_VERSION_CHECK=1

if [ ! -x "$VENV/bin/python" ]; then
    echo "fmipp.sh: $VENV is missing; run scripts/venv.sh first" >&2
    exit 1
fi
if "$VENV/bin/python" -c 'import fmipp' </dev/null >/dev/null 2>&1; then
    echo "==> fmipp is installed in $VENV"
    exit 0
fi

packages=(swig libboost-dev libboost-filesystem-dev libboost-system-dev g++)
missing=()
for p in "${packages[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "fmipp.sh: missing ${missing[*]}; run as root, or: sudo apt-get install -y ${missing[*]}" >&2
        exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y "${missing[@]}" </dev/null || { apt-get update </dev/null && apt-get install -y "${missing[@]}" </dev/null; }
fi

rm -rf "$WORK"
mkdir -p "$WORK"
"$VENV/bin/pip" download --no-deps --no-binary :all: "fmipp==$VERSION" -d "$WORK" </dev/null
archive="$WORK/fmipp-$VERSION.tar.gz"
echo "$SHA256  $archive" | sha256sum -c -
tar -xzf "$archive" -C "$WORK"
"$VENV/bin/python" - "$WORK/fmipp-$VERSION/setup.py" <<'EOF'
import sys
path = sys.argv[1]
text = open(path).read()
changes = [
    ("    ( 'USE_SUNDIALS', None ),\n", ""),
    ("    '-lboost_system',\n    '-lsundials_cvode',\n    '-lsundials_nvecserial'\n", "    '-lboost_system'\n"),
    (", '-DUSE_SUNDIALS' ]", " ]"),
    ("      import_wrapper,\n      export_wrapper,\n      fmi2_frontend,\n      fmi1_frontend_lib\n",
     "      import_wrapper,\n"),
]
for old, new in changes:
    if text.count(old) != 1:
        sys.exit(f"fmipp.sh: setup.py of fmipp is not the one expected: {old!r} found {text.count(old)} times")
    text = text.replace(old, new)
open(path, "w").write(text)
EOF
echo "==> building fmipp $VERSION into $VENV"
"$VENV/bin/pip" install --no-deps "$WORK/fmipp-$VERSION" </dev/null
"$VENV/bin/python" -c 'import fmipp; print("fmipp", fmipp.__file__)' </dev/null
