//! Writing an ensemble's time series to trajectory files ([`crate::data`]): the sampled
//! rows of every trajectory from rest, streamed to disk as they are simulated.

use super::{LinearRun, Model, Observables};
use crate::data::TrajectoryFile;
use crate::dynamics::Observer;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::stats::moments::MIN_SERIES_LEN;
use std::ops::Range;
use std::path::PathBuf;

/// What [`LinearRun::write_ensemble`] writes per trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct RowPlan {
    /// Positions x of the deflection columns (physical length units).
    pub positions: Vec<f64>,
    /// Steps between rows (rows at steps 0, every, 2·every, …).
    pub every: u64,
    /// Steps after the burn-in (the sampled duration).
    pub sampled_steps: u64,
    /// Rows per trajectory (the first at rest, t = 0).
    pub rows: u64,
    /// Column names ([`crate::data::columns`]).
    pub columns: Vec<String>,
}

/// Trajectories too short for `check` ([`LinearRun::short_for_check`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortRows {
    /// Rows after the burn-in.
    pub stationary: u64,
    /// Rows between the samples of the sparsest checked series.
    pub sparsest: u64,
    /// Rows after the burn-in `check` asks for: [`MIN_SERIES_LEN`] samples of it.
    pub needed: u64,
}

impl LinearRun {
    /// The rows of this run's trajectory files for a sampled duration of
    /// `sampled_steps` steps: deflections at the mesh nodes (for the spectral model, the
    /// nodes of a uniform mesh of its element count), the profile points and the two-time
    /// points; a row every `every` steps, by default the largest step count no larger
    /// than the cadence of the fastest checked mode that divides every two-time step (so
    /// the two-time correlation from rest can be checked on the rows).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--every` if `every` is 0.
    pub fn row_plan(
        &self,
        scene: &Scene,
        sampled_steps: u64,
        every: Option<u64>,
    ) -> Result<RowPlan> {
        let length = scene.line_length();
        let mut positions: Vec<f64> = match &self.model {
            Model::Fem { object, .. } => object.line_nodes(),
            Model::Spectral { .. } | Model::SpectralMembrane { .. } | Model::Data => {
                let n = scene.mesh.elements;
                (0..=n).map(|k| length * k as f64 / n as f64).collect()
            }
        };
        let r = &self.reference;
        positions.extend(&r.profile_x);
        positions.extend(r.two_time.iter().flat_map(|q| [q.x, q.y]));
        positions.sort_by(f64::total_cmp);
        positions.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * length);
        let every = match every {
            Some(0) => return Err(Error::invalid("--every", 0, "a step count >= 1")),
            Some(e) => e,
            None => {
                let fastest = self.mode_every.iter().copied().min().unwrap_or(1).max(1);
                let steps: Vec<u64> = r
                    .two_time
                    .iter()
                    .flat_map(|q| [q.t_step, q.eta_step])
                    .collect();
                (1..=fastest)
                    .rev()
                    .find(|d| steps.iter().all(|s| s % d == 0))
                    .unwrap_or(1)
            }
        };
        let total = self.schedule(sampled_steps).total();
        Ok(RowPlan {
            columns: if scene.is_membrane() {
                let labels: Vec<_> = r.modes.iter().filter_map(|m| m.label).collect();
                crate::data::membrane_columns(positions.len(), &labels)
            } else {
                let dims = self.components + 1;
                let rigid: Vec<&str> = r.rigid.iter().map(|m| m.coordinate).collect();
                let mut c = crate::data::columns(dims, positions.len(), r.modes.len());
                c.extend(crate::data::filament_extra_columns(
                    dims,
                    &rigid,
                    r.tangent.len(),
                ));
                c
            },
            positions,
            every,
            sampled_steps,
            rows: total / every + 1,
        })
    }

    /// Whether `check` could read trajectories written as `plan`: `None` if the sparsest
    /// of the checked series (the slowest mode, sampled at the data's cadence
    /// [`super::sample_every`] from the first row after the burn-in) has the
    /// [`MIN_SERIES_LEN`] samples `check` needs; else the rows after the burn-in, the
    /// rows between that mode's samples and the rows `check` asks for (as its refusal
    /// states them).
    pub fn short_for_check(&self, plan: &RowPlan) -> Option<ShortRows> {
        let dts = plan.every as f64 * self.reference.dt;
        let sparsest = self
            .reference
            .modes
            .iter()
            .map(|m| super::sample_every(m.rate_discrete.unwrap_or(m.rate_continuum), dts))
            .max()?;
        let stationary = plan
            .rows
            .saturating_sub(self.burn_in_steps.div_ceil(plan.every));
        let min = MIN_SERIES_LEN as u64;
        (stationary.div_ceil(sparsest) < min).then_some(ShortRows {
            stationary,
            sparsest,
            needed: sparsest * min,
        })
    }

    /// The cost of one deflection value of a row, in DOF-steps (for `run`'s projection of
    /// its rows, [`crate::work`]; measured on the reference machine): a spectral model
    /// sums a sine per mode at the position (about 18 ns a mode, a DOF-step each), a
    /// plate on its modal path dots its modal probe (about 1.2 ns a mode, 1/16 of a
    /// DOF-step), finite elements interpolate locally (counted as 1).
    pub fn deflection_cost(&self) -> f64 {
        match &self.model {
            Model::Fem {
                modal: Some(path), ..
            } => path.rates.len() as f64 / 16.0,
            Model::Fem { .. } => 1.0,
            Model::Spectral { n_modes, .. } => *n_modes as f64,
            Model::SpectralMembrane { simulator, .. } => simulator.modes().len() as f64,
            Model::Data => 0.0,
        }
    }

    /// Simulates the trajectories `range` of the ensemble seeded `seed` (the same
    /// trajectories as [`Self::simulate_ensemble`]: `0..count` for a whole run, one
    /// shard's share for `run --shard`, [`crate::shard`]) and writes each, as `plan`
    /// says, to `path(j)` (`.csv` or `.npy`), streaming; a file appears only once
    /// complete. Trajectory `j`'s file depends only on `seed`, `j` and `plan`, not on
    /// the range it is written in. `done(k)` is called as `k` more trajectories finish.
    ///
    /// # Errors
    /// A divergence naming the step; [`Error::Io`] naming the file.
    pub fn write_ensemble(
        &self,
        seed: u64,
        range: Range<u64>,
        plan: &RowPlan,
        path: impl Fn(u64) -> PathBuf + Sync,
        done: impl Fn(u64) + Sync,
    ) -> Result<()> {
        let writers = self.observe_ensemble(
            seed,
            range.start,
            range.end.saturating_sub(range.start),
            plan.sampled_steps,
            |j| RowWriter::new(self, plan, &path(j)),
            done,
        )?;
        for w in writers {
            w.commit()?;
        }
        Ok(())
    }
}

/// The observer of [`LinearRun::write_ensemble`]: one row every `plan.every` steps from
/// rest (step 0 included) to the end.
struct RowWriter<'r> {
    run: &'r LinearRun,
    plan: &'r RowPlan,
    file: Result<TrajectoryFile>,
    row: Vec<f64>,
    deflections: Vec<f64>,
    modes: Vec<f64>,
    rigid: Vec<f64>,
    tangent: Vec<f64>,
}

impl<'r> RowWriter<'r> {
    fn new(run: &'r LinearRun, plan: &'r RowPlan, path: &std::path::Path) -> Self {
        let c = run.components;
        RowWriter {
            run,
            plan,
            file: TrajectoryFile::create(path, &plan.columns, plan.rows),
            row: Vec::with_capacity(plan.columns.len()),
            deflections: vec![0.0; c * plan.positions.len()],
            modes: vec![0.0; c * run.reference.modes.len()],
            rigid: vec![0.0; c * run.reference.rigid.len()],
            tangent: vec![0.0; c * run.reference.tangent.len()],
        }
    }

    fn write<S: Observables + ?Sized>(&mut self, step: u64, sampler: &S) {
        let Ok(file) = &mut self.file else {
            return;
        };
        let nm = self.run.reference.modes.len();
        sampler.deflections(&self.plan.positions, &mut self.deflections);
        sampler.modes(&mut self.modes);
        self.row.clear();
        self.row.push(step as f64 * self.run.reference.dt);
        self.row.extend(&self.deflections);
        self.row.extend(
            self.modes
                .iter()
                .enumerate()
                .map(|(k, q)| q * self.run.amplitude_scale[k % nm]),
        );
        // The rigid coordinates in physical units (centre of mass, angle), then the
        // tangent-angle amplitudes (the data format's order).
        let rigid = &self.run.reference.rigid;
        if !rigid.is_empty() {
            sampler.rigid(&mut self.rigid);
            self.row.extend(
                self.rigid
                    .iter()
                    .enumerate()
                    .map(|(k, r)| r / rigid[k % rigid.len()].coordinate_scale),
            );
        }
        if let Some(g) = self.run.tangent_functionals() {
            sampler.functionals(g, &mut self.tangent);
            self.row.extend(&self.tangent);
        }
        if let Err(e) = file.push_row(&self.row) {
            self.file = Err(e);
        }
    }

    /// Completes the file (the first write error, if any).
    fn commit(self) -> Result<()> {
        self.file?.commit()
    }
}

impl<S: Observables + ?Sized> Observer<S> for RowWriter<'_> {
    fn on_start(&mut self, _: usize, sampler: &S) {
        self.write(0, sampler);
    }
    fn on_step(&mut self, _: usize, step: u64, sampler: &S) {
        if step.is_multiple_of(self.plan.every) {
            self.write(step, sampler);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::LinearRun;
    use crate::scene::builtin::load_scene;

    /// A periodic membrane at 99.99 % of its buckling tension, its τ₁ long, so that at
    /// dt_tau1 = 0.02 Crank–Nicolson's fastest checked mode has m ≈ −0.9996 and keeps
    /// most of its start after the burn-in: refused, naming runs[0].dt_tau1 and the bound;
    /// at the bound it forgets as the slowest mode does; the scene as built in (σ = 20)
    /// forgets at once.
    #[test]
    fn a_mode_that_does_not_forget_its_start_is_refused() {
        let mut scene = load_scene("membrane-periodic", None).unwrap();
        let k = scene
            .runs
            .iter()
            .position(|r| r.name == "crank-nicolson")
            .unwrap();
        let prepared =
            |s: &crate::scene::Scene| LinearRun::prepare_for_writing(s, &s.runs[k]).unwrap();
        assert!(prepared(&scene).require_forgetting(&scene, k).is_ok());
        let m = scene.membrane.as_mut().unwrap();
        m.tension = 0.9999 * m.buckling_tension();
        let run = prepared(&scene);
        let u = run.unforgetting_mode().expect("remembers");
        assert!(u.multiplier < -0.999 && u.memory > 0.5, "{u:?}");
        let e = run.require_forgetting(&scene, k).unwrap_err().to_string();
        assert!(
            e.contains(&format!("key `runs[{k}].dt_tau1`")) && e.contains("below about"),
            "{e}"
        );
        scene.runs[k].dt_tau1 = u.dt_bound / scene.tau1();
        let run = prepared(&scene);
        assert!(
            run.unforgetting_mode().is_none(),
            "{:?}",
            run.unforgetting_mode()
        );
    }
}
