//! `run` and `check`: the round trip of the project's own output, a bias injected into
//! the data that `check` must find, and data directories that are the user's mistake
//! (exit 2 naming the sidecar key or the file). The independent NumPy simulator is
//! checked by `make example-check` (part of `make test`).

mod common;

use common::{TempDir, all_files, assert_refused, describe, fixture, json, run, stderr_of};
use std::path::Path;

/// `run` of the Crank–Nicolson run of hinged-linear-2d (8 trajectories × 40 τ1, a row
/// every 10 steps: 4501 rows of 19 columns), into `out`, in `format`.
fn simulate(out: &str, format: &str) {
    let args = [
        "run",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "crank-nicolson",
        "--trajectories",
        "8",
        "--duration-tau1",
        "40",
        "--every",
        "10",
        "--format",
        format,
        "--out",
        out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
}

fn check(data: &str, out: &str) -> (std::process::Output, Vec<&'static str>) {
    on_data("check", data, out)
}

/// `langevin-fem COMMAND --scene hinged-linear-2d --data DATA --out OUT` (`check` or
/// `fit`): its output and arguments.
fn on_data(command: &str, data: &str, out: &str) -> (std::process::Output, Vec<&'static str>) {
    let args: Vec<&'static str> = [
        command,
        "--scene",
        "hinged-linear-2d",
        "--data",
        data,
        "--out",
        out,
    ]
    .iter()
    .map(|s| &*Box::leak(s.to_string().into_boxed_str()))
    .collect();
    (run(&args), args)
}

/// The checks of a report: (name, passed).
fn checks(report: &Path) -> Vec<(String, bool)> {
    let s = json(&report.join("summary.json"));
    s["scenes"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["name"].as_str().unwrap().to_string(),
                c["passed"].as_bool().unwrap(),
            )
        })
        .collect()
}

/// The project's own output passes its own checks in both formats, with the references
/// of its own discretization, and every check kind of the scene is evaluated.
#[test]
fn own_output_round_trips_in_both_formats() {
    let dir = TempDir::new("run-check");
    for format in ["npy", "csv"] {
        let data = dir.join_str(&format!("data-{format}"));
        simulate(&data, format);
        let side = json(&Path::new(&data).join("data.json"));
        assert_eq!(side["format"], "langevin-fem-trajectories");
        assert_eq!(side["runs"][0]["discretization"]["model"], "fem");
        assert!(side["provenance"]["seed"].is_u64());
        let report = dir.join(&format!("report-{format}"));
        let (o, args) = check(&data, report.to_str().unwrap());
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let names: Vec<String> = checks(&report).into_iter().map(|c| c.0).collect();
        for kind in [
            "profile",
            "mode-variance",
            "mode-ks",
            "decay-rate",
            "spectrum-low",
            "two-time",
        ] {
            assert!(
                names.iter().any(|n| n.contains(&format!("/{kind}/"))),
                "{kind} missing: {names:?}"
            );
        }
        let summary = json(&report.join("summary.json"));
        assert_eq!(summary["budget"], "data");
        // The data's own description leads (the report's scene table shows it), the
        // scene's description follows, and the references are the producer's
        // discretization's: discrete.
        let scene = &summary["scenes"][0];
        let lead = scene["notes"][0].as_str().unwrap();
        assert!(lead.starts_with("checked data: "), "{lead}");
        assert!(lead.contains("fem, 10 elements, crank-nicolson"), "{lead}");
        let second = scene["notes"][1].as_str().unwrap();
        assert!(
            second.starts_with("references and checks of scene hinged-linear-2d: "),
            "{second}"
        );
        for c in scene["checks"].as_array().unwrap() {
            if c["check"] == "mode-variance" {
                assert_eq!(c["reference_kind"], "discrete", "{c}");
            }
        }
    }
}

/// Multiplies, in every CSV file of the first run of the data in `data` (sidecar
/// `side`), the columns whose header `chosen` picks by `factor`.
fn scale_columns(data: &str, side: &serde_json::Value, chosen: impl Fn(&str) -> bool, factor: f64) {
    for f in side["runs"][0]["files"].as_array().unwrap() {
        let path = Path::new(data).join(f.as_str().unwrap());
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let mut out = header.join(",") + "\n";
        for line in lines {
            let row: Vec<String> = line
                .split(',')
                .zip(&header)
                .map(|(v, h)| {
                    if chosen(h) {
                        (v.parse::<f64>().unwrap() * factor).to_string()
                    } else {
                        v.to_string()
                    }
                })
                .collect();
            out += &(row.join(",") + "\n");
        }
        std::fs::write(&path, out).unwrap();
    }
}

/// Modal amplitudes scaled by 1.1 (variances +21 %): `check` exits 1 naming the mode
/// variance checks of the well-resolved modes; the deflections untouched, the profile
/// checks still pass.
#[test]
fn an_injected_bias_fails_naming_the_checks() {
    let dir = TempDir::new("run-check-bias");
    let data = dir.join_str("data");
    simulate(&data, "csv");
    let side = json(&Path::new(&data).join("data.json"));
    scale_columns(&data, &side, |h| h.starts_with("aw_"), 1.1);
    let report = dir.join("report");
    let (o, args) = check(&data, report.to_str().unwrap());
    assert_eq!(o.status.code(), Some(1), "{}", describe(&args, &o));
    let results = checks(&report);
    let failed: Vec<&String> = results.iter().filter(|c| !c.1).map(|c| &c.0).collect();
    for n in 2..=6 {
        let name = format!("crank-nicolson/mode-variance/n={n}");
        assert!(
            failed.iter().any(|f| **f == name),
            "{name} not in {failed:?}"
        );
    }
    assert!(
        results
            .iter()
            .filter(|c| c.0.contains("/profile/"))
            .all(|c| c.1)
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("failed: crank-nicolson/mode-variance/n=2"),
        "{stdout}"
    );
    // The closing totals line (#14): the checks of summary.json, counted.
    let n_failed = failed.len();
    let totals = format!("{} passed, {n_failed} failed, ", results.len() - n_failed);
    let last = stdout.lines().last().unwrap_or("");
    assert!(
        last.starts_with(&totals) && last.contains(" skipped in ") && last.ends_with(" s"),
        "{last:?}, expected {totals:?}..."
    );
}

/// A noise-variance error (issue #31): modal amplitudes scaled by √1.1, so every variance
/// × 1.1 and every decay rate unchanged. `check` exits 1; each failed mode-variance line
/// of the default output shows its ratio estimate/reference (1.1 within 5 of its
/// standard errors), and the run's hint names the uniform variance ratio with the rates
/// unchanged — noise amplitude or kT — as does the report's note.
#[test]
fn a_noise_variance_error_fails_with_ratios_and_the_uniform_variance_hint() {
    let dir = TempDir::new("run-check-noise");
    let data = dir.join_str("data");
    simulate(&data, "csv");
    let side = json(&Path::new(&data).join("data.json"));
    scale_columns(&data, &side, |h| h.starts_with("aw_"), 1.1f64.sqrt());
    let report = dir.join("report");
    let (o, args) = check(&data, report.to_str().unwrap());
    assert_eq!(o.status.code(), Some(1), "{}", describe(&args, &o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let variance_lines: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("    failed: crank-nicolson/mode-variance/n="))
        .collect();
    assert!(variance_lines.len() >= 3, "{stdout}");
    for line in &variance_lines {
        let (_, ratio) = line.split_once(" (ratio ").expect(line);
        let (r, se) = ratio.trim_end_matches(')').split_once(" ± ").expect(line);
        let (r, se): (f64, f64) = (r.parse().expect(line), se.parse().expect(line));
        assert!((r - 1.1).abs() < 5.0 * se, "{line}");
    }
    // A KS line has no ratio of its own: it shows its mode's variance ratio, named so.
    for line in stdout.lines().filter(|l| l.contains("/mode-ks/")) {
        assert!(line.contains("(variance ratio "), "{line}");
    }
    let hint = stdout
        .lines()
        .find(|l| l.starts_with("    crank-nicolson: hint: "))
        .unwrap_or_else(|| panic!("no hint in {stdout}"));
    assert!(
        hint.contains("uniform variance ratio 1.1")
            && hint.contains("with decay rates unchanged (ratio ")
            && hint.ends_with("noise amplitude or kT?"),
        "{hint}"
    );
    let s = json(&report.join("summary.json"));
    let notes = common::strings(&s["scenes"][0]["notes"]);
    assert!(
        notes
            .iter()
            .any(|n| n.starts_with("run crank-nicolson: hint: uniform variance ratio")),
        "{notes:?}"
    );
}

/// Compression data of both runs of the scene's Δt-halving pair get the `dt-halving`
/// check; data of one run list it as skipped with the reason (issue #31: it was dropped
/// silently). The strain-averaged `force-mean-bias` names its largest single-strain
/// deviation and the force check that tests that strain.
#[test]
fn check_runs_dt_halving_when_the_data_hold_both_runs_and_skips_it_otherwise() {
    let dir = TempDir::new("run-check-halving");
    let data = dir.join_str("data");
    let args = [
        "run",
        "--scene",
        "compression-2d",
        "--format",
        "csv",
        "--out",
        &data,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let report = dir.join("report");
    let args = [
        "check",
        "--scene",
        "compression-2d",
        "--data",
        &data,
        "--out",
        report.to_str().unwrap(),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let s = json(&report.join("summary.json"));
    let scene = &s["scenes"][0];
    assert_eq!(scene["skipped"].as_array().unwrap().len(), 0, "{scene}");
    let checks = scene["checks"].as_array().unwrap();
    assert!(
        checks
            .iter()
            .any(|c| c["name"] == "dt-halving/metropolis-vs-metropolis-half"),
        "{checks:?}"
    );
    let names: Vec<&str> = checks.iter().filter_map(|c| c["name"].as_str()).collect();
    for c in checks.iter().filter(|c| c["check"] == "force-mean-bias") {
        let detail = c["detail"].as_str().unwrap();
        assert!(detail.starts_with("strain-averaged bias: "), "{detail}");
        let l = &c["largest_deviation"];
        let tested_by = l["tested_by"].as_str().unwrap();
        assert!(names.contains(&tested_by), "{tested_by}");
        assert!(tested_by.ends_with(l["parameter"].as_str().unwrap()));
        assert!(
            detail.contains("largest single-strain deviation"),
            "{detail}"
        );
    }
    assert!(common::schema::violations(&common::schema::summary_schema(), &s).is_empty());
    // The same data without the run at dt/2: skipped, with the reason.
    let path = Path::new(&data).join("data.json");
    let mut side = json(&path);
    side["runs"]
        .as_array_mut()
        .unwrap()
        .retain(|r| r["name"] != "metropolis-half");
    std::fs::write(&path, serde_json::to_string_pretty(&side).unwrap()).unwrap();
    let args = [
        "-v",
        "check",
        "--scene",
        "compression-2d",
        "--data",
        &data,
        "--out",
        report.to_str().unwrap(),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains(
            "    skipped: dt-halving/metropolis-vs-metropolis-half: the data hold run(s) \
             metropolis but not metropolis-half"
        ) && stdout.contains(", 1 skipped"),
        "{stdout}"
    );
    let s = json(&report.join("summary.json"));
    let skipped = &s["scenes"][0]["skipped"];
    assert_eq!(
        skipped[0]["name"], "dt-halving/metropolis-vs-metropolis-half",
        "{skipped}"
    );
    assert!(
        skipped[0]["reason"]
            .as_str()
            .unwrap()
            .contains("compares run metropolis (at dt) with run metropolis-half (at dt/2)")
    );
}

/// Every file under `dir` with its bytes.
/// Modal amplitudes scaled by 3 (variances 9×, the size of a wrong boundary condition in
/// an integrator): every mode-variance check fails with p < 1e-12 — its null law, scale
/// included, comes from the reference, so it cannot saturate the way a t-test whose error
/// comes from the same data does (issue #30).
#[test]
fn a_nine_fold_variance_fails_every_mode_variance_check_with_a_tiny_p() {
    let dir = TempDir::new("run-check-nine");
    let data = dir.join_str("data");
    simulate(&data, "csv");
    let side = json(&Path::new(&data).join("data.json"));
    scale_columns(&data, &side, |h| h.starts_with("aw_"), 3.0);
    let report = dir.join("report");
    let (o, args) = check(&data, report.to_str().unwrap());
    assert_eq!(o.status.code(), Some(1), "{}", describe(&args, &o));
    let s = json(&report.join("summary.json"));
    let variance: Vec<&serde_json::Value> = s["scenes"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["check"] == "mode-variance")
        .collect();
    assert!(!variance.is_empty());
    for c in variance {
        let p = c["p_value"].as_f64().unwrap();
        assert!(p < 1e-12, "{}: p = {p:e}", c["name"]);
        assert_eq!(c["kind"], "quadratic-form");
    }
}

fn tree_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    all_files(dir)
        .into_iter()
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect()
}

/// What: a check that fails after its report was begun (exit 3: an estimator finds no
/// answer in valid but too short data) and one refused (exit 2: `--out` holding the
/// data) leave an earlier report in `--out`, and the data, byte for byte (issue #25:
/// the run's files wait in a staging folder until it succeeds).
/// Set-up: a passing check of 8 trajectories × 40 τ1, then compression data of 2
/// trajectories × 2 τ1 checked into the same `--out` (33 samples of the force: too
/// short for its integrated autocorrelation time, even pooled over the trajectories: the
/// message names the strain and says to record longer trajectories). Tolerance: exact
/// bytes; substrings.
#[test]
fn a_failed_or_refused_check_leaves_the_earlier_report_as_it_was() {
    let dir = TempDir::new("run-check-failed");
    let (good, report) = (dir.join_str("good"), dir.join_str("report"));
    simulate(&good, "npy");
    let (o, args) = check(&good, &report);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let before = tree_bytes(Path::new(&report));
    let short = dir.join_str("short");
    let args = [
        "run",
        "-q",
        "--scene",
        "compression-2d",
        "--trajectories",
        "2",
        "--duration-tau1",
        "2",
        "--out",
        &short,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let args = [
        "check",
        "--scene",
        "compression-2d",
        "--data",
        &short,
        "--out",
        &report,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(3), "{}", describe(&args, &o));
    // The message names the strain whose series are too short, even pooled, and what to do.
    let err = stderr_of(&o);
    assert!(
        err.contains("<F> at strain ") && err.contains("record longer trajectories"),
        "{}",
        describe(&args, &o)
    );
    assert_eq!(tree_bytes(Path::new(&report)), before, "after exit 3");
    let data = tree_bytes(Path::new(&good));
    let (o, args) = check(&good, &good);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    assert!(stderr_of(&o).contains("--out"), "{}", describe(&args, &o));
    assert_eq!(tree_bytes(Path::new(&good)), data, "check -d DIR -o DIR");
    assert_eq!(tree_bytes(Path::new(&report)), before);
}

/// What: `run`, `run --shard` and `check` never write over a user's file below `--out`
/// (issue #25: nothing the user gave is overwritten): a file of the user's at the name of
/// a trajectory, a shard's trajectory or a report table, in a folder no journal of the
/// command describes, is refused with exit 2 naming `--out` and the file, and the folder
/// is byte for byte as it was (nothing written beside it either).
/// Tolerance: exact bytes.
#[test]
fn run_and_check_refuse_to_overwrite_a_users_file_below_out() {
    let dir = TempDir::new("run-check-taken");
    let cases: [(&str, &[&str], &str); 3] = [
        ("run", &[], "crank-nicolson/trajectory-0000.npy"),
        (
            "run",
            &["--shard", "1/2"],
            "crank-nicolson/trajectory-0000.npy",
        ),
        ("check", &[], "hinged-linear-2d/crank-nicolson-modes.csv"),
    ];
    let data = dir.join_str("data");
    simulate(&data, "npy");
    for (i, (command, extra, mine)) in cases.into_iter().enumerate() {
        let out = dir.join(&format!("out{i}"));
        std::fs::create_dir_all(out.join(mine).parent().unwrap()).unwrap();
        std::fs::write(out.join(mine), b"my own data").unwrap();
        let before = tree_bytes(&out);
        let out_s = out.to_str().unwrap();
        let o = if command == "run" {
            let mut args = vec![
                "run",
                "-q",
                "--scene",
                "hinged-linear-2d",
                "--run",
                "crank-nicolson",
                "--trajectories",
                "2",
                "--duration-tau1",
                "5",
                "--out",
                out_s,
            ];
            args.extend(extra);
            run(&args)
        } else {
            check(&data, out_s).0
        };
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(2), "{command} {extra:?}: {err}");
        assert!(
            err.contains("--out") && err.contains(mine),
            "{command} {extra:?}: {err}"
        );
        assert_eq!(tree_bytes(&out), before, "{command} {extra:?}");
    }
}

/// What: `run --every` on a compression scene, whose rows follow the scene's
/// `compression.sample_every_tau1`, is refused (exit 2 naming `--every`) rather than
/// ignored, and nothing is written.
#[test]
fn run_every_is_refused_for_a_compression_scene() {
    let dir = TempDir::new("run-every-compression");
    let out = dir.join_str("out");
    let scene = fixture("tests/scenes/good/tiny-compression.toml");
    let scene = scene.to_str().unwrap();
    let args = ["run", "-q", "--scene", scene, "--every", "5", "--out", &out];
    assert_refused(&run(&args), &args, &["--every", "sample_every_tau1"]);
    assert!(!Path::new(&out).exists());
}

/// What: degenerate data of a broken simulator are judged, not mistaken for too little
/// data: (1) a trajectory identical to another, number for number (a reused seed), is
/// refused with exit 2 naming both files' keys; (2) a modal amplitude frozen at one value
/// in every trajectory (a mode the noise never drives) fails its checks (exit 1): the
/// mean, rate and spectra tests, whose error is the spread across series, give p = 0 for
/// values with no spread (probability zero under a continuous null) instead of exiting 3
/// with "longer or more trajectories may help".
#[test]
fn identical_trajectories_are_refused_and_a_frozen_amplitude_fails() {
    let dir = TempDir::new("run-check-degenerate");
    let data = dir.join_str("data");
    simulate(&data, "csv");
    let files = Path::new(&data).join("crank-nicolson");
    let t0 = files.join("trajectory-0000.csv");
    let original = std::fs::read(files.join("trajectory-0001.csv")).unwrap();
    std::fs::copy(&t0, files.join("trajectory-0001.csv")).unwrap();
    let (o, args) = check(&data, &dir.join_str("report-same"));
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    assert!(
        err.contains("runs[0].files[1]") && err.contains("runs[0].files[0]"),
        "{err}"
    );
    assert!(err.contains("independent"), "{err}");
    std::fs::write(files.join("trajectory-0001.csv"), original).unwrap();

    for entry in std::fs::read_dir(&files).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap();
        let col = header
            .split(',')
            .position(|c| c == "aw_2")
            .expect("aw_2 column");
        let body: Vec<String> = lines
            .map(|l| {
                let mut f: Vec<&str> = l.split(',').collect();
                f[col] = "0.25";
                f.join(",")
            })
            .collect();
        std::fs::write(&path, format!("{header}\n{}\n", body.join("\n"))).unwrap();
    }
    let report = dir.join("report-frozen");
    let (o, args) = check(&data, report.to_str().unwrap());
    assert_eq!(o.status.code(), Some(1), "{}", describe(&args, &o));
    let failed: Vec<String> = checks(&report)
        .into_iter()
        .filter(|(_, passed)| !passed)
        .map(|(name, _)| name)
        .collect();
    for name in ["mode-variance/n=2", "mode-mean/n=2", "decay-rate/n=2"] {
        assert!(
            failed.iter().any(|f| f.ends_with(name)),
            "{name} not failed: {failed:?}"
        );
    }
    assert!(
        failed
            .iter()
            .all(|f| f.ends_with("n=2") || f.contains("pooled")),
        "{failed:?}"
    );
}

/// `run -q --scene scene --trajectories n --out data` (exit 0); the sidecar's path.
fn run_fixture(scene: &str, n: &str, data: &str) -> std::path::PathBuf {
    let args = [
        "run",
        "-q",
        "--scene",
        scene,
        "--trajectories",
        n,
        "--out",
        data,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    Path::new(data).join("data.json")
}

/// What: membrane data whose sidecar names another boundary than the scene's (here
/// simply supported against a periodic patch) are refused with exit 2 naming
/// `membrane.boundary` and both boundaries, before any reference is computed (the
/// references are the scene's modes: a simply supported edge has zero variance where
/// the periodic patch has none).
#[test]
fn membrane_data_of_another_boundary_are_refused() {
    let dir = TempDir::new("run-check-boundary");
    let (data, out) = (dir.join_str("data"), dir.join_str("out"));
    let scene = fixture("tests/scenes/good/membrane-pbc.toml");
    let scene = scene.to_str().unwrap();
    let side = run_fixture(scene, "2", &data);
    let text = std::fs::read_to_string(&side).unwrap();
    assert!(text.contains("\"periodic\""), "{text}");
    std::fs::write(
        &side,
        text.replacen("\"periodic\"", "\"simply-supported\"", 1),
    )
    .unwrap();
    let args = [
        "check", "-q", "--scene", scene, "--data", &data, "--out", &out,
    ];
    let needles = ["membrane.boundary", "simply-supported", "periodic"];
    assert_refused(&run(&args), &args, &needles);
    assert!(!Path::new(&out).exists());
}

/// What: membrane data whose sidecar declares a mesh beyond a membrane scene's bounds
/// (within the sidecar's own [1, 1000], the filament's range) are refused with exit 2
/// naming `runs[0].discretization.elements_y` / `.elements`, the membrane's range and the
/// value, as `mesh.elements_y` is in scene files (they used to name `runs[0].discretization`
/// with an internal type's name, or the spectral simulator's `mx`).
/// Tolerance: exact substrings.
#[test]
fn membrane_data_beyond_a_membrane_mesh_are_refused_naming_the_key() {
    let dir = TempDir::new("run-check-membrane-mesh");
    let (data, out) = (dir.join_str("data"), dir.join_str("out"));
    let scene = fixture("tests/scenes/good/membrane-pbc.toml");
    let scene = scene.to_str().unwrap();
    let side = run_fixture(scene, "2", &data);
    let original: serde_json::Value = json(&side);
    for (edit, key, needles) in [
        (
            &[("elements_y", 1000)][..],
            "runs[0].discretization.elements_y",
            &["in [2, 256] for a periodic membrane", "got 1000"][..],
        ),
        (
            &[("elements", 1000), ("elements_y", 1000)][..],
            "runs[0].discretization.elements",
            &["in [2, 256]", "got 1000"][..],
        ),
        (
            &[("elements", 100), ("elements_y", 100)][..],
            "runs[0].discretization.elements_y",
            &["at most 40", "100 x 100 = 10000"][..],
        ),
    ] {
        let mut d = original.clone();
        for &(k, v) in edit {
            d["runs"][0]["discretization"][k] = serde_json::json!(v);
        }
        std::fs::write(&side, serde_json::to_string(&d).unwrap()).unwrap();
        let args = [
            "check", "-q", "--scene", scene, "--data", &data, "--out", &out,
        ];
        let mut all = vec!["data.json", key];
        all.extend_from_slice(needles);
        assert_refused(&run(&args), &args, &all);
        assert!(!Path::new(&out).exists());
    }
}

/// What: filament data whose sidecar states kT = 1e-30 (inside the sidecar's range, 30
/// orders below the data's scale) fail their checks (exit 1): the variance tests' null
/// law is so far from the data that its saddle point is not resolvable in f64, and the
/// Chernoff bound gives p = 0, where the run used to fail with exit 3 ("no saddle point").
/// Tolerance: the exit code; the failed checks include the variance ones.
#[test]
fn data_thirty_orders_off_the_reference_fail_their_checks() {
    let dir = TempDir::new("run-check-kt-off");
    let (data, out) = (dir.join_str("data"), dir.join_str("out"));
    let scene = fixture("tests/scenes/good/tiny-linear.toml");
    let scene = scene.to_str().unwrap();
    let side = run_fixture(scene, "4", &data);
    let mut d: serde_json::Value = json(&side);
    d["filament"]["kt"] = serde_json::json!(1e-30);
    std::fs::write(&side, serde_json::to_string(&d).unwrap()).unwrap();
    let args = [
        "check", "-q", "--scene", scene, "--data", &data, "--out", &out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(1), "{}", describe(&args, &o));
    let summary: serde_json::Value = json(&Path::new(&out).join("summary.json"));
    let checks = summary["scenes"][0]["checks"].as_array().unwrap();
    let far = checks.iter().find(|c| {
        c["check"] == "mode-variance" && c["kind"] == "quadratic-form" && c["parameter"] == "n=1"
    });
    let far = far.expect("the mode variance's quadratic-form check");
    assert_eq!(far["passed"], false, "{far}");
    assert_eq!(far["p_value"], 0.0, "{far}");
}

/// What: `run`'s projected work counts the rows it writes, not only the steps: the
/// spectral reference's 8 quick trajectories at `--every 1` (its default cadence here:
/// 1.8e6 rows of 65 positions, each a sum over 64 modes, measured 138 s) project about
/// 7.6e9 DOF-steps (they projected 1.2e8, "about 2.3 s", whatever the rows); at
/// `--every 200` the projection drops by the rows' share.
/// Tolerance: the projection's order (within 2× of the measured cost).
#[test]
fn run_projection_counts_the_rows_it_writes() {
    let dir = TempDir::new("run-row-cost");
    let out = dir.join_str("out");
    let projected = |every: &str| -> f64 {
        let args = [
            "run",
            "-q",
            "--scene",
            "spectral-reference",
            "--trajectories",
            "8",
            "--every",
            every,
            "--max-work",
            "1",
            "--out",
            &out,
        ];
        let o = run(&args);
        assert_refused(&o, &args, &["DOF-steps to evaluate them"]);
        let err = stderr_of(&o);
        let got = err.split("got ").nth(1).and_then(|t| t.split(' ').next());
        got.and_then(|g| g.parse().ok())
            .unwrap_or_else(|| panic!("no projection in {err}"))
    };
    let (dense, sparse) = (projected("1"), projected("200"));
    assert!((7e9..1.5e10).contains(&dense), "{dense:e}");
    assert!(sparse < 0.1 * dense, "{sparse:e} vs {dense:e}");
}

/// What: `run`'s work refusal names `--trajectories` and `--duration-tau1` (with their
/// values) when they drive the work, not the scene's budget keys they replace.
/// Tolerance: exact substrings.
#[test]
fn run_work_refusal_names_the_flags_that_drive_it() {
    let dir = TempDir::new("run-work-flags");
    let out = dir.join_str("out");
    let args = [
        "run",
        "-q",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "crank-nicolson",
        "--trajectories",
        "100000",
        "--duration-tau1",
        "1e6",
        "--out",
        &out,
    ];
    let needles = [
        "the projected work of `run` (--trajectories 100000, --duration-tau1 1000000)",
        "--max-work",
    ];
    assert_refused(&run(&args), &args, &needles);
    assert!(!Path::new(&out).exists());
}

/// What: `run` refuses, before anything runs or is written, trajectory files whose
/// projected size exceeds `--max-output-gib` (rows × columns × 8 bytes in .npy): 2
/// trajectories of 10⁶ τ₁ at `--every 1` (about 283 GiB) at the default 16 GiB; the same
/// small job passes its cap and fails a cap below it.
/// Tolerance: exact substrings.
#[test]
fn run_refuses_trajectory_files_above_the_output_cap() {
    let dir = TempDir::new("run-output-cap");
    let out = dir.join_str("out");
    let base = [
        "run",
        "-q",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "crank-nicolson",
    ];
    let mut args: Vec<&str> = base.to_vec();
    args.extend([
        "--duration-tau1",
        "1e6",
        "--trajectories",
        "2",
        "--every",
        "1",
        "--out",
        &out,
    ]);
    let needles = ["--max-output-gib", "GiB", "--every"];
    assert_refused(&run(&args), &args, &needles);
    assert!(!Path::new(&out).exists(), "nothing written");
    // 2 trajectories of the quick duration: a few MB.
    let mut args: Vec<&str> = base.to_vec();
    args.extend([
        "--trajectories",
        "2",
        "--max-output-gib",
        "1e-6",
        "--out",
        &out,
    ]);
    assert_eq!(run(&args).status.code(), Some(2));
    let mut args: Vec<&str> = base.to_vec();
    args.extend([
        "--trajectories",
        "2",
        "--max-output-gib",
        "0.1",
        "--out",
        &out,
    ]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
}

/// Sidecars and files that are the user's mistake: exit 2 naming the key or the file.
#[test]
fn bad_data_directories_exit_2_naming_what_to_fix() {
    let dir = TempDir::new("run-check-bad");
    let data = dir.join_str("data");
    simulate(&data, "npy");
    let side_path = Path::new(&data).join("data.json");
    let original = std::fs::read_to_string(&side_path).unwrap();
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "\"version\": 1",
            "\"version\": 7",
            &["data.json", "version", "7"],
        ),
        ("\"dims\": 2", "\"dims\": 3", &["data.json", "dims", "3"]),
        (
            "\"dt_sample\": ",
            "\"dt_sample\": -",
            &["runs[0].dt_sample"],
        ),
        (
            "trajectory-0003.npy",
            "trajectory-9999.npy",
            &["runs[0].files[3]", "trajectory-9999.npy"],
        ),
        (
            "\"modes\": 6",
            "\"modes\": 7",
            &["trajectory-0000.npy", "columns"],
        ),
    ];
    for (from, to, named) in cases {
        assert!(original.contains(from), "{from}");
        std::fs::write(&side_path, original.replacen(from, to, 1)).unwrap();
        let report = dir.join("report");
        let (o, args) = check(&data, report.to_str().unwrap());
        let err = stderr_of(&o);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{from} -> {to}: {}",
            describe(&args, &o)
        );
        for n in named {
            assert!(err.contains(n), "{from} -> {to}: {n:?} not in {err}");
        }
        assert!(!report.join("summary.json").exists());
    }
    std::fs::write(&side_path, &original).unwrap();
    let (o, args) = check(&dir.join_str("nowhere"), dir.join_str("report").as_str());
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    assert!(stderr_of(&o).contains("--data"));
}

/// From an empty directory outside the repository (built-in scenes): `list`, `run` and
/// `check` work, and every file each writes is listed in its directory's journal, whose
/// provenance names the version, the commit, the seed and the scene (with its hash).
#[test]
fn from_an_empty_directory_every_file_is_traced() {
    let dir = TempDir::new("run-check-anywhere");
    let in_dir = |args: &[&str]| {
        let o = common::command()
            .current_dir(dir.path())
            .args(args)
            .output()
            .expect("run");
        assert_eq!(o.status.code(), Some(0), "{}", describe(args, &o));
        o
    };
    let list = in_dir(&["list"]);
    assert!(String::from_utf8_lossy(&list.stdout).contains("hinged-linear-2d"));
    in_dir(&[
        "run",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "crank-nicolson",
        "--trajectories",
        "8",
        "--duration-tau1",
        "40",
        "--every",
        "10",
        "--seed",
        "99",
        "--out",
        "x",
    ]);
    in_dir(&[
        "check",
        "--scene",
        "hinged-linear-2d",
        "--data",
        "x",
        "--out",
        "r",
    ]);
    for out in ["x", "r"] {
        let root = dir.join(out);
        let m = json(&root.join("manifest.json"));
        let listed = common::strings(&m["files"]);
        for f in common::all_files(&root) {
            assert!(listed.contains(&f), "{out}/{f} is not in its journal");
        }
        let p = &m["provenance"];
        assert_eq!(p["version"], env!("CARGO_PKG_VERSION"));
        assert!(p["commit"].as_str().is_some_and(|c| !c.is_empty()), "{p}");
        let scene = &p["scenes"][0];
        assert_eq!(scene["name"], "hinged-linear-2d");
        assert_eq!(scene["sha256"].as_str().map(str::len), Some(64), "{scene}");
        if out == "x" {
            assert_eq!(scene["seed"].as_u64(), Some(99));
            let side = json(&root.join("data.json"));
            assert_eq!(side["provenance"]["seed"].as_u64(), Some(99));
            assert_eq!(side["provenance"]["record"]["commit"], p["commit"]);
        }
    }
    let summary = json(&dir.join("r").join("summary.json"));
    assert_eq!(summary["provenance"]["manifest"], "manifest.json");
}

/// A compression scene round-trips too: F and the stored length per strain, judged
/// against the exact theory of the producer's discretization.
#[test]
fn compression_data_round_trip() {
    let dir = TempDir::new("run-check-compression");
    let data = dir.join_str("data");
    let args = [
        "run",
        "--scene",
        "compression-2d",
        "--run",
        "metropolis",
        "--format",
        "csv",
        "--out",
        &data,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let side = json(&Path::new(&data).join("data.json"));
    let runs = side["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 12, "one data run per strain");
    assert!(side["filament"]["stretch_rigidity"].is_number());
    let report = dir.join("report");
    let args = [
        "check",
        "--scene",
        "compression-2d",
        "--data",
        &data,
        "--out",
        report.to_str().unwrap(),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let names: Vec<String> = checks(&report).into_iter().map(|c| c.0).collect();
    assert!(
        names
            .iter()
            .any(|n| n.starts_with("metropolis/force/strain_ratio=")),
        "{names:?}"
    );
    assert!(names.iter().any(|n| n.contains("/force-ks/")), "{names:?}");
    assert!(
        report
            .join("compression-2d/metropolis-force-strain.csv")
            .is_file()
    );
}

/// `run` of membrane-periodic's Crank–Nicolson run (16 trajectories, CSV) into `out`.
fn simulate_membrane(out: &str) {
    let args = [
        "run",
        "--scene",
        "membrane-periodic",
        "--run",
        "crank-nicolson",
        "--trajectories",
        "16",
        "--format",
        "csv",
        "--out",
        out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
}

/// `check` of data `data` against `scene`, the report in `out`.
fn check_scene(scene: &str, data: &str, out: &str) -> (std::process::Output, Vec<String>) {
    let args: Vec<String> = ["check", "--scene", scene, "--data", data, "--out", out]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    (run(&refs), args)
}

/// A membrane's trajectories (issue #27): heights on the midline and the modal
/// amplitudes named by their modes; its own output passes every check kind of the
/// scene against its discretization's exact references; amplitudes scaled by 1.1 fail
/// the mode variances of the slowest modes; a filament scene refuses the data naming
/// the sidecar key `membrane`.
#[test]
fn membrane_output_round_trips_and_a_bias_fails() {
    let dir = TempDir::new("run-check-membrane");
    let data = dir.join_str("data");
    simulate_membrane(&data);
    let side = json(&Path::new(&data).join("data.json"));
    assert_eq!(side["membrane"]["boundary"], "periodic");
    assert!(side.get("filament").is_none());
    assert_eq!(side["dims"], 3);
    let first = Path::new(&data).join(side["runs"][0]["files"][0].as_str().unwrap());
    let header = std::fs::read_to_string(&first).unwrap();
    let header = header.lines().next().unwrap();
    assert!(
        header.starts_with("t,h_0,h_1,") && header.contains(",ac_0_1,as_0_1,ac_1_0,as_1_0"),
        "{header}"
    );
    let report = dir.join("report");
    let (o, args) = check_scene("membrane-periodic", &data, report.to_str().unwrap());
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr_of(&o));
    let names: Vec<String> = checks(&report).into_iter().map(|c| c.0).collect();
    for kind in [
        "profile",
        "mode-variance",
        "decay-rate",
        "two-time",
        "pooled-variance",
    ] {
        assert!(
            names.iter().any(|n| n.contains(&format!("/{kind}"))),
            "{kind} missing: {names:?}"
        );
    }
    // The amplitudes are those of the continuum modes (M3), not C-normalized modal
    // coordinates: without the discretization the slowest modes' variances pass
    // against the continuum (the 8 x 8 mesh resolves them; the modal coordinates'
    // variances would be ξA/2 = 1/2 of theirs).
    let mut continuum = side.clone();
    continuum["runs"][0]
        .as_object_mut()
        .unwrap()
        .remove("discretization");
    let sidecar = Path::new(&data).join("data.json");
    std::fs::write(&sidecar, continuum.to_string()).unwrap();
    let against = dir.join("continuum");
    let _ = check_scene("membrane-periodic", &data, against.to_str().unwrap());
    let results = checks(&against);
    // Without a declared discretization every reference is the continuum's, and every
    // check of the run says so.
    let summary = json(&against.join("summary.json"));
    for c in summary["scenes"][0]["checks"].as_array().unwrap() {
        assert_eq!(c["reference_kind"], "continuum", "{c}");
    }
    // Modes 1-4: ac_0_1, as_0_1, ac_1_0, as_1_0.
    for n in 1..=4 {
        let name = format!("crank-nicolson/mode-variance/n={n}");
        assert!(
            results.iter().any(|c| c.0 == name && c.1),
            "{name} does not pass against the continuum: {results:?}"
        );
    }
    std::fs::write(&sidecar, side.to_string()).unwrap();
    // The amplitudes scaled by 1.1.
    scale_columns(&data, &side, |h| h.starts_with('a'), 1.1);
    let biased = dir.join("biased");
    let (o, args) = check_scene("membrane-periodic", &data, biased.to_str().unwrap());
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr_of(&o));
    let failed: Vec<String> = checks(&biased)
        .into_iter()
        .filter(|c| !c.1)
        .map(|c| c.0)
        .collect();
    assert!(
        failed.iter().any(|f| f == "crank-nicolson/pooled-variance"),
        "{failed:?}"
    );
    assert!(
        failed
            .iter()
            .any(|f| f.starts_with("crank-nicolson/mode-variance/")),
        "{failed:?}"
    );
    let (o, _) = check_scene(
        "hinged-linear-2d",
        &data,
        dir.join("other").to_str().unwrap(),
    );
    assert_eq!(o.status.code(), Some(2));
    let err = stderr_of(&o);
    assert!(
        err.contains("data.json: key `membrane`") && err.contains("the data are of a membrane"),
        "{err}"
    );
}

/// What: the membrane under imposed projected area (issue #28) goes through `verify`, and
/// the commands not written for it yet refuse it before anything runs, exit 2, naming the
/// key `membrane` and what is refused (not a filament's numbers from the scene's unused
/// default `[filament]`). Set-up: `run` and `converge` of `membrane-area-stiff`.
#[test]
fn membrane_under_imposed_area_is_refused_where_not_supported() {
    let tmp = TempDir::new("area-refused");
    let out = tmp.path().join("out");
    let out = out.to_str().unwrap();
    for (args, what) in [
        (
            vec!["run", "--scene", "membrane-area-stiff", "--out", out],
            "run of a membrane under imposed projected area",
        ),
        (
            vec![
                "converge",
                "--scene",
                "membrane-area-stiff",
                "--over",
                "elements",
                "--values",
                "4,8",
                "--out",
                out,
            ],
            "converge of a membrane under imposed projected area",
        ),
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let e = stderr_of(&o);
        assert!(e.contains("key `membrane`") && e.contains(what), "{e}");
        assert!(!Path::new(out).join("manifest.json").exists());
    }
}

/// A free–free microtubule's trajectories (issue #29): after the modal amplitudes the
/// rigid coordinates (w_mean, w_angle) and the tangent-angle cosine amplitudes of Gittes
/// et al. (gw_n); its own output passes the rigid-diffusion and tangent-angle checks
/// against its discretization's exact references (none skipped); the tangent-angle
/// amplitudes scaled by 1.1 fail the tangent variances, the rigid coordinates scaled by
/// 1.1 the rigid diffusion; `rigid` on a scene without rigid modes is refused naming the
/// key.
#[test]
fn free_filament_data_carry_rigid_and_tangent_angle_columns() {
    let dir = TempDir::new("run-check-free");
    let data = dir.join_str("data");
    let args = [
        "run",
        "--scene",
        "microtubule-free-free",
        "--run",
        "crank-nicolson",
        "--format",
        "csv",
        "--out",
        &data,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let side = json(&Path::new(&data).join("data.json"));
    assert_eq!(side["runs"][0]["rigid"], true);
    assert_eq!(side["runs"][0]["tangent_modes"], 4);
    let first = Path::new(&data).join(side["runs"][0]["files"][0].as_str().unwrap());
    let text = std::fs::read_to_string(&first).unwrap();
    assert!(
        text.lines()
            .next()
            .unwrap()
            .ends_with("aw_4,w_mean,w_angle,gw_1,gw_2,gw_3,gw_4"),
        "{}",
        text.lines().next().unwrap()
    );
    let report = dir.join_str("report");
    let (o, args) = check_scene("microtubule-free-free", &data, &report);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr_of(&o));
    let s = json(&Path::new(&report).join("summary.json"));
    let names: Vec<String> = s["scenes"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    for want in [
        "crank-nicolson/rigid-diffusion/mode=0",
        "crank-nicolson/rigid-diffusion/mode=1",
        "crank-nicolson/tangent-variance/n=1",
        "crank-nicolson/tangent-ks/n=4",
    ] {
        assert!(names.iter().any(|n| n == want), "{want} not in {names:?}");
    }
    let failed_of = |report: &str| -> Vec<String> {
        checks(Path::new(report))
            .into_iter()
            .filter(|c| !c.1)
            .map(|c| c.0)
            .collect()
    };
    scale_columns(&data, &side, |h| h.starts_with("gw_"), 1.1);
    let report2 = dir.join_str("report-tangent");
    let (o, args) = check_scene("microtubule-free-free", &data, &report2);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr_of(&o));
    let failed = failed_of(&report2);
    assert!(
        failed.iter().any(|f| f.contains("tangent-variance")),
        "{failed:?}"
    );
    assert!(failed.iter().all(|f| f.contains("tangent")), "{failed:?}");
    scale_columns(&data, &side, |h| h.starts_with("gw_"), 1.0 / 1.1);
    scale_columns(&data, &side, |h| h == "w_mean" || h == "w_angle", 1.1);
    let report3 = dir.join_str("report-rigid");
    let (o, args) = check_scene("microtubule-free-free", &data, &report3);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr_of(&o));
    let failed = failed_of(&report3);
    assert!(
        failed.iter().any(|f| f.contains("rigid-diffusion")),
        "{failed:?}"
    );
    assert!(failed.iter().all(|f| f.contains("rigid")), "{failed:?}");
    // The same data against a hinged scene: `rigid` names the key.
    let (o, args) = check_scene("hinged-linear-2d", &data, &dir.join_str("report-hinged"));
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr_of(&o));
    let err = stderr_of(&o);
    assert!(err.contains("runs[0].rigid"), "{err}");
}

/// Issue #31: `fit` on `run` output returns EI, ξ and kT with intervals that cover the
/// truth (the sidecar's 1, 1, 1), prints them and writes fit.json beside the report of
/// `check`; on data whose variances are scaled by 1.1 (a noise amplitude error), kT with
/// EI known is 1.1 within its interval and the interval excludes 1. A pass says where
/// the data could have missed an error: every passing run prints its detectable
/// deviation. `fit` of compression data is refused (exit 2).
#[test]
fn fit_recovers_the_parameters_with_intervals() {
    let dir = TempDir::new("run-check-fit");
    let data = dir.join_str("data");
    simulate(&data, "csv");
    let fit = |data: &str, out: &str| {
        let (o, args) = on_data("fit", data, out);
        let d = describe(&args, &o);
        (o, d)
    };
    let out = dir.join_str("fit");
    let (o, d) = fit(&data, &out);
    assert_eq!(o.status.code(), Some(0), "{d}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("fit crank-nicolson (95 % intervals):"),
        "{stdout}"
    );
    assert!(
        stdout.contains("    crank-nicolson: passed; would have caught a variance error ≥ "),
        "{stdout}"
    );
    let f = json(&Path::new(&out).join("fit.json"));
    let run0 = &f["runs"][0];
    for key in ["bending_rigidity", "drag", "kt_given_bending_rigidity"] {
        let i = &run0[key]["interval"];
        let (lo, hi) = (i[0].as_f64().unwrap(), i[1].as_f64().unwrap());
        assert!(
            lo <= 1.0 && 1.0 <= hi && hi / lo < 1.1,
            "{key}: [{lo}, {hi}]"
        );
    }
    let s = json(&Path::new(&out).join("summary.json"));
    let notes = common::strings(&s["scenes"][0]["notes"]);
    assert!(
        notes
            .iter()
            .any(|n| n.starts_with("fit, run crank-nicolson"))
    );

    let side = json(&Path::new(&data).join("data.json"));
    scale_columns(&data, &side, |h| h.starts_with("aw_"), 1.1f64.sqrt());
    let out = dir.join_str("fit-noise");
    let (o, d) = fit(&data, &out);
    assert_eq!(o.status.code(), Some(0), "{d}");
    let f = json(&Path::new(&out).join("fit.json"));
    let kt = &f["runs"][0]["kt_given_bending_rigidity"];
    let (lo, hi) = (
        kt["interval"][0].as_f64().unwrap(),
        kt["interval"][1].as_f64().unwrap(),
    );
    assert!(
        lo > 1.0 && lo <= 1.1 && 1.1 <= hi,
        "kT interval [{lo}, {hi}]"
    );

    let args = [
        "fit",
        "--scene",
        "compression-2d",
        "--data",
        &data,
        "--out",
        &dir.join_str("c"),
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
}

/// Membrane-periodic's Crank–Nicolson run simulated with `key = value` (its scene's
/// `key = 1.0` or `20.0` replaced) into `dir/name`, and its sidecar then set back to the
/// scene's value; returns the data directory.
fn membrane_data_off(dir: &TempDir, name: &str, key: &str, value: &str) -> String {
    let scene = dir.join_str(&format!("{name}.toml"));
    let text = std::fs::read_to_string(fixture("verification/membrane-periodic.toml")).unwrap();
    let old = match key {
        "bending_rigidity" => "1.0",
        _ => "20.0",
    };
    let line = format!("\n{key} = {old}\n");
    assert!(text.contains(&line), "{line}");
    std::fs::write(&scene, text.replace(&line, &format!("\n{key} = {value}\n"))).unwrap();
    let data = dir.join_str(name);
    let args = [
        "run",
        "-q",
        "--scene",
        &scene,
        "--run",
        "crank-nicolson",
        "--out",
        &data,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let side_path = Path::new(&data).join("data.json");
    let mut side = json(&side_path);
    side["membrane"][key] = old.parse::<f64>().unwrap().into();
    std::fs::write(&side_path, serde_json::to_vec_pretty(&side).unwrap()).unwrap();
    data
}

/// `fit` of membrane-periodic data (σ = 20) against a sidecar that misstates κ or σ:
/// - simulated at κ = 1.1 with a sidecar of 1: κ with σ held (the regression on the modes'
///   bending shares κq⁴/c_q) covers 1.1 and excludes 1, the law fitting the modes with that
///   one parameter (its χ² so labelled, not "one factor"; scaling every variance alike, as for a filament, gives κ ≈ 1.09 here, outside this
///   interval); ξ covers 1; κ and σ fitted together cover 1.1 and 20, and ξ with them 1;
/// - simulated at σ = 25 with a sidecar of 20: κ and σ together cover 1 and 25 (ξ with
///   them 1), σ's
///   interval excludes 20, and the fit with σ held says the law with κ alone does not
///   explain the modes (χ² p < 1e-3).
///
/// The printed fit names κ, the tension held and the joint fit. The hint of the checks
/// beside it (`summary.json`'s `hints`, in its schema, and stdout) names the parameter
/// from the modes' shares: κ × 1.1 with σ held (pattern `bending-rigidity`), then the tension (pattern
/// `tension`, σ within 5 % of 25 by its first-order slope).
#[test]
fn fit_recovers_a_membranes_bending_rigidity_and_tension() {
    let dir = TempDir::new("run-check-fit-membrane");
    let fit = |data: &str, out: &str| {
        let args = [
            "fit",
            "--scene",
            "membrane-periodic",
            "--data",
            data,
            "--out",
            out,
        ];
        let o = run(&args);
        let d = describe(&args, &o);
        let f = json(&Path::new(out).join("fit.json"));
        let summary = json(&Path::new(out).join("summary.json"));
        let v = common::schema::violations(&common::schema::summary_schema(), &summary);
        assert!(v.is_empty(), "{v:#?}");
        let hints = summary["scenes"][0]["hints"].clone();
        (
            f["runs"][0].clone(),
            String::from_utf8_lossy(&o.stdout).to_string(),
            d,
            hints,
        )
    };
    let hint = |hints: &serde_json::Value, pattern: &str| {
        let h = &hints[0];
        assert_eq!(h["run"], "crank-nicolson", "{hints}");
        assert_eq!(h["pattern"], pattern, "{hints}");
        h["text"].as_str().unwrap().to_string()
    };
    let interval = |v: &serde_json::Value| {
        let i = &v["interval"];
        (i[0].as_f64().unwrap(), i[1].as_f64().unwrap())
    };

    let data = membrane_data_off(&dir, "kappa", "bending_rigidity", "1.1");
    let (run0, stdout, d, hints) = fit(&data, &dir.join_str("fit-kappa"));
    let text = hint(&hints, "bending-rigidity");
    assert!(
        text.contains("bending rigidity κ × 1.09") || text.contains("bending rigidity κ × 1.10"),
        "{text}"
    );
    assert!(stdout.contains(&format!("crank-nicolson: {text}")), "{d}");
    assert!(
        stdout.contains("    kappa = ")
            && stdout.contains(
                "kT known, sigma = 20 held (the law with that one parameter over them: χ² p = "
            ),
        "{d}"
    );
    assert!(
        stdout.contains("kappa known instead (one factor over them: χ² p = "),
        "{d}"
    );
    assert!(
        stdout.contains(" together from the variances of modes "),
        "{d}"
    );
    let (lo, hi) = interval(&run0["bending_rigidity"]);
    assert!(
        lo <= 1.1 && 1.1 <= hi && lo > 1.0 && hi / lo < 1.02,
        "kappa [{lo}, {hi}]: {d}"
    );
    assert!(lo > 1.09, "kappa [{lo}, {hi}]");
    let p = run0["bending_regression"]["p_value"].as_f64().unwrap();
    assert!(p > 1e-3, "the law with κ alone over the modes: p = {p}");
    let (lo, hi) = interval(&run0["drag"]);
    assert!(lo <= 1.0 && 1.0 <= hi, "xi [{lo}, {hi}]");
    let (lo, hi) = interval(&run0["joint"]["bending_rigidity"]);
    assert!(lo <= 1.1 && 1.1 <= hi, "joint kappa [{lo}, {hi}]");
    let (lo, hi) = interval(&run0["joint"]["tension"]);
    assert!(lo <= 20.0 && 20.0 <= hi, "joint sigma [{lo}, {hi}]");
    let (lo, hi) = interval(&run0["joint"]["drag"]);
    assert!(lo <= 1.0 && 1.0 <= hi, "joint xi [{lo}, {hi}]");

    let data = membrane_data_off(&dir, "sigma", "tension", "25.0");
    let (run0, _, d, hints) = fit(&data, &dir.join_str("fit-sigma"));
    let text = hint(&hints, "tension");
    let sigma: f64 = text.split("tension σ ≈ ").nth(1).unwrap()[..5]
        .parse()
        .unwrap();
    assert!((sigma / 25.0 - 1.0).abs() < 0.05, "{text}");
    let (lo, hi) = interval(&run0["joint"]["tension"]);
    assert!(
        lo <= 25.0 && 25.0 <= hi && lo > 20.0,
        "joint sigma [{lo}, {hi}]: {d}"
    );
    let (lo, hi) = interval(&run0["joint"]["bending_rigidity"]);
    assert!(lo <= 1.0 && 1.0 <= hi, "joint kappa [{lo}, {hi}]");
    let (lo, hi) = interval(&run0["joint"]["drag"]);
    assert!(lo <= 1.0 && 1.0 <= hi, "joint xi [{lo}, {hi}]");
    let p = run0["bending_regression"]["p_value"].as_f64().unwrap();
    assert!(p < 1e-3, "sigma held at the wrong value: p = {p}");
}

/// What: `check` shows progress on stderr while it prepares references that take
/// seconds, weighted by each run's projected set-up (`0.1 n³` DOF-steps for a beam of n
/// unknowns, a tenth of that for a run on a discretization already decomposed): two runs
/// declaring 500 elements project 0.1·1000³·(1 + 0.1) = 1.1e8 DOF-steps. Nothing with
/// `-q`, and nothing for data whose references take no time (10 elements).
#[test]
fn check_shows_progress_over_a_long_preparation() {
    let dir = TempDir::new("run-check-progress");
    let (data, out) = (dir.join_str("data"), dir.join_str("out"));
    let side = run_fixture("hinged-linear-2d", "4", &data);
    let check = |extra: &[&str]| {
        let mut args = vec!["check", "-s", "hinged-linear-2d", "-d", &data, "-o", &out];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(
            matches!(o.status.code(), Some(0 | 1)),
            "{}",
            describe(&args, &o)
        );
        stderr_of(&o)
    };
    let mut v = json(&side);
    let runs = v["runs"].as_array_mut().unwrap();
    runs.retain(|r| r["discretization"]["integrator"] == "crank-nicolson");
    assert_eq!(runs.len(), 2, "{runs:?}");
    std::fs::write(&side, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let small = check(&[]);
    assert!(!small.contains("progress:"), "{small}");
    for r in v["runs"].as_array_mut().unwrap() {
        r["discretization"]["elements"] = serde_json::json!(500);
    }
    std::fs::write(&side, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let large = check(&[]);
    let first = large.lines().find(|l| l.starts_with("progress:"));
    let first = first.unwrap_or_else(|| panic!("no progress line: {large}"));
    assert!(
        first.contains("hinged-linear-2d/") && first.contains("(references)"),
        "{first}"
    );
    assert!(first.contains("of 1.1e8 DOF-steps"), "{first}");
    let quiet = check(&["-q"]);
    assert!(!quiet.contains("progress:"), "{quiet}");
}

/// What: a scene's own data of one trajectory (what `run --trajectories 1` writes) are
/// checked, not aborted: the checks their size cannot serve are skipped with the reason
/// — the χ² goodness of fit of a mode (fewer thinned samples than 4 bins of 5), the
/// two-time correlations (one value per point) — and the rest are reported (exit 0, a
/// report). They aborted the whole check with exit 3 and no report: the tool chose 4
/// bins and then refused its own choice.
#[test]
fn one_trajectory_of_data_skips_what_it_cannot_serve() {
    let dir = TempDir::new("run-check-one");
    let (data, out) = (dir.join_str("data"), dir.join_str("out"));
    run_fixture("hinged-linear-2d", "1", &data);
    let args = [
        "check",
        "-q",
        "-s",
        "hinged-linear-2d",
        "-d",
        &data,
        "-o",
        &out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let summary = json(&Path::new(&out).join("summary.json"));
    let scene = &summary["scenes"][0];
    let skipped = scene["skipped"].as_array().unwrap();
    let reason = |kind: &str| {
        skipped
            .iter()
            .find(|s| s["name"].as_str().unwrap().contains(kind))
            .map(|s| s["reason"].as_str().unwrap().to_string())
            .unwrap_or_else(|| panic!("no skipped {kind}: {skipped:?}"))
    };
    assert!(
        reason("/mode-chi2-gof/").contains("needs at least 20 thinned samples"),
        "{skipped:?}"
    );
    assert!(
        reason("/two-time/").contains("needs at least 2 independent values"),
        "{skipped:?}"
    );
    let checks = scene["checks"].as_array().unwrap();
    for kind in ["/mode-ks/", "/mode-variance/"] {
        assert!(
            checks
                .iter()
                .any(|c| c["name"].as_str().unwrap().contains(kind)),
            "no {kind} check: {checks:?}"
        );
    }
}

/// What: `run` warns, before it simulates, when its trajectories would be too short for
/// its own `check` (the slowest mode sampled fewer than 8 times after the burn-in), with
/// the numbers `check`'s refusal then gives and a duration that serves; at that duration
/// it does not warn and `check` reads the files.
/// Tolerance: exact text (the rows `check` asks for).
#[test]
fn run_warns_of_trajectories_too_short_for_check() {
    let dir = TempDir::new("run-check-short");
    let out = dir.join_str("out");
    let written = |duration: &str| {
        let data = dir.join_str(&format!("data-{duration}"));
        let args = [
            "run",
            "-q",
            "-s",
            "hinged-linear-2d",
            "--run",
            "crank-nicolson",
            "--trajectories",
            "2",
            "--duration-tau1",
            duration,
            "-o",
            &data,
        ];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        (data, stderr_of(&o))
    };
    let check = |data: &str| {
        let args = [
            "check",
            "-q",
            "-s",
            "hinged-linear-2d",
            "-d",
            data,
            "-o",
            &out,
        ];
        run(&args)
    };
    let (short, warned) = written("2");
    for needle in [
        "warning: hinged-linear-2d/crank-nicolson:",
        "2001 rows after the burn-in",
        "needs at least 3992",
        "every 499 rows",
        "--duration-tau1 4 or more",
    ] {
        assert!(warned.contains(needle), "{needle:?} not in {warned}");
    }
    let o = check(&short);
    assert_eq!(o.status.code(), Some(2), "{}", stderr_of(&o));
    for needle in [
        "needs at least 3992 stationary rows",
        "got 2001 (a series of 5)",
    ] {
        assert!(stderr_of(&o).contains(needle), "{}", stderr_of(&o));
    }
    let (long, quiet) = written("4");
    assert!(!quiet.contains("warning"), "{quiet}");
    let o = check(&long);
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
}

/// `fit` says why it cannot fit a membrane, naming the cause (issue #27; found by
/// fuzzing, where it said the scene lacked mode-variance checks it had):
/// - data whose heights and amplitudes are all but zero (membrane-periodic's own, × 1e-300
///   after the time column): its mode-variance checks estimate no positive variance, and
///   the first one is named with its estimate;
/// - a membrane far above κq_min² (σ = 1e30 in scene and sidecar alike): the bending
///   shares κq⁴/(κq⁴ + σq²), about 1e-29, cannot carry κ with σ held, and the refusal
///   gives their range.
#[test]
fn fit_says_why_it_cannot_fit_a_membrane() {
    use langevin_fem::data::{NpyWriter, read_npy};
    let dir = TempDir::new("run-check-fit-cannot");
    let simulate = |scene: &str, out: &str| {
        let args = [
            "run",
            "-q",
            "--scene",
            scene,
            "--run",
            "crank-nicolson",
            "--out",
            out,
        ];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    };
    let fit = |scene: &str, data: &str, out: &str| {
        let args = ["fit", "-q", "--scene", scene, "--data", data, "--out", out];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(3), "{}", describe(&args, &o));
        stderr_of(&o)
    };

    let data = dir.join_str("tiny");
    simulate("membrane-periodic", &data);
    let runs = Path::new(&data).join("crank-nicolson");
    for entry in std::fs::read_dir(&runs).unwrap() {
        let path = entry.unwrap().path();
        let (rows, cols, values) = read_npy(&path, "file", 1 << 30).unwrap();
        let file = std::fs::File::create(&path).unwrap();
        let mut w = NpyWriter::new(std::io::BufWriter::new(file), rows as u64, cols).unwrap();
        for row in values.chunks(cols) {
            let scaled: Vec<f64> = (row.iter().enumerate())
                .map(|(c, &v)| if c == 0 { v } else { v * 1e-300 })
                .collect();
            w.push_row(&scaled).unwrap();
        }
        w.finish().unwrap();
    }
    let e = fit("membrane-periodic", &data, &dir.join_str("fit-tiny"));
    assert!(
        e.contains("without a positive estimate")
            && e.contains("crank-nicolson/mode-variance/n=1 estimates")
            && e.contains("all but zero"),
        "{e}"
    );

    let text = std::fs::read_to_string(fixture("verification/membrane-periodic.toml")).unwrap();
    let scene = dir.join_str("taut.toml");
    std::fs::write(
        &scene,
        text.replace("\ntension = 20.0\n", "\ntension = 1e30\n"),
    )
    .unwrap();
    let data = dir.join_str("taut");
    simulate(&scene, &data);
    let e = fit(&scene, &data, &dir.join_str("fit-taut"));
    assert!(
        e.contains("membrane.bending_rigidity must be fittable with sigma held")
            && e.contains("bending shares")
            && e.contains("e-29"),
        "{e}"
    );
}
