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

/// The tangent-angle cosine functional of Gittes et al. (1993) on a shape the Hermite
/// cubics hold exactly: w = x² on a free–free beam (θ = 2x) has
/// a_n = √(2/L)∫2x cos(nπx/L) dx = √(2/L)·2(L/nπ)²((−1)ⁿ − 1).
#[test]
fn tangent_cosine_functional_is_exact_on_a_quadratic() {
    use langevin_fem::fem::beam::BeamModel;
    use langevin_fem::fem::mesh::Mesh;
    use langevin_fem::params::{Ends, FilamentParams};
    let length = 2.0;
    let p = FilamentParams {
        length,
        ..FilamentParams::default()
    };
    let ends: Ends = "free-free".parse().expect("ends");
    let beam =
        BeamModel::with_ends(p, Mesh::uniform(length, 7).expect("mesh"), ends).expect("beam");
    let mut w = vec![0.0; beam.n_dofs()];
    for (node, &x) in beam.mesh().nodes().iter().enumerate() {
        w[beam.node_deflection_index(node).expect("free")] = x * x;
        w[beam.node_rotation_index(node).expect("free")] = 2.0 * x;
    }
    for n in 1..=12 {
        let f = beam.tangent_cosine_functional(n);
        let got: f64 = f.iter().zip(&w).map(|(a, b)| a * b).sum();
        let k = n as f64 * std::f64::consts::PI / length;
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        let exact = (2.0 / length).sqrt() * 2.0 / (k * k) * (sign - 1.0);
        assert!(
            (got - exact).abs() <= 1e-12 * (1.0 + exact.abs()),
            "n = {n}: {got} vs {exact}"
        );
    }
}

/// The tangent-angle references: the exact discrete variance of the free–free beam under
/// Crank–Nicolson with consistent noise (its stationary law is the discrete Gibbs law)
/// converges to the continuum kT L²/(EI n²π²) as the mesh is refined (rigid modes do not
/// enter), and the pinned–free filament's likewise; a coarse mesh lies off by more than
/// a fine one.
#[test]
fn tangent_angle_references_converge_to_the_continuum() {
    for name in ["microtubule-free-free", "pinned-free-2d"] {
        let mut s = scene(name);
        let mut errors = Vec::new();
        for elements in [4, 8, 32] {
            s.mesh.elements = elements;
            let run = LinearRun::prepare(&s, &s.runs[0]).expect("prepares");
            let t = &run.reference.tangent;
            assert_eq!(t.len(), s.sampling.modes, "{name}");
            let worst = t
                .iter()
                .map(|r| (r.variance_discrete / r.variance_continuum - 1.0).abs())
                .fold(0.0, f64::max);
            errors.push(worst);
            for r in t {
                assert!((r.correlation(0) - 1.0).abs() < 1e-12, "{r:?}");
            }
        }
        assert!(errors[2] < 2e-4, "{name}: {errors:?}");
        assert!(errors[0] > errors[2], "{name}: {errors:?}");
    }
}

/// `tangent-angle` on a simulated free–free microtubule passes against the exact
/// discrete variances and fails when they are 10 % too small (as if the bending rigidity
/// were 10 % too large in the references).
#[test]
fn tangent_angle_check_accepts_the_truth_and_rejects_a_wrong_rigidity() {
    let s = scene("microtubule-free-free");
    let spec = &s.runs[0];
    let mut run = LinearRun::prepare(&s, spec).expect("prepares");
    let e = spec.quick;
    let steps = run.sampled_steps(e.duration_tau1 * s.tau1());
    let records = run
        .simulate_ensemble(s.seed, 0, e.trajectories as u64, steps, |_| {})
        .expect("ensemble");
    let kinds = [langevin_fem::scene::CheckKind::TangentAngle];
    let smallest_p = |run: &LinearRun| {
        let (out, est) = linear_checks(run, &kinds, &records, &[]).expect("checks");
        assert!(est.skipped.is_empty(), "{:?}", est.skipped);
        assert_eq!(out.len(), 2 * s.sampling.modes);
        out.iter()
            .filter(|c| c.name.contains("tangent-variance"))
            .map(|c| c.p_value.expect("p-value"))
            .fold(1.0, f64::min)
    };
    let p = smallest_p(&run);
    assert!(p > 0.01 / 8.0, "the truth rejected: p = {p}");
    for t in &mut run.reference.tangent {
        t.variance_discrete /= 1.1;
    }
    let p = smallest_p(&run);
    assert!(p < 1e-4, "a 10 % wrong variance passes: p = {p}");
}
