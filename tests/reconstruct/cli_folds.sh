#!/usr/bin/env bash
# `fire reconstruct` on the rook's K = 2 network without noise (perf/quality.sh's row): the curve along
# the foot's widest ring bends faster than the surface can follow, and when the fit's targets could
# gather there the surface folded across it (338 face pairs over 60 degrees; perf/folds.py counts them).
set -u
fire="$1"; meshes="$2"; folds="$3"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$fire" network-from-mesh "$meshes/rook.obj" --unrefine 2 --noise 0 --seed 1 --limit -o "$tmp/rook.fnet" >/dev/null || exit 1
"$fire" reconstruct "$tmp/rook.fnet" -o "$tmp/rook.obj" >/dev/null || exit 1
pairs=$(python3 "$folds" "$tmp/rook.obj" | sed -n 's/.*"pairs_over_60_deg": \([0-9]*\).*/\1/p')
# 2 measured on 2026-12-02; a few more would be a changed sum order, hundreds the gathering again.
if [ -n "$pairs" ] && [ "$pairs" -le 10 ]; then
  echo "ok: rook K=2, $pairs face pairs over 60 degrees"
else
  echo "FAILED: rook K=2, ${pairs:-?} face pairs over 60 degrees (at most 10)"; exit 1
fi
