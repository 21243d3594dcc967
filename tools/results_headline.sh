#!/usr/bin/env bash
# Prints the headline table of docs/results.md from the runs of
# tools/run_scenarios.sh: one row per scenario, aggregated over its seeds.
#
#   tools/results_headline.sh OUT scenario...   # OUT as in run_scenarios.sh
#
# Reads OUT/<scenario>/seed*/{swarm,single}/{metrics.csv,swarm_pairs.csv,
# network.csv} and OUT/<scenario>/seed*/<scenario>.yaml (for the duration).
# Columns (docs/results.md explains them): ego APE of the worst drone (mean
# over seeds) swarm / single-agent and the worst run; drift per distance of
# the worst drone; position NEES in G over every drone and seed; pairs
# identified and wrong; the latest identification after the excitation start;
# the worst extrinsic error at the end; the worst teammate relative RMSE; the
# share of scans with the teammate in view (>= 10 returns) that fused an
# active observation (all pairs together, and the worst pair); the per-scan
# median time swarm / single-agent; the broadcast bytes per second per drone.
set -euo pipefail

OUT="$1"
shift

# per_drone_worst <column> <csv files...>: "worst-drone mean|max over runs".
per_drone_worst() {
  local column="$1"
  shift
  [[ $# -gt 0 ]] || { echo "n/a|n/a"; return; }
  awk -F, -v col="$column" '
    FNR == 1 { c = 0; for (i = 1; i <= NF; ++i) if ($i == col) c = i; next }
    c > 0 && $c ~ /^[-+0-9.eE]+$/ { s[$1] += $c; n[$1]++; if ($c + 0 > mx) mx = $c + 0 }
    END { w = 0; for (d in s) if (s[d] / n[d] > w) w = s[d] / n[d]; printf "%g|%g", w, mx }' "$@"
}

# range <column> <csv files...>: "min-max" over every drone and run.
range() {
  local column="$1"
  shift
  [[ $# -gt 0 ]] || { echo "n/a"; return; }
  awk -F, -v col="$column" '
    FNR == 1 { c = 0; for (i = 1; i <= NF; ++i) if ($i == col) c = i; next }
    c > 0 && $c ~ /^[-+0-9.eE]+$/ { v = $c + 0; if (!k++ || v < lo) lo = v; if (k == 1 || v > hi) hi = v }
    END { if (k) printf "%.2g-%.2g", lo, hi; else printf "n/a" }' "$@"
}

# mean <column> <csv files...>
mean() {
  local column="$1"
  shift
  [[ $# -gt 0 ]] || { echo "n/a"; return; }
  awk -F, -v col="$column" '
    FNR == 1 { c = 0; for (i = 1; i <= NF; ++i) if ($i == col) c = i; next }
    c > 0 && $c ~ /^[-+0-9.eE]+$/ { s += $c; n++ }
    END { if (n) printf "%.2f", s / n; else printf "n/a" }' "$@"
}

# pairs <swarm_pairs.csv files...>: the teammate columns.
pairs() {
  [[ $# -gt 0 ]] || { echo "n/a | n/a | n/a | n/a | n/a"; return; }
  awk -F, -f "$(dirname "${BASH_SOURCE[0]}")/pairs_summary.awk" "$@" | awk '{
    printf "%d / %d, %d wrong | %.1f | %.1f / %.2f | %.1f | ", $1, $2, $3, $4, 100 * $5, $6,
           100 * $9
    if ($10 >= 0) printf "%.0f (%.0f)", 100 * $10, 100 * $11; else printf "n/a"
  }'
}

# bytes_per_s <duration_s> <network.csv files...>: the largest broadcast rate
# of a drone (bytes sent on its busiest link per second), worst run.
bytes_per_s() {
  local duration="$1"
  shift
  [[ $# -gt 0 ]] || { echo "n/a"; return; }
  awk -F, -v d="$duration" 'FNR > 1 { k = FILENAME "," $1; if ($9 > b[k]) b[k] = $9 }
    END { for (k in b) if (b[k] > m) m = b[k]; printf "%.0f", m / d }' "$@"
}

# cm <metres|n/a>
cm() { [[ "$1" == n/a ]] && echo n/a || awk -v v="$1" 'BEGIN { printf "%.1f", 100 * v }'; }

echo "| scenario (seeds) | ego APE worst drone swarm / single [cm] (worst run) | drift worst drone [%] | NEES in G, every drone and seed | pairs identified | latest identification after excitation [s] | extrinsic end worst [cm / deg] | teammate rel. RMSE worst [cm] | active fused / scans in view [%] (worst pair) | per-scan median swarm / single [ms] | broadcast per drone [B/s] |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for name in "$@"; do
  shopt -s nullglob
  seed_dirs=("$OUT/$name"/seed*)
  shopt -u nullglob
  [[ ${#seed_dirs[@]} -gt 0 ]] || { echo "| $name | (no runs) |||||||||"; continue; }
  seeds=() swarm=() single=() pair_files=() net=()
  for dir in "${seed_dirs[@]}"; do
    seeds+=("${dir##*/seed}")
    [[ -f "$dir/swarm/metrics.csv" ]] && swarm+=("$dir/swarm/metrics.csv")
    [[ -f "$dir/single/metrics.csv" ]] && single+=("$dir/single/metrics.csv")
    [[ -f "$dir/swarm/swarm_pairs.csv" ]] && pair_files+=("$dir/swarm/swarm_pairs.csv")
    [[ -f "$dir/swarm/network.csv" ]] && net+=("$dir/swarm/network.csv")
  done
  duration="$(sed -nE '/^scenario:/,/^[a-z]/{s/.*duration_s: *([0-9.]+).*/\1/p}' \
    "${seed_dirs[0]}/$name.yaml" | head -n1)"
  IFS='|' read -r ape_swarm ape_swarm_max <<< "$(per_drone_worst ape_rmse_m "${swarm[@]}")"
  IFS='|' read -r ape_single ape_single_max <<< "$(per_drone_worst ape_rmse_m "${single[@]}")"
  IFS='|' read -r drift _ <<< "$(per_drone_worst drift_percent "${swarm[@]}")"
  printf '| %s (%s) | %s / %s (%s / %s) | %s | %s | %s | %s / %s | %s |\n' \
    "$name" "$(IFS=,; echo "${seeds[*]}")" \
    "$(cm "$ape_swarm")" "$(cm "$ape_single")" "$(cm "$ape_swarm_max")" "$(cm "$ape_single_max")" \
    "$([[ "$drift" == n/a ]] && echo n/a || awk -v v="$drift" 'BEGIN { printf "%.2f", v }')" \
    "$(range nees_position "${swarm[@]}")" \
    "$(pairs "${pair_files[@]}")" \
    "$(mean time_median_ms "${swarm[@]}")" "$(mean time_median_ms "${single[@]}")" \
    "$(bytes_per_s "${duration:-60}" "${net[@]}")"
done
