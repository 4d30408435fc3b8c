#!/usr/bin/env bash
# Integration test (issue 12): an LCM log that ends in the middle of an event (a full disk, a
# logger killed mid-write) is played up to its last whole event, the cut named, and the player
# ends cleanly (exit 0): nudge-symmetry --lcm-in file://LOG answers every whole camera frame
# before the cut, and nudge-replay plays every whole event; both say where the log was cut.
# The log is recorded from nudge-camera, then cut in the middle of its last CAMERA_LEFT frame.
# In a private network namespace (nudge-replay publishes on UDP multicast).
# usage: truncated_log.sh BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: truncated_log.sh BIN_DIR}
nudge_test_in_private_network "$@"
nudge_test_work_dir
"$bin/nudge-synth-scenes" --out "$work/scenes" --count 4 --seed 7 >/dev/null
url=$NUDGE_TEST_URL

# The events of an LCM log: "end_offset channel" per whole event (LCM's file format).
events() {
  python3 - "$1" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
at = 0
while at + 24 <= len(data):
    sync, _, _, channel_len, data_len = struct.unpack('>IqqII', data[at:at + 28]) if at + 28 <= len(data) else (0, 0, 0, 0, 0)
    end = at + 28 + channel_len + data_len
    if sync != 0xEDA1DA01 or end > len(data):
        break
    print(end, data[at + 28:at + 28 + channel_len].decode())
    at = end
PY
}

"$bin/nudge-camera" --lcm-url "$url" --lcm-out "file://$work/camera.lcmlog?mode=w" \
  --left "images:$work/scenes/*.png" --right "images:$work/scenes/*.png" --rate 20 --format png 2>"$work/camera.log"
events "$work/camera.lcmlog" >"$work/events.txt"
# Cut the log in the middle of its last left frame.
last_left=$(grep -n " CAMERA_LEFT$" "$work/events.txt" | tail -n1 | cut -d: -f1)
start=$(sed -n "$((last_left - 1))p" "$work/events.txt" | cut -d' ' -f1)
end=$(sed -n "${last_left}p" "$work/events.txt" | cut -d' ' -f1)
cut=$(( (start + end) / 2 ))
head -c "$cut" "$work/camera.lcmlog" >"$work/cut.lcmlog"
whole_events=$((last_left - 1))
whole_left=$(head -n "$whole_events" "$work/events.txt" | grep -c " CAMERA_LEFT$")
echo "camera log: $(wc -l <"$work/events.txt") events; cut at byte $cut of $(stat -c %s "$work/camera.lcmlog"): $whole_events whole events, $whole_left left frames"

fail() { echo "FAILED: $*" >&2; cat "$work"/*.log >&2; exit 1; }

# A service reading the cut log: every whole left frame answered, the cut named, exit 0.
"$bin/nudge-symmetry" --lcm-in "file://$work/cut.lcmlog?speed=0" --lcm-out "file://$work/symmetry.lcmlog?mode=w" \
  --inputs CAMERA_LEFT,CAMERA_RIGHT 2>"$work/symmetry.log" || fail "nudge-symmetry exit $? on a cut log"
grep -q "cut.lcmlog ends in the middle of an event" "$work/symmetry.log" || fail "nudge-symmetry did not name the cut"
answered=$(events "$work/symmetry.lcmlog" | grep -c " SYMMETRY_LEFT$" || true)
[ "$answered" = "$whole_left" ] || fail "nudge-symmetry answered $answered left frames, the cut log holds $whole_left whole ones"

# The player: every whole event played, the cut named at the start and the end, exit 0.
"$bin/nudge-replay" --lcm-url "$url" --speed 20 "$work/cut.lcmlog" 2>"$work/replay.log" || fail "nudge-replay exit $? on a cut log"
[ "$(grep -c "cut.lcmlog ends in the middle of an event" "$work/replay.log")" = 2 ] || fail "nudge-replay did not name the cut twice"
grep -q "log finished: $whole_events events played" "$work/replay.log" || fail "nudge-replay did not play the $whole_events whole events"
grep -h "ends in the middle" "$work/symmetry.log" | head -n1
echo "PASSED: $answered of $whole_left whole left frames answered by symmetry, $whole_events events replayed; the cut named by both"
