//! # langevin-fem
//!
//! Finite-element Langevin dynamics for the thermal shape fluctuations of elastic
//! bio-filaments, after Lin & Shenoy, *A Langevin dynamics approach for analyzing the
//! mechanical response of bio-polymers*, and a statistical verification suite that judges
//! the simulation against exact references.
//!
//! Layers, from the bottom up (each imports only from the layers below it):
//!
//! 1. Foundation: [`params`], [`rng`], [`error`] (physical parameters, deterministic
//!    randomness, errors) and [`output`] (domain-free SVG figures and atomic file writers).
//! 2. References: [`spectral`] (the exact modal solution of the stochastic beam equation
//!    (2)–(4)) and [`theory`] (the exact equilibrium theory of the compressed filament,
//!    the paper's Fig. 2).
//! 3. Model: [`fem`] (Hermite-cubic beam elements, assembly, noise models, generalized
//!    modes, exact discrete stationary covariances, and the von Kármán filament).
//! 4. Dynamics: [`dynamics`] (every fact about an integrator in
//!    [`dynamics::IntegratorKind`], the linear and nonlinear integrators, the trajectory
//!    driver and parallel ensembles).
//! 5. Statistics: [`stats`] (estimators and hypothesis tests, validated on exactly
//!    solvable processes).
//! 6. Scenes: [`scene`] (scene files, their validation, and run preparation).
//! 7. Verification and studies, side by side: [`verify`] (pass/fail checks and the
//!    runner) and [`studies`] (convergence, stability map, work–precision).
//! 8. Reports: [`report`] (the HTML index and the convergence pages).
//!
//! The binary's `cli` module sits on top.

pub mod dynamics;
pub mod error;
pub mod fem;
pub mod output;
pub mod params;
pub mod report;
pub mod rng;
pub mod scene;
pub mod spectral;
pub mod stats;
pub mod studies;
pub mod theory;
pub mod verify;

pub use error::{Error, Result};
pub use params::FilamentParams;
