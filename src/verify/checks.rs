//! The statistical checks of a linear run. Each compares an estimate from the ensemble
//! with its exact discrete reference (this discretization, noise, integrator and time
//! step), reports the continuum value beside it, and carries a raw p-value; the runner
//! applies the Holm correction over the scene.

use crate::error::{Error, Result};
use crate::scene::CheckKind;
use crate::scene::linear::{LinearRun, TrajectoryRecord};
use crate::stats::{self, TestOutcome};
use crate::verify::summary::{CheckResult, SkippedCheck};

/// Confidence level of the intervals reported in details.
const CONFIDENCE: f64 = 0.95;
/// Samples for the distribution tests are spaced so that the lag correlation of the mode
/// is at most this (ln 100 ≈ 4.6 relaxation times): residual dependence then changes the
/// null distribution of KS and χ² by far less than their sampling error.
const MAX_THINNED_CORRELATION: f64 = 0.01;
/// Fewest independent series for an error from their spread (Student t); with fewer,
/// the variance and profile checks use the within-series (IAT) error and a z-test, and
/// the symmetry checks are skipped (listed in the notes).
const MIN_SERIES_FOR_T: usize = 4;
/// Welch segment length (samples) of the spectrum check.
pub const SEGMENT_LEN: usize = 64;
/// Shortest Welch segment accepted.
pub const MIN_SEGMENT_LEN: usize = 16;
/// Fewest Welch segments per series.
pub const MIN_SEGMENTS: usize = 8;

/// Per-mode estimates, kept for tables and figures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModeEstimate {
    /// Mode number.
    pub n: usize,
    /// Estimated stationary variance and its standard error.
    pub variance: (f64, f64),
    /// Estimated relaxation rate and its standard error (NaN if not estimated).
    pub rate: (f64, f64),
    /// Welch spectrum: frequencies, estimate, exact expectation (if computed).
    pub spectrum: Option<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

/// Profile and two-time estimates, kept for tables and figures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinearEstimates {
    /// Per mode.
    pub modes: Vec<ModeEstimate>,
    /// ⟨w²(x)⟩ at the profile points: (estimate, std error).
    pub profile: Vec<(f64, f64)>,
    /// ⟨w(x,t)w(y,η)⟩ at the two-time points: (estimate, std error).
    pub two_time: Vec<(f64, f64)>,
    /// Checks that could not be evaluated with this budget's data, and why. They are
    /// listed in the report's notes; they count neither as passed nor as failed.
    pub skipped: Vec<SkippedCheck>,
}

/// The kind of the tests of a Gaussian quadratic form against its null law from the
/// reference: [`stats::ar1_square_sum_test`] for a mode,
/// [`stats::WeightedChiSquares::whittle`] for the profile,
/// [`stats::WeightedChiSquares::product_sum`] for the two-time products.
const QUADRATIC_FORM: &str = "quadratic-form";

/// A check result before the family-wise correction (see [`CheckResult::statistical`]).
fn check(
    name: String,
    kind: &str,
    values: (f64, f64, f64),
    outcome: &TestOutcome,
    continuum: Option<f64>,
    detail: String,
) -> CheckResult {
    CheckResult::statistical(name, kind, values, continuum, outcome, detail)
}

/// The test of an average over independent series against `reference`: a t-test with
/// the error from the spread of the series' averages when there are at least
/// [`MIN_SERIES_FOR_T`] series, else a z-test with the within-series (IAT) errors.
/// `squares` holds per series the squared values whose average is tested. Returns
/// (estimate, error, outcome, kind, how the error was obtained).
fn series_average_test(
    squares: &[Vec<f64>],
    reference: f64,
) -> Result<(f64, f64, TestOutcome, &'static str, String)> {
    if squares.len() < MIN_SERIES_FOR_T {
        let parts = squares
            .iter()
            .map(|s| stats::mean_with_error(s))
            .collect::<Result<Vec<_>>>()?;
        let (mean, se) = stats::combine_independent(&parts);
        let o = stats::z_test(mean, reference, se)?;
        return Ok((
            mean,
            se,
            o,
            "z-test",
            format!("{} series, within-series (IAT) error", parts.len()),
        ));
    }
    // No within-series error is needed (nor estimated: on short series its window search
    // can fail).
    let values: Vec<f64> = squares
        .iter()
        .map(|s| {
            stats::require_samples("series", s, stats::moments::MIN_SERIES_LEN)
                .map(|()| s.iter().sum::<f64>() / s.len() as f64)
        })
        .collect::<Result<_>>()?;
    let between = stats::ensemble_mean(&values)?;
    let o = spread_t_test(between.mean, reference, between.std_error, values.len())?;
    Ok((
        between.mean,
        between.std_error,
        o,
        "t-test",
        format!(
            "{} independent series, error from the spread of their averages (t, {} dof)",
            values.len(),
            values.len() - 1
        ),
    ))
}

/// Student's t-test of the mean of `n` independent values whose error `std_error` is
/// their spread: as [`stats::t_test`], except that values all equal (no spread: identical
/// series, or an amplitude frozen by a simulator that never drives it) are an event of
/// probability zero under the null of a continuous process, so the test fails with
/// p = 0 (statistic ±∞, or 0 at the reference) instead of being a numerical failure.
fn spread_t_test(
    mean: f64,
    reference: f64,
    std_error: f64,
    n: usize,
) -> Result<stats::TestOutcome> {
    if std_error == 0.0 && n >= 2 && mean.is_finite() {
        let d = mean - reference;
        let statistic = if d == 0.0 {
            0.0
        } else {
            d.signum() * f64::INFINITY
        };
        return Ok(stats::TestOutcome {
            statistic,
            p_value: 0.0,
            dof: Some((n - 1) as f64),
        });
    }
    stats::t_test(mean, reference, std_error, n)
}

/// A t-test that independent values (one per trajectory or series) have mean zero: the
/// checks of a symmetry (zero mean, vanishing cross-correlation, time reversal), whose
/// error is estimated from the spread of the independent values, so that it holds for
/// short series too (Student's t with n − 1 degrees of freedom).
fn zero_mean_check(
    ctx: &mut LinearContext<'_>,
    name: String,
    values: &[f64],
    what: &str,
) -> Result<()> {
    if values.len() < MIN_SERIES_FOR_T {
        ctx.est.skipped.push(SkippedCheck {
            name,
            reason: format!(
                "needs at least {MIN_SERIES_FOR_T} independent series, the data have {}",
                values.len()
            ),
        });
        return Ok(());
    }
    let m = stats::ensemble_mean(values)?;
    let o = spread_t_test(m.mean, 0.0, m.std_error, values.len())?;
    ctx.out.push(check(
        name,
        "t-test",
        (m.mean, 0.0, m.std_error),
        &o,
        Some(0.0),
        format!(
            "{what}: mean of {} independent values (one per series), Student t with {} dof",
            values.len(),
            values.len() - 1
        ),
    ));
    Ok(())
}

/// Thinned, effectively independent samples of series pooled over trajectories:
/// every `stride`-th value.
fn thin(series: &[&[f64]], stride: usize) -> Vec<f64> {
    series
        .iter()
        .flat_map(|s| s.iter().step_by(stride.max(1)).copied())
        .collect()
}

/// The data of one linear run the checks read, and what they produce.
struct LinearContext<'a> {
    /// The run (model, exact references, sampling plan).
    run: &'a LinearRun,
    /// The full trajectories.
    records: &'a [TrajectoryRecord],
    /// Two-time products of all trajectories (full and extra short ones).
    two_time: &'a [Vec<f64>],
    /// The check results, in the order of `summary.json`.
    out: Vec<CheckResult>,
    /// Estimates for tables and figures.
    est: LinearEstimates,
}

/// The data of mode `i` the per-mode checks read, and its estimate.
struct ModeData<'a> {
    /// Mode index (0-based).
    i: usize,
    /// The mode's series, one per trajectory and component.
    series: Vec<&'a [f64]>,
    /// Effectively independent samples: every `stride`-th sample of each series.
    thinned: Vec<f64>,
    /// The thinning stride (samples).
    stride: usize,
    /// The exact lag correlation between successive samples, `m^every` (signed).
    lag_correlation: f64,
    /// Time between samples of the series.
    dt_sample: f64,
    /// The mode's estimates, filled by the checks.
    me: ModeEstimate,
}

/// A check run once per run.
type RunCheck = fn(&mut LinearContext<'_>) -> Result<()>;
/// A check run once per mode.
type ModeCheck = fn(&mut LinearContext<'_>, &mut ModeData<'_>) -> Result<()>;

/// When a linear check runs, which also fixes the order of its results in `summary.json`:
/// the run-wide checks before the modes, then mode by mode the per-mode checks (in the
/// order of their rank), then the run-wide checks after the modes.
enum Step {
    /// Once per run, before the per-mode checks.
    BeforeModes(RunCheck),
    /// Once per mode; the rank orders the checks within a mode.
    PerMode(u8, ModeCheck),
    /// Once per run, after the per-mode checks.
    AfterModes(RunCheck),
}

/// The step of a check kind on a linear run: the one dispatch over [`CheckKind`].
///
/// # Errors
/// [`Error::InvalidParameter`] for a compression check (refused for linear scenes by
/// [`crate::scene::Scene::validate`], so not reached from a scene file).
fn linear_step(run: &LinearRun, kind: CheckKind) -> Result<Step> {
    Ok(match kind {
        CheckKind::Profile => Step::BeforeModes(profile_check),
        CheckKind::ModeVariance => Step::PerMode(0, mode_variance_check),
        CheckKind::ModeDistribution => Step::PerMode(1, mode_distribution_check),
        CheckKind::DecayRate => Step::PerMode(2, decay_rate_check),
        CheckKind::Spectrum => Step::PerMode(3, spectrum_checks),
        CheckKind::TwoTime => Step::AfterModes(two_time_check),
        CheckKind::PooledVariance => Step::AfterModes(pooled_variance_check),
        CheckKind::XySymmetry => Step::AfterModes(xy_symmetry_check),
        CheckKind::RigidDiffusion => Step::AfterModes(rigid_diffusion_check),
        CheckKind::TangentAngle => Step::AfterModes(tangent_angle_check),
        CheckKind::ForceStrain | CheckKind::ForceDistribution | CheckKind::DtHalving => {
            return Err(Error::invalid(
                format!("checks of run {}", run.spec.name),
                format!("{kind:?}"),
                "linear checks only (a compression check needs model = \"compression\")",
            ));
        }
    })
}

/// Runs the requested checks of one linear run on the recorded trajectories.
///
/// `records` are the full trajectories; `two_time` holds the two-time products of all
/// trajectories (the full ones and the extra short ones). The results come in a fixed
/// order whatever the order of `checks`: profile; then for each mode its variance,
/// distribution, decay-rate and spectrum checks; then two-time (the private `Step`). A kind
/// listed twice runs once.
///
/// # Errors
/// An estimator's failure on the data (e.g. no self-consistent autocorrelation window, a
/// constant series) as [`Error::RunFailed`] naming the run and the check (and mode); a
/// compression check kind is [`Error::InvalidParameter`].
pub fn linear_checks(
    run: &LinearRun,
    checks: &[CheckKind],
    records: &[TrajectoryRecord],
    two_time: &[Vec<f64>],
) -> Result<(Vec<CheckResult>, LinearEstimates)> {
    let (mut before, mut per_mode, mut after) = (Vec::new(), Vec::new(), Vec::new());
    let mut seen = Vec::new();
    for &kind in checks {
        if seen.contains(&kind) {
            continue;
        }
        seen.push(kind);
        match linear_step(run, kind)? {
            Step::BeforeModes(f) => before.push((kind, f)),
            Step::PerMode(rank, f) => per_mode.push((rank, kind, f)),
            Step::AfterModes(f) => after.push((kind, f)),
        }
    }
    per_mode.sort_by_key(|(rank, _, _)| *rank);
    // An estimator's failure on the run's data is a run failure naming the observable.
    let failed = |what: String, e: Error| Error::run_failed(run.spec.name.clone(), what, e);
    let mut ctx = LinearContext {
        run,
        records,
        two_time,
        out: Vec::new(),
        est: LinearEstimates::default(),
    };
    for (kind, f) in before {
        f(&mut ctx).map_err(|e| failed(format!("{} check", kind_name(kind)), e))?;
    }
    for i in 0..run.reference.modes.len() {
        let mut mode = mode_data(run, records, i);
        for (_, kind, f) in &per_mode {
            f(&mut ctx, &mut mode).map_err(|e| {
                let n = run.reference.modes[i].n;
                failed(format!("{} check of mode {n}", kind_name(*kind)), e)
            })?;
        }
        ctx.est.modes.push(mode.me);
    }
    for (kind, f) in after {
        f(&mut ctx).map_err(|e| failed(format!("{} check", kind_name(kind)), e))?;
    }
    Ok((ctx.out, ctx.est))
}

/// The name of a check kind as in scene files (`mode-variance`).
fn kind_name(kind: CheckKind) -> &'static str {
    match kind {
        CheckKind::Profile => "profile",
        CheckKind::ModeVariance => "mode-variance",
        CheckKind::ModeDistribution => "mode-distribution",
        CheckKind::DecayRate => "decay-rate",
        CheckKind::Spectrum => "spectrum",
        CheckKind::TwoTime => "two-time",
        CheckKind::PooledVariance => "pooled-variance",
        CheckKind::XySymmetry => "xy-symmetry",
        CheckKind::RigidDiffusion => "rigid-diffusion",
        CheckKind::TangentAngle => "tangent-angle",
        CheckKind::ForceStrain => "force-strain",
        CheckKind::ForceDistribution => "force-distribution",
        CheckKind::DtHalving => "dt-halving",
    }
}

/// The series of mode `i` (one per trajectory and component), thinned so that the lag
/// correlation between kept samples is at most [`MAX_THINNED_CORRELATION`].
fn mode_data<'a>(run: &LinearRun, records: &'a [TrajectoryRecord], i: usize) -> ModeData<'a> {
    let nm = run.reference.modes.len();
    let c = run.components;
    let mr = &run.reference.modes[i];
    let series: Vec<&[f64]> = records
        .iter()
        .flat_map(|t| (0..c).map(move |k| t.modes[k * nm + i].as_slice()))
        .collect();
    // Samples between effectively independent samples of this mode.
    let rho_sample = mr.multiplier.abs().powf(run.mode_every[i] as f64);
    let stride = if rho_sample <= MAX_THINNED_CORRELATION {
        1
    } else {
        (MAX_THINNED_CORRELATION.ln() / rho_sample.ln()).ceil() as usize
    };
    let thinned = thin(&series, stride);
    ModeData {
        i,
        series,
        thinned,
        stride,
        lag_correlation: mr
            .multiplier
            .powi(run.mode_every[i].min(i32::MAX as u64) as i32),
        dt_sample: run.mode_dt(i),
        me: ModeEstimate {
            n: mr.n,
            rate: (f64::NAN, f64::NAN),
            ..Default::default()
        },
    }
}

/// [`CheckKind::Profile`]: ⟨w²(x)⟩ at every profile point against the exact discrete
/// profile: the sum of w² over every sample of every series against its null law where
/// the reference knows the field's autocovariance ([`profile_square_sum_test`]), else
/// (data of an unknown discretization) a t-test over the series' averages.
fn profile_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let r = &ctx.run.reference;
    let prefix = &ctx.run.spec.name;
    let c = ctx.run.components;
    let np = r.profile_x.len();
    for j in 0..np {
        let series: Vec<&[f64]> = ctx
            .records
            .iter()
            .flat_map(|t| (0..c).map(move |k| t.profile[k * np + j].as_slice()))
            .collect();
        let (mean, se, o, kind, how) = match r.profile_terms.get(j).filter(|t| !t.is_empty()) {
            Some(terms) => profile_square_sum_test(&series, terms, ctx.run.profile_every)?,
            None => {
                // Per series the squares w²; the series are independent. The error from
                // the spread of the independent series' averages where there are enough:
                // an error estimated within short series (IAT) is itself uncertain and
                // correlated with the estimate, which makes z-tails heavier than normal.
                let squares: Vec<Vec<f64>> = series
                    .iter()
                    .map(|s| s.iter().map(|w| w * w).collect())
                    .collect();
                series_average_test(&squares, r.profile_discrete[j])?
            }
        };
        let x = r.profile_x[j];
        ctx.out.push(check(
            format!("{prefix}/profile/x={x:.4}"),
            kind,
            (mean, r.profile_discrete[j], se),
            &o,
            Some(r.profile_continuum[j]),
            format!("<w^2(x)> over {how}"),
        ));
        ctx.est.profile.push((mean, se));
    }
    if ctx.run.reversible() {
        time_reversal_checks(ctx)?;
    }
    Ok(())
}

/// The sum of w² over every sample of `series` (independent, sampled every `every` steps)
/// against its null law: each series is a stationary Gaussian sequence whose
/// autocovariance after `k` samples is `Σ u_i m_i^{k·every}` (`terms` = `(u_i, m_i)`), so
/// the sum is a Gaussian quadratic form ([`stats::WeightedChiSquares::whittle`],
/// saddle-point tail) whose scale comes from the reference, not from the data under test
/// (issue #30: a wrong profile cannot pass by inflating its own error). Returns what
/// [`series_average_test`] returns.
fn profile_square_sum_test(
    series: &[&[f64]],
    terms: &[(f64, f64)],
    every: u64,
) -> Result<(f64, f64, TestOutcome, &'static str, String)> {
    for (i, s) in series.iter().enumerate() {
        stats::require_samples(&format!("profile series {i}"), s, 1)?;
    }
    let k = every.min(i32::MAX as u64) as i32;
    let sampled: Vec<(f64, f64)> = terms.iter().map(|&(u, m)| (u, m.powi(k))).collect();
    let lengths: Vec<usize> = series.iter().map(|s| s.len()).collect();
    let law = stats::WeightedChiSquares::whittle(&sampled, &lengths)?;
    let (o, mean, se) = stats::square_sum_test(series, &law)?;
    let how = format!(
        "{} series ({} samples), against its null law (Gaussian quadratic form of the \
         {}-term autocovariance, Whittle eigenvalues; saddle-point tail), error from the \
         reference",
        series.len(),
        lengths.iter().sum::<usize>(),
        terms.len()
    );
    Ok((mean, se, o, QUADRATIC_FORM, how))
}

/// Time-reversal symmetry of the stationary process (detailed balance, which holds
/// with consistent noise): ⟨w(x, t+τ) w(y, t)⟩ = ⟨w(y, t+τ) w(x, t)⟩ for every pair of
/// profile points, at τ one profile sample; per series the time average of
/// `w(x,t+τ)w(y,t) − w(y,t+τ)w(x,t)`, t-tested against zero.
fn time_reversal_checks(ctx: &mut LinearContext<'_>) -> Result<()> {
    let r = &ctx.run.reference;
    let prefix = &ctx.run.spec.name;
    let (c, np) = (ctx.run.components, r.profile_x.len());
    for a in 0..np {
        for b in a + 1..np {
            let values: Vec<f64> = ctx
                .records
                .iter()
                .flat_map(|t| {
                    (0..c).map(move |k| {
                        let (x, y) = (&t.profile[k * np + a], &t.profile[k * np + b]);
                        let n = x.len().saturating_sub(1).max(1);
                        (0..x.len().saturating_sub(1))
                            .map(|i| x[i + 1] * y[i] - y[i + 1] * x[i])
                            .sum::<f64>()
                            / n as f64
                    })
                })
                .collect();
            let (x, y) = (r.profile_x[a], r.profile_x[b]);
            zero_mean_check(
                ctx,
                format!("{prefix}/time-reversal/x={x:.4},y={y:.4}"),
                &values,
                "w(x,t+tau)w(y,t) - w(y,t+tau)w(x,t) at tau = one profile sample (zero under detailed balance)",
            )?;
        }
    }
    Ok(())
}

/// [`CheckKind::ModeVariance`]: the stationary variance of a mode against the exact
/// discrete variance, by an autocorrelation-aware z-test and a χ² test on thinned samples.
fn mode_variance_check(ctx: &mut LinearContext<'_>, m: &mut ModeData<'_>) -> Result<()> {
    let mr = &ctx.run.reference.modes[m.i];
    let prefix = &ctx.run.spec.name;
    // The variance about the known mean 0: the sum of q² over every sample of every series
    // against its exact null law. Each series of a linear scheme's modal amplitude is a
    // stationary Gaussian AR(1) sequence with the discrete variance and lag correlation
    // m^every (m the one-step multiplier), so the null law, its scale included, comes from
    // the reference: a wrong variance cannot pass by inflating its own error (issue #30).
    let rho = m.lag_correlation;
    let (o, mean, se) = stats::ar1_square_sum_test(&m.series, mr.variance_discrete, rho)?;
    m.me.variance = (mean, se);
    ctx.out.push(check(
        format!("{prefix}/mode-variance/n={}", mr.n),
        QUADRATIC_FORM,
        (mean, mr.variance_discrete, se),
        &o,
        Some(mr.variance_continuum),
        format!(
            "time average of q^2 over {} series ({} samples), against its exact null law \
             (stationary Gaussian AR(1), lag correlation {rho:.4}; saddle-point tail), error \
             from the reference; ratio to equipartition {:.4}",
            m.series.len(),
            m.series.iter().map(|s| s.len()).sum::<usize>(),
            mean / mr.variance_equipartition
        ),
    ));
    let means: Vec<f64> = m
        .series
        .iter()
        .map(|s| s.iter().sum::<f64>() / s.len() as f64)
        .collect();
    zero_mean_check(
        ctx,
        format!("{prefix}/mode-mean/n={}", mr.n),
        &means,
        "time average of the mode amplitude (zero in equilibrium)",
    )?;
    if ctx.run.components == 2 {
        // The series alternate between the two transverse components of a trajectory.
        let cross: Vec<f64> = m
            .series
            .chunks_exact(2)
            .map(|p| p[0].iter().zip(p[1]).map(|(a, b)| a * b).sum::<f64>() / p[0].len() as f64)
            .collect();
        zero_mean_check(
            ctx,
            format!("{prefix}/mode-cross/n={}", mr.n),
            &cross,
            "time average of the product of the two transverse components' amplitudes (independent in equilibrium)",
        )?;
    }
    let thinned = &m.thinned;
    let o = stats::chi2_variance_test(thinned, mr.variance_discrete, Some(0.0))?;
    let s2 = thinned.iter().map(|q| q * q).sum::<f64>() / thinned.len() as f64;
    ctx.out.push(check(
        format!("{prefix}/mode-variance-chi2/n={}", mr.n),
        "chi2-variance",
        (
            s2,
            mr.variance_discrete,
            mr.variance_discrete * (2.0 / thinned.len() as f64).sqrt(),
        ),
        &o,
        Some(mr.variance_continuum),
        format!(
            "{} samples spaced {} samples apart (lag correlation <= 0.01)",
            thinned.len(),
            m.stride
        ),
    ));
    Ok(())
}

/// [`CheckKind::ModeDistribution`]: the amplitude distribution of a mode against the
/// normal law of the exact discrete variance (KS and χ² goodness of fit, thinned samples;
/// the χ² bins grow with the sample as [`stats::gof_bins`] says).
fn mode_distribution_check(ctx: &mut LinearContext<'_>, m: &mut ModeData<'_>) -> Result<()> {
    let mr = &ctx.run.reference.modes[m.i];
    let prefix = &ctx.run.spec.name;
    let thinned = &m.thinned;
    let sd = mr.variance_discrete.sqrt();
    let o = stats::ks_normal(thinned, 0.0, sd)?;
    ctx.out.push(check(
        format!("{prefix}/mode-ks/n={}", mr.n),
        "ks",
        (f64::NAN, f64::NAN, f64::NAN),
        &o,
        None,
        format!(
            "KS distance to N(0, {:.4e}) over {} thinned samples",
            mr.variance_discrete,
            thinned.len()
        ),
    ));
    let bins = stats::gof_bins(thinned.len());
    // Data too short for the fewest bins (4, each expecting 5 samples): the χ² is
    // skipped, noted, and the KS above stands (`verify` refuses such budgets up front).
    if thinned.len() < 5 * bins {
        ctx.est.skipped.push(SkippedCheck {
            name: format!("{prefix}/mode-chi2-gof/n={}", mr.n),
            reason: format!(
                "needs at least {} thinned samples ({bins} equiprobable bins expecting 5 each), the data have {}",
                5 * bins,
                thinned.len()
            ),
        });
        return Ok(());
    }
    let o = stats::chi2_gof_normal(thinned, 0.0, sd, bins)?;
    ctx.out.push(check(
        format!("{prefix}/mode-chi2-gof/n={}", mr.n),
        "chi2-gof",
        (f64::NAN, f64::NAN, f64::NAN),
        &o,
        None,
        format!(
            "chi^2 over {bins} equiprobable bins, {} thinned samples",
            thinned.len()
        ),
    ));
    Ok(())
}

/// [`CheckKind::DecayRate`]: the autocorrelation decay rate of a mode against the exact
/// discrete rate, if the mode has one; skipped (noted) if the data cannot resolve it.
/// The error is a delete-one-block jackknife over B blocks, so the statistic is referred
/// to Student's t with B − 1 degrees of freedom, as the estimate's own interval is: a
/// normal reference over-rejected (1.5 % of p-values below 0.01 at B = 32, the
/// t₃₁ tail; statistics.md).
fn decay_rate_check(ctx: &mut LinearContext<'_>, m: &mut ModeData<'_>) -> Result<()> {
    let mr = &ctx.run.reference.modes[m.i];
    let prefix = &ctx.run.spec.name;
    let Some(rate_ref) = mr.rate_discrete else {
        return Ok(());
    };
    // The lag comes from the reference's rate, not from the data: whether the check runs
    // must not depend on how fast this sample happens to decay (statistics.md). Data that
    // decay far faster than the reference (ρ̂ not positive at its lag) get the pilot's lag,
    // so that they fail rather than skip.
    let lag = stats::LagRule::Expected(rate_ref);
    match stats::decay_rate_with_lag(&m.series, m.dt_sample, Some(0.0), CONFIDENCE, lag) {
        Ok(re) => {
            m.me.rate = (re.rate, re.std_error);
            let o = spread_t_test(re.rate, rate_ref, re.std_error, re.n_blocks)?;
            let mut c = check(
                format!("{prefix}/decay-rate/n={}", mr.n),
                "t-test",
                (re.rate, rate_ref, re.std_error),
                &o,
                Some(mr.rate_continuum),
                format!(
                    "-ln rho(k)/(k dt) at lag {}{}, {} jackknife blocks, 95% CI [{:.4e}, {:.4e}]",
                    re.lag,
                    if re.lag_from_data {
                        " (from the data: at the reference's lag rho(k) was not positive)"
                    } else {
                        ""
                    },
                    re.n_blocks,
                    re.ci_low,
                    re.ci_high
                ),
            );
            c.variance_correlation = re
                .variance_correlation
                .is_finite()
                .then_some(re.variance_correlation);
            ctx.out.push(c);
        }
        Err(e) => ctx.est.skipped.push(SkippedCheck {
            name: format!("{prefix}/decay-rate/n={}", mr.n),
            reason: e.to_string(),
        }),
    }
    Ok(())
}

/// [`CheckKind::Spectrum`]: the Welch spectrum of a mode with a positive multiplier
/// against its exact expectation ([`spectrum_check`]); skipped (noted) if the series are
/// too short.
fn spectrum_checks(ctx: &mut LinearContext<'_>, m: &mut ModeData<'_>) -> Result<()> {
    let mr = &ctx.run.reference.modes[m.i];
    if mr.multiplier > 0.0
        && let Err(e) = spectrum_check(
            ctx.run,
            m.i,
            &m.series,
            m.dt_sample,
            &mut m.me,
            &mut ctx.out,
        )
    {
        let prefix = &ctx.run.spec.name;
        ctx.est.skipped.push(SkippedCheck {
            name: format!("{prefix}/spectrum/n={}", mr.n),
            reason: e.to_string(),
        });
    }
    Ok(())
}

/// [`CheckKind::TwoTime`]: the two-time correlation eq. (4) from rest at every two-time
/// point against the exact discrete value (t-test over the ensemble).
fn two_time_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let r = &ctx.run.reference;
    let prefix = &ctx.run.spec.name;
    let c = ctx.run.components;
    let nt = r.two_time.len();
    for (j, q) in r.two_time.iter().enumerate() {
        let values: Vec<f64> = ctx
            .two_time
            .iter()
            .flat_map(|t| (0..c).map(move |k| t[k * nt + j]))
            .collect();
        let name = format!(
            "{prefix}/two-time/x={:.3},y={:.3},t={:.4e},eta={:.4e}",
            q.x, q.y, q.t, q.eta
        );
        // One trajectory's value has no ensemble mean to report (`verify` refuses such
        // budgets up front): skipped, noted.
        if values.len() < 2 {
            ctx.est.skipped.push(SkippedCheck {
                name,
                reason: format!(
                    "needs at least 2 independent values (trajectories x components), the data have {}",
                    values.len()
                ),
            });
            continue;
        }
        let m = stats::ensemble_mean(&values)?;
        // At one point and one time the products are squares of a zero-mean normal
        // deflection: n·mean/reference is exactly χ²(n). A t-test on such skewed values
        // has heavy tails with few samples (the calibration saw 3 % below p = 0.01).
        let diagonal = q.x == q.y && q.t_step == q.eta_step;
        // Elsewhere the sum of the products against its null law where the reference
        // knows the product's law (the two variances from rest beside the covariance);
        // the t-test, whose error comes from the data, for data of an unknown
        // discretization.
        let law = (!diagonal)
            .then(|| {
                let (vx, vy) = q.variances;
                stats::WeightedChiSquares::product_sum(vx, vy, q.discrete, values.len()).ok()
            })
            .flatten();
        let (o, kind, se) = if diagonal {
            let w: Vec<f64> = values.iter().map(|v| v.max(0.0).sqrt()).collect();
            let o = stats::chi2_variance_test(&w, q.discrete, Some(0.0))?;
            let se = q.discrete * (2.0 / values.len() as f64).sqrt();
            (o, "chi2-variance", se)
        } else if let Some(law) = &law {
            let (o, _, se) = stats::sum_test(values.iter().sum(), values.len(), law)?;
            (o, QUADRATIC_FORM, se)
        } else {
            let o = spread_t_test(m.mean, q.discrete, m.std_error, values.len())?;
            (o, "t-test", m.std_error)
        };
        // The error beside the estimate is the check's own: from the reference for the
        // χ² and the quadratic-form tests, from the spread over the samples for the t-test.
        ctx.est.two_time.push((m.mean, se));
        ctx.out.push(check(
            name,
            kind,
            (m.mean, q.discrete, se),
            &o,
            Some(q.continuum),
            format!(
                "eq. (4) from rest, ensemble of {} independent samples{}",
                values.len(),
                if diagonal {
                    " (squares of a normal deflection: chi2 test of n*mean/reference, n dof)"
                } else if law.is_some() {
                    " (the sum of the products against its exact null law: a weighted sum of two chi2(n), from the discrete variances at (x,t) and (y,eta) and the reference; saddle-point tail, error from the reference)"
                } else {
                    " (t-test)"
                }
            ),
        ));
    }
    Ok(())
}

/// Per independent series (trajectory and component), the time average of q² of mode
/// `i` over its exact discrete variance (1 in expectation).
fn normalized_variances(ctx: &LinearContext<'_>, i: usize) -> Vec<f64> {
    let reference = ctx.run.reference.modes[i].variance_discrete;
    mode_data(ctx.run, ctx.records, i)
        .series
        .iter()
        .map(|s| s.iter().map(|q| q * q).sum::<f64>() / s.len().max(1) as f64 / reference)
        .collect()
}

/// The effective samples of mode `i` per series, `n(1 − ρ²)/(1 + ρ²)` for `n` samples
/// with lag-one correlation ρ (the variance of the time average of q² of an AR(1)
/// sequence is `2σ⁴(1 + ρ²)/(n(1 − ρ²))`): the weight of the mode in the pooled checks,
/// fixed by the sampling plan, not by the data.
fn effective_samples(ctx: &LinearContext<'_>, i: usize) -> f64 {
    let run = ctx.run;
    let n = ctx
        .records
        .first()
        .map_or(0, |r| r.modes.get(i).map_or(0, Vec::len)) as f64;
    let rho = run.reference.modes[i]
        .multiplier
        .abs()
        .powf(run.mode_every[i] as f64);
    n * (1.0 - rho * rho) / (1.0 + rho * rho)
}

/// [`CheckKind::PooledVariance`]: per independent series the weighted mean over the
/// checked modes of (time average of q²)/(exact discrete variance), weights the modes'
/// effective samples ([`effective_samples`]), t-tested against 1 over the series (the
/// error from their spread, so that correlations between modes — the element-uniform
/// load drives the modes with correlated noise — are accounted for). Skipped (noted)
/// with fewer than [`MIN_SERIES_FOR_T`] series.
fn pooled_variance_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let r = &ctx.run.reference;
    let name = format!("{}/pooled-variance", ctx.run.spec.name);
    let nm = r.modes.len();
    let weights: Vec<f64> = (0..nm).map(|i| effective_samples(ctx, i)).collect();
    let total: f64 = weights.iter().sum();
    let per_mode: Vec<Vec<f64>> = (0..nm).map(|i| normalized_variances(ctx, i)).collect();
    let n_series = per_mode.first().map_or(0, Vec::len);
    if n_series < MIN_SERIES_FOR_T || total.is_nan() || total <= 0.0 {
        ctx.est.skipped.push(SkippedCheck {
            name,
            reason: format!(
                "needs at least {MIN_SERIES_FOR_T} independent series with samples, the data have {n_series}"
            ),
        });
        return Ok(());
    }
    let values: Vec<f64> = (0..n_series)
        .map(|j| {
            (0..nm)
                .map(|i| weights[i] / total * per_mode[i][j])
                .sum::<f64>()
        })
        .collect();
    let continuum: f64 = (0..nm)
        .map(|i| weights[i] / total * r.modes[i].variance_continuum / r.modes[i].variance_discrete)
        .sum();
    let m = stats::ensemble_mean(&values)?;
    let o = spread_t_test(m.mean, 1.0, m.std_error, values.len())?;
    ctx.out.push(check(
        name,
        "t-test",
        (m.mean, 1.0, m.std_error),
        &o,
        Some(continuum),
        format!(
            "weighted mean over {nm} modes of (time average of q^2)/(discrete variance), weights their effective samples; {} independent series, Student t with {} dof",
            values.len(),
            values.len() - 1
        ),
    ));
    Ok(())
}

/// [`CheckKind::XySymmetry`]: on a square patch the modes (m, n) and (n, m) of the same
/// shape have equal variances. Per independent series the weighted sum over the checked
/// pairs of the difference of their normalized time averages, t-tested against 0
/// ([`zero_mean_check`]); skipped (noted) without a checked pair.
fn xy_symmetry_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let r = &ctx.run.reference;
    let name = format!("{}/xy-symmetry", ctx.run.spec.name);
    let labels: Vec<_> = r.modes.iter().map(|m| m.label).collect();
    let mut pairs = Vec::new();
    for (i, a) in labels.iter().enumerate() {
        let Some(a) = a else { continue };
        if a.m >= a.n {
            continue;
        }
        let mirror = labels
            .iter()
            .position(|b| b.is_some_and(|b| b.m == a.n && b.n == a.m && b.shape == a.shape));
        if let Some(k) = mirror {
            pairs.push((i, k));
        }
    }
    if pairs.is_empty() {
        ctx.est.skipped.push(SkippedCheck {
            name,
            reason: "no pair of checked modes (m, n) and (n, m): raise sampling.modes".into(),
        });
        return Ok(());
    }
    let weight = |(i, k): (usize, usize)| effective_samples(ctx, i).min(effective_samples(ctx, k));
    let total: f64 = pairs.iter().map(|&p| weight(p)).sum();
    let mut values: Vec<f64> = Vec::new();
    for &(i, k) in &pairs {
        let w = weight((i, k)) / total;
        let (a, b) = (normalized_variances(ctx, i), normalized_variances(ctx, k));
        if values.is_empty() {
            values = vec![0.0; a.len()];
        }
        for (v, (x, y)) in values.iter_mut().zip(a.iter().zip(&b)) {
            *v += w * (x - y);
        }
    }
    let described: Vec<String> = pairs
        .iter()
        .filter_map(|&(i, _)| labels[i].map(|l| format!("({0}, {1})-({1}, {0})", l.m, l.n)))
        .collect();
    zero_mean_check(
        ctx,
        name,
        &values,
        &format!(
            "weighted difference of the normalized variances of the mirror pairs {}",
            described.join(", ")
        ),
    )
}

/// [`CheckKind::RigidDiffusion`]: per rigid mode, the increments `Δr` of its amplitude
/// between consecutive profile samples (lag τ, a whole number of steps) over every
/// trajectory and component, χ²-tested against the exact variance `D·τ`
/// ([`RigidReference`](crate::scene::linear::RigidReference)): a zero mode is a random
/// walk, so its increments are independent and normal with mean 0. Skipped (noted)
/// where the integrator does not step the rigid motion.
fn rigid_diffusion_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let run = ctx.run;
    let nr = run.reference.rigid.len();
    let prefix = &run.spec.name;
    let tau = run.profile_every as f64 * run.reference.dt;
    for (k, law) in run.reference.rigid.iter().enumerate() {
        let name = format!("{prefix}/rigid-diffusion/mode={k}");
        if !law.simulated {
            ctx.est.skipped.push(SkippedCheck {
                name,
                reason: format!(
                    "the {} integrator steps the elastic modes only: the {} is not simulated",
                    run.spec.integrator.name(),
                    law.name
                ),
            });
            continue;
        }
        let increments: Vec<f64> = ctx
            .records
            .iter()
            .flat_map(|t| (0..run.components).map(move |c| &t.rigid[c * nr + k]))
            .flat_map(|s| s.windows(2).map(|w| w[1] - w[0]))
            .collect();
        let reference = law.diffusion_discrete * tau;
        let o = stats::chi2_variance_test(&increments, reference, Some(0.0))?;
        let s2 = increments.iter().map(|d| d * d).sum::<f64>() / increments.len() as f64;
        ctx.out.push(check(
            name,
            "chi2-variance",
            (
                s2,
                reference,
                reference * (2.0 / increments.len() as f64).sqrt(),
            ),
            &o,
            Some(law.diffusion_continuum * tau),
            format!(
                "{}: mean squared increment of r = psi^T C w over lag {:.6e} ({} independent increments), exact random walk D*tau",
                law.name,
                tau,
                increments.len()
            ),
        ));
    }
    if nr == 0 {
        ctx.est.skipped.push(SkippedCheck {
            name: format!("{prefix}/rigid-diffusion"),
            reason: "no rigid-mode amplitudes: the ends allow no rigid motion, or the data carry none (sidecar key rigid: the rigid coordinates w_mean, w_angle after the modal amplitudes)".into(),
        });
    }
    Ok(())
}

/// Largest thinning stride of a tangent-angle series (samples); a series that needs more
/// is too short to give independent samples and its checks are skipped (noted).
const MAX_TANGENT_STRIDE: usize = 10_000;

/// Fewest thinned samples a tangent-angle check runs on.
const MIN_TANGENT_SAMPLES: usize = 20;

/// [`CheckKind::TangentAngle`]: per cosine n, the tangent-angle amplitudes of Gittes et
/// al. (1993) over every trajectory and component, thinned by their exact
/// autocorrelation ([`TangentReference::correlation`](crate::scene::linear::TangentReference))
/// to a lag correlation ≤ [`MAX_THINNED_CORRELATION`]: the variance against the exact
/// discrete value by a χ² test about the known mean 0 (continuum kT L²/(EI n²π²) beside
/// it), and the law against N(0, that variance) by KS.
fn tangent_angle_check(ctx: &mut LinearContext<'_>) -> Result<()> {
    let run = ctx.run;
    let prefix = &run.spec.name;
    let nt = run.reference.tangent.len();
    if nt == 0 {
        ctx.est.skipped.push(SkippedCheck {
            name: format!("{prefix}/tangent-angle"),
            reason: "no tangent-angle amplitudes: the data carry none (sidecar key tangent_modes)"
                .into(),
        });
    }
    for (i, tr) in run.reference.tangent.iter().enumerate() {
        let stride = tr.stride(
            run.profile_every,
            MAX_THINNED_CORRELATION,
            MAX_TANGENT_STRIDE,
        );
        let series: Vec<&[f64]> = ctx
            .records
            .iter()
            .flat_map(|t| (0..run.components).map(move |c| t.tangent[c * nt + i].as_slice()))
            .collect();
        let thinned = thin(&series, stride);
        let name = |what: &str| format!("{prefix}/{what}/n={}", tr.n);
        if stride >= MAX_TANGENT_STRIDE || thinned.len() < MIN_TANGENT_SAMPLES {
            for what in ["tangent-variance", "tangent-ks"] {
                ctx.est.skipped.push(SkippedCheck {
                    name: name(what),
                    reason: format!(
                        "{} samples {stride} apart (lag correlation <= {MAX_THINNED_CORRELATION}); at least {MIN_TANGENT_SAMPLES} needed",
                        thinned.len()
                    ),
                });
            }
            continue;
        }
        let v = tr.variance_discrete;
        let o = stats::chi2_variance_test(&thinned, v, Some(0.0))?;
        let s2 = thinned.iter().map(|q| q * q).sum::<f64>() / thinned.len() as f64;
        ctx.out.push(check(
            name("tangent-variance"),
            "chi2-variance",
            (s2, v, v * (2.0 / thinned.len() as f64).sqrt()),
            &o,
            Some(tr.variance_continuum),
            format!(
                "a_n = sqrt(2/L) int theta cos(n pi s/L) ds (Gittes et al. 1993): {} samples spaced {stride} profile samples apart (exact lag correlation <= {MAX_THINNED_CORRELATION}); ratio to the continuum kT L^2/(EI n^2 pi^2) {:.4}",
                thinned.len(),
                s2 / tr.variance_continuum
            ),
        ));
        let o = stats::ks_normal(&thinned, 0.0, v.sqrt())?;
        ctx.out.push(check(
            name("tangent-ks"),
            "ks",
            (f64::NAN, f64::NAN, f64::NAN),
            &o,
            None,
            format!(
                "KS distance of the tangent-angle amplitude to N(0, {v:.4e}) over {} thinned samples",
                thinned.len()
            ),
        ));
    }
    Ok(())
}

/// Spectrum of mode `i` against the exact expectation of the Welch estimator for the
/// sampled AR(1) sequence (window and mean removal included), in a low and a high band
/// split at the corner frequency; the error of each band ratio comes from the spread over
/// independent series.
fn spectrum_check(
    run: &LinearRun,
    i: usize,
    series: &[&[f64]],
    dt_sample: f64,
    me: &mut ModeEstimate,
    out: &mut Vec<CheckResult>,
) -> Result<()> {
    let mr = &run.reference.modes[i];
    let prefix = &run.spec.name;
    let shortest = series.iter().map(|s| s.len()).min().unwrap_or(0);
    // Segments of SEGMENT_LEN samples (~32 relaxation times), shorter so that every
    // series holds at least MIN_SEGMENTS half-overlapping segments: the per-series band
    // ratio is then close to normal and its spread over series a reliable error. Leakage
    // of short segments is inside the exact expectation, not in the comparison.
    let mut seg = SEGMENT_LEN;
    while seg > MIN_SEGMENT_LEN && seg * (MIN_SEGMENTS + 1) / 2 > shortest {
        seg /= 2;
    }
    if seg * (MIN_SEGMENTS + 1) / 2 > shortest {
        return Err(Error::invalid(
            format!("{prefix}: samples of mode {} per trajectory", mr.n),
            shortest,
            format!(
                ">= {} for the spectrum check (raise duration_tau1)",
                MIN_SEGMENT_LEN * (MIN_SEGMENTS + 1) / 2
            ),
        ));
    }
    let dts = dt_sample;
    let rho = mr.multiplier.powf(run.mode_every[i] as f64);
    let expected = stats::welch_expectation_ar1(rho, mr.variance_discrete, dts, seg)?;
    let corner = -rho.ln() / (2.0 * std::f64::consts::PI * dts);
    let mut low = Vec::new();
    let mut high = Vec::new();
    let mut pooled: Option<Vec<f64>> = None;
    let mut freqs = Vec::new();
    for s in series {
        let x = *s;
        let psd = stats::welch(x, dts, seg)?;
        let (lo, hi) = band_ratios(&psd.freqs, &psd.density, &expected, corner);
        low.extend(lo);
        high.extend(hi);
        match &mut pooled {
            None => pooled = Some(psd.density.clone()),
            Some(p) => p.iter_mut().zip(&psd.density).for_each(|(a, b)| *a += b),
        }
        freqs = psd.freqs;
    }
    if let Some(mut p) = pooled {
        p.iter_mut().for_each(|v| *v /= series.len() as f64);
        me.spectrum = Some((freqs, p, expected.clone()));
    }
    for (band, ratios) in [("low", &low), ("high", &high)] {
        if ratios.len() < 2 {
            continue;
        }
        let m = stats::ensemble_mean(ratios)?;
        let o = spread_t_test(m.mean, 1.0, m.std_error, ratios.len())?;
        out.push(check(
            format!("{prefix}/spectrum-{band}/n={}", mr.n),
            "t-test",
            (m.mean, 1.0, m.std_error),
            &o,
            None,
            format!(
                "mean Welch/exact ratio, {band} band (corner {corner:.4e}), {} series, segment {seg}, spacing {dts:.3e}",
                ratios.len()
            ),
        ));
    }
    Ok(())
}

/// The mean Welch/exact ratio of one series' spectrum over the interior bins (no DC, no
/// Nyquist bin) at or below `corner` and above it; `None` for a band without bins.
fn band_ratios(
    freqs: &[f64],
    density: &[f64],
    expected: &[f64],
    corner: f64,
) -> (Option<f64>, Option<f64>) {
    let (mut lo, mut nlo, mut hi, mut nhi) = (0.0, 0, 0.0, 0);
    // Skip the DC bin (mean removal) and the Nyquist bin.
    let interior = 1..freqs.len() - 1;
    for ((f, d), e) in freqs[interior.clone()]
        .iter()
        .zip(&density[interior.clone()])
        .zip(&expected[interior])
    {
        let ratio = d / e;
        if *f <= corner {
            lo += ratio;
            nlo += 1;
        } else {
            hi += ratio;
            nhi += 1;
        }
    }
    (
        (nlo > 0).then(|| lo / nlo as f64),
        (nhi > 0).then(|| hi / nhi as f64),
    )
}
