//! `langevin-fem verify`: run verification scenes and write reports.

use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::report::write_report;
use langevin_fem::scene::{Budget, load_scenes};
use langevin_fem::verify::{VerifyOptions, run_verification};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct VerifyArgs {
    /// Scene to run: a built-in scene's name (see `langevin-fem list`), a name in
    /// --scene-dir when given, or a path to a .toml file (repeatable; default: every
    /// built-in top-level scene, or every scene of --scene-dir).
    #[arg(long = "scene", value_name = "NAME|PATH")]
    scenes: Vec<String>,
    /// Statistics budget.
    #[arg(long, value_enum, default_value = "quick")]
    budget: BudgetArg,
    /// Output directory for summary.json, index.html and per-scene figures and tables.
    #[arg(long, default_value = "reports")]
    pub(super) out: PathBuf,
    /// Directory of scene files: names resolve there instead of among the built-in
    /// scenes, and without --scene every scene there runs.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Family-wise significance level per scene (Holm correction).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    pub(super) sim: super::SimArgs,
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

/// Runs the verification; exit code 0 if every check passes, 1 otherwise.
pub fn run(args: VerifyArgs) -> Result<i32> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha < 0.5) {
        return Err(Error::invalid("--alpha", args.alpha, "in (0, 0.5)"));
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
    let (mut summary, report) = run_verification(&VerifyOptions {
        scenes,
        budget,
        out: args.out.clone(),
        alpha: args.alpha,
        progress: std::io::stderr().is_terminal(),
        limits: args.limits.limits(),
    })?;
    for (scene, note) in summary.scenes.iter_mut().zip(seed_notes) {
        scene.notes.push(note);
    }
    write_report(report, &summary)?;
    for scene in &summary.scenes {
        let failed: Vec<&str> = scene
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name.as_str())
            .collect();
        eprintln!(
            "{:<24} {}  {} checks, {} failed, {:.1} s",
            scene.name,
            if scene.passed { "PASS" } else { "FAIL" },
            scene.checks.len(),
            failed.len(),
            scene.wall_seconds
        );
        for f in failed {
            eprintln!("    failed: {f}");
        }
        for w in &scene.warnings {
            eprintln!("    warning: {w}");
        }
        if let Some(seed) = scene.notes.last() {
            eprintln!("    {seed}");
        }
    }
    eprintln!(
        "{} (budget {}, family-wise alpha {} per scene, Holm); report: {} (run {})",
        if summary.passed { "PASSED" } else { "FAILED" },
        summary.budget,
        summary.alpha,
        args.out.join("index.html").display(),
        summary.run_id
    );
    Ok(if summary.passed { 0 } else { 1 })
}
