//! Time integrators of the finite-deflection (von Kármán) filament
//! [`CompressedFilament`] (the paper's steps i–iii): with u eliminated, the energy is
//! `U(w) = ½ wᵀK w + (EA·L/2)(s − ε)²` and the force on w is `−K w + F G w`,
//! `F = EA(ε − s)` ([`crate::fem::vonkarman`]).
//!
//! Integrators ([`NonlinearIntegrator`]):
//! - θ-schemes with the stretching force explicit: `(C + θΔtK) w' = (C − (1−θ)ΔtK) w +
//!   Δt F(w) G w + sqrt(2kTΔt) ζ`; θ = 0 is the paper's explicit scheme (with u from
//!   step i), θ = ½ Crank–Nicolson, θ = 1 backward Euler. Their stationary law is biased by
//!   O(Δt) through the stretching force, and θ = 1 also freezes the fast bending modes.
//! - `metropolis-crank-nicolson`: a Crank–Nicolson proposal for the Hessian
//!   `H_w = K − F(w) G` frozen at the current state,
//!
//!   ```text
//!   (C + ½Δt H_w) w' = (C − ½Δt H_w) w + sqrt(2kTΔt) ζ,   ζ ~ N(0, C),
//!   ```
//!
//!   accepted with the Metropolis–Hastings probability
//!   `min(1, e^{−(U(w') − U(w))/kT} q(w'→w)/q(w→w'))`, where the proposal density
//!   `q(w→w') ∝ det(A_w)^d e^{−½ζᵀC⁻¹ζ}` (`A_w = C + ½Δt H_w`, d components) is evaluated
//!   exactly, including the state dependence of `A_w` through F. Its stationary law is
//!   the exact equilibrium at any Δt (no bias on ⟨F⟩). Because the tension is in the
//!   proposal, the proposal is exact for the Gaussian with precision `H_w/kT`, and only
//!   the change of F between w and w' and the rank-one term `(EA/L)(Gw)(Gw)ᵀ` are left to
//!   the accept/reject step: the acceptance stays high for many elements and large EA
//!   (an explicit `Δt F G w` in the proposal costs about `Δt F² n/(2 EI ξ)` in ln α,
//!   which at 40 elements and Δt = 0.02 τ1 gave acceptance rates near 0.4 and strongly
//!   correlated F). A proposal from, or into, a state whose `A_w` is not positive definite
//!   (F beyond about `F_1(1 + 2/(λ_1Δt))`) is rejected.

use super::integrator::{check_dt, check_stability};
use super::{Family, IntegratorKind};
use crate::error::{Error, Result};
use crate::fem::banded::{BandedCholesky, SymBanded};
use crate::fem::noise::{NoiseGenerator, NoiseModel};
use crate::fem::vonkarman::{AxialScratch, CompressedFilament};
use crate::rng::TrajectoryRng;
use rand::RngExt;

mod batch;
pub use batch::NonlinearBatch;

/// Which nonlinear scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Scheme {
    Theta(f64),
    Metropolis,
}

/// Per-component buffers of a θ-step: the explicit right-hand side
/// `(C − (1−θ)ΔtK) w + Δt F(w) G w` (turned into the new state in place) and `K w`.
#[derive(Debug, Clone, Default)]
struct ThetaBuffers {
    explicit: Vec<Vec<f64>>,
    kw: Vec<Vec<f64>>,
}

/// One state of the Metropolis chain and what proposals from and to it need: its energy,
/// compressive force `F(w)`, the products `C w`, `K w`, `G w` per component, and the
/// Cholesky factor of `A_w = C + ½Δt H_w`, `H_w = K − F(w) G`, with `ln det A_w` (`None`
/// if `A_w` is not positive definite: no proposal is made from, or accepted into, such a
/// state). The buffers are allocated once and overwritten by each evaluation.
#[derive(Debug, Clone)]
struct MhEvaluation {
    state: Vec<Vec<f64>>,
    energy: f64,
    force: f64,
    cw: Vec<Vec<f64>>,
    kw: Vec<Vec<f64>>,
    gw: Vec<Vec<f64>>,
    /// `A_w`.
    a: SymBanded,
    /// The Cholesky factor of `A_w` (meaningful only if `log_det` is `Some`).
    chol: BandedCholesky,
    /// `ln det A_w`, `None` if `A_w` is not positive definite.
    log_det: Option<f64>,
}

impl MhEvaluation {
    /// Buffers for `nc` components of `n` DOFs; `base` (`C + ½ΔtK`) gives the shape of
    /// `A_w`. Not yet an evaluation of any state.
    fn new(base: &SymBanded, nc: usize, n: usize) -> Result<Self> {
        Ok(MhEvaluation {
            state: vec![vec![0.0; n]; nc],
            energy: 0.0,
            force: 0.0,
            cw: vec![vec![0.0; n]; nc],
            kw: vec![vec![0.0; n]; nc],
            gw: vec![vec![0.0; n]; nc],
            a: base.clone(),
            chol: base.cholesky()?,
            log_det: None,
        })
    }

    /// The Cholesky factor of `A_w` and `ln det A_w`, `None` if `A_w` is not positive
    /// definite.
    fn lhs(&self) -> Option<(&BandedCholesky, f64)> {
        self.log_det.map(|ld| (&self.chol, ld))
    }
}

/// The Metropolis chain's work space: the evaluated current state, the proposal
/// (swapped with the current state on acceptance) and the reverse noise.
#[derive(Debug, Clone)]
struct MhBuffers {
    current: MhEvaluation,
    /// Whether `current` holds the evaluation of `current.state` (false before the first
    /// step).
    evaluated: bool,
    proposal: MhEvaluation,
    reverse: Vec<Vec<f64>>,
}

/// One step of a stochastic time integrator for the nonlinear filament: the same shape as
/// [`super::Integrator`], with the model held by the integrator.
pub trait NonlinearStep: Send {
    /// Advances the state `w` (one vector per transverse component) by one time step,
    /// drawing its noise from `rng`.
    fn step(&mut self, w: &mut [Vec<f64>], rng: &mut TrajectoryRng);
}

/// A time integrator for [`CompressedFilament`] (the model is borrowed for its lifetime).
pub struct NonlinearIntegrator<'m> {
    model: &'m CompressedFilament,
    scheme: Scheme,
    kind: IntegratorKind,
    theta: f64,
    dt: f64,
    kt: f64,
    scale: f64,
    lhs: BandedCholesky,
    damping: BandedCholesky,
    noise: NoiseGenerator,
    zeta: Vec<Vec<f64>>,
    theta_buffers: ThetaBuffers,
    /// Metropolis: `C + ½ΔtK`, to which `−½Δt F(w) G` is added per state.
    mh_base: SymBanded,
    /// Metropolis: the chain's work space (`None` for the θ-schemes).
    mh: Option<MhBuffers>,
    scratch: [Vec<f64>; 3],
    /// Step (i) of the paper's explicit scheme: the axial solve's work space.
    axial: AxialScratch,
    /// Proposals made (Metropolis only).
    pub proposed: u64,
    /// Accepted proposals (Metropolis only).
    pub accepted: u64,
}

impl<'m> NonlinearIntegrator<'m> {
    /// Builds integrator `kind` for `model` (one of [`IntegratorKind::NONLINEAR`]) with step
    /// `dt` and noise model `noise`.
    ///
    /// # Errors
    /// [`Error::UnstableTimeStep`] for euler-maruyama above the linear stability limit
    /// 2/λ_max; [`Error::InvalidParameter`] for exact-modal (not available for the
    /// nonlinear filament) or for Metropolis with element-uniform noise (its proposal
    /// density is singular).
    pub fn new(
        model: &'m CompressedFilament,
        kind: IntegratorKind,
        noise: NoiseModel,
        dt: f64,
    ) -> Result<Self> {
        let beam = model.beam();
        check_dt(dt)?;
        let scheme = match kind.family() {
            Family::Metropolis => Scheme::Metropolis,
            Family::Theta(t) => Scheme::Theta(t),
            Family::ExactModal => {
                return Err(Error::invalid(
                    "integrator",
                    kind,
                    format!(
                        "{} for the nonlinear filament",
                        IntegratorKind::list(&IntegratorKind::NONLINEAR)
                    ),
                ));
            }
        };
        if scheme == Scheme::Metropolis && noise != NoiseModel::Consistent {
            return Err(Error::invalid(
                "noise",
                noise.name(),
                "consistent for metropolis-crank-nicolson (the element-uniform proposal density is singular)",
            ));
        }
        check_stability(
            kind,
            dt,
            beam.max_rate()?,
            "metropolis-crank-nicolson (exact stationary law, stable at any dt)",
        )?;
        let theta = match scheme {
            Scheme::Theta(t) => t,
            Scheme::Metropolis => 0.5,
        };
        let (k, c) = (beam.stiffness(), beam.damping());
        let n = beam.n_dofs();
        let nc = model.components();
        let mh_base = SymBanded::linear_combination(1.0, c, 0.5 * dt, k)?;
        let mh = match scheme {
            Scheme::Metropolis => Some(MhBuffers {
                current: MhEvaluation::new(&mh_base, nc, n)?,
                evaluated: false,
                proposal: MhEvaluation::new(&mh_base, nc, n)?,
                reverse: vec![vec![0.0; n]; nc],
            }),
            Scheme::Theta(_) => None,
        };
        Ok(NonlinearIntegrator {
            model,
            scheme,
            kind,
            theta,
            dt,
            kt: beam.params().kt,
            scale: (2.0 * beam.params().kt * dt).sqrt(),
            lhs: SymBanded::linear_combination(1.0, c, theta * dt, k)?.cholesky()?,
            damping: c.cholesky()?,
            noise: NoiseGenerator::new(noise, beam)?,
            zeta: vec![vec![0.0; n]; nc],
            theta_buffers: ThetaBuffers {
                explicit: vec![vec![0.0; n]; nc],
                kw: vec![vec![0.0; n]; nc],
            },
            mh_base,
            mh,
            scratch: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            axial: AxialScratch::default(),
            proposed: 0,
            accepted: 0,
        })
    }

    /// The integrator kind.
    pub fn kind(&self) -> IntegratorKind {
        self.kind
    }

    /// Fraction of accepted proposals (1 for the θ-schemes).
    pub fn acceptance(&self) -> f64 {
        if self.proposed == 0 {
            1.0
        } else {
            self.accepted as f64 / self.proposed as f64
        }
    }

    /// The explicit right-hand side of `w` into `out.explicit`, with three banded products
    /// per component (G w, K w, C w).
    /// The compressive force of the explicit stretching term comes, for the paper's
    /// explicit scheme, from the axial solve (step i), otherwise from the closed form
    /// (identical up to round-off; see the tests).
    fn evaluate(&mut self, w: &[Vec<f64>], out: &mut ThetaBuffers) {
        let model = self.model;
        let beam = model.beam();
        let p = beam.params();
        let nc = w.len();
        resize_state(&mut out.explicit, nc, beam.n_dofs());
        resize_state(&mut out.kw, nc, beam.n_dofs());
        let mut two_l_s = 0.0;
        // First pass: G w into explicit (temporarily), K w into kw.
        for (c, wc) in w.iter().enumerate() {
            beam.geometric().mul_vec(wc, &mut out.explicit[c]);
            beam.stiffness().mul_vec(wc, &mut out.kw[c]);
            two_l_s += wc
                .iter()
                .zip(&out.explicit[c])
                .map(|(a, b)| a * b)
                .sum::<f64>();
        }
        let s = two_l_s / (2.0 * p.length);
        let f = if self.kind == IntegratorKind::EulerMaruyama {
            model.axial_equilibrium_into(w, &mut self.axial);
            -self.axial.element_force[0]
        } else {
            model.compressive_force(s)
        };
        let cw = &mut self.scratch[0];
        for (c, wc) in w.iter().enumerate() {
            beam.damping().mul_vec(wc, cw);
            let (gw, kw) = (&mut out.explicit[c], &out.kw[c]);
            for i in 0..cw.len() {
                gw[i] = cw[i] - (1.0 - self.theta) * self.dt * kw[i] + self.dt * f * gw[i];
            }
        }
    }

    /// `Σ_c ζ_cᵀ C⁻¹ ζ_c`.
    fn noise_norm(&mut self, zeta: &[Vec<f64>]) -> f64 {
        let y = &mut self.scratch[1];
        zeta.iter()
            .map(|z| {
                y.copy_from_slice(z);
                self.damping.solve_in_place(y);
                z.iter().zip(y.iter()).map(|(a, b)| a * b).sum::<f64>()
            })
            .sum()
    }

    /// One θ-step (see [`NonlinearIntegrator`]).
    fn step_theta(&mut self, w: &mut [Vec<f64>], rng: &mut TrajectoryRng) {
        let mut zeta = std::mem::take(&mut self.zeta);
        self.draw_noise(rng, &mut zeta);
        self.theta_update(w, &zeta);
        self.zeta = zeta;
    }

    /// Draws one step's standardized noise `ζ` into `zeta` (one vector per transverse
    /// component, covariance C for consistent noise, the element-uniform load of eq. 5
    /// otherwise): the draw [`NonlinearStep::step`] makes. With
    /// [`Self::step_theta_with`], two steps of `Δt` and one of `2Δt` can share a Brownian
    /// path: `ζ_2Δt = (ζ₁ + ζ₂)/√2` (the coupling of [`crate::studies::coupled_dt`]).
    pub fn draw_noise(&self, rng: &mut TrajectoryRng, zeta: &mut [Vec<f64>]) {
        for z in zeta {
            self.noise.draw(rng, z);
        }
    }

    /// One θ-step of `w` with the given standardized noise `zeta` (as drawn by
    /// [`Self::draw_noise`]): `(C + θΔtK) w' = (C − (1−θ)ΔtK) w + Δt F(w) G w +
    /// sqrt(2kTΔt) ζ`. For a θ-scheme, [`NonlinearStep::step`] is exactly `draw_noise`
    /// then this.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for the Metropolis chain (its step also draws the
    /// acceptance variate, so it has no step of a given noise alone).
    pub fn step_theta_with(&mut self, w: &mut [Vec<f64>], zeta: &[Vec<f64>]) -> Result<()> {
        if !matches!(self.scheme, Scheme::Theta(_)) {
            return Err(Error::invalid(
                "integrator",
                self.kind,
                "a θ-scheme (euler-maruyama, crank-nicolson, backward-euler) for a step with given noise",
            ));
        }
        self.theta_update(w, zeta);
        Ok(())
    }

    /// The θ-update of `w` with noise `zeta` (see [`Self::step_theta_with`]).
    fn theta_update(&mut self, w: &mut [Vec<f64>], zeta: &[Vec<f64>]) {
        let mut buf = std::mem::take(&mut self.theta_buffers);
        self.evaluate(w, &mut buf);
        // The new state: (C + θΔtK) w' = explicit(w) + scale ζ, solved in place.
        for ((wc, rhs), zc) in w.iter_mut().zip(&mut buf.explicit).zip(zeta) {
            for (v, z) in rhs.iter_mut().zip(zc) {
                *v += self.scale * z;
            }
            self.lhs.solve_in_place(rhs);
            wc.copy_from_slice(rhs);
        }
        self.theta_buffers = buf;
    }

    /// Evaluates the state `e.state` of the Metropolis chain into `e` ([`MhEvaluation`]).
    fn evaluate_mh(&self, e: &mut MhEvaluation) {
        let model = self.model;
        let beam = model.beam();
        let p = beam.params();
        let n = beam.n_dofs();
        let nc = e.state.len();
        resize_state(&mut e.cw, nc, n);
        resize_state(&mut e.kw, nc, n);
        resize_state(&mut e.gw, nc, n);
        let (mut two_l_s, mut bend) = (0.0, 0.0);
        for (c, wc) in e.state.iter().enumerate() {
            beam.damping().mul_vec(wc, &mut e.cw[c]);
            beam.stiffness().mul_vec(wc, &mut e.kw[c]);
            beam.geometric().mul_vec(wc, &mut e.gw[c]);
            two_l_s += dot(wc, &e.gw[c]);
            bend += 0.5 * dot(wc, &e.kw[c]);
        }
        let s = two_l_s / (2.0 * p.length);
        e.force = model.compressive_force(s);
        let d = s - model.strain();
        e.energy = bend + 0.5 * p.stretch_rigidity * p.length * d * d;
        let factored =
            e.a.linear_combination_into(
                1.0,
                &self.mh_base,
                -0.5 * self.dt * e.force,
                beam.geometric(),
            )
            .is_ok()
                && e.chol.try_factor_from(&e.a);
        e.log_det = factored.then(|| e.chol.log_det());
    }

    /// The Metropolis proposal from `cur` with noise `zeta` (covariance C per component)
    /// into `next`: `A_w w' = B_w w + sqrt(2kTΔt) ζ`, `B_w = C − ½Δt H_w`. `false` (and
    /// `next` untouched) if `A_w` is not positive definite.
    fn propose(&self, cur: &MhEvaluation, zeta: &[Vec<f64>], next: &mut Vec<Vec<f64>>) -> bool {
        let Some((lhs, _)) = cur.lhs() else {
            return false;
        };
        let h = 0.5 * self.dt;
        resize_state(next, cur.state.len(), cur.cw.first().map_or(0, Vec::len));
        for (c, nc) in next.iter_mut().enumerate() {
            for (i, v) in nc.iter_mut().enumerate() {
                *v = cur.cw[c][i] - h * (cur.kw[c][i] - cur.force * cur.gw[c][i])
                    + self.scale * zeta[c][i];
            }
            lhs.solve_in_place(nc);
        }
        true
    }

    /// The noise of the reverse move `prop → cur` into `out`:
    /// `ζ_r = (A_{w'} w − B_{w'} w')/sqrt(2kTΔt)`.
    fn reverse_noise(&self, cur: &MhEvaluation, prop: &MhEvaluation, out: &mut Vec<Vec<f64>>) {
        let h = 0.5 * self.dt;
        let f = prop.force;
        resize_state(out, cur.state.len(), cur.cw.first().map_or(0, Vec::len));
        for (c, oc) in out.iter_mut().enumerate() {
            for (i, v) in oc.iter_mut().enumerate() {
                let a_w = cur.cw[c][i] + h * (cur.kw[c][i] - f * cur.gw[c][i]);
                let b_wp = prop.cw[c][i] - h * (prop.kw[c][i] - f * prop.gw[c][i]);
                *v = (a_w - b_wp) / self.scale;
            }
        }
    }

    /// `ln α` of the move `cur → prop` made with noise `zeta`:
    /// `−(U' − U)/kT + d (ln det A_{w'} − ln det A_w) − ½|ζ_r|²_{C⁻¹} + ½|ζ|²_{C⁻¹}`
    /// (d transverse components), with `reverse` the buffer for ζ_r. `−∞` if `A_{w'}` is
    /// not positive definite.
    fn log_acceptance(
        &mut self,
        cur: &MhEvaluation,
        prop: &MhEvaluation,
        zeta: &[Vec<f64>],
        reverse: &mut Vec<Vec<f64>>,
    ) -> f64 {
        let (Some(ld), Some(ld_p)) = (cur.log_det, prop.log_det) else {
            return f64::NEG_INFINITY;
        };
        let forward = self.noise_norm(zeta);
        self.reverse_noise(cur, prop, reverse);
        let backward = self.noise_norm(reverse);
        -(prop.energy - cur.energy) / self.kt + cur.state.len() as f64 * (ld_p - ld)
            - 0.5 * backward
            + 0.5 * forward
    }

    /// One Metropolis-adjusted step (see [`NonlinearIntegrator`]). Allocation-free: the
    /// evaluations of the current state and of the proposal live in preallocated buffers,
    /// swapped on acceptance.
    fn step_metropolis(&mut self, w: &mut [Vec<f64>], rng: &mut TrajectoryRng) {
        let mut mh = self
            .mh
            .take()
            .expect("the Metropolis integrator has its buffers");
        if !(mh.evaluated && mh.current.state.as_slice() == &*w) {
            copy_state(&mut mh.current.state, w);
            self.evaluate_mh(&mut mh.current);
            mh.evaluated = true;
        }
        for z in &mut self.zeta {
            self.noise.draw(rng, z);
        }
        let u: f64 = rng.random();
        self.proposed += 1;
        let zeta = std::mem::take(&mut self.zeta);
        let MhBuffers {
            current,
            proposal,
            reverse,
            ..
        } = &mut mh;
        let proposed = self.propose(current, &zeta, &mut proposal.state)
            && proposal.state.iter().flatten().all(|v| v.is_finite());
        if proposed {
            self.evaluate_mh(proposal);
            let log_alpha = self.log_acceptance(current, proposal, &zeta, reverse);
            if log_alpha >= 0.0 || u < log_alpha.exp() {
                for (wc, nc) in w.iter_mut().zip(&proposal.state) {
                    wc.copy_from_slice(nc);
                }
                std::mem::swap(current, proposal);
                self.accepted += 1;
            }
        }
        self.zeta = zeta;
        self.mh = Some(mh);
    }
}

impl NonlinearStep for NonlinearIntegrator<'_> {
    fn step(&mut self, w: &mut [Vec<f64>], rng: &mut TrajectoryRng) {
        match self.scheme {
            Scheme::Metropolis => self.step_metropolis(w, rng),
            Scheme::Theta(_) => self.step_theta(w, rng),
        }
    }
}

/// Gives `v` `nc` components of `n` entries (allocating only if its shape differs).
fn resize_state(v: &mut Vec<Vec<f64>>, nc: usize, n: usize) {
    v.resize_with(nc, Vec::new);
    for c in v {
        c.resize(n, 0.0);
    }
}

/// `dst ← src` (allocating only if the shapes differ).
fn copy_state(dst: &mut Vec<Vec<f64>>, src: &[Vec<f64>]) {
    dst.resize_with(src.len(), Vec::new);
    for (d, s) in dst.iter_mut().zip(src) {
        d.clone_from(s);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::fem::beam::BeamModel;
    use crate::fem::mesh::Mesh;
    use crate::fem::vonkarman::tests::{SEED, model, random_state};
    use crate::params::FilamentParams;
    use crate::rng::trajectory_rng;

    /// The evaluation of `w` in fresh buffers.
    fn evaluated(integ: &NonlinearIntegrator, w: &[Vec<f64>]) -> MhEvaluation {
        let mut e = MhEvaluation::new(&integ.mh_base, w.len(), w[0].len()).unwrap();
        copy_state(&mut e.state, w);
        integ.evaluate_mh(&mut e);
        e
    }

    /// The proposal from `cur` with noise `zeta`, if any.
    fn proposal(
        integ: &NonlinearIntegrator,
        cur: &MhEvaluation,
        zeta: &[Vec<f64>],
    ) -> Option<Vec<Vec<f64>>> {
        let mut next = Vec::new();
        integ.propose(cur, zeta, &mut next).then_some(next)
    }

    /// The reverse noise of `cur → prop`.
    fn reverse(
        integ: &NonlinearIntegrator,
        cur: &MhEvaluation,
        prop: &MhEvaluation,
    ) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        integ.reverse_noise(cur, prop, &mut out);
        out
    }

    /// Euler–Maruyama above its stability limit is refused before running, naming the
    /// limit; exact-modal is refused for the nonlinear filament; Metropolis refuses the
    /// singular element-uniform proposal.
    #[test]
    fn invalid_integrators_are_refused() {
        let m = model(2, 1.0);
        let limit = 2.0 / m.beam().max_rate().unwrap();
        let e = NonlinearIntegrator::new(
            &m,
            IntegratorKind::EulerMaruyama,
            NoiseModel::Consistent,
            1.5 * limit,
        )
        .err()
        .unwrap();
        assert!(matches!(e, Error::UnstableTimeStep { .. }), "{e}");
        assert!(
            NonlinearIntegrator::new(&m, IntegratorKind::ExactModal, NoiseModel::Consistent, 1e-3)
                .is_err()
        );
        assert!(
            NonlinearIntegrator::new(
                &m,
                IntegratorKind::MetropolisCrankNicolson,
                NoiseModel::ElementUniform,
                1e-3
            )
            .is_err()
        );
    }

    /// Detailed balance of the Metropolis step, algebraically: for a proposal w → w' made
    /// with noise ζ, the reverse noise ζ_r proposes w' → w exactly (the proposal map is
    /// invertible), ln α(w → w'; ζ) = −ln α(w' → w; ζ_r), and ln α equals
    /// −ΔU/kT + ln q(w'→w) − ln q(w→w') computed independently from dense matrices (the
    /// determinant of A_w included: without it the chain's ⟨F⟩ is off by up to 1 F_c0 at
    /// 40 elements, which the compression convergence study shows). Graded mesh,
    /// An independent oracle of `ln α` for the Metropolis-adjusted Crank–Nicolson move
    /// `w → wp` at step `dt`, from dense matrices: the proposal densities
    /// `ln q(a → b) = d ln det A_a − ½ Σ_c |A_a b_c − B_a a_c|²_{C⁻¹}/(2kTΔt)`
    /// (`A_a, B_a = C ± ½Δt(K − F(a) G)`) and the energy from
    /// [`CompressedFilament::energy`].
    pub(crate) fn dense_log_alpha(
        m: &CompressedFilament,
        dt: f64,
        w: &[Vec<f64>],
        wp: &[Vec<f64>],
    ) -> f64 {
        let beam = m.beam();
        let kt = beam.params().kt;
        let (k, c, g) = (
            beam.stiffness().to_dense(),
            beam.damping().to_dense(),
            beam.geometric().to_dense(),
        );
        let c_inv = c.clone().try_inverse().unwrap();
        let log_q = |a: &[Vec<f64>], b: &[Vec<f64>]| {
            let f = m.compressive_force(m.stored_length(a));
            let h = &k - &g * f;
            let am = &c + &h * (0.5 * dt);
            let bm = &c - &h * (0.5 * dt);
            let mut norm = 0.0;
            for (ac, bc) in a.iter().zip(b) {
                let r = &am * nalgebra::DVector::from_column_slice(bc)
                    - &bm * nalgebra::DVector::from_column_slice(ac);
                norm += (r.transpose() * &c_inv * &r)[(0, 0)];
            }
            a.len() as f64 * am.determinant().ln() - 0.5 * norm / (2.0 * kt * dt)
        };
        -(m.energy(wp) - m.energy(w)) / kt + log_q(wp, w) - log_q(w, wp)
    }

    /// 2D and 3D, in tension, near the Euler strain and buckled; states of a few kT, large
    /// Δt (0.05 τ1) so the F dependence of A_w matters. Tolerance: round-off (1e-9
    /// relative on the states, 1e-7 absolute on ln α, whose terms are O(100)).
    #[test]
    fn metropolis_step_is_reversible_with_exact_acceptance_ratio() {
        for dims in [2, 3] {
            for ratio in [0.0, 1.0, 6.0] {
                let m = model(dims, ratio);
                let dt = 0.05 * m.beam().params().tau1();
                let mut integ = NonlinearIntegrator::new(
                    &m,
                    IntegratorKind::MetropolisCrankNicolson,
                    NoiseModel::Consistent,
                    dt,
                )
                .unwrap();
                let w = random_state(&m, 0.01, 20 + dims as u64);
                let mut rng = trajectory_rng(SEED, 30 + dims as u64);
                let zeta: Vec<Vec<f64>> = (0..m.components())
                    .map(|_| {
                        let mut z = vec![0.0; m.beam().n_dofs()];
                        integ.noise.draw(&mut rng, &mut z);
                        z
                    })
                    .collect();
                let cur = evaluated(&integ, &w);
                let next = proposal(&integ, &cur, &zeta).unwrap();
                let prop = evaluated(&integ, &next);
                let zeta_r = reverse(&integ, &cur, &prop);
                let back = proposal(&integ, &prop, &zeta_r).unwrap();
                let scale = w.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
                for (a, b) in w.iter().flatten().zip(back.iter().flatten()) {
                    assert!(
                        (a - b).abs() < 1e-9 * scale,
                        "dims {dims} ratio {ratio}: {a} vs {b}"
                    );
                }
                // The reverse of the reverse noise is the forward noise.
                let zeta_rr = reverse(&integ, &prop, &cur);
                for (a, b) in zeta.iter().flatten().zip(zeta_rr.iter().flatten()) {
                    assert!((a - b).abs() < 1e-7 * (1.0 + a.abs()), "{a} vs {b}");
                }
                let mut buf = Vec::new();
                let fwd = integ.log_acceptance(&cur, &prop, &zeta, &mut buf);
                let rev = integ.log_acceptance(&prop, &cur, &zeta_r, &mut buf);
                assert!(fwd.is_finite() && fwd != 0.0, "ln alpha {fwd}");
                let oracle = dense_log_alpha(&m, dt, &w, &next);
                assert!(
                    (fwd - oracle).abs() < 1e-6 * (1.0 + oracle.abs()),
                    "dims {dims} ratio {ratio}: ln alpha {fwd} vs dense oracle {oracle}"
                );
                assert!(
                    (fwd + rev).abs() < 1e-7,
                    "dims {dims} ratio {ratio}: ln alpha {fwd} and reverse {rev}"
                );
                // The tension really is in the proposal: A_w differs between the states.
                let (ld, ldp) = (cur.log_det.unwrap(), prop.log_det.unwrap());
                assert!(cur.force != prop.force && ld != ldp);
            }
        }
    }

    /// Counts heap allocations per thread (so that tests running in parallel do not
    /// disturb each other).
    mod counting {
        use std::alloc::{GlobalAlloc, Layout, System};
        use std::cell::Cell;

        thread_local! {
            static COUNT: Cell<u64> = const { Cell::new(0) };
        }

        fn count() {
            let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        }

        pub struct Counting;

        // SAFETY: forwards to the system allocator; counting touches only a
        // const-initialized thread-local without destructor (which does not allocate).
        unsafe impl GlobalAlloc for Counting {
            unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
                count();
                unsafe { System.alloc(layout) }
            }
            unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
                count();
                unsafe { System.alloc_zeroed(layout) }
            }
            unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
                count();
                unsafe { System.realloc(ptr, layout, new_size) }
            }
            unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
                unsafe { System.dealloc(ptr, layout) }
            }
        }

        #[global_allocator]
        static ALLOCATOR: Counting = Counting;

        /// Heap allocations made so far by this thread.
        pub fn allocations() -> u64 {
            COUNT.with(Cell::get)
        }
    }

    /// After construction (and the first step, which evaluates the initial state), a
    /// Metropolis, Crank–Nicolson or explicit (paper's, with its axial solve) step
    /// allocates nothing, with proposals both accepted
    /// and rejected; 2D and 3D, in tension and buckled.
    #[test]
    fn steps_do_not_allocate() {
        let probe = counting::allocations();
        std::hint::black_box(vec![1.0; 8]);
        assert!(counting::allocations() > probe, "the counter counts");
        for kind in [
            IntegratorKind::MetropolisCrankNicolson,
            IntegratorKind::CrankNicolson,
            IntegratorKind::EulerMaruyama,
        ] {
            for dims in [2, 3] {
                for ratio in [0.0, 6.0] {
                    let m = model(dims, ratio);
                    // The explicit scheme at half its stability limit 2/λ_max.
                    let dt = if kind == IntegratorKind::EulerMaruyama {
                        1.0 / m.beam().max_rate().unwrap()
                    } else {
                        0.05 * m.beam().params().tau1()
                    };
                    let mut integ =
                        NonlinearIntegrator::new(&m, kind, NoiseModel::Consistent, dt).unwrap();
                    let mut w = random_state(&m, 0.01, 40 + dims as u64);
                    let mut rng = trajectory_rng(SEED, 50 + dims as u64);
                    integ.step(&mut w, &mut rng);
                    let before = counting::allocations();
                    for _ in 0..2000 {
                        integ.step(&mut w, &mut rng);
                    }
                    let allocations = counting::allocations() - before;
                    assert_eq!(allocations, 0, "{kind} dims {dims} ratio {ratio}");
                    if kind == IntegratorKind::MetropolisCrankNicolson {
                        assert!(
                            integ.accepted > 0 && integ.accepted < integ.proposed,
                            "{kind} dims {dims} ratio {ratio}: {} of {} accepted",
                            integ.accepted,
                            integ.proposed
                        );
                    }
                }
            }
        }
    }

    /// With the stretching switched off (EA tiny, ε = 0) the Metropolis proposal is the
    /// exact Crank–Nicolson step for a Gaussian target that it leaves invariant, so every
    /// proposal must be accepted (up to round-off in log α).
    #[test]
    fn metropolis_accepts_everything_for_the_linear_problem() {
        let p = FilamentParams {
            stretch_rigidity: 1e-12,
            ..FilamentParams::default()
        };
        let beam = BeamModel::new(p, Mesh::uniform(1.0, 6).unwrap()).unwrap();
        let m = CompressedFilament::new(beam, 3, 0.0).unwrap();
        let mut integ = NonlinearIntegrator::new(
            &m,
            IntegratorKind::MetropolisCrankNicolson,
            NoiseModel::Consistent,
            0.05 * p.tau1(),
        )
        .unwrap();
        let mut w = vec![vec![0.0; m.beam().n_dofs()]; 2];
        let mut rng = trajectory_rng(SEED, 99);
        for _ in 0..2000 {
            integ.step(&mut w, &mut rng);
        }
        assert_eq!(integ.accepted, integ.proposed);
    }
}
