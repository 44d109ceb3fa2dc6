#!/usr/bin/env bash
# `fire reconstruct` without folds (perf/folds.py counts face pairs over 60 degrees):
# - the rook's K = 2 network without noise (perf/quality.sh's row): the curve along the foot's widest ring
#   bends faster than the surface can follow, and when the fit's targets could gather there the surface
#   folded across it (338 pairs); its last 2 pairs were in one sliver triangle (face 186, a corner of 148
#   degrees), which went when exact curves kept their thin quads' shape term at the fairness's weight;
# - the rook's K = 2 network at 2 % noise: the 24 curves 0.0013 long around the hole in its bottom become
#   scribbles as long as the noise, which crossed their neighbours' and folded the surface there (31 pairs;
#   10 while such curves only weighed less in the fit), until the surface took such short curves nearer
#   their chords (kShortCurveNoises: those 24 and one more; 1 pair), and the last pair, at a battlement
#   notch where two curves meet at a vertex of valence 2, went when noisy curves were joined there
#   (joined_vertices: 5 such vertices; 0 pairs);
# - the demo dome (tools/demo/sketch.log), hand-drawn: its thin faces split into thin base quads, and
#   before the fit's shape term (FitWeights::shape) the surface folded in them (48 pairs, 182 faces
#   facing down).
set -u
fire="$1"; meshes="$2"; folds="$3"; demo="$4"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
count() { sed -n "s/.*\"$1\": \([0-9]*\).*/\1/p" "$2"; }
status=0

"$fire" network-from-mesh "$meshes/rook.obj" --unrefine 2 --noise 0 --seed 1 --limit -o "$tmp/rook.fnet" >/dev/null || exit 1
"$fire" reconstruct "$tmp/rook.fnet" -o "$tmp/rook.obj" >/dev/null || exit 1
python3 "$folds" "$tmp/rook.obj" >"$tmp/rook.json" || exit 1
pairs=$(count pairs_over_60_deg "$tmp/rook.json")
if [ "$pairs" = 0 ]; then
  echo "ok: rook K=2, no face pair over 60 degrees"
else
  echo "FAILED: rook K=2, ${pairs:-?} face pairs over 60 degrees (0)"; status=1
fi

"$fire" network-from-mesh "$meshes/rook.obj" --unrefine 2 --noise 2 --seed 1 --limit -o "$tmp/rook2.fnet" >/dev/null || exit 1
"$fire" reconstruct "$tmp/rook2.fnet" -o "$tmp/rook2.obj" >"$tmp/rook2.line" || exit 1
python3 "$folds" "$tmp/rook2.obj" >"$tmp/rook2.json" || exit 1
pairs=$(count pairs_over_60_deg "$tmp/rook2.json"); short=$(sed -n 's/.*"short_curves":\([0-9]*\).*/\1/p' "$tmp/rook2.line")
joined=$(sed -n 's/.*"joined_vertices":\([0-9]*\).*/\1/p' "$tmp/rook2.line")
if [ "$short" = 25 ] && [ "$joined" = 5 ] && [ "$pairs" = 0 ]; then
  echo "ok: rook K=2 at 2 % noise, its 25 short curves taken nearer their chords, 5 vertices joined, no face pair over 60 degrees"
else
  echo "FAILED: rook K=2 at 2 % noise, ${short:-?} short curves (25), ${joined:-?} joined vertices (5), ${pairs:-?} face pairs over 60 degrees (0)"; status=1
fi

"$fire" replay "$demo" --no-surface -o "$tmp/demo.fnet" >/dev/null 2>&1 || exit 1
"$fire" reconstruct "$tmp/demo.fnet" -o "$tmp/demo.obj" >/dev/null || exit 1
python3 "$folds" "$tmp/demo.obj" >"$tmp/demo.json" || exit 1
pairs=$(count pairs_over_60_deg "$tmp/demo.json"); down=$(count faces_facing_down "$tmp/demo.json")
if [ "$pairs" = 0 ] && [ "$down" = 0 ]; then
  echo "ok: demo dome, no face pairs over 60 degrees and no face facing down"
else
  echo "FAILED: demo dome, ${pairs:-?} face pairs over 60 degrees and ${down:-?} faces facing down (0 and 0)"; status=1
fi
exit $status
