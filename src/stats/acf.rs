//! Autocovariance and autocorrelation of a stationary series by FFT.
//!
//! Estimator (biased, 1/n normalization; Priestley 1981, §5.3; Box & Jenkins):
//!
//! ```text
//! γ̂(k) = (1/n) Σ_{i=0}^{n-1-k} (x_i − x̄)(x_{i+k} − x̄),   ρ̂(k) = γ̂(k)/γ̂(0).
//! ```
//!
//! The 1/n (rather than 1/(n−k)) normalization makes the estimated sequence positive
//! semi-definite and has a smaller mean-square error at large lags; its bias is a factor
//! (1 − k/n). It is computed by the Wiener–Khinchin theorem: the mean-subtracted series is
//! zero-padded to a power of two N ≥ 2n (so the circular correlation equals the linear
//! one), transformed with a real FFT (`realfft`), the squared modulus is transformed back,
//! and the result is divided by N·n. Cost O(n log n) for all lags.

use std::cell::RefCell;

use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

use crate::error::{Error, Result};

use super::{mean_of, require_samples};

/// Biased (1/n) autocovariance γ̂(k), k = 0..=max_lag, of `x` about its sample mean,
/// computed by FFT (see the module documentation for the exact formula).
///
/// # Errors
/// [`Error::InvalidParameter`] if `x` has fewer than 2 values, contains a non-finite
/// value, or `max_lag ≥ x.len()`.
pub fn autocovariance(x: &[f64], max_lag: usize) -> Result<Vec<f64>> {
    require_samples("x", x, 2)?;
    if max_lag >= x.len() {
        return Err(Error::invalid(
            "max_lag",
            max_lag,
            format!("< series length {}", x.len()),
        ));
    }
    autocovariance_about(x, mean_of(x), max_lag)
}

/// Autocorrelation ρ̂(k) = γ̂(k)/γ̂(0), k = 0..=max_lag, with γ̂ from [`autocovariance`].
///
/// # Errors
/// As [`autocovariance`], and [`Error::InvalidParameter`] if the series is constant
/// (γ̂(0) = 0).
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Result<Vec<f64>> {
    let g = autocovariance(x, max_lag)?;
    normalize(g)
}

/// Divides an autocovariance sequence by its lag-0 value.
pub(crate) fn normalize(mut g: Vec<f64>) -> Result<Vec<f64>> {
    let g0 = g[0];
    if !(g0.is_finite() && g0 > 0.0) {
        return Err(Error::invalid(
            "x",
            format!("a series with sample variance {g0}"),
            "a non-constant series (sample variance > 0)",
        ));
    }
    for v in &mut g {
        *v /= g0;
    }
    Ok(g)
}

thread_local! {
    /// Per-thread FFT planner: `RealFftPlanner` caches plans by length, and planning a
    /// large transform costs more than executing it, so repeated calls reuse the plans.
    static PLANNER: RefCell<RealFftPlanner<f64>> = RefCell::new(RealFftPlanner::new());
}

/// FFT autocovariance of already validated data about a given `mean` (1/n normalization).
pub(crate) fn autocovariance_about(x: &[f64], mean: f64, max_lag: usize) -> Result<Vec<f64>> {
    let n = x.len();
    let nfft = (2 * n).next_power_of_two();
    let (forward, inverse) = PLANNER.with(|p| {
        let mut p = p.borrow_mut();
        (p.plan_fft_forward(nfft), p.plan_fft_inverse(nfft))
    });
    let mut buf = forward.make_input_vec();
    for (b, &v) in buf.iter_mut().zip(x) {
        *b = v - mean;
    }
    let mut spec = forward.make_output_vec();
    let fft_err = |e: realfft::FftError| Error::Numerical {
        routine: "autocovariance (realfft)".into(),
        detail: e.to_string(),
    };
    forward.process(&mut buf, &mut spec).map_err(fft_err)?;
    for c in spec.iter_mut() {
        *c = Complex::new(c.norm_sqr(), 0.0);
    }
    inverse.process(&mut spec, &mut buf).map_err(fft_err)?;
    let scale = 1.0 / (nfft as f64 * n as f64);
    Ok(buf[..=max_lag].iter().map(|v| v * scale).collect())
}

#[cfg(test)]
mod tests {
    //! Checks the FFT estimator against the direct O(n·lag) sum of the defining formula
    //! on a random series, and the error paths. Tolerance 1e-10 relative: FFT round-off.
    use super::*;
    use crate::rng::trajectory_rng;
    use rand::RngExt;
    use rand_distr::StandardNormal;

    const SEED: u64 = 0xAC_F0;

    fn direct(x: &[f64], max_lag: usize) -> Vec<f64> {
        let n = x.len();
        let m = mean_of(x);
        (0..=max_lag)
            .map(|k| (0..n - k).map(|i| (x[i] - m) * (x[i + k] - m)).sum::<f64>() / n as f64)
            .collect()
    }

    #[test]
    fn fft_matches_direct_sum() {
        let mut rng = trajectory_rng(SEED, 0);
        // A correlated series with a non-zero mean, odd length (not a power of two).
        let mut x = Vec::with_capacity(1001);
        let mut s = 0.0;
        for _ in 0..1001 {
            let e: f64 = rng.sample(StandardNormal);
            s = 0.7 * s + e;
            x.push(3.0 + s);
        }
        let max_lag = 1000;
        let fast = autocovariance(&x, max_lag).unwrap();
        let slow = direct(&x, max_lag);
        for (k, (a, b)) in fast.iter().zip(&slow).enumerate() {
            assert!(
                (a - b).abs() <= 1e-10 * slow[0],
                "lag {k}: fft {a} direct {b}"
            );
        }
        let rho = autocorrelation(&x, 10).unwrap();
        assert!((rho[0] - 1.0).abs() < 1e-14);
        assert!((rho[3] - slow[3] / slow[0]).abs() < 1e-10);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(autocovariance(&[1.0], 0).is_err());
        assert!(autocovariance(&[1.0, 2.0], 2).is_err());
        assert!(autocovariance(&[1.0, f64::NAN, 2.0], 1).is_err());
        assert!(autocorrelation(&[2.0; 10], 3).is_err());
    }
}
