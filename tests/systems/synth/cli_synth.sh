#!/usr/bin/env bash
# `fire network-from-mesh` as a user runs it: good meshes print one JSON line of counts and write the
# network; bad input exits 1 with a message naming the file and the problem, and writes nothing.
set -u
fire="$1"; meshes="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAILED: $1"; fail=1; fi; }
# expect_error NAME PATTERN CMD...: exit code 1, stderr matching PATTERN, no network file written
expect_error() {
  local name="$1" pattern="$2"; shift 2
  rm -f "$tmp/net.fnet"
  "$@" -o "$tmp/net.fnet" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  if [ $rc -eq 1 ] && grep -q -- "$pattern" "$tmp/err" && [ ! -e "$tmp/net.fnet" ] && [ ! -s "$tmp/out" ]; then
    echo "ok: $name"; else echo "FAILED: $name (exit $rc)"; cat "$tmp/err"; fail=1; fi
}

check "network-from-mesh --help documents the noise" "'$fire' network-from-mesh --help | grep -q 'mean control-mesh edge length'"
out=$("$fire" network-from-mesh "$meshes/torus.obj" --unrefine 2 --noise 2 --seed 7 -o "$tmp/torus.fnet")
check "torus K=2 prints its counts" "[ '$out' = '{\"vertices\":8,\"edges\":16,\"faces\":8,\"points\":272,\"face_sizes\":{\"4\":8}}' ]"
check "torus K=2 writes the network" "[ -s '$tmp/torus.fnet' ]"
check "the network reads back: one OBJ line per edge" "'$fire' export-network '$tmp/torus.fnet' -o '$tmp/torus-lines.obj' && [ \$(grep -c '^l ' '$tmp/torus-lines.obj') -eq 16 ]"
"$fire" network-from-mesh "$meshes/torus.obj" --unrefine 2 --noise 2 --seed 7 -o "$tmp/again.fnet" >/dev/null
check "same seed, same file" "cmp -s '$tmp/torus.fnet' '$tmp/again.fnet'"
"$fire" network-from-mesh "$meshes/torus.obj" --unrefine 2 --noise 2 --seed 8 -o "$tmp/other.fnet" >/dev/null
check "other seed, other file" "! cmp -s '$tmp/torus.fnet' '$tmp/other.fnet'"

expect_error "non-manifold fan.obj" "fire network-from-mesh: .*fan.obj: edge between vertices 8 and 9 (OBJ numbering) is shared by 3 faces" \
  "$fire" network-from-mesh "$meshes/fan.obj"
head -c 200 "$meshes/cube.obj" >"$tmp/truncated.obj"
expect_error "truncated OBJ" "truncated.obj:[0-9]*: vertex needs three coordinates" "$fire" network-from-mesh "$tmp/truncated.obj"
grep '^v ' "$meshes/cube.obj" >"$tmp/nofaces.obj"
expect_error "OBJ cut before its faces" "nofaces.obj: no faces" "$fire" network-from-mesh "$tmp/nofaces.obj"
sed '3s/^v .*/v 0.0 nan 1.0/' "$meshes/cube.obj" >"$tmp/nan.obj"
expect_error "NaN coordinate" "nan.obj:3: vertex coordinate is not finite" "$fire" network-from-mesh "$tmp/nan.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 banana\n' >"$tmp/malformed.obj"
expect_error "malformed face" "malformed.obj:4: face vertex 'banana' is not a vertex index" "$fire" network-from-mesh "$tmp/malformed.obj"
: >"$tmp/empty.obj"
expect_error "empty file" "empty.obj: no vertices" "$fire" network-from-mesh "$tmp/empty.obj"
expect_error "missing file" "missing.obj" "$fire" network-from-mesh "$tmp/missing.obj"
expect_error "too coarse" "unrefine 4 too coarse for .*torus.obj" "$fire" network-from-mesh "$meshes/torus.obj" --unrefine 4
rm -f "$tmp/net.fnet"
"$fire" network-from-mesh "$meshes/cube.obj" --samples 7 -o "$tmp/net.fnet" >/dev/null 2>&1; rc=$?
check "fewer than 8 samples refused" "[ $rc -ne 0 ] && [ ! -e '$tmp/net.fnet' ]"
exit $fail
