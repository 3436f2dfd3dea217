#!/usr/bin/env bash
# The FMU as it stands against the FMU of an older commit, side by side in one run, from a
# plain C importer through the exported fmi2* functions (a benchmark, not a test: it fails only
# when a build or a run fails).
#
#   bash scripts/bench_vs_commit.sh [--pairs N] [--rounds R] [--callgrind] [COMMIT]
#
# COMMIT (default 545a082) is checked out into a temporary git worktree and built there with
# `cargo build --release --lib` (its build is kept under target/bench_vs_commit/ for the next
# run); the current FMU is built with `cargo build --release -p jetpipe-fmu --lib`. Both
# libjetpipe.so are driven by fmu_tests/c/cosimulation_timer.c: 10 s at 1 kHz (fmi2DoStep of
# 1 ms), the standard scenario's inputs (held for 10 ms), default parameters, the outputs read
# after every step. The script
#   1. checks that the two builds' outputs agree (bit for bit, or by how much they differ);
#   2. loads both libraries into one process and runs N pairs of runs (default 200), one of
#      each build, the order alternating from pair to pair, after one untimed run of each:
#      the two runs of a pair are some 20 ms apart, so a change in the machine's speed
#      (another tenant, the clock) falls on both; R such processes (default 5);
#   3. prints, per process, each build's median and fastest CPU time and the median of the
#      pairs' ratios (current / COMMIT), then the median of those ratios, with the load
#      average before and after;
#   4. with --callgrind, counts the instructions executed inside fmi2DoStep, fmi2GetReal and
#      fmi2SetReal (the calls of each step) for one cold run of each build (valgrind
#      --tool=callgrind): figures that do not drift with the machine.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"

pairs=200
rounds=5
callgrind=0
commit=545a082
usage() {
    echo "usage: bash scripts/bench_vs_commit.sh [--pairs N] [--rounds R] [--callgrind] [COMMIT]" >&2
    exit 2
}
while [ $# -gt 0 ]; do
    case "$1" in
        --pairs) [ $# -ge 2 ] || usage; pairs="$2"; shift 2 ;;
        --rounds) [ $# -ge 2 ] || usage; rounds="$2"; shift 2 ;;
        --callgrind) callgrind=1; shift ;;
        -h | --help) usage ;;
        -*) echo "unknown option $1" >&2; usage ;;
        *) commit="$1"; shift ;;
    esac
done
case "$pairs" in '' | *[!0-9]*) echo "--pairs $pairs: expected a positive integer" >&2; exit 2 ;; esac
[ "$pairs" -ge 1 ] || { echo "--pairs $pairs: expected a positive integer" >&2; exit 2; }
case "$rounds" in '' | *[!0-9]*) echo "--rounds $rounds: expected a positive integer" >&2; exit 2 ;; esac
[ "$rounds" -ge 1 ] || { echo "--rounds $rounds: expected a positive integer" >&2; exit 2; }
full="$(git rev-parse --verify --quiet "$commit^{commit}")" || {
    echo "COMMIT $commit: not a commit of this repository" >&2
    exit 2
}
short="$(git rev-parse --short "$full")"
load() { cut -d' ' -f1-3 /proc/loadavg; }
echo "==> $(nproc) cores, load average $(load)"

headers="$(ls -d .venv/lib/python3*/site-packages/fmpy/c-code 2>/dev/null | head -n1 || true)"
if [ -z "$headers" ] || [ ! -f "$headers/fmi2Functions.h" ]; then
    echo "the FMI 2.0 headers come from FMPy's package in .venv: run 'bash scripts/venv.sh' first" >&2
    exit 1
fi
guid_of() { grep -o 'guid="[^"]*"' | head -n1 | cut -d'"' -f2; }

work="$(mktemp -d)"
tree="$work/tree"
cleanup() {
    if [ -d "$tree" ]; then git worktree remove --force "$tree" >/dev/null 2>&1 || true; fi
    rm -rf "$work"
}
trap cleanup EXIT

echo "==> the current FMU"
cargo build --release -p jetpipe-fmu --lib
target="${CARGO_TARGET_DIR:-$root/target}"
current_lib="$(find "$target/release" -maxdepth 1 -name libjetpipe.so | head -n1)"
[ -n "$current_lib" ] || { echo "no libjetpipe.so under $target/release" >&2; exit 1; }
current_guid="$(guid_of <modelDescription.xml)"

echo "==> the FMU at $short"
old_target="$target/bench_vs_commit/$full"
old_lib="$(find "$old_target/release" -maxdepth 1 -name libjetpipe.so 2>/dev/null | head -n1 || true)"
if [ -z "$old_lib" ]; then
    git worktree add --detach "$tree" "$full" >/dev/null
    (cd "$tree" && CARGO_TARGET_DIR="$old_target" cargo build --release --lib)
    old_lib="$(find "$old_target/release" -maxdepth 1 -name libjetpipe.so | head -n1)"
    [ -n "$old_lib" ] || { echo "the build of $short left no libjetpipe.so" >&2; exit 1; }
else
    echo "(kept from an earlier run: $old_lib)"
fi
old_guid="$(git show "$full:modelDescription.xml" | guid_of)"
[ -n "$old_guid" ] || { echo "$short has no modelDescription.xml with a guid" >&2; exit 1; }

driver="$work/cosimulation_timer"
cc -O2 -std=c99 -Wall -Wextra -I "$headers" -o "$driver" fmu_tests/c/cosimulation_timer.c -ldl -lm

echo "==> outputs (F_act, P1, P2, i, x_jp after each of the 10000 steps)"
"$driver" --cold --csv "$work/old.csv" "$old_lib" "$old_guid" >/dev/null
"$driver" --cold --csv "$work/current.csv" "$current_lib" "$current_guid" >/dev/null
if cmp -s "$work/old.csv" "$work/current.csv"; then
    echo "bit-identical to $short at every step"
else
    echo "NOT bit-identical to $short; largest differences:"
    paste -d, "$work/old.csv" "$work/current.csv" | awk -F, 'NR > 1 {
        for (c = 2; c <= 6; c++) { d = $c - $(c + 6); if (d < 0) d = -d; if (d > m[c]) { m[c] = d; at[c] = $1 } } }
        END { split("F_act P1 P2 i x_jp", name, " ");
              for (c = 2; c <= 6; c++) printf "  max |d %s| = %.3g at t = %s s\n", name[c - 1], m[c], at[c] }'
fi

echo "==> $rounds times $pairs interleaved pairs in one process (CPU ms of a 10 s run)"
load_before="$(load)"
: >"$work/rounds"
for ((k = 1; k <= rounds; k++)); do
    "$driver" --pairs "$pairs" "$old_lib" "$old_guid" "$current_lib" "$current_guid" >"$work/round"
    value() { sed -n "s/^$1=//p" "$work/round"; }
    printf 'round %2d: median %s %8.3f ms, current %8.3f ms; fastest %8.3f and %8.3f ms; median ratio %s\n' \
        "$k" "$short" "$(value median_a_ms)" "$(value median_b_ms)" "$(value min_a_ms)" "$(value min_b_ms)" \
        "$(value median_ratio)"
    value median_ratio >>"$work/rounds"
done
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
echo "median of the rounds' median ratios (current / $short): $(median <"$work/rounds")"
echo "load average before $load_before, after $(load)"

if ((callgrind)); then
    command -v valgrind >/dev/null || { echo "--callgrind needs valgrind" >&2; exit 1; }
    echo "==> instructions of one cold run (callgrind), inside the calls of each step"
    count() {
        valgrind --tool=callgrind --callgrind-out-file="$work/callgrind.out" --toggle-collect="$3" \
            "$driver" --cold "$1" "$2" 2>&1 >/dev/null | sed -n 's/.*Collected : *//p'
    }
    total_old=0
    total_current=0
    for call in fmi2DoStep fmi2GetReal fmi2SetReal; do
        old_ir="$(count "$old_lib" "$old_guid" "$call")"
        current_ir="$(count "$current_lib" "$current_guid" "$call")"
        total_old=$((total_old + old_ir))
        total_current=$((total_current + current_ir))
        awk -v a="$old_ir" -v b="$current_ir" -v s="$short" -v f="$call" \
            'BEGIN { printf "%-12s %s %6.2f M, current %6.2f M; ratio %.3f\n", f, s, a / 1e6, b / 1e6, b / a }'
    done
    awk -v a="$total_old" -v b="$total_current" -v s="$short" \
        'BEGIN { printf "%-12s %s %6.2f M, current %6.2f M; ratio %.3f\n", "all three", s, a / 1e6, b / 1e6, b / a }'
fi
