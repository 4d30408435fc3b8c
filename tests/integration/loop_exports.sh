#!/usr/bin/env bash
# Integration test of scripts/lib.sh: nudge_run_loop runs in a child shell (the demo,
# experiments/nudge_segmentation.sh and experiments/learning.sh start it as
# `nudge_in_private_network bash -c 'nudge_run_loop ...'`), so every nudge_* function it calls must
# be exported into that child by nudge_export_loop. One was not once: the loop ran without its
# survey flags (no second, wider look) and only "command not found" in a log said so.
# Checks, in a child shell as the scripts start it: each function nudge_run_loop names is there,
# and the survey flags come out for every detection.
# usage: loop_exports.sh SOURCE_DIR
set -euo pipefail
source_dir=${1:?usage: loop_exports.sh SOURCE_DIR}
source "$source_dir/scripts/lib.sh"
nudge_export_loop
called=$(declare -f nudge_run_loop | grep -o '\bnudge_[a-z_]*' | sort -u)
failed=0
for name in $called; do
  declare -F "$name" >/dev/null || continue  # a variable or a program, not a function of lib.sh
  if ! bash -c "declare -F $name >/dev/null"; then
    echo "FAIL: nudge_run_loop calls $name, which nudge_export_loop does not export" >&2
    failed=1
  fi
done
for table in plain verified busy; do
  flags=$(NUDGE_LOOP_TABLE=$table bash -c 'nudge_loop_survey_flags') || { echo "FAIL: no survey flags for $table" >&2; failed=1; }
  [ -n "$flags" ] || { echo "FAIL: empty survey flags for $table" >&2; failed=1; }
done
[ "$(bash -c 'nudge_loop_survey_flags')" = "--wide-survey-tilt 5" ] ||
  { echo "FAIL: the plain detection's survey is not asked once more at 5 deg" >&2; failed=1; }
[ "$failed" = 0 ] && echo "PASS: every function nudge_run_loop calls reaches its child shell"
exit "$failed"
