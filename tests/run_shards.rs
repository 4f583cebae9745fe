//! `run --shard I/N` and the merge of `run` shards (issue #15): a scene's trajectories
//! written as 3 shards, each in a process of its own, and merged give the directory of the
//! same `run` made in one process, byte for byte apart from the run id and the
//! provenance; `check` says the same of both; a merge refuses (exit 2, naming the shard)
//! a missing shard, a trajectory missing from or given twice in the shards' manifests, and
//! shards of other settings or of another command.
//!
//! The scenes are the tiny fixtures of tests/shards.rs: a linear one (4 trajectories of
//! one run: shards of 1, 1 and 2 files, `.npy`) and a compression one (2 runs × 3 strains
//! of 7 and 5 trajectories, `--duration-tau1 5` since its quick budget is by target
//! precision, `.csv`). Each runs in well under a second.

mod common;

use common::shards::{assert_same_outputs, merge, shards_of, without};
use common::{TempDir, all_files, describe, fixture, json, stderr_of};
use std::path::{Path, PathBuf};
use std::process::Output;

const LINEAR: &str = "tests/scenes/good/tiny-linear.toml";
const COMPRESSION: &str = "tests/scenes/good/tiny-compression.toml";
/// The flags of the compression case: a duration (its quick budget chooses durations by
/// a pilot, which `run` does not do) and the CSV format.
const COMPRESSION_FLAGS: &[&str] = &["--duration-tau1", "5", "--format", "csv"];

/// The binary with `args` run in `cwd`; asserts that it did not panic.
fn run_in(cwd: &Path, args: &[String]) -> Output {
    let o = common::command()
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run langevin-fem");
    let shown: Vec<&str> = args.iter().map(String::as_str).collect();
    common::assert_no_panic(&shown, &o);
    o
}

/// The `run` command line of `scene` into `out` with `extra` flags.
fn run_args(scene: &str, out: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = vec![
        "run".to_string(),
        "-q".to_string(),
        "-s".to_string(),
        fixture(scene).display().to_string(),
        "-o".to_string(),
        out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// `run` of `scene` into `out` in one process; asserts exit 0.
fn whole(scene: &str, out: &Path, extra: &[&str]) {
    let args = run_args(scene, out, extra);
    let o = run_in(common::manifest_dir(), &args);
    let shown: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_eq!(o.status.code(), Some(0), "{}", describe(&shown, &o));
}

/// Shards `1/n … n/n` of `run` of `scene` with `extra` flags, run concurrently in
/// processes of their own into `<root>/<i>` ([`shards_of`]). Returns the shard directories.
fn shards(scene: &str, root: &Path, n: usize, extra: &[&str]) -> Vec<PathBuf> {
    let mut args = vec![
        "run".to_string(),
        "-q".to_string(),
        "-s".to_string(),
        fixture(scene).display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    shards_of(root, n, &args)
}

/// The keys that differ between two whole runs of the same work, per JSON file: in
/// `data.json` the run id and the provenance record (command line, start, wall time,
/// build state) inside its `provenance` (whose budget, seed and τ1 are compared); in the
/// journal `manifest.json` the run id and its provenance.
fn volatile(file: &str) -> &'static [&'static str] {
    if file.ends_with("data.json") {
        &["run_id", "record"]
    } else {
        &["run_id", "provenance"]
    }
}

/// Asserts that the run directories `a` and `b` hold the same files: every trajectory
/// file byte-identical, `data.json` and `manifest.json` equal as JSON without their
/// volatile keys ([`volatile`]). Returns the files.
fn assert_same_run(a: &Path, b: &Path) -> Vec<String> {
    assert_same_outputs(a, b, volatile)
}

/// `check` of `scene` on `<root>/data` into `<root>/check`, run in `root` (so that the
/// paths in its report are the same for every `root`).
fn check(scene: &str, root: &Path) -> Output {
    let args: Vec<String> = ["check", "-q", "-s", &fixture(scene).display().to_string()]
        .iter()
        .map(|s| s.to_string())
        .chain(["-d", "data", "-o", "check"].map(String::from))
        .collect();
    run_in(root, &args)
}

/// What: `run` of `scene` (with `extra` flags) in one process, and as 3 shards run
/// concurrently in processes of their own, merged; then `check` of both.
/// Reference: the whole run's directory; `check` on it.
/// Tolerance: the same files; every trajectory file byte-identical (the shards' shares
/// tile the run: each of the whole run's trajectory files is in exactly one shard, and a
/// shard holds no data.json nor manifest.json); `data.json` and `manifest.json` equal as
/// JSON without the run id and provenance. `check` gives the same exit code and the same
/// `summary.json` (run id, wall times and provenance aside) and tables on both.
fn three_shards_merge_to_the_whole_run(scene: &str, extra: &[&str], trajectories: usize) {
    let tmp = TempDir::new("run-shards");
    let (w, m) = (tmp.join("whole"), tmp.join("merged"));
    whole(scene, &w.join("data"), extra);
    let dirs = shards(scene, &tmp.join("shards"), 3, extra);
    let o = merge(&dirs, &m.join("data"));
    assert_eq!(o.status.code(), Some(0), "merge: {}", stderr_of(&o));

    let files = assert_same_run(&w.join("data"), &m.join("data"));
    let traj: Vec<&String> = files.iter().filter(|f| f.contains("trajectory-")).collect();
    assert_eq!(traj.len(), trajectories, "trajectory files: {files:?}");
    let mut in_shards: Vec<String> = Vec::new();
    for d in &dirs {
        let own = all_files(d);
        assert!(own.contains(&"shard.json".to_string()), "{}", d.display());
        assert!(
            !own.iter().any(|f| f == "data.json" || f == "manifest.json"),
            "a shard wrote a whole run's entry point: {own:?}"
        );
        assert!(own.len() > 1, "shard {} holds no trajectory", d.display());
        in_shards.extend(own.into_iter().filter(|f| f != "shard.json"));
    }
    in_shards.sort();
    let traj: Vec<String> = traj.into_iter().cloned().collect();
    assert_eq!(in_shards, traj, "the shards do not tile the run");

    let (cw, cm) = (check(scene, &w), check(scene, &m));
    assert_eq!(cw.status.code(), cm.status.code(), "{}", stderr_of(&cm));
    assert!(
        matches!(cw.status.code(), Some(0 | 1)),
        "check: {}",
        stderr_of(&cw)
    );
    let (rw, rm) = (w.join("check"), m.join("check"));
    let reports = all_files(&rw);
    assert_eq!(reports, all_files(&rm), "check wrote different files");
    for f in &reports {
        let (a, b) = (rw.join(f), rm.join(f));
        match f.as_str() {
            "index.html" => {}
            "summary.json" | "manifest.json" => {
                let drop = &["run_id", "wall_seconds", "provenance"];
                assert_eq!(
                    without(&json(&a), drop),
                    without(&json(&b), drop),
                    "check's {f} differs"
                );
            }
            _ => assert!(
                std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
                "check's {f} differs"
            ),
        }
    }
}

/// What/Reference/Tolerance: [`three_shards_merge_to_the_whole_run`], the linear fixture
/// in `.npy` (4 trajectories).
#[test]
fn linear_run_in_three_shards_merges_to_the_whole_run() {
    three_shards_merge_to_the_whole_run(LINEAR, &[], 4);
}

/// What/Reference/Tolerance: [`three_shards_merge_to_the_whole_run`], the compression
/// fixture in `.csv` (2 runs × 3 strains × 7 and 5 trajectories).
#[test]
fn compression_run_in_three_shards_merges_to_the_whole_run() {
    three_shards_merge_to_the_whole_run(COMPRESSION, COMPRESSION_FLAGS, 3 * (7 + 5));
}

/// What: `run --shard 1/1` writes a shard (its manifest, no data.json), as `verify
/// --shard 1/1` does and as `--help` says, and `merge` of it alone gives the whole run.
/// Reference: the whole run's directory. Tolerance: as [`assert_same_run`].
#[test]
fn run_shard_one_of_one_is_a_shard_that_merges_to_the_whole_run() {
    let tmp = TempDir::new("run-shard-1-of-1");
    let (w, s, m) = (tmp.join("whole"), tmp.join("shard"), tmp.join("merged"));
    whole(LINEAR, &w, &[]);
    whole(LINEAR, &s, &["--shard", "1/1"]);
    assert!(s.join("shard.json").is_file(), "a shard manifest");
    assert!(!s.join("data.json").exists(), "no sidecar in a shard");
    let o = merge(std::slice::from_ref(&s), &m);
    assert_eq!(o.status.code(), Some(0), "merge: {}", stderr_of(&o));
    assert_same_run(&w, &m);
}

/// What: a shard rerun into its own directory replaces its files; one killed while
/// moving them into place (no manifest; the hidden list of the files it owns,
/// `.langevin-fem-shard-publishing.json`, left behind) is rerun there too and merges to
/// the whole run; files with neither a manifest nor that list are the user's and the
/// shard is refused (exit 2, naming `--out` and the file), leaving them as they were.
/// Reference: the whole run's directory. Tolerance: as [`assert_same_run`]; exact bytes.
#[test]
fn a_shard_reruns_over_its_own_files_and_refuses_anyone_elses() {
    let tmp = TempDir::new("run-shard-rerun");
    let (w, s, m) = (tmp.join("whole"), tmp.join("shard"), tmp.join("merged"));
    whole(LINEAR, &w, &[]);
    whole(LINEAR, &s, &["--shard", "1/1"]);
    whole(LINEAR, &s, &["--shard", "1/1"]);
    let manifest = std::fs::read_to_string(s.join("shard.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    let files: Vec<String> = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["path"].as_str().unwrap().to_string())
        .collect();
    // Killed between the removal of the manifest and its rewrite.
    std::fs::remove_file(s.join("shard.json")).unwrap();
    let list = serde_json::to_string(&files).unwrap();
    std::fs::write(s.join(".langevin-fem-shard-publishing.json"), list).unwrap();
    whole(LINEAR, &s, &["--shard", "1/1"]);
    assert!(!s.join(".langevin-fem-shard-publishing.json").exists());
    let o = merge(std::slice::from_ref(&s), &m);
    assert_eq!(o.status.code(), Some(0), "merge: {}", stderr_of(&o));
    assert_same_run(&w, &m);
    // Neither a manifest nor the list: the files are somebody else's.
    std::fs::remove_file(s.join("shard.json")).unwrap();
    let mine = s.join(&files[0]);
    std::fs::write(&mine, b"my own data").unwrap();
    let args = run_args(LINEAR, &s, &["--shard", "1/1"]);
    let o = run_in(common::manifest_dir(), &args);
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--out") && err.contains(&files[0]), "{err}");
    assert_eq!(std::fs::read(&mine).unwrap(), b"my own data");
}

/// Asserts that merging `dirs` into `out` exits 2, that stderr names every string of
/// `names`, and that nothing of a run was written.
fn refused(dirs: &[PathBuf], out: &Path, names: &[&str]) {
    let o = merge(dirs, out);
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(2), "not refused: {err}");
    for n in names {
        assert!(err.contains(n), "the refusal does not name {n:?}: {err}");
    }
    assert!(
        !out.join("data.json").exists(),
        "a refused merge wrote data.json"
    );
    assert!(
        !out.join("manifest.json").exists(),
        "a refused merge started a run"
    );
}

/// Rewrites the shard manifest in `dir` with `edit`.
fn edit_manifest(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let path = dir.join("shard.json");
    let mut m = json(&path);
    edit(&mut m);
    std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

/// What: merges of `run` shards that must be refused before anything is written: a
/// missing shard; shard 2's manifest without one of its trajectories; shard 3's listing
/// a trajectory of shard 2 too; a shard run with other settings (`--trajectories`); a
/// shard of `verify` among `run` shards.
/// Reference: exit 2, the message naming the shard (its index, or its directory) and
/// what is wrong; no data.json nor manifest.json written.
#[test]
fn run_merge_refuses_missing_duplicated_and_foreign_shards() {
    let tmp = TempDir::new("run-shards-refused");
    let dirs = shards(LINEAR, &tmp.join("set"), 3, &[]);
    let out = tmp.join("out");

    refused(
        &[dirs[0].clone(), dirs[2].clone()],
        &out,
        &["missing shard 2/3"],
    );

    // 4 trajectories in 3 shards: 0 | 1 | 2, 3.
    let entry = |d: &Path, k: usize| json(&d.join("shard.json"))["files"][k].clone();
    let (of_2, last_of_3) = (entry(&dirs[1], 0), entry(&dirs[2], 1));
    assert_eq!(of_2["first"], 1, "{of_2}");
    assert_eq!(last_of_3["first"], 3, "{last_of_3}");

    edit_manifest(&dirs[2], |m| {
        m["files"].as_array_mut().unwrap().pop();
    });
    refused(
        &dirs,
        &out,
        &[
            "trajectory 3",
            "trajectory-0003.npy",
            "in no shard",
            "rerun shard 3/3",
        ],
    );
    edit_manifest(&dirs[2], |m| {
        m["files"].as_array_mut().unwrap().push(last_of_3)
    });
    let o = merge(&dirs, &out);
    assert_eq!(o.status.code(), Some(0), "restored: {}", stderr_of(&o));
    let out = tmp.join("out-2");

    // Shard 3 with a copy of shard 2's trajectory 1, listed in its manifest.
    let rel = of_2["path"].as_str().unwrap().to_string();
    std::fs::copy(dirs[1].join(&rel), dirs[2].join(&rel)).unwrap();
    edit_manifest(&dirs[2], |m| m["files"].as_array_mut().unwrap().push(of_2));
    refused(
        &dirs,
        &out,
        &["trajectory 1", "given twice", "shard 2/3", "shard 3/3"],
    );
    edit_manifest(&dirs[2], |m| {
        m["files"].as_array_mut().unwrap().pop();
    });

    let other = shards(LINEAR, &tmp.join("other"), 3, &["--trajectories", "5"]);
    refused(
        &[dirs[0].clone(), other[1].clone(), dirs[2].clone()],
        &out,
        &["settings", other[1].to_str().unwrap()],
    );

    let verify = tmp.join("verify");
    let o = common::run(&[
        "verify",
        "-q",
        "-s",
        fixture(LINEAR).to_str().unwrap(),
        "--shard",
        "2/3",
        "-o",
        verify.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    refused(
        &[dirs[0].clone(), verify, dirs[2].clone()],
        &out,
        &["command", "`verify`", "`run`"],
    );
}

/// What: `merge -o DIR` where DIR holds another command's report is refused naming
/// `--out` (the merge's own), not the shards' manifest: the shards never ran with that
/// directory. It named `shard.json`'s `settings.out` and called the manifest damaged.
/// Reference: exit 2; the message names `--out`, the directory and the report's command.
#[test]
fn merge_into_another_commands_report_names_its_own_out() {
    let tmp = TempDir::new("run-shards-out");
    let dirs = shards(LINEAR, &tmp.join("set"), 2, &[]);
    let report = tmp.join("report");
    let o = common::run(&[
        "verify",
        "-q",
        "-s",
        fixture(LINEAR).to_str().unwrap(),
        "-o",
        report.to_str().unwrap(),
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr_of(&o));
    let o = merge(&dirs, &report);
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--out") && err.contains(report.to_str().unwrap()) && err.contains("`verify`"),
        "{err}"
    );
    assert!(
        !err.contains("settings.out") && !err.contains("damaged"),
        "{err}"
    );
}

/// What: `run --shard` outside 1 ≤ I ≤ N is refused before anything runs.
/// Reference: exit 2 naming the flag and the rule; nothing written.
#[test]
fn run_shard_flag_out_of_range_is_refused() {
    let tmp = TempDir::new("run-shard-flag");
    let out = tmp.join("out");
    for bad in ["0/3", "4/3", "3", "x/y"] {
        let mut args = run_args(LINEAR, &out, &[]);
        args.extend(["--shard".to_string(), bad.to_string()]);
        let o = run_in(common::manifest_dir(), &args);
        let shown: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_eq!(o.status.code(), Some(2), "{}", describe(&shown, &o));
        let err = stderr_of(&o);
        assert!(
            err.contains("--shard") && err.contains("1 <= I <= N"),
            "{}",
            describe(&shown, &o)
        );
        assert!(!out.exists(), "a refused run wrote {}", out.display());
    }
}
