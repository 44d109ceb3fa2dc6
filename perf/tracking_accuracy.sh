#!/usr/bin/env bash
# Tracking accuracy on the simulated rig (issue 4, "Done when"): for each scenario and seed,
#   fire simulate wand -o w.log && fire calibrate w.log -o rig.json
#   fire simulate sketch -o s.log && fire track s.log --rig rig.json --truth --method M   (M: thesis, dlt, optimal)
# and a markdown table of reprojection_rms_px, static_rms_mm and dynamic_rms_mm against the targets
# (<= 0.35 px, <= 0.5 mm, <= 1.5 mm), with the other figures the commands report. Scenarios: the
# defaults (the accuracy scenario), and the nominal focal length 2 % wrong with camera 1's clock 5 ms
# off. A second table changes one condition at a time beyond the scenario (seed 1, optimal method),
# to show where the margins are; it does not count towards "All targets met".
# The tables go to stdout (for perf/notes/tracking.md and perf/RESULTS.md), progress to stderr.
#
# usage: perf/tracking_accuracy.sh [FIRE_BINARY]      (default: build/fire)
# env:   SEEDS   space-separated seeds (default "1 2 3 4 5"); each seed is both --seed and --rig-seed
set -u
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
read -r -a seeds <<<"${SEEDS:-1 2 3 4 5}"
[ -x "$fire" ] || { echo "perf/tracking_accuracy.sh: $fire not found; build it first (cmake --build build --target fire)" >&2; exit 2; }

field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\)[,}].*/\1/p" <<<"$2"; }
fmt() { [ -n "$1" ] && awk -v x="$1" -v d="${2:-3}" 'BEGIN { printf "%.*f", d, x }' || printf 'n/a'; }
# PASS or FAIL for value <= limit (a missing value fails).
check() { [ -n "$1" ] && awk -v x="$1" -v l="$2" 'BEGIN { exit !(x <= l) }' && printf 'PASS' || printf 'FAIL'; }
all_pass=yes

# One scenario and seed: prints a table row per method. Args: label seed "wand+sketch options" "sketch-only options" methods...
run_case() {
  local label="$1" seed="$2"; shift 2
  local -a both sketch_only
  read -r -a both <<<"$1"
  read -r -a sketch_only <<<"$2"
  shift 2
  echo "perf/tracking_accuracy.sh: $label, seed $seed" >&2
  local w="$tmp/w.log" s="$tmp/s.log" rig="$tmp/rig.json" cal tr
  "$fire" simulate wand --seed "$seed" --rig-seed "$seed" "${both[@]}" -o "$w" >/dev/null || { echo "simulate wand failed" >&2; exit 1; }
  cal=$("$fire" calibrate "$w" -o "$rig") || { echo "calibrate failed" >&2; exit 1; }
  "$fire" simulate sketch --seed "$seed" --rig-seed "$seed" "${both[@]}" "${sketch_only[@]}" -o "$s" >/dev/null ||
    { echo "simulate sketch failed" >&2; exit 1; }
  local rep wand offset method st dy verdict
  rep=$(field reprojection_rms_px "$cal")
  wand=$(field wand_length_error_mm "$cal")
  offset="$(fmt "$(field time_offset_ms "$cal")") / $(fmt "$(field true_time_offset_ms "$cal")" 1)"
  for method in "$@"; do
    tr=$("$fire" track "$s" --rig "$rig" -o "$tmp/pen.log" --truth --method "$method") || { echo "track failed" >&2; exit 1; }
    st=$(field static_rms_mm "$tr")
    dy=$(field dynamic_rms_mm "$tr")
    verdict="$(check "$rep" 0.35) $(check "$st" 0.5) $(check "$dy" 1.5)"
    case "$verdict" in *FAIL*) last_failed=yes ;; esac
    echo "| $label | $seed | $(fmt "$rep") | $(fmt "$wand") | $offset | $method | $(fmt "$st") | $(fmt "$dy") |" \
         "$(fmt "$(field registered_static_rms_mm "$tr")") / $(fmt "$(field registered_dynamic_rms_mm "$tr")") |" \
         "$(fmt "$(field raw_static_rms_mm "$tr")") / $(fmt "$(field raw_dynamic_rms_mm "$tr")") | $(field strokes "$tr") |" \
         "$verdict |"
  done
}

header() {
  echo "| scenario | seed | reprojection_rms_px (<= 0.35) | wand_length_error_mm | time offset, estimated / true (ms) | method | static_rms_mm (<= 0.5) | dynamic_rms_mm (<= 1.5) | registered static / dynamic (mm) | raw static / dynamic (mm) | strokes | targets |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
}

header
for scenario in "defaults|" "focal +2 %, clock 5 ms|--focal-error 0.02 --clock-offset-ms 5"; do
  for seed in "${seeds[@]}"; do
    last_failed=no
    run_case "${scenario%%|*}" "$seed" "${scenario#*|}" "" thesis dlt optimal
    [ "$last_failed" = yes ] && all_pass=no
  done
done
echo
echo "All targets met: $all_pass"
echo
echo "Beyond the scenario, one condition at a time (seed 1, optimal):"
echo
header
run_case "blob noise 0.5 px" 1 "--noise-px 0.5" "" optimal
run_case "5 % of reports lost" 1 "--dropout 0.05" "" optimal
run_case "hand occlusions 0.5/s per camera" 1 "--occlusion 0.5" "" optimal
run_case "stray blob always there" 1 "--stray 1" "" optimal
run_case "clocks 1000 ppm apart" 1 "--drift-ppm 1000" "" optimal
run_case "arrival jitter 1.5 ms" 1 "--jitter-ms 1.5" "" optimal
run_case "arrival jitter 2.5 ms" 1 "--jitter-ms 2.5" "" optimal
run_case "pen at 1 m/s" 1 "" "--speed 1" optimal
