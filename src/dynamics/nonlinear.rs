//! Finite deflection: the von Kármán filament under imposed end-shortening, with the axial
//! displacement u as the fast variable (the paper's steps i–iii).
//!
//! Energy of the discretized filament (Hermite cubic w, and v in 3D; linear u):
//!
//! ```text
//! U = Σ_e ∫_e [ EA/2 (u'_e + s_e)² ] dx + ½ Σ_c w_cᵀ K w_c,   s_e = (1/2h_e) ∫_e (w'² + v'²) dx
//! ```
//!
//! The stretching term uses the element-mean von Kármán strain `u'_e + s_e` (u' is constant
//! on a linear element; the cubic w'² is replaced by its element mean), i.e. the stretching
//! energy is integrated with the element's mean strain. With this energy, axial
//! equilibrium at fixed w (step i, [`CompressedFilament::axial_equilibrium`]) gives a
//! uniform axial force, exactly as in the continuum:
//!
//! ```text
//! N = (EA/L)(−Δ + ½ ∫ w'² dx) = EA (s − ε),   s = wᵀG w/(2L),  ε = Δ/L,
//! ```
//!
//! and, u eliminated, `U(w) = ½ wᵀK w + (EA·L/2)(s − ε)²`, whose force on w is
//! `−∂U/∂w = −K w + F G w` with the compressive force `F = −N = EA(ε − s)`. The exact
//! equilibrium theory ([`crate::theory::compression`]) uses the same energy.
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

use super::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::banded::{BandedCholesky, SymBanded};
use crate::fem::beam::BeamModel;
use crate::fem::hermite::geometric_matrix;
use crate::fem::noise::{NoiseGenerator, NoiseModel};
use crate::rng::TrajectoryRng;
use rand::RngExt;

/// The filament with imposed end-shortening: model and energy.
#[derive(Debug, Clone)]
pub struct CompressedFilament {
    beam: BeamModel,
    components: usize,
    strain: f64,
}

/// Result of the axial equilibrium solve (step i).
#[derive(Debug, Clone, PartialEq)]
pub struct AxialSolution {
    /// Nodal axial displacements u_0 = 0, …, u_N = −Δ.
    pub u: Vec<f64>,
    /// Axial force N per element (tension positive); uniform at equilibrium.
    pub element_force: Vec<f64>,
}

impl CompressedFilament {
    /// A filament on `beam` with `dims` = 2 (w) or 3 (w, v) and imposed nominal strain
    /// `strain` = Δ/L (compression positive).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for dims other than 2 or 3 or a non-finite strain.
    pub fn new(beam: BeamModel, dims: usize, strain: f64) -> Result<Self> {
        if dims != 2 && dims != 3 {
            return Err(Error::invalid("dims", dims, "2 or 3"));
        }
        if !strain.is_finite() {
            return Err(Error::invalid("strain", strain, "finite"));
        }
        Ok(CompressedFilament {
            beam,
            components: dims - 1,
            strain,
        })
    }

    /// The linear beam model (K, C, G).
    pub fn beam(&self) -> &BeamModel {
        &self.beam
    }

    /// Number of transverse components (1 in 2D, 2 in 3D).
    pub fn components(&self) -> usize {
        self.components
    }

    /// Imposed nominal strain ε = Δ/L.
    pub fn strain(&self) -> f64 {
        self.strain
    }

    /// Stored length per unit length `s = Σ_c w_cᵀ G w_c/(2L) = (1/2L)∫(w'² + v'²) dx`.
    pub fn stored_length(&self, w: &[Vec<f64>]) -> f64 {
        let g = self.beam.geometric();
        w.iter().map(|c| g.quadratic_form(c)).sum::<f64>() / (2.0 * self.beam.params().length)
    }

    /// Compressive force `F = EA(ε − s)` for stored length `s`.
    pub fn compressive_force(&self, s: f64) -> f64 {
        self.beam.params().stretch_rigidity * (self.strain - s)
    }

    /// Total energy with u eliminated: `½ Σ wᵀK w + (EA·L/2)(s − ε)²`.
    pub fn energy(&self, w: &[Vec<f64>]) -> f64 {
        let p = self.beam.params();
        let k = self.beam.stiffness();
        let bend: f64 = w.iter().map(|c| 0.5 * k.quadratic_form(c)).sum();
        let d = self.stored_length(w) - self.strain;
        bend + 0.5 * p.stretch_rigidity * p.length * d * d
    }

    /// Internal force `−∂U/∂w = −K w + F G w` per component, written to `out`.
    pub fn internal_force(&self, w: &[Vec<f64>], out: &mut [Vec<f64>]) {
        let f = self.compressive_force(self.stored_length(w));
        let mut gw = vec![0.0; self.beam.n_dofs()];
        for (c, o) in w.iter().zip(out.iter_mut()) {
            self.beam.stiffness().mul_vec(c, o);
            self.beam.geometric().mul_vec(c, &mut gw);
            for (oi, gi) in o.iter_mut().zip(&gw) {
                *oi = -*oi + f * gi;
            }
        }
    }

    /// Step (i) of the paper: with w fixed, solve axial equilibrium for the linear-element
    /// axial displacement with u(0) = 0, u(L) = −Δ. Element e has energy
    /// `(EA h_e/2)(u'_e + s_e)²`; stationarity at interior nodes is the tridiagonal system
    /// `(EA/h_{e−1})(u_e − u_{e−1}) − (EA/h_e)(u_{e+1} − u_e) = EA(s_e − s_{e−1})` (node e), solved
    /// by the Thomas algorithm in O(N).
    pub fn axial_equilibrium(&self, w: &[Vec<f64>]) -> AxialSolution {
        let mesh = self.beam.mesh();
        let ne = mesh.n_elements();
        let ea = self.beam.params().stretch_rigidity;
        let delta = self.strain * mesh.length();
        // Element-mean half squared slope s_e.
        let s: Vec<f64> = (0..ne)
            .map(|e| {
                let h = mesh.element_length(e);
                let g = geometric_matrix(h);
                let dofs = self.beam.element_dofs(e);
                let mut acc = 0.0;
                for c in w {
                    let loc: Vec<f64> = dofs.iter().map(|d| d.map_or(0.0, |i| c[i])).collect();
                    for a in 0..4 {
                        for b in 0..4 {
                            acc += loc[a] * g[a][b] * loc[b];
                        }
                    }
                }
                acc / (2.0 * h)
            })
            .collect();
        let mut u = vec![0.0; ne + 1];
        u[ne] = -delta;
        let m = ne - 1; // interior unknowns u_1..u_{N-1}
        if m > 0 {
            let k: Vec<f64> = (0..ne).map(|e| ea / mesh.element_length(e)).collect();
            // Row i (node i+1): −k_i u_i + (k_i + k_{i+1}) u_{i+1} − k_{i+1} u_{i+2} = EA(s_{i+1} − s_i).
            let mut diag: Vec<f64> = (0..m).map(|i| k[i] + k[i + 1]).collect();
            let mut rhs: Vec<f64> = (0..m).map(|i| ea * (s[i + 1] - s[i])).collect();
            rhs[m - 1] += k[ne - 1] * u[ne];
            for i in 1..m {
                let f = -k[i] / diag[i - 1];
                diag[i] -= f * -k[i];
                rhs[i] -= f * rhs[i - 1];
            }
            u[m] = rhs[m - 1] / diag[m - 1];
            for i in (1..m).rev() {
                u[i] = (rhs[i - 1] + k[i] * u[i + 1]) / diag[i - 1];
            }
        }
        let element_force = (0..ne)
            .map(|e| ea * ((u[e + 1] - u[e]) / mesh.element_length(e) + s[e]))
            .collect();
        AxialSolution { u, element_force }
    }
}

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
/// state).
#[derive(Debug, Clone)]
struct MhEvaluation {
    state: Vec<Vec<f64>>,
    energy: f64,
    force: f64,
    cw: Vec<Vec<f64>>,
    kw: Vec<Vec<f64>>,
    gw: Vec<Vec<f64>>,
    lhs: Option<(BandedCholesky, f64)>,
}

/// A time integrator for [`CompressedFilament`].
pub struct NonlinearIntegrator {
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
    /// Metropolis: the evaluated current state of the chain.
    mh_current: Option<MhEvaluation>,
    scratch: [Vec<f64>; 3],
    /// Proposals made (Metropolis only).
    pub proposed: u64,
    /// Accepted proposals (Metropolis only).
    pub accepted: u64,
}

impl NonlinearIntegrator {
    /// Builds integrator `kind` (euler-maruyama, backward-euler, crank-nicolson or
    /// metropolis-crank-nicolson) with step `dt` and noise model `noise`.
    ///
    /// # Errors
    /// [`Error::UnstableTimeStep`] for euler-maruyama above the linear stability limit
    /// 2/λ_max; [`Error::InvalidParameter`] for exact-modal (not available for the
    /// nonlinear filament) or for Metropolis with element-uniform noise (its proposal
    /// density is singular).
    pub fn new(
        model: &CompressedFilament,
        kind: IntegratorKind,
        noise: NoiseModel,
        dt: f64,
    ) -> Result<Self> {
        let beam = model.beam();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid("dt", dt, "finite and > 0"));
        }
        let scheme = match kind {
            IntegratorKind::MetropolisCrankNicolson => Scheme::Metropolis,
            k => match k.theta() {
                Some(t) => Scheme::Theta(t),
                None => {
                    return Err(Error::invalid(
                        "integrator",
                        k,
                        "euler-maruyama, backward-euler, crank-nicolson or metropolis-crank-nicolson for the nonlinear filament",
                    ));
                }
            },
        };
        if scheme == Scheme::Metropolis && noise != NoiseModel::Consistent {
            return Err(Error::invalid(
                "noise",
                noise.name(),
                "consistent for metropolis-crank-nicolson (the element-uniform proposal density is singular)",
            ));
        }
        if let Some(limit) = kind.stability_limit(beam.max_rate()?)
            && dt >= limit
        {
            return Err(Error::UnstableTimeStep {
                integrator: kind.name().to_string(),
                dt,
                limit,
                suggestion: "metropolis-crank-nicolson (exact stationary law, stable at any dt)"
                    .to_string(),
            });
        }
        let theta = match scheme {
            Scheme::Theta(t) => t,
            Scheme::Metropolis => 0.5,
        };
        let (k, c) = (beam.stiffness(), beam.damping());
        let n = beam.n_dofs();
        let nc = model.components();
        Ok(NonlinearIntegrator {
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
            theta_buffers: ThetaBuffers::default(),
            mh_base: SymBanded::linear_combination(1.0, c, 0.5 * dt, k)?,
            mh_current: None,
            scratch: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
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
    fn evaluate(&mut self, model: &CompressedFilament, w: &[Vec<f64>], out: &mut ThetaBuffers) {
        let beam = model.beam();
        let p = beam.params();
        let nc = w.len();
        out.explicit.resize(nc, vec![0.0; beam.n_dofs()]);
        out.kw.resize(nc, vec![0.0; beam.n_dofs()]);
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
            -model.axial_equilibrium(w).element_force[0]
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

    /// Advances the state `w` (one vector per transverse component) by one step.
    pub fn step(
        &mut self,
        model: &CompressedFilament,
        w: &mut [Vec<f64>],
        rng: &mut TrajectoryRng,
    ) {
        if self.scheme == Scheme::Metropolis {
            self.step_metropolis(model, w, rng);
            return;
        }
        let mut buf = std::mem::take(&mut self.theta_buffers);
        self.evaluate(model, w, &mut buf);
        for z in &mut self.zeta {
            self.noise.draw(rng, z);
        }
        // The new state: (C + θΔtK) w' = explicit(w) + scale ζ, solved in place.
        for ((wc, rhs), zc) in w.iter_mut().zip(&mut buf.explicit).zip(&self.zeta) {
            for (v, z) in rhs.iter_mut().zip(zc) {
                *v += self.scale * z;
            }
            self.lhs.solve_in_place(rhs);
            wc.copy_from_slice(rhs);
        }
        self.theta_buffers = buf;
    }

    /// Evaluates a state of the Metropolis chain ([`MhEvaluation`]).
    fn evaluate_mh(&self, model: &CompressedFilament, w: &[Vec<f64>]) -> MhEvaluation {
        let beam = model.beam();
        let p = beam.params();
        let n = beam.n_dofs();
        let mut e = MhEvaluation {
            state: w.to_vec(),
            energy: 0.0,
            force: 0.0,
            cw: vec![vec![0.0; n]; w.len()],
            kw: vec![vec![0.0; n]; w.len()],
            gw: vec![vec![0.0; n]; w.len()],
            lhs: None,
        };
        let (mut two_l_s, mut bend) = (0.0, 0.0);
        for (c, wc) in w.iter().enumerate() {
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
        e.lhs = SymBanded::linear_combination(
            1.0,
            &self.mh_base,
            -0.5 * self.dt * e.force,
            beam.geometric(),
        )
        .and_then(|a| a.cholesky())
        .ok()
        .map(|l| {
            let log_det = l.log_det();
            (l, log_det)
        });
        e
    }

    /// The Metropolis proposal from `cur` with noise `zeta` (covariance C per component):
    /// `A_w w' = B_w w + sqrt(2kTΔt) ζ`, `B_w = C − ½Δt H_w`. `None` if `A_w` is not
    /// positive definite.
    fn propose(&self, cur: &MhEvaluation, zeta: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
        let (lhs, _) = cur.lhs.as_ref()?;
        let h = 0.5 * self.dt;
        Some(
            (0..cur.state.len())
                .map(|c| {
                    let mut next: Vec<f64> = (0..cur.cw[c].len())
                        .map(|i| {
                            cur.cw[c][i] - h * (cur.kw[c][i] - cur.force * cur.gw[c][i])
                                + self.scale * zeta[c][i]
                        })
                        .collect();
                    lhs.solve_in_place(&mut next);
                    next
                })
                .collect(),
        )
    }

    /// The noise of the reverse move `prop → cur`: `ζ_r = (A_{w'} w − B_{w'} w')/sqrt(2kTΔt)`.
    fn reverse_noise(&self, cur: &MhEvaluation, prop: &MhEvaluation) -> Vec<Vec<f64>> {
        let h = 0.5 * self.dt;
        let f = prop.force;
        (0..cur.state.len())
            .map(|c| {
                (0..cur.cw[c].len())
                    .map(|i| {
                        let a_w = cur.cw[c][i] + h * (cur.kw[c][i] - f * cur.gw[c][i]);
                        let b_wp = prop.cw[c][i] - h * (prop.kw[c][i] - f * prop.gw[c][i]);
                        (a_w - b_wp) / self.scale
                    })
                    .collect()
            })
            .collect()
    }

    /// `ln α` of the move `cur → prop` made with noise `zeta`:
    /// `−(U' − U)/kT + d (ln det A_{w'} − ln det A_w) − ½|ζ_r|²_{C⁻¹} + ½|ζ|²_{C⁻¹}`
    /// (d transverse components). `−∞` if `A_{w'}` is not positive definite.
    fn log_acceptance(
        &mut self,
        cur: &MhEvaluation,
        prop: &MhEvaluation,
        zeta: &[Vec<f64>],
    ) -> f64 {
        let (Some((_, ld)), Some((_, ld_p))) = (&cur.lhs, &prop.lhs) else {
            return f64::NEG_INFINITY;
        };
        let forward = self.noise_norm(zeta);
        let rev = self.reverse_noise(cur, prop);
        let backward = self.noise_norm(&rev);
        -(prop.energy - cur.energy) / self.kt + cur.state.len() as f64 * (ld_p - ld)
            - 0.5 * backward
            + 0.5 * forward
    }

    /// One Metropolis-adjusted step (see [`NonlinearIntegrator`]).
    fn step_metropolis(
        &mut self,
        model: &CompressedFilament,
        w: &mut [Vec<f64>],
        rng: &mut TrajectoryRng,
    ) {
        let cur = match self.mh_current.take() {
            Some(e) if e.state.as_slice() == &*w => e,
            _ => self.evaluate_mh(model, w),
        };
        for z in &mut self.zeta {
            self.noise.draw(rng, z);
        }
        let u: f64 = rng.random();
        self.proposed += 1;
        let zeta = std::mem::take(&mut self.zeta);
        let next = self
            .propose(&cur, &zeta)
            .filter(|n| n.iter().flatten().all(|v| v.is_finite()));
        let mut keep = cur;
        if let Some(next) = next {
            let prop = self.evaluate_mh(model, &next);
            let log_alpha = self.log_acceptance(&keep, &prop, &zeta);
            if log_alpha >= 0.0 || u < log_alpha.exp() {
                for (wc, nc) in w.iter_mut().zip(&prop.state) {
                    wc.copy_from_slice(nc);
                }
                keep = prop;
                self.accepted += 1;
            }
        }
        self.zeta = zeta;
        self.mh_current = Some(keep);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::Mesh;
    use crate::params::FilamentParams;
    use crate::rng::trajectory_rng;
    use rand_distr::StandardNormal;

    const SEED: u64 = 20261126;

    fn model(dims: usize, strain_ratio: f64) -> CompressedFilament {
        let p = FilamentParams {
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            ..FilamentParams::default()
        };
        let beam = BeamModel::new(p, Mesh::graded(1.0, 7, 2.0).unwrap()).unwrap();
        CompressedFilament::new(beam, dims, strain_ratio * p.euler_strain()).unwrap()
    }

    fn random_state(m: &CompressedFilament, scale: f64, index: u64) -> Vec<Vec<f64>> {
        let mut rng = trajectory_rng(SEED, index);
        (0..m.components())
            .map(|_| {
                (0..m.beam().n_dofs())
                    .map(|_| scale * rng.sample::<f64, _>(StandardNormal))
                    .collect()
            })
            .collect()
    }

    /// Internal force against central differences of the energy (style: check
    /// derivatives numerically). Graded mesh, 2D and 3D, buckled and stretched states.
    /// Tolerance: central differences with step 1e-6·|w| have relative error O(1e-9).
    #[test]
    fn internal_force_is_minus_energy_gradient() {
        for dims in [2, 3] {
            for ratio in [0.0, 3.0, 10.0] {
                let m = model(dims, ratio);
                let w = random_state(&m, 0.02, dims as u64);
                let mut f = vec![vec![0.0; m.beam().n_dofs()]; m.components()];
                m.internal_force(&w, &mut f);
                let scale = f.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
                for c in 0..m.components() {
                    for i in 0..m.beam().n_dofs() {
                        let h = 1e-6 * (1.0 + w[c][i].abs());
                        let mut wp = w.clone();
                        let mut wm = w.clone();
                        wp[c][i] += h;
                        wm[c][i] -= h;
                        let fd = -(m.energy(&wp) - m.energy(&wm)) / (2.0 * h);
                        assert!(
                            (fd - f[c][i]).abs() < 1e-6 * scale,
                            "dims {dims} ratio {ratio} dof {i}: fd {fd} analytic {}",
                            f[c][i]
                        );
                    }
                }
            }
        }
    }

    /// Step (i): the axial solve gives a uniform axial force equal to the closed form
    /// EA(s − ε), meets u(0) = 0 and u(L) = −Δ, and the stretching energy evaluated with
    /// the solved u equals (EA L/2)(s − ε)² (tolerance: round-off, 1e-9 relative).
    #[test]
    fn axial_equilibrium_matches_closed_form() {
        for dims in [2, 3] {
            let m = model(dims, 4.0);
            let w = random_state(&m, 0.03, 10 + dims as u64);
            let sol = m.axial_equilibrium(&w);
            let n = -m.compressive_force(m.stored_length(&w));
            for f in &sol.element_force {
                assert!(
                    (f - n).abs() < 1e-9 * n.abs().max(1.0),
                    "element force {f} vs {n}"
                );
            }
            assert_eq!(sol.u[0], 0.0);
            assert!((sol.u[sol.u.len() - 1] + m.strain()).abs() < 1e-15);
        }
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
                let cur = integ.evaluate_mh(&m, &w);
                let next = integ.propose(&cur, &zeta).unwrap();
                let prop = integ.evaluate_mh(&m, &next);
                let zeta_r = integ.reverse_noise(&cur, &prop);
                let back = integ.propose(&prop, &zeta_r).unwrap();
                let scale = w.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
                for (a, b) in w.iter().flatten().zip(back.iter().flatten()) {
                    assert!(
                        (a - b).abs() < 1e-9 * scale,
                        "dims {dims} ratio {ratio}: {a} vs {b}"
                    );
                }
                // The reverse of the reverse noise is the forward noise.
                let zeta_rr = integ.reverse_noise(&prop, &cur);
                for (a, b) in zeta.iter().flatten().zip(zeta_rr.iter().flatten()) {
                    assert!((a - b).abs() < 1e-7 * (1.0 + a.abs()), "{a} vs {b}");
                }
                let fwd = integ.log_acceptance(&cur, &prop, &zeta);
                let rev = integ.log_acceptance(&prop, &cur, &zeta_r);
                assert!(fwd.is_finite() && fwd != 0.0, "ln alpha {fwd}");
                // An independent oracle: the proposal densities from dense matrices,
                // ln q(a → b) = d ln det A_a − ½ Σ_c |A_a b_c − B_a a_c|²_{C⁻¹}/(2kTΔt),
                // and the energy from CompressedFilament::energy.
                let beam = m.beam();
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
                    a.len() as f64 * am.determinant().ln()
                        - 0.5 * norm / (2.0 * m.beam().params().kt * dt)
                };
                let oracle = -(m.energy(&next) - m.energy(&w)) / m.beam().params().kt
                    + log_q(&next, &w)
                    - log_q(&w, &next);
                assert!(
                    (fwd - oracle).abs() < 1e-6 * (1.0 + oracle.abs()),
                    "dims {dims} ratio {ratio}: ln alpha {fwd} vs dense oracle {oracle}"
                );
                assert!(
                    (fwd + rev).abs() < 1e-7,
                    "dims {dims} ratio {ratio}: ln alpha {fwd} and reverse {rev}"
                );
                // The tension really is in the proposal: A_w differs between the states.
                let (ld, ldp) = (cur.lhs.as_ref().unwrap().1, prop.lhs.as_ref().unwrap().1);
                assert!(cur.force != prop.force && ld != ldp);
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
            integ.step(&m, &mut w, &mut rng);
        }
        assert_eq!(integ.accepted, integ.proposed);
    }
}
