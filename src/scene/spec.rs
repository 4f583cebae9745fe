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

use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::params::FilamentParams;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The ensemble size and duration of a run at one budget.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ensemble {
    /// Number of independent trajectories, each started from rest.
    pub trajectories: usize,
    /// Sampled duration of each trajectory after burn-in, in units of τ1.
    pub duration_tau1: f64,
    /// Extra short trajectories (from rest to the largest η) for the two-time check only;
    /// default 0.
    #[serde(default)]
    pub two_time_trajectories: usize,
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
        scene.validate(path)?;
        Ok(scene)
    }

    fn validate(&self, path: &Path) -> Result<()> {
        let bad = |key: &str, value: &dyn std::fmt::Display, allowed: &str| Error::Scene {
            file: path.to_path_buf(),
            key: key.to_string(),
            message: format!("must be {allowed}, got {value}"),
        };
        let f = &self.filament;
        // Bounds keep every derived quantity (tau1, lambda_max, variances) inside f64.
        for (key, v) in [
            ("filament.length", f.length),
            ("filament.bending_rigidity", f.bending_rigidity),
            ("filament.stretch_rigidity", f.stretch_rigidity),
            ("filament.drag", f.drag),
            ("filament.kt", f.kt),
        ] {
            if !(v.is_finite() && (1e-30..=1e30).contains(&v)) {
                return Err(bad(key, &v, "in [1e-30, 1e30]"));
            }
        }
        if self.dims != 2 && self.dims != 3 {
            return Err(bad("dims", &self.dims, "2 or 3"));
        }
        if self.checks.is_empty() {
            return Err(bad("checks", &"[]", "a non-empty list"));
        }
        if !(1..=1000).contains(&self.mesh.elements) {
            return Err(bad("mesh.elements", &self.mesh.elements, "in [1, 1000]"));
        }
        let g = self.mesh.grading;
        if !(g.is_finite() && (0.01..=100.0).contains(&g)) {
            return Err(bad("mesh.grading", &g, "in [0.01, 100]"));
        }
        let s = &self.sampling;
        if !(s.burn_in_tau1.is_finite() && s.burn_in_tau1 >= 0.0 && s.burn_in_tau1 <= 1e4) {
            return Err(bad("sampling.burn_in_tau1", &s.burn_in_tau1, "in [0, 1e4]"));
        }
        if self.model == ModelKind::Compression {
            return self.validate_compression(path);
        }
        for (i, c) in self.checks.iter().enumerate() {
            if c.is_compression() {
                let allowed = "a linear check (profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time) for model \"fem\" or \"spectral\"";
                return Err(bad(&format!("checks[{i}]"), &format!("{c:?}"), allowed));
            }
        }
        if self.compression.is_some() {
            return Err(bad(
                "compression",
                &"a [compression] table",
                "absent unless model = \"compression\"",
            ));
        }
        let max_modes = match self.model {
            ModelKind::Fem => 2 * self.mesh.elements,
            _ => self.mesh.elements,
        };
        if s.modes < 1 || s.modes > max_modes.min(50) {
            let allowed = format!("in [1, {}]", max_modes.min(50));
            return Err(bad("sampling.modes", &s.modes, &allowed));
        }
        for (i, &x) in s.profile_points.iter().enumerate() {
            if !(x.is_finite() && (0.0..=1.0).contains(&x)) {
                return Err(bad(
                    &format!("sampling.profile_points[{i}]"),
                    &x,
                    "in [0, 1]",
                ));
            }
        }
        for (i, p) in s.two_time.iter().enumerate() {
            for (j, name) in ["x/L", "y/L"].iter().enumerate() {
                if !(p[j].is_finite() && (0.0..=1.0).contains(&p[j])) {
                    let key = format!("sampling.two_time[{i}][{j}] ({name})");
                    return Err(bad(&key, &p[j], "in [0, 1]"));
                }
            }
            if !(p[3].is_finite() && p[3] > 0.0) {
                let key = format!("sampling.two_time[{i}][3] (eta/tau1)");
                return Err(bad(&key, &p[3], "finite and > 0"));
            }
            if !(p[2].is_finite() && p[2] > 0.0 && p[2] <= p[3]) {
                let key = format!("sampling.two_time[{i}][2] (t/tau1)");
                return Err(bad(&key, &p[2], &format!("in (0, eta/tau1 = {}]", p[3])));
            }
            if p[3].is_nan() || p[3] > s.burn_in_tau1 {
                let key = format!("sampling.two_time[{i}][3] (eta/tau1)");
                let allowed = format!("<= sampling.burn_in_tau1 = {}", s.burn_in_tau1);
                return Err(bad(&key, &p[3], &allowed));
            }
        }
        let all_checks = || {
            self.checks
                .iter()
                .chain(self.runs.iter().flat_map(|r| r.checks.iter().flatten()))
        };
        if all_checks().any(|c| *c == CheckKind::Profile) && s.profile_points.is_empty() {
            return Err(bad(
                "sampling.profile_points",
                &"[]",
                "non-empty when checks has \"profile\"",
            ));
        }
        if all_checks().any(|c| *c == CheckKind::TwoTime) && s.two_time.is_empty() {
            return Err(bad(
                "sampling.two_time",
                &"[]",
                "non-empty when checks has \"two-time\"",
            ));
        }
        if self.runs.is_empty() {
            return Err(bad("runs", &"[]", "at least one [[runs]] table"));
        }
        for (i, run) in self.runs.iter().enumerate() {
            let key = |k: &str| format!("runs[{i}].{k}");
            let valid_name = !run.name.is_empty()
                && run
                    .name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
            if !valid_name {
                return Err(bad(
                    &key("name"),
                    &format!("{:?}", run.name),
                    "non-empty [A-Za-z0-9_-]",
                ));
            }
            if self.runs[..i].iter().any(|r| r.name == run.name) {
                return Err(bad(&key("name"), &run.name, "unique within the scene"));
            }
            if run.integrator == IntegratorKind::MetropolisCrankNicolson {
                let allowed = "euler-maruyama, backward-euler, crank-nicolson or exact-modal for a linear scene (metropolis-crank-nicolson is for model = \"compression\")";
                return Err(bad(&key("integrator"), &run.integrator, allowed));
            }
            if run.checks.as_ref().is_some_and(|c| c.is_empty()) {
                return Err(bad(
                    &key("checks"),
                    &"[]",
                    "a non-empty list (or leave it out)",
                ));
            }
            if !(run.dt_tau1.is_finite() && run.dt_tau1 > 0.0 && run.dt_tau1 <= 100.0) {
                return Err(bad(&key("dt_tau1"), &run.dt_tau1, "in (0, 100]"));
            }
            for budget in [Budget::Quick, Budget::Standard, Budget::Full] {
                let e = run.ensemble(budget);
                let b = budget.name();
                if !(2..=100_000).contains(&e.trajectories) {
                    return Err(bad(
                        &key(&format!("{b}.trajectories")),
                        &e.trajectories,
                        "in [2, 100000]",
                    ));
                }
                if !(e.duration_tau1.is_finite() && e.duration_tau1 > 0.0 && e.duration_tau1 <= 1e6)
                {
                    return Err(bad(
                        &key(&format!("{b}.duration_tau1")),
                        &e.duration_tau1,
                        "in (0, 1e6]",
                    ));
                }
                let steps = (s.burn_in_tau1 + e.duration_tau1) / run.dt_tau1;
                if steps > 1e10 {
                    let allowed = "such that (burn_in_tau1 + duration_tau1)/dt_tau1 <= 1e10 steps";
                    return Err(bad(
                        &key(&format!("{b}.duration_tau1")),
                        &e.duration_tau1,
                        allowed,
                    ));
                }
            }
        }
        Ok(())
    }

    /// Validation of a compression scene (model = "compression").
    fn validate_compression(&self, path: &Path) -> Result<()> {
        let bad = |key: &str, value: &dyn std::fmt::Display, allowed: &str| Error::Scene {
            file: path.to_path_buf(),
            key: key.to_string(),
            message: format!("must be {allowed}, got {value}"),
        };
        let Some(c) = &self.compression else {
            return Err(bad(
                "compression",
                &"nothing",
                "a [compression] table for model = \"compression\"",
            ));
        };
        for (i, k) in self.checks.iter().enumerate() {
            if !k.is_compression() {
                return Err(bad(
                    &format!("checks[{i}]"),
                    &format!("{k:?}"),
                    "force-strain, force-distribution or dt-halving for model = \"compression\"",
                ));
            }
        }
        if c.strain_ratios.is_empty() {
            return Err(bad("compression.strain_ratios", &"[]", "a non-empty list"));
        }
        if self.mesh.grading != 1.0 {
            // The exact discrete theory uses the closed-form spectrum of a uniform mesh.
            return Err(bad(
                "mesh.grading",
                &self.mesh.grading,
                "1 (uniform) for model = \"compression\"",
            ));
        }
        for (i, &r) in c.strain_ratios.iter().enumerate() {
            if !(r.is_finite() && (-1e3..=1e3).contains(&r)) {
                return Err(bad(
                    &format!("compression.strain_ratios[{i}]"),
                    &r,
                    "finite, in [-1000, 1000]",
                ));
            }
        }
        for (i, r) in c.distribution_strain_ratios.iter().enumerate() {
            if !c.strain_ratios.contains(r) {
                return Err(bad(
                    &format!("compression.distribution_strain_ratios[{i}]"),
                    r,
                    "one of compression.strain_ratios",
                ));
            }
        }
        if !(c.burn_in_tau1.is_finite() && (0.0..=1e4).contains(&c.burn_in_tau1)) {
            return Err(bad(
                "compression.burn_in_tau1",
                &c.burn_in_tau1,
                "in [0, 1e4]",
            ));
        }
        if !(c.sample_every_tau1.is_finite()
            && c.sample_every_tau1 > 0.0
            && c.sample_every_tau1 <= 100.0)
        {
            return Err(bad(
                "compression.sample_every_tau1",
                &c.sample_every_tau1,
                "in (0, 100]",
            ));
        }
        if self.runs.is_empty() {
            return Err(bad("runs", &"[]", "at least one [[runs]] table"));
        }
        for (i, run) in self.runs.iter().enumerate() {
            let key = |k: &str| format!("runs[{i}].{k}");
            if run.integrator == IntegratorKind::ExactModal {
                return Err(bad(
                    &key("integrator"),
                    &run.integrator,
                    "euler-maruyama, backward-euler, crank-nicolson or metropolis-crank-nicolson for model = \"compression\"",
                ));
            }
            if run.integrator == IntegratorKind::MetropolisCrankNicolson
                && run.noise != NoiseModel::Consistent
            {
                return Err(bad(
                    &key("noise"),
                    &run.noise.name(),
                    "consistent for metropolis-crank-nicolson",
                ));
            }
            if run
                .checks
                .as_ref()
                .is_some_and(|cs| cs.iter().any(|k| !k.is_compression()))
            {
                return Err(bad(
                    &key("checks"),
                    &"a linear check",
                    "compression checks only",
                ));
            }
            if self.runs[..i].iter().any(|r| r.name == run.name) {
                return Err(bad(&key("name"), &run.name, "unique within the scene"));
            }
            if !(run.dt_tau1.is_finite() && run.dt_tau1 > 0.0 && run.dt_tau1 <= c.sample_every_tau1)
            {
                let allowed = format!(
                    "in (0, compression.sample_every_tau1 = {}]",
                    c.sample_every_tau1
                );
                return Err(bad(&key("dt_tau1"), &run.dt_tau1, &allowed));
            }
            for budget in [Budget::Quick, Budget::Standard, Budget::Full] {
                let e = run.ensemble(budget);
                let b = budget.name();
                if !(2..=100_000).contains(&e.trajectories) {
                    return Err(bad(
                        &key(&format!("{b}.trajectories")),
                        &e.trajectories,
                        "in [2, 100000] (per strain)",
                    ));
                }
                let samples = e.duration_tau1 / c.sample_every_tau1;
                if !(e.duration_tau1.is_finite() && samples >= 16.0 && e.duration_tau1 <= 1e6) {
                    let allowed = format!(
                        "<= 1e6 and >= 16 x sample_every_tau1 = {}",
                        16.0 * c.sample_every_tau1
                    );
                    return Err(bad(
                        &key(&format!("{b}.duration_tau1")),
                        &e.duration_tau1,
                        &allowed,
                    ));
                }
            }
        }
        if let Some([a, b]) = &c.halving {
            for (j, n) in [a, b].iter().enumerate() {
                if !self.runs.iter().any(|r| &r.name == *n) {
                    return Err(bad(
                        &format!("compression.halving[{j}]"),
                        n,
                        "the name of a run of this scene",
                    ));
                }
            }
        } else if self.checks.contains(&CheckKind::DtHalving) {
            return Err(bad(
                "compression.halving",
                &"nothing",
                "two run names when checks has \"dt-halving\"",
            ));
        }
        Ok(())
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
