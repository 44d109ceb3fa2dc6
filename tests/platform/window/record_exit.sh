#!/bin/sh
# record_exit.sh FILE COMMAND...: runs COMMAND and writes its exit status to FILE. The window tests run the
# app through it under xvfb-run, whose own exit status also reflects its cleanup (it once exited 5, "problem
# while cleaning up temporary directory", after the app had exited 0): the file holds the app's alone.
status_file="$1"
shift
"$@"
status=$?
echo "$status" >"$status_file"
exit "$status"
