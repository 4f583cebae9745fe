//! Exponential decay rate of the autocorrelation of an Ornstein–Uhlenbeck-like series.
//!
//! For a stationary series with ρ(t) = e^{−λ t} (an OU process sampled at spacing dt,
//! i.e. an AR(1) sequence with ρ(k) = ρ^k, ρ = e^{−λ dt}) the rate is estimated from one
//! lag k as
//!
//! ```text
//! λ̂ = −ln ρ̂(k) / (k dt),   ρ̂(k) = [C_k / P_k] / [C_0 / N],
//! C_k = Σ_series Σ_i (x_i − μ)(x_{i+k} − μ),   C_0 = Σ_series Σ_i (x_i − μ)²,
//! ```
//!
//! pooled over all series, where P_k is the number of lag-k pairs and N the number of
//! samples (the pair-count normalization removes the (1 − k/n) bias of the 1/n
//! autocovariance, which matters for many short series). μ is the known mean or the
//! pooled sample mean.
//!
//! **Choice of lag.** A pilot ρ̂(1) gives λ̂₁ dt = −ln ρ̂(1); the lag is
//! k = max(1, round(1/(λ̂₁ dt))), i.e. where ρ(k) ≈ e^{−1}. For an AR(1) sequence the
//! large-sample relative variance of λ̂ is dominated by e^{2λkdt}/(λkdt)², which is
//! smallest near λ k dt = 1: shorter lags lose resolution (ρ(k) close to 1), longer lags
//! drown ρ(k) in noise. For a series that is not a single exponential the estimate is the
//! effective rate at that lag. Where the rate is known beforehand (a test against an
//! exact reference) the lag is taken from it instead ([`LagRule::Expected`]), so that the
//! lag, and whether the series are long enough for it, do not depend on the data: a lag
//! from the data would make a test that is skipped when its series are too short run
//! only on data whose pilot decay looked fast, and its p-values would be biased.
//!
//! **Error.** Delete-one-block jackknife (Quenouille 1956; Tukey 1958; Efron & Stein
//! 1981; for blocks of a dependent series Künsch, Ann. Stat. 17, 1217 (1989)): the sums
//! above are additive over blocks, each replicate recomputes λ̂ (and the pooled mean, if
//! estimated) without one block, and SE² = (B−1)/B Σ_b (λ̂_(b) − λ̄)². Blocks are groups
//! of whole series when there are at least 20 series (up to [`TARGET_BLOCKS`]
//! groups of nearly equal numbers of series); otherwise each series is cut into
//! contiguous segments (a lag-k pair belongs to the block of its first sample). The
//! target is b = min([`TARGET_BLOCKS`], N / ([`MIN_SEGMENT_LAGS`]·k)) blocks of average
//! length ℓ = N/b ≥ [`MIN_SEGMENT_LAGS`]·k over the N samples; a series of n samples is
//! cut into round(n/ℓ) equal segments, at least one, so a segment is at least about ¾ℓ
//! long (15 lags) unless its whole series is shorter (8 series of 32 samples at lag 1
//! give 16 segments of 16 samples; the validation tests calibrate that layout). At least
//! [`MIN_JACKKNIFE_BLOCKS`] blocks are required. The confidence interval is
//! λ̂ ± t_{B−1, (1+confidence)/2} · SE.
//!
//! **Correlation with the variance.** The same replicates give the jackknife correlation
//! of λ̂ with the series' second moment Ĉ₀ = C_0/N (about the known or pooled mean: the
//! variance estimate of the same data), cov_J/(SE_λ·SE_C₀) with
//! cov_J = (B−1)/B Σ_b (λ̂_(b) − λ̄)(Ĉ₀_(b) − C̄₀). The two are not independent: a long
//! excursion raises Ĉ₀ and slows the measured decay. A parameter estimated from both (the
//! drag ξ ∝ 1/(Ĉ₀λ̂), `verify::fit`) needs it.
//!
//! The estimator is consistent and its bias is O(1/N) (ratio and logarithm
//! nonlinearities), negligible compared with its standard error for the sample sizes at
//! which it is used; the validation tests check the coverage of the interval.

use statrs::distribution::{ContinuousCDF, StudentsT};

use crate::error::{Error, Result};

/// Target number of jackknife blocks.
pub const TARGET_BLOCKS: usize = 32;
/// Minimum number of jackknife blocks.
pub const MIN_JACKKNIFE_BLOCKS: usize = 10;
/// Contiguous segments cut from the series are this many lags k long on average (per
/// series at least about ¾ of it, see the module documentation), so that neighbouring
/// blocks are nearly independent.
pub const MIN_SEGMENT_LAGS: usize = 20;
/// Number of series from which whole series are used as (groups of) blocks.
const WHOLE_SERIES_BLOCKS: usize = 20;

/// A decay-rate estimate with a jackknife standard error and confidence interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateEstimate {
    /// Estimated rate λ̂ (inverse time units of `dt`).
    pub rate: f64,
    /// Delete-one-block jackknife standard error of λ̂.
    pub std_error: f64,
    /// Lower end of the t confidence interval.
    pub ci_low: f64,
    /// Upper end of the t confidence interval.
    pub ci_high: f64,
    /// The lag k (in samples) at which ρ̂(k) was evaluated.
    pub lag: usize,
    /// Number of jackknife blocks B (the interval uses B − 1 degrees of freedom).
    pub n_blocks: usize,
    /// Jackknife correlation of λ̂ with the second moment Ĉ₀ of the same series (see the
    /// module documentation); NaN if either has no jackknife spread.
    pub variance_correlation: f64,
    /// Whether the lag came from the data's pilot ρ̂(1): always with [`LagRule::Pilot`];
    /// with [`LagRule::Expected`] only as its fallback (ρ̂ not positive at the expected
    /// lag).
    pub lag_from_data: bool,
}

/// Additive sufficient statistics of one block for the lag-k ratio estimator
/// (values already shifted by a reference so that sums stay well conditioned).
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    n: f64,
    sx: f64,
    sxx: f64,
    p: f64,
    sxy: f64,
    sh: f64,
    st: f64,
}

impl Sums {
    /// Sums over samples `start..end` of `x` and over the lag-k pairs starting there.
    fn of(x: &[f64], start: usize, end: usize, k: usize, shift: f64) -> Self {
        let mut s = Sums::default();
        for i in start..end {
            let v = x[i] - shift;
            s.n += 1.0;
            s.sx += v;
            s.sxx += v * v;
            if let Some(&w) = x.get(i + k) {
                let w = w - shift;
                s.p += 1.0;
                s.sxy += v * w;
                s.sh += v;
                s.st += w;
            }
        }
        s
    }

    fn add(self, o: Self) -> Self {
        Sums {
            n: self.n + o.n,
            sx: self.sx + o.sx,
            sxx: self.sxx + o.sxx,
            p: self.p + o.p,
            sxy: self.sxy + o.sxy,
            sh: self.sh + o.sh,
            st: self.st + o.st,
        }
    }

    fn sub(self, o: Self) -> Self {
        Sums {
            n: self.n - o.n,
            sx: self.sx - o.sx,
            sxx: self.sxx - o.sxx,
            p: self.p - o.p,
            sxy: self.sxy - o.sxy,
            sh: self.sh - o.sh,
            st: self.st - o.st,
        }
    }

    /// The mean about which moments are taken: 0 if the mean is known (data shifted by
    /// it), else the mean of these sums.
    fn mu(&self, known_mean: bool) -> f64 {
        if known_mean { 0.0 } else { self.sx / self.n }
    }

    /// The second moment Ĉ₀ = C_0/N about [`Self::mu`].
    fn c0(&self, known_mean: bool) -> f64 {
        let mu = self.mu(known_mean);
        (self.sxx - 2.0 * mu * self.sx + mu * mu * self.n) / self.n
    }

    /// ρ̂(k) about [`Self::mu`].
    fn rho(&self, known_mean: bool) -> f64 {
        let mu = self.mu(known_mean);
        let ck = (self.sxy - mu * (self.sh + self.st) + mu * mu * self.p) / self.p;
        ck / self.c0(known_mean)
    }
}

fn numerical(detail: String) -> Error {
    Error::Numerical {
        routine: "decay_rate".into(),
        detail,
    }
}

/// Exponential decay rate λ of the autocorrelation of one or more independent stationary
/// series sampled at spacing `dt`, with a block-jackknife standard error and a t
/// confidence interval at level `confidence`.
///
/// See the module documentation for the estimator, the automatic lag choice and the
/// blocking. `known_mean` (e.g. 0 for a modal amplitude) is used instead of the pooled
/// sample mean when given.
///
/// # Errors
/// - [`Error::InvalidParameter`] if `series` is empty, a series has fewer than 2 values
///   or a non-finite value, `dt` is not finite and positive, `confidence` is not in
///   (0, 1), or `known_mean` is not finite;
/// - [`Error::Numerical`] if the pilot ρ̂(1) is not in (0, 1) (decay too fast for the
///   sampling, or no decay), if the series are too short for the chosen lag or for
///   [`MIN_JACKKNIFE_BLOCKS`] blocks, or if a (jackknife) ρ̂(k) is not positive.
pub fn decay_rate(
    series: &[&[f64]],
    dt: f64,
    known_mean: Option<f64>,
    confidence: f64,
) -> Result<RateEstimate> {
    decay_rate_with_lag(series, dt, known_mean, confidence, LagRule::Pilot)
}

/// How [`decay_rate_with_lag`] chooses the lag k at which ρ̂(k) is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LagRule {
    /// From the data: the pooled pilot ρ̂(1) gives k = max(1, round(−1/ln ρ̂(1))) (module
    /// documentation). Whether the estimate can be made (enough blocks at that lag) then
    /// depends on the data, so a caller that tests the estimate must not skip on failure
    /// without biasing the tests it does run.
    Pilot,
    /// From a rate λ known before the data are seen (the exact reference's rate, in the
    /// inverse time units of `dt`): k = max(1, round(1/(λ dt))), lowered to the longest
    /// lag at which the series still give [`MIN_JACKKNIFE_BLOCKS`] blocks. The lag, and
    /// whether an estimate is made at all, then depend on the sampling plan only — with
    /// one exception: if ρ̂(k), or that of a jackknife replicate, is not positive there
    /// (data that decay far faster than λ; under λ itself a rare event, ρ(k) ≈ e⁻¹), the
    /// pilot's lag is used instead, so that a gross error gives an estimate to be
    /// rejected rather than no estimate ([`RateEstimate::lag_from_data`]).
    Expected(f64),
}

/// [`decay_rate`] with the lag chosen by `lag` ([`LagRule`]).
///
/// # Errors
/// Those of [`decay_rate`]; also [`Error::InvalidParameter`] if an expected rate is not
/// finite and positive, and [`Error::Numerical`] if the series are too short for
/// [`MIN_JACKKNIFE_BLOCKS`] blocks even at lag 1.
pub fn decay_rate_with_lag(
    series: &[&[f64]],
    dt: f64,
    known_mean: Option<f64>,
    confidence: f64,
    lag: LagRule,
) -> Result<RateEstimate> {
    validate_input(series, dt, known_mean, confidence)?;
    let n_total: usize = series.iter().map(|s| s.len()).sum();
    let shift = match known_mean {
        Some(mu) => mu,
        None => series.iter().flat_map(|s| s.iter()).sum::<f64>() / n_total as f64,
    };
    let known = known_mean.is_some();
    let pilot = || -> Result<RateEstimate> {
        let k = choose_lag(series, n_total, shift, known)?;
        let blocks = jackknife_blocks(series, n_total, k, shift)?;
        let estimate = jackknife_estimate(&blocks, k, dt, known, confidence)?;
        Ok(RateEstimate {
            lag_from_data: true,
            ..estimate
        })
    };
    match lag {
        LagRule::Pilot => pilot(),
        LagRule::Expected(rate) => {
            crate::error::require_positive("expected rate", rate)?;
            let k = expected_lag(series, n_total, rate * dt)?;
            require_resolvable(series, k, rate * dt)?;
            let blocks = jackknife_blocks(series, n_total, k, shift)?;
            if all_rho_positive(&blocks, known) {
                jackknife_estimate(&blocks, k, dt, known, confidence)
            } else {
                pilot()
            }
        }
    }
}

/// The fewest standard errors 1/√(pairs) by which the expected ρ(k) must exceed 0 for
/// [`LagRule::Expected`] to estimate a rate: at 5, ρ̂(k) ≤ 0 has probability below 10⁻⁶
/// and ln ρ̂(k) is near normal (relative error at most 20 %).
pub const MIN_RESOLVED_RHO_SE: f64 = 5.0;

/// Refuses (as [`Error::Numerical`], before the data are looked at) a lag `k` at which
/// the expected autocorrelation e^{−k·rate_dt} is below [`MIN_RESOLVED_RHO_SE`] standard
/// errors 1/√(lag pairs): the sampling does not resolve that decay (e.g. a stiff mode
/// sampled at rate·Δt ≫ 1), and an estimate made when the sample's ρ̂ happens to be
/// positive would be biased towards slow decay while one made otherwise would not exist —
/// whether the check runs, and what it finds, would depend on chance.
fn require_resolvable(series: &[&[f64]], k: usize, rate_dt: f64) -> Result<()> {
    let n_pairs: usize = series.iter().map(|s| s.len().saturating_sub(k)).sum();
    let rho = (-rate_dt * k as f64).exp();
    let floor = MIN_RESOLVED_RHO_SE / (n_pairs as f64).sqrt();
    if rho >= floor {
        return Ok(());
    }
    Err(numerical(format!(
        "the expected autocorrelation at lag {k}, exp(-rate x {k} dt) = {rho:.3e} (rate x dt = \
         {rate_dt:.3}), is below {MIN_RESOLVED_RHO_SE} standard errors 1/sqrt({n_pairs} lag \
         pairs) = {floor:.3e}: this sampling does not resolve the decay; rows taken more \
         often (a smaller dt or --every) would"
    )))
}

/// Whether ρ̂(k) of the pooled `blocks` and of every delete-one-block replicate is
/// positive (finite), as [`jackknife_estimate`] needs.
fn all_rho_positive(blocks: &[Sums], known: bool) -> bool {
    let total = blocks.iter().copied().fold(Sums::default(), Sums::add);
    let positive = |s: &Sums| {
        let r = s.rho(known);
        r.is_finite() && r > 0.0
    };
    positive(&total) && blocks.iter().all(|b| positive(&total.sub(*b)))
}

/// The argument checks of [`decay_rate`] (its `Error::InvalidParameter` cases).
fn validate_input(
    series: &[&[f64]],
    dt: f64,
    known_mean: Option<f64>,
    confidence: f64,
) -> Result<()> {
    if series.is_empty() {
        return Err(Error::invalid("series", "no series", "at least one series"));
    }
    for (j, s) in series.iter().enumerate() {
        super::require_samples(&format!("series[{j}]"), s, 2)?;
    }
    crate::error::require_positive("dt", dt)?;
    if !(confidence.is_finite() && confidence > 0.0 && confidence < 1.0) {
        return Err(Error::invalid("confidence", confidence, "in (0, 1)"));
    }
    if let Some(mu) = known_mean
        && !mu.is_finite()
    {
        return Err(Error::invalid("known_mean", mu, "finite"));
    }
    Ok(())
}

/// The lag k = max(1, round(1/(λ̂₁ dt))) where ρ ≈ e^{−1}, from the pooled pilot ρ̂(1);
/// an error if ρ̂(1) is not in (0, 1) or fewer than half the samples start a lag-k pair.
fn choose_lag(series: &[&[f64]], n_total: usize, shift: f64, known: bool) -> Result<usize> {
    let rho1 = series
        .iter()
        .map(|s| Sums::of(s, 0, s.len(), 1, shift))
        .fold(Sums::default(), Sums::add)
        .rho(known);
    if !(rho1.is_finite() && rho1 > 0.0 && rho1 < 1.0) {
        return Err(numerical(format!(
            "pilot lag-1 autocorrelation {rho1} is not in (0, 1): the series does not decay \
             resolvably at this sampling"
        )));
    }
    let lag_f = (-1.0 / rho1.ln()).round().max(1.0);
    let too_short = || {
        numerical(format!(
            "chosen lag {lag_f} (where rho = 1/e) leaves too few lag pairs in series of \
             total length {n_total}: the series are too short for their correlation time"
        ))
    };
    if lag_f >= n_total as f64 {
        return Err(too_short());
    }
    let k = lag_f as usize;
    let n_pairs: usize = series.iter().map(|s| s.len().saturating_sub(k)).sum();
    if 2 * n_pairs < n_total {
        return Err(too_short());
    }
    Ok(k)
}

/// The lag k = max(1, round(1/(λ dt))) for the expected `rate_dt` = λ dt, lowered to the
/// longest lag at which [`jackknife_blocks`] finds [`MIN_JACKKNIFE_BLOCKS`] blocks and at
/// least half the samples start a lag-k pair (the conditions [`choose_lag`] and
/// [`jackknife_blocks`] impose); an error if even lag 1 is too long.
fn expected_lag(series: &[&[f64]], n_total: usize, rate_dt: f64) -> Result<usize> {
    let target = (1.0 / rate_dt).round().clamp(1.0, n_total as f64) as usize;
    let fits = |k: usize| {
        let n_pairs: usize = series.iter().map(|s| s.len().saturating_sub(k)).sum();
        let blocks_fit = series.len() >= WHOLE_SERIES_BLOCKS
            || n_total / (MIN_SEGMENT_LAGS * k) >= MIN_JACKKNIFE_BLOCKS;
        2 * n_pairs >= n_total && blocks_fit
    };
    (1..=target).rev().find(|&k| fits(k)).ok_or_else(|| {
        numerical(format!(
            "{n_total} samples in {} series are too short for {MIN_JACKKNIFE_BLOCKS} \
             jackknife blocks even at lag 1",
            series.len()
        ))
    })
}

/// The jackknife blocks' sums: groups of whole series when there are at least
/// [`WHOLE_SERIES_BLOCKS`] series, else contiguous segments of each series (see the
/// module documentation); an error if fewer than [`MIN_JACKKNIFE_BLOCKS`] result.
fn jackknife_blocks(series: &[&[f64]], n_total: usize, k: usize, shift: f64) -> Result<Vec<Sums>> {
    let mut blocks: Vec<Sums> = Vec::new();
    let m = series.len();
    if m >= WHOLE_SERIES_BLOCKS {
        let b = m.min(TARGET_BLOCKS);
        for g in 0..b {
            let sums = series[g * m / b..(g + 1) * m / b]
                .iter()
                .map(|s| Sums::of(s, 0, s.len(), k, shift))
                .fold(Sums::default(), Sums::add);
            blocks.push(sums);
        }
    } else {
        let b_target = TARGET_BLOCKS.min(n_total / (MIN_SEGMENT_LAGS * k));
        if b_target < MIN_JACKKNIFE_BLOCKS {
            return Err(numerical(format!(
                "{n_total} samples in {m} series allow only {b_target} jackknife segments of \
                 {MIN_SEGMENT_LAGS} x lag {k} samples on average (need {MIN_JACKKNIFE_BLOCKS})"
            )));
        }
        let seg_len = n_total as f64 / b_target as f64;
        for s in series {
            let n = s.len();
            let segs = ((n as f64 / seg_len).round() as usize).max(1);
            for i in 0..segs {
                blocks.push(Sums::of(s, i * n / segs, (i + 1) * n / segs, k, shift));
            }
        }
    }
    if blocks.len() < MIN_JACKKNIFE_BLOCKS {
        return Err(numerical(format!(
            "only {} jackknife blocks (need {MIN_JACKKNIFE_BLOCKS})",
            blocks.len()
        )));
    }
    Ok(blocks)
}

/// λ̂ from the pooled `blocks` at lag `k`, its delete-one-block jackknife standard error
/// and the t confidence interval at level `confidence`.
fn jackknife_estimate(
    blocks: &[Sums],
    k: usize,
    dt: f64,
    known: bool,
    confidence: f64,
) -> Result<RateEstimate> {
    let n_blocks = blocks.len();
    let kdt = k as f64 * dt;
    let rate_of = |s: &Sums| -> Result<f64> {
        let r = s.rho(known);
        if r.is_finite() && r > 0.0 {
            Ok(-r.ln() / kdt)
        } else {
            Err(numerical(format!(
                "lag-{k} autocorrelation estimate {r} is not positive"
            )))
        }
    };
    let total = blocks.iter().copied().fold(Sums::default(), Sums::add);
    let rate = rate_of(&total)?;
    // Each delete-one-block replicate: its rate and its second moment.
    let (reps, c0s): (Vec<f64>, Vec<f64>) = blocks
        .iter()
        .map(|b| {
            let rest = total.sub(*b);
            Ok((rate_of(&rest)?, rest.c0(known)))
        })
        .collect::<Result<Vec<(f64, f64)>>>()?
        .into_iter()
        .unzip();
    let bf = n_blocks as f64;
    let rep_mean = reps.iter().sum::<f64>() / bf;
    let c0_mean = c0s.iter().sum::<f64>() / bf;
    let var = (bf - 1.0) / bf * reps.iter().map(|r| (r - rep_mean).powi(2)).sum::<f64>();
    let std_error = var.sqrt();
    let var_c0: f64 = c0s.iter().map(|c| (c - c0_mean).powi(2)).sum();
    let cov: f64 = reps
        .iter()
        .zip(&c0s)
        .map(|(r, c)| (r - rep_mean) * (c - c0_mean))
        .sum();
    let variance_correlation = if var > 0.0 && var_c0 > 0.0 {
        (cov / (var * bf / (bf - 1.0) * var_c0).sqrt()).clamp(-1.0, 1.0)
    } else {
        f64::NAN
    };
    let t = StudentsT::new(0.0, 1.0, bf - 1.0)
        .map_err(|e| numerical(e.to_string()))?
        .inverse_cdf(0.5 + 0.5 * confidence);
    Ok(RateEstimate {
        rate,
        std_error,
        ci_low: rate - t * std_error,
        ci_high: rate + t * std_error,
        lag: k,
        n_blocks,
        variance_correlation,
        lag_from_data: false,
    })
}

#[cfg(test)]
mod tests {
    //! Unit checks: the estimator on a single seeded AR(1) series (rate within 4 SE of
    //! the truth, lag near 1/(λ dt)), the block layout for many series, and error paths.
    //! Coverage over many seeds is in `tests/stats_validation.rs`.
    use super::*;
    use crate::rng::trajectory_rng;
    use rand::RngExt;
    use rand_distr::StandardNormal;

    const SEED: u64 = 0xDECA1;

    fn ar1(rho: f64, n: usize, index: u64) -> Vec<f64> {
        let mut rng = trajectory_rng(SEED, index);
        let c = (1.0 - rho * rho).sqrt();
        let mut x: f64 = rng.sample(StandardNormal);
        (0..n)
            .map(|_| {
                let v = x;
                let e: f64 = rng.sample(StandardNormal);
                x = rho * x + c * e;
                v
            })
            .collect()
    }

    #[test]
    fn single_long_series() {
        let rho: f64 = 0.8;
        let dt = 0.5;
        let lambda = -rho.ln() / dt;
        let x = ar1(rho, 100_000, 0);
        let est = decay_rate(&[&x], dt, None, 0.95).unwrap();
        assert_eq!(est.lag, 4); // 1/(-ln 0.8) = 4.48
        assert!(est.n_blocks >= MIN_JACKKNIFE_BLOCKS && est.n_blocks <= TARGET_BLOCKS + 2);
        assert!(
            (est.rate - lambda).abs() < 4.0 * est.std_error,
            "{est:?} vs {lambda}"
        );
        assert!(est.std_error < 0.05 * lambda);
        assert!(est.ci_low < est.rate && est.rate < est.ci_high);
    }

    #[test]
    fn many_series_use_whole_series_blocks() {
        let xs: Vec<Vec<f64>> = (0..50).map(|i| ar1(0.5, 200, 10 + i)).collect();
        let refs: Vec<&[f64]> = xs.iter().map(|v| v.as_slice()).collect();
        let est = decay_rate(&refs, 1.0, Some(0.0), 0.9).unwrap();
        assert_eq!(est.n_blocks, TARGET_BLOCKS);
        assert_eq!(est.lag, 1);
    }

    /// A decay the sampling cannot resolve is refused before the data are looked at:
    /// at rate·Δt = 8 the expected ρ(1) = 3.4e-4 is below 5/√(10⁵ pairs) = 0.016, whatever
    /// the sample (here white noise, whose ρ̂(1) is positive about half the time). At
    /// rate·Δt = 2 (ρ(1) = 0.135, 43 standard errors) the rate is estimated and covers
    /// the truth.
    #[test]
    fn an_unresolved_decay_is_refused_from_the_plan() {
        for index in 0..4 {
            let white = ar1(0.0, 100_000, index);
            let e = decay_rate_with_lag(&[&white], 1.0, Some(0.0), 0.95, LagRule::Expected(8.0))
                .unwrap_err();
            assert!(e.to_string().contains("does not resolve the decay"), "{e}");
        }
        let rho = (-2.0f64).exp();
        let x = ar1(rho, 100_000, 9);
        let e = decay_rate_with_lag(&[&x], 1.0, Some(0.0), 0.95, LagRule::Expected(2.0)).unwrap();
        assert!(!e.lag_from_data && e.lag == 1);
        assert!(
            (e.rate - 2.0).abs() < 4.0 * e.std_error,
            "{} ± {}",
            e.rate,
            e.std_error
        );
    }

    #[test]
    fn expected_lag_comes_from_the_rate_and_the_plan() {
        let rho: f64 = 0.8;
        let x = ar1(rho, 100_000, 0);
        let lambda = -rho.ln();
        let e = decay_rate_with_lag(&[&x], 1.0, None, 0.95, LagRule::Expected(lambda)).unwrap();
        let p = decay_rate(&[&x], 1.0, None, 0.95).unwrap();
        assert!(!e.lag_from_data && p.lag_from_data);
        assert_eq!(
            e,
            RateEstimate {
                lag_from_data: false,
                ..p
            }
        );
        // 1/(λ dt) = 4.48 but 1 000 samples allow 10 segments of 20 lags only up to lag 5,
        // 400 samples only lag 2: the lag shrinks to fit whatever the data.
        let rule = LagRule::Expected(lambda);
        assert_eq!(
            decay_rate_with_lag(&[&x[..1000]], 1.0, None, 0.95, rule)
                .unwrap()
                .lag,
            4
        );
        assert_eq!(
            decay_rate_with_lag(&[&x[..400]], 1.0, None, 0.95, rule)
                .unwrap()
                .lag,
            2
        );
        let slow = LagRule::Expected(0.01 * lambda);
        assert_eq!(
            decay_rate_with_lag(&[&x[..400]], 1.0, None, 0.95, slow)
                .unwrap()
                .lag,
            2
        );
        // Too short for 10 segments even at lag 1; invalid expected rates.
        assert!(decay_rate_with_lag(&[&x[..199]], 1.0, None, 0.95, rule).is_err());
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let r = LagRule::Expected(bad);
            assert!(decay_rate_with_lag(&[&x], 1.0, None, 0.95, r).is_err());
        }
    }

    /// ρ̂ negative at the expected lag (a series that oscillates with period 16 where the
    /// reference expects lag 8): the lag comes from the pilot instead, and says so.
    #[test]
    fn expected_lag_falls_back_to_the_pilot_where_rho_is_not_positive() {
        let x: Vec<f64> = (0..4000)
            .map(|i| (std::f64::consts::PI * i as f64 / 8.0).sin())
            .collect();
        let rule = LagRule::Expected(1.0 / 8.0);
        let e = decay_rate_with_lag(&[&x], 1.0, Some(0.0), 0.95, rule).unwrap();
        let p = decay_rate(&[&x], 1.0, Some(0.0), 0.95).unwrap();
        assert!(e.lag_from_data, "{e:?}");
        assert_eq!(e, p);
        assert_eq!(e.lag, 13); // −1/ln cos(π/8) = 12.6
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = ar1(0.8, 1000, 1);
        assert!(decay_rate(&[], 1.0, None, 0.95).is_err());
        assert!(decay_rate(&[&x], 0.0, None, 0.95).is_err());
        assert!(decay_rate(&[&x], 1.0, None, 1.0).is_err());
        assert!(decay_rate(&[&x], 1.0, Some(f64::NAN), 0.95).is_err());
        assert!(decay_rate(&[&x[..1]], 1.0, None, 0.95).is_err());
        // Too short for 10 segments of 20 lags.
        assert!(decay_rate(&[&x[..100]], 1.0, None, 0.95).is_err());
        // Alternating series: negative lag-1 correlation.
        let alt: Vec<f64> = (0..1000)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        assert!(decay_rate(&[&alt], 1.0, None, 0.95).is_err());
    }
}
