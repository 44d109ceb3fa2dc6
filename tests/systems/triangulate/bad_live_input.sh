#!/usr/bin/env bash
# Bad live input through the simulated rig and the whole frame (fire replay --rig): each kind of damage
# is counted, said in words on stderr naming the log, and leaves the drawing intact; none crashes.
#   bad_live_input.sh FIRE_BINARY WORK_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"

"$fire" simulate wand --duration-s 10 -o w.log >/dev/null
"$fire" calibrate w.log -o rig.json >/dev/null
"$fire" simulate sketch --strokes 6 --hold-s 0.5 --stray 0 -o s.log >/dev/null
edges_of() { sed -n 's/^vertices [0-9]* edges \([0-9]*\) .*/\1/p' <<<"$1"; }
clean=$(edges_of "$("$fire" replay s.log --rig rig.json --timings 2>clean.err)")
[ ! -s clean.err ] || fail "the undamaged drawing reports problems: $(cat clean.err)"
[ "$clean" -ge 6 ] || fail "the clean drawing gives $clean edges for 6 strokes"

# case NAME MIN_EDGES PATTERN: replays NAME.log, expecting success, a message with PATTERN naming the log,
# and at least MIN_EDGES curves kept.
case_() {
  local name="$1" min="$2" pattern="$3" out
  out=$("$fire" replay "$name.log" --rig rig.json --timings 2>"$name.err") || fail "$name: replay failed: $(cat "$name.err")"
  grep -q "^$name.log.*$pattern" "$name.err" || fail "$name: no message '$pattern' naming $name.log: $(cat "$name.err")"
  local edges
  edges=$(edges_of "$out")
  [ "$edges" -ge "$min" ] || fail "$name: $edges curves kept, expected at least $min"
  echo "$name: $edges of $clean curves; $(tr '\n' ' ' <"$name.err")"
}
# IR slot S of a report line's hex (field 4): 3 bytes from hex character 12 + 6 S.
slot() { echo "substr(\$4, 1, 12 + 6 * $1) $2 substr(\$4, 19 + 6 * $1)"; }

# A logged pen sample that is not a number, in the middle of a tracked stroke: that stroke is refused
# with its line, the others stay.
awk '{print} / hid 0 /{n++; if (n == 600) {print $1" pen nan 0 0"; print $1" pen inf 0 0"}}' s.log > nan.log
case_ nan $((clean - 1)) "rejected: the stroke has a pen sample that is not finite"
# Blobs outside the camera's pixels (y = 800) in every 50th report of camera 0.
awk "/ hid 0 /{n++; if (n % 50 == 0) \$4 = $(slot 0 '"0520c0"')} {print}" s.log > out_of_range.log
case_ out_of_range "$clean" "IR blob(s) outside the camera's 1024 x 768 pixels: dropped"
# Time going backwards: a camera 1 report stamped 30 ms before the one above it.
awk '/ hid 1 /{n++; if (n == 700) $1 = $1 - 30000} {print}' s.log > backwards.log
case_ backwards "$clean" "stamped earlier than their remote's previous report (time going backwards): dropped"
# A report delivered twice.
awk '{print} / hid 0 /{n++; if (n % 300 == 0) print}' s.log > duplicated.log
case_ duplicated "$clean" "repeating their remote's previous report at the same instant (sent twice, or held and sent with the next): kept"
# Camera 1 stops reporting halfway (switched off): the curves drawn before are kept.
half=$(awk '/ hid 1 /{t = $1} END {print int(t / 2)}' s.log)
awk -v half="$half" '!(/ hid 1 / && $1 > half)' s.log > stopped.log
awk -v half="$half" 'NR == 1 || $1 <= half' s.log > first_half.log
before=$(edges_of "$("$fire" replay first_half.log --rig rig.json --timings)")
case_ stopped "$before" "time(s) camera 1 stopped reporting for more than 0.5 s (silent at the end)"
# Both cameras lose the lit pen for 150 ms in the middle of the drawing (a hand over both): bridged, the
# strokes stay as many as drawn; the IR slots emptied (ff ff ff).
# (from the middle on, the first camera 0 report lit 10 reports back and 40 ahead: inside a stroke)
mid=$(awk '/ hid 0 / && substr($4, 13, 6) != "ffffff" {t[n++] = $1}
           END {for (i = int(n / 2); i + 40 < n; i++) if (t[i + 40] - t[i] < 420000 && t[i] - t[i - 10] < 110000) {print t[i]; exit}}' s.log)
awk -v a="$mid" -v b="$((mid + 150000))" "/ hid / && \$1 >= a && \$1 < b {\$4 = substr(\$4, 1, 12) \"ffffffffffffffffffffffff\" substr(\$4, 37)} {print}" s.log > both_lost.log
case_ both_lost "$clean" "time(s) neither camera saw the pen for a moment in the middle of a stroke"
out=$("$fire" replay both_lost.log --rig rig.json --timings 2>/dev/null)
[ "$(edges_of "$out")" = "$clean" ] || fail "both_lost: $(edges_of "$out") curves instead of the $clean drawn"
# A stray reflection that moves across camera 1's image (slot 3), for the whole drawing.
awk '/ hid 1 /{n++; x = (100 + 3 * n) % 1024; y = 300; b = sprintf("%02x%02x%02x", x % 256, y % 256, int(y / 256) * 64 + int(x / 256) * 16 + 3);
     $4 = substr($4, 1, 30) b substr($4, 37)} {print}' s.log > stray.log
case_ stray "$clean" "from frames that also showed another light (a reflection)"
# Garbled and cut-short reports.
awk '/ hid 0 /{n++; if (n == 400) $4 = $4 "z"; if (n == 800) $4 = substr($4, 1, 10)} {print}' s.log > garbled.log
case_ garbled "$clean" "device report(s) cut short for their report id: skipped (longer ones are read for their layout's bytes)"
grep -q "device report(s) garbled (not hexadecimal, or empty): skipped" garbled.err ||
  fail "garbled: the garbled line is not reported: $(cat garbled.err)"
# Reports far from a remote's 100 Hz: from halfway on, two of every three reports lost (a weak link); the
# curves drawn before are kept.
awk -v half="$half" '/ hid / && $1 > half {n[$3]++; if (n[$3] % 3 != 0) next} {print}' s.log > thinned.log
case_ thinned "$before" "camera 0 reports at 33 Hz, far from the 100 Hz of a Wii Remote streaming IR"
# ... and a device reporting at 250 Hz, which no Wii Remote does: said, and tracked all the same.
"$fire" simulate sketch --strokes 6 --hold-s 0.5 --stray 0 --rate-hz 250 -o fast.log >/dev/null
case_ fast "$clean" "camera 1 reports at 25[0-9] Hz, far from the 100 Hz"
# A device whose record names a product that is no Wii Remote's (a keyboard claiming camera 1's role)
# sends reports of its own: they are skipped, the remotes' drawing is whole.
awk 'NR == 1 {print; print "0 meta device 0 00:1F:32:AA:BB:01 camera0 0306"; print "0 meta device 1 00:1F:32:AA:BB:02 camera1 0330";
              print "0 meta device 2 00:1F:32:AA:BB:07 camera1 0001"; next}
     {print} / hid 1 /{n++; if (n % 7 == 0) {$3 = 2; $4 = substr($4, 1, 12) "7f7f00" substr($4, 19); print}}' s.log > not_a_remote.log
case_ not_a_remote "$clean" "device record(s) that do not read as D ADDRESS ROLE PRODUCT or name a product that is no Wii Remote's"
grep -q "report(s) from a device the log names as no camera: skipped" not_a_remote.err ||
  fail "not_a_remote: the other device's reports are not reported: $(cat not_a_remote.err)"
out=$("$fire" replay not_a_remote.log --rig rig.json --timings 2>/dev/null)
[ "$(edges_of "$out")" = "$clean" ] || fail "not_a_remote: $(edges_of "$out") curves instead of the $clean drawn"
