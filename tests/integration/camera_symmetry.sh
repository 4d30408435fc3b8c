#!/usr/bin/env bash
# Integration test: camera and symmetry run as separate processes and talk over real UDP
# multicast, inside a private network namespace (no traffic can leave it). A monitor process
# checks that lines arrive for every stereo frame.
# usage: camera_symmetry.sh BIN_DIR
set -euo pipefail
bin=${1:?usage: camera_symmetry.sh BIN_DIR}
frames=12

if [ "$(id -u)" != 0 ] || ! unshare -n true 2>/dev/null; then
  echo "SKIPPED: needs root and unshare -n for a private network namespace" >&2
  exit 77
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/nudge-synth-scenes" --out "$work/scenes" --count "$frames" --seed 7 >/dev/null

unshare -n bash -s "$bin" "$work" "$frames" <<'INNER'
set -euo pipefail
bin=$1; work=$2; frames=$3
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo
sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216 2>/dev/null || true
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"

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
INNER
