#!/usr/bin/env bash
# Runs verify-array.sbatch and merge.sbatch as Slurm would, without Slurm: each array
# task in turn with SLURM_ARRAY_TASK_ID / _COUNT set, then the merge. For testing
# the scripts (`make fig2-shards` does) and for a dry run before submitting.
#
#   examples/slurm/emulate.sh N
#
# Settings: the environment of verify-array.sbatch and merge.sbatch.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: emulate.sh N}
export SLURM_ARRAY_TASK_COUNT=$n SLURM_CPUS_PER_TASK=${SLURM_CPUS_PER_TASK:-1}
rm -rf "${SHARDS_DIR:-shards}"
# With PLAN_FROM set, as submit.sh with PLAN_FIRST=1: shard 1 first, then the others.
for i in $(seq 1 "$n"); do
    SLURM_ARRAY_TASK_ID=$i bash "$here/verify-array.sbatch" >/dev/null
done
bash "$here/merge.sbatch"
