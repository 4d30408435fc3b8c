#!/usr/bin/env bash
# lcm-spy, as scripts/spy.sh starts it, decodes the nudge types on a replayed log: under Xvfb and
# inside a private network namespace, nudge-replay plays a short camera log and nudge-symmetry
# answers it live; lcm-spy (in SpyTable.java's JVM) watches the bus. The check reads lcm-spy's
# channel table from its Swing model (what its window shows, without OCR): every channel is
# listed with its nudge type and none is undecodable. A screenshot of the screen is saved.
# usage: spy_screen.sh BUILD_DIR SOURCE_DIR [SCREENSHOT.png]   (NUDGE_KEEP=1: keep the work folder)
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
build=${1:?usage: spy_screen.sh BUILD_DIR SOURCE_DIR [SCREENSHOT.png]}
src=${2:?usage: spy_screen.sh BUILD_DIR SOURCE_DIR [SCREENSHOT.png]}
shot=${3:-$build/test_output/lcm_spy.png}
jar="$build/share/nudge_lcmtypes.jar"

nudge_test_in_private_network "$@"
for tool in Xvfb xwd xwdtopnm pnmtopng java javac; do
  command -v "$tool" >/dev/null || nudge_test_skip "$tool is not installed (Debian: xvfb, x11-apps, netpbm, default-jdk-headless)"
done
[ -f "$jar" ] || { echo "FAILED: $jar was not built" >&2; exit 1; }

nudge_test_work_dir  # every process started below is stopped on exit, Xvfb too
# The log: 20 stereo frames at 10 Hz, written by the camera straight to a file.
"$build/bin/nudge-synth-scenes" --out "$work/scenes" --count 20 --seed 7 >/dev/null || exit 1
"$build/bin/nudge-camera" --lcm-url "file://$work/camera.lcmlog?mode=w" --left "images:$work/scenes/*.png" \
  --right "images:$work/scenes/*.png" --rate 10 --format jpeg 2>"$work/camera.log" || { cat "$work/camera.log" >&2; exit 1; }
classpath="$jar:/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar"
javac -cp "$classpath" -d "$work" "$src/tests/integration/SpyTable.java" || exit 1
mkdir -p "$(dirname "$shot")"
url="udpm://239.255.76.67:7667?ttl=0"

# Xvfb picks a free display itself (-displayfd): other X servers on this machine are left alone.
Xvfb -displayfd 5 -screen 0 1100x800x24 -nolisten tcp 5>"$work/display" 2>"$work/xvfb.log" &
wait_for 5 "Xvfb started (its display number)" test -s "$work/display" || exit 1
export DISPLAY=":$(head -1 "$work/display")"

# lcm-spy as scripts/spy.sh runs it (the Spy class with the nudge jar on the CLASSPATH).
expected="CAMERA_LEFT=image_t CAMERA_RIGHT=image_t SYMMETRY_LEFT=symmetry_lines_t SYMMETRY_RIGHT=symmetry_lines_t"
expected+=" HEARTBEAT=heartbeat_t REPLAY_STATUS=replay_status_t"
channels=$(for e in $expected; do printf '%s,' "${e%%=*}"; done)
CLASSPATH="$work:$classpath" java -Djava.net.preferIPv4Stack=true -Dspy.open=SYMMETRY_LEFT -ea SpyTable 60 "${channels%,}" --lcm-url "$url" \
  >"$work/spy.out" 2>"$work/spy.err" &
wait_for 60 "lcm-spy's window (READY or NO_TABLE)" grep -qE '^(READY|NO_TABLE)' "$work/spy.out"
grep -q '^READY' "$work/spy.out" || { echo "FAILED: lcm-spy's window did not open" >&2; cat "$work/spy.out" "$work/spy.err" >&2; exit 1; }
"$build/bin/nudge-symmetry" --lcm-url "$url" --inputs CAMERA_LEFT,CAMERA_RIGHT 2>"$work/symmetry.log" &
sleep 1  # symmetry subscribes before the log plays
"$build/bin/nudge-replay" "$work/camera.lcmlog" --lcm-url "$url" --speed 0.5 2>"$work/replay.log" &
wait_for 60 "lcm-spy's table (COLUMNS)" grep -q '^COLUMNS' "$work/spy.out"
# SpyTable double-clicks SYMMETRY_LEFT while the log still plays: its viewer shows a live message.
wait_for 20 "lcm-spy's field view of SYMMETRY_LEFT (VIEWER)" grep -q '^VIEWER .*SYMMETRY_LEFT' "$work/spy.out"
sleep 1  # the windows repaint
xwd -root -silent | xwdtopnm 2>/dev/null | pnmtopng >"$shot" 2>/dev/null
cat "$work/spy.out"
grep -q '^COLUMNS' "$work/spy.out" || { echo "FAILED: lcm-spy's table was not read" >&2; cat "$work/spy.err" >&2; exit 1; }
grep -q '^VIEWER .*SYMMETRY_LEFT' "$work/spy.out" ||
  { echo "FAILED: a double click on SYMMETRY_LEFT opened no field view" >&2; cat "$work/spy.err" >&2; exit 1; }
[ "$(head -c 8 "$shot" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || { echo "FAILED: no PNG screenshot" >&2; exit 1; }
# Every channel listed with its nudge type (an unknown fingerprint shows as "?? HEX"), seen and
# all decoded. LCM's own LCM_SELF_TEST (not a nudge type) is ignored.
failed=0
for e in $expected; do
  channel=${e%%=*} type=${e#*=}
  row=$(awk -F'\t' -v c="$channel" '$1 == "ROW" && $2 == c' "$work/spy.out")
  if [ -z "$row" ]; then echo "FAILED: lcm-spy does not list $channel" >&2; failed=1; continue; fi
  IFS=$'\t' read -r _ name shown count _ _ _ _ undecodable <<<"$row"
  if [ "$shown" != "$type" ] || [ "$count" -lt 1 ] || [ "$undecodable" != 0 ]; then
    echo "FAILED: $channel shown as '$shown' ($count messages, $undecodable undecodable), expected $type" >&2
    failed=1
  fi
done
[ $failed -eq 0 ] || exit 1
echo "PASSED: lcm-spy decodes $(echo $expected | wc -w) channels of 4 nudge types on the replayed log"
echo "screenshot: $shot"
