#!/usr/bin/env python3
"""Coverage of `langevin-fem fit`'s 95 % intervals over seeds (issue #31).

For seeds 1..N: `langevin-fem run` of a scene's run at that seed, then `langevin-fem fit`
on its output; counts how often each interval covers the true parameter (the sidecar's:
EI, a membrane's kappa, and xi with kT known, kT with EI known; for a membrane also kappa
and sigma fitted together, and xi with them) and compares the count with the binomial law
of the nominal level: the exact two-sided 99 % range of covered counts. Pure Python
(standard library only). Exit 0 when every parameter's count is in its range.

Usage: coverage.py BIN WORKDIR [--scene S] [--run R] [--seeds N] [--first-seed S]

Seeds S .. S+N-1 (default 1 .. N). Besides the counts it prints, per parameter, the
variance of the normal scores ln(value/truth)/s.e.(ln) over the seeds (1 for honest
errors; (value - truth)/s.e. for sigma), with its approximate 99 % range
1 +- 2.58 sqrt(2/(N-1)).
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys


def binomial_range(n, p, alpha=0.01):
    """The smallest and largest k with P(X <= k) > alpha/2 and P(X >= k) > alpha/2."""
    pmf = [math.comb(n, k) * p**k * (1 - p) ** (n - k) for k in range(n + 1)]
    cdf, lo = 0.0, 0
    for k in range(n + 1):
        cdf += pmf[k]
        if cdf > alpha / 2:
            lo = k
            break
    sf, hi = 0.0, n
    for k in range(n, -1, -1):
        sf += pmf[k]
        if sf > alpha / 2:
            hi = k
            break
    return lo, hi


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("bin")
    a.add_argument("work")
    a.add_argument("--scene", default="hinged-linear-2d")
    a.add_argument("--run", default="crank-nicolson")
    a.add_argument("--seeds", type=int, default=100)
    a.add_argument("--first-seed", type=int, default=1)
    args = a.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    covered = {"bending_rigidity": 0, "drag": 0, "kt_given_bending_rigidity": 0}
    truth = None
    rows = []
    scores = {k: [] for k in covered}
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        data = os.path.join(args.work, f"data-{seed}")
        out = os.path.join(args.work, f"fit-{seed}")
        subprocess.run([args.bin, "-q", "run", "--scene", args.scene, "--run", args.run,
                        "--seed", str(seed), "--out", data], check=True, stdout=subprocess.DEVNULL)
        subprocess.run([args.bin, "-q", "fit", "--scene", args.scene, "--data", data, "--out", out],
                       check=True, stdout=subprocess.DEVNULL)
        side = json.load(open(os.path.join(data, "data.json")))
        f = side.get("filament") or side["membrane"]
        truth = {"bending_rigidity": f["bending_rigidity"], "drag": f["drag"],
                 "kt_given_bending_rigidity": f["kt"]}
        fit = json.load(open(os.path.join(out, "fit.json")))["runs"][0]
        if "joint" in fit:
            # A membrane's kappa and sigma fitted together (sigma on the linear scale).
            fit["joint_kappa"] = fit["joint"]["bending_rigidity"]
            fit["joint_sigma"] = fit["joint"]["tension"]
            fit["joint_drag"] = fit["joint"]["drag"]
            truth["joint_kappa"] = f["bending_rigidity"]
            truth["joint_sigma"] = f["tension"]
            truth["joint_drag"] = f["drag"]
            for k in ("joint_kappa", "joint_sigma", "joint_drag"):
                covered.setdefault(k, 0)
                scores.setdefault(k, [])
        row = [seed]
        for k in covered:
            lo, hi = fit[k]["interval"]
            ok = lo <= truth[k] <= hi
            covered[k] += ok
            if "log_std_error" in fit[k]:
                scores[k].append(math.log(fit[k]["value"] / truth[k]) / fit[k]["log_std_error"])
            else:
                scores[k].append((fit[k]["value"] - truth[k]) / fit[k]["std_error"])
            row += [fit[k]["value"], lo, hi, int(ok)]
        rows.append(row)
        shutil.rmtree(data)
        shutil.rmtree(out)
    lo, hi = binomial_range(args.seeds, 0.95)
    with open(os.path.join(args.work, "coverage.csv"), "w") as fh:
        fh.write("seed," + ",".join(f"{k},{k}_lo,{k}_hi,{k}_covered" for k in covered) + "\n")
        for r in rows:
            fh.write(",".join(str(v) for v in r) + "\n")
    ok = True
    for k, c in covered.items():
        inside = lo <= c <= hi
        ok &= inside
        print(f"{k}: {c}/{args.seeds} intervals cover the truth {truth[k]} "
              f"(nominal 95 %: {lo}-{hi} of {args.seeds} at the 99 % binomial range) "
              f"{'ok' if inside else 'OUT OF RANGE'}")
    band = 2.576 * math.sqrt(2.0 / max(args.seeds - 1, 1))
    for k, z in scores.items():
        m = sum(z) / len(z)
        v = sum((x - m) ** 2 for x in z) / max(len(z) - 1, 1)
        print(f"{k}: normal scores ln(value/truth)/s.e. have mean {m:.3f}, variance {v:.3f} "
              f"(honest errors: 1, about {1 - band:.2f}-{1 + band:.2f})")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
