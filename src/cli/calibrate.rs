//! `langevin-fem calibrate`: each scene's verification at N seeds, and how trustworthy
//! the verifier is under a correct simulator — the false-alarm rate per scene and the
//! uniformity of the p-values per check kind (the statistics are
//! [`langevin_fem::verify::calibrate`]'s).
//!
//! Seed k (k = 0 … N−1) is `--first-seed` + k, applied to every scene as `verify --seed`
//! does; each (seed, scene) is one in-process [`run_verification`] of that scene alone,
//! so its checks are exactly those of `verify --scene NAME --seed <seed>` at the same
//! budget and α. Its report goes to a scratch directory inside `--out`
//! ([`SCRATCH`]), removed as soon as its summary is read: `--out` is the only place
//! written. The seeds run one after the other (each verification already uses every
//! worker thread); seed 0 of every scene runs first, so bad input is found within the
//! first round. Bad input at the first seed (exit 2) and I/O errors stop the command.
//! Any other failure of a (seed, scene) — a run failure (exit-3 class: an estimator that
//! finds no answer in the data, a failed factorization), or at a later seed a
//! seed-dependent error such as a divergence, whose input passed at the first seed — is
//! recorded as a failure of that seed with its message (a *run failure*), not an abort.

use super::Verbosity;
use super::verify::BudgetArg;
use super::{count_in, usize_in};
use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::output::{Provenance, ReportRun};
use langevin_fem::progress::{Progress, ProgressOptions};
use langevin_fem::report::write_calibration_report;
use langevin_fem::scene::{Budget, Scene, load_scenes};
use langevin_fem::verify::calibrate::{
    CalibrationSummary, ENTRY_POINTS, FALSE_ALARM_RULE, FailedSeed, KindUniformity, MANIFEST,
    P_VALUES_CSV, PValueRow, SceneCalibration, SeedPlan, UNIFORMITY_LEVEL, UNIFORMITY_RULE,
    false_alarms, p_value_figure, p_values_csv, p_values_per_check, uniformity_by_kind,
};
use langevin_fem::verify::{
    Ensembles, SceneSummary, VerifyOptions, projected_work, run_verification,
};
use langevin_fem::work::{WorkLimits, WorkProjection};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The first seed when `--first-seed` is not given.
pub const DEFAULT_FIRST_SEED: u64 = 1;

/// The scratch directory inside `--out` that holds one verification's report while its
/// summary is read (removed after each seed, and at the start if an interrupted run left
/// it).
pub const SCRATCH: &str = ".calibrate-scratch";

/// The examples of `calibrate --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem calibrate -s hinged-linear-2d --seeds 20          20 seeds of one scene
  langevin-fem calibrate --seeds 100 -o reports/calibration      every built-in scene (about 25 min)
  langevin-fem calibrate -s my-scene.toml --seeds 50 --first-seed 1000 -j 2

Progress goes to stderr: a bar on a terminal, else a line per seed; the tables go to stdout.";

/// Command-line arguments of `langevin-fem calibrate`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct CalibrateArgs {
    /// Scene to calibrate: a built-in scene's name, a name in --scene-dir when given, or
    /// a path to a .toml file (repeatable; default: every built-in top-level scene, or
    /// every scene of --scene-dir).
    #[arg(short = 's', long = "scene", value_name = "NAME|PATH")]
    scenes: Vec<String>,
    /// Seeds per scene, N (2 to 100000): seed k = --first-seed + k, k = 0 .. N-1.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = count_in::<2, 100_000>)]
    seeds: u64,
    /// The first seed (any integer in [0, 18446744073709551615] such that the last seed,
    /// first + N - 1, is too).
    #[arg(long, value_name = "S", default_value_t = DEFAULT_FIRST_SEED, allow_negative_numbers = true, value_parser = count_in::<0, { u64::MAX }>)]
    first_seed: u64,
    /// Statistics budget of every verification.
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: BudgetArg,
    /// Family-wise significance level per scene (Holm), as in `verify`.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
    /// Output directory: calibration.json, p-values.csv, <scene>-p-values.svg,
    /// index.html and the journal manifest.json.
    #[arg(short, long, default_value = "reports/calibration")]
    pub(super) out: PathBuf,
    /// Directory of scene files: names resolve there instead of among the built-in
    /// scenes, and without --scene every scene there runs.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Worker threads of the parallel ensembles (1 to 256; default: rayon's, the number
    /// of CPUs or RAYON_NUM_THREADS). Results are bit-identical whatever the count.
    #[arg(short = 'j', long, value_name = "N", allow_negative_numbers = true, value_parser = usize_in::<1, 256>)]
    threads: Option<usize>,
    #[command(flatten)]
    limits: super::LimitArgs,
}

impl CalibrateArgs {
    /// Sizes rayon's global pool if `--threads` was given (as [`super::SimArgs::start`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--threads` if the pool cannot be built.
    pub(super) fn start(&self) -> Result<()> {
        super::SimArgs {
            seed: None,
            threads: self.threads,
        }
        .start()
    }
}

/// One scene's results over the seeds, as they come in.
#[derive(Default)]
struct SceneTally {
    failed: Vec<FailedSeed>,
    run_failures: u64,
    checks_per_seed: Vec<usize>,
    wall_seconds: f64,
}

/// Runs the calibration; exit code 0 if every scene is consistent with α and no check
/// kind is rejected, 1 otherwise.
pub fn run(args: CalibrateArgs, verbosity: Verbosity) -> Result<i32> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha < 0.5) {
        return Err(Error::invalid("--alpha", args.alpha, "in (0, 0.5)"));
    }
    let n = args.seeds;
    let plan = SeedPlan::consecutive(args.first_seed, n).ok_or_else(|| {
        Error::invalid(
            "--first-seed",
            args.first_seed,
            format!(
                "at most {} (the last of the --seeds {n} seeds, first + {}, must be at most 18446744073709551615)",
                u64::MAX - (n - 1),
                n - 1
            ),
        )
    })?;
    let budget = args.budget.budget();
    let scenes = load_scenes(&args.scenes, args.scene_dir.as_deref())?;
    if scenes.is_empty() {
        let dir = args.scene_dir.as_deref().unwrap_or(Path::new(""));
        return Err(Error::invalid(
            "--scene-dir",
            dir.display(),
            "a directory containing at least one scene (*.toml)",
        ));
    }
    let limits = args.limits.limits();
    limits.check(&total_work(&scenes, budget, n))?;
    let provenance = Provenance::begin(&scenes.iter().collect::<Vec<_>>());
    let scratch = args.out.join(SCRATCH);
    remove_scratch(&scratch)?;
    let progress = verbosity.progress();
    if progress.mode != langevin_fem::progress::ProgressMode::Hidden {
        eprintln!(
            "calibrate: {} scene(s) x {n} seeds ({} .. {}; seed k = {} + k, each as `verify --seed`), budget {}, alpha {} per scene",
            scenes.len(),
            plan.seeds[0],
            plan.seeds[plan.seeds.len() - 1],
            plan.first,
            budget.name(),
            args.alpha
        );
    }
    let (tallies, rows) = verify_seeds(
        &scenes,
        &plan,
        (budget, args.alpha, limits),
        &scratch,
        progress,
    )?;
    let per_check = p_values_per_check(&rows);
    let kinds = uniformity_by_kind(&per_check)?;
    let scene_results = scene_calibrations(&scenes, tallies, n, args.alpha)?;
    let report = ReportRun::begin(&args.out, "calibrate", MANIFEST, &ENTRY_POINTS)?;
    report.set_provenance(provenance)?;
    report.write(
        &args.out.join(P_VALUES_CSV),
        p_values_csv(&rows)?.as_bytes(),
    )?;
    for s in &scene_results {
        let fig = p_value_figure(&s.name, n, &kind_p_values(&rows, &s.name));
        report.write_svg(&args.out.join(&s.figure), &fig)?;
    }
    let passed = scene_results.iter().all(|s| s.false_alarms.consistent)
        && !kinds.iter().any(|k| k.rejected);
    let summary = CalibrationSummary {
        run_id: report.run_id(),
        budget: budget.name().to_string(),
        alpha: args.alpha,
        seeds: plan,
        false_alarm_rule: FALSE_ALARM_RULE.to_string(),
        uniformity_rule: UNIFORMITY_RULE.to_string(),
        passed,
        scenes: scene_results,
        kinds,
        files: report.files(),
        provenance: report.provenance_ref(),
    };
    write_calibration_report(report, &summary)?;
    print_summary(&summary);
    println!(
        "{}; report: {} (run {})",
        if passed { "PASSED" } else { "FAILED" },
        args.out.join("index.html").display(),
        summary.run_id
    );
    Ok(if passed { 0 } else { 1 })
}

/// Per scene, its false-alarm rate over the `seeds` seeds against `alpha` from its tally.
///
/// # Errors
/// As [`false_alarms`].
fn scene_calibrations(
    scenes: &[Scene],
    tallies: Vec<SceneTally>,
    seeds: u64,
    alpha: f64,
) -> Result<Vec<SceneCalibration>> {
    scenes
        .iter()
        .zip(tallies)
        .map(|(scene, tally)| {
            Ok(SceneCalibration {
                name: scene.name.clone(),
                false_alarms: false_alarms(
                    tally.failed.len() as u64,
                    tally.run_failures,
                    seeds,
                    alpha,
                )?,
                checks_per_seed: tally.checks_per_seed,
                failed_seeds: tally.failed,
                figure: figure_name(&scene.name),
                wall_seconds: tally.wall_seconds,
            })
        })
        .collect()
}

/// Verifies every scene at every seed of `plan` in `scratch` (removed after each), in
/// turn: per scene its tally, and one p-value row per check per seed. A run failure at a
/// seed is recorded, not returned; bad input at the first seed and I/O errors stop.
/// Progress (`progress`) is weighted by each scene's projected work; on plain lines,
/// one line at the start of every seed.
///
/// # Errors
/// Input errors at the first seed (exit 2), I/O errors.
fn verify_seeds(
    scenes: &[Scene],
    plan: &SeedPlan,
    (budget, alpha, limits): (Budget, f64, WorkLimits),
    scratch: &Path,
    progress: ProgressOptions,
) -> Result<(Vec<SceneTally>, Vec<PValueRow>)> {
    let n = plan.seeds.len() as u64;
    let work: Vec<f64> = scenes
        .iter()
        .map(|s| projected_work(std::slice::from_ref(s), budget).dof_steps())
        .collect();
    let bar = Progress::new(progress, n as f64 * work.iter().sum::<f64>(), "DOF-steps");
    let mut tallies: Vec<SceneTally> = scenes.iter().map(|_| SceneTally::default()).collect();
    let mut rows: Vec<PValueRow> = Vec::new();
    for (k, &seed) in plan.seeds.iter().enumerate() {
        for ((scene, tally), &w) in scenes.iter().zip(&mut tallies).zip(&work) {
            bar.begin_run(
                &format!("seed {seed}"),
                &format!("seed {} of {n} ({seed}): {}", k + 1, scene.name),
                w,
            );
            let mut one = scene.clone();
            one.seed = seed;
            let outcome = run_verification(&VerifyOptions {
                scenes: vec![one],
                budget,
                out: scratch.to_path_buf(),
                alpha,
                progress: ProgressOptions::HIDDEN,
                limits,
                ensembles: Ensembles::Simulate,
            });
            remove_scratch(scratch)?;
            match outcome {
                Ok((summary, _unfinished)) => {
                    for s in &summary.scenes {
                        record_scene(s, seed, tally, &mut rows, &bar);
                    }
                }
                Err(err @ Error::Io { .. }) => return Err(err),
                Err(err) if k == 0 && err.exit_code() == 2 => return Err(err),
                Err(err) => {
                    let message = err.to_string();
                    bar.println(&format!(
                        "{} seed {seed}: run failed: {message}",
                        scene.name
                    ));
                    tally.run_failures += 1;
                    tally.failed.push(FailedSeed {
                        seed,
                        failed_checks: Vec::new(),
                        run_failure: Some(message),
                    });
                }
            }
        }
    }
    bar.finish();
    Ok((tallies, rows))
}

/// The work of `n` verifications of every scene, one after the other: each part's
/// steps times `n`, its memory as it is (the seeds run in turn).
fn total_work(scenes: &[Scene], budget: Budget, n: u64) -> WorkProjection {
    let one = projected_work(scenes, budget);
    WorkProjection {
        command: format!("calibrate --budget {} --seeds {n}", budget.name()),
        parts: one
            .parts
            .into_iter()
            .map(|mut p| {
                p.work.trajectory_steps *= n as f64;
                p.work.dof_steps *= n as f64;
                p.label = format!("{} at each of {n} seeds", p.label);
                p.drivers = format!("{}, times --seeds {n}", p.drivers);
                p
            })
            .collect(),
    }
}

/// Removes the scratch directory if present.
///
/// # Errors
/// [`Error::Io`] naming it if it cannot be removed.
fn remove_scratch(scratch: &Path) -> Result<()> {
    match std::fs::remove_dir_all(scratch) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(Error::io(scratch, e)),
    }
}

/// Adds the checks of scene summary `s` at `seed` to `rows` and its outcome to `tally`.
fn record_scene(
    s: &SceneSummary,
    seed: u64,
    tally: &mut SceneTally,
    rows: &mut Vec<PValueRow>,
    bar: &Progress,
) {
    tally.wall_seconds += s.wall_seconds;
    if !tally.checks_per_seed.contains(&s.checks.len()) {
        tally.checks_per_seed.push(s.checks.len());
    }
    rows.extend(s.checks.iter().map(|c| PValueRow {
        scene: s.name.clone(),
        seed,
        check: c.name.clone(),
        kind: c.kind.clone(),
        p_value: c.p_value,
        p_adjusted: c.p_adjusted,
        passed: c.passed,
    }));
    if !s.passed {
        let failed: Vec<String> = s
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name.clone())
            .collect();
        bar.println(&format!(
            "{} seed {seed}: failed: {}",
            s.name,
            failed.join(", ")
        ));
        tally.failed.push(FailedSeed {
            seed,
            failed_checks: failed,
            run_failure: None,
        });
    }
}

/// The figure of `scene`'s p-values: `<scene>-p-values.svg`.
fn figure_name(scene: &str) -> String {
    format!("{scene}-p-values.svg")
}

/// The raw p-values of `scene` per kind, kinds sorted by name.
fn kind_p_values(rows: &[PValueRow], scene: &str) -> Vec<(String, Vec<f64>)> {
    let mut kinds: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.scene == scene) {
        let list = kinds.entry(r.kind.as_str()).or_default();
        list.extend(r.p_value);
    }
    kinds.into_iter().map(|(k, p)| (k.to_string(), p)).collect()
}

/// Stdout: one line per scene, then the table of the check kinds and the rules.
fn print_summary(s: &CalibrationSummary) {
    println!(
        "{:<24} {:>12} {:>8} {:>7} {:>18} {:>10}  verdict",
        "scene", "failed/seeds", "run-fail", "rate", "95% interval", "binom p"
    );
    for sc in &s.scenes {
        let f = &sc.false_alarms;
        println!(
            "{:<24} {:>12} {:>8} {:>7.4} {:>18} {:>10}  {}",
            sc.name,
            format!("{}/{}", f.failed, f.seeds),
            f.run_failures,
            f.rate,
            format!("[{:.4}, {:.4}]", f.interval[0], f.interval[1]),
            fmt_p(f.binomial_p),
            if f.consistent {
                "consistent with alpha"
            } else {
                "ABOVE alpha"
            }
        );
    }
    println!();
    println!(
        "{:<20} {:>6} {:>6} {:>8} {:>18} {:>18} {:>12}  verdict",
        "kind", "checks", "tested", "p-values", "p<0.05 (s.e.)", "p<0.01 (s.e.)", "min adj KS p"
    );
    for k in &s.kinds {
        println!(
            "{:<20} {:>6} {:>6} {:>8} {:>18} {:>18} {:>12}  {}",
            k.kind,
            k.checks,
            k.tested,
            k.p_values,
            tail(k, 0),
            tail(k, 1),
            k.smallest_adjusted_p.map_or("-".to_string(), fmt_p),
            kind_verdict(k)
        );
        for c in k.per_check.iter().filter(|c| c.rejected) {
            println!(
                "    non-uniform: {}: {} (KS D = {:.3}, adjusted p = {:.3e})",
                c.scene,
                c.name,
                c.ks_statistic.unwrap_or(f64::NAN),
                c.ks_p_adjusted.unwrap_or(f64::NAN)
            );
        }
    }
    println!(
        "rule: per check, KS of its raw p-values over the seeds against U(0,1); per kind, Holm over its checks; a kind is rejected if any adjusted KS p-value < {UNIFORMITY_LEVEL}"
    );
    println!(
        "rule: a scene is consistent with alpha unless its whole exact 95 % interval lies above alpha"
    );
}

/// A p-value for the tables: 4 decimals, or 3 significant digits below 0.001.
fn fmt_p(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.4}")
    } else {
        format!("{p:.2e}")
    }
}

/// A kind's pooled fraction below `TAIL_LEVELS[i]` with its standard error.
fn tail(k: &KindUniformity, i: usize) -> String {
    k.tails.get(i).map_or("-".to_string(), |t| {
        format!("{:.4} ({:.4})", t.fraction, t.std_error)
    })
}

fn kind_verdict(k: &KindUniformity) -> &'static str {
    match (k.tested, k.rejected) {
        (0, _) => "not tested",
        (_, true) => "REJECTED",
        (_, false) => "uniform",
    }
}
