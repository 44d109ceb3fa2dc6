#!/usr/bin/env bash
# The hardware guide's commands (issue 42, item 4). Every `fire` command that docs/*.md shows, in a code block or
# in a `code span`, names a command and options that `fire ... --help` lists. Then every `fire` line of
# docs/hardware.md's code blocks runs, in order, in an empty folder, none of them needing a remote:
#   fire calibrate --live      with --fake-rig 7 added (fake remotes streaming a simulated wand); then the pad's
#                              line of the guide's ```json block is added to the rig it wrote, as the guide says
#   fire app --live            twice: as written, without a display, where it must stop only for want of remotes
#                              (so the rig, with the pad's line, and the marks file of the guide's ```json block
#                              parse); then under Xvfb on fake remotes (--rig and --marks swapped for --fake-rig),
#                              Ctrl+S and E pressed when -o and --export are given (their files must appear), closed
#   fire app (not live)        under Xvfb, closed at once
#   fire aim                   twice: as written, without a display, where it must stop only for want of remotes (so
#                              the rig it names parses); then with --fake-rig 7 added: with --png-dir headless (both
#                              pictures must appear), else under Xvfb, closed after 30 frames
#   fire devices               as written: exit 0 with no remote found (1 only when remotes are there), never 2
#   anything else              as written: exit 0
# A placeholder (RIG, DIR, N) in a code block's `fire` line fails the run: write the guide's lines runnable.
#   hardware_guide.sh FIRE_BINARY WORK_DIR DOCS_DIR
source "$(dirname "${BASH_SOURCE[0]}")/../work_dir.sh"
docs="$3"
guide="$docs/hardware.md"
start=$SECONDS
problems=0
bad() { echo "FAILED: $*"; problems=$((problems + 1)); }

# --- what fire knows: its commands, their subcommands and the options each --help lists ---
# The lines of a help text's "Subcommands:" block, as readme_options.sh reads them.
subcommands() { "$fire" "$@" --help | sed -n '/^Subcommands:$/,/^$/p' | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p'; }
top_commands=$(subcommands)
# among LIST WORD: WORD is one of LIST's lines (no process: the docs hold a hundred commands and options)
among() { [[ $'\n'"$1"$'\n' == *$'\n'"$2"$'\n'* ]]; }
declare -A nested_of  # command -> its subcommands (simulate's), each asked once
[ "$(wc -l <<<"$top_commands")" -ge 10 ] || fail "only these commands in fire --help: $top_commands"
declare -A known_options
# ask_options COMMAND...: known_options["fire COMMAND..."], the options at the start of the lines of its --help's
# "Options:" block (-o and --output both), not the ones a description mentions; asked once.
ask_options() {
  local key="fire $*"
  [ -n "${known_options[$key]+set}" ] ||
    known_options[$key]=$("$fire" "$@" --help | sed -n '/^Options:$/,/^$/p' |
                          grep -oE -- '^  (-[a-z],)?--[a-z][a-z0-9-]*' | tr ',' '\n' | tr -d ' ' | sort -u)
}

# check_command WHERE TEXT: TEXT's command exists and each of its options is in that command's --help. Words after
# a pipe or a redirection belong to another command.
check_command() {
  local where="$1" text="$2" i=1 nested token
  local -a w cmd=()
  read -ra w <<<"$text"
  if [ "${#w[@]}" -gt 1 ] && [[ "${w[1]}" != -* ]]; then
    if ! among "$top_commands" "${w[1]}"; then bad "$where: fire has no command '${w[1]}': $text"; return; fi
    cmd=("${w[1]}")
    i=2
    [ -n "${nested_of[${w[1]}]+set}" ] || nested_of[${w[1]}]=$(subcommands "${w[1]}")
    nested="${nested_of[${w[1]}]}"
    if [ -n "$nested" ] && [ "${#w[@]}" -gt 2 ] && [[ "${w[2]}" != -* ]]; then
      if ! among "$nested" "${w[2]}"; then bad "$where: fire ${w[1]} has no '${w[2]}': $text"; return; fi
      cmd+=("${w[2]}")
      i=3
    fi
  fi
  ask_options "${cmd[@]}"
  local known="${known_options[fire ${cmd[*]}]}"
  for ((; i < ${#w[@]}; i++)); do
    token="${w[i]}"
    case "$token" in '|' | ';' | '&&' | '||' | '>'* | '<'* | '2>'*) break ;; esac
    # [--opt X] and --opt=X in the usage-like spans
    token="${token#[}"; token="${token%%]*}"; token="${token%%=*}"; token="${token%,}"
    if [[ "$token" =~ ^--?[a-z][a-z0-9-]*$ ]] && ! among "$known" "$token"; then
      bad "$where: fire ${cmd[*]} has no option $token: $text"
    fi
  done
}

# commands FILE: one line per `fire` command, "FILE:LINE<TAB>block|text<TAB>COMMAND". In a code block, a line
# whose first word is fire and whose second is a command word or an option (a "# ..." comment dropped; output
# such as "fire calibrate: camera 0 ..." is not a command); in the text, a code span that reads so.
commands() {
  awk '
    /^[ \t]*```/ { fenced = !fenced; next }
    fenced {
      line = $0
      sub(/^[ \t]+/, "", line); sub(/[ \t]+#.*$/, "", line)
      if (line ~ /^fire( +-|( +[a-z][a-z-]*)( |$))/) printf "%s:%d\tblock\t%s\n", FILENAME, FNR, line
      next
    }
    {
      s = $0
      while (match(s, /`fire [^`]*`/)) {
        span = substr(s, RSTART + 1, RLENGTH - 2)
        if (span ~ /^fire( +-|( +[a-z][a-z-]*)( |$))/) printf "%s:%d\ttext\t%s\n", FILENAME, FNR, span
        s = substr(s, RSTART + RLENGTH)
      }
    }' "$1"
}

# --- 1. every command the docs show is one fire has ---
checked=0
for doc in "$docs"/*.md; do
  while IFS=$'\t' read -r where _ text; do
    check_command "${where#"$docs"/}" "$text"
    checked=$((checked + 1))
  done < <(commands "$doc")
done
echo "checked the commands and options of $checked fire commands in $(ls "$docs"/*.md | wc -l) docs in $((SECONDS - start)) s"

# --- 2. the guide's code blocks run ---
mapfile -t lines < <(commands "$guide" | awk -F'\t' '$2 == "block"')
[ "${#lines[@]}" -ge 15 ] || fail "only ${#lines[@]} fire lines in $guide's code blocks: is the extraction broken?"

# The files the person writes by hand: the ```json blocks of the marks file and of the pad's line in the rig.
json_block() {  # PATTERN: the first ```json block of the guide holding PATTERN
  awk -v pattern="$1" '
    /^[ \t]*```json/ { inside = 1; block = ""; next }
    inside && /^[ \t]*```/ { if (index(block, pattern)) { printf "%s", block; exit } inside = 0; next }
    inside { block = block $0 "\n" }' "$guide"
}
json_block '"fire-marks"' >marks.json
[ -s marks.json ] || fail "$guide has no \`\`\`json block of a marks file (\"format\": \"fire-marks\")"
json_block '"role": "pad"' >pad.json
python3 -c 'import json, sys; json.load(open(sys.argv[1])); json.load(open(sys.argv[2]))' marks.json pad.json ||
  fail "the guide's marks file or pad line is not JSON"
# add_pad RIG: the pad's line added to the rig's remotes, as the guide tells the person to after each calibration
add_pad() {
  [ -s pad.json ] || return 0
  python3 - "$1" pad.json <<'EOF'
import json, sys
rig = json.load(open(sys.argv[1]))
rig.setdefault("remotes", []).append(json.load(open(sys.argv[2])))
json.dump(rig, open(sys.argv[1], "w"), indent=2)
EOF
}

command -v xvfb-run >/dev/null || fail "the guide's fire app lines need xvfb-run: apt-get install xvfb (tools/run test installs it)"
display=430  # xvfb-run -a looks for a free display from here, so a ctest -j neighbour's does not clash
# under_x STEM COMMAND...: COMMAND under a fresh X server, its output in STEM.out and STEM.err, its own exit status
# in STEM.status (xvfb-run's can reflect its cleanup too).
under_x() {
  local stem="$1"
  shift
  rm -f "$stem.status"
  xvfb-run -a -n "$display" -s '-screen 0 640x480x24' \
    bash -c 's="$1" o="$2" e="$3"; shift 3; "$@" >"$o" 2>"$e" </dev/null; echo $? >"$s"' _ \
    "$stem.status" "$stem.out" "$stem.err" "$@" >/dev/null 2>&1 || true
  cat "$stem.status" 2>/dev/null || echo "no status (xvfb-run did not run it)"
}

# A loop, not printf into grep -q: under pipefail grep's early exit can fail printf with SIGPIPE, and a word that
# is there reads as missing (the app's --live once did, and its session was closed at frame 5).
has() {
  local o="$1" word
  shift
  for word in "$@"; do [ "$word" = "$o" ] && return 0; done
  return 1
}
value_of() {  # OPTION WORDS...: the word after OPTION
  local o="$1"; shift
  while [ $# -gt 1 ]; do [ "$1" = "$o" ] && { echo "$2"; return; }; shift; done
}
declare -A ran

for entry in "${lines[@]}"; do
  IFS=$'\t' read -r where _ text <<<"$entry"
  n="line${where##*:}"
  where="${where#"$docs"/}"
  read -ra w <<<"${text#fire }"
  ran[${w[0]}]=1
  line_start=$SECONDS
  rc=0
  case "${w[0]}" in
    calibrate)
      if has --live "${w[@]}" && ! has --fake-rig "${w[@]}"; then w+=(--fake-rig 7); fi
      "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
      if [ $rc -ne 0 ]; then bad "$where: exit $rc: fire ${w[*]}: $(tail -3 "$n.err")"; continue; fi
      if has --live "${w[@]}"; then add_pad "$(value_of -o "${w[@]}")"; fi
      ;;
    app)
      script="$n.script"
      if has --live "${w[@]}" && ! has --fake-rig "${w[@]}"; then
        # As written: the files it names parse, and it stops for want of remotes (before any window).
        env -u DISPLAY -u WAYLAND_DISPLAY "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
        if [ $rc -ne 1 ] || ! grep -q "needs the rig's two camera remotes and found [01]" "$n.err"; then
          bad "$where: as written, exit $rc, not the want of remotes: fire ${w[*]}: $(cat "$n.err")"
          continue
        fi
        # On fake remotes: the fake rig brings its own rig and marks; 20 strokes of the simulated person are the
        # border and its first splits, faces to save and export by frame 280.
        fake=()
        for ((i = 0; i < ${#w[@]}; i++)); do
          case "${w[i]}" in --rig | --marks) i=$((i + 1)) ;; *) fake+=("${w[i]}") ;; esac
        done
        w=("${fake[@]}" --fake-rig 7 --fake-strokes 20 --fake-speed 20)
      fi
      if has --live "${w[@]}"; then
        : >"$script"
        if has -o "${w[@]}"; then echo "280 key ctrl+s" >>"$script"; fi
        if has --export "${w[@]}"; then echo "281 key e" >>"$script"; fi
        echo "300 close" >>"$script"
      else
        echo "5 close" >"$script"
      fi
      has --size "${w[@]}" || w+=(--size 320x240)  # a small window: lavapipe draws it on the CPU
      status=$(under_x "$n" "$fire" "${w[@]}" --script "$script")
      if [ "$status" != 0 ]; then bad "$where: exit $status: fire ${w[*]}: $(tail -3 "$n.err")"; continue; fi
      for o in -o --export; do
        f=$(value_of "$o" "${w[@]}")
        if [ -n "$f" ] && [ ! -s "$f" ]; then bad "$where: $o $f not written: fire ${w[*]}: $(tail -3 "$n.err")"; fi
      done
      ;;
    aim)
      if ! has --fake-rig "${w[@]}"; then
        env -u DISPLAY -u WAYLAND_DISPLAY "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
        if [ $rc -ne 1 ] || ! grep -q "needs two Wii Remotes as cameras and found [01]" "$n.err"; then
          bad "$where: as written, exit $rc, not the want of remotes: fire ${w[*]}: $(cat "$n.err")"
          continue
        fi
        w+=(--fake-rig 7)
      fi
      pictures=$(value_of --png-dir "${w[@]}")
      if [ -n "$pictures" ]; then
        rm -rf "$pictures"
        rc=0
        "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
        if [ $rc -ne 0 ]; then bad "$where: exit $rc: fire ${w[*]}: $(tail -3 "$n.err")"; continue; fi
        for c in 0 1; do
          [ -s "$pictures/camera$c.png" ] || bad "$where: $pictures/camera$c.png not written: fire ${w[*]}"
        done
      else
        echo "30 close" >"$n.script"
        has --size "${w[@]}" || w+=(--size 320x240)
        status=$(under_x "$n" "$fire" "${w[@]}" --script "$n.script")
        if [ "$status" != 0 ]; then bad "$where: exit $status: fire ${w[*]}: $(tail -3 "$n.err")"; continue; fi
      fi
      ;;
    devices)
      "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
      if [ $rc -eq 2 ] || { grep -q "no Wii Remote found" "$n.out" && [ $rc -ne 0 ]; } || [ $rc -gt 1 ]; then
        bad "$where: exit $rc: fire ${w[*]}: $(cat "$n.out" "$n.err")"
        continue
      fi
      ;;
    *)
      "$fire" "${w[@]}" </dev/null >"$n.out" 2>"$n.err" || rc=$?
      if [ $rc -ne 0 ]; then bad "$where: exit $rc: fire ${w[*]}: $(tail -3 "$n.err")"; continue; fi
      ;;
  esac
  echo "ok: $where: fire ${w[*]} ($((SECONDS - line_start)) s)"
done

# The guide goes from the remotes to an exported surface: each step's command must be among those run.
for c in simulate calibrate devices aim app replay reconstruct export-network eval track; do
  [ -n "${ran[$c]+set}" ] || bad "$guide runs no fire $c in its code blocks"
done
echo "${#lines[@]} lines of $guide run in $((SECONDS - start)) s; $problems failed"
[ $problems -eq 0 ]
