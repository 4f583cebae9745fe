//! `langevin-fem fit`: the bending rigidity and the drag (and, with EI known, the noise
//! temperature) that a filament's data imply, with 95 % intervals
//! ([`langevin_fem::verify::fit`]), from the checks `check` applies to the same data.

use super::Verbosity;
use super::check::{CheckArgs, evaluate, load_data, print_verdict};
use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::report::write_report;
use langevin_fem::verify::fit::{RunFit, estimate_text, fit_runs};
use serde::Serialize;
use std::time::Instant;

/// The examples of `fit --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem run -s hinged-linear-2d --run crank-nicolson -o traj
  langevin-fem fit -s hinged-linear-2d -d traj -o traj-fit

Prints per run EI (from the mode variances, kT known), xi (from the decay rates with that
EI) and kT (with EI known instead), each with its 95 % interval; writes them to fit.json in
the output directory, beside the report of `check` on the same data. Exit 0 when every run
gave a fit, 3 when a run's checks hold no mode variance to fit, 2 on bad input.";

/// Command-line arguments of `langevin-fem fit`: those of `check`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct FitArgs {
    #[command(flatten)]
    pub(super) check: CheckArgs,
}

/// What `fit.json` holds.
#[derive(Serialize)]
struct FitFile<'a> {
    scene: &'a str,
    data: String,
    level: f64,
    runs: &'a [RunFit],
}

/// Runs the checks of `check`, then the fit of every run; prints the fits after the
/// scene lines.
pub fn run(args: FitArgs, verbosity: Verbosity) -> Result<i32> {
    let start = Instant::now();
    let args = args.check;
    let sidecar = load_data(&args)?;
    let Some(filament) = &sidecar.filament else {
        return Err(Error::invalid(
            "--data",
            args.data.display(),
            "filament data (a `filament` table in data.json): fit estimates EI and xi of a filament",
        ));
    };
    let (scene, mut summary, report) = evaluate(&args, &sidecar, verbosity.progress())?;
    if scene.compression.is_some() {
        return Err(Error::invalid(
            "--scene",
            &scene.name,
            "a linear scene (mode variances and decay rates): a compression scene's force data do not fit EI this way",
        ));
    }
    let fits = fit_runs(&summary.scenes[0], filament);
    let mut lines = Vec::new();
    for f in &fits {
        let (Some(v), Some(ei), Some(kt)) = (
            &f.variance,
            &f.bending_rigidity,
            &f.kt_given_bending_rigidity,
        ) else {
            return Err(Error::run_failed(
                format!("data run {}", f.run),
                "fit",
                Error::invalid(
                    "mode-variance checks",
                    0,
                    "at least one (the scene's checks must include mode-variance)",
                ),
            ));
        };
        let mut parts = vec![estimate_text("EI", ei, v, "variances", "kT known")];
        if let (Some(r), Some(xi)) = (&f.rate, &f.drag) {
            parts.push(estimate_text("xi", xi, r, "decay rates", "with that EI"));
        }
        parts.push(estimate_text("kT", kt, v, "variances", "EI known instead"));
        summary.scenes[0].notes.push(format!(
            "fit, run {} (95 % intervals): {}",
            f.run,
            parts.join("; ")
        ));
        lines.push(format!("fit {} (95 % intervals):", f.run));
        lines.extend(parts.iter().map(|p| format!("    {p}")));
    }
    report.write_json(
        &args.out.join("fit.json"),
        &FitFile {
            scene: &scene.name,
            data: args.data.display().to_string(),
            level: langevin_fem::verify::fit::LEVEL,
            runs: &fits,
        },
    )?;
    write_report(report, &summary)?;
    print_verdict(&args, &summary, verbosity, start, &lines);
    Ok(0)
}
