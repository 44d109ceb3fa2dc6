#!/usr/bin/env bash
# tools/run bench render: the app frame on lavapipe in a real window (bench_render under Xvfb, as the
# window tests run `fire app`), validation off as in a release `fire app`, 10 s per network and level.
#   perf/render/run.sh [bench_render arguments]   (FIRE_BUILD_DIR selects the build folder, default build/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${FIRE_BUILD_DIR:-$here/build}"
command -v xvfb-run >/dev/null || { echo "perf/render/run.sh: needs xvfb-run (Debian xvfb, xauth; tools/run bench installs them)" >&2; exit 2; }
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
# A 24-bit screen larger than the window, as the window tests use; -a picks a free display number.
FIRE_VK_VALIDATION=0 xvfb-run -a -s '-screen 0 1280x800x24' "$build/perf/render/bench_render" "$@"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
