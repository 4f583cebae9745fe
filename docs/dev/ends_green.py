#!/usr/bin/env python3
"""Symbolic derivation of the equilibrium covariance of the filament with any ends (issue #29).

Derives, with sympy, the Green's function G(u, v) of d^4/du^4 on [0, 1] (L = EI = 1) for
every pair of ends, which `src/spectral/ends.rs` tabulates (its module docs): kT L^3/EI
times G is the equilibrium covariance of the elastic deflection, <w(x) w(y)>.

Method. For u < v and u > v, G is a polynomial in u: a cubic plus, where the ends allow
rigid modes psi_k, the particular solution -int_0^u (u - t)^3/6 P(t, v) dt of
G'''' = -P, with P(u, v) = sum_k psi_k(u) psi_k(v) / int psi_k^2 the projector on the
rigid modes. The two end conditions on each side (hinged G = G'' = 0, clamped G = G' = 0,
free G'' = G''' = 0), continuity of G, G', G'' at u = v and the unit jump of G''' there
fix the eight coefficients, up to the rigid modes where there are some; the orthogonality
int_0^1 G(u, v) psi_k(u) du = 0 fixes those. The script prints G for u <= v and its
diagonal for each pair of ends, and checks the symmetry G(u, v) = G(v, u).

Usage: python3 docs/dev/ends_green.py  (a few seconds)
"""
import sympy as sp

u, v, t = sp.symbols("u v t", real=True)
a = sp.symbols("a0:4")
b = sp.symbols("b0:4")

ENDS = {"h": "hinged", "c": "clamped", "f": "free"}


def conditions(end, f, at):
    d = [sp.diff(f, u, k).subs(u, at) for k in range(4)]
    return {"h": [d[0], d[2]], "c": [d[0], d[1]], "f": [d[2], d[3]]}[end]


def rigid_modes(left, right):
    if (left, right) == ("f", "f"):
        return [sp.Integer(1), u - sp.Rational(1, 2)]
    if (left, right) == ("h", "f"):
        return [u]
    if (left, right) == ("f", "h"):
        return [1 - u]
    return []


def green(left, right):
    rigid = rigid_modes(left, right)
    projector = sp.Integer(0) + sum(
        p * p.subs(u, v) / sp.integrate(p * p, (u, 0, 1)) for p in rigid
    )
    particular = -sp.integrate((u - t) ** 3 / 6 * projector.subs(u, t), (t, 0, u))
    lo = sum(a[k] * u**k for k in range(4)) + particular
    hi = sum(b[k] * u**k for k in range(4)) + particular
    eqs = conditions(left, lo, 0) + conditions(right, hi, 1)
    eqs += [(sp.diff(hi, u, k) - sp.diff(lo, u, k)).subs(u, v) for k in range(3)]
    eqs.append((sp.diff(hi, u, 3) - sp.diff(lo, u, 3)).subs(u, v) - 1)
    unknowns = list(a) + list(b)
    (sol,) = sp.solve(eqs, unknowns, dict=True)
    lo, hi = lo.subs(sol), hi.subs(sol)
    free = [s for s in unknowns if s not in sol]
    if free:
        orth = [
            sp.integrate(lo * p, (u, 0, v)) + sp.integrate(hi * p, (u, v, 1)) for p in rigid
        ]
        (fix,) = sp.solve(orth, free, dict=True)
        lo, hi = lo.subs(fix), hi.subs(fix)
    lo, hi = sp.factor(sp.expand(lo)), sp.factor(sp.expand(hi))
    assert sp.simplify(lo - hi.subs({u: v, v: u}, simultaneous=True)) == 0, "not symmetric"
    return lo, sp.factor(sp.expand(lo.subs(v, u)))


def main():
    for left in "hcf":
        for right in "hcf":
            lo, diag = green(left, right)
            print(f"{ENDS[left]}-{ENDS[right]}:")
            print(f"  G(u, v), u <= v: {lo}")
            print(f"  G(u, u):         {diag}")


if __name__ == "__main__":
    main()
