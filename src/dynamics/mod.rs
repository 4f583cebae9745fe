//! Time integration of the semi-discrete stochastic beam equation
//!
//! ```text
//! C ẇ = −K w + F(t),   ⟨F(t) F(t')ᵀ⟩ = 2kT Σ_ζ δ(t − t')
//! ```
//!
//! (the finite-element form of eq. 2 with the noise of eq. 1 or eq. 5). Over a step Δt the
//! nodal force is `F = sqrt(2kT/Δt) ζ` with `ζ` drawn by a
//! [`NoiseGenerator`](crate::fem::noise::NoiseGenerator).
//!
//! Every integrator here is linear and, in the generalized eigenbasis of (K, C)
//! (`K φ_i = λ_i C φ_i`, `ΦᵀCΦ = I`), diagonal: modal amplitude `q_i = φ_iᵀ C w` obeys
//!
//! ```text
//! q_{k+1,i} = m_i q_{k,i} + g_i (Φᵀ ζ_k)_i
//! ```
//!
//! with a per-mode multiplier `m_i` and gain `g_i` ([`IntegratorKind::modal_form`]). The
//! exact discrete stationary covariance of any of them follows
//! ([`crate::fem::modal::discrete_stationary_covariance`]).
//!
//! | integrator | m(a), a = λΔt | stationary variance / (kT/λ), consistent noise |
//! |---|---|---|
//! | `euler-maruyama` (θ = 0, the paper's step iii) | 1 − a | 1/(1 − a/2), stable for a < 2 |
//! | `backward-euler` (θ = 1) | 1/(1 + a) | 1/(1 + a/2) |
//! | `crank-nicolson` (θ = ½) | (1 − a/2)/(1 + a/2) | 1 (exact for any Δt) |
//! | `exact-modal` (OU transition per mode) | e^{−a} | 1 (exact for any Δt) |
//!
//! The θ-schemes cost one banded solve per step (O(n)); `exact-modal` uses dense modal
//! transforms (O(n²)) but is exact in distribution for the linear problem at any Δt.
//!
//! The nonlinear (von Kármán) filament has its own schemes ([`nonlinear`]); on a uniform
//! hinged mesh `metropolis-crank-nicolson` runs in the paired modal form
//! ([`modal_metropolis`], O(n) per step with 2×2 solves).

pub mod batch;
pub mod discrete;
pub mod driver;
pub mod ensemble;
pub(crate) mod integrator;
pub mod modal_metropolis;
pub mod modal_step;
pub mod nonlinear;

pub use batch::{BatchTrajectory, ComponentBatch, LaneOf, ThetaBatch};
pub use discrete::{DiscreteLaw, ModeLaw};
pub use driver::{Components, Driver, NonlinearState, Observer, Trajectory};
pub use ensemble::par_indexed;
pub use integrator::{ExactModal, Integrator, ThetaScheme, build_integrator};
pub use modal_metropolis::{ModalMetropolis, Proposal};
pub use modal_step::ModalStep;
pub use nonlinear::{NonlinearBatch, NonlinearIntegrator, NonlinearStep};

use crate::error::Error;
use serde::{Deserialize, Serialize};

/// The time integrators, for the linear and the nonlinear filament.
///
/// Every fact about an integrator is a method here, each an exhaustive `match` (no
/// catch-all arm), so that a new variant is a compile error until every fact is decided:
/// [`name`](Self::name), [`family`](Self::family), [`needs_modes`](Self::needs_modes),
/// [`exact_stationary`](Self::exact_stationary), and from the family the discrete-time
/// [`modal_form`](Self::modal_form), [`stationary_variance_ratio`](Self::stationary_variance_ratio)
/// and [`stability_limit`](Self::stability_limit). Names parse with [`std::str::FromStr`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// Explicit Euler–Maruyama, the paper's step (iii): `C w_{k+1} = C w_k − Δt K w_k + Δt F_k`.
    EulerMaruyama,
    /// Backward (semi-implicit) Euler: `(C + Δt K) w_{k+1} = C w_k + Δt F_k`.
    BackwardEuler,
    /// Stochastic trapezoidal rule: `(C + Δt K/2) w_{k+1} = (C − Δt K/2) w_k + Δt F_k`.
    CrankNicolson,
    /// Exact Ornstein–Uhlenbeck transition of every generalized mode.
    ExactModal,
    /// Crank–Nicolson proposal with a Metropolis–Hastings accept/reject step on the exact
    /// Boltzmann weight: the integrator of the nonlinear (finite-deflection) filament whose
    /// stationary law is exact at any Δt ([`nonlinear`]).
    MetropolisCrankNicolson,
}

/// How an integrator steps: the family decides its construction and its discrete-time
/// modal form on the linear problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Family {
    /// θ-scheme `(C + θΔtK) w_{k+1} = (C − (1−θ)ΔtK) w_k + sqrt(2kTΔt) ζ_k` with this θ.
    Theta(f64),
    /// Exact Ornstein–Uhlenbeck transition of every generalized mode of (K, C).
    ExactModal,
    /// Crank–Nicolson proposal with a Metropolis–Hastings accept/reject step.
    Metropolis,
}

impl IntegratorKind {
    /// Every integrator, in a fixed order.
    pub const ALL: [IntegratorKind; 5] = [
        IntegratorKind::EulerMaruyama,
        IntegratorKind::BackwardEuler,
        IntegratorKind::CrankNicolson,
        IntegratorKind::ExactModal,
        IntegratorKind::MetropolisCrankNicolson,
    ];

    /// The integrators of the linear filament, in a fixed order.
    pub const LINEAR: [IntegratorKind; 4] = [
        IntegratorKind::EulerMaruyama,
        IntegratorKind::BackwardEuler,
        IntegratorKind::CrankNicolson,
        IntegratorKind::ExactModal,
    ];

    /// The integrators of the nonlinear (finite-deflection) filament, in a fixed order.
    pub const NONLINEAR: [IntegratorKind; 4] = [
        IntegratorKind::EulerMaruyama,
        IntegratorKind::BackwardEuler,
        IntegratorKind::CrankNicolson,
        IntegratorKind::MetropolisCrankNicolson,
    ];

    /// The names of `kinds` for messages: `"a, b, c or d"` (", " between, " or " before
    /// the last).
    pub fn list(kinds: &[IntegratorKind]) -> String {
        match kinds.split_last() {
            None => String::new(),
            Some((last, [])) => last.name().to_string(),
            Some((last, rest)) => {
                let head: Vec<&str> = rest.iter().map(|k| k.name()).collect();
                format!("{} or {}", head.join(", "), last.name())
            }
        }
    }

    /// The name used in scene files and reports.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::EulerMaruyama => "euler-maruyama",
            IntegratorKind::BackwardEuler => "backward-euler",
            IntegratorKind::CrankNicolson => "crank-nicolson",
            IntegratorKind::ExactModal => "exact-modal",
            IntegratorKind::MetropolisCrankNicolson => "metropolis-crank-nicolson",
        }
    }

    /// The family of the integrator ([`Family`]).
    pub fn family(self) -> Family {
        match self {
            IntegratorKind::EulerMaruyama => Family::Theta(0.0),
            IntegratorKind::BackwardEuler => Family::Theta(1.0),
            IntegratorKind::CrankNicolson => Family::Theta(0.5),
            IntegratorKind::ExactModal => Family::ExactModal,
            IntegratorKind::MetropolisCrankNicolson => Family::Metropolis,
        }
    }

    /// Whether building the integrator needs the generalized modes of (K, C) (a dense
    /// O(n³) eigen-decomposition).
    pub fn needs_modes(self) -> bool {
        match self {
            IntegratorKind::ExactModal => true,
            IntegratorKind::EulerMaruyama
            | IntegratorKind::BackwardEuler
            | IntegratorKind::CrankNicolson
            | IntegratorKind::MetropolisCrankNicolson => false,
        }
    }

    /// Whether the stationary variance of the linear problem is exact (kT/λ per mode under
    /// consistent noise) at any Δt: Crank–Nicolson, the exact modal update and the
    /// Metropolis scheme (whose proposals are all accepted on the linear problem).
    pub fn exact_stationary(self) -> bool {
        match self {
            IntegratorKind::CrankNicolson
            | IntegratorKind::ExactModal
            | IntegratorKind::MetropolisCrankNicolson => true,
            IntegratorKind::EulerMaruyama | IntegratorKind::BackwardEuler => false,
        }
    }

    /// The implicitness θ of the θ-scheme, or `None` for `exact-modal` and the Metropolis
    /// scheme.
    pub fn theta(self) -> Option<f64> {
        match self.family() {
            Family::Theta(theta) => Some(theta),
            Family::ExactModal | Family::Metropolis => None,
        }
    }

    /// Per-mode multiplier `m` and noise gain `g` of one step for a mode of rate `rate`
    /// (λ), so that `q ← m q + g (Φᵀζ)` with `ζ` the noise vector of covariance Σ_ζ.
    ///
    /// θ-scheme: `m = (1 − (1−θ)a)/(1 + θa)`, `g = sqrt(2kTΔt)/(1 + θa)`, a = λΔt.
    /// Exact OU: `m = e^{−a}`, `g = sqrt(kT(1 − e^{−2a})/λ)`, so that the stationary
    /// variance `g²/(1 − m²)` is kT/λ for consistent noise (Σ_q = I). Metropolis: the
    /// Crank–Nicolson form (on the linear problem every proposal is accepted).
    pub fn modal_form(self, rate: f64, dt: f64, kt: f64) -> (f64, f64) {
        let a = rate * dt;
        match self.family() {
            Family::Theta(theta) => {
                let den = 1.0 + theta * a;
                (
                    (1.0 - (1.0 - theta) * a) / den,
                    (2.0 * kt * dt).sqrt() / den,
                )
            }
            Family::Metropolis => {
                // On the linear problem every Crank–Nicolson proposal is accepted.
                IntegratorKind::CrankNicolson.modal_form(rate, dt, kt)
            }
            Family::ExactModal => {
                let m = (-a).exp();
                // 1 − e^{−2a} computed without cancellation for small a.
                let one_minus_m2 = -(-2.0 * a).exp_m1();
                (m, (kt * one_minus_m2 / rate).sqrt())
            }
        }
    }

    /// Stationary variance of a single mode relative to equipartition kT/λ under
    /// consistent noise, `g²λ/((1 − m²)kT)`: for θ-schemes `1/(1 + (θ − ½)a)`, for the
    /// exact update 1. `None` where the step is unstable (|m| ≥ 1).
    pub fn stationary_variance_ratio(self, rate: f64, dt: f64) -> Option<f64> {
        let (m, g) = self.modal_form(rate, dt, 1.0);
        (m.abs() < 1.0).then(|| g * g * rate / (1.0 - m * m))
    }

    /// For Crank–Nicolson, the step above which its multiplier `(1 − a/2)/(1 + a/2)`,
    /// `a = λ_max Δt`, rounds to −1 in f64 (`a` about 2⁵⁵): A-stable in exact arithmetic,
    /// the fastest mode would then never decay and its discrete stationary variance
    /// `g²/(1 − m²)` is 0/0. `None` for every other integrator (explicit ones have
    /// [`Self::stability_limit`]; the others' multipliers tend to 0 or to `(θ − 1)/θ > −1`).
    pub fn rounding_limit(self, max_rate: f64) -> Option<f64> {
        if self != IntegratorKind::CrankNicolson {
            return None;
        }
        // The least a whose multiplier is −1, by bisection (m decreases with a).
        let m = |a: f64| self.modal_form(a, 1.0, 1.0).0;
        let (mut lo, mut hi) = (1.0_f64, 2.0_f64.powi(64));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid == lo || mid == hi {
                break;
            }
            if m(mid) <= -1.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(hi / max_rate)
    }

    /// Largest stable time step for a system whose fastest mode has rate `max_rate`, or
    /// `None` if the integrator is unconditionally stable on the linear part. For θ < ½
    /// the amplification factor `m = (1 − (1−θ)a)/(1 + θa)` reaches −1 at
    /// `a = 2/(1 − 2θ)`; Euler–Maruyama is stable for Δt < 2/λ_max.
    pub fn stability_limit(self, max_rate: f64) -> Option<f64> {
        match self.family() {
            Family::Theta(theta) if theta < 0.5 => Some(2.0 / ((1.0 - 2.0 * theta) * max_rate)),
            Family::Theta(_) | Family::ExactModal | Family::Metropolis => None,
        }
    }
}

impl std::str::FromStr for IntegratorKind {
    type Err = Error;

    /// Parses an integrator name ([`IntegratorKind::name`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] listing the allowed names.
    fn from_str(s: &str) -> Result<Self, Error> {
        IntegratorKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                Error::invalid("integrator", s, IntegratorKind::list(&IntegratorKind::ALL))
            })
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The θ-scheme stationary-variance ratios (the integrators' exact discrete-time
    /// formulas): EM 1/(1 − a/2), BE 1/(1 + a/2), CN and exact 1, for several a (exact
    /// algebra, tolerance 1e-12).
    #[test]
    fn stationary_variance_ratios_match_closed_forms() {
        for &a in &[1e-3, 0.1, 0.5, 1.0, 1.9] {
            let (rate, dt) = (a / 0.01, 0.01);
            let r = |k: IntegratorKind| k.stationary_variance_ratio(rate, dt).unwrap();
            assert!((r(IntegratorKind::EulerMaruyama) - 1.0 / (1.0 - a / 2.0)).abs() < 1e-12);
            assert!((r(IntegratorKind::BackwardEuler) - 1.0 / (1.0 + a / 2.0)).abs() < 1e-12);
            assert!((r(IntegratorKind::CrankNicolson) - 1.0).abs() < 1e-12);
            assert!((r(IntegratorKind::ExactModal) - 1.0).abs() < 1e-12);
        }
        // Beyond the explicit limit the Euler–Maruyama mode is unstable.
        assert!(
            IntegratorKind::EulerMaruyama
                .stationary_variance_ratio(2.5, 1.0)
                .is_none()
        );
        assert!(
            IntegratorKind::CrankNicolson
                .stationary_variance_ratio(1e6, 1.0)
                .is_some()
        );
    }

    /// Names round-trip through parsing; lists read "a, b or c"; an unknown name is refused
    /// with the allowed names.
    #[test]
    fn names_parse_and_list() {
        for k in IntegratorKind::ALL {
            assert_eq!(k.name().parse::<IntegratorKind>().unwrap(), k);
        }
        assert_eq!(
            IntegratorKind::list(&IntegratorKind::LINEAR),
            "euler-maruyama, backward-euler, crank-nicolson or exact-modal"
        );
        assert_eq!(
            IntegratorKind::list(&[IntegratorKind::ExactModal]),
            "exact-modal"
        );
        assert_eq!(IntegratorKind::list(&[]), "");
        let e = "rk4".parse::<IntegratorKind>().unwrap_err().to_string();
        assert!(
            e.contains("exact-modal or metropolis-crank-nicolson"),
            "{e}"
        );
        assert!(IntegratorKind::ExactModal.needs_modes());
        assert!(!IntegratorKind::BackwardEuler.exact_stationary());
        assert!(IntegratorKind::MetropolisCrankNicolson.exact_stationary());
    }

    #[test]
    fn stability_limits() {
        assert_eq!(
            IntegratorKind::EulerMaruyama.stability_limit(4.0),
            Some(0.5)
        );
        assert_eq!(IntegratorKind::BackwardEuler.stability_limit(4.0), None);
        assert_eq!(IntegratorKind::CrankNicolson.stability_limit(4.0), None);
        assert_eq!(IntegratorKind::ExactModal.stability_limit(4.0), None);
    }

    /// Crank–Nicolson's multiplier is above −1 just below its rounding limit and −1 at it;
    /// the limit is near a = 2⁵⁵ and scales as 1/λ_max; no other integrator has one.
    #[test]
    fn crank_nicolson_rounding_limit() {
        let cn = IntegratorKind::CrankNicolson;
        let limit = cn.rounding_limit(1.0).unwrap();
        assert!(cn.modal_form(limit, 1.0, 1.0).0 == -1.0);
        assert!(cn.modal_form(limit * (1.0 - 1e-12), 1.0, 1.0).0 > -1.0);
        assert!((2f64.powi(53)..2f64.powi(57)).contains(&limit), "{limit:e}");
        assert_eq!(cn.rounding_limit(4.0), Some(limit / 4.0));
        for kind in IntegratorKind::ALL.into_iter().filter(|&k| k != cn) {
            assert_eq!(kind.rounding_limit(1.0), None, "{kind}");
        }
    }
}
