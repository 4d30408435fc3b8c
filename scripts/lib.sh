# Shared by the scripts: install what is missing, build incrementally.
# Sourced, not run. Respects NUDGE_BUILD_DIR (default: build) and NUDGE_JOBS (default: 2).

NUDGE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
NUDGE_BUILD_DIR=${NUDGE_BUILD_DIR:-$NUDGE_ROOT/build}
NUDGE_JOBS=${NUDGE_JOBS:-2}

# Debian 12 packages the project builds and runs with.
NUDGE_PACKAGES=(
  build-essential cmake pkg-config
  liblcm-dev liblcm-bin liblcm-java default-jdk-headless libjchart2d-java
  libopencv-dev libopencv-contrib-dev libeigen3-dev libceres-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libmujoco-dev libosmesa6-dev
  iproute2 util-linux procps opencv-doc
  libcpp-httplib-dev nlohmann-json3-dev chromium
  clang-14 libfuzzer-14-dev
  libyaml-cpp-dev
  xvfb x11-apps netpbm libspdlog-dev libcli11-dev
)

nudge_log() { printf '\033[1m[nudge]\033[0m %s\n' "$*" >&2; }

# Installs the packages that are missing; runs apt-get update only when something is.
nudge_install_packages() {
  local missing=()
  for p in "${NUDGE_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  nudge_log "installing: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" != 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# Configures once, then builds what changed. Fails (with the compiler's messages) if the build does.
nudge_build() {
  if [ ! -f "$NUDGE_BUILD_DIR/CMakeCache.txt" ]; then
    cmake -S "$NUDGE_ROOT" -B "$NUDGE_BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
  fi
  nudge_log "building in $NUDGE_BUILD_DIR (the first build takes several minutes)"
  local log start=$SECONDS
  log=$(mktemp)
  if ! cmake --build "$NUDGE_BUILD_DIR" -j "$NUDGE_JOBS" 2>&1 | tee "$log" | nudge_build_progress "$start"; then
    grep -vE '^\[ *[0-9]+%\]' "$log" >&2
    rm -f "$log"
    nudge_log "build failed after $((SECONDS - start)) s"
    return 1
  fi
  grep -E 'warning:|error:' "$log" >&2 || true
  rm -f "$log"
  nudge_log "built in $((SECONDS - start)) s"
}

# "[k/N] item … 34 s left" on stderr for step K of N of a loop started at START ($SECONDS), as
# common/core's nudge::Progress writes it: rewritten in place on a terminal, a line each otherwise
# (a script's steps are long and few: each is worth a line in a log).
nudge_progress() {
  local k=$1 n=$2 start=$3 item=$4 left=""
  if [ "$k" -gt 1 ]; then left=" … $(((SECONDS - start) * (n - k + 1) / (k - 1))) s left"; fi
  if [ -t 2 ]; then printf '\r\033[K[%d/%d] %s%s' "$k" "$n" "$item" "$left" >&2
  else printf '[%d/%d] %s%s\n' "$k" "$n" "$item" "$left" >&2; fi
}

# The one-line summary at the end of a job started at START ($SECONDS), on stderr, as
# nudge::Progress ends its jobs: "JOB: done in 1 m 12 s — SUMMARY".
nudge_summary() {
  local job=$1 start=$2 took=$((SECONDS - $2))
  shift 2
  if [ $took -ge 60 ]; then took="$((took / 60)) m $(printf %02d $((took % 60))) s"; else took="$took s"; fi
  printf '%s: done in %s — %s\n' "$job" "$took" "$*" >&2
}

# A field of a run's summary.json (a number at its top level, the first of that name), or $3.
nudge_summary_field() {
  local value
  value=$(grep -o "\"$2\":[0-9]*" "$1" 2>/dev/null | head -1 | cut -d: -f2)
  echo "${value:-$3}"
}

# Reads cmake --build's output; on a terminal shows its percentage and the time left as one line.
nudge_build_progress() {
  local start=$1 line pct
  while IFS= read -r line; do
    [ -t 2 ] || continue
    [[ $line =~ ^\[\ *([0-9]+)%\] ]] || continue
    pct=${BASH_REMATCH[1]}
    if [ "$pct" -gt 0 ]; then
      printf '\r\033[K[%3d%%] building … %d s left' "$pct" $(((SECONDS - start) * (100 - pct) / pct)) >&2
    fi
  done
  if [ -t 2 ]; then printf '\r\033[K' >&2; fi
}

# LCM asks for recv_buf_size (the scripts: 16 MB) but the kernel caps every socket at
# net.core.rmem_max, which is global: a network namespace can neither raise it nor hide it (the
# sysctl fails there). Below 4 MB a burst of 300 KB images overflows and LCM drops frames
# silently, so say so (the services count the frame_id gaps in their heartbeats).
nudge_check_receive_buffers() {
  local max
  max=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)
  if [ "$max" -lt 4194304 ]; then
    nudge_log "warning: net.core.rmem_max is $max bytes; LCM receive buffers are capped there and images may be" \
      "dropped. Raise it on the host (as root): sysctl -w net.core.rmem_max=16777216"
  fi
}

# Runs "$@" where LCM multicast stays private: inside a new network namespace with only
# loopback when we can make one (root), otherwise on this host with ttl=0.
nudge_in_private_network() {
  nudge_check_receive_buffers
  if [ "$(id -u)" = 0 ] && unshare -n true 2>/dev/null && [ -z "${NUDGE_HOST_NETWORK:-}" ]; then
    unshare -n bash -c '
      ip link set lo up multicast on
      ip route add 224.0.0.0/4 dev lo
      exec "$@"' nudge-private-network "$@"
  else
    "$@"
  fi
}

# The autonomous segmentation loop on a simulated scene, every service its own process over LCM
# (run it inside nudge_in_private_network): world -> camera (sim, stills) -> symmetry ->
# triangulation, the arm on the simulated clock, and the supervisor, which ends the run by itself.
#   nudge_run_loop BIN_DIR SCENE CALIBRATION WORKSPACE OUT_DIR RUN_ID [supervisor flags...]
# The run's files land in OUT_DIR/RUN_ID/ (LCM log, summary.json, attempt_NN/), the services' logs
# in OUT_DIR/RUN_ID/services/. Returns the supervisor's exit code. NUDGE_LOOP_RATE (10 Hz) and
# NUDGE_LOOP_REALTIME (1) set the world's pace, NUDGE_LOOP_TIMEOUT (900 s) bounds the run.
# NUDGE_LOOP_LEARN=1 adds learning by interaction (thesis ch. 7): nudge-learner with its object
# database in NUDGE_OBJECT_DB (default OUT_DIR/RUN_ID/objects: each run starts knowing nothing; name
# one folder to keep what was learned across runs) and the world's one hand carrying the pad and
# the gripper (--tool auto); the supervisor (--learn auto) then recognises, grasps, turns and learns.
# NUDGE_LOOP_TABLE picks the detection (docs/supervisor.md, "Detection in the loop"):
#   "plain" (the default): the thesis' (5 lines per image, 3 surveyed, every left line paired with
#     every right);
#   "verified": the thesis' edges (blur 1, Canny 30/90, Dmin 25, Dmax 250), 80 accumulator peaks,
#     only those that can be upright axes on the calibrated table, verified by local support and
#     mirrored colour, 12 kept, 8 per image surveyed, the arm's base column's outline left out of
#     the edges, stereo-checked candidates and AXES: far fewer phantoms, but on the held-out scenes
#     it segmented fewer objects than "plain";
#   "busy": the busy-table pipeline of docs/clutter.md ("verified" with colour edges, blur 2,
#     Dmin 8, Dmax 90, the accumulator's suppression 3 px and 3 deg, support segments joined across 16 px gaps, no column mask; candidates
#     stereo-checked at 0.2 overlap, both images agreeing along the axis (0.6, waived at 0.85
#     overlap), QT clusters of at least 5 % of the intersects).
# NUDGE_LOOP_COLUMN_MASK (1 for "plain" and "verified", 0 for "busy" by default) leaves a band
# along the arm's base column's outline out of the edges (nudge-symmetry --column-calibration:
# a robot self-filter; docs/supervisor.md, "The column's outline left out by default").
# NUDGE_LOOP_TABLE_TEXTURE (1, the default; 0: off) leaves the table's own texture out of the
# edges (nudge-symmetry --table-texture-calibration: where the two cameras agree through the
# calibrated table plane; docs/clutter.md, "The table's own texture").
# NUDGE_LOOP_REACH (1, the default; 0: off) makes "plain" take 20 peaks and keep the 5 first whose
# support stands on the table within 0.45 m of the arm's base and not within 0.10 m of it
# (nudge-symmetry --reach-calibration, --reach-inner-radius: a wall's or the far table's lines
# cannot be objects the arm reaches, and the arm's own base column, 65 mm in radius, is none);
# the column's line, when its support reaches past 0.10 m, is published without counting among
# the 5 (--reach-column-px 8), as the survey pairs it uncounted.
# "plain" surveys pair only lines within 2 deg of the image of an upright axis
# (nudge-triangulation --candidate-line-tilt 2): objects' lines lean 0-1 deg (a degraded one up
# to 4), lines between two objects 2.5-5 deg; re-chosen on 33 recorded development runs
# (docs/supervisor.md, nudge-exp-survey-line-tilt: 2 and 3 deg keep as many real candidates).
# A survey that leaves nothing to nudge is asked once more at 5 deg before the run ends
# (nudge-supervisor --wide-survey-tilt 5): a label can lean a lone bottle's line past 2 deg.
# The supervisor's survey flags for NUDGE_LOOP_TABLE: nudge_run_loop's, and a replay's of its runs
# (experiments/nudge_segmentation_replay.sh).
# NUDGE_LOOP_SUPERVISOR_FLAGS adds nudge-supervisor flags to the loop's and a replay's (e.g.
# "--candidate-order support" or "--refine-target 0.05": options tried on the development scenes).
nudge_loop_survey_flags() {
  local extra=${NUDGE_LOOP_SUPERVISOR_FLAGS:+ $NUDGE_LOOP_SUPERVISOR_FLAGS}
  case "${NUDGE_LOOP_TABLE:-plain}" in
    verified|busy) echo "--survey-lines 8$extra" ;;
    *) echo "--wide-survey-tilt 5$extra" ;;
  esac
}

# The symmetry service's flags for NUDGE_LOOP_TABLE (a JSON list's items, for launch.json), its
# rig from CALIBRATION: nudge_loop_symmetry_flags CALIBRATION
nudge_loop_symmetry_flags() {
  local calibration=$1 symmetry_flags='"--lines", "5"' column_mask
  # The accumulator's suppression: 4 px and 4 deg for "verified", 3 for "busy" (docs/clutter.md, fifth round).
  local suppression=4
  [ "${NUDGE_LOOP_TABLE:-plain}" = busy ] && suppression=3
  local verified='"--lines", "80", "--suppress-r", "'$suppression'", "--suppress-theta", "'$suppression'", "--verify", "12",
                  "--upright-calibration", "'"$calibration"'"'
  case "${NUDGE_LOOP_TABLE:-plain}" in
    verified)
      symmetry_flags=$verified
      column_mask=${NUDGE_LOOP_COLUMN_MASK:-1} ;;
    busy)
      symmetry_flags="$verified"', "--colour-edges", "--blur", "2", "--dmin", "8", "--dmax", "90", "--support-gap", "16"'
      column_mask=${NUDGE_LOOP_COLUMN_MASK:-0} ;;
    plain)
      if [ "${NUDGE_LOOP_REACH:-1}" = 1 ]; then
        symmetry_flags='"--lines", "20", "--reach-calibration", "'"$calibration"'", "--reach-inner-radius", "0.10", "--reach-keep", "5",
                        "--reach-column-px", "8"'
      fi
      column_mask=${NUDGE_LOOP_COLUMN_MASK:-1} ;;
    *) echo "NUDGE_LOOP_TABLE: verified, plain or busy, not '$NUDGE_LOOP_TABLE'" >&2; return 2 ;;
  esac
  # A band along the arm's base column's outline is left out of the edges (its place from the
  # calibration: nudge-symmetry --column-calibration): a robot self-filter. The column's two
  # silhouette edges otherwise pair with the outlines of the objects before it into lines that
  # outrank theirs (docs/supervisor.md, "The column's outline left out by default").
  [ "$column_mask" = 1 ] && symmetry_flags+=', "--column-calibration", "'"$calibration"'"'
  [ "${NUDGE_LOOP_TABLE_TEXTURE:-1}" = 1 ] && symmetry_flags+=', "--table-texture-calibration", "'"$calibration"'"'
  # NUDGE_LOOP_EXPLORED_MASK=1: the objects each survey names as explored leave the symmetry
  # service's edges (nudge-symmetry --explored-calibration; docs/supervisor.md, "Explored objects
  # left out of the edges").
  [ "${NUDGE_LOOP_EXPLORED_MASK:-0}" = 1 ] && symmetry_flags+=', "--explored-calibration", "'"$calibration"'"'
  echo "$symmetry_flags"
}

# The triangulation service's flags for NUDGE_LOOP_TABLE beyond its calibration and workspace
# (each item preceded by ", ", for launch.json).
nudge_loop_triangulation_flags() {
  case "${NUDGE_LOOP_TABLE:-plain}" in
    verified) echo ', "--stereo-check", "--cluster-min-fraction", "0.03"' ;;
    busy)
      echo ', "--stereo-check", "--min-height-overlap", "0.2", "--stereo-appearance", "0.6",
                             "--appearance-waived-at-overlap", "0.85", "--cluster-min-fraction", "0.05"' ;;
    plain)
      # The arm's base column's lines are paired but do not take one of a survey's lines per
      # image (--candidate-column-lines uncounted; docs/supervisor.md, "The column's line").
      # A survey's place needs 0.05 of its intersects, not the thesis' 1/9: chosen on the development
      # runs' replays (docs/supervisor.md, "Weaker clusters": 26 of 34 objects a candidate against
      # 24, none lost). NUDGE_LOOP_CLUSTER_MIN_FRACTION=F sets another.
      echo ', "--candidate-line-tilt", "2", "--candidate-column-lines", "uncounted", "--cluster-min-fraction", "'"${NUDGE_LOOP_CLUSTER_MIN_FRACTION:-0.05}"'"' ;;
    *) echo "NUDGE_LOOP_TABLE: verified, plain or busy, not '$NUDGE_LOOP_TABLE'" >&2; return 2 ;;
  esac
}

# nudge_run_loop runs in a child shell (nudge_in_private_network bash -c ...): it and every
# function it calls must be exported into it. Call this, not `export -f nudge_run_loop` (a helper
# left out is "command not found" in the child, and the loop ran without its survey flags).
nudge_export_loop() {
  export -f nudge_run_loop nudge_loop_survey_flags nudge_loop_symmetry_flags nudge_loop_triangulation_flags
}

nudge_run_loop() {
  local bin=$1 scene=$2 calibration=$3 workspace=$4 out=$5 run=$6
  shift 6
  local url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216"
  local logs="$out/$run/services"
  mkdir -p "$logs"
  local pids=()
  # The services run under nudge-launch (docs/operator.md): a log each in $logs, restarted with
  # back-off if one crashes, all stopped together (SIGINT, then SIGKILL), their status on
  # PROCESS_STATUS. NUDGE_VIEWER=PORT adds the operator's page on http://127.0.0.1:PORT/ (reachable
  # from this host's browser with NUDGE_HOST_NETWORK=1).
  local learner= tool=pad
  if [ "${NUDGE_LOOP_LEARN:-0}" = 1 ]; then
    learner=",
    {\"name\": \"learner\", \"command\": [\"$bin/nudge-learner\", \"--db\", \"${NUDGE_OBJECT_DB:-$out/$run/objects}\"]}"
    tool=auto
  fi
  # NUDGE_LOOP_ARM_WATCHDOG=S: the arm stops when the supervisor's heartbeat is missing S seconds
  # (nudge-arm --supervisor-timeout; a loaded, shared machine may starve the supervisor that long).
  local arm_watchdog=
  [ -n "${NUDGE_LOOP_ARM_WATCHDOG:-}" ] && arm_watchdog=", \"--supervisor-timeout\", \"$NUDGE_LOOP_ARM_WATCHDOG\""
  local symmetry_flags triangulation_flags
  symmetry_flags=$(nudge_loop_symmetry_flags "$calibration") || return 2
  triangulation_flags=$(nudge_loop_triangulation_flags) || return 2
  local survey survey_text
  survey_text=$(nudge_loop_survey_flags) || { echo "nudge_run_loop: no survey flags (a helper of lib.sh not exported to this shell?)" >&2; return 2; }
  read -r -a survey <<<"$survey_text"

  local viewer=
  [ -n "${NUDGE_VIEWER:-}" ] && viewer=",
    {\"name\": \"viewer\", \"command\": [\"$bin/nudge-viewer\", \"--port\", \"$NUDGE_VIEWER\", \"--calibration\", \"$calibration\"]}"
  cat >"$logs/launch.json" <<EOF
{"lcm_url": "$url", "log_dir": "$logs", "backoff": {"initial_s": 1, "max_s": 10},
 "processes": [
    {"name": "symmetry", "command": ["$bin/nudge-symmetry", $symmetry_flags, "--theta-min", "-25", "--theta-max", "25",
                                     "--once-per-row", "--mirror-tolerance", "15"]},
    {"name": "camera", "command": ["$bin/nudge-camera", "--source", "sim", "--scene", "$scene", "--snapshots",
                                   "--snapshot-format", "png"]},
    {"name": "triangulation", "command": ["$bin/nudge-triangulation", "--calibration", "$calibration",
                                          "--workspace", "$workspace"$triangulation_flags]},
    {"name": "arm", "command": ["$bin/nudge-arm", "--backend", "sim", "--clock", "sim", "--workspace", "$workspace"$arm_watchdog]}$learner$viewer
 ]}
EOF
  "$bin/nudge-launch" "$logs/launch.json" 2>"$logs/launch.log" & pids+=($!)
  # Every subscriber listens before the world's first state (the camera builds its scene first).
  for _ in $(seq 300); do
    [ "$(grep -l "started:" "$logs"/{symmetry,camera,triangulation,arm}.log 2>/dev/null | wc -l)" -eq 4 ] && break
    sleep 0.1
  done
  "$bin/nudge-world" --lcm-url "$url" --scene "$scene" --workspace "$workspace" --realtime-factor "${NUDGE_LOOP_REALTIME:-1}" \
    --rate "${NUDGE_LOOP_RATE:-10}" --tool "$tool" 2>"$logs/world.log" & pids+=($!)
  local status=0
  timeout -s INT "${NUDGE_LOOP_TIMEOUT:-900}" "$bin/nudge-supervisor" --lcm-url "$url" --calibration "$calibration" \
    --workspace "$workspace" --out "$out" --run-id "$run" "${survey[@]}" "$@" || status=$?
  kill -INT "${pids[@]}" 2>/dev/null || true
  wait "${pids[@]}" 2>/dev/null || true
  return $status
}
