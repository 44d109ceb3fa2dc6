#!/usr/bin/env bash
# tools/run bench frame: the frame latency table (bench_frame, with `fire simulate drawing` replayed from its
# Wii Remote reports besides its own drawings), then instructions and cache misses per
# system under callgrind (valgrind 3.19's cachegrind cannot split per function): one run of `fire
# replay` per drawing with --cache-sim=yes, each system's inclusive cost read off callgrind_annotate.
# Drawings under callgrind: the bundled demo (whole), the grid drawing's first 30 strokes (the
# whole one takes tens of minutes there), and a tracked drawing: `fire simulate sketch` (12 strokes on the
# pawn, hand occlusions, a stray reflection) replayed from its Wii Remote reports with --rig, the only
# one that runs the triangulation system; its per-system latency comes from `fire replay --timings`.
#   perf/frame/run.sh   (FIRE_BUILD_DIR selects the build folder, default build/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${FIRE_BUILD_DIR:-$here/build}"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
echo "perf/frame/run.sh: simulating a wand, calibrating, simulating a drawing (about a minute)" >&2
"$build/fire" simulate wand -o "$tmp/wand.log" >/dev/null
"$build/fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null
"$build/fire" simulate drawing -o "$tmp/drawing.log" --marks-out "$tmp/marks.json" --object-out "$tmp/object.obj" >/dev/null
"$build/perf/frame/bench_frame" --tracked "$tmp/drawing.log" "$tmp/rig.json"

"$build/perf/frame/bench_frame" --write-grid-log "$tmp/grid.log"
# The first 30 strokes: everything up to the 30th pen-up.
awk '/ up$/ { n++ } { print } n == 30 { exit }' "$tmp/grid.log" >"$tmp/grid30.log"
"$build/fire" simulate sketch --occlusion 0.5 -o "$tmp/tracked.log" >/dev/null
echo
echo "tracked drawing (fire simulate sketch --occlusion 0.5, replayed with --rig):"
"$build/fire" replay "$tmp/tracked.log" --rig "$tmp/rig.json" --timings

# Each system's function as callgrind names it (the snap system is the index's sync).
systems=(input_system triangulate_system register_system sketch_system split_system refine_system subdivide_system SnapIndex::sync)
echo
echo "| drawing | system | instructions | D1 misses | LL misses | D1 misses per 1000 instructions |"
echo "|---|---|---|---|---|---|"
for drawing in demo grid30 tracked; do
  log="$here/tools/demo/sketch.log"
  snap=0.01
  extra=()
  [ "$drawing" = grid30 ] && { log="$tmp/grid30.log"; snap=0.005; }
  [ "$drawing" = tracked ] && { log="$tmp/tracked.log"; extra=(--rig "$tmp/rig.json"); }
  echo "perf/frame/run.sh: callgrind over $drawing (a few minutes)" >&2
  # The same caches as perf/layouts: this VM reports a bogus L3, so LL is the per-core L2.
  valgrind --tool=callgrind --cache-sim=yes --callgrind-out-file="$tmp/cg.$drawing" \
    --I1=32768,8,64 --D1=49152,12,64 --LL=1048576,8,64 \
    "$build/fire" replay "$log" --snap "$snap" "${extra[@]}" >/dev/null 2>"$tmp/vg.$drawing" ||
    { cat "$tmp/vg.$drawing" >&2; exit 1; }
  callgrind_annotate --inclusive=yes --threshold=100 "$tmp/cg.$drawing" >"$tmp/ann.$drawing"
  # Event order in the annotation: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw, each count followed by its
  # share in parentheses; a zero count is printed as ".".
  for s in "${systems[@]}"; do
    line=$(grep -E "fire::${s}\(" "$tmp/ann.$drawing" | head -1 || true)
    name="${s%_system}"
    [ "$s" = SnapIndex::sync ] && name=snap
    [ -n "$line" ] || { echo "| $drawing | $name | not run | | | |"; continue; }
    read -r ir dr dw i1 d1r d1w il dlr dlw _ <<<"$(sed -E 's/\( *[0-9.]+%\)//g; s/,//g; s/ \. / 0 /g; s/ \. / 0 /g' <<<"$line")"
    awk -v d="$drawing" -v s="$name" -v ir="$ir" -v d1r="$d1r" -v d1w="$d1w" -v dlr="$dlr" -v dlw="$dlw" \
      'BEGIN { d1 = d1r + d1w; ll = dlr + dlw; printf "| %s | %s | %.0f | %.0f | %.0f | %.2f |\n", d, s, ir, d1, ll, ir ? 1000 * d1 / ir : 0 }'
  done
done
