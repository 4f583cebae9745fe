//! Bogner–Fox–Schmit plate elements for the Helfrich membrane: the semi-discrete form of
//!
//! ```text
//! ξ ∂h/∂t = −κ∇⁴h + σ∇²h + f,   ⟨f(r,t) f(r′,t′)⟩ = 2ξkT δ(r−r′) δ(t−t′)        (M1)
//! ```
//!
//! (the membrane equation of [`crate::spectral::membrane`], energy
//! `E = ∫ κ/2 (∇²h)² + σ/2 |∇h|²`) on the `a × b` rectangle, simply supported or periodic,
//! with a uniform mesh of `nx × ny` rectangles of size `hx = a/nx`, `hy = b/ny`.
//!
//! # The element
//!
//! The Bogner–Fox–Schmit (BFS) rectangle is the tensor product of the 1D Hermite cubic
//! ([`super::hermite`]): its 16 shape functions are `N_a(x) N_b(y)`, and each node carries
//! the four products of a 1D x-DOF (`w` or `θ`) and a 1D y-DOF: `w`, `w_x`, `w_y`, `w_xy`.
//! The interpolant is C¹, so the element is conforming in H². With the 1D element matrices
//! `M = ∫NᵀN`, `K2 = ∫N′ᵀN′`, `K4 = ∫N″ᵀN″` ([`super::hermite`]) and `A ⊗ B` meaning "`A`
//! on the x-factor, `B` on the y-factor", every matrix is a sum of tensor products:
//!
//! ```text
//! C = ξ M⊗M                                        (∫ ξ h²)
//! K = κ (K4⊗M + 2 K2⊗K2 + M⊗K4) + σ (K2⊗M + M⊗K2)    (∫ κ(h_xx² + 2h_xy² + h_yy²) + σ|∇h|²)
//! b_e = b_x ⊗ b_y                                  (∫_e N, the load of eq. 5)
//! ```
//!
//! Because the mesh is a tensor grid, the assembled matrices are the same tensor products of
//! the assembled 1D matrices, and that is how they are built (one term per entry,
//! `O(n·bw₁²)`; the unit tests compare them with element-by-element assembly of the
//! 16×16 element matrices, [`PlateModel::element_matrices`]).
//!
//! **The bending form and `∫(∇²h)²`.** Per element, `∫(∇²N)ᵀ(∇²N)` is *not* the bending
//! block above: the two differ by `∫(N_xxᵀN_yy + N_yyᵀN_xx − 2N_xyᵀN_xy)`, the
//! Gaussian-curvature term `2∫(h_xx h_yy − h_xy²)` (nonzero element by element). Over the assembled spaces of this module the difference
//! vanishes: integrating by parts in x then in y (the interpolant is C¹, piecewise bicubic),
//! `∫ h_xx h_yy = ∫ h_xy² + ∮` boundary terms `[h_x h_yy]` on the x-edges and `[h_x h_xy]`
//! on the y-edges. Simply supported, `h = 0` along every edge (`w` and the tangential
//! derivative are constrained, and the edge trace is their cubic Hermite interpolant), so
//! `h_yy = 0` on x-edges and `h_x = 0` on y-edges; periodic, the terms cancel between
//! opposite edges. Hence `xᵀK x = ∫ κ(∇²h)² + σ|∇h|²` exactly for every free-DOF vector:
//! the discrete energy is the Helfrich energy of the interpolant (checked by quadrature in
//! the unit tests, which also show that without the constraints the two forms differ).
//!
//! # Boundary conditions
//!
//! - **Simply supported** (`h = ∇²h = 0` on every edge): the free 2D space is the tensor
//!   product of the 1D *hinged* spaces (`w` constrained at both end nodes, `θ` free; the
//!   moment condition is natural). On an x-edge (`x = 0` or `a`) `w` and its tangential
//!   derivative `w_y` are constrained and the normal derivative `w_x` and `w_xy` stay free;
//!   on a y-edge `w` and `w_x` are constrained. (Constraining the normal derivative as
//!   well, as some public BFS codes do, converges to a different problem:
//!   `tests/plate_model.rs` shows it.)
//! - **Periodic**: the 1D space has the `N` nodes `0 … N−1` (node `N` ≡ node 0), both
//!   DOFs free. `K` has exactly one zero mode, the uniform translation (`w ≡ 1`, derivatives
//!   0: [`PlateModel::zero_mode`]), as the continuum's excluded `q = 0`: it is a free
//!   Brownian translation with no stationary variance. Downstream modal code must exclude
//!   it ([`super::modal::generalized_modes_signed`] refuses zero rates; see
//!   [`super::plate_modes`]). For `σ` above the buckling tension every other rate is
//!   positive: the FE functions are periodic H² functions, for which
//!   `∫(∇²h)² ≥ q_min² ∫|∇h|²` (Fourier), so `xᵀKx ≥ (κq_min² + σ)∫|∇h|² > 0` unless
//!   `h` is constant. (Simply supported, `h ∈ H² ∩ H¹₀` and the same holds with the
//!   Dirichlet `q_min² = π²(1/a² + 1/b²)`: `K` is positive definite.)
//!
//! # The fastest rate
//!
//! For `σ ≥ 0` the largest generalized eigenvalue is, on any uniform mesh and for either
//! boundary ([`PlateModel::max_rate_closed_form`]),
//!
//! ```text
//! λ_max = [κ (2520/hx⁴ + 2·42²/(hx²hy²) + 2520/hy⁴) + 42 σ (1/hx² + 1/hy²)] / ξ,
//! ```
//!
//! i.e. `8568 κ/(ξh⁴) + 84 σ/(ξh²)` for `hx = hy = h` ([`PLATE_RATE_FACTOR`] = 8568 =
//! 3.4 × the beam's 2520). Proof: on the periodic 1D chain the Bloch blocks (`c = cos ϑ`,
//! `s = sin ϑ`, `h = 1`) are `M̂ = [[312+108c, −26is], [26is, 8−6c]]/420`,
//! `K̂2 = [[72−72c, 6is], [−6is, 8−2c]]/30`, `K̂4 = [[24−24c, 12is], [−12is, 8+4c]]`, and
//! `2520M̂ − K̂4` (trace `1888 + 632c`, determinant `(1−c)(45696 − 1344c)`) and
//! `30(42M̂ − K̂2)` (trace `880 + 380c`, determinant `(1−c)(6768 − 720c)`) are positive
//! semidefinite for every ϑ, so `K4 ≤ (2520/h⁴) M` and `K2 ≤ (42/h²) M` on every periodic
//! chain, hence on every hinged chain (its odd extension is a periodic chain of `2N`
//! elements with twice its quadratic forms). With `M, K2, K4 ≥ 0`, `A ≤ αM` and `B ≤ βM`
//! give `A⊗B ≤ αβ M⊗M` and `A⊗M ≤ α M⊗M`, so `K ≤ λ_max C`; and the twist vector
//! `w_xy ≡ 1` (all other DOFs 0; free in both spaces) is the top eigenvector of every 1D
//! pencil at once (`ϑ = 0`, the uniform rotation), so it attains the bound. For `σ < 0`
//! there is no such closed form; [`PlateModel::max_rate`] (Sturm bisection) covers every
//! case.
//!
//! ## References
//! - F. K. Bogner, R. L. Fox and L. A. Schmit, *The generation of interelement-compatible
//!   stiffness and mass matrices by the use of interpolation formulas*, Proc. Conf. Matrix
//!   Methods in Structural Mechanics, Wright-Patterson AFB (1965), 397–443.
//! - P. Grisvard, *Elliptic Problems in Nonsmooth Domains* (1985), § 3.1 (`‖∇²u‖ = ‖D²u‖`
//!   on polygons for `u ∈ H² ∩ H¹₀`, the identity used above).
//! - I. Fried, *Bounds on the extremal eigenvalues of the finite element stiffness and mass
//!   matrices and their spectral condition number*, J. Sound Vib. 22, 407 (1972) (the
//!   element bound of [`PlateModel::max_rate`]).

use super::banded::SymBanded;
use super::beam::UNIFORM_RATE_FACTOR;
use super::hermite::{self, ElementMatrix};
use super::modal::symmetric_pencil;
use super::system::{ElementLoad, LinearSystem};
use crate::error::{Error, Result};
use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
use nalgebra::{DMatrix, SymmetricEigen};

/// Largest number of free DOFs [`PlateModel::new`] accepts.
pub const MAX_PLATE_DOFS: usize = 4_000_000;

/// Largest number of stored band entries `n·(bw + 1)` per assembled matrix (320 MB of
/// `f64` each): the half-bandwidth grows with `nx`, so this, not the DOF count, limits
/// square meshes (to about 110 × 110 elements simply supported).
pub const MAX_BAND_ENTRIES: usize = 40_000_000;

/// The factor `c` in `λ_max = c·κ/(ξh⁴)` for `σ = 0`, `hx = hy = h`, uniform mesh, either
/// boundary: `2·2520 + 2·42² = 8568` (see the module docs for the proof).
pub const PLATE_RATE_FACTOR: f64 =
    2.0 * UNIFORM_RATE_FACTOR + 2.0 * SLOPE_RATE_FACTOR * SLOPE_RATE_FACTOR;

/// The factor `42` in `K2 ≤ (42/h²) M` on uniform periodic and hinged Hermite chains
/// (attained by the uniform rotation; see the module docs).
pub const SLOPE_RATE_FACTOR: f64 = 42.0;

/// One of the four DOFs of a BFS node: the product of a 1D x-DOF and a 1D y-DOF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeDof {
    /// `w` (x: `w`, y: `w`).
    Height,
    /// `w_x` (x: `θ`, y: `w`).
    SlopeX,
    /// `w_y` (x: `w`, y: `θ`).
    SlopeY,
    /// `w_xy` (x: `θ`, y: `θ`).
    Twist,
}

impl NodeDof {
    /// The 1D DOF kinds `(x, y)`, 0 for `w` and 1 for `θ`.
    fn parts(self) -> (usize, usize) {
        match self {
            NodeDof::Height => (0, 0),
            NodeDof::SlopeX => (1, 0),
            NodeDof::SlopeY => (0, 1),
            NodeDof::Twist => (1, 1),
        }
    }
}

/// One direction of the tensor grid: `elements` uniform Hermite-cubic elements on
/// `[0, length]`, hinged (simply supported) or periodic, and its 1D free-DOF numbering
/// (see [`PlateModel`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Axis {
    pub(crate) elements: usize,
    pub(crate) length: f64,
    pub(crate) periodic: bool,
}

/// The assembled 1D matrices of one [`Axis`] over its free DOFs: `M = ∫NᵀN`,
/// `K2 = ∫N′ᵀN′`, `K4 = ∫N″ᵀN″`.
#[derive(Debug, Clone)]
pub(crate) struct AxisMatrices {
    pub(crate) m: SymBanded,
    pub(crate) k2: SymBanded,
    pub(crate) k4: SymBanded,
}

impl Axis {
    /// Element length `h = length/elements`.
    pub(crate) fn h(&self) -> f64 {
        self.length / self.elements as f64
    }

    /// Number of 1D free DOFs: `2N` for both boundaries.
    pub(crate) fn n_free(&self) -> usize {
        2 * self.elements
    }

    /// Half-bandwidth of the 1D matrices: 3 hinged, 5 periodic (folded order).
    pub(crate) fn bandwidth(&self) -> usize {
        if self.periodic { 5 } else { 3 }
    }

    /// Free index of the 1D DOF `t` (0: `w`, 1: `θ`) of node `node ≤ N` (`None` if
    /// constrained or out of range); see [`PlateModel`] for both numberings.
    pub(crate) fn free(&self, node: usize, t: usize) -> Option<usize> {
        let n = self.elements;
        if node > n || t > 1 {
            return None;
        }
        if self.periodic {
            let node = node % n;
            let pos = if 2 * node < n {
                2 * node
            } else {
                2 * (n - 1 - node) + 1
            };
            return Some(2 * pos + t);
        }
        match (t, node) {
            (0, 0) => None,
            (0, i) if i == n => None,
            (0, i) => Some(2 * i - 1),
            (_, i) if i == n => Some(2 * n - 1),
            (_, i) => Some(2 * i),
        }
    }

    /// Free indices of the local DOFs `[w_a, θ_a, w_b, θ_b]` of element `e`.
    pub(crate) fn element_dofs(&self, e: usize) -> [Option<usize>; 4] {
        [
            self.free(e, 0),
            self.free(e, 1),
            self.free(e + 1, 0),
            self.free(e + 1, 1),
        ]
    }

    /// The element containing `x` and the local coordinate `s ∈ [0, h]` (the last element
    /// for `x = length`), or `None` if `x` is not finite or outside `[0, length]`.
    pub(crate) fn locate(&self, x: f64) -> Option<(usize, f64)> {
        if !(x.is_finite() && (0.0..=self.length).contains(&x)) {
            return None;
        }
        let h = self.h();
        let e = ((x / h).floor() as usize).min(self.elements - 1);
        Some((e, (x - e as f64 * h).clamp(0.0, h)))
    }

    /// Assembles `M`, `K2`, `K4` over the free DOFs.
    pub(crate) fn assemble(&self) -> Result<AxisMatrices> {
        let (n, bw, h) = (self.n_free(), self.bandwidth(), self.h());
        let mut out = AxisMatrices {
            m: SymBanded::new(n, bw),
            k2: SymBanded::new(n, bw),
            k4: SymBanded::new(n, bw),
        };
        let (me, k2e, k4e) = (
            hermite::damping_matrix(h, 1.0),
            hermite::geometric_matrix(h),
            hermite::bending_matrix(h, 1.0),
        );
        for e in 0..self.elements {
            let dofs = self.element_dofs(e);
            for a in 0..4 {
                for b in 0..=a {
                    if let (Some(i), Some(j)) = (dofs[a], dofs[b]) {
                        out.m.add(i, j, me[a][b])?;
                        out.k2.add(i, j, k2e[a][b])?;
                        out.k4.add(i, j, k4e[a][b])?;
                    }
                }
            }
        }
        Ok(out)
    }
}

/// A 16×16 BFS element matrix, local DOF `4b + a` for the x-local DOF `a` and the y-local
/// DOF `b` (each in `[w_a, θ_a, w_b, θ_b]` order).
pub type PlateElementMatrix = [[f64; 16]; 16];

/// The stiffness entry `κ((K4x·My + Mx·K4y) + 2·K2x·K2y) + σ(K2x·My + Mx·K2y)` from the 1D
/// entries `[M, K2, K4]` of the x- and the y-factor; symmetric in `x ↔ y` bit for bit
/// (floating-point sums and products of two terms commute).
pub(crate) fn stiffness_entry(kappa: f64, sigma: f64, x: [f64; 3], y: [f64; 3]) -> f64 {
    let [mx, k2x, k4x] = x;
    let [my, k2y, k4y] = y;
    kappa * ((k4x * my + mx * k4y) + 2.0 * k2x * k2y) + sigma * (k2x * my + mx * k2y)
}

/// The element stiffness `K_e` and damping `C_e` of an `hx × hy` BFS rectangle (see the
/// module docs; local order as [`PlateElementMatrix`]).
pub(crate) fn element_matrices(
    params: &MembraneParams,
    hx: f64,
    hy: f64,
) -> (PlateElementMatrix, PlateElementMatrix) {
    let one_d = |h: f64| -> [ElementMatrix; 3] {
        [
            hermite::damping_matrix(h, 1.0),
            hermite::geometric_matrix(h),
            hermite::bending_matrix(h, 1.0),
        ]
    };
    let (x, y) = (one_d(hx), one_d(hy));
    let mut k = [[0.0; 16]; 16];
    let mut c = [[0.0; 16]; 16];
    for (i, (ki, ci)) in k.iter_mut().zip(c.iter_mut()).enumerate() {
        let (a, b) = (i % 4, i / 4);
        for j in 0..16 {
            let (a2, b2) = (j % 4, j / 4);
            let ex = [x[0][a][a2], x[1][a][a2], x[2][a][a2]];
            let ey = [y[0][b][b2], y[1][b][b2], y[2][b][b2]];
            ki[j] = stiffness_entry(params.bending_rigidity, params.tension, ex, ey);
            ci[j] = params.drag * ex[0] * ey[0];
        }
    }
    (k, c)
}

/// The element load `b_e = ∫_e N = b_x ⊗ b_y` of an `hx × hy` rectangle (local order as
/// [`PlateElementMatrix`]).
pub(crate) fn element_load(hx: f64, hy: f64) -> [f64; 16] {
    let (bx, by) = (hermite::load_vector(hx), hermite::load_vector(hy));
    std::array::from_fn(|i| bx[i % 4] * by[i / 4])
}

/// The membrane of (M1) discretized by Bogner–Fox–Schmit rectangles on a uniform
/// `nx × ny` mesh (see the module docs for the element, the boundary conditions and the
/// energy).
///
/// **DOF numbering.** Node `(i, j)` sits at `(i·hx, j·hy)`, `i = 0…nx`, `j = 0…ny` (periodic:
/// node `nx` ≡ node 0 and node `ny` ≡ node 0), and carries `[w, w_x, w_y, w_xy]`, each the
/// product of a 1D DOF of the x-chain at node `i` and one of the y-chain at node `j`
/// ([`NodeDof`]: `w = (w, w)`, `w_x = (θ, w)`, `w_y = (w, θ)`, `w_xy = (θ, θ)`). A 2D DOF
/// is free iff both 1D DOFs are, and its free index is
///
/// ```text
/// I = iy·nfx + ix,    nfx = 2·nx, nfy = 2·ny, n = nfx·nfy = 4·nx·ny,
/// ```
///
/// with `ix` (`iy`) the 1D free index of its x (y) factor:
///
/// - **simply supported**, the hinged beam's numbering ([`super::BeamModel`]):
///   `θ_0 ↦ 0`, `w_i ↦ 2i − 1` (`1 ≤ i ≤ N−1`), `θ_i ↦ 2i` (`i < N`), `θ_N ↦ 2N − 1`;
///   `w_0`, `w_N` constrained;
/// - **periodic**, the folded order of the nodes `0, N−1, 1, N−2, 2, …`: node `i` at
///   position `p(i) = 2i` if `2i < N`, else `2(N−1−i) + 1`, so that neighbours (including
///   `N−1` and 0) are at most 2 positions apart; `w_i ↦ 2p(i)`, `θ_i ↦ 2p(i) + 1`.
///
/// For example, simply supported, the height of an interior node `(i, j)` has the free
/// index `(2j − 1)·2nx + 2i − 1` and the twist `w_xy` of the corner `(0, 0)` the index 0;
/// periodic, the height of node `(0, 0)` has the index 0 and that of `(1, 0)` the index 4.
///
/// The 1D matrices then have half-bandwidth `b₁ = 3` (simply supported) or 5 (periodic)
/// and the 2D ones `b₁·nfx + b₁`: `6nx + 3` simply supported, `10nx + 5` periodic (put the
/// direction with fewer elements along x).
///
/// Matrices over the free DOFs (symmetric banded): stiffness
/// `K = κ(K4⊗M + 2K2⊗K2 + M⊗K4) + σ(K2⊗M + M⊗K2)`, damping `C = ξ M⊗M`. The model *is* a
/// [`LinearSystem`] `C ḣ = −K h + F` (it dereferences to one), whose element loads are
/// `b_e = b_x ⊗ b_y` (16 entries, local order of [`PlateElementMatrix`]) with amplitude
/// `sqrt(ξ/(hx·hy))` (eq. 5 per element area), elements in the order `ey·nx + ex`.
#[derive(Debug, Clone)]
pub struct PlateModel {
    params: MembraneParams,
    axes: [Axis; 2],
    factors: [AxisMatrices; 2],
    system: LinearSystem,
}

impl std::ops::Deref for PlateModel {
    type Target = LinearSystem;

    fn deref(&self) -> &LinearSystem {
        &self.system
    }
}

/// Refuses fewer than `min` elements along the direction `name`.
fn check_elements(name: &str, value: usize, boundary: MembraneBoundary) -> Result<()> {
    let min = match boundary {
        MembraneBoundary::SimplySupported => 1,
        MembraneBoundary::Periodic => 2,
    };
    if value < min {
        return Err(Error::invalid(
            name,
            value,
            format!(">= {min} for a {} membrane", boundary.name()),
        ));
    }
    Ok(())
}

/// Refuses meshes whose DOF count or band storage exceeds the caps.
fn check_size(axes: &[Axis; 2]) -> Result<()> {
    // in u128 from the element counts, saturating: no overflow for any usize input
    let (nfx, nfy) = (2 * axes[0].elements as u128, 2 * axes[1].elements as u128);
    let n = nfx.saturating_mul(nfy);
    let entries = n.saturating_mul(axes[0].bandwidth() as u128 * (nfx + 1) + 1);
    if n > MAX_PLATE_DOFS as u128 || entries > MAX_BAND_ENTRIES as u128 {
        return Err(Error::invalid(
            "elements (nx, ny)",
            format!(
                "({}, {}): {n} DOFs, {entries} band entries per matrix",
                axes[0].elements, axes[1].elements
            ),
            format!(
                "at most {MAX_PLATE_DOFS} DOFs and {MAX_BAND_ENTRIES} band entries \
                 n·(bw + 1) per matrix (the half-bandwidth grows with nx: put the \
                 direction with fewer elements along x)"
            ),
        ));
    }
    Ok(())
}

impl PlateModel {
    /// Assembles `K`, `C` and the element loads of an `nx × ny` uniform mesh.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the parameters are invalid
    /// ([`MembraneParams::validate`]), `nx` or `ny` is below 1 (below 2 periodic: a
    /// single periodic element would couple a node to itself), or the mesh exceeds
    /// [`MAX_PLATE_DOFS`] or [`MAX_BAND_ENTRIES`].
    pub fn new(params: MembraneParams, nx: usize, ny: usize) -> Result<Self> {
        params.validate()?;
        check_elements("nx", nx, params.boundary)?;
        check_elements("ny", ny, params.boundary)?;
        let periodic = params.boundary == MembraneBoundary::Periodic;
        let axes = [
            Axis {
                elements: nx,
                length: params.width,
                periodic,
            },
            Axis {
                elements: ny,
                length: params.height,
                periodic,
            },
        ];
        check_size(&axes)?;
        let factors = [axes[0].assemble()?, axes[1].assemble()?];
        let (k, c) = assemble_kronecker(&params, &axes, &factors)?;
        let loads = element_loads(&params, &axes);
        Ok(PlateModel {
            system: LinearSystem::new(params.kt, k, c, loads)?,
            params,
            axes,
            factors,
        })
    }

    /// The physical parameters.
    pub fn params(&self) -> &MembraneParams {
        &self.params
    }

    /// Number of elements `(nx, ny)`.
    pub fn elements(&self) -> (usize, usize) {
        (self.axes[0].elements, self.axes[1].elements)
    }

    /// Element size `(hx, hy) = (a/nx, b/ny)`.
    pub fn element_size(&self) -> (f64, f64) {
        (self.axes[0].h(), self.axes[1].h())
    }

    /// The element stiffness `K_e` and damping `C_e` (16×16, local order of
    /// [`PlateElementMatrix`]; the same for every element of the uniform mesh): the tensor
    /// products of the module docs with the 1D element matrices of [`super::hermite`].
    pub fn element_matrices(&self) -> (PlateElementMatrix, PlateElementMatrix) {
        let (hx, hy) = self.element_size();
        element_matrices(&self.params, hx, hy)
    }

    /// The x and y chains (crate-internal: for [`super::plate_modes`]).
    pub(crate) fn axes(&self) -> &[Axis; 2] {
        &self.axes
    }

    /// The assembled 1D matrices of the x and y chains.
    pub(crate) fn axis_matrices(&self) -> &[AxisMatrices; 2] {
        &self.factors
    }

    /// Free index of DOF `dof` of node `(i, j)` (`None` if constrained, or `i > nx` or
    /// `j > ny`; periodic, node `nx` is node 0 and node `ny` is node 0).
    pub fn node_dof_index(&self, i: usize, j: usize, dof: NodeDof) -> Option<usize> {
        let (tx, ty) = dof.parts();
        let ix = self.axes[0].free(i, tx)?;
        let iy = self.axes[1].free(j, ty)?;
        Some(iy * self.axes[0].n_free() + ix)
    }

    /// Free index of the height `w` of node `(i, j)` ([`Self::node_dof_index`] of
    /// [`NodeDof::Height`]).
    pub fn node_height_index(&self, i: usize, j: usize) -> Option<usize> {
        self.node_dof_index(i, j, NodeDof::Height)
    }

    /// The element `(ex, ey)` containing `(x, y)` and the local coordinates, or `None`
    /// outside the closed rectangle or for non-finite coordinates.
    fn locate(&self, x: f64, y: f64) -> Option<((usize, f64), (usize, f64))> {
        Some((self.axes[0].locate(x)?, self.axes[1].locate(y)?))
    }

    /// The interpolation weights of the height at `(x, y)`: `h(x, y) = Σ weight·state[index]`
    /// over the returned `(index, weight)` pairs (at most 16, the element's free DOFs,
    /// weights `N_a(x)·N_b(y)`), or `None` outside the rectangle or for non-finite
    /// coordinates.
    pub fn probe(&self, x: f64, y: f64) -> Option<Vec<(usize, f64)>> {
        let ((ex, sx), (ey, sy)) = self.locate(x, y)?;
        let (nxv, nyv) = (
            hermite::shape(self.axes[0].h(), sx),
            hermite::shape(self.axes[1].h(), sy),
        );
        let (dx, dy) = (self.axes[0].element_dofs(ex), self.axes[1].element_dofs(ey));
        let nfx = self.axes[0].n_free();
        let mut out = Vec::with_capacity(16);
        for (b, iy) in dy.iter().enumerate() {
            for (a, ix) in dx.iter().enumerate() {
                if let (Some(ix), Some(iy)) = (ix, iy) {
                    out.push((iy * nfx + ix, nxv[a] * nyv[b]));
                }
            }
        }
        Some(out)
    }

    /// Bicubic Hermite interpolation `h(x, y) = Σ N_a(x) N_b(y) d_ab` on the element
    /// containing `(x, y)`. NaN outside the closed rectangle or for non-finite
    /// coordinates. Allocation-free.
    ///
    /// # Panics
    /// If `state.len() != n_dofs()`.
    pub fn height_at(&self, state: &[f64], x: f64, y: f64) -> f64 {
        assert_eq!(state.len(), self.n_dofs(), "height_at: wrong state length");
        let Some(((ex, sx), (ey, sy))) = self.locate(x, y) else {
            return f64::NAN;
        };
        let (nxv, nyv) = (
            hermite::shape(self.axes[0].h(), sx),
            hermite::shape(self.axes[1].h(), sy),
        );
        let (dx, dy) = (self.axes[0].element_dofs(ex), self.axes[1].element_dofs(ey));
        let nfx = self.axes[0].n_free();
        let mut sum = 0.0;
        for (b, iy) in dy.iter().enumerate() {
            let Some(iy) = iy else { continue };
            let row: f64 = dx
                .iter()
                .zip(nxv)
                .filter_map(|(ix, na)| ix.map(|ix| na * state[iy * nfx + ix]))
                .sum();
            sum += nyv[b] * row;
        }
        sum
    }

    /// The twist vector `w_xy ≡ 1` (every other DOF 0): the top generalized eigenvector for
    /// `σ ≥ 0` (see the module docs), the lower end of the bracket of [`Self::max_rate`].
    pub fn twist_vector(&self) -> Vec<f64> {
        let nfx = self.axes[0].n_free();
        let mut x = vec![0.0; self.n_dofs()];
        for j in 0..=self.axes[1].elements {
            for i in 0..=self.axes[0].elements {
                if let (Some(ix), Some(iy)) = (self.axes[0].free(i, 1), self.axes[1].free(j, 1)) {
                    x[iy * nfx + ix] = 1.0;
                }
            }
        }
        x
    }

    /// The zero mode of the periodic membrane, C-normalized: `w ≡ 1/sqrt(ξab)` at every
    /// node, derivatives 0 (`K·u = 0` exactly, `uᵀCu = 1`). `None` simply supported (`K` is
    /// then positive definite).
    pub fn zero_mode(&self) -> Option<Vec<f64>> {
        if !self.axes[0].periodic {
            return None;
        }
        let v = 1.0 / (self.params.drag * self.params.area()).sqrt();
        let mut u = vec![0.0; self.n_dofs()];
        for j in 0..self.axes[1].elements {
            for i in 0..self.axes[0].elements {
                if let Some(k) = self.node_height_index(i, j) {
                    u[k] = v;
                }
            }
        }
        Some(u)
    }

    /// Largest generalized eigenvalue `λ_max` of `K φ = λ C φ` (fastest decay rate), by
    /// Sturm-sequence bisection ([`LinearSystem::max_rate_bisection`]) between the
    /// Rayleigh quotient of the twist vector ([`Self::twist_vector`], a lower bound, exact
    /// for `σ ≥ 0`) and Fried's element bound `max λ(K_e, C_e)` of the 16×16 element pencil
    /// (an upper bound, times 1.001, confirmed by its count). Equals
    /// [`Self::max_rate_closed_form`] for `σ ≥ 0`. Cost `O(n·bw²)` per step (one banded
    /// `LDLᵀ`), about 45 steps.
    ///
    /// # Errors
    /// [`Error::Numerical`] if the element bound or the bracket cannot be established.
    pub fn max_rate(&self) -> Result<f64> {
        let (hx, hy) = self.element_size();
        let upper = 1.001 * element_rate_bound(&self.params, hx, hy)?;
        self.system.max_rate_bisection(upper, &self.twist_vector())
    }

    /// The closed form of `λ_max` for `σ ≥ 0` (module docs):
    /// `[κ(2520/hx⁴ + 2·42²/(hx²hy²) + 2520/hy⁴) + 42σ(1/hx² + 1/hy²)]/ξ`; `None` for
    /// `σ < 0`, where the bound it rests on fails.
    pub fn max_rate_closed_form(&self) -> Option<f64> {
        let p = &self.params;
        if p.tension < 0.0 {
            return None;
        }
        let (hx, hy) = self.element_size();
        let (c2x, c2y) = (SLOPE_RATE_FACTOR / (hx * hx), SLOPE_RATE_FACTOR / (hy * hy));
        let (c4x, c4y) = (
            UNIFORM_RATE_FACTOR / hx.powi(4),
            UNIFORM_RATE_FACTOR / hy.powi(4),
        );
        let bending = c4x + 2.0 * c2x * c2y + c4y;
        Some((p.bending_rigidity * bending + p.tension * (c2x + c2y)) / p.drag)
    }

    /// Explicit Euler(–Maruyama) stability limit `Δt < 2/λ_max` (the amplification factor
    /// `1 − λΔt` of the fastest mode must exceed −1).
    ///
    /// # Errors
    /// As [`Self::max_rate`].
    pub fn explicit_euler_dt_limit(&self) -> Result<f64> {
        Ok(2.0 / self.max_rate()?)
    }
}

/// `K` and `C` over the free DOFs as Kronecker sums of the assembled 1D matrices: entry
/// `(I, J)`, `I = iy·nfx + ix`, `J = jy·nfx + jx`, from the 1D entries `(ix, jx)` and
/// `(iy, jy)` ([`stiffness_entry`]; `C = ξ·Mx·My`). Each stored pair once.
fn assemble_kronecker(
    params: &MembraneParams,
    axes: &[Axis; 2],
    factors: &[AxisMatrices; 2],
) -> Result<(SymBanded, SymBanded)> {
    let (nfx, nfy) = (axes[0].n_free(), axes[1].n_free());
    let b1 = axes[0].bandwidth();
    let bw = b1 * nfx + b1;
    let n = nfx * nfy;
    let mut k = SymBanded::new(n, bw);
    let mut c = SymBanded::new(n, bw);
    let entries =
        |f: &AxisMatrices, i: usize, j: usize| [f.m.get(i, j), f.k2.get(i, j), f.k4.get(i, j)];
    for iy in 0..nfy {
        for jy in iy.saturating_sub(b1)..=iy {
            let ey = entries(&factors[1], iy, jy);
            if ey == [0.0; 3] {
                continue;
            }
            for ix in 0..nfx {
                let jx_hi = if jy == iy { ix } else { (ix + b1).min(nfx - 1) };
                for jx in ix.saturating_sub(b1)..=jx_hi {
                    let ex = entries(&factors[0], ix, jx);
                    let (i, j) = (iy * nfx + ix, jy * nfx + jx);
                    let kv = stiffness_entry(params.bending_rigidity, params.tension, ex, ey);
                    k.add(i, j, kv)?;
                    c.add(i, j, params.drag * ex[0] * ey[0])?;
                }
            }
        }
    }
    Ok((k, c))
}

/// The element loads of eq. (5): `b_e = b_x ⊗ b_y`, amplitude `sqrt(ξ/(hx·hy))`, element
/// `ey·nx + ex`.
fn element_loads(params: &MembraneParams, axes: &[Axis; 2]) -> Vec<ElementLoad> {
    let (hx, hy) = (axes[0].h(), axes[1].h());
    let nfx = axes[0].n_free();
    let load = element_load(hx, hy).to_vec();
    let amplitude = (params.drag / (hx * hy)).sqrt();
    let mut loads = Vec::with_capacity(axes[0].elements * axes[1].elements);
    for ey in 0..axes[1].elements {
        let dy = axes[1].element_dofs(ey);
        for ex in 0..axes[0].elements {
            let dx = axes[0].element_dofs(ex);
            let dofs = (0..16)
                .map(|l| Some(dy[l / 4]? * nfx + dx[l % 4]?))
                .collect();
            loads.push(ElementLoad {
                amplitude,
                load: load.clone(),
                dofs,
            });
        }
    }
    loads
}

/// Largest generalized eigenvalue of the element pencil `(K_e, C_e)` (16×16): Fried's
/// upper bound on `λ_max` of the assembled pencil (`xᵀKx = Σ x_eᵀK_e x_e ≤
/// λ_e Σ x_eᵀC_e x_e = λ_e xᵀCx`).
fn element_rate_bound(params: &MembraneParams, hx: f64, hy: f64) -> Result<f64> {
    let (ke, ce) = element_matrices(params, hx, hy);
    let k = DMatrix::from_fn(16, 16, |i, j| ke[i][j]);
    let c = DMatrix::from_fn(16, 16, |i, j| ce[i][j]);
    let numerical = |what: &str| Error::Numerical {
        routine: "plate element_rate_bound".into(),
        detail: what.into(),
    };
    let (_, a) = symmetric_pencil(&k, c, "plate element_rate_bound")?;
    let top = SymmetricEigen::new(a).eigenvalues.max();
    if top.is_finite() && top > 0.0 {
        Ok(top)
    } else {
        Err(numerical(&format!("element bound is {top:e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::fem::hermite::{GAUSS5, shape, shape_d1, shape_d2};
    use crate::fem::{BeamModel, Mesh};
    use crate::rng::trajectory_rng;
    use rand::RngExt;

    const SEED: u64 = 0xB0F5_0001;

    /// Non-unit parameters, so that a wrong power of one cannot cancel.
    fn params(boundary: MembraneBoundary) -> MembraneParams {
        MembraneParams {
            bending_rigidity: 0.8,
            tension: 0.3,
            drag: 2.5,
            kt: 1.3,
            width: 1.7,
            height: 1.1,
            boundary,
        }
    }

    const SS: MembraneBoundary = MembraneBoundary::SimplySupported;
    const PERIODIC: MembraneBoundary = MembraneBoundary::Periodic;

    /// `∫∫ f(s, t)` over `[0, hx] × [0, hy]` by 5×5 Gauss–Legendre (exact for degree ≤ 9 in
    /// each variable; the integrands below have degree ≤ 6).
    fn quad2(hx: f64, hy: f64, f: impl Fn(f64, f64) -> f64) -> f64 {
        let mut sum = 0.0;
        for &(u, wu) in &GAUSS5 {
            for &(v, wv) in &GAUSS5 {
                let (s, t) = (0.5 * hx * (u + 1.0), 0.5 * hy * (v + 1.0));
                sum += 0.25 * hx * hy * wu * wv * f(s, t);
            }
        }
        sum
    }

    /// `[N, N_x, N_y, N_xx, N_xy, N_yy]` of the 16 BFS shape functions at `(s, t)`.
    fn shape2(hx: f64, hy: f64, s: f64, t: f64) -> [[f64; 16]; 6] {
        let (x0, x1, x2) = (shape(hx, s), shape_d1(hx, s), shape_d2(hx, s));
        let (y0, y1, y2) = (shape(hy, t), shape_d1(hy, t), shape_d2(hy, t));
        let pairs = [(x0, y0), (x1, y0), (x0, y1), (x2, y0), (x1, y1), (x0, y2)];
        pairs.map(|(fx, fy)| std::array::from_fn(|l| fx[l % 4] * fy[l / 4]))
    }

    /// What: the hinged 1D numbering is the beam's, and the assembled 1D `K4` is the beam's
    /// stiffness over `EI`. Reference: [`BeamModel`]'s node indices and matrices.
    /// Tolerance: indices exact; matrices 1e-14 of the largest entry (a few round-offs).
    #[test]
    fn hinged_axis_is_the_beam() {
        let fp = FilamentParams::default();
        for n in 1..7 {
            let beam = BeamModel::new(fp, Mesh::uniform(fp.length, n).unwrap()).unwrap();
            let axis = Axis {
                elements: n,
                length: fp.length,
                periodic: false,
            };
            for node in 0..=n + 1 {
                assert_eq!(axis.free(node, 0), beam.node_deflection_index(node));
                assert_eq!(axis.free(node, 1), beam.node_rotation_index(node));
            }
            let k4 = axis.assemble().unwrap().k4;
            let scale = beam.stiffness().to_dense().amax() / fp.bending_rigidity;
            for i in 0..2 * n {
                for j in 0..2 * n {
                    let kb = beam.stiffness().get(i, j) / fp.bending_rigidity;
                    assert!(
                        (k4.get(i, j) - kb).abs() <= 1e-14 * scale,
                        "N = {n}: K[{i}][{j}]"
                    );
                }
            }
        }
    }

    /// What: the folded periodic numbering is a bijection of the `N` nodes' DOFs onto
    /// `0..2N`, node `N` is node 0, and every element's DOFs lie within half-bandwidth 5
    /// (attained for `N ≥ 4`). Reference: the definition. Tolerance: exact.
    #[test]
    fn folded_periodic_numbering_is_banded() {
        for n in 2..12 {
            let axis = Axis {
                elements: n,
                length: 1.0,
                periodic: true,
            };
            let mut seen = vec![false; 2 * n];
            for node in 0..n {
                for t in 0..2 {
                    let i = axis.free(node, t).unwrap();
                    assert!(!seen[i], "N = {n}: index {i} twice");
                    seen[i] = true;
                    assert_eq!(
                        axis.free(node + n, t),
                        if node == 0 { Some(i) } else { None }
                    );
                }
            }
            let mut widest = 0;
            for e in 0..n {
                let d = axis.element_dofs(e).map(|x| x.unwrap());
                for a in d {
                    for b in d {
                        widest = widest.max(a.abs_diff(b));
                    }
                }
            }
            assert!(widest <= axis.bandwidth(), "N = {n}: {widest}");
            assert!(n < 4 || widest == 5, "N = {n}: {widest}");
        }
    }

    /// What: the 16×16 tensor-product element matrices are `∫ξNᵀN`,
    /// `∫κ(N_xxᵀN_xx + 2N_xyᵀN_xy + N_yyᵀN_yy) + σ(N_xᵀN_x + N_yᵀN_y)` and `b_e = ∫N`, and
    /// differ from `∫κ(∇²N)ᵀ(∇²N)` (the Gaussian-curvature term is nonzero per element).
    /// Reference: 5×5 Gauss quadrature of the shape functions (exact for these degrees).
    /// Tolerance: 1e-12 of the largest entry (round-off of sums of ~100 terms); the
    /// difference from the Laplacian form is a few per cent of the largest entry (asserted
    /// > 1%).
    #[test]
    fn element_matrices_match_quadrature() {
        let p = params(SS);
        let (hx, hy) = (0.37, 0.61);
        let (ke, ce) = element_matrices(&p, hx, hy);
        let be = element_load(hx, hy);
        let kscale = ke.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
        let cscale = ce.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
        let (kap, sig) = (p.bending_rigidity, p.tension);
        let mut laplacian_gap = 0.0_f64;
        for i in 0..16 {
            let b = quad2(hx, hy, |s, t| shape2(hx, hy, s, t)[0][i]);
            assert!((be[i] - b).abs() <= 1e-14 * hx * hy, "b[{i}]");
            for j in 0..16 {
                let c = quad2(hx, hy, |s, t| {
                    let n = shape2(hx, hy, s, t);
                    p.drag * n[0][i] * n[0][j]
                });
                let k = quad2(hx, hy, |s, t| {
                    let n = shape2(hx, hy, s, t);
                    let bend = n[3][i] * n[3][j] + 2.0 * n[4][i] * n[4][j] + n[5][i] * n[5][j];
                    kap * bend + sig * (n[1][i] * n[1][j] + n[2][i] * n[2][j])
                });
                let lap = quad2(hx, hy, |s, t| {
                    let n = shape2(hx, hy, s, t);
                    let (li, lj) = (n[3][i] + n[5][i], n[3][j] + n[5][j]);
                    kap * li * lj + sig * (n[1][i] * n[1][j] + n[2][i] * n[2][j])
                });
                assert!((ce[i][j] - c).abs() <= 1e-12 * cscale, "C[{i}][{j}]");
                assert!((ke[i][j] - k).abs() <= 1e-12 * kscale, "K[{i}][{j}]");
                assert_eq!(ke[i][j], ke[j][i]);
                assert_eq!(ce[i][j], ce[j][i]);
                laplacian_gap = laplacian_gap.max((ke[i][j] - lap).abs());
            }
        }
        assert!(
            laplacian_gap > 0.01 * kscale,
            "gap {laplacian_gap} of {kscale}"
        );
    }

    /// Element-by-element assembly of the 16×16 element matrices over the free DOFs.
    fn assemble_by_elements(model: &PlateModel) -> (SymBanded, SymBanded) {
        let (n, bw) = (model.n_dofs(), model.stiffness().bandwidth());
        let (mut k, mut c) = (SymBanded::new(n, bw), SymBanded::new(n, bw));
        let (ke, ce) = model.element_matrices();
        for load in model.element_loads() {
            for a in 0..16 {
                for b in 0..=a {
                    if let (Some(i), Some(j)) = (load.dofs[a], load.dofs[b]) {
                        k.add(i, j, ke[a][b]).unwrap();
                        c.add(i, j, ce[a][b]).unwrap();
                    }
                }
            }
        }
        (k, c)
    }

    /// What: the Kronecker assembly equals element-by-element assembly of the 16×16
    /// element matrices through the element loads' DOF maps (which also fixes those maps
    /// and the stated half-bandwidths). Reference: the element matrices (checked above).
    /// Tolerance: 1e-13 of the largest entry (the two sum the same terms in different
    /// orders).
    #[test]
    fn kronecker_assembly_equals_element_assembly() {
        for (boundary, nx, ny) in [
            (SS, 1, 1),
            (SS, 3, 2),
            (SS, 2, 4),
            (PERIODIC, 2, 2),
            (PERIODIC, 3, 2),
            (PERIODIC, 5, 4),
        ] {
            let model = PlateModel::new(params(boundary), nx, ny).unwrap();
            let b1 = if boundary == SS { 3 } else { 5 };
            assert_eq!(model.stiffness().bandwidth(), b1 * 2 * nx + b1);
            assert_eq!(model.n_dofs(), 4 * nx * ny);
            let (k, c) = assemble_by_elements(&model);
            for (a, b) in [(&k, model.stiffness()), (&c, model.damping())] {
                let (da, db) = (a.to_dense(), b.to_dense());
                let gap = (&da - &db).amax();
                assert!(gap <= 1e-13 * db.amax(), "{boundary:?} {nx}x{ny}: {gap}");
            }
        }
    }

    /// `[h, h_x, h_y, h_xx, h_xy, h_yy]` at local `(s, t)` of element `(ex, ey)` from the
    /// 16 local DOF values `d`.
    fn field(hx: f64, hy: f64, d: &[f64; 16], s: f64, t: f64) -> [f64; 6] {
        shape2(hx, hy, s, t).map(|n| n.iter().zip(d).map(|(a, b)| a * b).sum())
    }

    /// `Σ_e ∫ [κ(∇²h)², κ(h_xx² + 2h_xy² + h_yy²), σ|∇h|²]` by quadrature, with the 16
    /// local DOF values of each element `ey·nx + ex` from `local(ex, ey)`.
    fn energies(model: &PlateModel, local: impl Fn(usize, usize) -> [f64; 16]) -> [f64; 3] {
        let (nx, ny) = model.elements();
        let (hx, hy) = model.element_size();
        let p = model.params();
        let mut out = [0.0; 3];
        for ey in 0..ny {
            for ex in 0..nx {
                let d = local(ex, ey);
                let f = |s: f64, t: f64| field(hx, hy, &d, s, t);
                out[0] += quad2(hx, hy, |s, t| {
                    let v = f(s, t);
                    p.bending_rigidity * (v[3] + v[5]).powi(2)
                });
                out[1] += quad2(hx, hy, |s, t| {
                    let v = f(s, t);
                    p.bending_rigidity * (v[3] * v[3] + 2.0 * v[4] * v[4] + v[5] * v[5])
                });
                out[2] += quad2(hx, hy, |s, t| {
                    let v = f(s, t);
                    p.tension * (v[1] * v[1] + v[2] * v[2])
                });
            }
        }
        out
    }

    /// What: on the simply supported and the periodic free spaces the quadratic form of the
    /// assembled `K` is the Helfrich energy `∫κ(∇²h)² + σ|∇h|²` of the interpolant (the
    /// Gaussian-curvature boundary term vanishes, module docs), while on the unconstrained
    /// space (every nodal DOF free, the edges free) `∫(∇²h)²` and `∫h_xx² + 2h_xy² + h_yy²`
    /// differ: the identity rests on the boundary conditions, and the test can fail.
    /// Reference: 5×5 Gauss quadrature per element of the interpolated field. Set-up:
    /// random free-DOF vectors (fixed seed), 3×2 and 4×3 meshes. Tolerance: 1e-11 relative
    /// (round-off of a few thousand terms); the unconstrained gap is of order one (> 1%).
    #[test]
    fn stiffness_form_is_the_helfrich_energy_on_the_free_spaces() {
        let mut rng = trajectory_rng(SEED, 0);
        for (boundary, nx, ny) in [(SS, 3, 2), (SS, 4, 3), (PERIODIC, 3, 2), (PERIODIC, 4, 3)] {
            let model = PlateModel::new(params(boundary), nx, ny).unwrap();
            let x: Vec<f64> = (0..model.n_dofs())
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            let loads = model.element_loads();
            let e = energies(&model, |ex, ey| {
                let dofs = &loads[ey * nx + ex].dofs;
                std::array::from_fn(|l| dofs[l].map_or(0.0, |i| x[i]))
            });
            let form = model.stiffness().quadratic_form(&x);
            let helfrich = e[0] + e[2];
            assert!(
                (form - helfrich).abs() <= 1e-11 * helfrich,
                "{boundary:?}: {form} vs {helfrich}"
            );
            assert!((e[0] - e[1]).abs() <= 1e-11 * e[0], "{boundary:?}");
        }
        // unconstrained: global nodal values, node (i, j) DOF t at [j][i][t]
        let model = PlateModel::new(params(SS), 3, 2).unwrap();
        let nodal: Vec<Vec<[f64; 4]>> = (0..3)
            .map(|_| {
                (0..4)
                    .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
                    .collect()
            })
            .collect();
        let e = energies(&model, |ex, ey| {
            std::array::from_fn(|l| {
                let (a, b) = (l % 4, l / 4);
                let (i, j) = (ex + a / 2, ey + b / 2);
                nodal[j][i][(a % 2) + 2 * (b % 2)]
            })
        });
        assert!(
            (e[0] - e[1]).abs() > 1e-2 * e[0],
            "unconstrained: {} vs {}",
            e[0],
            e[1]
        );
    }

    /// What: the algebra of the closed form of `λ_max` (module docs): the periodic Bloch
    /// blocks built from the 1D element matrices give `2520M̂ − K̂4` with trace
    /// `1888 + 632c` and determinant `(1−c)(45696 − 1344c)`, and `30(42M̂ − K̂2)` with trace
    /// `880 + 380c` and determinant `(1−c)(6768 − 720c)`, both ≥ 0 on `c ∈ [−1, 1]`
    /// (positive semidefinite), with equality of the determinant at `ϑ = 0`.
    /// Reference: the formulas of the module docs. Set-up: 201 wavenumbers ϑ ∈ [0, π],
    /// `h = 1`. Tolerance: 1e-9 absolute on numbers of size ≤ 10⁵ (round-off).
    #[test]
    fn bloch_blocks_prove_the_closed_form() {
        let bloch = |m: ElementMatrix, th: f64| -> (f64, f64, f64) {
            // [[p, q], [q̄, r]]: p, r real; q = i·(A01 − A10)_{01}·sin ϑ (real parts cancel)
            let (c, s) = (th.cos(), th.sin());
            let p = m[0][0] + m[2][2] + (m[0][2] + m[2][0]) * c;
            let r = m[1][1] + m[3][3] + (m[1][3] + m[3][1]) * c;
            let re_q = m[0][1] + m[2][3] + (m[0][3] + m[2][1]) * c;
            assert!(re_q.abs() < 1e-12);
            let im_q = (m[0][3] - m[2][1]) * s;
            (p, r, im_q)
        };
        let (me, k2e, k4e) = (
            hermite::damping_matrix(1.0, 1.0),
            hermite::geometric_matrix(1.0),
            hermite::bending_matrix(1.0, 1.0),
        );
        for i in 0..=200 {
            let th = std::f64::consts::PI * i as f64 / 200.0;
            let c = th.cos();
            let (mp, mr, mq) = bloch(me, th);
            for (k, f, scale, trace, det) in [
                (
                    k4e,
                    2520.0,
                    1.0,
                    1888.0 + 632.0 * c,
                    (1.0 - c) * (45696.0 - 1344.0 * c),
                ),
                (
                    k2e,
                    42.0,
                    30.0,
                    880.0 + 380.0 * c,
                    (1.0 - c) * (6768.0 - 720.0 * c),
                ),
            ] {
                let (kp, kr, kq) = bloch(k, th);
                let (p, r, q) = (
                    scale * (f * mp - kp),
                    scale * (f * mr - kr),
                    scale * (f * mq - kq),
                );
                assert!((p + r - trace).abs() < 1e-9, "trace at {th}");
                assert!(
                    (p * r - q * q - det).abs() < 1e-9,
                    "det at {th}: {}",
                    p * r - q * q
                );
                assert!(p >= 0.0 && r >= 0.0 && det >= 0.0);
            }
        }
        assert_eq!(PLATE_RATE_FACTOR, 8568.0);
    }

    /// What: the numbering examples of the [`PlateModel`] docs. Reference: the docs.
    /// Tolerance: exact.
    #[test]
    fn documented_numbering_examples() {
        let (nx, ny) = (4, 3);
        let model = PlateModel::new(params(SS), nx, ny).unwrap();
        for (i, j) in [(1, 1), (3, 2), (2, 1)] {
            assert_eq!(
                model.node_height_index(i, j),
                Some((2 * j - 1) * 2 * nx + 2 * i - 1)
            );
        }
        assert_eq!(model.node_dof_index(0, 0, NodeDof::Twist), Some(0));
        assert_eq!(model.node_height_index(0, 2), None);
        assert_eq!(model.node_dof_index(nx, 1, NodeDof::SlopeY), None);
        assert!(model.node_dof_index(nx, 1, NodeDof::SlopeX).is_some());
        assert_eq!(model.node_height_index(nx + 1, 1), None);
        let model = PlateModel::new(params(PERIODIC), nx, ny).unwrap();
        assert_eq!(model.node_height_index(0, 0), Some(0));
        assert_eq!(model.node_height_index(1, 0), Some(4));
        assert_eq!(model.node_height_index(nx, ny), Some(0));
    }

    /// What: bad meshes are refused with the key named. Reference: [`PlateModel::new`]'s
    /// contract. Tolerance: exact.
    #[test]
    fn refuses_bad_meshes() {
        let name = |r: Result<PlateModel>| match r {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("expected a refusal, got {other:?}"),
        };
        assert_eq!(name(PlateModel::new(params(SS), 0, 3)), "nx");
        assert_eq!(name(PlateModel::new(params(SS), 3, 0)), "ny");
        assert_eq!(name(PlateModel::new(params(PERIODIC), 1, 3)), "nx");
        assert_eq!(name(PlateModel::new(params(PERIODIC), 3, 1)), "ny");
        assert_eq!(
            name(PlateModel::new(params(SS), 200, 200)),
            "elements (nx, ny)"
        );
        assert_eq!(
            name(PlateModel::new(params(SS), 1, 2_000_000)),
            "elements (nx, ny)"
        );
        let bad = MembraneParams {
            drag: -1.0,
            ..params(SS)
        };
        assert_eq!(name(PlateModel::new(bad, 2, 2)), "drag");
        assert_eq!(
            name(PlateModel::new(params(SS), usize::MAX, 2)),
            "elements (nx, ny)"
        );
        assert!(PlateModel::new(params(SS), 1, 1).is_ok());
        assert!(PlateModel::new(params(PERIODIC), 2, 2).is_ok());
    }
}
