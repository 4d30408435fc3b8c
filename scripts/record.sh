#!/usr/bin/env bash
# Records all LCM traffic to a log: scripts/record.sh [out/NAME.lcmlog] [lcm-logger options]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
mkdir -p "$NUDGE_ROOT/out"
log=${1:-$NUDGE_ROOT/out/record-$(date +%Y%m%d-%H%M%S).lcmlog}
shift || true
nudge_log "recording to $log (Ctrl-C to stop)"
exec lcm-logger "$@" "$log"
