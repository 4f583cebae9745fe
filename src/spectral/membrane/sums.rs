//! Mode sums over the wavevector lattice, (M4)–(M6), and their rigorous truncation bounds.
//!
//! # The lattice tail bound
//!
//! A sum truncated at |q| ≤ Q omits Σ_{|q|>Q} F(|q|) over the lattice points, where F is
//! positive and non-increasing on [R, ∞), R = Q − d, d the diagonal of a lattice cell
//! (Δq_x × Δq_y, area Δ). Give each point q of a quadrant (m, n ≥ 1) the cell between it
//! and the origin, [q_x − Δq_x, q_x] × [q_y − Δq_y, q_y]. These cells are disjoint, every
//! point p of q's cell has |q| − d ≤ |p| ≤ |q|, so F(|q|) ≤ F(|p|), and for |q| > Q the
//! cell lies outside the disc of radius R. Hence
//!
//! Σ_{quadrant, |q|>Q} F(|q|) ≤ Δ⁻¹ ∫_{quadrant, |p|>R} F(|p|) d²p = (π/2Δ) ∫_R^∞ F(r) r dr.
//!
//! Simply supported: one quadrant, Δ = π²/A, so the tail is at most (A/2π)·∫_R^∞ F r dr.
//! Periodic (the full lattice Z² \ {0}): four quadrants with Δ = 4π²/A give the same
//! (A/2π)·∫_R^∞ F r dr, and the points on the axes, by the same argument in one dimension
//! (each point owns the segment between it and the origin), add at most
//! 2(1/Δq_x + 1/Δq_y)·∫_R^∞ F(r) dr = ((a + b)/π)·∫_R^∞ F(r) dr.
//!
//! The bounds are +∞ unless R > 0 and κR² + σ > 0 (then every F used here is positive
//! and decreasing on [R, ∞); c_q = κq⁴ + σq² increases there). They are asymptotically
//! tight for the periodic point variance (relative excess O(d/Q)); for simply supported
//! sums at a point they replace sin²·sin² by 1, whose average is ¼, so they are about four
//! times the actual tail. Floating-point rounding of the partial sums (relative order
//! 10⁻¹⁶ with the compensated summation used) is not included; the bound uses
//! Q(1 − 10⁻¹²) in place of Q, so that a point rounded out of the sum at |q| ≈ Q is still
//! covered.
//!
//! The radial and axial integrals used, with g = 1 + min(0, σ)/(κR²) > 0 (for r ≥ R,
//! κr² + σ ≥ g·κr²):
//!
//! - ∫_R^∞ r dr/c(r) = ln(1 + x)/(2κR²·x), x = σ/(κR²) (exactly; 1/(2κR²) at x = 0);
//!   ∫_R^∞ dr/c(r) ≤ 1/(3gκR³);
//! - ∫_R^∞ r dr/(κr² + σ)² = 1/(2κ(κR² + σ)); ∫_R^∞ dr/(κr² + σ)² ≤ 1/(3g²κ²R³);
//! - ∫_R^∞ r·|σ| dr/(κr⁴(κr² + σ)) ≤ |σ|/(4gκ²R⁴); ∫_R^∞ |σ| dr/(κr⁴(κr² + σ)) ≤
//!   |σ|/(5gκ²R⁵) (the tension correction of `levy.rs`).

use super::{Membrane, MembraneBoundary, cos_pi, frac};
use crate::error::{Error, Result, require_positive};
use crate::spectral::{SeriesValue, sin_pi};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The excess area ΔA = ½∫|∇h|² d²r of the modes with |q| ≤ `cutoff`, (M6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExcessArea {
    /// The wavenumber cutoff Q.
    pub cutoff: f64,
    /// Number of real modes with |q| ≤ Q.
    pub n_modes: usize,
    /// ⟨ΔA⟩ = (kT/2) Σ 1/(κq² + σ) over those modes (exact for them; it grows without
    /// bound, as ln Q, with the cutoff: see [`Membrane::excess_area`]).
    pub mean: f64,
    /// Var ΔA = (kT)²/2 · Σ (κq² + σ)⁻² over those modes (exact for them).
    pub variance: f64,
    /// Rigorous upper bound on Var ΔA(Q → ∞) − `variance` (the variance converges).
    pub variance_tail_bound: f64,
}

/// Time dependence of a two-time mode sum.
#[derive(Debug, Clone, Copy)]
pub(super) enum Kernel {
    /// From rest, h(·, 0) = 0, times t ≤ η: e^{−λ(η−t)} − e^{−λ(η+t)}.
    FromRest { t: f64, eta: f64 },
    /// Stationary, lag ≥ 0: e^{−λ·lag}.
    Stationary { lag: f64 },
}

impl Kernel {
    /// The factor of a mode of rate `rate`.
    pub(super) fn factor(self, rate: f64) -> f64 {
        match self {
            // e^{−λ(η−t)} (1 − e^{−2λt}), without cancellation.
            Kernel::FromRest { t, eta } => (-rate * (eta - t)).exp() * -(-2.0 * rate * t).exp_m1(),
            Kernel::Stationary { lag } => (-rate * lag).exp(),
        }
    }

    /// Upper bound on `factor` over every rate ≥ `rate` (both are at most e^{−rate·gap}).
    fn max_beyond(self, rate: f64) -> f64 {
        match self {
            Kernel::FromRest { t, eta } => (-rate * (eta - t)).exp(),
            Kernel::Stationary { lag } => (-rate * lag).exp(),
        }
    }
}

/// Neumaier's compensated sum.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct CompensatedSum {
    sum: f64,
    carry: f64,
}

impl CompensatedSum {
    pub(crate) fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.carry += (self.sum - t) + v;
        } else {
            self.carry += (v - t) + self.sum;
        }
        self.sum = t;
    }

    pub(crate) fn value(self) -> f64 {
        self.sum + self.carry
    }
}

/// Σ_φ φ(r) φ(r′)/‖φ‖² over the real modes of each lattice point, tabulated by index.
pub(crate) struct ShapeTable {
    periodic: bool,
    scale: f64,
    /// Simply supported: sin(mπx/a) sin(mπx′/a); periodic: cos(2πmΔx/a).
    x1: Vec<f64>,
    /// Periodic: sin(2πmΔx/a).
    x2: Vec<f64>,
    y1: Vec<f64>,
    y2: Vec<f64>,
}

impl ShapeTable {
    /// The table for the points r, r′ and every index reached below `cutoff`.
    pub(crate) fn new(mb: &Membrane, r: (f64, f64), r2: (f64, f64), cutoff: f64) -> Self {
        let p = &mb.params;
        let (kx, ky) = mb.spacing();
        let mx = (cutoff / kx).floor() as usize + 2;
        let ny = (cutoff / ky).floor() as usize + 2;
        let periodic = p.boundary == MembraneBoundary::Periodic;
        let (u, u2) = (r.0 / p.width, r2.0 / p.width);
        let (v, v2) = (r.1 / p.height, r2.1 / p.height);
        let pair = |s: f64, s2: f64, len: usize| -> (Vec<f64>, Vec<f64>) {
            if periodic {
                let d = s - s2;
                let phase = |k: usize| 2.0 * frac(k as f64 * d);
                let c = (0..len).map(|k| cos_pi(phase(k))).collect();
                let sn = (0..len).map(|k| sin_pi(phase(k))).collect();
                (c, sn)
            } else {
                let f = |k: usize| sin_pi(k as f64 * s) * sin_pi(k as f64 * s2);
                ((0..len).map(f).collect(), Vec::new())
            }
        };
        let (x1, x2) = pair(u, u2, mx);
        let (y1, y2) = pair(v, v2, ny);
        ShapeTable {
            periodic,
            scale: 1.0 / mb.mode_norm_sq(),
            x1,
            x2,
            y1,
            y2,
        }
    }

    /// Σ_φ φ(r)φ(r′)/‖φ‖² at lattice point (m, n): (4/A) sin sin sin sin, or, periodic,
    /// (2/A)(cos q·r cos q·r′ + sin q·r sin q·r′) = (2/A) cos(q·(r − r′)).
    pub(crate) fn product(&self, m: i64, n: i64) -> f64 {
        let (i, j) = (m as usize, n.unsigned_abs() as usize);
        if self.periodic {
            let sy = if n < 0 { -self.y2[j] } else { self.y2[j] };
            self.scale * (self.x1[i] * self.y1[j] - self.x2[i] * sy)
        } else {
            self.scale * self.x1[i] * self.y1[j]
        }
    }
}

impl Membrane {
    /// Calls `f(m, n, q²)` for every lattice point with q² ≤ cutoff² (simply supported:
    /// m, n ≥ 1; periodic: the half-lattice m > 0, or m = 0 and n > 0).
    pub(crate) fn visit_lattice(&self, cutoff: f64, mut f: impl FnMut(i64, i64, f64)) {
        let (kx, ky) = self.spacing();
        let q2max = cutoff * cutoff;
        let periodic = self.params.boundary == MembraneBoundary::Periodic;
        let m_max = (cutoff / kx).floor() as i64 + 1;
        for m in i64::from(!periodic)..=m_max {
            let qx = kx * m as f64;
            let qx2 = qx * qx;
            if qx2 > q2max {
                break;
            }
            let n_max = ((q2max - qx2).sqrt() / ky).floor() as i64 + 1;
            let n_lo = if periodic && m > 0 { -n_max } else { 1 };
            for n in n_lo..=n_max {
                let qy = ky * n as f64;
                let q2 = qx2 + qy * qy;
                if q2 <= q2max {
                    f(m, n, q2);
                }
            }
        }
    }

    /// Real modes per visited lattice point: 1 simply supported, 2 (cos, sin) periodic.
    fn modes_per_point(&self) -> usize {
        match self.params.boundary {
            MembraneBoundary::SimplySupported => 1,
            MembraneBoundary::Periodic => 2,
        }
    }

    /// The largest |Σ_φ φ(r)φ(r′)/‖φ‖²| per lattice point of the bound's lattice (quadrant
    /// points simply supported, full lattice periodic): 4/A and 1/A.
    pub(crate) fn point_weight(&self) -> f64 {
        match self.params.boundary {
            MembraneBoundary::SimplySupported => 4.0 / self.params.area(),
            MembraneBoundary::Periodic => 1.0 / self.params.area(),
        }
    }

    /// g = 1 + min(0, σ)/(κR²), so that κr² + σ ≥ g·κr² for r ≥ R.
    fn tension_factor(&self, r: f64) -> f64 {
        1.0 + self.params.tension.min(0.0) / (self.params.bending_rigidity * r * r)
    }

    /// Rigorous bound on Σ F(|q|) over the lattice points with |q| > `cutoff` (see the
    /// module docs), given radial(R) ≥ ∫_R^∞ F r dr and axial(R) ≥ ∫_R^∞ F dr.
    pub(crate) fn lattice_tail(
        &self,
        cutoff: f64,
        radial: impl Fn(f64) -> f64,
        axial: impl Fn(f64) -> f64,
    ) -> f64 {
        let p = &self.params;
        let r = cutoff * (1.0 - 1e-12) - self.cell_diagonal();
        if !(r > 0.0 && p.bending_rigidity * r * r + p.tension > 0.0) {
            return f64::INFINITY;
        }
        let bulk = p.area() / (2.0 * PI) * radial(r);
        match p.boundary {
            MembraneBoundary::SimplySupported => bulk,
            MembraneBoundary::Periodic => bulk + (p.width + p.height) / PI * axial(r),
        }
    }

    /// Bound on Σ_{|q|>Q} kT·|Σ_φ φφ′/‖φ‖²|/c_q, the tail of the point variance (M5).
    pub(crate) fn variance_tail(&self, cutoff: f64) -> f64 {
        let (kappa, sigma) = (self.params.bending_rigidity, self.params.tension);
        let w = self.point_weight() * self.params.kt;
        self.lattice_tail(
            cutoff,
            |r| {
                let x = sigma / (kappa * r * r);
                let ratio = if x == 0.0 { 1.0 } else { x.ln_1p() / x };
                w * ratio / (2.0 * kappa * r * r)
            },
            |r| w / (3.0 * self.tension_factor(r) * kappa * r * r * r),
        )
    }

    /// The smallest cutoff (to a relative 10⁻⁶) whose `bound` is at most `target`, or
    /// [`Membrane::max_cutoff`] if that is not enough. `bound` must be non-increasing and
    /// +∞ at q_min/2.
    pub(crate) fn cutoff_for(&self, target: f64, bound: impl Fn(f64) -> f64) -> f64 {
        self.cutoff_below(target, bound, self.max_cutoff())
    }

    /// [`Self::cutoff_for`] with the largest cutoff `max` instead of
    /// [`Membrane::max_cutoff`].
    pub(crate) fn cutoff_below(&self, target: f64, bound: impl Fn(f64) -> f64, max: f64) -> f64 {
        if bound(max) > target {
            return max;
        }
        let (mut lo, mut hi) = (0.5 * self.params.min_wavenumber_sq().sqrt(), max);
        while hi > lo * (1.0 + 1e-6) {
            let mid = (lo * hi).sqrt();
            if bound(mid) <= target {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }

    /// Bound on the tail of a two-time sum: the kernel's largest factor beyond Q times the
    /// equal-time tail.
    fn kernel_tail(&self, kernel: Kernel, cutoff: f64) -> f64 {
        if matches!(kernel, Kernel::FromRest { t, .. } if t == 0.0) {
            return 0.0;
        }
        let tail = self.variance_tail(cutoff);
        if tail.is_infinite() {
            return tail;
        }
        let beyond = kernel.max_beyond(self.c_of_q2(cutoff * cutoff) / self.params.drag);
        if beyond == 0.0 { 0.0 } else { beyond * tail }
    }

    /// Σ_{|q|≤Q} Σ_φ ⟨a²⟩ φ(r)φ(r′)·kernel(λ_q), with its tail bound.
    fn kernel_sum(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        kernel: Kernel,
        cutoff: f64,
    ) -> SeriesValue {
        let table = ShapeTable::new(self, r, r2, cutoff);
        let (kt, drag) = (self.params.kt, self.params.drag);
        let mut sum = CompensatedSum::default();
        let mut points = 0usize;
        if !matches!(kernel, Kernel::FromRest { t, .. } if t == 0.0) {
            self.visit_lattice(cutoff, |m, n, q2| {
                let c = self.c_of_q2(q2);
                sum.add(kt * table.product(m, n) / c * kernel.factor(c / drag));
                points += 1;
            });
        }
        SeriesValue {
            value: sum.value(),
            truncation_error: self.kernel_tail(kernel, cutoff),
            n_modes: points * self.modes_per_point(),
        }
    }

    /// Validates the arguments of a two-time sum and returns its kernel.
    fn rest_kernel(&self, r: (f64, f64), r2: (f64, f64), t: f64, eta: f64) -> Result<Kernel> {
        self.check_point("x", "y", r)?;
        self.check_point("x2", "y2", r2)?;
        crate::spectral::check_two_times(t, eta, "M4")?;
        Ok(Kernel::FromRest { t, eta })
    }

    fn stationary_kernel(&self, r: (f64, f64), r2: (f64, f64), lag: f64) -> Result<Kernel> {
        self.check_point("x", "y", r)?;
        self.check_point("x2", "y2", r2)?;
        if !lag.is_finite() {
            return Err(Error::invalid("lag", lag, "finite"));
        }
        Ok(Kernel::Stationary { lag: lag.abs() })
    }

    /// Sums with the cutoff chosen so that the bound is at most `tolerance`·scale
    /// (scale = [`Membrane::variance_scale`]), or at [`Membrane::max_cutoff`].
    fn kernel_sum_to(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        kernel: Kernel,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        require_positive("tolerance", tolerance)?;
        let target = tolerance * self.variance_scale();
        let cutoff = self.cutoff_for(target, |q| self.kernel_tail(kernel, q));
        Ok(self.kernel_sum(r, r2, kernel, cutoff))
    }

    /// (M4), the analogue of eq. (4): ⟨h(r,t) h(r′,η)⟩ from h(·, 0) = 0, for 0 ≤ t ≤ η,
    /// r = (x, y), r′ = (x2, y2), summing the modes with |q| ≤ Q for the smallest Q whose
    /// rigorous tail bound is at most `tolerance`·[`Membrane::variance_scale`], but never
    /// more than about [`super::MAX_MEMBRANE_MODES`] modes (the bound achieved is reported,
    /// and may then exceed the tolerance).
    ///
    /// Derivation: each amplitude obeys (M2) from a(0) = 0, so
    /// ⟨a(t)a(η)⟩ = ⟨a²⟩(e^{−λ(η−t)} − e^{−λ(η+t)}), and the modes are independent. Tail
    /// bound: for |q| > Q the bracket lies in [0, e^{−λ_Q(η−t)}] (c_q increases beyond Q),
    /// times the equal-time lattice tail of the module docs with F = w·kT/c(r), w = 4/A
    /// (simply supported) or 1/A (periodic, per point of Z²). At t = 0 the result is
    /// exactly 0 with zero error.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a position is outside the rectangle (naming `x`, `y`,
    /// `x2` or `y2`), t < 0, η < t, a time is not finite, or `tolerance` is not finite
    /// and > 0.
    pub fn correlation(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        t: f64,
        eta: f64,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        let kernel = self.rest_kernel(r, r2, t, eta)?;
        self.kernel_sum_to(r, r2, kernel, tolerance)
    }

    /// (M4) truncated to the modes with |q| ≤ `cutoff`, with the rigorous tail bound of
    /// [`Membrane::correlation`].
    ///
    /// # Errors
    /// As [`Membrane::correlation`]; also naming `cutoff` if it is not finite and > 0 or
    /// above [`Membrane::max_cutoff`].
    pub fn correlation_truncated(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        t: f64,
        eta: f64,
        cutoff: f64,
    ) -> Result<SeriesValue> {
        let kernel = self.rest_kernel(r, r2, t, eta)?;
        self.check_cutoff("cutoff", cutoff, super::MAX_MEMBRANE_MODES)?;
        Ok(self.kernel_sum(r, r2, kernel, cutoff))
    }

    /// Stationary two-time covariance ⟨h(r,t) h(r′,t+lag)⟩ = Σ_φ ⟨a²⟩ φ(r)φ(r′)e^{−λ|lag|}
    /// (the t → ∞ limit of (M4) at fixed η − t), to `tolerance` as
    /// [`Membrane::correlation`]; at lag 0 the equilibrium covariance.
    ///
    /// # Errors
    /// As [`Membrane::correlation`], and naming `lag` if it is not finite.
    pub fn stationary_correlation(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        lag: f64,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        let kernel = self.stationary_kernel(r, r2, lag)?;
        self.kernel_sum_to(r, r2, kernel, tolerance)
    }

    /// [`Membrane::stationary_correlation`] truncated to |q| ≤ `cutoff`, with its bound.
    ///
    /// # Errors
    /// As [`Membrane::stationary_correlation`] and [`Membrane::correlation_truncated`].
    pub fn stationary_correlation_truncated(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        lag: f64,
        cutoff: f64,
    ) -> Result<SeriesValue> {
        let kernel = self.stationary_kernel(r, r2, lag)?;
        self.check_cutoff("cutoff", cutoff, super::MAX_MEMBRANE_MODES)?;
        Ok(self.kernel_sum(r, r2, kernel, cutoff))
    }

    /// (M5) as the mode sum: ⟨h²(x, y)⟩ over the modes with |q| ≤ `cutoff`, with the
    /// rigorous tail bound of the module docs. The closed, fast-converging form is
    /// [`Membrane::point_variance`]. The sum converges (its terms fall as q⁻⁴ in two
    /// dimensions); the tail is O(1/Q²).
    ///
    /// # Errors
    /// As [`Membrane::stationary_correlation_truncated`].
    pub fn point_variance_series(&self, x: f64, y: f64, cutoff: f64) -> Result<SeriesValue> {
        self.stationary_correlation_truncated((x, y), (x, y), 0.0, cutoff)
    }

    /// (M6): the excess area ΔA = ½∫|∇h|² d²r of the real modes with |q| ≤ `cutoff`.
    ///
    /// Derivation. With h = Σ_φ a_φ φ and ∫∇φ·∇ψ = q²∫φψ (integration by parts; the
    /// boundary terms vanish for both boundaries), ΔA = Σ_φ ½q²‖φ‖² a_φ² = Σ_φ b_φ Z_φ²
    /// with independent standard normals Z_φ and, by (M3), b_φ = ½q²‖φ‖²·kT/(c_q‖φ‖²) =
    /// (kT/2)/(κq² + σ). So ⟨ΔA⟩ = Σ b_φ = (kT/2) Σ 1/(κq² + σ) and, since Var Z² = 2,
    /// Var ΔA = 2Σ b_φ² = (kT)²/2 · Σ (κq² + σ)⁻².
    ///
    /// **⟨ΔA⟩ depends on the cutoff, and that is physics, not truncation error**: in two
    /// dimensions the number of modes below Q grows as AQ²/(4π), so
    /// ⟨ΔA⟩ ≈ (kT A/(4πκ)) ln Q + const for Q² ≫ |σ|/κ (Helfrich–Servuss); Q is a physical
    /// short-distance cutoff (e.g. π over a molecular size) and must be stated with the
    /// result. Var ΔA converges as Q → ∞; `variance_tail_bound` bounds the rest of it
    /// (the lattice tail with F = (kT)²/2·(κr² + σ)⁻², one real mode per point).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `cutoff` if it is not finite and > 0 or above
    /// [`Membrane::max_cutoff`].
    pub fn excess_area(&self, cutoff: f64) -> Result<ExcessArea> {
        self.check_cutoff("cutoff", cutoff, super::MAX_MEMBRANE_MODES)?;
        let (kappa, sigma, kt) = (
            self.params.bending_rigidity,
            self.params.tension,
            self.params.kt,
        );
        let (mut mean, mut second) = (CompensatedSum::default(), CompensatedSum::default());
        let mut points = 0usize;
        self.visit_lattice(cutoff, |_, _, q2| {
            let inv = 1.0 / (kappa * q2 + sigma);
            mean.add(inv);
            second.add(inv * inv);
            points += 1;
        });
        let k = self.modes_per_point() as f64;
        let half_kt2 = 0.5 * kt * kt;
        let variance_tail_bound = self.lattice_tail(
            cutoff,
            |r| half_kt2 / (2.0 * kappa * (kappa * r * r + sigma)),
            |r| half_kt2 / (3.0 * (self.tension_factor(r) * kappa).powi(2) * r * r * r),
        );
        Ok(ExcessArea {
            cutoff,
            n_modes: points * self.modes_per_point(),
            mean: 0.5 * kt * k * mean.value(),
            variance: half_kt2 * k * second.value(),
            variance_tail_bound,
        })
    }

    /// Bound on Σ_{|q|>Q} kT·w·|σ|/(κq⁴(κq² + σ)), the tail of the tension correction of
    /// `levy.rs` (w = [`Membrane::point_weight`]).
    pub(crate) fn tension_correction_tail(&self, cutoff: f64) -> f64 {
        let (kappa, sigma) = (self.params.bending_rigidity, self.params.tension.abs());
        let w = self.point_weight() * self.params.kt * sigma / (kappa * kappa);
        self.lattice_tail(
            cutoff,
            |r| w / (4.0 * self.tension_factor(r) * r.powi(4)),
            |r| w / (5.0 * self.tension_factor(r) * r.powi(5)),
        )
    }
}
