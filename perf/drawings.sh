#!/usr/bin/env bash
# Any object drawn through the simulated remotes (issue 40): for each reference mesh and seed, the simulated
# person draws its network (`fire simulate drawing --mesh M --seed S`, default options), the reports are
# replayed through every frame system (`fire replay --rig`, the rig calibrated from a simulated wand), and the
# surface is measured against the object (`fire eval`, `perf/folds.py`). Prints a markdown table for
# perf/RESULTS.md on stdout: object, seed, curves drawn of the network's, poses, registrations, strokes, pieces,
# holes, Euler characteristic and border loops (surface / object), rms and hausdorff (fractions of the
# diagonal), folds (face pairs over 60 degrees at level 3, those along a curve marked sharp left out), curves
# marked sharp and the largest difference in degrees between how far the surface and the object bend across
# them (issue 44; fire eval's crease_error_max_deg), and seconds (simulate + replay). A drawing that cannot be
# made gets its row with the reason. Progress on stderr.
#
# usage: perf/drawings.sh [FIRE_BINARY]      (default: build/fire)
# env:   MESHES  space-separated subset (default "pawn rook torus lampshade mug egg box ridge"); SEEDS (default "1 2 3 4 5")
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
meshes_dir="$here/tests/data/meshes"
field() { sed -n "s/.*\"$1\": *\([-+0-9.eE]*\).*/\1/p" "$2" | head -1; }
crease_error() { local e; e=$(field crease_error_max_deg "$1"); [ -n "$e" ] && printf '%.1f' "$e" || echo -; }

"$fire" simulate wand -o "$tmp/wand.log" >/dev/null
"$fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null 2>&1
echo "| object | seed | curves | poses | registrations | strokes | pieces | holes | Euler / loops, surface | object | rms | hausdorff | folds > 60° | sharp | crease error ° | s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for mesh in ${MESHES:-pawn rook torus lampshade mug egg box ridge}; do
  for seed in ${SEEDS:-1 2 3 4 5}; do
    echo "drawings: $mesh seed $seed" >&2
    d="$tmp/$mesh-$seed"
    mkdir -p "$d"
    start=$(date +%s.%N)
    if ! "$fire" simulate drawing --mesh "$meshes_dir/$mesh.obj" --seed "$seed" -o "$d/drawing.log" --marks-out "$d/marks.json" \
         --object-out "$d/object.obj" >"$d/drawing.json" 2>"$d/err.txt"; then
      printf '| %s | %s | cannot be drawn: %s |||||||||||||\n' "$mesh" "$seed" "$(sed 's/.*drawing: [^:]*: //' "$d/err.txt" | tr -d '|')"
      continue
    fi
    "$fire" replay "$d/drawing.log" --rig "$tmp/rig.json" -o "$d/drawing.fnet" --surface "$d/surface.obj" >/dev/null 2>"$d/replay.txt"
    seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
    "$fire" eval "$d/surface.obj" --reference "$d/object.obj" --network "$d/drawing.fnet" >"$d/eval.json" 2>/dev/null
    python3 "$here/perf/folds.py" "$d/surface.obj" "$d/drawing.fnet" >"$d/folds.json"
    rejected=$(grep -c "rejected" "$d/replay.txt" || true)
    printf '| %s | %s | %s/%s | %s | %s | %s | %s | %s | %s / %s | %s / %s | %.2e | %.2e | %s | %s | %s | %.0f |%s\n' "$mesh" "$seed" \
      "$(field curves_drawn "$d/drawing.json")" "$(field curves_total "$d/drawing.json")" "$(field poses "$d/drawing.json")" \
      "$(field registrations "$d/drawing.json")" "$(field strokes "$d/drawing.json")" "$(field pieces "$d/drawing.json")" \
      "$(field holes "$d/drawing.json")" "$(field euler_characteristic "$d/eval.json")" "$(field border_loops "$d/eval.json")" \
      "$(field reference_euler_characteristic "$d/eval.json")" "$(field reference_border_loops "$d/eval.json")" \
      "$(field rms "$d/eval.json")" "$(field hausdorff "$d/eval.json")" "$(field pairs_over_60_deg "$d/folds.json")" \
      "$(field sharp "$d/drawing.json")" "$(crease_error "$d/eval.json")" "$seconds" \
      "$([ "$rejected" -gt 0 ] && echo " $rejected strokes rejected in replay")"
  done
done
