#!/usr/bin/env bash
# CTest sweep.slurm_single_node: a real single-node Slurm cluster on this
# machine (Debian's munge, slurmctld and slurmd on 127.0.0.1 with a generated
# slurm.conf, a one-node partition, everything in WORK_DIR), the stub sweep
# (stub_sweep.yaml, stub_run.sh) submitted as job arrays by `tools/sweep.sh
# slurm`, waited for (bounded), and its aggregated table compared with the one
# of the same sweep run locally through GNU parallel. Exit 77 (CTest: skipped)
# with the reason when the daemons cannot be started here (not root, the
# packages missing, a daemon that does not come up).
#   slurm_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -euo pipefail
ROOT="$1" BUILD="$2" WORK="$3"
TIMEOUT_S="${SLURM_TEST_TIMEOUT_S:-120}"
skip() { echo "SKIP: $*"; exit 77; }
fail() { echo "FAIL: $*"; for f in "$WORK"/*.log; do echo "== $f"; tail -n 20 "$f"; done; exit 1; }

[[ $(id -u) -eq 0 ]] || skip "the Slurm test starts munged, slurmctld and slurmd as root; not root here"
for tool in munged munge slurmctld slurmd sbatch squeue sinfo parallel; do
  command -v "$tool" >/dev/null || [[ -x "/usr/sbin/$tool" ]] ||
    skip "$tool missing (apt-get install munge slurmctld slurmd slurm-client parallel)"
done
rm -rf "$WORK" && mkdir -p "$WORK/state" "$WORK/spool" && chmod 700 "$WORK"

stop_daemons() {
  for d in slurmd slurmctld munged; do
    [[ -f "$WORK/$d.pid" ]] && kill "$(cat "$WORK/$d.pid")" 2>/dev/null || true
  done
}
trap stop_daemons EXIT

# munge: a key and a socket of our own, so a system munged is left alone.
head -c 1024 /dev/urandom > "$WORK/munge.key" && chmod 600 "$WORK/munge.key"
PATH="$PATH:/usr/sbin"
munged --force --socket="$WORK/munge.sock" --key-file="$WORK/munge.key" --log-file="$WORK/munged.log" \
  --pid-file="$WORK/munged.pid" --seed-file="$WORK/munged.seed" ||
  skip "munged does not start here: $(tail -n 3 "$WORK/munged.log" 2>/dev/null)"
munge -S "$WORK/munge.sock" -n >/dev/null || skip "munge cannot encode a credential"

host="$(hostname -s)"
port=$((20000 + RANDOM % 20000))
cat > "$WORK/slurm.conf" <<CONF
ClusterName=swarmlio-sweep-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$WORK/munge.sock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=sweep Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$WORK/slurm.conf"
slurmctld -f "$SLURM_CONF" || skip "slurmctld does not start here: $(tail -n 3 "$WORK/slurmctld.log" 2>/dev/null)"
slurmd -f "$SLURM_CONF" || skip "slurmd does not start here: $(tail -n 3 "$WORK/slurmd.log" 2>/dev/null)"
for _ in $(seq 60); do
  sinfo -h -o %t 2>/dev/null | grep -qE '^(idle|mix|alloc)' && break
  sleep 0.5
done
sinfo -h -o %t 2>/dev/null | grep -qE '^(idle|mix|alloc)' ||
  skip "the node did not come up within 30 s: $(sinfo 2>&1 | tail -n 2)"
echo "Slurm up: $(sinfo -h -o '%P %D %t %N')"

export BUILD_DIR="$BUILD" SWEEP_RUNNER="$ROOT/tests/sweep/stub_run.sh"
sweep="$ROOT/tests/sweep/stub_sweep.yaml"
JOBS=2 bash "$ROOT/tools/sweep.sh" local "$sweep" "$WORK/local" || fail "local sweep failed"
start=$SECONDS
job=$(bash "$ROOT/tools/sweep.sh" slurm "$sweep" "$WORK/slurm") || fail "submission failed"
while squeue -h -j "$job" 2>/dev/null | grep -q .; do
  (( SECONDS - start < TIMEOUT_S )) || { scancel --user=root 2>/dev/null || true; fail "not done within $TIMEOUT_S s: $(squeue)"; }
  sleep 1
done
[[ -f "$WORK/slurm/summary.tsv" ]] || fail "no summary.tsv from the Slurm sweep: $(cat "$WORK"/slurm/slurm/logs/* 2>/dev/null | tail -n 20)"
[[ $(find "$WORK/slurm/runs" -name 'done' | wc -l) -eq 8 ]] || fail "not 8 finished runs"
cmp "$WORK/local/summary.tsv" "$WORK/slurm/summary.tsv" || {
  diff "$WORK/local/summary.tsv" "$WORK/slurm/summary.tsv" | head -n 20; fail "the tables differ"; }
echo "PASS: Slurm array sweep done in $((SECONDS - start)) s; summary.tsv equals the GNU parallel run's"
