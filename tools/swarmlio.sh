#!/usr/bin/env bash
# One entry point for newcomers and CI.
#
#   tools/swarmlio.sh setup   install the Debian packages (idempotent) and build in Release
#   tools/swarmlio.sh demo    setup, then run the main job on the built-in default scenario
#   tools/swarmlio.sh test    setup, run all tests; then build with ASan+UBSan and run them again
#                             (all but the whole-scenario accuracy flights: SANITIZER_SKIP);
#                             then fuzz the packet decoder and the MCAP reader (clang, libFuzzer) and run the threaded
#                             tests under ThreadSanitizer (docs/network.md, "Fuzzing and sanitizers in CI")
#   tools/swarmlio.sh fuzz    only the fuzz stage;  tools/swarmlio.sh tsan   only the TSan stage
#   tools/swarmlio.sh tidy    only the static checks: clang-tidy (.clang-tidy: function size
#                             and naming) on src/swarm, src/lio, src/window, src/driver, and no function
#                             in src/ over 120 lines
#
# Environment: BUILD_DIR (default build), ASAN_BUILD_DIR (default build-asan),
# FUZZ_BUILD_DIR (default build-fuzz), TSAN_BUILD_DIR (default build-tsan),
# FUZZ_RUNS (default 1000000), FUZZ_MAX_TIME_S (default 300), MCAP_FUZZ_MAX_TIME_S (default 20),
# JOBS (default 2), CI=true turns warnings into errors.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
ASAN_BUILD_DIR="${ASAN_BUILD_DIR:-$ROOT/build-asan}"
FUZZ_BUILD_DIR="${FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
TSAN_BUILD_DIR="${TSAN_BUILD_DIR:-$ROOT/build-tsan}"
FUZZ_RUNS="${FUZZ_RUNS:-1000000}"
FUZZ_MAX_TIME_S="${FUZZ_MAX_TIME_S:-300}"
MCAP_FUZZ_MAX_TIME_S="${MCAP_FUZZ_MAX_TIME_S:-20}"
JOBS="${JOBS:-2}"
WERROR=OFF
if [[ "${CI:-}" == "true" ]]; then WERROR=ON; fi

PACKAGES=(
  cmake g++ make ccache pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev libgflags-dev libgoogle-glog-dev
  libgtest-dev libgmock-dev libbenchmark-dev libyaml-cpp-dev libpcl-dev
  librosbag-storage-dev libsensor-msgs-dev libgeometry-msgs-dev
  libroscpp-dev libtopic-tools-dev libnav-msgs-dev libvisualization-msgs-dev libtf2-msgs-dev
  python3-rosmaster
  libnanoflann-dev robin-map-dev libtbb-dev
  libcairo2-dev
  libsodium-dev
  libzstd-dev liblz4-dev zlib1g-dev libisal-dev libsqlite3-dev
  parallel
)
# The sweep test starts a single-node Slurm cluster (tests/sweep/slurm_test.sh;
# about 8 MB installed, no service is started by the install).
case "${1:-}" in
  test) PACKAGES+=(munge slurmctld slurmd slurm-client) ;;
esac
# The fuzz stage needs clang and its libFuzzer/sanitizer runtimes.
case "${1:-}" in
  test|fuzz) PACKAGES+=(clang libclang-rt-14-dev) ;;
esac
case "${1:-}" in
  test|tidy) PACKAGES+=(clang-tidy universal-ctags) ;;
esac

# Each line carries the minutes since the command started, so a CI log shows
# what every stage cost.
log() { printf '\033[1m[swarmlio %3d:%02d]\033[0m %s\n' $((SECONDS / 60)) $((SECONDS % 60)) "$*" >&2; }

# The sanitizer and fuzz builds: -O1 (the level the sanitizers' authors
# recommend), with line tables only (-g1). Sanitizer reports keep function,
# file and line; full debug info (-g) nearly doubled the compile time of the
# heaviest files, and -O2 costs 40-70% more compile time than -O1 under
# ASan+UBSan (esikf_update.cc 42 s -> 25 s, drone_estimator.cc 21 s -> 14 s,
# odometry.cc 25 s -> 15 s on 2 cores). CI has 90 minutes for everything.
# The libraries and tools of these builds are unity builds (CMAKE_UNITY_BUILD:
# a target's .cc files compiled in batches of 8, so the Eigen and Ceres
# headers and their template instances are compiled once per batch instead of
# once per file); test executables keep one translation unit per file
# (tests/CMakeLists.txt). The Release build, which makes the figures, does not.
SANITIZER_BUILD_TYPE=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
                      -DCMAKE_UNITY_BUILD=ON)

# The tests that fly whole simulated scenarios for their accuracy figures
# (30-60 s each in Release, 4-5 times that under ASan) run in the Release
# stage only. The sanitizer stage runs every other test, among them three
# whole flights that go through every module: the swarm replay
# (SwarmReplayTest.SameSeedGivesIdenticalResultsAndTraffic), the live swarm
# over UDP with its offline re-run (LiveSwarmTest), and the odometry's short
# indoor flight (OdometryEndToEnd.TracksAShortIndoorFlight).
# Also left to the Release stage: second flights over paths that a kept
# flight already runs under the sanitizers (35-85 s each under ASan): the
# broadcast budget's overdue entry and byte budget (the component's flight
# stays in with DroneEstimator.IdentifiesATeammate...), the window of one (the
# window of five stays), the replay's dropped-scans list (the same-seed replay
# stays), two of the three restart re-identifications, the spinning foreign
# bag (the sign-flipped one stays), the same flight from MCAP (the MCAP reader
# and writer stay under the sanitizers in McapReaderTest and Rosbag2Test), and
# the simulator's same-seed byte checks of the airframes and of MCAP output (a
# minute of simulation twice each; the default and realistic ones stay), the
# live push source fed in stamp order (the IMU-first ordering of the same
# flight stays), and the teammate added through an identified teammate (the
# graph-derived re-identification stays). The sweep test's single-node Slurm
# cluster (sweep.slurm_single_node, a stub run command; no estimator code)
# runs in the Release stage only.
SANITIZER_SKIP='^((InFlightStartTest|WindowSwarmTest|SwarmEndToEndTest|SwarmClockTest)\.[A-Za-z]+|ClockSyncSimulation\.SymmetricJitterNeedsManyExchanges|OdometryEndToEnd\.ConsistentOnTheRealisticSimulatorOnAHeldOutSeed|TeammateEndToEnd\.Uav2IdentifiesBothTeammatesInIndoor3uavOnEstimatedPoses|SwarmReplayTest\.SingleAgentAblationFusesNothingButKeepsMessaging|DroneEstimator\.(AddsATeammateThroughAnIdentifiedTeammate|AnEntryOverdueOnASaturatedBudgetGoesOutLikeANewOne|KeepsItsBroadcastWithinTheByteBudget|WithoutGraphThroughDerivedARestartedTeammateStaysUnknown|ReidentifiesARestartedTeammateThroughTheInverseOfADerivedEntry)|WindowOdometry\.WindowOfOneReproducesTheFilter|SwarmReplayTest\.LeavesOutTheListedScans|ForeignBagTest\.(SpinningCloudWithoutPointTimeTracksLikeTheOriginal|SameFlightFromMcapGivesTheSameTrajectory)|sim\.same_seed_gives_identical_bytes_(airframes|mcap)|sweep\.slurm_single_node|BothOrderings/PushSourceOrdering\.LiveDroneFedByPushesReproducesTheOfflineReplay/Stamp  .*)$'

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
  configure_and_build "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
}

# configure_and_build_targets DIR "TARGET..." [extra cmake args...]: only those
# targets and their dependencies.
configure_and_build_targets() {
  local dir="$1" targets="$2"; shift 2
  local launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S "$ROOT" -B "$dir" -DSWARMLIO_WERROR="$WERROR" "${launcher[@]}" "$@" >/dev/null
  log "building $targets in $dir"
  # shellcheck disable=SC2086  # a list of target names
  cmake --build "$dir" -j"$JOBS" --target $targets
}

# The packet decoder under libFuzzer + ASan + UBSan: FUZZ_RUNS inputs from a
# fresh corpus grown from generated seeds. A crash, a sanitizer report, a
# timeout or fewer than FUZZ_RUNS executions within FUZZ_MAX_TIME_S fails.
fuzz_stage() {
  log "fuzz stage: packet decoder, clang -fsanitize=fuzzer,address,undefined"
  CC=clang CXX=clang++ configure_and_build_targets "$FUZZ_BUILD_DIR" swarmlio_packet_decoder_fuzz \
    "${SANITIZER_BUILD_TYPE[@]}" -DSWARMLIO_FUZZ=ON -DBUILD_TESTING=OFF \
    -DSWARMLIO_BUILD_BENCHMARKS=OFF
  local bin="$FUZZ_BUILD_DIR/tools/fuzz/swarmlio_packet_decoder_fuzz"
  local work="$FUZZ_BUILD_DIR/fuzz-run"
  rm -rf "$work"
  mkdir -p "$work/seeds" "$work/corpus" "$work/artifacts"
  "$bin" --write_seeds="$work/seeds"
  log "fuzzing: $FUZZ_RUNS runs (cap ${FUZZ_MAX_TIME_S} s), log in $work/fuzz.log"
  local rc=0 start=$SECONDS
  "$bin" -runs="$FUZZ_RUNS" -max_total_time="$FUZZ_MAX_TIME_S" -timeout=10 -max_len=1300 \
    -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" "$work/seeds" \
    >"$work/fuzz.log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 60 "$work/fuzz.log" >&2
    log "fuzz stage FAILED (exit $rc); reproduce with: $bin $work/artifacts/<file>"
    return 1
  fi
  local executed
  executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/fuzz.log")
  log "fuzz: ${executed:-?} executions in $((SECONDS - start)) s," \
    "$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/fuzz.log") exec/s, 0 crashes"
  if [[ -z "$executed" || "$executed" -lt "$FUZZ_RUNS" ]]; then
    log "fuzz stage FAILED: only ${executed:-0} of $FUZZ_RUNS executions within ${FUZZ_MAX_TIME_S} s"
    return 1
  fi
  mcap_fuzz
}

# The MCAP reader (BagReader, ReadBagInfo; file-based, ~500 inputs/s) for
# MCAP_FUZZ_MAX_TIME_S from seeds the target writes. A crash, a sanitizer
# report or a timeout fails.
mcap_fuzz() {
  CC=clang CXX=clang++ configure_and_build_targets "$FUZZ_BUILD_DIR" swarmlio_mcap_reader_fuzz \
    "${SANITIZER_BUILD_TYPE[@]}" -DSWARMLIO_FUZZ=ON -DBUILD_TESTING=OFF \
    -DSWARMLIO_BUILD_BENCHMARKS=OFF
  local bin="$FUZZ_BUILD_DIR/tools/fuzz/swarmlio_mcap_reader_fuzz"
  local work="$FUZZ_BUILD_DIR/mcap-fuzz-run"
  rm -rf "$work"
  mkdir -p "$work/seeds" "$work/corpus" "$work/artifacts"
  "$bin" --write_seeds="$work/seeds"
  log "fuzzing the MCAP reader for ${MCAP_FUZZ_MAX_TIME_S} s, log in $work/fuzz.log"
  local rc=0
  "$bin" -max_total_time="$MCAP_FUZZ_MAX_TIME_S" -timeout=10 -max_len=20000 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts/" "$work/corpus" "$work/seeds" >"$work/fuzz.log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]]; then
    tail -n 60 "$work/fuzz.log" >&2
    log "MCAP fuzz FAILED (exit $rc); reproduce with: $bin $work/artifacts/<file>"
    return 1
  fi
  log "MCAP fuzz: $(sed -n 's/^stat::number_of_executed_units: *//p' "$work/fuzz.log") executions," \
    "0 crashes"
}

# ThreadSanitizer on the tests that run more than one thread: the simulator's
# per-drone workers (Simulator::Run with num_threads = 2) in-process and
# through the swarmlio_sim tool, and the live process (swarmlio_live: input,
# estimator and network threads per drone, three drones over UDP in one test;
# docs/online.md) with its queue, push-input and recording tests. No other
# library code starts threads.
TSAN_TESTS='^(Scenario\.ParsesAndSimulatesDeterministically|Imperfections\.RealisticRunLosesAndJittersImuSamples|sim\.same_seed_gives_identical_bytes(_realistic)?|(BoundedQueue|PacketLog|RecordedPacketTransport|ImuRateOdometry|PushSource|LiveSwarmTest|LiveDropTest|LiveDrone)\.[A-Za-z]+)$'
tsan_stage() {
  log "thread sanitizer stage: -fsanitize=thread on the threaded simulator and live tests"
  # libpcl_io loads Debian's uninstrumented libOpenNI2, whose static destructors
  # unlock destroyed mutexes at exit (not our code). The options also apply to
  # the build, which runs the test binary to list its tests.
  mkdir -p "$TSAN_BUILD_DIR"
  printf 'mutex:libOpenNI2.so\n' >"$TSAN_BUILD_DIR/tsan.supp"
  local -x TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$TSAN_BUILD_DIR/tsan.supp"
  configure_and_build_targets "$TSAN_BUILD_DIR" "swarmlio_sim_tests swarmlio_sim_tool swarmlio_bag_info swarmlio_live_tests" \
    "${SANITIZER_BUILD_TYPE[@]}" -DSWARMLIO_BUILD_BENCHMARKS=OFF \
    -DCMAKE_CXX_FLAGS=-fsanitize=thread -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread \
    -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread
  log "running the threaded tests in $TSAN_BUILD_DIR"
  ctest --test-dir "$TSAN_BUILD_DIR" -j"$JOBS" --output-on-failure --timeout 600 \
    -R "$TSAN_TESTS" --no-tests=error
}

# Static checks on the Release build's compile commands: clang-tidy with the
# repository's .clang-tidy (functions <= 80 lines, naming) on the component
# and estimator folders, and no function anywhere in src/ over 120 lines
# (Universal Ctags gives each function's extent).
TIDY_DIRS=(src/swarm src/lio src/window src/driver)
tidy_stage() {
  log "static checks: clang-tidy on ${TIDY_DIRS[*]}; function size in src/"
  local files
  files=$(cd "$ROOT" && git ls-files "${TIDY_DIRS[@]/%//*.cc}")
  (cd "$ROOT" && printf '%s\n' $files | xargs -P"$JOBS" -n 4 clang-tidy -p "$BUILD_DIR" --quiet) \
    2> >(grep -v -E '^[0-9]+ warnings? generated|^\*\* WARNING \*\*' >&2)
  local long
  long=$(cd "$ROOT" && ctags-universal -R --languages=C++ --kinds-C++=f --fields=+ne -x \
           --_xformat='%{end} %{line} %{input}:%{name}' src |
         awk '$1 ~ /^[0-9]+$/ && $2 ~ /^[0-9]+$/ && $1 - $2 + 1 > 120 {print $1 - $2 + 1 " lines " $3}')
  if [[ -n "$long" ]]; then
    log "functions over 120 lines in src/:"
    echo "$long" >&2
    return 1
  fi
  log "static checks passed"
}

# run_tests DIR [ctest args...]
run_tests() {
  local dir="$1"; shift
  log "running tests in $dir"
  ctest --test-dir "$dir" -j"$JOBS" --output-on-failure --timeout 600 "$@"
  log "tests in $dir passed"
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
    tidy_stage
    run_tests "$BUILD_DIR"
    log "sanitizer stage: -fsanitize=address,undefined"
    configure_and_build "$ASAN_BUILD_DIR" "${SANITIZER_BUILD_TYPE[@]}" \
      -DSWARMLIO_SANITIZE=ON -DSWARMLIO_BUILD_BENCHMARKS=OFF
    ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" \
      UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" run_tests "$ASAN_BUILD_DIR" -E "$SANITIZER_SKIP"
    fuzz_stage
    tsan_stage
    log "all stages passed"
    ;;
  fuzz)
    install_packages
    fuzz_stage
    ;;
  tsan)
    install_packages
    tsan_stage
    ;;
  tidy)
    setup
    tidy_stage
    ;;
  *)
    echo "usage: tools/swarmlio.sh {setup|demo|test|fuzz|tsan|tidy}" >&2
    exit 2
    ;;
esac
