#!/usr/bin/env bash
# Benchmark of the loop a user runs at the bench: diagnose a recording; where the report ties
# places or leaves a remainder, `jetpipe propose` a protocol, record it on the same actuator, and
# diagnose both recordings together with `--joint`. On recordings drawn by blindgen, the
# project's independent simulator, whose `record` command plays a protocol on the sealed actuator
# of a draw. Writes docs/results/loop.md: one row per draw (the first report, the proposal's
# predicted separation, the joint report, each recording's held-out error under the joint model
# against its own diagnosis's, wall times), then the scorer's account of the first reports and
# of the joint ones on the draws that went round the loop.
#
#   JETPIPE_BLINDGEN=DIR bash scripts/bench_loop.sh SEED COUNT
#
# DIR is blindgen's folder; JETPIPE_BLINDGEN_DRAWS=DIR2 keeps the draws in DIR2 (and takes them
# from there when drawn already). Use a seed never used before: the scorer reveals the truths.
# JETPIPE_LOOP_SECONDS sets the proposal's length (default 40). The last line, `TOTALS: ...`,
# goes into the results file's history table.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
source scripts/blindgen_setup.sh
record_results loop "The bench loop: diagnose, propose, record, diagnose jointly (blindgen)" "$@"
if [ $# -ne 2 ] || [ -z "${JETPIPE_BLINDGEN:-}" ]; then
    echo "usage: JETPIPE_BLINDGEN=DIR bash scripts/bench_loop.sh SEED COUNT" >&2
    echo "DIR is the folder of blindgen.py, the project's independent simulator (not shipped)." >&2
    exit 2
fi
seed="$1"
count="$2"
seconds="${JETPIPE_LOOP_SECONDS:-40}"
blindgen_prepare bench_loop.sh "$seed" "$count"
mkdir -p "$work/first" "$work/second" "$work/joint" "$work/next" "$work/loop/.truth"
echo "| draw | first report | why the loop | proposal: smallest predicted difference (noise floors) | joint report | each recording, held-out / noise floor: alone → joint | wall: first, propose, joint (s) |"
echo "|---|---|---|---|---|---|---|"
for rec in "$draws"/bg_"$seed"_*.csv; do
    name="$(basename "$rec" .csv)"
    t0=$SECONDS
    "$work/jetpipe" diagnose "$rec" --report "$work/first/$name.json" --no-html --jobs 2 >"$work/$name.first.log" 2>&1 || true
    t1=$SECONDS
    why=$(python3 - "$work/first/$name.json" <<'PY'
import json, os, sys
if not os.path.exists(sys.argv[1]):
    print("error"); sys.exit()
d = json.load(open(sys.argv[1]))
reasons = []
if d["verdict"] != "explained":
    reasons.append("remainder")
ties = [t for t in d["discovered"] if len(t.get("tied_locations") or []) > 1]
ties += [e for e in d["effects"] if len(e.get("tied_effects") or []) > 1]
if len((d.get("unexplained") or {}).get("tied_locations") or []) > 1:
    ties.append(d["unexplained"])
if ties:
    reasons.append("tie")
print(" and ".join(reasons) or "none")
PY
)
    summary() {
        python3 - "$1" <<'PY'
import json, os, sys
if not os.path.exists(sys.argv[1]):
    print("error"); sys.exit()
d = json.load(open(sys.argv[1]))
found = [f'{t["location"]} {t["family"]}' + (f' (tied: {", ".join(t["tied_locations"][1:])})' if len(t.get("tied_locations") or []) > 1 else "") for t in d["discovered"]]
found += [f'named {e["name"]}' for e in d["effects"]]
if d.get("unexplained"):
    found.append(f'remainder at {d["unexplained"]["location"]}')
print(f'{d["verdict"]}, {d["heldout"]["after_rms_N"] / d["noise_floor_N"]:.2f}: {"; ".join(found) or "nothing"}')
PY
    }
    first=$(summary "$work/first/$name.json")
    if [ "$why" = none ] || [ "$why" = error ]; then
        echo "| $name | $first | — | — | — | — | $((t1 - t0)), —, — |"
        continue
    fi
    "$work/jetpipe" propose "$work/first/$name.json" --out "$work/next/$name.csv" --seconds "$seconds" --jobs 2 >"$work/$name.propose.log" 2>&1 || true
    t2=$SECONDS
    if [ ! -f "$work/next/$name.csv" ]; then
        echo "| $name | $first | $why | proposal failed: $(tail -1 "$work/$name.propose.log" | tr '|' '/') | — | — | $((t1 - t0)), $((t2 - t1)), — |"
        continue
    fi
    separation=$(python3 -c "import json; print(f'{json.load(open(\"$work/next/$name.json\"))[\"smallest_noise_floors\"]:.1f}')")
    "$venv/bin/python" "$blindgen" record "$draws/$name" --protocol "$work/next/$name.csv" --out "$work/next/${name}_recorded.csv" >"$work/$name.record.log" 2>&1
    "$work/jetpipe" diagnose "$rec" "$work/next/${name}_recorded.csv" --joint --report "$work/joint/$name.json" --no-html --jobs 2 >"$work/$name.joint.log" 2>&1 || true
    t3=$SECONDS
    # The new recording alone, for the joint model's errors against its own diagnosis's.
    "$work/jetpipe" diagnose "$work/next/${name}_recorded.csv" --report "$work/second/$name.json" --no-html --jobs 2 >"$work/$name.second.log" 2>&1 || true
    joint=$(summary "$work/joint/$name.json")
    each=$(python3 - "$work/joint/$name.json" "$work/first/$name.json" "$work/second/$name.json" "$work/never_worse.txt" <<'PY'
import json, os, sys
joint, alone = sys.argv[1], sys.argv[2:4]
if not os.path.exists(joint) or not all(os.path.exists(p) for p in alone):
    print("—"); sys.exit()
d = json.load(open(joint))
cells, worse = [], False
for r, path in zip(d["recordings"], alone):
    a = json.load(open(path))
    own = a["heldout"]["after_rms_N"]
    together = r["after"]["heldout_force_rms_N"]
    worse |= together > 1.1 * own
    cells.append(f'{own / r["noise_floor_N"]:.2f} → {together / r["noise_floor_N"]:.2f}')
with open(sys.argv[4], "a") as f:
    f.write("worse\n" if worse else "kept\n")
print(", ".join(cells))
PY
)
    ln -sf "$rec" "$work/loop/$name.csv"
    ln -sf "$draws/.truth/$name.json" "$work/loop/.truth/$name.json"
    echo "| $name | $first | $why | $separation | $joint | $each | $((t1 - t0)), $((t2 - t1)), $((t3 - t2)) |"
done
echo
looped=$(ls "$work"/loop/*.csv 2>/dev/null | wc -l)
echo "$looped of $count draws went round the loop (a tie or a remainder in the first report)."
echo
if [ "$looped" -gt 0 ]; then
    echo "The scorer on those draws (truth revealed only here): the first reports, then the joint ones."
    echo
    echo '```'
    "$venv/bin/python" "$blindgen" score "$work/loop" --reports "$work/first" | tee "$work/score_first.txt"
    echo
    "$venv/bin/python" "$blindgen" score "$work/loop" --reports "$work/joint" | tee "$work/score_joint.txt"
    echo '```'
fi
python3 - "$looped" "$count" "$work/score_first.txt" "$work/score_joint.txt" "$work/never_worse.txt" <<'PY'
import os, re, sys
looped, count = int(sys.argv[1]), int(sys.argv[2])
outcomes = open(sys.argv[5]).read().split() if os.path.exists(sys.argv[5]) else []
def totals(path):
    if not os.path.exists(path):
        return "—"
    m = re.search(r"^\s*all\s+honest (\d+)/(\d+), located (\d+)/\d+, explained (\d+)/\d+", open(path).read(), re.M)
    return f"located {m[3]}, explained {m[4]} of {m[2]}" if m else "no totals"
print(f"TOTALS: {looped} of {count} draws looped; first reports {totals(sys.argv[3])}; joint reports {totals(sys.argv[4])}; "
      f"joint within 10 % of each recording's own diagnosis on {outcomes.count('kept')} of {len(outcomes)}")
PY
