//! The [`Integrator`] trait and its implementations.

use super::{Family, IntegratorKind};
use crate::error::{Error, Result};
use crate::fem::banded::{BandedCholesky, RowTerm, SymBanded};
use crate::fem::modal::GeneralizedModes;
use crate::fem::noise::{NoiseGenerator, NoiseModel, NoiseStream, standard_normal};
use crate::fem::system::LinearSystem;
use crate::rng::TrajectoryRng;
use nalgebra::{DMatrix, DVector};

/// One step of a stochastic time integrator for the linear filament.
pub trait Integrator: Send {
    /// Advances `state` (the free degrees of freedom of one transverse component) by one
    /// time step, drawing its noise from `rng`.
    fn step(&mut self, state: &mut [f64], rng: &mut TrajectoryRng);
}

impl<I: Integrator + ?Sized> Integrator for Box<I> {
    fn step(&mut self, state: &mut [f64], rng: &mut TrajectoryRng) {
        (**self).step(state, rng);
    }
}

/// The stable integrators named when an explicit step is refused.
pub(super) const THETA_SUGGESTION: &str =
    "crank-nicolson (O(n), exact stationary variance) or exact-modal";

/// The step-size refusal shared by the linear and the nonlinear integrators (with
/// [`check_stability`]): `dt` must be finite and positive.
///
/// # Errors
/// [`Error::InvalidParameter`] otherwise.
pub(super) fn check_dt(dt: f64) -> Result<()> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::invalid("dt", dt, "finite and > 0"));
    }
    Ok(())
}

/// The stability half of the shared step-size refusal: `dt` must lie below
/// [`IntegratorKind::stability_limit`] for the fastest rate `max_rate` (the amplification
/// factor of the fastest mode reaches −1 there; `suggestion` names stable alternatives),
/// and below [`IntegratorKind::rounding_limit`] (where Crank–Nicolson's multiplier of the
/// fastest mode rounds to −1).
///
/// # Errors
/// [`Error::UnstableTimeStep`] at or above either limit.
pub(crate) fn check_stability(
    kind: IntegratorKind,
    dt: f64,
    max_rate: f64,
    suggestion: &str,
) -> Result<()> {
    let refuse = |limit: f64, bound: &str, suggestion: String| Error::UnstableTimeStep {
        integrator: kind.name().to_string(),
        dt,
        limit,
        bound: bound.to_string(),
        suggestion,
    };
    if let Some(limit) = kind.stability_limit(max_rate)
        && dt >= limit
    {
        let instead = format!("a stable integrator such as {suggestion}");
        let bound = format!("the stability limit 2/lambda_max of {kind}");
        return Err(refuse(limit, &bound, instead));
    }
    if let Some(limit) = kind.rounding_limit(max_rate)
        && dt >= limit
    {
        let bound = format!(
            "the step at which the multiplier (1 - a/2)/(1 + a/2) of {kind}'s fastest mode, a = lambda_max dt, rounds to -1 in double precision and that mode stops decaying"
        );
        return Err(refuse(
            limit,
            &bound,
            "backward-euler or exact-modal (their multipliers tend to 0 on stiff modes), or a mesh with a smaller lambda_max (fewer elements, a milder mesh.grading)".into(),
        ));
    }
    Ok(())
}

/// θ-scheme `(C + θΔtK) w_{k+1} = (C − (1−θ)ΔtK) w_k + sqrt(2kTΔt) ζ_k`: θ = 0 is
/// Euler–Maruyama (the paper's step iii), θ = ½ Crank–Nicolson, θ = 1 backward Euler.
/// One banded mat-vec and one banded solve per step: O(n), allocation-free.
///
/// A step is two sweeps: the forward one forms row `i` of the right-hand side (the banded
/// product, then the noise `ζ_i`, drawn as the sweep reaches it) and immediately the
/// forward substitution of the factor of the left-hand side
/// ([`BandedCholesky::solve_lower_product`] with [`NoiseGenerator::stream`]); the
/// backward one the back substitution into the state
/// ([`BandedCholesky::solve_upper_into`]). The floating-point operations, and the random
/// draws, are those of the unfused sequence product, draw, scale-add, solve.
pub struct ThetaScheme {
    lhs: BandedCholesky,
    rhs: SymBanded,
    scale: f64,
    noise: NoiseGenerator,
    /// The forward-substituted right-hand side `L⁻¹ b`.
    buf: Vec<f64>,
    /// Scratch space of the noise stream.
    scratch: Vec<f64>,
}

impl ThetaScheme {
    /// Builds the scheme for `system`, noise `noise` and step `dt`.
    ///
    /// # Errors
    /// A factorization failure (non-positive-definite left-hand side).
    pub fn new(system: &LinearSystem, noise: NoiseModel, theta: f64, dt: f64) -> Result<Self> {
        let ThetaOperators {
            lhs,
            rhs,
            scale,
            noise,
        } = ThetaOperators::new(system, noise, theta, dt)?;
        let n = system.n_dofs();
        Ok(ThetaScheme {
            lhs,
            rhs,
            scale,
            noise,
            buf: vec![0.0; n],
            scratch: vec![0.0; n],
        })
    }
}

/// What a θ-step is made of, for one trajectory ([`ThetaScheme`]) or a batch
/// ([`ThetaBatch`](super::ThetaBatch)): the factor of `C + θΔtK`, the matrix
/// `C − (1−θ)ΔtK`, the noise scale `sqrt(2kTΔt)` and the noise generator.
pub(super) struct ThetaOperators {
    pub(super) lhs: BandedCholesky,
    pub(super) rhs: SymBanded,
    pub(super) scale: f64,
    pub(super) noise: NoiseGenerator,
}

impl ThetaOperators {
    /// The operators for `system`, noise `noise`, parameter `theta` and step `dt`.
    ///
    /// # Errors
    /// A factorization failure (non-positive-definite left-hand side).
    pub(super) fn new(
        system: &LinearSystem,
        noise: NoiseModel,
        theta: f64,
        dt: f64,
    ) -> Result<Self> {
        let (k, c) = (system.stiffness(), system.damping());
        Ok(ThetaOperators {
            lhs: SymBanded::linear_combination(1.0, c, theta * dt, k)?.cholesky()?,
            rhs: SymBanded::linear_combination(1.0, c, -(1.0 - theta) * dt, k)?,
            scale: (2.0 * system.kt() * dt).sqrt(),
            noise: NoiseGenerator::new(noise, system)?,
        })
    }
}

impl Integrator for ThetaScheme {
    fn step(&mut self, state: &mut [f64], rng: &mut TrajectoryRng) {
        let scale = self.scale;
        match self.noise.lower_factor() {
            Some(l) => self.lhs.solve_lower_product_noise(
                &self.rhs,
                state,
                l,
                scale,
                #[inline(always)]
                || standard_normal(rng),
                &mut self.scratch,
                &mut self.buf,
            ),
            None => {
                let zeta = self.noise.stream(rng, &mut self.scratch);
                let term = ScaledNoise { zeta, scale };
                self.lhs
                    .solve_lower_product(&self.rhs, state, term, &mut self.buf);
            }
        }
        self.lhs.solve_upper_into(&self.buf, state);
    }
}

/// `g_i = scale·ζ_i` from a noise stream, drawn block by block.
struct ScaledNoise<'a> {
    zeta: NoiseStream<'a, TrajectoryRng>,
    scale: f64,
}

impl RowTerm for ScaledNoise<'_> {
    #[inline(always)]
    fn term(&mut self, _i: usize) -> f64 {
        // the sweep prepares every row before requesting it
        self.scale * self.zeta.next_prepared()
    }
    #[inline]
    fn prepare(&mut self, end: usize) {
        self.zeta.prepare(end);
    }
}

/// Exact Ornstein–Uhlenbeck transition of every generalized mode of (K, C):
/// `w_{k+1} = Φ diag(e^{−λΔt}) ΦᵀC w_k + Φ diag(g) Φᵀ ζ_k`, `g = sqrt(kT(1−e^{−2λΔt})/λ)`.
/// With consistent noise (`Φᵀζ ~ N(0, I)`) this is the exact transition law of the
/// semi-discrete system for any Δt. Two dense mat-vecs per step: O(n²).
pub struct ExactModal {
    propagator: DMatrix<f64>,
    noise_map: DMatrix<f64>,
    noise: NoiseGenerator,
    state: DVector<f64>,
    zeta: DVector<f64>,
    out: DVector<f64>,
}

impl ExactModal {
    /// Builds the exact modal update from the generalized modes of `system`.
    ///
    /// # Errors
    /// Propagates noise-generator construction errors.
    pub fn new(
        system: &LinearSystem,
        modes: &GeneralizedModes,
        noise: NoiseModel,
        dt: f64,
    ) -> Result<Self> {
        let n = system.n_dofs();
        let kt = system.kt();
        let phi = &modes.vectors;
        let c = system.damping().to_dense();
        let mut phi_m = phi.clone();
        let mut phi_g = phi.clone();
        for (i, &rate) in modes.rates.iter().enumerate() {
            let (m, g) = IntegratorKind::ExactModal.modal_form(rate, dt, kt);
            phi_m.column_mut(i).scale_mut(m);
            phi_g.column_mut(i).scale_mut(g);
        }
        Ok(ExactModal {
            propagator: phi_m * phi.transpose() * c,
            noise_map: phi_g * phi.transpose(),
            noise: NoiseGenerator::new(noise, system)?,
            state: DVector::zeros(n),
            zeta: DVector::zeros(n),
            out: DVector::zeros(n),
        })
    }
}

impl Integrator for ExactModal {
    fn step(&mut self, state: &mut [f64], rng: &mut TrajectoryRng) {
        self.state.as_mut_slice().copy_from_slice(state);
        self.noise.draw(rng, self.zeta.as_mut_slice());
        self.out.gemv(1.0, &self.propagator, &self.state, 0.0);
        self.out.gemv(1.0, &self.noise_map, &self.zeta, 1.0);
        state.copy_from_slice(self.out.as_slice());
    }
}

/// Builds an integrator of kind `kind` for `system` with noise `noise` and step `dt`.
///
/// `max_rate` is the largest generalized eigenvalue λ_max of (K, C), used for the
/// stability limit of explicit schemes; `modes` are needed by `exact-modal` only.
///
/// # Errors
/// [`Error::InvalidParameter`] if `dt` is not finite and positive;
/// [`Error::UnstableTimeStep`] if `dt` is at or above the stability limit of an explicit
/// scheme (the message gives the limit and names a stable integrator);
/// [`Error::InvalidParameter`] if `exact-modal` is requested without modes.
pub fn build_integrator(
    kind: IntegratorKind,
    system: &LinearSystem,
    noise: NoiseModel,
    dt: f64,
    max_rate: f64,
    modes: Option<&GeneralizedModes>,
) -> Result<Box<dyn Integrator>> {
    check_dt(dt)?;
    let suggestion = THETA_SUGGESTION;
    Ok(match kind.family() {
        Family::Metropolis => {
            return Err(Error::invalid(
                "integrator",
                kind,
                format!(
                    "{} for the linear filament \
                     (metropolis-crank-nicolson is for the nonlinear one; on the linear problem it equals crank-nicolson)",
                    IntegratorKind::list(&IntegratorKind::LINEAR)
                ),
            ));
        }
        Family::Theta(theta) => {
            check_stability(kind, dt, max_rate, suggestion)?;
            Box::new(ThetaScheme::new(system, noise, theta, dt)?)
        }
        Family::ExactModal => {
            check_stability(kind, dt, max_rate, suggestion)?;
            let Some(modes) = modes else {
                return Err(Error::invalid(
                    "modes",
                    "none",
                    "the generalized modes of the system (required by exact-modal)",
                ));
            };
            Box::new(ExactModal::new(system, modes, noise, dt)?)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::fem::Mesh;
    use crate::fem::beam::BeamModel;
    use crate::rng::trajectory_rng;

    /// The θ-step as separate passes (product, whole-vector draw, scale-add, solve, copy):
    /// the reference for the fused sweeps of [`ThetaScheme::step`].
    fn unfused_step(s: &mut ThetaScheme, state: &mut [f64], rng: &mut TrajectoryRng) {
        let n = state.len();
        let (mut buf, mut zeta) = (vec![0.0; n], vec![0.0; n]);
        s.rhs.mul_vec(state, &mut buf);
        s.noise.draw(rng, &mut zeta);
        for (b, z) in buf.iter_mut().zip(&zeta) {
            *b += s.scale * z;
        }
        s.lhs.solve_in_place(&mut buf);
        state.copy_from_slice(&buf);
    }

    /// The fused step is bit-identical to the unfused passes, for every θ and noise model,
    /// over many steps and several mesh sizes (trajectories compared bit for bit).
    #[test]
    fn fused_theta_step_is_bit_identical_to_unfused_passes() {
        let params = FilamentParams::default();
        for ne in [1, 2, 3, 7, 40] {
            let beam = BeamModel::new(params, Mesh::uniform(params.length, ne).unwrap()).unwrap();
            let dt = 0.5 / beam.max_rate().unwrap();
            for noise in NoiseModel::ALL {
                for theta in [0.0, 0.5, 1.0] {
                    let mut fused = ThetaScheme::new(&beam, noise, theta, dt).unwrap();
                    let mut reference = ThetaScheme::new(&beam, noise, theta, dt).unwrap();
                    let n = beam.n_dofs();
                    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
                    let (mut ra, mut rb) =
                        (trajectory_rng(5, ne as u64), trajectory_rng(5, ne as u64));
                    for step in 0..200 {
                        fused.step(&mut a, &mut ra);
                        unfused_step(&mut reference, &mut b, &mut rb);
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&a), bits(&b), "{noise} θ={theta} N={ne} step {step}");
                    }
                }
            }
        }
    }
}
