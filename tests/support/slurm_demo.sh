#!/usr/bin/env bash
# demo.sh [DIR] - exercise a throw-away cluster from slurm_cluster.sh the way runout's Slurm
# backend will: job arrays, following tasks, final states/exit codes without slurmdbd,
# killed tasks, requeue, node failure, cancelling a whole array.
#   ./demo.sh 2>&1 | tee demo_output.txt
# Takes about 2 minutes; starts and stops its own cluster (in DIR, default a fresh temp dir).
set -u -o pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
DIR=${1:-$(mktemp -d /tmp/runout-slurm-demo.XXXXXX)}
WORK=$DIR/work
CLUSTER="$HERE/slurm_cluster.sh"

say()  { printf '\n### %s\n' "$*"; }
run()  { printf '$ %s\n' "$*"; "$@"; local rc=$?; [[ $rc -ne 0 ]] && echo "(exit $rc)"; return 0; }
fail() { echo "DEMO FAILED: $*"; exit 1; }

# One line per task of job/array $1 from "scontrol show job -o": the fields the backend needs.
fields() {
    scontrol show job -o "$1" 2>&1 | while read -r line; do
        for k in JobId ArrayJobId ArrayTaskId JobState Reason ExitCode Restarts NodeList; do
            v=$(grep -oE "(^| )$k=[^ ]*" <<<"$line" | head -1 | sed 's/^ //')
            printf '%s ' "${v:-$k=?}"
        done
        echo
    done | sort -t' ' -k3,3V
}
# state of a single task "$1" (e.g. 12_3)
state_of() { scontrol show job -o "$1" 2>/dev/null | grep -oE ' JobState=[^ ]*' | head -1 | cut -d= -f2; }
# wait until task $1 is in one of the states $2 (regex), at most $3 s
wait_state() {
    local end=$(( SECONDS + $3 )) s
    while (( SECONDS < end )); do s=$(state_of "$1"); [[ "$s" =~ ^($2)$ ]] && return 0; sleep 0.5; done
    echo "timeout waiting for $1 to be $2 (is: $(state_of "$1"))"; return 1
}
wait_no_active() {  # no task of job $1 pending/running/completing, at most $2 s
    local end=$(( SECONDS + $2 ))
    while (( SECONDS < end )); do [[ -z "$(squeue -h -r -j "$1" 2>/dev/null)" ]] && return 0; sleep 0.5; done
    return 1
}

cleanup() { say "stop"; local t=$SECONDS; "$CLUSTER" stop "$DIR"; echo "stopped in $(( SECONDS - t )) s"
            echo "leftover daemons: $(pgrep -a 'munged|slurm' | grep -F "$DIR" || echo none)"; }
trap cleanup EXIT

say "start (DIR=$DIR)"
t0=$(date +%s.%N)
eval "$("$CLUSTER" start "$DIR")" || fail "cluster start"
echo "start-up took $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.2f", b-a}') s"
echo "SLURM_CONF=$SLURM_CONF"
run sinfo
run sinfo -h -N -o '%N|%t|%c|%m|%E'
mkdir -p "$WORK" && cd "$WORK" || exit 1

# ------------------------------------------------------------------ (a)
say "(a) sbatch --array=0-4 --parsable: each task writes a file; task 3 exits 7"
cat >member.sh <<'EOF'
#!/bin/bash
echo "member $SLURM_ARRAY_TASK_ID of $SLURM_ARRAY_JOB_ID (job $SLURM_JOB_ID) on $SLURMD_NODENAME" >"out_$SLURM_ARRAY_TASK_ID.txt"
sleep 2
[ "$SLURM_ARRAY_TASK_ID" = 3 ] && exit 7
exit 0
EOF
echo "\$ sbatch --array=0-4 --parsable --job-name=ens --output=$WORK/slurm-%A_%a.out member.sh"
A=$(sbatch --array=0-4 --parsable --job-name=ens --output="$WORK/slurm-%A_%a.out" member.sh) || fail sbatch
echo "$A"

# ------------------------------------------------------------------ (b)
say "(b) follow with squeue -h -r -j $A -o '%i|%A|%F|%K|%T|%r|%N' (changes only)"
prev=""; end=$(( SECONDS + 60 ))
while (( SECONDS < end )); do
    cur=$(squeue -h -r -j "$A" -o '%i|%A|%F|%K|%T|%r|%N' 2>&1 | sort)
    [[ "$cur" != "$prev" ]] && { echo "--- t=$SECONDS s"; echo "${cur:-(no active task)}"; prev=$cur; }
    [[ -z "$cur" ]] && break
    sleep 0.5
done
run ls "$WORK"
run cat out_0.txt out_4.txt
say "(b) final states: sacct (no slurmdbd)"
run sacct -j "$A"
run sacct -c -j "$A" -S 2000-01-01
say "(b) final states: squeue -t all keeps ended tasks for MinJobAge, but no exit code / restarts"
run squeue -h -r -t all -j "$A" -o '%i|%A|%F|%K|%T|%r|%N'
run squeue -h -t all -j "$A" -O 'JobArrayID:12|,ArrayTaskID:4|,State:12|,Reason:18|,exit_code:6|'
say "(b) final states: scontrol show job -o $A (one line per task; raw line of task 3:)"
scontrol show job -o "${A}_3"
echo "--- selected fields per task:"
fields "$A"
say "(b) durable record without slurmdbd: JobCompType=jobcomp/filetxt (one line per run)"
grep -E " ArrayJobId=$A " "$DIR/log/jobcomp.txt" | grep -oE '^JobId=[^ ]*| JobState=[^ ]*| ArrayTaskId=[^ ]*| ExitCode=[^ ]*| NodeList=[^ ]*' | paste -d' ' - - - - -

# ------------------------------------------------------------------ (c)
say "(c) killing running tasks"
cat >long.sh <<'EOF'
#!/bin/bash
echo "start task $SLURM_ARRAY_TASK_ID restart=${SLURM_RESTART_COUNT:-0} $(date +%T)" >>"log_$SLURM_ARRAY_TASK_ID.txt"
if [ "${SLURM_RESTART_COUNT:-0}" -gt 0 ]; then sleep 2; exit 0; fi
sleep 60
rc=$?
echo "sleep ended rc=$rc" >>"log_$SLURM_ARRAY_TASK_ID.txt"
exit $rc
EOF
C=$(sbatch --array=0-2 --parsable --job-name=kill --output="$WORK/slurm-%A_%a.out" long.sh) || fail sbatch
wait_state "${C}_0" RUNNING 30; wait_state "${C}_1" RUNNING 30
run squeue -r -j "$C" -o '%i|%A|%T|%N'
echo "--- c1: scancel --signal=KILL ${C}_0"
run scancel --signal=KILL "${C}_0"
wait_state "${C}_0" 'CANCELLED|FAILED|COMPLETED' 30
run scontrol show job -o "${C}_0"
echo "--- c2: kill -9 of task 1's batch shell (pid from scontrol listpids <jobid>, LOCALID 0)"
J1=$(squeue -h -j "${C}_1" -o %A)
run scontrol listpids "$J1"
P=$(scontrol listpids "$J1" | awk '$3=="batch" && $4=="0" {print $1}')
run kill -9 "$P"
wait_state "${C}_1" 'CANCELLED|FAILED|COMPLETED' 30
echo "--- c3: kill -9 of task 2's payload (the sleep child; the script propagates its status)"
wait_state "${C}_2" RUNNING 30
J2=$(squeue -h -j "${C}_2" -o %A)
sleep 1
P=$(scontrol listpids "$J2" | awk '$3=="batch" && $4=="-" {print $1}' | head -1)
run ps -o pid,ppid,pgid,cmd -p "$P"
run kill -9 "$P"
wait_state "${C}_2" 'CANCELLED|FAILED|COMPLETED' 30
echo "--- results:"
fields "$C"
grep -E " ArrayJobId=$C " "$DIR/log/jobcomp.txt" | grep -oE '^JobId=[^ ]*| JobState=[^ ]*| ArrayTaskId=[^ ]*| ExitCode=[^ ]*' | paste -d' ' - - - -
run cat "$WORK/slurm-${C}_0.out" "$WORK/slurm-${C}_1.out"

# ------------------------------------------------------------------ (d)
say "(d1) scontrol requeue ${C}_1 (FAILED by kill -9): it runs again, Restarts=1"
t=$SECONDS
run scontrol requeue "${C}_1"
fields "${C}_1"
wait_state "${C}_1" RUNNING 60 && echo "running again after $(( SECONDS - t )) s"
wait_state "${C}_1" 'COMPLETED|FAILED' 60 && echo "ended after $(( SECONDS - t )) s"
fields "${C}_1"
run cat log_1.txt
run scontrol requeue "${C}_0"
echo "(requeue of the CANCELLED task:)"; fields "${C}_0"
scancel "$C" 2>/dev/null; wait_no_active "$C" 30

say "(d2) node failure while tasks run: task 0 submitted with --requeue, task 1 with --no-requeue"
R=$(sbatch --array=0 --requeue --parsable --job-name=rq --output=/dev/null long.sh) || fail sbatch
N=$(sbatch --array=0 --no-requeue --parsable --job-name=norq --output=/dev/null long.sh) || fail sbatch
wait_state "${R}_0" RUNNING 30; wait_state "${N}_0" RUNNING 30
run squeue -r -o '%i|%A|%T|%N'
t=$SECONDS
run scontrol update nodename=localhost state=down reason=test
sleep 2
run sinfo -h -N -o '%N|%t|%E'
echo "--- --requeue task:"; fields "$R"
echo "--- --no-requeue task:"; fields "$N"
run squeue -r -t all -o '%i|%T|%r'
echo "--- jobcomp.txt records the killed run of both:"
grep -E " ArrayJobId=($R|$N) " "$DIR/log/jobcomp.txt" | grep -oE '^JobId=[^ ]*| JobState=[^ ]*| ExitCode=[^ ]*' | paste -d' ' - - -
run scontrol update nodename=localhost state=resume
wait_state "${R}_0" RUNNING 60 && echo "requeued task running again $(( SECONDS - t )) s after the node went down"
wait_state "${R}_0" COMPLETED 60
fields "$R"
echo "--- requeue of the NODE_FAIL --no-requeue task (Requeue=0 on the job):"
run scontrol requeue "${N}_0"
run scontrol update jobid="${N}_0" requeue=1
fields "$N"

# ------------------------------------------------------------------ (e)
say "(e) scancel <arrayjob> cancels all tasks, running and pending"
E=$(sbatch --array=0-4 --parsable --job-name=cancel --output=/dev/null long.sh) || fail sbatch
wait_state "${E}_0" RUNNING 30; wait_state "${E}_1" RUNNING 30
run squeue -r -j "$E" -o '%i|%A|%T|%r'
fields "$E"
run scancel "$E"
wait_no_active "$E" 30
fields "$E"
run squeue -h -r -t all -j "$E" -o '%i|%T|%r'
echo "leftover job processes: $(pgrep -a sleep | grep -c 'sleep 60')"
say "demo done"
