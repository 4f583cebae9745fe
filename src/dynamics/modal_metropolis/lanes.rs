//! The inverses of several general blocks of one size at once: the Cholesky inverse of
//! [`super::spd_inverse_k`] with the blocks in lanes, so that their serial chains
//! (square roots, divisions) interleave. Per lane the floating-point operations, in the
//! same order, of the one-block code: the same bits.

/// Blocks inverted together.
pub(super) const BLOCK_LANES: usize = 4;

/// One entry of [`BLOCK_LANES`] blocks.
type V = [f64; BLOCK_LANES];

/// `Σ_p x_p y_p` per lane over the pairs `terms`, from −0.0 as `Iterator::sum` forms it.
#[inline(always)]
fn lane_sum(terms: impl Iterator<Item = (V, V)>) -> V {
    let mut s = [-0.0; BLOCK_LANES];
    for (x, y) in terms {
        for q in 0..BLOCK_LANES {
            s[q] += x[q] * y[q];
        }
    }
    s
}

/// [`super::spd_inverse_k`] of the `K × K` matrices `a[q]` (row-major, stride 4) of the
/// lanes `q`: their inverses and determinants, the determinant NaN for a matrix that is
/// not positive definite (its inverse then meaningless, where the one-block code gives
/// none).
#[inline(always)]
pub(super) fn spd_inverse_lanes<const K: usize>(
    a: &[[f64; 16]; BLOCK_LANES],
) -> ([[f64; 16]; BLOCK_LANES], V) {
    let at = |i: usize| -> V { std::array::from_fn(|q| a[q][i]) };
    // the Cholesky factor, as `cholesky_k`
    let mut l = [[0.0; BLOCK_LANES]; 16];
    let mut det = [1.0; BLOCK_LANES];
    let mut ok = [true; BLOCK_LANES];
    for j in 0..K {
        let s = lane_sum((0..j).map(|p| (l[4 * j + p], l[4 * j + p])));
        let ajj = at(5 * j);
        let mut ljj = [0.0; BLOCK_LANES];
        for q in 0..BLOCK_LANES {
            let d = ajj[q] - s[q];
            ok[q] &= !(d.is_nan() || d <= 0.0);
            ljj[q] = d.sqrt();
            det[q] *= d;
        }
        l[5 * j] = ljj;
        for i in j + 1..K {
            let s = lane_sum((0..j).map(|p| (l[4 * i + p], l[4 * j + p])));
            let aij = at(4 * i + j);
            l[4 * i + j] = std::array::from_fn(|q| (aij[q] - s[q]) / ljj[q]);
        }
    }
    // columns of L⁻¹ by forward substitution, then A⁻¹ = L⁻ᵀ L⁻¹
    let mut li = [[0.0; BLOCK_LANES]; 16];
    for c in 0..K {
        for i in c..K {
            let rhs = if i == c { 1.0 } else { 0.0 };
            let s = lane_sum((c..i).map(|p| (l[4 * i + p], li[4 * p + c])));
            li[4 * i + c] = std::array::from_fn(|q| (rhs - s[q]) / l[5 * i][q]);
        }
    }
    let mut inv = [[0.0; 16]; BLOCK_LANES];
    for r in 0..K {
        for c in 0..K {
            let s = lane_sum((r.max(c)..K).map(|p| (li[4 * p + r], li[4 * p + c])));
            for q in 0..BLOCK_LANES {
                inv[q][4 * r + c] = s[q];
            }
        }
    }
    for q in 0..BLOCK_LANES {
        if !ok[q] {
            det[q] = f64::NAN;
        }
    }
    (inv, det)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane equals the one-block inverse bit for bit (and a block that is not
    /// positive definite gets a NaN determinant), for every block size.
    #[test]
    fn lanes_equal_one_block_bit_for_bit() {
        fn check<const K: usize>() {
            let mut a = [[0.0; 16]; BLOCK_LANES];
            for (q, m) in a.iter_mut().enumerate() {
                for r in 0..K {
                    for c in 0..K {
                        let v = ((r * 7 + c * 7 + q * 3 + K) as f64 * 0.37).sin();
                        m[4 * r + c] = 0.3 * v;
                    }
                    m[5 * r] += 2.0 + q as f64 * 0.1;
                }
            }
            a[2][5 * (K - 1)] = -1.0; // not positive definite
            let (inv, det) = spd_inverse_lanes::<K>(&a);
            for q in 0..BLOCK_LANES {
                match super::super::spd_inverse_k::<K>(&a[q]) {
                    Some((one, d)) => {
                        assert_eq!(det[q].to_bits(), d.to_bits(), "K {K} lane {q}");
                        let bits = |m: &[f64; 16]| m.map(f64::to_bits);
                        assert_eq!(bits(&inv[q]), bits(&one), "K {K} lane {q}");
                    }
                    None => assert!(det[q].is_nan() && q == 2, "K {K} lane {q}"),
                }
            }
        }
        check::<1>();
        check::<2>();
        check::<3>();
        check::<4>();
    }
}
