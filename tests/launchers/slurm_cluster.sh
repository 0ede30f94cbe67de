#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for testing jobs/slurm/explore.sbatch.
#
#   tests/launchers/slurm_cluster.sh start     start it (or reuse one already working); last line of
#                                          output: SLURM_CONF=/path/to/slurm.conf (export it to use
#                                          sbatch, squeue, scontrol with this cluster)
#   tests/launchers/slurm_cluster.sh stop      stop the daemons this script started
#   tests/launchers/slurm_cluster.sh status    exit 0 when the cluster answers with its node idle or busy
#
# What it does (see NOTES.md): installs slurm-wlm and munge with apt-get when missing, makes a
# munge key and starts munged when munge does not work yet, writes a slurm.conf for this host
# alone (SlurmUser=root, proctrack/linuxproc, task/none, select/cons_tres, CPUs = nproc) in a
# private directory, starts slurmctld and slurmd as daemons and waits for the node to be idle.
# Idempotent: a cluster already answering (the one in $SLURM_CONF, this script's own, or the
# system's default configuration) is reused, and `stop` leaves alone what it did not start.
# Needs root (the daemons run as root). No accounting database: use squeue / scontrol, not sacct.
#
# Environment: SUPERBALL_SLURM_DIR (private directory, default /tmp/superball-slurm),
# SUPERBALL_SLURM_PORT (slurmctld port, default 6917; slurmd uses the next one).
# Exit status: 0 done, 1 failure, 3 Slurm cannot run on this machine (not root, packages cannot
# be installed): tests skip on 3.
set -uo pipefail

dir=${SUPERBALL_SLURM_DIR:-/tmp/superball-slurm}
port=${SUPERBALL_SLURM_PORT:-6917}
host=$(hostname -s)
conf=$dir/slurm.conf

say() { echo "slurm_cluster: $*" >&2; }
cannot() { say "cannot run Slurm here: $*"; exit 3; }
fail() { say "$*"; exit 1; }

# Prints the state of this host's node as the cluster of configuration $1 sees it; fails when
# the controller does not answer.
node_state() {
  SLURM_CONF=$1 timeout 10 sinfo -h -N -n "$host" -o '%T' 2>/dev/null | head -n 1
}

# 0 when the cluster of configuration $1 answers with this host's node usable.
working() {
  [[ -f $1 ]] || return 1
  case $(node_state "$1") in
    idle | mixed | allocated | completing) return 0 ;;
    *) return 1 ;;
  esac
}

alive() { [[ -f $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

install_packages() {
  local missing=() p
  for p in slurmctld slurmd slurm-client munge; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  ((${#missing[@]} == 0)) && return 0
  command -v apt-get >/dev/null || cannot "no apt-get to install ${missing[*]}"
  say "installing slurm-wlm munge (missing: ${missing[*]})"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq >/dev/null 2>&1 || cannot "apt-get update failed"
  apt-get install -y -qq --no-install-recommends slurm-wlm munge >"$dir/apt.log" 2>&1 ||
    cannot "apt-get install slurm-wlm munge failed (see $dir/apt.log)"
}

munge_works() { munge -n 2>/dev/null | unmunge >/dev/null 2>&1; }

start_munge() {
  munge_works && return 0
  local key=/etc/munge/munge.key
  if [[ ! -s $key ]]; then
    say "making a munge key"
    mkdir -p /etc/munge
    dd if=/dev/urandom of="$key" bs=1 count=1024 status=none || fail "cannot write $key"
  fi
  chown munge:munge "$key" && chmod 400 "$key"
  mkdir -p /run/munge /var/lib/munge /var/log/munge
  chown munge:munge /run/munge /var/lib/munge /var/log/munge
  chmod 755 /run/munge
  say "starting munged"
  if command -v runuser >/dev/null; then
    runuser -u munge -- /usr/sbin/munged 9>&- || fail "munged did not start (see /var/log/munge/munged.log)"
  else
    su -s /bin/sh munge -c /usr/sbin/munged 9>&- || fail "munged did not start (see /var/log/munge/munged.log)"
  fi
  echo started >"$dir/munged.started"
  for _ in $(seq 50); do munge_works && return 0; sleep 0.1; done
  fail "munged started but munge -n | unmunge fails"
}

write_conf() {
  mkdir -p "$dir/state" "$dir/spool"
  cat >"$conf" <<EOF
# One-node test cluster written by tests/launchers/slurm_cluster.sh
ClusterName=superball
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
# Finished jobs stay visible to scontrol for 10 minutes (there is no accounting database).
MinJobAge=600
KillWait=10
InactiveLimit=0
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
  # Reuse a cluster that already works: the caller's, ours, or the system's.
  local c
  for c in "${SLURM_CONF:-}" "$conf" /etc/slurm/slurm.conf; do
    if [[ -n $c ]] && command -v sinfo >/dev/null && working "$c"; then
      say "reusing the cluster of $c (node $host $(node_state "$c"))"
      echo "SLURM_CONF=$c"
      return 0
    fi
  done
  [[ $(id -u) -eq 0 ]] || cannot "the daemons need root (SlurmUser=root)"
  install_packages
  start_munge
  # Daemons of an earlier start that no longer answer are stopped before starting again.
  stop_daemons
  write_conf
  say "starting slurmctld and slurmd ($conf)"
  SLURM_CONF=$conf slurmctld -i -f "$conf" 9>&- || fail "slurmctld did not start (see $dir/slurmctld.log)"
  SLURM_CONF=$conf slurmd -f "$conf" 9>&- || fail "slurmd did not start (see $dir/slurmd.log)"
  local state=""
  for _ in $(seq 60); do
    state=$(node_state "$conf")
    [[ $state == idle ]] && break
    # A node remembered as down from an earlier run is put back in service.
    [[ $state == down* || $state == drain* ]] &&
      SLURM_CONF=$conf scontrol update NodeName="$host" State=RESUME >/dev/null 2>&1
    sleep 0.5
  done
  [[ $state == idle ]] || fail "node $host is '${state:-not answering}' after 30 s (see $dir/slurmctld.log, $dir/slurmd.log)"
  say "cluster up: node $host idle, $(nproc) CPUs"
  echo "SLURM_CONF=$conf"
}

# Stops the daemons started from this directory, by their pid files.
stop_daemons() {
  local f pids=()
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid"; do
    if alive "$f"; then
      pids+=("$(cat "$f")")
      kill -TERM "$(cat "$f")" 2>/dev/null
    fi
  done
  for _ in $(seq 50); do
    local left=0 p
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && left=1; done
    ((left)) || break
    sleep 0.2
  done
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; done
  rm -f "$dir/slurmd.pid" "$dir/slurmctld.pid"
}

stop() {
  stop_daemons
  if [[ -f $dir/munged.started && -f /run/munge/munged.pid ]]; then
    kill -TERM "$(cat /run/munge/munged.pid)" 2>/dev/null
    rm -f "$dir/munged.started"
  fi
  say "stopped"
}

# One start or stop at a time (two test runs may share the cluster).
lock() { mkdir -p "$dir" && exec 9>"$dir/lock" && flock 9; }

case ${1:-} in
  start) lock && start ;;
  stop) lock && stop ;;
  status) working "${SLURM_CONF:-$conf}" ;;
  *)
    sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
    exit 2
    ;;
esac
