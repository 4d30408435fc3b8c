#!/usr/bin/env bash
# Integration test: a simulated camera slower than the world stays current. The world publishes
# states faster than the camera can draw them; the camera runs twice over real UDP multicast in a
# private network namespace, once drawing every state (--max-lag-ms 0: LCM's queue fills and the
# frames come later and later) and once with --max-lag-ms: the states that waited too long are not
# drawn, their frame ids are used up (gaps, seen downstream as missed frames), and the frames drawn
# are near the world's present. The two runs are compared with each other (ratios in one run, no
# absolute timing).
# usage: camera_lag.sh BIN_DIR SCENE
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: camera_lag.sh BIN_DIR SCENE}
scene=${2:?usage: camera_lag.sh BIN_DIR SCENE}
rate=500 seconds=2 limit_ms=40

nudge_test_in_private_network "$@"
nudge_test_work_dir
url=$NUDGE_TEST_URL

# run_camera NAME MAX_LAG_MS: the world at `rate` Hz for `seconds`, the camera drawing it, every
# message logged by lcm-logger (receive times) into $work/NAME.lcmlog.
run_camera() {
  local name=$1 max_lag=$2
  lcm-logger --lcm-url "$url" "$work/$name.lcmlog" >/dev/null 2>&1 &
  local logger=$!
  "$bin/nudge-camera" --lcm-url "$url" --source sim --scene "$scene" --max-lag-ms "$max_lag" 2>"$work/$name.camera.log" &
  local cam=$!
  wait_for 30 "the camera started" log_has "started:" "$work/$name.camera.log"
  sleep 0.3
  "$bin/nudge-world" --lcm-url "$url" --scene "$scene" --realtime-factor 1 --rate "$rate" --duration "$seconds" \
    2>"$work/$name.world.log"
  sleep 1  # the camera's backlog, if any, drains into the log
  kill -INT $cam; wait $cam || true
  kill -INT $logger; wait $logger || true
}
run_camera every 0
run_camera limited "$limit_ms"

python3 - "$work/every.lcmlog" "$work/limited.lcmlog" <<'PY'
import struct, sys

def read(path):
    """(state receive times by utime, [(utime, frame_id, receive time)] of CAMERA_RIGHT)."""
    states, frames = {}, []
    with open(path, 'rb') as f:
        while True:
            head = f.read(28)
            if len(head) < 28:
                break
            _, _, ts, channel_len, data_len = struct.unpack('>IqqII', head)
            channel = f.read(channel_len).decode()
            data = f.read(data_len)
            if channel == 'SIM_STATE':
                states[struct.unpack('>q', data[8:16])[0]] = ts
            elif channel == 'CAMERA_RIGHT':
                utime, frame_id = struct.unpack('>qq', data[8:24])
                frames.append((utime, frame_id, ts))
    return states, frames

def lags_ms(states, frames):
    return sorted((ts - states[u]) / 1000 for u, _, ts in frames if u in states)

def p90(values):
    return values[int(0.9 * (len(values) - 1))]

every_states, every_frames = read(sys.argv[1])
states, frames = read(sys.argv[2])
assert len(states) > 500 and len(every_states) > 500, f"the world published {len(states)} / {len(every_states)} states"
assert len(frames) > 20, f"the limited camera drew {len(frames)} frames"
every, limited = lags_ms(every_states, every_frames), lags_ms(states, frames)
print(f"every state: {len(every_frames)} of {len(every_states)} drawn, lag p90 {p90(every):.0f} ms; "
      f"--max-lag-ms: {len(frames)} of {len(states)} drawn, lag p90 {p90(limited):.0f} ms")
# Skipped states use up their frame ids (a lost UDP message does not: the camera never had it).
ids = [frame_id for _, frame_id, _ in frames]
assert ids == sorted(ids) and len(set(ids)) == len(ids), "frame ids increase"
assert ids[-1] + 1 > len(frames), f"no gap in the frame ids ({len(frames)} frames, last id {ids[-1]}): nothing was skipped"
# The camera that skips stays far nearer the present than the one that draws every state.
assert p90(every) > 3 * p90(limited), f"lag p90 {p90(every):.0f} ms drawing every state vs {p90(limited):.0f} ms with the limit"
PY
for name in every limited; do
  grep -q " 0 errors" "$work/$name.camera.log" || { echo "FAILED: the camera ($name) reported errors" >&2; cat "$work/$name.camera.log" >&2; exit 1; }
done
echo "PASSED: a camera slower than the world skips stale states and stays current"
