# Shared by the integration test scripts (sourced, not run): the skip when a private namespace
# cannot be made, the test re-run inside a private network namespace, a work folder and a cleanup
# that stops every process the test started, and waits with a deadline that say what they waited for.
#
#   source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
#   nudge_test_in_private_network "$@"   # from here on: root, in a fresh network namespace
#   nudge_test_work_dir                  # $work, removed on exit after the test's processes stop
#   wait_for 20 "the monitor's first frame" log_has "SYMMETRY_LEFT frame" "$work/monitor.log"
#
# The LCM URL every test uses on its namespace's loopback.
NUDGE_TEST_URL="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"

# Ends the test as skipped (ctest's SKIP_RETURN_CODE 77), saying why.
nudge_test_skip() {
  echo "SKIPPED: $*" >&2
  exit 77
}

# Skips the test unless it runs as root and unshare can make a namespace of each kind given
# (e.g. -n: network, -m: mount).
nudge_test_require_namespace() {
  local kind=$1 what=${2:-a private namespace}
  if [ "$(id -u)" != 0 ] || ! unshare "$kind" true 2>/dev/null; then
    nudge_test_skip "needs root and unshare $kind for $what"
  fi
}

# Runs the calling script again, with the same arguments, inside a new network namespace whose
# loopback carries multicast (nothing the test sends can leave it), then returns there: call it
# first, with "$@". Skips the test (77) where no namespace can be made (not root, no unshare -n).
nudge_test_in_private_network() {
  if [ "${NUDGE_TEST_FRESH_NETWORK:-}" != 1 ]; then
    nudge_test_require_namespace -n "a private network namespace"
    NUDGE_TEST_FRESH_NETWORK=1 exec unshare -n bash "$0" "$@"
  fi
  unset NUDGE_TEST_FRESH_NETWORK  # the test's own children are not re-run
  ip link set lo up multicast on
  ip route add 224.0.0.0/4 dev lo
}

# Makes the test's work folder, $work, and sets the cleanup on exit (and on SIGINT/SIGTERM):
# every process the test started is stopped, then $work is removed (kept with NUDGE_KEEP=1).
nudge_test_work_dir() {
  work=$(mktemp -d)
  trap nudge_test_cleanup EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
}

# Every process below this shell, deepest first (a service started through timeout or nsenter too).
nudge_test_descendants() {
  local child
  for child in $(ps -o pid= --ppid "$1" 2>/dev/null); do
    nudge_test_descendants "$child"
    echo "$child"
  done
}

# Stops every process the test started: SIGTERM (and SIGCONT, for one the test stopped: a stopped
# process holding ctest's output pipe would keep the test "running" to its timeout), up to 2 s for
# them to end (Xvfb removes its lock files), then SIGKILL. Then removes $work.
nudge_test_cleanup() {
  local status=$? pids alive pid deadline
  pids=$(nudge_test_descendants $$)
  if [ -n "$pids" ]; then
    kill -TERM $pids 2>/dev/null || true
    kill -CONT $pids 2>/dev/null || true
    deadline=$(nudge_test_now_us)
    deadline=$((deadline + 2000000))
    while :; do
      alive=
      for pid in $pids; do kill -0 "$pid" 2>/dev/null && alive+=" $pid"; done
      [ -z "$alive" ] || [ "$(nudge_test_now_us)" -ge "$deadline" ] && break
      sleep 0.05
    done
    [ -z "$alive" ] || kill -KILL $alive 2>/dev/null || true
    wait 2>/dev/null || true
  fi
  if [ -n "${work:-}" ] && [ -z "${NUDGE_KEEP:-}" ]; then rm -rf "$work"; fi
  return $status
}

# Microseconds since the epoch (bash's clock: no process started).
nudge_test_now_us() {
  echo "${EPOCHREALTIME//[.,]/}"
}

# wait_for TIMEOUT_S DESCRIPTION COMMAND...: runs COMMAND every 50 ms until it succeeds (returns 0)
# or TIMEOUT_S seconds (e.g. 10 or 0.5) have passed (it is run once more at the deadline). On a timeout prints
# "FAILED: DESCRIPTION: not within TIMEOUT_S s" and the end of every log in $work, and returns 1.
wait_for() {
  local timeout_s=$1 description=$2
  shift 2
  local whole=${timeout_s%.*} fraction=000000 deadline
  [[ $timeout_s == *.* ]] && fraction=${timeout_s#*.}000000
  deadline=$(nudge_test_now_us)
  deadline=$((deadline + 10#${whole:-0} * 1000000 + 10#${fraction:0:6}))
  until "$@"; do
    if [ "$(nudge_test_now_us)" -ge "$deadline" ]; then
      "$@" && return 0
      echo "FAILED: $description: not within $timeout_s s" >&2
      if [ -n "${work:-}" ]; then tail -n 30 "$work"/*.log >&2 2>/dev/null || true; fi
      return 1
    fi
    sleep 0.05
  done
}

# log_has PATTERN FILE [N]: at least N (1) lines of FILE match the grep pattern PATTERN.
log_has() {
  [ "$(grep -c -- "$1" "$2" 2>/dev/null || true)" -ge "${3:-1}" ]
}
