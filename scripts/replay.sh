#!/usr/bin/env bash
# Replays an LCM log onto the bus: scripts/replay.sh LOG [lcm-logplayer options, e.g. -s 0.5]
# To feed one service as fast as it can read instead, give it the log directly:
#   build/bin/nudge-symmetry --lcm-in 'file://LOG?speed=0' --lcm-out 'file://out.lcmlog?mode=w'
set -euo pipefail
log=${1:?usage: scripts/replay.sh LOG [lcm-logplayer options]}
shift
[ -f "$log" ] || { echo "replay.sh: no such log: $log" >&2; exit 1; }
exec lcm-logplayer "$@" "$log"
