#!/usr/bin/env bash
# Reconstruction quality against ground truth (issue 13): for pawn, rook and torus, unrefine K = 2 and 3,
# noise 0, 1, 2 and 4 % drawn independently per point and correlated along each polyline ("1c": 1 %,
# correlation length CORRELATION % of the mean control edge), build a curve network from the control mesh
# (`fire network-from-mesh --limit`), reconstruct it with --method thesis and --method fire, and measure
# each surface with `fire eval` against the control mesh's limit surface and with perf/folds.py. Then the
# demo dome (tools/demo/sketch.log), which has no ground truth: folds, faces facing down and how far its
# curves lie from the surface. Then the simulated tracked drawing of the pawn (`fire simulate drawing` through the
# simulated rig), measured against the pawn. Prints markdown tables for perf/notes/quality.md (and the rows of
# perf/RESULTS.md) on stdout; progress on stderr.
#
# usage: perf/quality.sh [FIRE_BINARY]      (default: build/fire)
# env:   BASELINE=FIRE    a fire binary built from the commit to compare times with (say, main before a
#                         change): its reconstruction of the same network is timed in turn with ours
#        REPEAT=N         time = best of N runs of `fire reconstruct` (its printed `seconds`; default 3)
#        MESHES, KS, NOISES  space-separated subsets (defaults "pawn rook torus", "2 3", "0 1 2 4 1c 2c 4c")
#        CORRELATION=L    correlation length of the "c" noise, percent of the mean control edge (default 50)
#        RECONSTRUCT_ARGS extra options for every `fire reconstruct` (e.g. "--levels 4")
set -u
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
baseline="${BASELINE:-}"
meshes_dir="$here/tests/data/meshes"
repeat="${REPEAT:-3}"
correlation="${CORRELATION:-50}"
read -r -a extra <<<"${RECONSTRUCT_ARGS:-}"
read -r -a meshes <<<"${MESHES:-pawn rook torus}"
read -r -a ks <<<"${KS:-2 3}"
read -r -a noises <<<"${NOISES:-0 1 2 4 1c 2c 4c}"
seed=1
notes=()  # failures, printed under the tables

[ -x "$fire" ] || { echo "perf/quality.sh: $fire not found; build it first (cmake --build build --target fire)" >&2; exit 2; }
[ -z "$baseline" ] || [ -x "$baseline" ] || { echo "perf/quality.sh: BASELINE=$baseline is not an executable" >&2; exit 2; }
command -v python3 >/dev/null || { echo "perf/quality.sh: needs python3 for perf/folds.py" >&2; exit 2; }

field() { sed -n "s/.*\"$1\":\([-+0-9.eEinf]*\).*/\1/p" "$2"; }
folds() { sed -n "s/.*\"$1\": \([-0-9.]*\).*/\1/p" "$2"; }
fmt() { [ -n "$1" ] && awk -v x="$1" 'BEGIN { printf "%.2e", x }' || printf 'n/a'; }
seconds() { awk -v s="$1" 'BEGIN { if (s == "" || s == "failed") print (s == "" ? "n/a" : s); else printf "%.4f", s }'; }
less_than() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'; }
note() { notes+=("[${#notes[@]}] $1"); }
err_text() { tr '\n' ' ' <"$tmp/err" | sed "s|$tmp/||g"; }  # the last command's stderr, on one line

# measure NAME METHOD NET OUT REFERENCE: reconstruct NET with METHOD (best of REPEAT runs: seconds in $t,
# JSON in $tmp/rec), `fire eval` OUT against REFERENCE with the network ($tmp/eval) and perf/folds.py
# ($tmp/folds). On failure: a note, a "failed" row for an N-column table (N in $columns), status 1.
measure() {
  local name="$1" method="$2" net="$3" out="$4" reference="$5"
  if ! t=$(best_seconds "$fire" "$net" "$out" "$method") ||
     ! "$fire" eval "$out" --reference "$reference" --network "$net" >"$tmp/eval" 2>>"$tmp/err"; then
    note "$name $method: $(err_text)"
    printf '| %s | failed [%d] |%s\n' "$method" $(( ${#notes[@]} - 1 )) "$(printf ' |%.0s' $(seq 3 "$columns"))"
    return 1
  fi
  python3 "$here/perf/folds.py" "$out" >"$tmp/folds"
}

# best_seconds BINARY NET OUT METHOD: the best `seconds` of REPEAT reconstructions (empty on failure; the
# last run's JSON stays in $tmp/rec).
best_seconds() {
  local best="" t r
  for ((r = 0; r < repeat; ++r)); do
    "$1" reconstruct "$2" -o "$3" --method "$4" "${extra[@]}" >"$tmp/rec" 2>"$tmp/err" || return 1
    t=$(field seconds "$tmp/rec")
    if [ -z "$best" ] || less_than "$t" "$best"; then best=$t; fi
  done
  echo "$best"
}

echo "Networks: \`fire network-from-mesh MESH --unrefine K --noise P [--noise-correlation $correlation] --seed $seed --limit\`"
echo "(noise \"Pc\": P % correlated along each polyline over $correlation % of the mean control edge length)."
echo "Reconstruction: \`fire reconstruct NET -o OUT.obj --method M${extra[*]:+ ${extra[*]}}\`; rms, hausdorff"
echo "(two-sided) and network_max (largest distance of a polyline point to the surface) are fractions of the"
echo "reference limit surface's bounding-box diagonal (\`fire eval\`); folds: pairs of adjacent surface faces"
echo "whose normals differ by more than 60 degrees (\`perf/folds.py\`); aspect: the fire base mesh's worst quad"
echo "(longest side squared over area; 1 is a square). Time: best of $repeat runs of the \`seconds\` reconstruct"
echo "prints${baseline:+, fire against the baseline binary on the same network, runs taken in turn}."
echo "Goals (fire): K=2 noise 0: rms <= 1e-3, hausdorff <= 5e-3, network_max <= 1e-4; K=2, every noise: 0 folds;"
echo "noise 1, 2, 4 %: rms <= 2e-3, 3e-3, 5e-3; better than thesis on rms and hausdorff on every row."
echo
echo "| mesh | K | noise % | rms thesis | rms fire | hausdorff thesis | hausdorff fire | network_max thesis | network_max fire | folds thesis | folds fire | aspect fire | time fire (s) | time baseline (s) | fire / baseline | fire better (rms, hausdorff) | goals |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"

for mesh in "${meshes[@]}"; do
  for k in "${ks[@]}"; do
    for noise in "${noises[@]}"; do
      percent=${noise%c}
      correlate=()
      [ "$percent" != "$noise" ] && correlate=(--noise-correlation "$correlation")
      net="$tmp/$mesh-$k-$noise.fnet"
      echo "quality: $mesh K=$k noise=$noise" >&2
      if ! "$fire" network-from-mesh "$meshes_dir/$mesh.obj" --unrefine "$k" --noise "$percent" "${correlate[@]}" \
          --seed "$seed" --limit -o "$net" >/dev/null 2>"$tmp/err"; then
        note "$mesh K=$k noise $noise: network-from-mesh failed: $(err_text)"
        echo "| $mesh | $k | $noise | no network [$(( ${#notes[@]} - 1 ))] | | | | | | | | | | | | | |"
        continue
      fi
      declare -A rms=() hd=() nm=() fo=() err=()
      aspect="" secs="" base_secs=""
      for method in thesis fire; do
        out="$tmp/$mesh-$k-$noise-$method.obj"
        if [ "$method" = fire ] && [ -n "$baseline" ]; then
          # Ours and the baseline in turn, so that a change in the machine's load hits both.
          for ((r = 0; r < repeat; ++r)); do
            t=$(repeat=1 best_seconds "$baseline" "$net" "$tmp/base.obj" fire) || { base_secs=failed; break; }
            if [ -z "$base_secs" ] || less_than "$t" "$base_secs"; then base_secs=$t; fi
            t=$(repeat=1 best_seconds "$fire" "$net" "$out" fire) || { secs=""; break; }
            if [ -z "$secs" ] || less_than "$t" "$secs"; then secs=$t; fi
          done
          [ -n "$secs" ] || { note "$mesh K=$k noise $noise fire: $(err_text)"; err[fire]="failed [$(( ${#notes[@]} - 1 ))]"; continue; }
        else
          if ! t=$(best_seconds "$fire" "$net" "$out" "$method"); then
            note "$mesh K=$k noise $noise $method: $(err_text)"
            err[$method]="failed [$(( ${#notes[@]} - 1 ))]"
            continue
          fi
          [ "$method" = fire ] && secs=$t
        fi
        [ "$method" = fire ] && aspect=$(field worst_quad_aspect "$tmp/rec")
        if ! "$fire" eval "$out" --reference "$meshes_dir/$mesh.obj" --network "$net" >"$tmp/eval" 2>"$tmp/err"; then
          note "$mesh K=$k noise $noise $method: $(err_text)"
          err[$method]="eval failed [$(( ${#notes[@]} - 1 ))]"
          continue
        fi
        rms[$method]=$(field rms "$tmp/eval")
        hd[$method]=$(field hausdorff "$tmp/eval")
        nm[$method]=$(field network_max "$tmp/eval")
        python3 "$here/perf/folds.py" "$out" >"$tmp/folds"
        fo[$method]=$(folds pairs_over_60_deg "$tmp/folds")
      done
      better="n/a"
      if [ -z "${err[thesis]:-}" ] && [ -z "${err[fire]:-}" ]; then
        better=$(awk -v rt="${rms[thesis]}" -v rf="${rms[fire]}" -v ht="${hd[thesis]}" -v hf="${hd[fire]}" 'BEGIN {
            s = ""; if (!(rf < rt)) s = s " rms"; if (!(hf < ht)) s = s " hausdorff"; print (s == "" ? "yes" : "no:" s) }')
      fi
      goal="—"
      if [ "$k" = 2 ]; then
        if [ -n "${err[fire]:-}" ]; then goal="not measured"; else
          goal=$(awk -v p="$percent" -v r="${rms[fire]}" -v h="${hd[fire]}" -v n="${nm[fire]}" -v f="${fo[fire]}" 'BEGIN {
            s = ""
            if (p == 0) { if (!(r <= 0.001)) s = s " rms"; if (!(h <= 0.005)) s = s " hausdorff"; if (!(n <= 0.0001)) s = s " network_max" }
            limit = p == 1 ? 0.002 : p == 2 ? 0.003 : p == 4 ? 0.005 : 1
            if (p > 0 && !(r <= limit)) s = s " rms"
            if (f != 0) s = s " folds"
            print (s == "" ? "met" : "missed:" s) }')
        fi
      fi
      ratio="n/a"
      if [ -n "$baseline" ] && [ -n "$secs" ] && [ "$base_secs" != failed ] && [ -n "$base_secs" ]; then
        ratio=$(awk -v a="$secs" -v b="$base_secs" 'BEGIN { printf "%.2f", a / b }')
      fi
      cell() {  # METHOD VALUE: the value, or the method's error
        if [ -n "${err[$1]:-}" ]; then printf '%s' "${err[$1]}"; else fmt "$2"; fi
      }
      echo "| $mesh | $k | $noise | $(cell thesis "${rms[thesis]:-}") | $(cell fire "${rms[fire]:-}") |" \
           "$(cell thesis "${hd[thesis]:-}") | $(cell fire "${hd[fire]:-}") |" \
           "$(cell thesis "${nm[thesis]:-}") | $(cell fire "${nm[fire]:-}") |" \
           "${fo[thesis]:-n/a} | ${fo[fire]:-n/a} | $(awk -v a="$aspect" 'BEGIN { if (a == "") print "n/a"; else printf "%.1f", a }') |" \
           "$(seconds "$secs") | $(seconds "$base_secs") | $ratio | $better | $goal |"
      unset rms hd nm fo err
    done
  done
done

echo
echo "The demo dome (\`fire replay tools/demo/sketch.log --no-surface -o NET\`, then \`fire reconstruct NET\`;"
echo "no ground truth: network_max is measured against the surface itself, in mm as the log is in metres)."
echo "Goal (fire): 0 pairs over 60 degrees, 0 faces facing down, network_max within 1 mm."
echo
echo "| method | faces | pairs over 30 deg | pairs over 60 deg | largest angle (deg) | faces facing down | network_max (mm) | aspect | time (s) | goal |"
echo "|---|---|---|---|---|---|---|---|---|---|"
net="$tmp/demo.fnet"
echo "quality: demo dome" >&2
if ! "$fire" replay "$here/tools/demo/sketch.log" --no-surface -o "$net" >/dev/null 2>"$tmp/err"; then
  note "demo: replay failed: $(tr '\n' ' ' <"$tmp/err")"
else
  for method in thesis fire; do
    out="$tmp/demo-$method.obj"
    columns=10 measure demo "$method" "$net" "$out" "$out" || continue
    aspect=$(field worst_quad_aspect "$tmp/rec")
    mm=$(awk -v n="$(field network_max "$tmp/eval")" -v d="$(field diagonal "$tmp/eval")" 'BEGIN { printf "%.2f", n * d * 1000 }')
    p60=$(folds pairs_over_60_deg "$tmp/folds"); down=$(folds faces_facing_down "$tmp/folds")
    goal="—"
    [ "$method" = fire ] && goal=$(awk -v f="$p60" -v d="$down" -v m="$mm" 'BEGIN {
      s = ""; if (f != 0) s = s " folds"; if (d != 0) s = s " facing-down"; if (!(m <= 1.0)) s = s " network_max"
      print (s == "" ? "met" : "missed:" s) }')
    echo "| $method | $(folds faces "$tmp/folds") | $(folds pairs_over_30_deg "$tmp/folds") | $p60 |" \
         "$(folds max_angle_deg "$tmp/folds") | $down | $mm | $(awk -v a="$aspect" 'BEGIN { printf "%.1f", a }') | $(seconds "$t") | $goal |"
  done
fi

# The simulated tracked drawing: a person draws the pawn's K = 2 network (at 20 cm) through the simulated rig;
# the replay with the calibrated rig gives the network; its true surface is the pawn's limit surface.
echo
echo "The simulated tracked drawing (\`fire simulate drawing\`, \`simulate wand\`, \`calibrate\`, \`fire replay d.log"
echo "--rig rig.json --no-surface -o NET\`, then \`fire reconstruct NET\`; \`fire eval\` against the pawn at 20 cm, the"
echo "drawn object). network_rms: root mean square distance of the polyline points to the surface. No goal of its own."
echo
echo "| method | rms | hausdorff | network_max | network_rms | pairs over 30 deg | pairs over 60 deg | largest angle (deg) | aspect | time (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
echo "quality: simulated tracked drawing" >&2
sim="$tmp/sim"
mkdir -p "$sim"
if ! { "$fire" simulate drawing -o "$sim/d.log" --marks-out "$sim/marks.json" --object-out "$sim/pawn20.obj" &&
       "$fire" simulate wand -o "$sim/w.log" && "$fire" calibrate "$sim/w.log" -o "$sim/rig.json" &&
       "$fire" replay "$sim/d.log" --rig "$sim/rig.json" --no-surface -o "$sim/net.fnet"; } >/dev/null 2>"$tmp/err"; then
  note "simulated drawing: $(tail -3 "$tmp/err" | tr '\n' ' ' | sed "s|$tmp/||g")"
  echo "| failed [$(( ${#notes[@]} - 1 ))] | | | | | | | | | |"
else
  for method in thesis fire; do
    out="$sim/$method.obj"
    columns=10 measure "simulated drawing" "$method" "$sim/net.fnet" "$out" "$sim/pawn20.obj" || continue
    echo "| $method | $(fmt "$(field rms "$tmp/eval")") | $(fmt "$(field hausdorff "$tmp/eval")") |" \
         "$(fmt "$(field network_max "$tmp/eval")") | $(fmt "$(field network_rms "$tmp/eval")") |" \
         "$(folds pairs_over_30_deg "$tmp/folds") | $(folds pairs_over_60_deg "$tmp/folds") | $(folds max_angle_deg "$tmp/folds") |" \
         "$(awk -v a="$(field worst_quad_aspect "$tmp/rec")" 'BEGIN { printf "%.1f", a }') | $(seconds "$t") |"
  done
fi

if [ ${#notes[@]} -gt 0 ]; then
  echo
  echo "Failures:"
  for n in "${notes[@]}"; do echo "- $n"; done
fi
