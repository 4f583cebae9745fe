//! Stability map and per-mode stationary bias of the linear integrators
//! (`langevin-fem stability`).
//!
//! For each integrator, element count and normalized step a = Δt·λ_max (λ_max the fastest
//! generalized rate of (K, C) on that mesh) the linear filament (or the membrane's plate,
//! [`uniform_object`]) is simulated from rest with consistent noise, and the cell is
//! classified:
//!
//! - **unstable**: the amplification factor of some mode has |m| ≥ 1. The tool refuses
//!   such a run before simulating ([`build_integrator`] returns
//!   [`Error::UnstableTimeStep`]); to show that the refusal is not over-cautious the
//!   θ-scheme is then run anyway, bypassing the check, and the step at which the state
//!   overflowed is recorded;
//! - **biased**: stable, but the measured stationary variance of at least one checked
//!   mode differs from the Δt → 0 value kT/λ_i beyond its statistical error (two-sided
//!   z-tests, Holm over every checked mode of the map at level α, so that a map of
//!   unbiased cells shows no "biased" cell with probability ≥ 1 − α);
//! - **stable**: no bias resolved at this sample size (the formula's predicted bias is
//!   listed beside it, so "stable" reads as "unbiased within the error bar").
//!
//! Every checked mode's measured ratio var/(kT/λ_i) is also compared with the
//! integrator's exact discrete-time formula [`IntegratorKind::stationary_variance_ratio`]
//! (θ-schemes: 1/(1 + (θ − ½)λΔt); exact OU update: 1), z-tests with Holm over the whole
//! map: the formula must be accepted everywhere.
//!
//! Checked modes: the fastest mode and modes spaced by √10 in rate below it, as long as
//! the run resolves them: with |m_i| the mode's one-step multiplier and
//! d_i = −ln|m_i| its decay per step, the burn-in must cover [`BURN_IN_DECAYS`] decays
//! (the transient variance deficit |m_i|^{2B} ≤ e^{−14}) and the sampled part
//! [`MIN_SAMPLED_DECAYS`]. Crank–Nicolson's stiffest modes have m → −1 as λΔt → ∞ and
//! barely decay: they are left out and counted, since their variance is exact but cannot
//! be measured in such a run (and their dynamics is wrong).
//!
//! Each cell has its own seed (derived from the scene seed and the cell's label) and its
//! trajectories their own streams, so results do not depend on the thread count.

use super::output::StudyReport;
use crate::dynamics::{
    Components, Driver, Family, Integrator, IntegratorKind, Observer, ThetaScheme, build_integrator,
};
use crate::error::{Error, Result};
use crate::fem::beam::BeamModel;
use crate::fem::mesh::Mesh;
use crate::fem::noise::NoiseModel;
use crate::output::io::CsvWriter;
use crate::output::{Figure, Provenance, Series, SeriesStyle};
use crate::rng::{derive_seed, trajectory_rng};
use crate::scene::linear::FemObject;
use crate::scene::{ModelKind, Scene};
use crate::spectral::membrane::Membrane;
use crate::stats;
use crate::studies::converge::nan_if_null;
use crate::studies::converge::{MEMBRANE_ELEMENTS_RANGE, membrane_elements_y};
use crate::work::{Origin, Part, RunWork, WorkLimits, WorkProjection};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Default element counts of the map.
pub const DEFAULT_ELEMENTS: [usize; 4] = [5, 10, 20, 40];
/// Default element counts (along x) of the map of a membrane.
pub const DEFAULT_MEMBRANE_ELEMENTS: [usize; 2] = [4, 8];
/// Default normalized steps a = Δt·λ_max: well inside, at and beyond the explicit limit
/// (a = 2), and far beyond it.
pub const DEFAULT_DT_LAMBDA_MAX: [f64; 7] = [0.1, 1.0, 1.9, 2.1, 10.0, 1.0e3, 1.0e5];
/// Default integrators: every linear one.
pub const DEFAULT_INTEGRATORS: [IntegratorKind; 4] = IntegratorKind::LINEAR;
/// Burn-in length in decays of the slowest checked mode (−ln|m| per step).
pub const BURN_IN_DECAYS: f64 = 7.0;
/// Sampled length in decays of the slowest checked mode.
pub const MIN_SAMPLED_DECAYS: f64 = 100.0;
/// At most this many modes are checked per cell.
pub const MAX_CHECKED_MODES: usize = 6;
/// Allowed element counts (dense generalized eigen-decomposition per cell).
pub const ELEMENTS_RANGE: (usize, usize) = (2, 200);

/// Options of a stability study.
#[derive(Debug, Clone)]
pub struct StabilityOptions {
    /// A linear finite-element scene: filament parameters and seed.
    pub scene: Scene,
    /// Integrators (rows of the map).
    pub integrators: Vec<IntegratorKind>,
    /// Element counts.
    pub elements: Vec<usize>,
    /// Normalized steps a = Δt·λ_max.
    pub dt_lambda_max: Vec<f64>,
    /// Independent trajectories per cell.
    pub trajectories: usize,
    /// Sampled steps per trajectory (after the burn-in).
    pub sampled_steps: u64,
    /// Burn-in steps per trajectory.
    pub burn_in_steps: u64,
    /// Family-wise level of the bias and formula tests.
    pub alpha: f64,
    /// Output directory.
    pub out: PathBuf,
    /// Print one line per cell on stderr.
    pub progress: bool,
    /// The caps on the map's projected work and memory ([`projected_work`]), checked
    /// before any simulation.
    pub limits: WorkLimits,
}

/// The unknowns of `scene`'s object on a uniform mesh of `elements` elements (an upper
/// bound): 2·elements for a beam, 4(nx + 1)(ny + 1) for a plate.
fn unknowns(scene: &Scene, elements: usize) -> f64 {
    if scene.is_membrane() {
        let ny = membrane_elements_y(scene, elements);
        4.0 * (elements as f64 + 1.0) * (ny as f64 + 1.0)
    } else {
        2.0 * elements as f64
    }
}

/// The projected work of the map (an upper bound, see [`crate::work`]): every cell runs
/// `trajectories × (burn_in_steps + sampled_steps)` steps of its unknowns ([`unknowns`]:
/// `2·elements` for a filament)
/// (`(2·elements)²` for exact-modal; a refused cell runs one forced trajectory instead)
/// and holds the series of at most [`MAX_CHECKED_MODES`] modes at every sampled step;
/// the cells run in parallel, as many at once as there are threads.
pub fn projected_work(opts: &StabilityOptions) -> WorkProjection {
    // In f64: the projection may be asked of options that were not validated.
    let per_trajectory = opts.burn_in_steps as f64 + opts.sampled_steps as f64;
    let traj = opts.trajectories as f64;
    let mut work = RunWork::default();
    let mut per_cell_samples: f64 = 0.0;
    for &k in &opts.integrators {
        for &e in &opts.elements {
            let n = unknowns(&opts.scene, e);
            let cost = if k == IntegratorKind::ExactModal {
                n * n
            } else {
                n
            };
            let cells = opts.dt_lambda_max.len() as f64;
            work.trajectory_steps += cells * traj * per_trajectory;
            work.dof_steps += cells * traj * per_trajectory * cost;
            let rows = (MAX_CHECKED_MODES as f64).min(n);
            per_cell_samples = per_cell_samples.max(traj * rows * opts.sampled_steps as f64);
        }
    }
    let cells = opts.integrators.len() * opts.elements.len() * opts.dt_lambda_max.len();
    let at_once = rayon::current_num_threads().clamp(1, cells.max(1)) as f64;
    work.samples = per_cell_samples * at_once;
    let largest = opts.elements.iter().max().copied().unwrap_or(0);
    WorkProjection {
        command: format!("stability --scene {}", opts.scene.name),
        parts: vec![Part {
            label: format!(
                "the map of {cells} cells ({} integrators x {} element counts x {} steps dt*lambda_max, up to {largest} elements; {} cells at once)",
                opts.integrators.len(),
                opts.elements.len(),
                opts.dt_lambda_max.len(),
                at_once
            ),
            drivers: format!(
                "--integrators, --elements, --dt-lambda-max ({cells} cells) x --trajectories {} x (--burn-in {} + --steps {})",
                opts.trajectories, opts.burn_in_steps, opts.sampled_steps
            ),
            origin: Origin::Flags(
                "--integrators, --elements, --dt-lambda-max, --trajectories, --burn-in, --steps"
                    .to_string(),
            ),
            work,
        }],
    }
}

/// The classification of a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// Stable; no stationary bias resolved.
    Stable,
    /// Stable, but the stationary variance is biased beyond its statistical error.
    Biased,
    /// |m| ≥ 1 for some mode: refused before running; diverges when forced.
    Unstable,
}

impl Status {
    /// Name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Status::Stable => "stable",
            Status::Biased => "biased",
            Status::Unstable => "unstable",
        }
    }

    /// The status colour of the figures, (red, green, blue): stable green, biased amber,
    /// unstable red, as in the HTML table of the map.
    pub fn rgb(self) -> (u8, u8, u8) {
        match self {
            Status::Stable => (26, 127, 55),
            Status::Biased => (230, 145, 0),
            Status::Unstable => (207, 34, 46),
        }
    }
}

/// The measured stationary variance of one mode against the exact formula.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModeBias {
    /// Mode number (1-based, ascending rate).
    pub mode: usize,
    /// λ_i Δt.
    #[serde(deserialize_with = "nan_if_null")]
    pub lambda_dt: f64,
    /// One-step multiplier m_i of the mode.
    #[serde(deserialize_with = "nan_if_null")]
    pub multiplier: f64,
    /// Measured variance / (kT/λ_i).
    #[serde(deserialize_with = "nan_if_null")]
    pub measured_ratio: f64,
    /// Its standard error (autocorrelation-aware, trajectories in quadrature).
    #[serde(deserialize_with = "nan_if_null")]
    pub std_error: f64,
    /// The exact discrete-time ratio of the integrator.
    #[serde(deserialize_with = "nan_if_null")]
    pub formula_ratio: f64,
    /// z of measured against the formula.
    #[serde(deserialize_with = "nan_if_null")]
    pub z_formula: f64,
    /// Two-sided p-value of that z.
    #[serde(deserialize_with = "nan_if_null")]
    pub p_formula: f64,
    /// z of measured against 1 (no bias).
    #[serde(deserialize_with = "nan_if_null")]
    pub z_bias: f64,
    /// Two-sided p-value of that z.
    #[serde(deserialize_with = "nan_if_null")]
    pub p_bias: f64,
    /// Whether Holm over the whole map rejects the formula for this mode.
    pub formula_rejected: bool,
}

/// One cell of the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Integrator.
    pub integrator: String,
    /// Element count.
    pub elements: usize,
    /// a = Δt·λ_max.
    #[serde(deserialize_with = "nan_if_null")]
    pub dt_lambda_max: f64,
    /// Δt/τ1.
    #[serde(deserialize_with = "nan_if_null")]
    pub dt_tau1: f64,
    /// Multiplier of the fastest mode.
    #[serde(deserialize_with = "nan_if_null")]
    pub max_multiplier: f64,
    /// Classification.
    pub status: Status,
    /// Human-readable detail.
    pub detail: String,
    /// The tool's refusal message for an unstable step.
    pub refused: Option<String>,
    /// The step at which the forced run overflowed (unstable cells).
    pub diverged_at: Option<u64>,
    /// Modes not checked because the run cannot resolve them.
    pub unresolved_modes: usize,
    /// Largest |measured − formula| bias predicted among the checked modes, |ratio − 1|.
    #[serde(deserialize_with = "nan_if_null")]
    pub predicted_max_bias: f64,
    /// The checked modes.
    pub modes: Vec<ModeBias>,
}

/// The stem of the study's output set: `stability.json`, `stability.manifest.json`
/// ([`super::output`]).
pub const STEM: &str = "stability";

/// The JSON summary of a stability study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StabilitySummary {
    /// The run that wrote this summary: the run id of the journal
    /// `stability.manifest.json` ([`super::output`]); empty in a summary written before
    /// journals existed.
    #[serde(default)]
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Master seed of the study: the scene's `seed`, or `--seed` when given (0 in a
    /// summary written before the seed was stored).
    #[serde(default)]
    pub seed: u64,
    /// Noise model (consistent).
    pub noise: String,
    /// Family-wise level.
    #[serde(deserialize_with = "nan_if_null")]
    pub alpha: f64,
    /// Trajectories per cell.
    pub trajectories: usize,
    /// Burn-in steps per trajectory.
    pub burn_in_steps: u64,
    /// Sampled steps per trajectory.
    pub sampled_steps: u64,
    /// All cells, integrator-major, then elements, then a.
    pub cells: Vec<Cell>,
    /// Number of per-mode formula comparisons (the Holm family).
    pub formula_tests: usize,
    /// Number rejected by Holm at α.
    pub formula_rejections: usize,
    /// Whether the predicted stability agreed with every run (refused cells diverge
    /// when forced, accepted cells do not).
    pub stability_as_predicted: bool,
    /// The study's files (relative to the output directory, sorted): its tables, figures
    /// and this summary; its journal and the shared index apart.
    pub files: Vec<String>,
    /// Wall time (s).
    #[serde(deserialize_with = "nan_if_null")]
    pub wall_seconds: f64,
}

/// Validates the options (exit code 2 on bad input, naming the flag).
fn validate(opts: &StabilityOptions) -> Result<()> {
    if opts.scene.model != ModelKind::Fem {
        return Err(Error::invalid(
            "--scene",
            &opts.scene.name,
            "a linear finite-element scene (model = \"fem\", e.g. hinged-linear-2d)",
        ));
    }
    validate_elements(&opts.scene, &opts.elements, "--elements")?;
    for &a in &opts.dt_lambda_max {
        if !(a.is_finite() && a > 0.0 && a <= 1e12) {
            return Err(Error::invalid("--dt-lambda-max", a, "numbers in (0, 1e12]"));
        }
    }
    for &k in &opts.integrators {
        if k == IntegratorKind::MetropolisCrankNicolson {
            return Err(Error::invalid(
                "--integrators",
                k,
                format!(
                    "{} (on the linear filament metropolis-crank-nicolson is crank-nicolson)",
                    IntegratorKind::list(&IntegratorKind::LINEAR)
                ),
            ));
        }
    }
    if opts.integrators.is_empty() || opts.elements.is_empty() || opts.dt_lambda_max.is_empty() {
        return Err(Error::invalid(
            "--integrators/--elements/--dt-lambda-max",
            "(empty)",
            "at least one value each",
        ));
    }
    if !(2..=1024).contains(&opts.trajectories) {
        return Err(Error::invalid(
            "--trajectories",
            opts.trajectories,
            "an integer in [2, 1024]",
        ));
    }
    if !(1000..=100_000_000).contains(&opts.sampled_steps) {
        return Err(Error::invalid(
            "--steps",
            opts.sampled_steps,
            "an integer in [1000, 1e8]",
        ));
    }
    if opts.burn_in_steps > 100_000_000 {
        return Err(Error::invalid(
            "--burn-in",
            opts.burn_in_steps,
            "an integer in [0, 1e8]",
        ));
    }
    crate::error::require_in_range("--alpha", opts.alpha, 1e-6, 0.5)?;
    Ok(())
}

/// Checks the element counts `elements` of a study of `scene` (flag `flag`): integers in
/// [`ELEMENTS_RANGE`] for a filament; for a membrane in [`MEMBRANE_ELEMENTS_RANGE`] along
/// x and, at the scene's aspect ratio of elements, along y (a periodic membrane needs 2
/// a side).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `flag`, the value and the allowed range.
pub(crate) fn validate_elements(scene: &Scene, elements: &[usize], flag: &str) -> Result<()> {
    let (lo, hi) = if scene.is_membrane() {
        MEMBRANE_ELEMENTS_RANGE
    } else {
        ELEMENTS_RANGE
    };
    for &e in elements {
        let ny = if scene.is_membrane() {
            membrane_elements_y(scene, e)
        } else {
            e
        };
        if !(lo..=hi).contains(&e) || !(lo..=hi).contains(&ny) {
            let what = if scene.is_membrane() {
                format!(
                    "integers in [{lo}, {hi}] for a membrane, whose count along y at the aspect ratio of elements of {} ({} x {}) is in [{lo}, {hi}] too (got {e} x {ny})",
                    scene.path.display(),
                    scene.mesh.elements,
                    scene.mesh.elements_along_y()
                )
            } else {
                format!("integers in [{lo}, {hi}]")
            };
            return Err(Error::invalid(flag, e, what));
        }
    }
    Ok(())
}

/// Decay per step of a mode with multiplier `m` (infinite for m = 0).
fn decay(m: f64) -> f64 {
    -m.abs().ln()
}

/// Chooses the checked modes: the fastest, then modes spaced by √10 in rate, each
/// resolved by the run (burn-in and sampled length in decays).
fn checked_modes(rates: &[f64], mult: &[f64], burn_in: u64, sampled: u64) -> Vec<usize> {
    let n = rates.len();
    let resolved = |i: usize| {
        decay(mult[i]) * burn_in as f64 >= BURN_IN_DECAYS
            && decay(mult[i]) * sampled as f64 >= MIN_SAMPLED_DECAYS
    };
    let mut out: Vec<usize> = Vec::new();
    let mut k = 0;
    loop {
        let target = rates[n - 1] * 10f64.powf(-0.5 * k as f64);
        if target < rates[0] * 0.5 || out.len() >= MAX_CHECKED_MODES {
            break;
        }
        let i = (0..n)
            .min_by(|&a, &b| {
                (rates[a].ln() - target.ln())
                    .abs()
                    .total_cmp(&(rates[b].ln() - target.ln()).abs())
            })
            .unwrap_or(0);
        if resolved(i) && !out.contains(&i) {
            out.push(i);
        }
        k += 1;
    }
    out.sort_unstable();
    out
}

/// The finite-element object of `scene` on a uniform mesh of `elements` elements: the
/// filament's beam, or the membrane's plate with `elements` along x and, along y, the
/// scene's aspect ratio of elements ([`membrane_elements_y`]).
///
/// # Errors
/// As [`BeamModel::new`] and [`FemObject::plate`].
pub(crate) fn uniform_object(scene: &Scene, elements: usize) -> Result<FemObject> {
    match scene.membrane {
        None => {
            let p = scene.filament;
            let beam = BeamModel::with_ends(p, Mesh::uniform(p.length, elements)?, scene.ends)?;
            Ok(FemObject::Beam(Box::new(beam)))
        }
        Some(m) => FemObject::plate(
            &Membrane::new(m)?,
            elements,
            membrane_elements_y(scene, elements),
            Vec::new(),
        ),
    }
}

/// The model of one cell: the object, its generalized modes, the step and the
/// multipliers.
struct CellModel {
    object: FemObject,
    gm: crate::fem::modal::GeneralizedModes,
    rates: Vec<f64>,
    dt: f64,
    mult: Vec<f64>,
    seed: u64,
}

impl CellModel {
    /// The model of the cell (`kind`, `elements`, a = Δt·λ_max) and its empty [`Cell`].
    fn new(
        opts: &StabilityOptions,
        kind: IntegratorKind,
        elements: usize,
        a: f64,
    ) -> Result<(CellModel, Cell)> {
        let scene = &opts.scene;
        let object = uniform_object(scene, elements)?;
        let gm = object.modes()?;
        let rates: Vec<f64> = gm.rates.iter().copied().collect();
        let n = rates.len();
        let lmax = rates[n - 1];
        let dt = a / lmax;
        let kt = object.system().kt();
        let mult: Vec<f64> = rates
            .iter()
            .map(|&r| kind.modal_form(r, dt, kt).0)
            .collect();
        let seed = derive_seed(
            scene.seed,
            &format!("stability/{}/{elements}/{a:e}", kind.name()),
        );
        let cell = Cell {
            integrator: kind.name().to_string(),
            elements,
            dt_lambda_max: a,
            dt_tau1: dt / scene.tau1(),
            max_multiplier: mult[n - 1],
            status: Status::Stable,
            detail: String::new(),
            refused: None,
            diverged_at: None,
            unresolved_modes: 0,
            predicted_max_bias: 0.0,
            modes: Vec::new(),
        };
        let model = CellModel {
            object,
            gm,
            rates,
            dt,
            mult,
            seed,
        };
        Ok((model, cell))
    }

    /// λ_max.
    fn max_rate(&self) -> f64 {
        self.rates[self.rates.len() - 1]
    }

    /// The integrator of the cell, built with the tool's stability check.
    fn integrator(&self, kind: IntegratorKind) -> Result<Box<dyn Integrator>> {
        build_integrator(
            kind,
            self.object.system(),
            NoiseModel::Consistent,
            self.dt,
            self.max_rate(),
            Some(&self.gm),
        )
    }

    /// The θ-scheme run from rest bypassing the stability check (trajectory 0 of the cell):
    /// the step at which the state overflowed, or `None` if it stayed finite.
    fn forced_run(&self, opts: &StabilityOptions, kind: IntegratorKind) -> Result<Option<u64>> {
        let theta = match kind.family() {
            Family::Theta(theta) => theta,
            Family::ExactModal | Family::Metropolis => {
                return Err(Error::Numerical {
                    routine: "stability map".into(),
                    detail: format!("{kind} refused a step but is not a theta-scheme"),
                });
            }
        };
        let system = self.object.system();
        let forced = ThetaScheme::new(system, NoiseModel::Consistent, theta, self.dt)?;
        let mut system = Components::at_rest(forced, 1, system.n_dofs());
        let driver = Driver::new(self.dt, opts.burn_in_steps, opts.sampled_steps, 1);
        let mut rng = trajectory_rng(self.seed, 0);
        match driver.run(0, &mut system, &mut rng, &mut (), |_| String::new()) {
            Ok(()) => Ok(None),
            Err(Error::Diverged { step, .. }) => Ok(Some(step)),
            Err(e) => Err(e),
        }
    }

    /// Per trajectory, the sampled series of the checked modes (projection `rows`), or
    /// that trajectory's error.
    fn series(
        &self,
        opts: &StabilityOptions,
        kind: IntegratorKind,
        rows: &[Vec<f64>],
        (elements, a): (usize, f64),
    ) -> Vec<Result<Vec<Vec<f64>>>> {
        let driver = Driver::new(self.dt, opts.burn_in_steps, opts.sampled_steps, 1);
        (0..opts.trajectories)
            .map(|j| -> Result<Vec<Vec<f64>>> {
                let n_dofs = self.object.system().n_dofs();
                let mut system = Components::at_rest(self.integrator(kind)?, 1, n_dofs);
                let mut rng = trajectory_rng(self.seed, j as u64);
                let mut obs = ModeSeries {
                    rows,
                    out: vec![Vec::with_capacity(opts.sampled_steps as usize); rows.len()],
                };
                driver.run(j, &mut system, &mut rng, &mut obs, |_| {
                    format!("{kind} at dt*lambda_max = {a:e} with {elements} elements")
                })?;
                Ok(obs.out)
            })
            .collect()
    }

    /// The measured stationary variance of mode `i` (series `k` of each trajectory in
    /// `per_traj`) against the exact formula of `kind`.
    fn mode_bias(
        &self,
        kind: IntegratorKind,
        kt: f64,
        per_traj: &[Vec<Vec<f64>>],
        (k, i): (usize, usize),
    ) -> Result<ModeBias> {
        let (rates, dt) = (&self.rates, self.dt);
        let parts = per_traj
            .iter()
            .map(|t| stats::variance_with_error(&t[k], Some(0.0)))
            .collect::<Result<Vec<_>>>()?;
        let (var, var_se) = stats::combine_independent(&parts);
        let scale = rates[i] / kt;
        let ratio = var * scale;
        let se = var_se * scale;
        let formula = kind
            .stationary_variance_ratio(rates[i], dt)
            .ok_or_else(|| Error::Numerical {
                routine: "stability map".into(),
                detail: format!("no stationary variance for a stable mode of {kind}"),
            })?;
        let zf = stats::z_test(ratio, formula, se)?;
        let zb = stats::z_test(ratio, 1.0, se)?;
        Ok(ModeBias {
            mode: i + 1,
            lambda_dt: rates[i] * dt,
            multiplier: self.mult[i],
            measured_ratio: ratio,
            std_error: se,
            formula_ratio: formula,
            z_formula: zf.statistic,
            p_formula: zf.p_value,
            z_bias: zb.statistic,
            p_bias: zb.p_value,
            formula_rejected: false,
        })
    }
}

/// The observer of a cell's trajectories: the projections of the state on the checked
/// modes (`rows`) at every sampled step.
struct ModeSeries<'r> {
    rows: &'r [Vec<f64>],
    out: Vec<Vec<f64>>,
}

impl<I: Integrator> Observer<Components<I>> for ModeSeries<'_> {
    fn on_sample(&mut self, _: usize, _: u64, system: &Components<I>) {
        let w = &system.states[0];
        for (s, r) in self.out.iter_mut().zip(self.rows) {
            s.push(r.iter().zip(w).map(|(x, y)| x * y).sum());
        }
    }
}

/// Runs one cell.
fn run_cell(
    opts: &StabilityOptions,
    kind: IntegratorKind,
    elements: usize,
    a: f64,
) -> Result<Cell> {
    let (model, mut cell) = CellModel::new(opts, kind, elements, a)?;
    let (rates, mult) = (&model.rates, &model.mult);
    let n = rates.len();
    let total = opts.burn_in_steps + opts.sampled_steps;
    let worst = mult.iter().fold(0.0f64, |w, m| w.max(m.abs()));
    match model.integrator(kind) {
        Ok(_) => {}
        Err(e @ Error::UnstableTimeStep { .. }) => {
            cell.status = Status::Unstable;
            cell.refused = Some(e.to_string());
            // Forced run, bypassing the check, to show the refusal is warranted.
            cell.diverged_at = model.forced_run(opts, kind)?;
            cell.detail = match cell.diverged_at {
                Some(s) => format!(
                    "|m| = {worst:.3} >= 1: refused before running; forced, the state overflowed at step {s}"
                ),
                None => format!(
                    "|m| = {worst:.3} >= 1: refused before running; forced, still finite after {total} steps (growth too slow to overflow)"
                ),
            };
            return Ok(cell);
        }
        Err(e) => return Err(e),
    }
    let modes = checked_modes(rates, mult, opts.burn_in_steps, opts.sampled_steps);
    let n_resolvable = (0..n)
        .filter(|&i| {
            decay(mult[i]) * opts.burn_in_steps as f64 >= BURN_IN_DECAYS
                && decay(mult[i]) * opts.sampled_steps as f64 >= MIN_SAMPLED_DECAYS
        })
        .count();
    cell.unresolved_modes = n - n_resolvable;
    let projector = model.gm.projector(model.object.system(), n);
    let rows: Vec<Vec<f64>> = modes
        .iter()
        .map(|&i| projector.row(i).iter().copied().collect())
        .collect();
    let mut per_traj = Vec::new();
    for s in model.series(opts, kind, &rows, (elements, a)) {
        match s {
            Ok(s) => per_traj.push(s),
            Err(e @ Error::Diverged { .. }) => {
                cell.status = Status::Unstable;
                cell.detail = format!("predicted stable (|m| = {worst:.3}) but diverged: {e}");
                return Ok(cell);
            }
            Err(e) => return Err(e),
        }
    }
    let kt = model.object.system().kt();
    for (k, &i) in modes.iter().enumerate() {
        let m = model.mode_bias(kind, kt, &per_traj, (k, i))?;
        cell.predicted_max_bias = cell.predicted_max_bias.max((m.formula_ratio - 1.0).abs());
        cell.modes.push(m);
    }
    cell.detail = undamped_note(&cell, mult, total);
    Ok(cell)
}

/// Why some modes were not checked.
fn undamped_note(cell: &Cell, mult: &[f64], total: u64) -> String {
    let n = mult.len();
    if cell.unresolved_modes > 0 {
        format!(
            "; {} of {n} modes relax too slowly to be measured in {total} steps (|m| close to 1{})",
            cell.unresolved_modes,
            if mult[n - 1] < -0.9 {
                ": the stiff modes oscillate undamped, m -> -1"
            } else {
                ""
            }
        )
    } else {
        String::new()
    }
}

/// Classifies a simulated (not unstable) cell from the map-wide Holm decisions on its
/// bias tests, and writes its detail line.
fn classify(cell: &mut Cell, biased: bool) {
    let worst_mode = cell
        .modes
        .iter()
        .max_by(|x, y| x.z_bias.abs().total_cmp(&y.z_bias.abs()));
    cell.status = if biased {
        Status::Biased
    } else {
        Status::Stable
    };
    let undamped = std::mem::take(&mut cell.detail);
    let predicted = if cell.predicted_max_bias < 1e-12 {
        "0 (exact)".to_string()
    } else {
        format!("{:.2e}", cell.predicted_max_bias)
    };
    cell.detail = match worst_mode {
        None => format!("no mode resolved in this run{undamped}"),
        Some(m) if biased => format!(
            "mode {} variance ratio {:.4e} +- {:.1e} (formula {:.4e}), z = {:.1} against no bias{undamped}",
            m.mode, m.measured_ratio, m.std_error, m.formula_ratio, m.z_bias
        ),
        Some(m) => format!(
            "no bias resolved: largest |z| = {:.1} (mode {}, ratio {:.4} +- {:.4}); predicted largest bias {predicted}{undamped}",
            m.z_bias.abs(),
            m.mode,
            m.measured_ratio,
            m.std_error,
        ),
    };
}

/// Runs the stability study and writes `stability-cells.csv`, `stationary-bias.csv`,
/// `stability.json`, `stability-map-<integrator>.svg` and `stationary-bias.svg` in
/// `opts.out`, with their journal `stability.manifest.json`, after every simulation
/// ([`super::output`]); a rerun removes the maps of integrators it left out.
///
/// # Errors
/// Bad options (exit 2, naming the flag), a projected work or memory above
/// `opts.limits`; numerical or I/O failures.
pub fn run_stability(opts: &StabilityOptions) -> Result<StabilitySummary> {
    let start = Instant::now();
    let provenance = Provenance::begin(&[&opts.scene]);
    validate(opts)?;
    opts.limits.check(&projected_work(opts))?;
    let mut cells = run_cells(opts)?;
    classify_cells(&mut cells, opts.alpha);
    let (formula_tests, formula_rejections) = judge_formulas(&mut cells, opts.alpha);
    let stability_as_predicted = cells.iter().all(|c| match c.status {
        Status::Unstable => c.refused.is_some() && c.diverged_at.is_some(),
        _ => c.refused.is_none(),
    });
    let report = StudyReport::begin(&opts.out, "stability", STEM, provenance)?;
    write_outputs(&report, opts, &cells)?;
    let summary = StabilitySummary {
        run_id: report.run_id(),
        scene: opts.scene.name.clone(),
        seed: opts.scene.seed,
        noise: NoiseModel::Consistent.name().to_string(),
        alpha: opts.alpha,
        trajectories: opts.trajectories,
        burn_in_steps: opts.burn_in_steps,
        sampled_steps: opts.sampled_steps,
        formula_tests,
        formula_rejections,
        stability_as_predicted,
        cells,
        files: report.files(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    report.complete(&summary)?;
    Ok(summary)
}

/// Runs every cell of the map (rayon over cells), integrator-major, then elements,
/// then a.
fn run_cells(opts: &StabilityOptions) -> Result<Vec<Cell>> {
    let mut jobs = Vec::new();
    for &k in &opts.integrators {
        for &e in &opts.elements {
            for &a in &opts.dt_lambda_max {
                jobs.push((k, e, a));
            }
        }
    }
    jobs.par_iter()
        .map(|&(k, e, a)| {
            let t0 = Instant::now();
            let c = run_cell(opts, k, e, a);
            if opts.progress
                && let Ok(c) = &c
            {
                eprintln!(
                    "stability {k} {e} elements dt*lambda_max={a:e}: {} modes checked ({:.1} s)",
                    c.modes.len(),
                    t0.elapsed().as_secs_f64()
                );
            }
            c
        })
        .collect()
}

/// Holm at `alpha` over every bias test of the map: a simulated cell is biased if any of
/// its modes is rejected; classifies the simulated cells.
fn classify_cells(cells: &mut [Cell], alpha: f64) {
    let p_bias: Vec<f64> = cells
        .iter()
        .filter(|c| c.status != Status::Unstable)
        .flat_map(|c| c.modes.iter().map(|m| m.p_bias))
        .collect();
    let bias_decisions = stats::holm(&p_bias, alpha);
    let mut it = bias_decisions.iter();
    for c in cells.iter_mut().filter(|c| c.status != Status::Unstable) {
        let mut biased = false;
        for _ in &c.modes {
            biased |= it.next().is_some_and(|d| d.1);
        }
        classify(c, biased);
    }
}

/// Holm at `alpha` over every formula comparison of the map, marking the rejected
/// modes; returns the number of comparisons and of rejections.
fn judge_formulas(cells: &mut [Cell], alpha: f64) -> (usize, usize) {
    let p: Vec<f64> = cells
        .iter()
        .flat_map(|c| c.modes.iter().map(|m| m.p_formula))
        .collect();
    let decisions = stats::holm(&p, alpha);
    let mut it = decisions.iter();
    for c in cells.iter_mut() {
        for m in &mut c.modes {
            m.formula_rejected = it.next().is_some_and(|d| d.1);
        }
    }
    (p.len(), decisions.iter().filter(|d| d.1).count())
}

/// Writes the CSV tables and the figures of the output set through `report`.
fn write_outputs(report: &StudyReport, opts: &StabilityOptions, cells: &[Cell]) -> Result<()> {
    report.write("stability-cells.csv", cells_csv(cells)?.as_bytes())?;
    report.write("stationary-bias.csv", modes_csv(cells)?.as_bytes())?;
    for &k in &opts.integrators {
        let name = format!("stability-map-{}.svg", k.name());
        report.write_svg(&name, &map_figure(&opts.scene.name, k, cells))?;
    }
    report.write_svg(
        "stationary-bias.svg",
        &bias_figure(&opts.scene.name, &opts.integrators, cells),
    )
}

/// `stability-cells.csv`: one line per cell.
fn cells_csv(cells: &[Cell]) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        Path::new("stability-cells.csv"),
        &[
            "integrator",
            "elements",
            "dt_lambda_max",
            "dt_tau1",
            "max_multiplier",
            "status",
            "checked_modes",
            "unresolved_modes",
            "predicted_max_bias",
            "diverged_at",
            "detail",
        ],
    )?;
    for c in cells {
        table.record([
            c.integrator.to_string(),
            c.elements.to_string(),
            c.dt_lambda_max.to_string(),
            c.dt_tau1.to_string(),
            c.max_multiplier.to_string(),
            c.status.name().to_string(),
            c.modes.len().to_string(),
            c.unresolved_modes.to_string(),
            c.predicted_max_bias.to_string(),
            c.diverged_at.map(|s| s.to_string()).unwrap_or_default(),
            c.detail.clone(),
        ])?;
    }
    table.into_string()
}

/// `stationary-bias.csv`: one line per checked mode of every cell.
fn modes_csv(cells: &[Cell]) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        Path::new("stationary-bias.csv"),
        &[
            "integrator",
            "elements",
            "dt_lambda_max",
            "mode",
            "lambda_dt",
            "multiplier",
            "measured_ratio",
            "std_error",
            "formula_ratio",
            "z_formula",
            "p_formula",
            "formula_rejected",
            "z_bias",
            "p_bias",
        ],
    )?;
    for c in cells {
        for m in &c.modes {
            table.record([
                c.integrator.to_string(),
                c.elements.to_string(),
                c.dt_lambda_max.to_string(),
                m.mode.to_string(),
                m.lambda_dt.to_string(),
                m.multiplier.to_string(),
                m.measured_ratio.to_string(),
                m.std_error.to_string(),
                m.formula_ratio.to_string(),
                m.z_formula.to_string(),
                m.p_formula.to_string(),
                m.formula_rejected.to_string(),
                m.z_bias.to_string(),
                m.p_bias.to_string(),
            ])?;
        }
    }
    table.into_string()
}

/// A category label for a normalized step: `0.1`, `1.9`, `1000`, `1e5`.
fn step_label(a: f64) -> String {
    if a.abs() >= 1e4 {
        format!("{a:e}")
    } else {
        format!("{a}")
    }
}

/// The stability map of integrator `kind`: one disc per cell, coloured by its status
/// ([`Status::rgb`]), one column per normalized step Δt·λ_max and one row per element
/// count, as in the HTML table.
fn map_figure(scene: &str, kind: IntegratorKind, cells: &[Cell]) -> Figure {
    let mut steps: Vec<f64> = cells.iter().map(|c| c.dt_lambda_max).collect();
    steps.sort_by(f64::total_cmp);
    steps.dedup();
    let mut elements: Vec<usize> = cells.iter().map(|c| c.elements).collect();
    elements.sort_unstable();
    elements.dedup();
    let mut fig = Figure::new(
        format!("{scene}: stability map of {kind}"),
        "time step Δt·λ_max (dimensionless; one column per value, explicit limit 2)",
        "number of elements (dimensionless)",
    )
    .x_categories(steps.iter().map(|&a| step_label(a)).collect())
    .y_categories(elements.iter().map(ToString::to_string).collect())
    .caption(format!(
        "Stability map of {kind} with consistent noise: one disc per cell of time step \
         Δt·λ_max (λ_max the fastest rate of the mesh) and element count, coloured by \
         the cell's status: stable (green, no stationary bias resolved), biased (amber, \
         the stationary variance of a mode differs from kT/λ beyond its error) or \
         unstable (red, |m| ≥ 1: refused before running, diverging when forced). An \
         explicit scheme should turn red above Δt·λ_max = 2; implicit ones stay green or \
         amber."
    ));
    let index = |v: &[f64], x: f64| {
        v.iter()
            .position(|&y| y == x)
            .map_or(f64::NAN, |i| i as f64)
    };
    let elements_f: Vec<f64> = elements.iter().map(|&e| e as f64).collect();
    for status in [Status::Stable, Status::Biased, Status::Unstable] {
        let pts: Vec<(f64, f64)> = cells
            .iter()
            .filter(|c| c.integrator == kind.name() && c.status == status)
            .map(|c| {
                (
                    index(&steps, c.dt_lambda_max),
                    index(&elements_f, c.elements as f64),
                )
            })
            .collect();
        let (r, g, b) = status.rgb();
        // Every status gets a series, even an empty one, so that every map has the same
        // legend.
        fig = fig.series(
            Series::markers(status.name(), pts)
                .rgb(r, g, b)
                .marker_radius(11),
        );
    }
    fig
}

/// The measured stationary variance ratio of every checked mode against each
/// integrator's exact formula, one colour per integrator.
fn bias_figure(scene: &str, kinds: &[IntegratorKind], cells: &[Cell]) -> Figure {
    let mut fig = Figure::new(
        format!("{scene}: stationary variance per mode"),
        "λ·Δt of the mode (dimensionless)",
        "⟨aᵢ²⟩ / (kT/λᵢ) (dimensionless)",
    )
    .log_x()
    .log_y()
    .caption(
        "Stationary variance of every checked mode of every cell relative to kT/λ, \
         measured (markers, ±1 s.e.) against the integrator's exact discrete-time formula \
         (light line of the same colour), against the mode's λ·Δt. The markers should lie \
         on the line of their integrator; the line's distance from 1 is the integrator's \
         exact stationary bias.",
    );
    for (hue, &k) in kinds.iter().enumerate() {
        let modes: Vec<&ModeBias> = cells
            .iter()
            .filter(|c| c.integrator == k.name())
            .flat_map(|c| &c.modes)
            .collect();
        if modes.is_empty() {
            continue;
        }
        let (lo, hi) = modes.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
            (lo.min(m.lambda_dt), hi.max(m.lambda_dt))
        });
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|j| lo * (hi / lo).powf(j as f64 / 200.0))
            .filter_map(|x| k.stationary_variance_ratio(x, 1.0).map(|r| (x, r)))
            .collect();
        fig = fig
            .series(
                Series::markers(
                    format!("{k}: measured / formula"),
                    modes
                        .iter()
                        .map(|m| (m.lambda_dt, m.measured_ratio))
                        .collect(),
                )
                .with_errors(modes.iter().map(|m| m.std_error).collect())
                .palette(hue)
                .joined_with_next(),
            )
            .series(
                Series::line("", curve)
                    .with_style(SeriesStyle::Line)
                    .palette(hue)
                    .light(),
            );
    }
    fig
}
