//! `langevin-fem calibrate` end to end (issue #16, deliverable 1).
//!
//! What: the command writes its report (`calibration.json`, `p-values.csv`, one
//! `<scene>-p-values.svg` per scene, `index.html`, the journal) under `--out` and nothing
//! else; `p-values.csv` has one row per check per seed and each seed's rows are exactly
//! what `verify --scene NAME --seed <seed>` reports; the summary's false-alarm counts
//! agree with the rows; bad input exits 2 before anything runs, the work cap applying to
//! the N seeds together.
//!
//! Reference: the guide, docs/src/reference/statistics.md ("Calibration of the verifier"); `src/cli/calibrate.rs` (seed k = first + k, each an
//! in-process `verify` of one scene); the statistics are unit-tested against R's
//! `binom.test` and known laws in `src/verify/calibrate.rs`.
//!
//! Set-up: the built-in `actin-10um` scene (8 elements, about 0.3 s per verification at
//! the quick budget), 5 seeds from [`FIRST_SEED`]. Tolerance: exact — the p-values are
//! compared bit for bit (CSV and JSON both carry round-trip precision).

mod common;

use common::{TempDir, all_files, assert_no_panic, describe, run, stderr_of};
use langevin_fem::scene::Budget;
use langevin_fem::verify::calibrate::CalibrationSummary;
use serde_json::Value;
use std::collections::BTreeSet;

/// The first seed of the calibration under test.
const FIRST_SEED: u64 = 1_600_000;
/// Seeds of the calibration under test.
const SEEDS: u64 = 5;
/// The seed whose rows are compared with a plain `verify` run (k = 2).
const COMPARED_SEED: u64 = FIRST_SEED + 2;
/// The scene calibrated.
const SCENE: &str = "actin-10um";

/// One row of `p-values.csv`.
struct Row {
    scene: String,
    seed: u64,
    check: String,
    kind: String,
    p_value: Option<f64>,
    p_adjusted: Option<f64>,
    passed: bool,
}

/// The fields of one CSV line (RFC 4180: fields with commas or quotes are quoted, a
/// quote inside doubled); check names such as `two-time/x=5.000,y=5.000,...` are quoted.
fn split_csv(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

fn parse_rows(text: &str) -> Vec<Row> {
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("scene,seed,check,kind,p_value,p_adjusted,passed")
    );
    let opt = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().expect("a number"));
    lines
        .map(|l| {
            let f = split_csv(l);
            assert_eq!(f.len(), 7, "{l}");
            Row {
                scene: f[0].clone(),
                seed: f[1].parse().expect("seed"),
                check: f[2].clone(),
                kind: f[3].clone(),
                p_value: opt(&f[4]),
                p_adjusted: opt(&f[5]),
                passed: match f[6].as_str() {
                    "true" => true,
                    "false" => false,
                    other => panic!("passed = {other}"),
                },
            }
        })
        .collect()
}

/// What: the report's files, their contents and the seed-for-seed identity with
/// `verify --seed`.
#[test]
fn calibrate_writes_its_report_and_each_seed_is_a_plain_verify() {
    let dir = TempDir::new("calibrate");
    let out = dir.join_str("cal");
    let first = FIRST_SEED.to_string();
    let seeds = SEEDS.to_string();
    let args = [
        "calibrate",
        "--scene",
        SCENE,
        "--seeds",
        &seeds,
        "--first-seed",
        &first,
        "--out",
        &out,
    ];
    let o = run(&args);
    assert_no_panic(&args, &o);
    let code = o.status.code();
    assert!(matches!(code, Some(0 | 1)), "{}", describe(&args, &o));

    // calibration.json parses as the library's summary; its files are exactly the
    // directory's (no scratch directory left behind).
    let text = std::fs::read_to_string(dir.join("cal/calibration.json")).expect("json");
    let summary: CalibrationSummary = serde_json::from_str(&text).expect("summary parses");
    assert_eq!(code, Some(if summary.passed { 0 } else { 1 }));
    let on_disk = all_files(&dir.join("cal"));
    assert_eq!(on_disk, summary.files, "files on disk against the summary");
    for f in [
        "calibration.json",
        "p-values.csv",
        "index.html",
        "manifest.json",
        "actin-10um-p-values.svg",
    ] {
        assert!(on_disk.iter().any(|x| x == f), "{f} missing: {on_disk:?}");
    }
    let expected_seeds: Vec<u64> = (0..SEEDS).map(|k| FIRST_SEED + k).collect();
    assert_eq!(summary.seeds.seeds, expected_seeds);
    assert_eq!(summary.scenes.len(), 1);
    let scene = &summary.scenes[0];
    assert_eq!(scene.name, SCENE);
    assert_eq!(scene.false_alarms.seeds, SEEDS);
    assert!(!summary.kinds.is_empty());
    let svg = std::fs::read_to_string(dir.join("cal/actin-10um-p-values.svg")).expect("svg");
    assert!(svg.starts_with("<svg") && svg.contains("uniform expectation"));

    // p-values.csv: N x checks rows, every seed, every check once per seed.
    let rows = parse_rows(&std::fs::read_to_string(dir.join("cal/p-values.csv")).expect("csv"));
    assert_eq!(
        scene.checks_per_seed.len(),
        1,
        "{:?}",
        scene.checks_per_seed
    );
    let per_seed = scene.checks_per_seed[0];
    assert!(per_seed > 10);
    assert_eq!(
        rows.len() as u64,
        (SEEDS - scene.false_alarms.run_failures) * per_seed as u64
    );
    assert!(rows.iter().all(|r| r.scene == SCENE));
    let seen: BTreeSet<u64> = rows.iter().map(|r| r.seed).collect();
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), expected_seeds);
    for r in &rows {
        for p in [r.p_value, r.p_adjusted].into_iter().flatten() {
            assert!((0.0..=1.0).contains(&p), "{}: {p}", r.check);
        }
    }
    // The failed seeds of the summary are those with a failed row.
    let failed_rows: BTreeSet<u64> = rows.iter().filter(|r| !r.passed).map(|r| r.seed).collect();
    let failed_summary: BTreeSet<u64> = scene
        .failed_seeds
        .iter()
        .filter(|f| f.run_failure.is_none())
        .map(|f| f.seed)
        .collect();
    assert_eq!(failed_rows, failed_summary);
    assert_eq!(scene.false_alarms.failed, scene.failed_seeds.len() as u64);

    // One seed against a plain verify at that seed: the same checks, bit for bit.
    let vout = dir.join_str("verify");
    let seed = COMPARED_SEED.to_string();
    let vargs = ["verify", "--scene", SCENE, "--seed", &seed, "--out", &vout];
    let vo = run(&vargs);
    assert!(
        matches!(vo.status.code(), Some(0 | 1)),
        "{}",
        describe(&vargs, &vo)
    );
    let v: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("verify/summary.json")).expect("summary.json"),
    )
    .expect("summary parses");
    let checks = v["scenes"][0]["checks"].as_array().expect("checks");
    let mine: Vec<&Row> = rows.iter().filter(|r| r.seed == COMPARED_SEED).collect();
    assert_eq!(mine.len(), checks.len());
    for (r, c) in mine.iter().zip(checks) {
        assert_eq!(r.check, c["name"].as_str().unwrap());
        assert_eq!(r.kind, c["kind"].as_str().unwrap());
        assert_eq!(r.p_value, c["p_value"].as_f64(), "{}", r.check);
        assert_eq!(r.p_adjusted, c["p_adjusted"].as_f64(), "{}", r.check);
        assert_eq!(r.passed, c["passed"].as_bool().unwrap(), "{}", r.check);
    }
}

/// What: bad input exits 2 naming the flag or the scene, and writes nothing.
#[test]
fn bad_input_exits_2_before_anything_runs() {
    let dir = TempDir::new("calibrate-bad");
    let out = dir.join_str("cal");
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["--scene", SCENE, "--seeds", "0"],
            &["--seeds", "[2, 100000]"],
        ),
        (&["--scene", SCENE, "--seeds", "-3"], &["--seeds"]),
        (&["--scene", SCENE], &["--seeds"]),
        (
            &["--scene", "no-such-scene", "--seeds", "5"],
            &["no-such-scene"],
        ),
        (
            &[
                "--scene",
                SCENE,
                "--seeds",
                "3",
                "--first-seed",
                "18446744073709551614",
            ],
            &[
                "--first-seed",
                "18446744073709551614",
                "at most 18446744073709551613",
            ],
        ),
        (
            &["--scene", SCENE, "--seeds", "5", "--alpha", "0.6"],
            &["--alpha", "0.6"],
        ),
    ];
    for (tail, needles) in cases {
        let mut args = vec!["calibrate", "--out", &out];
        args.extend_from_slice(tail);
        let o = run(&args);
        assert_no_panic(&args, &o);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        for n in *needles {
            assert!(err.contains(n), "{n} not in: {}", describe(&args, &o));
        }
        assert!(!dir.join("cal").exists(), "{}", describe(&args, &o));
    }
}

/// What: the work cap applies to the N seeds together: a cap of three verifications
/// admits 2 seeds and refuses 5, naming `--seeds`.
#[test]
fn the_work_cap_applies_to_all_seeds_together() {
    let scene = common::verification_scene(SCENE);
    let one = langevin_fem::verify::projected_work(&[scene], Budget::Quick).dof_steps();
    let cap = format!("{:e}", 3.0 * one);
    let dir = TempDir::new("calibrate-cap");
    let out = dir.join_str("cal");
    let args = [
        "calibrate",
        "--scene",
        SCENE,
        "--seeds",
        "5",
        "--max-work",
        &cap,
        "--out",
        &out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    assert!(
        err.contains("--seeds 5") && err.contains("--max-work"),
        "{err}"
    );
    assert!(!dir.join("cal").exists());
    let args = [
        "calibrate",
        "--scene",
        SCENE,
        "--seeds",
        "2",
        "--max-work",
        &cap,
        "--out",
        &out,
    ];
    let o = run(&args);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
}
