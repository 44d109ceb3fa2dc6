#!/usr/bin/env bash
# Marks measured by touch through the whole command line (issue 42, item 1): the simulated person measures the
# pawn's marks (cmd table, cmd measure N, cmd mark N) and draws its network; the replay writes the marks
# measured, which name marks of the true marks file; aligned on them, the surface lies within 2e-3 of the
# diagonal of the object, and 10 times further without them; the replay as a session reopens to the same hash
# and measured marks; and a log that measures nothing, a marks file with too few shared ids and a malformed
# measuring command are refused in words.
#   measured_marks.sh FIRE_BINARY WORK_DIR [whole | first-strokes]
# first-strokes (the sanitizer build): the first 40 strokes, without fire eval's measures (a refused --align
# still runs).
set -euo pipefail
fire="$1"
dir="$2"
extent="${3:-whole}"
case "$extent" in
  whole) strokes=() ;;
  first-strokes) strokes=(--max-strokes 40) ;;
  *) echo "measured_marks.sh: extent must be whole or first-strokes, not '$extent'" >&2; exit 2 ;;
esac
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
fail() { echo "FAIL: $*" >&2; exit 1; }
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\)[,}].*/\1/p" <<<"$2"; }

"$fire" simulate drawing --measure-marks "${strokes[@]}" -o d.log --marks-out marks.json --object-out pawn20.obj >sim.json
"$fire" simulate wand -o w.log >/dev/null
"$fire" calibrate w.log -o rig.json >/dev/null
[ "$(grep -c ' cmd table$' d.log)" -eq 3 ] || fail "the person did not touch the table 3 times: $(grep -c ' cmd table$' d.log)"
grep -q ' cmd measure [0-9]*$' d.log || fail "no mark measured in the log"
grep -q ' cmd mark [0-9]*$' d.log || fail "no measured mark touched for a later registration"
! grep -q ' cmd mark [0-9]* ' d.log || fail "a mark was touched at the marks file's coordinates"

"$fire" replay d.log --rig rig.json -o net.fnet --surface d.obj --measured-marks-out measured.json --hash >first.out 2>replay.err
! grep -q rejected replay.err || fail "rejections: $(grep rejected replay.err | head -3)"
grep -q "registration 1 (line [0-9]*): the object's frame from the table" replay.err ||
  fail "the first registration did not make the frame: $(cat replay.err)"
grep -q "registration 2 (line [0-9]*): [3-9] marks" replay.err || fail "no later registration on measured marks: $(cat replay.err)"
grep -q '"frame": "measured"' measured.json || fail "measured.json is not the measured marks: $(head -5 measured.json)"
measured_ids=$(grep -c '"id"' measured.json)
[ "$measured_ids" -ge 3 ] || fail "$measured_ids marks measured"

# Under the sanitizers (first-strokes) fire eval's sampling takes minutes: the alignment is checked in Release.
if [ "$extent" = whole ]; then
  aligned=$("$fire" eval d.obj --reference pawn20.obj --align marks.json measured.json)
  unaligned=$("$fire" eval d.obj --reference pawn20.obj)
  echo "aligned: $aligned"
  [ "$(field align_marks "$aligned")" = "$measured_ids" ] || fail "aligned on $(field align_marks "$aligned") marks, not $measured_ids"
  awk -v r="$(field align_residual "$aligned")" 'BEGIN {exit !(r >= 0 && r < 0.001)}' || fail "alignment residual over 1 mm: $aligned"
  awk -v a="$(field rms "$aligned")" -v u="$(field rms "$unaligned")" 'BEGIN {exit !(a > 0 && a <= 0.002 && u > 10 * a)}' ||
    fail "aligned rms $(field rms "$aligned"), unaligned $(field rms "$unaligned"): not where the object is"
fi

# As a session with snapshots (holding the measured marks): reopened, the same hash.
"$fire" replay d.log --rig rig.json --session session --snapshot-every 3000 --hash >session.out 2>/dev/null
[ "$(cat session.out)" = "$(cat first.out)" ] || fail "the session hashes to $(cat session.out), not $(cat first.out)"
reopened=$("$fire" replay session --hash --measured-marks-out reopened.json 2>reopen.err)
[ "$reopened" = "$(cat first.out)" ] || fail "the reopened session hashes to $reopened: $(cat reopen.err)"
grep -q "snapshot after frame" reopen.err || fail "reopened without a snapshot: $(cat reopen.err)"
cmp -s measured.json reopened.json || fail "the reopened session's measured marks differ"

# Refusals: no mark measured; fewer than 3 ids shared; a measuring command without its number.
awk '/ cmd (table|measure)/ {next} {print}' d.log >unmeasured.log
if "$fire" replay unmeasured.log --rig rig.json --no-surface --measured-marks-out none.json >/dev/null 2>none.err; then
  fail "a log that measures nothing wrote measured marks"
fi
grep -q "unmeasured.log measures no mark (cmd measure N), nothing to write to none.json" none.err || fail "$(cat none.err)"
grep -q "rejected: mark [0-9]*: not measured (no mark is)" none.err || fail "touches of unmeasured marks not named: $(head -3 none.err)"
python3 - measured.json >two.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["marks"] = m["marks"][:2]
print(json.dumps(m))
PY
if "$fire" eval d.obj --reference pawn20.obj --align marks.json two.json >/dev/null 2>two.err; then fail "aligned on 2 marks"; fi
grep -q -- "--align: 2 mark id(s) of two.json are in marks.json, at least 3 are needed" two.err || fail "$(cat two.err)"
sed '0,/ cmd measure [0-9]*$/s// cmd measure/' d.log >bad.log
if "$fire" replay bad.log --rig rig.json --no-surface >/dev/null 2>bad.err; then fail "a measure without its number replayed"; fi
grep -q "bad.log:[0-9]*: cmd measure needs the mark's number" bad.err || fail "$(cat bad.err)"
echo "measured marks: $measured_ids, $(grep -c ' cmd register$' d.log) registrations"
