//! `langevin-fem work-precision`: error in ⟨w²(L/2)⟩ against wall time for every
//! integrator and noise model, with the projected cost of reaching a tolerance.

use super::{Verbosity, parse_list_or, usize_in};
use clap::Args;
use langevin_fem::dynamics::IntegratorKind;
use langevin_fem::error::{Error, Result};
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::scene::load_scene;
use langevin_fem::studies::work_precision::{
    DEFAULT_DT_TAU1, DEFAULT_EM_FRACTIONS, DEFAULT_METHODS, WorkPrecisionOptions,
    run_work_precision,
};
use std::path::PathBuf;

/// The examples of `work-precision --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem work-precision                              every method, default steps
  langevin-fem work-precision --methods crank-nicolson/consistent,exact-modal/consistent \\
      --dt-tau1 1e-2,1e-3 --duration-tau1 100 -o out
  langevin-fem work-precision --tolerance 0.001 -j 2

The cost table goes to stdout, progress to stderr.";

/// Command-line arguments of `langevin-fem work-precision`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct WorkPrecisionArgs {
    /// Linear finite-element scene (a built-in scene's name, a name in --scene-dir, or a
    /// .toml path): filament or membrane, mesh, seed, burn-in.
    #[arg(
        short,
        long,
        value_name = "NAME|PATH",
        default_value = "hinged-linear-2d"
    )]
    scene: String,
    /// Comma-separated methods INTEGRATOR/NOISE (default: euler-maruyama/element-uniform,
    /// euler-maruyama/consistent, backward-euler/consistent,
    /// crank-nicolson/element-uniform, crank-nicolson/consistent, exact-modal/consistent).
    #[arg(long, value_name = "I/N,...")]
    methods: Option<String>,
    /// Comma-separated dt/tau1 of the unconditionally stable integrators (default
    /// 1e-2,3e-3,1e-3,3e-4).
    #[arg(long, value_name = "D1,D2,...", allow_hyphen_values = true)]
    dt_tau1: Option<String>,
    /// Comma-separated fractions of the stability limit for euler-maruyama (default
    /// 0.9,0.45).
    #[arg(long, value_name = "F1,F2,...", allow_hyphen_values = true)]
    em_fractions: Option<String>,
    /// Trajectories per point (2 to 1024).
    #[arg(long, default_value_t = 8, allow_negative_numbers = true, value_parser = usize_in::<2, 1024>)]
    trajectories: usize,
    /// Sampled duration per trajectory, in units of tau1 (stable integrators).
    #[arg(
        long,
        value_name = "T",
        default_value_t = 400.0,
        allow_negative_numbers = true,
        alias = "duration"
    )]
    duration_tau1: f64,
    /// Sampled duration per trajectory of euler-maruyama, in units of tau1 (its step is
    /// bounded by the stability limit, about 1e5 steps per tau1 at 10 elements).
    #[arg(
        long,
        value_name = "T",
        default_value_t = 8.0,
        allow_negative_numbers = true,
        alias = "em-duration"
    )]
    em_duration_tau1: f64,
    /// Relative error whose projected cost is tabulated.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    tolerance: f64,
    /// Output directory.
    #[arg(short, long, default_value = "reports/convergence")]
    pub(super) out: PathBuf,
    /// Directory of scene files: --scene names resolve there instead of among the
    /// built-in scenes.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    #[command(flatten)]
    limits: super::LimitArgs,
    #[command(flatten)]
    pub(super) sim: super::SimArgs,
}

fn parse_method(text: &str) -> Result<(IntegratorKind, NoiseModel)> {
    let integrators: Vec<&str> = IntegratorKind::LINEAR.iter().map(|k| k.name()).collect();
    let allowed = format!(
        "INTEGRATOR/NOISE with INTEGRATOR one of {} and NOISE one of consistent, element-uniform",
        integrators.join(", ")
    );
    let (i, n) = text
        .trim()
        .split_once('/')
        .ok_or_else(|| Error::invalid("--methods", text.trim(), &allowed))?;
    let kind = IntegratorKind::LINEAR
        .into_iter()
        .find(|k| k.name() == i)
        .ok_or_else(|| Error::invalid("--methods", text.trim(), &allowed))?;
    let noise = [NoiseModel::Consistent, NoiseModel::ElementUniform]
        .into_iter()
        .find(|m| m.name() == n)
        .ok_or_else(|| Error::invalid("--methods", text.trim(), &allowed))?;
    Ok((kind, noise))
}

/// Runs the study (progress on stderr unless quiet) and prints the cost table on
/// stdout; exit code 0.
pub fn run(args: WorkPrecisionArgs, verbosity: Verbosity) -> Result<i32> {
    let methods = match &args.methods {
        None => DEFAULT_METHODS.to_vec(),
        Some(t) => t.split(',').map(parse_method).collect::<Result<_>>()?,
    };
    let dt_tau1 = parse_list_or(
        "--dt-tau1",
        args.dt_tau1.as_deref(),
        &DEFAULT_DT_TAU1,
        "comma-separated numbers in [1e-12, 1]",
    )?;
    let em_fractions = parse_list_or(
        "--em-fractions",
        args.em_fractions.as_deref(),
        &DEFAULT_EM_FRACTIONS,
        "comma-separated numbers in (0, 1)",
    )?;
    let mut scene = load_scene(&args.scene, args.scene_dir.as_deref())?;
    args.sim.apply(&mut scene);
    let s = run_work_precision(&WorkPrecisionOptions {
        scene,
        methods,
        dt_tau1,
        em_fractions,
        trajectories: args.trajectories,
        duration_tau1: args.duration_tau1,
        em_duration_tau1: args.em_duration_tau1,
        tolerance: args.tolerance,
        out: args.out.clone(),
        progress: verbosity.shows_progress(),
        limits: args.limits.limits(),
    })?;
    println!(
        "{} ({} elements, seed {}): <{}> continuum {:.6e}; {} trajectories x {} tau1 per point (euler-maruyama {} tau1), {} threads; sampling floor (median relative s.e.) {:.2e}",
        s.scene,
        s.elements,
        s.seed,
        s.observable,
        s.continuum,
        s.trajectories,
        s.duration_tau1,
        s.em_duration_tau1,
        s.threads,
        s.sampling_floor
    );
    println!(
        "projected wall time to a relative error of {} (95 %, bias + 2 s.e.):",
        s.tolerance
    );
    for m in &s.methods {
        match (m.seconds_to_tolerance, m.best_dt_tau1, m.relative_cost) {
            (Some(t), Some(dt), Some(r)) => println!(
                "  {:<16} {:<16} {t:>10.3e} s at dt/tau1 = {dt:.3e} ({r:.1}x the fastest)",
                m.integrator, m.noise
            ),
            _ => println!("  {:<16} {:<16} {}", m.integrator, m.noise, m.note),
        }
    }
    if s.inconsistent_points > 0 {
        eprintln!(
            "warning: {} points disagree with their exact discrete value by more than 3 s.e.",
            s.inconsistent_points
        );
    }
    langevin_fem::report::write_convergence_index(&args.out)?;
    println!(
        "wrote {} in {} ({:.1} s)",
        s.files.join(", "),
        args.out.display(),
        s.wall_seconds
    );
    Ok(0)
}
