#!/bin/bash
# Replays recorded runs of experiments/nudge_segmentation.sh through today's supervisor and scores the
# replayed segmentations: a change to the supervisor's decisions (line search, segmentation, checks)
# measured on the very messages and stills a set's runs recorded, everything else held fixed.
#   experiments/nudge_segmentation_replay.sh --runs DIR --set heldout|heldout2|development|development2 --out DIR [-- SUPERVISOR_FLAGS...]
# --runs: a set's folder of a recorded experiment (OUT/<set> of nudge_segmentation.sh); every run in it
# with a finished log is fed to nudge-supervisor (--lcm-in file://RUN.lcmlog?speed=0, the run's own
# first ARM_COMMAND seq, the survey flags of NUDGE_LOOP_TABLE) with SUPERVISOR_FLAGS added. The
# replayed runs land in OUT/<set>/ and the score in OUT/replay.json and OUT/replay.md (the table of
# docs/results/nudge_segmentation.md); docs/results is not touched. The replayed runs' own logs are
# deleted after scoring (a set's are several GB).
#
# A replay is exact while the supervisor decides as it did live: a change that alters an attempt's
# outcome (a mask now refused, say) sends commands the recorded world never answered, and the rest
# of that run's replay waits on answers that are not in the log (its later attempts end "timed out"
# or follow recorded states that do not belong to them). Single-attempt runs are exact.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/lib.sh"
runs_dir= which_set= out_dir=
flags=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs_dir="$(realpath -m "$2")"; shift 2 ;;
    --set) which_set="$2"; shift 2 ;;
    --out) out_dir="$(realpath -m "$2")"; shift 2 ;;
    --) shift; flags=("$@"); break ;;
    *) echo "unknown option $1 (--runs DIR --set heldout|heldout2|development|development2 --out DIR [-- FLAGS])" >&2; exit 2 ;;
  esac
done
declare -A scene_dirs=([heldout]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_heldout"
                       [heldout2]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_heldout2"
                       [development]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation"
                       [development2]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_dev2")
[ -n "$runs_dir" ] && [ -d "$runs_dir" ] || { echo "--runs: no such folder '$runs_dir'" >&2; exit 2; }
[ -n "${scene_dirs[$which_set]:-}" ] || { echo "--set: heldout, heldout2, development or development2, not '$which_set'" >&2; exit 2; }
[ -n "$out_dir" ] || { echo "--out is required" >&2; exit 2; }
[ "$out_dir" != "$runs_dir" ] && [ "$out_dir/$which_set" != "$runs_dir" ] || { echo "--out must not be the recorded runs' folder" >&2; exit 2; }
nudge_install_packages
nudge_build
read -r -a survey <<<"$(nudge_loop_survey_flags)"
replayed="$out_dir/$which_set"
rm -rf "${replayed:?}"
mkdir -p "$replayed"
count=0
for run_dir in "$runs_dir"/*/; do
  name=$(basename "$run_dir")
  log="$run_dir/$name/$name.lcmlog" summary="$run_dir/$name/summary.json"
  if [ ! -f "$log" ] || [ ! -f "$summary" ]; then
    nudge_log "$name: no finished run (no $name.lcmlog and summary.json): skipped"
    continue
  fi
  seq=$(grep -o '"first_command_seq": *[0-9]*' "$summary" | grep -o '[0-9]*$')
  mkdir -p "$replayed/$name"
  "$NUDGE_BUILD_DIR/bin/nudge-supervisor" --lcm-in "file://$log?speed=0" --lcm-out "file://$replayed/$name/published.lcmlog?mode=w" \
    --calibration "$NUDGE_ROOT/config/calibration_sim.yaml" --workspace "$NUDGE_ROOT/config/workspace.yaml" \
    --out "$replayed/$name" --run-id "$name" --first-seq "${seq:-1000}" "${survey[@]}" "${flags[@]}" \
    2>"$replayed/$name/supervisor.log" || nudge_log "$name: the replay exited $?"
  rm -f "$replayed/$name/published.lcmlog"
  nudge_log "$name: $(grep -h "ended:" "$replayed/$name/supervisor.log" | sed 's/^.*ended: //')"
  count=$((count + 1))
done
[ "$count" -gt 0 ] || { echo "no finished run in $runs_dir" >&2; exit 1; }
# The scorer writes docs/results/STEM.*: a name of its own, moved into OUT.
stem="replay_$$"
"$NUDGE_BUILD_DIR/bin/nudge-exp-nudge-segmentation" --workspace "$NUDGE_ROOT/config/workspace.yaml" "$replayed" "${scene_dirs[$which_set]}" --name "$stem" | tail -1
for ext in json md; do mv "$NUDGE_ROOT/docs/results/$stem.$ext" "$out_dir/replay.$ext"; done
mv "$NUDGE_ROOT/docs/results/${stem}_gallery.png" "$out_dir/replay_gallery.png" 2>/dev/null || true
sed -i "s/${stem}_gallery.png/replay_gallery.png/" "$out_dir/replay.md"
rm -f "$replayed"/*/*/*.lcmlog
nudge_log "replayed $count runs: $out_dir/replay.md"
