#!/usr/bin/env python3
"""An independent Fourier-space Brownian-dynamics simulator of a periodic membrane, in NumPy.

It shares no code with langevin-fem. The Helfrich membrane in the Monge gauge with local
friction, xi dh/dt = -kappa lap^2 h + sigma lap h + f, <f f> = 2 xi kT delta delta, on a
periodic a x b patch, is written in its real Fourier modes

    h(r) = sum_q [A_q cos(q.r) + B_q sin(q.r)],  q = 2 pi (m/a, n/b),

over the half-lattice m > 0, or m = 0 and n > 0 (the q = 0 translation left out), cut
off at |(m, n)| <= M. Each amplitude is an independent Ornstein-Uhlenbeck process with
rate c_q/xi, c_q = kappa q^4 + sigma q^2, and stationary variance kT/(c_q ||cos||^2) with
||cos||^2 = ab/2, advanced by its exact update over dt from rest (h = 0):

    A <- exp(-c_q dt/xi) A + sqrt(var (1 - exp(-2 c_q dt/xi))) Z.

The data: the height on the midline y = b/2 at the positions, and the amplitudes of the
slowest modes named `ac_m_n` and `as_m_n` (the trajectory data format of langevin-fem).
No discretization is declared, so `langevin-fem check` judges them against the continuum;
the cut-off leaves out a part kT/(4 pi kappa Q^2) of the point variance, Q = 2 pi M/a
(0.3 % at M = 16). `--noise-variance-factor 1.05` injects a 5 % error of the noise
variance; `--tension-factor 1.2` simulates sigma x 1.2 while the sidecar states sigma
(a tension entered in other units).
"""

import argparse
import json
import math
import os

import numpy as np


def lattice(M):
    """The half-lattice points (m, n), |(m, n)| <= M, slowest first (|q|^2, then m, n)."""
    pts = [(m, n) for m in range(0, M + 1) for n in range(-M, M + 1)
           if (m > 0 or n > 0) and m * m + n * n <= M * M]
    return pts


def simulate(args):
    a = b = 1.0
    kappa, sigma, xi, kT = 1.0, args.tension, 1.0, 1.0
    area = a * b
    pts = lattice(args.cutoff)
    q = np.array([[2 * math.pi * m / a, 2 * math.pi * n / b] for m, n in pts])
    q2 = (q ** 2).sum(axis=1)
    order = sorted(range(len(pts)), key=lambda k: (q2[k], pts[k][0], pts[k][1]))
    pts = [pts[k] for k in order]
    q, q2 = q[order], q2[order]
    c = kappa * q2 ** 2 + args.tension_factor * sigma * q2
    rate = c / xi
    var = args.noise_variance_factor * kT / (c * area / 2.0)
    tau1 = 1.0 / rate[0]
    dt = args.dt_tau1 * tau1
    rho = np.exp(-rate * dt)
    kick = np.sqrt(var * (1.0 - rho ** 2))
    steps = round((args.burn_in_tau1 + args.duration_tau1) / args.dt_tau1)
    x = np.array(args.positions) * a
    r = np.column_stack([x, np.full_like(x, 0.5 * b)])
    phase = r @ q.T  # (positions, modes)
    cos, sin = np.cos(phase), np.sin(phase)
    rng = np.random.default_rng(args.seed)
    nt, nm = args.trajectories, len(pts)
    A = np.zeros((nt, nm))
    B = np.zeros((nt, nm))
    heights = np.zeros((nt, steps + 1, len(x)))
    amps = np.zeros((nt, steps + 1, 2 * args.modes))
    for s in range(1, steps + 1):
        A = rho * A + kick * rng.standard_normal((nt, nm))
        B = rho * B + kick * rng.standard_normal((nt, nm))
        heights[:, s] = A @ cos.T + B @ sin.T
        amps[:, s, 0::2] = A[:, : args.modes]
        amps[:, s, 1::2] = B[:, : args.modes]
    t = np.arange(steps + 1) * dt
    os.makedirs(os.path.join(args.out, args.run), exist_ok=True)
    files = []
    for j in range(nt):
        name = f"{args.run}/trajectory-{j:04d}.npy"
        np.save(os.path.join(args.out, name), np.column_stack([t, heights[j], amps[j]]))
        files.append(name)
    sidecar = {
        "format": "langevin-fem-trajectories",
        "version": 1,
        "producer": "examples/membrane-simulator/simulate.py (NumPy %s), Fourier-space Brownian dynamics, %d modes%s"
        % (np.__version__, 2 * nm, "".join(
            f", {what} x{f}" for what, f in [("noise variance", args.noise_variance_factor),
                                              ("tension", args.tension_factor)] if f != 1.0)),
        "dims": 3,
        "membrane": {"width": a, "height": b, "bending_rigidity": kappa, "tension": sigma,
                     "drag": xi, "kt": kT, "boundary": "periodic"},
        "runs": [{
            "name": args.run,
            "dt_sample": dt,
            "start": "rest",
            "burn_in": args.burn_in_tau1 * tau1,
            "positions": [float(v) for v in x],
            "modes": 2 * args.modes,
            "files": files,
        }],
    }
    with open(os.path.join(args.out, "data.json"), "w") as f:
        json.dump(sidecar, f, indent=2)
    print(f"wrote {nt} trajectories x {len(t)} rows to {args.out} ({2 * nm} real modes, "
          f"cut-off |(m, n)| <= {args.cutoff}, dt = {args.dt_tau1} tau1)")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="data directory to write")
    p.add_argument("--tension", type=float, default=20.0, help="sigma (kappa = xi = kT = a = b = 1)")
    p.add_argument("--cutoff", type=int, default=16, help="lattice cut-off M")
    p.add_argument("--dt-tau1", type=float, default=0.02, help="time step (= time between rows) in tau1")
    p.add_argument("--modes", type=int, default=12, help="slowest lattice points whose amplitudes are written (two real modes each)")
    p.add_argument("--positions", type=float, nargs="+", default=[0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0], help="x/a on the midline")
    p.add_argument("--trajectories", type=int, default=64)
    p.add_argument("--duration-tau1", type=float, default=40.0, help="after burn-in")
    p.add_argument("--burn-in-tau1", type=float, default=3.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--run", default="numpy-fourier", help="run name")
    p.add_argument("--noise-variance-factor", type=float, default=1.0, help="fault: noise variance times this")
    p.add_argument("--tension-factor", type=float, default=1.0, help="fault: sigma simulated times this, the sidecar stating sigma")
    simulate(p.parse_args())


if __name__ == "__main__":
    main()
