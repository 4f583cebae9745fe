//! The filament as a chain of nodes (issue #31): the 5-point finite-difference filament
//! and the linearized bead-spring (discrete worm-like) chain, hinged ends. Other people's
//! simulators use these discretizations; their exact discrete references come from the
//! same [`LinearSystem`] pipeline as the Hermite-cubic beam's.
//!
//! **Finite differences.** `N` intervals of length `h = L/N`, nodes `x_i = ih`, the ends
//! `w_0 = w_N = 0` and `w'' = 0` there (the ghost nodes `w_{−1} = −w_1`,
//! `w_{N+1} = −w_{N−1}`). Eq. (2) at the interior nodes, with the noise averaged over a
//! node's cell,
//!
//! ```text
//! ξ ẇ_i = −(EI/h⁴)(w_{i−2} − 4w_{i−1} + 6w_i − 4w_{i+1} + w_{i+2}) + f_i,
//! ⟨f_i(t) f_j(t')⟩ = (2ξkT/h) δ_ij δ(t − t'),
//! ```
//!
//! times `h` is `C ẇ = −Kw + F` over the `N − 1` interior nodes with `C = ξh·I`,
//! `K = (EI/h³) D²`, `D = tridiag(1, −2, 1)` (the Dirichlet second difference; `D²` is
//! the 5-point stencil with the hinged ghosts) and `⟨FFᵀ⟩ = 2kT C δ`: the noise is
//! consistent with the lumped `C`. Its modes are the sines
//! `φ_n(x_i) = √(2/(ξL)) sin(nπx_i/L)` (`φᵀCφ = 1`), `n = 1 … N − 1`, at the rates
//!
//! ```text
//! λ_n = (EI/ξ) (4/h² · sin²(nπh/(2L)))²,
//! ```
//!
//! so the mode variances `kT/(ξλ_n)·2/L` lie *above* the continuum's (eq. 3) by
//! `(x/sin x)⁴`, `x = nπh/(2L)`.
//!
//! **Bead-spring chain.** `N + 1` beads at spacing `b`, the end beads pinned and free to
//! turn, a bending energy `(κ_θ/2)θ_i²` per hinge angle at the `N − 1` interior beads (the
//! harmonic angle potential, and the cosine one `κ_θ(1 − cos θ)` to second order), a drag
//! `ζ = ξb` per bead and stretching springs. For small deflections the transverse motion
//! decouples from the springs and `θ_i = (w_{i+1} − 2w_i + w_{i−1})/b`, so the energy is
//! `(κ_θ/(2b²)) |Dw|²`: the finite-difference `K` with `h = b` and `EI = κ_θ b`, and the
//! same `C`. One model serves both (the test `bead_spring_hessian_is_the_stencil` checks
//! the Hessian of the nonlinear angle energy against it).
//!
//! **The field between nodes** is the linear interpolant of the nodal values
//! ([`ChainModel::value_at`]): a producer that records the field elsewhere than at its
//! nodes is expected to interpolate so.
//!
//! **Element-uniform noise** (eq. 5) on a chain is a uniform load per node cell,
//! `ζ_i = √(ξ/h)·z_i·h`: the same law as the consistent noise.

use super::banded::SymBanded;
use super::modal::{GeneralizedModes, generalized_modes_signed};
use super::system::{ElementLoad, LinearSystem};
use crate::error::{Error, Result};
use crate::params::FilamentParams;
use std::f64::consts::PI;

/// Half-bandwidth of the chain's stiffness (the 5-point stencil).
pub const CHAIN_BANDWIDTH: usize = 2;

/// The hinged filament on `N` intervals as a chain of nodes (see the module docs): the
/// 5-point finite-difference filament, and the linearized bead-spring chain.
#[derive(Debug, Clone)]
pub struct ChainModel {
    params: FilamentParams,
    intervals: usize,
    system: LinearSystem,
}

impl ChainModel {
    /// The chain of filament `params` on `intervals` uniform intervals (`N ≥ 2`: at least
    /// one interior node).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `intervals < 2`, or the parameters are not finite
    /// and positive.
    pub fn new(params: FilamentParams, intervals: usize) -> Result<Self> {
        if intervals < 2 {
            return Err(Error::invalid(
                "intervals",
                intervals,
                ">= 2 (a chain needs an interior node)",
            ));
        }
        for (name, v) in [
            ("length", params.length),
            ("bending_rigidity", params.bending_rigidity),
            ("drag", params.drag),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(name, v, "finite and > 0"));
            }
        }
        let n = intervals - 1;
        let h = params.length / intervals as f64;
        let k = params.bending_rigidity / h.powi(3);
        let mut stiffness = SymBanded::new(n, CHAIN_BANDWIDTH.min(n.saturating_sub(1)));
        let mut damping = SymBanded::new(n, 0);
        let mut loads = Vec::with_capacity(n);
        // K = (EI/h³) D², D = tridiag(1, −2, 1): diagonal 6 (5 next to an end), −4, 1.
        for i in 0..n {
            let end = i == 0 || i == n - 1;
            let diag = if n == 1 {
                4.0
            } else if end {
                5.0
            } else {
                6.0
            };
            stiffness.add(i, i, k * diag)?;
            if i + 1 < n {
                stiffness.add(i, i + 1, -4.0 * k)?;
            }
            if i + 2 < n {
                stiffness.add(i, i + 2, k)?;
            }
            damping.add(i, i, params.drag * h)?;
            loads.push(ElementLoad {
                amplitude: (params.drag / h).sqrt(),
                load: vec![h],
                dofs: vec![Some(i)],
            });
        }
        let system = LinearSystem::new(params.kt, stiffness, damping, loads)?;
        Ok(ChainModel {
            params,
            intervals,
            system,
        })
    }

    /// The filament's parameters.
    pub fn params(&self) -> &FilamentParams {
        &self.params
    }

    /// Number of intervals `N` (bonds of a bead-spring chain).
    pub fn intervals(&self) -> usize {
        self.intervals
    }

    /// Node spacing `h = L/N`.
    pub fn spacing(&self) -> f64 {
        self.params.length / self.intervals as f64
    }

    /// The node positions `x_i = ih`, `i = 0 … N` (the ends included).
    pub fn nodes(&self) -> Vec<f64> {
        let h = self.spacing();
        (0..=self.intervals).map(|i| i as f64 * h).collect()
    }

    /// The exact rate of mode `n` (`1 ≤ n ≤ N − 1`): `λ_n = (EI/ξ)(4/h²·sin²(nπh/(2L)))²`
    /// (module docs), the eigenvalue of `(K, C)` for the sine `sin(nπx_i/L)`.
    pub fn mode_rate(&self, n: usize) -> f64 {
        let p = &self.params;
        let h = self.spacing();
        let s = (n as f64 * PI * h / (2.0 * p.length)).sin();
        let d = 4.0 * s * s / (h * h);
        p.bending_rigidity * d * d / p.drag
    }

    /// The largest rate, `λ_{N−1}` (exact, module docs).
    pub fn max_rate(&self) -> f64 {
        self.mode_rate(self.intervals - 1)
    }

    /// The generalized modes of `(K, C)`, slowest first, each signed so that its
    /// projection on the sine `sin(nπx/L)` at the nodes is positive (as the beam's
    /// hinged modes: positive at `x = L/(2n)`).
    ///
    /// # Errors
    /// As [`generalized_modes_signed`].
    pub fn modes(&self) -> Result<GeneralizedModes> {
        let (h, len) = (self.spacing(), self.params.length);
        generalized_modes_signed(&self.system, |i, col| {
            let kk = (i + 1) as f64 * PI / len;
            let dot: f64 = col
                .iter()
                .enumerate()
                .map(|(j, v)| v * (kk * (j + 1) as f64 * h).sin())
                .sum();
            dot < 0.0
        })
    }

    /// The field at `x` for interior nodal values `state` (length `N − 1`): the linear
    /// interpolant through the nodes with `w = 0` at the ends; NaN outside `[0, L]`.
    pub fn value_at(&self, state: &[f64], x: f64) -> f64 {
        let len = self.params.length;
        if !(0.0..=len).contains(&x) {
            return f64::NAN;
        }
        let node = |i: usize| -> f64 {
            if i == 0 || i >= self.intervals {
                0.0
            } else {
                state[i - 1]
            }
        };
        let s = x / self.spacing();
        let i = (s.floor() as usize).min(self.intervals - 1);
        let f = s - i as f64;
        (1.0 - f) * node(i) + f * node(i + 1)
    }
}

impl std::ops::Deref for ChainModel {
    type Target = LinearSystem;

    fn deref(&self) -> &LinearSystem {
        &self.system
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> FilamentParams {
        FilamentParams {
            bending_rigidity: 2.0,
            drag: 3.0,
            kt: 0.5,
            length: 1.5,
            ..FilamentParams::default()
        }
    }

    /// The stiffness is the 5-point stencil with the hinged ghosts: applied to the nodal
    /// values of a smooth w it gives EI h w'''' to O(h²), and the sines are its exact
    /// eigenvectors with the closed-form rates, which the inertia bisection confirms.
    #[test]
    fn stencil_modes_and_rates_are_exact() {
        let p = params();
        let chain = ChainModel::new(p, 12).unwrap();
        let gm = chain.modes().unwrap();
        assert_eq!(gm.len(), 11);
        let h = chain.spacing();
        for n in 1..=11 {
            let (lam, want) = (gm.rates[n - 1], chain.mode_rate(n));
            assert!(
                (lam / want - 1.0).abs() < 1e-11,
                "mode {n}: {lam} vs {want}"
            );
            let col = gm.vectors.column(n - 1);
            let c = (2.0 / (p.drag * p.length)).sqrt();
            for (j, v) in col.iter().enumerate() {
                let s = c * (n as f64 * PI * (j + 1) as f64 * h / p.length).sin();
                assert!(
                    (v - s).abs() < 1e-9 * c,
                    "mode {n} node {}: {v} vs {s}",
                    j + 1
                );
            }
        }
        let trial: Vec<f64> = (0..11)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let bisected = chain
            .max_rate_bisection(16.0 * p.bending_rigidity / (p.drag * h.powi(4)), &trial)
            .unwrap();
        assert!((bisected / chain.max_rate() - 1.0).abs() < 1e-11);
        // The rates approach the continuum's π⁴n⁴EI/(ξL⁴) from below, at O(h²):
        // λ_n/λ = (sin x/x)⁴ = 1 − (2/3)x² + O(x⁴), x = nπh/(2L).
        for n in 1..=3 {
            let cont = p.bending_rigidity * (n as f64 * PI / p.length).powi(4) / p.drag;
            let x = n as f64 * PI * h / (2.0 * p.length);
            let err = chain.mode_rate(n) / cont - 1.0;
            assert!(err < 0.0 && (err / (-2.0 / 3.0 * x * x) - 1.0).abs() < 0.05 * n as f64);
        }
    }

    /// The bead-spring chain's energy: the Hessian at the straight chain of the exact
    /// angle energy Σ κ_θ(1 − cos θ_i), θ_i the angle between consecutive bonds (by
    /// central differences of the nonlinear energy in the transverse bead coordinates),
    /// is the chain's K with EI = κ_θ b.
    #[test]
    fn bead_spring_hessian_is_the_stencil() {
        let (beads, b, kappa) = (8usize, 0.25, 3.0);
        let energy = |w: &[f64]| -> f64 {
            let y = |i: usize| {
                if i == 0 || i == beads - 1 {
                    0.0
                } else {
                    w[i - 1]
                }
            };
            let mut e = 0.0;
            for i in 1..beads - 1 {
                let (ax, ay) = (b, y(i) - y(i - 1));
                let (bx, by) = (b, y(i + 1) - y(i));
                let cos = (ax * bx + ay * by) / ((ax * ax + ay * ay) * (bx * bx + by * by)).sqrt();
                e += kappa * (1.0 - cos);
            }
            e
        };
        let p = FilamentParams {
            length: b * (beads - 1) as f64,
            bending_rigidity: kappa * b,
            ..FilamentParams::default()
        };
        let chain = ChainModel::new(p, beads - 1).unwrap();
        let n = beads - 2;
        let eps = 1e-4;
        for i in 0..n {
            for j in 0..n {
                let at = |di: f64, dj: f64| {
                    let mut w = vec![0.0; n];
                    w[i] += di;
                    w[j] += dj;
                    energy(&w)
                };
                let hij = (at(eps, eps) - at(eps, -eps) - at(-eps, eps) + at(-eps, -eps))
                    / (4.0 * eps * eps);
                let kij = chain.stiffness().get(i, j);
                assert!(
                    (hij - kij).abs() <= 1e-5 * kappa / (b * b),
                    "({i}, {j}): Hessian {hij} vs K {kij}"
                );
            }
        }
    }

    /// The field between nodes is the linear interpolant, 0 at the ends, NaN outside.
    #[test]
    fn field_is_the_nodal_interpolant() {
        let chain = ChainModel::new(FilamentParams::default(), 4).unwrap();
        let state = [1.0, 2.0, -1.0];
        assert_eq!(chain.value_at(&state, 0.0), 0.0);
        assert_eq!(chain.value_at(&state, 0.25), 1.0);
        assert!((chain.value_at(&state, 0.375) - 1.5).abs() < 1e-15);
        assert!((chain.value_at(&state, 0.875) + 0.5).abs() < 1e-15);
        assert_eq!(chain.value_at(&state, 1.0), 0.0);
        assert!(chain.value_at(&state, 1.1).is_nan());
        assert_eq!(chain.nodes(), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        assert!(ChainModel::new(FilamentParams::default(), 1).is_err());
        // Two intervals: one interior node, K = 4EI/h³ (w_{-1} = −w_1 on both sides).
        let two = ChainModel::new(FilamentParams::default(), 2).unwrap();
        assert_eq!(two.stiffness().get(0, 0), 4.0 / 0.125);
        assert!((two.max_rate() / (two.stiffness().get(0, 0) / 0.5) - 1.0).abs() < 1e-12);
    }
}
