#!/usr/bin/env bash
# A stand-in for tools/sweep/run_one.sh in the sweep tests: takes the same
# arguments, honours the same `done` contract, and writes a tiny metrics.csv
# whose figures follow from the seed, the mode and a --replay_arg=--scale=X
# (so two runs of a sweep give the same table), after STUB_SLEEP_S seconds.
# Every start of a run (not skipped) is appended to $STUB_LOG.
set -euo pipefail
seed="" mode="" run_dir="" scale=1 sim_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sim_only) sim_only=1; shift; continue ;;
    --seed) seed="$2" ;; --mode) mode="$2" ;; --run_dir) run_dir="$2" ;;
    --replay_arg) [[ "$2" == --scale=* ]] && scale="${2#--scale=}" ;;
  esac
  shift 2
done
[[ $sim_only -eq 1 ]] && exit 0
[[ -f "$run_dir/done" ]] && exit 0
echo "start $run_dir" >> "${STUB_LOG:-/dev/null}"
rm -rf "$run_dir"
mkdir -p "$run_dir"
echo $$ > "$run_dir.pid"  # the resume test stops runs in flight by this id
sleep "${STUB_SLEEP_S:-0}"
awk -v s="$seed" -v k="$scale" -v single="$([[ $mode == single ]] && echo 1 || echo 0)" 'BEGIN {
  print "drone,ape_rmse_m,drift_percent,nees_position,time_median_ms,ground_truth_frame"
  for (d = 1; d <= 2; ++d)
    printf "uav%d,%.6f,%.4f,%.3f,%.2f,G\n", d, k * (0.001 * (s % 97) + 0.01 * d + 0.005 * single),
           0.1 * d + 0.01 * (s % 7), 2 + (s % 5) * 0.25, 10 + d + single
}' > "$run_dir/metrics.csv"
echo "stub" > "$run_dir/done"
rm -f "$run_dir.pid"
