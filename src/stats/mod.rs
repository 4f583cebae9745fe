//! Estimators and hypothesis tests used to judge simulated trajectories against exact
//! references.
//!
//! Every estimator here is validated on exactly solvable processes (i.i.d. Gaussians,
//! the AR(1) / discretely sampled Ornstein–Uhlenbeck process) in
//! `tests/stats_validation.rs`.
//!
//! # What each piece is for
//! - [`moments`]: means and variances of *correlated* time series with honest standard
//!   errors. [`mean_with_error`] uses the integrated autocorrelation time τ_int with
//!   Sokal's automatic windowing ([`integrated_autocorrelation_time`]);
//!   [`blocking_std_error`] is the independent Flyvbjerg–Petersen cross-check;
//!   [`variance_with_error`] estimates a (co)variance of a mode amplitude from one long
//!   trajectory; [`ensemble_mean`] is for independent samples (one per trajectory).
//! - [`acf`]: FFT autocovariance / autocorrelation (biased 1/n estimator).
//! - [`decay`]: the exponential relaxation rate of an OU-like series (e.g. a modal
//!   amplitude) from one or many trajectories, with a block-jackknife error.
//! - [`spectrum`]: Welch power spectral density and the exact AR(1) density to compare it
//!   with.
//! - [`hypothesis`]: KS and χ² goodness-of-fit tests against a normal law, the χ² test of
//!   a variance, z-tests, the χ² combination of z-scores, and the Holm–Bonferroni
//!   family-wise correction.
//! - [`quadform`]: the null law of a sum of squares of stationary Gaussian series — exact
//!   for AR(1) series (a modal amplitude of a linear scheme), by the Whittle approximation
//!   for a sum of correlated AR(1) modes (the field at a point) — and the variance test
//!   built on it, whose scale comes from the reference instead of the data under test.
//!
//! # Pitfall: correlated samples
//! The goodness-of-fit tests ([`ks_normal`], [`chi2_gof_normal`], [`chi2_variance_test`])
//! assume *independent* samples. Successive states of one Langevin trajectory are
//! correlated over τ_int steps; feeding them in unthinned makes the effective sample size
//! n/(2τ_int) instead of n, so the tests **over-reject** a true null (the statistic
//! fluctuates more than its null distribution allows). Either use one sample per
//! independent trajectory, or thin a single trajectory by a stride well above 2τ_int
//! (several times τ_int, see [`integrated_autocorrelation_time`]). Estimators whose
//! errors are computed here from the data themselves ([`mean_with_error`],
//! [`variance_with_error`], [`decay_rate`]) do account for the correlation, and their
//! z-scores can be used with [`z_test`] / [`chi2_sum_test`].

pub mod acf;
pub mod decay;
pub mod hypothesis;
pub mod moments;
pub mod quadform;
pub mod spectrum;

pub use acf::{autocorrelation, autocovariance};
pub use decay::{LagRule, RateEstimate, decay_rate, decay_rate_with_lag};
pub use hypothesis::{
    TestOutcome, chi2_gof_normal, chi2_sum_test, chi2_variance_test, equivalent_z, gof_bins, holm,
    ks_normal, ks_test, t_test, z_test,
};
pub use moments::{
    IatEstimate, MeanEstimate, blocking_std_error, combine_independent, ensemble_mean,
    integrated_autocorrelation_time, mean_with_error, mean_with_error_at,
    pooled_integrated_autocorrelation_time, variance_with_error,
};
pub use quadform::{
    Ar1SquareSum, SquareSumLaw, WeightedChiSquares, ar1_square_sum_test, square_sum_test, sum_test,
};
pub use spectrum::{
    Psd, ar1_density, welch, welch_expectation, welch_expectation_ar1, welch_pooled,
};

use crate::error::{Error, Result};

/// Checks that `x` holds at least `min` values, all finite.
pub(crate) fn require_samples(name: &str, x: &[f64], min: usize) -> Result<()> {
    if x.len() < min {
        return Err(Error::invalid(
            name,
            format!("{} samples", x.len()),
            format!("at least {min} samples"),
        ));
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            format!("{name}[{i}]"),
            x[i],
            "finite (no NaN or infinity)",
        ));
    }
    Ok(())
}

/// Arithmetic mean of a non-empty slice.
pub(crate) fn mean_of(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}
