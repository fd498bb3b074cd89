#!/usr/bin/env bash
# The Slurm backend end to end (label slurm): a one-node Slurm cluster started here from Debian's
# packages (tests/support/slurm_cluster.sh), a server with --backend slurm, an ensemble submitted to
# it with one member's Slurm step killed while it runs, and its aggregate compared, byte for byte,
# with the same ensemble run locally (runout run). Everything under one temporary folder; the
# server and the cluster are stopped by their pids.
#   slurm_backend.sh RUNOUT SOURCE_DIR
set -u -o pipefail
RUNOUT=$1
SRC=$2
DIR=$(mktemp -d /tmp/runout-slurm-test.XXXXXX)
chmod 755 "$DIR"  # munged refuses a socket folder under a folder others cannot search
CLUSTER="$SRC/tests/support/slurm_cluster.sh"
SCENARIO="$SRC/tests/data/arelen-ensemble-30m.json"
SERVER_PID=
fail() {
  echo "slurm_backend: FAILED: $*"
  [[ -f $DIR/server.log ]] && tail -30 "$DIR/server.log"
  tail -n 8 "$DIR"/state/logs/*.log 2>/dev/null
  exit 1
}
cleanup() {
  [[ -n $SERVER_PID ]] && kill "$SERVER_PID" 2>/dev/null && wait "$SERVER_PID" 2>/dev/null
  bash "$CLUSTER" stop "$DIR/cluster" >/dev/null 2>&1
  rm -rf "$DIR"
}
trap cleanup EXIT
command -v sbatch >/dev/null || fail "Slurm's commands are missing (apt-get install munge slurmctld slurmd slurm-client; scripts/deps.sh has them)"

# The reference: the same ensemble through the local job system.
"$RUNOUT" run "$SCENARIO" --out "$DIR/local" --state-dir "$DIR/local-state" --workers 2 --quiet || fail "the local run failed"

CLUSTER_ENV=$(bash "$CLUSTER" start "$DIR/cluster") && [[ -n $CLUSTER_ENV ]] || fail "the cluster did not start"
eval "$CLUSTER_ENV"
"$RUNOUT" serve --backend slurm --workers 4 --threads-per-run 1 --listen 127.0.0.1:0 --state-dir "$DIR/state" \
  --log-file "$DIR/server.log" 2>"$DIR/server.err" &
SERVER_PID=$!
for _ in $(seq 200); do [[ -f $DIR/state/server.json ]] && break; sleep 0.1; done
ADDR=$(sed -n 's/.*"listen": *"\([^"]*\)".*/\1/p' "$DIR/state/server.json")
[[ -n $ADDR ]] || fail "the server did not start: $(cat "$DIR/server.err")"
export RUNOUT_SERVER=$ADDR

JOB=$("$RUNOUT" submit "$SCENARIO" --quiet | awk '{print $1}')
[[ $JOB == j* ]] || fail "submit gave '$JOB'"
# Kill a member's step that runs on the cluster (the batch process, SIGKILL). The scheduler sees the
# step's end (a crash of its worker, or a stop from outside) and queues the member again; only then
# the node fails (a node failure would requeue the killed task in Slurm too). A member of a few
# seconds can finish before the signal reaches it on a loaded machine: then the next running member
# is killed, while one runs.
KILLED=
TRACE=
for _ in $(seq 600); do
  TASK=$(squeue -h -r -t R -o '%i' | grep -vxF -e "${KILLED:-none}" | head -1)
  if [[ -n $TASK ]]; then
    sleep 1
    if scancel --signal=KILL --batch "$TASK"; then
      KILLED=$TASK
      echo "killed the step of $KILLED"
      for _ in $(seq 100); do grep -q "crashed\|stopped from outside" "$DIR/state/logs/"*.log 2>/dev/null && TRACE=1 && break; sleep 0.1; done
      [[ -n $TRACE ]] && break
      echo "the step of $KILLED left no trace within 10 s (it may have finished first): the next running member"
    fi
  fi
  sleep 0.1
done
[[ -n $KILLED ]] || fail "no member ran on the cluster"
[[ -n $TRACE ]] || fail "the killed step left no trace in the jobs' logs"
# Fail the node under another running task: Slurm runs it again (--requeue) once the node is back.
NODE=
for _ in $(seq 600); do
  TASK=$(squeue -h -r -t R -o '%i' | grep -v "^$KILLED\$" | head -1)
  if [[ -n $TASK ]]; then
    NODE=$(squeue -h -j "$TASK" -o '%N')
    scontrol update nodename="$NODE" state=down reason=runout-test && break
  fi
  sleep 0.1
done
[[ -n $NODE ]] || fail "no second member ran on the cluster"
sleep 2
scontrol update nodename="$NODE" state=resume || fail "the node did not come back"
echo "failed node $NODE under $TASK"
timeout 600 "$RUNOUT" watch "$JOB" >/dev/null 2>&1
"$RUNOUT" status "$JOB" > "$DIR/status.txt"
grep -q "^state *succeeded" "$DIR/status.txt" || fail "the ensemble did not succeed: $(cat "$DIR/status.txt")"
grep -q "4 of 4 members done" "$DIR/status.txt" || fail "members: $(grep members "$DIR/status.txt")"
grep -q "Slurm job" "$DIR/state/logs/"*.log || fail "no job ran on Slurm"
grep -q "Restarts=1" <(scontrol show job -o "$TASK" 2>/dev/null) || ls "$DIR"/state/slurm/*/*.events.1 >/dev/null 2>&1 ||
  fail "the task under the failed node was not run again by Slurm"
"$RUNOUT" fetch "$JOB" --out "$DIR/slurm" >/dev/null || fail "fetch failed"
n=0
for f in "$DIR"/local/*.tif "$DIR"/local/*.csv; do
  cmp -s "$f" "$DIR/slurm/$(basename "$f")" || fail "$(basename "$f") differs from the local aggregate"
  n=$((n + 1))
done
[[ $n -eq 14 ]] || fail "compared $n files, expected 14"
echo "slurm_backend: the ensemble ran on Slurm (a killed step run again) and equals the local aggregate ($n files)"
