//! Convergence of the compression scenes (`langevin-fem converge --scene compression-2d`):
//! the mean compressive force ⟨F⟩/F_c0 at imposed strains ε/ε_c0 (the paper's Fig. 2)
//! over the element count or the time step.
//!
//! References, all from the exact equilibrium theory ([`crate::theory::compression`], no
//! simulation):
//!
//! - `--over elements`: the limit is the continuum theory; the exact discrete reference is
//!   the theory of the discretized filament with the same element count and energy (the
//!   element-mean von Kármán strain, u eliminated). Their difference is the
//!   discretization error. Its leading term is O(h): the stored-length weights of the
//!   unresolved modes are missing, ⟨s⟩_h = ⟨s⟩(1 − 2h/5L) for the free filament. Deep in
//!   the 3D post-buckled regime that term is exponentially small and the error of the
//!   discrete buckling load, F_1^h − F_c0 ∝ h⁴, dominates over practical meshes. The
//!   expected order of each strain is decided from the exact references before any
//!   simulation ([`expected_over_elements`]).
//! - `--over dt`: the limit is the theory of the scene's mesh (the Δt → 0 law). For
//!   `metropolis-crank-nicolson` the stationary law is exact at any Δt, so the discrete
//!   reference equals the limit and every error is sampling noise. For the θ-schemes with
//!   an explicit stretching force (`--integrator crank-nicolson`, `backward-euler`) the
//!   stationary bias is O(Δt) and has no closed form: there is no discrete reference and
//!   the observed order is compared with 1. Their stability depends on the state (a large
//!   stored length makes the explicit stretching force stiff), so a too-large Δt can
//!   diverge after many steps: such a value is recorded as unstable with its step (and a
//!   value whose force series is too short for its correlation time, as failed).
//!
//! Estimates and errors are those of the verification runs
//! ([`crate::scene::compression::force_estimates`]): per trajectory the time average of
//! F with an integrated-autocorrelation-time error, trajectories independent.

use super::shard::{Outcome, Source};
use super::{ConvergeOptions, Expected, FailedValue, Over, Row, Study, validate_values};
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::mesh::Mesh;
use crate::rng::derive_seed;
use crate::scene::compression::{
    CONTINUUM_MODES, CompressionRun, ForceEstimates, ForceRecord, force_estimates_diagnosed,
};
use crate::scene::linear::small_slope_warning;
use crate::scene::{CompressionSpec, Ensemble, RunSpec, Scene};
use crate::theory::compression::{
    CompressionTheory, Dims, StoredLengthLaw, buckling_load_discrete,
};
use serde::Serialize;
use std::time::Instant;

/// Default strains ε/ε_c0 of a compression study: tension (0), the Euler strain (1), the
/// 2D force peak (3) and the post-buckled regime (10).
pub const DEFAULT_STRAIN_RATIOS: [f64; 4] = [0.0, 1.0, 3.0, 10.0];
/// Default element counts of `--over elements`.
pub const DEFAULT_ELEMENTS: [usize; 4] = [5, 10, 20, 40];
/// Default Δt/τ1 of `--over dt` for `metropolis-crank-nicolson` (exact at any Δt; the
/// acceptance rate falls as Δt grows).
pub const DEFAULT_METROPOLIS_DT_TAU1: [f64; 4] = [0.04, 0.02, 0.01, 0.005];
/// Default Δt/τ1 of `--over dt` for the θ-schemes with an explicit stretching force: at
/// 10 elements and EA·L/kT = 10⁶, Crank–Nicolson diverged within 4·10⁴ steps at
/// Δt = 7.5·10⁻³ τ1 and 10⁻² τ1.
pub const DEFAULT_THETA_DT_TAU1: [f64; 4] = [0.004, 0.002, 0.001, 0.0005];
/// Absolute accuracy of the exact theory (units of F_c0): an exact error below it is
/// round-off of the quadrature (the tests hold the theory to about 10⁻¹⁰).
pub const THEORY_ROUNDING: f64 = 1e-9;
/// Over elements, a strain's expected order is 1 if the exact error exceeds this multiple
/// of the buckling-load error |F_1^h/F_c0 − 1| at every value ...
pub const ORDER_ONE_RATIO: f64 = 10.0;
/// ... and 4 if it stays below this multiple at every value; otherwise no single order
/// applies over the values studied (the crossover).
pub const ORDER_FOUR_RATIO: f64 = 2.0;
/// Allowed imposed strains ε/ε_c0 of `--strain-ratios`.
pub const STRAIN_RANGE: (f64, f64) = (-100.0, 1000.0);

/// The observable name of strain ratio `r`.
pub fn observable_name(r: f64) -> String {
    format!("F(eps/eps_c0={r})")
}

/// The exact references of one value of a compression study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompressionPoint {
    /// The value (element count or Δt/τ1).
    pub value: f64,
    /// h: L/elements, or Δt/τ1.
    pub h: f64,
    /// Exact ⟨F⟩/F_c0 of this discretization per strain, if known (`None` for the time-step
    /// bias of the θ-schemes).
    pub discrete: Option<Vec<f64>>,
    /// The limit per strain: the continuum (over elements) or the theory of the scene's
    /// mesh (over dt).
    pub limit: Vec<f64>,
    /// Relative error of this mesh's buckling load, F_1^h/F_c0 − 1 (h⁴).
    pub buckling_error: f64,
}

fn dims_of(scene: &Scene) -> Result<Dims> {
    Dims::from_u32(scene.dims as u32)
}

/// ⟨F⟩/F_c0 at `strains` of the filament with `elements` elements (`None`: continuum).
pub(crate) fn theory_forces(
    scene: &Scene,
    elements: Option<usize>,
    strains: &[f64],
) -> Result<Vec<f64>> {
    let p = scene.filament;
    let dims = dims_of(scene)?;
    let law = match elements {
        Some(n) => StoredLengthLaw::discrete(&p, dims, n)?,
        None => StoredLengthLaw::continuum(&p, dims, CONTINUUM_MODES)?,
    };
    let th = CompressionTheory::new(&p, law)?;
    strains.iter().map(|&r| th.force_ratio(r)).collect()
}

/// Whether the run's integrator samples the exact stationary law at any Δt.
fn exact_stationary(kind: IntegratorKind) -> bool {
    kind == IntegratorKind::MetropolisCrankNicolson
}

/// The exact references of every value (no simulation).
///
/// # Errors
/// Invalid values or strains ([`Error::InvalidParameter`]); numerical failures of the
/// theory.
pub fn exact_study(
    scene: &Scene,
    run: usize,
    over: Over,
    values: &[f64],
    strains: &[f64],
) -> Result<Vec<CompressionPoint>> {
    validate_values(over, values)?;
    validate_strains(strains)?;
    let p = scene.filament;
    let integrator = scene.runs[run].integrator;
    let fixed_mesh = match over {
        Over::Dt => Some(theory_forces(scene, Some(scene.mesh.elements), strains)?),
        Over::Elements => None,
    };
    let continuum = match over {
        Over::Elements => Some(theory_forces(scene, None, strains)?),
        Over::Dt => None,
    };
    values
        .iter()
        .map(|&v| {
            let elements = match over {
                Over::Elements => v.round() as usize,
                Over::Dt => scene.mesh.elements,
            };
            let buckling_error = buckling_load_discrete(&p, elements)? / p.euler_load() - 1.0;
            let (discrete, limit, h) = match over {
                Over::Elements => (
                    Some(theory_forces(scene, Some(elements), strains)?),
                    continuum.clone().unwrap_or_default(),
                    p.length / v,
                ),
                Over::Dt => {
                    let l = fixed_mesh.clone().unwrap_or_default();
                    (exact_stationary(integrator).then(|| l.clone()), l, v)
                }
            };
            Ok(CompressionPoint {
                value: v,
                h,
                discrete,
                limit,
                buckling_error,
            })
        })
        .collect()
}

/// The expected order of ⟨F⟩ at strain index `k` over elements, from the exact
/// references: the O(h) stored-length deficit of the unresolved modes, unless the
/// buckling-load error (h⁴) dominates.
pub fn expected_over_elements(
    points: &[CompressionPoint],
    k: usize,
    integrator: IntegratorKind,
) -> Expected {
    let e = |order: Option<f64>, exact: bool, why: String| Expected { order, exact, why };
    if !exact_stationary(integrator) {
        return e(
            None,
            false,
            format!(
                "{integrator}: the explicit stretching force leaves an O(dt) stationary bias at fixed dt that does not vanish as h -> 0 (and its stiffness grows with the resolved modes): no order in h"
            ),
        );
    }
    let ratios: Vec<f64> = points
        .iter()
        .map(|p| {
            let d = p
                .discrete
                .as_ref()
                .map_or(f64::NAN, |d| (d[k] - p.limit[k]).abs());
            d / p.buckling_error.abs()
        })
        .collect();
    let min = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    let max = ratios.iter().copied().fold(0.0, f64::max);
    if min >= ORDER_ONE_RATIO {
        e(
            Some(1.0),
            false,
            format!(
                "the discretized filament lacks the stored length of its unresolved modes (free filament: <s>_h = <s>(1 - 2h/5L)), which shifts <F> = EA(eps - <s>) by O(h); the exact error is >= {min:.0} x the h^4 buckling-load error here"
            ),
        )
    } else if max <= ORDER_FOUR_RATIO {
        e(
            Some(4.0),
            false,
            format!(
                "deep post-buckled: F is pinned to the discrete buckling load F_1^h, whose error converges as h^4 (Hermite-cubic eigenvalues); the O(h) stored-length term is negligible on these meshes (exact error <= {max:.1} x the buckling-load error); order 1 only on much finer meshes"
            ),
        )
    } else {
        e(
            None,
            false,
            format!(
                "crossover: the O(h) stored-length deficit and the h^4 buckling-load error are comparable on these meshes (exact error / buckling-load error from {min:.1} to {max:.1}): no single order"
            ),
        )
    }
}

/// The expected order of ⟨F⟩ over Δt for `integrator`.
pub fn expected_over_dt(integrator: IntegratorKind) -> Expected {
    if exact_stationary(integrator) {
        return Expected {
            order: None,
            exact: true,
            why: "metropolis-crank-nicolson: every proposal is accepted or rejected with the exact Boltzmann weight e^(-U/kT) (detailed balance), so the stationary law of the chain is the exact equilibrium of the discretized filament at any dt: zero error, no order (only the correlation time depends on dt)".to_string(),
        };
    }
    let detail = match integrator {
        IntegratorKind::CrankNicolson => {
            "; at a frozen force F a mode of rate lambda and buckling load F_k has its stationary variance multiplied by 1/(1 + lambda dt F/(2 F_k)) (Crank-Nicolson is exact on the bending part): O(dt) with a coefficient that grows with the resolved modes (lambda/F_k ~ k^2), and in tension (F < 0) the factor diverges at lambda dt |F|/(2 F_k) = 1, the state-dependent stability limit, so near it the bias grows faster than linearly"
        }
        IntegratorKind::BackwardEuler => {
            "; backward Euler's bending part adds its own O(lambda dt) bias and freezes the fast modes"
        }
        IntegratorKind::EulerMaruyama
        | IntegratorKind::ExactModal
        | IntegratorKind::MetropolisCrankNicolson => "",
    };
    Expected {
        order: Some(1.0),
        exact: false,
        why: format!(
            "{integrator} with the stretching force F(w) G w explicit: a first-order (weak) approximation of the stationary law, bias O(dt), largest in tension{detail}"
        ),
    }
}

/// Default values of a compression study.
pub fn default_values(scene: &Scene, run: usize, over: Over) -> Vec<f64> {
    match over {
        Over::Elements => DEFAULT_ELEMENTS.iter().map(|&n| n as f64).collect(),
        Over::Dt if exact_stationary(scene.runs[run].integrator) => {
            DEFAULT_METROPOLIS_DT_TAU1.to_vec()
        }
        Over::Dt => DEFAULT_THETA_DT_TAU1.to_vec(),
    }
}

/// Validates the strains of a study: at least one, finite, in [`STRAIN_RANGE`], distinct.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--strain-ratios`.
pub fn validate_strains(strains: &[f64]) -> Result<()> {
    let (lo, hi) = STRAIN_RANGE;
    if strains.is_empty() {
        return Err(Error::invalid(
            "--strain-ratios",
            "(none)",
            "at least one strain ratio",
        ));
    }
    for (i, &r) in strains.iter().enumerate() {
        if !(r.is_finite() && (lo..=hi).contains(&r)) {
            return Err(Error::invalid(
                "--strain-ratios",
                r,
                format!("finite strain ratios eps/eps_c0 in [{lo}, {hi}]"),
            ));
        }
        if strains[..i].contains(&r) {
            return Err(Error::invalid(
                "--strain-ratios",
                r,
                "distinct strain ratios (this one is repeated)",
            ));
        }
    }
    Ok(())
}

/// Rebuilds compression scene `scene` for one value: the element count (or the run's
/// Δt/τ1), the studied strains, no distribution strains and no halving pair.
pub fn rebuild(scene: &Scene, run: usize, over: Over, value: f64, strains: &[f64]) -> Scene {
    let mut s = scene.clone();
    match over {
        Over::Elements => s.mesh.elements = value.round() as usize,
        Over::Dt => s.runs[run].dt_tau1 = value,
    }
    if let Some(c) = s.compression.as_mut() {
        c.strain_ratios = strains.to_vec();
        c.distribution_strain_ratios.clear();
        c.halving = None;
    }
    s
}

/// Prepares run `run` for one value, reporting an unstable (explicit) time step against
/// `--values`.
fn prepare(
    scene: &Scene,
    run: usize,
    over: Over,
    value: f64,
    strains: &[f64],
) -> Result<(Scene, CompressionRun)> {
    let s = rebuild(scene, run, over, value, strains);
    let spec = s.runs[run].clone();
    let comp = s.compression.clone().ok_or_else(|| {
        Error::invalid(
            "--scene",
            &s.name,
            "a compression scene with a [compression] table",
        )
    })?;
    // Compression scenes require a uniform mesh (the exact theory's closed form).
    Mesh::uniform(s.filament.length, s.mesh.elements)?;
    let cr = CompressionRun::prepare(&s, &comp, &spec).map_err(|e| match e {
        Error::UnstableTimeStep { limit, .. } => Error::invalid(
            "--values",
            value,
            format!(
                "a step below the stability limit of {} with {} elements ({:.4e} tau1), or a stable integrator such as metropolis-crank-nicolson",
                spec.integrator,
                s.mesh.elements,
                limit / s.tau1()
            ),
        ),
        other => other,
    })?;
    Ok((s, cr))
}

/// Runs the compression study of `scene` (with run `run` already carrying any integrator
/// override).
///
/// # Errors
/// Bad values or strains (exit 2); numerical failures (exit 3). A diverged value is
/// recorded, not fatal.
pub(super) fn study(
    scene: &Scene,
    run: usize,
    opts: &ConvergeOptions,
    ensemble: Ensemble,
    source: &mut Source<'_>,
) -> Result<Study> {
    let over = opts.over;
    let spec = &scene.runs[run];
    let (strains, values) = strains_and_values(scene, run, opts)?;
    let work = super::projected_work(scene, run, opts, ensemble, &values, Some(&strains));
    opts.limits.check(&work.scaled(source.fraction()))?;
    // Everything that can be refused is checked before any simulation.
    let prepared = values
        .iter()
        .map(|&v| prepare(scene, run, over, v, &strains))
        .collect::<Result<Vec<_>>>()?;
    let points = exact_study(scene, run, over, &values, &strains)?;
    let names: Vec<String> = strains.iter().map(|&r| observable_name(r)).collect();
    let expected: Vec<Expected> = (0..strains.len())
        .map(|k| match over {
            Over::Elements => expected_over_elements(&points, k, spec.integrator),
            Over::Dt => expected_over_dt(spec.integrator),
        })
        .collect();
    let Some(comp) = scene.compression.clone() else {
        return Err(Error::invalid(
            "--scene",
            &scene.name,
            "a compression scene with a [compression] table",
        ));
    };
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    let mut notes = Vec::new();
    let mut largest_slope: Option<(String, (f64, f64))> = None;
    for (((s, cr), point), &v) in prepared.iter().zip(&points).zip(&values) {
        let t0 = Instant::now();
        let (est, records) =
            match value_records((scene, s), cr, &spec.name, (over, v), ensemble, source)? {
                Outcome::Records(r) => match force_estimates_diagnosed(&r, &s.filament) {
                    Ok(est) => (est, r),
                    Err(e) => {
                        failed.push(record_failure(scene, spec, opts, v, e)?);
                        continue;
                    }
                },
                Outcome::Written => continue,
                Outcome::Failed(f) => {
                    failed.push(announce_failure(scene, spec, opts, f));
                    continue;
                }
            };
        let slope = cr.largest_rms_slope(&records);
        notes.push(value_note(
            over,
            v,
            spec.integrator,
            &est,
            &comp,
            slope,
            &strains,
        ));
        if let Some((sl, x, i)) = slope
            && largest_slope.as_ref().is_none_or(|l| sl > l.1.0)
        {
            largest_slope = Some((
                format!("{}={v} at strain ratio {}", over.name(), strains[i]),
                (sl, x),
            ));
        }
        rows.extend(point_rows(&names, point, &est));
        if opts.progress {
            eprintln!(
                "{}",
                progress_line(scene, spec, (over, v), strains.len(), ensemble, t0)
            );
        }
    }
    let warnings = largest_slope
        .and_then(|(what, slope)| small_slope_warning(&what, slope, &scene.filament))
        .into_iter()
        .collect();
    let (limit_reference, fixed) = texts(scene, spec, over, &comp);
    Ok(Study {
        values,
        names,
        expected,
        rows,
        limit_reference,
        fixed,
        failed,
        notes,
        warnings,
    })
}

/// The progress line of value `v` of a study, simulated since `t0`.
fn progress_line(
    scene: &Scene,
    spec: &RunSpec,
    (over, v): (Over, f64),
    strains: usize,
    ensemble: Ensemble,
    t0: Instant,
) -> String {
    format!(
        "converge {} {} ({}): {}={v}: {strains} strains x {} trajectories x {} tau1, {:.1} s",
        scene.name,
        spec.name,
        spec.integrator,
        over.name(),
        ensemble.trajectories,
        ensemble.duration_tau1,
        t0.elapsed().as_secs_f64()
    )
}

/// Records the failure of value `v` ([`FailedValue::record`]), with a progress line.
///
/// # Errors
/// `e` itself unless it is a divergence or an estimator failure.
fn record_failure(
    scene: &Scene,
    spec: &RunSpec,
    opts: &ConvergeOptions,
    v: f64,
    e: Error,
) -> Result<FailedValue> {
    Ok(announce_failure(
        scene,
        spec,
        opts,
        FailedValue::record(v, e)?,
    ))
}

/// `f` with its progress line.
fn announce_failure(
    scene: &Scene,
    spec: &RunSpec,
    opts: &ConvergeOptions,
    f: FailedValue,
) -> FailedValue {
    let v = f.value;
    if opts.progress {
        eprintln!(
            "converge {} {}: {}={v}: {}: {}",
            scene.name,
            spec.name,
            opts.over.name(),
            f.kind,
            f.error
        );
    }
    f
}

/// The strains and values of a study (the options' or the defaults), validated; the
/// values largest h first.
fn strains_and_values(
    scene: &Scene,
    run: usize,
    opts: &ConvergeOptions,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let over = opts.over;
    let strains = opts
        .strain_ratios
        .clone()
        .unwrap_or_else(|| DEFAULT_STRAIN_RATIOS.to_vec());
    validate_strains(&strains)?;
    let mut values = match &opts.values {
        Some(v) => v.clone(),
        None => default_values(scene, run, over),
    };
    validate_values(over, &values)?;
    values.sort_by(|a, b| match over {
        Over::Elements => a.total_cmp(b),
        Over::Dt => b.total_cmp(a),
    });
    Ok((strains, values))
}

/// The records of one value of the study of `scene` (`s`, `cr` prepared for it; one
/// seed per trajectory, from the run's name and the value), from `source`: simulated,
/// this shard's share written, or every shard's read ([`super::shard`]).
///
/// # Errors
/// As [`Source::force`] (a divergence is an [`Outcome::Failed`], not an error).
fn value_records(
    (scene, s): (&Scene, &Scene),
    cr: &CompressionRun,
    run_name: &str,
    (over, v): (Over, f64),
    ensemble: Ensemble,
    source: &mut Source<'_>,
) -> Result<Outcome<Vec<Vec<ForceRecord>>>> {
    let steps = vec![cr.sampled_steps(ensemble.duration_tau1 * s.tau1()); cr.points()];
    let label = super::seed_label(run_name, over, v);
    source.force((scene, run_name, over, v), (&ensemble, cr), |range| {
        cr.simulate_share_per_point(
            |i| derive_seed(s.seed, &format!("{label}/{i}")),
            range,
            &steps,
            || {},
        )
    })
}

/// The note of one value: acceptance (Metropolis), correlation time of F and largest RMS
/// slope.
fn value_note(
    over: Over,
    v: f64,
    integrator: IntegratorKind,
    est: &ForceEstimates,
    comp: &CompressionSpec,
    slope: Option<(f64, f64, usize)>,
    strains: &[f64],
) -> String {
    format!(
        "{}={v}: {}largest integrated autocorrelation time of F {:.1} samples (every {} tau1){}",
        over.name(),
        if exact_stationary(integrator) {
            format!("acceptance {:.4}, ", est.acceptance)
        } else {
            String::new()
        },
        est.max_tau_int,
        comp.sample_every_tau1,
        slope.map_or(String::new(), |(sl, x, i)| format!(
            ", largest RMS slope {sl:.3} rad at x/L = {x:.2} (strain ratio {})",
            strains[i]
        ))
    )
}

/// The rows of one value: one per strain, from its estimates and exact references.
fn point_rows(names: &[String], point: &CompressionPoint, est: &ForceEstimates) -> Vec<Row> {
    names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            Row::new(
                point.value,
                point.h,
                name,
                est.force[k],
                point.discrete.as_ref().map(|d| d[k]),
                point.limit[k],
                THEORY_ROUNDING,
            )
        })
        .collect()
}

/// What the errors of a compression study are measured against, and its fixed
/// parameters.
fn texts(scene: &Scene, spec: &RunSpec, over: Over, comp: &CompressionSpec) -> (String, String) {
    let p = scene.filament;
    match over {
        Over::Elements => (
            format!(
                "continuum exact equilibrium theory of <F>/F_c0 ({}D, EI/(kT L) = {}, EA L/kT = {:e}; {CONTINUUM_MODES} explicit modes plus the exact tail, a Hurwitz-zeta series); the exact discrete reference is the same theory for each mesh",
                scene.dims,
                p.bending_rigidity / (p.kt * p.length),
                p.stretch_rigidity * p.length / p.kt
            ),
            format!(
                "dt_tau1 = {:e}, burn-in {} tau1 per strain",
                spec.dt_tau1, comp.burn_in_tau1
            ),
        ),
        Over::Dt => (
            format!(
                "exact equilibrium theory of <F>/F_c0 of this mesh ({} elements, the dt -> 0 law)",
                scene.mesh.elements
            ),
            format!(
                "elements = {}, burn-in {} tau1 per strain",
                scene.mesh.elements, comp.burn_in_tau1
            ),
        ),
    }
}
