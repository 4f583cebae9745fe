//! Exact continuum references for a fluctuating membrane (issue #27): the linear Monge-gauge
//! Helfrich membrane with free-draining friction, modes, rates, variances, two-time
//! correlations with rigorous truncation bounds, the point variance, the excess area and
//! the per-mode spectra. The membrane analogue of [`super::HingedBeam`].
//!
//! # The model
//!
//! The height h(r, t) of a membrane over the a × b rectangle (a = `width` along x,
//! b = `height` along y, area A = ab) obeys, as eq. (2) of Lin & Shenoy for the filament,
//!
//! ξ ∂h/∂t = −κ∇⁴h + σ∇²h + f,  ⟨f(r,t) f(r′,t′)⟩ = 2ξkT δ(r−r′) δ(t−t′)   (M1)
//!
//! (the membrane version of eqs. 1–2): −κ∇⁴h + σ∇²h = −δE/δh for the quadratic Helfrich
//! energy E = ∫ [κ/2 (∇²h)² + σ/2 |∇h|²] d²r, with bending rigidity κ (energy), tension σ
//! (energy per area, of either sign) and friction ξ per unit area. The boundary is either
//!
//! - **simply supported** ([`MembraneBoundary::SimplySupported`]): h = ∇²h = 0 on the four
//!   edges. Real modes φ = sin(mπx/a) sin(nπy/b), m, n ≥ 1 ([`ModeShape::SineSine`]),
//!   wavevector q = (mπ/a, nπ/b), ‖φ‖² = ∫φ² = A/4;
//! - **periodic** ([`MembraneBoundary::Periodic`]): wavevectors q = 2π(m/a, n/b). The
//!   **q = 0 mode is excluded**: a uniform displacement has no restoring force (c₀ = 0); it
//!   is a free Brownian translation, ⟨(h₀(t) − h₀(0))²⟩ = 2kT t/(ξA), not a fluctuation
//!   with a variance. Every result here is for h measured from its spatial mean.
//!
//! Every mode relaxes independently. With c_q = κq⁴ + σq² (the energy per unit area per
//! squared amplitude, [`Membrane::stiffness`]) the energy is E = Σ ½ c_q ‖φ‖² a_φ² over the
//! real modes (the cross terms vanish: ∫φ∇⁴ψ = ∫∇²φ∇²ψ and ∫∇φ·∇ψ = q²∫φψ for these
//! boundaries, and distinct modes are orthogonal). Projecting (M1) onto φ gives one
//! Ornstein–Uhlenbeck process per real mode,
//!
//! da/dt = −λ_q a + g,  λ_q = c_q/ξ,  ⟨g(t) g(t′)⟩ = (2kT/(ξ‖φ‖²)) δ(t−t′),   (M2)
//!
//! whose stationary variance (2kT/(ξ‖φ‖²))/(2λ_q) = kT/(c_q‖φ‖²) is also equipartition's
//! ⟨½c_q‖φ‖²a²⟩ = ½kT:
//!
//! ⟨a²⟩ = kT/(c_q ‖φ‖²): 4kT/(A c_q) simply supported; 2kT/(A c_q) periodic.   (M3)
//!
//! The tension must lie above the buckling tension −κ q_min² (q_min the smallest wavenumber
//! of the geometry: q_min² = π²(1/a² + 1/b²) simply supported, (2π/max(a, b))² periodic):
//! at or below it, c_q ≤ 0 for the slowest mode and (M1) has no stationary state
//! ([`MembraneParams::validate`] refuses it).
//!
//! # Conventions (the one place they are stated)
//!
//! **Periodic, complex amplitudes.** h(r) = Σ_{q≠0} h_q e^{iq·r} with
//! h_q = A⁻¹∫ h(r) e^{−iq·r} d²r (the mean-height q = 0 term excluded), h₋q = h_q*, and
//!
//! ⟨|h_q|²⟩ = kT/(A c_q)   ([`Membrane::fourier_variance`]).
//!
//! Other conventions users meet: h_q = L⁻¹∫…d²r on an L × L square (common in MD codes)
//! is L times ours, so ⟨|h_q|²⟩ = kT/c_q; the unnormalised ∫…d²r gives A·kT/c_q; a raw FFT
//! H_q = Σ_{jk} h(r_jk) e^{−iq·r_jk} of N × N samples of a field without modes beyond the
//! grid's Nyquist wavenumber is N² h_q, so ⟨|H_q|²⟩ = N⁴ kT/(A c_q): N⁴ times ours, i.e.
//! N⁴/A times the kT/c_q of the L⁻¹ convention (with a continuum field, the FFT also
//! aliases: ⟨|H_q|²⟩ = N⁴ Σ_G kT/(A c_{q+G}) over the reciprocal grid vectors G).
//!
//! **Periodic, real amplitudes (what this module's modes are).** With the half-lattice
//! H = {m > 0} ∪ {m = 0, n > 0} (one of each pair ±q),
//! h(r) = Σ_{q∈H} [A_q cos(q·r) + B_q sin(q·r)], A_q = 2 Re h_q, B_q = −2 Im h_q, and the
//! A_q, B_q are independent with ⟨A_q²⟩ = ⟨B_q²⟩ = 2kT/(A c_q) = 2⟨|h_q|²⟩ (M3).
//! [`ModeShape::Cosine`] and [`ModeShape::Sine`] are these two modes of q ∈ H.
//!
//! **Simply supported.** h = Σ_{m,n≥1} a_mn sin(mπx/a) sin(nπy/b), ⟨a_mn²⟩ = 4kT/(A c_q).
//!
//! Mode sums ("the modes up to a cutoff Q") run over the real modes with |q| ≤ Q, |q|²
//! compared with Q² in floating point: a lattice shell lying exactly at Q may fall either
//! side, so choose a cutoff between shells when it matters. Positions must lie in the closed
//! rectangle [0, a] × [0, b] (also for the periodic membrane, although its results depend
//! only on differences of positions). Per-mode functions return NaN for a mode that is not
//! one of this geometry (see [`Membrane::is_mode`]) or a position outside the rectangle;
//! the fallible ones return [`Error::InvalidParameter`] instead.
//!
//! # Exact results and their equations
//!
//! - (M4) two-time correlation from rest, h(r, 0) = 0, for t ≤ η (the analogue of eq. 4):
//!   ⟨h(r,t) h(r′,η)⟩ = Σ_φ ⟨a²⟩ φ(r)φ(r′) [e^{−λ(η−t)} − e^{−λ(η+t)}]
//!   ([`Membrane::correlation`]); stationary: Σ_φ ⟨a²⟩ φ(r)φ(r′) e^{−λ|η−t|}
//!   ([`Membrane::stationary_correlation`]);
//! - (M5) point variance ⟨h²(r)⟩ = Σ_φ ⟨a²⟩ φ(r)² (mode sum
//!   [`Membrane::point_variance_series`]; fast single-series form
//!   [`Membrane::point_variance`], derived in `levy.rs`; far above κq_min² or on a long
//!   strip the proper-time integral [`Membrane::point_variance_proper_time`], derived in
//!   `heat.rs`);
//! - (M6) excess area ΔA = ½∫|∇h|² = Σ_φ ½q²‖φ‖² a², with ⟨ΔA⟩ = (kT/2) Σ_φ 1/(κq² + σ)
//!   and Var ΔA = (kT)²/2 · Σ_φ (κq² + σ)⁻² ([`Membrane::excess_area`]);
//! - (M7) per-mode spectra: the Lorentzian and the exact sampled (AR(1)) spectrum, as for
//!   the filament ([`Membrane::lorentzian`], [`Membrane::sampled_spectrum`]).
//!
//! Truncated sums come with rigorous bounds on the omitted tail ([`super::SeriesValue`]),
//! derived from an integral over the lattice cells outside the truncation radius (see
//! `sums.rs`).
//!
//! ## References
//! - W. Helfrich, Z. Naturforsch. 28c, 693 (1973) (the energy); W. Helfrich and
//!   R.-M. Servuss, Nuovo Cimento D 3, 137 (1984) (excess area, its logarithmic growth).
//! - S. Timoshenko and S. Woinowsky-Krieger, *Theory of Plates and Shells*, 2nd ed. (1959),
//!   §§ 28–30 (Navier and Lévy series of the simply supported plate, the centre deflection
//!   under a central point load, 0.01160·Pa²/D for a square).

mod heat;
mod levy;
pub mod simulator;
mod sums;

pub use levy::{PROPER_TIME_ASPECT_RATIO, PROPER_TIME_TENSION_RATIO};
pub use simulator::MembraneSimulator;
pub use sums::ExcessArea;

use super::{ou_lorentzian, ou_sampled_spectrum, sin_pi};
use crate::error::{Error, Result, require_positive};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Largest number of real modes (or single-series terms) summed by one call, and so the
/// largest cutoff accepted (see [`Membrane::max_cutoff`]): about 0.3 s of one core.
pub const MAX_MEMBRANE_MODES: usize = 10_000_000;

/// Largest number of modes listed by [`Membrane::modes`] and [`Membrane::modes_within`].
pub const MAX_LISTED_MODES: usize = 1_000_000;

/// Largest aspect ratio max(a, b)/min(a, b) accepted: the lattice sums tabulate one value
/// per index along each side, up to about √(4·[`MAX_MEMBRANE_MODES`]·aspect/π) of them,
/// which this keeps below 4·10⁶ (a membrane thinner than that is a filament).
pub const MAX_ASPECT_RATIO: f64 = 1.0e6;

/// The boundary conditions of the rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MembraneBoundary {
    /// h = ∇²h = 0 on every edge: modes sin(mπx/a) sin(nπy/b), m, n ≥ 1.
    SimplySupported,
    /// Periodic in x and y: modes cos(q·r), sin(q·r), q = 2π(m/a, n/b) ≠ 0.
    Periodic,
}

impl MembraneBoundary {
    /// The kebab-case name (`simply-supported`, `periodic`).
    pub fn name(self) -> &'static str {
        match self {
            MembraneBoundary::SimplySupported => "simply-supported",
            MembraneBoundary::Periodic => "periodic",
        }
    }
}

/// Physical parameters of the membrane of (M1), in any consistent units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MembraneParams {
    /// Bending rigidity κ (energy).
    pub bending_rigidity: f64,
    /// Tension σ (energy per area); negative values down to (excluded) the buckling
    /// tension −κ q_min² are allowed.
    pub tension: f64,
    /// Friction ξ per unit area (force·time per length³).
    pub drag: f64,
    /// Thermal energy k_B T.
    pub kt: f64,
    /// Side a along x.
    pub width: f64,
    /// Side b along y.
    pub height: f64,
    /// Boundary conditions.
    pub boundary: MembraneBoundary,
}

impl Default for MembraneParams {
    /// κ = ξ = kT = a = b = 1, σ = 0, simply supported.
    fn default() -> Self {
        MembraneParams {
            bending_rigidity: 1.0,
            tension: 0.0,
            drag: 1.0,
            kt: 1.0,
            width: 1.0,
            height: 1.0,
            boundary: MembraneBoundary::SimplySupported,
        }
    }
}

impl MembraneParams {
    /// Checks κ, ξ, kT, a, b finite and > 0, the aspect ratio at most
    /// [`MAX_ASPECT_RATIO`], and σ finite and above the buckling tension.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first offending field (`bending_rigidity`,
    /// `drag`, `kt`, `width`, `height`, `tension`), its value and the allowed range; for
    /// `tension` the range states the buckling tension −κ q_min² of this geometry.
    pub fn validate(&self) -> Result<()> {
        require_positive("bending_rigidity", self.bending_rigidity)?;
        require_positive("drag", self.drag)?;
        require_positive("kt", self.kt)?;
        require_positive("width", self.width)?;
        require_positive("height", self.height)?;
        let (lo, hi) = (self.width / MAX_ASPECT_RATIO, self.width * MAX_ASPECT_RATIO);
        if !(lo..=hi).contains(&self.height) {
            return Err(Error::invalid(
                "height",
                self.height,
                format!(
                    "in [{lo:e}, {hi:e}] (an aspect ratio of at most {MAX_ASPECT_RATIO:e} with \
                     width {:e})",
                    self.width
                ),
            ));
        }
        self.validate_scales()?;
        let buckling = self.buckling_tension();
        if !(self.tension.is_finite() && self.tension > buckling && buckling.is_finite()) {
            return Err(Error::invalid(
                "tension",
                self.tension,
                format!(
                    "finite and > {buckling:e}, the buckling tension -κ·q_min² of this {} \
                     {:e} × {:e} membrane (q_min² = {:e}); at or below it the slowest mode \
                     has no restoring force",
                    self.boundary.name(),
                    self.width,
                    self.height,
                    self.min_wavenumber_sq()
                ),
            ));
        }
        Ok(())
    }

    /// The scales every reference multiplies: the area ab and q_min² (named by `width`,
    /// the sides' scale) and the slowest mode's bending stiffness κq_min⁴ (named by
    /// `bending_rigidity`) must be normal, finite numbers in f64, or the buckling tension,
    /// τ₁ and the mode sums overflow or vanish.
    fn validate_scales(&self) -> Result<()> {
        let q2 = self.min_wavenumber_sq();
        if !(self.area().is_normal() && q2.is_normal()) {
            return Err(Error::invalid(
                "width",
                self.width,
                format!(
                    "such that the area ab and q_min² are finite and nonzero in f64 (here {:e} and {q2:e} with height {:e}): sides in about [1e-100, 1e100]",
                    self.area(),
                    self.height
                ),
            ));
        }
        let stiffness = self.bending_rigidity * q2 * q2;
        if !(stiffness.is_normal() && (self.bending_rigidity * q2).is_normal()) {
            // κq² and κq⁴ both normal: the smaller power sets the floor, the larger
            // the ceiling.
            let (small, large) = (q2.min(q2 * q2), q2.max(q2 * q2));
            let (lo, hi) = (f64::MIN_POSITIVE / small, f64::MAX / large);
            return Err(Error::invalid(
                "bending_rigidity",
                self.bending_rigidity,
                format!(
                    "such that the slowest mode's bending stiffness κ·q_min⁴ is finite and nonzero in f64 (here {stiffness:e}, q_min² = {q2:e}): about [{lo:e}, {hi:e}]"
                ),
            ));
        }
        Ok(())
    }

    /// Area A = ab.
    pub fn area(&self) -> f64 {
        self.width * self.height
    }

    /// q_min², the smallest squared wavenumber of the geometry: π²(1/a² + 1/b²) simply
    /// supported, (2π/max(a, b))² periodic (q = 0 excluded).
    pub fn min_wavenumber_sq(&self) -> f64 {
        match self.boundary {
            MembraneBoundary::SimplySupported => {
                let (u, v) = (PI / self.width, PI / self.height);
                u * u + v * v
            }
            MembraneBoundary::Periodic => {
                let u = 2.0 * PI / self.width.max(self.height);
                u * u
            }
        }
    }

    /// The slowest relaxation time 1/λ = ξ/c_q of the slowest mode ([`Membrane::modes`],
    /// c_q = κq⁴ + σq², (M2)): the membrane's time unit τ₁. NaN for parameters
    /// [`MembraneParams::validate`] refuses.
    pub fn tau1(&self) -> f64 {
        Membrane::new(*self)
            .and_then(|m| Ok((m, m.modes(1)?)))
            .map_or(f64::NAN, |(m, slowest)| self.drag / m.stiffness(slowest[0]))
    }

    /// The buckling tension −κ q_min²: the tension must be strictly above it.
    pub fn buckling_tension(&self) -> f64 {
        -self.bending_rigidity * self.min_wavenumber_sq()
    }

    /// The tension ratio σ/(κ q_min²): −1 at buckling, ≫ 1 where the tension dominates.
    pub fn tension_ratio(&self) -> f64 {
        self.tension / (self.bending_rigidity * self.min_wavenumber_sq())
    }
}

/// Which real mode of a lattice point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModeShape {
    /// sin(mπx/a) sin(nπy/b) (simply supported).
    SineSine,
    /// cos(q·r), q = 2π(m/a, n/b) (periodic).
    Cosine,
    /// sin(q·r), q = 2π(m/a, n/b) (periodic).
    Sine,
}

/// One real mode: lattice indices and shape. Simply supported: m, n ≥ 1 and
/// [`ModeShape::SineSine`]; periodic: (m, n) in the half-lattice H (m > 0, or m = 0 and
/// n > 0) and [`ModeShape::Cosine`] or [`ModeShape::Sine`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct MembraneMode {
    /// Index along x.
    pub m: i64,
    /// Index along y.
    pub n: i64,
    /// Which real mode of the lattice point.
    pub shape: ModeShape,
}

/// The membrane of (M1): exact modal results.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Membrane {
    /// Physical parameters (validated).
    pub params: MembraneParams,
}

impl Membrane {
    /// A membrane with validated parameters.
    ///
    /// # Errors
    /// As [`MembraneParams::validate`].
    pub fn new(params: MembraneParams) -> Result<Self> {
        params.validate()?;
        Ok(Membrane { params })
    }

    /// Whether `mode` is a real mode of this geometry (see [`MembraneMode`]).
    pub fn is_mode(&self, mode: MembraneMode) -> bool {
        let MembraneMode { m, n, shape } = mode;
        match self.params.boundary {
            MembraneBoundary::SimplySupported => m >= 1 && n >= 1 && shape == ModeShape::SineSine,
            MembraneBoundary::Periodic => {
                (m > 0 || (m == 0 && n > 0)) && shape != ModeShape::SineSine
            }
        }
    }

    /// Lattice spacings (Δq_x, Δq_y): (π/a, π/b) simply supported, (2π/a, 2π/b) periodic.
    pub(crate) fn spacing(&self) -> (f64, f64) {
        let f = match self.params.boundary {
            MembraneBoundary::SimplySupported => PI,
            MembraneBoundary::Periodic => 2.0 * PI,
        };
        (f / self.params.width, f / self.params.height)
    }

    /// Wavevector q = (Δq_x·m, Δq_y·n) of `mode` (NaN if it is not a mode).
    pub fn wavevector(&self, mode: MembraneMode) -> [f64; 2] {
        if !self.is_mode(mode) {
            return [f64::NAN; 2];
        }
        let (kx, ky) = self.spacing();
        [kx * mode.m as f64, ky * mode.n as f64]
    }

    /// |q|² of `mode` (NaN if it is not a mode).
    pub fn wavenumber_sq(&self, mode: MembraneMode) -> f64 {
        let [qx, qy] = self.wavevector(mode);
        qx * qx + qy * qy
    }

    /// c_q = κq⁴ + σq² at a squared wavenumber q².
    pub(crate) fn c_of_q2(&self, q2: f64) -> f64 {
        (self.params.bending_rigidity * q2 + self.params.tension) * q2
    }

    /// c_q = κq⁴ + σq² of `mode`, the energy per unit area per squared amplitude of (M1)
    /// (NaN if it is not a mode); > 0 for every mode above the buckling tension.
    pub fn stiffness(&self, mode: MembraneMode) -> f64 {
        self.c_of_q2(self.wavenumber_sq(mode))
    }

    /// The bending share s_q = ∂ln c_q/∂ln κ = κq⁴/(κq⁴ + σq²) of `mode`'s stiffness
    /// (M1) at fixed σ: 1 at σ = 0, below 1 under tension, above 1 under compression
    /// (NaN if it is not a mode). The regressor of `fit`'s κ under a tension held known.
    pub fn bending_share(&self, mode: MembraneMode) -> f64 {
        let q2 = self.wavenumber_sq(mode);
        let bending = self.params.bending_rigidity * q2 * q2;
        bending / (bending + self.params.tension * q2)
    }

    /// The tension sensitivity u_q = ∂ln c_q/∂σ = q²/(κq⁴ + σq²) of `mode`'s stiffness
    /// (M1) at fixed κ (NaN if it is not a mode). With [`Self::bending_share`], the
    /// regressors of `fit`'s joint κ and σ.
    pub fn tension_sensitivity(&self, mode: MembraneMode) -> f64 {
        let q2 = self.wavenumber_sq(mode);
        q2 / self.c_of_q2(q2)
    }

    /// Relaxation rate λ_q = c_q/ξ of `mode` (M2) (NaN if it is not a mode).
    pub fn mode_rate(&self, mode: MembraneMode) -> f64 {
        self.stiffness(mode) / self.params.drag
    }

    /// ‖φ‖² = ∫φ² d²r of a real mode: A/4 simply supported, A/2 periodic.
    pub fn mode_norm_sq(&self) -> f64 {
        match self.params.boundary {
            MembraneBoundary::SimplySupported => self.params.area() / 4.0,
            MembraneBoundary::Periodic => self.params.area() / 2.0,
        }
    }

    /// Stationary variance of the real amplitude of `mode`, (M3): kT/(c_q‖φ‖²), i.e.
    /// 4kT/(A c_q) simply supported and 2kT/(A c_q) periodic (NaN if it is not a mode).
    pub fn mode_variance(&self, mode: MembraneMode) -> f64 {
        self.params.kt / (self.stiffness(mode) * self.mode_norm_sq())
    }

    /// ⟨|h_q|²⟩ = kT/(A c_q) of the complex amplitude h_q = A⁻¹∫h e^{−iq·r} d²r of the
    /// periodic membrane, q = 2π(m/a, n/b), for any (m, n) ≠ (0, 0) (see the module docs
    /// for other conventions). NaN for (0, 0) and for a simply supported membrane, which
    /// has no complex Fourier amplitudes.
    pub fn fourier_variance(&self, m: i64, n: i64) -> f64 {
        if self.params.boundary != MembraneBoundary::Periodic || (m == 0 && n == 0) {
            return f64::NAN;
        }
        let (kx, ky) = self.spacing();
        let (qx, qy) = (kx * m as f64, ky * n as f64);
        self.params.kt / (self.params.area() * self.c_of_q2(qx * qx + qy * qy))
    }

    /// Variance of the slowest real mode, the scale of the relative tolerances of the
    /// mode sums (4kT/(A c_{q_min}) simply supported, 2kT/(A c_{q_min}) periodic).
    pub fn variance_scale(&self) -> f64 {
        let c = self.c_of_q2(self.params.min_wavenumber_sq());
        self.params.kt / (c * self.mode_norm_sq())
    }

    /// Stationary autocovariance ⟨a(t) a(t+lag)⟩ = ⟨a²⟩ e^{−λ|lag|} of `mode`.
    pub fn mode_autocovariance(&self, mode: MembraneMode, lag: f64) -> f64 {
        self.mode_variance(mode) * (-self.mode_rate(mode) * lag.abs()).exp()
    }

    /// Mode shape φ(x, y): sin(mπx/a) sin(nπy/b), cos(q·r) or sin(q·r) (NaN if `mode` is
    /// not a mode or (x, y) is outside the rectangle). Simply supported shapes are exactly
    /// 0 on the edges.
    pub fn mode_shape(&self, mode: MembraneMode, x: f64, y: f64) -> f64 {
        if !self.is_mode(mode) || !self.in_rect(x, y) {
            return f64::NAN;
        }
        let (u, v) = (x / self.params.width, y / self.params.height);
        let (m, n) = (mode.m as f64, mode.n as f64);
        match mode.shape {
            ModeShape::SineSine => sin_pi(m * u) * sin_pi(n * v),
            // 2π(mu + nv): phases of each index reduced exactly modulo 1 first.
            ModeShape::Cosine => cos_pi(2.0 * (frac(m * u) + frac(n * v))),
            ModeShape::Sine => sin_pi(2.0 * (frac(m * u) + frac(n * v))),
        }
    }

    /// One-sided Lorentzian power spectral density of the stationary amplitude of `mode`,
    /// (M7): S(f) = 4⟨a²⟩λ/(λ² + (2πf)²), ∫₀^∞ S df = ⟨a²⟩ (as
    /// [`super::HingedBeam::lorentzian`]).
    pub fn lorentzian(&self, mode: MembraneMode, f: f64) -> f64 {
        ou_lorentzian(self.mode_variance(mode), self.mode_rate(mode), f)
    }

    /// Exact one-sided spectral density of the amplitude of `mode` sampled every `dt`
    /// (an AR(1) sequence, aliasing included), 0 ≤ f ≤ 1/(2dt), (M7):
    /// S(f) = 2dt⟨a²⟩(1−ρ²)/(1 − 2ρcos(2πf dt) + ρ²), ρ = e^{−λdt}
    /// (as [`super::HingedBeam::sampled_spectrum`]; NaN if dt is not finite and > 0).
    pub fn sampled_spectrum(&self, mode: MembraneMode, dt: f64, f: f64) -> f64 {
        ou_sampled_spectrum(self.mode_variance(mode), self.mode_rate(mode), dt, f)
    }

    /// Largest cutoff Q accepted by the mode sums: the one whose rigorous mode-count bound
    /// ([`Membrane::mode_count_bound`]) is [`MAX_MEMBRANE_MODES`].
    pub fn max_cutoff(&self) -> f64 {
        self.cutoff_for_count(MAX_MEMBRANE_MODES as f64)
    }

    /// Rigorous upper bound on the number of real modes with |q| ≤ Q: each lattice point
    /// owns the lattice cell between it and the origin, which lies inside the disc of
    /// radius Q, so there are at most (πQ²/4)/Δ of them per quadrant (Δ the cell area):
    /// AQ²/(4π) in all, plus, periodic, the (a + b)Q/π points on the axes.
    pub fn mode_count_bound(&self, cutoff: f64) -> f64 {
        let p = &self.params;
        let bulk = p.area() * cutoff * cutoff / (4.0 * PI);
        match p.boundary {
            MembraneBoundary::SimplySupported => bulk,
            MembraneBoundary::Periodic => bulk + (p.width + p.height) * cutoff / PI,
        }
    }

    /// The Q at which [`Membrane::mode_count_bound`] equals `count`.
    pub(crate) fn cutoff_for_count(&self, count: f64) -> f64 {
        let p = &self.params;
        let c2 = p.area() / (4.0 * PI);
        match p.boundary {
            MembraneBoundary::SimplySupported => (count / c2).sqrt(),
            MembraneBoundary::Periodic => {
                let c1 = (p.width + p.height) / PI;
                // Positive root of c2 Q² + c1 Q − count, without cancellation.
                2.0 * count / (c1 + (c1 * c1 + 4.0 * c2 * count).sqrt())
            }
        }
    }

    /// Checks a cutoff: finite, > 0 and at most [`Membrane::max_cutoff`].
    pub(crate) fn check_cutoff(&self, name: &str, cutoff: f64, max_modes: usize) -> Result<()> {
        let max = self.cutoff_for_count(max_modes as f64);
        if cutoff.is_finite() && cutoff > 0.0 && cutoff <= max {
            Ok(())
        } else {
            Err(Error::invalid(
                name,
                cutoff,
                format!("finite, > 0 and <= {max:e} (at most {max_modes} modes)"),
            ))
        }
    }

    /// The real modes with |q| ≤ `cutoff`, slowest first (sorted by |q|², which orders the
    /// rates since c_q increases with q² above q_min; ties broken by (m, n, shape)).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `cutoff` if it is not finite and > 0 or could
    /// hold more than [`MAX_LISTED_MODES`] modes.
    pub fn modes_within(&self, cutoff: f64) -> Result<Vec<MembraneMode>> {
        self.check_cutoff("cutoff", cutoff, MAX_LISTED_MODES)?;
        let mut list: Vec<(f64, MembraneMode)> = Vec::new();
        self.visit_lattice(cutoff, |m, n, q2| {
            let shapes: &[ModeShape] = match self.params.boundary {
                MembraneBoundary::SimplySupported => &[ModeShape::SineSine],
                MembraneBoundary::Periodic => &[ModeShape::Cosine, ModeShape::Sine],
            };
            for &shape in shapes {
                list.push((q2, MembraneMode { m, n, shape }));
            }
        });
        list.sort_by(|(qa, a), (qb, b)| {
            qa.total_cmp(qb)
                .then((a.m, a.n, a.shape).cmp(&(b.m, b.n, b.shape)))
        });
        Ok(list.into_iter().map(|(_, mode)| mode).collect())
    }

    /// The `count` slowest real modes, slowest first (as [`Membrane::modes_within`]).
    ///
    /// The search radius Q = d + √(4π·count/A) (d the diagonal of a lattice cell) holds at
    /// least `count` modes: the cells of the points with |q| ≤ Q cover the disc of radius
    /// Q − d (per quadrant), whose area is count·Δ.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `count` if it is 0 or above [`MAX_LISTED_MODES`].
    pub fn modes(&self, count: usize) -> Result<Vec<MembraneMode>> {
        if count == 0 || count > MAX_LISTED_MODES {
            return Err(Error::invalid(
                "count",
                count,
                format!("in [1, {MAX_LISTED_MODES}]"),
            ));
        }
        let radius = self.cell_diagonal() + (4.0 * PI * count as f64 / self.params.area()).sqrt();
        let mut list = Vec::new();
        self.visit_lattice(radius, |m, n, q2| list.push((q2, m, n)));
        list.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        let shapes: &[ModeShape] = match self.params.boundary {
            MembraneBoundary::SimplySupported => &[ModeShape::SineSine],
            MembraneBoundary::Periodic => &[ModeShape::Cosine, ModeShape::Sine],
        };
        let mut modes: Vec<MembraneMode> = list
            .iter()
            .flat_map(|&(_, m, n)| {
                shapes
                    .iter()
                    .map(move |&shape| MembraneMode { m, n, shape })
            })
            .collect();
        modes.truncate(count);
        Ok(modes)
    }

    /// Diagonal d = √(Δq_x² + Δq_y²) of a lattice cell.
    pub(crate) fn cell_diagonal(&self) -> f64 {
        let (kx, ky) = self.spacing();
        kx.hypot(ky)
    }

    pub(crate) fn in_rect(&self, x: f64, y: f64) -> bool {
        x.is_finite()
            && y.is_finite()
            && (0.0..=self.params.width).contains(&x)
            && (0.0..=self.params.height).contains(&y)
    }

    /// Checks that (x, y) lies in the rectangle, naming `x_name` or `y_name`.
    pub(crate) fn check_point(&self, x_name: &str, y_name: &str, r: (f64, f64)) -> Result<()> {
        crate::error::require_in_range(x_name, r.0, 0.0, self.params.width)?;
        crate::error::require_in_range(y_name, r.1, 0.0, self.params.height)
    }
}

/// cos(π s), exact at multiples of ½ (via [`sin_pi`]).
pub(crate) fn cos_pi(s: f64) -> f64 {
    sin_pi(s.abs() + 0.5)
}

/// s − ⌊s⌋ (exact in floating point).
pub(crate) fn frac(s: f64) -> f64 {
    s - s.floor()
}

/// A 1 × 0.7 membrane of the default κ, ξ, kT with `boundary` and `tension`, for the
/// module's tests.
#[cfg(test)]
pub(crate) fn test_membrane(boundary: MembraneBoundary, tension: f64) -> Membrane {
    Membrane::new(MembraneParams {
        boundary,
        tension,
        width: 1.0,
        height: 0.7,
        ..MembraneParams::default()
    })
    .unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn membrane(boundary: MembraneBoundary) -> Membrane {
        Membrane::new(MembraneParams {
            bending_rigidity: 0.8,
            tension: 0.3,
            drag: 2.5,
            kt: 1.3,
            width: 1.7,
            height: 1.1,
            boundary,
        })
        .unwrap()
    }

    // What: the bending share s_q = ∂ln c_q/∂ln κ at fixed σ, and the tension
    // sensitivity u_q = ∂ln c_q/∂σ at fixed κ.
    // Reference: central differences of ln c_q in ln κ and in σ (step 1e-4; c_q is linear in κ, so
    // the difference is exact up to rounding and the O(step²) curvature of ln c_q);
    // exactly 1 at σ = 0; above 1 under compression. Tolerance: 1e-7.
    #[test]
    fn bending_share_and_tension_sensitivity_are_log_derivatives() {
        for b in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let mb = membrane(b);
            assert!(mb.params.tension > 0.0);
            let at = |kappa: f64, tension: f64| {
                Membrane::new(MembraneParams {
                    bending_rigidity: kappa,
                    tension,
                    ..mb.params
                })
                .unwrap()
            };
            let (k, h) = (mb.params.bending_rigidity, 1e-4_f64);
            for mode in mb.modes(20).unwrap() {
                let c = |kappa: f64| at(kappa, mb.params.tension).stiffness(mode).ln();
                let fd = (c(k * h.exp()) - c(k * (-h).exp())) / (2.0 * h);
                let s = mb.bending_share(mode);
                assert!((s - fd).abs() < 1e-7, "{mode:?}: {s} vs {fd}");
                let sigma = mb.params.tension;
                let c = |tension: f64| at(k, tension).stiffness(mode).ln();
                let fd = (c(sigma + h) - c(sigma - h)) / (2.0 * h);
                let u = mb.tension_sensitivity(mode);
                assert!((u / fd - 1.0).abs() < 1e-6, "{mode:?}: {u} vs {fd}");
                assert!(s > 0.0 && s < 1.0);
                assert_eq!(at(k, 0.0).bending_share(mode), 1.0);
                let q2 = mb.params.min_wavenumber_sq();
                assert!(at(k, -0.5 * k * q2).bending_share(mode) > 1.0);
            }
        }
    }

    // What: (M2)–(M3): rate c_q/ξ; variance kT/(c_q‖φ‖²) with ‖φ‖² = A/4 or A/2; the
    // fluctuation–dissipation product λ⟨a²⟩ = kT/(ξ‖φ‖²); ⟨A_q²⟩ = 2⟨|h_q|²⟩ (periodic).
    // Reference: the derivations in the module docs. Tolerance: 1e-14 relative (rounding).
    #[test]
    fn mode_rate_variance_and_conventions() {
        for b in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let mb = membrane(b);
            let p = mb.params;
            for mode in mb.modes(20).unwrap() {
                let [qx, qy] = mb.wavevector(mode);
                let q2 = qx * qx + qy * qy;
                let c = p.bending_rigidity * q2 * q2 + p.tension * q2;
                assert!((mb.stiffness(mode) / c - 1.0).abs() < 1e-14);
                assert!((mb.mode_rate(mode) * p.drag / c - 1.0).abs() < 1e-14);
                let norm = match b {
                    MembraneBoundary::SimplySupported => p.area() / 4.0,
                    MembraneBoundary::Periodic => p.area() / 2.0,
                };
                assert!((mb.mode_variance(mode) * c * norm / p.kt - 1.0).abs() < 1e-14);
                let fd = mb.mode_rate(mode) * mb.mode_variance(mode) * p.drag * norm / p.kt;
                assert!((fd - 1.0).abs() < 1e-14);
                if b == MembraneBoundary::Periodic {
                    let fv = mb.fourier_variance(mode.m, mode.n);
                    assert!((mb.mode_variance(mode) / (2.0 * fv) - 1.0).abs() < 1e-14);
                    assert_eq!(fv, mb.fourier_variance(-mode.m, -mode.n));
                }
            }
            let slowest = mb.modes(1).unwrap()[0];
            assert!((mb.variance_scale() / mb.mode_variance(slowest) - 1.0).abs() < 1e-14);
        }
        let ss = membrane(MembraneBoundary::SimplySupported);
        assert!(ss.fourier_variance(1, 1).is_nan());
        assert!(
            membrane(MembraneBoundary::Periodic)
                .fourier_variance(0, 0)
                .is_nan()
        );
    }

    // What: modes(k) lists the k slowest modes in rate order, equal to the head of
    // modes_within(Q) for a Q holding them, and only valid modes. Reference: brute force.
    #[test]
    fn mode_enumeration_is_sorted_and_complete() {
        for b in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let mb = membrane(b);
            let list = mb.modes(200).unwrap();
            assert_eq!(list.len(), 200);
            assert!(list.iter().all(|&m| mb.is_mode(m)));
            assert!(
                list.windows(2)
                    .all(|w| mb.mode_rate(w[0]) <= mb.mode_rate(w[1]))
            );
            let q_last = mb.wavenumber_sq(list[199]).sqrt();
            let within = mb.modes_within(q_last * 1.5).unwrap();
            assert_eq!(&within[..200], &list[..]);
            // Brute force over a box: every mode with |q| ≤ q_last·1.5 is listed.
            let count = (-60..=60i64)
                .flat_map(|m| (-60..=60i64).map(move |n| (m, n)))
                .flat_map(|(m, n)| {
                    [ModeShape::SineSine, ModeShape::Cosine, ModeShape::Sine]
                        .map(|shape| MembraneMode { m, n, shape })
                })
                .filter(|&md| mb.is_mode(md) && mb.wavenumber_sq(md) <= (q_last * 1.5).powi(2))
                .count();
            assert_eq!(count, within.len());
            assert!((within.len() as f64) <= mb.mode_count_bound(q_last * 1.5));
        }
    }

    // What: mode shapes: exact zeros on simply supported edges; periodic cos/sin of q·r;
    // NaN outside the rectangle or for a non-mode.
    #[test]
    fn mode_shapes() {
        let ss = membrane(MembraneBoundary::SimplySupported);
        let mode = MembraneMode {
            m: 3,
            n: 2,
            shape: ModeShape::SineSine,
        };
        for t in [0.0, 0.3, 1.1] {
            assert_eq!(ss.mode_shape(mode, 0.0, t), 0.0);
            assert_eq!(ss.mode_shape(mode, 1.7, t), 0.0);
            assert_eq!(ss.mode_shape(mode, t, 1.1), 0.0);
        }
        let (x, y) = (0.4, 0.7);
        let direct = (3.0 * PI * x / 1.7).sin() * (2.0 * PI * y / 1.1).sin();
        assert!((ss.mode_shape(mode, x, y) - direct).abs() < 1e-14);
        assert!(ss.mode_shape(mode, -0.1, 0.5).is_nan());
        assert!(ss.mode_shape(mode, 0.5, f64::NAN).is_nan());
        let bad = MembraneMode {
            m: 0,
            n: 2,
            shape: ModeShape::SineSine,
        };
        assert!(ss.mode_shape(bad, 0.5, 0.5).is_nan());
        assert!(ss.mode_variance(bad).is_nan());

        let pe = membrane(MembraneBoundary::Periodic);
        for (m, n) in [(1i64, -2i64), (0, 3), (2, 0)] {
            let theta = 2.0 * PI * (m as f64 * x / 1.7 + n as f64 * y / 1.1);
            let c = MembraneMode {
                m,
                n,
                shape: ModeShape::Cosine,
            };
            let s = MembraneMode {
                shape: ModeShape::Sine,
                ..c
            };
            assert!((pe.mode_shape(c, x, y) - theta.cos()).abs() < 1e-14);
            assert!((pe.mode_shape(s, x, y) - theta.sin()).abs() < 1e-14);
        }
        let not_half = MembraneMode {
            m: -1,
            n: 2,
            shape: ModeShape::Cosine,
        };
        assert!(!pe.is_mode(not_half));
        assert!(pe.wavevector(not_half)[0].is_nan());
    }

    // What: validate() names each parameter and refuses σ at and below the buckling tension
    // −κq_min², accepting it just above. Reference: q_min² of each geometry.
    #[test]
    fn validation_names_parameters_and_buckling() {
        for b in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let good = membrane(b).params;
            let q2 = match b {
                MembraneBoundary::SimplySupported => PI * PI * (1.0 / 1.7f64.powi(2) + 1.0 / 1.21),
                MembraneBoundary::Periodic => (2.0 * PI / 1.7).powi(2),
            };
            assert!((good.min_wavenumber_sq() / q2 - 1.0).abs() < 1e-14);
            let crit = good.buckling_tension();
            for sigma in [crit, crit * 1.01, f64::NAN, f64::NEG_INFINITY] {
                let p = MembraneParams {
                    tension: sigma,
                    ..good
                };
                match p.validate() {
                    Err(Error::InvalidParameter { name, allowed, .. }) => {
                        assert_eq!(name, "tension");
                        assert!(allowed.contains(&format!("{crit:e}")), "{allowed}");
                    }
                    other => panic!("sigma = {sigma}: {other:?}"),
                }
            }
            let near = MembraneParams {
                tension: crit * 0.999,
                ..good
            };
            assert!(Membrane::new(near).is_ok());
            for height in [1.7e-7, 1.7e7] {
                let thin = MembraneParams { height, ..good };
                match thin.validate() {
                    Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, "height"),
                    other => panic!("height {height}: {other:?}"),
                }
            }
            let extreme = MembraneParams {
                height: 1.7e6,
                tension: 0.0,
                ..good
            };
            let mb = Membrane::new(extreme).unwrap();
            assert!(mb.modes(3).unwrap().len() == 3);
            assert!(mb.excess_area(mb.max_cutoff()).unwrap().n_modes <= MAX_MEMBRANE_MODES);
            type Setter = fn(&mut MembraneParams, f64);
            let setters: [(&str, Setter); 5] = [
                ("bending_rigidity", |p, v| p.bending_rigidity = v),
                ("drag", |p, v| p.drag = v),
                ("kt", |p, v| p.kt = v),
                ("width", |p, v| p.width = v),
                ("height", |p, v| p.height = v),
            ];
            for (name, set) in setters {
                for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
                    let mut p = good;
                    set(&mut p, v);
                    match p.validate() {
                        Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                        other => panic!("{name} = {v}: {other:?}"),
                    }
                }
            }
        }
    }
}
