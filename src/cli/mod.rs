//! Argument parsing (clap) and dispatch.

mod calibrate;
mod check;
mod converge;
mod fit;
mod list;
mod merge;
#[cfg(feature = "faults")]
mod power;
mod run;
mod scene;
mod stability;
mod terminal;
mod theory;
mod verify;
mod work_precision;

use clap::{Args, CommandFactory, Parser, Subcommand};
use langevin_fem::Result;
use langevin_fem::error::Error;
use langevin_fem::output::OutputLock;
use langevin_fem::output::manifest::{OutputKind, refuse_occupied};
use langevin_fem::progress::ProgressOptions;
use langevin_fem::scene::Scene;
use langevin_fem::work::WorkLimits;
use std::path::Path;
use std::str::FromStr;

/// Finite-element Langevin dynamics of thermally fluctuating filaments and membranes, with
/// exact references and statistical verification.
///
/// Results and summaries go to stdout; progress, warnings and errors to stderr. Exit
/// codes: 0 ok, 1 checks failed, 2 bad input (the message names the flag, or the file and
/// key), 3 a run failed.
#[derive(Debug, Parser)]
#[command(name = "langevin-fem", version = langevin_fem::output::provenance::VERSION_LINE, about, long_about = None, after_help = EXAMPLES)]
struct Cli {
    /// Print no progress and no per-scene lines: only failures, warnings, errors and the
    /// closing totals line.
    #[arg(
        short,
        long,
        global = true,
        conflicts_with = "verbose",
        display_order = 1000
    )]
    quiet: bool,
    /// Print more: every failed check with its statistic, p-values and estimate, every
    /// skipped check with the reason, and the wall time of every run.
    #[arg(short, long, global = true, display_order = 1000)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

/// The examples of `langevin-fem --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem verify                          every built-in scene, quick budget, reports/
  langevin-fem verify -s hinged-linear-2d -b full -o out
  langevin-fem verify -q | tee verify.log      failures and the totals line only
  langevin-fem list                            the built-in scenes
  langevin-fem theory mode --n 1               exact rate and variance of mode 1
  langevin-fem completions bash > ~/.local/share/bash-completion/completions/langevin-fem";

/// How much a command prints (`--quiet`, `--verbose`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verbosity {
    /// Failures, warnings and the totals line only; no progress.
    Quiet,
    /// Progress, per-scene lines, totals.
    Normal,
    /// Also every failed and skipped check in detail, and run times.
    Verbose,
}

impl Verbosity {
    /// The progress a command shows on stderr: none if quiet, run times if verbose.
    pub fn progress(self) -> ProgressOptions {
        ProgressOptions::stderr(self != Verbosity::Quiet, self == Verbosity::Verbose)
    }

    /// Whether progress lines are printed (not quiet).
    pub fn shows_progress(self) -> bool {
        self != Verbosity::Quiet
    }
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Exact results of the theory, printed as one JSON object on stdout.
    Theory(theory::TheoryArgs),
    /// Run verification scenes and write reports.
    Verify(verify::VerifyArgs),
    /// Each scene's verification at N seeds: the false-alarm rate per scene (exact
    /// binomial interval) and the uniformity of the checks' p-values per check kind.
    Calibrate(calibrate::CalibrateArgs),
    /// Convergence study of a finite-element scene (linear or compression) over the
    /// element count or the time step.
    Converge(converge::ConvergeArgs),
    /// Stability map (integrator x dt*lambda_max x elements) and per-mode stationary
    /// bias against each integrator's exact discrete-time formula.
    Stability(stability::StabilityArgs),
    /// Work-precision study: error in <w2(L/2)> against wall time for every integrator
    /// and noise model, and the projected cost of reaching a tolerance.
    WorkPrecision(work_precision::WorkPrecisionArgs),
    /// Simulate a scene's ensemble and write every trajectory's time series (NumPy .npy
    /// or CSV, with a data.json sidecar) for your own analysis or `check`.
    Run(run::RunArgs),
    /// The output of a command split into shards (`verify`, `converge` or `run` with
    /// `--shard I/N`): byte for byte what the command writes in one process.
    Merge(merge::MergeArgs),
    /// Apply a scene's statistical checks to trajectories written by any simulator in
    /// the trajectory data format (the format `run` writes).
    Check(check::CheckArgs),
    /// The bending rigidity (from the mode variances) and the drag (from the decay rates)
    /// that a filament's or a membrane's data imply, with 95 % intervals, beside the
    /// report of `check`.
    Fit(fit::FitArgs),
    /// List the scenes: the built-in ones, and with --scene-dir the files there.
    List(list::ListArgs),
    /// Inspect a scene.
    Scene(scene::SceneArgs),
    /// Fault injection (a `--features faults` build only): the detection rate of every
    /// catalogued simulator fault over seeds, per scene and size, with Clopper-Pearson
    /// intervals; writes power.csv, power.json and power.md.
    #[cfg(feature = "faults")]
    Power(power::PowerArgs),
    /// Print a shell completion script on stdout (bash, zsh or fish).
    #[command(after_help = "\
Examples:
  langevin-fem completions bash > ~/.local/share/bash-completion/completions/langevin-fem
  langevin-fem completions zsh > ~/.zfunc/_langevin-fem     (with fpath+=~/.zfunc)
  langevin-fem completions fish > ~/.config/fish/completions/langevin-fem.fish")]
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: Shell,
    },
}

/// A shell of `completions`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum Shell {
    Bash,
    Zsh,
    Fish,
}

/// Parses the command line and runs the command; returns the process exit code.
pub fn run() -> Result<i32> {
    let cli = Cli::parse();
    let v = match (cli.quiet, cli.verbose) {
        (true, _) => Verbosity::Quiet,
        (false, true) => Verbosity::Verbose,
        (false, false) => Verbosity::Normal,
    };
    match cli.command {
        Command::Theory(args) => theory::run(args),
        Command::Verify(args) => {
            let _lock = check_out_dir(&args.out, shard_or(args.is_shard(), "verify", false))?;
            args.sim.start()?;
            verify::run(args, v)
        }
        Command::Calibrate(args) => {
            let _lock = check_out_dir(&args.out, report("calibrate", false))?;
            args.start()?;
            calibrate::run(args, v)
        }
        Command::Converge(args) => {
            let _lock = check_out_dir(&args.out, shard_or(args.is_shard(), "converge", true))?;
            args.sim.start()?;
            converge::run(args, v)
        }
        Command::Stability(args) => {
            let _lock = check_out_dir(&args.out, report("stability", true))?;
            args.sim.start()?;
            stability::run(args, v)
        }
        Command::WorkPrecision(args) => {
            let _lock = check_out_dir(&args.out, report("work-precision", true))?;
            args.sim.start()?;
            work_precision::run(args, v)
        }
        Command::Run(args) => {
            let _lock = check_out_dir(&args.out, shard_or(args.is_shard(), "run", false))?;
            run::run(args, v)
        }
        Command::Merge(args) => {
            let _lock = check_out_dir(&args.out, None)?;
            merge::run(args, v)
        }
        Command::Check(args) => {
            let _lock = check_out_dir(&args.out, report("check", false))?;
            check::run(args, v)
        }
        Command::Fit(args) => {
            let _lock = check_out_dir(&args.check.out, report("check", false))?;
            fit::run(args, v)
        }
        Command::List(args) => list::run(args),
        Command::Scene(args) => scene::run(args),
        #[cfg(feature = "faults")]
        Command::Power(args) => {
            let _lock = check_out_dir(&args.out, None)?;
            power::run(args, v)
        }
        Command::Completions { shell } => {
            let shell = match shell {
                Shell::Bash => clap_complete::Shell::Bash,
                Shell::Zsh => clap_complete::Shell::Zsh,
                Shell::Fish => clap_complete::Shell::Fish,
            };
            clap_complete::generate(
                shell,
                &mut Cli::command(),
                "langevin-fem",
                &mut std::io::stdout(),
            );
            Ok(0)
        }
    }
}

/// A report run of `command` (in the studies' shared folder if `shared`).
fn report(command: &str, shared: bool) -> Option<OutputKind<'_>> {
    Some(OutputKind::Report { command, shared })
}

/// A shard of `command` if `shard`, else its report run ([`report`]).
fn shard_or(shard: bool, command: &str, shared: bool) -> Option<OutputKind<'_>> {
    if shard {
        Some(OutputKind::Shard { command })
    } else {
        report(command, shared)
    }
}

/// `--out` must be, or be creatable as, a writable directory: checked before anything
/// runs, so an unwritable location fails at once (exit 2, naming `--out`) instead of after
/// the whole simulation. Nothing is created here: the nearest existing ancestor (or `out`
/// itself) must be a directory that accepts a file (probed and removed at once). An
/// existing `out` must hold no other command's output or data that the command (`kind`,
/// if known before the inputs are read) would replace or remove
/// ([`langevin_fem::output::manifest::refuse_occupied`]). The temporary files and staging
/// directories that interrupted runs left in an existing `out` are removed
/// ([`langevin_fem::output::remove_stale_temporaries`]). Then `out` is locked for the
/// command's life ([`OutputLock`], created if missing), so that a second command writing
/// there at the same time is refused (exit 2) — except a study's folder, which several
/// studies share by design (`kind` shared).
fn check_out_dir(out: &Path, kind: Option<OutputKind<'_>>) -> Result<Option<OutputLock>> {
    let fail = |why: String| {
        Error::invalid(
            "--out",
            out.display(),
            format!("a directory that can be created and written ({why})"),
        )
    };
    let mut existing = out;
    while !existing.as_os_str().is_empty() && !existing.exists() {
        // A path that is there but leads nowhere: a dangling symbolic link, or a loop. A
        // directory another process (a concurrent shard) created since `exists` is not
        // one: it is passed over as a missing ancestor would be.
        let symlink = std::fs::symlink_metadata(existing).is_ok_and(|m| m.file_type().is_symlink());
        if symlink && !existing.exists() {
            return Err(fail(format!(
                "{} is a symbolic link that leads to no file or directory (dangling, or a loop): remove it, point it at a directory, or give another --out",
                existing.display()
            )));
        }
        existing = existing.parent().unwrap_or(Path::new(""));
    }
    let existing = if existing.as_os_str().is_empty() {
        Path::new(".")
    } else {
        existing
    };
    if !existing.is_dir() {
        return Err(fail(format!("{} is not a directory", existing.display())));
    }
    if let Some(kind) = kind {
        refuse_occupied(out, kind)?;
    }
    let probe = existing.join(format!(".langevin-fem-write-test.{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| fail(format!("cannot write in {}: {e}", existing.display())))?;
    if out.is_dir() {
        let removed = langevin_fem::output::remove_stale_temporaries(out);
        if removed > 0 {
            eprintln!(
                "removed {removed} temporary file(s) left in {} by interrupted runs",
                out.display()
            );
        }
    }
    std::fs::remove_file(&probe).map_err(|e| {
        fail(format!(
            "cannot remove a file in {}: {e}",
            existing.display()
        ))
    })?;
    let shared = matches!(kind, Some(OutputKind::Report { shared: true, .. }));
    (!shared)
        .then(|| OutputLock::acquire("--out", out))
        .transpose()
}

/// The caps on a command's projected work and memory (`--max-work`,
/// `--max-memory-gib`), flattened into every command that simulates. The projection is
/// made from the input alone, before anything runs; above a cap the command exits 2 with
/// the projected figures and the flags or keys that drive them.
#[derive(Debug, Args)]
pub struct LimitArgs {
    /// Cap on the projected total work, in DOF-steps (time steps of every trajectory
    /// times the unknowns each updates; about 5e7 per second on 2 cores): the command is
    /// refused (exit 2) above it, before anything runs. Raise it deliberately to run a
    /// larger job.
    #[arg(long, value_name = "DOF_STEPS", default_value = "5e13", allow_negative_numbers = true, value_parser = parse_max_work)]
    max_work: f64,
    /// Cap on the samples held in memory at once, in GiB (8 bytes a sample): the command
    /// is refused (exit 2) above it, before anything is allocated. Raise it deliberately
    /// on a larger machine.
    #[arg(long, value_name = "GIB", default_value = "4", allow_negative_numbers = true, value_parser = parse_max_memory_gib)]
    max_memory_gib: f64,
}

impl LimitArgs {
    /// The caps.
    pub fn limits(&self) -> WorkLimits {
        WorkLimits {
            max_work: self.max_work,
            max_memory_gib: self.max_memory_gib,
        }
    }
}

/// `--max-work`: a number in [1, 1e30] (clap adds the flag to the message).
fn parse_max_work(text: &str) -> std::result::Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if (1.0..=1e30).contains(&v) => Ok(v),
        _ => Err("must be a number of DOF-steps in [1, 1e30], such as 1e14".to_string()),
    }
}

/// `gib` GiB in bytes (saturating).
fn gib_bytes(gib: f64) -> u64 {
    (gib * (1u64 << 30) as f64).min(u64::MAX as f64) as u64
}

/// `--max-memory-gib` (and `run --max-output-gib`): a number in (0, 1e6] (clap adds the
/// flag to the message).
fn parse_max_memory_gib(text: &str) -> std::result::Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1e6 => Ok(v),
        _ => Err("must be a number of GiB in (0, 1e6], such as 16".to_string()),
    }
}

/// A whole-number flag in `[LO, HI]`, as clap's value parser: any integer text is read
/// (a negative one, or one beyond `u64`) so that the message names the flag (clap adds
/// it), the value and the range, e.g. "invalid value '-3' for '--trajectories <N>': must
/// be an integer in [2, 1024]".
fn count_in<const LO: u64, const HI: u64>(text: &str) -> std::result::Result<u64, String> {
    let fmt = |v: u64| {
        // 100000000 reads better as 1e8.
        let exponent = v.checked_ilog10().unwrap_or(0);
        if v >= 1_000_000 && 10u64.pow(exponent) == v {
            format!("1e{exponent}")
        } else {
            v.to_string()
        }
    };
    let allowed = format!("must be an integer in [{}, {}]", fmt(LO), fmt(HI));
    match text.trim().parse::<i128>() {
        Ok(v) if v >= i128::from(LO) && v <= i128::from(HI) => Ok(v as u64),
        _ => Err(allowed),
    }
}

/// [`count_in`] for a `usize` flag.
fn usize_in<const LO: u64, const HI: u64>(text: &str) -> std::result::Result<usize, String> {
    count_in::<LO, HI>(text).and_then(|v| usize::try_from(v).map_err(|e| e.to_string()))
}

/// Parses a comma-separated list for `flag`; a bad item exits with code 2 naming the
/// flag, the item and `allowed`, and so does an item equal to an earlier one (a list of
/// study points or schemes: a repeat would compute and report one cell twice).
fn parse_list<T: FromStr + PartialEq>(flag: &str, text: &str, allowed: &str) -> Result<Vec<T>> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    let values = items
        .iter()
        .map(|s| s.parse::<T>().map_err(|_| Error::invalid(flag, s, allowed)))
        .collect::<Result<Vec<T>>>()?;
    refuse_repeated(flag, &values, &items, allowed)?;
    Ok(values)
}

/// Exit 2 naming `flag` and the item (as typed, `texts[i]`) if `values[i]` equals an
/// earlier value: the items of a list flag must be distinct.
fn refuse_repeated<T: PartialEq>(
    flag: &str,
    values: &[T],
    texts: &[&str],
    allowed: &str,
) -> Result<()> {
    match (1..values.len()).find(|&i| values[..i].contains(&values[i])) {
        Some(i) => Err(Error::invalid(
            flag,
            texts[i],
            format!("{allowed}, distinct (this one is repeated)"),
        )),
        None => Ok(()),
    }
}

/// [`parse_list`] of `text` if the flag was given, else `default`.
fn parse_list_or<T: FromStr + Clone + PartialEq>(
    flag: &str,
    text: Option<&str>,
    default: &[T],
    allowed: &str,
) -> Result<Vec<T>> {
    text.map_or_else(|| Ok(default.to_vec()), |t| parse_list(flag, t, allowed))
}

/// The end of a study command: rebuilds the convergence report's index in `out` and
/// prints the files the study wrote there and its wall time.
///
/// # Errors
/// As [`langevin_fem::report::write_convergence_index`].
fn study_written(out: &std::path::Path, files: &[String], wall_seconds: f64) -> Result<()> {
    langevin_fem::report::write_convergence_index(out)?;
    println!(
        "wrote {} in {} ({wall_seconds:.1} s)",
        files.join(", "),
        out.display()
    );
    Ok(())
}

/// The seed and thread count of a command that simulates (`--seed`, `--threads`),
/// flattened into each: `verify`, `converge`, `stability`, `work-precision`.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// Master seed, instead of the seed of every scene the command runs (any integer in
    /// [0, 18446744073709551615]); the reports note the seed used.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = count_in::<0, { u64::MAX }>)]
    seed: Option<u64>,
    /// Worker threads of the parallel ensembles (1 to 256; default: rayon's, the number
    /// of CPUs or RAYON_NUM_THREADS). Results are bit-identical whatever the count.
    #[arg(short = 'j', long, value_name = "N", allow_negative_numbers = true, value_parser = usize_in::<1, 256>)]
    threads: Option<usize>,
}

impl SimArgs {
    /// Sizes rayon's global pool if `--threads` was given; called before anything runs.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--threads` if the pool cannot be built.
    pub fn start(&self) -> Result<()> {
        let Some(n) = self.threads else {
            return Ok(());
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| {
                Error::invalid(
                    "--threads",
                    n,
                    format!("a thread count the system can start ({e})"),
                )
            })
    }

    /// Replaces the scene's seed with `--seed` if given; returns the note on the seed
    /// used, for the reports: `seed N (--seed; the scene's own seed is M)` or
    /// `seed N (the scene's own)`.
    pub fn apply(&self, scene: &mut Scene) -> String {
        let own = scene.seed;
        match self.seed {
            Some(seed) => {
                scene.seed = seed;
                format!("seed {seed} (--seed; the scene's own seed is {own})")
            }
            None => format!("seed {own} (the scene's own)"),
        }
    }
}
