#!/usr/bin/env bash
# CTest sweep.resume_after_interruption: tools/sweep.sh local on the stub
# sweep (stub_sweep.yaml, stub_run.sh), interrupted after some runs finished
# and started again: only the unfinished runs run again, and the aggregated
# table equals that of an uninterrupted sweep. Exit 77 (skipped) without GNU
# parallel.
#   resume_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -euo pipefail
ROOT="$1" BUILD="$2" WORK="$3"
command -v parallel >/dev/null || { echo "SKIP: GNU parallel is not installed (apt-get install parallel)"; exit 77; }
rm -rf "$WORK" && mkdir -p "$WORK"
export BUILD_DIR="$BUILD" SWEEP_RUNNER="$ROOT/tests/sweep/stub_run.sh" JOBS=2
sweep="$ROOT/tests/sweep/stub_sweep.yaml"
fail() { echo "FAIL: $*"; exit 1; }

# An uninterrupted sweep: 8 runs, each started once.
STUB_LOG="$WORK/full.log" bash "$ROOT/tools/sweep.sh" local "$sweep" "$WORK/full"
[[ $(wc -l < "$WORK/full.log") -eq 8 ]] || fail "8 runs expected, started: $(cat "$WORK/full.log")"
grep -q '^base	indoor_3uav	1001	swarm	' "$WORK/full/runs.tsv" || fail "run list: $(cat "$WORK/full/runs.tsv")"
# Re-run: every run finished, nothing starts.
STUB_LOG="$WORK/again.log" bash "$ROOT/tools/sweep.sh" local "$sweep" "$WORK/full"
[[ ! -s "$WORK/again.log" ]] || fail "finished runs started again: $(cat "$WORK/again.log")"

# An interrupted sweep: 1 s per run, 2 at a time; stopped (the process group
# killed, runs in flight included) once two runs finished.
out="$WORK/interrupted"
STUB_LOG="$WORK/first.log" STUB_SLEEP_S=1 setsid bash "$ROOT/tools/sweep.sh" local "$sweep" "$out" \
  > "$WORK/first.out" 2>&1 &
pid=$!
for _ in $(seq 100); do
  [[ $(find "$out/runs" -name 'done' 2>/dev/null | wc -l) -ge 2 ]] && break
  sleep 0.1
done
kill -KILL -- -"$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
# GNU parallel starts each job in a process group of its own: the runs still
# in flight are stopped by their ids (stub_run.sh writes <run folder>.pid).
for f in "$out"/runs/*/*/*/*.pid; do
  [[ -f "$f" ]] && kill -KILL "$(cat "$f")" 2>/dev/null || true
done
# A run that started just before the stop may have escaped both; let it end
# (it then counts as finished).
sleep 1.5
mapfile -t finished < <(find "$out/runs" -name 'done' -printf '%h\n' | sort)
echo "finished before the interruption: ${#finished[@]} of 8"
[[ ${#finished[@]} -ge 2 && ${#finished[@]} -lt 8 ]] || fail "${#finished[@]} runs finished before the stop"
STUB_LOG="$WORK/second.log" bash "$ROOT/tools/sweep.sh" local "$sweep" "$out"
for dir in "${finished[@]}"; do
  ! grep -qx "start $dir" "$WORK/second.log" || fail "finished run $dir ran again"
done
[[ $(wc -l < "$WORK/second.log") -eq $((8 - ${#finished[@]})) ]] ||
  fail "expected $((8 - ${#finished[@]})) runs to start again: $(cat "$WORK/second.log")"
cmp "$WORK/full/summary.tsv" "$out/summary.tsv" || fail "summary.tsv differs from the uninterrupted sweep's"
echo "PASS: $((8 - ${#finished[@]})) unfinished runs re-run, summary.tsv identical"
