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
    /// # Panics
    /// If `b.len() != n`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve_in_place: wrong length");
        let w = self.bw + 1;
        let n = self.n;
        for i in 0..n {
            let row = &self.data[i * w..i * w + w];
            let lo = i.saturating_sub(self.bw);
            let mut s = b[i];
            for (k, bk) in b[lo..i].iter().enumerate() {
                s -= row[i - lo - k] * bk;
            }
            b[i] = s * self.inv_diag[i];
        }
        self.solve_upper_in_place(b);
    }

    /// Solves `Lᵀ x = b` in place (the backward half of [`Self::solve_in_place`]),
    /// `O(n·bw)`. With `b` iid standard normal, `x ~ N(0, A⁻¹)`.
    ///
    /// # Panics
    /// If `b.len() != n`.
    pub fn solve_upper_in_place(&self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve_upper_in_place: wrong length");
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

    /// `out = L z`. With `z` iid standard normal, `out ~ N(0, A)`.
    ///
    /// # Panics
    /// If `z.len()` or `out.len()` differs from `n`.
    pub fn mul_lower(&self, z: &[f64], out: &mut [f64]) {
        assert_eq!(z.len(), self.n, "mul_lower: z has wrong length");
        assert_eq!(out.len(), self.n, "mul_lower: out has wrong length");
        let w = self.bw + 1;
        for i in 0..self.n {
            let mut s = 0.0;
            for k in i.saturating_sub(self.bw)..=i {
                s += self.data[i * w + (i - k)] * z[k];
            }
            out[i] = s;
        }
    }

    /// `z ← L z` in place (rows computed from the last to the first, so each uses only
    /// still-unmodified entries).
    ///
    /// # Panics
    /// If `z.len() != n`.
    pub fn mul_lower_in_place(&self, z: &mut [f64]) {
        assert_eq!(z.len(), self.n, "mul_lower_in_place: wrong length");
        let w = self.bw + 1;
        for i in (0..self.n).rev() {
            let mut s = 0.0;
            for k in i.saturating_sub(self.bw)..=i {
                s += self.data[i * w + (i - k)] * z[k];
            }
            z[i] = s;
        }
    }

    /// The dense lower-triangular factor `L`.
    pub fn to_dense_lower(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
