#!/usr/bin/env bash
# Thesis sec. 7.4 (Table 7.1) in simulation: each of the seven bottles of
# experiments/scenes/learning/train*.yaml learned by the whole chain (survey -> nudge -> segment ->
# grasp -> rotate -> learn -> place), one run per scene, no retries, all into ONE object database
# (OUT/learning/objects: the later runs first ask whether their bottle is already known).
# Then nudge-exp-learning scores the database on the 28 test and 10 never-learned images into
# docs/results/learning.{json,md} (docs/learning.md, "The experiment"). Runs land in
# OUT/learning/<scene>/, the test images (the right camera's 1280x960 stills) in
# OUT/learning_test_stills/ (rendered when missing). OUT is out/experiments unless --out says
# otherwise (a folder outside the checkout keeps the runs across checkouts). A few minutes per scene.
#   experiments/learning.sh [--out OUT]                the seven runs (a fresh database), then the scoring
#   experiments/learning.sh [--out OUT] --runs-only    the seven runs only
#   experiments/learning.sh [--out OUT] --score-only   the scoring of the runs already in OUT only
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/lib.sh"
runs=1 score=1 out="$NUDGE_ROOT/out/experiments"
usage() { echo "usage: $0 [--out DIR] [--runs-only | --score-only]" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --runs-only) score=0 ;;
    --score-only) runs=0 ;;
    --out) [ $# -ge 2 ] || usage; out="$2"; shift ;;
    *) usage ;;
  esac
  shift
done
mkdir -p "$out"
out="$(cd "$out" && pwd)"
scenes_dir="$NUDGE_ROOT/experiments/scenes/learning"
runs_dir="$out/learning"
calibration="$NUDGE_ROOT/config/calibration_sim.yaml"
targets=(nudge-launch nudge-world nudge-camera nudge-symmetry nudge-triangulation nudge-arm nudge-learner nudge-supervisor)
[ $score = 1 ] && targets+=(nudge-exp-learning nudge-exp-learning-scenes)
nudge_install_packages
[ -f "$NUDGE_BUILD_DIR/CMakeCache.txt" ] || cmake -S "$NUDGE_ROOT" -B "$NUDGE_BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
nudge_log "building ${targets[*]}"
cmake --build "$NUDGE_BUILD_DIR" -j "$NUDGE_JOBS" --target "${targets[@]}" >/dev/null

names=()
for f in "$scenes_dir"/train*.yaml; do names+=("$(basename "$f" .yaml)"); done
if [ $runs = 1 ]; then
  # One database for all seven, started empty: what a run learns, the next ones know.
  rm -rf "${runs_dir:?}"
  mkdir -p "$runs_dir/objects"
  nudge_export_loop
  # The loop is real-time (heartbeats every second, 1.5-3 s watchdogs), and a shared 2-core machine
  # at load 20 starves it: services fall silent, the arm stops, attempts abort (docs/learning.md).
  # What this experiment measures is learning and recognition, so: not under nice; the world at half
  # real time (half the rendering load; every wait of the supervisor is on the simulated clock); the
  # watchdogs (supervisor --service-timeout, arm --supervisor-timeout) at 10 s instead of 3 and 1.5.
  export NUDGE_LOOP_LEARN=1 NUDGE_OBJECT_DB="$runs_dir/objects" NUDGE_LOOP_REALTIME=${NUDGE_LOOP_REALTIME:-0.5}
  export NUDGE_LOOP_ARM_WATCHDOG=${NUDGE_LOOP_ARM_WATCHDOG:-10}
  i=0 loop_start=$SECONDS
  for name in "${names[@]}"; do
    i=$((i + 1))
    nudge_progress "$i" "${#names[@]}" "$loop_start" "$name"
    mkdir -p "$runs_dir/$name"
    start=$(date +%s)
    status=0
    nudge_in_private_network bash -c 'nudge_run_loop "$@"' loop "$NUDGE_BUILD_DIR/bin" "$scenes_dir/$name.yaml" \
      "$calibration" "$NUDGE_ROOT/config/workspace.yaml" "$runs_dir/$name" "$name" --learn on --first-seq 1000 --service-timeout "${NUDGE_LOOP_SERVICE_TIMEOUT:-10}" \
      2>"$runs_dir/$name/supervisor.log" || status=$?
    [ -d "$runs_dir/$name/$name" ] && echo $(($(date +%s) - start)) > "$runs_dir/$name/$name/wall_seconds.txt"
    learned=$(grep -ho '"learned_name":"[^"]*"' "$runs_dir/$name/$name/summary.json" 2>/dev/null | grep -v '""' | head -1 |
              sed 's/^.*:"\(.*\)"$/learned as \1/' || true)
    [ -t 2 ] && printf '\r\033[K' >&2
    nudge_log "[$i/${#names[@]}] $name: $(grep -h "ended:" "$runs_dir/$name/supervisor.log" | sed 's/^.*ended: //') ${learned:-nothing learned} ($(($(date +%s) - start)) s, exit $status)"
  done
fi
if [ $score = 1 ]; then
  # The test images, rendered once from the evaluation seeds (docs/results/learning_scenes.md):
  # the right camera's high-resolution stills, as the robot takes them to look closely.
  test_images="$out/learning_test_stills"
  if [ ! -f "$test_images/manifest.json" ]; then
    nudge_log "rendering the 38 test images into $test_images"
    "$NUDGE_BUILD_DIR/bin/nudge-exp-learning-scenes" --out "$test_images" --set eval --camera still
  fi
  "$NUDGE_BUILD_DIR/bin/nudge-exp-learning" --runs "$runs_dir" --scenes "$scenes_dir" --test-images "$test_images"
fi
nudge_summary learning.sh 0 "$(ls -d "$runs_dir"/objects/*/ 2>/dev/null | wc -l) objects in $runs_dir/objects"
