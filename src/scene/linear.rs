//! Linear hinged filament: simulation of an ensemble and the exact references every
//! check is judged against.
//!
//! Two models share this code: the finite-element filament ([`ModelKind::Fem`], any
//! integrator and noise model) and the exact modal simulator of eq. (2)
//! ([`ModelKind::Spectral`]), which is the self-check of the references and the checks.
//!
//! For each run the exact *discrete* reference is the stationary covariance of the
//! discretized system under this integrator and time step (see [`crate::dynamics`]), and
//! the *continuum* reference is the modal solution of eq. (2) (per-mode variance
//! 2kTL³/(π⁴n⁴EI), rate λ_n, profile kT x²(L−x)²/(3EI L), eq. 4).

use crate::dynamics::discrete::{DiscreteLaw, decay_rate};
use crate::dynamics::{
    BatchTrajectory, ComponentBatch, Components, Driver, Integrator, IntegratorKind, LaneOf,
    ModalStep, Observer, ThetaBatch, Trajectory, build_integrator, par_indexed,
};
use crate::error::{Error, Result};
use crate::fem::banded::LANES;
use crate::fem::beam::BeamModel;
use crate::fem::chain::ChainModel;
use crate::fem::modal::GeneralizedModes;
use crate::fem::noise::NoiseModel;
use crate::params::End;
use crate::rng::{TrajectoryRng, trajectory_rng};
use crate::scene::{CheckKind, MeshScheme, ModelKind, RunSpec, Scene};
use crate::spectral::HingedBeam;
use crate::spectral::membrane::{Membrane, MembraneMode, MembraneSimulator};
use crate::spectral::simulator::ModalSimulator;
use crate::stats;
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

mod object;
mod stream;

pub(crate) use object::Continuum;
pub(crate) use object::FemObject;
pub(crate) use object::MEMO_ENTRIES;
use object::Probes;

pub use stream::{RowPlan, ShortRows};

/// Exact references for one mode of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeReference {
    /// Mode number (1-based).
    pub n: usize,
    /// Stationary variance of the modal amplitude for this discretization, noise model,
    /// integrator and time step.
    pub variance_discrete: f64,
    /// The same under equipartition for this discretization (kT/λ_i of the discrete
    /// modes; the spectral model: its own σ_n²). The ratio variance/equipartition is what
    /// the element-uniform noise table reports.
    pub variance_equipartition: f64,
    /// The continuum stationary variance of the same mode (eq. 4, t = η → ∞).
    pub variance_continuum: f64,
    /// One-step multiplier m of the modal amplitude (the AR(1) coefficient per step).
    pub multiplier: f64,
    /// Relaxation rate of the discrete mode, −ln(m)/Δt (`None` if m ≤ 0).
    pub rate_discrete: Option<f64>,
    /// The continuum relaxation rate λ_n = π⁴n⁴EI/(ξL⁴).
    pub rate_continuum: f64,
    /// The membrane's mode this is (its lattice indices and shape); `None` for a
    /// filament's mode n.
    pub label: Option<MembraneMode>,
}

/// A checked mode the burn-in leaves remembering its start ([`LinearRun::unforgetting_mode`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnforgettingMode {
    /// The mode number.
    pub n: usize,
    /// Its one-step multiplier (negative, near −1).
    pub multiplier: f64,
    /// |m|^N after the burn-in's N steps.
    pub memory: f64,
    /// What the slowest positive-multiplier mode keeps (at least 10⁻³).
    pub slowest: f64,
    /// The burn-in's steps N.
    pub burn_in_steps: u64,
    /// About the largest Δt at which the mode forgets as fast as the slowest one,
    /// 0.9·√(4t_b/(λₙ ln(1/F))) with t_b the burn-in time and F `slowest` (time units).
    pub dt_bound: f64,
}

/// Exact references for the two-time correlation at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoTimeReference {
    /// Positions and times (physical units).
    pub x: f64,
    /// Second position.
    pub y: f64,
    /// Earlier time t (a whole number of steps).
    pub t: f64,
    /// Later time η (a whole number of steps).
    pub eta: f64,
    /// Step index of t.
    pub t_step: u64,
    /// Step index of η.
    pub eta_step: u64,
    /// ⟨w(x,t) w(y,η)⟩ for the discrete system from rest.
    pub discrete: f64,
    /// ⟨w(x,t)²⟩ and ⟨w(y,η)²⟩ for the discrete system from rest: with `discrete`, the
    /// whole law of the product (the null law of the two-time check); NaN for data of an
    /// unknown discretization.
    pub variances: (f64, f64),
    /// Eq. (4).
    pub continuum: f64,
}

/// Everything a run's checks are judged against.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearReference {
    /// Per checked mode.
    pub modes: Vec<ModeReference>,
    /// Profile positions (physical units).
    pub profile_x: Vec<f64>,
    /// ⟨w²(x)⟩ of the discrete system at `profile_x`.
    pub profile_discrete: Vec<f64>,
    /// Per profile point, the terms `(u_k, m_k)` of the discrete field's autocovariance
    /// after `s` steps, `⟨w(x, t) w(x, t + sΔt)⟩ = Σ_k u_k m_k^s` (`m_k` the one-step
    /// multiplier of mode k, `Σ u_k` = `profile_discrete`): the null law of the profile
    /// check. Empty for data of an unknown discretization.
    pub profile_terms: Vec<Vec<(f64, f64)>>,
    /// ⟨w²(x)⟩ of the continuum (closed form).
    pub profile_continuum: Vec<f64>,
    /// Two-time points.
    pub two_time: Vec<TwoTimeReference>,
    /// Time step.
    pub dt: f64,
    /// Largest rate of the discrete system (λ_max).
    pub max_rate: f64,
    /// Per rigid mode of the ends (issue #29; empty without), its exact diffusion law.
    pub rigid: Vec<RigidReference>,
    /// Per tangent-angle cosine amplitude n = 1 … (check `tangent-angle`; empty
    /// without), its exact law.
    pub tangent: Vec<TangentReference>,
}

/// The exact stationary law of one tangent-angle cosine amplitude
/// `a_n = √(2/L)∫θ cos(nπs/L) ds` (Gittes et al. 1993,
/// [`BeamModel::tangent_cosine_functional`]): a zero-mean Gaussian whose autocorrelation
/// after `k` steps is `Σ_i u_i m_i^k / Σ_i u_i` (not one exponential: the cosines are not
/// the modes of the beam).
#[derive(Debug, Clone, PartialEq)]
pub struct TangentReference {
    /// The cosine's index n ≥ 1.
    pub n: usize,
    /// The exact variance of the discretized system under its integrator (`aᵀSa`, `a`
    /// the functional's modal image and `S` the discrete stationary covariance), or the
    /// continuum's for data of an unknown discretization.
    pub variance_discrete: f64,
    /// The continuum's `kT L²/(EI n²π²)`.
    pub variance_continuum: f64,
    /// The autocorrelation's terms `(u_i, m_i)`: `u_i = a_i (S a)_i` and the one-step
    /// multiplier `m_i` of mode i (for data of an unknown discretization, the bound
    /// `(1, e^{−λ₁Δt})`: in the continuum the weights are positive and the slowest
    /// elastic rate λ₁ bounds every decay).
    pub terms: Vec<(f64, f64)>,
}

impl TangentReference {
    /// The autocorrelation after `steps` steps (`|·|` bounded by 1).
    pub fn correlation(&self, steps: u64) -> f64 {
        let total: f64 = self.terms.iter().map(|(u, _)| u).sum();
        let k = steps.min(i32::MAX as u64) as i32;
        let sum: f64 = self.terms.iter().map(|(u, m)| u * m.powi(k)).sum();
        if total > 0.0 { sum / total } else { 0.0 }
    }

    /// The smallest stride (in samples `every` steps apart) at which the correlation of
    /// kept samples is at most `limit` in magnitude, capped at `cap`.
    pub fn stride(&self, every: u64, limit: f64, cap: usize) -> usize {
        (1..cap)
            .find(|&k| self.correlation(every.saturating_mul(k as u64)).abs() <= limit)
            .unwrap_or(cap)
    }
}

/// The exact law of one rigid mode's amplitude `r = ψᵀCw` (C-normalized `ψ`, a free
/// end's translation or rotation): a random walk, `⟨(r(t+τ) − r(t))²⟩ = D_discrete·τ`
/// for τ a whole number of steps.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidReference {
    /// What the mode is (`translation`, `rotation about the centre`, …).
    pub name: String,
    /// `2kT·ψᵀΣψ`: Σ the covariance of the standardized noise of the run's noise model
    /// (`C` for the consistent noise, so `2kT`; the element-uniform load misses the
    /// within-element variation of a rotation).
    pub diffusion_discrete: f64,
    /// The continuum's `2kT` (the centre-of-mass MSD `2kT·t/(ξL)` and the angle MSD
    /// `2kT·t/(ξI)` in this normalization).
    pub diffusion_continuum: f64,
    /// Whether the integrator steps the rigid motion (the exact-modal integrator steps
    /// the elastic modes only: its rigid amplitudes stay 0).
    pub simulated: bool,
    /// The physical coordinate of the mode in trajectory files (column suffix): `mean`,
    /// the centre-of-mass deflection (1/L)∫w dx, or `angle`, the rigid rotation's angle
    /// ∫(x − x_p)w dx / I about its pivot x_p (I = ∫(x − x_p)² dx).
    pub coordinate: &'static str,
    /// `r` per unit of the physical coordinate: √(ξL) for `mean`, √(ξI) for `angle`
    /// (`r = ψᵀCw` with `ψᵀCψ = 1`, the elastic modes C-orthogonal to ψ).
    pub coordinate_scale: f64,
}

/// The rigid modes of a filament of parameters `p` with ends `ends`, as
/// `(name, coordinate, coordinate_scale)` of [`RigidReference`], in the order of
/// [`BeamModel::rigid_modes`]: free–free the translation and the rotation about the
/// centre (I = L³/12), hinged–free the rotation about the hinge (I = L³/3).
pub fn rigid_coordinates(
    p: &crate::params::FilamentParams,
    ends: crate::params::Ends,
) -> Vec<(&'static str, &'static str, f64)> {
    let (l, xi) = (p.length, p.drag);
    match (ends.left, ends.right) {
        (End::Free, End::Free) => vec![
            ("translation", "mean", (xi * l).sqrt()),
            (
                "rotation about the centre",
                "angle",
                (xi * l.powi(3) / 12.0).sqrt(),
            ),
        ],
        (End::Hinged, End::Free) | (End::Free, End::Hinged) => vec![(
            "rotation about the hinge",
            "angle",
            (xi * l.powi(3) / 3.0).sqrt(),
        )],
        _ => Vec::new(),
    }
}

/// The probe vector `a_x = Φᵀ p_x` of the deflection at `x`, where `w(x) = p_xᵀ w`
/// (Hermite interpolation) and Φ are the generalized modes: `⟨w(x)w(y)⟩ = a_yᵀ S a_x` for a
/// modal covariance S.
pub fn modal_probe(beam: &BeamModel, vectors: &DMatrix<f64>, x: f64) -> DVector<f64> {
    probe_of(beam.n_dofs(), vectors, |e| beam.deflection_at(e, x))
}

/// The probe vector `Φᵀ p` of the linear functional `value` of a state of `n` DOFs
/// (`value(e_k)` for every unit vector `e_k` gives `p`).
pub(crate) fn probe_of(
    n: usize,
    vectors: &DMatrix<f64>,
    value: impl Fn(&[f64]) -> f64,
) -> DVector<f64> {
    probe_of_transposed(n, &vectors.transpose(), value)
}

/// [`probe_of`] with `Φᵀ` given (`vectors_t`), for many probes of one set of modes: the
/// same product, bit for bit, without an n × n transpose per probe.
pub(crate) fn probe_of_transposed(
    n: usize,
    vectors_t: &DMatrix<f64>,
    value: impl Fn(&[f64]) -> f64,
) -> DVector<f64> {
    let mut e = vec![0.0; n];
    let mut v = DVector::zeros(n);
    for k in 0..n {
        e[k] = 1.0;
        v[k] = value(&e);
        e[k] = 0.0;
    }
    vectors_t * v
}

/// RMS slope (rad) above which the small-slope models are flagged: the geometric terms
/// they neglect (curvature w''/(1 + w'²)^{3/2}, arc length, tan θ ≈ θ) are O(θ²) relative
/// to the retained ones, 3θ² ≈ 12 % of the bending energy density at θ = 0.2.
pub const SMALL_SLOPE_LIMIT: f64 = 0.2;

/// The warning for a run whose measured RMS slope exceeds [`SMALL_SLOPE_LIMIT`], or
/// `None`. `what` names the run; `(rms, x_rel)` is the largest RMS slope and where (x/L).
pub fn small_slope_warning(
    what: &str,
    (rms, x_rel): (f64, f64),
    params: &crate::params::FilamentParams,
) -> Option<String> {
    (rms > SMALL_SLOPE_LIMIT).then(|| {
        format!(
            "{what}: measured RMS slope {rms:.3} rad ({:.1} deg) at x/L = {x_rel:.2} exceeds {SMALL_SLOPE_LIMIT} rad: the small-slope model neglects geometric terms of relative size ~3 theta^2 = {:.0} % here (EI/(kT L) = {}); the checks compare the model with its own exact solution and stay valid, but as a physical filament this one is too floppy for the model",
            rms.to_degrees(),
            300.0 * rms * rms,
            params.bending_rigidity / (params.kt * params.length)
        )
    })
}

/// The largest root-mean-square nodal slope `(rms, node x/L)` from `sums[k]`, the sum of
/// θ² at node k over `n` samples (samples × components). `None` without samples.
pub fn largest_rms_slope(beam: &BeamModel, sums: &[f64], n: usize) -> Option<(f64, f64)> {
    if n == 0 {
        return None;
    }
    sums.iter()
        .zip(beam.mesh().nodes())
        .map(|(sum, x)| ((sum / n as f64).sqrt(), x / beam.params().length))
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Adds θ² of every node of `state` (a deflection vector of `beam`) to `acc`.
pub fn add_slope_squares(beam: &BeamModel, state: &[f64], acc: &mut [f64]) {
    for (node, a) in acc.iter_mut().enumerate() {
        if let Some(i) = beam.node_rotation_index(node) {
            *a += state[i] * state[i];
        }
    }
}

/// The observables of one simulated filament, as the observers record them.
trait Observables {
    /// Modal amplitudes, component-major: `out[c * n_modes + i]`.
    fn modes(&self, out: &mut [f64]);
    /// Deflections at `xs`, component-major: `out[c * xs.len() + j]`.
    fn deflections(&self, xs: &[f64], out: &mut [f64]);
    /// Adds θ² of every node (slope w'; summed over components) to `acc`, if the model
    /// carries nodal rotations (the finite-element model does, the spectral one not).
    fn add_slope_squares(&self, _acc: &mut [f64]) {}
    /// The rigid-mode amplitudes `r_k = ψ_kᵀCw` ([`BeamModel::rigid_amplitudes`]),
    /// component-major `out[c * n_rigid + k]`; nothing for an object without rigid modes.
    fn rigid(&self, _out: &mut [f64]) {}
    /// The values `pᵀw` of the rows `p` of `functionals` (one per column of the state),
    /// component-major `out[c * rows + i]`; nothing for a model without nodal states.
    fn functionals(&self, _functionals: &DMatrix<f64>, _out: &mut [f64]) {}
}

/// A filament being simulated ([`Trajectory`]: advances all its transverse components by
/// one step) that reports the observables.
trait Sampler: Trajectory + Observables {}

impl<S: Trajectory + Observables + ?Sized> Sampler for S {}

/// The modal amplitudes of one component's state `s`, `out[i] = Σ_j P_ij s_j`.
fn project_modes(projector: &DMatrix<f64>, s: &[f64], out: &mut [f64]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = projector.row(i).iter().zip(s).map(|(p, w)| p * w).sum();
    }
}

/// [`LANES`] finite-element trajectories of a θ-scheme in lockstep ([`ComponentBatch`]);
/// each lane reports its observables as [`FemSampler`] does, from the lane's state
/// gathered into `lane` (so every lane is bit-identical to its one-trajectory run).
struct FemBatch<'a> {
    object: &'a FemObject,
    projector: &'a DMatrix<f64>,
    filament: ComponentBatch,
    lane: RefCell<Vec<f64>>,
    probes: ProbeCache,
}

impl BatchTrajectory for FemBatch<'_> {
    fn step(&mut self, rngs: &mut [TrajectoryRng]) {
        self.filament.step(rngs);
    }
    fn lane_is_finite(&self, lane: usize) -> bool {
        self.filament.lane_is_finite(lane)
    }
}

impl FemBatch<'_> {
    /// Calls `f(c, state)` with the state of every component `c` of lane `lane`.
    fn each_component(&self, lane: usize, mut f: impl FnMut(usize, &[f64])) {
        let mut s = self.lane.borrow_mut();
        for c in 0..self.filament.states.len() {
            self.filament.lane_state(c, lane, &mut s);
            f(c, &s);
        }
    }
}

impl Observables for LaneOf<'_, FemBatch<'_>> {
    fn modes(&self, out: &mut [f64]) {
        let m = self.batch.projector.nrows();
        self.batch.each_component(self.lane, |c, s| {
            project_modes(self.batch.projector, s, &mut out[c * m..(c + 1) * m]);
        });
    }
    fn deflections(&self, xs: &[f64], out: &mut [f64]) {
        self.batch.probes.with(self.batch.object, xs, |probes| {
            self.batch.each_component(self.lane, |c, s| {
                let row = &mut out[c * xs.len()..(c + 1) * xs.len()];
                self.batch.object.values_with(probes, s, row);
            });
        });
    }
    fn add_slope_squares(&self, acc: &mut [f64]) {
        if let Some(beam) = self.batch.object.beam() {
            self.batch
                .each_component(self.lane, |_, s| add_slope_squares(beam, s, acc));
        }
    }
    fn rigid(&self, out: &mut [f64]) {
        if let Some(beam) = self.batch.object.beam() {
            let r = beam.ends().rigid_modes();
            self.batch.each_component(self.lane, |c, s| {
                beam.rigid_amplitudes(s, &mut out[c * r..(c + 1) * r]);
            });
        }
    }
    fn functionals(&self, functionals: &DMatrix<f64>, out: &mut [f64]) {
        let m = functionals.nrows();
        self.batch.each_component(self.lane, |c, s| {
            project_modes(functionals, s, &mut out[c * m..(c + 1) * m]);
        });
    }
}

struct FemSampler<'a> {
    object: &'a FemObject,
    projector: &'a DMatrix<f64>,
    filament: Components<Box<dyn Integrator>>,
    probes: ProbeCache,
}

/// The points of the last [`Observables::deflections`] call prepared
/// ([`FemObject::probes`]), so that a sampler evaluated at the same points every sample
/// prepares them once.
#[derive(Default)]
struct ProbeCache(RefCell<Option<Probes>>);

impl ProbeCache {
    /// Calls `f` with `object`'s probes at `xs`, prepared anew if the points changed.
    fn with(&self, object: &FemObject, xs: &[f64], f: impl FnOnce(&Probes)) {
        let mut cache = self.0.borrow_mut();
        if cache.as_ref().is_none_or(|p| p.xs != xs) {
            *cache = Some(object.probes(xs));
        }
        if let Some(p) = cache.as_ref() {
            f(p);
        }
    }
}

impl Trajectory for FemSampler<'_> {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        self.filament.step(rng);
    }
    fn is_finite(&self) -> bool {
        self.filament.is_finite()
    }
}

impl Observables for FemSampler<'_> {
    fn modes(&self, out: &mut [f64]) {
        let m = self.projector.nrows();
        for (c, s) in self.filament.states.iter().enumerate() {
            project_modes(self.projector, s, &mut out[c * m..(c + 1) * m]);
        }
    }
    fn deflections(&self, xs: &[f64], out: &mut [f64]) {
        self.probes.with(self.object, xs, |probes| {
            for (c, s) in self.filament.states.iter().enumerate() {
                let row = &mut out[c * xs.len()..(c + 1) * xs.len()];
                self.object.values_with(probes, s, row);
            }
        });
    }
    fn add_slope_squares(&self, acc: &mut [f64]) {
        if let Some(beam) = self.object.beam() {
            for s in &self.filament.states {
                add_slope_squares(beam, s, acc);
            }
        }
    }
    fn rigid(&self, out: &mut [f64]) {
        if let Some(beam) = self.object.beam() {
            let r = beam.ends().rigid_modes();
            for (c, s) in self.filament.states.iter().enumerate() {
                beam.rigid_amplitudes(s, &mut out[c * r..(c + 1) * r]);
            }
        }
    }
    fn functionals(&self, functionals: &DMatrix<f64>, out: &mut [f64]) {
        let m = functionals.nrows();
        for (c, s) in self.filament.states.iter().enumerate() {
            project_modes(functionals, s, &mut out[c * m..(c + 1) * m]);
        }
    }
}

/// A finite-element object stepped in its generalized modes ([`ModalPath`]): the state
/// of each component is the vector of modal amplitudes, the checked modes first.
struct ModalSampler<'a> {
    path: &'a ModalPath,
    n_modes: usize,
    filament: Components<ModalStep>,
}

impl Trajectory for ModalSampler<'_> {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        self.filament.step(rng);
    }
    fn is_finite(&self) -> bool {
        self.filament.is_finite()
    }
}

impl Observables for ModalSampler<'_> {
    fn modes(&self, out: &mut [f64]) {
        let m = self.n_modes;
        for (c, s) in self.filament.states.iter().enumerate() {
            out[c * m..(c + 1) * m].copy_from_slice(&s[..m]);
        }
    }
    fn deflections(&self, xs: &[f64], out: &mut [f64]) {
        for (c, s) in self.filament.states.iter().enumerate() {
            for (j, &x) in xs.iter().enumerate() {
                out[c * xs.len() + j] = self
                    .path
                    .probe(x)
                    .map_or(f64::NAN, |p| p.iter().zip(s).map(|(a, q)| a * q).sum());
            }
        }
    }
}

struct SpectralSampler {
    sims: Vec<ModalSimulator>,
    n_modes: usize,
}

impl Trajectory for SpectralSampler {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        for s in &mut self.sims {
            s.step(rng);
        }
    }
    fn is_finite(&self) -> bool {
        self.sims
            .iter()
            .all(|s| s.amplitudes().iter().all(|a| a.is_finite()))
    }
}

impl Observables for SpectralSampler {
    fn modes(&self, out: &mut [f64]) {
        for (c, s) in self.sims.iter().enumerate() {
            out[c * self.n_modes..(c + 1) * self.n_modes]
                .copy_from_slice(&s.amplitudes()[..self.n_modes]);
        }
    }
    fn deflections(&self, xs: &[f64], out: &mut [f64]) {
        for (c, s) in self.sims.iter().enumerate() {
            for (j, &x) in xs.iter().enumerate() {
                out[c * xs.len() + j] = s.deflection(x);
            }
        }
    }
}

/// The membrane's exact modal simulator as a sampler: one component, the checked modes'
/// amplitudes, the height on the midline y = b/2.
struct MembraneSampler {
    sim: MembraneSimulator,
    checked: Vec<usize>,
}

impl Trajectory for MembraneSampler {
    fn step(&mut self, rng: &mut TrajectoryRng) {
        self.sim.step(rng);
    }
    fn is_finite(&self) -> bool {
        self.sim.amplitudes().iter().all(|a| a.is_finite())
    }
}

impl Observables for MembraneSampler {
    fn modes(&self, out: &mut [f64]) {
        for (o, &j) in out.iter_mut().zip(&self.checked) {
            *o = self.sim.amplitudes()[j];
        }
    }
    fn deflections(&self, xs: &[f64], out: &mut [f64]) {
        let y = 0.5 * self.sim.membrane().params.height;
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = self.sim.height(x, y);
        }
    }
}

/// The observer of [`LinearRun::trace`]: every sample, the checked modal amplitudes and
/// the profile deflections (component-major).
struct TraceObserver<'r> {
    profile_x: &'r [f64],
    m: Vec<f64>,
    p: Vec<f64>,
    out: Vec<Vec<f64>>,
}

impl<S: Observables + ?Sized> Observer<S> for TraceObserver<'_> {
    fn on_sample(&mut self, _: usize, _: u64, sampler: &S) {
        sampler.modes(&mut self.m);
        sampler.deflections(self.profile_x, &mut self.p);
        self.out
            .push(self.m.iter().chain(&self.p).copied().collect());
    }
}

/// The observer of [`LinearRun::simulate`]: the two-time products on every step, each
/// series at its own cadence after the burn-in.
struct Recorder<'r> {
    run: &'r LinearRun,
    rec: TrajectoryRecord,
    /// w(x, t) at the earlier time of each two-time point, per component.
    at_t: Vec<f64>,
    buf_m: Vec<f64>,
    buf_p: Vec<f64>,
    buf_r: Vec<f64>,
    buf_g: Vec<f64>,
    one: Vec<f64>,
}

impl<'r> Recorder<'r> {
    fn new(run: &'r LinearRun, sampled_steps: u64) -> Self {
        let r = &run.reference;
        let (nm, c, np, ntt) = (
            r.modes.len(),
            run.components,
            r.profile_x.len(),
            r.two_time.len(),
        );
        let cap = |every: u64| ((sampled_steps / every) as usize).min(MAX_SAMPLES);
        Recorder {
            run,
            rec: TrajectoryRecord {
                modes: (0..c * nm)
                    .map(|k| Vec::with_capacity(cap(run.mode_every[k % nm])))
                    .collect(),
                profile: vec![Vec::with_capacity(cap(run.profile_every)); c * np],
                rigid: vec![
                    Vec::with_capacity(cap(run.profile_every));
                    c * run.reference.rigid.len()
                ],
                tangent: vec![
                    Vec::with_capacity(cap(run.profile_every));
                    c * run.reference.tangent.len()
                ],
                two_time: vec![0.0; c * ntt],
                slope_squares: vec![0.0; run.n_nodes()],
                slope_samples: 0,
            },
            at_t: vec![0.0; c * ntt],
            buf_m: vec![0.0; c * nm],
            buf_p: vec![0.0; c * np],
            buf_r: vec![0.0; c * run.reference.rigid.len()],
            buf_g: vec![0.0; c * run.reference.tangent.len()],
            one: vec![0.0; c],
        }
    }
}

impl<S: Observables + ?Sized> Observer<S> for Recorder<'_> {
    fn on_step(&mut self, _: usize, step: u64, sampler: &S) {
        let tt = &self.run.reference.two_time;
        for (j, q) in tt.iter().enumerate() {
            if step == q.t_step {
                sampler.deflections(&[q.x], &mut self.one);
                for k in 0..self.run.components {
                    self.at_t[k * tt.len() + j] = self.one[k];
                }
            }
            if step == q.eta_step {
                sampler.deflections(&[q.y], &mut self.one);
                for k in 0..self.run.components {
                    self.rec.two_time[k * tt.len() + j] = self.at_t[k * tt.len() + j] * self.one[k];
                }
            }
        }
    }

    fn on_sample(&mut self, _: usize, since: u64, sampler: &S) {
        let run = self.run;
        let nm = run.reference.modes.len();
        let rec = &mut self.rec;
        if run.mode_every.iter().any(|&e| since.is_multiple_of(e)) {
            sampler.modes(&mut self.buf_m);
            for (k, s) in rec.modes.iter_mut().enumerate() {
                if since.is_multiple_of(run.mode_every[k % nm]) && s.len() < MAX_SAMPLES {
                    s.push(self.buf_m[k]);
                }
            }
        }
        if since.is_multiple_of(run.profile_every)
            && rec.profile.first().is_some_and(|s| s.len() < MAX_SAMPLES)
        {
            sampler.deflections(&run.reference.profile_x, &mut self.buf_p);
            for (s, v) in rec.profile.iter_mut().zip(&self.buf_p) {
                s.push(*v);
            }
            sampler.add_slope_squares(&mut rec.slope_squares);
            rec.slope_samples += 1;
            if !rec.rigid.is_empty() {
                sampler.rigid(&mut self.buf_r);
                for (s, v) in rec.rigid.iter_mut().zip(&self.buf_r) {
                    s.push(*v);
                }
            }
            if let Some(g) = run.tangent_functionals() {
                sampler.functionals(g, &mut self.buf_g);
                for (s, v) in rec.tangent.iter_mut().zip(&self.buf_g) {
                    s.push(*v);
                }
            }
        }
    }
}

/// The exact diffusion laws of the rigid modes of `beam` ([`RigidReference`]) under the
/// noise model `noise`, stepped by `integrator`.
///
/// # Errors
/// As [`NoiseGenerator::new`](crate::fem::NoiseGenerator::new).
fn rigid_references(
    beam: &BeamModel,
    noise: NoiseModel,
    integrator: IntegratorKind,
) -> Result<Vec<RigidReference>> {
    let rigid = beam.rigid_modes();
    if rigid.is_empty() {
        return Ok(Vec::new());
    }
    let sigma = crate::fem::NoiseGenerator::new(noise, beam)?.covariance();
    let names = rigid_coordinates(beam.params(), beam.ends());
    let kt = beam.kt();
    Ok(rigid
        .iter()
        .zip(names)
        .map(|(psi, (name, coordinate, coordinate_scale))| {
            let v = DVector::from_column_slice(psi);
            RigidReference {
                coordinate,
                coordinate_scale,
                name: name.to_string(),
                diffusion_discrete: 2.0 * kt * v.dot(&(&sigma * &v)),
                diffusion_continuum: 2.0 * kt,
                simulated: !integrator.needs_modes(),
            }
        })
        .collect())
}

/// The exact laws of the tangent-angle cosine amplitudes n = 1 … `count` of `beam`
/// ([`TangentReference`]) under the discrete law `law` of its generalized modes (`vectors_t`:
/// `Φᵀ`; the values NaN without a law), and the functionals' rows that sample them.
fn tangent_references(
    beam: &BeamModel,
    vectors_t: &DMatrix<f64>,
    law: Option<&DiscreteLaw>,
    count: usize,
) -> (Vec<TangentReference>, Option<DMatrix<f64>>) {
    let p = beam.params();
    let n_dofs = beam.n_dofs();
    let mut rows = DMatrix::zeros(count, n_dofs);
    let mut refs = Vec::with_capacity(count);
    for n in 1..=count {
        let f = beam.tangent_cosine_functional(n);
        rows.row_mut(n - 1).copy_from_slice(&f);
        let (variance_discrete, terms) = match law {
            Some(law) => {
                let a = probe_of_transposed(n_dofs, vectors_t, |e| {
                    f.iter().zip(e).map(|(x, y)| x * y).sum()
                });
                (
                    a.dot(&(&law.stationary * &a)),
                    autocovariance_terms(law, &a),
                )
            }
            None => (f64::NAN, Vec::new()),
        };
        let q = n as f64 * std::f64::consts::PI / p.length;
        refs.push(TangentReference {
            n,
            variance_discrete,
            variance_continuum: p.kt / (p.bending_rigidity * q * q),
            terms,
        });
    }
    (refs, Some(rows))
}

/// The terms `(u_i, m_i)`, `u_i = a_i (S a)_i`, of the autocovariance after `s` steps of
/// the functional with modal image `a` under `law`: `aᵀ diag(m^s) S a = Σ u_i m_i^s` (the
/// modal propagator is diagonal; the noise may correlate the modes, so a `u_i` may be
/// negative).
fn autocovariance_terms(law: &DiscreteLaw, a: &DVector<f64>) -> Vec<(f64, f64)> {
    let sa = &law.stationary * a;
    a.iter()
        .zip(sa.iter())
        .zip(&law.multipliers)
        .map(|((ai, si), &m)| (ai * si, m))
        .collect()
}

/// `rates` × `factor` (the rates themselves, bit for bit, at factor 1).
fn scaled(rates: &[f64], factor: f64) -> Vec<f64> {
    if factor == 1.0 {
        rates.to_vec()
    } else {
        rates.iter().map(|r| r * factor).collect()
    }
}

/// Greatest common divisor (the cadence at which every series' own cadence is met).
fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Largest number of samples of one series in one trajectory: fast modes are recorded
/// at their own cadence over the first `MAX_SAMPLES` samples only, which bounds memory
/// while keeping their relative error far below that of the slow modes.
pub const MAX_SAMPLES: usize = 1 << 16;

/// What one trajectory recorded.
#[derive(Debug, Clone, Default)]
pub struct TrajectoryRecord {
    /// Modal amplitude series: `modes[c * n_modes + i]` is the series of mode i+1 of
    /// component c, sampled every `mode_every[i]` steps after burn-in, at most
    /// [`MAX_SAMPLES`] samples.
    pub modes: Vec<Vec<f64>>,
    /// Deflection series at the profile points: `profile[c * n_points + j]`, every
    /// `profile_every` steps, at most [`MAX_SAMPLES`] samples.
    pub profile: Vec<Vec<f64>>,
    /// Rigid-mode amplitude series `rigid[c * n_rigid + k]` (issue #29: free ends),
    /// sampled with the profile (every `profile_every` steps); empty without rigid modes.
    pub rigid: Vec<Vec<f64>>,
    /// Tangent-angle cosine amplitude series `tangent[c * n_tangent + i]` (cosine
    /// n = i + 1, [`TangentReference`]), sampled with the profile; empty unless checked.
    pub tangent: Vec<Vec<f64>>,
    /// Two-time products w(x,t)·w(y,η), `two_time[c * n_points + j]`.
    pub two_time: Vec<f64>,
    /// Per node, the sum of θ² = w'² over the profile samples and components (empty for
    /// the spectral model).
    pub slope_squares: Vec<f64>,
    /// Number of profile samples summed in `slope_squares`.
    pub slope_samples: usize,
}

/// Steps (or data rows) between the samples of a mode of rate `rate` at spacing `dt`:
/// about two per relaxation time, at least one. The cadence of [`LinearRun::mode_every`],
/// for a simulation (`dt` its step) and for data (`dt` its row spacing, as `check` reads
/// it).
pub fn sample_every(rate: f64, dt: f64) -> u64 {
    ((0.5 / rate) / dt).floor().max(1.0) as u64
}

/// A prepared run of a linear scene: model, references and sampling plan.
pub struct LinearRun {
    /// The run specification.
    pub spec: RunSpec,
    /// Number of transverse components (1 in 2D, 2 in 3D).
    pub components: usize,
    /// Exact references.
    pub reference: LinearReference,
    /// Steps between samples of each checked mode.
    pub mode_every: Vec<u64>,
    /// Steps between samples of the profile deflections.
    pub profile_every: u64,
    /// Burn-in steps.
    pub burn_in_steps: u64,
    /// Per checked mode, the factor that turns the model's modal amplitude into the
    /// sine-basis amplitude aₙ of w(x) = Σ aₙ sin(nπx/L) (the trajectory data format,
    /// [`crate::data`]): ±√(2/(ξL)) for the finite-element modes (normalized by the
    /// damping matrix, signed so that the mode is positive at x = L/(2n)), 1 for the
    /// spectral model.
    pub amplitude_scale: Vec<f64>,
    model: Model,
    /// The injected fault of the scene ([`crate::fault`]; test and `faults` builds only).
    #[cfg(any(test, feature = "faults"))]
    fault: Option<crate::fault::Fault>,
}

enum Model {
    Fem {
        object: FemObject,
        modes: Option<GeneralizedModes>,
        projector: DMatrix<f64>,
        noise: NoiseModel,
        integrator: IntegratorKind,
        /// The O(n) path in modal coordinates, where the object's modes come without a
        /// dense transform and the noise is consistent (the plate).
        modal: Option<ModalPath>,
        /// The rows `p_n` of the tangent-angle cosine amplitudes `p_nᵀw`
        /// ([`BeamModel::tangent_cosine_functional`]), when checked.
        tangent: Option<Box<DMatrix<f64>>>,
    },
    Spectral {
        beam: HingedBeam,
        n_modes: usize,
    },
    /// The membrane's exact modal simulator ([`MembraneSimulator`], at rest), reporting
    /// the amplitudes of its modes `checked` (indices into its mode list).
    SpectralMembrane {
        simulator: Box<MembraneSimulator>,
        checked: Vec<usize>,
    },
    /// No model: the references of another program's data ([`LinearRun::for_data`]).
    Data,
}

/// The O(n) path of a run ([`ModalStep`]: the integrator in the generalized modes with
/// consistent noise): the rates of every mode (the checked ones first) and, at every
/// position an observer reads, the modal image of the probe, so that the field there is
/// `probeᵀq`.
struct ModalPath {
    rates: Vec<f64>,
    probes: Vec<(f64, DVector<f64>)>,
}

impl ModalPath {
    /// The modal probe at position `x` (one of the prepared positions).
    fn probe(&self, x: f64) -> Option<&DVector<f64>> {
        self.probes.iter().find(|(p, _)| *p == x).map(|(_, v)| v)
    }
}

/// What the preparation of a model yields besides the sampling plan.
struct Prepared {
    model: Model,
    amplitude_scale: Vec<f64>,
    modes: Vec<ModeReference>,
    profile_discrete: Vec<f64>,
    profile_terms: Vec<Vec<(f64, f64)>>,
    two_time: Vec<TwoTimeReference>,
    max_rate: f64,
    rigid: Vec<RigidReference>,
    tangent: Vec<TangentReference>,
}

/// The quantities shared by the preparation steps of a run.
struct Setup<'s> {
    scene: &'s Scene,
    spec: &'s RunSpec,
    continuum: Continuum,
    tau1: f64,
    dt: f64,
    profile_x: Vec<f64>,
    /// Whether the finite elements' discrete reference values are computed (the
    /// O(n³) [`DiscreteLaw`]); `false` for [`LinearRun::prepare_for_writing`].
    values: bool,
}

impl Setup<'_> {
    /// Number of steps of a duration (physical time), rounded.
    fn steps(&self, t: f64) -> u64 {
        (t / self.dt).round() as u64
    }

    /// The exact modal simulator of eq. (2): its references are the continuum's, the
    /// profile truncated to the simulated modes.
    fn spectral(&self) -> Result<Prepared> {
        let continuum = match &self.continuum {
            // Validation keeps the spectral model to hinged ends.
            Continuum::Filament(beam) => &HingedBeam::new(beam.params)?,
            Continuum::Membrane { membrane, modes } => {
                return self.spectral_membrane(membrane, modes);
            }
        };
        let dt = self.dt;
        let n_modes = self.scene.mesh.elements;
        let mut refs = Vec::new();
        for n in 1..=self.scene.sampling.modes {
            let rate = continuum.mode_rate(n);
            let var = continuum.mode_variance(n);
            refs.push(ModeReference {
                n,
                variance_discrete: var,
                variance_equipartition: var,
                variance_continuum: var,
                multiplier: (-rate * dt).exp(),
                rate_discrete: Some(rate),
                rate_continuum: rate,
                label: None,
            });
        }
        // The simulator carries n_modes modes: its exact profile is the truncated sum, of
        // independent AR(1) modes (scale · sin²(nπx/L)/n⁴ each).
        let profile_discrete = self
            .profile_x
            .iter()
            .map(|&x| continuum.profile_variance_series(x, n_modes).value)
            .collect();
        let profile_terms = self
            .profile_x
            .iter()
            .map(|&x| {
                let u = x / continuum.params.length;
                (1..=n_modes)
                    .map(|n| {
                        let s = crate::spectral::sin_pi(n as f64 * u);
                        let weight = continuum.mode_variance(n) * s * s;
                        (weight, (-continuum.mode_rate(n) * dt).exp())
                    })
                    .collect()
            })
            .collect();
        let length = self.scene.filament.length;
        let mut tt = Vec::new();
        for q in &self.scene.sampling.two_time {
            let (x, y) = (q[0] * length, q[1] * length);
            let (ts, es) = (self.steps(q[2] * self.tau1), self.steps(q[3] * self.tau1));
            let (t, eta) = (ts as f64 * dt, es as f64 * dt);
            tt.push(TwoTimeReference {
                x,
                y,
                t,
                eta,
                t_step: ts,
                eta_step: es,
                discrete: continuum
                    .correlation_truncated(x, y, t, eta, n_modes)?
                    .value,
                variances: (
                    continuum.correlation_truncated(x, x, t, t, n_modes)?.value,
                    continuum
                        .correlation_truncated(y, y, eta, eta, n_modes)?
                        .value,
                ),
                continuum: continuum.correlation(x, y, t, eta, 1e-12)?.value,
            });
        }
        Ok(Prepared {
            rigid: Vec::new(),
            tangent: Vec::new(),
            amplitude_scale: vec![1.0; self.scene.sampling.modes],
            model: Model::Spectral {
                beam: *continuum,
                n_modes,
            },
            modes: refs,
            profile_discrete,
            profile_terms,
            two_time: tt,
            max_rate: continuum.mode_rate(n_modes),
        })
    }

    /// The membrane's exact modal simulator over the index rectangle `mesh.elements` ×
    /// `mesh.elements_y`: its references are the continuum's per mode, and the exact sums
    /// over its own modes for the profile and the two-time points.
    fn spectral_membrane(
        &self,
        membrane: &Membrane,
        checked_modes: &[MembraneMode],
    ) -> Result<Prepared> {
        let dt = self.dt;
        let list = MembraneSimulator::index_rectangle(
            membrane,
            self.scene.mesh.elements,
            self.scene.mesh.elements_along_y(),
        )?;
        let simulator = MembraneSimulator::new(*membrane, list, dt)?;
        let mut checked = Vec::with_capacity(checked_modes.len());
        let mut refs = Vec::with_capacity(checked_modes.len());
        for (i, m) in checked_modes.iter().enumerate() {
            let j = simulator.modes().iter().position(|s| s == m).ok_or_else(|| {
                Error::invalid(
                    "sampling.modes",
                    checked_modes.len(),
                    format!(
                        "at most the modes the simulator carries (mode ({}, {}) is beyond mesh.elements x mesh.elements_y)",
                        m.m, m.n
                    ),
                )
            })?;
            checked.push(j);
            let (rate, var) = (membrane.mode_rate(*m), membrane.mode_variance(*m));
            refs.push(ModeReference {
                n: i + 1,
                variance_discrete: var,
                variance_equipartition: var,
                variance_continuum: var,
                multiplier: (-rate * dt).exp(),
                rate_discrete: Some(rate),
                rate_continuum: rate,
                label: Some(*m),
            });
        }
        let y = 0.5 * membrane.params.height;
        let profile_discrete = self
            .profile_x
            .iter()
            .map(|&x| simulator.covariance((x, y), (x, y)))
            .collect();
        let profile_terms = self
            .profile_x
            .iter()
            .map(|&x| simulator.point_terms((x, y)))
            .collect();
        let length = membrane.params.width;
        let mut two_time = Vec::new();
        for q in &self.scene.sampling.two_time {
            let (x, x2) = (q[0] * length, q[1] * length);
            let (ts, es) = (self.steps(q[2] * self.tau1), self.steps(q[3] * self.tau1));
            let (t, eta) = (ts as f64 * dt, es as f64 * dt);
            two_time.push(TwoTimeReference {
                x,
                y: x2,
                t,
                eta,
                t_step: ts,
                eta_step: es,
                discrete: simulator.correlation_from_rest((x, y), (x2, y), t, eta)?,
                variances: (
                    simulator.correlation_from_rest((x, y), (x, y), t, t)?,
                    simulator.correlation_from_rest((x2, y), (x2, y), eta, eta)?,
                ),
                continuum: self.continuum.correlation(x, x2, t, eta)?,
            });
        }
        let max_rate = simulator
            .modes()
            .iter()
            .map(|m| membrane.mode_rate(*m))
            .fold(0.0, f64::max);
        Ok(Prepared {
            rigid: Vec::new(),
            tangent: Vec::new(),
            amplitude_scale: vec![1.0; checked.len()],
            model: Model::SpectralMembrane {
                simulator: Box::new(simulator),
                checked,
            },
            modes: refs,
            profile_discrete,
            profile_terms,
            two_time,
            max_rate,
        })
    }

    /// The finite-element filament: fails early above the stability limit, then the
    /// exact discrete references from the generalized modes
    /// ([`DiscreteLaw`]: the same law whichever object assembled the system).
    fn fem(&self) -> Result<Prepared> {
        let (spec, dt) = (self.spec, self.dt);
        let object = self.fem_object()?;
        let system = object.system();
        // An explicit step above its limit, or a beam's Crank–Nicolson step whose fastest
        // multiplier rounds to −1, fails at once (λ_max by an O(n) inertia bisection),
        // before the O(n³) eigen-decomposition. (A plate's separable modes cost less
        // than its wide-band bisection: its Crank–Nicolson step is checked on them.)
        let beam = !matches!(object, FemObject::Plate { .. });
        let limited = |kind: IntegratorKind| {
            kind.stability_limit(1.0).is_some() || (beam && kind.rounding_limit(1.0).is_some())
        };
        if limited(spec.integrator) {
            build_integrator(
                spec.integrator,
                system,
                spec.noise,
                dt,
                object.max_rate()?,
                None,
            )?;
        }
        let gm = object.modes()?;
        let max_rate = gm.rates.max();
        // Fails early with the stability limit if the step is too large.
        build_integrator(spec.integrator, system, spec.noise, dt, max_rate, Some(&gm))?;
        // The law's O(n³) covariances only where reference values are wanted
        // (`Setup::values`).
        let law = self
            .values
            .then(|| DiscreteLaw::new(system, &gm, spec.integrator, spec.noise, dt))
            .transpose()?;
        let law = law.as_ref();
        let refs = self.fem_mode_references(law, &gm.rates, system.kt());
        // Probe vectors: w(x) = p_xᵀ w, and their images Φᵀ p_x in modal space.
        let vectors_t = gm.vectors.transpose();
        let probe =
            |x: f64| probe_of_transposed(system.n_dofs(), &vectors_t, |e| object.value_at(e, x));
        // ⟨w²(x)⟩ = aᵀSa, and the terms of its autocovariance.
        let (profile_discrete, profile_terms) = self
            .profile_x
            .iter()
            .map(|&x| match law {
                Some(law) => {
                    let a = probe(x);
                    (law.point_covariance(&a, &a), autocovariance_terms(law, &a))
                }
                None => (f64::NAN, Vec::new()),
            })
            .unzip();
        let two_time = self.fem_two_time(law, &probe)?;
        let modal = self.modal_path(&object, &gm, &two_time, &probe);
        let projector = gm.projector(system, self.scene.sampling.modes);
        let keep_modes = spec.integrator.needs_modes();
        let rigid = match &object {
            FemObject::Beam(beam) => rigid_references(beam, spec.noise, spec.integrator)?,
            FemObject::Chain(_) | FemObject::Plate { .. } => Vec::new(),
        };
        let (tangent, tangent_rows) = match object.beam() {
            Some(beam) if spec.checks(self.scene).contains(&CheckKind::TangentAngle) => {
                tangent_references(beam, &vectors_t, law, self.scene.sampling.modes)
            }
            _ => (Vec::new(), None),
        };
        let amplitude_scale = self.amplitude_scale(&object, &probe)?;
        Ok(Prepared {
            rigid,
            tangent,
            amplitude_scale,
            model: Model::Fem {
                object,
                modes: keep_modes.then_some(gm),
                projector,
                noise: spec.noise,
                integrator: spec.integrator,
                modal,
                tangent: tangent_rows.map(Box::new),
            },
            modes: refs,
            profile_discrete,
            profile_terms,
            two_time,
            max_rate,
        })
    }

    /// The finite-element model of the continuum: the beam, or the plate of a membrane
    /// (under an injected shared-model fault, the faulty one).
    ///
    /// # Errors
    /// Assembly failures; a checked mode the plate's mesh does not resolve.
    fn fem_object(&self) -> Result<FemObject> {
        let p = self.scene.filament;
        Ok(match &self.continuum {
            Continuum::Filament(_) if self.scene.mesh.scheme == MeshScheme::Chain => {
                FemObject::Chain(Box::new(ChainModel::new(p, self.scene.mesh.elements)?))
            }
            Continuum::Filament(_) => {
                let beam =
                    BeamModel::with_ends(p, self.scene.mesh.build(p.length)?, self.scene.ends)?;
                #[cfg(any(test, feature = "faults"))]
                let beam = crate::fault::shared_model(self.scene.fault, beam)?;
                FemObject::Beam(Box::new(beam))
            }
            Continuum::Membrane { membrane, modes } => FemObject::plate(
                #[cfg(any(test, feature = "faults"))]
                &Membrane::new(crate::fault::shared_membrane(
                    self.scene.fault,
                    membrane.params,
                ))?,
                #[cfg(not(any(test, feature = "faults")))]
                membrane,
                self.scene.mesh.elements,
                self.scene.mesh.elements_along_y(),
                modes.clone(),
            )?,
        })
    }

    /// The trajectory data format's amplitudes, per checked mode: the C-normalized modal
    /// coordinate q of a mode whose field is close to c·φ (φ the continuum mode,
    /// ξ∫(cφ)² = 1) is the amplitude a = c·q of φ, c = 1/√(ξ‖φ‖²): √(2/(ξL)) for the
    /// filament's sines (the hinged beam's signed as the sine at L/(2n), by `probe`),
    /// 1/√(ξ‖φ‖²) for a membrane's real modes (‖φ‖² = A/4 or A/2, (M3); signs free).
    fn amplitude_scale(
        &self,
        object: &FemObject,
        probe: &dyn Fn(f64) -> DVector<f64>,
    ) -> Result<Vec<f64>> {
        let p = self.scene.filament;
        Ok(match object {
            // Other ends: the modes are signed by their continuum mode already
            // (generalized_modes), whose normalization ∫φ² = L/2 is the sine's.
            FemObject::Beam(b) if !b.ends().is_hinged() => {
                vec![(2.0 / (p.drag * p.length)).sqrt(); self.scene.sampling.modes]
            }
            // The chain's modes are signed by their sine already (ChainModel::modes).
            FemObject::Chain(_) => {
                vec![(2.0 / (p.drag * p.length)).sqrt(); self.scene.sampling.modes]
            }
            FemObject::Beam(_) => {
                let scale = (2.0 / (p.drag * p.length)).sqrt();
                (1..=self.scene.sampling.modes)
                    .map(|n| {
                        let at = probe(p.length / (2.0 * n as f64))[n - 1];
                        if at < 0.0 { -scale } else { scale }
                    })
                    .collect()
            }
            FemObject::Plate { plate, .. } => {
                let membrane = Membrane::new(*plate.params())?;
                let scale = 1.0 / (membrane.params.drag * membrane.mode_norm_sq()).sqrt();
                vec![scale; self.scene.sampling.modes]
            }
        })
    }

    /// The references of every checked mode under the discrete law `law`, with the
    /// continuum's beside them (thermal energy `kt`).
    fn fem_mode_references(
        &self,
        law: Option<&DiscreteLaw>,
        rates: &DVector<f64>,
        kt: f64,
    ) -> Vec<ModeReference> {
        (0..self.scene.sampling.modes)
            .map(|i| {
                let n = i + 1;
                // The law's multiplier, equipartition and rate, bit for bit
                // ([`DiscreteLaw::new`], [`decay_rate`]).
                let (m, _) = self.spec.integrator.modal_form(rates[i], self.dt, kt);
                ModeReference {
                    n,
                    variance_discrete: law.map_or(f64::NAN, |law| law.mode_variance(i)),
                    variance_equipartition: kt / rates[i],
                    variance_continuum: kt / self.continuum.mode_rate(n),
                    multiplier: m,
                    rate_discrete: decay_rate(m, self.dt),
                    rate_continuum: self.continuum.mode_rate(n),
                    label: self.continuum.mode_label(n),
                }
            })
            .collect()
    }

    /// The O(n) modal path of a plate with consistent noise ([`ModalPath`]): its modes
    /// are separable, so its runs step in modal coordinates, with the modal probes at
    /// every position an observer reads (profile and two-time points, and the mesh
    /// nodes on the sampling line that `run` writes); `None` for the beam and for the
    /// element-uniform load (the banded nodal path, the general one).
    fn modal_path(
        &self,
        object: &FemObject,
        gm: &GeneralizedModes,
        two_time: &[TwoTimeReference],
        probe: &dyn Fn(f64) -> DVector<f64>,
    ) -> Option<ModalPath> {
        let plate = matches!(object, FemObject::Plate { .. });
        (plate && self.spec.noise == NoiseModel::Consistent).then(|| {
            let mut xs = self.profile_x.clone();
            xs.extend(two_time.iter().flat_map(|q| [q.x, q.y]));
            xs.extend(object.line_nodes());
            xs.sort_by(f64::total_cmp);
            xs.dedup();
            ModalPath {
                rates: gm.rates.iter().copied().collect(),
                probes: xs.into_iter().map(|x| (x, probe(x))).collect(),
            }
        })
    }

    /// The two-time references of the finite-element filament from rest, under the
    /// discrete law `law`, with the modal probe vectors `probe(x)`.
    fn fem_two_time(
        &self,
        law: Option<&DiscreteLaw>,
        probe: &dyn Fn(f64) -> DVector<f64>,
    ) -> Result<Vec<TwoTimeReference>> {
        let (length, dt, tau1) = (self.continuum.line_length(), self.dt, self.tau1);
        let mut tt = Vec::new();
        for q in &self.scene.sampling.two_time {
            let (x, y) = (q[0] * length, q[1] * length);
            let (ts, es) = (
                self.steps(q[2] * tau1).max(1),
                self.steps(q[3] * tau1).max(1),
            );
            let (t, eta) = (ts as f64 * dt, es as f64 * dt);
            let (discrete, variances) = match law {
                Some(law) => {
                    let (ax, ay) = (probe(x), probe(y));
                    (
                        law.two_time(ts, es, &ax, &ay),
                        (
                            law.two_time(ts, ts, &ax, &ax),
                            law.two_time(es, es, &ay, &ay),
                        ),
                    )
                }
                None => (f64::NAN, (f64::NAN, f64::NAN)),
            };
            tt.push(TwoTimeReference {
                x,
                y,
                t,
                eta,
                t_step: ts,
                eta_step: es,
                discrete,
                variances,
                continuum: self.continuum.correlation(x, y, t, eta)?,
            });
        }
        Ok(tt)
    }
}

impl LinearRun {
    /// Prepares run `spec` of `scene`: builds the model, checks the time step against the
    /// stability limit, and computes every exact reference.
    ///
    /// # Errors
    /// [`Error::UnstableTimeStep`] for an explicit integrator above its limit; numerical
    /// failures of the reference computations.
    pub fn prepare(scene: &Scene, spec: &RunSpec) -> Result<LinearRun> {
        Self::prepare_with(scene, spec, true)
    }

    /// Prepares run `spec` of `scene` to write its trajectories only (`run`): as
    /// [`Self::prepare`], the same model, integrator, modes and row cadence (the
    /// trajectories are bit for bit those of a prepared run), but without the finite
    /// elements' discrete reference values (variances, profile, two-time and tangent
    /// references are NaN): their O(n³) law is what a large mesh's preparation costs.
    ///
    /// # Errors
    /// As [`Self::prepare`].
    pub fn prepare_for_writing(scene: &Scene, spec: &RunSpec) -> Result<LinearRun> {
        Self::prepare_with(scene, spec, false)
    }

    /// Refuses run `k` of `scene` (this run) if a checked mode does not forget its start
    /// within the burn-in ([`Self::unforgetting_mode`]): [`Error::Scene`] naming
    /// `runs[k].dt_tau1`, the mode, its multiplier and memory, and about the largest
    /// dt_tau1 that would serve.
    ///
    /// # Errors
    /// As described.
    pub fn require_forgetting(&self, scene: &Scene, k: usize) -> Result<()> {
        let Some(u) = self.unforgetting_mode() else {
            return Ok(());
        };
        let tau1 = scene.tau1();
        Err(Error::Scene {
            file: scene.path.clone(),
            key: format!("runs[{k}].dt_tau1"),
            message: format!(
                "must be below about {:.3e} for this run: at {} ({}) checked mode {} has the one-step multiplier {:.6} and keeps {:.3e} of its start after the burn-in's {} steps, more than the slowest mode's {:.3e}, so its stationary references would not hold in the sampled rows; lower dt_tau1, or use the exact-modal or backward-euler integrator",
                u.dt_bound / tau1,
                self.spec.dt_tau1,
                self.spec.integrator,
                u.n,
                u.multiplier,
                u.memory,
                u.burn_in_steps,
                u.slowest
            ),
        })
    }

    /// A checked mode that the burn-in leaves remembering its start (rest) more than the
    /// slowest checked mode does, because its one-step multiplier m is near −1
    /// (Crank–Nicolson far past λΔt = 2, as a membrane near buckling, whose τ₁ is long,
    /// gets at a fixed dt_tau1): after the burn-in's N steps it keeps |m|^N of its
    /// start, and the stationary references of the checks do not yet hold. Only a mode
    /// that keeps more than 10⁻³ and more than the slowest positive-multiplier mode (whose
    /// memory `sampling.burn_in_tau1` sets) counts. `None` when every mode forgets.
    pub fn unforgetting_mode(&self) -> Option<UnforgettingMode> {
        let n = self.burn_in_steps as f64;
        let memory = |m: f64| m.abs().powf(n);
        let slowest = self
            .reference
            .modes
            .iter()
            .filter(|m| m.multiplier > 0.0)
            .map(|m| memory(m.multiplier))
            .fold(0.0, f64::max);
        let floor = slowest.max(1e-3);
        let (worst, kept) = self
            .reference
            .modes
            .iter()
            .filter(|m| m.multiplier < 0.0)
            .map(|m| (m, memory(m.multiplier)))
            .filter(|&(_, kept)| kept > floor)
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        // With m ≈ −(1 − 4/(λΔt)) the memory is e^{−4 t_b/(λΔt²)} (t_b the burn-in
        // time, fixed in τ₁): it is the allowed F at Δt = √(4 t_b/(λ ln(1/F))); 0.9 of
        // that, for the approximation.
        let t_b = n * self.reference.dt;
        let dt_bound = 0.9 * (4.0 * t_b / (worst.rate_continuum * (1.0 / floor).ln())).sqrt();
        Some(UnforgettingMode {
            n: worst.n,
            multiplier: worst.multiplier,
            memory: kept,
            slowest: floor,
            burn_in_steps: self.burn_in_steps,
            dt_bound,
        })
    }

    /// [`Self::prepare`], with the discrete reference values if `values`.
    fn prepare_with(scene: &Scene, spec: &RunSpec, values: bool) -> Result<LinearRun> {
        let continuum = Continuum::of(scene)?;
        let tau1 = scene.tau1();
        let dt = spec.dt_tau1 * tau1;
        let length = continuum.line_length();
        let profile_x: Vec<f64> = scene
            .sampling
            .profile_points
            .iter()
            .map(|f| f * length)
            .collect();
        let profile_continuum = profile_x
            .iter()
            .map(|&x| continuum.profile_variance(x))
            .collect::<Result<Vec<f64>>>()?;
        let setup = Setup {
            scene,
            spec,
            continuum,
            tau1,
            dt,
            profile_x,
            values,
        };
        let prepared = match scene.model {
            ModelKind::Compression => {
                return Err(Error::invalid(
                    "model",
                    "compression",
                    "fem or spectral for a linear run",
                ));
            }
            ModelKind::Spectral => setup.spectral()?,
            ModelKind::Fem => setup.fem()?,
        };
        let modes = prepared.modes;
        // Each mode is sampled about twice per relaxation time; the profile four times
        // per relaxation time of mode 1.
        let every = |rate: f64| sample_every(rate, dt);
        let mode_every: Vec<u64> = modes
            .iter()
            .map(|m| every(m.rate_discrete.unwrap_or(m.rate_continuum)))
            .collect();
        let profile_every = every(4.0 * modes[0].rate_discrete.unwrap_or(modes[0].rate_continuum));
        let burn_in_steps = setup.steps(scene.sampling.burn_in_tau1 * tau1);
        Ok(LinearRun {
            spec: spec.clone(),
            components: scene.components(),
            reference: LinearReference {
                modes,
                profile_x: setup.profile_x,
                profile_discrete: prepared.profile_discrete,
                profile_terms: prepared.profile_terms,
                profile_continuum,
                two_time: prepared.two_time,
                dt,
                max_rate: prepared.max_rate,
                rigid: prepared.rigid,
                tangent: prepared.tangent,
            },
            mode_every,
            profile_every,
            burn_in_steps,
            amplitude_scale: prepared.amplitude_scale,
            model: prepared.model,
            #[cfg(any(test, feature = "faults"))]
            fault: scene.fault,
        })
    }

    /// Whether the stationary process obeys detailed balance, so that its two-point
    /// correlations are symmetric under time reversal: the spectral model, and a model
    /// with consistent noise (the paper's element-uniform noise is not proportional to
    /// the damping matrix, and its modes are driven by correlated noise).
    pub fn reversible(&self) -> bool {
        matches!(
            self.model,
            Model::Spectral { .. } | Model::SpectralMembrane { .. }
        ) || self.spec.noise == NoiseModel::Consistent
    }

    /// Number of sampling steps for a sampled duration (physical time units).
    pub fn sampled_steps(&self, duration: f64) -> u64 {
        ((duration / self.reference.dt).round() as u64).max(1)
    }

    /// Time between samples of mode `i` (0-based).
    pub fn mode_dt(&self, i: usize) -> f64 {
        self.mode_every[i] as f64 * self.reference.dt
    }

    /// ⟨w²(x_j)⟩ at profile point `point` over an ensemble: per trajectory and component
    /// the time average of w² with an autocorrelation-aware standard error
    /// ([`stats::mean_with_error`]); the independent parts are averaged and their errors
    /// added in quadrature. Returns (estimate, standard error).
    ///
    /// # Errors
    /// Estimator errors (too few samples).
    pub fn profile_square_estimate(
        &self,
        records: &[TrajectoryRecord],
        point: usize,
    ) -> Result<(f64, f64)> {
        let np = self.reference.profile_x.len();
        let mut parts = Vec::new();
        for t in records {
            for k in 0..self.components {
                let sq: Vec<f64> = t.profile[k * np + point].iter().map(|w| w * w).collect();
                parts.push(stats::mean_with_error(&sq)?);
            }
        }
        Ok(stats::combine_independent(&parts))
    }

    /// The finite-element object this run simulates (its linear system, modes and field
    /// on the sampling line); `None` for the spectral models and for data.
    pub(crate) fn fem_object(&self) -> Option<&FemObject> {
        match &self.model {
            Model::Fem { object, .. } => Some(object),
            _ => None,
        }
    }

    /// The rows of the tangent-angle cosine functionals, when the run checks them.
    fn tangent_functionals(&self) -> Option<&DMatrix<f64>> {
        match &self.model {
            Model::Fem { tangent, .. } => tangent.as_deref(),
            _ => None,
        }
    }

    fn n_nodes(&self) -> usize {
        match &self.model {
            Model::Fem { object, .. } => object.beam().map_or(0, |b| b.mesh().n_nodes()),
            Model::Spectral { .. } | Model::SpectralMembrane { .. } | Model::Data => 0,
        }
    }

    /// What is wrong with the shapes of `records` and `extra` (the two-time products of
    /// the extra trajectories) read from elsewhere (a shard), against what this run gives
    /// its records: the numbers of mode, profile, rigid and tangent-angle series, two-time
    /// products and nodal slope sums, at most [`MAX_SAMPLES`] samples a series, and the same series lengths in
    /// every trajectory; `None` if they are this run's shapes. The checks index the
    /// records by this run's counts: records of other shapes are refused before them.
    pub fn records_shape_error(
        &self,
        records: &[TrajectoryRecord],
        extra: &[Vec<f64>],
    ) -> Option<String> {
        let c = self.components;
        let r = &self.reference;
        let want = (
            c * r.modes.len(),
            c * r.profile_x.len(),
            c * r.rigid.len(),
            c * r.tangent.len(),
            c * r.two_time.len(),
            self.n_nodes(),
        );
        let lengths = |rec: &TrajectoryRecord| -> Vec<usize> {
            rec.modes
                .iter()
                .chain(&rec.profile)
                .chain(&rec.rigid)
                .chain(&rec.tangent)
                .map(Vec::len)
                .collect()
        };
        let first = records.first().map(lengths);
        for (j, rec) in records.iter().enumerate() {
            let got = (
                rec.modes.len(),
                rec.profile.len(),
                rec.rigid.len(),
                rec.tangent.len(),
                rec.two_time.len(),
                rec.slope_squares.len(),
            );
            if got != want {
                return Some(format!(
                    "trajectory {j} holds (mode series, profile series, rigid series, tangent-angle series, two-time products, nodal slope sums) = {got:?}, run {} gives {want:?}",
                    self.spec.name
                ));
            }
            let l = lengths(rec);
            if l.iter().any(|&n| n > MAX_SAMPLES) || Some(&l) != first.as_ref() {
                return Some(format!(
                    "trajectory {j} has series of {l:?} samples, trajectory 0 of {:?} (at most {MAX_SAMPLES} each, the same in every trajectory)",
                    first.unwrap_or_default()
                ));
            }
        }
        extra.iter().position(|x| x.len() != want.4).map(|j| {
            format!(
                "two-time trajectory {j} holds {} products, run {} gives {}",
                extra[j].len(),
                self.spec.name,
                want.4
            )
        })
    }

    /// The largest root-mean-square slope |w'| over the mesh nodes, measured over the
    /// ensemble's profile samples (all components): `(rms slope, node x/L)`. `None` for
    /// the spectral model or without samples.
    pub fn measured_rms_slope(&self, records: &[TrajectoryRecord]) -> Option<(f64, f64)> {
        let Model::Fem { object, .. } = &self.model else {
            return None;
        };
        let beam = object.beam()?;
        let n = records.iter().map(|r| r.slope_samples).sum::<usize>() * self.components;
        let sums: Vec<f64> = (0..beam.mesh().n_nodes())
            .map(|k| records.iter().map(|r| r.slope_squares[k]).sum())
            .collect();
        largest_rms_slope(beam, &sums, n)
    }

    /// The O(n) modal path of this run, if it has one and an injected fault, if any, has
    /// an exact modal form ([`crate::fault::modal_form`]; the others step the nodal
    /// state): the path and the factors of the rates and the noise gains.
    fn modal_path(&self) -> Option<(&ModalPath, f64, f64)> {
        let Model::Fem { modal, .. } = &self.model else {
            return None;
        };
        #[cfg(any(test, feature = "faults"))]
        let (rate, gain) = crate::fault::modal_form(self.fault)?;
        #[cfg(not(any(test, feature = "faults")))]
        let (rate, gain) = (1.0, 1.0);
        modal.as_ref().map(|p| (p, rate, gain))
    }

    fn sampler(&self) -> Result<Box<dyn Sampler + '_>> {
        if let (
            Some((path, rate, gain)),
            Model::Fem {
                object, integrator, ..
            },
        ) = (self.modal_path(), &self.model)
        {
            let stepper = ModalStep::new(
                *integrator,
                &scaled(&path.rates, rate),
                self.reference.dt,
                object.system().kt(),
            )?;
            #[cfg(any(test, feature = "faults"))]
            let stepper = if gain == 1.0 {
                stepper
            } else {
                stepper.with_scaled_gains(gain)
            };
            #[cfg(not(any(test, feature = "faults")))]
            let _ = gain;
            return Ok(Box::new(ModalSampler {
                path,
                n_modes: self.reference.modes.len(),
                filament: Components::at_rest(stepper, self.components, path.rates.len()),
            }));
        }
        Ok(match &self.model {
            Model::Fem {
                object,
                modes,
                projector,
                noise,
                integrator,
                ..
            } => {
                let stepper = build_integrator(
                    *integrator,
                    object.system(),
                    *noise,
                    self.reference.dt,
                    self.reference.max_rate,
                    modes.as_ref(),
                )?;
                #[cfg(any(test, feature = "faults"))]
                let stepper = crate::fault::linear_integrator(
                    self.fault,
                    stepper,
                    crate::fault::IntegratorParts {
                        kind: *integrator,
                        system: object.system(),
                        beam: object.beam(),
                        noise: *noise,
                        dt: self.reference.dt,
                        components: self.components,
                    },
                )?;
                let n = object.system().n_dofs();
                Box::new(FemSampler {
                    object,
                    projector,
                    filament: Components::at_rest(stepper, self.components, n),
                    probes: ProbeCache::default(),
                })
            }
            Model::SpectralMembrane { simulator, checked } => {
                Box::new(self.membrane_sampler(simulator, checked)?)
            }
            Model::Spectral { beam, n_modes } => {
                #[cfg(any(test, feature = "faults"))]
                let beam = &crate::fault::spectral_simulator(self.fault, *beam)?;
                let mut sims = Vec::new();
                for _ in 0..self.components {
                    let mut s = ModalSimulator::new(*beam, *n_modes, self.reference.dt)?;
                    s.set_rest();
                    sims.push(s);
                }
                Box::new(SpectralSampler {
                    sims,
                    n_modes: self.reference.modes.len(),
                })
            }
            Model::Data => {
                return Err(Error::invalid(
                    format!("run {}", self.spec.name),
                    "data",
                    "a run with a model to simulate (this one checks another program's data)",
                ));
            }
        })
    }

    /// The membrane's exact modal simulator at rest as a sampler of the modes `checked`
    /// (under an injected fault, a simulator of the faulty membrane).
    ///
    /// # Errors
    /// Invalid faulty parameters.
    fn membrane_sampler(
        &self,
        simulator: &MembraneSimulator,
        checked: &[usize],
    ) -> Result<MembraneSampler> {
        #[cfg(any(test, feature = "faults"))]
        let faulty = crate::fault::spectral_membrane(self.fault, *simulator.membrane())?;
        #[cfg(any(test, feature = "faults"))]
        let mut sim = if faulty == *simulator.membrane() {
            simulator.clone()
        } else {
            MembraneSimulator::new(faulty, simulator.modes().to_vec(), self.reference.dt)?
        };
        #[cfg(not(any(test, feature = "faults")))]
        let mut sim = simulator.clone();
        sim.set_rest();
        Ok(MembraneSampler {
            sim,
            checked: checked.to_vec(),
        })
    }

    /// Runs `steps` steps from rest and returns, every `every` steps, the checked modal
    /// amplitudes and the profile deflections (component-major): a short deterministic
    /// trace for golden snapshots.
    ///
    /// # Errors
    /// [`Error::Diverged`] if the state becomes non-finite.
    pub fn trace(&self, rng: &mut TrajectoryRng, steps: u64, every: u64) -> Result<Vec<Vec<f64>>> {
        let mut sampler = self.sampler()?;
        let r = &self.reference;
        let mut obs = TraceObserver {
            profile_x: &r.profile_x,
            m: vec![0.0; self.components * r.modes.len()],
            p: vec![0.0; self.components * r.profile_x.len()],
            out: Vec::new(),
        };
        Driver::new(r.dt, 0, steps, every).run(0, &mut *sampler, rng, &mut obs, |_| {
            format!("non-finite deflection with {}", self.spec.integrator)
        })?;
        Ok(obs.out)
    }

    /// Simulates one trajectory from rest: burn-in (recording the two-time products on
    /// the way) and then `sampled_steps` steps, recording every series at its cadence.
    /// With `sampled_steps = 0` only the two-time part is run, up to the largest η.
    ///
    /// # Errors
    /// [`Error::Diverged`] naming the step and time at which the state became non-finite.
    pub fn simulate(
        &self,
        rng: &mut TrajectoryRng,
        sampled_steps: u64,
    ) -> Result<TrajectoryRecord> {
        let mut sampler = self.sampler()?;
        let mut recorder = Recorder::new(self, sampled_steps);
        self.schedule(sampled_steps)
            .run(0, &mut *sampler, rng, &mut recorder, |_| {
                self.divergence_detail()
            })?;
        Ok(recorder.rec)
    }

    /// [`Self::simulate`] for the trajectories `first..first + count` of the ensemble
    /// seeded `seed` (trajectory `j` draws from `trajectory_rng(seed, j)`), in parallel,
    /// in index order; `done(k)` is called as `k` more trajectories finish. The
    /// finite-element θ-schemes step [`LANES`] trajectories in lockstep
    /// ([`ComponentBatch`]); every record is bit-identical to that of
    /// [`Self::simulate`], whatever the batching and the thread count.
    ///
    /// # Errors
    /// The error of the smallest failing trajectory index, as [`Self::simulate`] gives it.
    pub fn simulate_ensemble(
        &self,
        seed: u64,
        first: u64,
        count: u64,
        sampled_steps: u64,
        done: impl Fn(u64) + Sync,
    ) -> Result<Vec<TrajectoryRecord>> {
        let recorders = self.observe_ensemble(
            seed,
            first,
            count,
            sampled_steps,
            |_| Recorder::new(self, sampled_steps),
            done,
        )?;
        Ok(recorders.into_iter().map(|r| r.rec).collect())
    }

    /// The trajectories `first..first + count` of the ensemble seeded `seed`, each
    /// observed by its own observer `make(j)` over the schedule of [`Self::simulate`], in
    /// parallel (the finite-element θ-schemes [`LANES`] at a time in lockstep); returns
    /// the observers in index order.
    ///
    /// # Errors
    /// The error of the smallest failing trajectory index.
    fn observe_ensemble<O>(
        &self,
        seed: u64,
        first: u64,
        count: u64,
        sampled_steps: u64,
        make: impl Fn(u64) -> O + Sync,
        done: impl Fn(u64) + Sync,
    ) -> Result<Vec<O>>
    where
        O: Send
            + for<'a, 'b> Observer<LaneOf<'a, FemBatch<'b>>>
            + for<'s> Observer<dyn Sampler + 's>,
    {
        // Without a lockstep batch (the explicit scheme, the exact modal one, the spectral
        // model) every trajectory is a task of its own, so that even an ensemble of
        // [`LANES`] or fewer trajectories uses every core.
        if self.batch()?.is_none() {
            return par_indexed(count, |t| {
                let j = first + t;
                let mut rng = trajectory_rng(seed, j);
                let mut obs = make(j);
                let mut sampler = self.sampler()?;
                self.schedule(sampled_steps)
                    .run(0, &mut *sampler, &mut rng, &mut obs, |_| {
                        self.divergence_detail()
                    })?;
                done(1);
                Ok(obs)
            });
        }
        // Up to LANES trajectories per batch, fewer when the ensemble would leave a core
        // idle (8 trajectories on 2 cores: two batches of 4). Each lane's trajectory is
        // bit-identical to its serial run whatever the batch it is in.
        let threads = rayon::current_num_threads().max(1) as u64;
        let lanes = count.div_ceil(threads).clamp(1, LANES as u64);
        let batches = count.div_ceil(lanes);
        let per_batch = par_indexed(batches, |b| {
            let start = first + b * lanes;
            let end = (start + lanes).min(first + count);
            let mut rngs: Vec<TrajectoryRng> =
                (start..end).map(|j| trajectory_rng(seed, j)).collect();
            let mut observers: Vec<O> = (start..end).map(&make).collect();
            let results: Vec<Result<()>> = match self.batch()? {
                Some(mut batch) => self.schedule(sampled_steps).run_batch(
                    start as usize,
                    &mut batch,
                    &mut rngs,
                    &mut observers,
                    |_| self.divergence_detail(),
                ),
                None => rngs
                    .iter_mut()
                    .zip(&mut observers)
                    .map(|(rng, obs)| {
                        let mut sampler = self.sampler()?;
                        self.schedule(sampled_steps)
                            .run(0, &mut *sampler, rng, obs, |_| self.divergence_detail())
                    })
                    .collect(),
            };
            done(end - start);
            Ok(results
                .into_iter()
                .zip(observers)
                .map(|(r, o)| r.map(|()| o))
                .collect::<Vec<_>>())
        })?;
        per_batch.into_iter().flatten().collect()
    }

    /// The lockstep batch of this run, if its model is the finite-element one and its
    /// integrator a θ-scheme the lane sweeps serve ([`ThetaBatch::build`]).
    fn batch(&self) -> Result<Option<FemBatch<'_>>> {
        let Model::Fem {
            object,
            projector,
            noise,
            integrator,
            ..
        } = &self.model
        else {
            return Ok(None);
        };
        if self.modal_path().is_some() {
            return Ok(None);
        }
        // A fault that replaces the integrator steps one trajectory at a time.
        #[cfg(any(test, feature = "faults"))]
        if crate::fault::replaces_integrator(self.fault) {
            return Ok(None);
        }
        let r = &self.reference;
        let system = object.system();
        let batch = ThetaBatch::build(*integrator, system, *noise, r.dt, r.max_rate)?;
        Ok(batch.map(|t| FemBatch {
            object,
            projector,
            filament: ComponentBatch::at_rest(t, self.components),
            lane: RefCell::new(vec![0.0; system.n_dofs()]),
            probes: ProbeCache::default(),
        }))
    }

    /// The schedule of [`Self::simulate`]: the burn-in (at least up to the largest
    /// two-time η; only that without sampled steps), then `sampled_steps` at the gcd of
    /// the series' cadences.
    fn schedule(&self, sampled_steps: u64) -> Driver {
        let r = &self.reference;
        let last_tt = r.two_time.iter().map(|q| q.eta_step).max().unwrap_or(0);
        let burn_in = if sampled_steps == 0 {
            last_tt
        } else {
            self.burn_in_steps.max(last_tt)
        };
        // Every series' cadence is a multiple of the driver's.
        let every = self
            .mode_every
            .iter()
            .fold(self.profile_every, |g, &e| gcd(g, e));
        Driver::new(r.dt, burn_in, sampled_steps, every)
    }

    /// The detail of a divergence error of this run.
    fn divergence_detail(&self) -> String {
        let r = &self.reference;
        format!(
            "non-finite deflection with {} (dt = {:e}, lambda_max*dt = {:.3e})",
            self.spec.integrator,
            r.dt,
            r.max_rate * r.dt
        )
    }
}

impl LinearRun {
    /// A run without a model, checking another program's data against `reference`
    /// ([`crate::verify::data`]): the sampling plan is in rows of the data (`reference.dt`
    /// is the time between rows), and `amplitude_scale` turns the data's aₙ into the
    /// reference's modal units (its inverse is applied on reading).
    pub fn for_data(
        spec: RunSpec,
        components: usize,
        reference: LinearReference,
        mode_every: Vec<u64>,
        profile_every: u64,
        amplitude_scale: Vec<f64>,
    ) -> LinearRun {
        LinearRun {
            spec,
            components,
            reference,
            mode_every,
            profile_every,
            burn_in_steps: 0,
            amplitude_scale,
            model: Model::Data,
            #[cfg(any(test, feature = "faults"))]
            fault: None,
        }
    }
}
