//! Report runs: a run id and a manifest of every file a run writes, so that every file of
//! a report directory belongs to one run, and a run that is killed, or a rerun that writes
//! fewer files, never leaves an old entry point describing new files or files nobody
//! describes.
//!
//! A report directory has a *journal* (`manifest.json` for `verify`), a JSON
//! [`Manifest`]: the run id, whether the run completed, the files it wrote and the files
//! of earlier runs not yet removed. Its *entry points* (`summary.json`, `index.html`) are
//! what a reader opens first. [`ReportRun`] keeps them consistent, and an earlier report
//! untouched until the new run has succeeded (issue #25):
//!
//! 1. [`ReportRun::begin`] refuses a directory that holds another command's output or
//!    data ([`refuse_occupied`]: nothing the user gave is ever replaced or removed),
//!    reads the earlier journal and opens a staging directory ([`super::staging`]).
//!    Nothing in the directory changes while the run goes on.
//! 2. [`ReportRun::write`] (and the CSV, JSON and SVG forms, and [`ReportRun::staged`]
//!    for files streamed by the caller) lists a file and writes it, atomically
//!    ([`write_atomic`]), into the staging directory. A run that is refused or fails at
//!    any point before it finishes is dropped with its staging directory: the earlier
//!    report is exactly as it was.
//! 3. [`ReportRun::finish`] first refuses, touching nothing, if a staged file would
//!    replace an entry below the directory that the earlier journal does not list (a
//!    user's file in a sub-directory; [`refuse_taken`]). Then it swaps: it removes the
//!    earlier entry points, replaces the
//!    journal by one naming the new run as incomplete with its files and every file the
//!    earlier journal listed (`superseded`), moves the staged files into place, removes
//!    the superseded files this run did not write (dropped scenes: only files named in
//!    our own journal, only below the directory, never directories that are not empty),
//!    completes the journal and writes the entry points last, each atomically. An entry
//!    point on disk therefore always carries the run id of the journal beside it, and a
//!    run killed during the swap leaves an incomplete journal naming every file, which the
//!    next run removes or replaces.
//!
//! A directory shared by runs of several kinds (the studies' `reports/convergence/`) has
//! one journal per output set (e.g. `<stem>.manifest.json`). A run's entry points are
//! then its own summary and the directory's shared index: the swap removes both,
//! [`ReportRun::complete`] writes the summary *before* marking the journal complete (a
//! complete journal always has its summary), and the caller rebuilds the index from
//! every complete journal afterwards. Runs sharing a directory write disjoint file names
//! (the shared index apart): a rerun removes the files its own earlier journal named, and
//! never reads another journal.
//!
//! A journal also records what produced the run, its [`Provenance`] (tool version and
//! commit, command line, start and wall time, threads, the scenes as run: see
//! [`super::provenance`]), set by [`ReportRun::set_provenance`] and completed with the
//! wall time when the run finishes, and the schema of every CSV file the run wrote: its
//! columns with their units and meanings ([`Manifest::columns`], from the column
//! dictionary [`super::columns`]).
//!
//! The temporary files and staging directories of killed writers are removed by the next
//! run ([`super::remove_stale_temporaries`]). Files the journal never named (e.g. the
//! `convergence/` folder of other commands) are left alone.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::hash::{BuildHasher, Hasher};
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;
use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use super::columns::{TableSchema, table_schema};
use super::figure::Figure;
use super::io::{csv_text, json_text, write_atomic};
use super::provenance::{Provenance, ProvenanceRef};
use super::staging::Staging;
use crate::error::{Error, Result};

/// The journal of a report run (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The run that owns the report ([`new_run_id`]).
    pub run_id: String,
    /// The command that wrote it, e.g. `verify`.
    pub command: String,
    /// Whether the run finished (entry points written). `false`: the run is going on, or
    /// was interrupted; the directory then holds no entry point of it.
    pub complete: bool,
    /// Files of this run, relative to the report directory with `/` separators, sorted.
    /// While the run goes on, a file may be listed before it exists (write-ahead).
    pub files: Vec<String>,
    /// Files of earlier runs that this run has not yet rewritten or removed; empty once
    /// the run is complete.
    #[serde(default)]
    pub superseded: Vec<String>,
    /// What produced the run (absent in journals of runs that did not record it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
    /// Per CSV file of the run (relative path as in `files`): its columns with their
    /// units and meanings, from the header line and the column dictionary
    /// ([`super::columns`]).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub columns: BTreeMap<String, TableSchema>,
}

/// A unique id for a run: UTC start time, process id and 32 random bits, e.g.
/// `20250101T120000Z-4242-1a2b3c4d`. No two runs share one (different processes differ in
/// pid or start time, and the random part separates runs within one process).
pub fn new_run_id() -> String {
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(now.as_nanos());
    h.write_u32(std::process::id());
    let secs = now.as_secs();
    let (y, m, d) = civil_from_days(secs / 86_400);
    let t = secs % 86_400;
    format!(
        "{y:04}{m:02}{d:02}T{:02}{:02}{:02}Z-{}-{:08x}",
        t / 3600,
        t / 60 % 60,
        t % 60,
        std::process::id(),
        h.finish() & 0xffff_ffff
    )
}

/// The proleptic Gregorian date (year, month, day) of `days` days after 1970-01-01
/// (H. Hinnant's `civil_from_days`).
fn civil_from_days(days: u64) -> (u64, u64, u64) {
    let z = days + 719_468;
    let era = z / 146_097;
    let doe = z % 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + u64::from(m <= 2), m, d)
}

/// The journal at `path`, if it exists and reads as a [`Manifest`]; `None` otherwise (a
/// missing, unreadable or foreign file is never attributed to a run).
pub fn read_manifest(path: &Path) -> Option<Manifest> {
    fs::read(path)
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
}

/// `rel` if it is a plain relative path below the directory (no root, no `..`, no `.`,
/// not empty); `None` otherwise. Journal entries that fail this are never touched.
pub fn safe_relative(rel: &str) -> Option<&Path> {
    let p = Path::new(rel);
    let plain = !rel.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)));
    plain.then_some(p)
}

/// A run writing one report directory (see the [module docs](self)).
#[derive(Debug)]
pub struct ReportRun {
    /// The report directory.
    dir: PathBuf,
    /// File name of the journal in `dir`.
    journal: String,
    /// File names of the entry points in `dir`, in the order [`Self::finish`] writes them.
    entry_points: Vec<String>,
    /// The journal of this run as [`Self::finish`] will write it: the files written so
    /// far (in staging) and the earlier run's files (`superseded`).
    state: Mutex<Manifest>,
    /// Where the files wait until the run finishes.
    staging: Staging,
}

impl ReportRun {
    /// Starts run `command` in `dir` (created if missing), with its journal `journal` and
    /// entry points `entry_points` (file names in `dir`): checks that `dir` holds no
    /// other command's output ([`refuse_occupied`]), reads the earlier journal, if any,
    /// and opens the staging directory where the run's files wait
    /// ([`super::staging`]). Nothing of the earlier report is touched before
    /// [`Self::finish`] (or [`Self::complete`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `--out` if `dir` holds another command's output
    /// or data; [`Error::Io`] naming the directory that cannot be created.
    pub fn begin(dir: &Path, command: &str, journal: &str, entry_points: &[&str]) -> Result<Self> {
        let kind = OutputKind::Report {
            command,
            shared: journal != MANIFEST_FILE,
        };
        refuse_occupied(dir, kind)?;
        let earlier = read_manifest(&dir.join(journal));
        let superseded: BTreeSet<String> = earlier
            .map(|m| m.files.into_iter().chain(m.superseded).collect())
            .unwrap_or_default();
        let staging = Staging::new(dir)?;
        Ok(ReportRun {
            dir: dir.to_path_buf(),
            journal: journal.to_string(),
            entry_points: entry_points.iter().map(|s| (*s).to_string()).collect(),
            state: Mutex::new(Manifest {
                run_id: new_run_id(),
                command: command.to_string(),
                complete: false,
                files: Vec::new(),
                superseded: superseded
                    .into_iter()
                    .filter(|f| f != journal && safe_relative(f).is_some())
                    .collect(),
                provenance: None,
                columns: BTreeMap::new(),
            }),
            staging,
        })
    }

    /// The run id.
    pub fn run_id(&self) -> String {
        self.lock().run_id.clone()
    }

    /// Records what produced the run, for its journal (the wall time is added when the
    /// run finishes).
    ///
    /// # Errors
    /// None at present (the journal is written when the run finishes); kept fallible for
    /// callers that persist it.
    pub fn set_provenance(&self, provenance: Provenance) -> Result<()> {
        self.lock().provenance = Some(provenance);
        Ok(())
    }

    /// The reference to the run's provenance for an entry point (the journal's file name
    /// and the essentials), if [`Self::set_provenance`] was called.
    pub fn provenance_ref(&self) -> Option<ProvenanceRef> {
        self.lock()
            .provenance
            .as_ref()
            .map(|p| p.reference(&self.journal))
    }

    /// The journal's file name in the directory.
    pub fn journal(&self) -> &str {
        &self.journal
    }

    /// The report directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Every file of this run as the final journal will list it: the files written so
    /// far, the entry points and the journal, relative to the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let state = self.lock();
        let mut all: BTreeSet<String> = state.files.iter().cloned().collect();
        all.extend(self.entry_points.iter().cloned());
        all.insert(self.journal.clone());
        all.into_iter().collect()
    }

    /// Writes `bytes` as the file `path` (below the directory) of this run: atomically,
    /// into the staging directory, moved into place when the run finishes.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` if it is not below the directory or cannot be written.
    /// A CSV file's columns are recorded in the journal with their units
    /// ([`Manifest::columns`]).
    pub fn write(&self, path: &Path, bytes: &[u8]) -> Result<()> {
        let rel = self.record(path)?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        {
            let text = String::from_utf8_lossy(bytes);
            let header = text.lines().next().unwrap_or("");
            let schema = table_schema(&rel, header);
            self.lock().columns.insert(rel.clone(), schema);
        }
        write_atomic(&self.staging.path(&rel), bytes)
    }

    /// [`crate::output::write_csv`] through [`Self::write`].
    ///
    /// # Errors
    /// As [`crate::output::write_csv`] and [`Self::write`].
    pub fn write_csv(&self, path: &Path, header: &[&str], rows: &[Vec<f64>]) -> Result<()> {
        let text = csv_text(path, header, rows)?;
        self.write(path, text.as_bytes())
    }

    /// [`crate::output::write_json`] through [`Self::write`].
    ///
    /// # Errors
    /// As [`crate::output::write_json`] and [`Self::write`].
    pub fn write_json<T: Serialize>(&self, path: &Path, value: &T) -> Result<()> {
        let text = json_text(path, value)?;
        self.write(path, text.as_bytes())
    }

    /// [`Figure::write_svg`] through [`Self::write`].
    ///
    /// # Errors
    /// As [`Figure::render_svg`] and [`Self::write`].
    pub fn write_svg(&self, path: &Path, figure: &Figure) -> Result<()> {
        let svg = figure.render_svg()?;
        self.write(path, svg.as_bytes())
    }

    /// Finishes the run: publishes its files, removes the superseded files it did not
    /// write, completes the journal, then writes `entries` — (entry point, content), in
    /// order — atomically. Every entry point given to [`Self::begin`] should be among
    /// `entries`.
    ///
    /// # Errors
    /// [`Error::Io`] naming a file that cannot be moved, removed or written; an entry that
    /// is not an entry point of the run ([`Error::Io`], nothing written).
    pub fn finish(self, entries: &[(&str, &[u8])]) -> Result<()> {
        self.close(&[], entries)
    }

    /// Completes the run in a directory shared with other runs, each with its own
    /// journal: publishes its files, removes the superseded files it did not write,
    /// writes `entries` — its own entry points, in order, atomically — and then marks the
    /// journal complete. So a complete journal always has its entries on disk. The entry
    /// points that describe the whole directory (an index of every complete journal
    /// there) are not among `entries`: the caller rebuilds them from the journals once
    /// this returns.
    ///
    /// # Errors
    /// As [`Self::finish`].
    pub fn complete(self, entries: &[(&str, &[u8])]) -> Result<()> {
        self.close(entries, &[])
    }

    /// The swap at the end of a run: removes the earlier entry points, writes the journal
    /// (incomplete, naming this run's files and the earlier ones), moves the staged files
    /// into place, removes the superseded files this run did not write, writes `before`,
    /// marks the journal complete and writes `after` (entry points, each atomically).
    fn close(mut self, before: &[(&str, &[u8])], after: &[(&str, &[u8])]) -> Result<()> {
        if let Some((name, _)) = before
            .iter()
            .chain(after)
            .find(|(n, _)| !self.entry_points.iter().any(|e| e == n))
        {
            let path = self.dir.join(name);
            return Err(Error::io(
                path,
                std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "not an entry point of this report run",
                ),
            ));
        }
        // Nothing the run does not own is replaced (issue #25): the top level was read by
        // `refuse_occupied`; below it a file of the user's, or of no journal of this
        // command, may stand where this run would write. Refused before anything moves.
        {
            let state = self.lock();
            let owned: BTreeSet<&str> = state.superseded.iter().map(String::as_str).collect();
            let files = state.files.iter().map(String::as_str);
            if let Some(rel) = self.staging.taken(files, |f| owned.contains(f)) {
                return Err(refuse_taken(&self.dir, &state.command, &rel));
            }
        }
        // Entry points first: an entry point on disk always names the run of the journal
        // beside it (killed in between, the earlier journal stays, without its entry
        // points: nothing describes a file wrongly).
        for name in &self.entry_points {
            let path = self.dir.join(name);
            if fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) {
                fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
            }
        }
        let files = self.files();
        let (written, stale) = {
            let mut state = self.lock();
            let written = state.files.clone();
            state.files = files.clone();
            let stale: Vec<String> = state
                .superseded
                .iter()
                .filter(|f| files.binary_search(f).is_err())
                .cloned()
                .collect();
            self.persist(&state)?;
            (written, stale)
        };
        self.staging.publish(written.iter().map(String::as_str))?;
        for rel in &stale {
            self.remove_superseded(rel)?;
        }
        for (name, bytes) in before {
            write_atomic(&self.dir.join(name), bytes)?;
        }
        {
            let mut state = self.lock();
            state.complete = true;
            state.columns.retain(|f, _| files.binary_search(f).is_ok());
            state.superseded.clear();
            if let Some(p) = &mut state.provenance {
                p.finish();
            }
            self.persist(&state)?;
        }
        for (name, bytes) in after {
            write_atomic(&self.dir.join(name), bytes)?;
        }
        Ok(())
    }

    /// Lists `path` (below the directory) among the run's files and returns its path
    /// relative to the directory.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` if it is not below the directory.
    pub fn record(&self, path: &Path) -> Result<String> {
        let rel = path
            .strip_prefix(&self.dir)
            .ok()
            .and_then(|r| r.to_str())
            .map(|r| r.replace('\\', "/"))
            .filter(|r| safe_relative(r).is_some())
            .ok_or_else(|| {
                Error::io(
                    path,
                    std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        format!(
                            "not a file below the report directory {}",
                            self.dir.display()
                        ),
                    ),
                )
            })?;
        let mut state = self.lock();
        if let Err(i) = state.files.binary_search(&rel) {
            state.files.insert(i, rel.clone());
        }
        Ok(rel)
    }

    /// Lists `path` (below the directory) among the run's files ([`Self::record`]) and
    /// returns where to write it while the run goes on (in the staging directory): for a
    /// file the caller streams itself (e.g. with [`crate::output::AtomicFile`]).
    ///
    /// # Errors
    /// As [`Self::record`].
    pub fn staged(&self, path: &Path) -> Result<PathBuf> {
        let rel = self.record(path)?;
        Ok(self.staging.path(&rel))
    }

    /// Removes the superseded file `rel` (a regular file, if present) and then its parent
    /// directories below the report directory that are left empty.
    fn remove_superseded(&self, rel: &str) -> Result<()> {
        let Some(rel) = safe_relative(rel) else {
            return Ok(());
        };
        let path = self.dir.join(rel);
        match fs::symlink_metadata(&path) {
            Ok(m) if m.is_file() => fs::remove_file(&path).map_err(|e| Error::io(&path, e))?,
            _ => return Ok(()),
        }
        let mut parent = rel.parent();
        while let Some(p) = parent.filter(|p| !p.as_os_str().is_empty()) {
            if fs::remove_dir(self.dir.join(p)).is_err() {
                break;
            }
            parent = p.parent();
        }
        Ok(())
    }

    /// Writes the journal `state` atomically.
    fn persist(&self, state: &Manifest) -> Result<()> {
        let path = self.dir.join(&self.journal);
        write_atomic(&path, json_text(&path, state)?.as_bytes())
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Manifest> {
        // A panic while holding the lock cannot leave the journal half-updated in memory
        // in a way that matters: the disk copy is always written whole.
        self.state
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// The journal of a directory that one command owns (`verify`, `check`, `run`,
/// `calibrate`); the studies' shared folder has one journal per output set,
/// `<stem>.manifest.json`.
pub const MANIFEST_FILE: &str = "manifest.json";
/// The manifest of a shard's directory (as [`crate::shard::SHARD_MANIFEST`]).
pub const SHARD_FILE: &str = "shard.json";
/// The sidecar of a trajectory data directory (as [`crate::data::SIDECAR`]).
pub const DATA_FILE: &str = "data.json";
/// The entry points a directory of one command may hold only beside its journal.
const ENTRY_FILES: [&str; 2] = ["summary.json", "index.html"];

/// What a command is about to write into an output directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind<'a> {
    /// A report run of `command`: the directory's own (`shared: false`, journal
    /// `manifest.json`), or one output set of the studies' shared folder (`shared: true`,
    /// journal `<stem>.manifest.json`).
    Report {
        /// The command.
        command: &'a str,
        /// Whether the directory is the studies' shared folder.
        shared: bool,
    },
    /// A shard of `command` (`shard.json` and its files).
    Shard {
        /// The command.
        command: &'a str,
    },
}

/// Refuses to write `kind` into `dir` if `dir` holds another command's output or data
/// that the write would replace or remove (issue #25: nothing the user gave is ever
/// deleted or overwritten). Only the top level of `dir` is read: its journals, a shard
/// manifest, a trajectory sidecar and entry points without a journal. Allowed: an empty
/// or missing directory, the same command's earlier output (which the run replaces, as
/// its journal says), another study's output set in the studies' shared folder, and any
/// sub-directory. Below the top level the run's own file names decide, when it finishes:
/// a file it would replace that its earlier journal does not list is refused then
/// ([`Staging::taken`], [`refuse_taken`]), before anything is moved.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--out`, the directory, what it holds (the file
/// and the command that wrote it) and what to do.
pub fn refuse_occupied(dir: &Path, kind: OutputKind<'_>) -> Result<()> {
    let (me, what) = match kind {
        OutputKind::Report { command, .. } => (command, "the output"),
        OutputKind::Shard { command } => (command, "a shard"),
    };
    let Some(held) = occupant(dir, kind) else {
        return Ok(());
    };
    Err(Error::invalid(
        "--out",
        dir.display(),
        format!(
            "a directory for {what} of `{me}` alone, but it holds {held}, which `{me}` would replace or remove; choose another output directory (or remove that one yourself if it is no longer needed)"
        ),
    ))
}

/// The refusal of a run of `command` whose file `rel` (relative to `dir`) would replace
/// what no earlier run of that command wrote there ([`Staging::taken`]): exit 2, naming
/// `--out`, the directory and the entry; nothing has been moved or removed.
pub(crate) fn refuse_taken(dir: &Path, command: &str, rel: &str) -> Error {
    Error::invalid(
        "--out",
        dir.display(),
        format!(
            "a directory `{command}` may write its files into, but it holds {rel}, which no earlier run of `{command}` wrote there and which this run would replace; nothing was written: choose another output directory (or move {rel} away yourself)"
        ),
    )
}

/// What of another command (or of nobody's) `dir` holds that `kind` must not touch, in
/// words naming the file; `None` if `kind` may write there.
fn occupant(dir: &Path, kind: OutputKind<'_>) -> Option<String> {
    let names: Vec<String> = fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    let has = |n: &str| names.iter().any(|x| x == n);
    let studies: Vec<&String> = names
        .iter()
        .filter(|n| n.len() > JOURNAL_SUFFIX.len() && n.ends_with(JOURNAL_SUFFIX))
        .collect();
    let command_of = |file: &str| -> Option<String> {
        let bytes = fs::read(dir.join(file)).ok()?;
        let v: serde_json::Value = serde_json::from_slice(&bytes).ok()?;
        v.get("command")?.as_str().map(str::to_string)
    };
    let journal = has(MANIFEST_FILE).then(|| command_of(MANIFEST_FILE));
    let describe = |file: &str, command: Option<String>| match command {
        Some(c) if c == "run" => {
            format!("trajectory data written by `run` ({file}, {DATA_FILE})")
        }
        Some(c) => format!("the output of `{c}` ({file})"),
        None => format!("{file}, which no langevin-fem run wrote"),
    };
    if has(SHARD_FILE) {
        let c = command_of(SHARD_FILE);
        return match (kind, &c) {
            (OutputKind::Shard { command }, Some(c)) if c == command => None,
            _ => Some(match c {
                Some(c) => format!("a shard of `{c}` ({SHARD_FILE})"),
                None => format!("{SHARD_FILE}, which no langevin-fem shard wrote"),
            }),
        };
    }
    match kind {
        OutputKind::Shard { .. } => {
            if let Some(c) = journal {
                return Some(describe(MANIFEST_FILE, c));
            }
            if let Some(s) = studies.first() {
                return Some(format!("the convergence studies' reports ({s})"));
            }
            has(DATA_FILE).then(|| format!("trajectory data ({DATA_FILE})"))
        }
        OutputKind::Report { command, shared } => {
            if shared {
                if let Some(c) = journal {
                    return Some(describe(MANIFEST_FILE, c));
                }
                if has(DATA_FILE) {
                    return Some(format!("trajectory data ({DATA_FILE})"));
                }
                return (studies.is_empty() && has("index.html"))
                    .then(|| "index.html, which no langevin-fem study wrote".to_string());
            }
            if let Some(s) = studies.first() {
                return Some(format!("the convergence studies' reports ({s})"));
            }
            match journal {
                Some(Some(c)) if c == command => None,
                Some(c) => Some(describe(MANIFEST_FILE, c)),
                None if has(DATA_FILE) => Some(format!(
                    "trajectory data ({DATA_FILE}) that no langevin-fem run described"
                )),
                None => ENTRY_FILES
                    .iter()
                    .find(|f| has(f))
                    .map(|f| format!("{f}, which no langevin-fem report run wrote")),
            }
        }
    }
}

/// How a study journal's file name ends (as [`crate::studies::output::JOURNAL_SUFFIX`]).
const JOURNAL_SUFFIX: &str = ".manifest.json";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(59), (1970, 3, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(19_723), (2024, 1, 1));
    }

    #[test]
    fn run_ids_differ_and_have_the_documented_shape() {
        let (a, b) = (new_run_id(), new_run_id());
        assert_ne!(a, b);
        let parts: Vec<&str> = a.split('-').collect();
        assert_eq!(parts.len(), 3, "{a}");
        assert_eq!(parts[0].len(), 16, "{a}");
        assert!(
            parts[0].ends_with('Z') && parts[0].as_bytes()[8] == b'T',
            "{a}"
        );
        assert_eq!(parts[1], std::process::id().to_string());
        assert_eq!(parts[2].len(), 8, "{a}");
    }

    /// Two output sets sharing a directory: `complete` writes the set's own entry point
    /// before marking its journal complete and leaves the shared index to the caller; a
    /// rerun removes both entry points first and then only its own dropped files.
    #[test]
    fn runs_sharing_a_directory_keep_each_others_files() {
        let dir = std::env::temp_dir().join(format!("lfem-shared-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let entries = ["s.json", "index.html"];
        let other = ReportRun::begin(&dir, "other", "o.manifest.json", &["o.json", "index.html"])
            .expect("begin");
        other.write(&dir.join("o.csv"), b"o").expect("write");
        other.complete(&[("o.json", b"{}")]).expect("complete");

        let run = ReportRun::begin(&dir, "s", "s.manifest.json", &entries).expect("begin");
        run.write(&dir.join("a.csv"), b"a").expect("write");
        run.write(&dir.join("b.svg"), b"b").expect("write");
        run.complete(&[("s.json", b"{}")]).expect("complete");
        let journal = read_manifest(&dir.join("s.manifest.json")).expect("journal");
        assert!(journal.complete);
        assert_eq!(
            journal.files,
            ["a.csv", "b.svg", "index.html", "s.json", "s.manifest.json"]
        );
        assert!(dir.join("s.json").exists() && !dir.join("index.html").exists());
        fs::write(dir.join("index.html"), b"index").unwrap(); // the caller's index

        let before = snapshot(&dir);
        let rerun = ReportRun::begin(&dir, "s", "s.manifest.json", &entries).expect("begin");
        rerun.write(&dir.join("a.csv"), b"a2").expect("write");
        assert_eq!(
            snapshot(&dir),
            before,
            "nothing changes while a run goes on"
        );
        let bad = rerun.complete(&[("a.csv", b"x")]);
        assert!(bad.is_err(), "only entry points are entries");
        assert_eq!(
            snapshot(&dir),
            before,
            "a failed run leaves the earlier report"
        );

        let rerun = ReportRun::begin(&dir, "s", "s.manifest.json", &entries).expect("begin");
        rerun.write(&dir.join("a.csv"), b"a3").expect("write");
        rerun.complete(&[("s.json", b"{}")]).expect("complete");
        assert!(!dir.join("b.svg").exists(), "dropped file removed");
        for kept in ["a.csv", "s.json", "o.csv", "o.json", "o.manifest.json"] {
            assert!(dir.join(kept).exists(), "{kept}");
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    /// Every file under `dir` (relative path, bytes), sorted.
    fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
        fn walk(root: &Path, d: &Path, out: &mut Vec<(String, Vec<u8>)>) {
            for e in fs::read_dir(d).unwrap().flatten() {
                let p = e.path();
                let staging = e
                    .file_name()
                    .to_string_lossy()
                    .starts_with(".langevin-fem-staging.");
                if staging {
                    continue;
                } else if p.is_dir() {
                    walk(root, &p, out);
                } else {
                    let rel = p.strip_prefix(root).unwrap().display().to_string();
                    out.push((rel, fs::read(&p).unwrap()));
                }
            }
        }
        let mut out = Vec::new();
        walk(dir, dir, &mut out);
        out.sort();
        out
    }

    /// A report run refuses a directory holding another command's output or data, or
    /// entry points no journal describes; it accepts its own earlier output, an empty
    /// directory and, in the studies' folder, the other studies' output sets. A refused
    /// or dropped run leaves the directory byte for byte as it was.
    #[test]
    fn occupied_directories_are_refused_and_left_as_they_were() {
        let root = std::env::temp_dir().join(format!("lfem-occupied-{}", std::process::id()));
        let _ = fs::remove_dir_all(&root);
        let data = root.join("data");
        let run = ReportRun::begin(&data, "run", MANIFEST_FILE, &[DATA_FILE]).expect("begin");
        run.write(&data.join("r/t.npy"), b"npy").expect("write");
        run.finish(&[(DATA_FILE, b"{}")]).expect("finish");
        let before = snapshot(&data);
        for command in ["check", "verify"] {
            let e = ReportRun::begin(&data, command, MANIFEST_FILE, &ENTRY_FILES).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            let text = e.to_string();
            assert!(text.contains("--out") && text.contains("`run`"), "{text}");
        }
        let shared = OutputKind::Report {
            command: "converge",
            shared: true,
        };
        assert!(refuse_occupied(&data, shared).is_err());
        let shard = OutputKind::Shard { command: "run" };
        assert!(refuse_occupied(&data, shard).is_err());
        assert_eq!(snapshot(&data), before);
        // The same command replaces its own output; a dropped run changes nothing.
        let again = ReportRun::begin(&data, "run", MANIFEST_FILE, &[DATA_FILE]).expect("begin");
        again.write(&data.join("r/t.npy"), b"other").expect("write");
        drop(again);
        assert_eq!(snapshot(&data), before);
        // Foreign data and stray entry points.
        let foreign = root.join("foreign");
        fs::create_dir_all(&foreign).unwrap();
        fs::write(foreign.join(DATA_FILE), b"{}").unwrap();
        assert!(ReportRun::begin(&foreign, "run", MANIFEST_FILE, &[DATA_FILE]).is_err());
        fs::remove_file(foreign.join(DATA_FILE)).unwrap();
        fs::write(foreign.join("index.html"), b"mine").unwrap();
        let e = ReportRun::begin(&foreign, "verify", MANIFEST_FILE, &ENTRY_FILES).unwrap_err();
        assert!(e.to_string().contains("index.html"), "{e}");
        fs::write(foreign.join(MANIFEST_FILE), b"not json").unwrap();
        let e = ReportRun::begin(&foreign, "verify", MANIFEST_FILE, &ENTRY_FILES).unwrap_err();
        assert!(e.to_string().contains("no langevin-fem run wrote"), "{e}");
        assert_eq!(fs::read(foreign.join("index.html")).unwrap(), b"mine");
        // An empty directory, and a study beside another study.
        let studies = root.join("studies");
        let a = ReportRun::begin(
            &studies,
            "stability",
            "a.manifest.json",
            &["a.json", "index.html"],
        )
        .expect("begin");
        a.complete(&[("a.json", b"{}")]).expect("complete");
        refuse_occupied(&studies, shared).expect("another study's folder");
        let kind = OutputKind::Report {
            command: "verify",
            shared: false,
        };
        assert!(refuse_occupied(&studies, kind).is_err());
        fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn only_plain_relative_paths_are_safe() {
        assert!(safe_relative("a/b.csv").is_some());
        for bad in ["", "/etc/passwd", "../x", "a/../../x", "./a"] {
            assert!(safe_relative(bad).is_none(), "{bad}");
        }
    }
}
