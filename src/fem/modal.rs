//! Generalized modes of `(K, C)` and the exact stationary covariances of the discrete
//! system.
//!
//! With `K φ_i = λ_i C φ_i`, `ΦᵀCΦ = I`, `ΦᵀKΦ = Λ`, and `w = Φ q`, `q = ΦᵀC w`, the
//! semi-discrete equation `C ẇ = −K w + F` decouples into `q̇_i = −λ_i q_i + (ΦᵀF)_i`.
//! The continuum analogue is `φ_n(x) = sqrt(2/(ξL))·sin(nπx/L)` with
//! `λ_n = π⁴n⁴EI/(ξL⁴)` and `⟨q_n²⟩ = kT/λ_n`; the Hermite-cubic rates converge to it as
//! `O(h⁴)`.
//!
//! Every linear integrator of the project is diagonal in this basis:
//! `q_{k+1,i} = m_i q_{k,i} + g_i (Φᵀζ_k)_i`, with `ζ_k` the standardized noise vector of
//! [`super::noise`] (covariance `Σ_ζ`), and multiplier `m_i` and gain `g_i` supplied by the
//! integrator. The functions below give the exact stationary covariances.

use super::beam::BeamModel;
use super::hermite::{GAUSS5, shape};
use super::system::LinearSystem;
use crate::error::{Error, Result};
use nalgebra::{Cholesky, DMatrix, DVector, SymmetricEigen};
use std::f64::consts::PI;

/// Generalized eigenpairs of `K φ = λ C φ` over the free DOFs of a [`LinearSystem`].
#[derive(Debug, Clone)]
pub struct GeneralizedModes {
    /// Rates `λ_i`, ascending.
    pub rates: DVector<f64>,
    /// Column `i` is `φ_i`, normalized `ΦᵀCΦ = I` (hence `ΦᵀKΦ = diag λ`). Sign: fixed by
    /// the object that assembled the system; for the beam ([`generalized_modes`]) the
    /// projection `∫₀ᴸ w_h(x) φ_{i+1}(x) dx` of the interpolated mode on the
    /// continuum mode of the same index (the sine for hinged ends) is positive (computed by 5-point Gauss per
    /// element); if that projection is negligible (< 1e-8 of its Cauchy–Schwarz bound),
    /// the largest-magnitude component is made positive.
    pub vectors: DMatrix<f64>,
}

fn numerical(routine: &str, detail: impl Into<String>) -> Error {
    Error::Numerical {
        routine: routine.into(),
        detail: detail.into(),
    }
}

/// Dense generalized eigen-decomposition of `(K, C)`: `C = LLᵀ`,
/// `A = L⁻¹ K L⁻ᵀ = Y Λ Yᵀ` (symmetric eigen), `Φ = L⁻ᵀ Y`. `O(n³)`; for the small and
/// moderate meshes used as references.
///
/// # Errors
/// [`Error::Numerical`] if `C` is not positive definite or the eigensolver fails.
///
/// A beam with rigid modes ([`BeamModel::rigid_modes`], a free end and no clamp) has as
/// many zero rates: they are left out, so the columns are the elastic modes only (the
/// rigid motions diffuse and have no stationary law; [`BeamModel::rigid_modes`] gives
/// them, C-orthogonal to every column here).
pub fn generalized_modes(beam: &BeamModel) -> Result<GeneralizedModes> {
    let skip = beam.ends().rigid_modes();
    if beam.ends().is_hinged() {
        let len = beam.mesh().length();
        return pencil_modes(beam, skip, |i, col| {
            let kk = (i + 1) as f64 * PI / len;
            beam_mode_flips(beam, col, |x| (kk * x).sin())
        });
    }
    let continuum = crate::spectral::EndedBeam::new(*beam.params(), beam.ends())?;
    pencil_modes(beam, skip, |i, col| {
        beam_mode_flips(beam, col, |x| continuum.mode_shape(i + 1, x))
    })
}

/// [`generalized_modes`] of any [`LinearSystem`], with the sign rule of the object that
/// assembled it: column `i` (C-normalized) is negated where `flip(i, φ_i)` is true.
///
/// # Errors
/// As [`generalized_modes`].
pub fn generalized_modes_signed(
    system: &LinearSystem,
    flip: impl Fn(usize, &[f64]) -> bool,
) -> Result<GeneralizedModes> {
    pencil_modes(system, 0, flip)
}

/// [`generalized_modes_signed`] leaving out the `skip` slowest modes, which must be zero
/// modes: their rates at most 1e-10 of the largest in magnitude (round-off of an exact
/// null space); the kept rates must be positive.
fn pencil_modes(
    system: &LinearSystem,
    skip: usize,
    flip: impl Fn(usize, &[f64]) -> bool,
) -> Result<GeneralizedModes> {
    let k = system.stiffness().to_dense();
    let c = system.damping().to_dense();
    let n = k.nrows();
    let (l, a) = symmetric_pencil(&k, c, "generalized_modes")?;
    let eig = SymmetricEigen::try_new(a, f64::EPSILON, 1000 * n.max(10)).ok_or_else(|| {
        numerical(
            "generalized_modes",
            "symmetric eigensolver did not converge",
        )
    })?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let top = eig.eigenvalues.amax();
    if let Some(&i) = order[..skip.min(n)]
        .iter()
        .find(|&&i| eig.eigenvalues[i].abs() > 1e-10 * top)
    {
        return Err(numerical(
            "generalized_modes",
            format!(
                "expected {skip} zero modes, rate {:e} is not zero (largest {top:e})",
                eig.eigenvalues[i]
            ),
        ));
    }
    let order = &order[skip.min(n)..];
    let n_kept = order.len();
    let rates = DVector::from_iterator(n_kept, order.iter().map(|&i| eig.eigenvalues[i]));
    let ysorted = DMatrix::from_fn(n, n_kept, |r, col| eig.eigenvectors[(r, order[col])]);
    let mut phi = l
        .tr_solve_lower_triangular(&ysorted)
        .ok_or_else(|| numerical("generalized_modes", "triangular solve L^-T Y failed"))?;
    if let Some(i) = rates.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(numerical(
            "generalized_modes",
            format!("rate {i} is {:e}, expected finite and > 0", rates[i]),
        ));
    }
    for i in 0..n_kept {
        let col: Vec<f64> = phi.column(i).iter().copied().collect();
        if flip(i, &col) {
            phi.column_mut(i).neg_mut();
        }
    }
    Ok(GeneralizedModes {
        rates,
        vectors: phi,
    })
}

/// The symmetric form of the pencil `K φ = λ C φ`: the Cholesky factor `L` of `C = LLᵀ`
/// and `A = L⁻¹ K L⁻ᵀ` (symmetrized), whose eigenpairs `(λ, y)` are the generalized ones
/// with `φ = L⁻ᵀ y` (`ΦᵀCΦ = I`). Dense; `routine` names the caller in errors.
///
/// # Errors
/// [`Error::Numerical`] if `C` is not positive definite or a triangular solve fails.
pub(crate) fn symmetric_pencil(
    k: &DMatrix<f64>,
    c: DMatrix<f64>,
    routine: &str,
) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let l = Cholesky::new(c)
        .ok_or_else(|| numerical(routine, "damping matrix not positive definite"))?
        .l();
    let y = l
        .solve_lower_triangular(k)
        .ok_or_else(|| numerical(routine, "triangular solve L^-1 K failed"))?;
    let a = l
        .solve_lower_triangular(&y.transpose())
        .ok_or_else(|| numerical(routine, "triangular solve L^-1 K L^-T failed"))?;
    let a = (&a + a.transpose()) * 0.5;
    Ok((l, a))
}

/// The beam's sign rule for a mode with C-normalized vector `col` (see
/// [`GeneralizedModes::vectors`]): whether its projection on `shape`, the continuum mode
/// of the same index (normalized ∫shape² = L/2: the sine for hinged ends,
/// [`crate::spectral::EndedBeam::mode_shape`] for any), is negative (or, where that
/// projection is negligible, its largest-magnitude component is).
fn beam_mode_flips(beam: &BeamModel, col: &[f64], mode: impl Fn(f64) -> f64) -> bool {
    let len = beam.mesh().length();
    let mut proj = 0.0;
    let mut norm2 = 0.0;
    let mesh = beam.mesh();
    for e in 0..mesh.n_elements() {
        let h = mesh.element_length(e);
        let x0 = mesh.nodes()[e];
        let dofs = beam.element_dofs(e);
        for &(t, wq) in &GAUSS5 {
            let s = 0.5 * h * (t + 1.0);
            let nv = shape(h, s);
            let w: f64 = dofs
                .iter()
                .zip(nv)
                .filter_map(|(d, na)| d.map(|j| na * col[j]))
                .sum();
            proj += 0.5 * h * wq * w * mode(x0 + s);
            norm2 += 0.5 * h * wq * w * w;
        }
    }
    let bound = (norm2 * 0.5 * len).sqrt();
    if proj.abs() > 1e-8 * bound {
        proj < 0.0
    } else {
        let jmax = col
            .iter()
            .enumerate()
            .fold((0, 0.0_f64), |(bj, bv), (j, v)| {
                if v.abs() > bv { (j, v.abs()) } else { (bj, bv) }
            })
            .0;
        col[jmax] < 0.0
    }
}

impl GeneralizedModes {
    /// Number of modes (= free DOFs).
    pub fn len(&self) -> usize {
        self.rates.len()
    }

    /// Whether there are no modes.
    pub fn is_empty(&self) -> bool {
        self.rates.is_empty()
    }

    /// Modal projector `P` with rows `φ_iᵀC`, `i < n_modes` (clamped to the number of
    /// modes), so modal amplitudes are `q = P w` and `w = Φ q` (all modes).
    pub fn projector(&self, system: &LinearSystem, n_modes: usize) -> DMatrix<f64> {
        let r = n_modes.min(self.len());
        let c = system.damping().to_dense();
        self.vectors.columns(0, r).transpose() * c
    }
}

/// Modal noise covariance `Σ_q = Φᵀ Σ_ζ Φ` (the identity for consistent noise,
/// `Σ_ζ = C`). The diagonal `Σ_q,ii` is the stationary variance of mode `i` relative to
/// equipartition `kT/λ_i` under the continuous-time dynamics.
///
/// # Panics
/// If `sigma_zeta` is not `n × n`.
pub fn modal_noise_covariance(modes: &GeneralizedModes, sigma_zeta: &DMatrix<f64>) -> DMatrix<f64> {
    modes.vectors.transpose() * sigma_zeta * &modes.vectors
}

/// Exact stationary covariance of the discrete modal recursion
/// `q_{k+1} = M q_k + G Φᵀζ_k` (diagonal `M = diag m`, `G = diag g`), i.e. the solution of
/// `S = M S M + G Σ_q G`: `S_ij = g_i g_j Σ_q,ij / (1 − m_i m_j)`. Only the leading
/// `r = m.len()` modes are used (`Σ_q` may be larger; its leading block is taken).
///
/// # Errors
/// [`Error::InvalidParameter`] if `m` and `g` differ in length or exceed `Σ_q`, or if
/// some `|m_i| ≥ 1` (or not finite), naming the mode (1-based).
pub fn discrete_stationary_covariance(
    sigma_q: &DMatrix<f64>,
    m: &[f64],
    g: &[f64],
) -> Result<DMatrix<f64>> {
    let r = m.len();
    if g.len() != r {
        return Err(Error::invalid(
            "gain vector length",
            g.len(),
            format!("= multiplier vector length {r}"),
        ));
    }
    if r > sigma_q.nrows() || r > sigma_q.ncols() {
        return Err(Error::invalid(
            "number of modes",
            r,
            format!("<= modal covariance size {}", sigma_q.nrows()),
        ));
    }
    for (i, mi) in m.iter().enumerate() {
        if !mi.is_finite() || mi.abs() >= 1.0 {
            return Err(Error::invalid(
                format!("multiplier m of mode {} (index {i})", i + 1),
                mi,
                "|m| < 1 (stable mode)",
            ));
        }
    }
    if let Some(i) = g.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            format!("gain g of mode {} (index {i})", i + 1),
            g[i],
            "finite",
        ));
    }
    Ok(DMatrix::from_fn(r, r, |i, j| {
        g[i] * g[j] * sigma_q[(i, j)] / (1.0 - m[i] * m[j])
    }))
}

/// Exact stationary covariance of the continuous-time modal dynamics
/// `q̇ = −Λ q + ΦᵀF`, `⟨F(t)F(t')ᵀ⟩ = 2kT Σ_ζ δ(t − t')`: the solution of
/// `ΛS + SΛ = 2kT Σ_q`, `S_ij = 2kT Σ_q,ij / (λ_i + λ_j)`. Uses the leading
/// `r = rates.len()` modes. For consistent noise, `S = kT Λ⁻¹` and `ΦSΦᵀ = kT K⁻¹`.
///
/// # Panics
/// If `sigma_q` is smaller than `rates.len()`.
pub fn continuous_stationary_covariance(
    sigma_q: &DMatrix<f64>,
    rates: &DVector<f64>,
    kt: f64,
) -> DMatrix<f64> {
    let r = rates.len();
    DMatrix::from_fn(r, r, |i, j| {
        2.0 * kt * sigma_q[(i, j)] / (rates[i] + rates[j])
    })
}

/// Nodal (free-DOF) covariance `Φ_r S Φ_rᵀ` of a modal covariance `S` over the leading
/// `r = S.nrows()` modes.
///
/// # Panics
/// If `s_modal` is not square or has more rows than there are modes.
pub fn nodal_covariance(modes: &GeneralizedModes, s_modal: &DMatrix<f64>) -> DMatrix<f64> {
    let r = s_modal.nrows();
    let phi = modes.vectors.columns(0, r);
    phi * s_modal * phi.transpose()
}
