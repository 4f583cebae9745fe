//! The von Kármán filament under imposed end-shortening (finite deflection), with the
//! axial displacement u as the fast variable (the paper's step i).
//!
//! Energy of the discretized filament (Hermite cubic w, and v in 3D; linear u):
//!
//! ```text
//! U = Σ_e ∫_e [ EA/2 (u'_e + s_e)² ] dx + ½ Σ_c w_cᵀ K w_c,   s_e = (1/2h_e) ∫_e (w'² + v'²) dx
//! ```
//!
//! The stretching term uses the element-mean von Kármán strain `u'_e + s_e` (u' is constant
//! on a linear element; the cubic w'² is replaced by its element mean), i.e. the stretching
//! energy is integrated with the element's mean strain. With this energy, axial
//! equilibrium at fixed w (step i, [`CompressedFilament::axial_equilibrium`]) gives a
//! uniform axial force, exactly as in the continuum:
//!
//! ```text
//! N = (EA/L)(−Δ + ½ ∫ w'² dx) = EA (s − ε),   s = wᵀG w/(2L),  ε = Δ/L,
//! ```
//!
//! and, u eliminated, `U(w) = ½ wᵀK w + (EA·L/2)(s − ε)²`, whose force on w is
//! `−∂U/∂w = −K w + F G w` with the compressive force `F = −N = EA(ε − s)`. The exact
//! equilibrium theory ([`crate::theory::compression`]) uses the same energy; the
//! integrators are in [`crate::dynamics::nonlinear`].

use crate::error::{Error, Result};
use crate::fem::banded::{LANES, Lanes};
use crate::fem::beam::BeamModel;
use crate::fem::hermite::{ElementMatrix, geometric_matrix};
use crate::theory::compression::GlobalConstraint;

/// The global constraint at an imposed strain, shared by the von Kármán filament and the
/// membrane under imposed projected area (issue #28): with the bending energy `½ xᵀK x`
/// and the normalized quadratic excess `s = xᵀG x/(2ℓ)` (stored length per length, or
/// excess area per area),
///
/// ```text
/// U = ½ xᵀK x + (S·ℓ/2)(s − ε)²,   F = S(ε − s),   −∂U/∂x = −K x + F G x,
/// ```
///
/// with the constraint's stiffness S (EA, or the area modulus K_A) and measure ℓ (L, or
/// A₀) ([`GlobalConstraint`], the same parameters as the exact theory's) and the imposed
/// strain ε (Δ/L, or `1 − A_p/A₀`). F is the compressive force (filament) or the
/// compressive stress `−σ` (membrane).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalStrain {
    /// S, ℓ, kT and the reference load (F_c0 or σ_c0).
    pub constraint: GlobalConstraint,
    /// Imposed strain ε (compression positive).
    pub strain: f64,
}

impl GlobalStrain {
    /// `s` from `2ℓs = xᵀG x`.
    pub fn excess(&self, two_l_s: f64) -> f64 {
        two_l_s / (2.0 * self.constraint.measure)
    }

    /// `F = S(ε − s)`.
    pub fn force(&self, s: f64) -> f64 {
        self.constraint.stiffness * (self.strain - s)
    }

    /// The constraint's energy `(S·ℓ/2)(s − ε)²`.
    pub fn energy(&self, s: f64) -> f64 {
        let (c, d) = (&self.constraint, s - self.strain);
        0.5 * c.stiffness * c.measure * d * d
    }
}

/// The filament with imposed end-shortening: model and energy.
#[derive(Debug, Clone)]
pub struct CompressedFilament {
    beam: BeamModel,
    components: usize,
    strain: f64,
    axial: AxialOperator,
}

/// What step (i) ([`CompressedFilament::axial_equilibrium_into`]) needs of the mesh and
/// EA alone, formed once: per element its length, geometric matrix and DOFs, the axial
/// stiffnesses `k_e = EA/h_e`, and the Thomas elimination of the tridiagonal system
/// (pivots and multipliers depend on `k` only). The same values, in the same order, as
/// forming them at every step.
#[derive(Debug, Clone)]
struct AxialOperator {
    h: Vec<f64>,
    g: Vec<ElementMatrix>,
    dofs: Vec<[Option<usize>; 4]>,
    k: Vec<f64>,
    /// Pivots of the eliminated system (interior nodes 1..N−1).
    diag: Vec<f64>,
    /// Multipliers `f_i = −k_i/diag_{i−1}` (`f_0` unused).
    mult: Vec<f64>,
}

impl AxialOperator {
    fn new(beam: &BeamModel) -> Self {
        let mesh = beam.mesh();
        let ne = mesh.n_elements();
        let ea = beam.params().stretch_rigidity;
        let h: Vec<f64> = (0..ne).map(|e| mesh.element_length(e)).collect();
        let k: Vec<f64> = h.iter().map(|h| ea / h).collect();
        let m = ne.saturating_sub(1);
        let mut diag: Vec<f64> = (0..m).map(|i| k[i] + k[i + 1]).collect();
        let mut mult = vec![0.0; m];
        for i in 1..m {
            let f = -k[i] / diag[i - 1];
            diag[i] -= f * -k[i];
            mult[i] = f;
        }
        AxialOperator {
            g: h.iter().map(|&h| geometric_matrix(h)).collect(),
            dofs: (0..ne).map(|e| beam.element_dofs(e)).collect(),
            h,
            k,
            diag,
            mult,
        }
    }
}

/// Work space of [`CompressedFilament::axial_equilibrium_into`]: the element-mean half
/// squared slopes, the tridiagonal system and its solution.
#[derive(Debug, Clone, Default)]
pub struct AxialScratch {
    s: Vec<f64>,
    /// Nodal axial displacements u_0 = 0, …, u_N = −Δ (after a solve).
    pub u: Vec<f64>,
    rhs: Vec<f64>,
    /// Axial force N per element (tension positive; after a solve).
    pub element_force: Vec<f64>,
}

/// Work space of [`CompressedFilament::axial_force_lanes`].
#[derive(Debug, Clone, Default)]
pub struct AxialLanes {
    s: Vec<Lanes>,
    u: Vec<Lanes>,
    rhs: Vec<Lanes>,
}

/// Result of the axial equilibrium solve (step i).
#[derive(Debug, Clone, PartialEq)]
pub struct AxialSolution {
    /// Nodal axial displacements u_0 = 0, …, u_N = −Δ.
    pub u: Vec<f64>,
    /// Axial force N per element (tension positive); uniform at equilibrium.
    pub element_force: Vec<f64>,
}

impl CompressedFilament {
    /// A filament on `beam` with `dims` = 2 (w) or 3 (w, v) and imposed nominal strain
    /// `strain` = Δ/L (compression positive).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for dims other than 2 or 3 or a non-finite strain.
    pub fn new(beam: BeamModel, dims: usize, strain: f64) -> Result<Self> {
        if dims != 2 && dims != 3 {
            return Err(Error::invalid("dims", dims, "2 or 3"));
        }
        if !strain.is_finite() {
            return Err(Error::invalid("strain", strain, "finite"));
        }
        Ok(CompressedFilament {
            axial: AxialOperator::new(&beam),
            beam,
            components: dims - 1,
            strain,
        })
    }

    /// The linear beam model (K, C, G).
    pub fn beam(&self) -> &BeamModel {
        &self.beam
    }

    /// Number of transverse components (1 in 2D, 2 in 3D).
    pub fn components(&self) -> usize {
        self.components
    }

    /// Imposed nominal strain ε = Δ/L.
    pub fn strain(&self) -> f64 {
        self.strain
    }

    /// The global constraint of this filament (S = EA, ℓ = L, F_c0 = π²EI/L²).
    pub fn global_strain(&self) -> GlobalStrain {
        let p = self.beam.params();
        GlobalStrain {
            constraint: GlobalConstraint {
                stiffness: p.stretch_rigidity,
                measure: p.length,
                kt: p.kt,
                reference_load: p.euler_load(),
                reference_strain: p.euler_strain(),
            },
            strain: self.strain,
        }
    }

    /// Stored length per unit length `s = Σ_c w_cᵀ G w_c/(2L) = (1/2L)∫(w'² + v'²) dx`.
    pub fn stored_length(&self, w: &[Vec<f64>]) -> f64 {
        let g = self.beam.geometric();
        w.iter().map(|c| g.quadratic_form(c)).sum::<f64>() / (2.0 * self.beam.params().length)
    }

    /// Compressive force `F = EA(ε − s)` for stored length `s`.
    pub fn compressive_force(&self, s: f64) -> f64 {
        self.beam.params().stretch_rigidity * (self.strain - s)
    }

    /// Total energy with u eliminated: `½ Σ wᵀK w + (EA·L/2)(s − ε)²`.
    pub fn energy(&self, w: &[Vec<f64>]) -> f64 {
        let p = self.beam.params();
        let k = self.beam.stiffness();
        let bend: f64 = w.iter().map(|c| 0.5 * k.quadratic_form(c)).sum();
        let d = self.stored_length(w) - self.strain;
        bend + 0.5 * p.stretch_rigidity * p.length * d * d
    }

    /// Internal force `−∂U/∂w = −K w + F G w` per component, written to `out`.
    pub fn internal_force(&self, w: &[Vec<f64>], out: &mut [Vec<f64>]) {
        let f = self.compressive_force(self.stored_length(w));
        let mut gw = vec![0.0; self.beam.n_dofs()];
        for (c, o) in w.iter().zip(out.iter_mut()) {
            self.beam.stiffness().mul_vec(c, o);
            self.beam.geometric().mul_vec(c, &mut gw);
            for (oi, gi) in o.iter_mut().zip(&gw) {
                *oi = -*oi + f * gi;
            }
        }
    }

    /// Step (i) of the paper: with w fixed, solve axial equilibrium for the linear-element
    /// axial displacement with u(0) = 0, u(L) = −Δ. Element e has energy
    /// `(EA h_e/2)(u'_e + s_e)²`; stationarity at interior nodes is the tridiagonal system
    /// `(EA/h_{e−1})(u_e − u_{e−1}) − (EA/h_e)(u_{e+1} − u_e) = EA(s_e − s_{e−1})` (node e), solved
    /// by the Thomas algorithm in O(N).
    pub fn axial_equilibrium(&self, w: &[Vec<f64>]) -> AxialSolution {
        let mut scratch = AxialScratch::default();
        self.axial_equilibrium_into(w, &mut scratch);
        AxialSolution {
            u: scratch.u,
            element_force: scratch.element_force,
        }
    }

    /// [`Self::axial_equilibrium`] into the buffers of `scratch` (the same arithmetic, so
    /// the same bits; allocation-free once the buffers have their size): the paper's
    /// explicit scheme solves step (i) at every step.
    pub fn axial_equilibrium_into(&self, w: &[Vec<f64>], scratch: &mut AxialScratch) {
        let op = &self.axial;
        let ne = op.h.len();
        let ea = self.beam.params().stretch_rigidity;
        let delta = self.strain * self.beam.mesh().length();
        let AxialScratch {
            s,
            u,
            rhs,
            element_force,
        } = scratch;
        // Element-mean half squared slope s_e.
        s.clear();
        s.extend(op.h.iter().zip(&op.g).zip(&op.dofs).map(|((&h, g), dofs)| {
            let mut acc = 0.0;
            for c in w {
                let loc = dofs.map(|d| d.map_or(0.0, |i| c[i]));
                for a in 0..4 {
                    for b in 0..4 {
                        acc += loc[a] * g[a][b] * loc[b];
                    }
                }
            }
            acc / (2.0 * h)
        }));
        u.clear();
        u.resize(ne + 1, 0.0);
        u[ne] = -delta;
        let m = ne - 1; // interior unknowns u_1..u_{N-1}
        if m > 0 {
            let (k, diag) = (&op.k, &op.diag);
            // Row i (node i+1): −k_i u_i + (k_i + k_{i+1}) u_{i+1} − k_{i+1} u_{i+2} = EA(s_{i+1} − s_i),
            // eliminated once ([`AxialOperator`]); here the right-hand side follows it.
            rhs.clear();
            rhs.extend((0..m).map(|i| ea * (s[i + 1] - s[i])));
            rhs[m - 1] += k[ne - 1] * u[ne];
            for i in 1..m {
                rhs[i] -= op.mult[i] * rhs[i - 1];
            }
            u[m] = rhs[m - 1] / diag[m - 1];
            for i in (1..m).rev() {
                u[i] = (rhs[i - 1] + k[i] * u[i + 1]) / diag[i - 1];
            }
        }
        element_force.clear();
        element_force.extend((0..ne).map(|e| ea * ((u[e + 1] - u[e]) / op.h[e] + s[e])));
    }

    /// The compressive force `F = −N_0` of step (i) for [`LANES`] states at once (`w[c][i][l]`:
    /// component `c`, DOF `i`, lane `l`), as the paper's explicit scheme takes it: per lane
    /// the floating-point operations of [`Self::axial_equilibrium_into`] that lead to the
    /// first element's force, in the same order, so every lane is bit-identical to it.
    ///
    /// Plain loops, inlined into its caller: called from code compiled for AVX, it runs in
    /// 4-wide vectors (no fused multiply-add, so with the same bits).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // lane loops indexed as the scalar code's entries
    pub fn axial_force_lanes(&self, w: &[Vec<Lanes>], scratch: &mut AxialLanes) -> Lanes {
        let op = &self.axial;
        let ne = op.h.len();
        let ea = self.beam.params().stretch_rigidity;
        let delta = self.strain * self.beam.mesh().length();
        let AxialLanes { s, u, rhs } = scratch;
        s.resize(ne, [0.0; LANES]);
        for e in 0..ne {
            let (g, dofs) = (&op.g[e], &op.dofs[e]);
            let mut acc = [0.0; LANES];
            for c in w {
                let loc = dofs.map(|d| d.map_or([0.0; LANES], |i| c[i]));
                for a in 0..4 {
                    for b in 0..4 {
                        for l in 0..LANES {
                            acc[l] += loc[a][l] * g[a][b] * loc[b][l];
                        }
                    }
                }
            }
            let two_h = 2.0 * op.h[e];
            for l in 0..LANES {
                s[e][l] = acc[l] / two_h;
            }
        }
        u.resize(ne + 1, [0.0; LANES]);
        u[0] = [0.0; LANES];
        u[ne] = [-delta; LANES];
        let m = ne - 1;
        if m > 0 {
            let (k, diag) = (&op.k, &op.diag);
            rhs.resize(m, [0.0; LANES]);
            for i in 0..m {
                for l in 0..LANES {
                    rhs[i][l] = ea * (s[i + 1][l] - s[i][l]);
                }
            }
            for l in 0..LANES {
                rhs[m - 1][l] += k[ne - 1] * u[ne][l];
            }
            for i in 1..m {
                for l in 0..LANES {
                    rhs[i][l] -= op.mult[i] * rhs[i - 1][l];
                }
            }
            for l in 0..LANES {
                u[m][l] = rhs[m - 1][l] / diag[m - 1];
            }
            for i in (1..m).rev() {
                for l in 0..LANES {
                    u[i][l] = (rhs[i - 1][l] + k[i] * u[i + 1][l]) / diag[i - 1];
                }
            }
        }
        let mut force = [0.0; LANES];
        for l in 0..LANES {
            force[l] = -(ea * ((u[1][l] - u[0][l]) / op.h[0] + s[0][l]));
        }
        force
    }

    /// The axial equilibrium residual of state `w` against the compressive force `force`
    /// a simulator used for it (u eliminated): step (i) solved for u at fixed w
    /// ([`Self::axial_equilibrium`], element-wise strains and the tridiagonal solve), and
    /// `max_e |N_e + F| / (EA (|ε| + s))`, the largest element force's departure from the
    /// simulator's uniform axial force `N = −F`, relative to the size of the terms that
    /// cancel in `N = EA(u'_e + s_e)`. At equilibrium every `N_e` equals `EA(s − ε)`
    /// exactly, so the residual is round-off unless the simulator's stored length (its
    /// assembled or modal G) or its force law departs from the von Kármán strain of
    /// the elements, or the axial solve is wrong.
    pub fn axial_residual(&self, w: &[Vec<f64>], force: f64) -> f64 {
        let ea = self.beam.params().stretch_rigidity;
        let sol = self.axial_equilibrium(w);
        let s = self.strain - force / ea;
        let scale = ea * (self.strain.abs() + s.abs());
        let worst = sol
            .element_force
            .iter()
            .fold(0.0f64, |m, n| m.max((n + force).abs()));
        if scale > 0.0 { worst / scale } else { worst }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::fem::mesh::Mesh;
    use crate::params::FilamentParams;
    use crate::rng::trajectory_rng;
    use rand::RngExt;
    use rand_distr::StandardNormal;

    pub(crate) const SEED: u64 = 20261126;

    pub(crate) fn model(dims: usize, strain_ratio: f64) -> CompressedFilament {
        let p = FilamentParams {
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            ..FilamentParams::default()
        };
        let beam = BeamModel::new(p, Mesh::graded(1.0, 7, 2.0).unwrap()).unwrap();
        CompressedFilament::new(beam, dims, strain_ratio * p.euler_strain()).unwrap()
    }

    pub(crate) fn random_state(m: &CompressedFilament, scale: f64, index: u64) -> Vec<Vec<f64>> {
        let mut rng = trajectory_rng(SEED, index);
        (0..m.components())
            .map(|_| {
                (0..m.beam().n_dofs())
                    .map(|_| scale * rng.sample::<f64, _>(StandardNormal))
                    .collect()
            })
            .collect()
    }

    /// Internal force against central differences of the energy (style: check
    /// derivatives numerically). Graded mesh, 2D and 3D, buckled and stretched states.
    /// Tolerance: central differences with step 1e-6·|w| have relative error O(1e-9).
    #[test]
    fn internal_force_is_minus_energy_gradient() {
        for dims in [2, 3] {
            for ratio in [0.0, 3.0, 10.0] {
                let m = model(dims, ratio);
                let w = random_state(&m, 0.02, dims as u64);
                let mut f = vec![vec![0.0; m.beam().n_dofs()]; m.components()];
                m.internal_force(&w, &mut f);
                let scale = f.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
                for c in 0..m.components() {
                    for i in 0..m.beam().n_dofs() {
                        let h = 1e-6 * (1.0 + w[c][i].abs());
                        let mut wp = w.clone();
                        let mut wm = w.clone();
                        wp[c][i] += h;
                        wm[c][i] -= h;
                        let fd = -(m.energy(&wp) - m.energy(&wm)) / (2.0 * h);
                        assert!(
                            (fd - f[c][i]).abs() < 1e-6 * scale,
                            "dims {dims} ratio {ratio} dof {i}: fd {fd} analytic {}",
                            f[c][i]
                        );
                    }
                }
            }
        }
    }

    /// Step (i): the axial solve gives a uniform axial force equal to the closed form
    /// EA(s − ε), meets u(0) = 0 and u(L) = −Δ, and the stretching energy evaluated with
    /// the solved u equals (EA L/2)(s − ε)² (tolerance: round-off, 1e-9 relative).
    #[test]
    fn axial_equilibrium_matches_closed_form() {
        for dims in [2, 3] {
            let m = model(dims, 4.0);
            let w = random_state(&m, 0.03, 10 + dims as u64);
            let sol = m.axial_equilibrium(&w);
            let n = -m.compressive_force(m.stored_length(&w));
            for f in &sol.element_force {
                assert!(
                    (f - n).abs() < 1e-9 * n.abs().max(1.0),
                    "element force {f} vs {n}"
                );
            }
            assert_eq!(sol.u[0], 0.0);
            assert!((sol.u[sol.u.len() - 1] + m.strain()).abs() < 1e-15);
        }
    }

    /// The residual is round-off (below 1e-12) for the force of the eliminated energy, in
    /// compression and tension, and finds a force computed with a stored length 1e-6 too
    /// large (relative), the size of a von Kármán strain error far below any statistical
    /// check's reach.
    #[test]
    fn axial_residual_is_round_off_and_finds_a_wrong_stored_length() {
        for dims in [2, 3] {
            for ratio in [0.0, 0.5, 4.0] {
                let m = model(dims, ratio);
                let w = random_state(&m, 0.03, 20 + dims as u64);
                let s = m.stored_length(&w);
                let r = m.axial_residual(&w, m.compressive_force(s));
                assert!(r < 1e-12, "dims {dims} ratio {ratio}: residual {r:e}");
                let wrong = m.axial_residual(&w, m.compressive_force(s * (1.0 + 1e-6)));
                assert!(
                    wrong > 1e-8,
                    "dims {dims} ratio {ratio}: residual {wrong:e}"
                );
            }
        }
    }
}
