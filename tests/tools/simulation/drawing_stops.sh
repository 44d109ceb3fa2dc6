#!/usr/bin/env bash
# The simulated person says so when it cannot draw every curve:
#   drawing_stops.sh FIRE_BINARY WORK_DIR MESHES_DIR box|rook
# box: the pawn with a closed box hidden inside its head (the pawn is open at its base: lower down, a camera sees
# a box through it when the pawn is upside down): the pawn is drawn whole, then the box, a second part, would
# start with a border loop of its own that no camera sees, so `fire simulate drawing` exits 1 naming what it
# could not draw, why, and how many curves it drew; --max-strokes still stops a drawing early with exit 0.
# rook: its only border, a hole 3 mm across under its base, is closed (no stroke draws round it), and the rook is
# drawn as a closed object up to the notches of its crenellations, which it names.
source "$(dirname "${BASH_SOURCE[0]}")/../../work_dir.sh"
meshes="$3"
if [ "$4" = rook ]; then
  if "$fire" simulate drawing --mesh "$meshes/rook.obj" -o r.log --marks-out m.json --object-out o.obj >out.txt 2>err.txt; then
    fail "the rook's notches were drawn, or its plan has changed: $(cat out.txt)"
  fi
  # The border loop too small to draw is closed: the drawing starts at all and gets to the notches.
  grep -q "cannot draw curve 472 (from (.*)): every stroke that would draw it is one the sketch would take otherwise" err.txt ||
    fail "the rook's first notch is not named: $(cat err.txt)"
  grep -q "; 613 of 626 curves drawn" err.txt || fail "not the rook's 613 of 626 curves: $(cat err.txt)"
  [ ! -e r.log ] || fail "a log was written for the rook's drawing that failed"
  echo "drawing stops: ok (rook)"
  exit 0
fi

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

out=$("$fire" simulate drawing --mesh pawn_and_box.obj --max-strokes 3 -o d.log --marks-out m.json --object-out o.obj) ||
  fail "--max-strokes 3 did not exit 0"
grep -q '"curves_total":336' <<<"$out" || fail "the summary does not give the curves total: $out"
echo "drawing stops: ok"
