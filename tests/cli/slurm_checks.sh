#!/usr/bin/env bash
# The farm contract on a real batch engine (docs/farm.md): a one-node Slurm cluster, started here
# and stopped here, runs packaging/slurm/bake-region.sh (a 4-tile job array and a dependent merge)
# on a committed DEM; every tile's files and the merged scene must equal, byte for byte, the same
# tiles baked here one at a time on one thread. Skips (77) without root or without Slurm and munge.
#   slurm_checks.sh TERRALUX_BAKE DEM SCRIPT
set -euo pipefail
bake=$1 dem=$2 script=$3

if [ "$(id -u)" -ne 0 ] || ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
   ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
  echo "skipped: needs root, slurm-wlm and munge (packaging/install-deps.sh)"
  exit 77
fi

work=$(mktemp -d)
host=$(hostname -s)
munge_pid="" ctld_pid="" d_pid=""
cleanup() {
  # Exactly the daemons started here, by their pids.
  for p in "$d_pid" "$ctld_pid" "$munge_pid"; do [ -n "$p" ] && kill "$p" 2>/dev/null || true; done
  for p in "$d_pid" "$ctld_pid" "$munge_pid"; do
    [ -n "$p" ] && for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
  done
  rm -rf "$work"
}
trap cleanup EXIT

mkdir -p "$work/state" "$work/spool" "$work/log" "$work/munge"
cat > "$work/slurm.conf" <<CONF
ClusterName=terralux-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/ctld.log
SlurmdLogFile=$work/log/d.log
SlurmctldPort=$(( 20000 + RANDOM % 20000 ))
SlurmdPort=$(( 40000 + RANDOM % 20000 ))
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$(nproc) RealMemory=$(( $(free -m | awk '/Mem:/{print $2}') * 8 / 10 )) State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf

# munge with a key and a socket of its own, so a munged already running is left alone.
dd if=/dev/urandom bs=1 count=1024 of="$work/munge/munge.key" status=none
chown -R munge:munge "$work/munge" 2>/dev/null || true
chmod 700 "$work/munge"; chmod 400 "$work/munge/munge.key"
socket=$work/munge/munge.socket
munged --force --key-file="$work/munge/munge.key" --socket="$socket" --pid-file="$work/munge/munged.pid" \
  --log-file="$work/munge/munged.log" --seed-file="$work/munge/seed"
munge_pid=$(cat "$work/munge/munged.pid")
echo "AuthInfo=socket=$socket" >> "$work/slurm.conf"
slurmctld -c
slurmd -c
for _ in $(seq 100); do [ -s "$work/slurmctld.pid" ] && [ -s "$work/slurmd.pid" ] && break; sleep 0.1; done
ctld_pid=$(cat "$work/slurmctld.pid"); d_pid=$(cat "$work/slurmd.pid")
for _ in $(seq 100); do sinfo -h -o %t 2>/dev/null | grep -q idle && break; sleep 0.2; done
sinfo -h -o %t | grep -q idle || { echo "FAIL: the Slurm node never came up"; cat "$work/log/"*; exit 1; }

project=$work/region.json
cat > "$project" <<JSON
{"version": 4, "terrain": {"dem": "$dem", "max_resolution": 65},
 "probe_volumes": [{"name": "probes", "grid_dims": [9, 7]}], "bake": {"quality": "draft"}}
JSON

out=$work/farm
ids=$(TERRALUX_BAKE=$bake "$script" "$project" "$out" 2,2)
echo "$ids"
merge=$(echo "$ids" | sed -n 's/.*merge \([0-9]*\).*/\1/p')
for _ in $(seq 600); do
  squeue -h 2>/dev/null | grep -q . || break
  squeue -h -o %r | grep -q DependencyNeverSatisfied && break
  sleep 0.5
done
if squeue -h | grep -q .; then echo "FAIL: jobs still queued"; squeue; tail -n 20 "$out/logs/"* || true; exit 1; fi
[ -s "$out/scene.gltf" ] || { echo "FAIL: no merged scene (merge job $merge)"; cat "$out/logs/"* || true; exit 1; }
grep -q "merged 4 tiles (4 probe grids)" "$out/logs/merge.log" || { echo "FAIL: merge log"; cat "$out/logs/"*; exit 1; }

# The same tiles here, one after another on one thread, then merged.
local=$work/local
for i in 0 1 2 3; do
  "$bake" --bake "$project" --tiles 2,2 --tile "$i/4" --out "$local" --quiet --threads 1 > /dev/null
done
"$bake" --merge "$local" > /dev/null
# Everything but the reports (their times) and tiles.json (which hashes the reports) is the same.
(cd "$out" && find tiles scene.gltf -type f ! -name bake_report.json | sort) > "$work/files"
[ "$(wc -l < "$work/files")" -eq 19 ] || { echo "FAIL: farm files:"; cat "$work/files"; exit 1; }
while read -r f; do
  cmp -s "$out/$f" "$local/$f" || { echo "FAIL: $f differs between the farm and the local bake"; exit 1; }
done < "$work/files"
# A second submission finds every tile baked and only merges again.
ids=$(TERRALUX_BAKE=$bake "$script" "$project" "$out" 2,2)
for _ in $(seq 600); do squeue -h 2>/dev/null | grep -q . || break; sleep 0.5; done
grep -q "inputs are unchanged since its bake" "$out/logs/tile-3.log" || { echo "FAIL: tile 3 baked again"; cat "$out/logs/tile-3.log"; exit 1; }
echo "OK: 4 tiles through Slurm equal the local bake; a resubmission skipped them"
