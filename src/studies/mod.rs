//! Parametric studies: how the numerics behave as a discretization parameter changes.
//! Unlike [`crate::verify`], a study has no single pass/fail verdict over a scene; it
//! measures orders, biases and costs and writes JSON summaries, CSV tables and figures
//! (the convergence report, [`crate::report::convergence`], is built from those).
//!
//! - [`converge`]: observed orders in h and Δt for linear scenes, and for compression
//!   scenes ([`converge::compression`]), against the exact discrete and continuum
//!   references.
//! - [`stability`]: the stability map, integrator × Δt·λ_max × element count, against the
//!   integrators' exact discrete-time stationary-variance formulas.
//! - [`work_precision`]: error in ⟨w²(L/2)⟩ against wall time, and the projected cost to a
//!   tolerance.
//! - [`fig2_schemes`]: the schemes of Fig. 2 (the paper's, Crank–Nicolson with explicit
//!   stretching, the Metropolis chain) over Δt: the bias of ⟨F⟩, the projected CPU time to
//!   the figure, and the autocorrelation times of F and of the buckled mode compared.
//! - [`coupled_dt`]: the order of a θ-scheme's time-step error of ⟨F⟩ from pairs of
//!   trajectories at a step and its half driven by the same Brownian path (`converge
//!   --coupled`), resolved where independent runs sit at their sampling floor.
//! - [`output`]: the shared study folder: one output set and journal per study
//!   ([`output::StudyReport`]), so that studies keep each other's files and a rerun
//!   replaces its own.

pub mod converge;
pub mod coupled_dt;
pub mod fig2_schemes;
pub mod output;
pub mod stability;
pub mod work_precision;
