#!/usr/bin/env python3
"""An independent bead-spring (discrete worm-like chain) simulator in 2D, in NumPy.

It shares no code with langevin-fem. N + 1 beads at rest spacing b = L/N, overdamped
(drag zeta = xi b per bead), with the full nonlinear energy

    U = (k_s/2) sum_i (|r_{i+1} - r_i| - b)^2  +  kappa sum_{i=1}^{N-1} (1 - cos theta_i),

theta_i the angle between bonds i-1 and i (the cosine angle potential of LAMMPS and
Cytosim-like codes), integrated with explicit Euler-Maruyama,
r <- r - (dt/zeta) grad U + sqrt(2 kT dt/zeta) Z. Bead 0 is pinned; bead N is pinned
transversally and slides freely along x (a roller: no axial force), and neither end
bead carries an angle term, so both ends are hinged.

For small deflections the transverse motion decouples from the springs and is the
5-point finite-difference filament with h = b and EI = kappa b: declared as
`"model": "bead-spring"`, `langevin-fem check` judges it against that discretization's
exact discrete law. The filament is stiff (L/l_p = kT L/EI = 0.01) so that the nonlinear
terms (relative size ~ theta^2, about 1e-3 here) stay below what the data resolve.

The data: the transverse bead coordinates y_i at their nominal positions x_i = i b (and
the linear interpolant at L/4), and the sine amplitudes a_n = (2/N) sum_i y_i sin(n pi i/N).
`--noise-variance-factor 1.05` injects a 5 % error of the noise variance.
"""

import argparse
import json
import math
import os

import numpy as np


def forces(r, b, ks, kappa):
    """-grad U for positions r (trajectories, beads, 2)."""
    d = r[:, 1:] - r[:, :-1]  # bonds (T, N, 2)
    ln = np.linalg.norm(d, axis=2, keepdims=True)
    u = d / ln
    f = np.zeros_like(r)
    fs = ks * (ln - b) * u  # tension along each bond pulls its ends together
    f[:, :-1] += fs
    f[:, 1:] -= fs
    # bending: U_i = kappa (1 - u_{i-1}.u_i); dU/dd_{i-1} = -kappa (u_i - c u_{i-1}) / |d_{i-1}|
    c = np.sum(u[:, :-1] * u[:, 1:], axis=2, keepdims=True)
    ga = -kappa * (u[:, 1:] - c * u[:, :-1]) / ln[:, :-1]  # dU_i/d(bond i-1)
    gb = -kappa * (u[:, :-1] - c * u[:, 1:]) / ln[:, 1:]  # dU_i/d(bond i)
    # bond j = r_{j+1} - r_j: dU/dr_{j+1} += g, dU/dr_j -= g
    f[:, 1:-1] -= ga
    f[:, :-2] += ga
    f[:, 2:] -= gb
    f[:, 1:-1] += gb
    return f


def simulate(args):
    N = args.bonds
    L, EI, xi, kT = 1.0, 1.0, 1.0, args.kt
    b = L / N
    kappa = EI / b
    zeta = xi * b
    ks = 4.0 * EI / b**3  # axial rate 4 ks/zeta = 16 EI/(xi b^4), the bending limit
    tau1 = xi * L**4 / (math.pi**4 * EI)
    dt = args.dt_tau1 * tau1
    every = max(1, round(args.sample_tau1 / args.dt_tau1))
    total = round((args.burn_in_tau1 + args.duration_tau1) / args.dt_tau1)
    total -= total % every
    lam_max = 16.0 * EI / (xi * b**4)
    if lam_max * dt >= 2.0:
        raise SystemExit(f"unstable: lambda_max dt = {lam_max * dt:.3g} >= 2")
    nt = args.trajectories
    rng = np.random.default_rng(args.seed)
    r = np.zeros((nt, N + 1, 2))
    r[:, :, 0] = np.arange(N + 1) * b
    free = np.ones((N + 1, 2))
    free[0, :] = 0.0  # pinned
    free[N, 1] = 0.0  # roller: slides along x
    sigma = math.sqrt(args.noise_variance_factor * 2.0 * kT * dt / zeta)
    rows = [r[:, :, 1].copy()]
    done = 0
    chunk = 2048 * every
    while done < total:
        n = min(chunk, total - done)
        z = sigma * rng.standard_normal((n, nt, N + 1, 2))
        for k in range(n):
            r = r + free * ((dt / zeta) * forces(r, b, ks, kappa) + z[k])
            if (done + k + 1) % every == 0:
                rows.append(r[:, :, 1].copy())
        done += n
    y = np.stack(rows, axis=1)  # (trajectories, rows, beads)
    dt_sample = every * dt
    x_nodes = np.arange(N + 1) * b
    positions = sorted(set([round(v, 12) for v in x_nodes] + [0.25 * L]))
    interp = np.zeros((N + 1, len(positions)))
    for j, xj in enumerate(positions):
        i = min(int(math.floor(xj / b + 1e-12)), N - 1)
        f = xj / b - i
        interp[i, j] += 1.0 - f
        interp[i + 1, j] += f
    n = np.arange(1, args.modes + 1)
    dst = np.zeros((N + 1, args.modes))
    dst[1:N] = (2.0 / N) * np.sin(np.outer(np.arange(1, N), n) * math.pi / N)
    t = np.arange(y.shape[1]) * dt_sample
    os.makedirs(os.path.join(args.out, args.run), exist_ok=True)
    files = []
    for j in range(nt):
        table = np.column_stack([t, y[j] @ interp, y[j] @ dst])
        name = f"{args.run}/trajectory-{j:04d}.npy"
        np.save(os.path.join(args.out, name), table)
        files.append(name)
    slope = np.sqrt(np.mean(((y[:, :, 1:] - y[:, :, :-1]) / b) ** 2))
    sidecar = {
        "format": "langevin-fem-trajectories",
        "version": 1,
        "producer": "examples/bead-spring-simulator/simulate.py (NumPy %s), %d beads, cosine angle potential, Euler-Maruyama%s"
        % (np.__version__, N + 1, "" if args.noise_variance_factor == 1.0 else f", noise variance x{args.noise_variance_factor}"),
        "dims": 2,
        "filament": {"length": L, "bending_rigidity": EI, "drag": xi, "kt": kT},
        "runs": [
            {
                "name": args.run,
                "dt_sample": dt_sample,
                "start": "rest",
                "burn_in": args.burn_in_tau1 * tau1,
                "positions": [float(p) for p in positions],
                "modes": args.modes,
                "discretization": {
                    "model": "bead-spring",
                    "elements": N,
                    "integrator": "euler-maruyama",
                    "noise": "consistent",
                    "dt": dt,
                },
                "files": files,
            }
        ],
    }
    with open(os.path.join(args.out, "data.json"), "w") as f:
        json.dump(sidecar, f, indent=2)
    print(
        f"wrote {nt} trajectories x {len(t)} rows to {args.out} "
        f"({N + 1} beads, dt = {args.dt_tau1} tau1, lambda_max dt = {lam_max * dt:.3g}, rms bond angle {slope:.3g} rad)"
    )


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True, help="data directory to write")
    p.add_argument("--bonds", type=int, default=10, help="bonds N (N + 1 beads)")
    p.add_argument("--kt", type=float, default=0.01, help="kT (EI = L = xi = 1)")
    p.add_argument("--dt-tau1", type=float, default=2e-4, help="time step in tau1")
    p.add_argument("--modes", type=int, default=6, help="sine amplitudes written")
    p.add_argument("--trajectories", type=int, default=32)
    p.add_argument("--duration-tau1", type=float, default=6.0, help="after burn-in")
    p.add_argument("--burn-in-tau1", type=float, default=4.0)
    p.add_argument("--sample-tau1", type=float, default=1e-3, help="time between rows")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--run", default="numpy-beads", help="run name")
    p.add_argument("--noise-variance-factor", type=float, default=1.0, help="fault: noise variance times this")
    simulate(p.parse_args())


if __name__ == "__main__":
    main()
