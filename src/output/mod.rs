//! Domain-free output: SVG figures, atomic file writers, journals with provenance and the
//! column dictionary. Nothing here depends on filaments, scenes or checks (a scene
//! describes itself to the provenance through [`DescribeScene`]); every layer above
//! writes its files through this one.
//!
//! - [`io`]: atomic writers. [`write_atomic`] writes through a temporary file in the
//!   destination directory and a rename, so an interrupted run never leaves a truncated
//!   file; [`write_csv`] writes numbers with full round-trip precision; [`write_json`]
//!   writes pretty-printed JSON (e.g. `summary.json`).
//! - [`manifest`]: [`ReportRun`], a run id and a journal (`manifest.json`) of every file
//!   a run writes, which keep a report directory consistent when a run is killed or a
//!   rerun writes fewer files (old entry points removed first, dropped files removed,
//!   entry points written last); several journals may share one directory, one per
//!   output set (the studies' convergence folder).
//! - [`lock`]: [`OutputLock`], one running command per output directory (an advisory
//!   lock on the directory, released when the process ends).
//! - [`staging`]: [`Staging`], where a run's files wait, hidden inside the output
//!   directory, until the run has succeeded; a refusal or failure drops them and leaves
//!   the directory as it was.
//! - [`provenance`]: [`Provenance`], what produced an output (version and commit baked
//!   in at build time, command line, start and wall time, threads, every scene as run
//!   with its hash, seed and parameters with units), carried by every journal and
//!   referenced from every entry point ([`ProvenanceRef`]).
//! - [`columns`]: the column dictionary, the unit and meaning of every column of every
//!   CSV table the commands write; the journal records each CSV file's schema from it.
//! - [`figure`]: [`Figure`] and [`Series`], rendered to SVG with `plotters` (SVG backend
//!   only, no font files: text is emitted as SVG `<text>` and laid out by the viewer).
//!   Rendering is deterministic, tolerates non-finite data and empty figures, and draws
//!   error bars and horizontal reference lines.

pub mod columns;
pub mod figure;
pub mod io;
pub mod lock;
pub mod manifest;
pub mod provenance;
pub mod staging;

pub use figure::{AxisUnits, Figure, Series, SeriesColor, SeriesStyle};
pub use io::{AtomicFile, remove_stale_temporaries, write_atomic, write_csv, write_json};
pub use lock::OutputLock;
pub use manifest::{Manifest, ReportRun, new_run_id, read_manifest};
pub use provenance::{DescribeScene, Provenance, ProvenanceRef, SceneProvenance};
pub use staging::Staging;
