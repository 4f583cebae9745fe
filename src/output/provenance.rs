//! Provenance: what produced an output (issue #13). Every report directory's journal
//! (`manifest.json`, `<stem>.manifest.json`) carries one [`Provenance`]; the entry points
//! (`summary.json`, a study's `<stem>.json`) carry its [`ProvenanceRef`], the file name of
//! that journal plus the essentials in clear.
//!
//! A [`Provenance`] records the tool and its version, the git commit it was built from
//! (baked in by `build.rs`; `unknown` for a build outside a git checkout) and whether
//! the work tree had uncommitted changes to tracked files, the command line, the start
//! time (RFC 3339, UTC), the wall time, the thread count, and per scene a
//! [`SceneProvenance`]: its name, where it came from, the full scene text as parsed with
//! its SHA-256 and the overrides applied after parsing, the seed as run, the
//! discretization and the physical parameters with their units and dimensionless groups.
//!
//! This module knows nothing about scenes: a scene type describes itself through
//! [`DescribeScene`] (implemented by [`crate::scene::Scene`]), so that any command, the
//! verification, the studies or a future one, calls
//! [`Provenance::begin`]`(&[&scene])` when it starts and [`Provenance::finish`] when it
//! ends.
//!
//! ## Units
//! A [`Quantity`]'s unit is concrete (`µm`, `pN·µm²`, `s`) for a scene given in physical
//! units, and names the scene's consistent unit system otherwise: `[L]`, `[E]` and `[T]`
//! are the units of the scene's `length`, of its energies (`kt`) and the time unit they
//! imply (τ₁ = ξL⁴/(π⁴EI) is given in it). [`SceneProvenance::units`] maps these base
//! dimensions to the concrete units of the scene; the column dictionary
//! ([`super::columns`]) writes units in the same base dimensions.

use std::collections::BTreeMap;
use std::time::{Instant, SystemTime};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// The tool's name, as in every provenance record.
pub const TOOL: &str = "langevin-fem";
/// The package version (`Cargo.toml`).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The git commit the binary was built from (`git rev-parse HEAD` at build time), or
/// `unknown` for a build outside a git checkout.
pub const COMMIT: &str = env!("LANGEVIN_FEM_COMMIT");
/// `true` if tracked files differed from [`COMMIT`] at build time, `false` if not,
/// `unknown` without git.
pub const DIRTY: &str = env!("LANGEVIN_FEM_DIRTY");
/// What `langevin-fem --version` prints after the name: version, commit (12 hex
/// digits) and `dirty` if the work tree had changes.
pub const VERSION_LINE: &str = env!("LANGEVIN_FEM_VERSION_LINE");

/// Whether the build's work tree had uncommitted changes ([`DIRTY`]); `None` if unknown.
pub fn build_dirty() -> Option<bool> {
    match DIRTY {
        "true" => Some(true),
        "false" => Some(false),
        _ => None,
    }
}

/// A value with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quantity {
    /// The value (full precision).
    pub value: f64,
    /// Its unit: concrete (`µm`, `pN·µm²`, `s`), in the scene's base dimensions (`[L]`,
    /// `[E]`, `[T]`), or `1` for a dimensionless number.
    pub unit: String,
}

impl Quantity {
    /// `value` in `unit`.
    pub fn new(value: f64, unit: impl Into<String>) -> Self {
        Quantity {
            value,
            unit: unit.into(),
        }
    }
}

/// The physical parameters of a scene: as the scene file gave them, converted, and the
/// dimensionless groups.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ParameterRecord {
    /// `physical` (the scene gave the filament in physical units, converted to µm, s,
    /// pN) or `consistent` (the scene's own consistent units).
    pub unit_system: String,
    /// The keys the scene file gave in physical units, as written (e.g.
    /// `persistence_length_um`); empty for a scene in consistent units.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub given: BTreeMap<String, Quantity>,
    /// The parameters the simulation uses (`length`, `bending_rigidity`,
    /// `stretch_rigidity`, `drag`, `kt`; a membrane's `width`, `height`,
    /// `bending_rigidity`, `tension`, `drag`, `kt`).
    pub parameters: BTreeMap<String, Quantity>,
    /// Dimensionless groups and scales: `persistence_ratio` ℓp/L = EI/(kT·L),
    /// `stretch_ratio` EA·L/kT, `tau1` τ₁ = ξL⁴/(π⁴EI), `euler_load` F_c0 = π²EI/L²;
    /// a membrane's `tau1` (its slowest relaxation time), `buckling_tension` −κq_min²
    /// and `tension_ratio` σ/(κq_min²).
    pub groups: BTreeMap<String, Quantity>,
}

/// One scene as run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneProvenance {
    /// Scene name.
    pub name: String,
    /// Where the scene came from: the file path as given, or the name of a built-in scene.
    pub source: String,
    /// The full scene text as parsed (empty for a scene built in code).
    pub text: String,
    /// SHA-256 of `text` (its UTF-8 bytes), lowercase hex.
    pub sha256: String,
    /// Changes made to the parsed scene before it ran (e.g. `seed = 7 (file: 20261123)`
    /// from a `--seed` flag); empty if it ran as written.
    #[serde(default)]
    pub overrides: Vec<String>,
    /// The master seed as run.
    pub seed: u64,
    /// The model (`fem`, `spectral`, `compression`).
    pub model: String,
    /// 2 or 3.
    pub dims: usize,
    /// Element count (fem, compression) or number of modes (spectral).
    pub elements: usize,
    /// The scene's base dimensions and their concrete units: `length`, `energy`,
    /// `time`, `force`.
    pub units: BTreeMap<String, String>,
    /// The physical parameters with their units.
    pub parameters: ParameterRecord,
}

impl SceneProvenance {
    /// SHA-256 of `text`, lowercase hex.
    pub fn hash(text: &str) -> String {
        Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }
}

/// A scene type that can describe itself for the provenance (see the
/// [module docs](self)).
pub trait DescribeScene {
    /// The provenance record of the scene as it will run.
    fn describe(&self) -> SceneProvenance;
}

impl DescribeScene for SceneProvenance {
    fn describe(&self) -> SceneProvenance {
        self.clone()
    }
}

/// What produced an output (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// `langevin-fem`.
    pub tool: String,
    /// The package version.
    pub version: String,
    /// The git commit of the build ([`COMMIT`]).
    pub commit: String,
    /// Whether tracked files differed from `commit` at build time (`null`: unknown).
    pub dirty: Option<bool>,
    /// The command line (`std::env::args`), program name first.
    pub command_line: Vec<String>,
    /// Start time, RFC 3339 in UTC to the second, e.g. `2026-12-02T02:06:36Z`.
    pub started: String,
    /// Wall time from start to [`Provenance::finish`], in seconds (`null` until then).
    pub wall_seconds: Option<f64>,
    /// Worker threads of the parallel runs (`rayon::current_num_threads`). The results
    /// do not depend on it (one random stream per trajectory).
    pub threads: usize,
    /// The scenes, in the order they ran.
    pub scenes: Vec<SceneProvenance>,
    /// The clock of `wall_seconds` (not serialized).
    #[serde(skip)]
    clock: Option<Instant>,
}

impl Provenance {
    /// Starts the record of a command running `scenes` now.
    pub fn begin<S: DescribeScene + ?Sized>(scenes: &[&S]) -> Provenance {
        Provenance {
            tool: TOOL.to_string(),
            version: VERSION.to_string(),
            commit: COMMIT.to_string(),
            dirty: build_dirty(),
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            started: humantime::format_rfc3339_seconds(SystemTime::now()).to_string(),
            wall_seconds: None,
            threads: rayon::current_num_threads(),
            scenes: scenes.iter().map(|s| s.describe()).collect(),
            clock: Some(Instant::now()),
        }
    }

    /// Records the wall time since [`Provenance::begin`] (again on a second call; a
    /// record read back from a file, without a clock, keeps its wall time).
    pub fn finish(&mut self) {
        if let Some(clock) = self.clock {
            self.wall_seconds = Some(clock.elapsed().as_secs_f64());
        }
    }

    /// The reference to this record for an entry point: the journal `manifest` that holds
    /// it, and the essentials in clear.
    pub fn reference(&self, manifest: &str) -> ProvenanceRef {
        ProvenanceRef {
            manifest: manifest.to_string(),
            version: self.version.clone(),
            commit: self.commit.clone(),
            dirty: self.dirty,
            started: self.started.clone(),
            command_line: self.command_line.clone(),
            threads: self.threads,
            scenes: self
                .scenes
                .iter()
                .map(|s| SceneRef {
                    name: s.name.clone(),
                    source: s.source.clone(),
                    sha256: s.sha256.clone(),
                    seed: s.seed,
                    overrides: s.overrides.clone(),
                })
                .collect(),
        }
    }
}

/// An entry point's reference to the provenance in its journal, with the essentials in
/// clear (what the index page shows).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProvenanceRef {
    /// File name of the journal that holds the full [`Provenance`] (e.g.
    /// `manifest.json`), in the same directory.
    pub manifest: String,
    /// The package version.
    pub version: String,
    /// The git commit of the build.
    pub commit: String,
    /// Whether the build's work tree had changes (`null`: unknown).
    pub dirty: Option<bool>,
    /// Start time, RFC 3339 UTC.
    pub started: String,
    /// The command line.
    pub command_line: Vec<String>,
    /// Worker threads.
    pub threads: usize,
    /// Per scene: name, source, hash, seed as run and overrides.
    pub scenes: Vec<SceneRef>,
}

/// One scene of a [`ProvenanceRef`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneRef {
    /// Scene name.
    pub name: String,
    /// File path or built-in name.
    pub source: String,
    /// SHA-256 of the scene text as parsed.
    pub sha256: String,
    /// The master seed as run.
    pub seed: u64,
    /// Changes made to the parsed scene before it ran.
    #[serde(default)]
    pub overrides: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str, text: &str) -> SceneProvenance {
        SceneProvenance {
            name: name.to_string(),
            source: format!("{name}.toml"),
            text: text.to_string(),
            sha256: SceneProvenance::hash(text),
            overrides: Vec::new(),
            seed: 7,
            model: "fem".to_string(),
            dims: 2,
            elements: 4,
            units: BTreeMap::new(),
            parameters: ParameterRecord::default(),
        }
    }

    /// SHA-256 test vectors (FIPS 180-2 examples).
    #[test]
    fn sha256_of_known_texts() {
        assert_eq!(
            SceneProvenance::hash(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            SceneProvenance::hash("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn begin_records_the_build_the_clock_and_the_scenes() {
        let a = scene("a", "seed = 7\n");
        let mut p = Provenance::begin(&[&a]);
        assert_eq!(p.tool, "langevin-fem");
        assert_eq!(p.version, env!("CARGO_PKG_VERSION"));
        assert!(
            p.commit == "unknown" || p.commit.len() == 40,
            "{}",
            p.commit
        );
        assert!(p.threads >= 1);
        assert!(!p.command_line.is_empty());
        // RFC 3339, UTC, to the second: 2026-12-02T02:06:36Z.
        let t = humantime::parse_rfc3339(&p.started).expect("rfc 3339");
        assert!(
            p.started.ends_with('Z') && p.started.len() == 20,
            "{}",
            p.started
        );
        assert!(SystemTime::now().duration_since(t).expect("past").as_secs() < 60);
        assert_eq!(p.wall_seconds, None);
        p.finish();
        assert!(p.wall_seconds.is_some_and(|w| (0.0..60.0).contains(&w)));
        assert_eq!(p.scenes.len(), 1);
        assert_eq!(p.scenes[0], a);
        let r = p.reference("manifest.json");
        assert_eq!(r.manifest, "manifest.json");
        assert_eq!(r.scenes[0].sha256, a.sha256);
        assert_eq!(r.scenes[0].seed, 7);
        // Read back from JSON: the same record, and finish keeps its wall time.
        let mut back: Provenance =
            serde_json::from_str(&serde_json::to_string(&p).expect("json")).expect("read");
        let wall = p.wall_seconds;
        back.finish();
        assert_eq!(back.wall_seconds, wall);
        assert_eq!(back.scenes, p.scenes);
    }
}
