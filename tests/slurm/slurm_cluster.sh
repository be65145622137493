#!/usr/bin/env bash
# A one-node Slurm cluster on localhost for the slurm test, from Debian's slurm-wlm and munge:
#   slurm_cluster.sh start <dir>   munged, slurmctld and slurmd with a generated configuration,
#                                  all files under <dir>; prints the path of slurm.conf
#   slurm_cluster.sh stop <dir>    stops the three daemons of <dir>
# Ports are drawn from the process id so that two checkouts' tests do not collide.
set -euo pipefail
action=$1
dir=$(realpath -m "$2")

stop() {
    if [ -f "$dir/slurm.conf" ]; then
        SLURM_CONF="$dir/slurm.conf" scontrol shutdown >/dev/null 2>&1 || true
    fi
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
        if [ -f "$pidfile" ]; then
            kill "$(cat "$pidfile")" 2>/dev/null || true
        fi
    done
}

case "$action" in
stop)
    stop
    exit 0
    ;;
start) ;;
*)
    echo "usage: $0 start|stop <dir>" >&2
    exit 2
    ;;
esac

for program in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
    command -v "$program" >/dev/null || { echo "slurm_cluster: $program is missing (Debian packages slurm-wlm, munge)" >&2; exit 3; }
done
stop
rm -rf "$dir"
mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
chmod 700 "$dir/munge"
chmod 755 "$dir"
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$dir/munge/munge.key"
# -f: munged refuses a key and socket outside its own directories otherwise (we are root here).
munged -f --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.sock" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/seed"

port=$((20000 + ($$ % 20000) * 2))
host=$(hostname -s)
cat >"$dir/slurm.conf" <<CONF
ClusterName=rtlabtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.sock
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
ReturnToService=2
SwitchType=switch/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=rtlab Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
# slurmd 22.05 loads its cgroup plugin even with proctrack/linuxproc and task/none, and fails
# where no cgroup file system is mounted on /sys/fs/cgroup (a bare root, a container): there it
# gets cgroup v1 controllers mounted under the cluster's own folder instead.
if ! grep -qs ' /sys/fs/cgroup' /proc/mounts; then
    mkdir -p "$dir/cgroup"
    cat >"$dir/cgroup.conf" <<CGROUP
CgroupPlugin=cgroup/v1
CgroupAutomount=yes
CgroupMountpoint=$dir/cgroup
CGROUP
fi
export SLURM_CONF="$dir/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
# Ready when the node is idle.
for _ in $(seq 1 100); do
    if sinfo -h -o '%T' 2>/dev/null | grep -q idle; then
        echo "$SLURM_CONF"
        exit 0
    fi
    sleep 0.2
done
echo "slurm_cluster: the node did not become idle; logs:" >&2
tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" "$dir/munge/munged.log" >&2 || true
stop
exit 1
