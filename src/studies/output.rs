//! The study folder (`reports/convergence/` by default): several studies write into one
//! directory, each invocation kind with its own output set and journal, so that a second
//! study keeps the first one's files while a rerun of a study replaces its own.
//!
//! An output set is named by a *stem*: `<scene>-<run>-<over>` for `converge`,
//! `stability` and `work-precision`. It holds
//!
//! - the journal `<stem>.manifest.json` ([`crate::output::manifest`]: run id, complete,
//!   files, the [`Provenance`] of the study — version, commit, command line, start and
//!   wall time, threads, the scene as run with its hash, seed and parameters with units
//!   — and the columns of every CSV file with their units; [`journal_name`]),
//! - the entry point `<stem>.json`, the study's summary with its run id and a
//!   `provenance` reference to the journal with version, commit and seed in clear
//!   ([`summary_name`]), written after every other file of the set and before the
//!   journal is marked complete,
//! - the study's tables and figures (`<stem>.csv`, `<stem>.svg`, `stability-map-*.svg`,
//!   ...), file names no other output set uses,
//!
//! and shares the folder's entry point [`INDEX`], removed when a study starts writing
//! and rebuilt from the complete journals when it has finished
//! ([`crate::report::write_convergence_index`]). A study starts writing only after its
//! simulations: a run killed while simulating leaves the earlier report as it was; one
//! killed while writing leaves an incomplete journal, no index, and files that its next
//! run replaces or removes. The temporary files of killed writers are removed by the next
//! command that writes into the folder ([`crate::output::remove_stale_temporaries`]).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::Result;
use crate::output::io::json_text;
use crate::output::{Figure, Provenance, ProvenanceRef, ReportRun};

/// The folder's index page, an entry point shared by every study there.
pub const INDEX: &str = "index.html";

/// How a study journal's file name ends.
pub const JOURNAL_SUFFIX: &str = ".manifest.json";

/// The commands that write study output sets (the `command` of their journals).
pub const STUDY_COMMANDS: [&str; 3] = ["converge", "stability", "work-precision"];

/// The journal of the output set `stem`: `<stem>.manifest.json`.
pub fn journal_name(stem: &str) -> String {
    format!("{stem}{JOURNAL_SUFFIX}")
}

/// The summary (entry point) of the output set `stem`: `<stem>.json`.
pub fn summary_name(stem: &str) -> String {
    format!("{stem}.json")
}

/// The stem of a journal file name (`None` if `name` is not one).
pub fn stem_of_journal(name: &str) -> Option<&str> {
    name.strip_suffix(JOURNAL_SUFFIX).filter(|s| !s.is_empty())
}

/// A study's summary with the reference to its provenance appended (its own keys first,
/// in their order).
#[derive(Serialize)]
struct WithProvenance<'a, T> {
    #[serde(flatten)]
    summary: &'a T,
    #[serde(skip_serializing_if = "Option::is_none")]
    provenance: Option<ProvenanceRef>,
}

/// A study writing its output set into the folder (see the [module docs](self)).
#[derive(Debug)]
pub struct StudyReport {
    run: ReportRun,
    stem: String,
}

impl StudyReport {
    /// Starts writing the output set `stem` of `command` in `dir` (created if missing):
    /// the journal names the new run as incomplete and records `provenance` (begun when
    /// the study started: [`Provenance::begin`]), then the set's summary and the folder's
    /// index are removed.
    ///
    /// # Errors
    /// As [`ReportRun::begin`].
    pub fn begin(dir: &Path, command: &str, stem: &str, provenance: Provenance) -> Result<Self> {
        let summary = summary_name(stem);
        let run = ReportRun::begin(dir, command, &journal_name(stem), &[&summary, INDEX])?;
        run.set_provenance(provenance)?;
        Ok(StudyReport {
            run,
            stem: stem.to_string(),
        })
    }

    /// The run id.
    pub fn run_id(&self) -> String {
        self.run.run_id()
    }

    /// The path of the file `name` of the folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.run.dir().join(name)
    }

    /// Writes `bytes` as `name` in the folder ([`ReportRun::write`]).
    ///
    /// # Errors
    /// As [`ReportRun::write`].
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<()> {
        self.run.write(&self.path(name), bytes)
    }

    /// Renders `figure` as `name` in the folder ([`ReportRun::write_svg`]).
    ///
    /// # Errors
    /// As [`ReportRun::write_svg`].
    pub fn write_svg(&self, name: &str, figure: &Figure) -> Result<()> {
        self.run.write_svg(&self.path(name), figure)
    }

    /// The files of the output set as its summary lists them: those written so far and
    /// the summary, sorted (not the journal, not the shared index).
    pub fn files(&self) -> Vec<String> {
        let journal = journal_name(&self.stem);
        self.run
            .files()
            .into_iter()
            .filter(|f| *f != journal && f != INDEX)
            .collect()
    }

    /// Writes `summary` as the set's entry point `<stem>.json`, after removing the files
    /// of the earlier run that this one did not write, and marks the journal complete
    /// ([`ReportRun::complete`]). The caller then rebuilds the index. The summary (a
    /// struct or map) gains the key `provenance`, last: the journal's file name with
    /// version, commit, command line and seeds in clear ([`ProvenanceRef`]).
    ///
    /// # Errors
    /// As [`ReportRun::complete`].
    pub fn complete<T: Serialize>(self, summary: &T) -> Result<()> {
        let name = summary_name(&self.stem);
        let path = self.path(&name);
        let value = WithProvenance {
            summary,
            provenance: self.run.provenance_ref(),
        };
        let text = json_text(&path, &value)?;
        self.run.complete(&[(&name, text.as_bytes())])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_of_an_output_set() {
        assert_eq!(journal_name("a-b-dt"), "a-b-dt.manifest.json".to_string());
        assert_eq!(summary_name("stability"), "stability.json");
        assert_eq!(
            stem_of_journal("work-precision.manifest.json"),
            Some("work-precision")
        );
        assert_eq!(stem_of_journal("manifest.json"), None);
        assert_eq!(stem_of_journal(".manifest.json"), None);
        assert_eq!(stem_of_journal("stability.json"), None);
    }
}
