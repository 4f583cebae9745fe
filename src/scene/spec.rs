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
//!
//! [mesh]
//! elements = 10                  # fem: element count; spectral: number of modes
//! grading = 1.0                  # last/first element length (1 = uniform)
//!
//! [sampling]
//! burn_in_tau1 = 5.0             # from rest, before sampling starts (units of τ1)
//! modes = 6                      # modes checked
//! profile_points = [0.25, 0.5]   # x/L where ⟨w²(x)⟩ is checked
//! two_time = [[0.5, 0.5, 0.05, 0.1]]  # (x/L, y/L, t/τ1, η/τ1) for eq. (4), from rest
//!
//! [[runs]]
//! name = "crank-nicolson"
//! integrator = "crank-nicolson"  # euler-maruyama | backward-euler | crank-nicolson | exact-modal
//! noise = "consistent"           # consistent | element-uniform
//! dt_tau1 = 0.01                 # time step in units of τ1
//! quick = { trajectories = 16, duration_tau1 = 20.0 }
//! standard = { trajectories = 32, duration_tau1 = 100.0 }
//! full = { trajectories = 64, duration_tau1 = 400.0 }
//! ```
//!
//! An ensemble's keys (every budget: `quick`, `standard`, `full`):
//!
//! - `trajectories`: independent trajectories (per strain in a compression scene),
//!   in [2, 100000];
//! - `duration_tau1`: sampled duration of each trajectory after burn-in, in units of τ1
//!   (a fixed budget; required unless `target_std_error` is given, and then left out);
//! - `two_time_trajectories`: extra short trajectories of the two-time check (linear
//!   scenes only), default 0.
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

use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::params::FilamentParams;
use serde::{Deserialize, Serialize};
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

/// A missing `duration_tau1` (NaN: not a valid duration, refused by validation unless
/// `target_std_error` replaces it).
fn not_given() -> f64 {
    f64::NAN
}

/// Whether a duration was left out ([`not_given`]).
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
}

/// Discretization of the filament.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Element count (fem) or number of modes (spectral).
    pub elements: usize,
    /// Ratio of the last to the first element length (geometric grading); 1 is uniform.
    #[serde(default = "one")]
    pub grading: f64,
}

fn one() -> f64 {
    1.0
}

impl MeshSpec {
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
    /// Positions x/L of the profile check.
    #[serde(default)]
    pub profile_points: Vec<f64>,
    /// (x/L, y/L, t/τ1, η/τ1) of the two-time check.
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
    /// 2 (one transverse direction) or 3 (two).
    pub dims: usize,
    /// What is simulated.
    pub model: ModelKind,
    /// Which checks to run.
    pub checks: Vec<CheckKind>,
    /// Physical parameters.
    #[serde(default)]
    pub filament: FilamentParams,
    /// Discretization.
    pub mesh: MeshSpec,
    /// Sampling plan (linear models).
    #[serde(default)]
    pub sampling: Sampling,
    /// Strains and sampling (compression model).
    #[serde(default)]
    pub compression: Option<CompressionSpec>,
    /// Integrator/noise/time-step combinations.
    pub runs: Vec<RunSpec>,
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
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let message = e.message().trim().to_string();
            let key = match (e.span(), missing_field(&message)) {
                (Some(s), Some(field)) => match table_at(text, s.start) {
                    Some(t) => format!("{t}.{field}"),
                    None => field.to_string(),
                },
                (Some(s), None) => key_at(text, s.start),
                (None, Some(field)) => field.to_string(),
                (None, None) => "-".to_string(),
            };
            Error::Scene {
                file: path.to_path_buf(),
                key,
                message,
            }
        })?;
        scene.path = path.to_path_buf();
        scene.name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
            .to_string();
        scene.validate()?;
        Ok(scene)
    }

    /// Wraps an error raised while preparing or running run `run` of this scene so that
    /// the message names the scene file and the run's key (bad input, exit 2), unless it
    /// already names them. A divergence (exit 3) keeps its kind and step and gains the
    /// file and run.
    pub fn run_error(&self, run: usize, what: &str, err: Error) -> Error {
        let tau1 = self.filament.tau1();
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
                integrator,
                dt,
                limit,
                suggestion,
            } => Error::Scene {
                file: self.path.clone(),
                key: key("dt_tau1"),
                message: format!(
                    "must be < {:.4e} (the stability limit 2/lambda_max of {integrator} for this mesh, in units of tau1), got {:.4e}; use a smaller dt_tau1 or a stable integrator such as {suggestion}",
                    limit / tau1,
                    dt / tau1
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

/// The field named by a serde "missing field `x`" message.
fn missing_field(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("missing field `")?;
    rest.split('`').next()
}

/// The table whose header (`[t]` or `[[t]]`) is on the line of byte `offset`, or the
/// nearest header above it; `None` at top level (before any header).
fn table_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let lines: Vec<&str> = text[..line_end].lines().map(str::trim).collect();
    let at = lines.iter().rposition(|l| l.starts_with('['))?;
    let header = lines[at];
    let name = header.trim_matches(|c| c == '[' || c == ']').to_string();
    if header.starts_with("[[") {
        // An array of tables: name the element, e.g. `runs[1]`.
        let index = lines[..at].iter().filter(|l| **l == header).count();
        Some(format!("{name}[{index}]"))
    } else {
        Some(name)
    }
}

/// The dotted key of the TOML entry around byte `offset`: the nearest `key =` on the
/// line of the error, qualified by the table header above it.
fn key_at(text: &str, offset: usize) -> String {
    let before = &text[..offset.min(text.len())];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    let line = &text[line_start..line_end];
    let key = line.split('=').next().unwrap_or("").trim();
    let table = before[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').to_string());
    let key = if line.contains('=') && !key.starts_with('[') {
        key.to_string()
    } else {
        String::new()
    };
    match (table, key.is_empty()) {
        (Some(t), false) => format!("{t}.{key}"),
        (Some(t), true) => t,
        (None, false) => key,
        (None, true) => "-".to_string(),
    }
}

/// Resolves `--scene` arguments (names or paths) against `scene_dir`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming an unknown scene and listing the known ones.
pub fn resolve_scenes(names: &[String], scene_dir: &Path) -> Result<Vec<PathBuf>> {
    if names.is_empty() {
        return Scene::discover(scene_dir);
    }
    names
        .iter()
        .map(|n| {
            let p = PathBuf::from(n);
            if p.extension().is_some_and(|x| x == "toml") && p.exists() {
                return Ok(p);
            }
            let known = Scene::discover(scene_dir)?;
            known
                .iter()
                .find(|k| k.file_stem().is_some_and(|s| s == n.as_str()))
                .cloned()
                .ok_or_else(|| {
                    let names: Vec<String> = known
                        .iter()
                        .filter_map(|k| k.file_stem().map(|s| s.to_string_lossy().into_owned()))
                        .collect();
                    Error::invalid("--scene", n, format!("one of: {}", names.join(", ")))
                })
        })
        .collect()
}
