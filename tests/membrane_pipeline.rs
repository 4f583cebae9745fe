//! The membrane through the filament's pipeline (issue #27, "one pipeline for both
//! objects"): a membrane scene file is prepared by the same `LinearRun` as a filament's —
//! the plate's `LinearSystem`, its separable modes ordered by the continuum's checked
//! modes, the exact discrete references of `DiscreteLaw` — and its ensemble is simulated by
//! the same driver, lockstep batches and observers.
//!
//! What: for the simply supported fixture (`tests/scenes/good/membrane-hinged.toml`, 8 × 8
//! plate elements, Crank–Nicolson with consistent noise) the references are the discrete
//! ones (mode rates above the continuum's by the O(h⁴) plate error, variance kT/λ_h: the
//! scheme's stationary variance is exact) and the continuum's beside them; the simulated
//! modal amplitudes' variances match the discrete references.
//! Reference: `DiscreteLaw` (discrete) and `spectral::membrane` (continuum).
//! Test: per checked mode, z = (estimate − reference)/s.e. with the autocorrelation-aware
//! standard error of `stats::mean_with_error` over 4 trajectories × 80 τ₁; |z| < 4 for
//! each of the 4 modes (fixed seed; family-wise false alarm below 4·6.3e-5), and the same
//! estimates reject a reference 30 % too large (|z| > 4 for the slowest mode).

use langevin_fem::scene::Scene;
use langevin_fem::scene::linear::{LinearRun, TrajectoryRecord};
use langevin_fem::stats;
use std::path::Path;

/// The simply supported membrane fixture.
fn scene() -> Scene {
    Scene::load(Path::new("tests/scenes/good/membrane-hinged.toml")).expect("fixture")
}

/// z = (estimate − reference)/s.e. of the variance of checked mode `i` over `records`:
/// per trajectory the time average of q² with its autocorrelation-aware standard error,
/// the independent trajectories combined.
fn variance_z(records: &[TrajectoryRecord], i: usize, reference: f64) -> f64 {
    let parts: Vec<_> = records
        .iter()
        .map(|rec| {
            let sq: Vec<f64> = rec.modes[i].iter().map(|q| q * q).collect();
            stats::mean_with_error(&sq).expect("estimate")
        })
        .collect();
    let (mean, se) = stats::combine_independent(&parts);
    (mean - reference) / se
}

#[test]
fn membrane_scene_runs_through_the_linear_pipeline() {
    let scene = scene();
    let spec = &scene.runs[0];
    let run = LinearRun::prepare(&scene, spec).expect("membrane run prepares");
    let r = &run.reference;
    assert_eq!(r.modes.len(), 4);
    for m in &r.modes {
        let rate = m.rate_discrete.expect("positive multiplier");
        // Crank–Nicolson: the discrete rate is −ln(m)/Δt of the plate's rate λ_h, the
        // variance exactly kT/λ_h; λ_h above the continuum's by the plate's O(h⁴) error.
        assert!((m.variance_discrete / m.variance_equipartition - 1.0).abs() < 1e-12);
        let lambda_h = 1.0 / m.variance_equipartition;
        assert!(lambda_h > m.rate_continuum && lambda_h < 1.01 * m.rate_continuum);
        assert!(rate > 0.0);
    }
    // The checked modes of a square, (1,1), (1,2), (2,1), (2,2): the middle pair share
    // their rate.
    assert_eq!(r.modes[1].rate_continuum, r.modes[2].rate_continuum);
    assert!(r.profile_discrete.iter().all(|v| *v > 0.0));
    let steps = run.sampled_steps(80.0 * scene.tau1());
    let records = run
        .simulate_ensemble(scene.seed, 0, 16, steps, |_| {})
        .expect("membrane ensemble");
    let nm = r.modes.len();
    let z_of = |i: usize, reference: f64| variance_z(&records, i, reference);
    for i in 0..nm {
        let z = z_of(i, r.modes[i].variance_discrete);
        assert!(z.abs() < 4.0, "mode {}: z = {z}", i + 1);
    }
    let wrong = z_of(0, 1.3 * r.modes[0].variance_discrete);
    assert!(
        wrong.abs() > 4.0,
        "a 30 % wrong reference passes: z = {wrong}"
    );
}

/// What: the membrane's spectral reference scene (the periodic 2 × 1 fixture under
/// tension, `model = "spectral"`: the exact modal simulator over 8 × 4 mode indices)
/// through the same pipeline: per-mode references are the continuum's (M3), the profile's
/// discrete reference is the exact sum over the simulated modes, below the continuum's
/// (the truncation removes positive terms), and the simulated amplitudes' variances
/// match (M3). Test: as above, |z| < 4 for each of the 6 checked modes (8 trajectories ×
/// 160 τ₁), and a reference 50 % too large is rejected for the slowest mode (its 8 × 350
/// samples, half a relaxation time apart, give a relative standard error near 7 %).
#[test]
fn membrane_spectral_scene_runs_through_the_linear_pipeline() {
    let scene = Scene::load(Path::new("tests/scenes/good/membrane-pbc.toml")).expect("fixture");
    let run = LinearRun::prepare(&scene, &scene.runs[0]).expect("spectral membrane prepares");
    let r = &run.reference;
    assert_eq!(r.modes.len(), 6);
    for (d, c) in r.profile_discrete.iter().zip(&r.profile_continuum) {
        assert!(*d > 0.0 && d < c, "truncated {d} vs continuum {c}");
    }
    let steps = run.sampled_steps(160.0 * scene.tau1());
    let records = run
        .simulate_ensemble(scene.seed, 0, 8, steps, |_| {})
        .expect("spectral membrane ensemble");
    let z_of = |i: usize, reference: f64| variance_z(&records, i, reference);
    for (i, m) in r.modes.iter().enumerate() {
        let z = z_of(i, m.variance_continuum);
        assert!(z.abs() < 4.0, "mode {}: z = {z}", i + 1);
    }
    let wrong = z_of(0, 1.5 * r.modes[0].variance_continuum);
    assert!(
        wrong.abs() > 4.0,
        "a 50 % wrong reference passes: z = {wrong}"
    );
}
