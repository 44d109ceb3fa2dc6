#!/usr/bin/env bash
# The engine's commands as a user runs them: help, replay hashes, and bad files.
set -u
fire="$1"; src="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAILED: $1"; fail=1; fi; }
# expect_error NAME PATTERN CMD...: non-zero exit, stderr matching PATTERN
expect_error() {
  local name="$1" pattern="$2"; shift 2
  "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  if [ $rc -ne 0 ] && grep -q -- "$pattern" "$tmp/err"; then echo "ok: $name"; else
    echo "FAILED: $name (exit $rc)"; cat "$tmp/err"; fail=1; fi
}

check "fire --help" "'$fire' --help | grep -q replay"
check "replay --help lists --hash" "'$fire' replay --help | grep -q -- --hash"
check "export-network --help" "'$fire' export-network --help | grep -q OBJ"
h1=$("$fire" replay "$src/tools/demo/sketch.log" --hash 2>/dev/null)
h2=$("$fire" replay "$src/tools/demo/sketch.log" --hash 2>/dev/null)
check "replay hash is stable ($h1)" "[ -n '$h1' ] && [ '$h1' = '$h2' ]"
check "replay --progress says how far it is on stderr, every 10 %, sums up, and prints the same hash" \
  "[ \"\$('$fire' replay '$src/tools/demo/sketch.log' --hash --progress 2>'$tmp/progress')\" = '$h1' ] && grep -q '^fire replay: 100 % of the log' '$tmp/progress' && [ \$(grep -c '% of the log' '$tmp/progress') -eq 11 ] && grep -qE '^fire replay: [0-9]+ frames in [0-9.]+ s: [0-9]+ edits applied, [0-9]+ rejected, [0-9]+ curves$' '$tmp/progress'"
# The hash of the pools and the surface every build on every machine must print for the bundled demo
# (regenerate it only when the demo log, the pools or the surface change on purpose).
golden=$(cat "$src/tests/engine/demo.hash")
check "replay hash matches the recorded one ($golden)" "[ '$h1' = '$golden' ]"
check "replay writes the network" "'$fire' replay '$src/tools/demo/sketch.log' -o '$tmp/demo.fnet' 2>/dev/null && [ -s '$tmp/demo.fnet' ]"
# --until-stroke N: the drawing as it was after its N-th committed pen stroke. The demo's 18 strokes end the log, so
# the 18th gives the whole replay's hash; after 4 it is the closed border alone (one face), after 5 its first split.
check "replay --until-stroke 18 of the demo's 18 strokes prints the whole replay's hash" \
  "[ \"\$('$fire' replay '$src/tools/demo/sketch.log' --until-stroke 18 --hash 2>/dev/null)\" = '$h1' ]"
check "replay --until-stroke 4 and 5: the border alone, then its first split" \
  "'$fire' replay '$src/tools/demo/sketch.log' --until-stroke 4 -o '$tmp/u4.fnet' 2>/dev/null && grep -o '\"reversed\"' '$tmp/u4.fnet' | wc -l | grep -qx 1 && '$fire' replay '$src/tools/demo/sketch.log' --until-stroke 5 -o '$tmp/u5.fnet' 2>/dev/null && grep -o '\"reversed\"' '$tmp/u5.fnet' | wc -l | grep -qx 2"
expect_error "replay --until-stroke past the log's strokes says how many it has" "commits 18 pen stroke(s), not 19" \
  "$fire" replay "$src/tools/demo/sketch.log" --until-stroke 19
expect_error "replay --until-stroke 0 is refused, saying what it must be" "until-stroke: must be at least 1, not 0" "$fire" replay "$src/tools/demo/sketch.log" --until-stroke 0
# The surface the frame's refine and subdivide systems left equals a reconstruction from scratch of the
# same network, byte for byte.
check "replay writes the surface, to each --surface" "'$fire' replay '$src/tools/demo/sketch.log' -o '$tmp/s.fnet' --surface '$tmp/live.obj' --surface '$tmp/live.glb' 2>/dev/null && [ -s '$tmp/live.obj' ]"
check "the live surface equals a full rebuild" "'$fire' reconstruct '$tmp/s.fnet' -o '$tmp/full.obj' && cmp -s '$tmp/live.obj' '$tmp/full.obj'"
check "so does its second file" "'$fire' reconstruct '$tmp/s.fnet' -o '$tmp/full.glb' && cmp -s '$tmp/live.glb' '$tmp/full.glb'"
check "--timings gives each system and the frame by the wall and by the thread's CPU time, and how much faster than drawn" \
  "'$fire' replay '$src/tools/demo/sketch.log' --timings 2>/dev/null >'$tmp/timings.txt' && [ \$(grep -c '^system .* max .* cpu mean .* max ' '$tmp/timings.txt') -eq 9 ] && grep -q '^log .* s replayed in .* times faster' '$tmp/timings.txt'"
check "--no-surface skips refine and subdivide" "'$fire' replay '$src/tools/demo/sketch.log' --no-surface --timings 2>/dev/null | grep -q 'surface: level 0, 0 quads'"
expect_error "--surface with an unknown extension" "unknown surface format" "$fire" replay "$src/tools/demo/sketch.log" --surface "$tmp/x.xyz"
check "export-network writes one l per edge" "'$fire' export-network '$tmp/demo.fnet' -o '$tmp/demo.obj' && [ \$(grep -c '^l ' '$tmp/demo.obj') -eq 32 ]"

printf 'FIRE-LOG 1\n0 down\n10 pen 1 2' >"$tmp/trunc.log"
expect_error "truncated log" "trunc.log:3: truncated" "$fire" replay "$tmp/trunc.log"
printf 'FIRE-LOG 9\n' >"$tmp/v9.log"
expect_error "unknown log version" "unknown input log version '9'" "$fire" replay "$tmp/v9.log"
expect_error "missing log" "cannot open" "$fire" replay "$tmp/nope.log"
expect_error "a folder given as a network" "is a folder, not a file" "$fire" reconstruct "$tmp" -o "$tmp/x.obj"
expect_error "export-network to another format's name" "give a name ending in .obj" "$fire" export-network "$tmp/demo.fnet" -o "$tmp/x.ply"
check "and writes nothing there" "[ ! -e '$tmp/x.ply' ]"
# Usage errors exit 2 and name the command; --version prints the version.
usage_exit() { "$@" >/dev/null 2>"$tmp/err"; [ $? -eq 2 ]; }
check "an unknown command exits 2, named" "usage_exit '$fire' frobnicate && grep -q \"fire: 'frobnicate' is not a command\" '$tmp/err'"
check "an unknown option exits 2, naming the command" "usage_exit '$fire' replay --bogus && grep -q '^fire replay: .*--bogus' '$tmp/err'"
check "a malformed value exits 2, naming the subcommand" "usage_exit '$fire' simulate drawing --seed x && grep -q '^fire simulate drawing: ' '$tmp/err'"
check "an unknown option of reconstruct exits 2, naming it" "usage_exit '$fire' reconstruct x.fnet -o x.obj --frobnicate && grep -q '^fire reconstruct: .*--frobnicate' '$tmp/err'"
check "no command exits 2" "usage_exit '$fire'"
check "--version names the version and the commit" "'$fire' --version | grep -q '^fire [0-9][0-9.]* (commit [0-9a-f]'"
head -c 300 "$tmp/demo.fnet" >"$tmp/trunc.fnet"
expect_error "truncated network" "trunc.fnet: not valid JSON" "$fire" export-network "$tmp/trunc.fnet" -o "$tmp/x.obj"
sed 's/"version":1/"version":3/' "$tmp/demo.fnet" >"$tmp/v3.fnet"
expect_error "network version" "unsupported network version 3" "$fire" export-network "$tmp/v3.fnet" -o "$tmp/x.obj"
: >"$tmp/empty.fnet"
expect_error "empty network" "empty file" "$fire" export-network "$tmp/empty.fnet" -o "$tmp/x.obj"
check "no partial output after errors" "[ ! -e '$tmp/x.obj' ]"
expect_error "unwritable output" "cannot write" "$fire" export-network "$tmp/demo.fnet" -o "$tmp/no/such/dir/x.obj"
# Session folders (engine/SESSION.md): written while replaying, reopened to the same hash, damage named.
check "replay --help tells of --session" "'$fire' replay --help | grep -q -- '--snapshot-every'"
check "open --help" "'$fire' open --help | grep -q 'torn last record'"
check "replay --session writes a log and snapshots" "'$fire' replay '$src/tools/demo/sketch.log' --session '$tmp/s' --snapshot-every 300 >/dev/null 2>&1 && [ -s '$tmp/s/input.log' ] && ls '$tmp/s' | grep -q 'snapshot-.*fsnap'"
check "fire open prints the demo's hash" "[ \"\$('$fire' open '$tmp/s' 2>/dev/null)\" = '$golden' ]"
check "fire replay DIR reopens it" "[ \"\$('$fire' replay '$tmp/s' --hash 2>/dev/null)\" = '$golden' ]"
check "the session's log replays alone to the same hash" "[ \"\$('$fire' replay '$tmp/s/input.log' --hash 2>/dev/null)\" = '$golden' ]"
expect_error "a session is written into a new folder" "not empty" "$fire" replay "$src/tools/demo/sketch.log" --session "$tmp/s"
expect_error "--snapshot-every needs --session" "needs --session" "$fire" replay "$src/tools/demo/sketch.log" --snapshot-every 5
expect_error "session settings are not overridden" "settings.json" "$fire" replay "$tmp/s" --levels 2
expect_error "missing session folder" "nope: no such session folder" "$fire" open "$tmp/nope"
# fire replay takes fire reconstruct's surface options; a session keeps them all and reopens with them.
h2=$("$fire" replay "$src/tools/demo/sketch.log" --coons-steps 2 --hash 2>/dev/null)
check "replay --coons-steps 2 builds another surface ($h2)" "[ -n '$h2' ] && [ '$h2' != '$golden' ]"
expect_error "replay refuses Coons steps out of range" "fire replay: the number of Coons steps must be 1 to 5, not 9" \
  "$fire" replay "$src/tools/demo/sketch.log" --coons-steps 9 --hash
expect_error "replay refuses an unknown planarity" "fire replay: --planarity must be" \
  "$fire" replay "$src/tools/demo/sketch.log" --planarity flat --hash
ht=$("$fire" replay "$src/tools/demo/sketch.log" --method thesis --planarity hough --session "$tmp/thesis" --hash 2>/dev/null)
check "a session with the thesis's method and the Hough measure reopens to its hash" \
  "[ -n '$ht' ] && [ '$ht' != '$golden' ] && [ \"\$('$fire' open '$tmp/thesis' 2>/dev/null)\" = '$ht' ]"
expect_error "session settings are not overridden, whichever surface option" "settings.json" "$fire" replay "$tmp/thesis" --method fire
cp -r "$tmp/s" "$tmp/bad"; newest=$(ls "$tmp/bad"/snapshot-* | tail -1)
printf 'XXXX' | dd of="$newest" bs=1 seek=200 conv=notrunc 2>/dev/null
"$fire" open "$tmp/bad" >"$tmp/out" 2>"$tmp/err"
check "a damaged snapshot is named and the one before used" "grep -q \"$(basename "$newest"): checksum mismatch\" '$tmp/err' && [ \"\$(cat '$tmp/out')\" = '$golden' ]"
cp -r "$tmp/s" "$tmp/torn"; rm "$tmp/torn"/snapshot-*; printf '16900000 pen 0.1 0.1' >>"$tmp/torn/input.log"
"$fire" open "$tmp/torn" >"$tmp/out" 2>"$tmp/err"
check "a torn last record is dropped with its size" "grep -q 'torn last record dropped (20 bytes' '$tmp/err' && [ \"\$(cat '$tmp/out')\" = '$golden' ]"
sed -i '5s/pen/pne/' "$tmp/torn/input.log"
expect_error "corruption before the last line is refused" "input.log:5: unknown event kind 'pne'" "$fire" open "$tmp/torn"
rm "$tmp/torn/settings.json"
expect_error "a session without settings" "settings.json: cannot open" "$fire" open "$tmp/torn"
# The frame as the README shows it is the frame the code declares.
awk '/^<!-- fire replay --schedule -->$/ { marked = 1; next } marked && /^```$/ { if (inside) exit; inside = 1; next } inside' \
  "$src/README.md" >"$tmp/readme_schedule"
"$fire" replay --schedule >"$tmp/schedule"
check "fire replay --schedule prints the frame the README shows" "[ -s '$tmp/schedule' ] && cmp -s '$tmp/schedule' '$tmp/readme_schedule'"
check "the frame names every system in order" "[ \"\$(cut -d: -f1 '$tmp/schedule' | tr '\\n' ' ')\" = 'input triangulate register sketch split refine subdivide snap ' ]"
expect_error "fire replay without LOG says it is needed" "LOG is required" "$fire" replay
expect_error "unknown subcommand" "" "$fire" frobnicate
exit $fail
