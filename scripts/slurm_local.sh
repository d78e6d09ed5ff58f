#!/usr/bin/env bash
# slurm_local.sh - start/stop a private, single-node Slurm cluster for tests.
#
# Usage:
#   eval "$(scripts/slurm_local.sh start DIR)"   # start; prints `export NAME=value`
#   sbatch ...; squeue ...; scontrol ...          # client commands use $SLURM_CONF
#   scripts/slurm_local.sh stop DIR               # stop everything started for DIR
#   scripts/slurm_local.sh status DIR             # report which daemons run
#   scripts/slurm_local.sh env DIR                # re-print the exports
#
# Everything lives under DIR (created if missing): slurm.conf, a fresh munge
# key, a private munged (own socket, never the system one), slurmctld state,
# slurmd spool, logs and pid files.  Nothing system-wide is read or touched.
#
# `start` waits (up to SLURM_LOCAL_TIMEOUT seconds, default 60) until the node
# is idle, then prints on stdout only the environment the client commands need
# (`export SLURM_CONF=DIR/slurm.conf` ...); all chatter goes to stderr.  Calling
# `start` again on a DIR whose cluster is running restarts it cleanly (jobs and
# job ids are reset).  On failure it prints one line naming what failed and the
# log file to read, stops whatever it started and exits 1.
#
# Exit codes: 0 ok; 1 failure; 2 usage error; 3 cannot run here (Slurm/munge
# not installed, or not root - slurmd must run as root).  Tests skip on 3.
#
# The cluster: partition `tgnav` (default, no time limit), one node named
# `hostname -s` at 127.0.0.1 with CPUs=$(nproc), select/cons_tres + CR_Core
# (one 1-CPU task per core at once), proctrack/linuxproc, task/none, no
# cgroups, no accounting database (sacct does not work; use squeue/scontrol,
# finished jobs stay visible for MinJobAge=300 s).  `stop` cancels jobs, then
# SIGTERMs slurmd, slurmctld, munged (by pid file, checking the process really
# belongs to DIR), waits up to 10 s each, then SIGKILLs.  Logs stay in DIR.
set -euo pipefail

readonly PROG="slurm_local"
readonly PARTITION="tgnav"

log() { printf '%s: %s\n' "$PROG" "$*" >&2; }

usage() {
    echo "usage: $0 {start|stop|status|env} DIR" >&2
    exit 2
}

# ---------------------------------------------------------------- checks ----

check_installed() {
    local missing=() b
    for b in slurmctld slurmd munged sbatch squeue sinfo scontrol scancel; do
        if ! command -v "$b" >/dev/null 2>&1 &&
            [[ ! -x "/usr/sbin/$b" && ! -x "/usr/bin/$b" ]]; then
            missing+=("$b")
        fi
    done
    if ((${#missing[@]})); then
        echo "$PROG: not installed: ${missing[*]}" >&2
        exit 3
    fi
}

check_root() {
    if [[ "$(id -u)" != 0 ]]; then
        echo "$PROG: must run as root (slurmd needs root); skipping" >&2
        exit 3
    fi
}

# Resolve a binary that may live in /usr/sbin (not always on a user's PATH).
bin() {
    local b="$1" p
    if p="$(command -v "$b" 2>/dev/null)"; then
        printf '%s\n' "$p"
    elif [[ -x "/usr/sbin/$b" ]]; then
        printf '%s\n' "/usr/sbin/$b"
    else
        printf '%s\n' "/usr/bin/$b"
    fi
}

# -------------------------------------------------------------- paths -------

set_paths() {
    DIR="$1"
    mkdir -p "$DIR"
    DIR="$(cd "$DIR" && pwd -P)"
    CONF="$DIR/slurm.conf"
    MUNGE_DIR="$DIR/munge"
    MUNGE_KEY="$MUNGE_DIR/munge.key"
    MUNGE_SOCK="$MUNGE_DIR/munge.sock"
    MUNGE_PID="$MUNGE_DIR/munged.pid"
    MUNGE_LOG="$DIR/log/munged.log"
    STATE_DIR="$DIR/state"
    SPOOL_DIR="$DIR/spool"
    LOG_DIR="$DIR/log"
    CTLD_LOG="$LOG_DIR/slurmctld.log"
    SLURMD_LOG="$LOG_DIR/slurmd.log"
    CTLD_PID="$DIR/run/slurmctld.pid"
    SLURMD_PID="$DIR/run/slurmd.pid"
}

# ------------------------------------------------------------ processes -----

# pid_of PIDFILE COMM: print the pid if it is alive, is named COMM and its
# command line mentions DIR (so a recycled pid is never mistaken for ours).
pid_of() {
    local pidfile="$1" comm="$2" pid
    [[ -r "$pidfile" ]] || return 1
    pid="$(tr -dc '0-9' <"$pidfile" 2>/dev/null || true)"
    [[ -n "$pid" && -d "/proc/$pid" ]] || return 1
    [[ "$(cat "/proc/$pid/comm" 2>/dev/null || true)" == "$comm" ]] || return 1
    tr '\0' ' ' <"/proc/$pid/cmdline" 2>/dev/null | grep -qF -- "$DIR/" ||
        return 1
    printf '%s\n' "$pid"
}

# kill_wait PID NAME: SIGTERM, wait up to 10 s, then SIGKILL.
kill_wait() {
    local pid="$1" name="$2" i
    kill -TERM "$pid" 2>/dev/null || return 0
    for ((i = 0; i < 100; i++)); do
        [[ -d "/proc/$pid" ]] || return 0
        # a zombie child of ours counts as gone
        [[ "$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)" == Z ]] && return 0
        sleep 0.1
    done
    log "$name (pid $pid) ignored SIGTERM for 10 s; sending SIGKILL"
    kill -KILL "$pid" 2>/dev/null || true
    for ((i = 0; i < 50; i++)); do
        [[ -d "/proc/$pid" ]] || return 0
        sleep 0.1
    done
}

stop_daemon() {
    local pidfile="$1" comm="$2" pid
    if pid="$(pid_of "$pidfile" "$comm")"; then
        log "stopping $comm (pid $pid)"
        kill_wait "$pid" "$comm"
    fi
    rm -f "$pidfile"
}

# slurmstepd processes of this cluster: they own unix sockets in SPOOL_DIR.
stepd_pids() {
    local p fd inode inodes
    inodes="$(awk -v d="$SPOOL_DIR/" 'index($8, d) == 1 {print $7}' \
        /proc/net/unix 2>/dev/null || true)"
    [[ -n "$inodes" ]] || return 0
    for p in /proc/[0-9]*; do
        [[ "$(cat "$p/comm" 2>/dev/null || true)" == slurmstepd ]] || continue
        for fd in "$p"/fd/*; do
            inode="$(readlink "$fd" 2>/dev/null || true)"
            [[ "$inode" == socket:\[*\] ]] || continue
            inode="${inode#socket:[}"
            inode="${inode%]}"
            if grep -qx -- "$inode" <<<"$inodes"; then
                echo "${p#/proc/}"
                break
            fi
        done
    done
}

cancel_jobs() {
    local ids i
    pid_of "$CTLD_PID" slurmctld >/dev/null || return 0
    ids="$(SLURM_CONF="$CONF" timeout 10 squeue -h -o %A 2>/dev/null || true)"
    [[ -n "$ids" ]] || return 0
    log "cancelling jobs: $(tr '\n' ' ' <<<"$ids")"
    # shellcheck disable=SC2086  # word splitting of the id list is intended
    SLURM_CONF="$CONF" timeout 10 scancel $ids 2>/dev/null || true
    for ((i = 0; i < 50; i++)); do
        ids="$(SLURM_CONF="$CONF" timeout 5 squeue -h -o %A 2>/dev/null || true)"
        [[ -z "$ids" ]] && return 0
        sleep 0.2
    done
}

do_stop() {
    local p
    cancel_jobs
    stop_daemon "$SLURMD_PID" slurmd
    for p in $(stepd_pids); do
        log "stopping leftover slurmstepd (pid $p)"
        kill_wait "$p" slurmstepd
    done
    stop_daemon "$CTLD_PID" slurmctld
    stop_daemon "$MUNGE_PID" munged
    rm -f "$MUNGE_SOCK" "$MUNGE_SOCK.lock"
}

# ----------------------------------------------------------------- start ----

# Print N distinct TCP ports that are free right now on all addresses.
free_ports() {
    local n="$1"
    if command -v python3 >/dev/null 2>&1; then
        python3 - "$n" <<'EOF'
import random, socket, sys
n, got, held = int(sys.argv[1]), [], []
for _ in range(2000):
    if len(got) == n:
        break
    p = random.randint(20000, 32000)
    if p in got:
        continue
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.bind(("0.0.0.0", p))
    except OSError:
        s.close()
        continue
    held.append(s)
    got.append(p)
print(" ".join(map(str, got)))
EOF
    else
        local used p got=()
        used="$(ss -Htan 2>/dev/null | awk '{n = split($4, a, ":"); print a[n]}')"
        while ((${#got[@]} < n)); do
            p=$((20000 + RANDOM % 12000))
            grep -qx -- "$p" <<<"$used" && continue
            [[ " ${got[*]} " == *" $p "* ]] && continue
            got+=("$p")
        done
        echo "${got[*]}"
    fi
}

# fail WHAT LOGFILE: one-line error, tail of the log, stop everything, exit 1.
fail() {
    local what="$1" logfile="${2:-}"
    if [[ -n "$logfile" ]]; then
        echo "$PROG: start failed: $what (see $logfile)" >&2
        if [[ -s "$logfile" ]]; then
            tail -n 15 "$logfile" | sed 's/^/    /' >&2
        fi
    else
        echo "$PROG: start failed: $what" >&2
    fi
    do_stop >/dev/null 2>&1 || true
    exit 1
}

write_conf() {
    local node="$1" cpus="$2" ctld_port="$3" slurmd_port="$4"
    : >"$DIR/plugstack.conf"
    cat >"$CONF" <<EOF
# Generated by scripts/slurm_local.sh - private single-node test cluster.
ClusterName=tgnav
SlurmctldHost=${node}(127.0.0.1)
SlurmctldPort=${ctld_port}
SlurmdPort=${slurmd_port}
SlurmUser=root
SlurmdUser=root

AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=${MUNGE_SOCK}

StateSaveLocation=${STATE_DIR}
SlurmdSpoolDir=${SPOOL_DIR}
SlurmctldPidFile=${CTLD_PID}
SlurmdPidFile=${SLURMD_PID}
SlurmctldLogFile=${CTLD_LOG}
SlurmdLogFile=${SLURMD_LOG}
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=${DIR}/plugstack.conf
MailProg=/bin/true

MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=${LOG_DIR}/jobcomp.log
SwitchType=switch/none

SchedulerType=sched/backfill
SchedulerParameters=sched_interval=2,bf_interval=2
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
MinJobAge=300
KillWait=5
InactiveLimit=0
MessageTimeout=10
SlurmctldTimeout=30
SlurmdTimeout=30
BatchStartTimeout=10
CompleteWait=0

NodeName=${node} NodeAddr=127.0.0.1 NodeHostname=${node} CPUs=${cpus} State=UNKNOWN
PartitionName=${PARTITION} Nodes=${node} Default=YES MaxTime=INFINITE State=UP
EOF
}

do_start() {
    local node cpus ctld_port slurmd_port i state longest
    local timeout="${SLURM_LOCAL_TIMEOUT:-60}"
    umask 022

    if pid_of "$CTLD_PID" slurmctld >/dev/null ||
        pid_of "$SLURMD_PID" slurmd >/dev/null ||
        pid_of "$MUNGE_PID" munged >/dev/null; then
        log "a cluster is already running for $DIR; restarting it"
        do_stop
    fi

    node="$(hostname -s 2>/dev/null || true)"
    [[ -n "$node" ]] || node=localhost
    cpus="$(nproc 2>/dev/null || echo 1)"

    # unix socket paths are limited to 107 bytes; slurmstepd puts
    # "<node>_<jobid>.<stepid>" sockets in the spool dir.
    longest=$((${#SPOOL_DIR} + 1 + ${#node} + 23))
    if ((longest > 107)); then
        echo "$PROG: DIR path too long for unix sockets (${#DIR} chars): $DIR" >&2
        exit 2
    fi

    rm -rf "$STATE_DIR" "$SPOOL_DIR" "$MUNGE_DIR" "$DIR/run"
    mkdir -p "$STATE_DIR" "$SPOOL_DIR" "$MUNGE_DIR" "$LOG_DIR" "$DIR/run"
    chmod 0755 "$DIR" "$STATE_DIR" "$SPOOL_DIR" "$LOG_DIR" "$DIR/run"
    chmod 0755 "$MUNGE_DIR"
    rm -f "$CTLD_LOG" "$SLURMD_LOG" "$MUNGE_LOG"

    # --- munge -------------------------------------------------------------
    if command -v mungekey >/dev/null 2>&1 || [[ -x /usr/sbin/mungekey ]]; then
        "$(bin mungekey)" --create --keyfile="$MUNGE_KEY" >/dev/null 2>&1 ||
            fail "mungekey could not create $MUNGE_KEY"
    else
        dd if=/dev/urandom of="$MUNGE_KEY" bs=1024 count=1 status=none ||
            fail "could not create $MUNGE_KEY"
    fi
    chmod 0400 "$MUNGE_KEY"

    log "starting munged (socket $MUNGE_SOCK)"
    "$(bin munged)" --force --socket="$MUNGE_SOCK" --key-file="$MUNGE_KEY" \
        --pid-file="$MUNGE_PID" --log-file="$MUNGE_LOG" \
        --seed-file="$MUNGE_DIR/munged.seed" \
        </dev/null >>"$MUNGE_LOG" 2>&1 ||
        fail "munged did not start" "$MUNGE_LOG"
    for ((i = 0; i < 100; i++)); do
        if munge --socket="$MUNGE_SOCK" -n 2>/dev/null |
            unmunge --socket="$MUNGE_SOCK" >/dev/null 2>&1; then
            break
        fi
        sleep 0.1
    done
    ((i < 100)) || fail "munged does not answer on $MUNGE_SOCK" "$MUNGE_LOG"

    # --- config ------------------------------------------------------------
    read -r ctld_port slurmd_port <<<"$(free_ports 2)"
    [[ -n "$ctld_port" && -n "$slurmd_port" ]] || fail "no free TCP ports found"
    write_conf "$node" "$cpus" "$ctld_port" "$slurmd_port"
    export SLURM_CONF="$CONF"

    # --- slurmctld ---------------------------------------------------------
    log "starting slurmctld (port $ctld_port)"
    "$(bin slurmctld)" -c -f "$CONF" </dev/null >>"$CTLD_LOG" 2>&1 ||
        fail "slurmctld did not start" "$CTLD_LOG"
    for ((i = 0; i < timeout * 5; i++)); do
        if pid_of "$CTLD_PID" slurmctld >/dev/null &&
            timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP'; then
            break
        fi
        if ((i > 10)) && ! pid_of "$CTLD_PID" slurmctld >/dev/null; then
            fail "slurmctld exited" "$CTLD_LOG"
        fi
        sleep 0.2
    done
    ((i < timeout * 5)) || fail "slurmctld not responding" "$CTLD_LOG"

    # --- slurmd ------------------------------------------------------------
    log "starting slurmd (node $node, $cpus CPUs, port $slurmd_port)"
    "$(bin slurmd)" -f "$CONF" -N "$node" </dev/null >>"$SLURMD_LOG" 2>&1 ||
        fail "slurmd did not start" "$SLURMD_LOG"
    state=""
    for ((i = 0; i < timeout * 5; i++)); do
        state="$(timeout 5 sinfo -h -o %t 2>/dev/null | head -n 1 || true)"
        [[ "$state" == idle ]] && break
        if ((i > 10)) && ! pid_of "$SLURMD_PID" slurmd >/dev/null; then
            fail "slurmd exited" "$SLURMD_LOG"
        fi
        sleep 0.2
    done
    [[ "$state" == idle ]] ||
        fail "node $node not idle after ${timeout}s (state '${state}')" \
            "$SLURMD_LOG"

    log "cluster up in $DIR (partition $PARTITION, node $node, $cpus CPUs)"
    print_env
}

print_env() {
    printf 'export SLURM_CONF=%q\n' "$CONF"
    printf 'export SLURM_LOCAL_DIR=%q\n' "$DIR"
}

do_status() {
    local rc=0 pid d
    for d in "munged:$MUNGE_PID" "slurmctld:$CTLD_PID" "slurmd:$SLURMD_PID"; do
        if pid="$(pid_of "${d#*:}" "${d%%:*}")"; then
            echo "${d%%:*}: running (pid $pid)"
        else
            echo "${d%%:*}: not running"
            rc=1
        fi
    done
    if ((rc == 0)); then
        SLURM_CONF="$CONF" timeout 5 sinfo 2>&1 || rc=1
    fi
    return "$rc"
}

# ------------------------------------------------------------------ main ----

main() {
    (($# == 2)) || usage
    local cmd="$1"
    [[ -n "$2" ]] || usage
    case "$cmd" in
    start)
        check_installed
        check_root
        set_paths "$2"
        do_start
        ;;
    stop)
        [[ -d "$2" ]] || exit 0
        set_paths "$2"
        do_stop
        ;;
    status)
        [[ -d "$2" ]] || {
            echo "no cluster dir: $2"
            exit 1
        }
        set_paths "$2"
        do_status
        ;;
    env)
        set_paths "$2"
        print_env
        ;;
    *) usage ;;
    esac
}

main "$@"
