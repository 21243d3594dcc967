#!/usr/bin/env bash
# One run of a sweep (docs/sweeps.md): a self-contained command that
# swarmlio_sweep expand writes, one per line of OUT/runs.jobs (and
# OUT/sims.jobs with --sim_only). It writes only into its own folders, writes
# `done` last, and exits 0 at once when `done` is already there, so any engine
# (GNU parallel, a Slurm array task, a shell loop) can run and re-run it.
#
#   run_one.sh --build B --scenario S.yaml --seed N --sim_dir D [--imperfections P]
#              [--sim_arg X]... (--sim_only | --mode swarm|single --run_dir R
#              [--overrides YAML] [--network YAML] [--replay_arg X]...)
#   run_one.sh --build B --manifest M --network_seed N --mode ... --run_dir R ...
#
# The simulation D (D/sim/, D/<scenario>.yaml with the seed set, D/done) is
# shared by every run of the same scenario, seed and simulator settings; it
# is made under a lock (flock D.lock) by the first run that needs it. Under
# GNU parallel each run is pinned to the core of its job slot (taskset), so
# each per-scan time is measured on a core of its own.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="" scenario="" seed="" sim_dir="" imperfections="" sim_only=0 mode="" run_dir=""
manifest="" network_seed="" overrides="" network=""
sim_args=() replay_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sim_only) sim_only=1; shift; continue ;;
    --build) build="$2" ;; --scenario) scenario="$2" ;; --seed) seed="$2" ;;
    --sim_dir) sim_dir="$2" ;; --imperfections) imperfections="$2" ;; --sim_arg) sim_args+=("$2") ;;
    --mode) mode="$2" ;; --run_dir) run_dir="$2" ;; --manifest) manifest="$2" ;;
    --network_seed) network_seed="$2" ;; --overrides) overrides="$2" ;; --network) network="$2" ;;
    --replay_arg) replay_args+=("$2") ;;
    *) echo "run_one.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift 2
done

# pin: the core of this GNU parallel job slot, when there is one.
pin=()
if [[ -n "${PARALLEL_JOBSLOT:-}" ]] && command -v taskset >/dev/null; then
  pin=(taskset -c $(( (PARALLEL_JOBSLOT - 1) % $(nproc) )))
fi

# simulate: D/<name>.yaml is the scenario with its seed set (and the
# imperfections map appended), D/sim the simulator's output.
simulate() {
  local name tmp
  name="$(basename "$scenario" .yaml)"
  tmp="$sim_dir/$name.yaml"
  rm -rf "$sim_dir/sim" "$sim_dir/done"
  mkdir -p "$sim_dir"
  # Sensor presets are named relative to the scenario (../livox_avia.yaml).
  ln -sf "$ROOT"/configs/*.yaml "$(dirname "$sim_dir")/"
  sed -E "/^scenario:/,/^[a-z]/s/seed: *[0-9]+/seed: $seed/" "$scenario" > "$tmp"
  grep -qE "seed: $seed([^0-9]|\$)" "$tmp" || { echo "could not set seed $seed in $tmp" >&2; return 1; }
  local args=(--scenario "$tmp" --output_dir "$sim_dir/sim")
  if [[ "$imperfections" == \{* ]]; then
    grep -q '^imperfections:' "$tmp" &&
      { echo "$scenario has its own imperfections: key; the variant's would repeat it" >&2; return 1; }
    echo "imperfections: $imperfections" >> "$tmp"
  elif [[ -n "$imperfections" ]]; then
    args+=(--imperfections "$imperfections")
  fi
  "${pin[@]}" "$build/tools/sim/swarmlio_sim" "${args[@]}" "${sim_args[@]}" > "$sim_dir/sim.log" 2>&1 ||
    { echo "simulation failed: $sim_dir/sim.log" >&2; return 1; }
  date -u +%FT%TZ > "$sim_dir/done"
}

ensure_sim() {
  [[ -f "$sim_dir/done" ]] && return 0
  mkdir -p "$sim_dir"
  (
    flock 9
    [[ -f "$sim_dir/done" ]] || simulate
  ) 9> "$sim_dir.lock"
}

replay() {
  local seed_dir args=() start=$SECONDS
  seed_dir="$(dirname "$run_dir")"
  rm -rf "$run_dir"
  mkdir -p "$seed_dir"
  if [[ -n "$scenario" ]]; then
    manifest="$sim_dir/sim/swarm.yaml"
    cp "$sim_dir/$(basename "$scenario")" "$seed_dir/.$mode.yaml" &&
      mv "$seed_dir/.$mode.yaml" "$seed_dir/$(basename "$scenario")"
  fi
  args=(--manifest "$manifest" --output_dir "$run_dir" --save_maps=false)
  [[ "$mode" == single ]] && args+=(--single_agent)
  [[ -n "$network_seed" ]] && args+=(--network_seed "$network_seed")
  if [[ -n "$overrides" ]]; then
    printf '%s\n' "$overrides" > "$seed_dir/$mode.overrides.yaml"
    args+=(--drone_overrides "$seed_dir/$mode.overrides.yaml")
  fi
  if [[ -n "$network" ]]; then
    printf 'network: %s\n' "$network" > "$seed_dir/$mode.network.yaml"
    args+=(--network_config "$seed_dir/$mode.network.yaml")
  fi
  local status=0
  "${pin[@]}" "$build/tools/replay/swarmlio_replay" "${args[@]}" "${replay_args[@]}" \
    > "$seed_dir/$mode.log" 2>&1 || status=$?
  if [[ $status -ne 0 ]]; then
    echo "$status" > "$run_dir.failed"
    echo "replay exit status $status: $seed_dir/$mode.log" >&2
    return "$status"
  fi
  rm -f "$run_dir.failed"
  echo "elapsed_s $((SECONDS - start)) host $(hostname)" > "$run_dir/done"
}

if [[ -n "$scenario" ]]; then
  [[ -n "$seed" && -n "$sim_dir" ]] || { echo "run_one.sh: --scenario needs --seed and --sim_dir" >&2; exit 2; }
  if [[ $sim_only -eq 0 && -f "$run_dir/done" ]]; then exit 0; fi
  ensure_sim
  [[ $sim_only -eq 1 ]] && exit 0
elif [[ -z "$manifest" ]]; then
  echo "run_one.sh: give --scenario or --manifest" >&2; exit 2
fi
[[ -n "$mode" && -n "$run_dir" ]] || { echo "run_one.sh: --mode and --run_dir are needed" >&2; exit 2; }
[[ -f "$run_dir/done" ]] && exit 0
replay
