#!/usr/bin/env bash
# Bakes a region on a Slurm cluster as a job array of tiles, then merges them (docs/farm.md).
#
#   bake-region.sh PROJECT OUT NX,NZ [extra terralux-bake options...]
#
# Submits NX·NZ array tasks, each `terralux-bake --bake PROJECT --tiles NX,NZ --tile I/N --out OUT`
# with I from SLURM_ARRAY_TASK_ID, and a merge job that runs once every task has succeeded
# (--dependency=afterok). Prints the two job ids. A task whose tile is already baked with the
# same inputs exits at once, so the array can simply be submitted again after a failure.
# Environment: TERRALUX_BAKE (default terralux-bake on PATH), SBATCH_OPTIONS (more sbatch options,
# e.g. "--partition=bake --cpus-per-task=8"), TERRALUX_THREADS (default: the task's CPUs).
set -euo pipefail

if [ $# -lt 3 ]; then
  echo "usage: bake-region.sh PROJECT OUT NX,NZ [terralux-bake options...]" >&2
  exit 2
fi
project=$(realpath "$1")
out=$(realpath -m "$2")
tiles=$3
shift 3
if ! [[ $tiles =~ ^[1-9][0-9]*,[1-9][0-9]*$ ]]; then
  echo "bake-region.sh: NX,NZ '$tiles': must be two whole numbers >= 1" >&2
  exit 2
fi
n=$(( ${tiles%,*} * ${tiles#*,} ))
bake=${TERRALUX_BAKE:-terralux-bake}
mkdir -p "$out/logs"

extra=""
for a in "$@"; do extra+=" $(printf '%q' "$a")"; done
# shellcheck disable=SC2086
array=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=terralux-tile --array=0-$((n - 1)) \
  --output="$out/logs/tile-%a.log" \
  --wrap "exec $(printf '%q' "$bake") --bake $(printf '%q' "$project") --tiles $tiles \
--tile \$SLURM_ARRAY_TASK_ID/$n --out $(printf '%q' "$out") --quiet \
--threads \${TERRALUX_THREADS:-\${SLURM_CPUS_PER_TASK:-\${SLURM_CPUS_ON_NODE:-1}}}$extra")
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --job-name=terralux-merge --dependency=afterok:"$array" \
  --output="$out/logs/merge.log" \
  --wrap "exec $(printf '%q' "$bake") --merge $(printf '%q' "$out")")
echo "array $array ($n tiles), merge $merge"
