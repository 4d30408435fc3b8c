#!/usr/bin/env bash
# Integration test (issue 12): a clock that jumps back. Two recordings back to back in one log
# (the second's stamps start before the first's end, as when a replay is restarted): nudge-replay
# plays every event of both, the second part paced from its own start (ReplayPacer re-anchors;
# unit-tested), and ends cleanly; nudge-symmetry fed the log (--lcm-in file://) answers every frame
# of both parts and ends cleanly. In a private network namespace (nudge-replay publishes on UDP).
# usage: logs_back_to_back.sh BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: logs_back_to_back.sh BIN_DIR}
nudge_test_in_private_network "$@"
nudge_test_work_dir
"$bin/nudge-synth-scenes" --out "$work/scenes" --count 3 --seed 7 >/dev/null
url=$NUDGE_TEST_URL
fail() { echo "FAILED: $*" >&2; cat "$work"/*.log >&2; exit 1; }
# Events per channel of an LCM log (LCM's file format): "COUNT CHANNEL" lines.
channels() {
  python3 - "$1" <<'PY'
import collections, struct, sys
data = open(sys.argv[1], 'rb').read()
at, counts = 0, collections.Counter()
while at + 28 <= len(data):
    sync, _, _, channel_len, data_len = struct.unpack('>IqqII', data[at:at + 28])
    if sync != 0xEDA1DA01 or at + 28 + channel_len + data_len > len(data):
        break
    counts[data[at + 28:at + 28 + channel_len].decode()] += 1
    at += 28 + channel_len + data_len
for channel, count in sorted(counts.items()):
    print(count, channel)
PY
}

"$bin/nudge-camera" --lcm-url "$url" --lcm-out "file://$work/once.lcmlog?mode=w" \
  --left "images:$work/scenes/*.png" --right "images:$work/scenes/*.png" --rate 10 --format png 2>"$work/camera.log"
cat "$work/once.lcmlog" "$work/once.lcmlog" >"$work/twice.lcmlog"
once_left=$(channels "$work/once.lcmlog" | awk '$2 == "CAMERA_LEFT" { print $1 }')
events_once=$(channels "$work/once.lcmlog" | awk '{ n += $1 } END { print n }')

timeout 60 "$bin/nudge-replay" --lcm-url "$url" --speed 4 "$work/twice.lcmlog" 2>"$work/replay.log" || fail "nudge-replay exit $?"
grep -q "log finished: $((2 * events_once)) events played" "$work/replay.log" || fail "nudge-replay did not play both parts"

timeout 120 "$bin/nudge-symmetry" --lcm-in "file://$work/twice.lcmlog?speed=0" --lcm-out "file://$work/symmetry.lcmlog?mode=w" \
  --inputs CAMERA_LEFT,CAMERA_RIGHT 2>"$work/symmetry.log" || fail "nudge-symmetry exit $?"
answered=$(channels "$work/symmetry.lcmlog" | awk '$2 == "SYMMETRY_LEFT" { print $1 }')
[ "$answered" = $((2 * once_left)) ] || fail "nudge-symmetry answered ${answered:-0} left frames of $((2 * once_left))"
echo "PASSED: $((2 * events_once)) events replayed across the jump back, $answered left frames answered"
