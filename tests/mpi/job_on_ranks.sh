#!/usr/bin/env bash
# job_on_ranks.sh RUNOUT RANKS_CHECK SOURCE_DIR BACKEND: a 3D job over 2 MPI ranks through the
# service (`runout submit --ranks 2`) on BACKEND "local" (the worker pool starts it with mpirun) or
# "slurm" (a one-node Slurm cluster started here: one job of 2 tasks, the ranks started by srun).
#   1. the job is submitted, followed, and stopped with the server while it runs (the ranks end at
#      the same step with a checkpoint); the server started again continues it from there;
#   2. its rasters, fetched, are those of the uninterrupted run over 2 ranks byte for byte, and
#      agree with `runout run` on one process (ranks_check: the record says 2 ranks; figures and
#      rasters within the mpi tests' tolerances);
#   3. a second job over 2 ranks is cancelled while it runs: it ends cancelled, nothing of it runs on.
# Everything under one temporary folder; the server and the cluster are stopped by their pids.
set -u -o pipefail
RUNOUT=$1 CHECK=$2 SRC=$3 BACKEND=$4
SCENARIO="$SRC/tests/data/mpi/arelen-3d-12s.json"
CLUSTER="$SRC/tests/support/slurm_cluster.sh"
DIR=$(mktemp -d /tmp/runout-ranks-job.XXXXXX)
chmod 755 "$DIR"  # munged refuses a socket folder under a folder others cannot search
SERVER_PID=
. "$(dirname "$0")/mpi_env.sh"
fail() {
  echo "job_on_ranks ($BACKEND): FAILED: $*"
  [[ -f $DIR/server.log ]] && tail -20 "$DIR/server.log"
  tail -n 30 "$DIR"/state/logs/*.log 2>/dev/null
  exit 1
}
cleanup() {
  [[ -n $SERVER_PID ]] && kill "$SERVER_PID" 2>/dev/null && wait "$SERVER_PID" 2>/dev/null
  [[ $BACKEND == slurm ]] && bash "$CLUSTER" stop "$DIR/cluster" >/dev/null 2>&1
  rm -rf "$DIR"
}
trap cleanup EXIT

start_server() {
  rm -f "$DIR/state/server.json"
  echo '{"max_ranks_per_job": 4}' > "$DIR/server.json"  # (the local default, the machine's cores, may be 1)
  "$RUNOUT" serve --config "$DIR/server.json" --backend "$BACKEND" --workers 2 --threads-per-run 1 --listen 127.0.0.1:0 --state-dir "$DIR/state" \
    --log-file "$DIR/server.log" 2>>"$DIR/server.err" &
  SERVER_PID=$!
  for _ in $(seq 200); do [[ -f $DIR/state/server.json ]] && break; sleep 0.1; done
  export RUNOUT_SERVER=$(sed -n 's/.*"listen": *"\([^"]*\)".*/\1/p' "$DIR/state/server.json")
  [[ -n $RUNOUT_SERVER ]] || fail "the server did not start: $(cat "$DIR/server.err")"
}
# The job's simulated time by its log's last progress line ("t = 4.123 s, ..."); 0 before any.
simulated() {
  local t
  t=$(grep -o '^[^ ]* t = [0-9.]*' "$DIR/state/logs/$1.log" 2>/dev/null | tail -1 | awk '{print $4}')
  echo "${t:-0}"
}
wait_until_simulated() {  # JOB SECONDS: until the job's run has passed SECONDS of simulated time
  for _ in $(seq 1200); do
    awk -v t="$(simulated "$1")" -v s="$2" 'BEGIN { exit !(t >= s) }' && return 0
    sleep 0.1
  done
  fail "job $1 did not reach t = $2 s: $(tail -3 "$DIR/state/logs/$1.log" 2>/dev/null)"
}

"$RUNOUT" run "$SCENARIO" --out "$DIR/one" --quiet || fail "the one-process run failed"
if [[ $BACKEND == slurm ]]; then
  command -v sbatch >/dev/null || fail "Slurm's commands are missing (scripts/deps.sh installs them)"
  CLUSTER_ENV=$(bash "$CLUSTER" start "$DIR/cluster") && [[ -n $CLUSTER_ENV ]] || fail "the cluster did not start"
  eval "$CLUSTER_ENV"
fi
start_server

# 1. Submitted over 2 ranks, stopped with the server at t >= 5 s, continued after the restart.
JOB=$("$RUNOUT" submit "$SCENARIO" --ranks 2 --quiet | awk '{print $1}')
[[ $JOB == j* ]] || fail "submit gave '$JOB'"
wait_until_simulated "$JOB" 4
grep -q "2 MPI ranks" "$DIR/state/logs/$JOB.log" || fail "the job's log does not say it runs on 2 MPI ranks"
if [[ $BACKEND == slurm ]]; then
  TASK=$(grep -o 'Slurm job [0-9_]*' "$DIR/state/logs/$JOB.log" | tail -1 | awk '{print $3}')
  scontrol show job -o "$TASK" | grep -q "NumTasks=2" || fail "Slurm job $TASK is not one job of 2 tasks: $(scontrol show job -o "$TASK")"
fi
kill -TERM "$SERVER_PID"
wait "$SERVER_PID"
SERVER_PID=
grep -q "interrupted by the server stopping at t = .*continue from its checkpoint" "$DIR/state/logs/$JOB.log" ||
  fail "the stopped job did not end its step with a checkpoint"
start_server
timeout 600 "$RUNOUT" watch "$JOB" >/dev/null 2>&1
"$RUNOUT" status "$JOB" | grep -q "^state *succeeded" || fail "the job did not succeed: $("$RUNOUT" status "$JOB")"
grep -q "continuing from its checkpoint" "$DIR/state/logs/$JOB.log" || fail "the job did not continue from its checkpoint"

# 2. Its results: the uninterrupted run over 2 ranks's byte for byte (the checkpoint carries the
# pressure preconditioner's operators: the continued run builds the same blocks), and one process's
# within the mpi tests' tolerances.
"$RUNOUT" fetch "$JOB" --out "$DIR/many" >/dev/null || fail "fetch failed"
mpirun --oversubscribe -n 2 "$RUNOUT" run "$SCENARIO" --out "$DIR/two" --quiet || fail "the uninterrupted run over 2 ranks failed"
for f in max_depth.tif max_speed.tif max_pressure.tif deposit.tif arrival_time.tif; do
  cmp -s "$DIR/two/$f" "$DIR/many/$f" || fail "$f of the stopped and continued job differs from the uninterrupted run over 2 ranks"
done
"$CHECK" "$DIR/one" "$DIR/many" 2 simulated_s:0 volume_final_m3:1e-9 affected_area_m2:0 max_depth.tif:1e-3 \
  max_speed.tif:1e-2 deposit.tif:1e-3 max_pressure.tif:0.1 || fail "the job's results differ from one process's"

# 3. Cancelled while it runs (another name: another scenario, not answered from the results).
sed 's/"name": "[^"]*"/"name": "to be cancelled"/' "$SCENARIO" > "$DIR/cancel.json"
sed -i "s#\.\./\.\./\.\./scenarios/#$SRC/scenarios/#g" "$DIR/cancel.json"
CJOB=$("$RUNOUT" submit "$DIR/cancel.json" --ranks 2 --quiet | awk '{print $1}')
wait_until_simulated "$CJOB" 2
"$RUNOUT" cancel "$CJOB" >/dev/null || fail "cancel refused"
timeout 120 "$RUNOUT" watch "$CJOB" >/dev/null 2>&1
"$RUNOUT" status "$CJOB" | grep -q "^state *cancelled" || fail "the cancelled job: $("$RUNOUT" status "$CJOB")"
sleep 2
if [[ $BACKEND == slurm ]]; then
  [[ -z $(squeue -h -o %i) ]] || fail "Slurm still runs: $(squeue)"
else
  # The server's children are its workers (mpirun, whose children are the ranks): none is left.
  pgrep -P "$SERVER_PID" >/dev/null && fail "a worker of the server runs on: $(pgrep -a -P "$SERVER_PID")"
fi
echo "job_on_ranks ($BACKEND): a 2-rank 3D job stopped and continued from its checkpoint: the uninterrupted 2-rank run byte for byte, one process's within the mpi tests' tolerances; another cancelled"
