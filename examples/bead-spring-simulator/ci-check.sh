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

"$PY" "$HERE/simulate.py" --out "$WORK/declared"
"$BIN" check --scene $SCENE --data "$WORK/declared" --out "$WORK/declared-report" \
  || { echo "FAIL: bead-spring data declared as such should pass"; exit 1; }
"$BIN" fit --scene $SCENE --data "$WORK/declared" --out "$WORK/declared-fit" | grep -A3 "^fit "
"$PY" - "$WORK/declared-fit/fit.json" <<'PYEOF'
import json, sys
fit = json.load(open(sys.argv[1]))["runs"][0]
lo, hi = fit["bending_rigidity"]["interval"]
assert lo <= 1.0 <= hi, f"EI interval [{lo}, {hi}] misses the simulator's EI = 1"
print(f"fit: EI = {fit['bending_rigidity']['value']:.4f} [{lo:.4f}, {hi:.4f}] covers the simulator's EI = 1")
PYEOF

"$PY" "$HERE/simulate.py" --out "$WORK/noise" --noise-variance-factor 1.05
set +e
"$BIN" check --scene $SCENE --data "$WORK/noise" --out "$WORK/noise-report" > "$WORK/noise.txt"
code=$?
set -e
cat "$WORK/noise.txt"
[ "$code" -eq 1 ] || { echo "FAIL: noise variance x1.05 should fail (exit 1), got $code"; exit 1; }
grep -Eq "failed: numpy-beads/mode-variance/n=[0-9]+ \(ratio 1\.0[0-9]+ ± " "$WORK/noise.txt" \
  || { echo "FAIL: noise x1.05 should fail mode-variance checks, naming the mode with its ratio"; exit 1; }
echo "bead-spring example check: passed"
