#!/usr/bin/env bash
# Integration test of scripts/lib.sh: nudge_run_loop runs in a child shell (the demo,
# experiments/nudge_segmentation.sh and experiments/learning.sh start it as
# `nudge_in_private_network bash -c 'nudge_run_loop ...'`), so every nudge_* function it calls must
# be exported into that child by nudge_export_loop. One was not once: the loop ran without its
# survey flags (no second, wider look) and only "command not found" in a log said so.
# Checks, in a child shell as the scripts start it: each function nudge_run_loop names is there,
# and the survey and detection flags come out for every detection.
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
# The detection's flags: every table gives some, an unknown one is refused, and the arm's base
# column's outline is left out of the plain and verified detections' edges unless asked not to.
for table in plain verified busy; do
  NUDGE_LOOP_TABLE=$table bash -c 'nudge_loop_symmetry_flags CAL.yaml && nudge_loop_triangulation_flags' >/dev/null ||
    { echo "FAIL: no detection flags for $table" >&2; failed=1; }
done
if NUDGE_LOOP_TABLE=bumpy bash -c 'nudge_loop_symmetry_flags CAL.yaml' >/dev/null 2>&1 ||
   NUDGE_LOOP_TABLE=bumpy bash -c 'nudge_loop_triangulation_flags' >/dev/null 2>&1; then
  echo "FAIL: an unknown NUDGE_LOOP_TABLE gave detection flags" >&2
  failed=1
fi
column_masked() { bash -c 'nudge_loop_symmetry_flags CAL.yaml' | grep -q '"--column-calibration", "CAL.yaml"'; }
for table in plain verified; do
  NUDGE_LOOP_TABLE=$table column_masked || { echo "FAIL: $table does not leave the column out by default" >&2; failed=1; }
  ! NUDGE_LOOP_TABLE=$table NUDGE_LOOP_COLUMN_MASK=0 column_masked ||
    { echo "FAIL: NUDGE_LOOP_COLUMN_MASK=0 does not keep the column in for $table" >&2; failed=1; }
done
! NUDGE_LOOP_TABLE=busy column_masked || { echo "FAIL: busy leaves the column out by default" >&2; failed=1; }
NUDGE_LOOP_TABLE=busy NUDGE_LOOP_COLUMN_MASK=1 column_masked || { echo "FAIL: NUDGE_LOOP_COLUMN_MASK=1 does not mask for busy" >&2; failed=1; }
[ "$failed" = 0 ] && echo "PASS: every function nudge_run_loop calls reaches its child shell"
exit "$failed"
