# Sourced by the perf scripts, with their arguments: `here` (the repository), `fire` (the binary: the first
# argument, else build/fire) and `tmp` (a scratch folder removed when the script exits).
here="$(cd "$(dirname "${BASH_SOURCE[1]}")/.." && pwd)"
fire="${1:-$here/build/fire}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
