#!/usr/bin/env bash
# Sweeps (docs/sweeps.md): a YAML grid of variants x scenarios or logs x seeds
# x modes, expanded into one self-contained command per run and run through an
# existing engine. Needs a Release build in $BUILD_DIR (tools/swarmlio.sh setup).
#
#   tools/sweep.sh local SWEEP.yaml [OUT]   # GNU parallel on this machine, all cores
#   tools/sweep.sh slurm SWEEP.yaml [OUT]   # Slurm job arrays; OUT on a shared folder
#   tools/sweep.sh aggregate OUT            # OUT/summary.{tsv,md}, OUT/summary_*.png
#   tools/sweep.sh expand SWEEP.yaml [OUT]  # only the job lists OUT/{sims,runs}.jobs
#
# OUT defaults to results/sweeps/<sweep file name>. Re-running a sweep skips
# every run that finished (its folder has `done`); an interrupted sweep re-runs
# only the unfinished ones. After aggregation the sweep's `report:` script runs
# as `<report> OUT` when every run finished (REPORT=0 skips it).
# Environment: BUILD_DIR (default build), JOBS (local: parallel jobs, default
# every core), SBATCH_ARGS (slurm: extra sbatch options, e.g. "-p lab -t 2:00:00"),
# SLURM_WAIT=1 (slurm: wait for the aggregation job to finish), SWEEP_RUNNER
# (the per-run script instead of tools/sweep/run_one.sh; the tests' stub).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="$(realpath -m "${BUILD_DIR:-$ROOT/build}")"
SWEEP_TOOL="$BUILD_DIR/tools/sweep/swarmlio_sweep"
log() { echo "[sweep] $*" >&2; }
usage() { sed -n '4,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }

[[ -x "$SWEEP_TOOL" ]] || { echo "missing $SWEEP_TOOL: run tools/swarmlio.sh setup first" >&2; exit 1; }

# expand SWEEP OUT: the job lists; the GNU parallel job logs go when the lists change.
expand() {
  local sweep="$1" out="$2"
  local before=""
  [[ -f "$out/runs.jobs" ]] && before="$(cat "$out/sims.jobs" "$out/runs.jobs")"
  "$SWEEP_TOOL" expand --sweep "$sweep" --out "$out" --root "$ROOT" --build "$BUILD_DIR" \
    ${SWEEP_RUNNER:+--runner "$SWEEP_RUNNER"} >&2
  if [[ "$before" != "$(cat "$out/sims.jobs" "$out/runs.jobs")" ]]; then
    rm -f "$out/jobs.joblog"
  fi
}

# unfinished_lines OUT: the runs.jobs line numbers of the runs without `done`.
unfinished_lines() {
  awk -F'\t' 'NR > 1 { if (system("test -f \"" $5 "/done\"") != 0) print NR - 1 }' "$1/runs.tsv"
}

aggregate() {
  local out="$1" report
  "$SWEEP_TOOL" aggregate --out "$out" >&2
  report="$(cat "$out/report" 2>/dev/null || true)"
  [[ -n "$report" && "${REPORT:-1}" != 0 ]] || return 0
  if [[ -n "$(unfinished_lines "$out")" ]]; then
    log "not every run finished: $report not run (re-run the sweep to finish them)"
    return 1
  fi
  log "report: $report $out"
  bash "$report" "$out"
}

run_local() {
  local out="$1" rc=0
  command -v parallel >/dev/null || { echo "GNU parallel is missing (apt-get install parallel)" >&2; exit 1; }
  local jobs="${JOBS:-100%}"
  log "$(wc -l < "$out/sims.jobs") simulations, then $(wc -l < "$out/runs.jobs") runs; GNU parallel -j $jobs"
  # One list, simulations first, so that no core waits at a barrier between
  # the two (a run whose simulation is still in progress waits on its lock).
  # --resume-failed: jobs in the job log that ended with status 0 are
  # skipped; the others (failed, or killed by an interruption) run again.
  cat "$out/sims.jobs" "$out/runs.jobs" |
    parallel --will-cite -j "$jobs" --joblog "$out/jobs.joblog" --resume-failed || rc=1
  aggregate "$out" || rc=1
  return $rc
}

# write_array_script OUT NAME LIST: an sbatch script whose task i runs line i of LIST.
write_array_script() {
  local out="$1" name="$2" list="$3"
  cat > "$out/slurm/$name.sbatch" <<SCRIPT
#!/bin/bash
#SBATCH --job-name=$(cat "$out/name")-$name
#SBATCH --cpus-per-task=1
#SBATCH --output=$out/slurm/logs/${name}_%A_%a.out
set -euo pipefail
line="\$(sed -n "\${SLURM_ARRAY_TASK_ID}p" '$list')"
[[ -n "\$line" ]] || { echo "no line \$SLURM_ARRAY_TASK_ID in $list" >&2; exit 1; }
exec bash -c "\$line"
SCRIPT
}

run_slurm() {
  local out="$1" sim_id="" run_id="" dep=() indices
  command -v sbatch >/dev/null || { echo "sbatch is missing (a Slurm client: apt-get install slurm-client)" >&2; exit 1; }
  mkdir -p "$out/slurm/logs"
  write_array_script "$out" sims "$out/sims.jobs"
  write_array_script "$out" runs "$out/runs.jobs"
  # shellcheck disable=SC2086  # SBATCH_ARGS is a list of options
  if [[ -s "$out/sims.jobs" ]]; then
    sim_id=$(sbatch --parsable ${SBATCH_ARGS:-} --array="1-$(wc -l < "$out/sims.jobs")" "$out/slurm/sims.sbatch")
    dep=(--dependency="afterany:$sim_id")
    log "simulations: job array $sim_id"
  fi
  indices="$(unfinished_lines "$out" | paste -sd, -)"
  if [[ -n "$indices" ]]; then
    # shellcheck disable=SC2086
    run_id=$(sbatch --parsable ${SBATCH_ARGS:-} "${dep[@]}" --array="$indices" "$out/slurm/runs.sbatch")
    dep=(--dependency="afterany:$run_id")
    log "runs: job array $run_id (tasks $indices)"
  else
    log "every run finished already"
  fi
  local wait=()
  [[ "${SLURM_WAIT:-0}" == 1 ]] && wait=(--wait)
  # shellcheck disable=SC2086
  local agg_id
  agg_id=$(sbatch --parsable ${SBATCH_ARGS:-} "${dep[@]}" "${wait[@]}" --job-name="$(cat "$out/name")-aggregate" \
    --output="$out/slurm/logs/aggregate_%j.out" \
    --wrap="BUILD_DIR='$BUILD_DIR' bash '$ROOT/tools/sweep.sh' aggregate '$out'")
  log "aggregation: job $agg_id (writes $out/summary.md)"
  echo "$agg_id"
}

cmd="${1:-}"
case "$cmd" in
  local|slurm|expand)
    [[ $# -ge 2 ]] || usage
    sweep="$2"
    out="$(realpath -m "${3:-$ROOT/results/sweeps/$(basename "$sweep" .yaml)}")"
    expand "$sweep" "$out"
    case "$cmd" in
      local) run_local "$out" ;;
      slurm) run_slurm "$out" ;;
    esac
    ;;
  aggregate)
    [[ $# -eq 2 ]] || usage
    aggregate "$(realpath -m "$2")"
    ;;
  *) usage ;;
esac
