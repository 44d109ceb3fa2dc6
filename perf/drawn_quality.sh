#!/usr/bin/env bash
# The quality table for drawn objects (issue 44, item 6): for each object the simulated person can draw and each
# seed, the drawing (`fire simulate drawing --mesh M --seed S`, default options) is replayed through every frame
# system (`fire replay --rig`, the rig calibrated from a simulated wand) to its end and to a third and two thirds
# of its committed strokes (`--until-stroke`), and each surface is measured: rms, hausdorff and network_max
# against the object (`fire eval`, fractions of the diagonal), folds (face pairs over 60 degrees at the level
# `--surface` writes, those along a curve marked sharp left out: perf/folds.py) at a third, two thirds and the
# end, and the fire base mesh's worst quad aspect (`fire reconstruct` of the final network). With BASELINE, the
# whole replay is timed with this binary and the baseline's in turn. Prints a markdown table on stdout,
# progress on stderr. A drawing that cannot be made gets its row with the reason.
#
# usage: perf/drawn_quality.sh [FIRE_BINARY]      (default: build/fire)
# env:   MESHES  space-separated subset (default "pawn torus lampshade mug egg box ridge": the rook cannot be drawn)
#        SEEDS   seeds for every object (default: 1 to 20 for the pawn, 1 to 5 for the others)
#        BASELINE=FIRE  a fire binary built from the commit to compare replay times with
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
baseline="${BASELINE:-}"
[ -z "$baseline" ] || [ -x "$baseline" ] || { echo "perf/drawn_quality.sh: BASELINE=$baseline is not an executable" >&2; exit 2; }
meshes_dir="$here/tests/data/meshes"
field() { sed -n "s/.*\"$1\": *\([-+0-9.eE]*\).*/\1/p" "$2" | head -1; }
now() { date +%s.%N; }
seconds_since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
# Folds of the surface replayed from log $1 to file $2 (extra replay options after), against the network; "no
# surface yet" where the drawing has no face then (a border not closed).
folds_at() {
  local log="$1" surface="$2"
  shift 2
  if ! "$fire" replay "$log" --rig "$tmp/rig.json" -o "$surface.fnet" --surface "$surface" "$@" >/dev/null 2>"$surface.err"; then
    grep -q "the network has no faces" "$surface.err" && echo "no surface yet" || echo "replay failed"
    return
  fi
  python3 "$here/perf/folds.py" "$surface" "$surface.fnet" | sed -n 's/.*"pairs_over_60_deg": *\([0-9]*\).*/\1/p'
}

"$fire" simulate wand -o "$tmp/wand.log" >/dev/null
"$fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null 2>&1
echo "| object | seed | curves | strokes | rms | hausdorff | network_max | folds at a third | at two thirds | at the end | worst quad aspect | replay s${baseline:+ | baseline s | ours / baseline} |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---${baseline:+|---|---}|"
for mesh in ${MESHES:-pawn torus lampshade mug egg box ridge}; do
  default_seeds="1 2 3 4 5"
  [ "$mesh" = pawn ] && default_seeds="$(seq -s ' ' 1 20)"
  for seed in ${SEEDS:-$default_seeds}; do
    echo "drawn_quality: $mesh seed $seed" >&2
    d="$tmp/$mesh-$seed"
    mkdir -p "$d"
    if ! "$fire" simulate drawing --mesh "$meshes_dir/$mesh.obj" --seed "$seed" -o "$d/drawing.log" --marks-out "$d/marks.json" \
         --object-out "$d/object.obj" >"$d/drawing.json" 2>"$d/err.txt"; then
      printf '| %s | %s | cannot be drawn: %s |||||||||%s\n' "$mesh" "$seed" "$(sed 's/.*drawing: [^:]*: //' "$d/err.txt" | tr -d '|')" "${baseline:+||}"
      continue
    fi
    start=$(now)
    "$fire" replay "$d/drawing.log" --rig "$tmp/rig.json" -o "$d/end.fnet" --surface "$d/end.obj" >/dev/null 2>&1
    ours=$(seconds_since "$start")
    timing=""
    if [ -n "$baseline" ]; then
      start=$(now)
      "$baseline" replay "$d/drawing.log" --rig "$tmp/rig.json" --surface "$d/base.obj" >/dev/null 2>&1
      theirs=$(seconds_since "$start")
      timing=" $theirs | $(awk -v a="$ours" -v b="$theirs" 'BEGIN { printf "%.2f", a / b }') |"
    fi
    strokes=$(field strokes "$d/drawing.json")
    "$fire" eval "$d/end.obj" --reference "$d/object.obj" --network "$d/end.fnet" >"$d/eval.json" 2>/dev/null
    "$fire" reconstruct "$d/end.fnet" -o "$d/reconstructed.obj" >"$d/reconstruct.json" 2>/dev/null
    printf '| %s | %s | %s/%s | %s | %.2e | %.2e | %.2e | %s | %s | %s | %.1f | %s |%s\n' "$mesh" "$seed" \
      "$(field curves_drawn "$d/drawing.json")" "$(field curves_total "$d/drawing.json")" "$strokes" \
      "$(field rms "$d/eval.json")" "$(field hausdorff "$d/eval.json")" "$(field network_max "$d/eval.json")" \
      "$(folds_at "$d/drawing.log" "$d/third.obj" --until-stroke $((strokes / 3)))" \
      "$(folds_at "$d/drawing.log" "$d/two_thirds.obj" --until-stroke $((2 * strokes / 3)))" \
      "$(python3 "$here/perf/folds.py" "$d/end.obj" "$d/end.fnet" | sed -n 's/.*"pairs_over_60_deg": *\([0-9]*\).*/\1/p')" \
      "$(field worst_quad_aspect "$d/reconstruct.json")" "$ours" "$timing"
  done
done
