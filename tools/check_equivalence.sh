#!/usr/bin/env bash
# Behaviour check for restructurings (issue #28): replays the same simulated
# logs with two builds of swarmlio_replay and compares every output byte for
# byte (trajectories, teammate trajectories, extrinsics, identifications,
# swarm pairs) and the metrics but for the timing columns.
#
#   tools/check_equivalence.sh OLD_BUILD_DIR NEW_BUILD_DIR [OUT]
#
# Scenarios: indoor_3uav, wall_degenerate, corridor (first 45 s) and swarm_40
# (first 25 s), each swarm and single-agent, filter and window K = 5 (swarm_40
# filter only), simulated once with the new build's simulator. Exit 1 on any
# difference. About 30 minutes on 2 cores. With REUSE_OLD=1 the old side's
# outputs already in OUT are kept (one baseline run shared by several checks).
set -euo pipefail
OLD="${1:?old build dir}"
NEW="${2:?new build dir}"
OUT="${3:-/tmp/swarmlio_equivalence}"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mkdir -p "$OUT"
for scn in indoor_3uav wall_degenerate corridor swarm_40; do
  dur=()
  [[ $scn == corridor ]] && dur=(--duration_s=45)
  [[ $scn == swarm_40 ]] && dur=(--duration_s=25)
  sim="$OUT/sim/$scn"
  if [[ ! -f $sim/swarm.yaml ]]; then
    "$NEW/tools/sim/swarmlio_sim" --scenario "$ROOT/configs/scenarios/$scn.yaml" \
      --output_dir "$sim" "${dur[@]}" > "$OUT/sim_$scn.log" 2>&1
  fi
  for mode in swarm single; do
    for est in filter window; do
      [[ $scn == swarm_40 && $est == window ]] && continue
      args=(--manifest "$sim/swarm.yaml" --save_maps=false)
      [[ $mode == single ]] && args+=(--single_agent)
      [[ $est == window ]] && args+=(--estimator=window --window_size=5)
      for side in old new; do
        dir="$OUT/$side/$scn/$mode-$est"
        bin="$OLD"; [[ $side == new ]] && bin="$NEW"
        [[ $side == old && ${REUSE_OLD:-0} == 1 && -f $dir/log.txt ]] && continue
        mkdir -p "$dir"
        "$bin/tools/replay/swarmlio_replay" "${args[@]}" --output_dir "$dir" > "$dir/log.txt" 2>&1
      done
      echo "$scn $mode $est replayed"
    done
  done
done
differ=0 files=0
while IFS= read -r f; do
  files=$((files + 1))
  cmp -s "$OUT/old/$f" "$OUT/new/$f" || { echo "DIFFERS: $f"; differ=$((differ + 1)); }
done < <(cd "$OUT/old" && find . -name '*_tum.txt' -o -name '*_extrinsics.csv' \
           -o -name identifications.csv -o -name swarm_pairs.csv)
while IFS= read -r f; do
  files=$((files + 1))
  strip() { cut -d, -f1-13,17- "$1"; }  # without time_median_ms, time_p95_ms, realtime_factor
  cmp -s <(strip "$OUT/old/$f") <(strip "$OUT/new/$f") || { echo "DIFFERS: $f"; differ=$((differ + 1)); }
done < <(cd "$OUT/old" && find . -name metrics.csv)
echo "$files files compared, $differ differ"
[[ $differ -eq 0 ]]
