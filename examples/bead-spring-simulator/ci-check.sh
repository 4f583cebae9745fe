#!/usr/bin/env bash
# CI check of `langevin-fem check` on a bead-spring chain (issue #31): simulate.py, an
# independent NumPy simulator of 11 beads with stretching springs and the full cosine
# angle potential (nonlinear), explicit Euler-Maruyama at dt = 2e-4 tau1, L/l_p = 0.01.
#  1. declared as "bead-spring" (10 bonds), its data pass: exit 0 — the linearized
#     chain's exact discrete law is the reference, and the nonlinear terms are below
#     what the data resolve;
#     and `fit` recovers its EI = 1 within its 95 % interval;
#  2. with the noise variance x1.05 they fail: exit 1, naming mode-variance checks with
#     their ratios.
# Usage: ci-check.sh PYTHON BIN WORKDIR
set -euo pipefail
PY=$1 BIN=$2 WORK=$3
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$WORK" && mkdir -p "$WORK"
SCENE=hinged-linear-2d

# Steps 1 and 2 (examples/declared-check.sh).
source "$HERE/../declared-check.sh"
declared_check bead-spring numpy-beads
echo "bead-spring example check: passed"
