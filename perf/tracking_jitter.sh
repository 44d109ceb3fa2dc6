#!/usr/bin/env bash
# Bluetooth timing (issue 12, "Bluetooth's timing"): calibration and tracking on the simulated rig as the
# report arrival jitter grows, with and without bursts (a report held and delivered with the next one):
#   fire simulate wand --jitter-ms J --burst B -o w.log && fire calibrate w.log -o rig.json
#   fire simulate sketch --jitter-ms J --burst B -o s.log && fire track s.log --rig rig.json --truth
# A markdown table of reprojection_rms_px, static_rms_mm and dynamic_rms_mm per row, against the
# issue's targets at 4 ms with bursts (<= 0.35 px, <= 0.5 mm, <= 1.5 mm). Table on stdout, progress on stderr.
#
# usage: perf/tracking_jitter.sh [FIRE_BINARY]      (default: build/fire)
# env:   JITTERS (default "0.3 1 2.5 4 6"), BURSTS (default "0 0.1"), SEED (default 1)
set -u
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
read -r -a jitters <<<"${JITTERS:-0.3 1 2.5 4 6}"
read -r -a bursts <<<"${BURSTS:-0 0.1}"
seed="${SEED:-1}"
[ -x "$fire" ] || { echo "perf/tracking_jitter.sh: $fire not found; build it first (cmake --build build --target fire)" >&2; exit 2; }
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\)[,}].*/\1/p" <<<"$2"; }
fmt() { [ -n "$1" ] && awk -v x="$1" 'BEGIN { printf "%.2f", x }' || printf 'n/a'; }

echo "| jitter (ms) | burst | reprojection_rms_px | static_rms_mm | dynamic_rms_mm |"
echo "|---|---|---|---|---|"
for j in "${jitters[@]}"; do
  for b in "${bursts[@]}"; do
    echo "perf/tracking_jitter.sh: jitter $j ms, burst $b" >&2
    opts=(--seed "$seed" --rig-seed "$seed" --jitter-ms "$j" --burst "$b")
    "$fire" simulate wand "${opts[@]}" -o "$tmp/w.log" >/dev/null || { echo "| $j | $b | simulate failed | | |"; continue; }
    cal=$("$fire" calibrate "$tmp/w.log" -o "$tmp/rig.json") || { echo "| $j | $b | calibration failed | | |"; continue; }
    "$fire" simulate sketch "${opts[@]}" -o "$tmp/s.log" >/dev/null || { echo "| $j | $b | | simulate failed | |"; continue; }
    trk=$("$fire" track "$tmp/s.log" --rig "$tmp/rig.json" -o "$tmp/p.log" --truth) || { echo "| $j | $b | $(fmt "$(field reprojection_rms_px "$cal")") | tracking failed | |"; continue; }
    echo "| $j | $b | $(fmt "$(field reprojection_rms_px "$cal")") | $(fmt "$(field static_rms_mm "$trk")") | $(fmt "$(field dynamic_rms_mm "$trk")") |"
  done
done
