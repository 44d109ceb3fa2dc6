#!/usr/bin/env bash
# `fire render` as a user runs it, on lavapipe or a GPU with the validation layer on (FIRE_VK_VALIDATION=1
# from ctest): a network and an input log become PNGs of the asked size, with `fire reconstruct`'s surface
# options; bad input (no Vulkan device, a
# reference mesh that does not load, a PNG that cannot be written, a bad view or size, a log of Wii Remote
# reports without its --rig) exits 1 with a message saying what is wrong, and writes nothing.
set -u
fire="$1" here="$2" log="$3"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAILED: $1"; fail=1; fi; }
# expect_error NAME PATTERN OUT CMD...: exit code 1 (not a crash), stderr matching PATTERN, no OUT
expect_error() {
  local name="$1" pattern="$2" out="$3"; shift 3
  "$@" >"$tmp/stdout" 2>"$tmp/err"; local rc=$?
  if [ $rc -eq 1 ] && grep -q -- "$pattern" "$tmp/err" && [ ! -e "$out" ] && [ ! -s "$tmp/stdout" ]; then
    echo "ok: $name"; else echo "FAILED: $name (exit $rc)"; cat "$tmp/err"; fail=1; fi
}
# png_size FILE: "WIDTH HEIGHT" from the PNG's IHDR chunk
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{print $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8}'; }
# some_partial_upload FILE: a JSON line of --every whose edges_uploaded is below its edges
some_partial_upload() {
  sed -n 's/.*"edges":\([0-9]*\),.*"edges_uploaded":\([0-9]*\),.*/\1 \2/p' "$1" | awk '$2 < $1 {n++} END {exit !(n > 0)}'
}
is_png() { [ "$(od -An -c -j1 -N3 "$1" | tr -d ' ')" = "PNG" ]; }

out=$("$fire" render "$here/data/sketch.fnet" -o "$tmp/net.png" --size 400x300 --view front 2>"$tmp/err"); rc=$?
check "a network renders (exit 0, nothing on stderr)" "[ $rc -eq 0 ] && [ ! -s '$tmp/err' ]"
check "prints one JSON line with the device and the counts" \
  "echo '$out' | grep -q '^{\"output\":\"$tmp/net.png\",\"width\":400,\"height\":300,\"view\":\"front\",\"device\":\"[^\"]*\",\"edges\":32,\"surface_quads\":3328,\"bytes_uploaded\":[1-9][0-9]*,\"validation\":true}$'"
check "writes a 400x300 PNG" "is_png '$tmp/net.png' && [ \"\$(png_size '$tmp/net.png')\" = '400 300' ]"

# The surface options are `fire reconstruct`'s: the picture shows the surface that command exports.
out=$("$fire" render "$here/data/sketch.fnet" -o "$tmp/steps.png" --size 400x300 --view front --coons-steps 2 --levels 2 --fairness 0.05 2>"$tmp/err"); rc=$?
# The dome's 51 base faces, 4 of them pentagons beside its long side (kLongSideRatio), have 208 corners: 3328
# quads at level 3. 2 steps give 204 base faces, 8 of them pentagons there: 824 corners, 3296 quads at level 2.
check "--coons-steps, --levels and --fairness reach the reconstruction (2 steps at level 2: 3296 quads)" \
  "[ $rc -eq 0 ] && echo '$out' | grep -q '\"surface_quads\":3296,'"
"$fire" reconstruct "$here/data/sketch.fnet" -o "$tmp/steps.obj" --coons-steps 2 --levels 2 --fairness 0.05 >/dev/null
"$fire" reconstruct "$here/data/sketch.fnet" -o "$tmp/default.obj" >/dev/null
"$fire" render "$here/data/sketch.fnet" -o "$tmp/steps-noise.png" --size 400x300 --view front --coons-steps 2 --levels 2 >/dev/null
check "that surface is not the default one, nor the one with the fairness from the noise" \
  "! cmp -s '$tmp/steps.png' '$tmp/net.png' && ! cmp -s '$tmp/steps.png' '$tmp/steps-noise.png' && ! cmp -s '$tmp/steps.obj' '$tmp/default.obj'"
out=$("$fire" render "$here/data/sketch.fnet" -o "$tmp/thesis.png" --size 400x300 --method thesis --levels 2 2>"$tmp/err"); rc=$?
check "--method thesis renders the thesis's surface" "[ $rc -eq 0 ] && echo '$out' | grep -q '\"surface_quads\":[1-9]'"
expect_error "Coons steps out of range" "fire render: the number of Coons steps must be 1 to 5, not 9" "$tmp/c9.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/c9.png" --coons-steps 9
expect_error "an unknown method" "fire render: --method must be thesis or fire" "$tmp/m.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/m.png" --method magic
expect_error "a fairness out of range" "fire render: the fairness weight must be 0 to 1" "$tmp/f.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/f.png" --fairness 2

"$fire" render "$log" -o "$tmp/log.png" --size 320x180 --view top >"$tmp/stdout" 2>"$tmp/err"; rc=$?
check "an input log is replayed and rendered" "[ $rc -eq 0 ] && is_png '$tmp/log.png' && [ \"\$(png_size '$tmp/log.png')\" = '320 180' ]"
check "the replay's rejected stroke is reported, not fatal" "grep -q 'rejected' '$tmp/err'"

"$fire" render "$log" --every 40 --png-dir "$tmp/frames" --size 160x90 >"$tmp/seq" 2>"$tmp/err"; rc=$?
pictures=$(ls "$tmp/frames" 2>/dev/null | grep -c '^frame_[0-9]*\.png$')
check "--every: a picture per JSON line as the sketch grows (exit 0, at least 10)" \
  "[ $rc -eq 0 ] && [ $pictures -ge 10 ] && [ \$(grep -c '^{\"frame\":' '$tmp/seq') -eq $pictures ]"
check "--every: the last picture has the final network and surface" "tail -1 '$tmp/seq' | grep -q '\"edges\":32,\"surface_quads\":3328,'"
check "--every: some picture re-sends fewer edges than the network has" "some_partial_upload '$tmp/seq'"
expect_error "--every with a network file" "--every needs an input log" "$tmp/frames2" \
  "$fire" render "$here/data/sketch.fnet" --every 5 --png-dir "$tmp/frames2"
expect_error "neither -o nor --every" "give either -o OUT.png or --every N" "$tmp/none" "$fire" render "$log"

printf 'v 0 0 0\nv 0.2 0 0\nv 0.2 0.2 0\nv 0 0.2 0\nf 1 2 3 4\n' >"$tmp/plane.obj"
"$fire" render "$here/data/sketch.fnet" -o "$tmp/ref.png" --size 320x180 --reference "$tmp/plane.obj" >/dev/null 2>"$tmp/err"; rc=$?
check "a reference mesh is drawn with the network" "[ $rc -eq 0 ] && is_png '$tmp/ref.png'"
check "the reference changes the image" "! cmp -s '$tmp/ref.png' '$tmp/log.png'"

expect_error "no Vulkan device: says where lavapipe comes from" "mesa-vulkan-drivers" "$tmp/none.png" \
  env VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json "$fire" render "$here/data/sketch.fnet" -o "$tmp/none.png"
printf 'v 0 0 0\nf 1 2 3\n' >"$tmp/broken.obj"
expect_error "a reference mesh that does not load" "--reference: .*broken.obj" "$tmp/broken.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/broken.png" --reference "$tmp/broken.obj"
expect_error "a missing reference mesh" "--reference: .*missing.obj" "$tmp/missing.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/missing.png" --reference "$tmp/missing.obj"
expect_error "a PNG path that cannot be written" "$tmp/no/such/dir/x.png: cannot write" "$tmp/no/such/dir/x.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/no/such/dir/x.png" --size 64x64
expect_error "an output that is not a PNG" "must be a .png" "$tmp/x.jpg" "$fire" render "$here/data/sketch.fnet" -o "$tmp/x.jpg"
expect_error "an unknown view" "--view must be iso, front, top, side or bottom" "$tmp/v.png" \
  "$fire" render "$here/data/sketch.fnet" -o "$tmp/v.png" --view diagonal
expect_error "a bad size" "--size must be WIDTHxHEIGHT" "$tmp/s.png" "$fire" render "$here/data/sketch.fnet" -o "$tmp/s.png" --size 0x10
expect_error "a network that does not load" "missing.fnet" "$tmp/n.png" "$fire" render "$tmp/missing.fnet" -o "$tmp/n.png"

# A log of Wii Remote reports (the demo's kind): drawn through the triangulation system with --rig, refused
# without one. The simulated person draws the border of the pawn's --unrefine 4 network (24 curves made 18 edges)
# and stops there (--max-strokes: it could draw no more of that network, and would say so with exit 1).
"$fire" simulate wand -o "$tmp/wand.log" >/dev/null && "$fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null 2>&1 &&
  "$fire" simulate drawing -o "$tmp/drawing.log" --marks-out "$tmp/marks.json" --object-out "$tmp/pawn.obj" --unrefine 4 \
    --max-strokes 18 >/dev/null
check "a simulated rig and drawing" "[ -s '$tmp/rig.json' ] && [ -s '$tmp/drawing.log' ]"
out=$("$fire" render "$tmp/drawing.log" --rig "$tmp/rig.json" -o "$tmp/tracked.png" --size 320x180 2>"$tmp/err"); rc=$?
check "a log of reports rendered with --rig: its tracked border and the surface inside it" \
  "[ $rc -eq 0 ] && is_png '$tmp/tracked.png' && echo '$out' | grep -q '\"edges\":18,\"surface_quads\":[1-9]'"
expect_error "a log of reports without --rig" "holds Wii Remote reports; give the rig" "$tmp/untracked.png" \
  "$fire" render "$tmp/drawing.log" -o "$tmp/untracked.png"
expect_error "--rig with a network" "--rig is for an input log" "$tmp/r.png" \
  "$fire" render "$here/data/sketch.fnet" --rig "$tmp/rig.json" -o "$tmp/r.png"
exit $fail
