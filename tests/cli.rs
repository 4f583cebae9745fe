//! Command-line and scene-file tests of the `langevin-fem` binary.
//!
//! Every test runs the built binary (`CARGO_BIN_EXE_langevin-fem`) the way a user does and
//! judges only what a user sees: the exit code (`src/error.rs`: 0 ok, 1 a verification
//! check failed, 2 bad input, 3 a run failed), stdout (`theory` prints one JSON object),
//! stderr (error messages must name the flag or the file and key, the value and the
//! allowed range, and must never be a panic), and the files `verify` writes.
//!
//! Fixtures:
//! - `tests/scenes/good/*.toml`: small valid scenes that run in well under a second.
//! - `tests/scenes/bad/*.toml`: invalid scenes. Each starts with comment lines
//!   `# expect: <substring>` (the first line must be one): substrings the error message
//!   must contain today. A file whose bug is in its message also has `# bug: <what>` and
//!   `# expect-after-fix: <substring>` lines; those are checked only by the ignored test
//!   [`bad_scenes_with_known_bugs_name_file_and_key`].
//!
//! Tests marked `#[ignore = "BUG: ..."]` document the expected behaviour that the binary
//! does not have yet; run them with `cargo test --test cli -- --ignored`.
//!
//! The whole file runs in a few seconds: every `verify` run uses the quick budget of a
//! 4-element scene.

mod common;

use common::{
    TempDir, assert_no_panic, command, describe, fixture, hinged_profile_variance, run, stderr_of,
    stdout_of, toml_files, write_scene,
};
use serde_json::Value;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The good fixture used by the determinism and seed tests.
const TINY: &str = "tests/scenes/good/tiny-linear.toml";

/// Relative tolerance for closed-form values: they are a handful of floating-point
/// operations away from the exact result, so 1e-12 leaves four orders of magnitude for
/// round-off while catching any wrong factor or exponent.
const REL: f64 = 1e-12;

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// The scene directory shipped with the crate; passed explicitly as `--scene-dir` so
/// that the tests do not depend on the working directory (see
/// [`verify_scene_path_works_outside_the_crate_root`]).
fn scene_dir() -> String {
    fixture("verification").display().to_string()
}

/// Runs `args` and asserts exit code 2, no panic, nothing on stdout, and every needle in
/// stderr.
fn assert_bad_input(args: &[&str], needles: &[&str]) {
    let o = run(args);
    assert_no_panic(args, &o);
    assert_eq!(o.status.code(), Some(2), "{}", describe(args, &o));
    assert!(
        o.stdout.is_empty(),
        "bad input printed a result: {}",
        describe(args, &o)
    );
    let err = stderr_of(&o);
    for n in needles {
        assert!(
            err.contains(n),
            "stderr lacks {n:?}: {}",
            describe(args, &o)
        );
    }
}

/// Runs `langevin-fem theory <args>`, asserts exit 0 and exactly one JSON object on
/// stdout, and returns it.
fn theory(args: &[&str]) -> serde_json::Map<String, Value> {
    let full: Vec<&str> = std::iter::once("theory")
        .chain(args.iter().copied())
        .collect();
    let o = run(&full);
    assert_no_panic(&full, &o);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&full, &o));
    let out = stdout_of(&o);
    let lines: Vec<&str> = out.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line: {}", describe(&full, &o));
    match serde_json::from_str::<Value>(lines[0]) {
        Ok(Value::Object(m)) => m,
        other => panic!("not a JSON object ({other:?}): {}", describe(&full, &o)),
    }
}

fn num(obj: &serde_json::Map<String, Value>, key: &str) -> f64 {
    obj.get(key)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("key {key:?} is not a number in {obj:?}"))
}

fn keys(obj: &serde_json::Map<String, Value>) -> Vec<&str> {
    let mut k: Vec<&str> = obj.keys().map(String::as_str).collect();
    k.sort_unstable();
    k
}

fn assert_rel(actual: f64, expected: f64, rel: f64, what: &str) {
    let err = (actual - expected).abs();
    assert!(
        err <= rel * expected.abs(),
        "{what}: got {actual:e}, expected {expected:e} (relative error {:e} > {rel:e})",
        err / expected.abs()
    );
}

/// Runs `verify --scene <scene> --out <out>` (quick budget, explicit scene dir) with
/// `threads` rayon threads (None: rayon's default); asserts exit 0 or 1 and no panic and
/// returns the parsed `summary.json`.
fn verify_scene(scene: &Path, out: &Path, threads: Option<usize>) -> Value {
    let (scene_s, out_s, dir_s) = (
        scene.display().to_string(),
        out.display().to_string(),
        scene_dir(),
    );
    let args = [
        "verify",
        "--scene",
        &scene_s,
        "--out",
        &out_s,
        "--scene-dir",
        &dir_s,
    ];
    let mut c = command();
    c.args(args);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t.to_string());
    }
    let o = c.output().expect("binary runs");
    assert_no_panic(&args, &o);
    let code = o.status.code();
    assert!(
        code == Some(0) || code == Some(1),
        "a valid scene must run to exit 0 (all checks pass) or 1 (a check failed): {}",
        describe(&args, &o)
    );
    let text = std::fs::read_to_string(out.join("summary.json"))
        .unwrap_or_else(|e| panic!("no summary.json ({e}): {}", describe(&args, &o)));
    let summary: Value = serde_json::from_str(&text).expect("summary.json is JSON");
    assert_eq!(
        summary["passed"].as_bool(),
        Some(code == Some(0)),
        "exit code and summary.passed disagree: {}",
        describe(&args, &o)
    );
    summary
}

/// `v` with every `wall_seconds`, `run_id` and `provenance` field removed (the only
/// non-deterministic fields: the provenance records how the run was made — start time,
/// command line, thread count — and is checked by `tests/provenance.rs`).
fn without_wall_seconds(v: &Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| !matches!(k.as_str(), "wall_seconds" | "run_id" | "provenance"))
                .map(|(k, v)| (k.clone(), without_wall_seconds(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(without_wall_seconds).collect()),
        other => other.clone(),
    }
}

/// Every file under `dir` with extension `ext`, by path relative to `dir`.
fn files_with_ext(dir: &Path, ext: &str) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, ext: &str, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).expect("readable output dir") {
            let p = entry.expect("dir entry").path();
            if p.is_dir() {
                walk(root, &p, ext, out);
            } else if p.extension().is_some_and(|e| e == ext) {
                let rel = p.strip_prefix(root).expect("under root").to_path_buf();
                out.insert(rel, std::fs::read(&p).expect("readable file"));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, ext, &mut out);
    out
}

/// Every check's estimate, by check name.
fn estimates(summary: &Value) -> BTreeMap<String, Value> {
    summary["scenes"]
        .as_array()
        .expect("scenes")
        .iter()
        .flat_map(|s| s["checks"].as_array().expect("checks").iter())
        .map(|c| {
            (
                c["name"].as_str().expect("name").to_string(),
                c["estimate"].clone(),
            )
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// 1. theory: exact values
// ---------------------------------------------------------------------------------------

/// What: `theory variance` prints one JSON object `{"x", "variance"}` with the closed
/// form kT·x²(L−x)²/(3·EI·L) — 1/48 at x = 1/2 with the defaults — also for
/// non-default L, EI, kT; the drag does not enter an equilibrium quantity.
/// Reference: the equipartition sum of eq. (4) at t = η → ∞ in closed form.
/// Tolerance: 1e-12 relative (closed form, see [`REL`]).
#[test]
fn theory_variance_matches_closed_form() {
    let v = theory(&["variance", "--x", "0.5"]);
    assert_eq!(keys(&v), ["variance", "x"]);
    assert_eq!(num(&v, "x"), 0.5);
    assert_rel(num(&v, "variance"), 1.0 / 48.0, REL, "variance at x = 1/2");

    let args = [
        "variance",
        "--length",
        "2",
        "--bending-rigidity",
        "3",
        "--kt",
        "0.5",
        "--x",
        "0.7",
    ];
    let v = theory(&args);
    assert_eq!(keys(&v), ["variance", "x"]);
    assert_eq!(num(&v, "x"), 0.7);
    assert_rel(
        num(&v, "variance"),
        hinged_profile_variance(0.7, 2.0, 3.0, 0.5),
        REL,
        "variance with L = 2, EI = 3, kT = 0.5 at x = 0.7",
    );

    // Hinged ends do not fluctuate, and the drag only sets time scales.
    assert_eq!(num(&theory(&["variance", "--x", "0"]), "variance"), 0.0);
    assert_eq!(num(&theory(&["variance", "--x", "1"]), "variance"), 0.0);
    let v = theory(&["variance", "--x", "0.5", "--drag", "7"]);
    assert_rel(num(&v, "variance"), 1.0 / 48.0, REL, "variance with drag 7");
}

/// What: `theory mode` prints `{"n", "rate", "variance"}` with λₙ = π⁴n⁴EI/(ξL⁴) and
/// σₙ² = 2kTL³/(π⁴n⁴EI): for n = 2 with the defaults, rate = 16π⁴ and variance
/// = 2/(16π⁴); and for n = 3 with L = 2, EI = 3, ξ = 5, kT = 1/2.
/// Reference: the modal solution of eq. (2) with hinged ends.
/// Tolerance: 1e-12 relative (closed form).
#[test]
fn theory_mode_rate_and_variance() {
    let m = theory(&["mode", "--n", "2"]);
    assert_eq!(keys(&m), ["n", "rate", "variance"]);
    assert_eq!(m["n"].as_u64(), Some(2));
    let pi4 = PI.powi(4);
    assert_rel(num(&m, "rate"), 16.0 * pi4, REL, "rate of mode 2");
    assert_rel(
        num(&m, "variance"),
        2.0 / (16.0 * pi4),
        REL,
        "variance of mode 2",
    );

    let args = [
        "mode",
        "--n",
        "3",
        "--length",
        "2",
        "--bending-rigidity",
        "3",
        "--drag",
        "5",
        "--kt",
        "0.5",
    ];
    let m = theory(&args);
    let (l, ei, xi, kt, n4) = (2.0_f64, 3.0, 5.0, 0.5, 81.0);
    assert_rel(
        num(&m, "rate"),
        pi4 * n4 * ei / (xi * l.powi(4)),
        REL,
        "rate of mode 3 with L = 2, EI = 3, xi = 5",
    );
    assert_rel(
        num(&m, "variance"),
        2.0 * kt * l.powi(3) / (pi4 * n4 * ei),
        REL,
        "variance of mode 3 with L = 2, EI = 3, kT = 1/2",
    );
}

/// What: `theory correlation` at t = η = 50 (≈ 4900 τ₁) equals the equilibrium variance
/// 1/48 within its own reported `truncation_error` (plus round-off), and that error is
/// ≥ 0 and within the requested tolerance 1e-12 × 2kTL³/(π⁴EI); from rest at t = 0 the
/// correlation is exactly 0 (w(x, 0) = 0).
/// Reference: eq. (4); at t = 50 the transient factor 1 − e^{−2λ₁t} is 1 in f64, so
/// the only error is the truncation of the mode sum.
/// Tolerance: the reported rigorous bound plus 1e-12 relative for round-off.
#[test]
fn theory_correlation_limits() {
    let c = theory(&[
        "correlation",
        "--x",
        "0.5",
        "--y",
        "0.5",
        "--t",
        "50",
        "--eta",
        "50",
    ]);
    assert_eq!(
        keys(&c),
        [
            "correlation",
            "eta",
            "modes",
            "t",
            "truncation_error",
            "x",
            "y"
        ]
    );
    let value = num(&c, "correlation");
    let bound = num(&c, "truncation_error");
    assert!(bound >= 0.0, "truncation_error {bound} < 0");
    let requested = 1e-12 * 2.0 / PI.powi(4);
    assert!(
        bound <= requested * (1.0 + 1e-9),
        "truncation_error {bound:e} above the requested 1e-12 x 2kTL^3/(pi^4 EI) = {requested:e}"
    );
    let err = (value - 1.0 / 48.0).abs();
    assert!(
        err <= bound + REL / 48.0,
        "correlation {value:e} differs from 1/48 by {err:e}, more than its bound {bound:e}"
    );
    assert!(c["modes"].as_u64().is_some_and(|n| n >= 1), "{c:?}");

    let c = theory(&[
        "correlation",
        "--x",
        "0.5",
        "--y",
        "0.5",
        "--t",
        "0",
        "--eta",
        "1",
    ]);
    assert_eq!(num(&c, "correlation"), 0.0, "from rest, w(x, 0) = 0: {c:?}");
    assert!(num(&c, "truncation_error") >= 0.0);
}

// ---------------------------------------------------------------------------------------
// 2. theory: bad input
// ---------------------------------------------------------------------------------------

/// What: out-of-range values exit 2 with a message naming the flag (as typed), the
/// allowed range and the value, without a panic and without printing a result.
/// Reference: `src/error.rs` (`InvalidParameter`: "{name} must be {allowed}, got
/// {value}") and the ranges in `src/cli/theory.rs`.
/// Tolerance: exact substrings.
#[test]
fn theory_rejects_out_of_range_values_with_exit_2() {
    let cases: &[(&[&str], &[&str])] = &[
        // `--flag=-1`: see `theory_negative_value_after_space_names_flag_and_range` for `--flag -1`.
        (
            &["theory", "variance", "--x", "0.5", "--bending-rigidity=-1"],
            &["--bending-rigidity must be finite and > 0, got -1"],
        ),
        (
            &["theory", "variance", "--x", "0.5", "--kt", "0"],
            &["--kt must be finite and > 0, got 0"],
        ),
        (
            &["theory", "variance", "--x", "0.5", "--drag", "0"],
            &["--drag must be finite and > 0, got 0"],
        ),
        (
            &["theory", "variance", "--x", "0.5", "--length", "inf"],
            &["--length must be finite and > 0, got inf"],
        ),
        (
            &["theory", "variance", "--x", "2"],
            &["--x must be in [0, 1], got 2"],
        ),
        (
            &["theory", "variance", "--x", "3", "--length", "2"],
            &["--x must be in [0, 2], got 3"],
        ),
        (
            &["theory", "variance", "--x", "-0.1"],
            &["--x must be in [0, 1], got -0.1"],
        ),
        (
            &["theory", "variance", "--x", "NaN"],
            &["--x must be in [0, 1], got NaN"],
        ),
        (
            &[
                "theory",
                "correlation",
                "--x",
                "0.5",
                "--y",
                "1.5",
                "--t",
                "0",
                "--eta",
                "1",
            ],
            &["--y must be in [0, 1], got 1.5"],
        ),
        (
            &[
                "theory",
                "correlation",
                "--x",
                "0.5",
                "--y",
                "0.5",
                "--t",
                "2",
                "--eta",
                "1",
            ],
            &["--t must be in [0, --eta] = [0, 1]", "got 2"],
        ),
        (
            &[
                "theory",
                "correlation",
                "--x",
                "0.5",
                "--y",
                "0.5",
                "--t",
                "0",
                "--eta",
                "-1",
            ],
            &["--eta must be finite and >= 0, got -1"],
        ),
        (
            &[
                "theory",
                "correlation",
                "--x",
                "0.5",
                "--y",
                "0.5",
                "--t",
                "0",
                "--eta",
                "1",
                "--tolerance",
                "0",
            ],
            &["--tolerance must be in (0, 1), got 0"],
        ),
        (
            &["theory", "mode", "--n", "0"],
            &["--n must be >= 1, got 0"],
        ),
        (
            &["theory", "mode", "--n", "-3"],
            &["--n must be >= 1, got -3"],
        ),
    ];
    for (args, needles) in cases {
        assert_bad_input(args, needles);
    }
}

/// What: unknown subcommands, unknown flags, missing required flags and unparsable
/// values are rejected by clap with exit 2, naming the offending token, without a panic.
/// Reference: clap's usage errors (exit code 2).
/// Tolerance: exact substrings.
#[test]
fn usage_errors_exit_2() {
    let cases: &[(&[&str], &[&str])] = &[
        (&["frobnicate"], &["frobnicate"]),
        (&["theory", "foo"], &["foo"]),
        (
            &["theory", "variance", "--x", "0.5", "--bogus", "1"],
            &["--bogus"],
        ),
        (&["theory", "mode"], &["--n"]),
        (&["theory", "variance", "--x", "abc"], &["--x", "abc"]),
        (
            &["verify", "--budget", "huge"],
            &["--budget", "huge", "quick"],
        ),
        // Unbounded sizes are refused before anything runs (issue #12).
        (
            &[
                "stability",
                "--scene",
                "hinged-linear-2d",
                "--burn-in",
                "18446744073709551615",
            ],
            &["--burn-in", "[0, 1e8]", "18446744073709551615"],
        ),
        (
            &[
                "work-precision",
                "--scene",
                "hinged-linear-2d",
                "--dt-tau1",
                "1e-12",
            ],
            &["--dt-tau1", "1e10 steps per trajectory"],
        ),
    ];
    for (args, needles) in cases {
        assert_bad_input(args, needles);
    }
}

/// What: a `--scene` path that is a directory or a FIFO named `*.toml` is refused with
/// exit 2 naming the file (a FIFO used to block the run, a directory exited 3).
/// Tolerance: exact substrings; a time limit for the FIFO.
#[test]
fn scene_paths_that_are_not_files_are_refused() {
    let dir = TempDir::new("scene-kinds");
    let d = dir.path().join("x.toml");
    std::fs::create_dir(&d).unwrap();
    let fifo = dir.path().join("f.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let mut cases = vec![(d, "a directory")];
    if made.is_ok_and(|s| s.success()) {
        cases.push((fifo, "not a regular file"));
    }
    for (path, want) in cases {
        let p = path.to_str().unwrap();
        let args = ["verify", "--scene", p, "--out", &dir.join_str("out")];
        let start = std::time::Instant::now();
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        assert!(err.contains(p) && err.contains(want), "{err}");
        assert!(start.elapsed().as_secs_f64() < 5.0);
    }
}

/// What: temporary files that a killed run left in `--out` (`.<name>.tmp.<pid>.<n>` of a
/// process that is gone) are removed by the next run, which says so.
/// Tolerance: exact substrings.
#[test]
fn stale_temporaries_of_killed_runs_are_removed() {
    if !Path::new("/proc").is_dir() {
        return;
    }
    let dir = TempDir::new("stale-tmp");
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("hinged-linear-2d")).unwrap();
    let stale = [
        out.join(".summary.json.tmp.4000000000.0"),
        out.join("hinged-linear-2d")
            .join(".modes.csv.tmp.4000000000.5"),
    ];
    for p in &stale {
        std::fs::write(p, b"half").unwrap();
    }
    let tiny = fixture(TINY).display().to_string();
    let args = ["verify", "--scene", &tiny, "--out", out.to_str().unwrap()];
    let o = run(&args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    assert!(stale.iter().all(|p| !p.exists()));
    assert!(stderr_of(&o).contains("removed 2 temporary file(s)"));
}

/// What: an `--out` that cannot be created or written is refused before anything runs:
/// exit 2 naming `--out`, no simulation (the verify of the paper's 3D scene would take
/// seconds; the refusal is immediate). Set-up: `--out` below a regular file.
/// Tolerance: exact substrings.
#[test]
fn unwritable_out_is_refused_before_running() {
    let dir = TempDir::new("out-file");
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let out = file.join("reports");
    for cmd in ["verify", "converge", "stability", "work-precision"] {
        let mut args = vec![
            cmd,
            "--scene",
            "hinged-linear-2d",
            "--out",
            out.to_str().unwrap(),
        ];
        if cmd == "converge" {
            args.extend(["--over", "elements"]);
        }
        let start = std::time::Instant::now();
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        assert!(err.contains("--out") && err.contains("a-file"), "{err}");
        assert!(
            start.elapsed().as_secs_f64() < 5.0,
            "{cmd} ran before refusing --out"
        );
    }
}

/// What: an `--out` that is a symbolic link leading nowhere (dangling, or a loop of
/// links), or a path below one, is refused before anything runs: exit 2 naming `--out`,
/// the link and the cause; the link is left as it was. It failed with exit 3 "File
/// exists (os error 17)". A `--scene` file that is such a link is named as one.
/// Tolerance: exact substrings.
#[cfg(unix)]
#[test]
fn out_through_a_link_to_nowhere_is_refused() {
    let dir = TempDir::new("out-link");
    let dangling = dir.path().join("dangling");
    std::os::unix::fs::symlink(dir.path().join("nowhere"), &dangling).unwrap();
    let looped = dir.path().join("loop");
    std::os::unix::fs::symlink(&looped, &looped).unwrap();
    let below = dangling.join("reports");
    for (out, link) in [
        (&dangling, &dangling),
        (&looped, &looped),
        (&below, &dangling),
    ] {
        for cmd in ["verify", "run"] {
            let args = [
                cmd,
                "--scene",
                "hinged-linear-2d",
                "--out",
                out.to_str().unwrap(),
            ];
            let o = run(&args);
            assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
            let err = stderr_of(&o);
            assert!(
                err.contains("--out")
                    && err.contains(&link.display().to_string())
                    && err.contains("symbolic link that leads to no file or directory"),
                "{err}"
            );
            assert!(std::fs::symlink_metadata(link).unwrap().is_symlink());
        }
    }
    // A scene file that is such a link is named as one (it read "there is no file").
    let scene = dir.path().join("scene.toml");
    std::os::unix::fs::symlink(&scene, &scene).unwrap();
    let args = ["verify", "--scene", scene.to_str().unwrap()];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(
        err.contains("--scene") && err.contains("is a symbolic link that leads to no file"),
        "{err}"
    );
}

/// What: a negative value after a space (`--bending-rigidity -1`, the usual spelling) must
/// be reported like `--bending-rigidity=-1`: exit 2 naming the flag and its range.
/// Today clap takes `-1` for a flag ("unexpected argument '-1' found"): the exit code
/// is 2 but the message names neither the flag's range nor that the value is negative;
/// the physical flags lack `allow_negative_numbers` (only --x/--y/--t/--eta/--n have it).
/// Reference: `src/cli/theory.rs` `PhysicalArgs`.
/// Tolerance: exact substrings.
#[test]

fn theory_negative_value_after_space_names_flag_and_range() {
    for flag in ["--bending-rigidity", "--length", "--drag", "--kt"] {
        let expected = format!("{flag} must be finite and > 0, got -1");
        assert_bad_input(
            &["theory", "variance", "--x", "0.5", flag, "-1"],
            &[&expected],
        );
    }
}

/// What: a result that overflows must not be printed as `null` with exit 0.
/// `theory variance --x 0.5 --length 1e200` has the finite value
/// kT x²(L−x)²/(3 EI L) ≈ 8.33e198, but the intermediate (L−x)² overflows and the binary
/// prints `{"variance":null,"x":0.5}` and exits 0. Expected: the finite value, or exit 2
/// naming `--length`.
/// Reference: closed form, evaluated without overflow as kT x² ((L−x)/L)(L−x)/(3 EI).
/// Tolerance: 1e-12 relative.
#[test]

fn theory_overflow_is_not_reported_as_success_with_null() {
    let args = ["theory", "variance", "--x", "0.5", "--length", "1e200"];
    let o = run(&args);
    assert_no_panic(&args, &o);
    if o.status.code() == Some(0) {
        let v: Value = serde_json::from_str(stdout_of(&o).trim()).expect("JSON");
        let got = v["variance"]
            .as_f64()
            .unwrap_or_else(|| panic!("variance is not a finite number: {}", describe(&args, &o)));
        let (x, l) = (0.5_f64, 1e200_f64);
        let expected = x * x * ((l - x) / l) * (l - x) / 3.0;
        assert_rel(got, expected, REL, "variance with L = 1e200");
    } else {
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        assert!(
            stderr_of(&o).contains("--length"),
            "{}",
            describe(&args, &o)
        );
    }
}

/// What: a result beyond f64 (`theory variance --ends free-free --length 1e300`) exits 2
/// naming the result's field and the parameter flags to rescale (it named neither flag).
/// Tolerance: exact substrings.
#[test]
fn theory_overflow_names_the_flags_to_rescale() {
    let args = [
        "theory",
        "variance",
        "--x",
        "0.5",
        "--ends",
        "free-free",
        "--length",
        "1e300",
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    for needle in ["`variance`", "--length", "--bending-rigidity", "rescale"] {
        assert!(err.contains(needle), "{needle}: {}", describe(&args, &o));
    }
}

// ---------------------------------------------------------------------------------------
// 3. Scene files
// ---------------------------------------------------------------------------------------

/// What: every scene in `tests/scenes/good/` runs to exit 0 or 1 (statistics: 1
/// is a legitimate outcome of a tiny ensemble), exit 0 exactly when `summary.passed`, and
/// writes `summary.json` of the documented shape (`budget`, `alpha`, `passed`,
/// `scenes[].{name, passed, wall_seconds, figures, tables, checks[].{name, kind, passed,
/// p_value, estimate, reference, std_error}}`) with consistent pass flags, `index.html`
/// naming the scene, and exactly the CSV/SVG files listed in `figures`/`tables`; the
/// membrane scenes there (a `[membrane]` table, issue #27) as well.
/// Reference: `src/verify/summary.rs`, `src/verify/runner.rs`, `Scene::refuse_membrane`.
/// Tolerance: exact (structure).
#[test]
fn good_scenes_run_and_write_documented_outputs() {
    let scenes = toml_files(&fixture("tests/scenes/good"));
    assert!(!scenes.is_empty(), "no good scene fixtures");
    let (mut filaments, mut membranes) = (0, 0);
    for scene in scenes {
        let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
        let out = TempDir::new("good");
        let text = std::fs::read_to_string(&scene).expect("readable fixture");
        if text.lines().any(|l| l.trim() == "[membrane]") {
            membranes += 1;
        } else {
            filaments += 1;
        }
        let s = verify_scene(&scene, out.path(), None);
        let ctx = format!("scene {}", scene.display());

        // The shape the repository's JSON Schema states (src/verify/summary.schema.json).
        let v = common::schema::violations(&common::schema::summary_schema(), &s);
        assert!(
            v.is_empty(),
            "{ctx}: summary.json departs from its schema: {v:#?}"
        );
        assert_eq!(s["budget"], "quick", "{ctx}");
        assert_eq!(s["alpha"].as_f64(), Some(0.01), "{ctx}");
        let scenes = s["scenes"].as_array().expect("scenes is an array");
        assert_eq!(scenes.len(), 1, "{ctx}");
        let sc = &scenes[0];
        assert_eq!(
            sc["name"],
            stem.as_str(),
            "scene name is the file stem: {ctx}"
        );
        let wall = sc["wall_seconds"]
            .as_f64()
            .expect("wall_seconds is a number");
        assert!(
            wall.is_finite() && wall >= 0.0,
            "{ctx}: wall_seconds {wall}"
        );

        let checks = sc["checks"].as_array().expect("checks is an array");
        assert!(!checks.is_empty(), "{ctx}: no checks");
        let mut names = std::collections::BTreeSet::new();
        let mut fully_numeric = 0;
        for c in checks {
            let name = c["name"].as_str().expect("check name is a string");
            assert!(names.insert(name), "{ctx}: duplicate check name {name}");
            assert!(c["kind"].as_str().is_some_and(|k| !k.is_empty()), "{c}");
            assert!(c["passed"].is_boolean(), "{c}");
            let mut numeric = true;
            for key in ["p_value", "estimate", "reference", "std_error"] {
                let v = c
                    .get(key)
                    .unwrap_or_else(|| panic!("{ctx}: {key} missing in {c}"));
                assert!(v.is_null() || v.is_f64(), "{ctx}: {key} = {v} in {c}");
                numeric &= v.is_f64();
            }
            if let Some(p) = c["p_value"].as_f64() {
                assert!((0.0..=1.0).contains(&p), "{ctx}: p_value {p} in {c}");
            }
            fully_numeric += usize::from(numeric);
        }
        assert!(
            fully_numeric > 0,
            "{ctx}: no statistical check with numbers"
        );
        let all_passed = checks.iter().all(|c| c["passed"] == true);
        assert_eq!(sc["passed"].as_bool(), Some(all_passed), "{ctx}");
        assert_eq!(s["passed"].as_bool(), Some(all_passed), "{ctx}");

        // index.html, and exactly the listed figures and tables.
        let index = std::fs::read_to_string(out.join("index.html")).expect("index.html");
        assert!(
            index.contains(&stem),
            "{ctx}: index.html does not name the scene"
        );
        for (key, ext) in [("figures", "svg"), ("tables", "csv")] {
            let listed: std::collections::BTreeSet<PathBuf> = sc[key]
                .as_array()
                .unwrap_or_else(|| panic!("{key} is an array"))
                .iter()
                .map(|p| PathBuf::from(p.as_str().expect("relative path")))
                .collect();
            assert!(!listed.is_empty(), "{ctx}: no {key}");
            let written = files_with_ext(out.path(), ext);
            let written_names: std::collections::BTreeSet<PathBuf> =
                written.keys().cloned().collect();
            assert_eq!(listed, written_names, "{ctx}: {key} vs *.{ext} written");
            for (p, bytes) in &written {
                // A compression scene also draws the run-wide Fig. 2 at the top.
                assert!(
                    p.is_relative() && (p.starts_with(&stem) || p == Path::new("fig2.svg")),
                    "{ctx}: {}",
                    p.display()
                );
                let text = String::from_utf8_lossy(bytes);
                match ext {
                    "svg" => assert!(text.contains("<svg"), "{ctx}: {} is no SVG", p.display()),
                    _ => assert!(text.lines().count() >= 2, "{ctx}: {} is empty", p.display()),
                }
            }
        }
    }
    assert!(
        filaments >= 2 && membranes >= 2,
        "{filaments} filament and {membranes} membrane fixtures"
    );
}

/// What: the continuum columns `verify` writes agree with the `theory` subcommand: the
/// profile table's `continuum` at each x equals `theory variance --x x` and the two-time
/// table's equals `theory correlation` at the same (x, y, t, η). The fixture uses the
/// default filament (all parameters 1).
/// Reference: both come from the spectral reference (`src/spectral`); the profile is
/// 1/48 at x = L/2.
/// Tolerance: 1e-12 relative (the same computation, printed with round-trip precision).
#[test]
fn verify_continuum_columns_match_theory_subcommand() {
    let out = TempDir::new("continuum");
    verify_scene(&fixture(TINY), out.path(), None);
    let read_csv = |name: &str| -> Vec<BTreeMap<String, String>> {
        let text = std::fs::read_to_string(out.join(&format!("tiny-linear/{name}")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        lines
            .map(|l| {
                header
                    .iter()
                    .cloned()
                    .zip(l.split(',').map(String::from))
                    .collect()
            })
            .collect()
    };
    let profile = read_csv("crank-nicolson-profile.csv");
    assert!(!profile.is_empty());
    for row in profile {
        let x = &row["x"];
        let continuum: f64 = row["continuum"].parse().unwrap();
        let v = theory(&["variance", "--x", x]);
        assert_rel(
            continuum,
            num(&v, "variance"),
            REL,
            &format!("profile at x = {x}"),
        );
        if x == "0.5" {
            assert_rel(continuum, 1.0 / 48.0, REL, "profile at x = 1/2");
        }
    }
    let two_time = read_csv("crank-nicolson-two-time.csv");
    assert!(!two_time.is_empty());
    for row in two_time {
        let (x, y, t, eta) = (&row["x"], &row["y"], &row["t"], &row["eta"]);
        let continuum: f64 = row["continuum"].parse().unwrap();
        let c = theory(&["correlation", "--x", x, "--y", y, "--t", t, "--eta", eta]);
        assert_rel(
            continuum,
            num(&c, "correlation"),
            REL,
            &format!("two-time at ({x}, {y}, {t}, {eta})"),
        );
    }
}

/// What: the two-time table's `std_error` beside each estimate is the error of that
/// point's check in `summary.json`, for a diagonal point (x = y, t = η: the χ² test,
/// error from the reference) and an off-diagonal one (the quadratic-form test, error
/// from the reference) alike.
/// Reference: `summary.json`'s `std_error` of the same checks, in the same order.
/// Tolerance: exact (both print the same f64 with round-trip precision).
#[test]
fn two_time_table_errors_are_the_checks_errors() {
    let dir = TempDir::new("two-time-errors");
    let text = std::fs::read_to_string(fixture(TINY)).unwrap();
    let text = replaced(
        &text,
        "two_time = [[0.5, 0.5, 0.5, 1.0]]",
        "two_time = [[0.5, 0.5, 0.5, 1.0], [0.5, 0.5, 1.0, 1.0]]",
    );
    let scene = write_scene(&dir, "two-time-errors", text.as_bytes());
    let out = dir.join("out");
    let summary = verify_scene(&scene, &out, None);
    let checks: Vec<(String, f64)> = summary["scenes"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["check"] == "two-time")
        .map(|c| {
            let kind = c["kind"].as_str().unwrap().to_string();
            (kind, c["std_error"].as_f64().unwrap())
        })
        .collect();
    let kinds: Vec<&str> = checks.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(kinds, ["quadratic-form", "chi2-variance"]);
    let table = std::fs::read_to_string(out.join("two-time-errors/crank-nicolson-two-time.csv"))
        .expect("two-time table");
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "std_error").unwrap();
    let errors: Vec<f64> = lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    let expected: Vec<f64> = checks.iter().map(|c| c.1).collect();
    assert_eq!(errors, expected);
}

/// What: `verify` refuses (exit 2, naming `--scene` and both files) two scene files of
/// one name (the file stem, which names the output folder: the second would write over
/// the first's tables) and one scene given twice (it would be counted twice), before
/// writing anything.
/// Tolerance: exact substrings.
#[test]
fn scenes_of_one_name_are_refused() {
    let dir = TempDir::new("same-stem");
    let text = std::fs::read_to_string(fixture(TINY)).unwrap();
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::create_dir_all(dir.join("b")).unwrap();
    std::fs::write(dir.join("a/x.toml"), &text).unwrap();
    std::fs::write(dir.join("b/x.toml"), text.replace("kt = 1.0", "kt = 2.0")).unwrap();
    let (a, b, out) = (
        dir.join_str("a/x.toml"),
        dir.join_str("b/x.toml"),
        dir.join_str("out"),
    );
    for (first, second, named) in [(&a, &b, "both named \"x\""), (&a, &a, "given twice")] {
        let args = [
            "verify", "-q", "--scene", first, "--scene", second, "--out", &out,
        ];
        let o = command().args(args).output().expect("binary runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("--scene") && err.contains(named) && err.contains(second.as_str()),
            "{err}"
        );
        assert!(!Path::new(&out).exists(), "nothing written");
    }
}

/// The directives of a bad scene fixture.
struct BadScene {
    path: PathBuf,
    file_name: String,
    expect: Vec<String>,
    expect_after_fix: Vec<String>,
    bug: Option<String>,
}

fn bad_scenes() -> Vec<BadScene> {
    let files = toml_files(&fixture("tests/scenes/bad"));
    assert!(files.len() >= 17, "expected the bad-scene fixtures");
    files
        .into_iter()
        .map(|path| {
            let text = std::fs::read_to_string(&path).expect("readable fixture");
            let file_name = path.file_name().unwrap().to_string_lossy().into_owned();
            assert!(
                text.starts_with("# expect: "),
                "{file_name}: the first line must be `# expect: <substring>`"
            );
            let mut s = BadScene {
                path,
                file_name,
                expect: Vec::new(),
                expect_after_fix: Vec::new(),
                bug: None,
            };
            for line in text.lines().take_while(|l| l.starts_with('#')) {
                if let Some(v) = line.strip_prefix("# expect: ") {
                    s.expect.push(v.to_string());
                } else if let Some(v) = line.strip_prefix("# expect-after-fix: ") {
                    s.expect_after_fix.push(v.to_string());
                } else if let Some(v) = line.strip_prefix("# bug: ") {
                    s.bug = Some(v.to_string());
                }
            }
            s
        })
        .collect()
}

/// Runs `verify --scene <bad file>` and returns (args as text, output).
fn run_bad_scene(scene: &BadScene, out: &TempDir) -> (Vec<String>, Output) {
    let args: Vec<String> = vec![
        "verify".into(),
        "--scene".into(),
        scene.path.display().to_string(),
        "--out".into(),
        out.join_str(&scene.file_name),
        "--scene-dir".into(),
        scene_dir(),
    ];
    let o = command().args(&args).output().expect("binary runs");
    (args, o)
}

/// What: every scene in `tests/scenes/bad/` is rejected with exit 2, no panic, no
/// `summary.json`, and an error message containing each `# expect:` substring (the key,
/// and the allowed range or the reason) and — unless the file documents a `# bug:` in
/// its message — the file name. All files are run and all failures reported together.
/// Reference: `Scene::validate` in `src/scene/validate.rs`, `src/error.rs`.
/// Tolerance: exact substrings.
#[test]
fn bad_scenes_are_rejected_with_exit_2() {
    let out = TempDir::new("bad");
    let mut failures = Vec::new();
    for scene in bad_scenes() {
        let (args, o) = run_bad_scene(&scene, &out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = stderr_of(&o);
        let mut problems = Vec::new();
        if o.status.code() != Some(2) {
            problems.push(format!("exit {:?}, expected 2", o.status.code()));
        }
        if err.contains("panicked") || o.status.code().is_none() {
            problems.push("panicked or killed".to_string());
        }
        if out.join(&scene.file_name).join("summary.json").exists() {
            problems.push("wrote summary.json".to_string());
        }
        if scene.bug.is_none() && !err.contains(&scene.file_name) {
            problems.push(format!(
                "message does not name the file {}",
                scene.file_name
            ));
        }
        for e in &scene.expect {
            if !err.contains(e.as_str()) {
                problems.push(format!("message lacks {e:?}"));
            }
        }
        if !problems.is_empty() {
            failures.push(format!("{}\n{}", problems.join("; "), describe(&args, &o)));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

/// What: the bad scenes that document a bug in their message (`# bug:`) must, once it is
/// fixed, name the file and contain each `# expect-after-fix:` substring, still with
/// exit 2 and no panic. Today:
/// - `euler-maruyama-unstable.toml`: the stability error names neither the file nor the
///   run/key and gives dt and the limit in physical units (dt = 1.03e-6, limit 7.94e-8)
///   where the file uses units of τ₁ (dt_tau1 = 1e-4, limit 7.73e-6);
/// - `missing-standard-ensemble.toml`: a key missing from a `[[runs]]` table is reported
///   under the table above it (`key `sampling`: missing field `standard``);
/// - `two-time-nan-eta.toml`: η/τ₁ = nan is blamed on t/τ₁ (`two_time[0][2]`).
///
/// Reference: `src/error.rs` (every error names the file and key, the value and the
/// allowed range).
/// Tolerance: exact substrings.
#[test]

fn bad_scenes_with_known_bugs_name_file_and_key() {
    let out = TempDir::new("bad-bugs");
    let mut failures = Vec::new();
    for scene in bad_scenes().into_iter().filter(|s| s.bug.is_some()) {
        let (args, o) = run_bad_scene(&scene, &out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = stderr_of(&o);
        let mut problems = Vec::new();
        if o.status.code() != Some(2) || err.contains("panicked") {
            problems.push(format!("exit {:?}, expected 2", o.status.code()));
        }
        let needles = std::iter::once(&scene.file_name)
            .chain(&scene.expect)
            .chain(&scene.expect_after_fix);
        for e in needles {
            if !err.contains(e.as_str()) {
                problems.push(format!("message lacks {e:?}"));
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{} (bug: {})\n{}",
                problems.join("; "),
                scene.bug.as_deref().unwrap_or(""),
                describe(&args, &o)
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

fn tiny_text() -> String {
    std::fs::read_to_string(fixture(TINY)).expect("tiny scene")
}

/// `text` with the first occurrence of `from` outside comment lines replaced by `to`.
fn replaced(text: &str, from: &str, to: &str) -> String {
    let mut done = false;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if !done && !l.trim_start().starts_with('#') && l.contains(from) {
                done = true;
                l.replacen(from, to, 1)
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "fixture lacks {from:?} outside comments");
    lines.join("\n") + "\n"
}

/// What: scenes that pass validation but cannot be run as written must either run
/// (exit 0/1, e.g. leaving out a check the data cannot support, as `decay-rate` already
/// does) or be rejected with exit 2 naming the scene file and the key. Today each fails
/// with a message about an internal variable and no file or key:
/// - `dt_tau1 = 100` (allowed: (0, 100]) → exit 2 "x must be at least 8 samples, got 1 samples";
/// - `quick.duration_tau1 = 0.02` (allowed: (0, 1e6]) → exit 2 "x must be at least 8 samples, got 0 samples";
/// - `filament.kt = 1e-300` (allowed: > 0) → exit 2 "x must be a non-constant series …";
/// - `filament.length = 1e200` (allowed: > 0) → exit 3 "numerical failure in
///   generalized_modes: damping matrix not positive definite".
///
/// Reference: `src/error.rs` (bad input names the file and key).
/// Tolerance: exact substrings.
#[test]

fn run_time_input_errors_name_the_scene_file_and_key() {
    let base = tiny_text();
    let cases = [
        (
            "dt-100",
            replaced(&base, "dt_tau1 = 0.01", "dt_tau1 = 100.0"),
            "runs[0].dt_tau1",
        ),
        (
            "short-duration",
            replaced(&base, "duration_tau1 = 40.0", "duration_tau1 = 0.02"),
            "runs[0].quick.duration_tau1",
        ),
        (
            "tiny-kt",
            replaced(&base, "kt = 1.0", "kt = 1e-300"),
            "filament.kt",
        ),
        (
            "huge-length",
            replaced(&base, "length = 1.0", "length = 1e200"),
            "filament.length",
        ),
    ];
    let dir = TempDir::new("runtime");
    let mut failures = Vec::new();
    for (name, text, key) in cases {
        let scene = write_scene(&dir, name, text.as_bytes());
        let (scene_s, out_s, dir_s) = (
            scene.display().to_string(),
            dir.join_str(&format!("out-{name}")),
            scene_dir(),
        );
        let args = [
            "verify",
            "--scene",
            &scene_s,
            "--out",
            &out_s,
            "--scene-dir",
            &dir_s,
        ];
        let o = run(&args);
        let err = stderr_of(&o);
        let ok = match o.status.code() {
            Some(0 | 1) => true,
            Some(2) => err.contains(&format!("{name}.toml")) && err.contains(key),
            _ => false,
        } && !err.contains("panicked");
        if !ok {
            failures.push(format!(
                "expected exit 0/1, or 2 naming {name}.toml and `{key}`:\n{}",
                describe(&args, &o)
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

/// What: a missing top-level key is reported under its own name or `-`, not under the
/// key on the first line of the file. Today a file starting with `description = …` and
/// lacking `seed` gives "key `description`: missing field `seed`".
/// Reference: `key_at` in `src/scene/spec.rs` (`-` for errors without a key).
/// Tolerance: exact substrings.
#[test]

fn missing_top_level_key_is_not_blamed_on_the_first_line() {
    let dir = TempDir::new("missing-seed");
    let text = replaced(&tiny_text(), "seed = 424242", "");
    let body = text
        .lines()
        .skip_while(|l| l.starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    assert!(body.starts_with("description = "));
    let scene = write_scene(&dir, "no-seed", body.as_bytes());
    let (scene_s, out_s, dir_s) = (
        scene.display().to_string(),
        dir.join_str("out"),
        scene_dir(),
    );
    let args = [
        "verify",
        "--scene",
        &scene_s,
        "--out",
        &out_s,
        "--scene-dir",
        &dir_s,
    ];
    let o = run(&args);
    assert_no_panic(&args, &o);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(
        err.contains("no-seed.toml") && err.contains("missing field `seed`"),
        "{err}"
    );
    assert!(
        !err.contains("key `description`"),
        "blames `description`: {}",
        describe(&args, &o)
    );
}

/// What: a scene file that is not UTF-8 is bad input: exit 2 naming the file, not exit 3
/// ("a run failed"). Today: exit 3, "<file>: stream did not contain valid UTF-8".
/// Reference: `src/error.rs` (2: bad input incl. scene files; 3: failures during a run).
/// Tolerance: exact substrings.
#[test]

fn non_utf8_scene_is_bad_input() {
    let dir = TempDir::new("utf8");
    let text = tiny_text();
    let (head, tail) = text.split_once("CLI test fixture").expect("fixture text");
    // "CLI t\xE9st fixture" in Latin-1: 0xE9 followed by 's' is not valid UTF-8.
    let bytes = [head.as_bytes(), b"CLI t\xE9st fixture", tail.as_bytes()].concat();
    let scene = write_scene(&dir, "latin1", &bytes);
    let (scene_s, out_s, dir_s) = (
        scene.display().to_string(),
        dir.join_str("out"),
        scene_dir(),
    );
    assert_bad_input(
        &[
            "verify",
            "--scene",
            &scene_s,
            "--out",
            &out_s,
            "--scene-dir",
            &dir_s,
        ],
        &["latin1.toml", "UTF-8"],
    );
}

// ---------------------------------------------------------------------------------------
// 4. verify: bad flags
// ---------------------------------------------------------------------------------------

/// What: `verify --scene does-not-exist` exits 2 naming the flag, the value and every
/// known scene of the scene directory, and writes nothing.
/// Reference: `resolve_scenes` in `src/verify/runner.rs`.
/// Tolerance: exact substrings.
#[test]
fn verify_unknown_scene_names_known_scenes() {
    let out = TempDir::new("unknown-scene");
    let known: Vec<String> = toml_files(&fixture("verification"))
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(!known.is_empty());
    let mut needles = vec!["--scene must be one of: ", "got does-not-exist"];
    needles.extend(known.iter().map(String::as_str));
    let (out_s, dir_s) = (out.join_str("out"), scene_dir());
    let args = [
        "verify",
        "--scene",
        "does-not-exist",
        "--out",
        &out_s,
        "--scene-dir",
        &dir_s,
    ];
    assert_bad_input(&args, &needles);
    assert!(
        !out.join("out").exists(),
        "wrote output for an unknown scene"
    );
    // The default scene directory (`verification`, relative to the working directory).
    assert_bad_input(
        &["verify", "--scene", "does-not-exist", "--out", &out_s],
        &needles,
    );
}

/// What: `--alpha` outside (0, 0.5) exits 2 naming the flag, range and value, before any
/// scene runs.
/// Reference: `src/cli/verify.rs`.
/// Tolerance: exact substrings.
#[test]
fn verify_alpha_out_of_range_exits_2() {
    let out = TempDir::new("alpha");
    let out_s = out.join_str("out");
    let tiny = fixture(TINY).display().to_string();
    for (alpha, shown) in [("2", "2"), ("0", "0"), ("NaN", "NaN"), ("0.5", "0.5")] {
        let expected = format!("--alpha must be in (0, 0.5), got {shown}");
        assert_bad_input(
            &[
                "verify", "--scene", &tiny, "--alpha", alpha, "--out", &out_s,
            ],
            &[&expected],
        );
    }
    assert!(
        !out.join("out").exists(),
        "wrote output despite a bad --alpha"
    );
}

/// What: `verify --scene <path>.toml` must not need the scene directory: run from a
/// directory without `verification/`, the path works (exit 0/1). Today `resolve_scenes`
/// lists the scene directory first and fails with exit 3
/// "error: verification: No such file or directory (os error 2)" — exit 3 means "a run
/// failed", and the message names neither `--scene-dir` nor the fix.
/// Reference: `src/verify/runner.rs` `resolve_scenes`; the guide, docs/src/reference/scenes.md (`--scene NAME` or path).
/// Tolerance: exact.
#[test]

fn verify_scene_path_works_outside_the_crate_root() {
    let cwd = TempDir::new("cwd");
    let tiny = fixture(TINY).display().to_string();
    let out = cwd.join_str("out");
    let args = ["verify", "--scene", &tiny, "--out", &out];
    let o = command()
        .current_dir(cwd.path())
        .args(args)
        .output()
        .expect("binary runs");
    assert_no_panic(&args, &o);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    assert!(cwd.join("out/summary.json").exists());
}

/// What: a missing `--scene-dir` is bad input: exit 2 naming `--scene-dir` and the path.
/// Today: exit 3 "error: <dir>: No such file or directory (os error 2)".
/// Reference: `src/error.rs` (2: bad input; 3: a run failed).
/// Tolerance: exact substrings.
#[test]

fn verify_missing_scene_dir_is_bad_input() {
    let tmp = TempDir::new("no-scene-dir");
    let missing = tmp.join_str("no-such-dir");
    let out = tmp.join_str("out");
    assert_bad_input(
        &["verify", "--scene-dir", &missing, "--out", &out],
        &["--scene-dir", "no-such-dir"],
    );
}

// ---------------------------------------------------------------------------------------
// 5–6. Determinism
// ---------------------------------------------------------------------------------------

/// What: the tiny scene run with `RAYON_NUM_THREADS=1` and `=2` gives the same
/// `summary.json` (as parsed JSON, after deleting every `wall_seconds`) and byte-identical
/// CSV files (same set of files, same bytes).
/// Reference: the guide, docs/src/reference/reproducibility.md (one PCG stream per trajectory, derived from
/// seed, run name and index).
/// Tolerance: exact equality; anything else is a thread-count dependence.
#[test]
fn results_do_not_depend_on_thread_count() {
    let (a, b) = (TempDir::new("threads1"), TempDir::new("threads2"));
    let sa = verify_scene(&fixture(TINY), a.path(), Some(1));
    let sb = verify_scene(&fixture(TINY), b.path(), Some(2));
    assert!(
        sa["scenes"][0].get("wall_seconds").is_some(),
        "the field to strip exists"
    );
    assert_eq!(
        without_wall_seconds(&sa),
        without_wall_seconds(&sb),
        "summary.json differs between 1 and 2 threads"
    );
    let (ca, cb) = (
        files_with_ext(a.path(), "csv"),
        files_with_ext(b.path(), "csv"),
    );
    assert!(!ca.is_empty(), "no CSV written");
    assert_eq!(
        ca.keys().collect::<Vec<_>>(),
        cb.keys().collect::<Vec<_>>(),
        "different CSV files"
    );
    for (path, bytes) in &ca {
        assert!(
            bytes == &cb[path],
            "{} differs between 1 and 2 threads",
            path.display()
        );
    }
}

/// What: the same seed run twice gives identical summaries (without `wall_seconds`) and
/// CSVs; a copy of the scene with only the seed changed (same file name, so the same
/// scene name) changes at least one estimate, so the seed is actually used.
/// Reference: the guide, docs/src/reference/reproducibility.md.
/// Tolerance: exact equality for the repeat; any difference for the new seed (a
/// collision of every estimate across seeds has probability ~0).
#[test]
fn same_seed_reproduces_and_new_seed_changes_estimates() {
    let (a, b) = (TempDir::new("seed-a"), TempDir::new("seed-b"));
    let sa = verify_scene(&fixture(TINY), a.path(), None);
    let sb = verify_scene(&fixture(TINY), b.path(), None);
    assert_eq!(
        without_wall_seconds(&sa),
        without_wall_seconds(&sb),
        "the same seed gave different summaries"
    );
    assert_eq!(
        files_with_ext(a.path(), "csv"),
        files_with_ext(b.path(), "csv"),
        "the same seed gave different CSVs"
    );

    let c = TempDir::new("seed-c");
    let reseeded = replaced(&tiny_text(), "seed = 424242", "seed = 424243");
    let scene = write_scene(&c, "tiny-linear", reseeded.as_bytes());
    let out = c.join("out");
    let sc = verify_scene(&scene, &out, None);
    let (ea, ec) = (estimates(&sa), estimates(&sc));
    assert_eq!(
        ea.keys().collect::<Vec<_>>(),
        ec.keys().collect::<Vec<_>>(),
        "the seed changed which checks ran"
    );
    assert!(
        ea.iter().any(|(k, v)| v.is_f64() && ec[k] != *v),
        "changing the seed changed no estimate: {ea:?}"
    );
}

/// What: a run that goes unstable stops with an error naming the step and the time, exit
/// code 3, and writes no summary (no NaN output).
/// Set-up: the paper's explicit Euler–Maruyama on the compressed filament, just below its
/// linear stability limit (7.73e-6 tau1 for 10 elements), with EA·L/kT = 1e13: the
/// stretching stiffness (EA/L)(Gw)(Gw)ᵀ, which the linear limit does not see, blows the
/// explicit scheme up within a few steps.
/// Reference: `src/error.rs` (`Diverged`: step and time), the brief's "a run that goes
/// unstable stops with an error naming the step".
/// Tolerance: exact substrings.
#[test]
fn diverging_run_stops_with_the_step() {
    let text = std::fs::read_to_string(fixture("verification/compression-2d.toml")).unwrap();
    let text = replaced(
        &text,
        "stretch_rigidity = 1.0e6",
        "stretch_rigidity = 1.0e13",
    );
    let text = text.replace(
        "integrator = \"metropolis-crank-nicolson\"",
        "integrator = \"euler-maruyama\"",
    );
    let text = text
        // A step search is for the Metropolis scheme only.
        .replace(", max_dt_tau1 = 0.16, min_acceptance = 0.6", "")
        .replace("dt_tau1 = 0.02\n", "dt_tau1 = 7.0e-6\n")
        .replace("dt_tau1 = 0.01\n", "dt_tau1 = 3.0e-6\n")
        .replace(
            "checks = [\"force-strain\", \"force-distribution\", \"dt-halving\"]",
            "checks = [\"force-strain\"]",
        );
    let dir = TempDir::new("diverge");
    let scene = write_scene(&dir, "diverge", text.as_bytes());
    let (scene_s, out_s) = (scene.display().to_string(), dir.join_str("out"));
    let args = ["verify", "--scene", &scene_s, "--out", &out_s];
    let o = run(&args);
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(3), "{}", describe(&args, &o));
    assert!(
        err.contains("unstable at step") && err.contains("t = "),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!Path::new(&out_s).join("summary.json").exists());
}

/// What: output into a pipe the reader has closed (`langevin-fem scene show NAME | head
/// -1`, as a guide page might show) ends the process quietly, as for other Unix tools: no
/// panic message. Set-up: stdout is a pipe whose read end is closed before the process
/// starts, so its first write fails (deterministically, unlike `| head`).
/// Reference: src/main.rs (SIGPIPE restored).
#[test]
fn output_into_a_closed_pipe_ends_quietly() {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let o = common::command()
        .args(["scene", "show", "hinged-linear-2d"])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .expect("the binary runs");
    let err = stderr_of(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(o.status.code(), Some(101), "{err}");
}
