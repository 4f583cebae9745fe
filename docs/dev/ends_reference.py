#!/usr/bin/env python3
"""High-precision reference values for the filament with any ends (issue #29).

Prints, as Rust constants, what `tests/ends_theory.rs` compares `EndedBeam` against:

- ROOTS: the first five elastic roots beta_n = q_n L of each characteristic equation
  (sin b = 0; cos b cosh b = 1; cos b cosh b = -1; tan b = tanh b), 25 digits;
- SHAPES: the normalized eigenfunctions phi_n(x) for every pair of ends, n in
  {1, 7, 20, 50}, at several x/L (both ends and points near them), 20 digits.

The script is independent of the Rust code: it solves the characteristic equations in
their textbook form (no rewriting), builds each eigenfunction in the textbook basis
cos, sin, cosh, sinh from the 4 x 4 boundary-condition matrix, normalizes it by numerical
quadrature, and fixes its sign, all in arbitrary precision. The textbook forms cancel
catastrophically for large b (cosh b ~ e^b / 2 ~ 1e68 at n = 50), so every evaluation
runs at 60 + 2 b / ln 10 significant digits and is rounded to mp.dps = 50 afterwards.

Conventions (as in `src/spectral/ends.rs`): u = x / L; ends are `<left>-<right>` with the
left end at x = 0; phi_n normalized to int_0^1 phi^2 du = 1/2 (so hinged-hinged gives
sin(n pi u)); sign: the first non-zero Taylor coefficient of phi_n at u = 0 is positive.

Usage: python3 docs/dev/ends_reference.py > /tmp/ends_reference.rs  (takes ~1 minute)
"""
import mpmath
from mpmath import mp, mpf, cos, sin, cosh, sinh, tan, tanh, pi, findroot, quad, matrix
from mpmath import sqrt, linspace, nstr, ln

mp.dps = 50

ENDS = ["hinged", "clamped", "free"]
NS = [1, 7, 20, 50]
US = ["0.0", "0.001", "0.02", "0.25", "0.5", "0.73", "0.98", "0.999", "1.0"]


def family(left, right):
    pair = {left, right}
    if left == right == "hinged":
        return "sin"
    if left == right:  # clamped-clamped, free-free
        return "coscosh+1"
    if pair == {"clamped", "free"}:
        return "coscosh-1"
    return "tantanh"  # clamped-hinged, hinged-free and mirrors


def char(fam, b):
    if fam == "sin":
        return sin(b)
    if fam == "coscosh+1":
        return cos(b) * cosh(b) - 1
    if fam == "coscosh-1":
        return cos(b) * cosh(b) + 1
    return tan(b) - tanh(b)


def guess(fam, n):
    """The asymptotic root and a bracket of half-width 0.45 around it, which holds
    exactly one root (the roots are about pi apart; the first cos cosh = -1 root sits
    0.30 above pi/2)."""
    shift = {"sin": 0, "coscosh+1": mpf(1) / 2, "coscosh-1": -mpf(1) / 2, "tantanh": mpf(1) / 4}
    return (n + shift[fam]) * pi


def root(fam, n):
    g = guess(fam, n)
    with mp.workdps(60 + int(2 * g / ln(10))):
        if fam == "sin":
            r = n * pi
        else:
            lo, hi = g - mpf("0.45"), g + mpf("0.45")
            if fam == "tantanh":
                # tan has a pole at (n + 1/2) pi, outside [lo, hi]; tan - tanh changes
                # sign once in (n pi, (n + 1/4) pi].
                lo, hi = n * pi + mpf("1e-30"), g + mpf("0.1")
            assert char(fam, lo) * char(fam, hi) < 0, (fam, n)
            r = findroot(lambda b: char(fam, b), (lo, hi), solver="anderson")
            # polish with Newton from the bracketed root
            r = findroot(lambda b: char(fam, b), r)
        return +r


def derivs(coef, b, u):
    """phi and its first three u-derivatives, phi = a cos bu + b2 sin bu + c cosh bu + d sinh bu."""
    a, b2, c, d = coef
    x = b * u
    ca, sa, ch, sh = cos(x), sin(x), cosh(x), sinh(x)
    return [
        a * ca + b2 * sa + c * ch + d * sh,
        b * (-a * sa + b2 * ca + c * sh + d * ch),
        b**2 * (-a * ca - b2 * sa + c * ch + d * sh),
        b**3 * (a * sa - b2 * ca + c * sh + d * ch),
    ]


def rows(end, b, u):
    """Boundary-condition rows (on the coefficients) of one end at u."""
    basis = [derivs(e, b, u) for e in ([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1])]
    orders = {"hinged": (0, 2), "clamped": (0, 1), "free": (2, 3)}[end]
    return [[basis[j][k] for j in range(4)] for k in orders]


def eigenfunction(left, right, n):
    """(beta, coefficients) of phi_n, normalized and signed, at high working precision."""
    fam = family(left, right)
    b = root(fam, n)
    prec = 60 + int(2 * b / ln(10))
    with mp.workdps(prec):
        m = rows(left, b, 0) + rows(right, b, 1)
        # Null vector: cofactors of the row whose deletion leaves the best-conditioned
        # 3 x 3 minor set (the largest cofactor vector).
        best = None
        for drop in range(4):
            keep = [m[i] for i in range(4) if i != drop]
            cof = []
            for j in range(4):
                sub = matrix([[keep[i][k] for k in range(4) if k != j] for i in range(3)])
                cof.append((-1) ** j * mp.det(sub))
            size = max(abs(v) for v in cof)
            if best is None or size > best[0]:
                best = (size, cof)
        coef = [v / best[0] for v in best[1]]
        # check the null vector
        resid = max(abs(sum(m[i][j] * coef[j] for j in range(4))) for i in range(4))
        assert resid < mpf(10) ** (-(prec - 40)) * cosh(b) ** 2, (left, right, n, resid)

        def phi2(u):
            with mp.workdps(prec):
                return derivs(coef, b, u)[0] ** 2

    # Normalization by Gauss-Legendre quadrature on 4 (n + 2) panels, to 60 digits (the
    # integrand is evaluated at the full working precision).
    with mp.workdps(60):
        norm2 = quad(phi2, linspace(0, 1, 4 * (n + 2) + 1), method="gauss-legendre")
    with mp.workdps(prec):
        scale = 1 / sqrt(2 * norm2)
        # Sign: first non-zero Taylor coefficient at u = 0.
        d0 = derivs(coef, b, mpf(0))
        big = max(abs(v) / b**k for k, v in enumerate(d0))
        lead = next(v for k, v in enumerate(d0) if abs(v) / b**k > big * mpf(10) ** (-30))
        if lead < 0:
            scale = -scale
        coef = [v * scale for v in coef]
    return b, coef, prec


def main():
    print(f"// Printed by docs/dev/ends_reference.py (mpmath {mpmath.__version__}, "
          f"mp.dps = {mp.dps}); do not edit by hand.")
    print("// First five elastic roots beta_n = q_n L of each characteristic equation.")
    for fam, name in [("sin", "SINE"), ("coscosh+1", "COS_COSH_PLUS_ONE"),
                      ("coscosh-1", "COS_COSH_MINUS_ONE"), ("tantanh", "TAN_TANH")]:
        vals = ", ".join(nstr(root(fam, n), 25) for n in range(1, 6))
        print("#[rustfmt::skip]")
        print(f"const ROOTS_{name}: [f64; 5] = [{vals}];")
    print()
    print("// (left, right, n, [(u = x/L, phi_n(u)); 9]): normalized int_0^1 phi^2 du = 1/2,")
    print("// first non-zero Taylor coefficient at u = 0 positive.")
    print("type ShapeRow = (&'static str, &'static str, usize, [(f64, f64); 9]);")
    print("#[rustfmt::skip]")
    print("const SHAPES: &[ShapeRow] = &[")
    for left in ENDS:
        for right in ENDS:
            for n in NS:
                b, coef, prec = eigenfunction(left, right, n)
                with mp.workdps(prec):
                    vals = []
                    for us in US:
                        u = mpf(us)
                        v = derivs(coef, b, u)[0]
                        if abs(v) < mpf(10) ** (-40):
                            v = mpf(0)
                        vals.append(f"({us}, {nstr(v, 20, min_fixed=-3, max_fixed=3)})")
                print(f'    ("{left}", "{right}", {n}, [{", ".join(vals)}]),')
    print("];")


if __name__ == "__main__":
    main()
