//! Interrupted runs, reruns and the exit-code policy, through the binary (issue #12).
//!
//! What: (1) a `verify` killed (SIGKILL) at spread-out moments and rerun leaves a
//! consistent report — no temporary file, `summary.json` lists exactly the files present
//! (a `convergence/` folder of another command apart), and `summary.json`, `index.html`
//! and `manifest.json` carry one run id; at every interruption each file is attributable
//! to a run through the journal. (2) A rerun with fewer scenes removes the dropped
//! scenes' files. (3) Exit codes: 2 for the user's input, found before any run and
//! leaving the earlier report intact; 3 for a failure after the run started (an estimator
//! that finds no answer in the data), naming the run and the observable, never a key.
//! Reference: the guide, docs/src/reference/exit-codes-and-limits.md; `src/output/manifest.rs`; `src/error.rs`.
//! Set-up: `tests/scenes/good/tiny-linear.toml` (well under a second per run), copied
//! under two names so that a run writes two scene folders.
//! Tolerance: exact (file sets, ids, codes and substrings). Kill moments are fixed
//! fractions of a measured run time with a fixed-seed jitter, so the test is repeatable
//! in what it asks while covering the run from start to end.

mod common;

use common::{
    TempDir, all_files, command, describe, fixture, json, run, stderr_of, strings, write_scene,
};
use langevin_fem::Error;
use langevin_fem::rng::trajectory_rng;
use langevin_fem::scene::Scene;
use langevin_fem::scene::linear::LinearRun;
use langevin_fem::verify::checks::linear_checks;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const TINY: &str = "tests/scenes/good/tiny-linear.toml";
/// Interruptions of the kill test.
const KILLS: u64 = 6;
/// Seed of the jitter of the kill moments.
const KILL_JITTER_SEED: u64 = 0x5eed_0012;

fn tiny_with_duration(duration: &str) -> String {
    let text = std::fs::read_to_string(fixture(TINY)).expect("tiny scene");
    let quick = "quick = { trajectories = 4, duration_tau1 = 40.0";
    assert!(text.contains(quick), "fixture changed");
    text.replace(
        quick,
        &format!("quick = {{ trajectories = 4, duration_tau1 = {duration}"),
    )
}

/// The run id shown in `index.html`.
fn index_run_id(out: &Path) -> String {
    let html = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    let start = html.find("<code id=\"run-id\">").expect("run id in index") + 18;
    html[start..start + html[start..].find('<').expect("closed")].to_string()
}

/// A finished report: no temporary file; summary.json lists exactly the files present
/// apart from `convergence/`; one run id in summary, index and complete journal.
fn assert_consistent(out: &Path, ctx: &str) {
    let present: Vec<String> = all_files(out)
        .into_iter()
        .filter(|f| !f.starts_with("convergence/"))
        .collect();
    assert!(
        !present.iter().any(|f| common::transient(f)),
        "{ctx}: temporary or staged files left: {present:?}"
    );
    let summary = json(&out.join("summary.json"));
    assert_eq!(strings(&summary["files"]), present, "{ctx}");
    let journal = json(&out.join("manifest.json"));
    let id = summary["run_id"].as_str().expect("run id");
    assert!(!id.is_empty(), "{ctx}");
    assert_eq!(journal["run_id"].as_str(), Some(id), "{ctx}");
    assert_eq!(journal["complete"].as_bool(), Some(true), "{ctx}");
    assert_eq!(index_run_id(out), id, "{ctx}");
}

/// Right after a kill: an entry point exists only for a complete run whose id it
/// carries, and every other file is named by the journal (or is a temporary or staged
/// file, which the next run removes).
fn assert_attributable(out: &Path, ctx: &str) {
    if !out.join("manifest.json").exists() {
        // Killed before the first journal: nothing but temporaries may exist.
        let files = all_files(out);
        assert!(
            files
                .iter()
                .all(|f| common::transient(f) || f.starts_with("convergence/")),
            "{ctx}: {files:?} without a journal"
        );
        return;
    }
    let journal = json(&out.join("manifest.json"));
    let named: Vec<String> = strings(&journal["files"])
        .into_iter()
        .chain(strings(&journal["superseded"]))
        .collect();
    if out.join("summary.json").exists() {
        let summary = json(&out.join("summary.json"));
        assert_eq!(summary["run_id"], journal["run_id"], "{ctx}");
        assert_eq!(journal["complete"].as_bool(), Some(true), "{ctx}");
    }
    if out.join("index.html").exists() {
        assert_eq!(
            Some(index_run_id(out).as_str()),
            journal["run_id"].as_str(),
            "{ctx}"
        );
    }
    for f in all_files(out) {
        let ours = f == "manifest.json" || named.contains(&f);
        assert!(
            ours || common::transient(&f) || f.starts_with("convergence/"),
            "{ctx}: {f} is not attributable to a run ({journal})"
        );
    }
}

fn verify_args(scenes: &[&PathBuf], out: &Path) -> Vec<String> {
    let mut args = vec!["verify".to_string()];
    for s in scenes {
        args.extend(["--scene".to_string(), s.display().to_string()]);
    }
    args.extend(["--out".to_string(), out.display().to_string()]);
    args
}

fn verify_ok(scenes: &[&PathBuf], out: &Path) {
    let args = verify_args(scenes, out);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
}

/// (1) Killed at spread-out moments and rerun: always a consistent report. The reruns
/// alternate between two scenes and one, so that a killed run may leave files of a scene
/// that the rerun drops.
#[test]
fn a_run_killed_at_any_moment_and_rerun_leaves_a_consistent_report() {
    let dir = TempDir::new("kill");
    let text = tiny_with_duration("200.0");
    let a = write_scene(&dir, "a", text.as_bytes());
    let b = write_scene(&dir, "b", text.as_bytes());
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("convergence")).unwrap();
    std::fs::write(out.join("convergence/index.html"), b"another command's").unwrap();
    let start = Instant::now();
    verify_ok(&[&a, &b], &out);
    let full = start.elapsed();
    assert_consistent(&out, "first run");

    let mut state = KILL_JITTER_SEED;
    for i in 0..KILLS {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let jitter = (state >> 11) as f64 / (1u64 << 53) as f64;
        let delay = full.mul_f64((i as f64 + jitter) / KILLS as f64);
        let (killed, rerun): (Vec<&PathBuf>, Vec<&PathBuf>) = if i % 2 == 0 {
            (vec![&a, &b], vec![&a])
        } else {
            (vec![&a], vec![&a, &b])
        };
        let args = verify_args(&killed, &out);
        let mut child = command()
            .args(&args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("spawn");
        std::thread::sleep(delay);
        let _ = child.kill();
        let _ = child.wait();
        let ctx = format!("kill {i} after {delay:?} of {full:?}");
        assert_attributable(&out, &ctx);
        verify_ok(&rerun, &out);
        assert_consistent(&out, &format!("{ctx}, then rerun"));
        let scenes_present = ["a", "b"].map(|s| out.join(s).exists());
        assert_eq!(scenes_present, [true, rerun.len() == 2], "{ctx}");
        assert!(out.join("convergence/index.html").exists(), "{ctx}");
    }
}

/// (2) A rerun with fewer scenes removes the dropped scene's files and folder.
#[test]
fn a_rerun_with_fewer_scenes_removes_the_dropped_scenes_files() {
    let dir = TempDir::new("fewer");
    let text = tiny_with_duration("40.0");
    let a = write_scene(&dir, "a", text.as_bytes());
    let b = write_scene(&dir, "b", text.as_bytes());
    let out = dir.join("out");
    verify_ok(&[&a, &b], &out);
    assert!(all_files(&out).iter().any(|f| f.starts_with("b/")));
    let first = json(&out.join("summary.json"))["run_id"].clone();
    verify_ok(&[&a], &out);
    assert_consistent(&out, "rerun with scene a only");
    assert!(!out.join("b").exists(), "{:?}", all_files(&out));
    assert_ne!(json(&out.join("summary.json"))["run_id"], first);
}

/// (3a) Input: a duration too short for the checks' estimators is refused before any run
/// (exit 2 naming the file, the key, the value and the allowed range: at least 16 tau1
/// and 256 steps, see `src/scene/validate.rs`), and the earlier report is left as it was.
#[test]
fn a_duration_too_short_is_input_refused_before_the_run_keeping_the_old_report() {
    let dir = TempDir::new("short");
    let good = write_scene(&dir, "good", tiny_with_duration("40.0").as_bytes());
    let short = write_scene(&dir, "short", tiny_with_duration("0.02").as_bytes());
    let out = dir.join("out");
    verify_ok(&[&good], &out);
    let before = all_files(&out);
    let id = json(&out.join("summary.json"))["run_id"].clone();
    let args = verify_args(&[&short], &out);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let start = Instant::now();
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    for want in [
        "short.toml",
        "runs[0].quick.duration_tau1",
        "must be in [16, 1e6]",
        "got 0.02",
        "runs[0].dt_tau1",
    ] {
        assert!(err.contains(want), "missing {want:?}: {err}");
    }
    assert!(start.elapsed() < Duration::from_secs(5));
    assert_eq!(all_files(&out), before);
    assert_eq!(json(&out.join("summary.json"))["run_id"], id);
}

/// (3b) The shortest durations the validation admits (16 tau1, several seeds) run: they
/// exit 0 or 1, or 3 if an estimator finds no answer in the data — then naming the run
/// and the observable, with advice, not blamed on a key, and the earlier report
/// invalidated (no summary.json) — but never 2: whatever is input is refused before the
/// run (3a).
#[test]
fn the_shortest_admitted_durations_never_fail_as_input() {
    let dir = TempDir::new("estimator");
    let out = dir.join("out");
    for seed in ["424242", "1", "2", "3"] {
        let name = format!("s{seed}");
        let text = tiny_with_duration("16.0").replace("seed = 424242", &format!("seed = {seed}"));
        let scene = write_scene(&dir, &name, text.as_bytes());
        let args = verify_args(&[&scene], &out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&args);
        let err = stderr_of(&o);
        match o.status.code() {
            Some(0 | 1) => {}
            Some(3) => {
                for want in [
                    "run failed: ",
                    "runs[0] (crank-nicolson)",
                    " check of mode ",
                    "raising runs[0].quick.duration_tau1 may help",
                ] {
                    assert!(err.contains(want), "missing {want:?}: {err}");
                }
                assert!(!err.contains("key `"), "blamed on a key: {err}");
                assert!(!out.join("summary.json").exists());
                assert!(!out.join("index.html").exists());
            }
            _ => panic!("{}", describe(&args, &o)),
        }
    }
}

/// (3c) Through the library: an estimator failure on a tiny series (2 samples of mode 1,
/// and the profile's series cut to none, fewer than its test accepts) from
/// `linear_checks` is a run failure (exit code 3) naming the run and the check; a scene
/// input error is exit code 2. (The checks with exact null laws accept 2 samples, the
/// others are skipped: only an empty series is too short for every test.)
#[test]
fn error_classes_map_to_their_exit_codes() {
    let scene = Scene::load(&fixture(TINY)).expect("tiny scene");
    let run = LinearRun::prepare(&scene, &scene.runs[0]).expect("prepares");
    let steps = 2 * run.mode_every[0];
    let records: Vec<_> = (0..2)
        .map(|j| {
            let mut r = run
                .simulate(&mut trajectory_rng(7, j), steps)
                .expect("simulates");
            r.profile.iter_mut().for_each(Vec::clear);
            r
        })
        .collect();
    let two_time: Vec<Vec<f64>> = records.iter().map(|r| r.two_time.clone()).collect();
    let err = linear_checks(&run, run.spec.checks(&scene), &records, &two_time)
        .expect_err("no profile samples are too few");
    assert!(matches!(err, Error::RunFailed { .. }), "{err:?}");
    assert_eq!(err.exit_code(), 3, "{err}");
    let msg = err.to_string();
    assert!(
        msg.starts_with("run failed: crank-nicolson: ") && msg.contains(" check"),
        "{msg}"
    );

    let bad = Scene::load(&fixture("tests/scenes/bad/dt-zero.toml")).expect_err("bad scene");
    assert!(matches!(bad, Error::Scene { .. }), "{bad:?}");
    assert_eq!(bad.exit_code(), 2);

    // The mapping itself: input raised by an estimator after a run is a run failure; a
    // divergence keeps its step; I/O stays I/O.
    let from_input = Error::run_failed("r", "obs", Error::invalid("x", 1, "> 1"));
    assert_eq!(from_input.exit_code(), 3);
    let diverged = Error::run_failed("r", "obs", Error::diverged(12, 0.5, "nan"));
    assert!(matches!(diverged, Error::Diverged { step: 12, .. }));
    let io = Error::run_failed("r", "obs", Error::io("f", std::io::Error::other("x")));
    assert!(matches!(io, Error::Io { .. }) && io.exit_code() == 3);
}

/// (4) One writer per output folder: while another process holds the folder's lock
/// (this test, through [`OutputLock`], as a running command does), `verify` pointed at
/// it exits 2 naming `--out` and the folder, at once, and leaves the earlier report
/// exactly as it was; `calibrate` pointed at a folder that is being created is refused
/// the same way and leaves nothing behind. Once the lock is released the same command
/// runs. (A study's shared folder is not locked: several studies write one folder by
/// design.)
#[test]
fn a_folder_another_command_is_writing_to_is_refused_and_left_intact() {
    use langevin_fem::output::OutputLock;
    let dir = TempDir::new("locked");
    let tiny = write_scene(&dir, "tiny", tiny_with_duration("40.0").as_bytes());
    let out = dir.join("out");
    verify_ok(&[&tiny], &out);
    let snapshot = || -> Vec<(String, Vec<u8>)> {
        all_files(&out)
            .into_iter()
            .map(|f| {
                let bytes = std::fs::read(out.join(&f)).unwrap();
                (f, bytes)
            })
            .collect()
    };
    let before = snapshot();
    let refused = |args: &[String], folder: &Path| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let started = Instant::now();
        let o = run(&args);
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let named = err.contains("--out") && err.contains(&folder.display().to_string());
        assert!(named && err.contains("no other running"), "{err}");
        assert!(started.elapsed() < Duration::from_secs(5));
    };
    let lock = OutputLock::acquire("--out", &out).unwrap();
    refused(&verify_args(&[&tiny], &out), &out);
    assert_eq!(snapshot(), before);
    // A folder being created by another process: refused, and nothing left beside it.
    let fresh = dir.join("fresh/cal");
    let held = OutputLock::acquire("--out", &fresh).unwrap();
    let calibrate: Vec<String> = ["calibrate", "--scene", &tiny.display().to_string()]
        .into_iter()
        .map(String::from)
        .chain(["--seeds", "2", "--out"].map(String::from))
        .chain([fresh.display().to_string()])
        .collect();
    refused(&calibrate, &fresh);
    drop(held);
    assert!(!dir.join("fresh").exists());
    // Released: the same command runs.
    drop(lock);
    verify_ok(&[&tiny], &out);
    assert_consistent(&out, "after the lock was released");
}

/// What: `run`'s preparation without reference values (`LinearRun::prepare_for_writing`,
/// which skips the O(n³) discrete law: a 40 × 40 plate's `run` went from 106 s to 7 s)
/// writes the very files a fully prepared run writes, bit for bit, with the same row
/// plan and modal scales, on a beam with tangent and rigid columns (free ends), a
/// periodic plate (modal path) and a simply supported plate with element-uniform noise;
/// its reference values are NaN where the full preparation's are finite, so nothing can
/// judge data against them.
/// Tolerance: exact (bytes).
#[test]
fn writing_preparation_writes_what_the_full_one_writes() {
    let dir = common::TempDir::new("prepare-writing");
    for (name, run) in [
        ("microtubule-free-free", 0),
        ("grafted-clamped-free", 0),
        ("membrane-periodic", 0),
        ("membrane-hinged", 1),
    ] {
        let scene = common::verification_scene(name);
        let spec = &scene.runs[run];
        let full = LinearRun::prepare(&scene, spec).unwrap();
        let light = LinearRun::prepare_for_writing(&scene, spec).unwrap();
        let steps = full.sampled_steps(0.5 * scene.tau1());
        let plan = full.row_plan(&scene, steps, None).unwrap();
        assert_eq!(plan, light.row_plan(&scene, steps, None).unwrap(), "{name}");
        assert_eq!(full.amplitude_scale, light.amplitude_scale, "{name}");
        assert!(
            full.reference.modes[0].variance_discrete.is_finite(),
            "{name}"
        );
        assert!(
            light.reference.modes[0].variance_discrete.is_nan(),
            "{name}"
        );
        assert_eq!(
            full.reference
                .modes
                .iter()
                .map(|m| m.rate_discrete)
                .collect::<Vec<_>>(),
            light
                .reference
                .modes
                .iter()
                .map(|m| m.rate_discrete)
                .collect::<Vec<_>>(),
            "{name}"
        );
        let write = |r: &LinearRun, tag: &str| -> Vec<Vec<u8>> {
            let path = |j: u64| dir.path().join(format!("{name}-{tag}-{j}.npy"));
            r.write_ensemble(7, 0..2, &plan, path, |_| {}).unwrap();
            (0..2).map(|j| std::fs::read(path(j)).unwrap()).collect()
        };
        assert_eq!(write(&full, "full"), write(&light, "light"), "{name}");
    }
}
