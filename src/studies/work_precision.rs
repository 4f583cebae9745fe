//! Work–precision study (`langevin-fem work-precision`): the error in ⟨w²(L/2)⟩ (a
//! membrane's ⟨h²⟩ at the middle of its midline, the centre) against wall time for every
//! integrator and noise model on the same scene.
//!
//! Each method (integrator × noise model) is run at several time steps, each point with
//! the same ensemble (trajectories × sampled duration; euler-maruyama, whose step is
//! bounded by its stability limit, with a shorter duration of its own), so the points of
//! a method have about the same sampling error and cost wall time ∝ (steps per τ1) ×
//! (cost per step). For each point:
//!
//! - the measured relative error |estimate − continuum|/continuum (the continuum profile
//!   variance kT x²(L − x)²/(3EIL) of eq. 2, or the membrane's (M5)), with its standard error
//!   (autocorrelation-aware, trajectories in quadrature, as in the verification checks);
//! - the exact relative bias b = |discrete − continuum|/continuum of this mesh, noise
//!   model, integrator and Δt (no sampling): the error the method keeps with unlimited
//!   samples (spatial error of the noise model plus the integrator's stationary bias);
//! - z of the estimate against the exact discrete value (the run is right if |z| is small);
//! - the projected wall time to reach a relative error ε with 95 % confidence: the
//!   sampling error of a time average falls as T^{-1/2}, so with the measured relative
//!   standard error s₀ at wall time t₀, b + 2s ≤ ε needs t(ε) = t₀ (2s₀/(ε − b))² (∞ if
//!   ε ≤ b). The burn-in is scaled with the samples, so t(ε) slightly overstates long
//!   runs. Per method the best time step is the one minimizing t(ε).
//!
//! Wall times are measured on this machine with the rayon pool over trajectories (the
//! thread count is recorded); they are not reproducible bit for bit, the estimates are.

use super::output::StudyReport;
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::noise::NoiseModel;
use crate::output::io::CsvWriter;
use crate::output::{Figure, Provenance, Series, SeriesStyle};
use crate::rng::derive_seed;
use crate::scene::linear::{FemObject, LinearRun};
use crate::scene::validate::Num;
use crate::scene::{ModelKind, RunSpec, Scene};
use crate::studies::converge::nan_if_null;
use crate::work::{Origin, Part, WorkLimits, WorkProjection};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Default methods: the paper's explicit scheme with both noise models, backward Euler,
/// Crank–Nicolson with both noise models, and the exact modal update.
pub const DEFAULT_METHODS: [(IntegratorKind, NoiseModel); 6] = [
    (IntegratorKind::EulerMaruyama, NoiseModel::ElementUniform),
    (IntegratorKind::EulerMaruyama, NoiseModel::Consistent),
    (IntegratorKind::BackwardEuler, NoiseModel::Consistent),
    (IntegratorKind::CrankNicolson, NoiseModel::ElementUniform),
    (IntegratorKind::CrankNicolson, NoiseModel::Consistent),
    (IntegratorKind::ExactModal, NoiseModel::Consistent),
];
/// Default Δt/τ1 of the unconditionally stable integrators.
pub const DEFAULT_DT_TAU1: [f64; 4] = [1e-2, 3e-3, 1e-3, 3e-4];
/// Default fractions of the stability limit for euler-maruyama.
pub const DEFAULT_EM_FRACTIONS: [f64; 2] = [0.9, 0.45];
/// Tolerances of the projected curves (relative error).
const CURVE_TOLERANCES: usize = 61;

/// Options of a work–precision study.
#[derive(Debug, Clone)]
pub struct WorkPrecisionOptions {
    /// A linear finite-element scene (filament, mesh, seed, burn-in).
    pub scene: Scene,
    /// Methods (integrator, noise model).
    pub methods: Vec<(IntegratorKind, NoiseModel)>,
    /// Δt/τ1 of the unconditionally stable integrators.
    pub dt_tau1: Vec<f64>,
    /// Fractions of the stability limit for euler-maruyama.
    pub em_fractions: Vec<f64>,
    /// Trajectories per point.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ1).
    pub duration_tau1: f64,
    /// Sampled duration per trajectory (τ1) of euler-maruyama.
    pub em_duration_tau1: f64,
    /// The tolerance whose projected cost is tabulated (relative error, e.g. 0.01).
    pub tolerance: f64,
    /// Output directory.
    pub out: PathBuf,
    /// Print one line per point on stderr.
    pub progress: bool,
    /// The caps on the study's projected work and memory ([`projected_work`]), checked
    /// before any simulation.
    pub limits: WorkLimits,
}

/// The projected work of the study: one part per method and time step (the points run
/// one after the other), each the work of its one-run scene ([`Scene::run_work`]).
///
/// # Errors
/// As the stability limit of euler-maruyama ([`BeamModel::explicit_euler_dt_limit`]).
///
/// [`BeamModel::explicit_euler_dt_limit`]: crate::fem::beam::BeamModel::explicit_euler_dt_limit
pub fn projected_work(opts: &WorkPrecisionOptions) -> Result<WorkProjection> {
    let mut parts = Vec::new();
    for &method in &opts.methods {
        let em = method.0 == IntegratorKind::EulerMaruyama;
        let flags = if em {
            "--methods, --em-fractions, --trajectories, --em-duration-tau1"
        } else {
            "--methods, --dt-tau1, --trajectories, --duration-tau1"
        };
        for dt in method_dts(opts, method)? {
            let s = point_scene(opts, method, dt);
            let e = s.runs[0].quick;
            parts.push(Part {
                label: format!("{} at dt/tau1 = {}", label(method), Num(dt)),
                drivers: format!(
                    "{} (--trajectories {} x {} = {} tau1 at dt/tau1 = {}, {} elements)",
                    flags,
                    opts.trajectories,
                    if em {
                        "--em-duration-tau1"
                    } else {
                        "--duration-tau1"
                    },
                    Num(e.duration_tau1),
                    Num(dt),
                    s.mesh.elements
                ),
                origin: Origin::Flags(flags.to_string()),
                work: s.run_work(0, &e, None),
            });
        }
    }
    Ok(WorkProjection {
        command: format!("work-precision --scene {}", opts.scene.name),
        parts,
    })
}

/// One method at one time step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WpPoint {
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// Δt/τ1.
    #[serde(deserialize_with = "nan_if_null")]
    pub dt_tau1: f64,
    /// Trajectories.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ1).
    #[serde(deserialize_with = "nan_if_null")]
    pub duration_tau1: f64,
    /// Steps per trajectory (burn-in + sampled).
    pub steps_per_trajectory: u64,
    /// Measured wall time of the ensemble (s).
    #[serde(deserialize_with = "nan_if_null")]
    pub wall_seconds: f64,
    /// Estimate of ⟨w²(L/2)⟩ (a membrane's ⟨h²⟩ at the centre).
    #[serde(deserialize_with = "nan_if_null")]
    pub estimate: f64,
    /// Its standard error.
    #[serde(deserialize_with = "nan_if_null")]
    pub std_error: f64,
    /// Exact discrete value (this mesh, noise, integrator and Δt).
    #[serde(deserialize_with = "nan_if_null")]
    pub discrete: f64,
    /// Continuum value.
    #[serde(deserialize_with = "nan_if_null")]
    pub continuum: f64,
    /// |estimate − continuum|/continuum.
    #[serde(deserialize_with = "nan_if_null")]
    pub rel_error: f64,
    /// std_error/continuum.
    #[serde(deserialize_with = "nan_if_null")]
    pub rel_std_error: f64,
    /// |discrete − continuum|/continuum.
    #[serde(deserialize_with = "nan_if_null")]
    pub rel_bias: f64,
    /// (estimate − discrete)/std_error.
    #[serde(deserialize_with = "nan_if_null")]
    pub z_discrete: f64,
    /// Projected wall time to reach the tolerance (s), if the bias allows it.
    pub seconds_to_tolerance: Option<f64>,
}

/// The cheapest way a method reaches the tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodSummary {
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// Smallest relative bias over the time steps studied.
    #[serde(deserialize_with = "nan_if_null")]
    pub min_rel_bias: f64,
    /// Projected wall time to reach the tolerance (s), if any time step can.
    pub seconds_to_tolerance: Option<f64>,
    /// The time step achieving it.
    pub best_dt_tau1: Option<f64>,
    /// Its cost relative to the fastest method.
    pub relative_cost: Option<f64>,
    /// Why the tolerance cannot be reached, if it cannot.
    pub note: String,
}

/// The stem of the study's output set: `work-precision.json`,
/// `work-precision.manifest.json` ([`super::output`]).
pub const STEM: &str = "work-precision";

/// The JSON summary of a work–precision study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkPrecisionSummary {
    /// The run that wrote this summary: the run id of the journal
    /// `work-precision.manifest.json` ([`super::output`]); empty in a summary written
    /// before journals existed.
    #[serde(default)]
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Master seed of the study: the scene's `seed`, or `--seed` when given (0 in a
    /// summary written before the seed was stored).
    #[serde(default)]
    pub seed: u64,
    /// Elements of the mesh.
    pub elements: usize,
    /// The observable: `w2(L/2)`, or a membrane's `h2(a/2,b/2)` (the centre).
    pub observable: String,
    /// Its continuum value.
    #[serde(deserialize_with = "nan_if_null")]
    pub continuum: f64,
    /// The tolerance of the table (relative error).
    #[serde(deserialize_with = "nan_if_null")]
    pub tolerance: f64,
    /// Trajectories per point.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ1), stable integrators.
    #[serde(deserialize_with = "nan_if_null")]
    pub duration_tau1: f64,
    /// Sampled duration per trajectory (τ1), euler-maruyama.
    #[serde(deserialize_with = "nan_if_null")]
    pub em_duration_tau1: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// Median relative standard error of the points (the sampling floor of this
    /// ensemble).
    #[serde(deserialize_with = "nan_if_null")]
    pub sampling_floor: f64,
    /// All points.
    pub points: Vec<WpPoint>,
    /// Per method.
    pub methods: Vec<MethodSummary>,
    /// Points whose estimate disagrees with the exact discrete value (|z| > 3).
    pub inconsistent_points: usize,
    /// The study's files (relative to the output directory, sorted): its table, figures
    /// and this summary; its journal and the shared index apart.
    pub files: Vec<String>,
    /// Wall time (s).
    #[serde(deserialize_with = "nan_if_null")]
    pub wall_seconds: f64,
}

/// `--methods` names at least one method (both work–precision studies).
pub(super) fn require_methods(methods: &[(IntegratorKind, NoiseModel)]) -> Result<()> {
    if methods.is_empty() {
        return Err(Error::invalid(
            "--methods",
            "(empty)",
            "at least one method",
        ));
    }
    Ok(())
}

/// Every `--dt-tau1` in [dt_min, 1] and every `--em-fractions` in (0, 1) (both
/// work–precision studies).
pub(super) fn require_steps(dt_tau1: &[f64], dt_min: f64, em_fractions: &[f64]) -> Result<()> {
    for &d in dt_tau1 {
        crate::error::require_in_range("--dt-tau1", d, dt_min, 1.0)?;
    }
    for &f in em_fractions {
        if !(f > 0.0 && f < 1.0) {
            return Err(Error::invalid(
                "--em-fractions",
                f,
                "fractions of the stability limit in (0, 1)",
            ));
        }
    }
    Ok(())
}

/// `scene` is a compression scene of a filament (the Fig. 2 studies: work–precision of
/// its schemes, the coupled time-step study); `what` names the study in the message.
pub(super) fn require_filament_compression(scene: &Scene, what: &str) -> Result<()> {
    if scene.model != ModelKind::Compression || scene.is_membrane() || scene.compression.is_none() {
        return Err(Error::invalid(
            "--scene",
            &scene.name,
            format!("a compression scene of a filament{what} (e.g. fig2-paper-2d, compression-2d)"),
        ));
    }
    Ok(())
}

/// `--strain-ratios` names at least one strain, each in [−100, 100] (the Fig. 2 studies).
pub(super) fn require_strains(strain_ratios: &[f64]) -> Result<()> {
    if strain_ratios.is_empty() {
        return Err(Error::invalid(
            "--strain-ratios",
            "(empty)",
            "at least one strain",
        ));
    }
    for &r in strain_ratios {
        crate::error::require_in_range("--strain-ratios", r, -100.0, 100.0)?;
    }
    Ok(())
}

/// `--trajectories` in [2, 1024] (both work–precision studies).
pub(super) fn require_trajectories(trajectories: usize) -> Result<()> {
    if !(2..=1024).contains(&trajectories) {
        return Err(Error::invalid(
            "--trajectories",
            trajectories,
            "an integer in [2, 1024]",
        ));
    }
    Ok(())
}

fn validate(opts: &WorkPrecisionOptions) -> Result<()> {
    if opts.scene.model != ModelKind::Fem {
        return Err(Error::invalid(
            "--scene",
            &opts.scene.name,
            "a linear finite-element scene (model = \"fem\", e.g. hinged-linear-2d)",
        ));
    }
    require_methods(&opts.methods)?;
    for &(k, _) in &opts.methods {
        if k == IntegratorKind::MetropolisCrankNicolson {
            return Err(Error::invalid(
                "--methods",
                k,
                format!(
                    "integrators {}",
                    IntegratorKind::list(&IntegratorKind::LINEAR)
                ),
            ));
        }
    }
    require_steps(&opts.dt_tau1, 1e-12, &opts.em_fractions)?;
    require_trajectories(opts.trajectories)?;
    crate::error::require_in_range("--duration-tau1", opts.duration_tau1, 1.0, 1e6)?;
    crate::error::require_in_range("--em-duration-tau1", opts.em_duration_tau1, 1.0, 1e6)?;
    crate::error::require_in_range("--tolerance", opts.tolerance, 1e-6, 1.0)?;
    // At most 1e10 sampled steps per trajectory (--dt-tau1 1e-12 would ask for 1e18).
    let shortest = opts.duration_tau1 / MAX_STEPS_PER_TRAJECTORY;
    if let Some(&d) = opts.dt_tau1.iter().find(|&&d| d < shortest) {
        return Err(Error::invalid(
            "--dt-tau1",
            d,
            format!(">= --duration-tau1/1e10 = {shortest:.3e} (at most 1e10 steps per trajectory)"),
        ));
    }
    Ok(())
}

/// The most sampled steps one trajectory of the study may take.
const MAX_STEPS_PER_TRAJECTORY: f64 = 1e10;

/// Projected wall time to reach relative error `eps` at 95 % (b + 2s ≤ ε).
fn projected_seconds(p: &WpPoint, eps: f64) -> Option<f64> {
    (eps > p.rel_bias && p.rel_std_error > 0.0)
        .then(|| p.wall_seconds * (2.0 * p.rel_std_error / (eps - p.rel_bias)).powi(2))
}

/// The scene with one run of `method` at `dt_tau1`, sampling only the profile at L/2.
fn point_scene(
    opts: &WorkPrecisionOptions,
    (kind, noise): (IntegratorKind, NoiseModel),
    dt_tau1: f64,
) -> Scene {
    let mut s = opts.scene.clone();
    let duration = if kind == IntegratorKind::EulerMaruyama {
        opts.em_duration_tau1
    } else {
        opts.duration_tau1
    };
    s.runs = vec![RunSpec::fixed(
        kind,
        noise,
        dt_tau1,
        opts.trajectories,
        duration,
    )];
    s.sampling.modes = 1;
    s.sampling.profile_points = vec![0.5];
    s.sampling.two_time.clear();
    s
}

/// A method at one time step, prepared: the method, Δt/τ1, its scene and its run.
type PreparedPoint = ((IntegratorKind, NoiseModel), f64, Scene, LinearRun);

/// Runs the study and writes `work-precision.{csv,json,svg}` and
/// `work-precision-projected.svg` in `opts.out`, with their journal
/// `work-precision.manifest.json`, after every simulation ([`super::output`]).
///
/// # Errors
/// Bad options (exit 2, naming the flag), a projected work or memory above
/// `opts.limits`; run failures.
pub fn run_work_precision(opts: &WorkPrecisionOptions) -> Result<WorkPrecisionSummary> {
    let start = Instant::now();
    let provenance = Provenance::begin(&[&opts.scene]);
    validate(opts)?;
    opts.limits.check(&projected_work(opts)?)?;
    // Prepare every point first, so that bad input fails before any simulation.
    let prepared = prepare_points(opts)?;
    let points = prepared
        .iter()
        .map(|p| run_point(opts, p))
        .collect::<Result<Vec<_>>>()?;
    let methods = summarize(opts, &points);
    let mut ses: Vec<f64> = points.iter().map(|p| p.rel_std_error).collect();
    ses.sort_by(f64::total_cmp);
    let sampling_floor = ses.get(ses.len() / 2).copied().unwrap_or(f64::NAN);

    let report = StudyReport::begin(&opts.out, "work-precision", STEM, provenance)?;
    report.write("work-precision.csv", points_csv(&points)?.as_bytes())?;
    report.write_svg(
        "work-precision.svg",
        &measured_figure(opts, &points, sampling_floor),
    )?;
    report.write_svg(
        "work-precision-projected.svg",
        &projected_figure(opts, &points),
    )?;
    let summary = WorkPrecisionSummary {
        run_id: report.run_id(),
        scene: opts.scene.name.clone(),
        seed: opts.scene.seed,
        elements: opts.scene.mesh.elements,
        observable: if opts.scene.is_membrane() {
            "h2(a/2,b/2)"
        } else {
            "w2(L/2)"
        }
        .to_string(),
        continuum: points.first().map_or(f64::NAN, |p| p.continuum),
        tolerance: opts.tolerance,
        trajectories: opts.trajectories,
        duration_tau1: opts.duration_tau1,
        em_duration_tau1: opts.em_duration_tau1,
        threads: rayon::current_num_threads(),
        sampling_floor,
        inconsistent_points: points.iter().filter(|p| p.z_discrete.abs() > 3.0).count(),
        points,
        methods,
        files: report.files(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    report.complete(&summary)?;
    Ok(summary)
}

/// Every method at each of its time steps (the options' Δt/τ1, or for euler-maruyama
/// the fractions of its stability limit), prepared.
fn prepare_points(opts: &WorkPrecisionOptions) -> Result<Vec<PreparedPoint>> {
    let mut prepared = Vec::new();
    for &method in &opts.methods {
        for dt in method_dts(opts, method)? {
            let s = point_scene(opts, method, dt);
            let lr = LinearRun::prepare(&s, &s.runs[0])?;
            prepared.push((method, dt, s, lr));
        }
    }
    Ok(prepared)
}

/// The time steps Δt/τ1 of `method`: the options' `dt_tau1`, or for euler-maruyama the
/// fractions of its stability limit.
fn method_dts(
    opts: &WorkPrecisionOptions,
    method: (IntegratorKind, NoiseModel),
) -> Result<Vec<f64>> {
    Ok(if method.0 == IntegratorKind::EulerMaruyama {
        let s = point_scene(opts, method, 1.0);
        let object = match s.membrane {
            None => FemObject::Beam(Box::new(crate::fem::beam::BeamModel::with_ends(
                s.filament,
                s.mesh.build(s.filament.length)?,
                s.ends,
            )?)),
            Some(_) => super::stability::uniform_object(&s, s.mesh.elements)?,
        };
        // The explicit limit Δt < 2/λ_max (BeamModel::explicit_euler_dt_limit).
        let limit = 2.0 / object.max_rate()? / s.tau1();
        opts.em_fractions.iter().map(|f| f * limit).collect()
    } else {
        opts.dt_tau1.clone()
    })
}

/// Simulates one point's ensemble, timing it, and measures its errors and projected
/// cost.
fn run_point(opts: &WorkPrecisionOptions, (method, dt, s, lr): &PreparedPoint) -> Result<WpPoint> {
    let seed = derive_seed(
        s.seed,
        &format!(
            "work-precision/{}/{}/{dt:e}",
            method.0.name(),
            method.1.name()
        ),
    );
    let duration = s.runs[0].quick.duration_tau1;
    let steps = lr.sampled_steps(duration * s.tau1());
    let t0 = Instant::now();
    let records = lr.simulate_ensemble(seed, 0, opts.trajectories as u64, steps, |_| {})?;
    let wall = t0.elapsed().as_secs_f64();
    let (est, se) = lr.profile_square_estimate(&records, 0)?;
    let cont = lr.reference.profile_continuum[0];
    let disc = lr.reference.profile_discrete[0];
    let mut p = WpPoint {
        integrator: method.0.name().to_string(),
        noise: method.1.name().to_string(),
        dt_tau1: *dt,
        trajectories: opts.trajectories,
        duration_tau1: duration,
        steps_per_trajectory: lr.burn_in_steps + steps,
        wall_seconds: wall,
        estimate: est,
        std_error: se,
        discrete: disc,
        continuum: cont,
        rel_error: (est - cont).abs() / cont,
        rel_std_error: se / cont,
        rel_bias: (disc - cont).abs() / cont,
        z_discrete: (est - disc) / se,
        seconds_to_tolerance: None,
    };
    p.seconds_to_tolerance = projected_seconds(&p, opts.tolerance);
    if opts.progress {
        eprintln!(
            "work-precision {} {} dt/tau1={dt:.3e}: error {:.2e} +- {:.1e} (bias {:.1e}), {:.2} s",
            p.integrator, p.noise, p.rel_error, p.rel_std_error, p.rel_bias, wall
        );
    }
    Ok(p)
}

/// The points as CSV (one line per point).
fn points_csv(points: &[WpPoint]) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        Path::new("work-precision.csv"),
        &[
            "integrator",
            "noise",
            "dt_tau1",
            "trajectories",
            "duration_tau1",
            "steps_per_trajectory",
            "wall_seconds",
            "estimate",
            "std_error",
            "discrete",
            "continuum",
            "rel_error",
            "rel_std_error",
            "rel_bias",
            "z_discrete",
            "seconds_to_tolerance",
        ],
    )?;
    for p in points {
        table.record([
            p.integrator.to_string(),
            p.noise.to_string(),
            p.dt_tau1.to_string(),
            p.trajectories.to_string(),
            p.duration_tau1.to_string(),
            p.steps_per_trajectory.to_string(),
            p.wall_seconds.to_string(),
            p.estimate.to_string(),
            p.std_error.to_string(),
            p.discrete.to_string(),
            p.continuum.to_string(),
            p.rel_error.to_string(),
            p.rel_std_error.to_string(),
            p.rel_bias.to_string(),
            p.z_discrete.to_string(),
            p.seconds_to_tolerance
                .map(|t| t.to_string())
                .unwrap_or_default(),
        ])?;
    }
    table.into_string()
}

fn method_points(points: &[WpPoint], (k, n): (IntegratorKind, NoiseModel)) -> Vec<&WpPoint> {
    points
        .iter()
        .filter(|p| p.integrator == k.name() && p.noise == n.name())
        .collect()
}

fn summarize(opts: &WorkPrecisionOptions, points: &[WpPoint]) -> Vec<MethodSummary> {
    let mut out: Vec<MethodSummary> = opts
        .methods
        .iter()
        .map(|&m| {
            let ps = method_points(points, m);
            let min_rel_bias = ps.iter().map(|p| p.rel_bias).fold(f64::INFINITY, f64::min);
            let best = ps
                .iter()
                .filter_map(|p| p.seconds_to_tolerance.map(|t| (t, p.dt_tau1)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            MethodSummary {
                integrator: m.0.name().to_string(),
                noise: m.1.name().to_string(),
                min_rel_bias,
                seconds_to_tolerance: best.map(|b| b.0),
                best_dt_tau1: best.map(|b| b.1),
                relative_cost: None,
                note: if best.is_none() {
                    format!(
                        "cannot reach {:.2e}: its smallest exact bias over these time steps is {min_rel_bias:.2e} (a smaller dt{} is needed)",
                        opts.tolerance,
                        if m.1 == NoiseModel::ElementUniform {
                            " cannot remove the element-uniform noise deficit; more elements"
                        } else {
                            ""
                        }
                    )
                } else {
                    String::new()
                },
            }
        })
        .collect();
    let fastest = out
        .iter()
        .filter_map(|m| m.seconds_to_tolerance)
        .fold(f64::INFINITY, f64::min);
    for m in &mut out {
        m.relative_cost = m.seconds_to_tolerance.map(|t| t / fastest);
    }
    out
}

fn label((k, n): (IntegratorKind, NoiseModel)) -> String {
    format!("{} ({})", k.name(), n.name())
}

fn measured_figure(opts: &WorkPrecisionOptions, points: &[WpPoint], floor: f64) -> Figure {
    let mut fig = Figure::new(
        format!(
            "{}: error in ⟨w²(L/2)⟩ against wall time ({} × {} τ₁ per point, EM {} τ₁)",
            opts.scene.name, opts.trajectories, opts.duration_tau1, opts.em_duration_tau1
        ),
        "wall time of the ensemble [s]",
        "|estimate − continuum| / continuum (dimensionless)",
    )
    .log_x()
    .log_y()
    .caption(
        "Relative error of ⟨w²(L/2)⟩ against the continuum for each method and time step \
         (markers, ±1 s.e., joined in order of the step) against the wall time of its \
         ensemble (log–log); the dashed lines are the sampling floor and the tolerance. A \
         better method should reach the tolerance in less wall time; points near the floor \
         are limited by sampling, not by the method.",
    );
    for &m in &opts.methods {
        let ps = method_points(points, m);
        fig = fig.series(
            Series::line(
                label(m),
                ps.iter().map(|p| (p.wall_seconds, p.rel_error)).collect(),
            )
            .with_style(SeriesStyle::LineMarkers)
            .with_errors(ps.iter().map(|p| p.rel_std_error).collect()),
        );
    }
    fig.hline(floor, "sampling floor (median standard error)")
        .hline(opts.tolerance, "tolerance")
}

fn projected_figure(opts: &WorkPrecisionOptions, points: &[WpPoint]) -> Figure {
    let mut fig = Figure::new(
        format!(
            "{}: projected wall time to reach a relative error in ⟨w²(L/2)⟩ (95 %)",
            opts.scene.name
        ),
        "projected wall time [s]",
        "relative error reached (dimensionless)",
    )
    .log_x()
    .log_y()
    .caption(
        "Projected wall time for each method to reach a relative error in ⟨w²(L/2)⟩ with \
         95 % confidence (bias + 2 s.e.), from its measured cost and standard error, at \
         its best time step (log–log); the dashed line is the tolerance. The leftmost curve \
         at a given error should be the cheapest method there; a curve that stops never \
         reaches smaller errors (its bias is larger).",
    );
    for &m in &opts.methods {
        let ps = method_points(points, m);
        let curve: Vec<(f64, f64)> = (0..CURVE_TOLERANCES)
            .filter_map(|j| {
                let eps = 10f64.powf(-3.0 + 3.0 * j as f64 / (CURVE_TOLERANCES - 1) as f64);
                ps.iter()
                    .filter_map(|p| projected_seconds(p, eps))
                    .min_by(f64::total_cmp)
                    .map(|t| (t, eps))
            })
            .collect();
        fig = fig.series(Series::line(label(m), curve));
    }
    fig.hline(opts.tolerance, "tolerance")
}
