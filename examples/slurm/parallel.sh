#!/usr/bin/env bash
# The same on one machine (issue #15): N shards run concurrently with GNU parallel (or
# xargs -P when GNU parallel is not installed), then merged.
#
#   examples/slurm/parallel.sh N DIR [verify arguments...]
#   examples/slurm/parallel.sh 4 out/fig2 --scene compression-2d --scene compression-3d --budget full
#
# Shards go to DIR/shards/1 … DIR/shards/N, the report to DIR/report. JOBS processes run
# at once (default: N); each gets THREADS threads (default 1). LANGEVIN_FEM names the
# binary (default: langevin-fem on PATH). The exit code is the merge's (verify's codes).
set -euo pipefail

n=${1:?usage: parallel.sh N DIR [verify arguments...]}
dir=${2:?usage: parallel.sh N DIR [verify arguments...]}
shift 2
case $n in '' | *[!0-9]*) echo "N must be a positive integer, got '$n'" >&2; exit 2 ;; esac
[ "$n" -ge 1 ] || { echo "N must be >= 1" >&2; exit 2; }
LANGEVIN_FEM=${LANGEVIN_FEM:-langevin-fem}
jobs=${JOBS:-$n}
threads=${THREADS:-1}

rm -rf "$dir/shards"
mkdir -p "$dir/shards"
if command -v parallel >/dev/null 2>&1 && parallel --version 2>/dev/null | grep -q GNU; then
    seq 1 "$n" | parallel --will-cite --halt now,fail=1 -j "$jobs" \
        "$LANGEVIN_FEM" verify -q "$@" --threads "$threads" --shard "{}/$n" --out "$dir/shards/{}"
else
    # xargs: the same, one process per shard index; a failing shard fails the whole.
    seq 1 "$n" | xargs -P "$jobs" -I{} \
        "$LANGEVIN_FEM" verify -q "$@" --threads "$threads" --shard "{}/$n" --out "$dir/shards/{}"
fi
"$LANGEVIN_FEM" merge "$dir/shards" --out "$dir/report"
