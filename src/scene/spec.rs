//! Scene files (`verification/*.toml`): one physical set-up, its discretization, the
//! ensemble per budget and the checks to run.
//!
//! ```toml
//! description = "Hinged linear filament in 2D"
//! seed = 20261123
//! dims = 2                       # 2: w only; 3: w and v
//! model = "fem"                  # "fem" (finite elements) or "spectral" (exact modal simulator)
//! checks = ["profile", "mode-variance", "mode-distribution", "decay-rate", "spectrum", "two-time"]
//!
//! [filament]                     # any FilamentParams field; defaults 1 (EA 1e6)
//! bending_rigidity = 1.0
//! # or, in physical units (never both; see crate::params::physical):
//! # contour_length_um = 10.0, persistence_length_um = 17.0 (or bending_rigidity_pn_um2),
//! # viscosity_pa_s = 1e-3 with diameter_nm = 7.0 (or drag_pn_s_per_um2),
//! # temperature_k = 300.0, optional stretch_rigidity_pn
//!
//! [mesh]
//! elements = 10                  # fem: element count; spectral: number of modes
//! grading = 1.0                  # last/first element length (1 = uniform)
//!
//! [sampling]
//! burn_in_tau1 = 5.0             # from rest, before sampling starts (units of τ1)
//! modes = 6                      # modes checked
//! profile_points = [0.25, 0.5]   # x/L in (0, 1) where ⟨w²(x)⟩ is checked (at most 100)
//! two_time = [[0.5, 0.5, 0.05, 0.1]]  # (x/L, y/L, t/τ1, η/τ1) for eq. (4), from rest (at most 100)
//!
//! [[runs]]
//! name = "crank-nicolson"        # [A-Za-z0-9_-], at most 64 characters (a file name)
//! integrator = "crank-nicolson"  # euler-maruyama | backward-euler | crank-nicolson | exact-modal
//! noise = "consistent"           # consistent | element-uniform
//! dt_tau1 = 0.01                 # time step in units of τ1
//! quick = { trajectories = 16, duration_tau1 = 20.0 }
//! standard = { trajectories = 32, duration_tau1 = 100.0 }
//! full = { trajectories = 64, duration_tau1 = 400.0 }
//! ```
//!
//! **Membrane scenes** (issue #27). A scene with a `[membrane]` table instead of
//! `[filament]` describes a Helfrich membrane on an a × b rectangle, whose exact continuum
//! theory is [`crate::spectral::membrane`] (a scene has one object: never both tables).
//! Its time unit τ1 is the relaxation time ξ/(κq₁⁴ + σq₁²) of its slowest mode
//! ([`Scene::tau1`]); positions are fractions x/a on the midline y = b/2:
//!
//! ```toml
//! description = "Simply supported membrane, no tension"
//! seed = 20270127
//! dims = 3                       # always 3: a surface in 3D space, one height h(x, y)
//! model = "fem"                  # "fem" (plate elements) or "spectral"; never "compression"
//! checks = ["profile", "mode-variance", "two-time"]
//!
//! [membrane]                     # any MembraneParams field, consistent units; defaults:
//! bending_rigidity = 1.0         # κ = ξ = kT = a = b = 1, σ = 0, simply supported
//! tension = 0.0                  # σ > the buckling tension −κ·q₁² (may be negative)
//! drag = 1.0                     # ξ, friction per area
//! kt = 1.0
//! width = 1.0                    # a, along x
//! height = 1.0                   # b, along y
//! boundary = "simply-supported"  # or "periodic"
//!
//! [mesh]                         # uniform only (grading = 1)
//! elements = 8                   # fem: elements along x; spectral: mode indices along x
//! elements_y = 8                 # along y (default: elements); at most 4096 in all
//!
//! [sampling]
//! burn_in_tau1 = 2.0
//! modes = 4                      # at most elements·elements_y (periodic: that − 1)
//! profile_points = [0.25, 0.5]   # x/a on y = b/2: (0, 1) simply supported, [0, 1) periodic
//! two_time = [[0.5, 0.5, 0.5, 1.0]]  # (x/a, x'/a, t/τ1, η/τ1) on y = b/2
//! ```
//!
//! (`[[runs]]` as for the filament.) Every command of the linear filament takes membrane
//! scenes. With `model = "compression"` and `compression.area_modulus`, a membrane scene is
//! the membrane under imposed projected area (issue #28), which `verify` (also sharded),
//! `calibrate` and `power` take; `run`, `check` and `converge` refuse it for now
//! ([`Scene::refuse_membrane`]).
//!
//! An ensemble's keys (every budget: `quick`, `standard`, `full`):
//!
//! - `trajectories`: independent trajectories (per strain in a compression scene),
//!   in [2, 100000];
//! - `duration_tau1`: sampled duration of each trajectory after burn-in, in units of τ1
//!   (a fixed budget; required unless `target_std_error` is given, and then left out); at
//!   most 1e6; linear scenes: at least 16 (32 samples of mode 1) and 256 steps
//!   (`256·dt_tau1`), compression scenes: at least 16 samples (`16·sample_every_tau1`);
//!   every run takes at most 1e10 steps per trajectory (burn-in included);
//! - `two_time_trajectories`: extra short trajectories of the two-time check (linear
//!   scenes only), in [0, 100000], default 0.
//!
//! The scene file's stem is the name of its output directory: `[A-Za-z0-9_-]`, at most
//! 64 characters. A compression scene has at most 100 `strain_ratios`.
//!
//! **Budgets by target precision** (compression scenes only): instead of
//! `duration_tau1`, give all three of
//!
//! - `target_std_error`: the aimed standard error of ⟨F⟩ at every strain, in units of
//!   the Euler load F_c0, in (0, 1];
//! - `pilot_tau1`: sampled duration of each pilot trajectory, in units of τ1 (at least 16
//!   samples, at most `max_duration_tau1`);
//! - `max_duration_tau1`: the cap on the main stage's sampled duration per trajectory,
//!   in units of τ1 (≤ 1e6).
//!
//! ```toml
//! full = { trajectories = 16, target_std_error = 0.01, pilot_tau1 = 40.0, max_duration_tau1 = 2000.0 }
//! ```
//!
//! Metropolis runs may add a **step search** (both keys): `max_dt_tau1` (the largest step
//! tried, in [dt_tau1, 100] τ1) and `min_acceptance` (in (0, 1)). At each strain the
//! candidates `dt_tau1·2^k ≤ max_dt_tau1` are probed from the largest down, and the first
//! whose acceptance reaches `min_acceptance` is used by the pilot and the main stage (the
//! chain is exact at any Δt; the burn-in stays at `dt_tau1`); the second run of the
//! Δt-halving pair runs at half the chosen steps. Keep `max_dt_tau1` moderate: at a large
//! step Crank–Nicolson keeps the squared amplitude of a stiff mode nearly frozen for
//! about λΔt/8 steps, a slow tail of F that the windowed autocorrelation estimate misses
//! (errors too small: measured over seeds at 10 elements, fine at 0.16 τ1, too small by
//! √2 at 0.32 and 0.64 τ1 in tension).
//!
//! At each strain separately a pilot of `trajectories` × `pilot_tau1` (its own random
//! streams) estimates the standard error with the integrated autocorrelation time; the
//! main stage then runs `trajectories` fresh, independent trajectories for the duration
//! the pilot predicts for the target (s.e. ∝ T^(-1/2), times a safety factor, at least
//! `pilot_tau1`, at most `max_duration_tau1`; see
//! [`targeted_duration`](crate::scene::compression::targeted_duration)), and only the
//! main stage is reported. The main stage's duration depends on the pilot only, which is
//! independent of the main-stage samples, so given that duration the reported estimate
//! is an ordinary fixed-budget estimate: its standard error and p-values are honest (no
//! optional-stopping bias). A strain whose main stage misses the target is reported as it
//! is, not rerun.

use super::validate::Num;
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::output::provenance::{DescribeScene, ParameterRecord, Quantity, SceneProvenance};
use crate::params::physical::{self, FilamentInput, PhysicalFilament};
use crate::params::{Ends, FilamentParams};
use crate::spectral::membrane::MembraneParams;
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The largest scene file read (1 MiB; the shipped scenes are a few KiB).
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The ensemble size and duration of a run at one budget.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ensemble {
    /// Number of independent trajectories, each started from rest.
    pub trajectories: usize,
    /// Sampled duration of each trajectory after burn-in, in units of τ1. Left out (NaN)
    /// when `target_std_error` is given: the duration is then chosen per strain.
    #[serde(default = "not_given", skip_serializing_if = "is_not_given")]
    pub duration_tau1: f64,
    /// Extra short trajectories (from rest to the largest η) for the two-time check only;
    /// default 0.
    #[serde(default)]
    pub two_time_trajectories: usize,
    /// Compression scenes: the aimed standard error of ⟨F⟩ per strain, in units of F_c0
    /// (a budget by target precision, see the module documentation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_std_error: Option<f64>,
    /// With `target_std_error`: sampled duration of each pilot trajectory, in units of τ1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pilot_tau1: Option<f64>,
    /// With `target_std_error`: the largest sampled duration of a main-stage trajectory,
    /// in units of τ1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration_tau1: Option<f64>,
    /// With `target_std_error`, Metropolis runs only: the largest step of the step search,
    /// in units of τ1 (with `min_acceptance`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_dt_tau1: Option<f64>,
    /// With `max_dt_tau1`: the acceptance rate the step search asks of a step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_acceptance: Option<f64>,
}

/// The step search of a budget by target precision (Metropolis runs only, whose
/// stationary law is exact at any Δt): at each strain, the largest step
/// `dt_tau1·2^k ≤ max_dt_tau1` whose probe acceptance is at least `min_acceptance`
/// ([`crate::scene::compression::CompressionRun::search_step`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSearch {
    /// Largest step tried (τ1).
    pub max_dt_tau1: f64,
    /// Acceptance rate a step must reach.
    pub min_acceptance: f64,
}

/// The value of a `duration_tau1` that was left out: a NaN (not a valid duration, refused
/// by validation unless `target_std_error` replaces it) with a payload of its own, so that
/// validation can tell it from a `nan` written in the file ([`Ensemble::duration_given`]).
const NOT_GIVEN: f64 = f64::from_bits(0x7FF8_0000_0000_0DA7);

/// A missing `duration_tau1` ([`NOT_GIVEN`]).
fn not_given() -> f64 {
    NOT_GIVEN
}

/// Whether a duration was left out (any NaN: a `nan` in the file is refused anyway).
fn is_not_given(x: &f64) -> bool {
    x.is_nan()
}

/// A budget by target precision of a compression run (all in F_c0 and τ1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrecisionTarget {
    /// Aimed standard error of ⟨F⟩/F_c0 at every strain.
    pub std_error: f64,
    /// Sampled duration of each pilot trajectory (τ1).
    pub pilot_tau1: f64,
    /// Largest sampled duration of a main-stage trajectory (τ1).
    pub max_duration_tau1: f64,
    /// The step search, if the budget has one.
    pub step_search: Option<StepSearch>,
}

impl Ensemble {
    /// Whether `duration_tau1` was written in the file (a `nan` written there counts as
    /// given, so that validation reports it as NaN rather than as missing).
    pub fn duration_given(&self) -> bool {
        self.duration_tau1.to_bits() != NOT_GIVEN.to_bits()
    }

    /// The budget by target precision, if this ensemble has one (all three keys given;
    /// validation refuses a partial set).
    pub fn precision_target(&self) -> Option<PrecisionTarget> {
        Some(PrecisionTarget {
            std_error: self.target_std_error?,
            pilot_tau1: self.pilot_tau1?,
            max_duration_tau1: self.max_duration_tau1?,
            step_search: match (self.max_dt_tau1, self.min_acceptance) {
                (Some(max_dt_tau1), Some(min_acceptance)) => Some(StepSearch {
                    max_dt_tau1,
                    min_acceptance,
                }),
                _ => None,
            },
        })
    }
}

/// How much statistics to gather.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Budget {
    /// The CI budget of `make verify` (minutes in all).
    Quick,
    /// Enough to resolve the element-uniform noise error per mode.
    Standard,
    /// Publication-grade error bars.
    Full,
}

impl Budget {
    /// The budget's name.
    pub fn name(self) -> &'static str {
        match self {
            Budget::Quick => "quick",
            Budget::Standard => "standard",
            Budget::Full => "full",
        }
    }
}

/// The model a scene simulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelKind {
    /// Hermite-cubic finite elements with a time integrator.
    Fem,
    /// The exact modal (spectral) simulator of eq. (2): a self-check of the references and
    /// of the statistical checks.
    Spectral,
    /// The finite-deflection (von Kármán) filament under imposed end-shortening: the
    /// force–strain curve of the paper's Fig. 2.
    Compression,
}

/// The checks a scene can request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CheckKind {
    /// Equilibrium profile ⟨w²(x)⟩ at `profile_points`.
    Profile,
    /// Per-mode stationary variance: χ² variance test and autocorrelation-aware z-test.
    ModeVariance,
    /// Per-mode amplitude distribution: KS and χ² goodness of fit against the normal law.
    ModeDistribution,
    /// Per-mode autocorrelation decay rate.
    DecayRate,
    /// Per-mode power spectrum against the exact sampled (AR(1)) spectrum.
    Spectrum,
    /// Two-time correlation eq. (4) from w(x, 0) = 0 at `two_time` points.
    TwoTime,
    /// The stationary variances of all checked modes pooled: per independent series the
    /// weighted mean of (time average of q²)/(exact discrete variance) over the modes,
    /// t-tested against 1 over the series. Sensitive to a global error (a temperature,
    /// a drag, a stiffness) that each mode alone is too noisy to see.
    PooledVariance,
    /// A membrane on a square patch (a = b, as many elements along x as along y): the
    /// variances of the modes (m, n) and (n, m) are equal; per independent series the
    /// pooled difference of their normalized time averages, t-tested against 0.
    XySymmetry,
    /// A filament with rigid modes (a free end and no clamp, issue #29): the increments
    /// of each rigid amplitude `r = ψᵀCw` between profile samples against their exact
    /// random-walk law, a χ² variance test of the increments (independent by the
    /// Markov property of a zero mode).
    RigidDiffusion,
    /// A filament with no clamped end (issue #29): the tangent-angle cosine amplitudes
    /// `a_n = √(2/L)∫θ cos(nπs/L) ds` of Gittes et al. (1993), the standard analysis of
    /// imaged microtubules and actin, for n = 1 … `modes`: their variance against the exact
    /// discrete value (continuum `kT L²/(EI n²π²)` beside it) by a χ² test, and their
    /// normal law by KS, on samples thinned to a lag correlation ≤ 0.01 by the exact
    /// autocorrelation.
    TangentAngle,
    /// Compression: ⟨F⟩ at every strain against the exact discrete equilibrium theory
    /// (per-point z-tests and a χ² over all points).
    ForceStrain,
    /// Compression: distribution of F at `distribution_strain_ratios` (KS against the
    /// exact equilibrium law).
    ForceDistribution,
    /// Compression: the Δt-halving check between the two runs named in `halving`.
    DtHalving,
}

impl CheckKind {
    /// The name as scene files write it (`xy-symmetry`).
    pub fn name(self) -> String {
        serde_json::to_value(self)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_else(|| format!("{self:?}"))
    }

    /// Whether the check applies to the compression model (otherwise to linear ones).
    pub fn is_compression(self) -> bool {
        matches!(
            self,
            CheckKind::ForceStrain | CheckKind::ForceDistribution | CheckKind::DtHalving
        )
    }
}

/// The imposed strains and sampling of a compression scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompressionSpec {
    /// Imposed strains ε/ε_c0 (ε_c0 = π²EI/(EA L²)).
    pub strain_ratios: Vec<f64>,
    /// Strains (a subset of `strain_ratios`) where the distribution of F is tested.
    #[serde(default)]
    pub distribution_strain_ratios: Vec<f64>,
    /// Burn-in from rest at each strain, in units of τ1.
    pub burn_in_tau1: f64,
    /// Time between samples of F, in units of τ1.
    pub sample_every_tau1: f64,
    /// The two runs compared by the Δt-halving check: `[run at Δt, run at Δt/2]`.
    #[serde(default)]
    pub halving: Option<[String; 2]>,
    /// A membrane under imposed projected area (issue #28): the area modulus K_A (energy
    /// per area); the strains are `ε = 1 − A_p/A₀` in units of `ε_c0 = κq²_min/K_A`.
    /// Required with a `[membrane]` table, refused with a filament.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area_modulus: Option<f64>,
}

/// Discretization of the filament or the membrane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Element count (fem) or number of modes (spectral); of a membrane, the count along x
    /// (fem) or the number of mode indices kept along x (spectral).
    pub elements: usize,
    /// Membrane scenes only: the element count along y (fem) or the number of mode
    /// indices kept along y (spectral); left out, the same as `elements`
    /// ([`MeshSpec::elements_along_y`]). Refused in a filament scene.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements_y: Option<usize>,
    /// Ratio of the last to the first element length (geometric grading); 1 is uniform.
    #[serde(default = "one")]
    pub grading: f64,
    /// How a filament's `fem` model is discretized (not in scene files): Hermite-cubic
    /// elements, or a chain of nodes when `check` models another program's declared
    /// finite-difference or bead-spring discretization (issue #31).
    #[serde(skip)]
    pub scheme: MeshScheme,
}

/// The discretization of a filament's `fem` model ([`MeshSpec::scheme`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MeshScheme {
    /// Hermite-cubic beam elements ([`crate::fem::BeamModel`]).
    #[default]
    Hermite,
    /// A chain of `elements` intervals ([`crate::fem::ChainModel`]): the 5-point
    /// finite-difference filament, or the linearized bead-spring chain; hinged ends.
    Chain,
}

fn one() -> f64 {
    1.0
}

impl MeshSpec {
    /// The count along y of a membrane mesh: `elements_y`, or `elements` if left out.
    pub fn elements_along_y(&self) -> usize {
        self.elements_y.unwrap_or(self.elements)
    }

    /// The mesh of a filament of length `length`: uniform, or geometrically graded.
    ///
    /// # Errors
    /// Invalid element count or grading (see [`Mesh::uniform`], [`Mesh::graded`]).
    pub fn build(&self, length: f64) -> Result<Mesh> {
        if self.grading == 1.0 {
            Mesh::uniform(length, self.elements)
        } else {
            Mesh::graded(length, self.elements, self.grading)
        }
    }
}

/// What is sampled and where.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sampling {
    /// Burn-in from rest before sampling, in units of τ1.
    pub burn_in_tau1: f64,
    /// Number of (lowest) modes checked.
    pub modes: usize,
    /// Positions x/L of the profile check (membrane: x/a on the midline y = b/2).
    #[serde(default)]
    pub profile_points: Vec<f64>,
    /// (x/L, y/L, t/τ1, η/τ1) of the two-time check (membrane: (x/a, x'/a, t/τ1, η/τ1),
    /// both points on the midline y = b/2).
    #[serde(default)]
    pub two_time: Vec<[f64; 4]>,
}

/// One integrator/noise/time-step combination of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// Name, unique within the scene (used in file names).
    pub name: String,
    /// Time integrator (ignored by the spectral model, which is exact).
    #[serde(default = "default_integrator")]
    pub integrator: IntegratorKind,
    /// Noise model (fem only).
    #[serde(default = "default_noise")]
    pub noise: NoiseModel,
    /// Time step in units of τ1.
    pub dt_tau1: f64,
    /// Checks of this run, if not the scene's `checks` (e.g. to leave out a check an
    /// expensive run cannot afford at every budget).
    #[serde(default)]
    pub checks: Option<Vec<CheckKind>>,
    /// Ensemble at the quick budget.
    pub quick: Ensemble,
    /// Ensemble at the standard budget.
    pub standard: Ensemble,
    /// Ensemble at the full budget.
    pub full: Ensemble,
}

fn default_integrator() -> IntegratorKind {
    IntegratorKind::CrankNicolson
}

fn default_noise() -> NoiseModel {
    NoiseModel::Consistent
}

impl RunSpec {
    /// A study's run `integrator-noise` at `dt_tau1` with the same fixed ensemble at every
    /// budget (`trajectories` × `duration_tau1` τ1, no two-time extras, no target
    /// precision) and the scene's checks.
    pub fn fixed(
        integrator: IntegratorKind,
        noise: NoiseModel,
        dt_tau1: f64,
        trajectories: usize,
        duration_tau1: f64,
    ) -> Self {
        let e = Ensemble {
            trajectories,
            duration_tau1,
            two_time_trajectories: 0,
            target_std_error: None,
            pilot_tau1: None,
            max_duration_tau1: None,
            max_dt_tau1: None,
            min_acceptance: None,
        };
        RunSpec {
            name: format!("{}-{}", integrator.name(), noise.name()),
            integrator,
            noise,
            dt_tau1,
            checks: None,
            quick: e,
            standard: e,
            full: e,
        }
    }

    /// The checks of this run: its own list, or the scene's.
    pub fn checks<'a>(&'a self, scene: &'a Scene) -> &'a [CheckKind] {
        self.checks.as_deref().unwrap_or(&scene.checks)
    }

    /// The ensemble at `budget`.
    pub fn ensemble(&self, budget: Budget) -> Ensemble {
        match budget {
            Budget::Quick => self.quick,
            Budget::Standard => self.standard,
            Budget::Full => self.full,
        }
    }
}

/// A verification scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name: the file stem (not in the file).
    #[serde(skip)]
    pub name: String,
    /// The file the scene was read from (not in the file), for messages.
    #[serde(skip)]
    pub path: PathBuf,
    /// One-line description for the report.
    pub description: String,
    /// Master seed: every trajectory's generator derives from it, the run name and the
    /// trajectory index.
    pub seed: u64,
    /// 2 (one transverse direction) or 3 (two); a membrane scene: 3 (one height
    /// component, [`Scene::components`]).
    pub dims: usize,
    /// What is simulated.
    pub model: ModelKind,
    /// Which checks to run.
    pub checks: Vec<CheckKind>,
    /// Physical parameters, in the scene's consistent units: as written, or converted
    /// from physical units ([`crate::params::physical`]).
    #[serde(default, deserialize_with = "deserialize_filament")]
    pub filament: FilamentParams,
    /// The filament's ends (`[filament] ends`, issue #29; not in the file under this
    /// name: read from the `[filament]` table): both hinged unless the scene says
    /// otherwise.
    #[serde(skip)]
    pub ends: Ends,
    /// The membrane of a membrane scene (its `[membrane]` table, consistent units), or
    /// `None` for a filament scene (see the module docs). A membrane scene leaves
    /// `filament` at its defaults and never reads it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub membrane: Option<MembraneParams>,
    /// Whether the file has a `[filament]` table (not in the file under this name: set
    /// by [`Scene::parse`]); validation refuses it next to a `[membrane]` table.
    #[serde(skip)]
    pub(crate) filament_table: bool,
    /// The filament as given in physical units, if the scene gave it so (not in the
    /// file under this name: read from the `[filament]` keys).
    #[serde(skip)]
    pub physical: Option<PhysicalFilament>,
    /// The scene text as parsed (not in the file), for the provenance: its hash is of
    /// what was parsed. Empty for a scene built in code.
    #[serde(skip)]
    pub source_text: String,
    /// Discretization.
    pub mesh: MeshSpec,
    /// Sampling plan (linear models; left out when a compression scene is written).
    #[serde(default, skip_serializing_if = "is_unused_sampling")]
    pub sampling: Sampling,
    /// Strains and sampling (compression model).
    #[serde(default)]
    pub compression: Option<CompressionSpec>,
    /// Integrator/noise/time-step combinations.
    pub runs: Vec<RunSpec>,
    /// A simulator fault injected into every run of this scene
    /// ([`crate::fault`]; never read from a file). Test and `--features faults` builds
    /// only: set with [`Scene::with_fault`].
    #[cfg(any(test, feature = "faults"))]
    #[serde(skip)]
    pub fault: Option<crate::fault::Fault>,
}

/// Whether a scene's `[sampling]` table is the default one that a compression scene
/// (which does not read it) has: not written out.
fn is_unused_sampling(s: &Sampling) -> bool {
    *s == Sampling::default()
}

impl Scene {
    /// Reads and validates a scene file.
    ///
    /// # Errors
    /// [`Error::Io`] if unreadable; [`Error::Scene`] naming the file, key, value and
    /// allowed range if invalid.
    pub fn load(path: &Path) -> Result<Scene> {
        // A directory, FIFO or device named *.toml is the user's mistake (exit 2), and a
        // FIFO must not block the run: only regular files of bounded size are read.
        let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
        let refuse = |message: String| Error::Scene {
            file: path.to_path_buf(),
            key: "-".to_string(),
            message,
        };
        if !meta.is_file() {
            let what = if meta.is_dir() {
                "a directory"
            } else {
                "not a regular file (a FIFO, socket or device)"
            };
            return Err(refuse(format!("is {what}: a scene is a TOML text file")));
        }
        if meta.len() > MAX_SCENE_BYTES {
            return Err(refuse(format!(
                "is {} bytes: a scene file has at most {MAX_SCENE_BYTES} bytes",
                meta.len()
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| Error::Scene {
            file: path.to_path_buf(),
            key: "-".to_string(),
            message: format!(
                "not a UTF-8 text file (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        })?;
        Scene::parse(&text, path)
    }

    /// Parses and validates scene text; `path` is used for messages and the name.
    ///
    /// # Errors
    /// [`Error::Scene`] naming the file, key, value and allowed range.
    pub fn parse(text: &str, path: &Path) -> Result<Scene> {
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
        Scene::parse_named(text, path, name)
    }

    /// [`Scene::parse`] with the scene's name given rather than taken from the file stem
    /// (a built-in scene, whose `path` is a label such as `hinged-linear-2d (built in)`:
    /// see [`crate::scene::builtin`]).
    ///
    /// # Errors
    /// [`Error::Scene`] naming `path`, the key, value and allowed range.
    pub fn parse_named(text: &str, path: &Path, name: &str) -> Result<Scene> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| parse_error(text, path, &e))?;
        let table = FilamentTable::read(text);
        scene.filament_table = table.as_ref().is_some_and(|t| t.filament.is_some());
        scene.ends = table
            .as_ref()
            .and_then(|t| t.filament.and_then(|f| f.ends))
            .unwrap_or_default();
        scene.physical = table.and_then(FilamentTable::physical);
        scene.source_text = text.to_string();
        scene.path = path.to_path_buf();
        scene.name = name.to_string();
        scene.validate()?;
        Ok(scene)
    }

    /// Whether this is a membrane scene (a `[membrane]` table; see the module docs).
    pub fn is_membrane(&self) -> bool {
        self.membrane.is_some()
    }

    /// The scene's time unit τ1, in its consistent units: every key ending in `_tau1` is
    /// a multiple of it. A filament's slowest relaxation time ξL⁴/(π⁴EI)
    /// ([`FilamentParams::tau1`], the same arithmetic); a membrane's, 1/λ = ξ/c_q of its
    /// slowest mode ([`Membrane::modes`], c_q = κq⁴ + σq², [`Membrane::stiffness`]): with
    /// q² = π²(1/a² + 1/b²) simply supported, (2π/max(a, b))² periodic. NaN for a membrane
    /// whose parameters [`MembraneParams::validate`] refuses (validation refuses the
    /// scene). A filament with other ends (issue #29): the slowest elastic mode's,
    /// ξL⁴/(EI β₁⁴) ([`EndedBeam::tau1`]; NaN for parameters it refuses).
    pub fn tau1(&self) -> f64 {
        match &self.membrane {
            None if self.ends.is_hinged() => self.filament.tau1(),
            None => crate::spectral::EndedBeam::new(self.filament, self.ends)
                .map_or(f64::NAN, |b| b.tau1()),
            Some(p) => p.tau1(),
        }
    }

    /// The length of the line the scene's positions lie on (profile and two-time points
    /// are fractions of it): the filament's length L, or the membrane's width a (its
    /// midline y = b/2).
    pub fn line_length(&self) -> f64 {
        match &self.membrane {
            None => self.filament.length,
            Some(p) => p.width,
        }
    }

    /// The components of the displacement each node or mode carries: a filament's
    /// transverse directions, `dims − 1` (w; or w and v); a membrane's one height h.
    pub fn components(&self) -> usize {
        if self.is_membrane() {
            1
        } else {
            self.dims.saturating_sub(1)
        }
    }

    /// Refuses a membrane scene where only filament scenes can go (issue #27: every
    /// command of the linear filament takes membranes; of the membrane under imposed
    /// projected area, `run`, `check` and `converge` are not written yet):
    /// `what` names the command or path, e.g. `run`.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the scene file, the key `membrane` and the scene,
    /// saying that `what` is not written yet and which commands take the scene.
    pub fn refuse_membrane(&self, what: &str) -> Result<()> {
        if !self.is_membrane() {
            return Ok(());
        }
        Err(Error::Scene {
            file: self.path.clone(),
            key: "membrane".to_string(),
            message: format!(
                "{what} is not written yet: scene \"{}\" is a membrane under imposed \
                 projected area, which `verify` checks; `run`, `check` and `converge` take the \
                 linear membrane scenes (model \"fem\" or \"spectral\": membrane-hinged, \
                 membrane-periodic, ...) and the filament's",
                self.name
            ),
        })
    }

    /// Wraps an error raised while preparing or running run `run` of this scene so that
    /// the message names the scene file and the run's key (bad input, exit 2), unless it
    /// already names them. A divergence or a numerical failure (exit 3: the run failed,
    /// not the input) keeps its kind and gains the file and run. Values are printed in
    /// full precision (shortest round trip), so that "must be < a, got b" never shows
    /// a = b.
    pub fn run_error(&self, run: usize, what: &str, err: Error) -> Error {
        let tau1 = self.tau1();
        let key = |k: &str| format!("runs[{run}].{k}");
        match err {
            Error::Scene { .. } | Error::Io { .. } => err,
            Error::Diverged { step, time, detail } => Error::Diverged {
                step,
                time,
                detail: format!(
                    "{}: runs[{run}] ({}): {detail}",
                    self.path.display(),
                    self.runs.get(run).map_or("?", |r| r.name.as_str())
                ),
            },
            Error::UnstableTimeStep {
                integrator: _,
                dt,
                limit,
                bound,
                suggestion,
            } => Error::Scene {
                file: self.path.clone(),
                key: key("dt_tau1"),
                message: format!(
                    "must be < {} ({bound} for this mesh, in units of tau1), got {}; use a smaller dt_tau1 or {suggestion}",
                    Num(limit / tau1),
                    // The value as written in the file when it is the step that was
                    // refused (dt/tau1 may differ from it in the last digit).
                    Num(self
                        .runs
                        .get(run)
                        .map(|r| r.dt_tau1)
                        .filter(|g| (g * tau1 - dt).abs() <= 1e-12 * dt)
                        .unwrap_or(dt / tau1))
                ),
            },
            // A numerical failure while running (e.g. an estimator that finds no
            // autocorrelation window) is the run's failure, not the user's (exit 3).
            Error::Numerical { routine, detail } => Error::Numerical {
                routine,
                detail: format!(
                    "{detail} ({}: runs[{run}] ({}))",
                    self.path.display(),
                    self.runs.get(run).map_or("?", |r| r.name.as_str())
                ),
            },
            other => Error::Scene {
                file: self.path.clone(),
                key: key(what),
                message: format!(
                    "cannot be run as given ({other}); for too little data raise duration_tau1 or trajectories, or lower {}",
                    key("dt_tau1")
                ),
            },
        }
    }

    /// The scene files in `dir`, sorted by name.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (exit 2) if the directory cannot be read.
    pub fn discover(dir: &Path) -> Result<Vec<PathBuf>> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| {
                Error::invalid(
                    "--scene-dir",
                    dir.display(),
                    format!("a readable directory of scene files ({e})"),
                )
            })?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        files.sort();
        Ok(files)
    }
}

/// `[filament]` as written, converted to [`FilamentParams`] ([`FilamentInput::resolve`]);
/// a table that mixes or leaves out keys is an error at the table, naming the keys.
fn deserialize_filament<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<FilamentParams, D::Error> {
    let input = FilamentInput::deserialize(d)?;
    input
        .resolve()
        .map(|(params, _)| params)
        .map_err(serde::de::Error::custom)
}

/// The `[filament]` table alone (every other key of the file ignored), to recover the
/// physical filament and whether the table was given once the scene has parsed.
#[derive(Deserialize)]
struct FilamentTable {
    #[serde(default)]
    filament: Option<FilamentInput>,
}

impl FilamentTable {
    /// The `[filament]` table of `text` (`None` for text that does not parse:
    /// [`Scene::parse`] has refused it before).
    fn read(text: &str) -> Option<FilamentTable> {
        toml::from_str(text).ok()
    }

    /// The physical filament the table gives, if any.
    fn physical(self) -> Option<PhysicalFilament> {
        self.filament.unwrap_or_default().resolve().ok()?.1
    }
}

impl DescribeScene for Scene {
    /// The scene as it will run: its source and text as parsed with their hash, the seed,
    /// the discretization, the parameters with units, and the overrides — every
    /// difference between this scene and its text parsed afresh (e.g. `seed = 7 (file:
    /// 20261123)` after a `--seed`), found by comparing the two key by key.
    fn describe(&self) -> SceneProvenance {
        SceneProvenance {
            name: self.name.clone(),
            source: self.path.display().to_string(),
            text: self.source_text.clone(),
            sha256: SceneProvenance::hash(&self.source_text),
            overrides: self.overrides(),
            seed: self.seed,
            model: match self.model {
                ModelKind::Fem => "fem",
                ModelKind::Spectral => "spectral",
                ModelKind::Compression => "compression",
            }
            .to_string(),
            dims: self.dims,
            elements: self.mesh.elements,
            units: physical::base_units(self.physical.is_some()),
            parameters: match &self.membrane {
                Some(m) => membrane_record(m),
                None => physical::parameter_record(&self.filament, self.physical.as_ref()),
            },
        }
    }
}

/// The provenance record of a membrane's parameters (always in the scene's consistent
/// units): its sides, κ, σ, ξ (per area), kT, and the groups τ₁ (its slowest relaxation
/// time, (M2)), the buckling tension −κq_min² and σ/(κq_min²).
fn membrane_record(m: &MembraneParams) -> ParameterRecord {
    let q = |k: &str, v: f64, unit: &str| (k.to_string(), Quantity::new(v, unit));
    ParameterRecord {
        unit_system: "consistent".to_string(),
        given: BTreeMap::new(),
        parameters: [
            q("width", m.width, "[L]"),
            q("height", m.height, "[L]"),
            q("bending_rigidity", m.bending_rigidity, "[E]"),
            q("tension", m.tension, "[E]/[L]^2"),
            q("drag", m.drag, "[E]*[T]/[L]^4"),
            q("kt", m.kt, "[E]"),
        ]
        .into_iter()
        .collect(),
        groups: [
            q("tau1", m.tau1(), "[T]"),
            q("buckling_tension", m.buckling_tension(), "[E]/[L]^2"),
            q("tension_ratio", m.tension_ratio(), "1"),
        ]
        .into_iter()
        .collect(),
    }
}

impl Scene {
    /// The differences between this scene and its text parsed afresh, as `key = value
    /// (file: value)`, in key order; empty for a scene without text or that runs as
    /// written.
    pub fn overrides(&self) -> Vec<String> {
        if self.source_text.is_empty() {
            return Vec::new();
        }
        let as_written = match toml::from_str::<Scene>(&self.source_text) {
            Ok(s) => s,
            Err(_) => return vec!["(the scene text no longer parses)".to_string()],
        };
        let (Ok(now), Ok(file)) = (
            serde_json::to_value(self),
            serde_json::to_value(&as_written),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        json_diff("", &now, &file, &mut out);
        out
    }
}

/// The leaves where `now` differs from `file`, as `key = now (file: file)`.
fn json_diff(key: &str, now: &serde_json::Value, file: &serde_json::Value, out: &mut Vec<String>) {
    use serde_json::Value;
    let join = |k: &str| {
        if key.is_empty() {
            k.to_string()
        } else {
            format!("{key}.{k}")
        }
    };
    match (now, file) {
        (Value::Object(a), Value::Object(b)) => {
            let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
            for k in keys {
                let null = Value::Null;
                json_diff(
                    &join(k),
                    a.get(k).unwrap_or(&null),
                    b.get(k).unwrap_or(&null),
                    out,
                );
            }
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                json_diff(&format!("{key}[{i}]"), x, y, out);
            }
        }
        _ if now != file => out.push(format!("{key} = {now} (file: {file})")),
        _ => {}
    }
}

/// The [`Error::Scene`] of a file that is not valid TOML or does not fit the scene types:
/// the dotted key at the error (`runs[1].quick`, `mesh.elements`, `-` if none), the
/// parser's message in the words of the file (no Rust type names) and the line, column
/// and text where it was found.
fn parse_error(text: &str, path: &Path, e: &toml::de::Error) -> Error {
    let raw = e.message().trim();
    let at = e.span().map(|s| s.start.min(text.len()));
    let key = match (at, missing_field(raw)) {
        // A missing field of an inline table (`quick = { ... }`) is reported at its
        // value; of a table, at the table (or the whole file at top level).
        (Some(at), Some(field)) => match value_key(text, at) {
            Some(k) => format!("{k}.{field}"),
            None => {
                table_at(text, at).map_or_else(|| field.to_string(), |t| format!("{t}.{field}"))
            }
        },
        (Some(at), None) => key_at(text, at),
        (None, Some(field)) => field.to_string(),
        (None, None) => "-".to_string(),
    };
    let mut message = if raw == "duplicate key" {
        let line = at.map_or("", |at| line_at(text, at).1);
        match header_name(line) {
            Some(name) => format!(
                "a second [{name}] table: allowed is one [{name}] table per file (merge the two)"
            ),
            None => format!("duplicate key: `{key}` is given twice; each key may be given once"),
        }
    } else {
        user_words(raw)
    };
    if let Some(at) = at {
        let (start, line) = line_at(text, at);
        let number = text[..start].matches('\n').count() + 1;
        let column = text[start..at].chars().count() + 1;
        // At most 80 characters, control characters escaped.
        let mut snippet: String = line
            .trim()
            .chars()
            .take(80)
            .flat_map(|c| {
                if c.is_control() {
                    c.escape_unicode().collect::<Vec<_>>()
                } else {
                    vec![c]
                }
            })
            .collect();
        if line.trim().chars().count() > 80 {
            snippet.push_str("...");
        }
        message.push_str(&format!(" (line {number}, column {column}: `{snippet}`)"));
    }
    Error::Scene {
        file: path.to_path_buf(),
        key,
        message,
    }
}

/// A serde message with the Rust type names replaced by what a scene file holds.
fn user_words(message: &str) -> String {
    let mut m = message
        .replace("expected usize", "expected a whole number >= 0")
        .replace(
            "expected u64",
            "expected a whole number in [0, 18446744073709551615]",
        )
        .replace("expected f64", "expected a number (such as 1.0 or 1e-3)")
        .replace(
            "expected struct Ensemble",
            "expected an inline table such as { trajectories = 16, duration_tau1 = 40.0 }",
        )
        .replace("expected a sequence", "expected an array [...]")
        .replace("invalid type: map", "invalid type: table")
        .replace("invalid type: sequence", "invalid type: array");
    if m == "recursion limit" {
        m = "keys, tables or arrays nested too deeply for the TOML parser; a scene file's keys are at most four levels deep (e.g. runs[0].quick.trajectories): see `langevin-fem scene keys`".into();
    }
    if let Some(i) = m.find("expected struct ") {
        let end = m[i + 16..]
            .find(|c: char| !c.is_alphanumeric())
            .map_or(m.len(), |j| i + 16 + j);
        m.replace_range(i..end, "expected a table");
    }
    m
}

/// The field named by a serde "missing field `x`" message.
fn missing_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("missing field `")?;
    rest.split('`').next()
}

/// The start offset and text of the line holding byte `offset`.
fn line_at(text: &str, offset: usize) -> (usize, &str) {
    let offset = floor_char_boundary(text, offset.min(text.len()));
    let start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    (start, &text[start..end])
}

/// The largest char boundary of `text` at or below `i`.
fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The table name of a header line `[t]` or `[[t]]` (a comment after it allowed); `None`
/// for any other line, e.g. the continuation `[0.5, 0.5, 0.1, 0.2],` of an array.
fn header_name(line: &str) -> Option<&str> {
    let line = line.split('#').next().unwrap_or("").trim();
    let inner = line.strip_prefix('[')?.strip_suffix(']')?;
    let inner = inner
        .strip_prefix('[')
        .and_then(|i| i.strip_suffix(']'))
        .unwrap_or(inner)
        .trim();
    let ok = inner
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_' || c == '"')
        && !inner.contains(',');
    ok.then_some(inner)
}

/// The table whose header (`[t]` or `[[t]]`) is on the line of byte `offset`, or the
/// nearest header above it; `None` at top level (before any header). An element of an
/// array of tables is named with its index, e.g. `runs[1]`.
fn table_at(text: &str, offset: usize) -> Option<String> {
    let (start, line) = line_at(text, offset);
    let lines: Vec<&str> = text[..start + line.len()].lines().collect();
    let at = lines.iter().rposition(|l| header_name(l).is_some())?;
    let name = header_name(lines[at])?;
    if lines[at].trim_start().starts_with("[[") {
        let index = lines[..at]
            .iter()
            .filter(|l| l.trim_start().starts_with("[[") && header_name(l) == Some(name))
            .count();
        Some(format!("{name}[{index}]"))
    } else {
        Some(name.to_string())
    }
}

/// The key `k` of a line `k = value` (empty if the line has none).
fn line_key(line: &str) -> &str {
    match line.split_once('=') {
        Some((k, _)) if header_name(line).is_none() => k.trim(),
        _ => "",
    }
}

/// The dotted key of the entry around byte `offset`: the header's table on a header
/// line, else the `key =` of its line qualified by the table above it, else that table.
fn key_at(text: &str, offset: usize) -> String {
    let (_, line) = line_at(text, offset);
    let table = table_at(text, offset);
    let key = line_key(line);
    match (table, header_name(line).is_some() || key.is_empty()) {
        (Some(t), true) => t,
        (Some(t), false) => format!("{t}.{key}"),
        (None, false) => key.to_string(),
        (None, true) => "-".to_string(),
    }
}

/// The dotted key of the entry whose value holds byte `offset` (`offset` after the `=`
/// of a `key = value` line), else `None`.
fn value_key(text: &str, offset: usize) -> Option<String> {
    let (start, line) = line_at(text, offset);
    let eq = line.find('=')?;
    (header_name(line).is_none() && offset > start + eq).then(|| key_at(text, offset))
}

#[cfg(test)]
mod tests {

    //! The accessors of a scene that are not its filament's: τ1 and the displacement
    //! components of a membrane against closed forms written out here (independent of
    //! `crate::spectral::membrane`), and the same arithmetic as before for a filament.

    use super::*;
    use std::f64::consts::PI;

    /// A membrane scene's provenance records the membrane (sides, κ, σ, ξ, kT; τ₁, the
    /// buckling tension and σ/(κq_min²)), not the filament defaults it never reads.
    #[test]
    fn a_membrane_scene_records_its_membrane() {
        let scene = crate::scene::builtin::load_scene("membrane-periodic", None).unwrap();
        let m = scene.membrane.unwrap();
        let r = scene.describe().parameters;
        let names: Vec<&str> = r.parameters.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            [
                "bending_rigidity",
                "drag",
                "height",
                "kt",
                "tension",
                "width"
            ]
        );
        assert_eq!(r.parameters["tension"].value, m.tension);
        assert_eq!(r.groups["tau1"].value, m.tau1());
        assert!(!r.groups.contains_key("euler_load"));
        let ratio = r.groups["tension_ratio"].value;
        assert!((ratio - m.tension / (4.0 * std::f64::consts::PI.powi(2))).abs() < 1e-12);
    }

    /// A membrane scene with `[membrane]` keys `table` (a valid sampling plan for any
    /// simply supported or periodic 8 × 4 mesh).
    fn membrane(table: &str) -> Scene {
        let text = format!(
            r#"description = "membrane"
seed = 1
dims = 3
model = "fem"
checks = ["mode-variance"]

[membrane]
{table}

[mesh]
elements = 8
elements_y = 4

[sampling]
burn_in_tau1 = 1.0
modes = 4

[[runs]]
name = "cn"
dt_tau1 = 0.01
quick = {{ trajectories = 4, duration_tau1 = 40.0 }}
standard = {{ trajectories = 4, duration_tau1 = 40.0 }}
full = {{ trajectories = 4, duration_tau1 = 40.0 }}
"#
        );
        Scene::parse(&text, Path::new("m.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"))
    }

    /// A filament scene in `dims` dimensions with `[filament]` keys `table`.
    fn filament(dims: usize, table: &str) -> Scene {
        let text = format!(
            r#"description = "filament"
seed = 1
dims = {dims}
model = "fem"
checks = ["mode-variance"]

[filament]
{table}

[mesh]
elements = 4

[sampling]
burn_in_tau1 = 1.0
modes = 2

[[runs]]
name = "cn"
dt_tau1 = 0.01
quick = {{ trajectories = 4, duration_tau1 = 40.0 }}
standard = {{ trajectories = 4, duration_tau1 = 40.0 }}
full = {{ trajectories = 4, duration_tau1 = 40.0 }}
"#
        );
        Scene::parse(&text, Path::new("f.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"))
    }

    /// Relative difference.
    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// τ1 of a simply supported membrane is ξ/(κq⁴ + σq²) of its slowest mode (1, 1),
    /// q² = π²(1/a² + 1/b²), for a tension of either sign. Tolerance 1e-14: a handful of
    /// roundings either way.
    #[test]
    fn membrane_tau1_simply_supported_is_the_slowest_mode_closed_form() {
        let (kappa, xi, a, b) = (0.8, 2.5, 1.7, 1.1);
        let q2 = PI * PI * (1.0 / (a * a) + 1.0 / (b * b));
        for sigma in [0.0, 0.3, -0.9 * kappa * q2] {
            let s = membrane(&format!(
                "bending_rigidity = {kappa}\ntension = {sigma:e}\ndrag = {xi}\nwidth = {a}\nheight = {b}"
            ));
            let expected = xi / (kappa * q2 * q2 + sigma * q2);
            assert!(
                rel(s.tau1(), expected) < 1e-14,
                "sigma {sigma}: {} vs {expected}",
                s.tau1()
            );
        }
        // κ = ξ = a = b = 1, σ = 0: τ1 = 1/(4π⁴).
        let unit = membrane("boundary = \"simply-supported\"");
        assert!(rel(unit.tau1(), 1.0 / (4.0 * PI.powi(4))) < 1e-14);
    }

    /// τ1 of a periodic membrane is that of its slowest modes, q = 2π/max(a, b) along the
    /// longer side: ξ/(κq⁴ + σq²).
    #[test]
    fn membrane_tau1_periodic_is_the_longest_wavelength_closed_form() {
        let (kappa, sigma, xi) = (1.3, 0.7, 0.4);
        for (a, b) in [(2.0, 1.0), (1.0, 3.0)] {
            let s = membrane(&format!(
                "bending_rigidity = {kappa}\ntension = {sigma}\ndrag = {xi}\nwidth = {a}\nheight = {b}\nboundary = \"periodic\""
            ));
            let q = 2.0 * PI / f64::max(a, b);
            let expected = xi / (kappa * q.powi(4) + sigma * q * q);
            assert!(
                rel(s.tau1(), expected) < 1e-14,
                "{a} x {b}: {} vs {expected}",
                s.tau1()
            );
        }
    }

    /// A filament's τ1 is its ξL⁴/(π⁴EI), bit for bit (the accessor replaced
    /// `scene.filament.tau1()` at every call site outside the pipeline).
    #[test]
    fn filament_tau1_is_unchanged() {
        let s = filament(2, "length = 1.7\nbending_rigidity = 0.3\ndrag = 2.9");
        assert_eq!(s.tau1().to_bits(), s.filament.tau1().to_bits());
        let expected = 2.9 * 1.7f64.powi(4) / (PI.powi(4) * 0.3);
        assert!(rel(s.tau1(), expected) < 1e-14);
    }

    /// Components: a filament has dims − 1 transverse directions, a membrane one height.
    #[test]
    fn components_of_filaments_and_membranes() {
        assert_eq!(filament(2, "kt = 1.0").components(), 1);
        assert_eq!(filament(3, "kt = 1.0").components(), 2);
        let m = membrane("kt = 1.0");
        assert_eq!((m.dims, m.components()), (3, 1));
        assert!(m.is_membrane() && !filament(3, "kt = 1.0").is_membrane());
    }

    /// A membrane scene is refused where only filaments can go, naming the file, the key
    /// `membrane`, the scene and what was refused; a filament scene passes.
    #[test]
    fn membranes_are_refused_where_only_filaments_go() {
        let what = "run of a membrane under imposed projected area";
        assert!(filament(2, "kt = 1.0").refuse_membrane(what).is_ok());
        let e = membrane("kt = 1.0").refuse_membrane(what).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let m = e.to_string();
        for needle in [
            "m.toml: key `membrane`",
            "run of a membrane under imposed projected area is not written yet",
            "scene \"m\"",
            "`verify` checks",
        ] {
            assert!(m.contains(needle), "{needle}: {m}");
        }
    }
}
