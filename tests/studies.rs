//! Tests of the stability map (`langevin-fem stability`), the work–precision study
//! (`langevin-fem work-precision`) and the extreme scenes' failure messages. A few seconds
//! in all.

mod common;

use common::{TempDir, scene};
use langevin_fem::dynamics::IntegratorKind;
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::studies::stability::{StabilityOptions, StabilitySummary, Status, run_stability};
use langevin_fem::studies::work_precision::{
    WorkPrecisionOptions, WorkPrecisionSummary, run_work_precision,
};
use langevin_fem::work::WorkLimits;

/// The map of every linear integrator on `scene` at `elements` elements and a = 1 and
/// 2.1, 4 trajectories × 20000 sampled steps after 5000, α = 0.01, written to `dir`.
fn small_map(scene_file: &str, elements: usize, dir: &TempDir) -> StabilitySummary {
    run_stability(&StabilityOptions {
        scene: scene(scene_file),
        integrators: IntegratorKind::LINEAR.to_vec(),
        elements: vec![elements],
        dt_lambda_max: vec![1.0, 2.1],
        trajectories: 4,
        sampled_steps: 20_000,
        burn_in_steps: 5_000,
        alpha: 0.01,
        out: dir.path().to_path_buf(),
        progress: false,
        limits: WorkLimits::default(),
    })
    .expect("study runs")
}

/// A small map: each integrator's measured per-mode stationary variance agrees with its
/// exact discrete-time formula (no Holm rejection), and the classification rejects the
/// wrong answer "no bias" where the formula predicts one: Euler–Maruyama at λΔt = 1
/// doubles the fastest mode's variance (ratio 2) and backward Euler multiplies it by 2/3,
/// both "biased"; Crank–Nicolson and the exact update are "stable" at the same steps; past
/// the explicit limit (a = 2.1) Euler–Maruyama is refused and, forced, overflows.
/// Set-up: 5 elements, 4 trajectories × 20000 sampled steps, α = 0.01.
/// Tolerance: no Holm rejection at α = 0.01 among the formula tests; the fastest mode's
/// formula ratio 2 to 10⁻¹² (closed form) and its measured ratio within 4 standard errors.
#[test]
fn stability_map_classifies_and_matches_the_exact_formulas() {
    let dir = TempDir::new("stability");
    let s = small_map("verification/hinged-linear-2d.toml", 5, &dir);
    assert_eq!(s.formula_rejections, 0, "{:#?}", s.cells);
    assert!(s.formula_tests >= 6);
    assert!(s.stability_as_predicted);
    let cell = |k: IntegratorKind, a: f64| {
        s.cells
            .iter()
            .find(|c| c.integrator == k.name() && c.dt_lambda_max == a)
            .expect("cell")
    };
    use IntegratorKind::*;
    assert_eq!(cell(EulerMaruyama, 1.0).status, Status::Biased);
    assert_eq!(cell(BackwardEuler, 1.0).status, Status::Biased);
    assert_eq!(cell(CrankNicolson, 1.0).status, Status::Stable);
    assert_eq!(cell(ExactModal, 2.1).status, Status::Stable);
    let em = cell(EulerMaruyama, 2.1);
    assert_eq!(em.status, Status::Unstable);
    assert!(em.refused.as_deref().unwrap().contains("stability limit"));
    assert!(em.diverged_at.is_some());
    // The fastest mode of Euler–Maruyama at a = 1: ratio 1/(1 − 1/2) = 2.
    let top = cell(EulerMaruyama, 1.0).modes.last().unwrap();
    assert!((top.lambda_dt - 1.0).abs() < 1e-12);
    assert!((top.formula_ratio - 2.0).abs() < 1e-12);
    assert!((top.measured_ratio - 2.0).abs() < 4.0 * top.std_error);
    for f in [
        "stability.json",
        "stability-cells.csv",
        "stationary-bias.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
}

/// The work–precision study of Crank–Nicolson with both noise models on `scene` at
/// Δt/τ1 = 1e-2 and 3e-3, 4 trajectories × 40 τ1 per point, at `tolerance`, written to
/// `dir`.
fn small_study(scene_file: &str, tolerance: f64, dir: &TempDir) -> WorkPrecisionSummary {
    run_work_precision(&WorkPrecisionOptions {
        scene: scene(scene_file),
        methods: vec![
            (IntegratorKind::CrankNicolson, NoiseModel::Consistent),
            (IntegratorKind::CrankNicolson, NoiseModel::ElementUniform),
        ],
        dt_tau1: vec![1e-2, 3e-3],
        em_fractions: vec![0.9],
        trajectories: 4,
        duration_tau1: 40.0,
        em_duration_tau1: 16.0,
        tolerance,
        out: dir.path().to_path_buf(),
        progress: false,
        limits: WorkLimits::default(),
    })
    .expect("study runs")
}

/// Crank–Nicolson with consistent noise has zero exact bias in ⟨w²(L/2)⟩ (nodal
/// covariance kT K⁻¹ is exact for Hermite cubics, the scheme's stationary law exact);
/// the paper's element-uniform noise keeps its spatial deficit at any Δt. Every estimate
/// agrees with its exact discrete value, and only the unbiased method reaches a
/// tolerance below the element-uniform bias.
/// Tolerance: consistent-noise bias below 10⁻⁹ relative (round-off of exact formulas);
/// element-uniform bias above 5·10⁻³, the requested tolerance 0.005.
#[test]
fn work_precision_separates_bias_from_sampling() {
    let dir = TempDir::new("work-precision");
    let s = small_study("verification/hinged-linear-2d.toml", 0.005, &dir);
    assert_eq!(s.points.len(), 4);
    assert_eq!(s.inconsistent_points, 0, "{:#?}", s.points);
    for p in &s.points {
        if p.noise == "consistent" {
            assert!(p.rel_bias < 1e-9, "{p:?}");
        } else {
            assert!(p.rel_bias > 5e-3, "{p:?}");
        }
    }
    let consistent = &s.methods[0];
    assert!(consistent.seconds_to_tolerance.is_some());
    assert_eq!(consistent.relative_cost, Some(1.0));
    assert!(s.methods[1].seconds_to_tolerance.is_none());
    assert!(s.methods[1].note.contains("cannot reach"));
    assert!(dir.join("work-precision.json").exists());
}

/// The membrane's plate (issue #27) goes through the same map and study: on a 4 × 4
/// simply supported plate the measured per-mode variances agree with each integrator's
/// exact formula, Euler–Maruyama doubles the fastest mode's variance at λΔt = 1 and is
/// refused (and overflows when forced) at 2.1, Crank–Nicolson is stable; in the
/// work–precision study every estimate of ⟨h²⟩ at the centre agrees with its exact
/// discrete value, and the paper's element-uniform load keeps a larger bias than the
/// consistent noise (the plate's own spatial error) at every Δt.
/// Set-up: `verification/membrane-hinged.toml` (a unit square, κ = ξ = kT = 1), 4
/// trajectories × 20000 steps per cell; the study 4 trajectories × 40 τ₁ per point.
/// Tolerance: no Holm rejection at α = 0.01; the formula ratio 2 to 10⁻¹²; the measured
/// ratio within 4 standard errors; no point beyond 3 s.e. of its discrete value.
#[test]
fn the_membrane_maps_and_studies_like_the_filament() {
    let dir = TempDir::new("stability-membrane");
    let s = small_map("verification/membrane-hinged.toml", 4, &dir);
    assert_eq!(s.formula_rejections, 0, "{:#?}", s.cells);
    assert!(s.stability_as_predicted);
    let cell = |k: IntegratorKind, a: f64| {
        s.cells
            .iter()
            .find(|c| c.integrator == k.name() && c.dt_lambda_max == a)
            .expect("cell")
    };
    use IntegratorKind::*;
    assert_eq!(cell(EulerMaruyama, 2.1).status, Status::Unstable);
    assert!(cell(EulerMaruyama, 2.1).diverged_at.is_some());
    assert_eq!(cell(CrankNicolson, 1.0).status, Status::Stable);
    let top = cell(EulerMaruyama, 1.0).modes.last().unwrap();
    assert!((top.formula_ratio - 2.0).abs() < 1e-12);
    assert!(
        (top.measured_ratio - 2.0).abs() < 4.0 * top.std_error,
        "{top:?}"
    );

    let wp = TempDir::new("work-precision-membrane");
    let w = small_study("verification/membrane-hinged.toml", 0.01, &wp);
    assert_eq!(w.observable, "h2(a/2,b/2)");
    assert_eq!(w.points.len(), 4);
    assert_eq!(w.inconsistent_points, 0, "{:#?}", w.points);
    for (c, u) in w.points[..2].iter().zip(&w.points[2..]) {
        assert_eq!(
            (c.noise.as_str(), u.noise.as_str()),
            ("consistent", "element-uniform")
        );
        assert!(u.rel_bias > 10.0 * c.rel_bias, "{c:?} {u:?}");
    }
}

/// Bad options exit with code 2 naming the flag. Tolerance: exact substrings.
#[test]
fn studies_refuse_bad_options() {
    for (args, flag) in [
        (vec!["stability", "--elements", "1"], "--elements"),
        (vec!["stability", "--dt-lambda-max", "0"], "--dt-lambda-max"),
        (
            vec!["stability", "--integrators", "leapfrog"],
            "--integrators",
        ),
        (
            vec!["work-precision", "--methods", "crank-nicolson/white"],
            "--methods",
        ),
        (vec!["work-precision", "--tolerance", "0"], "--tolerance"),
        (vec!["stability", "--scene", "compression-2d"], "--scene"),
    ] {
        let tmp = TempDir::new("bad");
        let out = common::command()
            .args(&args)
            .args(["--out", tmp.path().to_str().unwrap()])
            .output()
            .expect("binary runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err}");
    }
}

/// EA L/kT = 1e9 (nearly inextensible): Metropolis CN, whose proposal carries the
/// tension, mixes (acceptance well above the sticky-chain level of 0.2) and passes its
/// checks against the exact theory; Crank–Nicolson with the stretching force explicit
/// diverges and the run stops with an error naming the step (exit 3), writing no
/// numbers.
#[test]
fn huge_stretch_rigidity_metropolis_works_and_explicit_stops_naming_the_step() {
    let (out, dir) = verify_scene("verification/extreme/compression-stiff-ea-2d.toml", "ea");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).expect("summary"))
            .expect("json");
    let notes = summary["scenes"][0]["notes"].to_string();
    let rate: f64 = notes
        .split("acceptance ")
        .nth(1)
        .and_then(|t| t.split(';').next())
        .and_then(|t| t.parse().ok())
        .expect("acceptance in the notes");
    assert!(rate > 0.2, "acceptance {rate}: {notes}");
    let (out, dir) = verify_scene(
        "verification/extreme/compression-stiff-ea-explicit-2d.toml",
        "ea-explicit",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(err.contains("unstable at step"), "{err}");
    assert!(err.contains("crank-nicolson"), "{err}");
    assert!(
        !dir.join("summary.json").exists(),
        "numbers written for a diverged run"
    );
}

/// The small-slope warning under compression: the floppy compression scene
/// (EI/(kT L) = 1) passes its checks against the exact theory of its own (von Kármán)
/// model, and its summary warns with the measured RMS slope (> 0.2 rad); the paper's
/// scene (EI/(kT L) = 100) measures its slope (a note) but stays below the limit (no
/// warning).
#[test]
fn compression_runs_measure_the_slope_and_warn_when_floppy() {
    let summary = |scene: &str, tag: &str| {
        let (out, dir) = verify_scene(scene, tag);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join("summary.json")).expect("summary"),
        )
        .expect("json");
        v["scenes"][0].clone()
    };
    let floppy = summary(
        "verification/extreme/compression-floppy-2d.toml",
        "floppy-c",
    );
    let w = floppy["warnings"].to_string();
    assert!(
        w.contains("measured RMS slope") && w.contains("exceeds 0.2 rad"),
        "{w}"
    );
    let paper = summary("compression-2d", "paper-c");
    assert!(
        paper["warnings"].as_array().unwrap().is_empty(),
        "{}",
        paper["warnings"]
    );
    assert!(paper["notes"].to_string().contains("largest RMS slope"));
}

/// Runs `langevin-fem verify --scene SCENE` (quick budget) into a fresh directory, which
/// lives as long as the returned [`TempDir`].
fn verify_scene(scene: &str, tag: &str) -> (std::process::Output, TempDir) {
    let dir = TempDir::new(tag);
    let out = common::run(&[
        "verify",
        "--scene",
        scene,
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    (out, dir)
}
