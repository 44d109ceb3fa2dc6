#!/usr/bin/env bash
# The memory-layout study (thesis 5.3.5): times both builds of bench_layouts, profiles the -O2 build under
# cachegrind, then prints the tables and writes the plots. Output in $build/perf/layouts/results/.
# Run by `perf/run-all layouts` (so by `tools/run bench layouts`); FIRE_BUILD_DIR selects another build folder.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${FIRE_BUILD_DIR:-$here/../../build}"
bin="$build/perf/layouts"
out="$bin/results"
for level in O0 O2; do
  [ -x "$bin/bench_layouts_$level" ] || { echo "perf/layouts/run.sh: no $bin/bench_layouts_$level; build with -DFIRE_BENCH=ON" >&2; exit 2; }
done
command -v valgrind >/dev/null || { echo "perf/layouts/run.sh: valgrind is missing (apt-get install valgrind)" >&2; exit 2; }
mkdir -p "$out/cachegrind"
sizes=1000,10000,100000,1000000,10000000
iterations=1,3,10,30,100
repeat=3
cg_points=100000
variants=(s1 s2 s3 s4 s5 s6 s3_fresh s4_fresh fire openmesh openmesh_fresh)
ops=(none seq_read seq_write rand_read rand_write)

start=$(date +%s)
for level in O0 O2; do
  echo "perf/layouts: timing -$level over points ($sizes, 1 iteration) and iterations ($iterations, $cg_points points)" >&2
  "$bin/bench_layouts_$level" points 1 "$sizes" "$repeat" >"$out/points_$level.csv"
  "$bin/bench_layouts_$level" iters "$cg_points" "$iterations" "$repeat" >"$out/iters_$level.csv"
done
# Cachegrind cannot switch its counting on and off in valgrind 3.19, so each operation runs in its own process
# and the setup-only run ("none") is subtracted. The caches are given explicitly: this VM reports a bogus L3,
# so D1 is this machine's L1d and LL its per-core L2 (the same size as the thesis's 1 MB L2).
# The simulation does not depend on timing, so these runs go two at a time.
echo "perf/layouts: cachegrind on -O2, $cg_points points, ${#variants[@]} layouts x ${#ops[@]} runs" >&2
cachegrind_one() { # binary, points, output folder, variant, op
  valgrind --tool=cachegrind --cache-sim=yes --cachegrind-out-file=/dev/null \
    --I1=32768,8,64 --D1=49152,12,64 --LL=1048576,8,64 \
    "$1" once "$4" "$2" 1 "$5" no 2>"$3/cachegrind/${4}_$5.log"
}
export -f cachegrind_one
for v in "${variants[@]}"; do
  for op in "${ops[@]}"; do echo "$v $op"; done
done | xargs -P 2 -n 2 bash -c 'cachegrind_one "$0" "$1" "$2" "$3" "$4"' "$bin/bench_layouts_O2" "$cg_points" "$out"
echo "perf/layouts: measured in $(( $(date +%s) - start )) s" >&2
# Debian's interpreter, which has python3-matplotlib, even where another python3 comes first on PATH.
/usr/bin/python3 "$here/report.py" "$out"
