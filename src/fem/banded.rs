//! Symmetric banded matrices and their Cholesky factors.
//!
//! Storage is the lower band: entry `A_ij` with `j ≤ i ≤ j + bw` is kept at
//! `data[i·(bw+1) + (i − j)]`. Factorization costs `O(n·bw²)`, a solve or a product
//! `O(n·bw)`.

// Index loops over the band mirror the textbook formulas and are clearer than iterator
// chains here.
#![allow(clippy::needless_range_loop)]

use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// A symmetric `n × n` matrix with half-bandwidth `bw`: `A_ij = 0` for `|i − j| > bw`.
#[derive(Debug, Clone, PartialEq)]
pub struct SymBanded {
    n: usize,
    bw: usize,
    data: Vec<f64>,
}

impl SymBanded {
    /// The zero matrix of size `n` and half-bandwidth `bw`.
    pub fn new(n: usize, bw: usize) -> Self {
        SymBanded {
            n,
            bw,
            data: vec![0.0; n * (bw + 1)],
        }
    }

    /// Dimension `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Half-bandwidth `bw`.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        // requires j <= i <= j + bw
        i * (self.bw + 1) + (i - j)
    }

    /// Adds `v` to the entry `A_ij` — which is the same stored entry as `A_ji`, so the
    /// matrix stays symmetric (`A_ij = A_ji` both increase by `v`; call it once per
    /// unordered pair when assembling).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `i` or `j` is `≥ n` or `|i − j| > bw`.
    pub fn add(&mut self, i: usize, j: usize, v: f64) -> Result<()> {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i >= self.n || i - j > self.bw {
            return Err(Error::invalid(
                "banded matrix index",
                format!("({i}, {j})"),
                format!("< {} and within half-bandwidth {}", self.n, self.bw),
            ));
        }
        let k = self.idx(i, j);
        self.data[k] += v;
        Ok(())
    }

    /// Entry `A_ij` (0 outside the band).
    ///
    /// # Panics
    /// If `i` or `j` is `≥ n`.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.n && j < self.n, "index ({i}, {j}) out of range");
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i - j > self.bw {
            0.0
        } else {
            self.data[self.idx(i, j)]
        }
    }

    /// `y = A x`.
    ///
    /// # Panics
    /// If `x.len()` or `y.len()` differs from `n`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(x.len(), self.n, "mul_vec: x has wrong length");
        assert_eq!(y.len(), self.n, "mul_vec: y has wrong length");
        match self.bw {
            1 => self.mul_vec_fixed::<2>(x, y),
            2 => self.mul_vec_fixed::<3>(x, y),
            3 => self.mul_vec_fixed::<4>(x, y),
            _ => self.mul_vec_generic(x, y),
        }
    }

    /// `y = A x` for [`LANES`] vectors at once (structure-of-arrays): per lane the
    /// floating-point operations of [`Self::mul_vec`] in the same order, so every lane is
    /// bit-identical to its one-vector product.
    ///
    /// # Panics
    /// If the half-bandwidth is not 1, 2 or 3 or `x`, `y` do not have `n` rows.
    pub fn mul_lanes(&self, x: &[Lanes], y: &mut [Lanes]) {
        assert!(
            (1..=3).contains(&self.bw) && x.len() == self.n && y.len() == self.n,
            "mul_lanes: unsupported band or wrong length"
        );
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (just checked).
            unsafe { self.mul_lanes_avx(x, y) };
            return;
        }
        self.mul_lanes_band(x, y);
    }

    /// [`Self::mul_lanes_band`] compiled for AVX (no fused multiply-add: bit-identical).
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn mul_lanes_avx(&self, x: &[Lanes], y: &mut [Lanes]) {
        self.mul_lanes_band(x, y);
    }

    /// [`Self::mul_lanes`] after its checks, by half-bandwidth.
    #[inline(always)]
    fn mul_lanes_band(&self, x: &[Lanes], y: &mut [Lanes]) {
        match self.bw {
            1 => self.mul_lanes_fixed::<2>(x, y),
            2 => self.mul_lanes_fixed::<3>(x, y),
            _ => self.mul_lanes_fixed::<4>(x, y),
        }
    }

    /// [`Self::mul_lanes`] for half-bandwidth `W − 1`, row by row ([`lanes_product`]).
    #[inline(always)]
    fn mul_lanes_fixed<const W: usize>(&self, x: &[Lanes], y: &mut [Lanes]) {
        let rows = band_rows::<W>(&self.data, self.n);
        for_rows::<W>(
            self.n,
            #[inline(always)]
            |i, lower, upper| {
                y[i] = lanes_product(rows, x, i, lower, upper);
            },
        );
    }

    /// [`Self::mul_vec`] for half-bandwidth `W − 1`: one pass, row by row
    /// ([`product_row`]).
    fn mul_vec_fixed<const W: usize>(&self, x: &[f64], y: &mut [f64]) {
        let rows = band_rows::<W>(&self.data, self.n);
        for_rows::<W>(
            self.n,
            #[inline(always)]
            |i, lower, upper| {
                y[i] = product_row(rows, x, i, lower, upper);
            },
        );
    }

    /// [`Self::mul_vec`] for any half-bandwidth: the lower band row by row, then the
    /// upper band column by column. The reference for the fixed-bandwidth kernels.
    fn mul_vec_generic(&self, x: &[f64], y: &mut [f64]) {
        let w = self.bw + 1;
        for i in 0..self.n {
            let row = &self.data[i * w..(i + 1) * w];
            let mut acc = row[0] * x[i];
            let jmin = i.saturating_sub(self.bw);
            for j in jmin..i {
                acc += row[i - j] * x[j];
            }
            y[i] = acc;
        }
        // upper part: A_ji for j > i equals the stored A_ji (row j, offset j - i)
        for j in 0..self.n {
            let row = &self.data[j * w..(j + 1) * w];
            let imin = j.saturating_sub(self.bw);
            for i in imin..j {
                y[i] += row[j - i] * x[j];
            }
        }
    }

    /// Quadratic form `xᵀ A x`.
    ///
    /// # Panics
    /// If `x.len() != n`.
    pub fn quadratic_form(&self, x: &[f64]) -> f64 {
        let mut y = vec![0.0; self.n];
        self.mul_vec(x, &mut y);
        x.iter().zip(&y).map(|(a, b)| a * b).sum()
    }

    /// The ∞-norm `max_i Σ_j |A_ij|` (largest absolute row sum).
    pub fn inf_norm(&self) -> f64 {
        let (n, bw) = (self.n, self.bw);
        (0..n)
            .map(|i| {
                (i.saturating_sub(bw)..(i + bw + 1).min(n))
                    .map(|j| self.get(i, j).abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The dense symmetric matrix.
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut m = DMatrix::zeros(self.n, self.n);
        for i in 0..self.n {
            for j in i.saturating_sub(self.bw)..=i {
                let v = self.data[self.idx(i, j)];
                m[(i, j)] = v;
                m[(j, i)] = v;
            }
        }
        m
    }

    /// `a·A + b·B`, with half-bandwidth `max(bw_A, bw_B)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the dimensions differ.
    #[allow(non_snake_case)]
    pub fn linear_combination(a: f64, A: &SymBanded, b: f64, B: &SymBanded) -> Result<SymBanded> {
        let mut out = SymBanded {
            n: 0,
            bw: 0,
            data: Vec::new(),
        };
        out.linear_combination_into(a, A, b, B)?;
        Ok(out)
    }

    /// `self ← a·A + b·B` (half-bandwidth `max(bw_A, bw_B)`), reusing the storage of `self`
    /// (no allocation if `self` already has that shape). The same floating-point
    /// operations as [`Self::linear_combination`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the dimensions of `A` and `B` differ (`self` is then
    /// unchanged).
    #[allow(non_snake_case)]
    pub fn linear_combination_into(
        &mut self,
        a: f64,
        A: &SymBanded,
        b: f64,
        B: &SymBanded,
    ) -> Result<()> {
        if A.n != B.n {
            return Err(Error::invalid(
                "banded matrix dimension",
                B.n,
                format!("= {} (the other operand)", A.n),
            ));
        }
        self.n = A.n;
        self.bw = A.bw.max(B.bw);
        self.data.clear();
        self.data.resize(self.n * (self.bw + 1), 0.0);
        for (m, f) in [(A, a), (B, b)] {
            for i in 0..m.n {
                for j in i.saturating_sub(m.bw)..=i {
                    let k = self.idx(i, j);
                    self.data[k] += f * m.data[m.idx(i, j)];
                }
            }
        }
        Ok(())
    }

    /// Banded Cholesky factorization `A = L Lᵀ` (`L` lower triangular with the same
    /// half-bandwidth): `L_jj = sqrt(A_jj − Σ_k L_jk²)`,
    /// `L_ij = (A_ij − Σ_k L_ik L_jk)/L_jj`. Cost `O(n·bw²)`.
    ///
    /// # Errors
    /// [`Error::Numerical`] naming the pivot if `A` is not (numerically) positive definite.
    pub fn cholesky(&self) -> Result<BandedCholesky> {
        let mut l = BandedCholesky {
            n: 0,
            bw: 0,
            data: Vec::new(),
            inv_diag: Vec::new(),
        };
        l.factor_from(self)?;
        Ok(l)
    }

    /// Number of negative eigenvalues of `A`, by Sylvester's law of inertia: the number of
    /// negative pivots `d_j` of the banded `LDLᵀ` factorization without pivoting. Used for
    /// Sturm-sequence bisection of generalized eigenvalues (`#{λ < σ}` of `(K, C)` is the
    /// count for `K − σC`).
    ///
    /// # Errors
    /// [`Error::Numerical`] if a pivot is zero or not finite (the count is then undefined;
    /// shift slightly and retry).
    pub fn negative_eigenvalue_count(&self) -> Result<usize> {
        let (n, bw) = (self.n, self.bw);
        let w = bw + 1;
        // l holds unit-lower L off the diagonal and D on the diagonal
        let mut l = self.data.clone();
        let mut negative = 0;
        for j in 0..n {
            let kmin = j.saturating_sub(bw);
            let mut d = l[j * w];
            for k in kmin..j {
                let ljk = l[j * w + (j - k)];
                d -= ljk * ljk * l[k * w];
            }
            if d == 0.0 || !d.is_finite() {
                return Err(Error::Numerical {
                    routine: "banded LDLt inertia".into(),
                    detail: format!("pivot {j} is {d:e}"),
                });
            }
            l[j * w] = d;
            if d < 0.0 {
                negative += 1;
            }
            for i in j + 1..(j + w).min(n) {
                let kmin = i.saturating_sub(bw);
                let mut s = l[i * w + (i - j)];
                for k in kmin..j {
                    s -= l[i * w + (i - k)] * l[j * w + (j - k)] * l[k * w];
                }
                l[i * w + (i - j)] = s / d;
            }
        }
        Ok(negative)
    }
}

/// Cholesky factor `L` of a [`SymBanded`] matrix `A = L Lᵀ`, same half-bandwidth.
#[derive(Debug, Clone, PartialEq)]
pub struct BandedCholesky {
    n: usize,
    bw: usize,
    data: Vec<f64>,
    /// 1/L_jj: multiplications instead of divisions on the serial chain of the solves.
    inv_diag: Vec<f64>,
}

impl BandedCholesky {
    /// Factors `a = L Lᵀ` into `self` ([`SymBanded::cholesky`]), reusing the storage of
    /// `self` (no allocation if `self` already has the shape of `a`).
    ///
    /// # Errors
    /// [`Error::Numerical`] naming the pivot if `a` is not (numerically) positive definite;
    /// `self` then holds a partial factorization and must be refactored before use.
    pub fn factor_from(&mut self, a: &SymBanded) -> Result<()> {
        match self.factor(a) {
            None => Ok(()),
            Some((j, d)) => Err(Error::Numerical {
                routine: "banded Cholesky".into(),
                detail: format!(
                    "pivot {j} is {d:e}: matrix (n = {}) is not positive definite",
                    a.n
                ),
            }),
        }
    }

    /// [`Self::factor_from`] without building the error: `false` if `a` is not
    /// (numerically) positive definite. Allocation-free if `self` already has the shape of
    /// `a`, also on failure.
    pub fn try_factor_from(&mut self, a: &SymBanded) -> bool {
        self.factor(a).is_none()
    }

    /// The factorization; the first non-positive (or non-finite) pivot `(j, d_j)` if any.
    fn factor(&mut self, a: &SymBanded) -> Option<(usize, f64)> {
        let (n, bw) = (a.n, a.bw);
        let w = bw + 1;
        self.n = n;
        self.bw = bw;
        self.data.clear();
        self.data.extend_from_slice(&a.data);
        self.inv_diag.clear();
        let l = &mut self.data;
        for j in 0..n {
            // diagonal
            let kmin = j.saturating_sub(bw);
            let mut d = l[j * w];
            for k in kmin..j {
                let ljk = l[j * w + (j - k)];
                d -= ljk * ljk;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Some((j, d));
            }
            let ljj = d.sqrt();
            l[j * w] = ljj;
            for i in j + 1..(j + w).min(n) {
                let kmin = i.saturating_sub(bw);
                let mut s = l[i * w + (i - j)];
                for k in kmin..j {
                    s -= l[i * w + (i - k)] * l[j * w + (j - k)];
                }
                l[i * w + (i - j)] = s / ljj;
            }
        }
        self.inv_diag.extend((0..n).map(|j| 1.0 / l[j * w]));
        None
    }

    /// Dimension `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Half-bandwidth of `L`.
    pub fn bandwidth(&self) -> usize {
        self.bw
    }

    /// Entry `L_ij` (0 above the diagonal and outside the band).
    ///
    /// # Panics
    /// If `i` or `j` is `≥ n`.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.n && j < self.n, "index ({i}, {j}) out of range");
        if j > i || i - j > self.bw {
            0.0
        } else {
            self.data[i * (self.bw + 1) + (i - j)]
        }
    }

    /// Solves `A x = b` in place (forward `L y = b`, then backward `Lᵀ x = y`), `O(n·bw)`.
    ///
    /// Row `i` of the forward sweep is `y_i = (b_i − Σ_k L_ik y_k)·(1/L_ii)`, `k` ascending;
    /// row `i` of the backward sweep `x_i = (y_i − Σ_k L_ki x_k)·(1/L_ii)`, `k` ascending.
    ///
    /// # Panics
    /// If `b.len() != n`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve_in_place: wrong length");
        match self.bw {
            1 => self.solve_fixed::<2>(b),
            2 => self.solve_fixed::<3>(b),
            3 => self.solve_fixed::<4>(b),
            _ => {
                self.forward_generic(b);
                self.backward_generic(b);
            }
        }
    }

    /// `y ← L⁻¹ (A x + g)`: a banded product fused with the forward half of
    /// [`Self::solve_in_place`] in one sweep, the additive term `g_i` given by `term`
    /// ([`RowTerm`]; any `FnMut(usize) -> f64` closure is one). [`RowTerm::term`] is called
    /// once per row, for `i = 0, 1, …, n − 1` in this order (so it may draw random
    /// numbers). The same floating-point operations as [`SymBanded::mul_vec`] into `y`,
    /// then `y_i += g_i` for ascending `i`, then the forward sweep of
    /// [`Self::solve_in_place`], so the result is bit-identical to them. Follow with
    /// [`Self::solve_upper_into`] for `A_L⁻¹ (A x + g)`.
    ///
    /// # Panics
    /// If `a`, `x` or `y` does not have dimension `n`.
    pub fn solve_lower_product<T: RowTerm>(
        &self,
        a: &SymBanded,
        x: &[f64],
        mut term: T,
        y: &mut [f64],
    ) {
        assert_eq!(a.n, self.n, "solve_lower_product: matrix has wrong size");
        assert_eq!(x.len(), self.n, "solve_lower_product: x has wrong length");
        assert_eq!(y.len(), self.n, "solve_lower_product: y has wrong length");
        match (self.bw, a.bw) {
            (1, 1) => self.solve_lower_product_fixed::<2, _>(a, x, &mut term, y),
            (2, 2) => self.solve_lower_product_fixed::<3, _>(a, x, &mut term, y),
            (3, 3) => self.solve_lower_product_fixed::<4, _>(a, x, &mut term, y),
            _ => {
                a.mul_vec_generic(x, y);
                term.prepare(self.n);
                for (i, yi) in y.iter_mut().enumerate() {
                    *yi += term.term(i);
                }
                self.forward_generic(y);
            }
        }
    }

    /// `y ← L⁻¹ (A x + s·M z)`: [`Self::solve_lower_product`] with the additive term the
    /// product of a lower factor `M` (same dimension) with a vector `z` drawn during the
    /// sweep, `z_i = draw()` for `i = 0, 1, …, n − 1` in this order (row `i` of `M z`
    /// as [`Self::mul_lower_row`] sums it). `z` receives the draws where the sweep needs
    /// them stored (its contents afterwards are unspecified). Bit-identical to drawing
    /// all of `z`, [`SymBanded::mul_vec`] into `y`, [`Self::mul_lower`] into `m`,
    /// `y_i += s·m_i`, then the forward sweep of [`Self::solve_in_place`].
    ///
    /// # Panics
    /// If `a`, `m`, `x`, `z` or `y` does not have dimension `n`.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_lower_product_noise(
        &self,
        a: &SymBanded,
        x: &[f64],
        m: &BandedCholesky,
        s: f64,
        mut draw: impl FnMut() -> f64,
        z: &mut [f64],
        y: &mut [f64],
    ) {
        assert_eq!(
            a.n, self.n,
            "solve_lower_product_noise: matrix has wrong size"
        );
        assert_eq!(
            m.n, self.n,
            "solve_lower_product_noise: factor has wrong size"
        );
        assert_eq!(
            x.len(),
            self.n,
            "solve_lower_product_noise: x has wrong length"
        );
        assert_eq!(
            z.len(),
            self.n,
            "solve_lower_product_noise: z has wrong length"
        );
        assert_eq!(
            y.len(),
            self.n,
            "solve_lower_product_noise: y has wrong length"
        );
        match (self.bw, a.bw, m.bw) {
            (1, 1, 1) => {
                let mut term = LowerProductTerm::<2, _>::new(m, s, draw, z);
                self.solve_lower_product_fixed::<2, _>(a, x, &mut term, y);
            }
            (2, 2, 2) => {
                let mut term = LowerProductTerm::<3, _>::new(m, s, draw, z);
                self.solve_lower_product_fixed::<3, _>(a, x, &mut term, y);
            }
            (3, 3, 3) => {
                let mut term = LowerProductTerm::<4, _>::new(m, s, draw, z);
                self.solve_lower_product_fixed::<4, _>(a, x, &mut term, y);
            }
            _ => {
                for zi in z.iter_mut() {
                    *zi = draw();
                }
                a.mul_vec_generic(x, y);
                for (i, yi) in y.iter_mut().enumerate() {
                    *yi += s * m.mul_lower_row(z, i);
                }
                self.forward_generic(y);
            }
        }
    }

    /// Solves `Lᵀ x = y` from `y` into `x` (the backward half of [`Self::solve_in_place`],
    /// same operations as [`Self::solve_upper_in_place`]), `O(n·bw)`.
    ///
    /// # Panics
    /// If `y.len()` or `x.len()` differs from `n`.
    pub fn solve_upper_into(&self, y: &[f64], x: &mut [f64]) {
        assert_eq!(y.len(), self.n, "solve_upper_into: y has wrong length");
        assert_eq!(x.len(), self.n, "solve_upper_into: x has wrong length");
        match self.bw {
            1 => self.backward_fixed::<2>(Some(y), x),
            2 => self.backward_fixed::<3>(Some(y), x),
            3 => self.backward_fixed::<4>(Some(y), x),
            _ => {
                x.copy_from_slice(y);
                self.backward_generic(x);
            }
        }
    }

    /// Solves `Lᵀ x = b` in place (the backward half of [`Self::solve_in_place`]),
    /// `O(n·bw)`. With `b` iid standard normal, `x ~ N(0, A⁻¹)`.
    ///
    /// # Panics
    /// If `b.len() != n`.
    pub fn solve_upper_in_place(&self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve_upper_in_place: wrong length");
        match self.bw {
            1 => self.backward_fixed::<2>(None, b),
            2 => self.backward_fixed::<3>(None, b),
            3 => self.backward_fixed::<4>(None, b),
            _ => self.backward_generic(b),
        }
    }

    /// [`Self::solve_in_place`] for half-bandwidth `W − 1`.
    fn solve_fixed<const W: usize>(&self, b: &mut [f64]) {
        let n = self.n;
        let (rows, inv) = (band_rows::<W>(&self.data, n), &self.inv_diag[..n]);
        let head = (W - 1).min(n);
        for i in 0..head {
            b[i] = forward_row_edge(&rows[i], b, i, b[i], inv[i]);
        }
        if head < n {
            // pipelined as in `solve_lower_product_fixed`
            let mut window = window_before::<W>(b, head);
            let mut partial = far_terms_from(&rows[head], b, head, b[head]);
            for i in head..n {
                let v = near_term(&rows[i], &window, partial) * inv[i];
                b[i] = v;
                if i + 1 < n {
                    partial = far_terms(&rows[i + 1], &window, b[i + 1]);
                }
                push(&mut window, v);
            }
        }
        self.backward_fixed::<W>(None, b);
    }

    /// [`Self::solve_lower_product`] for half-bandwidth `W − 1` (of both matrices).
    fn solve_lower_product_fixed<const W: usize, T: RowTerm>(
        &self,
        a: &SymBanded,
        x: &[f64],
        term: &mut T,
        y: &mut [f64],
    ) {
        let (n, bw) = (self.n, W - 1);
        let (rows, inv) = (band_rows::<W>(&self.data, n), &self.inv_diag[..n]);
        let a_rows = band_rows::<W>(&a.data, n);
        let head = bw.min(n);
        term.prepare((head + 1).min(n));
        for i in 0..head {
            let b = product_row(a_rows, x, i, i, (n - 1 - i).min(bw)) + term.term(i);
            y[i] = forward_row_edge(&rows[i], y, i, b, inv[i]);
        }
        if head < n {
            // Software-pipelined: the terms of row i + 1 that do not involve y_i are
            // formed in iteration i, so the chain from y_{i−1} to y_i is one
            // multiply-subtract-multiply (the data flow, and so the result, is that of the
            // plain sweep; written this way no vectorized pair of products with y_{i−1}
            // lengthens the chain). The terms are prepared block by block, so that the
            // rows of a block make no calls (which would spill the windows).
            let upper = |i: usize| (n - 1 - i).min(bw);
            let mut window = window_before::<W>(y, head);
            let b = product_row(a_rows, x, head, bw, upper(head)) + term.term(head);
            let mut partial = far_terms_from(&rows[head], y, head, b);
            // rows whose successor has the full band (constant counts: unrolled)
            let full = n.saturating_sub(bw + 1).max(head);
            let mut start = head;
            while start < full {
                let end = (start + ROW_BLOCK).min(full);
                term.prepare(end + 1);
                for i in start..end {
                    let v = near_term(&rows[i], &window, partial) * inv[i];
                    y[i] = v;
                    let b = product_row(a_rows, x, i + 1, bw, bw) + term.term(i + 1);
                    partial = far_terms(&rows[i + 1], &window, b);
                    push(&mut window, v);
                }
                start = end;
            }
            term.prepare(n);
            for i in full..n {
                let v = near_term(&rows[i], &window, partial) * inv[i];
                y[i] = v;
                if i + 1 < n {
                    let b = product_row(a_rows, x, i + 1, bw, upper(i + 1)) + term.term(i + 1);
                    partial = far_terms(&rows[i + 1], &window, b);
                }
                push(&mut window, v);
            }
        }
    }

    /// Whether [`Self::theta_sweeps_lanes`] serves `a` with this factor: both of
    /// half-bandwidth 1, 2 or 3 (the fixed-bandwidth kernels, whose summation order the
    /// lane sweeps repeat), the same dimension.
    pub fn lanes_supported(&self, a: &SymBanded) -> bool {
        a.n == self.n && a.bw == self.bw && (1..=3).contains(&self.bw)
    }

    /// `x ← L⁻ᵀ L⁻¹ (A x + g)` for [`LANES`] independent vectors at once, stored
    /// structure-of-arrays (`x[i][l]` is entry `i` of vector `l`); `y` is scratch. Per
    /// lane the floating-point operations, in the same order, are those of
    /// [`Self::solve_lower_product`] with the additive term `g_i`, then
    /// [`Self::solve_upper_into`] into `x`: every lane is bit-identical to its one-vector
    /// sweep. The lanes' serial chains interleave, so the sweeps run at the throughput of
    /// the arithmetic rather than at the latency of one chain (the θ-scheme step of an
    /// ensemble in lockstep).
    ///
    /// # Panics
    /// If `!self.lanes_supported(a)` or `x`, `g`, `y` do not have `n` rows.
    pub fn theta_sweeps_lanes(&self, a: &SymBanded, g: &[Lanes], y: &mut [Lanes], x: &mut [Lanes]) {
        assert!(g.len() == self.n, "theta_sweeps_lanes: wrong length");
        self.sweeps_lanes(a, LaneTerm::Given(g), y, x);
    }

    /// [`Self::theta_sweeps_lanes`] with `g = s·M z` for a lower factor `M` of the same
    /// dimension and half-bandwidth, formed row by row inside the forward sweep: per lane
    /// bit-identical to [`Self::solve_lower_product_noise`] with the draws `z`, then
    /// [`Self::solve_upper_into`] into `x`.
    ///
    /// # Panics
    /// If `!self.lanes_supported(a)`, `m` differs in dimension or half-bandwidth, or `x`,
    /// `z`, `y` do not have `n` rows.
    #[allow(clippy::too_many_arguments)]
    pub fn theta_sweeps_lanes_noise(
        &self,
        a: &SymBanded,
        m: &BandedCholesky,
        s: f64,
        z: &[Lanes],
        y: &mut [Lanes],
        x: &mut [Lanes],
    ) {
        assert!(
            m.n == self.n && m.bw == self.bw && z.len() == self.n,
            "theta_sweeps_lanes_noise: factor or z does not match"
        );
        self.sweeps_lanes(a, LaneTerm::Lower { m, s, z }, y, x);
    }

    /// The lane sweeps with the additive term `term`.
    fn sweeps_lanes(&self, a: &SymBanded, term: LaneTerm, y: &mut [Lanes], x: &mut [Lanes]) {
        assert!(
            self.lanes_supported(a),
            "theta_sweeps_lanes: unsupported band"
        );
        assert!(
            x.len() == self.n && y.len() == self.n,
            "theta_sweeps_lanes: wrong length"
        );
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (just checked).
            unsafe { self.sweeps_lanes_avx(a, term, y, x) };
            return;
        }
        self.sweeps_lanes_band(a, term, y, x);
    }

    /// [`Self::sweeps_lanes_band`] compiled for AVX: the lane arithmetic in 4-wide
    /// vectors instead of SSE2's 2-wide ones. AVX has no fused multiply-add (that is the
    /// separate FMA extension, not enabled), so every product and sum is rounded as in the
    /// SSE2 code: the results are bit-identical with or without AVX.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn sweeps_lanes_avx(
        &self,
        a: &SymBanded,
        term: LaneTerm,
        y: &mut [Lanes],
        x: &mut [Lanes],
    ) {
        self.sweeps_lanes_band(a, term, y, x);
    }

    /// [`Self::sweeps_lanes`] after its checks, by half-bandwidth.
    #[inline(always)]
    fn sweeps_lanes_band(&self, a: &SymBanded, term: LaneTerm, y: &mut [Lanes], x: &mut [Lanes]) {
        match self.bw {
            1 => self.sweeps_lanes_term::<2>(a, term, y, x),
            2 => self.sweeps_lanes_term::<3>(a, term, y, x),
            _ => self.sweeps_lanes_term::<4>(a, term, y, x),
        }
    }

    /// [`Self::sweeps_lanes`] for half-bandwidth `W − 1`, the term by kind.
    #[inline(always)]
    fn sweeps_lanes_term<const W: usize>(
        &self,
        a: &SymBanded,
        term: LaneTerm,
        y: &mut [Lanes],
        x: &mut [Lanes],
    ) {
        match term {
            LaneTerm::Given(g) => self.sweeps_lanes_fixed::<W, _>(a, &GivenRows(g), y, x),
            LaneTerm::Lower { m, s, z } => {
                let term = LowerRows {
                    rows: band_rows::<W>(&m.data, m.n),
                    s,
                    z,
                };
                self.sweeps_lanes_fixed::<W, _>(a, &term, y, x);
            }
        }
    }

    /// [`Self::sweeps_lanes`] for half-bandwidth `W − 1`: one forward sweep forming row
    /// `i` of `A x + g` and substituting it at once, then the backward sweep; the last
    /// values of each sweep held in registers, the interior rows with constant band
    /// counts. (Plain functions marked `inline(always)`, no closures: a closure that is
    /// not inlined would be compiled without the caller's AVX.)
    #[inline(always)]
    fn sweeps_lanes_fixed<const W: usize, T: LaneRows>(
        &self,
        a: &SymBanded,
        term: &T,
        y: &mut [Lanes],
        x: &mut [Lanes],
    ) {
        let n = self.n;
        let bw = W - 1;
        let (rows, inv) = (band_rows::<W>(&self.data, n), &self.inv_diag[..n]);
        let a_rows = band_rows::<W>(&a.data, n);
        // the first rows, y_k for k ascending as `forward_row_edge` subtracts them
        let head = bw.min(n);
        for i in 0..head {
            let mut b = lanes_rhs(a_rows, x, i, i, (n - 1 - i).min(bw), term.edge_row(i));
            for d in (1..=i).rev() {
                lanes_sub_product(&mut b, rows[i][d], &y[i - d]);
            }
            y[i] = lanes_scaled(inv[i], &b);
        }
        if head < n {
            // the last values in registers (`window[d − 1] = y_{i−d}`), as
            // `window_before` keeps them for one vector: read back from memory, each
            // would wait for the store of the previous row
            let mut window = [[0.0; LANES]; W];
            for d in 1..W {
                window[d - 1] = y[head - d];
            }
            let full = n.saturating_sub(bw).max(head);
            for i in head..full {
                let b = lanes_rhs(a_rows, x, i, bw, bw, term.row(i));
                y[i] = lanes_forward_row(&rows[i], &mut window, b, inv[i]);
            }
            for i in full..n {
                let b = lanes_rhs(a_rows, x, i, bw, n - 1 - i, term.row(i));
                y[i] = lanes_forward_row(&rows[i], &mut window, b, inv[i]);
            }
        }
        lanes_backward(rows, inv, y, x);
    }

    /// `x ← L⁻ᵀ L⁻¹ b` for [`LANES`] vectors at once (structure-of-arrays), `y` holding
    /// `b` on entry and `L⁻¹ b` on return: per lane the floating-point operations, in the
    /// same order, of [`Self::solve_in_place`], so every lane is bit-identical to its
    /// one-vector solve (the θ-step of an ensemble of nonlinear filaments in lockstep,
    /// whose right-hand side is not a banded product plus a term).
    ///
    /// # Panics
    /// If the half-bandwidth is not 1, 2 or 3 or `y`, `x` do not have `n` rows.
    pub fn solve_lanes(&self, y: &mut [Lanes], x: &mut [Lanes]) {
        assert!(
            (1..=3).contains(&self.bw) && y.len() == self.n && x.len() == self.n,
            "solve_lanes: unsupported band or wrong length"
        );
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (just checked).
            unsafe { self.solve_lanes_avx(y, x) };
            return;
        }
        self.solve_lanes_band(y, x);
    }

    /// [`Self::solve_lanes_band`] compiled for AVX (bit-identical, as
    /// [`Self::sweeps_lanes_avx`]).
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn solve_lanes_avx(&self, y: &mut [Lanes], x: &mut [Lanes]) {
        self.solve_lanes_band(y, x);
    }

    /// [`Self::solve_lanes`] after its checks, by half-bandwidth.
    #[inline(always)]
    fn solve_lanes_band(&self, y: &mut [Lanes], x: &mut [Lanes]) {
        match self.bw {
            1 => self.solve_lanes_fixed::<2>(y, x),
            2 => self.solve_lanes_fixed::<3>(y, x),
            _ => self.solve_lanes_fixed::<4>(y, x),
        }
    }

    /// [`Self::solve_lanes`] for half-bandwidth `W − 1`: the forward sweep of
    /// [`Self::solve_in_place`] in place in `y` (its rows as `forward_row_edge`, then
    /// `far_terms` + `near_term` subtract them, `k` ascending), then [`lanes_backward`].
    #[inline(always)]
    fn solve_lanes_fixed<const W: usize>(&self, y: &mut [Lanes], x: &mut [Lanes]) {
        let n = self.n;
        let (rows, inv) = (band_rows::<W>(&self.data, n), &self.inv_diag[..n]);
        let head = (W - 1).min(n);
        for i in 0..head {
            let mut b = y[i];
            for d in (1..=i).rev() {
                lanes_sub_product(&mut b, rows[i][d], &y[i - d]);
            }
            y[i] = lanes_scaled(inv[i], &b);
        }
        if head < n {
            let mut window = [[0.0; LANES]; W];
            for d in 1..W {
                window[d - 1] = y[head - d];
            }
            for i in head..n {
                y[i] = lanes_forward_row(&rows[i], &mut window, y[i], inv[i]);
            }
        }
        lanes_backward(rows, inv, y, x);
    }

    /// The backward sweep for half-bandwidth `W − 1`, from `y` into `x`, or in place in
    /// `x` if `y` is `None`.
    fn backward_fixed<const W: usize>(&self, y: Option<&[f64]>, x: &mut [f64]) {
        let n = self.n;
        let (rows, inv) = (band_rows::<W>(&self.data, n), &self.inv_diag[..n]);
        let tail = n.saturating_sub(W - 1);
        for i in (tail..n).rev() {
            let s = y.map_or(x[i], |y| y[i]);
            x[i] = backward_row_edge(rows, x, i, s, inv[i]);
        }
        if tail > 0 {
            let mut window = window_after::<W>(x, tail - 1);
            for i in (0..tail).rev() {
                let s = y.map_or(x[i], |y| y[i]);
                x[i] = backward_row(rows, &mut window, i, s, inv[i]);
            }
        }
    }

    /// The forward sweep `L y = b` in place, any half-bandwidth.
    fn forward_generic(&self, b: &mut [f64]) {
        let w = self.bw + 1;
        for i in 0..self.n {
            let row = &self.data[i * w..i * w + w];
            let lo = i.saturating_sub(self.bw);
            let mut s = b[i];
            for (k, bk) in b[lo..i].iter().enumerate() {
                s -= row[i - lo - k] * bk;
            }
            b[i] = s * self.inv_diag[i];
        }
    }

    /// The backward sweep `Lᵀ x = b` in place, any half-bandwidth.
    fn backward_generic(&self, b: &mut [f64]) {
        let w = self.bw + 1;
        let n = self.n;
        for i in (0..n).rev() {
            let hi = (i + w).min(n);
            let mut s = b[i];
            for k in i + 1..hi {
                s -= self.data[k * w + (k - i)] * b[k];
            }
            b[i] = s * self.inv_diag[i];
        }
    }

    /// `ln det A = 2 Σ_j ln L_jj`.
    pub fn log_det(&self) -> f64 {
        -2.0 * self.inv_diag.iter().map(|d| d.ln()).sum::<f64>()
    }

    /// Row `i` of `L z`: `(L z)_i = 0 + Σ_k L_ik z_k`, `k` ascending from
    /// `max(0, i − bw)` to `i`, reading only `z_k` for those `k`. The same operations as
    /// row `i` of [`Self::mul_lower`].
    ///
    /// # Panics
    /// If `i ≥ n` or `z.len() ≤ i`.
    #[inline]
    pub fn mul_lower_row(&self, z: &[f64], i: usize) -> f64 {
        self.mul_lower_row_with(i, z[i], |d| z[i - d])
    }

    /// [`Self::mul_lower_row`] with `z_i` given as a value and the earlier entries by
    /// distance, `previous(d) = z_{i−d}` for `d = 1 … min(i, bw)`: for forming `L z` row by
    /// row while `z` is being drawn, without reading `z_i` back from memory right after
    /// storing it (a wide load over a fresh narrow store stalls store forwarding).
    ///
    /// # Panics
    /// If `i ≥ n`.
    #[inline]
    pub fn mul_lower_row_with(&self, i: usize, z_i: f64, previous: impl Fn(usize) -> f64) -> f64 {
        assert!(i < self.n, "mul_lower_row: row {i} out of range");
        let w = self.bw + 1;
        let row = &self.data[i * w..i * w + w];
        let mut s = 0.0;
        for d in (1..=i.min(self.bw)).rev() {
            s += row[d] * previous(d);
        }
        s + row[0] * z_i
    }

    /// `out = L z`. With `z` iid standard normal, `out ~ N(0, A)`.
    ///
    /// # Panics
    /// If `z.len()` or `out.len()` differs from `n`.
    pub fn mul_lower(&self, z: &[f64], out: &mut [f64]) {
        assert_eq!(z.len(), self.n, "mul_lower: z has wrong length");
        assert_eq!(out.len(), self.n, "mul_lower: out has wrong length");
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.mul_lower_row(z, i);
        }
    }

    /// `z ← L z` in place (rows computed from the last to the first, so each uses only
    /// still-unmodified entries).
    ///
    /// # Panics
    /// If `z.len() != n`.
    pub fn mul_lower_in_place(&self, z: &mut [f64]) {
        assert_eq!(z.len(), self.n, "mul_lower_in_place: wrong length");
        match self.bw {
            1 => self.mul_lower_in_place_fixed::<2>(z),
            2 => self.mul_lower_in_place_fixed::<3>(z),
            3 => self.mul_lower_in_place_fixed::<4>(z),
            _ => {
                for i in (0..self.n).rev() {
                    z[i] = self.mul_lower_row(z, i);
                }
            }
        }
    }

    /// [`Self::mul_lower_in_place`] for half-bandwidth `W − 1`.
    fn mul_lower_in_place_fixed<const W: usize>(&self, z: &mut [f64]) {
        let rows = band_rows::<W>(&self.data, self.n);
        let head = (W - 1).min(self.n);
        for i in (head..self.n).rev() {
            z[i] = lower_row(&rows[i], z, i, W - 1);
        }
        for i in (0..head).rev() {
            z[i] = lower_row(&rows[i], z, i, i);
        }
    }

    /// The dense lower-triangular factor `L`.
    pub fn to_dense_lower(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }
}

/// Vectors advanced together by the lane sweeps ([`BandedCholesky::theta_sweeps_lanes`]).
pub const LANES: usize = 8;

/// One entry of [`LANES`] vectors (structure-of-arrays).
pub type Lanes = [f64; LANES];

/// The additive term `g` of the lane sweeps: given, or `s·M z` formed row by row.
enum LaneTerm<'a> {
    Given(&'a [Lanes]),
    Lower {
        m: &'a BandedCholesky,
        s: f64,
        z: &'a [Lanes],
    },
}

/// The additive term of the lane sweeps, row by row.
trait LaneRows {
    /// `g_i` for an interior row (`i ≥ bw`).
    fn row(&self, i: usize) -> Lanes;
    /// `g_i` for any row.
    fn edge_row(&self, i: usize) -> Lanes;
}

/// `g` given.
struct GivenRows<'a>(&'a [Lanes]);

impl LaneRows for GivenRows<'_> {
    #[inline(always)]
    fn row(&self, i: usize) -> Lanes {
        self.0[i]
    }
    #[inline(always)]
    fn edge_row(&self, i: usize) -> Lanes {
        self.0[i]
    }
}

/// `g = s·M z` for a lower factor `M` of half-bandwidth `W − 1` (band rows `rows`), row
/// `i` summed as `lower_row` sums it, then scaled.
struct LowerRows<'a, const W: usize> {
    rows: &'a [[f64; W]],
    s: f64,
    z: &'a [Lanes],
}

impl<const W: usize> LowerRows<'_, W> {
    #[inline(always)]
    fn lower(&self, i: usize, count: usize) -> Lanes {
        let row = &self.rows[i];
        let mut acc = [0.0; LANES];
        for d in (1..=count).rev() {
            lanes_add_product(&mut acc, row[d], &self.z[i - d]);
        }
        lanes_add_product(&mut acc, row[0], &self.z[i]);
        lanes_scaled(self.s, &acc)
    }
}

impl<const W: usize> LaneRows for LowerRows<'_, W> {
    #[inline(always)]
    fn row(&self, i: usize) -> Lanes {
        self.lower(i, W - 1)
    }
    #[inline(always)]
    fn edge_row(&self, i: usize) -> Lanes {
        self.lower(i, i.min(W - 1))
    }
}

/// Row `i` of `A x` for [`LANES`] vectors, summed as [`product_row`] sums it, plus `g`.
#[inline(always)]
fn lanes_rhs<const W: usize>(
    a_rows: &[[f64; W]],
    x: &[Lanes],
    i: usize,
    lower: usize,
    upper: usize,
    g: Lanes,
) -> Lanes {
    let mut b = lanes_product(a_rows, x, i, lower, upper);
    lanes_add(&mut b, &g);
    b
}

/// Row `i` of `A x` for [`LANES`] vectors, summed as [`product_row`] sums it.
#[inline(always)]
fn lanes_product<const W: usize>(
    a_rows: &[[f64; W]],
    x: &[Lanes],
    i: usize,
    lower: usize,
    upper: usize,
) -> Lanes {
    let row = &a_rows[i];
    let mut b = lanes_scaled(row[0], &x[i]);
    for d in (1..=lower).rev() {
        lanes_add_product(&mut b, row[d], &x[i - d]);
    }
    for d in 1..=upper {
        lanes_add_product(&mut b, a_rows[i + d][d], &x[i + d]);
    }
    b
}

/// The backward sweep `Lᵀ x = y` for [`LANES`] vectors (band rows `rows`, reciprocal
/// pivots `inv`), its rows as `backward_row_edge` and `backward_row` sum them
/// (`k = i + 1, i + 2, …`), the last values in registers.
#[inline(always)]
fn lanes_backward<const W: usize>(rows: &[[f64; W]], inv: &[f64], y: &[Lanes], x: &mut [Lanes]) {
    let n = rows.len();
    let tail = n.saturating_sub(W - 1);
    for i in (tail..n).rev() {
        let mut s = y[i];
        for d in 1..n - i {
            lanes_sub_product(&mut s, rows[i + d][d], &x[i + d]);
        }
        x[i] = lanes_scaled(inv[i], &s);
    }
    if tail > 0 {
        let mut window = [[0.0; LANES]; W];
        for d in 1..W {
            window[d - 1] = x[tail - 1 + d];
        }
        for i in (0..tail).rev() {
            let mut s = y[i];
            for d in 1..W {
                lanes_sub_product(&mut s, rows[i + d][d], &window[d - 1]);
            }
            let v = lanes_scaled(inv[i], &s);
            x[i] = v;
            push(&mut window, v);
        }
    }
}

/// An interior row of the forward sweep for [`LANES`] vectors: `y_i = (b − Σ_k L_ik y_k)·inv`,
/// `k` ascending as `far_terms` + `near_term` subtract them, the previous values from
/// `window`, onto which `y_i` is pushed.
#[inline(always)]
fn lanes_forward_row<const W: usize>(
    l_row: &[f64; W],
    window: &mut [Lanes; W],
    mut b: Lanes,
    inv: f64,
) -> Lanes {
    for d in (1..W).rev() {
        lanes_sub_product(&mut b, l_row[d], &window[d - 1]);
    }
    let v = lanes_scaled(inv, &b);
    push(window, v);
    v
}

/// `c·v` per lane (`c * v[l]`, the product order of the one-vector kernels).
#[inline(always)]
fn lanes_scaled(c: f64, v: &Lanes) -> Lanes {
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        out[l] = c * v[l];
    }
    out
}

/// `acc ← acc + c·v` per lane.
#[inline(always)]
fn lanes_add_product(acc: &mut Lanes, c: f64, v: &Lanes) {
    for l in 0..LANES {
        acc[l] += c * v[l];
    }
}

/// `acc ← acc − c·v` per lane.
#[inline(always)]
fn lanes_sub_product(acc: &mut Lanes, c: f64, v: &Lanes) {
    for l in 0..LANES {
        acc[l] -= c * v[l];
    }
}

/// `acc ← acc + v` per lane.
#[inline(always)]
fn lanes_add(acc: &mut Lanes, v: &Lanes) {
    for l in 0..LANES {
        acc[l] += v[l];
    }
}

/// Rows per block of the fused forward sweep: [`RowTerm::prepare`] is called once per
/// block.
const ROW_BLOCK: usize = 16;

/// The additive term `g_i` of the rows of a fused forward sweep
/// ([`BandedCholesky::solve_lower_product`]).
pub trait RowTerm {
    /// `g_i`. Called once per row, for `i = 0, 1, …, n − 1` in this order.
    fn term(&mut self, i: usize) -> f64;

    /// Announces that the rows `i < end` will be requested next (`end` never decreases,
    /// and is `n` before the last rows): a term that draws random numbers may draw them
    /// here, block by block, so that the sweep over the block makes no calls. Does
    /// nothing by default.
    #[inline]
    fn prepare(&mut self, _end: usize) {}
}

impl<F: FnMut(usize) -> f64> RowTerm for F {
    #[inline(always)]
    fn term(&mut self, i: usize) -> f64 {
        self(i)
    }
}

/// `g_i = s·(M z)_i` for a lower factor `M` of half-bandwidth `W − 1`, with `z_i = draw()`
/// drawn into `z` block by block ([`RowTerm::prepare`]), in ascending `i`.
struct LowerProductTerm<'a, const W: usize, D> {
    rows: &'a [[f64; W]],
    s: f64,
    draw: D,
    z: &'a mut [f64],
    /// Entries of `z` drawn so far.
    drawn: usize,
}

impl<'a, const W: usize, D: FnMut() -> f64> LowerProductTerm<'a, W, D> {
    fn new(m: &'a BandedCholesky, s: f64, draw: D, z: &'a mut [f64]) -> Self {
        debug_assert_eq!(m.bw + 1, W);
        LowerProductTerm {
            rows: band_rows::<W>(&m.data, m.n),
            s,
            draw,
            z,
            drawn: 0,
        }
    }
}

impl<const W: usize, D: FnMut() -> f64> RowTerm for LowerProductTerm<'_, W, D> {
    #[inline]
    fn prepare(&mut self, end: usize) {
        while self.drawn < end {
            self.z[self.drawn] = (self.draw)();
            self.drawn += 1;
        }
    }

    #[inline(always)]
    fn term(&mut self, i: usize) -> f64 {
        debug_assert!(i < self.drawn);
        let row = &self.rows[i];
        let lz = if i + 1 >= W {
            lower_row(row, self.z, i, W - 1)
        } else {
            lower_row(row, self.z, i, i)
        };
        self.s * lz
    }
}

/// The band of an `n`-row banded matrix as rows of `W = bw + 1` entries (row `i`:
/// `[M_ii, M_i,i−1, …, M_i,i−bw]`).
fn band_rows<const W: usize>(data: &[f64], n: usize) -> &[[f64; W]] {
    let (rows, rest) = data.as_chunks::<W>();
    debug_assert!(rest.is_empty());
    &rows[..n]
}

/// Calls `f(i, lower, upper)` for the rows `i = 0, 1, …, n − 1` of an `n × n` matrix of
/// half-bandwidth `W − 1`, with `lower = min(i, W − 1)` and `upper = min(n − 1 − i, W − 1)`
/// the numbers of band entries left and right of the diagonal. On the interior rows both
/// are the constant `W − 1`, so that the loops over them unroll.
#[inline(always)]
fn for_rows<const W: usize>(n: usize, mut f: impl FnMut(usize, usize, usize)) {
    let bw = W - 1;
    let head = bw.min(n);
    let tail = n.saturating_sub(bw).max(head);
    for i in 0..head {
        f(i, i, (n - 1 - i).min(bw));
    }
    for i in head..tail {
        f(i, bw, bw);
    }
    for i in tail..n {
        f(i, i.min(bw), n - 1 - i);
    }
}

/// Row `i` of `A x` for a symmetric band `rows`, summed as [`SymBanded::mul_vec`] does:
/// the diagonal term, then the `lower` terms left of it in ascending column, then the
/// `upper` terms right of it in ascending column.
#[inline(always)]
fn product_row<const W: usize>(
    rows: &[[f64; W]],
    x: &[f64],
    i: usize,
    lower: usize,
    upper: usize,
) -> f64 {
    let row = &rows[i];
    let mut acc = row[0] * x[i];
    for d in (1..=lower).rev() {
        acc += row[d] * x[i - d];
    }
    for d in 1..=upper {
        acc += rows[i + d][d] * x[i + d];
    }
    acc
}

/// Row `i` of `L z`, summed as [`BandedCholesky::mul_lower_row`] does: `0 + Σ_k L_ik z_k`,
/// `k` ascending over the `lower` entries left of the diagonal, then the diagonal.
#[inline(always)]
fn lower_row<const W: usize>(row: &[f64; W], z: &[f64], i: usize, lower: usize) -> f64 {
    let mut acc = 0.0;
    for d in (1..=lower).rev() {
        acc += row[d] * z[i - d];
    }
    acc + row[0] * z[i]
}

/// `window ← [v, window[0], …]`: the last values of a sweep, nearest first.
#[inline(always)]
fn push<T: Copy, const W: usize>(window: &mut [T; W], v: T) {
    for k in (1..W).rev() {
        window[k] = window[k - 1];
    }
    window[0] = v;
}

/// The values of a forward sweep before row `i ≥ W − 1`, nearest first:
/// `window[d − 1] = y_{i−d}` for `d = 1 … W − 1` (the last slot is unused). Held in
/// registers over the interior rows: read back from memory, each would wait for the store
/// of the previous row.
#[inline(always)]
fn window_before<const W: usize>(y: &[f64], i: usize) -> [f64; W] {
    let mut window = [0.0; W];
    for d in 1..W {
        window[d - 1] = y[i - d];
    }
    window
}

/// The values of a backward sweep after row `i`, nearest first: `window[d − 1] = x_{i+d}`
/// for `d = 1 … W − 1`, `i + W − 1 < n`.
#[inline(always)]
fn window_after<const W: usize>(x: &[f64], i: usize) -> [f64; W] {
    let mut window = [0.0; W];
    window[..W - 1].copy_from_slice(&x[i + 1..i + W]);
    window
}

/// `s − Σ_{d = W−1 … 2} row[d]·y_{i−d}`: the first terms of an interior row `i ≥ W − 1`
/// of the forward sweep `y_i = (s − Σ_k L_ik y_k)·inv` (`k` ascending), formed in the
/// iteration of row `i − 1`, before `y_{i−1}` is pushed (`window[d − 2] = y_{i−d}`).
#[inline(always)]
fn far_terms<const W: usize>(row: &[f64; W], window: &[f64; W], mut s: f64) -> f64 {
    for d in (2..W).rev() {
        s -= row[d] * window[d - 2];
    }
    s
}

/// [`far_terms`] for the first interior row `i`, reading `y_{i−d}` from `y`.
#[inline(always)]
fn far_terms_from<const W: usize>(row: &[f64; W], y: &[f64], i: usize, mut s: f64) -> f64 {
    for d in (2..W).rev() {
        s -= row[d] * y[i - d];
    }
    s
}

/// `s − row[1]·y_{i−1}` (`window[0] = y_{i−1}`): the last term of an interior forward row, after
/// [`far_terms`].
#[inline(always)]
fn near_term<const W: usize>(row: &[f64; W], window: &[f64; W], s: f64) -> f64 {
    if W > 1 { s - row[1] * window[0] } else { s }
}

/// A first row of the forward sweep (`i < W − 1`), the previous values read from `y`.
#[inline(always)]
fn forward_row_edge<const W: usize>(
    row: &[f64; W],
    y: &[f64],
    i: usize,
    mut s: f64,
    inv: f64,
) -> f64 {
    for d in (1..=i).rev() {
        s -= row[d] * y[i - d];
    }
    s * inv
}

/// One interior row of the backward sweep (`i + W − 1 < n`): `x_i = (s − Σ_k L_ki x_k)·inv`,
/// `k` ascending over the `W − 1` next rows, whose values `window` holds
/// ([`window_after`]); `x_i` is pushed onto `window`.
#[inline(always)]
fn backward_row<const W: usize>(
    rows: &[[f64; W]],
    window: &mut [f64; W],
    i: usize,
    mut s: f64,
    inv: f64,
) -> f64 {
    for d in 1..W {
        s -= rows[i + d][d] * window[d - 1];
    }
    let v = s * inv;
    push(window, v);
    v
}

/// A last row of the backward sweep (`i + W − 1 ≥ n`), the next values read from `x`.
#[inline(always)]
fn backward_row_edge<const W: usize>(
    rows: &[[f64; W]],
    x: &[f64],
    i: usize,
    mut s: f64,
    inv: f64,
) -> f64 {
    for d in 1..rows.len() - i {
        s -= rows[i + d][d] * x[i + d];
    }
    s * inv
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane sweeps, with a given term and with `s·M z`, through the AVX and the
    /// plain path, equal the one-vector fused sweeps bit for bit in every lane, for every
    /// served half-bandwidth and for sizes below, at and above the band.
    #[test]
    fn lane_sweeps_equal_one_vector_sweeps_bit_for_bit() {
        for bw in 1..=3 {
            for n in [1, 2, 3, 4, 5, 9, 20] {
                let a = spd(n, bw);
                let lhs = SymBanded::linear_combination(1.0, &a, 0.3, &spd(n, bw))
                    .unwrap()
                    .cholesky()
                    .unwrap();
                let m = a.cholesky().unwrap();
                assert!(lhs.lanes_supported(&a));
                let val = |i: usize, l: usize, k: usize| ((i * 13 + l * 7 + k) as f64 * 0.37).sin();
                let x0: Vec<Lanes> = (0..n)
                    .map(|i| std::array::from_fn(|l| val(i, l, 1)))
                    .collect();
                let z: Vec<Lanes> = (0..n)
                    .map(|i| std::array::from_fn(|l| val(i, l, 2)))
                    .collect();
                let s = 0.7;
                for noise in [false, true] {
                    let mut paths = Vec::new();
                    for plain in [false, true] {
                        let (mut x, mut y) = (x0.clone(), vec![[0.0; LANES]; n]);
                        let term = if noise {
                            LaneTerm::Lower { m: &m, s, z: &z }
                        } else {
                            LaneTerm::Given(&z)
                        };
                        if plain {
                            lhs.sweeps_lanes_band(&a, term, &mut y, &mut x);
                        } else {
                            lhs.sweeps_lanes(&a, term, &mut y, &mut x);
                        }
                        paths.push(x);
                    }
                    for l in 0..LANES {
                        let xl: Vec<f64> = x0.iter().map(|v| v[l]).collect();
                        let zl: Vec<f64> = z.iter().map(|v| v[l]).collect();
                        let mut y = vec![0.0; n];
                        if noise {
                            let mut k = 0;
                            let mut scratch = vec![0.0; n];
                            lhs.solve_lower_product_noise(
                                &a,
                                &xl,
                                &m,
                                s,
                                || {
                                    k += 1;
                                    zl[k - 1]
                                },
                                &mut scratch,
                                &mut y,
                            );
                        } else {
                            lhs.solve_lower_product(&a, &xl, |i: usize| zl[i], &mut y);
                        }
                        let mut expected = vec![0.0; n];
                        lhs.solve_upper_into(&y, &mut expected);
                        for x in &paths {
                            for i in 0..n {
                                assert_eq!(
                                    x[i][l].to_bits(),
                                    expected[i].to_bits(),
                                    "bw {bw} n {n} noise {noise} lane {l} row {i}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// The lane product and the lane solve, through the AVX and the plain path, equal
    /// [`SymBanded::mul_vec`] and [`BandedCholesky::solve_in_place`] bit for bit in every
    /// lane, for every served half-bandwidth and for sizes below, at and above the band.
    #[test]
    fn lane_products_and_solves_equal_one_vector_ones_bit_for_bit() {
        for bw in 1..=3 {
            for n in [1, 2, 3, 4, 5, 9, 20] {
                let a = spd(n, bw);
                let chol = a.cholesky().unwrap();
                let x: Vec<Lanes> = (0..n)
                    .map(|i| std::array::from_fn(|l| ((i * 11 + l * 5) as f64 * 0.41).cos()))
                    .collect();
                for plain in [false, true] {
                    let (mut ax, mut y, mut sol) =
                        (vec![[0.0; LANES]; n], x.clone(), vec![[f64::NAN; LANES]; n]);
                    if plain {
                        a.mul_lanes_band(&x, &mut ax);
                        chol.solve_lanes_band(&mut y, &mut sol);
                    } else {
                        a.mul_lanes(&x, &mut ax);
                        chol.solve_lanes(&mut y, &mut sol);
                    }
                    for l in 0..LANES {
                        let xl: Vec<f64> = x.iter().map(|v| v[l]).collect();
                        let mut expected = vec![0.0; n];
                        a.mul_vec(&xl, &mut expected);
                        let mut solved = xl.clone();
                        chol.solve_in_place(&mut solved);
                        for i in 0..n {
                            let at = format!("bw {bw} n {n} plain {plain} lane {l} row {i}");
                            assert_eq!(ax[i][l].to_bits(), expected[i].to_bits(), "{at}");
                            assert_eq!(sol[i][l].to_bits(), solved[i].to_bits(), "{at}");
                        }
                    }
                }
            }
        }
    }

    /// A deterministic SPD banded test matrix.
    fn spd(n: usize, bw: usize) -> SymBanded {
        let mut a = SymBanded::new(n, bw);
        for i in 0..n {
            for j in i.saturating_sub(bw)..i {
                let v = ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.5;
                a.add(i, j, v).unwrap();
            }
            a.add(i, i, 2.0 * bw as f64 + 1.0 + (i % 3) as f64).unwrap();
        }
        a
    }

    #[test]
    fn add_get_and_band_errors() {
        let mut a = SymBanded::new(5, 2);
        a.add(3, 1, 2.0).unwrap();
        a.add(1, 3, 0.5).unwrap();
        assert_eq!(a.get(3, 1), 2.5);
        assert_eq!(a.get(1, 3), 2.5);
        assert_eq!(a.get(4, 0), 0.0);
        assert!(a.add(4, 1, 1.0).is_err());
        assert!(a.add(5, 5, 1.0).is_err());
        assert_eq!(a.n(), 5);
        assert_eq!(a.bandwidth(), 2);
    }

    #[test]
    fn mul_vec_and_combination_match_dense() {
        let a = spd(9, 3);
        let b = spd(9, 1);
        let x: Vec<f64> = (0..9).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; 9];
        a.mul_vec(&x, &mut y);
        let yd = a.to_dense() * nalgebra::DVector::from_column_slice(&x);
        for i in 0..9 {
            assert!((y[i] - yd[i]).abs() < 1e-13);
        }
        let c = SymBanded::linear_combination(0.3, &a, -2.0, &b).unwrap();
        assert_eq!(c.bandwidth(), 3);
        let cd = a.to_dense() * 0.3 - b.to_dense() * 2.0;
        assert!((c.to_dense() - cd).amax() < 1e-14);
        assert!(SymBanded::linear_combination(1.0, &a, 1.0, &spd(8, 3)).is_err());
        let q = a.quadratic_form(&x);
        let xd = nalgebra::DVector::from_column_slice(&x);
        assert!((q - (xd.transpose() * a.to_dense() * &xd)[(0, 0)]).abs() < 1e-12);
    }

    #[test]
    fn cholesky_matches_dense() {
        for &(n, bw) in &[(1, 0), (1, 3), (7, 0), (12, 3), (30, 5)] {
            let a = spd(n, bw);
            let ch = a.cholesky().unwrap();
            assert_eq!(ch.n(), n);
            let ld = ch.to_dense_lower();
            assert!((&ld * ld.transpose() - a.to_dense()).amax() < 1e-12);
            let dense = nalgebra::Cholesky::new(a.to_dense()).unwrap();
            assert!((dense.l() - &ld).amax() < 1e-12);
            let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).cos()).collect();
            let mut x = b.clone();
            ch.solve_in_place(&mut x);
            let xd = dense.solve(&nalgebra::DVector::from_column_slice(&b));
            for i in 0..n {
                assert!((x[i] - xd[i]).abs() < 1e-12);
            }
            let z: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).sin()).collect();
            let mut out = vec![0.0; n];
            ch.mul_lower(&z, &mut out);
            let od = &ld * nalgebra::DVector::from_column_slice(&z);
            let mut zz = z.clone();
            ch.mul_lower_in_place(&mut zz);
            for i in 0..n {
                assert!((out[i] - od[i]).abs() < 1e-13);
                assert_eq!(out[i], zz[i]);
            }
        }
    }

    /// The in-place variants give bit-identical results to the allocating ones, reusing
    /// storage across shapes and after a failed factorization.
    #[test]
    fn in_place_variants_match_allocating_ones() {
        let mut c = SymBanded::new(1, 0);
        let mut l = spd(1, 0).cholesky().unwrap();
        let mut bad = spd(6, 2);
        bad.add(3, 3, -100.0).unwrap();
        assert!(l.factor_from(&bad).is_err());
        assert!(!l.try_factor_from(&bad));
        for &(n, bw_a, bw_b) in &[(9, 3, 1), (9, 1, 3), (4, 0, 0), (30, 5, 2)] {
            let (a, b) = (spd(n, bw_a), spd(n, bw_b));
            c.linear_combination_into(1.0, &a, -0.3, &b).unwrap();
            let expected = SymBanded::linear_combination(1.0, &a, -0.3, &b).unwrap();
            assert_eq!(c, expected);
            l.factor_from(&c).unwrap();
            assert_eq!(l, expected.cholesky().unwrap());
            assert!(!l.try_factor_from(&bad));
            assert!(l.try_factor_from(&c));
            assert_eq!(l, expected.cholesky().unwrap());
            assert!(
                c.linear_combination_into(1.0, &a, 1.0, &spd(n + 1, 1))
                    .is_err()
            );
            assert_eq!(c, expected);
        }
    }

    /// A test vector with signed zeros among its entries (a sign of zero that a
    /// padded kernel would flip shows up in the bitwise comparisons).
    fn test_vector(n: usize, phase: f64) -> Vec<f64> {
        (0..n)
            .map(|i| match i % 5 {
                1 => -0.0,
                3 => 0.0,
                _ => (i as f64 * 0.91 + phase).sin(),
            })
            .collect()
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The fixed-bandwidth kernels behind the public products and solves (bandwidths 1 to
    /// 3) perform the operations of the generic loops in the same order: bit-identical
    /// results, at every size including those smaller than the band, for the generic
    /// bandwidths too.
    #[test]
    fn fixed_bandwidth_kernels_are_bit_identical_to_generic_loops() {
        for bw in 0..=5 {
            for n in 1..=13 {
                let (a, r) = (spd(n, bw), spd(n, bw).cholesky().unwrap());
                let mut other = spd(n, bw);
                for i in 0..n {
                    other.add(i, i, -(bw as f64) - 0.5).unwrap();
                }
                let l = a.cholesky().unwrap();
                let x = test_vector(n, 0.3);
                let g = test_vector(n, 1.7);

                let (mut y, mut y_ref) = (vec![0.0; n], vec![0.0; n]);
                other.mul_vec(&x, &mut y);
                other.mul_vec_generic(&x, &mut y_ref);
                assert_eq!(bits(&y), bits(&y_ref), "mul_vec n={n} bw={bw}");

                let (mut s, mut s_ref) = (g.clone(), g.clone());
                l.solve_in_place(&mut s);
                l.forward_generic(&mut s_ref);
                l.backward_generic(&mut s_ref);
                assert_eq!(bits(&s), bits(&s_ref), "solve n={n} bw={bw}");

                let (mut u, mut u_ref) = (g.clone(), g.clone());
                l.solve_upper_in_place(&mut u);
                l.backward_generic(&mut u_ref);
                assert_eq!(bits(&u), bits(&u_ref), "solve_upper n={n} bw={bw}");
                let mut u_into = vec![0.0; n];
                l.solve_upper_into(&g, &mut u_into);
                assert_eq!(
                    bits(&u_into),
                    bits(&u_ref),
                    "solve_upper_into n={n} bw={bw}"
                );

                // fused product + extra + forward sweep, then the backward sweep
                let mut calls = Vec::new();
                let mut f = vec![0.0; n];
                l.solve_lower_product(
                    &other,
                    &x,
                    |i| {
                        calls.push(i);
                        0.25 * g[i]
                    },
                    &mut f,
                );
                assert_eq!(calls, (0..n).collect::<Vec<_>>());
                let mut out = vec![0.0; n];
                l.solve_upper_into(&f, &mut out);
                let mut b_ref = vec![0.0; n];
                other.mul_vec_generic(&x, &mut b_ref);
                for (b, gi) in b_ref.iter_mut().zip(&g) {
                    *b += 0.25 * gi;
                }
                l.forward_generic(&mut b_ref);
                assert_eq!(bits(&f), bits(&b_ref), "forward product n={n} bw={bw}");
                l.backward_generic(&mut b_ref);
                assert_eq!(bits(&out), bits(&b_ref), "product solve n={n} bw={bw}");

                // L z: the row-wise form against the plain loop
                let w = bw + 1;
                let lz_ref: Vec<f64> = (0..n)
                    .map(|i| {
                        let mut acc = 0.0;
                        for k in i.saturating_sub(bw)..=i {
                            acc += r.data[i * w + (i - k)] * x[k];
                        }
                        acc
                    })
                    .collect();
                let mut lz = vec![0.0; n];
                r.mul_lower(&x, &mut lz);
                assert_eq!(bits(&lz), bits(&lz_ref), "mul_lower n={n} bw={bw}");
                let mut lz_in_place = x.clone();
                r.mul_lower_in_place(&mut lz_in_place);
                assert_eq!(bits(&lz_in_place), bits(&lz_ref), "mul_lower_in_place");
            }
        }
    }

    /// A product solve with matrices of different bandwidths takes the generic path.
    #[test]
    fn product_solve_with_mixed_bandwidths() {
        let (a, l) = (spd(11, 1), spd(11, 3).cholesky().unwrap());
        let x = test_vector(11, 0.1);
        let mut f = vec![0.0; 11];
        l.solve_lower_product(&a, &x, |i| i as f64, &mut f);
        let mut b = vec![0.0; 11];
        a.mul_vec(&x, &mut b);
        for (i, bi) in b.iter_mut().enumerate() {
            *bi += i as f64;
        }
        l.solve_in_place(&mut b);
        let mut out = vec![0.0; 11];
        l.solve_upper_into(&f, &mut out);
        assert_eq!(bits(&out), bits(&b));
    }

    #[test]
    fn cholesky_rejects_indefinite_naming_pivot() {
        let mut a = spd(6, 2);
        a.add(3, 3, -100.0).unwrap();
        let err = a.cholesky().unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, Error::Numerical { .. }));
        assert!(msg.contains("pivot 3"), "{msg}");
    }

    #[test]
    fn inertia_counts_negative_eigenvalues() {
        let a = spd(20, 3);
        let ev = nalgebra::SymmetricEigen::new(a.to_dense()).eigenvalues;
        let mut sorted: Vec<f64> = ev.iter().copied().collect();
        sorted.sort_by(f64::total_cmp);
        for k in 0..=20 {
            // shift between consecutive eigenvalues
            let sigma = match k {
                0 => sorted[0] - 1.0,
                20 => sorted[19] + 1.0,
                _ => 0.5 * (sorted[k - 1] + sorted[k]),
            };
            let mut shift = a.clone();
            for i in 0..20 {
                shift.add(i, i, -sigma).unwrap();
            }
            assert_eq!(shift.negative_eigenvalue_count().unwrap(), k);
        }
    }
}
