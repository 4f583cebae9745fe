//! Scenes usable from anywhere, `list`, `scene show`, `--seed` and `--threads` (issue
//! #13), through the built binary as a user runs it.
//!
//! What: the built-in scenes resolve from a directory outside the repository (no scene
//! directory); `list` and `scene show` print what they promise; `--threads` leaves every
//! CSV byte-identical and sizes the pool; `--seed` changes the results, and `--seed` equal
//! to the scene's own seed does not; the seed used is stored in every report; bad values
//! of the new flags exit 2 naming the flag and its range.
//! Reference: the guide, docs/src/reference/scenes.md; `src/scene/builtin.rs` (resolution), `src/scene/keys.rs`
//! (key documentation), `src/cli/mod.rs` (`SimArgs`).
//! Set-up: the tiny linear fixture (4 elements, under a second per run) for every run
//! that simulates; built-in scenes only where nothing is simulated (a refusal by
//! `--max-work`, `list`, `scene show`) or for the shortest study.
//! Tolerance: exact (bytes, substrings, exit codes).

mod common;

use common::{
    TempDir, all_files, assert_no_panic, assert_refused, command, describe, fixture, stdout_of,
};
use langevin_fem::scene::keys::{KEYS, key_paths, matches};
use langevin_fem::scene::{BUILTIN, Scene};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Output;

/// The small verify scene of these tests; its own seed is [`TINY_SEED`].
const TINY: &str = "tests/scenes/good/tiny-linear.toml";
/// The `seed` written in [`TINY`].
const TINY_SEED: &str = "424242";
/// Another seed, for the test that `--seed` changes the results.
const OTHER_SEED: &str = "7";

/// Runs the binary with `args` in `cwd`, asserting no panic.
fn run_in(cwd: &Path, args: &[&str]) -> Output {
    let o = command()
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("binary runs");
    assert_no_panic(args, &o);
    o
}

/// Runs `verify --scene <tiny> --out <out>` plus `extra` from the crate root; asserts
/// exit 0 or 1.
fn verify_tiny(out: &Path, extra: &[&str]) -> Output {
    let (scene, out) = (
        fixture(TINY).display().to_string(),
        out.display().to_string(),
    );
    let mut args = vec!["verify", "--scene", &scene, "--out", &out];
    args.extend(extra);
    let o = run_in(&fixture(""), &args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    o
}

/// Every CSV file under `dir` (relative path → bytes).
fn csvs(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    all_files(dir)
        .into_iter()
        .filter(|f| f.ends_with(".csv"))
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).expect("read CSV");
            (f, bytes)
        })
        .collect()
}

/// The notes of the first scene of `<out>/summary.json`.
fn notes(out: &Path) -> String {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let v: Value = serde_json::from_str(&text).expect("JSON");
    v["scenes"][0]["notes"].to_string()
}

/// What: from an empty directory outside the repository, a built-in scene resolves by
/// name with no scene directory, and messages name it as built in: `verify --scene
/// hinged-linear-2d --max-work 1` is refused by the work cap (exit 2, before anything
/// runs) naming "hinged-linear-2d (built in)" and its key; an unknown name exits 2
/// listing every built-in scene.
#[test]
fn builtin_scenes_resolve_outside_the_repository() {
    let cwd = TempDir::new("anywhere");
    let args = [
        "verify",
        "--scene",
        "hinged-linear-2d",
        "--out",
        "x",
        "--max-work",
        "1",
    ];
    let o = run_in(cwd.path(), &args);
    assert_refused(
        &o,
        &args,
        &[
            "hinged-linear-2d (built in): key `runs[0].quick`",
            "--max-work",
        ],
    );
    assert!(!cwd.join("x").exists(), "wrote output");

    let args = ["verify", "--scene", "no-such-scene", "--out", "x"];
    let o = run_in(cwd.path(), &args);
    let mut needles = vec!["--scene must be one of: ", "got no-such-scene"];
    needles.extend(BUILTIN.iter().map(|b| b.name));
    assert_refused(&o, &args, &needles);
}

/// What: a built-in scene verifies from an empty directory outside the repository (the
/// shortest study, `stability` on hinged-linear-2d at 5 elements and 1000 steps), and
/// its summary stores the seed given by `--seed`.
#[test]
fn a_study_of_a_builtin_scene_runs_anywhere_and_stores_the_seed() {
    let cwd = TempDir::new("anywhere-study");
    let args = [
        "stability",
        "--scene",
        "hinged-linear-2d",
        "--elements",
        "5",
        "--dt-lambda-max",
        "0.1",
        "--steps",
        "1000",
        "--burn-in",
        "0",
        "--trajectories",
        "2",
        "--seed",
        OTHER_SEED,
        "--out",
        "st",
    ];
    let o = run_in(cwd.path(), &args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let text = std::fs::read_to_string(cwd.join("st/stability.json")).expect("stability.json");
    let v: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(v["seed"].to_string(), OTHER_SEED, "{text}");
    // The map and its seed are results: stdout (#14).
    assert!(stdout_of(&o).contains(&format!("seed {OTHER_SEED}")));
}

/// What: `list` from an empty directory prints a header and one line per built-in scene
/// in the table's order (name, source, model and dims, elements, runs, description);
/// `--json` gives the same scenes as objects; with `--scene-dir` the directory's files
/// follow the built-in ones, and an invalid file there is listed, named on stderr, and
/// makes the exit code 2.
#[test]
fn list_prints_every_scene() {
    let cwd = TempDir::new("list");
    let o = run_in(cwd.path(), &["list"]);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&["list"], &o));
    let out = stdout_of(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert!(lines[0].starts_with("NAME "), "{out}");
    assert_eq!(lines.len(), BUILTIN.len() + 1, "{out}");
    for (line, b) in lines[1..].iter().zip(BUILTIN) {
        assert!(line.starts_with(&format!("{} ", b.name)), "{line}");
    }
    let line = lines
        .iter()
        .find(|l| l.starts_with("hinged-1000-2d "))
        .unwrap();
    for field in [
        "built-in (extreme)",
        "fem 2D",
        "1000",
        "Hinged filament with 1000",
    ] {
        assert!(line.contains(field), "{field:?} not in {line:?}");
    }
    // Aligned: the description starts in the same column on every line.
    let col = |l: &str| l.find("Hinged").or_else(|| l.find("Compress"));
    let first = lines[1..].iter().find_map(|l| col(l)).unwrap();
    for l in &lines[1..] {
        if let Some(c) = col(l) {
            assert_eq!(c, first, "{out}");
        }
    }

    let o = run_in(cwd.path(), &["list", "--json"]);
    let v: Value = serde_json::from_str(&stdout_of(&o)).expect("JSON");
    let names: Vec<&str> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    let expected: Vec<&str> = BUILTIN.iter().map(|b| b.name).collect();
    assert_eq!(names, expected);
    let c2d = names.iter().position(|n| *n == "compression-2d").unwrap();
    assert_eq!(v[c2d]["model"], "compression");
    assert_eq!(v[c2d]["runs"].as_array().unwrap().len(), 2);

    let dir = TempDir::new("list-dir");
    std::fs::copy(fixture(TINY), dir.join("tiny-linear.toml")).unwrap();
    std::fs::write(dir.join("broken.toml"), "seed = \"x\"\n").unwrap();
    let d = dir.path().display().to_string();
    let args = ["list", "--scene-dir", &d];
    let o = run_in(cwd.path(), &args);
    assert_refused(&o, &args, &["broken.toml"]);
    let out = stdout_of(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), BUILTIN.len() + 3, "{out}");
    assert!(lines[BUILTIN.len() + 1].starts_with("broken "), "{out}");
    assert!(
        lines[BUILTIN.len() + 2].starts_with("tiny-linear "),
        "{out}"
    );
    assert!(lines[BUILTIN.len() + 2].contains("fem 2D"), "{out}");
}

/// What: `scene show NAME` prints the scene as it will run, and every key it uses with
/// its row of the key table; the output as a whole (the documentation is TOML comments)
/// reads back as the same scene. `--as-written` prints the file with its comments. An
/// unknown name exits 2 listing the names; a path works too.
#[test]
fn scene_show_prints_the_scene_and_documents_its_keys() {
    let cwd = TempDir::new("show");
    for b in BUILTIN {
        let args = ["scene", "show", b.name];
        let o = run_in(cwd.path(), &args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let out = stdout_of(&o);
        assert!(
            out.starts_with(&format!("# {} (built in), as it will run", b.name)),
            "{out}"
        );
        let shown = Scene::parse_named(&out, Path::new("shown"), b.name)
            .unwrap_or_else(|e| panic!("{}: {e}\n{out}", b.name));
        let builtin = b.load().unwrap();
        assert_eq!(
            toml::to_string(&shown).unwrap(),
            toml::to_string(&builtin).unwrap()
        );
        let value: toml::Value = out.parse::<toml::Table>().map(toml::Value::Table).unwrap();
        for key in key_paths(&value) {
            let row = KEYS.iter().find(|d| matches(d.key, &key)).unwrap();
            let line = format!(
                "# {}  [{}]  {}; default: {}",
                row.key, row.unit, row.range, row.default
            );
            assert!(out.contains(&line), "{}: no line {line:?}", b.name);
            assert!(out.contains(row.meaning), "{}: {}", b.name, row.meaning);
        }
    }
    let args = ["scene", "show", "hinged-linear-2d", "--as-written"];
    let o = run_in(cwd.path(), &args);
    let out = stdout_of(&o);
    let text = BUILTIN
        .iter()
        .find(|b| b.name == "hinged-linear-2d")
        .unwrap()
        .text;
    assert!(out.contains(text), "{}", describe(&args, &o));

    let tiny = fixture(TINY).display().to_string();
    let args = ["scene", "show", &tiny];
    let o = run_in(cwd.path(), &args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    assert!(stdout_of(&o).starts_with(&format!("# {tiny}, as it will run")));

    let args = ["scene", "show", "nope"];
    let o = run_in(cwd.path(), &args);
    assert_refused(
        &o,
        &args,
        &["--scene must be one of: ", "hinged-linear-2d", "got nope"],
    );
}

/// What: `--threads 1` and `--threads 2` give byte-identical CSV files (same set, same
/// bytes) and identical notes; and `--threads` sizes the pool (work-precision records
/// the pool's size).
/// Reference: the guide, docs/src/reference/reproducibility.md (one stream per trajectory).
#[test]
fn thread_count_changes_no_byte() {
    let (a, b) = (TempDir::new("t1"), TempDir::new("t2"));
    verify_tiny(a.path(), &["--threads", "1"]);
    verify_tiny(b.path(), &["--threads", "2"]);
    let (ca, cb) = (csvs(a.path()), csvs(b.path()));
    assert!(!ca.is_empty(), "no CSV written");
    assert_eq!(ca.keys().collect::<Vec<_>>(), cb.keys().collect::<Vec<_>>());
    for (path, bytes) in &ca {
        assert!(bytes == &cb[path], "{path} differs between 1 and 2 threads");
    }
    assert_eq!(notes(a.path()), notes(b.path()));

    for threads in ["1", "2"] {
        let out = TempDir::new("wp");
        let o_s = out.join_str("wp");
        let args = [
            "work-precision",
            "--methods",
            "crank-nicolson/consistent",
            "--dt-tau1",
            "1e-2",
            "--trajectories",
            "2",
            "--duration",
            "20",
            "--threads",
            threads,
            "--out",
            &o_s,
        ];
        let o = run_in(&fixture(""), &args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let text = std::fs::read_to_string(out.join("wp/work-precision.json")).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["threads"].to_string(), threads, "{text}");
    }
}

/// What: `--seed <the scene's own seed>` gives the same CSV bytes as no `--seed`; another
/// seed changes them; each report notes the seed used.
#[test]
fn seed_flag_replaces_the_scene_seed() {
    let (own, same, other) = (
        TempDir::new("own"),
        TempDir::new("same"),
        TempDir::new("other"),
    );
    verify_tiny(own.path(), &[]);
    verify_tiny(same.path(), &["--seed", TINY_SEED]);
    verify_tiny(other.path(), &["--seed", OTHER_SEED]);
    let (c_own, c_same, c_other) = (csvs(own.path()), csvs(same.path()), csvs(other.path()));
    assert!(!c_own.is_empty());
    assert_eq!(
        c_own, c_same,
        "--seed {TINY_SEED} (the scene's own) changed the CSVs"
    );
    assert_eq!(
        c_own.keys().collect::<Vec<_>>(),
        c_other.keys().collect::<Vec<_>>()
    );
    let changed = c_own.iter().filter(|(k, v)| c_other[*k] != **v).count();
    assert!(changed > 0, "--seed {OTHER_SEED} changed no CSV");
    assert!(notes(own.path()).contains(&format!("seed {TINY_SEED} (the scene's own)")));
    assert!(notes(other.path()).contains(&format!(
        "seed {OTHER_SEED} (--seed; the scene's own seed is {TINY_SEED})"
    )));

    // converge stores the seed in its summary.
    let out = TempDir::new("cv");
    let (scene, o_s) = (fixture(TINY).display().to_string(), out.join_str("cv"));
    let args = [
        "converge",
        "--scene",
        &scene,
        "--over",
        "dt",
        "--values",
        "0.02,0.01",
        "--trajectories",
        "2",
        "--duration-tau1",
        "16",
        "--seed",
        OTHER_SEED,
        "--out",
        &o_s,
    ];
    let o = run_in(&fixture(""), &args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let text = std::fs::read_to_string(out.join("cv/tiny-linear-crank-nicolson-dt.json")).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["seed"].to_string(), OTHER_SEED);
}

/// What: `--threads` outside [1, 256] and `--seed` outside the u64 range (or not a whole
/// number) exit 2 naming the flag and its range, on every simulating command.
#[test]
fn bad_seed_and_threads_name_the_flag_and_range() {
    let cwd = TempDir::new("bad-flags");
    let commands: [&[&str]; 4] = [
        &["verify"],
        &["converge", "--scene", "hinged-linear-2d", "--over", "dt"],
        &["stability"],
        &["work-precision"],
    ];
    for command in commands {
        for (flag, value, range) in [
            ("--threads", "0", "[1, 256]"),
            ("--threads", "257", "[1, 256]"),
            ("--threads", "two", "[1, 256]"),
            ("--seed", "-1", "[0, 18446744073709551615]"),
            (
                "--seed",
                "18446744073709551616",
                "[0, 18446744073709551615]",
            ),
            ("--seed", "1.5", "[0, 18446744073709551615]"),
        ] {
            let mut args = command.to_vec();
            args.extend([flag, value, "--out", "x"]);
            let o = run_in(cwd.path(), &args);
            let named = format!("invalid value '{value}' for '{flag} <N>'");
            assert_refused(&o, &args, &[&named, range]);
        }
    }
    assert!(!cwd.join("x").exists());
}
