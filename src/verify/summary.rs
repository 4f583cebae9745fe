//! The machine-readable result of a verification run (`summary.json`): the run id and
//! every file of the report (see [`crate::output::manifest`]), what produced it (a
//! reference to the provenance in `manifest.json`, with version, commit and seeds in
//! clear), the budget, the scenes and their checks.

use crate::output::ProvenanceRef;
use serde::{Deserialize, Serialize};

/// One statistical or deterministic check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckResult {
    /// Unique name within the scene, e.g. `mode-variance/n=3`.
    pub name: String,
    /// Kind of check, e.g. `chi2-variance`, `ks`, `z-test`, `deterministic`.
    pub kind: String,
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
    /// Free-text detail for a reader (what was compared, sample size, …).
    pub detail: String,
}

impl CheckResult {
    /// A statistical check before the family-wise correction (`passed` is set by the
    /// runner's Holm step). `values` is (estimate, reference, standard error) against the
    /// exact discrete reference; a non-finite entry means "not applicable" (e.g. the
    /// reference of a KS distance) and is stored as `None`.
    pub fn statistical(
        name: String,
        kind: &str,
        values: (f64, f64, f64),
        continuum: Option<f64>,
        p_value: f64,
        detail: String,
    ) -> Self {
        let finite = |v: f64| v.is_finite().then_some(v);
        CheckResult {
            name,
            kind: kind.to_string(),
            passed: true,
            p_value: Some(p_value),
            p_adjusted: None,
            estimate: finite(values.0),
            reference: finite(values.1),
            std_error: finite(values.2),
            continuum,
            reference_kind: "discrete".to_string(),
            detail,
        }
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
    /// Relative paths of the CSV tables written for the scene.
    pub tables: Vec<String>,
    /// Notes for a reader (e.g. how a ratio changes with element count).
    pub notes: Vec<String>,
    /// Warnings: the run is valid for its model, but the model may not be for the
    /// physics (e.g. slopes too large for the small-slope approximation).
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The checks.
    pub checks: Vec<CheckResult>,
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
