#!/usr/bin/env bash
# The lossy-network acceptance run (docs/notes/results_history.md "Lossy network"): replays
# scenarios already simulated by tools/run_scenarios.sh (their file seed, in
# results/scenarios/<name>/seed<S>/) through a network
# with 20 % loss and 100 ms latency (10 ms jitter) for network seeds 1-3 and
# compares every drone's APE with the lossless swarm run.
#
#   tools/run_lossy_network.sh                      # wall_degenerate corridor indoor_3uav
#   tools/run_lossy_network.sh wall_degenerate      # only the named ones
#   SEEDS="$(seq -s ' ' 1 16)" SCENARIO_SEEDS="2 102 202" OUT=results/ideal \
#     tools/run_lossy_network.sh wall_degenerate    # held-out scenario seeds too
#
#   tools/run_lossy_network.sh --from_sweep OUT     # only the table, from a finished
#                                                   # `tools/sweep.sh local configs/sweeps/lossy_network.yaml OUT`
#
# SCENARIO_SEEDS (default: the file's seed) lists scenario seeds; one without a run in
# OUT/<name>/seed<S>/ is simulated here (swarmlio_sim --seed S --imperfections
# $IMPERFECTIONS, default realistic) and replayed lossless first.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
OUT="${OUT:-$ROOT/results/scenarios}"
REPLAY="$BUILD_DIR/tools/replay/swarmlio_replay"
SIM="$BUILD_DIR/tools/sim/swarmlio_sim"
IMPERFECTIONS="${IMPERFECTIONS:-realistic}"
SEEDS="${SEEDS:-1 2 3}"
LOSS="${LOSS:-0.2}"
LATENCY_S="${LATENCY_S:-0.1}"
[[ -x "$REPLAY" ]] || { echo "missing $REPLAY: run tools/swarmlio.sh setup first" >&2; exit 1; }
if [[ $# -gt 0 ]]; then scenarios=("$@"); else scenarios=(wall_degenerate corridor indoor_3uav); fi

ape() {  # ape <metrics.csv> <drone>: the SE(3)-aligned APE RMSE [m]
  awk -F, -v d="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "ape_rmse_m") c = i }
                     NR > 1 && $1 == d { printf "%.4f", $c }' "$1"
}

# row <scenario> <scenario seed> <lossless metrics.csv> <lossy metrics.csv>...: one row per drone.
row() {
  local name="$1" scenario_seed="$2" base_csv="$3"; shift 3
  for drone in $(awk -F, 'NR > 1 { print $1 }' "$base_csv"); do
    base=$(ape "$base_csv" "$drone")
    values=() worst=0
    for csv in "$@"; do
      v=$(ape "$csv" "$drone")
      values+=("${v:-n/a}")
      worst=$(awk -v a="$v" -v b="$base" -v w="$worst" 'BEGIN { c = (a - b) / b * 100; print (c > w ? c : w) }')
    done
    joined=$(IFS=/; echo "${values[*]}")
    printf '| %s | %s | %s | %s | %s | %+.0f %% |\n' "$name" "$scenario_seed" "$drone" "$base" \
        "${joined//\// \/ }" "$worst"
  done
}

if [[ "${1:-}" == "--from_sweep" ]]; then
  out="${2:?--from_sweep needs the output folder of the sweep}"
  echo "| scenario | scenario seed | drone | lossless | network seeds ${SEEDS// / \/ } | worst change |"
  echo "|---|---:|---|---:|---|---:|"
  for base_csv in "$out"/runs/lossless/*/seed*/swarm/metrics.csv; do
    seed_dir="$(dirname "$(dirname "$base_csv")")"
    name="$(basename "$(dirname "$seed_dir")")" scenario_seed="$(basename "$seed_dir")"
    lossy=()
    for seed in $SEEDS; do lossy+=("$out/runs/lossy_seed$seed/$name/$scenario_seed/swarm/metrics.csv"); done
    row "$name" "${scenario_seed#seed}" "$base_csv" "${lossy[@]}"
  done
  exit 0
fi

echo "| scenario | scenario seed | drone | lossless | network seeds ${SEEDS// / \/ } | worst change |"
echo "|---|---:|---|---:|---|---:|"
for name in "${scenarios[@]}"; do
  seed0=$(sed -nE '/^scenario:/,/^[a-z]/{s/.*seed: *([0-9]+).*/\1/p}' "$ROOT/configs/scenarios/$name.yaml" | head -n1)
  for scenario_seed in ${SCENARIO_SEEDS:-$seed0}; do
    dir="$OUT/$name/seed$scenario_seed"
    if [[ "$scenario_seed" != "$seed0" && ! -f "$dir/swarm/metrics.csv" ]]; then
      mkdir -p "$dir"
      "$SIM" --scenario "$ROOT/configs/scenarios/$name.yaml" --seed "$scenario_seed" \
          --imperfections "$IMPERFECTIONS" --output_dir "$dir/sim" > "$dir.sim.log" 2>&1 ||
        { echo "simulation failed: $dir.sim.log" >&2; exit 1; }
      "$REPLAY" --manifest "$dir/sim/swarm.yaml" --output_dir "$dir/swarm" --save_maps=false \
          > "$dir/swarm.log" 2>&1 || { echo "replay failed: $dir/swarm.log" >&2; exit 1; }
    fi
    [[ -f "$dir/sim/swarm.yaml" && -f "$dir/swarm/metrics.csv" ]] ||
      { echo "missing $dir/sim or $dir/swarm (or run the same grid as a sweep: tools/sweep.sh local configs/sweeps/lossy_network.yaml)" >&2; exit 1; }
    for seed in $SEEDS; do
      cfg="$dir/lossy_seed$seed.yaml"
      printf 'network:\n  seed: %s\n  default_link: {latency_mean_s: %s, jitter_std_s: 0.01, loss_probability: %s}\n' \
        "$seed" "$LATENCY_S" "$LOSS" > "$cfg"
      "$REPLAY" --manifest "$dir/sim/swarm.yaml" --network_config "$cfg" \
        --output_dir "$dir/lossy_seed$seed" --save_maps=false > "$dir/lossy_seed$seed.log" 2>&1 ||
        echo "replay failed: $dir/lossy_seed$seed.log" >&2
    done
    lossy=()
    for seed in $SEEDS; do lossy+=("$dir/lossy_seed$seed/metrics.csv"); done
    row "$name" "$scenario_seed" "$dir/swarm/metrics.csv" "${lossy[@]}"
  done
done
