# Sourced by the benchmarks on blindgen draws (bench_blindgen.sh, bench_loop.sh):
# `blindgen_prepare SCRIPT SEED COUNT` checks $JETPIPE_BLINDGEN (blindgen's folder, not shipped
# with the repository), makes target/blindgen-venv (numpy and numba from PyPI) on first use,
# builds `jetpipe` and copies it into a temporary $work (removed on exit; a build during the run,
# cargo in another shell, does not change the copy), and draws COUNT recordings of SEED into
# $draws unless they are there already. Sets $blindgen, $venv, $work and $draws.
#
# JETPIPE_BLINDGEN_DRAWS=DIR keeps the draws in DIR and takes them from there when they are
# already drawn (blindgen is deterministic in the seed): the drawing, several minutes for 30,
# can run while the program is still being built.
blindgen_prepare() {
    local script="$1" seed="$2" count="$3"
    [ -d "$JETPIPE_BLINDGEN" ] || { echo "$script: $JETPIPE_BLINDGEN is not a folder (blindgen is not shipped with the repository)" >&2; exit 2; }
    blindgen="$(cd "$JETPIPE_BLINDGEN" && pwd)/blindgen.py"
    [ -f "$blindgen" ] || { echo "$script: no blindgen.py in $JETPIPE_BLINDGEN (blindgen is not shipped with the repository)" >&2; exit 2; }
    venv=target/blindgen-venv
    if ! "$venv/bin/python" -c 'import numpy, numba' >/dev/null 2>&1; then
        python3 -m venv "$venv" >&2
        "$venv/bin/python" -m pip install --quiet --disable-pip-version-check numpy numba >&2
    fi
    export NUMBA_CACHE_DIR="$PWD/target/blindgen-numba-cache"
    cargo build --release --bin jetpipe >&2
    work="$(mktemp -d)"
    trap 'rm -rf "$work"' EXIT
    cp target/release/jetpipe "$work/"
    draws="${JETPIPE_BLINDGEN_DRAWS:-$work/draws}"
    if [ "$(ls "$draws"/bg_"$seed"_*.csv 2>/dev/null | wc -l)" -ne "$count" ]; then
        "$venv/bin/python" "$blindgen" draw --seed "$seed" --count "$count" --out "$draws" >&2
    fi
}
