#!/usr/bin/env bash
# One entry point for newcomers and CI.
#
#   tools/swarmlio.sh setup   install the Debian packages (idempotent) and build in Release
#   tools/swarmlio.sh demo    setup, then run the main job on the built-in default scenario
#   tools/swarmlio.sh test    setup, run all tests; then build with ASan+UBSan and run them again
#
# Environment: BUILD_DIR (default build), ASAN_BUILD_DIR (default build-asan),
# JOBS (default 2), CI=true turns warnings into errors.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
ASAN_BUILD_DIR="${ASAN_BUILD_DIR:-$ROOT/build-asan}"
JOBS="${JOBS:-2}"
WERROR=OFF
if [[ "${CI:-}" == "true" ]]; then WERROR=ON; fi

PACKAGES=(
  cmake g++ make ccache pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev libgflags-dev libgoogle-glog-dev
  libgtest-dev libgmock-dev libbenchmark-dev libyaml-cpp-dev libpcl-dev
  librosbag-storage-dev libsensor-msgs-dev libgeometry-msgs-dev
  libnanoflann-dev robin-map-dev libtbb-dev
  libcairo2-dev
  libsodium-dev
)

log() { printf '\033[1m[swarmlio]\033[0m %s\n' "$*" >&2; }

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    log "all ${#PACKAGES[@]} Debian packages present"
    return
  fi
  log "installing: ${missing[*]}"
  local sudo=()
  if [[ $(id -u) -ne 0 ]]; then sudo=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# configure_and_build DIR [extra cmake args...]
configure_and_build() {
  local dir="$1"; shift
  local launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S "$ROOT" -B "$dir" -DSWARMLIO_WERROR="$WERROR" "${launcher[@]}" "$@" >/dev/null
  log "building $dir"
  cmake --build "$dir" -j"$JOBS"
}

setup() {
  install_packages
  configure_and_build "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release
}

run_tests() {
  local dir="$1"
  log "running tests in $dir"
  ctest --test-dir "$dir" -j"$JOBS" --output-on-failure --timeout 600
}

cmd="${1:-}"
case "$cmd" in
  setup)
    setup
    ;;
  demo)
    # The main job on the built-in default: simulate indoor_3uav (3 drones,
    # 60 s), replay all three logs through the estimators and the simulated
    # network, and print the per-drone metrics table (results in $out).
    setup
    out="${DEMO_OUT:-$ROOT/results/demo}"
    log "simulating configs/scenarios/indoor_3uav.yaml into $out/sim"
    "$BUILD_DIR/tools/sim/swarmlio_sim" --scenario "$ROOT/configs/scenarios/indoor_3uav.yaml" \
      --output_dir "$out/sim"
    log "replaying $out/sim/swarm.yaml into $out"
    "$BUILD_DIR/tools/replay/swarmlio_replay" --manifest "$out/sim/swarm.yaml" \
      --output_dir "$out" "${@:2}"
    ;;
  test)
    setup
    run_tests "$BUILD_DIR"
    log "sanitizer stage: -fsanitize=address,undefined"
    configure_and_build "$ASAN_BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DSWARMLIO_SANITIZE=ON -DSWARMLIO_BUILD_BENCHMARKS=OFF
    ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" \
      UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" run_tests "$ASAN_BUILD_DIR"
    ;;
  *)
    echo "usage: tools/swarmlio.sh {setup|demo|test}" >&2
    exit 2
    ;;
esac
