//! The machine-readable result of a verification run (`summary.json`): the run id and
//! every file of the report (see [`crate::output::manifest`]), what produced it (a
//! reference to the provenance in `manifest.json`, with version, commit and seeds in
//! clear), the budget, the scenes and their checks.

use crate::output::ProvenanceRef;
use crate::stats::TestOutcome;
use serde::{Deserialize, Serialize};

/// One statistical or deterministic check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckResult {
    /// Unique name within the scene, `run/check/parameter`, e.g.
    /// `paper/mode-variance/n=3` (the three parts are also given apart below).
    pub name: String,
    /// The run the check belongs to; empty for a check of the scene (the oracle's
    /// checks of the scene's theory, the Δt-halving comparison of two runs).
    #[serde(default)]
    pub run: String,
    /// What is checked, e.g. `mode-variance`, `decay-rate`, `force`,
    /// `oracle-eigenvalue` (the name without run and parameter).
    #[serde(default)]
    pub check: String,
    /// Where it is checked, e.g. `n=3`, `x=0.2500`, `strain_ratio=1.5`; empty if the
    /// check has no parameter.
    #[serde(default)]
    pub parameter: String,
    /// The test, e.g. `t-test`, `z-test`, `chi2-variance`, `quadratic-form`, `chi2-gof`, `chi2-sum`, `ks`, `band-t-test`, `band-z-test` (against the nearest point of a tolerance band), `band-chi2-sum` (their sum of squared scores);
    /// `oracle` and `residual` for deterministic checks.
    pub kind: String,
    /// The test statistic (t, z, χ², KS distance D); `None` for a deterministic check.
    #[serde(default)]
    pub statistic: Option<f64>,
    /// Degrees of freedom of the statistic's null distribution, where it has any.
    #[serde(default)]
    pub dof: Option<f64>,
    /// Whether the check passed (after the family-wise correction).
    pub passed: bool,
    /// Raw (unadjusted) p-value, for statistical checks.
    pub p_value: Option<f64>,
    /// Holm-adjusted p-value over the scene's family of checks.
    pub p_adjusted: Option<f64>,
    /// The estimate from the simulation.
    pub estimate: Option<f64>,
    /// The exact reference it is compared with.
    pub reference: Option<f64>,
    /// Standard error of the estimate.
    pub std_error: Option<f64>,
    /// The continuum value of the same quantity (eq. 2–4), for comparison: the gap
    /// between `reference` and `continuum` is the discretization (or integrator) error.
    pub continuum: Option<f64>,
    /// Which reference is used: `discrete` (exact for the discretized system and
    /// integrator) or `continuum`.
    pub reference_kind: String,
    /// Unit of `estimate`, `reference`, `std_error` and `continuum`, in the scene's base
    /// dimensions as in the column dictionary ([`crate::output::columns`]): `[L]^2`,
    /// `1/[T]`, `F_c0`, `1`, …; empty when the check has no estimate (a χ² or KS test,
    /// whose result is its statistic).
    #[serde(default)]
    pub unit: String,
    /// Free-text detail for a reader (what was compared, sample size, …).
    pub detail: String,
    /// For a check of a mean over points (`force-mean-bias`: the mean over the strains),
    /// the single point farthest from its reference, which the mean can hide; absent
    /// (not serialized) for every other check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub largest_deviation: Option<LargestDeviation>,
    /// For a `decay-rate` check, the jackknife correlation of its rate estimate with the
    /// mean square of the same series — the estimate of the mode's `mode-variance` check
    /// ([`crate::stats::RateEstimate::variance_correlation`]); `fit` needs it for the
    /// drag, which takes both. Absent (not serialized) for every other check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variance_correlation: Option<f64>,
}

/// The point of a pooled check farthest from its reference (issue #31): a bias of a few
/// points of opposite signs, or at a few strains only, can hide in a mean that passes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LargestDeviation {
    /// Where, e.g. `strain_ratio=6`.
    pub parameter: String,
    /// The point's estimate, in the check's unit.
    pub estimate: f64,
    /// Its exact reference (the exact discrete theory), in the check's unit.
    pub reference: f64,
    /// Its standard error (that of the point's own check), in the check's unit.
    pub std_error: f64,
    /// (estimate − reference) / std_error.
    pub z: f64,
    /// The check that tests this point on its own (name `run/check/parameter`).
    pub tested_by: String,
}

/// A check the scene asks for that was not evaluated, with the reason (e.g. the series at
/// this budget are too short for a decay-rate window). Counted apart: neither passed nor
/// failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedCheck {
    /// The name the check would have had (`run/check/parameter`).
    pub name: String,
    /// Why it was not evaluated.
    pub reason: String,
}

/// The unit of the estimate of check `check` (see [`CheckResult::unit`]), empty for a
/// check whose result is its statistic.
pub fn unit_of_check(check: &str) -> &'static str {
    match check {
        "mode-variance" | "mode-variance-chi2" | "mode-cross" | "profile" | "time-reversal"
        | "two-time" | "oracle-profile" => "[L]^2",
        "mode-mean" => "[L]",
        "decay-rate" => "1/[T]",
        "force" | "force-mean-bias" | "oracle-force" => "F_c0",
        "spectrum-low"
        | "spectrum-high"
        | "pooled-variance"
        | "xy-symmetry"
        | "oracle-eigenvalue"
        | "oracle-variance"
        | "oracle-multiplier"
        | "oracle-noise"
        | "oracle-stored-length"
        | "axial-equilibrium" => "1",
        _ if check.starts_with("oracle") => "1",
        _ => "",
    }
}

impl CheckResult {
    /// A statistical check before the family-wise correction (`passed` is set by the
    /// runner's Holm step). `values` is (estimate, reference, standard error) against the
    /// exact discrete reference; a non-finite entry means "not applicable" (e.g. the
    /// reference of a KS distance) and is stored as `None`.
    /// The test's statistic, degrees of freedom and p-value are `outcome`'s.
    pub fn statistical(
        name: String,
        kind: &str,
        values: (f64, f64, f64),
        continuum: Option<f64>,
        outcome: &TestOutcome,
        detail: String,
    ) -> Self {
        let finite = |v: f64| v.is_finite().then_some(v);
        CheckResult {
            name,
            run: String::new(),
            check: String::new(),
            parameter: String::new(),
            kind: kind.to_string(),
            statistic: finite(outcome.statistic),
            dof: outcome.dof,
            unit: String::new(),
            passed: true,
            p_value: Some(outcome.p_value),
            p_adjusted: None,
            estimate: finite(values.0),
            reference: finite(values.1),
            std_error: finite(values.2),
            continuum,
            reference_kind: "discrete".to_string(),
            detail,
            largest_deviation: None,
            variance_correlation: None,
        }
    }

    /// Fills [`Self::run`], [`Self::check`], [`Self::parameter`] and [`Self::unit`] from
    /// the name `run/check/parameter` (`run` one of `runs`; a name whose first part is
    /// not a run is a check of the scene), unless they are set.
    pub fn locate(&mut self, runs: &[&str]) {
        if !self.check.is_empty() {
            return;
        }
        let mut rest = self.name.as_str();
        if let Some((first, tail)) = rest.split_once('/')
            && runs.contains(&first)
        {
            self.run = first.to_string();
            rest = tail;
        }
        let (check, parameter) = match rest.rsplit_once('/') {
            Some((c, p)) if p.contains('=') => (c, p),
            _ => (rest, ""),
        };
        self.check = check.to_string();
        self.parameter = parameter.to_string();
        if self.unit.is_empty() {
            self.unit = unit_of_check(check).to_string();
        }
    }
}

/// Checks passed, failed and skipped (not evaluated) in a set of scenes: the totals the
/// terminal's closing line and the report's verdict show.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Totals {
    /// Checks that passed.
    pub passed: usize,
    /// Checks that failed.
    pub failed: usize,
    /// Checks not evaluated ([`SceneSummary::skipped`]).
    pub skipped: usize,
}

impl Totals {
    /// The totals of `scenes`.
    pub fn of<'a>(scenes: impl IntoIterator<Item = &'a SceneSummary>) -> Self {
        scenes.into_iter().fold(Totals::default(), |t, s| {
            let failed = s.checks.iter().filter(|c| !c.passed).count();
            Totals {
                passed: t.passed + s.checks.len() - failed,
                failed: t.failed + failed,
                skipped: t.skipped + s.skipped.len(),
            }
        })
    }

    /// `N passed, N failed, N skipped`.
    pub fn text(&self) -> String {
        format!(
            "{} passed, {} failed, {} skipped",
            self.passed, self.failed, self.skipped
        )
    }
}

/// The result of one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneSummary {
    /// Scene name (file stem).
    pub name: String,
    /// Whether every check passed.
    pub passed: bool,
    /// Wall time of the scene in seconds (the only non-deterministic field).
    pub wall_seconds: f64,
    /// Relative paths (from the output directory) of the figures written for the scene.
    pub figures: Vec<String>,
    /// The caption of each figure, in the order of `figures`: what is plotted and what a
    /// reader should see (empty for a figure without one).
    #[serde(default)]
    pub captions: Vec<String>,
    /// Relative paths of the CSV tables written for the scene.
    pub tables: Vec<String>,
    /// Notes for a reader (e.g. how a ratio changes with element count).
    pub notes: Vec<String>,
    /// Warnings: the run is valid for its model, but the model may not be for the
    /// physics (e.g. slopes too large for the small-slope approximation).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Checks the scene asks for that were not evaluated (neither passed nor failed).
    #[serde(default)]
    pub skipped: Vec<SkippedCheck>,
    /// The checks.
    pub checks: Vec<CheckResult>,
    /// Per run and observable, the smallest relative error its checks would have
    /// detected at the scene's α with 80 % power (issue #31,
    /// [`crate::verify::diagnosis::detectable_deviations`]); empty where no check
    /// states a ratio with a standard error.
    #[serde(default)]
    pub detectable: Vec<crate::verify::diagnosis::Detectable>,
    /// Per run with a failed check, the pattern its per-mode ratios show, stated as a
    /// hint with its evidence (issue #31, [`crate::verify::diagnosis::run_hints`]); not
    /// written when there is none (every check passed, or no pattern).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hints: Vec<crate::verify::diagnosis::RunHint>,
}

impl SceneSummary {
    /// The summary of scene `name` holding only `checks` (passed if every check passed;
    /// no figures, notes or wall time), e.g. for the analyses of a summary's checks.
    pub fn of_checks(name: &str, checks: Vec<CheckResult>) -> SceneSummary {
        SceneSummary {
            name: name.to_string(),
            passed: checks.iter().all(|c| c.passed),
            wall_seconds: 0.0,
            figures: vec![],
            captions: vec![],
            tables: vec![],
            notes: vec![],
            warnings: vec![],
            skipped: vec![],
            checks,
            detectable: vec![],
            hints: vec![],
        }
    }
}

/// The result of a verification run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The run that wrote the report ([`crate::output::new_run_id`]); `index.html` shows
    /// the same id. Empty for a summary not written by a run.
    #[serde(default)]
    pub run_id: String,
    /// Budget name: `quick`, `standard` or `full`.
    pub budget: String,
    /// Family-wise significance level used in each scene.
    pub alpha: f64,
    /// Whether every scene passed.
    pub passed: bool,
    /// The scenes.
    pub scenes: Vec<SceneSummary>,
    /// Every file of the report, relative to the output directory with `/` separators,
    /// sorted: the figures and tables of the scenes, `fig2.svg` if written,
    /// `summary.json`, `index.html` and the run's journal `manifest.json`. Nothing else
    /// in the directory belongs to this run (a `convergence/` folder is another
    /// command's).
    #[serde(default)]
    pub files: Vec<String>,
    /// What produced the report: the journal holding the full provenance
    /// (`manifest.json`: scene texts, parameters with units, wall time), with version,
    /// commit, command line, start time, threads and per scene its source, hash and
    /// seed in clear. `null` for a summary not written by a run.
    #[serde(default)]
    pub provenance: Option<ProvenanceRef>,
}
