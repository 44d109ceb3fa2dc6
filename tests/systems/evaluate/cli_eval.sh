#!/usr/bin/env bash
# `fire eval` as a user runs it: good input prints exactly one JSON line with rms and hausdorff (and
# network_max with --network); bad input exits 1 with a message naming the file and prints nothing.
set -u
fire="$1"; meshes="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAILED: $1"; fail=1; fi; }
# field NAME: the number after "NAME": in $tmp/out
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\).*/\1/p" "$tmp/out"; }
expect_error() {  # NAME PATTERN CMD...: exit 1, stderr matching PATTERN, nothing on stdout
  local name="$1" pattern="$2"; shift 2
  "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  if [ $rc -eq 1 ] && grep -q -- "$pattern" "$tmp/err" && [ ! -s "$tmp/out" ]; then
    echo "ok: $name"; else echo "FAILED: $name (exit $rc)"; cat "$tmp/err"; fail=1; fi
}

# The control mesh is a coarse polygon around its own limit surface: small but clearly non-zero distances.
"$fire" eval "$meshes/torus.obj" --reference "$meshes/torus.obj" --spacing 0.01 >"$tmp/out" 2>"$tmp/err"
check "eval exits 0" "[ $? -eq 0 ]"
check "exactly one line on stdout" "[ \$(wc -l <'$tmp/out') -eq 1 ]"
check "nothing on stderr" "[ ! -s '$tmp/err' ]"
check "the line is a JSON object with rms and hausdorff" "grep -q '^{\"rms\":[0-9.e-]*,\"hausdorff\":[0-9.e-]*,.*}$' '$tmp/out'"
rms=$(field rms); hausdorff=$(field hausdorff)
check "0.005 < rms < hausdorff < 0.2 (rms $rms, hausdorff $hausdorff)" \
  "awk -v r='$rms' -v h='$hausdorff' 'BEGIN { exit !(r > 0.005 && r < h && h < 0.2) }'"
check "no network_max without --network" "! grep -q network_max '$tmp/out'"

# Topology, counted on the surface after welding and on the reference: a vessel open at both ends and a mug
# (genus 1, one border loop), reconstructed from networks of their control meshes, keep their references'.
for shape in lampshade:0:2 mug:-1:1; do
  IFS=: read -r name euler loops <<<"$shape"
  "$fire" network-from-mesh "$meshes/$name.obj" -o "$tmp/$name.fnet" >/dev/null
  "$fire" reconstruct "$tmp/$name.fnet" -o "$tmp/$name.obj" >/dev/null
  "$fire" eval "$tmp/$name.obj" --reference "$meshes/$name.obj" --spacing 0.01 >"$tmp/out"
  got="$(field euler_characteristic) $(field border_loops) $(field reference_euler_characteristic) $(field reference_border_loops)"
  check "$name: Euler characteristic and border loops $euler $loops, the reference's too (got $got)" "[ '$got' = '$euler $loops $euler $loops' ]"
done

# A network sampled on the control mesh's edges lies on that mesh: network_max is 0 up to rounding.
"$fire" network-from-mesh "$meshes/torus.obj" --unrefine 2 -o "$tmp/torus.fnet" >/dev/null
"$fire" eval "$meshes/torus.obj" --reference "$meshes/torus.obj" --network "$tmp/torus.fnet" --spacing 0.01 >"$tmp/out"
network_max=$(field network_max)
check "network on the surface: network_max ~ 0 ($network_max)" \
  "[ -n '$network_max' ] && awk -v n='$network_max' 'BEGIN { exit !(n >= 0 && n < 1e-12) }'"
# Noise moves the polyline points off the surface.
"$fire" network-from-mesh "$meshes/torus.obj" --unrefine 2 --noise 5 -o "$tmp/noisy.fnet" >/dev/null
"$fire" eval "$meshes/torus.obj" --reference "$meshes/torus.obj" --network "$tmp/noisy.fnet" --spacing 0.01 >"$tmp/out"
noisy_max=$(field network_max)
check "noisy network: network_max > 0.001 ($noisy_max)" "awk -v n='$noisy_max' 'BEGIN { exit !(n > 0.001) }'"
# network_max_at names the point: its edge and index in the file, and its position there.
python3 - "$tmp/out" "$tmp/noisy.fnet" >"$tmp/where" 2>&1 <<'PY'
import json, sys
out = json.loads(open(sys.argv[1]).read())
at = out["network_max_at"]
point = json.load(open(sys.argv[2]))["edges"][at["edge"]]["points"][at["point"]]
print("same" if point == at["position"] else f"differs: {point} {at}")
print("rms below max" if 0 < out["network_rms"] < out["network_max"] else f"network_rms {out['network_rms']}")
PY
check "network_max_at is the file's point ($(head -1 "$tmp/where"))" "[ \"\$(head -1 '$tmp/where')\" = same ]"
check "0 < network_rms < network_max ($(tail -1 "$tmp/where"))" "[ \"\$(tail -1 '$tmp/where')\" = 'rms below max' ]"

expect_error "non-manifold reference fan.obj" \
  "fire eval: .*fan.obj: reference mesh cannot be subdivided: .*shared by more than 2 faces" \
  "$fire" eval "$meshes/cube.obj" --reference "$meshes/fan.obj"
sed '3s/^v .*/v 0.0 nan 1.0/' "$meshes/cube.obj" >"$tmp/nan.obj"
expect_error "NaN in the surface" "fire eval: .*nan.obj:3: vertex coordinate is not finite" \
  "$fire" eval "$tmp/nan.obj" --reference "$meshes/cube.obj"
expect_error "NaN in the reference" "fire eval: .*nan.obj:3: vertex coordinate is not finite" \
  "$fire" eval "$meshes/cube.obj" --reference "$tmp/nan.obj"
expect_error "missing surface" "fire eval: .*missing.obj: cannot open" \
  "$fire" eval "$tmp/missing.obj" --reference "$meshes/cube.obj"
expect_error "missing reference" "fire eval: .*missing.obj: cannot open" \
  "$fire" eval "$meshes/cube.obj" --reference "$tmp/missing.obj"
cp "$meshes/cube.obj" "$tmp/cube.xyz"
expect_error "unknown surface format" "fire eval: .*cube.xyz: unknown surface format 'xyz'" \
  "$fire" eval "$tmp/cube.xyz" --reference "$meshes/cube.obj"
printf 'ply\nformat ascii 1.0\nend_header\n' >"$tmp/ascii.ply"
expect_error "unsupported PLY" "fire eval: .*ascii.ply: unsupported PLY layout" \
  "$fire" eval "$tmp/ascii.ply" --reference "$meshes/cube.obj"
head -c 300 "$tmp/torus.fnet" >"$tmp/truncated.fnet"
expect_error "truncated network" "fire eval: .*truncated.fnet" \
  "$fire" eval "$meshes/cube.obj" --reference "$meshes/cube.obj" --network "$tmp/truncated.fnet"
# A dense surface given as the reference: 130 x 130 quads make 17.3 million at 5 levels, about 9 GB to measure
# against; refused before anything is subdivided (it was killed by the kernel for memory).
awk 'BEGIN { n = 130; for (j = 0; j <= n; ++j) for (i = 0; i <= n; ++i) print "v", i, j, 0;
             for (j = 0; j < n; ++j) for (i = 0; i < n; ++i) { a = j * (n + 1) + i + 1; print "f", a, a + 1, a + n + 2, a + n + 1 } }' \
  >"$tmp/dense.obj"
expect_error "dense reference" \
  "fire eval: .*dense.obj: reference mesh cannot be subdivided: 16900 faces make 17305600 quads at 5 Catmull-Clark levels, more than the 16777216 a reference may have" \
  "$fire" eval "$meshes/cube.obj" --reference "$tmp/dense.obj"
"$fire" eval "$meshes/cube.obj" --reference "$meshes/cube.obj" --reference-levels 4 >/dev/null 2>&1
check "reference levels below 5 refused" "[ $? -ne 0 ]"
"$fire" eval "$meshes/cube.obj" --reference "$meshes/cube.obj" --spacing 0 >/dev/null 2>&1
check "spacing 0 refused" "[ $? -ne 0 ]"
exit $fail
