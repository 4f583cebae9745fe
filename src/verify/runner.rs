//! The verification runner: checks the input, runs scenes, applies the family-wise
//! correction and writes the per-scene CSV tables and SVG figures through a
//! [`ReportRun`]; it returns the [`Summary`] and the open report run, which
//! [`crate::report::write_report`] finishes with `summary.json` and `index.html`.
//!
//! The runs' trajectories are simulated here, or, for `merge`, read from a complete set
//! of shards ([`Ensembles::Merge`], [`super::shard`]): everything after that is the same
//! code on the same records, so a merged report is the unsharded one.
//!
//! # Errors and exit codes
//! Everything that can be checked before a simulation is (scene files, every run's
//! set-up, the samples each check will get at the budget: [`Error::Scene`], exit 2), and
//! the earlier report is left untouched then. A failure after the runs started — a
//! divergence, an estimator that finds no answer in the data, a factorization that
//! fails — is a run failure (exit 3) naming the run and the observable
//! ([`Error::RunFailed`]), never an input error.
//!
//! # Outputs
//! Under `--out`: the entry points `summary.json` and `index.html`, the journal
//! `manifest.json` ([`crate::output::manifest`]: run id, every file of the run, the
//! provenance and the columns of every CSV file with their units), and
//! for scene `<scene>` in `<scene>/`:
//!
//! - a linear scene, per run `<run>`: `<run>-modes.csv` and `.svg` (modal variance against
//!   equipartition, when estimated), `<run>-mode-statistics.csv`, `<run>-rates.svg` (when
//!   rates were estimated), `<run>-profile.csv` and `.svg`, `<run>-two-time.csv` and
//!   `.svg`, `<run>-spectrum.csv` and `.svg` (Welch spectra per mode; when the checks
//!   produced them);
//! - a membrane scene, in addition: `<run>-height-spectrum.svg` (each mode's variance
//!   against its wavenumber |q| on log–log axes, with the continuum law (M3), when the
//!   variances were estimated), and the columns `m`, `n` (lattice indices) and `q` (|q|)
//!   after `mode` in `<run>-modes.csv` and `<run>-mode-statistics.csv`; its profile and
//!   two-time outputs are on the midline y = b/2, against (M5) and (M4). The words and
//!   continuum curves of every figure are the object's (`subject.rs`); a filament's
//!   outputs are the same as before membranes ran here;
//! - a `fem` scene with an element-uniform run: the element-count study of that noise
//!   (theory only, [`element_uniform_variance_ratios`]), `element-uniform-vs-elements.csv`
//!   and `.svg` and a note, written right after the outputs of the first such run;
//! - a compression scene: `force-strain.csv` (first run), `<run>-force-strain.csv` (other
//!   runs), `force-strain.svg`, and `fig2.svg` under `--out` with the first run of every
//!   compression scene so far (one per dimension) whose strains are all ≥ 0 (the paper's
//!   Fig. 2 is imposed compression; a scene reaching into tension writes no `fig2.svg`,
//!   and its `force-strain.svg` adds the Gaussian mean field and the athermal rod).
//!
//! Every figure has axis labels with units and a caption, listed beside it in
//! `summary.json` (`captions`, parallel to `figures`) and written into the SVG as its
//! `<title>`.
//!
//! A rerun removes the files of the earlier run that it does not write again (e.g. of a
//! scene left out); an interrupted run leaves no entry point (see
//! [`crate::output::manifest`]).

use crate::error::{Error, Result};
use crate::fem::noise::{NoiseModel, element_uniform_variance_ratios};
use crate::output::{AxisUnits, Figure, Provenance, ReportRun, Series, SeriesStyle};
use crate::params::physical::units_note;
use crate::progress::{Progress, ProgressOptions};
use crate::rng::derive_seed;
use crate::scene::compression::{
    CompressionRun, CompressionTheoryTable, DURATION_SAFETY, ForceEstimates, ForceRecord,
    PROBE_STEPS, StepChoice, force_estimates_diagnosed, targeted_duration,
};
use crate::scene::linear::{LinearRun, TrajectoryRecord, small_slope_warning};
use crate::scene::{Budget, CheckKind, Ensemble, ModelKind, PrecisionTarget, Scene};
use crate::shard::{Shard, ShardSet};
use crate::stats;
use crate::verify::checks::{LinearEstimates, linear_checks};
use crate::verify::compression::{compression_checks, halving_check};
use crate::verify::diagnosis::SensitivityOf;
use crate::verify::oracle::{Oracle, compression_oracle, linear_oracle};
use crate::verify::summary::{CheckResult, SceneSummary, SkippedCheck, Summary};
use crate::work::{WorkLimits, WorkProjection};
use std::path::{Path, PathBuf};
use std::time::Instant;
use subject::{Subject, Words};

mod subject;

/// Options of a verification run.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    /// The scenes to run, loaded and validated ([`crate::scene::load_scenes`]).
    pub scenes: Vec<Scene>,
    /// Budget.
    pub budget: Budget,
    /// Output directory.
    pub out: PathBuf,
    /// Family-wise significance level per scene (Holm).
    pub alpha: f64,
    /// Progress on stderr, over the projected work of the runs, naming the scene and the
    /// run ([`crate::progress`]).
    pub progress: ProgressOptions,
    /// The caps on the projected work and memory of all the scenes
    /// ([`projected_work`]), checked before anything runs.
    pub limits: WorkLimits,
    /// Where the runs' trajectories come from: simulated here, or read from shards.
    pub ensembles: Ensembles,
}

/// Where a verification's trajectories come from (issue #15, [`crate::shard`]).
#[derive(Debug, Clone, Default)]
pub enum Ensembles {
    /// Every trajectory simulated by this process.
    #[default]
    Simulate,
    /// Every run's records read from a complete set of shards (`merge`), in trajectory
    /// order: nothing is simulated, and the outputs are those of [`Ensembles::Simulate`].
    Merge(std::sync::Arc<ShardSet>),
}

/// The projected work of verifying `scenes` at `budget`: every run of every scene, one
/// after the other ([`Scene::projected_work`]).
pub fn projected_work(scenes: &[Scene], budget: Budget) -> WorkProjection {
    WorkProjection {
        command: format!("verify --budget {}", budget.name()),
        parts: scenes
            .iter()
            .flat_map(|s| s.projected_work(budget))
            .collect(),
    }
}

/// Element counts of the element-uniform noise study (theory only).
const NOISE_STUDY_ELEMENTS: [usize; 6] = [5, 10, 20, 40, 80, 160];
/// Modes of the element-uniform noise study (the columns `mode1` … `mode6`).
const NOISE_STUDY_MODES: usize = 6;

/// File name of the journal of a verification report ([`crate::output::manifest`]).
pub const MANIFEST: &str = "manifest.json";
/// The entry points of a verification report, in the order they are written, last.
pub const ENTRY_POINTS: [&str; 2] = ["summary.json", "index.html"];

/// Checks every scene, then runs them and writes their tables and figures; returns the
/// summary (with the run id and every file of the report) and the report run, to be
/// finished by [`crate::report::write_report`]. The earlier report in `opts.out` is
/// invalidated only once the input has passed every check.
///
/// # Errors
/// Input (exit 2): bad scene files, a projected work or memory above `opts.limits`, a time
/// step above a stability limit, a budget that gives a check fewer samples than its
/// estimator needs ([`Error::Scene`]). Run failures (exit 3): diverging runs
/// ([`Error::Diverged`]), estimator or set-up failures ([`Error::RunFailed`]), I/O
/// failures.
pub fn run_verification(opts: &VerifyOptions) -> Result<(Summary, ReportRun)> {
    let scenes = &opts.scenes;
    let provenance = Provenance::begin(&scenes.iter().collect::<Vec<_>>());
    // The total work and memory, from the scene files alone, before anything is prepared.
    let mut work = projected_work(scenes, opts.budget);
    if let Ensembles::Merge(_) = opts.ensembles {
        // Nothing is simulated, but the records held at once are the whole run's.
        work = work.scaled(0.0);
    }
    opts.limits.check(&work)?;
    let prepared = prepare_all(scenes, opts.budget)?;
    let report = ReportRun::begin(&opts.out, "verify", MANIFEST, &ENTRY_POINTS)?;
    report.set_provenance(provenance)?;
    let bar = Progress::new(opts.progress, work.dof_steps(), "DOF-steps");
    let mut summaries = Vec::new();
    let mut curves = Vec::new();
    for (scene, work) in scenes.iter().zip(&prepared) {
        summaries.push(match work {
            Prepared::Linear(runs, oracles) => {
                run_scene(scene, runs, oracles, opts, &report, &bar)?
            }
            Prepared::Compression(theory, oracle, runs) => run_compression_scene(
                scene,
                (theory, oracle),
                runs,
                opts,
                &report,
                &bar,
                &mut curves,
            )?,
        });
    }
    bar.finish();
    let summary = Summary {
        run_id: report.run_id(),
        budget: opts.budget.name().to_string(),
        alpha: opts.alpha,
        passed: summaries.iter().all(|s| s.passed),
        scenes: summaries,
        files: report.files(),
        provenance: report.provenance_ref(),
    };
    Ok((summary, report))
}

/// Prepares every run of every scene and checks, before any long work, that the budget
/// gives each check the samples it needs ([`check_sample_counts`]).
///
/// # Errors
/// As [`prepare`] and [`check_sample_counts`].
pub(super) fn prepare_all(scenes: &[Scene], budget: Budget) -> Result<Vec<Prepared>> {
    let prepared = scenes.iter().map(prepare).collect::<Result<Vec<_>>>()?;
    for (scene, work) in scenes.iter().zip(&prepared) {
        if let Prepared::Linear(runs, oracles) = work {
            // A run whose references fail the oracle is not simulated: its sampling
            // plan (from wrong rates) is not the user's to fix.
            for (k, run) in runs.iter().enumerate() {
                if oracles[k].passed() {
                    check_sample_counts(scene, k, run, budget)?;
                    run.require_forgetting(scene, k)?;
                }
            }
        }
    }
    Ok(prepared)
}

/// The run `k` of `scene` as named in a run failure: file, index and name.
fn run_label(scene: &Scene, k: usize) -> String {
    format!(
        "{}: runs[{k}] ({})",
        scene.path.display(),
        scene.runs.get(k).map_or("?", |r| r.name.as_str())
    )
}

/// An error of run `k` while it simulates: a time step above a stability limit is input
/// (exit 2, naming `runs[k].dt_tau1`); a divergence names the run and step; anything
/// else is a run failure of the simulation (exit 3).
fn simulation_error(scene: &Scene, k: usize, err: Error) -> Error {
    match err {
        Error::UnstableTimeStep { .. } | Error::Diverged { .. } | Error::Scene { .. } => {
            scene.run_error(k, "dt_tau1", err)
        }
        other => Error::run_failed(run_label(scene, k), "simulation", other),
    }
}

/// An estimator's failure on the data of run `k` (after the run): a run failure naming
/// the observable, with the advice to raise `budget_key` (the input passed every check
/// made before the run, so this is not an input error).
fn estimation_error(
    scene: &Scene,
    k: usize,
    observable: &str,
    budget_key: &str,
    err: Error,
) -> Error {
    Error::run_failed(run_label(scene, k), observable, err).with_advice(&format!(
        "the data did not support the estimate; if the series are short compared with \
         their correlation time, raising runs[{k}].{budget_key} may help"
    ))
}

/// An error preparing run `k` (before any simulation): a numerical failure of the
/// set-up (a factorization of a matrix that should be positive definite, an
/// eigensolver) is a run failure (exit 3); anything else is input, named by
/// [`Scene::run_error`].
fn prepare_error(scene: &Scene, k: usize, err: Error) -> Error {
    match err {
        Error::Numerical { .. } => Error::run_failed(
            run_label(scene, k),
            "set-up (matrices, modes, references)",
            err,
        ),
        other => scene.run_error(k, "integrator", other),
    }
}

/// Refuses, before anything runs, linear run `k` of `scene` if at `budget` a check would
/// get fewer samples than its estimator accepts: at least
/// [`stats::moments::MIN_SERIES_LEN`] samples per profile series (profile check) and per mode
/// series (mode-variance check), and two values per two-time point (two-time check).
/// Whether a series that long is also long enough for its correlation time shows only
/// in the data: that is then a run failure with advice ([`estimation_error`]).
///
/// # Errors
/// [`Error::Scene`] naming `runs[k].<budget>.duration_tau1` (or `.trajectories`), the
/// value, the samples it gives and the smallest value that is enough.
fn check_sample_counts(scene: &Scene, k: usize, run: &LinearRun, budget: Budget) -> Result<()> {
    let e = run.spec.ensemble(budget);
    let checks = run.spec.checks(scene);
    let tau1 = scene.tau1();
    let dt_tau1 = run.reference.dt / tau1;
    let steps = run.sampled_steps(e.duration_tau1 * tau1);
    let key = |k2: &str| format!("runs[{k}].{}.{k2}", budget.name());
    let min = stats::moments::MIN_SERIES_LEN as u64;
    let mut series: Vec<(String, u64)> = Vec::new();
    if checks.contains(&CheckKind::Profile) && !run.reference.profile_x.is_empty() {
        series.push(("each profile series".to_string(), run.profile_every));
    }
    if checks.contains(&CheckKind::ModeVariance) {
        for (m, &every) in run.reference.modes.iter().zip(&run.mode_every) {
            series.push((format!("mode {}", m.n), every));
        }
    }
    // The sparsest series gets the fewest samples: it sets the duration needed.
    if let Some((what, every)) = series.into_iter().max_by_key(|(_, every)| *every) {
        let samples = steps / every;
        if samples < min {
            return Err(Error::Scene {
                file: scene.path.clone(),
                key: key("duration_tau1"),
                message: format!(
                    "must be >= {} (at least {min} samples of {what}, one every {every} steps of dt_tau1 = {dt_tau1}), got {}, which gives {samples}; raise it, or lower runs[{k}].dt_tau1",
                    (min * every) as f64 * dt_tau1,
                    e.duration_tau1
                ),
            });
        }
    }
    let values = (e.trajectories + e.two_time_trajectories) * run.components;
    if checks.contains(&CheckKind::TwoTime) && !run.reference.two_time.is_empty() && values < 2 {
        return Err(Error::Scene {
            file: scene.path.clone(),
            key: key("trajectories"),
            message: format!(
                "must give at least 2 values per two-time point (trajectories + two_time_trajectories, times {} components), got {} trajectories and {} two-time trajectories",
                run.components, e.trajectories, e.two_time_trajectories
            ),
        });
    }
    Ok(())
}

/// The prepared work of one scene: the runs, their exact references and the oracle's
/// verdict on those references ([`oracle`]).
pub(super) enum Prepared {
    /// A linear scene: its runs and, per run, the oracle of its references.
    Linear(Vec<LinearRun>, Vec<Oracle>),
    /// A compression scene: the exact theory, its oracle, the runs.
    Compression(CompressionTheoryTable, Oracle, Vec<CompressionRun>),
}

/// Prepares every run of `scene` (and the exact theory of a compression scene); errors
/// name the scene file and the run.
fn prepare(scene: &Scene) -> Result<Prepared> {
    let Some(comp) = &scene.compression else {
        let runs = scene
            .runs
            .iter()
            .enumerate()
            .map(|(i, spec)| {
                LinearRun::prepare(scene, spec).map_err(|e| prepare_error(scene, i, e))
            })
            .collect::<Result<Vec<_>>>()?;
        let oracles = runs.iter().map(|r| linear_oracle(scene, r)).collect();
        return Ok(Prepared::Linear(runs, oracles));
    };
    let runs = scene
        .runs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            CompressionRun::prepare(scene, comp, spec).map_err(|e| prepare_error(scene, i, e))
        })
        .collect::<Result<_>>()?;
    let theory = CompressionTheoryTable::new(scene, comp).map_err(|e| match e {
        Error::Numerical { .. } => Error::run_failed(
            scene.path.display().to_string(),
            "exact compression theory (before any run)",
            e,
        ),
        other => scene.run_error(0, "integrator", other),
    })?;
    let oracle = compression_oracle(scene, comp).map_err(|e| {
        Error::run_failed(
            scene.path.display().to_string(),
            "oracle of the compression theory (before any run)",
            e,
        )
    })?;
    Ok(Prepared::Compression(theory, oracle, runs))
}

/// Starts run `k` of `scene` on `bar`: labelled `scene/run`, of the `share` of its
/// projected work at `budget` that this process does (1 for a whole run, 1/N for a
/// shard).
pub(super) fn begin_run(bar: &Progress, scene: &Scene, k: usize, budget: Budget, share: f64) {
    let run = scene.runs.get(k).map_or("?", |r| r.name.as_str());
    let work = run_projected_work(scene, k, budget) * share;
    bar.begin_run(&scene.name, &format!("{}/{run}", scene.name), work);
}

/// The projected work (DOF-steps) of run `k` of `scene` at `budget`, whole
/// ([`Scene::projected_work`]).
fn run_projected_work(scene: &Scene, k: usize, budget: Budget) -> f64 {
    scene
        .projected_work(budget)
        .get(k)
        .map_or(0.0, |p| p.work.dof_steps)
}

/// What a scene produces, each list in the order of `summary.json`, and the report run
/// its files are written through.
struct SceneOutputs<'r> {
    /// The report run.
    report: &'r ReportRun,
    /// The checks, before the family-wise correction.
    checks: Vec<CheckResult>,
    /// Figures written, each with its caption.
    figures: Vec<(PathBuf, String)>,
    /// Tables written.
    tables: Vec<PathBuf>,
    /// Notes for a reader; the first is the scene's description.
    notes: Vec<String>,
    /// Checks not evaluated (budget or data too small for them), with the reason.
    skipped: Vec<SkippedCheck>,
    /// The names of the runs whose checks these are (the scene's, or the data's for
    /// `check`): the first part of a check's name when it is one of them.
    runs: Vec<String>,
    /// Whether the run being written is referenced to the continuum (`check` of data
    /// whose discretization this tool does not model): its figures say so
    /// ([`SceneOutputs::words`]).
    continuum_references: bool,
    /// The membrane whose modes the hints of a failed run read (issue #27,
    /// [`crate::verify::diagnosis::diagnose_membrane`]): a linear membrane scene's, or for
    /// `check` the data's; `None` for a filament or a membrane under imposed area.
    membrane: Option<crate::spectral::MembraneParams>,
}

impl<'r> SceneOutputs<'r> {
    /// A figure's words as this run's references are: said of the continuum when they
    /// are the continuum's ([`Words::continuum_referenced`]).
    fn words(&self, words: Words) -> Words {
        if self.continuum_references {
            words.continuum_referenced()
        } else {
            words
        }
    }

    /// A figure's caption as this run's references are ([`subject::continuum_caption`]).
    fn caption(&self, caption: String) -> String {
        if self.continuum_references {
            subject::continuum_caption(&caption)
        } else {
            caption
        }
    }

    fn new(scene: &Scene, report: &'r ReportRun) -> Self {
        SceneOutputs {
            report,
            checks: Vec::new(),
            figures: Vec::new(),
            tables: Vec::new(),
            skipped: Vec::new(),
            runs: scene.runs.iter().map(|r| r.name.clone()).collect(),
            continuum_references: false,
            membrane: scene.membrane.filter(|_| scene.compression.is_none()),
            notes: std::iter::once(scene.description.clone())
                .chain(
                    scene
                        .physical
                        .as_ref()
                        .map(|p| units_note(&scene.filament, p)),
                )
                .collect(),
        }
    }

    /// Writes `fig` to `path` (SVG) and lists it, with its caption, among the scene's
    /// figures.
    fn write_figure(&mut self, fig: &Figure, path: PathBuf) -> Result<()> {
        self.report.write_svg(&path, fig)?;
        self.figures.push((path, fig.caption.clone()));
        Ok(())
    }

    /// Writes `rows` under `header` to `path` (CSV) and lists it among the scene's tables.
    fn write_table(&mut self, path: PathBuf, header: &[&str], rows: &[Vec<f64>]) -> Result<()> {
        self.report.write_csv(&path, header, rows)?;
        self.tables.push(path);
        Ok(())
    }
}

/// One dimension's simulated and theoretical force–strain curve, for the Fig. 2 figure.
struct Curve {
    dims: usize,
    theory: Vec<(f64, f64, f64)>,
    simulated: Vec<(f64, f64, f64)>,
}

/// Columns of `force-strain.csv`.
const FORCE_STRAIN_HEADER: [&str; 5] = [
    "strain_ratio",
    "force_ratio",
    "std_error",
    "theory_discrete",
    "theory_continuum",
];

/// Runs a compression scene: every run, its checks, table and points in the scene's
/// force–strain figure, the Δt-halving check, and `fig2.svg` (updated in `curves`).
fn run_compression_scene(
    scene: &Scene,
    (theory, oracle): (&CompressionTheoryTable, &Oracle),
    runs: &[CompressionRun],
    opts: &VerifyOptions,
    report: &ReportRun,
    bar: &Progress,
    curves: &mut Vec<Curve>,
) -> Result<SceneSummary> {
    let start = Instant::now();
    let dir = opts.out.join(&scene.name);
    let mut outputs = SceneOutputs::new(scene, report);
    outputs.checks.extend(oracle.checks.iter().cloned());
    outputs.notes.extend(oracle.notes.iter().cloned());
    if !oracle.passed() {
        outputs.notes.push(oracle.not_simulated_note("(every run)"));
        return finish_scene(scene, outputs, start, opts.alpha, &opts.out);
    }
    let mut estimates = Vec::new();
    let mut largest_slope: Option<(String, (f64, f64))> = None;
    // Each run's points in the scene's force–strain figure.
    let mut points: Vec<Series> = Vec::new();
    for_compression_runs(scene, runs, |k, run| {
        begin_run(bar, scene, k, opts.budget, 1.0);
        let (est, slope, steps) = run_compression(scene, theory, k, run, opts, bar, &mut outputs)?;
        if let Some((s, x, i)) = slope
            && largest_slope.as_ref().is_none_or(|l| s > l.1.0)
        {
            largest_slope = Some((
                format!(
                    "run {} at strain ratio {} (largest of the runs and strains)",
                    run.spec.name, theory.strain_ratios[i]
                ),
                (s, x),
            ));
        }
        let rows = force_strain_rows(theory, &est);
        let path = if k == 0 {
            dir.join("force-strain.csv")
        } else {
            dir.join(format!("{}-force-strain.csv", run.spec.name))
        };
        outputs.write_table(path, &FORCE_STRAIN_HEADER, &rows)?;
        points.push(force_points(
            format!("simulated: {} (±1 s.e.)", run.spec.name),
            &rows,
            k,
            theory,
        ));
        if k == 0 && !theory.reaches_tension() {
            curves.retain(|c| c.dims != scene.dims);
            curves.push(Curve {
                dims: scene.dims,
                theory: theory.curve.clone(),
                simulated: rows.iter().map(|r| (r[0], r[1], r[2])).collect(),
            });
        }
        estimates.push(est);
        Ok(steps)
    })?;
    let halving = scene_halving_check(scene, runs, &estimates)
        .map_err(|e| Error::run_failed(scene.path.display().to_string(), "dt-halving check", e))?;
    if let Some((check, note)) = halving {
        outputs.checks.push(check);
        outputs.notes.push(note);
    }
    let fig = points
        .into_iter()
        .fold(force_strain_figure(scene, theory), Figure::series);
    outputs.write_figure(&fig, dir.join("force-strain.svg"))?;
    // The paper's Fig. 2 is the filament under imposed compression: a scene reaching into
    // tension has its own figure only.
    if !theory.reaches_tension() {
        let fig2 = fig2_figure(curves);
        outputs.write_figure(&fig2, opts.out.join("fig2.svg"))?;
    }
    let mut summary = finish_scene(scene, outputs, start, opts.alpha, &opts.out)?;
    if let Some((what, slope)) = largest_slope {
        add_slope_status(scene, &mut summary, &what, slope);
    }
    Ok(summary)
}

/// The small-slope status of `scene` when its largest RMS slope exceeds the model's limit
/// ([`small_slope_warning`]): a warning for a user's scene file, which may be meant as a
/// physical filament; for a built-in scene, floppy on purpose to exercise the model, one
/// note in the report instead (a warning on every default run would teach users to
/// ignore warnings).
fn add_slope_status(scene: &Scene, summary: &mut SceneSummary, what: &str, slope: (f64, f64)) {
    let Some(text) = small_slope_warning(what, slope, &scene.filament) else {
        return;
    };
    let builtin = crate::scene::builtin::find(&scene.name).is_some_and(|b| scene.path == b.label());
    if builtin {
        summary.notes.push(format!(
            "small-slope status (a built-in scene, floppy on purpose): {text}"
        ));
    } else {
        summary.warnings.push(text);
    }
}

/// Calls `each(k, run)` on the runs of a compression scene in order, the second run of
/// the Δt-halving pair at half the steps that the first chose by a step search
/// ([`halved_steps`]); `each` returns the steps its run chose by a step search, if any.
///
/// # Errors
/// The first error of `each`, or of the halved run's set-up.
pub(super) fn for_compression_runs(
    scene: &Scene,
    runs: &[CompressionRun],
    mut each: impl FnMut(usize, &CompressionRun) -> Result<Option<Vec<f64>>>,
) -> Result<()> {
    let mut chosen: Vec<Option<Vec<f64>>> = Vec::new();
    for (k, run) in runs.iter().enumerate() {
        let halved = halved_steps(scene, runs, &chosen, k)
            .map(|dts| run.with_steps(&dts))
            .transpose()?;
        chosen.push(each(k, halved.as_ref().unwrap_or(run))?);
    }
    Ok(())
}

/// The steps of run `k` if it is the second run of the scene's Δt-halving pair and the
/// first (an earlier run, validated) chose its steps by a step search: half of those.
fn halved_steps(
    scene: &Scene,
    runs: &[CompressionRun],
    chosen: &[Option<Vec<f64>>],
    k: usize,
) -> Option<Vec<f64>> {
    let [a, b] = scene.compression.as_ref()?.halving.as_ref()?;
    if &runs[k].spec.name != b {
        return None;
    }
    let ia = runs.iter().position(|r| &r.spec.name == a)?;
    let steps = chosen.get(ia)?.as_ref()?;
    Some(steps.iter().map(|d| 0.5 * d).collect())
}

/// The largest RMS slope of a compression run: (slope in rad, x/L, strain index).
type RmsSlope = (f64, f64, usize);

/// Simulates run `k` of a compression scene at the budget and adds its checks and note
/// to `outputs`; returns its force estimates and its largest RMS slope (slope, x/L,
/// strain index).
fn run_compression(
    scene: &Scene,
    theory: &CompressionTheoryTable,
    k: usize,
    run: &CompressionRun,
    opts: &VerifyOptions,
    bar: &Progress,
    outputs: &mut SceneOutputs<'_>,
) -> Result<(ForceEstimates, Option<RmsSlope>, Option<Vec<f64>>)> {
    let e = run.spec.ensemble(opts.budget);
    let (records, plan) = match &opts.ensembles {
        Ensembles::Simulate => {
            simulate_compression(scene, k, run, &e, opts.budget, bar, (Shard::WHOLE, None))?
        }
        Ensembles::Merge(set) => super::shard::merged_compression(set, scene, run, &e)?,
    };
    let adapted = adapted_run(run, plan.as_ref())?;
    let run = adapted.as_ref().unwrap_or(run);
    let budget_key = match plan {
        None => format!("{}.duration_tau1", opts.budget.name()),
        Some(_) => format!("{}.max_duration_tau1", opts.budget.name()),
    };
    let est = force_estimates_diagnosed(&records, &scene.filament).map_err(|e| {
        estimation_error(scene, k, "force estimates <F> per strain", &budget_key, e)
    })?;
    outputs.checks.extend(
        compression_checks(run, run.spec.checks(scene), theory, &records, &est)
            .map_err(|e| estimation_error(scene, k, "compression checks", &budget_key, e))?,
    );
    let slope = run.largest_rms_slope(&records);
    outputs
        .notes
        .push(compression_run_note(scene, theory, run, &e, &est, slope));
    if let Some(plan) = &plan {
        outputs.notes.push(targeted_note(run, &e, plan, &est));
    }
    let steps = plan
        .and_then(|p| p.search)
        .map(|s| s.iter().map(|c| c.dt_tau1).collect());
    Ok((est, slope, steps))
}

/// Simulates shard `shard`'s share of the trajectories of compression run `k` at
/// ensemble `e` (every trajectory for [`Shard::WHOLE`]); returns the records per strain
/// and, for a budget by target precision, its plan: `known` (another shard's, `verify
/// --plan-from`), else its step search and pilot run here in full, whatever the shard
/// (the plan depends on the scene alone).
///
/// # Errors
/// As [`simulate_error`] and [`targeted_plan`].
pub(super) fn simulate_compression(
    scene: &Scene,
    k: usize,
    run: &CompressionRun,
    e: &Ensemble,
    budget: Budget,
    bar: &Progress,
    (shard, known): (Shard, Option<TargetedPlan>),
) -> Result<(Vec<Vec<ForceRecord>>, Option<TargetedPlan>)> {
    let tick = tick_work(scene, k, budget, run, e);
    let seed = |i: usize| derive_seed(scene.seed, &format!("{}/{i}", run.spec.name));
    let range = shard.range(e.trajectories.max(1) as u64);
    let (steps, plan) = match e.precision_target() {
        None => {
            let steps: Vec<u64> = (0..run.points())
                .map(|i| run.sampled_steps_at(i, e.duration_tau1 * scene.tau1()))
                .collect();
            (steps, None)
        }
        Some(target) => {
            let plan = match known {
                Some(plan) => plan,
                None => targeted_plan(scene, k, run, e, target, budget, bar)?,
            };
            (plan.main_steps.clone(), Some(plan))
        }
    };
    let adapted = adapted_run(run, plan.as_ref())?;
    let records = adapted
        .as_ref()
        .unwrap_or(run)
        .simulate_share_per_point(seed, range, &steps, || bar.advance(tick))
        .map_err(|e| simulation_error(scene, k, e))?;
    Ok((records, plan))
}

/// `run` at the steps its plan's step search chose, if it has one.
///
/// # Errors
/// As [`CompressionRun::with_steps`].
fn adapted_run(
    run: &CompressionRun,
    plan: Option<&TargetedPlan>,
) -> Result<Option<CompressionRun>> {
    plan.and_then(|p| p.search.as_ref())
        .map(|s| run.with_steps(&s.iter().map(|c| c.dt_tau1).collect::<Vec<_>>()))
        .transpose()
}

/// The work of one trajectory at one strain of compression run `k` of `scene` at
/// ensemble `e`, for the progress: the run's whole projected work shared equally among
/// its trajectories (times two stages, pilot and main, for a budget by target
/// precision), whichever share of them this process simulates.
fn tick_work(scene: &Scene, k: usize, budget: Budget, run: &CompressionRun, e: &Ensemble) -> f64 {
    let stages = if e.precision_target().is_some() { 2 } else { 1 };
    run_projected_work(scene, k, budget) / (stages * run.points() * e.trajectories.max(1)) as f64
}

/// The pilot of a budget by target precision and the main-stage durations it chose.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TargetedPlan {
    /// The target (F_c0, τ1).
    pub(super) target: PrecisionTarget,
    /// Sampled duration of each pilot trajectory actually run (τ1).
    pub(super) pilot_tau1: f64,
    /// The pilot's standard error of ⟨F⟩/F_c0 per strain.
    pub(super) pilot_std_error: Vec<f64>,
    /// Main-stage sampled duration per strain (τ1).
    pub(super) main_tau1: Vec<f64>,
    /// Main-stage sampled steps per strain.
    pub(super) main_steps: Vec<u64>,
    /// The step search per strain, if the budget has one.
    pub(super) search: Option<Vec<StepChoice>>,
}

/// Runs the pilot of a budget by target precision at every strain — `trajectories` ×
/// `pilot_tau1` on streams of their own (seed label `<run>/pilot/<strain>`), disjoint
/// from the main stage's `<run>/<strain>` — and chooses each strain's main-stage duration
/// with [`targeted_duration`]. The pilot's samples are discarded: the main stage is then
/// an ordinary fixed-budget run given its durations, which depend on the pilot only.
fn targeted_plan(
    scene: &Scene,
    k: usize,
    run: &CompressionRun,
    e: &Ensemble,
    target: PrecisionTarget,
    budget: Budget,
    bar: &Progress,
) -> Result<TargetedPlan> {
    let tau1 = scene.tau1();
    let name = &run.spec.name;
    let tick = tick_work(scene, k, budget, run, e);
    let (search, adapted) = match target.step_search {
        None => (None, None),
        Some(search) => {
            let choices = crate::dynamics::par_indexed(run.points() as u64, |i| {
                let i = i as usize;
                let seed = |c: usize| derive_seed(scene.seed, &format!("{name}/probe/{i}/{c}"));
                run.search_step(i, search, e.trajectories, seed)
            })
            .map_err(|e| simulation_error(scene, k, e))?;
            let dts: Vec<f64> = choices.iter().map(|c| c.dt_tau1).collect();
            (Some(choices), Some(run.with_steps(&dts)?))
        }
    };
    let run = adapted.as_ref().unwrap_or(run);
    let pilot_steps: Vec<u64> = (0..run.points())
        .map(|i| run.sampled_steps_at(i, target.pilot_tau1 * tau1))
        .collect();
    let pilot = run
        .simulate_ensemble_per_point(
            |i| derive_seed(scene.seed, &format!("{name}/pilot/{i}")),
            e.trajectories,
            &pilot_steps,
            || bar.advance(tick),
        )
        .map_err(|e| simulation_error(scene, k, e))?;
    let pilot_key = format!("{}.pilot_tau1", budget.name());
    let pilot_est = force_estimates_diagnosed(&pilot, &scene.filament)
        .map_err(|e| estimation_error(scene, k, "pilot force estimates", &pilot_key, e))?;
    let pilot_tau1 = pilot_steps[0] as f64 * run.dt_at(0) / tau1;
    let pilot_std_error: Vec<f64> = pilot_est.force.iter().map(|f| f.1).collect();
    let main_steps: Vec<u64> = pilot_std_error
        .iter()
        .enumerate()
        .map(|(i, &se)| {
            let pilot_i = pilot_steps[i] as f64 * run.dt_at(i) / tau1;
            let d = targeted_duration(se, pilot_i, target.std_error, target.max_duration_tau1);
            run.sampled_steps_at(i, d * tau1)
        })
        .collect();
    let main_tau1 = main_steps
        .iter()
        .enumerate()
        .map(|(i, &n)| n as f64 * run.dt_at(i) / tau1)
        .collect();
    Ok(TargetedPlan {
        target,
        pilot_tau1,
        pilot_std_error,
        main_tau1,
        main_steps,
        search,
    })
}

/// The note of a budget by target precision: pilot, chosen durations, the strains that
/// missed the target, and why the reported errors stay honest.
fn targeted_note(
    run: &CompressionRun,
    e: &Ensemble,
    plan: &TargetedPlan,
    est: &ForceEstimates,
) -> String {
    let list = |v: &[f64], digits: usize| {
        v.iter()
            .map(|x| format!("{x:.digits$}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let se: Vec<f64> = est.force.iter().map(|f| f.1).collect();
    let missed = se.iter().filter(|&&s| s > plan.target.std_error).count();
    let largest = se.iter().copied().fold(0.0, f64::max);
    let search = match (&plan.search, plan.target.step_search) {
        (Some(choices), Some(s)) => format!(
            "a step search first chose each strain's dt: the largest dt_tau1 x 2^k <= {} whose probe ({} trajectories x {PROBE_STEPS} steps after burn-in, streams of their own, discarded) accepted at least {} of its proposals (exact at any dt: the step changes the cost, not the law). Chosen dt per strain (tau1): {}; probe acceptance at the chosen dt: {}. Then ",
            s.max_dt_tau1,
            e.trajectories,
            s.min_acceptance,
            list(&choices.iter().map(|c| c.dt_tau1).collect::<Vec<_>>(), 2),
            list(
                &choices
                    .iter()
                    .map(|c| c.tried.last().map_or(f64::NAN, |t| t.1))
                    .collect::<Vec<_>>(),
                2
            ),
        ),
        _ => String::new(),
    };
    format!(
        "run {}: budget by target precision (standard error {} F_c0 per strain): {search}a pilot of {} trajectories x {:.1} tau1 per strain on streams of its own (pilot s.e. per strain: {}) chose each strain's main-stage duration (s.e. ~ T^-1/2, safety factor {DURATION_SAFETY} on the duration, at least the pilot's, at most {} tau1): {} tau1 per trajectory, {} fresh trajectories; reported: the main stage only, largest s.e. {:.4}, {} of {} strains above the target (reported as they are, not rerun). The main stage's duration depends on the pilot only and the pilot is independent of the main-stage samples, so given its duration each point is an ordinary fixed-budget estimate: its standard error and p-values are honest (no optional-stopping bias)",
        run.spec.name,
        plan.target.std_error,
        e.trajectories,
        plan.pilot_tau1,
        list(&plan.pilot_std_error, 4),
        plan.target.max_duration_tau1,
        list(&plan.main_tau1, 1),
        e.trajectories,
        largest,
        missed,
        se.len(),
    )
}

/// The note of a compression run: scheme, ensemble, acceptance, autocorrelation and
/// largest slope.
fn compression_run_note(
    scene: &Scene,
    theory: &CompressionTheoryTable,
    run: &CompressionRun,
    e: &Ensemble,
    est: &ForceEstimates,
    slope: Option<RmsSlope>,
) -> String {
    let tau1 = scene.tau1();
    let dts: Vec<f64> = (0..run.points()).map(|i| run.dt_at(i) / tau1).collect();
    let dt = if dts.iter().all(|&d| d == run.spec.dt_tau1) {
        format!("{:.3e} tau1", run.spec.dt_tau1)
    } else {
        let list: Vec<String> = dts.iter().map(|d| format!("{d:.3e}")).collect();
        format!("{} tau1 per strain", list.join(", "))
    };
    format!(
        "run {}: {} with {} noise, dt = {dt}, {} trajectories x {} per strain after {} tau1 burn-in; acceptance {:.4}; largest integrated autocorrelation time of F {:.1} samples{}",
        run.spec.name,
        run.spec.integrator,
        run.spec.noise.name(),
        e.trajectories,
        if e.precision_target().is_some() {
            "a duration chosen per strain (budget by target precision)".to_string()
        } else {
            format!("{} tau1", e.duration_tau1)
        },
        scene.compression.as_ref().map_or(0.0, |c| c.burn_in_tau1),
        est.acceptance,
        est.max_tau_int,
        slope.map_or(String::new(), |(s, x, i)| format!(
            "; largest RMS slope {s:.3} rad at x/L = {x:.2}, strain ratio {}",
            theory.strain_ratios[i]
        ))
    )
}

/// The rows of `force-strain.csv` ([`FORCE_STRAIN_HEADER`]), one per strain.
fn force_strain_rows(theory: &CompressionTheoryTable, est: &ForceEstimates) -> Vec<Vec<f64>> {
    (0..theory.strain_ratios.len())
        .map(|i| {
            vec![
                theory.strain_ratios[i],
                est.force[i].0,
                est.force[i].1,
                theory.discrete[i],
                theory.continuum[i],
            ]
        })
        .collect()
}

/// The points of run `k` (rows of `force-strain.csv`) in a force–strain figure: markers
/// with ±1 s.e. bars. The tension figure ([`tension_force_strain_figure`]) has two more
/// reference curves before the points, so there they keep palette colours 2, 3, … by
/// `k`; a compression figure's take theirs from their index (the same colours).
fn force_points(
    label: String,
    rows: &[Vec<f64>],
    k: usize,
    theory: &CompressionTheoryTable,
) -> Series {
    let markers = Series::markers(label, rows.iter().map(|r| (r[0], r[1])).collect())
        .with_errors(rows.iter().map(|r| r[2]).collect());
    if theory.reaches_tension() {
        markers.palette(2 + k)
    } else {
        markers
    }
}

/// Label of the imposed-strain axis of the force–strain figures.
const STRAIN_LABEL: &str = "imposed strain ε / ε_c0 (Euler strain)";
/// Label of the force axis of the force–strain figures.
const FORCE_LABEL: &str = "⟨F⟩ / F_c0 (Euler load)";

/// The scene's force–strain figure with the exact theory; runs add their points (in
/// palette colours 2, 3, …). A scene reaching into tension gets
/// [`tension_force_strain_figure`] instead.
fn force_strain_figure(scene: &Scene, theory: &CompressionTheoryTable) -> Figure {
    if theory.reaches_tension() {
        return tension_force_strain_figure(scene, theory);
    }
    Figure::new(
        format!("{}: mean force against imposed strain", scene.name),
        STRAIN_LABEL,
        FORCE_LABEL,
    )
    .series(Series::line(
        "exact, discretized filament",
        theory.curve.iter().map(|c| (c.0, c.1)).collect(),
    ))
    .series(
        Series::line(
            "exact, continuum",
            theory.curve.iter().map(|c| (c.0, c.2)).collect(),
        )
        .dashed(),
    )
    .hline(1.0, "Euler load F_c0")
    .caption(
        "Mean compressive force ⟨F⟩/F_c0 against the imposed end-to-end strain ε/ε_c0, \
         simulated per run (markers, ±1 s.e.) against the exact equilibrium force of the \
         discretized filament (solid line) and of the continuum (dashed line); the dashed \
         black line is the Euler load. The markers should lie on the solid line within \
         their error bars; a systematic offset is a sampling, integrator or force-estimator \
         error.",
    )
}

/// What the force–strain figure of a scene reaching into tension says: the filament's
/// force or the membrane's stress.
struct TensionWording {
    title: &'static str,
    x: &'static str,
    y: &'static str,
    discrete: &'static str,
    athermal: &'static str,
    load: &'static str,
    caption: &'static str,
}

/// The filament's [`TensionWording`].
const FILAMENT_TENSION: TensionWording = TensionWording {
    title: "mean force from tension through buckling",
    x: STRAIN_LABEL,
    y: "⟨F⟩ / F_c0 (Euler load; negative: tension)",
    discrete: "exact, discretized filament",
    athermal: "athermal rod: EA ε up to F_c0",
    load: "Euler load F_c0",
    caption: "Mean force ⟨F⟩/F_c0 from tension (negative) through buckling against the imposed \
         strain ε/ε_c0, simulated per run (markers, ±1 s.e.) against the exact equilibrium \
         force of the discretized filament (solid line) and of the continuum (dashed line); \
         the Gaussian mean field (purple, dashed) and the athermal rod (grey: F = EA ε up to \
         the Euler load, then F_c0) for comparison; the dashed black line is the Euler load. \
         The markers should lie on the solid line within their error bars. The vertical \
         distance below the grey line is the thermal stored length EA⟨s⟩: pulled out in \
         tension, where the mean field is accurate; past the Euler strain the 2D force \
         rises above F_c0, which the mean field never does.",
};

/// The membrane's [`TensionWording`] (imposed projected area, issue #28).
const MEMBRANE_TENSION: TensionWording = TensionWording {
    title: "mean tension against imposed projected area",
    x: "imposed area strain ε / ε_c0 (ε = 1 − A_p/A₀, ε_c0 = σ_c0/K_A)",
    y: "−⟨σ⟩ / σ_c0 (compressive stress; negative: tension)",
    discrete: "exact, discretized membrane (BFS mesh)",
    athermal: "athermal membrane: K_A ε up to σ_c0",
    load: "buckling stress σ_c0 = κ q²_min",
    caption: "Mean compressive stress −⟨σ⟩/σ_c0 (negative: the membrane is under tension) \
         against the imposed area strain ε/ε_c0, ε = 1 − A_p/A₀, simulated per run (markers, \
         ±1 s.e.) against the exact equilibrium of the discretized membrane (solid line) and \
         of the continuum at the mesh's mode cutoff (dashed line); the Gaussian mean field \
         (purple, dashed) and the athermal membrane (grey: K_A ε up to the buckling stress \
         σ_c0 = κq²_min, then σ_c0) for comparison; the dashed black line is σ_c0. The \
         markers should lie on the solid line within their error bars. The vertical distance \
         below the grey line is K_A times the thermal excess area ⟨ΔA⟩/A₀: it keeps a soft \
         membrane under tension well past ε_c0, and it grows with the mode cutoff \
         (Helfrich–Servuss), so the continuum curve depends on the mesh — physics, not \
         discretization error. The discretization error proper, the mesh's modes within a \
         fixed mode cutoff against the continuum's, falls at the fourth order in the element \
         size (`langevin-fem theory area --mesh-convergence`).",
};

/// The force–strain figure of a scene whose strains reach into tension (negative ⟨F⟩ is
/// a tension): the exact curves as in [`force_strain_figure`], and the two limits they
/// interpolate between: the Gaussian mean field of the discretized object (accurate in
/// tension, never above the buckling load) and the athermal object, `F = S·ε` up to the
/// buckling load and the load beyond (the distance below it is the thermal stored length
/// or area, `S·⟨s⟩`). Runs add their points (palette colours 2, 3, …; the mean field is
/// drawn in purple, palette colour 4's, which a scene with at most two runs leaves free).
fn tension_force_strain_figure(scene: &Scene, theory: &CompressionTheoryTable) -> Figure {
    let w = if scene.is_membrane() {
        &MEMBRANE_TENSION
    } else {
        &FILAMENT_TENSION
    };
    let (lo, hi) = (
        theory.curve.first().map_or(0.0, |c| c.0),
        theory.curve.last().map_or(0.0, |c| c.0),
    );
    let mut athermal = vec![(lo, lo.min(1.0))];
    if lo < 1.0 && hi > 1.0 {
        athermal.push((1.0, 1.0));
    }
    athermal.push((hi, hi.min(1.0)));
    Figure::new(format!("{}: {}", scene.name, w.title), w.x, w.y)
        .series(Series::line(
            w.discrete,
            theory.curve.iter().map(|c| (c.0, c.1)).collect(),
        ))
        .series(
            Series::line(
                "exact, continuum",
                theory.curve.iter().map(|c| (c.0, c.2)).collect(),
            )
            .dashed(),
        )
        .series(
            Series::line(
                "Gaussian mean field, discretized (not exact)",
                theory
                    .curve
                    .iter()
                    .zip(&theory.mean_field)
                    .map(|(c, m)| (c.0, m.0))
                    .collect(),
            )
            .dashed()
            .rgb(148, 103, 189),
        )
        .series(Series::line(w.athermal, athermal).rgb(140, 140, 140))
        .hline(1.0, w.load)
        .caption(w.caption)
}

/// The Δt-halving check of a compression scene and its note, if the scene asks for it.
fn scene_halving_check(
    scene: &Scene,
    runs: &[CompressionRun],
    estimates: &[ForceEstimates],
) -> Result<Option<(CheckResult, String)>> {
    if let Some(comp) = &scene.compression
        && let Some([a, b]) = &comp.halving
        && scene.checks.contains(&CheckKind::DtHalving)
    {
        let ia = runs.iter().position(|r| &r.spec.name == a);
        let ib = runs.iter().position(|r| &r.spec.name == b);
        if let (Some(ia), Some(ib)) = (ia, ib) {
            return halving_check([a, b], &estimates[ia], &estimates[ib]).map(Some);
        }
    }
    Ok(None)
}

/// What `check` does with the Δt-halving check of a compression scene.
enum DataHalving {
    /// The scene does not ask for it.
    NotAsked,
    /// The data hold both runs of the pair: the check and its note.
    Checked(Box<CheckResult>, String),
    /// The data lack a run of the pair: listed as skipped, with the reason.
    Skipped(SkippedCheck),
}

/// The Δt-halving check of `check` (data of run names `runs`, force estimates
/// `estimates` in the same order): made when the data hold both runs of the scene's
/// pair, otherwise listed as skipped with the reason (never silently dropped, issue #31).
///
/// # Errors
/// [`halving_check`]'s.
fn data_halving_check(
    scene: &Scene,
    runs: &[&str],
    estimates: &[ForceEstimates],
) -> Result<DataHalving> {
    let Some(comp) = &scene.compression else {
        return Ok(DataHalving::NotAsked);
    };
    let Some([a, b]) = &comp.halving else {
        return Ok(DataHalving::NotAsked);
    };
    if !scene.checks.contains(&CheckKind::DtHalving) {
        return Ok(DataHalving::NotAsked);
    }
    let ia = runs.iter().position(|r| r == a);
    let ib = runs.iter().position(|r| r == b);
    if let (Some(ia), Some(ib)) = (ia, ib) {
        let (check, note) = halving_check([a, b], &estimates[ia], &estimates[ib])?;
        return Ok(DataHalving::Checked(Box::new(check), note));
    }
    let missing: Vec<&str> = [(ia, a), (ib, b)]
        .iter()
        .filter(|(i, _)| i.is_none())
        .map(|(_, n)| n.as_str())
        .collect();
    let held = if runs.is_empty() {
        "no run".to_string()
    } else {
        format!("run(s) {}", runs.join(", "))
    };
    Ok(DataHalving::Skipped(SkippedCheck {
        name: format!("dt-halving/{a}-vs-{b}"),
        reason: format!(
            "the data hold {held} but not {}: the dt-halving check of scene {} compares run \
             {a} (at dt) with run {b} (at dt/2); give the data of both runs (e.g. `langevin-fem \
             run --scene {}` writes every run) to have it checked",
            missing.join(" nor "),
            scene.name,
            scene.name
        ),
    }))
}

/// The paper's Fig. 2: ⟨F⟩/F_c0 against ε/ε_c0 in 2D and 3D, one colour per dimension:
/// simulated points with error bars, exact theory (discretized filament: solid light
/// line, continuum: dashed).
fn fig2_figure(curves: &[Curve]) -> Figure {
    let mut fig = Figure::new(
        "Fig. 2: hinged filament under imposed compression",
        STRAIN_LABEL,
        FORCE_LABEL,
    )
    .hline(1.0, "Euler load F_c0")
    .caption(
        "The paper's Fig. 2: mean compressive force ⟨F⟩/F_c0 against imposed strain \
         ε/ε_c0, one colour per dimension: simulated (markers, ±1 s.e.; the first run of \
         each compression scene), exact for the discretized filament (light solid line) \
         and for the continuum (dashed line). The markers should lie on the solid line of \
         their colour within their error bars.",
    );
    for (k, c) in curves.iter().enumerate() {
        let d = c.dims;
        fig = fig
            .series(
                Series::markers(
                    format!("{d}D: simulated (±1 s.e.) / exact, discretized"),
                    c.simulated.iter().map(|t| (t.0, t.1)).collect(),
                )
                .with_errors(c.simulated.iter().map(|t| t.2).collect())
                .palette(k)
                .joined_with_next(),
            )
            .series(
                Series::line("", c.theory.iter().map(|t| (t.0, t.1)).collect())
                    .palette(k)
                    .light(),
            )
            .series(
                Series::line(
                    format!("{d}D: exact, continuum"),
                    c.theory.iter().map(|t| (t.0, t.2)).collect(),
                )
                .dashed()
                .palette(k),
            );
    }
    fig
}

/// The summary of a scene: the Holm correction over its checks at `opts.alpha`, and the
/// paths of its outputs relative to `opts.out`.
fn finish_scene(
    scene: &Scene,
    outputs: SceneOutputs<'_>,
    start: Instant,
    alpha: f64,
    out: &Path,
) -> Result<SceneSummary> {
    let SceneOutputs {
        report: _,
        mut checks,
        figures,
        tables,
        notes,
        skipped,
        runs,
        continuum_references: _,
        membrane,
    } = outputs;
    let runs: Vec<&str> = runs.iter().map(String::as_str).collect();
    for c in &mut checks {
        c.locate(&runs);
    }
    // Holm over the statistical checks; a deterministic check (no p-value, e.g. the
    // oracle's) keeps its own verdict and is not part of the family.
    let p: Vec<f64> = checks.iter().filter_map(|c| c.p_value).collect();
    let statistical = checks.iter_mut().filter(|c| c.p_value.is_some());
    for (c, (adj, reject)) in statistical.zip(stats::holm(&p, alpha)) {
        c.p_adjusted = Some(adj);
        c.passed = !reject;
    }
    let rel = |v: Vec<PathBuf>| -> Vec<String> {
        v.iter()
            .map(|p| {
                p.strip_prefix(out)
                    .unwrap_or(p)
                    .to_string_lossy()
                    .into_owned()
            })
            .collect()
    };
    let (figures, captions): (Vec<PathBuf>, Vec<String>) = figures.into_iter().unzip();
    let mut summary = SceneSummary {
        name: scene.name.clone(),
        passed: checks.iter().all(|c| c.passed),
        wall_seconds: start.elapsed().as_secs_f64(),
        captions,
        figures: rel(figures),
        tables: rel(tables),
        notes,
        warnings: Vec::new(),
        skipped,
        checks,
        detectable: Vec::new(),
        hints: Vec::new(),
    };
    // Per run and observable, the smallest error the checks would have caught (issue #31).
    summary.detectable = crate::verify::diagnosis::detectable_deviations(&summary, alpha);
    for (run, text) in crate::verify::diagnosis::detectable_lines(&summary.detectable) {
        summary.notes.push(format!(
            "run {run}: {text}: the smallest relative error of each observable that the \
             run's most precise check of it detects with 80 % probability at the scene's \
             alpha (Holm's strictest step), from the measured standard errors"
        ));
    }
    // Per run with a failed check, the pattern of its per-mode ratios, if any (issue #31).
    let membrane = membrane.and_then(|p| crate::spectral::membrane::Membrane::new(p).ok());
    let of = |mode: &str| {
        let m = membrane.as_ref()?;
        crate::verify::diagnosis::membrane_sensitivities(m, mode)
    };
    let tension = membrane.map(|m| (m.params.tension, &of as SensitivityOf));
    summary.hints = crate::verify::diagnosis::run_hints(&summary, tension);
    for h in &summary.hints {
        summary.notes.push(format!(
            "run {}: {} (a pattern among the run's per-mode ratios estimate/reference, \
             not a verdict: the checks are)",
            h.run, h.text
        ));
    }
    Ok(summary)
}

/// Runs a linear scene: every run, its checks, notes, tables and figures, and the
/// element-uniform noise study of a `fem` scene (see the [module docs](self)).
fn run_scene(
    scene: &Scene,
    runs: &[LinearRun],
    oracles: &[Oracle],
    opts: &VerifyOptions,
    report: &ReportRun,
    bar: &Progress,
) -> Result<SceneSummary> {
    let start = Instant::now();
    let dir = opts.out.join(&scene.name);
    let mut outputs = SceneOutputs::new(scene, report);
    let mut largest_slope: Option<(String, (f64, f64))> = None;
    // The element-count study of the paper's noise: once per fem scene, after the first
    // element-uniform run.
    // The element-uniform noise study is the filament's (the membrane's per-mode ratios
    // are in `theory membrane`).
    let noise_study_after = match scene.model {
        ModelKind::Fem if !scene.is_membrane() => runs
            .iter()
            .position(|r| r.spec.noise == NoiseModel::ElementUniform),
        ModelKind::Fem | ModelKind::Spectral | ModelKind::Compression => None,
    };
    for (k, (run, oracle)) in runs.iter().zip(oracles).enumerate() {
        begin_run(bar, scene, k, opts.budget, 1.0);
        outputs.checks.extend(oracle.checks.iter().cloned());
        outputs.notes.extend(oracle.notes.iter().cloned());
        if !oracle.passed() {
            outputs
                .notes
                .push(oracle.not_simulated_note(&run.spec.name));
            continue;
        }
        let e = run.spec.ensemble(opts.budget);
        let (records, two_time) = linear_sample(opts, scene, k, run, &e, bar)?;
        let budget_key = format!("{}.duration_tau1", opts.budget.name());
        let est = apply_linear_checks(scene, run, &records, &two_time, &mut outputs)
            .map_err(|e| estimation_error(scene, k, "checks", &budget_key, e))?;
        if let Some(slope) = run.measured_rms_slope(&records)
            && largest_slope.as_ref().is_none_or(|(_, s)| slope.0 > s.0)
        {
            largest_slope = Some((run.spec.name.clone(), slope));
        }
        outputs.skipped.extend(est.skipped.iter().cloned());
        outputs.notes.push(linear_run_note(scene, run, &e));
        write_run_outputs(scene, &dir, run, &est, &mut outputs)?;
        if noise_study_after == Some(k) {
            let note = write_noise_study(scene, &dir, &mut outputs)?;
            outputs.notes.push(note);
        }
    }
    let mut summary = finish_scene(scene, outputs, start, opts.alpha, &opts.out)?;
    if let Some((run, slope)) = largest_slope {
        let what = format!("run {run} (largest of the runs)");
        add_slope_status(scene, &mut summary, &what, slope);
    }
    Ok(summary)
}

/// The checks of linear run `run` on its records, added to `outputs`; returns the
/// estimates for its tables and figures.
///
/// # Errors
/// An estimator's failure ([`linear_checks`]).
fn apply_linear_checks(
    scene: &Scene,
    run: &LinearRun,
    records: &[TrajectoryRecord],
    two_time: &[Vec<f64>],
    outputs: &mut SceneOutputs<'_>,
) -> Result<LinearEstimates> {
    let (run_checks, est) = linear_checks(run, run.spec.checks(scene), records, two_time)?;
    outputs.checks.extend(run_checks);
    Ok(est)
}

/// Applies `scene`'s checks to the trajectory data in `data_dir`, described by its
/// `sidecar` (`data.json`, read once by the caller: [`crate::data::DataSidecar::load`];
/// any program's data, in the format of [`crate::data`]; see [`crate::verify::data`]),
/// and writes the report to `out` as `verify` does (summary, index, per-run tables and
/// figures, journal); returns the summary (budget `data`) and the report run, to be
/// finished by [`crate::report::write_report`]. The trajectory files listed may hold at
/// most `max_bytes` together (the memory cap, `--max-memory-gib`): above it nothing is
/// read.
///
/// # Errors
/// Input (exit 2): a bad sidecar or trajectory file, data of the other kind or object
/// than the scene's or that cannot serve it, files larger than `max_bytes` together; run failures
/// (exit 3): an estimator that finds no answer in the data.
pub fn check_data(
    scene: &Scene,
    sidecar: &crate::data::DataSidecar,
    data_dir: &Path,
    out: &Path,
    alpha: f64,
    max_bytes: u64,
    progress: ProgressOptions,
) -> Result<(Summary, ReportRun)> {
    crate::verify::data::check_data_kind(scene, sidecar, data_dir)?;
    crate::verify::data::require_data_size(sidecar, data_dir, max_bytes)?;
    if scene.compression.is_some() {
        return check_compression_data(scene, sidecar, data_dir, out, alpha, max_bytes);
    }
    let prepared = prepare_data_checks(scene, sidecar, data_dir, max_bytes, progress)?;
    let report = begin_check(scene, out)?;
    let start = Instant::now();
    let dir = out.join(&scene.name);
    let mut outputs = SceneOutputs::new(scene, &report);
    outputs.membrane = sidecar.membrane.map(|m| m.params());
    lead_with_data(&mut outputs, scene, data_note(sidecar, data_dir));
    for (data, dc) in sidecar.runs.iter().zip(&prepared) {
        outputs.runs.push(data.name.clone());
        let first_check = outputs.checks.len();
        let est = apply_linear_checks(scene, &dc.run, &dc.records, &dc.two_time, &mut outputs)
            .map_err(|e| {
                Error::run_failed(format!("data run {}", data.name), "checks", e).with_advice(
                    "the data did not support the estimate; longer or more trajectories may help",
                )
            })?;
        if dc.continuum_references {
            // No reference of this run is the producer's discretization's.
            for c in &mut outputs.checks[first_check..] {
                c.reference_kind = "continuum".to_string();
            }
        }
        outputs.skipped.extend(est.skipped.iter().cloned());
        outputs.notes.extend(dc.notes.iter().cloned());
        outputs.notes.push(format!(
            "run {}: {} trajectories {}, rows every {:e} (time units of the data), burn-in {:e}",
            data.name,
            dc.records.len(),
            if data.start == crate::data::Start::Rest {
                "from rest"
            } else {
                "stationary"
            },
            data.dt_sample,
            data.burn_in
        ));
        outputs.continuum_references = dc.continuum_references;
        write_run_outputs(scene, &dir, &dc.run, &est, &mut outputs)?;
        outputs.continuum_references = false;
    }
    let summary = finish_check(scene, outputs, start, alpha, out, &report)?;
    Ok((summary, report))
}

/// Starts the report of a `check` run in `out`, with the provenance of `scene`.
fn begin_check(scene: &Scene, out: &Path) -> Result<ReportRun> {
    let report = ReportRun::begin(out, "check", MANIFEST, &ENTRY_POINTS)?;
    report.set_provenance(Provenance::begin(&[scene]))?;
    Ok(report)
}

/// The note naming the data a `check` run read: the directory, the producer and each
/// run's declared discretization (model, elements, integrator, noise, step) and row
/// interval.
fn data_note(sidecar: &crate::data::DataSidecar, data_dir: &Path) -> String {
    let runs: Vec<String> = sidecar
        .runs
        .iter()
        .map(|r| {
            let disc = r.discretization.as_ref().map_or_else(
                || "discretization not declared".to_string(),
                |d| {
                    let mut parts = vec![d.model.clone()];
                    parts.extend(d.elements.map(|n| format!("{n} elements")));
                    parts.extend(d.integrator.clone());
                    parts.extend(d.noise.as_ref().map(|n| format!("{n} noise")));
                    parts.extend(d.dt.map(|dt| format!("dt {dt:e}")));
                    parts.join(", ")
                },
            );
            format!("{} ({disc}; rows every {:e})", r.name, r.dt_sample)
        })
        .collect();
    format!(
        "checked data: {} (producer: {}), {} run(s): {}",
        data_dir.display(),
        if sidecar.producer.is_empty() {
            "not given"
        } else {
            &sidecar.producer
        },
        sidecar.runs.len(),
        runs.join("; ")
    )
}

/// Puts the data's own description first among a `check` run's notes (the report's
/// scene table shows the first note), the scene's description after it, saying that it
/// describes the references and checks applied.
fn lead_with_data(outputs: &mut SceneOutputs<'_>, scene: &Scene, note: String) {
    if let Some(first) = outputs.notes.first_mut() {
        *first = format!(
            "references and checks of scene {}: {}",
            scene.name, scene.description
        );
    }
    outputs.notes.insert(0, note);
}

/// The summary of a `check` run (budget `data`): the family-wise correction over the
/// scene's checks.
fn finish_check(
    scene: &Scene,
    outputs: SceneOutputs<'_>,
    start: Instant,
    alpha: f64,
    out: &Path,
    report: &ReportRun,
) -> Result<Summary> {
    let scene_summary = finish_scene(scene, outputs, start, alpha, out)?;
    Ok(Summary {
        run_id: report.run_id(),
        budget: "data".to_string(),
        alpha,
        passed: scene_summary.passed,
        scenes: vec![scene_summary],
        files: report.files(),
        provenance: report.provenance_ref(),
    })
}

/// Least projected set-up, in DOF-steps (about 2 s), that `check` shows progress for.
const CHECK_PROGRESS_MIN_WORK: f64 = 1e8;

/// The linear data runs of `sidecar` read and their references prepared, in order
/// ([`crate::verify::data::prepare_data_check`]), with progress on stderr weighted by
/// each run's projected set-up when the whole takes seconds (a large mesh's exact
/// references cost O(n³): 1000 elements, about 20 s a run).
fn prepare_data_checks(
    scene: &Scene,
    sidecar: &crate::data::DataSidecar,
    data_dir: &Path,
    max_bytes: u64,
    progress: ProgressOptions,
) -> Result<Vec<crate::verify::data::DataCheck>> {
    // A beam's discretization decomposed for an earlier run costs a tenth: its modes are
    // kept (the last `MEMO_ENTRIES`; see `FemObject::modes`), only its discrete law is new.
    let mut recent: Vec<(String, Option<usize>, Option<usize>)> = Vec::new();
    let weights: Vec<f64> = sidecar
        .runs
        .iter()
        .map(|r| {
            let cost = crate::verify::data::data_setup_cost(scene, r);
            let Some(d) = &r.discretization else {
                return cost;
            };
            let key = (d.model.clone(), d.elements, d.elements_y);
            if !scene.is_membrane() && recent.contains(&key) {
                return 0.1 * cost;
            }
            recent.push(key);
            if recent.len() > crate::scene::linear::MEMO_ENTRIES {
                recent.remove(0);
            }
            cost
        })
        .collect();
    let total: f64 = weights.iter().sum();
    let bar = if total >= CHECK_PROGRESS_MIN_WORK {
        Progress::new(progress, total, "DOF-steps")
    } else {
        Progress::hidden()
    };
    let prepared = weights
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            let label = format!("{}/{} (references)", scene.name, sidecar.runs[k].name);
            bar.begin_run(&scene.name, &label, w);
            let check =
                crate::verify::data::prepare_data_check(scene, sidecar, data_dir, k, max_bytes);
            bar.advance(w);
            check
        })
        .collect();
    bar.finish();
    prepared
}

/// [`check_data`] of a compression scene: per run name of the data, ⟨F⟩ at every strain
/// of the scene (and the distribution of F, against the producer's discretization)
/// with the force checks of `verify`, `<run>-force-strain.csv` and the scene's
/// force–strain figure.
fn check_compression_data(
    scene: &Scene,
    sidecar: &crate::data::DataSidecar,
    data_dir: &Path,
    out: &Path,
    alpha: f64,
    max_bytes: u64,
) -> Result<(Summary, ReportRun)> {
    let checks =
        crate::verify::data::prepare_compression_checks(scene, sidecar, data_dir, max_bytes)?;
    let report = begin_check(scene, out)?;
    let start = Instant::now();
    let dir = out.join(&scene.name);
    let mut outputs = SceneOutputs::new(scene, &report);
    lead_with_data(&mut outputs, scene, data_note(sidecar, data_dir));
    let mut fig: Option<Figure> = None;
    let mut estimates = Vec::new();
    for (k, c) in checks.iter().enumerate() {
        let name = &c.run.spec.name;
        outputs.runs.push(name.clone());
        let failed = |e: Error| {
            Error::run_failed(format!("data run {name}"), "force checks", e).with_advice(
                "the data did not support the estimate; longer or more trajectories may help",
            )
        };
        let est = force_estimates_diagnosed(&c.records, &scene.filament).map_err(failed)?;
        outputs.checks.extend(
            compression_checks(
                &c.run,
                c.run.spec.checks(scene),
                &c.theory,
                &c.records,
                &est,
            )
            .map_err(failed)?,
        );
        outputs.notes.extend(c.notes.iter().cloned());
        let rows = force_strain_rows(&c.theory, &est);
        outputs.write_table(
            dir.join(format!("{name}-force-strain.csv")),
            &FORCE_STRAIN_HEADER,
            &rows,
        )?;
        let f = fig
            .take()
            .unwrap_or_else(|| force_strain_figure(scene, &c.theory));
        fig = Some(f.series(force_points(
            format!("data: {name} (±1 s.e.)"),
            &rows,
            k,
            &c.theory,
        )));
        estimates.push(est);
    }
    let runs: Vec<&str> = checks.iter().map(|c| c.run.spec.name.as_str()).collect();
    match data_halving_check(scene, &runs, &estimates)
        .map_err(|e| Error::run_failed(scene.path.display().to_string(), "dt-halving check", e))?
    {
        DataHalving::Checked(check, note) => {
            outputs.checks.push(*check);
            outputs.notes.push(note);
        }
        DataHalving::Skipped(skipped) => outputs.skipped.push(skipped),
        DataHalving::NotAsked => {}
    }
    if let Some(f) = fig {
        outputs.write_figure(&f, dir.join("force-strain.svg"))?;
    }
    let summary = finish_check(scene, outputs, start, alpha, out, &report)?;
    Ok((summary, report))
}

/// Simulates run `k` of a linear scene with ensemble `e`: the full trajectories, and the
/// two-time products of all trajectories (the full ones, then the extra short ones).
pub(super) fn simulate_linear(
    scene: &Scene,
    k: usize,
    run: &LinearRun,
    e: &Ensemble,
    bar: &Progress,
    shard: Shard,
) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let seed = derive_seed(scene.seed, &run.spec.name);
    let steps = run.sampled_steps(e.duration_tau1 * scene.tau1());
    let full = e.trajectories as u64;
    // The work of one full trajectory and of one extra two-time trajectory (much
    // shorter), from the run's projection.
    let only_full = Ensemble {
        two_time_trajectories: 0,
        ..*e
    };
    let full_work = scene.run_work(k, &only_full, None).dof_steps;
    let extra_work = scene.run_work(k, e, None).dof_steps - full_work;
    let per_full = full_work / e.trajectories.max(1) as f64;
    let per_extra = extra_work / e.two_time_trajectories.max(1) as f64;
    let own = shard.range(full);
    let records = run
        .simulate_ensemble(seed, own.start, own.end - own.start, steps, |n| {
            bar.advance(n as f64 * per_full)
        })
        .map_err(|e| simulation_error(scene, k, e))?;
    let own = shard.range(e.two_time_trajectories as u64);
    let extra: Vec<Vec<f64>> = run
        .simulate_ensemble(seed, full + own.start, own.end - own.start, 0, |n| {
            bar.advance(n as f64 * per_extra)
        })
        .map_err(|e| simulation_error(scene, k, e))?
        .into_iter()
        .map(|r| r.two_time)
        .collect();
    Ok((records, extra))
}

/// The trajectories of linear run `k` at ensemble `e`, simulated or read from shards
/// (`opts.ensembles`): the records and the two-time products of every trajectory, the
/// full trajectories' first and then the extra two-time trajectories'.
///
/// # Errors
/// As [`simulate_linear`] and [`super::shard::merged_linear`].
fn linear_sample(
    opts: &VerifyOptions,
    scene: &Scene,
    k: usize,
    run: &LinearRun,
    e: &Ensemble,
    bar: &Progress,
) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let (records, extra) = match &opts.ensembles {
        Ensembles::Simulate => simulate_linear(scene, k, run, e, bar, Shard::WHOLE)?,
        Ensembles::Merge(set) => super::shard::merged_linear(set, scene, run, e)?,
    };
    let two_time = records
        .iter()
        .map(|r| r.two_time.clone())
        .chain(extra)
        .collect();
    Ok((records, two_time))
}

/// The note of a linear run: scheme, time step, ensemble and sampling.
fn linear_run_note(scene: &Scene, run: &LinearRun, e: &Ensemble) -> String {
    format!(
        "run {}: {} with {} noise, dt = {:.4e} tau1 (lambda_max dt = {:.3e}), {} trajectories x {} tau1 after {} tau1 burn-in, mode 1 sampled every {} steps",
        run.spec.name,
        run.spec.integrator,
        run.spec.noise.name(),
        run.spec.dt_tau1,
        run.reference.max_rate * run.reference.dt,
        e.trajectories,
        e.duration_tau1,
        scene.sampling.burn_in_tau1,
        run.mode_every[0]
    )
}

/// The tables and figures of one linear run (see the [module docs](self)), in this order,
/// worded and drawn for the scene's object ([`Subject`], built here: it is cheap).
fn write_run_outputs(
    scene: &Scene,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let units = AxisUnits::new(scene.physical.is_some());
    let subject = Subject::of(scene)?;
    if est.modes.iter().any(|m| m.variance.1 > 0.0) {
        write_mode_variances(&subject, dir, run, est, outputs)?;
        if subject.is_membrane() {
            write_height_spectrum(&subject, units, dir, run, est, outputs)?;
        }
    }
    write_mode_statistics(&subject, dir, run, est, outputs)?;
    if !est.profile.is_empty() {
        write_profile(&subject, units, dir, run, est, outputs)?;
    }
    if !est.two_time.is_empty() {
        write_two_time(scene, &subject, units, dir, run, est, outputs)?;
    }
    write_spectra(&subject, units, dir, run, est, outputs)
}

/// `<run>-modes.csv` and `.svg`: the modal variances relative to equipartition,
/// simulated against the exact discrete and the continuum values.
fn write_mode_variances(
    subject: &Subject,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let name = &run.spec.name;
    let refs = &run.reference.modes;
    let modes: Vec<_> = refs.iter().zip(&est.modes).collect();
    let path = dir.join(format!("{name}-modes.csv"));
    // (mode, predicted ratio, simulated ratio, its standard error, continuum ratio).
    let ratios: Vec<[f64; 5]> = modes
        .iter()
        .map(|(mr, me)| {
            let eq = mr.variance_equipartition;
            [
                mr.n as f64,
                mr.variance_discrete / eq,
                me.variance.0 / eq,
                me.variance.1 / eq,
                mr.variance_continuum / eq,
            ]
        })
        .collect();
    let rows: Vec<Vec<f64>> = modes
        .iter()
        .zip(&ratios)
        .map(|((mr, _), r)| {
            let mut row = subject.mode_columns(mr);
            row.extend(&r[1..4]);
            row
        })
        .collect();
    outputs.write_table(
        path,
        &subject.mode_header(&["predicted_ratio", "simulated_ratio", "std_error"]),
        &rows,
    )?;
    let words = outputs.words(subject.variance_words(name, refs));
    let fig = Figure::new(words.title, words.x_label, words.y_label)
        .series(
            Series::line(
                words.discrete,
                ratios.iter().map(|r| (r[0], r[1])).collect(),
            )
            .palette(1),
        )
        .series(
            Series::line(
                words.continuum,
                ratios.iter().map(|r| (r[0], r[4])).collect(),
            )
            .dashed()
            .palette(2),
        )
        .series(
            Series::markers(
                "simulated (±1 s.e.)",
                ratios.iter().map(|r| (r[0], r[2])).collect(),
            )
            .with_errors(ratios.iter().map(|r| r[3]).collect())
            .palette(0),
        )
        .hline(1.0, "equipartition kT/λᵢ")
        .caption(words.caption);
    outputs.write_figure(&fig, dir.join(format!("{name}-modes.svg")))?;
    Ok(())
}

/// `<run>-height-spectrum.svg` of a membrane: the stationary variance of each checked
/// mode against its wavenumber |q| on log–log axes, simulated (±1 s.e.), exact discrete
/// and the continuum law (M3), all in the normalization of (M3) (finite-element
/// amplitudes scaled by [`Subject::Membrane::to_sine`]).
fn write_height_spectrum(
    subject: &Subject,
    units: AxisUnits,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let Subject::Membrane { to_sine, .. } = *subject else {
        return Ok(());
    };
    let name = &run.spec.name;
    let refs = &run.reference.modes;
    // (|q|, simulated, its standard error, exact discrete), in (M3)'s normalization.
    let points: Vec<[f64; 4]> = refs
        .iter()
        .zip(&est.modes)
        .map(|(mr, me)| {
            [
                subject.wavenumber(mr),
                to_sine * me.variance.0,
                to_sine * me.variance.1,
                to_sine * mr.variance_discrete,
            ]
        })
        .collect();
    let qs: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let words = outputs.words(subject.spectrum_words(name, units, refs));
    let fig = Figure::new(words.title, words.x_label, words.y_label)
        .log_x()
        .log_y()
        .series(
            Series::line(words.continuum, subject.spectrum_curve(&qs))
                .dashed()
                .palette(2),
        )
        .series(
            Series::markers(
                words.discrete,
                points.iter().map(|p| (p[0], p[3])).collect(),
            )
            .palette(1)
            .light()
            .marker_radius(8),
        )
        .series(
            Series::markers(
                "simulated (±1 s.e.)",
                points.iter().map(|p| (p[0], p[1])).collect(),
            )
            .with_errors(points.iter().map(|p| p[2]).collect())
            .palette(0),
        )
        .caption(words.caption);
    outputs.write_figure(&fig, dir.join(format!("{name}-height-spectrum.svg")))
}

/// `<run>-mode-statistics.csv` (variance and rate per mode, simulated, exact discrete and
/// continuum) and, when rates were estimated, `<run>-rates.svg`.
fn write_mode_statistics(
    subject: &Subject,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let name = &run.spec.name;
    let refs = &run.reference.modes;
    let stats_path = dir.join(format!("{name}-mode-statistics.csv"));
    let label_columns = subject.mode_header(&[]).len();
    let rows: Vec<Vec<f64>> = refs
        .iter()
        .zip(&est.modes)
        .map(|(mr, me)| {
            let mut row = subject.mode_columns(mr);
            row.extend([
                me.variance.0,
                me.variance.1,
                mr.variance_discrete,
                mr.variance_continuum,
                me.rate.0,
                me.rate.1,
                mr.rate_discrete.unwrap_or(f64::NAN),
                mr.rate_continuum,
            ]);
            row
        })
        .collect();
    outputs.write_table(
        stats_path,
        &subject.mode_header(&[
            "variance",
            "variance_std_error",
            "variance_discrete",
            "variance_continuum",
            "rate",
            "rate_std_error",
            "rate_discrete",
            "rate_continuum",
        ]),
        &rows,
    )?;
    if est.modes.iter().any(|m| m.rate.0.is_finite()) {
        // Each row's mode number, then its columns after the labels: variance (4), rate,
        // its error, discrete rate and continuum rate.
        let at = |r: &Vec<f64>, k: usize| r[label_columns + k - 1];
        let words = outputs.words(subject.rate_words(name, refs));
        let fig = Figure::new(words.title, words.x_label, words.y_label)
            .series(
                Series::line(
                    words.discrete,
                    rows.iter().map(|r| (r[0], at(r, 7) / at(r, 8))).collect(),
                )
                .palette(1),
            )
            .series(
                Series::markers(
                    "simulated (±1 s.e.)",
                    rows.iter().map(|r| (r[0], at(r, 5) / at(r, 8))).collect(),
                )
                .with_errors(rows.iter().map(|r| at(r, 6) / at(r, 8)).collect())
                .palette(0),
            )
            .hline(1.0, words.continuum)
            .caption(words.caption);
        outputs.write_figure(&fig, dir.join(format!("{name}-rates.svg")))?;
    }
    Ok(())
}

/// `<run>-profile.csv`: ⟨w²(x)⟩ simulated, exact discrete and continuum; and
/// `<run>-profile.svg`, the same with the continuum curve over the whole filament (or
/// ⟨h²(x, b/2)⟩ along the whole midline of a membrane).
fn write_profile(
    subject: &Subject,
    units: AxisUnits,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let r = &run.reference;
    let path = dir.join(format!("{}-profile.csv", run.spec.name));
    let rows: Vec<Vec<f64>> = (0..est.profile.len())
        .map(|j| {
            vec![
                r.profile_x[j],
                est.profile[j].0,
                est.profile[j].1,
                r.profile_discrete[j],
                r.profile_continuum[j],
            ]
        })
        .collect();
    outputs.write_table(
        path,
        &["x", "variance", "std_error", "discrete", "continuum"],
        &rows,
    )?;
    let words = outputs.words(subject.profile_words(&run.spec.name, units));
    let fig = Figure::new(words.title, words.x_label, words.y_label)
        .series(
            Series::line(words.continuum, subject.profile_curve())
                .dashed()
                .palette(2),
        )
        .series(
            Series::markers(words.discrete, rows.iter().map(|r| (r[0], r[3])).collect())
                .palette(1)
                .light()
                .marker_radius(8),
        )
        .series(
            Series::markers(
                "simulated (±1 s.e.)",
                rows.iter().map(|r| (r[0], r[1])).collect(),
            )
            .with_errors(rows.iter().map(|r| r[2]).collect())
            .palette(0),
        )
        .caption(words.caption);
    outputs.write_figure(&fig, dir.join(format!("{}-profile.svg", run.spec.name)))
}

/// `<run>-two-time.csv`: the two-time correlation eq. (4) (a membrane's (M4) on its
/// midline) simulated, exact discrete and continuum; and `<run>-two-time.svg`: per point,
/// the simulated value and the exact discrete one at η, on the continuum as a function
/// of η at the point's x, y and t.
fn write_two_time(
    scene: &Scene,
    subject: &Subject,
    units: AxisUnits,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let path = dir.join(format!("{}-two-time.csv", run.spec.name));
    let rows: Vec<Vec<f64>> = run
        .reference
        .two_time
        .iter()
        .zip(&est.two_time)
        .map(|(q, e)| vec![q.x, q.y, q.t, q.eta, e.0, e.1, q.discrete, q.continuum])
        .collect();
    outputs.write_table(
        path,
        &[
            "x",
            "y",
            "t",
            "eta",
            "correlation",
            "std_error",
            "discrete",
            "continuum",
        ],
        &rows,
    )?;
    let words = outputs.words(subject.two_time_words(&run.spec.name, units));
    let fig = two_time_figure(scene.tau1(), subject, words, &rows);
    outputs.write_figure(&fig, dir.join(format!("{}-two-time.svg", run.spec.name)))
}

/// The two-time figure of [`write_two_time`] from the rows of `<run>-two-time.csv`, in
/// `words` (the subject's two-time words).
fn two_time_figure(tau1: f64, subject: &Subject, words: Words, rows: &[Vec<f64>]) -> Figure {
    let (length, unit, equation) = subject.two_time_legend();
    let eta_max = 1.25 * rows.iter().map(|r| r[3]).fold(0.0, f64::max);
    let mut fig = Figure::new(words.title, words.x_label, words.y_label).caption(words.caption);
    for (k, r) in rows.iter().enumerate() {
        let (x, y, t, eta) = (r[0], r[1], r[2], r[3]);
        let curve = subject.two_time_curve((x, y, t), eta_max, tau1);
        fig = fig
            .series(
                Series::markers(
                    format!(
                        "x = {} {unit}, y = {} {unit}, t = {} τ₁: simulated / {equation}",
                        short(x / length),
                        short(y / length),
                        short(t / tau1)
                    ),
                    vec![(eta / tau1, r[4])],
                )
                .with_errors(vec![r[5]])
                .palette(k)
                .joined_with_next(),
            )
            .series(Series::line("", curve).palette(k).light())
            .series(
                Series::markers("", vec![(eta / tau1, r[6])])
                    .palette(k)
                    .light()
                    .marker_radius(8),
            );
    }
    fig.series(
        Series::markers(words.discrete, Vec::new())
            .rgb(127, 127, 127)
            .light()
            .marker_radius(8),
    )
}

/// `v` with at most three decimals and no trailing zeros: `0.5`, `0.05`, `0.125`.
fn short(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// The modes whose Welch spectra `<run>-spectrum.svg` draws.
const SPECTRUM_MODES: [usize; 3] = [1, 3, 6];

/// `<run>-spectrum.csv` and `.svg` (modes 1, 3, 6): the pooled Welch spectra against
/// their exact expectation, when the spectrum check computed any.
fn write_spectra(
    subject: &Subject,
    units: AxisUnits,
    dir: &Path,
    run: &LinearRun,
    est: &LinearEstimates,
    outputs: &mut SceneOutputs<'_>,
) -> Result<()> {
    let name = &run.spec.name;
    let spectra: Vec<_> = est
        .modes
        .iter()
        .filter_map(|m| m.spectrum.as_ref().map(|s| (m.n, s)))
        .collect();
    if spectra.is_empty() {
        return Ok(());
    }
    let mut rows = Vec::new();
    let mut fig = Figure::new(
        format!("{name}: modal power spectra (Welch)"),
        format!("frequency f {}", units.frequency()),
        format!("one-sided PSD S(f) {}", units.psd()),
    )
    .log_x()
    .log_y()
    .caption(outputs.caption(subject.welch_caption(&SPECTRUM_MODES, &run.reference.modes)));
    let mut hue = 0;
    for (n, (f, p, e)) in &spectra {
        for k in 1..f.len() {
            rows.push(vec![*n as f64, f[k], p[k], e[k]]);
        }
        if SPECTRUM_MODES.contains(n) {
            fig = fig
                .series(
                    Series::markers(
                        format!(
                            "{}: simulated / exact",
                            subject.mode_name(*n, &run.reference.modes)
                        ),
                        f.iter().zip(p).skip(1).map(|(a, b)| (*a, *b)).collect(),
                    )
                    .palette(hue)
                    .joined_with_next(),
                )
                .series(
                    Series::line("", f.iter().zip(e).skip(1).map(|(a, b)| (*a, *b)).collect())
                        .palette(hue)
                        .light(),
                );
            hue += 1;
        }
    }
    let path = dir.join(format!("{name}-spectrum.csv"));
    outputs.write_table(path, &["mode", "frequency", "psd", "expected"], &rows)?;
    outputs.write_figure(&fig, dir.join(format!("{name}-spectrum.svg")))?;
    Ok(())
}

/// The element-count study of the paper's element-uniform noise (eq. 5), an output of
/// every `fem` scene with an element-uniform run (see the [module docs](self)): the
/// stationary variance of modes 1–6 relative to equipartition on uniform meshes of
/// [`NOISE_STUDY_ELEMENTS`] elements, from the exact discrete model alone
/// ([`element_uniform_variance_ratios`]). Writes `element-uniform-vs-elements.csv`
/// (`elements, mode1, …, mode6`) and `.svg` (1 − ratio against element count) and
/// returns the note (the ratios at 10 elements and the observed order of the deficit).
fn write_noise_study(scene: &Scene, dir: &Path, outputs: &mut SceneOutputs<'_>) -> Result<String> {
    let ratios =
        element_uniform_variance_ratios(&scene.filament, &NOISE_STUDY_ELEMENTS, NOISE_STUDY_MODES)?;
    let rows: Vec<Vec<f64>> = NOISE_STUDY_ELEMENTS
        .iter()
        .zip(ratios)
        .map(|(&ne, r)| std::iter::once(ne as f64).chain(r).collect())
        .collect();
    let path = dir.join("element-uniform-vs-elements.csv");
    outputs.write_table(
        path,
        &[
            "elements", "mode1", "mode2", "mode3", "mode4", "mode5", "mode6",
        ],
        &rows,
    )?;
    let mut fig = Figure::new(
        "element-uniform noise (eq. 5): variance deficit against element count",
        "elements N (dimensionless)",
        "1 − ⟨aₙ²⟩ / (kT/λᵢ) (dimensionless)",
    )
    .log_x()
    .log_y()
    .caption(
        "Theory only, no simulation: the stationary variance deficit of modes 1–6 under \
         the paper's element-uniform noise (eq. 5), relative to equipartition kT/λᵢ, on \
         uniform meshes of 5 to 160 elements (log–log). The lines should fall with element \
         count at the order given in the scene's note; the deficit belongs to that noise \
         model, not to the simulation.",
    );
    for i in 0..NOISE_STUDY_MODES {
        fig = fig.series(
            Series::line(
                format!("mode {}", i + 1),
                rows.iter().map(|r| (r[0], 1.0 - r[i + 1])).collect(),
            )
            .with_style(SeriesStyle::LineMarkers),
        );
    }
    outputs.write_figure(&fig, dir.join("element-uniform-vs-elements.svg"))?;
    // Observed order of the deficit of mode 1 between the two finest meshes.
    let k = rows.len() - 1;
    let order = ((1.0 - rows[k - 1][1]) / (1.0 - rows[k][1])).log2();
    let at10 = &rows[1];
    Ok(format!(
        "element-uniform noise (eq. 5) under-excites the discrete modes: with 10 elements modes 1-6 get {} of equipartition; the deficit of each mode falls as h^{order:.2} with element count (mode 1 at 160 elements: {:.2e}); see element-uniform-vs-elements.csv",
        at10[1..]
            .iter()
            .map(|v| format!("{v:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        1.0 - rows[k][1]
    ))
}
