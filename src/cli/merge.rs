//! `langevin-fem merge`: the output of a command split into shards (`verify`, `converge`
//! or `run` with `--shard I/N`), from the shards' records, byte for byte the output of
//! the same command run in one process (wall times, run id and provenance aside). See
//! [`langevin_fem::shard`].

use super::Verbosity;
use clap::Args;
use langevin_fem::error::Result;
use langevin_fem::progress::ProgressOptions;
use langevin_fem::shard::ShardSet;
use langevin_fem::studies::converge::shard::COMMAND as CONVERGE;
use langevin_fem::verify::shard::{COMMAND, settings_of};
use langevin_fem::verify::{Ensembles, VerifyOptions, run_verification};
use langevin_fem::work::WorkLimits;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// The examples of `merge --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem verify -b full --shard 1/2 -o shards/1      (one process or array task each)
  langevin-fem verify -b full --shard 2/2 -o shards/2
  langevin-fem merge shards/1 shards/2 -o reports          the report of the whole run
  langevin-fem merge shards -o reports                     the same: every shard under shards/
  langevin-fem converge -s compression-2d --over elements --shard 1/2 -o cv/1   (and 2/2)
  langevin-fem merge cv/1 cv/2 -o reports/convergence      the whole study and its index
  langevin-fem run -s hinged-linear-2d --shard 1/2 -o traj/1                     (and 2/2)
  langevin-fem merge traj/1 traj/2 -o trajectories         the whole run's trajectories

Refused (exit 2, naming the shard): a missing or duplicated shard, shards of other scenes,
seeds, budgets, settings or builds, a damaged record file; an output directory that is or
holds a shard, or holds another command's output. A refused or failed merge leaves an
earlier output in --out as it was. The exit code is otherwise the
command's: for verify 0 if every check passed, 1 if one failed.";

/// Command-line arguments of `langevin-fem merge`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct MergeArgs {
    /// Shard directories (each with a shard.json), or directories whose sub-directories
    /// are shards; together exactly the shards 1/N … N/N of one run.
    #[arg(required = true, value_name = "DIR")]
    shards: Vec<PathBuf>,
    /// Output directory of the merged output (verify: summary.json, index.html, tables,
    /// figures; converge: the study's set and index; run: the trajectories and data.json).
    #[arg(short, long, default_value = "reports")]
    pub(super) out: PathBuf,
    /// Cap on the record bytes held at once (one run's records from every shard, and so
    /// any one record file), in GiB: a larger set is refused (exit 2) before it is read.
    #[arg(long, value_name = "GIB", default_value = "4", allow_negative_numbers = true, value_parser = super::parse_max_memory_gib)]
    max_memory_gib: f64,
}

/// Opens the shard set, checks it, and writes the whole command's output to `--out`.
///
/// # Errors
/// Exit 2 for a shard set that is not one complete, consistent set
/// ([`ShardSet::open`]); as `verify` otherwise.
pub fn run(args: MergeArgs, verbosity: Verbosity) -> Result<i32> {
    let start = Instant::now();
    for dir in &args.shards {
        langevin_fem::input::refuse_input_in_output(&args.out, dir, "merge DIR")?;
    }
    let set = ShardSet::open(&args.shards, super::gib_bytes(args.max_memory_gib))?;
    match set.manifest().command.as_str() {
        COMMAND => merge_verify(set, &args, verbosity, start),
        CONVERGE => super::converge::merge(set, &args.out, verbosity),
        super::run::COMMAND => super::run::merge(set, &args.out, verbosity),
        other => Err(set.refuse(
            "command",
            format!(
                "a shard of `{other}`, but merge takes shards of `verify`, `converge` or `run`"
            ),
        )),
    }
}

/// `merge` of a verification's shards.
fn merge_verify(
    set: ShardSet,
    args: &MergeArgs,
    verbosity: Verbosity,
    start: Instant,
) -> Result<i32> {
    let (budget, alpha) = settings_of(&set)?;
    if !(alpha.is_finite() && alpha > 0.0 && alpha < 0.5) {
        return Err(set.settings_error(langevin_fem::Error::invalid(
            "--alpha",
            alpha,
            "in (0, 0.5)",
        )));
    }
    let (scenes, seed_notes): (Vec<_>, Vec<_>) = set.scenes()?.into_iter().unzip();
    if verbosity.shows_progress() {
        eprintln!(
            "merging {} shards of verify (budget {}, {} scene(s))",
            set.shards.len(),
            budget.name(),
            scenes.len()
        );
    }
    let (summary, report) = run_verification(&VerifyOptions {
        scenes,
        budget,
        out: args.out.clone(),
        alpha,
        // Nothing is simulated: no progress bar over DOF-steps.
        progress: ProgressOptions::HIDDEN,
        limits: WorkLimits {
            max_memory_gib: args.max_memory_gib,
            ..WorkLimits::default()
        },
        ensembles: Ensembles::Merge(Arc::new(set)),
    })?;
    super::verify::finish(summary, report, seed_notes, &args.out, verbosity, start)
}
