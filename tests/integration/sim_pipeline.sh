#!/usr/bin/env bash
# Integration test of the simulated pipeline: world -> camera (--source sim) -> symmetry ->
# monitor, separate processes over real UDP multicast inside a private network namespace. The
# world runs in real time; the monitor checks that lines arrive for the rendered stereo frames
# and compares them with the true axes in SIM_STATE. One frame per camera may be lost: the kernel
# caps receive buffers at the host's net.core.rmem_max (4 MB here, not raisable in a namespace),
# and on a loaded machine a stalled receiver drops a 300 KB image now and then. The monitor
# names the lost frame ids; the services count them in their heartbeats.
# usage: sim_pipeline.sh BIN_DIR SCENE
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: sim_pipeline.sh BIN_DIR SCENE}
scene=${2:?usage: sim_pipeline.sh BIN_DIR SCENE}
# 5 Hz: the symmetry service takes 40-70 ms per image, so at 10 Hz a stereo pair's 80-140 ms of
# work filled the period, and with ctest's other job on the second core its backlog overflowed the
# receive buffer (3 of 21 right images lost, 2026-12-02 CI). The real-time rates are measured by
# the benchmarks, not here. ctest runs this test alone (RUN_SERIAL): at 5 Hz beside another test it
# still lost 2 of 21 right images once (2026-12-02 CI).
seconds=4 rate=5
frames=$((seconds * rate + 1))  # the state at t = 0, then one per period

nudge_test_in_private_network "$@"
nudge_test_work_dir
sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216 2>/dev/null || true
url=$NUDGE_TEST_URL

# Mirror-consistent pairs: the striped mug's texture must not take the cup's line.
"$bin/nudge-symmetry" --lcm-url "$url" --lines 5 --theta-min -25 --theta-max 25 --once-per-row --mirror-tolerance 15 \
  2>"$work/symmetry.log" &
sym=$!
"$bin/nudge-monitor" --lcm-url "$url" --truth --expect-frames "$frames" --allow-missing 1 --timeout 45 2>"$work/monitor.log" &
mon=$!
"$bin/nudge-camera" --lcm-url "$url" --source sim --scene "$scene" --max-lag-ms 0 2>"$work/camera.log" &  # every state drawn (the default)
cam=$!
# Every subscriber listens before the first state: wait until each has started (the camera
# builds its World first), each within 30 s.
for s in symmetry monitor camera; do wait_for 30 "$s started" log_has "started:" "$work/$s.log"; done
sleep 0.2
"$bin/nudge-world" --lcm-url "$url" --scene "$scene" --realtime-factor 1 --rate "$rate" --duration "$seconds" \
  2>"$work/world.log"
status=0
wait $mon || status=$?
kill -INT $sym $cam; wait $sym || true; wait $cam || true
if [ $status -ne 0 ]; then
  echo "FAILED: lines did not arrive for the frames (more than one lost per camera)" >&2
  cat "$work/monitor.log" "$work/symmetry.log" "$work/camera.log" "$work/world.log" >&2
  exit 1
fi
grep -E "lines for|no lines for|truth " "$work/monitor.log"
# Every object's true axis is among the lines in at least 90 % of the frames of each camera.
objects=$(grep -c "truth SYMMETRY_" "$work/monitor.log" || true)
[ "$objects" -ge 6 ] || { echo "FAILED: expected 3 objects x 2 cameras in the truth summary, got $objects" >&2; exit 1; }
while read -r found total; do
  [ $((10 * found)) -ge $((9 * total)) ] || { echo "FAILED: an object's axis found in only $found/$total frames" >&2; exit 1; }
done < <(sed -n 's/.*truth SYMMETRY_.*: found in \([0-9]*\)\/\([0-9]*\) frames.*/\1 \2/p' "$work/monitor.log")
for s in symmetry camera world; do
  grep -q " 0 errors" "$work/$s.log" || { echo "FAILED: $s reported errors" >&2; cat "$work/$s.log" >&2; exit 1; }
done
echo "PASSED: world -> camera (sim) -> symmetry over UDP multicast, lines for the $frames stereo frames"
