//! `langevin-fem power` (built with `--features faults` only): the detection rate of
//! every catalogued simulator fault over seeds, per scene and size
//! ([`langevin_fem::fault::run_power`]).

use super::Verbosity;
use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::fault::{FaultKind, PowerOptions, run_power};
use std::path::PathBuf;

/// The examples of `power --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem power                                   every fault, 20 seeds (about 25 min)
  langevin-fem power --fault noise-variance --seeds 5 -o out

Progress and per-size rows go to stderr, the smallest detected sizes to stdout.";

/// Command-line arguments of `langevin-fem power`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct PowerArgs {
    /// Fault to measure (repeatable; default: the whole catalogue): noise-variance,
    /// noise-time-scaling, integrator-stiffness, integrator-drag, correlated-noise,
    /// integrator-hinge, component-noise-sharing, von-karman-strain,
    /// axial-stretch-rigidity, proposal-force, shared-stiffness or shared-hinge.
    #[arg(long = "fault", value_name = "NAME")]
    faults: Vec<String>,
    /// Target scene to measure (repeatable; default: every target scene of each fault):
    /// a built-in scene that is a target of a measured fault, e.g. membrane-hinged.
    #[arg(long = "scene", value_name = "NAME")]
    scenes: Vec<String>,
    /// Seeds per fault, scene and size (the same fixed seeds 16000, 16001, ... for all).
    #[arg(long, default_value_t = 20, allow_negative_numbers = true, value_parser = super::count_in::<1, 100_000>)]
    seeds: u64,
    /// Statistics budget of every verification.
    #[arg(short, long, value_enum, default_value = "quick")]
    budget: super::verify::BudgetArg,
    /// Family-wise significance level per scene (Holm), as `verify --alpha`.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
    /// Output directory for power.csv, power.json and power.md.
    #[arg(short, long, default_value = "reports/power")]
    pub(super) out: PathBuf,
    /// Measure each fault at its stated size only instead of the size ladder, e.g. to
    /// compare budgets by the checks failed per seed.
    #[arg(long)]
    stated_size: bool,
}

/// Runs the power study; exit code 0 once the tables are written (a measurement: the
/// tables say which stated sizes were detected in at least 95 % of seeds).
pub fn run(args: PowerArgs, verbosity: Verbosity) -> Result<i32> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha < 0.5) {
        return Err(Error::invalid("--alpha", args.alpha, "in (0, 0.5)"));
    }
    let faults = if args.faults.is_empty() {
        FaultKind::ALL.to_vec()
    } else {
        args.faults
            .iter()
            .map(|f| f.parse::<FaultKind>())
            .collect::<Result<Vec<_>>>()?
    };
    if let Some(s) = args.scenes.iter().find(|s| {
        !faults.iter().any(|k| {
            langevin_fem::fault::targets(*k)
                .iter()
                .any(|t| t.scene == s.as_str())
        })
    }) {
        let mut names: Vec<&str> = faults
            .iter()
            .flat_map(|k| langevin_fem::fault::targets(*k))
            .map(|t| t.scene)
            .collect();
        names.sort_unstable();
        names.dedup();
        return Err(Error::invalid(
            "--scene",
            s,
            format!(
                "a target scene of the measured faults: {}",
                names.join(", ")
            ),
        ));
    }
    let report = run_power(&PowerOptions {
        faults,
        scenes: args.scenes.clone(),
        seeds: args.seeds,
        budget: args.budget.budget(),
        alpha: args.alpha,
        out: args.out.clone(),
        progress: verbosity.shows_progress(),
        stated_only: args.stated_size,
    })?;
    for m in &report.smallest_detected {
        println!(
            "{:<24} {:<20} smallest detected size {:<18} stated {} {}",
            m.fault,
            m.scene,
            m.size.map_or("none".to_string(), |s| s.to_string()),
            m.stated_size,
            if m.stated_detected {
                "detected"
            } else {
                "NOT detected in 95 % of seeds"
            }
        );
    }
    println!(
        "power: {:.0} s; tables: {}",
        report.wall_seconds,
        args.out.join("power.md").display()
    );
    Ok(0)
}
