//! `langevin-fem run`: simulate a scene's ensemble and write every trajectory's time
//! series in the trajectory data format ([`langevin_fem::data`]), ready for NumPy, pandas
//! or `langevin-fem check`.
//!
//! With `--shard I/N` (issue #15, [`langevin_fem::shard`]) the process simulates only
//! shard `I`'s share of every chosen run's trajectories (per strain for a compression
//! run) and writes their files under the same relative names as the whole run, with a
//! shard manifest instead of `data.json` and `manifest.json`; `langevin-fem merge`
//! ([`merge`]) then assembles the whole run's directory from the shards.

mod merge;

pub use merge::merge;

use super::{Verbosity, usize_in};
use clap::Args;
use langevin_fem::data::{
    COMPRESSION_COLUMNS, DataFilament, DataMembrane, DataRun, DataSidecar, Discretization, FORMAT,
    SIDECAR, Start, TrajectoryFile, VERSION, trajectory_columns_with_ends,
};
use langevin_fem::error::{Error, Result};
use langevin_fem::fem::banded::LANES;
use langevin_fem::output::{Provenance, ReportRun};
use langevin_fem::progress::Progress;
use langevin_fem::rng::derive_seed;
use langevin_fem::scene::compression::CompressionRun;
use langevin_fem::scene::linear::{LinearRun, RowPlan};
use langevin_fem::scene::{Budget, ModelKind, Scene};
use langevin_fem::shard::{Shard, ShardScene, ShardWriter};
use langevin_fem::stats::moments::MIN_SERIES_LEN;
use langevin_fem::work::{Origin, Part, RunWork, WorkLimits, WorkProjection};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// The name of the command in a `run` shard's manifest.
pub const COMMAND: &str = "run";
/// The largest `--trajectories` of `run` (and of a merged run's settings).
const MAX_TRAJECTORIES: usize = 100_000;
/// The largest `--every` of `run`.
const MAX_EVERY: u64 = 1_000_000_000;

/// The examples of `run --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem run -s hinged-linear-2d -o traj                 every run, quick budget, .npy
  langevin-fem run -s hinged-linear-2d --run crank-nicolson --trajectories 8 \\
      --duration-tau1 40 --every 10 --format csv -o traj
  langevin-fem check -s hinged-linear-2d -d traj               then check them
  langevin-fem run -s hinged-linear-2d --shard 2/4 -o shards/2 shard 2 of 4, then:
  langevin-fem merge shards/1 shards/2 shards/3 shards/4 -o traj

Progress goes to stderr, the closing line (what was written, where) to stdout.";

/// Command-line arguments of `langevin-fem run`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct RunArgs {
    /// Scene: a name from the scene directory or a path to a .toml file, linear
    /// (hinged-linear-2d, hinged-linear-3d, spectral-reference: the deflection and modal
    /// amplitudes), a membrane (membrane-hinged, membrane-periodic, ...: the height on the
    /// midline and modal amplitudes) or compression (compression-2d, compression-3d: F and
    /// the stored length per strain; a budget by target precision needs --duration-tau1).
    #[arg(short, long, value_name = "NAME|PATH")]
    scene: String,
    /// Run of the scene to simulate (repeatable; default: every run).
    #[arg(long = "run", value_name = "NAME")]
    runs: Vec<String>,
    /// The ensemble: trajectories and duration of the scene's budget.
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: super::verify::BudgetArg,
    /// Trajectories per run (default: the budget's).
    #[arg(long, value_name = "N", value_parser = usize_in::<1, { MAX_TRAJECTORIES as u64 }>)]
    trajectories: Option<usize>,
    /// Sampled duration per trajectory after the burn-in, in tau1 (default: the budget's).
    #[arg(long, value_name = "TAU1", allow_negative_numbers = true)]
    duration_tau1: Option<f64>,
    /// Steps between rows (default: the cadence of the fastest checked mode, made a
    /// divisor of the two-time points' steps). Linear scenes only: a compression scene
    /// records F every `compression.sample_every_tau1`.
    #[arg(long, value_name = "STEPS", value_parser = super::count_in::<1, MAX_EVERY>)]
    every: Option<u64>,
    /// File format of the trajectories.
    #[arg(long, value_enum, default_value = "npy")]
    format: FormatArg,
    /// Simulate only shard I of N of every chosen run's trajectories and write their
    /// files and a manifest (shard.json) to --out, without data.json; `langevin-fem
    /// merge` then writes the whole run's directory, byte for byte.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
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
    /// Cap on the projected size of the trajectory files this command writes, in GiB
    /// (rows × columns × 8 bytes in .npy, about 25 bytes a value in CSV): refused (exit 2)
    /// above it, before anything runs. Raise it deliberately for a larger data set.
    #[arg(long, value_name = "GIB", default_value = "16", allow_negative_numbers = true, value_parser = super::parse_max_memory_gib)]
    max_output_gib: f64,
}

impl RunArgs {
    /// Whether `--shard` was given (the output is then a shard, not a report).
    pub(super) fn is_shard(&self) -> bool {
        self.shard.is_some()
    }
}

/// The file format of the trajectories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum FormatArg {
    Npy,
    Csv,
}

/// Everything of a `run` that shapes its files, apart from the scene and its seed: a
/// shard manifest's settings, from which `merge` rebuilds the job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RunSettings {
    /// The budget whose ensembles the flags amend.
    budget: Budget,
    /// The chosen runs' names, in the scene's order.
    runs: Vec<String>,
    /// `--trajectories`.
    trajectories: Option<usize>,
    /// `--duration-tau1`.
    duration_tau1: Option<f64>,
    /// `--every`.
    every: Option<u64>,
    /// `--format`.
    format: FormatArg,
}

/// What one `run` command (or a merge of its shards) does: the scene (seed applied), the
/// chosen runs and their ensembles, and where the files go.
struct Job {
    settings: RunSettings,
    /// The output directory.
    out: PathBuf,
    /// What is printed on stderr while it runs.
    verbosity: Verbosity,
    scene: Scene,
    seed_note: String,
    /// Indices of the chosen runs in the scene.
    chosen: Vec<usize>,
    /// `--shard`, if given: the output is then a shard (even `1/1`, which `merge` takes
    /// alone), else the whole run's directory.
    shard: Option<Shard>,
    limits: WorkLimits,
    /// `--max-output-gib` in bytes (`None`: no cap, as for `merge`, whose files exist).
    max_output_bytes: Option<f64>,
}

/// Where a job's files go: a whole run's report directory, with its provenance (its
/// journal `manifest.json` and sidecar `data.json` written at the end), or a shard.
enum Sink {
    /// A whole run (or a merge): every file listed in the journal before it is written.
    Whole(Provenance, ReportRun),
    /// A shard: every file listed in the shard manifest once written.
    Shard(ShardWriter),
}

impl Sink {
    /// Where to write the file `rel` (relative to the output directory `out`) while the
    /// job goes on: in the staging directory of the whole run (listed in its journal) or
    /// of the shard, moved into place when the job finishes.
    fn record(&self, out: &Path, rel: &str) -> Result<PathBuf> {
        match self {
            Sink::Whole(_, report) => report.staged(&out.join(rel)),
            Sink::Shard(writer) => writer.staged(rel),
        }
    }

    /// Lists the file `rel`, trajectory `j` of run `key` (`<run>` or
    /// `<run>/strain-NN`), in a shard's manifest once written.
    fn written(&mut self, (scene, key): (&str, &str), rel: &str, j: u64) -> Result<()> {
        match self {
            Sink::Whole(..) => Ok(()),
            Sink::Shard(w) => w.add_file((scene, key), rel, j..j + 1, serde_json::Value::Null),
        }
    }
}

/// How `check --scene` names `scene` so that it finds it again: a built-in scene by its
/// name, any other by its file's path (which needs no `--scene-dir`).
fn scene_argument(scene: &Scene) -> String {
    let path = scene.path.display().to_string();
    match path.strip_suffix(" (built in)") {
        Some(name) => name.to_string(),
        None => path,
    }
}

/// `word` as one word of a POSIX shell command line: as it is if it holds only safe
/// characters, else single-quoted.
fn shell_word(word: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./:=+,@%".contains(c);
    if !word.is_empty() && word.chars().all(safe) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

/// The relative name of linear run `run`'s trajectory `j` in format `ext`.
fn linear_file(run: &str, j: u64, ext: &str) -> String {
    format!("{run}/trajectory-{j:04}.{ext}")
}

/// The shard-manifest key of compression run `run` at strain `i`.
fn strain_key(run: &str, i: usize) -> String {
    format!("{run}/strain-{i:02}")
}

/// The relative name of compression run `run`'s trajectory `j` at strain `i`.
fn compression_file(run: &str, i: usize, j: u64, ext: &str) -> String {
    format!("{}/trajectory-{j:04}.{ext}", strain_key(run, i))
}

impl Job {
    /// The job of `settings` on `scene`: the chosen runs checked against the scene.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--run` for a run the scene lacks, or
    /// `--duration-tau1` out of range.
    fn new(
        settings: RunSettings,
        scene: Scene,
        seed_note: String,
        out: PathBuf,
        verbosity: Verbosity,
        (shard, limits): (Option<Shard>, WorkLimits),
    ) -> Result<Job> {
        if let Some(n) = settings.trajectories
            && !(1..=MAX_TRAJECTORIES).contains(&n)
        {
            return Err(Error::invalid(
                "--trajectories",
                n,
                format!("an integer in [1, {MAX_TRAJECTORIES}]"),
            ));
        }
        if let Some(n) = settings.every
            && !(1..=MAX_EVERY).contains(&n)
        {
            return Err(Error::invalid(
                "--every",
                n,
                format!("an integer in [1, {MAX_EVERY}]"),
            ));
        }
        if let (Some(n), Some(c)) = (settings.every, &scene.compression) {
            // A compression run records F every compression.sample_every_tau1.
            return Err(Error::invalid(
                "--every",
                n,
                format!(
                    "left out for a compression scene (its rows are one every compression.sample_every_tau1 = {} tau1 of the scene, {})",
                    c.sample_every_tau1,
                    scene.path.display()
                ),
            ));
        }
        if let Some(d) = settings.duration_tau1
            && !(d.is_finite() && (1.0..=1e6).contains(&d))
        {
            return Err(Error::invalid(
                "--duration-tau1",
                d,
                "a duration in [1, 1e6] tau1",
            ));
        }
        for r in &settings.runs {
            if !scene.runs.iter().any(|s| &s.name == r) {
                let names: Vec<&str> = scene.runs.iter().map(|s| s.name.as_str()).collect();
                return Err(Error::invalid(
                    "--run",
                    r,
                    format!("a run of {}: {}", scene.name, names.join(", ")),
                ));
            }
        }
        let chosen = (0..scene.runs.len())
            .filter(|&k| settings.runs.contains(&scene.runs[k].name))
            .collect();
        Ok(Job {
            settings,
            out,
            verbosity,
            scene,
            seed_note,
            chosen,
            shard,
            limits,
            max_output_bytes: None,
        })
    }

    /// The budget whose ensembles the flags amend.
    fn budget(&self) -> Budget {
        self.settings.budget
    }

    /// Trajectories and sampled duration (τ1) of run `k`: the flags, else the budget's.
    fn ensemble(&self, k: usize) -> (usize, f64) {
        let e = self.scene.runs[k].ensemble(self.budget());
        (
            self.settings.trajectories.unwrap_or(e.trajectories),
            self.settings.duration_tau1.unwrap_or(e.duration_tau1),
        )
    }

    /// The share of every run's trajectories simulated: `--shard`, else the whole.
    fn share(&self) -> Shard {
        self.shard.unwrap_or(Shard::WHOLE)
    }

    /// The file extension of the trajectories.
    fn ext(&self) -> &'static str {
        match self.settings.format {
            FormatArg::Npy => "npy",
            FormatArg::Csv => "csv",
        }
    }

    /// Starts the output: the report directory with its provenance, or the shard.
    fn begin(&self) -> Result<Sink> {
        let provenance = Provenance::begin(&[&self.scene]);
        if let Some(shard) = self.shard {
            let settings = serde_json::to_value(&self.settings).map_err(|e| {
                Error::io(self.out.join(langevin_fem::shard::SHARD_MANIFEST), e.into())
            })?;
            let scenes = vec![ShardScene::of(&self.scene, &self.seed_note)];
            let writer =
                ShardWriter::begin(&self.out, COMMAND, shard, settings, scenes, provenance)?;
            return Ok(Sink::Shard(writer));
        }
        let report = ReportRun::begin(&self.out, "run", "manifest.json", &[SIDECAR])?;
        report.set_provenance(provenance.clone())?;
        Ok(Sink::Whole(provenance, report))
    }

    /// Completes the output: a shard's manifest, or the whole run's final provenance
    /// and sidecar listing `runs` (EA given for compression data); then the closing line
    /// naming `what`.
    fn finish(
        &self,
        sink: Sink,
        runs: Vec<DataRun>,
        stretch_rigidity: Option<f64>,
        what: String,
    ) -> Result<i32> {
        let (mut provenance, report) = match sink {
            Sink::Whole(provenance, report) => (provenance, report),
            Sink::Shard(writer) => {
                let manifest = writer.finish()?;
                let n = self.share().count;
                println!(
                    "shard {}: {} trajectory file(s) in {}; when every shard of {n} is done: langevin-fem merge <the {n} shard directories> -o <output dir>",
                    self.share(),
                    manifest.files.len(),
                    self.out.display(),
                );
                return Ok(0);
            }
        };
        provenance.finish();
        report.set_provenance(provenance.clone())?;
        let sidecar = self.sidecar(&report, provenance, runs, stretch_rigidity);
        let out = &self.out;
        let text = serde_json::to_string_pretty(&sidecar)
            .map_err(|e| Error::io(out.join(SIDECAR), e.into()))?
            + "\n";
        report.finish(&[(SIDECAR, text.as_bytes())])?;
        println!(
            "wrote {what} to {}; check them with: langevin-fem check --scene {} --data {}",
            out.display(),
            shell_word(&scene_argument(&self.scene)),
            shell_word(&out.display().to_string())
        );
        Ok(0)
    }

    /// The sidecar (`data.json`) of the whole run `report` listing `runs`.
    fn sidecar(
        &self,
        report: &ReportRun,
        provenance: Provenance,
        runs: Vec<DataRun>,
        stretch_rigidity: Option<f64>,
    ) -> DataSidecar {
        let (scene, f) = (&self.scene, self.scene.filament);
        DataSidecar {
            format: FORMAT.to_string(),
            version: VERSION,
            producer: format!("langevin-fem {}", env!("CARGO_PKG_VERSION")),
            dims: scene.dims,
            filament: scene.membrane.is_none().then_some(DataFilament {
                length: f.length,
                bending_rigidity: f.bending_rigidity,
                drag: f.drag,
                kt: f.kt,
                stretch_rigidity,
            }),
            membrane: scene.membrane.as_ref().map(DataMembrane::of),
            runs,
            provenance: Some(serde_json::json!({
                "run_id": report.run_id(),
                "budget": self.budget().name(),
                "seed": scene.seed,
                "seed_note": self.seed_note,
                "tau1": scene.tau1(),
                "journal": "manifest.json",
                "record": provenance,
            })),
            columns: Some(trajectory_columns_with_ends(
                scene.is_membrane(),
                scene.ends,
            )),
        }
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
            elements_y: self
                .scene
                .is_membrane()
                .then(|| self.scene.mesh.elements_along_y()),
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
    let runs = if args.runs.is_empty() {
        scene.runs.iter().map(|r| r.name.clone()).collect()
    } else {
        args.runs.clone()
    };
    let settings = RunSettings {
        budget: args.budget.budget(),
        runs,
        trajectories: args.trajectories,
        duration_tau1: args.duration_tau1,
        every: args.every,
        format: args.format,
    };
    let mut job = Job::new(
        settings,
        scene,
        seed_note,
        args.out,
        verbosity,
        (args.shard, args.limits.limits()),
    )?;
    job.max_output_bytes = Some(args.max_output_gib * GIB);
    if job.scene.compression.is_some() {
        run_compression(&job)
    } else {
        run_linear(&job)
    }
}

/// The chosen runs of a linear scene, prepared, with their row plans.
fn prepare_linear(job: &Job) -> Result<(Vec<LinearRun>, Vec<RowPlan>)> {
    let scene = &job.scene;
    let tau1 = scene.tau1();
    let runs = job
        .chosen
        .iter()
        .map(|&k| {
            let run = LinearRun::prepare_for_writing(scene, &scene.runs[k])
                .map_err(|e| scene.run_error(k, "integrator", e))?;
            run.require_forgetting(scene, k)?;
            Ok(run)
        })
        .collect::<Result<Vec<_>>>()?;
    let plans = job
        .chosen
        .iter()
        .zip(&runs)
        .map(|(&k, run)| {
            let steps = run.sampled_steps(job.ensemble(k).1 * tau1);
            run.row_plan(scene, steps, job.settings.every)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((runs, plans))
}

/// What a linear job writes, for the closing line.
fn linear_what(job: &Job) -> String {
    let total: u64 = job.chosen.iter().map(|&k| job.ensemble(k).0 as u64).sum();
    format!(
        "{total} trajectories of {} ({} run(s))",
        job.scene.name,
        job.chosen.len()
    )
}

/// `run` of a linear scene: every chosen run's trajectories (this shard's) from rest,
/// streamed.
fn run_linear(job: &Job) -> Result<i32> {
    let scene = &job.scene;
    let (runs, plans) = prepare_linear(job)?;
    warn_short_for_check(job, &runs, &plans);
    // This shard's share of the work.
    let work = projection(job, &runs, &plans).scaled(job.share().fraction());
    job.limits.check(&work)?;
    check_output_size(job, &plans)?;
    let mut sink = job.begin()?;
    let bar = Progress::new(job.verbosity.progress(), work.dof_steps(), "DOF-steps");
    let mut data_runs = Vec::new();
    for (((&k, run), plan), part) in job.chosen.iter().zip(&runs).zip(&plans).zip(&work.parts) {
        let label = format!("{}/{}", scene.name, scene.runs[k].name);
        bar.begin_run(&scene.name, &label, part.work.dof_steps);
        data_runs.push(write_linear_run(job, &mut sink, k, run, plan, &bar)?);
    }
    bar.finish();
    job.finish(sink, data_runs, None, linear_what(job))
}

/// Warns (stderr, also under `--quiet`) of every chosen run whose trajectories `check`
/// would refuse as too short for the slowest mode ([`LinearRun::short_for_check`]),
/// naming the sampled duration that would serve. The files are written all the same: they
/// may be for the user's own analysis.
fn warn_short_for_check(job: &Job, runs: &[LinearRun], plans: &[RowPlan]) {
    let tau1 = job.scene.tau1();
    for ((&k, run), plan) in job.chosen.iter().zip(runs).zip(plans) {
        if let Some(s) = run.short_for_check(plan) {
            let dt_sample = plan.every as f64 * run.reference.dt;
            let duration = (s.needed as f64 * dt_sample / tau1 * 100.0).ceil() / 100.0;
            eprintln!(
                "warning: {}/{}: each trajectory will have {} rows after the burn-in; `langevin-fem check` needs at least {} (mode 1 is taken every {} rows, {MIN_SERIES_LEN} samples at least) and will refuse these files: --duration-tau1 {duration} or more would serve",
                job.scene.name, job.scene.runs[k].name, s.stationary, s.needed, s.sparsest
            );
        }
    }
}

/// Bytes in a GiB.
const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Refuses a linear job whose trajectory files (this shard's) would exceed
/// `--max-output-gib`: rows × columns × bytes a value, summed over the files, before
/// anything runs (a long run at `--every 1` could otherwise fill the disk).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--max-output-gib`, the projected size and what
/// drives it.
fn check_output_size(job: &Job, plans: &[RowPlan]) -> Result<()> {
    let Some(cap) = job.max_output_bytes else {
        return Ok(());
    };
    let per_value = match job.settings.format {
        FormatArg::Npy => 8.0,
        FormatArg::Csv => 25.0,
    };
    let mut total = 0.0;
    let mut largest = (0.0, 0u64, 0usize);
    for (&k, plan) in job.chosen.iter().zip(plans) {
        let range = job.share().range(job.ensemble(k).0 as u64);
        let file = plan.rows as f64 * plan.columns.len() as f64 * per_value;
        total += file * (range.end - range.start) as f64;
        if file > largest.0 {
            largest = (file, plan.rows, plan.columns.len());
        }
    }
    if total <= cap {
        return Ok(());
    }
    let (_, rows, cols) = largest;
    Err(Error::invalid(
        "--max-output-gib",
        cap / GIB,
        format!(
            "at least the {:.3} GiB the trajectory files would take ({rows} rows x {cols} columns a file at most, {}): raise --every, lower --duration-tau1 or --trajectories, or raise --max-output-gib deliberately",
            total / GIB,
            job.ext()
        ),
    ))
}

/// Simulates and writes this shard's trajectories of linear run `k`; returns its
/// sidecar entry.
fn write_linear_run(
    job: &Job,
    sink: &mut Sink,
    k: usize,
    run: &LinearRun,
    plan: &RowPlan,
    bar: &Progress,
) -> Result<DataRun> {
    let (scene, out) = (&job.scene, &job.out);
    let spec = &scene.runs[k];
    let count = job.ensemble(k).0 as u64;
    let range = job.share().range(count);
    let per_trajectory = bar.run_work() / (range.end - range.start).max(1) as f64;
    let files: Vec<String> = (0..count)
        .map(|j| linear_file(&spec.name, j, job.ext()))
        .collect();
    let paths = range
        .clone()
        .map(|j| sink.record(out, &files[j as usize]))
        .collect::<Result<Vec<_>>>()?;
    let seed = derive_seed(scene.seed, &spec.name);
    run.write_ensemble(
        seed,
        range.clone(),
        plan,
        |j| paths[(j - range.start) as usize].clone(),
        |n| bar.advance(n as f64 * per_trajectory),
    )
    .map_err(|e| scene.run_error(k, "dt_tau1", e))?;
    for j in range.clone() {
        sink.written((&scene.name, &spec.name), &files[j as usize], j)?;
    }
    if job.verbosity == Verbosity::Verbose {
        bar.println(&format!(
            "{} / {}: {} trajectories x {} rows",
            scene.name,
            spec.name,
            range.end - range.start,
            plan.rows
        ));
    }
    Ok(linear_data_run(job, k, run, plan, files))
}

/// The sidecar entry of linear run `k` with its trajectory files `files`.
fn linear_data_run(
    job: &Job,
    k: usize,
    run: &LinearRun,
    plan: &RowPlan,
    files: Vec<String>,
) -> DataRun {
    let dt = run.reference.dt;
    DataRun {
        name: job.scene.runs[k].name.clone(),
        dt_sample: plan.every as f64 * dt,
        start: Start::Rest,
        burn_in: run.burn_in_steps as f64 * dt,
        positions: plan.positions.clone(),
        modes: run.reference.modes.len(),
        discretization: Some(job.discretization(k, dt)),
        files,
        strain_ratio: None,
        rigid: !run.reference.rigid.is_empty(),
        tangent_modes: run.reference.tangent.len(),
    }
}

/// The projected work of the whole run: per chosen run, every trajectory's steps
/// (burn-in included) times the unknowns each updates, at the cost per step of the
/// scene's own projection.
fn projection(job: &Job, runs: &[LinearRun], plans: &[RowPlan]) -> WorkProjection {
    let parts = job.scene.projected_work(job.budget());
    WorkProjection {
        command: "run".to_string(),
        parts: job
            .chosen
            .iter()
            .zip(runs.iter().zip(plans))
            .map(|(&k, (run, plan))| {
                let mut part = parts[k].clone();
                // The step's cost alone: the preparation (set-up) is done by now.
                let per_step = job.scene.step_cost(&job.scene.runs[k]);
                let n = job.ensemble(k).0 as f64;
                let steps = n * (plan.rows * plan.every) as f64;
                // Writing a row evaluates every deflection column (a spectral model sums
                // its modes at each position): at `--every 1` this, not the step, is
                // the cost.
                let rows = n * plan.rows as f64;
                let values = (job.scene.components() * plan.positions.len()) as f64;
                let row_work = rows * values * run.deflection_cost();
                part.work = RunWork {
                    trajectory_steps: steps,
                    dof_steps: steps * per_step + row_work,
                    samples: (plan.columns.len() * LANES) as f64,
                };
                part.drivers = format!(
                    "{}; {} trajectories x {} rows of {} columns written ({} DOF-steps to evaluate them)",
                    part.drivers,
                    n,
                    plan.rows,
                    plan.columns.len(),
                    langevin_fem::work::count(row_work)
                );
                flag_driven(job, part)
            })
            .collect(),
    }
}

/// `part` named after `--trajectories` / `--duration-tau1` where they were given (they, not
/// the scene's budget keys, then drive the work): the refusal names the flags first.
fn flag_driven(job: &Job, mut part: Part) -> Part {
    let mut flags = Vec::new();
    if let Some(n) = job.settings.trajectories {
        flags.push(format!("--trajectories {n}"));
    }
    if let Some(d) = job.settings.duration_tau1 {
        flags.push(format!("--duration-tau1 {d}"));
    }
    if !flags.is_empty() {
        let flags = flags.join(", ");
        part.drivers = format!("{flags} (the flags; the scene's {})", part.drivers);
        part.origin = Origin::Flags(flags);
    }
    part
}

/// The chosen runs of a compression scene, prepared. A budget by target precision
/// chooses durations by a pilot: `--duration-tau1` is then required.
fn prepare_compression(job: &Job) -> Result<Vec<CompressionRun>> {
    let scene = &job.scene;
    let Some(comp) = &scene.compression else {
        return Ok(Vec::new());
    };
    for &k in &job.chosen {
        let e = scene.runs[k].ensemble(job.budget());
        if e.precision_target().is_some() && job.settings.duration_tau1.is_none() {
            return Err(Error::invalid(
                "--duration-tau1",
                "not given",
                format!(
                    "a duration in tau1: the {} budget of run {} chooses its durations by a pilot (target precision), which run does not do",
                    job.budget().name(),
                    scene.runs[k].name
                ),
            ));
        }
    }
    job.chosen
        .iter()
        .map(|&k| {
            CompressionRun::prepare(scene, comp, &scene.runs[k])
                .map_err(|e| scene.run_error(k, "integrator", e))
        })
        .collect()
}

/// What a compression job writes, for the closing line.
fn compression_what(job: &Job) -> String {
    let strains = job
        .scene
        .compression
        .as_ref()
        .map_or(0, |c| c.strain_ratios.len());
    let total: u64 = job
        .chosen
        .iter()
        .map(|&k| (job.ensemble(k).0 * strains) as u64)
        .sum();
    format!(
        "{total} trajectories of {} ({} run(s) x {strains} strains)",
        job.scene.name,
        job.chosen.len()
    )
}

/// `run` of a compression scene: per run and strain, every trajectory's (this shard's)
/// F and stored length after the burn-in (the samples `verify` takes, same seeds), one
/// data run per strain in the sidecar.
fn run_compression(job: &Job) -> Result<i32> {
    let scene = &job.scene;
    scene.refuse_membrane("run of a membrane under imposed projected area")?;
    let runs = prepare_compression(job)?;
    // This shard's share of the work.
    let work = compression_projection(job).scaled(job.share().fraction());
    job.limits.check(&work)?;
    let mut sink = job.begin()?;
    let bar = Progress::new(job.verbosity.progress(), work.dof_steps(), "DOF-steps");
    let mut data_runs = Vec::new();
    for ((&k, run), part) in job.chosen.iter().zip(&runs).zip(&work.parts) {
        let label = format!("{}/{}", scene.name, scene.runs[k].name);
        bar.begin_run(&scene.name, &label, part.work.dof_steps);
        data_runs.extend(write_compression_run(job, &mut sink, k, run, &bar)?);
    }
    bar.finish();
    let ea = Some(scene.filament.stretch_rigidity);
    job.finish(sink, data_runs, ea, compression_what(job))
}

/// The projected work of the chosen compression runs: the scene's projection at the
/// budget, scaled up to the flags' trajectories and duration (against the longest
/// duration of a budget by target precision).
fn compression_projection(job: &Job) -> WorkProjection {
    let parts = job.scene.projected_work(job.budget());
    WorkProjection {
        command: "run".to_string(),
        parts: job
            .chosen
            .iter()
            .map(|&k| {
                let mut part = parts[k].clone();
                let (n, d) = job.ensemble(k);
                let e = job.scene.runs[k].ensemble(job.budget());
                let projected = e
                    .precision_target()
                    .map_or(e.duration_tau1, |t| t.max_duration_tau1);
                let scale = (n as f64 / e.trajectories.max(1) as f64) * (d / projected.max(1e-300));
                if scale.is_finite() {
                    part.work.trajectory_steps *= scale.max(1.0);
                    part.work.dof_steps *= scale.max(1.0);
                }
                flag_driven(job, part)
            })
            .collect(),
    }
}

/// Simulates this shard's trajectories of compression run `k` at every strain and
/// writes each one's F and stored length; returns one sidecar entry per strain.
fn write_compression_run(
    job: &Job,
    sink: &mut Sink,
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
    let range = job.share().range(n as u64);
    let share = (range.end - range.start) as usize;
    let per_trajectory = bar.run_work() / (share * run.points()).max(1) as f64;
    let steps: Vec<u64> = (0..run.points())
        .map(|i| run.sampled_steps_at(i, duration * f.tau1()))
        .collect();
    let seed = |i: usize| derive_seed(scene.seed, &format!("{}/{i}", spec.name));
    let records = run
        .simulate_share_per_point(seed, range.clone(), &steps, || bar.advance(per_trajectory))
        .map_err(|e| scene.run_error(k, "dt_tau1", e))?;
    let columns: Vec<String> = COMPRESSION_COLUMNS.iter().map(|c| c.to_string()).collect();
    let euler_strain = PI.powi(2) * f.bending_rigidity / (f.stretch_rigidity * f.length.powi(2));
    for (i, at_strain) in records.iter().enumerate() {
        let strain = comp.strain_ratios[i] * euler_strain;
        let (dts, burn_in) = (run.sample_dt_at(i), run.burn_in_at(i));
        for (j, rec) in (range.start..).zip(at_strain) {
            let rel = compression_file(&spec.name, i, j, job.ext());
            let path = sink.record(&job.out, &rel)?;
            let mut file = TrajectoryFile::create(&path, &columns, rec.force_ratio.len() as u64)?;
            for (r, fr) in rec.force_ratio.iter().enumerate() {
                let force = fr * run.euler_load;
                let stored = (strain - force / f.stretch_rigidity) * f.length;
                file.push_row(&[burn_in + (r + 1) as f64 * dts, force, stored])?;
            }
            file.commit()?;
            sink.written((&scene.name, &strain_key(&spec.name, i)), &rel, j)?;
        }
    }
    Ok(compression_data_runs(job, k, run, n as u64))
}

/// The sidecar entries of compression run `k`, one per strain, each listing the `n`
/// trajectory files of its strain.
fn compression_data_runs(job: &Job, k: usize, run: &CompressionRun, n: u64) -> Vec<DataRun> {
    let Some(comp) = &job.scene.compression else {
        return Vec::new();
    };
    let name = &job.scene.runs[k].name;
    comp.strain_ratios
        .iter()
        .take(run.points())
        .enumerate()
        .map(|(i, &ratio)| DataRun {
            name: name.clone(),
            dt_sample: run.sample_dt_at(i),
            start: Start::Stationary,
            burn_in: run.burn_in_at(i),
            positions: Vec::new(),
            modes: 0,
            discretization: Some(job.discretization(k, run.dt_at(i))),
            files: (0..n)
                .map(|j| compression_file(name, i, j, job.ext()))
                .collect(),
            strain_ratio: Some(ratio),
            rigid: false,
            tangent_modes: 0,
        })
        .collect()
}
