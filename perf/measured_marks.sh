#!/usr/bin/env bash
# Marks measured by touch (issue 42, item 1): for each seed, the simulated person draws the same object twice,
# once registering on the marks file's coordinates (cmd mark N X Y Z) and once measuring the marks by touch
# (`fire simulate drawing --measure-marks`: cmd table, cmd measure N, cmd mark N). Both are replayed through
# every frame system (`fire replay --rig`); the measured drawing's surface is brought into the object's frame by
# the marks (`fire eval --align TRUE.json MEASURED.json`) and both are measured against the object. The two
# drawings have different timelines (the measured one has more touches), so each draws its own tracking noise;
# the measured log is therefore also replayed with its marks registered on the marks file's coordinates (its
# first round's `cmd measure N` and every `cmd mark N` given the true X Y Z, its table touches and later
# measures left out): the same strokes, the same noise, only the marks' source differs. Prints a markdown table
# for perf/RESULTS.md: seed, rms of each (fraction of the diagonal), the measured drawing's ratio to the marks
# file's drawing and to its own log on the file's marks, the alignment's residual, marks measured and
# registrations. Progress on stderr.
#
# usage: perf/measured_marks.sh [FIRE_BINARY]   (default: build/fire)
# env:   MESH (default pawn), SEEDS (default "1 2 3 4 5")
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
mesh="$here/tests/data/meshes/${MESH:-pawn}.obj"
field() { sed -n "s/.*\"$1\": *\([-+0-9.eE]*\).*/\1/p" "$2" | head -1; }

"$fire" simulate wand -o "$tmp/wand.log" >/dev/null
"$fire" calibrate "$tmp/wand.log" -o "$tmp/rig.json" >/dev/null 2>&1
echo "| object | seed | rms, marks file | rms, marks measured | ratio | rms, the measured log on the file's marks | ratio, same log | align residual mm | marks measured | registrations |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for seed in ${SEEDS:-1 2 3 4 5}; do
  for how in file measured; do
    echo "measured_marks: ${MESH:-pawn} seed $seed, marks $how" >&2
    d="$tmp/$seed-$how"
    mkdir -p "$d"
    extra=()
    [ "$how" = measured ] && extra=(--measure-marks)
    "$fire" simulate drawing --mesh "$mesh" --seed "$seed" "${extra[@]}" -o "$d/drawing.log" --marks-out "$d/marks.json" \
      --object-out "$d/object.obj" >"$d/drawing.json"
    if [ "$how" = measured ]; then
      "$fire" replay "$d/drawing.log" --rig "$tmp/rig.json" -o "$d/drawing.fnet" --surface "$d/surface.obj" \
        --measured-marks-out "$d/measured.json" >/dev/null 2>"$d/replay.txt"
      "$fire" eval "$d/surface.obj" --reference "$d/object.obj" --network "$d/drawing.fnet" \
        --align "$d/marks.json" "$d/measured.json" >"$d/eval.json"
    else
      "$fire" replay "$d/drawing.log" --rig "$tmp/rig.json" -o "$d/drawing.fnet" --surface "$d/surface.obj" >/dev/null 2>"$d/replay.txt"
      "$fire" eval "$d/surface.obj" --reference "$d/object.obj" --network "$d/drawing.fnet" >"$d/eval.json"
    fi
  done
  f="$tmp/$seed-file" m="$tmp/$seed-measured"
  python3 - "$m/drawing.log" "$m/marks.json" "$m/on_file_marks.log" <<'PY'
import json, sys
log, marks, out = sys.argv[1:]
xyz = {m["id"]: (m["x"], m["y"], m["z"]) for m in json.load(open(marks))["marks"]}
first_round = True
with open(out, "w") as w:
    for line in open(log):
        f = line.split()
        if len(f) >= 3 and f[1] == "cmd":
            if f[2] == "table" or (f[2] == "measure" and not first_round):
                continue
            if f[2] in ("measure", "mark") and len(f) == 4:
                line = " ".join([f[0], "cmd", "mark", f[3]] + ["%.17g" % v for v in xyz[int(f[3])]]) + "\n"
            first_round = first_round and f[2] != "register"
        w.write(line)
PY
  "$fire" replay "$m/on_file_marks.log" --rig "$tmp/rig.json" -o "$m/on_file_marks.fnet" --surface "$m/on_file_marks.obj" \
    >/dev/null 2>"$m/on_file_marks.txt"
  "$fire" eval "$m/on_file_marks.obj" --reference "$m/object.obj" --network "$m/on_file_marks.fnet" >"$m/on_file_marks.json"
  awk -v o="${MESH:-pawn}" -v s="$seed" -v a="$(field rms "$f/eval.json")" -v b="$(field rms "$m/eval.json")" \
      -v c="$(field rms "$m/on_file_marks.json")" \
      -v r="$(field align_residual "$m/eval.json")" -v k="$(field align_marks "$m/eval.json")" \
      -v g="$(field registrations "$m/drawing.json")" \
      'BEGIN { printf "| %s | %s | %.3e | %.3e | %.3f | %.3e | %.3f | %.3f | %s | %s |\n", o, s, a, b, b / a, c, b / c, r * 1000, k, g }'
done
