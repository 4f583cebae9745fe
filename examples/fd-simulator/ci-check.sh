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

# Steps 1 and 2 (examples/declared-check.sh).
source "$HERE/../declared-check.sh"
declared_check finite-difference numpy-fd

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
