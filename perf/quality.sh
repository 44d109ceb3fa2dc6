#!/usr/bin/env bash
# Reconstruction quality against ground truth (issue 3): for pawn, rook and torus, unrefine K = 2 and 3,
# noise 0 and 1 %, build a curve network from the control mesh (`fire network-from-mesh`, sampled on the
# limit surface with --limit when the binary has it), reconstruct it with --method thesis and --method
# fire (`fire reconstruct`), and measure each surface with `fire eval` against the control mesh's limit
# surface. Prints a markdown table for perf/RESULTS.md on stdout; progress goes to stderr.
#
# usage: perf/quality.sh [FIRE_BINARY]      (default: build/fire)
# env:   REPEAT=N          reconstruction time (the `seconds` reconstruct prints) = best of N runs (default 3)
#        RECONSTRUCT_ARGS  extra options for every `fire reconstruct` (e.g. "--levels 3")
#        MESHES            space-separated mesh names (default "pawn rook torus")
set -u
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
fire="${1:-$here/build/fire}"
meshes_dir="$here/../shared/data/meshes"
repeat="${REPEAT:-3}"
read -r -a extra <<<"${RECONSTRUCT_ARGS:-}"
read -r -a meshes <<<"${MESHES:-pawn rook torus}"
seed=1
notes=()  # failures, printed under the table

[ -x "$fire" ] || { echo "perf/quality.sh: $fire not found; build it first (cmake --build build --target fire)" >&2; exit 2; }
if ! "$fire" reconstruct --help >/dev/null 2>&1; then
  echo "perf/quality.sh: $fire has no 'reconstruct' subcommand yet; nothing to measure" >&2
  exit 2
fi
limit=()
limit_note="--limit (polylines sample the limit surface)"
if "$fire" network-from-mesh --help 2>/dev/null | grep -q -- '--limit'; then
  limit=(--limit)
else
  limit_note="NO --limit: this binary's network-from-mesh has no --limit, so polylines are sampled linearly on the control edges and lie off the limit surface"
fi

tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
field() { sed -n "s/.*\"$1\":\([-+0-9.eE]*\).*/\1/p" "$2"; }
fmt() { [ -n "$1" ] && awk -v x="$1" 'BEGIN { printf "%.2e", x }' || printf 'n/a'; }

echo "Reconstruction quality: fractions of the reference limit surface's bounding-box diagonal (rms, hausdorff:"
echo "two-sided, densely sampled; network_max: largest distance of a network polyline point to the surface)."
net_cmd="fire network-from-mesh MESH --unrefine K --noise P --seed $seed${limit[*]:+ ${limit[*]}}"
rec_cmd="fire reconstruct NET -o OUT.obj --method M${extra[*]:+ ${extra[*]}}"
echo "Networks: \`$net_cmd\`; $limit_note."
echo "Time: the \`seconds\` that \`$rec_cmd\` prints (reconstruction only, file I/O excluded), best of $repeat."
echo "Goal for fire at K=2, noise 0: rms <= 0.001, hausdorff <= 0.005, network_max <= 0.0001."
echo
echo "| mesh | K | noise % | rms thesis | rms fire | hausdorff thesis | hausdorff fire | network_max thesis | network_max fire | time thesis (s) | time fire (s) | fire better on all three | goal (K=2, noise 0) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"

for mesh in "${meshes[@]}"; do
  for k in 2 3; do
    for noise in 0 1; do
      net="$tmp/$mesh-$k-$noise.fnet"
      echo "quality: $mesh K=$k noise=$noise" >&2
      if ! "$fire" network-from-mesh "$meshes_dir/$mesh.obj" --unrefine "$k" --noise "$noise" --seed "$seed" "${limit[@]}" \
          -o "$net" >/dev/null 2>"$tmp/err"; then
        notes+=("[${#notes[@]}] $mesh K=$k noise $noise: network-from-mesh failed: $(tr '\n' ' ' <"$tmp/err" | sed "s|$tmp/||g")")
        echo "| $mesh | $k | $noise | no network [$(( ${#notes[@]} - 1 ))] | | | | | | | | | |"
        continue
      fi
      declare -A rms=() hd=() nm=() secs=() err=()
      for method in thesis fire; do
        out="$tmp/$mesh-$k-$noise-$method.obj"
        best=""
        for ((r = 0; r < repeat; ++r)); do
          if ! "$fire" reconstruct "$net" -o "$out" --method "$method" "${extra[@]}" >"$tmp/rec" 2>"$tmp/err"; then
            notes+=("[${#notes[@]}] $mesh K=$k noise $noise $method: $(tr '\n' ' ' <"$tmp/err" | sed "s|$tmp/||g")")
            err[$method]="failed [$(( ${#notes[@]} - 1 ))]"
            break
          fi
          t=$(field seconds "$tmp/rec")
          if [ -z "$best" ] || awk -v t="$t" -v b="$best" 'BEGIN { exit !(t < b) }'; then best=$t; fi
        done
        [ -n "${err[$method]:-}" ] && continue
        secs[$method]=$(awk -v s="$best" 'BEGIN { printf "%.4f", s }')
        if ! "$fire" eval "$out" --reference "$meshes_dir/$mesh.obj" --network "$net" >"$tmp/eval" 2>"$tmp/err"; then
          notes+=("[${#notes[@]}] $mesh K=$k noise $noise $method: $(tr '\n' ' ' <"$tmp/err" | sed "s|$tmp/||g")")
          err[$method]="eval failed [$(( ${#notes[@]} - 1 ))]"
          continue
        fi
        rms[$method]=$(field rms "$tmp/eval")
        hd[$method]=$(field hausdorff "$tmp/eval")
        nm[$method]=$(field network_max "$tmp/eval")
      done
      better="n/a"
      if [ -z "${err[thesis]:-}" ] && [ -z "${err[fire]:-}" ]; then
        better=$(awk -v rt="${rms[thesis]}" -v rf="${rms[fire]}" -v ht="${hd[thesis]}" -v hf="${hd[fire]}" \
          -v nt="${nm[thesis]}" -v nf="${nm[fire]}" 'BEGIN {
            s = ""; if (!(rf < rt)) s = s " rms"; if (!(hf < ht)) s = s " hausdorff"; if (!(nf < nt)) s = s " network_max";
            print (s == "" ? "yes" : "no:" s) }')
      fi
      goal="—"
      if [ "$k" = 2 ] && [ "$noise" = 0 ]; then
        if [ -n "${err[fire]:-}" ]; then goal="not measured"; else
          goal=$(awk -v r="${rms[fire]}" -v h="${hd[fire]}" -v n="${nm[fire]}" 'BEGIN {
            s = ""; if (!(r <= 0.001)) s = s " rms"; if (!(h <= 0.005)) s = s " hausdorff"; if (!(n <= 0.0001)) s = s " network_max";
            print (s == "" ? "met" : "missed:" s) }')
        fi
      fi
      cell() {  # METHOD VALUE: the value, or the method's error
        if [ -n "${err[$1]:-}" ]; then printf '%s' "${err[$1]}"; else fmt "$2"; fi
      }
      echo "| $mesh | $k | $noise | $(cell thesis "${rms[thesis]:-}") | $(cell fire "${rms[fire]:-}") |" \
           "$(cell thesis "${hd[thesis]:-}") | $(cell fire "${hd[fire]:-}") |" \
           "$(cell thesis "${nm[thesis]:-}") | $(cell fire "${nm[fire]:-}") |" \
           "${secs[thesis]:-n/a} | ${secs[fire]:-n/a} | $better | $goal |"
      unset rms hd nm secs err
    done
  done
done
if [ ${#notes[@]} -gt 0 ]; then
  echo
  echo "Failures:"
  for n in "${notes[@]}"; do echo "- $n"; done
fi
