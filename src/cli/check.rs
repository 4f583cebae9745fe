//! `langevin-fem check`: a scene's statistical checks applied to trajectories written by
//! any program in the trajectory data format ([`langevin_fem::data`]).

use super::Verbosity;
use super::terminal::{print_scenes, totals_line};
use clap::Args;
use langevin_fem::data::DataSidecar;
use langevin_fem::error::{Error, Result};
use langevin_fem::output::ReportRun;
use langevin_fem::progress::ProgressOptions;
use langevin_fem::report::write_report;
use langevin_fem::scene::Scene;
use langevin_fem::verify::check_data;
use langevin_fem::verify::summary::{Summary, Totals};
use std::path::PathBuf;
use std::time::Instant;

/// The examples of `check --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem run -s hinged-linear-2d -o traj            trajectories in the data format
  langevin-fem check -s hinged-linear-2d -d traj -o traj-report
  langevin-fem check -s my-scene.toml -d my-simulator-output -q

The last line of stdout is `N passed, N failed, N skipped in T s`; the exit code is 0 if
every check passed, 1 if one failed, 2 on bad input (the message names the file and key),
3 if an estimator found no answer in the data.";

/// Command-line arguments of `langevin-fem check`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct CheckArgs {
    /// Scene whose checks are applied: a name from the scene directory or a path to a
    /// .toml file. Its check kinds, modes, profile and two-time points say what is
    /// checked; the data's sidecar says what was simulated.
    #[arg(short, long, value_name = "NAME|PATH")]
    scene: String,
    /// Data directory: data.json (the sidecar) and the trajectory files it lists, as
    /// `langevin-fem run` writes them (see the guide, docs/src/reference/data-format.md).
    #[arg(short, long, value_name = "DIR")]
    pub(super) data: PathBuf,
    /// Output directory for summary.json, index.html and per-run tables and figures.
    #[arg(short, long, default_value = "check-report")]
    pub(super) out: PathBuf,
    /// Directory of scene files in which --scene NAME is looked up (default: the
    /// built-in scenes).
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Family-wise significance level (Holm correction over every check).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
    /// Cap on the trajectory data read, in GiB (the files' total size, and their values
    /// held as float64): larger data are refused (exit 2) before anything is read.
    #[arg(long, value_name = "GIB", default_value = "4", allow_negative_numbers = true, value_parser = super::parse_max_memory_gib)]
    max_memory_gib: f64,
}

/// Runs the checks; exit code 0 if every check passes, 1 otherwise. Prints the scenes
/// and the totals on stdout at `verbosity` ([`super::terminal`]).
pub fn run(args: CheckArgs, verbosity: Verbosity) -> Result<i32> {
    let start = Instant::now();
    let sidecar = load_data(&args)?;
    let (_, summary, report) = evaluate(&args, &sidecar, verbosity.progress())?;
    write_report(report, &summary)?;
    print_verdict(&args, &summary, verbosity, start, &[]);
    Ok(if summary.passed { 0 } else { 1 })
}

/// The scenes, `extra` lines, the verdict line and the totals of `check` on stdout at
/// `verbosity`.
pub(super) fn print_verdict(
    args: &CheckArgs,
    summary: &Summary,
    verbosity: Verbosity,
    start: Instant,
    extra: &[String],
) {
    print_scenes(summary, verbosity, false, true);
    for line in extra {
        println!("{line}");
    }
    if verbosity != Verbosity::Quiet {
        println!(
            "{} (data {}, family-wise alpha {}, Holm); report: {}",
            if summary.passed { "PASSED" } else { "FAILED" },
            args.data.display(),
            summary.alpha,
            args.out.join("index.html").display()
        );
    }
    println!(
        "{}",
        totals_line(&Totals::of(&summary.scenes), start.elapsed().as_secs_f64())
    );
}

/// The flags of `args` validated and the data's sidecar (`data.json`) read, once: what
/// [`evaluate`] checks and `fit` reads the filament's parameters from.
///
/// # Errors
/// Invalid flags (`--alpha`, `--data` not a directory or inside `--out`) or sidecar.
pub(super) fn load_data(args: &CheckArgs) -> Result<DataSidecar> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha < 0.5) {
        return Err(Error::invalid("--alpha", args.alpha, "in (0, 0.5)"));
    }
    if !args.data.is_dir() {
        return Err(Error::invalid(
            "--data",
            args.data.display(),
            "a directory holding data.json and the trajectory files it lists",
        ));
    }
    langevin_fem::input::refuse_input_in_output(&args.out, &args.data, "--data")?;
    DataSidecar::load(&args.data)
}

/// The checks of `args` on the data `sidecar` describes (from [`load_data`]): the scene,
/// the summary and the report (its files written, its index and summary not yet), with
/// `progress` over a long preparation of the references.
///
/// # Errors
/// An invalid scene or data; the checks' errors (as [`check_data`]).
pub(super) fn evaluate(
    args: &CheckArgs,
    sidecar: &DataSidecar,
    progress: ProgressOptions,
) -> Result<(Scene, Summary, ReportRun)> {
    let scene = langevin_fem::scene::load_scene(&args.scene, args.scene_dir.as_deref())?;
    let (summary, report) = check_data(
        &scene,
        sidecar,
        &args.data,
        &args.out,
        args.alpha,
        super::gib_bytes(args.max_memory_gib),
        progress,
    )?;
    Ok((scene, summary, report))
}
