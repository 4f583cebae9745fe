//! Random nodal forces: the paper's element-uniform load (eq. 5) and consistent noise.
//!
//! **Convention.** Over a step `Δt` the random nodal force on the free DOFs is
//! `F = sqrt(2kT/Δt)·ζ`, where the generator draws `ζ` with covariance `Σ_ζ`:
//!
//! - [`NoiseModel::Consistent`]: `Σ_ζ = C` (the damping matrix, including ξ), so
//!   `cov F = 2kT·C/Δt` exactly — the discrete fluctuation–dissipation relation.
//!   Drawn as `ζ = L z` with `C = LLᵀ` (banded Cholesky) and `z` iid `N(0, 1)`, one normal
//!   per free DOF.
//! - [`NoiseModel::ElementUniform`] (eq. 5): a uniform load `f_e` per element and step,
//!   `var f_e = 2ξkT/(h_e Δt)`, turned into nodal forces through `b_e = ∫ N dx`:
//!   `ζ = Σ_e sqrt(ξ/h_e)·z_e·b_e`, one normal per element, so
//!   `Σ_ζ = Σ_e (ξ/h_e) b_e b_eᵀ` and `cov F = Σ_e (2ξkT/(h_e Δt)) b_e b_eᵀ ≠ 2kT·C/Δt`.

use super::banded::BandedCholesky;
use super::beam::BeamModel;
use super::mesh::Mesh;
use super::modal::{generalized_modes, modal_noise_covariance};
use super::system::{ElementLoad, LinearSystem};
use crate::error::Result;
use crate::params::FilamentParams;
use nalgebra::DMatrix;
use rand::RngExt;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

/// Which random nodal force to apply (see the module docs for the covariances).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseModel {
    /// Uniform load per element and step, eq. (5): `Σ_ζ = Σ_e (ξ/h_e) b_e b_eᵀ`.
    ElementUniform,
    /// Consistent nodal noise: `Σ_ζ = C`, so `cov F = 2kT·C/Δt`.
    Consistent,
}

impl NoiseModel {
    /// Both models.
    pub const ALL: [NoiseModel; 2] = [NoiseModel::ElementUniform, NoiseModel::Consistent];

    /// The kebab-case name used in scene files and reports:
    /// `"element-uniform"` or `"consistent"`.
    pub fn name(&self) -> &'static str {
        match self {
            NoiseModel::ElementUniform => "element-uniform",
            NoiseModel::Consistent => "consistent",
        }
    }
}

impl std::fmt::Display for NoiseModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Debug, Clone)]
enum Source {
    Consistent(BandedCholesky),
    ElementUniform {
        /// `sqrt(ξ/|Ω_e|)` per element (the loads' amplitudes, gathered).
        amplitude: Vec<f64>,
        loads: Vec<ElementLoad>,
        /// The same loads by free DOF, for [`NoiseStream`].
        by_dof: DofLoads,
    },
}

/// The element loads gathered by free DOF: the contributions `(e, b_e[p])` to DOF `i` are
/// `entries[start[i]..start[i + 1]]`, in the order in which [`NoiseGenerator::draw`]
/// scatters them (ascending element, then local DOF).
#[derive(Debug, Clone)]
struct DofLoads {
    start: Vec<usize>,
    entries: Vec<(usize, f64)>,
    /// Number of elements (drawn in element order) that DOFs `0 … i` need: one more than
    /// the largest element loading any of them, and all elements for the last DOF.
    elements_needed: Vec<usize>,
}

impl DofLoads {
    fn new(n: usize, loads: &[ElementLoad]) -> Self {
        let mut elements_needed = Vec::with_capacity(n);
        let mut per_dof = vec![Vec::new(); n];
        for (e, l) in loads.iter().enumerate() {
            for (bv, d) in l.load.iter().zip(&l.dofs) {
                if let Some(i) = d {
                    per_dof[*i].push((e, *bv));
                }
            }
        }
        let mut start = Vec::with_capacity(n + 1);
        start.push(0);
        let mut entries = Vec::new();
        let mut needed = 0;
        for list in per_dof {
            needed = list.iter().fold(needed, |m, &(e, _)| m.max(e + 1));
            elements_needed.push(needed);
            entries.extend(list);
            start.push(entries.len());
        }
        if let Some(last) = elements_needed.last_mut() {
            *last = loads.len();
        }
        DofLoads {
            start,
            entries,
            elements_needed,
        }
    }
}

/// One standard normal `N(0, 1)` from `rng`, as every draw of this module takes it
/// (`rand_distr::StandardNormal`).
#[inline]
pub fn standard_normal<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    rng.sample(StandardNormal)
}

/// Draws the standardized noise vector `ζ` (covariance `Σ_ζ`) over the free DOFs of a
/// [`LinearSystem`]; the caller scales it by `sqrt(2kT/Δt)`.
#[derive(Debug, Clone)]
pub struct NoiseGenerator {
    model: NoiseModel,
    n: usize,
    source: Source,
}

impl NoiseGenerator {
    /// Prepares the generator (for [`NoiseModel::Consistent`], the banded Cholesky
    /// factor of `C`).
    ///
    /// # Errors
    /// [`crate::Error::Numerical`] if `C` is not positive definite.
    pub fn new(model: NoiseModel, system: &LinearSystem) -> Result<Self> {
        let n = system.n_dofs();
        let source = match model {
            NoiseModel::Consistent => Source::Consistent(system.damping().cholesky()?),
            NoiseModel::ElementUniform => {
                let loads = system.element_loads().to_vec();
                let amplitude: Vec<f64> = loads.iter().map(|l| l.amplitude).collect();
                let by_dof = DofLoads::new(n, &loads);
                Source::ElementUniform {
                    amplitude,
                    loads,
                    by_dof,
                }
            }
        };
        Ok(NoiseGenerator { model, n, source })
    }

    /// The noise model.
    pub fn model(&self) -> NoiseModel {
        self.model
    }

    /// For [`NoiseModel::Consistent`], the factor `L` of `C = LLᵀ` with which
    /// [`Self::draw`] forms `ζ = L z` from `z_0 … z_{n−1}` drawn in this order by
    /// [`standard_normal`]; `None` for [`NoiseModel::ElementUniform`]. For fused kernels
    /// such as [`BandedCholesky::solve_lower_product_noise`].
    pub fn lower_factor(&self) -> Option<&BandedCholesky> {
        match &self.source {
            Source::Consistent(l) => Some(l),
            Source::ElementUniform { .. } => None,
        }
    }

    /// Number of free DOFs (length of the drawn vector).
    pub fn n_dofs(&self) -> usize {
        self.n
    }

    /// Draws `ζ` into `out` in `O(n)`. Draw order is fixed: for
    /// [`NoiseModel::Consistent`] `z_0 … z_{n−1}` (free-DOF order), then `ζ = L z`; for
    /// [`NoiseModel::ElementUniform`] `z_0 … z_{N−1}` (element order),
    /// `ζ = Σ_e sqrt(ξ/h_e) z_e b_e`.
    ///
    /// # Panics
    /// If `out.len() != n_dofs()`.
    pub fn draw<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [f64]) {
        assert_eq!(out.len(), self.n, "NoiseGenerator::draw: wrong length");
        match &self.source {
            Source::Consistent(l) => {
                for v in out.iter_mut() {
                    *v = standard_normal(rng);
                }
                l.mul_lower_in_place(out);
            }
            Source::ElementUniform {
                amplitude, loads, ..
            } => {
                out.fill(0.0);
                for (a, l) in amplitude.iter().zip(loads) {
                    let f = a * standard_normal(rng);
                    for (bv, d) in l.load.iter().zip(&l.dofs) {
                        if let Some(i) = d {
                            out[*i] += f * bv;
                        }
                    }
                }
            }
        }
    }

    /// The same draw as [`Self::draw`], handed out one entry at a time: pull `ζ_0, ζ_1,
    /// …, ζ_{n−1}` with [`NoiseStream::next_value`], e.g. while a banded sweep consumes
    /// them. The random numbers are drawn as they are needed, in the order of
    /// [`Self::draw`], and every entry is bit-identical to that of [`Self::draw`] with the
    /// same generator state. After all `n` entries the generator has consumed exactly the
    /// draws of [`Self::draw`]; pulling fewer leaves the draw incomplete.
    ///
    /// `scratch` is resized to the length needed (no allocation once it has it).
    pub fn stream<'a, R: rand::Rng + ?Sized>(
        &'a self,
        rng: &'a mut R,
        scratch: &'a mut Vec<f64>,
    ) -> NoiseStream<'a, R> {
        let len = match &self.source {
            Source::Consistent(_) => self.n,
            Source::ElementUniform { amplitude, .. } => amplitude.len(),
        };
        scratch.resize(len, 0.0);
        NoiseStream {
            source: &self.source,
            n: self.n,
            rng,
            scratch,
            next: 0,
            drawn: 0,
        }
    }

    /// Standard normals consumed per draw: `n` (consistent) or `N` elements
    /// (element-uniform).
    pub fn draws_per_step(&self) -> usize {
        match &self.source {
            Source::Consistent(_) => self.n,
            Source::ElementUniform { amplitude, .. } => amplitude.len(),
        }
    }

    /// Dense `Σ_ζ` over the free DOFs: `C = L Lᵀ` (consistent) or
    /// `Σ_e (ξ/h_e) b_e b_eᵀ` (element-uniform). Built on demand (O(n²) memory), so that
    /// integrators, which only draw, stay O(n).
    pub fn covariance(&self) -> DMatrix<f64> {
        match &self.source {
            Source::Consistent(l) => {
                let l = l.to_dense_lower();
                &l * l.transpose()
            }
            Source::ElementUniform {
                amplitude, loads, ..
            } => {
                let mut cov = DMatrix::zeros(self.n, self.n);
                for (a, l) in amplitude.iter().zip(loads) {
                    let (b, dofs) = (&l.load, &l.dofs);
                    for p in 0..b.len() {
                        for q in 0..b.len() {
                            if let (Some(i), Some(j)) = (dofs[p], dofs[q]) {
                                cov[(i, j)] += a * a * b[p] * b[q];
                            }
                        }
                    }
                }
                cov
            }
        }
    }
}

/// One draw of `ζ` handed out entry by entry ([`NoiseGenerator::stream`]).
pub struct NoiseStream<'a, R: ?Sized> {
    source: &'a Source,
    n: usize,
    rng: &'a mut R,
    /// `z_k` drawn so far (consistent) or `sqrt(ξ/h_e)·z_e` per element drawn so far
    /// (element-uniform).
    scratch: &'a mut [f64],
    /// Index of the next entry.
    next: usize,
    /// Entries of `scratch` drawn so far.
    drawn: usize,
}

impl<R: rand::Rng + ?Sized> NoiseStream<'_, R> {
    /// Draws now what the entries `ζ_i`, `i < end`, need (consistent: `z_i`;
    /// element-uniform: every element up to the last one loading one of these DOFs, and
    /// for `end = n` every element), so that pulling them makes no calls to the
    /// generator. Optional: [`Self::next_value`] draws whatever is missing. The draws
    /// and their order are the same either way.
    #[inline]
    pub fn prepare(&mut self, end: usize) {
        if end == 0 {
            return;
        }
        let end = end.min(self.n);
        match self.source {
            Source::Consistent(_) => {
                while self.drawn < end {
                    self.scratch[self.drawn] = standard_normal(self.rng);
                    self.drawn += 1;
                }
            }
            Source::ElementUniform {
                amplitude, by_dof, ..
            } => {
                let needed = by_dof.elements_needed[end - 1];
                while self.drawn < needed {
                    let z = standard_normal(self.rng);
                    self.scratch[self.drawn] = amplitude[self.drawn] * z;
                    self.drawn += 1;
                }
            }
        }
    }

    /// The next entry `ζ_i` (`i = 0, 1, …`): for consistent noise, row `i` of `L z`
    /// ([`BandedCholesky::mul_lower_row`]); for element-uniform noise, the sum of the
    /// loads of the elements on DOF `i`. Draws what [`Self::prepare`] has not drawn yet
    /// (after `ζ_{n−1}`, also the elements loading no free DOF).
    ///
    /// # Panics
    /// If all `n` entries have been pulled already.
    #[inline]
    pub fn next_value(&mut self) -> f64 {
        self.prepare(self.next + 1);
        self.next_prepared()
    }

    /// [`Self::next_value`] for an entry that [`Self::prepare`] has drawn for: never
    /// calls the generator (so a sweep over prepared entries keeps its values in
    /// registers).
    ///
    /// # Panics
    /// If all `n` entries have been pulled already, or the entry was not prepared.
    #[inline]
    pub fn next_prepared(&mut self) -> f64 {
        let i = self.next;
        assert!(i < self.n, "NoiseStream: all {} entries drawn", self.n);
        self.next += 1;
        match self.source {
            Source::Consistent(l) => {
                assert!(i < self.drawn, "NoiseStream: entry {i} not prepared");
                l.mul_lower_row(self.scratch, i)
            }
            Source::ElementUniform { by_dof, .. } => {
                assert!(
                    by_dof.elements_needed[i] <= self.drawn,
                    "NoiseStream: entry {i} not prepared"
                );
                let mut s = 0.0;
                for &(e, bv) in &by_dof.entries[by_dof.start[i]..by_dof.start[i + 1]] {
                    s += self.scratch[e] * bv;
                }
                s
            }
        }
    }
}

impl<R: ?Sized> NoiseStream<'_, R> {
    /// Every entry at once, after [`NoiseStream::prepare`]`(n)`: `out(i, ζ_i)` for
    /// `i = 0, 1, …, n − 1`, the values of [`NoiseStream::next_prepared`] (the same sums in
    /// the same order) without its checks per entry; the stream is then exhausted.
    ///
    /// # Panics
    /// If an entry has been pulled already or not every entry is prepared.
    pub fn for_each_prepared(&mut self, mut out: impl FnMut(usize, f64)) {
        assert_eq!(self.next, 0, "NoiseStream: entries pulled already");
        match self.source {
            Source::Consistent(l) => {
                assert!(self.drawn >= self.n, "NoiseStream: not prepared");
                for i in 0..self.n {
                    out(i, l.mul_lower_row(self.scratch, i));
                }
            }
            Source::ElementUniform { by_dof, .. } => {
                let ready = self.n == 0 || by_dof.elements_needed[self.n - 1] <= self.drawn;
                assert!(ready, "NoiseStream: not prepared");
                for (i, w) in by_dof.start.windows(2).enumerate() {
                    let mut s = 0.0;
                    for &(e, bv) in &by_dof.entries[w[0]..w[1]] {
                        s += self.scratch[e] * bv;
                    }
                    out(i, s);
                }
            }
        }
        self.next = self.n;
    }
}

/// Stationary variance of the lowest `n_modes` discrete modes relative to equipartition
/// (`kT/λ_i` of the discrete modes) under the paper's element-uniform noise (eq. 5), on
/// uniform meshes of each element count in `elements`.
///
/// Pure theory from the exact discrete model, no simulation: with the generalized modes
/// `K φ = λ C φ` normalized to `ΦᵀCΦ = I`, the ratio of mode `i` is the diagonal entry
/// `(ΦᵀΣ_ζΦ)_ii` of the modal noise covariance
/// ([`super::modal::modal_noise_covariance`]) with `Σ_ζ = Σ_e (ξ/h_e) b_e b_eᵀ`. It is
/// the ratio under the continuous-time dynamics, so for any integrator whose
/// consistent-noise variance is exact; consistent noise (`Σ_ζ = C`) gives exactly 1.
///
/// Returns one row per entry of `elements`, each with `n_modes` ratios; a mode the mesh
/// does not have (`i ≥ 2N` free DOFs) is NaN.
///
/// # Errors
/// Invalid element count or filament parameters ([`Mesh::uniform`], [`BeamModel::new`]);
/// [`crate::Error::Numerical`] if the eigensolver fails.
pub fn element_uniform_variance_ratios(
    params: &FilamentParams,
    elements: &[usize],
    n_modes: usize,
) -> Result<Vec<Vec<f64>>> {
    elements
        .iter()
        .map(|&ne| {
            let beam = BeamModel::new(*params, Mesh::uniform(params.length, ne)?)?;
            let gm = generalized_modes(&beam)?;
            element_uniform_ratios(&beam, &gm, n_modes)
        })
        .collect()
}

/// [`element_uniform_variance_ratios`] of any [`LinearSystem`] with generalized modes
/// `modes` (`K φ = λ C φ`, `ΦᵀCΦ = I`): the diagonal `(ΦᵀΣ_ζΦ)_ii` of the modal noise
/// covariance of the element-uniform noise (eq. 5 per element measure) for the first
/// `n_modes` modes, NaN for a mode the system does not have.
///
/// # Errors
/// As [`NoiseGenerator::new`].
pub fn element_uniform_ratios(
    system: &LinearSystem,
    modes: &super::modal::GeneralizedModes,
    n_modes: usize,
) -> Result<Vec<f64>> {
    let sigma_zeta = NoiseGenerator::new(NoiseModel::ElementUniform, system)?.covariance();
    let sq = modal_noise_covariance(modes, &sigma_zeta);
    Ok((0..n_modes)
        .map(|i| {
            if i < modes.rates.len() {
                sq[(i, i)]
            } else {
                f64::NAN
            }
        })
        .collect())
}

/// The element-uniform variance ratio of one mode `phi` (nodal values over the free DOFs
/// of `system`, any normalization): `φᵀΣ_ζφ / φᵀCφ` with `Σ_ζ = Σ_e (ξ/|Ω_e|) b_e b_eᵀ`
/// (eq. 5 per element measure), in O(n), so that one mode of a large mesh needs no dense
/// modes. For a generalized mode it is the entry [`element_uniform_ratios`] gives (equal
/// up to rounding).
///
/// # Panics
/// If `phi` is not as long as the system has free DOFs.
pub fn element_uniform_mode_ratio(system: &LinearSystem, phi: &[f64]) -> f64 {
    assert_eq!(phi.len(), system.n_dofs(), "one value per free DOF");
    let loaded: f64 = system
        .element_loads()
        .iter()
        .map(|l| {
            let projection: f64 = l
                .load
                .iter()
                .zip(&l.dofs)
                .filter_map(|(b, d)| d.map(|i| b * phi[i]))
                .sum();
            (l.amplitude * projection).powi(2)
        })
        .sum();
    loaded / system.damping().quadratic_form(phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_serde() {
        assert_eq!(NoiseModel::ElementUniform.name(), "element-uniform");
        assert_eq!(NoiseModel::Consistent.name(), "consistent");
        let s = serde_json::to_string(&NoiseModel::ElementUniform).unwrap();
        assert_eq!(s, "\"element-uniform\"");
        let m: NoiseModel = serde_json::from_str("\"consistent\"").unwrap();
        assert_eq!(m, NoiseModel::Consistent);
        assert!(serde_json::from_str::<NoiseModel>("\"uniform\"").is_err());
    }

    /// The streamed draw (entry by entry, and all at once after `prepare`) equals the
    /// whole-vector draw bit for bit and leaves the generator in the same state, for both
    /// models, on meshes of 1 to 12 elements.
    #[test]
    fn stream_matches_draw_bit_for_bit() {
        use crate::rng::trajectory_rng;
        use rand::Rng;
        let params = FilamentParams::default();
        let mut scratch = Vec::new();
        for ne in 1..=12 {
            let beam = BeamModel::new(params, Mesh::uniform(params.length, ne).unwrap()).unwrap();
            for model in NoiseModel::ALL {
                let g = NoiseGenerator::new(model, &beam).unwrap();
                let n = g.n_dofs();
                let (mut r1, mut r2, mut r3) = (
                    trajectory_rng(11, ne as u64),
                    trajectory_rng(11, ne as u64),
                    trajectory_rng(11, ne as u64),
                );
                for _ in 0..3 {
                    let mut whole = vec![0.0; n];
                    g.draw(&mut r1, &mut whole);
                    let mut stream = g.stream(&mut r2, &mut scratch);
                    let streamed: Vec<f64> = (0..n).map(|_| stream.next_value()).collect();
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&streamed), bits(&whole), "{model} at {ne} elements");
                    let mut at_once = vec![f64::NAN; n];
                    let mut stream = g.stream(&mut r3, &mut scratch);
                    stream.prepare(n);
                    stream.for_each_prepared(|i, v| at_once[i] = v);
                    assert_eq!(bits(&at_once), bits(&whole), "{model} at {ne} elements");
                }
                let next = [r1.next_u64(), r2.next_u64(), r3.next_u64()];
                assert!(
                    next.iter().all(|&v| v == next[0]),
                    "{model} at {ne} elements"
                );
            }
        }
    }

    /// One mode's ratio equals the dense modal covariance's diagonal entry.
    #[test]
    fn one_mode_ratio_is_the_dense_diagonal() {
        let params = FilamentParams::default();
        let beam = BeamModel::new(params, Mesh::uniform(params.length, 7).unwrap()).unwrap();
        let gm = generalized_modes(&beam).unwrap();
        let dense = element_uniform_ratios(&beam, &gm, 5).unwrap();
        for (i, d) in dense.iter().enumerate() {
            let phi: Vec<f64> = gm.vectors.column(i).iter().map(|v| 3.0 * v).collect();
            let one = element_uniform_mode_ratio(&beam, &phi);
            assert!((one - d).abs() <= 1e-12 * d, "mode {i}: {one} vs {d}");
        }
    }

    #[test]
    fn element_uniform_ratios_below_one_and_converging() {
        let params = FilamentParams::default();
        let r = element_uniform_variance_ratios(&params, &[1, 10, 40], 3).unwrap();
        assert_eq!(r.len(), 3);
        // One hinged element has 2 free DOFs: the third mode does not exist.
        assert!(r[0][2].is_nan());
        for i in 0..3 {
            assert!(r[1][i] < 1.0 && r[1][i] > 0.5, "{:?}", r[1]);
            assert!(1.0 - r[2][i] < 1.0 - r[1][i], "{r:?}");
        }
    }
}
