#!/usr/bin/env bash
# Topology kept by reconstruction (issue 40): for each reference mesh with a topology other than a disc,
# build its curve network (`fire network-from-mesh`, default options), reconstruct it (`fire reconstruct`)
# and read `fire eval`'s Euler characteristic and border loops of the surface and of the reference, with
# rms and hausdorff. Prints a markdown table for perf/notes/topology.md on stdout; progress on stderr.
#
# usage: perf/topology.sh [FIRE_BINARY]      (default: build/fire)
# env:   MESHES   space-separated subset (default "lampshade mug egg torus")
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
meshes_dir="$here/tests/data/meshes"
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\).*/\1/p" "$tmp/eval.json"; }
echo "| mesh | Euler characteristic / border loops, surface | the same, reference | rms | hausdorff |"
echo "|---|---|---|---|---|"
for mesh in ${MESHES:-lampshade mug egg torus}; do
  echo "topology: $mesh" >&2
  "$fire" network-from-mesh "$meshes_dir/$mesh.obj" -o "$tmp/$mesh.fnet" >/dev/null
  "$fire" reconstruct "$tmp/$mesh.fnet" -o "$tmp/$mesh.obj" >/dev/null
  "$fire" eval "$tmp/$mesh.obj" --reference "$meshes_dir/$mesh.obj" >"$tmp/eval.json" 2>/dev/null
  printf '| %s | %s / %s | %s / %s | %.2e | %.2e |\n' "$mesh" "$(field euler_characteristic)" "$(field border_loops)" \
    "$(field reference_euler_characteristic)" "$(field reference_border_loops)" "$(field rms)" "$(field hausdorff)"
done
