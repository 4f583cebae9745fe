//! Verification: scenes, checks and the runner behind `langevin-fem verify`.
//!
//! A scene (`verification/*.toml`, [`scene::Scene`]) is one physical set-up with its
//! discretization, its ensembles per budget and the checks to run. Each run of a scene
//! simulates independent trajectories in parallel (one PCG stream per trajectory, so the
//! result does not depend on the thread count), computes the exact references
//! ([`linear::LinearReference`]), runs the checks ([`checks`]) and the runner applies the
//! Holm correction over all checks of the scene at the family-wise level α.

pub mod checks;
pub mod compression;
pub mod converge;
pub mod linear;
pub mod runner;
pub mod scene;
pub mod stability;
pub mod summary;
pub mod work_precision;

pub use runner::{VerifyOptions, resolve_scenes, run_verification};
pub use scene::{Budget, Scene};
pub use summary::{CheckResult, SceneSummary, Summary};
