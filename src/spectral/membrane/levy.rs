//! The point variance (M5) in a fast-converging form: one index summed in closed form
//! (Lévy's method for plates), the tension as a quickly converging correction.
//!
//! # Splitting off the tension
//!
//! 1/c_q = 1/(κq⁴) − σ/(κq⁴(κq² + σ)), so ⟨h²⟩ = ⟨h²⟩₀ − C_σ: the tensionless sum ⟨h²⟩₀
//! (below, in closed or single-series form) minus the correction
//! C_σ = Σ_φ ⟨a²⟩₀-weights·σ/(κq⁴(κq² + σ)), a lattice sum whose terms fall as q⁻⁶, so that
//! its lattice tail bound ([`Membrane::tension_correction_tail`]) is O(1/Q⁴). κq² + σ > 0
//! for every mode above buckling, so the split holds for either sign of σ.
//!
//! # Simply supported, σ = 0 (M5a)
//!
//! Orient the rectangle so that a ≥ b (swap x and y otherwise); u = x/a, v = y/b. With
//! q² = ((mπ)² + s_n²)/a², s_n = nπa/b ≥ nπ,
//!
//! ⟨h²⟩₀ = Σ_{m,n≥1} (4kT/(Aκ)) sin²(mπu) sin²(nπv)/q⁴
//!       = (2kT a³/(bκ)) Σ_{n≥1} sin²(nπv) D(u, s_n),
//! D(u, s) = Σ_{m≥1} 2 sin²(mπu)/((mπ)² + s²)².
//!
//! D in closed form: Σ_{m≥1} 2 sin(mπu) sin(mπu′)/((mπ)² + μ) is the Green's function of
//! −∂² + μ on [0, 1] with Dirichlet ends (expand δ(u−u′) = 2Σ sin sin), which at u = u′ is
//! G(u; μ) = sinh(su) sinh(s(1−u))/(s sinh s) = E(s)/(2s), s = √μ,
//! E(s) = (1 − e^{−2su})(1 − e^{−2s(1−u)})/(1 − e^{−2s}).
//! Then D = −∂G/∂μ = −(1/2s)∂G/∂s = (E − sE′)/(4s³), and with ψ(z) = z/(e^z − 1),
//! sE′/E = ψ(2su) + ψ(2s(1−u)) − ψ(2s), so
//!
//! D(u, s) = E(s)·[1 − ψ(2su) − ψ(2s(1−u)) + ψ(2s)]/(4s³)   (M5a)
//!
//! (s → 0 gives u²(1−u)²/3, the filament's Σ2sin²/(mπ)⁴; at u = ½ it is
//! tanh(s/2)(1 − s/sinh s)/(4s³), Timoshenko's central-load Lévy series). Overflow-free
//! for every s, and free of cancellation for s ≥ π (which the orientation ensures).
//! Tail of the n-sum: D ≤ 1/(4s³), because E ≤ 1 ((1−α)(1−β) ≤ 1 − αβ for α, β in
//! [0, 1], here α = e^{−2su}, β = e^{−2s(1−u)}) and the bracket is at most 1 − ψ(2su) ≤ 1
//! (ψ decreases, so ψ(2s) ≤ ψ(2s(1−u))). With sin² ≤ 1 the terms n > N add at most
//! (2kTa³/(bκ))·(b³/(4π³a³))·Σ_{n>N} n⁻³ ≤ kT b²/(4π³κ(N + ½)²)
//! (Σ_{n>N} n⁻³ ≤ ∫_{N+½}^∞ t⁻³ dt by convexity); this is about twice the true tail, the
//! mean of sin² being ½.
//!
//! # Periodic, σ = 0 (M5b)
//!
//! Orient so that a ≥ b; c_n = na/b. Then q² = (2π/a)²(m² + c_n²) and
//! ⟨h²⟩₀ = (kT/(Aκ))(a/2π)⁴ Σ_{(m,n)≠0} (m² + c_n²)⁻². Row n = 0 gives 2ζ(4) = π⁴/45.
//! For n ≠ 0, differentiating Σ_{m∈ℤ} 1/(m² + c²) = (π/c) coth(πc) in c gives
//! Σ_{m∈ℤ} (m² + c²)⁻² = π coth(πc)/(2c³) + π² csch²(πc)/(2c²) = π/(2c³) + R(c),
//! R(c) = e^{−2πc}[π/(c³ω) + 2π²/(c²ω²)], ω = 1 − e^{−2πc}. The π/(2c³) parts of the rows
//! ±n sum to πζ(3)(b/a)³, so
//!
//! ⟨h²⟩₀ = (kT/(Aκ))(a/2π)⁴ [π⁴/45 + πζ(3)(b/a)³ + 2Σ_{n≥1} R(na/b)]   (M5b)
//!
//! and R(c)e^{2πc} decreases, so R(c_{n+1}) ≤ e^{−2πa/b} R(c_n) and the rows beyond N add
//! at most 2R(c_{N+1})/(1 − e^{−2πa/b}): a geometric tail, ratio ≤ e^{−2π}. On an L × L
//! square, Σ_{(m,n)≠0}(m² + n²)⁻² = 4ζ(2)β(2) = (2π²/3)G (Dirichlet's r₂ series; G is
//! Catalan's constant), so ⟨h²⟩₀ = kT L² G/(24π²κ) (tested against this form).

use super::sums::{CompensatedSum, ShapeTable};
use super::{MAX_MEMBRANE_MODES, Membrane, MembraneBoundary};
use crate::error::{Result, require_positive};
use crate::spectral::{SeriesValue, sin_pi};
use std::f64::consts::PI;

/// σ/(κq_min²) above which [`Membrane::point_variance`] sums the proper-time integral
/// (M5c) instead of the lattice form ⟨h²⟩₀ − C_σ. Every built-in scene but the extreme
/// `membrane-tension-dominated` (σ/(κq_min²) = 253) lies below it.
pub const PROPER_TIME_TENSION_RATIO: f64 = 10.0;

/// Aspect ratio max(a, b)/min(a, b) above which [`Membrane::point_variance`] also takes
/// the proper-time form: on a 10⁴ × 1 strip under a tension of 3 κq_min² the lattice
/// form reaches its caps with a bound of 6·10⁻⁶ of the value, the proper-time form meets
/// 10⁻⁹ of the slowest mode's variance in 279 nodes. Every built-in scene has an aspect
/// ratio of 1 or 2.
pub const PROPER_TIME_ASPECT_RATIO: f64 = 10.0;

/// ζ(3), Apéry's constant.
pub(crate) const ZETA3: f64 = 1.202_056_903_159_594_3;

/// ψ(z) = z/(e^z − 1), z ≥ 0 (ψ(0) = 1; 0 when e^z overflows).
fn psi(z: f64) -> f64 {
    if z == 0.0 { 1.0 } else { z / z.exp_m1() }
}

/// 1 − ψ(z), z ≥ 0, accurate for small z: the Bernoulli series
/// z/2 − z²/12 + z⁴/720 − z⁶/30240 + z⁸/1209600 below z = 0.1 (next term < 10⁻¹⁷ relative).
fn one_minus_psi(z: f64) -> f64 {
    if z < 0.1 {
        let z2 = z * z;
        z * (0.5 - z * (1.0 / 12.0 - z2 * (1.0 / 720.0 - z2 * (1.0 / 30240.0 - z2 / 1_209_600.0))))
    } else {
        1.0 - psi(z)
    }
}

/// D(u, s) = Σ_{m≥1} 2 sin²(mπu)/((mπ)² + s²)² in closed form, (M5a), u ∈ [0, 1], s > 0.
pub(crate) fn coincident_d(u: f64, s: f64) -> f64 {
    let u = u.min(1.0 - u);
    if u <= 0.0 {
        return 0.0;
    }
    let e = (-(-2.0 * s * u).exp_m1()) * (-(-2.0 * s * (1.0 - u)).exp_m1()) / -(-2.0 * s).exp_m1();
    let bracket = one_minus_psi(2.0 * s * u) - psi(2.0 * s * (1.0 - u)) + psi(2.0 * s);
    e * bracket / (4.0 * s * s * s)
}

/// R(c) of (M5b): Σ_{m∈ℤ}(m² + c²)⁻² − π/(2c³), c > 0.
fn row_excess(c: f64) -> f64 {
    let e = (-2.0 * PI * c).exp();
    let w = -(-2.0 * PI * c).exp_m1();
    e * (PI / (c * c * c * w) + 2.0 * PI * PI / (c * c * w * w))
}

impl Membrane {
    /// Whether [`Membrane::point_variance`] takes the proper-time form (`heat.rs`, cost
    /// independent of σ and of the aspect ratio) rather than the lattice form of this
    /// module: for a tension above [`PROPER_TIME_TENSION_RATIO`]·κq_min², where the
    /// tension correction's lattice sum grows long (millions of terms from σ ≈ 10³ κq_min²),
    /// or an aspect ratio above [`PROPER_TIME_ASPECT_RATIO`], where the single series does.
    pub fn point_variance_by_proper_time(&self) -> bool {
        let p = &self.params;
        let aspect = p.width.max(p.height) / p.width.min(p.height);
        p.tension > PROPER_TIME_TENSION_RATIO * p.bending_rigidity * p.min_wavenumber_sq()
            || aspect > PROPER_TIME_ASPECT_RATIO
    }

    /// (M5) in the fast form of the module docs: ⟨h²(x, y)⟩ = ⟨h²⟩₀ − C_σ, each part
    /// summed until its rigorous bound is at most half of `tolerance`·scale
    /// (scale = [`Membrane::variance_scale`]; all of it when σ = 0), or at the caps
    /// ([`MAX_MEMBRANE_MODES`] terms each), in which case the achieved bound is reported.
    /// `n_modes` is the number of terms summed: single-series terms of ⟨h²⟩₀ plus real
    /// modes of C_σ. The periodic value does not depend on (x, y). Above
    /// [`PROPER_TIME_TENSION_RATIO`]·κq_min², or above an aspect ratio of
    /// [`PROPER_TIME_ASPECT_RATIO`], it is [`Membrane::point_variance_proper_time`]
    /// instead (`n_modes` then counts its quadrature nodes).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming `x` or `y` outside the rectangle, or
    /// `tolerance` if it is not finite and > 0.
    pub fn point_variance(&self, x: f64, y: f64, tolerance: f64) -> Result<SeriesValue> {
        self.point_variance_capped(x, y, tolerance, MAX_MEMBRANE_MODES)
    }

    /// [`Membrane::point_variance`] with at most about `cap` terms in each part instead
    /// of [`MAX_MEMBRANE_MODES`] (the bound reached is reported): for a figure's curve,
    /// whose points must not each cost a second where a tension far above κq_min² makes
    /// the sums long. The proper-time form ([`Membrane::point_variance_by_proper_time`])
    /// needs no cap.
    ///
    /// # Errors
    /// As [`Membrane::point_variance`].
    pub fn point_variance_capped(
        &self,
        x: f64,
        y: f64,
        tolerance: f64,
        cap: usize,
    ) -> Result<SeriesValue> {
        if self.point_variance_by_proper_time() {
            return self.point_variance_proper_time(x, y, tolerance);
        }
        self.check_point("x", "y", (x, y))?;
        require_positive("tolerance", tolerance)?;
        let target = tolerance * self.variance_scale();
        let has_tension = self.params.tension != 0.0;
        let share = if has_tension { 0.5 * target } else { target };
        let base = match self.params.boundary {
            MembraneBoundary::SimplySupported => {
                self.tensionless_simply_supported(x, y, share, cap)
            }
            MembraneBoundary::Periodic => self.tensionless_periodic(share, cap),
        };
        let corr = if has_tension {
            self.tension_correction(x, y, share, cap)
        } else {
            SeriesValue {
                value: 0.0,
                truncation_error: 0.0,
                n_modes: 0,
            }
        };
        Ok(SeriesValue {
            value: base.value - corr.value,
            truncation_error: base.truncation_error + corr.truncation_error,
            n_modes: base.n_modes + corr.n_modes,
        })
    }

    /// ⟨h²⟩₀ of the simply supported membrane, (M5a), to the bound `target`.
    fn tensionless_simply_supported(&self, x: f64, y: f64, target: f64, cap: usize) -> SeriesValue {
        let p = &self.params;
        let (a, b, u, v) = if p.width >= p.height {
            (p.width, p.height, x / p.width, y / p.height)
        } else {
            (p.height, p.width, y / p.height, x / p.width)
        };
        let tail_coef = p.kt * b * b / (4.0 * PI.powi(3) * p.bending_rigidity);
        let tail = |n: usize| tail_coef / (n as f64 + 0.5).powi(2);
        // Smallest N with tail(N) ≤ target, capped.
        let guess = ((tail_coef / target).sqrt() - 0.5).ceil();
        let mut n_terms = if guess.is_finite() && guess >= 1.0 {
            (guess as usize).min(cap)
        } else if guess.is_finite() {
            1
        } else {
            cap
        };
        while n_terms < cap && tail(n_terms) > target {
            n_terms += 1;
        }
        let mut sum = CompensatedSum::default();
        for n in (1..=n_terms).rev() {
            let sv = sin_pi(n as f64 * v);
            sum.add(sv * sv * coincident_d(u, n as f64 * PI * a / b));
        }
        SeriesValue {
            value: 2.0 * p.kt * a.powi(3) / (b * p.bending_rigidity) * sum.value(),
            truncation_error: tail(n_terms),
            n_modes: n_terms,
        }
    }

    /// ⟨h²⟩₀ of the periodic membrane, (M5b), to the bound `target`.
    fn tensionless_periodic(&self, target: f64, cap: usize) -> SeriesValue {
        let p = &self.params;
        let (a, b) = (p.width.max(p.height), p.width.min(p.height));
        let pref = p.kt / (p.area() * p.bending_rigidity) * (a / (2.0 * PI)).powi(4);
        let ratio = -(-2.0 * PI * a / b).exp_m1();
        let mut rows = CompensatedSum::default();
        let mut n = 0usize;
        let tail = |n: usize| pref * 2.0 * row_excess((n + 1) as f64 * a / b) / ratio;
        while tail(n) > target && n < cap {
            n += 1;
            rows.add(2.0 * row_excess(n as f64 * a / b));
        }
        let base = PI.powi(4) / 45.0 + PI * ZETA3 * (b / a).powi(3);
        SeriesValue {
            value: pref * (base + rows.value()),
            truncation_error: tail(n),
            n_modes: n,
        }
    }

    /// The tension correction C_σ = Σ_{|q|≤Q} kT·(Σ_φ φ²/‖φ‖²)·σ/(κq⁴(κq² + σ)), with Q
    /// chosen so that its lattice tail bound is at most `target`.
    fn tension_correction(&self, x: f64, y: f64, target: f64, cap: usize) -> SeriesValue {
        let cutoff = self.cutoff_below(
            target,
            |q| self.tension_correction_tail(q),
            self.cutoff_for_count(cap as f64),
        );
        let table = ShapeTable::new(self, (x, y), (x, y), cutoff);
        let (kappa, sigma, kt) = (
            self.params.bending_rigidity,
            self.params.tension,
            self.params.kt,
        );
        let mut sum = CompensatedSum::default();
        let mut points = 0usize;
        self.visit_lattice(cutoff, |m, n, q2| {
            sum.add(kt * table.product(m, n) * sigma / (kappa * q2 * q2 * (kappa * q2 + sigma)));
            points += 1;
        });
        let per_point = match self.params.boundary {
            MembraneBoundary::SimplySupported => 1,
            MembraneBoundary::Periodic => 2,
        };
        SeriesValue {
            value: sum.value(),
            truncation_error: self.tension_correction_tail(cutoff),
            n_modes: points * per_point,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // What: the closed form D(u, s) of (M5a) against its defining sum, and its limits.
    // Reference: Σ_{m≤10⁶} 2sin²(mπu)/((mπ)²+s²)² (its tail is below
    // 2∫_{10⁶}^∞ dm/(mπ)⁴ = 2/(3π⁴·10¹⁸)); u²(1−u)²/3 as s → 0;
    // tanh(s/2)(1 − s/sinh s)/(4s³) at u = ½.
    // Tolerance: that tail plus 1e-13 relative (rounding of 10⁶ terms, compensated).
    #[test]
    fn coincident_d_matches_its_series_and_limits() {
        for &u in &[0.5, 0.3, 0.07, 0.93, 1e-4] {
            for &s in &[PI, 4.2, 11.0, 40.0] {
                let mut sum = CompensatedSum::default();
                for m in (1..=1_000_000u32).rev() {
                    let sv = sin_pi(f64::from(m) * u);
                    let d = (f64::from(m) * PI).powi(2) + s * s;
                    sum.add(2.0 * sv * sv / (d * d));
                }
                let got = coincident_d(u, s);
                let tail = 2.0 / (3.0 * PI.powi(4) * 1e18);
                assert!(
                    (got - sum.value()).abs() <= 1e-13 * got + tail,
                    "u={u} s={s}: {got:e} vs {:e}",
                    sum.value()
                );
            }
        }
        for &u in &[0.2, 0.5] {
            let small = coincident_d(u, 1e-3);
            let limit = (u * (1.0 - u)).powi(2) / 3.0;
            assert!((small / limit - 1.0).abs() < 1e-5);
        }
        for &s in &[PI, 7.0, 800.0] {
            let centre = (s / 2.0).tanh() * (1.0 - s / s.sinh()) / (4.0 * s.powi(3));
            let centre = if s.sinh().is_finite() {
                centre
            } else {
                1.0 / (4.0 * s.powi(3))
            };
            assert!((coincident_d(0.5, s) / centre - 1.0).abs() < 1e-14, "s={s}");
        }
        // The tail bound D ≤ 1/(4s³), on a grid of u and s (s from 0.1 to 10³).
        for i in 0..=100 {
            let u = f64::from(i) / 100.0;
            for j in 0..=40 {
                let s = 0.1 * 10f64.powf(f64::from(j) / 10.0);
                assert!(
                    coincident_d(u, s) * 4.0 * s.powi(3) <= 1.0 + 1e-15,
                    "u={u} s={s}"
                );
            }
        }
        assert_eq!(coincident_d(0.0, 3.0), 0.0);
        assert_eq!(coincident_d(1.0, 3.0), 0.0);
    }

    // What: 1 − ψ(z) on both sides of the switch to the series at z = 0.1, and far below.
    // Reference: 40-digit values (mpmath, 1 − z/expm1(z)). Tolerance: 1e-14 relative (the
    // direct branch loses ≈ 20 ulp to cancellation at z = 0.1).
    #[test]
    fn one_minus_psi_on_both_branches() {
        let cases = [
            (0.0999, 0.049_118_470_801_303_445),
            (0.1001, 0.049_215_138_578_685_64),
            (0.05, 0.024_791_675_346_705_556),
            (1e-3, 0.000_499_916_666_668_055_6),
        ];
        for (z, exact) in cases {
            assert!((one_minus_psi(z) / exact - 1.0).abs() < 1e-14, "z = {z}");
        }
    }

    // What: the capped point variance. Where the cap does not bind it sums the same terms
    // to the same value, bit for bit; where it binds (σ just below
    // PROPER_TIME_TENSION_RATIO·κq_min², 300 terms, tolerance 1e-9) its reported bound
    // still covers the distance to the full value (itself within its own bound); above
    // that tension the proper-time form, which has no cap, is returned whatever the cap.
    // Reference: `point_variance` at the full caps. Tolerance: the two bounds.
    #[test]
    fn the_capped_point_variance_reports_an_honest_bound() {
        use super::super::{MembraneBoundary, test_membrane};
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let mb = |tension| test_membrane(boundary, tension);
            let m = mb(20.0);
            let full = m.point_variance(0.3, 0.2, 1e-5).unwrap();
            let capped = m.point_variance_capped(0.3, 0.2, 1e-5, 100_000).unwrap();
            // The same terms and value; the tail bound of the tension part may differ in
            // the last digits (its cutoff is bisected from a different upper end).
            assert_eq!(
                (full.value, full.n_modes),
                (capped.value, capped.n_modes),
                "{boundary:?}"
            );
            assert!((capped.truncation_error / full.truncation_error - 1.0).abs() < 1e-5);
            let q2 = m.params.min_wavenumber_sq();
            let m = mb(0.99 * PROPER_TIME_TENSION_RATIO * q2);
            let full = m.point_variance(0.3, 0.2, 1e-9).unwrap();
            let capped = m.point_variance_capped(0.3, 0.2, 1e-9, 300).unwrap();
            assert!(
                capped.n_modes < full.n_modes,
                "{boundary:?}: {capped:?} {full:?}"
            );
            let gap = (capped.value - full.value).abs();
            assert!(
                gap <= capped.truncation_error + full.truncation_error,
                "{boundary:?}: {gap:e} against {capped:?}, {full:?}"
            );
            let m = mb(1.01 * PROPER_TIME_TENSION_RATIO * q2);
            assert_eq!(
                m.point_variance_capped(0.3, 0.2, 1e-9, 300).unwrap(),
                m.point_variance_proper_time(0.3, 0.2, 1e-9).unwrap()
            );
        }
    }
}
