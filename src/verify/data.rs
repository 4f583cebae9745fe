//! `check`: a scene's statistical checks applied to trajectories written by any program
//! in the trajectory data format ([`crate::data`]).
//!
//! The scene says what is checked (its check kinds, modes, profile points and two-time
//! points); the data's sidecar says what was simulated (the filament, the sampling, the
//! positions and, if known, the discretization). The references are:
//!
//! - the exact discrete reference of the producer's discretization, when it is one this
//!   tool models (`fem` with its elements, integrator, noise and time step, or
//!   `spectral`): as in `verify`, a failure then says the data disagree with what that
//!   discretization must give; each check states the continuum value beside it and the
//!   run's note the expected discretization deficit (discrete / continuum − 1) per mode;
//! - otherwise the continuum solution of eq. (2)–(4): the producer's discretization and
//!   time-step errors are then part of what is checked, and a producer whose bias
//!   exceeds the statistical error fails, naming the checks.
//!
//! The data are read into the same per-trajectory records `verify` builds while it
//! simulates, and judged by the same checks ([`crate::verify::checks::linear_checks`]),
//! family-wise correction and report.

use crate::data::{DataRun, DataSidecar, Discretization, Start, columns, read_table};
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::noise::NoiseModel;
use crate::params::FilamentParams;
use crate::scene::compression::{CompressionRun, CompressionTheoryTable, ForceRecord};
use crate::scene::linear::{
    LinearReference, LinearRun, ModeReference, TrajectoryRecord, TwoTimeReference,
};
use crate::scene::{CompressionSpec, ModelKind, RunSpec, Scene};
use crate::spectral::HingedBeam;
use crate::stats::moments::MIN_SERIES_LEN;
use std::path::Path;

/// A data run ready for the checks: the references in rows of the data, the records
/// read from its files, and what a reader should know.
pub struct DataCheck {
    /// The run (no model; references and sampling plan in rows).
    pub run: LinearRun,
    /// The per-trajectory records, as `verify` builds them.
    pub records: Vec<TrajectoryRecord>,
    /// The two-time products per trajectory.
    pub two_time: Vec<Vec<f64>>,
    /// Notes: the references used, the expected discretization deficit, what the data
    /// did not allow to check and why.
    pub notes: Vec<String>,
}

/// Relative tolerance on a time or position of the data matching a scene's.
const MATCH: f64 = 1e-6;

/// Prepares the checks of data run `k` of `sidecar` (read from `dir`) against `scene`.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar (or scene) key when the data cannot serve the
/// scene's checks (another model kind, too few rows for the slowest checked series);
/// [`Error::InvalidParameter`] naming a trajectory file that does not hold what the
/// sidecar says; [`Error::Io`] if unreadable.
pub fn prepare_data_check(
    scene: &Scene,
    sidecar: &DataSidecar,
    dir: &Path,
    k: usize,
) -> Result<DataCheck> {
    check_linear_data(scene, sidecar, dir, k)?;
    let data = &sidecar.runs[k];
    let filament = sidecar.filament.params();
    let continuum = HingedBeam::new(filament)?;
    let mut notes = Vec::new();
    let discrete = discrete_run(scene, filament, data, &mut notes)?;
    let spec = data_spec(scene, data);
    let (modes, scale, discrete) = mode_references(scene, data, &continuum, discrete, &mut notes);
    let d = discrete.as_ref();
    let profile = profile_references(scene, data, filament.length, &continuum, d, &mut notes);
    let (two_time, tt_cols) =
        two_time_references(scene, data, filament, &continuum, d, &mut notes)?;
    let dts = data.dt_sample;
    let every = |rate: f64| ((0.5 / rate) / dts).floor().max(1.0) as u64;
    let mode_every: Vec<u64> = modes
        .iter()
        .map(|m| every(m.rate_discrete.unwrap_or(m.rate_continuum)))
        .collect();
    let rate1 = continuum.mode_rate(1);
    let profile_every = every(4.0 * rate1);
    let max_rate = modes.last().map_or(rate1, |m| m.rate_continuum);
    let components = scene.dims - 1;
    let reference = LinearReference {
        modes,
        profile_x: profile.0,
        profile_discrete: profile.1,
        profile_continuum: profile.2,
        two_time,
        dt: dts,
        max_rate,
    };
    let run = LinearRun::for_data(
        spec,
        components,
        reference,
        mode_every,
        profile_every,
        scale,
    );
    let layout = Layout {
        n_positions: data.positions.len(),
        n_modes_data: data.modes,
        profile_cols: profile.3,
        tt_cols,
    };
    let (records, products) = read_records(&run, sidecar, dir, k, &layout)?;
    Ok(DataCheck {
        run,
        records,
        two_time: products,
        notes,
    })
}

/// The error of key `runs[k].<key>` of the sidecar in `dir`.
fn sidecar_error(dir: &Path, k: usize, key: &str, message: String) -> Error {
    Error::Scene {
        file: dir.join(crate::data::SIDECAR),
        key: format!("runs[{k}].{key}"),
        message,
    }
}

/// Refuses data run `k` unless `scene` is linear, the dimensions agree, the run has no
/// strain and every listed file exists.
fn check_linear_data(scene: &Scene, sidecar: &DataSidecar, dir: &Path, k: usize) -> Result<()> {
    let sidecar_path = dir.join(crate::data::SIDECAR);
    let data = &sidecar.runs[k];
    let key_err = |key: &str, message: String| sidecar_error(dir, k, key, message);
    if scene.compression.is_some() || scene.model == ModelKind::Compression {
        return Err(Error::Scene {
            file: scene.path.clone(),
            key: "model".into(),
            message: "check reads linear scenes (model = \"fem\" or \"spectral\"); the data format has no compression runs yet".into(),
        });
    }
    if sidecar.dims != scene.dims {
        return Err(Error::Scene {
            file: sidecar_path.clone(),
            key: "dims".into(),
            message: format!(
                "must equal the scene's dims = {} ({}), got {}",
                scene.dims,
                scene.path.display(),
                sidecar.dims
            ),
        });
    }
    if let Some(r) = data.strain_ratio {
        return Err(key_err(
            "strain_ratio",
            format!(
                "is for compression data; scene {} is linear (its data have no strain), got {r}",
                scene.name
            ),
        ));
    }
    require_files(data, dir, k)
}

/// Refuses data run `k` unless every file it lists exists.
fn require_files(data: &DataRun, dir: &Path, k: usize) -> Result<()> {
    for (j, path) in data.paths(dir).iter().enumerate() {
        if !path.is_file() {
            return Err(sidecar_error(
                dir,
                k,
                &format!("files[{j}]"),
                format!(
                    "must name a trajectory file in the data directory; {} is not a file",
                    path.display()
                ),
            ));
        }
    }
    Ok(())
}

/// The mode references of data run `data` in rows of the data, and the factors that
/// turn its aₙ into their units: the producer's discretization's (`discrete`, kept only
/// if a row is a whole number of its steps) or the continuum's; the notes say which.
fn mode_references(
    scene: &Scene,
    data: &DataRun,
    continuum: &HingedBeam,
    discrete: Option<LinearRun>,
    notes: &mut Vec<String>,
) -> (Vec<ModeReference>, Vec<f64>, Option<LinearRun>) {
    let n_modes = scene.sampling.modes.min(data.modes);
    if data.modes < scene.sampling.modes {
        notes.push(format!(
            "run {}: the data carry {} modal amplitudes per component; modes {}..{} of the scene are not checked",
            data.name,
            data.modes,
            data.modes + 1,
            scene.sampling.modes
        ));
    }
    let dts = data.dt_sample;
    // Steps of the discretization per row, if whole.
    let per_row = discrete.as_ref().and_then(|d| {
        let r = dts / d.reference.dt;
        ((r - r.round()).abs() <= MATCH * r.max(1.0)).then(|| r.round())
    });
    let mut modes = Vec::new();
    let mut scale = Vec::new();
    for i in 0..n_modes {
        let n = i + 1;
        let rate_c = continuum.mode_rate(n);
        match (&discrete, per_row) {
            (Some(d), Some(r)) => {
                let mut m = d.reference.modes[i].clone();
                m.multiplier = m.multiplier.powf(r);
                modes.push(m);
                scale.push(d.amplitude_scale[i]);
            }
            _ => {
                let var = continuum.mode_variance(n);
                modes.push(ModeReference {
                    n,
                    variance_discrete: var,
                    variance_equipartition: var,
                    variance_continuum: var,
                    multiplier: (-rate_c * dts).exp(),
                    rate_discrete: Some(rate_c),
                    rate_continuum: rate_c,
                });
                scale.push(1.0);
            }
        }
    }
    if discrete.is_some() && per_row.is_none() {
        notes.push(format!(
            "run {}: dt_sample = {dts} is not a whole number of the discretization's steps: continuum references",
            data.name
        ));
    }
    let discrete = discrete.filter(|_| per_row.is_some());
    if let Some(d) = &discrete {
        let deficits: Vec<String> = d.reference.modes[..n_modes]
            .iter()
            .map(|m| format!("{:+.2e}", m.variance_discrete / m.variance_continuum - 1.0))
            .collect();
        notes.push(format!(
            "run {}: references of the producer's discretization (exact, discrete); expected deficit of its mode variances (mesh, noise, integrator and step) against the continuum, discrete/continuum - 1, modes 1..{n_modes}: {}",
            data.name,
            deficits.join(", ")
        ));
    } else {
        notes.push(format!(
            "run {}: continuum references (eq. 2-4): the producer's discretization and time-step errors are part of what is checked",
            data.name
        ));
    }
    (modes, scale, discrete)
}

/// The column of the data's position `x`, if any.
fn column_of(data: &DataRun, length: f64, x: f64) -> Option<usize> {
    data.positions
        .iter()
        .position(|&p| (p - x).abs() <= MATCH * length)
}

/// The scene's profile points among the data's positions: x, discrete and continuum
/// references, column; the others are noted as not checked.
fn profile_references(
    scene: &Scene,
    data: &DataRun,
    length: f64,
    continuum: &HingedBeam,
    discrete: Option<&LinearRun>,
    notes: &mut Vec<String>,
) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<usize>) {
    // Profile points present in the data.
    let mut profile = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (j, f) in scene.sampling.profile_points.iter().enumerate() {
        let x = f * length;
        match column_of(data, length, x) {
            Some(col) => {
                profile.0.push(x);
                profile.1.push(match discrete {
                    Some(d) => d.reference.profile_discrete[j],
                    None => continuum.profile_variance(x),
                });
                profile.2.push(continuum.profile_variance(x));
                profile.3.push(col);
            }
            None => notes.push(format!(
                "run {}: profile point x/L = {f} is not among the data's positions: not checked",
                data.name
            )),
        }
    }
    profile
}

/// The scene's two-time points on the data's rows and positions, from rest only: the
/// references (with row indices as steps) and the columns of x and y; the others are
/// noted as not checked.
fn two_time_references(
    scene: &Scene,
    data: &DataRun,
    filament: FilamentParams,
    continuum: &HingedBeam,
    discrete: Option<&LinearRun>,
    notes: &mut Vec<String>,
) -> Result<TwoTimeRefs> {
    let (length, tau1, dts) = (filament.length, filament.tau1(), data.dt_sample);
    // Two-time points on the rows, from rest only.
    let mut two_time = Vec::new();
    let mut tt_cols = Vec::new();
    if data.start == Start::Rest {
        for (j, q) in scene.sampling.two_time.iter().enumerate() {
            let (x, y) = (q[0] * length, q[1] * length);
            let (t, eta) = match discrete {
                Some(d) => (d.reference.two_time[j].t, d.reference.two_time[j].eta),
                None => (q[2] * tau1, q[3] * tau1),
            };
            let row = |time: f64| {
                let r = time / dts;
                ((r - r.round()).abs() <= MATCH * r.max(1.0)).then(|| r.round() as u64)
            };
            match (
                column_of(data, length, x),
                column_of(data, length, y),
                row(t),
                row(eta),
            ) {
                (Some(cx), Some(cy), Some(rt), Some(re)) => {
                    two_time.push(TwoTimeReference {
                        x,
                        y,
                        t,
                        eta,
                        t_step: rt,
                        eta_step: re,
                        discrete: match discrete {
                            Some(d) => d.reference.two_time[j].discrete,
                            None => continuum.correlation(x, y, t, eta, 1e-12)?.value,
                        },
                        continuum: continuum.correlation(x, y, t, eta, 1e-12)?.value,
                    });
                    tt_cols.push((cx, cy));
                }
                _ => notes.push(format!(
                    "run {}: two-time point (x/L, y/L, t/tau1, eta/tau1) = ({}, {}, {}, {}) needs the positions among the data's and t, eta on the rows (dt_sample = {dts}): not checked",
                    data.name, q[0], q[1], q[2], q[3]
                )),
            }
        }
    } else if !scene.sampling.two_time.is_empty() {
        notes.push(format!(
            "run {}: the trajectories do not start from rest: the two-time correlation from rest, eq. (4), is not checked",
            data.name
        ));
    }
    Ok((two_time, tt_cols))
}

/// Two-time references and the columns of their x and y.
type TwoTimeRefs = (Vec<TwoTimeReference>, Vec<(usize, usize)>);

/// Reads every file of data run `k` into records and two-time products; refuses
/// trajectories too short for the sparsest checked series.
fn read_records(
    run: &LinearRun,
    sidecar: &DataSidecar,
    dir: &Path,
    k: usize,
    layout: &Layout,
) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let data = &sidecar.runs[k];
    let dts = data.dt_sample;
    let cols = columns(sidecar.dims, data.positions.len(), data.modes);
    let mut records = Vec::new();
    let mut products = Vec::new();
    for path in data.paths(dir) {
        let (rec, tt) = read_record(run, data, &path, &cols, layout)?;
        records.push(rec);
        products.push(tt);
    }
    // The sparsest checked series sets the rows needed.
    if let Some(shortest) = records
        .iter()
        .flat_map(|r| r.modes.iter().chain(&r.profile))
        .map(Vec::len)
        .min()
        && shortest < MIN_SERIES_LEN
    {
        let sparsest = run.mode_every.iter().copied().max().unwrap_or(1);
        return Err(sidecar_error(
            dir,
            k,
            "files",
            format!(
                "each trajectory needs at least {} stationary rows after burn_in = {} (mode 1 is taken every {sparsest} rows of dt_sample = {dts}, {MIN_SERIES_LEN} samples at least), got {}; write longer trajectories",
                sparsest * MIN_SERIES_LEN as u64,
                data.burn_in,
                shortest as u64 * sparsest
            ),
        ));
    }
    Ok((records, products))
}

/// The columns the checks read from a file.
struct Layout {
    n_positions: usize,
    n_modes_data: usize,
    profile_cols: Vec<usize>,
    tt_cols: Vec<(usize, usize)>,
}

/// Reads one trajectory file into the record `verify` would have built: the mode and
/// profile series at their cadences after the burn-in (modal amplitudes in the
/// reference's units), and the two-time products.
fn read_record(
    run: &LinearRun,
    data: &DataRun,
    path: &Path,
    cols: &[String],
    layout: &Layout,
) -> Result<(TrajectoryRecord, Vec<f64>)> {
    let table = read_table(path, cols)?;
    let bad = |what: String| Error::invalid("trajectory file", path.display(), what);
    if table.rows == 0 {
        return Err(bad("at least one row".into()));
    }
    let dts = data.dt_sample;
    let t0 = table.get(0, 0);
    if data.start == Start::Rest && t0.abs() > MATCH * dts {
        return Err(bad(format!(
            "a first row at t = 0 (the sidecar says start = \"rest\"), got t = {t0}"
        )));
    }
    for r in 0..table.rows {
        let t = table.get(r, 0);
        let expected = t0 + r as f64 * dts;
        let off = (t - expected).abs();
        if off.is_nan() || off > MATCH * dts + 1e-12 * expected.abs() {
            return Err(bad(format!(
                "rows every dt_sample = {dts} (row {} should be at t = {expected}, got {t})",
                r + 1
            )));
        }
    }
    let first = ((data.burn_in - t0) / dts - MATCH).ceil().max(0.0) as usize;
    let c = run.components;
    let nm = run.reference.modes.len();
    let np = layout.n_positions;
    let rows_from = |every: u64| (first..table.rows).step_by(every as usize);
    // Column indices: t, w_j, (v_j), aw_n, (av_n).
    let deflection_col = |k: usize, j: usize| 1 + k * np + j;
    let mode_col = |k: usize, i: usize| 1 + c * np + k * layout.n_modes_data + i;
    let mut modes = Vec::with_capacity(c * nm);
    for k in 0..c {
        for i in 0..nm {
            let scale = run.amplitude_scale[i];
            modes.push(
                rows_from(run.mode_every[i])
                    .map(|r| table.get(r, mode_col(k, i)) / scale)
                    .collect(),
            );
        }
    }
    let mut profile = Vec::with_capacity(c * layout.profile_cols.len());
    for k in 0..c {
        for &j in &layout.profile_cols {
            profile.push(
                rows_from(run.profile_every)
                    .map(|r| table.get(r, deflection_col(k, j)))
                    .collect(),
            );
        }
    }
    let tt = &run.reference.two_time;
    let mut two_time = vec![0.0; c * tt.len()];
    for (j, (q, &(cx, cy))) in tt.iter().zip(&layout.tt_cols).enumerate() {
        let (rt, re) = (q.t_step as usize, q.eta_step as usize);
        if re >= table.rows {
            return Err(bad(format!(
                "rows up to t = {} for the two-time point at eta = {} (from rest), got {} rows",
                q.eta, q.eta, table.rows
            )));
        }
        for k in 0..c {
            two_time[k * tt.len() + j] =
                table.get(rt, deflection_col(k, cx)) * table.get(re, deflection_col(k, cy));
        }
    }
    let record = TrajectoryRecord {
        modes,
        profile,
        two_time: two_time.clone(),
        slope_squares: Vec::new(),
        slope_samples: 0,
    };
    Ok((record, two_time))
}

/// The run specification the checks of data run `data` take from `scene`: the scene's
/// run of the same name if there is one (its own check list), else the first run with
/// the scene's checks; named after the data run.
fn data_spec(scene: &Scene, data: &DataRun) -> RunSpec {
    let mut spec = scene
        .runs
        .iter()
        .find(|r| r.name == data.name)
        .cloned()
        .unwrap_or_else(|| RunSpec {
            checks: None,
            ..scene.runs[0].clone()
        });
    spec.name = data.name.clone();
    spec
}

/// The producer's discretization as a run of this tool, when it is one it models
/// (`fem` with elements, integrator, noise and dt; `spectral` with modes and dt): the
/// run prepared on the data's filament, whose exact discrete references serve as the
/// data's. `None` (with a note) otherwise.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar key of a known model given with an unknown
/// integrator or noise name; the preparation's errors.
fn discrete_run(
    scene: &Scene,
    filament: FilamentParams,
    data: &DataRun,
    notes: &mut Vec<String>,
) -> Result<Option<LinearRun>> {
    let Some(d) = &data.discretization else {
        return Ok(None);
    };
    let model = match d.model.as_str() {
        "fem" => ModelKind::Fem,
        "spectral" => ModelKind::Spectral,
        other => {
            notes.push(format!(
                "run {}: the producer's discretization ({other}) is not one this tool models",
                data.name
            ));
            return Ok(None);
        }
    };
    let (Some(elements), Some(dt)) = (d.elements, d.dt) else {
        notes.push(format!(
            "run {}: the discretization gives no elements or dt: continuum references",
            data.name
        ));
        return Ok(None);
    };
    let name_of = |v: &Option<String>, default: &str| v.clone().unwrap_or(default.into());
    let integrator: IntegratorKind = parse_name(&name_of(&d.integrator, "exact-modal"))
        .ok_or_else(|| discretization_error(data, "integrator", d))?;
    let noise: NoiseModel = parse_name(&name_of(&d.noise, "consistent"))
        .ok_or_else(|| discretization_error(data, "noise", d))?;
    let mut scene = scene.clone();
    scene.filament = FilamentParams {
        stretch_rigidity: scene.filament.stretch_rigidity,
        ..filament
    };
    scene.model = model;
    scene.mesh.elements = elements;
    scene.mesh.grading = 1.0;
    let spec = RunSpec {
        integrator,
        noise,
        dt_tau1: dt / filament.tau1(),
        ..data_spec(&scene, data)
    };
    LinearRun::prepare(&scene, &spec).map(Some)
}

/// A name as the scene files spell it (`crank-nicolson`), parsed by serde.
fn parse_name<T: serde::de::DeserializeOwned>(name: &str) -> Option<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string())).ok()
}

/// An unknown integrator or noise name in a discretization.
fn discretization_error(data: &DataRun, key: &str, d: &Discretization) -> Error {
    Error::invalid(
        format!("discretization.{key} of data run {}", data.name),
        format!("{d:?}"),
        "an integrator (euler-maruyama, backward-euler, crank-nicolson, exact-modal) and noise (consistent, element-uniform) as in scene files",
    )
}

/// The compression data of one run name: every strain of the scene, the exact theory
/// it is judged against and the force records read from the files.
pub struct CompressionDataCheck {
    /// The run (prepared on the data's filament and discretization, for the checks).
    pub run: CompressionRun,
    /// The exact theory (discrete: the producer's discretization when it is this tool's
    /// finite elements; otherwise the continuum in both columns).
    pub theory: CompressionTheoryTable,
    /// Per strain of the scene, per trajectory, F/F_c0 after the burn-in.
    pub records: Vec<Vec<ForceRecord>>,
    /// What a reader should know.
    pub notes: Vec<String>,
}

/// Prepares the force checks of compression data: one [`CompressionDataCheck`] per run
/// name of the sidecar, each holding one data run per strain of the scene.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar key when a strain of the scene has no data, a
/// data run has no strain, or EA is missing; file errors as [`read_table`]; the
/// preparation's and the theory's errors.
pub fn prepare_compression_checks(
    scene: &Scene,
    sidecar: &DataSidecar,
    dir: &Path,
) -> Result<Vec<CompressionDataCheck>> {
    let sidecar_path = dir.join(crate::data::SIDECAR);
    let bad = |key: String, message: String| Error::Scene {
        file: sidecar_path.clone(),
        key,
        message,
    };
    let Some(comp) = &scene.compression else {
        return Err(bad(
            "runs".into(),
            "compression data need a compression scene".into(),
        ));
    };
    if sidecar.dims != scene.dims {
        return Err(bad(
            "dims".into(),
            format!(
                "must equal the scene's dims = {}, got {}",
                scene.dims, sidecar.dims
            ),
        ));
    }
    if sidecar.filament.stretch_rigidity.is_none() {
        return Err(bad(
            "filament.stretch_rigidity".into(),
            "must be given for compression data (EA: the force-strain law depends on it)".into(),
        ));
    }
    if let Some(k) = sidecar.runs.iter().position(|r| r.strain_ratio.is_none()) {
        return Err(bad(
            format!("runs[{k}].strain_ratio"),
            format!("must be given: scene {} is a compression scene", scene.name),
        ));
    }
    let mut names: Vec<&str> = Vec::new();
    for r in &sidecar.runs {
        if !names.contains(&r.name.as_str()) {
            names.push(&r.name);
        }
    }
    names
        .into_iter()
        .map(|name| compression_data_check(scene, comp, sidecar, dir, name))
        .collect()
}

/// The [`CompressionDataCheck`] of the data runs named `name`: one per strain of the
/// scene (refused if one is missing), judged against the discrete theory of the
/// producer's finite elements or the continuum.
fn compression_data_check(
    scene: &Scene,
    comp: &CompressionSpec,
    sidecar: &DataSidecar,
    dir: &Path,
    name: &str,
) -> Result<CompressionDataCheck> {
    let sidecar_path = dir.join(crate::data::SIDECAR);
    let bad = |key: String, message: String| Error::Scene {
        file: sidecar_path.clone(),
        key,
        message,
    };
    let runs: Vec<(usize, &DataRun)> = sidecar
        .runs
        .iter()
        .enumerate()
        .filter(|(_, r)| r.name == name)
        .collect();
    let mut notes = Vec::new();
    let mut by_strain = Vec::new();
    for &ratio in &comp.strain_ratios {
        let found = runs.iter().find(|(_, r)| {
            r.strain_ratio
                .is_some_and(|s| (s - ratio).abs() <= MATCH * ratio.abs().max(1.0))
        });
        match found {
            Some(&(k, r)) => by_strain.push((k, r)),
            None => {
                return Err(bad(
                    "runs".into(),
                    format!(
                        "must hold run {name:?} at every strain ratio of scene {} ({:?}); strain_ratio {ratio} is missing",
                        scene.name, comp.strain_ratios
                    ),
                ));
            }
        }
    }
    let first = by_strain[0].1;
    let mut scene = scene.clone();
    scene.filament = sidecar.filament.params();
    let fem = first
        .discretization
        .as_ref()
        .filter(|d| d.model == "fem")
        .and_then(|d| d.elements);
    if let Some(elements) = fem {
        scene.mesh.elements = elements;
        scene.mesh.grading = 1.0;
    }
    let spec = data_spec(&scene, first);
    let run = CompressionRun::prepare(&scene, comp, &spec)?;
    let mut theory = CompressionTheoryTable::new(&scene, comp)?;
    match fem {
        Some(e) => notes.push(format!(
            "run {name}: references: the exact equilibrium theory of the producer's discretization ({e} elements) at every strain; the continuum beside it"
        )),
        None => {
            theory.discrete.clone_from(&theory.continuum);
            for c in &mut theory.curve {
                c.1 = c.2;
            }
            theory.distributions.iter_mut().for_each(|d| *d = None);
            notes.push(format!(
                "run {name}: references: the continuum theory (the producer's discretization is not this tool's finite elements); the distribution of F is not checked (its exact law is known for the discretized filament only)"
            ));
        }
    }
    let records = read_force_records(dir, &sidecar_path, &by_strain, run.euler_load)?;
    Ok(CompressionDataCheck {
        run,
        theory,
        records,
        notes,
    })
}

/// F/F_c0 of every trajectory file of the data runs `by_strain` (index in the sidecar,
/// run), from the first row at or after each run's burn-in.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar key of a listed file that is not a file; the
/// table reader's errors.
fn read_force_records(
    dir: &Path,
    sidecar_path: &Path,
    by_strain: &[(usize, &DataRun)],
    euler_load: f64,
) -> Result<Vec<Vec<ForceRecord>>> {
    let cols: Vec<String> = crate::data::COMPRESSION_COLUMNS
        .iter()
        .map(|c| c.to_string())
        .collect();
    let mut records = Vec::new();
    for &(k, data) in by_strain {
        let mut at_strain = Vec::new();
        for (j, path) in data.paths(dir).iter().enumerate() {
            if !path.is_file() {
                return Err(Error::Scene {
                    file: sidecar_path.to_path_buf(),
                    key: format!("runs[{k}].files[{j}]"),
                    message: format!(
                        "must name a trajectory file; {} is not a file",
                        path.display()
                    ),
                });
            }
            let table = read_table(path, &cols)?;
            let t0 = if table.rows > 0 { table.get(0, 0) } else { 0.0 };
            let first_row = ((data.burn_in - t0) / data.dt_sample - MATCH)
                .ceil()
                .max(0.0) as usize;
            at_strain.push(ForceRecord {
                force_ratio: (first_row..table.rows)
                    .map(|r| table.get(r, 1) / euler_load)
                    .collect(),
                ..ForceRecord::default()
            });
        }
        records.push(at_strain);
    }
    Ok(records)
}
