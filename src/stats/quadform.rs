//! The null laws of sums of squares of stationary Gaussian series, and the test of a
//! variance built on them (issue #30: a variance test whose scale comes from the
//! reference, not from the data under test): exact for AR(1) series ([`Ar1SquareSum`], a
//! mode's amplitudes), and by the Whittle approximation for a sum of correlated AR(1)
//! modes ([`WeightedChiSquares`], the field at a point); both through the saddle point of
//! [`SquareSumLaw`].
//!
//! A series `x_1 … x_T` of a stationary Gaussian AR(1) process with variance `v` and lag-one
//! correlation `ρ` (`|ρ| < 1`) has covariance `v R`, `R_ij = ρ^|i−j|` (the
//! Kac–Murdock–Szegő matrix). Its sum of squares `S = Σ x_t²` is a weighted sum of χ²₁
//! variables, with cumulant generating function
//!
//! ```text
//! K(u) = ln E e^{uS} = −½ ln det(I − 2uv R),      u < 1/(2v λ_max(R)).
//! ```
//!
//! `R⁻¹ = M/(1 − ρ²)` with `M` tridiagonal (diagonal `1, 1 + ρ², …, 1 + ρ², 1`, off-diagonal
//! `−ρ`, `det M = 1 − ρ²`), so `det(I − cR) = det(M − c(1 − ρ²) I)/(1 − ρ²)`: the
//! determinant and its first two derivatives follow in O(T) from the three-term recurrence
//! of the leading minors, written in ratios `r_k = D_k/D_{k−1}` so that nothing overflows
//! (`r_k = d_k − ρ²/r_{k−1}`). The ratios converge geometrically to the fixed point of the
//! recurrence, after which the remaining interior terms are equal and are added at once.
//! Independent series add their cumulant generating functions.
//!
//! Tail probabilities come from the Lugannani–Rice saddle-point formula (Lugannani & Rice
//! 1980; Butler 2007, §1.2), whose relative error is O(1/N) uniformly in the tail for a sum of
//! N independent terms: `P(S ≥ s) ≈ 1 − Φ(w) + φ(w)(1/ũ − 1/w)` with `K′(û) = s`,
//! `w = sgn(û)·sqrt(2(ûs − K(û)))`, `ũ = û·sqrt(K″(û))`. Unlike a t-test, whose error comes
//! from the spread of the data under test, the test of [`ar1_square_sum_test`] takes the whole
//! null law from the reference (variance and lag correlation): a variance 9× too large gives
//! an astronomically small p-value instead of a t statistic bounded by the data.

use super::hypothesis::TestOutcome;
use crate::error::{Error, Result};
use statrs::distribution::{Continuous, ContinuousCDF, Normal};

/// Relative change of the recurrence's ratio (and its derivatives) below which it is
/// treated as converged to its fixed point.
const FIXED_POINT_TOLERANCE: f64 = 1e-15;
/// Below this |w| the saddle point is at the mean, where the Lugannani–Rice formula
/// cancels; the normal approximation `Φ(−w)` is used there (the two-sided p-value is then
/// within about 1e-4 of 1).
const CENTRE_W: f64 = 1e-4;

/// The law of a quadratic form `S` in zero-mean Gaussian variables — a sum of squares
/// (`S ≥ 0`), or an indefinite form such as a sum of products (with a
/// [`Self::lower_bound`]) — given by its cumulant generating function `K(u) = ln E e^{uS}`;
/// its tails come from the Lugannani–Rice saddle-point formula (module docs).
pub trait SquareSumLaw {
    /// `K(u)`, `K′(u)`, `K″(u)`, or `None` past the first singularity of `K`.
    fn cumulants(&self, u: f64) -> Option<Cumulants>;

    /// `E S = K′(0)`.
    fn mean(&self) -> f64;

    /// `Var S = K″(0)`.
    fn variance(&self) -> f64;

    /// A positive `u` of the order of the first singularity, from which the saddle-point
    /// search brackets its root.
    fn bracket_scale(&self) -> f64;

    /// The negative end of the domain of `K` for a form with negative weights (`S` then
    /// takes negative values); `None` for a sum of squares (`K` finite for every `u < 0`).
    fn lower_bound(&self) -> Option<f64> {
        None
    }

    /// The saddle point `û` with `K′(û) = s` (`s > 0` for a sum of squares, any `s` for an
    /// indefinite form), by safeguarded Newton iteration on a bracket ([`Self::cumulants`]
    /// is `None` past a singularity, `K′` increases).
    fn saddle_point(&self, s: f64) -> Option<(f64, Cumulants)> {
        let at = |u: f64| self.cumulants(u);
        let mean = self.mean();
        // A bracket [lo, hi] with K'(lo) <= s <= K'(hi) (hi may be outside the domain).
        let scale = self.bracket_scale();
        let (mut lo, mut hi);
        if s >= mean {
            lo = 0.0;
            hi = scale;
            // Within the domain and below s: move lo up until K' passes s or the domain
            // ends.
            while let Some(cu) = at(hi) {
                if cu.k1 >= s {
                    break;
                }
                lo = hi;
                hi *= 2.0;
            }
        } else if let Some(bound) = self.lower_bound() {
            // K' → −∞ at the lower end of the domain.
            hi = 0.0;
            lo = bound;
        } else {
            hi = 0.0;
            lo = -scale;
            while at(lo)?.k1 > s {
                hi = lo;
                lo *= 2.0;
                if !lo.is_finite() {
                    return None;
                }
            }
        }
        let mut u = 0.5 * (lo + hi);
        for _ in 0..200 {
            let Some(cu) = at(u) else {
                // Past an end of the domain.
                if u > 0.0 {
                    hi = u;
                } else {
                    lo = u;
                }
                u = 0.5 * (lo + hi);
                continue;
            };
            let f = cu.k1 - s;
            if f > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            if f.abs() <= 1e-14 * s.abs()
                || (hi - lo).abs() <= 1e-16 * u.abs().max(f64::MIN_POSITIVE)
            {
                return Some((u, cu));
            }
            let newton = u - f / cu.k2;
            u = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        at(u).map(|cu| (u, cu))
    }

    /// `P(S ≥ s)` by the Lugannani–Rice formula (module docs); `None` for a non-finite `s`.
    /// Where the saddle point cannot be resolved in f64 (`s` so far in a tail, e.g. a
    /// variance 10³⁰ times the reference's, that `K′` reaches it only within rounding of
    /// the domain's end), the tail's Chernoff bound instead ([`Self::chernoff_bound`]): an
    /// upper bound on the tail's probability, so that the p-value it gives is conservative.
    fn upper_tail(&self, s: f64) -> Option<f64> {
        if !s.is_finite() {
            return None;
        }
        if s <= 0.0 && self.lower_bound().is_none() {
            return Some(1.0);
        }
        let Some((u, cu)) = self.saddle_point(s) else {
            let upper = s > self.mean();
            return Some(bounded_tail(self.chernoff_bound(s, upper)?, upper));
        };
        let normal = Normal::standard();
        let w2 = 2.0 * (u * s - cu.k);
        let w = u.signum() * w2.max(0.0).sqrt();
        if w.abs() < CENTRE_W {
            return Some(normal.sf(w));
        }
        let ut = u * cu.k2.sqrt();
        let p = normal.sf(w) + normal.pdf(w) * (1.0 / ut - 1.0 / w);
        Some(p.clamp(0.0, 1.0))
    }

    /// The Chernoff bound on the tail beyond `s`: `P(S ≥ s) ≤ exp(K(u) − us)` for every
    /// `u > 0` of the domain (`upper`), `P(S ≤ s) ≤ exp(K(u) − us)` for every `u < 0`
    /// (Markov's inequality for `e^{uS}`), at the best `u` of a grid geometric towards
    /// both ends of the half-domain (`end·2^{−j}` and `end·(1 − 2^{−j})`, `j ≤ 60`, with
    /// the end found by bisection; `u = −2^k/(2λ)` where a sum of squares has none).
    /// `K(u) − us` is convex in `u` and least at the saddle point, so where the saddle
    /// point lies within rounding of the domain's end, so does the best bound. `None` if no
    /// `u` of the domain gives a finite bound.
    fn chernoff_bound(&self, s: f64, upper: bool) -> Option<f64> {
        let exponent = |u: f64| {
            self.cumulants(u)
                .map(|cu| cu.k - u * s)
                .filter(|g| g.is_finite())
        };
        let scale = self.bracket_scale();
        let end = if upper {
            // Double to a point past the domain's end, then bisect onto it.
            let (mut inside, mut outside) = (0.0, scale);
            while self.cumulants(outside).is_some() {
                inside = outside;
                outside *= 2.0;
                if !outside.is_finite() {
                    return None;
                }
            }
            for _ in 0..200 {
                let mid = 0.5 * (inside + outside);
                if mid == inside || mid == outside {
                    break;
                }
                if self.cumulants(mid).is_some() {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            Some(outside)
        } else {
            self.lower_bound()
        };
        let grid: Vec<f64> = match end {
            Some(end) => (1..=60)
                .flat_map(|j| {
                    let f = 0.5_f64.powi(j);
                    [end * f, end * (1.0 - f)]
                })
                .collect(),
            None => (-60..=1100).map(|k| -scale * 2.0_f64.powi(k)).collect(),
        };
        grid.into_iter()
            .filter_map(exponent)
            .min_by(f64::total_cmp)
            .map(|g| g.exp().min(1.0))
    }
}

/// `P(S ≥ s)` to report from a bound `bound` on the tail beyond `s` (the upper tail if
/// `upper`, else the lower), such that the two-sided p-value `2·min(P(S ≥ s), P(S ≤ s))`
/// comes out as `2·min(bound, ½)`: at or above the truth whatever the bound's slack
/// (unclamped, a loose bound above ½ would make the other tail look small).
fn bounded_tail(bound: f64, upper: bool) -> f64 {
    let b = bound.min(0.5);
    if upper { b } else { 1.0 - b }
}

/// The law of `S = Σ_series Σ_t x_t²` for independent stationary Gaussian AR(1) series
/// with a common variance and lag-one correlation (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Ar1SquareSum {
    /// Stationary variance `v` of each sample.
    variance: f64,
    /// Lag-one correlation `ρ` between successive samples.
    rho: f64,
    /// `(T, count)`: `count` series of length `T`.
    lengths: Vec<(usize, usize)>,
}

/// `K(u)`, `K′(u)`, `K″(u)` at one argument; `None` outside the domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cumulants {
    /// `K(u)`.
    pub k: f64,
    /// `K′(u)`.
    pub k1: f64,
    /// `K″(u)`.
    pub k2: f64,
}

impl Ar1SquareSum {
    /// The law for series of the given lengths (series of length 0 are ignored).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a variance that is not finite and positive, `|ρ| ≥ 1`
    /// or not finite, or no samples at all.
    pub fn new(variance: f64, rho: f64, lengths: &[usize]) -> Result<Self> {
        crate::error::require_positive("variance", variance)?;
        if !(rho.is_finite() && rho.abs() < 1.0) {
            return Err(Error::invalid("rho", rho, "finite, in (-1, 1)"));
        }
        Ok(Ar1SquareSum {
            variance,
            rho,
            lengths: grouped_lengths(lengths)?,
        })
    }

    /// Number of samples in all series.
    pub fn samples(&self) -> usize {
        self.lengths.iter().map(|(t, c)| t * c).sum()
    }

    /// `E S = N v`.
    pub fn mean(&self) -> f64 {
        self.samples() as f64 * self.variance
    }

    /// `Var S = 2v² Σ tr(R²)`, `tr(R²) = Σ_{i,j} ρ^{2|i−j|} = T(1 + r)/(1 − r) −
    /// 2r(1 − r^T)/(1 − r)²`, `r = ρ²`.
    pub fn variance(&self) -> f64 {
        let r = self.rho * self.rho;
        let tr: f64 = self
            .lengths
            .iter()
            .map(|&(t, c)| {
                let t = t as f64;
                c as f64
                    * (t * (1.0 + r) / (1.0 - r) - 2.0 * r * (1.0 - r.powf(t)) / (1.0 - r).powi(2))
            })
            .sum();
        2.0 * self.variance * self.variance * tr
    }

    /// `K(u)` and its first two derivatives (module docs), or `None` where `I − 2uvR` is not
    /// positive definite (`u` beyond the first singularity).
    pub fn cumulants(&self, u: f64) -> Option<Cumulants> {
        let r2 = self.rho * self.rho;
        let q = 1.0 - r2;
        // c' = 2uv(1 − ρ²): det(I − 2uvR) = det(M − c'I)/(1 − ρ²).
        let dc = 2.0 * self.variance * q;
        let c = u * dc;
        let mut out = Cumulants {
            k: 0.0,
            k1: 0.0,
            k2: 0.0,
        };
        for &(t, count) in &self.lengths {
            let (l, l1, l2) = tridiagonal_log_det(t, r2, c)?;
            let n = count as f64;
            out.k += n * -0.5 * (l - q.ln());
            out.k1 += n * -0.5 * l1 * dc;
            out.k2 += n * -0.5 * l2 * dc * dc;
        }
        Some(out)
    }
}

impl SquareSumLaw for Ar1SquareSum {
    fn cumulants(&self, u: f64) -> Option<Cumulants> {
        Ar1SquareSum::cumulants(self, u)
    }

    fn mean(&self) -> f64 {
        Ar1SquareSum::mean(self)
    }

    fn variance(&self) -> f64 {
        Ar1SquareSum::variance(self)
    }

    fn bracket_scale(&self) -> f64 {
        1.0 / (2.0 * self.variance)
    }
}

/// The series lengths as `(T, count)`, ascending in `T`, lengths 0 ignored: independent
/// series of one length share their cumulant terms.
///
/// # Errors
/// [`Error::InvalidParameter`] if no series has a sample.
fn grouped_lengths(lengths: &[usize]) -> Result<Vec<(usize, usize)>> {
    let mut grouped: Vec<(usize, usize)> = Vec::new();
    for &t in lengths.iter().filter(|&&t| t > 0) {
        match grouped.iter_mut().find(|(len, _)| *len == t) {
            Some((_, count)) => *count += 1,
            None => grouped.push((t, 1)),
        }
    }
    if grouped.is_empty() {
        return Err(Error::invalid("series", 0, "at least one sample"));
    }
    grouped.sort_unstable();
    Ok(grouped)
}

/// `ln det(M − cI)` and its first two derivatives in `c`, for the `t × t` tridiagonal `M`
/// of the module docs (`r2 = ρ²`), or `None` unless `M − cI` is positive definite.
fn tridiagonal_log_det(t: usize, r2: f64, c: f64) -> Option<(f64, f64, f64)> {
    // Diagonal entry k (0-based) of M − cI.
    let d = |k: usize| {
        if k == 0 || k + 1 == t {
            1.0 - c
        } else {
            1.0 + r2 - c
        }
    };
    if t == 1 {
        // M = [1 − ρ²]: the 1 × 1 KMS inverse is 1, i.e. M = 1 − ρ² (det M = 1 − ρ²).
        let a = 1.0 - r2 - c;
        return (a > 0.0).then(|| (a.ln(), -1.0 / a, -1.0 / (a * a)));
    }
    // r_k, r'_k, r''_k (derivatives in c) of the ratios of leading minors.
    let (mut r, mut r1, mut r2d) = (d(0), -1.0, 0.0);
    if r <= 0.0 {
        return None;
    }
    let (mut l, mut l1, mut l2) = (r.ln(), r1 / r, r2d / r - (r1 / r).powi(2));
    let mut k = 1;
    while k < t {
        let (rp, rp1, rp2) = (r, r1, r2d);
        r = d(k) - r2 / rp;
        r1 = -1.0 + r2 * rp1 / (rp * rp);
        r2d = r2 * (rp2 / (rp * rp) - 2.0 * rp1 * rp1 / (rp * rp * rp));
        if r <= 0.0 || !r.is_finite() {
            return None;
        }
        let (term, term1, term2) = (r.ln(), r1 / r, r2d / r - (r1 / r).powi(2));
        l += term;
        l1 += term1;
        l2 += term2;
        k += 1;
        // At the fixed point every further interior entry adds the same terms: add them at
        // once and go on with the last entry.
        let converged =
            |a: f64, b: f64| (a - b).abs() <= FIXED_POINT_TOLERANCE * a.abs().max(1e-300);
        if k + 1 < t && converged(r, rp) && converged(r1, rp1) && converged(r2d, rp2) {
            let rest = (t - 1 - k) as f64;
            l += rest * term;
            l1 += rest * term1;
            l2 += rest * term2;
            k = t - 1;
        }
    }
    Some((l, l1, l2))
}

/// The two-sided test that independent stationary Gaussian AR(1) series (lag-one
/// correlation `rho` between successive samples) have variance `variance` about mean zero:
/// `S = Σ x²` against its exact null law ([`Ar1SquareSum`]) by [`square_sum_test`].
///
/// # Errors
/// [`Error::InvalidParameter`] for invalid parameters, no samples, a non-finite sample; a
/// [`Error::Numerical`] if the saddle point is not found.
pub fn ar1_square_sum_test(
    series: &[&[f64]],
    variance: f64,
    rho: f64,
) -> Result<(TestOutcome, f64, f64)> {
    require_finite_series(series)?;
    let lengths: Vec<usize> = series.iter().map(|s| s.len()).collect();
    square_sum_test(series, &Ar1SquareSum::new(variance, rho, &lengths)?)
}

/// Refuses a non-finite sample, naming its series and index.
fn require_finite_series(series: &[&[f64]]) -> Result<()> {
    for (i, s) in series.iter().enumerate() {
        if let Some(j) = s.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(format!("series[{i}][{j}]"), s[j], "finite"));
        }
    }
    Ok(())
}

/// The two-sided test of `S = Σ x²` over every sample of `series` (finite) against the null
/// law `law` (built for these series' lengths): `p = 2 min(P(S ≥ s), P(S ≤ s))`. Returns
/// the outcome (statistic: the normal score of `s` under the null's mean and variance, no
/// degrees of freedom), the estimate `S/N`, and the null standard deviation of `S/N` (from
/// the reference, not the data).
///
/// # Errors
/// [`Error::Numerical`] if the saddle point is not found.
pub fn square_sum_test(
    series: &[&[f64]],
    law: &impl SquareSumLaw,
) -> Result<(TestOutcome, f64, f64)> {
    let s: f64 = series.iter().flat_map(|x| x.iter()).map(|x| x * x).sum();
    let n = series.iter().map(|x| x.len()).sum::<usize>();
    sum_test(s, n, law)
}

/// The two-sided test of a sum `s` of `n` terms against its null law `law`:
/// `p = 2 min(P(S ≥ s), P(S ≤ s))`. Returns the outcome (statistic: the normal score of
/// `s` under the null's mean and variance, no degrees of freedom), the estimate `s/n`, and
/// the null standard deviation of `S/n` (from the reference, not the data).
///
/// # Errors
/// [`Error::Numerical`] if the saddle point is not found (e.g. a non-finite `s`).
pub fn sum_test(s: f64, n: usize, law: &impl SquareSumLaw) -> Result<(TestOutcome, f64, f64)> {
    let n = n as f64;
    let sd = law.variance().sqrt();
    let upper = law.upper_tail(s).ok_or_else(|| Error::Numerical {
        routine: "square_sum_test".into(),
        detail: format!("no saddle point for the sum of squares {s:e}"),
    })?;
    let p_value = (2.0 * upper.min(1.0 - upper)).clamp(0.0, 1.0);
    Ok((
        TestOutcome {
            statistic: (s - law.mean()) / sd,
            p_value,
            dof: None,
        },
        s / n,
        sd / n,
    ))
}

/// A weighted sum of independent χ² variables, `S = Σ_j λ_j χ²_{m_j}` (weights of either
/// sign): the law of any Gaussian quadratic form, with cumulant generating function
/// `K(u) = −½ Σ_j m_j ln(1 − 2uλ_j)` on `1/(2λ_min) < u < 1/(2λ_max)`. Built for the
/// sum of squares of a field at a point ([`Self::whittle`]) and for the sum of products of
/// two correlated normals ([`Self::product_sum`]).
#[derive(Debug, Clone, PartialEq)]
pub struct WeightedChiSquares {
    /// `(λ_j, m_j)`.
    weights: Vec<(f64, f64)>,
    /// The largest weight (positive).
    largest: f64,
    /// The smallest weight.
    smallest: f64,
}

impl WeightedChiSquares {
    /// The law of `Σ_j λ_j χ²_{m_j}` for `weights` = `(λ_j, m_j)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a weight that is not finite, a degree of freedom that
    /// is not finite and positive, or no positive weight.
    pub fn new(weights: Vec<(f64, f64)>) -> Result<Self> {
        for (j, &(l, m)) in weights.iter().enumerate() {
            if !l.is_finite() {
                return Err(Error::invalid(format!("weights[{j}]"), l, "finite"));
            }
            crate::error::require_positive(&format!("weights[{j}].dof"), m)?;
        }
        let largest = weights.iter().map(|w| w.0).fold(0.0, f64::max);
        let smallest = weights.iter().map(|w| w.0).fold(0.0, f64::min);
        if largest <= 0.0 {
            return Err(Error::invalid(
                "weights",
                largest,
                "at least one positive weight",
            ));
        }
        Ok(WeightedChiSquares {
            weights,
            largest,
            smallest,
        })
    }

    /// The law of `S = Σ_series Σ_t x_t²` for independent stationary Gaussian series of the
    /// given lengths (length 0 ignored) whose autocovariance is a sum of geometric terms,
    /// `γ(ℓ) = Σ_k u_k ρ_k^{|ℓ|}`, `terms` = `(u_k, ρ_k)` (a field at a point of a linear
    /// system: a sum of modes, each decaying by its multiplier; a `u_k` may be negative
    /// where the modes are driven by correlated noise, `γ` is still an autocovariance).
    ///
    /// `S` over one series of length `T` is a weighted sum of χ²₁ variables whose weights
    /// are the eigenvalues of the `T × T` Toeplitz covariance `Γ_T`. They are taken as the
    /// spectral density at the Fourier frequencies, `λ_j = f(2πj/T)`,
    /// `f(ω) = Σ_k u_k (1 − ρ_k²)/(1 − 2ρ_k cos ω + ρ_k²)` (the circulant, or Whittle,
    /// approximation; Grenander & Szegő 1958, Gray 2006): `Σ_j λ_j = T γ(0)` up to the
    /// wrapped terms `2T Σ_q γ(qT)`, and `Σ_j λ_j² = T Σ_ℓ γ(ℓ)²` exceeds the exact
    /// `tr Γ_T²` by `2 Σ_ℓ |ℓ| γ(ℓ)²`, a relative `O(τ/T)` for a correlation time of `τ`
    /// samples, on the side of a wider null (a conservative test). For a single AR(1) term
    /// [`Ar1SquareSum`] is exact; the unit tests measure the difference.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a weight or correlation that is not finite,
    /// `|ρ_k| ≥ 1`, a variance `γ(0) = Σ u_k` that is not positive, or no samples at all.
    pub fn whittle(terms: &[(f64, f64)], lengths: &[usize]) -> Result<Self> {
        for (k, &(u, rho)) in terms.iter().enumerate() {
            if !u.is_finite() {
                return Err(Error::invalid(format!("terms[{k}].weight"), u, "finite"));
            }
            if !(rho.is_finite() && rho.abs() < 1.0) {
                return Err(Error::invalid(
                    format!("terms[{k}].rho"),
                    rho,
                    "finite, in (-1, 1)",
                ));
            }
        }
        crate::error::require_positive("variance", terms.iter().map(|t| t.0).sum())?;
        let counts = grouped_lengths(lengths)?;
        let density = |omega: f64| -> f64 {
            let c = omega.cos();
            terms
                .iter()
                .map(|&(u, r)| u * (1.0 - r * r) / (1.0 - 2.0 * r * c + r * r))
                .sum::<f64>()
                .max(0.0)
        };
        let mut weights = Vec::new();
        for &(t, count) in &counts {
            // f(ω_j) = f(ω_{T−j}): each frequency below the Nyquist one twice.
            for j in 0..=t / 2 {
                let twice = j != 0 && 2 * j != t;
                let omega = 2.0 * std::f64::consts::PI * j as f64 / t as f64;
                let m = count as f64 * if twice { 2.0 } else { 1.0 };
                weights.push((density(omega), m));
            }
        }
        Self::new(weights)
    }

    /// The law of `S = Σ_{i ≤ n} X_i Y_i` for `n` independent pairs of zero-mean normals
    /// with variances `var_x`, `var_y` and covariance `cov`: `E e^{uXY} =
    /// ((1 − uc)² − u² v_x v_y)^{−1/2}`, so `S = λ₊χ²_n + λ₋χ²_n` with
    /// `λ± = (c ± √(v_x v_y))/2` (mean `nc`, variance `n(c² + v_x v_y)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for variances that are not finite and positive, a
    /// covariance that is not finite or beyond `±√(v_x v_y)`, or `n = 0`.
    pub fn product_sum(var_x: f64, var_y: f64, cov: f64, n: usize) -> Result<Self> {
        crate::error::require_positive("var_x", var_x)?;
        crate::error::require_positive("var_y", var_y)?;
        let r = (var_x * var_y).sqrt();
        if !(cov.is_finite() && cov.abs() < r) {
            return Err(Error::invalid(
                "cov",
                cov,
                format!("finite, |cov| < sqrt(var_x var_y) = {r:e}"),
            ));
        }
        if n == 0 {
            return Err(Error::invalid("pairs", 0, "at least one"));
        }
        let m = n as f64;
        Self::new(vec![(0.5 * (cov + r), m), (0.5 * (cov - r), m)])
    }
}

impl SquareSumLaw for WeightedChiSquares {
    /// `K(u) = −½ Σ_j m_j ln(1 − 2uλ_j)` and its derivatives `Σ m_j λ_j/(1 − 2uλ_j)`,
    /// `Σ 2 m_j λ_j²/(1 − 2uλ_j)²`.
    fn cumulants(&self, u: f64) -> Option<Cumulants> {
        let mut out = Cumulants {
            k: 0.0,
            k1: 0.0,
            k2: 0.0,
        };
        for &(l, m) in &self.weights {
            let x = 1.0 - 2.0 * u * l;
            if x <= 0.0 {
                return None;
            }
            out.k += -0.5 * m * x.ln();
            out.k1 += m * l / x;
            out.k2 += 2.0 * m * (l / x).powi(2);
        }
        Some(out)
    }

    fn mean(&self) -> f64 {
        self.weights.iter().map(|(l, m)| m * l).sum()
    }

    fn variance(&self) -> f64 {
        2.0 * self.weights.iter().map(|(l, m)| m * l * l).sum::<f64>()
    }

    fn bracket_scale(&self) -> f64 {
        1.0 / (2.0 * self.largest)
    }

    fn lower_bound(&self) -> Option<f64> {
        (self.smallest < 0.0).then(|| 1.0 / (2.0 * self.smallest))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use statrs::distribution::ChiSquared;

    /// `K, K', K''` from the eigenvalues of `vR` (dense), for a few series: the AR(1)
    /// autocovariance `v ρ^|ℓ|` is the one-term [`dense_toeplitz`].
    fn dense(v: f64, rho: f64, lengths: &[usize], u: f64) -> (f64, f64, f64) {
        lengths
            .iter()
            .map(|&t| dense_toeplitz(&[(v, rho)], t, u))
            .fold((0.0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2))
    }

    #[test]
    fn cumulants_match_the_dense_eigenvalues() {
        for &(rho, ref lengths) in &[
            (0.6, vec![7, 7, 3]),
            (-0.85, vec![12]),
            (0.0, vec![5, 1]),
            (0.97, vec![40, 2]),
        ] {
            let law = Ar1SquareSum::new(1.7, rho, lengths).unwrap();
            // Up to 90 % of the way to the first singularity 1/(2v λ_max).
            let t = *lengths.iter().max().unwrap();
            let r = DMatrix::from_fn(t, t, |i, j| rho.powi((i as i32 - j as i32).abs()));
            let u_max = 1.0 / (2.0 * 1.7 * r.symmetric_eigenvalues().max());
            for &u in &[-3.0, -0.2, 0.0, 0.3 * u_max, 0.9 * u_max] {
                let cu = law.cumulants(u).unwrap();
                let (k, k1, k2) = dense(1.7, rho, lengths, u);
                for (a, b) in [(cu.k, k), (cu.k1, k1), (cu.k2, k2)] {
                    assert!(
                        (a - b).abs() <= 1e-10 * b.abs().max(1.0),
                        "{rho} {u}: {a} vs {b}"
                    );
                }
            }
            // Mean and variance are K'(0) and K''(0).
            let c0 = law.cumulants(0.0).unwrap();
            assert!((c0.k1 - law.mean()).abs() <= 1e-12 * law.mean());
            assert!((c0.k2 - law.variance()).abs() <= 1e-10 * law.variance());
        }
    }

    #[test]
    fn the_fixed_point_shortcut_is_exact() {
        // Long series (the shortcut taken) against the same sum without it: a series of
        // length T is the long recurrence; compare with the dense result at moderate T.
        let law = Ar1SquareSum::new(0.3, -0.5, &[300]).unwrap();
        let (k, k1, k2) = dense(0.3, -0.5, &[300], 0.4);
        let cu = law.cumulants(0.4).unwrap();
        assert!((cu.k - k).abs() <= 1e-10 * k.abs());
        assert!((cu.k1 - k1).abs() <= 1e-10 * k1.abs());
        assert!((cu.k2 - k2).abs() <= 1e-10 * k2.abs());
    }

    /// The Chernoff bound is a bound: at or above the exact χ²₁₀ tails, both sides.
    #[test]
    fn the_chernoff_bound_bounds_exact_chi_square_tails() {
        let law = WeightedChiSquares::new(vec![(1.0, 10.0)]).unwrap();
        let chi = ChiSquared::new(10.0).unwrap();
        for s in [12.0, 20.0, 40.0, 80.0] {
            let b = law.chernoff_bound(s, true).unwrap();
            assert!(chi.sf(s) <= b && b < 1.0, "{s}: {b} vs {}", chi.sf(s));
        }
        for s in [0.5, 2.0, 8.0] {
            let b = law.chernoff_bound(s, false).unwrap();
            assert!(chi.cdf(s) <= b && b < 1.0, "{s}: {b} vs {}", chi.cdf(s));
        }
        // Far in the tail, where the best u = (1 − k/s)/2 nears the domain's end 1/2, the
        // grid finds the optimal bound e^{−(s−k)/2} (s/k)^{k/2} within a factor e.
        let s = 1000.0;
        let optimal = -(s - 10.0) / 2.0 + 5.0 * (s / 10.0_f64).ln();
        let got = law.chernoff_bound(s, true).unwrap().ln();
        assert!(optimal <= got && got <= optimal + 1.0, "{got} vs {optimal}");
    }

    /// A bound's p-value is never below the truth: a loose bound gives p = 1 on either
    /// side, a tight one twice itself.
    #[test]
    fn bounded_tails_give_conservative_p_values() {
        let p = |upper_tail: f64| 2.0 * upper_tail.min(1.0 - upper_tail);
        for upper in [true, false] {
            assert_eq!(p(bounded_tail(0.9, upper)), 1.0);
            assert_eq!(p(bounded_tail(1.0, upper)), 1.0);
            assert!((p(bounded_tail(1e-3, upper)) - 2e-3).abs() < 1e-15);
            assert_eq!(p(bounded_tail(0.0, upper)), 0.0);
        }
    }

    /// A variance 10³⁰ times too small or too large: the saddle point is not resolvable in
    /// f64 and the test says p = 0 from the Chernoff bound, instead of failing.
    #[test]
    fn unresolvable_tails_give_a_zero_p_value() {
        let x: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1000) as f64 / 500.0 - 1.0)
            .collect();
        let s: f64 = x.iter().map(|v| v * v).sum();
        for variance in [1e-30, 1e30] {
            let law = Ar1SquareSum::new(variance, 0.5, &[x.len()]).unwrap();
            if variance < 1.0 {
                assert!(law.saddle_point(s).is_none(), "the fallback is exercised");
            }
            let (out, _, _) = square_sum_test(&[&x], &law).unwrap();
            assert_eq!(out.p_value, 0.0, "{variance}");
        }
        // Where the saddle point is found, nothing changes: the truth is accepted.
        let law = Ar1SquareSum::new(s / x.len() as f64, 0.0, &[x.len()]).unwrap();
        assert!(square_sum_test(&[&x], &law).unwrap().0.p_value > 0.9);
    }

    #[test]
    fn the_domain_ends_at_the_first_singularity() {
        // 1/(2 v λ_max): beyond it no cumulants.
        let (v, rho, t) = (1.0_f64, 0.5_f64, 20);
        let r = DMatrix::from_fn(t, t, |i, j| rho.powi((i as i32 - j as i32).abs()));
        let lmax = r.symmetric_eigenvalues().max();
        let law = Ar1SquareSum::new(v, rho, &[t]).unwrap();
        assert!(law.cumulants(0.999 / (2.0 * v * lmax)).is_some());
        assert!(law.cumulants(1.001 / (2.0 * v * lmax)).is_none());
    }

    #[test]
    fn white_noise_tails_are_chi_squared() {
        // ρ = 0: S/v is exactly χ²(N); Lugannani–Rice is within 2 % in both tails from
        // N = 10 (its error is O(1/N)), within 0.1 % from N = 200.
        for &n in &[10usize, 200, 5000] {
            let law = Ar1SquareSum::new(2.0, 0.0, &[n]).unwrap();
            let chi = ChiSquared::new(n as f64).unwrap();
            for &p in &[1e-12, 1e-6, 1e-3, 0.05, 0.3, 0.7, 0.95, 0.999, 1.0 - 1e-6] {
                let q = chi.inverse_cdf(p);
                let exact = chi.sf(q);
                let approx = law.upper_tail(2.0 * q).unwrap();
                let (e, a) = if exact < 0.5 {
                    (exact, approx)
                } else {
                    (1.0 - exact, 1.0 - approx)
                };
                let tol = if n < 100 { 0.02 } else { 1e-3 };
                assert!((a / e - 1.0).abs() < tol, "n {n}, p {p}: {a:e} vs {e:e}");
            }
        }
    }

    /// The exact `Σ_j ln(1 − 2uλ_j)`-type cumulants from the dense Toeplitz covariance of
    /// `γ(ℓ) = Σ u_k ρ_k^|ℓ|`.
    fn dense_toeplitz(terms: &[(f64, f64)], t: usize, u: f64) -> (f64, f64, f64) {
        let g = |l: usize| -> f64 { terms.iter().map(|(w, r)| w * r.powi(l as i32)).sum() };
        let cov = DMatrix::from_fn(t, t, |i, j| g(i.abs_diff(j)));
        let mut out = (0.0, 0.0, 0.0);
        for lam in cov.symmetric_eigenvalues().iter() {
            let x = 1.0 - 2.0 * u * lam;
            out.0 += -0.5 * x.ln();
            out.1 += lam / x;
            out.2 += 2.0 * lam * lam / (x * x);
        }
        out
    }

    #[test]
    fn whittle_cumulants_approach_the_exact_toeplitz_ones() {
        // A slow and a fast mode with a negative cross weight (correlated driving), as at
        // a point of a finite-element run; T = 400 samples, correlation time of the slow
        // mode τ = (1 + ρ)/(1 − ρ) ≈ 16 samples.
        let terms = [(0.8, 0.88), (0.3, 0.2), (-0.05, 0.5)];
        let t = 400;
        let law = WeightedChiSquares::whittle(&terms, &[t, t]).unwrap();
        let (k0, k1, k2) = dense_toeplitz(&terms, t, 0.0);
        let c0 = law.cumulants(0.0).unwrap();
        assert_eq!(c0.k, 0.0);
        assert!(k0.abs() < 1e-12);
        // The mean is exact up to the wrapped terms (ρ^T ≈ 1e-22).
        assert!(
            (c0.k1 - 2.0 * k1).abs() <= 1e-10 * k1,
            "{} vs {}",
            c0.k1,
            2.0 * k1
        );
        // The variance is wider by 2Σ|ℓ|γ(ℓ)²/tr Γ² = O(τ/T): here 2.1 %.
        let excess = c0.k2 / (2.0 * k2) - 1.0;
        assert!((0.0..0.03).contains(&excess), "variance excess {excess}");
        // Away from 0 the cumulant generating function keeps that relative accuracy.
        let lam_max = {
            let g = |l: usize| -> f64 { terms.iter().map(|(w, r)| w * r.powi(l as i32)).sum() };
            DMatrix::from_fn(t, t, |i, j| g(i.abs_diff(j)))
                .symmetric_eigenvalues()
                .max()
        };
        for &u in &[-2.0, 0.5 / (2.0 * lam_max)] {
            let cu = law.cumulants(u).unwrap();
            let (k, k1, _) = dense_toeplitz(&terms, t, u);
            assert!(
                (cu.k / (2.0 * k) - 1.0).abs() < 0.03,
                "K({u}): {} vs {}",
                cu.k,
                2.0 * k
            );
            assert!((cu.k1 / (2.0 * k1) - 1.0).abs() < 0.03, "K'({u})");
        }
    }

    #[test]
    fn whittle_tails_of_one_ar1_term_are_close_to_the_exact_ones() {
        // One AR(1) term: the Whittle law against the exact one (tridiagonal recurrence),
        // 8 series of 320 samples at the profile's lag correlation e^{-1/8} (a quick
        // budget's 40 τ₁): the Whittle tails are the larger in both tails (a conservative
        // test), by at most 10 % relative within 3 null standard deviations of the mean
        // (measured: 1 % at 1σ, 4–5 % at 2.5σ, 8 % at −3σ) and 20 % to 5.5σ (15 % at 2e-6).
        let rho = (-0.125f64).exp();
        let lengths = [320; 8];
        let exact = Ar1SquareSum::new(1.0, rho, &lengths).unwrap();
        let whittle = WeightedChiSquares::whittle(&[(1.0, rho)], &lengths).unwrap();
        let (mean, sd) = (exact.mean(), exact.variance().sqrt());
        assert!((whittle.mean() / mean - 1.0).abs() < 1e-12);
        for z in [-4.0, -3.0, -2.5, -1.0, 0.5, 1.0, 2.5, 3.0, 4.0, 5.5] {
            let s = mean + z * sd;
            let (a, b) = (exact.upper_tail(s).unwrap(), whittle.upper_tail(s).unwrap());
            let (a, b) = if z > 0.0 { (a, b) } else { (1.0 - a, 1.0 - b) };
            let tol = if z.abs() <= 3.0 { 0.1 } else { 0.2 };
            assert!(
                b >= a && b / a - 1.0 < tol,
                "z {z}: exact {a:e}, Whittle {b:e}"
            );
        }
    }

    #[test]
    fn product_sums_have_the_closed_form_cumulants_and_both_tails() {
        // K(u) = −(n/2) ln((1 − uc)² − u² v_x v_y) for n products XY; its derivatives by
        // central differences; mean nc, variance n(c² + v_x v_y).
        let (vx, vy, c, n) = (2.0, 0.5, -0.3, 24);
        let law = WeightedChiSquares::product_sum(vx, vy, c, n).unwrap();
        let k = |u: f64| -0.5 * n as f64 * ((1.0 - u * c).powi(2) - u * u * vx * vy).ln();
        let r = (vx * vy).sqrt();
        let (lo, hi) = (1.0 / (c - r), 1.0 / (c + r));
        assert_eq!(law.lower_bound(), Some(lo));
        for u in [0.9 * lo, 0.3 * lo, 0.0, 0.4 * hi, 0.95 * hi] {
            let cu = law.cumulants(u).unwrap();
            let h = 1e-5 * (hi - lo);
            let d1 = (k(u + h) - k(u - h)) / (2.0 * h);
            let d2 = (k(u + h) - 2.0 * k(u) + k(u - h)) / (h * h);
            assert!((cu.k - k(u)).abs() <= 1e-12 * k(u).abs().max(1.0), "K({u})");
            assert!((cu.k1 - d1).abs() <= 1e-6 * d1.abs().max(1.0), "K'({u})");
            assert!((cu.k2 - d2).abs() <= 1e-4 * d2.abs().max(1.0), "K''({u})");
        }
        assert!(law.cumulants(1.01 * lo).is_none() && law.cumulants(1.01 * hi).is_none());
        assert!((law.mean() - n as f64 * c).abs() < 1e-12);
        assert!((law.variance() - n as f64 * (c * c + vx * vy)).abs() < 1e-12);
        // The tails on both sides of the mean, negative sums included, are monotone
        // probabilities.
        let sd = law.variance().sqrt();
        let mut last = 1.0;
        for z in [-6.0, -3.0, -1.0, -0.1, 0.1, 1.0, 3.0, 6.0] {
            let p = law.upper_tail(law.mean() + z * sd).unwrap();
            assert!(p < last && p > 0.0, "z {z}: {p}");
            last = p;
        }
    }

    #[test]
    fn invalid_parameters_are_refused() {
        assert!(WeightedChiSquares::product_sum(1.0, 1.0, 1.0, 3).is_err());
        assert!(WeightedChiSquares::product_sum(0.0, 1.0, 0.0, 3).is_err());
        assert!(WeightedChiSquares::product_sum(1.0, 1.0, 0.5, 0).is_err());
        assert!(WeightedChiSquares::new(vec![(-1.0, 2.0)]).is_err());
        assert!(WeightedChiSquares::new(vec![(1.0, 0.0)]).is_err());
        assert!(WeightedChiSquares::whittle(&[(1.0, 1.0)], &[3]).is_err());
        assert!(WeightedChiSquares::whittle(&[(f64::NAN, 0.1)], &[3]).is_err());
        assert!(WeightedChiSquares::whittle(&[(-1.0, 0.1)], &[3]).is_err());
        assert!(WeightedChiSquares::whittle(&[(1.0, 0.1)], &[0]).is_err());
        assert!(Ar1SquareSum::new(0.0, 0.1, &[3]).is_err());
        assert!(Ar1SquareSum::new(1.0, 1.0, &[3]).is_err());
        assert!(Ar1SquareSum::new(1.0, f64::NAN, &[3]).is_err());
        assert!(Ar1SquareSum::new(1.0, 0.1, &[0]).is_err());
        assert!(ar1_square_sum_test(&[&[1.0, f64::NAN]], 1.0, 0.0).is_err());
    }
}
