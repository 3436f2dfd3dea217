#!/usr/bin/env bash
# The FMU as it stands against the FMU of an older commit, side by side in one run, from a
# plain C importer through the exported fmi2* functions (a benchmark, not a test: it fails only
# when a build or a run fails).
#
#   bash scripts/bench_vs_commit.sh [--pairs N] [--repeat R] [--callgrind] [COMMIT]
#
# COMMIT (default 545a082) is checked out into a temporary git worktree and built there with
# `cargo build --release --lib` (its build is kept under target/bench_vs_commit/ for the next
# run); the current FMU is built with `cargo build --release -p jetpipe-fmu --lib`. Both
# libjetpipe.so are driven by fmu_tests/c/cosimulation_timer.c: 10 s at 1 kHz (fmi2DoStep of
# 1 ms), the standard scenario's inputs (held for 10 ms), default parameters, the outputs read
# after every step. The script
#   1. checks that the two builds' outputs agree (bit for bit, or by how much they differ);
#   2. runs N pairs (default 9), the two builds one after the other, the order alternating
#      from pair to pair; each run is one process that warms the library with one untimed run
#      and reports the CPU time of the fastest of R timed runs (default 3);
#   3. prints each pair, the median CPU time of each build and the median of the pairs'
#      ratios (current / COMMIT), with the load average before and after;
#   4. with --callgrind, counts the instructions executed inside fmi2DoStep, fmi2GetReal and
#      fmi2SetReal (the calls of each step) for one cold run of each build (valgrind
#      --tool=callgrind): figures that do not drift with the machine.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"

pairs=9
repeat=3
callgrind=0
commit=545a082
usage() {
    echo "usage: bash scripts/bench_vs_commit.sh [--pairs N] [--repeat R] [--callgrind] [COMMIT]" >&2
    exit 2
}
while [ $# -gt 0 ]; do
    case "$1" in
        --pairs) [ $# -ge 2 ] || usage; pairs="$2"; shift 2 ;;
        --repeat) [ $# -ge 2 ] || usage; repeat="$2"; shift 2 ;;
        --callgrind) callgrind=1; shift ;;
        -h | --help) usage ;;
        -*) echo "unknown option $1" >&2; usage ;;
        *) commit="$1"; shift ;;
    esac
done
case "$pairs" in '' | *[!0-9]*) echo "--pairs $pairs: expected a positive integer" >&2; exit 2 ;; esac
[ "$pairs" -ge 1 ] || { echo "--pairs $pairs: expected a positive integer" >&2; exit 2; }
case "$repeat" in '' | *[!0-9]*) echo "--repeat $repeat: expected a positive integer" >&2; exit 2 ;; esac
[ "$repeat" -ge 1 ] || { echo "--repeat $repeat: expected a positive integer" >&2; exit 2; }
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

cpu_of() { "$driver" --repeat "$repeat" "$1" "$2" | sed -n 's/^cpu_ms=//p'; }
echo "==> $pairs interleaved pairs (CPU ms of a 10 s run, best of $repeat per process)"
load_before="$(load)"
: >"$work/pairs"
for ((k = 1; k <= pairs; k++)); do
    if ((k % 2)); then
        old_ms="$(cpu_of "$old_lib" "$old_guid")"
        current_ms="$(cpu_of "$current_lib" "$current_guid")"
    else
        current_ms="$(cpu_of "$current_lib" "$current_guid")"
        old_ms="$(cpu_of "$old_lib" "$old_guid")"
    fi
    ratio="$(awk -v a="$current_ms" -v b="$old_ms" 'BEGIN { printf "%.3f", a / b }')"
    printf 'pair %2d: %s %8.3f ms, current %8.3f ms, ratio %s\n' "$k" "$short" "$old_ms" "$current_ms" "$ratio"
    echo "$old_ms $current_ms $ratio" >>"$work/pairs"
done
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
old_median="$(cut -d' ' -f1 "$work/pairs" | median)"
current_median="$(cut -d' ' -f2 "$work/pairs" | median)"
ratio_median="$(cut -d' ' -f3 "$work/pairs" | median)"
echo "median: $short $old_median ms, current $current_median ms; median ratio (current / $short) $ratio_median"
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
