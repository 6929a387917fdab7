#!/usr/bin/env bash
# A one-node Slurm cluster on localhost, for trying and testing the job
# scripts in deploy/slurm/ (scripts/slurm-test.sh uses it).
#
# Usage:
#   scripts/slurm.sh start    # start munged, slurmctld and slurmd; wait for the node
#   scripts/slurm.sh status   # the daemons' PIDs, `sinfo`, `squeue`; 0 iff all 3 run
#   scripts/slurm.sh stop     # cancel the cluster's jobs, stop the daemons it started
#   scripts/slurm.sh env      # prints `export SLURM_CONF=...` (eval "$(scripts/slurm.sh env)")
#
# Client commands (sbatch, squeue, scancel, sinfo, ...) reach this cluster
# through SLURM_CONF=<state>/slurm.conf; `start` prints the line to export.
#
# Everything lives in one state directory, $SLURM_STATE_DIR (default
# target/slurm/ in the repository): slurm.conf, the munge key and socket,
# the controller's state, slurmd's spool, logs and PID files. Nothing under
# /etc is read or written, and a system munged or Slurm is left alone: this
# cluster has its own munged on its own socket and its own ports.
#
# Environment:
#   SLURM_STATE_DIR     state directory (default: <repo>/target/slurm)
#   SLURM_CTLD_PORT     slurmctld's port (default 16817)
#   SLURMD_PORT         slurmd's port (default 16818)
#   SLURM_START_TIMEOUT seconds `start` waits for the node to be idle (default 45)
#
# Requirements: Debian's slurm-wlm (slurmctld, slurmd, slurm-client) and
# munge packages (scripts/setup.sh installs them), and root: slurmd runs
# jobs as their submitting user, and SlurmUser is root here. No systemd and
# no cgroups are needed: processes are tracked through /proc
# (proctrack/linuxproc), tasks are not confined (task/none), and memory is
# not a scheduled resource.
#
# `stop` cancels the cluster's jobs, then kills exactly the processes
# `start` recorded in <state>/run/*.pid (munged, slurmctld, slurmd), after
# checking each PID still runs that daemon with this cluster's files; it
# never kills by name. `start` and `stop` are idempotent: `start` on a
# running cluster only waits for the node, `stop` on a stopped one does
# nothing.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
state=${SLURM_STATE_DIR:-$repo/target/slurm}
ctld_port=${SLURM_CTLD_PORT:-16817}
slurmd_port=${SLURMD_PORT:-16818}
start_timeout=${SLURM_START_TIMEOUT:-45}

conf=$state/slurm.conf
run=$state/run
logs=$state/log
munge_dir=$state/munge
munge_socket=$munge_dir/munge.socket

say() { printf 'slurm.sh: %s\n' "$*"; }
err() { printf 'slurm.sh: %s\n' "$*" >&2; }

usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "${BASH_SOURCE[0]}" >&2
    exit 2
}

# The tail of every log this cluster writes, for a failure's message.
log_tails() {
    local f
    for f in "$logs"/*.log "$logs"/*.out; do
        [[ -s "$f" ]] || continue
        printf '\n----- %s (last 25 lines) -----\n' "$f" >&2
        tail -n 25 "$f" >&2
    done
}

die() {
    err "$*"
    log_tails
    exit 1
}

# Whether process $1 exists and has not exited (a zombie has: the daemons'
# parent, once this script has exited, may reap them late).
running() {
    local stat
    stat=$(cat "/proc/$1/stat" 2>/dev/null) || return 1
    stat=${stat##*) }
    [[ "${stat:0:1}" != Z ]]
}

# The PID recorded for daemon $1, if that process still runs it with this
# cluster's files; nothing (status 1) otherwise.
live_pid() {
    local name=$1 pid cmdline
    [[ -f "$run/$name.pid" ]] || return 1
    pid=$(<"$run/$name.pid")
    [[ "$pid" =~ ^[0-9]+$ ]] || return 1
    running "$pid" || return 1
    cmdline=$(tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null) || return 1
    # The daemon's own name and a path of this cluster's state directory
    # (its config or munge socket): a recycled PID fails one of the two.
    [[ "$cmdline" == *"$name"* && "$cmdline" == *"$state/"* ]] || return 1
    printf '%s\n' "$pid"
}

require_tools() {
    local missing=() tool
    for tool in munged slurmctld slurmd sinfo scontrol; do
        command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
    done
    if ((${#missing[@]})); then
        err "not found on PATH: ${missing[*]}"
        err "install Debian's slurm-wlm and munge (scripts/setup.sh does), as root"
        exit 3
    fi
    if [[ $(id -u) -ne 0 ]]; then
        err "this cluster runs its daemons as root (SlurmUser=root); run as root"
        exit 3
    fi
}

write_conf() {
    local cpus mem_mb
    cpus=$(nproc)
    # 90% of the memory, in MB: a RealMemory above what slurmd measures
    # would mark the node invalid.
    mem_mb=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
    cat >"$conf.tmp" <<EOF
# Written by scripts/slurm.sh: a one-node cluster on localhost.
ClusterName=fractal
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root

# munge, through this cluster's own munged and socket.
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$munge_socket

# No systemd, no cgroups: processes tracked through /proc, tasks unconfined,
# no accounting daemon. Finished jobs are logged to a text file instead.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$logs/jobcomp.log
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true

# CPUs are the scheduled resource (memory is not, so a job asks none).
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
# The node is what this file says, whatever slurmd detects (containers
# often report other sockets, cores or memory than they may use).
SlurmdParameters=config_overrides
ReturnToService=2
# A cancelled job's processes get SIGTERM, then SIGKILL 5 s later.
KillWait=5
# Finished jobs stay visible to scontrol/squeue for 10 minutes.
MinJobAge=600

StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$run/slurmctld.pid
SlurmdPidFile=$run/slurmd.pid
SlurmctldLogFile=$logs/slurmctld.log
SlurmdLogFile=$logs/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info

NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
    mv "$conf.tmp" "$conf"
}

start_munged() {
    if live_pid munged >/dev/null; then
        return
    fi
    if ((${#munge_socket} > 100)); then
        die "the munge socket path is too long for a Unix socket (${#munge_socket} > 100): set SLURM_STATE_DIR to a shorter path"
    fi
    mkdir -p "$munge_dir"
    # Clients of every user reach munged through this directory; the key
    # inside it stays readable by root only.
    chmod 0755 "$munge_dir"
    if [[ ! -s "$munge_dir/munge.key" ]]; then
        if command -v mungekey >/dev/null 2>&1; then
            mungekey --create --keyfile="$munge_dir/munge.key"
        else
            dd if=/dev/urandom of="$munge_dir/munge.key" bs=1024 count=1 status=none
        fi
    fi
    chmod 0600 "$munge_dir/munge.key"
    rm -f "$munge_socket" "$munge_socket.lock"
    # --force: the state directory lies in a checkout whose parents munged
    # may find too open (it refuses group- or world-writable ones).
    nohup munged --foreground --force \
        --socket="$munge_socket" \
        --key-file="$munge_dir/munge.key" \
        --pid-file="$munge_dir/munged.pid" \
        --seed-file="$munge_dir/munged.seed" \
        --log-file="$logs/munged.log" \
        </dev/null >>"$logs/munged.out" 2>&1 &
    local pid=$!
    echo "$pid" >"$run/munged.pid"
    local i
    for ((i = 0; i < 100; i++)); do
        [[ -S "$munge_socket" ]] && return
        running "$pid" || die "munged exited at start"
        sleep 0.1
    done
    die "munged did not create its socket $munge_socket within 10 s"
}

# start_daemon NAME ARGS...: run a Slurm daemon in the foreground (-D) in
# the background of this script, recording its PID.
start_daemon() {
    local name=$1
    shift
    if live_pid "$name" >/dev/null; then
        return
    fi
    nohup "$name" -D -f "$conf" "$@" </dev/null >>"$logs/$name.out" 2>&1 &
    echo $! >"$run/$name.pid"
}

node_state() {
    # %T: the node's state in full (idle, mixed, allocated, down*, ...).
    timeout 5 sinfo --noheader --nodes=localhost --format=%T 2>/dev/null | head -n 1
}

cmd_start() {
    require_tools
    mkdir -p "$state" "$run" "$logs" "$state/ctld" "$state/spool"
    local t0=$SECONDS
    # A running daemon keeps the file it started with: rewrite it only when
    # neither runs (so a changed port applies on the next start).
    if ! live_pid slurmctld >/dev/null && ! live_pid slurmd >/dev/null; then
        write_conf
    fi
    export SLURM_CONF=$conf
    start_munged
    start_daemon slurmctld
    start_daemon slurmd -N localhost
    local s=""
    while ((SECONDS - t0 < start_timeout)); do
        running "$(<"$run/slurmctld.pid")" || die "slurmctld exited at start"
        running "$(<"$run/slurmd.pid")" || die "slurmd exited at start"
        s=$(node_state || true)
        case "$s" in
        idle | mixed | allocated | completing) break ;;
        down* | drain* | fail*)
            # A node that was down when the controller last stopped comes
            # back by itself (ReturnToService=2) once slurmd registers.
            ;;
        esac
        sleep 0.5
    done
    case "$s" in
    idle | mixed | allocated | completing) ;;
    *) die "the node was not idle after ${start_timeout}s (sinfo says: '${s:-no answer}')" ;;
    esac
    say "cluster up in $((SECONDS - t0))s (node: $s)"
    say "for client commands: export SLURM_CONF=$conf"
}

# Cancel the cluster's jobs and wait (bounded) until none is left, so that
# no job step outlives its slurmd.
cancel_jobs() {
    live_pid slurmctld >/dev/null || return 0
    timeout 10 scancel --full --quiet --partition=debug 2>/dev/null || true
    local i left
    for ((i = 0; i < 40; i++)); do
        left=$(timeout 5 squeue --noheader --states=all --format=%T 2>/dev/null |
            grep -cE 'RUNNING|COMPLETING|SUSPENDED|STOPPED' || true)
        [[ "$left" == 0 ]] && return 0
        sleep 0.5
    done
    err "jobs still running after 20 s; stopping the daemons anyway"
}

stop_one() {
    local name=$1 pid i
    if ! pid=$(live_pid "$name"); then
        rm -f "$run/$name.pid"
        return
    fi
    kill -TERM "$pid" 2>/dev/null || true
    for ((i = 0; i < 100; i++)); do
        running "$pid" || break
        sleep 0.1
    done
    if running "$pid"; then
        err "$name ($pid) still running after 10 s; sending SIGKILL"
        kill -KILL "$pid" 2>/dev/null || true
        sleep 0.2
    fi
    rm -f "$run/$name.pid"
    say "stopped $name ($pid)"
}

cmd_stop() {
    export SLURM_CONF=$conf
    [[ -d "$run" ]] || return 0
    cancel_jobs
    stop_one slurmd
    stop_one slurmctld
    stop_one munged
}

cmd_status() {
    export SLURM_CONF=$conf
    local name pid up=0
    for name in munged slurmctld slurmd; do
        if pid=$(live_pid "$name"); then
            say "$name running (pid $pid)"
            up=$((up + 1))
        else
            say "$name not running"
        fi
    done
    if live_pid slurmctld >/dev/null; then
        timeout 10 sinfo || true
        timeout 10 squeue || true
    fi
    ((up == 3))
}

case "${1:-}" in
start) cmd_start ;;
stop) cmd_stop ;;
status) cmd_status ;;
env) printf 'export SLURM_CONF=%q\n' "$conf" ;;
*) usage ;;
esac
