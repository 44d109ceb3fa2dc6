#!/usr/bin/env bash
# The simulated pawn drawn through the simulated remotes, seed 2, reconstructed without folds (perf/folds.py):
# - its pole holds the 12 curves drawn to it: a meridian's end on the head's ring, which the cameras see within
#   3 degrees of the surface, was judged against the direction to the camera and went into a thin face 10 mm
#   away, dragging the curve through the pole between two ring vertices (11 curves there);
# - its pole and head ring do not fold: curves leave their vertices a millimetre off, and those a few degrees
#   apart crossed near the pole (101 face pairs over 60 degrees; 57 with 12 curves at the pole) until the
#   surface took them straight from their vertices (kEndStraightNoises).
# And seed 11, whose base border does not fold: the pen rests where two border strokes meet and drifts a
# millimetre there, and the border's turn read inside that rest made vertices of the smooth border corners of the
# surface (22 face pairs over 60 degrees) until the turn was read past the rest (kPauseNoises).
set -u
fire="$1"; folds="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$fire" simulate wand -o "$tmp/wand.log" >/dev/null || exit 1
"$fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null 2>&1 || exit 1
for seed in 2 11; do
  "$fire" simulate drawing --seed $seed -o "$tmp/d.log" --marks-out "$tmp/marks.json" --object-out "$tmp/pawn.obj" \
    >/dev/null || exit 1
  "$fire" replay "$tmp/d.log" --rig "$tmp/rig.json" --no-surface -o "$tmp/d.fnet" >/dev/null 2>&1 || exit 1
  "$fire" reconstruct "$tmp/d.fnet" -o "$tmp/d.obj" >/dev/null || exit 1
  python3 "$folds" "$tmp/d.obj" >"$tmp/folds.json" || exit 1
  pairs=$(sed -n 's/.*"pairs_over_60_deg": \([0-9]*\).*/\1/p' "$tmp/folds.json")
  pole=$(python3 -c "
import json, sys
net = json.load(open(sys.argv[1]))
valence = [0] * len(net['vertices'])
for e in net['edges']:
    for v in e['v']: valence[v] += 1
print(max(valence))" "$tmp/d.fnet")
  if [ "$pole" = 12 ] && [ "$pairs" = 0 ]; then
    echo "ok: simulated pawn, seed $seed: 12 curves at the pole, no face pair over 60 degrees"
  else
    echo "FAILED: simulated pawn, seed $seed: ${pole:-?} curves at the pole (12)," \
      "${pairs:-?} face pairs over 60 degrees (0)"
    exit 1
  fi
done
