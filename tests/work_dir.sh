# Sourced first by the command-line test scripts called as SCRIPT FIRE_BINARY WORK_DIR [...]: strict mode,
# $fire, a fresh $dir entered, and fail MESSAGE.
set -euo pipefail
fire="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
fail() { echo "FAIL: $*" >&2; exit 1; }
