//! Reports on top of everything: the HTML index of a verification run and the convergence
//! index page of the studies.
//!
//! - [`html`]: the static, self-contained `index.html` built from a
//!   [`Summary`](crate::verify::summary::Summary): overall verdict, one section per scene
//!   with notes, embedded figures, links to the CSV tables, and the table of checks.
//! - [`convergence`]: `reports/convergence/index.html`, built from the studies' JSON
//!   summaries.
//! - [`calibration`]: the `index.html` of `calibrate` (false alarms per scene, p-value
//!   uniformity per check kind), built from its
//!   [`CalibrationSummary`](crate::verify::calibrate::CalibrationSummary).
//!
//! Figures and files are written through the domain-free [`crate::output`] layer.
//! Everything a report contains is a deterministic function of the run's results, except
//! the run id, the wall-clock times and the provenance (start time, command line, thread
//! count).

pub mod calibration;
pub mod convergence;
pub mod html;

pub use calibration::write_calibration_report;
pub use convergence::write_convergence_index;
pub use html::{render_index, write_index, write_report};
