//! The schemes of Fig. 2 side by side (`langevin-fem work-precision` on a compression
//! scene, issue #30): the paper's explicit scheme, Crank–Nicolson with the stretching
//! force explicit and the Metropolis-adjusted chain, each at several time steps across
//! buckling, measured for
//!
//! - **work–precision**: the bias of ⟨F⟩/F_c0 against the exact discrete theory of the
//!   same mesh at each strain (± its autocorrelation-aware standard error) and the CPU
//!   time per simulated τ₁, from which the CPU time to reach Fig. 2 at a standard error
//!   ≤ ε with the bias below ε is projected: the sampled time a strain needs is
//!   `T₀(s₀/ε)²` (the standard error of a time average falls as T^(−1/2)); a scheme
//!   reaches ε only if a 95 % bound on its bias is below ε at every strain
//!   ([`SchemePoint::bias_bound`]): the Metropolis chain is exact at any Δt (0; bounded
//!   by `force-mean-bias` in the scenes); a θ-scheme with consistent noise has a bias of
//!   first order in Δt through the explicit stretching force, fitted per strain over its
//!   steps as `b = cΔt` (weighted least squares), bound `(|ĉ| + 2 s.e.(ĉ))Δt`, so that its
//!   small steps borrow the precision of its large ones; any other scheme (the paper's,
//!   whose element-uniform noise leaves a bias at Δt → 0) the measured `|b| + 2s₀`;
//! - **the nonlinear dynamics** (item 3 of the issue): the integrated autocorrelation
//!   time of F and of the buckled mode's squared amplitude `A²` (the first discrete sine
//!   of the nodal deflections, summed over components,
//!   [`crate::scene::compression::buckled_mode_square`]), in units of τ₁, from the
//!   autocovariance pooled over the trajectories
//!   ([`crate::stats::pooled_integrated_autocorrelation_time`]). The three schemes are
//!   consistent discretizations of the same Langevin dynamics `ξẇ = −∂U/∂w + f` (the
//!   paper's with a noise that is not fluctuation–dissipation exact on the mesh: each mode
//!   gets a little less than kT, about (kπh/L)²/12), so at each scheme's smallest step the
//!   τ_int agree within their errors: tested per strain and observable by a χ² of the
//!   log τ about their weighted mean (k − 1 dof), Holm over the tests at α. The
//!   differences at larger steps are drawn against Δt.
//!
//! CPU times are the process's user + system time around each point's ensemble
//! (`getrusage`), so they do not depend on how busy the other core is; they are not
//! reproducible bit for bit, every estimate is.

use super::output::StudyReport;
use super::work_precision::{
    require_filament_compression, require_methods, require_steps, require_strains,
    require_trajectories,
};
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::beam::BeamModel;
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::output::io::CsvWriter;
use crate::output::{Figure, Provenance, Series, SeriesStyle};
use crate::rng::derive_seed;
use crate::scene::compression::{CompressionRun, ForceRecord, force_estimates};
use crate::scene::validate::Num;
use crate::scene::{RunSpec, Scene};
use crate::stats::{self, holm};
use crate::studies::converge::nan_if_null;
use crate::work::{Origin, Part, WorkLimits, WorkProjection};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The three schemes of Fig. 2: the paper's (explicit Euler, axial solve, element-uniform
/// noise), Crank–Nicolson with the stretching force explicit, and the Metropolis chain.
pub const DEFAULT_METHODS: [(IntegratorKind, NoiseModel); 3] = [
    (IntegratorKind::EulerMaruyama, NoiseModel::ElementUniform),
    (IntegratorKind::CrankNicolson, NoiseModel::Consistent),
    (
        IntegratorKind::MetropolisCrankNicolson,
        NoiseModel::Consistent,
    ),
];
/// Default Δt/τ₁ of the implicit schemes: from the Metropolis chain's steps in the scenes
/// (0.02–0.16) down to the paper's step.
pub const DEFAULT_DT_TAU1: [f64; 6] = [8e-2, 2e-2, 2e-3, 5e-4, 1e-4, 7e-6];
/// Default fraction of the explicit scheme's stability limit (one step: the limit allows
/// no larger one, and each halving doubles the most expensive point).
pub const DEFAULT_EM_FRACTIONS: [f64; 1] = [0.9];
/// Default strains ε/ε_c0: in tension, near the force peak, buckled.
pub const DEFAULT_STRAIN_RATIOS: [f64; 3] = [0.0, 2.0, 6.0];
/// Default trajectories per point.
pub const DEFAULT_TRAJECTORIES: usize = 8;
/// Default sampled duration per trajectory (τ₁).
pub const DEFAULT_DURATION_TAU1: f64 = 40.0;
/// Default interval between samples (τ₁): fine enough to resolve τ_int of F.
pub const DEFAULT_SAMPLE_EVERY_TAU1: f64 = 0.005;
/// Family-wise level of the dynamics comparison (Holm).
pub const ALPHA: f64 = 0.01;
/// Tolerances of the projected curve (standard error of ⟨F⟩/F_c0, 10⁻³ to 1).
const CURVE_TOLERANCES: usize = 61;

/// The stem of the study's output set: `work-precision-fig2.json`, its journal.
pub const STEM: &str = "work-precision-fig2";

/// Options of the study.
#[derive(Debug, Clone)]
pub struct Fig2SchemesOptions {
    /// A compression scene of a filament (filament, mesh, seed, burn-in).
    pub scene: Scene,
    /// Methods (integrator, noise model).
    pub methods: Vec<(IntegratorKind, NoiseModel)>,
    /// Δt/τ₁ of the implicit schemes.
    pub dt_tau1: Vec<f64>,
    /// Fractions of the stability limit for euler-maruyama.
    pub em_fractions: Vec<f64>,
    /// Strains ε/ε_c0.
    pub strain_ratios: Vec<f64>,
    /// Trajectories per point and strain.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ₁).
    pub duration_tau1: f64,
    /// Interval between samples (τ₁; at least one step).
    pub sample_every_tau1: f64,
    /// The standard error of ⟨F⟩/F_c0 whose projected cost is tabulated.
    pub tolerance: f64,
    /// Output directory.
    pub out: PathBuf,
    /// Print one line per point on stderr.
    pub progress: bool,
    /// Caps on the projected work and memory, checked before any simulation.
    pub limits: WorkLimits,
}

/// One method at one time step and one strain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SchemePoint {
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// Δt/τ₁.
    #[serde(deserialize_with = "nan_if_null")]
    pub dt_tau1: f64,
    /// ε/ε_c0.
    #[serde(deserialize_with = "nan_if_null")]
    pub strain_ratio: f64,
    /// Interval between samples actually used (τ₁: a whole number of steps).
    #[serde(deserialize_with = "nan_if_null")]
    pub sample_interval_tau1: f64,
    /// ⟨F⟩/F_c0.
    #[serde(deserialize_with = "nan_if_null")]
    pub force: f64,
    /// Its standard error.
    #[serde(deserialize_with = "nan_if_null")]
    pub force_std_error: f64,
    /// The exact discrete theory of the mesh (the Δt → 0 law of a fluctuation–dissipation
    /// exact scheme).
    #[serde(deserialize_with = "nan_if_null")]
    pub exact: f64,
    /// force − exact.
    #[serde(deserialize_with = "nan_if_null")]
    pub bias: f64,
    /// bias / force_std_error.
    #[serde(deserialize_with = "nan_if_null")]
    pub z: f64,
    /// The 95 % bound on |bias| the projection uses (see the module docs).
    #[serde(deserialize_with = "nan_if_null")]
    pub bias_bound: f64,
    /// τ_int of F (τ₁).
    #[serde(deserialize_with = "nan_if_null")]
    pub tau_force: f64,
    /// Its standard error.
    #[serde(deserialize_with = "nan_if_null")]
    pub tau_force_std_error: f64,
    /// τ_int of the buckled mode's squared amplitude A² (τ₁).
    #[serde(deserialize_with = "nan_if_null")]
    pub tau_mode: f64,
    /// Its standard error.
    #[serde(deserialize_with = "nan_if_null")]
    pub tau_mode_std_error: f64,
    /// ⟨A²⟩/L² (the buckled mode's mean squared amplitude).
    #[serde(deserialize_with = "nan_if_null")]
    pub mode_square: f64,
    /// Metropolis acceptance rate (1 for θ-schemes).
    #[serde(deserialize_with = "nan_if_null")]
    pub acceptance: f64,
}

/// One method at one time step: its strains and its cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SchemeRun {
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// Δt/τ₁.
    #[serde(deserialize_with = "nan_if_null")]
    pub dt_tau1: f64,
    /// Whether the scheme is exact in law at any Δt (the Metropolis chain).
    pub exact_at_any_dt: bool,
    /// CPU seconds of the ensemble (all strains, burn-in included).
    #[serde(deserialize_with = "nan_if_null")]
    pub cpu_seconds: f64,
    /// CPU seconds per simulated τ₁ of one trajectory (burn-in included).
    #[serde(deserialize_with = "nan_if_null")]
    pub cpu_per_tau1: f64,
    /// Projected CPU seconds to the tolerance at every strain of the study, if reachable.
    pub cpu_to_tolerance: Option<f64>,
    /// Why the point has no estimates, if it has none: it diverged, or its series are too
    /// short for their autocorrelation time (the other fields are then NaN, no points).
    pub failed: Option<String>,
    /// Per strain.
    pub points: Vec<SchemePoint>,
}

/// The comparison of one observable's τ_int across the methods at one strain, each at
/// its smallest step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicsTest {
    /// ε/ε_c0.
    #[serde(deserialize_with = "nan_if_null")]
    pub strain_ratio: f64,
    /// `F` or `A2` (the buckled mode's squared amplitude).
    pub observable: String,
    /// Per method: `(integrator/noise, Δt/τ₁, τ_int/τ₁, standard error)`.
    pub methods: Vec<(String, f64, f64, f64)>,
    /// Σ (ln τ − weighted mean)²/(se/τ)².
    #[serde(deserialize_with = "nan_if_null")]
    pub chi2: f64,
    /// Degrees of freedom (methods − 1).
    pub dof: usize,
    /// Raw p-value.
    #[serde(deserialize_with = "nan_if_null")]
    pub p_value: f64,
    /// Holm-adjusted p-value over the study's tests.
    #[serde(deserialize_with = "nan_if_null")]
    pub p_holm: f64,
    /// Whether the methods agree at α (Holm).
    pub passed: bool,
}

/// The JSON summary of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fig2SchemesSummary {
    /// The journal's run id.
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Master seed.
    pub seed: u64,
    /// Elements of the mesh.
    pub elements: usize,
    /// Dimensions of the filament's space (2 or 3).
    pub dims: usize,
    /// Strains ε/ε_c0.
    pub strain_ratios: Vec<f64>,
    /// Trajectories per point and strain.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ₁).
    #[serde(deserialize_with = "nan_if_null")]
    pub duration_tau1: f64,
    /// The tolerance of the cost table (standard error of ⟨F⟩/F_c0).
    #[serde(deserialize_with = "nan_if_null")]
    pub tolerance: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// Every method at every step.
    pub runs: Vec<SchemeRun>,
    /// The dynamics comparison at each method's smallest step.
    pub dynamics: Vec<DynamicsTest>,
    /// Family-wise level of the comparison.
    #[serde(deserialize_with = "nan_if_null")]
    pub alpha: f64,
    /// The study's files (relative to the output directory).
    pub files: Vec<String>,
    /// Wall time (s).
    #[serde(deserialize_with = "nan_if_null")]
    pub wall_seconds: f64,
}

/// The explicit scheme's stability limit 2/λ_max of the scene's bending (Δt/τ₁).
pub(crate) fn em_limit_tau1(scene: &Scene) -> Result<f64> {
    let p = scene.filament;
    let beam = BeamModel::new(p, Mesh::uniform(p.length, scene.mesh.elements)?)?;
    Ok(beam.explicit_euler_dt_limit()? / p.tau1())
}

/// The time steps Δt/τ₁ of `method`, smallest last.
fn method_dts(opts: &Fig2SchemesOptions, method: (IntegratorKind, NoiseModel)) -> Result<Vec<f64>> {
    let mut d = if method.0 == IntegratorKind::EulerMaruyama {
        let limit = em_limit_tau1(&opts.scene)?;
        opts.em_fractions.iter().map(|f| f * limit).collect()
    } else {
        opts.dt_tau1.clone()
    };
    d.sort_by(|a: &f64, b| b.total_cmp(a));
    Ok(d)
}

fn validate(opts: &Fig2SchemesOptions) -> Result<()> {
    require_filament_compression(&opts.scene, "")?;
    require_methods(&opts.methods)?;
    for &(k, _) in &opts.methods {
        if k == IntegratorKind::ExactModal || k == IntegratorKind::BackwardEuler {
            return Err(Error::invalid(
                "--methods",
                k,
                "integrators euler-maruyama, crank-nicolson, metropolis-crank-nicolson on a compression scene",
            ));
        }
    }
    require_steps(&opts.dt_tau1, 1e-7, &opts.em_fractions)?;
    require_strains(&opts.strain_ratios)?;
    require_trajectories(opts.trajectories)?;
    crate::error::require_in_range("--duration-tau1", opts.duration_tau1, 1.0, 1e5)?;
    crate::error::require_in_range("--sample-every-tau1", opts.sample_every_tau1, 1e-5, 1.0)?;
    if opts.duration_tau1 < 100.0 * opts.sample_every_tau1 {
        return Err(Error::invalid(
            "--duration-tau1",
            opts.duration_tau1,
            format!(
                ">= 100 x --sample-every-tau1 = {} (the autocorrelation time needs at least 100 samples per trajectory)",
                Num(100.0 * opts.sample_every_tau1)
            ),
        ));
    }
    crate::error::require_in_range("--tolerance", opts.tolerance, 1e-6, 1.0)
}

/// The scene of one point: the method's run at `dt_tau1`, the study's strains and
/// ensemble.
fn point_scene(
    opts: &Fig2SchemesOptions,
    (kind, noise): (IntegratorKind, NoiseModel),
    dt_tau1: f64,
) -> Scene {
    let mut s = opts.scene.clone();
    s.runs = vec![RunSpec::fixed(
        kind,
        noise,
        dt_tau1,
        opts.trajectories,
        opts.duration_tau1,
    )];
    at_strains(&mut s, &opts.strain_ratios);
    s
}

/// Restricts a compression scene to the study's `strain_ratios` (ε/ε_c0), without the
/// force-distribution strains and the Δt/2 run's halving: what the Fig. 2 studies (this
/// one and [`super::coupled_dt`]) measure.
pub(crate) fn at_strains(s: &mut Scene, strain_ratios: &[f64]) {
    if let Some(c) = s.compression.as_mut() {
        c.strain_ratios = strain_ratios.to_vec();
        c.distribution_strain_ratios.clear();
        c.halving = None;
    }
}

/// The projected work: one part per method and step.
///
/// # Errors
/// As the explicit stability limit.
pub fn projected_work(opts: &Fig2SchemesOptions) -> Result<WorkProjection> {
    let mut parts = Vec::new();
    for &m in &opts.methods {
        for dt in method_dts(opts, m)? {
            let s = point_scene(opts, m, dt);
            let e = s.runs[0].quick;
            parts.push(Part {
                label: format!("{} at dt/tau1 = {}", label(m), Num(dt)),
                drivers: format!(
                    "--methods, --dt-tau1, --em-fractions, --strain-ratios, --trajectories {} x --duration-tau1 {} at dt/tau1 = {}",
                    opts.trajectories,
                    Num(opts.duration_tau1),
                    Num(dt)
                ),
                origin: Origin::Flags(
                    "--methods, --dt-tau1, --em-fractions, --strain-ratios, --trajectories, --duration-tau1"
                        .into(),
                ),
                work: s.run_work(0, &e, None),
            });
        }
    }
    Ok(WorkProjection {
        command: format!("work-precision --scene {}", opts.scene.name),
        parts,
    })
}

/// A figure legend's short name of a method: the three schemes of Fig. 2 by name, any
/// other combination as `integrator/noise`.
fn short_label(m: (IntegratorKind, NoiseModel)) -> String {
    match m {
        (IntegratorKind::EulerMaruyama, NoiseModel::ElementUniform) => "paper's scheme".into(),
        (IntegratorKind::CrankNicolson, NoiseModel::Consistent) => "Crank–Nicolson".into(),
        (IntegratorKind::MetropolisCrankNicolson, NoiseModel::Consistent) => {
            "Metropolis chain".into()
        }
        other => label(other),
    }
}

fn label((k, n): (IntegratorKind, NoiseModel)) -> String {
    format!("{}/{}", k.name(), n.name())
}

/// User + system CPU seconds of this process so far.
pub(crate) fn process_cpu_seconds() -> f64 {
    // SAFETY: getrusage writes into the zeroed struct it is given and reads nothing else.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: as above; RUSAGE_SELF is a valid `who`.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return f64::NAN;
    }
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// Runs the study and writes `work-precision-fig2.{csv,json}` and its figures in
/// `opts.out` with their journal.
///
/// # Errors
/// Bad options (exit 2, naming the flag), a projected work above `opts.limits`; an
/// estimator failure (too short trajectories for the autocorrelation time).
pub fn run_fig2_schemes(opts: &Fig2SchemesOptions) -> Result<Fig2SchemesSummary> {
    let start = Instant::now();
    let provenance = Provenance::begin(&[&opts.scene]);
    validate(opts)?;
    opts.limits.check(&projected_work(opts)?)?;
    let exact = crate::studies::converge::compression::theory_forces(
        &opts.scene,
        Some(opts.scene.mesh.elements),
        &opts.strain_ratios,
    )?;
    // Prepare every point first, so that bad input fails before any simulation.
    let mut prepared = Vec::new();
    for &m in &opts.methods {
        for dt in method_dts(opts, m)? {
            let s = point_scene(opts, m, dt);
            let comp = s.compression.clone().unwrap_or_else(|| unreachable!());
            let run = CompressionRun::prepare(&s, &comp, &s.runs[0])?
                .with_buckled_mode()
                .with_sample_interval(opts.sample_every_tau1 * s.tau1());
            prepared.push((m, dt, s, run));
        }
    }
    let mut runs = Vec::new();
    for (m, dt, s, run) in &prepared {
        runs.push(run_point(opts, *m, *dt, s, run, &exact)?);
    }
    first_order_bounds(opts, &mut runs);
    for r in &mut runs {
        r.cpu_to_tolerance = projected_cpu(r, opts, opts.tolerance);
    }
    let dynamics = dynamics_tests(opts, &runs);
    let report = StudyReport::begin(&opts.out, "work-precision", STEM, provenance)?;
    report.write("work-precision-fig2.csv", points_csv(&runs)?.as_bytes())?;
    report.write_svg("work-precision-fig2.svg", &projected_figure(opts, &runs))?;
    report.write_svg("fig2-bias.svg", &bias_figure(opts, &runs))?;
    report.write_svg("fig2-tau-int-force.svg", &tau_figure(opts, &runs, false))?;
    report.write_svg(
        "fig2-tau-int-buckled-mode.svg",
        &tau_figure(opts, &runs, true),
    )?;
    let summary = Fig2SchemesSummary {
        run_id: report.run_id(),
        scene: opts.scene.name.clone(),
        seed: opts.scene.seed,
        elements: opts.scene.mesh.elements,
        dims: opts.scene.dims,
        strain_ratios: opts.strain_ratios.clone(),
        trajectories: opts.trajectories,
        duration_tau1: opts.duration_tau1,
        tolerance: opts.tolerance,
        threads: rayon::current_num_threads(),
        runs,
        dynamics,
        alpha: ALPHA,
        files: report.files(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    report.complete(&summary)?;
    Ok(summary)
}

/// Simulates one method at one step at every strain (a divergence is recorded, not
/// raised) and measures it.
fn run_point(
    opts: &Fig2SchemesOptions,
    method: (IntegratorKind, NoiseModel),
    dt: f64,
    s: &Scene,
    run: &CompressionRun,
    exact: &[f64],
) -> Result<SchemeRun> {
    let base = derive_seed(
        s.seed,
        &format!(
            "work-precision-fig2/{}/{}/{dt:e}",
            method.0.name(),
            method.1.name()
        ),
    );
    let tau1 = s.tau1();
    let steps: Vec<u64> = (0..run.points())
        .map(|i| run.sampled_steps_at(i, opts.duration_tau1 * tau1))
        .collect();
    let cpu0 = process_cpu_seconds();
    let records = run.simulate_ensemble_per_point(
        |i| derive_seed(base, &format!("strain/{i}")),
        opts.trajectories,
        &steps,
        || {},
    );
    let cpu = process_cpu_seconds() - cpu0;
    let mut out = SchemeRun {
        integrator: method.0.name().to_string(),
        noise: method.1.name().to_string(),
        dt_tau1: dt,
        exact_at_any_dt: method.0 == IntegratorKind::MetropolisCrankNicolson,
        cpu_seconds: cpu,
        cpu_per_tau1: f64::NAN,
        cpu_to_tolerance: None,
        failed: None,
        points: Vec::new(),
    };
    let failed = |mut out: SchemeRun, e: Error| {
        if opts.progress {
            eprintln!("work-precision {} dt/tau1={dt:.3e}: {e}", label(method));
        }
        out.failed = Some(e.to_string());
        Ok(out)
    };
    let records = match records {
        Ok(r) => r,
        Err(e @ Error::Diverged { .. }) => return failed(out, e),
        Err(e) => return Err(e),
    };
    let simulated: f64 = (0..run.points())
        .map(|i| (run.burn_in_at(i) + steps[i] as f64 * run.dt_at(i)) / tau1)
        .sum::<f64>()
        * opts.trajectories as f64;
    out.cpu_per_tau1 = cpu / simulated;
    match measure(opts, &out, run, &records, exact) {
        Ok(points) => out.points = points,
        Err(e @ Error::Numerical { .. }) => return failed(out, e),
        Err(e) => return Err(e),
    }
    if opts.progress {
        let worst = out.points.iter().map(|p| p.z.abs()).fold(0.0, f64::max);
        eprintln!(
            "work-precision {} dt/tau1={dt:.3e}: {:.1} CPU-s ({:.3e} per tau1), largest |z| {worst:.1}",
            label(method),
            cpu,
            out.cpu_per_tau1
        );
    }
    Ok(out)
}

/// The points of `run_out` (its method and step) at every strain from the ensemble's
/// `records`: ⟨F⟩ against `exact`, the measured bias bound, the dynamics.
///
/// # Errors
/// [`Error::Numerical`] when a series is too short for its autocorrelation time.
fn measure(
    opts: &Fig2SchemesOptions,
    run_out: &SchemeRun,
    run: &CompressionRun,
    records: &[Vec<ForceRecord>],
    exact: &[f64],
) -> Result<Vec<SchemePoint>> {
    let tau1 = opts.scene.tau1();
    let est = force_estimates(records)?;
    let mut points = Vec::new();
    for (i, recs) in records.iter().enumerate() {
        let interval = run.sample_dt_at(i) / tau1;
        let d = dynamics_of(recs, interval)?;
        let (force, se) = est.force[i];
        points.push(SchemePoint {
            integrator: run_out.integrator.clone(),
            noise: run_out.noise.clone(),
            dt_tau1: run_out.dt_tau1,
            strain_ratio: opts.strain_ratios[i],
            sample_interval_tau1: interval,
            force,
            force_std_error: se,
            exact: exact[i],
            bias: force - exact[i],
            z: (force - exact[i]) / se,
            bias_bound: if run_out.exact_at_any_dt {
                0.0
            } else {
                (force - exact[i]).abs() + 2.0 * se
            },
            tau_force: d.tau_force.0,
            tau_force_std_error: d.tau_force.1,
            tau_mode: d.tau_mode.0,
            tau_mode_std_error: d.tau_mode.1,
            mode_square: d.mode_square,
            acceptance: est.acceptance,
        });
    }
    Ok(points)
}

/// The dynamics of one strain's records: τ_int of F and of A² with their standard
/// errors (units of τ₁, samples `interval` τ₁ apart), and ⟨A²⟩.
struct Dynamics {
    tau_force: (f64, f64),
    tau_mode: (f64, f64),
    mode_square: f64,
}

fn dynamics_of(recs: &[ForceRecord], interval: f64) -> Result<Dynamics> {
    let tau = |series: Vec<&[f64]>| -> Result<(f64, f64)> {
        let t = stats::pooled_integrated_autocorrelation_time(&series)?;
        Ok((t.tau_int * interval, t.std_error * interval))
    };
    let n: usize = recs.iter().map(|r| r.buckled_mode.len()).sum();
    Ok(Dynamics {
        tau_force: tau(recs.iter().map(|r| r.force_ratio.as_slice()).collect())?,
        tau_mode: tau(recs.iter().map(|r| r.buckled_mode.as_slice()).collect())?,
        mode_square: recs.iter().flat_map(|r| &r.buckled_mode).sum::<f64>() / n as f64,
    })
}

/// The bias bounds of the θ-schemes with consistent noise from the first-order fit
/// `b = cΔt` per strain over each such method's steps (see the module docs); needs two
/// steps or more (with one, the measured bound stays).
fn first_order_bounds(opts: &Fig2SchemesOptions, runs: &mut [SchemeRun]) {
    for &(k, n) in &opts.methods {
        if k == IntegratorKind::MetropolisCrankNicolson || n != NoiseModel::Consistent {
            continue;
        }
        let idx: Vec<usize> = (0..runs.len())
            .filter(|&j| {
                let r = &runs[j];
                r.integrator == k.name() && r.noise == n.name() && r.failed.is_none()
            })
            .collect();
        if idx.len() < 2 {
            continue;
        }
        for i in 0..opts.strain_ratios.len() {
            // Weighted least squares through the origin: ĉ = Σ w Δt b / Σ w Δt²,
            // w = 1/s², s.e.(ĉ) = (Σ w Δt²)^(−1/2).
            let (mut sxy, mut sxx) = (0.0, 0.0);
            for &j in &idx {
                let p = &runs[j].points[i];
                let w = p.force_std_error.powi(-2);
                sxy += w * p.dt_tau1 * p.bias;
                sxx += w * p.dt_tau1 * p.dt_tau1;
            }
            let (c, se) = (sxy / sxx, sxx.powf(-0.5));
            for &j in &idx {
                let p = &mut runs[j].points[i];
                p.bias_bound = (c.abs() + 2.0 * se) * p.dt_tau1;
            }
        }
    }
}

/// Projected CPU seconds for a standard error ≤ `eps` at every strain with the bias below
/// `eps` (see the module docs); `None` if the bias bound does not allow it.
fn projected_cpu(run: &SchemeRun, opts: &Fig2SchemesOptions, eps: f64) -> Option<f64> {
    if run.points.is_empty() {
        return None;
    }
    let mut sampled = 0.0;
    for p in &run.points {
        if p.bias_bound.is_nan() || p.bias_bound >= eps {
            return None;
        }
        sampled +=
            opts.trajectories as f64 * opts.duration_tau1 * (p.force_std_error / eps).powi(2);
    }
    Some(run.cpu_per_tau1 * sampled)
}

/// The comparison of τ_int across methods at each method's smallest step with estimates,
/// per strain and observable, Holm over all.
fn dynamics_tests(opts: &Fig2SchemesOptions, runs: &[SchemeRun]) -> Vec<DynamicsTest> {
    let smallest: Vec<&SchemeRun> = opts
        .methods
        .iter()
        .filter_map(|&m| {
            runs.iter()
                .filter(|r| {
                    r.integrator == m.0.name() && r.noise == m.1.name() && r.failed.is_none()
                })
                .min_by(|a, b| a.dt_tau1.total_cmp(&b.dt_tau1))
        })
        .collect();
    if smallest.len() < 2 {
        return Vec::new();
    }
    let mut tests = Vec::new();
    for (i, &r) in opts.strain_ratios.iter().enumerate() {
        for mode in [false, true] {
            let methods: Vec<(String, f64, f64, f64)> = smallest
                .iter()
                .map(|run| {
                    let p = &run.points[i];
                    let (t, se) = if mode {
                        (p.tau_mode, p.tau_mode_std_error)
                    } else {
                        (p.tau_force, p.tau_force_std_error)
                    };
                    (
                        format!("{}/{}", run.integrator, run.noise),
                        run.dt_tau1,
                        t,
                        se,
                    )
                })
                .collect();
            let chi2 = log_chi2(&methods);
            let dof = methods.len() - 1;
            let p_value = ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.sf(chi2));
            tests.push(DynamicsTest {
                strain_ratio: r,
                observable: if mode { "A2" } else { "F" }.to_string(),
                methods,
                chi2,
                dof,
                p_value,
                p_holm: f64::NAN,
                passed: false,
            });
        }
    }
    let adjusted = holm(&tests.iter().map(|t| t.p_value).collect::<Vec<_>>(), ALPHA);
    for (t, (p, rejected)) in tests.iter_mut().zip(adjusted) {
        t.p_holm = p;
        t.passed = !rejected;
    }
    tests
}

/// χ² of the log τ about their inverse-variance weighted mean (relative errors se/τ).
fn log_chi2(methods: &[(String, f64, f64, f64)]) -> f64 {
    let ys: Vec<(f64, f64)> = methods
        .iter()
        .map(|(_, _, t, se)| (t.ln(), (t / se).powi(2)))
        .collect();
    let wsum: f64 = ys.iter().map(|y| y.1).sum();
    let mean = ys.iter().map(|(y, w)| y * w).sum::<f64>() / wsum;
    ys.iter().map(|(y, w)| (y - mean).powi(2) * w).sum()
}

/// Every point as CSV.
fn points_csv(runs: &[SchemeRun]) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        Path::new("work-precision-fig2.csv"),
        &[
            "integrator",
            "noise",
            "dt_tau1",
            "strain_ratio",
            "force",
            "force_std_error",
            "exact_discrete",
            "bias",
            "z",
            "bias_bound",
            "tau_int_force_tau1",
            "tau_int_force_std_error",
            "tau_int_mode_tau1",
            "tau_int_mode_std_error",
            "mode_square",
            "acceptance",
            "sample_interval_tau1",
            "cpu_per_tau1",
            "cpu_to_tolerance",
            "failed",
        ],
    )?;
    for r in runs {
        if let Some(why) = &r.failed {
            table.record([
                r.integrator.clone(),
                r.noise.clone(),
                r.dt_tau1.to_string(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                why.clone(),
            ])?;
        }
        for p in &r.points {
            table.record([
                p.integrator.clone(),
                p.noise.clone(),
                p.dt_tau1.to_string(),
                p.strain_ratio.to_string(),
                p.force.to_string(),
                p.force_std_error.to_string(),
                p.exact.to_string(),
                p.bias.to_string(),
                p.z.to_string(),
                p.bias_bound.to_string(),
                p.tau_force.to_string(),
                p.tau_force_std_error.to_string(),
                p.tau_mode.to_string(),
                p.tau_mode_std_error.to_string(),
                p.mode_square.to_string(),
                p.acceptance.to_string(),
                p.sample_interval_tau1.to_string(),
                r.cpu_per_tau1.to_string(),
                r.cpu_to_tolerance
                    .map(|t| t.to_string())
                    .unwrap_or_default(),
                String::new(),
            ])?;
        }
    }
    table.into_string()
}

/// The runs of one method, by step.
fn method_runs(runs: &[SchemeRun], (k, n): (IntegratorKind, NoiseModel)) -> Vec<&SchemeRun> {
    runs.iter()
        .filter(|r| r.integrator == k.name() && r.noise == n.name() && r.failed.is_none())
        .collect()
}

fn projected_figure(opts: &Fig2SchemesOptions, runs: &[SchemeRun]) -> Figure {
    let mut fig = Figure::new(
        format!(
            "{}: projected CPU time to Fig. 2 at a standard error of ⟨F⟩ (strains {})",
            opts.scene.name,
            strains_text(&opts.strain_ratios)
        ),
        "projected CPU time [s]",
        "standard error of ⟨F⟩/F_c0 reached, bias below it (dimensionless)",
    )
    .log_x()
    .log_y()
    .caption(
        "For each scheme at its cheapest time step, the CPU time projected to reach a \
         standard error ε of ⟨F⟩/F_c0 at every strain of the study with a 95 % bound on its \
         bias below ε (Crank–Nicolson: a first-order fit b = cΔt over its steps; the \
         paper's scheme: its measured |bias| + 2 s.e.; the Metropolis chain is exact at any \
         step), from its measured CPU time per τ₁ and standard errors (log–log). A curve that stops cannot reach smaller ε at the steps \
         studied: its bias is larger; the paper's scheme keeps the bias of its \
         element-uniform noise at every step. The dashed line is the tolerance. \
         The paper's scheme: euler-maruyama with the axial solve and element-uniform noise; \
         Crank–Nicolson: crank-nicolson with the stretching force explicit, consistent \
         noise; Metropolis chain: metropolis-crank-nicolson.",
    );
    for (c, &m) in opts.methods.iter().enumerate() {
        let rs = method_runs(runs, m);
        let curve: Vec<(f64, f64)> = (0..CURVE_TOLERANCES)
            .filter_map(|j| {
                let eps = 10f64.powf(-3.0 + 3.0 * j as f64 / (CURVE_TOLERANCES - 1) as f64);
                rs.iter()
                    .filter_map(|r| projected_cpu(r, opts, eps))
                    .min_by(f64::total_cmp)
                    .map(|t| (t, eps))
            })
            .collect();
        fig = fig.series(Series::line(short_label(m), curve).palette(c));
    }
    fig.hline(opts.tolerance, "tolerance")
}

fn strains_text(r: &[f64]) -> String {
    r.iter()
        .map(|x| Num(*x).to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

fn bias_figure(opts: &Fig2SchemesOptions, runs: &[SchemeRun]) -> Figure {
    let mut fig = Figure::new(
        format!(
            "{}: ⟨F⟩/F_c0 minus the exact discrete theory against Δt",
            opts.scene.name
        ),
        "Δt/τ₁",
        "⟨F⟩/F_c0 − exact discrete theory (dimensionless)",
    )
    .log_x()
    .caption(
        "The deviation of ⟨F⟩/F_c0 from the exact discrete theory of the same mesh (the \
         Δt → 0 law of a fluctuation–dissipation-exact scheme) for each scheme (colour) and \
         strain (one line each), ±1 s.e., against the time step (log). The Metropolis chain \
         should stay at 0 at every step; Crank–Nicolson with the stretching force explicit \
         drifts as Δt grows; the paper's scheme sits above 0 by its noise's deficit at \
         every step it can take.",
    );
    fig = per_strain_series(fig, opts, runs, |p| (p.bias, p.force_std_error));
    fig.hline(0.0, "exact discrete theory")
}

/// `fig` with one series per method and strain: `value(point)` = (y, its error)
/// against Δt/τ₁, in the method's colour.
fn per_strain_series(
    mut fig: Figure,
    opts: &Fig2SchemesOptions,
    runs: &[SchemeRun],
    value: impl Fn(&SchemePoint) -> (f64, f64),
) -> Figure {
    for (c, &m) in opts.methods.iter().enumerate() {
        let rs = method_runs(runs, m);
        for (i, r) in opts.strain_ratios.iter().enumerate() {
            let pts: Vec<(f64, f64, f64)> = rs
                .iter()
                .map(|run| {
                    let (y, e) = value(&run.points[i]);
                    (run.dt_tau1, y, e)
                })
                .collect();
            fig = fig.series(
                Series::line(
                    format!("{}, ε/ε_c0 = {}", short_label(m), Num(*r)),
                    pts.iter().map(|p| (p.0, p.1)).collect(),
                )
                .with_style(SeriesStyle::LineMarkers)
                .with_errors(pts.iter().map(|p| p.2).collect())
                .palette(c),
            );
        }
    }
    fig
}

fn tau_figure(opts: &Fig2SchemesOptions, runs: &[SchemeRun], mode: bool) -> Figure {
    let what = if mode {
        "the buckled mode's squared amplitude A²"
    } else {
        "F"
    };
    let fig = Figure::new(
        format!(
            "{}: integrated autocorrelation time of {what} against Δt",
            opts.scene.name
        ),
        "Δt/τ₁",
        "τ_int/τ₁",
    )
    .log_x()
    .log_y()
    .caption(format!(
        "The integrated autocorrelation time of {what} (autocovariance pooled over {} \
         trajectories of {} τ₁, ±1 s.e.) for each scheme (colour) and strain (one line each) \
         against the time step (log–log). At the smallest steps the schemes follow the \
         same Langevin dynamics and should agree (tested, Holm at α = {ALPHA}); at larger \
         steps a scheme's own time-step error shows as a drift.",
        opts.trajectories,
        Num(opts.duration_tau1)
    ));
    per_strain_series(fig, opts, runs, |p| {
        if mode {
            (p.tau_mode, p.tau_mode_std_error)
        } else {
            (p.tau_force, p.tau_force_std_error)
        }
    })
}

/// A study small enough for a unit test (about 0.2 s): `fig2-paper-2d` on 4 elements,
/// strains 0 and 6, 4 trajectories × 4 τ₁, steps 1e-3 and 2e-4 τ₁ (the explicit scheme
/// at 0.9 of its limit, 3·10⁻⁴ τ₁ at 4 elements).
#[cfg(test)]
pub(crate) fn test_options(
    methods: Vec<(IntegratorKind, NoiseModel)>,
    out: &Path,
) -> Fig2SchemesOptions {
    let mut scene = crate::scene::load_scene("fig2-paper-2d", None).unwrap();
    scene.mesh.elements = 4;
    Fig2SchemesOptions {
        scene,
        methods,
        dt_tau1: vec![1e-3, 2e-4],
        em_fractions: vec![0.9],
        strain_ratios: vec![0.0, 6.0],
        trajectories: 4,
        duration_tau1: 4.0,
        sample_every_tau1: 0.005,
        tolerance: 0.01,
        out: out.to_path_buf(),
        progress: false,
        limits: WorkLimits::default(),
    }
}

#[cfg(test)]
mod tests {
    //! The comparison statistic on exact inputs (equal τ accepted, a factor 2 rejected),
    //! and the study end to end on a 4-element filament with short runs.
    use super::*;

    fn tiny(methods: Vec<(IntegratorKind, NoiseModel)>, out: &Path) -> Fig2SchemesOptions {
        test_options(methods, out)
    }

    fn entry(t: f64, se: f64) -> (String, f64, f64, f64) {
        (String::new(), 1.0, t, se)
    }

    #[test]
    fn log_chi2_is_zero_for_equal_taus_and_grows_with_a_ratio() {
        assert!(log_chi2(&[entry(2.0, 0.2), entry(2.0, 0.1)]) < 1e-28);
        // Two estimates, relative errors 0.1 each, ratio e^0.3: χ² = 0.3²/(0.1² + 0.1²).
        let c = log_chi2(&[entry(1.0, 0.1), entry(0.3f64.exp(), 0.1 * 0.3f64.exp())]);
        assert!((c - 4.5).abs() < 1e-12, "{c}");
    }

    /// End to end on 4 elements: every method at every step, finite estimates, the
    /// Metropolis chain within 4 s.e. of the exact discrete theory at every strain (it is
    /// exact at any Δt), one comparison per strain and observable with k − 1 dof, the
    /// files written; a τ_int twice as long in one method fails its comparison.
    #[test]
    fn the_study_runs_end_to_end_and_its_comparison_rejects_a_doubled_time() {
        let dir = std::env::temp_dir().join(format!("lfem-fig2-schemes-{}", std::process::id()));
        let opts = tiny(DEFAULT_METHODS.to_vec(), &dir);
        let s = run_fig2_schemes(&opts).unwrap();
        assert_eq!(s.runs.len(), 1 + 2 + 2);
        for r in &s.runs {
            assert!(r.failed.is_none(), "{r:?}");
            assert_eq!(r.points.len(), 2);
            assert!(r.cpu_per_tau1 > 0.0, "{r:?}");
            for p in &r.points {
                assert!(
                    p.tau_force > 0.0 && p.tau_mode > 0.0 && p.mode_square > 0.0,
                    "{p:?}"
                );
                assert!(
                    p.tau_force_std_error > 0.0 && p.force_std_error > 0.0,
                    "{p:?}"
                );
                if r.exact_at_any_dt {
                    assert!(p.z.abs() < 4.0, "{p:?}");
                }
            }
        }
        assert_eq!(s.dynamics.len(), 4);
        assert!(
            s.dynamics
                .iter()
                .all(|t| t.dof == 2 && t.p_value.is_finite())
        );
        for f in [
            "work-precision-fig2.csv",
            "work-precision-fig2.json",
            "work-precision-fig2.svg",
            "fig2-bias.svg",
            "fig2-tau-int-force.svg",
            "fig2-tau-int-buckled-mode.svg",
        ] {
            assert!(dir.join(f).is_file(), "{f}");
        }
        // The comparison rejects one method's τ doubled (relative errors about 10 %).
        let mut runs = s.runs.clone();
        for r in &mut runs {
            for p in &mut r.points {
                p.tau_force = 0.1;
                p.tau_force_std_error = 0.01;
                p.tau_mode = if r.exact_at_any_dt { 0.2 } else { 0.1 };
                p.tau_mode_std_error = 0.1 * p.tau_mode;
            }
        }
        let t = dynamics_tests(&opts, &runs);
        assert!(
            t.iter().filter(|t| t.observable == "F").all(|t| t.passed),
            "{t:?}"
        );
        assert!(
            t.iter().filter(|t| t.observable == "A2").all(|t| !t.passed),
            "{t:?}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    /// The first-order fit on exact input: biases b = 5Δt with equal errors give ĉ = 5,
    /// so the bound at each step is (5 + 2 s.e.(ĉ))Δt, s.e.(ĉ) = s/sqrt(Σ Δt²); the chain
    /// and the paper's scheme keep theirs.
    #[test]
    fn first_order_bounds_fit_the_slope_through_the_origin() {
        let opts = tiny(DEFAULT_METHODS.to_vec(), Path::new("unused"));
        let point = |dt: f64, bias: f64| SchemePoint {
            integrator: String::new(),
            noise: String::new(),
            dt_tau1: dt,
            strain_ratio: 0.0,
            sample_interval_tau1: 0.005,
            force: bias,
            force_std_error: 0.01,
            exact: 0.0,
            bias,
            z: bias / 0.01,
            bias_bound: bias.abs() + 0.02,
            tau_force: 0.1,
            tau_force_std_error: 0.01,
            tau_mode: 0.1,
            tau_mode_std_error: 0.01,
            mode_square: 1e-3,
            acceptance: 1.0,
        };
        let run = |(k, n): (IntegratorKind, NoiseModel), dt: f64| SchemeRun {
            integrator: k.name().into(),
            noise: n.name().into(),
            dt_tau1: dt,
            exact_at_any_dt: false,
            cpu_seconds: 1.0,
            cpu_per_tau1: 1e-3,
            cpu_to_tolerance: None,
            failed: None,
            points: vec![point(dt, 5.0 * dt), point(dt, 5.0 * dt)],
        };
        let mut runs: Vec<SchemeRun> = [2e-3, 1e-3]
            .iter()
            .map(|&dt| run(DEFAULT_METHODS[1], dt))
            .chain([run(DEFAULT_METHODS[0], 7e-6)])
            .collect();
        first_order_bounds(&opts, &mut runs);
        let se = 0.01 / (2e-3f64.powi(2) + 1e-3f64.powi(2)).sqrt();
        for r in &runs[..2] {
            for p in &r.points {
                let want = (5.0 + 2.0 * se) * r.dt_tau1;
                assert!((p.bias_bound - want).abs() < 1e-12 * want, "{p:?}");
            }
        }
        assert_eq!(runs[2].points[0].bias_bound, 5.0 * 7e-6 + 0.02);
    }

    #[test]
    fn bad_options_are_refused_naming_the_flag() {
        let dir = std::env::temp_dir().join("lfem-fig2-schemes-bad");
        let mut o = tiny(DEFAULT_METHODS.to_vec(), &dir);
        o.methods = vec![(IntegratorKind::ExactModal, NoiseModel::Consistent)];
        assert!(validate(&o).unwrap_err().to_string().contains("--methods"));
        let mut o = tiny(DEFAULT_METHODS.to_vec(), &dir);
        o.duration_tau1 = 0.2;
        assert!(
            validate(&o)
                .unwrap_err()
                .to_string()
                .contains("--duration-tau1")
        );
        let mut o = tiny(DEFAULT_METHODS.to_vec(), &dir);
        o.scene = crate::scene::load_scene("hinged-linear-2d", None).unwrap();
        assert!(validate(&o).unwrap_err().to_string().contains("--scene"));
    }
}
