//! Convergence studies (`langevin-fem converge`) of the linear scenes (here) and of the
//! compression scenes ([`compression`]: ⟨F⟩ at imposed strains against the exact
//! equilibrium theory).
//!
//! For each value of the refined parameter (the element count, or the time step Δt/τ1)
//! the scene is rebuilt with that value, the run is prepared ([`LinearRun::prepare`]) and
//! its ensemble simulated (rayon over trajectories, one PCG stream per trajectory, so the
//! result does not depend on the thread count). The observables are ⟨w²(L/2)⟩ and the
//! stationary variances of discrete modes 1–3. A membrane scene (plate elements, issue
//! #27) goes through the same code, branching only where the object differs
//! ([`StudyObject`]): its profile observable is ⟨h²⟩ at the centre (a/2, b/2), its modes
//! 1–3 are its slowest continuum modes (named with their (m, n)), both directions are
//! refined together (h = a/elements), and over elements it has one more, exact
//! observable: the plate's eigenvalue of mode 1 relative to the continuum's, λ_h/λ, with
//! no sampling. For each one and each value:
//!
//! - the ensemble estimate and its standard error (per trajectory and component:
//!   autocorrelation-aware errors from [`stats::variance_with_error`] /
//!   [`stats::mean_with_error`], added in quadrature, as in [`crate::verify::checks`]);
//! - the exact discrete reference (this mesh, noise model, integrator and Δt);
//! - the *limit* reference the refinement converges to: the continuum (eq. 2) for
//!   `--over elements`; for `--over dt` the Δt → 0 limit of the same mesh and noise model
//!   (the semi-discrete stationary covariance `S_ij = 2kT Σ_q,ij/(λ_i + λ_j)`), because the
//!   spatial error does not depend on Δt;
//! - the total error |estimate − limit| with the estimate's standard error, and the exact
//!   discretization/integrator error |discrete − limit| (no sampling).
//!
//! The observed order p of error ∝ h^p (h = L/elements, a/elements or Δt/τ1) is fitted by
//! weighted least squares on ln error against ln h ([`fit_order`]), using only points whose
//! total error exceeds [`FLOOR_SIGMAS`] standard errors; the others are flagged "sampling
//! floor". The order of the exact error is fitted on all points whose exact error is above
//! round-off ([`ROUNDING_FACTOR`]). Confidence intervals use Student's t with n − 2 degrees of
//! freedom (residual scale), so at least three points are needed for an interval. The
//! observed order *agrees* with the expected one when its interval holds it
//! ([`ObservableSummary::agrees`]); a disagreement is stated in the observable's note. An
//! exact observable (no sampling: its rows have a zero standard error) has no observed
//! order: its exact-error order is compared with the expected one instead.
//!
//! A value whose run diverges (a non-finite state, e.g. an explicit stretching force at a
//! too-large Δt) is recorded with the step it failed at, and one whose estimators fail
//! (a series too short for its correlation time) with the cause ([`FailedValue`]); the
//! study goes on with the other values.

use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::fem::beam::BeamModel;

use super::output::StudyReport;
use crate::fem::modal::{continuous_stationary_covariance, modal_noise_covariance};
use crate::fem::noise::{NoiseGenerator, NoiseModel};
use crate::fem::plate::PlateModel;
use crate::fem::plate_modes::PlateModes;
use crate::output::io::CsvWriter;
use crate::output::{AxisUnits, Figure, Provenance, Series};
use crate::rng::derive_seed;
use crate::scene::linear::{LinearRun, TrajectoryRecord, probe_of, small_slope_warning};
use crate::scene::validate::Num;
use crate::scene::{Budget, Ensemble, ModelKind, RunSpec, Scene};
use crate::spectral::membrane::{Membrane, MembraneMode, ModeShape};
use crate::stats;
use crate::work::{Origin, Part, WorkLimits, WorkProjection};
use serde::{Deserialize, Deserializer, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub mod compression;
pub mod shard;

/// A total error is resolved (not at the sampling floor) if it exceeds this many
/// standard errors.
pub const FLOOR_SIGMAS: f64 = 3.0;
/// An exact error below `ROUNDING_FACTOR · ε · λ_max/λ_1` of the limit reference is
/// round-off of the references themselves (a dense generalized eigen-decomposition,
/// whose relative accuracy on the slow modes is about ε·λ_max/λ_1): the discretization
/// is exact for that observable there and the point is left out of the fit.
pub const ROUNDING_FACTOR: f64 = 4.0;
/// Confidence level of the fitted-order intervals.
pub const CONFIDENCE: f64 = 0.95;
/// Number of modes reported (modes 1..=3).
pub const N_MODES: usize = 3;
/// Default element counts of `--over elements`.
pub const DEFAULT_ELEMENTS: [usize; 4] = [5, 10, 20, 40];
/// Default Δt/τ1 of `--over dt` for the unconditionally stable integrators.
pub const DEFAULT_DT_TAU1: [f64; 4] = [4e-3, 2e-3, 1e-3, 5e-4];
/// Default fractions of the stability limit of `--over dt` for euler-maruyama.
pub const DEFAULT_EM_FRACTIONS: [f64; 4] = [0.9, 0.5, 0.25, 0.125];
/// Allowed element counts (the references use a dense eigen-decomposition).
pub const ELEMENTS_RANGE: (usize, usize) = (2, 200);
/// Default element counts along x of `--over elements` for a membrane scene whose
/// coarsest of them resolves its modes 1–3 (along y the scene's aspect ratio of elements
/// is kept, [`rebuild`]; else multiplied, [`default_values`]). Even counts put the centre
/// (a/2, b/2) of a square mesh on a node in every mesh.
pub const DEFAULT_MEMBRANE_ELEMENTS: [usize; 3] = [4, 8, 16];
/// Allowed element counts of a membrane, along x and along y: the references decompose
/// the plate's 4(nx + 1)(ny + 1) unknowns densely (at 24 × 24 about 2500, seconds per
/// value). A mesh must also resolve the study's modes 1–3 (a simply supported mode
/// (m, n) needs m < nx and n < ny).
pub const MEMBRANE_ELEMENTS_RANGE: (usize, usize) = (2, 24);

/// Reads a number of a study's JSON summary back (`#[serde(deserialize_with)]`): the
/// JSON writer stores a non-finite `f64` as `null`, read back as NaN.
///
/// # Errors
/// The deserializer's, for anything but a number or `null`.
pub fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// [`nan_if_null`] for an optional pair of numbers (a confidence interval).
///
/// # Errors
/// The deserializer's, for anything but `null` or a pair of numbers or `null`s.
pub fn pair_nan_if_null<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<Option<(f64, f64)>, D::Error> {
    let pair = Option::<(Option<f64>, Option<f64>)>::deserialize(d)?;
    Ok(pair.map(|(a, b)| (a.unwrap_or(f64::NAN), b.unwrap_or(f64::NAN))))
}

/// The refined parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Over {
    /// Element count; h = L/elements.
    Elements,
    /// Time step; h = Δt/τ1.
    Dt,
}

impl Over {
    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Over::Elements => "elements",
            Over::Dt => "dt",
        }
    }

    /// What h is for this refinement: `L/elements` or `dt/tau1`.
    pub fn h_label(self) -> &'static str {
        match self {
            Over::Elements => "L/elements",
            Over::Dt => "dt/tau1",
        }
    }
}

/// A least-squares fit of ln error = ln C + p ln h.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrderFit {
    /// The fitted order p.
    #[serde(deserialize_with = "nan_if_null")]
    pub order: f64,
    /// Its standard error (residual scale, n − 2 degrees of freedom); `None` with two
    /// points.
    pub std_error: Option<f64>,
    /// The [`CONFIDENCE`] interval (Student's t, n − 2 degrees of freedom); `None` with
    /// two points.
    #[serde(deserialize_with = "pair_nan_if_null")]
    pub ci: Option<(f64, f64)>,
    /// The fitted prefactor C.
    #[serde(deserialize_with = "nan_if_null")]
    pub prefactor: f64,
    /// Number of points used.
    pub points: usize,
}

/// Fits the order p of `err ∝ h^p` by (weighted) least squares on ln err against ln h.
/// With `std_errors`, the weight of a point is (err/se)² (the inverse variance of ln err);
/// without, all weights are 1. Points with a non-positive or non-finite h, error or
/// standard error are ignored. Returns `None` with fewer than two usable points or a
/// single distinct h.
pub fn fit_order(h: &[f64], err: &[f64], std_errors: Option<&[f64]>) -> Option<OrderFit> {
    let mut pts = Vec::new();
    for i in 0..h.len().min(err.len()) {
        let w = match std_errors {
            Some(se) => {
                let s = *se.get(i)?;
                if !(s.is_finite() && s > 0.0) {
                    continue;
                }
                (err[i] / s).powi(2)
            }
            None => 1.0,
        };
        if h[i].is_finite() && h[i] > 0.0 && err[i].is_finite() && err[i] > 0.0 {
            pts.push((h[i].ln(), err[i].ln(), w));
        }
    }
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let WeightedLine {
        slope: order,
        intercept,
        sxx,
        rss,
    } = weighted_line(&pts)?;
    let (std_error, ci) = if n > 2 {
        let dof = (n - 2) as f64;
        let se = (rss / dof / sxx).sqrt();
        let t = StudentsT::new(0.0, 1.0, dof)
            .map(|d| d.inverse_cdf(0.5 + CONFIDENCE / 2.0))
            .unwrap_or(f64::NAN);
        (Some(se), Some((order - t * se, order + t * se)))
    } else {
        (None, None)
    };
    Some(OrderFit {
        order,
        std_error,
        ci,
        prefactor: intercept.exp(),
        points: n,
    })
}

/// A weighted least-squares line `y = intercept + slope·x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WeightedLine {
    /// The slope.
    pub slope: f64,
    /// The intercept.
    pub intercept: f64,
    /// `Σ w (x − x̄)²` (x̄ the weighted mean): the slope's variance is `1/sxx` when the
    /// weights are inverse variances.
    pub sxx: f64,
    /// The weighted residual sum of squares `Σ w (y − intercept − slope·x)²`.
    pub rss: f64,
}

/// The weighted least-squares line through the points `(x, y, w)`; `None` if the x do
/// not spread (`sxx` not positive). Serves [`fit_order`] and the coupled time-step study.
pub(crate) fn weighted_line(pts: &[(f64, f64, f64)]) -> Option<WeightedLine> {
    let sw: f64 = pts.iter().map(|p| p.2).sum();
    let xm = pts.iter().map(|p| p.2 * p.0).sum::<f64>() / sw;
    let ym = pts.iter().map(|p| p.2 * p.1).sum::<f64>() / sw;
    let sxx: f64 = pts.iter().map(|p| p.2 * (p.0 - xm).powi(2)).sum();
    if not_above(sxx, 0.0) {
        return None;
    }
    let sxy: f64 = pts.iter().map(|p| p.2 * (p.0 - xm) * (p.1 - ym)).sum();
    let slope = sxy / sxx;
    let intercept = ym - slope * xm;
    let rss = pts
        .iter()
        .map(|p| p.2 * (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    Some(WeightedLine {
        slope,
        intercept,
        sxx,
        rss,
    })
}

/// `a` is not above `b` (also when either is NaN).
fn not_above(a: f64, b: f64) -> bool {
    a.partial_cmp(&b) != Some(std::cmp::Ordering::Greater)
}

/// Whether each total error is at the sampling floor: not above [`FLOOR_SIGMAS`]
/// standard errors.
pub fn sampling_floor(err: &[f64], std_errors: &[f64]) -> Vec<bool> {
    err.iter()
        .zip(std_errors)
        .map(|(e, s)| not_above(*e, FLOOR_SIGMAS * s))
        .collect()
}

/// Number of sampled observables: the profile point and modes 1–3. Those after them
/// (the membrane's eigenvalue over elements) are exact, without sampling.
const SAMPLED: usize = 1 + N_MODES;

/// The object of a linear study, where the expected orders differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StudyObject {
    /// The filament (Hermite-cubic beam elements).
    Filament {
        /// Whether x = L/2 is a mesh node for every value studied.
        node_at_mid: bool,
        /// Whether the ends allow rigid motion (issue #29), projected out of the field.
        rigid: bool,
    },
    /// The membrane (Bogner–Fox–Schmit plate elements).
    Membrane {
        /// Whether the centre (a/2, b/2) sits alike in every mesh studied (the parities
        /// of nx and ny the same for every value: a node, or inside an element, for all).
        centre_alike: bool,
    },
}

/// A membrane mode's label: `(m,n)`, with `cos`/`sin` for the two real modes of a
/// periodic lattice point.
fn mode_label(m: MembraneMode) -> String {
    let shape = match m.shape {
        ModeShape::SineSine => "",
        ModeShape::Cosine => "cos",
        ModeShape::Sine => "sin",
    };
    format!("({},{}){shape}", m.m, m.n)
}

/// The observables of a study of `scene` over `over`. A filament: `0` is ⟨w²(L/2)⟩,
/// `1..=3` the variances of modes 1–3 (`w2(L/2)`, `mode1`, …). A membrane: `0` is ⟨h²⟩ at
/// the centre (`h2(a/2,b/2)`), `1..=3` the variances of its three slowest modes, named
/// with their indices (`mode1(1,1)`, …), and over elements `4`, exact (no sampling), the
/// plate's eigenvalue of mode 1 over the continuum's (`lambda_h/lambda(1,1)`, limit 1).
///
/// # Errors
/// A membrane's invalid parameters ([`Membrane::new`], [`Membrane::modes`]).
pub fn observable_names(scene: &Scene, over: Over) -> Result<Vec<String>> {
    let Some(p) = scene.membrane else {
        return Ok(std::iter::once("w2(L/2)".to_string())
            .chain((1..=N_MODES).map(|n| format!("mode{n}")))
            .collect());
    };
    let modes = Membrane::new(p)?.modes(N_MODES)?;
    let mut names = vec!["h2(a/2,b/2)".to_string()];
    names.extend(
        modes
            .iter()
            .enumerate()
            .map(|(i, m)| format!("mode{}{}", i + 1, mode_label(*m))),
    );
    if over == Over::Elements {
        names.push(format!("lambda_h/lambda{}", mode_label(modes[0])));
    }
    Ok(names)
}

/// The exact references of one value of the refined parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointReference {
    /// The value (element count or Δt/τ1).
    pub value: f64,
    /// h: L/elements (a membrane: a/elements), or Δt/τ1.
    pub h: f64,
    /// Exact discrete value per observable (order of [`observable_names`]).
    pub discrete: Vec<f64>,
    /// Limit reference per observable (continuum, or the Δt → 0 limit of this mesh).
    pub limit: Vec<f64>,
    /// Relative round-off level of the references, [`ROUNDING_FACTOR`]·ε·λ_max/λ_1.
    pub rounding_rel: f64,
}

/// The expected order of the error of one observable, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Expected {
    /// The order, if the theory predicts a power law; `None` if the discretization is
    /// exact for this observable or no single order applies.
    pub order: Option<f64>,
    /// Whether the error is exactly zero (up to round-off).
    pub exact: bool,
    /// The reason.
    pub why: String,
}

/// The expected order of the error of observable `obs` (index into
/// [`observable_names`]) when refining `over` with this run's integrator and noise, on
/// `object` (a filament, with whether x = L/2 is a mesh node for every value studied, or
/// a membrane).
pub fn expected_order(over: Over, spec: &RunSpec, obs: usize, object: StudyObject) -> Expected {
    match over {
        Over::Elements => expected_over_elements(spec, obs, object),
        Over::Dt => expected_over_dt(spec, obs, matches!(object, StudyObject::Membrane { .. })),
    }
}

/// An expected order with its reason.
fn expected(order: Option<f64>, exact: bool, why: &str) -> Expected {
    Expected {
        order,
        exact,
        why: why.to_string(),
    }
}

/// [`expected_order`] over the element count.
fn expected_over_elements(spec: &RunSpec, obs: usize, object: StudyObject) -> Expected {
    let exact_stationary = matches!(
        spec.integrator,
        IntegratorKind::CrankNicolson | IntegratorKind::ExactModal
    );
    let e = expected;
    if obs >= SAMPLED {
        return e(
            Some(4.0),
            false,
            "the plate's eigenvalue of the mode: Bogner-Fox-Schmit (bicubic Hermite) elements are a conforming Rayleigh-Ritz discretization, so lambda_h >= lambda, and the error lambda_h/lambda - 1 > 0 is O(h^4) (2(k+1-m), k = 3, m = 2); exact (no sampling), whatever the integrator, noise and dt",
        );
    }
    if !exact_stationary {
        return e(
            None,
            false,
            "the integrator's stationary bias at fixed dt (O(lambda dt) per mode) does not vanish as h -> 0, and grows with lambda_max for sums over modes: no order in h",
        );
    }
    match (spec.noise, obs, object) {
        (
            NoiseModel::Consistent,
            0,
            StudyObject::Filament {
                node_at_mid: true,
                rigid: true,
            },
        ) => e(
            Some(4.0),
            false,
            "kT K^-1 is exact at nodes, but the field is the elastic part, the rigid motion projected out: the continuum's projection also removes the rigid part of the element bubbles (the clamped-clamped fluctuations between nodes), which the model lacks, so the nodal variance falls below the continuum by (kT/EI) sum over elements of the bubbles' rigid projection, O(h^4) (the oracle's closed form)",
        ),
        (
            NoiseModel::Consistent,
            0,
            StudyObject::Filament {
                node_at_mid: true, ..
            },
        ) => e(
            None,
            true,
            "consistent noise with an exact-stationary integrator gives the covariance kT K^-1, whose nodal values are exact for Hermite cubics (the beam's Green's function is piecewise cubic): zero error, no order",
        ),
        (NoiseModel::Consistent, 0, StudyObject::Filament { .. }) => e(
            None,
            false,
            "kT K^-1 is exact at nodes (zero error there); where x = L/2 lies inside an element (odd element counts) the interpolated variance falls below the continuum by the energy-norm error of the point-load response, about h^3: no single order over these meshes",
        ),
        (NoiseModel::Consistent, 0, StudyObject::Membrane { centre_alike: true }) => e(
            Some(2.0),
            false,
            "consistent noise with an exact-stationary integrator gives the covariance kT K^-1: the centre variance is the plate's energy of its response to a point load there, below the continuum by the energy-norm error of that response (Galerkin); the biharmonic point-load response (r^2 ln r) makes this O(h^2), as does the modal tail sum 4kT/(ab kappa q^4) over the 2D modes beyond q ~ pi/h. Unlike the beam's, the plate's nodal values are not exact. Measured from the exact references (simply supported square, kappa = kT = 1): error/h^2 -> 0.0021 with the centre on a node, 0.0058 inside an element",
        ),
        (NoiseModel::Consistent, 0, StudyObject::Membrane { .. }) => e(
            None,
            false,
            "the centre variance converges as h^2 from below (the energy-norm error of the point-load response), but with a different constant where (a/2, b/2) is a node (even counts; simply supported square: about 0.0021 h^2 kT/kappa) and where it lies inside an element (odd counts: about 0.0058 h^2 kT/kappa): no single power law over meshes of both kinds",
        ),
        (NoiseModel::Consistent, _, StudyObject::Filament { .. }) => e(
            Some(4.0),
            false,
            "the variance is kT/lambda_i^h; Hermite-cubic generalized eigenvalues converge as h^4 (2(k+1-m), k = 3, m = 2)",
        ),
        (NoiseModel::Consistent, _, StudyObject::Membrane { .. }) => e(
            Some(4.0),
            false,
            "the variance is kT/lambda_h of the plate's mode; Bogner-Fox-Schmit (bicubic Hermite) eigenvalues converge as h^4 from above (2(k+1-m), k = 3, m = 2), so the variance converges as h^4 from below",
        ),
        (NoiseModel::ElementUniform, 0, StudyObject::Filament { .. }) => e(
            Some(2.0),
            false,
            "the element-uniform noise (eq. 5) under-excites every mode by about (i pi h/L)^2/12; the profile sums these h^2 deficits (plus the h^4 eigenvalue error)",
        ),
        (NoiseModel::ElementUniform, 0, StudyObject::Membrane { .. }) => e(
            None,
            false,
            "element-uniform noise under-excites every mode by about (q_x^2 h_x^2 + q_y^2 h_y^2)/12; summed over the 2D modes at the centre (sum 1/q^2 up to q ~ pi/h) these deficits give about h^2 ln(1/h)/(24 pi) kT/kappa (simply supported square; measured from the exact references: 0.0134 h^2 ln(1/h)): no pure power law, the fitted order over 4-24 elements is about 1.6-1.75, tending to 2 only logarithmically",
        ),
        (NoiseModel::ElementUniform, _, StudyObject::Filament { .. }) => e(
            Some(2.0),
            false,
            "element-uniform noise (eq. 5): stationary variance (Phi^T Sigma Phi)_ii kT/lambda_i, deficit about (i pi h/L)^2/12, order h^2 (dominates the h^4 eigenvalue error)",
        ),
        (NoiseModel::ElementUniform, _, StudyObject::Membrane { .. }) => e(
            Some(2.0),
            false,
            "element-uniform noise (a uniform load per element area): stationary variance (Phi^T Sigma Phi)_ii kT/lambda_i, deficit about (q_x^2 h_x^2 + q_y^2 h_y^2)/12, order h^2 (dominates the h^4 eigenvalue error)",
        ),
    }
}

/// [`expected_order`] over Δt, for a membrane's study if `membrane`.
fn expected_over_dt(spec: &RunSpec, obs: usize, membrane: bool) -> Expected {
    let e = expected;
    match spec.integrator {
        IntegratorKind::CrankNicolson => e(
            None,
            true,
            "Crank-Nicolson: m = (1-a/2)/(1+a/2), g^2 = 2kT dt/(1+a/2)^2 give S_ij = 2kT Sigma_q,ij/(lambda_i+lambda_j) exactly for any dt, any noise model: zero error, no order",
        ),
        IntegratorKind::ExactModal if spec.noise == NoiseModel::Consistent || obs > 0 => e(
            None,
            true,
            "exact OU update per mode: the stationary variance of every mode is kT Sigma_q,ii/lambda_i at any dt: zero error, no order",
        ),
        IntegratorKind::ExactModal => e(
            None,
            false,
            "exact OU update with element-uniform noise: the modal variances are exact, but the cross-covariances of modes (correlated by eq. 5 noise) are not, by O((lambda dt)^2) for resolved modes: no single order",
        ),
        IntegratorKind::EulerMaruyama if obs == 0 && membrane => e(
            Some(1.0),
            false,
            "Euler-Maruyama: every mode's variance is multiplied by 1/(1 - lambda dt/2); at a fixed mesh the error at the profile point is dt kT/2 sum_i phi_i(a/2, b/2)^2 + O(dt^2): order 1",
        ),
        IntegratorKind::EulerMaruyama if obs == 0 => e(
            Some(1.0),
            false,
            "Euler-Maruyama: every mode's variance is multiplied by 1/(1 - lambda dt/2); at a fixed mesh the profile error is dt kT/2 sum_i phi_i(L/2)^2 + O(dt^2): order 1",
        ),
        IntegratorKind::EulerMaruyama => e(
            Some(1.0),
            false,
            "Euler-Maruyama stationary variance ratio 1/(1 - lambda dt/2): bias O(lambda dt), order 1",
        ),
        IntegratorKind::BackwardEuler if obs == 0 && membrane => e(
            Some(1.0),
            false,
            "backward Euler: each mode's variance is multiplied by 1/(1 + lambda dt/2): order 1 once lambda_max dt << 1; while lambda_max dt >> 1 the modes above lambda dt ~ 1 are frozen and the membrane's sum over its 2D modes (sum 1/q^4 beyond q ~ dt^(-1/4)) gives about dt^(1/2), so the observed order lies between 1/2 and 1",
        ),
        IntegratorKind::BackwardEuler if obs == 0 => e(
            Some(1.0),
            false,
            "backward Euler: each mode's variance is multiplied by 1/(1 + lambda dt/2): order 1 once lambda_max dt << 1; while lambda_max dt >> 1 the modes above lambda dt ~ 1 are frozen and the continuum-like sum gives about dt^(3/4), so the observed order lies between 3/4 and 1",
        ),
        IntegratorKind::BackwardEuler => e(
            Some(1.0),
            false,
            "backward Euler stationary variance ratio 1/(1 + lambda dt/2): bias O(lambda dt), order 1",
        ),
        IntegratorKind::MetropolisCrankNicolson => e(
            None,
            true,
            "on the linear problem every Crank-Nicolson proposal is accepted: exact",
        ),
    }
}

/// Rebuilds `scene` for one value of the study: sets the element count (a membrane's in
/// both directions, [`membrane_elements_y`]) or the run's Δt/τ1, samples modes 1–3 and
/// the profile at x/L = 0.5 (a membrane: x/a = 0.5 on its midline y = b/2, its centre),
/// and drops the two-time points (not reported here).
pub fn rebuild(scene: &Scene, run: usize, over: Over, value: f64) -> Scene {
    let mut s = scene.clone();
    match over {
        Over::Elements => {
            let nx = value.round() as usize;
            if s.is_membrane() && s.mesh.elements_y.is_some() {
                s.mesh.elements_y = Some(membrane_elements_y(scene, nx));
            }
            s.mesh.elements = nx;
        }
        Over::Dt => s.runs[run].dt_tau1 = value,
    }
    s.sampling.modes = N_MODES;
    s.sampling.profile_points = vec![0.5];
    s.sampling.two_time.clear();
    s
}

/// The element count along y of membrane `scene` refined to `nx` elements along x: the
/// scene's aspect ratio of elements kept, round(nx · ny₀/nx₀) (`nx` if the scene gives no
/// `mesh.elements_y`).
pub fn membrane_elements_y(scene: &Scene, nx: usize) -> usize {
    match scene.mesh.elements_y {
        Some(ny0) => ((nx * ny0) as f64 / scene.mesh.elements as f64).round() as usize,
        None => nx,
    }
}

/// The mesh of `scene` in words: its element count, a membrane's `nx x ny`.
fn mesh_text(scene: &Scene) -> String {
    if scene.is_membrane() {
        format!(
            "{} x {}",
            scene.mesh.elements,
            scene.mesh.elements_along_y()
        )
    } else {
        scene.mesh.elements.to_string()
    }
}

/// The Δt → 0 limit of the mesh of the prepared run `lr` (whichever object it is) with
/// the noise model of `spec`: the variance at the profile point and those of modes 1–3
/// from the semi-discrete stationary covariance `S_ij = 2kT Σ_q,ij/(λ_i + λ_j)` of the
/// object's linear system (its generalized modes, the modal covariance of the noise).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--scene` if the run has no finite-element object;
/// numerical failures of the modes or of the noise covariance.
fn semi_discrete_limit(scene: &Scene, lr: &LinearRun, spec: &RunSpec) -> Result<Vec<f64>> {
    let object = lr
        .fem_object()
        .ok_or_else(|| Error::invalid("--scene", &scene.name, "a finite-element scene"))?;
    let system = object.system();
    let gm = object.modes()?;
    let sq = modal_noise_covariance(&gm, &NoiseGenerator::new(spec.noise, system)?.covariance());
    let s = continuous_stationary_covariance(&sq, &gm.rates, system.kt());
    let x = lr.reference.profile_x[0];
    let a = probe_of(system.n_dofs(), &gm.vectors, |e| object.value_at(e, x));
    let mut out = vec![(a.transpose() * &s * &a)[(0, 0)]];
    out.extend((0..N_MODES).map(|i| s[(i, i)]));
    Ok(out)
}

/// h of a value: L/elements (a membrane: a/elements, its element width), or Δt/τ1.
fn h_of(scene: &Scene, over: Over, value: f64) -> f64 {
    match (over, scene.membrane) {
        (Over::Elements, None) => scene.filament.length / value,
        (Over::Elements, Some(m)) => m.width / value,
        (Over::Dt, _) => value,
    }
}

/// What h is for a study of `scene` over `over`: `L/elements`, `a/elements` (a membrane)
/// or `dt/tau1`.
fn h_label(scene: &Scene, over: Over) -> &'static str {
    match over {
        Over::Elements if scene.is_membrane() => "a/elements",
        _ => over.h_label(),
    }
}

/// Prepares run `run` of `scene` rebuilt for `value`, mapping an unstable time step to a
/// message naming `--values`.
fn prepare(scene: &Scene, run: usize, over: Over, value: f64) -> Result<(Scene, LinearRun)> {
    let s = rebuild(scene, run, over, value);
    let spec = s.runs[run].clone();
    let lr = LinearRun::prepare(&s, &spec).map_err(|e| match e {
        Error::UnstableTimeStep { limit, .. } => {
            let limit_tau1 = limit / s.tau1();
            match over {
                Over::Dt => Error::invalid(
                    "--values",
                    value,
                    format!(
                        "< {limit_tau1:.4e} (dt_tau1: the stability limit 2/lambda_max of {} with {} elements)",
                        spec.integrator,
                        mesh_text(&s)
                    ),
                ),
                Over::Elements => Error::invalid(
                    "--values",
                    value,
                    format!(
                        "an element count whose stability limit of {} exceeds the run's dt_tau1 = {:e} (with {} elements the limit is {limit_tau1:.4e}); use fewer elements or a stable integrator such as crank-nicolson",
                        spec.integrator,
                        spec.dt_tau1,
                        mesh_text(&s)
                    ),
                ),
            }
        }
        other => other,
    })?;
    Ok((s, lr))
}

/// The exact references (no simulation) of every value of the study.
///
/// # Errors
/// As [`LinearRun::prepare`]; an unstable Δt is reported against `--values`.
pub fn exact_study(
    scene: &Scene,
    run: usize,
    over: Over,
    values: &[f64],
) -> Result<Vec<PointReference>> {
    let prepared = values
        .iter()
        .map(|&v| prepare(scene, run, over, v))
        .collect::<Result<Vec<_>>>()?;
    let limit_dt = match (over, prepared.first()) {
        (Over::Dt, Some((_, lr))) => Some(semi_discrete_limit(scene, lr, &scene.runs[run])?),
        _ => None,
    };
    Ok(prepared
        .iter()
        .zip(values)
        .map(|((_, lr), &v)| reference_point(scene, lr, over, v, limit_dt.as_deref()))
        .collect())
}

fn reference_point(
    scene: &Scene,
    lr: &LinearRun,
    over: Over,
    value: f64,
    limit_dt: Option<&[f64]>,
) -> PointReference {
    let r = &lr.reference;
    let mut discrete = vec![r.profile_discrete[0]];
    discrete.extend(r.modes.iter().take(N_MODES).map(|m| m.variance_discrete));
    let mut limit = match limit_dt {
        Some(l) => l.to_vec(),
        None => {
            let mut c = vec![r.profile_continuum[0]];
            c.extend(r.modes.iter().take(N_MODES).map(|m| m.variance_continuum));
            c
        }
    };
    let rate1 = lr.reference.modes[0]
        .rate_discrete
        .unwrap_or(lr.reference.modes[0].rate_continuum);
    if scene.is_membrane() && over == Over::Elements {
        // The exact observable: λ_h/λ of mode 1, kT/λ over kT/λ_h.
        let m = &r.modes[0];
        discrete.push(m.variance_continuum / m.variance_equipartition);
        limit.push(1.0);
    }
    PointReference {
        value,
        h: h_of(scene, over, value),
        discrete,
        limit,
        rounding_rel: ROUNDING_FACTOR * f64::EPSILON * lr.reference.max_rate / rate1,
    }
}

/// Default values of the study for run `run` of `scene`.
///
/// # Errors
/// From the stability-limit computation (euler-maruyama over dt).
pub fn default_values(scene: &Scene, run: usize, over: Over) -> Result<Vec<f64>> {
    Ok(match over {
        Over::Elements if scene.is_membrane() => membrane_default_elements(scene)?,
        Over::Elements => DEFAULT_ELEMENTS.iter().map(|&n| n as f64).collect(),
        // Schemes with a stability limit (the explicit ones): fractions of that limit.
        Over::Dt if scene.runs[run].integrator.stability_limit(1.0).is_some() => {
            if let Some(m) = scene.membrane {
                let plate = PlateModel::new(m, scene.mesh.elements, scene.mesh.elements_along_y())?;
                let limit = scene.runs[run]
                    .integrator
                    .stability_limit(plate.max_rate()?)
                    .unwrap_or(f64::INFINITY)
                    / scene.tau1();
                return Ok(DEFAULT_EM_FRACTIONS.iter().map(|f| f * limit).collect());
            }
            let p = scene.filament;
            let beam = BeamModel::with_ends(p, scene.mesh.build(p.length)?, scene.ends)?;
            let limit = scene.runs[run]
                .integrator
                .stability_limit(beam.max_rate()?)
                .unwrap_or(f64::INFINITY)
                / scene.tau1();
            DEFAULT_EM_FRACTIONS.iter().map(|f| f * limit).collect()
        }
        Over::Dt => DEFAULT_DT_TAU1.to_vec(),
    })
}

/// The default element counts along x of a membrane: [`DEFAULT_MEMBRANE_ELEMENTS`] if
/// its coarsest mesh resolves the study's modes 1–3 ([`membrane_resolves`], the y count at
/// the scene's aspect ratio of elements, [`membrane_elements_y`]); else s, 2s, 4s (s, 2s,
/// 3s where 4s exceeds the cap) from the coarsest count s ≥ 4 that resolves them, one
/// with both counts even (the centre on a node) if there is one. Counts are kept where
/// both directions are within [`MEMBRANE_ELEMENTS_RANGE`]. A square mesh of a square or
/// a 2 × 1 rectangle: 4, 8, 16.
///
/// # Errors
/// As [`PlateModel::new`] and [`PlateModes::new`]; [`Error::InvalidParameter`] naming
/// `--values` if fewer than two counts remain.
fn membrane_default_elements(scene: &Scene) -> Result<Vec<f64>> {
    let (_, hi) = MEMBRANE_ELEMENTS_RANGE;
    let first = DEFAULT_MEMBRANE_ELEMENTS[0];
    let within = |n: usize| n <= hi && membrane_elements_y(scene, n) <= hi;
    let counts: Vec<usize> = if membrane_resolves(scene, first)? {
        DEFAULT_MEMBRANE_ELEMENTS.to_vec()
    } else {
        let mut resolving = Vec::new();
        for n in first..=hi / 2 {
            if membrane_resolves(scene, n)? {
                resolving.push(n);
            }
        }
        let even =
            |n: &&usize| n.is_multiple_of(2) && membrane_elements_y(scene, **n).is_multiple_of(2);
        match resolving.iter().find(even).or(resolving.first()) {
            Some(&s) if within(4 * s) => vec![s, 2 * s, 4 * s],
            Some(&s) => vec![s, 2 * s, 3 * s],
            None => Vec::new(),
        }
    };
    let values: Vec<f64> = counts
        .into_iter()
        .filter(|&n| within(n))
        .map(|n| n as f64)
        .collect();
    if values.len() < 2 {
        return Err(Error::invalid(
            "--values",
            "(not given)",
            format!(
                "element counts given explicitly: at the aspect ratio of elements of {} ({} x {}) fewer than two default counts resolve the study's modes with at most {hi} elements a side",
                scene.path.display(),
                scene.mesh.elements,
                scene.mesh.elements_along_y()
            ),
        ));
    }
    Ok(values)
}

/// Whether the mesh of membrane `scene` refined to `nx` elements along x (and
/// [`membrane_elements_y`] along y) resolves the study's modes 1–3: each has an acoustic
/// plate mode ([`PlateModes::acoustic`]), as the run's references need.
///
/// # Errors
/// As [`PlateModel::new`] and [`PlateModes::new`]; `Ok(false)` for a y count below 1.
fn membrane_resolves(scene: &Scene, nx: usize) -> Result<bool> {
    let Some(p) = scene.membrane else {
        return Ok(true);
    };
    let ny = membrane_elements_y(scene, nx);
    if ny == 0 {
        return Ok(false);
    }
    let modes = PlateModes::new(&PlateModel::new(p, nx, ny)?)?;
    Ok(Membrane::new(p)?
        .modes(N_MODES)?
        .iter()
        .all(|m| modes.acoustic(*m).is_some()))
}

/// Validates the element counts of a study of membrane `scene`: integers within
/// [`MEMBRANE_ELEMENTS_RANGE`] along x, and along y at the scene's aspect ratio of
/// elements ([`membrane_elements_y`]), whose meshes resolve the study's modes 1–3.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--values`, the value and the allowed range.
pub fn validate_membrane_elements(scene: &Scene, values: &[f64]) -> Result<()> {
    let (lo, hi) = MEMBRANE_ELEMENTS_RANGE;
    let file = scene.path.display();
    for &v in values {
        if !(v.fract() == 0.0 && v >= lo as f64 && v <= hi as f64) {
            return Err(Error::invalid(
                "--values",
                v,
                format!(
                    "integer element counts in [{lo}, {hi}] for a membrane ({file}: the references decompose the plate's 4(nx+1)(ny+1) unknowns densely)"
                ),
            ));
        }
        let ny = membrane_elements_y(scene, v as usize);
        if !(lo..=hi).contains(&ny) {
            return Err(Error::invalid(
                "--values",
                v,
                format!(
                    "element counts whose count along y, round({v} x {}/{}) = {ny} at the aspect ratio of elements of {file}, is in [{lo}, {hi}] too",
                    scene.mesh.elements_along_y(),
                    scene.mesh.elements
                ),
            ));
        }
        if !membrane_resolves(scene, v as usize)? {
            let labels: Vec<String> = match scene.membrane {
                Some(p) => Membrane::new(p)?
                    .modes(N_MODES)?
                    .into_iter()
                    .map(mode_label)
                    .collect(),
                None => Vec::new(),
            };
            return Err(Error::invalid(
                "--values",
                v,
                format!(
                    "element counts whose {v} x {ny} mesh of {file} resolves the study's modes {} (a simply supported mode (m,n) needs m < nx and n < ny; a periodic one 2|m| < nx and 2|n| < ny)",
                    labels.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Validates the values of a study: at least two, distinct, in range.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--values`.
pub fn validate_values(over: Over, values: &[f64]) -> Result<()> {
    if values.len() < 2 {
        return Err(Error::invalid(
            "--values",
            format!("{} value(s)", values.len()),
            "at least 2 distinct values (3 or more for a confidence interval)",
        ));
    }
    for &v in values {
        match over {
            Over::Elements => {
                let (lo, hi) = ELEMENTS_RANGE;
                if !(v.fract() == 0.0 && v >= lo as f64 && v <= hi as f64) {
                    return Err(Error::invalid(
                        "--values",
                        v,
                        format!("integer element counts in [{lo}, {hi}]"),
                    ));
                }
            }
            Over::Dt => {
                // Below 1e-9 tau1 a study would take over 1e9 steps per tau1, and the
                // slowest mode's multiplier rounds to 1 long before double precision
                // ends: refused here, naming the flag.
                if !(v.is_finite() && (1e-9..=100.0).contains(&v)) {
                    return Err(Error::invalid(
                        "--values",
                        v,
                        "dt_tau1 values in (0, 100], at least 1e-9",
                    ));
                }
            }
        }
    }
    for (i, v) in values.iter().enumerate() {
        if values[..i].contains(v) {
            return Err(Error::invalid(
                "--values",
                v,
                "distinct values (this one is repeated)",
            ));
        }
    }
    Ok(())
}

/// Options of a convergence study.
#[derive(Debug, Clone)]
pub struct ConvergeOptions {
    /// The scene (linear, model = "fem", or compression).
    pub scene: Scene,
    /// The run's name (default: the scene's first run).
    pub run: Option<String>,
    /// What is refined.
    pub over: Over,
    /// The values (default: [`default_values`], or
    /// [`compression::default_values`] for compression scenes).
    pub values: Option<Vec<f64>>,
    /// Another integrator for the run (its noise, time step and ensembles kept).
    pub integrator: Option<IntegratorKind>,
    /// Strains ε/ε_c0 whose ⟨F⟩ is studied (compression scenes only; default
    /// [`compression::DEFAULT_STRAIN_RATIOS`]).
    pub strain_ratios: Option<Vec<f64>>,
    /// Ensemble budget.
    pub budget: Budget,
    /// Overrides the budget's number of trajectories per value.
    pub trajectories: Option<usize>,
    /// Overrides the budget's sampled duration per trajectory (τ1).
    pub duration_tau1: Option<f64>,
    /// Output directory.
    pub out: PathBuf,
    /// Progress lines on stderr.
    pub progress: bool,
    /// The caps on the study's projected work and memory ([`projected_work`]), checked
    /// before any simulation.
    pub limits: WorkLimits,
    /// The shards whose records a merge reads instead of simulating (issue #15,
    /// [`shard`]); `None` simulates every trajectory.
    pub merge: Option<std::sync::Arc<crate::shard::ShardSet>>,
}

/// The projected work of a study of run `run` of `scene` with `ensemble` at `values`
/// (and, for a compression scene, at `strains`): one part per value, each the work of
/// the scene rebuilt for it ([`Scene::run_work`]); the values run one after the other.
pub fn projected_work(
    scene: &Scene,
    run: usize,
    opts: &ConvergeOptions,
    ensemble: Ensemble,
    values: &[f64],
    strains: Option<&[f64]>,
) -> WorkProjection {
    let b = opts.budget.name();
    // A flag as given, or the scene's key it defaults to.
    let source = |flag: &str, given: bool, key: &str, v: String| {
        if given {
            format!("{flag} {v}")
        } else {
            format!("{flag} not given: runs[{run}].{b}.{key} = {v}")
        }
    };
    let mut drivers = vec![
        format!("--values ({} values)", values.len()),
        source(
            "--trajectories",
            opts.trajectories.is_some(),
            "trajectories",
            ensemble.trajectories.to_string(),
        ),
        source(
            "--duration-tau1",
            opts.duration_tau1.is_some(),
            "duration_tau1",
            Num(ensemble.duration_tau1).to_string(),
        ),
    ];
    let mut flags = "--values, --trajectories, --duration-tau1".to_string();
    if let Some(st) = strains {
        drivers.push(format!("--strain-ratios ({} strains)", st.len()));
        flags.push_str(", --strain-ratios");
    }
    let parts = values
        .iter()
        .map(|&v| {
            let s = match strains {
                Some(st) => compression::rebuild(scene, run, opts.over, v, st),
                None => rebuild(scene, run, opts.over, v),
            };
            let name = s.runs.get(run).map_or("?", |r| r.name.as_str());
            Part {
                label: format!("{} {name} at {}={}", s.name, opts.over.name(), Num(v)),
                drivers: format!(
                    "{} ({} elements, dt_tau1 = {})",
                    drivers.join(", "),
                    mesh_text(&s),
                    Num(s.runs.get(run).map_or(f64::NAN, |r| r.dt_tau1))
                ),
                origin: Origin::Flags(flags.clone()),
                work: s.run_work(run, &ensemble, None),
            }
        })
        .collect();
    WorkProjection {
        command: format!(
            "converge --scene {} --over {}",
            scene.name,
            opts.over.name()
        ),
        parts,
    }
}

/// Allowed `--trajectories` of a study.
pub const TRAJECTORIES_RANGE: (usize, usize) = (1, 100_000);
/// Allowed `--duration-tau1` of a study (τ1).
pub const DURATION_RANGE: (f64, f64) = (1.0, 1.0e6);

/// The ensemble of a study: the run's ensemble at the budget, with the options'
/// overrides.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--trajectories` or `--duration-tau1`.
pub fn study_ensemble(opts: &ConvergeOptions, spec: &RunSpec) -> Result<Ensemble> {
    let mut e = spec.ensemble(opts.budget);
    if let Some(n) = opts.trajectories {
        let (lo, hi) = TRAJECTORIES_RANGE;
        if !(lo..=hi).contains(&n) {
            return Err(Error::invalid(
                "--trajectories",
                n,
                format!("an integer in [{lo}, {hi}]"),
            ));
        }
        e.trajectories = n;
    }
    if let Some(d) = opts.duration_tau1 {
        let (lo, hi) = DURATION_RANGE;
        if !(d.is_finite() && (lo..=hi).contains(&d)) {
            return Err(Error::invalid(
                "--duration-tau1",
                d,
                format!("a duration in [{lo}, {hi:e}] tau1"),
            ));
        }
        e.duration_tau1 = d;
    }
    if e.target_std_error.is_some() && e.duration_tau1.is_nan() {
        // A budget by target precision chooses its duration per strain; a study compares
        // values at one fixed ensemble.
        let (lo, hi) = DURATION_RANGE;
        return Err(Error::invalid(
            "--duration-tau1",
            "(not given)",
            format!(
                "a duration in [{lo}, {hi:e}] tau1: the {} budget of run {} sets a target standard error, and a study needs a fixed ensemble",
                opts.budget.name(),
                spec.name
            ),
        ));
    }
    Ok(e)
}

/// One row of the table: one value and one observable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The value (element count or Δt/τ1).
    #[serde(deserialize_with = "nan_if_null")]
    pub value: f64,
    /// h.
    #[serde(deserialize_with = "nan_if_null")]
    pub h: f64,
    /// Observable name.
    pub observable: String,
    /// Ensemble estimate.
    #[serde(deserialize_with = "nan_if_null")]
    pub estimate: f64,
    /// Its standard error.
    #[serde(deserialize_with = "nan_if_null")]
    pub std_error: f64,
    /// Exact discrete reference, if one is known (none for the time-step bias of the
    /// nonlinear θ-schemes).
    pub discrete: Option<f64>,
    /// Limit reference (continuum, or Δt → 0 of this mesh).
    #[serde(deserialize_with = "nan_if_null")]
    pub limit: f64,
    /// |estimate − limit|.
    #[serde(deserialize_with = "nan_if_null")]
    pub total_error: f64,
    /// Its standard error (that of the estimate).
    #[serde(deserialize_with = "nan_if_null")]
    pub total_error_se: f64,
    /// |discrete − limit|, if the discrete reference is known.
    pub exact_error: Option<f64>,
    /// Whether the total error is at the sampling floor (≤ 3 standard errors).
    pub sampling_floor: bool,
    /// Whether the exact error is at the round-off level of the references (the
    /// discretization is exact for this observable here).
    pub exact_at_rounding: bool,
}

impl Row {
    /// A row from the estimate `(e, se)`, the exact discrete reference (if known), the
    /// limit and the references' absolute round-off level.
    pub fn new(
        value: f64,
        h: f64,
        observable: &str,
        (e, se): (f64, f64),
        discrete: Option<f64>,
        limit: f64,
        rounding: f64,
    ) -> Row {
        let total = (e - limit).abs();
        let exact_error = discrete.map(|d| (d - limit).abs());
        Row {
            value,
            h,
            observable: observable.to_string(),
            estimate: e,
            std_error: se,
            discrete,
            limit,
            total_error: total,
            total_error_se: se,
            exact_error,
            sampling_floor: not_above(total, FLOOR_SIGMAS * se),
            exact_at_rounding: exact_error.is_some_and(|x| not_above(x, rounding)),
        }
    }
}

/// The fitted and expected orders of one observable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObservableSummary {
    /// Observable name.
    pub observable: String,
    /// Expected order and why.
    pub expected: Expected,
    /// Order of the total error fitted on the resolved points (`None` if fewer than two).
    pub observed: Option<OrderFit>,
    /// Values at the sampling floor (left out of the fit).
    pub floor_values: Vec<f64>,
    /// Order of the exact error, fitted on the points above round-off.
    pub exact: Option<OrderFit>,
    /// Values whose exact error is at round-off (the discretization is exact there).
    pub exact_at_rounding: Vec<f64>,
    /// Whether the observed order agrees with the expected one: its confidence interval
    /// holds the expected order (`None` without an expected order or an interval). For
    /// an exact observable ([`ObservableSummary::unsampled`]), the exact-error order's
    /// interval.
    pub agrees: Option<bool>,
    /// An exact observable: computed without sampling (every standard error zero), so
    /// it has no observed order, only its exact-error order (the membrane's λ_h/λ).
    /// Absent from the JSON when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unsampled: bool,
    /// Why no observed order was fitted, if none was, or why it differs from the
    /// expected one.
    pub note: String,
}

/// The simulation against the exact discrete references of a study, all rows together:
/// z = (estimate − discrete)/s.e. per row (two-sided z-test), the largest |z| judged with
/// a Bonferroni correction over the rows (valid although rows of one value share their
/// trajectories: ⟨w²(L/2)⟩ is dominated by mode 1). A small p-value says the simulation
/// disagrees with its own discretization's exact value (an integrator, sampling or
/// burn-in problem, not discretization error). Σz² is reported as a summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscreteConsistency {
    /// Σz² (descriptive: the rows are not all independent).
    #[serde(deserialize_with = "nan_if_null")]
    pub chi2: f64,
    /// Rows compared.
    pub rows: usize,
    /// Bonferroni-adjusted p-value of the largest |z|: min(1, rows × p).
    #[serde(deserialize_with = "nan_if_null")]
    pub p_value: f64,
    /// The largest |z|.
    #[serde(deserialize_with = "nan_if_null")]
    pub max_abs_z: f64,
    /// Where the largest |z| is: "observable at value".
    pub worst: String,
}

/// [`DiscreteConsistency`] of the rows with a discrete reference; `None` without such
/// rows.
pub fn discrete_consistency(rows: &[Row]) -> Option<DiscreteConsistency> {
    let tests: Vec<(stats::TestOutcome, &Row)> = rows
        .iter()
        .filter_map(|r| {
            let d = r.discrete?;
            stats::z_test(r.estimate, d, r.std_error)
                .ok()
                .map(|o| (o, r))
        })
        .collect();
    let (worst, r) = tests
        .iter()
        .max_by(|a, b| a.0.statistic.abs().total_cmp(&b.0.statistic.abs()))?;
    let n = tests.len();
    Some(DiscreteConsistency {
        chi2: tests.iter().map(|t| t.0.statistic.powi(2)).sum(),
        rows: n,
        p_value: (n as f64 * worst.p_value).min(1.0),
        max_abs_z: worst.statistic.abs(),
        worst: format!("{} at {}", r.observable, r.value),
    })
}

/// A value of the study that gave no rows: its run went unstable (diverged), or its
/// estimates could not be formed (too short for the correlation time). Recorded, not
/// fatal: the study goes on with the other values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedValue {
    /// The value (element count or Δt/τ1).
    #[serde(deserialize_with = "nan_if_null")]
    pub value: f64,
    /// `"unstable"` (a non-finite state) or `"estimate"` (the estimators failed).
    pub kind: String,
    /// The error, naming the step (unstable) or the cause.
    pub error: String,
}

impl FailedValue {
    /// Records `err` for `value` if it is a divergence or an estimator failure; any other
    /// error is returned.
    ///
    /// # Errors
    /// `err` itself unless it is [`Error::Diverged`] or [`Error::Numerical`].
    pub fn record(value: f64, err: Error) -> Result<FailedValue> {
        let kind = match &err {
            Error::Diverged { .. } => "unstable",
            Error::Numerical { .. } => "estimate",
            _ => return Err(err),
        };
        Ok(FailedValue {
            value,
            kind: kind.to_string(),
            error: err.to_string(),
        })
    }
}

/// The JSON summary of a study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergeSummary {
    /// The run that wrote this summary: the run id of the study's journal
    /// ([`super::output`]); empty in a summary written before journals existed.
    #[serde(default)]
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Master seed of the study: the scene's `seed`, or `--seed` when given (0 in a
    /// summary written before the seed was stored).
    #[serde(default)]
    pub seed: u64,
    /// Run name (with `-as-<integrator>` if the integrator was overridden).
    pub run: String,
    /// Integrator.
    pub integrator: String,
    /// Noise model.
    pub noise: String,
    /// What is refined.
    pub over: Over,
    /// What h is.
    pub h: String,
    /// What the errors are measured against.
    pub limit_reference: String,
    /// Budget.
    pub budget: String,
    /// Trajectories × duration per value.
    pub trajectories: usize,
    /// Sampled duration per trajectory (τ1).
    #[serde(deserialize_with = "nan_if_null")]
    pub duration_tau1: f64,
    /// Fixed parameters of the study (the other of elements / dt).
    pub fixed: String,
    /// Values studied, in the order of h descending.
    pub values: Vec<f64>,
    /// Per observable.
    pub observables: Vec<ObservableSummary>,
    /// The simulation against the exact discrete references (`None` if there are none).
    pub discrete_consistency: Option<DiscreteConsistency>,
    /// Values that gave no rows (unstable, or the estimators failed).
    pub failed: Vec<FailedValue>,
    /// Notes (acceptance rates, measured slopes, ...).
    pub notes: Vec<String>,
    /// Warnings about the physics (e.g. slopes too large for the small-slope model).
    pub warnings: Vec<String>,
    /// All rows.
    pub rows: Vec<Row>,
    /// The study's files (relative to the output directory, sorted): its table, figure
    /// and this summary; its journal and the shared index apart.
    pub files: Vec<String>,
    /// Wall time (s).
    #[serde(deserialize_with = "nan_if_null")]
    pub wall_seconds: f64,
}

/// What a study computed, before it is summarized and written.
#[derive(Debug, Clone, Default)]
pub struct Study {
    /// Values studied (h descending).
    pub values: Vec<f64>,
    /// Observable names.
    pub names: Vec<String>,
    /// Expected order per observable.
    pub expected: Vec<Expected>,
    /// All rows.
    pub rows: Vec<Row>,
    /// What the errors are measured against.
    pub limit_reference: String,
    /// The fixed parameter.
    pub fixed: String,
    /// Values that gave no rows.
    pub failed: Vec<FailedValue>,
    /// Notes.
    pub notes: Vec<String>,
    /// Warnings.
    pub warnings: Vec<String>,
}

/// Estimates of the observables from the records: (estimate, standard error).
fn estimates(lr: &LinearRun, records: &[TrajectoryRecord]) -> Result<Vec<(f64, f64)>> {
    let c = lr.components;
    let nm = lr.reference.modes.len();
    let np = lr.reference.profile_x.len();
    let mut out = Vec::new();
    let mut parts = Vec::new();
    for t in records {
        for k in 0..c {
            let sq: Vec<f64> = t.profile[k * np].iter().map(|w| w * w).collect();
            parts.push(stats::mean_with_error(&sq)?);
        }
    }
    out.push(stats::combine_independent(&parts));
    for i in 0..N_MODES {
        let mut parts = Vec::new();
        for t in records {
            for k in 0..c {
                parts.push(stats::variance_with_error(&t.modes[k * nm + i], Some(0.0))?);
            }
        }
        out.push(stats::combine_independent(&parts));
    }
    Ok(out)
}

/// Finds run `name` (default: the first) of a finite-element scene (linear or
/// compression).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--scene` (spectral scene) or `--run` (unknown
/// run).
pub fn select_run(scene: &Scene, name: Option<&str>) -> Result<usize> {
    if scene.model == ModelKind::Spectral {
        return Err(Error::invalid(
            "--scene",
            &scene.name,
            "a finite-element scene (model = \"fem\" or \"compression\", e.g. hinged-linear-2d, compression-2d): the spectral model has no discretization to refine",
        ));
    }
    match name {
        None => Ok(0),
        Some(n) => scene.runs.iter().position(|r| r.name == n).ok_or_else(|| {
            let names: Vec<&str> = scene.runs.iter().map(|r| r.name.as_str()).collect();
            Error::invalid("--run", n, format!("one of: {}", names.join(", ")))
        }),
    }
}

/// Runs a convergence study and writes `<scene>-<run>-<over>.{csv,svg,json}` in `out`
/// (`<run>-as-<integrator>` with an integrator override) with its journal
/// `<scene>-<run>-<over>.manifest.json`, after every simulation ([`super::output`]).
///
/// # Errors
/// Bad input (exit 2) naming the flag; run failures (exit 3). A value whose run
/// diverges, or whose estimators fail, is recorded in [`ConvergeSummary::failed`], not
/// fatal.
pub fn run_convergence(opts: &ConvergeOptions) -> Result<ConvergeSummary> {
    let start = Instant::now();
    let setup = setup(opts)?;
    let mut source = match &opts.merge {
        Some(set) => shard::Source::Merge(set),
        None => shard::Source::Simulate,
    };
    let study = study_of(opts, &setup, &mut source)?;
    let Setup {
        scene,
        spec,
        label,
        ensemble,
        provenance,
        ..
    } = setup;
    finish(
        opts,
        &scene,
        &spec,
        &label,
        study,
        ensemble,
        (start, provenance),
    )
}

/// What a study runs: the scene with any integrator override, its run (index, spec,
/// label), the ensemble and the provenance started.
pub(crate) struct Setup {
    run: usize,
    scene: Scene,
    spec: RunSpec,
    label: String,
    ensemble: Ensemble,
    pub(crate) provenance: Provenance,
}

/// The set-up of the study `opts` ([`Setup`]).
///
/// # Errors
/// Bad input (exit 2) naming the flag.
fn setup(opts: &ConvergeOptions) -> Result<Setup> {
    let run = select_run(&opts.scene, opts.run.as_deref())?;
    let mut scene = opts.scene.clone();
    let mut label = scene.runs[run].name.clone();
    if let Some(k) = opts.integrator
        && k != scene.runs[run].integrator
    {
        scene.runs[run].integrator = k;
        label = format!("{label}-as-{}", k.name());
    }
    let spec = scene.runs[run].clone();
    let provenance = Provenance::begin(&[&scene]);
    let ensemble = study_ensemble(opts, &spec)?;
    if scene.model != ModelKind::Compression && opts.strain_ratios.is_some() {
        return Err(Error::invalid(
            "--strain-ratios",
            &scene.name,
            "a compression scene (model = \"compression\"): the linear scenes have no imposed strain",
        ));
    }
    Ok(Setup {
        run,
        scene,
        spec,
        label,
        ensemble,
        provenance,
    })
}

/// The study of `setup`, its trajectories from `source`.
///
/// # Errors
/// As [`run_convergence`].
fn study_of(
    opts: &ConvergeOptions,
    setup: &Setup,
    source: &mut shard::Source<'_>,
) -> Result<Study> {
    let (scene, run, ensemble) = (&setup.scene, setup.run, setup.ensemble);
    match scene.model {
        ModelKind::Compression => {
            scene.refuse_membrane("converge of a membrane under imposed projected area")?;
            compression::study(scene, run, opts, ensemble, source)
        }
        ModelKind::Fem | ModelKind::Spectral => linear_study(scene, run, opts, ensemble, source),
    }
}

/// The linear study: ⟨w²(L/2)⟩ and the variances of modes 1–3 per value.
fn linear_study(
    scene: &Scene,
    run: usize,
    opts: &ConvergeOptions,
    ensemble: Ensemble,
    source: &mut shard::Source<'_>,
) -> Result<Study> {
    let spec = &scene.runs[run];
    let over = opts.over;
    let values = linear_values(scene, run, opts)?;
    let work = projected_work(scene, run, opts, ensemble, &values, None);
    opts.limits.check(&work.scaled(source.fraction()))?;
    let names = observable_names(scene, over)?;
    // Prepare everything first, so that bad input fails before any simulation.
    let prepared = values
        .iter()
        .map(|&v| prepare(scene, run, over, v))
        .collect::<Result<Vec<_>>>()?;
    let limit_dt = match (over, prepared.first()) {
        (Over::Dt, Some((_, lr))) => Some(semi_discrete_limit(scene, lr, spec)?),
        _ => None,
    };
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    let mut largest_slope: Option<(f64, (f64, f64))> = None;
    for ((s, lr), &v) in prepared.iter().zip(&values) {
        let t0 = Instant::now();
        let refp = reference_point(s, lr, over, v, limit_dt.as_deref());
        let seed = derive_seed(s.seed, &seed_label(&spec.name, over, v));
        let steps = lr.sampled_steps(ensemble.duration_tau1 * s.tau1());
        let outcome = source.linear(
            (scene, &spec.name, over, v),
            (&ensemble, lr),
            |first, count| lr.simulate_ensemble(seed, first, count, steps, |_| {}),
        )?;
        let records = match outcome {
            shard::Outcome::Records(r) => r,
            shard::Outcome::Written => continue,
            shard::Outcome::Failed(f) => {
                failed.push(f);
                continue;
            }
        };
        let est = match estimates(lr, &records) {
            // The exact observables (past the sampled ones) are their exact values.
            Ok(mut est) => {
                est.extend(refp.discrete[SAMPLED..].iter().map(|&d| (d, 0.0)));
                est
            }
            Err(e) => {
                failed.push(FailedValue::record(v, e)?);
                continue;
            }
        };
        if let Some(slope) = lr.measured_rms_slope(&records)
            && largest_slope.is_none_or(|l| slope.0 > l.1.0)
        {
            largest_slope = Some((v, slope));
        }
        rows.extend(value_rows(&names, &refp, &est));
        if opts.progress {
            eprintln!(
                "converge {} {}: {}={v}: {} trajectories x {} tau1, {:.1} s",
                scene.name,
                spec.name,
                over.name(),
                ensemble.trajectories,
                ensemble.duration_tau1,
                t0.elapsed().as_secs_f64()
            );
        }
    }
    let object = study_object(scene, over, &values);
    let expected = (0..names.len())
        .map(|k| expected_order(over, spec, k, object))
        .collect();
    let (notes, warnings) = slope_notes(scene, over, largest_slope);
    let (limit_reference, fixed) = linear_texts(scene, spec, over);
    Ok(Study {
        values,
        names,
        expected,
        rows,
        limit_reference,
        fixed,
        failed,
        notes,
        warnings,
    })
}

/// What the expected orders of a linear study of `scene` over `over` at `values` depend
/// on: a membrane's meshes alike in where their centre falls (the parities of nx and ny),
/// or whether every filament mesh has a node at the middle.
fn study_object(scene: &Scene, over: Over, values: &[f64]) -> StudyObject {
    if scene.is_membrane() {
        StudyObject::Membrane {
            centre_alike: match over {
                Over::Elements => {
                    let parities = |v: &f64| {
                        let nx = v.round() as usize;
                        (nx % 2, membrane_elements_y(scene, nx) % 2)
                    };
                    values.iter().all(|v| parities(v) == parities(&values[0]))
                }
                Over::Dt => true,
            },
        }
    } else {
        StudyObject::Filament {
            rigid: scene.ends.rigid_modes() > 0,
            node_at_mid: match over {
                Over::Elements => values
                    .iter()
                    .all(|v| (v.round() as usize).is_multiple_of(2)),
                Over::Dt => scene.mesh.elements.is_multiple_of(2),
            },
        }
    }
}

/// The values of a linear study (the options' or the defaults), validated, largest h
/// first.
fn linear_values(scene: &Scene, run: usize, opts: &ConvergeOptions) -> Result<Vec<f64>> {
    let over = opts.over;
    let mut values = match &opts.values {
        Some(v) => v.clone(),
        None => default_values(scene, run, over)?,
    };
    if over == Over::Elements && scene.is_membrane() {
        validate_membrane_elements(scene, &values)?;
    }
    validate_values(over, &values)?;
    values.sort_by(|a, b| h_of(scene, over, *b).total_cmp(&h_of(scene, over, *a)));
    Ok(values)
}

/// An estimate and its standard error.
type Estimate = (f64, f64);

/// The label of the streams of value `v` of a study of run `run` (`<run>/converge/<over>=<v>`;
/// a compression study appends `/<strain>`), from which the seeds derive.
fn seed_label(run: &str, over: Over, v: f64) -> String {
    format!("{run}/converge/{}={v}", over.name())
}

/// The rows of one value: one per observable, from its estimates and exact references.
fn value_rows(names: &[String], refp: &PointReference, est: &[Estimate]) -> Vec<Row> {
    names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            Row::new(
                refp.value,
                refp.h,
                name,
                est[k],
                Some(refp.discrete[k]),
                refp.limit[k],
                refp.rounding_rel * refp.limit[k].abs(),
            )
        })
        .collect()
}

/// The note on the largest measured RMS slope of the study (at value `v`) and the
/// small-slope warning it may call for.
fn slope_notes(
    scene: &Scene,
    over: Over,
    largest_slope: Option<(f64, (f64, f64))>,
) -> (Vec<String>, Vec<String>) {
    let mut notes = Vec::new();
    let mut warnings = Vec::new();
    if let Some((v, slope)) = largest_slope {
        notes.push(format!(
            "largest measured RMS slope {:.3} rad at x/L = {:.2} ({}={v})",
            slope.0,
            slope.1,
            over.name()
        ));
        warnings.extend(small_slope_warning(
            &format!("{}={v}", over.name()),
            slope,
            &scene.filament,
        ));
    }
    (notes, warnings)
}

/// What the errors of a linear study are measured against, and its fixed parameter.
fn linear_texts(scene: &Scene, spec: &RunSpec, over: Over) -> (String, String) {
    match over {
        Over::Elements if scene.is_membrane() => (
            "continuum (M1): mode variance kT/lambda_q = kT xi/(kappa q^4 + sigma q^2) (damping-normalized modes), <h^2(a/2, b/2)> the exact sum over the modes (M3); the eigenvalue ratio lambda_h/lambda against 1"
                .to_string(),
            format!("dt_tau1 = {:e}", spec.dt_tau1),
        ),
        Over::Elements => (
            "continuum (eq. 2): mode variance 2kTL^3/(pi^4 n^4 EI), profile kT x^2(L-x)^2/(3 EI L)"
                .to_string(),
            format!("dt_tau1 = {:e}", spec.dt_tau1),
        ),
        Over::Dt => (
            format!(
                "dt -> 0 limit of this mesh ({} elements) and noise model: S_ij = 2kT Sigma_q,ij/(lambda_i + lambda_j)",
                mesh_text(scene)
            ),
            format!("elements = {}", mesh_text(scene)),
        ),
    }
}

/// Summarizes `study` and writes its output set `<stem>.{csv,svg,json}` with its journal
/// `<stem>.manifest.json` ([`super::output`]); the CLI then rebuilds the index page.
fn finish(
    opts: &ConvergeOptions,
    scene: &Scene,
    spec: &RunSpec,
    label: &str,
    study: Study,
    ensemble: Ensemble,
    (start, provenance): (Instant, Provenance),
) -> Result<ConvergeSummary> {
    let over = opts.over;
    let observables = summarize(&study.names, &study.rows, &study.expected);
    let stem = format!("{}-{label}-{}", scene.name, over.name());
    let report = StudyReport::begin(&opts.out, "converge", &stem, provenance)?;
    let csv = format!("{stem}.csv");
    report.write(&csv, rows_csv(Path::new(&csv), &study.rows)?.as_bytes())?;
    report.write_svg(
        &format!("{stem}.svg"),
        &figure(scene, label, spec, over, &observables, &study.rows),
    )?;
    let summary = ConvergeSummary {
        run_id: report.run_id(),
        scene: scene.name.clone(),
        seed: scene.seed,
        run: label.to_string(),
        integrator: spec.integrator.name().to_string(),
        noise: spec.noise.name().to_string(),
        over,
        h: h_label(scene, over).to_string(),
        limit_reference: study.limit_reference,
        budget: opts.budget.name().to_string(),
        trajectories: ensemble.trajectories,
        duration_tau1: ensemble.duration_tau1,
        fixed: study.fixed,
        values: study.values,
        observables,
        discrete_consistency: discrete_consistency(&study.rows),
        failed: study.failed,
        notes: study.notes,
        warnings: study.warnings,
        rows: study.rows,
        files: report.files(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    report.complete(&summary)?;
    Ok(summary)
}

/// Fits the observed and exact orders per observable and compares the observed order
/// with the expected one.
pub fn summarize(names: &[String], rows: &[Row], expected: &[Expected]) -> Vec<ObservableSummary> {
    names
        .iter()
        .zip(expected)
        .map(|(name, expected)| {
            let rs: Vec<&Row> = rows.iter().filter(|r| &r.observable == name).collect();
            if is_unsampled(&rs) {
                unsampled_summary(name, expected, &rs)
            } else {
                sampled_summary(name, expected, &rs)
            }
        })
        .collect()
}

/// The summary of sampled observable `name` from its rows `rs`: the order fitted on
/// the points above the sampling floor, the exact discrete error's order, and whether
/// the observed order agrees with the expected one.
fn sampled_summary(name: &str, expected: &Expected, rs: &[&Row]) -> ObservableSummary {
    let resolved: Vec<&&Row> = rs.iter().filter(|r| !r.sampling_floor).collect();
    let all_exact = !rs.is_empty() && rs.iter().all(|r| r.exact_at_rounding);
    let observed = if all_exact || expected.exact {
        None
    } else {
        fit_order(
            &resolved.iter().map(|r| r.h).collect::<Vec<_>>(),
            &resolved.iter().map(|r| r.total_error).collect::<Vec<_>>(),
            Some(
                &resolved
                    .iter()
                    .map(|r| r.total_error_se)
                    .collect::<Vec<_>>(),
            ),
        )
    };
    let agrees = match (expected.order, observed.and_then(|f| f.ci)) {
        (Some(p), Some((lo, hi))) => Some(lo <= p && p <= hi),
        _ => None,
    };
    let exact = exact_order_fit(rs);
    let note = order_note(rs, expected, (observed, exact), agrees);
    ObservableSummary {
        observable: name.to_string(),
        expected: expected.clone(),
        observed,
        floor_values: rs
            .iter()
            .filter(|r| r.sampling_floor)
            .map(|r| r.value)
            .collect(),
        exact,
        exact_at_rounding: rs
            .iter()
            .filter(|r| r.exact_at_rounding)
            .map(|r| r.value)
            .collect(),
        agrees,
        unsampled: false,
        note,
    }
}

/// What the fit of sampled observable rows `rs` says: an exact discretization's
/// sampling-only error, too few resolved points, or the observed order (`fits`: the
/// observed and the exact discrete error's) against the expected one, telling a
/// pre-asymptotic range from a simulation error.
fn order_note(
    rs: &[&Row],
    expected: &Expected,
    (observed, exact_fit): (Option<OrderFit>, Option<OrderFit>),
    agrees: Option<bool>,
) -> String {
    let resolved: Vec<&&Row> = rs.iter().filter(|r| !r.sampling_floor).collect();
    let all_exact = !rs.is_empty() && rs.iter().all(|r| r.exact_at_rounding);
    let within = rs.len() - resolved.len();
    if all_exact || expected.exact {
        let resolved_points: Vec<f64> = resolved.iter().map(|r| r.value).collect();
        return format!(
            "the discretization is exact for this observable: the total error is sampling noise only, no order is fitted; {within} of {} estimates within {FLOOR_SIGMAS} standard errors of the reference{}",
            rs.len(),
            if resolved_points.is_empty() {
                String::new()
            } else {
                format!(
                    " (NOT within at {resolved_points:?}: an error the exact theory does not predict)"
                )
            }
        );
    }
    if resolved.len() < 2 {
        return format!(
            "{within} of {} points at the sampling floor: too few resolved points for an observed order{}",
            rs.len(),
            budget_hint(rs)
        );
    }
    match (agrees, expected.order, observed) {
        (Some(true), Some(p), _) => {
            format!("observed order agrees with the expected {p} (inside its 95 % interval)")
        }
        (Some(false), Some(p), Some(f)) => {
            let pre =
                exact_fit.filter(|e| f.ci.is_some_and(|(lo, hi)| lo <= e.order && e.order <= hi));
            match pre {
                Some(e) => format!(
                    "observed order {:.2} differs from the asymptotic {p} but agrees with the order {:.2} of the exact discrete error over these values: the values are not yet in the asymptotic range (pre-asymptotic), not a simulation error",
                    f.order, e.order
                ),
                None => format!(
                    "observed order {:.2} differs from the expected {p}: its 95 % interval excludes {p}{}",
                    f.order,
                    if f.points < rs.len() {
                        " (fitted on the resolved points only; nearer the floor the sampling error inflates the measured error, which flattens the fit)"
                    } else {
                        ""
                    }
                ),
            }
        }
        (None, Some(_), Some(_)) => format!(
            "two resolved points: an order but no interval to compare with the expected one{}",
            budget_hint(rs)
        ),
        _ => String::new(),
    }
}

/// Whether the rows of an observable are of an exact observable: computed, not sampled
/// (every standard error zero).
fn is_unsampled(rs: &[&Row]) -> bool {
    !rs.is_empty() && rs.iter().all(|r| r.std_error == 0.0)
}

/// The summary of an exact observable (rows `rs`, no sampling): no observed order; its
/// exact-error order, with its interval, is compared with the expected one.
fn unsampled_summary(name: &str, expected: &Expected, rs: &[&Row]) -> ObservableSummary {
    let exact = exact_order_fit(rs);
    let agrees = match (expected.order, exact.and_then(|f| f.ci)) {
        (Some(p), Some((lo, hi))) => Some(lo <= p && p <= hi),
        _ => None,
    };
    let at_rounding: Vec<f64> = rs
        .iter()
        .filter(|r| r.exact_at_rounding)
        .map(|r| r.value)
        .collect();
    let order = match (exact, expected.order) {
        (Some(f), Some(p)) => {
            let ci =
                f.ci.map_or("no interval (2 points)".to_string(), |(lo, hi)| {
                    format!("95 % interval [{lo:.2}, {hi:.2}]")
                });
            let verdict = match agrees {
                Some(true) => format!("agrees with the expected {p}"),
                Some(false) => format!("differs from the expected {p}: its interval excludes it"),
                None => format!("no interval to compare with the expected {p}"),
            };
            format!(
                "exact-error order {:.2} ({ci}, {} points) {verdict}",
                f.order, f.points
            )
        }
        (Some(f), None) => format!("exact-error order {:.2} ({} points)", f.order, f.points),
        (None, _) => "too few points above round-off for an order".to_string(),
    };
    ObservableSummary {
        observable: name.to_string(),
        expected: expected.clone(),
        observed: None,
        floor_values: Vec::new(),
        exact,
        agrees,
        unsampled: true,
        note: format!(
            "an exact observable (no sampling): its error is the exact discrete error, so no observed order is fitted; {order}{}",
            if at_rounding.is_empty() {
                String::new()
            } else {
                format!("; at round-off at {at_rounding:?}")
            }
        ),
        exact_at_rounding: at_rounding,
    }
}

/// The order of the exact error, fitted on the rows whose exact error is known and
/// above round-off.
fn exact_order_fit(rs: &[&Row]) -> Option<OrderFit> {
    let above: Vec<&&Row> = rs
        .iter()
        .filter(|r| r.exact_error.is_some() && !r.exact_at_rounding)
        .collect();
    fit_order(
        &above.iter().map(|r| r.h).collect::<Vec<_>>(),
        &above
            .iter()
            .map(|r| r.exact_error.unwrap_or(f64::NAN))
            .collect::<Vec<_>>(),
        None,
    )
}

/// What it would take to resolve the floor points of an observable: with a known exact
/// error e and standard error s at a floor point, the error is resolved (e > 3 s) with
/// about (3s/e)² times the ensemble (s ∝ 1/sqrt(trajectories × duration)).
fn budget_hint(rs: &[&Row]) -> String {
    let need = rs
        .iter()
        .filter(|r| r.sampling_floor)
        .filter_map(|r| {
            let e = r.exact_error?;
            (e > 0.0 && !r.exact_at_rounding).then(|| (FLOOR_SIGMAS * r.total_error_se / e).powi(2))
        })
        .fold(0.0, f64::max);
    if need > 1.0 {
        format!(
            "; resolving every floor point needs about {need:.0}x this ensemble (the exact error there is below 3 standard errors: a larger --budget, --trajectories or --duration-tau1)"
        )
    } else {
        "; a larger --budget, --trajectories or --duration-tau1 resolves more".to_string()
    }
}

fn opt_cell(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| x.to_string())
}

/// The study's table `<stem>.csv` (`path` names it in errors): one line per value and
/// observable.
fn rows_csv(path: &Path, rows: &[Row]) -> Result<String> {
    let mut table = CsvWriter::new(
        Vec::new(),
        path,
        &[
            "value",
            "h",
            "observable",
            "estimate",
            "std_error",
            "discrete",
            "limit",
            "total_error",
            "total_error_se",
            "exact_error",
            "status",
        ],
    )?;
    for r in rows {
        table.record([
            r.value.to_string(),
            r.h.to_string(),
            r.observable.to_string(),
            r.estimate.to_string(),
            r.std_error.to_string(),
            opt_cell(r.discrete),
            r.limit.to_string(),
            r.total_error.to_string(),
            r.total_error_se.to_string(),
            opt_cell(r.exact_error),
            if r.sampling_floor {
                "sampling floor"
            } else {
                "resolved"
            }
            .to_string(),
        ])?;
    }
    table.into_string()
}

/// The study's figure: per observable (one colour each), |error| of the resolved
/// estimates (markers, ±1 s.e.), the sampling-floor points (light markers at 3 s.e.), the
/// exact discretization error (light line) and the least-squares fit of the observed
/// order (dashed, its order in the legend).
fn figure(
    scene: &Scene,
    label: &str,
    spec: &RunSpec,
    over: Over,
    observables: &[ObservableSummary],
    rows: &[Row],
) -> Figure {
    let units = AxisUnits::new(scene.physical.is_some());
    let membrane = scene.is_membrane();
    let x_label = match over {
        Over::Elements if membrane => format!("element width h = a/N_x {}", units.length()),
        Over::Elements => format!("element length h = L/N {}", units.length()),
        Over::Dt => "time step h = Δt / τ₁".to_string(),
    };
    let y_label = match scene.model {
        ModelKind::Compression => "|error of ⟨F⟩| / F_c0".to_string(),
        ModelKind::Fem | ModelKind::Spectral if membrane && over == Over::Elements => {
            format!("|error| {} (λ_h/λ: relative)", units.area())
        }
        ModelKind::Fem | ModelKind::Spectral => format!("|error| {}", units.area()),
    };
    let mut fig = Figure::new(
        format!(
            "{} {label} ({} noise): error against {}",
            scene.name,
            spec.noise.name(),
            over.name()
        ),
        x_label,
        y_label,
    )
    .log_x()
    .log_y()
    .caption(format!(
        "Error of each observable against the {} as the {} is refined (log–log), one \
         colour per observable: |estimate − limit| (markers, ±1 s.e.), estimates within \
         3 standard errors of the limit (light markers, drawn at 3 s.e.: the sampling \
         floor), the exact error of the discretization (light line) and the \
         least-squares fit of the observed order (dashed). The markers should follow the \
         light line, and the fitted order should match the expected one.",
        if over == Over::Elements {
            "continuum"
        } else {
            "Δt → 0 limit"
        },
        if over == Over::Elements {
            "mesh"
        } else {
            "time step"
        }
    ));
    for (hue, o) in observables.iter().enumerate() {
        fig = observable_series(fig, hue, o, rows);
    }
    fig
}

/// The series of observable `o` in the convergence figure, in colour `hue`: the resolved
/// errors with their error bars, the sampling floor, the exact error and the fitted order.
fn observable_series(mut fig: Figure, hue: usize, o: &ObservableSummary, rows: &[Row]) -> Figure {
    let name = &o.observable;
    let rs: Vec<&Row> = rows.iter().filter(|r| &r.observable == name).collect();
    // An exact observable (no sampling) has its exact error and the fit of its order only.
    let unsampled = is_unsampled(&rs);
    let res: Vec<&&Row> = rs
        .iter()
        .filter(|r| !(r.sampling_floor || unsampled && r.exact_at_rounding))
        .collect();
    let floor: Vec<&&Row> = rs.iter().filter(|r| r.sampling_floor).collect();
    if !res.is_empty() && !unsampled {
        fig = fig.series(
            Series::markers(
                format!("{name}: simulated"),
                res.iter().map(|r| (r.h, r.total_error)).collect(),
            )
            .with_errors(res.iter().map(|r| r.total_error_se).collect())
            .palette(hue),
        );
    }
    if !floor.is_empty() && !unsampled {
        // At the floor the error is not resolved: drawn at 3 standard errors (an
        // upper bound), without error bars.
        fig = fig.series(
            Series::markers(
                format!("{name}: sampling floor (3 s.e.)"),
                floor
                    .iter()
                    .map(|r| (r.h, FLOOR_SIGMAS * r.total_error_se))
                    .collect(),
            )
            .palette(hue)
            .light(),
        );
    }
    let exact: Vec<(f64, f64)> = rs
        .iter()
        .filter(|r| !r.exact_at_rounding)
        .filter_map(|r| r.exact_error.map(|e| (r.h, e)))
        .collect();
    if !exact.is_empty() {
        fig = fig.series(
            Series::line(format!("{name}: exact error"), exact)
                .palette(hue)
                .light(),
        );
    }
    let fit = if unsampled { o.exact } else { o.observed };
    if let Some(f) = fit.filter(|f| f.order.is_finite() && f.prefactor > 0.0) {
        let (lo, hi) = res.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
            (lo.min(r.h), hi.max(r.h))
        });
        if lo < hi {
            let line = [lo, hi]
                .iter()
                .map(|&h| (h, f.prefactor * h.powf(f.order)))
                .collect();
            let what = if unsampled {
                "fit of the exact error"
            } else {
                "fit"
            };
            fig = fig.series(
                Series::line(format!("{name}: {what}, order {:.2}", f.order), line)
                    .dashed()
                    .palette(hue),
            );
        }
    }
    fig
}
