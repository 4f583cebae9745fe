//! # langevin-fem
//!
//! Finite-element Langevin dynamics for the thermal shape fluctuations of elastic
//! bio-filaments and membranes, after Lin & Shenoy, *A Langevin dynamics approach for
//! analyzing the mechanical response of bio-polymers*, and a statistical verification
//! suite that judges the simulation against exact references.
//!
//! Layers, from the bottom up (each imports only from the layers below it):
//!
//! 1. Foundation: [`params`], [`rng`], [`error`] (physical parameters, deterministic
//!    randomness, errors), [`output`] (domain-free SVG figures and atomic file writers),
//!    [`input`] (domain-free reading of the files a user gives: regular files only,
//!    capped before they are read), [`work`] (the caps on a command's projected total
//!    work and memory) and [`progress`] (progress on stderr, weighted by that work).
//! 2. References: [`spectral`] (the exact modal solution of the stochastic beam equation
//!    (2)–(4), and in [`spectral::membrane`] the continuum references of a fluctuating
//!    Helfrich membrane: modes, rates, variances, two-time correlations, point variance,
//!    excess area).
//! 3. Model: [`fem`] (the [`fem::LinearSystem`] every object assembles to; Hermite-cubic
//!    beam elements and Bogner–Fox–Schmit plate elements with their separable modes
//!    ([`fem::plate`], [`fem::plate_modes`]), assembly, noise models, generalized modes,
//!    exact discrete stationary covariances, and the von Kármán filament), and on it
//!    [`theory`] (the exact equilibrium theory of the compressed filament, the paper's
//!    Fig. 2, for the continuum and for a given mesh).
//! 4. Dynamics: [`dynamics`] (every fact about an integrator in
//!    [`dynamics::IntegratorKind`], the linear and nonlinear integrators, their exact
//!    discrete law on any linear system ([`dynamics::DiscreteLaw`]), the O(n) modal step
//!    ([`dynamics::ModalStep`]), the trajectory driver and parallel ensembles).
//! 5. Statistics: [`stats`] (estimators and hypothesis tests, validated on exactly
//!    solvable processes).
//! 6. Scenes: [`scene`] (scene files, their validation, and run preparation), [`data`]
//!    (the trajectory data format that `run` writes and `check` reads), and
//!    [`shard`] (a command's ensembles split across processes: the shard format, and the
//!    checks of a shard set before a merge).
//! 7. Verification and studies, side by side: [`verify`] (pass/fail checks and the
//!    runner) and [`studies`] (convergence, stability map, work–precision).
//! 8. Reports: [`report`] (the HTML index and the convergence pages).
//!
//! The binary's `cli` module sits on top.
//!
//! ## Equation map: the paper → the code
//!
//! Equation numbers are those of Lin & Shenoy (the seed paper); notation as in
//! [`params::FilamentParams`].
//!
//! | paper | what | where |
//! |---|---|---|
//! | eq. (1) | white-noise load, ⟨f f⟩ = 2ξkT δ(x−y) δ(t−τ) | [`spectral::HingedBeam`] (modal OU noise), [`fem::noise::NoiseModel::Consistent`] (its exact finite-element covariance 2kT·C/Δt) |
//! | eq. (2) | stochastic beam equation ξ∂w/∂t + EI∂⁴w/∂x⁴ = f | modal solution [`spectral`]; semi-discrete form C ẇ = −K w + F in [`fem::beam::BeamModel`] ([`fem::hermite`] element matrices), integrated by [`dynamics`] |
//! | eq. (3) | solution from w(x,0) = 0 | [`spectral::simulator::ModalSimulator`] (exact OU transition per mode, from rest) |
//! | eq. (4) | two-time correlation ⟨w(x,t) w(y,η)⟩ | [`spectral::HingedBeam::correlation`]; discrete counterpart in [`scene::linear::TwoTimeReference`]; checked by [`verify::checks`] |
//! | eq. (4), t→∞, η=t | equipartition profile ⟨w²(x)⟩ | [`spectral::HingedBeam::profile_variance`] (closed form) and [`spectral::HingedBeam::profile_variance_series`] |
//! | per-mode law | variance 2kTL³/(π⁴n⁴EI), rate λₙ = π⁴n⁴EI/(ξL⁴), Lorentzian spectrum | [`spectral::HingedBeam::mode_variance`], [`spectral::HingedBeam::mode_rate`], [`spectral::HingedBeam::lorentzian`], [`spectral::HingedBeam::sampled_spectrum`] (AR(1), aliasing included) |
//! | membrane (issue #27) | ξ∂h/∂t = −κ∇⁴h + σ∇²h + f: variance 4kT/(ab·c_q) (simply supported) or ⟨\|h_q\|²⟩ = kT/(ab·c_q) (periodic), rate c_q/ξ, c_q = κq⁴ + σq² | [`spectral::membrane::Membrane`] (mode variances and rates, [`spectral::membrane::Membrane::correlation`], [`spectral::membrane::Membrane::point_variance`], [`spectral::membrane::Membrane::excess_area`], spectra) |
//! | membrane, finite elements (issue #27) | C = ξM⊗M, K = κ(K4⊗M + 2K2⊗K2 + M⊗K4) + σ(K2⊗M + M⊗K2), eq. (5) per element area; exact modal simulator of (M1) | [`fem::plate::PlateModel`], [`fem::plate_modes::PlateModes`] (separable modes), [`spectral::membrane::MembraneSimulator`] |
//! | eq. (5) | element-uniform load, variance 2ξkT/(hΔt) | [`fem::noise::NoiseModel::ElementUniform`]; its exact stationary covariance (a Lyapunov solution) in [`fem::modal::discrete_stationary_covariance`] |
//! | element energy (von Kármán) | ∫ [EA/2 (u′ + ½w′²)² + EI/2 w″²] dx | [`fem::vonkarman::CompressedFilament`] (energy, internal force) |
//! | step (i) | axial equilibrium for u at fixed w | [`fem::vonkarman::CompressedFilament::axial_equilibrium`] |
//! | steps (ii)–(iii) | explicit update of w | [`dynamics::IntegratorKind::EulerMaruyama`] in [`dynamics::nonlinear::NonlinearIntegrator`]; the exact-stationary alternative [`dynamics::IntegratorKind::MetropolisCrankNicolson`] |
//! | Fig. 2 | ⟨F⟩/F_c0 against ε/ε_c0, 2D and 3D | exact theory [`theory::compression::CompressionTheory::force_ratio`]; simulated by [`scene::compression::CompressionRun`]; checked by [`verify::compression`] |
//!
//! Reference values derived beyond the paper (time-step bias of each integrator, exact
//! discrete covariances) are documented where they are computed:
//! [`dynamics::IntegratorKind::modal_form`], [`fem::modal`].

pub mod data;
pub mod dynamics;
pub mod error;
#[cfg(any(test, feature = "faults"))]
pub mod fault;
pub mod fem;
pub mod input;
pub mod output;
pub mod params;
pub mod progress;
pub mod report;
pub mod rng;
pub mod scene;
pub mod shard;
pub mod spectral;
pub mod stats;
pub mod studies;
pub mod theory;
pub mod verify;
pub mod work;

pub use error::{Error, Result};
pub use params::FilamentParams;
