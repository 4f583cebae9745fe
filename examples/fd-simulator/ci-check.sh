#!/usr/bin/env bash
# CI check of `langevin-fem check` on another discretization (issue #31): simulate.py, an
# independent NumPy 5-point finite-difference filament on 10 intervals with explicit
# Euler-Maruyama at dt = 1e-4 tau1 (lambda_max dt = 0.16, so its Euler-Maruyama bias is
# 8 % in its fastest mode: the discrete law accounts for it).
#  1. declared as "finite-difference", its data pass: exit 0;
#     and `fit` recovers its EI = 1 within its 95 % interval;
#  2. with the noise variance x1.05 they fail: exit 1, naming mode-variance checks with
#     their ratios;
#  3. the correct data declared as an unknown model ("my-fd") fail against the continuum
#     (the mesh alone: +17 % in mode 3), and every label says "continuum": each check's
#     reference_kind in summary.json, the figures' captions and legends, the table.
# Usage: ci-check.sh PYTHON BIN WORKDIR
set -euo pipefail
PY=$1 BIN=$2 WORK=$3
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$WORK" && mkdir -p "$WORK"
SCENE=hinged-linear-2d

"$PY" "$HERE/simulate.py" --out "$WORK/declared"
"$BIN" check --scene $SCENE --data "$WORK/declared" --out "$WORK/declared-report" \
  || { echo "FAIL: finite-difference data declared as such should pass"; exit 1; }
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
grep -Eq "failed: numpy-fd/mode-variance/n=[0-9]+ \(ratio 1\.0[0-9]+ ± " "$WORK/noise.txt" \
  || { echo "FAIL: noise x1.05 should fail mode-variance checks, naming the mode with its ratio"; exit 1; }

"$PY" "$HERE/simulate.py" --out "$WORK/unknown" --declare my-fd
set +e
"$BIN" check --scene $SCENE --data "$WORK/unknown" --out "$WORK/unknown-report" > "$WORK/unknown.txt"
code=$?
set -e
[ "$code" -eq 1 ] || { echo "FAIL: declared unknown, the mesh should fail against the continuum (exit 1), got $code"; exit 1; }
"$PY" - "$WORK/unknown-report" <<'PYEOF'
import html, json, re, sys, glob
d = sys.argv[1]
summary = json.load(open(f"{d}/summary.json"))
kinds = {c["reference_kind"] for s in summary["scenes"] for c in s["checks"]}
assert kinds == {"continuum"}, kinds
page = open(f"{d}/index.html").read()
captions = [html.unescape(c) for c in re.findall(r'alt="([^"]*)"', page)]
assert captions, "no figures"
for c in captions:
    assert c.startswith("References: the continuum"), c[:120]
    assert "discretized" not in c and "discrete update" not in c, c
for svg in glob.glob(f"{d}/*/*.svg"):
    text = open(svg).read()
    assert "discretized system" not in text and "discrete update" not in text, svg
assert "(continuum)</span>" in page
print(f"declared unknown: {len(captions)} captions, the table and {len(glob.glob(d + '/*/*.svg'))} figures say continuum")
PYEOF
echo "finite-difference example check: passed"
