//! The terminal as a user and a CI log see it (issue #14): what goes to stdout and to
//! stderr, the closing totals line, `--quiet` and `--verbose`, the progress lines under a
//! pipe, warnings only for the user's own scenes, and the command line's consistency
//! (choices as enums, examples in `--help`, completions, the old flag spellings kept).
//!
//! Set-up: the binary is run with stdout and stderr captured as pipes (as under CI or
//! `| cat`), so its progress is in plain-line mode. The scenes are the quickest built-in
//! ones (compression-2d, hinged-linear-3d: a few seconds each at the quick budget).
//! Nothing here is statistical: every assertion is about text and exit codes.

mod common;

use common::{TempDir, describe, run, stderr_of, stdout_of};

/// Whether `line` reads `N passed, N failed, N skipped in T s` (T with one decimal).
fn is_totals_line(line: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let words: Vec<&str> = line.split(' ').collect();
    let [p, "passed,", f, "failed,", s, "skipped", "in", t, "s"] = words[..] else {
        return false;
    };
    let time_ok = t
        .split_once('.')
        .is_some_and(|(i, d)| digits(i) && d.len() == 1 && digits(d));
    digits(p) && digits(f) && digits(s) && time_ok
}

#[test]
fn totals_line_pattern_is_strict() {
    assert!(is_totals_line("51 passed, 0 failed, 0 skipped in 1.7 s"));
    for bad in [
        "51 passed, 0 failed, 0 skipped in 1.75 s",
        "51 passed, 0 failed, 0 skipped in 2 s",
        "51 passed, 0 failed in 1.7 s",
        "x passed, 0 failed, 0 skipped in 1.7 s",
        "51 passed, 0 failed, 0 skipped in 1.7 s ",
    ] {
        assert!(!is_totals_line(bad), "{bad}");
    }
}

/// `verify` under a pipe: stderr has a plain progress line naming the scene and a run
/// (`progress: compression-2d/<run> …`); stdout has the per-scene line and ends with the
/// totals line; exit code 0.
#[test]
fn verify_under_a_pipe_prints_progress_lines_and_ends_with_the_totals() {
    let dir = TempDir::new("term-verify");
    let args = [
        "verify",
        "--scene",
        "compression-2d",
        "--out",
        &dir.join_str("r"),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    let runs = common::scene("verification/compression-2d.toml").runs;
    assert!(
        err.lines()
            .any(|l| l.starts_with("progress: compression-2d/")
                && runs
                    .iter()
                    .any(|r| l.contains(&format!("compression-2d/{} ", r.name)))
                && l.contains("DOF-steps")
                && l.contains("ETA")),
        "no progress line naming the scene and a run: {err}"
    );
    let out = stdout_of(&o);
    assert!(!out.contains("progress:"), "progress on stdout: {out}");
    assert!(out.starts_with("compression-2d "), "{out}");
    let last = out.lines().last().unwrap_or("");
    assert!(is_totals_line(last), "last line of stdout: {last:?}\n{out}");
    assert!(last.starts_with("53 passed, 0 failed, 0 skipped"), "{last}");
}

/// `-q`: no progress, no per-scene line: stdout is the totals line alone when every
/// check passes; exit code 0. `--quiet` after the subcommand works the same.
#[test]
fn quiet_prints_the_totals_line_only() {
    let dir = TempDir::new("term-quiet");
    for quiet in [
        vec!["-q", "verify", "--scene", "compression-2d"],
        vec!["verify", "--quiet", "--scene", "compression-2d"],
    ] {
        let out_dir = dir.join_str("r");
        let mut args = quiet.clone();
        args.extend(["--out", &out_dir]);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        assert!(!err.contains("progress:"), "progress despite -q: {err}");
        let out = stdout_of(&o);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines.len(), 1, "{out}");
        assert!(is_totals_line(lines[0]), "{out}");
    }
}

/// Bad input keeps its exit code (2) and prints nothing on stdout, quiet or not.
#[test]
fn bad_input_exits_2_with_nothing_on_stdout() {
    for args in [
        vec!["verify", "--scene", "no-such-scene"],
        vec!["-q", "verify", "--scene", "no-such-scene"],
        vec![
            "theory",
            "compression",
            "--dims",
            "4",
            "--strain-ratio",
            "1",
        ],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        assert!(o.stdout.is_empty(), "{}", describe(&args, &o));
    }
}

/// `theory compression --dims` is a choice of 2 or 3: 4 exits 2 naming the flag and the
/// possible values.
#[test]
fn theory_dims_accepts_2_or_3_only() {
    let args = [
        "theory",
        "compression",
        "--dims",
        "4",
        "--strain-ratio",
        "1",
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(err.contains("--dims") && err.contains("2, 3"), "{err}");
    let args = [
        "theory",
        "compression",
        "--dims",
        "3",
        "--strain-ratio",
        "1",
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
}

/// Every command's `--help` has an examples section; `--tolerance` shows its default as
/// `1e-12`; the global `-q`/`-v` and the short flags are listed.
#[test]
fn help_has_examples_short_flags_and_readable_defaults() {
    let commands: &[&[&str]] = &[
        &[],
        &["verify"],
        &["check"],
        &["calibrate"],
        &["converge"],
        &["stability"],
        &["work-precision"],
        &["run"],
        &["list"],
        &["scene"],
        &["theory"],
        &["completions"],
    ];
    for c in commands {
        let mut args = c.to_vec();
        args.push("--help");
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let help = stdout_of(&o);
        assert!(help.contains("Examples:"), "{args:?}: {help}");
        assert!(
            help.contains("-q, --quiet") && help.contains("-v, --verbose"),
            "{args:?}: {help}"
        );
    }
    let help = stdout_of(&run(&["verify", "--help"]));
    for flag in ["-s, --scene", "-o, --out", "-b, --budget", "-j, --threads"] {
        assert!(help.contains(flag), "verify --help lacks {flag}: {help}");
    }
    let help = stdout_of(&run(&["theory", "correlation", "--help"]));
    assert!(help.contains("[default: 1e-12]"), "{help}");
    let help = stdout_of(&run(&["theory", "compression", "--help"]));
    assert!(help.contains("--dims <DIMS>"), "{help}");
    assert!(
        help.contains("2") && help.contains("Three-dimensional"),
        "{help}"
    );
}

/// `completions bash|zsh|fish` prints a script naming the binary and its commands; an
/// unknown shell exits 2.
#[test]
fn completions_are_printed_for_bash_zsh_and_fish() {
    for shell in ["bash", "zsh", "fish"] {
        let args = ["completions", shell];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let out = stdout_of(&o);
        assert!(
            out.contains("langevin-fem") && out.contains("verify") && out.contains("calibrate"),
            "{shell}: {out}"
        );
    }
    let o = run(&["completions", "tcsh"]);
    assert_eq!(o.status.code(), Some(2));
}

/// `work-precision --duration-tau1` is the flag's name now (as in `converge` and `run`);
/// the old `--duration` and `--em-duration` still work as hidden aliases, and a bad
/// value names the new flag.
#[test]
fn old_duration_spellings_are_hidden_aliases() {
    let help = stdout_of(&run(&["work-precision", "--help"]));
    assert!(
        help.contains("--duration-tau1") && help.contains("--em-duration-tau1"),
        "{help}"
    );
    assert!(!help.contains("--duration <"), "{help}");
    for (flag, named) in [
        ("--duration", "--duration-tau1"),
        ("--duration-tau1", "--duration-tau1"),
        ("--em-duration", "--em-duration-tau1"),
    ] {
        let args = ["work-precision", flag, "0"];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        assert!(err.contains(named) && err.contains("got 0"), "{err}");
    }
}

/// The small-slope status of a built-in scene (hinged-linear-3d is floppy on purpose) is
/// a note in the report, not a warning on the terminal; the same scene given as a file
/// (a user's scene) warns on stderr. `-v` lists the run times and the seed.
#[test]
fn small_slope_warnings_only_for_the_users_scene_files() {
    let dir = TempDir::new("term-slope");
    let args = [
        "verify",
        "-v",
        "--scene",
        "hinged-linear-3d",
        "--out",
        &dir.join_str("builtin"),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(!err.contains("warning"), "{err}");
    assert!(
        err.contains("run hinged-linear-3d/crank-nicolson: "),
        "{err}"
    );
    assert!(stdout_of(&o).contains("    seed "), "{}", stdout_of(&o));
    let summary = std::fs::read_to_string(dir.join("builtin/summary.json")).expect("summary");
    let v: serde_json::Value = serde_json::from_str(&summary).expect("json");
    let scene = &v["scenes"][0];
    assert!(scene["warnings"].as_array().is_some_and(|w| w.is_empty()));
    let notes = scene["notes"].to_string();
    assert_eq!(notes.matches("small-slope status").count(), 1, "{notes}");

    let args = [
        "verify",
        "--scene",
        "verification/hinged-linear-3d.toml",
        "--out",
        &dir.join_str("file"),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(
        err.contains("warning: hinged-linear-3d: ") && err.contains("small-slope model"),
        "{err}"
    );
    assert!(!stdout_of(&o).contains("warning"), "{}", stdout_of(&o));
}
