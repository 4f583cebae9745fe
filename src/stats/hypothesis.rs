//! Hypothesis tests against exact references and the Holm–Bonferroni correction.
//!
//! All goodness-of-fit tests here assume **independent** samples; see the pitfall in the
//! [`super`] module documentation. Distributions, the KS statistic and the χ² statistic
//! come from `statrs`.

use statrs::distribution::{ChiSquared, ContinuousCDF, Normal, StudentsT};
use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::chisquare::chisquare;
use statrs::stats_tests::ks_test::{KSOneSampleAlternativeMethod, ks_onesample};

use crate::error::{Error, Result};

use super::require_samples;

/// The outcome of a hypothesis test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TestOutcome {
    /// The test statistic (D for KS, χ² for χ² tests, z for the z-test).
    pub statistic: f64,
    /// The p-value under the null hypothesis.
    pub p_value: f64,
    /// Degrees of freedom of the null distribution, where it has any.
    pub dof: Option<f64>,
}

fn normal(mean: f64, std_dev: f64) -> Result<Normal> {
    if !mean.is_finite() {
        return Err(Error::invalid("mean", mean, "finite"));
    }
    crate::error::require_positive("std_dev", std_dev)?;
    Normal::new(mean, std_dev).map_err(|e| Error::invalid("std_dev", std_dev, e.to_string()))
}

fn chi2(dof: f64) -> Result<ChiSquared> {
    ChiSquared::new(dof).map_err(|e| Error::Numerical {
        routine: "chi-squared distribution".into(),
        detail: e.to_string(),
    })
}

/// One-sample two-sided Kolmogorov–Smirnov test of `samples` against N(mean, std_dev²).
///
/// Statistic D = sup |F_n(x) − Φ((x − mean)/std_dev)|; p-value from Kolmogorov's
/// asymptotic distribution P(√n D > t) = 2 Σ_{k≥1} (−1)^{k−1} e^{−2k²t²}
/// (`statrs::stats_tests::ks_test::ks_onesample`, `TwoSidedAsymptotic`; accurate for
/// n ≳ 100, slightly conservative for small n). The samples **must be independent**:
/// with autocorrelated samples the test over-rejects.
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 2 samples, a non-finite sample or mean, or
/// a non-positive standard deviation.
pub fn ks_normal(samples: &[f64], mean: f64, std_dev: f64) -> Result<TestOutcome> {
    ks_against(samples, &normal(mean, std_dev)?)
}

/// A continuous distribution given only by its CDF, for [`ks_test`].
struct CdfFn<F>(F);

impl<F> statrs::statistics::Min<f64> for CdfFn<F> {
    fn min(&self) -> f64 {
        f64::NEG_INFINITY
    }
}

impl<F> statrs::statistics::Max<f64> for CdfFn<F> {
    fn max(&self) -> f64 {
        f64::INFINITY
    }
}

impl<F: Fn(f64) -> f64> ContinuousCDF<f64, f64> for CdfFn<F> {
    fn cdf(&self, x: f64) -> f64 {
        (self.0)(x)
    }
}

/// Two-sided one-sample Kolmogorov–Smirnov test of independent `samples` against the
/// continuous distribution with CDF `cdf` (statrs `ks_onesample`, asymptotic p-value).
/// Used where the reference law is known only numerically (e.g. the equilibrium force
/// distribution of the compressed filament).
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 2 samples or a non-finite sample.
pub fn ks_test(samples: &[f64], cdf: impl Fn(f64) -> f64) -> Result<TestOutcome> {
    ks_against(samples, &CdfFn(cdf))
}

fn ks_against<D: ContinuousCDF<f64, f64>>(samples: &[f64], dist: &D) -> Result<TestOutcome> {
    require_samples("samples", samples, 2)?;
    let (statistic, p_value) = ks_onesample(
        samples.to_vec(),
        dist,
        KSOneSampleAlternativeMethod::TwoSidedAsymptotic,
        NaNPolicy::Error,
    )
    .map_err(|e| Error::Numerical {
        routine: "ks_onesample".into(),
        detail: e.to_string(),
    })?;
    Ok(TestOutcome {
        statistic,
        p_value,
        dof: None,
    })
}

/// The number of equiprobable bins for a χ² goodness-of-fit test of `n` samples.
///
/// Moore's rule k = ⌊2 n^{2/5}⌋ (D. S. Moore, "Tests of chi-squared type", ch. 3 of
/// D'Agostino & Stephens, *Goodness-of-Fit Techniques*, 1986; the Mann–Wald n^{2/5}
/// growth), but never fewer than 20 bins while every bin can expect at least 10 samples,
/// and never fewer than 4: k = max(4, min(⌊n/10⌋, max(20, ⌊2 n^{2/5}⌋))). Up to
/// n ≈ 316 this is the fixed rule min(⌊n/10⌋, 20) the checks used before; beyond, the bins
/// grow with the data, so a larger sample resolves the distribution more finely instead
/// of pooling it into the same 20 bins (at n = 4·10⁵, 357 bins of about 1 200 samples).
pub fn gof_bins(n: usize) -> usize {
    let moore = (2.0 * (n as f64).powf(0.4)).floor() as usize;
    (n / 10).min(moore.max(20)).max(4)
}

/// Pearson χ² goodness-of-fit test of independent `samples` against N(mean, std_dev²)
/// with `n_bins` equiprobable bins.
///
/// Bin edges are the normal quantiles Φ⁻¹(j/n_bins), j = 1..n_bins−1 (`statrs`
/// `inverse_cdf`), so every bin expects E = n/n_bins samples; the statistic
/// Σ (O_j − E)²/E is referred to χ²(n_bins − 1) (`statrs::stats_tests::chisquare`).
/// The χ² approximation requires E ≥ 5 (Cochran 1952).
///
/// # Errors
/// [`Error::InvalidParameter`] for a non-finite sample or mean, a non-positive standard
/// deviation, `n_bins` < 2, or an expected count per bin below 5.
pub fn chi2_gof_normal(
    samples: &[f64],
    mean: f64,
    std_dev: f64,
    n_bins: usize,
) -> Result<TestOutcome> {
    require_samples("samples", samples, 1)?;
    let dist = normal(mean, std_dev)?;
    if n_bins < 2 {
        return Err(Error::invalid("n_bins", n_bins, ">= 2"));
    }
    let expected = samples.len() as f64 / n_bins as f64;
    if expected < 5.0 {
        return Err(Error::invalid(
            "n_bins",
            n_bins,
            format!(
                "<= {} for {} samples (expected count per bin >= 5)",
                samples.len() / 5,
                samples.len()
            ),
        ));
    }
    let edges: Vec<f64> = (1..n_bins)
        .map(|j| dist.inverse_cdf(j as f64 / n_bins as f64))
        .collect();
    let mut counts = vec![0usize; n_bins];
    for &x in samples {
        counts[edges.partition_point(|&e| e <= x)] += 1;
    }
    let (statistic, p_value) = chisquare(&counts, None, None).map_err(|e| Error::Numerical {
        routine: "chisquare".into(),
        detail: e.to_string(),
    })?;
    Ok(TestOutcome {
        statistic,
        p_value,
        dof: Some((n_bins - 1) as f64),
    })
}

/// Two-sided χ² test that independent normal `samples` have variance `variance_ref`.
///
/// With a known mean μ: T = Σ (x_i − μ)²/σ² ~ χ²(n); otherwise
/// T = (n − 1) s²/σ² = Σ (x_i − x̄)²/σ² ~ χ²(n − 1). Two-sided p = 2 min(P, 1 − P),
/// capped at 1, where P = F_χ²(T). Exact for independent normal samples; sensitive to
/// non-normality and to correlation (use one sample per independent trajectory).
///
/// # Errors
/// [`Error::InvalidParameter`] for fewer than 2 samples (1 with a known mean), a
/// non-finite sample or mean, or a non-positive `variance_ref`.
pub fn chi2_variance_test(
    samples: &[f64],
    variance_ref: f64,
    known_mean: Option<f64>,
) -> Result<TestOutcome> {
    require_samples("samples", samples, if known_mean.is_some() { 1 } else { 2 })?;
    crate::error::require_positive("variance_ref", variance_ref)?;
    let n = samples.len();
    let (mu, dof) = match known_mean {
        Some(mu) if mu.is_finite() => (mu, n),
        Some(mu) => return Err(Error::invalid("known_mean", mu, "finite")),
        None => (super::mean_of(samples), n - 1),
    };
    let statistic = samples.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / variance_ref;
    let dist = chi2(dof as f64)?;
    let lower = dist.cdf(statistic);
    let upper = dist.sf(statistic);
    Ok(TestOutcome {
        statistic,
        p_value: (2.0 * lower.min(upper)).min(1.0),
        dof: Some(dof as f64),
    })
}

/// Two-sided z-test of `estimate` against `reference` with standard error `std_error`:
/// z = (estimate − reference)/std_error, p = 2(1 − Φ(|z|)). The statistic returned is z.
/// Valid when the estimate is approximately normal with a well-determined error.
///
/// # Errors
/// [`Error::InvalidParameter`] if `estimate` or `reference` is not finite or
/// `std_error` is not finite and positive.
pub fn z_test(estimate: f64, reference: f64, std_error: f64) -> Result<TestOutcome> {
    if !estimate.is_finite() {
        return Err(Error::invalid("estimate", estimate, "finite"));
    }
    if !reference.is_finite() {
        return Err(Error::invalid("reference", reference, "finite"));
    }
    crate::error::require_positive("std_error", std_error)?;
    let z = (estimate - reference) / std_error;
    let p_value = (2.0 * normal(0.0, 1.0)?.sf(z.abs())).min(1.0);
    Ok(TestOutcome {
        statistic: z,
        p_value,
        dof: None,
    })
}

/// Two-sided one-sample t-test of `estimate` against `reference` when the standard error
/// was itself estimated from `n` independent values (Student 1908): t = (est − ref)/se
/// with n − 1 degrees of freedom. Use it instead of [`z_test`] for an ensemble mean over
/// few independent trajectories, where the estimated error is itself uncertain.
///
/// # Errors
/// [`Error::InvalidParameter`] for non-finite input, a non-positive error or n < 2.
pub fn t_test(estimate: f64, reference: f64, std_error: f64, n: usize) -> Result<TestOutcome> {
    let z = z_test(estimate, reference, std_error)?;
    if n < 2 {
        return Err(Error::invalid("n", n, ">= 2"));
    }
    let dof = (n - 1) as f64;
    let t = StudentsT::new(0.0, 1.0, dof).map_err(|e| Error::Numerical {
        routine: "t_test".into(),
        detail: e.to_string(),
    })?;
    Ok(TestOutcome {
        statistic: z.statistic,
        p_value: (2.0 * t.sf(z.statistic.abs())).min(1.0),
        dof: Some(dof),
    })
}

/// The standard normal score with the same two-sided p-value and sign as a test
/// statistic (e.g. a t statistic): `sign(statistic)·Φ⁻¹(1 − p/2)`, computed as
/// `−Φ⁻¹(p/2)` so that small p keep their precision. Under the null it is exactly
/// standard normal whenever p is exactly uniform, so such scores can be combined by
/// [`chi2_sum_test`].
///
/// # Errors
/// [`Error::InvalidParameter`] for a p-value outside (0, 1] or a non-finite statistic.
pub fn equivalent_z(statistic: f64, p_value: f64) -> Result<f64> {
    if !statistic.is_finite() {
        return Err(Error::invalid("statistic", statistic, "finite"));
    }
    if !(p_value > 0.0 && p_value <= 1.0) {
        return Err(Error::invalid("p_value", p_value, "in (0, 1]"));
    }
    let z = -normal(0.0, 1.0)?.inverse_cdf(p_value / 2.0);
    Ok(if statistic < 0.0 { -z } else { z })
}

/// Combines independent z-scores: T = Σ z_i² is χ²(m) under the null (m = number of
/// scores); p = P(χ²(m) ≥ T) (upper tail). Detects a common misfit spread over many
/// checks that no single z-test flags.
///
/// # Errors
/// [`Error::InvalidParameter`] if `z_scores` is empty or has a non-finite value.
pub fn chi2_sum_test(z_scores: &[f64]) -> Result<TestOutcome> {
    require_samples("z_scores", z_scores, 1)?;
    let m = z_scores.len() as f64;
    let statistic: f64 = z_scores.iter().map(|z| z * z).sum();
    Ok(TestOutcome {
        statistic,
        p_value: chi2(m)?.sf(statistic),
        dof: Some(m),
    })
}

/// Holm–Bonferroni step-down adjustment (S. Holm, Scand. J. Stat. 6, 65 (1979)).
///
/// With the m p-values sorted ascending, p_(1) ≤ … ≤ p_(m), the adjusted values are
/// p̃_(i) = max_{j≤i} min(1, (m − j + 1) p_(j)); hypothesis i is rejected iff
/// p̃_i ≤ `alpha`, which controls the family-wise error rate at `alpha` for any
/// dependence between the tests. Returns (adjusted p-value, reject) in the input order.
/// A NaN p-value is treated as 1 (never rejected, and it cannot cause rejections of
/// others); ties keep their input order.
pub fn holm(p_values: &[f64], alpha: f64) -> Vec<(f64, bool)> {
    let m = p_values.len();
    let clean: Vec<f64> = p_values
        .iter()
        .map(|&p| if p.is_nan() { 1.0 } else { p.clamp(0.0, 1.0) })
        .collect();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| clean[a].total_cmp(&clean[b]));
    let mut out = vec![(1.0, false); m];
    let mut running = 0.0_f64;
    for (rank, &i) in order.iter().enumerate() {
        let adj = ((m - rank) as f64 * clean[i]).min(1.0);
        running = running.max(adj);
        out[i] = (running, running <= alpha);
    }
    out
}

#[cfg(test)]
mod tests {
    //! Hand-worked examples (exact values) and error paths; the false-rejection rates and
    //! power are validated over many seeds in `tests/stats_validation.rs`.
    use super::*;

    #[test]
    fn equivalent_z_by_hand() {
        // p = 0.05 two-sided is |z| = 1.959964; the sign follows the statistic.
        assert!((equivalent_z(2.5, 0.05).unwrap() - 1.959_963_984_540_054).abs() < 1e-9);
        assert!((equivalent_z(-0.1, 0.05).unwrap() + 1.959_963_984_540_054).abs() < 1e-9);
        assert_eq!(equivalent_z(1.0, 1.0).unwrap(), 0.0);
        // A z-test's own statistic comes back.
        let o = z_test(2.2, 0.0, 1.0).unwrap();
        assert!((equivalent_z(o.statistic, o.p_value).unwrap() - 2.2).abs() < 1e-9);
        // Tiny p keep their precision: two-sided p = 1e-20 is |z| = 9.336045 (erfc inverted by bisection).
        assert!((equivalent_z(1.0, 1e-20).unwrap() - 9.336_044_849_234_06).abs() < 1e-6);
        assert!(equivalent_z(1.0, 0.0).is_err());
        assert!(equivalent_z(f64::NAN, 0.5).is_err());
    }

    #[test]
    fn holm_hand_example() {
        // Sorted: 0.01 (x4 = 0.04), 0.02 (x3 = 0.06), 0.03 (x2 = 0.06), 0.5 (x1 = 0.5).
        let p = [0.03, 0.5, 0.01, 0.02];
        let adj = holm(&p, 0.05);
        let expect = [0.06, 0.5, 0.04, 0.06];
        for ((a, r), e) in adj.iter().zip(expect) {
            assert!((a - e).abs() < 1e-15, "{adj:?}");
            assert_eq!(*r, e <= 0.05);
        }
        assert!(holm(&[], 0.05).is_empty());
        let nan = holm(&[f64::NAN, 0.001], 0.05);
        assert_eq!(nan, vec![(1.0, false), (0.002, true)]);
    }

    #[test]
    fn z_and_chi2_sum_hand_values() {
        let t = z_test(1.96, 0.0, 1.0).unwrap();
        assert!((t.p_value - 0.05).abs() < 1e-4);
        assert_eq!(t.statistic, 1.96);
        // χ²(2) upper tail is e^{-T/2}.
        let c = chi2_sum_test(&[1.0, 1.0]).unwrap();
        assert!((c.p_value - (-1.0f64).exp()).abs() < 1e-12);
        assert_eq!(c.dof, Some(2.0));
    }

    #[test]
    fn chi2_variance_hand_value() {
        // Known mean 0, σ² = 1: T = 1 + 4 + 9 = 14 with 3 dof.
        let t = chi2_variance_test(&[1.0, -2.0, 3.0], 1.0, Some(0.0)).unwrap();
        assert_eq!(t.statistic, 14.0);
        assert_eq!(t.dof, Some(3.0));
        let upper = ChiSquared::new(3.0).unwrap().sf(14.0);
        assert!((t.p_value - 2.0 * upper).abs() < 1e-12);
        // Sample mean 2/3: Σ (x − x̄)² = 14 − 3·(2/3)² = 12.666…, 2 dof.
        let u = chi2_variance_test(&[1.0, -2.0, 3.0], 1.0, None).unwrap();
        assert!((u.statistic - (14.0 - 4.0 / 3.0)).abs() < 1e-12);
        assert_eq!(u.dof, Some(2.0));
    }

    #[test]
    fn gof_binning_is_equiprobable() {
        // The 8 midpoints of equiprobable bins of N(0, 1) fall one per bin: χ² = 0, p = 1.
        let n = Normal::new(0.0, 1.0).unwrap();
        let x: Vec<f64> = (0..40)
            .map(|i| n.inverse_cdf(((i % 8) as f64 + 0.5) / 8.0))
            .collect();
        let t = chi2_gof_normal(&x, 0.0, 1.0, 8).unwrap();
        assert!(t.statistic.abs() < 1e-12);
        assert!((t.p_value - 1.0).abs() < 1e-12);
        assert_eq!(t.dof, Some(7.0));
    }

    #[test]
    fn gof_bins_is_the_fixed_rule_up_to_316_samples_then_moore() {
        for n in 0..=316 {
            assert_eq!(gof_bins(n), (n / 10).clamp(4, 20), "n = {n}");
        }
        // 2·1000^0.4 = 31.70, 2·10⁴^0.4 = 79.62, 2·426 688^0.4 = 357.2.
        assert_eq!(gof_bins(1000), 31);
        assert_eq!(gof_bins(10_000), 79);
        assert_eq!(gof_bins(426_688), 357);
        // At least 10 expected per bin wherever there are 40 samples or more.
        for n in (40..200_000).step_by(997) {
            assert!(n / gof_bins(n) >= 10, "n = {n}");
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = [0.1, -0.3, 0.7, 1.2, -0.5];
        assert!(ks_normal(&x, 0.0, 0.0).is_err());
        assert!(ks_normal(&x, f64::NAN, 1.0).is_err());
        assert!(ks_normal(&[0.1], 0.0, 1.0).is_err());
        assert!(ks_normal(&[0.1, f64::NAN], 0.0, 1.0).is_err());
        assert!(chi2_gof_normal(&x, 0.0, 1.0, 2).is_err()); // 2.5 expected per bin
        assert!(chi2_gof_normal(&x, 0.0, 1.0, 1).is_err());
        assert!(chi2_variance_test(&x, -1.0, None).is_err());
        assert!(chi2_variance_test(&x, 1.0, Some(f64::INFINITY)).is_err());
        assert!(chi2_variance_test(&[1.0], 1.0, None).is_err());
        assert!(z_test(1.0, 0.0, 0.0).is_err());
        assert!(z_test(f64::NAN, 0.0, 1.0).is_err());
        assert!(chi2_sum_test(&[]).is_err());
    }

    /// `ks_test` with a CDF given as a closure: exponential samples (inverse-CDF from
    /// uniforms, n = 4000) are accepted against their own CDF and rejected against a CDF
    /// with a 10% wrong scale at α = 0.001 (expected D ≈ 0.035 against a critical value
    /// 0.031 at n = 4000). It also
    /// agrees with `ks_normal` on normal samples (same statistic to round-off).
    #[test]
    fn ks_test_with_closure_cdf() {
        use rand::RngExt;
        let mut rng = crate::rng::trajectory_rng(20261127, 0);
        let x: Vec<f64> = (0..4000)
            .map(|_| -(1.0 - rng.random::<f64>()).ln())
            .collect();
        let good = ks_test(&x, |v| if v < 0.0 { 0.0 } else { 1.0 - (-v).exp() }).unwrap();
        let bad = ks_test(&x, |v| if v < 0.0 { 0.0 } else { 1.0 - (-v / 1.1).exp() }).unwrap();
        assert!(good.p_value > 1e-3, "true CDF rejected: {good:?}");
        assert!(bad.p_value < 1e-3, "wrong CDF accepted: {bad:?}");
        let z: Vec<f64> = (0..500)
            .map(|_| rng.sample(rand_distr::StandardNormal))
            .collect();
        let n = normal(0.0, 1.0).unwrap();
        let a = ks_test(&z, |v| n.cdf(v)).unwrap();
        let b = ks_normal(&z, 0.0, 1.0).unwrap();
        assert!((a.statistic - b.statistic).abs() < 1e-12);
    }
}
