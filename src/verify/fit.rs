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
//! **Exactness.** The scaling is exact for the continuum, the spectral model and the
//! stationary variances of the exact-modal and Crank–Nicolson integrators (their
//! stationary law is kT K⁻¹); for an Euler variance, and for every discrete rate, the
//! reference depends on λΔt too, so the scaling holds to first order in the parameter's
//! error with a slope 1 − O(λΔt). At the true parameters every ratio is 1 either way, so
//! the interval's coverage does not depend on it (measured in statistics.md).

use crate::data::DataFilament;
use crate::verify::diagnosis::{ModeRatio, first_seen, mode_ratios};
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

/// The pooled log ratio of one observable over the modes of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pooled {
    /// The modes used, as their checks name them (`n=3`).
    pub modes: Vec<String>,
    /// The inverse-variance weighted mean m of ln(estimate/reference).
    pub log_ratio: f64,
    /// Its standard error.
    pub std_error: f64,
    /// χ² of the modes' ln r about m (modes − 1 dof).
    pub chi2: f64,
    /// Its p-value (`None` with one mode).
    pub p_value: Option<f64>,
}

impl Pooled {
    /// The pooled log ratio of `ratios` (`None` if there is none, or one is not positive
    /// with a positive finite error).
    pub fn of(ratios: &[ModeRatio]) -> Option<Pooled> {
        if ratios.is_empty()
            || ratios.iter().any(|m| {
                !(m.ratio.is_finite()
                    && m.ratio > 0.0
                    && m.std_error.is_finite()
                    && m.std_error > 0.0)
            })
        {
            return None;
        }
        let logs: Vec<(f64, f64)> = ratios
            .iter()
            .map(|m| (m.ratio.ln(), m.std_error / m.ratio))
            .collect();
        let sw: f64 = logs.iter().map(|(_, s)| s.powi(-2)).sum();
        let mean = logs.iter().map(|(l, s)| l * s.powi(-2)).sum::<f64>() / sw;
        let chi2: f64 = logs.iter().map(|(l, s)| ((l - mean) / s).powi(2)).sum();
        let dof = logs.len() as f64 - 1.0;
        Some(Pooled {
            modes: ratios.iter().map(|m| m.mode.clone()).collect(),
            log_ratio: mean,
            std_error: sw.sqrt().recip(),
            chi2,
            p_value: (dof > 0.0).then(|| ChiSquared::new(dof).map_or(f64::NAN, |d| d.sf(chi2))),
        })
    }
}

/// The fit of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunFit {
    /// The run.
    pub run: String,
    /// The pooled variance ratio (its `mode-variance` checks).
    pub variance: Option<Pooled>,
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
/// modes in both, the product of their normalized inverse-variance weights, log errors
/// and `correlation(mode)`.
fn pooled_covariance(
    var: &[ModeRatio],
    rate: &[ModeRatio],
    correlation: impl Fn(&str) -> Option<f64>,
) -> f64 {
    let log_se = |m: &ModeRatio| m.std_error / m.ratio;
    let total = |ms: &[ModeRatio]| ms.iter().map(|m| log_se(m).powi(-2)).sum::<f64>();
    let (wv, wr) = (total(var), total(rate));
    var.iter()
        .filter_map(|v| {
            let r = rate.iter().find(|r| r.mode == v.mode)?;
            let rho = correlation(&v.mode)?;
            // a·s_var·b·s_rate with a = s_var⁻²/Σ, b = s_rate⁻²/Σ.
            Some(rho / (log_se(v) * log_se(r) * wv * wr))
        })
        .sum()
}

/// The fits of every run of `scene` (the summary of `check` of filament data with the
/// sidecar's `filament`), in the order of the runs' first checks (see the module docs).
pub fn fit_runs(scene: &SceneSummary, filament: &DataFilament) -> Vec<RunFit> {
    first_seen(scene.checks.iter().map(|c| c.run.as_str()))
        .into_iter()
        .map(|run| {
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
            let correlation = |mode: &str| rate_check(mode).and_then(|c| c.variance_correlation);
            let ei = variance.as_ref().map(|v| {
                Estimate::scaled(filament.bending_rigidity, -1.0, v.log_ratio, v.std_error)
            });
            let kt = variance
                .as_ref()
                .map(|v| Estimate::scaled(filament.kt, 1.0, v.log_ratio, v.std_error));
            let both = variance.as_ref().zip(rate.as_ref());
            let cov = both.map(|_| pooled_covariance(&var_ratios, &rate_ratios, correlation));
            let drag = both.zip(cov).map(|((v, r), cov)| {
                let var = v.std_error.powi(2) + r.std_error.powi(2) + 2.0 * cov;
                Estimate::scaled(
                    filament.drag,
                    -1.0,
                    v.log_ratio + r.log_ratio,
                    var.max(0.0).sqrt(),
                )
            });
            let variance_rate_correlation = both
                .zip(cov)
                .map(|((v, r), cov)| cov / (v.std_error * r.std_error));
            RunFit {
                run: run.to_string(),
                variance,
                rate,
                bending_rigidity: ei,
                drag,
                kt_given_bending_rigidity: kt,
                variance_rate_correlation,
            }
        })
        .collect()
}

/// `EI = 1.0002 [0.9976, 1.0027] from the variances of modes 1, 2, 3, kT known (one
/// factor over them: χ² p = 0.519)` for an estimate of parameter `name` pooled as
/// `pooled` from `what` (the interval at [`LEVEL`]; `given`: what is held known).
pub fn estimate_text(name: &str, e: &Estimate, pooled: &Pooled, what: &str, given: &str) -> String {
    // Four significant digits: fixed between 0.1 and 10⁴, else in exponent form.
    let f = |v: f64| {
        if (0.1..1e4).contains(&v.abs()) {
            format!("{v:.4}")
        } else {
            format!("{v:.4e}")
        }
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
        pooled.p_value.map_or(String::new(), |p| format!(
            " (one factor over them: χ² p = {p:.3})"
        ))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let one = pooled_covariance(&ratios(&[(1.0, 0.02)]), &ratios(&[(2.0, 0.08)]), |_| {
            Some(-0.5)
        });
        assert!((one - (-0.5 * 0.02 * 0.04)).abs() < 1e-15, "{one}");
        let v = ratios(&[(1.0, 0.01), (1.0, 0.02)]);
        let r = ratios(&[(1.0, 0.03), (1.0, 0.03)]);
        let rho = |m: &str| Some(if m == "n=1" { -0.6 } else { -0.2 });
        let a = [1e4 / 12_500.0, 2_500.0 / 12_500.0];
        let expected = a[0] * 0.5 * -0.6 * 0.01 * 0.03 + a[1] * 0.5 * -0.2 * 0.02 * 0.03;
        let two = pooled_covariance(&v, &r, rho);
        assert!((two - expected).abs() < 1e-15, "{two} vs {expected}");
        // The same weights as Pooled's: var(m_var) = Σ aₙ² s_var,n².
        let pv = Pooled::of(&v).unwrap();
        let sum_a2s2 = a[0] * a[0] * 1e-4 + a[1] * a[1] * 4e-4;
        assert!((pv.std_error.powi(2) - sum_a2s2).abs() < 1e-15);
        let none = pooled_covariance(&v, &r, |m: &str| (m == "n=1").then_some(-0.6));
        assert!((none - a[0] * 0.5 * -0.6 * 0.01 * 0.03).abs() < 1e-15);
        let rate_one = ratios(&[(1.0, 0.03)]);
        let only_first = pooled_covariance(&v, &rate_one, rho);
        assert!((only_first - a[0] * -0.6 * 0.01 * 0.03).abs() < 1e-15);
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
