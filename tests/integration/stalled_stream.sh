#!/usr/bin/env bash
# Integration test (issue 12): a camera stream that ends (a file source at its end: the camera
# says goodbye and stops) and one that stalls (the camera process stopped with SIGSTOP, as a hung
# driver: no frames, no heartbeats) are named by the service that reads them: nudge-symmetry
# logs "no messages: CAMERA_LEFT (or CAMERA_RIGHT, whichever falls silent first) silent for ..." and its heartbeat turns DEGRADED naming the
# channel (shown by nudge-monitor), then no longer names it once the frames are back (RUNNING
# after kDegradedHoldUs, 5 s, unless frames are being dropped on a loaded machine). camera -> symmetry -> monitor over UDP multicast in a private network namespace.
# usage: stalled_stream.sh BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: stalled_stream.sh BIN_DIR}
nudge_test_in_private_network "$@"
# On any exit (a failed check included) no process of the test outlives it (common.sh's cleanup
# continues the stopped camera too): it would keep ctest's output pipe, and the test "running".
nudge_test_work_dir
"$bin/nudge-synth-scenes" --out "$work/scenes" --count 10 --seed 7 >/dev/null
url=$NUDGE_TEST_URL

# The time (s since the epoch) of the n-th ($3) line matching $1 in $2, by the line's own stamp.
stamp_of() {
  date -d "$(grep -- "$1" "$2" | sed -n "${3:-1}p" | cut -d' ' -f1)" +%s.%N
}
count() { grep -c -- "$1" "$2" || true; }
# Symmetry's heartbeats, as the monitor logs their changes, that name no silent stream: RUNNING,
# or DEGRADED for another reason (frames dropped on a loaded machine keep it DEGRADED for 5 s).
recovered() { grep "heartbeat: symmetry " "$work/monitor.log" | grep -vc "silent" || true; }
more_recovered() { [ "$(recovered)" -gt "$1" ]; }
wait_recovered() {  # wait_recovered BEFORE: up to 20 s for a new such heartbeat
  wait_for 20 "a heartbeat of symmetry's naming no silent stream after the frames returned" more_recovered "$1"
}
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

"$bin/nudge-symmetry" --lcm-url "$url" --inputs CAMERA_LEFT,CAMERA_RIGHT 2>"$work/symmetry.log" &
sym=$!
"$bin/nudge-monitor" --lcm-url "$url" 2>"$work/monitor.log" &
mon=$!
camera() {  # camera ARGS...: 2 Hz from the ten scenes (a loaded machine keeps up: no missed frames)
  "$bin/nudge-camera" --lcm-url "$url" --left "images:$work/scenes/*.png" --right "images:$work/scenes/*.png" \
    --rate 2 --format png "$@" 2>>"$work/camera.log" >/dev/null &
  cam=$!
}

# 1. The stream ends: ten frames, then the camera says goodbye (STOPPING) and exits.
camera
wait_for 20 "a SYMMETRY_LEFT frame at the monitor" log_has "SYMMETRY_LEFT frame" "$work/monitor.log"
wait_for 30 "the camera's file at its end" log_has "finished after" "$work/camera.log"
wait_for 10 "symmetry naming the ended stream" log_has "no messages: CAMERA_\(LEFT\|RIGHT\) silent" "$work/symmetry.log"
wait_for 10 "symmetry's heartbeat DEGRADED naming the ended stream" \
  log_has "heartbeat: symmetry DEGRADED: .*CAMERA_\(LEFT\|RIGHT\) silent for" "$work/monitor.log"
t_end=$(seconds "$(stamp_of "finished after" "$work/camera.log")" "$(stamp_of "no messages: CAMERA_\(LEFT\|RIGHT\) silent" "$work/symmetry.log")")

# 2. Frames again (a new camera, looping): the stream is back, and RUNNING after the hold.
before=$(recovered)
camera --loop
wait_for 10 "symmetry seeing the stream back" log_has "every watched stream is flowing again" "$work/symmetry.log"
wait_recovered "$before"

# 3. The stream stalls: the camera process stopped (no frames, no heartbeats), then resumed.
quiet=$(count "no messages: " "$work/symmetry.log")
degraded=$(count "heartbeat: symmetry DEGRADED: .*CAMERA_\(LEFT\|RIGHT\) silent for" "$work/monitor.log")
flowing=$(count "every watched stream is flowing again" "$work/symmetry.log")
kill -STOP $cam
stalled=$(date +%s.%N)
wait_for 10 "symmetry naming the stalled stream" log_has "no messages: " "$work/symmetry.log" $((quiet + 1))
grep -- "no messages: " "$work/symmetry.log" | sed -n "$((quiet + 1))p" | grep -q "CAMERA_\(LEFT\|RIGHT\) silent" ||
  { echo "FAILED: the stall was not named as a camera stream's" >&2; exit 1; }
wait_for 10 "symmetry's heartbeat DEGRADED naming the stalled stream" \
  log_has "heartbeat: symmetry DEGRADED: .*CAMERA_\(LEFT\|RIGHT\) silent for" "$work/monitor.log" $((degraded + 1))
t_stall=$(seconds "$stalled" "$(stamp_of "no messages: " "$work/symmetry.log" $((quiet + 1)))")
before=$(recovered)
kill -CONT $cam
wait_for 10 "symmetry seeing the resumed stream" \
  log_has "every watched stream is flowing again" "$work/symmetry.log" $((flowing + 1))
wait_recovered "$before"

kill -INT $cam $sym $mon
wait $cam $sym $mon 2>/dev/null || true
grep -h "no messages\|flowing again" "$work/symmetry.log"
grep -h "heartbeat: symmetry" "$work/monitor.log"
echo "PASSED: the ended stream was named ${t_end} s after the camera logged its end, the stalled one ${t_stall} s after SIGSTOP; its heartbeat stopped naming it both times once frames returned"
