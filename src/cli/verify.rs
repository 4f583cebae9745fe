//! `langevin-fem verify`: run verification scenes and write reports.

use super::Verbosity;
use super::terminal::{print_scenes, totals_line};
use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::output::ReportRun;
use langevin_fem::report::write_report;
use langevin_fem::scene::{Budget, load_scenes};
use langevin_fem::shard::Shard;
use langevin_fem::verify::Summary;
use langevin_fem::verify::shard::write_shard;
use langevin_fem::verify::summary::Totals;
use langevin_fem::verify::{Ensembles, VerifyOptions, run_verification};
use std::path::PathBuf;
use std::time::Instant;

/// The examples of `verify --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem verify                                  every built-in scene, quick budget, into reports/
  langevin-fem verify -s hinged-linear-2d -s compression-2d -b standard -o out
  langevin-fem verify -s my-scene.toml --seed 7 -j 2   a scene file of yours, another seed, 2 threads
  langevin-fem verify --scene-dir scenes/ -q           every scene in scenes/; failures and totals only
  langevin-fem verify -v | cat                         failed and skipped checks in detail, run times
  langevin-fem verify -b full --shard 2/4 -o shards/2  shard 2 of 4 (records only), then:
  langevin-fem merge shards/1 shards/2 shards/3 shards/4 -o reports

The last line of stdout is `N passed, N failed, N skipped in T s`; the exit code is 0 if
every check passed, 1 if one failed, 2 on bad input, 3 if a run failed.";

/// Command-line arguments of `langevin-fem verify`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct VerifyArgs {
    /// Scene to run: a built-in scene's name (see `langevin-fem list`), a name in
    /// --scene-dir when given, or a path to a .toml file (repeatable; default: every
    /// built-in top-level scene, or every scene of --scene-dir).
    #[arg(short = 's', long = "scene", value_name = "NAME|PATH")]
    scenes: Vec<String>,
    /// Statistics budget.
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: BudgetArg,
    /// Output directory for summary.json, index.html and per-scene figures and tables.
    #[arg(short, long, default_value = "reports")]
    pub(super) out: PathBuf,
    /// Directory of scene files: names resolve there instead of among the built-in
    /// scenes, and without --scene every scene there runs.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Family-wise significance level per scene (Holm correction).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
    /// Simulate only shard I of N of every run's trajectories and write their records and
    /// a manifest to --out, without checks or report; `langevin-fem merge` then writes the
    /// report of the whole run, byte for byte (see the guide, docs/src/tutorials/cluster.md).
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// With --shard: take the plans of a budget by target precision (step search and
    /// pilot) from this finished shard of the same set instead of computing them again
    /// (submit that shard first; the guide, docs/src/tutorials/cluster.md).
    #[arg(long, value_name = "SHARD_DIR", requires = "shard")]
    plan_from: Option<PathBuf>,
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    pub(super) sim: super::SimArgs,
}

impl VerifyArgs {
    /// Whether `--shard` was given (the output is then a shard, not a report).
    pub(super) fn is_shard(&self) -> bool {
        self.shard.is_some()
    }
}

/// A statistics budget on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(super) enum BudgetArg {
    Quick,
    Standard,
    Full,
}

impl BudgetArg {
    /// The budget.
    pub(super) fn budget(self) -> Budget {
        match self {
            BudgetArg::Quick => Budget::Quick,
            BudgetArg::Standard => Budget::Standard,
            BudgetArg::Full => Budget::Full,
        }
    }
}

/// Runs the verification; exit code 0 if every check passes, 1 otherwise. Prints the
/// scenes and the totals on stdout at `verbosity` ([`super::terminal`]), progress on
/// stderr.
pub fn run(args: VerifyArgs, verbosity: Verbosity) -> Result<i32> {
    let start = Instant::now();
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha < 0.5) {
        return Err(Error::invalid("--alpha", args.alpha, "in (0, 0.5)"));
    }
    if let Some(dir) = &args.plan_from {
        langevin_fem::input::refuse_input_in_output(&args.out, dir, "--plan-from")?;
    }
    let budget = args.budget.budget();
    let mut scenes = load_scenes(&args.scenes, args.scene_dir.as_deref())?;
    if scenes.is_empty() {
        let dir = args
            .scene_dir
            .as_deref()
            .unwrap_or(std::path::Path::new(""));
        return Err(Error::invalid(
            "--scene-dir",
            dir.display(),
            "a directory containing at least one scene (*.toml)",
        ));
    }
    let seed_notes: Vec<String> = scenes.iter_mut().map(|s| args.sim.apply(s)).collect();
    let opts = VerifyOptions {
        scenes,
        budget,
        out: args.out.clone(),
        alpha: args.alpha,
        progress: verbosity.progress(),
        limits: args.limits.limits(),
        ensembles: Ensembles::Simulate,
    };
    if let Some(shard) = args.shard {
        let manifest = write_shard(&opts, shard, &seed_notes, args.plan_from.as_deref())?;
        println!(
            "shard {shard}: {} record file(s) in {}; when every shard of {} is done: langevin-fem merge <the {} shard directories> -o <report dir>",
            manifest.files.len(),
            args.out.display(),
            shard.count,
            shard.count
        );
        return Ok(0);
    }
    let (summary, report) = run_verification(&opts)?;
    finish(summary, report, seed_notes, &args.out, verbosity, start)
}

/// Finishes a verification (or a merge of one): adds each scene's seed note, writes the
/// report, prints the scenes and the totals at `verbosity`; exit code 0 if every check
/// passed, 1 otherwise.
pub(super) fn finish(
    mut summary: Summary,
    report: ReportRun,
    seed_notes: Vec<String>,
    out: &std::path::Path,
    verbosity: Verbosity,
    start: Instant,
) -> Result<i32> {
    for (scene, note) in summary.scenes.iter_mut().zip(seed_notes) {
        scene.notes.push(note);
    }
    write_report(report, &summary)?;
    print_scenes(&summary, verbosity, true, false);
    if verbosity != Verbosity::Quiet {
        println!(
            "{} (budget {}, family-wise alpha {} per scene, Holm); report: {} (run {})",
            if summary.passed { "PASSED" } else { "FAILED" },
            summary.budget,
            summary.alpha,
            out.join("index.html").display(),
            summary.run_id
        );
    }
    println!(
        "{}",
        totals_line(&Totals::of(&summary.scenes), start.elapsed().as_secs_f64())
    );
    Ok(if summary.passed { 0 } else { 1 })
}
