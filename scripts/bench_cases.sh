#!/usr/bin/env bash
# Every case of the diagnosis's end-to-end tests, the broad ones included: the test command
# (scripts/test.sh) runs a representative subset, one or two cases per place of the chain and
# per function class, within its time; the cases it leaves out (marked `#[ignore]` in
# crates/diagnosis/tests/diagnose/ and `broad` in fmu_tests/) are run here, each on its own.
# Prints one Markdown table row per case: its name, whether it passed, and its wall time.
#
#   bash scripts/bench_cases.sh            (every case: about 35 min on 2 cores)
#   bash scripts/bench_cases.sh broad      (only the cases the test command leaves out)
#
# Writes docs/results/diagnosis_cases.md (the repository does not hold one until this has run).
# The last line, `TOTALS: ...` (cases passed of those run, and the wall time of the diagnosis's
# cases), goes into the results file's history table. Exits non-zero when a case fails.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results diagnosis_cases "The diagnosis's end-to-end test cases, one by one" "$@"
only_broad=0
[ "${1:-}" = "broad" ] && only_broad=1
rows="$(mktemp)"
trap 'rm -f "$rows"' EXIT

cargo test --release -p jetpipe-diagnosis --test diagnose --no-run >/dev/null 2>&1
binary=$(cargo test --release -p jetpipe-diagnosis --test diagnose --no-run --message-format=json 2>/dev/null |
    python3 -c 'import json,sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("target", {}).get("name") == "diagnose" and m.get("executable"):
        print(m["executable"])')
cd crates/diagnosis
if [ "$only_broad" = 1 ]; then
    cases=$("$binary" --list --ignored 2>/dev/null | sed -n 's/: test$//p')
else
    cases=$("$binary" --list 2>/dev/null | sed -n 's/: test$//p')
fi
failed=0
echo "| case | result | wall (s) on $(nproc) cores |"
echo "|---|---|---|"
for case in $cases; do
    start=$(date +%s%N)
    if "$binary" --exact "$case" --include-ignored >/tmp/bench_cases.$$.log 2>&1; then
        result=passed
    else
        result=FAILED
        failed=1
    fi
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    echo "| diagnose: $case | $result | $((ms / 1000)).$(( (ms % 1000) / 100 )) |" | tee -a "$rows"
    [ "$result" = passed ] || sed 's/^/    /' /tmp/bench_cases.$$.log | tail -20 >&2
done
rm -f /tmp/bench_cases.$$.log
cd ../..

# The FMU's cases (the packaged FMU in dist/ must be current: scripts/package.sh).
bash scripts/venv.sh >/dev/null
marker=()
[ "$only_broad" = 1 ] && marker=(-m broad)
if ! JETPIPE_BROAD=1 .venv/bin/python -m pytest fmu_tests/test_diagnose_fmu.py "${marker[@]}" -q -rA \
    -p no:cacheprovider 2>&1 | sed -n 's/^\(PASSED\|FAILED\) \(.*\)$/| fmu: \2 | \1 | |/p' | tee -a "$rows"; then
    failed=1
fi
# The totals, for the history table of docs/results/diagnosis_cases.md.
python3 - "$rows" <<'PY'
import sys
rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in open(sys.argv[1]) if line.startswith("| ")]
def count(prefix):
    mine = [r for r in rows if r[0].startswith(prefix)]
    return sum(1 for r in mine if r[1] in ("passed", "PASSED")), len(mine)
(dp, dn), (fp, fn) = count("diagnose: "), count("fmu: ")
wall = sum(float(r[2]) for r in rows if r[0].startswith("diagnose: ") and r[2])
print(f"TOTALS: passed {dp + fp} of {dn + fn} (diagnose {dp} of {dn}, fmu {fp} of {fn}); "
      f"the diagnosis's cases {wall / 60:.0f} min")
PY
exit "$failed"
