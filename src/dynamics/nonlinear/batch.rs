//! The θ-schemes of [`NonlinearIntegrator`] for [`LANES`] trajectories in lockstep: the
//! paper's explicit scheme (with the axial solve of step i), Crank–Nicolson and backward
//! Euler with the stretching force explicit, each lane bit-identical to its trajectory
//! stepped alone.

use super::{NonlinearIntegrator, Scheme};
use crate::dynamics::IntegratorKind;
use crate::dynamics::batch::BatchTrajectory;
use crate::error::Result;
use crate::fem::banded::{BandedCholesky, LANES, Lanes};
use crate::fem::noise::{NoiseGenerator, NoiseModel};
use crate::fem::vonkarman::{AxialLanes, CompressedFilament};
use crate::rng::TrajectoryRng;

/// [`LANES`] trajectories of a θ-scheme of [`NonlinearIntegrator`], advanced together:
/// the noise of each lane drawn as the one-trajectory step draws it (component by
/// component), then the banded products `G w`, `K w`, `C w`, the stretching force and
/// the solve with `C + θΔtK` for all lanes at once ([`crate::fem::banded::SymBanded::mul_lanes`],
/// [`BandedCholesky::solve_lanes`], [`CompressedFilament::axial_force_lanes`]), every
/// lane with the floating-point operations of [`NonlinearIntegrator`]'s θ-step in the
/// same order. The lanes' serial chains interleave, so the step runs at the throughput
/// of the arithmetic rather than at the latency of one chain. Allocation-free per step.
pub struct NonlinearBatch<'m> {
    model: &'m CompressedFilament,
    /// Whether F comes from the axial solve (the paper's explicit scheme) rather than
    /// the closed form.
    axial_step: bool,
    theta: f64,
    dt: f64,
    scale: f64,
    lhs: BandedCholesky,
    noise: NoiseGenerator,
    /// The states, `states[c][i][l]`: component `c`, DOF `i`, lane `l`.
    states: Vec<Vec<Lanes>>,
    /// The standardized noise of the step, as `states`.
    z: Vec<Vec<Lanes>>,
    /// `G w` per component, then the right-hand side (in place, as the one-trajectory
    /// step forms it).
    gw: Vec<Vec<Lanes>>,
    /// `K w` per component.
    kw: Vec<Vec<Lanes>>,
    /// `C w` of one component.
    cw: Vec<Lanes>,
    /// One component's draw of one lane.
    zeta: Vec<f64>,
    axial: AxialLanes,
}

impl<'m> NonlinearBatch<'m> {
    /// The batched θ-scheme `kind` for `model` with noise `noise` and step `dt`, at rest,
    /// or `None` for the Metropolis chain or a band the lane kernels do not serve (the
    /// caller then steps trajectories one by one).
    ///
    /// # Errors
    /// As [`NonlinearIntegrator::new`] (the same refusals: it is built first).
    pub fn new(
        model: &'m CompressedFilament,
        kind: IntegratorKind,
        noise: NoiseModel,
        dt: f64,
    ) -> Result<Option<Self>> {
        let single = NonlinearIntegrator::new(model, kind, noise, dt)?;
        let Scheme::Theta(theta) = single.scheme else {
            return Ok(None);
        };
        if !(1..=3).contains(&single.lhs.bandwidth()) {
            return Ok(None);
        }
        let (n, nc) = (model.beam().n_dofs(), model.components());
        let lanes = || vec![vec![[0.0; LANES]; n]; nc];
        Ok(Some(NonlinearBatch {
            model,
            axial_step: kind == IntegratorKind::EulerMaruyama,
            theta,
            dt: single.dt,
            scale: single.scale,
            lhs: single.lhs,
            noise: single.noise,
            states: lanes(),
            z: lanes(),
            gw: lanes(),
            kw: lanes(),
            cw: vec![[0.0; LANES]; n],
            zeta: vec![0.0; n],
            axial: AxialLanes::default(),
        }))
    }

    /// Sets the state of lane `lane` to `w` (one vector per component).
    ///
    /// # Panics
    /// If `w` does not have the model's shape or `lane ≥ LANES`.
    pub fn set_lane(&mut self, lane: usize, w: &[Vec<f64>]) {
        assert_eq!(w.len(), self.states.len(), "set_lane: wrong components");
        for (s, c) in self.states.iter_mut().zip(w) {
            assert_eq!(s.len(), c.len(), "set_lane: wrong length");
            for (v, x) in s.iter_mut().zip(c) {
                v[lane] = *x;
            }
        }
    }

    /// Copies the state of lane `lane` into `out` (one vector per component, resized).
    pub fn lane_state(&self, lane: usize, out: &mut Vec<Vec<f64>>) {
        out.resize(self.states.len(), Vec::new());
        for (o, s) in out.iter_mut().zip(&self.states) {
            o.clear();
            o.extend(s.iter().map(|v| v[lane]));
        }
    }

    /// The deterministic part of the step and the solve, for all lanes (the noise drawn
    /// into `z`): [`NonlinearIntegrator`]'s `theta_update` per lane.
    fn update(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (just checked).
            unsafe { self.update_avx() };
            return;
        }
        self.update_lanes();
    }

    /// [`Self::update_lanes`] compiled for AVX: 4-wide vectors, no fused multiply-add
    /// (a separate extension, not enabled), so bit-identical to the SSE2 code.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn update_avx(&mut self) {
        self.update_lanes();
    }

    /// [`Self::update`] after the dispatch (plain loops, inlined into the AVX copy).
    #[inline(always)]
    fn update_lanes(&mut self) {
        let beam = self.model.beam();
        let mut two_l_s = [0.0; LANES];
        for ((w, gw), kw) in self.states.iter().zip(&mut self.gw).zip(&mut self.kw) {
            beam.geometric().mul_lanes(w, gw);
            beam.stiffness().mul_lanes(w, kw);
            // `Σ_i w_i (Gw)_i` as `Iterator::sum` forms it, from −0.0
            let mut part = [-0.0; LANES];
            for (wi, gi) in w.iter().zip(gw.iter()) {
                for l in 0..LANES {
                    part[l] += wi[l] * gi[l];
                }
            }
            for l in 0..LANES {
                two_l_s[l] += part[l];
            }
        }
        let force: Lanes = if self.axial_step {
            self.model.axial_force_lanes(&self.states, &mut self.axial)
        } else {
            let two_l = 2.0 * beam.params().length;
            let mut f = [0.0; LANES];
            for l in 0..LANES {
                f[l] = self.model.compressive_force(two_l_s[l] / two_l);
            }
            f
        };
        let (theta, dt, scale) = (self.theta, self.dt, self.scale);
        let parts = self.states.iter_mut().zip(&mut self.gw).zip(&self.kw);
        for (((w, rhs), kw), z) in parts.zip(&self.z) {
            beam.damping().mul_lanes(w, &mut self.cw);
            for (((r, c), k), z) in rhs.iter_mut().zip(&self.cw).zip(kw).zip(z) {
                for l in 0..LANES {
                    r[l] = c[l] - (1.0 - theta) * dt * k[l] + dt * force[l] * r[l];
                    r[l] += scale * z[l];
                }
            }
            self.lhs.solve_lanes(rhs, w);
        }
    }
}

impl BatchTrajectory for NonlinearBatch<'_> {
    /// # Panics
    /// If `rngs.len() > LANES`.
    fn step(&mut self, rngs: &mut [TrajectoryRng]) {
        assert!(
            rngs.len() <= LANES,
            "NonlinearBatch: more than {LANES} lanes"
        );
        for (l, rng) in rngs.iter_mut().enumerate() {
            for z in &mut self.z {
                self.noise.draw(rng, &mut self.zeta);
                for (zi, v) in z.iter_mut().zip(&self.zeta) {
                    zi[l] = *v;
                }
            }
        }
        for z in self.z.iter_mut().flatten() {
            z[rngs.len()..].fill(0.0);
        }
        self.update();
    }

    fn lane_is_finite(&self, lane: usize) -> bool {
        self.states.iter().flatten().all(|v| v[lane].is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::NonlinearStep;
    use crate::fem::vonkarman::tests::{model, random_state};
    use crate::rng::trajectory_rng;

    /// Every θ-scheme and noise model, 2D and 3D, below and above the Euler strain: each of
    /// 3 trajectories stepped in a batch (the other lanes idle) is bit-identical to the
    /// same trajectory stepped alone by [`NonlinearIntegrator`] for 300 steps from the
    /// same start, and the idle lanes stay exactly at rest.
    #[test]
    fn batched_lanes_equal_single_trajectories_bit_for_bit() {
        let kinds = [
            IntegratorKind::EulerMaruyama,
            IntegratorKind::CrankNicolson,
            IntegratorKind::BackwardEuler,
        ];
        for dims in [2, 3] {
            for ratio in [0.5, 4.0] {
                let m = model(dims, ratio);
                let tau = m.beam().params().tau1();
                for kind in kinds {
                    for noise in [NoiseModel::Consistent, NoiseModel::ElementUniform] {
                        let dt = if kind == IntegratorKind::EulerMaruyama {
                            1e-5 * tau
                        } else {
                            1e-3 * tau
                        };
                        let mut batch = NonlinearBatch::new(&m, kind, noise, dt).unwrap().unwrap();
                        let start = |j: u64| random_state(&m, 0.01, j);
                        let mut rngs: Vec<_> = (0..3).map(|j| trajectory_rng(5, j)).collect();
                        for j in 0..3 {
                            batch.set_lane(j, &start(j as u64));
                        }
                        for _ in 0..300 {
                            batch.step(&mut rngs);
                        }
                        let mut lane = Vec::new();
                        for j in 0..3u64 {
                            let mut single = NonlinearIntegrator::new(&m, kind, noise, dt).unwrap();
                            let (mut w, mut rng) = (start(j), trajectory_rng(5, j));
                            for _ in 0..300 {
                                single.step(&mut w, &mut rng);
                            }
                            batch.lane_state(j as usize, &mut lane);
                            let bits = |v: &Vec<Vec<f64>>| -> Vec<u64> {
                                v.iter().flatten().map(|x| x.to_bits()).collect()
                            };
                            assert_eq!(
                                bits(&lane),
                                bits(&w),
                                "{kind} {noise:?} dims {dims} ratio {ratio} lane {j}"
                            );
                            assert!(w.iter().flatten().any(|&x| x != 0.0));
                            assert!(w.iter().flatten().all(|x| x.is_finite()));
                        }
                        for l in 3..LANES {
                            batch.lane_state(l, &mut lane);
                            assert!(
                                lane.iter().flatten().all(|&x| x == 0.0),
                                "idle lane {l} moved"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The Metropolis chain is not batched.
    #[test]
    fn the_metropolis_chain_is_stepped_alone() {
        let m = model(2, 1.0);
        let dt = 1e-3 * m.beam().params().tau1();
        let batch = NonlinearBatch::new(
            &m,
            IntegratorKind::MetropolisCrankNicolson,
            NoiseModel::Consistent,
            dt,
        )
        .unwrap();
        assert!(batch.is_none());
    }
}
