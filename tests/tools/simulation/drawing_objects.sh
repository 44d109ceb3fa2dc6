#!/usr/bin/env bash
# Objects other than the pawn, drawn through the simulated remotes and replayed through every frame system
# (issue 40): drawing_objects.sh FIRE_BINARY WORK_DIR MESHES_DIR OBJECT EULER LOOPS [SIMULATE OPTIONS...]
# The simulated person draws every curve of OBJECT; the replay rejects no stroke and leaves nothing pending; the
# surface has the object's Euler characteristic and border loops, and fire eval's rms is within 2e-3 of the
# diagonal. The summary's counts are checked where the options ask for them: `--turns 3` on the lampshade
# draws curves in pieces, continued after the object is turned and registered again. HOLES=N: at least N holes
# opened. RMS=F: the most fire eval's rms may be (default 2e-3). SHARP=N (issue 44): a creased object's crease
# curves, at least N, marked sharp and still sharp after the replay, and the surface bends across each within 10
# degrees of the object's limit surface (fire eval). SHARP_EARLY=1: some are sharp already at a third of the strokes
# (the person marks them as they are drawn; the ridge's get their second face later).
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"
meshes="$3" object="$4" euler="$5" loops="$6"
shift 6
field() { sed -n "s/.*\"$1\": *\([-+0-9.eE]*\).*/\1/p" "$2" | head -1; }

"$fire" simulate wand -o wand.log >/dev/null
"$fire" calibrate wand.log -o rig.json >/dev/null 2>&1 || fail "the wand did not calibrate"
"$fire" simulate drawing --mesh "$meshes/$object.obj" "$@" -o drawing.log --marks-out marks.json --object-out object.obj \
  >drawing.json 2>err.txt || fail "$object was not drawn: $(cat err.txt)"
[ "$(field curves_drawn drawing.json)" = "$(field curves_total drawing.json)" ] || fail "not every curve drawn: $(cat drawing.json)"
"$fire" replay drawing.log --rig rig.json -o drawing.fnet --surface surface.obj >/dev/null 2>replay.txt || fail "replay failed: $(cat replay.txt)"
! grep -q "rejected" replay.txt || fail "the replay rejected strokes: $(grep rejected replay.txt | head -3)"
! grep -q "pending" replay.txt || fail "the replay left a stroke pending: $(grep pending replay.txt)"
"$fire" eval surface.obj --reference object.obj --network drawing.fnet >eval.json 2>/dev/null || fail "fire eval failed"
[ "$(field euler_characteristic eval.json)" = "$euler" ] && [ "$(field border_loops eval.json)" = "$loops" ] ||
  fail "the surface's Euler characteristic and border loops are not $euler and $loops: $(cat eval.json)"
[ "$(field reference_euler_characteristic eval.json)" = "$euler" ] || fail "the object's Euler characteristic is not $euler"
awk -v r="$(field rms eval.json)" -v most="${RMS:-2e-3}" 'BEGIN { exit !(r <= most) }' ||
  fail "rms $(field rms eval.json) is over ${RMS:-2e-3} of the diagonal"
case " $* " in
  *" --turns 3 "*) [ "$(field pieces drawing.json)" -ge 1 ] || fail "no curve was drawn in pieces: $(cat drawing.json)" ;;
esac
[ "$(field holes drawing.json)" -ge "${HOLES:-0}" ] || fail "fewer than ${HOLES:-0} holes opened: $(cat drawing.json)"
if [ "${SHARP:-0}" -gt 0 ]; then
  [ "$(field sharp drawing.json)" -ge 1 ] || fail "no curve marked sharp: $(cat drawing.json)"
  [ "$(field sharp_curves eval.json)" -ge "$SHARP" ] || fail "the replayed network has fewer than $SHARP sharp curves: $(cat eval.json)"
  awk -v e="$(field crease_error_max_deg eval.json)" 'BEGIN { exit !(e != "" && e <= 10) }' ||
    fail "the surface does not keep the creases: $(cat eval.json)"
fi
if [ -n "${SHARP_EARLY:-}" ]; then
  "$fire" replay drawing.log --rig rig.json --until-stroke $(($(field strokes drawing.json) / 3)) -o third.fnet \
    --surface third.obj >/dev/null 2>&1 || fail "the replay to a third of the strokes failed"
  "$fire" eval third.obj --reference object.obj --network third.fnet >third.json 2>/dev/null || fail "fire eval at a third failed"
  [ "$(field sharp_curves third.json)" -ge 1 ] || fail "no curve is sharp at a third of the strokes: $(cat third.json)"
fi
echo "$object drawn: $(field curves_drawn drawing.json) curves, $(field poses drawing.json) poses, $(field pieces drawing.json) pieces, rms $(field rms eval.json), crease error $(field crease_error_max_deg eval.json) degrees"
