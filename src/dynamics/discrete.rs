//! The exact discrete references of a linear system under one integrator, noise model and
//! time step, whichever object assembled the system (filament or membrane).
//!
//! In the generalized modes of `(K, C)` every linear integrator is the per-mode recursion
//! `q_{k+1} = M q_k + G Φᵀζ_k` (`M = diag m`, `G = diag g`,
//! [`IntegratorKind::modal_form`]), driven by the modal noise covariance
//! `Σ_q = Φᵀ Σ_ζ Φ` (the identity for consistent noise, not for the paper's element-uniform
//! load, eq. 5). Hence, exactly:
//!
//! - the stationary covariance `S_ij = g_i g_j Σ_q,ij / (1 − m_i m_j)`
//!   ([`discrete_stationary_covariance`]);
//! - the discrete decay rate of mode `i`, `−ln(m_i)/Δt` (for `m_i > 0`);
//! - from rest, the covariance after `k` steps
//!   `S_k,ij = g_i g_j Σ_q,ij (1 − (m_i m_j)^k)/(1 − m_i m_j)`, and the two-time
//!   covariance `⟨q(η) q(t)ᵀ⟩ = diag(m^{η−t}) S_t` (the discrete eq. 4);
//! - at a point with modal probe `a_x = Φᵀ p_x` (`w(x) = p_xᵀ w`),
//!   `⟨w(x) w(y)⟩ = a_yᵀ S a_x`.

use crate::dynamics::IntegratorKind;
use crate::error::Result;
use crate::fem::modal::{GeneralizedModes, discrete_stationary_covariance, modal_noise_covariance};
use crate::fem::noise::{NoiseGenerator, NoiseModel};
use crate::fem::system::LinearSystem;
use nalgebra::{DMatrix, DVector};

/// The exact discrete-time law of a linear system's modal amplitudes under one integrator,
/// noise model and step (see the module docs).
#[derive(Debug, Clone)]
pub struct DiscreteLaw {
    /// Time step Δt.
    pub dt: f64,
    /// Thermal energy kT.
    pub kt: f64,
    /// Generalized rates `λ_i`, ascending (all modes).
    pub rates: Vec<f64>,
    /// One-step multipliers `m_i`.
    pub multipliers: Vec<f64>,
    /// Noise gains `g_i`.
    pub gains: Vec<f64>,
    /// Modal noise covariance `Σ_q = Φᵀ Σ_ζ Φ`.
    pub noise_covariance: DMatrix<f64>,
    /// Stationary modal covariance `S`.
    pub stationary: DMatrix<f64>,
}

impl DiscreteLaw {
    /// The law of `system` with generalized modes `modes` under `integrator`, `noise` and
    /// step `dt`.
    ///
    /// # Errors
    /// A noise-generator failure (non-positive-definite `C`); [`crate::Error::InvalidParameter`]
    /// naming the mode if the step is unstable for some mode (`|m| ≥ 1`).
    pub fn new(
        system: &LinearSystem,
        modes: &GeneralizedModes,
        integrator: IntegratorKind,
        noise: NoiseModel,
        dt: f64,
    ) -> Result<Self> {
        let kt = system.kt();
        let sigma_zeta = NoiseGenerator::new(noise, system)?.covariance();
        let noise_covariance = modal_noise_covariance(modes, &sigma_zeta);
        let (multipliers, gains): (Vec<f64>, Vec<f64>) = modes
            .rates
            .iter()
            .map(|&r| integrator.modal_form(r, dt, kt))
            .unzip();
        let stationary = discrete_stationary_covariance(&noise_covariance, &multipliers, &gains)?;
        Ok(DiscreteLaw {
            dt,
            kt,
            rates: modes.rates.iter().copied().collect(),
            multipliers,
            gains,
            noise_covariance,
            stationary,
        })
    }

    /// Stationary variance of modal amplitude `i` (0-based).
    pub fn mode_variance(&self, i: usize) -> f64 {
        self.stationary[(i, i)]
    }

    /// Equipartition's variance `kT/λ_i` of the discrete mode `i`.
    pub fn equipartition(&self, i: usize) -> f64 {
        self.kt / self.rates[i]
    }

    /// The discrete decay rate of mode `i` ([`decay_rate`]).
    pub fn decay_rate(&self, i: usize) -> Option<f64> {
        decay_rate(self.multipliers[i], self.dt)
    }

    /// Stationary `⟨w(x) w(y)⟩ = a_yᵀ S a_x` for modal probes `a_x`, `a_y`.
    pub fn point_covariance(&self, ax: &DVector<f64>, ay: &DVector<f64>) -> f64 {
        (ay.transpose() * &self.stationary * ax)[(0, 0)]
    }

    /// `⟨w(x, t) w(y, η)⟩` from rest, `t = ts·Δt ≤ η = es·Δt`, for modal probes `ax` (at
    /// the earlier time) and `ay` (at the later): `a_yᵀ diag(m^{es−ts}) S_ts a_x`.
    pub fn two_time(&self, ts: u64, es: u64, ax: &DVector<f64>, ay: &DVector<f64>) -> f64 {
        let (m, g, sigma_q) = (&self.multipliers, &self.gains, &self.noise_covariance);
        let n = m.len();
        // `m_i m_j` is symmetric in (i, j) exactly, and so is its power: one `powf` per
        // pair, and one per mode for the decay `m_i^{es−ts}`.
        let decay: Vec<f64> = m.iter().map(|mi| mi.powf((es - ts) as f64)).collect();
        let mut st = DMatrix::zeros(n, n);
        for j in 0..n {
            for i in j..n {
                let mm = m[i] * m[j];
                let transient = if mm == 1.0 {
                    0.0
                } else {
                    1.0 - mm.powf(ts as f64)
                };
                let entry = |r: usize, c: usize| {
                    g[r] * g[c] * sigma_q[(r, c)] * transient / (1.0 - mm) * decay[r]
                };
                st[(i, j)] = entry(i, j);
                st[(j, i)] = entry(j, i);
            }
        }
        (ay.transpose() * &st * ax)[(0, 0)]
    }
}

/// The discrete decay rate `−ln(m)/Δt` of a mode of one-step multiplier `m`, `None` if
/// `m ≤ 0` (the mode alternates in sign and has no rate).
pub fn decay_rate(m: f64, dt: f64) -> Option<f64> {
    (m > 0.0).then(|| -m.ln() / dt)
}

/// The exact discrete law of one mode alone (the diagonal of [`DiscreteLaw`], module docs):
/// what a mode's variance and decay need, in O(1), for one mode of a mesh too large for
/// dense modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeLaw {
    /// One-step multiplier `m`.
    pub multiplier: f64,
    /// Stationary variance `g² Σ_q,ii / (1 − m²)` of the mode's amplitude.
    pub variance: f64,
    /// Equipartition's variance `kT/λ`.
    pub equipartition: f64,
    /// The discrete decay rate `−ln(m)/Δt`, `None` if `m ≤ 0`.
    pub decay_rate: Option<f64>,
}

impl ModeLaw {
    /// The law of a mode of generalized rate `rate` under `integrator` and step `dt` at
    /// temperature `kt`, driven by modal noise of variance `noise_variance` (`Σ_q,ii`: 1
    /// for consistent noise, the element-uniform ratio for the paper's load).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] if the step is unstable for the mode (`|m| ≥ 1`).
    pub fn new(
        rate: f64,
        noise_variance: f64,
        integrator: IntegratorKind,
        dt: f64,
        kt: f64,
    ) -> Result<Self> {
        let (m, g) = integrator.modal_form(rate, dt, kt);
        let s = discrete_stationary_covariance(
            &DMatrix::from_element(1, 1, noise_variance),
            &[m],
            &[g],
        )?;
        Ok(ModeLaw {
            multiplier: m,
            variance: s[(0, 0)],
            equipartition: kt / rate,
            decay_rate: decay_rate(m, dt),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::banded::SymBanded;
    use crate::fem::modal::generalized_modes_signed;
    use crate::fem::system::ElementLoad;

    /// One mode's law is the diagonal of the whole law, both noises, every integrator.
    #[test]
    fn one_mode_law_is_the_diagonal_of_the_whole() {
        use crate::fem::beam::BeamModel;
        use crate::fem::mesh::Mesh;
        use crate::fem::modal::generalized_modes;
        use crate::fem::noise::element_uniform_mode_ratio;
        let p = crate::params::FilamentParams::default();
        let beam = BeamModel::new(p, Mesh::uniform(p.length, 6).unwrap()).unwrap();
        let gm = generalized_modes(&beam).unwrap();
        let dt = 0.3 / gm.rates[0];
        for integrator in IntegratorKind::LINEAR {
            if integrator
                .stability_limit(gm.rates.max())
                .is_some_and(|l| dt >= l)
            {
                continue;
            }
            for noise in NoiseModel::ALL {
                let law = DiscreteLaw::new(&beam, &gm, integrator, noise, dt).unwrap();
                for i in 0..gm.rates.len() {
                    let sq = match noise {
                        NoiseModel::Consistent => 1.0,
                        NoiseModel::ElementUniform => {
                            let phi: Vec<f64> = gm.vectors.column(i).iter().copied().collect();
                            element_uniform_mode_ratio(&beam, &phi)
                        }
                    };
                    let one = ModeLaw::new(gm.rates[i], sq, integrator, dt, beam.kt()).unwrap();
                    // The dense ΦᵀΣ_ζΦ rounds at the scale of its largest entries (a stiff
                    // mode's element-uniform variance, ~1e-41, comes out as ~±1e-26
                    // there): compare at the slowest mode's scale.
                    let (a, b) = (one.variance, law.mode_variance(i));
                    let scale = law.mode_variance(0);
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "{integrator} {noise} {i}: {a} vs {b}"
                    );
                    assert!(a > 0.0, "{integrator} {noise} {i}: {a}");
                    assert_eq!(one.multiplier, law.multipliers[i]);
                    assert_eq!(one.equipartition, law.equipartition(i));
                    assert_eq!(one.decay_rate, law.decay_rate(i));
                }
            }
        }
        // An unstable step is refused.
        assert!(ModeLaw::new(10.0, 1.0, IntegratorKind::EulerMaruyama, 0.3, 1.0).is_err());
    }

    /// One DOF, `c ẋ = −k x + F`: rate λ = k/c, and for Euler–Maruyama the closed forms
    /// m = 1 − λΔt, stationary variance (kT/λ)/(1 − λΔt/2) (consistent noise), the
    /// element-uniform noise with Σ_ζ = s² instead of c scaling it by s²/c, and from rest
    /// ⟨q(η) q(t)⟩ = m^{η−t} g² (1 − m^{2t})/(1 − m²).
    #[test]
    fn one_dof_closed_forms() {
        let (k, c, kt, dt, s) = (3.0, 2.0, 0.7, 0.1, 0.9);
        let mut km = SymBanded::new(1, 0);
        km.add(0, 0, k).unwrap();
        let mut cm = SymBanded::new(1, 0);
        cm.add(0, 0, c).unwrap();
        let load = ElementLoad {
            amplitude: s,
            load: vec![1.0],
            dofs: vec![Some(0)],
        };
        let sys = LinearSystem::new(kt, km, cm, vec![load]).unwrap();
        let modes = generalized_modes_signed(&sys, |_, _| false).unwrap();
        let lambda = k / c;
        let a = lambda * dt;
        let law = DiscreteLaw::new(
            &sys,
            &modes,
            IntegratorKind::EulerMaruyama,
            NoiseModel::Consistent,
            dt,
        )
        .unwrap();
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-13 * y.abs();
        assert!(close(law.rates[0], lambda));
        assert!(close(law.multipliers[0], 1.0 - a));
        assert!(close(law.mode_variance(0), kt / lambda / (1.0 - a / 2.0)));
        assert!(close(law.equipartition(0), kt / lambda));
        assert!(close(law.decay_rate(0).unwrap(), -(1.0 - a).ln() / dt));
        // The modal probe of x itself: x = φ q with φ = 1/sqrt(c).
        let probe = DVector::from_element(1, 1.0 / c.sqrt());
        assert!(close(
            law.point_covariance(&probe, &probe),
            law.mode_variance(0) / c
        ));
        let (m, g2) = (1.0 - a, 2.0 * kt * dt);
        let expect = m.powi(3) * g2 * (1.0 - m.powi(8)) / (1.0 - m * m);
        assert!(close(law.two_time(4, 7, &probe, &probe), expect / c));
        let eu = DiscreteLaw::new(
            &sys,
            &modes,
            IntegratorKind::EulerMaruyama,
            NoiseModel::ElementUniform,
            dt,
        )
        .unwrap();
        assert!(close(eu.mode_variance(0), law.mode_variance(0) * s * s / c));
        // A wrong closed form is told apart: backward Euler's variance is not EM's.
        let be = DiscreteLaw::new(
            &sys,
            &modes,
            IntegratorKind::BackwardEuler,
            NoiseModel::Consistent,
            dt,
        )
        .unwrap();
        assert!(!close(be.mode_variance(0), law.mode_variance(0)));
        assert!(close(be.mode_variance(0), kt / lambda / (1.0 + a / 2.0)));
    }
}
