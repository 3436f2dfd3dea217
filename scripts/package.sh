#!/usr/bin/env bash
# Build the shipped dist/JetPipeActuator.fmu:
#  * binaries/linux64 linked against glibc 2.17 (manylinux2014 class) with cargo-zigbuild and
#    the Zig toolchain from PyPI (both pinned in fmu_tests/requirements.txt, installed into .venv
#    by scripts/venv.sh), so that RHEL/CentOS 7 and newer, Ubuntu 14.04+ and Debian 8+ load it;
#  * binaries/win64, when scripts/build_win64.sh has built target/win64/JetPipeActuator.dll
#    (JETPIPE_WIN64=0 leaves it out, JETPIPE_WIN64=1 makes its absence an error).
# Set JETPIPE_NATIVE=1 to package the host build instead (no Zig; the binary then needs the
# build machine's glibc).
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=x86_64-unknown-linux-gnu
GLIBC=2.17
DLL=target/win64/JetPipeActuator.dll

args=()
if [ "${JETPIPE_NATIVE:-0}" = "1" ]; then
    echo "==> packaging the host build (JETPIPE_NATIVE=1)"
else
    bash scripts/venv.sh
    # cargo-zigbuild runs `python3 -m ziglang` when no `zig` is on PATH: the venv's python.
    echo "==> cargo zigbuild --release --lib -p jetpipe-fmu --target $TARGET.$GLIBC"
    PATH="$PWD/.venv/bin:$PATH" .venv/bin/cargo-zigbuild zigbuild --release --lib -p jetpipe-fmu --target "$TARGET.$GLIBC"
    args+=(--library "target/$TARGET/release/libjetpipe.so")
fi
case "${JETPIPE_WIN64:-auto}" in
    0) ;;
    1)
        [ -f "$DLL" ] || { echo "package.sh: $DLL is missing (run scripts/build_win64.sh)" >&2; exit 1; }
        args+=(--win64 "$DLL")
        ;;
    *) [ -f "$DLL" ] && args+=(--win64 "$DLL") ;;
esac
cargo run --release --bin jetpipe -- package "${args[@]}"
