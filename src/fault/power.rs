//! `langevin-fem power`: the detection rate of every catalogued fault ([`FaultKind`]) over
//! seeds, per scene and size, at a budget.
//!
//! For each fault, each of its scenes ([`targets`]: the cheapest scenes that exercise it,
//! some restricted to the runs it touches) and each size of its ladder
//! ([`FaultKind::ladder`]), the scene is verified in-process
//! ([`run_verification`]) at the seeds [`seeds`] (the same fixed seeds for every fault
//! and size). A seed counts as a detection when the scene fails its checks (the exit-1
//! class) or the run fails (exit 3; also an input error, exit 2, which a fault should
//! never cause: both counted separately, as weak detections). Per row: the detection rate
//! with its Clopper–Pearson 95 % interval ([`clopper_pearson`]); per fault and scene: the
//! smallest size detected in at least 95 % of seeds. The ladder runs from the smallest
//! size up, and stops once a size is detected in every seed (the larger sizes are not
//! run: detection grows with the size).

use super::{Fault, FaultKind};
use crate::error::{Error, Result};
use crate::output::io::{CsvWriter, write_atomic, write_json};
use crate::scene::builtin::find as find_builtin;
use crate::scene::{Budget, Scene};
use crate::verify::{Ensembles, VerifyOptions, run_verification};
use crate::work::WorkLimits;
use serde::Serialize;
use statrs::distribution::{Beta, ContinuousCDF};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The first seed of a power study; seed `j` (0-based) is `FIRST_SEED + j`.
pub const FIRST_SEED: u64 = 16_000;

/// The detection rate a size must reach to count as detected ("in ≥ 95 % of seeds").
pub const POWER_TARGET: f64 = 0.95;

/// The seeds of a study of `n` seeds: `FIRST_SEED, FIRST_SEED + 1, …`.
pub fn seeds(n: u64) -> Vec<u64> {
    (0..n).map(|j| FIRST_SEED + j).collect()
}

/// One scene a fault is measured in, optionally restricted to some of its runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// The built-in scene.
    pub scene: &'static str,
    /// The runs kept (all if empty).
    pub runs: &'static [&'static str],
}

/// The scenes each fault is measured in: the cheapest that exercise it; noise variance
/// and stiffness errors in every default scene (the smallest detectable size per scene).
/// To keep `make power` within about 30 minutes on 2 cores, the linear finite-element
/// scenes are restricted to one run each: their Crank–Nicolson run (consistent noise;
/// `hinged-linear-2d` takes about 10 s a quick verify in full), and the exact-modal run
/// (element-uniform noise) for the time-scaling fault, which acts on the exact update's
/// gains.
pub fn targets(kind: FaultKind) -> Vec<Target> {
    const ALL: &[&str] = &[];
    const CN: &[&str] = &["crank-nicolson"];
    let t = |scene, runs| Target { scene, runs };
    match kind {
        FaultKind::NoiseVariance | FaultKind::IntegratorStiffness => vec![
            t("hinged-linear-3d", CN),
            t("hinged-linear-2d", CN),
            t("actin-10um", CN),
            t("spectral-reference", ALL),
            t("compression-2d", ALL),
            t("compression-3d", ALL),
            t("tension-2d", ALL),
            t("membrane-hinged", CN),
            t("membrane-periodic", CN),
            t("membrane-spectral", ALL),
            t("membrane-area-stiff", ALL),
            t("grafted-clamped-free", CN),
            t("microtubule-free-free", CN),
        ],
        FaultKind::NoiseTimeScaling => vec![t("hinged-linear-3d", &["exact-modal"])],
        FaultKind::IntegratorDrag | FaultKind::SharedStiffness => vec![
            t("hinged-linear-3d", CN),
            t("membrane-hinged", CN),
            t("membrane-periodic", CN),
            t("microtubule-free-free", CN),
        ],
        // Other ends (issue #29): the hinge of a pinned–free filament on its rotation.
        FaultKind::IntegratorHinge | FaultKind::SharedHinge => {
            vec![t("hinged-linear-3d", CN), t("pinned-free-2d", CN)]
        }
        FaultKind::CorrelatedNoise | FaultKind::ComponentNoiseSharing => {
            vec![t("hinged-linear-3d", CN)]
        }
        // The modal chains' proposal force: every compression scene.
        FaultKind::ProposalForce => vec![
            t("compression-2d", ALL),
            t("compression-3d", ALL),
            t("tension-2d", ALL),
            t("membrane-area-soft", ALL),
            t("membrane-area-stiff", ALL),
        ],
        // The stretch rigidity matters most in tension (F ≈ EA·ε there): tension-2d.
        FaultKind::VonKarmanStrain | FaultKind::AxialStretchRigidity => {
            vec![
                t("compression-2d", ALL),
                t("tension-2d", ALL),
                t("membrane-area-soft", ALL),
                t("membrane-area-stiff", ALL),
            ]
        }
    }
}

/// The options of a power study.
#[derive(Debug, Clone)]
pub struct PowerOptions {
    /// The faults measured.
    pub faults: Vec<FaultKind>,
    /// The target scenes measured (by name; empty: every target of each fault).
    pub scenes: Vec<String>,
    /// Seeds per size.
    pub seeds: u64,
    /// The verification budget.
    pub budget: Budget,
    /// Family-wise α of each scene's verification.
    pub alpha: f64,
    /// Output directory (`power.csv`, `power.json`, `power.md`; a scratch directory for
    /// the verifications, removed at the end).
    pub out: PathBuf,
    /// Print progress on stderr: a line per row, and within a row at most one every
    /// [`crate::progress::LINE_INTERVAL`] (off with `--quiet`).
    pub progress: bool,
    /// Measure each fault at its stated size only, not the ladder (to compare budgets: the
    /// checks failed per seed at the size a careless bug has).
    pub stated_only: bool,
}

/// One fault, scene and size over the seeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerRow {
    /// The fault's name.
    pub fault: String,
    /// The scene.
    pub scene: String,
    /// The runs kept (empty: all).
    pub runs: Vec<String>,
    /// The fault's size.
    pub size: f64,
    /// Whether this is the stated size.
    pub stated: bool,
    /// Seeds verified.
    pub seeds: u64,
    /// Seeds whose verification failed its checks (exit-1 class).
    pub failed_checks: u64,
    /// Failed checks per seed, on average over the seeds (a run failure counts none): how
    /// strongly the budget detects the fault, comparable between budgets.
    pub mean_failed_checks: f64,
    /// Seeds whose run failed (exit 3).
    pub run_failures: u64,
    /// Seeds refused as bad input (exit 2): a fault should never cause one.
    pub input_errors: u64,
    /// (failed checks + run failures + input errors) / seeds.
    pub detection_rate: f64,
    /// Clopper–Pearson 95 % interval of the detection rate.
    pub interval: [f64; 2],
    /// The checks that failed most often, `name: count`, at most five.
    pub top_failed_checks: Vec<String>,
    /// The first error message of a failed run, if any.
    pub first_error: Option<String>,
    /// Mean wall time of one verification, in seconds.
    pub mean_seconds: f64,
}

/// The result of a power study (`power.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerReport {
    /// Budget of every verification.
    pub budget: String,
    /// Family-wise α of each verification.
    pub alpha: f64,
    /// The seeds, the same for every fault and size.
    pub seeds: Vec<u64>,
    /// The rate that counts as detected.
    pub target_rate: f64,
    /// Every fault, scene and size.
    pub rows: Vec<PowerRow>,
    /// Per fault and scene: the smallest size detected in at least `target_rate` of the
    /// seeds, `null` if none of the ladder was.
    pub smallest_detected: Vec<Smallest>,
    /// Wall time of the study, in seconds.
    pub wall_seconds: f64,
}

/// The smallest size of a fault detected in a scene in at least [`POWER_TARGET`] of seeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Smallest {
    /// The fault.
    pub fault: String,
    /// The scene.
    pub scene: String,
    /// The smallest detected size, if any.
    pub size: Option<f64>,
    /// The stated size of the fault.
    pub stated_size: f64,
    /// Whether the stated size is at or above the smallest detected size.
    pub stated_detected: bool,
}

/// The Clopper–Pearson (exact binomial) interval of `k` successes in `n` trials at
/// confidence `1 − alpha`: `[B(α/2; k, n−k+1), B(1−α/2; k+1, n−k)]` with `B` the Beta
/// quantile, 0 for `k = 0` and 1 for `k = n`.
///
/// # Errors
/// [`Error::InvalidParameter`] for `n = 0`, `k > n` or `alpha` outside (0, 1).
pub fn clopper_pearson(k: u64, n: u64, alpha: f64) -> Result<[f64; 2]> {
    if n == 0 || k > n {
        return Err(Error::invalid(
            "k of n",
            format!("{k} of {n}"),
            "0 <= k <= n, n >= 1",
        ));
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::invalid("alpha", alpha, "in (0, 1)"));
    }
    let (kf, nf) = (k as f64, n as f64);
    let beta = |a: f64, b: f64, p: f64| -> Result<f64> {
        Beta::new(a, b)
            .map(|d| d.inverse_cdf(p))
            .map_err(|e| Error::invalid("Beta parameters", format!("({a}, {b})"), e.to_string()))
    };
    let low = if k == 0 {
        0.0
    } else {
        beta(kf, nf - kf + 1.0, alpha / 2.0)?
    };
    let high = if k == n {
        1.0
    } else {
        beta(kf + 1.0, nf - kf, 1.0 - alpha / 2.0)?
    };
    Ok([low, high])
}

/// The outcome of one verification.
enum Outcome {
    Passed,
    FailedChecks(Vec<String>),
    RunFailed(String),
    InputError(String),
}

/// The scene of `target` at seed `seed` with `fault` injected.
fn faulty_scene(target: &Target, fault: Fault, seed: u64) -> Result<Scene> {
    let builtin = find_builtin(target.scene).ok_or_else(|| {
        Error::invalid(
            "power scene",
            target.scene,
            "a built-in scene (langevin-fem list)",
        )
    })?;
    let mut scene = builtin.load()?;
    if !target.runs.is_empty() {
        scene
            .runs
            .retain(|r| target.runs.contains(&r.name.as_str()));
        if let Some(c) = &mut scene.compression {
            c.halving = None;
        }
    }
    scene.seed = seed;
    Ok(scene.with_fault(fault))
}

/// Verifies `scene` once into `scratch` and classifies the result.
fn verify_once(scene: Scene, opts: &PowerOptions, scratch: &std::path::Path) -> Outcome {
    let result = run_verification(&VerifyOptions {
        scenes: vec![scene],
        budget: opts.budget,
        out: scratch.to_path_buf(),
        alpha: opts.alpha,
        progress: crate::progress::ProgressOptions::HIDDEN,
        limits: WorkLimits::default(),
        ensembles: Ensembles::Simulate,
    });
    match result {
        Ok((summary, _report)) if summary.passed => Outcome::Passed,
        Ok((summary, _report)) => Outcome::FailedChecks(
            summary
                .scenes
                .iter()
                .flat_map(|s| s.checks.iter().filter(|c| !c.passed))
                .map(|c| c.name.clone())
                .collect(),
        ),
        Err(e) if e.exit_code() == 2 => Outcome::InputError(e.to_string()),
        Err(e) => Outcome::RunFailed(e.to_string()),
    }
}

/// One row: `fault` in `target` over `seeds`.
fn measure(
    target: &Target,
    fault: Fault,
    seeds: &[u64],
    opts: &PowerOptions,
    scratch: &std::path::Path,
) -> Result<PowerRow> {
    let start = Instant::now();
    let (mut failed, mut crashed, mut refused) = (0u64, 0u64, 0u64);
    let mut names: BTreeMap<String, u64> = BTreeMap::new();
    let mut total_failed = 0u64;
    let mut first_error = None;
    let mut last_line = Instant::now();
    for (k, &seed) in seeds.iter().enumerate() {
        if opts.progress && last_line.elapsed() >= crate::progress::LINE_INTERVAL {
            last_line = Instant::now();
            eprintln!(
                "progress: {} s = {} in {}: seed {} of {}, elapsed {}",
                fault.kind.name(),
                fault.size,
                target.scene,
                k + 1,
                seeds.len(),
                crate::progress::fmt_seconds(start.elapsed().as_secs_f64())
            );
        }
        match verify_once(faulty_scene(target, fault, seed)?, opts, scratch) {
            Outcome::Passed => {}
            Outcome::FailedChecks(checks) => {
                failed += 1;
                total_failed += checks.len() as u64;
                for c in checks {
                    *names.entry(c).or_default() += 1;
                }
            }
            Outcome::RunFailed(e) => {
                crashed += 1;
                first_error.get_or_insert(e);
            }
            Outcome::InputError(e) => {
                refused += 1;
                first_error.get_or_insert(e);
            }
        }
    }
    let n = seeds.len() as u64;
    let detected = failed + crashed + refused;
    let mut top: Vec<(String, u64)> = names.into_iter().collect();
    top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    Ok(PowerRow {
        fault: fault.kind.name().to_string(),
        scene: target.scene.to_string(),
        runs: target.runs.iter().map(|r| r.to_string()).collect(),
        size: fault.size,
        stated: fault.size == fault.kind.stated_size(),
        seeds: n,
        failed_checks: failed,
        mean_failed_checks: total_failed as f64 / n as f64,
        run_failures: crashed,
        input_errors: refused,
        detection_rate: detected as f64 / n as f64,
        interval: clopper_pearson(detected, n, 0.05)?,
        top_failed_checks: top
            .into_iter()
            .take(5)
            .map(|(c, k)| format!("{c}: {k}"))
            .collect(),
        first_error,
        mean_seconds: start.elapsed().as_secs_f64() / n as f64,
    })
}

/// Per fault and scene, the smallest size of `rows` detected in at least
/// [`POWER_TARGET`] of seeds.
fn smallest_detected(rows: &[PowerRow]) -> Vec<Smallest> {
    let mut out: Vec<Smallest> = Vec::new();
    for r in rows {
        let kind: FaultKind = match r.fault.parse() {
            Ok(k) => k,
            Err(_) => continue,
        };
        let i = match out
            .iter()
            .position(|s| s.fault == r.fault && s.scene == r.scene)
        {
            Some(i) => i,
            None => {
                out.push(Smallest {
                    fault: r.fault.clone(),
                    scene: r.scene.clone(),
                    size: None,
                    stated_size: kind.stated_size(),
                    stated_detected: false,
                });
                out.len() - 1
            }
        };
        if r.detection_rate >= POWER_TARGET {
            let s = &mut out[i];
            s.size = Some(s.size.map_or(r.size, |x: f64| x.min(r.size)));
        }
    }
    // A stated size above the smallest detected one counts as detected (detection grows
    // with the size; the ladder does not run sizes above one detected in every seed).
    for s in &mut out {
        s.stated_detected = s.size.is_some_and(|x| x <= s.stated_size);
    }
    out
}

/// Runs the power study (progress on stderr if `opts.progress`) and writes `power.csv`, `power.json` and
/// `power.md` to `opts.out`.
///
/// # Errors
/// [`Error::InvalidParameter`] for no seeds; I/O failures writing the outputs.
pub fn run_power(opts: &PowerOptions) -> Result<PowerReport> {
    if opts.seeds == 0 {
        return Err(Error::invalid("--seeds", 0, "at least 1"));
    }
    let start = Instant::now();
    let seeds = seeds(opts.seeds);
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::io(&opts.out, e))?;
    let scratch = opts.out.join(".verify-scratch");
    // Progress lines on stderr, unless quiet.
    let say = |line: String| {
        if opts.progress {
            eprintln!("{line}");
        }
    };
    say(format!(
        "power: budget {}, alpha {}, seeds {}..={} ({} per size)",
        opts.budget.name(),
        opts.alpha,
        seeds[0],
        seeds[seeds.len() - 1],
        seeds.len()
    ));
    let mut rows = Vec::new();
    for &kind in &opts.faults {
        let chosen = targets(kind)
            .into_iter()
            .filter(|t| opts.scenes.is_empty() || opts.scenes.iter().any(|s| s == t.scene));
        for target in chosen {
            let sizes = if opts.stated_only {
                vec![kind.stated_size()]
            } else {
                kind.ladder()
            };
            for size in sizes {
                // Detection grows with the size: once a size is detected in every seed,
                // the larger ones are not run (saves most of the study's time).
                if rows.last().is_some_and(|r: &PowerRow| {
                    r.fault == kind.name() && r.scene == target.scene && r.detection_rate == 1.0
                }) {
                    say(format!(
                        "{:<24} {:<20} s = {:<8} not run: a smaller size was detected in every seed",
                        kind.name(),
                        target.scene,
                        size
                    ));
                    continue;
                }
                let fault = Fault::new(kind, size)?;
                let row = measure(&target, fault, &seeds, opts, &scratch)?;
                say(format!(
                    "{:<24} {:<20} s = {:<8} detected {:>3}/{} (checks {}, {:.1} failed checks per seed, run failures {}, input errors {}) [{:.2}, {:.2}]  {:.1} s/seed",
                    kind.name(),
                    target.scene,
                    size,
                    row.failed_checks + row.run_failures + row.input_errors,
                    row.seeds,
                    row.failed_checks,
                    row.mean_failed_checks,
                    row.run_failures,
                    row.input_errors,
                    row.interval[0],
                    row.interval[1],
                    row.mean_seconds
                ));
                rows.push(row);
            }
        }
    }
    if scratch.exists() {
        std::fs::remove_dir_all(&scratch).map_err(|e| Error::io(&scratch, e))?;
    }
    let report = PowerReport {
        budget: opts.budget.name().to_string(),
        alpha: opts.alpha,
        seeds,
        target_rate: POWER_TARGET,
        smallest_detected: smallest_detected(&rows),
        rows,
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    write_json(&opts.out.join("power.json"), &report)?;
    let csv = opts.out.join("power.csv");
    write_atomic(&csv, csv_text(&report)?.as_bytes())?;
    let md = opts.out.join("power.md");
    write_atomic(&md, markdown(&report).as_bytes())?;
    Ok(report)
}

/// `power.csv`: one line per row.
fn csv_text(report: &PowerReport) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        Path::new("power.csv"),
        &[
            "fault",
            "scene",
            "runs",
            "size",
            "stated",
            "seeds",
            "failed_checks",
            "mean_failed_checks",
            "run_failures",
            "input_errors",
            "detection_rate",
            "ci_low",
            "ci_high",
            "mean_seconds",
        ],
    )?;
    for r in &report.rows {
        table.record([
            r.fault.to_string(),
            r.scene.to_string(),
            if r.runs.is_empty() {
                "all".to_string()
            } else {
                r.runs.join(" ")
            },
            r.size.to_string(),
            r.stated.to_string(),
            r.seeds.to_string(),
            r.failed_checks.to_string(),
            r.mean_failed_checks.to_string(),
            r.run_failures.to_string(),
            r.input_errors.to_string(),
            r.detection_rate.to_string(),
            r.interval[0].to_string(),
            r.interval[1].to_string(),
            format!("{:.3}", r.mean_seconds),
        ])?;
    }
    table.into_string()
}

/// `power.md`: the rows as a markdown table, then the smallest detected sizes.
fn markdown(report: &PowerReport) -> String {
    let mut s = format!(
        "Power at the {} budget (family-wise alpha {} per scene), {} seeds per size ({}..={}); \
         detected = the scene fails its checks, or (weak, counted apart) the run fails or is refused; \
         95 % Clopper-Pearson intervals; sizes above one detected in every seed are not run. \
         Wall time {:.0} s.\n\n",
        report.budget,
        report.alpha,
        report.seeds.len(),
        report.seeds.first().copied().unwrap_or(0),
        report.seeds.last().copied().unwrap_or(0),
        report.wall_seconds
    );
    s.push_str("| fault | scene (runs) | size | detected | checks / run failed / refused | failed checks per seed | 95 % interval |\n");
    s.push_str("|---|---|---|---|---|---|---|\n");
    for r in &report.rows {
        let runs = if r.runs.is_empty() {
            String::new()
        } else {
            format!(" ({})", r.runs.join(", "))
        };
        s.push_str(&format!(
            "| {} | {}{} | {}{} | {}/{} | {} / {} / {} | {:.1} | [{:.2}, {:.2}] |\n",
            r.fault,
            r.scene,
            runs,
            r.size,
            if r.stated { " (stated)" } else { "" },
            r.failed_checks + r.run_failures + r.input_errors,
            r.seeds,
            r.failed_checks,
            r.run_failures,
            r.input_errors,
            r.mean_failed_checks,
            r.interval[0],
            r.interval[1]
        ));
    }
    s.push_str(&format!(
        "\nSmallest size detected in at least {:.0} % of seeds:\n\n| fault | scene | smallest detected | stated | stated detected |\n|---|---|---|---|---|\n",
        100.0 * report.target_rate
    ));
    for m in &report.smallest_detected {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            m.fault,
            m.scene,
            m.size
                .map_or("none of the ladder".to_string(), |x| x.to_string()),
            m.stated_size,
            if m.stated_detected { "yes" } else { "no" }
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Clopper–Pearson against known values: 0 of 20 gives [0, 0.1684] (the upper bound
    /// is 1 − 0.025^(1/20)); 20 of 20 gives [0.8316, 1]; 10 of 20 is symmetric about ½
    /// ([0.2720, 0.7280], R's binom.test).
    #[test]
    fn clopper_pearson_known_values() {
        let [lo, hi] = clopper_pearson(0, 20, 0.05).unwrap();
        assert_eq!(lo, 0.0);
        assert!(
            (hi - (1.0 - 0.025f64.powf(1.0 / 20.0))).abs() < 1e-9,
            "{hi}"
        );
        let [lo, hi] = clopper_pearson(20, 20, 0.05).unwrap();
        assert!((lo - 0.025f64.powf(1.0 / 20.0)).abs() < 1e-9, "{lo}");
        assert_eq!(hi, 1.0);
        let [lo, hi] = clopper_pearson(10, 20, 0.05).unwrap();
        assert!(
            (lo - 0.2720).abs() < 1e-4 && (hi - 0.7280).abs() < 1e-4,
            "{lo} {hi}"
        );
        assert!(clopper_pearson(3, 2, 0.05).is_err());
        assert!(clopper_pearson(0, 0, 0.05).is_err());
    }

    /// Every target is a built-in scene the fault has a hook in, and keeps at least one
    /// run.
    #[test]
    fn targets_exercise_their_faults() {
        for kind in FaultKind::ALL {
            for t in targets(kind) {
                let scene = faulty_scene(&t, Fault::stated(kind), 1).unwrap();
                assert!(
                    kind.applies_to(scene.model, scene.dims, scene.is_membrane()),
                    "{kind} in {}",
                    t.scene
                );
                assert!(!scene.runs.is_empty(), "{kind} in {}", t.scene);
                assert_eq!(scene.fault, Some(Fault::stated(kind)));
            }
            assert!(kind.ladder().contains(&kind.stated_size()), "{kind}");
        }
    }

    /// The smallest detected size is the smallest row at or above the target rate.
    #[test]
    fn smallest_detected_picks_the_smallest_size_at_target() {
        let row = |size: f64, rate: f64| PowerRow {
            fault: "noise-variance".into(),
            scene: "s".into(),
            runs: vec![],
            size,
            stated: size == FaultKind::NoiseVariance.stated_size(),
            seeds: 20,
            failed_checks: 0,
            mean_failed_checks: 0.0,
            run_failures: 0,
            input_errors: 0,
            detection_rate: rate,
            interval: [0.0, 1.0],
            top_failed_checks: vec![],
            first_error: None,
            mean_seconds: 0.0,
        };
        let m = smallest_detected(&[row(0.025, 0.5), row(0.05, 0.95), row(0.1, 1.0)]);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].size, Some(0.05));
        assert!(m[0].stated_detected);
        let m = smallest_detected(&[row(0.1, 0.9)]);
        assert_eq!(m[0].size, None);
        assert!(!m[0].stated_detected);
    }
}
