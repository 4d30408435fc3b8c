#!/usr/bin/env bash
# Thesis sec. 6.5 in simulation: the autonomous segmentation loop on every scene of the held-out set
# (experiments/scenes/nudge_segmentation_heldout/: seeds fixed in advance, the headline figures) and
# of the development set (experiments/scenes/nudge_segmentation/), then nudge-exp-nudge-segmentation
# scores the runs into docs/results/nudge_segmentation.{json,md}. Runs land in OUT/<set>/<scene>/
# (--out, default out/experiments/nudge_segmentation). About a minute per single-object scene.
#   experiments/nudge_segmentation.sh [--out DIR] [--set heldout|heldout2|development|development2|both] [SCENE_NAME...]
# Scene names run only those scenes of the one set chosen with --set (and score that set alone).
# --set heldout2 runs the second held-out set (seeds 620001-620015, fixed 2026-11-25) and writes
# docs/results/nudge_segmentation_heldout2.{json,md}. --set development2 runs the second development
# set (seeds 630001-630015, fixed 2026-11-30; tuned on) into nudge_segmentation_development2.{json,md};
# --set development the first (tuned on) into nudge_segmentation_development.{json,md}. Only the
# held-out set alone or both sets (--set heldout, both) write the headline nudge_segmentation.*.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/lib.sh"
out_dir="$NUDGE_ROOT/out/experiments/nudge_segmentation"
which_set=both
names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out_dir="$(realpath -m "$2")"; shift 2 ;;
    --set) which_set="$2"; shift 2 ;;
    -*) echo "unknown option $1 (--out DIR, --set heldout|heldout2|development|development2|both)" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
case "$which_set" in
  heldout|heldout2|development|development2) ;;
  both) [ ${#names[@]} -eq 0 ] || { echo "scene names need --set heldout or --set development" >&2; exit 2; } ;;
  *) echo "--set: heldout, heldout2, development, development2 or both, not '$which_set'" >&2; exit 2 ;;
esac
nudge_install_packages
nudge_build
calibration="$NUDGE_ROOT/config/calibration_sim.yaml"
declare -A scene_dirs=([heldout]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_heldout"
                       [heldout2]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_heldout2"
                       [development]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation"
                       [development2]="$NUDGE_ROOT/experiments/scenes/nudge_segmentation_dev2")
nudge_export_loop

# run_set SET [SCENE_NAME...]: every scene of the set (or the ones named) into OUT/SET/.
run_set() {
  local set=$1; shift
  local scenes_dir="${scene_dirs[$set]}" runs_dir="$out_dir/$set"
  local list=("$@")
  if [ ${#list[@]} -eq 0 ]; then
    for f in "$scenes_dir"/*.yaml; do list+=("$(basename "$f" .yaml)"); done
  fi
  local i=0 loop_start=$SECONDS name start status
  for name in "${list[@]}"; do
    i=$((i + 1))
    nudge_progress "$i" "${#list[@]}" "$loop_start" "$set/$name"
    rm -rf "${runs_dir:?}/$name"
    mkdir -p "$runs_dir/$name"
    start=$(date +%s)
    status=0
    nudge_in_private_network bash -c 'nudge_run_loop "$@"' loop "$NUDGE_BUILD_DIR/bin" "$scenes_dir/$name.yaml" \
      "$calibration" "$NUDGE_ROOT/config/workspace.yaml" "$runs_dir/$name" "$name" --first-seq 1000 2>"$runs_dir/$name/supervisor.log" || status=$?
    [ -d "$runs_dir/$name/$name" ] && echo $(($(date +%s) - start)) > "$runs_dir/$name/$name/wall_seconds.txt"
    [ -t 2 ] && printf '\r\033[K' >&2
    nudge_log "[$i/${#list[@]}] $set/$name: $(grep -h "ended:" "$runs_dir/$name/supervisor.log" | sed 's/^.*ended: //') (exit $status)"
  done
  nudge_log "$set: ${#list[@]} scenes run in $((SECONDS - loop_start)) s"
}

score=("$NUDGE_BUILD_DIR/bin/nudge-exp-nudge-segmentation" --workspace "$NUDGE_ROOT/config/workspace.yaml")
if [ "$which_set" = both ]; then
  run_set heldout
  run_set development
  "${score[@]}" "$out_dir/heldout" "${scene_dirs[heldout]}" --development "$out_dir/development" "${scene_dirs[development]}"
else
  run_set "$which_set" "${names[@]}"
  case "$which_set" in
    heldout) result_name=nudge_segmentation ;;
    heldout2) result_name=nudge_segmentation_heldout2 ;;
    development*) result_name=nudge_segmentation_$which_set; score+=(--development-set) ;;
  esac
  "${score[@]}" "$out_dir/$which_set" "${scene_dirs[$which_set]}" "${names[@]}" --name "$result_name"
fi
