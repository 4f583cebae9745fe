//! Exact modal (spectral) solution of the linear stochastic beam equation, hinged ends.
//!
//! This module is the exact reference against which the finite-element Langevin dynamics
//! is judged. It implements, for a filament of length L with both ends hinged
//! (w = ∂²w/∂x² = 0 at x = 0 and x = L), the closed-form results of Lin & Shenoy:
//!
//! - eq. (1), the thermal load: ⟨f(x,t) f(y,τ)⟩ = 2ξkT δ(x−y) δ(t−τ);
//! - eq. (2), the overdamped beam: ξ ∂w/∂t + EI ∂⁴w/∂x⁴ = f(x,t);
//! - eq. (3), its solution from rest, w(x,0) = 0:
//!   w(x,t) = (2/(Lξ)) Σₙ sin(nπx/L) ∫₀ᴸ sin(nπs/L) ∫₀ᵗ f(s,τ) e^{−λₙ(t−τ)} dτ ds;
//! - eq. (4), its two-time correlation for η ≥ t:
//!   ⟨w(x,t) w(y,η)⟩ = (2kT L³/(π⁴EI)) Σₙ sin(nπx/L) sin(nπy/L)/n⁴
//!   · [e^{−λₙ(η−t)} − e^{−λₙ(η+t)}].
//!
//! # Modal decomposition
//!
//! The hinged boundary conditions are satisfied by every sin(nπx/L), n ≥ 1, which are the
//! eigenfunctions of ∂⁴/∂x⁴ with eigenvalues (nπ/L)⁴ and are orthogonal with
//! ∫₀ᴸ sin² = L/2. Writing w(x,t) = Σₙ aₙ(t) sin(nπx/L) and projecting eq. (2) onto
//! sin(nπx/L) gives one independent Ornstein–Uhlenbeck process per mode:
//!
//! daₙ/dt = −λₙ aₙ + gₙ(t),  λₙ = π⁴n⁴EI/(ξL⁴),
//! gₙ(t) = (2/(ξL)) ∫₀ᴸ f(s,t) sin(nπs/L) ds,  ⟨gₙ(t) gₘ(τ)⟩ = δₙₘ (4kT/(ξL)) δ(t−τ),
//!
//! (the noise covariance follows from eq. (1) and ∫ sin² = L/2). The stationary variance
//! of an OU process with rate λ and white-noise intensity q is q/(2λ), here
//! σₙ² = (4kT/(ξL))/(2λₙ) = 2kT L³/(π⁴n⁴EI), which is also what equipartition gives (see
//! [`HingedBeam::mode_variance`]). The transition over any Δt is exact:
//! aₙ(t+Δt) = aₙ(t) e^{−λₙΔt} + σₙ √(1 − e^{−2λₙΔt}) Z, Z ~ N(0,1); this is the
//! [`ModalSimulator`]. Eq. (4) is Σₙ sin sin ⟨aₙ(t)aₙ(η)⟩ with, from aₙ(0) = 0,
//! ⟨aₙ(t)aₙ(η)⟩ = σₙ² (e^{−λₙ(η−t)} − e^{−λₙ(η+t)}).
//!
//! # Conventions
//!
//! Mode indices start at n = 1; the per-mode functions return NaN for n = 0, which is not
//! a mode of the hinged beam. Functions returning a plain `f64` of a position return NaN
//! for a position outside [0, L] (or non-finite); the fallible ones ([`HingedBeam::new`],
//! [`HingedBeam::correlation`], [`HingedBeam::correlation_truncated`],
//! [`ModalSimulator::new`]) return [`Error::InvalidParameter`] instead.
//!
//! # The membrane
//!
//! [`membrane`] holds the same kind of references for a fluctuating membrane (the Monge-gauge
//! Helfrich membrane with tension, simply supported or periodic): [`Membrane`] and
//! [`MembraneParams`]. Its conventions are stated once, in its module docs.

pub mod ends;
pub mod membrane;
pub mod simulator;

pub use ends::{CharacteristicEquation, EndedBeam, RigidMode, RigidMotion};
pub use membrane::{
    ExcessArea, MAX_ASPECT_RATIO, MAX_LISTED_MODES, MAX_MEMBRANE_MODES, Membrane, MembraneBoundary,
    MembraneMode, MembraneParams, ModeShape,
};
pub use simulator::ModalSimulator;

use crate::error::{Error, Result, require_in_range};
use crate::params::FilamentParams;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Largest number of modes summed by [`HingedBeam::correlation`], and largest number of
/// modes accepted by [`HingedBeam::correlation_truncated`] and [`ModalSimulator::new`].
pub const MAX_MODES: usize = 100_000;

/// A truncated mode sum together with a rigorous bound on the omitted tail.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SeriesValue {
    /// The partial sum over modes 1..=`n_modes` (for the membrane: over the modes below
    /// a wavenumber cutoff, see each function; for its proper-time point variance the
    /// quadrature sum).
    pub value: f64,
    /// Rigorous upper bound on |exact − value| due to the omitted modes n > `n_modes`
    /// (membrane: the modes beyond the cutoff; the proper-time point variance: the nodes
    /// left out and the trapezoidal rule's discretization; floating-point rounding of the
    /// partial sum, of relative order 10⁻¹⁶, is not included).
    pub truncation_error: f64,
    /// Number of modes (or series terms, or quadrature nodes) summed.
    pub n_modes: usize,
}

/// Rigorous upper bound on Σ_{n>N} 1/n⁴.
///
/// Since 1/n⁴ is convex, each term is at most its integral over [n−½, n+½] (midpoint
/// rule), so Σ_{n>N} 1/n⁴ ≤ ∫_{N+½}^∞ u⁻⁴ du = 1/(3(N+½)³). This is tighter than the
/// textbook 1/(3N³) and asymptotically exact (relative excess O(1/N²)). For N = 0 the
/// exact value ζ(4) = π⁴/90 is returned.
pub fn inverse_fourth_power_tail(n: usize) -> f64 {
    if n == 0 {
        PI.powi(4) / 90.0
    } else {
        let m = n as f64 + 0.5;
        1.0 / (3.0 * m * m * m)
    }
}

/// sin(π s), with exact zeros at integer s (so hinged ends give exactly 0) and accurate
/// argument reduction for large s.
pub(crate) fn sin_pi(s: f64) -> f64 {
    if s < 0.0 {
        return -sin_pi(-s);
    }
    // r in [0, 2); the floating-point remainder is exact.
    let r = s % 2.0;
    let (r, sign) = if r >= 1.0 { (r - 1.0, -1.0) } else { (r, 1.0) };
    // sin(πr) = sin(π(1−r)); use the smaller argument.
    let r = if r > 0.5 { 1.0 - r } else { r };
    sign * (PI * r).sin()
}

/// One-sided Lorentzian power spectral density of a stationary Ornstein–Uhlenbeck process
/// with the given variance and rate: S(f) = 4·variance·rate/(rate² + (2πf)²), f ≥ 0, with
/// ∫₀^∞ S df = variance (the Fourier transform of variance·e^{−rate·|lag|}, doubled to fold
/// negative frequencies).
pub(crate) fn ou_lorentzian(variance: f64, rate: f64, f: f64) -> f64 {
    let w = 2.0 * PI * f;
    4.0 * variance * rate / (rate * rate + w * w)
}

/// Exact one-sided spectral density of that process sampled every `dt` (an AR(1)
/// sequence), 0 ≤ f ≤ 1/(2dt): S(f) = 2dt·variance·(1−ρ²)/(1 − 2ρcos(2πf dt) + ρ²),
/// ρ = e^{−rate·dt} (NaN if dt is not finite and > 0). See
/// [`HingedBeam::sampled_spectrum`] for the derivation.
pub(crate) fn ou_sampled_spectrum(variance: f64, rate: f64, dt: f64, f: f64) -> f64 {
    if !(dt.is_finite() && dt > 0.0) {
        return f64::NAN;
    }
    let x = rate * dt;
    let rho = (-x).exp();
    // 1 − ρ² computed without cancellation for small λ·dt.
    let one_minus_rho2 = -(-2.0 * x).exp_m1();
    // 1 − 2ρcos(2πf·dt) + ρ² = (1−ρ)² + 4ρ sin²(πf·dt), free of cancellation.
    let one_minus_rho = -(-x).exp_m1();
    let s = sin_pi(f * dt);
    let denom = one_minus_rho * one_minus_rho + 4.0 * rho * s * s;
    2.0 * dt * variance * one_minus_rho2 / denom
}

/// Checks the times of a two-time correlation from rest: `t` finite and ≥ 0, `eta`
/// finite and ≥ `t` (as `formula`, e.g. eq. 4, assumes).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `t` or `eta`.
pub(crate) fn check_two_times(t: f64, eta: f64, formula: &str) -> Result<()> {
    if !(t.is_finite() && t >= 0.0) {
        return Err(Error::invalid("t", t, "finite and >= 0"));
    }
    if !eta.is_finite() || eta < t {
        return Err(Error::invalid(
            "eta",
            eta,
            format!("finite and >= t = {t} ({formula} assumes eta >= t)"),
        ));
    }
    Ok(())
}

/// The hinged (simply supported) filament of eq. (2): exact modal results.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HingedBeam {
    /// Physical parameters (only L, EI, ξ and kT enter; EA does not).
    pub params: FilamentParams,
}

impl HingedBeam {
    /// A hinged beam with validated parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if any parameter is not finite and > 0.
    pub fn new(params: FilamentParams) -> Result<Self> {
        params.validate()?;
        Ok(HingedBeam { params })
    }

    /// The scale 2kT L³/(π⁴EI) of every mode sum: σₙ² = scale/n⁴.
    pub fn variance_scale(&self) -> f64 {
        let p = &self.params;
        2.0 * p.kt * p.length.powi(3) / (PI.powi(4) * p.bending_rigidity)
    }

    /// Relaxation rate of mode n, λₙ = π⁴n⁴EI/(ξL⁴) = n⁴/τ₁ (NaN for n = 0).
    pub fn mode_rate(&self, n: usize) -> f64 {
        if n == 0 {
            return f64::NAN;
        }
        let n4 = (n as f64).powi(4);
        n4 / self.params.tau1()
    }

    /// Stationary variance of the amplitude aₙ in w = Σₙ aₙ sin(nπx/L) (NaN for n = 0):
    /// σₙ² = 2kT L³/(π⁴n⁴EI).
    ///
    /// Derivation (equipartition). The bending energy is U = (EI/2)∫₀ᴸ (∂²w/∂x²)² dx.
    /// With ∂²w/∂x² = −Σₙ (nπ/L)² aₙ sin(nπx/L) and the orthogonality
    /// ∫₀ᴸ sin(nπx/L) sin(mπx/L) dx = δₙₘ L/2, U = Σₙ ½ kₙ aₙ² with
    /// kₙ = EI (nπ/L)⁴ (L/2) = π⁴n⁴EI/(2L³). The Boltzmann weight e^{−U/kT} makes the aₙ
    /// independent Gaussians with ⟨½kₙaₙ²⟩ = ½kT, so σₙ² = kT/kₙ = 2kT L³/(π⁴n⁴EI). The
    /// dynamics give the same: the OU process daₙ/dt = −λₙaₙ + gₙ with noise intensity
    /// 4kT/(ξL) has stationary variance (4kT/(ξL))/(2λₙ), the same number
    /// (fluctuation–dissipation).
    pub fn mode_variance(&self, n: usize) -> f64 {
        if n == 0 {
            return f64::NAN;
        }
        self.variance_scale() / (n as f64).powi(4)
    }

    /// Stationary autocovariance of aₙ at a time lag: ⟨aₙ(t) aₙ(t+lag)⟩ = σₙ² e^{−λₙ|lag|}.
    pub fn mode_autocovariance(&self, n: usize, lag: f64) -> f64 {
        self.mode_variance(n) * (-self.mode_rate(n) * lag.abs()).exp()
    }

    /// Mode shape sin(nπx/L) (NaN for n = 0 or x outside [0, L]). Exactly 0 at x = 0 and
    /// x = L.
    pub fn mode_shape(&self, n: usize, x: f64) -> f64 {
        if n == 0 || !self.in_span(x) {
            return f64::NAN;
        }
        sin_pi(n as f64 * (x / self.params.length))
    }

    /// Equilibrium variance of the deflection at x, in closed form:
    /// ⟨w²(x)⟩ = Σₙ 2kT L³ sin²(nπx/L)/(π⁴n⁴EI) = kT x²(L−x)²/(3 EI L)
    /// (NaN for x outside [0, L]).
    ///
    /// Derivation. The mode sum is kT·G(x,x), with G the static Green's function of the
    /// hinged beam (see [`HingedBeam::equilibrium_covariance`]): expanding
    /// δ(x−y) = (2/L) Σₙ sin(nπx/L) sin(nπy/L) and solving EI ∂⁴G/∂x⁴ = δ(x−y) mode by
    /// mode gives G(x,y) = Σₙ (2/L) sin sin /(EI(nπ/L)⁴) = (1/kT) Σₙ σₙ² sin sin. In
    /// closed form G is the deflection at x of a simply supported beam under a unit
    /// point load at y; for x ≤ y, G = x(L−y)(2Ly − x² − y²)/(6 EI L). At y = x,
    /// 2Lx − 2x² = 2x(L−x), so G(x,x) = x²(L−x)²/(3 EI L). Check: at midspan this is
    /// L³/(48 EI), the classical midspan compliance.
    pub fn profile_variance(&self, x: f64) -> f64 {
        if !self.in_span(x) {
            return f64::NAN;
        }
        let p = &self.params;
        let l = p.length;
        let s = x * (l - x);
        // s·(s/L) rather than s²/L: no overflow of s² for very long filaments.
        p.kt * s * (s / l) / (3.0 * p.bending_rigidity)
    }

    /// Equilibrium covariance ⟨w(x) w(y)⟩ = kT·G(x,y) in closed form (NaN if x or y is
    /// outside [0, L]), where G is the hinged-beam Green's function,
    /// EI ∂⁴G/∂x⁴ = δ(x−y), G = ∂²G/∂x² = 0 at x = 0, L:
    ///
    /// - x ≤ y: G(x,y) = x (L−y) (2Ly − x² − y²) / (6 EI L);
    /// - x > y: G(x,y) = y (L−x) (2Lx − x² − y²) / (6 EI L) (symmetry, G(x,y) = G(y,x)).
    ///
    /// Derivation. G is a cubic in x on each side of y. G(0) = G''(0) = 0 leaves
    /// G = A x + B x³ for x < y; likewise in (L−x) for x > y. Continuity of G, G', G''
    /// at x = y and the jump EI[G''']ₓ₌ᵧ = 1 fix the four constants and give the formula
    /// above (the classical deflection of a simply supported beam under a unit point
    /// load at y). Its eigen-expansion is Σₙ (2L³/(π⁴n⁴EI)) sin(nπx/L) sin(nπy/L), so
    /// kT·G(x,y) = Σₙ σₙ² sin(nπx/L) sin(nπy/L), the t = η → ∞ limit of eq. (4).
    pub fn equilibrium_covariance(&self, x: f64, y: f64) -> f64 {
        if !self.in_span(x) || !self.in_span(y) {
            return f64::NAN;
        }
        let p = &self.params;
        let l = p.length;
        let (a, b) = if x <= y { (x, y) } else { (y, x) };
        p.kt * a * (l - b) * (2.0 * l * b - a * a - b * b) / (6.0 * p.bending_rigidity * l)
    }

    /// The mode sum Σ_{n=1}^{N} σₙ² sin²(nπx/L) of ⟨w²(x)⟩ with N = `n_modes`, and the
    /// rigorous tail bound scale·Σ_{n>N} n⁻⁴ ≤ scale/(3(N+½)³) (see
    /// [`inverse_fourth_power_tail`]; scale = 2kTL³/(π⁴EI)). The value is NaN for x
    /// outside [0, L].
    pub fn profile_variance_series(&self, x: f64, n_modes: usize) -> SeriesValue {
        let value = if self.in_span(x) {
            let u = x / self.params.length;
            // Smallest terms first, for accuracy.
            (1..=n_modes)
                .rev()
                .map(|n| {
                    let s = sin_pi(n as f64 * u);
                    s * s / (n as f64).powi(4)
                })
                .sum::<f64>()
                * self.variance_scale()
        } else {
            f64::NAN
        };
        SeriesValue {
            value,
            truncation_error: self.variance_scale() * inverse_fourth_power_tail(n_modes),
            n_modes,
        }
    }

    /// Eq. (4): ⟨w(x,t) w(y,η)⟩ starting from w(x,0) = 0, for 0 ≤ t ≤ η, summing modes
    /// until the rigorous tail bound is at most `tolerance`·scale, scale = 2kTL³/(π⁴EI),
    /// but never more than [`MAX_MODES`] modes. The reported `truncation_error` is the
    /// bound actually achieved (so it may exceed `tolerance`·scale if the tolerance is
    /// below what [`MAX_MODES`] modes reach, about 3·10⁻¹⁶).
    ///
    /// The tail bound: for n > N, |sin sin| ≤ 1 and the bracket
    /// e^{−λₙ(η−t)} − e^{−λₙ(η+t)} lies in [0, e^{−λₙ(η−t)}] ⊂ [0, e^{−λ_{N+1}(η−t)}], so
    /// the omitted tail is at most scale · e^{−λ_{N+1}(η−t)} · Σ_{n>N} n⁻⁴. At t = 0 every
    /// term vanishes and the result is exactly 0 with zero error.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if x or y is outside [0, L], t < 0, t > η, t or η is
    /// not finite, or `tolerance` is not finite and > 0.
    pub fn correlation(
        &self,
        x: f64,
        y: f64,
        t: f64,
        eta: f64,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        self.check_correlation_args(x, y, t, eta)?;
        crate::error::require_positive("tolerance", tolerance)?;
        let target = tolerance * self.variance_scale();
        let mut n = 1;
        while n < MAX_MODES && self.correlation_tail_bound(t, eta, n) > target {
            n += 1;
        }
        Ok(self.correlation_sum(x, y, t, eta, n))
    }

    /// Eq. (4) truncated to the first `n_modes` modes, with the rigorous tail bound of
    /// [`HingedBeam::correlation`].
    ///
    /// # Errors
    /// As [`HingedBeam::correlation`]; also if `n_modes` > [`MAX_MODES`].
    pub fn correlation_truncated(
        &self,
        x: f64,
        y: f64,
        t: f64,
        eta: f64,
        n_modes: usize,
    ) -> Result<SeriesValue> {
        self.check_correlation_args(x, y, t, eta)?;
        if n_modes > MAX_MODES {
            return Err(Error::invalid(
                "n_modes",
                n_modes,
                format!("<= {MAX_MODES}"),
            ));
        }
        Ok(self.correlation_sum(x, y, t, eta, n_modes))
    }

    /// One-sided power spectral density of the stationary amplitude aₙ (a Lorentzian):
    /// S(f) = 4σₙ²λₙ/(λₙ² + (2πf)²), f ≥ 0, normalised so that ∫₀^∞ S df = σₙ².
    /// It is the Fourier transform of [`HingedBeam::mode_autocovariance`], doubled to
    /// fold negative frequencies (the formula is even in f).
    pub fn lorentzian(&self, n: usize, f: f64) -> f64 {
        ou_lorentzian(self.mode_variance(n), self.mode_rate(n), f)
    }

    /// Exact one-sided power spectral density of the sampled sequence aₙ(k·dt), k ∈ ℤ,
    /// on 0 ≤ f ≤ 1/(2dt) (NaN if dt is not finite and > 0).
    ///
    /// The sampled OU process is an AR(1): a_{k+1} = ρ a_k + e_k with ρ = e^{−λₙdt} and
    /// Var e = σₙ²(1−ρ²). Its autocovariance σₙ²ρ^{|k|} has the two-sided density (per
    /// unit frequency) dt·σₙ²(1−ρ²)/|1 − ρe^{−2πi f dt}|², so the one-sided density is
    /// S(f) = 2 dt σₙ² (1−ρ²)/(1 − 2ρ cos(2πf dt) + ρ²), with ∫₀^{1/(2dt)} S df = σₙ².
    /// Sampling aliases the Lorentzian: S(f) = Σ_{m∈ℤ} `lorentzian`(f + m/dt).
    pub fn sampled_spectrum(&self, n: usize, dt: f64, f: f64) -> f64 {
        ou_sampled_spectrum(self.mode_variance(n), self.mode_rate(n), dt, f)
    }

    fn in_span(&self, x: f64) -> bool {
        x.is_finite() && (0.0..=self.params.length).contains(&x)
    }

    fn check_correlation_args(&self, x: f64, y: f64, t: f64, eta: f64) -> Result<()> {
        let l = self.params.length;
        require_in_range("x", x, 0.0, l)?;
        require_in_range("y", y, 0.0, l)?;
        check_two_times(t, eta, "eq. 4")
    }

    /// Rigorous bound on the tail n > N of eq. (4).
    fn correlation_tail_bound(&self, t: f64, eta: f64, n_modes: usize) -> f64 {
        if t == 0.0 {
            return 0.0;
        }
        let decay = (-self.mode_rate(n_modes + 1) * (eta - t)).exp();
        self.variance_scale() * decay * inverse_fourth_power_tail(n_modes)
    }

    /// Partial sum of eq. (4) over modes 1..=N (arguments already validated).
    fn correlation_sum(&self, x: f64, y: f64, t: f64, eta: f64, n_modes: usize) -> SeriesValue {
        let l = self.params.length;
        let (u, v) = (x / l, y / l);
        let tau1 = self.params.tau1();
        let value = (1..=n_modes)
            .rev()
            .map(|n| {
                let nf = n as f64;
                let lam = nf.powi(4) / tau1;
                // e^{−λ(η−t)} − e^{−λ(η+t)} = e^{−λ(η−t)} (1 − e^{−2λt}), no cancellation.
                let bracket = (-lam * (eta - t)).exp() * -(-2.0 * lam * t).exp_m1();
                sin_pi(nf * u) * sin_pi(nf * v) * bracket / nf.powi(4)
            })
            .sum::<f64>()
            * self.variance_scale();
        SeriesValue {
            value,
            truncation_error: self.correlation_tail_bound(t, eta, n_modes),
            n_modes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beam() -> HingedBeam {
        HingedBeam::new(FilamentParams {
            length: 2.5,
            bending_rigidity: 0.7,
            stretch_rigidity: 1.0e6,
            drag: 3.0,
            kt: 0.4,
        })
        .unwrap()
    }

    // What: sin_pi has exact zeros at integers, the right sign, and agrees with sin(πs).
    // Reference: the definition. Tolerance: a few ulp (argument reduction is exact).
    #[test]
    fn sin_pi_exact_zeros_and_values() {
        for k in 0..50 {
            assert_eq!(sin_pi(k as f64), 0.0);
        }
        for &s in &[0.1, 0.5, 0.9, 1.3, 1.75, 2.2, -0.3, 7.6, 123.25] {
            let direct = (PI * s).sin();
            assert!((sin_pi(s) - direct).abs() < 1e-13, "s = {s}");
        }
        assert_eq!(sin_pi(0.5), 1.0);
        assert_eq!(sin_pi(1.5), -1.0);
    }

    // What: the tail bound 1/(3(N+½)³) really bounds Σ_{n>N} n⁻⁴ and is tight.
    // Reference: brute-force tail (10⁶ terms plus the integral remainder, which is below
    // 1/(3·10¹⁸)). Tolerance: bound ≥ tail exactly; bound ≤ (1 + 1/N²)·tail.
    #[test]
    fn inverse_fourth_power_tail_is_a_tight_bound() {
        let zeta4 = PI.powi(4) / 90.0;
        assert_eq!(inverse_fourth_power_tail(0), zeta4);
        for &nn in &[1usize, 2, 3, 5, 10, 40] {
            let tail: f64 = (nn + 1..1_000_000).rev().map(|n| (n as f64).powi(-4)).sum();
            let bound = inverse_fourth_power_tail(nn);
            assert!(bound >= tail, "N = {nn}");
            assert!(bound <= tail * (1.0 + 1.0 / (nn * nn) as f64), "N = {nn}");
        }
    }

    // What: mode rate is n⁴/τ₁, the variance is the equipartition value kT/kₙ with
    // kₙ = π⁴n⁴EI/(2L³), and λₙσₙ² = 2kT/(ξL) (fluctuation–dissipation: q/2 with
    // q = 4kT/(ξL)). Reference: the derivations in the doc comments. Tolerance: 1e-14
    // relative (only rounding).
    #[test]
    fn mode_rate_and_variance_formulas() {
        let b = beam();
        let p = b.params;
        for n in 1..6 {
            let nf = n as f64;
            let lam = PI.powi(4) * nf.powi(4) * p.bending_rigidity / (p.drag * p.length.powi(4));
            assert!((b.mode_rate(n) / lam - 1.0).abs() < 1e-14);
            let kn = PI.powi(4) * nf.powi(4) * p.bending_rigidity / (2.0 * p.length.powi(3));
            assert!((b.mode_variance(n) * kn / p.kt - 1.0).abs() < 1e-14);
            let fd = b.mode_rate(n) * b.mode_variance(n) / (2.0 * p.kt / (p.drag * p.length));
            assert!((fd - 1.0).abs() < 1e-14);
            assert!((b.mode_autocovariance(n, -0.3) - b.mode_autocovariance(n, 0.3)).abs() == 0.0);
        }
        assert!(b.mode_rate(0).is_nan());
        assert!(b.mode_variance(0).is_nan());
        assert!(b.mode_shape(0, 1.0).is_nan());
        assert!(b.lorentzian(0, 1.0).is_nan());
    }

    // What: the sampled spectrum equals the closed-form aliasing sum
    // Σₘ 2λ/(λ²+(ω+2πm/dt)²) = dt·sinh(λdt)/(cosh(λdt) − cos(ωdt)), times 2σ² for the
    // one-sided density. Reference: the classical lattice sum of a Lorentzian.
    // Tolerance: 1e-12 relative (rounding).
    #[test]
    fn sampled_spectrum_matches_sinh_cosh_form() {
        let b = beam();
        let tau1 = b.params.tau1();
        for &(n, dt) in &[(1usize, 0.01 * tau1), (1, 2.0 * tau1), (3, 0.05 * tau1)] {
            let lam = b.mode_rate(n);
            for k in 0..=10 {
                let f = k as f64 / 10.0 / (2.0 * dt);
                let x = lam * dt;
                // cosh x − cos θ = 2sinh²(x/2) + 2sin²(θ/2), without cancellation.
                let denom = 2.0 * (x / 2.0).sinh().powi(2) + 2.0 * (PI * f * dt).sin().powi(2);
                let expect = 2.0 * b.mode_variance(n) * dt * x.sinh() / denom;
                let got = b.sampled_spectrum(n, dt, f);
                assert!((got / expect - 1.0).abs() < 1e-12, "n={n} dt={dt} f={f}");
            }
        }
        assert!(b.sampled_spectrum(1, 0.0, 1.0).is_nan());
        assert!(b.sampled_spectrum(1, f64::NAN, 1.0).is_nan());
    }

    // What: positions outside [0, L] give NaN from the f64-returning functions.
    #[test]
    fn out_of_span_positions_give_nan() {
        let b = beam();
        let l = b.params.length;
        for &x in &[-0.1, l + 1e-9, f64::NAN, f64::INFINITY] {
            assert!(b.profile_variance(x).is_nan());
            assert!(b.equilibrium_covariance(x, 0.5).is_nan());
            assert!(b.equilibrium_covariance(0.5, x).is_nan());
            assert!(b.mode_shape(1, x).is_nan());
            assert!(b.profile_variance_series(x, 5).value.is_nan());
        }
    }
}
