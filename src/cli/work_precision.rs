//! `langevin-fem work-precision`: error in ⟨w²(L/2)⟩ against wall time for every
//! integrator and noise model, with the projected cost of reaching a tolerance; on a
//! compression scene, the schemes of Fig. 2 over Δt ([`langevin_fem::studies::fig2_schemes`]).

use super::{Verbosity, parse_list_or, usize_in};
use clap::Args;
use langevin_fem::dynamics::IntegratorKind;
use langevin_fem::error::{Error, Result};
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::scene::{ModelKind, Scene, load_scene};
use langevin_fem::studies::fig2_schemes::{
    self, Fig2SchemesOptions, Fig2SchemesSummary, run_fig2_schemes,
};
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
  langevin-fem work-precision --scene fig2-paper-2d        the three schemes of Fig. 2
  langevin-fem work-precision --scene fig2-paper-2d --strain-ratios 0,6 --duration-tau1 10

The cost table goes to stdout, progress to stderr.";

/// Command-line arguments of `langevin-fem work-precision`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct WorkPrecisionArgs {
    /// Linear finite-element scene (a built-in scene's name, a name in --scene-dir, or a
    /// .toml path): filament or membrane, mesh, seed, burn-in. A compression scene of a
    /// filament (e.g. fig2-paper-2d) runs the schemes of Fig. 2 instead: bias of <F>,
    /// projected CPU time to the figure, autocorrelation times of F and of the buckled
    /// mode.
    #[arg(
        short,
        long,
        value_name = "NAME|PATH",
        default_value = "hinged-linear-2d"
    )]
    scene: String,
    /// Comma-separated methods INTEGRATOR/NOISE (default: euler-maruyama/element-uniform,
    /// euler-maruyama/consistent, backward-euler/consistent,
    /// crank-nicolson/element-uniform, crank-nicolson/consistent, exact-modal/consistent;
    /// on a compression scene euler-maruyama/element-uniform, crank-nicolson/consistent,
    /// metropolis-crank-nicolson/consistent).
    #[arg(long, value_name = "I/N,...")]
    methods: Option<String>,
    /// Comma-separated dt/tau1 of the unconditionally stable integrators (default
    /// 1e-2,3e-3,1e-3,3e-4; on a compression scene 8e-2,2e-2,2e-3,5e-4,1e-4,7e-6).
    #[arg(long, value_name = "D1,D2,...", allow_hyphen_values = true)]
    dt_tau1: Option<String>,
    /// Comma-separated fractions of the stability limit for euler-maruyama (default
    /// 0.9,0.45; on a compression scene 0.9).
    #[arg(long, value_name = "F1,F2,...", allow_hyphen_values = true)]
    em_fractions: Option<String>,
    /// Trajectories per point (2 to 1024).
    #[arg(long, default_value_t = 8, allow_negative_numbers = true, value_parser = usize_in::<2, 1024>)]
    trajectories: usize,
    /// Sampled duration per trajectory, in units of tau1 (stable integrators; default 400;
    /// on a compression scene every method, default 40).
    #[arg(
        long,
        value_name = "T",
        allow_negative_numbers = true,
        alias = "duration"
    )]
    duration_tau1: Option<f64>,
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
    /// Relative error whose projected cost is tabulated (on a compression scene: the
    /// standard error of <F>/F_c0, with the bias below it).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    tolerance: f64,
    /// Compression scene only: comma-separated strains eps/eps_c0 (default 0,2,6).
    #[arg(long, value_name = "R1,R2,...", allow_hyphen_values = true)]
    strain_ratios: Option<String>,
    /// Compression scene only: interval between samples of F and of the buckled mode, in
    /// units of tau1 (at least one step; 1e-5 to 1).
    #[arg(long, value_name = "T", default_value_t = fig2_schemes::DEFAULT_SAMPLE_EVERY_TAU1, allow_negative_numbers = true)]
    sample_every_tau1: f64,
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

fn parse_method(text: &str, kinds: &[IntegratorKind]) -> Result<(IntegratorKind, NoiseModel)> {
    let integrators: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
    let allowed = format!(
        "INTEGRATOR/NOISE with INTEGRATOR one of {} and NOISE one of consistent, element-uniform",
        integrators.join(", ")
    );
    let (i, n) = text
        .trim()
        .split_once('/')
        .ok_or_else(|| Error::invalid("--methods", text.trim(), &allowed))?;
    let kind = kinds
        .iter()
        .copied()
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
    let mut scene = load_scene(&args.scene, args.scene_dir.as_deref())?;
    args.sim.apply(&mut scene);
    if scene.model == ModelKind::Compression {
        return run_fig2(args, scene, verbosity);
    }
    for (flag, given) in [
        ("--strain-ratios", args.strain_ratios.is_some()),
        (
            "--sample-every-tau1",
            args.sample_every_tau1 != fig2_schemes::DEFAULT_SAMPLE_EVERY_TAU1,
        ),
    ] {
        if given {
            return Err(Error::invalid(
                flag,
                &scene.name,
                "a compression scene (the flag is the Fig. 2 study's)",
            ));
        }
    }
    let methods = match &args.methods {
        None => DEFAULT_METHODS.to_vec(),
        Some(t) => {
            let items: Vec<&str> = t.split(',').map(str::trim).collect();
            let methods = items
                .iter()
                .map(|m| parse_method(m, &IntegratorKind::LINEAR))
                .collect::<Result<Vec<_>>>()?;
            super::refuse_repeated("--methods", &methods, &items, "INTEGRATOR/NOISE pairs")?;
            methods
        }
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
    let s = run_work_precision(&WorkPrecisionOptions {
        scene,
        methods,
        dt_tau1,
        em_fractions,
        trajectories: args.trajectories,
        duration_tau1: args.duration_tau1.unwrap_or(400.0),
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
    super::study_written(&args.out, &s.files, s.wall_seconds)?;
    Ok(0)
}

/// The schemes of Fig. 2 on a compression scene: the study, its table on stdout.
fn run_fig2(args: WorkPrecisionArgs, scene: Scene, verbosity: Verbosity) -> Result<i32> {
    let kinds = [
        IntegratorKind::EulerMaruyama,
        IntegratorKind::CrankNicolson,
        IntegratorKind::MetropolisCrankNicolson,
    ];
    let methods = match &args.methods {
        None => fig2_schemes::DEFAULT_METHODS.to_vec(),
        Some(t) => {
            let items: Vec<&str> = t.split(',').map(str::trim).collect();
            let methods = items
                .iter()
                .map(|m| parse_method(m, &kinds))
                .collect::<Result<Vec<_>>>()?;
            super::refuse_repeated("--methods", &methods, &items, "INTEGRATOR/NOISE pairs")?;
            methods
        }
    };
    let s = run_fig2_schemes(&Fig2SchemesOptions {
        methods,
        dt_tau1: parse_list_or(
            "--dt-tau1",
            args.dt_tau1.as_deref(),
            &fig2_schemes::DEFAULT_DT_TAU1,
            "comma-separated numbers in [1e-7, 1]",
        )?,
        em_fractions: parse_list_or(
            "--em-fractions",
            args.em_fractions.as_deref(),
            &fig2_schemes::DEFAULT_EM_FRACTIONS,
            "comma-separated numbers in (0, 1)",
        )?,
        strain_ratios: parse_list_or(
            "--strain-ratios",
            args.strain_ratios.as_deref(),
            &fig2_schemes::DEFAULT_STRAIN_RATIOS,
            "comma-separated numbers in [-100, 100]",
        )?,
        trajectories: args.trajectories,
        duration_tau1: args
            .duration_tau1
            .unwrap_or(fig2_schemes::DEFAULT_DURATION_TAU1),
        sample_every_tau1: args.sample_every_tau1,
        tolerance: args.tolerance,
        out: args.out.clone(),
        progress: verbosity.shows_progress(),
        limits: args.limits.limits(),
        scene,
    })?;
    print_fig2(&s);
    super::study_written(&args.out, &s.files, s.wall_seconds)?;
    Ok(0)
}

/// The tables of the Fig. 2 schemes study on stdout: every point, the projected cost of
/// every method and step, the dynamics comparison.
fn print_fig2(s: &Fig2SchemesSummary) {
    println!(
        "{} ({} elements, {}D, seed {}): {} trajectories x {} tau1 per strain and step, {} threads",
        s.scene, s.elements, s.dims, s.seed, s.trajectories, s.duration_tau1, s.threads
    );
    println!(
        "<F>/F_c0 minus the exact discrete theory (+- 1 s.e.), tau_int of F and of the buckled mode A^2 (tau1):"
    );
    for r in &s.runs {
        if let Some(why) = &r.failed {
            println!(
                "  {}/{} dt/tau1={:.3e}: {why}",
                r.integrator, r.noise, r.dt_tau1
            );
            continue;
        }
        for p in &r.points {
            println!(
                "  {:<26} dt/tau1={:<9.3e} eps/eps_c0={:<4} bias {:+.4} +- {:.4}  tau_F {:.4} +- {:.4}  tau_A2 {:.4} +- {:.4}",
                format!("{}/{}", r.integrator, r.noise),
                r.dt_tau1,
                p.strain_ratio,
                p.bias,
                p.force_std_error,
                p.tau_force,
                p.tau_force_std_error,
                p.tau_mode,
                p.tau_mode_std_error
            );
        }
    }
    println!(
        "projected CPU time to a standard error of {} F_c0 at every strain, bias below it:",
        s.tolerance
    );
    for r in &s.runs {
        if r.failed.is_some() {
            continue;
        }
        println!(
            "  {:<26} dt/tau1={:<9.3e} {:.3e} CPU-s per tau1: {}",
            format!("{}/{}", r.integrator, r.noise),
            r.dt_tau1,
            r.cpu_per_tau1,
            r.cpu_to_tolerance.map_or(
                "not reachable (its bias bound is above the tolerance at a strain)".to_string(),
                |t| { format!("{t:.3e} CPU-s") }
            )
        );
    }
    println!(
        "dynamics at each scheme's smallest step (chi2 of log tau_int, Holm at alpha = {}):",
        s.alpha
    );
    for t in &s.dynamics {
        println!(
            "  eps/eps_c0={:<4} {:<2}: {} p = {:.3} (Holm {:.3}) {}",
            t.strain_ratio,
            t.observable,
            t.methods
                .iter()
                .map(|(m, _, tau, se)| format!("{m} {tau:.4}+-{se:.4}"))
                .collect::<Vec<_>>()
                .join(", "),
            t.p_value,
            t.p_holm,
            if t.passed { "agree" } else { "DIFFER" }
        );
    }
}
