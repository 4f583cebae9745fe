//! The paired modal form of a uniform hinged beam: `K`, `C` and `G` block-diagonal with
//! blocks of at most 2×2, one block per wavenumber.
//!
//! On a uniform mesh of N Hermite-cubic elements with hinged ends (`w_0 = w_N = 0`), every
//! assembled matrix `M ∈ {K, C, G}` has the same stencil at every node: the w–w and θ–θ
//! couplings are even in the node offset, the w–θ couplings odd. Hence the vectors
//!
//! ```text
//! s_k: w_j = sin(kπj/N) (j = 1…N−1), θ = 0;     c_k: θ_j = cos(kπj/N) (j = 0…N), w = 0
//! ```
//!
//! satisfy `M s_k, M c_k ∈ D·span(s_k, c_k)` (D halves the end rotations, which belong to
//! one element only), and by the discrete orthogonality of sines and cosines the
//! congruence with `V = [s_1, c_1, …, s_{N−1}, c_{N−1}, c_0, c_N]` makes `K`, `C` and `G`
//! all block-diagonal: 2×2 blocks for k = 1…N−1, 1×1 blocks for k = 0 (uniform rotation)
//! and k = N (alternating rotation). Solving the 2×2 generalized eigenproblem
//! `K_b φ = λ C_b φ` per block gives the generalized modes of `(K, C)` (`ΦᵀCΦ = I`,
//! `ΦᵀKΦ = Λ`), in which `B = ΦᵀGΦ` is block-diagonal with the same blocks.
//!
//! The von Kármán filament ([`crate::fem::vonkarman`]) then has the energy
//! `U = ½ Σ λ_i a_i² + (EA·L/2)(s − ε)²`, `s = aᵀB a/(2L)`, whose Hessian without the
//! rank-one term, `Λ − F B`, is block-diagonal: the Metropolis-adjusted Crank–Nicolson
//! proposal ([`crate::dynamics::modal_metropolis`]) costs O(n) per step with 2×2 solves.
//!
//! Built in O(n²) from banded products (no dense eigensolver) and verified on
//! construction: every mode satisfies `Kφ = λCφ` and `Gφ_i = Σ_j B_ji Cφ_j` (j in the
//! block) to round-off, or the form is refused (`None`: the mesh is not uniform).

use super::beam::BeamModel;
use std::f64::consts::PI;

/// The modes of one wavenumber k: two (k = 1…N−1) or one (k = 0, N), rates ascending.
///
/// A mode's nodal vector is `φ_i = α_i s_k + β_i c_k`; its deflection at node j is
/// `α_i sin(kπj/N)`, its rotation `β_i cos(kπj/N)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeBlock {
    /// Wavenumber k (0…N).
    pub wavenumber: usize,
    /// Rates `λ` of the block's modes (`rates[1]` unused for a 1×1 block).
    pub rates: [f64; 2],
    /// The block of `B = ΦᵀGΦ`: `[b00, b01, b11]` (only `b00` for a 1×1 block).
    pub geometric: [f64; 3],
    /// Deflection coefficients `α_i`.
    pub deflection: [f64; 2],
    /// Rotation coefficients `β_i`.
    pub rotation: [f64; 2],
}

/// The paired modal form of a uniform hinged beam (see the module docs).
///
/// Modal coordinates are ordered block by block: the 2×2 blocks k = 1…N−1 first
/// (coordinates `2(k−1)`, `2(k−1)+1`), then the 1×1 blocks k = 0 and k = N (coordinates
/// `2(N−1)` and `2N−1`).
#[derive(Debug, Clone, PartialEq)]
pub struct PairedModes {
    elements: usize,
    pairs: Vec<ModeBlock>,
    singles: Vec<ModeBlock>,
}

/// Backward error (relative to the matrix norms) below which a mode of the paired form is
/// accepted.
const RESIDUAL_TOLERANCE: f64 = 1e-10;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Adds the nodal vector of `deflection·s_k + rotation·c_k` to `out` (free DOFs of `beam`,
/// `ne` elements): `deflection·sin(kπj/N)` to the deflection and `rotation·cos(kπj/N)` to
/// the rotation of every node j that has them.
fn add_wave(
    beam: &BeamModel,
    ne: usize,
    k: usize,
    deflection: f64,
    rotation: f64,
    out: &mut [f64],
) {
    for j in 0..=ne {
        let arg = PI * (k * j) as f64 / ne as f64;
        if let Some(idx) = beam.node_deflection_index(j) {
            out[idx] += deflection * arg.sin();
        }
        if let Some(idx) = beam.node_rotation_index(j) {
            out[idx] += rotation * arg.cos();
        }
    }
}

/// `residual ≤ RESIDUAL_TOLERANCE · scale` (false for NaN).
fn within(residual: f64, scale: f64) -> bool {
    residual <= RESIDUAL_TOLERANCE * scale
}

/// `x > 0` (false for NaN).
fn is_positive(x: f64) -> bool {
    x > 0.0
}

/// The 2×2 generalized eigenproblem `K φ = λ C φ` (both symmetric, `[m00, m01, m11]`, C
/// positive definite): rates ascending and the columns `φ` with `φᵀCφ = 1`.
fn generalized_2x2(k: [f64; 3], c: [f64; 3]) -> Option<([f64; 2], [[f64; 2]; 2])> {
    // C = L Lᵀ, M = L⁻¹ K L⁻ᵀ, M y = λ y, φ = L⁻ᵀ y.
    let l00 = c[0].sqrt();
    let l10 = c[1] / l00;
    let l11 = (c[2] - l10 * l10).sqrt();
    if !(l00 > 0.0 && l11 > 0.0) {
        return None;
    }
    // L⁻¹ = [[1/l00, 0], [−l10/(l00 l11), 1/l11]].
    let (i00, i10, i11) = (1.0 / l00, -l10 / (l00 * l11), 1.0 / l11);
    let m00 = i00 * i00 * k[0];
    let m01 = i00 * (i10 * k[0] + i11 * k[1]);
    let m11 = i10 * i10 * k[0] + 2.0 * i10 * i11 * k[1] + i11 * i11 * k[2];
    let mean = 0.5 * (m00 + m11);
    let radius = (0.25 * (m00 - m11).powi(2) + m01 * m01).sqrt();
    let rates = [mean - radius, mean + radius];
    let mut phi = [[0.0; 2]; 2];
    for (col, &lam) in rates.iter().enumerate() {
        // (M − λ I) y = 0: y ∝ (m01, λ − m00) or (λ − m11, m01), whichever is larger.
        let (a, b) = (m01, lam - m00);
        let (c2, d) = (lam - m11, m01);
        let (y0, y1) = if a * a + b * b >= c2 * c2 + d * d {
            (a, b)
        } else {
            (c2, d)
        };
        let (y0, y1) = if y0 == 0.0 && y1 == 0.0 {
            if col == 0 { (1.0, 0.0) } else { (0.0, 1.0) }
        } else {
            let r = (y0 * y0 + y1 * y1).sqrt();
            (y0 / r, y1 / r)
        };
        // φ = L⁻ᵀ y: L⁻ᵀ = [[i00, i10], [0, i11]].
        phi[col] = [i00 * y0 + i10 * y1, i11 * y1];
    }
    Some((rates, phi))
}

impl PairedModes {
    /// The paired modal form of `beam`, or `None` if its mesh is not uniform (checked on
    /// the residuals of every mode, see the module docs).
    pub fn new(beam: &BeamModel) -> Option<Self> {
        let mesh = beam.mesh();
        let ne = mesh.n_elements();
        let h = mesh.length() / ne as f64;
        if (0..ne).any(|e| (mesh.element_length(e) - h).abs() > 1e-12 * h) {
            return None;
        }
        let n = beam.n_dofs();
        let (km, cm, gm) = (beam.stiffness(), beam.damping(), beam.geometric());
        let mut buf = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        // s_k (sine deflections) or c_k (cosine rotations).
        let basis = |k: usize, sine: bool| -> Vec<f64> {
            let mut v = vec![0.0; n];
            let (d, r) = if sine { (1.0, 0.0) } else { (0.0, 1.0) };
            add_wave(beam, ne, k, d, r, &mut v);
            v
        };
        let mut pairs = Vec::with_capacity(ne.saturating_sub(1));
        for k in 1..ne {
            let (s, c) = (basis(k, true), basis(k, false));
            let block = |m: &super::SymBanded, out: &mut [Vec<f64>; 3]| -> [f64; 3] {
                m.mul_vec(&s, &mut out[0]);
                m.mul_vec(&c, &mut out[1]);
                [
                    dot(&s, &out[0]),
                    0.5 * (dot(&s, &out[1]) + dot(&c, &out[0])),
                    dot(&c, &out[1]),
                ]
            };
            let kb = block(km, &mut buf);
            let cb = block(cm, &mut buf);
            let gb = block(gm, &mut buf);
            let (rates, phi) = generalized_2x2(kb, cb)?;
            // B_b = Φ_bᵀ G_b Φ_b.
            let quad = |x: [f64; 2], y: [f64; 2]| {
                x[0] * (gb[0] * y[0] + gb[1] * y[1]) + x[1] * (gb[1] * y[0] + gb[2] * y[1])
            };
            pairs.push(ModeBlock {
                wavenumber: k,
                rates,
                geometric: [
                    quad(phi[0], phi[0]),
                    quad(phi[0], phi[1]),
                    quad(phi[1], phi[1]),
                ],
                deflection: [phi[0][0], phi[1][0]],
                rotation: [phi[0][1], phi[1][1]],
            });
        }
        let mut singles = Vec::with_capacity(2);
        for k in [0, ne] {
            let c = basis(k, false);
            km.mul_vec(&c, &mut buf[0]);
            cm.mul_vec(&c, &mut buf[1]);
            gm.mul_vec(&c, &mut buf[2]);
            let cc = dot(&c, &buf[1]);
            if !is_positive(cc) {
                return None;
            }
            let beta = 1.0 / cc.sqrt();
            singles.push(ModeBlock {
                wavenumber: k,
                rates: [dot(&c, &buf[0]) / cc, 0.0],
                geometric: [beta * beta * dot(&c, &buf[2]), 0.0, 0.0],
                deflection: [0.0, 0.0],
                rotation: [beta, 0.0],
            });
        }
        let form = PairedModes {
            elements: ne,
            pairs,
            singles,
        };
        form.verify(beam).then_some(form)
    }

    /// Checks every mode by its backward error: `‖Kφ − λCφ‖ ≤ tol (‖K‖ + |λ|‖C‖) ‖φ‖` and
    /// `‖Gφ_i − Σ_j B_ji Cφ_j‖ ≤ tol (‖G‖‖φ_i‖ + Σ_j |B_ji| ‖C‖‖φ_j‖)` (j in the block,
    /// ∞-norms of the matrices, tol = [`RESIDUAL_TOLERANCE`]): the form is then exact for
    /// matrices within a relative `tol` of the assembled ones. (Relative to `‖Kφ‖` the
    /// residual of a smooth mode is amplified by cancellation: at 1000 elements the
    /// rounding of the node coordinates alone, 1e-13 of h, leaves 7e-4.)
    fn verify(&self, beam: &BeamModel) -> bool {
        let n = beam.n_dofs();
        if self.n_modes() != n {
            return false;
        }
        let (km, cm, gm) = (beam.stiffness(), beam.damping(), beam.geometric());
        let (kn, cn, gn) = (km.inf_norm(), cm.inf_norm(), gm.inf_norm());
        let (mut kphi, mut cphi, mut gphi) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut cphi_other = vec![0.0; n];
        let blocks = self
            .pairs
            .iter()
            .map(|b| (b, 2))
            .chain(self.singles.iter().map(|b| (b, 1)));
        for (b, len) in blocks {
            for i in 0..len {
                let phi = self.mode_vector(beam, b, i);
                km.mul_vec(&phi, &mut kphi);
                cm.mul_vec(&phi, &mut cphi);
                gm.mul_vec(&phi, &mut gphi);
                let lam = b.rates[i];
                let r: Vec<f64> = kphi.iter().zip(&cphi).map(|(k, c)| k - lam * c).collect();
                let phi_norm = norm(&phi);
                if !within(norm(&r), (kn + lam.abs() * cn) * phi_norm) {
                    return false;
                }
                // G φ_i = C Φ B_{:,i}: within the block only.
                let (bii, bij) = if i == 0 {
                    (b.geometric[0], b.geometric[1])
                } else {
                    (b.geometric[2], b.geometric[1])
                };
                let mut r: Vec<f64> = gphi.iter().zip(&cphi).map(|(g, c)| g - bii * c).collect();
                let mut scale = (gn + bii.abs() * cn) * phi_norm;
                if len == 2 {
                    let other = self.mode_vector(beam, b, 1 - i);
                    cm.mul_vec(&other, &mut cphi_other);
                    for (ri, c) in r.iter_mut().zip(&cphi_other) {
                        *ri -= bij * c;
                    }
                    scale += bij.abs() * cn * norm(&other);
                }
                if !within(norm(&r), scale) {
                    return false;
                }
            }
        }
        true
    }

    /// The nodal vector (over the free DOFs of `beam`) of mode `i` of block `b`.
    fn mode_vector(&self, beam: &BeamModel, b: &ModeBlock, i: usize) -> Vec<f64> {
        let mut v = vec![0.0; beam.n_dofs()];
        add_wave(
            beam,
            self.elements,
            b.wavenumber,
            b.deflection[i],
            b.rotation[i],
            &mut v,
        );
        v
    }

    /// Number of elements N.
    pub fn elements(&self) -> usize {
        self.elements
    }

    /// Number of modes (= free DOFs, 2N).
    pub fn n_modes(&self) -> usize {
        2 * self.pairs.len() + self.singles.len()
    }

    /// The 2×2 blocks, k = 1…N−1 (modal coordinates `2(k−1)`, `2(k−1)+1`).
    pub fn pairs(&self) -> &[ModeBlock] {
        &self.pairs
    }

    /// The 1×1 blocks, k = 0 and k = N (modal coordinates `2(N−1)` and `2N−1`).
    pub fn singles(&self) -> &[ModeBlock] {
        &self.singles
    }

    /// The rates `λ` in modal-coordinate order.
    pub fn rates(&self) -> Vec<f64> {
        self.pairs
            .iter()
            .flat_map(|b| b.rates)
            .chain(self.singles.iter().map(|b| b.rates[0]))
            .collect()
    }

    /// The nodal state (free DOFs of the beam the form was built from) of the modal
    /// coordinates `a`: `w = Φ a`, O(n²).
    ///
    /// # Panics
    /// If `a` or `out` does not have [`Self::n_modes`] entries.
    pub fn to_nodal(&self, beam: &BeamModel, a: &[f64], out: &mut [f64]) {
        assert_eq!(
            a.len(),
            self.n_modes(),
            "to_nodal: wrong number of modal coordinates"
        );
        assert_eq!(out.len(), self.n_modes(), "to_nodal: wrong number of DOFs");
        out.fill(0.0);
        let ne = self.elements;
        let p = self.pairs.len();
        let coords = self
            .pairs
            .iter()
            .enumerate()
            .map(|(q, b)| (b, [a[2 * q], a[2 * q + 1]]))
            .chain(
                self.singles
                    .iter()
                    .enumerate()
                    .map(|(q, b)| (b, [a[2 * p + q], 0.0])),
            );
        for (b, x) in coords {
            let wk = b.deflection[0] * x[0] + b.deflection[1] * x[1];
            let tk = b.rotation[0] * x[0] + b.rotation[1] * x[1];
            add_wave(beam, ne, b.wavenumber, wk, tk, out);
        }
    }

    /// `Σ_k cos²(kπj/N) u_k` for every node j (the mean squared nodal rotation from the
    /// per-wavenumber mean squares `u_k` of `β_0 a_0 + β_1 a_1`, block order as the
    /// coordinates), added to `acc` (one entry per node). O(n²).
    pub fn add_rotation_squares(&self, block_squares: &[f64], acc: &mut [f64]) {
        let ne = self.elements;
        for (b, &u) in self.pairs.iter().chain(&self.singles).zip(block_squares) {
            for (j, a) in acc.iter_mut().enumerate().take(ne + 1) {
                let c = (PI * (b.wavenumber * j) as f64 / ne as f64).cos();
                *a += c * c * u;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::fem::mesh::Mesh;
    use crate::fem::modal::generalized_modes;

    fn beam(ne: usize) -> BeamModel {
        let p = FilamentParams {
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            ..FilamentParams::default()
        };
        BeamModel::new(p, Mesh::uniform(1.0, ne).unwrap()).unwrap()
    }

    /// Against the dense generalized eigen-decomposition: the same rates, and the dense
    /// `ΦᵀCΦ = I`, `ΦᵀKΦ = Λ`, `ΦᵀGΦ` block-diagonal with the stored blocks.
    #[test]
    fn paired_form_diagonalizes_k_c_and_blocks_g() {
        for ne in [1, 2, 3, 10, 17] {
            let b = beam(ne);
            let form = PairedModes::new(&b).expect("uniform mesh");
            let n = b.n_dofs();
            let mut rates = form.rates();
            let dense = generalized_modes(&b).unwrap();
            rates.sort_by(f64::total_cmp);
            for (a, d) in rates.iter().zip(dense.rates.iter()) {
                assert!((a - d).abs() < 1e-10 * d, "ne {ne}: rate {a} vs dense {d}");
            }
            // Φ column by column from to_nodal of unit coordinates.
            let mut phi = nalgebra::DMatrix::zeros(n, n);
            let mut col = vec![0.0; n];
            for i in 0..n {
                let mut e = vec![0.0; n];
                e[i] = 1.0;
                form.to_nodal(&b, &e, &mut col);
                phi.set_column(i, &nalgebra::DVector::from_column_slice(&col));
            }
            let (k, c, g) = (
                b.stiffness().to_dense(),
                b.damping().to_dense(),
                b.geometric().to_dense(),
            );
            let ck = phi.transpose() * &c * &phi;
            let kk = phi.transpose() * &k * &phi;
            let gg = phi.transpose() * &g * &phi;
            let lam = form.rates();
            let gscale = gg.amax();
            for i in 0..n {
                for j in 0..n {
                    let eye = if i == j { 1.0 } else { 0.0 };
                    assert!((ck[(i, j)] - eye).abs() < 1e-10, "ne {ne}: C[{i},{j}]");
                    assert!(
                        (kk[(i, j)] - eye * lam[i]).abs() < 1e-10 * lam[n - 1].max(lam[i]),
                        "ne {ne}: K[{i},{j}] = {}",
                        kk[(i, j)]
                    );
                    let same_block = i / 2 == j / 2 && i < 2 * (ne - 1) && j < 2 * (ne - 1);
                    let expect = if i == j || same_block {
                        let q = i / 2;
                        if i >= 2 * (ne - 1) {
                            form.singles()[i - 2 * (ne - 1)].geometric[0]
                        } else {
                            form.pairs()[q].geometric[(i % 2) + (j % 2)]
                        }
                    } else {
                        0.0
                    };
                    assert!(
                        (gg[(i, j)] - expect).abs() < 1e-10 * gscale,
                        "ne {ne}: G[{i},{j}] = {} vs {expect}",
                        gg[(i, j)]
                    );
                }
            }
        }
    }

    /// Large uniform meshes (node coordinates rounded in floating point) are accepted.
    #[test]
    fn large_uniform_meshes_are_accepted() {
        for ne in [100, 1000] {
            assert!(PairedModes::new(&beam(ne)).is_some(), "{ne} elements");
        }
    }

    #[test]
    fn graded_mesh_is_refused() {
        let p = FilamentParams::default();
        let b = BeamModel::new(p, Mesh::graded(1.0, 8, 2.0).unwrap()).unwrap();
        assert!(PairedModes::new(&b).is_none());
    }

    /// The mean squared rotations from block squares equal the squared nodal rotations
    /// of `to_nodal` for a state with one nonzero block (no cross-block terms).
    #[test]
    fn rotation_squares_match_nodal_rotations() {
        let b = beam(6);
        let form = PairedModes::new(&b).unwrap();
        let n = b.n_dofs();
        let nblocks = form.pairs().len() + form.singles().len();
        for blk in 0..nblocks {
            let mut a = vec![0.0; n];
            let (i0, i1) = if blk < form.pairs().len() {
                (2 * blk, Some(2 * blk + 1))
            } else {
                (2 * form.pairs().len() + blk - form.pairs().len(), None)
            };
            a[i0] = 0.3;
            if let Some(i1) = i1 {
                a[i1] = -0.7;
            }
            let mut w = vec![0.0; n];
            form.to_nodal(&b, &a, &mut w);
            let bl = form.pairs().iter().chain(form.singles()).nth(blk).unwrap();
            let u = bl.rotation[0] * a[i0] + i1.map_or(0.0, |i| bl.rotation[1] * a[i]);
            let mut squares = vec![0.0; nblocks];
            squares[blk] = u * u;
            let mut acc = vec![0.0; 7];
            form.add_rotation_squares(&squares, &mut acc);
            for (j, s) in acc.iter().enumerate() {
                let t = w[b.node_rotation_index(j).unwrap()];
                assert!(
                    (s - t * t).abs() < 1e-12,
                    "block {blk} node {j}: {s} vs {}",
                    t * t
                );
            }
        }
    }
}
