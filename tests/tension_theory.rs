//! Tests of the exact stored-length theory (`langevin_fem::theory::compression`) in
//! tension and far in the tails: the filament under large tension and in the entropic
//! (inextensible) stretching regime against closed-form asymptotes, the documented
//! tension bound of the CLI, and the saddle-point contour against an independent
//! real-space quadrature of a law with a closed-form density.
//!
//! Deterministic (no sampling). Units L = kT = 1 (EI = P, EA = S) unless stated.

use langevin_fem::FilamentParams;
use langevin_fem::theory::{
    CompressionTheory, DEFAULT_CONTINUUM_MODES, Dims, GlobalConstraint, MIN_STRAIN_RATIO,
    STRETCH_BEND_RATIO_RANGE, StoredLengthLaw,
};
use std::f64::consts::PI;

fn dimensionless(p: f64, s: f64) -> FilamentParams {
    FilamentParams {
        length: 1.0,
        bending_rigidity: p,
        stretch_rigidity: s,
        drag: 1.0,
        kt: 1.0,
    }
}

fn continuum(p: &FilamentParams, dims: Dims) -> CompressionTheory {
    CompressionTheory::new(
        p,
        StoredLengthLaw::continuum(p, dims, DEFAULT_CONTINUUM_MODES).unwrap(),
    )
    .unwrap()
}

/// What: the large-tension limit ε ≪ 0 of the continuum: Hookean `EA·ε` plus the entropic
/// correction, and the Gaussian mean field becoming exact.
/// Reference (derivation): `F = EA(ε − ⟨s⟩)`; under a tension f ≫ F_c0 the mean stored
/// length is `⟨s⟩ = d c₁ Σ_n 1/(n² + x)`, `x = f/F_c0`, `c₁ = kT L/(2EIπ²)`, and
/// `Σ 1/(n² + x) = (π√x coth π√x − 1)/(2x)`, so `⟨s⟩ = (d kT/(4√(EI f)))(1 − 1/(π√x))` up
/// to `e^{−2π√x}`. With `f = EA(|ε| + ⟨s⟩)`, `x = |r|(1 + O(x^{−3/2}))`, `r = ε/ε_c0`:
/// `F − EAε = −(EA d kT/(4√(EI·EA|ε|)))·(1 − 1/(π√|r|) + O(|r|^{−3/2}))`. The exact force
/// differs from the mean field `(kT/L)η̂` by the Laplace correction
/// `(kT/L)ψ'''/(2(ψ'' + 1/(2A))²)`, which relative to the entropic term falls as `x^{−2}`.
/// Set-up: P = 100, S = 10⁶ (the paper), 2D and 3D, r = −10² … −10⁶.
/// Tolerance: `|Q − (1 − 1/(π√|r|))| ≤ |r|^{−3/2} + 16ε_mach|F|/|F − EAε|` for
/// `Q = (F − EAε)/entropic` (observed 0.4|r|^{−3/2}; the last term is the rounding of F
/// itself, which the difference amplifies); `|F − F_mf| ≤ |F − EAε|(1/r² + 16ε_mach
/// |F|/|F − EAε|)` (observed 0.36/r²).
#[test]
fn large_tension_is_hookean_plus_entropic() {
    let (pp, s) = (100.0, 1e6);
    let p = dimensionless(pp, s);
    for dims in [Dims::Two, Dims::Three] {
        let d = dims.copies() as f64;
        let th = continuum(&p, dims);
        for r in [-1e2, -1e3, -1e4, -1e5, -1e6] {
            let eps = r * p.euler_strain();
            let f = th.mean_force(eps).unwrap();
            let f_mf = th.mean_field_force(eps).unwrap();
            let entropic = -s * d / (4.0 * (pp * s * eps.abs()).sqrt());
            let excess = f - s * eps;
            let rounding = 16.0 * f64::EPSILON * f.abs() / excess.abs();
            let q = excess / entropic;
            let predicted = 1.0 - 1.0 / (PI * r.abs().sqrt());
            assert!(
                (q - predicted).abs() <= r.abs().powf(-1.5) + rounding,
                "{dims:?} r {r:e}: Q {q} vs {predicted}"
            );
            assert!(
                (f - f_mf).abs() <= excess.abs() * (1.0 / (r * r) + rounding),
                "{dims:?} r {r:e}: F {f} vs mean field {f_mf}"
            );
        }
    }
}

/// What: the entropic-stretching asymptote of the inextensible filament: at imposed strain
/// ε → 0⁺ (the imposed extension approaching the thermal stored length) the tension is
/// `f = −⟨F⟩ → (d kT/(4⟨s⟩))²/EI`, with the sub-leading correction derived here.
/// Reference (derivation): as A → ∞, `⟨F⟩ → −(kT/L)(ln p₀)'(s)` at `s = ⟨s⟩`; the saddle
/// point (Laplace) form `ln p₀(s) = ψ(η) − ηs − ½ln(2πψ''(η)) + O(1/N_eff)`, `ψ'(η) = s`,
/// gives `f = −(kT/L)(η + ψ'''/(2ψ''²))`. In the continuum with `x = f_mf/F_c0 ≫ 1`:
/// `s = dc₁(π/(2√x) − 1/(2x))` (mean field) and `ψ'''/(2ψ''²) = 3√x/(πdc₁)`, so with
/// `f₀ = (d kT/(4s))²/EI` and `x₀ = f₀/F_c0`:
/// `f/f₀ = 1 − (2 + 6/d)/(π√x₀) + O(1/x₀)`
/// (−2/(π√x₀) from the mean field's end correction, −6/(πd√x₀) from the fluctuations).
/// Set-up: P = 100 and S = 10¹⁶ (S/P² = 10¹², the top of the CLI range: the stretching
/// Gaussian's variance 1/(2A) is ≤ 2.5·10⁻⁴ of ψ'' at x₀ ≤ 10⁴), 2D and 3D, the strain
/// that puts `⟨s⟩` at the target `x₀ = 10², 10³, 10⁴`; ⟨s⟩ = ε − ⟨F⟩/EA exactly.
/// Tolerance: `|f/f₀ − 1 + (2 + 6/d)/(π√x₀)| ≤ 0.5/x₀` (a tolerance falling as the
/// omitted order; observed 0.30/x₀ in 2D, 0.20/x₀ in 3D); the leading error must be the
/// derived one, i.e. `|f/f₀ − 1| > (2 + 6/d)/(π√x₀) − 0.5/x₀`.
#[test]
fn entropic_stretching_asymptote() {
    let pp = 100.0;
    let s = 1e12 * pp * pp;
    let p = dimensionless(pp, s);
    for dims in [Dims::Two, Dims::Three] {
        let d = dims.copies() as f64;
        let th = continuum(&p, dims);
        for x0 in [1e2, 1e3, 1e4] {
            let f_target = x0 * p.euler_load();
            let stored = d / (4.0 * (pp * f_target).sqrt());
            let eps = stored - f_target / s;
            assert!(eps > 0.0);
            let f = -th.mean_force(eps).unwrap();
            let stored = eps + f / s;
            let f0 = (d / (4.0 * stored)).powi(2) / pp;
            let x0 = f0 / p.euler_load();
            let rel = f / f0 - 1.0;
            let correction = (2.0 + 6.0 / d) / (PI * x0.sqrt());
            assert!(
                (rel + correction).abs() <= 0.5 / x0,
                "{dims:?} x0 {x0:e}: f/f0 - 1 = {rel:e}, derived {:e}",
                -correction
            );
            assert!(rel.abs() > correction - 0.5 / x0);
        }
    }
}

/// What: the documented tension bound of the CLI, `ε/ε_c0 ≥ MIN_STRAIN_RATIO = −10⁸`:
/// at the bound, over the whole S/P² range, the quadrature work stays small and the force
/// is Hookean.
/// Reference: `F/F_c0 = r − ⟨s⟩_ε/ε_c0` with `0 ≤ ⟨s⟩_ε ≤ ⟨s⟩₀` (tension pulls undulations
/// out), so `r − ⟨s⟩₀/ε_c0 ≤ F/F_c0 ≤ r`.
/// Set-up: P = 100, S/P² = 10⁻², 10⁰, …, 10¹², 2D, continuum and 10 elements.
/// Tolerance: work ≤ 10⁴ mode evaluations (observed ≈ 500); the bracket above up to
/// 10⁻¹⁴|r| (rounding).
#[test]
fn tension_bound_keeps_the_work_bounded() {
    let pp = 100.0;
    let (k_lo, k_hi) = STRETCH_BEND_RATIO_RANGE;
    let mut kappa = k_lo;
    while kappa <= k_hi * 1.001 {
        let p = dimensionless(pp, kappa * pp * pp);
        for law in [
            StoredLengthLaw::continuum(&p, Dims::Two, DEFAULT_CONTINUUM_MODES).unwrap(),
            StoredLengthLaw::discrete(&p, Dims::Two, 10).unwrap(),
        ] {
            let s0 = law.mean();
            let th = CompressionTheory::new(&p, law).unwrap();
            let r = MIN_STRAIN_RATIO;
            let work = th.quadrature_work(r * p.euler_strain()).unwrap();
            assert!(work <= 1e4, "kappa {kappa:e}: work {work:e}");
            let f = th.force_ratio(r).unwrap();
            let slack = 1e-14 * r.abs();
            assert!(
                f <= r + slack && f >= r - s0 / p.euler_strain() - slack,
                "kappa {kappa:e}: F/F_c0 = {f}"
            );
        }
        kappa *= 100.0;
    }
}

/// `ln p₀(s)` of `s = Σ c_i χ²₂` (distinct c_i): a hypoexponential law with rates
/// `λ_i = 1/(2c_i)`, `p₀(s) = Σ_i λ_i Π_{j≠i} λ_j/(λ_j − λ_i) e^{−λ_i s}`. For
/// `λ_max s ≤ 1` the alternating sum cancels, so there the series
/// `p₀(s) = Πλ · Σ_n (−1)^n h_n(λ) s^{k−1+n}/(k−1+n)!` (h_n the complete homogeneous
/// symmetric polynomials, the Taylor coefficients of `Π 1/(1 + λ_i t)`' inverse Laplace
/// transform) is used instead; otherwise the sum, factored by the slowest exponential.
fn hypoexponential_log_density(c: &[f64], s: f64) -> f64 {
    let lam: Vec<f64> = c.iter().map(|c| 0.5 / c).collect();
    let k = lam.len();
    let lmax = lam.iter().fold(0.0_f64, |a, &b| a.max(b));
    if lmax * s <= 1.0 {
        // h_n by the recurrence over the rates
        let terms = 60;
        let mut h = vec![0.0; terms];
        h[0] = 1.0;
        for &l in &lam {
            for n in 1..terms {
                h[n] += l * h[n - 1];
            }
        }
        let prod: f64 = lam.iter().product();
        // s^{k−1+n}/(k−1+n)! relative to s^{k−1}/(k−1)!
        let mut sum = 0.0;
        let mut p = 1.0;
        for (n, hn) in h.iter().enumerate() {
            sum += if n % 2 == 0 { hn * p } else { -hn * p };
            p *= s / (k + n) as f64;
        }
        let lead: f64 = (1..k).map(|j| (s / j as f64).ln()).sum();
        prod.ln() + lead + sum.ln()
    } else {
        let lmin = lam.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let mut sum = 0.0;
        for (i, &li) in lam.iter().enumerate() {
            let mut coef = li;
            for (j, &lj) in lam.iter().enumerate() {
                if j != i {
                    coef *= lj / (lj - li);
                }
            }
            sum += coef * (-(li - lmin) * s).exp();
        }
        -lmin * s + sum.ln()
    }
}

/// `⟨ε − s⟩` under `p₀(s)e^{−A(s−ε)²}` by composite Simpson in log-scaled form over
/// `[lo, hi]` (2·10⁵ panels), with the integrand at both ends below e⁻⁴⁰ of its maximum.
fn real_space_mean_deficit(c: &[f64], a: f64, eps: f64, lo: f64, hi: f64) -> f64 {
    let n = 200_000;
    let h = (hi - lo) / n as f64;
    let log_g = |s: f64| hypoexponential_log_density(c, s) - a * (s - eps) * (s - eps);
    let vals: Vec<f64> = (0..=n).map(|i| log_g(lo + i as f64 * h)).collect();
    let top = vals.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v));
    assert!(
        vals[0] - top < -40.0 || lo == 0.0,
        "window start: {}",
        vals[0] - top
    );
    assert!(vals[n] - top < -40.0, "window end: {}", vals[n] - top);
    let (mut z, mut m) = (0.0, 0.0);
    for (i, v) in vals.iter().enumerate() {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let g = w * (v - top).exp();
        z += g;
        m += g * (eps - (lo + i as f64 * h));
    }
    m / z
}

/// What: the saddle-point contour against an independent quadrature far in the tails (large
/// compression and large tension), where the real-line Fourier integral would cancel
/// catastrophically (Z ∝ e^{−ε/(2c₁)} or e^{−Aε²}).
/// Reference: `⟨ε − s⟩ = ∫(ε − s)p₀(s)e^{−A(s−ε)²}ds / ∫p₀(s)e^{−A(s−ε)²}ds` by composite
/// Simpson in real space, with the closed-form hypoexponential density of four χ²₂ weights
/// (`hypoexponential_log_density`), evaluated in log-scaled form (no exponent overflows).
/// Set-up: weights c = 1, 0.6, 0.3, 0.1 (d = 2, ⟨s⟩₀ = 4), kT = X = 1, S = 100 (A = 50) and
/// S = 10⁴ (A = 5000); ε = 40, 100, 400 (compression: ε/⟨s⟩₀ up to 100) and ε = −5, −50,
/// −500 (tension). The contour's `⟨ε − s⟩ = ⟨F⟩/S` of a `CompressionTheory` built from a
/// `GlobalConstraint` (the generic route the membrane uses).
/// Tolerance: 10⁻¹⁰ relative (Simpson with ≥ 5000 panels per width of the integrand: error
/// ≈ 10⁻¹⁴; the contour's ≈ 10⁻¹⁴).
#[test]
fn contour_matches_real_space_quadrature_in_the_tails() {
    let c = [1.0, 0.6, 0.3, 0.1];
    for s in [100.0, 1e4] {
        let constraint = GlobalConstraint {
            stiffness: s,
            measure: 1.0,
            kt: 1.0,
            reference_load: 1.0,
            reference_strain: 1.0,
        };
        let law = StoredLengthLaw::from_weights(c.to_vec(), 2).unwrap();
        let th = CompressionTheory::with_constraint(constraint, law).unwrap();
        let a = constraint.stretch_exponent();
        let width = (40.0 / a).sqrt();
        for eps in [40.0, 100.0, 400.0, -5.0, -50.0, -500.0] {
            let contour = th.mean_force(eps).unwrap() / s;
            let (lo, hi) = if eps > 0.0 {
                // the tilted Gaussian peaks at ε − λ₁/(2A), λ₁ = 1/(2c₁)
                let peak = eps - 0.25 / (c[0] * a);
                (peak - 1.2 * width, peak + 1.2 * width)
            } else {
                // decay e^{−2A|ε|s} from s = 0, times s³
                (0.0, (80.0 / (2.0 * a * eps.abs())).min(2.0 * width))
            };
            let reference = real_space_mean_deficit(&c, a, eps, lo, hi);
            println!(
                "S {s:e} eps {eps}: relative difference {:e}",
                contour / reference - 1.0
            );
            assert!(
                (contour / reference - 1.0).abs() <= 1e-10,
                "S {s:e} eps {eps}: contour {contour:e} vs real space {reference:e}"
            );
        }
    }
}
