//! Trajectory data: the format that `langevin-fem run` writes and `langevin-fem check`
//! reads, so that any simulator's output can be checked against the exact references.
//!
//! # The format (version 1)
//! A data directory holds a sidecar `data.json` ([`DataSidecar`]) and one file per
//! trajectory, listed in the sidecar (paths relative to the directory):
//!
//! ```json
//! { "format": "langevin-fem-trajectories", "version": 1,
//!   "producer": "my-simulator 2.1",
//!   "dims": 2,
//!   "filament": { "length": 1.0, "bending_rigidity": 1.0, "drag": 1.0, "kt": 1.0 },
//!   "runs": [ { "name": "euler", "dt_sample": 1.0e-5, "start": "rest", "burn_in": 0.05,
//!               "positions": [0.25, 0.5], "modes": 4,
//!               "discretization": { "model": "spectral", "elements": 4,
//!                                   "integrator": "euler-maruyama", "dt": 1.0e-7 },
//!               "files": ["euler/trajectory-0000.csv", "euler/trajectory-0001.csv"] } ] }
//! ```
//!
//! - `filament`: length L, bending rigidity EI, transverse drag per length ξ and thermal
//!   energy kT in one consistent unit system; every time (`dt_sample`, `burn_in`, the
//!   column `t`) is in the time unit it implies (τ₁ = ξL⁴/(π⁴EI) sets the scale).
//! - A run's trajectories are sampled every `dt_sample`: row `r` of a file is at time
//!   `t₀ + r·dt_sample`. `start = "rest"`: each trajectory starts from w = 0 at t = 0
//!   (the first row), so the two-time correlation from rest, eq. (4), can be checked at
//!   sample times; `"stationary"`: the first row is already stationary. Rows before
//!   `burn_in` (time) are left out of the stationary statistics.
//! - Columns ([`columns`]), in this order: `t`; the deflection `w_j` at `positions[j]`
//!   (length units, 0 ≤ x ≤ L); in 3D the second transverse component `v_j`; the modal
//!   amplitudes `aw_n` (n = 1..`modes`), defined by w(x, t) = Σₙ aₙ(t) sin(nπx/L) (length
//!   units); in 3D `av_n` of v. Signs of the aₙ are free (every check is sign-blind).
//! - Files: CSV with a header of these column names (any column order; extra columns
//!   are ignored), or NumPy `.npy` (little-endian float64, C order, shape (rows,
//!   columns), the columns in the order above).
//! - `discretization` (optional): what produced the data. When it is one this tool
//!   models (`model = "fem"` with `elements`, `integrator`, `noise` and the time step
//!   `dt`, or `"spectral"`), the checks compare with that discretization's exact
//!   reference and state its expected deficit against the continuum; otherwise with the
//!   continuum, and the producer's discretization and time-step errors are part of what
//!   is checked.

mod npy;
mod table;

pub use npy::{NpyWriter, read_npy};
pub use table::{Table, TrajectoryFile, read_table};

use crate::error::{Error, Result};
use crate::params::FilamentParams;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` field of a sidecar.
pub const FORMAT: &str = "langevin-fem-trajectories";
/// The format version this tool writes and reads.
pub const VERSION: u32 = 1;
/// File name of the sidecar in a data directory.
pub const SIDECAR: &str = "data.json";

/// The sidecar of a data directory (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataSidecar {
    /// Always [`FORMAT`].
    pub format: String,
    /// The format version ([`VERSION`]).
    pub version: u32,
    /// Free text naming the program that wrote the data.
    #[serde(default)]
    pub producer: String,
    /// 2 (one transverse deflection w) or 3 (w and v).
    pub dims: usize,
    /// Physical parameters, in one consistent unit system.
    pub filament: DataFilament,
    /// The runs.
    pub runs: Vec<DataRun>,
    /// Where the data came from when this tool wrote it (version, commit, seed, scene):
    /// free-form, not read by `check`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<serde_json::Value>,
    /// The columns of the trajectory files with their units and meanings, for a reader
    /// ([`trajectory_columns`]): written by this tool, not read by `check`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<serde_json::Value>,
}

/// The units and meanings of the trajectory files' columns (`#` stands for the index
/// `j` of `positions` or the mode number `n`), in the base dimensions of the filament's
/// unit system ([`crate::output::columns`]: `[L]` its length unit, `[T]` its time unit).
pub fn trajectory_columns() -> serde_json::Value {
    serde_json::json!([
        { "name": "t", "unit": "[T]", "meaning": "time since the start (physical time, not a multiple of tau1)" },
        { "name": "w_#", "unit": "[L]", "meaning": "transverse deflection w at positions[#]" },
        { "name": "v_#", "unit": "[L]", "meaning": "3D: second transverse deflection v at positions[#]" },
        { "name": "aw_#", "unit": "[L]", "meaning": "modal amplitude a_n of w, w(x) = sum_n a_n sin(n pi x / L), n = #" },
        { "name": "av_#", "unit": "[L]", "meaning": "3D: modal amplitude a_n of v, n = #" },
        { "name": "force", "unit": "[E]/[L]", "meaning": "compression runs: compressive axial force F (F_c0 = pi^2 EI/L^2)" },
        { "name": "stored_length", "unit": "[L]", "meaning": "compression runs: stored length (eps - F/EA) L" },
        { "name": "positions (sidecar)", "unit": "[L]", "meaning": "positions of the deflection columns" },
        { "name": "dt_sample, burn_in, discretization.dt (sidecar)", "unit": "[T]", "meaning": "time between rows, burn-in, integration step" }
    ])
}

/// The filament of a data directory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataFilament {
    /// Length L.
    pub length: f64,
    /// Bending rigidity EI (energy × length).
    pub bending_rigidity: f64,
    /// Transverse drag per length ξ.
    pub drag: f64,
    /// Thermal energy kT.
    pub kt: f64,
    /// Stretching rigidity EA (force): compression data only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch_rigidity: Option<f64>,
}

impl DataFilament {
    /// The filament parameters (EA at its default: the linear checks do not use it).
    pub fn params(&self) -> FilamentParams {
        let default = FilamentParams::default();
        FilamentParams {
            length: self.length,
            bending_rigidity: self.bending_rigidity,
            drag: self.drag,
            kt: self.kt,
            stretch_rigidity: self.stretch_rigidity.unwrap_or(default.stretch_rigidity),
        }
    }
}

/// How the trajectories of a run start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// From w = 0 at t = 0 (the first row).
    Rest,
    /// Already stationary at the first row.
    Stationary,
}

/// One run of a data directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataRun {
    /// Run name (reports use it as a prefix).
    pub name: String,
    /// Time between rows.
    pub dt_sample: f64,
    /// How the trajectories start.
    pub start: Start,
    /// Time before which rows are not stationary (left out of stationary statistics).
    #[serde(default)]
    pub burn_in: f64,
    /// Positions x of the deflection columns (length units).
    pub positions: Vec<f64>,
    /// Number of modal amplitude columns per component.
    #[serde(default)]
    pub modes: usize,
    /// The producer's discretization, if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub discretization: Option<Discretization>,
    /// Trajectory files, relative to the data directory.
    pub files: Vec<String>,
    /// Compression data: the imposed strain ε/ε_c0 of these trajectories (one data run
    /// per strain, sharing the run name); their columns are [`COMPRESSION_COLUMNS`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strain_ratio: Option<f64>,
}

/// The columns of a compression run's files: time, the compressive force F (force
/// units; F_c0 = π²EI/L² is the Euler load) and the stored length s·L = (ε − F/EA)·L
/// (length units).
pub const COMPRESSION_COLUMNS: [&str; 3] = ["t", "force", "stored_length"];

impl DataRun {
    /// The column names of this run's files.
    pub fn column_names(&self, dims: usize) -> Vec<String> {
        match self.strain_ratio {
            Some(_) => COMPRESSION_COLUMNS.iter().map(|c| c.to_string()).collect(),
            None => columns(dims, self.positions.len(), self.modes),
        }
    }
}

/// The discretization that produced a run's data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Discretization {
    /// `fem` (this tool's Hermite-cubic elements), `spectral` (exact modal), or any other
    /// name (then only reported).
    pub model: String,
    /// Elements (`fem`) or modes carried (`spectral`).
    #[serde(default)]
    pub elements: Option<usize>,
    /// Integrator name as in scene files.
    #[serde(default)]
    pub integrator: Option<String>,
    /// Noise model name as in scene files (`fem`).
    #[serde(default)]
    pub noise: Option<String>,
    /// Integration time step.
    #[serde(default)]
    pub dt: Option<f64>,
}

/// The column names of a run's files, in order (see the [module docs](self)).
pub fn columns(dims: usize, positions: usize, modes: usize) -> Vec<String> {
    let mut c = vec!["t".to_string()];
    let comps: &[&str] = if dims == 3 { &["w", "v"] } else { &["w"] };
    for k in comps {
        c.extend((0..positions).map(|j| format!("{k}_{j}")));
    }
    for k in comps {
        c.extend((1..=modes).map(|n| format!("a{k}_{n}")));
    }
    c
}

impl DataSidecar {
    /// Reads and checks the sidecar of data directory `dir`.
    ///
    /// # Errors
    /// [`Error::Io`] if unreadable; [`Error::Scene`] naming the sidecar, the key, the value
    /// and the allowed range if it is not a valid version-1 sidecar.
    pub fn load(dir: &Path) -> Result<DataSidecar> {
        let path = dir.join(SIDECAR);
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let sidecar: DataSidecar = serde_json::from_str(&text).map_err(|e| Error::Scene {
            file: path.clone(),
            key: "-".to_string(),
            message: format!(
                "not a {FORMAT} sidecar: {e} (line {}, column {})",
                e.line(),
                e.column()
            ),
        })?;
        sidecar.validate(&path)?;
        Ok(sidecar)
    }

    /// Checks every field of the sidecar read from `path`.
    ///
    /// # Errors
    /// [`Error::Scene`] naming `path`, the key, the value and the allowed range.
    pub fn validate(&self, path: &Path) -> Result<()> {
        let bad = |key: String, message: String| Error::Scene {
            file: path.to_path_buf(),
            key,
            message,
        };
        if self.format != FORMAT {
            return Err(bad(
                "format".into(),
                format!("must be \"{FORMAT}\", got {:?}", self.format),
            ));
        }
        if self.version != VERSION {
            return Err(bad(
                "version".into(),
                format!(
                    "must be {VERSION} (this tool reads version {VERSION}), got {}",
                    self.version
                ),
            ));
        }
        if !matches!(self.dims, 2 | 3) {
            return Err(bad(
                "dims".into(),
                format!("must be 2 or 3, got {}", self.dims),
            ));
        }
        let f = &self.filament;
        for (key, v) in [
            ("stretch_rigidity", f.stretch_rigidity.unwrap_or(1.0)),
            ("length", f.length),
            ("bending_rigidity", f.bending_rigidity),
            ("drag", f.drag),
            ("kt", f.kt),
        ] {
            if !(v.is_finite() && v > 0.0 && (1e-30..=1e30).contains(&v)) {
                return Err(bad(
                    format!("filament.{key}"),
                    format!("must be a finite number in [1e-30, 1e30], got {v}"),
                ));
            }
        }
        if self.runs.is_empty() {
            return Err(bad("runs".into(), "must list at least one run".into()));
        }
        for (k, run) in self.runs.iter().enumerate() {
            run.validate(k, f.length, self.runs.iter().take(k))
                .map_err(|(key, message)| bad(key, message))?;
        }
        Ok(())
    }
}

impl DataRun {
    /// Checks run `k` of a sidecar (`earlier`: the runs before it), for a filament of
    /// length `length`; on failure (key, message).
    fn validate<'a>(
        &self,
        k: usize,
        length: f64,
        mut earlier: impl Iterator<Item = &'a DataRun>,
    ) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].{s}");
        if !crate::scene::validate::is_path_name(&self.name) {
            return Err((
                key("name"),
                format!(
                    "must be 1 to 64 letters, digits, '-' or '_' (it names files), got {:?}",
                    self.name
                ),
            ));
        }
        if earlier.any(|r| r.name == self.name && r.strain_ratio == self.strain_ratio) {
            return Err((
                key("name"),
                format!(
                    "{:?} is used twice{}",
                    self.name,
                    self.strain_ratio
                        .map_or(String::new(), |r| format!(" at strain_ratio {r}"))
                ),
            ));
        }
        if let Some(r) = self.strain_ratio
            && !(r.is_finite() && (-1e6..=1e6).contains(&r))
        {
            return Err((
                key("strain_ratio"),
                format!("must be a finite ratio in [-1e6, 1e6], got {r}"),
            ));
        }
        if !(self.dt_sample.is_finite() && self.dt_sample > 0.0) {
            return Err((
                key("dt_sample"),
                format!("must be a positive finite time, got {}", self.dt_sample),
            ));
        }
        if !(self.burn_in.is_finite() && self.burn_in >= 0.0) {
            return Err((
                key("burn_in"),
                format!("must be a finite time >= 0, got {}", self.burn_in),
            ));
        }
        self.validate_layout(k, length)
    }

    /// The columns and files of run `k` (for a filament of length `length`): positions
    /// within [0, L], the mode count, relative `.csv`/`.npy` paths and the
    /// discretization's step; on failure (key, message).
    fn validate_layout(&self, k: usize, length: f64) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].{s}");
        if self.positions.len() > 10_000 {
            return Err((
                key("positions"),
                format!(
                    "must hold at most 10000 positions, got {}",
                    self.positions.len()
                ),
            ));
        }
        for (j, &x) in self.positions.iter().enumerate() {
            if !(x.is_finite() && (0.0..=length).contains(&x)) {
                return Err((
                    format!("runs[{k}].positions[{j}]"),
                    format!("must be in [0, L] = [0, {length}], got {x}"),
                ));
            }
        }
        if self.modes > 1000 {
            return Err((
                key("modes"),
                format!("must be in [0, 1000], got {}", self.modes),
            ));
        }
        if self.files.is_empty() {
            return Err((
                key("files"),
                "must list at least one trajectory file".into(),
            ));
        }
        for (j, f) in self.files.iter().enumerate() {
            if crate::output::manifest::safe_relative(f).is_none() {
                return Err((
                    format!("runs[{k}].files[{j}]"),
                    format!("must be a relative path inside the data directory, got {f:?}"),
                ));
            }
            if !(f.ends_with(".csv") || f.ends_with(".npy")) {
                return Err((
                    format!("runs[{k}].files[{j}]"),
                    format!("must end in .csv or .npy, got {f:?}"),
                ));
            }
        }
        if let Some(d) = &self.discretization
            && let Some(dt) = d.dt
            && !(dt.is_finite() && dt > 0.0)
        {
            return Err((
                key("discretization.dt"),
                format!("must be a positive finite time, got {dt}"),
            ));
        }
        Ok(())
    }

    /// The paths of the run's files under data directory `dir`.
    pub fn paths(&self, dir: &Path) -> Vec<PathBuf> {
        self.files.iter().map(|f| dir.join(f)).collect()
    }
}
