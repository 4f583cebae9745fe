//! Verification: scenes, checks and the runner behind `langevin-fem verify`.

pub mod summary;

pub use summary::{CheckResult, SceneSummary, Summary};
