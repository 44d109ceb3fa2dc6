#!/usr/bin/env bash
# FreeCAD opens FIRE's CAD files (issue 43): STEP and IGES of the pawn's, the rook's and the egg's networks and of
# a simulated drawing (the demo's: a simulated person draws the pawn, replayed through every frame system), written
# by perf/cad's bench_cad, which prints the patches, times, sizes and what OpenCASCADE reads back; then FreeCAD's
# command line (freecadcmd, Debian freecad-python3, installed here when missing; not part of tools/run test) reads
# each file and prints: valid or not, faces against patches, shells, solids, size in mm.
#
#   perf/cad/freecad_check.sh [OUT_DIR]     (default build/cad-check; FIRE_BUILD_DIR selects the build folder)
#
# Needs build/fire and build/perf/cad/bench_cad (tools/run bench cad builds both). Exits non-zero if a file is
# not valid or has not one face per patch, in either reader.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${FIRE_BUILD_DIR:-$here/build}"
out="${1:-$build/cad-check}"
fire="$build/fire"
bench="$build/perf/cad/bench_cad"
for tool in "$fire" "$bench"; do
  [ -x "$tool" ] || { echo "freecad_check: no $tool; build it first (tools/run bench cad)" >&2; exit 2; }
done
if ! command -v freecadcmd >/dev/null; then
  echo "freecad_check: installing FreeCAD's command line (freecad-python3)"
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends freecad-python3
fi
mkdir -p "$out"
echo "freecad_check: a simulated drawing of the pawn, replayed (as tools/run demo does)"
"$fire" simulate wand -o "$out/wand.log" >/dev/null
"$fire" calibrate "$out/wand.log" -o "$out/rig.json" >/dev/null 2>&1
"$fire" simulate drawing -o "$out/drawing.log" --marks-out "$out/marks.json" --object-out "$out/pawn20.obj" >/dev/null
"$fire" replay "$out/drawing.log" --rig "$out/rig.json" -o "$out/drawing.fnet" >/dev/null
echo "freecad_check: STEP and IGES by bench_cad, read back by OpenCASCADE ($out)"
"$bench" --out "$out" --mesh pawn --mesh rook --mesh egg --network "$out/drawing.fnet" | tee "$out/bench.txt"
echo "freecad_check: the same networks through the command line: fire reconstruct NET -o NAME-cli.step / .igs"
for name in pawn rook egg; do
  "$fire" network-from-mesh "$here/tests/data/meshes/$name.obj" --unrefine 2 --limit -o "$out/$name.fnet" >/dev/null
done
for name in pawn rook egg drawing; do
  for ext in step igs; do
    json=$("$fire" reconstruct "$out/$name.fnet" -o "$out/$name-cli.$ext")
    patches=$(sed -n 's/.*"cad":{"patches":\([0-9]*\),.*/\1/p' <<<"$json")
    [ -n "$patches" ] || { echo "freecad_check: fire reconstruct printed no patch count: $json" >&2; exit 1; }
  done
  echo "$name-cli: network $name.fnet patches $patches (fire reconstruct, levels 3) ${json#*\"cad\":}" | tee -a "$out/bench.txt"
done
echo "freecad_check: every file read by FreeCAD's command line"
FIRE_CAD_DIR="$out" freecadcmd "$here/perf/cad/freecad_check.py" 2>&1 | grep '^freecad'
