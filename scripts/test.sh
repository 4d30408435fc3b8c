#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, service, integration).
# Extra arguments go to ctest, e.g. scripts/test.sh -L unit   or   scripts/test.sh -R symmetry
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
job_start=$SECONDS
nudge_install_packages
nudge_build
cd "$NUDGE_BUILD_DIR"
status=0
ctest --output-on-failure -j "$NUDGE_JOBS" --timeout 600 "$@" || status=$?
nudge_summary test.sh "$job_start" "$([ $status = 0 ] && echo "built, every test passed" || echo "ctest exit $status: see the failures above")"
exit $status
