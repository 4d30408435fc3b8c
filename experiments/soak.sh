#!/usr/bin/env bash
# The soak (issue 12, "Load"; docs/reliability.md "Soak"): the simulated world rendered by the
# camera at 25 Hz stereo -> symmetry -> tracker -> triangulation, each its own process over UDP
# multicast in a private network namespace, for N minutes, with nudge-exp-soak recording per
# stage latency, the frames each stage never answered, and every process's RSS and CPU.
#
# usage: experiments/soak.sh [--minutes M | --seconds S] [--slowest] [--queue N] [--out DIR]
#   --minutes M   length of the run (default 10)
#   --slowest     the services at their most expensive settings: symmetry with contours, peak
#                 verification and colour edges, three trackers per camera that track noise
#   --queue N     every service's --queue (messages held per subscription; default: the services')
#   --out DIR     where the run's files go (default out/soak/<label>): run.json (the recorder's),
#                 rss.csv, the services' logs
#   --label NAME  the run's name (default normal or slowest, with -qN)
#   --warmup S    latencies and RSS growth count from S seconds on (default 30, at most half the run)
# Needs root (a private network namespace). Run it with nice on a shared machine.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${NUDGE_BIN:-$here/build/bin}
seconds=600 slowest=0 queue= out= label= warmup=30
while [ $# -gt 0 ]; do
  case $1 in
    --minutes) seconds=$(awk -v m="$2" 'BEGIN { printf "%d", m * 60 }'); shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --slowest) slowest=1; shift ;;
    --queue) queue=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --label) label=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    *) echo "soak.sh: unknown argument '$1' (see the usage at the top of $0)" >&2; exit 2 ;;
  esac
done
[ "$seconds" -gt 0 ] 2>/dev/null || { echo "soak.sh: the run must last at least a second, not '$seconds'" >&2; exit 2; }
[ $((2 * warmup)) -le "$seconds" ] 2>/dev/null || warmup=$((seconds / 2))
[ -z "$label" ] && label=$([ $slowest = 1 ] && echo slowest || echo normal)${queue:+-q$queue}
out=${out:-$here/out/soak/$label}
for b in nudge-world nudge-camera nudge-symmetry nudge-tracker nudge-triangulation nudge-exp-soak; do
  [ -x "$bin/$b" ] || { echo "soak.sh: $bin/$b is not built (cmake --build build --target $b)" >&2; exit 2; }
done
if [ "$(id -u)" != 0 ] || ! unshare -n true 2>/dev/null; then
  echo "soak.sh: needs root and unshare -n for a private network namespace" >&2
  exit 77
fi
mkdir -p "$out"
rm -f "$out/run.json" "$out/rss.csv"
echo "soak: $label, $seconds s, files in $out" >&2

unshare -n bash -s "$bin" "$here" "$out" "$seconds" "$slowest" "$queue" "$label" "$warmup" <<'INNER'
set -euo pipefail
bin=$1; here=$2; out=$3; seconds=$4; slowest=$5; queue=$6; label=$7; warmup=$8
source "$here/scripts/lib.sh"  # nudge_progress
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
scene=$here/common/sim/scenes/three_objects.yaml
common=(--lcm-url "$url" ${queue:+--queue "$queue"})
pids=()
names=()
cleanup() { kill -INT "${pids[@]}" 2>/dev/null || true; wait 2>/dev/null || true; }
trap cleanup EXIT
start() {  # start NAME COMMAND...: in the background, its log in $out/NAME.log
  local name=$1; shift
  "$@" 2>"$out/$name.log" &
  pids+=($!); names+=("$name=$!")
}

sym_flags=(--lines 5 --theta-min -25 --theta-max 25 --once-per-row --mirror-tolerance 15)
trackers=1 tracker_flags=()
if [ "$slowest" = 1 ]; then
  # The costliest settings a user may pick: contours of the top 3 lines, peak verification,
  # colour edges, no extension that prunes votes; trackers that take pixel noise for motion.
  sym_flags=(--lines 5 --theta-min -25 --theta-max 25 --contours 3 --verify 3 --colour-edges)
  trackers=3 tracker_flags=(--motion-threshold 1.05 --start-min-blocks 1)
fi
start symmetry "$bin/nudge-symmetry" "${common[@]}" "${sym_flags[@]}"
for k in $(seq "$trackers"); do
  suffix=$([ "$k" = 1 ] && echo "" || echo "_$k")
  start "tracker$suffix" "$bin/nudge-tracker" "${common[@]}" --instance "tracker$suffix" \
    --outputs "TRACK_LEFT$suffix,TRACK_RIGHT$suffix" "${tracker_flags[@]}"
done
start triangulation "$bin/nudge-triangulation" "${common[@]}" --calibration "$here/config/calibration_sim.yaml" \
  --workspace "$here/config/workspace.yaml"
start camera "$bin/nudge-camera" "${common[@]}" --source sim --scene "$scene"
# Every service listens before the first state (the camera builds its world first), at most 60 s.
for _ in $(seq 600); do
  [ "$(grep -l "started:" "$out"/*.log 2>/dev/null | wc -l)" -ge "${#pids[@]}" ] && break
  sleep 0.1
done
start world "$bin/nudge-world" "${common[@]}" --scene "$scene" --realtime-factor 1 --rate 25
sleep 1
pid_list=$(IFS=,; echo "${names[*]}")
"$bin/nudge-exp-soak" record --lcm-url "$url" --seconds "$seconds" --warmup "$warmup" --pids "$pid_list" --label "$label" \
  --out "$out/run.json" --csv "$out/rss.csv" 2>"$out/recorder.log" &
recorder=$!
# How far the recording is, every 30 s (its log is a file: the recorder draws no status there).
steps=$(((seconds + 29) / 30)) step=0 recording_start=$SECONDS
while kill -0 "$recorder" 2>/dev/null; do
  step=$((step + 1))
  [ "$step" -le "$steps" ] && nudge_progress "$step" "$steps" "$recording_start" "recording, $((SECONDS - recording_start)) s of $seconds"
  timeout 30 tail --pid="$recorder" -f /dev/null || true
done
[ -t 2 ] && printf '\r\033[K' >&2
wait "$recorder"
INNER
echo "soak: done in $SECONDS s — $label, $(tail -1 "$out/recorder.log" | sed 's/^.* — //'); wrote $out/run.json" >&2
