//! The linear hinged beam: assembly of the Hermite-cubic matrices over the free DOFs.

use super::banded::SymBanded;
use super::hermite;
use super::mesh::Mesh;
use super::modal::symmetric_pencil;
use super::system::{ElementLoad, LinearSystem};
use crate::error::{Error, Result};
use crate::params::{End, Ends, FilamentParams};
use nalgebra::{DMatrix, SymmetricEigen};

/// Half-bandwidth of the assembled free-DOF matrices (DOFs of one element span at most
/// 4 consecutive free indices).
pub const BANDWIDTH: usize = 3;

/// The exact factor `c` in `λ_max = c·EI/(ξh⁴)` for a uniform hinged Hermite-cubic mesh
/// of any number of elements: `c = 2520`.
///
/// The top generalized eigenvector of `(K, C)` is `w_i = 0, θ_i = 1` at every node
/// (allowed by the hinged constraints). Per element, with `θ_a = θ_b = 1`,
/// the rotation rows give `K_e·x = (EI/h)[6, 6]` and `C_e·x = (ξh³/420)[1, 1]`
/// (interior nodes receive two such contributions; the deflection rows cancel between
/// neighbouring elements), so `λ = 6·420·EI/(ξh⁴) = 2520·EI/(ξh⁴)`. That it is the
/// largest follows from the Bloch dispersion relation of the periodic chain, whose upper
/// branch peaks at wavenumber 0 with this value; [`BeamModel::max_rate`] confirms it
/// numerically (see `tests/fem_model.rs`).
pub const UNIFORM_RATE_FACTOR: f64 = 2520.0;

/// The linear Euler–Bernoulli beam of eq. (2) discretized by Hermite cubics, one
/// transverse direction, hinged ends.
///
/// **DOF numbering.** Globally each node `i = 0..=N` carries `[w_i, θ_i]` (global
/// indices `2i, 2i+1`, `θ = w'`). The hinged constraints `w_0 = w_N = 0` remove two DOFs;
/// rotations stay free, so the natural condition `w'' = 0` holds weakly. The remaining
/// `n = 2N` free DOFs are numbered in node order:
///
/// ```text
/// free index: 0    1    2    3    4   …  2N−3     2N−2     2N−1
/// DOF:        θ_0  w_1  θ_1  w_2  θ_2 …  w_{N−1}  θ_{N−1}  θ_N
/// ```
///
/// i.e. `w_i ↦ 2i − 1` (`1 ≤ i ≤ N−1`), `θ_i ↦ 2i` (`i < N`), `θ_N ↦ 2N − 1`.
///
/// Matrices over the free DOFs (all symmetric banded, half-bandwidth 3):
/// stiffness `K = EI ∫ N''ᵀN'' dx`, damping `C = ξ ∫ NᵀN dx`, geometric
/// `G = ∫ N'ᵀN' dx`. The semi-discrete equation is `C ẇ = −K w + F`: the beam *is* a
/// [`LinearSystem`] (it dereferences to one: `K`, `C`, `kT`, the element loads
/// `b_e = ∫ N dx = [h/2, h²/12, h/2, −h²/12]` with amplitude `sqrt(ξ/h_e)`), with its
/// mesh, its geometric matrix and its DOF numbering besides.
#[derive(Debug, Clone)]
pub struct BeamModel {
    params: FilamentParams,
    mesh: Mesh,
    system: LinearSystem,
    geometric: SymBanded,
    dofs: Vec<[Option<usize>; 4]>,
    ends: Ends,
    /// The rigid modes `ψ_r` with `Cψ_r` ([`BeamModel::rigid_modes`]).
    rigid: Vec<(Vec<f64>, Vec<f64>)>,
}

impl std::ops::Deref for BeamModel {
    type Target = LinearSystem;

    fn deref(&self) -> &LinearSystem {
        &self.system
    }
}

/// Free index of global DOF `g` (`w_i = 2i`, `θ_i = 2i + 1`) for a mesh with `n_nodes`
/// nodes and ends `ends`: `None` where an end imposes it (hinged: `w`; clamped: `w` and
/// `θ`; free: nothing, [`crate::params::End`]) or `g` is beyond the last node; otherwise
/// `g` less the number of imposed DOFs before it, so the free DOFs keep node order.
fn free_index_with(ends: Ends, g: usize, n_nodes: usize) -> Option<usize> {
    let last = 2 * (n_nodes - 1);
    let fixed = |g: usize| {
        let (end, node_w) = match g {
            0 | 1 => (ends.left, 0),
            _ if g == last || g == last + 1 => (ends.right, last),
            _ => return false,
        };
        if g == node_w {
            end.fixes_deflection()
        } else {
            end.fixes_slope()
        }
    };
    if g > last + 1 || fixed(g) {
        return None;
    }
    let before = [0, 1, last, last + 1]
        .iter()
        .filter(|&&h| h < g && fixed(h))
        .count();
    Some(g - before)
}

impl BeamModel {
    /// Assembles `K`, `C`, `G` and the element load vectors.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the parameters are invalid or the mesh length
    /// differs from `params.length` (relative tolerance 1e-12).
    pub fn new(params: FilamentParams, mesh: Mesh) -> Result<Self> {
        Self::with_ends(params, mesh, Ends::HINGED)
    }

    /// [`BeamModel::new`] with any ends (issue #29): each end's essential conditions
    /// imposed on the end node's DOFs (hinged `w`, clamped `w` and `θ`, free none), the
    /// natural ones left to hold weakly. With a free end and no clamp, `K` is singular:
    /// its null space is the rigid motions `w = a + bx` that the ends allow
    /// ([`Ends::rigid_modes`]; [`BeamModel::rigid_modes`]).
    ///
    /// # Errors
    /// As [`BeamModel::new`].
    pub fn with_ends(params: FilamentParams, mesh: Mesh, ends: Ends) -> Result<Self> {
        let mut beam = Self::assemble(params, mesh, |g, n| free_index_with(ends, g, n))?;
        beam.ends = ends;
        beam.rigid = beam
            .rigid_basis()
            .into_iter()
            .map(|psi| {
                let mut c_psi = vec![0.0; psi.len()];
                beam.damping().mul_vec(&psi, &mut c_psi);
                (psi, c_psi)
            })
            .collect();
        Ok(beam)
    }

    /// [`BeamModel::new`] with the free-DOF numbering `free(g, n_nodes)` (global DOF `g`
    /// to its free index, `None` where constrained): the ends' one, [`free_index_with`], or a
    /// fault's ([`crate::fault`]).
    fn assemble(
        params: FilamentParams,
        mesh: Mesh,
        free: impl Fn(usize, usize) -> Option<usize>,
    ) -> Result<Self> {
        params.validate()?;
        let l = mesh.length();
        if (l - params.length).abs() > 1e-12 * params.length {
            return Err(Error::invalid(
                "mesh length",
                l,
                format!("= params.length = {}", params.length),
            ));
        }
        let n_nodes = mesh.n_nodes();
        let n_dofs = (0..2 * n_nodes)
            .filter(|&g| free(g, n_nodes).is_some())
            .count();
        let mut k = SymBanded::new(n_dofs, BANDWIDTH);
        let mut c = SymBanded::new(n_dofs, BANDWIDTH);
        let mut g = SymBanded::new(n_dofs, BANDWIDTH);
        let mut loads = Vec::with_capacity(mesh.n_elements());
        let mut element_dofs = Vec::with_capacity(mesh.n_elements());
        for e in 0..mesh.n_elements() {
            let h = mesh.element_length(e);
            let dofs: [Option<usize>; 4] = std::array::from_fn(|a| free(2 * e + a, n_nodes));
            let ke = hermite::bending_matrix(h, params.bending_rigidity);
            let ce = hermite::damping_matrix(h, params.drag);
            let ge = hermite::geometric_matrix(h);
            for a in 0..4 {
                for b in 0..=a {
                    if let (Some(i), Some(j)) = (dofs[a], dofs[b]) {
                        k.add(i, j, ke[a][b])?;
                        c.add(i, j, ce[a][b])?;
                        g.add(i, j, ge[a][b])?;
                    }
                }
            }
            loads.push(ElementLoad {
                amplitude: (params.drag / h).sqrt(),
                load: hermite::load_vector(h).to_vec(),
                dofs: dofs.to_vec(),
            });
            element_dofs.push(dofs);
        }
        Ok(BeamModel {
            system: LinearSystem::new(params.kt, k, c, loads)?,
            params,
            mesh,
            geometric: g,
            dofs: element_dofs,
            ends: Ends::HINGED,
            rigid: Vec::new(),
        })
    }

    /// A fault's model ([`crate::fault`]; test and `faults` builds only): the matrices
    /// assembled with the free-DOF numbering `free` instead of the hinged one (e.g. the
    /// hinge at x = L on the rotation). The node-index methods
    /// ([`Self::node_deflection_index`], [`Self::node_rotation_index`]) keep the hinged
    /// numbering; interpolation ([`Self::deflection_at`]) follows `free`.
    ///
    /// # Errors
    /// As [`BeamModel::new`].
    #[cfg(any(test, feature = "faults"))]
    pub(crate) fn with_free_numbering(
        params: FilamentParams,
        mesh: Mesh,
        free: impl Fn(usize, usize) -> Option<usize>,
    ) -> Result<Self> {
        Self::assemble(params, mesh, free)
    }

    /// A fault's model ([`crate::fault`]; test and `faults` builds only): this model with
    /// `K`, `C` and `G` multiplied by `k`, `c` and `g` (the element loads unchanged).
    ///
    /// # Errors
    /// As [`SymBanded::linear_combination`].
    #[cfg(any(test, feature = "faults"))]
    pub(crate) fn with_scaled_matrices(mut self, k: f64, c: f64, g: f64) -> Result<Self> {
        self.system.scale_matrices(k, c)?;
        self.geometric = SymBanded::linear_combination(g, &self.geometric, 0.0, &self.geometric)?;
        Ok(self)
    }

    /// The physical parameters.
    pub fn params(&self) -> &FilamentParams {
        &self.params
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// Geometric matrix `G = ∫ N'ᵀN' dx` over the free DOFs (`wᵀGw = ∫ w'² dx`).
    pub fn geometric(&self) -> &SymBanded {
        &self.geometric
    }

    /// Free indices of the local DOFs `[w_a, θ_a, w_b, θ_b]` of element `e`
    /// (`None` where constrained).
    ///
    /// # Panics
    /// If `e >= n_elements`.
    pub fn element_dofs(&self, e: usize) -> [Option<usize>; 4] {
        self.dofs[e]
    }

    /// The ends ([`BeamModel::with_ends`]; a fault's model: hinged).
    pub fn ends(&self) -> Ends {
        self.ends
    }

    /// Free index of the deflection `w_node` (`None` where an end imposes it and for
    /// `node > N`); hinged ends: `2·node − 1`.
    pub fn node_deflection_index(&self, node: usize) -> Option<usize> {
        free_index_with(self.ends, 2 * node, self.mesh.n_nodes())
    }

    /// Free index of the rotation `θ_node` (`None` where an end imposes it and for
    /// `node > N`); hinged ends: `2·node` for `node < N`, `2N − 1` for `node = N`.
    pub fn node_rotation_index(&self, node: usize) -> Option<usize> {
        free_index_with(self.ends, 2 * node + 1, self.mesh.n_nodes())
    }

    /// The rigid motions the ends allow ([`Ends::rigid_modes`]), as free-DOF vectors
    /// `ψ_r` (exact: Hermite cubics represent `w = a + bx` exactly, `Kψ_r = 0`),
    /// orthonormal in the damping metric (`ΨᵀCΨ = I`): free–free the translation
    /// `w = 1` and the rotation about the drag-weighted centre, hinged–free the rotation
    /// about the hinge `w = x − x_h`; empty otherwise.
    pub fn rigid_modes(&self) -> Vec<Vec<f64>> {
        self.rigid.iter().map(|(psi, _)| psi.clone()).collect()
    }

    /// The amplitudes `r_k = ψ_kᵀ C w` of the rigid modes in state `state` (each
    /// diffuses: `⟨Δr²⟩ = 2kT·t·ψᵀΣψ/ψᵀCψ` under noise of covariance Σ, `2kT·t` for the
    /// consistent noise), written to `out` (length [`Ends::rigid_modes`]).
    pub fn rigid_amplitudes(&self, state: &[f64], out: &mut [f64]) {
        for (o, (_, c_psi)) in out.iter_mut().zip(&self.rigid) {
            *o = rigid_amplitude(c_psi, state);
        }
    }

    /// The tangent-angle cosine amplitude of Gittes, Mickey, Nettleton & Howard (1993) as
    /// a linear functional of the state: the vector `p` with
    /// `pᵀw = √(2/L) ∫₀ᴸ θ(x) cos(nπx/L) dx`, θ = w_h′ the slope of the Hermite
    /// interpolant (small slopes). With no clamped end the bending energy
    /// `(EI/2)∫θ′²` is diagonal in these cosines, so in the continuum
    /// `⟨a_n²⟩ = kT L²/(EI n²π²)` exactly; the rigid motions (θ constant or 0) do not enter
    /// for n ≥ 1. Integrated per element by 5-point Gauss on 8 sub-intervals (the
    /// integrand is a quadratic times a cosine: relative error below 1e-12 for
    /// n ≤ 8·elements).
    pub fn tangent_cosine_functional(&self, n: usize) -> Vec<f64> {
        const SUB: usize = 8;
        let l = self.mesh.length();
        let k = n as f64 * std::f64::consts::PI / l;
        let norm = (2.0 / l).sqrt();
        let nodes = self.mesh.nodes();
        let mut p = vec![0.0; self.n_dofs()];
        for (e, dofs) in self.dofs.iter().enumerate() {
            let h = self.mesh.element_length(e);
            let hs = h / SUB as f64;
            for sub in 0..SUB {
                let centre = (sub as f64 + 0.5) * hs;
                for &(xi, wt) in &super::hermite::GAUSS5 {
                    let s = centre + 0.5 * hs * xi;
                    let weight = norm * 0.5 * hs * wt * (k * (nodes[e] + s)).cos();
                    let d = hermite::shape_d1(h, s);
                    for (a, dof) in dofs.iter().enumerate() {
                        if let Some(i) = dof {
                            p[*i] += weight * d[a];
                        }
                    }
                }
            }
        }
        p
    }

    /// The elastic deflection at `x`: [`BeamModel::deflection_at`] less the rigid
    /// motion `Σ_k r_k ψ_k(x)` (the C-orthogonal projection onto the elastic modes; the
    /// deflection itself where the ends allow no rigid motion). NaN outside `[0, L]`.
    ///
    /// # Panics
    /// If `state.len() != n_dofs()`.
    pub fn elastic_deflection_at(&self, state: &[f64], x: f64) -> f64 {
        let w = self.deflection_at(state, x);
        if self.rigid.is_empty() {
            return w;
        }
        self.rigid.iter().fold(w, |w, (psi, c_psi)| {
            w - rigid_amplitude(c_psi, state) * self.deflection_at(psi, x)
        })
    }

    /// [`BeamModel::elastic_deflection_at`] prepared for repeated use at `x`: the
    /// element's shape functions at `x` on its DOFs and the rigid modes' deflections
    /// there, computed once ([`DeflectionProbe::elastic`] then gives the same values,
    /// bit for bit, for any state).
    pub fn deflection_probe(&self, x: f64) -> DeflectionProbe {
        let weights = self.shape_weights(x).map(Iterator::collect);
        let rigid = self
            .rigid
            .iter()
            .map(|(psi, _)| self.deflection_at(psi, x))
            .collect();
        DeflectionProbe { weights, rigid }
    }

    /// The rigid basis before caching ([`BeamModel::rigid_modes`]).
    fn rigid_basis(&self) -> Vec<Vec<f64>> {
        let nodes = self.mesh.nodes();
        let line = |a: f64, b: f64| {
            let mut v = vec![0.0; self.n_dofs()];
            for (i, &x) in nodes.iter().enumerate() {
                if let Some(j) = self.node_deflection_index(i) {
                    v[j] = a + b * x;
                }
                if let Some(j) = self.node_rotation_index(i) {
                    v[j] = b;
                }
            }
            v
        };
        let l = self.mesh.length();
        let raw = match (self.ends.left, self.ends.right) {
            (End::Free, End::Free) => vec![line(1.0, 0.0), line(0.0, 1.0)],
            (End::Hinged, End::Free) => vec![line(0.0, 1.0)],
            (End::Free, End::Hinged) => vec![line(l, -1.0)],
            _ => vec![],
        };
        // Gram–Schmidt in the C metric.
        let c = self.damping();
        let dot = |a: &[f64], b: &[f64]| {
            let mut cb = vec![0.0; b.len()];
            c.mul_vec(b, &mut cb);
            a.iter().zip(&cb).map(|(x, y)| x * y).sum::<f64>()
        };
        let mut out: Vec<Vec<f64>> = Vec::new();
        for mut v in raw {
            for u in &out {
                let p = dot(u, &v);
                v.iter_mut().zip(u).for_each(|(x, y)| *x -= p * y);
            }
            let norm = dot(&v, &v).sqrt();
            v.iter_mut().for_each(|x| *x /= norm);
            out.push(v);
        }
        out
    }

    /// Hermite interpolation `w_h(x) = Σ_a N_a(x − x_e) d_a` on the element containing
    /// `x`. Returns NaN if `x` is outside `[0, L]` or not finite.
    ///
    /// # Panics
    /// If `state.len() != n_dofs()`.
    pub fn deflection_at(&self, state: &[f64], x: f64) -> f64 {
        assert_eq!(
            state.len(),
            self.n_dofs(),
            "deflection_at: wrong state length"
        );
        self.shape_weights(x)
            .map_or(f64::NAN, |w| w.map(|(i, na)| na * state[i]).sum())
    }

    /// (free DOF, shape function value) of the element holding `x`, in the element's DOF
    /// order ([`BeamModel::deflection_at`]'s terms); `None` outside `[0, L]`.
    fn shape_weights(&self, x: f64) -> Option<impl Iterator<Item = (usize, f64)> + '_> {
        let (e, s) = self.mesh.locate(x)?;
        let n = hermite::shape(self.mesh.element_length(e), s);
        Some((self.dofs[e].iter().zip(n)).filter_map(|(d, na)| d.map(|i| (i, na))))
    }

    /// Largest generalized eigenvalue `λ_max` of `K φ = λ C φ` (fastest decay rate of the
    /// semi-discrete system). For uniform meshes `λ_max = 2520·EI/(ξh⁴)`
    /// ([`UNIFORM_RATE_FACTOR`]); explicit Euler(–Maruyama) is stable only for
    /// `Δt < 2/λ_max` ([`BeamModel::explicit_euler_dt_limit`]).
    ///
    /// Computed by Sturm-sequence bisection ([`LinearSystem::max_rate_bisection`]),
    /// without any eigensolver: the number of eigenvalues below `σ` equals the number of
    /// negative pivots of the banded `LDLᵀ` of `K − σC` (Sylvester). The bracket starts at
    /// the Rayleigh quotient of the all-rotations vector (a lower bound) and Fried's element
    /// bound `max_e λ_max(K_e, C_e)` (an upper bound, checked by its count); bisection runs
    /// to a relative width of 1e-13. Cost `O(n)` per step, about 45 steps.
    ///
    /// # Errors
    /// [`Error::Numerical`] if the bracket cannot be established.
    pub fn max_rate(&self) -> Result<f64> {
        // upper bound: Fried's element eigenvalue bound, scaled by EI/(ξh⁴)
        let p = &self.params;
        let hmin = self.mesh.min_element_length();
        let hi = 1.001 * element_rate_factor()? * p.bending_rigidity / (p.drag * hmin.powi(4));
        // lower bound: Rayleigh quotient of the all-rotations vector
        let mut x = vec![0.0; self.n_dofs()];
        for node in 0..self.mesh.n_nodes() {
            if let Some(i) = self.node_rotation_index(node) {
                x[i] = 1.0;
            }
        }
        self.system.max_rate_bisection(hi, &x)
    }

    /// Explicit Euler(–Maruyama) stability limit `Δt < 2/λ_max` (the amplification
    /// factor `1 − λΔt` of the fastest mode must exceed −1).
    ///
    /// # Errors
    /// As [`BeamModel::max_rate`].
    pub fn explicit_euler_dt_limit(&self) -> Result<f64> {
        Ok(2.0 / self.max_rate()?)
    }
}

/// Largest eigenvalue of the element pencil `(K_e, C_e)` for `h = EI = ξ = 1`
/// (element eigenvalues scale as `EI/(ξh⁴)`).
fn element_rate_factor() -> Result<f64> {
    let ke = hermite::bending_matrix(1.0, 1.0);
    let ce = hermite::damping_matrix(1.0, 1.0);
    let k = DMatrix::from_fn(4, 4, |i, j| ke[i][j]);
    let c = DMatrix::from_fn(4, 4, |i, j| ce[i][j]);
    let (_, a) = symmetric_pencil(&k, c, "element_rate_factor")?;
    Ok(SymmetricEigen::new(a).eigenvalues.max())
}

/// The amplitude `r = (Cψ)ᵀw` of a rigid mode in `state`, from the mode's `c_psi = Cψ`
/// ([`BeamModel::elastic_deflection_at`], [`BeamModel::rigid_amplitudes`]).
fn rigid_amplitude(c_psi: &[f64], state: &[f64]) -> f64 {
    c_psi.iter().zip(state).map(|(a, b)| a * b).sum()
}

/// The deflection functional of a beam at one point ([`BeamModel::deflection_probe`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DeflectionProbe {
    /// (DOF, shape function value) of the element holding the point; `None` outside
    /// `[0, L]`.
    weights: Option<Vec<(usize, f64)>>,
    /// The rigid modes' deflections ψ_k(x).
    rigid: Vec<f64>,
}

impl DeflectionProbe {
    /// [`BeamModel::elastic_deflection_at`] of `state` at the probe's point, with `rigid`
    /// its rigid amplitudes ([`BeamModel::rigid_amplitudes`]): the same operations in the
    /// same order (NaN outside `[0, L]`).
    pub fn elastic(&self, state: &[f64], rigid: &[f64]) -> f64 {
        let w: f64 = match &self.weights {
            Some(weights) => weights.iter().map(|&(i, na)| na * state[i]).sum(),
            None => f64::NAN,
        };
        (rigid.iter().zip(&self.rigid)).fold(w, |w, (r, psi_x)| w - r * psi_x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The prepared probe gives `elastic_deflection_at` bit for bit, for every pair of
    /// ends (rigid motion projected out where there is some), on a graded mesh, at nodes,
    /// between them and outside [0, L] (NaN).
    #[test]
    fn deflection_probe_equals_elastic_deflection_bit_for_bit() {
        use rand::RngExt;
        let params = FilamentParams::default();
        let mut rng = crate::rng::trajectory_rng(20261206, 0);
        for ends in Ends::all() {
            let Ok(beam) = BeamModel::with_ends(params, Mesh::graded(1.0, 7, 0.3).unwrap(), ends)
            else {
                continue;
            };
            let state: Vec<f64> = (0..beam.n_dofs())
                .map(|_| rng.random::<f64>() - 0.5)
                .collect();
            let mut rigid = vec![0.0; ends.rigid_modes()];
            beam.rigid_amplitudes(&state, &mut rigid);
            let xs = beam
                .mesh()
                .nodes()
                .to_vec()
                .into_iter()
                .chain([0.123, 0.5, 0.987]);
            for x in xs {
                let p = beam.deflection_probe(x);
                let (a, b) = (
                    p.elastic(&state, &rigid),
                    beam.elastic_deflection_at(&state, x),
                );
                assert_eq!(a.to_bits(), b.to_bits(), "{ends:?} at {x}: {a} vs {b}");
            }
            assert!(beam.deflection_probe(1.5).elastic(&state, &rigid).is_nan());
        }
    }

    #[test]
    fn free_numbering() {
        // N = 3: nodes 0..=3, globals 0..8
        let f: Vec<Option<usize>> = (0..9)
            .map(|g| free_index_with(Ends::HINGED, g, 4))
            .collect();
        assert_eq!(
            f,
            vec![
                None,
                Some(0),
                Some(1),
                Some(2),
                Some(3),
                Some(4),
                None,
                Some(5),
                None
            ]
        );
    }

    #[test]
    fn element_factor_bounds_uniform_factor() {
        let c = element_rate_factor().unwrap();
        assert!(c >= UNIFORM_RATE_FACTOR, "{c}");
        assert!(c < 1e5);
    }
}
