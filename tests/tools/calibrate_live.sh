#!/usr/bin/env bash
# fire calibrate --live against fake remotes (the --fake-rig hook): it records a session folder, shows
# each camera's progress and the bundle adjustment converging, and writes the rig that the offline
# fire calibrate gives on that folder, byte for byte.
#   calibrate_live.sh FIRE_BINARY WORK_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../work_dir.sh"

"$fire" calibrate --live --fake-rig 7 --session live --samples 600 --coverage 0.3 --max-seconds 30 -o live.json \
  >live.out 2>live.err </dev/null || fail "calibrate --live failed: $(cat live.err)"
grep -q "camera 0: [0-9]* wand samples, [0-9]*% of the image covered; camera 1: [0-9]*, [0-9]*%" live.err ||
  fail "no progress per camera on stderr: $(cat live.err)"
grep -q "both cameras have seen enough of the wand" live.err || fail "did not stop on coverage: $(cat live.err)"
grep -q '^[0-9]* hid 0 33' live/input.log || fail "no camera 0 reports in the session's input.log"
grep -q '^[0-9]* meta device 1 00:1F:32:FA:CE:01 camera1 0306$' live/input.log || fail "no device record of camera 1"
"$fire" calibrate live -o offline.json >offline.out 2>offline.err || fail "offline calibrate failed: $(cat offline.err)"
cmp live.json offline.json || fail "the live rig differs from the offline one on the same reports"
rms=$(sed -n 's/.*"reprojection_rms_px":\([0-9.e-]*\).*/\1/p' live.out)
awk -v r="$rms" 'BEGIN { exit !(r > 0 && r < 1) }' || fail "reprojection RMS $rms px"
# The bundle adjustment converging, on stderr; its last word is the rig's RMS to the printed precision.
ba_line='^fire calibrate: bundle adjustment pass [0-9]*'
grep -q "$ba_line, iteration 0: reprojection [0-9.]* px (camera 0 [0-9.]*, camera 1 [0-9.]*), [0-9]* wand frames$" live.err ||
  fail "no bundle adjustment start on stderr: $(cat live.err)"
grep -q "$ba_line, iteration [1-9][0-9]*: reprojection" live.err || fail "no bundle adjustment iteration on stderr: $(cat live.err)"
last=$(grep "$ba_line" live.err | tail -1)
echo "$last" | grep -q "$ba_line converged after [0-9]* iterations: reprojection [0-9.]* px" ||
  fail "the last bundle adjustment line is not its end: $last"
printed=$(echo "$last" | sed 's/.*: reprojection \([0-9.]*\) px.*/\1/')
[ "$printed" = "$(awk -v r="$rms" 'BEGIN { printf "%.3f", r }')" ] || fail "last printed RMS $printed px, the rig's $rms px"
echo "live and offline rigs equal; $(tail -1 live.err); $(cat live.out)"

# Misuse is said in words.
if "$fire" calibrate --live -o x.json 2>nosession.err; then fail "--live without --session succeeded"; fi
grep -q "give --session DIR" nosession.err || fail "no word on --session: $(cat nosession.err)"
if "$fire" calibrate --live --fake-rig 7 --session live -o x.json 2>again.err; then fail "recorded into a used folder"; fi
grep -q "live" again.err || fail "the used folder is not named: $(cat again.err)"
if "$fire" calibrate --live --fake-rig 7 --session other --max-seconds nan -o x.json 2>nan.err; then fail "--max-seconds nan accepted"; fi
grep -q "max-seconds must be" nan.err || fail "no word on --max-seconds: $(cat nan.err)"
# Without remotes (no --fake-rig; this machine has none, or they are not cameras) no folder is left behind.
if "$fire" calibrate --live --session none --max-seconds 1 -o x.json 2>none.err </dev/null; then
  echo "calibrate --live found remotes here: the no-remote case is not checked"
else
  [ ! -e none ] || fail "a failed --live start left the folder none: $(cat none.err)"
fi
