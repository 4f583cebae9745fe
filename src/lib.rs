//! # langevin-fem
//!
//! Finite-element Langevin dynamics for the thermal shape fluctuations of elastic
//! bio-filaments, after Lin & Shenoy, *A Langevin dynamics approach for analyzing the
//! mechanical response of bio-polymers*, and a statistical verification suite that judges
//! the simulation against exact references.
//!
//! Layers, from the bottom up:
//! - [`params`], [`rng`], [`error`]: physical parameters, deterministic randomness, errors.
//! - [`spectral`]: the exact modal solution of the stochastic beam equation (2)–(4).
//! - [`stats`]: estimators and hypothesis tests, validated on exactly solvable processes.
//! - [`fem`]: Hermite-cubic beam elements, assembly, generalized modes, exact discrete
//!   stationary covariances.
//! - [`dynamics`]: thermal noise models and time integrators.
//! - [`verify`]: scenes, checks and the verification runner.
//! - [`report`]: SVG figures and the HTML index.

pub mod dynamics;
pub mod error;
pub mod fem;
pub mod params;
pub mod report;
pub mod rng;
pub mod spectral;
pub mod stats;
pub mod theory;
pub mod verify;

pub use error::{Error, Result};
pub use params::FilamentParams;
