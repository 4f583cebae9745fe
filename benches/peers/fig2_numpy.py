#!/usr/bin/env python3
"""The paper's Fig. 2 in plain NumPy: the peer baseline of `make bench-peers`.

The model of verification/compression-{2d,3d}.toml: a hinged filament, L = kT = xi = 1,
EI = 100, EA = 1e6, 10 equal Hermite-cubic elements (w, w' per node, w = 0 at both ends;
in 3D a second transverse component v). With u eliminated the energy is
U = 1/2 w'Kw + (EA L/2)(s - eps)^2, s = w'Gw/(2L), and the compressive force is
F = EA(eps - s); the transverse force is -Kw + F G w. Damping C = xi * int N'N dx.

Integrator: exponential Euler in the exact bending modes (K phi = lam C phi), the
stretching force explicit, an ensemble of trajectories vectorized as one array:
  q <- e^{-lam dt} q + (1 - e^{-lam dt})/lam * Phi'(F G w) + sqrt(kT(1 - e^{-2 lam dt})/lam) Z.
Each strain runs until the batch-means standard error of <F> (per-trajectory time
averages, std over trajectories / sqrt(n)) is <= 0.01 F_c0, or until the cap.
The explicit stretching force leaves an O(dt) bias on <F>: --theory shows it.
"""
import argparse
import json
import sys
import time

import numpy as np

L, KT, XI, EI, EA, NEL = 1.0, 1.0, 1.0, 100.0, 1.0e6, 10
RATIOS = [0, 0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10]
FC0, EPSC0, TAU1 = np.pi**2 * EI / L**2, np.pi**2 * EI / (EA * L**2), XI * L**4 / (np.pi**4 * EI)


def assemble():
    """K, C, G over the free DOFs (w at both ends removed) by 4-point Gauss quadrature."""
    h, ndof = L / NEL, 2 * (NEL + 1)
    x, wq = np.polynomial.legendre.leggauss(4)
    r = (x + 1) / 2  # reference coordinate in [0, 1]
    one = np.ones_like(r)
    # Hermite cubics (w1, w1', w2, w2') and their first and second derivatives in x.
    N = np.array([1 - 3*r**2 + 2*r**3, h*(r - 2*r**2 + r**3), 3*r**2 - 2*r**3, h*(r**3 - r**2)])
    dN = np.array([-6*r + 6*r**2, h*(1 - 4*r + 3*r**2), 6*r - 6*r**2, h*(3*r**2 - 2*r)]) / h
    ddN = np.array([-6*one + 12*r, h*(-4*one + 6*r), 6*one - 12*r, h*(6*r - 2*one)]) / h**2
    wx = wq * h / 2
    Ke, Ce, Ge = [(A * wx) @ A.T for A in (ddN, N, dN)]
    K, C, G = (np.zeros((ndof, ndof)) for _ in range(3))
    for e in range(NEL):
        i = slice(2 * e, 2 * e + 4)
        K[i, i] += EI * Ke
        C[i, i] += XI * Ce
        G[i, i] += Ge
    free = [d for d in range(ndof) if d not in (0, ndof - 2)]
    return [A[np.ix_(free, free)] for A in (K, C, G)]


def modes(K, C, G):
    """Generalized eigenpairs of (K, C) via Cholesky of C; B = Phi' G Phi."""
    Lc = np.linalg.cholesky(C)
    Li = np.linalg.inv(Lc)
    lam, Y = np.linalg.eigh(Li @ K @ Li.T)
    Phi = Li.T @ Y  # Phi' C Phi = I, Phi' K Phi = diag(lam)
    return lam, Phi.T @ G @ Phi


def run_strain(rng, lam, B, comps, ratio, a):
    dt = a.dt_tau1 * TAU1
    eps = ratio * EPSC0
    decay = np.exp(-lam * dt)
    drift = -np.expm1(-lam * dt) / lam
    noise = np.sqrt(-KT * np.expm1(-2 * lam * dt) / lam)
    shape = (a.trajectories, comps, lam.size)
    q = rng.standard_normal(shape) * np.sqrt(KT / lam)  # bending-only equilibrium sample

    z = np.empty(shape)

    def step(q):
        Bq = (q.reshape(-1, lam.size) @ B).reshape(shape)  # Phi'G w (B symmetric), one GEMM
        F = EA * (eps - np.einsum("tcn,tcn->t", q, Bq) / (2 * L))
        Bq *= F[:, None, None]
        Bq *= drift
        q *= decay
        q += Bq
        q += noise * rng.standard_normal(out=z)
        return q, F

    for _ in range(round(a.burn_in_tau1 / a.dt_tau1)):
        q, _ = step(q)
    every = round(a.sample_every_tau1 / a.dt_tau1)
    per_check = round(a.check_every_tau1 / a.sample_every_tau1)
    total, count, t = np.zeros(a.trajectories), 0, 0.0
    while True:
        for _ in range(per_check):
            for _ in range(every):
                q, F = step(q)
            total += F  # F(w) of the state the last step started from
            count += 1
        t += per_check * a.sample_every_tau1
        means = total / count / FC0
        se = means.std(ddof=1) / np.sqrt(a.trajectories)
        if (se <= a.target_se and t >= a.min_tau1) or t >= a.cap_tau1:
            return means.mean(), se, t


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--dims", type=int, nargs="+", default=[2, 3])
    p.add_argument("--ratios", type=float, nargs="+", default=RATIOS)
    p.add_argument("--trajectories", type=int, default=256)
    p.add_argument("--dt-tau1", type=float, default=0.0025)
    p.add_argument("--burn-in-tau1", type=float, default=5.0)
    p.add_argument("--sample-every-tau1", type=float, default=0.05)
    p.add_argument("--check-every-tau1", type=float, default=2.0)
    p.add_argument("--min-tau1", type=float, default=4.0)
    p.add_argument("--cap-tau1", type=float, default=400.0)
    p.add_argument("--target-se", type=float, default=0.01, help="in units of F_c0")
    p.add_argument("--seed", type=int, default=20261122)
    p.add_argument("--theory", action="append", default=[],
                   help="JSON of `langevin-fem theory compression` (one per dims; repeatable)")
    a = p.parse_args()

    print(f"numpy {np.__version__}, python {sys.version.split()[0]}")
    try:
        from threadpoolctl import threadpool_info
        for pool in threadpool_info():
            print("threadpool: " + ", ".join(f"{k}={pool.get(k)}" for k in
                  ("user_api", "internal_api", "num_threads", "architecture", "version")))
    except ImportError:
        print("threadpool: threadpoolctl not installed")
    theory = {}
    for path in a.theory:
        with open(path) as f:
            doc = json.load(f)
        theory[doc["dims"]] = {pt["strain_ratio"]: pt["force_ratio"] for pt in doc["points"]}

    K, C, G = assemble()
    lam, B = modes(K, C, G)
    print(f"{NEL} elements, {lam.size} DOFs per component, lam_1 tau1 = {lam[0] * TAU1:.6f}, "
          f"lam_max dt = {lam[-1] * a.dt_tau1 * TAU1:.1f}; {a.trajectories} trajectories, "
          f"dt = {a.dt_tau1} tau1, target s.e. {a.target_se} F_c0")
    rng = np.random.default_rng(a.seed)
    print(f"{'dims':>4} {'eps/eps_c0':>10} {'<F>/F_c0':>9} {'s.e.':>7} {'tau1':>6}"
          + (f" {'theory':>9} {'dev/se':>7}" if theory else ""))
    start, devs, ztot = time.process_time(), [], []
    for dims in a.dims:
        for ratio in a.ratios:
            f, se, t = run_strain(rng, lam, B, dims - 1, ratio, a)
            line = f"{dims:>4} {ratio:>10g} {f:>9.4f} {se:>7.4f} {t:>6.0f}"
            exact = theory.get(dims, {}).get(ratio)
            if exact is not None:
                devs.append(f - exact)
                ztot.append((f - exact) / se)
                line += f" {exact:>9.4f} {ztot[-1]:>+7.2f}"
            print(line, flush=True)
    cpu = time.process_time() - start
    if devs:
        z = np.array(ztot)
        print(f"vs exact theory: mean deviation {np.mean(devs):+.4f} F_c0, "
              f"max |dev| {np.max(np.abs(devs)):.4f} F_c0, chi2 = {np.sum(z**2):.1f} on {z.size} points, "
              f"{np.sum(np.abs(z) > 3)} points beyond 3 s.e.")
    print(f"total CPU {cpu:.1f} s (process_time)")
    print(f"numpy_cpu_seconds={cpu:.2f}")


if __name__ == "__main__":
    main()
