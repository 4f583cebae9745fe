//! `langevin-fem converge`: convergence study of a finite-element scene (linear or
//! compression) over the element count or the time step, with fitted orders against the
//! expected ones.

use super::verify::BudgetArg;
use super::{Verbosity, parse_list, usize_in};
use clap::Args;
use langevin_fem::dynamics::IntegratorKind;
use langevin_fem::error::{Error, Result};
use langevin_fem::report::write_convergence_index;
use langevin_fem::scene::load_scene;
use langevin_fem::shard::{Shard, ShardSet};
use langevin_fem::studies::converge::shard::{ConvergeSettings, write_convergence_shard};
use langevin_fem::studies::converge::{
    ConvergeOptions, ConvergeSummary, ObservableSummary, OrderFit, Over, run_convergence,
    select_run,
};
use langevin_fem::studies::coupled_dt::{self, CoupledDtOptions, run_coupled_dt};
use langevin_fem::work::WorkLimits;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The examples of `converge --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem converge -s hinged-linear-2d --over elements
  langevin-fem converge -s hinged-linear-2d --over dt --run crank-nicolson -b standard
  langevin-fem converge -s compression-2d --over elements --values 5,10,20 --strain-ratios 0 \\
      --trajectories 16 --duration-tau1 200 -o reports/convergence
  langevin-fem converge -s my-membrane.toml --over elements --values 4,8,12,16
  langevin-fem converge -s fig2-paper-2d --over dt --coupled   the paper's scheme's order
  langevin-fem converge -s hinged-linear-2d --over dt --shard 1/2 -o cv/1   (and 2/2), then:
  langevin-fem merge cv/1 cv/2 -o reports/convergence

The fitted orders go to stdout, progress to stderr; the exit code is 3 if every value failed.";

/// Command-line arguments of `langevin-fem converge`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct ConvergeArgs {
    /// Scene: a built-in scene's name (finite-element scenes: hinged-linear-2d,
    /// hinged-linear-3d, compression-2d, compression-3d, ...; see `langevin-fem list`), a
    /// name in --scene-dir, or a path to a .toml file (also a membrane with model = "fem").
    #[arg(short, long, value_name = "NAME|PATH")]
    scene: String,
    /// What is refined: the element count or the time step dt/tau1.
    #[arg(long, value_enum)]
    over: OverArg,
    /// Comma-separated values (element counts, or dt/tau1); default 5,10,20,40 elements
    /// (a membrane: 4,8,16 along x, at most 24 a side, the y count at the scene's aspect
    /// ratio of elements), or dt/tau1 4e-3,2e-3,1e-3,5e-4 (euler-maruyama:
    /// 0.9,0.5,0.25,0.125 of its stability limit; compression with
    /// metropolis-crank-nicolson: 0.04,0.02,0.01,0.005).
    #[arg(long, value_name = "V1,V2,...", allow_hyphen_values = true)]
    values: Option<String>,
    /// Run of the scene (default: its first run).
    #[arg(long)]
    run: Option<String>,
    /// Replace the run's integrator (its noise, time step and ensembles are kept), e.g.
    /// crank-nicolson on a compression scene to measure the time-step bias of the
    /// explicit stretching force.
    #[arg(long, value_name = "NAME")]
    integrator: Option<String>,
    /// Compression scenes: comma-separated strains eps/eps_c0 whose <F> is studied
    /// (default 0,1,3,10).
    #[arg(long, value_name = "R1,R2,...", allow_hyphen_values = true)]
    strain_ratios: Option<String>,
    /// Ensemble budget of the run (trajectories and duration per value).
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: BudgetArg,
    /// Trajectories per value, instead of the budget's (1 to 100000).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = usize_in::<1, 100_000>)]
    trajectories: Option<usize>,
    /// Sampled duration per trajectory (tau1), instead of the budget's.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    duration_tau1: Option<f64>,
    /// Output directory.
    #[arg(short, long, default_value = "reports/convergence")]
    pub(super) out: PathBuf,
    /// Directory of scene files: --scene names resolve there instead of among the
    /// built-in scenes.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Simulate only shard I of N of every value's trajectories and write their records
    /// and a manifest to --out, without the study's tables; `langevin-fem merge` then
    /// writes the whole study, byte for byte (see the guide, docs/src/tutorials/cluster.md).
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// With --over dt on a compression scene (a θ-scheme: euler-maruyama, crank-nicolson):
    /// the differences of <F> between each step and its half, from pairs of trajectories
    /// driven by the same Brownian path, and the order of the time-step error with its
    /// 95 % interval. --values are the steps, each half the previous (default 0.5, 0.25,
    /// 0.125, 0.0625 of the explicit stability limit for euler-maruyama, else
    /// 4e-3,2e-3,1e-3,5e-4); --trajectories the pairs per step and strain (default 16);
    /// --duration-tau1 each pair's sampled time (default 0.05); --strain-ratios default
    /// 0,2,6; a --budget other than quick is refused (size it with those two flags).
    #[arg(long)]
    coupled: bool,
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    pub(super) sim: super::SimArgs,
}

impl ConvergeArgs {
    /// Whether `--shard` was given (the output is then a shard, not a report).
    pub(super) fn is_shard(&self) -> bool {
        self.shard.is_some()
    }
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum OverArg {
    Elements,
    Dt,
}

/// Runs the study (progress on stderr unless quiet), prints a summary of the fitted
/// orders on stdout and rebuilds the index page of the output directory; exit code 0,
/// or 3 if every value failed (diverged or too short for its correlation time).
pub fn run(args: ConvergeArgs, verbosity: Verbosity) -> Result<i32> {
    if args.coupled {
        return run_coupled(args, verbosity);
    }
    let out = args.out.clone();
    let shard = args.shard;
    let (opts, seed_note) = options(args, verbosity)?;
    if let Some(shard) = shard {
        let m = write_convergence_shard(&opts, shard, &seed_note)?;
        println!(
            "shard {shard}: {} record file(s) in {}; when every shard of {} is done: langevin-fem merge <the {} shard directories> -o <study dir>",
            m.files.len(),
            out.display(),
            shard.count,
            shard.count
        );
        return Ok(0);
    }
    finish(&run_convergence(&opts)?, &out)
}

/// `converge --coupled`: the coupled time-step study ([`coupled_dt`]); its orders on
/// stdout, exit code 0.
fn run_coupled(args: ConvergeArgs, verbosity: Verbosity) -> Result<i32> {
    let out = args.out.clone();
    let (opts, seed_note) = coupled_options(args, verbosity)?;
    let s = run_coupled_dt(&opts)?;
    write_convergence_index(&out)?;
    print_coupled(&s, &seed_note, &out);
    Ok(0)
}

/// The options of `converge --coupled` from its flags, and the note on the seed.
///
/// # Errors
/// Exit 2 for flags the coupled study does not take (`--over elements`, `--shard`, a
/// `--budget` other than quick) or that do not parse, and for a scene or run refused.
fn coupled_options(args: ConvergeArgs, verbosity: Verbosity) -> Result<(CoupledDtOptions, String)> {
    if !matches!(args.over, OverArg::Dt) {
        return Err(Error::invalid(
            "--over",
            "elements",
            "dt with --coupled (the pairs couple a time step and its half)",
        ));
    }
    if let Some(s) = args.shard {
        return Err(Error::invalid(
            "--shard",
            s,
            "no shard with --coupled (its pairs run on one machine)",
        ));
    }
    if !matches!(args.budget, BudgetArg::Quick) {
        return Err(Error::invalid(
            "--budget",
            args.budget.budget().name(),
            format!(
                "quick (the default) with --coupled: the coupled study is sized by --trajectories \
                 (pairs per step and strain, default {}) and --duration-tau1 (default {})",
                coupled_dt::DEFAULT_TRAJECTORIES,
                coupled_dt::DEFAULT_DURATION_TAU1
            ),
        ));
    }
    let mut scene = load_scene(&args.scene, args.scene_dir.as_deref())?;
    let seed_note = args.sim.apply(&mut scene);
    let run = select_run(&scene, args.run.as_deref())?;
    if let Some(k) = args
        .integrator
        .as_deref()
        .map(parse_integrator)
        .transpose()?
    {
        scene.runs[run].integrator = k;
    }
    let dt_tau1 = match args.values.as_deref() {
        Some(t) => parse_list("--values", t, "a comma-separated list of numbers")?,
        None => coupled_dt::default_steps(&scene, run)?,
    };
    let strain_ratios = match args.strain_ratios.as_deref() {
        Some(t) => parse_list("--strain-ratios", t, "a comma-separated list of numbers")?,
        None => coupled_dt::DEFAULT_STRAIN_RATIOS.to_vec(),
    };
    let opts = CoupledDtOptions {
        scene,
        run,
        dt_tau1,
        strain_ratios,
        trajectories: args
            .trajectories
            .unwrap_or(coupled_dt::DEFAULT_TRAJECTORIES),
        duration_tau1: args
            .duration_tau1
            .unwrap_or(coupled_dt::DEFAULT_DURATION_TAU1),
        out: args.out.clone(),
        progress: verbosity.shows_progress(),
        limits: args.limits.limits(),
    };
    Ok((opts, seed_note))
}

/// Prints the coupled study `s` (written to `out`): per strain the differences and the
/// observed order with its interval, then the files written.
fn print_coupled(s: &coupled_dt::CoupledDtSummary, seed_note: &str, out: &Path) {
    println!(
        "{} / {} ({} with {} noise, {seed_note}): <F>_dt - <F>_dt/2 from {} coupled pairs x {} tau1 per step and strain",
        s.scene, s.run, s.integrator, s.noise, s.trajectories, s.duration_tau1
    );
    for o in &s.orders {
        let diffs: Vec<String> = s
            .points
            .iter()
            .filter(|p| p.strain_ratio == o.strain_ratio)
            .map(|p| {
                format!(
                    "{:.3e}: {:+.3e} +- {:.1e} (predicted {:+.3e})",
                    p.dt_tau1, p.difference, p.std_error, p.predicted
                )
            })
            .collect();
        println!(
            "  eps/eps_c0 = {}: D at dt/tau1 {}",
            o.strain_ratio,
            diffs.join("; ")
        );
        match o.ci {
            Some((lo, hi)) => println!(
                "           observed order {:.2} [{lo:.2}, {hi:.2}] (fit p = {:.2}); predicted {}; expected {} as dt -> 0",
                o.order,
                o.fit_p_value,
                if o.predicted_order.is_finite() {
                    format!("{:.2}", o.predicted_order)
                } else {
                    "- (no prediction, or a predicted difference of 0)".to_string()
                },
                o.expected
            ),
            None => println!("           {}", o.note),
        }
    }
    println!(
        "wrote {} in {} ({:.1} CPU-s, {:.1} s)",
        s.files.join(", "),
        out.display(),
        s.cpu_seconds,
        s.wall_seconds
    );
}

/// `merge` of a study's shards into `out`: the whole study's output set and index.
///
/// # Errors
/// Exit 2 for settings that do not parse; as `converge` otherwise.
pub fn merge(set: ShardSet, out: &Path, verbosity: Verbosity) -> Result<i32> {
    let settings = ConvergeSettings::of_set(&set)?;
    let (mut scenes, _) = set.scenes()?.into_iter().unzip::<_, _, Vec<_>, Vec<_>>();
    let scene = scenes.pop().ok_or_else(|| {
        Error::invalid("merge DIR", "a converge shard without a scene", "one scene")
    })?;
    let mut opts = ConvergeOptions {
        scene,
        run: None,
        over: settings.over,
        values: None,
        integrator: None,
        strain_ratios: None,
        budget: settings.budget,
        trajectories: None,
        duration_tau1: None,
        out: out.to_path_buf(),
        progress: verbosity.shows_progress(),
        limits: WorkLimits::default(),
        merge: Some(Arc::new(set)),
    };
    settings.apply(&mut opts).map_err(|e| match e {
        Error::InvalidParameter {
            name,
            value,
            allowed,
        } => set_of(&opts).refuse("settings", format!("{name} must be {allowed}, got {value}")),
        other => other,
    })?;
    let summary = run_convergence(&opts).map_err(|e| set_of(&opts).settings_error(e))?;
    finish(&summary, out)
}

/// The shard set a merge's options read.
fn set_of(opts: &ConvergeOptions) -> &ShardSet {
    opts.merge
        .as_deref()
        .expect("a merge's options hold its shard set")
}

/// Writes the index of `out`, prints the study; exit code 3 if every value failed.
fn finish(s: &ConvergeSummary, out: &Path) -> Result<i32> {
    write_convergence_index(out)?;
    print_summary(s, out);
    // Every value failed: nothing was measured (exit 3, as for a failed run).
    if s.rows.is_empty() && !s.failed.is_empty() {
        eprintln!("error: every value of the study failed (see above); no rows were written");
        return Ok(3);
    }
    Ok(0)
}

/// The study's options from the command line (the scene resolved last, after the
/// flags are parsed).
fn options(args: ConvergeArgs, verbosity: Verbosity) -> Result<(ConvergeOptions, String)> {
    let over = match args.over {
        OverArg::Elements => Over::Elements,
        OverArg::Dt => Over::Dt,
    };
    let budget = args.budget.budget();
    let values = args
        .values
        .as_deref()
        .map(|t| parse_list("--values", t, "a comma-separated list of numbers"))
        .transpose()?;
    let strain_ratios = args
        .strain_ratios
        .as_deref()
        .map(|t| parse_list("--strain-ratios", t, "a comma-separated list of numbers"))
        .transpose()?;
    let integrator = args
        .integrator
        .as_deref()
        .map(parse_integrator)
        .transpose()?;
    let mut scene = load_scene(&args.scene, args.scene_dir.as_deref())?;
    let seed_note = args.sim.apply(&mut scene);
    let opts = ConvergeOptions {
        scene,
        run: args.run,
        over,
        values,
        integrator,
        strain_ratios,
        budget,
        trajectories: args.trajectories,
        duration_tau1: args.duration_tau1,
        out: args.out,
        progress: verbosity.shows_progress(),
        limits: args.limits.limits(),
        merge: None,
    };
    Ok((opts, seed_note))
}

/// The integrator named by `--integrator`.
fn parse_integrator(name: &str) -> Result<IntegratorKind> {
    IntegratorKind::ALL
        .into_iter()
        .find(|k| k.name() == name.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
            Error::invalid(
                "--integrator",
                name.trim(),
                format!("one of: {}", names.join(", ")),
            )
        })
}

/// A fitted order with its interval, for the terminal.
fn fmt_fit(f: &Option<OrderFit>) -> String {
    match f {
        None => "no fit (fewer than 2 points)".to_string(),
        Some(f) => match f.ci {
            Some((lo, hi)) => {
                format!("{:.2} [{lo:.2}, {hi:.2}] ({} points)", f.order, f.points)
            }
            None => format!("{:.2} (2 points, no CI)", f.order),
        },
    }
}

/// One observable's fitted orders, expected order, note and reason on stdout.
fn print_observable(o: &ObservableSummary) {
    let expected = match (o.expected.order, o.expected.exact) {
        (Some(p), _) => format!("{p}"),
        (None, true) => "exact (zero error)".to_string(),
        (None, false) => "no single order".to_string(),
    };
    println!(
        "  {:<8} observed {}; exact-error order {}; expected {}; sampling floor at {:?}",
        o.observable,
        if o.unsampled {
            "- (exact observable, no sampling)".to_string()
        } else {
            fmt_fit(&o.observed)
        },
        if o.exact.is_none() && !o.exact_at_rounding.is_empty() {
            format!("- (exact at {:?})", o.exact_at_rounding)
        } else {
            fmt_fit(&o.exact)
        },
        expected,
        o.floor_values
    );
    if !o.note.is_empty() {
        println!("           {}", o.note);
    }
    println!("           expected: {}", o.expected.why);
}

/// The study's summary on stdout (warnings on stderr): what was refined, the
/// observables, the consistency with the exact discrete references, the failed values,
/// notes and files.
fn print_summary(s: &ConvergeSummary, out: &Path) {
    println!(
        "{} / {} ({} with {} noise, seed {}), over {} (h = {}), {}; errors against the {}",
        s.scene,
        s.run,
        s.integrator,
        s.noise,
        s.seed,
        s.over.name(),
        s.h,
        s.fixed,
        s.limit_reference
    );
    for o in &s.observables {
        print_observable(o);
    }
    if let Some(c) = &s.discrete_consistency {
        println!(
            "  simulation vs exact discrete reference: largest |z| = {:.2} ({}) over {} rows, Bonferroni p = {:.3}; sum z^2 = {:.2}",
            c.max_abs_z, c.worst, c.rows, c.p_value, c.chi2
        );
    }
    for u in &s.failed {
        println!(
            "  FAILED ({}) at {}={}: {}",
            u.kind,
            s.over.name(),
            u.value,
            u.error
        );
    }
    for n in &s.notes {
        println!("  note: {n}");
    }
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "wrote {} in {} ({:.1} s)",
        s.files.join(", "),
        out.display(),
        s.wall_seconds
    );
}
