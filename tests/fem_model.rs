//! Tests of the finite-element model (`src/fem`) against closed forms, dense linear
//! algebra and the continuum solution of eq. (2).

mod common;

use common::filament;
use common::hinged_profile_variance;
use common::seeds::{SEED_NOISE_COVARIANCE, SEED_NOISE_DETERMINISM};
use langevin_fem::FilamentParams;
use langevin_fem::fem::{
    BeamModel, GeneralizedModes, Mesh, NoiseGenerator, NoiseModel, UNIFORM_RATE_FACTOR,
    continuous_stationary_covariance, discrete_stationary_covariance, generalized_modes,
    modal_noise_covariance, nodal_covariance,
};
use langevin_fem::rng::trajectory_rng;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

fn beam(mesh: Mesh) -> BeamModel {
    BeamModel::new(filament::sample(), mesh).unwrap()
}

fn uniform(n: usize) -> BeamModel {
    beam(Mesh::uniform(filament::sample().length, n).unwrap())
}

fn graded(n: usize, ratio: f64) -> BeamModel {
    beam(Mesh::graded(filament::sample().length, n, ratio).unwrap())
}

/// Continuum rate λ_n = π⁴n⁴EI/(ξL⁴).
fn continuum_rate(p: &FilamentParams, n: usize) -> f64 {
    (PI * n as f64).powi(4) * p.bending_rigidity / (p.drag * p.length.powi(4))
}

fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// What: on uniform meshes (N = 1 … 1000) `max_rate` is λ_max = 2520·EI/(ξh⁴)
/// ([`UNIFORM_RATE_FACTOR`]) and equals the largest dense eigenvalue for N ≤ 40; the
/// explicit Euler limit 2/λ_max for 10 elements is 2π⁴/(2520·10⁴) τ₁ ≈ 7.73·10⁻⁶ τ₁.
/// Reference: the closed form 2520·EI/(ξh⁴) (`src/fem/beam.rs`); the dense generalized
/// eigenproblem K φ = λ C φ (`generalized_modes`), independent of the Sturm bisection.
/// Set-up: non-unit filament ([`filament::sample`]).
/// Tolerance: 10⁻¹⁰ relative: the bisection runs to 10⁻¹³, the rest is round-off.
#[test]
fn max_rate_uniform_factor_is_2520_and_euler_limit() {
    let p = filament::sample();
    for &n in &[1usize, 2, 3, 10, 37, 200, 1000] {
        let b = uniform(n);
        let h = p.length / n as f64;
        let lmax = b.max_rate().unwrap();
        let c = lmax * p.drag * h.powi(4) / p.bending_rigidity;
        println!("N = {n:5}: lambda_max * xi h^4 / EI = {c:.12}");
        assert!(
            (c / UNIFORM_RATE_FACTOR - 1.0).abs() < 1e-10,
            "N = {n}: c = {c}"
        );
        if n <= 40 {
            let dense = generalized_modes(&b).unwrap().rates.max();
            assert!(
                (lmax / dense - 1.0).abs() < 1e-10,
                "N = {n}: {lmax} vs {dense}"
            );
        }
    }
    // explicit Euler limit for 10 elements: 2/λ_max = 2π⁴/(2520·10⁴)·τ1 ≈ 7.73e-6 τ1
    let b = uniform(10);
    let limit = b.explicit_euler_dt_limit().unwrap() / p.tau1();
    let expected = 2.0 * PI.powi(4) / (2520.0 * 1e4);
    println!("explicit Euler limit, 10 elements: dt < {limit:.4e} tau1");
    assert!((limit / expected - 1.0).abs() < 1e-10);
}

/// What: on graded meshes (N = 2 … 25, size ratios 0.02 … 5), where no closed form exists,
/// `max_rate` (Sturm bisection) equals the largest dense generalized eigenvalue.
/// Reference: `generalized_modes` (dense eigen-solve of K φ = λ C φ).
/// Tolerance: 10⁻¹⁰ relative: the bisection runs to 10⁻¹³, the rest is round-off.
#[test]
fn max_rate_graded_matches_dense_eigenvalue() {
    let p = filament::sample();
    for &(n, ratio) in &[(2usize, 3.0), (7, 0.1), (16, 5.0), (25, 0.02)] {
        let b = graded(n, ratio);
        let lmax = b.max_rate().unwrap();
        let dense = generalized_modes(&b).unwrap().rates.max();
        let hmin = b.mesh().min_element_length();
        let c = lmax * p.drag * hmin.powi(4) / p.bending_rigidity;
        println!("graded N = {n}, ratio {ratio}: lambda_max * xi hmin^4/EI = {c:.4}");
        assert!((lmax / dense - 1.0).abs() < 1e-10, "{lmax} vs {dense}");
    }
}

/// What: the DOF layout of a graded 6-element mesh with hinged ends (no deflection DOF at
/// the end nodes, 12 DOFs, element DOF maps); and, for the cubic w = x(L−x)(x + 0.3),
/// which Hermite cubics represent exactly, `deflection_at` reproduces w (NaN outside
/// [0, L]) and the assembled load vector, geometric, stiffness and damping forms give ∫w,
/// ∫w'², EI∫w''² and ξ∫w².
/// Reference: 5-point Gauss–Legendre on 8 panels, exact for these polynomials (degree ≤ 6).
/// Tolerance: round-off only: 10⁻¹³ for the interpolation, 10⁻¹² to 10⁻¹⁰ (absolute) for
/// the forms, the largest for the stiffness form, whose entries scale as EI/h³.
#[test]
fn dof_layout_interpolation_and_assembled_forms_are_exact_for_cubics() {
    let p = filament::sample();
    let l = p.length;
    let b = graded(6, 0.4);
    let n = b.n_dofs();
    assert_eq!(n, 12);
    let nodes = b.mesh().nodes().to_vec();
    assert_eq!(b.node_deflection_index(0), None);
    assert_eq!(b.node_deflection_index(6), None);
    assert_eq!(b.node_deflection_index(7), None);
    assert_eq!(b.node_deflection_index(1), Some(1));
    assert_eq!(b.node_rotation_index(0), Some(0));
    assert_eq!(b.node_rotation_index(6), Some(11));
    assert_eq!(b.element_dofs(0), [None, Some(0), Some(1), Some(2)]);
    assert_eq!(b.element_dofs(5), [Some(9), Some(10), None, Some(11)]);
    assert_eq!(b.element_loads().len(), 6);
    // cubic with w(0) = w(L) = 0
    let w = |x: f64| x * (l - x) * (x + 0.3);
    let dw = |x: f64| -3.0 * x * x + 2.0 * (l - 0.3) * x + 0.3 * l;
    let mut state = vec![0.0; n];
    for (i, &x) in nodes.iter().enumerate() {
        if let Some(k) = b.node_deflection_index(i) {
            state[k] = w(x);
        }
        state[b.node_rotation_index(i).unwrap()] = dw(x);
    }
    for k in 0..=50 {
        let x = l * k as f64 / 50.0;
        assert!((b.deflection_at(&state, x) - w(x)).abs() < 1e-13);
    }
    assert!(b.deflection_at(&state, -0.1).is_nan());
    assert!(b.deflection_at(&state, l * 1.01).is_nan());
    // ∫w dx, ∫w'² dx, EI∫w''² dx and ξ∫w² dx by exact polynomial integration
    let integrate = |f: &dyn Fn(f64) -> f64| {
        // Simpson on a fine grid is exact for these polynomials only up to cubic; use
        // Gauss–Legendre with 5 points on 8 panels (exact to degree 9)
        let g = [
            (0.0, 128.0 / 225.0),
            (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
            (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
            (-0.906_179_845_938_664, 0.236_926_885_056_189_08),
            (0.906_179_845_938_664, 0.236_926_885_056_189_08),
        ];
        let panels = 8;
        let hp = l / panels as f64;
        let mut s = 0.0;
        for k in 0..panels {
            for &(t, wq) in &g {
                s += 0.5 * hp * wq * f(hp * (k as f64 + 0.5 * (t + 1.0)));
            }
        }
        s
    };
    let bvec = b.assembled_load_vector();
    let int_w: f64 = bvec.iter().zip(&state).map(|(a, c)| a * c).sum();
    assert!((int_w - integrate(&|x| w(x))).abs() < 1e-12);
    let gq = b.geometric().quadratic_form(&state);
    assert!((gq - integrate(&|x| dw(x) * dw(x))).abs() < 1e-11);
    let d2w = |x: f64| -6.0 * x + 2.0 * (l - 0.3);
    let kq = b.stiffness().quadratic_form(&state);
    assert!((kq - p.bending_rigidity * integrate(&|x| d2w(x) * d2w(x))).abs() < 1e-10);
    let cq = b.damping().quadratic_form(&state);
    assert!((cq - p.drag * integrate(&|x| w(x) * w(x))).abs() < 1e-12);
}

fn check_modes(b: &BeamModel, m: &GeneralizedModes) {
    let c = b.damping().to_dense();
    let k = b.stiffness().to_dense();
    let phi = &m.vectors;
    let n = b.n_dofs();
    let ctc = phi.transpose() * &c * phi;
    assert!((ctc - DMatrix::<f64>::identity(n, n)).amax() < 1e-9);
    let ktk = phi.transpose() * &k * phi;
    for i in 0..n {
        for j in 0..n {
            let expect = if i == j { m.rates[i] } else { 0.0 };
            let scale = (m.rates[i] * m.rates[j]).sqrt();
            assert!(
                (ktk[(i, j)] - expect).abs() < 1e-9 * scale,
                "K-orthogonality ({i},{j}): {} vs {expect}",
                ktk[(i, j)]
            );
        }
    }
    for i in 1..n {
        assert!(m.rates[i] > m.rates[i - 1]);
    }
    let proj = m.projector(b, 4);
    assert_eq!(proj.nrows(), 4);
    let pq = &proj * phi;
    for i in 0..4 {
        for j in 0..n {
            let e = if i == j { 1.0 } else { 0.0 };
            assert!((pq[(i, j)] - e).abs() < 1e-9);
        }
    }
}

/// What: the generalized modes are C-orthonormal, K-orthogonal with ΦᵀKΦ = diag(λ),
/// λ increasing, and the modal projector inverts Φ on the 4 leading modes (one uniform,
/// two graded meshes); on 40 uniform elements the first 4 modes match the continuum
/// shapes √(2/(ξL)) sin(nπx/L) at the nodes, with positive sign.
/// Reference: the definition of the generalized eigenproblem; the continuum modes of
/// eq. (2) with hinged ends.
/// Tolerance: 10⁻⁹ (relative to √(λᵢλⱼ) for K) for the identities: round-off of the dense
/// eigen-solve; 10⁻⁴ of the amplitude for the shapes: the discretization error at h = L/40.
#[test]
fn generalized_modes_are_orthonormal_and_match_continuum_shapes() {
    let p = filament::sample();
    for b in [uniform(12), graded(9, 0.2), graded(5, 4.0)] {
        let m = generalized_modes(&b).unwrap();
        check_modes(&b, &m);
    }
    // low modes approach φ_n(x) = sqrt(2/(ξL)) sin(nπx/L) at the nodes, with positive sign
    let b = uniform(40);
    let m = generalized_modes(&b).unwrap();
    let amp = (2.0 / (p.drag * p.length)).sqrt();
    for mode in 0..4 {
        let mut err: f64 = 0.0;
        for (i, &x) in b.mesh().nodes().iter().enumerate() {
            if let Some(k) = b.node_deflection_index(i) {
                let exact = amp * ((mode + 1) as f64 * PI * x / p.length).sin();
                err = err.max((m.vectors[(k, mode)] - exact).abs());
            }
        }
        println!(
            "mode {}: max nodal |phi - phi_continuum| = {err:.2e} (amp {amp:.3})",
            mode + 1
        );
        assert!(err < 1e-4 * amp, "mode {}: {err}", mode + 1);
    }
}

/// What: the first 3 discrete rates are upper bounds of the continuum rates (conforming
/// Rayleigh–Ritz) and converge to them at fourth order in h.
/// Reference: λₙ = π⁴n⁴EI/(ξL⁴) (eq. (2), hinged ends); Hermite-cubic eigenvalue error O(h⁴).
/// Set-up: uniform meshes of 2, 4, 8, 16 elements.
/// Tolerance: the observed order log₂(e_N/e_2N) from 8 to 16 elements within 0.15 of 4
/// (higher-order terms on these coarse meshes).
#[test]
fn rates_converge_to_continuum_at_fourth_order() {
    let p = filament::sample();
    let ns = [2usize, 4, 8, 16];
    let modes = 3;
    let mut errs = vec![vec![0.0; ns.len()]; modes];
    for (a, &n) in ns.iter().enumerate() {
        let m = generalized_modes(&uniform(n)).unwrap();
        for (i, row) in errs.iter_mut().enumerate() {
            let exact = continuum_rate(&p, i + 1);
            let rel = m.rates[i] / exact - 1.0;
            // conforming Rayleigh–Ritz: upper bounds
            assert!(rel > 0.0, "N = {n}, mode {}: {rel}", i + 1);
            row[a] = rel;
        }
    }
    for (i, row) in errs.iter().enumerate() {
        let orders: Vec<f64> = row.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        println!(
            "mode {}: rel. errors {:?}, observed orders {:?}",
            i + 1,
            row.iter().map(|e| format!("{e:.3e}")).collect::<Vec<_>>(),
            orders.iter().map(|o| format!("{o:.3}")).collect::<Vec<_>>()
        );
        let last = orders[orders.len() - 1];
        assert!((last - 4.0).abs() < 0.15, "mode {}: order {last}", i + 1);
    }
}

/// kT·x²(L−x)²/(3·EI·L): the continuum equipartition profile ⟨w²(x)⟩.
fn continuum_variance(p: &FilamentParams, x: f64) -> f64 {
    hinged_profile_variance(x, p.length, p.bending_rigidity, p.kt)
}

/// What: the closed-form profile kT x²(L−x)²/(3EI L) equals its mode series; with
/// consistent noise Σ_ζ = C, the modal noise covariance is I, the stationary nodal
/// covariance is kT K⁻¹, and the nodal variances equal the continuum profile (by banded
/// solves and by the modal route).
/// Reference: the equipartition series Σ 2kTL³ sin²(nπx/L)/(π⁴n⁴EI) (4000 terms); kT K⁻¹ by
/// a dense Cholesky inverse; the continuum profile, which Hermite cubics reproduce at the
/// nodes (the Green's function of EI ∂⁴ is cubic between nodes).
/// Set-up: one uniform and two graded meshes.
/// Tolerance: 10⁻⁹ for the series (its omitted tail is ~10⁻¹⁰ relative); otherwise
/// round-off: 10⁻¹³ of max|C| for the Cholesky product, 10⁻⁹ for the modal (dense
/// eigen-solve) routes, 10⁻¹² relative for the banded variances, 10⁻¹⁰ for the modal ones.
#[test]
fn consistent_noise_gives_kt_k_inverse_and_exact_nodal_variances() {
    let p = filament::sample();
    // the closed form equals the modal series Σ 2kT L³ sin²(nπx/L)/(π⁴n⁴EI)
    for &x in &[0.1, 0.77, 1.0, 1.9] {
        let series: f64 = (1..=4000)
            .map(|n| {
                let nf = n as f64;
                2.0 * p.kt * p.length.powi(3) * (nf * PI * x / p.length).sin().powi(2)
                    / (PI.powi(4) * nf.powi(4) * p.bending_rigidity)
            })
            .sum();
        assert!((series / continuum_variance(&p, x) - 1.0).abs() < 1e-9);
    }
    for b in [uniform(10), graded(12, 0.3), graded(7, 6.0)] {
        let n = b.n_dofs();
        let gen_ = NoiseGenerator::new(NoiseModel::Consistent, &b).unwrap();
        let sigma_zeta = gen_.covariance();
        // Σ_ζ = L Lᵀ = C up to round-off of the Cholesky product.
        let c = b.damping().to_dense();
        assert!((&sigma_zeta - &c).amax() < 1e-13 * c.amax());
        let modes = generalized_modes(&b).unwrap();
        let sigma_q = modal_noise_covariance(&modes, &sigma_zeta);
        assert!((&sigma_q - DMatrix::<f64>::identity(n, n)).amax() < 1e-9);
        let s = continuous_stationary_covariance(&sigma_q, &modes.rates, p.kt);
        let nodal = nodal_covariance(&modes, &s);
        let kinv = b
            .stiffness()
            .to_dense()
            .cholesky()
            .unwrap()
            .inverse()
            .scale(p.kt);
        let d_modal = rel_diff(&nodal, &kinv);
        // banded route: kT (K⁻¹)_kk by banded Cholesky solves
        let chol = b.stiffness().cholesky().unwrap();
        let mut worst_banded: f64 = 0.0;
        let mut worst_modal: f64 = 0.0;
        for (i, &x) in b.mesh().nodes().iter().enumerate() {
            let Some(k) = b.node_deflection_index(i) else {
                continue;
            };
            let mut e = vec![0.0; n];
            e[k] = 1.0;
            chol.solve_in_place(&mut e);
            let exact = continuum_variance(&p, x);
            worst_banded = worst_banded.max((p.kt * e[k] / exact - 1.0).abs());
            worst_modal = worst_modal.max((nodal[(k, k)] / exact - 1.0).abs());
        }
        println!(
            "N = {}: modal kT K^-1 rel diff {d_modal:.2e}; nodal variance vs continuum: \
             banded {worst_banded:.2e}, modal {worst_modal:.2e}",
            b.mesh().n_elements()
        );
        assert!(d_modal < 1e-9);
        assert!(worst_banded < 1e-12);
        assert!(worst_modal < 1e-10);
    }
}

/// `(C⁻¹, A = −C⁻¹K, B = 2kT C⁻¹ Σ_ζ C⁻¹)` of `ẇ = A w + C⁻¹F`.
fn drift_and_diffusion(b: &BeamModel, sigma_zeta: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let kt = b.params().kt;
    let cinv = b.damping().to_dense().try_inverse().unwrap();
    let a = -(&cinv * b.stiffness().to_dense());
    let bm = (&cinv * sigma_zeta * &cinv).scale(2.0 * kt);
    (a, bm)
}

/// What: with the paper's element-uniform noise the stationary nodal covariance P from the
/// modal route solves AP + PAᵀ + B = 0 for ẇ = −C⁻¹K w + noise, equals the solution of the
/// Kronecker system, and is not kT K⁻¹.
/// Reference: the Lyapunov equation, solved independently as (I⊗A + A⊗I) vec P = −vec B
/// (dense LU).
/// Set-up: 3 elements, uniform and graded.
/// Tolerance: residual below 10⁻¹⁰ of max|B| and 10⁻⁹ relative between the routes
/// (round-off); the difference from kT K⁻¹ must exceed 10⁻³ relative.
#[test]
fn continuous_covariance_solves_lyapunov_for_element_uniform_noise() {
    let p = filament::sample();
    for b in [uniform(3), graded(3, 0.25)] {
        let n = b.n_dofs();
        let sigma_zeta = NoiseGenerator::new(NoiseModel::ElementUniform, &b)
            .unwrap()
            .covariance();
        let modes = generalized_modes(&b).unwrap();
        let sigma_q = modal_noise_covariance(&modes, &sigma_zeta);
        let s = continuous_stationary_covariance(&sigma_q, &modes.rates, p.kt);
        let nodal = nodal_covariance(&modes, &s);
        let (a, bm) = drift_and_diffusion(&b, &sigma_zeta);
        let resid = &a * &nodal + &nodal * a.transpose() + &bm;
        let r = resid.amax() / bm.amax();
        // independent route: (I⊗A + A⊗I) vec P = −vec B
        let id = DMatrix::<f64>::identity(n, n);
        let big = id.kronecker(&a) + a.kronecker(&id);
        let rhs = -DVector::from_column_slice(bm.as_slice());
        let vecp = big.lu().solve(&rhs).unwrap();
        let pk = DMatrix::from_column_slice(n, n, vecp.as_slice());
        let d = rel_diff(&nodal, &pk);
        println!("Lyapunov residual {r:.2e}, modal vs Kronecker {d:.2e}");
        assert!(r < 1e-10);
        assert!(d < 1e-9);
        // element-uniform noise is not kT K⁻¹
        let kinv = b.stiffness().to_dense().try_inverse().unwrap().scale(p.kt);
        assert!(rel_diff(&nodal, &kinv) > 1e-3);
    }
}

/// Stationary covariance of `x ← M x + noise(cov N)` by Smith's doubling iteration
/// (`S ← S + M_k S M_kᵀ`, `M_k ← M_k²`), run to convergence.
fn iterate_stationary(m: &DMatrix<f64>, noise: &DMatrix<f64>) -> DMatrix<f64> {
    let mut s = noise.clone();
    let mut mk = m.clone();
    for _ in 0..64 {
        s = &s + &mk * &s * mk.transpose();
        mk = &mk * &mk;
        if mk.amax() < 1e-300 {
            break;
        }
    }
    s
}

/// What: the exact stationary covariance of the θ-scheme
/// (C + θΔtK) w' = (C − (1−θ)ΔtK) w + √(2kTΔt) ζ with element-uniform noise, from the
/// modal multipliers and gains (`discrete_stationary_covariance`), equals the reference for
/// explicit Euler at Δt = 1/λ_max, backward Euler at 10/λ₁ and Crank–Nicolson at 100/λ₁;
/// truncation to 2 modes gives the leading block, with S₁₀ = g₁g₀Σ_q,10/(1 − m₁m₀)
/// = 2Σ_q,10/1.1.
/// Reference: the nodal recursion's stationary covariance by Smith's doubling iteration
/// (no modal decomposition).
/// Set-up: graded 3-element mesh.
/// Tolerance: 10⁻⁸ relative (round-off of the iteration with multipliers near ±1);
/// 10⁻¹⁴ of max|S| for the closed-form entry.
#[test]
fn discrete_covariance_matches_iterated_recursion() {
    let p = filament::sample();
    let kt = p.kt;
    let b = graded(3, 0.5);
    let n = b.n_dofs();
    let sigma_zeta = NoiseGenerator::new(NoiseModel::ElementUniform, &b)
        .unwrap()
        .covariance();
    let modes = generalized_modes(&b).unwrap();
    let sigma_q = modal_noise_covariance(&modes, &sigma_zeta);
    let c = b.damping().to_dense();
    let k = b.stiffness().to_dense();
    let lmax = b.max_rate().unwrap();
    let l1 = modes.rates[0];
    // (name, Δt, θ): θ = 0 explicit Euler, 1 backward Euler, ½ Crank–Nicolson.
    let cases = [
        ("explicit Euler", 1.0 / lmax, 0.0),
        ("backward Euler", 10.0 / l1, 1.0),
        ("Crank-Nicolson", 100.0 / l1, 0.5),
    ];
    for (name, dt, theta) in cases {
        // (C + θΔtK) w' = (C − (1−θ)ΔtK) w + sqrt(2kTΔt) ζ
        let lhs = &c + k.scale(theta * dt);
        let lhs_inv = lhs.try_inverse().unwrap();
        let m_nodal = &lhs_inv * (&c - k.scale((1.0 - theta) * dt));
        let noise = (&lhs_inv * &sigma_zeta * lhs_inv.transpose()).scale(2.0 * kt * dt);
        let iterated = iterate_stationary(&m_nodal, &noise);
        let mult: Vec<f64> = modes
            .rates
            .iter()
            .map(|l| (1.0 - (1.0 - theta) * l * dt) / (1.0 + theta * l * dt))
            .collect();
        let gain: Vec<f64> = modes
            .rates
            .iter()
            .map(|l| (2.0 * kt * dt).sqrt() / (1.0 + theta * l * dt))
            .collect();
        let s = discrete_stationary_covariance(&sigma_q, &mult, &gain).unwrap();
        let nodal = nodal_covariance(&modes, &s);
        let d = rel_diff(&nodal, &iterated);
        println!(
            "{name}: dt*lambda in [{:.3e}, {:.3e}], m in [{:.4}, {:.4}], rel diff {d:.2e}",
            dt * l1,
            dt * modes.rates[n - 1],
            mult.iter().cloned().fold(f64::INFINITY, f64::min),
            mult.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        );
        assert!(d < 1e-8, "{name}: {d}");
    }
    // truncation to the leading modes is the leading block
    let mult = [0.5, -0.2];
    let gain = [1.0, 2.0];
    let s2 = discrete_stationary_covariance(&sigma_q, &mult, &gain).unwrap();
    assert_eq!(s2.nrows(), 2);
    assert!((s2[(1, 0)] - 2.0 * sigma_q[(1, 0)] / 1.1).abs() < 1e-14 * s2.amax());
}

/// What: `discrete_stationary_covariance` refuses a multiplier with |m| ≥ 1 (naming the
/// mode, 1-based), a NaN multiplier, multipliers and gains of different lengths, and more
/// modes than the covariance has.
/// Reference: a stationary law exists only for |m| < 1.
/// Tolerance: exact (errors).
#[test]
fn discrete_covariance_rejects_unstable_modes() {
    let sq = DMatrix::<f64>::identity(3, 3);
    let err = discrete_stationary_covariance(&sq, &[0.5, -1.0, 0.1], &[1.0; 3]).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("mode 2"), "{msg}");
    assert!(discrete_stationary_covariance(&sq, &[0.5, 1.5, 0.1], &[1.0; 3]).is_err());
    assert!(discrete_stationary_covariance(&sq, &[0.5, f64::NAN, 0.1], &[1.0; 3]).is_err());
    assert!(discrete_stationary_covariance(&sq, &[0.5], &[1.0, 1.0]).is_err());
    assert!(discrete_stationary_covariance(&sq, &[0.5; 4], &[1.0; 4]).is_err());
}

/// What: with element-uniform noise the stationary modal variance relative to kT/λᵢ,
/// Σ_q,ii, lies in (0, 1], increases with N once the mode is resolved, and its deficit
/// 1 − Σ_q,ii ≈ (iπh/L)²/12 is of second order in h and below 3 % at 40 elements
/// (modes 1–6); graded meshes obey the same bound.
/// Reference: Σ_q,ii = Σ_e h_e·mean_e(φᵢ)²/∫φᵢ² ≤ 1 (Cauchy–Schwarz per element).
/// Set-up: uniform meshes of 5, 10, 20, 40 elements; graded meshes (ratio 0.3).
/// Tolerance: the bound up to 10⁻⁹ (round-off); the observed order from 20 to 40
/// elements within 0.1 of 2.
#[test]
fn element_uniform_modal_variance_ratios_tend_to_one() {
    let ns = [5usize, 10, 20, 40];
    let n_modes = 6;
    let mut table = vec![vec![0.0; ns.len()]; n_modes];
    for (a, &n) in ns.iter().enumerate() {
        let b = uniform(n);
        let modes = generalized_modes(&b).unwrap();
        let sz = NoiseGenerator::new(NoiseModel::ElementUniform, &b)
            .unwrap()
            .covariance();
        let sq = modal_noise_covariance(&modes, &sz);
        for (i, row) in table.iter_mut().enumerate() {
            row[a] = sq[(i, i)];
        }
        // graded meshes obey the same Cauchy–Schwarz bound
        let bg = graded(n, 0.3);
        let mg = generalized_modes(&bg).unwrap();
        let szg = NoiseGenerator::new(NoiseModel::ElementUniform, &bg)
            .unwrap()
            .covariance();
        let sqg = modal_noise_covariance(&mg, &szg);
        for i in 0..bg.n_dofs() {
            assert!(sqg[(i, i)] <= 1.0 + 1e-9 && sqg[(i, i)] >= -1e-12);
        }
    }
    println!("element-uniform noise: stationary modal variance / (kT/lambda_i) = Sigma_q,ii");
    println!("mode | N = 5      N = 10     N = 20     N = 40   | order 20->40");
    for (i, row) in table.iter().enumerate() {
        let order = ((1.0 - row[2]) / (1.0 - row[3])).log2();
        println!(
            "{:4} | {:.6}  {:.6}  {:.6}  {:.6} | {order:.3}",
            i + 1,
            row[0],
            row[1],
            row[2],
            row[3]
        );
        for a in 0..ns.len() {
            // Σ_q,ii = Σ_e h_e·mean_e(w)² / ∫w² ≤ 1 (Cauchy–Schwarz per element)
            assert!(row[a] <= 1.0 + 1e-9 && row[a] > 0.0);
            // monotone once the mode is resolved (mode number < N on the coarser mesh;
            // mode N of N elements vanishes at every node and is not sine-like)
            if a > 0 && ns[a - 1] > i + 1 {
                assert!(row[a] > row[a - 1], "mode {} not converging", i + 1);
            }
        }
        // deficit 1 − Σ_q,ii ≈ (iπh/L)²/12 → second order in h
        assert!((order - 2.0).abs() < 0.1, "mode {}: order {order}", i + 1);
        assert!(1.0 - row[3] < 0.03);
    }
}

/// What: each noise model's generator draws vectors whose sample mean and covariance
/// match its `covariance()`, with n (consistent) or 4 (element-uniform) draws per step, and
/// two generators seeded alike draw alike.
/// Reference: the exact Σ; Gaussian standard errors √(Σᵢᵢ/M) for a mean and
/// √((ΣᵢᵢΣⱼⱼ + Σᵢⱼ²)/M) for a covariance.
/// Set-up: graded 4-element mesh (8 DOFs), M = 40000 draws from
/// [`SEED_NOISE_COVARIANCE`].
/// Tolerance: every |z| < 5 (72 statistics per model at 5.7·10⁻⁷ each).
#[test]
fn noise_generator_sample_covariance_matches() {
    let b = graded(4, 0.5);
    let n = b.n_dofs();
    let samples = 40_000;
    for (idx, model) in NoiseModel::ALL.into_iter().enumerate() {
        let g = NoiseGenerator::new(model, &b).unwrap();
        assert_eq!(g.model(), model);
        assert_eq!(
            g.draws_per_step(),
            match model {
                NoiseModel::Consistent => n,
                NoiseModel::ElementUniform => 4,
            }
        );
        let sigma = g.covariance();
        let mut rng = trajectory_rng(SEED_NOISE_COVARIANCE, idx as u64);
        let mut z = vec![0.0; n];
        let mut sum = DVector::<f64>::zeros(n);
        let mut sum2 = DMatrix::<f64>::zeros(n, n);
        for _ in 0..samples {
            g.draw(&mut rng, &mut z);
            let v = DVector::from_column_slice(&z);
            sum += &v;
            sum2 += &v * v.transpose();
        }
        let m = samples as f64;
        let mean = sum / m;
        let cov = sum2 / m;
        let mut worst: f64 = 0.0;
        for i in 0..n {
            let se_mean = (sigma[(i, i)] / m).sqrt();
            worst = worst.max((mean[i] / se_mean).abs());
            for j in 0..n {
                // var of x_i x_j for Gaussians: Σ_ii Σ_jj + Σ_ij²
                let se = ((sigma[(i, i)] * sigma[(j, j)] + sigma[(i, j)].powi(2)) / m).sqrt();
                worst = worst.max(((cov[(i, j)] - sigma[(i, j)]) / se).abs());
            }
        }
        println!("{model}: worst |z-score| over means and covariances = {worst:.2}");
        assert!(worst < 5.0, "{model}: {worst}");
        // determinism
        let mut r1 = trajectory_rng(SEED_NOISE_DETERMINISM, 2);
        let mut r2 = trajectory_rng(SEED_NOISE_DETERMINISM, 2);
        let (mut a1, mut a2) = (vec![0.0; n], vec![0.0; n]);
        g.draw(&mut r1, &mut a1);
        g.draw(&mut r2, &mut a2);
        assert_eq!(a1, a2);
    }
}

/// What: `BeamModel::new` rejects a negative drag, a mesh whose length differs from the
/// filament's, and a NaN kT.
/// Tolerance: exact (errors).
#[test]
fn invalid_inputs_are_errors() {
    let mut p = filament::sample();
    p.drag = -1.0;
    assert!(BeamModel::new(p, Mesh::uniform(2.0, 4).unwrap()).is_err());
    let p = filament::sample();
    assert!(BeamModel::new(p, Mesh::uniform(2.5, 4).unwrap()).is_err());
    let mut p = filament::sample();
    p.kt = f64::NAN;
    assert!(BeamModel::new(p, Mesh::uniform(2.0, 4).unwrap()).is_err());
}

/// Issue #31: the finite-difference (bead-spring) chain as a run's model, through the same
/// pipeline as the elements: its exact discrete references are the closed forms of the
/// 5-point stencil — per mode the continuum variance times (x/sin x)⁴, x = nπh/(2L)
/// (exact-modal), over 1 − λΔt/2 under explicit Euler–Maruyama, with the multiplier
/// 1 − λΔt — and its profile at a node is the sum over its N − 1 sine modes, within
/// O(h²) of the continuum's kT x²(L−x)²/(3EI·L).
#[test]
fn chain_references_are_the_stencil_closed_forms() {
    use langevin_fem::scene::linear::LinearRun;
    use langevin_fem::scene::{MeshScheme, Scene};
    let mut scene =
        Scene::load(std::path::Path::new("verification/hinged-linear-2d.toml")).unwrap();
    scene.mesh.scheme = MeshScheme::Chain;
    scene.mesh.elements = 10;
    let p = scene.filament;
    let h = p.length / 10.0;
    let tau1 = scene.tau1();
    let rate = |n: usize| {
        let s = (n as f64 * PI * h / (2.0 * p.length)).sin();
        p.bending_rigidity * (4.0 * s * s / (h * h)).powi(2) / p.drag
    };
    for (integrator, dt_tau1) in [("exact-modal", 1e-3), ("euler-maruyama", 1e-4)] {
        let spec = scene
            .runs
            .iter()
            .find(|r| r.integrator.to_string() == integrator)
            .cloned()
            .map(|mut r| {
                r.dt_tau1 = dt_tau1;
                r
            })
            .unwrap_or_else(|| panic!("a {integrator} run"));
        let run = LinearRun::prepare(&scene, &spec).unwrap();
        let dt = dt_tau1 * tau1;
        for m in &run.reference.modes {
            let n = m.n;
            let x = n as f64 * PI * h / (2.0 * p.length);
            let em = if integrator == "euler-maruyama" {
                1.0 / (1.0 - 0.5 * rate(n) * dt)
            } else {
                1.0
            };
            let want = (x / x.sin()).powi(4) * em;
            let got = m.variance_discrete / m.variance_continuum;
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "{integrator} mode {n}: {got} vs {want}"
            );
            let mult = if integrator == "euler-maruyama" {
                1.0 - rate(n) * dt
            } else {
                (-rate(n) * dt).exp()
            };
            assert!(
                (m.multiplier / mult - 1.0).abs() < 1e-9,
                "{integrator} mode {n}"
            );
        }
        // The profile at the mid node: Σ_n (2kT/(ξLλ_n)) sin²(nπ/2) over the chain's modes.
        let i = run
            .reference
            .profile_x
            .iter()
            .position(|&x| x == 0.5)
            .unwrap();
        if integrator == "exact-modal" {
            let sum: f64 = (1..10)
                .map(|n| {
                    2.0 * p.kt / (p.drag * p.length * rate(n)) * (n as f64 * PI / 2.0).sin().powi(2)
                })
                .sum();
            let got = run.reference.profile_discrete[i];
            assert!((got / sum - 1.0).abs() < 1e-9, "profile {got} vs {sum}");
            let cont = p.kt * 0.0625 / (3.0 * p.bending_rigidity * p.length);
            // O(h²): +2.0 % on 10 intervals (by the sum above).
            assert!(
                (got / cont - 1.0 - 0.02).abs() < 1e-9,
                "{got} vs continuum {cont}"
            );
        }
    }
}
