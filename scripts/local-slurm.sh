#!/usr/bin/env bash
# A single-node Slurm cluster on this host, for the cluster tests (ctest -L slurm) and for trying `--backend slurm`:
#   bash scripts/local-slurm.sh start   writes a minimal slurm.conf for this host, starts munged, slurmctld and slurmd
#                                       (no systemd) and waits until `sinfo` shows the node idle
#   bash scripts/local-slurm.sh stop    stops the three daemons this script started (by their pid files)
#   bash scripts/local-slurm.sh env     prints the export line the Slurm commands need (SLURM_CONF)
# Everything (configuration, munge key and socket, state, spool, logs, pid files) lives under LOCAL_SLURM_DIR
# (default /tmp/roamlab-slurm); nothing under /etc is written. Clients find the cluster through
# SLURM_CONF=LOCAL_SLURM_DIR/slurm.conf, which `start` prints. Needs root (slurmd starts jobs as their user) and the
# Debian packages slurm-wlm and munge (scripts/setup.sh installs them). slurmctld listens on LOCAL_SLURM_PORT, slurmd
# on the next port; by default the first pair from 6817 on (6817, 6819, ...) where nothing listens yet, so that a second
# cluster on the same network (another checkout's, or a chroot's on this host) does not clash with the first.
set -euo pipefail

dir=${LOCAL_SLURM_DIR:-/tmp/roamlab-slurm}
conf=$dir/slurm.conf

die() {
  echo "local-slurm: $*" >&2
  [ "${started:-0}" = 1 ] && { started=0; stop >/dev/null 2>&1 || true; }
  exit 1
}

# Whether something listens on 127.0.0.1:$1.
listening() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

# Sets `port`: LOCAL_SLURM_PORT, or the first pair of free ports from 6817 on.
choose_port() {
  if [ -n "${LOCAL_SLURM_PORT:-}" ]; then
    port=$LOCAL_SLURM_PORT
    return 0
  fi
  for port in $(seq 6817 2 6915); do
    listening "$port" || listening $((port + 1)) || return 0
  done
  die "no free pair of ports in 6817-6916 (set LOCAL_SLURM_PORT)"
}

write_conf() {
  local node_line
  # The node as slurmd sees it (CPUs, sockets, cores, memory), so that the node registers without a mismatch.
  node_line=$(slurmd -C | head -n 1)
  local host=${node_line#NodeName=}
  host=${host%% *}
  cat >"$conf" <<EOF
# Written by scripts/local-slurm.sh: a one-node cluster for tests.
ClusterName=roamlab-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
# Dispatch a freed CPU's next task at once rather than at the next periodic pass.
SchedulerParameters=sched_min_interval=0,batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=600
KillWait=5
$node_line NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  # slurmd loads a cgroup plugin even though no plugin above uses cgroups, and its automatic choice fails where no
  # cgroup file system is mounted on /sys/fs/cgroup (a chroot that bind-mounts /sys alone, as a fresh CI root does);
  # the cgroup/v1 plugin loads without one.
  rm -f "$dir/cgroup.conf"
  case "$(stat -fc %T /sys/fs/cgroup 2>/dev/null)" in
    tmpfs | cgroup2fs) ;;
    *) echo "CgroupPlugin=cgroup/v1" >"$dir/cgroup.conf" ;;
  esac
}

start_munge() {
  mkdir -p "$dir/munge"
  chmod 0700 "$dir" "$dir/munge"
  [ -f "$dir/munge/munge.key" ] || mungekey --create --keyfile="$dir/munge/munge.key" >/dev/null
  chmod 0400 "$dir/munge/munge.key"
  munged --force --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"
}

# Waits up to $1 seconds for `sinfo` to show the node idle.
wait_idle() {
  local deadline=$((SECONDS + $1)) state
  while ((SECONDS < deadline)); do
    state=$(SLURM_CONF=$conf sinfo -h -o %t 2>/dev/null | head -n 1 || true)
    [ "$state" = "idle" ] && return 0
    sleep 0.2
  done
  die "the node is not idle after $1 s (sinfo: '${state:-no answer}'); see $dir/slurmctld.log and $dir/slurmd.log"
}

start() {
  [ "$(id -u)" -eq 0 ] || die "start needs root (slurmd runs jobs as their user)"
  command -v slurmctld >/dev/null && command -v munged >/dev/null ||
    die "slurm-wlm and munge are not installed (bash scripts/setup.sh installs them)"
  if [ -f "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
    die "already running (SLURM_CONF=$conf); stop it first"
  fi
  local t0=$SECONDS
  mkdir -p "$dir/state" "$dir/spool"
  choose_port
  write_conf
  # From here a daemon that does not come up stops the others (die), so that no port stays taken.
  started=1
  start_munge || die "munged did not start; see $dir/munge/munged.log"
  slurmctld -f "$conf" -i || die "slurmctld did not start: $(tail -n 3 "$dir/slurmctld.log" 2>/dev/null)"
  slurmd -f "$conf" || die "slurmd did not start: $(tail -n 3 "$dir/slurmd.log" 2>/dev/null)"
  wait_idle 60
  echo "local-slurm: node idle after $((SECONDS - t0)) s; export SLURM_CONF=$conf"
}

# Stops the daemon whose pid file is $1 and waits for it to exit.
stop_daemon() {
  [ -f "$1" ] || return 0
  local pid
  pid=$(cat "$1")
  if kill -0 "$pid" 2>/dev/null; then
    kill "$pid"
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
  fi
  rm -f "$1"
}

stop() {
  stop_daemon "$dir/slurmd.pid"
  stop_daemon "$dir/slurmctld.pid"
  stop_daemon "$dir/munge/munged.pid"
  echo "local-slurm: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  env) echo "export SLURM_CONF=$conf" ;;
  *) die "usage: local-slurm.sh start|stop|env" ;;
esac
