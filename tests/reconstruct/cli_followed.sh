#!/usr/bin/env bash
# Exact curves the surface can follow are followed to within issue 13's goal (network_max at most 1e-4 of
# the diagonal), where the fairness that keeps other places from folding held the surface off them: the
# pawn's K = 2 network without noise (perf/quality.sh's row), whose collar's curves lay 1.42e-4 off the
# surface with one fairness weight everywhere (FitWeights::followed_distance).
set -u
fire="$1"; meshes="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# the pawn's K = 2 network_max, as a fraction of the reference's diagonal
"$fire" network-from-mesh "$meshes/pawn.obj" --unrefine 2 --noise 0 --seed 1 --limit -o "$tmp/pawn.fnet" >/dev/null || exit 1
"$fire" reconstruct "$tmp/pawn.fnet" -o "$tmp/pawn.obj" >/dev/null || exit 1
"$fire" eval "$tmp/pawn.obj" --reference "$meshes/pawn.obj" --network "$tmp/pawn.fnet" >"$tmp/pawn.json" || exit 1
got=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["network_max"])' "$tmp/pawn.json") || exit 1
if python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) <= 1e-4 else 1)' "$got"; then
  echo "ok: pawn K=2, network_max $got (at most 1e-4)"
else
  echo "FAILED: pawn K=2, network_max $got (at most 1e-4)"; exit 1
fi
