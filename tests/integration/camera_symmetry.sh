#!/usr/bin/env bash
# Integration test: camera and symmetry run as separate processes and talk over real UDP
# multicast, inside a private network namespace (no traffic can leave it). A monitor process
# checks that lines arrive for every stereo frame.
# usage: camera_symmetry.sh BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: camera_symmetry.sh BIN_DIR}
frames=12
nudge_test_in_private_network "$@"
nudge_test_work_dir
"$bin/nudge-synth-scenes" --out "$work/scenes" --count "$frames" --seed 7 >/dev/null
sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216 2>/dev/null || true
url=$NUDGE_TEST_URL

"$bin/nudge-symmetry" --lcm-url "$url" --inputs CAMERA_LEFT,CAMERA_RIGHT 2>"$work/symmetry.log" &
sym=$!
"$bin/nudge-monitor" --lcm-url "$url" --expect-frames "$frames" --timeout 60 2>"$work/monitor.log" &
mon=$!
sleep 0.5
# Frames paced so the detector keeps up on a loaded machine; pairs share one utime.
"$bin/nudge-camera" --lcm-url "$url" --left "images:$work/scenes/*.png" --right "images:$work/scenes/*.png" \
  --rate 5 --format png 2>"$work/camera.log"
status=0
wait $mon || status=$?
kill -INT $sym; wait $sym || true
if [ $status -ne 0 ]; then
  echo "FAILED: lines did not arrive for every frame" >&2
  cat "$work/monitor.log" "$work/symmetry.log" "$work/camera.log" >&2
  exit 1
fi
grep -E "lines for" "$work/monitor.log"
grep -q "0 errors" "$work/symmetry.log" || { echo "FAILED: symmetry reported errors" >&2; cat "$work/symmetry.log" >&2; exit 1; }
echo "PASSED: camera -> symmetry over UDP multicast, lines for all $frames stereo frames"
