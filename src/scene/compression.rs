//! Compression scenes: the force–strain curve of the paper's Fig. 2, simulated with the
//! finite-deflection filament ([`crate::dynamics::nonlinear`]) and judged against the exact
//! equilibrium theory of the same discretization ([`crate::theory::compression`]), with
//! the continuum theory beside it; and its relative for the membrane under imposed
//! projected area ([`AreaMembrane`], issue #28), whose compressive stress `F = −σ` is
//! recorded in units of `σ_c0 = κq²_min` exactly as the filament's force in units of F_c0.

use crate::dynamics::{
    Driver, Family, IntegratorKind, LaneOf, ModalMetropolis, NonlinearBatch, NonlinearState,
    Observer,
};
use crate::error::{Error, Result};
use crate::fem::area::AreaMembrane;
use crate::fem::banded::{BandedCholesky, LANES};
use crate::fem::beam::BeamModel;
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::fem::paired::PairedModes;
use crate::fem::plate_area::{AreaCutoff, AreaParams, AreaTheory};
use crate::fem::plate_modes::PlateModes;
use crate::params::FilamentParams;
use crate::rng::{TrajectoryRng, trajectory_rng};
use crate::scene::linear::{add_slope_squares, largest_rms_slope};
use crate::scene::{CompressionSpec, RunSpec, Scene, StepSearch};
use crate::stats;
use crate::theory::compression::{CompressionTheory, Dims, ForceDistribution, StoredLengthLaw};
use crate::{dynamics::nonlinear::NonlinearIntegrator, fem::vonkarman::CompressedFilament};
use rand::RngExt;
use rand_distr::StandardNormal;

/// Explicit modes of the continuum theory (the rest summed exactly as a Hurwitz-zeta series).
pub const CONTINUUM_MODES: usize = crate::theory::DEFAULT_CONTINUUM_MODES;

/// Theory of one compression scene, shared by its runs.
pub struct CompressionTheoryTable {
    /// Imposed strains ε/ε_c0.
    pub strain_ratios: Vec<f64>,
    /// Exact ⟨F⟩/F_c0 of the discretized filament (same elements and energy as the
    /// simulation).
    pub discrete: Vec<f64>,
    /// Exact ⟨F⟩/F_c0 of the continuum.
    pub continuum: Vec<f64>,
    /// Exact law of F at the distribution strains (None elsewhere).
    pub distributions: Vec<Option<ForceDistribution>>,
    /// The exact curves on a fine grid for figures: (ε/ε_c0, discrete, continuum).
    pub curve: Vec<(f64, f64, f64)>,
    /// The Gaussian mean-field force ⟨F⟩/F_c0 ([`CompressionTheory::mean_field_force`],
    /// not exact) at the strains of `curve`, (discretized filament, continuum): the
    /// textbook approximation, accurate in tension, below the buckling load at every
    /// strain.
    pub mean_field: Vec<(f64, f64)>,
}

/// Points of the fine theory curve drawn in the figures.
const CURVE_POINTS: usize = 81;

impl CompressionTheoryTable {
    /// Computes the theory for `scene`.
    ///
    /// # Errors
    /// Numerical failures of the theory; a membrane scene ([`Scene::refuse_membrane`],
    /// exit 2: compression is a filament's).
    pub fn new(scene: &Scene, spec: &CompressionSpec) -> Result<Self> {
        let (disc, cont) = theories(scene, spec)?;
        let strain_unit = disc.constraint().reference_strain;
        let mut discrete = Vec::new();
        let mut continuum = Vec::new();
        let mut distributions = Vec::new();
        for &r in &spec.strain_ratios {
            discrete.push(disc.force_ratio(r)?);
            continuum.push(cont.force_ratio(r)?);
            let j = spec.distribution_strain_ratios.iter().position(|&d| d == r);
            distributions.push(match j {
                Some(j) => Some(
                    disc.force_distribution(r * strain_unit)
                        .map_err(|e| distribution_error(scene, j, r, e))?,
                ),
                None => None,
            });
        }
        let lo = spec
            .strain_ratios
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = spec
            .strain_ratios
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let curve: Vec<(f64, f64, f64)> = (0..CURVE_POINTS)
            .map(|k| {
                let r = lo + (hi - lo) * k as f64 / (CURVE_POINTS - 1) as f64;
                Ok((r, disc.force_ratio(r)?, cont.force_ratio(r)?))
            })
            .collect::<Result<_>>()?;
        let mean_field = curve
            .iter()
            .map(|c| {
                let e = c.0 * strain_unit;
                let load = disc.constraint().reference_load;
                let f = |t: &CompressionTheory| Ok(t.mean_field_force(e)? / load);
                Ok((f(&disc)?, f(&cont)?))
            })
            .collect::<Result<_>>()?;
        Ok(CompressionTheoryTable {
            strain_ratios: spec.strain_ratios.clone(),
            discrete,
            continuum,
            distributions,
            curve,
            mean_field,
        })
    }

    /// Whether the strains reach into tension (a negative ratio): the scene's force–strain
    /// figure then also draws the Gaussian mean field and the athermal rod, and the scene
    /// stays out of the paper's Fig. 2 (imposed compression, `fig2.svg`).
    pub fn reaches_tension(&self) -> bool {
        self.strain_ratios.iter().any(|&r| r < 0.0)
    }
}

/// A failure of the exact law of F at distribution strain `j` (ratio `r`) as the key of
/// the scene that asked for it (exit 2): where the law's Fourier series is out of reach
/// (F too narrow at a small stretch rigidity) the strain can only be left out of the list.
fn distribution_error(scene: &Scene, j: usize, r: f64, e: Error) -> Error {
    match e {
        Error::Numerical { routine, detail } => Error::Scene {
            file: scene.path.clone(),
            key: format!("compression.distribution_strain_ratios[{j}]"),
            message: format!(
                "asks for the exact distribution of F at strain ratio {r}, which cannot be computed for this filament ({routine}: {detail}); leave this strain out of distribution_strain_ratios (its mean force is still checked)"
            ),
        },
        other => other,
    }
}

/// The exact theories of a compression scene's object, `(discrete, continuum)`: the
/// filament's of its Hermite-cubic mesh and of the continuum; a membrane under imposed
/// projected area's of its BFS mesh and of the continuum at the mesh's mode cutoff
/// ([`AreaCutoff::Lattice`]: the same lattice indices as the mesh's acoustic modes).
fn theories(
    scene: &Scene,
    spec: &CompressionSpec,
) -> Result<(CompressionTheory, CompressionTheory)> {
    let Some(mp) = scene.membrane else {
        let p = scene.filament;
        let dims = Dims::from_u32(scene.dims as u32)?;
        let disc = CompressionTheory::new(
            &p,
            StoredLengthLaw::discrete(&p, dims, scene.mesh.elements)?,
        )?;
        let cont =
            CompressionTheory::new(&p, StoredLengthLaw::continuum(&p, dims, CONTINUUM_MODES)?)?;
        return Ok((disc, cont));
    };
    let k_a = spec.area_modulus.ok_or_else(|| {
        Error::invalid(
            "compression.area_modulus",
            "nothing",
            "the area modulus K_A",
        )
    })?;
    let params = AreaParams::from_membrane(&mp, k_a);
    let (nx, ny) = (scene.mesh.elements, scene.mesh.elements_along_y());
    let disc = AreaTheory::discrete(&params, nx, ny)?;
    let cont = AreaTheory::continuum(&params, AreaCutoff::Lattice { nx, ny })?;
    Ok((disc.theory().clone(), cont.theory().clone()))
}

/// Samples between two evaluations of the axial equilibrium residual
/// ([`CompressedFilament::axial_residual`], O(n²) on the modal chain): the first sample of
/// a trajectory and every 20th after it, about 40 states per trajectory at the quick
/// budget, so that the residual check costs a few per cent of the chain.
pub const AXIAL_RESIDUAL_EVERY: usize = 20;

/// The largest axial equilibrium residual of a trajectory and the number of states it
/// was evaluated at.
fn note_axial_residual(rec: &mut ForceRecord, residual: f64) {
    let worst = rec.axial_residual.unwrap_or(0.0);
    // NaN (a non-finite state) is kept: it fails the check.
    rec.axial_residual = Some(if residual.is_nan() || residual > worst {
        residual
    } else {
        worst
    });
    rec.axial_states += 1;
}

/// Samples between two probes of the proposal's drift ([`ModalMetropolis::drift_residual`],
/// about ten steps' work): the first sample of a trajectory and every 100th after it.
pub const DRIFT_PROBE_EVERY: usize = 100;

/// Probes the proposal's drift of `chain` at its current state into `rec` (the largest
/// residual and the number of states probed; a state where no proposal can be made is not
/// counted, NaN is kept and fails the check).
fn note_drift(rec: &mut ForceRecord, chain: &ModalMetropolis<'_>) {
    if let Some(r) = chain.drift_residual() {
        let worst = rec.drift_residual.unwrap_or(0.0);
        rec.drift_residual = Some(if r.is_nan() || r > worst { r } else { worst });
        rec.drift_states += 1;
    }
}

/// The observer of [`CompressionRun::simulate`]: F/F_c0 and the nodal slopes at every
/// sample, the axial equilibrium residual every [`AXIAL_RESIDUAL_EVERY`] samples, the
/// Metropolis counts at the end.
struct ForceRecorder<'m> {
    model: &'m CompressedFilament,
    euler_load: f64,
    rec: ForceRecord,
    /// Whether to record [`ForceRecord::buckled_mode`].
    buckled_mode: bool,
    /// A lane's state, copied out of a [`NonlinearBatch`] at each sample.
    lane: Vec<Vec<f64>>,
}

impl ForceRecorder<'_> {
    /// The observer of one trajectory of `model` (one strain of `run`) with step plan
    /// `plan`.
    fn new<'m>(
        run: &CompressionRun,
        model: &'m CompressedFilament,
        plan: StepPlan,
        sampled_steps: u64,
    ) -> ForceRecorder<'m> {
        ForceRecorder {
            model,
            euler_load: run.euler_load,
            rec: ForceRecord {
                force_ratio: Vec::with_capacity((sampled_steps / plan.sample_every) as usize),
                slope_squares: vec![0.0; model.beam().mesh().n_nodes()],
                ..Default::default()
            },
            buckled_mode: run.buckled_mode,
            lane: Vec::new(),
        }
    }

    /// Records the sample `w`.
    fn record(&mut self, w: &[Vec<f64>]) {
        let model = self.model;
        let f = model.compressive_force(model.stored_length(w));
        self.rec.force_ratio.push(f / self.euler_load);
        if self.buckled_mode {
            self.rec
                .buckled_mode
                .push(buckled_mode_square(model.beam(), w));
        }
        if self.rec.slope_samples.is_multiple_of(AXIAL_RESIDUAL_EVERY) {
            note_axial_residual(&mut self.rec, model.axial_residual(w, f));
        }
        for c in w {
            add_slope_squares(model.beam(), c, &mut self.rec.slope_squares);
        }
        self.rec.slope_samples += 1;
    }
}

impl Observer<NonlinearState<NonlinearIntegrator<'_>>> for ForceRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, state: &NonlinearState<NonlinearIntegrator<'_>>) {
        self.record(&state.w);
    }

    fn on_finish(&mut self, _: usize, state: &NonlinearState<NonlinearIntegrator<'_>>) {
        self.rec.proposed = state.integrator.proposed;
        self.rec.accepted = state.integrator.accepted;
    }
}

/// A lane of a batch of θ-scheme trajectories: the θ-schemes propose nothing, so the
/// counts stay 0 as [`NonlinearIntegrator`]'s.
impl Observer<LaneOf<'_, NonlinearBatch<'_>>> for ForceRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, view: &LaneOf<'_, NonlinearBatch<'_>>) {
        let mut w = std::mem::take(&mut self.lane);
        view.batch.lane_state(view.lane, &mut w);
        self.record(&w);
        self.lane = w;
    }
}

/// The observer of [`CompressionRun::simulate_modal`]: F/F_c0 and the squared rotation
/// amplitude per wavenumber at every sample, the axial equilibrium residual of the nodal
/// state every [`AXIAL_RESIDUAL_EVERY`] samples (the chain itself never forms u).
struct ModalForceRecorder<'m> {
    model: &'m CompressedFilament,
    euler_load: f64,
    rec: ForceRecord,
    block_squares: Vec<f64>,
    /// Whether to record [`ForceRecord::buckled_mode`].
    buckled_mode: bool,
}

impl Observer<ModalMetropolis<'_>> for ModalForceRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, chain: &ModalMetropolis<'_>) {
        self.rec.force_ratio.push(chain.force() / self.euler_load);
        if self.buckled_mode {
            let w = chain.nodal_state();
            self.rec
                .buckled_mode
                .push(buckled_mode_square(self.model.beam(), &w));
        }
        chain.add_block_rotation_squares(&mut self.block_squares);
        if self.rec.slope_samples.is_multiple_of(AXIAL_RESIDUAL_EVERY) {
            let r = self
                .model
                .axial_residual(&chain.nodal_state(), chain.force());
            note_axial_residual(&mut self.rec, r);
        }
        if self.rec.slope_samples.is_multiple_of(DRIFT_PROBE_EVERY) {
            note_drift(&mut self.rec, chain);
        }
        self.rec.slope_samples += 1;
    }
}

/// The observer of a membrane's chain: `F/σ_c0 = −σ/σ_c0` at every sample, the proposal's
/// drift every [`DRIFT_PROBE_EVERY`] samples (in `drift`, whose force series stays empty).
struct StressRecorder {
    unit: f64,
    force_ratio: Vec<f64>,
    drift: ForceRecord,
}

impl Observer<ModalMetropolis<'_>> for StressRecorder {
    fn on_sample(&mut self, _: usize, _: u64, chain: &ModalMetropolis<'_>) {
        if self.force_ratio.len().is_multiple_of(DRIFT_PROBE_EVERY) {
            note_drift(&mut self.drift, chain);
        }
        self.force_ratio.push(chain.force() / self.unit);
    }
}

/// Sampled steps of each probe trajectory of a step search ([`CompressionRun::search_step`]),
/// after its burn-in: with 16 trajectories, about 800 proposals, so the acceptance rate
/// is known to about ±0.02.
pub const PROBE_STEPS: u64 = 50;

/// The outcome of a step search at one strain: the chosen step and every candidate probed
/// with its acceptance rate, `(dt_tau1, acceptance)`, largest step first.
#[derive(Debug, Clone, PartialEq)]
pub struct StepChoice {
    /// The chosen step, in units of τ1.
    pub dt_tau1: f64,
    /// The candidates probed, `(dt_tau1, acceptance rate)`.
    pub tried: Vec<(f64, f64)>,
}

/// The time step of one strain of a run, with its burn-in and sampling cadence in steps.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StepPlan {
    dt: f64,
    /// The step of the burn-in (the scene's `dt_tau1`; see [`CompressionRun::with_steps`]).
    burn_in_dt: f64,
    /// Burn-in steps at `burn_in_dt`.
    burn_in_steps: u64,
    sample_every: u64,
}

impl StepPlan {
    /// Step `dt`, burn-in and sampling interval in physical time (rounded to whole steps,
    /// at least one step between samples); the burn-in at the step `burn_in_dt`.
    fn new(dt: f64, burn_in: f64, sample_interval: f64, burn_in_dt: f64) -> Self {
        StepPlan {
            dt,
            burn_in_dt,
            burn_in_steps: (burn_in / burn_in_dt).round() as u64,
            sample_every: ((sample_interval / dt).round() as u64).max(1),
        }
    }

    /// Steps of a sampled duration (physical time): a whole number of sampling intervals,
    /// at least one.
    fn sampled_steps(&self, duration: f64) -> u64 {
        let n = (duration / self.dt).round() as u64;
        (n / self.sample_every).max(1) * self.sample_every
    }
}

/// One run (integrator and time step) of a compression scene.
#[derive(Debug, Clone)]
pub struct CompressionRun {
    /// The run specification.
    pub spec: RunSpec,
    /// Time step (the scene's `dt_tau1`; a step search may choose other steps per strain,
    /// see [`Self::with_steps`]).
    pub dt: f64,
    /// Burn-in steps at each strain (at `dt`).
    pub burn_in_steps: u64,
    /// Steps between samples of F (at `dt`).
    pub sample_every: u64,
    /// The step, burn-in and sampling cadence of each strain.
    plans: Vec<StepPlan>,
    /// Burn-in and sampling interval (physical time), for [`Self::with_steps`].
    burn_in: f64,
    sample_interval: f64,
    /// The simulated object at each strain.
    object: Strained,
    /// Euler buckling load F_c0 (the unit of the recorded forces); a membrane's buckling
    /// stress σ_c0.
    pub euler_load: f64,
    /// The scene's filament, its dims and element count (a membrane: `None`): the true
    /// parameters, whatever fault the chain's model carries, for [`Self::scheme_band`].
    filament: Option<(FilamentParams, Dims, usize)>,
    /// Whether trajectories record the buckled mode's squared amplitude
    /// ([`Self::with_buckled_mode`]).
    buckled_mode: bool,
    /// The injected fault's factor on the modal chain's proposal force
    /// ([`crate::fault::FaultKind::ProposalForce`]).
    #[cfg(any(test, feature = "faults"))]
    proposal_force_factor: f64,
}

/// The object of a compression run at each strain.
#[derive(Debug, Clone)]
enum Strained {
    Filament {
        models: Vec<CompressedFilament>,
        /// Cholesky factor of the bending stiffness K, for the equilibrium start.
        stiffness: BandedCholesky,
        /// The paired modal form, for `metropolis-crank-nicolson` on a uniform mesh
        /// (always, in the scenes): [`CompressionRun::simulate`] then runs
        /// [`ModalMetropolis`].
        paired: Option<PairedModes>,
    },
    /// The membrane under imposed projected area, always in its plate's modes.
    Membrane {
        models: Vec<AreaMembrane>,
        modes: Box<PlateModes>,
    },
}

/// What one trajectory at one strain recorded.
#[derive(Debug, Clone, Default)]
pub struct ForceRecord {
    /// F/F_c0 every `sample_every` steps after burn-in.
    pub force_ratio: Vec<f64>,
    /// Metropolis proposals and acceptances (0 for θ-schemes); on a uniform mesh (the
    /// modal chain) those of the sampled steps only, without the burn-in.
    pub proposed: u64,
    /// Accepted proposals.
    pub accepted: u64,
    /// Sum over the samples of θ² at each node (slope w', summed over components).
    pub slope_squares: Vec<f64>,
    /// Number of samples in `slope_squares`.
    pub slope_samples: usize,
    /// The largest axial equilibrium residual over the states evaluated
    /// ([`CompressedFilament::axial_residual`]); `None` if none was (data from another
    /// program).
    pub axial_residual: Option<f64>,
    /// Number of states the residual was evaluated at.
    pub axial_states: u64,
    /// The largest relative difference between the Metropolis proposal's drift and the
    /// gradient of the chain's energy over the states probed
    /// ([`ModalMetropolis::drift_residual`]); `None` if none was (the banded chain, data
    /// from another program).
    pub drift_residual: Option<f64>,
    /// Number of states the drift was probed at.
    pub drift_states: u64,
    /// The squared amplitude of the buckled mode at every sample, `A² = Σ_c s_c²` over the
    /// transverse components, `s_c = (2/N) Σ_j w_c(x_j) sin(πx_j/L)` the first discrete
    /// sine coefficient of the nodal deflections (units of L²); empty unless the run
    /// records it ([`CompressionRun::with_buckled_mode`]: the dynamics comparison of
    /// [`crate::studies::fig2_schemes`]).
    pub buckled_mode: Vec<f64>,
}

/// What a coupled pair of trajectories recorded ([`CompressionRun::simulate_coupled`]):
/// sums over its coarse steps of F/F_c0 on the coarse and on the fine trajectory and of
/// their difference.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CoupledRecord {
    /// Σ F/F_c0 of the coarse trajectory (step Δt).
    pub coarse_sum: f64,
    /// Σ F/F_c0 of the fine trajectory (step Δt/2), after every second fine step.
    pub fine_sum: f64,
    /// Σ (F_coarse − F_fine)/F_c0, summed as differences.
    pub difference_sum: f64,
    /// Coarse steps summed.
    pub steps: u64,
}

/// The squared amplitude of the buckled mode of the nodal state `w` (one vector per
/// transverse component): `Σ_c s_c²`, `s_c = (2/N) Σ_{j=1}^{N−1} w_c(x_j) sin(πj/N)` on
/// `N` uniform elements (a hinged filament's first sine; on the paired modal form
/// exactly the deflection part of the wavenumber-1 block, [`crate::fem::paired`]).
pub fn buckled_mode_square(beam: &crate::fem::beam::BeamModel, w: &[Vec<f64>]) -> f64 {
    let n = beam.mesh().n_nodes() - 1;
    w.iter()
        .map(|c| {
            let s: f64 = (1..n)
                .filter_map(|j| {
                    beam.node_deflection_index(j)
                        .map(|i| c[i] * (std::f64::consts::PI * j as f64 / n as f64).sin())
                })
                .sum::<f64>()
                * 2.0
                / n as f64;
            s * s
        })
        .sum()
}

impl CompressionRun {
    /// Prepares run `spec` of compression scene `scene`.
    ///
    /// # Errors
    /// Invalid integrator or a time step above an explicit stability limit, a membrane
    /// scene ([`Scene::refuse_membrane`]) (exit 2).
    pub fn prepare(scene: &Scene, comp: &CompressionSpec, spec: &RunSpec) -> Result<Self> {
        if let Some(mp) = scene.membrane {
            return Self::prepare_membrane(scene, mp, comp, spec);
        }
        let p = scene.filament;
        let tau1 = p.tau1();
        let dt = spec.dt_tau1 * tau1;
        let beam = BeamModel::new(p, Mesh::uniform(p.length, scene.mesh.elements)?)?;
        #[cfg(any(test, feature = "faults"))]
        let beam = crate::fault::compression_model(scene.fault, beam)?;
        let models: Vec<CompressedFilament> = comp
            .strain_ratios
            .iter()
            .map(|r| CompressedFilament::new(beam.clone(), scene.dims, r * p.euler_strain()))
            .collect::<Result<_>>()?;
        // Fails early (exit 2) for a bad integrator or time step.
        NonlinearIntegrator::new(&models[0], spec.integrator, spec.noise, dt)?;
        let (burn_in, sample_interval) = (comp.burn_in_tau1 * tau1, comp.sample_every_tau1 * tau1);
        let plan = StepPlan::new(dt, burn_in, sample_interval, dt);
        Ok(CompressionRun {
            spec: spec.clone(),
            dt,
            burn_in_steps: plan.burn_in_steps,
            sample_every: plan.sample_every,
            plans: vec![plan; models.len()],
            burn_in,
            sample_interval,
            object: Strained::Filament {
                stiffness: beam.stiffness().cholesky()?,
                paired: match spec.integrator.family() {
                    Family::Metropolis => PairedModes::new(&beam),
                    Family::Theta(_) | Family::ExactModal => None,
                },
                models,
            },
            euler_load: p.euler_load(),
            filament: Some((p, Dims::from_u32(scene.dims as u32)?, scene.mesh.elements)),
            buckled_mode: false,
            #[cfg(any(test, feature = "faults"))]
            proposal_force_factor: crate::fault::proposal_force_factor(scene.fault),
        })
    }

    /// [`Self::prepare`] for the membrane `mp` under imposed projected area
    /// (`compression.area_modulus`): a BFS plate at zero tension, one [`AreaMembrane`] per
    /// strain `ε = r·ε_c0`, `ε_c0 = σ_c0/K_A`, and the plate's modes.
    fn prepare_membrane(
        scene: &Scene,
        mp: crate::spectral::membrane::MembraneParams,
        comp: &CompressionSpec,
        spec: &RunSpec,
    ) -> Result<Self> {
        let k_a = comp.area_modulus.ok_or_else(|| {
            Error::invalid(
                "compression.area_modulus",
                "nothing",
                "the area modulus K_A",
            )
        })?;
        let (nx, ny) = (scene.mesh.elements, scene.mesh.elements_along_y());
        let base = AreaMembrane::new(mp, nx, ny, k_a, 0.0)?;
        let sigma_c0 = base.buckling_stress();
        let model = |strain: f64| {
            #[cfg(any(test, feature = "faults"))]
            return crate::fault::area_model(scene.fault, mp, (nx, ny), k_a, strain);
            #[cfg(not(any(test, feature = "faults")))]
            AreaMembrane::new(mp, nx, ny, k_a, strain)
        };
        let models: Vec<AreaMembrane> = comp
            .strain_ratios
            .iter()
            .map(|r| model(r * sigma_c0 / k_a))
            .collect::<Result<_>>()?;
        if !matches!(
            spec.integrator.family(),
            Family::Metropolis | Family::Theta(_)
        ) {
            return Err(Error::invalid(
                "integrator",
                spec.integrator,
                "metropolis-crank-nicolson or a theta-scheme for a membrane under imposed area",
            ));
        }
        let tau1 = scene.tau1();
        let dt = spec.dt_tau1 * tau1;
        let (burn_in, sample_interval) = (comp.burn_in_tau1 * tau1, comp.sample_every_tau1 * tau1);
        let plan = StepPlan::new(dt, burn_in, sample_interval, dt);
        let modes = Box::new(PlateModes::new(models[0].plate())?);
        // Fails early (exit 2) for an explicit step at or above the stability limit of the
        // fastest bending mode (tension raises the rates further).
        let max_rate = modes.modes().iter().map(|m| m.rate).fold(0.0, f64::max);
        crate::dynamics::integrator::check_stability(
            spec.integrator,
            dt,
            max_rate,
            "metropolis-crank-nicolson (exact at any step)",
        )?;
        Ok(CompressionRun {
            spec: spec.clone(),
            dt,
            burn_in_steps: plan.burn_in_steps,
            sample_every: plan.sample_every,
            plans: vec![plan; models.len()],
            burn_in,
            sample_interval,
            object: Strained::Membrane { models, modes },
            euler_load: sigma_c0,
            filament: None,
            buckled_mode: false,
            #[cfg(any(test, feature = "faults"))]
            proposal_force_factor: crate::fault::proposal_force_factor(scene.fault),
        })
    }

    /// The tolerance band of ⟨F⟩/F_c0 at each of `strain_ratios` for a run whose linear
    /// part is not fluctuation–dissipation exact at its step — the paper's explicit scheme
    /// (`euler-maruyama`: its stiff modes' variance `1/(1 − λΔt/2)`) or the paper's
    /// element-uniform noise (eq. 5: a per-mode deficit) — on a filament, or the explicit
    /// scheme on a membrane under imposed area ([`crate::theory::scheme_law::scheme_area_law`]):
    /// around the
    /// linear-response prediction `F_pred = F_exact + Δ` of that scheme
    /// ([`crate::theory::scheme_law`]), half-width `|Δ|/2` (the allowance for the
    /// prediction's neglect of the nonlinear coupling under such noise), as
    /// `(F_exact + Δ − |Δ|/2, F_exact + Δ + |Δ|/2)`. `None` for every other run (its
    /// reference is the exact discrete theory itself, with no tolerance).
    ///
    /// # Errors
    /// As [`crate::theory::scheme_law::scheme_force_ratios`].
    pub fn scheme_band(&self, strain_ratios: &[f64]) -> Result<Option<Vec<(f64, f64)>>> {
        if self.spec.integrator != IntegratorKind::EulerMaruyama
            && self.spec.noise != NoiseModel::ElementUniform
        {
            return Ok(None);
        }
        let pairs = match (&self.object, self.filament) {
            (Strained::Membrane { models, modes }, _) => {
                crate::theory::scheme_law::scheme_area_force_ratios(
                    &models[0],
                    modes,
                    self.spec.integrator,
                    self.dt,
                    strain_ratios,
                )?
            }
            (_, Some((params, dims, elements))) => crate::theory::scheme_law::scheme_force_ratios(
                &params,
                dims,
                elements,
                self.spec.integrator,
                self.spec.noise,
                self.dt,
                strain_ratios,
            )?,
            _ => return Ok(None),
        };
        Ok(Some(
            pairs
                .into_iter()
                .map(|(pred, exact)| {
                    let half = 0.5 * (pred - exact).abs();
                    (pred - half, pred + half)
                })
                .collect(),
        ))
    }

    /// Number of steps for a sampled duration (physical time) at the scene's step `dt`.
    pub fn sampled_steps(&self, duration: f64) -> u64 {
        StepPlan::new(self.dt, self.burn_in, self.sample_interval, self.dt).sampled_steps(duration)
    }

    /// Number of steps for a sampled duration (physical time) at strain `point`'s step.
    pub fn sampled_steps_at(&self, point: usize, duration: f64) -> u64 {
        self.plans[point].sampled_steps(duration)
    }

    /// The time step of strain `point`.
    pub fn dt_at(&self, point: usize) -> f64 {
        self.plans[point].dt
    }

    /// The time between samples of F at strain `point` (physical time).
    pub fn sample_dt_at(&self, point: usize) -> f64 {
        let p = &self.plans[point];
        p.sample_every as f64 * p.dt
    }

    /// The burn-in before the first sample at strain `point` (physical time).
    pub fn burn_in_at(&self, point: usize) -> f64 {
        let p = &self.plans[point];
        p.burn_in_steps as f64 * p.burn_in_dt
    }

    /// This run with every filament trajectory recording the squared amplitude of its
    /// buckled mode at each sample ([`ForceRecord::buckled_mode`]; a membrane's records
    /// stay without it). Changes nothing else: the same streams, the same forces.
    pub fn with_buckled_mode(mut self) -> Self {
        self.buckled_mode = true;
        self
    }

    /// The time between samples, in physical time, at every strain set to
    /// `sample_interval` (at least one step), for a study that samples finer than the
    /// scene. Changes no trajectory, only which states are recorded.
    pub fn with_sample_interval(mut self, sample_interval: f64) -> Self {
        self.sample_interval = sample_interval;
        for plan in &mut self.plans {
            plan.sample_every = ((sample_interval / plan.dt).round() as u64).max(1);
        }
        if let Some(p) = self.plans.first() {
            self.sample_every = p.sample_every;
        }
        self
    }

    /// This run with its own time step at every strain, `dt_tau1[i]` (units of τ1) at
    /// strain `i` (burn-in and sampling interval kept in physical time): the outcome of a
    /// step search, which only schemes exact at any Δt may use (validated with the scene).
    ///
    /// The burn-in stays at the scene's step: Crank–Nicolson damps a mode of rate λ only
    /// by `(1 − a/2)/(1 + a/2) ≈ −1 + 4/a` per step (a = λΔt), so at a large step the
    /// mid-spectrum modes would carry their start variance (free bending equilibrium,
    /// not the tensioned or compressed one) for hundreds of steps; at 0.64 τ1 and 5 τ1
    /// of burn-in this biased ⟨F⟩ in tension by about 3 standard errors (3D, 10
    /// elements). The chain is exact at both steps, so the switch costs nothing in law.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] without one finite, positive step per strain.
    pub fn with_steps(&self, dt_tau1: &[f64]) -> Result<Self> {
        if dt_tau1.len() != self.points() {
            return Err(Error::invalid(
                "time steps per strain",
                dt_tau1.len(),
                format!("one per strain ({})", self.points()),
            ));
        }
        let tau1 = self.dt / self.spec.dt_tau1;
        let mut out = self.clone();
        for (plan, &d) in out.plans.iter_mut().zip(dt_tau1) {
            if !(d.is_finite() && d > 0.0) {
                return Err(Error::invalid("dt_tau1", d, "finite and > 0"));
            }
            *plan = StepPlan::new(d * tau1, self.burn_in, self.sample_interval, self.dt);
        }
        Ok(out)
    }

    /// An exact sample of the free bending equilibrium, `w_c ~ N(0, kT K⁻¹)` per
    /// transverse component (`w = sqrt(kT) L⁻ᵀ z` with `K = LLᵀ`, O(n)): the start of
    /// every trajectory.
    ///
    /// Why not from rest: Crank–Nicolson (the proposal of the Metropolis scheme, and the
    /// θ = ½ scheme) damps a stiff mode of rate λ only by `m = (1 − a/2)/(1 + a/2) ≈
    /// −1 + 4/a` per step (a = λΔt), so from rest its variance needs about a/8 steps to
    /// build up: at 10 elements and Δt = 0.02 τ1 that is 300 steps for the stiffest mode,
    /// at 40 elements 8·10⁴ steps (1600 τ1). Those modes are almost purely bending (their
    /// buckling loads are ≫ F), so starting from the bending equilibrium puts them in
    /// equilibrium at once; the burn-in then equilibrates the slow, strain-dependent
    /// modes. From rest, the missing stored length of the stiff modes biased ⟨F⟩ upwards
    /// by up to 0.04 F_c0 (3D, 40 elements, Δt = 0.04 τ1), which the convergence study
    /// over Δt exposed.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a membrane run (its chain starts itself, in modal
    /// coordinates).
    pub fn equilibrium_start(&self, rng: &mut TrajectoryRng) -> Result<Vec<Vec<f64>>> {
        let Strained::Filament {
            models, stiffness, ..
        } = &self.object
        else {
            return Err(Error::invalid(
                "run",
                "a membrane",
                "a filament for the nodal equilibrium start (a membrane's chain starts in its modes)",
            ));
        };
        let model = &models[0];
        let kt_sqrt = model.beam().params().kt.sqrt();
        Ok((0..model.components())
            .map(|_| {
                let mut z: Vec<f64> = (0..model.beam().n_dofs())
                    .map(|_| kt_sqrt * rng.sample::<f64, _>(StandardNormal))
                    .collect();
                stiffness.solve_upper_in_place(&mut z);
                z
            })
            .collect())
    }

    /// Simulates one trajectory at strain index `point` from an equilibrium start
    /// ([`Self::equilibrium_start`]).
    ///
    /// # Errors
    /// [`Error::Diverged`] naming the step, time and strain if the state becomes
    /// non-finite.
    pub fn simulate(
        &self,
        point: usize,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
    ) -> Result<ForceRecord> {
        self.simulate_plan(point, self.plans[point], rng, sampled_steps)
    }

    /// A coupled pair of trajectories at strain index `point` (a θ-scheme of the run's
    /// integrator and noise): one at step `dt_coarse`, one at `dt_coarse/2`, driven by the
    /// same Brownian path — each coarse step takes the noise of the two fine steps it
    /// spans, `ζ = (ζ₁ + ζ₂)/√2` (common random numbers, as in multilevel Monte Carlo).
    /// Both start from one state: an equilibrium start ([`Self::equilibrium_start`])
    /// burnt in for `burn_in_steps` coarse steps. Over the next `steps` coarse steps it
    /// sums F/F_c0 of both trajectories after every coarse step.
    ///
    /// The two trajectories stay close (their distance is the schemes' pathwise error),
    /// so the difference of their time averages estimates ⟨F⟩_Δt − ⟨F⟩_Δt/2 with far
    /// less variance than two independent runs: what is left is the fast modes' share,
    /// which decorrelates within a few steps.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for the Metropolis chain or a membrane run; an unstable
    /// step as [`NonlinearIntegrator::new`]; [`Error::Diverged`] naming the coarse step
    /// if a state becomes non-finite.
    pub fn simulate_coupled(
        &self,
        point: usize,
        dt_coarse: f64,
        burn_in_steps: u64,
        steps: u64,
        rng: &mut TrajectoryRng,
    ) -> Result<CoupledRecord> {
        let Strained::Filament { models, .. } = &self.object else {
            return Err(Error::invalid(
                "scene",
                "a membrane",
                "a filament's compression scene for the coupled time-step study",
            ));
        };
        let model = &models[point];
        let (kind, noise) = (self.spec.integrator, self.spec.noise);
        let mut coarse = NonlinearIntegrator::new(model, kind, noise, dt_coarse)?;
        let mut fine = NonlinearIntegrator::new(model, kind, noise, 0.5 * dt_coarse)?;
        let n = model.beam().n_dofs();
        let mut z1 = vec![vec![0.0; n]; model.components()];
        let (mut z2, mut zc) = (z1.clone(), z1.clone());
        let mut wc = self.equilibrium_start(rng)?;
        let diverged = |step: u64, which: &str| {
            Error::diverged(
                step,
                dt_coarse,
                format!(
                    "non-finite deflection of the {which} trajectory of a coupled pair with {kind} at strain {:.4e} (coarse dt = {:.3e} tau1)",
                    model.strain(),
                    dt_coarse / self.euler_tau1()
                ),
            )
        };
        for step in 0..burn_in_steps {
            coarse.draw_noise(rng, &mut zc);
            coarse.step_theta_with(&mut wc, &zc)?;
            if !wc.iter().flatten().all(|v| v.is_finite()) {
                return Err(diverged(step + 1, "burn-in"));
            }
        }
        let mut wf = wc.clone();
        let force =
            |w: &[Vec<f64>]| model.compressive_force(model.stored_length(w)) / self.euler_load;
        let mut rec = CoupledRecord::default();
        for step in 0..steps {
            fine.draw_noise(rng, &mut z1);
            fine.draw_noise(rng, &mut z2);
            fine.step_theta_with(&mut wf, &z1)?;
            fine.step_theta_with(&mut wf, &z2)?;
            for ((c, a), b) in zc.iter_mut().zip(&z1).zip(&z2) {
                for ((v, x), y) in c.iter_mut().zip(a).zip(b) {
                    *v = (x + y) * std::f64::consts::FRAC_1_SQRT_2;
                }
            }
            coarse.step_theta_with(&mut wc, &zc)?;
            let (fc, ff) = (force(&wc), force(&wf));
            if !(fc.is_finite() && ff.is_finite()) {
                return Err(diverged(
                    burn_in_steps + step + 1,
                    if fc.is_finite() { "fine" } else { "coarse" },
                ));
            }
            rec.coarse_sum += fc;
            rec.fine_sum += ff;
            rec.difference_sum += fc - ff;
            rec.steps += 1;
        }
        Ok(rec)
    }

    /// τ₁ of the run's filament (1 for a membrane: not used there).
    fn euler_tau1(&self) -> f64 {
        self.filament.map_or(1.0, |(p, _, _)| p.tau1())
    }

    /// [`Self::simulate`] with the step and cadence `plan`.
    fn simulate_plan(
        &self,
        point: usize,
        plan: StepPlan,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
    ) -> Result<ForceRecord> {
        let (model, paired) = match &self.object {
            Strained::Filament { models, paired, .. } => (&models[point], paired),
            Strained::Membrane { models, modes } => {
                return self.simulate_membrane(&models[point], modes, plan, rng, sampled_steps);
            }
        };
        if let Some(modes) = paired {
            return self.simulate_modal(model, plan, modes, rng, sampled_steps);
        }
        let integrator =
            NonlinearIntegrator::new(model, self.spec.integrator, self.spec.noise, plan.dt)?;
        let mut state = NonlinearState {
            integrator,
            w: self.equilibrium_start(rng)?,
        };
        let mut recorder = ForceRecorder::new(self, model, plan, sampled_steps);
        self.nodal_driver(plan, sampled_steps).run(
            point,
            &mut state,
            rng,
            &mut recorder,
            |_| self.nodal_divergence(model),
        )?;
        Ok(recorder.rec)
    }

    /// The schedule of a nodal trajectory with step plan `plan`.
    fn nodal_driver(&self, plan: StepPlan, sampled_steps: u64) -> Driver {
        let burn_in_steps = (self.burn_in / plan.dt).round() as u64;
        Driver::new(plan.dt, burn_in_steps, sampled_steps, plan.sample_every)
    }

    /// What a diverged nodal trajectory of `model` reports.
    fn nodal_divergence(&self, model: &CompressedFilament) -> String {
        format!(
            "non-finite deflection with {} at strain {:.4e} (dt = {:.3e} tau1)",
            self.spec.integrator,
            model.strain(),
            self.spec.dt_tau1
        )
    }

    /// The trajectories `js` of strain index `point` (the stream of trajectory `j` is
    /// `trajectory_rng(seed, j)`) as one [`NonlinearBatch`] in lockstep, or `None` if the
    /// run is no nodal θ-scheme the lane kernels serve. Each lane is bit-identical to
    /// [`Self::simulate`] of its trajectory: the same start, draws and operations.
    fn simulate_batch(
        &self,
        point: usize,
        seed: u64,
        js: std::ops::Range<u64>,
        sampled_steps: u64,
    ) -> Result<Option<Vec<Result<ForceRecord>>>> {
        let Strained::Filament {
            models,
            paired: None,
            ..
        } = &self.object
        else {
            return Ok(None);
        };
        let (model, plan) = (&models[point], self.plans[point]);
        let Some(mut batch) =
            NonlinearBatch::new(model, self.spec.integrator, self.spec.noise, plan.dt)?
        else {
            return Ok(None);
        };
        let mut rngs: Vec<TrajectoryRng> = js.clone().map(|j| trajectory_rng(seed, j)).collect();
        for (lane, rng) in rngs.iter_mut().enumerate() {
            batch.set_lane(lane, &self.equilibrium_start(rng)?);
        }
        let mut recorders: Vec<ForceRecorder> = js
            .map(|_| ForceRecorder::new(self, model, plan, sampled_steps))
            .collect();
        let results = self.nodal_driver(plan, sampled_steps).run_batch(
            point,
            &mut batch,
            &mut rngs,
            &mut recorders,
            |_| self.nodal_divergence(model),
        );
        Ok(Some(
            results
                .into_iter()
                .zip(recorders)
                .map(|(r, o)| r.map(|()| o.rec))
                .collect(),
        ))
    }

    /// [`Self::simulate`] for `metropolis-crank-nicolson` on the paired modal form
    /// ([`ModalMetropolis`]): the same chain at O(n) per step, started from the free
    /// bending equilibrium (moved onto the buckled branch above the Euler strain).
    fn simulate_modal(
        &self,
        model: &CompressedFilament,
        plan: StepPlan,
        modes: &PairedModes,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
    ) -> Result<ForceRecord> {
        let mut chain = ModalMetropolis::new(model, modes, plan.burn_in_dt, rng)?;
        #[cfg(any(test, feature = "faults"))]
        {
            chain = chain.with_proposal_force_factor(self.proposal_force_factor);
        }
        self.burn_in(&mut chain, plan, model.strain(), rng)?;
        let mut recorder = ModalForceRecorder {
            model,
            euler_load: self.euler_load,
            rec: ForceRecord {
                force_ratio: Vec::with_capacity((sampled_steps / plan.sample_every) as usize),
                ..Default::default()
            },
            block_squares: vec![0.0; modes.pairs().len() + modes.singles().len()],
            buckled_mode: self.buckled_mode,
        };
        self.sample(
            &mut chain,
            plan,
            model.strain(),
            rng,
            sampled_steps,
            &mut recorder,
        )?;
        let mut slope_squares = vec![0.0; model.beam().mesh().n_nodes()];
        modes.add_rotation_squares(&recorder.block_squares, &mut slope_squares);
        Ok(ForceRecord {
            proposed: chain.proposed,
            accepted: chain.accepted,
            slope_squares,
            ..recorder.rec
        })
    }

    /// [`Self::simulate`] for a membrane under imposed projected area: the modal chain
    /// ([`ModalMetropolis::for_membrane`], its θ-scheme for the θ integrators) from the
    /// free bending equilibrium, recording the compressive stress `−σ/σ_c0` (no slopes).
    fn simulate_membrane(
        &self,
        model: &AreaMembrane,
        modes: &PlateModes,
        plan: StepPlan,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
    ) -> Result<ForceRecord> {
        let mut chain = ModalMetropolis::for_membrane(model, modes, plan.burn_in_dt, rng)?;
        #[cfg(any(test, feature = "faults"))]
        {
            chain = chain.with_proposal_force_factor(self.proposal_force_factor);
        }
        if let Family::Theta(theta) = self.spec.integrator.family() {
            chain = chain.with_theta(theta)?;
        }
        self.burn_in(&mut chain, plan, model.strain(), rng)?;
        let mut recorder = StressRecorder {
            unit: self.euler_load,
            force_ratio: Vec::with_capacity((sampled_steps / plan.sample_every) as usize),
            drift: ForceRecord::default(),
        };
        self.sample(
            &mut chain,
            plan,
            model.strain(),
            rng,
            sampled_steps,
            &mut recorder,
        )?;
        Ok(ForceRecord {
            force_ratio: recorder.force_ratio,
            proposed: chain.proposed,
            accepted: chain.accepted,
            drift_residual: recorder.drift.drift_residual,
            drift_states: recorder.drift.drift_states,
            ..Default::default()
        })
    }

    /// The burn-in of a modal chain at the plan's burn-in step, then the switch to its
    /// sampling step with the counts reset.
    fn burn_in(
        &self,
        chain: &mut ModalMetropolis<'_>,
        plan: StepPlan,
        strain: f64,
        rng: &mut TrajectoryRng,
    ) -> Result<()> {
        Driver::new(plan.burn_in_dt, plan.burn_in_steps, 0, 1).run(
            0,
            chain,
            rng,
            &mut (),
            |_| self.divergence(strain, "burn-in", plan.burn_in_dt),
        )?;
        chain.set_dt(plan.dt)?;
        chain.proposed = 0;
        chain.accepted = 0;
        Ok(())
    }

    /// The sampled steps of a modal chain after its burn-in.
    fn sample<'a>(
        &self,
        chain: &mut ModalMetropolis<'a>,
        plan: StepPlan,
        strain: f64,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
        observer: &mut impl Observer<ModalMetropolis<'a>>,
    ) -> Result<()> {
        Driver::new(plan.dt, 0, sampled_steps, plan.sample_every).run(
            0,
            chain,
            rng,
            observer,
            |_| self.divergence(strain, "sampling after the burn-in", plan.dt),
        )
    }

    /// What a diverged modal chain reports: integrator, strain, phase and step.
    fn divergence(&self, strain: f64, phase: &str, dt: f64) -> String {
        format!(
            "non-finite energy with {} at strain {:.4e} ({phase}, dt = {:.3e} tau1)",
            self.spec.integrator,
            strain,
            dt / (self.dt / self.spec.dt_tau1)
        )
    }

    /// Simulates `trajectories` trajectories at every strain, `sampled_steps[i]` sampled
    /// steps at strain `i` (the main stage of a budget by target precision gives each
    /// strain its own), in parallel (rayon over strain × trajectory). Trajectory `j` at
    /// strain `i` uses the stream `trajectory_rng(seed(i), j)`, so the result does not
    /// depend on the thread count. `tick` is called after each trajectory (progress).
    /// Returns the records per strain.
    ///
    /// # Errors
    /// As [`Self::simulate`]: the first diverged trajectory (in index order);
    /// [`Error::InvalidParameter`] if `sampled_steps` does not have one entry per strain.
    pub fn simulate_ensemble_per_point(
        &self,
        seed: impl Fn(usize) -> u64 + Sync,
        trajectories: usize,
        sampled_steps: &[u64],
        tick: impl Fn() + Sync,
    ) -> Result<Vec<Vec<ForceRecord>>> {
        self.simulate_share_per_point(seed, 0..trajectories.max(1) as u64, sampled_steps, tick)
    }

    /// [`Self::simulate_ensemble_per_point`] for the trajectories `range` of every strain
    /// only (one shard's share, [`crate::shard`]): strain `i`, trajectory `j` draws from
    /// `trajectory_rng(seed(i), j)` as in the whole ensemble, so the records are those of
    /// the whole ensemble's trajectories `range`, bit for bit.
    ///
    /// # Errors
    /// As [`Self::simulate_ensemble_per_point`].
    pub fn simulate_share_per_point(
        &self,
        seed: impl Fn(usize) -> u64 + Sync,
        range: std::ops::Range<u64>,
        sampled_steps: &[u64],
        tick: impl Fn() + Sync,
    ) -> Result<Vec<Vec<ForceRecord>>> {
        if sampled_steps.len() != self.points() {
            return Err(Error::invalid(
                "sampled steps per strain",
                sampled_steps.len(),
                format!("one entry per strain ({})", self.points()),
            ));
        }
        let nt = range.end.saturating_sub(range.start);
        if nt == 0 {
            return Ok(vec![Vec::new(); self.points()]);
        }
        if let Some(records) = self.simulate_batches(&seed, range.clone(), sampled_steps, &tick)? {
            return Ok(records);
        }
        let flat = crate::dynamics::par_indexed(self.points() as u64 * nt, |t| {
            let (i, j) = ((t / nt) as usize, range.start + t % nt);
            let rec = self.simulate(i, &mut trajectory_rng(seed(i), j), sampled_steps[i]);
            tick();
            rec
        })?;
        Ok(flat.chunks(nt as usize).map(<[_]>::to_vec).collect())
    }

    /// [`Self::simulate_share_per_point`] in lockstep batches ([`Self::simulate_batch`])
    /// for a nodal θ-scheme, `None` for any other run. Up to [`LANES`] trajectories of one
    /// strain per batch, fewer when the ensemble would leave a core idle. The records are
    /// those of the trajectory-by-trajectory run bit for bit, and so is the error: the
    /// first in strain-major trajectory order (a batch that cannot be built fails at its
    /// first trajectory, as the first of its trajectories run alone would).
    fn simulate_batches(
        &self,
        seed: &(impl Fn(usize) -> u64 + Sync),
        range: std::ops::Range<u64>,
        sampled_steps: &[u64],
        tick: &(impl Fn() + Sync),
    ) -> Result<Option<Vec<Vec<ForceRecord>>>> {
        let nodal = matches!(self.object, Strained::Filament { paired: None, .. });
        if !nodal || !matches!(self.spec.integrator.family(), Family::Theta(_)) {
            return Ok(None);
        }
        let (points, nt) = (self.points() as u64, range.end - range.start);
        let threads = rayon::current_num_threads().max(1) as u64;
        let lanes = (points * nt)
            .div_ceil(threads)
            .clamp(1, LANES as u64)
            .min(nt);
        let per_point = nt.div_ceil(lanes);
        let batches = crate::dynamics::par_indexed(points * per_point, |b| {
            let i = (b / per_point) as usize;
            let start = range.start + (b % per_point) * lanes;
            let js = start..(start + lanes).min(range.end);
            let recs = match self.simulate_batch(i, seed(i), js.clone(), sampled_steps[i]) {
                Ok(Some(recs)) => recs,
                Ok(None) => js
                    .clone()
                    .map(|j| self.simulate(i, &mut trajectory_rng(seed(i), j), sampled_steps[i]))
                    .collect(),
                Err(e) => vec![Err(e)],
            };
            js.for_each(|_| tick());
            Ok(recs)
        })?;
        let mut out = vec![Vec::with_capacity(nt as usize); points as usize];
        for (b, recs) in batches.into_iter().enumerate() {
            for rec in recs {
                out[b / per_point as usize].push(rec?);
            }
        }
        Ok(Some(out))
    }

    /// The step search of a budget by target precision at strain `point` (see
    /// [`StepSearch`]): the candidates `dt_tau1·2^k ≤ max_dt_tau1`, largest first, each
    /// probed with `trajectories` trajectories of [`PROBE_STEPS`] sampled steps after the
    /// burn-in (trajectory `j` of candidate `k` on the stream `trajectory_rng(seed(k), j)`),
    /// until the acceptance rate over the probe's sampled steps (the burn-in runs at the
    /// scene's step, see [`Self::with_steps`]) reaches `min_acceptance`; the scene's own
    /// `dt_tau1` if none does. The probes are discarded.
    ///
    /// # Errors
    /// As [`Self::simulate`].
    pub fn search_step(
        &self,
        point: usize,
        search: StepSearch,
        trajectories: usize,
        seed: impl Fn(usize) -> u64,
    ) -> Result<StepChoice> {
        let base = self.spec.dt_tau1;
        let tau1 = self.dt / base;
        let doublings = (search.max_dt_tau1 / base).log2().floor().max(0.0) as i32;
        let mut tried = Vec::new();
        for k in (0..=doublings).rev() {
            let dt_tau1 = base * 2f64.powi(k);
            let plan = StepPlan::new(dt_tau1 * tau1, self.burn_in, self.sample_interval, self.dt);
            let steps = PROBE_STEPS.div_ceil(plan.sample_every) * plan.sample_every;
            let (mut proposed, mut accepted) = (0, 0);
            for j in 0..trajectories.max(1) {
                let mut rng = trajectory_rng(seed(k as usize), j as u64);
                let rec = self.simulate_plan(point, plan, &mut rng, steps)?;
                proposed += rec.proposed;
                accepted += rec.accepted;
            }
            let rate = accepted as f64 / proposed.max(1) as f64;
            tried.push((dt_tau1, rate));
            if rate >= search.min_acceptance {
                return Ok(StepChoice { dt_tau1, tried });
            }
        }
        Ok(StepChoice {
            dt_tau1: base,
            tried,
        })
    }

    /// The strains of this run (ε/ε_c0 is in the theory table).
    pub fn points(&self) -> usize {
        match &self.object {
            Strained::Filament { models, .. } => models.len(),
            Strained::Membrane { models, .. } => models.len(),
        }
    }

    /// The filament models (one per strain); `None` for a membrane.
    fn filaments(&self) -> Option<&[CompressedFilament]> {
        match &self.object {
            Strained::Filament { models, .. } => Some(models),
            Strained::Membrane { .. } => None,
        }
    }

    /// What is wrong with the shapes of `records` (per strain, per trajectory) read from
    /// elsewhere (a shard), against what this run gives its records: one list per strain,
    /// the nodal slope sums of its mesh, no more acceptances than proposals, and the same
    /// number of samples in every trajectory of a strain; `None` if they are this run's
    /// shapes.
    pub fn records_shape_error(&self, records: &[Vec<ForceRecord>]) -> Option<String> {
        if records.len() != self.points() {
            return Some(format!(
                "records of {} strains, run {} has {}",
                records.len(),
                self.spec.name,
                self.points()
            ));
        }
        let nodes = self
            .filaments()
            .and_then(|m| m.first())
            .map_or(0, |m| m.beam().mesh().n_nodes());
        for (i, at) in records.iter().enumerate() {
            let samples = at.first().map(|r| r.force_ratio.len());
            for (j, r) in at.iter().enumerate() {
                if r.slope_squares.len() != nodes
                    || r.accepted > r.proposed
                    || Some(r.force_ratio.len()) != samples
                {
                    return Some(format!(
                        "trajectory {j} at strain {i}: {} samples (trajectory 0: {}), {} nodal slope sums (the mesh has {nodes} nodes), {} of {} proposals accepted",
                        r.force_ratio.len(),
                        samples.unwrap_or(0),
                        r.slope_squares.len(),
                        r.accepted,
                        r.proposed
                    ));
                }
            }
        }
        None
    }

    /// The largest root-mean-square nodal slope |w'| (all components) of the records of
    /// one strain: `(rms slope, node x/L)`; `None` without samples. The small-slope
    /// (von Kármán) model is flagged above
    /// [`SMALL_SLOPE_LIMIT`](crate::scene::linear::SMALL_SLOPE_LIMIT).
    /// `None` for a membrane (no slopes are recorded).
    pub fn measured_rms_slope(&self, records: &[ForceRecord]) -> Option<(f64, f64)> {
        let models = self.filaments()?;
        let beam = models.first()?.beam();
        let n = records.iter().map(|r| r.slope_samples).sum::<usize>() * models[0].components();
        let sums: Vec<f64> = (0..beam.mesh().n_nodes())
            .map(|k| records.iter().map(|r| r.slope_squares[k]).sum())
            .collect();
        largest_rms_slope(beam, &sums, n)
    }

    /// The largest RMS slope over all strains of `records` (one entry per strain):
    /// `(rms slope, node x/L, strain index)`.
    pub fn largest_rms_slope(&self, records: &[Vec<ForceRecord>]) -> Option<(f64, f64, usize)> {
        records
            .iter()
            .enumerate()
            .filter_map(|(i, r)| self.measured_rms_slope(r).map(|(s, x)| (s, x, i)))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// Safety factor on the sampled duration a pilot predicts for a target standard error:
/// the pilot's own error estimate scatters (its integrated autocorrelation time most,
/// about 20 % with 16 trajectories), and 2 on the duration is a margin of √2 ≈ 1.41 on
/// the standard error, so that a strain misses the target only if its pilot
/// underestimated the error by about 30 % (with 1.5, one or two of 24 strains missed by
/// a few per cent).
pub const DURATION_SAFETY: f64 = 2.0;

/// The main stage's sampled duration per trajectory of a budget by target precision, from
/// a pilot of the same trajectory count: the standard error of a time average falls as
/// T^(-1/2) (for T much longer than the autocorrelation time), so the target `target` is
/// reached at `T = pilot_duration · (pilot_std_error / target)²`; returned is that times
/// [`DURATION_SAFETY`], at least `pilot_duration` (the main stage's own error estimate
/// needs as many samples as the pilot's) and at most `max_duration` (also for a
/// non-finite pilot error). Units are the caller's (τ1 in the scenes; F_c0 for errors).
///
/// The rule uses the pilot only, and the pilot's streams are independent of the main
/// stage's: given the duration, the main stage is an ordinary fixed-budget estimate, so
/// its standard error and p-values stay honest (no optional-stopping bias).
pub fn targeted_duration(
    pilot_std_error: f64,
    pilot_duration: f64,
    target: f64,
    max_duration: f64,
) -> f64 {
    let needed = DURATION_SAFETY * pilot_duration * (pilot_std_error / target).powi(2);
    if needed.is_finite() {
        needed.max(pilot_duration).min(max_duration)
    } else {
        max_duration
    }
}

/// Per-strain estimates of one run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ForceEstimates {
    /// (⟨F⟩/F_c0, standard error) per strain.
    pub force: Vec<(f64, f64)>,
    /// Metropolis acceptance rate over the run (1 for θ-schemes).
    pub acceptance: f64,
    /// Largest integrated autocorrelation time of F (in samples) over the strains.
    pub max_tau_int: f64,
}

/// ⟨F⟩/F_c0 per strain: per trajectory the time average with an autocorrelation-aware
/// error (integrated autocorrelation time); trajectories are independent, so errors add
/// in quadrature. Where one trajectory's series is too short for its own
/// autocorrelation window (a quick run of a few τ₁), every trajectory of that strain
/// takes the time pooled over them ([`stats::pooled_integrated_autocorrelation_time`]):
/// the same process, so the same τ_int (issue #30; a strain whose own windows all exist
/// is estimated as before).
///
/// # Errors
/// Estimator errors (too few samples, also for the pooled time).
pub fn force_estimates(records: &[Vec<ForceRecord>]) -> Result<ForceEstimates> {
    let mut out = ForceEstimates::default();
    let (mut prop, mut acc) = (0u64, 0u64);
    for (k, point) in records.iter().enumerate() {
        let own: Result<Vec<_>> = point
            .iter()
            .map(|r| stats::mean_with_error(&r.force_ratio))
            .collect();
        let parts = match own {
            Ok(parts) => parts,
            Err(e) => {
                let series: Vec<&[f64]> = point.iter().map(|r| r.force_ratio.as_slice()).collect();
                let tau = stats::pooled_integrated_autocorrelation_time(&series)
                    .map_err(|_| {
                        let at = format!("<F> at strain {} of {}", k + 1, records.len());
                        too_short_to_pool(&at, &series, e)
                    })?
                    .tau_int;
                point
                    .iter()
                    .map(|r| stats::mean_with_error_at(&r.force_ratio, tau))
                    .collect()
            }
        };
        for (m, r) in parts.iter().zip(point) {
            out.max_tau_int = out.max_tau_int.max(m.tau_int);
            prop += r.proposed;
            acc += r.accepted;
        }
        out.force.push(stats::combine_independent(&parts));
    }
    out.acceptance = if prop == 0 {
        1.0
    } else {
        acc as f64 / prop as f64
    };
    Ok(out)
}

/// The error of a strain whose series of F are too short for the autocorrelation window
/// even pooled over its trajectories (`e`, the window's error for one of them): `what`
/// (the strain, the check) named, and what to change.
pub(crate) fn too_short_to_pool(what: &str, series: &[&[f64]], e: Error) -> Error {
    let detail = match e {
        Error::Numerical { detail, .. } => detail,
        other => other.to_string(),
    };
    Error::Numerical {
        routine: what.to_string(),
        detail: format!(
            "{detail}, even pooled over its {} trajectories (the window needs about {} tau_int samples per trajectory): record longer trajectories (F relaxes slowest near buckling)",
            series.len(),
            2.0 * stats::moments::SOKAL_C
        ),
    }
}

/// Metropolis acceptance rates below this are named as the likely cause of a failed
/// force estimate (a sticky chain).
pub const LOW_ACCEPTANCE: f64 = 0.2;

/// [`force_estimates`], with the usual cause of a failure named: the Metropolis
/// acceptance rate and the filament's EA·L/kT and EI/(kT·L) are added to the message,
/// and a rate below [`LOW_ACCEPTANCE`] (a sticky chain) is named as the cause.
///
/// # Errors
/// As [`force_estimates`].
pub fn force_estimates_diagnosed(
    records: &[Vec<ForceRecord>],
    params: &crate::params::FilamentParams,
) -> Result<ForceEstimates> {
    force_estimates(records).map_err(|e| {
        let (proposed, accepted) = records
            .iter()
            .flatten()
            .fold((0u64, 0u64), |(p, a), r| (p + r.proposed, a + r.accepted));
        if proposed == 0 {
            return e;
        }
        let rate = accepted as f64 / proposed as f64;
        let cause = if rate < LOW_ACCEPTANCE {
            "a low acceptance makes F strongly correlated; a smaller dt_tau1 raises it"
        } else {
            "the acceptance is not the cause: F relaxes slowly compared with the sampled duration; raise duration_tau1"
        };
        Error::Numerical {
            routine: "force estimates".into(),
            detail: format!(
                "{e}; the Metropolis acceptance rate was {rate:.3} (EA L/kT = {:e}, EI/(kT L) = {:e}): {cause}",
                params.stretch_rigidity * params.length / params.kt,
                params.bending_rigidity / (params.kt * params.length),
            ),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::membrane::MembraneParams;

    /// Issue #30 (fig2-paper-2d at seed 65): a strain where one trajectory's series is too
    /// short for its own autocorrelation window takes the time pooled over the strain's
    /// trajectories, for every trajectory of it; a strain whose windows all exist is
    /// estimated exactly as before (bit for bit).
    #[test]
    fn a_series_too_short_for_its_window_takes_the_pooled_time() {
        // AR(1) series of 400 samples, ρ = 0.95 (τ_int = 19.5 samples, the window needs
        // M ≥ 6τ ≈ 117 of at most n/2 = 200, which a noisy ρ̂ of one series can miss):
        // seven whose own windows exist, and the first seed whose own window fails.
        let ar1 = |n: usize, seed: u64| {
            let mut rng = crate::rng::trajectory_rng(seed, 0);
            let mut x = 0.0;
            (0..n)
                .map(|_| {
                    let z: f64 =
                        rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
                    x = 0.95 * x + z;
                    1.0 + 0.01 * x
                })
                .collect::<Vec<f64>>()
        };
        let all: Vec<Vec<f64>> = (1..400).map(|seed| ar1(400, seed)).collect();
        let long: Vec<Vec<f64>> = all
            .iter()
            .filter(|x| stats::mean_with_error(x).is_ok())
            .take(7)
            .cloned()
            .collect();
        let drift = all
            .iter()
            .find(|x| stats::mean_with_error(x).is_err())
            .expect("a series without its own window")
            .clone();
        let rec = |force_ratio: Vec<f64>| ForceRecord {
            force_ratio,
            ..ForceRecord::default()
        };
        let good: Vec<ForceRecord> = long.iter().cloned().map(rec).collect();
        let mut short = good.clone();
        short.push(rec(drift.clone()));
        let e = force_estimates(&[good.clone(), short]).expect("pooled fallback");
        let own: Vec<_> = long
            .iter()
            .map(|x| stats::mean_with_error(x).unwrap())
            .collect();
        assert_eq!(e.force[0], stats::combine_independent(&own));
        let series: Vec<&[f64]> = long
            .iter()
            .map(Vec::as_slice)
            .chain([drift.as_slice()])
            .collect();
        let tau = stats::pooled_integrated_autocorrelation_time(&series)
            .unwrap()
            .tau_int;
        let pooled: Vec<_> = series
            .iter()
            .map(|x| stats::mean_with_error_at(x, tau))
            .collect();
        assert_eq!(e.force[1], stats::combine_independent(&pooled));
        // Nothing to pool from: the error stands.
        assert!(force_estimates(&[vec![rec(drift)]]).is_err());
    }

    /// A compression scene carrying a membrane is the membrane under imposed projected
    /// area: without `compression.area_modulus` (refused by validation in a file,
    /// possible in code) its theory and its runs are refused before anything is
    /// computed, naming the key; with it, the run records the compressive stress.
    #[test]
    fn membrane_compression_needs_an_area_modulus() {
        let mut scene = crate::scene::builtin::find("membrane-area-stiff")
            .expect("built in")
            .load()
            .expect("loads");
        let mut comp = scene.compression.clone().expect("compression table");
        comp.area_modulus = None;
        let refusals = [
            CompressionTheoryTable::new(&scene, &comp).err(),
            CompressionRun::prepare(&scene, &comp, &scene.runs[0]).err(),
        ];
        for e in refusals {
            let m = e.expect("refused").to_string();
            assert!(m.contains("compression.area_modulus"), "{m}");
        }
        scene.membrane = Some(MembraneParams {
            tension: 0.0,
            ..scene.membrane.unwrap()
        });
        let comp = scene.compression.clone().unwrap();
        let run = CompressionRun::prepare(&scene, &comp, &scene.runs[0]).unwrap();
        let rec = run.simulate(0, &mut trajectory_rng(1, 0), 100).unwrap();
        assert_eq!(rec.force_ratio.len() as u64, 100 / run.sample_every);
        assert!(rec.force_ratio.iter().all(|f| f.is_finite()));
        assert!(rec.slope_squares.is_empty() && rec.axial_residual.is_none());
    }

    /// The paper's explicit scheme and Crank–Nicolson with explicit stretching (2D and 3D,
    /// both noises) run in lockstep batches: every strain's records (forces, slopes,
    /// axial residuals, buckled mode) equal those of each trajectory simulated alone, bit
    /// for bit, with 1 and 3 worker threads and for a shard's share of the trajectories.
    #[test]
    fn batched_ensembles_are_the_trajectories_run_alone() {
        let bits = |r: &ForceRecord| -> Vec<u64> {
            let mut v: Vec<u64> = [&r.force_ratio, &r.slope_squares, &r.buckled_mode]
                .iter()
                .flat_map(|s| s.iter().map(|x| x.to_bits()))
                .collect();
            v.extend([r.slope_samples as u64, r.axial_states, r.proposed]);
            v.push(r.axial_residual.map_or(u64::MAX, f64::to_bits));
            v
        };
        for (name, integrator) in [
            ("fig2-paper-2d", IntegratorKind::EulerMaruyama),
            ("fig2-paper-3d", IntegratorKind::EulerMaruyama),
            ("fig2-paper-2d", IntegratorKind::CrankNicolson),
        ] {
            let scene = crate::scene::builtin::find(name)
                .expect("built in")
                .load()
                .expect("loads");
            // short: a burn-in of 0.01 tau1 and a sample every 5e-4 tau1 (71 steps)
            let comp = CompressionSpec {
                burn_in_tau1: 0.01,
                sample_every_tau1: 5e-4,
                ..scene.compression.clone().unwrap()
            };
            let mut spec = scene.runs[0].clone();
            spec.integrator = integrator;
            if integrator == IntegratorKind::CrankNicolson {
                spec.noise = NoiseModel::Consistent;
                spec.dt_tau1 = 1e-3;
            }
            let run = CompressionRun::prepare(&scene, &comp, &spec)
                .unwrap()
                .with_buckled_mode();
            let steps = vec![50 * run.sample_every; run.points()];
            let seed = |i: usize| 40 + i as u64;
            for (threads, range) in [(1, 0..5), (3, 0..5), (2, 2..5)] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let batched = pool
                    .install(|| run.simulate_share_per_point(seed, range.clone(), &steps, || {}))
                    .unwrap();
                for (i, recs) in batched.iter().enumerate() {
                    assert_eq!(recs.len(), range.clone().count());
                    for (rec, j) in recs.iter().zip(range.clone()) {
                        let alone = run.simulate(i, &mut trajectory_rng(seed(i), j), steps[i]);
                        assert_eq!(
                            bits(rec),
                            bits(&alone.unwrap()),
                            "{name} {integrator} strain {i} trajectory {j}, {threads} threads"
                        );
                        assert_eq!(rec.force_ratio.len(), 50);
                    }
                }
            }
        }
    }
}
