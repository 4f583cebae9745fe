//! Provenance and units of every output, through the built binary (issue #13, Deliver 3
//! and 5).
//!
//! What: (1) `--version` prints the version and the commit the binary was built from.
//! (2) A small `verify` (the tiny fixture and the physical-units scene
//! `verification/actin-10um.toml`) writes into `manifest.json` a provenance whose every
//! field is present and right: tool, version, commit (= `git rev-parse HEAD` of the
//! repository when the test runs in it), dirty flag, command line (the arguments given),
//! start time (RFC 3339 UTC, within the test's run), wall time, thread count (=
//! `RAYON_NUM_THREADS`), and per scene its source path, full text (= the file), SHA-256
//! (= SHA-256 of the file's bytes), seed, overrides (none), and the parameters with
//! units and dimensionless groups (the actin scene: the keys as written, the converted
//! µm–s–pN values, ℓp/L = 1.7); `summary.json` references the journal and repeats
//! version, commit and seeds; `index.html` shows commit, command line, thread count and
//! each scene's seed, source and hash. (3) Small studies (`stability`, `work-precision`,
//! `converge` over elements and over dt) record the same in their journals and summaries.
//! (4) Every column of every CSV file those commands write has a unit in the column
//! dictionary, recorded per file in the journal, and the recorded columns are the file's
//! header.
//! Reference: the guide, docs/src/reference/reports.md ("The report directory", "Provenance"); `src/output/provenance.rs`,
//! `src/output/columns.rs`, `src/params/physical.rs`.
//! Set-up: quick budget of 4- and 8-element scenes; studies scaled down to well under a
//! second each.
//! Tolerance: exact (strings, hashes, seeds), except the time stamps: the start time lies
//! between the test's own clock readings (to the second) and the wall time is positive
//! and below the test's elapsed time.

mod common;

use common::{TempDir, command, describe, fixture, json, manifest_dir, strings};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::path::Path;
use std::process::Output;
use std::time::{Duration, SystemTime};

/// The thread count the runs are given (`RAYON_NUM_THREADS`), checked in the provenance.
const THREADS: &str = "2";

/// The tiny linear fixture.
const TINY: &str = "tests/scenes/good/tiny-linear.toml";
/// The physical-units scene.
const ACTIN: &str = "verification/actin-10um.toml";

/// `git rev-parse HEAD` of the crate's repository, if git runs and the crate is one.
fn git_head() -> Option<String> {
    let o = std::process::Command::new("git")
        .args(["rev-parse", "--show-toplevel", "HEAD"])
        .current_dir(manifest_dir())
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let mut lines = text.lines();
    let top = lines.next()?;
    let same = Path::new(top).canonicalize().ok()? == manifest_dir().canonicalize().ok()?;
    (o.status.success() && same).then(|| lines.next().unwrap_or("").to_string())
}

/// The commit the binary must report: HEAD, or `unknown` outside a git checkout.
fn expected_commit() -> String {
    git_head().unwrap_or_else(|| "unknown".to_string())
}

/// Runs the binary with `args` and `RAYON_NUM_THREADS` = [`THREADS`]; asserts exit 0.
fn run_ok(args: &[&str]) -> Output {
    let o = command()
        .env("RAYON_NUM_THREADS", THREADS)
        .args(args)
        .output()
        .expect("run the binary");
    assert_eq!(o.status.code(), Some(0), "{}", describe(args, &o));
    o
}

/// SHA-256 of a file's bytes, lowercase hex.
fn sha256_of(path: &Path) -> String {
    let bytes = std::fs::read(path).expect("read scene");
    Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The seed line `seed = N` of a scene file.
fn seed_of(path: &Path) -> u64 {
    let text = std::fs::read_to_string(path).expect("read scene");
    text.lines()
        .find_map(|l| l.strip_prefix("seed = "))
        .and_then(|s| s.trim().parse().ok())
        .expect("seed line")
}

/// Checks the provenance record `p` of a run of `args` started at `t0` and finished
/// `elapsed` later, whose scenes are the files `scenes` (crate-relative paths as given
/// on the command line).
fn check_provenance(p: &Value, args: &[&str], t0: SystemTime, elapsed: Duration, scenes: &[&str]) {
    assert_eq!(p["tool"], "langevin-fem");
    assert_eq!(p["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(p["commit"], expected_commit().as_str());
    assert!(
        p["dirty"].is_boolean() || (p["dirty"].is_null() && p["commit"] == "unknown"),
        "{p}"
    );
    let line = strings(&p["command_line"]);
    assert_eq!(
        line[1..],
        args.iter().map(|s| s.to_string()).collect::<Vec<_>>()[..]
    );
    assert!(line[0].ends_with("langevin-fem"), "{line:?}");
    let started = p["started"].as_str().expect("started");
    let t = humantime::parse_rfc3339(started).expect("RFC 3339");
    assert!(started.ends_with('Z'), "UTC: {started}");
    let t0_s = t0
        - Duration::from_nanos(u64::from(
            t0.duration_since(SystemTime::UNIX_EPOCH)
                .unwrap()
                .subsec_nanos(),
        ));
    assert!(t >= t0_s && t <= t0 + elapsed, "{started} outside the run");
    let wall = p["wall_seconds"].as_f64().expect("wall time");
    assert!(wall > 0.0 && wall <= elapsed.as_secs_f64(), "{wall}");
    assert_eq!(p["threads"].as_u64(), Some(THREADS.parse().unwrap()));
    let recorded = p["scenes"].as_array().expect("scenes");
    assert_eq!(recorded.len(), scenes.len());
    for (s, rel) in recorded.iter().zip(scenes) {
        let path = fixture(rel);
        assert_eq!(s["source"], *rel, "the path as given");
        assert_eq!(s["text"], std::fs::read_to_string(&path).unwrap().as_str());
        assert_eq!(s["sha256"], sha256_of(&path).as_str());
        assert_eq!(s["seed"].as_u64(), Some(seed_of(&path)));
        assert_eq!(s["overrides"], serde_json::json!([]));
        assert_eq!(s["name"], path.file_stem().unwrap().to_str().unwrap());
        for key in [
            "length",
            "bending_rigidity",
            "stretch_rigidity",
            "drag",
            "kt",
        ] {
            let q = &s["parameters"]["parameters"][key];
            assert!(q["value"].as_f64().is_some_and(|v| v > 0.0), "{key}: {q}");
            assert!(!q["unit"].as_str().unwrap_or("").is_empty(), "{key}: {q}");
        }
        for key in ["persistence_ratio", "stretch_ratio", "tau1", "euler_load"] {
            assert!(s["parameters"]["groups"][key]["value"].is_f64(), "{key}");
        }
        assert!(s["elements"].as_u64().is_some_and(|e| e > 0));
    }
}

/// Checks an entry point's provenance reference `r` against the journal's record `p`.
fn check_reference(r: &Value, p: &Value, journal: &str) {
    assert_eq!(r["manifest"], journal);
    for key in [
        "version",
        "commit",
        "dirty",
        "started",
        "command_line",
        "threads",
    ] {
        assert_eq!(r[key], p[key], "{key}");
    }
    let scenes = r["scenes"].as_array().expect("scenes");
    assert_eq!(scenes.len(), p["scenes"].as_array().unwrap().len());
    for (a, b) in scenes.iter().zip(p["scenes"].as_array().unwrap()) {
        for key in ["name", "source", "sha256", "seed", "overrides"] {
            assert_eq!(a[key], b[key], "{key}");
        }
    }
}

/// Every CSV file the journal `m` names has its columns recorded, each with a unit from
/// the dictionary, in the order of the file's header; returns how many CSV files.
fn check_columns(dir: &Path, m: &Value) -> usize {
    let files = strings(&m["files"]);
    let csvs: Vec<&String> = files.iter().filter(|f| f.ends_with(".csv")).collect();
    for f in &csvs {
        let text = std::fs::read_to_string(dir.join(f)).expect("read csv");
        let header: Vec<&str> = text.lines().next().unwrap_or("").split(',').collect();
        let schema = &m["columns"][f.as_str()];
        assert!(
            schema["table"].is_string(),
            "{f}: no table kind in the dictionary"
        );
        let columns = schema["columns"]
            .as_array()
            .unwrap_or_else(|| panic!("{f}: no schema"));
        let names: Vec<&str> = columns
            .iter()
            .map(|c| c["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, header, "{f}");
        for c in columns {
            assert!(
                c["unit"].as_str().is_some_and(|u| !u.is_empty()),
                "{f}: column {} is not in the column dictionary",
                c["name"]
            );
        }
    }
    assert_eq!(
        m["columns"].as_object().map_or(0, |o| o.len()),
        csvs.len(),
        "a schema per CSV file, no more"
    );
    csvs.len()
}

#[test]
fn version_prints_version_and_commit() {
    let o = run_ok(&["--version"]);
    let out = String::from_utf8_lossy(&o.stdout);
    let commit = expected_commit();
    let short: String = commit.chars().take(12).collect();
    assert!(
        out.starts_with(&format!(
            "langevin-fem {} (commit {short}",
            env!("CARGO_PKG_VERSION")
        )),
        "{out}"
    );
}

/// A verify of the tiny fixture and the physical-units scene: manifest, summary and
/// index carry the provenance; the actin scene's parameters are converted and reported
/// with their units; every CSV column has its unit.
#[test]
fn verify_records_provenance_units_and_columns() {
    let dir = TempDir::new("provenance-verify");
    let out = dir.join_str("out");
    let args = ["verify", "--scene", TINY, "--scene", ACTIN, "--out", &out];
    let t0 = SystemTime::now();
    let o = command()
        .env("RAYON_NUM_THREADS", THREADS)
        .args(args)
        .output()
        .expect("run");
    let elapsed = t0.elapsed().unwrap();
    // The tiny fixture's statistics are thin: 0 or 1, never an error.
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    let out = dir.join("out");
    let m = json(&out.join("manifest.json"));
    let p = &m["provenance"];
    check_provenance(p, &args, t0, elapsed, &[TINY, ACTIN]);

    // The actin scene: the keys as written, converted values in µm, s, pN, the groups.
    let actin = &p["scenes"][1]["parameters"];
    assert_eq!(actin["unit_system"], "physical");
    assert_eq!(actin["given"]["persistence_length_um"]["value"], 17.0);
    assert_eq!(actin["given"]["persistence_length_um"]["unit"], "µm");
    assert_eq!(actin["given"]["temperature_k"]["unit"], "K");
    let ei = &actin["parameters"]["bending_rigidity"];
    assert_eq!(ei["unit"], "pN·µm²");
    // EI = lp kT = 17 µm × 1.380649e-5 pN·µm/K × 300 K.
    let expected_ei = 17.0 * 1.380649e-5 * 300.0;
    assert!((ei["value"].as_f64().unwrap() - expected_ei).abs() < 1e-12 * expected_ei);
    let g = &actin["groups"];
    assert!((g["persistence_ratio"]["value"].as_f64().unwrap() - 1.7).abs() < 1e-12);
    assert_eq!(g["tau1"]["unit"], "s");
    assert_eq!(p["scenes"][1]["units"]["[T]"], "s");
    assert_eq!(p["scenes"][0]["parameters"]["unit_system"], "consistent");
    assert_eq!(
        p["scenes"][0]["units"]["[T]"]
            .as_str()
            .map(|s| s.contains("time unit")),
        Some(true)
    );

    // summary.json: the reference with version, commit and seeds in clear.
    let summary = json(&out.join("summary.json"));
    check_reference(&summary["provenance"], p, "manifest.json");
    assert_eq!(
        summary["provenance"]["scenes"][1]["seed"].as_u64(),
        Some(seed_of(&fixture(ACTIN)))
    );
    let actin_notes = strings(&summary["scenes"][1]["notes"]);
    assert!(
        actin_notes
            .iter()
            .any(|n| n.contains("physical units") && n.contains("lp/L = 1.700")),
        "{actin_notes:?}"
    );

    // index.html: the provenance box.
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("id=\"provenance\""));
    assert!(html.contains(&format!("<code id=\"commit\">{}</code>", expected_commit())));
    assert!(html.contains(&format!("<td class=\"num\">{THREADS}</td>")));
    assert!(html.contains("verify --scene tests/scenes/good/tiny-linear.toml"));
    for rel in [TINY, ACTIN] {
        let path = fixture(rel);
        assert!(html.contains(&sha256_of(&path)), "{rel}: hash");
        assert!(
            html.contains(&format!("<td class=\"num\">{}</td>", seed_of(&path))),
            "{rel}: seed"
        );
        assert!(
            html.contains(&format!("<code>{rel}</code>")),
            "{rel}: source"
        );
    }
    assert!(html.contains("<a href=\"manifest.json\">manifest.json</a>"));

    let n = check_columns(&out, &m);
    assert!(n >= 8, "{n} CSV files");
}

/// The studies record the same: a provenance in each journal, a reference in each
/// summary, and every CSV column with its unit.
#[test]
fn studies_record_provenance_and_columns() {
    let dir = TempDir::new("provenance-studies");
    let out = dir.join_str("out");
    let scene = "verification/hinged-linear-2d.toml";
    let runs: [(&str, Vec<&str>); 4] = [
        (
            "stability",
            vec![
                "stability",
                "--scene",
                scene,
                "--elements",
                "6",
                "--dt-lambda-max",
                "0.5,2.5",
                "--steps",
                "4000",
                "--out",
                &out,
            ],
        ),
        (
            "work-precision",
            vec![
                "work-precision",
                "--scene",
                scene,
                "--methods",
                "crank-nicolson/consistent",
                "--dt-tau1",
                "1e-2",
                "--trajectories",
                "2",
                "--duration",
                "40",
                "--out",
                &out,
            ],
        ),
        (
            "hinged-linear-2d-crank-nicolson-elements",
            vec![
                "converge",
                "--scene",
                scene,
                "--run",
                "crank-nicolson",
                "--over",
                "elements",
                "--values",
                "4,8",
                "--trajectories",
                "4",
                "--duration-tau1",
                "40",
                "--out",
                &out,
            ],
        ),
        (
            "hinged-linear-2d-crank-nicolson-dt",
            vec![
                "converge",
                "--scene",
                scene,
                "--run",
                "crank-nicolson",
                "--over",
                "dt",
                "--values",
                "0.02,0.01",
                "--trajectories",
                "4",
                "--duration-tau1",
                "40",
                "--out",
                &out,
            ],
        ),
    ];
    let out = dir.join("out");
    let mut csvs = 0;
    for (stem, args) in &runs {
        let t0 = SystemTime::now();
        run_ok(args);
        let elapsed = t0.elapsed().unwrap();
        let journal = format!("{stem}.manifest.json");
        let m = json(&out.join(&journal));
        assert_eq!(m["complete"], true, "{stem}");
        check_provenance(&m["provenance"], args, t0, elapsed, &[scene]);
        let summary = json(&out.join(format!("{stem}.json")));
        check_reference(&summary["provenance"], &m["provenance"], &journal);
        assert_eq!(summary["run_id"], m["run_id"]);
        csvs += check_columns(&out, &m);
    }
    assert!(csvs >= 5, "{csvs} CSV files");
}

/// A scene changed after parsing (a seed from the command line, another integrator)
/// records each change as an override, with the value in the file; the text and its hash
/// stay those of the file.
#[test]
fn overrides_name_each_change_and_the_file_value() {
    use langevin_fem::output::DescribeScene;
    let mut scene = common::scene(TINY);
    assert!(scene.describe().overrides.is_empty());
    scene.seed = 7;
    scene.runs[0].integrator = langevin_fem::dynamics::IntegratorKind::BackwardEuler;
    let d = scene.describe();
    assert_eq!(
        d.overrides,
        [
            "runs[0].integrator = \"backward-euler\" (file: \"crank-nicolson\")",
            "seed = 7 (file: 424242)"
        ]
    );
    assert_eq!(d.seed, 7);
    assert_eq!(d.sha256, sha256_of(&fixture(TINY)));
}
