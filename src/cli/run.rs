//! `langevin-fem run`: simulate a scene's ensemble and write every trajectory's time
//! series in the trajectory data format ([`langevin_fem::data`]), ready for NumPy, pandas
//! or `langevin-fem check`.

use super::{Verbosity, usize_in};
use clap::Args;
use langevin_fem::data::{
    COMPRESSION_COLUMNS, DataFilament, DataRun, DataSidecar, Discretization, FORMAT, SIDECAR,
    Start, TrajectoryFile, VERSION, trajectory_columns,
};
use langevin_fem::error::{Error, Result};
use langevin_fem::fem::banded::LANES;
use langevin_fem::output::{Provenance, ReportRun};
use langevin_fem::progress::Progress;
use langevin_fem::rng::derive_seed;
use langevin_fem::scene::compression::CompressionRun;
use langevin_fem::scene::linear::{LinearRun, RowPlan};
use langevin_fem::scene::{Budget, ModelKind, Scene};
use langevin_fem::work::{RunWork, WorkProjection};
use std::f64::consts::PI;
use std::path::PathBuf;

/// The examples of `run --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem run -s hinged-linear-2d -o traj                 every run, quick budget, .npy
  langevin-fem run -s hinged-linear-2d --run crank-nicolson --trajectories 8 \\
      --duration-tau1 40 --every 10 --format csv -o traj
  langevin-fem check -s hinged-linear-2d -d traj               then check them

Progress goes to stderr, the closing line (what was written, where) to stdout.";

/// Command-line arguments of `langevin-fem run`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct RunArgs {
    /// Scene: a name from the scene directory or a path to a .toml file (linear scenes:
    /// hinged-linear-2d, hinged-linear-3d, spectral-reference).
    #[arg(short, long, value_name = "NAME|PATH")]
    scene: String,
    /// Run of the scene to simulate (repeatable; default: every run).
    #[arg(long = "run", value_name = "NAME")]
    runs: Vec<String>,
    /// The ensemble: trajectories and duration of the scene's budget.
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: super::verify::BudgetArg,
    /// Trajectories per run (default: the budget's).
    #[arg(long, value_name = "N", value_parser = usize_in::<1, 100_000>)]
    trajectories: Option<usize>,
    /// Sampled duration per trajectory after the burn-in, in tau1 (default: the budget's).
    #[arg(long, value_name = "TAU1", allow_negative_numbers = true)]
    duration_tau1: Option<f64>,
    /// Steps between rows (default: the cadence of the fastest checked mode, made a
    /// divisor of the two-time points' steps).
    #[arg(long, value_name = "STEPS", value_parser = super::count_in::<1, 1_000_000_000>)]
    every: Option<u64>,
    /// File format of the trajectories.
    #[arg(long, value_enum, default_value = "npy")]
    format: FormatArg,
    #[command(flatten)]
    sim: super::SimArgs,
    /// Output directory: data.json (the sidecar), manifest.json and <run>/trajectory-NNNN.<format>.
    #[arg(short, long, default_value = "trajectories")]
    pub(super) out: PathBuf,
    /// Directory of scene files in which --scene NAME is looked up (default: the
    /// built-in scenes).
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    #[command(flatten)]
    limits: super::LimitArgs,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum FormatArg {
    Npy,
    Csv,
}

/// What one `run` command does: the scene (seed applied), the chosen runs and their
/// ensembles.
struct Job<'a> {
    args: &'a RunArgs,
    /// What is printed on stderr while it runs.
    verbosity: Verbosity,
    scene: Scene,
    seed_note: String,
    budget: Budget,
    /// Indices of the chosen runs in the scene.
    chosen: Vec<usize>,
}

impl Job<'_> {
    /// Trajectories and sampled duration (τ1) of run `k`: the flags, else the budget's.
    fn ensemble(&self, k: usize) -> (usize, f64) {
        let e = self.scene.runs[k].ensemble(self.budget);
        (
            self.args.trajectories.unwrap_or(e.trajectories),
            self.args.duration_tau1.unwrap_or(e.duration_tau1),
        )
    }

    /// The file extension of the trajectories.
    fn ext(&self) -> &'static str {
        match self.args.format {
            FormatArg::Npy => "npy",
            FormatArg::Csv => "csv",
        }
    }

    /// Starts the report directory with its provenance.
    fn begin(&self) -> Result<(Provenance, ReportRun)> {
        let provenance = Provenance::begin(&[&self.scene]);
        let report = ReportRun::begin(&self.args.out, "run", "manifest.json", &[SIDECAR])?;
        report.set_provenance(provenance.clone())?;
        Ok((provenance, report))
    }

    /// Completes the report directory: the final provenance, then the sidecar listing
    /// `runs` (EA given for compression data), and the closing line naming `what`.
    fn finish(
        &self,
        mut provenance: Provenance,
        report: ReportRun,
        runs: Vec<DataRun>,
        stretch_rigidity: Option<f64>,
        what: String,
    ) -> Result<i32> {
        provenance.finish();
        report.set_provenance(provenance.clone())?;
        let (scene, f) = (&self.scene, self.scene.filament);
        let sidecar = DataSidecar {
            format: FORMAT.to_string(),
            version: VERSION,
            producer: format!("langevin-fem {}", env!("CARGO_PKG_VERSION")),
            dims: scene.dims,
            filament: DataFilament {
                length: f.length,
                bending_rigidity: f.bending_rigidity,
                drag: f.drag,
                kt: f.kt,
                stretch_rigidity,
            },
            runs,
            provenance: Some(serde_json::json!({
                "run_id": report.run_id(),
                "budget": self.budget.name(),
                "seed": scene.seed,
                "seed_note": self.seed_note,
                "tau1": f.tau1(),
                "journal": "manifest.json",
                "record": provenance,
            })),
            columns: Some(trajectory_columns()),
        };
        let out = &self.args.out;
        let text = serde_json::to_string_pretty(&sidecar)
            .map_err(|e| Error::io(out.join(SIDECAR), e.into()))?
            + "\n";
        report.finish(&[(SIDECAR, text.as_bytes())])?;
        println!(
            "wrote {what} to {}; check them with: langevin-fem check --scene {} --data {}",
            out.display(),
            self.args.scene,
            out.display()
        );
        Ok(0)
    }

    /// The discretization of run `k` at time step `dt`, as the sidecar records it.
    fn discretization(&self, k: usize, dt: f64) -> Discretization {
        let spec = &self.scene.runs[k];
        Discretization {
            model: match self.scene.model {
                ModelKind::Spectral => "spectral",
                _ => "fem",
            }
            .to_string(),
            elements: Some(self.scene.mesh.elements),
            integrator: Some(spec.integrator.to_string()),
            noise: Some(spec.noise.name().to_string()),
            dt: Some(dt),
        }
    }
}

/// Runs the command (progress on stderr unless quiet); exit code 0.
pub fn run(args: RunArgs, verbosity: Verbosity) -> Result<i32> {
    let mut scene = langevin_fem::scene::load_scene(&args.scene, args.scene_dir.as_deref())?;
    args.sim.start()?;
    let seed_note = args.sim.apply(&mut scene);
    if let Some(d) = args.duration_tau1
        && !(d.is_finite() && (1.0..=1e6).contains(&d))
    {
        return Err(Error::invalid(
            "--duration-tau1",
            d,
            "a duration in [1, 1e6] tau1",
        ));
    }
    for r in &args.runs {
        if !scene.runs.iter().any(|s| &s.name == r) {
            let names: Vec<&str> = scene.runs.iter().map(|s| s.name.as_str()).collect();
            return Err(Error::invalid(
                "--run",
                r,
                format!("a run of {}: {}", scene.name, names.join(", ")),
            ));
        }
    }
    let chosen: Vec<usize> = (0..scene.runs.len())
        .filter(|&k| args.runs.is_empty() || args.runs.contains(&scene.runs[k].name))
        .collect();
    let job = Job {
        budget: args.budget.budget(),
        args: &args,
        verbosity,
        scene,
        seed_note,
        chosen,
    };
    if job.scene.compression.is_some() {
        run_compression(&job)
    } else {
        run_linear(&job)
    }
}

/// `run` of a linear scene: every chosen run's trajectories from rest, streamed.
fn run_linear(job: &Job<'_>) -> Result<i32> {
    let (scene, args) = (&job.scene, job.args);
    let tau1 = scene.filament.tau1();
    let runs = job
        .chosen
        .iter()
        .map(|&k| {
            LinearRun::prepare(scene, &scene.runs[k])
                .map_err(|e| scene.run_error(k, "integrator", e))
        })
        .collect::<Result<Vec<_>>>()?;
    let plans = job
        .chosen
        .iter()
        .zip(&runs)
        .map(|(&k, run)| {
            let steps = run.sampled_steps(job.ensemble(k).1 * tau1);
            run.row_plan(scene, steps, args.every)
        })
        .collect::<Result<Vec<_>>>()?;
    let work = projection(job, &plans);
    args.limits.limits().check(&work)?;
    let (provenance, report) = job.begin()?;
    let total: u64 = job.chosen.iter().map(|&k| job.ensemble(k).0 as u64).sum();
    let bar = Progress::new(job.verbosity.progress(), work.dof_steps(), "DOF-steps");
    let mut data_runs = Vec::new();
    for (((&k, run), plan), part) in job.chosen.iter().zip(&runs).zip(&plans).zip(&work.parts) {
        let label = format!("{}/{}", scene.name, scene.runs[k].name);
        bar.begin_run(&scene.name, &label, part.work.dof_steps);
        data_runs.push(write_linear_run(job, &report, k, run, plan, &bar)?);
    }
    bar.finish();
    let what = format!(
        "{total} trajectories of {} ({} run(s))",
        scene.name,
        job.chosen.len()
    );
    job.finish(provenance, report, data_runs, None, what)
}

/// Simulates and writes the trajectories of linear run `k`; returns its sidecar entry.
fn write_linear_run(
    job: &Job<'_>,
    report: &ReportRun,
    k: usize,
    run: &LinearRun,
    plan: &RowPlan,
    bar: &Progress,
) -> Result<DataRun> {
    let (scene, out) = (&job.scene, &job.args.out);
    let spec = &scene.runs[k];
    let count = job.ensemble(k).0 as u64;
    let per_trajectory = bar.run_work() / count.max(1) as f64;
    let files: Vec<String> = (0..count)
        .map(|j| format!("{}/trajectory-{j:04}.{}", spec.name, job.ext()))
        .collect();
    for f in &files {
        report.record(&out.join(f))?;
    }
    let seed = derive_seed(scene.seed, &spec.name);
    run.write_ensemble(
        seed,
        count,
        plan,
        |j| out.join(&files[j as usize]),
        |n| bar.advance(n as f64 * per_trajectory),
    )
    .map_err(|e| scene.run_error(k, "dt_tau1", e))?;
    if job.verbosity == Verbosity::Verbose {
        bar.println(&format!(
            "{} / {}: {count} trajectories x {} rows",
            scene.name, spec.name, plan.rows
        ));
    }
    let dt = run.reference.dt;
    Ok(DataRun {
        name: spec.name.clone(),
        dt_sample: plan.every as f64 * dt,
        start: Start::Rest,
        burn_in: run.burn_in_steps as f64 * dt,
        positions: plan.positions.clone(),
        modes: run.reference.modes.len(),
        discretization: Some(job.discretization(k, dt)),
        files,
        strain_ratio: None,
    })
}

/// The projected work: per chosen run, every trajectory's steps (burn-in included)
/// times the unknowns each updates, at the cost per step of the scene's own projection.
fn projection(job: &Job<'_>, plans: &[RowPlan]) -> WorkProjection {
    let parts = job.scene.projected_work(job.budget);
    WorkProjection {
        command: "run".to_string(),
        parts: job
            .chosen
            .iter()
            .zip(plans)
            .map(|(&k, plan)| {
                let mut part = parts[k].clone();
                let w = part.work;
                let per_step = if w.trajectory_steps > 0.0 {
                    w.dof_steps / w.trajectory_steps
                } else {
                    0.0
                };
                let n = job.ensemble(k).0 as f64;
                let steps = n * (plan.rows * plan.every) as f64;
                part.work = RunWork {
                    trajectory_steps: steps,
                    dof_steps: steps * per_step,
                    samples: (plan.columns.len() * LANES) as f64,
                };
                part.drivers = format!(
                    "{}; {} trajectories x {} rows of {} columns written",
                    part.drivers,
                    n,
                    plan.rows,
                    plan.columns.len()
                );
                part
            })
            .collect(),
    }
}

/// `run` of a compression scene: per run and strain, every trajectory's F and stored
/// length after the burn-in (the samples `verify` takes, same seeds), one data run per
/// strain in the sidecar. A budget by target precision chooses durations by a pilot:
/// `--duration-tau1` is then required.
fn run_compression(job: &Job<'_>) -> Result<i32> {
    let (scene, args) = (&job.scene, job.args);
    let Some(comp) = &scene.compression else {
        return run_linear(job);
    };
    for &k in &job.chosen {
        let e = scene.runs[k].ensemble(job.budget);
        if e.precision_target().is_some() && args.duration_tau1.is_none() {
            return Err(Error::invalid(
                "--duration-tau1",
                "not given",
                format!(
                    "a duration in tau1: the {} budget of run {} chooses its durations by a pilot (target precision), which run does not do",
                    job.budget.name(),
                    scene.runs[k].name
                ),
            ));
        }
    }
    let runs = job
        .chosen
        .iter()
        .map(|&k| {
            CompressionRun::prepare(scene, comp, &scene.runs[k])
                .map_err(|e| scene.run_error(k, "integrator", e))
        })
        .collect::<Result<Vec<_>>>()?;
    let work = compression_projection(job);
    args.limits.limits().check(&work)?;
    let (provenance, report) = job.begin()?;
    let strains = comp.strain_ratios.len();
    let total: u64 = job
        .chosen
        .iter()
        .map(|&k| (job.ensemble(k).0 * strains) as u64)
        .sum();
    let bar = Progress::new(job.verbosity.progress(), work.dof_steps(), "DOF-steps");
    let mut data_runs = Vec::new();
    for ((&k, run), part) in job.chosen.iter().zip(&runs).zip(&work.parts) {
        let label = format!("{}/{}", scene.name, scene.runs[k].name);
        bar.begin_run(&scene.name, &label, part.work.dof_steps);
        data_runs.extend(write_compression_run(job, &report, k, run, &bar)?);
    }
    bar.finish();
    let what = format!(
        "{total} trajectories of {} ({} run(s) x {strains} strains)",
        scene.name,
        job.chosen.len()
    );
    job.finish(
        provenance,
        report,
        data_runs,
        Some(scene.filament.stretch_rigidity),
        what,
    )
}

/// The projected work of the chosen compression runs: the scene's projection at the
/// budget, scaled up to the flags' trajectories and duration.
fn compression_projection(job: &Job<'_>) -> WorkProjection {
    let parts = job.scene.projected_work(job.budget);
    WorkProjection {
        command: "run".to_string(),
        parts: job
            .chosen
            .iter()
            .map(|&k| {
                let mut part = parts[k].clone();
                let (n, d) = job.ensemble(k);
                let e = job.scene.runs[k].ensemble(job.budget);
                let scale =
                    (n as f64 / e.trajectories.max(1) as f64) * (d / e.duration_tau1.max(1e-300));
                if scale.is_finite() {
                    part.work.trajectory_steps *= scale.max(1.0);
                    part.work.dof_steps *= scale.max(1.0);
                }
                part
            })
            .collect(),
    }
}

/// Simulates compression run `k` at every strain and writes each trajectory's F and
/// stored length; returns one sidecar entry per strain.
fn write_compression_run(
    job: &Job<'_>,
    report: &ReportRun,
    k: usize,
    run: &CompressionRun,
    bar: &Progress,
) -> Result<Vec<DataRun>> {
    let scene = &job.scene;
    let (Some(comp), f) = (&scene.compression, scene.filament) else {
        return Ok(Vec::new());
    };
    let spec = &scene.runs[k];
    let (n, duration) = job.ensemble(k);
    let per_trajectory = bar.run_work() / (n * run.points()).max(1) as f64;
    let steps: Vec<u64> = (0..run.points())
        .map(|i| run.sampled_steps_at(i, duration * f.tau1()))
        .collect();
    let seed = |i: usize| derive_seed(scene.seed, &format!("{}/{i}", spec.name));
    let records = run
        .simulate_ensemble_per_point(seed, n, &steps, || bar.advance(per_trajectory))
        .map_err(|e| scene.run_error(k, "dt_tau1", e))?;
    let columns: Vec<String> = COMPRESSION_COLUMNS.iter().map(|c| c.to_string()).collect();
    let euler_strain = PI.powi(2) * f.bending_rigidity / (f.stretch_rigidity * f.length.powi(2));
    let mut data_runs = Vec::new();
    for (i, at_strain) in records.iter().enumerate() {
        let ratio = comp.strain_ratios[i];
        let strain = ratio * euler_strain;
        let (dts, burn_in) = (run.sample_dt_at(i), run.burn_in_at(i));
        let mut files = Vec::new();
        for (j, rec) in at_strain.iter().enumerate() {
            let rel = format!(
                "{}/strain-{i:02}/trajectory-{j:04}.{}",
                spec.name,
                job.ext()
            );
            let path = job.args.out.join(&rel);
            report.record(&path)?;
            let mut file = TrajectoryFile::create(&path, &columns, rec.force_ratio.len() as u64)?;
            for (r, fr) in rec.force_ratio.iter().enumerate() {
                let force = fr * run.euler_load;
                let stored = (strain - force / f.stretch_rigidity) * f.length;
                file.push_row(&[burn_in + (r + 1) as f64 * dts, force, stored])?;
            }
            file.commit()?;
            files.push(rel);
        }
        data_runs.push(DataRun {
            name: spec.name.clone(),
            dt_sample: dts,
            start: Start::Stationary,
            burn_in,
            positions: Vec::new(),
            modes: 0,
            discretization: Some(job.discretization(k, run.dt_at(i))),
            files,
            strain_ratio: Some(ratio),
        });
    }
    Ok(data_runs)
}
