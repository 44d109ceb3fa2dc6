#!/usr/bin/env bash
# From device bytes to a surface (issue 10, item 6): a simulated person registers the pawn on marks and draws
# its K = 2 network through the simulated rig; the replay with the calibrated (not the true) rig gives the
# whole network and a surface within 0.005 of the diagonal of the pawn's limit surface, the same hash twice;
# and a registration on 2 marks is rejected in words, the replay going on.
#   drawing.sh FIRE_BINARY WORK_DIR [whole | first-strokes]
# first-strokes (the sanitizer build): the first 40 strokes only, without the checks that need the whole
# network (its counts, the second registration, the rms against the pawn).
set -euo pipefail
fire="$1"
dir="$2"
extent="${3:-whole}"
case "$extent" in
  whole) strokes=() ;;
  first-strokes) strokes=(--max-strokes 40) ;;
  *) echo "drawing.sh: extent must be whole or first-strokes, not '$extent'" >&2; exit 2 ;;
esac
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
fail() { echo "FAIL: $*" >&2; exit 1; }
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\)[,}].*/\1/p" <<<"$2"; }

"$fire" simulate drawing "${strokes[@]}" -o d.log --marks-out marks.json --object-out pawn20.obj >sim.json
"$fire" simulate wand -o w.log >/dev/null
"$fire" calibrate w.log -o rig.json >/dev/null
grep -q '"marks": \[' marks.json || fail "marks.json lists no marks: $(cat marks.json)"
[ "$(grep -c '^v ' pawn20.obj)" -eq "$(grep -c '^v ' "$(dirname "$0")/../../data/meshes/pawn.obj")" ] ||
  fail "pawn20.obj is not the pawn's control mesh"

# The whole network, every stroke accepted, the same hash twice.
"$fire" replay d.log --rig rig.json -o net.fnet --surface d.obj --surface d.stl --hash --timings >first.out 2>replay.err
"$fire" replay d.log --rig rig.json -o net2.fnet --surface d2.obj --hash --timings >second.out 2>/dev/null
! grep -q rejected replay.err || fail "strokes rejected: $(grep rejected replay.err | head -3)"
if [ "$extent" = whole ]; then
  grep -q "registration 2 (line [0-9]*): [3-6] marks" replay.err || fail "the object was not registered again: $(cat replay.err)"
  grep -q "^vertices 169 edges 324 faces 156 " first.out || fail "not the pawn's K = 2 network: $(grep vertices first.out)"
fi
hash1=$(grep -E '^[0-9a-f]{16}$' first.out)
hash2=$(grep -E '^[0-9a-f]{16}$' second.out)
[ -n "$hash1" ] && [ "$hash1" = "$hash2" ] || fail "two replays of one log hash to $hash1 and $hash2"
cmp -s net.fnet net2.fnet || fail "two replays of one log write different networks"

echo "drawing: $(cat sim.json)"
if [ "$extent" = whole ]; then
  eval_out=$("$fire" eval d.obj --reference pawn20.obj --network net.fnet)
  rms=$(field rms "$eval_out")
  awk -v r="$rms" 'BEGIN {exit !(r > 0 && r <= 0.005)}' || fail "rms $rms of the diagonal, at most 0.005 wanted: $eval_out"
  echo "eval: $eval_out"
  # A default STL is in millimetres: the 20 cm pawn stands about 200 units tall in it.
  height=$(python3 -c 'import struct, sys
data = open(sys.argv[1], "rb").read()
n = struct.unpack_from("<I", data, 80)[0]
z = [struct.unpack_from("<f", data, 84 + 50 * t + 12 + 12 * k + 8)[0] for t in range(n) for k in range(3)]
print(max(z) - min(z))' d.stl)
  awk -v h="$height" 'BEGIN {exit !(h > 195 && h < 205)}' || fail "the STL of the 20 cm pawn is $height units tall, about 200 (mm) wanted"
  echo "stl height: $height"
fi

# The first registration with its third mark left out: 2 marks, rejected in words, the log replays on.
awk '/ cmd mark / && ++n == 3 {next} {print} / cmd register$/ {exit}' d.log >two.log
"$fire" replay two.log --rig rig.json --no-surface 2>two.err >/dev/null || fail "two.log does not replay: $(cat two.err)"
grep -q "^two.log:[0-9]*: rejected: register: 2 mark(s) touched since the last registration, a registration needs at least 3" two.err ||
  fail "no rejection of the 2-mark registration naming its line: $(cat two.err)"
grep -q "2 mark(s) touched after the last registration, not registered" two.err ||
  fail "the marks touched were not kept: $(cat two.err)"

# As a session folder with the rig's copy, snapshots on the way (each holding the triangulation and the
# registration state): reopened from its last snapshot and from its log alone, the same hash as the replay.
"$fire" replay d.log --rig rig.json --session session --snapshot-every 4000 --hash >session.out 2>/dev/null
[ "$(cat session.out)" = "$hash1" ] || fail "written as a session the drawing hashes to $(cat session.out), not $hash1"
ls session/snapshot-*.fsnap >/dev/null || fail "the session holds no snapshot"
reopened=$("$fire" replay session --hash 2>reopen.err)
[ "$reopened" = "$hash1" ] || fail "the reopened session hashes to $reopened, not $hash1: $(cat reopen.err)"
grep -q "snapshot after frame" reopen.err || fail "the session reopened without its snapshot: $(cat reopen.err)"
"$fire" simulate drawing "${strokes[@]}" --session simulated --rig rig.json --marks-out marks2.json --object-out pawn20b.obj >/dev/null
cmp -s marks.json simulated/marks.json || fail "the simulated session's marks.json is not the drawing's marks"
from_folder=$("$fire" replay simulated --hash 2>/dev/null)
[ "$from_folder" = "$hash1" ] || fail "the simulated session folder hashes to $from_folder, not $hash1"
