//! Linear integrators stepped in the generalized modes of `(K, C)`: the O(n) form of any
//! linear integrator once the modes are known without a dense transform (the separable
//! modes of a uniform simply supported or periodic plate, the paired modes of a uniform
//! hinged beam).
//!
//! In the C-orthonormal generalized modes every linear integrator of this crate is
//! `q_{k+1,i} = m_i q_{k,i} + g_i (Φᵀζ_k)_i` ([`IntegratorKind::modal_form`]). With
//! consistent noise (`Σ_ζ = C`) the modal noise `Φᵀζ` has the identity covariance
//! (`ΦᵀCΦ = I`), so it is drawn directly as `n` independent standard normals: a step costs
//! `n` normals and `2n` flops, and its law is exactly the [`DiscreteLaw`](super::DiscreteLaw)
//! of the nodal scheme (the same `m_i`, `g_i`, `Σ_q = I`). The nodal θ-schemes on the
//! banded matrices ([`super::ThetaScheme`]) stay the general path and its cross-check.

use super::IntegratorKind;
use super::integrator::{Integrator, THETA_SUGGESTION, check_dt, check_stability};
use crate::error::{Error, Result};
use crate::fem::noise::standard_normal;
use crate::rng::TrajectoryRng;

/// One step of a linear integrator in modal coordinates with consistent noise (see the
/// module docs); the state is the vector of modal amplitudes `q`.
#[derive(Debug, Clone)]
pub struct ModalStep {
    multipliers: Vec<f64>,
    gains: Vec<f64>,
}

impl ModalStep {
    /// The step of `kind` at `dt` for modes of rates `rates` (ascending or not) at thermal
    /// energy `kt`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `dt` is not finite and positive, a rate is not finite
    /// and positive, or `kind` is the Metropolis scheme (nonlinear problems only);
    /// [`Error::UnstableTimeStep`] for an explicit scheme at or above its stability limit
    /// for the largest rate.
    pub fn new(kind: IntegratorKind, rates: &[f64], dt: f64, kt: f64) -> Result<Self> {
        check_dt(dt)?;
        if kind == IntegratorKind::MetropolisCrankNicolson {
            return Err(Error::invalid(
                "integrator",
                kind,
                IntegratorKind::list(&IntegratorKind::LINEAR),
            ));
        }
        if let Some(i) = rates.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(Error::invalid(
                format!("rate of mode {i}"),
                rates[i],
                "finite and > 0",
            ));
        }
        let max_rate = rates.iter().copied().fold(0.0, f64::max);
        check_stability(kind, dt, max_rate, THETA_SUGGESTION)?;
        let (multipliers, gains) = rates.iter().map(|&r| kind.modal_form(r, dt, kt)).unzip();
        Ok(ModalStep { multipliers, gains })
    }

    /// Number of modes.
    pub fn len(&self) -> usize {
        self.multipliers.len()
    }

    /// Whether there are no modes.
    pub fn is_empty(&self) -> bool {
        self.multipliers.is_empty()
    }

    /// The one-step multipliers `m_i`.
    pub fn multipliers(&self) -> &[f64] {
        &self.multipliers
    }

    /// The noise gains `g_i`.
    pub fn gains(&self) -> &[f64] {
        &self.gains
    }

    /// This step with every noise gain × `factor` (an injected fault, [`crate::fault`]).
    #[cfg(any(test, feature = "faults"))]
    pub(crate) fn with_scaled_gains(mut self, factor: f64) -> Self {
        self.gains.iter_mut().for_each(|g| *g *= factor);
        self
    }
}

impl Integrator for ModalStep {
    /// `q_i ← m_i q_i + g_i z_i`, `z_i` standard normals drawn in mode order.
    ///
    /// # Panics
    /// If `state.len()` differs from the number of modes.
    fn step(&mut self, state: &mut [f64], rng: &mut TrajectoryRng) {
        assert_eq!(
            state.len(),
            self.multipliers.len(),
            "ModalStep: wrong state length"
        );
        for ((q, m), g) in state.iter_mut().zip(&self.multipliers).zip(&self.gains) {
            *q = m * *q + g * standard_normal(rng);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{DiscreteLaw, ThetaScheme};
    use crate::fem::modal::generalized_modes;
    use crate::fem::noise::NoiseModel;
    use crate::fem::{BeamModel, Mesh};
    use crate::params::FilamentParams;
    use crate::rng::trajectory_rng;
    use nalgebra::DVector;

    /// The modal step is the nodal scheme in modal coordinates: (i) without noise
    /// (kT → 0 is not allowed, so the noise is removed by comparing the mean map), one
    /// nodal θ-step of `w = Φq` equals `Φ(m ∘ q)` to round-off for every θ-scheme; (ii) its
    /// stationary variance `g²/(1 − m²)` is the discrete law's under consistent noise.
    #[test]
    fn is_the_nodal_scheme_in_modal_coordinates() {
        let params = FilamentParams::default();
        let beam = BeamModel::new(params, Mesh::uniform(1.0, 6).unwrap()).unwrap();
        let gm = generalized_modes(&beam).unwrap();
        let rates: Vec<f64> = gm.rates.iter().copied().collect();
        let dt = 0.4 / rates[rates.len() - 1];
        for kind in [
            IntegratorKind::EulerMaruyama,
            IntegratorKind::BackwardEuler,
            IntegratorKind::CrankNicolson,
        ] {
            let ms = ModalStep::new(kind, &rates, dt, params.kt).unwrap();
            let law = DiscreteLaw::new(&beam, &gm, kind, NoiseModel::Consistent, dt).unwrap();
            for i in 0..ms.len() {
                let (m, g) = (ms.multipliers()[i], ms.gains()[i]);
                let v = g * g / (1.0 - m * m);
                assert!(
                    (v - law.mode_variance(i)).abs() <= 1e-12 * v,
                    "{kind} mode {i}"
                );
            }
            // The mean map: two nodal steps from the same state with the same noise
            // differ only by the map applied to the difference of their states.
            let q = DVector::from_fn(ms.len(), |i, _| 1.0 / (1.0 + i as f64));
            let w = &gm.vectors * &q;
            let mut a: Vec<f64> = w.iter().copied().collect();
            let mut b = vec![0.0; a.len()];
            let mut scheme =
                ThetaScheme::new(&beam, NoiseModel::Consistent, kind.theta().unwrap(), dt).unwrap();
            scheme.step(&mut a, &mut trajectory_rng(1, 2));
            scheme.step(&mut b, &mut trajectory_rng(1, 2));
            let diff = DVector::from_iterator(a.len(), a.iter().zip(&b).map(|(x, y)| x - y));
            let expect =
                &gm.vectors * DVector::from_fn(ms.len(), |i, _| ms.multipliers()[i] * q[i]);
            let err = (&diff - &expect).amax();
            assert!(err <= 1e-10 * expect.amax(), "{kind}: {err:e}");
        }
    }

    #[test]
    fn refuses_bad_inputs() {
        let ok = [1.0, 2.0];
        assert!(ModalStep::new(IntegratorKind::CrankNicolson, &ok, 0.0, 1.0).is_err());
        assert!(ModalStep::new(IntegratorKind::CrankNicolson, &[1.0, 0.0], 0.1, 1.0).is_err());
        assert!(ModalStep::new(IntegratorKind::MetropolisCrankNicolson, &ok, 0.1, 1.0).is_err());
        assert!(matches!(
            ModalStep::new(IntegratorKind::EulerMaruyama, &ok, 1.0, 1.0),
            Err(Error::UnstableTimeStep { .. })
        ));
        assert!(ModalStep::new(IntegratorKind::EulerMaruyama, &ok, 0.9, 1.0).is_ok());
    }
}
