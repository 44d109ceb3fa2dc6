#!/usr/bin/env bash
# The README names every command `fire --help` lists and every option each command's `--help` shows: in the rows
# of its tables that start with that command (the commands table and "Every option").
#   readme_options.sh FIRE_BINARY README
set -u
fire="$1"
readme="$2"
fail=0
# The subcommands of a help text: the lines of its "Subcommands:" block.
subcommands() { "$fire" $1 --help | sed -n '/^Subcommands:$/,/^$/p' | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p'; }
commands=()
for c in $(subcommands ""); do
  nested=$(subcommands "$c")
  if [ -n "$nested" ]; then
    for n in $nested; do commands+=("$c $n"); done
  else
    commands+=("$c")
  fi
done
[ "${#commands[@]}" -ge 14 ] || { echo "FAILED: only ${#commands[@]} commands found in fire --help"; exit 1; }
for c in "${commands[@]}"; do
  rows=$(grep -E "^\| \`fire $c[ \`]" "$readme")
  if [ -z "$rows" ]; then
    echo "FAILED: the README has no row for fire $c"
    fail=1
    continue
  fi
  # Options: the block after "Options:" up to its blank line (footers mention other commands' options).
  for option in $("$fire" $c --help | sed -n '/^Options:$/,/^$/p' | grep -oE -- '^  (-[a-z],)?--[a-z][a-z0-9-]*' |
                  grep -oE -- '--[a-z][a-z0-9-]*' | sort -u); do
    [ "$option" = --help ] && continue
    if ! grep -q -- "$option\\b" <<<"$rows"; then
      # -o,--output is named as either.
      if [ "$option" = --output ] && grep -q -- "-o\\b" <<<"$rows"; then continue; fi
      echo "FAILED: fire $c $option is in --help but not in the README's rows for fire $c"
      fail=1
    fi
  done
done
[ $fail -eq 0 ] && echo "ok: the README names all ${#commands[@]} commands and every option their --help shows"
exit $fail
