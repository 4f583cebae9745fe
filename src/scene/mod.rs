//! Scenes: one physical set-up plus its discretization, ensembles per budget and checks
//! (`verification/*.toml`), and the preparation of its runs.
//!
//! - [`spec`]: the scene types ([`Scene`], [`RunSpec`], [`CompressionSpec`], …) and
//!   loading.
//! - [`builtin`]: the project's scenes compiled into the binary, and the one resolver of
//!   `--scene NAME|PATH` ([`load_scene`], [`resolve_scenes`]).
//! - [`keys`]: the documentation of every scene key (meaning, unit, range, default).
//! - [`validate`]: the one validator of linear and compression scenes
//!   ([`Scene::validate`]), with one per-run check shared by both and one check of every
//!   name that becomes a path component of the outputs ([`validate::is_path_name`]).
//! - [`linear`]: a prepared run of a linear scene ([`linear::LinearRun`]): model, exact
//!   references and sampling plan, and the simulation of one trajectory.
//! - [`compression`]: a prepared run of a compression scene
//!   ([`compression::CompressionRun`]), its exact theory table and force estimates.
//! - [`records`]: the per-trajectory records of a run as bytes, bit for bit (what a shard
//!   of an ensemble will hand to the merge, issue #15).
//!
//! Both [`crate::verify`] (pass/fail checks) and [`crate::studies`] (parametric studies)
//! are built on the runs prepared here.

pub mod builtin;
pub mod compression;
pub mod keys;
pub mod linear;
pub mod records;
pub mod spec;
pub mod validate;

pub use builtin::{BUILTIN, BuiltinScene, SceneSource, load_scene, load_scenes, resolve_scenes};
pub use spec::{
    Budget, CheckKind, CompressionSpec, Ensemble, MeshScheme, MeshSpec, ModelKind, PrecisionTarget,
    RunSpec, Sampling, Scene, StepSearch,
};
