#!/usr/bin/env bash
# Benchmarks (a) and (b) against OpenSubdiv under several code layouts. OpenSubdiv's
# StencilTable::UpdateValues is a template compiled into bench_subdivide, and its inner loop runs up to
# 40 % faster or slower depending on where the loop lands (perf/notes/subdivide.md); ours barely moves. This
# builds the benchmark once per alignment setting, each in its own folder build-layout-NAME, runs each
# RUNS times (interleaved, 11 repetitions), and prints the (a) and (b) columns as one Markdown table, so
# that a ratio can be quoted against the peer's best layout.
#
# usage: perf/subdivide/layouts.sh [RUNS]   (RUNS defaults to 3; run from anywhere, after `tools/run bench`
#        has installed the packages; about 2 minutes of building per layout on 2 cores)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
runs="${1:-3}"
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || { echo "usage: perf/subdivide/layouts.sh [RUNS >= 1]" >&2; exit 2; }
jobs="$(nproc 2>/dev/null || echo 2)"
layouts=("default=" "loops16=-falign-loops=16" "loops32=-falign-loops=32" "loops64=-falign-loops=64 -falign-functions=64")

echo "Benchmarks (a) and (b), $(uname -m), $(nproc) cores, $(date -u +%Y-%m-%d)"
echo
echo "| layout (CMAKE_CXX_FLAGS) | run | base mesh | level | (a) ours ms | (a) OSD ms | (a) OSD / ours | (b) ours ms | (b) OSD level by level ms | (b) fastest OSD / fastest ours |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for layout in "${layouts[@]}"; do
  name="${layout%%=*}" flags="${layout#*=}"
  dir="$root/build-layout-$name"
  echo "layouts: building $name (${flags:-no flags}) in $dir" >&2
  cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DFIRE_BENCH=ON -DFIRE_TESTS=OFF \
    "-DCMAKE_CXX_FLAGS=$flags" >/dev/null
  cmake --build "$dir" -j "$jobs" --target bench_subdivide >/dev/null
  for ((run = 1; run <= runs; ++run)); do
    # Table rows of bench_subdivide: | mesh | level | vertices | (a) ours | (a) OSD | (a) ratio | ... | (b) ours |
    # ... | (b) OSD level by level | (b) ratio | max diff |
    "$dir/perf/subdivide/bench_subdivide" "$root/tests/data" 11 interleaved |
      awk -F'|' -v layout="${flags:-default}" -v run="$run" \
        'NR > 2 { gsub(/^ +| +$/, "", $2); printf "| %s | %d | %s |%s|%s|%s|%s|%s|%s|%s|\n", layout, run, $2, $3, $5, $6, $7, $11, $16, $17 }'
  done
done
