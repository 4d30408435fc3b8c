#!/usr/bin/env bash
# Replays an LCM log onto the bus with nudge-replay, which nudge-viewer's page pauses, steps and
# speeds up (docs/operator.md):
#   scripts/replay.sh LOG [--speed 0.5] [--paused]        # then: build/bin/nudge-viewer, open :8088
# lcm-logplayer's "-s X" is taken as --speed X. NUDGE_REPLAY_PLAYER=lcm-logplayer plays with
# lcm-logplayer instead (no pause or step).
# To feed one service as fast as it can read instead, give it the log directly:
#   build/bin/nudge-symmetry --lcm-in 'file://LOG?speed=0' --lcm-out 'file://out.lcmlog?mode=w'
set -euo pipefail
log=${1:?usage: scripts/replay.sh LOG [--speed S] [--paused] [nudge-replay options]}
shift
[ -f "$log" ] || { echo "replay.sh: no such log: $log" >&2; exit 1; }
if [ "${NUDGE_REPLAY_PLAYER:-}" = lcm-logplayer ]; then
  exec lcm-logplayer "$@" "$log"
fi
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    -s) args+=(--speed "${2:?-s needs a speed}"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
bin="${NUDGE_BUILD_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/build}/bin"
exec "$bin/nudge-replay" "${args[@]}" "$log"
