#!/usr/bin/env bash
# CI check of `langevin-fem check` against an independent simulator (simulate.py, NumPy):
#  1. at dt = 1e-5 tau1 (Euler-Maruyama bias 0.13 % in mode 4, below the statistical
#     error) its data must pass: exit 0;
#  2. at dt = 2e-3 tau1 (bias +34 % in mode 4, +9 % in mode 3) they must fail: exit 1,
#     naming the mode-variance checks of modes 3 and 4;
#  3. NumPy must read what `langevin-fem run` writes (.npy and CSV) with the shapes and
#     columns its sidecar announces.
# Usage: ci-check.sh PYTHON BIN WORKDIR
set -euo pipefail
PY=$1 BIN=$2 WORK=$3
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$WORK" && mkdir -p "$WORK"

"$PY" "$HERE/simulate.py" --out "$WORK/small-dt" --dt-tau1 1e-5
"$BIN" check --scene hinged-linear-2d --data "$WORK/small-dt" --out "$WORK/small-dt-report" \
  || { echo "FAIL: the NumPy simulator at dt = 1e-5 tau1 should pass"; exit 1; }

"$PY" "$HERE/simulate.py" --out "$WORK/large-dt" --dt-tau1 2e-3
set +e
"$BIN" check --scene hinged-linear-2d --data "$WORK/large-dt" --out "$WORK/large-dt-report" > "$WORK/large-dt.txt"
code=$?
set -e
cat "$WORK/large-dt.txt"
[ "$code" -eq 1 ] || { echo "FAIL: at dt = 2e-3 tau1 check should exit 1, got $code"; exit 1; }
for n in 3 4; do
  grep -q "failed: numpy-euler/mode-variance/n=$n" "$WORK/large-dt.txt" \
    || { echo "FAIL: the mode-variance check of mode $n should fail at dt = 2e-3 tau1"; exit 1; }
done

for fmt in npy csv; do
  "$BIN" run --scene hinged-linear-2d --run crank-nicolson --trajectories 8 --duration-tau1 40 --every 10 \
    --format "$fmt" --out "$WORK/run-$fmt"
  "$PY" - "$WORK/run-$fmt" <<'PYEOF'
import json, sys
import numpy as np
d = sys.argv[1]
side = json.load(open(f"{d}/data.json"))
for run in side["runs"]:
    cols = 1 + (side["dims"] - 1) * (len(run["positions"]) + run["modes"])
    for f in run["files"]:
        if f.endswith(".npy"):
            a = np.load(f"{d}/{f}")
        else:
            a = np.genfromtxt(f"{d}/{f}", delimiter=",", names=True)
            a = a.view(np.float64).reshape(len(a), -1)
        assert a.ndim == 2 and a.shape[1] == cols, (f, a.shape, cols)
        assert a[0, 0] == 0.0 and np.all(np.diff(a[:, 0]) > 0), f
        assert np.allclose(np.diff(a[:, 0]), run["dt_sample"], rtol=1e-9), f
print(f"NumPy read {d}: columns and times as the sidecar says")
PYEOF
  "$BIN" check --scene hinged-linear-2d --data "$WORK/run-$fmt" --out "$WORK/run-$fmt-report"
done
echo "example check: passed"
