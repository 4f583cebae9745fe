//! Validation of a scene: one validator for linear (`fem`, `spectral`) and compression
//! scenes.
//!
//! [`Scene::validate`] runs, in order:
//!
//! 1. the checks of every scene: its name (the file stem, a path component of the
//!    outputs: [`is_path_name`], at most [`MAX_NAME_LEN`] characters), filament, `dims`,
//!    `checks`, mesh and burn-in; of a membrane scene, instead of the filament and its
//!    mesh: one object only (no `[filament]` table), a linear model, `dims = 3`, the
//!    membrane's parameters and its uniform mesh ([`MAX_MEMBRANE_ELEMENTS_PER_SIDE`],
//!    [`MAX_MEMBRANE_ELEMENTS`]);
//! 2. the model's own tables: `[sampling]` of a linear scene, `[compression]` of a
//!    compression scene;
//! 3. ONE per-run check shared by both kinds of scene ([`Scene::validate`] →
//!    `validate_run`): run name (a path component: non-empty `[A-Za-z0-9_-]`, unique),
//!    integrator and noise, the run's own checks, `dt_tau1` and the ensemble of every
//!    budget. What differs between models (allowed integrators, largest time step,
//!    shortest duration) is stated by the private `RunRules`;
//! 4. the Δt-halving pair of a compression scene.
//!
//! Every error is an [`Error::Scene`] naming the file, the key, the value (numbers in
//! full precision, [`Num`]) and the allowed range (exit code 2). Every count is bounded
//! here, before anything is allocated or run: trajectories, list lengths
//! ([`MAX_POINTS`]), durations and steps per trajectory (at most 1e10).
//!
//! Their product, the total work of the scene's runs at a budget, is projected here too
//! ([`Scene::projected_work`], [`Scene::run_work`]) and capped by the command that runs
//! them ([`crate::work::WorkLimits`]): the cap is a setting of the command
//! (`--max-work`), not of the scene.

use super::compression::PROBE_STEPS;
use super::linear::MAX_SAMPLES;
use super::spec::{
    Budget, CheckKind, CompressionSpec, Ensemble, ModelKind, RunSpec, Sampling, Scene,
};
use crate::dynamics::{Family, IntegratorKind};
use crate::error::{Error, Result};
use crate::fem::noise::NoiseModel;
use crate::fem::plate_area::AreaParams;
use crate::params::{End, physical};
use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
use crate::theory::DomainInput;
use crate::work::{Origin, Part, RunWork};
use std::fmt::Display;

/// Most trajectories (full or two-time) of a run at one budget.
const MAX_TRAJECTORIES: usize = 100_000;

/// Longest name that becomes a path component (scene file stem, run name), in
/// characters: file names of the outputs add a suffix to it and must stay below the
/// 255 bytes file systems allow.
pub const MAX_NAME_LEN: usize = 64;

/// Most entries of `sampling.profile_points`, `sampling.two_time` and
/// `compression.strain_ratios` (each one multiplies the recorded series or the runs).
pub const MAX_POINTS: usize = 100;

/// Shortest sampled duration of a linear run, in units of τ1: mode 1 is sampled about
/// every 0.5 τ1, and its estimators need at least 32 samples per trajectory.
pub const MIN_LINEAR_DURATION_TAU1: f64 = 16.0;

/// The most elements (or spectral modes) of a mesh: `mesh.elements` is in
/// [1, `MAX_ELEMENTS`], and so is a data sidecar's `discretization.elements`.
pub const MAX_ELEMENTS: usize = 1000;

/// The most elements (or mode indices kept) along either side of a membrane:
/// `mesh.elements` and `mesh.elements_y` are in [1, 256] ([2, 256] periodic).
pub const MAX_MEMBRANE_ELEMENTS_PER_SIDE: usize = 256;

/// The most elements (or modes kept) of a membrane mesh in all:
/// `mesh.elements × mesh.elements_y` is at most 4096.
pub const MAX_MEMBRANE_ELEMENTS: usize = 4096;

/// The most modes a linear scene checks (`sampling.modes`).
pub const MAX_CHECKED_MODES: usize = 50;

/// Fewest sampled steps of a linear run per trajectory (`duration_tau1 / dt_tau1`): below
/// this the series of the stiff modes, sampled every step, are too short for their
/// autocorrelation-aware estimators.
pub const MIN_LINEAR_STEPS: f64 = 256.0;

/// A number as the user wrote it: the shortest text that reads back as the same `f64`
/// (so that "must be < a, got b" never shows a = b), in exponent form below 1e-3 and from
/// 1e7 on (`1e300`, not 301 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-3..1e7).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// The allowed checks of a linear scene, for messages.
const LINEAR_CHECKS: &str = "a linear check (profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time, pooled-variance; xy-symmetry for a membrane; rigid-diffusion for a filament with a free end; tangent-angle for a finite-element filament without a clamped end) for model \"fem\" or \"spectral\"";
/// The allowed positions x/L of the profile and two-time checks, for messages: the
/// hinges x/L = 0 and 1 have w = 0 exactly, so nothing fluctuates there to check.
const INTERIOR: &str = "in (0, 1) (inside the filament: w = 0 at the hinges x/L = 0 and 1)";
/// The allowed positions x/a of a simply supported membrane, for messages.
/// As [`INTERIOR`] for hinged or clamped ends other than two hinges.
const FIXED_ENDS: &str =
    "in (0, 1) (inside the filament: w = 0 at its hinged or clamped ends x/L = 0 and 1)";
/// A free end at x = 0 fluctuates: it may be checked.
const FREE_LEFT: &str = "in [0, 1) (w = 0 at the end x/L = 1; the free end x/L = 0 fluctuates)";
/// A free end at x = L fluctuates: it may be checked (the tip of a grafted filament).
const FREE_RIGHT: &str = "in (0, 1] (w = 0 at the end x/L = 0; the free end x/L = 1 fluctuates)";
/// Both ends free.
const FREE_BOTH: &str = "in [0, 1] (both ends are free)";
const MEMBRANE_INTERIOR: &str = "in (0, 1) (x/a on the midline y = b/2, inside the membrane: h = 0 on the simply supported edges x/a = 0 and 1)";
/// The allowed positions x/a of a periodic membrane, for messages.
const MEMBRANE_PERIOD: &str =
    "in [0, 1) (x/a on the midline y = b/2 of a periodic membrane, where x/a = 1 is x/a = 0)";
/// The allowed checks of a compression scene, for messages.
const COMPRESSION_CHECKS: &str =
    "force-strain, force-distribution or dt-halving for model = \"compression\"";

/// The error for `key` of `scene`'s file: "must be {allowed}, got {value}".
/// The counts of a membrane mesh (a scene's `mesh`, or a sidecar's `discretization`:
/// `prefix`), `elements` and `elements_y` (default: `elements`), each in
/// [1, [`MAX_MEMBRANE_ELEMENTS_PER_SIDE`]] ([2, …] periodic: one element would join its
/// own opposite edges), their product at most [`MAX_MEMBRANE_ELEMENTS`]; the first
/// violation as (key, value, allowed), or `None`.
pub(crate) fn membrane_mesh_violation(
    boundary: MembraneBoundary,
    nx: usize,
    elements_y: Option<usize>,
    prefix: &str,
) -> Option<(String, usize, String)> {
    let (lo, allowed) = match boundary {
        MembraneBoundary::SimplySupported => (
            1,
            format!("in [1, {MAX_MEMBRANE_ELEMENTS_PER_SIDE}] for a membrane"),
        ),
        MembraneBoundary::Periodic => (
            2,
            format!(
                "in [2, {MAX_MEMBRANE_ELEMENTS_PER_SIDE}] for a periodic membrane (one element would join its own opposite edges, leaving only the uniform displacement, which is not a mode)"
            ),
        ),
    };
    let (kx, ky) = (format!("{prefix}.elements"), format!("{prefix}.elements_y"));
    let range = lo..=MAX_MEMBRANE_ELEMENTS_PER_SIDE;
    if !range.contains(&nx) {
        return Some((kx, nx, allowed));
    }
    if let Some(ny) = elements_y
        && !range.contains(&ny)
    {
        return Some((ky, ny, allowed));
    }
    let ny = elements_y.unwrap_or(nx);
    if nx * ny <= MAX_MEMBRANE_ELEMENTS {
        return None;
    }
    Some(match elements_y {
        Some(ny) => (
            ky.clone(),
            ny,
            format!(
                "at most {} (a membrane mesh has at most {MAX_MEMBRANE_ELEMENTS} elements: {kx} x {ky} = {nx} x {ny} = {})",
                MAX_MEMBRANE_ELEMENTS / nx,
                nx * ny
            ),
        ),
        None => (
            kx.clone(),
            nx,
            format!(
                "at most {} when {ky} is left out (it defaults to {kx}, and a membrane mesh has at most {MAX_MEMBRANE_ELEMENTS} elements: {nx} x {nx} = {})",
                MAX_MEMBRANE_ELEMENTS.isqrt(),
                nx * nx
            ),
        ),
    })
}

fn bad(scene: &Scene, key: &str, value: &dyn Display, allowed: &str) -> Error {
    Error::Scene {
        file: scene.path.clone(),
        key: key.to_string(),
        message: format!("must be {allowed}, got {value}"),
    }
}

/// Whether `name` is safe as one path component of the outputs: 1 to [`MAX_NAME_LEN`]
/// characters of `[A-Za-z0-9_-]` only (so no `/`, `..` or hidden file, and room for the
/// suffixes of the file names it prefixes within a file system's 255 bytes).
pub fn is_path_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_NAME_LEN
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// The one check of every name that becomes a path component under `--out` (the scene
/// name and the run names): [`is_path_name`], else an [`Error::Scene`] naming the file,
/// `key` and the name.
fn check_path_name(scene: &Scene, key: &str, name: &str) -> Result<()> {
    let chars = name.chars().count();
    if chars > MAX_NAME_LEN {
        let value = format!("a name of {chars} characters");
        let allowed = format!("at most {MAX_NAME_LEN} characters of [A-Za-z0-9_-]");
        Err(bad(scene, key, &value, &allowed))
    } else if is_path_name(name) {
        Ok(())
    } else {
        Err(bad(
            scene,
            key,
            &format!("{name:?}"),
            "non-empty [A-Za-z0-9_-]",
        ))
    }
}

/// The model-specific limits of the shared per-run check.
enum RunRules<'a> {
    /// A linear scene (`fem` or `spectral`) and its sampling plan.
    Linear(&'a Sampling),
    /// A compression scene and its strains and sampling.
    Compression(&'a CompressionSpec),
}

/// The most steps one compression trajectory may take (burn-in and sampling).
const MAX_STEPS_PER_TRAJECTORY: f64 = 1e10;

impl RunRules<'_> {
    /// The integrator and noise of run `i`: linear scenes cannot use the Metropolis
    /// scheme, compression scenes neither the exact modal one nor Metropolis with
    /// element-uniform noise.
    fn check_integrator(&self, scene: &Scene, i: usize, run: &RunSpec) -> Result<()> {
        let key = |k: &str| format!("runs[{i}].{k}");
        match self {
            RunRules::Linear(_) => {
                if run.integrator == IntegratorKind::MetropolisCrankNicolson {
                    let allowed = format!(
                        "{} for a linear scene (metropolis-crank-nicolson is for model = \"compression\")",
                        IntegratorKind::list(&IntegratorKind::LINEAR)
                    );
                    return Err(bad(scene, &key("integrator"), &run.integrator, &allowed));
                }
            }
            RunRules::Compression(_) => {
                if run.integrator == IntegratorKind::ExactModal {
                    let allowed = format!(
                        "{} for model = \"compression\"",
                        IntegratorKind::list(&IntegratorKind::NONLINEAR)
                    );
                    return Err(bad(scene, &key("integrator"), &run.integrator, &allowed));
                }
                if run.integrator == IntegratorKind::MetropolisCrankNicolson
                    && run.noise != NoiseModel::Consistent
                {
                    let allowed = "consistent for metropolis-crank-nicolson";
                    return Err(bad(scene, &key("noise"), &run.noise.name(), allowed));
                }
            }
        }
        Ok(())
    }

    /// The largest `dt_tau1` and how the allowed range reads in messages.
    fn dt_limit(&self) -> (f64, String) {
        match self {
            RunRules::Linear(_) => (100.0, "in (0, 100]".to_string()),
            RunRules::Compression(c) => (
                c.sample_every_tau1,
                format!(
                    "in (0, compression.sample_every_tau1 = {}]",
                    Num(c.sample_every_tau1)
                ),
            ),
        }
    }

    /// The allowed trajectory count, for messages.
    fn trajectories_allowed(&self) -> &'static str {
        match self {
            RunRules::Linear(_) => "in [2, 100000]",
            RunRules::Compression(_) => "in [2, 100000] (per strain)",
        }
    }

    /// `None` if `duration_tau1` is valid for run `i` at `dt_tau1`, else the allowed
    /// range. The steps per trajectory are bounded by `validate_run` (through `dt_tau1`).
    fn duration_error(&self, i: usize, duration_tau1: f64, dt_tau1: f64) -> Option<String> {
        match self {
            RunRules::Linear(_) => {
                let shortest = MIN_LINEAR_DURATION_TAU1.max(MIN_LINEAR_STEPS * dt_tau1);
                let ok =
                    duration_tau1.is_finite() && duration_tau1 >= shortest && duration_tau1 <= 1e6;
                (!ok).then(|| {
                    format!(
                        "in [{MIN_LINEAR_DURATION_TAU1}, 1e6] and >= {MIN_LINEAR_STEPS} x runs[{i}].dt_tau1 = {} (at least 32 samples of mode 1, sampled about every 0.5 tau1, and {MIN_LINEAR_STEPS} steps per trajectory)",
                        Num(MIN_LINEAR_STEPS * dt_tau1)
                    )
                })
            }
            RunRules::Compression(c) => {
                let samples = duration_tau1 / c.sample_every_tau1;
                let ok = duration_tau1.is_finite() && samples >= 16.0 && duration_tau1 <= 1e6;
                (!ok).then(|| {
                    format!(
                        "<= 1e6 and >= 16 x sample_every_tau1 = {}",
                        Num(16.0 * c.sample_every_tau1)
                    )
                })
            }
        }
    }

    /// `None` if `n` extra two-time trajectories are valid, else the allowed range: only
    /// linear scenes have the two-time check.
    fn two_time_error(&self, n: usize) -> Option<&'static str> {
        match self {
            RunRules::Linear(_) => (n > MAX_TRAJECTORIES).then_some("in [0, 100000]"),
            RunRules::Compression(_) => {
                (n != 0).then_some("0 for model = \"compression\" (two-time is a linear check)")
            }
        }
    }
}

impl Scene {
    /// Validates the scene (see the [module docs](self) for the order of the checks).
    /// [`Scene::load`] and [`Scene::parse`] call it.
    ///
    /// # Errors
    /// [`Error::Scene`] naming the file, the key, the value and the allowed range.
    pub fn validate(&self) -> Result<()> {
        check_path_name(self, "name (the scene file stem)", &self.name)?;
        self.validate_common()?;
        self.validate_check_family("checks", &self.checks)?;
        let rules = match (self.model, &self.compression) {
            (ModelKind::Compression, Some(c)) => {
                self.validate_compression_table(c)?;
                RunRules::Compression(c)
            }
            (ModelKind::Compression, None) => {
                let allowed = "a [compression] table for model = \"compression\"";
                return Err(bad(self, "compression", &"nothing", allowed));
            }
            (ModelKind::Fem | ModelKind::Spectral, Some(_)) => {
                let allowed = "absent unless model = \"compression\"";
                return Err(bad(self, "compression", &"a [compression] table", allowed));
            }
            (ModelKind::Fem | ModelKind::Spectral, None) => {
                self.validate_sampling()?;
                RunRules::Linear(&self.sampling)
            }
        };
        if self.runs.is_empty() {
            return Err(bad(self, "runs", &"[]", "at least one [[runs]] table"));
        }
        for (i, run) in self.runs.iter().enumerate() {
            self.validate_run(i, run, &rules)?;
        }
        match &self.compression {
            Some(c) => self.validate_halving(c),
            None => Ok(()),
        }
    }

    /// The checks of every scene: filament (or membrane), `dims`, `checks` non-empty,
    /// mesh, burn-in.
    fn validate_common(&self) -> Result<()> {
        match &self.membrane {
            Some(m) => self.validate_membrane(m)?,
            None => {
                self.validate_filament()?;
                if self.dims != 2 && self.dims != 3 {
                    return Err(bad(self, "dims", &self.dims, "2 or 3"));
                }
                if !self.ends.is_hinged() && self.model != ModelKind::Fem {
                    let allowed = "hinged-hinged with model = \"spectral\" or \"compression\" (their modes and their theory are the hinged filament's); other ends with model = \"fem\"";
                    return Err(bad(self, "filament.ends", &self.ends, allowed));
                }
            }
        }
        if self.checks.is_empty() {
            return Err(bad(self, "checks", &"[]", "a non-empty list"));
        }
        match &self.membrane {
            Some(m) => self.validate_membrane_mesh(m)?,
            None => self.validate_filament_mesh()?,
        }
        let b = self.sampling.burn_in_tau1;
        if !(b.is_finite() && (0.0..=1e4).contains(&b)) {
            return Err(bad(self, "sampling.burn_in_tau1", &Num(b), "in [0, 1e4]"));
        }
        Ok(())
    }

    /// The mesh of a filament: `elements` in [1, [`MAX_ELEMENTS`]], no `elements_y`,
    /// `grading` in [0.01, 100].
    fn validate_filament_mesh(&self) -> Result<()> {
        if !(1..=MAX_ELEMENTS).contains(&self.mesh.elements) {
            return Err(bad(
                self,
                "mesh.elements",
                &self.mesh.elements,
                &format!("in [1, {MAX_ELEMENTS}]"),
            ));
        }
        if let Some(ny) = self.mesh.elements_y {
            let allowed = "left out of a filament scene (elements_y is the element count along y of a [membrane] scene)";
            return Err(bad(self, "mesh.elements_y", &ny, allowed));
        }
        let g = self.mesh.grading;
        if !(g.is_finite() && (0.01..=100.0).contains(&g)) {
            return Err(bad(self, "mesh.grading", &Num(g), "in [0.01, 100]"));
        }
        Ok(())
    }

    /// A membrane scene's object and parameters: no `[filament]` table beside it, model
    /// `fem` or `spectral`, `dims = 3`; κ, ξ, kT, a, b in [1e-30, 1e30] and σ finite with
    /// |σ| ≤ 1e30 (bounds that keep τ1, the rates and the variances inside f64), then
    /// [`MembraneParams::validate`] (the aspect ratio, σ above the buckling tension), its
    /// error named as the key `membrane.<field>`.
    fn validate_membrane(&self, m: &MembraneParams) -> Result<()> {
        if self.filament_table {
            let allowed = "left out of a membrane scene (a scene describes one object, and this one has a [membrane] table)";
            return Err(bad(self, "filament", &"a [filament] table", allowed));
        }
        if self.dims != 3 {
            let allowed = "3 for a membrane scene (a surface in 3D space with one height component h(x, y) normal to its x-y rectangle; dims = 2 would hold a curve, the filament)";
            return Err(bad(self, "dims", &self.dims, allowed));
        }
        for (key, v) in [
            ("bending_rigidity", m.bending_rigidity),
            ("drag", m.drag),
            ("kt", m.kt),
            ("width", m.width),
            ("height", m.height),
        ] {
            if !(v.is_finite() && (1e-30..=1e30).contains(&v)) {
                let key = format!("membrane.{key}");
                return Err(bad(self, &key, &Num(v), "in [1e-30, 1e30]"));
            }
        }
        let t = m.tension;
        if !(t.is_finite() && t.abs() <= 1e30) {
            let allowed = format!(
                "finite, in [-1e30, 1e30] and > the buckling tension -kappa q_min^2 = {}",
                Num(m.buckling_tension())
            );
            return Err(bad(self, "membrane.tension", &Num(t), &allowed));
        }
        m.validate().map_err(|e| match e {
            Error::InvalidParameter { name, allowed, .. } => {
                let value = match name.as_str() {
                    "bending_rigidity" => m.bending_rigidity,
                    "drag" => m.drag,
                    "kt" => m.kt,
                    "width" => m.width,
                    "height" => m.height,
                    _ => m.tension,
                };
                bad(self, &format!("membrane.{name}"), &Num(value), &allowed)
            }
            other => other,
        })?;
        let tau1 = self.tau1();
        if !(tau1.is_finite() && tau1 > 0.0) {
            // Not reached within the bounds above (tau1 stays below about 1e194): a guard
            // of the arithmetic.
            let allowed = format!(
                "a tension that gives the slowest mode a finite relaxation time (got tau1 = {}; the buckling tension is {})",
                Num(tau1),
                Num(m.buckling_tension())
            );
            return Err(bad(self, "membrane.tension", &Num(t), &allowed));
        }
        Ok(())
    }

    /// The mesh of a membrane: [`membrane_mesh_violation`] of `mesh.elements` and
    /// `mesh.elements_y`, and a uniform mesh (`grading = 1`).
    fn validate_membrane_mesh(&self, m: &MembraneParams) -> Result<()> {
        let (nx, ny) = (self.mesh.elements, self.mesh.elements_y);
        if let Some((key, value, allowed)) = membrane_mesh_violation(m.boundary, nx, ny, "mesh") {
            return Err(bad(self, &key, &value, &allowed));
        }
        let g = self.mesh.grading;
        if g != 1.0 {
            let allowed = "1 for a membrane scene (membrane meshes are uniform)";
            return Err(bad(self, "mesh.grading", &Num(g), allowed));
        }
        Ok(())
    }

    /// The filament: every parameter in [1e-30, 1e30] (bounds that keep every derived
    /// quantity, τ1, λ_max, variances, inside f64). For a filament given in physical units
    /// the bounds apply after conversion (in µm, s, pN) and the message names the keys the
    /// user wrote, with their values; the slender-body drag needs L/d ≥
    /// [`physical::MIN_SLENDERNESS`].
    fn validate_filament(&self) -> Result<()> {
        let f = &self.filament;
        if let Some(p) = &self.physical {
            for (key, value, _) in p.given() {
                if !(value.is_finite() && value > 0.0) {
                    return Err(bad(
                        self,
                        &format!("filament.{key}"),
                        &Num(value),
                        "a finite number > 0",
                    ));
                }
            }
            if let physical::Drag::Solvent { diameter_nm, .. } = p.drag {
                let slenderness = p.contour_length_um / (diameter_nm * 1e-3);
                if slenderness < physical::MIN_SLENDERNESS {
                    return Err(bad(
                        self,
                        "filament.diameter_nm",
                        &Num(diameter_nm),
                        &format!(
                            "at most contour_length_um/{} = {} nm for the slender-body drag (L/d >= {}; got L/d = {})",
                            physical::MIN_SLENDERNESS,
                            Num(p.contour_length_um * 1e3 / physical::MIN_SLENDERNESS),
                            physical::MIN_SLENDERNESS,
                            Num(slenderness)
                        ),
                    ));
                }
            }
        }
        for (key, v) in [
            ("length", f.length),
            ("bending_rigidity", f.bending_rigidity),
            ("stretch_rigidity", f.stretch_rigidity),
            ("drag", f.drag),
            ("kt", f.kt),
        ] {
            if v.is_finite() && (1e-30..=1e30).contains(&v) {
                continue;
            }
            return Err(match &self.physical {
                None => bad(
                    self,
                    &format!("filament.{key}"),
                    &Num(v),
                    "in [1e-30, 1e30]",
                ),
                Some(p) => {
                    let keys = p.keys_of(key);
                    let given: Vec<String> = p
                        .given()
                        .iter()
                        .filter(|(k, _, _)| keys.contains(k))
                        .map(|(k, v, unit)| format!("{k} = {} {unit}", Num(*v)))
                        .collect();
                    let unit = physical::parameter_record(f, Some(p))
                        .parameters
                        .get(key)
                        .map_or_else(String::new, |q| q.unit.clone());
                    Error::Scene {
                        file: self.path.clone(),
                        key: format!("filament.{}", keys.first().copied().unwrap_or(key)),
                        message: format!(
                            "gives {key} = {} {unit} after conversion (from {}), which must be in [1e-30, 1e30] {unit}",
                            Num(v),
                            if given.is_empty() {
                                "defaults".to_string()
                            } else {
                                given.join(", ")
                            }
                        ),
                    }
                }
            });
        }
        Ok(())
    }

    /// Whether this is a membrane scene on a square patch with a square mesh (where the
    /// x ↔ y symmetry check applies).
    fn is_square_membrane(&self) -> bool {
        self.membrane.is_some_and(|m| {
            m.width == m.height && self.mesh.elements_along_y() == self.mesh.elements
        })
    }

    /// Every check in `kinds` (the scene's list under `key = "checks"`, or a run's) is of
    /// the scene's model: linear checks for `fem`/`spectral`, compression checks for
    /// `compression`.
    fn validate_check_family(&self, key: &str, kinds: &[CheckKind]) -> Result<()> {
        let compression = self.model == ModelKind::Compression;
        let allowed = if compression {
            COMPRESSION_CHECKS
        } else {
            LINEAR_CHECKS
        };
        let rigid = self.membrane.is_none() && self.ends.rigid_modes() > 0;
        // The cosines diagonalize the bending energy of θ only where every end leaves θ
        // free (no clamp); the angle needs the finite-element slope.
        let tangent = self.membrane.is_none()
            && self.model == ModelKind::Fem
            && ![self.ends.left, self.ends.right].contains(&End::Clamped);
        let misplaced = |k: &CheckKind| {
            k.is_compression() != compression
                || (*k == CheckKind::XySymmetry && !self.is_square_membrane())
                || (*k == CheckKind::RigidDiffusion && !rigid)
                || (*k == CheckKind::TangentAngle && !tangent)
        };
        let allowed = if kinds.contains(&CheckKind::TangentAngle) && !tangent {
            "tangent-angle only for a finite-element filament (model = \"fem\") with no clamped end (the cosines of Gittes et al. diagonalize the bending energy only where theta is free at both ends); otherwise a linear check (profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time, pooled-variance)"
        } else if kinds.contains(&CheckKind::RigidDiffusion) && !rigid {
            "rigid-diffusion only for a filament with rigid modes (filament.ends free-free, hinged-free or free-hinged); otherwise a linear check (profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time, pooled-variance)"
        } else if kinds.contains(&CheckKind::XySymmetry) && !self.is_square_membrane() {
            "xy-symmetry only for a membrane on a square patch (width = height, elements_y = elements); otherwise a linear check (profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time, pooled-variance)"
        } else {
            allowed
        };
        match kinds.iter().position(misplaced) {
            Some(i) => Err(bad(self, &format!("{key}[{i}]"), &kinds[i].name(), allowed)),
            None => Ok(()),
        }
    }

    /// The `[sampling]` table of a linear scene: modes, profile points, two-time points,
    /// and the points the requested checks need.
    fn validate_sampling(&self) -> Result<()> {
        let s = &self.sampling;
        let (max_modes, why) = self.mode_count();
        let most = max_modes.min(MAX_CHECKED_MODES);
        if s.modes < 1 || s.modes > most {
            let allowed = match why {
                None => format!("in [1, {most}]"),
                Some(why) => format!("in [1, {most}] ({why})"),
            };
            return Err(bad(self, "sampling.modes", &s.modes, &allowed));
        }
        for (key, n) in [
            ("sampling.profile_points", s.profile_points.len()),
            ("sampling.two_time", s.two_time.len()),
        ] {
            if n > MAX_POINTS {
                let allowed = format!("a list of at most {MAX_POINTS} points");
                return Err(bad(self, key, &format!("{n} points"), &allowed));
            }
        }
        let (inside, allowed) = self.positions();
        for (i, &x) in s.profile_points.iter().enumerate() {
            if !inside(x) {
                let key = format!("sampling.profile_points[{i}]");
                return Err(bad(self, &key, &Num(x), allowed));
            }
        }
        for (i, p) in s.two_time.iter().enumerate() {
            self.validate_two_time_point(i, p)?;
        }
        let all_checks = || {
            self.checks
                .iter()
                .chain(self.runs.iter().flat_map(|r| r.checks.iter().flatten()))
        };
        if all_checks().any(|c| *c == CheckKind::Profile) && s.profile_points.is_empty() {
            let allowed = "non-empty when checks has \"profile\"";
            return Err(bad(self, "sampling.profile_points", &"[]", allowed));
        }
        if all_checks().any(|c| *c == CheckKind::TwoTime) && s.two_time.is_empty() {
            let allowed = "non-empty when checks has \"two-time\"";
            return Err(bad(self, "sampling.two_time", &"[]", allowed));
        }
        Ok(())
    }

    /// Two-time point `i`, `(x/L, y/L, t/τ1, η/τ1)` (membrane: `(x/a, x'/a, t/τ1,
    /// η/τ1)`): positions as [`Self::positions`] allows them, 0 < t ≤ η ≤ burn-in.
    fn validate_two_time_point(&self, i: usize, p: &[f64; 4]) -> Result<()> {
        let (inside, allowed) = self.positions();
        let names = if self.is_membrane() {
            ["x/a", "x'/a"]
        } else {
            ["x/L", "y/L"]
        };
        for (j, name) in names.iter().enumerate() {
            if !inside(p[j]) {
                let key = format!("sampling.two_time[{i}][{j}] ({name})");
                return Err(bad(self, &key, &Num(p[j]), allowed));
            }
        }
        if !(p[3].is_finite() && p[3] > 0.0) {
            let key = format!("sampling.two_time[{i}][3] (eta/tau1)");
            return Err(bad(self, &key, &Num(p[3]), "finite and > 0"));
        }
        if !(p[2].is_finite() && p[2] > 0.0 && p[2] <= p[3]) {
            let key = format!("sampling.two_time[{i}][2] (t/tau1)");
            return Err(bad(
                self,
                &key,
                &Num(p[2]),
                &format!("in (0, eta/tau1 = {}]", Num(p[3])),
            ));
        }
        let burn_in = self.sampling.burn_in_tau1;
        if p[3].is_nan() || p[3] > burn_in {
            let key = format!("sampling.two_time[{i}][3] (eta/tau1)");
            let allowed = format!("<= sampling.burn_in_tau1 = {}", Num(burn_in));
            return Err(bad(self, &key, &Num(p[3]), &allowed));
        }
        Ok(())
    }

    /// The modes the scene's discretization has, the most `sampling.modes` may check
    /// below [`MAX_CHECKED_MODES`], and for a membrane why: a filament's finite elements
    /// have `2·elements` (w and its slope at every node), its spectral model `elements`
    /// modes; a membrane mesh of nx × ny elements (or mode indices kept) has nx·ny of its
    /// lowest modes, less the uniform displacement (not a mode) if periodic.
    fn mode_count(&self) -> (usize, Option<String>) {
        let Some(m) = &self.membrane else {
            let n = match self.model {
                ModelKind::Fem => 2 * self.mesh.elements,
                ModelKind::Spectral | ModelKind::Compression => self.mesh.elements,
            };
            return (n, None);
        };
        let (nx, ny) = (self.mesh.elements, self.mesh.elements_along_y());
        let n = nx * ny;
        match m.boundary {
            MembraneBoundary::SimplySupported => (
                n,
                Some(format!(
                    "at most {MAX_CHECKED_MODES}, and at most mesh.elements x mesh.elements_y = {nx} x {ny} = {n}, the modes a membrane mesh resolves"
                )),
            ),
            MembraneBoundary::Periodic => (
                n - 1,
                Some(format!(
                    "at most {MAX_CHECKED_MODES}, and at most mesh.elements x mesh.elements_y - 1 = {nx} x {ny} - 1 = {}, the modes a periodic membrane mesh resolves (its {n} heights less the uniform displacement, which is not a mode)",
                    n - 1
                )),
            ),
        }
    }

    /// The allowed positions of the profile and two-time checks (fractions x/L of the
    /// filament, x/a on the midline y = b/2 of a membrane), as a test and the message:
    /// inside (0, 1) where the ends or edges hold w = 0 (hinges, simply supported edges),
    /// [0, 1) on a periodic membrane (x/a = 1 is x/a = 0).
    fn positions(&self) -> (fn(f64) -> bool, &'static str) {
        fn interior(x: f64) -> bool {
            x.is_finite() && x > 0.0 && x < 1.0
        }
        fn period(x: f64) -> bool {
            x.is_finite() && (0.0..1.0).contains(&x)
        }
        fn from_left(x: f64) -> bool {
            x.is_finite() && (0.0..1.0).contains(&x)
        }
        fn to_right(x: f64) -> bool {
            x.is_finite() && x > 0.0 && x <= 1.0
        }
        fn closed(x: f64) -> bool {
            x.is_finite() && (0.0..=1.0).contains(&x)
        }
        let free = |e: crate::params::End| e == crate::params::End::Free;
        match self.membrane.map(|m| m.boundary) {
            None => match (free(self.ends.left), free(self.ends.right)) {
                (false, false) if self.ends.is_hinged() => (interior, INTERIOR),
                (false, false) => (interior, FIXED_ENDS),
                (true, false) => (from_left, FREE_LEFT),
                (false, true) => (to_right, FREE_RIGHT),
                (true, true) => (closed, FREE_BOTH),
            },
            Some(MembraneBoundary::SimplySupported) => (interior, MEMBRANE_INTERIOR),
            Some(MembraneBoundary::Periodic) => (period, MEMBRANE_PERIOD),
        }
    }

    /// `compression.area_modulus`: required in [1e-30, 1e30] for a membrane (under
    /// imposed projected area, whose `membrane.tension` must then be 0: the tension is
    /// `K_A(ΔA/A₀ − ε)`), refused for a filament; a membrane's compression scene takes
    /// `metropolis-crank-nicolson` and the θ-schemes with consistent noise (its runs are
    /// modal: [`crate::dynamics::ModalMetropolis`]).
    fn validate_area_modulus(&self, c: &CompressionSpec) -> Result<()> {
        let Some(m) = &self.membrane else {
            return match c.area_modulus {
                None => Ok(()),
                Some(v) => Err(bad(
                    self,
                    "compression.area_modulus",
                    &Num(v),
                    "left out of a filament scene (the area modulus of a [membrane] under imposed projected area; a filament's stretch modulus is filament.stretch_rigidity)",
                )),
            };
        };
        let Some(k) = c.area_modulus else {
            let allowed =
                "the area modulus K_A in [1e-30, 1e30] for a membrane under imposed projected area";
            return Err(bad(self, "compression.area_modulus", &"nothing", allowed));
        };
        if !(k.is_finite() && (1e-30..=1e30).contains(&k)) {
            return Err(bad(
                self,
                "compression.area_modulus",
                &Num(k),
                "in [1e-30, 1e30]",
            ));
        }
        if m.tension != 0.0 {
            let allowed = "0 for a membrane under imposed projected area (model = \"compression\": its tension is K_A (dA/A0 - eps), set by the imposed area strain)";
            return Err(bad(self, "membrane.tension", &Num(m.tension), allowed));
        }
        for (i, run) in self.runs.iter().enumerate() {
            let ok = matches!(
                run.integrator.family(),
                Family::Metropolis | Family::Theta(_)
            ) && run.noise == NoiseModel::Consistent;
            if !ok {
                let allowed = "metropolis-crank-nicolson, euler-maruyama, backward-euler or crank-nicolson with noise = \"consistent\" for a membrane under imposed projected area (its runs are modal)";
                let value = format!("{} with noise {}", run.integrator, run.noise);
                return Err(bad(self, &format!("runs[{i}].integrator"), &value, allowed));
            }
        }
        Ok(())
    }

    /// The `[compression]` table of a compression scene: strains, uniform mesh, burn-in
    /// and sampling interval.
    fn validate_compression_table(&self, c: &CompressionSpec) -> Result<()> {
        self.validate_area_modulus(c)?;
        if c.strain_ratios.is_empty() {
            return Err(bad(
                self,
                "compression.strain_ratios",
                &"[]",
                "a non-empty list",
            ));
        }
        if self.mesh.grading != 1.0 {
            // The exact discrete theory uses the closed-form spectrum of a uniform mesh.
            let allowed = "1 (uniform) for model = \"compression\"";
            return Err(bad(self, "mesh.grading", &self.mesh.grading, allowed));
        }
        let n = c.strain_ratios.len();
        if n > MAX_POINTS {
            let allowed = format!("a list of at most {MAX_POINTS} strains");
            let value = format!("{n} strains");
            return Err(bad(self, "compression.strain_ratios", &value, &allowed));
        }
        for (i, &r) in c.strain_ratios.iter().enumerate() {
            if !(r.is_finite() && (-1e3..=1e3).contains(&r)) {
                let key = format!("compression.strain_ratios[{i}]");
                return Err(bad(self, &key, &Num(r), "finite, in [-1000, 1000]"));
            }
        }
        for (i, &r) in c.distribution_strain_ratios.iter().enumerate() {
            if !c.strain_ratios.contains(&r) {
                let key = format!("compression.distribution_strain_ratios[{i}]");
                return Err(bad(self, &key, &Num(r), "one of compression.strain_ratios"));
            }
        }
        self.validate_theory_domain(&c.strain_ratios, c.area_modulus)?;
        let b = c.burn_in_tau1;
        if !(b.is_finite() && (0.0..=1e4).contains(&b)) {
            return Err(bad(
                self,
                "compression.burn_in_tau1",
                &Num(b),
                "in [0, 1e4]",
            ));
        }
        let s = c.sample_every_tau1;
        if !(s.is_finite() && s > 0.0 && s <= 100.0) {
            return Err(bad(
                self,
                "compression.sample_every_tau1",
                &Num(s),
                "in (0, 100]",
            ));
        }
        Ok(())
    }

    /// A compression scene lies in the exact theory's domain: a filament's
    /// ([`crate::theory::domain_violation`]) or a membrane's under imposed projected area
    /// of modulus `area_modulus` ([`AreaParams::domain_violation`]). Outside, the key of
    /// the input (EI or κ, EA or K_A, a strain ratio) with its allowed range.
    fn validate_theory_domain(
        &self,
        strain_ratios: &[f64],
        area_modulus: Option<f64>,
    ) -> Result<()> {
        let f = &self.filament;
        let area = self.membrane.zip(area_modulus);
        let found = match area {
            Some((m, k_a)) => AreaParams::from_membrane(&m, k_a).domain_violation(strain_ratios),
            None => crate::theory::domain_violation(
                f.persistence_ratio(),
                f.stretch_ratio(),
                strain_ratios,
            ),
        };
        let Some((input, allowed)) = found else {
            return Ok(());
        };
        let filament_key = |key: &'static str| {
            let key = match &self.physical {
                Some(ph) => ph.keys_of(key).first().copied().unwrap_or(key),
                None => key,
            };
            format!("filament.{key}")
        };
        let (key, value) = match (input, area) {
            (DomainInput::StrainRatio(i), _) => {
                (format!("compression.strain_ratios[{i}]"), strain_ratios[i])
            }
            (DomainInput::BendingRigidity, Some((m, _))) => {
                ("membrane.bending_rigidity".to_string(), m.bending_rigidity)
            }
            (DomainInput::StretchRigidity, Some((_, k_a))) => {
                ("compression.area_modulus".to_string(), k_a)
            }
            (DomainInput::BendingRigidity, None) => {
                (filament_key("bending_rigidity"), f.bending_rigidity)
            }
            (DomainInput::StretchRigidity, None) => {
                (filament_key("stretch_rigidity"), f.stretch_rigidity)
            }
        };
        Err(bad(self, &key, &Num(value), &allowed))
    }

    /// The one per-run check of every scene: name, integrator and noise, own checks,
    /// time step and the ensemble of every budget, with the model's limits `rules`.
    fn validate_run(&self, i: usize, run: &RunSpec, rules: &RunRules) -> Result<()> {
        let key = |k: &str| format!("runs[{i}].{k}");
        check_path_name(self, &key("name"), &run.name)?;
        if self.runs[..i].iter().any(|r| r.name == run.name) {
            return Err(bad(
                self,
                &key("name"),
                &run.name,
                "unique within the scene",
            ));
        }
        rules.check_integrator(self, i, run)?;
        if let Some(checks) = &run.checks {
            if checks.is_empty() {
                let allowed = "a non-empty list (or leave it out)";
                return Err(bad(self, &key("checks"), &"[]", allowed));
            }
            self.validate_check_family(&key("checks"), checks)?;
            if let Some(j) = checks.iter().position(|k| *k == CheckKind::DtHalving) {
                // The Δt-halving check compares two runs: it is a check of the scene.
                let allowed = "force-strain or force-distribution in a run's checks (dt-halving compares two runs: list it in the scene's checks)";
                let k = key(&format!("checks[{j}]"));
                return Err(bad(self, &k, &"DtHalving", allowed));
            }
        }
        let (dt_max, dt_allowed) = rules.dt_limit();
        let dt = run.dt_tau1;
        if !(dt.is_finite() && dt > 0.0 && dt <= dt_max) {
            return Err(bad(self, &key("dt_tau1"), &Num(dt), &dt_allowed));
        }
        // Steps per trajectory, at the longest duration any budget may run (durations
        // above 1e6 are refused below, naming their key).
        let longest = [Budget::Quick, Budget::Standard, Budget::Full]
            .iter()
            .map(|&b| {
                let e = run.ensemble(b);
                [e.duration_tau1, e.max_duration_tau1.unwrap_or(0.0)]
                    .into_iter()
                    .filter(|d| d.is_finite())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
            .min(1e6);
        let burn_in = match rules {
            RunRules::Linear(s) => s.burn_in_tau1,
            RunRules::Compression(c) => c.burn_in_tau1,
        };
        let shortest_dt = (burn_in + longest) / MAX_STEPS_PER_TRAJECTORY;
        if dt < shortest_dt {
            let allowed = format!(
                ">= (burn_in_tau1 + longest duration_tau1 = {})/1e10 = {}, at most 1e10 steps per trajectory",
                Num(burn_in + longest),
                Num(shortest_dt)
            );
            return Err(bad(self, &key("dt_tau1"), &Num(dt), &allowed));
        }
        for budget in [Budget::Quick, Budget::Standard, Budget::Full] {
            let e = run.ensemble(budget);
            let b = budget.name();
            if !(2..=MAX_TRAJECTORIES).contains(&e.trajectories) {
                let allowed = rules.trajectories_allowed();
                let k = key(&format!("{b}.trajectories"));
                return Err(bad(self, &k, &e.trajectories, allowed));
            }
            self.validate_duration(i, b, &e, dt, rules)?;
            if let Some(allowed) = rules.two_time_error(e.two_time_trajectories) {
                let k = key(&format!("{b}.two_time_trajectories"));
                return Err(bad(self, &k, &e.two_time_trajectories, allowed));
            }
        }
        Ok(())
    }

    /// The duration keys of the ensemble `e` of run `i` at budget `b`: a fixed
    /// `duration_tau1`, or (compression scenes) a budget by target precision
    /// (`target_std_error`, `pilot_tau1`, `max_duration_tau1`, all three).
    fn validate_duration(
        &self,
        i: usize,
        b: &str,
        e: &super::spec::Ensemble,
        dt: f64,
        rules: &RunRules,
    ) -> Result<()> {
        let key = |k: &str| format!("runs[{i}].{b}.{k}");
        let Some(target) = e.target_std_error else {
            for (k, v) in [
                ("pilot_tau1", e.pilot_tau1),
                ("max_duration_tau1", e.max_duration_tau1),
                ("max_dt_tau1", e.max_dt_tau1),
                ("min_acceptance", e.min_acceptance),
            ] {
                if let Some(v) = v {
                    let allowed = "left out unless target_std_error is given";
                    return Err(bad(self, &key(k), &Num(v), allowed));
                }
            }
            if !e.duration_given() {
                let allowed = "given (sampled duration per trajectory in tau1), or replaced by target_std_error, pilot_tau1 and max_duration_tau1 (compression scenes)";
                return Err(bad(self, &key("duration_tau1"), &"nothing", allowed));
            }
            if let Some(allowed) = rules.duration_error(i, e.duration_tau1, dt) {
                let value = Num(e.duration_tau1);
                return Err(bad(self, &key("duration_tau1"), &value, &allowed));
            }
            return Ok(());
        };
        if let RunRules::Linear(_) = rules {
            let allowed = "left out for model \"fem\" or \"spectral\" (budgets by target precision are for model = \"compression\"); give duration_tau1";
            return Err(bad(self, &key("target_std_error"), &Num(target), allowed));
        }
        if !(target.is_finite() && target > 0.0 && target <= 1.0) {
            let allowed = "in (0, 1] (standard error of <F> in units of the Euler load F_c0)";
            return Err(bad(self, &key("target_std_error"), &Num(target), allowed));
        }
        if e.duration_given() {
            let allowed = "left out when target_std_error is given (the duration is chosen per strain, at most max_duration_tau1)";
            return Err(bad(
                self,
                &key("duration_tau1"),
                &Num(e.duration_tau1),
                allowed,
            ));
        }
        let mut given = [0.0; 2];
        for (slot, (k, v)) in given.iter_mut().zip([
            ("pilot_tau1", e.pilot_tau1),
            ("max_duration_tau1", e.max_duration_tau1),
        ]) {
            let Some(v) = v else {
                let allowed =
                    "given with target_std_error (a sampled duration per trajectory in tau1)";
                return Err(bad(self, &key(k), &"nothing", allowed));
            };
            if let Some(allowed) = rules.duration_error(i, v, dt) {
                return Err(bad(self, &key(k), &Num(v), &allowed));
            }
            *slot = v;
        }
        let [pilot, max] = given;
        if pilot > max {
            let allowed = format!("<= max_duration_tau1 = {}", Num(max));
            return Err(bad(self, &key("pilot_tau1"), &Num(pilot), &allowed));
        }
        self.validate_step_search(i, b, e)
    }

    /// The step search of a budget by target precision (`max_dt_tau1` and
    /// `min_acceptance`, both or neither): Metropolis runs only (exact at any Δt), steps
    /// from `dt_tau1` to 100 τ1; the second run of the Δt-halving pair inherits the first
    /// run's steps (halved), so it has no search of its own and comes after the first.
    fn validate_step_search(&self, i: usize, b: &str, e: &super::spec::Ensemble) -> Result<()> {
        let key = |k: &str| format!("runs[{i}].{b}.{k}");
        let run = &self.runs[i];
        let (max_dt, min_acc) = match (e.max_dt_tau1, e.min_acceptance) {
            (None, None) => return Ok(()),
            (Some(m), Some(a)) => (m, a),
            (Some(_), None) => {
                let allowed = "given with max_dt_tau1 (the acceptance rate the step search asks of a step, in (0, 1))";
                return Err(bad(self, &key("min_acceptance"), &"nothing", allowed));
            }
            (None, Some(_)) => {
                let allowed =
                    "given with min_acceptance (the largest step of the step search, in tau1)";
                return Err(bad(self, &key("max_dt_tau1"), &"nothing", allowed));
            }
        };
        if run.integrator.family() != Family::Metropolis {
            let allowed = format!(
                "left out for integrator \"{}\" (a step search only for metropolis-crank-nicolson, whose stationary law is exact at any dt)",
                run.integrator
            );
            return Err(bad(self, &key("max_dt_tau1"), &Num(max_dt), &allowed));
        }
        if !(max_dt.is_finite() && max_dt >= run.dt_tau1 && max_dt <= 100.0) {
            let allowed = format!("in [dt_tau1 = {}, 100] (tau1)", Num(run.dt_tau1));
            return Err(bad(self, &key("max_dt_tau1"), &Num(max_dt), &allowed));
        }
        if !(min_acc > 0.0 && min_acc < 1.0) {
            return Err(bad(
                self,
                &key("min_acceptance"),
                &Num(min_acc),
                "in (0, 1)",
            ));
        }
        // A pair naming one run twice is refused by `validate_halving`, naming the pair.
        if let Some([first, second]) = self.compression.as_ref().and_then(|c| c.halving.as_ref())
            && first != second
        {
            if &run.name == second {
                let allowed = format!(
                    "left out for the second run of compression.halving (it runs at half the steps that run \"{first}\" chose)"
                );
                return Err(bad(self, &key("max_dt_tau1"), &Num(max_dt), &allowed));
            }
            let later = |name: &str| self.runs.iter().position(|r| r.name == name);
            if &run.name == first && later(second).is_some_and(|j| j < i) {
                let allowed = format!(
                    "left out, or run \"{second}\" listed after run \"{first}\" (the second run of compression.halving inherits the steps the first chose)"
                );
                return Err(bad(self, &key("max_dt_tau1"), &Num(max_dt), &allowed));
            }
        }
        Ok(())
    }

    /// The Δt-halving pair of a compression scene: two run names of the scene, required
    /// when the scene's checks have `dt-halving`.
    fn validate_halving(&self, c: &CompressionSpec) -> Result<()> {
        match &c.halving {
            Some(pair) => {
                for (j, n) in pair.iter().enumerate() {
                    if !self.runs.iter().any(|r| &r.name == n) {
                        let key = format!("compression.halving[{j}]");
                        return Err(bad(self, &key, n, "the name of a run of this scene"));
                    }
                }
                if pair[0] == pair[1] {
                    let allowed = format!(
                        "the name of another run than compression.halving[0] = \"{}\" (the check compares a run at dt with one at dt/2)",
                        pair[0]
                    );
                    return Err(bad(self, "compression.halving[1]", &pair[1], &allowed));
                }
                Ok(())
            }
            None if self.checks.contains(&CheckKind::DtHalving) => {
                let allowed = "two run names when checks has \"dt-halving\"";
                Err(bad(self, "compression.halving", &"nothing", allowed))
            }
            None => Ok(()),
        }
    }
}

/// Steps of a duration at a step (both in τ1), rounded as the runs round them; in `f64`,
/// so that no projection overflows.
fn steps_of(duration_tau1: f64, dt_tau1: f64) -> f64 {
    (duration_tau1 / dt_tau1).round()
}

/// The cost per DOF of a banded step of a plate of `nx` elements along x, relative to the
/// beam's (half-bandwidth 3), which a DOF-step counts: the plate's half-bandwidth is
/// `b₁(2nx + 1)`, `b₁` = 3 simply supported, 5 periodic (its 1D matrices' bandwidth times
/// the free DOFs along x, plus one: [`crate::fem::PlateModel`]).
fn plate_band_factor(boundary: MembraneBoundary, nx: f64) -> f64 {
    let b1 = match boundary {
        MembraneBoundary::SimplySupported => 3.0,
        MembraneBoundary::Periodic => 5.0,
    };
    b1 * (2.0 * nx + 1.0) / 3.0
}

impl Scene {
    /// The unknowns one step of `run` updates, over all components: `components × n`
    /// (n = 2·elements for the finite elements, the number of modes for the spectral
    /// model), `components × n²` for the dense exact modal update of the finite elements.
    /// A membrane of nx × ny elements: n = nx·ny modes (spectral), and for the plate
    /// elements 4·(nx + 1)·(ny + 1) (h, h_x, h_y and h_xy at every node, an upper bound
    /// of the free DOFs), each at the cost of its band on the banded nodal path (the
    /// element-uniform load): [`plate_band_factor`].
    pub fn step_cost(&self, run: &RunSpec) -> f64 {
        let components = self.components() as f64;
        let (nx, ny) = (
            self.mesh.elements as f64,
            self.mesh.elements_along_y() as f64,
        );
        let n = match (self.model, self.is_membrane()) {
            (ModelKind::Spectral, false) => nx,
            (ModelKind::Fem | ModelKind::Compression, false) => 2.0 * nx,
            (ModelKind::Spectral, true) => nx * ny,
            (ModelKind::Fem | ModelKind::Compression, true) => 4.0 * (nx + 1.0) * (ny + 1.0),
        };
        if self.dense_step(run) {
            return components * n * n;
        }
        let banded_plate = self.model == ModelKind::Fem && run.noise != NoiseModel::Consistent;
        match &self.membrane {
            Some(m) if banded_plate => components * n * plate_band_factor(m.boundary, nx),
            _ => components * n,
        }
    }

    /// The projected set-up of a finite-element run's exact discrete references, in
    /// DOF-steps: the dense modal law ([`crate::dynamics::DiscreteLaw`]: `Φᵀ Σ Φ` and the
    /// stationary covariance) costs O(n³) in the n unknowns of one component, and a beam's
    /// modes a dense symmetric eigen-decomposition besides. Measured on the reference
    /// machine: about 0.1·n³ DOF-steps for a beam (1000 elements: 17 s) and 0.02·n³ for a
    /// plate (40 × 40 elements: about 100 s a run); 0 for the spectral and compression
    /// models. Large meshes only: 0.1·20³ is 800 DOF-steps.
    pub fn setup_cost(&self) -> f64 {
        if self.model != ModelKind::Fem || self.compression.is_some() {
            return 0.0;
        }
        let (nx, ny) = (
            self.mesh.elements as f64,
            self.mesh.elements_along_y() as f64,
        );
        if self.is_membrane() {
            0.02 * (4.0 * (nx + 1.0) * (ny + 1.0)).powi(3)
        } else {
            0.1 * (2.0 * nx).powi(3)
        }
    }

    /// Whether a step of `run` costs a dense n × n product: the exact modal update of a
    /// finite-element object, except a plate with consistent noise (stepped in its
    /// separable modes, O(n)).
    fn dense_step(&self, run: &RunSpec) -> bool {
        self.model == ModelKind::Fem
            && run.integrator == IntegratorKind::ExactModal
            && !(self.is_membrane() && run.noise == NoiseModel::Consistent)
    }

    /// The projected work of run `i` with ensemble `e` (an upper bound, from the scene
    /// alone: see [`crate::work`]):
    ///
    /// - a linear run: `trajectories` × (burn-in, at least to the largest two-time η, +
    ///   `duration_tau1/dt_tau1`) plus `two_time_trajectories` × the largest η; samples
    ///   `trajectories × components × (modes + profile points)` series of at most
    ///   `min(sampled steps, MAX_SAMPLES)` samples, and the two-time products;
    /// - a compression run, at every strain: `trajectories` × (burn-in + sampled steps)
    ///   for a fixed budget; for a budget by target precision (`duration_tau1` left out)
    ///   the probes of the step search (every candidate), the pilot and the main stage at
    ///   its longest, `max_duration_tau1`; samples those of the main stage at every
    ///   strain. `sampling_dt_tau1` replaces the run's step while sampling: the second run
    ///   of the Δt-halving pair inherits half the steps the first chose (at least half the
    ///   first run's `dt_tau1`).
    ///
    /// # Panics
    /// Never: a run index out of range projects no work.
    pub fn run_work(&self, i: usize, e: &Ensemble, sampling_dt_tau1: Option<f64>) -> RunWork {
        let Some(run) = self.runs.get(i) else {
            return RunWork::default();
        };
        let components = self.components() as f64;
        let dt = run.dt_tau1;
        let traj = e.trajectories as f64;
        let (trajectory_steps, samples) = match &self.compression {
            None => {
                let s = &self.sampling;
                let burn = steps_of(s.burn_in_tau1, dt);
                let last_eta = s
                    .two_time
                    .iter()
                    .map(|p| steps_of(p[3], dt))
                    .fold(0.0, f64::max);
                let sampled = steps_of(e.duration_tau1, dt).max(1.0);
                let two_time = e.two_time_trajectories as f64;
                let series = (s.modes + s.profile_points.len()) as f64;
                let products = s.two_time.len() as f64;
                (
                    traj * (burn.max(last_eta) + sampled) + two_time * last_eta,
                    components
                        * (traj * (series * sampled.min(MAX_SAMPLES as f64) + products)
                            + two_time * products),
                )
            }
            Some(c) => {
                let points = c.strain_ratios.len() as f64;
                let burn = steps_of(c.burn_in_tau1, dt);
                // (sampled steps, samples) of a duration at step `h`, as `StepPlan` rounds.
                let sampled = |d: f64, h: f64| {
                    let every = steps_of(c.sample_every_tau1, h).max(1.0);
                    let n = (steps_of(d, h) / every).floor().max(1.0);
                    (n * every, n)
                };
                let h = sampling_dt_tau1.unwrap_or(dt);
                let per_trajectory = match e.precision_target() {
                    Some(t) if !e.duration_given() => {
                        let probes = t.step_search.map_or(0.0, |search| {
                            let doublings = (search.max_dt_tau1 / dt).log2().floor().max(0.0);
                            (0..=doublings.min(64.0) as i32)
                                .map(|k| {
                                    let hk = dt * 2f64.powi(k);
                                    let every = steps_of(c.sample_every_tau1, hk).max(1.0);
                                    burn + (PROBE_STEPS as f64 / every).ceil() * every
                                })
                                .sum()
                        });
                        let (pilot, _) = sampled(t.pilot_tau1, h);
                        let (main, n) = sampled(t.max_duration_tau1, h);
                        (probes + 2.0 * burn + pilot + main, n)
                    }
                    _ => {
                        let (steps, n) = sampled(e.duration_tau1, h);
                        (burn + steps, n)
                    }
                };
                (
                    points * traj * per_trajectory.0,
                    points * traj * per_trajectory.1,
                )
            }
        };
        RunWork {
            trajectory_steps,
            dof_steps: trajectory_steps * self.step_cost(run),
            samples,
        }
    }

    /// The sampling step of run `i` at `budget` if it is the second run of the
    /// Δt-halving pair and the first searches its steps: half the first run's `dt_tau1`
    /// at the least (see [`Self::run_work`]).
    fn inherited_dt(&self, i: usize, budget: Budget) -> Option<f64> {
        let [first, second] = self.compression.as_ref()?.halving.as_ref()?;
        if &self.runs.get(i)?.name != second {
            return None;
        }
        let first = self.runs.iter().find(|r| &r.name == first)?;
        first
            .ensemble(budget)
            .max_dt_tau1
            .map(|_| 0.5 * first.dt_tau1)
    }

    /// The keys (with their values) that drive the work of run `i` with ensemble `e` at
    /// `budget` (`inherited`: its sampling step from the Δt-halving pair), for
    /// [`Self::projected_work`]'s messages.
    fn work_drivers(
        &self,
        i: usize,
        budget: Budget,
        e: &Ensemble,
        inherited: Option<f64>,
    ) -> Vec<String> {
        let b = budget.name();
        let run = &self.runs[i];
        let k = |key: &str| format!("runs[{i}].{b}.{key}");
        let mut keys = Vec::new();
        if let Some(c) = &self.compression {
            keys.push(format!(
                "compression.strain_ratios ({} strains)",
                c.strain_ratios.len()
            ));
        }
        keys.push(format!("{} = {}", k("trajectories"), e.trajectories));
        match e.precision_target() {
            Some(t) if !e.duration_given() => {
                keys.push(format!("{} = {}", k("pilot_tau1"), Num(t.pilot_tau1)));
                keys.push(format!(
                    "{} = {}",
                    k("max_duration_tau1"),
                    Num(t.max_duration_tau1)
                ));
                if let Some(s) = t.step_search {
                    keys.push(format!("{} = {}", k("max_dt_tau1"), Num(s.max_dt_tau1)));
                }
            }
            _ => keys.push(format!("{} = {}", k("duration_tau1"), Num(e.duration_tau1))),
        }
        if e.two_time_trajectories > 0 && !self.sampling.two_time.is_empty() {
            keys.push(format!(
                "{} = {}",
                k("two_time_trajectories"),
                e.two_time_trajectories
            ));
        }
        keys.push(format!("runs[{i}].dt_tau1 = {}", Num(run.dt_tau1)));
        if let Some(h) = inherited {
            keys.push(format!(
                "sampling at dt_tau1 >= {} (half the steps of the first run of compression.halving)",
                Num(h)
            ));
        }
        match &self.compression {
            Some(c) => {
                keys.push(format!(
                    "compression.burn_in_tau1 = {}",
                    Num(c.burn_in_tau1)
                ));
                keys.push(format!(
                    "compression.sample_every_tau1 = {}",
                    Num(c.sample_every_tau1)
                ));
            }
            None => {
                let s = &self.sampling;
                keys.push(format!("sampling.burn_in_tau1 = {}", Num(s.burn_in_tau1)));
                keys.push(format!(
                    "sampling.modes = {} and {} profile points",
                    s.modes,
                    s.profile_points.len()
                ));
            }
        }
        let elements_y = if self.is_membrane() {
            format!(", mesh.elements_y = {}", self.mesh.elements_along_y())
        } else {
            String::new()
        };
        keys.push(format!(
            "mesh.elements = {}{elements_y}, dims = {}{}",
            self.mesh.elements,
            self.dims,
            if self.dense_step(run) {
                " (exact-modal: n^2 per step)"
            } else {
                ""
            }
        ));
        keys
    }

    /// The projected work of every run of the scene at `budget`, one [`Part`] per run
    /// (the runs run one after the other), each naming the keys that drive it.
    pub fn projected_work(&self, budget: Budget) -> Vec<Part> {
        let b = budget.name();
        self.runs
            .iter()
            .enumerate()
            .map(|(i, run)| {
                let e = run.ensemble(budget);
                let inherited = self.inherited_dt(i, budget);
                let mut keys = self.work_drivers(i, budget, &e, inherited);
                let mut work = self.run_work(i, &e, inherited);
                let setup = self.setup_cost();
                work.dof_steps += setup;
                // Named where it is a noticeable part (0.2 s nominal or more).
                if setup >= 1e7 {
                    keys.push(format!(
                        "and the set-up of its exact discrete references, O(n^3) in the unknowns: {} DOF-steps",
                        crate::work::count(setup)
                    ));
                }
                Part {
                    label: format!("{} runs[{i}] ({}) at budget {b}", self.name, run.name),
                    drivers: keys.join(", "),
                    origin: Origin::Scene {
                        file: self.path.clone(),
                        key: format!("runs[{i}].{b}"),
                    },
                    work,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The plate's band factor is its assembled half-bandwidth over the beam's 3, for both
    /// boundaries and a few meshes.
    #[test]
    fn plate_band_factor_is_the_assembled_bandwidth() {
        use crate::fem::PlateModel;
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            for (nx, ny) in [(2, 3), (8, 8), (13, 5)] {
                let params = MembraneParams {
                    boundary,
                    ..MembraneParams::default()
                };
                let plate = PlateModel::new(params, nx, ny).unwrap();
                let bw = plate.damping().bandwidth() as f64;
                assert_eq!(
                    plate_band_factor(boundary, nx as f64),
                    bw / 3.0,
                    "{boundary:?} {nx}x{ny}"
                );
            }
        }
    }

    const COMPRESSION: &str = r#"
description = "compression scene"
seed = 1
dims = 2
model = "compression"
checks = ["force-strain"]

[mesh]
elements = 4

[compression]
strain_ratios = [0.0, 1.0]
burn_in_tau1 = 1.0
sample_every_tau1 = 0.05

[[runs]]
name = "NAME"
integrator = "crank-nicolson"
dt_tau1 = 0.01
quick = { trajectories = 4, duration_tau1 = 10.0 }
standard = { trajectories = 4, duration_tau1 = 10.0 }
full = { trajectories = 4, duration_tau1 = 10.0 }
"#;

    fn message(text: &str, file: &str) -> String {
        match Scene::parse(text, Path::new(file)) {
            Ok(_) => String::new(),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn path_names() {
        for good in ["a", "run-1", "A_b-2"] {
            assert!(is_path_name(good), "{good}");
        }
        for bad in ["", ".", "..", "../x", "a/b", "a b", "a.b", "é"] {
            assert!(!is_path_name(bad), "{bad}");
        }
        assert!(is_path_name(&"x".repeat(MAX_NAME_LEN)));
        assert!(!is_path_name(&"x".repeat(MAX_NAME_LEN + 1)));
    }

    #[test]
    fn compression_scene_is_valid() {
        assert_eq!(message(&COMPRESSION.replace("NAME", "cn"), "ok.toml"), "");
    }

    #[test]
    fn compression_run_name_outside_out_is_refused() {
        let m = message(&COMPRESSION.replace("NAME", "../x"), "dir/comp.toml");
        assert!(m.starts_with("dir/comp.toml: key `runs[0].name`"), "{m}");
        assert!(
            m.contains("must be non-empty [A-Za-z0-9_-], got \"../x\""),
            "{m}"
        );
    }

    #[test]
    fn scene_name_outside_out_is_refused() {
        let m = message(&COMPRESSION.replace("NAME", "cn"), "dir/...toml");
        assert!(m.contains("key `name (the scene file stem)`"), "{m}");
        assert!(m.contains("got \"..\""), "{m}");
    }

    #[test]
    fn run_checks_of_the_other_model_are_refused() {
        let text = COMPRESSION.replace("NAME", "cn").replace(
            "dt_tau1 = 0.01",
            "dt_tau1 = 0.01\nchecks = [\"force-strain\", \"profile\"]",
        );
        let m = message(&text, "c.toml");
        assert!(m.contains("key `runs[0].checks[1]`"), "{m}");
        assert!(m.contains("got profile"), "{m}");
    }

    /// A membrane scene: `MEMBRANE`, `MESH` and `POINTS` stand for the `[membrane]`
    /// keys, the `[mesh]` keys and the profile points.
    const MEMBRANE_SCENE: &str = r#"
description = "membrane scene"
seed = 1
dims = 3
model = "fem"
checks = ["profile", "mode-variance"]

[membrane]
MEMBRANE

[mesh]
MESH

[sampling]
burn_in_tau1 = 1.0
modes = 3
profile_points = POINTS

[[runs]]
name = "cn"
dt_tau1 = 0.01
quick = { trajectories = 4, duration_tau1 = 40.0 }
standard = { trajectories = 4, duration_tau1 = 40.0 }
full = { trajectories = 4, duration_tau1 = 40.0 }
"#;

    /// The message of parsing [`MEMBRANE_SCENE`] with these keys (empty if accepted).
    fn membrane(table: &str, mesh: &str, points: &str) -> String {
        let text = MEMBRANE_SCENE
            .replace("MEMBRANE", table)
            .replace("MESH", mesh)
            .replace("POINTS", points);
        message(&text, "m.toml")
    }

    /// The membrane mesh at the ends of its ranges: each side in [1, 256] ([2, 256]
    /// periodic), at most 4096 elements in all (also when `elements_y` defaults to
    /// `elements`); the ends themselves accepted, one past them refused naming the key.
    #[test]
    fn membrane_mesh_bounds_at_their_ends() {
        let ss = |mesh: &str| membrane("kt = 1.0", mesh, "[0.5]");
        let periodic = |mesh: &str| membrane("boundary = \"periodic\"", mesh, "[0.5]");
        assert_eq!(ss("elements = 16\nelements_y = 256"), "");
        assert_eq!(ss("elements = 4\nelements_y = 1"), "");
        assert_eq!(ss("elements = 64"), "");
        assert_eq!(periodic("elements = 2\nelements_y = 2"), "");
        let m = ss("elements = 16\nelements_y = 257");
        assert!(
            m.contains("key `mesh.elements_y`: must be in [1, 256] for a membrane, got 257"),
            "{m}"
        );
        let m = ss("elements = 17\nelements_y = 241");
        assert!(m.contains("key `mesh.elements_y`: must be at most 240 (a membrane mesh has at most 4096 elements: mesh.elements x mesh.elements_y = 17 x 241 = 4097), got 241"), "{m}");
        let m = ss("elements = 65");
        assert!(
            m.contains("key `mesh.elements`: must be at most 64 when mesh.elements_y is left out"),
            "{m}"
        );
        let m = periodic("elements = 1\nelements_y = 2");
        assert!(
            m.contains("key `mesh.elements`: must be in [2, 256] for a periodic membrane"),
            "{m}"
        );
        let m = ss("elements = 4\ngrading = 1.5");
        assert!(
            m.contains("key `mesh.grading`: must be 1 for a membrane scene"),
            "{m}"
        );
    }

    /// The membrane's parameters at the ends of their ranges: a side up to 1e30 (within
    /// the aspect ratio), the tension just above the buckling tension −κq₁² (accepted)
    /// and at it (refused).
    #[test]
    fn membrane_parameter_bounds_at_their_ends() {
        let with = |table: &str| membrane(table, "elements = 4", "[0.5]");
        assert_eq!(with("width = 1e27\nheight = 1e30"), "");
        let m = with("width = 1e27\nheight = 1.000000001e30");
        assert!(
            m.contains("key `membrane.height`: must be in [1e-30, 1e30], got 1.000000001e30"),
            "{m}"
        );
        let buckling = -2.0 * std::f64::consts::PI.powi(2);
        assert_eq!(with(&format!("tension = {:e}", buckling.next_up())), "");
        let m = with(&format!("tension = {buckling:e}"));
        assert!(m.contains("key `membrane.tension`: must be finite and > -1.9739208802178716e1, the buckling tension"), "{m}");
    }

    /// Sampling positions x/a: the simply supported edges (h = 0) are refused, a periodic
    /// membrane takes x/a = 0 (the same point as x/a = 1, which it refuses).
    #[test]
    fn membrane_positions_by_boundary() {
        let ss = |points: &str| membrane("kt = 1.0", "elements = 4", points);
        let periodic = |points: &str| membrane("boundary = \"periodic\"", "elements = 4", points);
        assert_eq!(periodic("[0.0, 0.5]"), "");
        assert!(
            periodic("[0.5, 1.0]").contains("key `sampling.profile_points[1]`: must be in [0, 1)")
        );
        assert!(ss("[0.0]").contains("key `sampling.profile_points[0]`: must be in (0, 1)"));
        assert_eq!(ss("[0.5]"), "");
    }

    /// A filament scene refuses `mesh.elements_y` (the count along y of a membrane).
    #[test]
    fn filament_refuses_elements_y() {
        let text = COMPRESSION
            .replace("NAME", "cn")
            .replace("elements = 4", "elements = 4\nelements_y = 4");
        let m = message(&text, "c.toml");
        assert!(
            m.contains("key `mesh.elements_y`: must be left out of a filament scene"),
            "{m}"
        );
    }

    #[test]
    fn compression_run_checks_must_not_be_empty() {
        let text = COMPRESSION
            .replace("NAME", "cn")
            .replace("dt_tau1 = 0.01", "dt_tau1 = 0.01\nchecks = []");
        let m = message(&text, "c.toml");
        assert!(
            m.contains("key `runs[0].checks`: must be a non-empty list"),
            "{m}"
        );
    }
}
