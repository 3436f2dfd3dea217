#!/usr/bin/env bash
# Benchmark of `jetpipe diagnose` across protocols and mechanisms: benchgen writes each
# mechanism under each protocol (its own integrator, noise and quantisation), the diagnosis
# runs on it, and one Markdown table row per recording says whether the place and family are
# the truth's, the verdict, and the held-out error after in noise floors.
#
#   bash scripts/bench_protocols.sh [SECONDS]     (default 40 s recordings)
#
# JETPIPE_BENCH_PROTOCOLS and JETPIPE_BENCH_MECHANISMS (space-separated names of the lists
# below) choose a subset. The recordings are all written by benchgen: the benchmark needs
# nothing beside the repository. The last line, `TOTALS: ...`, goes into the results file's
# history table.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/results.sh
record_results diagnosis_protocols "Diagnosis of mechanisms under protocols" "$@"
seconds="${1:-40}"
cargo build --release --bin jetpipe --bin benchgen >/dev/null 2>&1
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Copies of the programs: a build during the run (cargo in another shell) does not change them.
cp target/release/jetpipe target/release/benchgen "$work/"

# name|benchgen protocol options
protocols=(
    "staircase_1k_p|--protocol staircase --sample-rate 1000"
    "multisine_1k_nop|--protocol multisine --sample-rate 1000 --no-pressures"
    "prbs_2k_shake_p|--protocol prbs --sample-rate 2000 --stopper sine:0.054:0.004:2.5 --force-noise 0.03"
    "ramps_500_moves_nop|--protocol ramps --sample-rate 500 --stopper moves:0.02 --no-pressures"
    "tracking_500_p|--protocol force_tracking --sample-rate 500 --force-noise 0.08"
    "sine_250_p|--protocol sine --sample-rate 250"
    "sine_2k_moves_noisy_nop|--protocol sine --sample-rate 2000 --stopper moves:0.01 --no-pressures --force-noise 0.15"
    "staircase_250_shake_p|--protocol staircase --sample-rate 250 --stopper sine:0.05:0.006:0.7 --pressure-noise 600"
)
# name|truth location|truth family|benchgen effect options
# A compound's truth lists its places (and families) joined by "+": it is at the right place
# when every one of them was found, in any order.
mechanisms=(
    "clean|none|none|"
    "pickup_50hz|force_sensor|periodic|--force-sensor-pickup-amplitude 0.2 --force-sensor-pickup-frequency 50"
    "supply_30kpa_low|supply|parameter_offset|--supply-pressure 622925"
    "receiver_offset|jet_pipe|parameter_offset|--undeclared receiver_offset"
    "jet_pipe_lag|jet_pipe|dynamics|--undeclared jet_pipe_lag"
    "chamber_1_leak|chambers|extra_flow|--undeclared chamber_1_leak"
    "force_sensor_lag|force_sensor|dynamics|--undeclared force_sensor_lag"
    "command_dead_zone|command|nonlinearity|--command-dead-zone 0.4"
    "force_sensor_saturation|force_sensor|limit|--force-sensor-saturation 85"
    "force_sensor_saturation_40|force_sensor|limit|--force-sensor-saturation 40"
    "p1_sensor_saturation|pressure_sensors|limit|--pressure-sensor-saturation 450000"
    "p2_sensor_quadratic|pressure_sensors|nonlinearity|--pressure-sensor-quadratic 5e-8"
    "force_sensor_offset_gain|force_sensor|parameter_offset|--force-sensor-offset 0.7 --force-sensor-gain 1.02"
    "stopper_offset_1mm|chambers|parameter_offset|--stopper-position-offset 1e-3"
    "mount_lag_1ms|mechanics|compliance|--contact-stiffness 2e4 --contact-lag 1e-3"
    "gas_drift_20k|chambers|drift|--gas-temperature-drift 20"
    "discharge_ratio_rise|valve|nonlinearity|--discharge-ratio-rise 0.3"
    "supply_leak_2|chambers|extra_flow|--supply-leak-2 1e-8"
    "laminar_leak_1|chambers|extra_flow|--laminar-leak-1 3e-11"
    "laminar_supply_leak_2|chambers|extra_flow|--laminar-supply-leak-2 4e-12"
    "laminar_cross_leak|chambers|extra_flow|--laminar-cross-leak 4e-12"
    "difference_inflow_2|chambers|extra_flow|--difference-inflow-2 5e-12"
    "force_filter_40hz|force_sensor|dynamics|--force-sensor-filter 40 --force-sensor-filter-damping 0.5"
    "p1_filter_30hz|pressure_sensors|dynamics|--pressure-sensor-filter-1 30 --pressure-sensor-filter-damping-1 1"
    "spring_rate_150|mechanics|parameter_offset|--plant k_spring=150"
    "spring_length_85mm|mechanics|parameter_offset|--plant l_spring0=0.085"
    "slow_current_driver|current_driver|dynamics|--plant omega_cd=1500"
    "jet_diameter|valve|parameter_offset|--plant d_jp=1.0e-3"
    "jet_resonance|jet_pipe|dynamics|--plant omega_2=1300 --plant zeta_2=0.1"
    "piston_bore|mechanics|parameter_offset|--plant d_cyl=0.0163"
    "gas_gamma_1_3|chambers|parameter_offset|--plant gamma=1.3"
    "command_filter_30hz|command|dynamics|--command-filter 30 --command-filter-damping 0.6"
    "torque_motor_gain|jet_pipe|parameter_offset|--plant k_m=1.75"
    "discharge_coefficient|valve|parameter_offset|--plant c_d=0.64"
    "gas_temperature_313k|chambers|parameter_offset|--plant temperature=313.15"
    "cylinder_length_84mm|chambers|parameter_offset|--plant l_cyl=0.084"
    "current_offset|current_driver|parameter_offset|--plant i_offset=5e-3"
    "jet_pipe_saturation|jet_pipe|parameter_offset|--plant x_jp_sat=0.35e-3"
    "jet_pipe_corner_500|jet_pipe|dynamics|--plant omega_1=500"
    "receiver_and_supply|jet_pipe+supply|parameter_offset|--undeclared receiver_offset --supply-pressure 622925"
    "receiver_and_pickup|jet_pipe+force_sensor|parameter_offset+periodic|--undeclared receiver_offset --force-sensor-pickup-amplitude 0.2 --force-sensor-pickup-frequency 50"
)
# Extra forces on the piston, which show only while the stopper moves: their own protocols.
balance_protocols=(
    "staircase_1k_moves_p|--protocol staircase --sample-rate 1000 --stopper moves:0.2 --force-noise 0.03"
    "sine_2k_moves_p|--protocol sine --sample-rate 2000 --stopper moves:0.2 --force-noise 0.03"
    "multisine_1k_moves_nop|--protocol multisine --sample-rate 1000 --stopper moves:0.2 --no-pressures --force-noise 0.03"
    "ramps_500_moves_p|--protocol ramps --sample-rate 500 --stopper moves:0.1 --force-noise 0.03"
    "multisine_250_shake_nop|--protocol multisine --sample-rate 250 --stopper sine:0.054:0.01:2.5 --no-pressures --force-noise 0.03"
    "sine_250_slow_moves_nop|--protocol sine --sample-rate 250 --stopper moves:0.05 --no-pressures --force-noise 0.03"
)
balance_mechanisms=(
    "clean|none|none|"
    "moving_mass_100g|mechanics|extra_force|--moving-mass 0.1"
    "quadratic_damping|mechanics|extra_force|--quadratic-damping 300"
    "seal_pressure_friction|mechanics|extra_force|--seal-pressure-friction 1e-6"
    "viscous_friction|mechanics|extra_force|--viscous-friction 60"
)

chosen() { # NAME LIST: whether NAME is in the space-separated LIST (or LIST is empty)
    [ -z "$2" ] && return 0
    for x in $2; do [ "$x" = "$1" ] && return 0; done
    return 1
}

mkdir -p "$work/reports"
echo "| protocol | mechanism | truth | verdict | found (location, family) | right place | held-out after / noise | wall (s) |"
echo "|---|---|---|---|---|---|---|---|"
run_table() { # PROTOCOL-ARRAY-NAME MECHANISM-ARRAY-NAME
local -n plist="$1"
local -n mlist="$2"
for p in "${plist[@]}"; do
    pname="${p%%|*}"
    popts="${p#*|}"
    chosen "$pname" "${JETPIPE_BENCH_PROTOCOLS:-}" || continue
    for m in "${mlist[@]}"; do
        IFS='|' read -r mname mloc mfam mopts <<<"$m"
        chosen "$mname" "${JETPIPE_BENCH_MECHANISMS:-}" || continue
        rec="$work/${pname}_${mname}.csv"
        # shellcheck disable=SC2086
        "$work/benchgen" --out "$rec" --seed 5 --duration "$seconds" $popts $mopts >/dev/null 2>&1
        start=$(date +%s%N)
        report="$work/reports/${pname}_${mname}.json"
        "$work/jetpipe" diagnose "$rec" --report "$report" >/dev/null 2>&1 || true
        end=$(date +%s%N)
        ms=$(((end - start) / 1000000))
        row=$(python3 - "$report" "$mloc" "$mfam" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
loc, fam = sys.argv[2], sys.argv[3]
places = [(t["location"], t["family"]) for t in d["discovered"]]
places += [("named: " + e["name"], e["location"]) for e in d["effects"]]
if "unexplained" in d and d["unexplained"].get("channel", "force") == "force":
    u = d["unexplained"]
    places.append((u["location"], u["family"]))
found = "; ".join(f"{a}, {b}" for a, b in places) or "nothing"
if loc == "none":
    right = "yes" if not d["discovered"] and not d["effects"] else "no"
elif "+" in loc:
    locs = loc.split("+")
    fams = fam.split("+") if "+" in fam else [fam] * len(locs)
    truth = list(zip(locs, fams))
    right = "yes" if all(t in places for t in truth) else ("place" if all(l in [p[0] for p in places] for l in locs) else "no")
else:
    right = "yes" if places and places[0] == (loc, fam) else ("place" if places and places[0][0] == loc else "no")
ratio = f'{d["heldout"]["after_rms_N"] / d["noise_floor_N"]:.2f}'
# A transducer's term: the pressures held out after it, in their noise floors, too.
for t in d["discovered"]:
    if t.get("pressures_heldout_after_rms_Pa") and d.get("noise_floor_Pa"):
        after = t["pressures_heldout_after_rms_Pa"]
        ratio += " (P1 {:.2f}, P2 {:.2f})".format(after[0] / d["noise_floor_Pa"]["p1"], after[1] / d["noise_floor_Pa"]["p2"])
print(f'{d["verdict"]} | {found} | {right} | {ratio}')
PY
) || row="error | — | no | —"
        echo "| $pname | $mname | $mloc, $mfam | $row | $((ms / 1000)).$(((ms % 1000) / 100)) |"
    done
done
}
{
    run_table protocols mechanisms
    run_table balance_protocols balance_mechanisms
} | tee "$work/rows.md"
echo
python3 scripts/never_worse.py "$work"/reports/*.json
# The totals, for the history table of docs/results/diagnosis_protocols.md.
python3 - "$work/rows.md" "$work"/reports/*.json <<'PY'
import json, os, sys
sys.path.insert(0, "scripts")
from never_worse import ALLOWANCE_SHARE_OF_NOISE, excesses
rows = [line.strip().strip("|").split("|") for line in open(sys.argv[1]) if line.startswith("| ")]
rows = [[c.strip() for c in r] for r in rows if len(r) == 8]
explained = sum(1 for r in rows if r[3] == "explained")
right = sum(1 for r in rows if r[5] == "yes")
place = sum(1 for r in rows if r[5] == "place")
reports = [json.load(open(p)) for p in sys.argv[2:] if os.path.exists(p)]
worse = sum(1 for d in reports if max(excesses(d)) > ALLOWANCE_SHARE_OF_NOISE)
minutes = sum(float(r[7]) for r in rows if r[7] not in ("", "—")) / 60
print(f"TOTALS: explained {explained} of {len(rows)}; the truth's place and family {right}, its place only {place}; "
      f"worse than the start {worse}; {minutes:.0f} min of diagnosis")
PY
