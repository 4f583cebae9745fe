#!/usr/bin/env bash
# Submits a verification as a Slurm job array of N shards and a merge job that runs when
# every shard succeeded (issue #15).
#
#   examples/slurm/submit.sh N [verify arguments...]
#   examples/slurm/submit.sh 16 --scene hinged-linear-3d --budget full
#
# Without verify arguments: Fig. 2 at the full budget. The shards go to $SHARDS_DIR
# (default ./shards, one sub-directory per task), the report to $REPORT_DIR (./reports);
# LANGEVIN_FEM names the binary (default: langevin-fem on PATH). Add sbatch options
# (partition, account) in SBATCH_EXTRA, e.g. SBATCH_EXTRA="--partition=short".
# PLAN_FIRST=1 runs shard 1 first and the others after it with its plans (--plan-from):
# worth it for a budget by target precision (Fig. 2 full), whose step search and pilot
# every shard would otherwise repeat.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: submit.sh N [verify arguments...]}
shift
case $n in '' | *[!0-9]*) echo "N must be a positive integer, got '$n'" >&2; exit 2 ;; esac
[ "$n" -ge 1 ] || { echo "N must be >= 1" >&2; exit 2; }

export SHARDS=$n
export LANGEVIN_FEM=${LANGEVIN_FEM:-langevin-fem}
export SHARDS_DIR=${SHARDS_DIR:-$PWD/shards}
export REPORT_DIR=${REPORT_DIR:-$PWD/reports}
if [ $# -gt 0 ]; then export VERIFY_ARGS="$*"; fi

# Old shards of another run would be refused by the merge; start clean.
rm -rf "$SHARDS_DIR"
mkdir -p "$SHARDS_DIR"

# shellcheck disable=SC2086 # SBATCH_EXTRA is a list of options
if [ "${PLAN_FIRST:-0}" = 1 ] && [ "$n" -gt 1 ]; then
    first=$(sbatch --parsable ${SBATCH_EXTRA:-} --array=1 --export=ALL "$here/verify-array.sbatch")
    first=${first%%;*}
    # shellcheck disable=SC2086
    array=$(PLAN_FROM="$SHARDS_DIR/1" sbatch --parsable ${SBATCH_EXTRA:-} --array="2-$n" \
        --dependency="afterok:$first" --kill-on-invalid-dep=yes --export=ALL "$here/verify-array.sbatch")
    array="$first:${array%%;*}"
else
    array=$(sbatch --parsable ${SBATCH_EXTRA:-} --array="1-$n" --export=ALL "$here/verify-array.sbatch")
    array=${array%%;*}
fi
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_EXTRA:-} --dependency="afterok:$array" --kill-on-invalid-dep=yes \
    --export=ALL "$here/merge.sbatch")
merge=${merge%%;*}
echo "array job $array ($n shards into $SHARDS_DIR), merge job $merge (report in $REPORT_DIR)"
