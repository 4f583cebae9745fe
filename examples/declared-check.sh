# Sourced by the CI checks of the examples with a declared discretization (issue #31:
# fd-simulator, bead-spring-simulator); expects PY, BIN, WORK, HERE and SCENE set.
# declared_check WHAT RUN: simulate.py's data, declared as the example's discretization,
#  1. pass `check` (exit 0), and `fit` recovers the simulator's EI = 1 within its 95 %
#     interval;
#  2. with the noise variance x1.05 fail (exit 1), naming mode-variance checks of run RUN
#     with their ratios.
# WHAT names the data in the failure messages.
declared_check() {
  local what=$1 run=$2 code
  "$PY" "$HERE/simulate.py" --out "$WORK/declared"
  "$BIN" check --scene "$SCENE" --data "$WORK/declared" --out "$WORK/declared-report" \
    || { echo "FAIL: $what data declared as such should pass"; exit 1; }
  "$BIN" fit --scene "$SCENE" --data "$WORK/declared" --out "$WORK/declared-fit" | grep -A3 "^fit "
  "$PY" - "$WORK/declared-fit/fit.json" <<'PYEOF'
import json, sys
fit = json.load(open(sys.argv[1]))["runs"][0]
lo, hi = fit["bending_rigidity"]["interval"]
assert lo <= 1.0 <= hi, f"EI interval [{lo}, {hi}] misses the simulator's EI = 1"
print(f"fit: EI = {fit['bending_rigidity']['value']:.4f} [{lo:.4f}, {hi:.4f}] covers the simulator's EI = 1")
PYEOF

  "$PY" "$HERE/simulate.py" --out "$WORK/noise" --noise-variance-factor 1.05
  set +e
  "$BIN" check --scene "$SCENE" --data "$WORK/noise" --out "$WORK/noise-report" > "$WORK/noise.txt"
  code=$?
  set -e
  cat "$WORK/noise.txt"
  [ "$code" -eq 1 ] || { echo "FAIL: noise variance x1.05 should fail (exit 1), got $code"; exit 1; }
  grep -Eq "failed: $run/mode-variance/n=[0-9]+ \(ratio 1\.0[0-9]+ ± " "$WORK/noise.txt" \
    || { echo "FAIL: noise x1.05 should fail mode-variance checks, naming the mode with its ratio"; exit 1; }
}
