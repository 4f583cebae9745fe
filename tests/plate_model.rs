//! Tests of the Bogner–Fox–Schmit plate (`langevin_fem::fem::plate`, `plate_modes`): the
//! membrane's rates against the continuum of `spectral::membrane` (convergence order and
//! side), the separable block form against dense linear algebra on the banded assembly,
//! the simply supported constraints (and the common wrong ones), the periodic zero mode,
//! interpolation, the element noise of eq. (5), and the fastest rate.
//!
//! Parameters are deliberately not 1 (κ = 0.8, ξ = 2.5, kT = 1.3, a = 1.7) so that a wrong
//! power of one cannot cancel; random inputs use the named seeds of `common::seeds`.

mod common;

use common::seeds::{SEED_PLATE_INTERPOLATION, SEED_PLATE_NOISE};
use langevin_fem::error::Error;
use langevin_fem::fem::modal::generalized_modes_signed;
use langevin_fem::fem::{
    NodeDof, PLATE_RATE_FACTOR, PlateModeLabel, PlateModel, PlateModes, SymBanded,
};
use langevin_fem::rng::trajectory_rng;
use langevin_fem::spectral::{Membrane, MembraneBoundary, MembraneMode, MembraneParams, ModeShape};
use nalgebra::{Cholesky, DMatrix, DVector};
use rand::RngExt;

const SS: MembraneBoundary = MembraneBoundary::SimplySupported;
const PERIODIC: MembraneBoundary = MembraneBoundary::Periodic;
const KAPPA: f64 = 0.8;
const WIDTH: f64 = 1.7;

fn params(boundary: MembraneBoundary, tension: f64, height: f64) -> MembraneParams {
    MembraneParams {
        bending_rigidity: KAPPA,
        tension,
        drag: 2.5,
        kt: 1.3,
        width: WIDTH,
        height,
        boundary,
    }
}

fn plate(p: MembraneParams, nx: usize, ny: usize) -> PlateModel {
    PlateModel::new(p, nx, ny).unwrap()
}

fn sine_sine(m: i64, n: i64) -> MembraneMode {
    MembraneMode {
        m,
        n,
        shape: ModeShape::SineSine,
    }
}

/// All generalized eigenvalues of `(K, C)`, ascending, by the dense route (Cholesky of
/// `C`, symmetric eigenvalues of `L⁻¹KL⁻ᵀ`); unlike `generalized_modes_signed` it accepts
/// the periodic zero rate.
fn dense_rates(model: &PlateModel) -> Vec<f64> {
    let l = Cholesky::new(model.damping().to_dense()).unwrap().l();
    let y = l
        .solve_lower_triangular(&model.stiffness().to_dense())
        .unwrap();
    let a = l.solve_lower_triangular(&y.transpose()).unwrap();
    let mut ev: Vec<f64> = ((&a + a.transpose()) * 0.5)
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .collect();
    ev.sort_by(f64::total_cmp);
    ev
}

/// Number of generalized eigenvalues of `(K, C)` below `s` (Sylvester: negative pivots of
/// `K − sC`).
fn count_below(k: &SymBanded, c: &SymBanded, s: f64) -> usize {
    SymBanded::linear_combination(1.0, k, -s, c)
        .unwrap()
        .negative_eigenvalue_count()
        .unwrap()
}

/// `A` restricted to the indices `keep` (ascending): still banded.
fn restrict(a: &SymBanded, keep: &[usize]) -> SymBanded {
    let bw = a.bandwidth();
    let mut out = SymBanded::new(keep.len(), bw);
    for (i, &gi) in keep.iter().enumerate() {
        for (j, &gj) in keep
            .iter()
            .enumerate()
            .take(i + 1)
            .skip(i.saturating_sub(bw))
        {
            let v = a.get(gi, gj);
            if v != 0.0 {
                out.add(i, j, v).unwrap();
            }
        }
    }
    out
}

/// Smallest generalized eigenvalue of `(K, C)` (both positive definite) by Sturm bisection
/// from `[0, upper]` to a relative width of 1e-12.
fn smallest_rate(k: &SymBanded, c: &SymBanded, upper: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, upper);
    assert_eq!(count_below(k, c, 0.0), 0, "K not positive definite");
    assert!(count_below(k, c, hi) >= 1, "upper bound too low");
    while hi - lo > 1e-12 * hi {
        let mid = 0.5 * (lo + hi);
        if count_below(k, c, mid) >= 1 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// What: the acoustic rate of the modes (1,1), (2,1), (1,2), (2,2) of the simply supported
/// plate converges to the continuum rate (κq⁴ + σq²)/ξ from above, at fourth order, and the
/// equipartition variance kT/λ_h of the C-normalized mode (= the continuum
/// `mode_variance`·ξ‖φ‖², the variance of the C-normalized continuum amplitude) from below.
/// Reference: `Membrane::mode_rate`, `Membrane::mode_variance` (M2, M3). Set-up: σ = 0 and
/// σ = 10κ/a², on a square (a = b = 1.7) and a 2:1 rectangle (b = a/2), nx = ny ∈
/// {2, 4, 8, 16} (a mode (m, n) needs m < nx and n < ny). Tolerance: the observed order
/// log₂(e(h)/e(h/2)) within [3.7, 4.3] for the pairs (4, 8) and (8, 16) (the O(h²)
/// correction of the h⁴ law moves it by < 0.15 there; measured 3.93–4.03); the rates'
/// round-off (≈ ε·λ_max/λ ≈ 1e-11 at 16×16) is 10⁵ times below the smallest error (1e-6).
#[test]
fn acoustic_rates_converge_from_above_at_fourth_order() {
    for tension in [0.0, 10.0 * KAPPA / (WIDTH * WIDTH)] {
        for height in [WIDTH, WIDTH / 2.0] {
            let p = params(SS, tension, height);
            let continuum = Membrane::new(p).unwrap();
            let forms: Vec<(usize, PlateModes)> = [2, 4, 8, 16]
                .iter()
                .map(|&n| (n, PlateModes::new(&plate(p, n, n)).unwrap()))
                .collect();
            for (m, n) in [(1, 1), (2, 1), (1, 2), (2, 2)] {
                let mode = sine_sine(m, n);
                let (exact, var) = (continuum.mode_rate(mode), continuum.mode_variance(mode));
                let var_c = var * p.drag * continuum.mode_norm_sq();
                let mut errors = Vec::new();
                for (ne, form) in &forms {
                    let Some(fe) = form.acoustic(mode) else {
                        assert!(*ne as i64 <= m.max(n), "({m},{n}) missing at {ne}");
                        continue;
                    };
                    assert_eq!(fe.label.branch, 0);
                    let err = fe.rate / exact - 1.0;
                    assert!(err > 0.0, "σ {tension} b {height} ({m},{n}) {ne}: {err:e}");
                    assert!(p.kt / fe.rate < var_c, "variance not below at {ne}");
                    errors.push((*ne, err));
                }
                for w in errors.windows(2).filter(|w| w[0].0 >= 4) {
                    let order = (w[0].1 / w[1].1).log2();
                    println!(
                        "σ {tension:.3} b {height} ({m},{n}) {}→{}: order {order:.3}",
                        w[0].0, w[1].0
                    );
                    assert!((3.7..=4.3).contains(&order), "order {order} at {:?}", w);
                }
            }
        }
    }
}

/// What: the separable block rates equal the dense generalized eigenvalues of the assembled
/// banded `(K, C)` — the cross-check of the tensor-product block form against the banded
/// assembly — and the dense `GeneralizedModes` built from the blocks satisfy `ΦᵀCΦ = I`,
/// `ΦᵀKΦ = Λ` with the banded matrices. Reference: `generalized_modes_signed` (dense
/// Cholesky and symmetric eigensolver) on the plate's `LinearSystem`. Set-up: simply
/// supported, 1×1 to 5×5, square and not, σ ∈ {0, 0.3, 0.9 of the way down to buckling}.
/// Tolerance: 1e-10 relative per rate (the dense solver's absolute error ε·λ_max is
/// ≈ 1e-12 of the smallest rate at 5×5); the Φ checks 1e-10 of λ_max.
#[test]
fn block_rates_equal_dense_eigenvalues() {
    for (nx, ny, height) in [
        (1, 1, 1.1),
        (2, 3, 1.1),
        (3, 4, 1.1),
        (4, 2, 0.6),
        (5, 5, WIDTH),
    ] {
        let base = params(SS, 0.0, height);
        for tension in [0.0, 0.3, 0.9 * base.buckling_tension()] {
            let model = plate(params(SS, tension, height), nx, ny);
            let form = PlateModes::new(&model).unwrap();
            let dense = generalized_modes_signed(&model, |_, _| false).unwrap();
            let rates = form.rates();
            for (i, (a, d)) in rates.iter().zip(dense.rates.iter()).enumerate() {
                assert!(
                    (a - d).abs() <= 1e-10 * d,
                    "{nx}x{ny} σ {tension}: rate {i} {a} vs {d}"
                );
            }
            let gm = form.generalized_modes().unwrap();
            let phi = &gm.vectors;
            let ck = phi.transpose() * model.damping().to_dense() * phi;
            let kk = phi.transpose() * model.stiffness().to_dense() * phi;
            let top = rates[rates.len() - 1];
            let identity = DMatrix::<f64>::identity(ck.nrows(), ck.ncols());
            assert!((&ck - identity).amax() < 1e-10, "{nx}x{ny}: C");
            assert!(
                (kk - DMatrix::from_diagonal(&gm.rates)).amax() < 1e-10 * top,
                "{nx}x{ny}: K"
            );
        }
    }
}

/// What: on a square plate meshed alike in x and y, the degenerate pairs (m, n), (n, m)
/// come out as the separable sin·sin modes, with exactly equal rates and in label order
/// ((1,2) before (2,1)), every acoustic mode's nodal heights are a positive multiple of
/// sin(mπx/a)·sin(nπy/b) (the sign convention), and repeated construction is bit-identical.
/// Reference: the continuum mode shapes (`Membrane::mode_shape`). Set-up: 6×6, a = b.
/// Tolerance: the height ratio constant to 1e-12 (round-off of the nodal sines).
#[test]
fn degenerate_pairs_are_separable_sine_products_in_label_order() {
    let p = params(SS, 0.3, WIDTH);
    let model = plate(p, 6, 6);
    let form = PlateModes::new(&model).unwrap();
    let continuum = Membrane::new(p).unwrap();
    let index = |m, n| {
        let label = PlateModeLabel {
            m,
            n,
            shape: ModeShape::SineSine,
            branch: 0,
        };
        form.find(label).unwrap().0
    };
    for (m, n) in [(1, 2), (1, 3), (2, 3)] {
        let (i, j) = (index(m, n), index(n, m));
        assert_eq!(j, i + 1, "({m},{n}) then ({n},{m})");
        assert_eq!(form.modes()[i].rate, form.modes()[j].rate);
    }
    for (idx, mode) in form.modes().iter().enumerate() {
        if let Some(target) = mode.continuum {
            assert_heights_proportional(&model, &continuum, target, &form.mode_vector(idx));
        }
    }
    let again = PlateModes::new(&model).unwrap();
    assert_eq!(again.modes(), form.modes());
}

/// The model's DOFs that a code constraining the normal slope on the edges would remove
/// besides ours: `w_x` on the x-edges, `w_y` on the y-edges.
fn normal_slope_dofs(model: &PlateModel) -> Vec<usize> {
    let (nx, ny) = model.elements();
    let mut out = Vec::new();
    for j in 0..=ny {
        for i in [0, nx] {
            out.extend(model.node_dof_index(i, j, NodeDof::SlopeX));
        }
    }
    for i in 0..=nx {
        for j in [0, ny] {
            out.extend(model.node_dof_index(i, j, NodeDof::SlopeY));
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// What: the simply supported constraints are the right ones — the lowest rate converges
/// to the continuum λ₁₁ = κπ⁴(1/a² + 1/b²)²/ξ — while the common mistake of also
/// constraining the normal slope on the edges (`w_x` on x = 0, a; `w_y` on y = 0, b) gives
/// a lowest rate that stays far above it (it tends to the clamped plate's, about 3.3 λ₁₁ on
/// a square: 35.99² against (2π²)²), so a test against the continuum catches it.
/// Reference: `Membrane::mode_rate` of (1, 1); the clamped square plate's
/// λ a⁴ξ/κ ≈ 1294.9 (Leissa, *Vibration of Plates*, NASA SP-160, 1969, table 4.23) for
/// orientation only. Set-up: square a = b, σ = 0, nx = ny ∈ {4, 8, 16}; the lowest rate by
/// Sturm bisection on the banded matrices restricted to the remaining DOFs.
/// Tolerance: ours within 1e-3 at 8×8 and converging; the wrong one above 2.5 λ₁₁ on every
/// mesh (a margin of 30% below what it approaches), its distance to λ₁₁ not shrinking by
/// more than 10% per refinement, and within 1% of the clamped value at 16×16 (measured
/// 3.188, 3.305, 3.321 λ₁₁ at 4, 8, 16: it converges from below, as a non-conforming
/// clamp would).
#[test]
fn constraining_the_normal_slope_does_not_converge_to_simply_supported() {
    let p = params(SS, 0.0, WIDTH);
    let exact = Membrane::new(p).unwrap().mode_rate(sine_sine(1, 1));
    let mut previous: Option<f64> = None;
    for ne in [4, 8, 16] {
        let model = plate(p, ne, ne);
        let upper = 10.0 * exact;
        let ours = smallest_rate(model.stiffness(), model.damping(), upper);
        let removed = normal_slope_dofs(&model);
        assert_eq!(
            removed.len(),
            4 * (ne - 1),
            "edge normal slopes, corners excluded"
        );
        let keep: Vec<usize> = (0..model.n_dofs())
            .filter(|i| removed.binary_search(i).is_err())
            .collect();
        let (k, c) = (
            restrict(model.stiffness(), &keep),
            restrict(model.damping(), &keep),
        );
        let wrong = smallest_rate(&k, &c, upper);
        println!(
            "{ne}x{ne}: ours/λ11 = {:.8}, wrong/λ11 = {:.6}",
            ours / exact,
            wrong / exact
        );
        assert!(
            ours >= exact && (ne < 8 || ours / exact - 1.0 < 1e-3),
            "ours {ours} vs {exact}"
        );
        assert!(wrong / exact > 2.5, "wrong BC {wrong} close to {exact}");
        if let Some(previous) = previous {
            assert!(
                wrong / exact - 1.0 > 0.9 * (previous / exact - 1.0),
                "wrong BC approaches λ11"
            );
        }
        previous = Some(wrong);
        if ne == 16 {
            // it tends to the clamped plate: (35.985/(2π²))² = 3.3234
            assert!(
                (wrong / exact / 3.3234 - 1.0).abs() < 0.01,
                "{}",
                wrong / exact
            );
        }
    }
}

/// Asserts that the nodal heights of `v` are a positive multiple of the continuum shape
/// `target` at every node (the separable form and the sign convention), to 1e-12.
fn assert_heights_proportional(
    model: &PlateModel,
    continuum: &Membrane,
    target: MembraneMode,
    v: &[f64],
) {
    let (nx, ny) = model.elements();
    let (hx, hy) = model.element_size();
    let vmax = v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let mut ratio = None;
    for j in 0..=ny {
        for i in 0..=nx {
            let shape = continuum.mode_shape(target, i as f64 * hx, j as f64 * hy);
            let w = model.node_height_index(i, j).map_or(0.0, |k| v[k]);
            if shape.abs() > 0.1 {
                let r = w / shape;
                assert!(r > 0.0, "{target:?}: sign");
                let r0 = *ratio.get_or_insert(r);
                assert!(
                    (r - r0).abs() <= 1e-12 * r0,
                    "{target:?}: not the continuum shape"
                );
            }
        }
    }
    let r0 = ratio.expect("a node where the shape is not small");
    for j in 0..=ny {
        for i in 0..=nx {
            let shape = continuum.mode_shape(target, i as f64 * hx, j as f64 * hy);
            let w = model.node_height_index(i, j).map_or(0.0, |k| v[k]);
            assert!(
                (w - r0 * shape).abs() <= 1e-12 * vmax,
                "{target:?} at ({i}, {j})"
            );
        }
    }
}

/// What: the periodic plate has exactly one zero rate, the uniform translation
/// (`zero_mode`: `K u = 0`, `uᵀCu = 1`, labelled (0, 0, Cosine, 0) with rate exactly 0);
/// every other rate is positive; and the acoustic rates of (1, 0) cosine and sine, (0, 1),
/// (1, 1) and (1, −1) converge from above at fourth order to the periodic continuum
/// (κq⁴ + σq²)/ξ, q = 2π(m/a, n/b), their nodal heights being positive multiples of
/// cos(q·r) or sin(q·r) (the travelling combinations and the sign convention). The dense
/// `generalized_modes` of the blocks leave the zero mode out and are C-orthogonal to it. Reference: Sylvester's inertia of `K ∓ εC`
/// (exactly one eigenvalue in (−ε, ε)); `Membrane::mode_rate` (periodic). Set-up:
/// a = 1.7, b = 1.1, σ = 0.3, nx = ny ∈ {4, 8, 16, 32}. Tolerance: orders in [3.7, 4.3]
/// for the pairs from 8 (the O(h²) correction); `‖Ku‖ ≤ 1e-13 ‖K‖∞‖u‖`, round-off.
#[test]
fn periodic_plate_has_one_zero_mode_and_converges() {
    let p = params(PERIODIC, 0.3, 1.1);
    let continuum = Membrane::new(p).unwrap();
    let targets = [
        (1, 0, ModeShape::Cosine),
        (1, 0, ModeShape::Sine),
        (0, 1, ModeShape::Cosine),
        (1, 1, ModeShape::Cosine),
        (1, -1, ModeShape::Sine),
    ];
    let mut errors: Vec<Vec<f64>> = vec![Vec::new(); targets.len()];
    for ne in [4, 8, 16, 32] {
        let model = plate(p, ne, ne);
        let form = PlateModes::new(&model).unwrap();
        let zero = form.zero_mode().unwrap();
        assert_eq!(form.modes()[zero].rate, 0.0);
        assert_eq!(zero, 0);
        assert!(form.modes()[1..].iter().all(|m| m.rate > 0.0));
        let eps = 1e-6 * form.modes()[1].rate;
        let (k, c) = (model.stiffness(), model.damping());
        assert_eq!(
            (count_below(k, c, -eps), count_below(k, c, eps)),
            (0, 1),
            "{ne}"
        );
        let u = model.zero_mode().unwrap();
        let mut ku = vec![0.0; u.len()];
        k.mul_vec(&u, &mut ku);
        let knorm = k.to_dense().abs().row_sum().max();
        let unorm = u.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(ku.iter().map(|v| v * v).sum::<f64>().sqrt() <= 1e-13 * knorm * unorm);
        assert!((c.quadratic_form(&u) - 1.0).abs() < 1e-13);
        for (t, &(m, n, shape)) in targets.iter().enumerate() {
            let mode = MembraneMode { m, n, shape };
            let fe = form.acoustic(mode).unwrap();
            let err = fe.rate / continuum.mode_rate(mode) - 1.0;
            assert!(err > 0.0, "{mode:?} at {ne}: {err:e}");
            errors[t].push(err);
        }
        if ne == 8 {
            for &(m, n, shape) in &targets {
                let target = MembraneMode { m, n, shape };
                let index = form.find(form.acoustic(target).unwrap().label).unwrap().0;
                assert_heights_proportional(&model, &continuum, target, &form.mode_vector(index));
            }
        }
        if ne == 4 {
            let gm = form.generalized_modes().unwrap();
            assert_eq!(gm.len(), model.n_dofs() - 1);
            let cu = model.damping().to_dense() * DVector::from_column_slice(&u);
            assert!((gm.vectors.transpose() * cu).amax() < 1e-12);
            assert!(generalized_modes_signed(&model, |_, _| false).is_err());
        }
    }
    for (t, e) in errors.iter().enumerate() {
        for w in e.windows(2).skip(1) {
            let order = (w[0] / w[1]).log2();
            println!("{:?}: order {order:.3}", targets[t]);
            assert!(
                (3.7..=4.3).contains(&order),
                "{:?}: order {order}",
                targets[t]
            );
        }
    }
}

/// Random cubic `[c0, c1, c2, c3]` vanishing at 0 and `len`: `x(len − x)(α + βx)`.
fn edge_cubic(rng: &mut impl rand::Rng, len: f64) -> [f64; 4] {
    let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    [0.0, len * a, len * b - a, -b]
}

/// `[p(x), p′(x)]` of a cubic.
fn cubic(c: &[f64; 4], x: f64) -> [f64; 2] {
    let v = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
    let d = c[1] + x * (2.0 * c[2] + x * 3.0 * c[3]);
    [v, d]
}

/// What: `height_at` (and `probe`) reproduce bicubic polynomials exactly: a sum of two
/// products X(x)Y(y) of cubics vanishing at the ends (so h = 0 and its tangential slope
/// vanish on every edge: the field lies in the simply supported space, as the constrained
/// DOFs' values, all 0, confirm) is interpolated from its nodal (h, h_x, h_y, h_xy) to
/// round-off at random points, edges and corners included; the periodic interpolant
/// reproduces a constant and is continuous across the seam; outside the rectangle and for
/// non-finite coordinates the result is NaN (`probe`: None). Reference: the polynomial.
/// Set-up: 3×4 mesh of a 1.7 × 1.1 rectangle, 200 points. Tolerance: 1e-13 of max |p|.
#[test]
fn interpolation_reproduces_bicubics() {
    let mut rng = trajectory_rng(SEED_PLATE_INTERPOLATION, 0);
    let p = params(SS, 0.3, 1.1);
    let model = plate(p, 3, 4);
    let (hx, hy) = model.element_size();
    let terms: Vec<([f64; 4], [f64; 4])> = (0..2)
        .map(|_| {
            (
                edge_cubic(&mut rng, p.width),
                edge_cubic(&mut rng, p.height),
            )
        })
        .collect();
    let eval = |x: f64, y: f64, tx: usize, ty: usize| -> f64 {
        terms
            .iter()
            .map(|(cx, cy)| cubic(cx, x)[tx] * cubic(cy, y)[ty])
            .sum()
    };
    let mut state = vec![0.0; model.n_dofs()];
    let mut scale = 0.0_f64;
    for j in 0..=4 {
        for i in 0..=3 {
            let (x, y) = (i as f64 * hx, j as f64 * hy);
            for (dof, tx, ty) in [
                (NodeDof::Height, 0, 0),
                (NodeDof::SlopeX, 1, 0),
                (NodeDof::SlopeY, 0, 1),
                (NodeDof::Twist, 1, 1),
            ] {
                let v = eval(x, y, tx, ty);
                match model.node_dof_index(i, j, dof) {
                    Some(k) => state[k] = v,
                    None => assert!(v.abs() < 1e-14, "constrained DOF holds {v}"),
                }
            }
            scale = scale.max(eval(x, y, 0, 0).abs());
        }
    }
    let mut points: Vec<(f64, f64)> = (0..200)
        .map(|_| {
            (
                rng.random_range(0.0..=p.width),
                rng.random_range(0.0..=p.height),
            )
        })
        .collect();
    points.extend([
        (0.0, 0.0),
        (p.width, p.height),
        (p.width, 0.3),
        (0.7, p.height),
        (hx, hy),
    ]);
    for (x, y) in points {
        let h = model.height_at(&state, x, y);
        assert!((h - eval(x, y, 0, 0)).abs() <= 1e-13 * scale, "({x}, {y})");
        let probed: f64 = model
            .probe(x, y)
            .unwrap()
            .iter()
            .map(|(i, w)| w * state[*i])
            .sum();
        assert!((probed - h).abs() <= 1e-14 * scale);
    }
    for (x, y) in [
        (-1e-9, 0.5),
        (0.5, p.height * (1.0 + 1e-12)),
        (f64::NAN, 0.5),
        (0.5, f64::INFINITY),
    ] {
        assert!(model.height_at(&state, x, y).is_nan());
        assert!(model.probe(x, y).is_none());
    }
    // periodic: constants, and continuity across the seam of a random state
    let model = plate(params(PERIODIC, 0.3, 1.1), 3, 4);
    let u = model.zero_mode().unwrap();
    let c = u.iter().copied().fold(0.0, f64::max);
    let random: Vec<f64> = (0..model.n_dofs())
        .map(|_| rng.random_range(-1.0..1.0))
        .collect();
    for _ in 0..50 {
        let (x, y) = (
            rng.random_range(0.0..=p.width),
            rng.random_range(0.0..=p.height),
        );
        assert!((model.height_at(&u, x, y) - c).abs() < 1e-14 * c);
        let seam_x = model.height_at(&random, 0.0, y) - model.height_at(&random, p.width, y);
        let seam_y = model.height_at(&random, x, 0.0) - model.height_at(&random, x, p.height);
        assert!(
            seam_x.abs() < 1e-13 && seam_y.abs() < 1e-13,
            "seam {seam_x} {seam_y}"
        );
    }
}

/// `∫_e h` of the interpolated `state` over element `ey·nx + ex` by 5×5 Gauss quadrature
/// of `height_at` (independent of the element load vectors).
fn element_integral(model: &PlateModel, state: &[f64], ex: usize, ey: usize) -> f64 {
    const G: [(f64, f64); 5] = [
        (0.0, 128.0 / 225.0),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (-0.906_179_845_938_664, 0.236_926_885_056_189_08),
        (0.906_179_845_938_664, 0.236_926_885_056_189_08),
    ];
    let (hx, hy) = model.element_size();
    let mut sum = 0.0;
    for &(u, wu) in &G {
        for &(v, wv) in &G {
            let x = (ex as f64 + 0.5 * (u + 1.0)) * hx;
            let y = (ey as f64 + 0.5 * (v + 1.0)) * hy;
            sum += 0.25 * hx * hy * wu * wv * model.height_at(state, x, y);
        }
    }
    sum
}

/// What: the element noise of eq. (5) on the plate. Its covariance per unit `2kT/Δt` is
/// `Σ_ζ = Σ_e amp²·b_e b_eᵀ` with `amp² = ξ/|Ω_e|`, `b_e = ∫_e N`. For any field `g` with
/// DOFs `y`, `b_eᵀy = ∫_e g`, so `yᵀΣ_ζ y = ξ Σ_e (∫_e g)²/|Ω_e|` — the continuum
/// `ξ∫g²` of ⟨f f⟩ = 2ξkT δ (M1) with `g` replaced by its element means, hence `≤ yᵀCy`
/// (Cauchy–Schwarz), with equality for piecewise-constant `g`. In particular the total force
/// on the periodic membrane, the load on the uniform translation `u` (`w ≡ 1`), has
/// `uᵀΣ_ζ u = Σ_e (ξ/|Ω_e|)|Ω_e|² = ξab`, the continuum's ⟨(∫f)²⟩ = 2ξkT·ab per unit time;
/// and the assembled load vector gives `bᵀy = ∫g`. Reference: 5×5 Gauss quadrature of
/// `height_at` per element. Set-up: simply supported and periodic 3×4, 10 random vectors.
/// Tolerance: 1e-12 relative (round-off of sums of ~100 terms).
#[test]
fn element_noise_has_the_covariance_of_eq5() {
    let mut rng = trajectory_rng(SEED_PLATE_NOISE, 0);
    for boundary in [SS, PERIODIC] {
        let p = params(boundary, 0.3, 1.1);
        let model = plate(p, 3, 4);
        let n = model.n_dofs();
        let (hx, hy) = model.element_size();
        let mut sigma = DMatrix::<f64>::zeros(n, n);
        for l in model.element_loads() {
            assert!((l.amplitude - (p.drag / (hx * hy)).sqrt()).abs() < 1e-15 * l.amplitude);
            let mut b = DVector::<f64>::zeros(n);
            for (v, d) in l.load.iter().zip(&l.dofs) {
                if let Some(i) = d {
                    b[*i] += v;
                }
            }
            sigma += l.amplitude * l.amplitude * &b * b.transpose();
        }
        let c = model.damping().to_dense();
        let load = model.assembled_load_vector();
        for _ in 0..10 {
            let y = DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0));
            let ys = y.as_slice();
            let means: Vec<f64> = (0..4)
                .flat_map(|ey| (0..3).map(move |ex| (ex, ey)))
                .map(|(ex, ey)| element_integral(&model, ys, ex, ey))
                .collect();
            let expected: f64 = p.drag * means.iter().map(|m| m * m).sum::<f64>() / (hx * hy);
            let got = (y.transpose() * &sigma * &y)[(0, 0)];
            assert!(
                (got - expected).abs() <= 1e-12 * expected,
                "{boundary:?}: {got} vs {expected}"
            );
            assert!(got < (y.transpose() * &c * &y)[(0, 0)]);
            let integral: f64 = means.iter().sum();
            let by: f64 = load.iter().zip(ys).map(|(a, b)| a * b).sum();
            assert!((by - integral).abs() <= 1e-12 * means.iter().map(|m| m.abs()).sum::<f64>());
        }
        if boundary == PERIODIC {
            let u = DVector::from_vec(model.zero_mode().unwrap()) * (p.drag * p.area()).sqrt();
            let total = (u.transpose() * &sigma * &u)[(0, 0)];
            assert!(
                (total - p.drag * p.area()).abs() <= 1e-12 * total,
                "{total}"
            );
            assert!(((u.transpose() * &c * &u)[(0, 0)] - total).abs() <= 1e-12 * total);
        }
    }
}

/// What: `max_rate` (Sturm bisection between the twist vector's Rayleigh quotient and
/// Fried's element bound) equals the largest dense generalized eigenvalue, and for σ ≥ 0
/// the proven closed form [κ(2520/hx⁴ + 3528/(hx²hy²) + 2520/hy⁴) + 42σ(1/hx² + 1/hy²)]/ξ
/// (`max_rate_closed_form`; 8568κ/(ξh⁴) for σ = 0, hx = hy), also on meshes too large for
/// the dense route; for σ < 0 there is no closed form. The explicit Euler limit is
/// 2/λ_max. Reference: dense eigenvalues of the banded `(K, C)` (`dense_rates`); the closed
/// form (proof in `src/fem/plate.rs`). Set-up: both boundaries, σ ∈ {0, 0.3, −0.5 of the
/// buckling tension}, meshes 1×1 … 5×4 (dense) and up to 12×7 and 6×40 (closed form).
/// Tolerance: 1e-10 relative: the bisection stops at 1e-13, the dense eigensolver's
/// round-off is ≈ 1e-15 of λ_max.
#[test]
fn max_rate_matches_dense_and_closed_form() {
    for boundary in [SS, PERIODIC] {
        let base = params(boundary, 0.0, 1.1);
        for tension in [0.0, 0.3, 0.5 * base.buckling_tension()] {
            let p = params(boundary, tension, 1.1);
            let small: &[(usize, usize)] = if boundary == SS {
                &[(1, 1), (2, 3), (5, 4)]
            } else {
                &[(2, 2), (3, 2), (5, 4)]
            };
            for &(nx, ny) in small {
                let model = plate(p, nx, ny);
                let lmax = model.max_rate().unwrap();
                let dense = *dense_rates(&model).last().unwrap();
                assert!(
                    (lmax / dense - 1.0).abs() < 1e-10,
                    "{boundary:?} {nx}x{ny} σ {tension}: {lmax} vs {dense}"
                );
                let limit = model.explicit_euler_dt_limit().unwrap();
                assert!((limit * lmax - 2.0).abs() < 1e-15);
            }
            for (nx, ny) in [(3, 3), (12, 7), (6, 40)] {
                let model = plate(p, nx, ny);
                let closed = model.max_rate_closed_form();
                if tension < 0.0 {
                    assert!(closed.is_none());
                    continue;
                }
                let (lmax, closed) = (model.max_rate().unwrap(), closed.unwrap());
                assert!(
                    (lmax / closed - 1.0).abs() < 1e-10,
                    "{boundary:?} {nx}x{ny}: {lmax} vs {closed}"
                );
            }
        }
    }
    // the factor itself: square elements, σ = 0
    let model = plate(params(SS, 0.0, WIDTH), 9, 9);
    let h = WIDTH / 9.0;
    let factor = model.max_rate().unwrap() * 2.5 * h.powi(4) / KAPPA;
    assert!((factor / PLATE_RATE_FACTOR - 1.0).abs() < 1e-10, "{factor}");
}

/// What: bad input is refused, naming the key; `PlateModes` refuses meshes above its
/// cap. Reference: the documented contracts. Tolerance: exact.
#[test]
fn refusals_name_the_key() {
    let name = |e: Error| match e {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other}"),
    };
    assert_eq!(
        name(PlateModel::new(params(SS, 0.0, 1.1), 0, 2).unwrap_err()),
        "nx"
    );
    assert_eq!(
        name(PlateModel::new(params(PERIODIC, 0.0, 1.1), 2, 1).unwrap_err()),
        "ny"
    );
    let buckled = params(SS, 1.01 * params(SS, 0.0, 1.1).buckling_tension(), 1.1);
    assert_eq!(name(PlateModel::new(buckled, 2, 2).unwrap_err()), "tension");
    let big = plate(params(SS, 0.0, 1.1), 8, 600);
    assert_eq!(
        name(PlateModes::new(&big).unwrap_err()),
        "plate DOFs for PlateModes"
    );
}
