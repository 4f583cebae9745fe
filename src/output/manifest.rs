//! Report runs: a run id and a manifest of every file a run writes, so that every file of
//! a report directory belongs to one run, and a run that is killed, or a rerun that writes
//! fewer files, never leaves an old entry point describing new files or files nobody
//! describes.
//!
//! A report directory has a *journal* (`manifest.json` for `verify`), a JSON
//! [`Manifest`]: the run id, whether the run completed, the files it wrote and the files
//! of earlier runs not yet removed. Its *entry points* (`summary.json`, `index.html`) are
//! what a reader opens first. [`ReportRun`] keeps them consistent:
//!
//! 1. [`ReportRun::begin`] removes the entry points, then replaces the journal,
//!    atomically, by one naming the new run as incomplete and carrying every file the
//!    earlier journal listed (`superseded`). An entry point on disk therefore always
//!    carries the run id of the journal beside it, no entry point describes a file of
//!    this run before it is complete, and no file of an earlier run is forgotten.
//! 2. [`ReportRun::write`] (and the CSV, JSON and SVG forms) lists a file in the journal
//!    *before* writing it (write-ahead), so a run killed at any moment leaves no file the
//!    journal does not name; every file is written atomically ([`write_atomic`]).
//! 3. [`ReportRun::finish`] removes the superseded files this run did not write (dropped
//!    scenes): only files named in our own journal, only below the directory, never
//!    directories that are not empty. Then it completes the journal and writes the entry
//!    points last, each atomically.
//!
//! A directory shared by runs of several kinds (the studies' `reports/convergence/`) has
//! one journal per output set (e.g. `<stem>.manifest.json`). A run's entry points are
//! then its own summary and the directory's shared index: [`ReportRun::begin`] removes
//! both, [`ReportRun::complete`] writes the summary *before* marking the journal complete
//! (a complete journal always has its summary), and the caller rebuilds the index from
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
//! The temporary files of killed writers are removed by the next run
//! ([`super::remove_stale_temporaries`]). Files the journal never named (e.g. the
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
    /// The journal as it is on disk, apart from files already recorded there under
    /// `superseded` and rewritten since.
    state: Mutex<Manifest>,
}

impl ReportRun {
    /// Starts run `command` in `dir` (created if missing), with its journal `journal` and
    /// entry points `entry_points` (file names in `dir`): reads the earlier journal, if
    /// any, removes the entry points and then writes the new journal (incomplete, the
    /// earlier files as `superseded`). An unreadable earlier journal is treated as absent
    /// (its files are then never removed: they cannot be attributed).
    ///
    /// # Errors
    /// [`Error::Io`] naming the directory, the journal or an entry point that cannot be
    /// created, written or removed.
    pub fn begin(dir: &Path, command: &str, journal: &str, entry_points: &[&str]) -> Result<Self> {
        fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let earlier = read_manifest(&dir.join(journal));
        let superseded: BTreeSet<String> = earlier
            .map(|m| m.files.into_iter().chain(m.superseded).collect())
            .unwrap_or_default();
        let run = ReportRun {
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
        };
        // Entry points first: an entry point on disk always names the run of the journal
        // beside it (killed in between, the earlier journal stays, without its entry
        // points: nothing describes a file wrongly).
        for name in &run.entry_points {
            let path = dir.join(name);
            if fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) {
                fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
            }
        }
        run.persist(&run.lock())?;
        Ok(run)
    }

    /// The run id.
    pub fn run_id(&self) -> String {
        self.lock().run_id.clone()
    }

    /// Records what produced the run in its journal (written at once; the wall time is
    /// added when the run finishes).
    ///
    /// # Errors
    /// [`Error::Io`] naming the journal if it cannot be written.
    pub fn set_provenance(&self, provenance: Provenance) -> Result<()> {
        let mut state = self.lock();
        state.provenance = Some(provenance);
        self.persist(&state)
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

    /// Writes `bytes` to `path` (below the directory) atomically, after listing it in the
    /// journal.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` if it is not below the directory or cannot be written,
    /// or naming the journal if that cannot be updated.
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
            self.lock().columns.insert(rel, schema);
        }
        write_atomic(path, bytes)
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

    /// Finishes the run: removes the superseded files it did not write, completes the
    /// journal, then writes `entries` — (entry point, content), in order — atomically.
    /// Every entry point given to [`Self::begin`] should be among `entries`.
    ///
    /// # Errors
    /// [`Error::Io`] naming a file that cannot be removed or written; an entry that is not
    /// an entry point of the run ([`Error::Io`], nothing written).
    pub fn finish(self, entries: &[(&str, &[u8])]) -> Result<()> {
        self.close(&[], entries)
    }

    /// Completes the run in a directory shared with other runs, each with its own
    /// journal: removes the superseded files it did not write, writes `entries` — its own
    /// entry points, in order, atomically — and then marks the journal complete. So a
    /// complete journal always has its entries on disk. The entry points that describe
    /// the whole directory (an index of every complete journal there) are not among
    /// `entries`: the caller rebuilds them from the journals once this returns.
    ///
    /// # Errors
    /// As [`Self::finish`].
    pub fn complete(self, entries: &[(&str, &[u8])]) -> Result<()> {
        self.close(entries, &[])
    }

    /// Removes the superseded files this run did not write, writes `before`, marks the
    /// journal complete and writes `after` (entry points, each atomically).
    fn close(self, before: &[(&str, &[u8])], after: &[(&str, &[u8])]) -> Result<()> {
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
        let files = self.files();
        let stale: Vec<String> = {
            let state = self.lock();
            state
                .superseded
                .iter()
                .filter(|f| files.binary_search(f).is_err())
                .cloned()
                .collect()
        };
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
            state.files = files;
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

    /// Lists `path` (below the directory) in the journal, on disk first if the journal
    /// does not yet name it, and returns its path relative to the directory: called
    /// before a file the caller streams itself (e.g. with [`crate::output::AtomicFile`])
    /// is created.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` if it is not below the directory, or the journal if
    /// that cannot be updated.
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
            let on_disk = state.superseded.binary_search(&rel).is_ok();
            state.files.insert(i, rel.clone());
            if !on_disk {
                self.persist(&state)?;
            }
        }
        Ok(rel)
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

        let rerun = ReportRun::begin(&dir, "s", "s.manifest.json", &entries).expect("begin");
        assert!(!dir.join("s.json").exists() && !dir.join("index.html").exists());
        rerun.write(&dir.join("a.csv"), b"a2").expect("write");
        let bad = rerun.complete(&[("a.csv", b"x")]);
        assert!(bad.is_err(), "only entry points are entries");
        assert_eq!(fs::read(dir.join("a.csv")).unwrap(), b"a2");

        let rerun = ReportRun::begin(&dir, "s", "s.manifest.json", &entries).expect("begin");
        rerun.write(&dir.join("a.csv"), b"a3").expect("write");
        rerun.complete(&[("s.json", b"{}")]).expect("complete");
        assert!(!dir.join("b.svg").exists(), "dropped file removed");
        for kept in ["a.csv", "s.json", "o.csv", "o.json", "o.manifest.json"] {
            assert!(dir.join(kept).exists(), "{kept}");
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn only_plain_relative_paths_are_safe() {
        assert!(safe_relative("a/b.csv").is_some());
        for bad in ["", "/etc/passwd", "../x", "a/../../x", "./a"] {
            assert!(safe_relative(bad).is_none(), "{bad}");
        }
    }
}
