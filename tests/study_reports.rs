//! The shared study folder (`converge`, `stability`, `work-precision` into one `--out`)
//! after interruption and rerun, through the binary (issue #12, Deliver 5).
//!
//! What: (1) `stability` and `converge` killed (SIGKILL) at seeded-random moments — some
//! spread over the whole run, some just after the study starts writing (its journal turns
//! incomplete; chased with immediate kills until one lands while it writes) — and rerun to completion leave a consistent folder: no temporary file;
//! `index.html` lists exactly the studies whose journal (`<stem>.manifest.json`) is
//! complete, each with its journal's run id; every file of the folder is named by a
//! complete journal (verify's `extreme/` report apart); every file a complete journal
//! names exists, and each summary carries its journal's run id. Right after each kill,
//! every file is attributable to a journal and an index, if any, lists only complete
//! journals. (2) A second, different study into the folder keeps the first one's files;
//! a rerun of `stability` with fewer integrators removes the maps it no longer writes and
//! keeps the other studies' files, a user's own file and a summary no journal names;
//! a temporary file of a dead writer is removed by the next run.
//! Reference: the guide, docs/src/reference/reports.md; `src/studies/output.rs`;
//! `src/output/manifest.rs`.
//! Set-up: the smallest settings of the Makefile's verify target, scaled down (well under
//! a second per run on 2 cores); about 20 runs in all.
//! Tolerance: exact (file sets, ids and exit codes). Kill moments come from a fixed seed,
//! so the test asks the same every time while covering the runs from start to end.

mod common;

use common::{TempDir, all_files, command, describe, json, run, strings};
use serde_json::Value;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Interruptions per study in the kill test.
const KILLS: u64 = 4;
/// Seed of the kill moments.
const KILL_SEED: u64 = 0x5eed_0512;
/// At most this many immediate kills chase the writing window if no seeded kill hit it.
const CHASES: u64 = 40;

/// `stability`: 10 elements, below and above the explicit limit, 20000 steps.
fn stability_args(out: &Path, integrators: &str) -> Vec<String> {
    [
        "stability",
        "--scene",
        "hinged-linear-2d",
        "--integrators",
        integrators,
        "--elements",
        "10",
        "--dt-lambda-max",
        "0.1,2.1",
        "--steps",
        "20000",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([out.display().to_string()])
    .collect()
}

const ALL_INTEGRATORS: &str = "euler-maruyama,backward-euler,crank-nicolson,exact-modal";

/// `converge`: compression, <F> at eps = 0 over 5, 10, 20 elements, 16 x 400 tau1.
fn converge_args(out: &Path) -> Vec<String> {
    [
        "converge",
        "--scene",
        "compression-2d",
        "--over",
        "elements",
        "--values",
        "5,10,20",
        "--strain-ratios",
        "0",
        "--trajectories",
        "16",
        "--duration-tau1",
        "400",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([out.display().to_string()])
    .collect()
}

/// `work-precision`: one method at one step, 2 x 40 tau1.
fn work_precision_args(out: &Path) -> Vec<String> {
    [
        "work-precision",
        "--methods",
        "crank-nicolson/consistent",
        "--dt-tau1",
        "1e-2",
        "--trajectories",
        "2",
        "--duration",
        "40",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([out.display().to_string()])
    .collect()
}

/// Runs the binary with `args` to completion, asserting exit 0; returns the wall time.
fn run_ok(args: &[String]) -> Duration {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let start = Instant::now();
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    start.elapsed()
}

/// A study journal of the folder.
#[derive(Debug)]
struct Journal {
    name: String,
    run_id: String,
    complete: bool,
    /// `files` and `superseded`.
    named: Vec<String>,
}

/// Every `*.manifest.json` directly in `out`, sorted by name.
fn journals(out: &Path) -> Vec<Journal> {
    all_files(out)
        .into_iter()
        .filter(|f| !f.contains('/') && f.ends_with(".manifest.json"))
        .map(|name| {
            let j = json(&out.join(&name));
            Journal {
                run_id: j["run_id"].as_str().expect("run id").to_string(),
                complete: j["complete"].as_bool().expect("complete"),
                named: strings(&j["files"])
                    .into_iter()
                    .chain(strings(&j["superseded"]))
                    .collect(),
                name,
            }
        })
        .collect()
}

/// The (journal, run id) pairs the index lists, sorted.
fn index_entries(out: &Path) -> Vec<(String, String)> {
    let html = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    let tag = "<code class=\"run-id\" data-journal=\"";
    let mut entries: Vec<(String, String)> = html
        .match_indices(tag)
        .map(|(i, _)| {
            let rest = &html[i + tag.len()..];
            let (journal, rest) = rest.split_once("\">").expect("attribute closed");
            let id = &rest[..rest.find("</code>").expect("code closed")];
            (journal.to_string(), id.to_string())
        })
        .collect();
    entries.sort();
    entries
}

/// Whether `f` belongs to verify's extreme-scene report, which the folder index links.
fn verifys(f: &str) -> bool {
    f.starts_with("extreme/")
}

/// A finished folder: no temporary file; every journal complete and listed by the index
/// with its run id, and nothing else listed; every file named by a complete journal (or
/// verify's); every file a journal names present; each summary with its journal's id.
fn assert_consistent(out: &Path, ctx: &str) {
    let files = all_files(out);
    assert!(
        !files.iter().any(|f| common::transient(f)),
        "{ctx}: temporary or staged files left: {files:?}"
    );
    let journals = journals(out);
    assert!(!journals.is_empty(), "{ctx}: no journal");
    assert!(
        journals.iter().all(|j| j.complete),
        "{ctx}: incomplete journal after a complete run: {journals:?}"
    );
    let expected: Vec<(String, String)> = journals
        .iter()
        .map(|j| (j.name.clone(), j.run_id.clone()))
        .collect();
    assert_eq!(
        index_entries(out),
        expected,
        "{ctx}: index against journals"
    );
    for f in &files {
        assert!(
            verifys(f) || journals.iter().any(|j| j.named.contains(f)),
            "{ctx}: {f} is named by no complete journal ({journals:?})"
        );
    }
    for j in &journals {
        for f in &j.named {
            assert!(files.contains(f), "{ctx}: {} names {f}, missing", j.name);
        }
        let summary = j.name.replace(".manifest.json", ".json");
        assert_eq!(
            json(&out.join(&summary))["run_id"].as_str(),
            Some(j.run_id.as_str()),
            "{ctx}: {summary}"
        );
    }
}

/// Right after a kill: every file is a temporary or staged file (removed by the next run), or
/// named by some journal, or verify's; an index, if present, lists only complete journals
/// with their run ids; a summary, if present, carries the run id of its journal (it is
/// written just before the journal is marked complete, and removed before a new run's
/// journal is written).
fn assert_attributable(out: &Path, ctx: &str) {
    let journals = journals(out);
    for f in all_files(out) {
        let ours = journals.iter().any(|j| j.name == f || j.named.contains(&f));
        assert!(
            ours || verifys(&f) || common::transient(&f),
            "{ctx}: {f} is not attributable to a run ({journals:?})"
        );
    }
    if out.join("index.html").exists() {
        for (journal, id) in index_entries(out) {
            let j = journals.iter().find(|j| j.name == journal);
            assert!(
                j.is_some_and(|j| j.complete && j.run_id == id),
                "{ctx}: the index lists {journal} {id}, journals {journals:?}"
            );
        }
    }
    for j in &journals {
        let summary = out.join(j.name.replace(".manifest.json", ".json"));
        if summary.exists() {
            assert_eq!(
                json(&summary)["run_id"].as_str(),
                Some(j.run_id.as_str()),
                "{ctx}: {} beside {j:?}",
                summary.display()
            );
        }
    }
}

/// The next value of a 64-bit LCG, as a uniform number in [0, 1).
fn uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Whether the journal `out/journal` names a run other than `before` as incomplete:
/// the study has started writing.
fn writing(out: &Path, journal: &str, before: &str) -> bool {
    let Ok(text) = std::fs::read_to_string(out.join(journal)) else {
        return false;
    };
    serde_json::from_str::<Value>(&text)
        .is_ok_and(|j| j["complete"] == Value::Bool(false) && j["run_id"] != before)
}

/// Starts `args` and kills it (SIGKILL): after `delay`, or, with `at_writing`, `delay`
/// after its journal `journal` turns incomplete (polled every 0.2 ms). Returns what
/// happened, for the failure messages.
fn kill_during(args: &[String], delay: Duration, at_writing: Option<&str>, out: &Path) -> String {
    let before = at_writing
        .map(|j| {
            json(&out.join(j))["run_id"]
                .as_str()
                .unwrap_or("")
                .to_string()
        })
        .unwrap_or_default();
    let mut child = command()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    let start = Instant::now();
    let what = match at_writing {
        None => {
            std::thread::sleep(delay);
            format!("killed after {delay:?}")
        }
        Some(journal) => loop {
            if writing(out, journal, &before) {
                if !delay.is_zero() {
                    std::thread::sleep(delay);
                }
                break format!("killed {delay:?} after writing started");
            }
            if child.try_wait().expect("wait").is_some() {
                break "finished before the kill".to_string();
            }
            if start.elapsed() > Duration::from_secs(30) {
                break "killed after 30 s without writing".to_string();
            }
            if delay.is_zero() {
                std::thread::yield_now();
            } else {
                std::thread::sleep(Duration::from_micros(200));
            }
        },
    };
    let _ = child.kill();
    let status = child.wait().expect("wait");
    format!("{} {what} (status {status})", args[0])
}

/// Kills `args` ([`kill_during`]), checks that every file left is attributable, reruns
/// it to completion and checks the folder is consistent. Returns what happened and what
/// the kill left of the study's journal `journal`.
fn kill_check_rerun(
    args: &[String],
    journal: &str,
    delay: Duration,
    at_writing: Option<&str>,
    out: &Path,
) -> String {
    let what = kill_during(args, delay, at_writing, out);
    let left = match journals(out).iter().find(|j| j.name == journal) {
        Some(j) if j.complete => "its journal complete",
        Some(_) => "its journal incomplete",
        None => "no journal",
    };
    let what = format!("{what}, leaving {left}");
    eprintln!("{what}");
    assert_attributable(out, &what);
    run_ok(args);
    assert_consistent(out, &format!("{what}, then rerun"));
    what
}

/// (1) Killed at seeded-random moments and rerun: always a consistent folder. The first
/// half of each study's kills are spread over its whole run, the second half land within
/// a millisecond after it starts writing; if none of them landed while it writes, further
/// immediate kills chase that window until one does.
#[test]
fn studies_killed_at_random_moments_and_rerun_leave_a_consistent_folder() {
    let dir = TempDir::new("study-kill");
    let out = dir.join("convergence");
    std::fs::create_dir_all(out.join("extreme")).unwrap();
    std::fs::write(out.join("extreme/index.html"), b"verify's extreme scenes").unwrap();
    let stability = stability_args(&out, ALL_INTEGRATORS);
    let converge = converge_args(&out);
    let full = [run_ok(&stability), run_ok(&converge)];
    assert_consistent(&out, "first runs");
    assert_eq!(journals(&out).len(), 2);
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("extreme/index.html"), "verify's link kept");

    let studies = [
        (&stability, "stability.manifest.json"),
        (
            &converge,
            "compression-2d-metropolis-elements.manifest.json",
        ),
    ];
    let mut state = KILL_SEED;
    let mut outcomes = Vec::new();
    for i in 0..KILLS {
        for (k, &(args, journal)) in studies.iter().enumerate() {
            let u = uniform(&mut state);
            let (delay, at_writing) = if i < KILLS / 2 {
                (full[k].mul_f64(u), None)
            } else {
                (Duration::from_micros((u * 1000.0) as u64), Some(journal))
            };
            let what = kill_check_rerun(args, journal, delay, at_writing, &out);
            outcomes.push(format!("kill {i}: {what}"));
        }
    }
    // The window in which a study's files and journal are half-written lasts a few
    // hundred microseconds, so the seeded delays may all miss it on a fast disk. Until a
    // kill has landed in it, chase it: kill as soon as the journal turns incomplete
    // (polled without sleeping), alternating the studies, at most CHASES times.
    let mut chases = 0;
    while !outcomes.iter().any(|w| w.ends_with("journal incomplete")) && chases < CHASES {
        let (args, journal) = studies[(chases % 2) as usize];
        let what = kill_check_rerun(args, journal, Duration::ZERO, Some(journal), &out);
        outcomes.push(format!("chase {chases}: {what}"));
        chases += 1;
    }
    // The targeted kills exercised the window in which a study's files and journal are
    // half-written.
    assert!(
        outcomes.iter().any(|w| w.ends_with("journal incomplete")),
        "no kill landed while a study was writing: {outcomes:#?}"
    );
    assert_eq!(journals(&out).len(), 2, "{outcomes:?}");
    assert!(
        out.join("extreme/index.html").exists(),
        "verify's report kept"
    );
}

/// (2) Studies keep each other's files; a rerun with fewer integrators removes its
/// dropped maps and nothing else; a dead writer's temporary file is removed.
#[test]
fn studies_share_the_folder_and_a_smaller_rerun_removes_only_its_own_dropped_files() {
    let dir = TempDir::new("study-share");
    let out = dir.join("convergence");
    std::fs::create_dir_all(&out).unwrap();
    // A user's file and a summary of an older version that no journal names.
    std::fs::write(out.join("notes.txt"), b"mine").unwrap();
    std::fs::write(out.join("old-study-elements.json"), b"{}").unwrap();
    let foreign = ["notes.txt", "old-study-elements.json"];

    run_ok(&stability_args(&out, ALL_INTEGRATORS));
    let maps = |out: &Path| -> Vec<String> {
        all_files(out)
            .into_iter()
            .filter(|f| f.starts_with("stability-map-"))
            .collect()
    };
    assert_eq!(maps(&out).len(), 4, "{:?}", all_files(&out));
    let first_stability = json(&out.join("stability.json"))["run_id"].clone();

    run_ok(&converge_args(&out));
    run_ok(&work_precision_args(&out));
    let before = all_files(&out);
    assert!(before.iter().any(|f| f.starts_with("stability-map-")));
    assert!(before.contains(&"compression-2d-metropolis-elements.csv".to_string()));
    assert!(before.contains(&"work-precision.csv".to_string()));
    assert_eq!(
        json(&out.join("stability.json"))["run_id"],
        first_stability,
        "the other studies left stability alone"
    );
    let index: Vec<String> = index_entries(&out).into_iter().map(|e| e.0).collect();
    assert_eq!(
        index,
        [
            "compression-2d-metropolis-elements.manifest.json",
            "stability.manifest.json",
            "work-precision.manifest.json"
        ]
    );

    // A temporary file of a writer that is gone (a pid above any Linux pid_max).
    let stale = out.join(".stability-cells.csv.tmp.4000000000.3");
    std::fs::write(&stale, b"half").unwrap();
    // And the staging folder of a run that was killed before its swap.
    let staged = out.join(".langevin-fem-staging.4000000000.0");
    std::fs::create_dir_all(&staged).unwrap();
    std::fs::write(staged.join("stability-cells.csv"), b"half").unwrap();
    run_ok(&stability_args(&out, "crank-nicolson"));
    if Path::new("/proc").is_dir() {
        assert!(!stale.exists(), "a dead writer's temporary file is removed");
        assert!(!staged.exists(), "a dead run's staging folder is removed");
    } else {
        std::fs::remove_file(&stale).unwrap();
        std::fs::remove_dir_all(&staged).unwrap();
    }
    assert_eq!(maps(&out), ["stability-map-crank-nicolson.svg"]);
    assert_ne!(json(&out.join("stability.json"))["run_id"], first_stability);
    let after = all_files(&out);
    let dropped: Vec<&String> = before.iter().filter(|f| !after.contains(f)).collect();
    assert_eq!(
        dropped,
        [
            "stability-map-backward-euler.svg",
            "stability-map-euler-maruyama.svg",
            "stability-map-exact-modal.svg"
        ],
        "only the dropped maps are removed"
    );
    for f in foreign {
        assert!(out.join(f).exists(), "{f} kept");
    }
    for f in foreign {
        std::fs::remove_file(out.join(f)).unwrap();
    }
    assert_consistent(&out, "three studies, stability rerun smaller");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        !html.contains("old-study"),
        "a summary no journal names is not listed"
    );
}
