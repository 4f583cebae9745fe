//! The one trajectory driver: every simulated trajectory (linear and nonlinear filament,
//! spectral self-check, stability map, benchmarks) is advanced by [`Driver::run`].
//!
//! The driver owns the schedule of a trajectory — `burn_in` steps, then `sampled` steps
//! with a sample every `every` steps — and the finiteness check after every step: the
//! first non-finite state ends the run with [`Error::diverged`] naming the step (time =
//! step·Δt) and the caller's detail. What is recorded is the business of an [`Observer`],
//! whose callbacks default to doing nothing:
//!
//! - [`Observer::on_start`] before the first step;
//! - [`Observer::on_step`] after every (finite) step, burn-in included (the two-time
//!   products of eq. 4 are taken during the burn-in);
//! - [`Observer::on_sample`] after the steps `burn_in + k·every`, k = 1, 2, … up to
//!   `burn_in + sampled`, with `k·every` (steps since the end of the burn-in);
//! - [`Observer::on_finish`] after the last step.
//!
//! The stepped thing is a [`Trajectory`]: one step of every transverse component, drawing
//! from the trajectory's own random stream in a fixed order (one PCG stream per
//! trajectory, components in order inside a step), and a finiteness test. The linear
//! integrators ([`Integrator`]) step a component vector, the nonlinear ones
//! ([`NonlinearStep`]) all components at once; [`Components`] and [`NonlinearState`]
//! make trajectories of them.
//!
//! # Batched ensembles
//!
//! [`Driver::run_batch`] advances up to [`LANES`](crate::fem::banded::LANES) trajectories
//! of a [`BatchTrajectory`] in lockstep (their states structure-of-arrays, one random
//! stream per trajectory drawn in the same order as alone, so every trajectory stays
//! bit-identical to its serial run), checks finiteness per lane and calls each lane's
//! observer with the lane's trajectory index and a [`LaneOf`] view: the same schedule and
//! callbacks as [`Driver::run`], which is the batch of one.

use super::batch::{BatchTrajectory, LaneOf};
use super::integrator::Integrator;
use super::nonlinear::NonlinearStep;
use crate::error::{Error, Result};
use crate::rng::TrajectoryRng;

/// Something advanced by the [`Driver`]: one trajectory's state and its stepper.
pub trait Trajectory {
    /// One time step of every component, drawing the noise from `rng` (components in
    /// order).
    fn step(&mut self, rng: &mut TrajectoryRng);
    /// Whether the whole state is finite.
    fn is_finite(&self) -> bool;
}

/// Callbacks of a [`Driver`] run; every method defaults to doing nothing. `trajectory`
/// is the index of the trajectory in its ensemble.
pub trait Observer<S: ?Sized> {
    /// Before the first step.
    fn on_start(&mut self, _trajectory: usize, _system: &S) {}
    /// After step `step` (1-based), burn-in included, once the state is known finite.
    fn on_step(&mut self, _trajectory: usize, _step: u64, _system: &S) {}
    /// After a sampling step; `since_burn_in` is its number of steps after the burn-in (a
    /// positive multiple of the cadence). Called after [`Self::on_step`] of that step.
    fn on_sample(&mut self, _trajectory: usize, _since_burn_in: u64, _system: &S) {}
    /// After the last step.
    fn on_finish(&mut self, _trajectory: usize, _system: &S) {}
}

impl<S: ?Sized> Observer<S> for () {}

/// The schedule of a trajectory: `burn_in` steps, then `sampled` steps with a sample every
/// `every` steps, with time step `dt` (for the time in the divergence error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Driver {
    /// Time step (the divergence error gives the time step·dt).
    pub dt: f64,
    /// Steps before the first sample.
    pub burn_in: u64,
    /// Steps after the burn-in.
    pub sampled: u64,
    /// Steps between samples (≥ 1).
    pub every: u64,
}

impl Driver {
    /// A schedule of `burn_in` + `sampled` steps of size `dt`, sampling every `every`
    /// steps after the burn-in (`every` = 0 is taken as 1).
    pub fn new(dt: f64, burn_in: u64, sampled: u64, every: u64) -> Self {
        Driver {
            dt,
            burn_in,
            sampled,
            every: every.max(1),
        }
    }

    /// Total number of steps.
    pub fn total(&self) -> u64 {
        self.burn_in + self.sampled
    }

    /// `Some(steps since the burn-in)` if step `step` (1-based) is a sampling step.
    fn sample_at(&self, step: u64) -> Option<u64> {
        (step > self.burn_in && (step - self.burn_in).is_multiple_of(self.every))
            .then(|| step - self.burn_in)
    }

    /// Runs trajectory `trajectory` of `system` with random stream `rng` through the
    /// schedule, calling `observer` ([`Observer`]).
    ///
    /// # Errors
    /// [`Error::Diverged`] at the first step after which the state is not finite, with
    /// detail `detail(system)`.
    pub fn run<S, O>(
        &self,
        trajectory: usize,
        system: &mut S,
        rng: &mut TrajectoryRng,
        observer: &mut O,
        detail: impl FnOnce(&S) -> String,
    ) -> Result<()>
    where
        S: Trajectory + ?Sized,
        O: Observer<S> + ?Sized,
    {
        observer.on_start(trajectory, system);
        for step in 1..=self.total() {
            system.step(rng);
            if !system.is_finite() {
                return Err(Error::diverged(step, self.dt, detail(system)));
            }
            observer.on_step(trajectory, step, system);
            if let Some(since) = self.sample_at(step) {
                observer.on_sample(trajectory, since, system);
            }
        }
        observer.on_finish(trajectory, system);
        Ok(())
    }
}

impl Driver {
    /// Runs the lanes `0..rngs.len()` of `batch` (trajectories `first + l`, lane `l`
    /// drawing from `rngs[l]` and observed by `observers[l]`, which sees it as a
    /// [`LaneOf`]) through the schedule in lockstep: the batched form of [`Self::run`],
    /// with the same callbacks in the same order per lane. A lane whose state becomes
    /// non-finite gets [`Error::diverged`] (its step, detail `detail(batch)`) and is no
    /// longer observed; the others go on. One result per lane.
    ///
    /// # Panics
    /// If `observers` and `rngs` differ in length.
    pub fn run_batch<B, O>(
        &self,
        first: usize,
        batch: &mut B,
        rngs: &mut [TrajectoryRng],
        observers: &mut [O],
        detail: impl Fn(&B) -> String,
    ) -> Vec<Result<()>>
    where
        B: BatchTrajectory + ?Sized,
        O: for<'a> Observer<LaneOf<'a, B>>,
    {
        assert_eq!(
            rngs.len(),
            observers.len(),
            "run_batch: one observer per lane"
        );
        let mut results: Vec<Result<()>> = rngs.iter().map(|_| Ok(())).collect();
        let mut alive = vec![true; rngs.len()];
        for (lane, o) in observers.iter_mut().enumerate() {
            o.on_start(
                first + lane,
                &LaneOf {
                    batch: &*batch,
                    lane,
                },
            );
        }
        for step in 1..=self.total() {
            if !alive.contains(&true) {
                break;
            }
            batch.step(rngs);
            let sample = self.sample_at(step);
            for (lane, o) in observers.iter_mut().enumerate() {
                if !alive[lane] {
                    continue;
                }
                if !batch.lane_is_finite(lane) {
                    results[lane] = Err(Error::diverged(step, self.dt, detail(batch)));
                    alive[lane] = false;
                    continue;
                }
                let view = LaneOf {
                    batch: &*batch,
                    lane,
                };
                o.on_step(first + lane, step, &view);
                if let Some(since) = sample {
                    o.on_sample(first + lane, since, &view);
                }
            }
        }
        for (lane, o) in observers.iter_mut().enumerate() {
            if alive[lane] {
                o.on_finish(
                    first + lane,
                    &LaneOf {
                        batch: &*batch,
                        lane,
                    },
                );
            }
        }
        results
    }
}

/// A linear filament's trajectory: the transverse components `states` (one free-DOF
/// vector each), advanced in order by the same `integrator`.
pub struct Components<I> {
    /// The integrator.
    pub integrator: I,
    /// One state vector per transverse component.
    pub states: Vec<Vec<f64>>,
}

impl<I> Components<I> {
    /// `components` components of `n_dofs` degrees of freedom each, at rest.
    pub fn at_rest(integrator: I, components: usize, n_dofs: usize) -> Self {
        Components {
            integrator,
            states: vec![vec![0.0; n_dofs]; components],
        }
    }
}

impl<I: Integrator> Trajectory for Components<I> {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        for s in &mut self.states {
            self.integrator.step(s, rng);
        }
    }
    fn is_finite(&self) -> bool {
        self.states.iter().flatten().all(|v| v.is_finite())
    }
}

/// A nonlinear filament's trajectory: the state `w` (one vector per transverse component)
/// and its `integrator`.
pub struct NonlinearState<N> {
    /// The integrator.
    pub integrator: N,
    /// One state vector per transverse component.
    pub w: Vec<Vec<f64>>,
}

impl<N: NonlinearStep> Trajectory for NonlinearState<N> {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        self.integrator.step(&mut self.w, rng);
    }
    fn is_finite(&self) -> bool {
        self.w.iter().flatten().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::trajectory_rng;

    /// A scalar AR(1)-like system that becomes infinite at a chosen step.
    struct Counter {
        steps: u64,
        blow_up_at: u64,
    }

    impl Trajectory for Counter {
        fn step(&mut self, _rng: &mut TrajectoryRng) {
            self.steps += 1;
        }
        fn is_finite(&self) -> bool {
            self.steps < self.blow_up_at
        }
    }

    #[derive(Default)]
    struct Log {
        events: Vec<(char, u64)>,
    }

    impl Observer<Counter> for Log {
        fn on_start(&mut self, _: usize, _: &Counter) {
            self.events.push(('s', 0));
        }
        fn on_sample(&mut self, _: usize, since: u64, c: &Counter) {
            self.events.push(('x', since));
            assert_eq!(c.steps, 3 + since);
        }
        fn on_finish(&mut self, _: usize, c: &Counter) {
            self.events.push(('f', c.steps));
        }
    }

    /// Three scalar lanes in lockstep, lane `l` non-finite from step `blow_up[l]`.
    struct Lanes3 {
        steps: u64,
        blow_up: [u64; 3],
    }

    impl BatchTrajectory for Lanes3 {
        fn step(&mut self, rngs: &mut [TrajectoryRng]) {
            assert_eq!(rngs.len(), 3);
            self.steps += 1;
        }
        fn lane_is_finite(&self, lane: usize) -> bool {
            self.steps < self.blow_up[lane]
        }
    }

    impl Observer<LaneOf<'_, Lanes3>> for Log {
        fn on_start(&mut self, _: usize, _: &LaneOf<'_, Lanes3>) {
            self.events.push(('s', 0));
        }
        fn on_sample(&mut self, t: usize, since: u64, v: &LaneOf<'_, Lanes3>) {
            assert_eq!(t, 10 + v.lane);
            self.events.push(('x', since));
        }
        fn on_finish(&mut self, _: usize, v: &LaneOf<'_, Lanes3>) {
            self.events.push(('f', v.batch.steps));
        }
    }

    /// A batch follows the schedule of [`Driver::run`] per lane; a lane that goes
    /// non-finite gets its own divergence error (its step) and no further callbacks,
    /// while the other lanes run to the end.
    #[test]
    fn batch_schedule_and_per_lane_divergence() {
        let d = Driver::new(0.5, 3, 7, 2);
        let mut rngs: Vec<_> = (0..3).map(|j| trajectory_rng(1, j)).collect();
        let mut logs: Vec<Log> = (0..3).map(|_| Log::default()).collect();
        let mut b = Lanes3 {
            steps: 0,
            blow_up: [u64::MAX, 6, u64::MAX],
        };
        let results = d.run_batch(10, &mut b, &mut rngs, &mut logs, |_| "lane".into());
        let full = vec![('s', 0), ('x', 2), ('x', 4), ('x', 6), ('f', 10)];
        assert_eq!(logs[0].events, full);
        assert_eq!(logs[2].events, full);
        assert_eq!(logs[1].events, vec![('s', 0), ('x', 2)]);
        assert!(results[0].is_ok() && results[2].is_ok());
        match &results[1] {
            Err(Error::Diverged { step, time, .. }) => assert_eq!((*step, *time), (6, 3.0)),
            r => panic!("{r:?}"),
        }
    }

    /// Samples come after the burn-in at the cadence; the divergence error names the
    /// first non-finite step and its time.
    #[test]
    fn schedule_and_divergence() {
        let d = Driver::new(0.5, 3, 7, 2);
        let mut rng = trajectory_rng(1, 0);
        let mut log = Log::default();
        let mut c = Counter {
            steps: 0,
            blow_up_at: u64::MAX,
        };
        d.run(0, &mut c, &mut rng, &mut log, |_| String::new())
            .unwrap();
        assert_eq!(
            log.events,
            vec![('s', 0), ('x', 2), ('x', 4), ('x', 6), ('f', 10)]
        );
        let mut c = Counter {
            steps: 0,
            blow_up_at: 4,
        };
        let e = d
            .run(0, &mut c, &mut rng, &mut (), |c| format!("at {}", c.steps))
            .unwrap_err();
        match e {
            Error::Diverged { step, time, detail } => {
                assert_eq!((step, time, detail.as_str()), (4, 2.0, "at 4"));
            }
            e => panic!("{e}"),
        }
    }
}
