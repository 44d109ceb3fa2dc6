#!/usr/bin/env bash
# The tracking commands end to end on a short scenario, as a user runs them:
#   commands.sh FIRE_BINARY WORK_DIR
# Checks that each prints one JSON line whose accuracy fields are finite numbers, that a damaged
# log still tracks with its bad reports counted, and that bad input fails with a message.
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"
# A finite JSON number for "key" (JSON has no NaN or infinity: those would be null or absent).
has_number() { # json key
  grep -Eq "\"$2\":-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?[,}]" <<<"$1" || fail "no finite \"$2\" in: $1"
}
one_line() { # output
  [ "$(printf '%s\n' "$1" | wc -l)" -eq 1 ] || fail "expected exactly one line of output, got: $1"
}

out=$("$fire" simulate wand --duration-s 10 --clock-offset-ms 5 --focal-error 0.02 -o w.log)
one_line "$out"
has_number "$out" duration_s
out=$("$fire" calibrate w.log -o rig.json)
one_line "$out"
for k in reprojection_rms_px wand_length_error_mm observations_used observations_rejected rejected_reports time_offset_ms; do
  has_number "$out" "$k"
done
[ -s rig.json ] || fail "rig.json not written"

out=$("$fire" simulate sketch --strokes 2 --hold-s 0.5 --clock-offset-ms 5 --focal-error 0.02 -o s.log)
one_line "$out"
for m in thesis dlt optimal; do
  out=$("$fire" track s.log --rig rig.json -o pen.log --truth --method "$m")
  one_line "$out"
  for k in static_rms_mm dynamic_rms_mm samples strokes rejected_reports time_offset_ms; do has_number "$out" "$k"; done
done
head -1 pen.log | grep -qx 'FIRE-LOG 3' || fail "pen.log is not an input log"
grep -q ' down$' pen.log && grep -q ' up$' pen.log && grep -q ' pen ' pen.log || fail "pen.log lacks down/pen/up"

# Hands passing in front of the cameras (0.5 occlusions per second per camera) do not break strokes:
# as many strokes are found as were drawn, and the resting pen is as accurate as in the same drawing
# without them (this short calibration is less accurate than the defaults' 60 s one).
static_of() { sed -n 's/.*"static_rms_mm":\([-+0-9.eE]*\)[,}].*/\1/p' <<<"$1"; }
"$fire" simulate sketch --strokes 6 --clock-offset-ms 5 --focal-error 0.02 -o clear.log >/dev/null
clear=$(static_of "$("$fire" track clear.log --rig rig.json -o pen3.log --truth)")
out=$("$fire" simulate sketch --strokes 6 --occlusion 0.5 --clock-offset-ms 5 --focal-error 0.02 -o occluded.log)
drawn=$(sed -n 's/.*"strokes":\([0-9]*\).*/\1/p' <<<"$out")
out=$("$fire" track occluded.log --rig rig.json -o pen3.log --truth)
found=$(sed -n 's/.*"strokes":\([0-9]*\).*/\1/p' <<<"$out")
[ "$drawn" = 6 ] && [ "$found" = "$drawn" ] || fail "occluded sketch: $drawn strokes drawn, $found found: $out"
static=$(static_of "$out")
awk -v x="$static" -v c="$clear" 'BEGIN { exit !(x <= 1.1 * c) }' ||
  fail "occluded sketch: static_rms_mm $static, more than 10 % above the unoccluded $clear"

# The whole frame from device bytes: fire replay --rig runs the same triangulation system as fire track, so
# its strokes are the same pen log's; the same replay twice gives the same hash.
h1=$("$fire" replay occluded.log --rig rig.json --hash -o occluded.fnet)
h2=$("$fire" replay occluded.log --rig rig.json --hash)
[ "$h1" = "$h2" ] || fail "fire replay --rig: two replays of one log differ: $h1 vs $h2"
tracked=$("$fire" replay pen3.log --hash)
[ "$tracked" = "$h1" ] || fail "fire replay --rig ($h1) and fire replay of fire track's pen log ($tracked) disagree"
expect_replay_error() { # what, pattern, arguments...
  local what="$1" pattern="$2"; shift 2
  if "$fire" replay "$@" >out.txt 2>err.txt; then fail "$what: succeeded"; fi
  grep -q "$pattern" err.txt || fail "$what: message lacks '$pattern': $(cat err.txt)"
}
expect_replay_error "replay of device reports without a rig" "give the rig they were drawn with: --rig" occluded.log
{ head -1 occluded.log; echo "0 meta device 0 00:1F:32:AA:BB:07 camera0 0306"; tail -n +2 occluded.log; } > other.log
sed '0,/{/s//{"remotes": [{"address": "00:1f:32:aa:bb:01", "role": "camera0"}],/' rig.json > other_rig.json
expect_replay_error "replay with the rig of other remotes" "was calibrated with 00:1F:32:AA:BB:01 as camera 0" other.log --rig other_rig.json
# Calibrating again over a rig file whose remotes a person assigned keeps them when the wand log names none.
cp other_rig.json recalibrated.json
"$fire" calibrate w.log -o recalibrated.json >/dev/null 2>err.txt || fail "calibrate over an existing rig failed: $(cat err.txt)"
grep -q '"address": "00:1f:32:aa:bb:01"' recalibrated.json || fail "calibrate dropped the rig's remotes: $(cat recalibrated.json)"
grep -q 'kept its "remotes"' err.txt || fail "calibrate did not say it kept the remotes: $(cat err.txt)"
# The rig it replaced is kept beside it, and said so; the same rig again replaces nothing.
cmp -s other_rig.json recalibrated.json.bak || fail "calibrate did not keep the replaced rig as recalibrated.json.bak"
grep -q "the rig it replaces is kept as recalibrated.json.bak" err.txt || fail "calibrate did not say where the old rig is: $(cat err.txt)"
rm recalibrated.json.bak
"$fire" calibrate w.log -o recalibrated.json >/dev/null 2>err.txt || fail "calibrating again failed: $(cat err.txt)"
[ ! -e recalibrated.json.bak ] || fail "an unchanged rig was backed up"

# Written as a session, the drawing keeps its rig: reopening it (last snapshot, then the tail) needs no
# --rig and gives the same hash; a session whose rig.json is gone is refused by name.
h3=$("$fire" replay occluded.log --rig rig.json --session tracked --snapshot-every 700 --hash)
[ "$h3" = "$h1" ] || fail "fire replay --rig --session ($h3) and fire replay --rig ($h1) disagree"
cmp -s rig.json tracked/rig.json || fail "the session folder's rig.json is not the rig it was written with"
h4=$("$fire" replay tracked --hash 2>reopen.txt)
[ "$h4" = "$h1" ] || fail "the reopened tracked session ($h4) is not the replay ($h1)"
grep -q "snapshot after frame" reopen.txt || fail "the tracked session reopened without its snapshot: $(cat reopen.txt)"
expect_replay_error "a session folder given --rig" "it replays with the rig.json it holds" tracked --rig rig.json
rm tracked/rig.json
expect_replay_error "a tracked session without its rig" "has no rig.json to triangulate them with" tracked

# The simulators write the session layout too: the same drawing as a folder with its rig replays, tracks
# and reopens as the bare log does; a wand session calibrates as its log does.
"$fire" simulate sketch --strokes 6 --occlusion 0.5 --clock-offset-ms 5 --focal-error 0.02 --session simulated \
  --rig rig.json >/dev/null
cmp -s rig.json simulated/rig.json || fail "fire simulate --session --rig: the folder's rig.json is not the rig"
h5=$("$fire" replay simulated --hash 2>/dev/null)
[ "$h5" = "$h1" ] || fail "the simulated session ($h5) and the simulated log with --rig ($h1) disagree"
"$fire" track simulated --rig rig.json -o pen4.log >/dev/null
grep -v ' meta source ' pen3.log > a.txt; grep -v ' meta source ' pen4.log > b.txt
cmp -s a.txt b.txt || fail "fire track of the simulated session and of the simulated log give different pen logs"
"$fire" simulate wand --duration-s 10 --clock-offset-ms 5 --focal-error 0.02 --session wand >/dev/null
"$fire" calibrate wand -o rig_session.json >/dev/null
cmp -s rig.json rig_session.json || fail "fire calibrate of the wand session and of the wand log give different rigs"
if "$fire" simulate sketch --strokes 1 --rig rig.json -o x.log >out.txt 2>err.txt; then fail "--rig without --session: succeeded"; fi
grep -q "requires --session" err.txt || fail "--rig without --session: $(cat err.txt)"

# Damage some reports: an odd hex digit count, a truncated report, an unknown id, a NaN truth line.
awk 'BEGIN{n=0} / hid /{n++; if (n==100) $4=$4"f"; if (n==200) $4=substr($4,1,10); if (n==300) $4="99" substr($4,3)}
     {print} / hid 0 /{if (!done && n>400) {print $1" truth pen 0 nan 0 0 0 1 0 0"; done=1}}' s.log > damaged.log
out=$("$fire" track damaged.log --rig rig.json -o pen2.log --truth)
one_line "$out"
has_number "$out" static_rms_mm
grep -q '"garbled":1,' <<<"$out" || fail "garbled report not counted: $out"
grep -q '"bad_length":1,' <<<"$out" || fail "truncated report not counted: $out"
grep -q '"unknown_id":1,' <<<"$out" || fail "unknown report id not counted: $out"
grep -q '"truth_lines_rejected":1' <<<"$out" || fail "NaN truth line not counted: $out"

# Bad input fails with a message naming the problem, and a non-zero exit.
expect_failure() { # what, command...
  local what="$1"; shift
  if "$@" >out.txt 2>err.txt; then fail "$what: succeeded"; fi
  grep -q "^fire " err.txt || fail "$what: no 'fire <command>: ...' message: $(cat err.txt)"
}
printf 'not a log\n' > junk.log
expect_failure "calibrate a file that is not a log" "$fire" calibrate junk.log -o x.json
expect_failure "calibrate a log without wand" "$fire" calibrate pen.log -o x.json
expect_failure "track with a missing rig" "$fire" track s.log --rig missing.json -o x.log
printf '{"format":"fire-rig"' > broken.json
expect_failure "track with a broken rig" "$fire" track s.log --rig broken.json -o x.log
expect_failure "track --truth on a log without truth" "$fire" track pen.log --rig rig.json -o x.log --truth
expect_failure "simulate with a NaN option" "$fire" simulate wand --noise-px nan -o x.log
expect_failure "track with a NaN filter option" "$fire" track s.log --rig rig.json -o x.log --beta nan

# Remotes by their Bluetooth address: a wand log whose device records name the remotes gives a rig that
# names them; a drawing by the same remotes tracks (the pad's reports counted apart, not rejected), one
# by another camera is refused with both addresses.
records() { # camera0 camera1
  printf '0 meta device 0 %s camera0 0306\n0 meta device 1 %s camera1 0306\n0 meta device 2 00:1F:32:AA:BB:03 pad 0306\n' "$1" "$2"
}
named() { # log camera0 camera1 -> the log with device records after its header, and a pad report
  { head -1 "$1"; records "$2" "$3"; tail -n +2 "$1"; echo "999999999 hid 2 3000"; }
}
named w.log 00:1F:32:AA:BB:01 00:1F:32:AA:BB:02 > w_named.log
"$fire" calibrate w_named.log -o rig_named.json >/dev/null
grep -qi '"address": "00:1f:32:aa:bb:01"' rig_named.json && grep -q '"role": "pad"' rig_named.json ||
  fail "the rig does not name the calibrated remotes: $(cat rig_named.json)"
named s.log 00:1f:32:aa:bb:01 00:1F:32:AA:BB:02 > s_named.log
out=$("$fire" track s_named.log --rig rig_named.json -o x.log)
grep -q '"pad":1,' <<<"$out" && grep -q '"unknown_device":0,' <<<"$out" || fail "the pad's report was not counted apart: $out"
named s.log 00:1F:32:AA:BB:01 00:1F:32:AA:BB:09 > s_other.log
expect_failure "track a drawing by other remotes than the rig's" "$fire" track s_other.log --rig rig_named.json -o x.log
grep -qi "camera 1 is the remote 00:1f:32:aa:bb:09" err.txt && grep -qi "calibrated with 00:1f:32:aa:bb:02" err.txt ||
  fail "the other remote is not named: $(cat err.txt)"
echo "tracking commands: ok"
