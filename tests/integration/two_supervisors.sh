#!/usr/bin/env bash
# Integration test (issue 12): two supervisors commanding one arm would fight. A second
# supervisor started on a bus where one already runs must refuse to start (exit 1, naming the
# other's pid) without sending any command, and the first must carry on. Private network namespace.
# usage: two_supervisors.sh BIN_DIR SOURCE_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: two_supervisors.sh BIN_DIR SOURCE_DIR}
src=${2:?usage: two_supervisors.sh BIN_DIR SOURCE_DIR}
nudge_test_in_private_network "$@"
nudge_test_work_dir
url=$NUDGE_TEST_URL
supervisor() {  # waits for services that never come: it stays in WAIT_SERVICES
  exec "$bin/nudge-supervisor" --lcm-url "$url" --clock wall --calibration "$src/config/calibration_sim.yaml" \
    --workspace "$src/config/workspace.yaml" --out "$work/runs" --run-id "$1" --require camera
}
supervisor first 2>"$work/first.log" &
first=$!
sleep 2
status=0
timeout 20 bash -c "$(declare -f supervisor); bin='$bin' src='$src' work='$work' url='$url' supervisor second" \
  2>"$work/second.log" || status=$?
if [ $status -ne 1 ] || ! grep -q "another supervisor (pid $first) runs on this bus: refusing to start" "$work/second.log"; then
  echo "FAILED: the second supervisor exited $status" >&2
  cat "$work/first.log" "$work/second.log" >&2
  exit 1
fi
if grep -q "first ARM_COMMAND seq" "$work/second.log"; then
  echo "FAILED: the second supervisor started its loop before refusing" >&2
  exit 1
fi
kill -0 $first || { echo "FAILED: the first supervisor did not carry on" >&2; cat "$work/first.log" >&2; exit 1; }
kill -INT $first
wait $first || true
echo "PASSED: the second supervisor refused to start; the first carried on"
