#!/usr/bin/env bash
# stop-local-slurm.sh - stop the one-node cluster started by start-local-slurm.sh (beside this
# file; tests/slurm.rs leaves the cluster up for the next test, this script ends it).
# Only the PIDs recorded in $SLURM_LOCAL_DIR/run/*.pid are signalled (after
# checking that each pid still belongs to the expected daemon); munged is only
# stopped if start-local-slurm.sh started it. Never kills anything by name.
#   SLURM_LOCAL_DIR  (default /tmp/slurm-local)
#   SLURM_LOCAL_CONF (default /etc/slurm/slurm.conf)
set -uo pipefail

BASE=${SLURM_LOCAL_DIR:-/tmp/slurm-local}
RUN="$BASE/run"
export SLURM_CONF=${SLURM_LOCAL_CONF:-/etc/slurm/slurm.conf}
export PATH="/usr/sbin:/usr/bin:/sbin:/bin:$PATH"
WAIT=${SLURM_LOCAL_STOP_WAIT:-20}   # seconds per daemon before SIGKILL

log() { echo "[stop-local-slurm] $*"; }

# alive PID: process exists and is not a zombie (PID 1 here may reap late)
alive() { [ -r "/proc/$1/stat" ] && [ "$(sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | cut -d' ' -f1)" != Z ]; }

pid_of() {
  local f="$RUN/$1.pid" p
  [ -s "$f" ] || return 1
  p=$(tr -dc '0-9' <"$f")
  [ -n "$p" ] && [ -r "/proc/$p/comm" ] && [ "$(cat "/proc/$p/comm")" = "$1" ] && alive "$p" && echo "$p"
}

stop_one() {  # NAME
  local name=$1 p i
  if ! p=$(pid_of "$name"); then
    log "$name: not running (no live pid in $RUN/$name.pid)"; rm -f "$RUN/$name.pid"; return 0
  fi
  kill -TERM "$p" 2>/dev/null || true
  for ((i = 0; i < WAIT * 10; i++)); do
    alive "$p" || break
    sleep 0.1
  done
  if alive "$p"; then
    log "$name (pid $p) still running ${WAIT}s after SIGTERM; sending SIGKILL"
    kill -KILL "$p" 2>/dev/null || true
    sleep 0.2
  else
    log "$name (pid $p) exited $(awk "BEGIN{print $i/10}")s after SIGTERM"
  fi
  rm -f "$RUN/$name.pid"
}

if [ ! -d "$RUN" ]; then log "nothing recorded in $RUN; nothing to stop"; exit 0; fi

# Cancel remaining jobs first, so no slurmstepd/job processes outlive slurmd.
if pid_of slurmctld >/dev/null && scontrol ping 2>/dev/null | grep -q 'is UP'; then
  jobs=$(squeue -h -o '%A' 2>/dev/null | sort -u | tr '\n' ' ')
  if [ -n "${jobs// /}" ]; then
    log "cancelling jobs: $jobs"
    # shellcheck disable=SC2086
    scancel $jobs 2>/dev/null || true
    # wait (max 20s) for the jobs to end; pointless if slurmd is gone, as the
    # jobs then stay COMPLETING (the fallback below handles that case)
    for _ in $(seq 100); do
      pid_of slurmd >/dev/null || break
      [ -z "$(squeue -h -o '%A' 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
fi

# Fallback (e.g. slurmd crashed, so scancel could not reach the steps): job
# steps outlive slurmd. `scontrol listpids` asks the slurmstepd's of this node
# (through sockets in SlurmdSpoolDir) for the pids of every process of every
# job step; stop exactly those pids, then the slurmstepd's exit by themselves.
# (guarded: without a slurm.conf every Slurm command hangs ~60s on a DNS lookup)
step_pids() { [ -e "$SLURM_CONF" ] || return 0; scontrol listpids 2>/dev/null | awk 'NR > 1 && $1 ~ /^[0-9]+$/ {print $1}' | sort -u; }
left=$(step_pids | tr '\n' ' ')
if [ -n "${left// /}" ]; then
  log "job processes still running: $left- sending SIGTERM"
  # shellcheck disable=SC2086
  kill -TERM $left 2>/dev/null || true
  sleep 1
  left=$(step_pids | tr '\n' ' ')
  if [ -n "${left// /}" ]; then
    log "still running: $left- sending SIGKILL"
    # shellcheck disable=SC2086
    kill -KILL $left 2>/dev/null || true
  fi
fi

stop_one slurmd
stop_one slurmctld
if [ -e "$RUN/munged.ours" ]; then
  stop_one munged
  rm -f "$RUN/munged.ours"
else
  log "munged: not started by start-local-slurm.sh; leaving it alone"
fi
rmdir "$RUN" 2>/dev/null || true
log "done (logs kept in $BASE/log)"
