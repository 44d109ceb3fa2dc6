#!/usr/bin/env bash
# Exact curves the surface can follow are followed to within issue 13's goal (network_max at most 1e-4 of
# the diagonal), where the fairness that keeps other places from folding held the surface off them: the
# pawn's K = 2 network without noise (perf/quality.sh's row), whose collar's curves lay 1.42e-4 off the
# surface with one fairness weight everywhere (FitWeights::followed_distance).
set -u
fire="$1"; meshes="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
status=0
check() {  # mesh, largest network_max
  local mesh=$1 most=$2
  "$fire" network-from-mesh "$meshes/$mesh.obj" --unrefine 2 --noise 0 --seed 1 --limit -o "$tmp/$mesh.fnet" >/dev/null || exit 1
  "$fire" reconstruct "$tmp/$mesh.fnet" -o "$tmp/$mesh.obj" >/dev/null || exit 1
  "$fire" eval "$tmp/$mesh.obj" --reference "$meshes/$mesh.obj" --network "$tmp/$mesh.fnet" >"$tmp/$mesh.json" || exit 1
  local got
  got=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["network_max"])' "$tmp/$mesh.json") || exit 1
  if python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) <= float(sys.argv[2]) else 1)' "$got" "$most"; then
    echo "ok: $mesh K=2, network_max $got (at most $most)"
  else
    echo "FAILED: $mesh K=2, network_max $got (at most $most)"; status=1
  fi
}
check pawn 1e-4
exit $status
