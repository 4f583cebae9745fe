//! Welch power spectral density estimates and the exact AR(1) density.
//!
//! # Convention (contract)
//! For a series x sampled at spacing dt with autocovariance γ(k), the two-sided spectral
//! density is S(f) = Σ_k γ(k) dt e^{−2πi f k dt} on |f| ≤ f_N = 1/(2dt), with
//! ∫_{−f_N}^{f_N} S(f) df = var x. The estimates here are of the **one-sided** density
//! G(f) = 2 S(f), in units of x²·time, at f_k = k/(L dt), k = 0..=L/2 (L = segment
//! length, required even, so the last bin is the Nyquist frequency). Every bin, including
//! DC and Nyquist, estimates 2 S(f_k), so that
//!
//! ```text
//! Σ'_k G_k Δf ≈ var x,   Δf = 1/(L dt),
//! ```
//!
//! where Σ' weights the DC and Nyquist bins by ½ (trapezoidal rule on [0, f_N];
//! see [`Psd::integral`]). With the per-segment mean removed the DC bin is biased low.
//!
//! # Method (Welch 1967)
//! P. D. Welch, IEEE Trans. Audio Electroacoust. AU-15, 70 (1967). Segments of length L
//! overlap by 50 % (step L/2); in each the segment mean is subtracted, the periodic Hann
//! window w_j = sin²(π j/L) applied, and the real FFT X_k taken (`realfft`). Then
//! G_k = 2 dt ⟨|X_k|²⟩ / Σ_j w_j², averaged over all segments. By Parseval,
//! Σ'_k G_k Δf is the window-weighted mean square of the data.
//!
//! Away from DC and Nyquist each bin is approximately G(f_k)·χ²_ν/ν with the equivalent
//! degrees of freedom (Welch 1967; Percival & Walden 1993, eq. 292b)
//! ν = 2K² / Σ_series [K_s + 2 Σ_{m≥1} (K_s − m) ρ_w(m)²], where K_s is the number of
//! segments of series s, K = Σ K_s, and ρ_w(m) = Σ_j w_j w_{j+mL/2} / Σ_j w_j²
//! (ρ_w(1) = 1/6 for Hann at 50 % overlap, so ν ≈ 1.89 K for long series). The DC and
//! Nyquist bins are real and have ν/2. The window also causes leakage: the expected
//! estimate is G convolved with the Hann spectral window (main lobe ±2 bins), so L must be
//! large compared with the correlation time for a bias-free comparison.

use std::f64::consts::PI;

use realfft::RealFftPlanner;

use crate::error::{Error, Result};

/// A one-sided power spectral density estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Frequencies f_k = k/(L dt), k = 0..=L/2.
    pub freqs: Vec<f64>,
    /// One-sided density estimates G_k ≈ 2 S(f_k) (x²·time).
    pub density: Vec<f64>,
    /// Number of segments averaged (over all series).
    pub n_segments: usize,
    /// Equivalent degrees of freedom ν of each interior bin (see module docs).
    pub dof: f64,
}

impl Psd {
    /// Σ'_k G_k Δf with the DC and Nyquist bins weighted ½: the estimate of the variance
    /// of the series (exactly the window-weighted mean square of the mean-removed
    /// segments, averaged over segments).
    pub fn integral(&self) -> f64 {
        let (Some(first), Some(last)) = (self.density.first(), self.density.last()) else {
            return 0.0;
        };
        let df = self.freqs.get(1).copied().unwrap_or(0.0) - self.freqs[0];
        (self.density.iter().sum::<f64>() - 0.5 * (first + last)) * df
    }
}

/// Welch PSD of one series: periodic Hann window, 50 % overlap, segment mean removed,
/// one-sided density normalized as in the module documentation.
///
/// # Errors
/// [`Error::InvalidParameter`] if `segment_len` is odd or below 4, the series is
/// shorter than `segment_len` or has a non-finite value, or `dt` is not finite and
/// positive.
pub fn welch(x: &[f64], dt: f64, segment_len: usize) -> Result<Psd> {
    welch_pooled(&[x], dt, segment_len)
}

/// Welch PSD averaged over the segments of several independent series (same `dt`).
/// Each series contributes its own 50 %-overlapping segments; segments never straddle
/// two series. The degrees of freedom account for the overlap within each series.
///
/// # Errors
/// As [`welch`] for every series, and [`Error::InvalidParameter`] if `series` is empty.
pub fn welch_pooled(series: &[&[f64]], dt: f64, segment_len: usize) -> Result<Psd> {
    let l = segment_len;
    if l < 4 || !l.is_multiple_of(2) {
        return Err(Error::invalid("segment_len", l, "even and >= 4"));
    }
    crate::error::require_positive("dt", dt)?;
    if series.is_empty() {
        return Err(Error::invalid("series", "no series", "at least one series"));
    }
    for (j, s) in series.iter().enumerate() {
        super::require_samples(&format!("series[{j}]"), s, l)?;
    }

    let window: Vec<f64> = (0..l)
        .map(|j| (PI * j as f64 / l as f64).sin().powi(2))
        .collect();
    let sw2: f64 = window.iter().map(|w| w * w).sum();
    let step = l / 2;

    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(l);
    let mut buf = fft.make_input_vec();
    let mut spec = fft.make_output_vec();
    let mut acc = vec![0.0; l / 2 + 1];
    let mut seg_counts = Vec::with_capacity(series.len());
    for s in series {
        let k_s = (s.len() - l) / step + 1;
        seg_counts.push(k_s);
        for seg in 0..k_s {
            let chunk = &s[seg * step..seg * step + l];
            let mean = super::mean_of(chunk);
            for ((b, &v), &w) in buf.iter_mut().zip(chunk).zip(&window) {
                *b = (v - mean) * w;
            }
            fft.process(&mut buf, &mut spec)
                .map_err(|e| Error::Numerical {
                    routine: "welch (realfft)".into(),
                    detail: e.to_string(),
                })?;
            for (a, c) in acc.iter_mut().zip(&spec) {
                *a += c.norm_sqr();
            }
        }
    }
    let n_segments: usize = seg_counts.iter().sum();
    let scale = 2.0 * dt / (n_segments as f64 * sw2);
    let density = acc.iter().map(|a| a * scale).collect();
    let freqs = (0..=l / 2).map(|k| k as f64 / (l as f64 * dt)).collect();

    // Equivalent degrees of freedom (Welch 1967; Percival & Walden 1993).
    let rho_w: Vec<f64> = (1..)
        .map(|m| m * step)
        .take_while(|&off| off < l)
        .map(|off| {
            (0..l - off)
                .map(|j| window[j] * window[j + off])
                .sum::<f64>()
                / sw2
        })
        .collect();
    let denom: f64 = seg_counts
        .iter()
        .map(|&k_s| {
            let k_s = k_s as f64;
            k_s + 2.0
                * rho_w
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (k_s - (i + 1) as f64).max(0.0) * r * r)
                    .sum::<f64>()
        })
        .sum();
    let k_tot = n_segments as f64;
    Ok(Psd {
        freqs,
        density,
        n_segments,
        dof: 2.0 * k_tot * k_tot / denom,
    })
}

/// Exact one-sided spectral density (same convention as [`welch`]) of the stationary
/// AR(1) sequence x_{k+1} = ρ x_k + e_k with stationary variance `variance`, sampled at
/// spacing `dt`:
///
/// ```text
/// G(f) = 2 dt σ² (1 − ρ²) / (1 − 2ρ cos(2π f dt) + ρ²),
/// ```
///
/// from S(f) = Σ_k σ² ρ^{|k|} dt e^{−2πifkdt}. ∫_0^{1/(2dt)} G(f) df = σ².
/// Returns NaN unless |ρ| < 1, `variance` ≥ 0 and `dt` > 0 (all finite) and `f` is finite.
pub fn ar1_density(rho: f64, variance: f64, dt: f64, f: f64) -> f64 {
    let valid = rho.is_finite()
        && rho.abs() < 1.0
        && variance.is_finite()
        && variance >= 0.0
        && dt.is_finite()
        && dt > 0.0
        && f.is_finite();
    if !valid {
        return f64::NAN;
    }
    2.0 * dt * variance * (1.0 - rho * rho)
        / (1.0 - 2.0 * rho * (2.0 * PI * f * dt).cos() + rho * rho)
}

/// Exact expectation of the [`welch`] estimate, bin by bin, for a stationary series with
/// autocovariance `acov[d] = γ(d)` (lags `0..segment_len`), including the Hann window and
/// the per-segment mean removal.
///
/// With `u_a = w_a e^{−2πika/L} − W_k/L` (`W_k = Σ_j w_j e^{−2πikj/L}`), the windowed,
/// demeaned transform of a segment is `X_k = Σ_a u_a x_a`, so
/// `E|X_k|² = Σ_{a,b} u_a ū_b γ(a − b)` and `E[G_k] = 2 dt E|X_k|² / Σ_j w_j²`. This is
/// the sharp reference for a spectrum check: leakage and the low bias of the first bins
/// are in it, not in the comparison's error. Cost O(L³/2) (L = segment length).
///
/// # Errors
/// [`Error::InvalidParameter`] if `segment_len` is odd or < 4, `acov` is shorter than
/// `segment_len`, or `dt` is not positive.
pub fn welch_expectation(acov: &[f64], dt: f64, segment_len: usize) -> Result<Vec<f64>> {
    let l = segment_len;
    if l < 4 || !l.is_multiple_of(2) {
        return Err(Error::invalid("segment_len", l, "even and >= 4"));
    }
    crate::error::require_positive("dt", dt)?;
    if acov.len() < l || acov.iter().any(|v| !v.is_finite()) {
        return Err(Error::invalid(
            "acov",
            acov.len(),
            format!("{l} finite lags"),
        ));
    }
    let window: Vec<f64> = (0..l)
        .map(|j| (PI * j as f64 / l as f64).sin().powi(2))
        .collect();
    let sw2: f64 = window.iter().map(|w| w * w).sum();
    let mut out = Vec::with_capacity(l / 2 + 1);
    for k in 0..=l / 2 {
        let theta = 2.0 * PI * k as f64 / l as f64;
        let (mut wr, mut wi) = (0.0, 0.0);
        for (j, w) in window.iter().enumerate() {
            wr += w * (theta * j as f64).cos();
            wi -= w * (theta * j as f64).sin();
        }
        let u: Vec<(f64, f64)> = window
            .iter()
            .enumerate()
            .map(|(a, w)| {
                let ph = theta * a as f64;
                (w * ph.cos() - wr / l as f64, -w * ph.sin() - wi / l as f64)
            })
            .collect();
        let mut e = 0.0;
        for (a, ua) in u.iter().enumerate() {
            for (b, ub) in u.iter().enumerate() {
                // Re(u_a conj(u_b)) γ(|a − b|); the imaginary parts cancel in the sum.
                e += (ua.0 * ub.0 + ua.1 * ub.1) * acov[a.abs_diff(b)];
            }
        }
        out.push(2.0 * dt * e / sw2);
    }
    Ok(out)
}

/// [`welch_expectation`] for a stationary AR(1) sequence with lag-one correlation `rho`
/// and variance `variance`: γ(d) = variance·ρ^d.
///
/// # Errors
/// As [`welch_expectation`]; also if |ρ| ≥ 1 or the variance is not positive.
pub fn welch_expectation_ar1(
    rho: f64,
    variance: f64,
    dt: f64,
    segment_len: usize,
) -> Result<Vec<f64>> {
    if !(rho.is_finite() && rho.abs() < 1.0) {
        return Err(Error::invalid("rho", rho, "in (-1, 1)"));
    }
    crate::error::require_positive("variance", variance)?;
    let acov: Vec<f64> = (0..segment_len)
        .map(|d| variance * rho.powi(d as i32))
        .collect();
    welch_expectation(&acov, dt, segment_len)
}

#[cfg(test)]
mod tests {
    //! Deterministic checks of the normalization (Parseval identity for one segment,
    //! exact to round-off), of the AR(1) density integral (trapezoidal quadrature of a
    //! smooth periodic function, exact to ~1e-12), of the degrees of freedom, and of the
    //! error paths. Statistical validation is in `tests/stats_validation.rs`.
    use super::*;

    #[test]
    fn single_segment_parseval() {
        let l = 64;
        let x: Vec<f64> = (0..l).map(|i| ((i * 7919) % 101) as f64 / 13.0).collect();
        let psd = welch(&x, 0.25, l).unwrap();
        assert_eq!(psd.n_segments, 1);
        assert_eq!(psd.freqs.len(), l / 2 + 1);
        assert!((psd.freqs[l / 2] - 2.0).abs() < 1e-12); // Nyquist 1/(2 dt)
        let m = super::super::mean_of(&x);
        let (mut num, mut den) = (0.0, 0.0);
        for (j, v) in x.iter().enumerate() {
            let w = (PI * j as f64 / l as f64).sin().powi(2);
            num += w * w * (v - m).powi(2);
            den += w * w;
        }
        assert!((psd.integral() - num / den).abs() < 1e-12 * num / den);
        assert!((psd.dof - 2.0).abs() < 1e-12);
    }

    #[test]
    fn dof_for_many_segments() {
        let x = vec![0.5; 1 << 12];
        let mut y = x.clone();
        y[3] = 1.0;
        let psd = welch(&y, 1.0, 64).unwrap();
        assert_eq!(psd.n_segments, 127);
        // ρ_w(1) = 1/6 exactly for the periodic Hann window at 50 % overlap.
        let expect = 2.0 * 127.0 * 127.0 / (127.0 + 2.0 * 126.0 / 36.0);
        assert!((psd.dof - expect).abs() < 1e-9, "{} vs {expect}", psd.dof);
    }

    #[test]
    fn ar1_density_integrates_to_variance() {
        let (rho, var, dt) = (0.9, 2.5, 0.1);
        let n = 20_000;
        let fny = 0.5 / dt;
        let h = fny / n as f64;
        let mut s = 0.5 * (ar1_density(rho, var, dt, 0.0) + ar1_density(rho, var, dt, fny));
        for i in 1..n {
            s += ar1_density(rho, var, dt, i as f64 * h);
        }
        assert!((s * h - var).abs() < 1e-9 * var);
        assert!(ar1_density(1.0, 1.0, 1.0, 0.1).is_nan());
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = vec![1.0, 2.0, 0.0, 3.0, 1.0, 2.0, 0.0, 3.0];
        assert!(welch(&x, 1.0, 9).is_err()); // longer than data
        assert!(welch(&x, 1.0, 5).is_err()); // odd
        assert!(welch(&x, 1.0, 2).is_err());
        assert!(welch(&x, -1.0, 4).is_err());
        assert!(welch_pooled(&[], 1.0, 4).is_err());
        let mut y = x.clone();
        y[2] = f64::NAN;
        assert!(welch(&y, 1.0, 4).is_err());
    }

    /// The exact Welch expectation for AR(1) against a Monte Carlo average of the
    /// estimator (4000 segments of 32 samples, ρ = 0.8): every bin within 4.5 standard
    /// errors of the mean periodogram (the standard error of each bin's mean is known from
    /// its χ²₂ law, ≈ E/√(K·ν/2) with ν ≈ 1.89), and close to the unwindowed AR(1)
    /// density away from DC, where leakage is small.
    #[test]
    fn welch_expectation_matches_monte_carlo() {
        use rand::RngExt;
        let (rho, var, dt, l): (f64, f64, f64, usize) = (0.8, 2.0, 0.5, 32);
        let mut rng = crate::rng::trajectory_rng(20261123, 0);
        let n = 4000 * l / 2 + l / 2;
        let mut x = Vec::with_capacity(n);
        let mut v: f64 = rng.sample::<f64, _>(rand_distr::StandardNormal) * var.sqrt();
        for _ in 0..n {
            x.push(v);
            let z: f64 = rng.sample(rand_distr::StandardNormal);
            v = rho * v + (var * (1.0 - rho * rho)).sqrt() * z;
        }
        let psd = welch(&x, dt, l).unwrap();
        let e = welch_expectation_ar1(rho, var, dt, l).unwrap();
        let se_rel = (2.0 / psd.dof).sqrt();
        for (k, (d, ek)) in psd.density.iter().zip(&e).enumerate().take(l / 2).skip(1) {
            let z = (d - ek) / (ek * se_rel);
            assert!(z.abs() < 4.5, "bin {k}: estimate {d} expected {ek} z {z}");
        }
        // Mean removal depletes the DC bin; far from DC the expectation is the density.
        assert!(e[0] < ar1_density(rho, var, dt, 0.0));
        let mid = l / 4;
        let f = psd.freqs[mid];
        assert!((e[mid] / ar1_density(rho, var, dt, f) - 1.0).abs() < 0.05);
    }
}
