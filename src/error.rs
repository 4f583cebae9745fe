//! The error type of the library. Every variant carries the context a user needs to fix
//! the problem: the parameter or file and key, the offending value and the allowed range,
//! or the step at which a run went unstable.
//!
//! # Exit codes
//! [`Error::exit_code`] sorts every error into one of two classes, and never the other
//! way round: **2, the user's input** ([`Error::InvalidParameter`], [`Error::Scene`],
//! [`Error::UnstableTimeStep`]; found before any simulation wherever it can be) and
//! **3, the run failed** ([`Error::Diverged`], [`Error::RunFailed`], [`Error::Numerical`],
//! [`Error::Io`]). A failure of the simulator or of an estimator after a run started is
//! never blamed on a key of the input: the runner turns it into [`Error::RunFailed`]
//! naming the run and the observable ([`Error::run_failed`]).

use std::path::PathBuf;

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Errors of langevin-fem.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A parameter (command-line flag or struct field) is outside its allowed range.
    #[error("{name} must be {allowed}, got {value}")]
    InvalidParameter {
        /// Name of the parameter or flag, e.g. `bending_rigidity` or `--x`.
        name: String,
        /// The value as given.
        value: String,
        /// The allowed range, e.g. `> 0` or `in [0, 1]`.
        allowed: String,
    },
    /// A scene file is invalid.
    #[error("{file}: key `{key}`: {message}")]
    Scene {
        /// The scene file.
        file: PathBuf,
        /// The offending key (dotted path), or `-` for a parse error.
        key: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A time step is above the stability limit of an explicit integrator, or above the
    /// step at which Crank–Nicolson's multiplier of the fastest mode rounds to −1.
    #[error(
        "time step dt = {dt:e} of the {integrator} integrator is not below {limit:e}, {bound}; \
         use a smaller dt or {suggestion}"
    )]
    UnstableTimeStep {
        /// Integrator name.
        integrator: String,
        /// Requested time step.
        dt: f64,
        /// The stability limit.
        limit: f64,
        /// What the limit is (e.g. `the stability limit 2/lambda_max of euler-maruyama`).
        bound: String,
        /// What to do instead (e.g. a stable integrator to use).
        suggestion: String,
    },
    /// The state became non-finite during a run.
    #[error("run became unstable at step {step} (t = {time:e}): {detail}")]
    Diverged {
        /// Step index at which the non-finite state was detected.
        step: u64,
        /// Simulation time at that step.
        time: f64,
        /// What was non-finite.
        detail: String,
    },
    /// A numerical routine failed (e.g. a factorization of a matrix that should be
    /// positive definite).
    #[error("numerical failure in {routine}: {detail}")]
    Numerical {
        /// The routine.
        routine: String,
        /// What went wrong.
        detail: String,
    },
    /// A run failed after it started: an estimator found no answer in the data (e.g. no
    /// self-consistent autocorrelation window), an estimate was not finite, or a matrix
    /// that should be positive definite could not be factorized. Not the user's input
    /// (exit 3); the detail may suggest what to change.
    #[error(
        "run failed: {run}: {observable}{}: {detail}",
        step.map_or(String::new(), |s| format!(" (at step {s})"))
    )]
    RunFailed {
        /// The run: scene file, run index and name, e.g. `a.toml: runs[0] (crank-nicolson)`.
        run: String,
        /// The observable or stage, e.g. `mode-variance check of mode 1`.
        observable: String,
        /// The step at which it failed, where known.
        step: Option<u64>,
        /// What went wrong, and any advice.
        detail: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// The most characters of a value a message repeats ([`shown_value`]).
pub const MAX_SHOWN_CHARS: usize = 120;

/// A value as a message shows it: a number written with more than 20 characters (as
/// Rust prints 1e300 in full) in exponent form, and any text longer than
/// [`MAX_SHOWN_CHARS`] cut there, saying how long it was — so that a refusal of a huge
/// input does not repeat it.
pub fn shown_value(text: &str) -> String {
    if text.len() > 20
        && let Ok(x) = text.parse::<f64>()
        && x.is_finite()
    {
        return format!("{x:e}");
    }
    shown_text(text, MAX_SHOWN_CHARS)
}

/// A number as a message shows it ([`shown_value`] of its shortest round-trip text).
pub fn shown_number(x: f64) -> String {
    shown_value(&x.to_string())
}

/// `text` cut to its first `max` characters, with "… (N characters in all)" if cut.
pub fn shown_text(text: &str, max: usize) -> String {
    let n = text.chars().count();
    if n <= max {
        return text.to_string();
    }
    let head: String = text.chars().take(max).collect();
    format!("{head}… ({n} characters in all)")
}

impl Error {
    /// Shorthand for [`Error::InvalidParameter`].
    pub fn invalid(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Error::InvalidParameter {
            name: name.into(),
            value: shown_value(&value.to_string()),
            allowed: allowed.into(),
        }
    }

    /// [`Error::Diverged`] at step `step` of a run with time step `dt` (time = step·dt).
    pub fn diverged(step: u64, dt: f64, detail: impl Into<String>) -> Self {
        Error::Diverged {
            step,
            time: step as f64 * dt,
            detail: detail.into(),
        }
    }

    /// `err`, raised by run `run` while computing `observable` after the run started, as
    /// a run failure (exit 3): [`Error::RunFailed`] naming the run and the observable.
    /// Input errors raised by an estimator on the run's data (too few samples, a constant
    /// series) become run failures too: the input had passed validation. A
    /// [`Error::RunFailed`] keeps its (more specific) observable and takes `run`;
    /// [`Error::Diverged`] (which names its step) and [`Error::Io`] are kept as they are.
    pub fn run_failed(run: impl Into<String>, observable: impl Into<String>, err: Error) -> Self {
        let run = run.into();
        match err {
            Error::Io { .. } | Error::Diverged { .. } => err,
            Error::RunFailed {
                observable,
                step,
                detail,
                ..
            } => Error::RunFailed {
                run,
                observable,
                step,
                detail,
            },
            other => Error::RunFailed {
                run,
                observable: observable.into(),
                step: None,
                detail: other.to_string(),
            },
        }
    }

    /// `self` with `advice` appended to the detail of a [`Error::RunFailed`] (other
    /// errors are returned unchanged).
    #[must_use]
    pub fn with_advice(mut self, advice: &str) -> Self {
        if let Error::RunFailed { detail, .. } = &mut self {
            *detail = format!("{detail}; {advice}");
        }
        self
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// Process exit code for this error: 2 for bad input (parameters, scene files,
    /// a time step above the stability limit), 3 for failures during a run (see the
    /// [module docs](self)).
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::InvalidParameter { .. }
            | Error::Scene { .. }
            | Error::UnstableTimeStep { .. } => 2,
            Error::Diverged { .. }
            | Error::RunFailed { .. }
            | Error::Numerical { .. }
            | Error::Io { .. } => 3,
        }
    }
}

/// Checks that `value` is finite and strictly positive.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn require_positive(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(name, value, "finite and > 0"))
    }
}

/// Checks that `value` is finite and lies in the closed interval `[lo, hi]`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn require_in_range(name: &str, value: f64, lo: f64, hi: f64) -> Result<()> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(Error::invalid(name, value, format!("in [{lo}, {hi}]")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refusal does not repeat a huge input: 1e300 as Rust prints it in full comes out
    /// in exponent form, a long text is cut with its length; short values are untouched.
    #[test]
    fn refusals_show_huge_values_briefly() {
        let e = Error::invalid("width", 1e300, "in [1e-30, 1e30]");
        assert!(e.to_string().ends_with("got 1e300"), "{e}");
        let e = Error::invalid("width", 0.25, "in [1e-30, 1e30]");
        assert!(e.to_string().ends_with("got 0.25"), "{e}");
        let long = "x".repeat(1000);
        let e = Error::invalid("name", &long, "short");
        let m = e.to_string();
        assert!(
            m.len() < 300 && m.contains("(1000 characters in all)"),
            "{m}"
        );
        assert_eq!(shown_number(1e308), "1e308");
        assert_eq!(shown_text("abc", 3), "abc");
        assert_eq!(shown_text("abcd", 3), "abc… (4 characters in all)");
    }
}
