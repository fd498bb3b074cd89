#!/usr/bin/env bash
# slurm_cluster.sh - throw-away one-node Slurm cluster for tests.
#
#   slurm_cluster.sh start DIR    start munged + slurmctld + slurmd, everything under DIR,
#                                 wait for the node to be idle, print client env (export ...)
#   slurm_cluster.sh stop DIR     cancel jobs, stop the daemons by their pid files
#                                 (TERM, then KILL after a grace), sweep leftover slurmstepd
#   slurm_cluster.sh status DIR   show daemons / sinfo, exit 0 if all three daemons are alive
#   slurm_cluster.sh env DIR      print the client environment again
#
# Needs (Debian 12 bookworm):
#   apt-get install -y --no-install-recommends munge slurmctld slurmd slurm-client
# Runs as root (SlurmUser=root, SlurmdUser=root).  Uses no systemd and no system path:
# no /etc/slurm, /etc/munge, /run/munge; two clusters (different DIRs) can run side by side.
#
# Tunables (environment, all optional):
#   SLURM_PROTO_START_TIMEOUT  seconds to wait for the node to become idle   (default 60)
#   SLURM_PROTO_STOP_GRACE     seconds between TERM and KILL                 (default 10)
#   SLURM_PROTO_MIN_JOB_AGE    MinJobAge: seconds ended jobs stay visible    (default 300)
#   SLURM_PROTO_CRED_EXPIRE    AuthInfo cred_expire; also the delay before a
#                              requeued job may start again                  (default 10)
#   SLURM_PROTO_NODENAME       NodeName                                       (default localhost)
#   SLURM_PROTO_DEBUG          SlurmctldDebug/SlurmdDebug level              (default info)
set -u -o pipefail

MARKER_VAR=SLURM_PROTO_CLUSTER_DIR   # put in the daemons' environment; inherited by slurmstepd

die() { echo "slurm_cluster.sh: error: $*" >&2; exit 1; }
log() { echo "slurm_cluster.sh: $*" >&2; }

usage() {
    sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}

# ---------------------------------------------------------------- helpers
abspath() { realpath -m -- "$1"; }

need() { command -v "$1" >/dev/null 2>&1 || die "'$1' not found; install: apt-get install -y --no-install-recommends munge slurmctld slurmd slurm-client"; }

# Is TCP port $1 in use (any state, IPv4 or IPv6)?  Pure /proc, no ss/netstat/python needed.
port_in_use() {
    local hex; hex=$(printf '%04X' "$1")
    cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | awk -v h="$hex" 'NR>1 { split($2,a,":"); if (a[2]==h) {found=1} } END { exit !found }'
}

# Print a free TCP port from 20000-59999 not in the space-separated list $1.
pick_port() {
    local avoid=" ${1:-} " p i
    for i in $(seq 1 200); do
        p=$(( 20000 + (RANDOM * 32768 + RANDOM) % 40000 ))
        [[ "$avoid" == *" $p "* ]] && continue
        port_in_use "$p" && continue
        echo "$p"; return 0
    done
    die "could not find a free TCP port"
}

# pid from pid file $1, if that process is alive and its command line or environment
# mentions our DIR (so we never signal a daemon we did not start, e.g. after pid reuse).
our_pid() {
    local pf=$1 pid
    [[ -s "$pf" ]] || return 1
    pid=$(tr -dc '0-9' <"$pf")
    [[ -n "$pid" ]] || return 1
    kill -0 "$pid" 2>/dev/null || return 1
    is_ours "$pid" || return 1
    echo "$pid"
}

is_ours() {
    local pid=$1
    # zombies are not ours to kill
    [[ "$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)" == Z ]] && return 1
    tr '\0' '\n' 2>/dev/null <"/proc/$pid/cmdline" | grep -qF -- "$DIR/" && return 0
    tr '\0' '\n' 2>/dev/null <"/proc/$pid/environ" | grep -qxF -- "$MARKER_VAR=$DIR" && return 0
    return 1
}

# All live processes carrying our marker in their environment (slurmstepd, job tasks), and
# their descendants.
marked_pids() {
    local p seeds=() all
    for p in /proc/[0-9]*; do
        p=${p#/proc/}
        [[ "$p" == "$$" ]] && continue
        tr '\0' '\n' 2>/dev/null <"/proc/$p/environ" | grep -qxF -- "$MARKER_VAR=$DIR" && seeds+=("$p")
    done
    [[ ${#seeds[@]} -eq 0 ]] && return 0
    # add descendants (ppid walk)
    all=$(for p in /proc/[0-9]*; do awk '{print $1, $4}' "$p/stat" 2>/dev/null; done |
        awk -v s="${seeds[*]}" 'BEGIN{n=split(s,a," "); for(i=1;i<=n;i++) keep[a[i]]=1}
             {par[$1]=$2} END{ch=1; while(ch){ch=0; for(p in par) if(!(p in keep) && (par[p] in keep)){keep[p]=1; ch=1}}
             for(k in keep) print k}')
    for p in $all; do [[ "$p" != "$$" ]] && echo "$p"; done
}

tail_logs() {
    local f
    for f in "$DIR"/log/munged.log "$DIR"/log/slurmctld.log "$DIR"/log/slurmd.log \
             "$DIR"/log/slurmctld.out "$DIR"/log/slurmd.out; do
        [[ -s "$f" ]] || continue
        echo "----- tail -n 20 $f" >&2
        tail -n 20 "$f" >&2
    done
}

print_env() {
    echo "export SLURM_CONF=$DIR/etc/slurm.conf"
    # libmunge has no socket env var; Slurm's clients read AuthInfo=socket=... from SLURM_CONF.
    # This one is only for the munge/unmunge CLIs: munge -S "\$SLURM_PROTO_MUNGE_SOCKET".
    echo "export SLURM_PROTO_MUNGE_SOCKET=$DIR/run/munge.sock"
}

# Wait until condition command "$@" succeeds or $timeout s; returns 1 on timeout.
wait_for() {
    local timeout=$1; shift
    local end=$(( SECONDS + timeout ))
    while (( SECONDS < end )); do
        "$@" && return 0
        sleep 0.2
    done
    "$@"
}

# ---------------------------------------------------------------- start
start_munged() {
    rm -f "$DIR/run/munge.sock" "$DIR/run/munge.sock.lock" "$DIR/run/munged.pid"
    env "$MARKER_VAR=$DIR" munged \
        --socket="$DIR/run/munge.sock" \
        --key-file="$DIR/munge/munge.key" \
        --log-file="$DIR/log/munged.log" \
        --pid-file="$DIR/run/munged.pid" \
        --seed-file="$DIR/munge/munged.seed" \
        </dev/null >>"$DIR/log/munged.out" 2>&1 || { tail_logs; die "munged failed to start"; }
    wait_for 10 test -S "$DIR/run/munge.sock" || { tail_logs; die "munged socket did not appear"; }
    munge -S "$DIR/run/munge.sock" -n 2>/dev/null | unmunge -S "$DIR/run/munge.sock" >/dev/null 2>&1 ||
        { tail_logs; die "munge/unmunge round trip failed"; }
}

write_conf() {
    local ctld_port=$1 slurmd_port=$2 hw cpus mem topo nodename cluster
    nodename=${SLURM_PROTO_NODENAME:-localhost}
    # CPUs / topology / RealMemory as slurmd itself detects them (slurmd -C), else nproc/meminfo.
    hw=$(slurmd -C 2>/dev/null | head -1)
    cpus=$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<<"$hw")
    mem=$(sed -n 's/.* RealMemory=\([0-9]*\).*/\1/p' <<<"$hw")
    topo=$(grep -oE '(Boards|SocketsPerBoard|CoresPerSocket|ThreadsPerCore)=[0-9]+' <<<"$hw" | tr '\n' ' ')
    [[ -n "$cpus" ]] || { cpus=$(nproc); topo=""; }
    [[ -n "$mem" ]] || mem=$(( $(awk '/MemTotal/{print $2}' /proc/meminfo) / 1024 ))
    # keep a little memory back so that RealMemory never exceeds what slurmd detects
    mem=$(( mem > 1024 ? mem - 256 : mem ))
    # ClusterName: lower case, <= 40 chars; unique per DIR (state files are per cluster name)
    cluster="runout$(printf '%s' "$DIR" | cksum | awk '{print $1}')"
    cat >"$DIR/etc/slurm.conf" <<EOF
# generated by slurm_cluster.sh for $DIR
ClusterName=$cluster
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$DIR/run/munge.sock,cred_expire=${SLURM_PROTO_CRED_EXPIRE:-10}
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool/slurmd
SlurmctldPidFile=$DIR/run/slurmctld.pid
SlurmdPidFile=$DIR/run/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=${SLURM_PROTO_DEBUG:-info}
SlurmdDebug=${SLURM_PROTO_DEBUG:-info}
PlugStackConfig=$DIR/etc/plugstack.conf
TmpFS=$DIR/tmp
MailProg=/bin/true
# no cgroups (containers, gVisor, no systemd).  proctrack/pgid, not linuxproc: linuxproc
# follows parent links, so a child orphaned by a kill -9 of the batch script escapes it.
ProctrackType=proctrack/pgid
TaskPlugin=task/none
# marks every job process (see stop: sweeps leftovers by this marker)
TaskProlog=$DIR/etc/task_prolog.sh
JobAcctGatherType=jobacct_gather/none
# no slurmdbd; a plain-text completion record per finished job instead
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/log/jobcomp.txt
SchedulerType=sched/backfill
# short scheduling passes: a requeued task is retried within ~2 s of becoming eligible
SchedulerParameters=sched_interval=2,bf_interval=2
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
# 1: a node DOWN for not responding returns when slurmd registers again; a node set DOWN by
# "scontrol update state=down" stays down until "scontrol update nodename=... state=resume"
ReturnToService=1
JobRequeue=1
MinJobAge=${SLURM_PROTO_MIN_JOB_AGE:-300}
KillWait=5
InactiveLimit=0
Waittime=0
SlurmdTimeout=300
SlurmctldTimeout=120
NodeName=$nodename NodeAddr=127.0.0.1 NodeHostname=$nodename CPUs=$cpus ${topo}RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$nodename Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
    : >"$DIR/etc/plugstack.conf"
    printf '#!/bin/sh\necho "export %s=%s"\n' "$MARKER_VAR" "$DIR" >"$DIR/etc/task_prolog.sh"
    chmod 0755 "$DIR/etc/task_prolog.sh"
}

# Launch slurm daemon $1 (slurmctld|slurmd) in the foreground (-D) in its own session.
launch() {
    local name=$1; shift
    rm -f "$DIR/run/$name.pid"
    setsid env "$MARKER_VAR=$DIR" SLURM_CONF="$DIR/etc/slurm.conf" \
        "$name" -D -f "$DIR/etc/slurm.conf" "$@" </dev/null >>"$DIR/log/$name.out" 2>&1 &
    echo $! >"$DIR/run/$name.launcher.pid"
}

alive() { our_pid "$DIR/run/$1.pid" >/dev/null || { [[ -s "$DIR/run/$1.launcher.pid" ]] && our_pid "$DIR/run/$1.launcher.pid" >/dev/null; }; }

ctld_up() { scontrol ping 2>/dev/null | grep -q 'is UP'; }
node_idle() { [[ "$(sinfo -h -N -o '%t' 2>/dev/null | head -1)" == idle ]]; }

cmd_start() {
    local timeout=${SLURM_PROTO_START_TIMEOUT:-60} t0 try ctld_port slurmd_port state
    need munged; need mungekey; need munge; need unmunge
    need slurmctld; need slurmd; need sinfo; need scontrol; need squeue; need sbatch
    [[ $EUID -eq 0 ]] || log "warning: not root; SlurmUser=root/SlurmdUser=root will not work as non-root"
    t0=$(date +%s.%N)
    for d in munged slurmctld slurmd; do
        our_pid "$DIR/run/$d.pid" >/dev/null && die "$d of $DIR is already running; run: $0 stop $DIR"
    done
    mkdir -p "$DIR"/{etc,munge,run,log,state,spool/slurmd,tmp}
    chmod 0755 "$DIR" "$DIR"/{etc,run,log,spool,tmp}     # munged: socket dir must be a+x
    chmod 0700 "$DIR/munge" "$DIR/state" "$DIR/spool/slurmd"
    rm -f "$DIR"/run/*.pid
    if [[ ! -s "$DIR/munge/munge.key" ]]; then
        mungekey -c -b 1024 -k "$DIR/munge/munge.key" 2>/dev/null ||
            dd if=/dev/urandom of="$DIR/munge/munge.key" bs=128 count=1 status=none
    fi
    chmod 0400 "$DIR/munge/munge.key"          # munged refuses group/other-readable keys
    export SLURM_CONF="$DIR/etc/slurm.conf"

    start_munged

    # Ports: picked free now; if a concurrent start (or anything else) binds one of them first,
    # the daemon dies with "Address already in use" and we retry with fresh ports.
    local end outcome
    for try in 1 2 3 4; do
        ctld_port=$(pick_port)
        slurmd_port=$(pick_port "$ctld_port")
        write_conf "$ctld_port" "$slurmd_port"
        launch slurmctld
        outcome=""
        end=$(( SECONDS + 20 ))
        while [[ -z "$outcome" ]]; do
            if ctld_up; then outcome=up
            elif ! alive slurmctld; then outcome=died
            elif (( SECONDS >= end )); then outcome=timeout
            else sleep 0.2; fi
        done
        if [[ $outcome == up ]]; then
            launch slurmd -N "${SLURM_PROTO_NODENAME:-localhost}"
            end=$(( SECONDS + timeout ))
            while [[ $outcome == up ]]; do
                if node_idle; then outcome=idle
                elif ! alive slurmd; then outcome=slurmd_died
                elif (( SECONDS >= end )); then outcome=slurmd_timeout
                else sleep 0.2; fi
            done
        fi
        [[ $outcome == idle ]] && break
        if (( try < 4 )) && grep -qs 'Address already in use' "$DIR"/log/slurm*.log "$DIR"/log/slurm*.out; then
            log "port $ctld_port or $slurmd_port already in use; retrying with other ports"
            stop_one slurmd 3; stop_one slurmctld 3
            for f in slurmctld.log slurmctld.out slurmd.log slurmd.out; do
                [[ -e "$DIR/log/$f" ]] && mv -f "$DIR/log/$f" "$DIR/log/$f.try$try"
            done
            continue
        fi
        state=$(sinfo -h -N -o '%N %t %E' 2>&1)
        tail_logs; cmd_stop_quiet
        case $outcome in
            died)           die "slurmctld exited during start-up" ;;
            timeout)        die "slurmctld did not answer 'scontrol ping' within 20 s" ;;
            slurmd_died)    die "slurmd exited during start-up (sinfo: $state)" ;;
            *)              die "node not idle within $timeout s (sinfo: $state)" ;;
        esac
    done
    log "cluster up in $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b-a}') s (slurmctld :$ctld_port, slurmd :$slurmd_port)"
    print_env
}

# ---------------------------------------------------------------- stop
# stop_one NAME GRACE: TERM the daemon from DIR/run/NAME.pid (or its launcher), KILL after GRACE s.
stop_one() {
    local name=$1 grace=$2 pids=() p
    for p in "$DIR/run/$name.pid" "$DIR/run/$name.launcher.pid"; do
        p=$(our_pid "$p") && pids+=("$p")
    done
    [[ ${#pids[@]} -eq 0 ]] && { rm -f "$DIR/run/$name.pid" "$DIR/run/$name.launcher.pid"; return 0; }
    pids=($(printf '%s\n' "${pids[@]}" | sort -u))
    kill -TERM "${pids[@]}" 2>/dev/null
    local end=$(( SECONDS + grace ))
    while (( SECONDS < end )); do
        local left=()
        for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && is_ours "$p" && left+=("$p"); done
        [[ ${#left[@]} -eq 0 ]] && break
        sleep 0.2
    done
    for p in "${pids[@]}"; do
        if kill -0 "$p" 2>/dev/null && is_ours "$p"; then
            log "$name (pid $p) ignored TERM for ${grace}s; sending KILL"
            kill -KILL "$p" 2>/dev/null
        fi
    done
    rm -f "$DIR/run/$name.pid" "$DIR/run/$name.launcher.pid"
}

cmd_stop() {
    local grace=${SLURM_PROTO_STOP_GRACE:-10} p
    [[ -d "$DIR/run" ]] || { log "nothing to stop in $DIR"; return 0; }
    export SLURM_CONF="$DIR/etc/slurm.conf"
    # 1. cancel all jobs while the daemons are still there, so slurmstepd/tasks end cleanly
    if our_pid "$DIR/run/slurmctld.pid" >/dev/null && [[ -n "$(squeue -h -o %i 2>/dev/null)" ]]; then
        scancel --full --signal=KILL $(squeue -h -o %A 2>/dev/null) 2>/dev/null
        scancel $(squeue -h -o %A 2>/dev/null) 2>/dev/null
        wait_for 10 bash -c '[[ -z "$(squeue -h -t running,completing -o %i 2>/dev/null)" ]]' || true
    fi
    # 2. daemons, in reverse start order
    stop_one slurmd "$grace"
    stop_one slurmctld "$grace"
    # 3. anything still carrying our marker (slurmstepd, job processes)
    local left; left=$(marked_pids | grep -vxF "$(our_pid "$DIR/run/munged.pid" || echo none)")
    if [[ -n "$left" ]]; then
        log "killing leftover job processes: $(echo $left)"
        kill -KILL $left 2>/dev/null
    fi
    stop_one munged "$grace"
    rm -f "$DIR/run/munge.sock" "$DIR/run/munge.sock.lock"
    # final check
    left=$(marked_pids)
    [[ -z "$left" ]] || { log "warning: processes still alive: $(echo $left)"; return 1; }
    return 0
}

cmd_stop_quiet() { SLURM_PROTO_STOP_GRACE=3 cmd_stop >/dev/null 2>&1 || true; }

cmd_status() {
    local rc=0 d p
    for d in munged slurmctld slurmd; do
        if p=$(our_pid "$DIR/run/$d.pid"); then echo "$d: running (pid $p)"; else echo "$d: not running"; rc=1; fi
    done
    if [[ $rc -eq 0 ]]; then SLURM_CONF="$DIR/etc/slurm.conf" sinfo -N -o '%N %t %c %m %E'; fi
    return $rc
}

# ---------------------------------------------------------------- main
[[ $# -eq 2 ]] || usage
cmd=$1
DIR=$(abspath "$2") || die "bad directory $2"
case "$cmd" in
    start)  cmd_start ;;
    stop)   cmd_stop ;;
    status) cmd_status ;;
    env)    print_env ;;
    *)      usage ;;
esac
