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
//! - Or `membrane` ([`DataMembrane`], `dims` = 3): `width` a, `height` b,
//!   `bending_rigidity` κ, `tension` σ, `drag` ξ per area, `kt` and `boundary`, every key
//!   required; τ₁ = ξ/c_q of the slowest mode. Positions are x on the midline y = b/2;
//!   the columns are `t`, `h_j` (the height there; periodic: from the spatial mean) and
//!   the amplitudes of the `modes` slowest real modes named by their mode
//!   ([`membrane_columns`]: `a_m_n`, or `ac_m_n` and `as_m_n`), in the conventions of
//!   [`crate::spectral::membrane`].
//! - A run's trajectories are sampled every `dt_sample` (between 1e-12 and 1e6 τ₁):
//!   row `r` of a file is at time `t₀ + r·dt_sample`. `start = "rest"`: each trajectory starts from w = 0 at t = 0
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
//!   models (`model = "fem"`, `"finite-difference"` or `"bead-spring"` — a chain of
//!   `elements` intervals, [`crate::fem::chain`] — with `elements`, `integrator`, `noise`
//!   and the time step `dt`, or `"spectral"`), the checks compare with that
//!   discretization's exact reference and state its expected difference from the
//!   continuum; otherwise with the continuum, labelled so, and the producer's
//!   discretization and time-step errors are part of what is checked. For the modelled
//!   ones, `elements` must be in [1, 1000] ([2, 1000] for a chain; as
//!   `mesh.elements` in scene files), `integrator` and `noise` names as in scene files,
//!   and `dt` at most 100 τ₁ (as `dt_tau1` in scene files) and at least `dt_sample`/1e10
//!   (at most 1e10 steps per row); for another model they are only reported.
//!
//! ## What is refused
//! `check` refuses (exit 2, naming the file, the key or column and row, and the value):
//!
//! - JSON that is not JSON: `NaN`, `Infinity` and `-Infinity` are not JSON numbers
//!   (Python's `json.dump` writes them unless given `allow_nan=False`): every number of
//!   the sidecar must be finite. A UTF-8 byte-order mark is accepted.
//! - `null` where a value is required (`dt_sample`, `positions[j]`, `filament.kt`, …):
//!   JSON null stands for a missing value. At an optional key (`strain_ratio`,
//!   `filament.stretch_rigidity`, `discretization` and its keys, `producer`) `null`
//!   reads as the key left out. Every refusal of the JSON layer (a wrong type, a missing
//!   or unknown key) names the key, with its line and column.
//! - A trajectory file that is not a regular file (a FIFO, a device, a directory), or
//!   trajectory files whose total size exceeds what the check may read (`check
//!   --max-memory-gib`).
//! - A file with no data rows; a CSV file naming a column of the format twice; a value
//!   of a column of the format (`t`, `w_j`, `v_j`, `aw_n`, `av_n`; `t`, `force`,
//!   `stored_length`) that is not a finite number (other CSV columns are not read), or
//!   that the checks use and is larger than 1e60 in magnitude in their units (its
//!   fourth powers would overflow: no physical value is near it); a column `t` off the
//!   cadence `t₀ + r·dt_sample`, or (`start = "rest"`) not starting at 0; a `.npy`
//!   header whose shape does not match the file's size, or that gives a key twice.

mod npy;
mod table;

pub use npy::{NpyWriter, read_npy};
pub use table::{Table, TrajectoryFile, read_table};

use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result, shown_number};
use crate::fem::noise::NoiseModel;
use crate::input::{MAX_METADATA_BYTES, read_text};
use crate::params::FilamentParams;
use crate::scene::validate::MAX_ELEMENTS;
use crate::spectral::membrane::{
    Membrane, MembraneBoundary, MembraneMode, MembraneParams, ModeShape,
};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The shortest time between rows of a data run, in τ1 (`dt_sample`): below it a
/// trajectory would need more than 1e12 rows per τ1.
pub const MIN_SAMPLE_TAU1: f64 = 1e-12;
/// The longest time between rows of a data run, in τ1 (`dt_sample`).
pub const MAX_SAMPLE_TAU1: f64 = 1e6;

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
    /// 2 (one transverse deflection w) or 3 (w and v; a membrane, whose height h is its
    /// one component).
    pub dims: usize,
    /// The filament's physical parameters, in one consistent unit system (filament data:
    /// exactly one of `filament` and `membrane` is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filament: Option<DataFilament>,
    /// The membrane's physical parameters and boundary (membrane data).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub membrane: Option<DataMembrane>,
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
/// `j` of `positions` or the mode number `n`), in the base dimensions of the object's
/// unit system ([`crate::output::columns`]: `[L]` its length unit, `[T]` its time unit):
/// a filament's, or (`membrane`) a membrane's. A filament with other ends than two hinges
/// (issue #29; `ends`) has its own modes and, with a free end, its rigid motion
/// projected out of the deflection columns: [`trajectory_columns_with_ends`].
pub fn trajectory_columns(membrane: bool) -> serde_json::Value {
    if membrane {
        return serde_json::json!([
            { "name": "t", "unit": "[T]", "meaning": "time since the start (physical time, not a multiple of tau1)" },
            { "name": "h_#", "unit": "[L]", "meaning": "height h at (positions[#], b/2) on the midline; periodic: measured from the spatial mean" },
            { "name": "a_m_n", "unit": "[L]", "meaning": "simply supported: amplitude of sin(m pi x/a) sin(n pi y/b)" },
            { "name": "ac_m_n, as_m_n", "unit": "[L]", "meaning": "periodic: amplitudes of cos(q.r) and sin(q.r), q = 2 pi (m/a, n/b)" },
            { "name": "positions (sidecar)", "unit": "[L]", "meaning": "x of the height columns on the midline y = b/2" },
            { "name": "dt_sample, burn_in, discretization.dt (sidecar)", "unit": "[T]", "meaning": "time between rows, burn-in, integration step" }
        ]);
    }
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

/// [`trajectory_columns`] of a filament with ends `ends`: for two hinges the same; for
/// other ends the deflections are the elastic shape (the rigid motion of free ends
/// projected out in the damping metric) and the amplitudes those of the ends' modes φ_n
/// (∫φ_n² = L/2, [`crate::spectral::EndedBeam::mode_shape`]).
pub fn trajectory_columns_with_ends(
    membrane: bool,
    ends: crate::params::Ends,
) -> serde_json::Value {
    let mut columns = trajectory_columns(membrane);
    if membrane || ends.is_hinged() {
        return columns;
    }
    let rigid = if ends.rigid_modes() > 0 {
        ", its rigid motion (free ends) projected out: the elastic shape"
    } else {
        ""
    };
    if let Some(list) = columns.as_array_mut() {
        for c in list.iter_mut() {
            let meaning = match c["name"].as_str() {
                Some("w_#") => format!("transverse deflection w at positions[#]{rigid}"),
                Some("aw_#") => format!(
                    "modal amplitude a_n of w, w(x) = sum_n a_n phi_n(x), phi_n the n-th mode of the {ends} filament (int phi_n^2 = L/2), n = #"
                ),
                _ => continue,
            };
            c["meaning"] = serde_json::Value::String(meaning);
        }
    }
    columns
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

/// The membrane of a data directory: the parameters of (M1) ([`MembraneParams`]), every
/// key required.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DataMembrane {
    /// Side a along x (the sampling line y = b/2 runs along it).
    pub width: f64,
    /// Side b along y.
    pub height: f64,
    /// Bending rigidity κ (energy).
    pub bending_rigidity: f64,
    /// Tension σ (energy per area), above the buckling tension −κ q_min².
    pub tension: f64,
    /// Friction ξ per unit area.
    pub drag: f64,
    /// Thermal energy kT.
    pub kt: f64,
    /// `simply-supported` or `periodic`.
    pub boundary: MembraneBoundary,
}

impl DataMembrane {
    /// The membrane's parameters.
    pub fn params(&self) -> MembraneParams {
        MembraneParams {
            bending_rigidity: self.bending_rigidity,
            tension: self.tension,
            drag: self.drag,
            kt: self.kt,
            width: self.width,
            height: self.height,
            boundary: self.boundary,
        }
    }

    /// The membrane of `params`, as a sidecar records it.
    pub fn of(params: &MembraneParams) -> Self {
        DataMembrane {
            width: params.width,
            height: params.height,
            bending_rigidity: params.bending_rigidity,
            tension: params.tension,
            drag: params.drag,
            kt: params.kt,
            boundary: params.boundary,
        }
    }
}

/// What the trajectories of a (validated) data directory are of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DataObject {
    /// A filament.
    Filament(DataFilament),
    /// A membrane, sampled on its midline y = b/2.
    Membrane(DataMembrane),
}

impl DataObject {
    /// The time unit τ₁ (the slowest relaxation time) of the object: ξL⁴/(π⁴EI) for a
    /// filament ([`FilamentParams::tau1`]), ξ/c_q of the slowest mode for a membrane
    /// ([`MembraneParams::tau1`]); NaN for parameters [`DataSidecar::validate`] refuses.
    pub fn tau1(&self) -> f64 {
        match self {
            DataObject::Filament(f) => f.params().tau1(),
            DataObject::Membrane(m) => m.params().tau1(),
        }
    }

    /// The length of the sampling line on which `positions` lie: L, or the width a.
    pub fn line_length(&self) -> f64 {
        match self {
            DataObject::Filament(f) => f.length,
            DataObject::Membrane(m) => m.width,
        }
    }

    /// The column names of a linear run with `positions` deflection columns and `modes`
    /// modal amplitudes per component ([`columns`], [`membrane_columns`]).
    ///
    /// # Errors
    /// A membrane whose modes cannot be listed ([`Membrane::modes`]).
    pub fn columns(&self, dims: usize, positions: usize, modes: usize) -> Result<Vec<String>> {
        match self {
            DataObject::Filament(_) => Ok(columns(dims, positions, modes)),
            DataObject::Membrane(m) => {
                let labels = if modes == 0 {
                    Vec::new()
                } else {
                    Membrane::new(m.params())?.modes(modes)?
                };
                Ok(membrane_columns(positions, &labels))
            }
        }
    }
}

/// The name of the modal-amplitude column of membrane mode `mode`: `a_m_n` for
/// sin(mπx/a) sin(nπy/b), `ac_m_n` and `as_m_n` for cos(q·r) and sin(q·r), q = 2π(m/a,
/// n/b) (the real amplitudes of [`crate::spectral::membrane`]).
pub fn membrane_mode_column(mode: MembraneMode) -> String {
    let prefix = match mode.shape {
        ModeShape::SineSine => "a",
        ModeShape::Cosine => "ac",
        ModeShape::Sine => "as",
    };
    format!("{prefix}_{}_{}", mode.m, mode.n)
}

/// The columns of a membrane run's files: `t`, the heights `h_j` at `positions` on the
/// midline, then the modal amplitudes of `modes`, in their order
/// ([`membrane_mode_column`]).
pub fn membrane_columns(positions: usize, modes: &[MembraneMode]) -> Vec<String> {
    let mut c = vec!["t".to_string()];
    c.extend((0..positions).map(|j| format!("h_{j}")));
    c.extend(modes.iter().map(|&m| membrane_mode_column(m)));
    c
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
    /// Required, as the documentation lists it: a default of 0 would take a run from rest
    /// as stationary from its first row.
    pub burn_in: f64,
    /// Positions x of the deflection columns (length units).
    pub positions: Vec<f64>,
    /// Number of modal amplitude columns per component (required; 0 for none).
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
    /// Filament data whose ends allow rigid motion (a free end and no clamp, issue #29):
    /// whether the files carry the rigid coordinates after the modal amplitudes
    /// ([`filament_extra_columns`]: `w_mean` = (1/L)∫w dx, `w_angle` = the rigid
    /// rotation's angle ∫(x − x_p)w dx / ∫(x − x_p)² dx about its pivot x_p).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub rigid: bool,
    /// Filament data with no clamped end: the number of tangent-angle cosine amplitudes
    /// per component the files carry after the rigid coordinates (Gittes et al. 1993:
    /// `gw_n` = √(2/L)∫θ cos(nπs/L) ds, θ the tangent angle, n = 1 …).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tangent_modes: usize,
}

/// Whether a count is 0 (left out of a written sidecar).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The largest `tangent_modes` of a data run.
pub const MAX_TANGENT_MODES: usize = 1000;

/// The columns a filament's run adds after the modal amplitudes: per component the rigid
/// coordinates `{w,v}_{suffix}` for `rigid` (suffix `mean` for a translation, `angle` for
/// a rotation), then per component the tangent-angle cosine amplitudes `g{w,v}_n`,
/// n = 1 … `tangent_modes`.
pub fn filament_extra_columns(dims: usize, rigid: &[&str], tangent_modes: usize) -> Vec<String> {
    let comps: &[&str] = if dims == 3 { &["w", "v"] } else { &["w"] };
    let mut c = Vec::new();
    for k in comps {
        c.extend(rigid.iter().map(|s| format!("{k}_{s}")));
    }
    for k in comps {
        c.extend((1..=tangent_modes).map(|n| format!("g{k}_{n}")));
    }
    c
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
    /// `fem` (this tool's Hermite-cubic elements), `spectral` (exact modal),
    /// `finite-difference` (the 5-point filament on its nodes) or `bead-spring` (the
    /// linearized discrete worm-like chain; [`crate::fem::chain`]), or any other name
    /// (then only reported).
    pub model: String,
    /// Elements (`fem`), modes carried (`spectral`) or intervals — bonds of a
    /// bead-spring chain — (`finite-difference`, `bead-spring`); of a membrane, along x.
    #[serde(default)]
    pub elements: Option<usize>,
    /// Membrane data: elements (`fem`) or mode indices (`spectral`) along y (left out:
    /// as `elements`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements_y: Option<usize>,
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

/// The most integration steps per row (`dt_sample / discretization.dt`) of a modelled
/// discretization, as scene files allow per trajectory.
pub const MAX_STEPS_PER_ROW: f64 = 1e10;

/// The largest `discretization.dt` of a modelled discretization, in τ₁ (as `dt_tau1` in
/// scene files).
pub const MAX_DT_TAU1: f64 = 100.0;

impl Discretization {
    /// Whether this tool models the discretization (`fem`, `spectral`,
    /// `finite-difference` or `bead-spring`): its `elements`, `integrator`, `noise` and
    /// `dt` then size the reference `check` builds, and are bounded.
    pub fn is_modelled(&self) -> bool {
        matches!(self.model.as_str(), "fem" | "spectral") || self.is_chain()
    }

    /// Whether the discretization is a chain of nodes (`finite-difference` or
    /// `bead-spring`: [`crate::fem::ChainModel`], at least 2 intervals).
    pub fn is_chain(&self) -> bool {
        matches!(self.model.as_str(), "finite-difference" | "bead-spring")
    }

    /// The integrator (default `exact-modal`), if its name is one of the scene files'.
    pub fn integrator_kind(&self) -> Option<IntegratorKind> {
        parse_name(self.integrator.as_deref().unwrap_or("exact-modal"))
    }

    /// The noise model (default `consistent`), if its name is one of the scene files'.
    pub fn noise_model(&self) -> Option<NoiseModel> {
        parse_name(self.noise.as_deref().unwrap_or("consistent"))
    }

    /// Checks the discretization of run `k` (rows every `dt_sample`, a filament of
    /// relaxation time `tau1`): `dt` positive and finite; for a modelled one, `elements`
    /// in [1, [`MAX_ELEMENTS`]], known integrator and noise names, and `dt` in
    /// [`dt_sample`/[`MAX_STEPS_PER_ROW`], [`MAX_DT_TAU1`] τ₁]; on failure (key, message).
    fn validate(
        &self,
        k: usize,
        dt_sample: f64,
        tau1: f64,
    ) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].discretization.{s}");
        if let Some(dt) = self.dt
            && !(dt.is_finite() && dt > 0.0)
        {
            return Err((
                key("dt"),
                format!("must be a positive finite time, got {}", shown_number(dt)),
            ));
        }
        if !self.is_modelled() {
            return Ok(());
        }
        let least = if self.is_chain() { 2 } else { 1 };
        for (name, count) in [("elements", self.elements), ("elements_y", self.elements_y)] {
            if let Some(e) = count
                && !(least..=MAX_ELEMENTS).contains(&e)
            {
                return Err((
                    key(name),
                    format!(
                        "must be in [{least}, {MAX_ELEMENTS}] (as mesh.{name} in scene files{}) for model {:?}, got {e}",
                        if self.is_chain() {
                            "; intervals of the chain, at least one interior node"
                        } else {
                            ""
                        },
                        self.model
                    ),
                ));
            }
        }
        if self.integrator_kind().is_none() {
            return Err((
                key("integrator"),
                format!(
                    "must be an integrator name as in scene files ({}) for model {:?}, got {:?}",
                    IntegratorKind::list(&IntegratorKind::ALL),
                    self.model,
                    self.integrator.as_deref().unwrap_or_default()
                ),
            ));
        }
        if self.noise_model().is_none() {
            return Err((
                key("noise"),
                format!(
                    "must be a noise model name as in scene files ({}) for model {:?}, got {:?}",
                    NoiseModel::ALL.map(|n| n.name()).join(" or "),
                    self.model,
                    self.noise.as_deref().unwrap_or_default()
                ),
            ));
        }
        if let Some(dt) = self.dt {
            let (lo, hi) = (dt_sample / MAX_STEPS_PER_ROW, MAX_DT_TAU1 * tau1);
            if !(lo..=hi).contains(&dt) {
                return Err((
                    key("dt"),
                    format!(
                        "must be in [dt_sample/1e10, 100 tau1] = [{lo:e}, {hi:e}] (at most 1e10 steps per row; at most 100 tau1, as dt_tau1 in scene files) for model {:?}, got {dt:e}",
                        self.model
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A name as the scene files spell it (`crank-nicolson`), parsed by serde.
fn parse_name<T: serde::de::DeserializeOwned>(name: &str) -> Option<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string())).ok()
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
    /// The sidecar is read as a regular file of at most [`MAX_METADATA_BYTES`]
    /// ([`crate::input::read_text`]: a FIFO is refused at once, a byte-order mark
    /// dropped).
    ///
    /// # Errors
    /// [`Error::Scene`] naming the sidecar, the key, the value and the allowed range if it
    /// cannot be read or is not a valid version-1 sidecar (see [What is
    /// refused](self#what-is-refused)).
    pub fn load(dir: &Path) -> Result<DataSidecar> {
        let path = dir.join(SIDECAR);
        let text = read_text(&path, "-", MAX_METADATA_BYTES)?;
        let sidecar: DataSidecar =
            crate::input::parse_json(&path, &text, &format!("a {FORMAT} sidecar"))?;
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
        let object = self.validate_object(path)?;
        if self.runs.is_empty() {
            return Err(bad("runs".into(), "must list at least one run".into()));
        }
        for (k, run) in self.runs.iter().enumerate() {
            run.validate(k, &object, self.runs.iter().take(k))
                .map_err(|(key, message)| bad(key, message))?;
        }
        // Each file is one trajectory: listed twice, it would be counted twice. Compared
        // as path components, so that `a/./b` and `a//b` are `a/b` (the same file reached
        // through a link is found when the files are opened: `require_data_size`).
        let mut seen: std::collections::HashMap<std::path::PathBuf, (usize, usize)> =
            Default::default();
        for (k, run) in self.runs.iter().enumerate() {
            for (j, file) in run.files.iter().enumerate() {
                let spelled = Path::new(file).components().collect();
                if let Some((k0, j0)) = seen.insert(spelled, (k, j)) {
                    return Err(bad(
                        format!("runs[{k}].files[{j}]"),
                        format!(
                            "names {file:?} again (as runs[{k0}].files[{j0}]): each file is one trajectory and may be listed once"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

impl DataSidecar {
    /// The object of the data: the filament or the membrane (`None` unless exactly one
    /// is given; [`DataSidecar::load`] refuses that).
    pub fn object(&self) -> Option<DataObject> {
        match (self.filament, self.membrane) {
            (Some(f), None) => Some(DataObject::Filament(f)),
            (None, Some(m)) => Some(DataObject::Membrane(m)),
            _ => None,
        }
    }

    /// Checks the object's parameters (sidecar `path`): exactly one of `filament` and
    /// `membrane`, every parameter finite, positive where it must be and within
    /// [1e-30, 1e30] in magnitude; a membrane's tension above its buckling tension and
    /// `dims` = 3 (a surface in space).
    fn validate_object(&self, path: &Path) -> Result<DataObject> {
        let bad = |key: String, message: String| Error::Scene {
            file: path.to_path_buf(),
            key,
            message,
        };
        let Some(object) = self.object() else {
            let key = if self.filament.is_some() {
                "membrane"
            } else {
                "filament"
            };
            return Err(bad(
                key.into(),
                "exactly one of filament (a filament's length, bending_rigidity, drag, kt) and membrane (width, height, bending_rigidity, tension, drag, kt, boundary) must be given".into(),
            ));
        };
        let (table, values): (&str, Vec<(&str, f64)>) = match &object {
            DataObject::Filament(f) => (
                "filament",
                vec![
                    ("stretch_rigidity", f.stretch_rigidity.unwrap_or(1.0)),
                    ("length", f.length),
                    ("bending_rigidity", f.bending_rigidity),
                    ("drag", f.drag),
                    ("kt", f.kt),
                ],
            ),
            DataObject::Membrane(m) => (
                "membrane",
                vec![
                    ("width", m.width),
                    ("height", m.height),
                    ("bending_rigidity", m.bending_rigidity),
                    ("drag", m.drag),
                    ("kt", m.kt),
                ],
            ),
        };
        for (key, v) in values {
            if !(v.is_finite() && v > 0.0 && (1e-30..=1e30).contains(&v)) {
                return Err(bad(
                    format!("{table}.{key}"),
                    format!(
                        "must be a finite number in [1e-30, 1e30], got {}",
                        shown_number(v)
                    ),
                ));
            }
        }
        if let DataObject::Membrane(m) = &object {
            if !(m.tension.is_finite() && m.tension.abs() <= 1e30) {
                return Err(bad(
                    "membrane.tension".into(),
                    format!(
                        "must be a finite number in [-1e30, 1e30], got {}",
                        shown_number(m.tension)
                    ),
                ));
            }
            m.params().validate().map_err(|e| match e {
                Error::InvalidParameter {
                    name,
                    value,
                    allowed,
                } => bad(
                    format!("membrane.{name}"),
                    format!("must be {allowed}, got {value}"),
                ),
                other => other,
            })?;
            if self.dims != 3 {
                return Err(bad(
                    "dims".into(),
                    format!(
                        "must be 3 for membrane data (a surface in space, one height h per position), got {}",
                        self.dims
                    ),
                ));
            }
        }
        Ok(object)
    }
}

impl DataRun {
    /// Checks run `k` of a sidecar (`earlier`: the runs before it), of `object`; on
    /// failure (key, message).
    fn validate<'a>(
        &self,
        k: usize,
        object: &DataObject,
        earlier: impl Iterator<Item = &'a DataRun>,
    ) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].{s}");
        self.validate_kind(k, matches!(object, DataObject::Membrane(_)))?;
        self.validate_name(k, earlier)?;
        if let Some(r) = self.strain_ratio
            && !(r.is_finite() && (-1e6..=1e6).contains(&r))
        {
            return Err((
                key("strain_ratio"),
                format!(
                    "must be a finite ratio in [-1e6, 1e6], got {}",
                    shown_number(r)
                ),
            ));
        }
        let tau1 = object.tau1();
        let (lo, hi) = (MIN_SAMPLE_TAU1 * tau1, MAX_SAMPLE_TAU1 * tau1);
        if !(self.dt_sample.is_finite() && (lo..=hi).contains(&self.dt_sample)) {
            return Err((
                key("dt_sample"),
                format!(
                    "must be a time between rows in [{MIN_SAMPLE_TAU1:e}, {MAX_SAMPLE_TAU1:e}] tau1 = [{lo:e}, {hi:e}] (tau1 = {} = {tau1:e}), got {:e}",
                    match object {
                        DataObject::Filament(_) => "xi L^4/(pi^4 EI) from the filament",
                        DataObject::Membrane(_) => "xi/c_q of the membrane's slowest mode",
                    },
                    self.dt_sample
                ),
            ));
        }
        if !(self.burn_in.is_finite() && self.burn_in >= 0.0) {
            return Err((
                key("burn_in"),
                format!(
                    "must be a finite time >= 0, got {}",
                    shown_number(self.burn_in)
                ),
            ));
        }
        self.validate_layout(k, object.line_length())?;
        match &self.discretization {
            Some(d) => d.validate(k, self.dt_sample, tau1),
            None => Ok(()),
        }
    }

    /// The optional columns of run `k` against its kind of data (`membrane` or a
    /// filament; compression data when it has a strain ratio): tangent modes, rigid
    /// coordinates and a mesh along y only where they exist; on failure (key, message).
    fn validate_kind(&self, k: usize, membrane: bool) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].{s}");
        if self.tangent_modes > MAX_TANGENT_MODES || (membrane && self.tangent_modes > 0) {
            return Err((
                key("tangent_modes"),
                format!(
                    "must be in [0, {MAX_TANGENT_MODES}] for filament data (the tangent-angle cosine amplitudes per component) and 0 (left out) for membrane data, got {}",
                    self.tangent_modes
                ),
            ));
        }
        if let Some(e) = self.discretization.as_ref().and_then(|d| d.elements_y)
            && !membrane
        {
            return Err((
                key("discretization.elements_y"),
                format!(
                    "must be left out for filament data (a membrane's elements or mode indices along y; a filament's count is discretization.elements), got {e}"
                ),
            ));
        }
        if membrane && self.rigid {
            return Err((
                key("rigid"),
                "must be false (left out) for membrane data: rigid coordinates belong to a filament with a free end".into(),
            ));
        }
        if self.strain_ratio.is_some() && (self.rigid || self.tangent_modes > 0) {
            return Err((
                key(if self.rigid { "rigid" } else { "tangent_modes" }),
                "must be left out for compression data (columns t, force, stored_length)".into(),
            ));
        }
        Ok(())
    }

    /// The name of run `k`: a path component, not used twice at one strain ratio among
    /// the runs before it (`earlier`); on failure (key, message).
    fn validate_name<'a>(
        &self,
        k: usize,
        mut earlier: impl Iterator<Item = &'a DataRun>,
    ) -> std::result::Result<(), (String, String)> {
        let key = |s: &str| format!("runs[{k}].{s}");
        if !crate::scene::validate::is_path_name(&self.name) {
            return Err((
                key("name"),
                format!(
                    "must be 1 to {} letters, digits, '-' or '_' (it names files), got {}",
                    crate::scene::validate::MAX_NAME_LEN,
                    match self.name.chars().count() {
                        n if n > crate::scene::validate::MAX_NAME_LEN =>
                            format!("a name of {n} characters"),
                        _ => format!("{:?}", self.name),
                    }
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
        Ok(())
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
                    format!(
                        "must be in [0, {length}] (the filament's [0, L], or a membrane's midline x in [0, a]), got {}",
                        shown_number(x)
                    ),
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
        Ok(())
    }

    /// The paths of the run's files under data directory `dir`.
    pub fn paths(&self, dir: &Path) -> Vec<PathBuf> {
        self.files.iter().map(|f| dir.join(f)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid sidecar of one `fem` run (τ₁ = 1/π⁴ ≈ 0.0103), as text.
    const VALID: &str = r#"{ "format": "langevin-fem-trajectories", "version": 1, "dims": 2,
  "filament": { "length": 1.0, "bending_rigidity": 1.0, "drag": 1.0, "kt": 1.0 },
  "runs": [ { "name": "cn", "dt_sample": 1.0e-4, "start": "rest", "burn_in": 0.0,
              "positions": [0.5], "modes": 2,
              "discretization": { "model": "fem", "elements": 4,
                                  "integrator": "crank-nicolson", "noise": "consistent", "dt": 1.0e-5 },
              "files": ["cn/t0.csv"] } ] }"#;

    /// `text` as the sidecar of a fresh directory (of its own: tests run in parallel),
    /// loaded.
    fn load(tag: &str, text: &str) -> Result<DataSidecar> {
        static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("lfem-sidecar-{tag}-{n}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(SIDECAR), text).unwrap();
        let r = DataSidecar::load(&dir);
        std::fs::remove_dir_all(&dir).unwrap();
        r
    }

    /// The refusal of `VALID` with `from` replaced by `to`: exit 2, naming the sidecar
    /// and holding every string of `named`.
    fn refused_with(from: &str, to: &str, named: &[&str]) {
        assert!(VALID.contains(from), "{from}");
        let e = load("bad", &VALID.replacen(from, to, 1)).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
        let text = e.to_string();
        assert!(text.contains(SIDECAR), "{text}");
        for n in named {
            assert!(text.contains(n), "{from} -> {to}: {n:?} not in {text}");
        }
    }

    /// A valid sidecar loads, with or without a byte-order mark; optional text keys may be
    /// null.
    #[test]
    fn valid_sidecars_load() {
        let side = load("valid", VALID).unwrap();
        assert_eq!(
            side.runs[0].discretization.as_ref().unwrap().elements,
            Some(4)
        );
        assert_eq!(load("bom", &format!("\u{feff}{VALID}")).unwrap(), side);
        let null_noise = VALID.replace("\"consistent\"", "null");
        let d = load("null", &null_noise).unwrap().runs[0]
            .discretization
            .clone();
        assert_eq!(d.unwrap().noise, None);
    }

    /// A run name names files: 1 to 64 characters of `[A-Za-z0-9_-]`, as a scene's run
    /// names (a longer one would exceed a file system's 255 bytes with its suffixes).
    #[test]
    fn run_names_are_path_names_of_at_most_64_characters() {
        let name = |n: usize| format!("\"name\": \"{}\"", "x".repeat(n));
        assert!(load("name64", &VALID.replacen("\"name\": \"cn\"", &name(64), 1)).is_ok());
        refused_with(
            "\"name\": \"cn\"",
            &name(65),
            &[
                "`runs[0].name`",
                "1 to 64 letters",
                "a name of 65 characters",
            ],
        );
        refused_with(
            "\"name\": \"cn\"",
            "\"name\": \"../cn\"",
            &["`runs[0].name`", "\"../cn\""],
        );
    }

    /// Non-finite literals and nulls at numeric keys, named with their keys.
    #[test]
    fn non_numbers_are_refused_naming_the_key() {
        refused_with(
            "\"burn_in\": 0.0",
            "\"burn_in\": Infinity",
            &["`runs[0].burn_in`", "Infinity at line 3", "allow_nan=False"],
        );
        refused_with(
            "\"dt_sample\": 1.0e-4",
            "\"dt_sample\": null",
            &["`runs[0].dt_sample`", "got null"],
        );
        refused_with(
            "\"kt\": 1.0",
            "\"kt\": null",
            &["`filament.kt`", "got null"],
        );
    }

    /// The numbers that size the reference of a modelled discretization are bounded,
    /// and its names must be the scene files'; another model's are only reported.
    #[test]
    fn modelled_discretizations_are_bounded() {
        for (e, v) in [("0", "got 0"), ("100000000", "got 100000000")] {
            refused_with(
                "\"elements\": 4",
                &format!("\"elements\": {e}"),
                &["`runs[0].discretization.elements`", "[1, 1000]", v],
            );
        }
        for dt in ["1e-15", "2.0"] {
            refused_with(
                "\"dt\": 1.0e-5",
                &format!("\"dt\": {dt}"),
                &[
                    "`runs[0].discretization.dt`",
                    "1e10 steps per row",
                    "100 tau1",
                ],
            );
        }
        refused_with(
            "\"crank-nicolson\"",
            "\"rk4\"",
            &[
                "`runs[0].discretization.integrator`",
                "\"rk4\"",
                "exact-modal",
            ],
        );
        refused_with(
            "\"consistent\"",
            "\"white\"",
            &[
                "`runs[0].discretization.noise`",
                "\"white\"",
                "element-uniform",
            ],
        );
        let other = VALID
            .replace("\"fem\"", "\"finite-differences\"")
            .replace("\"elements\": 4", "\"elements\": 100000");
        assert!(load("other", &other).is_ok());
    }

    /// A valid membrane sidecar: a simply supported unit square, rows of heights on
    /// its midline.
    const MEMBRANE: &str = r#"{ "format": "langevin-fem-trajectories", "version": 1, "dims": 3,
  "membrane": { "width": 1.0, "height": 1.0, "bending_rigidity": 1.0, "tension": 0.0,
                "drag": 1.0, "kt": 1.0, "boundary": "simply-supported" },
  "runs": [ { "name": "cn", "dt_sample": 1.0e-4, "start": "rest", "burn_in": 0.0,
              "positions": [0.5], "modes": 3, "files": ["cn/t0.csv"] } ] }"#;

    /// Membrane data load with their own time unit and columns (heights `h_j`, then
    /// the modal amplitudes named by their modes, slowest first); every key is
    /// required, the tension must lie above buckling, dims must be 3, and exactly one
    /// of filament and membrane may be given.
    #[test]
    fn membrane_sidecars_load_and_their_errors_name_the_key() {
        let side = load("membrane", MEMBRANE).unwrap();
        let object = side.object().unwrap();
        // τ₁ = ξ/c_q of mode (1, 1): q² = 2π², c_q = κq⁴.
        let q2 = 2.0 * std::f64::consts::PI.powi(2);
        assert!((object.tau1() * q2 * q2 - 1.0).abs() < 1e-14);
        assert_eq!(
            object.columns(3, 1, 3).unwrap(),
            ["t", "h_0", "a_1_1", "a_1_2", "a_2_1"]
        );
        let periodic = MEMBRANE.replace("\"simply-supported\"", "\"periodic\"");
        let p = load("periodic", &periodic).unwrap().object().unwrap();
        assert_eq!(
            p.columns(3, 0, 4).unwrap(),
            ["t", "ac_0_1", "as_0_1", "ac_1_0", "as_1_0"]
        );
        let bad = |from: &str, to: &str, named: &[&str]| {
            assert!(MEMBRANE.contains(from), "{from}");
            let e = load("bad-membrane", &MEMBRANE.replacen(from, to, 1)).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{e}");
            for n in named {
                assert!(e.to_string().contains(n), "{n:?} not in {e}");
            }
        };
        bad(
            "\"tension\": 0.0",
            "\"tension\": -20.0",
            &["`membrane.tension`", "buckling tension", "got -20"],
        );
        bad("\"kt\": 1.0,", "", &["`membrane.kt`", "missing field `kt`"]);
        bad(
            "\"width\": 1.0",
            "\"width\": 0.0",
            &["`membrane.width`", "[1e-30, 1e30]", "got 0"],
        );
        bad(
            "\"dims\": 3",
            "\"dims\": 2",
            &["`dims`", "must be 3", "got 2"],
        );
        bad(
            "\"membrane\": {",
            "\"filament\": { \"length\": 1.0, \"bending_rigidity\": 1.0, \"drag\": 1.0, \"kt\": 1.0 }, \"membrane\": {",
            &["`membrane`", "exactly one of filament"],
        );
        bad(
            "\"positions\": [0.5]",
            "\"positions\": [1.5]",
            &["`runs[0].positions[0]`", "[0, 1]", "got 1.5"],
        );
    }

    /// A FIFO named data.json is refused at once.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_fifo_sidecar_is_refused_at_once() {
        let dir = std::env::temp_dir().join(format!("lfem-sidecar-fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join(SIDECAR))
            .status()
            .is_ok_and(|s| s.success());
        if made {
            let e = DataSidecar::load(&dir).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            assert!(e.to_string().contains("FIFO"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
