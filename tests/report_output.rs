//! Integration tests of the report layer: atomic writers, CSV/JSON output, SVG figures and
//! the HTML index.

mod common;

use common::svg::svg_texts;
use common::{TempDir, all_files};
use std::fs;
use std::path::Path;

use langevin_fem::Error;
use langevin_fem::output::{
    Figure, Manifest, ReportRun, Series, write_atomic, write_csv, write_json,
};
use langevin_fem::report::{render_index, write_index, write_report};
use langevin_fem::verify::summary::{CheckResult, SceneSummary, Summary};

fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("read dir")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

/// write_atomic creates missing parent directories, replaces existing content and leaves no
/// temporary file behind; a failed write names the destination path.
#[test]
fn write_atomic_replaces_content_and_leaves_no_temp_files() {
    let tmp = TempDir::new("atomic");
    let dir = tmp.path();
    let path = dir.join("nested").join("deeper").join("out.txt");
    write_atomic(&path, b"first version, longer than the second").expect("first write");
    assert_eq!(
        fs::read(&path).unwrap(),
        b"first version, longer than the second"
    );
    write_atomic(&path, b"second").expect("second write");
    assert_eq!(fs::read(&path).unwrap(), b"second");
    assert_eq!(file_names(path.parent().unwrap()), vec!["out.txt"]);

    // A regular file where a directory is needed: the error names the path.
    let blocked = dir
        .join("nested")
        .join("deeper")
        .join("out.txt")
        .join("x.txt");
    let err = write_atomic(&blocked, b"x").expect_err("parent is a file");
    assert!(matches!(err, Error::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("out.txt"), "{err}");
    assert_eq!(file_names(path.parent().unwrap()), vec!["out.txt"]);
}

/// write_csv refuses a row whose length differs from the header (and writes nothing).
#[test]
fn write_csv_rejects_ragged_rows() {
    let tmp = TempDir::new("csv_ragged");
    let dir = tmp.path();
    let path = dir.join("ragged.csv");
    let err = write_csv(&path, &["n", "variance"], &[vec![1.0, 0.5], vec![2.0]])
        .expect_err("ragged rows");
    assert!(matches!(err, Error::InvalidParameter { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("row 1") && msg.contains("ragged.csv"), "{msg}");
    assert!(!path.exists());
    assert!(file_names(dir).is_empty());
}

/// write_csv prints numbers with round-trip precision: every value, including extreme
/// magnitudes, subnormals, signed zero and non-finite values, parses back bit-identically.
#[test]
fn write_csv_round_trips_numbers() {
    let tmp = TempDir::new("csv_roundtrip");
    let dir = tmp.path();
    let path = dir.join("t.csv");
    let values = [
        0.1,
        1.0 / 3.0,
        std::f64::consts::PI,
        -2.5e17,
        6.022_140_76e23,
        1e-5,
        1.234_567_890_123_456_7e-4,
        123_456.789,
        f64::MIN_POSITIVE,
        5e-324,
        f64::MAX,
        -0.0,
        0.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    let rows: Vec<Vec<f64>> = values.chunks(4).map(<[f64]>::to_vec).collect();
    write_csv(&path, &["a", "b, with comma", "c", "d"], &rows).expect("write csv");

    let text = fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("a,\"b, with comma\",c,d"));
    let parsed: Vec<f64> = lines
        .flat_map(|line| line.split(','))
        .map(|field| field.parse::<f64>().expect("number parses"))
        .collect();
    assert_eq!(parsed.len(), values.len());
    for (got, want) in parsed.iter().zip(values) {
        if want.is_nan() {
            assert!(got.is_nan());
        } else {
            assert_eq!(got.to_bits(), want.to_bits(), "{got} vs {want}");
        }
    }
    assert!(text.contains(",nan\n"), "{text}");
    assert!(text.ends_with('\n'));
}

/// write_json writes exactly serde_json's pretty form plus a trailing newline, which
/// deserializes to the same structure. (Floats are compared only through the text: without
/// serde_json's `float_roundtrip` feature its parser may be off by one ulp.)
#[test]
fn write_json_is_pretty_and_round_trips() {
    let tmp = TempDir::new("json");
    let dir = tmp.path();
    let path = dir.join("summary.json");
    let summary = sample_summary();
    write_json(&path, &summary).expect("write json");
    let text = fs::read_to_string(&path).unwrap();
    assert!(text.ends_with("}\n"));
    assert!(text.contains("\n  \"budget\": \"quick\""), "{text}");
    assert_eq!(text, serde_json::to_string_pretty(&summary).unwrap() + "\n");
    let back: Summary = serde_json::from_str(&text).expect("parse back");
    assert_eq!(back.scenes.len(), summary.scenes.len());
    assert_eq!(
        back.scenes[1].checks[0].name,
        summary.scenes[1].checks[0].name
    );
}

/// A figure with two series, error bars, a reference line and log axes renders an SVG whose
/// <text> elements contain the title, both axis labels and every legend label, and a
/// second render is byte-identical.
#[test]
fn figure_with_errors_and_log_axes_renders_labels_deterministically() {
    let n: Vec<f64> = (1..=12).map(f64::from).collect();
    let estimate: Vec<(f64, f64)> = n.iter().map(|&k| (k, 2.0 / (k * k * k * k))).collect();
    let errors: Vec<f64> = estimate.iter().map(|&(_, v)| 0.1 * v).collect();
    let exact: Vec<(f64, f64)> = n.iter().map(|&k| (k, 2.0 / (k * k * k * k))).collect();
    let fig = Figure::new(
        "Mode variances <a_n²> vs mode number",
        "mode number n",
        "variance ⟨a_n²⟩ (µm²)",
    )
    .log_x()
    .log_y()
    .series(Series::markers("simulation ± 1 s.e.", estimate).with_errors(errors))
    .series(Series::line("exact (discrete)", exact).dashed())
    .hline(1e-3, "resolution limit");

    let svg = fig.render_svg().expect("render");
    assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
    assert!(svg.trim_end().ends_with("</svg>"));
    let texts = svg_texts(&svg);
    for want in [
        "Mode variances <a_n²> vs mode number",
        "mode number n",
        "variance ⟨a_n²⟩ (µm²)",
        "simulation ± 1 s.e.",
        "exact (discrete)",
        "resolution limit",
    ] {
        assert!(
            texts.iter().any(|t| t == want),
            "missing text {want:?} in {texts:?}"
        );
    }
    // The markup itself is escaped.
    assert!(svg.contains("&lt;a_n²&gt;"));
    // Decade tick labels on the log axes.
    assert!(texts.iter().any(|t| t == "10⁰"), "{texts:?}");
    // Two series colours and error bars (vertical polylines in the first colour).
    assert!(svg.contains("#1F77B4") && svg.contains("#FF7F0E"));

    let again = fig.render_svg().expect("second render");
    assert_eq!(svg, again, "rendering is not deterministic");
}

/// Non-finite points, non-positive values on a log axis, mismatched data and a figure without
/// any drawable point: rendering does not fail (except for the mismatched error bars), and
/// the figure says what it left out.
#[test]
fn figure_with_nan_and_nonpositive_on_log_axis_does_not_fail() {
    let tmp = TempDir::new("figure_robust");
    let dir = tmp.path();
    let fig = Figure::new("robustness", "t", "C(t)")
        .log_y()
        .series(
            Series::line(
                "autocorrelation",
                vec![
                    (0.0, 1.0),
                    (1.0, 0.5),
                    (2.0, f64::NAN),
                    (3.0, 0.1),
                    (4.0, 0.0),
                    (5.0, -0.02),
                    (f64::INFINITY, 0.3),
                    (6.0, 0.01),
                ],
            )
            .with_errors(vec![0.1, 0.6, 0.1, 0.2, 0.1, 0.1, 0.1, f64::NAN]),
        )
        .hline(-1.0, "not drawable on a log axis");
    let path = dir.join("figs").join("robust.svg");
    fig.write_svg(&path).expect("renders despite bad points");
    let svg = fs::read_to_string(&path).unwrap();
    let texts = svg_texts(&svg);
    assert!(
        texts.iter().any(|t| t == "4 points and 1 reference line not shown (non-finite, or not positive on a log axis)"),
        "{texts:?}"
    );

    let empty = Figure::new("nothing yet", "x", "y")
        .log_x()
        .series(Series::markers(
            "all NaN",
            vec![(f64::NAN, 1.0), (-1.0, 2.0)],
        ));
    let svg = empty.render_svg().expect("empty figure renders");
    assert!(
        svg_texts(&svg)
            .iter()
            .any(|t| t == "no finite data to plot")
    );
    let svg = Figure::new("no series", "x", "y")
        .render_svg()
        .expect("figure without series renders");
    assert!(
        svg_texts(&svg)
            .iter()
            .any(|t| t == "no finite data to plot")
    );

    let bad = Figure::new("bad", "x", "y")
        .series(Series::markers("s", vec![(1.0, 1.0), (2.0, 2.0)]).with_errors(vec![0.1]));
    let err = bad.render_svg().expect_err("error-bar count mismatch");
    assert!(matches!(err, Error::InvalidParameter { .. }), "{err:?}");
}

fn check(name: &str, passed: bool, p: Option<f64>) -> CheckResult {
    CheckResult {
        name: name.to_string(),
        run: String::new(),
        check: String::new(),
        parameter: String::new(),
        kind: "chi2-variance".to_string(),
        statistic: Some(4.2),
        dof: Some(3.0),
        unit: "[L]^2".to_string(),
        passed,
        p_value: p,
        p_adjusted: p.map(|p| (3.0 * p).min(1.0)),
        estimate: Some(0.123_456_7),
        reference: Some(0.125),
        std_error: None,
        continuum: Some(0.126),
        reference_kind: "discrete".to_string(),
        detail: "n = 4000 samples & 3 lags".to_string(),
        largest_deviation: None,
        variance_correlation: None,
    }
}

fn sample_summary() -> Summary {
    Summary {
        run_id: "20250101T120000Z-4242-1a2b3c4d".to_string(),
        budget: "quick".to_string(),
        alpha: 0.01,
        passed: false,
        scenes: vec![
            SceneSummary {
                name: "clamped_free".to_string(),
                passed: true,
                wall_seconds: 1.25,
                figures: vec![
                    "clamped_free/mode_variance.svg".to_string(),
                    "clamped_free/autocorrelation.svg".to_string(),
                ],
                tables: vec!["clamped_free/mode_variance.csv".to_string()],
                warnings: vec![],
                skipped: vec![],
                captions: vec![],
                notes: vec!["ratio → 1 as elements increase".to_string()],
                checks: vec![
                    check("mode-variance/n=1", true, Some(0.42)),
                    check("energy/equipartition", true, None),
                ],
                detectable: vec![],
                hints: vec![],
            },
            SceneSummary {
                name: "pinned".to_string(),
                passed: false,
                wall_seconds: 12.5,
                figures: vec!["pinned/msd.svg".to_string()],
                tables: vec![],
                warnings: vec![],
                skipped: vec![],
                captions: vec![],
                notes: vec![],
                checks: vec![
                    check("msd/<script>alert(1)</script>", true, Some(0.3)),
                    check("msd/late-time", false, Some(1.234_567e-9)),
                ],
                detectable: vec![],
                hints: vec![langevin_fem::verify::diagnosis::RunHint {
                    run: "msd".to_string(),
                    pattern: langevin_fem::verify::diagnosis::Pattern::Tension,
                    text: "hint: … — tension σ ≈ 24.09 rather than 20?".to_string(),
                }],
            },
        ],
        files: vec![
            "clamped_free/mode_variance.csv".to_string(),
            "index.html".to_string(),
            "manifest.json".to_string(),
            "summary.json".to_string(),
        ],
        provenance: None,
    }
}

/// `summary.json` follows its JSON Schema (src/verify/summary.schema.json), and the
/// validator rejects what departs from it: a key missing, a key not in the schema, a
/// wrong type, a value outside an enum.
#[test]
fn summary_json_follows_its_schema_and_departures_are_found() {
    let schema = common::schema::summary_schema();
    let value = serde_json::to_value(sample_summary()).unwrap();
    let v = common::schema::violations(&schema, &value);
    assert!(v.is_empty(), "{v:#?}");
    let broken = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut b = value.clone();
        f(&mut b);
        common::schema::violations(&schema, &b)
    };
    let v = broken(&|b| {
        b["scenes"][0]["checks"][0]
            .as_object_mut()
            .unwrap()
            .remove("dof");
    });
    assert!(v.iter().any(|e| e.contains("required key dof")), "{v:?}");
    let v = broken(&|b| b["scenes"][1]["extra"] = serde_json::json!(1));
    assert!(
        v.iter().any(|e| e.contains("key extra not in the schema")),
        "{v:?}"
    );
    let v = broken(&|b| b["scenes"][0]["checks"][1]["statistic"] = serde_json::json!("4.2"));
    assert!(v.iter().any(|e| e.contains("statistic")), "{v:?}");
    let v = broken(&|b| b["scenes"][0]["checks"][0]["reference_kind"] = serde_json::json!("x"));
    assert!(v.iter().any(|e| e.contains("not one of")), "{v:?}");
    let v = broken(&|b| b["scenes"][1]["hints"][0]["pattern"] = serde_json::json!("kappa"));
    assert!(v.iter().any(|e| e.contains("not one of")), "{v:?}");
}

/// index.html embeds every figure, names every check (HTML-escaped, so a `<script>` in a
/// check name stays text), marks the failing check, and write_index writes the same page.
#[test]
fn index_html_lists_figures_and_checks_and_escapes_text() {
    let summary = sample_summary();
    let html = render_index(&summary);

    assert!(html.starts_with("<!DOCTYPE html>"));
    for scene in &summary.scenes {
        for fig in &scene.figures {
            assert!(
                html.contains(&format!("<img src=\"{fig}\"")),
                "missing {fig}"
            );
        }
        for table in &scene.tables {
            assert!(
                html.contains(&format!("href=\"{table}\"")),
                "missing {table}"
            );
        }
        for c in &scene.checks {
            let escaped = c.name.replace('<', "&lt;").replace('>', "&gt;");
            assert!(html.contains(&escaped), "missing check {}", c.name);
        }
    }
    assert!(!html.contains("<script"), "unescaped script tag");
    assert!(html.contains("msd/&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(html.contains("n = 4000 samples &amp; 3 lags"));
    // The failing check's row is marked, and so are its scene and the whole run; the
    // verdict comes first, then the failures (the failing check, linked to its scene),
    // then the scenes.
    assert!(html.contains("<tr class=\"check fail\"><td><a href=\"#scene-1\">pinned</a></td>"));
    assert!(html.contains("<td class=\"fail\">FAIL</td>"));
    assert!(html.contains("<tr class=\"check pass\"><td>(scene)</td>"));
    let at = |s: &str| html.find(s).unwrap_or_else(|| panic!("missing {s}"));
    assert!(
        at("<div class=\"verdict fail\" id=\"verdict\"><span class=\"word\">FAILED</span>")
            < at("id=\"failures\"")
    );
    assert!(at("id=\"failures\"") < at("id=\"scenes\""));
    assert!(html.contains("3 passed, 1 failed, 0 skipped"));
    // The check tables are collapsed; columns keep one meaning (statistic, dof, unit).
    assert!(html.contains("<details class=\"checks\"><summary>All 2 checks"));
    assert!(html.contains(">4.200<") && html.contains(">3<") && html.contains(">[L]^2<"));
    // The run id, as in summary.json.
    assert!(html.contains("<code id=\"run-id\">20250101T120000Z-4242-1a2b3c4d</code>"));
    // Numbers to 4 significant digits, a dash where there is no value, Holm mentioned.
    assert!(html.contains(">0.1235<") && html.contains(">1.235e-9<"));
    assert!(html.contains(">—<"));
    assert!(html.contains("Holm"));
    // Self-contained: no scripts, no external resources.
    assert!(!html.contains("http://") && !html.contains("https://"));

    let tmp = TempDir::new("index");
    let dir = tmp.path();
    write_index(dir, &summary).expect("write index");
    let written = fs::read_to_string(dir.join("index.html")).unwrap();
    // As rendered, with the convergence section saying how to make it (no link to a
    // folder that does not exist).
    assert!(!written.contains("href=\"convergence/index.html\""));
    assert!(written.contains("id=\"convergence\""));
    let (a, b) = html.split_once("<!-- convergence -->\n").unwrap();
    assert!(written.starts_with(a) && written.ends_with(b));
    assert_eq!(file_names(dir), vec!["index.html"]);
}

// ---------------------------------------------------------------------------------------
// Report runs: run id, journal, consistency after interruption and reruns
// (src/output/manifest.rs; issue #12)
// ---------------------------------------------------------------------------------------

fn journal(dir: &Path) -> Manifest {
    serde_json::from_str(&fs::read_to_string(dir.join("manifest.json")).expect("journal"))
        .expect("journal parses")
}

const ENTRIES: [&str; 2] = ["summary.json", "index.html"];

/// A complete report run writing `files` (relative) in `dir`; returns its run id.
fn complete_run(dir: &Path, files: &[&str]) -> String {
    let run = ReportRun::begin(dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    for f in files {
        run.write(&dir.join(f), f.as_bytes()).expect("write");
    }
    let id = run.run_id();
    run.finish(&[
        ("summary.json", id.as_bytes()),
        ("index.html", id.as_bytes()),
    ])
    .expect("finish");
    id
}

/// What: a rerun leaves the earlier report byte for byte as it was while it runs (its
/// files wait in a staging directory, issue #25), and at its end swaps: the earlier
/// run's files it did not write are removed (a dropped scene, its then empty folder
/// too), every file it never wrote is kept (a user's file, a `convergence/` folder), and
/// the journal lists exactly the files of the directory that are its own.
/// Tolerance: exact (file sets and bytes).
#[test]
fn a_rerun_leaves_the_old_report_until_it_finishes_and_removes_dropped_files() {
    let tmp = TempDir::new("report-run");
    let dir = tmp.path();
    let first = complete_run(dir, &["a/x.csv", "b/y.csv", "b/y.svg", "fig2.svg"]);
    fs::write(dir.join("notes.txt"), b"mine").unwrap();
    fs::create_dir_all(dir.join("convergence")).unwrap();
    fs::write(dir.join("convergence/index.html"), b"other command").unwrap();
    let j = journal(dir);
    assert!(j.complete && j.run_id == first && j.superseded.is_empty());
    let before = tree_bytes(dir);

    let run = ReportRun::begin(dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    run.write(&dir.join("a/x.csv"), b"new").expect("write");
    run.write(&dir.join("a/z.csv"), b"new").expect("write");
    assert_eq!(tree_bytes(dir), before, "the earlier report is untouched");
    let id = run.run_id();
    assert_ne!(id, first);
    let files = run.files();
    run.finish(&[("summary.json", b"s"), ("index.html", b"i")])
        .expect("finish");

    assert!(!dir.join("b").exists(), "dropped scene's folder removed");
    assert!(!dir.join("fig2.svg").exists());
    assert_eq!(fs::read(dir.join("a/x.csv")).unwrap(), b"new");
    assert_eq!(
        all_files(dir),
        [
            "a/x.csv",
            "a/z.csv",
            "convergence/index.html",
            "index.html",
            "manifest.json",
            "notes.txt",
            "summary.json"
        ]
    );
    let j = journal(dir);
    assert!(j.complete && j.run_id == id && j.superseded.is_empty());
    assert_eq!(j.files, files);
    assert_eq!(
        files,
        [
            "a/x.csv",
            "a/z.csv",
            "index.html",
            "manifest.json",
            "summary.json"
        ]
    );
}

/// What: a run never replaces what it does not own below the top level (issue #25): a
/// user's file at the name of one of its files, in a directory no journal describes or
/// that the earlier run of the same command did not write, and a file where one of its
/// directories must go, make its finish refuse with exit 2 (`--out`, naming the entry),
/// before anything is moved or removed: the tree, entry points and earlier report
/// included, is byte for byte as it was. The earlier run's own files are replaced.
/// Tolerance: exact (file sets and bytes).
#[test]
fn a_run_refuses_to_replace_files_it_does_not_own() {
    let tmp = TempDir::new("report-taken");
    let dir = tmp.path().join("out");
    // No journal: a user's file where the run writes.
    fs::create_dir_all(dir.join("a")).unwrap();
    fs::write(dir.join("a/x.csv"), b"mine").unwrap();
    let before = tree_bytes(&dir);
    let run = ReportRun::begin(&dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    run.write(&dir.join("a/x.csv"), b"new").expect("write");
    let err = run
        .finish(&[("summary.json", b"s"), ("index.html", b"i")])
        .expect_err("a user's file at a file's name");
    assert_eq!(err.exit_code(), 2, "{err}");
    assert!(
        err.to_string().contains("--out") && err.to_string().contains("a/x.csv"),
        "{err}"
    );
    assert_eq!(tree_bytes(&dir), before);
    assert_eq!(all_files(&dir), ["a/x.csv"], "no staging left");

    // An earlier report of the same command, and a user's files beside its own.
    fs::remove_dir_all(&dir).unwrap();
    complete_run(&dir, &["a/x.csv"]);
    fs::write(dir.join("a/mine.csv"), b"mine").unwrap();
    fs::write(dir.join("b"), b"a file where a directory must go").unwrap();
    let before = tree_bytes(&dir);
    for (rel, obstacle) in [("a/mine.csv", "a/mine.csv"), ("b/y.csv", "b")] {
        let run = ReportRun::begin(&dir, "verify", "manifest.json", &ENTRIES).expect("begin");
        run.write(&dir.join("a/x.csv"), b"new").expect("write");
        run.write(&dir.join(rel), b"new").expect("write");
        let err = run
            .finish(&[("summary.json", b"s"), ("index.html", b"i")])
            .expect_err(rel);
        assert_eq!(err.exit_code(), 2, "{err}");
        assert!(
            err.to_string().contains(&format!("holds {obstacle},")),
            "{err}"
        );
        assert_eq!(tree_bytes(&dir), before, "{rel}: nothing moved or removed");
    }
    // Its own earlier file it replaces.
    let run = ReportRun::begin(&dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    run.write(&dir.join("a/x.csv"), b"newer").expect("write");
    run.finish(&[("summary.json", b"s"), ("index.html", b"i")])
        .expect("finish");
    assert_eq!(fs::read(dir.join("a/x.csv")).unwrap(), b"newer");
    assert_eq!(fs::read(dir.join("a/mine.csv")).unwrap(), b"mine");
}

/// Every file under `dir` with its bytes, but those of a run's staging directory (where
/// its files wait, unseen, until it finishes).
fn tree_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    all_files(dir)
        .into_iter()
        .filter(|f| !f.starts_with(".langevin-fem-staging."))
        .map(|f| {
            let bytes = fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect()
}

/// What: a run killed or failing before it finishes leaves the earlier report byte for
/// byte (nothing but its staging directory was written, and that is dropped); a run
/// killed during the swap at its end (an incomplete journal naming its files and the
/// earlier ones) is cleaned up by the next, which removes the files it does not write.
/// A journal entry pointing outside the directory is never followed, and a write outside
/// the directory is refused.
/// Tolerance: exact (file sets and bytes).
#[test]
fn an_interrupted_run_leaves_the_earlier_report_and_nothing_outside_is_touched() {
    let tmp = TempDir::new("report-killed");
    let dir = tmp.path().join("out");
    complete_run(&dir, &["a/x.csv"]);
    let before = tree_bytes(&dir);
    let killed = ReportRun::begin(&dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    killed
        .write(&dir.join("c/new.csv"), b"half a run")
        .expect("write");
    drop(killed); // as if it failed: no finish
    assert_eq!(tree_bytes(&dir), before, "the earlier report is untouched");
    assert_eq!(all_files(&dir).len(), before.len(), "no staging left");

    // Killed during the swap: an incomplete journal naming a file of its own.
    fs::create_dir_all(dir.join("c")).unwrap();
    fs::write(dir.join("c/new.csv"), b"half a swap").unwrap();
    let mut j = journal(&dir);
    j.complete = false;
    j.superseded = j.files.clone();
    j.files = vec!["c/new.csv".to_string()];
    // ... and tampered, naming a file outside the directory.
    let outside = tmp.path().join("outside.txt");
    fs::write(&outside, b"keep").unwrap();
    j.superseded.push("../outside.txt".to_string());
    fs::write(
        dir.join("manifest.json"),
        serde_json::to_string(&j).unwrap(),
    )
    .unwrap();

    let run = ReportRun::begin(&dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    let err = run
        .write(&tmp.path().join("escape.csv"), b"x")
        .expect_err("outside the directory");
    assert!(matches!(err, Error::Io { .. }), "{err:?}");
    assert!(!tmp.path().join("escape.csv").exists());
    run.write(&dir.join("a/x.csv"), b"x").expect("write");
    run.finish(&[("summary.json", b"s"), ("index.html", b"i")])
        .expect("finish");
    assert_eq!(
        all_files(&dir),
        ["a/x.csv", "index.html", "manifest.json", "summary.json"]
    );
    assert!(outside.exists());
}

/// What: `write_report` writes `summary.json` and `index.html` last, with the same run id
/// as the journal, and `summary.json` lists exactly the files of the directory.
/// Tolerance: exact.
#[test]
fn write_report_puts_one_run_id_in_summary_index_and_journal() {
    let tmp = TempDir::new("write-report");
    let dir = tmp.path();
    let run = ReportRun::begin(dir, "verify", "manifest.json", &ENTRIES).expect("begin");
    run.write_csv(&dir.join("s/t.csv"), &["a"], &[vec![1.0]])
        .expect("csv");
    let mut summary = sample_summary();
    summary.run_id = run.run_id();
    summary.files = run.files();
    write_report(run, &summary).expect("report");
    let back: Summary =
        serde_json::from_str(&fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(back.files, all_files(dir));
    assert_eq!(back.run_id, journal(dir).run_id);
    let html = fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(html.contains(&format!("<code id=\"run-id\">{}</code>", back.run_id)));
}
