#!/usr/bin/env bash
# cmake --install gives a fire that runs the demo's steps on its own: it finds the bundled pawn beside
# itself (share/fire/meshes), prints its version and commit, and needs nothing from the source tree.
#   install.sh BUILD_DIR WORK_DIR
set -euo pipefail
build="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
fail() { echo "FAIL: $*" >&2; exit 1; }
cmake --install "$build" --prefix "$dir/prefix" >/dev/null
fire="$dir/prefix/bin/fire"
[ -x "$fire" ] || fail "no bin/fire installed"
[ -f "$dir/prefix/share/fire/meshes/pawn.obj" ] || fail "the pawn was not installed"
[ -f "$dir/prefix/share/doc/fire/LICENSE" ] || fail "the licence was not installed"
"$fire" --version | grep -q '^fire [0-9.]* (commit ' || fail "--version names no commit: $("$fire" --version)"
cd "$dir"  # nowhere near the source tree
"$fire" simulate wand -o wand.log >/dev/null
"$fire" calibrate wand.log -o rig.json >/dev/null
"$fire" simulate drawing --max-strokes 12 -o drawing.log --marks-out marks.json --object-out pawn20.obj >sim.json
head -1 pawn20.obj | grep -q '^# pawn.obj scaled to 0.2 m' || fail "the simulated object is not the bundled pawn: $(head -1 pawn20.obj)"
"$fire" replay drawing.log --rig rig.json -o drawing.fnet --surface surface.obj >/dev/null
"$fire" eval surface.obj --reference pawn20.obj --network drawing.fnet >eval.json
grep -q '"rms":' eval.json || fail "fire eval printed no rms: $(cat eval.json)"
"$fire" render drawing.fnet -o surface.png >/dev/null
[ -s surface.png ] || fail "no picture rendered"
echo "installed fire ran the demo's steps in $dir"
