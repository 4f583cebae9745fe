//! The proposal's drift against the gradient of the chain's own energy (issue #30).
//!
//! The Metropolis step corrects any error of the force its proposal uses: the chain's law
//! stays exact and the force–strain checks pass, while the dynamics — relaxation of the
//! buckled mode, the autocorrelation of F — are those of a wrong force. The stationary law
//! checks the energy; this checks that the proposal moves along that energy's gradient.
//! Every proposal here (and the θ-schemes) is a consistent discretization of
//! `da = −∇U dt + sqrt(2kT) dW` in modal coordinates (`ΦᵀCΦ = I`), so at a small step its
//! noise-free move, read off the executed proposal with `z = 0`, is
//! `(a − a′)/Δt = ∇U − ½Δt H∇U + O(Δt²)`; two steps (`Δt λ_max = 1e-3` and twice that),
//! Richardson-extrapolated, give `∇U` to O(Δt²). The gradient is taken independently, by
//! central differences of the energy the acceptance uses, along the drift's own direction,
//! the slowest coordinates and a fixed pseudo-random direction.

use super::ModalMetropolis;

/// `Δt λ_max` of the finer probe step (module docs).
const PROBE_STEP: f64 = 1e-3;
/// Central-difference step along a unit direction `d`, in units of the thermal scale
/// `sqrt(kT/(dᵀΛd))` along it.
const DIFFERENCE_STEP: f64 = 1e-3;
/// Slowest coordinates probed one by one.
const SLOW_COORDINATES: usize = 3;

impl ModalMetropolis<'_> {
    /// The largest relative difference, over a few directions `d`, between the proposal's
    /// drift (its noise-free move at small steps, extrapolated) and the directional derivative
    /// `dᵀ∇U` of the chain's energy by central differences, relative to the thermal force
    /// scale `sqrt(kT κ_d)` along `d` (`κ_d = dᵀΛd + (S/ℓ)(dᵀBa)²`, the bending and the
    /// constraint's rank-one curvature), at the current state (module docs). Far below 1e-4
    /// for a consistent proposal; a force error `δ` in the proposal shows as about
    /// `δ |dᵀF B a|/sqrt(kT κ_d)`, of order δ·|F|/F_c0 along the slowest coordinate. `None`
    /// if the proposal cannot be made at the current state.
    pub fn drift_residual(&self) -> Option<f64> {
        let lam_max = self.rates.iter().fold(0.0f64, |m, &r| m.max(r));
        if lam_max.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        // The noise-free move at Δt and 2Δt, Richardson-extrapolated: (a − a′)/Δt =
        // ∇U − ½Δt H∇U + O(Δt²) for every proposal here, so 2 m(Δt) − m(2Δt) = ∇U + O(Δt²).
        // A larger Δt would bias it, a smaller one lose the slow coordinates' move to
        // round-off (relative ε_mach/(Δt λ_min)).
        let dt = PROBE_STEP / lam_max;
        let fine = self.noise_free_move(dt)?;
        let coarse = self.noise_free_move(2.0 * dt)?;
        let drift: Vec<f64> = fine.iter().zip(&coarse).map(|(f, c)| 2.0 * f - c).collect();
        let a = &self.current.a;
        let norm = drift.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        let n = self.rates.len();
        let mut directions: Vec<Vec<f64>> = vec![drift.iter().map(|v| v / norm).collect()];
        for k in 0..SLOW_COORDINATES.min(n) {
            let mut d = vec![0.0; a.len()];
            d[k] = 1.0;
            directions.push(d);
        }
        let fixed: Vec<f64> = (0..a.len())
            .map(|i| ((i as f64 + 1.0) * 1.618_033_988_75).sin())
            .collect();
        let fixed_norm = fixed.iter().map(|v| v * v).sum::<f64>().sqrt();
        directions.push(fixed.iter().map(|v| v / fixed_norm).collect());
        let mut worst = 0.0f64;
        for d in &directions {
            // The thermal scale along d: the curvature dᵀΛd of the bending energy plus the
            // constraint's rank-one part (S/ℓ)(dᵀg)², g = B a (∂s/∂a = g/ℓ), which dominates
            // for a nearly inextensible filament.
            let bending: f64 = d
                .iter()
                .enumerate()
                .map(|(i, v)| self.rates[i % n] * v * v)
                .sum();
            let dg: f64 = d.iter().zip(&self.current.g).map(|(x, y)| x * y).sum();
            let c = &self.constraint.constraint;
            let curvature = bending + c.stiffness / c.measure * dg * dg;
            let h = DIFFERENCE_STEP * (self.kt / curvature).sqrt();
            let energy_at = |sign: f64| {
                let mut e = self.current.clone();
                for (x, v) in e.a.iter_mut().zip(d) {
                    *x += sign * h * v;
                }
                self.evaluate(&mut e);
                e.energy
            };
            let derivative = (energy_at(1.0) - energy_at(-1.0)) / (2.0 * h);
            let along: f64 = d.iter().zip(&drift).map(|(x, y)| x * y).sum();
            // Relative to the thermal force scale along d, sqrt(kT × curvature).
            worst = worst.max((along - derivative).abs() / (self.kt * curvature).sqrt());
        }
        Some(worst)
    }

    /// `(a − a′)/Δt` of the proposal (or θ-step) made from the current state with zero
    /// noise at step `dt`; `None` if it cannot be made.
    fn noise_free_move(&self, dt: f64) -> Option<Vec<f64>> {
        let mut probe = self.clone();
        probe.set_dt(dt).ok()?;
        probe.z.iter_mut().for_each(|z| *z = 0.0);
        let moved = match probe.theta {
            Some(theta) => {
                probe.theta_step(theta);
                &probe.current.a
            }
            None => {
                if !probe.propose() {
                    return None;
                }
                &probe.proposal.a
            }
        };
        Some(
            self.current
                .a
                .iter()
                .zip(moved)
                .map(|(x, y)| (x - y) / dt)
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ModalMetropolis, Proposal};
    use crate::FilamentParams;
    use crate::dynamics::driver::Trajectory;
    use crate::fem::area::AreaMembrane;
    use crate::fem::beam::BeamModel;
    use crate::fem::mesh::Mesh;
    use crate::fem::paired::PairedModes;
    use crate::fem::plate_modes::PlateModes;
    use crate::fem::vonkarman::CompressedFilament;
    use crate::rng::trajectory_rng;
    use crate::spectral::membrane::{MembraneBoundary, MembraneParams};

    /// Runs `chain` 200 steps and returns its drift residual at the end.
    fn residual_after_steps(mut chain: ModalMetropolis<'_>, seed: u64) -> f64 {
        let mut rng = trajectory_rng(seed, 1);
        for _ in 0..200 {
            chain.step(&mut rng);
        }
        chain
            .drift_residual()
            .expect("a proposal at the probe step")
    }

    /// The filament's chain (2D and 3D, below and above buckling): the residual is at
    /// round-off for the true proposal force and about |F|/F_c0 × 5 % for a 5 % error.
    #[test]
    fn the_filament_proposal_moves_along_the_energy_gradient() {
        let p = FilamentParams {
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            ..FilamentParams::default()
        };
        let beam = BeamModel::new(p, Mesh::uniform(1.0, 10).unwrap()).unwrap();
        let tau1 = p.tau1();
        for dims in [2, 3] {
            for ratio in [0.5, 3.0] {
                let m =
                    CompressedFilament::new(beam.clone(), dims, ratio * p.euler_strain()).unwrap();
                let modes = PairedModes::new(m.beam()).unwrap();
                let mut rng = trajectory_rng(30, dims as u64);
                let chain = ModalMetropolis::new(&m, &modes, 0.05 * tau1, &mut rng).unwrap();
                let clean = residual_after_steps(chain.clone(), 7);
                assert!(clean < 1e-5, "{dims}D at {ratio}: {clean:e}");
                let wrong = residual_after_steps(chain.with_proposal_force_factor(1.05), 7);
                assert!(
                    wrong > 1e-3,
                    "{dims}D at {ratio}: 5 % error gives {wrong:e}"
                );
            }
        }
    }

    /// The membrane's chain with every proposal and the θ-schemes (explicit force): the
    /// residual is at round-off for the true force and far above the tolerance for 5 %.
    #[test]
    fn every_membrane_proposal_moves_along_the_energy_gradient() {
        let p = MembraneParams {
            bending_rigidity: 20.0,
            boundary: MembraneBoundary::SimplySupported,
            ..MembraneParams::default()
        };
        let k_a = 2e4;
        let sigma_c0 = p.bending_rigidity * p.min_wavenumber_sq();
        let m = AreaMembrane::new(p, 3, 3, k_a, 4.0 * sigma_c0 / k_a).unwrap();
        let modes = PlateModes::new(m.plate()).unwrap();
        let tau1 = p.drag / (p.bending_rigidity * p.min_wavenumber_sq().powi(2));
        let chains = |rng: &mut _| -> Vec<(String, ModalMetropolis<'_>)> {
            let base = ModalMetropolis::for_membrane(&m, &modes, 0.05 * tau1, rng).unwrap();
            let mut out = Vec::new();
            for kind in [
                Proposal::CrankNicolson,
                Proposal::Newton,
                Proposal::OrnsteinUhlenbeck,
            ] {
                out.push((
                    format!("{kind:?}"),
                    base.clone().with_proposal(kind).unwrap(),
                ));
            }
            // The explicit scheme within its stability limit (λ_max Δt < 2).
            let lam_max = modes.modes().iter().fold(0.0f64, |a, m| a.max(m.rate));
            let small = ModalMetropolis::for_membrane(&m, &modes, 0.5 / lam_max, rng).unwrap();
            for theta in [0.0, 0.5] {
                out.push((
                    format!("theta {theta}"),
                    small.clone().with_theta(theta).unwrap(),
                ));
            }
            out
        };
        let mut rng = trajectory_rng(31, 0);
        for (name, chain) in chains(&mut rng) {
            let clean = residual_after_steps(chain.clone(), 8);
            assert!(clean < 1e-5, "{name}: {clean:e}");
            let wrong = residual_after_steps(chain.with_proposal_force_factor(1.05), 8);
            assert!(wrong > 1e-3, "{name}: 5 % error gives {wrong:e}");
        }
    }
}
