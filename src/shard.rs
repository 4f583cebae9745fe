//! Shards (issue #15): one command's ensembles split across processes or machines, and
//! merged back exactly.
//!
//! `--shard I/N` (1 ≤ I ≤ N) makes a process simulate only its share of every run's
//! trajectories: of `T` trajectories, shard `I` takes the contiguous range
//! `⌊(I−1)T/N⌋ .. ⌊IT/N⌋` ([`Shard::range`]), so the shards' ranges tile `0..T` in order
//! and a shard may be empty when `N > T`. Every trajectory's random stream depends only
//! on the scene seed, the run and the trajectory index ([`crate::rng`]), so trajectory
//! `j` is the same bits whichever process simulates it.
//!
//! A shard writes, under its output directory, the per-trajectory sufficient statistics
//! of each run that the checks need (`records/<scene>/<run>.<ext>`, bit for bit, see
//! [`crate::scene::records`]) and, last, the manifest [`SHARD_MANIFEST`]: the command,
//! the shard `I/N`, the build (version and commit), the command's settings (budget, α),
//! every scene's text, SHA-256 and seed, and every record file with its size, SHA-256
//! and trajectory range. A directory without the manifest is an unfinished shard.
//!
//! `langevin-fem merge DIR...` opens the shards ([`ShardSet::open`]) and refuses (exit
//! 2, naming the directory and what differs) shards of another command, build, scene
//! text, seed, setting or shard count, a missing or duplicated shard index, and a record
//! file whose size or SHA-256 is not the manifest's. The command then runs as an
//! unsharded run would, with every run's records read from the shards in trajectory
//! order instead of simulated: its outputs are the unsharded run's, byte for byte, apart
//! from the wall times, run id and provenance.

use crate::error::{Error, Result};
use crate::output::Staging;
use crate::output::io::write_json;
use crate::output::manifest::{OutputKind, refuse_occupied, refuse_taken};
use crate::output::provenance::{Provenance, SceneProvenance, VERSION_LINE};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::Range;
use std::path::{Component, Path, PathBuf};
use std::str::FromStr;

/// File name of a shard's manifest, written last.
pub const SHARD_MANIFEST: &str = crate::output::manifest::SHARD_FILE;
/// The `format` field of a shard manifest.
pub const SHARD_FORMAT: &str = "langevin-fem shard";
/// The version of the shard format (bumped when a reader of the old one would misread).
pub const SHARD_FORMAT_VERSION: u32 = 1;
/// The largest shard count `N` of `--shard I/N`.
pub const MAX_SHARDS: usize = 1_000_000;
/// The directory of a shard's record files, under its output directory.
pub const RECORDS_DIR: &str = "records";

/// Shard `index` of `count` (1-based: `1/4` … `4/4`), as in `--shard I/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Shard {
    /// The shard's index, in `1..=count`.
    pub index: usize,
    /// The number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole ensemble: shard 1 of 1.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// This shard's share of `total` trajectories: `⌊(I−1)·total/N⌋ .. ⌊I·total/N⌋`.
    /// The shards `1/N … N/N` tile `0..total` in order, with sizes differing by at
    /// most one.
    pub fn range(self, total: u64) -> Range<u64> {
        let at = |i: usize| (u128::from(total) * i as u128 / self.count as u128) as u64;
        at(self.index - 1)..at(self.index)
    }

    /// The fraction `1/N` of the work this shard does (for progress and work caps).
    pub fn fraction(self) -> f64 {
        1.0 / self.count as f64
    }

    /// Whether this is the whole ensemble (`1/1`).
    pub fn is_whole(self) -> bool {
        self.count == 1
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;

    /// Parses `I/N` with `1 ≤ I ≤ N ≤` [`MAX_SHARDS`]; the error names what is allowed.
    fn from_str(s: &str) -> std::result::Result<Shard, String> {
        let allowed = format!(
            "I/N with integers 1 <= I <= N <= {MAX_SHARDS} (shard I of N, e.g. 2/4; under Slurm: $SLURM_ARRAY_TASK_ID/N with --array=1-N)"
        );
        let (i, n) = s.split_once('/').ok_or_else(|| allowed.clone())?;
        let (Ok(index), Ok(count)) = (i.trim().parse::<usize>(), n.trim().parse::<usize>()) else {
            return Err(allowed);
        };
        if index < 1 || index > count || count > MAX_SHARDS {
            return Err(allowed);
        }
        Ok(Shard { index, count })
    }
}

/// A scene as a shard ran it: enough to rebuild it exactly at the merge.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardScene {
    /// The scene's name.
    pub name: String,
    /// The scene's file path, or the label of a built-in scene.
    pub source: String,
    /// The scene text as parsed.
    pub text: String,
    /// SHA-256 of `text`.
    pub sha256: String,
    /// The master seed as run (after `--seed`).
    pub seed: u64,
    /// The report's note on the seed ([`crate::verify`]'s callers add it).
    pub seed_note: String,
}

impl ShardScene {
    /// `scene` as run, with the report's note on its seed.
    pub fn of(scene: &Scene, seed_note: &str) -> ShardScene {
        ShardScene {
            name: scene.name.clone(),
            source: scene.path.to_string_lossy().into_owned(),
            text: scene.source_text.clone(),
            sha256: SceneProvenance::hash(&scene.source_text),
            seed: scene.seed,
            seed_note: seed_note.to_string(),
        }
    }

    /// The scene rebuilt from its text, with the seed as run.
    ///
    /// # Errors
    /// [`Error::Scene`] if the text no longer parses (a manifest edited by hand).
    pub fn scene(&self) -> Result<Scene> {
        let mut scene = Scene::parse_named(&self.text, Path::new(&self.source), &self.name)?;
        scene.seed = self.seed;
        Ok(scene)
    }
}

/// One record file of a shard: one run's share of trajectories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    /// The scene.
    pub scene: String,
    /// The run.
    pub run: String,
    /// Path relative to the shard directory (`records/<scene>/<run>.<ext>`).
    pub path: String,
    /// Size in bytes.
    pub bytes: u64,
    /// SHA-256 of the content.
    pub sha256: String,
    /// The trajectories of this shard: `first..first + count` (per strain for a
    /// compression run).
    pub first: u64,
    /// Number of trajectories.
    pub count: u64,
    /// What every shard computes in full and the merge needs (e.g. the plan of a budget
    /// by target precision); equal in every shard of a set.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub common: serde_json::Value,
}

/// A shard's manifest ([`SHARD_MANIFEST`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShardManifest {
    /// [`SHARD_FORMAT`].
    pub format: String,
    /// [`SHARD_FORMAT_VERSION`].
    pub format_version: u32,
    /// The build ([`VERSION_LINE`]: version, commit, dirty).
    pub build: String,
    /// The command (`verify`).
    pub command: String,
    /// This shard.
    pub shard: Shard,
    /// The command's settings that shape the results (budget, α, …); equal in every
    /// shard of a set.
    pub settings: serde_json::Value,
    /// The scenes, in the order run.
    pub scenes: Vec<ShardScene>,
    /// The record files, in the order written.
    pub files: Vec<ShardFile>,
    /// The shard process's provenance ([`Provenance`]: its command line and wall time;
    /// not compared, and dropped by [`ShardSet::open`] but for the first shard).
    pub provenance: serde_json::Value,
}

impl ShardManifest {
    /// The manifest of the shard in `dir`, checked: its format, its shard `I/N`, and that
    /// this build wrote it.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the manifest: unreadable, not a manifest, another
    /// format or build, an index outside `1..=N`.
    pub fn read(dir: &Path) -> Result<ShardManifest> {
        let m = ShardSet::read_manifest(dir)?;
        if m.build != VERSION_LINE {
            return Err(refuse(
                dir,
                "build",
                format!(
                    "written by langevin-fem {}, but this is {VERSION_LINE}: use the build that ran the shards",
                    m.build
                ),
            ));
        }
        Ok(m)
    }

    /// Checks that this manifest (of the shard in `dir`) belongs to the set of `other`
    /// (in `other_dir`): the same command, shard count, settings, scenes and seeds.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming this manifest and what differs.
    pub fn check_same_set(
        &self,
        dir: &Path,
        other: &ShardManifest,
        other_dir: &Path,
    ) -> Result<()> {
        same_set(dir, self, other_dir, other)
    }
}

/// A shard being written: record files first, the manifest last ([`ShardWriter::finish`]).
#[derive(Debug)]
pub struct ShardWriter {
    dir: PathBuf,
    manifest: ShardManifest,
    provenance: Provenance,
    /// Where the shard's files wait until [`Self::finish`] ([`crate::output::staging`]);
    /// `None` before [`Self::start`].
    staging: Option<Staging>,
    /// The files an earlier shard of the same command in the directory lists (read by
    /// [`Self::start`]): the only existing files the shard may replace.
    earlier: std::collections::BTreeSet<String>,
}

impl ShardWriter {
    /// Starts shard `shard` of `command` in `dir` ([`Self::new`], then [`Self::start`]).
    ///
    /// # Errors
    /// As [`Self::start`].
    pub fn begin(
        dir: &Path,
        command: &str,
        shard: Shard,
        settings: serde_json::Value,
        scenes: Vec<ShardScene>,
        provenance: Provenance,
    ) -> Result<ShardWriter> {
        Self::new(dir, command, shard, settings, scenes, provenance).start()
    }

    /// Checks that the shard's directory holds nothing but an earlier shard of the same
    /// command ([`refuse_occupied`]) and opens the staging directory where its files wait
    /// until [`Self::finish`]; called after any check of the input. An earlier shard in
    /// the directory stays as it was (complete, with its manifest) until the new one has
    /// written everything: a refusal or failure before that leaves it untouched.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--out` if the directory holds another command's
    /// output; [`Error::Io`] if the staging directory cannot be created.
    pub fn start(mut self) -> Result<ShardWriter> {
        let kind = OutputKind::Shard {
            command: &self.manifest.command,
        };
        refuse_occupied(&self.dir, kind)?;
        // `refuse_occupied` let a manifest here only if it is the same command's; a shard
        // killed while moving its files into place left their list instead.
        let read = |name: &str| {
            crate::input::read_text(&self.dir.join(name), "-", crate::input::MAX_METADATA_BYTES)
                .ok()
        };
        self.earlier = read(SHARD_MANIFEST)
            .and_then(|text| serde_json::from_str::<ShardManifest>(&text).ok())
            .map(|m| m.files.into_iter().map(|f| f.path).collect())
            .unwrap_or_default();
        if let Some(list) =
            read(PUBLISHING).and_then(|t| serde_json::from_str::<Vec<String>>(&t).ok())
        {
            self.earlier.extend(list);
        }
        self.staging = Some(Staging::new(&self.dir)?);
        Ok(self)
    }

    /// Shard `shard` of `command` in `dir`, not started: nothing is touched on disk until
    /// [`Self::start`].
    pub fn new(
        dir: &Path,
        command: &str,
        shard: Shard,
        settings: serde_json::Value,
        scenes: Vec<ShardScene>,
        provenance: Provenance,
    ) -> ShardWriter {
        ShardWriter {
            dir: dir.to_path_buf(),
            manifest: ShardManifest {
                format: SHARD_FORMAT.to_string(),
                format_version: SHARD_FORMAT_VERSION,
                build: VERSION_LINE.to_string(),
                command: command.to_string(),
                shard,
                settings,
                scenes,
                files: Vec::new(),
                provenance: serde_json::Value::Null,
            },
            provenance,
            staging: None,
            earlier: Default::default(),
        }
    }

    /// This shard.
    pub fn shard(&self) -> Shard {
        self.manifest.shard
    }

    /// The manifest so far (its files: those written yet).
    pub fn manifest(&self) -> &ShardManifest {
        &self.manifest
    }

    /// Writes one run's records (`bytes`, trajectories `range`) atomically as
    /// `records/<scene>/<run>.<ext>` (staged until [`Self::finish`]) and lists it, with
    /// `common`.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be written.
    pub fn write(
        &mut self,
        (scene, run, ext): (&str, &str, &str),
        range: Range<u64>,
        bytes: &[u8],
        common: serde_json::Value,
    ) -> Result<()> {
        let rel = format!("{RECORDS_DIR}/{scene}/{run}.{ext}");
        crate::output::io::write_atomic(&self.staged(&rel)?, bytes)?;
        self.list((scene, run), &rel, bytes, range, common);
        Ok(())
    }

    /// Where to write the shard's file `rel` (a plain relative path) while the shard goes
    /// on: in its staging directory, moved into place by [`Self::finish`].
    ///
    /// # Errors
    /// [`Error::Io`] if the writer was not started or `rel` is not a plain relative path.
    pub fn staged(&self, rel: &str) -> Result<PathBuf> {
        let invalid = |why: &str| {
            Error::io(
                self.dir.join(rel),
                std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string()),
            )
        };
        let staging = self
            .staging
            .as_ref()
            .ok_or_else(|| invalid("the shard writer was not started"))?;
        crate::output::manifest::safe_relative(rel)
            .ok_or_else(|| invalid("not a plain relative path"))?;
        Ok(staging.path(rel))
    }

    /// Lists the file `rel` with content `bytes` in the manifest.
    fn list(
        &mut self,
        (scene, run): (&str, &str),
        rel: &str,
        bytes: &[u8],
        range: Range<u64>,
        common: serde_json::Value,
    ) {
        self.manifest.files.push(ShardFile {
            scene: scene.to_string(),
            run: run.to_string(),
            path: rel.to_string(),
            bytes: bytes.len() as u64,
            sha256: sha256_hex(bytes),
            first: range.start,
            count: range.end - range.start,
            common,
        });
    }

    /// The shard's output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Lists a file already written (atomically) at [`Self::staged`]`(rel)`: one run's
    /// trajectories `range`, with `common`; its size and SHA-256 are read back.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read.
    pub fn add_file(
        &mut self,
        (scene, run): (&str, &str),
        rel: &str,
        range: Range<u64>,
        common: serde_json::Value,
    ) -> Result<()> {
        let path = self.staged(rel)?;
        let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
        self.list((scene, run), rel, &bytes, range, common);
        Ok(())
    }

    /// Finishes the shard: refuses, touching nothing, a file that would replace one no
    /// earlier shard here listed ([`Staging::taken`]); writes the list of files it owns
    /// ([`PUBLISHING`]), removes an earlier manifest (so that a shard killed from here on
    /// is never taken for a finished one), moves the files into place, writes the
    /// manifest (atomically) and removes the list; returns the manifest.
    ///
    /// # Errors
    /// [`Error::Io`] if a file cannot be moved or written.
    pub fn finish(mut self) -> Result<ShardManifest> {
        self.provenance.finish();
        self.manifest.provenance = serde_json::to_value(&self.provenance)
            .map_err(|e| Error::io(self.dir.join(SHARD_MANIFEST), e.into()))?;
        if let Some(staging) = &self.staging {
            let files = self.manifest.files.iter().map(|f| f.path.as_str());
            if let Some(rel) = staging.taken(files, |f| self.earlier.contains(f)) {
                return Err(refuse_taken(&self.dir, &self.manifest.command, &rel));
            }
        }
        // The files this shard owns from here until its manifest is written: a shard
        // killed in between is rerun into the same directory without a refusal.
        let owned: Vec<&str> = (self.earlier.iter().map(String::as_str))
            .chain(self.manifest.files.iter().map(|f| f.path.as_str()))
            .collect();
        let publishing = self.dir.join(PUBLISHING);
        write_json(&publishing, &owned)?;
        let old = self.dir.join(SHARD_MANIFEST);
        match std::fs::remove_file(&old) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(Error::io(&old, e)),
            _ => {}
        }
        if let Some(staging) = &mut self.staging {
            staging.publish(self.manifest.files.iter().map(|f| f.path.as_str()))?;
        }
        write_json(&self.dir.join(SHARD_MANIFEST), &self.manifest)?;
        std::fs::remove_file(&publishing).map_err(|e| Error::io(&publishing, e))?;
        Ok(self.manifest)
    }
}

/// The list of files a shard is moving into place (hidden; removed once its manifest is
/// written): what a rerun after a kill in between may replace.
const PUBLISHING: &str = ".langevin-fem-shard-publishing.json";

/// The SHA-256 of `bytes` in lower-case hex.
fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A complete, consistent set of shards `1/N … N/N` of one command, opened for the merge.
#[derive(Debug, Clone)]
pub struct ShardSet {
    /// Each shard's directory and manifest, in shard order, without the scenes and the
    /// provenance (equal in every shard: see [`Self::manifest`]).
    pub shards: Vec<(PathBuf, ShardManifest)>,
    /// The first manifest read, whole.
    first: ShardManifest,
    /// The largest total of record bytes held at once (one run's records from every
    /// shard), and so the largest record file: the memory cap (`--max-memory-gib`).
    max_bytes: u64,
}

/// One record file of a shard set as read: its manifest entry, its bytes, and where it
/// comes from in words (`<shard dir>/<path> (shard I/N)`), for the messages of its
/// decoder.
#[derive(Debug, Clone)]
pub struct ShardRecord {
    /// The manifest entry.
    pub file: ShardFile,
    /// The content, checked against the entry's size and SHA-256.
    pub bytes: Vec<u8>,
    /// The file's path and shard, in words.
    pub source: String,
}

/// Refusal of the shard in `dir` (exit 2): names its manifest, the key and what is
/// wrong. Every refusal of a shard or a shard set is one of these.
pub fn refuse(dir: &Path, key: &str, message: String) -> Error {
    Error::Scene {
        file: dir.join(SHARD_MANIFEST),
        key: key.to_string(),
        message,
    }
}

/// The manifest key of the setting that flag `flag` sets (`--duration-tau1` →
/// `settings.duration_tau1`, `--run` → `settings.runs`).
fn settings_key(flag: &str) -> String {
    match flag.trim_start_matches('-') {
        "run" => "settings.runs".to_string(),
        f => format!("settings.{}", f.replace('-', "_")),
    }
}

/// The manifest key of the files of run `run` of scene `scene` (`files[<scene>/<run>]`),
/// as refusals name them.
pub fn files_key(scene: &str, run: &str) -> String {
    format!("files[{scene}/{run}]")
}

impl ShardSet {
    /// The shard directories named by `dirs`: each a shard directory (with a
    /// [`SHARD_MANIFEST`]) or a directory whose sub-directories are shards.
    fn expand(dirs: &[PathBuf]) -> Result<Vec<PathBuf>> {
        let mut out = Vec::new();
        for dir in dirs {
            // Any entry of that name (a FIFO or directory too) makes a shard directory,
            // whose manifest is then refused for what it is, not taken for absent.
            let has_manifest = |d: &Path| std::fs::symlink_metadata(d.join(SHARD_MANIFEST)).is_ok();
            if has_manifest(dir) {
                out.push(dir.clone());
                continue;
            }
            let entries = std::fs::read_dir(dir).map_err(|e| {
                refuse(
                    dir,
                    "-",
                    format!("cannot read the directory {}: {e}", dir.display()),
                )
            })?;
            let mut subs: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_dir() && has_manifest(p))
                .collect();
            if subs.is_empty() {
                return Err(refuse(
                    dir,
                    "-",
                    format!(
                        "no {SHARD_MANIFEST} in {} nor in its sub-directories: not a shard (an unfinished shard has no manifest yet; rerun it)",
                        dir.display()
                    ),
                ));
            }
            subs.sort();
            out.extend(subs);
        }
        Ok(out)
    }

    /// Reads a manifest.
    fn read_manifest(dir: &Path) -> Result<ShardManifest> {
        let path = dir.join(SHARD_MANIFEST);
        let text =
            crate::input::read_text(&path, "-", crate::input::MAX_METADATA_BYTES).map_err(|e| {
                match e {
                    Error::Scene { message, .. } => {
                        refuse(dir, "-", format!("cannot be read as text: {message}"))
                    }
                    other => other,
                }
            })?;
        let m: ShardManifest = crate::input::parse_json(&path, &text, "a shard manifest")?;
        let s = m.shard;
        if s.index < 1 || s.index > s.count || s.count > MAX_SHARDS {
            return Err(refuse(
                dir,
                "shard",
                format!(
                    "shard {}/{}: 1 <= I <= N <= {MAX_SHARDS} is required",
                    s.index, s.count
                ),
            ));
        }
        if m.format != SHARD_FORMAT || m.format_version != SHARD_FORMAT_VERSION {
            return Err(refuse(
                dir,
                "format_version",
                format!(
                    "{} version {}; this build reads {SHARD_FORMAT} version {SHARD_FORMAT_VERSION}",
                    m.format, m.format_version
                ),
            ));
        }
        Ok(m)
    }

    /// Opens the shards in `dirs` (shard directories, or directories of them) and checks
    /// that they are one complete set of one command ([`ShardManifest::command`]) whose
    /// every file has the size and SHA-256 its manifest lists.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the shard's manifest: not a shard; another format,
    /// command, build (also than this merge's), shard count, setting, scene or seed than
    /// the first shard; a duplicated index (naming both directories); missing indices; a
    /// file missing, unreadable or damaged ([`Self::read_file`]).
    pub fn open(dirs: &[PathBuf], max_bytes: u64) -> Result<ShardSet> {
        let mut shards: Vec<(PathBuf, ShardManifest)> = Vec::new();
        let mut first: Option<(PathBuf, ShardManifest)> = None;
        // Index → position in `shards`: duplicates and gaps in O(N log N).
        let mut seen: std::collections::BTreeMap<usize, usize> = Default::default();
        for dir in Self::expand(dirs)? {
            let mut m = ShardManifest::read(&dir)?;
            match &first {
                Some((first_dir, first)) => same_set(&dir, &m, first_dir, first)?,
                None => {
                    check_scene_hashes(&dir, &m)?;
                    first = Some((dir.clone(), m.clone()));
                }
            }
            if let Some(&k) = seen.get(&m.shard.index) {
                return Err(refuse(
                    &dir,
                    "shard",
                    format!(
                        "shard {} given twice: in {} and in {}",
                        m.shard,
                        shards[k].0.display(),
                        dir.display()
                    ),
                ));
            }
            seen.insert(m.shard.index, shards.len());
            // Checked equal to the first shard's: not kept (10⁴ shards' scene texts and
            // provenance would be most of the merge's memory).
            m.scenes = Vec::new();
            m.provenance = serde_json::Value::Null;
            shards.push((dir, m));
        }
        shards.sort_by_key(|(_, m)| m.shard.index);
        let Some((_, first)) = first else {
            return Err(Error::invalid(
                "merge DIR",
                "no directory",
                "at least one shard",
            ));
        };
        let count = first.shard.count;
        let missing: Vec<String> = (1..=count)
            .filter(|i| !seen.contains_key(i))
            .map(|i| format!("{i}/{count}"))
            .collect();
        if !missing.is_empty() {
            let shown = missing
                .iter()
                .take(20)
                .cloned()
                .collect::<Vec<_>>()
                .join(", ");
            let more = if missing.len() > 20 {
                format!(" and {} more", missing.len() - 20)
            } else {
                String::new()
            };
            return Err(refuse(
                &shards[0].0,
                "shard",
                format!(
                    "the set of {count} shards is incomplete: missing shard {shown}{more} (given: {} director{})",
                    shards.len(),
                    if shards.len() == 1 { "y" } else { "ies" }
                ),
            ));
        }
        let set = ShardSet {
            shards,
            first,
            max_bytes,
        };
        // Every file against its manifest now, before the merge writes anything: a
        // damaged shard is input (exit 2) and must leave an earlier output untouched.
        for (k, (_, m)) in set.shards.iter().enumerate() {
            for entry in &m.files {
                set.read_file(k, entry)?;
            }
        }
        Ok(set)
    }

    /// A refusal of this set (exit 2) naming the first shard's manifest ([`refuse`]): its
    /// settings or scenes (equal in every shard) or what the shards together hold.
    pub fn refuse(&self, key: &str, message: String) -> Error {
        refuse(&self.shards[0].0, key, message)
    }

    /// `e`, raised by the command's own check of the settings the shards ran with (an
    /// [`Error::InvalidParameter`] naming a flag, e.g. `--trajectories`), as a refusal
    /// of this set naming the first manifest's `settings` (exit 2): the flags were checked
    /// when the shards ran, so a value out of range here is a damaged or edited manifest.
    /// Other errors are returned as they are, and so is one naming `--out`: the merge's
    /// own output directory (`merge -o`), not the shards'.
    pub fn settings_error(&self, e: Error) -> Error {
        match e {
            Error::InvalidParameter {
                name,
                value,
                allowed,
            } if name.starts_with("--") && name != "--out" => self.refuse(
                &settings_key(&name),
                format!(
                    "the shards ran with {name} = {value}, but {name} must be {allowed}: a damaged or edited manifest; rerun the shards"
                ),
            ),
            other => other,
        }
    }

    /// The largest total of record bytes the merge may hold at once (the memory cap).
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    /// The first manifest read, whole: the command's settings and scenes (equal in every
    /// shard of the set).
    pub fn manifest(&self) -> &ShardManifest {
        &self.first
    }

    /// The scenes, rebuilt from their text, and each one's seed note.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the first shard's manifest and the key
    /// `scenes[k].text: <scene key>` if a scene's text does not parse or validate: the
    /// text and its SHA-256 edited together after the shard ran (the scene's own file
    /// or built-in label is not what the user must fix).
    pub fn scenes(&self) -> Result<Vec<(Scene, String)>> {
        self.manifest()
            .scenes
            .iter()
            .enumerate()
            .map(|(k, s)| match s.scene() {
                Ok(scene) => Ok((scene, s.seed_note.clone())),
                Err(Error::Scene { key, message, .. }) => Err(self.refuse(
                    &format!("scenes[{k}].text: {key}"),
                    format!(
                        "{message} (the text of scene {}, edited after the shard ran; rerun the shards)",
                        s.name
                    ),
                )),
                Err(e) => Err(e),
            })
            .collect()
    }

    /// The content of `entry`, a file of shard number `k` (0-based, in shard order),
    /// checked against the manifest's size and SHA-256.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the shard: a path that leaves the shard
    /// directory, a file unreadable, of another size or hash.
    pub fn read_file(&self, k: usize, entry: &ShardFile) -> Result<Vec<u8>> {
        let (dir, m) = &self.shards[k];
        let key = files_key(&entry.scene, &entry.run);
        let rel = Path::new(&entry.path);
        if !rel.components().all(|c| matches!(c, Component::Normal(_))) {
            return Err(refuse(
                dir,
                &key,
                format!(
                    "path {} leaves the shard directory: a relative path inside it is required",
                    entry.path
                ),
            ));
        }
        let path = dir.join(rel);
        if entry.bytes > self.max_bytes {
            return Err(refuse(
                dir,
                &key,
                format!(
                    "{} is listed with {} bytes, more than the memory cap of {} (--max-memory-gib): a damaged manifest, or raise the cap",
                    entry.path,
                    entry.bytes,
                    crate::input::human_bytes(self.max_bytes)
                ),
            ));
        }
        // Read at most one byte more than listed: a longer file is damaged, never read
        // whole.
        let bytes =
            crate::input::read_bytes(&path, &key, entry.bytes.saturating_add(1)).map_err(|e| {
                match e {
                    Error::Scene { message, .. } => {
                        refuse(dir, &key, format!("{}: {message}", path.display()))
                    }
                    other => other,
                }
            })?;
        if bytes.len() as u64 != entry.bytes || sha256_hex(&bytes) != entry.sha256 {
            return Err(refuse(
                dir,
                &key,
                format!(
                    "{} is {} bytes with SHA-256 {}, the manifest says {} bytes with {}: damaged or replaced; rerun shard {}",
                    path.display(),
                    bytes.len(),
                    sha256_hex(&bytes),
                    entry.bytes,
                    entry.sha256,
                    m.shard
                ),
            ));
        }
        Ok(bytes)
    }

    /// Every shard's files of run `run` of scene `scene`, in shard order (hence in
    /// trajectory order), each with the index of its shard (for [`Self::read_file`]).
    pub fn files<'a>(
        &'a self,
        scene: &'a str,
        run: &'a str,
    ) -> impl Iterator<Item = (usize, &'a ShardFile)> + 'a {
        self.shards.iter().enumerate().flat_map(move |(k, (_, m))| {
            m.files
                .iter()
                .filter(move |f| f.scene == scene && f.run == run)
                .map(move |f| (k, f))
        })
    }

    /// Every shard's one record file of run `run` of scene `scene`, in shard order (hence
    /// in trajectory order), each with its manifest entry and source, checked for
    /// contiguous ranges, size and SHA-256, their total within the memory cap.
    ///
    /// # Errors
    /// [`Error::Scene`] (exit 2) naming the shard: a file not listed, unreadable, of
    /// another size or hash; ranges that do not follow one another; a `common` value
    /// that differs from the first shard's; more bytes in all than the memory cap.
    pub fn read(&self, scene: &str, run: &str) -> Result<Vec<ShardRecord>> {
        let mut out: Vec<ShardRecord> = Vec::new();
        let mut total: u64 = 0;
        for (k, (dir, m)) in self.shards.iter().enumerate() {
            let key = files_key(scene, run);
            let entry = m
                .files
                .iter()
                .find(|f| f.scene == scene && f.run == run)
                .ok_or_else(|| {
                    refuse(
                        dir,
                        &key,
                        format!(
                            "shard {} has no records of run {run} of scene {scene}",
                            m.shard
                        ),
                    )
                })?;
            total = total.saturating_add(entry.bytes);
            if total > self.max_bytes {
                return Err(refuse(
                    dir,
                    &key,
                    format!(
                        "the shards' records of run {run} of scene {scene} come to more than the memory cap of {} (--max-memory-gib) by shard {}: raise the cap, or check the manifests' sizes",
                        crate::input::human_bytes(self.max_bytes),
                        m.shard
                    ),
                ));
            }
            let bytes = self.read_file(k, entry)?;
            if let Some(ShardRecord { file: prev, .. }) = out.last() {
                let next = prev.first.checked_add(prev.count);
                if next != Some(entry.first) {
                    let (prev_dir, prev_m) = &self.shards[k - 1];
                    return Err(refuse(
                        dir,
                        &key,
                        format!(
                            "trajectories {}..{} (first {}, count {}) do not follow those of the previous shard {} in {}: {}..{} (first {}, count {}); one of the two manifests is damaged",
                            entry.first,
                            entry.first.saturating_add(entry.count),
                            entry.first,
                            entry.count,
                            prev_m.shard,
                            prev_dir.join(SHARD_MANIFEST).display(),
                            prev.first,
                            prev.first.saturating_add(prev.count),
                            prev.first,
                            prev.count
                        ),
                    ));
                }
                if entry.common != out[0].file.common {
                    return Err(refuse(
                        dir,
                        &key,
                        format!(
                            "shard {} computed another plan for this run than shard {}: not the same inputs or build",
                            m.shard, self.shards[0].1.shard
                        ),
                    ));
                }
            }
            out.push(ShardRecord {
                file: entry.clone(),
                bytes,
                source: format!("{} (shard {})", dir.join(&entry.path).display(), m.shard),
            });
        }
        Ok(out)
    }
}

/// Checks that every scene text of manifest `m` (in `dir`) has the SHA-256 the manifest
/// lists: a text edited by hand is refused, never merged and judged.
fn check_scene_hashes(dir: &Path, m: &ShardManifest) -> Result<()> {
    for (k, scene) in m.scenes.iter().enumerate() {
        let hash = SceneProvenance::hash(&scene.text);
        if hash != scene.sha256 {
            return Err(refuse(
                dir,
                &format!("scenes[{k}].text"),
                format!(
                    "the text of scene {} has SHA-256 {hash}, but the manifest lists {}: edited after the shard ran; rerun the shards",
                    scene.name, scene.sha256
                ),
            ));
        }
    }
    Ok(())
}

/// Checks that shard `m` (in `dir`) belongs to the set of `first` (in `first_dir`).
fn same_set(dir: &Path, m: &ShardManifest, first_dir: &Path, first: &ShardManifest) -> Result<()> {
    let against = format!("{} (shard {})", first_dir.display(), first.shard);
    if m.command != first.command {
        return Err(refuse(
            dir,
            "command",
            format!(
                "a shard of `{}`, but {against} is of `{}`",
                m.command, first.command
            ),
        ));
    }
    if m.shard.count != first.shard.count {
        return Err(refuse(
            dir,
            "shard",
            format!(
                "shard {} of a set of {}, but {against} is of a set of {}",
                m.shard, m.shard.count, first.shard.count
            ),
        ));
    }
    if m.settings != first.settings {
        return Err(refuse(
            dir,
            "settings",
            format!("{} differ from {against}'s {}", m.settings, first.settings),
        ));
    }
    let names = |m: &ShardManifest| m.scenes.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    if names(m) != names(first) {
        return Err(refuse(
            dir,
            "scenes",
            format!(
                "scenes [{}], but {against} ran [{}]",
                names(m).join(", "),
                names(first).join(", ")
            ),
        ));
    }
    for (k, (a, b)) in m.scenes.iter().zip(&first.scenes).enumerate() {
        if a.sha256 != b.sha256 || a.text != b.text || a.source != b.source {
            return Err(refuse(
                dir,
                &format!("scenes[{k}].sha256"),
                format!(
                    "scene {} has SHA-256 {}, but {against} ran it with {}: another scene file",
                    a.name, a.sha256, b.sha256
                ),
            ));
        }
        if a.seed != b.seed || a.seed_note != b.seed_note {
            return Err(refuse(
                dir,
                &format!("scenes[{k}].seed"),
                format!(
                    "scene {} ran with seed {}, but {against} with seed {}",
                    a.name, a.seed, b.seed
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shards' ranges tile `0..total` in order, sizes differing by at most one,
    /// including empty shares when there are more shards than trajectories.
    #[test]
    fn ranges_tile_the_ensemble() {
        for total in [0u64, 1, 5, 16, 17, 1000] {
            for count in [1usize, 2, 3, 4, 7, 16, 40] {
                let mut next = 0;
                for index in 1..=count {
                    let r = Shard { index, count }.range(total);
                    assert_eq!(r.start, next, "{index}/{count} of {total}");
                    let size = r.end - r.start;
                    assert!(size * count as u64 <= total + count as u64, "{size}");
                    assert!((size + 1) * count as u64 >= total, "{size}");
                    next = r.end;
                }
                assert_eq!(next, total);
            }
        }
        assert_eq!(Shard::WHOLE.range(16), 0..16);
    }

    /// `I/N` parses with 1 ≤ I ≤ N ≤ MAX_SHARDS; anything else is refused with the rule.
    #[test]
    fn shard_flag_parses_and_refuses() {
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        assert_eq!(" 1 / 1 ".parse::<Shard>(), Ok(Shard::WHOLE));
        for bad in ["0/4", "5/4", "2", "a/b", "-1/3", "1/0", "1/2000000", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains("1 <= I <= N"), "{bad}: {e}");
        }
        assert_eq!(Shard { index: 3, count: 7 }.to_string(), "3/7");
    }

    /// Hand-edited or foreign manifests are refused as input (exit 2) naming the
    /// manifest, never a panic: an index outside 1..=N, a count of 0, not JSON, not text.
    #[test]
    fn bad_manifests_are_refused_as_input() {
        let scene = crate::scene::builtin::find("hinged-linear-2d")
            .expect("built-in scene")
            .load()
            .expect("loads");
        let root =
            std::env::temp_dir().join(format!("langevin-fem-bad-manifests-{}", std::process::id()));
        let dir = root.join("1");
        let writer = ShardWriter::begin(
            &dir,
            "verify",
            Shard::WHOLE,
            serde_json::json!({}),
            vec![ShardScene::of(&scene, "")],
            Provenance::begin(&[&scene]),
        )
        .unwrap();
        writer.finish().unwrap();
        assert!(ShardSet::open(std::slice::from_ref(&dir), 1 << 30).is_ok());
        let path = dir.join(SHARD_MANIFEST);
        let good: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let with_shard = |index: usize, count: usize| {
            let mut m = good.clone();
            m["shard"] = serde_json::json!({"index": index, "count": count});
            serde_json::to_vec(&m).unwrap()
        };
        let cases: [(&str, Vec<u8>, &str); 5] = [
            ("index 0", with_shard(0, 3), "1 <= I <= N"),
            ("index above count", with_shard(4, 3), "1 <= I <= N"),
            ("count 0", with_shard(1, 0), "1 <= I <= N"),
            ("not JSON", b"{ not json".to_vec(), "not a shard manifest"),
            ("not text", vec![0xff, 0xfe, 0x00], "cannot be read as text"),
        ];
        for (what, bytes, expect) in cases {
            std::fs::write(&path, bytes).unwrap();
            let err = ShardSet::open(std::slice::from_ref(&dir), 1 << 30).unwrap_err();
            assert_eq!(err.exit_code(), 2, "{what}: {err}");
            let text = err.to_string();
            assert!(
                text.contains(expect) && text.contains(SHARD_MANIFEST),
                "{what}: {text}"
            );
        }
        let _ = std::fs::remove_dir_all(&root);
    }
}
