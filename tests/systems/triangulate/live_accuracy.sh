#!/usr/bin/env bash
# The live path's accuracy on the simulated rig against the batch tracker it replaced (perf/notes/tracking.md,
# "Tracking accuracy", defaults, seed 1, optimal: static_rms_mm 0.340, dynamic_rms_mm 0.978, 12 strokes,
# measured 2026-11-24 with the whole-log frame clock and time offset): fire track now runs the
# triangulation system frame by frame, and must stay within 5 % of those figures.
#   live_accuracy.sh FIRE_BINARY WORK_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\)[,}].*/\1/p" <<<"$2"; }

"$fire" simulate wand --seed 1 --rig-seed 1 -o w.log >/dev/null
"$fire" calibrate w.log -o rig.json >/dev/null
"$fire" simulate sketch --seed 1 --rig-seed 1 -o s.log >/dev/null
out=$("$fire" track s.log --rig rig.json -o pen.log --truth --method optimal)
static=$(field static_rms_mm "$out")
dynamic=$(field dynamic_rms_mm "$out")
strokes=$(field strokes "$out")
echo "live path: static_rms_mm $static (batch 0.340), dynamic_rms_mm $dynamic (batch 0.978), strokes $strokes"
[ "$strokes" = 12 ] || fail "12 strokes drawn, $strokes found: $out"
awk -v s="$static" -v d="$dynamic" 'BEGIN { exit !(s <= 1.05 * 0.340 && d <= 1.05 * 0.978) }' ||
  fail "the live path is more than 5 % less accurate than the batch tracker was: $out"
