//! `langevin-fem converge`: convergence study of a linear scene over the element count or
//! the time step, with fitted orders against the expected ones.

use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::verify::converge::{ConvergeOptions, Over, run_convergence};
use langevin_fem::verify::{Budget, Scene, resolve_scenes};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ConvergeArgs {
    /// Scene: a name from the scene directory or a path to a .toml file (linear fem
    /// scenes only, e.g. hinged-linear-2d, hinged-linear-3d).
    #[arg(long, value_name = "NAME|PATH")]
    scene: String,
    /// What is refined: the element count or the time step dt/tau1.
    #[arg(long, value_enum)]
    over: OverArg,
    /// Comma-separated values (element counts, or dt/tau1); default 5,10,20,40 elements,
    /// or dt/tau1 4e-3,2e-3,1e-3,5e-4 (euler-maruyama: 0.9,0.5,0.25,0.125 of its
    /// stability limit).
    #[arg(long, value_name = "V1,V2,...")]
    values: Option<String>,
    /// Run of the scene (default: its first run).
    #[arg(long)]
    run: Option<String>,
    /// Ensemble budget of the run (trajectories and duration per value).
    #[arg(long, value_enum, default_value = "quick")]
    budget: BudgetArg,
    /// Output directory.
    #[arg(long, default_value = "reports/convergence")]
    out: PathBuf,
    /// Directory holding the scene files.
    #[arg(long, default_value = "verification")]
    scene_dir: PathBuf,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum OverArg {
    Elements,
    Dt,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum BudgetArg {
    Quick,
    Standard,
    Full,
}

fn parse_values(text: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|s| {
            s.trim().parse::<f64>().map_err(|_| {
                Error::invalid("--values", s.trim(), "a comma-separated list of numbers")
            })
        })
        .collect()
}

/// Runs the study and prints a summary of the fitted orders on stderr; exit code 0.
pub fn run(args: ConvergeArgs) -> Result<i32> {
    let over = match args.over {
        OverArg::Elements => Over::Elements,
        OverArg::Dt => Over::Dt,
    };
    let budget = match args.budget {
        BudgetArg::Quick => Budget::Quick,
        BudgetArg::Standard => Budget::Standard,
        BudgetArg::Full => Budget::Full,
    };
    let values = args.values.as_deref().map(parse_values).transpose()?;
    let path = resolve_scenes(std::slice::from_ref(&args.scene), &args.scene_dir)?
        .into_iter()
        .next()
        .ok_or_else(|| Error::invalid("--scene", &args.scene, "a scene name or .toml path"))?;
    let scene = Scene::load(&path)?;
    let s = run_convergence(&ConvergeOptions {
        scene,
        run: args.run,
        over,
        values,
        budget,
        out: args.out.clone(),
        progress: true,
    })?;
    eprintln!(
        "{} / {} ({} with {} noise), over {} (h = {}), {}; errors against the {}",
        s.scene,
        s.run,
        s.integrator,
        s.noise,
        s.over.name(),
        s.h,
        s.fixed,
        s.limit_reference
    );
    for o in &s.observables {
        let fmt = |f: &Option<langevin_fem::verify::converge::OrderFit>| match f {
            None => "no fit (fewer than 2 points)".to_string(),
            Some(f) => match f.ci {
                Some((lo, hi)) => {
                    format!("{:.2} [{lo:.2}, {hi:.2}] ({} points)", f.order, f.points)
                }
                None => format!("{:.2} (2 points, no CI)", f.order),
            },
        };
        let expected = match (o.expected.order, o.expected.exact) {
            (Some(p), _) => format!("{p}"),
            (None, true) => "exact (zero error)".to_string(),
            (None, false) => "no single order".to_string(),
        };
        eprintln!(
            "  {:<8} observed {}; exact-error order {}; expected {}; sampling floor at {:?}",
            o.observable,
            fmt(&o.observed),
            if o.exact.is_none() && !o.exact_at_rounding.is_empty() {
                format!("- (exact at {:?})", o.exact_at_rounding)
            } else {
                fmt(&o.exact)
            },
            expected,
            o.floor_values
        );
        if !o.note.is_empty() {
            eprintln!("           {}", o.note);
        }
        eprintln!("           expected: {}", o.expected.why);
    }
    eprintln!(
        "wrote {} in {} ({:.1} s)",
        s.files.join(", "),
        args.out.display(),
        s.wall_seconds
    );
    Ok(0)
}
