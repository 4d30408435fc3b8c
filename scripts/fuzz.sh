#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang in build-fuzz/ (-DNUDGE_FUZZ=ON: ASan +
# UBSan + coverage) and runs each for a bounded time, starting from the committed seed corpus.
# An input that crashes is written to tests/fuzz/crashes/TARGET/ (commit it once fixed:
# fuzz_replay_test replays it in every build). Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
# Environment: NUDGE_FUZZ_BUILD_DIR (build-fuzz).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
seconds=${1:-20}
shift || true
build=${NUDGE_FUZZ_BUILD_DIR:-$NUDGE_ROOT/build-fuzz}
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang-14 CXX=clang++-14 cmake -S "$NUDGE_ROOT" -B "$build" -DCMAKE_BUILD_TYPE=Release -DNUDGE_FUZZ=ON \
    -DNUDGE_BUILD_BENCHMARKS=OFF >/dev/null
fi
nudge_log "building the fuzz targets in $build"
cmake --build "$build" -j "$NUDGE_JOBS" --target fuzz_all >/dev/null
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for program in "$build"/bin/fuzz_*; do targets+=("${program##*/fuzz_}"); done
fi
failed=0 k=0 loop_start=$SECONDS
for target in "${targets[@]}"; do
  k=$((k + 1))
  nudge_progress "$k" "${#targets[@]}" "$loop_start" "fuzz_$target, $seconds s"
  [ -t 2 ] && printf '\r\033[K' >&2  # the target's result line follows
  corpus=$(mktemp -d)  # new inputs stay out of the committed seeds
  crashes="$NUDGE_ROOT/tests/fuzz/crashes/$target"
  mkdir -p "$crashes"
  log="$build/fuzz_$target.log"
  # NUDGE_FUZZ_SEED (CI: 1) makes a run repeatable: the same inputs in the same order, so a red CI
  # is a crash anyone can reproduce, not a roll of the dice (explore with the default: a new seed).
  if "$build/bin/fuzz_$target" -max_total_time="$seconds" ${NUDGE_FUZZ_SEED:+-seed=$NUDGE_FUZZ_SEED} -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$crashes/" "$corpus" "$NUDGE_ROOT/tests/fuzz/corpus/$target" >"$log" 2>&1; then
    nudge_log "fuzz_$target: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$') inputs in ${seconds} s, no crash"
  else
    nudge_log "fuzz_$target FOUND A CRASH: see $log; the input is in $crashes/"
    grep -m5 -E "ERROR|SUMMARY|runtime error" "$log" >&2 || true
    failed=1
  fi
  rm -rf "$corpus"
done
nudge_summary fuzz.sh 0 "${#targets[@]} target(s) for $seconds s each, $([ $failed = 0 ] && echo "no crash" || echo "CRASHES found (see above)")"
exit $failed
