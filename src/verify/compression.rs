//! The compression checks of one run (the paper's Fig. 2): ⟨F⟩ against the exact
//! equilibrium theory of the same discretization, the distribution of F, and the Δt-halving
//! check, each one small function.

use crate::error::Result;
use crate::scene::CheckKind;
use crate::scene::compression::{
    CompressionRun, CompressionTheoryTable, ForceEstimates, ForceRecord,
};
use crate::stats;
use crate::verify::summary::CheckResult;

/// Thinning of F samples for the KS test, in integrated autocorrelation times.
const KS_THINNING_TAU: f64 = 10.0;

/// The force–strain and force-distribution checks of one run.
///
/// # Errors
/// Estimator errors.
pub fn compression_checks(
    run: &CompressionRun,
    checks: &[CheckKind],
    theory: &CompressionTheoryTable,
    records: &[Vec<ForceRecord>],
    est: &ForceEstimates,
) -> Result<Vec<CheckResult>> {
    let name = &run.spec.name;
    let mut out = Vec::new();
    if checks.contains(&CheckKind::ForceStrain) {
        let mut z = Vec::new();
        for (i, &(f, se)) in est.force.iter().enumerate() {
            let o = stats::z_test(f, theory.discrete[i], se)?;
            z.push(o.statistic);
            out.push(CheckResult::statistical(
                format!("{name}/force/strain_ratio={}", theory.strain_ratios[i]),
                "z-test",
                (f, theory.discrete[i], se),
                Some(theory.continuum[i]),
                o.p_value,
                format!(
                    "<F>/F_c0 over {} trajectories (IAT errors)",
                    records[i].len()
                ),
            ));
        }
        let o = stats::chi2_sum_test(&z)?;
        out.push(CheckResult::statistical(
            format!("{name}/force-strain-chi2"),
            "chi2-sum",
            (o.statistic, z.len() as f64, f64::NAN),
            None,
            o.p_value,
            format!(
                "sum of squared z over {} strains against chi2({})",
                z.len(),
                z.len()
            ),
        ));
    }
    if checks.contains(&CheckKind::ForceDistribution) {
        for (i, dist) in theory.distributions.iter().enumerate() {
            let Some(dist) = dist else { continue };
            // Thin each trajectory's series to effectively independent samples.
            let mut samples = Vec::new();
            let mut stride = 1;
            for r in &records[i] {
                let tau = stats::integrated_autocorrelation_time(&r.force_ratio)?.tau_int;
                stride = stride.max((KS_THINNING_TAU * tau).ceil() as usize);
            }
            for r in &records[i] {
                samples.extend(r.force_ratio.iter().step_by(stride).copied());
            }
            let fc0 = run.euler_load;
            let o = stats::ks_test(&samples, |f| dist.cdf(f * fc0))?;
            out.push(CheckResult::statistical(
                format!("{name}/force-ks/strain_ratio={}", theory.strain_ratios[i]),
                "ks",
                (o.statistic, f64::NAN, f64::NAN),
                None,
                o.p_value,
                format!(
                    "{} samples thinned every {stride} (>= {KS_THINNING_TAU} IAT)",
                    samples.len()
                ),
            ));
        }
    }
    Ok(out)
}

/// The Δt-halving check: per strain z = (F_Δt − F_Δt/2)/sqrt(se² + se²), combined as
/// Σz² against χ²(points); estimate = mean difference over strains with its error.
///
/// # Errors
/// Estimator errors.
pub fn halving_check(
    names: [&str; 2],
    a: &ForceEstimates,
    b: &ForceEstimates,
) -> Result<(CheckResult, String)> {
    let z: Vec<f64> = a
        .force
        .iter()
        .zip(&b.force)
        .map(|(x, y)| (x.0 - y.0) / (x.1 * x.1 + y.1 * y.1).sqrt())
        .collect();
    let n = z.len() as f64;
    let mean_diff = a
        .force
        .iter()
        .zip(&b.force)
        .map(|(x, y)| x.0 - y.0)
        .sum::<f64>()
        / n;
    let se = a
        .force
        .iter()
        .zip(&b.force)
        .map(|(x, y)| x.1 * x.1 + y.1 * y.1)
        .sum::<f64>()
        .sqrt()
        / n;
    let max_diff = a
        .force
        .iter()
        .zip(&b.force)
        .map(|(x, y)| (x.0 - y.0).abs())
        .fold(0.0, f64::max);
    let max_se = a.force.iter().map(|x| x.1).fold(0.0, f64::max);
    let o = stats::chi2_sum_test(&z)?;
    let note = format!(
        "dt-halving ({} vs {}): mean <F>/F_c0 difference {:.2e} ± {:.2e} over {} strains (95% bound on |bias| {:.2e}), largest |difference| {:.2e}; largest point standard error of {} {:.2e}: the time-step bias {} below the standard error",
        names[0],
        names[1],
        mean_diff,
        se,
        z.len(),
        mean_diff.abs() + 2.0 * se,
        max_diff,
        names[0],
        max_se,
        if mean_diff.abs() + 2.0 * se < max_se {
            "is shown"
        } else {
            "is NOT shown"
        }
    );
    Ok((
        CheckResult::statistical(
            format!("dt-halving/{}-vs-{}", names[0], names[1]),
            "chi2-sum",
            (mean_diff, 0.0, se),
            None,
            o.p_value,
            format!(
                "per-strain z of the difference, sum of z^2 = {:.2} against chi2({})",
                o.statistic,
                z.len()
            ),
        ),
        note,
    ))
}
