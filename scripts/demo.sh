#!/usr/bin/env bash
# The main job: camera -> symmetry -> monitor as separate processes over LCM, on a stereo image
# sequence; the whole run is recorded to an LCM log under out/ and the detections are drawn
# into out/demo/.
#   scripts/demo.sh                       # the shipped synthetic sequence
#   scripts/demo.sh 'images:/data/left/*.png' 'images:/data/right/*.png'
# By default the processes share a private network namespace (when run as root), so no
# traffic leaves it; NUDGE_HOST_NETWORK=1 uses this host's network instead (to watch with
# scripts/spy.sh).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
nudge_install_packages
nudge_build

out="$NUDGE_ROOT/out"
mkdir -p "$out/demo"
frames=${NUDGE_DEMO_FRAMES:-20}
if [ $# -ge 2 ]; then
  left=$1; right=$2
else
  if [ ! -f "$out/scenes/frame_$(printf %03d $((frames - 1))).png" ]; then
    "$NUDGE_BUILD_DIR/bin/nudge-synth-scenes" --out "$out/scenes" --count "$frames" --seed 1 >/dev/null
  fi
  left="images:$out/scenes/*.png"; right="images:$out/scenes/*.png"
  nudge_log "no sources given: using the synthetic sequence in out/scenes"
fi
log="$out/demo-$(date +%Y%m%d-%H%M%S).lcmlog"

run_pipeline() {
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
export -f run_pipeline
nudge_log "camera -> symmetry -> monitor over LCM, $frames stereo frames; recording $log"
if nudge_in_private_network bash -c 'run_pipeline "$@"' demo "$NUDGE_BUILD_DIR/bin" "$left" "$right" "$log" "$out" "$frames"; then
  nudge_log "done: detections drawn in out/demo/, LCM log $log ($(du -h "$log" | cut -f1))"
  nudge_log "replay it with: scripts/replay.sh $log"
else
  nudge_log "the pipeline did not deliver lines for every frame"
  exit 1
fi
