//! The time-step error of ⟨F⟩ on Fig. 2 resolved by coupled trajectories (`langevin-fem
//! converge --over dt --coupled`, issue #30): the observed order of a θ-scheme's weak
//! error with its confidence interval, where independent runs cannot reach it.
//!
//! The paper's explicit scheme changes ⟨F⟩ by less than 10⁻³ F_c0 between its stability
//! limit and Δt → 0 (its element-uniform noise hardly excites the stiff modes whose
//! variance the explicit step inflates by `1/(1 − λΔt/2)`), while an independent
//! ensemble's standard error is about 0.03 F_c0: the order would need 10⁴ times the
//! ensemble ([`crate::studies::converge`] prints "no observed order" there). The
//! differences between steps, not the values, carry the order: for a weak error
//! `e(Δt) = cΔt^p`, `D(Δt) = e(Δt) − e(Δt/2) = c(1 − 2^−p)Δt^p` has the same order.
//!
//! **Coupling.** A trajectory at Δt and one at Δt/2 are driven by the same Brownian path:
//! each coarse step takes the noise of the two fine steps it spans, `ζ = (ζ₁ + ζ₂)/√2`
//! ([`CompressionRun::simulate_coupled`]; common random numbers, the coupling of
//! multilevel Monte Carlo). Both start from one state (an equilibrium start burnt in at the
//! coarse step). The slow modes, which carry nearly all of F's variance and its long
//! correlation time, then move together and cancel in the difference of the time averages;
//! what is left is the fast modes' share, which decorrelates within a few steps. Each pair
//! is independent of the others, so `D` at a step and strain is the mean over the pairs of
//! their time-averaged differences, with the standard error of a mean of independent
//! values (no autocorrelation estimate needed) and a t-test over the pairs.
//!
//! **Order.** Per strain, ln|D_k| against ln Δt_k is fitted by weighted least squares with
//! the weights (D_k/s.e._k)² (the inverse variances of ln|D_k|); the order's standard error
//! is that of the known weights, its 95 % interval normal, and χ² of the residuals (n − 2
//! degrees of freedom) tells whether one power law fits. The fit needs every D_k of one sign
//! and at least [`RESOLVED_SIGMAS`] standard errors from 0; otherwise the strain's order is
//! reported as not resolved, with the reason.
//!
//! **Expected.** Order 1 (the θ-schemes' weak order, with the stretching force explicit).
//! Beside it, the *linear-response prediction* ([`crate::theory::scheme_law`]): the ⟨F⟩ a
//! Gaussian of the scheme's exact discrete stationary covariance predicts at each step,
//! its differences and their order over the same steps. Near the stability limit both are
//! pre-asymptotic (the stiff modes' `1/(1 − λΔt/2)` is superlinear there).

use super::converge::weighted_line;
use super::fig2_schemes::{at_strains, em_limit_tau1, process_cpu_seconds};
use super::output::StudyReport;
use super::work_precision::{require_filament_compression, require_strains};
use crate::dynamics::{Family, IntegratorKind, par_indexed};
use crate::error::{Error, Result};
use crate::output::{Figure, Provenance, Series, SeriesStyle};
use crate::rng::{derive_seed, trajectory_rng};
use crate::scene::Scene;
use crate::scene::compression::{CompressionRun, CoupledRecord};
use crate::scene::validate::Num;
use crate::stats;
use crate::studies::converge::nan_if_null;
use crate::theory::compression::Dims;
use crate::theory::scheme_law::scheme_force_ratios;
use crate::work::{Origin, Part, RunWork, WorkLimits, WorkProjection};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::path::PathBuf;
use std::time::Instant;

/// Default steps as fractions of the explicit stability limit 2/λ_max (euler-maruyama).
pub const DEFAULT_LIMIT_FRACTIONS: [f64; 4] = [0.5, 0.25, 0.125, 0.0625];
/// Default Δt/τ₁ of the other θ-schemes.
pub const DEFAULT_DT_TAU1: [f64; 4] = [4e-3, 2e-3, 1e-3, 5e-4];
/// Default strains ε/ε_c0: in tension, near the force peak, buckled (those of the
/// schemes' work–precision study).
pub use super::fig2_schemes::DEFAULT_STRAIN_RATIOS;
/// Default coupled pairs per step and strain.
pub const DEFAULT_TRAJECTORIES: usize = 16;
/// Default sampled duration of each pair (τ₁).
pub const DEFAULT_DURATION_TAU1: f64 = 0.05;
/// A difference is resolved when it is at least this many standard errors from 0.
pub const RESOLVED_SIGMAS: f64 = 3.0;
/// The θ-schemes' weak order.
pub const EXPECTED_ORDER: f64 = 1.0;
/// Two-sided 95 % normal quantile.
const Z95: f64 = 1.959_963_984_540_054;

/// Options of the study.
#[derive(Debug, Clone)]
pub struct CoupledDtOptions {
    /// A compression scene of a filament (filament, mesh, seed, burn-in).
    pub scene: Scene,
    /// The run whose integrator and noise are studied (a θ-scheme).
    pub run: usize,
    /// Steps Δt/τ₁, each half the previous one (at least three); pair k couples
    /// `dt_tau1[k]` with `dt_tau1[k + 1]`.
    pub dt_tau1: Vec<f64>,
    /// Strains ε/ε_c0.
    pub strain_ratios: Vec<f64>,
    /// Coupled pairs per step and strain.
    pub trajectories: usize,
    /// Sampled duration of each pair (τ₁).
    pub duration_tau1: f64,
    /// Output directory.
    pub out: PathBuf,
    /// Print one line per step on stderr.
    pub progress: bool,
    /// Caps on the projected work and memory, checked before any simulation.
    pub limits: WorkLimits,
}

/// One coupled step pair at one strain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoupledPoint {
    /// ε/ε_c0.
    pub strain_ratio: f64,
    /// The coarse step Δt/τ₁ (the fine one is half of it).
    pub dt_tau1: f64,
    /// ⟨F⟩_Δt − ⟨F⟩_Δt/2 over F_c0: the mean over the pairs of their time-averaged
    /// differences.
    pub difference: f64,
    /// Its standard error (the pairs' spread over √n).
    pub std_error: f64,
    /// Two-sided p-value of the t-test of the difference against 0 (n − 1 dof).
    pub p_value: f64,
    /// ⟨F⟩/F_c0 at the coarse step, averaged over the pairs (not a converged estimate:
    /// the pairs are short).
    pub coarse_mean: f64,
    /// The standard error the same difference would have from independent trajectories
    /// of the same length, `sqrt((var_coarse + var_fine)/n)` from the spread of the
    /// pairs' coarse and fine time averages: the coupling's gain is its ratio to
    /// [`Self::std_error`].
    pub independent_std_error: f64,
    /// The linear-response prediction of the difference ([`crate::theory::scheme_law`]);
    /// `null` where the scheme has no discrete law.
    #[serde(deserialize_with = "nan_if_null")]
    pub predicted: f64,
}

/// The observed order of one strain's differences.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoupledOrder {
    /// ε/ε_c0.
    pub strain_ratio: f64,
    /// The fitted order p of |D| ∝ Δt^p (`null` if not resolved).
    #[serde(deserialize_with = "nan_if_null")]
    pub order: f64,
    /// Its standard error from the known weights.
    #[serde(deserialize_with = "nan_if_null")]
    pub std_error: f64,
    /// The 95 % interval (normal).
    pub ci: Option<(f64, f64)>,
    /// χ² of the weighted residuals about the power law.
    #[serde(deserialize_with = "nan_if_null")]
    pub chi2: f64,
    /// Its degrees of freedom (points − 2).
    pub dof: usize,
    /// Its upper-tail p-value (`null` with two points): small if one power law does not
    /// fit the differences.
    #[serde(deserialize_with = "nan_if_null")]
    pub fit_p_value: f64,
    /// The order of the predicted differences over the same steps (unweighted fit;
    /// `null` where there is no prediction).
    #[serde(deserialize_with = "nan_if_null")]
    pub predicted_order: f64,
    /// The expected asymptotic order ([`EXPECTED_ORDER`]).
    pub expected: f64,
    /// Why the order is not resolved (empty if it is).
    pub note: String,
}

/// The study's summary (`<stem>.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoupledDtSummary {
    /// The run id of the output set.
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Run name.
    pub run: String,
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// Master seed.
    pub seed: u64,
    /// Elements.
    pub elements: usize,
    /// Dimensions.
    pub dims: usize,
    /// The steps Δt/τ₁.
    pub dt_tau1: Vec<f64>,
    /// Strains ε/ε_c0.
    pub strain_ratios: Vec<f64>,
    /// Pairs per step and strain.
    pub trajectories: usize,
    /// Sampled duration of each pair (τ₁).
    pub duration_tau1: f64,
    /// Burn-in of each pair at its coarse step (τ₁).
    pub burn_in_tau1: f64,
    /// One point per step pair and strain.
    pub points: Vec<CoupledPoint>,
    /// One order per strain.
    pub orders: Vec<CoupledOrder>,
    /// Process CPU seconds of the simulations.
    pub cpu_seconds: f64,
    /// Worker threads.
    pub threads: usize,
    /// Files of the output set.
    pub files: Vec<String>,
    /// Wall time (s).
    pub wall_seconds: f64,
}

/// How the stem of the study's output set ends.
pub const STEM_SUFFIX: &str = "-coupled-dt";

/// The stem of the output set: `<scene>-<run>-coupled-dt`.
pub fn stem(opts: &CoupledDtOptions) -> String {
    format!(
        "{}-{}{STEM_SUFFIX}",
        opts.scene.name, opts.scene.runs[opts.run].name
    )
}

/// The default steps of `scene`'s run `run`: fractions of the explicit stability limit
/// for euler-maruyama ([`DEFAULT_LIMIT_FRACTIONS`]), [`DEFAULT_DT_TAU1`] otherwise.
///
/// # Errors
/// Invalid filament parameters or mesh.
pub fn default_steps(scene: &Scene, run: usize) -> Result<Vec<f64>> {
    if scene.runs[run].integrator == IntegratorKind::EulerMaruyama {
        let limit = em_limit_tau1(scene)?;
        Ok(DEFAULT_LIMIT_FRACTIONS.iter().map(|f| f * limit).collect())
    } else {
        Ok(DEFAULT_DT_TAU1.to_vec())
    }
}

/// Refuses options the study cannot run, naming the flag.
fn validate(opts: &CoupledDtOptions) -> Result<()> {
    let s = &opts.scene;
    require_filament_compression(s, " for --coupled")?;
    let spec = &s.runs[opts.run];
    if !matches!(spec.integrator.family(), Family::Theta(_)) {
        return Err(Error::invalid(
            "--integrator",
            spec.integrator,
            "a θ-scheme for --coupled (euler-maruyama, crank-nicolson, backward-euler): the Metropolis chain's accept/reject step breaks the coupling, and it is exact at any step",
        ));
    }
    let d = &opts.dt_tau1;
    if d.len() < 3 {
        return Err(Error::invalid(
            "--values",
            d.len(),
            "at least 3 steps for --coupled (2 differences)",
        ));
    }
    for (k, &v) in d.iter().enumerate() {
        crate::error::require_in_range("--values", v, 1e-9, 1.0)?;
        if k > 0 && ((2.0 * v / d[k - 1]) - 1.0).abs() > 1e-9 {
            return Err(Error::invalid(
                "--values",
                Num(v),
                format!(
                    "half the previous step, {} (each coupled pair is a step and its half)",
                    Num(0.5 * d[k - 1])
                ),
            ));
        }
    }
    require_strains(&opts.strain_ratios)?;
    crate::error::require_in_range("--trajectories", opts.trajectories as f64, 3.0, 1e5)?;
    crate::error::require_in_range("--duration-tau1", opts.duration_tau1, 1e-3, 1e4)
}

/// The scene of the study: the run alone, at the study's strains (its step the first).
fn study_scene(opts: &CoupledDtOptions) -> Scene {
    let mut s = opts.scene.clone();
    let mut spec = s.runs[opts.run].clone();
    spec.dt_tau1 = opts.dt_tau1[0];
    s.runs = vec![spec];
    at_strains(&mut s, &opts.strain_ratios);
    s
}

/// Burn-in and sampled coarse steps of a pair at coarse step `dt_tau1`.
fn pair_steps(opts: &CoupledDtOptions, dt_tau1: f64) -> (u64, u64) {
    let burn = opts
        .scene
        .compression
        .as_ref()
        .map_or(0.0, |c| c.burn_in_tau1);
    (
        (burn / dt_tau1).round() as u64,
        ((opts.duration_tau1 / dt_tau1).round() as u64).max(1),
    )
}

/// The projected work: one part per step pair (burn-in at the coarse step, then three
/// steps' worth per coarse step: two fine and one coarse).
///
/// # Errors
/// None at present (a `Result` as the other studies' projections).
pub fn projected_work(opts: &CoupledDtOptions) -> Result<WorkProjection> {
    let dofs = (2 * opts.scene.mesh.elements + 2) as f64 * (opts.scene.dims - 1) as f64;
    let pairs = (opts.trajectories * opts.strain_ratios.len()) as f64;
    let parts = opts.dt_tau1[..opts.dt_tau1.len().saturating_sub(1)]
        .iter()
        .map(|&dt| {
            let (burn, steps) = pair_steps(opts, dt);
            let trajectory_steps = pairs * (burn + 3 * steps) as f64;
            Part {
                label: format!("coupled pairs at dt/tau1 = {} and its half", Num(dt)),
                drivers: format!(
                    "--values, --strain-ratios, --trajectories {} x --duration-tau1 {}",
                    opts.trajectories,
                    Num(opts.duration_tau1)
                ),
                origin: Origin::Flags(
                    "--values, --strain-ratios, --trajectories, --duration-tau1".into(),
                ),
                work: RunWork {
                    trajectory_steps,
                    dof_steps: trajectory_steps * dofs,
                    samples: pairs,
                },
            }
        })
        .collect();
    Ok(WorkProjection {
        command: format!("converge --coupled --scene {}", opts.scene.name),
        parts,
    })
}

/// Mean, standard error and two-sided t-test p-value (against 0, n − 1 dof) of
/// independent values ([`stats::ensemble_mean`], [`stats::t_test`]; p is NaN if the values
/// do not spread).
fn mean_test(values: &[f64]) -> Result<(f64, f64, f64)> {
    let m = stats::ensemble_mean(values)?;
    let p = stats::t_test(m.mean, 0.0, m.std_error, m.n).map_or(f64::NAN, |o| o.p_value);
    Ok((m.mean, m.std_error, p))
}

/// Runs the study and writes `<stem>.{csv,json,svg}` in `opts.out` with its journal.
///
/// # Errors
/// Bad options (exit 2) naming the flag; a diverged pair or other run failure (exit 3).
pub fn run_coupled_dt(opts: &CoupledDtOptions) -> Result<CoupledDtSummary> {
    let start = Instant::now();
    let provenance = Provenance::begin(&[&opts.scene]);
    validate(opts)?;
    opts.limits.check(&projected_work(opts)?)?;
    let s = study_scene(opts);
    let comp = s.compression.clone().unwrap_or_else(|| unreachable!());
    let run = CompressionRun::prepare(&s, &comp, &s.runs[0])?;
    let spec = &s.runs[0];
    let predicted = predictions(opts, &s)?;
    let tau1 = s.tau1();
    let (nt, ns) = (opts.trajectories, opts.strain_ratios.len());
    let cpu0 = process_cpu_seconds();
    let mut points = Vec::new();
    for (k, &dt) in opts.dt_tau1[..opts.dt_tau1.len() - 1].iter().enumerate() {
        let base = derive_seed(
            s.seed,
            &format!(
                "coupled-dt/{}/{}/{dt:e}",
                spec.integrator.name(),
                spec.noise.name()
            ),
        );
        let (burn, steps) = pair_steps(opts, dt);
        let recs: Vec<CoupledRecord> = par_indexed((nt * ns) as u64, |t| {
            let (i, j) = ((t / nt as u64) as usize, t % nt as u64);
            let mut rng = trajectory_rng(derive_seed(base, &format!("strain/{i}")), j);
            run.simulate_coupled(i, dt * tau1, burn, steps, &mut rng)
        })?;
        for (i, &r) in opts.strain_ratios.iter().enumerate() {
            let pairs = &recs[i * nt..(i + 1) * nt];
            let diffs: Vec<f64> = pairs
                .iter()
                .map(|p| p.difference_sum / p.steps as f64)
                .collect();
            let (difference, std_error, p_value) = mean_test(&diffs)?;
            let means = |f: fn(&CoupledRecord) -> f64| -> Result<(f64, f64)> {
                let v: Vec<f64> = pairs.iter().map(|p| f(p) / p.steps as f64).collect();
                let (m, se, _) = mean_test(&v)?;
                Ok((m, se))
            };
            let (coarse_mean, coarse_se) = means(|p| p.coarse_sum)?;
            let (_, fine_se) = means(|p| p.fine_sum)?;
            points.push(CoupledPoint {
                strain_ratio: r,
                dt_tau1: dt,
                difference,
                std_error,
                p_value,
                coarse_mean,
                independent_std_error: coarse_se.hypot(fine_se),
                predicted: snap(predicted[k][i] - predicted[k + 1][i]),
            });
        }
        if opts.progress {
            eprintln!(
                "coupled dt/tau1 = {dt:.3e} and {:.3e}: {}",
                0.5 * dt,
                points[points.len() - ns..]
                    .iter()
                    .map(|p| format!(
                        "eps/eps_c0 = {}: D = {:.3e} +- {:.1e}",
                        Num(p.strain_ratio),
                        p.difference,
                        p.std_error
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            );
        }
    }
    let cpu_seconds = process_cpu_seconds() - cpu0;
    let orders = opts
        .strain_ratios
        .iter()
        .map(|&r| {
            let pts: Vec<&CoupledPoint> = points.iter().filter(|p| p.strain_ratio == r).collect();
            strain_order(r, &pts)
        })
        .collect();
    write(opts, start, provenance, points, orders, cpu_seconds)
}

/// The linear-response prediction of ⟨F⟩/F_c0 at every step (rows) and strain (columns);
/// NaN where the scheme has no discrete law.
fn predictions(opts: &CoupledDtOptions, s: &Scene) -> Result<Vec<Vec<f64>>> {
    let spec = &s.runs[0];
    let dims = Dims::from_u32(s.dims as u32)?;
    opts.dt_tau1
        .iter()
        .map(|&dt| {
            match scheme_force_ratios(
                &s.filament,
                dims,
                s.mesh.elements,
                spec.integrator,
                spec.noise,
                dt * s.tau1(),
                &opts.strain_ratios,
            ) {
                Ok(v) => Ok(v.into_iter().map(|(pred, _)| pred).collect()),
                Err(Error::InvalidParameter { .. }) => Ok(vec![f64::NAN; opts.strain_ratios.len()]),
                Err(e) => Err(e),
            }
        })
        .collect()
}

/// A predicted difference at round-off (|D| < 1e-12 F_c0, e.g. Crank–Nicolson with
/// consistent noise, whose stationary covariance does not depend on Δt) is 0.
fn snap(d: f64) -> f64 {
    if d.abs() < 1e-12 { 0.0 } else { d }
}

/// The weighted power-law fit of |D| against Δt (see the module docs).
fn strain_order(strain_ratio: f64, pts: &[&CoupledPoint]) -> CoupledOrder {
    let dt: Vec<f64> = pts.iter().map(|p| p.dt_tau1).collect();
    let pred: Vec<f64> = pts.iter().map(|p| p.predicted).collect();
    let predicted_order = if pred.iter().all(|v| v.is_finite() && *v != 0.0)
        && pred.iter().all(|v| v.signum() == pred[0].signum())
    {
        let abs: Vec<f64> = pred.iter().map(|v| v.abs()).collect();
        super::converge::fit_order(&dt, &abs, None).map_or(f64::NAN, |f| f.order)
    } else {
        f64::NAN
    };
    let mut out = CoupledOrder {
        strain_ratio,
        order: f64::NAN,
        std_error: f64::NAN,
        ci: None,
        chi2: f64::NAN,
        dof: pts.len().saturating_sub(2),
        fit_p_value: f64::NAN,
        predicted_order,
        expected: EXPECTED_ORDER,
        note: String::new(),
    };
    if let Some(p) = pts.iter().find(|p| {
        p.difference
            .abs()
            .partial_cmp(&(RESOLVED_SIGMAS * p.std_error))
            != Some(std::cmp::Ordering::Greater)
    }) {
        out.note = format!(
            "not resolved: the difference at dt/tau1 = {} is {:.2e} +- {:.1e}, within {RESOLVED_SIGMAS} s.e. of 0 (more or longer pairs resolve it)",
            Num(p.dt_tau1),
            p.difference,
            p.std_error
        );
        return out;
    }
    if pts
        .iter()
        .any(|p| p.difference.signum() != pts[0].difference.signum())
    {
        out.note = "not resolved: the differences change sign (no single power law)".into();
        return out;
    }
    let fit: Vec<(f64, f64, f64)> = pts
        .iter()
        .map(|p| {
            (
                p.dt_tau1.ln(),
                p.difference.abs().ln(),
                (p.difference / p.std_error).powi(2),
            )
        })
        .collect();
    let Some(line) = weighted_line(&fit) else {
        out.note = "not resolved: a single step (no spread in dt)".into();
        return out;
    };
    out.order = line.slope;
    out.std_error = line.sxx.sqrt().recip();
    out.ci = Some((
        out.order - Z95 * out.std_error,
        out.order + Z95 * out.std_error,
    ));
    out.chi2 = line.rss;
    if out.dof > 0 {
        out.fit_p_value = ChiSquared::new(out.dof as f64).map_or(f64::NAN, |c| c.sf(out.chi2));
    }
    out
}

/// Writes the output set and returns the summary.
fn write(
    opts: &CoupledDtOptions,
    start: Instant,
    provenance: Provenance,
    points: Vec<CoupledPoint>,
    orders: Vec<CoupledOrder>,
    cpu_seconds: f64,
) -> Result<CoupledDtSummary> {
    let stem = stem(opts);
    let report = StudyReport::begin(&opts.out, "converge", &stem, provenance)?;
    report.write(&format!("{stem}.csv"), points_csv(&points).as_bytes())?;
    report.write_svg(&format!("{stem}.svg"), &figure(opts, &points))?;
    let spec = &opts.scene.runs[opts.run];
    let summary = CoupledDtSummary {
        run_id: report.run_id(),
        scene: opts.scene.name.clone(),
        run: spec.name.clone(),
        integrator: spec.integrator.name().to_string(),
        noise: spec.noise.name().to_string(),
        seed: opts.scene.seed,
        elements: opts.scene.mesh.elements,
        dims: opts.scene.dims,
        dt_tau1: opts.dt_tau1.clone(),
        strain_ratios: opts.strain_ratios.clone(),
        trajectories: opts.trajectories,
        duration_tau1: opts.duration_tau1,
        burn_in_tau1: opts
            .scene
            .compression
            .as_ref()
            .map_or(0.0, |c| c.burn_in_tau1),
        points,
        orders,
        cpu_seconds,
        threads: rayon::current_num_threads(),
        files: report.files(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    report.complete(&summary)?;
    Ok(summary)
}

/// The points as CSV (one row per step pair and strain).
fn points_csv(points: &[CoupledPoint]) -> String {
    let mut s = String::from(
        "strain_ratio,dt_tau1,fine_dt_tau1,difference,std_error,p_value,coarse_mean,independent_std_error,predicted\n",
    );
    for p in points {
        s.push_str(&format!(
            "{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            p.strain_ratio,
            p.dt_tau1,
            0.5 * p.dt_tau1,
            p.difference,
            p.std_error,
            p.p_value,
            p.coarse_mean,
            p.independent_std_error,
            p.predicted
        ));
    }
    s
}

/// |D| against Δt (log–log) per strain, ±1 s.e., with the prediction dashed.
fn figure(opts: &CoupledDtOptions, points: &[CoupledPoint]) -> Figure {
    let spec = &opts.scene.runs[opts.run];
    let mut fig = Figure::new(
        format!(
            "{} / {}: ⟨F⟩_Δt − ⟨F⟩_Δt/2 from coupled pairs",
            opts.scene.name, spec.name
        ),
        "coarse step Δt/τ₁",
        "|⟨F⟩_Δt − ⟨F⟩_Δt/2| / F_c0",
    )
    .log_x()
    .log_y()
    .caption(format!(
        "The difference of ⟨F⟩ between a step and its half ({} with {} noise), measured \
         by {} pairs of trajectories per step and strain driven by the same Brownian path \
         ({} τ₁ each after a burn-in at the coarse step), ±1 s.e. (log–log; a strain with a \
         difference within {RESOLVED_SIGMAS} s.e. of 0 gets no fitted order). Its slope is the order of the \
         scheme's time-step error of ⟨F⟩ (expected {EXPECTED_ORDER} as Δt → 0). Dashed: the \
         linear-response prediction of the scheme's exact discrete stationary covariance.",
        spec.integrator.name(),
        spec.noise.name(),
        opts.trajectories,
        Num(opts.duration_tau1)
    ));
    for (c, &r) in opts.strain_ratios.iter().enumerate() {
        let pts: Vec<&CoupledPoint> = points.iter().filter(|p| p.strain_ratio == r).collect();
        let shown: Vec<&&CoupledPoint> = pts.iter().filter(|p| p.difference != 0.0).collect();
        fig = fig.series(
            Series::line(
                format!("ε/ε_c0 = {}", Num(r)),
                shown
                    .iter()
                    .map(|p| (p.dt_tau1, p.difference.abs()))
                    .collect(),
            )
            .with_style(SeriesStyle::LineMarkers)
            .with_errors(shown.iter().map(|p| p.std_error).collect())
            .palette(c),
        );
        let pred: Vec<(f64, f64)> = pts
            .iter()
            .filter(|p| p.predicted.is_finite() && p.predicted != 0.0)
            .map(|p| (p.dt_tau1, p.predicted.abs()))
            .collect();
        if !pred.is_empty() {
            // |·| on a log axis hides the sign: name it where it differs from the data's.
            let flipped = pts
                .iter()
                .any(|p| p.predicted.is_finite() && p.predicted.signum() != p.difference.signum());
            let sign = if flipped { " (opposite sign)" } else { "" };
            fig = fig.series(
                Series::line(format!("prediction{sign}, ε/ε_c0 = {}", Num(r)), pred)
                    .dashed()
                    .palette(c),
            );
        }
    }
    fig
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(dt: f64, d: f64, se: f64) -> CoupledPoint {
        CoupledPoint {
            strain_ratio: 0.0,
            dt_tau1: dt,
            difference: d,
            std_error: se,
            p_value: 0.0,
            coarse_mean: 0.0,
            independent_std_error: 0.0,
            predicted: d,
        }
    }

    #[test]
    fn the_order_of_an_exact_power_law_is_recovered_with_zero_chi2() {
        let pts: Vec<CoupledPoint> = [1e-3, 5e-4, 2.5e-4]
            .iter()
            .map(|&dt| point(dt, -3.0 * dt * dt, 0.01 * dt * dt))
            .collect();
        let refs: Vec<&CoupledPoint> = pts.iter().collect();
        let o = strain_order(1.0, &refs);
        assert!((o.order - 2.0).abs() < 1e-12, "{o:?}");
        assert!((o.predicted_order - 2.0).abs() < 1e-12);
        assert!(o.chi2 < 1e-20 && o.note.is_empty());
        // s.e. of the slope with relative errors 0.01/3 at three points ln 2 apart.
        let w = (300.0f64).powi(2);
        let expected = (w * 2.0 * 2f64.ln().powi(2)).sqrt().recip();
        assert!((o.std_error / expected - 1.0).abs() < 1e-12);
    }

    /// A filament whose stretching barely feeds back (EA L²/EI = 1, ε = 0: F/F_c0 ~ 1e-4,
    /// the stretching tilt exp(−EA L s²/2kT) within 1e-4 of 1) samples the Gaussian of its
    /// linear scheme, whose ⟨F⟩ = EA(ε − ⟨s⟩) at each step is exact
    /// ([`crate::theory::scheme_law`]): explicit Euler with consistent noise near its
    /// stability limit (the stiff modes' 1/(1 − λΔt/2)). The coupled differences match the
    /// exact ones within 4 s.e. and reject a difference 20 % off; the coupling cuts the
    /// standard error well below that of independent trajectories.
    #[test]
    fn coupled_differences_match_the_exact_law_of_a_linear_scheme() {
        let dir = std::env::temp_dir().join(format!("lfem-coupled-{}", std::process::id()));
        let mut scene = crate::scene::load_scene("fig2-paper-2d", None).unwrap();
        scene.mesh.elements = 4;
        scene.filament.stretch_rigidity = scene.filament.bending_rigidity;
        scene.runs[0].noise = crate::fem::noise::NoiseModel::Consistent;
        let limit = default_steps(&scene, 0).unwrap()[0] / DEFAULT_LIMIT_FRACTIONS[0];
        let opts = CoupledDtOptions {
            scene,
            run: 0,
            dt_tau1: vec![0.8 * limit, 0.4 * limit, 0.2 * limit],
            strain_ratios: vec![0.0],
            trajectories: 16,
            duration_tau1: 0.5,
            out: dir.clone(),
            progress: false,
            limits: WorkLimits::default(),
        };
        let s = run_coupled_dt(&opts).unwrap();
        assert_eq!(s.points.len(), 2);
        for p in &s.points {
            let z = (p.difference - p.predicted) / p.std_error;
            assert!(z.abs() < 4.0, "{p:?}: z = {z}");
            let z_wrong = (p.difference - 1.2 * p.predicted) / p.std_error;
            assert!(
                z_wrong.abs() > 4.0,
                "{p:?}: z = {z_wrong} against 1.2 x the exact"
            );
            assert!(p.independent_std_error > 10.0 * p.std_error, "{p:?}");
        }
        assert!(dir.join("fig2-paper-2d-paper-coupled-dt.json").exists());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn bad_options_are_refused_naming_the_flag() {
        let scene = crate::scene::load_scene("fig2-paper-2d", None).unwrap();
        let base = CoupledDtOptions {
            scene,
            run: 0,
            dt_tau1: vec![4e-6, 2e-6, 1e-6],
            strain_ratios: vec![0.0],
            trajectories: 4,
            duration_tau1: 0.01,
            out: std::env::temp_dir(),
            progress: false,
            limits: WorkLimits::default(),
        };
        let refused = |o: &CoupledDtOptions, flag: &str| match validate(o) {
            Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, flag),
            other => panic!("{flag}: {other:?}"),
        };
        let mut o = base.clone();
        o.dt_tau1 = vec![4e-6, 3e-6, 1e-6];
        refused(&o, "--values");
        o.dt_tau1 = vec![4e-6, 2e-6];
        refused(&o, "--values");
        let mut o = base.clone();
        o.scene.runs[0].integrator = IntegratorKind::MetropolisCrankNicolson;
        refused(&o, "--integrator");
        let mut o = base.clone();
        o.strain_ratios.clear();
        refused(&o, "--strain-ratios");
        let mut o = base.clone();
        o.trajectories = 2;
        refused(&o, "--trajectories");
        let mut o = base;
        o.scene = crate::scene::load_scene("hinged-linear-2d", None).unwrap();
        refused(&o, "--scene");
    }

    #[test]
    fn an_unresolved_or_sign_changing_difference_gives_no_order() {
        let pts = [point(1e-3, 1e-4, 1e-5), point(5e-4, 2e-5, 1e-5)];
        let o = strain_order(0.0, &pts.iter().collect::<Vec<_>>());
        assert!(
            o.order.is_nan() && o.note.contains("within 3 s.e."),
            "{o:?}"
        );
        let pts = [point(1e-3, 1e-4, 1e-6), point(5e-4, -2e-5, 1e-7)];
        let o = strain_order(0.0, &pts.iter().collect::<Vec<_>>());
        assert!(o.order.is_nan() && o.note.contains("change sign"), "{o:?}");
    }
}
