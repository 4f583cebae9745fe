//! Verification: the pass/fail checks of a scene and the runner behind
//! `langevin-fem verify`.
//!
//! Each run of a scene ([`crate::scene`]) simulates independent trajectories in parallel
//! (one PCG stream per trajectory, so the result does not depend on the thread count),
//! against exact references ([`crate::scene::linear::LinearReference`]); the checks
//! ([`checks`] for linear scenes, [`compression`] for compression scenes) turn the
//! records into [`CheckResult`]s and the runner applies the Holm correction over all
//! checks of the scene at the family-wise level α. The runner returns a [`Summary`] and
//! writes the per-scene CSV tables and SVG figures; the HTML index is the report layer's
//! ([`crate::report`]).

pub mod calibrate;
pub mod checks;
pub mod compression;
pub mod data;
pub mod diagnosis;
pub mod fit;
pub mod oracle;
pub mod runner;
pub mod shard;
pub mod summary;

pub use runner::{Ensembles, VerifyOptions, check_data, projected_work, run_verification};
pub use summary::{CheckResult, SceneSummary, Summary};
