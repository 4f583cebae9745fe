#!/usr/bin/env python3
"""An independent simulator of a thermally fluctuating hinged filament, in NumPy.

It shares no code with langevin-fem: it integrates the modal form of the stochastic beam
equation (2) of Lin & Shenoy, xi dw/dt + EI w'''' = f with <f f> = 2 xi kT delta delta,
with explicit Euler-Maruyama. For w(x, t) = sum_n a_n(t) sin(n pi x / L) each amplitude
obeys

    da_n = -lambda_n a_n dt + sqrt(4 kT / (xi L)) dW_n,   lambda_n = EI (n pi / L)^4 / xi,

so the Euler-Maruyama step is a_{k+1} = (1 - lambda dt) a_k + sqrt(4 kT dt / (xi L)) Z_k.
Its stationary variance is (2 kT L^3 / (pi^4 n^4 EI)) / (1 - lambda dt / 2): the
time-step bias that `langevin-fem check` must find at a large step and not at a small
one. The recurrence is evaluated in blocks, exactly (up to rounding), with NumPy
cumulative sums instead of a Python loop per step.

It writes the trajectory data format of langevin-fem (see the README, "Check your own
simulator"): data.json and one .npy file per trajectory, and then

    langevin-fem check --scene hinged-linear-2d --data DIR

judges it against the exact continuum solution.
"""

import argparse
import json
import math
import os
import sys

import numpy as np


def simulate(args):
    L, EI, xi, kT = 1.0, 1.0, 1.0, 1.0
    tau1 = xi * L**4 / (math.pi**4 * EI)
    dt = args.dt_tau1 * tau1
    every = max(1, round(args.sample_tau1 / args.dt_tau1))
    dt_sample = every * dt
    burn_in = args.burn_in_tau1 * tau1
    total_steps = round((args.burn_in_tau1 + args.duration_tau1) / args.dt_tau1)
    total_steps -= total_steps % every
    n = np.arange(1, args.modes + 1)
    lam = EI * (n * math.pi / L) ** 4 / xi
    r = 1.0 - lam * dt  # Euler-Maruyama multiplier per step
    if np.any(np.abs(r) >= 1.0):
        sys.exit(f"unstable: lambda_max dt = {lam[-1] * dt:.3g} >= 2")
    sigma = math.sqrt(4.0 * kT * dt / (xi * L))
    positions = sorted(set([round(0.1 * k, 12) for k in range(11)] + [0.25]))
    x = np.array(positions) * L
    basis = np.sin(np.outer(n * math.pi / L, x))  # (modes, positions)
    rng = np.random.default_rng(args.seed)
    os.makedirs(os.path.join(args.out, args.run), exist_ok=True)
    # Steps per block: r**-block stays below e^5, so the cumulative sums keep their digits.
    block = max(every, int(5.0 / (lam[-1] * dt)) // every * every)
    m, nt = args.modes, args.trajectories
    a = np.zeros((nt, m))
    rows = [a]
    done = 0
    while done < total_steps:  # every trajectory at once: arrays (steps, trajectories, modes)
        b = min(block, total_steps - done)
        e = sigma * rng.standard_normal((b, nt, m))
        rk = r[None, None, :] ** np.arange(1, b + 1)[:, None, None]
        # a_{k0+k} = r^k a_{k0} + sum_{i<k} r^{k-1-i} e_i = r^k (a_{k0} + sum_{i<k} r^{-(i+1)} e_i)
        traj = rk * (a[None] + np.cumsum(e / rk, axis=0))
        rows.extend(traj[every - 1 :: every])
        a = traj[-1]
        done += b
    amp = np.stack(rows, axis=1)  # (trajectories, rows, modes)
    t = np.arange(amp.shape[1]) * dt_sample
    files = []
    for j in range(nt):
        table = np.column_stack([t, amp[j] @ basis, amp[j]])
        name = f"{args.run}/trajectory-{j:04d}.npy"
        np.save(os.path.join(args.out, name), table)
        files.append(name)
    sidecar = {
        "format": "langevin-fem-trajectories",
        "version": 1,
        "producer": "examples/numpy-simulator/simulate.py (NumPy %s), modal Euler-Maruyama"
        % np.__version__,
        "dims": 2,
        "filament": {"length": L, "bending_rigidity": EI, "drag": xi, "kt": kT},
        "runs": [
            {
                "name": args.run,
                "dt_sample": dt_sample,
                "start": "rest",
                "burn_in": burn_in,
                "positions": [float(p) for p in x],
                "modes": args.modes,
                "discretization": {
                    "model": "numpy-modal-euler-maruyama",
                    "elements": args.modes,
                    "integrator": "euler-maruyama",
                    "dt": dt,
                },
                "files": files,
            }
        ],
    }
    with open(os.path.join(args.out, "data.json"), "w") as f:
        json.dump(sidecar, f, indent=2)
    print(
        f"wrote {args.trajectories} trajectories x {len(t)} rows to {args.out} "
        f"(dt = {args.dt_tau1} tau1, lambda_max dt = {lam[-1] * dt:.3g})"
    )


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="data directory to write")
    p.add_argument("--dt-tau1", type=float, default=1e-5, help="time step in tau1")
    p.add_argument("--modes", type=int, default=4, help="modes simulated")
    p.add_argument("--trajectories", type=int, default=8)
    p.add_argument("--duration-tau1", type=float, default=20.0, help="after burn-in")
    p.add_argument("--burn-in-tau1", type=float, default=5.0)
    p.add_argument("--sample-tau1", type=float, default=1e-3, help="time between rows")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--run", default="numpy-euler", help="run name")
    simulate(p.parse_args())


if __name__ == "__main__":
    main()
