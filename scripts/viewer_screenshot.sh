#!/usr/bin/env bash
# A screenshot of nudge-viewer on a recorded run (docs/operator.md, images/viewer_replay.png):
# in a private network namespace, nudge-replay plays LOG at x4 to SECONDS into it, pauses, steps
# one frame, and headless Chromium takes the page.
#   scripts/viewer_screenshot.sh out/runs/<run>/<run>.lcmlog 100 docs/images/viewer_replay.png
# Needs root (unshare -n) and Debian's chromium.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
log=${1:?usage: viewer_screenshot.sh LOG SECONDS OUT.png}
seconds=${2:?usage: viewer_screenshot.sh LOG SECONDS OUT.png}
out=${3:?usage: viewer_screenshot.sh LOG SECONDS OUT.png}
[ -r "$log" ] || { echo "viewer_screenshot.sh: $log: cannot read it" >&2; exit 2; }
[ -x /usr/bin/chromium ] || { echo "viewer_screenshot.sh: needs /usr/bin/chromium (Debian package chromium)" >&2; exit 2; }
out=$(realpath -m "$out")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$SECONDS
unshare -n bash -s "$NUDGE_BUILD_DIR/bin" "$NUDGE_ROOT" "$log" "$seconds" "$out" "$work" <<'INNER'
set -euo pipefail
bin=$1 root=$2 log=$3 seconds=$4 out=$5 work=$6
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo
page=http://127.0.0.1:8088
"$bin/nudge-viewer" --calibration "$root/config/calibration_sim.yaml" 2>"$work/viewer.log" & viewer=$!
"$bin/nudge-replay" "$log" --paused 2>"$work/replay.log" & replay=$!
trap 'kill -INT $replay $viewer 2>/dev/null || true; wait 2>/dev/null || true' EXIT
command() { curl -sf -d '' "$page/api/replay?command=$1" >/dev/null; }
position() {  # seconds into the log, as the replay last reported it
  curl -sf "$page/api/state" | python3 -c 'import json, sys
r = json.load(sys.stdin)["replay"] or {}
print(int((r.get("position_utime", 0) - r.get("start_utime", 0)) / 1e6))'
}
for _ in $(seq 50); do [ "$(position 2>/dev/null || echo -1)" -ge 0 ] && break; sleep 0.2; done
command "speed&speed=4"
command play
for _ in $(seq 600); do [ "$(position)" -ge "$seconds" ] && break; sleep 0.5; done
command pause
sleep 1
command step
sleep 1
timeout 90 chromium --headless --no-sandbox --disable-gpu --user-data-dir="$work/profile" --virtual-time-budget=2500 \
  --window-size=1400,1300 --screenshot="$out" "$page/?snapshot" >"$work/chromium.log" 2>&1
INNER
[ -s "$out" ] || { echo "viewer_screenshot.sh: no screenshot was written" >&2; exit 1; }
nudge_summary viewer_screenshot.sh "$start" "$out at $seconds s of $log"
