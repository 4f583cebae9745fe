//! Progress of a long command on stderr, weighted by work.
//!
//! A command that simulates knows its projected work before it starts
//! ([`crate::work`]: DOF-steps, proportional to CPU time) and the work of each run. It
//! opens a [`Progress`] over the total, starts each run with [`Progress::begin_run`]
//! (its label names the scene and the run) and reports work as trajectories finish
//! ([`Progress::advance`], callable from the worker threads). The position is therefore
//! proportional to time spent, not to trajectories counted, and the estimated time left
//! means something even when one run's trajectories cost a hundred times another's.
//!
//! Where it goes ([`ProgressMode`]): on a terminal a bar redrawn in place with the
//! elapsed time, the percentage, the ETA and the run; on a pipe or a file (CI, `| cat`)
//! plain lines such as
//!
//! ```text
//! progress: hinged-linear-2d/paper 43% (1.2e7 of 2.8e7 DOF-steps), elapsed 12 s, ETA 16 s
//! ```
//!
//! one at each change of group (a scene; a seed of `calibrate`) and in between at most one
//! per [`LINE_INTERVAL`] *and* per [`LINE_FRACTION`] of the work, whichever is rarer
//! ([`Throttle`]); or nothing (`--quiet`, or a run nested in a command that shows its own
//! progress). Progress never goes to stdout, which holds the results.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// The shortest time between two periodic plain lines.
pub const LINE_INTERVAL: Duration = Duration::from_secs(10);

/// The smallest fraction of the total work between two periodic plain lines.
pub const LINE_FRACTION: f64 = 0.1;

/// Where progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// Nothing.
    Hidden,
    /// A bar on stderr, redrawn in place (stderr is a terminal).
    Bar,
    /// Plain periodic lines on stderr (stderr is a pipe or a file).
    Lines,
}

impl ProgressMode {
    /// [`ProgressMode::Bar`] if stderr is a terminal, else [`ProgressMode::Lines`];
    /// [`ProgressMode::Hidden`] if not `show`.
    pub fn stderr(show: bool) -> Self {
        match (show, std::io::stderr().is_terminal()) {
            (false, _) => ProgressMode::Hidden,
            (true, true) => ProgressMode::Bar,
            (true, false) => ProgressMode::Lines,
        }
    }
}

/// What a command shows on stderr while it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProgressOptions {
    /// Where progress goes.
    pub mode: ProgressMode,
    /// Also print the wall time of every run as it ends (`--verbose`).
    pub run_times: bool,
}

impl ProgressOptions {
    /// No progress and no run times.
    pub const HIDDEN: ProgressOptions = ProgressOptions {
        mode: ProgressMode::Hidden,
        run_times: false,
    };

    /// Progress on stderr if `show` ([`ProgressMode::stderr`]), with run times if
    /// `run_times`.
    pub fn stderr(show: bool, run_times: bool) -> Self {
        ProgressOptions {
            mode: ProgressMode::stderr(show),
            run_times,
        }
    }
}

/// When the next periodic plain line is due: at most one per `interval` and per
/// `fraction` of the total work, whichever is rarer (both must have passed since the
/// last line). Time is given by the caller (time since the start), so that a test can
/// use a fake clock.
#[derive(Debug, Clone)]
pub struct Throttle {
    interval: Duration,
    fraction: f64,
    /// Time and work of the last line.
    last: (Duration, f64),
}

impl Throttle {
    /// A throttle whose first line is due once `interval` and `fraction` of the work have
    /// passed since the start.
    pub fn new(interval: Duration, fraction: f64) -> Self {
        Throttle {
            interval,
            fraction,
            last: (Duration::ZERO, 0.0),
        }
    }

    /// Whether a periodic line is due at `now` with `done` of `total` work done; if it
    /// is, it counts as printed.
    pub fn due(&mut self, now: Duration, done: f64, total: f64) -> bool {
        let (t0, d0) = self.last;
        let due = now.saturating_sub(t0) >= self.interval && done - d0 >= self.fraction * total;
        if due {
            self.mark(now, done);
        }
        due
    }

    /// Records a line printed at `now` with `done` work done (e.g. one printed at the
    /// start of a scene): the next periodic line is counted from it.
    pub fn mark(&mut self, now: Duration, done: f64) {
        self.last = (now, done);
    }
}

/// Seconds for a person: `12 s`, `3 min 05 s`, `2 h 03 min`.
pub fn fmt_seconds(seconds: f64) -> String {
    if !seconds.is_finite() || seconds < 0.0 {
        return "unknown".to_string();
    }
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// A plain progress line: `progress: LABEL P% (DONE of TOTAL UNIT), elapsed E, ETA R`,
/// the ETA extrapolated from the rate so far (`unknown` before any work is done).
pub fn progress_line(label: &str, done: f64, total: f64, unit: &str, elapsed: Duration) -> String {
    let fraction = if total > 0.0 {
        (done / total).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let secs = elapsed.as_secs_f64();
    let eta = if done > 0.0 && total > 0.0 {
        fmt_seconds(secs * (total - done).max(0.0) / done)
    } else {
        "unknown".to_string()
    };
    let work = |w: f64| {
        if w == 0.0 {
            "0".to_string()
        } else {
            format!("{w:.1e}")
        }
    };
    format!(
        "progress: {label} {:.0}% ({} of {} {unit}), elapsed {}, ETA {eta}",
        100.0 * fraction,
        work(done),
        work(total),
        fmt_seconds(secs)
    )
}

/// The mutable part of a [`Progress`].
#[derive(Debug)]
struct State {
    /// Work done so far.
    done: f64,
    /// Work done when the current run started, and its projected work.
    run_start: f64,
    run_work: f64,
    /// The group (scene) and label (scene/run) of the current run.
    group: String,
    label: String,
    /// When the current run started (for `run_times`).
    run_clock: Option<Instant>,
    throttle: Throttle,
}

/// The progress of one command over its projected work (see the [module docs](self)).
/// Shared by reference with the worker threads.
#[derive(Debug)]
pub struct Progress {
    opts: ProgressOptions,
    bar: ProgressBar,
    total: f64,
    unit: String,
    start: Instant,
    state: Mutex<State>,
}

impl Progress {
    /// Progress over `total` work in `unit` (e.g. `DOF-steps`).
    pub fn new(opts: ProgressOptions, total: f64, unit: &str) -> Self {
        let total = if total.is_finite() {
            total.max(0.0)
        } else {
            0.0
        };
        let bar = match opts.mode {
            ProgressMode::Bar => {
                let bar = ProgressBar::with_draw_target(
                    Some(total.round() as u64),
                    ProgressDrawTarget::stderr(),
                );
                if let Ok(style) = ProgressStyle::with_template(
                    "{spinner} [{elapsed_precise}] {bar:30} {percent:>3}%  ETA {eta:<4} {msg}",
                ) {
                    bar.set_style(style);
                }
                bar
            }
            ProgressMode::Hidden | ProgressMode::Lines => ProgressBar::hidden(),
        };
        Progress {
            opts,
            bar,
            total,
            unit: unit.to_string(),
            start: Instant::now(),
            state: Mutex::new(State {
                done: 0.0,
                run_start: 0.0,
                run_work: 0.0,
                group: String::new(),
                label: String::new(),
                run_clock: None,
                throttle: Throttle::new(LINE_INTERVAL, LINE_FRACTION),
            }),
        }
    }

    /// No progress.
    pub fn hidden() -> Self {
        Progress::new(ProgressOptions::HIDDEN, 0.0, "")
    }

    /// The state; a worker that panicked while holding it leaves it usable.
    fn state(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Ends the current run, if any: its projected work counts as done (a run's ticks
    /// need not add up to its projection exactly, e.g. a pilot that chose durations
    /// below the largest), and with `run_times` its wall time is printed.
    fn close_run(&self, s: &mut State) {
        s.done = s.done.max(s.run_start + s.run_work);
        if let Some(clock) = s.run_clock.take()
            && self.opts.run_times
        {
            self.println(&format!(
                "run {}: {:.1} s",
                s.label,
                clock.elapsed().as_secs_f64()
            ));
        }
    }

    /// Starts a run of `work` units labelled `label` (e.g. `hinged-linear-2d/paper`) in
    /// `group` (e.g. the scene), ending the previous run. On plain lines, a line is
    /// printed when the group changes (and a periodic one if due).
    pub fn begin_run(&self, group: &str, label: &str, work: f64) {
        let mut s = self.state();
        self.close_run(&mut s);
        s.run_start = s.done;
        s.run_work = if work.is_finite() { work.max(0.0) } else { 0.0 };
        s.label = label.to_string();
        s.run_clock = Some(Instant::now());
        self.bar.set_message(label.to_string());
        self.bar.set_position(s.done.round() as u64);
        let new_group = s.group != group;
        s.group = group.to_string();
        if self.opts.mode == ProgressMode::Lines {
            let now = self.start.elapsed();
            let done = s.done;
            if new_group {
                s.throttle.mark(now, done);
                eprintln!(
                    "{}",
                    progress_line(label, done, self.total, &self.unit, now)
                );
            } else if s.throttle.due(now, done, self.total) {
                eprintln!(
                    "{}",
                    progress_line(label, done, self.total, &self.unit, now)
                );
            }
        }
    }

    /// The projected work of the current run.
    pub fn run_work(&self) -> f64 {
        self.state().run_work
    }

    /// Adds `work` done in the current run (from any thread), never beyond the run's
    /// projected work; on plain lines, prints a periodic line if one is due.
    pub fn advance(&self, work: f64) {
        if self.opts.mode == ProgressMode::Hidden || work.is_nan() || work <= 0.0 {
            return;
        }
        let mut s = self.state();
        s.done = (s.done + work).min(s.run_start + s.run_work);
        self.bar.set_position(s.done.round() as u64);
        if self.opts.mode == ProgressMode::Lines {
            let now = self.start.elapsed();
            let done = s.done;
            if s.throttle.due(now, done, self.total) {
                eprintln!(
                    "{}",
                    progress_line(&s.label, done, self.total, &self.unit, now)
                );
            }
        }
    }

    /// Ends the last run and clears the bar.
    pub fn finish(&self) {
        let mut s = self.state();
        self.close_run(&mut s);
        self.bar.finish_and_clear();
    }

    /// Prints `text` on stderr (above the bar, which is redrawn after it).
    pub fn println(&self, text: &str) {
        if self.bar.is_hidden() {
            eprintln!("{text}");
        } else {
            self.bar.suspend(|| eprintln!("{text}"));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: fn(u64) -> Duration = Duration::from_secs;

    /// With a fake clock: no periodic line before both 10 s and 10 % of the work have
    /// passed since the last one, whichever is rarer; a line printed at a scene's start
    /// restarts both counts.
    #[test]
    fn throttle_waits_for_both_the_interval_and_the_fraction() {
        let mut t = Throttle::new(LINE_INTERVAL, LINE_FRACTION);
        let total = 1000.0;
        // Much work, little time: not due.
        assert!(!t.due(S(1), 500.0, total));
        assert!(!t.due(S(9), 900.0, total));
        // Time enough and work enough: due once, then counted from there.
        assert!(t.due(S(10), 900.0, total));
        assert!(!t.due(S(11), 1000.0, total));
        // Much time, little work (a slow run): not due until 10 % more is done.
        let mut t = Throttle::new(LINE_INTERVAL, LINE_FRACTION);
        assert!(!t.due(S(100), 99.0, total));
        assert!(t.due(S(100), 100.0, total));
        assert!(!t.due(S(300), 199.0, total));
        assert!(t.due(S(300), 200.0, total));
        // A line at a scene's start (mark) restarts the count.
        t.mark(S(305), 400.0);
        assert!(!t.due(S(310), 600.0, total));
        assert!(t.due(S(315), 500.0, total));
    }

    /// The plain line names the label, the percentage, the work and the times; the ETA
    /// is the remaining work at the rate so far, unknown before any work.
    #[test]
    fn progress_line_reads_as_documented() {
        let line = progress_line("hinged-linear-2d/paper", 1.2e7, 2.8e7, "DOF-steps", S(12));
        assert_eq!(
            line,
            "progress: hinged-linear-2d/paper 43% (1.2e7 of 2.8e7 DOF-steps), elapsed 12 s, ETA 16 s"
        );
        let line = progress_line("a/b", 0.0, 2.8e7, "DOF-steps", S(0));
        assert_eq!(
            line,
            "progress: a/b 0% (0 of 2.8e7 DOF-steps), elapsed 0 s, ETA unknown"
        );
        assert!(progress_line("a/b", 5.0, 0.0, "x", S(1)).contains(" 0% "));
    }

    #[test]
    fn seconds_read_as_seconds_minutes_or_hours() {
        assert_eq!(fmt_seconds(0.4), "0 s");
        assert_eq!(fmt_seconds(59.4), "59 s");
        assert_eq!(fmt_seconds(185.0), "3 min 05 s");
        assert_eq!(fmt_seconds(7380.0), "2 h 03 min");
        assert_eq!(fmt_seconds(f64::NAN), "unknown");
    }

    /// Work is capped at the current run's projection, and beginning the next run counts
    /// the previous one as done.
    #[test]
    fn work_stays_within_the_run_and_a_new_run_completes_the_last() {
        let p = Progress::new(
            ProgressOptions {
                mode: ProgressMode::Bar,
                run_times: false,
            },
            100.0,
            "steps",
        );
        p.begin_run("s", "s/a", 40.0);
        p.advance(25.0);
        p.advance(25.0);
        assert_eq!(p.state().done, 40.0);
        p.begin_run("s", "s/b", 60.0);
        p.advance(10.0);
        assert_eq!(p.state().done, 50.0);
        assert_eq!(p.run_work(), 60.0);
        p.finish();
        assert_eq!(p.state().done, 100.0);
    }
}
