//! The filament with other ends through the linear pipeline (issue #29): the scenes'
//! references against closed forms, the rigid modes' exact diffusion laws, and the
//! `rigid-diffusion` check accepting the simulation and rejecting a wrong law.

use langevin_fem::scene::Scene;
use langevin_fem::scene::builtin;
use langevin_fem::scene::linear::LinearRun;
use langevin_fem::verify::checks::linear_checks;

fn scene(name: &str) -> Scene {
    builtin::find(name)
        .expect("built-in")
        .load()
        .expect("scene loads")
}

/// The grafted filament's tip: continuum ⟨w²(L)⟩ = kT L³/(3EI) (closed form, here 1/3),
/// and the model's exact reference equal to it at the node (Hermite cubics are nodally
/// exact); its τ₁ is the cantilever's, ξL⁴/(EI·1.8751⁴).
#[test]
fn grafted_tip_variance_is_kt_l3_over_3ei() {
    let s = scene("grafted-clamped-free");
    let run = LinearRun::prepare(&s, &s.runs[1]).expect("crank-nicolson prepares");
    let r = &run.reference;
    let tip = r
        .profile_x
        .iter()
        .position(|&x| x == 1.0)
        .expect("tip point");
    assert!(
        (r.profile_continuum[tip] - 1.0 / 3.0).abs() < 1e-14,
        "{}",
        r.profile_continuum[tip]
    );
    assert!((r.profile_discrete[tip] / r.profile_continuum[tip] - 1.0).abs() < 1e-9);
    let beta1: f64 = 1.875_104_068_711_961;
    assert!(
        (s.tau1() * beta1.powi(4) - 1.0).abs() < 1e-12,
        "{}",
        s.tau1()
    );
    assert!(r.rigid.is_empty());
}

/// The free–free microtubule's rigid modes: with consistent noise each amplitude
/// r = ψᵀCw diffuses at exactly 2kT; the element-uniform load gives the translation
/// exactly 2kT (the load integrates constants exactly) and the rotation less (it misses
/// the within-element variation of a linear function, by (h²/12)·ψ'²-weighted ∫).
#[test]
fn rigid_modes_have_their_exact_diffusion_laws() {
    let s = scene("microtubule-free-free");
    let kt = s.filament.kt;
    let cn = LinearRun::prepare(&s, &s.runs[0]).expect("crank-nicolson prepares");
    assert_eq!(cn.reference.rigid.len(), 2);
    for law in &cn.reference.rigid {
        assert!(
            (law.diffusion_discrete / (2.0 * kt) - 1.0).abs() < 1e-9,
            "{law:?}"
        );
        assert_eq!(law.diffusion_continuum, 2.0 * kt);
        assert!(law.simulated);
    }
    let eu = LinearRun::prepare(&s, &s.runs[1]).expect("element-uniform prepares");
    let [t, rot] = [&eu.reference.rigid[0], &eu.reference.rigid[1]];
    assert!(
        (t.diffusion_discrete / (2.0 * kt) - 1.0).abs() < 1e-9,
        "{t:?}"
    );
    // Rotation ψ ∝ x − L/2 on 8 elements: deficit Σ_e h³ψ'²/12 / ∫ψ² = (h/L)² = 1/64.
    let deficit = 1.0 - rot.diffusion_discrete / (2.0 * kt);
    assert!((deficit - 1.0 / 64.0).abs() < 1e-9, "{deficit}");
}

/// `rigid-diffusion` on a simulated pinned–free filament passes against the exact law
/// and fails against a law 10 % too large (the rotation's diffusion), at the scene's
/// quick ensemble.
#[test]
fn rigid_diffusion_check_accepts_the_truth_and_rejects_a_wrong_law() {
    let s = scene("pinned-free-2d");
    let spec = &s.runs[0];
    let mut run = LinearRun::prepare(&s, spec).expect("prepares");
    let e = spec.quick;
    let steps = run.sampled_steps(e.duration_tau1 * s.tau1());
    let records = run
        .simulate_ensemble(s.seed, 0, e.trajectories as u64, steps, |_| {})
        .expect("ensemble");
    let kinds = [langevin_fem::scene::CheckKind::RigidDiffusion];
    let p_of = |run: &LinearRun| {
        let (out, _) = linear_checks(run, &kinds, &records, &[]).expect("checks");
        assert_eq!(out.len(), 1);
        out[0].p_value.expect("p-value")
    };
    let p = p_of(&run);
    assert!(p > 0.01, "the truth rejected: p = {p}");
    run.reference.rigid[0].diffusion_discrete *= 1.1;
    let p = p_of(&run);
    assert!(p < 1e-4, "a 10 % wrong law passes: p = {p}");
}
