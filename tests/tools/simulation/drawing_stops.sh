#!/usr/bin/env bash
# The simulated person says so when it cannot draw every curve:
#   drawing_stops.sh FIRE_BINARY WORK_DIR MESHES_DIR
# The pawn with a closed box hidden inside its head (the pawn is open at its base: lower down, a camera sees a
# box through it when the pawn is upside down): the pawn is drawn whole, then the box, a second part, would
# start with a border loop of its own that no camera sees, so `fire simulate drawing` exits 1 naming what it
# could not draw, why, and how many curves it drew; --max-strokes still stops a drawing early with exit 0. The
# rook, whose only border is a 3 mm hole, is refused before it starts.
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"
meshes="$3"
awk '
  /^v / { print "v", $2, $3, $4; n++ }
  /^f / { line = "f"; for (i = 2; i <= NF; i++) { split($i, idx, "/"); line = line " " idx[1] } print line }
  END {
    s = 0.02
    for (z = 0; z < 2; z++) for (y = 0; y < 2; y++) for (x = 0; x < 2; x++) print "v", 1.737 + x * s, -1.285 + y * s, 0.45 + z * s
    print "f", n + 1, n + 3, n + 4, n + 2; print "f", n + 5, n + 6, n + 8, n + 7; print "f", n + 1, n + 2, n + 6, n + 5
    print "f", n + 3, n + 7, n + 8, n + 4; print "f", n + 1, n + 5, n + 7, n + 3; print "f", n + 2, n + 4, n + 8, n + 6
  }' "$meshes/pawn.obj" > pawn_and_box.obj

if "$fire" simulate drawing --mesh pawn_and_box.obj -o d.log --marks-out m.json --object-out o.obj >out.txt 2>err.txt; then
  fail "a drawing that cannot reach the hidden box succeeded: $(cat out.txt)"
fi
grep -q "part of the first border loop of part 2 of the network is seen whole by both cameras in no pose" err.txt ||
  fail "the box's border not named, or no reason given: $(cat err.txt)"
grep -q "; 324 of 336 curves drawn" err.txt || fail "not the pawn's 324 of 336 curves: $(cat err.txt)"
[ ! -e d.log ] || fail "a log was written for a drawing that failed"

# The rook's only border is a hole 3 mm across under its base: its strokes would be touches, not curves.
if "$fire" simulate drawing --mesh "$meshes/rook.obj" -o r.log --marks-out m.json --object-out o.obj >out.txt 2>err.txt; then
  fail "the rook's 3 mm border was drawn: $(cat out.txt)"
fi
grep -q "the first border loop of the network (through (.*), 9.48 mm round) has a stroke 0.79 mm long, under the 5.00 mm a tracked pen draws" err.txt ||
  fail "the rook's border too small to draw is not named: $(cat err.txt)"
[ ! -e r.log ] || fail "a log was written for the rook's drawing that failed"

out=$("$fire" simulate drawing --mesh pawn_and_box.obj --max-strokes 3 -o d.log --marks-out m.json --object-out o.obj) ||
  fail "--max-strokes 3 did not exit 0"
grep -q '"curves_total":336' <<<"$out" || fail "the summary does not give the curves total: $out"
echo "drawing stops: ok"
