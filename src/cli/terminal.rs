//! What `verify` and `check` print: per-scene lines and the closing totals line on
//! stdout, warnings on stderr, at the chosen [`Verbosity`].
//!
//! - quiet: every failed check (`SCENE  failed: NAME`, with its ratio as below), then
//!   the totals line;
//! - normal: a line per scene (verdict, checks passed, failed and skipped, wall time),
//!   its failed checks, each with the ratio estimate/reference where it means something
//!   ([`diagnosis::ratio_of`]), a hint per run with a failed check where its per-mode
//!   ratios show a pattern ([`diagnosis::run_hints`]), the verdict with the report's
//!   path, then the totals line;
//! - verbose: also, per failed check, its test, statistic, p-values and estimate
//!   against the reference, per skipped check the reason, and the seed of each scene;
//! - per run without a failed check, the smallest relative error of each observable it
//!   would have caught with 80 % power ([`diagnosis::detectable_deviations`]): `check`
//!   at normal verbosity, `verify` at verbose; `verify` at normal verbosity prints one such
//!   line per passing scene (per observable, its most sensitive run).
//!
//! The last line of stdout is always `N passed, N failed, N skipped in T s` (checks
//! summed over the scenes; T the command's wall time), for a person and for a script.

use super::Verbosity;
use langevin_fem::verify::diagnosis;
use langevin_fem::verify::summary::{CheckResult, Summary, Totals};

/// The closing line of `verify` and `check`: `N passed, N failed, N skipped in T s`.
pub fn totals_line(totals: &Totals, seconds: f64) -> String {
    format!("{} in {seconds:.1} s", totals.text())
}

/// A number for the terminal: 4 significant digits.
fn num(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |x| format!("{x:.4e}"))
}

/// The detail of a failed check for `--verbose`: test, statistic, p-values, estimate ±
/// s.e. against the reference.
fn failure_detail(c: &CheckResult) -> String {
    let mut parts = vec![c.kind.clone()];
    if let Some(stat) = c.statistic {
        let dof = c.dof.map_or(String::new(), |d| format!(" (dof {d})"));
        parts.push(format!("statistic {stat:.4}{dof}"));
    }
    if c.p_value.is_some() {
        parts.push(format!(
            "p = {}, adjusted p = {}",
            num(c.p_value),
            num(c.p_adjusted)
        ));
    }
    if c.estimate.is_some() || c.reference.is_some() {
        let unit = if c.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", c.unit)
        };
        parts.push(format!(
            "estimate {} +- {} against reference {}{unit}",
            num(c.estimate),
            num(c.std_error),
            num(c.reference)
        ));
    }
    if let Some((r, se)) = diagnosis::ratio_of(c) {
        parts.push(diagnosis::ratio_text(r, se));
    }
    parts.join("; ")
}

/// The failed line's name with the ratio estimate/reference where it means something:
/// `run/mode-variance/n=3 (ratio 1.099 ± 0.013)`. A check without a ratio of its own
/// borrows that of its sibling, named so: a check of a mode (a KS or χ² test of its
/// distribution, its mean against 0) the same mode's `mode-variance` check
/// (`run/mode-ks/n=4 (variance ratio 1.344 ± 0.007)`), a force distribution test the
/// same strain's `force` check (`run/force-ks/strain_ratio=10 (mean-force ratio 1.04 ±
/// 0.01)`). Otherwise the estimate against its reference where both exist (a check
/// against 0, a residual against its bound: `(estimate 3.1e-3 ± 8.0e-4 against 0)`),
/// else the p-value.
fn failed_name(c: &CheckResult, checks: &[CheckResult]) -> String {
    if let Some((r, se)) = diagnosis::ratio_of(c) {
        return format!("{} ({})", c.name, diagnosis::ratio_text(r, se));
    }
    let sibling = |kind: &str| {
        checks
            .iter()
            .find(|v| v.check == kind && v.run == c.run && v.parameter == c.parameter)
    };
    let borrowed = if c.check.starts_with("mode-") {
        sibling("mode-variance").map(|v| ("variance", v))
    } else if c.check.starts_with("force-") {
        sibling("force").map(|v| ("mean-force", v))
    } else {
        None
    };
    if let Some((what, v)) = borrowed
        && let Some((r, se)) = diagnosis::ratio_of(v)
    {
        return format!("{} ({what} {})", c.name, diagnosis::ratio_text(r, se));
    }
    match (c.estimate, c.reference) {
        (Some(e), Some(r)) if e.is_finite() && r.is_finite() => {
            let se = c
                .std_error
                .filter(|s| s.is_finite() && *s > 0.0)
                .map_or(String::new(), |s| format!(" ± {s:.1e}"));
            let r = if r == 0.0 {
                "0".to_string()
            } else {
                format!("{r:.3e}")
            };
            format!("{} (estimate {e:.3e}{se} against {r})", c.name)
        }
        _ => match c.p_value {
            Some(p) => format!("{} (p = {p:.1e})", c.name),
            None => c.name.clone(),
        },
    }
}

/// Prints the scenes of `summary` at `verbosity`: failures and per-scene lines on
/// stdout, warnings on stderr (`wall`: print each scene's wall time; `detectable`: at
/// normal verbosity, per run without a failed check, the smallest errors it would have
/// caught — `check`'s default; otherwise, as `verify` does, one such line per passing
/// scene, per observable its most sensitive run, and per run with `--verbose`).
pub fn print_scenes(summary: &Summary, verbosity: Verbosity, wall: bool, detectable: bool) {
    for s in &summary.scenes {
        let t = Totals::of([s]);
        if verbosity != Verbosity::Quiet {
            let time = if wall {
                format!(", {:.1} s", s.wall_seconds)
            } else {
                String::new()
            };
            println!(
                "{:<24} {}  {} checks: {} passed, {} failed, {} skipped{time}",
                s.name,
                if s.passed { "PASS" } else { "FAIL" },
                s.checks.len(),
                t.passed,
                t.failed,
                t.skipped
            );
        }
        for c in s.checks.iter().filter(|c| !c.passed) {
            match verbosity {
                Verbosity::Quiet => {
                    println!("{}  failed: {}", s.name, failed_name(c, &s.checks))
                }
                Verbosity::Normal => println!("    failed: {}", failed_name(c, &s.checks)),
                Verbosity::Verbose => {
                    println!("    failed: {}: {}", c.name, failure_detail(c));
                }
            }
        }
        if verbosity != Verbosity::Quiet {
            for h in &s.hints {
                println!("    {}: {}", h.run, h.text);
            }
        }
        if verbosity == Verbosity::Normal
            && !detectable
            && s.passed
            && let Some(text) = diagnosis::scene_detectable_text(&s.detectable)
        {
            println!("    {text}");
        }
        if verbosity == Verbosity::Verbose || (detectable && verbosity == Verbosity::Normal) {
            for (run, text) in diagnosis::detectable_lines(&s.detectable) {
                if s.checks.iter().any(|c| c.run == run && !c.passed) {
                    continue;
                }
                println!("    {run}: passed; {text}");
            }
        }
        if verbosity == Verbosity::Verbose {
            for k in &s.skipped {
                println!("    skipped: {}: {}", k.name, k.reason);
            }
            if let Some(seed) = s.notes.iter().rev().find(|n| n.starts_with("seed ")) {
                println!("    {seed}");
            }
        }
        for w in &s.warnings {
            eprintln!("warning: {}: {w}", s.name);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use langevin_fem::verify::summary::SceneSummary;

    fn check(name: &str, passed: bool) -> CheckResult {
        CheckResult {
            name: name.to_string(),
            run: String::new(),
            check: String::new(),
            parameter: String::new(),
            kind: "z-test".to_string(),
            statistic: Some(3.5),
            dof: None,
            passed,
            p_value: Some(4.6e-4),
            p_adjusted: Some(2.1e-3),
            estimate: Some(1.1),
            reference: Some(1.0),
            std_error: Some(0.03),
            continuum: None,
            reference_kind: "discrete".to_string(),
            unit: "[L]^2".to_string(),
            detail: String::new(),
            largest_deviation: None,
            variance_correlation: None,
        }
    }

    fn scene(checks: Vec<CheckResult>, skipped: usize) -> SceneSummary {
        SceneSummary {
            name: "s".to_string(),
            passed: checks.iter().all(|c| c.passed),
            wall_seconds: 1.0,
            figures: vec![],
            captions: vec![],
            tables: vec![],
            notes: vec![],
            warnings: vec![],
            skipped: (0..skipped)
                .map(|k| langevin_fem::verify::summary::SkippedCheck {
                    name: format!("r/decay-rate/n={k}"),
                    reason: "too short".to_string(),
                })
                .collect(),
            checks,
            detectable: vec![],
            hints: vec![],
        }
    }

    /// Totals sum over scenes; skipped checks count apart; the line reads as documented.
    #[test]
    fn totals_count_passed_failed_and_skipped_checks() {
        let a = scene(vec![check("a", true), check("b", false)], 2);
        let b = scene(vec![check("c", true)], 1);
        let t = Totals::of([&a, &b]);
        assert_eq!(
            t,
            Totals {
                passed: 2,
                failed: 1,
                skipped: 3
            }
        );
        assert_eq!(
            totals_line(&t, 12.345),
            "2 passed, 1 failed, 3 skipped in 12.3 s"
        );
    }

    #[test]
    fn failure_detail_names_the_test_the_p_values_and_the_estimate() {
        let d = failure_detail(&check("a", false));
        assert_eq!(
            d,
            "z-test; statistic 3.5000; p = 4.6000e-4, adjusted p = 2.1000e-3; estimate 1.1000e0 +- 3.0000e-2 against reference 1.0000e0 [L]^2; ratio 1.100 ± 0.030"
        );
    }

    /// The default failed line: the name with the ratio where the check has an estimate
    /// and a nonzero reference, a sibling's ratio, the estimate against 0 or a bound, or
    /// the p-value: never the name alone.
    #[test]
    fn failed_lines_show_the_ratio_where_it_means_something() {
        let c = check("r/mode-variance/n=3", false);
        assert_eq!(
            failed_name(&c, &[]),
            "r/mode-variance/n=3 (ratio 1.100 ± 0.030)"
        );
        // Against 0, or a residual without a p-value: the estimate against its reference.
        let mut zero = check("r/mode-mean/n=3", false);
        zero.reference = Some(0.0);
        assert_eq!(
            failed_name(&zero, &[]),
            "r/mode-mean/n=3 (estimate 1.100e0 ± 3.0e-2 against 0)"
        );
        let mut residual = check("r/axial-equilibrium", false);
        residual.p_value = None;
        residual.std_error = None;
        assert_eq!(
            failed_name(&residual, &[]),
            "r/axial-equilibrium (estimate 1.100e0 against 1.000e0)"
        );
        // Neither ratio nor estimate: the p-value.
        let mut bare = check("r/two-time", false);
        bare.estimate = None;
        assert_eq!(failed_name(&bare, &[]), "r/two-time (p = 4.6e-4)");
        // A mode's distribution test borrows its mode-variance check's ratio, named so.
        let at = |name: &str, check_name: &str| CheckResult {
            run: "r".into(),
            check: check_name.into(),
            parameter: "n=3".into(),
            ..check(name, false)
        };
        let variance = at("r/mode-variance/n=3", "mode-variance");
        let mut ks = at("r/mode-ks/n=3", "mode-ks");
        ks.estimate = None;
        assert_eq!(
            failed_name(&ks, &[variance.clone(), ks.clone()]),
            "r/mode-ks/n=3 (variance ratio 1.100 ± 0.030)"
        );
        let mut other = variance;
        other.parameter = "n=4".into();
        assert_eq!(failed_name(&ks, &[other]), "r/mode-ks/n=3 (p = 4.6e-4)");
        // A force distribution test borrows the same strain's mean-force ratio.
        let force = CheckResult {
            check: "force".into(),
            parameter: "strain_ratio=10".into(),
            ..at("r/force/strain_ratio=10", "force")
        };
        let fks = CheckResult {
            check: "force-ks".into(),
            parameter: "strain_ratio=10".into(),
            estimate: None,
            ..at("r/force-ks/strain_ratio=10", "force-ks")
        };
        assert_eq!(
            failed_name(&fks, &[force, fks.clone()]),
            "r/force-ks/strain_ratio=10 (mean-force ratio 1.100 ± 0.030)"
        );
    }
}
