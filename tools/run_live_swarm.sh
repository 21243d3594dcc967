#!/usr/bin/env bash
# The live-swarm acceptance run (issue #13, docs/online.md "Live against offline"): the
# scenario's drones run as separate swarmlio_live processes on this machine, talking over UDP
# on loopback, their bags played at --rate; the same bags are replayed offline; per drone the
# ego APE (SE(3)-aligned, as the replay's metrics) and per pair the extrinsic error at the end
# are compared.
#
#   tools/run_live_swarm.sh                          # indoor_3uav, rate 1, realistic preset
#   SCENARIO=wall_degenerate RATE=2 OUT=/tmp/live tools/run_live_swarm.sh
#   PROXY="--loss 0.3 --delay_s 0.2 --jitter_s 0.01 --reorder_probability 0.1" \
#     CLOCK_OFFSETS=0,0.5,-0.5 JOIN=uav3=20 RESTART=uav2=30 OUT=/tmp/faults tools/run_live_swarm.sh
#
# Environment: SCENARIO (indoor_3uav), RATE (1), IMPERFECTIONS (realistic), SEED (the file's),
# CLOCK_OFFSETS (the drones' clock offsets for the simulation, e.g. "0,0.5,-0.5"), LIVE_ARGS
# (more swarmlio_live flags, e.g. "--network_poll_period_ms=0.5"), LATE_INIT (in_flight: the
# odometry.initialization of a JOIN or RESTART drone, which starts while flying; static: as
# before the in-flight initializer),
# UDP_MODE (unicast: multicast needs a route on loopback), BASE_PORT (9100), OUT
# (results/live/<scenario>), BUILD_DIR (build). Exit code 1 if a step fails; the comparison
# is printed, not judged.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
SCENARIO="${SCENARIO:-indoor_3uav}"
RATE="${RATE:-1}"
IMPERFECTIONS="${IMPERFECTIONS:-realistic}"
UDP_MODE="${UDP_MODE:-unicast}"
BASE_PORT="${BASE_PORT:-9100}"
OUT="${OUT:-$ROOT/results/live/$SCENARIO}"
SIM="$BUILD_DIR/tools/sim/swarmlio_sim"
REPLAY="$BUILD_DIR/tools/replay/swarmlio_replay"
LIVE="$BUILD_DIR/tools/live/swarmlio_live"
EVAL="$BUILD_DIR/tools/eval/swarmlio_eval"
PROXY_TOOL="$BUILD_DIR/tools/live/swarmlio_net_proxy"
for tool in "$SIM" "$REPLAY" "$LIVE" "$EVAL" "$PROXY_TOOL"; do
  [[ -x "$tool" ]] || { echo "missing $tool: run tools/swarmlio.sh setup first" >&2; exit 1; }
done
mkdir -p "$OUT"

if [[ ! -f "$OUT/sim/swarm.yaml" ]]; then
  seed_flag=()
  [[ -n "${SEED:-}" ]] && seed_flag=(--seed "$SEED")
  [[ -n "${CLOCK_OFFSETS:-}" ]] && seed_flag+=(--clock_offsets_s "$CLOCK_OFFSETS")
  "$SIM" --scenario "$ROOT/configs/scenarios/$SCENARIO.yaml" --imperfections "$IMPERFECTIONS" \
      "${seed_flag[@]}" --output_dir "$OUT/sim" > "$OUT/sim.log" 2>&1 ||
    { echo "simulation failed: $OUT/sim.log" >&2; exit 1; }
fi
drones=($(sed -nE 's/^  - name: *([A-Za-z0-9_]+).*/\1/p' "$OUT/sim/swarm.yaml"))
[[ ${#drones[@]} -ge 2 ]] || { echo "fewer than two drones in $OUT/sim/swarm.yaml" >&2; exit 1; }

# A fresh swarm key for this run (never a default key).
key="$OUT/swarm.key"
head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \n' > "$key"
chmod 600 "$key"

echo "offline replay of $SCENARIO ..."
"$REPLAY" --manifest "$OUT/sim/swarm.yaml" --output_dir "$OUT/offline" --save_maps=false \
    > "$OUT/offline.log" 2>&1 || { echo "replay failed: $OUT/offline.log" >&2; exit 1; }

echo "live: ${#drones[@]} processes at rate $RATE ($UDP_MODE)${PROXY:+, through swarmlio_net_proxy $PROXY} ..."
# Faults (docs/online.md "Faults"): PROXY routes every datagram through a lossy relay;
# JOIN=name=S starts that drone S s late, its log from S s on; RESTART=name=S kills it S s into
# the run and starts it again 1 s later, its log from there (output in live_restart/). Every
# process starts its playback at a common wall-clock time (--start_at_unix_s), so the logs,
# recorded simultaneously, are played simultaneously; clock offsets between the drones are
# the simulator's (CLOCK_OFFSETS at simulation time).
join_name="${JOIN:-}"; join_name="${join_name%%=*}"; join_s="${JOIN:-}"; join_s="${join_s#*=}"
restart_name="${RESTART:-}"; restart_name="${restart_name%%=*}"; restart_s="${RESTART:-}"; restart_s="${restart_s#*=}"
peers=""
for i in "${!drones[@]}"; do
  port=$((BASE_PORT + i + 1))
  [[ -n "${PROXY:-}" ]] && port=$((BASE_PORT + 100 + i + 1))
  peers+="${peers:+,}${drones[$i]}=127.0.0.1:$port"
done
proxy_pid=""
if [[ -n "${PROXY:-}" ]]; then
  [[ "$UDP_MODE" == unicast ]] || { echo "PROXY needs UDP_MODE=unicast" >&2; exit 1; }
  routes=""
  for i in "${!drones[@]}"; do routes+="${routes:+,}$((BASE_PORT + 100 + i + 1))=$((BASE_PORT + i + 1))"; done
  "$PROXY_TOOL" --routes "$routes" $PROXY > "$OUT/proxy.log" 2>&1 &
  proxy_pid=$!
fi
launch() {  # launch <index> <output dir> <log offset s> <wall start> <log suffix> [more flags]
  local i=$1 name="${drones[$1]}"      # (pid in LAUNCHED)
  local args=(--manifest "$OUT/sim/swarm.yaml" --drone "$name" --key_file "$key" --rate "$RATE"
              --output_dir "$2" --imu_odom=false --udp_mode "$UDP_MODE" --start_s "$3"
              --start_at_unix_s "$4" ${6:-} ${LIVE_ARGS:-})
  if [[ "$UDP_MODE" == unicast ]]; then
    args+=(--port "$((BASE_PORT + i + 1))" --peers "$peers")
  else
    args+=(--port "$BASE_PORT")
  fi
  "$LIVE" "${args[@]}" > "$OUT/live_$name$5.log" 2>&1 &
  LAUNCHED=$!
}
sleep_until() { awk -v t="$1" -v now="$(date +%s.%N)" 'BEGIN { w = t - now; if (w > 0) system("sleep " w) }'; }
plus() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a + b }'; }
times() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a * b }'; }
mkdir -p "$OUT/live" "$OUT/live_restart"
t0=$(plus "$(date +%s.%N)" 3)  # every process has opened its log by then
pids=()
for i in "${!drones[@]}"; do
  [[ "${drones[$i]}" == "$join_name" ]] && { join_index=$i; continue; }
  launch "$i" "$OUT/live" 0 "$t0" ""
  pids[$i]=$LAUNCHED
done
if [[ -n "${JOIN:-}" ]]; then  # (a RESTART is assumed to come after the JOIN)
  sleep_until "$(plus "$t0" "$(plus "$join_s" -2)")"  # opens its log, then waits for its start
  launch "$join_index" "$OUT/live" "$(times "$join_s" "$RATE")" "$(plus "$t0" "$join_s")" "" \
      "--initialization=${LATE_INIT:-in_flight}"
  pids[$join_index]=$LAUNCHED
fi
if [[ -n "${RESTART:-}" ]]; then
  for i in "${!drones[@]}"; do [[ "${drones[$i]}" == "$restart_name" ]] && restart_index=$i; done
  sleep_until "$(plus "$t0" "$restart_s")"
  kill -9 "${pids[$restart_index]}" 2> /dev/null || true
  wait "${pids[$restart_index]}" 2> /dev/null || true
  restart_at=$(plus "$restart_s" 1)  # down for a second
  echo "killed $restart_name ${restart_s} s into the run; back at ${restart_at} s, its log from there"
  launch "$restart_index" "$OUT/live_restart" "$(times "$restart_at" "$RATE")" \
      "$(plus "$t0" "$restart_at")" "_restart" "--initialization=${LATE_INIT:-in_flight}"
  pids[$restart_index]=$LAUNCHED
fi
failed=0
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || { echo "live ${drones[$i]} failed: $OUT/live_${drones[$i]}.log" >&2; failed=1; }
done
if [[ -n "$proxy_pid" ]]; then kill "$proxy_pid" 2> /dev/null || true; wait "$proxy_pid" || true; fi
[[ $failed == 0 ]] || exit 1

rmse() {  # rmse <gt> <estimate>: SE(3)-aligned APE RMSE [m]
  "$EVAL" ape "$1" "$2" --align se3 | awk '$1 == "rmse" { print $2 }'
}
change() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%+.1f %%", (a - b) / b * 100 }'; }
# The live output folder of a drone's last process (a restarted one: live_restart).
live_dir() { if [[ "$1" == "${restart_name:-}" && -n "${RESTART:-}" ]]; then echo "$OUT/live_restart"; else echo "$OUT/live"; fi; }
summary_value() {  # summary_value <drone> <sed expression>
  sed -nE "$2" "$(live_dir "$1")/$1_live_summary.txt"
}

echo
echo "| drone | APE offline [m] | APE live [m] | change | live latency p95 [ms] | live scans dropped |"
echo "|---|---:|---:|---:|---:|---:|"
for name in "${drones[@]}"; do
  gt="$OUT/sim/${name}_gt_tum.txt"
  off=$(rmse "$gt" "$OUT/offline/${name}_tum.txt")
  dir=$(live_dir "$name")
  label="$name"
  [[ "$dir" == "$OUT/live_restart" ]] && label="$name (after the restart)"
  [[ "$name" == "${join_name:-}" && -n "${JOIN:-}" ]] && label="$name (joined ${join_s} s late)"
  liv=$(rmse "$gt" "$dir/${name}_tum.txt")
  p95=$(summary_value "$name" 's/.*latency scan end -> odometry out \[ms\]: median [0-9.]+  p95 ([0-9.]+).*/\1/p')
  dropped=$(summary_value "$name" 's/.*scans: [0-9]+ played, [0-9]+ processed, ([0-9]+) dropped.*/\1/p')
  printf '| %s | %.4f | %.4f | %s | %s | %s |\n' "$label" "$off" "$liv" "$(change "$liv" "$off")" \
      "$p95" "$dropped"
done

# A drone that joined late or restarted has its G at its body pose when its odometry
# initialized (docs/conventions.md): the extrinsic truth follows it.
origins=""
for name in "${drones[@]}"; do
  if [[ ( -n "${JOIN:-}" && "$name" == "$join_name" ) || ( -n "${RESTART:-}" && "$name" == "$restart_name" ) ]]; then
    stamp=$(summary_value "$name" 's/.*odometry initialized at sensor stamp ([0-9]+) ns.*/\1/p')
    origins+="${origins:+,}$name=$(awk -v s="$stamp" 'BEGIN { printf "%.9f", s * 1e-9 }')"
  fi
done
echo
echo "| observer | teammate | identified offline / live [s after first scan] | extrinsic end offline [m / deg] | live [m / deg] | live - offline [m] |"
echo "|---|---|---:|---:|---:|---:|"
for name in "${drones[@]}"; do
  dir=$(live_dir "$name")
  "$EVAL" extrinsics "$OUT/offline/${name}_extrinsics.csv" --manifest "$OUT/sim/swarm.yaml" \
      --observer "$name" | tail -n +2 > "$OUT/offline_${name}_extrinsics_errors.csv"
  "$EVAL" extrinsics "$dir/${name}_extrinsics.csv" --manifest "$OUT/sim/swarm.yaml" \
      --observer "$name" --origins "$origins" | tail -n +2 > "$OUT/live_${name}_extrinsics_errors.csv"
  for teammate in "${drones[@]}"; do
    [[ "$teammate" == "$name" ]] && continue
    o=$(awk -F, -v t="$teammate" '$2 == t' "$OUT/offline_${name}_extrinsics_errors.csv")
    l=$(awk -F, -v t="$teammate" '$2 == t' "$OUT/live_${name}_extrinsics_errors.csv")
    id_off=$(awk -F, -v o="$name" -v t="$teammate" '$1 == o && $2 == t { printf "%.1f", $4; exit }' \
             "$OUT/offline/identifications.csv")
    id_live=$(awk -F, -v t="$teammate" 'NR > 1 && $2 == t { s = s (s ? ", " : "") sprintf("%.1f", $4) } END { print s }' \
              "$dir/${name}_identifications.csv")
    if [[ -z "$l" ]]; then
      printf '| %s | %s | %s / never | %s | not identified | |\n' "$name" "$teammate" \
          "${id_off:-never}" "$(echo "$o" | awk -F, '{ printf "%.4f / %.2f", $6, $7 }')"
      continue
    fi
    printf '| %s | %s | %s / %s | %s | %s | %s |\n' "$name" "$teammate" "${id_off:-never}" \
        "${id_live:-?}" "$(echo "$o" | awk -F, '{ printf "%.4f / %.2f", $6, $7 }')" \
        "$(echo "$l" | awk -F, '{ printf "%.4f / %.2f", $6, $7 }')" \
        "$(awk -v a="$(echo "$l" | cut -d, -f6)" -v b="$(echo "$o" | cut -d, -f6)" \
           'BEGIN { printf "%+.4f", a - b }')"
  done
done
if [[ -n "${RESTART:-}" ]]; then
  echo
  echo "$restart_name back ${restart_at} s into the run; its teammates identified it again after:"
  for i in "${!drones[@]}"; do
    name="${drones[$i]}"
    [[ "$name" == "$restart_name" ]] && continue
    # The observer's log time of the restart: restart_at x rate, less the
    # time a late joiner's log starts after the others' (its since_first_scan_s
    # counts from its own first scan).
    late=0
    [[ -n "${JOIN:-}" && "$name" == "$join_name" ]] && late="$join_s"
    awk -F, -v t="$restart_name" -v at="$restart_at" -v r="$RATE" -v o="$name" -v late="$late" '
      NR > 1 && $2 == t && $4 > (at - late) * r {
        printf "  %s: %.1f s (%s)\n", o, $4 - (at - late) * r, $5; found = 1; exit }
      END { if (!found) printf "  %s: not identified again\n", o }' "$OUT/live/${name}_identifications.csv"
  done
fi

# Clock offsets: the processes share this machine's steady clock, so each one's playback
# mapping (sensor stamp S0 played at steady time C0, rate r) gives the true offset of j's sensor
# clock from i's: (S0_j - S0_i) - r (C0_j - C0_i).
mapping() {  # mapping <drone>: "S0 C0 r"
  summary_value "$1" 's/.*playback: sensor stamp (-?[0-9]+) ns at steady clock (-?[0-9]+) ns, rate ([0-9.e+-]+).*/\1 \2 \3/p'
}
echo
echo "| observer | teammate | clock offset true [ms] | estimated [ms] | error [ms] |"
echo "|---|---|---:|---:|---:|"
for name in "${drones[@]}"; do
  read -r s_i c_i r_i <<< "$(mapping "$name")"
  for teammate in "${drones[@]}"; do
    [[ "$teammate" == "$name" ]] && continue
    read -r s_j c_j _ <<< "$(mapping "$teammate")"
    est=$(summary_value "$name" "s/.*clock of $teammate: offset ([+-]?[0-9.]+) ms.*/\\1/p")
    awk -v si="$s_i" -v ci="$c_i" -v sj="$s_j" -v cj="$c_j" -v r="$r_i" -v e="$est" \
        -v o="$name" -v t="$teammate" 'BEGIN {
          truth = ((sj - si) - r * (cj - ci)) * 1e-6
          if (e == "") printf "| %s | %s | %.3f | not estimated | |\n", o, t, truth
          else printf "| %s | %s | %.3f | %.3f | %+.3f |\n", o, t, truth, e, e - truth }'
  done
done
[[ -n "${PROXY:-}" ]] && { echo; cat "$OUT/proxy.log"; }
echo
echo "outputs in $OUT (offline/, live/, live_restart/, logs)"
