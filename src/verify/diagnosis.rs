//! Diagnosis of failed checks (issue #31): the ratio estimate/reference of a check, and
//! the pattern a run's per-mode ratios show, stated as a *hint with its evidence*, never
//! as a verdict.
//!
//! The patterns are those of one wrong parameter of the Langevin equation
//! ξ ẇ = −K w + η, ⟨η η⟩ = 2 kT ξ δ(t − t′), whose mode n has the stationary variance
//! kT/kₙ and the decay rate kₙ/ξ:
//!
//! | error | variance ratio | decay-rate ratio |
//! |---|---|---|
//! | noise amplitude or kT × c | c, every mode | 1 |
//! | stiffness K × c (e.g. EI) | 1/c, every mode | c, every mode |
//! | drag ξ × c, the noise following it (fluctuation–dissipation kept) | 1 | 1/c, every mode |
//! | drag ξ × c in the deterministic step only, the noise of the true drag | 1/c | 1/c |
//! | the time unit of the data (dt, dt_sample) × 1/c | 1 | c |
//! | mesh or time step | departs from 1 more at higher modes | departs from 1 more at higher modes |
//!
//! [`diagnose`] recognises these patterns in lists of per-mode ratios with standard
//! errors (pure, unit-tested on synthetic lists); [`run_hints`] applies it to the
//! `mode-variance` and `decay-rate` checks of every run of a scene that has a failed
//! check. A pattern needs at least [`MIN_MODES`] modes; "off 1" means that the
//! inverse-variance weighted mean lies more than [`Z_HINT`] standard errors from 1,
//! "uniform" (one factor) that every mode lies within [`BAND`] of that deviation (or
//! within [`Z_HINT`] of its own errors) of the mean, "about the inverse" or "about the
//! same" that the logs of the variance and rate ratios agree within a factor [`APPROX`].
//! These are thresholds for a hint, not tests: the checks themselves are the verdict.

use crate::spectral::membrane::Membrane;
use crate::verify::summary::{CheckResult, SceneSummary};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal, StudentsT};

/// Fewest modes in which a pattern is named.
pub const MIN_MODES: usize = 3;
/// Standard errors by which a pooled ratio (or the growth of a deviation) must depart
/// from 1 to be named.
pub const Z_HINT: f64 = 3.0;
/// The χ² p-value below which ratios are not consistent with 1.
pub const P_STRUCTURE: f64 = 1e-3;
/// Ratios are one factor over the modes when each lies within this fraction of the
/// weighted mean's deviation from 1 (or within [`Z_HINT`] of its own standard errors) of
/// that mean: a discrete integrator's rate is not exactly proportional to the stiffness at
/// large λΔt (Crank–Nicolson's −ln((1 − a/2)/(1 + a/2)) grows faster than a), so the
/// rates of a stiffness error are one factor only roughly.
pub const BAND: f64 = 0.5;
/// Two deviations (logs of the pooled ratios) are of one size when their quotient lies
/// within [1/APPROX, APPROX].
pub const APPROX: f64 = 1.5;

/// The ratio estimate/reference of a check with its standard error (that of the
/// estimate over |reference|; `None` when the check has none), where the ratio means
/// something: a statistical check (with a p-value) with a finite estimate and a nonzero
/// reference resolved by the estimate's error (|reference| > standard error). `None` for
/// a deterministic check (oracle, residual), a check whose result is its statistic (χ²,
/// KS) and one against 0 (a mean, a cross-correlation, a symmetry, a bias).
pub fn ratio_of(c: &CheckResult) -> Option<(f64, Option<f64>)> {
    c.p_value?;
    let (e, r) = (c.estimate?, c.reference?);
    let se = c.std_error.filter(|s| s.is_finite() && *s >= 0.0);
    if !e.is_finite() || !r.is_finite() || r == 0.0 || se.is_some_and(|s| r.abs() <= s) {
        return None;
    }
    let ratio = e / r;
    ratio
        .is_finite()
        .then_some((ratio, se.map(|s| s / r.abs())))
}

/// `ratio 1.052 ± 0.013` (or `ratio 1.052` without an error) for a failed line; three
/// decimals, or three significant digits in exponent form outside [0.01, 1000) (the
/// error: outside [0.001, 1000), two).
pub fn ratio_text(ratio: f64, std_error: Option<f64>) -> String {
    let f = |v: f64| {
        if v == 0.0 || (0.01..1000.0).contains(&v.abs()) {
            format!("{v:.3}")
        } else {
            format!("{v:.2e}")
        }
    };
    let err = |s: f64| {
        if (0.001..1000.0).contains(&s) {
            format!("{s:.3}")
        } else {
            format!("{s:.1e}")
        }
    };
    match std_error {
        Some(s) => format!("ratio {} ± {}", f(ratio), err(s)),
        None => format!("ratio {}", f(ratio)),
    }
}

/// The ratio estimate/reference of one mode's check, with its standard error.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeRatio {
    /// The mode, as its check names it (`n=3`, or `3`).
    pub mode: String,
    /// estimate / reference.
    pub ratio: f64,
    /// Its standard error (> 0).
    pub std_error: f64,
}

impl ModeRatio {
    /// A mode's ratio.
    pub fn new(mode: impl Into<String>, ratio: f64, std_error: f64) -> Self {
        ModeRatio {
            mode: mode.into(),
            ratio,
            std_error,
        }
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
        Self::regressed(ratios, None)
    }

    /// The weighted least-squares slope m through the origin of ln rₙ on the regressors
    /// `shares` (sₙ; all 1 when `None`, which makes m the weighted mean of [`Self::of`],
    /// bit for bit): m = Σ wₙsₙ ln rₙ / Σ wₙsₙ², its standard error (Σ wₙsₙ²)^(−1/2),
    /// and the χ² of ln rₙ about sₙm (modes − 1 dof), wₙ = 1/s.e.(ln rₙ)². `None` as
    /// [`Self::of`], or if `shares` does not give every mode a finite regressor.
    pub fn regressed(ratios: &[ModeRatio], shares: Option<&[f64]>) -> Option<Pooled> {
        if ratios.is_empty()
            || ratios.iter().any(|m| {
                !(m.ratio.is_finite()
                    && m.ratio > 0.0
                    && m.std_error.is_finite()
                    && m.std_error > 0.0)
            })
            || shares.is_some_and(|s| s.len() != ratios.len() || s.iter().any(|x| !x.is_finite()))
        {
            return None;
        }
        let share = |k: usize| shares.map_or(1.0, |s| s[k]);
        let logs: Vec<(f64, f64)> = ratios
            .iter()
            .map(|m| (m.ratio.ln(), m.std_error / m.ratio))
            .collect();
        let sw: f64 = (logs.iter().enumerate())
            .map(|(k, (_, s))| s.powi(-2) * share(k) * share(k))
            .sum();
        let mean = (logs.iter().enumerate())
            .map(|(k, (l, s))| l * s.powi(-2) * share(k))
            .sum::<f64>()
            / sw;
        let chi2: f64 = (logs.iter().enumerate())
            .map(|(k, (l, s))| ((l - share(k) * mean) / s).powi(2))
            .sum();
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

/// A checked mode's log sensitivities of its stiffness kₙ = κq⁴ + σq² (M1),
/// (∂ln kₙ/∂ln κ, ∂ln kₙ/∂σ) = (κq⁴, q²)/kₙ, by its check's parameter (`n=k`), if it has
/// them ([`membrane_sensitivities`]; `fit`'s [`FitBase`](crate::verify::fit::FitBase)
/// and [`diagnose_membrane`]).
pub type SensitivityOf<'a> = &'a dyn Fn(&str) -> Option<[f64; 2]>;

/// The log sensitivities ([`Membrane::bending_share`], [`Membrane::tension_sensitivity`])
/// of `membrane`'s checked mode `mode`: `n=k` names the k-th slowest continuum mode
/// ([`Membrane::modes`]), as the membrane's checks do; `None` for another label.
pub fn membrane_sensitivities(membrane: &Membrane, mode: &str) -> Option<[f64; 2]> {
    let k: usize = mode.strip_prefix("n=")?.parse().ok()?;
    let modes = membrane.modes(k).ok()?;
    let mode = *modes.get(k.checked_sub(1)?)?;
    Some([
        membrane.bending_share(mode),
        membrane.tension_sensitivity(mode),
    ])
}

/// A pattern among a run's per-mode ratios.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pattern {
    /// Variances off by one factor over the modes, decay rates unchanged: the noise
    /// amplitude or kT.
    NoiseAmplitude,
    /// Variances off by one factor over the modes, no decay rates to compare: the noise
    /// amplitude, kT or the stiffness.
    UniformVariance,
    /// Variances × 1/c and decay rates × c, each uniform: the stiffness × c.
    Stiffness,
    /// Decay rates off by one factor, variances unchanged: the drag (with its noise) or
    /// the time unit.
    DragOrTimeUnit,
    /// Variances and decay rates off by the same factor 1/c: the drag × c in the
    /// deterministic step, with the noise of the true drag.
    DragWithoutItsNoise,
    /// Variances and decay rates each off by a uniform factor, in no single-parameter
    /// relation: more than one parameter.
    UniformBoth,
    /// Deviations from 1 that grow with the mode number: mesh or time step.
    GrowingWithMode,
    /// A membrane under tension: log variance ratios proportional to the modes' bending
    /// shares sₙ = κq⁴/(κq⁴ + σq²), decay rates the inverse: κ × c with σ right
    /// ([`diagnose_membrane`]).
    BendingRigidity,
    /// A membrane: log variance ratios proportional to the modes' tension sensitivities
    /// uₙ = q²/(κq⁴ + σq²), decay rates the inverse: a tension σ other than the stated
    /// σ₀ ([`diagnose_membrane`]).
    Tension,
}

/// A run's hint as a scene's summary keeps it ([`run_hints`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunHint {
    /// The run.
    pub run: String,
    /// The pattern seen.
    pub pattern: Pattern,
    /// The sentence naming it with its evidence (`hint: …?`).
    pub text: String,
}

/// A hint: the pattern and the sentence naming it with its evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct Hint {
    /// The pattern seen.
    pub pattern: Pattern,
    /// `uniform variance ratio 1.100 ± 0.004 over modes 1–8 with decay rates unchanged
    /// (ratio 1.002 ± 0.010) — noise amplitude or kT?`
    pub text: String,
}

/// The weighted summary of a list of ratios.
#[derive(Debug, Clone, Copy)]
struct RatioPool {
    /// Inverse-variance weighted mean.
    mean: f64,
    /// Its standard error.
    se: f64,
    /// Every ratio within [`BAND`] of the mean's deviation from 1, or within [`Z_HINT`]
    /// of its own standard errors, of the mean.
    in_band: bool,
    /// p-value of the χ² of the ratios about 1 (k dof).
    p_one: f64,
    /// Number of ratios.
    n: usize,
}

impl RatioPool {
    /// `None` for an empty list or one with a non-finite ratio or a non-positive error.
    fn of(r: &[ModeRatio]) -> Option<RatioPool> {
        if r.is_empty()
            || r.iter()
                .any(|m| !(m.ratio.is_finite() && m.std_error.is_finite() && m.std_error > 0.0))
        {
            return None;
        }
        let w: Vec<f64> = r.iter().map(|m| m.std_error.powi(-2)).collect();
        let sw: f64 = w.iter().sum();
        let mean = r.iter().zip(&w).map(|(m, w)| m.ratio * w).sum::<f64>() / sw;
        let band = BAND * (mean - 1.0).abs();
        let chi2: f64 = r
            .iter()
            .map(|m| ((m.ratio - 1.0) / m.std_error).powi(2))
            .sum();
        Some(RatioPool {
            mean,
            se: sw.sqrt().recip(),
            in_band: r
                .iter()
                .all(|m| (m.ratio - mean).abs() <= band.max(Z_HINT * m.std_error)),
            p_one: ChiSquared::new(r.len() as f64).map_or(f64::NAN, |d| d.sf(chi2)),
            n: r.len(),
        })
    }

    /// The mean more than [`Z_HINT`] standard errors from 1.
    fn off_one(&self) -> bool {
        (self.mean - 1.0).abs() > Z_HINT * self.se
    }

    /// At least [`MIN_MODES`] ratios, off 1 and within the band about their mean: one
    /// factor for every mode.
    fn uniformly_off(&self) -> bool {
        self.n >= MIN_MODES && self.off_one() && self.in_band
    }

    /// Neither off 1 nor structured about 1.
    fn unchanged(&self) -> bool {
        !self.off_one() && self.p_one >= P_STRUCTURE
    }

    /// ln of the mean: the size and sign of the deviation.
    fn log(&self) -> f64 {
        self.mean.ln()
    }

    /// `1.100 ± 0.004`.
    fn text(&self) -> String {
        format!("{:.3} ± {:.3}", self.mean, self.se)
    }
}

/// Whether two deviations (logs of ratios) are of one size within [`APPROX`]: the
/// signature of one parameter acting on both observables.
fn same_size(a: f64, b: f64) -> bool {
    let q = (a / b).abs();
    q.is_finite() && (1.0 / APPROX..=APPROX).contains(&q)
}

/// The mode number of a label (`n=3` → `3`).
fn mode_label(m: &ModeRatio) -> &str {
    m.mode.strip_prefix("n=").unwrap_or(&m.mode)
}

/// `modes 1–8` (or `mode 3`).
fn modes_text(r: &[ModeRatio]) -> String {
    match r {
        [] => "no modes".to_string(),
        [one] => format!("mode {}", mode_label(one)),
        [first, .., last] => format!("modes {}–{}", mode_label(first), mode_label(last)),
    }
}

/// Whether the deviations from 1 grow with the mode number (the list's order): the
/// highest mode off 1 by more than [`Z_HINT`] standard errors and by that much more than
/// the weighted mean of the lower modes (a poorly resolved lowest mode does not hide the
/// growth), no mode significantly (2 s.e.) on the other side of 1, and no mode below its
/// predecessor by more than [`Z_HINT`] standard errors of their difference.
fn grows_with_mode(r: &[ModeRatio]) -> bool {
    let Some((last, lower)) = r.split_last() else {
        return false;
    };
    let Some(below) = RatioPool::of(lower) else {
        return false;
    };
    if r.len() < MIN_MODES || RatioPool::of(r).is_none() {
        return false;
    }
    let sign = (last.ratio - 1.0).signum();
    let dev = |m: &ModeRatio| sign * (m.ratio - 1.0);
    let hyp = |a: &ModeRatio, b: &ModeRatio| a.std_error.hypot(b.std_error);
    dev(last) > Z_HINT * last.std_error
        && dev(last) - sign * (below.mean - 1.0) > Z_HINT * last.std_error.hypot(below.se)
        && r.iter().all(|m| dev(m) > -2.0 * m.std_error)
        && r.windows(2)
            .all(|w| dev(&w[1]) >= dev(&w[0]) - Z_HINT * hyp(&w[0], &w[1]))
}

/// `1.000, 1.002, 1.099, 1.343 over modes 1–4` (the first and last of a long list).
fn ratios_text(r: &[ModeRatio]) -> String {
    let list: Vec<String> = if r.len() <= 8 {
        r.iter().map(|m| format!("{:.3}", m.ratio)).collect()
    } else {
        vec![
            format!("{:.3}", r[0].ratio),
            "…".to_string(),
            format!("{:.3}", r[r.len() - 1].ratio),
        ]
    };
    format!("{} over {}", list.join(", "), modes_text(r))
}

/// The pattern among the per-mode variance ratios `variance` and decay-rate ratios
/// `rate` of one run (each in mode order), stated as a hint with its evidence (see the
/// [module docs](self)); `None` when the ratios are consistent with 1, too few, or show
/// no pattern named here.
///
/// The variances decide first (a linear scheme's stationary variance does not depend on
/// its step when it is exact, so they are the cleaner signature): one factor over the
/// modes, then the rates say which parameter — unchanged (noise amplitude or kT), off by
/// about the inverse factor (stiffness), off by about the same factor (a drag without its
/// noise), otherwise more than one parameter. Variances unchanged with rates off by one
/// factor: the drag or the time unit. Otherwise, deviations that grow with the mode
/// number: mesh or time step.
pub fn diagnose(variance: &[ModeRatio], rate: &[ModeRatio]) -> Option<Hint> {
    let v = RatioPool::of(variance);
    let r = RatioPool::of(rate);
    let hint = |pattern, text: String| {
        Some(Hint {
            pattern,
            text: format!("hint: {text}"),
        })
    };
    if let Some(v) = v.filter(RatioPool::uniformly_off) {
        let over = modes_text(variance);
        let var = format!("uniform variance ratio {} over {over}", v.text());
        let c = 1.0 / v.mean;
        return match r {
            None => hint(
                Pattern::UniformVariance,
                format!("{var} (no decay rates to compare) — noise amplitude, kT or stiffness?"),
            ),
            Some(r) if !r.off_one() => hint(
                Pattern::NoiseAmplitude,
                format!(
                    "{var} with decay rates unchanged (ratio {} over {}) — noise amplitude or kT?",
                    r.text(),
                    modes_text(rate)
                ),
            ),
            Some(r) => {
                let both = format!(
                    "{var} and decay-rate ratio {} over {}",
                    r.text(),
                    modes_text(rate)
                );
                if same_size(v.log(), r.log()) && v.log() * r.log() < 0.0 {
                    hint(
                        Pattern::Stiffness,
                        format!(
                            "{both}, about its inverse — stiffness × {c:.3} (K: EI or a \
                             membrane's κ, variances × 1/c, rates × c; `fit` gives the \
                             parameters)?"
                        ),
                    )
                } else if same_size(v.log(), r.log()) {
                    hint(
                        Pattern::DragWithoutItsNoise,
                        format!(
                            "{both}, about the same — drag × {c:.3} in the deterministic step \
                             with the noise of the true drag (fluctuation–dissipation broken)?"
                        ),
                    )
                } else {
                    hint(
                        Pattern::UniformBoth,
                        format!(
                            "{both}, in no single-parameter relation — more than one of noise \
                             amplitude (kT), stiffness and drag?"
                        ),
                    )
                }
            }
        };
    }
    if let (Some(v), Some(r)) = (v, r)
        && v.unchanged()
        && r.uniformly_off()
    {
        return hint(
            Pattern::DragOrTimeUnit,
            format!(
                "uniform decay-rate ratio {} over {} with variances unchanged (ratio {} over \
                 {}) — drag × {:.3} (its noise following it), or the time unit (dt, \
                 dt_sample)?",
                r.text(),
                modes_text(rate),
                v.text(),
                modes_text(variance),
                1.0 / r.mean
            ),
        );
    }
    let mut grown = Vec::new();
    if grows_with_mode(variance) {
        grown.push(format!("variance {}", ratios_text(variance)));
    }
    if grows_with_mode(rate) {
        grown.push(format!("decay rate {}", ratios_text(rate)));
    }
    if grown.is_empty() {
        return None;
    }
    hint(
        Pattern::GrowingWithMode,
        format!(
            "ratios depart from 1 more at higher modes ({}) — mesh or time step?",
            grown.join("; ")
        ),
    )
}

/// Δχ² by which one membrane explanation of a run's variance ratios must beat every
/// other to be named alone by [`diagnose_membrane`]: a likelihood ratio of e³ ≈ 20
/// between two one-parameter models.
pub const DECISIVE: f64 = 6.0;

/// A one-parameter explanation of a membrane's log variance ratios, ln r_var,n = xₙ·m
/// ([`diagnose_membrane`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Explanation {
    /// xₙ = 1: one factor for every mode (noise amplitude, kT, or K as a whole).
    OneFactor,
    /// xₙ = sₙ, the bending share: κ × e^(−m), σ right.
    Bending,
    /// xₙ = uₙ, the tension sensitivity: σ = σ₀ − m.
    Tension,
}

impl Explanation {
    /// Its name among the alternatives of a hint.
    fn name(self) -> &'static str {
        match self {
            Explanation::OneFactor => "one factor for every mode",
            Explanation::Bending => "κ alone",
            Explanation::Tension => "σ alone",
        }
    }

    /// The regressor xₙ of mode `mode` (its sensitivities `of`); `None` without them.
    fn regressor(self, of: SensitivityOf, mode: &str) -> Option<f64> {
        match self {
            Explanation::OneFactor => Some(1.0),
            Explanation::Bending => of(mode).map(|x| x[0]),
            Explanation::Tension => of(mode).map(|x| x[1]),
        }
    }

    /// The parameter the slope `m` (and its error `se`) of variances (`sign` 1) or rates
    /// (−1) gives: `κ × 1.101 ± 0.002` or `σ = 238.2 ± 1.0`.
    fn parameter(self, m: f64, se: f64, sign: f64, sigma0: f64) -> String {
        match self {
            Explanation::OneFactor => format!("× {:.3} ± {:.3}", (-sign * m).exp(), se),
            Explanation::Bending => {
                let c = (-sign * m).exp();
                format!("κ × {c:.3} ± {:.3}", c * se)
            }
            Explanation::Tension => {
                format!(
                    "σ = {} ± {}",
                    significant(sigma0 - sign * m, 4),
                    significant(se, 2)
                )
            }
        }
    }
}

/// `v` to `digits` significant digits (at most six decimals).
fn significant(v: f64, digits: i32) -> String {
    let decimals = if v == 0.0 || !v.is_finite() {
        0
    } else {
        (digits - 1 - v.abs().log10().floor() as i32).clamp(0, 6) as usize
    };
    format!("{v:.decimals$}")
}

/// The pattern among the per-mode ratios of a linear membrane's run (as [`diagnose`]),
/// whose stated tension is `sigma0` and whose modes' log sensitivities of the stiffness
/// kₙ = κq⁴ + σq² are `of` (sₙ, uₙ; issue #27).
///
/// A membrane's κ and σ act on the modes unequally: to first order ln r_var,n =
/// −sₙ·ln(κ/κ₀) − uₙ·(σ − σ₀), and the rates the inverse, while kT, the noise amplitude
/// or K as a whole scale every mode alike. The log variance ratios are regressed through
/// the origin on each regressor in turn — 1, sₙ (under tension only; at σ₀ = 0 every
/// sₙ = 1) and uₙ ([`Pooled::regressed`]) — and an explanation *fits* when its χ² about
/// the modes has p ≥ [`P_STRUCTURE`] and its slope lies more than [`Z_HINT`] standard
/// errors from 0. κ (or σ) is named when it fits with the smallest χ², every other
/// explanation's χ² is at least [`DECISIVE`] larger, and the rates, regressed on the same
/// regressor, give about the inverse slope ([`same_size`]; or there are none). Otherwise
/// the pattern is [`diagnose`]'s; to its stiffness hints (one factor) a fitting κ or σ
/// within [`DECISIVE`] of the one factor is added as the alternative the variances do not
/// rule out.
pub fn diagnose_membrane(
    variance: &[ModeRatio],
    rate: &[ModeRatio],
    sigma0: f64,
    of: SensitivityOf,
) -> Option<Hint> {
    let general = diagnose(variance, rate);
    let regress = |r: &[ModeRatio], e: Explanation| -> Option<Option<Pooled>> {
        let x: Option<Vec<f64>> = r.iter().map(|m| e.regressor(of, &m.mode)).collect();
        Some(Pooled::regressed(r, Some(&x?)))
    };
    let explanations = [
        Explanation::OneFactor,
        Explanation::Bending,
        Explanation::Tension,
    ];
    let mut fits = Vec::new();
    for e in explanations {
        if e == Explanation::Bending && sigma0 == 0.0 {
            continue;
        }
        let (Some(v), Some(r)) = (regress(variance, e), regress(rate, e)) else {
            return general;
        };
        fits.extend(v.map(|v| (e, v, r)));
    }
    if variance.len() < MIN_MODES {
        return general;
    }
    let fitting = |p: &Pooled| {
        p.p_value.is_some_and(|q| q >= P_STRUCTURE) && p.log_ratio.abs() > Z_HINT * p.std_error
    };
    // The rates about the inverse slope (or none to compare).
    let rates_agree = |v: &Pooled, r: &Option<Pooled>| {
        r.as_ref()
            .is_none_or(|r| same_size(v.log_ratio, -r.log_ratio) && v.log_ratio * r.log_ratio < 0.0)
    };
    let candidates: Vec<&Fit> = fits
        .iter()
        .filter(|(_, v, r)| fitting(v) && rates_agree(v, r))
        .collect();
    let best = candidates
        .iter()
        .min_by(|a, b| a.1.chi2.total_cmp(&b.1.chi2))
        .filter(|best| {
            best.0 != Explanation::OneFactor
                && fits
                    .iter()
                    .all(|(e, v, _)| *e == best.0 || v.chi2 - best.1.chi2 >= DECISIVE)
        });
    match best {
        Some(best) => Some(membrane_hint(best, &fits, variance, rate, sigma0, of)),
        None => general.map(|h| with_alternative(h, &fits, &candidates, sigma0)),
    }
}

/// An explanation with its regression of the variances and, if there are rates, of the
/// rates ([`diagnose_membrane`]).
type Fit = (Explanation, Pooled, Option<Pooled>);

/// [`diagnose`]'s stiffness hint `h` with the membrane explanations among `candidates`
/// (those that fit, their rates agreeing) whose χ² lies within [`DECISIVE`] of one
/// factor's for every mode (in `fits`) added as alternatives; `h` unchanged for other
/// patterns or without one.
fn with_alternative(h: Hint, fits: &[Fit], candidates: &[&Fit], sigma0: f64) -> Hint {
    if !matches!(h.pattern, Pattern::Stiffness | Pattern::UniformVariance) {
        return h;
    }
    let Some((_, one, _)) = fits.iter().find(|f| f.0 == Explanation::OneFactor) else {
        return h;
    };
    let dof = one.modes.len() - 1;
    let alternatives: Vec<String> = candidates
        .iter()
        .filter(|(e, v, _)| *e != Explanation::OneFactor && v.chi2 < one.chi2 + DECISIVE)
        .map(|(e, v, _)| {
            let held = match e {
                Explanation::Bending => format!(" with σ = {sigma0} held"),
                _ => String::new(),
            };
            format!(
                "{}{held}, which fits the variances as well (χ² {:.1} against one factor's \
                 {:.1} on {dof} dof)",
                e.parameter(v.log_ratio, v.std_error, 1.0, sigma0),
                v.chi2,
                one.chi2
            )
        })
        .collect();
    if alternatives.is_empty() {
        return h;
    }
    Hint {
        text: format!("{} Or {}?", h.text, alternatives.join(", or ")),
        ..h
    }
}

/// The hint naming κ or σ alone (`best`, with the other explanations `fits`) for
/// [`diagnose_membrane`].
fn membrane_hint(
    (e, v, r): &Fit,
    fits: &[Fit],
    variance: &[ModeRatio],
    rate: &[ModeRatio],
    sigma0: f64,
    of: SensitivityOf,
) -> Hint {
    let shares: Vec<f64> = variance
        .iter()
        .filter_map(|m| of(&m.mode))
        .map(|x| x[0])
        .collect();
    let (lo, hi) = shares
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| {
            (a.min(s), b.max(s))
        });
    let others: Vec<String> = fits
        .iter()
        .filter(|f| f.0 != *e)
        .map(|(o, p, _)| format!("{}: {:.1}", o.name(), p.chi2))
        .collect();
    let (follow, held, pattern) = match e {
        Explanation::Bending => (
            format!("the modes' bending shares κq⁴/(κq⁴ + σq²) ({lo:.2}–{hi:.2})"),
            format!(" with σ = {sigma0} held"),
            Pattern::BendingRigidity,
        ),
        _ => (
            "the modes' tension sensitivities q²/(κq⁴ + σq²)".to_string(),
            format!(" for the stated {sigma0}"),
            Pattern::Tension,
        ),
    };
    let rates = r
        .as_ref()
        .map_or(" (no decay rates to compare)".to_string(), |r| {
            format!(
                ", and the decay-rate ratios about the inverse ({} over {})",
                e.parameter(r.log_ratio, r.std_error, -1.0, sigma0),
                modes_text(rate)
            )
        });
    let verdict = match e {
        Explanation::Bending => format!(
            "bending rigidity κ × {:.3} (`fit` gives κ, and κ and σ together)?",
            (-v.log_ratio).exp()
        ),
        _ => format!(
            "tension σ ≈ {} rather than {sigma0} (`fit` gives κ and σ together)?",
            significant(sigma0 - v.log_ratio, 4),
        ),
    };
    Hint {
        pattern,
        text: format!(
            "hint: variance ratios {} follow {follow}: {}{held} explains them (χ² {:.1} on {} \
             dof; {}){rates} — {verdict}",
            ratios_text(variance),
            e.parameter(v.log_ratio, v.std_error, 1.0, sigma0),
            v.chi2,
            variance.len() - 1,
            others.join(", "),
        ),
    }
}

/// The per-mode ratios of run `run`'s checks named `check` in `checks`, in their order.
/// A `quadratic-form` check's standard error is the null one (from the reference, at
/// ratio 1); the relative error of a variance is what stays fixed, so it is scaled by the
/// ratio.
pub(crate) fn mode_ratios(checks: &[CheckResult], run: &str, check: &str) -> Vec<ModeRatio> {
    checks
        .iter()
        .filter(|c| c.run == run && c.check == check)
        .filter_map(|c| {
            let (ratio, se) = ratio_of(c)?;
            let se = se?
                * if c.kind == "quadratic-form" {
                    ratio.abs()
                } else {
                    1.0
                };
            Some(ModeRatio::new(c.parameter.clone(), ratio, se))
        })
        .collect()
}

/// The distinct non-empty run names of `runs`, in the order of their first appearance
/// (a scene's checks name their run; a check of the scene names none).
pub(crate) fn first_seen<'a>(runs: impl IntoIterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for run in runs {
        if !run.is_empty() && !out.contains(&run) {
            out.push(run);
        }
    }
    out
}

/// The hint of every run of `scene` with a failed check, in the order of their first
/// failure: [`diagnose`] on its `mode-variance` and `decay-rate` checks (passed and
/// failed: a pattern needs every mode), or for a linear membrane, whose tension σ₀ and
/// modes' sensitivities `membrane` gives, [`diagnose_membrane`].
pub fn run_hints(scene: &SceneSummary, membrane: Option<(f64, SensitivityOf)>) -> Vec<RunHint> {
    first_seen(
        scene
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.run.as_str()),
    )
    .into_iter()
    .filter_map(|run| {
        let v = mode_ratios(&scene.checks, run, "mode-variance");
        let r = mode_ratios(&scene.checks, run, "decay-rate");
        let hint = match membrane {
            Some((sigma, of)) => diagnose_membrane(&v, &r, sigma, of),
            None => diagnose(&v, &r),
        }?;
        Some(RunHint {
            run: run.to_string(),
            pattern: hint.pattern,
            text: hint.text,
        })
    })
    .collect()
}

/// The power at which [`detectable_deviations`] states the smallest detectable error.
pub const POWER: f64 = 0.8;

/// The checks a detectable deviation is stated for, with what an error of their
/// observable is called: per-mode variance and decay rate, the profile's variance and a
/// compression run's mean force.
pub const DETECTABLE: [(&str, &str); 4] = [
    ("mode-variance", "variance"),
    ("decay-rate", "rate"),
    ("profile", "profile variance"),
    ("force", "mean force"),
];

/// The smallest relative error of one observable of one run that its checks would have
/// detected at the scene's α with probability [`POWER`] (issue #31: what a pass could
/// have missed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Detectable {
    /// The run.
    pub run: String,
    /// The observable, as [`DETECTABLE`] names it (`variance`, `rate`, …).
    pub observable: String,
    /// The smallest relative deviation |estimate/reference − 1| detected with
    /// probability [`POWER`].
    pub deviation: f64,
    /// The check that would detect it (the run's most precise of the observable).
    pub check: String,
}

/// The relative deviation one statistical check detects with probability [`POWER`] at
/// the scene's family-wise level `alpha` over `family` checks: under Holm the first
/// step, at α/m, is the strictest, so δ = (q(1 − α/(2m)) + q(POWER))·s.e./|reference|
/// for a two-sided test whose statistic is normal — or Student's t of the check's
/// degrees of freedom for a t-test — about (estimate − reference)/s.e. An upper bound
/// for the check's own detection threshold (Holm's later steps are more lenient, and an
/// error of one factor over modes moves every mode's check). `None` where the check has
/// no ratio ([`ratio_of`]) or no standard error.
pub fn detectable_deviation(c: &CheckResult, alpha: f64, family: usize) -> Option<f64> {
    let (se, dof) = relative_error_and_dof(c)?;
    Some(detectable_shift(alpha / family.max(1) as f64, dof)? * se)
}

/// A check's relative standard error s.e./|reference| (positive; [`ratio_of`]) and, for
/// a t-test, its degrees of freedom.
fn relative_error_and_dof(c: &CheckResult) -> Option<(f64, Option<f64>)> {
    let (_, se) = ratio_of(c)?;
    let se = se.filter(|s| s.is_finite() && *s > 0.0)?;
    let dof = c
        .dof
        .filter(|d| c.kind.ends_with("t-test") && d.is_finite() && *d > 0.0);
    Some((se, dof))
}

/// Points of the midpoint rule over the χ² law in [`detectable_shift`].
const CHI_POINTS: usize = 2000;

/// The shift λ of the mean of a two-sided test's statistic at which it rejects at
/// level `level` with probability [`POWER`]: for a normal statistic
/// λ = z(1 − level/2) + z(POWER) (exact but for the far tail, below 1e-9 here); for
/// Student's t of `dof` degrees of freedom, the noncentrality of the noncentral t,
/// T = (Z + λ)/S, S² = χ²_ν/ν, whose power
/// P(λ) = E_S[Φ(λ − t_c S) + Φ(−λ − t_c S)], t_c = t_ν(1 − level/2), is averaged over S by
/// the midpoint rule in probability ([`CHI_POINTS`] quantiles of χ²_ν) and solved for
/// P(λ) = POWER by bisection. (The sum of the two t quantiles would understate λ: at
/// ν = 7 its power is 0.74, not 0.8.) `None` for an invalid level or dof.
pub fn detectable_shift(level: f64, dof: Option<f64>) -> Option<f64> {
    if !(level > 0.0 && level < 1.0) {
        return None;
    }
    let n = Normal::standard();
    let Some(nu) = dof else {
        return Some(n.inverse_cdf(1.0 - level / 2.0) + n.inverse_cdf(POWER));
    };
    let t = StudentsT::new(0.0, 1.0, nu).ok()?;
    let tc = t.inverse_cdf(1.0 - level / 2.0);
    let chi = ChiSquared::new(nu).ok()?;
    let s: Vec<f64> = (0..CHI_POINTS)
        .map(|k| (chi.inverse_cdf((k as f64 + 0.5) / CHI_POINTS as f64) / nu).sqrt())
        .collect();
    let power = |lam: f64| {
        s.iter()
            .map(|&s| n.cdf(lam - tc * s) + n.cdf(-lam - tc * s))
            .sum::<f64>()
            / CHI_POINTS as f64
    };
    let (mut lo, mut hi) = (0.0, tc + 10.0);
    while power(hi) < POWER {
        hi *= 2.0;
        if hi > 1e6 {
            return None;
        }
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if power(mid) < POWER {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Per run and observable of `scene` ([`DETECTABLE`]), the smallest relative error its
/// checks would have detected at the family-wise level `alpha` with probability
/// [`POWER`] ([`detectable_deviation`], the family being the scene's statistical
/// checks), minimized over the observable's checks in the run (its modes, points or
/// strains): a pass says "no error this large". Runs in the order of their first check.
pub fn detectable_deviations(scene: &SceneSummary, alpha: f64) -> Vec<Detectable> {
    let family = scene.checks.iter().filter(|c| c.p_value.is_some()).count();
    // The shift depends on the test's dof only: one solve per dof.
    let mut shifts: Vec<(Option<u64>, Option<f64>)> = Vec::new();
    let mut deviation = |c: &CheckResult| -> Option<f64> {
        let (se, dof) = relative_error_and_dof(c)?;
        let key = dof.map(f64::to_bits);
        let shift = match shifts.iter().find(|(k, _)| *k == key) {
            Some((_, v)) => *v,
            None => {
                let v = detectable_shift(alpha / family.max(1) as f64, dof);
                shifts.push((key, v));
                v
            }
        };
        Some(shift? * se)
    };
    let mut out = Vec::new();
    for run in first_seen(scene.checks.iter().map(|c| c.run.as_str())) {
        for (check, observable) in DETECTABLE {
            let best = scene
                .checks
                .iter()
                .filter(|c| c.run == run && c.check == check)
                .filter_map(|c| Some((deviation(c)?, c)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((deviation, c)) = best {
                out.push(Detectable {
                    run: run.to_string(),
                    observable: observable.to_string(),
                    deviation,
                    check: c.name.clone(),
                });
            }
        }
    }
    out
}

/// `would have caught a variance error ≥ 1.8 % (n=6), a rate error ≥ 4.0 % (n=5) (80 %
/// power)` for the statements `run` of one run (each observable's parameter in
/// brackets; the power at the scene's α, Holm, as [`detectable_deviation`]).
pub fn detectable_text(run: &[&Detectable]) -> String {
    let parts: Vec<String> = run
        .iter()
        .map(|d| {
            let pct = 100.0 * d.deviation;
            let v = if pct >= 10.0 {
                format!("{pct:.0}")
            } else if pct >= 1.0 {
                format!("{pct:.1}")
            } else {
                format!("{pct:.2}")
            };
            let at = d.check.rsplit('/').next().unwrap_or_default();
            format!("a {} error ≥ {v} % ({at})", d.observable)
        })
        .collect();
    format!("would have caught {} (80 % power)", parts.join(", "))
}

/// The scene-wide statement of `all`: per observable the smallest deviation over the
/// runs, naming its run — `would have caught a variance error ≥ 0.84 % (crank-nicolson,
/// n=6), … (80 % power)` — for `verify`'s line under a passing scene; `None` if there is
/// none.
pub fn scene_detectable_text(all: &[Detectable]) -> Option<String> {
    let best: Vec<Detectable> = DETECTABLE
        .iter()
        .filter_map(|(_, observable)| {
            all.iter()
                .filter(|d| d.observable == *observable)
                .min_by(|a, b| a.deviation.total_cmp(&b.deviation))
                .map(|d| Detectable {
                    check: format!("{}, {}", d.run, d.check.rsplit('/').next().unwrap_or("")),
                    ..d.clone()
                })
        })
        .collect();
    (!best.is_empty()).then(|| detectable_text(&best.iter().collect::<Vec<_>>()))
}

/// The statements of `all` grouped by run, in order: (run, [`detectable_text`]).
pub fn detectable_lines(all: &[Detectable]) -> Vec<(String, String)> {
    first_seen(all.iter().map(|d| d.run.as_str()))
        .into_iter()
        .map(|run| {
            let of: Vec<&Detectable> = all.iter().filter(|d| d.run == run).collect();
            (run.to_string(), detectable_text(&of))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::trajectory_rng;
    use rand_distr::{Distribution, StandardNormal};

    /// The detectable shift has the power it claims: for a normal statistic exactly
    /// (Φ, 1e-6); for Student's t at 7 and 30 dof by simulation of the noncentral t
    /// (40 000 draws, power within 0.8 ± 0.01, 4.5 standard errors), where the naive sum
    /// of the two t quantiles (power 0.74 at 7 dof) fails the same band. Levels as a
    /// scene's Holm first step, α/m = 0.01/15.
    #[test]
    fn detectable_shift_has_its_power() {
        let n = Normal::standard();
        let level = 0.01 / 15.0;
        let lam = detectable_shift(level, None).unwrap();
        let zc = n.inverse_cdf(1.0 - level / 2.0);
        let power = n.cdf(lam - zc) + n.cdf(-lam - zc);
        assert!((power - POWER).abs() < 1e-6, "{power}");
        let mut rng = trajectory_rng(20261204, 31);
        for nu in [7.0, 30.0] {
            let t = StudentsT::new(0.0, 1.0, nu).unwrap();
            let tc = t.inverse_cdf(1.0 - level / 2.0);
            let naive = tc + t.inverse_cdf(POWER);
            let lam = detectable_shift(level, Some(nu)).unwrap();
            let mut simulate = |shift: f64| {
                let draws = 40_000;
                let mut hits = 0;
                for _ in 0..draws {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    let chi: f64 = (0..nu as usize)
                        .map(|_| {
                            let g: f64 = StandardNormal.sample(&mut rng);
                            g * g
                        })
                        .sum();
                    if ((z + shift) / (chi / nu).sqrt()).abs() > tc {
                        hits += 1;
                    }
                }
                hits as f64 / draws as f64
            };
            let p = simulate(lam);
            assert!((p - POWER).abs() < 0.01, "dof {nu}: power {p} at {lam}");
            if nu == 7.0 {
                let p = simulate(naive);
                assert!((p - POWER).abs() > 0.01, "naive sum {naive}: power {p}");
            }
        }
        assert!(detectable_shift(0.0, None).is_none());
    }

    /// The statement per run: the most precise check of each observable, in the run's
    /// order; a check without a standard error or a reference says nothing.
    #[test]
    fn detectable_deviations_take_each_runs_most_precise_check() {
        let check = |name: &str, se: Option<f64>| {
            let parts: Vec<&str> = name.split('/').collect();
            CheckResult {
                name: name.to_string(),
                run: parts[0].to_string(),
                check: parts[1].to_string(),
                parameter: parts[2].to_string(),
                kind: "z-test".to_string(),
                statistic: Some(0.1),
                dof: None,
                passed: true,
                p_value: Some(0.9),
                p_adjusted: Some(1.0),
                estimate: Some(2.0),
                reference: Some(2.0),
                std_error: se,
                continuum: None,
                reference_kind: "discrete".to_string(),
                unit: String::new(),
                detail: String::new(),
                largest_deviation: None,
                variance_correlation: None,
            }
        };
        let scene = SceneSummary::of_checks(
            "s",
            vec![
                check("a/mode-variance/n=1", Some(0.2)),
                check("a/mode-variance/n=2", Some(0.02)),
                check("a/decay-rate/n=2", Some(0.1)),
                check("a/decay-rate/n=3", None),
                check("b/mode-variance/n=1", Some(0.04)),
            ],
        );
        let d = detectable_deviations(&scene, 0.01);
        let lam = detectable_shift(0.01 / 5.0, None).unwrap();
        let got: Vec<(&str, &str, &str)> = d
            .iter()
            .map(|d| (d.run.as_str(), d.observable.as_str(), d.check.as_str()))
            .collect();
        assert_eq!(
            got,
            [
                ("a", "variance", "a/mode-variance/n=2"),
                ("a", "rate", "a/decay-rate/n=2"),
                ("b", "variance", "b/mode-variance/n=1")
            ]
        );
        assert!((d[0].deviation - lam * 0.01).abs() < 1e-12);
        // Scene-wide (verify's line): per observable the most sensitive run, named.
        let scene_line = scene_detectable_text(&d).unwrap();
        assert!(
            scene_line.starts_with(
                "would have caught a variance error ≥ 3.9 % (a, n=2), a rate error ≥ 20 % (a, n=2)"
            ),
            "{scene_line}"
        );
        assert!(scene_detectable_text(&[]).is_none());
        let lines = detectable_lines(&d);
        assert_eq!(lines.len(), 2);
        assert!(
            lines[0].1.starts_with(
                "would have caught a variance error ≥ 3.9 % (n=2), a rate error ≥ 20 % (n=2)"
            ),
            "{}",
            lines[0].1
        );
    }

    /// Ratios `values` with standard error `se` each, modes 1, 2, ….
    fn ratios(values: &[f64], se: f64) -> Vec<ModeRatio> {
        values
            .iter()
            .enumerate()
            .map(|(i, &v)| ModeRatio::new(format!("n={}", i + 1), v, se))
            .collect()
    }

    fn pattern(v: &[ModeRatio], r: &[ModeRatio]) -> Option<Pattern> {
        diagnose(v, r).map(|h| h.pattern)
    }

    /// A noise amplitude (or kT) error: every variance × 1.10 within its error, the rates
    /// at 1 within theirs; the hint names the ratio, the modes and the unchanged rates.
    #[test]
    fn a_uniform_variance_ratio_with_rates_unchanged_hints_at_the_noise() {
        let v = ratios(
            &[1.104, 1.097, 1.101, 1.093, 1.108, 1.099, 1.102, 1.096],
            0.005,
        );
        let r = ratios(&[1.01, 0.99, 1.02, 0.995, 1.0, 0.985], 0.015);
        let h = diagnose(&v, &r).unwrap();
        assert_eq!(h.pattern, Pattern::NoiseAmplitude);
        assert!(
            h.text
                .starts_with("hint: uniform variance ratio 1.100 ± 0.002 over modes 1–8")
                && h.text.contains("decay rates unchanged (ratio 1.00")
                && h.text.ends_with("noise amplitude or kT?"),
            "{}",
            h.text
        );
        // Without decay rates the stiffness cannot be told apart.
        assert_eq!(pattern(&v, &[]), Some(Pattern::UniformVariance));
    }

    /// A stiffness error K × 1.05: variances × 1/1.05, rates × 1.05; a drag error of the
    /// deterministic step alone (ξ × 1.1, the noise of the true ξ): both × 1/1.1; a drag
    /// with its noise, or a wrong time unit: rates × 1/1.1 with variances unchanged.
    #[test]
    fn variance_and_rate_ratios_together_hint_at_stiffness_or_drag() {
        let v = ratios(&[0.953, 0.951, 0.954, 0.950, 0.952, 0.953], 0.003);
        let r = ratios(&[1.046, 1.055, 1.050, 1.052, 1.049], 0.006);
        let h = diagnose(&v, &r).unwrap();
        assert_eq!(h.pattern, Pattern::Stiffness, "{}", h.text);
        assert!(h.text.contains("stiffness × 1.050"), "{}", h.text);
        let v = ratios(&[0.909, 0.911, 0.907, 0.910, 0.908], 0.003);
        let r = ratios(&[0.905, 0.913, 0.909, 0.910, 0.908], 0.006);
        let h = diagnose(&v, &r).unwrap();
        assert_eq!(h.pattern, Pattern::DragWithoutItsNoise, "{}", h.text);
        assert!(h.text.contains("drag × 1.10"), "{}", h.text);
        let v = ratios(&[1.002, 0.998, 1.001, 0.999, 1.003], 0.003);
        let h = diagnose(&v, &r).unwrap();
        assert_eq!(h.pattern, Pattern::DragOrTimeUnit, "{}", h.text);
        assert!(h.text.contains("time unit"), "{}", h.text);
        // Crank–Nicolson's rates at large λΔt are not proportional to the stiffness: the
        // integrator's K × 1.05 in hinged-linear-3d gave these (quick budget), still a
        // stiffness.
        let v = ratios(&[0.979, 0.940, 0.954, 0.954, 0.953, 0.953], 0.002);
        let mut r = ratios(&[0.982, 1.045, 1.048, 1.049, 1.054, 1.079], 0.0026);
        r[0].std_error = 0.072;
        r[1].std_error = 0.016;
        let mut v = v;
        v[0].std_error = 0.04;
        v[1].std_error = 0.0097;
        assert_eq!(pattern(&v, &r), Some(Pattern::Stiffness));
        // Variances × 1.1 and rates × 1.2: no one parameter does that.
        let v = ratios(&[1.101, 1.099, 1.1, 1.102, 1.098], 0.003);
        let r = ratios(&[1.2, 1.205, 1.195, 1.2, 1.198], 0.006);
        assert_eq!(pattern(&v, &r), Some(Pattern::UniformBoth));
    }

    /// A time-step error (Euler–Maruyama's 1/(1 − λΔt/2), λₙ ∝ n⁴): variances and rates
    /// depart from 1 more at higher modes; the evidence lists the ratios.
    #[test]
    fn deviations_growing_with_mode_number_hint_at_mesh_or_time_step() {
        let v = ratios(&[1.001, 1.008, 1.044, 1.149], 0.01);
        let r = ratios(&[1.003, 1.02, 1.09, 1.38], 0.02);
        let h = diagnose(&v, &r).unwrap();
        assert_eq!(h.pattern, Pattern::GrowingWithMode);
        assert!(
            h.text
                .contains("variance 1.001, 1.008, 1.044, 1.149 over modes 1–4")
                && h.text.contains("decay rate 1.003")
                && h.text.ends_with("mesh or time step?"),
            "{}",
            h.text
        );
        // A coarse mesh: eigenvalues too large, variances falling below 1 with n.
        let v = ratios(&[0.999, 0.99, 0.96, 0.9, 0.82, 0.73], 0.01);
        assert_eq!(pattern(&v, &[]), Some(Pattern::GrowingWithMode));
        // A poorly resolved lowest mode (short data) does not hide the growth.
        let mut v = ratios(&[1.29, 1.073, 1.099, 1.344], 0.01);
        v[0].std_error = 0.15;
        v[1].std_error = 0.03;
        assert_eq!(pattern(&v, &[]), Some(Pattern::GrowingWithMode));
    }

    /// No hint for ratios consistent with 1, for too few modes, or for an unstructured
    /// pattern (deviations of both signs, or up and down with the mode number).
    #[test]
    fn no_hint_without_a_pattern() {
        let one = ratios(&[1.004, 0.995, 1.01, 0.99, 1.002, 0.998], 0.008);
        let rates = ratios(&[0.99, 1.01, 1.0, 1.02], 0.015);
        assert_eq!(pattern(&one, &rates), None);
        assert_eq!(pattern(&one, &[]), None);
        assert_eq!(pattern(&[], &[]), None);
        let two = ratios(&[1.1, 1.1], 0.002);
        assert_eq!(pattern(&two, &[]), None);
        for unstructured in [
            vec![1.0, 1.2, 0.9, 1.15, 0.85, 1.1],
            vec![1.0, 1.2, 1.02, 1.18, 1.01, 1.2],
            vec![1.15, 1.0, 1.05, 0.92, 1.2],
        ] {
            let v = ratios(&unstructured, 0.01);
            assert_eq!(pattern(&v, &rates), None, "{unstructured:?}");
        }
        // A bad standard error gives no pattern, and no panic.
        let bad = vec![
            ModeRatio::new("n=1", 1.1, 0.0),
            ModeRatio::new("n=2", f64::NAN, 0.1),
        ];
        assert_eq!(pattern(&bad, &bad), None);
    }

    /// A periodic unit-square membrane, κ = ξ = kT = 1, at tension `sigma`.
    fn membrane(sigma: f64) -> Membrane {
        use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
        Membrane::new(MembraneParams {
            tension: sigma,
            boundary: MembraneBoundary::Periodic,
            ..MembraneParams::default()
        })
        .unwrap()
    }

    /// The variance and decay-rate ratios of modes 1–24 of `m` (stated κ₀ = 1, σ₀) for
    /// data of κ = `kappa`, σ = `sigma`, noise variance × `noise`: the exact
    /// r_var = noise·k(κ₀, σ₀)/k(κ, σ) and r_rate = k(κ, σ)/k(κ₀, σ₀), each scattered by a
    /// fixed pattern within ±1 of its relative errors `se` (variances, rates).
    fn membrane_ratios(
        m: &Membrane,
        (kappa, sigma, noise): (f64, f64, f64),
        se: (f64, f64),
    ) -> (Vec<ModeRatio>, Vec<ModeRatio>) {
        let modes = m.modes(24).unwrap();
        let p = m.params;
        let (mut v, mut r) = (Vec::new(), Vec::new());
        for (k, &mode) in modes.iter().enumerate() {
            let q2 = m.wavenumber_sq(mode);
            let k0 = p.bending_rigidity * q2 * q2 + p.tension * q2;
            let k1 = kappa * q2 * q2 + sigma * q2;
            let z = ((k * 37) % 11) as f64 / 5.0 - 1.0;
            let (rv, rr) = (
                noise * k0 / k1 * (z * se.0).exp(),
                k1 / k0 * (-z * se.1).exp(),
            );
            v.push(ModeRatio::new(format!("n={}", k + 1), rv, se.0 * rv));
            r.push(ModeRatio::new(format!("n={}", k + 1), rr, se.1 * rr));
        }
        (v, r)
    }

    /// **A membrane's κ and σ are told apart by the modes' shares** (issue #27). Under
    /// σ₀ = 200 (bending shares 0.16–0.61): κ × 1.1 is named κ (the filament's one-factor
    /// diagnosis takes it for a mesh or time-step error); σ = 240 is named the tension,
    /// with σ ≈ 240 (the one-factor diagnosis finds no pattern); a noise amplitude × 1.05
    /// and K as a whole × 1.05 keep their one-factor hints, with no alternative.
    #[test]
    fn a_membranes_bending_rigidity_and_tension_are_told_apart_by_their_shares() {
        let m = membrane(200.0);
        let of = |mode: &str| membrane_sensitivities(&m, mode);
        let se = (0.004, 0.006);
        let (v, r) = membrane_ratios(&m, (1.1, 200.0, 1.0), se);
        let h = diagnose_membrane(&v, &r, 200.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::BendingRigidity, "{}", h.text);
        assert!(
            h.text.contains("(0.16–0.61)")
                && h.text.contains("bending rigidity κ × 1.10")
                && h.text.ends_with('?'),
            "{}",
            h.text
        );
        let filament = diagnose(&v, &r).unwrap();
        assert_eq!(
            filament.pattern,
            Pattern::GrowingWithMode,
            "{}",
            filament.text
        );

        let (v, r) = membrane_ratios(&m, (1.0, 240.0, 1.0), se);
        let h = diagnose_membrane(&v, &r, 200.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::Tension, "{}", h.text);
        let sigma: f64 = h.text.split("tension σ ≈ ").nth(1).unwrap()[..5]
            .parse()
            .unwrap();
        assert!((sigma / 240.0 - 1.0).abs() < 0.02, "{}", h.text);
        assert!(h.text.contains("rather than 200"), "{}", h.text);
        assert!(!matches!(diagnose(&v, &r), Some(h) if h.pattern == Pattern::Tension));

        let (v, r) = membrane_ratios(&m, (1.0, 200.0, 1.05), se);
        let h = diagnose_membrane(&v, &r, 200.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::NoiseAmplitude, "{}", h.text);
        let (v, r) = membrane_ratios(&m, (1.05, 210.0, 1.0), se);
        let h = diagnose_membrane(&v, &r, 200.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::Stiffness, "{}", h.text);
        assert!(!h.text.contains(" Or "), "{}", h.text);
    }

    /// At a stated σ₀ = 0 a tension σ = 3 in the data (variances low at the slow modes,
    /// near 1 at the fast ones) is named, σ ≈ 3; the one-factor diagnosis names nothing.
    #[test]
    fn a_tension_the_data_have_but_the_sidecar_does_not_is_named() {
        let m = membrane(0.0);
        let of = |mode: &str| membrane_sensitivities(&m, mode);
        let (v, r) = membrane_ratios(&m, (1.0, 3.0, 1.0), (0.004, 0.006));
        let h = diagnose_membrane(&v, &r, 0.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::Tension, "{}", h.text);
        assert!(h.text.contains("rather than 0 "), "{}", h.text);
        let sigma: f64 = h.text.split("tension σ ≈ ").nth(1).unwrap()[..4]
            .parse()
            .unwrap();
        assert!((sigma - 3.0).abs() < 0.3, "{}", h.text);
        assert_eq!(diagnose(&v, &r), None);
    }

    /// Where the shares vary too little for the data to tell κ alone from one factor (σ₀
    /// = 20, errors 2 %), the one-factor stiffness hint stands, with κ alone added as the
    /// alternative that fits as well; a mode without sensitivities gives the one-factor
    /// diagnosis unchanged.
    #[test]
    fn explanations_the_data_do_not_separate_are_both_stated() {
        let m = membrane(20.0);
        let of = |mode: &str| membrane_sensitivities(&m, mode);
        let (v, r) = membrane_ratios(&m, (1.1, 20.0, 1.0), (0.02, 0.03));
        let h = diagnose_membrane(&v, &r, 20.0, &of).unwrap();
        assert_eq!(h.pattern, Pattern::Stiffness, "{}", h.text);
        assert!(
            h.text.contains(" Or κ × 1.1") && h.text.contains("with σ = 20 held, which fits"),
            "{}",
            h.text
        );
        let partial = |mode: &str| (mode != "n=3").then(|| of(mode)).flatten();
        assert_eq!(diagnose_membrane(&v, &r, 20.0, &partial), diagnose(&v, &r));
    }

    /// The ratio of a check: estimate/reference with the error over |reference|; none for
    /// a deterministic check, one against 0, or an unresolved reference.
    #[test]
    fn a_ratio_only_where_it_means_something() {
        let outcome = crate::stats::TestOutcome {
            statistic: 3.3,
            p_value: 1e-3,
            dof: None,
        };
        let c = |values| {
            CheckResult::statistical(
                "r/x/n=1".into(),
                "z-test",
                values,
                None,
                &outcome,
                String::new(),
            )
        };
        let (r, se) = ratio_of(&c((1.1, 1.0, 0.03))).unwrap();
        assert!((r - 1.1).abs() < 1e-12 && (se.unwrap() - 0.03).abs() < 1e-12);
        assert_eq!(ratio_text(r, se), "ratio 1.100 ± 0.030");
        assert_eq!(ratio_text(2.5e-4, None), "ratio 2.50e-4");
        assert!(ratio_of(&c((0.1, 0.0, 0.03))).is_none());
        assert!(ratio_of(&c((0.1, 0.02, 0.03))).is_none());
        assert!(ratio_of(&c((f64::NAN, 1.0, 0.03))).is_none());
        let mut det = c((1.1, 1.0, 0.03));
        det.p_value = None;
        assert!(ratio_of(&det).is_none());
    }
}
