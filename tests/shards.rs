//! Shards and merge (issue #15): a verification split into 3 shards, each run in a process
//! of its own, and merged gives the report of the same verification run in one process,
//! byte for byte apart from wall times, run id and provenance; a merge refuses (exit 2,
//! naming the shard) a missing, duplicated, foreign or damaged shard.
//!
//! The scenes are two tiny fixtures that run in about a second together: a linear one
//! (full trajectories and extra two-time trajectories, both sharded) and a compression
//! one whose quick budget is by target precision with a step search and a Δt-halving
//! pair (the plan every shard computes in full, and the merge checks equal).

mod common;

use common::shards::{assert_same_outputs, merge, shards_of};
use common::{TempDir, all_files, describe, fixture, run, stderr_of};
use sha2::Digest;
use std::path::{Path, PathBuf};
use std::process::Output;

const LINEAR: &str = "tests/scenes/good/tiny-linear.toml";
const COMPRESSION: &str = "tests/scenes/good/tiny-compression.toml";
/// A membrane (issue #27: plate elements on their modal path).
const MEMBRANE: &str = "tests/scenes/good/membrane-hinged.toml";

/// `verify -q` of the fixtures (filament, compression, membrane) with `extra` flags, as
/// arguments.
fn verify_args(extra: &[&str]) -> Vec<String> {
    let (lin, comp, memb) = (fixture(LINEAR), fixture(COMPRESSION), fixture(MEMBRANE));
    let mut args = strings(&["verify", "-q", "-s", lin.to_str().unwrap()]);
    args.extend(strings(&["-s", comp.to_str().unwrap()]));
    args.extend(strings(&["-s", memb.to_str().unwrap()]));
    args.extend(strings(extra));
    args
}

/// `verify` of both fixtures into `out` with `extra` flags; asserts exit 0 or 1.
fn verify(out: &Path, extra: &[&str]) -> Output {
    let args = verify_args(&[extra, &["-o", out.to_str().unwrap()]].concat());
    let shown: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&shown);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&shown, &o)
    );
    o
}

/// The strings of `args`.
fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// Runs shards `1/n … n/n` of both fixtures' verification concurrently, each in a
/// process of its own, into `<root>/<i>`, with `extra` flags.
fn shards(root: &Path, n: usize, extra: &[&str]) -> Vec<PathBuf> {
    shards_of(root, n, &verify_args(extra))
}

/// The keys of a JSON output that differ between two runs of the same work.
fn volatile(_file: &str) -> &'static [&'static str] {
    &["wall_seconds", "run_id", "provenance"]
}

/// What: both fixtures verified in one process, and as 3 shards run concurrently in
/// processes of their own and merged (from the parent directory of the shards).
/// Reference: the whole run's outputs.
/// Tolerance: every table, figure and other file byte-identical; `summary.json` and
/// `manifest.json` equal as JSON without wall times, run id and provenance; `index.html`
/// equal without the run id, the provenance block and the wall times. The exit codes are
/// equal.
#[test]
fn three_shards_merge_to_the_whole_run_byte_for_byte() {
    let tmp = TempDir::new("shards");
    let whole = tmp.join("whole");
    let w = verify(&whole, &[]);
    let root = tmp.join("shards");
    shards(&root, 3, &[]);
    let merged = tmp.join("merged");
    let m = merge(&[&root], &merged);
    assert_eq!(m.status.code(), w.status.code(), "{}", stderr_of(&m));

    let files = assert_same_outputs(&whole, &merged, volatile);
    assert!(
        files.iter().any(|f| f.ends_with("force-strain.csv"))
            && files.iter().any(|f| f.ends_with("-two-time.csv"))
            && files.iter().any(|f| f.ends_with("-height-spectrum.svg")),
        "the fixtures wrote no force-strain or two-time table or membrane spectrum: {files:?}"
    );
}

/// What: convergence studies (a compression one over elements, a linear one over dt)
/// run whole, and as 3 shards run concurrently in processes of their own and merged.
/// Reference: the whole study's outputs.
/// Tolerance: as `three_shards_merge_to_the_whole_run_byte_for_byte` (tables and
/// figures byte-identical; JSON and the index without wall times, run ids, provenance).
#[test]
fn converge_in_three_shards_merges_to_the_whole_study() {
    let tmp = TempDir::new("converge-shards");
    let (lin, comp) = (fixture(LINEAR), fixture(COMPRESSION));
    let studies: [Vec<&str>; 2] = [
        vec![
            "converge",
            "-q",
            "-s",
            comp.to_str().unwrap(),
            "--over",
            "elements",
            "--values",
            "4,8",
            "--strain-ratios",
            "0,2",
            "--trajectories",
            "6",
            "--duration-tau1",
            "5",
        ],
        vec![
            "converge",
            "-q",
            "-s",
            lin.to_str().unwrap(),
            "--over",
            "dt",
            "--values",
            "0.02,0.01",
        ],
    ];
    for (k, study) in studies.iter().enumerate() {
        let whole = tmp.join(&format!("whole-{k}"));
        let mut args = study.clone();
        let out = whole.display().to_string();
        args.extend(["-o", &out]);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
        let root = tmp.join(&format!("shards-{k}"));
        shards_of(&root, 3, &strings(study));
        let merged = tmp.join(&format!("merged-{k}"));
        let m = merge(&[&root], &merged);
        assert_eq!(m.status.code(), Some(0), "{}", stderr_of(&m));
        let files = assert_same_outputs(&whole, &merged, volatile);
        assert!(
            files
                .iter()
                .any(|f| f.ends_with("-elements.csv") || f.ends_with("-dt.csv"))
        );
    }
}

/// A merge of `dirs` into `out` that must be refused: asserts exit 2, that stderr names
/// every string of `names`, and that the earlier report in `out` is untouched (its
/// `summary.json` and `index.html` as they were).
fn refused(dirs: &[&Path], out: &Path, names: &[&str]) {
    let before = |f: &str| std::fs::read(out.join(f)).expect("an earlier report");
    let (summary, index) = (before("summary.json"), before("index.html"));
    let o = merge(dirs, out);
    let err = stderr_of(&o);
    assert_eq!(o.status.code(), Some(2), "not refused: {err}");
    for n in names {
        assert!(err.contains(n), "the refusal does not name {n:?}: {err}");
    }
    assert!(
        before("summary.json") == summary && before("index.html") == index,
        "a refused merge changed the earlier report"
    );
}

/// What: merges that must be refused before anything is written: a missing shard, a
/// duplicated one, one of another seed, budget, shard count or scene set, a scene text
/// edited with its hash, a damaged record file, and a directory that is not a shard.
/// Reference: exit 2, the message naming the shard (its directory and index) and what
/// differs; the earlier report in the output directory untouched.
#[test]
fn merge_refuses_missing_duplicate_foreign_and_damaged_shards() {
    let tmp = TempDir::new("shards-refused");
    let root = tmp.join("set");
    shards(&root, 3, &[]);
    let (s1, s2, s3) = (root.join("1"), root.join("2"), root.join("3"));
    // An earlier report, which no refused merge may touch.
    let out = tmp.join("out");
    let first = merge(&[&s1, &s2, &s3], &out);
    assert!(
        matches!(first.status.code(), Some(0 | 1)),
        "{}",
        stderr_of(&first)
    );

    refused(&[&s1, &s3], &out, &["missing shard 2/3"]);

    let copy = tmp.join("copy-of-1");
    std::fs::create_dir_all(&copy).unwrap();
    for f in all_files(&s1) {
        std::fs::create_dir_all(copy.join(&f).parent().unwrap()).unwrap();
        std::fs::copy(s1.join(&f), copy.join(&f)).unwrap();
    }
    refused(
        &[&s1, &copy, &s2, &s3],
        &out,
        &["shard 1/3 given twice", "copy-of-1", s1.to_str().unwrap()],
    );

    let seed = tmp.join("seed");
    shards(&seed, 3, &["--seed", "7"]);
    let foreign = seed.join("2");
    refused(
        &[&s1, &foreign, &s3],
        &out,
        &[foreign.to_str().unwrap(), "seed 7"],
    );

    let budget = tmp.join("budget");
    shards(&budget, 3, &["-b", "standard"]);
    refused(
        &[&s1, &budget.join("2"), &s3],
        &out,
        &["settings", "standard"],
    );

    let four = tmp.join("four");
    shards(&four, 4, &[]);
    refused(
        &[&s1, &four.join("2"), &s3],
        &out,
        &["set of 4", "set of 3"],
    );

    let other = tmp.join("other");
    let o = run(&[
        "verify",
        "-q",
        "-s",
        fixture(LINEAR).to_str().unwrap(),
        "--shard",
        "2/3",
        "-o",
        other.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    refused(&[&s1, &other, &s3], &out, &["scenes", "tiny-compression"]);

    // A scene's text and its SHA-256 edited together in every manifest: the manifest
    // and the text's key are named (not the scene's original file).
    let edited = tmp.join("edited");
    for k in ["1", "2", "3"] {
        common::copy_tree(&root.join(k), &edited.join(k));
        let path = edited.join(k).join("shard.json");
        let mut m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
        let text = m["scenes"][0]["text"].as_str().unwrap().replacen(
            "[filament]",
            "[filament]\nbogus_key = 3",
            1,
        );
        let hash: String = sha2::Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        m["scenes"][0]["sha256"] = hash.into();
        m["scenes"][0]["text"] = text.into();
        std::fs::write(&path, serde_json::to_vec(&m).unwrap()).unwrap();
    }
    let first = edited.join("1").join("shard.json");
    refused(
        &[&edited],
        &out,
        &[
            first.to_str().unwrap(),
            "scenes[0].text: filament.bogus_key",
            "rerun the shards",
        ],
    );

    let record = s2.join("records/tiny-linear/crank-nicolson.lin");
    let mut bytes = std::fs::read(&record).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 1;
    std::fs::write(&record, bytes).unwrap();
    refused(
        &[&s1, &s2, &s3],
        &out,
        &["crank-nicolson.lin", "SHA-256", "rerun shard 2/3"],
    );

    let empty = tmp.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(&[&empty], &out, &["not a shard"]);
}

/// What: `--shard` outside 1 ≤ I ≤ N is refused before anything runs.
/// Reference: exit 2 naming the flag and the rule.
#[test]
fn shard_flag_out_of_range_is_refused() {
    let tmp = TempDir::new("shard-flag");
    for bad in ["0/3", "4/3", "3", "x/y"] {
        let args = [
            "verify",
            "-s",
            LINEAR,
            "--shard",
            bad,
            "-o",
            &tmp.join_str("out"),
        ];
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
        let err = stderr_of(&o);
        assert!(
            err.contains("--shard") && err.contains("1 <= I <= N"),
            "{}",
            describe(&args, &o)
        );
    }
}

/// What: the work cap of a shard is its share of the projected work: the tiny linear
/// scene projects 182400 DOF-steps; `--max-work 1e4` refuses it whole (exit 2, naming
/// the cap) and admits its shard 1/100 (about 1824 DOF-steps).
/// Reference: `WorkProjection::scaled` by 1/N.
#[test]
fn a_shard_is_capped_by_its_share_of_the_work() {
    let tmp = TempDir::new("shard-cap");
    let lin = fixture(LINEAR);
    let base = [
        "verify",
        "-q",
        "-s",
        lin.to_str().unwrap(),
        "--max-work",
        "1e4",
    ];
    let out = tmp.join_str("whole");
    let mut args = base.to_vec();
    args.extend(["-o", &out]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    assert!(
        stderr_of(&o).contains("--max-work"),
        "{}",
        describe(&args, &o)
    );
    let out = tmp.join_str("shard");
    let mut args = base.to_vec();
    args.extend(["--shard", "1/100", "-o", &out]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
}

/// What: shard 1 of both fixtures run first, then shards 2 and 3 with `--plan-from` it
/// (the compression fixture's budget is by target precision with a step search: they
/// take shard 1's plans instead of running the search and the pilot), merged; and
/// `--plan-from` a shard of another seed.
/// Reference: the whole run's outputs (as in `three_shards_merge_to_the_whole_run_byte_for_byte`);
/// the refusal names the seed (exit 2).
#[test]
fn shards_with_plans_from_shard_one_merge_to_the_whole_run() {
    let tmp = TempDir::new("plan-from");
    let whole = tmp.join("whole");
    verify(&whole, &[]);
    let root = tmp.join("shards");
    let shard = |i: usize, extra: &[&str]| {
        let out = root.join(i.to_string()).display().to_string();
        let n = format!("{i}/3");
        let args = verify_args(&[&["--shard", &n, "-o", &out], extra].concat());
        let shown: Vec<&str> = args.iter().map(String::as_str).collect();
        (run(&shown), args)
    };
    let first = root.join("1").display().to_string();
    for i in 1..=3 {
        let extra: &[&str] = if i == 1 {
            &[]
        } else {
            &["--plan-from", &first]
        };
        let (o, args) = shard(i, extra);
        let shown: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_eq!(o.status.code(), Some(0), "{}", describe(&shown, &o));
    }
    let merged = tmp.join("merged");
    let m = merge(&[&root], &merged);
    assert!(matches!(m.status.code(), Some(0 | 1)), "{}", stderr_of(&m));
    assert_same_outputs(&whole, &merged, volatile);

    // Refused as input before the earlier shard 2 in the same directory is touched.
    let manifest = root.join("2").join("shard.json");
    let before = std::fs::read(&manifest).expect("shard 2's manifest");
    let (o, args) = shard(2, &["--plan-from", &first, "--seed", "7"]);
    let shown: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_eq!(o.status.code(), Some(2), "{}", describe(&shown, &o));
    assert!(
        stderr_of(&o).contains("seed 7") && stderr_of(&o).contains(&first),
        "{}",
        describe(&shown, &o)
    );
    assert!(
        std::fs::read(&manifest).ok() == Some(before),
        "a refused --plan-from changed the earlier shard's manifest"
    );
}
