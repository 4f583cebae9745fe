//! Material parameters from data (issue #31, `langevin-fem fit`): the bending rigidity
//! from the mode variances and the drag from the decay rates, each with a confidence
//! interval from the checks' autocorrelation-aware errors — the analysis of Gittes et al.
//! (1993) for microtubules and actin, on the exact references `check` builds.
//!
//! **Model.** A filament's mode n has the variance kT/kₙ and the rate kₙ/ξ with
//! kₙ ∝ EI (eq. 3), so the per-mode ratios estimate/reference of a run whose sidecar
//! states EI₀, ξ₀, kT₀ satisfy r_var,n = (kT/kT₀)(EI₀/EI) and r_rate,n = (EI/EI₀)(ξ₀/ξ).
//! The fit pools ln r over the modes with inverse-variance weights (the standard error of
//! ln r is s.e.(r)/r, a `quadratic-form` check's null error scaled by its ratio, as the
//! diagnosis does) and reports, with kT known,
//!
//! ```text
//! EI = EI₀ · exp(−m_var),   ξ = ξ₀ · exp(−m_var − m_rate),
//! ```
//!
//! and, with EI known instead, kT = kT₀ · exp(m_var); 95 % intervals exp(±1.96 s.e.) on
//! the log scale. For ξ the two pooled ratios come from the same series and are
//! correlated (a long excursion raises a mode's variance and slows its measured decay):
//! var(m_var + m_rate) = s_var² + s_rate² + 2 Σₙ aₙbₙρₙ s_var,n s_rate,n, with aₙ, bₙ the
//! normalized weights of mode n in the two pools, s_·,n its log errors and ρₙ its
//! `decay-rate` check's jackknife correlation with the variance
//! ([`crate::stats::RateEstimate::variance_correlation`]; 0 where a mode has none, e.g.
//! in a summary written before it was recorded). A rate's error is itself an estimate,
//! with ν = B − 1 degrees of freedom (its jackknife's): inverse-variance weights 1/ŝ²
//! are biased high by E[ν/χ²_ν] = ν/(ν − 2), so the pooled error would come out too
//! small; each rate's error is scaled by √(ν/(ν − 2)) before pooling. The modes' scatter about the
//! pooled value is tested (χ² of ln r about m, its p-value): a small p says one factor
//! does not explain every mode (a mesh or a time step the references do not model).
//!
//! **A membrane** (issue #27's object) has kₙ = κq⁴ + σq² (M1–M2). At σ = 0 it scales as
//! the filament (κ for EI). Under a tension held at the sidecar's σ₀, a mode's stiffness
//! depends on κ through its bending share sₙ = ∂ln kₙ/∂ln κ = κ₀q⁴/kₙ⁰
//! ([`crate::spectral::membrane::Membrane::bending_share`], from the continuum mode the
//! check names): kₙ(κ, σ₀)/kₙ⁰ = gₙ = (κ/κ₀)·sₙ + 1 − sₙ, so ln r_var,n = ln(kT/kT₀) − ln
//! gₙ and ln r_rate,n = ln gₙ − ln(ξ/ξ₀). With kT known, κ is the weighted least-squares
//! solution of that law ([`held_tension`], Gauss–Newton: the first step is the regression
//! of ln r_var on sₙ through the origin, [`Pooled::regressed`], each further step the
//! regression on the local shares (κ/κ₀)sₙ/gₙ at the current κ); ξ = ξ₀·e^(Ḡ − m_rate) with
//! Ḡ the rates' weighted mean of ln gₙ at κ̂, its error var = s̄²s_m² + s_rate² +
//! 2s̄·cov(m, m_rate) with s̄ the rates' weighted mean local share and m's regression
//! weights (to first order Ḡ = s̄·ln(κ/κ₀)); kT with κ known is the plain pool, as above
//! (kT scales every mode alike). Scaling every variance alike instead would mistake
//! tension-dominated modes, which hardly feel κ, for noise (a run at κ = 1.1 under σ = 20:
//! κ = 1.09 with an interval that misses 1.1; tested). When σ is not known either, κ and σ
//! are fitted together ([`JointFit::solved`]): ln r_var,n = −ln gₙ with gₙ = (κ/κ₀)sₙ +
//! σuₙ, uₙ = ∂ln kₙ/∂σ = q²/kₙ⁰, a two-parameter weighted least-squares fit (modes − 2 dof,
//! Gauss–Newton from the first-order fit [`JointFit::of`]) whose covariance at the solution
//! gives both intervals and their correlation; the tension-dominated modes fix σ, the
//! bending-dominated ones κ. Solved in the law, a large misstatement is not biased by the
//! linearization (σ = 40 for a stated 20: the first-order fit gives 34; tested).
//!
//! **Exactness.** The scaling is exact for the continuum, the spectral model and the
//! stationary variances of the exact-modal and Crank–Nicolson integrators (their stationary
//! law is kT K⁻¹); for an Euler variance, and for every discrete rate, the reference
//! depends on λΔt too, so the scaling holds to first order in the parameter's error with a
//! slope 1 − O(λΔt). A finite-element membrane's mode stiffness follows the continuum's
//! shares to the mesh's relative error. At the true parameters every ratio is 1 either way,
//! so the interval's coverage does not depend on it (measured in statistics.md).

use crate::verify::diagnosis::{ModeRatio, first_seen, mode_ratios};
pub use crate::verify::diagnosis::{Pooled, SensitivityOf};
use crate::verify::summary::SceneSummary;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

/// Level of the intervals.
pub const LEVEL: f64 = 0.95;

/// One fitted parameter: the estimate, its interval at [`LEVEL`], and the standard error
/// of its logarithm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// The interval at [`LEVEL`] (lower, upper).
    pub interval: [f64; 2],
    /// Standard error of ln(value).
    pub log_std_error: f64,
}

impl Estimate {
    /// `base · exp(sign·m)` with the interval of `m ± z·se`.
    fn scaled(base: f64, sign: f64, m: f64, se: f64) -> Estimate {
        let z = Normal::standard().inverse_cdf(0.5 + LEVEL / 2.0);
        let at = |x: f64| base * (sign * x).exp();
        let (a, b) = (at(m - z * se), at(m + z * se));
        Estimate {
            value: at(m),
            interval: [a.min(b), a.max(b)],
            log_std_error: se,
        }
    }

    /// Whether `x` lies in the interval.
    pub fn covers(&self, x: f64) -> bool {
        (self.interval[0]..=self.interval[1]).contains(&x)
    }
}

/// The parameters a data set was simulated with (its sidecar's), as [`fit_runs`] scales
/// them, and how each mode's stiffness kₙ depends on the bending rigidity.
pub struct FitBase<'a> {
    /// EI of a filament, κ of a membrane.
    pub bending_rigidity: f64,
    /// ξ.
    pub drag: f64,
    /// kT.
    pub kt: f64,
    /// A membrane's tension σ₀ and, per mode, its log sensitivities
    /// (∂ln kₙ/∂ln κ, ∂ln kₙ/∂σ) = (κq⁴, q²)/kₙ at these parameters: for κ with σ held at
    /// σ₀ ≠ 0 the first is the mode's bending share sₙ (every sₙ = 1 at σ₀ = 0, and for a
    /// filament, `None`), and both serve the joint fit of κ and σ ([`JointFit`]).
    pub tension: Option<(f64, SensitivityOf<'a>)>,
}

/// κ and σ fitted together from a membrane's mode variances, kT known: the weighted
/// least-squares fit of ln r_var,n = −sₙ·ln(κ/κ₀) − uₙ·(σ − σ₀) over the modes
/// ([`Self::of`], first order in the parameters' errors), or of ln r_var,n = −ln gₙ in
/// the stiffness law itself ([`Self::solved`], what `fit` reports); sₙ, uₙ the
/// sensitivities of [`FitBase::tension`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointFit {
    /// The modes used.
    pub modes: Vec<String>,
    /// κ, its interval exp(±z·s.e.) on the log scale.
    pub bending_rigidity: Estimate,
    /// σ, its interval ±z·s.e.
    pub tension: LinearEstimate,
    /// The correlation of the estimates of ln κ and σ.
    pub correlation: f64,
    /// χ² of the modes about the fit (modes − 2 dof).
    pub chi2: f64,
    /// Its p-value.
    pub p_value: f64,
    /// ξ from the decay rates with these κ and σ ([`joint_drag`]); absent without rates
    /// (or from [`Self::of`] alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag: Option<Estimate>,
}

/// A parameter estimated on the linear scale: the estimate, its interval at [`LEVEL`]
/// and its standard error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearEstimate {
    /// The estimate.
    pub value: f64,
    /// The interval at [`LEVEL`] (lower, upper).
    pub interval: [f64; 2],
    /// Its standard error.
    pub std_error: f64,
}

impl LinearEstimate {
    /// Whether `x` lies in the interval.
    pub fn covers(&self, x: f64) -> bool {
        (self.interval[0]..=self.interval[1]).contains(&x)
    }
}

impl JointFit {
    /// The joint fit of `ratios` with each mode's sensitivities `x[n] = [sₙ, uₙ]` about
    /// κ₀ = `kappa`, σ₀ = `sigma`; `None` with fewer than 3 modes, a ratio or error
    /// [`Pooled::of`] refuses, or sensitivities that do not separate the two (the normal
    /// matrix singular to 1e-12 of its scale).
    pub fn of(ratios: &[ModeRatio], x: &[[f64; 2]], kappa: f64, sigma: f64) -> Option<JointFit> {
        Pooled::of(ratios)?;
        if ratios.len() < 3 || x.len() != ratios.len() || x.iter().flatten().any(|v| !v.is_finite())
        {
            return None;
        }
        let yw: Vec<(f64, f64)> = ratios
            .iter()
            .map(|m| (m.ratio.ln(), (m.std_error / m.ratio).powi(-2)))
            .collect();
        let (mut a, mut b) = ([[0.0; 2]; 2], [0.0; 2]);
        for ((y, w), xn) in yw.iter().zip(x) {
            for i in 0..2 {
                b[i] += w * xn[i] * y;
                for j in 0..2 {
                    a[i][j] += w * xn[i] * xn[j];
                }
            }
        }
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if det.is_nan() || det <= 1e-12 * a[0][0] * a[1][1] {
            return None;
        }
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let beta = [
            inv[0][0] * b[0] + inv[0][1] * b[1],
            inv[1][0] * b[0] + inv[1][1] * b[1],
        ];
        let chi2: f64 = (yw.iter().zip(x))
            .map(|((y, w), xn)| w * (y - xn[0] * beta[0] - xn[1] * beta[1]).powi(2))
            .sum();
        let dof = ratios.len() as f64 - 2.0;
        let z = Normal::standard().inverse_cdf(0.5 + LEVEL / 2.0);
        let se_sigma = inv[1][1].sqrt();
        let value = sigma - beta[1];
        Some(JointFit {
            modes: ratios.iter().map(|m| m.mode.clone()).collect(),
            bending_rigidity: Estimate::scaled(kappa, -1.0, beta[0], inv[0][0].sqrt()),
            tension: LinearEstimate {
                value,
                interval: [value - z * se_sigma, value + z * se_sigma],
                std_error: se_sigma,
            },
            // ln κ = −β₀, σ = σ₀ − β₁: the sign of the covariance is kept.
            correlation: inv[0][1] / (inv[0][0] * inv[1][1]).sqrt(),
            chi2,
            p_value: ChiSquared::new(dof).map_or(f64::NAN, |d| d.sf(chi2)),
            drag: None,
        })
    }

    /// The joint fit of [`Self::of`] solved in the stiffness law itself: the weighted
    /// least-squares (ln κ, σ) of ln r_var,n = −ln gₙ, gₙ = kₙ(κ, σ)/kₙ(κ₀, σ₀) =
    /// (κ/κ₀)·sₙ + σ·uₙ (exact for kₙ = κq⁴ + σq² with `x[n] = [sₙ, uₙ]` at κ₀, σ₀), by Gauss–Newton
    /// from (κ₀, σ₀): each step is [`Self::of`] of the ratios the law at (κ, σ) leaves to
    /// explain ([`relative_to`]) on the local sensitivities ((κ/κ₀)sₙ/gₙ, uₙ/gₙ), halved
    /// while a gₙ would not be positive. The first step is the first-order fit; the
    /// estimate, its intervals, the correlation and χ² are those of the step taken at the
    /// solution (|Δln κ| and |Δσ|/(1 + |σ|) below 1e-12). `None` as [`Self::of`], or
    /// without convergence in [`MAX_ITERATIONS`] steps.
    pub fn solved(
        ratios: &[ModeRatio],
        x: &[[f64; 2]],
        kappa: f64,
        sigma: f64,
    ) -> Option<JointFit> {
        let law = |(c, s): (f64, f64)| x.iter().map(|x| c * x[0] + s * x[1]).collect();
        solve_in_law(
            (1.0, sigma),
            law,
            |(c, s), g| {
                let local: Vec<[f64; 2]> = (x.iter().zip(g))
                    .map(|(x, g)| [c * x[0] / g, x[1] / g])
                    .collect();
                let step = Self::of(&relative_to(ratios, g), &local, kappa * c, s)?;
                let d = (
                    (step.bending_rigidity.value / (kappa * c)).ln(),
                    step.tension.value - s,
                );
                Some((step, d))
            },
            |(_, s), (dl, ds)| dl.abs() < 1e-12 && ds.abs() < 1e-12 * (1.0 + s.abs()),
            |(c, s), (dl, ds), h| (c * (h * dl).exp(), s + h * ds),
        )
    }
}

/// Steps of the Gauss–Newton fits ([`held_tension`], [`JointFit::solved`]) before they
/// give up.
pub const MAX_ITERATIONS: usize = 50;

/// The ratios `ratios` over the law's at the current parameters, rₙ·gₙ (gₙ the stiffness
/// ratio kₙ/kₙ⁰, so ln(rₙgₙ) = ln rₙ + ln gₙ is the part of ln rₙ = −ln gₙ + … the law
/// leaves unexplained), with the same relative errors: their linearized fit about the
/// current parameters is one Gauss–Newton step.
fn relative_to(ratios: &[ModeRatio], g: &[f64]) -> Vec<ModeRatio> {
    (ratios.iter().zip(g))
        .map(|(m, g)| ModeRatio::new(m.mode.clone(), m.ratio * g, m.std_error * g))
        .collect()
}

/// κ with the tension held at σ₀ ≠ 0, solved in the stiffness law: the weighted
/// least-squares ℓ = ln(κ/κ₀) of ln r_var,n = −ln gₙ, gₙ = e^ℓ·sₙ + 1 − sₙ
/// (kₙ(κ, σ₀)/kₙ(κ₀, σ₀), exact for kₙ = κq⁴ + σq² with the bending shares `shares` at
/// κ₀), by Gauss–Newton from ℓ = 0: each step is the regression ([`Pooled::regressed`])
/// of the ratios the law at ℓ leaves ([`relative_to`]) on the local shares e^ℓsₙ/gₙ,
/// halved while a gₙ would not be positive. The first step is the first-order
/// regression on sₙ. Returns the pool with m = −ℓ (κ = κ₀e^(−m)) and the standard error
/// and χ² of the step at the solution (|Δℓ| below 1e-12), and the local shares there;
/// `None` as [`Pooled::regressed`] or without convergence in [`MAX_ITERATIONS`] steps.
fn held_tension(ratios: &[ModeRatio], shares: &[f64]) -> Option<(Pooled, Vec<f64>)> {
    let law = |l: f64| {
        let c = l.exp();
        shares.iter().map(|s| c * s + 1.0 - s).collect()
    };
    solve_in_law(
        0.0,
        law,
        |l, g| {
            let c = l.exp();
            let local: Vec<f64> = shares.iter().zip(g).map(|(s, g)| c * s / g).collect();
            let step = Pooled::regressed(&relative_to(ratios, g), Some(&local))?;
            let d = step.log_ratio;
            Some((
                (
                    Pooled {
                        log_ratio: -l,
                        ..step
                    },
                    local,
                ),
                d,
            ))
        },
        |_, d| d.abs() < 1e-12,
        |l, d, h| l - h * d,
    )
}

/// Damped Gauss–Newton in a stiffness law ([`held_tension`], [`JointFit::solved`]): from
/// the parameters `theta`, each step fits the ratios linearized at the law's stiffness
/// ratios g = `law(θ)` (`step(θ, g)`: the fit at θ and the step Δθ it implies); the fit
/// is returned once `converged(θ, Δθ)`, else θ moves to `moved(θ, Δθ, h)` with h
/// halved from 1 while a gₙ there would not be positive. `None` if the law at `theta`
/// has a gₙ ≤ 0, a fit fails, the step shrinks below 1e-9 or [`MAX_ITERATIONS`] pass.
fn solve_in_law<P: Copy, R>(
    mut theta: P,
    law: impl Fn(P) -> Vec<f64>,
    step: impl Fn(P, &[f64]) -> Option<(R, P)>,
    converged: impl Fn(P, P) -> bool,
    moved: impl Fn(P, P, f64) -> P,
) -> Option<R> {
    let positive = |theta: P| {
        let g = law(theta);
        g.iter().all(|g| *g > 0.0).then_some(g)
    };
    let mut g = positive(theta)?;
    for _ in 0..MAX_ITERATIONS {
        let (fit, d) = step(theta, &g)?;
        if converged(theta, d) {
            return Some(fit);
        }
        let mut h = 1.0;
        loop {
            let next = moved(theta, d, h);
            if let Some(gn) = positive(next) {
                (theta, g) = (next, gn);
                break;
            }
            h *= 0.5;
            if h < 1e-9 {
                return None;
            }
        }
    }
    None
}

/// The fit of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunFit {
    /// The run.
    pub run: String,
    /// The pooled variance ratio (its `mode-variance` checks): kT's, and the bending
    /// rigidity's when every mode's bending share is 1.
    pub variance: Option<Pooled>,
    /// The fit of the variance ratios in the stiffness law that gives the bending
    /// rigidity under tension held known ([`held_tension`]: `log_ratio` = −ln(κ/κ₀), its
    /// standard error and the modes' χ² about the law at the solution); absent when every
    /// share is 1 (`variance` gives it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_regression: Option<Pooled>,
    /// A membrane's κ and σ fitted together from the variances, kT known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<JointFit>,
    /// The pooled decay-rate ratio (its `decay-rate` checks).
    pub rate: Option<Pooled>,
    /// EI with kT known (the sidecar's): from the variances.
    pub bending_rigidity: Option<Estimate>,
    /// ξ with kT known: from the rates and the fitted EI.
    pub drag: Option<Estimate>,
    /// kT with EI known instead (the sidecar's): from the variances.
    pub kt_given_bending_rigidity: Option<Estimate>,
    /// The correlation of the pooled log ratios m_var and m_rate that ξ's error takes
    /// into account (see the module docs); `None` without both.
    pub variance_rate_correlation: Option<f64>,
}

/// The factor √(ν/(ν − 2)) by which `fit` scales an error estimated with ν degrees of
/// freedom (a decay rate's jackknife error, ν = B − 1) before pooling: the weights
/// 1/ŝ² of an inverse-variance pool are then unbiased, E[ν/χ²_ν] = ν/(ν − 2), so that the
/// pooled error and the modes' χ² about it are not understated. 1 without ν or for
/// ν ≤ 2 (an exact error, e.g. a `quadratic-form` check's, has none).
fn estimated_error_factor(dof: Option<f64>) -> f64 {
    match dof {
        Some(nu) if nu > 2.0 => (nu / (nu - 2.0)).sqrt(),
        _ => 1.0,
    }
}

/// cov(m_var, m_rate) of the pooled log ratios `var` and `rate` (module docs): over the
/// modes in both, the product of their normalized weights, log errors and
/// `correlation(mode)`; m_var's weights are those of the regression on `var_shares`
/// ([`Pooled::regressed`]: wₙsₙ/Σwₖsₖ², the inverse-variance weights when `None`).
fn pooled_covariance(
    var: &[ModeRatio],
    rate: &[ModeRatio],
    var_shares: Option<&[f64]>,
    correlation: impl Fn(&str) -> Option<f64>,
) -> f64 {
    let share = |k: usize| var_shares.map_or(1.0, |s| s[k]);
    let log_se = |m: &ModeRatio| m.std_error / m.ratio;
    let wv: f64 = (var.iter().enumerate())
        .map(|(k, m)| log_se(m).powi(-2) * share(k) * share(k))
        .sum();
    let wr: f64 = rate.iter().map(|m| log_se(m).powi(-2)).sum();
    (var.iter().enumerate())
        .filter_map(|(k, v)| {
            let r = rate.iter().find(|r| r.mode == v.mode)?;
            let rho = correlation(&v.mode)?;
            // a·s_var·b·s_rate with a = sₙs_var⁻²/Σ, b = s_rate⁻²/Σ.
            Some(rho * share(k) / (log_se(v) * log_se(r) * wv * wr))
        })
        .sum()
}

/// The bending shares of `ratios`' modes under a tension σ₀ ≠ 0 held known (`None` if
/// `base` has none or σ₀ = 0: every share is 1; `Some(Err(mode))` for the first mode
/// without one).
fn shares_of(
    base: &FitBase,
    ratios: &[ModeRatio],
) -> Option<std::result::Result<Vec<f64>, String>> {
    let (_, sensitivities) = base.tension.filter(|(sigma, _)| *sigma != 0.0)?;
    Some(
        ratios
            .iter()
            .map(|m| {
                sensitivities(&m.mode)
                    .map(|s| s[0])
                    .ok_or_else(|| m.mode.clone())
            })
            .collect(),
    )
}

/// ξ (about ξ₀ = `drag`) with κ and σ from the joint fit `j` (about κ₀ = `kappa`, of
/// the variances `var` with sensitivities `xv`): the decay rates `rate` (sensitivities `xr`)
/// satisfy ln r_rate,n = ln gₙ − ln(ξ/ξ₀) with gₙ = (κ/κ₀)sₙ + σuₙ, so
/// ln(ξ/ξ₀) = Ḡ − m_rate, Ḡ the rates' inverse-variance weighted mean of ln gₙ at the
/// fit's (κ̂, σ̂) and m_rate their pooled log ratio. Its error, to first order:
/// var = s_rate² + aᵀΣa − 2aᵀc, with a = ∂Ḡ/∂(ln κ, σ) (the rates' weighted mean local
/// sensitivities), Σ the joint fit's covariance and c = cov((ln κ̂, σ̂), m_rate) =
/// −Σ·Σₙ Xₙ wₙ bₙ ρₙ s_var,n s_rate,n over the modes in both, with Xₙ = ((κ/κ₀)sₙ/gₙ,
/// uₙ/gₙ) the variance's local sensitivities, wₙ = s_var,n⁻² its weight, bₙ the mode's
/// normalized weight in m_rate and ρₙ its `correlation` (the jackknife's, 0 without).
/// `None` without rates, with a rate mode lacking sensitivities, or a gₙ not positive.
pub fn joint_drag(
    j: &JointFit,
    (kappa, drag): (f64, f64),
    (var, xv): (&[ModeRatio], &[[f64; 2]]),
    (rate, xr): (&[ModeRatio], &[[f64; 2]]),
    correlation: impl Fn(&str) -> Option<f64>,
) -> Option<Estimate> {
    let pool = Pooled::of(rate)?;
    if xr.len() != rate.len() || xv.len() != var.len() {
        return None;
    }
    let (c, s) = (j.bending_rigidity.value / kappa, j.tension.value);
    let local = |x: &[f64; 2]| {
        let g = c * x[0] + s * x[1];
        (g > 0.0).then(|| (g, [c * x[0] / g, x[1] / g]))
    };
    let log_se = |m: &ModeRatio| m.std_error / m.ratio;
    let wr: Vec<f64> = rate.iter().map(|m| log_se(m).powi(-2)).collect();
    let sw: f64 = wr.iter().sum();
    let (mut gbar, mut a) = (0.0, [0.0; 2]);
    for (x, w) in xr.iter().zip(&wr) {
        let (g, l) = local(x)?;
        gbar += w * g.ln() / sw;
        a[0] += w * l[0] / sw;
        a[1] += w * l[1] / sw;
    }
    let (sl, ss, rho) = (
        j.bending_rigidity.log_std_error,
        j.tension.std_error,
        j.correlation,
    );
    let cov = [[sl * sl, rho * sl * ss], [rho * sl * ss, ss * ss]];
    // Σₙ Xₙ wₙ bₙ ρₙ s_var,n s_rate,n over the modes in both.
    let mut t = [0.0; 2];
    for (m, x) in var.iter().zip(xv) {
        let Some(k) = rate.iter().position(|r| r.mode == m.mode) else {
            continue;
        };
        let Some(r) = correlation(&m.mode) else {
            continue;
        };
        let (_, l) = local(x)?;
        let term = log_se(m).powi(-2) * (wr[k] / sw) * r * log_se(m) * log_se(&rate[k]);
        t[0] += l[0] * term;
        t[1] += l[1] * term;
    }
    let quad = |u: [f64; 2], v: [f64; 2]| {
        (0..2)
            .map(|i| (0..2).map(|k| u[i] * cov[i][k] * v[k]).sum::<f64>())
            .sum::<f64>()
    };
    // c = −Σt, so −2aᵀc = 2aᵀΣt.
    let var_m = pool.std_error.powi(2) + quad(a, a) + 2.0 * quad(a, t);
    Some(Estimate::scaled(
        drag,
        -1.0,
        pool.log_ratio - gbar,
        var_m.max(0.0).sqrt(),
    ))
}

/// The fits of every run of `scene` (the summary of `check` of the data whose sidecar
/// gives `base`), in the order of the runs' first checks (see the module docs). A run
/// under tension held known (`base.tension`) whose variance or rate modes lack a share
/// gets no bending rigidity or drag.
pub fn fit_runs(scene: &SceneSummary, base: &FitBase) -> Vec<RunFit> {
    first_seen(scene.checks.iter().map(|c| c.run.as_str()))
        .into_iter()
        .map(|run| fit_run(scene, run, base))
        .collect()
}

/// The fit of run `run` ([`fit_runs`]).
fn fit_run(scene: &SceneSummary, run: &str, base: &FitBase) -> RunFit {
    let rate_check = |mode: &str| {
        scene
            .checks
            .iter()
            .find(|c| c.run == run && c.check == "decay-rate" && c.parameter == mode)
    };
    let var_ratios = mode_ratios(&scene.checks, run, "mode-variance");
    let rate_ratios: Vec<ModeRatio> = mode_ratios(&scene.checks, run, "decay-rate")
        .into_iter()
        .map(|mut m| {
            let dof = rate_check(&m.mode).and_then(|c| c.dof);
            m.std_error *= estimated_error_factor(dof);
            m
        })
        .collect();
    let variance = Pooled::of(&var_ratios);
    let rate = Pooled::of(&rate_ratios);
    // Under tension: κ from the variances in the stiffness law (held_tension), and the
    // rates' part of ξ, ln ξ/ξ₀ = Ḡ − m_rate with Ḡ their weighted mean of ln gₙ at κ̂
    // (−s̄·m to first order) and s̄ their mean local share (module docs); without, the
    // plain pool, −Ḡ = m (exactly 1·m) and s̄ = 1.
    let var_shares = shares_of(base, &var_ratios);
    let held = var_shares
        .as_ref()
        .map(|v| v.as_ref().ok().and_then(|v| held_tension(&var_ratios, v)));
    let (regression, shares) = match held {
        Some(h) => {
            let (pool, local) = h.unzip();
            (Some(pool), local)
        }
        None => (None, None),
    };
    let bending = regression.clone().unwrap_or_else(|| variance.clone());
    let rate_part = match (&var_shares, shares_of(base, &rate_ratios)) {
        (None, _) => bending.as_ref().map(|v| (v.log_ratio, 1.0)),
        (Some(_), r) => bending.as_ref().zip(r.and_then(|r| r.ok())).map(|(v, r)| {
            let c = (-v.log_ratio).exp();
            let w = |m: &ModeRatio| (m.std_error / m.ratio).powi(-2);
            let sw: f64 = rate_ratios.iter().map(w).sum();
            let mean = |f: &dyn Fn(f64) -> f64| {
                (rate_ratios.iter().zip(&r))
                    .map(|(m, &s)| w(m) * f(s))
                    .sum::<f64>()
                    / sw
            };
            let g = |s: f64| c * s + 1.0 - s;
            (-mean(&|s| g(s).ln()), mean(&|s| c * s / g(s)))
        }),
    };
    let correlation = |mode: &str| rate_check(mode).and_then(|c| c.variance_correlation);
    let ei = bending
        .as_ref()
        .map(|v| Estimate::scaled(base.bending_rigidity, -1.0, v.log_ratio, v.std_error));
    let kt = variance
        .as_ref()
        .map(|v| Estimate::scaled(base.kt, 1.0, v.log_ratio, v.std_error));
    let both = bending.as_ref().zip(rate.as_ref()).zip(rate_part);
    let cov =
        both.map(|_| pooled_covariance(&var_ratios, &rate_ratios, shares.as_deref(), correlation));
    let drag = both.zip(cov).map(|(((v, r), (g, sbar)), cov)| {
        let var = sbar * sbar * v.std_error.powi(2) + r.std_error.powi(2) + 2.0 * sbar * cov;
        Estimate::scaled(base.drag, -1.0, g + r.log_ratio, var.max(0.0).sqrt())
    });
    let variance_rate_correlation = both
        .zip(cov)
        .map(|(((v, r), _), cov)| cov / (v.std_error * r.std_error));
    let joint = base.tension.and_then(|(sigma, of)| {
        let xv: Vec<[f64; 2]> = var_ratios
            .iter()
            .map(|m| of(&m.mode))
            .collect::<Option<_>>()?;
        let mut j = JointFit::solved(&var_ratios, &xv, base.bending_rigidity, sigma)?;
        let xr: Option<Vec<[f64; 2]>> = rate_ratios.iter().map(|m| of(&m.mode)).collect();
        j.drag = xr.and_then(|xr| {
            joint_drag(
                &j,
                (base.bending_rigidity, base.drag),
                (&var_ratios, &xv),
                (&rate_ratios, &xr),
                correlation,
            )
        });
        Some(j)
    });
    RunFit {
        run: run.to_string(),
        variance,
        bending_regression: regression.flatten(),
        joint,
        rate,
        bending_rigidity: ei,
        drag,
        kt_given_bending_rigidity: kt,
        variance_rate_correlation,
    }
}

/// A fitted number as `fit` prints it: four decimals between 0.1 and 10⁴, else four in
/// exponent form.
pub fn number_text(v: f64) -> String {
    if (0.1..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.4e}")
    }
}

/// `EI = 1.0002 [0.9976, 1.0027] from the variances of modes 1, 2, 3, kT known (one
/// factor over them: χ² p = 0.519)` for an estimate of parameter `name` pooled as
/// `pooled` from `what` (the interval at [`LEVEL`]; `given`: what is held known).
///
/// The χ² is of one factor over the modes, or, for a membrane's κ with σ held
/// (`in_law`), of the stiffness law gₙ = (κ/κ₀)sₙ + σuₙ with its one parameter κ, which
/// is not one factor over the modes.
pub fn estimate_text(
    name: &str,
    e: &Estimate,
    pooled: &Pooled,
    what: &str,
    given: &str,
    in_law: bool,
) -> String {
    let f = number_text;
    let over = if in_law {
        "the law with that one parameter over them"
    } else {
        "one factor over them"
    };
    format!(
        "{name} = {} [{}, {}] from the {what} of modes {}, {given}{}",
        f(e.value),
        f(e.interval[0]),
        f(e.interval[1]),
        pooled
            .modes
            .iter()
            .map(|m| m.trim_start_matches("n="))
            .collect::<Vec<_>>()
            .join(", "),
        pooled
            .p_value
            .map_or(String::new(), |p| format!(" ({over}: χ² p = {p:.3})"))
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verify::summary::CheckResult;

    fn ratios(values: &[(f64, f64)]) -> Vec<ModeRatio> {
        values
            .iter()
            .enumerate()
            .map(|(i, &(r, se))| ModeRatio::new(format!("n={}", i + 1), r, se))
            .collect()
    }

    /// The pooled log ratio is the inverse-variance weighted mean of ln r, its error
    /// 1/√Σw, its χ² about the mean; one mode has no χ² p-value; a non-positive ratio
    /// or error gives none.
    #[test]
    fn pooled_log_ratio_is_the_weighted_mean() {
        let p = Pooled::of(&ratios(&[(1.1, 0.011), (1.1, 0.022)])).unwrap();
        assert!((p.log_ratio - 1.1f64.ln()).abs() < 1e-12);
        let se = (1e4f64 + 2500.0).sqrt().recip();
        assert!((p.std_error - se).abs() < 1e-12, "{} vs {se}", p.std_error);
        assert!(p.chi2.abs() < 1e-20 && p.p_value.unwrap() > 0.999);
        let one = Pooled::of(&ratios(&[(0.9, 0.01)])).unwrap();
        assert!(one.p_value.is_none());
        assert!(Pooled::of(&ratios(&[(-1.0, 0.1)])).is_none());
        assert!(Pooled::of(&ratios(&[(1.0, 0.0)])).is_none());
        assert!(Pooled::of(&[]).is_none());
    }

    /// The covariance of the pooled log ratios: one mode gives ρ·s_var·s_rate; two modes
    /// give Σ aₙbₙρₙ s_var,n s_rate,n with the normalized inverse-variance weights; a mode
    /// without a rate, or without a correlation, adds nothing.
    #[test]
    fn pooled_covariance_weights_each_modes_correlation() {
        // Log errors 0.02 and 0.04.
        let one = pooled_covariance(
            &ratios(&[(1.0, 0.02)]),
            &ratios(&[(2.0, 0.08)]),
            None,
            |_| Some(-0.5),
        );
        assert!((one - (-0.5 * 0.02 * 0.04)).abs() < 1e-15, "{one}");
        let v = ratios(&[(1.0, 0.01), (1.0, 0.02)]);
        let r = ratios(&[(1.0, 0.03), (1.0, 0.03)]);
        let rho = |m: &str| Some(if m == "n=1" { -0.6 } else { -0.2 });
        let a = [1e4 / 12_500.0, 2_500.0 / 12_500.0];
        let expected = a[0] * 0.5 * -0.6 * 0.01 * 0.03 + a[1] * 0.5 * -0.2 * 0.02 * 0.03;
        let two = pooled_covariance(&v, &r, None, rho);
        assert!((two - expected).abs() < 1e-15, "{two} vs {expected}");
        // The same weights as Pooled's: var(m_var) = Σ aₙ² s_var,n².
        let pv = Pooled::of(&v).unwrap();
        let sum_a2s2 = a[0] * a[0] * 1e-4 + a[1] * a[1] * 4e-4;
        assert!((pv.std_error.powi(2) - sum_a2s2).abs() < 1e-15);
        let none = pooled_covariance(&v, &r, None, |m: &str| (m == "n=1").then_some(-0.6));
        assert!((none - a[0] * 0.5 * -0.6 * 0.01 * 0.03).abs() < 1e-15);
        let rate_one = ratios(&[(1.0, 0.03)]);
        let only_first = pooled_covariance(&v, &rate_one, None, rho);
        assert!((only_first - a[0] * -0.6 * 0.01 * 0.03).abs() < 1e-15);
    }

    /// With every regressor 1 the regression is the weighted mean of `Pooled::of`, bit
    /// for bit; a regressor per mode that is missing or not finite gives none.
    #[test]
    fn regression_on_unit_shares_is_the_pooled_mean() {
        let r = ratios(&[(1.1, 0.011), (0.97, 0.02), (1.03, 0.015)]);
        assert_eq!(Pooled::regressed(&r, Some(&[1.0; 3])), Pooled::of(&r));
        assert!(Pooled::regressed(&r, Some(&[1.0; 2])).is_none());
        assert!(Pooled::regressed(&r, Some(&[1.0, f64::NAN, 1.0])).is_none());
    }

    /// A run whose stiffness kₙ = κq⁴ + σq² is off by κ/κ₀ = e^a at a tension held known,
    /// with drag ξ/ξ₀ = e^b: the exact ratios r_var,n = 1/gₙ and r_rate,n = gₙe^(−b),
    /// gₙ = e^a·sₙ + 1 − sₙ, give κ₀e^a and ξ₀e^b with χ² 0, and kT from the plain mean;
    /// the first-order regression on sₙ alone (the Gauss–Newton fit's first step) misses
    /// κ by more than 0.1 %; without the shares (σ = 0 assumed) κ is off by more than 1 %
    /// and the modes disagree (χ² p < 1e-6).
    #[test]
    fn shares_recover_the_bending_rigidity_under_tension() {
        let (a, b) = (0.1_f64, -0.05_f64);
        let shares: [f64; 4] = [0.95, 0.8, 0.6, 0.4];
        let check = |kind: &str, n: usize, ratio: f64| CheckResult {
            name: format!("cn/{kind}/n={n}"),
            run: "cn".into(),
            check: kind.into(),
            parameter: format!("n={n}"),
            kind: "t-test".into(),
            statistic: Some(0.0),
            dof: None,
            passed: true,
            p_value: Some(0.5),
            p_adjusted: Some(1.0),
            estimate: Some(ratio),
            reference: Some(1.0),
            std_error: Some(1e-3),
            continuum: None,
            reference_kind: "discrete".into(),
            unit: String::new(),
            detail: String::new(),
            largest_deviation: None,
            variance_correlation: None,
        };
        let g = |s: f64| a.exp() * s + 1.0 - s;
        let mut checks = Vec::new();
        for (k, &s) in shares.iter().enumerate() {
            checks.push(check("mode-variance", k + 1, 1.0 / g(s)));
            checks.push(check("decay-rate", k + 1, g(s) * (-b).exp()));
        }
        let scene = SceneSummary::of_checks("m", checks);
        // No tension sensitivity: the joint fit has none to separate, only κ is fitted.
        let share = |mode: &str| {
            let k: usize = mode.strip_prefix("n=")?.parse().ok()?;
            shares.get(k - 1).map(|&s| [s, 0.0])
        };
        fn base(tension: Option<(f64, SensitivityOf<'_>)>) -> FitBase<'_> {
            FitBase {
                bending_rigidity: 2.0,
                drag: 3.0,
                kt: 0.5,
                tension,
            }
        }
        let fit = &fit_runs(&scene, &base(Some((20.0, &share))))[0];
        let kappa = fit.bending_rigidity.as_ref().unwrap();
        assert!(
            (kappa.value / (2.0 * a.exp()) - 1.0).abs() < 1e-12,
            "{kappa:?}"
        );
        let xi = fit.drag.as_ref().unwrap();
        assert!((xi.value / (3.0 * b.exp()) - 1.0).abs() < 1e-12, "{xi:?}");
        let regression = fit.bending_regression.as_ref().unwrap();
        assert!(regression.chi2 < 1e-12, "{regression:?}");
        let ratios = mode_ratios(&scene.checks, "cn", "mode-variance");
        let first = Pooled::regressed(&ratios, Some(&shares)).unwrap();
        let missed = (-first.log_ratio - a).exp() - 1.0;
        assert!(missed.abs() > 1e-3, "{missed}");
        // ln r weighted by 1/s.e.(ln r)² = (r/1e-3)².
        let w = |s: f64| g(s).powi(-2);
        let mean: f64 = shares.iter().map(|&s| -g(s).ln() * w(s)).sum::<f64>()
            / shares.iter().map(|&s| w(s)).sum::<f64>();
        let kt = fit.kt_given_bending_rigidity.as_ref().unwrap();
        assert!(
            (kt.value / (0.5 * mean.exp()) - 1.0).abs() < 1e-12,
            "{kt:?}"
        );

        let naive = &fit_runs(&scene, &base(None))[0];
        let wrong = naive.bending_rigidity.as_ref().unwrap().value / (2.0 * a.exp());
        assert!((wrong - 1.0).abs() > 0.01, "{wrong}");
        assert!(naive.bending_regression.is_none());
        assert!(naive.variance.as_ref().unwrap().p_value.unwrap() < 1e-6);
    }

    /// The joint fit recovers ln κ/κ₀ = a and σ − σ₀ = d from exact ratios
    /// ln rₙ = −sₙa − uₙd with χ² 0, and a covariance that gives the single-parameter
    /// error when the two regressors are orthogonal in the weights; it refuses fewer than
    /// 3 modes and regressors that do not separate κ from σ (uₙ ∝ sₙ).
    #[test]
    fn joint_fit_recovers_kappa_and_sigma() {
        let (a, d) = (0.08_f64, -1.5_f64);
        let x = [[1.0, 0.02], [0.9, 0.01], [0.7, 0.005], [0.5, 0.002]];
        let r: Vec<ModeRatio> = (x.iter().enumerate())
            .map(|(k, [s, u])| ModeRatio::new(format!("n={}", k + 1), (-s * a - u * d).exp(), 1e-3))
            .collect();
        let j = JointFit::of(&r, &x, 2.0, 20.0).unwrap();
        assert!(
            (j.bending_rigidity.value / (2.0 * a.exp()) - 1.0).abs() < 1e-10,
            "{j:?}"
        );
        assert!((j.tension.value - (20.0 + d)).abs() < 1e-8, "{j:?}");
        assert!(j.chi2 < 1e-12 && j.p_value > 0.999, "{j:?}");
        assert!(j.tension.covers(20.0 + d) && j.correlation.abs() < 1.0);
        assert!(JointFit::of(&r[..2], &x[..2], 2.0, 20.0).is_none());
        let collinear: Vec<[f64; 2]> = x.iter().map(|[s, _]| [*s, 0.01 * s]).collect();
        assert!(JointFit::of(&r, &collinear, 2.0, 20.0).is_none());
        // Orthogonal regressors, equal weights (ratio 1): errors 1/√Σwₙxₙ² each.
        let one: Vec<ModeRatio> = (0..4)
            .map(|k| ModeRatio::new(format!("n={k}"), 1.0, 0.01))
            .collect();
        let x = [[1.0, 1.0], [1.0, -1.0], [1.0, 1.0], [1.0, -1.0]];
        let j = JointFit::of(&one, &x, 1.0, 0.0).unwrap();
        let se = (4.0f64 * 1e4).sqrt().recip();
        assert!((j.bending_rigidity.log_std_error - se).abs() < 1e-15);
        assert!((j.tension.std_error - se).abs() < 1e-15 && j.correlation.abs() < 1e-15);
    }

    /// Solved in the law, the joint fit recovers a large misstatement exactly: ratios
    /// 1/gₙ of κ/κ₀ = 1.5 and σ = 40 for a stated σ₀ = 20 (gₙ = 1.5sₙ + 40uₙ, with
    /// sₙ + 20uₙ = 1 as for kₙ = κq⁴ + σq²) give κ = 1.5κ₀ and σ = 40 to 1e-9 with χ² 0,
    /// while the first-order fit ([`JointFit::of`], its first step) misses σ by more than
    /// 5 %; a law that a step would take through gₙ ≤ 0 is approached by halved steps.
    #[test]
    fn the_joint_fit_solved_in_the_law_has_no_linearization_bias() {
        let shares = [0.9, 0.75, 0.6, 0.45, 0.3, 0.2];
        let x: Vec<[f64; 2]> = shares.iter().map(|s| [*s, (1.0 - s) / 20.0]).collect();
        // Variance ratios 1/gₙ (errors 0.1 %) of the law gₙ = c·sₙ + σ·uₙ.
        let law = |c: f64, sigma: f64| -> Vec<ModeRatio> {
            (x.iter().enumerate())
                .map(|(k, [s, u])| {
                    let g = c * s + sigma * u;
                    ModeRatio::new(format!("n={}", k + 1), 1.0 / g, 1e-3 / g)
                })
                .collect()
        };
        let r = law(1.5, 40.0);
        let j = JointFit::solved(&r, &x, 2.0, 20.0).unwrap();
        assert!((j.bending_rigidity.value / 3.0 - 1.0).abs() < 1e-9, "{j:?}");
        assert!((j.tension.value - 40.0).abs() < 1e-8, "{j:?}");
        assert!(j.chi2 < 1e-12, "{j:?}");
        let first = JointFit::of(&r, &x, 2.0, 20.0).unwrap();
        assert!((first.tension.value / 40.0 - 1.0).abs() > 0.05, "{first:?}");
        // σ far below: the first step would leave gₙ ≤ 0 for the tension-dominated modes.
        let soft = law(0.9, 2.0);
        let j = JointFit::solved(&soft, &x, 2.0, 20.0).unwrap();
        assert!((j.tension.value - 2.0).abs() < 1e-8, "{j:?}");
        assert!((j.bending_rigidity.value / 1.8 - 1.0).abs() < 1e-9, "{j:?}");
    }

    /// ξ with the joint κ and σ: exact law ratios of κ × 1.5, σ = 40 (stated 20) and
    /// ξ × 0.8 give ξ₀·0.8 to 1e-9; and its standard error is the delta method's — the
    /// numerical gradient of ln ξ̂ in the variance and rate log ratios (a central
    /// difference through [`JointFit::solved`] and [`joint_drag`]) against their
    /// covariance (log errors s_var, s_rate, and ρₙ between a mode's two) gives the same
    /// variance to 1e-4; with the correlations left out it does not (the covariance term
    /// is tested, not idle).
    #[test]
    fn the_joint_drag_is_exact_in_the_law_with_the_delta_methods_error() {
        let shares = [0.9, 0.75, 0.6, 0.45, 0.3, 0.2];
        let x: Vec<[f64; 2]> = shares.iter().map(|s| [*s, (1.0 - s) / 20.0]).collect();
        let (sv, sr) = ([0.01, 0.012, 0.015, 0.02, 0.025, 0.03], 0.04);
        let rho = |m: &str| Some(if m == "n=2" { -0.6 } else { -0.3 });
        let ratios = |y: &[f64], z: &[f64]| {
            let v: Vec<ModeRatio> = (y.iter().zip(&sv).enumerate())
                .map(|(k, (y, s))| ModeRatio::new(format!("n={}", k + 1), y.exp(), s * y.exp()))
                .collect();
            let r: Vec<ModeRatio> = (z.iter().enumerate())
                .map(|(k, z)| ModeRatio::new(format!("n={}", k + 1), z.exp(), sr * z.exp()))
                .collect();
            (v, r)
        };
        let drag = |y: &[f64], z: &[f64], rho: &dyn Fn(&str) -> Option<f64>| {
            let (v, r) = ratios(y, z);
            let j = JointFit::solved(&v, &x, 2.0, 20.0).unwrap();
            joint_drag(&j, (2.0, 3.0), (&v, &x), (&r, &x), rho).unwrap()
        };
        let g: Vec<f64> = x.iter().map(|[s, u]| 1.5 * s + 40.0 * u).collect();
        let y: Vec<f64> = g.iter().map(|g| -g.ln()).collect();
        let z: Vec<f64> = g.iter().map(|g| g.ln() - 0.8f64.ln()).collect();
        let xi = drag(&y, &z, &rho);
        assert!((xi.value / 2.4 - 1.0).abs() < 1e-9, "{xi:?}");
        // The delta method, by central differences in each log ratio.
        let h = 1e-6;
        let grad = |k: usize| {
            let (mut yp, mut ym, mut zp, mut zm) = (y.clone(), y.clone(), z.clone(), z.clone());
            if k < 6 {
                yp[k] += h;
                ym[k] -= h;
            } else {
                zp[k - 6] += h;
                zm[k - 6] -= h;
            }
            (drag(&yp, &zp, &rho).value.ln() - drag(&ym, &zm, &rho).value.ln()) / (2.0 * h)
        };
        let d: Vec<f64> = (0..12).map(grad).collect();
        let mut var = 0.0;
        for n in 0..6 {
            let r = rho(&format!("n={}", n + 1)).unwrap();
            var += d[n] * d[n] * sv[n] * sv[n] + d[6 + n] * d[6 + n] * sr * sr;
            var += 2.0 * d[n] * d[6 + n] * r * sv[n] * sr;
        }
        let stated = xi.log_std_error.powi(2);
        assert!((stated / var - 1.0).abs() < 1e-4, "{stated} vs {var}");
        let without = drag(&y, &z, &|_| None).log_std_error.powi(2);
        assert!((without / var - 1.0).abs() > 1e-2, "{without} vs {var}");
    }

    /// An error estimated with ν degrees of freedom is scaled by √(ν/(ν − 2)) before
    /// pooling (E[ν/χ²_ν] = ν/(ν − 2)); an exact one, or ν ≤ 2, is not.
    #[test]
    fn estimated_errors_are_debiased_before_pooling() {
        assert!((estimated_error_factor(Some(31.0)) - (31.0f64 / 29.0).sqrt()).abs() < 1e-15);
        assert_eq!(estimated_error_factor(None), 1.0);
        assert_eq!(estimated_error_factor(Some(2.0)), 1.0);
        // The expectation it corrects, by quadrature over the χ²₃₁ law: E[31/χ²] = 31/29.
        let chi = ChiSquared::new(31.0).unwrap();
        let n = 20_000;
        let mean: f64 = (0..n)
            .map(|k| 31.0 / chi.inverse_cdf((k as f64 + 0.5) / n as f64))
            .sum::<f64>()
            / n as f64;
        assert!((mean - 31.0 / 29.0).abs() < 1e-3, "{mean}");
    }

    /// The estimates follow the scaling of the module docs: variances × 1/c (EI × c)
    /// give EI₀·c, kT₀/c; rates × c/d with them give ξ₀·d; the interval is
    /// exp(±1.96 s.e.) about the estimate on the log scale.
    #[test]
    fn estimates_scale_as_the_references() {
        let (c, d) = (1.2, 0.8);
        let v = Pooled::of(&ratios(&[(1.0 / c, 1e-3), (1.0 / c, 1e-3)])).unwrap();
        let r = Pooled::of(&ratios(&[(c / d, 1e-3)])).unwrap();
        let ei = Estimate::scaled(2.0, -1.0, v.log_ratio, v.std_error);
        assert!((ei.value - 2.0 * c).abs() < 1e-12);
        let z = 1.959963984540054;
        assert!((ei.interval[1] / ei.value - (z * v.std_error).exp()).abs() < 1e-12);
        assert!(ei.covers(2.0 * c) && !ei.covers(2.0));
        let kt = Estimate::scaled(0.5, 1.0, v.log_ratio, v.std_error);
        assert!((kt.value - 0.5 / c).abs() < 1e-12);
        let xi = Estimate::scaled(3.0, -1.0, v.log_ratio + r.log_ratio, 0.1);
        assert!((xi.value - 3.0 * d).abs() < 1e-12);
    }
}
