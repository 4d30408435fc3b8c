#!/usr/bin/env bash
# The main job: the robot segments the objects on a simulated table by itself (thesis ch. 6).
# Every service is its own process over LCM: world (MuJoCo physics, the PUMA 260) -> camera
# (--source sim: renders every state, 1280x960 stills on request) -> symmetry -> triangulation
# (candidates), the arm service, and the supervisor, which surveys, nudges each object, watches it
# move, cuts it out of the stills and goes on until nothing is left, printing every state change.
# It leaves in out/runs/<run>/ the run's LCM log, summary.json and per attempt the stills, the mask,
# the cut-out, the fig. 6.6 picture and the fig. 6.7 stages, and report.html (nudge-report).
#   scripts/demo.sh                       # the loop (NUDGE_DEMO_SCENE, default arm_three_objects.yaml);
#                                         # each segmented object is then grasped, turned, learned
#                                         # (nudge-learner, thesis ch. 7) and put back
#                                         # (NUDGE_DEMO_LEARN=0: segmentation only)
#   scripts/demo.sh perception            # perception only: world -> camera -> symmetry -> monitor
#   scripts/demo.sh 'images:/data/left/*.png' 'images:/data/right/*.png'   # recorded stereo data
#   scripts/demo.sh synthetic             # the synthetic image sequence (generated into out/scenes)
# NUDGE_DEMO_SECONDS (4) and NUDGE_DEMO_RATE (10 Hz) set the simulated run, NUDGE_DEMO_SYMMETRY_FLAGS
# the symmetry extensions (default "--once-per-row --mirror-tolerance 15"); NUDGE_DEMO_FRAMES (20)
# the length of the synthetic sequence. NUDGE_DEMO_SUPERVISOR_FLAGS sets the loop's supervisor flags
# (default "--track-trace": the trackers are watched, so the report has each attempt's tracking
# plot, while the settled AXES decide; "--track": the trackers decide; "": no trackers).
# By default the processes share a private network namespace (when run as root), so no
# traffic leaves it; NUDGE_HOST_NETWORK=1 uses this host's network instead (to watch with
# scripts/spy.sh).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
nudge_install_packages
nudge_build

out="$NUDGE_ROOT/out"
mkdir -p "$out/demo"
rm -f "$out/demo"/*.png
log="$out/demo-$(date +%Y%m%d-%H%M%S).lcmlog"

# Recorded (or synthetic) stereo images: camera -> symmetry -> monitor.
run_images_pipeline() {
  local bin=$1 left=$2 right=$3 log=$4 out=$5 frames=$6
  local url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
  lcm-logger --lcm-url="$url" -q "$log" & local logger=$!
  # Thesis set-up for upright objects on a table: orientation limits of +-25 deg about vertical.
  "$bin/nudge-symmetry" --lcm-url "$url" --lines 5 --theta-min -25 --theta-max 25 & local sym=$!
  "$bin/nudge-monitor" --lcm-url "$url" --draw-dir "$out/demo" --expect-frames "$frames" --timeout 120 & local mon=$!
  sleep 0.5
  "$bin/nudge-camera" --lcm-url "$url" --left "$left" --right "$right" --rate 5 --count "$frames"
  local status=0
  wait $mon || status=$?
  kill -INT $sym $logger 2>/dev/null || true
  wait $sym $logger 2>/dev/null || true
  return $status
}

# The simulated world: world -> camera (sim) -> symmetry -> monitor (with the ground truth).
run_sim_pipeline() {
  local bin=$1 scene=$2 log=$3 out=$4 seconds=$5 rate=$6 calibration=$7 workspace=$8
  local frames=$((seconds * rate + 1))  # the state at t = 0, then one per period
  local url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
  rm -f "$out/demo"/*.log  # the start-up check below reads the services' fresh logs
  lcm-logger --lcm-url="$url" -q "$log" & local logger=$!
  # Upright objects: +-25 deg about vertical. The backdrop's foot is a long straight edge: the
  # thesis' rule that a row of Rot votes for a bin at most once keeps it from outvoting objects.
  # Mirror-consistent pairs keep a striped mug's texture from taking the other objects' lines
  # (NUDGE_DEMO_SYMMETRY_FLAGS replaces these extensions, e.g. with "" for Algorithm 1 as published).
  "$bin/nudge-symmetry" --lcm-url "$url" --lines 5 --theta-min -25 --theta-max 25 \
    ${NUDGE_DEMO_SYMMETRY_FLAGS---once-per-row --mirror-tolerance 15} \
    2>"$out/demo/symmetry.log" & local sym=$!
  "$bin/nudge-monitor" --lcm-url "$url" --truth --draw-dir "$out/demo" --expect-frames "$frames" --timeout 120 \
    2>"$out/demo/monitor.log" & local mon=$!
  "$bin/nudge-camera" --lcm-url "$url" --source sim --scene "$scene" --snapshots 2>"$out/demo/camera.log" & local cam=$!
  # 3D axes (AXES, recorded in the log) when the triangulation service is built, with the rig and
  # table found by the camera-arm calibration in simulation (nudge-exp-calibration-sim), and the
  # arm's workspace ring from the workspace file every service reads (docs/robot.md).
  local tri=
  if [ -x "$bin/nudge-triangulation" ] && [ -f "$calibration" ]; then
    "$bin/nudge-triangulation" --lcm-url "$url" --calibration "$calibration" --workspace "$workspace" \
      2>"$out/demo/triangulation.log" & tri=$!
  fi
  # Every subscriber listens before the first state: wait until each has started (the camera
  # builds its World first), at most 30 s.
  for _ in $(seq 300); do
    [ "$(grep -l "started:" "$out/demo/symmetry.log" "$out/demo/monitor.log" "$out/demo/camera.log" 2>/dev/null | wc -l)" -eq 3 ] && break
    sleep 0.1
  done
  sleep 0.2
  "$bin/nudge-world" --lcm-url "$url" --scene "$scene" --workspace "$workspace" --realtime-factor 1 --rate "$rate" \
    --duration "$seconds" 2>"$out/demo/world.log"
  local status=0
  wait $mon || status=$?
  kill -INT $sym $cam $tri $logger 2>/dev/null || true
  wait $sym $cam $tri $logger 2>/dev/null || true
  grep -hE "truth |lines for" "$out/demo/monitor.log" | sed 's/^.* I monitor: /  /' >&2 || true
  if [ -n "$tri" ]; then
    grep -hE "stopping:" "$out/demo/triangulation.log" | sed 's/^.* I triangulation: stopping: /  triangulation (AXES in the log): /' >&2 || true
  fi
  return $status
}
export -f run_images_pipeline run_sim_pipeline

# The autonomous segmentation loop (the default).
if [ $# -eq 0 ]; then
  scene=${NUDGE_DEMO_SCENE:-$NUDGE_ROOT/common/sim/scenes/arm_three_objects.yaml}
  run="run-$(date +%Y%m%d-%H%M%S)"
  nudge_export_loop
  export NUDGE_LOOP_LEARN=${NUDGE_DEMO_LEARN:-1}
  nudge_log "autonomous segmentation of $(basename "$scene"): world, camera, symmetry, triangulation, arm, learner and supervisor over LCM; run $run"
  status=0
  loop_start=$SECONDS
  nudge_in_private_network bash -c 'nudge_run_loop "$@"' loop "$NUDGE_BUILD_DIR/bin" "$scene" \
    "$NUDGE_ROOT/config/calibration_sim.yaml" "$NUDGE_ROOT/config/workspace.yaml" "$out/runs" "$run" \
    ${NUDGE_DEMO_SUPERVISOR_FLAGS---track-trace} || status=$?
  dir="$out/runs/$run"
  if [ -f "$dir/summary.json" ]; then
    nudge_log "files: $dir/ (LCM log $run.lcmlog, summary.json, attempt_NN/ with before/after stills, mask, cutout, workspace.png, stages/, views/; objects/: what was learned)"
    report="(no report)"
    "$NUDGE_BUILD_DIR/bin/nudge-report" "$dir" --scene "$scene" >/dev/null && report="report $dir/report.html"
    nudge_log "replay the decisions: build/bin/nudge-supervisor --lcm-in 'file://$dir/$run.lcmlog?speed=0' --lcm-out 'file:///tmp/replay.lcmlog?mode=w' --calibration config/calibration_sim.yaml --first-seq $(nudge_summary_field "$dir/summary.json" first_command_seq)"
    # The one-line summary, last: what the run did and where it is.
    learned=
    [ "$NUDGE_LOOP_LEARN" = 1 ] && learned=", $(nudge_summary_field "$dir/summary.json" learned 0) learned"
    nudge_summary demo "$loop_start" "$(nudge_summary_field "$dir/summary.json" segmented 0) objects segmented$learned" \
      "in $(nudge_summary_field "$dir/summary.json" attempts 0) nudges (exit $status); run folder $dir, $report"
  else
    nudge_summary demo "$loop_start" "no run summary (exit $status): the services' logs are in $dir/services/"
  fi
  exit $status
fi
[ "${1:-}" = perception ] && shift

if [ $# -ge 2 ] || [ "${1:-}" = synthetic ]; then
  frames=${NUDGE_DEMO_FRAMES:-20}
  if [ $# -ge 2 ]; then
    left=$1; right=$2
  else
    if [ ! -f "$out/scenes/frame_$(printf %03d $((frames - 1))).png" ]; then
      "$NUDGE_BUILD_DIR/bin/nudge-synth-scenes" --out "$out/scenes" --count "$frames" --seed 1 >/dev/null
    fi
    left="images:$out/scenes/*.png"; right="images:$out/scenes/*.png"
    nudge_log "using the synthetic sequence in out/scenes"
  fi
  nudge_log "camera -> symmetry -> monitor over LCM, $frames stereo frames; recording $log"
  pipeline=(run_images_pipeline "$NUDGE_BUILD_DIR/bin" "$left" "$right" "$log" "$out" "$frames")
  drawn="detections drawn in out/demo/"
else
  scene=${NUDGE_DEMO_SCENE:-$NUDGE_ROOT/common/sim/scenes/arm_three_objects.yaml}
  seconds=${NUDGE_DEMO_SECONDS:-4}
  rate=${NUDGE_DEMO_RATE:-10}
  nudge_log "world ($(basename "$scene"), ${seconds} s in real time) -> camera (sim, $rate Hz) -> symmetry -> monitor over LCM; recording $log"
  pipeline=(run_sim_pipeline "$NUDGE_BUILD_DIR/bin" "$scene" "$log" "$out" "$seconds" "$rate"
            "$NUDGE_ROOT/config/calibration_sim.yaml" "$NUDGE_ROOT/config/workspace.yaml")
  drawn="detections drawn in out/demo/ (true axes dashed white)"
fi
pipeline_start=$SECONDS
if nudge_in_private_network bash -c '"$@"' demo "${pipeline[@]}"; then
  nudge_log "replay it with: scripts/replay.sh $log"
  nudge_summary demo "$pipeline_start" "$drawn, LCM log $log ($(du -h "$log" | cut -f1))"
else
  nudge_summary demo "$pipeline_start" "the pipeline did not deliver lines for every frame (logs in out/demo/)"
  exit 1
fi
