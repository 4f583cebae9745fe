//! The Hermite cubic beam element on `[0, h]`.
//!
//! Local DOFs are `[w_a, θ_a, w_b, θ_b]` (deflection and slope `θ = w'` at the left end
//! `a`, `s = 0`, and right end `b`, `s = h`). With `t = s/h` the shape functions are
//!
//! ```text
//! N1 = 1 − 3t² + 2t³      N2 = h (t − 2t² + t³)
//! N3 = 3t² − 2t³          N4 = h (−t² + t³)
//! ```
//!
//! so that `w(s) = N1 w_a + N2 θ_a + N3 w_b + N4 θ_b` interpolates every cubic exactly.

/// Element matrix type (symmetric, indexed by local DOF).
pub type ElementMatrix = [[f64; 4]; 4];

/// Shape functions `[N1, N2, N3, N4](s)` at local coordinate `s ∈ [0, h]` (see module
/// docs for the formulas).
pub fn shape(h: f64, s: f64) -> [f64; 4] {
    let t = s / h;
    let t2 = t * t;
    let t3 = t2 * t;
    [
        1.0 - 3.0 * t2 + 2.0 * t3,
        h * (t - 2.0 * t2 + t3),
        3.0 * t2 - 2.0 * t3,
        h * (t3 - t2),
    ]
}

/// First derivatives `dN/ds`: `[(−6t + 6t²)/h, 1 − 4t + 3t², (6t − 6t²)/h, −2t + 3t²]`.
pub fn shape_d1(h: f64, s: f64) -> [f64; 4] {
    let t = s / h;
    let t2 = t * t;
    [
        (-6.0 * t + 6.0 * t2) / h,
        1.0 - 4.0 * t + 3.0 * t2,
        (6.0 * t - 6.0 * t2) / h,
        -2.0 * t + 3.0 * t2,
    ]
}

/// Second derivatives `d²N/ds²`: `[(−6 + 12t)/h², (−4 + 6t)/h, (6 − 12t)/h², (−2 + 6t)/h]`.
pub fn shape_d2(h: f64, s: f64) -> [f64; 4] {
    let t = s / h;
    [
        (-6.0 + 12.0 * t) / (h * h),
        (-4.0 + 6.0 * t) / h,
        (6.0 - 12.0 * t) / (h * h),
        (-2.0 + 6.0 * t) / h,
    ]
}

/// Element damping ("consistent mass") matrix `C_e = ξ ∫₀ʰ NᵀN ds`
///
/// ```text
///           ⎡ 156   22h   54  −13h ⎤
/// ξh/420 ·  ⎢ 22h   4h²  13h  −3h² ⎥
///           ⎢  54   13h  156  −22h ⎥
///           ⎣−13h  −3h² −22h   4h² ⎦
/// ```
pub fn damping_matrix(h: f64, drag: f64) -> ElementMatrix {
    let f = drag * h / 420.0;
    let h2 = h * h;
    scale(
        [
            [156.0, 22.0 * h, 54.0, -13.0 * h],
            [22.0 * h, 4.0 * h2, 13.0 * h, -3.0 * h2],
            [54.0, 13.0 * h, 156.0, -22.0 * h],
            [-13.0 * h, -3.0 * h2, -22.0 * h, 4.0 * h2],
        ],
        f,
    )
}

/// Element bending stiffness `K_e = EI ∫₀ʰ N''ᵀN'' ds`
///
/// ```text
///           ⎡ 12   6h  −12   6h ⎤
/// EI/h³ ·   ⎢ 6h  4h²  −6h  2h² ⎥
///           ⎢−12  −6h   12  −6h ⎥
///           ⎣ 6h  2h²  −6h  4h² ⎦
/// ```
pub fn bending_matrix(h: f64, ei: f64) -> ElementMatrix {
    let f = ei / (h * h * h);
    let h2 = h * h;
    scale(
        [
            [12.0, 6.0 * h, -12.0, 6.0 * h],
            [6.0 * h, 4.0 * h2, -6.0 * h, 2.0 * h2],
            [-12.0, -6.0 * h, 12.0, -6.0 * h],
            [6.0 * h, 2.0 * h2, -6.0 * h, 4.0 * h2],
        ],
        f,
    )
}

/// Element geometric matrix `G_e = ∫₀ʰ N'ᵀN' ds` (so `½ wᵀG w = ½∫w'² ds`)
///
/// ```text
///            ⎡ 36   3h  −36   3h ⎤
/// 1/(30h) ·  ⎢ 3h  4h²  −3h  −h² ⎥
///            ⎢−36  −3h   36  −3h ⎥
///            ⎣ 3h  −h²  −3h  4h² ⎦
/// ```
pub fn geometric_matrix(h: f64) -> ElementMatrix {
    let f = 1.0 / (30.0 * h);
    let h2 = h * h;
    scale(
        [
            [36.0, 3.0 * h, -36.0, 3.0 * h],
            [3.0 * h, 4.0 * h2, -3.0 * h, -h2],
            [-36.0, -3.0 * h, 36.0, -3.0 * h],
            [3.0 * h, -h2, -3.0 * h, 4.0 * h2],
        ],
        f,
    )
}

/// Element load vector of a unit uniform load, `b_e = ∫₀ʰ N ds = [h/2, h²/12, h/2, −h²/12]`.
pub fn load_vector(h: f64) -> [f64; 4] {
    [0.5 * h, h * h / 12.0, 0.5 * h, -h * h / 12.0]
}

fn scale(mut m: ElementMatrix, f: f64) -> ElementMatrix {
    for row in m.iter_mut() {
        for v in row.iter_mut() {
            *v *= f;
        }
    }
    m
}

/// Gauss–Legendre nodes and weights on `[−1, 1]`, 5 points (exact for degree ≤ 9).
pub(crate) const GAUSS5: [(f64, f64); 5] = [
    (0.0, 128.0 / 225.0),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_08),
    (0.906_179_845_938_664, 0.236_926_885_056_189_08),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀ʰ f(s) ds by 5-point Gauss–Legendre.
    fn quad(h: f64, f: impl Fn(f64) -> f64) -> f64 {
        GAUSS5
            .iter()
            .map(|&(x, w)| 0.5 * h * w * f(0.5 * h * (x + 1.0)))
            .sum()
    }

    fn close(a: f64, b: f64, scale: f64) -> bool {
        (a - b).abs() <= 1e-13 * scale.max(1.0)
    }

    #[test]
    fn shape_functions_interpolate_end_values_and_cubics() {
        let h = 0.7;
        assert_eq!(shape(h, 0.0), [1.0, 0.0, 0.0, 0.0]);
        let nb = shape(h, h);
        for (v, e) in nb.iter().zip([0.0, 0.0, 1.0, 0.0]) {
            assert!((v - e).abs() < 1e-15);
        }
        let d0 = shape_d1(h, 0.0);
        assert!((d0[1] - 1.0).abs() < 1e-15 && d0[0].abs() < 1e-15);
        let dh = shape_d1(h, h);
        assert!((dh[3] - 1.0).abs() < 1e-14 && dh[2].abs() < 1e-14);
        // exact for an arbitrary cubic
        let p = |s: f64| 0.3 - 1.1 * s + 2.0 * s * s - 0.7 * s * s * s;
        let dp = |s: f64| -1.1 + 4.0 * s - 2.1 * s * s;
        let ddp = |s: f64| 4.0 - 4.2 * s;
        let dofs = [p(0.0), dp(0.0), p(h), dp(h)];
        for k in 0..=10 {
            let s = h * k as f64 / 10.0;
            let (n, n1, n2) = (shape(h, s), shape_d1(h, s), shape_d2(h, s));
            let dot = |a: [f64; 4]| a.iter().zip(dofs).map(|(x, y)| x * y).sum::<f64>();
            assert!((dot(n) - p(s)).abs() < 1e-13);
            assert!((dot(n1) - dp(s)).abs() < 1e-13);
            assert!((dot(n2) - ddp(s)).abs() < 1e-12);
        }
    }

    #[test]
    fn element_matrices_match_quadrature() {
        for &(h, ei, xi) in &[(1.0, 1.0, 1.0), (0.37, 2.5, 0.8), (3.1, 0.02, 7.0)] {
            let c = damping_matrix(h, xi);
            let k = bending_matrix(h, ei);
            let g = geometric_matrix(h);
            let b = load_vector(h);
            for i in 0..4 {
                let bi = quad(h, |s| shape(h, s)[i]);
                assert!(close(b[i], bi, h), "b[{i}] {} vs {bi}", b[i]);
                for j in 0..4 {
                    let cij = xi * quad(h, |s| shape(h, s)[i] * shape(h, s)[j]);
                    let kij = ei * quad(h, |s| shape_d2(h, s)[i] * shape_d2(h, s)[j]);
                    let gij = quad(h, |s| shape_d1(h, s)[i] * shape_d1(h, s)[j]);
                    assert!(close(c[i][j], cij, cij.abs()), "C[{i}][{j}]");
                    assert!(close(k[i][j], kij, kij.abs()), "K[{i}][{j}]");
                    assert!(close(g[i][j], gij, gij.abs()), "G[{i}][{j}]");
                    assert_eq!(c[i][j], c[j][i]);
                    assert_eq!(k[i][j], k[j][i]);
                    assert_eq!(g[i][j], g[j][i]);
                }
            }
        }
    }
}
