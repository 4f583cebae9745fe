//! `langevin-fem stability`: stability map (integrator × Δt·λ_max × element count) and
//! the measured per-mode stationary bias against each integrator's exact formula.

use super::{Verbosity, count_in, parse_list_or, usize_in};
use clap::Args;
use langevin_fem::dynamics::IntegratorKind;
use langevin_fem::error::{Error, Result};
use langevin_fem::scene::load_scene;
use langevin_fem::studies::stability::{
    DEFAULT_DT_LAMBDA_MAX, DEFAULT_ELEMENTS, DEFAULT_INTEGRATORS, DEFAULT_MEMBRANE_ELEMENTS,
    ELEMENTS_RANGE, StabilityOptions, Status, run_stability,
};
use std::path::PathBuf;

/// The examples of `stability --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem stability                                   the default map (4 integrators x 4 meshes x 7 steps)
  langevin-fem stability --elements 10 --dt-lambda-max 0.1,1.9,2.1,1e3 --steps 20000
  langevin-fem stability --integrators euler-maruyama,crank-nicolson -o out -j 2
  langevin-fem stability -s membrane-hinged --elements 4 -o out   a membrane's plate, 4 x 4

The map goes to stdout, progress to stderr; the exit code is 1 if an exact formula was
rejected or a stability prediction failed.";

/// Command-line arguments of `langevin-fem stability`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct StabilityArgs {
    /// Linear finite-element scene supplying the filament (or membrane) and the seed: a
    /// built-in scene's name, a name in --scene-dir, or a path to a .toml file.
    #[arg(
        short,
        long,
        value_name = "NAME|PATH",
        default_value = "hinged-linear-2d"
    )]
    scene: String,
    /// Comma-separated integrators (default: euler-maruyama, backward-euler,
    /// crank-nicolson, exact-modal).
    #[arg(long, value_name = "I1,I2,...")]
    integrators: Option<String>,
    /// Comma-separated element counts (default 5,10,20,40; a membrane's along x, default
    /// 4,8, along y at the scene's aspect ratio of elements).
    #[arg(long, value_name = "N1,N2,...", allow_hyphen_values = true)]
    elements: Option<String>,
    /// Comma-separated normalized steps dt*lambda_max (default 0.1,1,1.9,2.1,10,1e3,1e5;
    /// the explicit limit is 2).
    #[arg(long, value_name = "A1,A2,...", allow_hyphen_values = true)]
    dt_lambda_max: Option<String>,
    /// Independent trajectories per cell (2 to 1024).
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = usize_in::<2, 1024>)]
    trajectories: usize,
    /// Sampled steps per trajectory (1000 to 1e8).
    #[arg(long, default_value_t = 50_000, allow_negative_numbers = true, value_parser = count_in::<1000, 100_000_000>)]
    steps: u64,
    /// Burn-in steps per trajectory, from rest (0 to 1e8).
    #[arg(long, default_value_t = 5_000, allow_negative_numbers = true, value_parser = count_in::<0, 100_000_000>)]
    burn_in: u64,
    /// Family-wise significance level (Holm) of the bias and formula tests.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    alpha: f64,
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

/// Runs the study (progress on stderr unless quiet) and prints the map on stdout; exit
/// code 0 if every formula comparison passed and every stability prediction held, 1
/// otherwise.
pub fn run(args: StabilityArgs, verbosity: Verbosity) -> Result<i32> {
    let allowed = IntegratorKind::list(&IntegratorKind::LINEAR);
    let integrators = match &args.integrators {
        None => DEFAULT_INTEGRATORS.to_vec(),
        Some(t) => {
            let items: Vec<&str> = t.split(',').map(str::trim).collect();
            let kinds = items
                .iter()
                .map(|s| {
                    IntegratorKind::LINEAR
                        .into_iter()
                        .find(|k| k.name() == *s)
                        .ok_or_else(|| Error::invalid("--integrators", s, &allowed))
                })
                .collect::<Result<Vec<_>>>()?;
            super::refuse_repeated("--integrators", &kinds, &items, &allowed)?;
            kinds
        }
    };
    let mut scene = load_scene(&args.scene, args.scene_dir.as_deref())?;
    args.sim.apply(&mut scene);
    let elements = parse_list_or(
        "--elements",
        args.elements.as_deref(),
        if scene.is_membrane() {
            &DEFAULT_MEMBRANE_ELEMENTS
        } else {
            &DEFAULT_ELEMENTS
        },
        &format!(
            "comma-separated integers in [{}, {}]",
            ELEMENTS_RANGE.0, ELEMENTS_RANGE.1
        ),
    )?;
    let dt_lambda_max = parse_list_or(
        "--dt-lambda-max",
        args.dt_lambda_max.as_deref(),
        &DEFAULT_DT_LAMBDA_MAX,
        "comma-separated numbers in (0, 1e12]",
    )?;
    let s = run_stability(&StabilityOptions {
        scene,
        integrators,
        elements,
        dt_lambda_max,
        trajectories: args.trajectories,
        sampled_steps: args.steps,
        burn_in_steps: args.burn_in,
        alpha: args.alpha,
        out: args.out.clone(),
        progress: verbosity.shows_progress(),
        limits: args.limits.limits(),
    })?;
    println!(
        "stability map of {} (consistent noise; {} trajectories x {} steps after {} burn-in; seed {})",
        s.scene, s.trajectories, s.sampled_steps, s.burn_in_steps, s.seed
    );
    let mut last = String::new();
    for c in &s.cells {
        if c.integrator != last {
            println!("  {}:", c.integrator);
            last.clone_from(&c.integrator);
        }
        let mark = match c.status {
            Status::Stable => "stable  ",
            Status::Biased => "BIASED  ",
            Status::Unstable => "UNSTABLE",
        };
        println!(
            "    {:>4} elements, dt*lambda_max {:>8.3e}: {mark} {}",
            c.elements, c.dt_lambda_max, c.detail
        );
    }
    println!(
        "exact stationary-variance formulas: {} of {} per-mode comparisons rejected (Holm, alpha = {}); stability predictions {}",
        s.formula_rejections,
        s.formula_tests,
        s.alpha,
        if s.stability_as_predicted {
            "all held"
        } else {
            "FAILED somewhere (see the table)"
        }
    );
    super::study_written(&args.out, &s.files, s.wall_seconds)?;
    Ok(if s.formula_rejections == 0 && s.stability_as_predicted {
        0
    } else {
        1
    })
}
