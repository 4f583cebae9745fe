//! Report output: SVG figures, CSV tables, JSON documents and the HTML index.
//!
//! - [`io`]: atomic writers. [`write_atomic`] writes through a temporary file in the
//!   destination directory and a rename, so an interrupted run never leaves a truncated
//!   report file; [`write_csv`] writes numbers with full round-trip precision;
//!   [`write_json`] writes pretty-printed JSON (e.g. `summary.json`).
//! - [`figure`]: [`Figure`] and [`Series`], rendered to SVG with `plotters` (SVG backend
//!   only, no font files: text is emitted as SVG `<text>` and laid out by the viewer).
//!   Rendering is deterministic, tolerates non-finite data and empty figures, and draws
//!   error bars and horizontal reference lines.
//! - [`html`]: the static, self-contained `index.html` built from a
//!   [`Summary`](crate::verify::summary::Summary): overall verdict, one section per scene
//!   with notes, embedded figures, links to the CSV tables, and the table of checks.
//!
//! Everything a report contains is a deterministic function of the run's results, except
//! the wall-clock times.

pub mod convergence;
pub mod figure;
pub mod html;
pub mod io;

pub use convergence::write_convergence_index;
pub use figure::{Figure, Series, SeriesStyle};
pub use html::{render_index, write_index};
pub use io::{write_atomic, write_csv, write_json};
