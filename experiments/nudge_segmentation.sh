#!/usr/bin/env bash
# Thesis sec. 6.5 in simulation: the autonomous segmentation loop on every evaluation scene of
# experiments/scenes/nudge_segmentation/ (or the ones named), then nudge-exp-nudge-segmentation
# scores the runs into docs/results/nudge_segmentation.{json,md}. Runs land in
# out/experiments/nudge_segmentation/<scene>/. About a minute per single-object scene.
#   experiments/nudge_segmentation.sh [SCENE_NAME...]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/lib.sh"
nudge_install_packages
nudge_build
scenes_dir="$NUDGE_ROOT/experiments/scenes/nudge_segmentation"
runs_dir="$NUDGE_ROOT/out/experiments/nudge_segmentation"
calibration="$NUDGE_ROOT/config/calibration_sim.yaml"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in "$scenes_dir"/*.yaml; do names+=("$(basename "$f" .yaml)"); done
fi
export -f nudge_run_loop
i=0
loop_start=$SECONDS
for name in "${names[@]}"; do
  i=$((i + 1))
  nudge_progress "$i" "${#names[@]}" "$loop_start" "$name"
  rm -rf "${runs_dir:?}/$name"
  mkdir -p "$runs_dir/$name"
  start=$(date +%s)
  status=0
  nudge_in_private_network bash -c 'nudge_run_loop "$@"' loop "$NUDGE_BUILD_DIR/bin" "$scenes_dir/$name.yaml" \
    "$calibration" "$NUDGE_ROOT/config/workspace.yaml" "$runs_dir/$name" "$name" --first-seq 1000 2>"$runs_dir/$name/supervisor.log" || status=$?
  [ -d "$runs_dir/$name/$name" ] && echo $(($(date +%s) - start)) > "$runs_dir/$name/$name/wall_seconds.txt"
  [ -t 2 ] && printf '\r\033[K' >&2
  nudge_log "[$i/${#names[@]}] $name: $(grep -h "ended:" "$runs_dir/$name/supervisor.log" | sed 's/^.*ended: //') (exit $status)"
done
nudge_log "${#names[@]} scenes run in $((SECONDS - loop_start)) s"
"$NUDGE_BUILD_DIR/bin/nudge-exp-nudge-segmentation" "$runs_dir" "$scenes_dir" "${names[@]}"
