//! The separable modes of the uniform plate ([`super::PlateModel`]): `K` and `C`
//! block-diagonal with blocks of at most 4×4, one per pair of 1D waves.
//!
//! **1D waves.** On a uniform chain of N Hermite-cubic elements every assembled 1D matrix
//! `A ∈ {M, K2, K4}` has the same stencil at every node, with even w–w and θ–θ couplings
//! and odd w–θ couplings (see [`super::paired`]). Hence the waves (node `j`, `ϕ = πkj/N`
//! hinged, `2πkj/N` periodic)
//!
//! ```text
//! hinged, k = 0…N:              w_j = sin ϕ,  θ_j = cos ϕ           ("sine" waves)
//! periodic, k = 0…⌊N/2⌋, cosine: w_j = cos ϕ,  θ_j = −sin ϕ
//!                        sine:   w_j = sin ϕ,  θ_j = cos ϕ
//! ```
//!
//! each span (their `w` part and their `θ` part, dropping a part that vanishes at every
//! node: the `w` of `k = 0, N` hinged, the `θ` of the periodic cosine and the `w` of the
//! periodic sine at `k = 0` and `2k = N`) a space of dimension 1 or 2 that every `A` maps
//! into `D·span` (D halves the hinged end rotations, D = I periodic), and distinct waves are
//! `D`-orthogonal: in the basis of all waves each 1D matrix is block-diagonal (the hinged
//! waves are [`super::paired`]'s `s_k`, `c_k`). The signs are those of the continuum: `θ`
//! is the derivative's direction (`d cos = −sin`). The two periodic waves of a wavenumber
//! `0 < 2k < N` have equal blocks (`Re` and `Im` of one Bloch wave); the cosine's serve
//! both, so that their modes tie exactly.
//!
//! **2D blocks.** The plate's matrices are sums of tensor products of the 1D ones
//! ([`super::plate`]), so for waves `X` (size `s_x`) and `Y` (`s_y`) the products
//! `v_a ⊗ u_b` span an invariant space and `K`, `C` are block-diagonal with the blocks
//!
//! ```text
//! K_b = κ(K4_X⊗M_Y + 2K2_X⊗K2_Y + M_X⊗K4_Y) + σ(K2_X⊗M_Y + M_X⊗K2_Y),   C_b = ξ M_X⊗M_Y
//! ```
//!
//! of size `s_x·s_y ≤ 4` (`A_X = V_Xᵀ A V_X`). Each small pencil `K_b y = λ C_b y` is
//! solved exactly (Cholesky and a symmetric eigensolver of at most 4×4): every generalized
//! mode of the plate, without any large eigensolver. The modes come out separable by
//! construction, so degenerate pairs such as (1, 2) and (2, 1) on a square are the
//! sin·sin products, never a rotation of them.
//!
//! **Labels** ([`PlateModeLabel`]): lattice indices `(m, n)`, a [`ModeShape`] and a branch.
//!
//! - Simply supported: `(m, n) = (kx, ky)`, `0 ≤ m ≤ nx`, `0 ≤ n ≤ ny`,
//!   [`ModeShape::SineSine`], branch = rank in the block (ascending rate). For
//!   `1 ≤ m < nx`, `1 ≤ n < ny` the block holds the height vector `w ⊗ w`, and its branch 0
//!   (the acoustic mode) converges to the continuum mode sin(mπx/a) sin(nπy/b); the other
//!   branches (and every mode of the blocks `m ∈ {0, nx}` or `n ∈ {0, ny}`, pure slope
//!   patterns) are optical, with rates of order `κ/(ξh⁴)`.
//! - Periodic, the continuum's half-lattice convention ([`MembraneMode`]): for
//!   `0 < 2kx < nx` and `0 < 2ky < ny` the four blocks (cos or sin in x) × (cos or sin in
//!   y) have equal matrices, and the modes are combined as the continuum's travelling
//!   waves: with the same block coefficients, `(cc ∓ ss)/√2` is the Cosine of
//!   `(kx, ±ky)` (`cos(q·r) = cos cos − sin sin`) and `(sc ± cs)/√2` the Sine of
//!   `(kx, ±ky)`; branch = rank in the block. When `kx` or `ky` is 0 or `N/2` (Nyquist)
//!   the waves have one part and no combination is formed: the blocks (cos, cos) and
//!   (sin, sin) form the Cosine group of `(kx, ky)`, (cos, sin) and (sin, cos) the Sine
//!   group; branches number the modes of the group's block holding `w ⊗ w` first
//!   (ascending), then the other block's (ascending). Branch 0 of a group with `w ⊗ w`,
//!   `(m, n) ≠ (0, 0)`, `2m < nx`, `2|n| < ny` converges to the continuum mode `(m, n)`
//!   of that shape. The label `(0, 0, Cosine, 0)` is the **zero mode** (uniform
//!   translation, rate exactly 0).
//!
//! **Signs.** A mode with a continuum counterpart has a positive projection
//! `∫ h_φ(r) φ_c(r) d²r` on it (`φ_c` = sin·sin, cos(q·r) or sin(q·r), by 5-point Gauss
//! per element and direction); if that projection is below 10⁻⁸ of its Cauchy–Schwarz bound,
//! and for every other mode, the block coefficient of largest magnitude (the first on exact
//! ties, order `a + s_x·b`) is positive.
//!
//! **Order and accuracy.** Modes are sorted by rate; a run of rates within a relative
//! 10⁻¹⁰ of its first is ordered by label (`m`, then `n`, shape, branch), so degenerate
//! modes come in a fixed order. On a square meshed alike in x and y the block of waves
//! `(Y, X)` reuses the solution of `(X, Y)` (transposed), so (m, n) and (n, m) tie exactly.
//! A rate's round-off is about `ε·λ_max,b/λ` relative (`λ_max,b` the largest rate of its
//! block, as for any eigensolver), e.g. 10⁻¹¹ for the (2, 1) mode at 16 × 16: far below
//! the discretization error.
//!
//! **Verification.** On construction every mode's part `(V_X⊗V_Y) y` (for the periodic
//! combinations, the (cos, cos) coefficients on each of the four blocks) is checked by its
//! backward error `‖Kφ − λCφ‖ ≤ 10⁻¹⁰ (‖K‖∞ + |λ|‖C‖∞) ‖φ‖` (as
//! [`super::PairedModes`]), with `Kφ` applied in tensor form from the assembled 1D
//! matrices the plate's `K` is built from (`O(n)` per mode, `O(n²)` in all); a failure
//! refuses the form. The integration tests compare the rates with the dense generalized
//! eigenvalues of the assembled banded `K` and `C`.

use super::hermite::{GAUSS5, shape};
use super::modal::{GeneralizedModes, symmetric_pencil};
use super::plate::{Axis, AxisMatrices, PlateModel, stiffness_entry};
use crate::error::{Error, Result};
use crate::spectral::membrane::{MembraneMode, MembraneParams, ModeShape};
use crate::spectral::sin_pi;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::collections::BTreeMap;
use std::f64::consts::FRAC_1_SQRT_2;

/// Largest number of DOFs [`PlateModes::new`] accepts (its verification costs `O(n²)`,
/// about a second at the cap).
pub const MAX_PLATE_MODE_DOFS: usize = 16_384;

/// Largest number of DOFs [`PlateModes::generalized_modes`] accepts (a dense `n × n`
/// matrix: 512 MB at the cap).
pub const MAX_DENSE_MODE_DOFS: usize = 8_192;

/// Backward error (relative to the matrix norms) below which a mode is accepted.
const RESIDUAL_TOLERANCE: f64 = 1e-10;

/// Relative gap below which two rates count as tied and are ordered by label.
const TIE_TOLERANCE: f64 = 1e-10;

/// Which of the two periodic waves of a wavenumber (hinged waves are all `Sine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Parity {
    Cosine,
    Sine,
}

/// One 1D wave of an axis and its blocks (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct Wave {
    pub(crate) k: usize,
    pub(crate) parity: Parity,
    /// The 1D DOF kinds of its basis vectors (0: `w` part, 1: `θ` part), 1 or 2 of them.
    pub(crate) kinds: &'static [usize],
    /// `[M, K2, K4]` blocks `V_ᵀ A V` (indices below `kinds.len()` used).
    pub(crate) mats: [[[f64; 2]; 2]; 3],
    /// `∫ v_h · [cos, sin](ϕ(x))` of each basis vector, `ϕ = kπx/L` hinged, `2kπx/L`
    /// periodic.
    proj: [[f64; 2]; 2],
}

impl Wave {
    pub(crate) fn size(&self) -> usize {
        self.kinds.len()
    }

    /// Whether the wave has a `w` part.
    pub(crate) fn has_height(&self) -> bool {
        self.kinds[0] == 0
    }

    /// Whether the wave has both parts (`0 < k < N` hinged, `0 < 2k < N` periodic).
    fn is_interior(&self) -> bool {
        self.kinds.len() == 2
    }
}

/// Phase multiple of π of wave `k` at node `j`: `kj/N` hinged, `2kj/N` periodic, reduced
/// exactly modulo 2.
fn phase(axis: &Axis, k: usize, j: usize) -> f64 {
    let n = axis.elements;
    let f = if axis.periodic { 2 } else { 1 };
    ((f * k * j) % (2 * n)) as f64 / n as f64
}

/// Nodal value of kind `t` (0: `w`, 1: `θ`) of the wave `(k, parity)` at node `j`.
fn nodal_value(axis: &Axis, k: usize, parity: Parity, t: usize, j: usize) -> f64 {
    let s = phase(axis, k, j);
    let (sin, cos) = (sin_pi(s), sin_pi(s + 0.5));
    match (parity, t) {
        (Parity::Cosine, 0) => cos,
        (Parity::Cosine, _) => -sin,
        (Parity::Sine, 0) => sin,
        (Parity::Sine, _) => cos,
    }
}

/// The basis vector of kind `t` of a wave over the axis' free DOFs.
fn basis_vector(axis: &Axis, k: usize, parity: Parity, t: usize) -> Vec<f64> {
    let mut v = vec![0.0; axis.n_free()];
    let nodes = if axis.periodic {
        axis.elements
    } else {
        axis.elements + 1
    };
    for j in 0..nodes {
        if let Some(i) = axis.free(j, t) {
            v[i] = nodal_value(axis, k, parity, t, j);
        }
    }
    v
}

/// `∫₀ᴸ v_h(x) [cos, sin](ϕ(x)) dx` for the kind-`t` part of wave `(k, parity)` (5-point
/// Gauss per element).
fn projections(axis: &Axis, k: usize, parity: Parity, t: usize) -> [f64; 2] {
    let (h, len) = (axis.h(), axis.length);
    let f = if axis.periodic { 2.0 } else { 1.0 };
    let mut out = [0.0; 2];
    for e in 0..axis.elements {
        let (va, vb) = (
            nodal_value(axis, k, parity, t, e),
            nodal_value(axis, k, parity, t, e + 1),
        );
        for &(u, w) in &GAUSS5 {
            let s = 0.5 * h * (u + 1.0);
            let n = shape(h, s);
            let value = n[t] * va + n[2 + t] * vb;
            let arg = f * k as f64 * (e as f64 * h + s) / len;
            out[0] += 0.5 * h * w * value * sin_pi(arg + 0.5);
            out[1] += 0.5 * h * w * value * sin_pi(arg);
        }
    }
    out
}

/// The waves of one axis with their 1D blocks and projections, in the order
/// (k ascending, cosine before sine).
pub(crate) fn axis_waves(axis: &Axis, mats: &AxisMatrices) -> Vec<Wave> {
    let n = axis.elements;
    let mut list: Vec<(usize, Parity, &'static [usize])> = Vec::new();
    if axis.periodic {
        for k in 0..=n / 2 {
            let edge = k == 0 || 2 * k == n;
            list.push((k, Parity::Cosine, if edge { &[0] } else { &[0, 1] }));
            list.push((k, Parity::Sine, if edge { &[1] } else { &[0, 1] }));
        }
    } else {
        for k in 0..=n {
            let edge = k == 0 || k == n;
            list.push((k, Parity::Sine, if edge { &[1] } else { &[0, 1] }));
        }
    }
    let nf = axis.n_free();
    let mut av = vec![0.0; nf];
    let mut waves: Vec<Wave> = list
        .into_iter()
        .map(|(k, parity, kinds)| {
            let vecs: Vec<Vec<f64>> = kinds
                .iter()
                .map(|&t| basis_vector(axis, k, parity, t))
                .collect();
            let mut blocks = [[[0.0; 2]; 2]; 3];
            for (q, a) in [&mats.m, &mats.k2, &mats.k4].into_iter().enumerate() {
                for (i, vi) in vecs.iter().enumerate() {
                    a.mul_vec(vi, &mut av);
                    for (j, vj) in vecs.iter().enumerate() {
                        blocks[q][j][i] = dot(vj, &av);
                    }
                }
                // symmetrize the round-off
                let off = 0.5 * (blocks[q][0][1] + blocks[q][1][0]);
                blocks[q][0][1] = off;
                blocks[q][1][0] = off;
            }
            let mut proj = [[0.0; 2]; 2];
            for (i, &t) in kinds.iter().enumerate() {
                proj[i] = projections(axis, k, parity, t);
            }
            Wave {
                k,
                parity,
                kinds,
                mats: blocks,
                proj,
            }
        })
        .collect();
    // The two periodic waves of an interior wavenumber have equal blocks (module docs):
    // the cosine's serve both, so that their modes tie exactly (the residual check
    // confirms them for the sine).
    if axis.periodic {
        for pair in waves.chunks_exact_mut(2) {
            if pair[0].is_interior() {
                pair[1].mats = pair[0].mats;
            }
        }
    }
    waves
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The label of a plate mode (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PlateModeLabel {
    /// Lattice index along x (`kx ≥ 0`).
    pub m: i64,
    /// Lattice index along y (`ky`; negative only for the periodic travelling
    /// combinations `(kx, −ky)`).
    pub n: i64,
    /// [`ModeShape::SineSine`] simply supported; [`ModeShape::Cosine`] or
    /// [`ModeShape::Sine`] periodic.
    pub shape: ModeShape,
    /// Branch (0 = lowest; see the module docs for the groups it ranks in).
    pub branch: usize,
}

/// One part `weight · (V_X ⊗ V_Y) y` of a mode: indices of the x and y waves.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Part {
    x: usize,
    y: usize,
    weight: f64,
}

/// One generalized mode of the plate: `K φ = λ C φ`, `φᵀCφ = 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlateMode {
    /// Rate `λ` (0 for the periodic zero mode).
    pub rate: f64,
    /// Its label.
    pub label: PlateModeLabel,
    /// The continuum mode it converges to under refinement (the acoustic modes of
    /// resolved wavevectors), else `None`.
    pub continuum: Option<MembraneMode>,
    parts: [Option<Part>; 2],
    /// Block coefficients `y_{a + s_x·b}` (the same for both parts).
    coefficients: [f64; 4],
}

/// A group of plate modes coupled by the area matrix ([`PlateModes::geometric_blocks`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricBlock {
    /// Indices of its modes in [`PlateModes::modes`], ascending.
    pub modes: Vec<usize>,
    /// `B = Φ_gᵀ G Φ_g` over those modes, row-major `k × k` (`k` = number of modes).
    pub matrix: Vec<f64>,
}

/// One solved block: waves, and its `(λ, y)` ascending.
#[derive(Debug, Clone)]
struct Block {
    x: usize,
    y: usize,
    solutions: Vec<(f64, [f64; 4])>,
}

/// The separable modes of a uniform plate (see the module docs), sorted by rate.
#[derive(Debug, Clone)]
pub struct PlateModes {
    params: MembraneParams,
    axes: [Axis; 2],
    waves: [Vec<Wave>; 2],
    modes: Vec<PlateMode>,
}

/// `K_b`, `C_b` of the block of waves `x ⊗ y` (local index `a + s_x·b`).
fn block_matrices(p: &MembraneParams, x: &Wave, y: &Wave) -> (DMatrix<f64>, DMatrix<f64>) {
    let (sx, d) = (x.size(), x.size() * y.size());
    let mut k = DMatrix::zeros(d, d);
    let mut c = DMatrix::zeros(d, d);
    for i in 0..d {
        for j in 0..d {
            let (a, b, a2, b2) = (i % sx, i / sx, j % sx, j / sx);
            let ex = [x.mats[0][a][a2], x.mats[1][a][a2], x.mats[2][a][a2]];
            let ey = [y.mats[0][b][b2], y.mats[1][b][b2], y.mats[2][b][b2]];
            k[(i, j)] = stiffness_entry(p.bending_rigidity, p.tension, ex, ey);
            c[(i, j)] = p.drag * ex[0] * ey[0];
        }
    }
    (k, c)
}

fn numerical(detail: impl Into<String>) -> Error {
    Error::Numerical {
        routine: "PlateModes".into(),
        detail: detail.into(),
    }
}

/// The pencil `K y = λ C y` of size ≤ 4: `(λ, y)` ascending, `yᵀCy = 1`.
fn solve_small(k: DMatrix<f64>, c: DMatrix<f64>) -> Result<Vec<(f64, [f64; 4])>> {
    let d = k.nrows();
    let (l, a) = symmetric_pencil(&k, c, "PlateModes block")?;
    let eig = SymmetricEigen::new(a);
    let phi = l
        .tr_solve_lower_triangular(&eig.eigenvectors)
        .ok_or_else(|| numerical("block solve L^-T Y failed"))?;
    let mut out: Vec<(f64, [f64; 4])> = (0..d)
        .map(|i| {
            let mut y = [0.0; 4];
            for (r, v) in y.iter_mut().take(d).enumerate() {
                *v = phi[(r, i)];
            }
            (eig.eigenvalues[i], y)
        })
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

/// The solutions of the block `(P, Q)` from those of `(Q, P)` (`s_q`, `s_p` the sizes of
/// `Q` and `P`): `y_PQ[a + s_p·b] = y_QP[b + s_q·a]`.
fn transposed(solutions: &[(f64, [f64; 4])], sq: usize, sp: usize) -> Vec<(f64, [f64; 4])> {
    solutions
        .iter()
        .map(|(rate, y)| {
            let mut t = [0.0; 4];
            for a in 0..sp {
                for b in 0..sq {
                    t[a + sp * b] = y[b + sq * a];
                }
            }
            (*rate, t)
        })
        .collect()
}

impl PlateModes {
    /// The separable modes of `model`, verified (module docs) and sorted by rate (ties
    /// within a relative 10⁻¹⁰, e.g. (1, 2) and (2, 1) on a square, ordered by label).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the model has more than [`MAX_PLATE_MODE_DOFS`]
    /// DOFs; [`Error::Numerical`] if a block cannot be solved or a mode fails its residual
    /// check.
    pub fn new(model: &PlateModel) -> Result<Self> {
        let n = model.n_dofs();
        if n > MAX_PLATE_MODE_DOFS {
            return Err(Error::invalid(
                "plate DOFs for PlateModes",
                n,
                format!("<= {MAX_PLATE_MODE_DOFS} (the verification costs O(n²))"),
            ));
        }
        let axes = *model.axes();
        let mats = model.axis_matrices();
        let waves = [
            axis_waves(&axes[0], &mats[0]),
            axis_waves(&axes[1], &mats[1]),
        ];
        let mut form = PlateModes {
            params: *model.params(),
            axes,
            waves,
            modes: Vec::with_capacity(n),
        };
        let blocks = form.solve_blocks()?;
        form.verify(model, &blocks)?;
        form.label_modes(&blocks);
        if form.modes.len() != n {
            return Err(numerical(format!(
                "{} modes for {n} DOFs",
                form.modes.len()
            )));
        }
        form.fix_signs();
        form.sort();
        Ok(form)
    }

    /// Solves every block; for periodic interior pairs the (cos, cos) solution is used
    /// for all four blocks of the pair (their matrices are equal).
    ///
    /// When both axes are the same chain (a square mesh of a square), the block `(X, Y)`
    /// with `Y` listed before `X` takes the solution of `(Y, X)` with its coefficients
    /// transposed: the two pencils are the same up to the order of the basis (bit for bit,
    /// [`stiffness_entry`] being symmetric), so degenerate pairs such as (1, 2) and (2, 1)
    /// get equal rates, and their order is the label's.
    fn solve_blocks(&self) -> Result<Vec<Block>> {
        let [wx, wy] = &self.waves;
        let square = self.axes[0] == self.axes[1];
        let mut blocks: Vec<Block> = Vec::with_capacity(wx.len() * wy.len());
        for (ix, x) in wx.iter().enumerate() {
            for (iy, y) in wy.iter().enumerate() {
                let travelling = x.is_interior() && y.is_interior() && self.axes[0].periodic;
                let solutions =
                    if travelling && (x.parity, y.parity) != (Parity::Cosine, Parity::Cosine) {
                        let cc = Self::periodic_wave(x.k, Parity::Cosine) * wy.len()
                            + Self::periodic_wave(y.k, Parity::Cosine);
                        blocks[cc].solutions.clone()
                    } else if square && iy < ix {
                        transposed(&blocks[iy * wy.len() + ix].solutions, y.size(), x.size())
                    } else {
                        let (kb, cb) = block_matrices(&self.params, x, y);
                        solve_small(kb, cb)?
                    };
                blocks.push(Block {
                    x: ix,
                    y: iy,
                    solutions,
                });
            }
        }
        Ok(blocks)
    }
}

/// A wave's basis vectors and their products `[v, Mv, K2v, K4v]`, one entry per basis
/// vector.
struct WaveData(Vec<[Vec<f64>; 4]>);

fn wave_data(axis: &Axis, mats: &AxisMatrices, wave: &Wave) -> WaveData {
    let nf = axis.n_free();
    WaveData(
        wave.kinds
            .iter()
            .map(|&t| {
                let v = basis_vector(axis, wave.k, wave.parity, t);
                let mut out = [v, vec![0.0; nf], vec![0.0; nf], vec![0.0; nf]];
                let [v, mv, k2v, k4v] = &mut out;
                mats.m.mul_vec(v, mv);
                mats.k2.mul_vec(v, k2v);
                mats.k4.mul_vec(v, k4v);
                out
            })
            .collect(),
    )
}

/// Work space of the residual check: the 2D residual and the x-factor combinations.
struct Scratch {
    nfx: usize,
    r: Vec<f64>,
    /// `[φ_b, X_M, X_K2, X_K4]` for the current y-basis index b.
    x: [Vec<f64>; 4],
    /// `φ_b` for each b (for the norm).
    phis: [Vec<f64>; 2],
}

impl Scratch {
    fn new(nfx: usize, nfy: usize) -> Self {
        let v = || vec![0.0; nfx];
        Scratch {
            nfx,
            r: vec![0.0; nfx * nfy],
            x: [v(), v(), v(), v()],
            phis: [v(), v()],
        }
    }

    /// `(‖Kφ − λCφ‖, ‖φ‖)` for `φ = Σ_ab y_{a+s_x b} v_a ⊗ u_b`, with
    /// `Kφ − λCφ = Σ_b [(κK4 + σK2 − λξM)φ_b ⊗ M u_b + (2κK2 + σM)φ_b ⊗ K2 u_b +
    /// κMφ_b ⊗ K4 u_b]`, `φ_b = Σ_a y_{a+s_x b} v_a` (the tensor form of the plate's `K`
    /// and `C`).
    fn residual(
        &mut self,
        p: &MembraneParams,
        xd: &WaveData,
        yd: &WaveData,
        y: &[f64; 4],
        lam: f64,
    ) -> (f64, f64) {
        let (kap, sig, xi) = (p.bending_rigidity, p.tension, p.drag);
        let sx = xd.0.len();
        self.r.fill(0.0);
        for (b, u) in yd.0.iter().enumerate() {
            for v in self.x.iter_mut() {
                v.fill(0.0);
            }
            for (a, [v, mv, k2v, k4v]) in xd.0.iter().enumerate() {
                let c = y[a + sx * b];
                for i in 0..self.nfx {
                    self.x[0][i] += c * v[i];
                    self.x[1][i] += c * (kap * k4v[i] + sig * k2v[i] - lam * xi * mv[i]);
                    self.x[2][i] += c * (2.0 * kap * k2v[i] + sig * mv[i]);
                    self.x[3][i] += c * kap * mv[i];
                }
            }
            self.phis[b].copy_from_slice(&self.x[0]);
            for (uq, xq) in u.iter().zip(&self.x).skip(1) {
                add_outer(&mut self.r, uq, xq);
            }
        }
        let mut norm2 = 0.0;
        for (b, ub) in yd.0.iter().enumerate() {
            for (b2, ub2) in yd.0.iter().enumerate() {
                norm2 += dot(&self.phis[b], &self.phis[b2]) * dot(&ub[0], &ub2[0]);
            }
        }
        (dot(&self.r, &self.r).sqrt(), norm2.max(0.0).sqrt())
    }
}

/// `residual ≤ RESIDUAL_TOLERANCE · scale` (false for NaN).
fn within(residual: f64, scale: f64) -> bool {
    residual <= RESIDUAL_TOLERANCE * scale
}

/// `r[iy·nfx + ix] += y[iy]·x[ix]`.
fn add_outer(r: &mut [f64], y: &[f64], x: &[f64]) {
    for (row, &c) in r.chunks_exact_mut(x.len()).zip(y) {
        if c != 0.0 {
            for (ri, xi) in row.iter_mut().zip(x) {
                *ri += c * xi;
            }
        }
    }
}

impl PlateModes {
    /// Checks every block solution's backward error (module docs); the waves of the
    /// shorter axis are tabulated once, those of the longer one once per wave.
    fn verify(&self, model: &PlateModel, blocks: &[Block]) -> Result<()> {
        let (kn, cn) = (model.stiffness().inf_norm(), model.damping().inf_norm());
        let mats = model.axis_matrices();
        let long = usize::from(self.axes[1].n_free() > self.axes[0].n_free());
        let short = 1 - long;
        let table: Vec<WaveData> = self.waves[short]
            .iter()
            .map(|w| wave_data(&self.axes[short], &mats[short], w))
            .collect();
        let index = |b: &Block| if long == 0 { (b.x, b.y) } else { (b.y, b.x) };
        let mut order: Vec<&Block> = blocks.iter().collect();
        order.sort_by_key(|b| index(b));
        let mut scratch = Scratch::new(self.axes[0].n_free(), self.axes[1].n_free());
        let mut current: Option<(usize, WaveData)> = None;
        for b in order {
            let (li, si) = index(b);
            if current.as_ref().map(|c| c.0) != Some(li) {
                let w = &self.waves[long][li];
                current = Some((li, wave_data(&self.axes[long], &mats[long], w)));
            }
            let Some((_, ld)) = current.as_ref() else {
                continue;
            };
            let (xd, yd) = if long == 0 {
                (ld, &table[si])
            } else {
                (&table[si], ld)
            };
            for (lam, y) in &b.solutions {
                let (res, norm) = scratch.residual(&self.params, xd, yd, y, *lam);
                if !within(res, (kn + lam.abs() * cn) * norm) {
                    let (x, yw) = (&self.waves[0][b.x], &self.waves[1][b.y]);
                    return Err(numerical(format!(
                        "mode of waves kx = {} ({:?}), ky = {} ({:?}), rate {lam:e}: \
                         residual {res:e} for |phi| = {norm:e}, |K| = {kn:e}, |C| = {cn:e}",
                        x.k, x.parity, yw.k, yw.parity
                    )));
                }
            }
        }
        Ok(())
    }

    /// Index of the periodic wave `(k, parity)` (waves are listed k by k, cosine first).
    fn periodic_wave(k: usize, parity: Parity) -> usize {
        2 * k + usize::from(parity == Parity::Sine)
    }

    /// Builds the labelled modes from the block solutions (module docs).
    fn label_modes(&mut self, blocks: &[Block]) {
        let periodic = self.axes[0].periodic;
        let mut groups: BTreeMap<(usize, usize, ModeShape), Vec<&Block>> = BTreeMap::new();
        for b in blocks {
            let (x, y) = (&self.waves[0][b.x], &self.waves[1][b.y]);
            if !periodic {
                self.push_group(x.k, y.k, ModeShape::SineSine, &[b]);
            } else if x.is_interior() && y.is_interior() {
                if (x.parity, y.parity) == (Parity::Cosine, Parity::Cosine) {
                    self.push_travelling(b);
                }
            } else {
                let shape = if x.parity == y.parity {
                    ModeShape::Cosine
                } else {
                    ModeShape::Sine
                };
                groups.entry((x.k, y.k, shape)).or_default().push(b);
            }
        }
        for ((kx, ky, shape), mut group) in groups {
            // the block holding w ⊗ w first
            group.sort_by_key(|b| {
                !(self.waves[0][b.x].has_height() && self.waves[1][b.y].has_height())
            });
            self.push_group(kx, ky, shape, &group);
        }
    }

    /// The modes of a group of blocks sharing the label `(kx, ky, shape)`, branches in
    /// block order then ascending; a continuum label for branch 0 where it converges.
    fn push_group(&mut self, kx: usize, ky: usize, shape: ModeShape, group: &[&Block]) {
        let first = group[0];
        let height = self.waves[0][first.x].has_height() && self.waves[1][first.y].has_height();
        let (nx, ny) = (self.axes[0].elements, self.axes[1].elements);
        let resolved = if self.axes[0].periodic {
            (kx, ky) != (0, 0) && 2 * kx < nx && 2 * ky < ny
        } else {
            true
        };
        let (m, n) = (kx as i64, ky as i64);
        let mut branch = 0;
        for b in group {
            for &(rate, coefficients) in &b.solutions {
                let continuum =
                    (branch == 0 && height && resolved).then_some(MembraneMode { m, n, shape });
                self.modes.push(PlateMode {
                    rate,
                    label: PlateModeLabel {
                        m,
                        n,
                        shape,
                        branch,
                    },
                    continuum,
                    parts: [
                        Some(Part {
                            x: b.x,
                            y: b.y,
                            weight: 1.0,
                        }),
                        None,
                    ],
                    coefficients,
                });
                branch += 1;
            }
        }
    }

    /// The 4 travelling combinations of each solution of the (cos, cos) block `b` of an
    /// interior periodic pair (module docs).
    fn push_travelling(&mut self, b: &Block) {
        let (kx, ky) = (self.waves[0][b.x].k, self.waves[1][b.y].k);
        let (xc, xs) = (
            Self::periodic_wave(kx, Parity::Cosine),
            Self::periodic_wave(kx, Parity::Sine),
        );
        let (yc, ys) = (
            Self::periodic_wave(ky, Parity::Cosine),
            Self::periodic_wave(ky, Parity::Sine),
        );
        let part = |x, y, weight| {
            Some(Part {
                x,
                y,
                weight: weight * FRAC_1_SQRT_2,
            })
        };
        let (m, n) = (kx as i64, ky as i64);
        for (branch, &(rate, coefficients)) in b.solutions.iter().enumerate() {
            let combos = [
                (
                    n,
                    ModeShape::Cosine,
                    [part(xc, yc, 1.0), part(xs, ys, -1.0)],
                ),
                (
                    -n,
                    ModeShape::Cosine,
                    [part(xc, yc, 1.0), part(xs, ys, 1.0)],
                ),
                (n, ModeShape::Sine, [part(xs, yc, 1.0), part(xc, ys, 1.0)]),
                (-n, ModeShape::Sine, [part(xs, yc, 1.0), part(xc, ys, -1.0)]),
            ];
            for (n, shape, parts) in combos {
                self.modes.push(PlateMode {
                    rate,
                    label: PlateModeLabel {
                        m,
                        n,
                        shape,
                        branch,
                    },
                    continuum: (branch == 0).then_some(MembraneMode { m, n, shape }),
                    parts,
                    coefficients,
                });
            }
        }
    }

    /// `∫ h_φ φ_c d²r` of `mode` on the continuum shape `target` (tensor form from the 1D
    /// projections of the waves).
    fn projection(&self, mode: &PlateMode, target: MembraneMode) -> f64 {
        let sgn = target.n.signum() as f64;
        // φ_c = Σ ε g(x) g(y), g index 0: cos, 1: sin
        let terms: [(f64, usize, usize); 2] = match target.shape {
            ModeShape::SineSine => [(1.0, 1, 1), (0.0, 0, 0)],
            ModeShape::Cosine => [(1.0, 0, 0), (-sgn, 1, 1)],
            ModeShape::Sine => [(1.0, 1, 0), (sgn, 0, 1)],
        };
        let mut sum = 0.0;
        for part in mode.parts.iter().flatten() {
            let (x, y) = (&self.waves[0][part.x], &self.waves[1][part.y]);
            for b in 0..y.size() {
                for a in 0..x.size() {
                    let c = mode.coefficients[a + x.size() * b];
                    for &(eps, gx, gy) in &terms {
                        sum += part.weight * c * eps * x.proj[a][gx] * y.proj[b][gy];
                    }
                }
            }
        }
        sum
    }

    /// Applies the sign rule of the module docs to every mode.
    fn fix_signs(&mut self) {
        let p = &self.params;
        let norm_c = if self.axes[0].periodic {
            p.area() / 2.0
        } else {
            p.area() / 4.0
        };
        let bound = (norm_c / p.drag).sqrt();
        for i in 0..self.modes.len() {
            let mode = &self.modes[i];
            let by_projection = mode.continuum.and_then(|target| {
                let proj = self.projection(mode, target);
                (proj.abs() > 1e-8 * bound).then_some(proj < 0.0)
            });
            let flip = by_projection.unwrap_or_else(|| {
                let big = mode
                    .coefficients
                    .iter()
                    .fold(0.0_f64, |m, v| if v.abs() > m.abs() { *v } else { m });
                big < 0.0
            });
            if flip {
                for c in self.modes[i].coefficients.iter_mut() {
                    *c = -*c;
                }
            }
        }
    }

    /// Sorts by rate; runs of rates within a relative [`TIE_TOLERANCE`] of the run's first
    /// are ordered by label.
    fn sort(&mut self) {
        self.modes
            .sort_by(|a, b| a.rate.total_cmp(&b.rate).then(a.label.cmp(&b.label)));
        let mut start = 0;
        while start < self.modes.len() {
            let r0 = self.modes[start].rate;
            let end = (start + 1..self.modes.len())
                .find(|&j| self.modes[j].rate > r0 + TIE_TOLERANCE * r0.abs())
                .unwrap_or(self.modes.len());
            self.modes[start..end].sort_by_key(|m| m.label);
            start = end;
        }
    }

    /// The modes, sorted by rate (ties ordered by label).
    pub fn modes(&self) -> &[PlateMode] {
        &self.modes
    }

    /// Number of modes (= free DOFs, the zero mode included).
    pub fn n_modes(&self) -> usize {
        self.modes.len()
    }

    /// The rates in mode order.
    pub fn rates(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.rate).collect()
    }

    /// Number of elements `(nx, ny)` of the plate.
    pub fn elements(&self) -> (usize, usize) {
        (self.axes[0].elements, self.axes[1].elements)
    }

    /// The index and mode with label `label`.
    pub fn find(&self, label: PlateModeLabel) -> Option<(usize, &PlateMode)> {
        self.modes
            .iter()
            .enumerate()
            .find(|(_, m)| m.label == label)
    }

    /// The acoustic mode converging to the continuum mode `mode`, if the mesh resolves it.
    pub fn acoustic(&self, mode: MembraneMode) -> Option<&PlateMode> {
        self.modes.iter().find(|m| m.continuum == Some(mode))
    }

    /// The index of the acoustic mode of `mode` among the modes (for [`Self::mode_vector`]),
    /// if the mesh resolves it.
    pub fn position(&self, mode: MembraneMode) -> Option<usize> {
        self.modes.iter().position(|m| m.continuum == Some(mode))
    }

    /// The column of the acoustic mode of `mode` in [`Self::generalized_modes`] (its index
    /// among the modes, less one past the periodic zero mode, which the dense modes leave
    /// out), if the mesh resolves it. By label, so that equal rates (a square's (1, 2) and
    /// (2, 1)) are told apart.
    pub fn dense_column(&self, mode: MembraneMode) -> Option<usize> {
        let i = self.position(mode)?;
        Some(i - usize::from(self.zero_mode().is_some_and(|z| z < i)))
    }

    /// Index of the periodic zero mode (label `(0, 0, Cosine, 0)`, rate 0); `None`
    /// simply supported.
    pub fn zero_mode(&self) -> Option<usize> {
        let label = PlateModeLabel {
            m: 0,
            n: 0,
            shape: ModeShape::Cosine,
            branch: 0,
        };
        self.find(label).map(|(i, _)| i)
    }

    /// The nodal vector (free DOFs of the plate) of mode `index`, `O(n)`; `C`-normalized.
    ///
    /// # Panics
    /// If `index >= n_modes()`.
    pub fn mode_vector(&self, index: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.axes[0].n_free() * self.axes[1].n_free()];
        self.add_mode_vector(&self.modes[index], &mut out);
        out
    }

    /// Adds the nodal vector of `mode` to `out`.
    fn add_mode_vector(&self, mode: &PlateMode, out: &mut [f64]) {
        let nfx = self.axes[0].n_free();
        for part in mode.parts.iter().flatten() {
            let (x, y) = (&self.waves[0][part.x], &self.waves[1][part.y]);
            let vx: Vec<Vec<f64>> = x
                .kinds
                .iter()
                .map(|&t| basis_vector(&self.axes[0], x.k, x.parity, t))
                .collect();
            let mut comb = vec![0.0; nfx];
            for (b, &t) in y.kinds.iter().enumerate() {
                comb.fill(0.0);
                for (a, v) in vx.iter().enumerate() {
                    let c = part.weight * mode.coefficients[a + x.size() * b];
                    for (ci, vi) in comb.iter_mut().zip(v) {
                        *ci += c * vi;
                    }
                }
                let u = basis_vector(&self.axes[1], y.k, y.parity, t);
                add_outer(out, &u, &comb);
            }
        }
    }

    /// The dense [`GeneralizedModes`] (columns `C`-normalized, in mode order, signs as in
    /// the module docs). Periodic, the zero mode is left out (`n − 1` columns; it is
    /// [`PlateModel::zero_mode`]), since modal references divide by the rates.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] above [`MAX_DENSE_MODE_DOFS`] DOFs.
    pub fn generalized_modes(&self) -> Result<GeneralizedModes> {
        let n = self.axes[0].n_free() * self.axes[1].n_free();
        if n > MAX_DENSE_MODE_DOFS {
            return Err(Error::invalid(
                "plate DOFs for dense modes",
                n,
                format!("<= {MAX_DENSE_MODE_DOFS} (an n x n matrix)"),
            ));
        }
        let zero = self.zero_mode();
        let kept: Vec<&PlateMode> = self
            .modes
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != zero)
            .map(|(_, m)| m)
            .collect();
        let mut vectors = DMatrix::zeros(n, kept.len());
        let mut col = vec![0.0; n];
        for (j, mode) in kept.iter().enumerate() {
            col.fill(0.0);
            self.add_mode_vector(mode, &mut col);
            vectors.column_mut(j).copy_from_slice(&col);
        }
        Ok(GeneralizedModes {
            rates: DVector::from_iterator(kept.len(), kept.iter().map(|m| m.rate)),
            vectors,
        })
    }

    /// The area matrix `G = K2⊗M + M⊗K2` (`hᵀG h = ∫|∇h|²`, the σ-part of `K`) in the
    /// modal coordinates `h = Σ a_i φ_i`: `aᵀ(ΦᵀGΦ)a = Σ_g a_gᵀ B_g a_g` over the groups
    /// returned, one per label `(m, n, shape)` (at most 4 modes: the branches of a block,
    /// or of the two blocks of a periodic edge group). `ΦᵀGΦ` vanishes between groups:
    /// distinct waves are orthogonal under every 1D matrix (module docs), and the two
    /// travelling combinations `(kx, ±ky)` of one interior periodic pair cancel exactly,
    /// their four blocks having equal matrices. `O(n)`.
    ///
    /// This is the coupling of the modes through the excess area `ΔA = ½ hᵀG h` of the
    /// membrane under imposed projected area (issue #28), as
    /// [`super::PairedModes`]' `geometric` blocks are for the filament's stored length.
    pub fn geometric_blocks(&self) -> Vec<GeometricBlock> {
        let mut groups: BTreeMap<(i64, i64, ModeShape), Vec<usize>> = BTreeMap::new();
        for (i, m) in self.modes.iter().enumerate() {
            groups
                .entry((m.label.m, m.label.n, m.label.shape))
                .or_default()
                .push(i);
        }
        let mut blocks: Vec<GeometricBlock> = groups
            .into_values()
            .map(|modes| {
                let k = modes.len();
                let mut matrix = vec![0.0; k * k];
                for (r, &i) in modes.iter().enumerate() {
                    for (c, &j) in modes.iter().enumerate().skip(r) {
                        let v = self.geometric_entry(&self.modes[i], &self.modes[j]);
                        matrix[r * k + c] = v;
                        matrix[c * k + r] = v;
                    }
                }
                GeometricBlock { modes, matrix }
            })
            .collect();
        blocks.sort_by_key(|b| b.modes[0]);
        blocks
    }

    /// `φ_iᵀ G φ_j` from the parts the two modes share (distinct wave blocks are
    /// G-orthogonal).
    fn geometric_entry(&self, a: &PlateMode, b: &PlateMode) -> f64 {
        let mut out = 0.0;
        for pa in a.parts.iter().flatten() {
            for pb in b.parts.iter().flatten() {
                if (pa.x, pa.y) != (pb.x, pb.y) {
                    continue;
                }
                let (x, y) = (&self.waves[0][pa.x], &self.waves[1][pa.y]);
                let (sx, d) = (x.size(), x.size() * y.size());
                let mut q = 0.0;
                for i in 0..d {
                    for j in 0..d {
                        let (ia, ib, ja, jb) = (i % sx, i / sx, j % sx, j / sx);
                        let ex = [x.mats[0][ia][ja], x.mats[1][ia][ja], x.mats[2][ia][ja]];
                        let ey = [y.mats[0][ib][jb], y.mats[1][ib][jb], y.mats[2][ib][jb]];
                        q += a.coefficients[i]
                            * stiffness_entry(0.0, 1.0, ex, ey)
                            * b.coefficients[j];
                    }
                }
                out += pa.weight * pb.weight * q;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::membrane::MembraneBoundary;

    fn model(boundary: MembraneBoundary, nx: usize, ny: usize) -> PlateModel {
        let p = MembraneParams {
            bending_rigidity: 0.8,
            tension: 0.3,
            drag: 2.5,
            kt: 1.3,
            width: 1.7,
            height: 1.1,
            boundary,
        };
        PlateModel::new(p, nx, ny).unwrap()
    }

    /// What: the 1D waves are a basis (2N vectors) in which every assembled 1D matrix is
    /// block-diagonal, with the stored blocks (`VᵀAV`, zero between distinct waves).
    /// Reference: dense products of the assembled 1D matrices. Set-up: hinged N = 1, 2, 5,
    /// periodic N = 2, 3, 6, 7 (even and odd: with and without a Nyquist wave).
    /// Tolerance: 1e-12 of the largest entry (round-off of sums of 2N terms).
    #[test]
    fn waves_block_diagonalize_the_axis_matrices() {
        use MembraneBoundary::{Periodic, SimplySupported};
        for (boundary, n) in [
            (SimplySupported, 1),
            (SimplySupported, 2),
            (SimplySupported, 5),
            (Periodic, 2),
            (Periodic, 3),
            (Periodic, 6),
            (Periodic, 7),
        ] {
            let plate = model(boundary, n, 2);
            let (axis, mats) = (&plate.axes()[0], &plate.axis_matrices()[0]);
            let waves = axis_waves(axis, mats);
            let mut cols = Vec::new();
            let mut owner = Vec::new();
            for (w, wave) in waves.iter().enumerate() {
                for &t in wave.kinds {
                    cols.push(basis_vector(axis, wave.k, wave.parity, t));
                    owner.push(w);
                }
            }
            assert_eq!(cols.len(), axis.n_free(), "{boundary:?} N = {n}");
            let v = DMatrix::from_fn(axis.n_free(), cols.len(), |i, j| cols[j][i]);
            assert!(v.clone().try_inverse().is_some(), "not a basis");
            for (q, a) in [&mats.m, &mats.k2, &mats.k4].into_iter().enumerate() {
                let b = v.transpose() * a.to_dense() * &v;
                let scale = b.amax();
                let mut local = vec![0; waves.len()];
                let pos: Vec<usize> = owner
                    .iter()
                    .map(|&w| {
                        local[w] += 1;
                        local[w] - 1
                    })
                    .collect();
                for i in 0..cols.len() {
                    for j in 0..cols.len() {
                        let expect = if owner[i] == owner[j] {
                            waves[owner[i]].mats[q][pos[i]][pos[j]]
                        } else {
                            0.0
                        };
                        assert!(
                            (b[(i, j)] - expect).abs() <= 1e-12 * scale,
                            "{boundary:?} N = {n}, matrix {q}: ({i}, {j}) = {} vs {expect}",
                            b[(i, j)]
                        );
                    }
                }
            }
        }
    }

    /// What: the residual check is not vacuous: the true block solutions pass, and a rate
    /// off by 10⁻⁶ (relative) or a coefficient off by 10⁻⁶ is refused. Reference: the
    /// check's own tolerance (10⁻¹⁰ backward error). Set-up: 4×3 plates, both boundaries,
    /// the block of the lowest acoustic mode. Tolerance: exact (pass or refuse).
    #[test]
    fn verification_refuses_wrong_modes() {
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let plate = model(boundary, 4, 3);
            let axes = *plate.axes();
            let mats = plate.axis_matrices();
            let form = PlateModes {
                params: *plate.params(),
                axes,
                waves: [
                    axis_waves(&axes[0], &mats[0]),
                    axis_waves(&axes[1], &mats[1]),
                ],
                modes: Vec::new(),
            };
            let blocks = form.solve_blocks().unwrap();
            assert!(form.verify(&plate, &blocks).is_ok());
            let b = blocks.iter().position(|b| b.solutions.len() == 4).unwrap();
            let mut wrong_rate = blocks.clone();
            wrong_rate[b].solutions[0].0 *= 1.0 + 1e-6;
            assert!(
                form.verify(&plate, &wrong_rate).is_err(),
                "{boundary:?}: rate"
            );
            let mut wrong_vector = blocks.clone();
            wrong_vector[b].solutions[0].1[1] += 1e-6 * wrong_vector[b].solutions[0].1[0];
            assert!(
                form.verify(&plate, &wrong_vector).is_err(),
                "{boundary:?}: vector"
            );
        }
    }

    /// What: `transposed` maps the solution of the block `(Q, P)` to that of `(P, Q)`:
    /// equal to a direct solve of `(P, Q)` (same rates; coefficients equal up to sign).
    /// Reference: `solve_small` on `block_matrices` of `(P, Q)`. Set-up: square 5×5 plate,
    /// blocks of sizes 4 and 2 (an edge wave with one part), both ways. Tolerance: 1e-12
    /// relative for rates and coefficients (two eigensolves of permuted matrices; the
    /// eigenvector round-off ε·‖A‖/gap measured ≤ 1e-14 here).
    #[test]
    fn transposed_solutions_solve_the_transposed_block() {
        let plate = model(MembraneBoundary::SimplySupported, 5, 5);
        let axes = *plate.axes();
        let waves = axis_waves(&axes[0], &plate.axis_matrices()[0]);
        let p = *plate.params();
        for (q, pw) in [(1, 2), (0, 3), (5, 2)] {
            let (kq, cq) = block_matrices(&p, &waves[q], &waves[pw]);
            let from_qp = solve_small(kq, cq).unwrap();
            let (kp, cp) = block_matrices(&p, &waves[pw], &waves[q]);
            let direct = solve_small(kp, cp).unwrap();
            let mapped = transposed(&from_qp, waves[pw].size(), waves[q].size());
            for ((r1, y1), (r2, y2)) in mapped.iter().zip(&direct) {
                assert!((r1 - r2).abs() <= 1e-12 * r2, "{r1} vs {r2}");
                let sign = if y1.iter().zip(y2).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                let scale = y2.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                let gap = y1
                    .iter()
                    .zip(y2)
                    .fold(0.0_f64, |m, (a, b)| m.max((sign * a - b).abs()));
                assert!(gap <= 1e-12 * scale, "{y1:?} vs {y2:?}");
            }
        }
    }

    /// What: [`PlateModes::geometric_blocks`] is `ΦᵀGΦ` of the area matrix, block by
    /// block, and zero between blocks. Reference: the dense `ΦᵀGΦ` with `G = K(σ = 1) −
    /// K(σ = 0)` from the assembled banded stiffness (independent of the wave blocks) and
    /// `Φ` from [`PlateModes::mode_vector`]. Set-up: simply supported 3 × 2, 4 × 4 and
    /// periodic 4 × 3, 4 × 4, 5 × 5 (odd: no Nyquist wave); the equal counts on a square
    /// (tied modes), 3 × 2 and 4 × 3 on a 1.7 × 1.1 rectangle. Tolerance: 1e-11 of the largest entry (sums of n products).
    #[test]
    fn geometric_blocks_are_the_area_matrix_in_modal_coordinates() {
        use MembraneBoundary::{Periodic, SimplySupported};
        for (boundary, nx, ny) in [
            (SimplySupported, 3, 2),
            (SimplySupported, 4, 4),
            (Periodic, 4, 3),
            (Periodic, 4, 4),
            (Periodic, 5, 5),
        ] {
            let square = |t: f64| {
                let mut p = *model(boundary, nx, ny).params();
                if nx == ny {
                    (p.width, p.height) = (1.3, 1.3);
                }
                p.tension = t;
                PlateModel::new(p, nx, ny).unwrap()
            };
            let plate = square(0.0);
            let g = square(1.0).stiffness().to_dense() - plate.stiffness().to_dense();
            let modes = PlateModes::new(&plate).unwrap();
            let n = modes.n_modes();
            let mut phi = DMatrix::zeros(n, n);
            for j in 0..n {
                phi.column_mut(j).copy_from_slice(&modes.mode_vector(j));
            }
            let dense = phi.transpose() * g * &phi;
            let mut blocked = DMatrix::zeros(n, n);
            let mut seen = vec![0; n];
            for b in modes.geometric_blocks() {
                let k = b.modes.len();
                assert!((1..=4).contains(&k), "{k} modes in a block");
                for (r, &i) in b.modes.iter().enumerate() {
                    seen[i] += 1;
                    for (c, &j) in b.modes.iter().enumerate() {
                        blocked[(i, j)] = b.matrix[r * k + c];
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "every mode in one block");
            let err = (&dense - &blocked).amax();
            assert!(
                err <= 1e-11 * dense.amax(),
                "{boundary:?} {nx}x{ny}: {err:e}"
            );
        }
    }
}
