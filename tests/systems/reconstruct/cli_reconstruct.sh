#!/usr/bin/env bash
# `fire reconstruct` as a user runs it: a good network prints one JSON line and writes the surface in
# the extension's format; bad input exits 1 with a message naming the file and the problem, and writes
# nothing.
set -u
fire="$1"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAILED: $1"; fail=1; fi; }
# expect_error NAME PATTERN OUT CMD...: exit code 1, stderr matching PATTERN, nothing on stdout, no OUT
expect_error() {
  local name="$1" pattern="$2" out="$3"; shift 3
  "$@" >"$tmp/stdout" 2>"$tmp/err"; local rc=$?
  if [ $rc -eq 1 ] && grep -q -- "$pattern" "$tmp/err" && [ ! -e "$out" ] && [ ! -s "$tmp/stdout" ]; then
    echo "ok: $name"; else echo "FAILED: $name (exit $rc)"; cat "$tmp/err"; fail=1; fi
}
network() {  # NAME VERTICES EDGES FACES: writes $tmp/NAME.fnet
  printf '{"format":"fire-network","version":1,"vertices":[%s],"edges":[%s],"faces":[%s]}\n' "$2" "$3" "$4" >"$tmp/$1.fnet"
}
v() { printf '{"p":[%s],"split":false}' "$1"; }
e() { printf '{"v":[%s],"sharp":false,"points":[%s]}' "$1" "$2"; }

# A square with curved sides.
network square "$(v 0,0,0),$(v 1,0,0),$(v 1,1,0),$(v 0,1,0)" \
  "$(e 0,1 '[0,0,0],[0.25,0,0.1],[0.5,0,0.15],[0.75,0,0.1],[1,0,0]'),$(e 1,2 '[1,0,0],[1,0.5,0.2],[1,1,0]'),$(e 3,2 '[0,1,0],[0.5,1,0.3],[1,1,0]'),$(e 0,3 '[0,0,0],[0,0.5,0.1],[0,1,0]')" \
  '{"edges":[0,1,2,3],"reversed":[false,false,true,true]}'
out=$("$fire" reconstruct "$tmp/square.fnet" -o "$tmp/square.obj")
check "prints one JSON line with the counts" "echo '$out' | grep -q '^{\"method\":\"fire\",\"coons_steps\":1,\"levels\":3,\"base_faces\":4,\"faces\":256,\"vertices\":289,\"seconds\":[0-9.e-]*,\"worst_quad_aspect\":[0-9.e+-]*,\"noise_estimate\":[0-9.e+-]*,\"tangent_spread_deg\":[0-9.e+-]*,\"fairness\":0.001,\"short_curves\":0,\"joined_vertices\":0}$'"
check "writes the OBJ: 289 vertices with normals, 256 faces" "[ \$(grep -c '^v ' '$tmp/square.obj') -eq 289 ] && [ \$(grep -c '^vn ' '$tmp/square.obj') -eq 289 ] && [ \$(grep -c '^f ' '$tmp/square.obj') -eq 256 ]"
out=$("$fire" reconstruct "$tmp/square.fnet" -o "$tmp/square.glb" --method thesis --coons-steps 2 --levels 1 --planarity hough)
check "thesis, 2 Coons steps, level 1" "echo '$out' | grep -q '\"method\":\"thesis\",\"coons_steps\":2,\"levels\":1,\"base_faces\":16,\"faces\":64,\"vertices\":81'"
for ext in ply stl glb; do
  "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/s.$ext" --levels 2 >/dev/null
  check "writes .$ext" "[ -s '$tmp/s.$ext' ]"
done

# A face of 2 curves: FIRE makes 2 quads; the thesis needs triangles and quads.
network digon "$(v 0,0,0),$(v 1,0,0)" "$(e 0,1 '[0,0,0],[0.5,0.3,0],[1,0,0]'),$(e 1,0 '[1,0,0],[0.5,-0.3,0.1],[0,0,0]')" \
  '{"edges":[0,1],"reversed":[false,false]}'
check "fire reconstructs a 2-sided face" "'$fire' reconstruct '$tmp/digon.fnet' -o '$tmp/digon.obj' | grep -q '\"base_faces\":2,'"
expect_error "thesis rejects a 2-sided face" "fire reconstruct: .*digon.fnet: face 0 has 2 edges; the thesis method needs at least 3" \
  "$tmp/digon2.obj" "$fire" reconstruct "$tmp/digon.fnet" -o "$tmp/digon2.obj" --method thesis

network zero "$(v 0,0,0),$(v 1,0,0),$(v 0,0,0)" \
  "$(e 0,1 '[0,0,0],[1,0,0]'),$(e 1,2 '[1,0,0],[0.5,0.5,0],[0,0,0]'),$(e 2,0 '[0,0,0],[0,0,0]')" \
  '{"edges":[0,1,2],"reversed":[false,false,false]}'
expect_error "zero-length polyline" "zero.fnet: edge 2's polyline has zero length" "$tmp/zero.obj" \
  "$fire" reconstruct "$tmp/zero.fnet" -o "$tmp/zero.obj"
network pinched "$(v 0,0,0),$(v 1,0,0),$(v 0,0,0)" \
  "$(e 0,1 '[0,0,0],[1,0,0]'),$(e 1,2 '[1,0,0],[0.5,0.5,0],[0,0,0]'),$(e 2,0 '[0,0,0],[-0.2,-0.2,0],[0,0,0]')" \
  '{"edges":[0,1,2],"reversed":[false,false,false]}'
expect_error "coincident corners" "pinched.fnet: face 0 has coincident corners: vertices 0 and 2" "$tmp/pinched.obj" \
  "$fire" reconstruct "$tmp/pinched.fnet" -o "$tmp/pinched.obj"
network repeated "$(v 0,0,0),$(v 1,0,0),$(v 0,1,0)" \
  "$(e 0,1 '[0,0,0],[0.5,0,0],[0.5,0,0],[1,0,0]'),$(e 1,2 '[1,0,0],[0,1,0]'),$(e 2,0 '[0,1,0],[0,0,0]')" \
  '{"edges":[0,1,2],"reversed":[false,false,false]}'
expect_error "coincident consecutive points" "repeated.fnet: edge 0's polyline has coincident consecutive points 1 and 2" \
  "$tmp/repeated.obj" "$fire" reconstruct "$tmp/repeated.fnet" -o "$tmp/repeated.obj"
sed 's/\[0.5,0.5,0\]/[0.5,NaN,0]/' "$tmp/zero.fnet" >"$tmp/nan.fnet"
expect_error "NaN coordinate" "fire reconstruct: .*nan.fnet" "$tmp/nan.obj" "$fire" reconstruct "$tmp/nan.fnet" -o "$tmp/nan.obj"
expect_error "missing network" "fire reconstruct: .*missing.fnet" "$tmp/missing.obj" \
  "$fire" reconstruct "$tmp/missing.fnet" -o "$tmp/missing.obj"
expect_error "unwritable output" "fire reconstruct: .*$tmp/no/such/dir/out.obj" "$tmp/no/such/dir/out.obj" \
  "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/no/such/dir/out.obj"
expect_error "unknown output format" "fire reconstruct: .*out.xyz" "$tmp/out.xyz" "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/out.xyz"
expect_error "level out of range" "fire reconstruct: .*subdivision level must be 1 to 6, not 9" "$tmp/l9.obj" \
  "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/l9.obj" --levels 9
expect_error "unknown method" "fire reconstruct: --method must be thesis or fire, not 'magic'" "$tmp/m.obj" \
  "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/m.obj" --method magic
# Units: millimetres by default, said in the file, read back as metres; a glB stays metres.
"$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u.stl" >/dev/null
"$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u_m.obj" --units m >/dev/null
"$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u_mm.obj" >/dev/null
check "an STL says millimetres in its header" "head -c 80 '$tmp/u.stl' | grep -q 'units: mm; up: +Z'"
maxx() { awk '/^v / { if (!n++ || $2 + 0 > m) m = $2 + 0 } END { printf "%.17g", m }' "$1"; }
check "an OBJ in mm holds 1000 times the metres, and says so" "awk -v a=\$(maxx '$tmp/u_mm.obj') -v b=\$(maxx '$tmp/u_m.obj') 'BEGIN { d = a - 1000 * b; exit !(d < 1e-9 && d > -1e-9) }' && grep -q '^# units: mm, up: +Z$' '$tmp/u_mm.obj'"
rms() { "$fire" eval "$1" --reference "$tmp/u_m.obj" | sed 's/.*"rms":\([0-9.e+-]*\).*/\1/'; }
check "fire eval measures the same in mm and m (to rounding)" "awk -v a=\$(rms '$tmp/u_mm.obj') -v b=\$(rms '$tmp/u_m.obj') 'BEGIN { d = a - b; exit !(b > 0 && d < 1e-12 * b && d > -1e-12 * b) }'"
expect_error "--units cm with a glB" "a glTF file is in metres" "$tmp/u.glb" "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u.glb" --units cm
expect_error "an unknown unit" "unknown length unit 'inch'" "$tmp/u_in.obj" "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u_in.obj" --units inch
# The cage: OBJ with OpenSubdiv's tags and USDA, without a surface file too.
"$fire" reconstruct "$tmp/square.fnet" --cage "$tmp/u_cage.obj" --cage "$tmp/u_cage.usda" >/dev/null
check "--cage alone writes the OBJ and USDA cages" "grep -q '^t interpolateboundary 1/0/0 2$' '$tmp/u_cage.obj' && [ \$(grep -c '^f ' '$tmp/u_cage.obj') -eq 4 ] && grep -q 'subdivisionScheme = \"catmullClark\"' '$tmp/u_cage.usda' && grep -q 'metersPerUnit = 0.001' '$tmp/u_cage.usda'"
expect_error "a cage in an unknown format" "unknown cage format 'fbx'" "$tmp/u_cage.fbx" "$fire" reconstruct "$tmp/square.fnet" --cage "$tmp/u_cage.fbx"
"$fire" reconstruct "$tmp/square.fnet" >/dev/null 2>"$tmp/err"
check "nothing to write is a usage error" "[ \$? -eq 2 ] && grep -q 'nothing to write' '$tmp/err'"
# CAD: B-spline patches in STEP and IGES, in millimetres; the square's 4 regular-bordered quads are exact.
out=$("$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u.step")
check "STEP: patches, sewn into one shell with its border free, in mm" "grep -q '\"cad\":{\"patches\":[0-9]*,\"exact\":[0-9]*,\"fitted\":0,.*\"solids\":0,\"shells\":1,\"free_edges\":[1-9][0-9]*,\"units\":\"mm\"}' <<<'$out' && grep -q 'SI_UNIT(.MILLI.,.METRE.)' '$tmp/u.step'"
"$fire" reconstruct "$tmp/square.fnet" -o "$tmp/u.IGES" --units m >/dev/null
check "IGES in metres" "[ -s '$tmp/u.IGES' ] && grep -q '\"units\":\"m\"' <<<\"\$('$fire' reconstruct '$tmp/square.fnet' -o '$tmp/u.IGES' --units m)\""
expect_error "STEP into a folder that is not there" "fire reconstruct: .*no/such/dir/x.step" "$tmp/no/such/dir/x.step" \
  "$fire" reconstruct "$tmp/square.fnet" -o "$tmp/no/such/dir/x.step"
# A cage with a sharp curve as fire eval's reference: its tags are honoured (the crease measured as a crease), and
# a tag FIRE's subdivision cannot honour is refused by its line.
network ridge "$(v 0,0,0),$(v 1,0,0),$(v 2,0,0),$(v 2,1,0),$(v 1,1,0),$(v 0,1,0)" \
  "$(e 0,1 '[0,0,0],[0.5,0,0.1],[1,0,0]'),$(e 1,4 '[1,0,0],[1,0.5,0.3],[1,1,0]'),$(e 4,5 '[1,1,0],[0.5,1,0.1],[0,1,0]'),$(e 5,0 '[0,1,0],[0,0.5,0.1],[0,0,0]'),$(e 1,2 '[1,0,0],[1.5,0,0.1],[2,0,0]'),$(e 2,3 '[2,0,0],[2,0.5,0.1],[2,1,0]'),$(e 3,4 '[2,1,0],[1.5,1,0.1],[1,1,0]')" \
  '{"edges":[0,1,2,3],"reversed":[false,false,false,false]},{"edges":[4,5,6,1],"reversed":[false,false,false,true]}'
sed -i 's/"v":\[1,4\],"sharp":false/"v":[1,4],"sharp":true/' "$tmp/ridge.fnet"
"$fire" reconstruct "$tmp/ridge.fnet" -o "$tmp/u_ridge.obj" --cage "$tmp/u_ridge_cage.obj" --levels 4 >/dev/null
sed '/^t /d' "$tmp/u_ridge_cage.obj" >"$tmp/u_ridge_untagged.obj"
eval_rms() { "$fire" eval "$tmp/u_ridge.obj" --reference "$1" | sed 's/.*"rms":\([0-9.e+-]*\).*/\1/'; }
check "fire eval honours the cage's crease: the surface measured against its own cage, not a rounded one" \
  "grep -q '^t crease 2/1/0 ' '$tmp/u_ridge_cage.obj' && awk -v a=\$(eval_rms '$tmp/u_ridge_cage.obj') -v b=\$(eval_rms '$tmp/u_ridge_untagged.obj') 'BEGIN { exit !(a < 2e-4 && b > 10 * a) }'"
sed 's/^\(t crease 2\/1\/0 [0-9]* [0-9]*\) 10$/\1 2.5/' "$tmp/u_ridge_cage.obj" >"$tmp/u_ridge_soft.obj"
expect_error "a finite crease in a reference" "u_ridge_soft.obj:[0-9]*: crease sharpness 2.5: FIRE's subdivision takes only infinitely sharp creases" \
  "$tmp/none" "$fire" eval "$tmp/u_ridge.obj" --reference "$tmp/u_ridge_soft.obj"
{ cat "$tmp/u_ridge_cage.obj"; echo 't hole 1/0/0 0'; } >"$tmp/u_ridge_hole.obj"
expect_error "a tag FIRE cannot honour" "u_ridge_hole.obj:[0-9]*: tag 'hole' is not one FIRE's subdivision honours" \
  "$tmp/none" "$fire" eval "$tmp/u_ridge.obj" --reference "$tmp/u_ridge_hole.obj"
check "nothing else was left in the folder" "[ -z \"\$(ls '$tmp' | grep -v -e '\\.fnet\$' -e '^square\\.' -e '^s\\.' -e '^digon\\.obj\$' -e '^u\\.stl\$' -e '^u_m\\.obj\$' -e '^u_mm\\.obj\$' -e '^u_cage\\.obj\$' -e '^u_cage\\.usda\$' -e '^u\\.step\$' -e '^u_ridge' -e '^u\\.IGES\$' -e '^stdout\$' -e '^err\$')\" ]"
exit $fail
