//! Ensembles stepped in lockstep: [`LANES`] trajectories of a linear θ-scheme advanced
//! together, their states stored structure-of-arrays, so that the serial chains of the
//! banded substitutions of the trajectories interleave (the one-trajectory step is bound by
//! the latency of that chain, see [`ThetaScheme`](super::ThetaScheme)).
//!
//! Every lane draws from its own random stream in the order of its one-trajectory run
//! (per step, the components in order, each the `n` noise entries of
//! [`NoiseGenerator::stream`]), and the floating-point operations of every lane are those
//! of [`ThetaScheme::step`](super::ThetaScheme): a trajectory stepped in a batch is
//! bit-identical to the same trajectory stepped alone, whatever lane it occupies and
//! whatever the other lanes hold (tests below).

use super::integrator::{THETA_SUGGESTION, ThetaOperators, check_dt, check_stability};
use super::{Family, IntegratorKind};
use crate::error::Result;
use crate::fem::banded::{BandedCholesky, LANES, Lanes, SymBanded};
use crate::fem::noise::{NoiseGenerator, NoiseModel, standard_normal};
use crate::fem::system::LinearSystem;
use crate::rng::TrajectoryRng;

/// Up to [`LANES`] trajectories advanced together by the [`Driver`](super::Driver)'s
/// [`run_batch`](super::Driver::run_batch).
pub trait BatchTrajectory {
    /// One time step of lanes `0..rngs.len()` (≤ [`LANES`]), lane `l` drawing its noise
    /// from `rngs[l]`; the other lanes stay at rest.
    fn step(&mut self, rngs: &mut [TrajectoryRng]);
    /// Whether the whole state of lane `lane` is finite.
    fn lane_is_finite(&self, lane: usize) -> bool;
}

/// Lane `lane` of a batch `batch`, as an [`Observer`](super::Observer) of a batched run
/// sees one trajectory.
pub struct LaneOf<'a, B: ?Sized> {
    /// The batch.
    pub batch: &'a B,
    /// The lane.
    pub lane: usize,
}

/// The θ-scheme of [`ThetaScheme`](super::ThetaScheme) for [`LANES`] trajectories at
/// once: the noise of each lane drawn and formed as the one-trajectory step forms it
/// (`g_i = sqrt(2kTΔt)·ζ_i`), then one forward and one backward banded sweep over all
/// lanes ([`BandedCholesky::theta_sweeps_lanes`]; for consistent noise the product `L z`
/// of all lanes formed inside the forward sweep,
/// [`BandedCholesky::theta_sweeps_lanes_noise`]). Allocation-free per step.
pub struct ThetaBatch {
    lhs: BandedCholesky,
    rhs: SymBanded,
    scale: f64,
    noise: NoiseGenerator,
    /// The additive terms `g`, structure-of-arrays.
    g: Vec<Lanes>,
    /// The forward-substituted right-hand sides.
    y: Vec<Lanes>,
    /// The standard normals of consistent noise.
    z: Vec<Lanes>,
    /// Scratch space of the noise stream.
    scratch: Vec<f64>,
}

impl ThetaBatch {
    /// The batched θ-scheme with parameter `theta` for `system`, noise `noise` and step
    /// `dt`, or `None` if the lane sweeps do not serve its band
    /// ([`BandedCholesky::lanes_supported`]; the caller then steps trajectories one by
    /// one).
    ///
    /// # Errors
    /// As [`ThetaScheme::new`](super::ThetaScheme::new).
    pub fn new(
        system: &LinearSystem,
        noise: NoiseModel,
        theta: f64,
        dt: f64,
    ) -> Result<Option<Self>> {
        let ThetaOperators {
            lhs,
            rhs,
            scale,
            noise,
        } = ThetaOperators::new(system, noise, theta, dt)?;
        if !lhs.lanes_supported(&rhs) {
            return Ok(None);
        }
        let n = system.n_dofs();
        Ok(Some(ThetaBatch {
            lhs,
            rhs,
            scale,
            noise,
            g: vec![[0.0; LANES]; n],
            y: vec![[0.0; LANES]; n],
            z: vec![[0.0; LANES]; n],
            scratch: Vec::new(),
        }))
    }

    /// The batched form of what [`build_integrator`](super::build_integrator) builds
    /// for `kind`, with the same step-size refusals, if `kind` is a θ-scheme and its band
    /// is served ([`Self::new`]); `None` otherwise (the caller steps one by one).
    ///
    /// # Errors
    /// As [`build_integrator`](super::build_integrator).
    pub fn build(
        kind: IntegratorKind,
        system: &LinearSystem,
        noise: NoiseModel,
        dt: f64,
        max_rate: f64,
    ) -> Result<Option<Self>> {
        match kind.family() {
            Family::Theta(theta) => {
                check_dt(dt)?;
                check_stability(kind, dt, max_rate, THETA_SUGGESTION)?;
                Self::new(system, noise, theta, dt)
            }
            Family::ExactModal | Family::Metropolis => Ok(None),
        }
    }

    /// Number of free degrees of freedom of one component.
    pub fn n_dofs(&self) -> usize {
        self.g.len()
    }

    /// Advances `state` (one component of every lane, structure-of-arrays) by one step,
    /// lane `l < rngs.len()` drawing from `rngs[l]`; the lanes `≥ rngs.len()` get no
    /// noise (at rest they stay at rest).
    ///
    /// # Panics
    /// If `rngs.len() > LANES` or `state.len()` differs from the number of DOFs.
    pub fn step(&mut self, state: &mut [Lanes], rngs: &mut [TrajectoryRng]) {
        assert!(rngs.len() <= LANES, "ThetaBatch: more than {LANES} lanes");
        let n = self.g.len();
        match self.noise.lower_factor() {
            Some(factor) => {
                // consistent noise: z drawn lane by lane, then `s·L z` for all lanes
                for (l, rng) in rngs.iter_mut().enumerate() {
                    for z in &mut self.z {
                        z[l] = standard_normal(rng);
                    }
                }
                for z in &mut self.z {
                    z[rngs.len()..].fill(0.0);
                }
                self.lhs.theta_sweeps_lanes_noise(
                    &self.rhs,
                    factor,
                    self.scale,
                    &self.z,
                    &mut self.y,
                    state,
                );
            }
            None => {
                let (scale, g) = (self.scale, &mut self.g);
                for (l, rng) in rngs.iter_mut().enumerate() {
                    let mut zeta = self.noise.stream(rng, &mut self.scratch);
                    zeta.prepare(n);
                    zeta.for_each_prepared(|i, v| g[i][l] = scale * v);
                }
                for g in &mut self.g {
                    g[rngs.len()..].fill(0.0);
                }
                self.lhs
                    .theta_sweeps_lanes(&self.rhs, &self.g, &mut self.y, state);
            }
        }
    }
}

/// The transverse components of [`LANES`] linear trajectories, advanced in order by one
/// [`ThetaBatch`] (the batched form of [`Components`](super::Components)).
pub struct ComponentBatch {
    /// The batched integrator.
    pub integrator: ThetaBatch,
    /// One structure-of-arrays state per transverse component.
    pub states: Vec<Vec<Lanes>>,
}

impl ComponentBatch {
    /// `components` components of every lane, at rest.
    pub fn at_rest(integrator: ThetaBatch, components: usize) -> Self {
        let n = integrator.n_dofs();
        ComponentBatch {
            integrator,
            states: vec![vec![[0.0; LANES]; n]; components],
        }
    }

    /// Copies component `component` of lane `lane` into `out` (length: the DOF count).
    ///
    /// # Panics
    /// If `out` has the wrong length or an index is out of range.
    pub fn lane_state(&self, component: usize, lane: usize, out: &mut [f64]) {
        let s = &self.states[component];
        assert_eq!(out.len(), s.len(), "lane_state: wrong length");
        for (o, v) in out.iter_mut().zip(s) {
            *o = v[lane];
        }
    }
}

impl BatchTrajectory for ComponentBatch {
    fn step(&mut self, rngs: &mut [TrajectoryRng]) {
        for s in &mut self.states {
            self.integrator.step(s, rngs);
        }
    }
    fn lane_is_finite(&self, lane: usize) -> bool {
        self.states.iter().flatten().all(|v| v[lane].is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::dynamics::{Components, ThetaScheme, Trajectory};
    use crate::fem::Mesh;
    use crate::fem::beam::BeamModel;
    use crate::rng::trajectory_rng;

    /// Every θ-scheme and noise model, 2D (one component) and 3D (two), uniform and
    /// graded meshes: each of 3 trajectories stepped in a batch of 3 (one lane idle) is
    /// bit-identical to the same trajectory stepped alone by [`ThetaScheme`] for 200
    /// steps, and the idle lane stays exactly at rest.
    #[test]
    fn batched_lanes_equal_single_trajectories_bit_for_bit() {
        let params = FilamentParams::default();
        let meshes = [
            Mesh::uniform(params.length, 9).unwrap(),
            Mesh::graded(params.length, 7, 3.0).unwrap(),
        ];
        let kinds = [
            IntegratorKind::EulerMaruyama,
            IntegratorKind::BackwardEuler,
            IntegratorKind::CrankNicolson,
        ];
        for mesh in &meshes {
            let beam = BeamModel::new(params, mesh.clone()).unwrap();
            let n = beam.n_dofs();
            for kind in kinds {
                let Family::Theta(theta) = kind.family() else {
                    unreachable!()
                };
                for noise in [NoiseModel::Consistent, NoiseModel::ElementUniform] {
                    let dt = 1e-4 * params.tau1();
                    for components in [1, 2] {
                        let batch = ThetaBatch::new(&beam, noise, theta, dt).unwrap().unwrap();
                        let mut batch = ComponentBatch::at_rest(batch, components);
                        let mut rngs: Vec<_> = (0..3).map(|j| trajectory_rng(5, j)).collect();
                        for _ in 0..200 {
                            batch.step(&mut rngs);
                        }
                        for j in 0..3u64 {
                            let single = ThetaScheme::new(&beam, noise, theta, dt).unwrap();
                            let mut one = Components::at_rest(single, components, n);
                            let mut rng = trajectory_rng(5, j);
                            for _ in 0..200 {
                                one.step(&mut rng);
                            }
                            let mut lane = vec![0.0; n];
                            for (c, expected) in one.states.iter().enumerate() {
                                batch.lane_state(c, j as usize, &mut lane);
                                assert!(
                                    lane.iter()
                                        .zip(expected)
                                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                                    "{kind:?} {noise:?} lane {j} component {c}"
                                );
                            }
                        }
                        assert!(batch.states.iter().flatten().all(|v| v[3] == 0.0));
                    }
                }
            }
        }
    }
}
