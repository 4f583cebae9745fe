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

use crate::data::{
    DataObject, DataRun, DataSidecar, MAX_STEPS_PER_ROW, Start, Table, filament_extra_columns,
    read_table,
};
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::input::{human_bytes, open_regular, refused};
use crate::params::FilamentParams;
use crate::scene::compression::{CompressionRun, CompressionTheoryTable, ForceRecord};
use crate::scene::linear::{
    Continuum, LinearReference, LinearRun, ModeReference, RigidReference, TangentReference,
    TrajectoryRecord, TwoTimeReference, rigid_coordinates,
};
use crate::scene::validate::membrane_mesh_violation;
use crate::scene::{CheckKind, CompressionSpec, MeshScheme, ModelKind, RunSpec, Scene};
use crate::stats::moments::MIN_SERIES_LEN;
use crate::theory::DomainInput;
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
    /// Whether every reference is the continuum's (the producer's discretization is not
    /// one this tool models, or not declared): the run's checks then say
    /// `reference_kind = "continuum"`.
    pub continuum_references: bool,
}

/// Relative tolerance on a time or position of the data matching a scene's.
const MATCH: f64 = 1e-6;

/// Prepares the checks of data run `k` of `sidecar` (read from `dir`) against `scene`,
/// reading each trajectory file as a regular file of at most `max_bytes`.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar (or scene) key when the data cannot serve the
/// scene's checks (another data kind, too few rows for the slowest checked series, a
/// discretization this tool cannot build), and naming a trajectory file and its key
/// `runs[k].files[j]` when it does not hold what the sidecar says (see the [data
/// format](crate::data#what-is-refused)).
pub fn prepare_data_check(
    scene: &Scene,
    sidecar: &DataSidecar,
    dir: &Path,
    k: usize,
    max_bytes: u64,
) -> Result<DataCheck> {
    check_linear_data(scene, sidecar, dir, k)?;
    let data = &sidecar.runs[k];
    let object = data_object(sidecar, dir)?;
    let data_scene = data_scene(scene, &object, dir)?;
    let continuum = Continuum::of(&data_scene)?;
    // The scene's τ₁ with the data's parameters: the unit of the scene's times (dt_tau1,
    // two-time points), that of the ends' slowest elastic mode for other ends than hinges.
    let tau1 = data_scene.tau1();
    let mut notes = Vec::new();
    let discrete = discrete_run(&data_scene, tau1, (dir, k), data, &mut notes)?;
    let spec = data_spec(scene, data);
    let (modes, scale, discrete) = mode_references(scene, data, &continuum, discrete, &mut notes);
    let continuum_references = discrete.is_none();
    let d = discrete.as_ref();
    let profile = profile_references(scene, data, &continuum, d, &mut notes)?;
    let (two_time, tt_cols) = two_time_references(scene, data, tau1, &continuum, d, &mut notes)?;
    let rigid = rigid_data_references(&data_scene, data, d);
    let tangent = tangent_data_references(&data_scene, (data, &spec), &continuum, d, &mut notes);
    let dts = data.dt_sample;
    let every = |rate: f64| crate::scene::linear::sample_every(rate, dts);
    let mode_every: Vec<u64> = modes
        .iter()
        .map(|m| every(m.rate_discrete.unwrap_or(m.rate_continuum)))
        .collect();
    let rate1 = continuum.mode_rate(1);
    let profile_every = every(4.0 * rate1);
    let max_rate = modes.last().map_or(rate1, |m| m.rate_continuum);
    let components = scene.components();
    let reference = LinearReference {
        modes,
        profile_x: profile.x,
        profile_discrete: profile.discrete,
        profile_terms: profile.terms,
        profile_continuum: profile.continuum,
        two_time,
        dt: dts,
        max_rate,
        rigid,
        tangent,
    };
    let run = LinearRun::for_data(
        spec,
        components,
        reference,
        mode_every,
        profile_every,
        scale,
    );
    let rigid_suffixes: Vec<&str> = if data.rigid {
        rigid_coordinates(&data_scene.filament, data_scene.ends)
            .iter()
            .map(|r| r.1)
            .collect()
    } else {
        Vec::new()
    };
    let layout = Layout {
        n_positions: data.positions.len(),
        n_modes_data: data.modes,
        n_rigid_data: rigid_suffixes.len(),
        n_tangent_data: data.tangent_modes,
        profile_cols: profile.columns,
        tt_cols,
    };
    let mut columns = object.columns(sidecar.dims, data.positions.len(), data.modes)?;
    columns.extend(filament_extra_columns(
        sidecar.dims,
        &rigid_suffixes,
        data.tangent_modes,
    ));
    let (records, products) = read_records(&run, (data, &columns), dir, k, &layout, max_bytes)?;
    Ok(DataCheck {
        run,
        records,
        two_time: products,
        notes,
        continuum_references,
    })
}

/// `scene` with the data's object: a filament's parameters (the scene's EA kept), or a
/// membrane's, which must share the scene's boundary (the references are the scene's
/// modes).
///
/// # Errors
/// [`Error::Scene`] naming the sidecar's `membrane.boundary` if it is not the scene's.
fn data_scene(scene: &Scene, object: &DataObject, dir: &Path) -> Result<Scene> {
    let mut data_scene = scene.clone();
    match object {
        DataObject::Filament(f) => {
            data_scene.filament = FilamentParams {
                stretch_rigidity: scene.filament.stretch_rigidity,
                ..f.params()
            }
        }
        DataObject::Membrane(m) => {
            if let Some(sm) = &scene.membrane
                && sm.boundary != m.boundary
            {
                return Err(refused(
                    &dir.join(crate::data::SIDECAR),
                    "membrane.boundary",
                    format!(
                        "is {}, but scene {} is {}: check data against a scene of their boundary",
                        m.boundary.name(),
                        scene.name,
                        sm.boundary.name()
                    ),
                ));
            }
            data_scene.membrane = Some(m.params())
        }
    }
    Ok(data_scene)
}

/// The object of a loaded sidecar (in `dir`).
fn data_object(sidecar: &DataSidecar, dir: &Path) -> Result<DataObject> {
    sidecar.object().ok_or_else(|| {
        refused(
            &dir.join(crate::data::SIDECAR),
            "filament",
            "exactly one of filament and membrane must be given",
        )
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

/// Whether `scene` is a compression scene (its data are compression runs).
fn is_compression(scene: &Scene) -> bool {
    scene.compression.is_some() || scene.model == ModelKind::Compression
}

/// Refuses data of the other kind than `scene`'s, first, saying so: linear runs (no
/// `strain_ratio`) against a compression scene, or compression runs (every run with a
/// `strain_ratio`) against a linear scene. Data mixing both kinds are refused later,
/// naming the first run of the wrong kind.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar in `dir`, key `runs`.
pub fn check_data_kind(scene: &Scene, sidecar: &DataSidecar, dir: &Path) -> Result<()> {
    let strained = sidecar
        .runs
        .iter()
        .filter(|r| r.strain_ratio.is_some())
        .count();
    let first_strained = sidecar.runs.iter().position(|r| r.strain_ratio.is_some());
    let (key, message) = match first_strained {
        None if is_compression(scene) => (
            "runs".to_string(),
            format!(
                "the data are linear runs (no strain_ratio) but scene {} ({}) is a compression scene: check them with a linear scene, or give strain_ratio per run",
                scene.name,
                scene.path.display()
            ),
        ),
        Some(k) if !is_compression(scene) && strained == sidecar.runs.len() => (
            format!("runs[{k}].strain_ratio"),
            format!(
                "= {} marks compression data (every run has a strain_ratio) but scene {} ({}) is a linear scene: check them with a compression scene, or leave strain_ratio out of linear runs",
                sidecar.runs[k].strain_ratio.unwrap_or(f64::NAN),
                scene.name,
                scene.path.display()
            ),
        ),
        _ => return object_kind(scene, sidecar, dir),
    };
    Err(refused(&dir.join(crate::data::SIDECAR), &key, message))
}

/// Refuses data of the other object than `scene`'s: a membrane's data against a filament
/// scene, or a filament's against a membrane scene.
fn object_kind(scene: &Scene, sidecar: &DataSidecar, dir: &Path) -> Result<()> {
    let (given, needed) = match (scene.is_membrane(), sidecar.membrane.is_some()) {
        (true, false) => ("filament", "membrane"),
        (false, true) => ("membrane", "filament"),
        _ => return Ok(()),
    };
    Err(refused(
        &dir.join(crate::data::SIDECAR),
        given,
        format!(
            "the data are of a {given} but scene {} ({}) is a {needed} scene: check them with a {given} scene (e.g. {}), or give the {needed}'s data",
            scene.name,
            scene.path.display(),
            if given == "membrane" {
                "membrane-hinged"
            } else {
                "hinged-linear-2d"
            }
        ),
    ))
}

/// The filament of compression data (`check_data_kind` has refused a membrane's).
fn data_filament(sidecar: &DataSidecar, dir: &Path) -> Result<crate::data::DataFilament> {
    sidecar.filament.ok_or_else(|| {
        refused(
            &dir.join(crate::data::SIDECAR),
            "filament",
            "must be given for compression data",
        )
    })
}

/// Refuses compression data whose filament (`data.json`'s, `f`) puts the scene's strains
/// `strain_ratios` outside the exact theory's domain ([`crate::theory::domain_violation`]),
/// naming the sidecar's key, before any reference is computed.
fn data_theory_domain(f: &FilamentParams, strain_ratios: &[f64], dir: &Path) -> Result<()> {
    let (p, s) = (f.persistence_ratio(), f.stretch_ratio());
    let Some((input, allowed)) = crate::theory::domain_violation(p, s, strain_ratios) else {
        return Ok(());
    };
    let (key, message) = match input {
        DomainInput::BendingRigidity => (
            "filament.bending_rigidity",
            format!("must be {allowed}, got {:e}", f.bending_rigidity),
        ),
        DomainInput::StretchRigidity => (
            "filament.stretch_rigidity",
            format!("must be {allowed}, got {:e}", f.stretch_rigidity),
        ),
        DomainInput::StrainRatio(i) => (
            "filament",
            format!(
                "puts the scene's strain ratio {} outside the exact theory's domain: it must be {allowed}",
                strain_ratios[i]
            ),
        ),
    };
    Err(refused(&dir.join(crate::data::SIDECAR), key, message))
}

/// Refuses the trajectory files of `sidecar` (in `dir`) unless each is a regular file
/// and together they hold at most `max_bytes` (the memory cap of `check`): nothing is
/// read above it.
///
/// # Errors
/// [`Error::Scene`] naming a file that is missing or not a regular file and its key
/// `runs[k].files[j]`, or the data directory, the total and the cap.
pub fn require_data_size(sidecar: &DataSidecar, dir: &Path, max_bytes: u64) -> Result<()> {
    let mut total: u64 = 0;
    let mut files = 0usize;
    let mut seen = std::collections::HashMap::new();
    for (k, run) in sidecar.runs.iter().enumerate() {
        for (j, path) in run.paths(dir).iter().enumerate() {
            let key = format!("runs[{k}].files[{j}]");
            let (file, len) = open_regular(path, &key).map_err(|e| match e {
                // Named from the sidecar that lists the file, with why it cannot be read.
                Error::Scene { message, .. } => refused(
                    &dir.join(crate::data::SIDECAR),
                    &key,
                    format!("names {}, which {message}", path.display()),
                ),
                other => other,
            })?;
            // One file reached by two names (a symbolic or hard link) is one trajectory.
            if let Some(first) = file_identity(&file).and_then(|id| seen.insert(id, key.clone())) {
                return Err(refused(
                    &dir.join(crate::data::SIDECAR),
                    &key,
                    format!(
                        "names {}, the same file as {first} (through a link): each file is one trajectory and may be listed once",
                        path.display()
                    ),
                ));
            }
            total = total.saturating_add(len);
            files += 1;
        }
    }
    if total > max_bytes {
        return Err(refused(
            dir,
            "runs[*].files",
            format!(
                "the {files} trajectory files hold {total} bytes ({}), more than the {max_bytes} bytes ({}) a check may read: raise --max-memory-gib deliberately on a larger machine, or check fewer or shorter trajectories",
                human_bytes(total),
                human_bytes(max_bytes)
            ),
        ));
    }
    Ok(())
}

/// The device and inode of an open file (Unix), which two names of one file share.
fn file_identity(file: &std::fs::File) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        file.metadata().ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        None
    }
}

/// Refuses data run `k` unless `scene` is linear, the dimensions agree and the run has
/// no strain.
fn check_linear_data(scene: &Scene, sidecar: &DataSidecar, dir: &Path, k: usize) -> Result<()> {
    let sidecar_path = dir.join(crate::data::SIDECAR);
    let data = &sidecar.runs[k];
    let key_err = |key: &str, message: String| sidecar_error(dir, k, key, message);
    check_data_kind(scene, sidecar, dir)?;
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
    let filament = !scene.is_membrane();
    if data.rigid && !(filament && scene.ends.rigid_modes() > 0) {
        return Err(key_err(
            "rigid",
            format!(
                "is true, but scene {} has no rigid modes (its ends are {}): give rigid coordinates only for a filament with a free end and no clamp",
                scene.name,
                if filament {
                    scene.ends.to_string()
                } else {
                    "a membrane's".into()
                }
            ),
        ));
    }
    if data.tangent_modes > 0
        && [scene.ends.left, scene.ends.right].contains(&crate::params::End::Clamped)
    {
        return Err(key_err(
            "tangent_modes",
            format!(
                "is {}, but scene {} has a clamped end ({}): the tangent-angle cosines diagonalize the bending energy only where both ends leave the angle free; give 0 (leave the key out)",
                data.tangent_modes, scene.name, scene.ends
            ),
        ));
    }
    Ok(())
}

/// The mode references of data run `data` in rows of the data, and the factors that
/// turn its aₙ into their units: the producer's discretization's (`discrete`, kept only
/// if a row is a whole number of its steps) or the continuum's; the notes say which.
fn mode_references(
    scene: &Scene,
    data: &DataRun,
    continuum: &Continuum,
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
                    label: continuum.mode_label(n),
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
            "run {}: references of the producer's discretization (exact, discrete); expected difference of its mode variances (mesh, noise, integrator and step) from the continuum, discrete/continuum - 1, modes 1..{n_modes}: {}",
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

/// The rigid modes' laws of data run `data` (none unless its files carry the rigid
/// coordinates, sidecar `rigid`), in `r = ψᵀCw` units: the producer's discretization's
/// (`discrete`) or the continuum's (a random walk of diffusivity 2kT, the centre of mass
/// `2kT/(ξL)` and the angle `2kT/(ξI)` in physical units).
fn rigid_data_references(
    scene: &Scene,
    data: &DataRun,
    discrete: Option<&LinearRun>,
) -> Vec<RigidReference> {
    if !data.rigid {
        return Vec::new();
    }
    let kt = scene.filament.kt;
    rigid_coordinates(&scene.filament, scene.ends)
        .into_iter()
        .enumerate()
        .map(|(k, (name, coordinate, coordinate_scale))| {
            match discrete.and_then(|d| d.reference.rigid.get(k)) {
                Some(r) => r.clone(),
                None => RigidReference {
                    name: name.to_string(),
                    diffusion_discrete: 2.0 * kt,
                    diffusion_continuum: 2.0 * kt,
                    simulated: true,
                    coordinate,
                    coordinate_scale,
                },
            }
        })
        .collect()
}

/// The tangent-angle laws of data run `data` (run `spec` of the scene) when the run
/// checks `tangent-angle`: for its first `min(tangent_modes, sampling.modes)` cosines, the
/// producer's discretization's (`discrete`, its autocorrelation per row of the data) or
/// the continuum's variance kT L²/(EI n²π²) with the bound e^{−λ₁t} on the
/// autocorrelation; notes for cosines the data do not carry.
fn tangent_data_references(
    scene: &Scene,
    (data, spec): (&DataRun, &RunSpec),
    continuum: &Continuum,
    discrete: Option<&LinearRun>,
    notes: &mut Vec<String>,
) -> Vec<TangentReference> {
    if !spec.checks(scene).contains(&CheckKind::TangentAngle) {
        return Vec::new();
    }
    let wanted = scene.sampling.modes;
    let count = wanted.min(data.tangent_modes);
    if count < wanted {
        notes.push(format!(
            "run {}: the data carry {} tangent-angle amplitudes per component (sidecar tangent_modes); cosines {}..{wanted} of the scene are not checked",
            data.name,
            data.tangent_modes,
            count + 1
        ));
    }
    let dts = data.dt_sample;
    let per_row = discrete.map(|d| (dts / d.reference.dt).round());
    match (discrete, per_row) {
        (Some(d), Some(r)) if d.reference.tangent.len() >= count => d.reference.tangent[..count]
            .iter()
            .map(|t| TangentReference {
                terms: t.terms.iter().map(|&(u, m)| (u, m.powf(r))).collect(),
                ..t.clone()
            })
            .collect(),
        _ => {
            let p = &scene.filament;
            let decay = (-continuum.mode_rate(1) * dts).exp();
            (1..=count)
                .map(|n| {
                    let q = n as f64 * std::f64::consts::PI / p.length;
                    let v = p.kt / (p.bending_rigidity * q * q);
                    TangentReference {
                        n,
                        variance_discrete: v,
                        variance_continuum: v,
                        terms: vec![(1.0, decay)],
                    }
                })
                .collect()
        }
    }
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
    continuum: &Continuum,
    discrete: Option<&LinearRun>,
    notes: &mut Vec<String>,
) -> Result<ProfileRefs> {
    let length = continuum.line_length();
    // Profile points present in the data.
    let mut profile = ProfileRefs::default();
    for (j, f) in scene.sampling.profile_points.iter().enumerate() {
        let x = f * length;
        let Some(col) = column_of(data, length, x) else {
            notes.push(format!(
                "run {}: profile point x/L = {f} is not among the data's positions: not checked",
                data.name
            ));
            continue;
        };
        let exact = continuum.profile_variance(x)?;
        let (reference, terms) = match discrete {
            Some(d) => {
                // The discrete terms are per step of the discrete run; a data row is
                // `per_row` steps.
                let per_row = (data.dt_sample / d.reference.dt).round();
                let terms = d.reference.profile_terms[j]
                    .iter()
                    .map(|&(u, m)| (u, m.powf(per_row)))
                    .collect();
                (d.reference.profile_discrete[j], terms)
            }
            None => (exact, Vec::new()),
        };
        profile.x.push(x);
        profile.discrete.push(reference);
        profile.continuum.push(exact);
        profile.columns.push(col);
        profile.terms.push(terms);
    }
    Ok(profile)
}

/// The profile points found among the data's positions, one entry each.
#[derive(Default)]
struct ProfileRefs {
    /// x.
    x: Vec<f64>,
    /// The reference: discrete where the discretization is known, else the continuum's.
    discrete: Vec<f64>,
    /// The continuum's ⟨w²(x)⟩.
    continuum: Vec<f64>,
    /// The data's column.
    columns: Vec<usize>,
    /// The discrete autocovariance terms per data row (empty without a discrete
    /// reference).
    terms: Vec<Vec<(f64, f64)>>,
}

/// The scene's two-time points on the data's rows and positions, from rest only: the
/// references (with row indices as steps) and the columns of x and y; the others are
/// noted as not checked.
fn two_time_references(
    scene: &Scene,
    data: &DataRun,
    tau1: f64,
    continuum: &Continuum,
    discrete: Option<&LinearRun>,
    notes: &mut Vec<String>,
) -> Result<TwoTimeRefs> {
    let (length, dts) = (continuum.line_length(), data.dt_sample);
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
                ((r - r.round()).abs() <= MATCH * r.max(1.0))
                    .then(|| r.round())
                    .and_then(row_index)
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
                            None => continuum.correlation(x, y, t, eta)?,
                        },
                        variances: discrete
                            .map_or((f64::NAN, f64::NAN), |d| d.reference.two_time[j].variances),
                        continuum: continuum.correlation(x, y, t, eta)?,
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

/// A row index `r` (a whole number ≥ 0) as a count, if it is one that a table can
/// have (at most 2⁵³, where every whole number is an `f64`).
fn row_index(r: f64) -> Option<u64> {
    (r.is_finite() && (0.0..=9.007_199_254_740_992e15).contains(&r)).then_some(r as u64)
}

/// The first row of a trajectory starting at `t0` at or after the burn-in of `data`
/// (`usize::MAX` if the burn-in is beyond any row a file can hold).
fn first_row(data: &DataRun, t0: f64) -> usize {
    let r = ((data.burn_in - t0) / data.dt_sample - MATCH)
        .ceil()
        .max(0.0);
    row_index(r).map_or(usize::MAX, |r| usize::try_from(r).unwrap_or(usize::MAX))
}

/// Reads trajectory file `path` of data run `data` (key `key` of the sidecar, at most
/// `max_bytes`) with its `columns`, and checks its time column, every kind of data
/// alike: the first row at t = 0 if the run starts from rest, and row `r` at
/// `t₀ + r·dt_sample` within a relative 1e-6 of `dt_sample`.
///
/// # Errors
/// [`read_table`]'s; [`Error::Scene`] naming the file, the key, the data row (from 1),
/// the expected and the actual t.
fn read_trajectory(
    data: &DataRun,
    path: &Path,
    key: &str,
    columns: &[String],
    max_bytes: u64,
) -> Result<Table> {
    let table = read_table(path, key, columns, max_bytes)?;
    let bad = |what: String| refused(path, key, what);
    let dts = data.dt_sample;
    let t0 = table.get(0, 0);
    if data.start == Start::Rest && t0.abs() > MATCH * dts {
        return Err(bad(format!(
            "column \"t\", data row 1: must be t = 0 (the sidecar says start = \"rest\"), got t = {t0:?}"
        )));
    }
    for r in 0..table.rows {
        let t = table.get(r, 0);
        let expected = t0 + r as f64 * dts;
        let off = (t - expected).abs();
        if off.is_nan() || off > MATCH * dts + 1e-12 * expected.abs() {
            return Err(bad(format!(
                "column \"t\", data row {}: must be t = {expected:?} (rows every dt_sample = {dts:?} from t = {t0:?}), got t = {t:?}",
                r + 1
            )));
        }
    }
    Ok(table)
}

/// The largest magnitude of a value the checks use, in their units (deflections in the
/// filament's length unit, modal amplitudes in the reference's, forces in F_c0): the
/// fourth powers (the variance of a variance estimate sums them) and their sums over a
/// billion samples stay far from overflow (10²⁴⁰·10⁹). Larger finite values are no
/// physical data (a filament is at most 1e30 long), and would make an estimator fail as
/// if the data were too few (at 1e99 a pooled variance's standard error was infinite).
const MAX_MAGNITUDE: f64 = 1e60;

/// Refuses column `col` of `table` (file `path`, key `key`) if a value of it times
/// `factor` (the change to the checks' units) exceeds [`MAX_MAGNITUDE`], naming the
/// column, the data row and the value.
fn require_magnitude(
    table: &Table,
    (path, key): (&Path, &str),
    col: usize,
    factor: f64,
) -> Result<()> {
    let limit = MAX_MAGNITUDE / factor.abs();
    match (0..table.rows).find(|&r| table.get(r, col).abs() > limit) {
        None => Ok(()),
        Some(r) => Err(refused(
            path,
            key,
            format!(
                "column {:?}, data row {}: must be at most {limit:e} in magnitude (the checks sum its squares and fourth powers, which must stay finite), got {:?}",
                table.columns[col],
                r + 1,
                table.get(r, col)
            ),
        )),
    }
}

/// Reads every file of data run `k` (in `dir`, each of at most `max_bytes`) into
/// records and two-time products; refuses trajectories too short for the sparsest
/// checked series.
fn read_records(
    run: &LinearRun,
    (data, cols): (&DataRun, &[String]),
    dir: &Path,
    k: usize,
    layout: &Layout,
    max_bytes: u64,
) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let dts = data.dt_sample;
    let mut records = Vec::new();
    let mut products = Vec::new();
    let paths = data.paths(dir);
    // the fewest rows a file has after the burn-in
    let mut stationary = usize::MAX;
    for (j, path) in paths.iter().enumerate() {
        let key = format!("runs[{k}].files[{j}]");
        let table = read_trajectory(data, path, &key, cols, max_bytes)?;
        let first = first_row(data, table.get(0, 0));
        stationary = stationary.min(table.rows.saturating_sub(first));
        let (rec, tt) = read_record(run, data, (path, &key), &table, layout)?;
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
                "each trajectory needs at least {} stationary rows after burn_in = {:?} (mode 1 is taken every {sparsest} rows of dt_sample = {dts:?}, {MIN_SERIES_LEN} samples at least), got {stationary} (a series of {shortest}); write longer trajectories",
                sparsest.saturating_mul(MIN_SERIES_LEN as u64),
                data.burn_in,
            ),
        ));
    }
    // Trajectories are independent draws: two with the same checked series (a simulator
    // that reused its seed) are no ensemble, and would give a zero spread.
    let mut signatures = std::collections::HashMap::new();
    for (j, rec) in records.iter().enumerate() {
        if let Some(i) = signatures.insert(signature(rec), j) {
            let earlier = &records[i];
            if earlier.modes == rec.modes && earlier.profile == rec.profile {
                return Err(sidecar_error(
                    dir,
                    k,
                    &format!("files[{j}]"),
                    format!(
                        "names {}, whose checked series are those of runs[{k}].files[{i}], number for number: the trajectories of a run must be independent (a simulator that reused one seed?)",
                        paths[j].display()
                    ),
                ));
            }
        }
    }
    Ok((records, products))
}

/// A hash of the modal and profile series of a trajectory (their bits), to find two
/// identical trajectories without comparing every pair.
fn signature(rec: &TrajectoryRecord) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for s in rec.modes.iter().chain(&rec.profile) {
        s.len().hash(&mut h);
        s.iter().for_each(|v| v.to_bits().hash(&mut h));
    }
    h.finish()
}

/// The columns the checks read from a file.
struct Layout {
    n_positions: usize,
    n_modes_data: usize,
    /// Rigid coordinates per component in the files.
    n_rigid_data: usize,
    /// Tangent-angle amplitudes per component in the files.
    n_tangent_data: usize,
    profile_cols: Vec<usize>,
    tt_cols: Vec<(usize, usize)>,
}

/// Turns the trajectory `table` (read from file `path`, sidecar key `key`) into the
/// record `verify` would have built: the mode and profile series at their cadences
/// after the burn-in (modal amplitudes in the reference's units), and the two-time
/// products.
fn read_record(
    run: &LinearRun,
    data: &DataRun,
    (path, key): (&Path, &str),
    table: &Table,
    layout: &Layout,
) -> Result<(TrajectoryRecord, Vec<f64>)> {
    let first = first_row(data, table.get(0, 0));
    let c = run.components;
    let nm = run.reference.modes.len();
    let np = layout.n_positions;
    let rows_from = |every: u64| {
        (first.min(table.rows)..table.rows).step_by(usize::try_from(every).unwrap_or(usize::MAX))
    };
    // Column indices: t, w_j, (v_j), aw_n, (av_n).
    let deflection_col = |k: usize, j: usize| 1 + k * np + j;
    let mode_col = |k: usize, i: usize| 1 + c * np + k * layout.n_modes_data + i;
    let used = layout.tt_cols.iter().flat_map(|&(x, y)| [x, y]);
    for j in layout.profile_cols.iter().copied().chain(used) {
        for k in 0..c {
            require_magnitude(table, (path, key), deflection_col(k, j), 1.0)?;
        }
    }
    for i in 0..nm {
        for k in 0..c {
            let factor = 1.0 / run.amplitude_scale[i];
            require_magnitude(table, (path, key), mode_col(k, i), factor)?;
        }
    }
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
    // After the modal amplitudes: the rigid coordinates, then the tangent-angle
    // amplitudes, each component by component.
    let extra = 1 + c * np + c * layout.n_modes_data;
    let rigid_col = |k: usize, r: usize| extra + k * layout.n_rigid_data + r;
    let tangent_col =
        |k: usize, i: usize| extra + c * layout.n_rigid_data + k * layout.n_tangent_data + i;
    // column `col` at the profile cadence, × `scale`, after its magnitude check
    let scaled = |col: usize, scale: f64| -> Result<Vec<f64>> {
        require_magnitude(table, (path, key), col, scale)?;
        Ok(rows_from(run.profile_every)
            .map(|row| table.get(row, col) * scale)
            .collect())
    };
    let rigid_refs = &run.reference.rigid;
    let mut rigid = Vec::with_capacity(c * rigid_refs.len());
    for k in 0..c {
        for (r, law) in rigid_refs.iter().enumerate() {
            rigid.push(scaled(rigid_col(k, r), law.coordinate_scale)?);
        }
    }
    let nt = run.reference.tangent.len();
    let mut tangent = Vec::with_capacity(c * nt);
    for k in 0..c {
        for i in 0..nt {
            tangent.push(scaled(tangent_col(k, i), 1.0)?);
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
    let two_time = two_time_products(run, data, (path, key), table, layout)?;
    let record = TrajectoryRecord {
        modes,
        profile,
        rigid,
        tangent,
        two_time: two_time.clone(),
        slope_squares: Vec::new(),
        slope_samples: 0,
    };
    Ok((record, two_time))
}

/// The two-time products `w(x, t) w(y, t + η)` of [`read_record`]'s table, per component
/// and two-time point; refused if the table is too short for a point.
fn two_time_products(
    run: &LinearRun,
    data: &DataRun,
    (path, key): (&Path, &str),
    table: &Table,
    layout: &Layout,
) -> Result<Vec<f64>> {
    let c = run.components;
    let deflection_col = |k: usize, j: usize| 1 + k * layout.n_positions + j;
    let tt = &run.reference.two_time;
    let mut two_time = vec![0.0; c * tt.len()];
    for (j, (q, &(cx, cy))) in tt.iter().zip(&layout.tt_cols).enumerate() {
        let on_rows = |step: u64| usize::try_from(step).ok().filter(|&r| r < table.rows);
        let (Some(rt), Some(re)) = (on_rows(q.t_step), on_rows(q.eta_step)) else {
            return Err(refused(
                path,
                key,
                format!(
                    "must have rows up to t = {:?} for the two-time point at eta = {:?} (from rest; row {} of dt_sample = {:?}), got {} rows",
                    q.eta,
                    q.eta,
                    q.eta_step.saturating_add(1),
                    data.dt_sample,
                    table.rows
                ),
            ));
        };
        for k in 0..c {
            two_time[k * tt.len() + j] =
                table.get(rt, deflection_col(k, cx)) * table.get(re, deflection_col(k, cy));
        }
    }
    Ok(two_time)
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
/// run prepared on `scene` (the scene with the data's filament or membrane, of time
/// unit `tau1`), whose exact discrete references serve as the data's. `None` (with a
/// note) otherwise.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar key of a known model given with an unknown
/// integrator or noise name; the preparation's errors.
fn discrete_run(
    scene: &Scene,
    tau1: f64,
    (dir, k): (&Path, usize),
    data: &DataRun,
    notes: &mut Vec<String>,
) -> Result<Option<LinearRun>> {
    let Some(d) = &data.discretization else {
        return Ok(None);
    };
    let (model, scheme) = match d.model.as_str() {
        "fem" => (ModelKind::Fem, MeshScheme::Hermite),
        "spectral" if !scene.is_membrane() && !scene.ends.is_hinged() => {
            let message = format!(
                "is \"spectral\" (the sine modes of a filament with hinged ends), but scene {} has {} ends: give the producer's own model (\"fem\" with its elements), or leave discretization out for the continuum references",
                scene.name, scene.ends
            );
            return Err(sidecar_error(dir, k, "discretization.model", message));
        }
        "spectral" => (ModelKind::Spectral, MeshScheme::Hermite),
        _ if d.is_chain() && !scene.is_membrane() && scene.ends.is_hinged() => {
            (ModelKind::Fem, MeshScheme::Chain)
        }
        other => {
            notes.push(format!(
                "run {}: the producer's discretization ({other}) is not one this tool models{}",
                data.name,
                if d.is_chain() {
                    " for this object (a chain of nodes is modelled for a filament with hinged ends)"
                } else {
                    ""
                }
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
    let key_err = |key: &str, message: String| sidecar_error(dir, k, key, message);
    // Names and ranges were checked with the sidecar (`DataSidecar::validate`).
    let unknown = |key: &str| key_err(key, "must be a name as in scene files".into());
    let integrator = d
        .integrator_kind()
        .ok_or_else(|| unknown("discretization.integrator"))?;
    if !IntegratorKind::LINEAR.contains(&integrator) {
        return Err(key_err(
            "discretization.integrator",
            format!(
                "must be an integrator of the linear filament for linear data ({}), got {integrator} (on the linear problem metropolis-crank-nicolson equals crank-nicolson)",
                IntegratorKind::list(&IntegratorKind::LINEAR)
            ),
        ));
    }
    let noise = d
        .noise_model()
        .ok_or_else(|| unknown("discretization.noise"))?;
    fits(scene, data, (model, scheme, elements, dt / tau1)).map_err(|(key, m)| key_err(key, m))?;
    // A membrane's counts are bounded as a scene file's mesh is (the sidecar's own range
    // is the filament's).
    if let Some(m) = &scene.membrane
        && let Some((key, value, allowed)) =
            membrane_mesh_violation(m.boundary, elements, d.elements_y, "discretization")
    {
        return Err(key_err(&key, format!("must be {allowed}, got {value}")));
    }
    let scene = discretized(scene, (model, scheme), elements, d.elements_y);
    let spec = RunSpec {
        integrator,
        noise,
        dt_tau1: dt / tau1,
        ..data_spec(&scene, data)
    };
    // The input errors of the preparation are the discretization's: say where it is.
    LinearRun::prepare(&scene, &spec)
        .map(Some)
        .map_err(|e| match e {
            Error::UnstableTimeStep { .. } => key_err("discretization.dt", e.to_string()),
            Error::InvalidParameter { .. } => key_err("discretization", e.to_string()),
            other => other,
        })
}

/// `scene` on the producer's discretization: its model and mesh scheme, `elements` (and
/// `elements_y` for a membrane) on a uniform mesh.
fn discretized(
    scene: &Scene,
    (model, scheme): (ModelKind, MeshScheme),
    elements: usize,
    elements_y: Option<usize>,
) -> Scene {
    let mut scene = scene.clone();
    scene.model = model;
    scene.mesh.scheme = scheme;
    scene.mesh.elements = elements;
    scene.mesh.elements_y = elements_y.filter(|_| scene.is_membrane());
    scene.mesh.grading = 1.0;
    scene
}

/// The projected set-up of linear data run `data`'s exact discrete references on
/// `scene`, in DOF-steps ([`Scene::setup_cost`] of the producer's finite-element
/// discretization, O(n³)); 0 for continuum or spectral references. What `check`'s
/// progress is weighted by.
pub fn data_setup_cost(scene: &Scene, data: &DataRun) -> f64 {
    let Some(d) = &data.discretization else {
        return 0.0;
    };
    let scheme = match d.model.as_str() {
        "fem" => MeshScheme::Hermite,
        _ if d.is_chain() => MeshScheme::Chain,
        _ => return 0.0,
    };
    match d.elements {
        Some(elements) => {
            discretized(scene, (ModelKind::Fem, scheme), elements, d.elements_y).setup_cost()
        }
        None => 0.0,
    }
}

/// Whether the modelled discretization `(model, scheme, elements, dt/τ₁)` of data run `data`
/// can serve `scene`: it carries at least the modes the scene checks, and (from rest)
/// puts every two-time point of the scene at most 1e10 steps from rest; on failure the
/// key under `runs[k]` and the message.
fn fits(
    scene: &Scene,
    data: &DataRun,
    (model, scheme, elements, dt_tau1): (ModelKind, MeshScheme, usize, f64),
) -> std::result::Result<(), (&'static str, String)> {
    let carried = match (model, scheme) {
        (ModelKind::Fem, MeshScheme::Chain) => elements - 1,
        (ModelKind::Fem, MeshScheme::Hermite) => 2 * elements,
        _ => elements,
    };
    // A membrane's plate refuses, when prepared, a checked mode its mesh does not resolve.
    if carried < scene.sampling.modes && !scene.is_membrane() {
        return Err((
            "discretization.elements",
            format!(
                "is {elements} (model {}): it carries {carried} modes, fewer than the {} modes scene {} checks (sampling.modes): check the data with a scene of at most {carried} modes, or leave the discretization out to be judged against the continuum",
                match (model, scheme) {
                    (ModelKind::Fem, MeshScheme::Chain) => "finite-difference or bead-spring",
                    (ModelKind::Fem, MeshScheme::Hermite) => "fem",
                    _ => "spectral",
                },
                scene.sampling.modes,
                scene.name
            ),
        ));
    }
    let steps = |q: &[f64; 4]| q[3] / dt_tau1;
    if data.start == Start::Rest
        && let Some(q) = scene
            .sampling
            .two_time
            .iter()
            .find(|q| steps(q) > MAX_STEPS_PER_ROW)
    {
        return Err((
            "discretization.dt",
            format!(
                "puts the two-time point at eta = {} tau1 of scene {} {:e} steps from rest, more than 1e10: give the step the data were made with, or leave the discretization out to be judged against the continuum; got dt = {:e} tau1",
                q[3],
                scene.name,
                steps(q),
                dt_tau1
            ),
        ));
    }
    Ok(())
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
/// Each trajectory file is read as a regular file of at most `max_bytes`.
///
/// # Errors
/// [`Error::Scene`] naming the sidecar key when the data are linear runs, a strain of
/// the scene has no data, a data run has no strain, or EA is missing; file errors as
/// [`read_table`] and those of the time column (see the [data
/// format](crate::data#what-is-refused)); the preparation's and the theory's errors.
pub fn prepare_compression_checks(
    scene: &Scene,
    sidecar: &DataSidecar,
    dir: &Path,
    max_bytes: u64,
) -> Result<Vec<CompressionDataCheck>> {
    let sidecar_path = dir.join(crate::data::SIDECAR);
    let bad = |key: String, message: String| Error::Scene {
        file: sidecar_path.clone(),
        key,
        message,
    };
    check_data_kind(scene, sidecar, dir)?;
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
    if data_filament(sidecar, dir)?.stretch_rigidity.is_none() {
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
        .map(|name| compression_data_check(scene, comp, sidecar, dir, name, max_bytes))
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
    max_bytes: u64,
) -> Result<CompressionDataCheck> {
    scene.refuse_membrane("check of a membrane under imposed projected area")?;
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
    scene.filament = data_filament(sidecar, dir)?.params();
    data_theory_domain(&scene.filament, &comp.strain_ratios, dir)?;
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
    let mut theory = CompressionTheoryTable::new(&scene, comp).map_err(|e| match e {
        // The scene's distribution strains are out of reach at the data's filament.
        Error::Scene { key, message, .. } if key.starts_with("compression.") => refused(
            &dir.join(crate::data::SIDECAR),
            "filament.stretch_rigidity",
            format!("is the stretch rigidity at which the scene's {key} {message}"),
        ),
        other => other,
    })?;
    match fem {
        Some(e) => notes.push(format!(
            "run {name}: references: the exact equilibrium theory of the producer's discretization ({e} elements) at every strain; the continuum beside it"
        )),
        None => {
            theory.discrete.clone_from(&theory.continuum);
            for c in &mut theory.curve {
                c.1 = c.2;
            }
            for m in &mut theory.mean_field {
                m.0 = m.1;
            }
            theory.distributions.iter_mut().for_each(|d| *d = None);
            notes.push(format!(
                "run {name}: references: the continuum theory (the producer's discretization is not this tool's finite elements); the distribution of F is not checked (its exact law is known for the discretized filament only)"
            ));
        }
    }
    let records = read_force_records(dir, &by_strain, run.euler_load, max_bytes)?;
    Ok(CompressionDataCheck {
        run,
        theory,
        records,
        notes,
    })
}

/// F/F_c0 of every trajectory file of the data runs `by_strain` (index in the sidecar,
/// run), from the first row at or after each run's burn-in; each file is read as a
/// regular file of at most `max_bytes` and its time column checked.
///
/// # Errors
/// As [`read_trajectory`]; [`Error::Scene`] naming a file and its key
/// `runs[k].files[j]` if no row is at or after the burn-in.
fn read_force_records(
    dir: &Path,
    by_strain: &[(usize, &DataRun)],
    euler_load: f64,
    max_bytes: u64,
) -> Result<Vec<Vec<ForceRecord>>> {
    let cols: Vec<String> = crate::data::COMPRESSION_COLUMNS
        .iter()
        .map(|c| c.to_string())
        .collect();
    let mut records = Vec::new();
    for &(k, data) in by_strain {
        let mut at_strain = Vec::new();
        for (j, path) in data.paths(dir).iter().enumerate() {
            let key = format!("runs[{k}].files[{j}]");
            let table = read_trajectory(data, path, &key, &cols, max_bytes)?;
            require_magnitude(&table, (path, &key), 1, 1.0 / euler_load)?;
            let first_row = first_row(data, table.get(0, 0));
            if first_row >= table.rows {
                return Err(refused(
                    &dir.join(crate::data::SIDECAR),
                    &format!("runs[{k}].burn_in"),
                    format!(
                        "= {:?} leaves no data row of {} ({key}: its {} rows end at t = {:?}): give a burn_in within the data, or write longer trajectories",
                        data.burn_in,
                        path.display(),
                        table.rows,
                        table.get(table.rows - 1, 0)
                    ),
                ));
            }
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

#[cfg(test)]
mod tests {
    //! Refusals of data that cannot serve a scene (exit 2, naming the file, the key, the
    //! row and the value), on small data directories written here: tiny-linear and
    //! tiny-compression (tests/scenes/good) with trajectories of arbitrary finite values
    //! (the preparation reads them; no estimator runs).

    use super::*;
    use crate::data::{DataFilament, Discretization, FORMAT, SIDECAR, TrajectoryFile, VERSION};
    use std::path::PathBuf;

    const CAP: u64 = 1 << 30;

    fn scene(name: &str) -> Scene {
        crate::scene::load_scene(&format!("tests/scenes/good/{name}.toml"), None).unwrap()
    }

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("lfem-vdata-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// The refusal of `r`: exit 2, its message holding every string of `named`.
    fn refusal<T>(r: Result<T>, named: &[&str]) -> String {
        let e = r.err().expect("refused");
        let text = e.to_string();
        assert_eq!(e.exit_code(), 2, "{text}");
        for n in named {
            assert!(text.contains(n), "{n:?} not in {text}");
        }
        text
    }

    /// A run of two trajectory files (CSV) named `name`, rows every `dt_sample`.
    fn run(name: &str, dt_sample: f64, strain_ratio: Option<f64>) -> DataRun {
        DataRun {
            name: name.into(),
            dt_sample,
            start: if strain_ratio.is_some() {
                Start::Stationary
            } else {
                Start::Rest
            },
            burn_in: 0.0,
            positions: if strain_ratio.is_some() {
                vec![]
            } else {
                vec![0.5]
            },
            modes: if strain_ratio.is_some() { 0 } else { 2 },
            discretization: None,
            files: (0..2)
                .map(|j| format!("{name}-{}/t{j}.csv", strain_ratio.unwrap_or(0.0)))
                .collect(),
            strain_ratio,
            rigid: false,
            tangent_modes: 0,
        }
    }

    /// Writes `sidecar` and `rows` rows of each of its files to `dir` (t = t₀ + r·dt_sample
    /// with t₀ = 0 from rest, else 3·dt_sample; other columns arbitrary finite values,
    /// different in every file),
    /// then reads it back as `check` does.
    fn write(dir: &Path, sidecar: &DataSidecar, rows: u64) -> DataSidecar {
        for r in &sidecar.runs {
            let cols = r.column_names(sidecar.dims);
            let t0 = if r.start == Start::Rest {
                0.0
            } else {
                3.0 * r.dt_sample
            };
            for (j, path) in r.paths(dir).iter().enumerate() {
                let mut f = TrajectoryFile::create(path, &cols, rows).unwrap();
                for i in 0..rows {
                    let mut row = vec![t0 + i as f64 * r.dt_sample];
                    // Files differ (independent trajectories are never identical).
                    row.extend(
                        (1..cols.len())
                            .map(|c| ((i * 31 + c as u64 * 17 + j as u64 * 13) % 97) as f64 - 48.0),
                    );
                    f.push_row(&row).unwrap();
                }
                f.commit().unwrap();
            }
        }
        std::fs::write(dir.join(SIDECAR), serde_json::to_string(sidecar).unwrap()).unwrap();
        DataSidecar::load(dir).unwrap()
    }

    /// Linear data for tiny-linear (τ₁ = 1/π⁴): one run, rows every τ₁/100 from rest.
    fn linear(runs: Vec<DataRun>) -> DataSidecar {
        DataSidecar {
            format: FORMAT.into(),
            version: VERSION,
            producer: "test".into(),
            dims: 2,
            filament: Some(DataFilament {
                length: 1.0,
                bending_rigidity: 1.0,
                drag: 1.0,
                kt: 1.0,
                stretch_rigidity: None,
            }),
            membrane: None,
            runs,
            provenance: None,
            columns: None,
        }
    }

    fn tau1() -> f64 {
        1.0 / std::f64::consts::PI.powi(4)
    }

    fn builtin(name: &str) -> Scene {
        crate::scene::builtin::find(name).unwrap().load().unwrap()
    }

    /// Rigid coordinates (`rigid`) against a scene whose ends allow no rigid motion, and
    /// tangent-angle amplitudes (`tangent_modes`) against one with a clamped end, are
    /// refused naming the key.
    #[test]
    fn rigid_and_tangent_columns_are_refused_where_the_ends_have_none() {
        let dir = temp("ends-keys");
        let mut r = run("cn", tau1() / 100.0, None);
        r.rigid = true;
        let side = write(&dir, &linear(vec![r]), 600);
        for name in ["hinged-linear-2d", "grafted-clamped-free"] {
            let r = prepare_data_check(&builtin(name), &side, &dir, 0, CAP);
            refusal(r, &["key `runs[0].rigid`", "has no rigid modes", name]);
        }
        let mut r = run("cn", tau1() / 100.0, None);
        r.tangent_modes = 3;
        let side = write(&dir, &linear(vec![r]), 600);
        let r = prepare_data_check(&builtin("grafted-clamped-free"), &side, &dir, 0, CAP);
        refusal(r, &["key `runs[0].tangent_modes`", "clamped end", "is 3"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A declared `spectral` discretization (the hinged filament's sine modes) against a
    /// scene with other ends is refused naming `runs[0].discretization.model` and the
    /// ends, instead of a zero reference variance at a clamp failing as a run.
    #[test]
    fn a_spectral_discretization_of_other_ends_is_refused() {
        let dir = temp("spectral-ends");
        let mut r = run("cn", tau1() / 100.0, None);
        r.discretization = Some(Discretization {
            model: "spectral".into(),
            elements: Some(2),
            elements_y: None,
            integrator: Some("exact-modal".into()),
            noise: None,
            dt: Some(tau1() / 100.0),
        });
        let side = write(&dir, &linear(vec![r]), 600);
        for name in ["grafted-clamped-free", "microtubule-free-free"] {
            let r = prepare_data_check(&builtin(name), &side, &dir, 0, CAP);
            refusal(r, &["key `runs[0].discretization.model`", "spectral", name]);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Valid data are read; too few rows after the burn-in are still refused naming
    /// `runs[k].files`; a two-time point beyond the rows names the file.
    /// Data of the other object are refused before their files are read, naming the
    /// sidecar key of the object the data are of and the scene: a filament's data
    /// against a membrane scene (and, in `tests/run_check.rs`, a membrane's against a
    /// filament scene).
    #[test]
    fn data_of_the_other_object_are_refused() {
        let dir = temp("membrane");
        let side = write(&dir, &linear(vec![run("cn", tau1() / 100.0, None)]), 600);
        for name in ["membrane-hinged", "membrane-pbc"] {
            let r = prepare_data_check(&scene(name), &side, &dir, 0, CAP);
            refusal(
                r,
                &[
                    "data.json: key `filament`",
                    "the data are of a filament",
                    &format!("scene {name}"),
                    "is a membrane scene",
                ],
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn linear_data_are_read_and_short_ones_refused() {
        let dir = temp("linear");
        let s = scene("tiny-linear");
        let side = write(&dir, &linear(vec![run("cn", tau1() / 100.0, None)]), 600);
        let dc = prepare_data_check(&s, &side, &dir, 0, CAP).unwrap();
        assert_eq!(dc.records.len(), 2);
        assert_eq!(dc.two_time[0].len(), 1);
        let side = write(&dir, &side, 300);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "data.json",
                "runs[0].files",
                "burn_in",
                "write longer trajectories",
            ],
        );
        let side = write(&dir, &side, 60);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "t0.csv",
                "runs[0].files[0]",
                "two-time point",
                "got 60 rows",
            ],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A tiny `dt_sample` with a huge burn-in (every index beyond any row, cadences
    /// beyond u64) is refused as too short, without a panic.
    #[test]
    fn absurd_cadences_and_burn_ins_do_not_panic() {
        let dir = temp("absurd");
        let s = scene("tiny-linear");
        // The shortest cadence a sidecar may give, and a burn-in beyond any data.
        let mut r = run("cn", tau1() * crate::data::MIN_SAMPLE_TAU1, None);
        r.burn_in = 1e300;
        r.start = Start::Stationary;
        let side = write(&dir, &linear(vec![r]), 40);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "runs[0].files",
                "at least 4000000000000 stationary rows",
                "got 0",
            ],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The time column: a first row off 0 from rest, a row off the cadence, all equal
    /// times (compression data too, through the same function).
    #[test]
    fn time_columns_are_on_the_cadence() {
        let dir = temp("times");
        let s = scene("tiny-linear");
        let dts = tau1() / 100.0;
        let side = write(&dir, &linear(vec![run("cn", dts, None)]), 600);
        let path = dir.join(&side.runs[0].files[1]);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let mut bad = lines.clone();
        let row7 = lines[7].replacen(lines[7].split(',').next().unwrap(), "1.5", 1);
        bad[7] = &row7;
        std::fs::write(&path, bad.join("\n")).unwrap();
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "t1.csv",
                "runs[0].files[1]",
                "column \"t\", data row 7",
                "got t = 1.5",
            ],
        );
        let shifted = lines[1].replacen('0', "0.5", 1);
        bad = lines.clone();
        bad[1] = &shifted;
        std::fs::write(&path, bad.join("\n")).unwrap();
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &["data row 1", "start = \"rest\"", "got t = 0.5"],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Finite values too large for the checks' sums (a deflection or a force of 1e300)
    /// are refused naming the column, the data row and the value, before any estimator.
    #[test]
    fn values_too_large_for_the_checks_are_refused() {
        let dir = temp("huge");
        let s = scene("tiny-linear");
        let side = write(&dir, &linear(vec![run("cn", tau1() / 100.0, None)]), 600);
        let path = dir.join(&side.runs[0].files[0]);
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        lines[42] = lines[42].replacen(",", ",1e300,", 1);
        let mut cells: Vec<&str> = lines[42].split(',').collect();
        cells.remove(2);
        lines[42] = cells.join(",");
        std::fs::write(&path, lines.join("\n")).unwrap();
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "t0.csv",
                "runs[0].files[0]",
                "column \"w_0\", data row 42",
                "1e300",
            ],
        );
        let cs = scene("tiny-compression");
        let side = write(&dir, &compression(), 50);
        let path = dir.join(&side.runs[2].files[1]);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| match (i, l.split_once(',')) {
                (7, Some((t, rest))) => format!("{t},-1e300,{}", rest.split_once(',').unwrap().1),
                _ => l.to_string(),
            })
            .collect();
        std::fs::write(&path, lines.join("\n")).unwrap();
        refusal(
            prepare_compression_checks(&cs, &side, &dir, CAP),
            &["runs[2].files[1]", "column \"force\", data row 7", "-1e300"],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The kind of the data is checked first: linear runs against a compression scene and
    /// compression runs against a linear scene are refused saying so.
    #[test]
    fn data_of_the_other_kind_are_refused_first() {
        let dir = temp("kind");
        let side = write(&dir, &linear(vec![run("cn", tau1() / 100.0, None)]), 10);
        let comp = scene("tiny-compression");
        let named = [
            "data.json",
            "`runs`",
            "linear runs",
            "tiny-compression",
            "strain_ratio",
        ];
        refusal(check_data_kind(&comp, &side, &dir), &named);
        refusal(prepare_compression_checks(&comp, &side, &dir, CAP), &named);
        let mut c = linear(vec![run("m", 0.01, Some(0.0))]);
        c.filament.as_mut().unwrap().stretch_rigidity = Some(1e6);
        let side = write(&dir, &c, 10);
        let named = [
            "`runs[0].strain_ratio`",
            "compression data",
            "tiny-linear",
            "compression scene",
        ];
        refusal(
            prepare_data_check(&scene("tiny-linear"), &side, &dir, 0, CAP),
            &named,
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Trajectory files above the cap together are refused unread, naming the data
    /// directory, the total, the cap and the flag; a missing file names its key.
    #[test]
    fn the_files_are_capped_together() {
        let dir = temp("cap");
        let side = write(&dir, &linear(vec![run("cn", tau1() / 100.0, None)]), 10);
        let size: u64 = side.runs[0]
            .paths(&dir)
            .iter()
            .map(|p| std::fs::metadata(p).unwrap().len())
            .sum();
        assert!(require_data_size(&side, &dir, size).is_ok());
        let total = format!("hold {size} bytes");
        let cap = format!("the {} bytes", size - 1);
        let named = [dir.to_str().unwrap(), &total, &cap, "--max-memory-gib"];
        refusal(require_data_size(&side, &dir, size - 1), &named);
        std::fs::remove_file(dir.join(&side.runs[0].files[1])).unwrap();
        refusal(
            require_data_size(&side, &dir, CAP),
            &["runs[0].files[1]", "t1.csv"],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A discretization this tool models but cannot build for the scene: fewer modes
    /// than the scene checks, a step putting a two-time point beyond 1e10 steps, an
    /// integrator of the nonlinear filament; each names its sidecar key.
    #[test]
    fn discretizations_that_cannot_serve_are_refused_naming_the_key() {
        let dir = temp("disc");
        let s = scene("tiny-linear");
        let dts = tau1() / 100.0;
        let with = |model: &str, elements: usize, integrator: &str, dt: f64| {
            let mut r = run("cn", dts, None);
            r.discretization = Some(Discretization {
                model: model.into(),
                elements: Some(elements),
                elements_y: None,
                integrator: Some(integrator.into()),
                noise: None,
                dt: Some(dt),
            });
            write(&dir, &linear(vec![r]), 600)
        };
        let side = with("fem", 4, "crank-nicolson", dts / 10.0);
        assert!(prepare_data_check(&s, &side, &dir, 0, CAP).is_ok());
        let side = with("spectral", 1, "exact-modal", dts);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "data.json",
                "runs[0].discretization.elements",
                "carries 1 modes",
                "2 modes",
            ],
        );
        let side = with("fem", 4, "crank-nicolson", dts * 2e-10);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "runs[0].discretization.dt",
                "two-time point",
                "more than 1e10",
            ],
        );
        let side = with("fem", 4, "metropolis-crank-nicolson", dts);
        refusal(
            prepare_data_check(&s, &side, &dir, 0, CAP),
            &[
                "runs[0].discretization.integrator",
                "metropolis-crank-nicolson",
            ],
        );
        // A chain of nodes (issue #31): N intervals carry N − 1 modes; one interval has
        // no interior node (refused with the sidecar, naming the key and [2, 1000]).
        for model in ["finite-difference", "bead-spring"] {
            let side = with(model, 3, "euler-maruyama", dts / 10.0);
            let dc = prepare_data_check(&s, &side, &dir, 0, CAP).expect(model);
            assert!(!dc.continuum_references, "{model}");
            let side = with(model, 2, "euler-maruyama", dts / 10.0);
            refusal(
                prepare_data_check(&s, &side, &dir, 0, CAP),
                &["runs[0].discretization.elements", "carries 1 modes"],
            );
        }
        let mut side = with("finite-difference", 2, "euler-maruyama", dts / 10.0);
        side.runs[0].discretization.as_mut().unwrap().elements = Some(1);
        let err = side
            .validate(Path::new("data.json"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("runs[0].discretization.elements") && err.contains("[2, 1000]"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Compression data for tiny-compression: run "metropolis" at its three strains,
    /// rows every 0.05 τ₁ (τ₁ = 0.01/π⁴) from the burn-in.
    fn compression() -> DataSidecar {
        let dts = 0.05 * 0.01 / std::f64::consts::PI.powi(4);
        let runs = [0.0, 2.0, 4.0]
            .iter()
            .map(|&e| DataRun {
                burn_in: 2.0 * dts,
                ..run("metropolis", dts, Some(e))
            })
            .collect();
        let mut side = linear(runs);
        side.filament.as_mut().unwrap().bending_rigidity = 100.0;
        side.filament.as_mut().unwrap().stretch_rigidity = Some(1e6);
        side
    }

    /// Compression data are read; an empty file, a file whose rows all precede the
    /// burn-in and rows at one time are refused naming the file and its key.
    #[test]
    fn compression_files_are_checked_as_linear_ones() {
        let dir = temp("compression");
        let s = scene("tiny-compression");
        let side = write(&dir, &compression(), 50);
        let checks = prepare_compression_checks(&s, &side, &dir, CAP).unwrap();
        assert_eq!(checks[0].records.len(), 3);
        assert_eq!(checks[0].records[0][0].force_ratio.len(), 50);
        let mut start_late = compression();
        start_late.runs[0].burn_in = 4.5 * start_late.runs[0].dt_sample;
        let side = write(&dir, &start_late, 50);
        let checks = prepare_compression_checks(&s, &side, &dir, CAP).unwrap();
        assert_eq!(checks[0].records[0][0].force_ratio.len(), 48);
        let path = dir.join(&side.runs[1].files[0]);
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, "").unwrap();
        refusal(
            prepare_compression_checks(&s, &side, &dir, CAP),
            &["t0.csv", "runs[1].files[0]", "no data rows"],
        );
        let same_t: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| match i {
                0 => l.to_string(),
                _ => format!("1.0,{}", l.split_once(',').unwrap().1),
            })
            .collect();
        std::fs::write(&path, same_t.join("\n")).unwrap();
        refusal(
            prepare_compression_checks(&s, &side, &dir, CAP),
            &[
                "runs[1].files[0]",
                "column \"t\", data row 2",
                "got t = 1.0",
            ],
        );
        std::fs::write(&path, text).unwrap();
        let mut late = compression();
        late.runs[2].burn_in = 1.0;
        let side = write(&dir, &late, 50);
        refusal(
            prepare_compression_checks(&s, &side, &dir, CAP),
            &[
                "runs[2].burn_in",
                "runs[2].files[0]",
                "= 1.0 leaves no data row",
            ],
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
