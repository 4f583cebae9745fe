//! Tests of the exact spectral reference (`langevin_fem::spectral`) for the hinged filament:
//! closed forms against mode sums, the limits of eq. (4), the honesty of the truncation
//! bounds, the mode spectra (with aliasing), and the exact modal simulator against the
//! analytic moments.
//!
//! Parameters are deliberately not all 1 (L = 2.5, EI = 0.7, ξ = 3, kT = 0.4), so that a
//! wrong power of L, EI, ξ or kT cannot cancel. Statistical checks use fixed seeds (named
//! consts) and a tolerance of Z = 4 standard errors each, where the standard error is the
//! exact one of the estimator (known analytically) or estimated from an ensemble of
//! independent trajectories; there are 25 such checks, so with independent estimators the
//! family-wise false-alarm probability for a fresh seed is below 25·6.3·10⁻⁵ ≈ 1.6·10⁻³
//! (Bonferroni; the suite also passed for six other seed sets).
//! Sample moments are computed inline (plain sums), not with `crate::stats`.

mod common;

use common::Z;
use common::filament::spectral_sample;
use common::seeds::{SEED_ENSEMBLE, SEED_EQUILIBRIUM, SEED_LARGE_STEP, SEED_REPRODUCIBLE};
use langevin_fem::error::Error;
use langevin_fem::params::FilamentParams;
use langevin_fem::rng::trajectory_rng;
use langevin_fem::spectral::{HingedBeam, MAX_MODES, ModalSimulator, inverse_fourth_power_tail};
use std::f64::consts::PI;

/// The hinged beam of [`spectral_sample`] (L = 2.5, EI = 0.7, ξ = 3, kT = 0.4).
fn beam() -> HingedBeam {
    HingedBeam::new(spectral_sample()).unwrap()
}

/// Positions (as fractions of L) used for the deterministic checks; 0 and 1 are hinges.
const FRACTIONS: [f64; 9] = [0.0, 0.05, 0.11, 0.3, 0.37, 0.5, 0.62, 0.9, 1.0];

/// What: the closed form ⟨w²(x)⟩ = kT x²(L−x)²/(3EI·L) against the mode sum
/// Σ_{n≤N} σₙ² sin²(nπx/L), for N = 1 … 100; plus the classical midspan value kT L³/(48EI).
/// Reference: equipartition mode sum (paper, after eq. 4) and the simply-supported-beam
/// midspan compliance L³/(48EI).
/// Tolerance: the reported rigorous tail bound (plus 10⁻¹⁴·scale for rounding) must cover
/// the actual error; and at generic x, for N ≥ 3, the bound must not be loose by more than
/// a factor 4 (it replaces sin² by 1, whose mean is ½, so the typical ratio is ≈ 2; it
/// reaches ≈ 3.7 when the first omitted modes sit near nodes, e.g. x = 0.11L, N = 7).
#[test]
fn closed_form_profile_matches_mode_sum_within_reported_bound() {
    let b = beam();
    let p = b.params;
    let l = p.length;
    let scale = b.variance_scale();
    let mid = b.profile_variance(l / 2.0);
    let classical = p.kt * l.powi(3) / (48.0 * p.bending_rigidity);
    assert!((mid / classical - 1.0).abs() < 1e-14);
    for &u in &FRACTIONS {
        let x = u * l;
        let closed = b.profile_variance(x);
        for &n in &[1usize, 2, 3, 5, 10, 30, 100] {
            let s = b.profile_variance_series(x, n);
            assert_eq!(s.n_modes, n);
            let err = (closed - s.value).abs();
            assert!(
                err <= s.truncation_error + 1e-14 * scale,
                "x = {u}L, N = {n}: error {err:e} > bound {:e}",
                s.truncation_error
            );
            if n >= 3 && [0.11, 0.3, 0.37].contains(&u) {
                assert!(
                    s.truncation_error <= 4.0 * err,
                    "x = {u}L, N = {n}: bound {:e} loose vs error {err:e}",
                    s.truncation_error
                );
            }
        }
    }
    assert_eq!(b.profile_variance(0.0), 0.0);
    assert_eq!(b.profile_variance(l), 0.0);
}

/// What: the closed-form Green's function covariance kT·G(x,y) (both branches x ≤ y and
/// x > y) against the mode sum Σ σₙ² sin(nπx/L) sin(nπy/L) with 2000 modes; symmetry;
/// zeros at the hinges; and G(x,x) = profile variance.
/// Reference: the eigen-expansion of the hinged-beam Green's function.
/// Tolerance: the tail bound scale·Σ_{n>2000} n⁻⁴ ≈ 4·10⁻¹¹·scale plus 10⁻¹³·scale for
/// rounding of the 2000-term sum.
#[test]
fn equilibrium_covariance_matches_series_and_is_symmetric_with_hinge_zeros() {
    let b = beam();
    let l = b.params.length;
    let scale = b.variance_scale();
    let n_terms = 2000;
    let tol = scale * inverse_fourth_power_tail(n_terms) + 1e-13 * scale;
    for &u in &FRACTIONS {
        for &v in &FRACTIONS {
            let (x, y) = (u * l, v * l);
            let g = b.equilibrium_covariance(x, y);
            let series: f64 = (1..=n_terms)
                .rev()
                .map(|n| b.mode_variance(n) * b.mode_shape(n, x) * b.mode_shape(n, y))
                .sum();
            assert!(
                (g - series).abs() <= tol,
                "x = {u}L, y = {v}L: closed {g:e} vs series {series:e}"
            );
            assert_eq!(g, b.equilibrium_covariance(y, x));
        }
        let x = u * l;
        assert_eq!(b.equilibrium_covariance(0.0, x), 0.0);
        assert_eq!(b.equilibrium_covariance(x, l), 0.0);
        assert!((b.equilibrium_covariance(x, x) - b.profile_variance(x)).abs() <= 1e-15 * scale);
    }
}

/// What: limits of eq. (4): (a) t = η → ∞ (t = 50τ₁) gives the equilibrium covariance;
/// (b) t = 0 gives exactly 0; (c) for η > t with t large (30τ₁) it tends to the stationary
/// two-time covariance Σ σₙ² e^{−λₙ(η−t)} sin sin (built from `mode_autocovariance`).
/// Reference: the closed-form Green's function, and a 2000-term stationary sum.
/// Tolerance: the reported truncation bound of `correlation` plus the tail of the 2000-term
/// reference plus 10⁻¹³·scale for rounding; the neglected e^{−λ₁(η+t)} ≤ e^{−60} is far
/// below that.
#[test]
fn eq4_limits_equilibrium_rest_and_stationary_two_time() {
    let b = beam();
    let l = b.params.length;
    let tau1 = b.params.tau1();
    let scale = b.variance_scale();
    let pairs = [(0.3, 0.5), (0.11, 0.9), (0.62, 0.62), (0.5, 0.37)];
    for &(u, v) in &pairs {
        let (x, y) = (u * l, v * l);
        // (a)
        let big = 50.0 * tau1;
        let c = b.correlation(x, y, big, big, 1e-10).unwrap();
        assert!(c.truncation_error <= 1e-10 * scale);
        let g = b.equilibrium_covariance(x, y);
        assert!(
            (c.value - g).abs() <= c.truncation_error + 1e-13 * scale,
            "t = eta = 50 tau1 at ({u}L, {v}L): {:e} vs {g:e}",
            c.value
        );
        // (b)
        for &eta in &[0.0, 0.01 * tau1, 2.0 * tau1] {
            let c0 = b.correlation(x, y, 0.0, eta, 1e-12).unwrap();
            assert_eq!(c0.value, 0.0);
            assert_eq!(c0.truncation_error, 0.0);
        }
        // (c)
        let t = 30.0 * tau1;
        for &lag in &[0.05 * tau1, 0.3 * tau1, tau1] {
            let c = b.correlation(x, y, t, t + lag, 1e-12).unwrap();
            let stationary: f64 = (1..=2000usize)
                .rev()
                .map(|n| b.mode_autocovariance(n, lag) * b.mode_shape(n, x) * b.mode_shape(n, y))
                .sum();
            let ref_tail = scale * inverse_fourth_power_tail(2000);
            assert!(
                (c.value - stationary).abs() <= c.truncation_error + ref_tail + 1e-13 * scale,
                "lag {lag} at ({u}L, {v}L): {:e} vs {stationary:e}",
                c.value
            );
        }
    }
}

/// What: the truncation bound of eq. (4) is honest: the N-term sum differs from the
/// 10⁵-term sum by at most the reported bound, for N = 1 … 100 and several (x, y, t, η)
/// (including small t, where the bracket is far from 1, and η > t, where the bound uses
/// the exponential decay of the omitted modes); `correlation` meets its tolerance; with an
/// unreachable tolerance it stops at MAX_MODES and reports the bound it achieved; and in
/// the equilibrium regime (N ≥ 3) the bound is not loose by more than a factor 4 (as for
/// the profile variance).
/// Reference: `correlation_truncated` with 10⁵ modes (its own bound ≈ 3·10⁻¹⁶·scale).
/// Tolerance: bound_N + bound_ref + 10⁻¹³·scale (rounding).
#[test]
fn eq4_truncation_bound_is_honest() {
    let b = beam();
    let l = b.params.length;
    let tau1 = b.params.tau1();
    let scale = b.variance_scale();
    let cases = [
        (0.3, 0.5, 0.2, 0.6),
        (0.37, 0.37, 0.01, 0.01),
        (0.11, 0.9, 1.0, 1.003),
        (0.62, 0.3, 20.0, 20.0),
        (0.3, 0.3, 20.0, 20.0),
    ];
    for &(u, v, ts, es) in &cases {
        let (x, y, t, eta) = (u * l, v * l, ts * tau1, es * tau1);
        let reference = b.correlation_truncated(x, y, t, eta, MAX_MODES).unwrap();
        assert!(reference.truncation_error <= 4e-16 * scale);
        for &n in &[1usize, 2, 3, 5, 10, 30, 100] {
            let s = b.correlation_truncated(x, y, t, eta, n).unwrap();
            assert_eq!(s.n_modes, n);
            let err = (s.value - reference.value).abs();
            assert!(
                err <= s.truncation_error + reference.truncation_error + 1e-13 * scale,
                "case {:?}, N = {n}: error {err:e} > bound {:e}",
                (u, v, ts, es),
                s.truncation_error
            );
            if n >= 3 && u == 0.3 && v == 0.3 && ts == 20.0 {
                assert!(s.truncation_error <= 4.0 * err, "N = {n}: bound loose");
            }
        }
        for &tol in &[1e-3, 1e-6, 1e-9] {
            let c = b.correlation(x, y, t, eta, tol).unwrap();
            assert!(c.truncation_error <= tol * scale);
            assert!((c.value - reference.value).abs() <= tol * scale + 1e-13 * scale);
        }
    }
    let capped = b.correlation(0.3 * l, 0.5 * l, tau1, tau1, 1e-20).unwrap();
    assert_eq!(capped.n_modes, MAX_MODES);
    assert!(capped.truncation_error > 1e-20 * scale);
    assert!(capped.truncation_error <= 4e-16 * scale);
}

/// What: the mode variances (equipartition) reproduce the closed-form profile variance,
/// and the Lorentzian one-sided density of each mode integrates to σₙ² over [0, ∞).
/// Reference: profile_variance; ∫₀^∞ 4σ²λ/(λ²+(2πf)²) df = σ².
/// Tolerance: the 3000-mode tail bound for the profile; for the integral, the midpoint rule
/// with 2·10⁵ nodes on the map f = (λ/2π)·s/(1−s), s ∈ [0, 1) (smooth integrand, error
/// O(h²) ≈ 10⁻¹¹), so 10⁻⁹ relative.
#[test]
fn mode_variances_sum_to_profile_and_lorentzian_integrates_to_variance() {
    let b = beam();
    let l = b.params.length;
    let scale = b.variance_scale();
    for &u in &FRACTIONS {
        let x = u * l;
        let sum: f64 = (1..=3000usize)
            .rev()
            .map(|n| b.mode_variance(n) * b.mode_shape(n, x).powi(2))
            .sum();
        let tol = scale * inverse_fourth_power_tail(3000) + 1e-14 * scale;
        assert!((sum - b.profile_variance(x)).abs() <= tol, "x = {u}L");
    }
    for &n in &[1usize, 2, 5] {
        let fc = b.mode_rate(n) / (2.0 * PI);
        let nodes = 200_000;
        let h = 1.0 / nodes as f64;
        let integral: f64 = (0..nodes)
            .map(|i| {
                let s = (i as f64 + 0.5) * h;
                let f = fc * s / (1.0 - s);
                b.lorentzian(n, f) * fc / (1.0 - s).powi(2) * h
            })
            .sum();
        let var = b.mode_variance(n);
        assert!(
            (integral / var - 1.0).abs() < 1e-9,
            "mode {n}: {integral:e} vs {var:e}"
        );
    }
}

/// What: the sampled (AR(1)) spectrum (a) integrates to σₙ² over [0, 1/(2dt)], and (b)
/// equals the folded Lorentzian Σ_{|m|≤M} lorentzian(f + m/dt) up to the omitted images.
/// Reference: (a) the variance of the sampled sequence is σₙ²; (b) aliasing.
/// Tolerance: (a) the trapezoid rule on a smooth periodic (even) integrand converges
/// geometrically; 10⁵ intervals resolve the narrowest peak (width λdt/(2π) = 1.6·10⁻³ of a
/// period at λdt = 0.01) and give 10⁻¹⁰ relative. (b) Every image is positive, so the
/// partial sum is below the exact value, and the omitted images with |m| > M sum to at most
/// B = 2σ²λdt²/(π²M) (each ≤ 4σ²λdt²/(2π(|m|−½))², then Σ_{m>M}(m−½)⁻² ≤ 1/M); asserted:
/// 0.9·B ≤ exact − partial ≤ B with M = 500 (B is the exact tail up to O(1/M) and
/// O((λdt)²/M²), so this is sharp), within 10⁻¹² relative rounding, and B itself must be
/// at least 100 times that rounding allowance.
#[test]
fn sampled_spectrum_integrates_to_variance_and_is_folded_lorentzian() {
    let b = beam();
    let tau1 = b.params.tau1();
    for &n in &[1usize, 2] {
        let var = b.mode_variance(n);
        let lam = b.mode_rate(n);
        for &dts in &[0.01, 0.3, 3.0] {
            let dt = dts * tau1 / (n as f64).powi(4);
            // (a)
            let fmax = 1.0 / (2.0 * dt);
            let k = 100_000;
            let h = fmax / k as f64;
            let integral: f64 = (0..=k)
                .map(|i| {
                    let w = if i == 0 || i == k { 0.5 } else { 1.0 };
                    w * b.sampled_spectrum(n, dt, i as f64 * h) * h
                })
                .sum();
            assert!(
                (integral / var - 1.0).abs() < 1e-10,
                "n = {n}, dt = {dts}: {integral:e} vs {var:e}"
            );
            // (b)
            let m_max: i64 = 500;
            for &ff in &[0.0, 0.13, 0.5] {
                let f = ff / dt;
                let exact = b.sampled_spectrum(n, dt, f);
                // Sum smallest images first.
                let partial: f64 = (0..=m_max)
                    .rev()
                    .map(|m| {
                        let shift = m as f64 / dt;
                        if m == 0 {
                            b.lorentzian(n, f)
                        } else {
                            b.lorentzian(n, f + shift) + b.lorentzian(n, f - shift)
                        }
                    })
                    .sum();
                let bound = 2.0 * var * lam * dt * dt / (PI * PI * m_max as f64);
                let missing = exact - partial;
                let rounding = 1e-12 * exact;
                assert!(bound > 100.0 * rounding, "test not sharp: bound {bound:e}");
                assert!(
                    missing <= bound + rounding && missing >= 0.9 * bound - rounding,
                    "n = {n}, dt = {dts}, f·dt = {ff}: missing {missing:e}, bound {bound:e}"
                );
            }
        }
    }
}

/// What: a long stationary run of the modal simulator (6 modes, Δt = 0.1τ₁, 2·10⁵ steps,
/// started from `set_equilibrium`): per-mode sample variance = σₙ², and lag-1 sample
/// autocorrelation = ρₙ = e^{−λₙΔt}.
/// Reference: stationary OU moments.
/// Tolerance: Z = 4 standard errors, with the exact large-sample SEs of a Gaussian AR(1)
/// with known mean 0: Var(Σa²/K) ≈ 2σ⁴(1+ρ²)/((1−ρ²)K), and (Bartlett)
/// Var(r₁) ≈ (1−ρ²)/K. For mode 1 (ρ = e^{−0.1}) the variance SE is ≈ 1 %.
#[test]
fn simulator_stationary_variance_and_lag1_correlation() {
    let b = beam();
    let tau1 = b.params.tau1();
    let dt = 0.1 * tau1;
    let n_modes = 6;
    let k = 200_000usize;
    let mut sim = ModalSimulator::new(b, n_modes, dt).unwrap();
    let mut rng = trajectory_rng(SEED_EQUILIBRIUM, 0);
    sim.set_equilibrium(&mut rng);
    let mut sum_sq = vec![0.0; n_modes];
    let mut sum_lag = vec![0.0; n_modes];
    let mut prev = sim.amplitudes().to_vec();
    for _ in 0..k {
        sim.step(&mut rng);
        for (i, (&a, p)) in sim.amplitudes().iter().zip(prev.iter_mut()).enumerate() {
            sum_sq[i] += *p * *p;
            sum_lag[i] += *p * a;
            *p = a;
        }
    }
    let kf = k as f64;
    for i in 0..n_modes {
        let n = i + 1;
        let var = b.mode_variance(n);
        let rho = (-b.mode_rate(n) * dt).exp();
        let var_hat = sum_sq[i] / kf;
        let se_var = var * (2.0 * (1.0 + rho * rho) / ((1.0 - rho * rho) * kf)).sqrt();
        assert!(
            (var_hat - var).abs() <= Z * se_var,
            "mode {n}: variance {var_hat:e} vs {var:e} (SE {se_var:e})"
        );
        let r1 = sum_lag[i] / sum_sq[i];
        let se_r = ((1.0 - rho * rho) / kf).sqrt();
        assert!(
            (r1 - rho).abs() <= Z * se_r,
            "mode {n}: lag-1 correlation {r1} vs {rho} (SE {se_r:e})"
        );
    }
}

/// What: from rest, an ensemble of independent trajectories (trajectory_rng index i) of
/// the modal simulator (12 modes, Δt = 0.1τ₁) reproduces eq. (4) at several (x, y, t, η),
/// both equal-time and two-time.
/// Reference: eq. (4) truncated to the simulated 12 modes (`correlation_truncated`), which
/// is exact for the simulated process; its distance to the full eq. (4) is checked to be
/// within the reported bound (so the simulator also matches the full eq. (4) to within
/// that bound, ≈ 1.7·10⁻⁴·scale).
/// Tolerance: Z = 4 standard errors of the ensemble mean of w(x,t)w(y,η), the SE being
/// estimated from the ensemble (sample SD/√M, M = 40000; relative SE ≈ 1 %).
#[test]
fn simulator_ensemble_from_rest_matches_eq4() {
    let b = beam();
    let l = b.params.length;
    let tau1 = b.params.tau1();
    let dt = 0.1 * tau1;
    let n_modes = 12;
    let m = 40_000u64;
    // (x/L, y/L, step of t, step of η)
    let cases: [(f64, f64, usize, usize); 5] = [
        (0.3, 0.5, 2, 6),
        (0.7, 0.5, 2, 6),
        (0.3, 0.3, 2, 2),
        (0.5, 0.5, 6, 6),
        (0.11, 0.62, 1, 3),
    ];
    let last = cases.iter().map(|c| c.3).max().unwrap();
    let mut sum = [0.0f64; 5];
    let mut sum_sq = [0.0f64; 5];
    let mut sim = ModalSimulator::new(b, n_modes, dt).unwrap();
    let mut w_t = [0.0f64; 5];
    for i in 0..m {
        let mut rng = trajectory_rng(SEED_ENSEMBLE, i);
        sim.set_rest();
        for step in 1..=last {
            sim.step(&mut rng);
            for (c, &(u, v, st, se)) in cases.iter().enumerate() {
                if step == st {
                    w_t[c] = sim.deflection(u * l);
                }
                if step == se {
                    let prod = w_t[c] * sim.deflection(v * l);
                    sum[c] += prod;
                    sum_sq[c] += prod * prod;
                }
            }
        }
        assert_eq!(sim.steps(), last as u64);
    }
    let mf = m as f64;
    for (c, &(u, v, st, se)) in cases.iter().enumerate() {
        let (x, y, t, eta) = (u * l, v * l, st as f64 * dt, se as f64 * dt);
        let exact = b.correlation_truncated(x, y, t, eta, n_modes).unwrap();
        let full = b.correlation(x, y, t, eta, 1e-12).unwrap();
        assert!((exact.value - full.value).abs() <= exact.truncation_error + full.truncation_error);
        let mean = sum[c] / mf;
        let sd = ((sum_sq[c] / mf - mean * mean) * mf / (mf - 1.0)).sqrt();
        let se_mean = sd / mf.sqrt();
        assert!(
            (mean - exact.value).abs() <= Z * se_mean,
            "case {:?}: ensemble {mean:e} vs eq. (4) {:e} (SE {se_mean:e})",
            cases[c],
            exact.value
        );
    }
}

/// What: the OU update is exact for any Δt: one step from rest gives per-mode variance
/// σₙ²(1 − e^{−2λₙΔt}), for Δt = 0.05τ₁ (mode 1 at 9.5 % of σ₁²) and Δt = 10τ₁ (where an
/// Euler–Maruyama step would give 2λ₁Δt·σ₁² = 20σ₁²).
/// Reference: the OU transition law.
/// Tolerance: Z = 4 standard errors of a Gaussian sample variance with known mean 0,
/// SE = v·√(2/M), M = 20000 independent trajectories.
#[test]
fn simulator_is_exact_for_large_time_steps() {
    let b = beam();
    let tau1 = b.params.tau1();
    let n_modes = 4;
    let m = 20_000u64;
    for (j, &dts) in [0.05, 10.0].iter().enumerate() {
        let dt = dts * tau1;
        let mut sim = ModalSimulator::new(b, n_modes, dt).unwrap();
        let mut sum_sq = vec![0.0; n_modes];
        for i in 0..m {
            let mut rng = trajectory_rng(SEED_LARGE_STEP, i + j as u64 * m);
            sim.set_rest();
            sim.step(&mut rng);
            for (s, a) in sum_sq.iter_mut().zip(sim.amplitudes()) {
                *s += a * a;
            }
        }
        assert_eq!(sim.time(), dt);
        for (i, s) in sum_sq.iter().enumerate() {
            let n = i + 1;
            let v = b.mode_variance(n) * -(-2.0 * b.mode_rate(n) * dt).exp_m1();
            let v_hat = s / m as f64;
            let se = v * (2.0 / m as f64).sqrt();
            assert!(
                (v_hat - v).abs() <= Z * se,
                "dt = {dts} tau1, mode {n}: {v_hat:e} vs {v:e} (SE {se:e})"
            );
        }
    }
}

/// What: the same seed gives a bit-identical trajectory; a different trajectory index gives
/// a different one. Reference: determinism contract (fixed draw order, PCG-64).
#[test]
fn same_seed_gives_bit_identical_amplitudes() {
    let b = beam();
    let run = |index: u64| -> Vec<u64> {
        let mut sim = ModalSimulator::new(b, 8, 0.05).unwrap();
        let mut rng = trajectory_rng(SEED_REPRODUCIBLE, index);
        sim.set_equilibrium(&mut rng);
        for _ in 0..100 {
            sim.step(&mut rng);
        }
        sim.amplitudes().iter().map(|a| a.to_bits()).collect()
    };
    assert_eq!(run(3), run(3));
    assert_ne!(run(3), run(4));
}

/// What: invalid inputs return Error::InvalidParameter (never panic): non-positive, NaN or
/// infinite parameters; x or y outside [0, L]; t < 0; t > η; non-finite times; bad
/// tolerance; too many modes.
#[test]
fn invalid_inputs_are_errors() {
    let bad_values = [-1.0, 0.0, f64::NAN, f64::INFINITY];
    type Setter = fn(&mut FilamentParams, f64);
    let setters: [(&str, Setter); 5] = [
        ("length", |p, v| p.length = v),
        ("bending_rigidity", |p, v| p.bending_rigidity = v),
        ("stretch_rigidity", |p, v| p.stretch_rigidity = v),
        ("drag", |p, v| p.drag = v),
        ("kt", |p, v| p.kt = v),
    ];
    for (name, set) in setters {
        for &v in &bad_values {
            let mut p = spectral_sample();
            set(&mut p, v);
            match HingedBeam::new(p) {
                Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                other => panic!("{name} = {v}: expected InvalidParameter, got {other:?}"),
            }
        }
    }

    let b = beam();
    let l = b.params.length;
    let is_invalid = |r: langevin_fem::Result<_>| matches!(r, Err(Error::InvalidParameter { .. }));
    let bad_args = [
        (-0.1, 1.0, 0.1, 0.2),
        (l + 0.1, 1.0, 0.1, 0.2),
        (f64::NAN, 1.0, 0.1, 0.2),
        (1.0, -1e-9, 0.1, 0.2),
        (1.0, l * 1.5, 0.1, 0.2),
        (1.0, 1.0, -0.1, 0.2),
        (1.0, 1.0, 0.3, 0.2),
        (1.0, 1.0, 0.1, f64::INFINITY),
        (1.0, 1.0, f64::NAN, 0.2),
        (1.0, 1.0, 0.1, f64::NAN),
    ];
    for &(x, y, t, eta) in &bad_args {
        assert!(
            is_invalid(b.correlation(x, y, t, eta, 1e-6)),
            "{:?}",
            (x, y, t, eta)
        );
        assert!(
            is_invalid(b.correlation_truncated(x, y, t, eta, 10)),
            "{:?}",
            (x, y, t, eta)
        );
    }
    for &tol in &[0.0, -1e-6, f64::NAN] {
        assert!(is_invalid(b.correlation(1.0, 1.0, 0.1, 0.2, tol)));
    }
    assert!(is_invalid(b.correlation_truncated(
        1.0,
        1.0,
        0.1,
        0.2,
        MAX_MODES + 1
    )));
    assert!(b.correlation(1.0, 1.0, 0.1, 0.2, 1e-6).is_ok());
    for &dt in &bad_values {
        assert!(matches!(
            ModalSimulator::new(b, 4, dt),
            Err(Error::InvalidParameter { .. })
        ));
    }
    assert!(matches!(
        ModalSimulator::new(b, 0, 0.1),
        Err(Error::InvalidParameter { .. })
    ));
}
