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
  local log
  log=$(mktemp)
  if ! cmake --build "$NUDGE_BUILD_DIR" -j "$NUDGE_JOBS" >"$log" 2>&1; then
    grep -vE '^\[ *[0-9]+%\]' "$log" >&2
    rm -f "$log"
    nudge_log "build failed"
    return 1
  fi
  grep -E 'warning:|error:' "$log" >&2 || true
  rm -f "$log"
}

# Runs "$@" where LCM multicast stays private: inside a new network namespace with only
# loopback when we can make one (root), otherwise on this host with ttl=0.
nudge_in_private_network() {
  if [ "$(id -u)" = 0 ] && unshare -n true 2>/dev/null && [ -z "${NUDGE_HOST_NETWORK:-}" ]; then
    unshare -n bash -c '
      ip link set lo up multicast on
      ip route add 224.0.0.0/4 dev lo
      sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216 2>/dev/null || true
      exec "$@"' nudge-private-network "$@"
  else
    "$@"
  fi
}
