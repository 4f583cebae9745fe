//! How far the verifier itself can be trusted under a correct simulator: the statistics
//! behind `langevin-fem calibrate` (issue #16).
//!
//! `calibrate` runs each scene's verification at N seeds, k = 0 … N−1. Two things are
//! measured from the results, and both are pure functions here:
//!
//! 1. **The false-alarm rate per scene.** Each seed's verification fails the scene if any
//!    check is rejected after the Holm correction at the family-wise level α, or if the
//!    run fails (an estimator that finds no answer in the data). A correct simulator
//!    fails a scene with probability at most α (Holm controls the family-wise error rate
//!    under any dependence, if every p-value is valid), so the number of failed seeds
//!    k out of N is at most Binomial(N, α) in distribution. Reported: the rate k/N, its
//!    exact two-sided Clopper–Pearson interval ([`clopper_pearson`]) and the one-sided
//!    exact binomial test of "rate ≤ α", p = P(X ≥ k | N, α) ([`binomial_tail_p`]).
//!    **Rule** ([`false_alarms`]): the scene is *consistent with α* unless the whole
//!    interval lies above α (lower bound > α). A rate well below α is fine: Holm is
//!    conservative.
//! 2. **The uniformity of the p-values.** Under a correct simulator the raw p-value of a
//!    check with an exact null distribution is U(0, 1). The p-values of *one* check (one
//!    scene, one name) over the seeds are independent; the p-values of different checks
//!    of one seed are not (they share the trajectories). So each check's N p-values are
//!    tested against U(0, 1) with the one-sample Kolmogorov–Smirnov test
//!    ([`crate::stats::ks_test`]), and per check kind (`CheckResult::kind`: `z-test`,
//!    `chi2-variance`, `ks`, …) the KS p-values of its checks, over every calibrated
//!    scene, are Holm-adjusted. **Rule** ([`uniformity_by_kind`]): a kind is *rejected*
//!    if any of its checks has a Holm-adjusted KS p-value below [`UNIFORMITY_LEVEL`]
//!    (0.01). Beside it, per kind, the pooled fraction of raw p-values below 0.05 and
//!    0.01 ([`TailFraction`]) shows heavy tails directly (a z-test whose standard error
//!    is estimated low from short series gives too many small p-values).
//!
//! Discrete p-values are handled: ties and p = 1 exactly are valid KS input (the test
//! is then conservative); a check without a p-value (a deterministic check) or whose
//! p-value is the same at every seed is not a random check and is listed as not tested
//! ([`UniformityStatus`]), as is an interval test against a tolerance band (kinds
//! `band-…`, p = 1 inside the band: conservative, not uniform by design); a check with fewer than two p-values (seeds whose run failed
//! have none) cannot be tested either.
//!
//! ## References
//! - C. J. Clopper, E. S. Pearson, *The use of confidence or fiducial limits illustrated
//!   in the case of the binomial*, Biometrika 26, 404 (1934).
//! - S. Holm, *A simple sequentially rejective multiple test procedure*, Scand. J. Stat.
//!   6, 65 (1979).
//! - The SBML discrete stochastic models test suite (DSMTS), which states how often a
//!   correct simulator fails it: the model for reporting the verifier's own error rates.

use crate::error::{Error, Result};
use crate::output::io::{CsvWriter, csv_number};
use crate::output::{Figure, Series};
use crate::stats;
use serde::{Deserialize, Serialize};
use statrs::distribution::{Beta, Binomial, ContinuousCDF, DiscreteCDF};
use std::collections::BTreeMap;
use std::path::Path;

/// File name of the journal of a calibration report ([`crate::output::manifest`]).
pub const MANIFEST: &str = "manifest.json";
/// The entry points of a calibration report, in the order they are written, last.
pub const ENTRY_POINTS: [&str; 2] = ["calibration.json", "index.html"];
/// The table of every check's p-values at every seed.
pub const P_VALUES_CSV: &str = "p-values.csv";

/// Confidence level of the false-alarm rate's interval.
pub const CONFIDENCE: f64 = 0.95;

/// Level at which a check kind's uniformity is rejected (Holm-adjusted KS p-value below
/// it).
pub const UNIFORMITY_LEVEL: f64 = 0.01;

/// The levels at which the pooled fraction of small raw p-values is reported.
pub const TAIL_LEVELS: [f64; 2] = [0.05, 0.01];

/// Bins of the p-value histograms.
pub const HISTOGRAM_BINS: usize = 20;

/// The rule by which a scene's false-alarm rate is judged, as stated in the outputs.
pub const FALSE_ALARM_RULE: &str = "a scene fails a seed if any check is rejected after the Holm correction at alpha, or if its run fails; the rate k/N of failed seeds is consistent with alpha unless the whole exact (Clopper-Pearson) 95 % interval lies above alpha; binomial_p is the one-sided exact test of rate <= alpha, P(X >= k | N, alpha)";

/// The rule by which a check kind's p-values are judged, as stated in the outputs.
pub const UNIFORMITY_RULE: &str = "per check (one scene, one name) a one-sample Kolmogorov-Smirnov test of its raw p-values over the seeds against U(0,1); per kind, Holm over the KS p-values of its checks in every calibrated scene; a kind is rejected if any Holm-adjusted KS p-value is below 0.01. Checks without a p-value, with the same p-value at every seed, with fewer than 2 p-values, or interval tests against a tolerance band (kinds band-*, p = 1 inside the band: conservative, not uniform by design) are not tested";

/// The exact (Clopper–Pearson) two-sided interval for a binomial proportion: `k`
/// successes in `n` trials at `confidence` (e.g. 0.95). With a = 1 − confidence,
/// lower = B⁻¹(a/2; k, n−k+1) (0 for k = 0), upper = B⁻¹(1−a/2; k+1, n−k) (1 for
/// k = n), B⁻¹ the inverse CDF of the Beta law (`statrs`). Each side covers with
/// probability at least 1 − a/2.
///
/// # Errors
/// [`Error::InvalidParameter`] for `n` = 0, `k` > `n`, or `confidence` outside (0, 1).
pub fn clopper_pearson(k: u64, n: u64, confidence: f64) -> Result<[f64; 2]> {
    check_counts(k, n)?;
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::invalid("confidence", confidence, "in (0, 1)"));
    }
    let a = 1.0 - confidence;
    let beta = |x: u64, y: u64| {
        Beta::new(x as f64, y as f64).map_err(|e| Error::Numerical {
            routine: "Beta distribution (Clopper-Pearson interval)".into(),
            detail: e.to_string(),
        })
    };
    let lower = if k == 0 {
        0.0
    } else {
        beta(k, n - k + 1)?.inverse_cdf(a / 2.0)
    };
    let upper = if k == n {
        1.0
    } else {
        beta(k + 1, n - k)?.inverse_cdf(1.0 - a / 2.0)
    };
    Ok([lower, upper])
}

/// The one-sided exact binomial test of "success probability ≤ `p0`" after `k`
/// successes in `n` trials: p = P(X ≥ k) for X ~ Binomial(n, p0) (1 for k = 0), as R's
/// `binom.test(k, n, p0, alternative = "greater")`.
///
/// # Errors
/// [`Error::InvalidParameter`] for `n` = 0, `k` > `n`, or `p0` outside [0, 1].
pub fn binomial_tail_p(k: u64, n: u64, p0: f64) -> Result<f64> {
    check_counts(k, n)?;
    if !(0.0..=1.0).contains(&p0) {
        return Err(Error::invalid("p0", p0, "in [0, 1]"));
    }
    if k == 0 {
        return Ok(1.0);
    }
    let law = Binomial::new(p0, n).map_err(|e| Error::Numerical {
        routine: "Binomial distribution".into(),
        detail: e.to_string(),
    })?;
    // sf(x) = P(X > x).
    Ok(law.sf(k - 1).clamp(0.0, 1.0))
}

fn check_counts(k: u64, n: u64) -> Result<()> {
    if n == 0 {
        return Err(Error::invalid("n", n, "at least 1 trial"));
    }
    if k > n {
        return Err(Error::invalid("k", k, format!("at most n = {n}")));
    }
    Ok(())
}

/// A scene's false-alarm rate over the seeds (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FalseAlarms {
    /// Seeds run (N).
    pub seeds: u64,
    /// Seeds at which the scene failed (k): a check rejected, or the run failed.
    pub failed: u64,
    /// Of those, the seeds whose run failed (no checks), reported separately.
    pub run_failures: u64,
    /// k / N.
    pub rate: f64,
    /// The exact (Clopper–Pearson) interval of the rate at [`Self::confidence`].
    pub interval: [f64; 2],
    /// The interval's confidence level.
    pub confidence: f64,
    /// The family-wise level α of each scene's verification.
    pub alpha: f64,
    /// One-sided exact binomial test of "rate ≤ α": P(X ≥ k | N, α).
    pub binomial_p: f64,
    /// Consistent with α: the interval's lower bound is not above α ([`FALSE_ALARM_RULE`]).
    pub consistent: bool,
}

/// The false-alarm rate of a scene that failed `failed` of `seeds` seeds (of which
/// `run_failures` by a failed run), judged at `alpha` ([`FALSE_ALARM_RULE`]).
///
/// # Errors
/// [`Error::InvalidParameter`] for `seeds` = 0, `failed` > `seeds`, `run_failures` >
/// `failed`, or `alpha` outside (0, 1).
pub fn false_alarms(failed: u64, run_failures: u64, seeds: u64, alpha: f64) -> Result<FalseAlarms> {
    if run_failures > failed {
        return Err(Error::invalid(
            "run_failures",
            run_failures,
            format!("at most the failed seeds ({failed})"),
        ));
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::invalid("alpha", alpha, "in (0, 1)"));
    }
    let interval = clopper_pearson(failed, seeds, CONFIDENCE)?;
    Ok(FalseAlarms {
        seeds,
        failed,
        run_failures,
        rate: failed as f64 / seeds as f64,
        interval,
        confidence: CONFIDENCE,
        alpha,
        binomial_p: binomial_tail_p(failed, seeds, alpha)?,
        consistent: interval[0] <= alpha,
    })
}

/// The raw p-values of one check over the seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckPValues {
    /// The scene.
    pub scene: String,
    /// The check's name (unique within the scene).
    pub name: String,
    /// Its kind (`CheckResult::kind`).
    pub kind: String,
    /// Its raw p-values, one per seed at which it was evaluated and had one.
    pub p_values: Vec<f64>,
}

/// Whether a check's p-values were tested for uniformity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum UniformityStatus {
    /// Tested (KS against U(0, 1)).
    Tested,
    /// The same p-value at every seed (e.g. a deterministic check): not a random check.
    Constant,
    /// Fewer than two p-values (no p-value, or the runs failed).
    TooFew,
    /// An interval test (kind `band-…`: a point tested against a tolerance band, p = 1
    /// inside it): conservative by design, its p-values are not uniform under a correct
    /// simulator; its false alarms still count in the scene's rate.
    Interval,
}

/// The prefix of the kinds of interval tests ([`UniformityStatus::Interval`]).
pub const INTERVAL_KIND_PREFIX: &str = "band-";

/// The uniformity test of one check's p-values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckUniformity {
    /// The scene.
    pub scene: String,
    /// The check's name.
    pub name: String,
    /// Number of p-values (seeds).
    pub p_values: usize,
    /// Whether it was tested.
    pub status: UniformityStatus,
    /// KS distance D to U(0, 1), if tested.
    pub ks_statistic: Option<f64>,
    /// KS p-value (asymptotic Kolmogorov law; conservative for discrete p-values), if
    /// tested.
    pub ks_p: Option<f64>,
    /// Holm-adjusted over the tested checks of the kind, if tested.
    pub ks_p_adjusted: Option<f64>,
    /// Whether the adjusted KS p-value is below [`UNIFORMITY_LEVEL`].
    pub rejected: bool,
}

/// The pooled fraction of a kind's raw p-values below `level`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TailFraction {
    /// The level q.
    pub level: f64,
    /// p-values below q.
    pub count: usize,
    /// p-values pooled (every check of the kind, every seed).
    pub n: usize,
    /// count / n (q under uniformity).
    pub fraction: f64,
    /// Binomial standard error of the fraction, √(f(1−f)/n). The p-values of different
    /// checks of one seed are dependent, so this is a guide, not a test.
    pub std_error: f64,
    /// (fraction − q) / √(q(1−q)/n): the excess in standard errors under uniformity.
    pub z: f64,
}

/// The uniformity of one check kind's p-values (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindUniformity {
    /// The kind.
    pub kind: String,
    /// Checks of this kind (over every calibrated scene).
    pub checks: usize,
    /// Of those, tested.
    pub tested: usize,
    /// Raw p-values pooled.
    pub p_values: usize,
    /// Pooled fractions below each of [`TAIL_LEVELS`].
    pub tails: Vec<TailFraction>,
    /// Smallest Holm-adjusted KS p-value of the kind, if any check was tested.
    pub smallest_adjusted_p: Option<f64>,
    /// Rejected: some adjusted KS p-value below [`UNIFORMITY_LEVEL`] ([`UNIFORMITY_RULE`]).
    pub rejected: bool,
    /// Per check.
    pub per_check: Vec<CheckUniformity>,
}

/// The uniformity of the p-values per check kind, kinds sorted by name, checks in input
/// order ([`UNIFORMITY_RULE`]). Non-finite p-values are dropped, the others clamped to
/// [0, 1]. A kind none of whose checks has a p-value (a deterministic kind, e.g. the
/// oracle's) has no p-values to calibrate and is left out.
///
/// # Errors
/// [`Error::Numerical`] if the KS test fails (not expected for finite input).
pub fn uniformity_by_kind(checks: &[CheckPValues]) -> Result<Vec<KindUniformity>> {
    let mut kinds: BTreeMap<&str, Vec<&CheckPValues>> = BTreeMap::new();
    for c in checks {
        kinds.entry(c.kind.as_str()).or_default().push(c);
    }
    kinds.retain(|_, list| list.iter().any(|c| !c.p_values.is_empty()));
    kinds
        .into_iter()
        .map(|(kind, list)| kind_uniformity(kind, &list))
        .collect()
}

fn kind_uniformity(kind: &str, list: &[&CheckPValues]) -> Result<KindUniformity> {
    let mut per_check = Vec::with_capacity(list.len());
    let mut pooled = Vec::new();
    for c in list {
        let p: Vec<f64> = c
            .p_values
            .iter()
            .filter(|p| p.is_finite())
            .map(|p| p.clamp(0.0, 1.0))
            .collect();
        pooled.extend_from_slice(&p);
        let status = if c.kind.starts_with(INTERVAL_KIND_PREFIX) {
            UniformityStatus::Interval
        } else if p.len() < 2 {
            UniformityStatus::TooFew
        } else if p.iter().all(|&x| x == p[0]) {
            UniformityStatus::Constant
        } else {
            UniformityStatus::Tested
        };
        let ks = match status {
            UniformityStatus::Tested => Some(stats::ks_test(&p, |x| x.clamp(0.0, 1.0))?),
            _ => None,
        };
        per_check.push(CheckUniformity {
            scene: c.scene.clone(),
            name: c.name.clone(),
            p_values: p.len(),
            status,
            ks_statistic: ks.map(|o| o.statistic),
            ks_p: ks.map(|o| o.p_value),
            ks_p_adjusted: None,
            rejected: false,
        });
    }
    let tested: Vec<usize> = (0..per_check.len())
        .filter(|&i| per_check[i].ks_p.is_some())
        .collect();
    let raw: Vec<f64> = tested
        .iter()
        .map(|&i| per_check[i].ks_p.unwrap_or(1.0))
        .collect();
    for (&i, (adj, _)) in tested.iter().zip(stats::holm(&raw, UNIFORMITY_LEVEL)) {
        per_check[i].ks_p_adjusted = Some(adj);
        per_check[i].rejected = adj < UNIFORMITY_LEVEL;
    }
    let smallest_adjusted_p = per_check
        .iter()
        .filter_map(|c| c.ks_p_adjusted)
        .min_by(f64::total_cmp);
    Ok(KindUniformity {
        kind: kind.to_string(),
        checks: per_check.len(),
        tested: tested.len(),
        p_values: pooled.len(),
        tails: TAIL_LEVELS
            .iter()
            .map(|&q| tail_fraction(&pooled, q))
            .collect(),
        smallest_adjusted_p,
        rejected: per_check.iter().any(|c| c.rejected),
        per_check,
    })
}

/// The fraction of `p` below `q`, with its binomial standard error and its excess over
/// q in standard errors under uniformity (NaN fractions for an empty `p`).
pub fn tail_fraction(p: &[f64], q: f64) -> TailFraction {
    let n = p.len();
    let count = p.iter().filter(|&&x| x < q).count();
    let f = count as f64 / n as f64;
    TailFraction {
        level: q,
        count,
        n,
        fraction: f,
        std_error: (f * (1.0 - f) / n as f64).sqrt(),
        z: (f - q) / (q * (1.0 - q) / n as f64).sqrt(),
    }
}

/// Counts of `p` in `bins` equal bins of [0, 1]; p = 1 falls in the last bin, values
/// outside [0, 1] in the end bins, non-finite values nowhere. `bins` = 0 gives an empty
/// histogram.
pub fn histogram(p: &[f64], bins: usize) -> Vec<u64> {
    let mut counts = vec![0u64; bins];
    if bins == 0 {
        return counts;
    }
    for &x in p.iter().filter(|x| x.is_finite()) {
        let i = (x.clamp(0.0, 1.0) * bins as f64).floor() as usize;
        counts[i.min(bins - 1)] += 1;
    }
    counts
}

/// The caption of every p-value histogram ([`p_value_figure`]), in the SVG and the
/// calibration page.
pub const P_VALUE_CAPTION: &str = "Histogram of the raw p-values of each check kind over every \
     seed, as a density. For checks whose p-values are calibrated it should be flat at 1 \
     (dashed line); a peak near 0 means the kind rejects too often, a dip near 0 that it is \
     conservative.";

/// The figure `<scene>-p-values.svg`: per kind, the histogram of the scene's raw
/// p-values (every check of the kind, every seed) in [`HISTOGRAM_BINS`] bins, drawn as a
/// step outline of the density (count / (n · bin width)), against the uniform density 1.
/// `kinds` is (kind, p-values) per kind; `seeds` is N.
pub fn p_value_figure(scene: &str, seeds: u64, kinds: &[(String, Vec<f64>)]) -> Figure {
    let bins = HISTOGRAM_BINS;
    let width = 1.0 / bins as f64;
    let mut fig = Figure::new(
        format!("{scene}: raw p-values of the checks over {seeds} seeds, per kind ({bins} bins)"),
        "raw p-value (dimensionless)",
        "density (dimensionless; uniform: 1)",
    )
    .caption(P_VALUE_CAPTION);
    for (kind, p) in kinds {
        let n = p.iter().filter(|x| x.is_finite()).count();
        if n == 0 {
            continue;
        }
        let mut points = vec![(0.0, 0.0)];
        for (i, &c) in histogram(p, bins).iter().enumerate() {
            let d = c as f64 / (n as f64 * width);
            points.push((i as f64 * width, d));
            points.push(((i + 1) as f64 * width, d));
        }
        points.push((1.0, 0.0));
        fig = fig.series(Series::line(format!("{kind} ({n} p-values)"), points));
    }
    fig.hline(1.0, "uniform expectation")
}

/// One row of `p-values.csv`: one check at one seed.
#[derive(Debug, Clone, PartialEq)]
pub struct PValueRow {
    /// The scene.
    pub scene: String,
    /// The seed (`verify --seed` of the same run).
    pub seed: u64,
    /// The check's name.
    pub check: String,
    /// Its kind.
    pub kind: String,
    /// Raw p-value (none for a check without one).
    pub p_value: Option<f64>,
    /// Holm-adjusted p-value within the scene at that seed.
    pub p_adjusted: Option<f64>,
    /// Whether the check passed.
    pub passed: bool,
}

/// Header of `p-values.csv`.
pub const P_VALUES_HEADER: [&str; 7] = [
    "scene",
    "seed",
    "check",
    "kind",
    "p_value",
    "p_adjusted",
    "passed",
];

/// The text of `p-values.csv`: [`P_VALUES_HEADER`], then one line per row; numbers with
/// round-trip precision, an empty field for a missing p-value, `passed` as `true` or
/// `false`, text fields quoted where they need it.
///
/// # Errors
/// [`Error::Io`] naming `p-values.csv` if the table cannot be
/// written (it is written to memory; this does not happen).
pub fn p_values_csv(rows: &[PValueRow]) -> Result<String> {
    let mut table = CsvWriter::new(Vec::new(), Path::new(P_VALUES_CSV), &P_VALUES_HEADER)?;
    for r in rows {
        table.record([
            r.scene.clone(),
            r.seed.to_string(),
            r.check.clone(),
            r.kind.clone(),
            csv_number(r.p_value),
            csv_number(r.p_adjusted),
            r.passed.to_string(),
        ])?;
    }
    table.into_string()
}

/// The p-values of each check in `rows`, grouped by (scene, check) in order of first
/// appearance, without the missing ones.
pub fn p_values_per_check(rows: &[PValueRow]) -> Vec<CheckPValues> {
    let mut index: BTreeMap<(&str, &str), usize> = BTreeMap::new();
    let mut out: Vec<CheckPValues> = Vec::new();
    for r in rows {
        let i = *index
            .entry((r.scene.as_str(), r.check.as_str()))
            .or_insert_with(|| {
                out.push(CheckPValues {
                    scene: r.scene.clone(),
                    name: r.check.clone(),
                    kind: r.kind.clone(),
                    p_values: Vec::new(),
                });
                out.len() - 1
            });
        out[i].p_values.extend(r.p_value);
    }
    out
}

/// A seed at which a scene failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedSeed {
    /// The seed.
    pub seed: u64,
    /// The checks rejected after the Holm correction.
    pub failed_checks: Vec<String>,
    /// The run failure's message, if the run failed (then there are no checks).
    pub run_failure: Option<String>,
}

/// The calibration of one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneCalibration {
    /// The scene.
    pub name: String,
    /// The false-alarm rate.
    pub false_alarms: FalseAlarms,
    /// Checks per seed (of the seeds whose run did not fail; usually one value).
    pub checks_per_seed: Vec<usize>,
    /// The seeds at which the scene failed, with the failing checks or the run failure.
    pub failed_seeds: Vec<FailedSeed>,
    /// The figure of the scene's p-values, relative to the output directory.
    pub figure: String,
    /// Wall time of the scene's verifications, summed over the seeds (s).
    pub wall_seconds: f64,
}

/// The seeds of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedPlan {
    /// `--first-seed`.
    pub first: u64,
    /// N (`--seeds`).
    pub count: u64,
    /// How seed k is made from them.
    pub rule: String,
    /// Every seed, in order.
    pub seeds: Vec<u64>,
}

impl SeedPlan {
    /// Seed k = `first` + k, k = 0 … `count` − 1, applied to every scene as
    /// `verify --seed` does; `None` if the last seed overflows `u64`.
    pub fn consecutive(first: u64, count: u64) -> Option<SeedPlan> {
        first.checked_add(count.checked_sub(1)?)?;
        Some(SeedPlan {
            first,
            count,
            rule: "seed k = first + k for k = 0 .. N-1, replacing every scene's own seed as `verify --seed` does (each scene's streams are derived from its seed by SplitMix64 hashing, so consecutive seeds give independent streams); seed k of scene S is exactly `langevin-fem verify --scene S --seed <seed k>` at the same budget and alpha".to_string(),
            seeds: (0..count).map(|k| first + k).collect(),
        })
    }
}

/// The machine-readable result of a calibration (`calibration.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationSummary {
    /// The run that wrote the report.
    pub run_id: String,
    /// Budget name.
    pub budget: String,
    /// Family-wise level α of each scene's verification.
    pub alpha: f64,
    /// The seeds.
    pub seeds: SeedPlan,
    /// The rule of the false-alarm verdict ([`FALSE_ALARM_RULE`]).
    pub false_alarm_rule: String,
    /// The rule of the uniformity verdict ([`UNIFORMITY_RULE`]).
    pub uniformity_rule: String,
    /// Every scene consistent with α and no kind rejected.
    pub passed: bool,
    /// Per scene.
    pub scenes: Vec<SceneCalibration>,
    /// Per check kind, over every scene.
    pub kinds: Vec<KindUniformity>,
    /// Every file of the report, relative to the output directory, sorted.
    pub files: Vec<String>,
    /// What produced the report (the journal `manifest.json` holds the full record).
    pub provenance: Option<crate::output::ProvenanceRef>,
}

#[cfg(test)]
mod tests {
    //! Known values from the literature (R's `binom.test`, closed forms), and the
    //! uniformity test on p-values with a known law.
    use super::*;
    use rand::RngExt;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// R 4.x: `binom.test(5, 10)$conf.int` = 0.1870860 0.8129140; for 0/10 and 10/10
    /// the bounds are closed forms, 1 − 0.025^(1/10) = 0.3084971 and 0.025^(1/10) =
    /// 0.6915029 (`binom.test(0, 10)`: 0.0000000 0.3084971).
    #[test]
    fn clopper_pearson_matches_r_binom_test() {
        let [lo, hi] = clopper_pearson(5, 10, 0.95).unwrap();
        assert!(close(lo, 0.187_086_0, 5e-7), "{lo}");
        assert!(close(hi, 0.812_914_0, 5e-7), "{hi}");
        let [lo, hi] = clopper_pearson(0, 10, 0.95).unwrap();
        assert_eq!(lo, 0.0);
        assert!(close(hi, 0.308_497_1, 5e-7), "{hi}");
        assert!(close(hi, 1.0 - 0.025f64.powf(0.1), 1e-12), "{hi}");
        let [lo, hi] = clopper_pearson(10, 10, 0.95).unwrap();
        assert!(close(lo, 0.691_502_9, 5e-7), "{lo}");
        assert_eq!(hi, 1.0);
        // k = 1 of n: the lower bound solves 1 - (1 - p)^n = 0.025.
        let [lo, _] = clopper_pearson(1, 200, 0.95).unwrap();
        assert!(close(lo, 1.0 - 0.975f64.powf(1.0 / 200.0), 1e-12), "{lo}");
    }

    /// At each bound the binomial tail equals a/2 (the defining equations), with the
    /// tail summed term by term here, independently of statrs.
    #[test]
    fn clopper_pearson_bounds_solve_their_equations() {
        let tail_ge = |k: u64, n: u64, p: f64| -> f64 { (k..=n).map(|j| pmf(j, n, p)).sum() };
        for (k, n) in [(4u64, 200u64), (2, 48), (7, 100), (1, 5)] {
            let [lo, hi] = clopper_pearson(k, n, 0.95).unwrap();
            assert!(close(tail_ge(k, n, lo), 0.025, 1e-9), "{k}/{n} lower {lo}");
            assert!(
                close(1.0 - tail_ge(k + 1, n, hi), 0.025, 1e-9),
                "{k}/{n} upper {hi}"
            );
            assert!(lo < k as f64 / n as f64 && hi > k as f64 / n as f64);
        }
    }

    /// Binomial pmf from the product form (no statrs).
    fn pmf(j: u64, n: u64, p: f64) -> f64 {
        let mut ln_c = 0.0;
        for i in 0..j {
            ln_c += ((n - i) as f64).ln() - ((i + 1) as f64).ln();
        }
        (ln_c + j as f64 * p.ln() + (n - j) as f64 * (1.0 - p).ln()).exp()
    }

    /// R: `binom.test(9, 10, 0.5, "greater")$p.value` = 11/1024 = 0.01074219,
    /// `binom.test(1, 10, 0.5, "greater")` = 1023/1024; `binom.test(0, n, p, "greater")`
    /// = 1; and P(X >= 4 | 200, 0.01) summed term by term.
    #[test]
    fn binomial_tail_matches_known_values() {
        assert!(close(
            binomial_tail_p(9, 10, 0.5).unwrap(),
            11.0 / 1024.0,
            1e-12
        ));
        assert!(close(
            binomial_tail_p(1, 10, 0.5).unwrap(),
            1023.0 / 1024.0,
            1e-12
        ));
        assert_eq!(binomial_tail_p(0, 100, 0.01).unwrap(), 1.0);
        assert!(close(
            binomial_tail_p(10, 10, 0.5).unwrap(),
            1.0 / 1024.0,
            1e-15
        ));
        let by_hand: f64 = (4..=200).map(|j| pmf(j, 200, 0.01)).sum();
        assert!(close(
            binomial_tail_p(4, 200, 0.01).unwrap(),
            by_hand,
            1e-10
        ));
        assert!(binomial_tail_p(11, 10, 0.5).is_err());
        assert!(binomial_tail_p(0, 0, 0.5).is_err());
        assert!(binomial_tail_p(1, 10, 1.5).is_err());
        assert!(clopper_pearson(1, 10, 1.0).is_err());
    }

    /// The verdict: consistent unless the interval lies wholly above α.
    #[test]
    fn false_alarm_verdict_follows_the_interval() {
        // 4 of 200 at alpha 0.01: interval about [0.0055, 0.050] contains 0.01.
        let f = false_alarms(4, 1, 200, 0.01).unwrap();
        assert!(f.consistent && f.interval[0] < 0.01 && f.interval[1] > 0.01);
        assert_eq!(f.rate, 0.02);
        // 0 of 100: below alpha is fine.
        assert!(false_alarms(0, 0, 100, 0.01).unwrap().consistent);
        // 10 of 100 at 0.01: the lower bound (0.049) is above alpha.
        let f = false_alarms(10, 0, 100, 0.01).unwrap();
        assert!(!f.consistent && f.binomial_p < 1e-6, "{f:?}");
        assert!(false_alarms(1, 2, 10, 0.01).is_err());
        assert!(false_alarms(1, 0, 10, 0.0).is_err());
    }

    fn uniform(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = crate::rng::trajectory_rng(seed, 0);
        (0..n).map(|_| rng.random::<f64>()).collect()
    }

    /// Two-sided p-values of z-scores drawn from N(shift, scale²) but tested against
    /// N(0, 1): a wrong reference (shift) or an underestimated standard error (scale > 1).
    fn wrong_reference_p_values(seed: u64, n: usize, shift: f64, scale: f64) -> Vec<f64> {
        use rand_distr::{Distribution, StandardNormal};
        use statrs::distribution::Normal;
        let std = Normal::standard();
        let mut rng = crate::rng::trajectory_rng(seed, 1);
        (0..n)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                2.0 * std.sf((scale * z + shift).abs())
            })
            .collect()
    }

    fn checks(kind: &str, ps: Vec<Vec<f64>>) -> Vec<CheckPValues> {
        ps.into_iter()
            .enumerate()
            .map(|(i, p)| CheckPValues {
                scene: "s".into(),
                name: format!("{kind}/{i}"),
                kind: kind.into(),
                p_values: p,
            })
            .collect()
    }

    /// Uniform p-values are accepted; the p-values of a z-test whose reference is off by
    /// 0.3 standard deviations, and of one whose standard error is 1.2 times too small,
    /// are rejected. The sizes give the KS test ample power: the KS distance of the
    /// shifted law from U(0,1) is 0.021 (computed by quadrature), against a 1 % critical
    /// value 1.63/√20000 = 0.012; that of the scaled law 0.088 against 1.63/√2000 =
    /// 0.036. Seeds fixed: the outcome is deterministic.
    #[test]
    fn uniformity_accepts_uniform_and_rejects_a_wrong_reference() {
        let good = checks(
            "good",
            (0..4).map(|i| uniform(0xCA11_0000 + i, 2000)).collect(),
        );
        let k = uniformity_by_kind(&good).unwrap();
        assert_eq!(k.len(), 1);
        assert!(!k[0].rejected, "{k:?}");
        assert_eq!(k[0].tested, 4);
        assert_eq!(k[0].p_values, 8000);
        for t in &k[0].tails {
            assert!(t.z.abs() < 4.0, "{t:?}");
        }
        for (n, shift, scale) in [(20_000, 0.3, 1.0), (2000, 0.0, 1.2)] {
            let mut mixed = checks("bad", vec![uniform(0xCA11_0010, n)]);
            mixed.push(CheckPValues {
                scene: "s".into(),
                name: "bad/wrong".into(),
                kind: "bad".into(),
                p_values: wrong_reference_p_values(0xCA11_0011, n, shift, scale),
            });
            let k = uniformity_by_kind(&mixed).unwrap();
            assert!(k[0].rejected, "{k:?}");
            assert!(!k[0].per_check[0].rejected && k[0].per_check[1].rejected);
            assert!(k[0].smallest_adjusted_p.unwrap() < UNIFORMITY_LEVEL);
            // The excess of small p-values shows in the pooled fraction below 0.05.
            assert!(k[0].tails[0].fraction > 0.05, "{k:?}");
        }
    }

    /// Ties, p = 1 exactly, NaN, constant and too-short series break nothing.
    #[test]
    fn discrete_and_degenerate_p_values_are_handled() {
        let list = vec![
            CheckPValues {
                scene: "s".into(),
                name: "ties".into(),
                kind: "k".into(),
                p_values: vec![1.0, 1.0, 0.5, 0.5, 0.25, 1.0, 0.75, f64::NAN, 0.0],
            },
            CheckPValues {
                scene: "s".into(),
                name: "deterministic".into(),
                kind: "k".into(),
                p_values: vec![1.0; 5],
            },
            CheckPValues {
                scene: "s".into(),
                name: "once".into(),
                kind: "k".into(),
                p_values: vec![0.3],
            },
            CheckPValues {
                scene: "s".into(),
                name: "none".into(),
                kind: "other".into(),
                p_values: vec![],
            },
            CheckPValues {
                scene: "s".into(),
                name: "band".into(),
                kind: "band-t-test".into(),
                p_values: vec![1.0, 1.0, 0.4, 1.0, 0.2],
            },
        ];
        let k = uniformity_by_kind(&list).unwrap();
        // A kind without any p-value (deterministic checks) is left out; an interval
        // test's kind is listed, untested.
        assert_eq!(k.len(), 2);
        assert_eq!(k[0].kind, "band-t-test");
        assert_eq!(k[0].per_check[0].status, UniformityStatus::Interval);
        assert!(!k[0].rejected && k[0].tested == 0);
        let k = &k[1..];
        assert!(k.iter().all(|u| u.kind != "other"));
        let statuses: Vec<_> = k[0].per_check.iter().map(|c| c.status).collect();
        assert_eq!(
            statuses,
            [
                UniformityStatus::Tested,
                UniformityStatus::Constant,
                UniformityStatus::TooFew
            ]
        );
        assert_eq!(k[0].per_check[0].p_values, 8);
        assert!(
            k[0].per_check[0]
                .ks_p
                .is_some_and(|p| (0.0..=1.0).contains(&p))
        );
        assert_eq!(k[0].tested, 1);
    }

    #[test]
    fn histogram_bins_edges_and_ones() {
        let h = histogram(
            &[0.0, 0.05, 0.049_999, 0.5, 1.0, 1.0, f64::NAN, 1.2, -0.1],
            20,
        );
        assert_eq!(h.len(), 20);
        assert_eq!(h[0], 3, "{h:?}"); // 0, 0.049999, -0.1
        assert_eq!(h[1], 1); // 0.05
        assert_eq!(h[10], 1); // 0.5
        assert_eq!(h[19], 3); // 1, 1, 1.2
        assert_eq!(h.iter().sum::<u64>(), 8);
        assert!(histogram(&[0.5], 0).is_empty());
    }

    #[test]
    fn csv_rows_quote_text_and_leave_missing_p_values_empty() {
        let rows = vec![
            PValueRow {
                scene: "a".into(),
                seed: 18_446_744_073_709_551_615,
                check: "mode-variance/n=1".into(),
                kind: "z-test".into(),
                p_value: Some(0.25),
                p_adjusted: Some(1e-7),
                passed: true,
            },
            PValueRow {
                scene: "a".into(),
                seed: 2,
                check: "odd, name".into(),
                kind: "deterministic".into(),
                p_value: None,
                p_adjusted: None,
                passed: false,
            },
        ];
        assert_eq!(
            p_values_csv(&rows).unwrap(),
            "scene,seed,check,kind,p_value,p_adjusted,passed\n\
             a,18446744073709551615,mode-variance/n=1,z-test,0.25,1e-7,true\n\
             a,2,\"odd, name\",deterministic,,,false\n"
        );
        let per = p_values_per_check(&rows);
        assert_eq!(per.len(), 2);
        assert_eq!(per[0].p_values, [0.25]);
        assert!(per[1].p_values.is_empty());
    }

    #[test]
    fn seed_plan_is_consecutive_and_refuses_overflow() {
        let s = SeedPlan::consecutive(7, 3).unwrap();
        assert_eq!(s.seeds, [7, 8, 9]);
        assert!(SeedPlan::consecutive(u64::MAX, 1).is_some());
        assert!(SeedPlan::consecutive(u64::MAX, 2).is_none());
        assert!(SeedPlan::consecutive(0, 0).is_none());
    }
}
