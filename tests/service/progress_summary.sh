#!/usr/bin/env bash
# Every long job says how far it is and ends with a one-line summary on stderr (issue 13).
#  1. Every experiment program (experiments/*.cpp with a main()) uses nudge::Progress: one that
#     forgets it is named.
#  2. Each given command (a cheap experiment run on a tiny input, its results written into a
#     scratch NUDGE_RESULTS_DIR) exits 0 with nothing on stdout but what it means to print, and its
#     stderr starts with "JOB: N steps" and ends with "JOB: done N/N in ... — SUMMARY" (stderr is
#     a file here, so no status line is drawn in between, only notes).
# usage: progress_summary.sh EXPERIMENTS_DIR 'COMMAND ARGS...' ['COMMAND ARGS...' ...]
set -uo pipefail
experiments=${1:?usage: progress_summary.sh EXPERIMENTS_DIR COMMAND...}
shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
fail() { echo "FAILED: $*" >&2; failed=1; }

for source in "$experiments"/*.cpp; do
  grep -q '^int main(' "$source" || continue
  grep -q '#include "nudge/progress.hpp"' "$source" ||
    fail "$(basename "$source") has a main() but does not use nudge::Progress (nudge/progress.hpp)"
done

for command in "$@"; do
  read -r -a argv <<<"$command"
  job=$(basename "${argv[0]}")
  NUDGE_RESULTS_DIR=$work "${argv[@]}" >"$work/out" 2>"$work/err"
  rc=$?
  [ $rc -eq 0 ] || { fail "$command: exit $rc: $(tail -3 "$work/err")"; continue; }
  first=$(head -1 "$work/err")
  last=$(tail -1 "$work/err")
  [[ $first =~ ^$job:\ ([0-9]+)\ steps$ ]] || { fail "$command: first stderr line '$first', not '$job: N steps'"; continue; }
  total=${BASH_REMATCH[1]}
  [[ $last =~ ^$job:\ done\ $total/$total\ in\ [0-9].*\ —\ .+$ ]] ||
    fail "$command: last stderr line '$last', not '$job: done $total/$total in ... — SUMMARY'"
  [ ! -s "$work/out" ] || fail "$command: wrote to stdout (progress and notes belong on stderr): $(head -2 "$work/out")"
  grep -q $'\r' "$work/err" && fail "$command: a status line (\\r) on a stderr that is no terminal"
  echo "$job: $last"
done
[ $failed -eq 0 ] && echo "PASSED: every experiment program uses nudge::Progress; $# run(s) end with their summary line"
exit $failed
