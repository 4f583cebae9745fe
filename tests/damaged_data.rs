//! A corpus of damaged DATA (issue #25, deliverable 5): the files a user hands to `check`,
//! `merge` and `verify --plan-from` — a data directory's sidecar `data.json`, its `.npy`
//! and CSV trajectory files, shard manifests `shard.json` and their record files, a
//! `--plan-from` shard — each damaged in one way, and output directories misused. The
//! corpus for bad scene files and flags is `tests/bad_inputs.rs`; this file follows its
//! pattern.
//!
//! What: every case is run as a child process of the binary on a fresh copy of a VALID
//! input with ONE damage applied, and must
//! 1. be safe: no panic (exit 101 or "panicked"), no signal or abort, no hang (killed
//!    after [`TIMEOUT`]);
//! 2. lose no data: every file of the input trees (data directory, shard directories,
//!    `--plan-from` directory, any other directory the case hands over) has the same
//!    bytes afterwards and none is missing (trees hashed before and after, symbolic links
//!    and FIFOs compared without being followed or opened); and if the exit code is not
//!    0 or 1, every file of the earlier report in `--out` (written by the same command on
//!    the undamaged input before the case runs) has the same bytes;
//! 3. give the expected outcome: `Refused` — exit 2 and stderr naming the file (its
//!    basename, or `shards/2/shard.json` for a shard), the key, column, row or flag, and
//!    the value as given (`a|b` in an expected string accepts either spelling: `1e31` as
//!    given or `10000000000000000000000000000000` as Rust prints it); or `Unchanged` —
//!    the exit code of the same command on the undamaged input (a byte-order mark, CRLF
//!    line ends, an extra CSV column, reformatted JSON, an edited producer text…).
//!
//! Writing into an input directory is reported too (an outcome problem, not data loss).
//!
//! Reference: the guide, docs/src/reference/exit-codes-and-limits.md (2: the user's input, named with file, key and value);
//! `src/input.rs` (regular files only, capped reads, never written to); issue #25.
//!
//! Set-up: the valid inputs are made at test time, once per test process, in a temporary
//! directory ([`Fixtures`]): `run` of `tests/scenes/good/tiny-linear.toml` (`.npy` and
//! CSV) and of `tiny-compression.toml` (`--duration-tau1 5`, CSV and `.npy`); shard sets of
//! `verify --shard I/3` of both fixtures, `run --shard I/2` and `converge --shard I/2` of
//! the linear one; `verify --shard 1/3` of the compression fixture (a budget by target
//! precision, whose plans shards 2 and 3 may take with `--plan-from`). For each input the
//! command a case runs (`check`, `merge`, `verify --shard 2/3 --plan-from plan`) is run
//! once undamaged: its exit code is the `Unchanged` verdict and its output directory the
//! earlier report copied into each case's `out`. Each case then runs in a tree of its own
//! (`data/`, `shards/1…N`, `plan/`, `out/`), from that tree. Children run with one rayon
//! thread (the corpus runs two at a time on the 2-core machine) and an address space of
//! [`MEMORY_LIMIT_KIB`]: a claimed size that makes the binary allocate more aborts it,
//! which counts as unsafe (on a user's machine it would exhaust memory).
//!
//! Tolerance: 100 % of the cases safe, 100 % with the expected exit code, and at least
//! 95 % of the `Refused` cases naming every expected string (file AND key/flag/column AND
//! value); the counts per damage kind, the pass fractions and a table of every failing case
//! (expected, exit code, first line of stderr) are printed.
//!
//! The property test ([`random_byte_mutations_are_safe`]) mutates the valid `.npy`, CSV,
//! `data.json` and a run shard's `shard.json` at random (one flip, deletion, insertion or
//! truncation per mutant; proptest strategies with the ChaCha generator and the fixed seed
//! `SEED_DAMAGED_DATA`, so every run draws the same 64 mutants per file kind) and asserts
//! the same safety (no panic, hang or data loss). Its outcome rule: a mutant whose bytes
//! are structure — the `.npy` header (or any deletion, insertion or truncation of a
//! `.npy`, which breaks its size), the CSV header line, any byte of a shard manifest
//! (compared with the other shard, hashed, or provenance that is not compared) — must
//! exit 2 or with the undamaged verdict. A mutant that may only have changed numbers (a
//! flipped byte in the `.npy` body, an edit in the CSV rows, any edit of `data.json`,
//! whose digits are numbers the checks use) legitimately changes the data, so it may give
//! either verdict: exit 0, 1 or 2, never 3 (an estimator failing on damaged input is a
//! refusal the tool missed) nor a crash. Mutants are drawn first and run on two worker
//! threads like the corpus, every failure listed (no shrinking: each mutant is a single
//! edit already). The provenance of the mutated `data.json` and `shard.json` (start time,
//! wall time, run id, command line; read by neither `check` nor `merge`) is replaced by a
//! fixed string first, so that the mutated bytes are the same on every run: exactly for the
//! `.npy`, CSV and `data.json`; a manifest also holds the build line and the scene files'
//! paths, whose lengths may differ between commits and checkouts.
//!
//! Judgement calls of the corpus (each a case, so a decision to the contrary is one edit):
//! a NaN or infinity anywhere in a trajectory file is refused, also in a column no check
//! of the scene reads (`w_1`, `w_0`, `t`): a producer that writes one is broken, and the
//! refusal costs one pass over the values read anyway; a sidecar listing the same file
//! twice is refused (it would count a trajectory twice); unknown keys of `data.json` are
//! refused (the format is `deny_unknown_fields`), an unknown CSV column is ignored (as the
//! format documents); a merge into an output directory is refused when that directory is
//! one of the shards, their parent, or holds another command's output (a `check` report,
//! a `run` data directory): the same rule as `check -o` over a data directory.

mod common;

use common::seeds::SEED_DAMAGED_DATA;
use common::shards::shards_of;
use common::{BIN, TempDir, copy_tree, fixture};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed, TestRunner};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

/// Longest time a case may take; a case still running then is killed and counted as a
/// hang. Every undamaged command here takes under a second.
const TIMEOUT: Duration = Duration::from_secs(10);
/// The address space of a child, in KiB (4 GiB): ample for the tiny fixtures (the
/// undamaged commands use well under 200 MiB).
const MEMORY_LIMIT_KIB: u64 = 4 << 20;
/// The fraction of `Refused` cases that must name every expected string.
const NAMED_FRACTION: f64 = 0.95;
/// Mutants per file kind in the property test.
const MUTANTS: usize = 64;
/// The provenance of the `data.json` and `shard.json` the property test mutates.
const NORMALIZED: &str = "normalized by tests/damaged_data.rs";

const LINEAR: &str = "tests/scenes/good/tiny-linear.toml";
const COMPRESSION: &str = "tests/scenes/good/tiny-compression.toml";

/// The JSON bits of f64 NaN, +inf and −1.0 (plans store floats as their bits).
const NAN_BITS: &str = "9221120237041090560";
const INF_BITS: &str = "9218868437227405312";
const MINUS_ONE_BITS: &str = "13830554455654793216";

// ---------------------------------------------------------------------------------------
// The valid inputs
// ---------------------------------------------------------------------------------------

/// A valid input a case starts from.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Input {
    /// `run` of the tiny linear fixture, `.npy`; checked with `check -s tiny-linear`.
    LinNpy,
    /// The same in CSV.
    LinCsv,
    /// `run --duration-tau1 5 --format csv` of the tiny compression fixture.
    CompCsv,
    /// The same in `.npy`.
    CompNpy,
    /// `verify --shard I/3` of both fixtures; `merge shards/1 shards/2 shards/3`.
    VerifySet,
    /// `run --shard I/2` of the linear fixture; `merge shards/1 shards/2`.
    RunSet,
    /// `converge --over dt --values 0.02,0.01 --shard I/2` of the linear fixture.
    ConvergeSet,
    /// `verify --shard 1/3` of the compression fixture, as `plan/`; the command is
    /// `verify --shard 2/3 --plan-from plan`.
    PlanFrom,
}

impl Input {
    const ALL: [Input; 8] = [
        Input::LinNpy,
        Input::LinCsv,
        Input::CompCsv,
        Input::CompNpy,
        Input::VerifySet,
        Input::RunSet,
        Input::ConvergeSet,
        Input::PlanFrom,
    ];

    fn label(self) -> &'static str {
        match self {
            Input::LinNpy => "lin-npy",
            Input::LinCsv => "lin-csv",
            Input::CompCsv => "comp-csv",
            Input::CompNpy => "comp-npy",
            Input::VerifySet => "verify-set",
            Input::RunSet => "run-set",
            Input::ConvergeSet => "converge-set",
            Input::PlanFrom => "plan-from",
        }
    }

    /// Where the input lies in a case's tree.
    fn place(self) -> &'static str {
        match self {
            Input::LinNpy | Input::LinCsv | Input::CompCsv | Input::CompNpy => "data",
            Input::VerifySet | Input::RunSet | Input::ConvergeSet => "shards",
            Input::PlanFrom => "plan",
        }
    }

    /// The command a case runs on this input, from the case's tree (`LIN` and `COMP`
    /// stand for the fixtures' scene files).
    fn argv(self) -> Vec<String> {
        let a: &[&str] = match self {
            Input::LinNpy | Input::LinCsv => {
                &["check", "-q", "-s", "LIN", "-d", "data", "-o", "out"]
            }
            Input::CompCsv | Input::CompNpy => {
                &["check", "-q", "-s", "COMP", "-d", "data", "-o", "out"]
            }
            Input::VerifySet => &[
                "merge", "-q", "shards/1", "shards/2", "shards/3", "-o", "out",
            ],
            Input::RunSet | Input::ConvergeSet => {
                &["merge", "-q", "shards/1", "shards/2", "-o", "out"]
            }
            Input::PlanFrom => &[
                "verify",
                "-q",
                "-s",
                "COMP",
                "--shard",
                "2/3",
                "--plan-from",
                "plan",
                "-o",
                "out",
            ],
        };
        expand(a)
    }
}

/// `args` with `LIN` and `COMP` replaced by the fixtures' paths.
fn expand(args: &[&str]) -> Vec<String> {
    args.iter()
        .map(|a| match *a {
            "LIN" => fixture(LINEAR).display().to_string(),
            "COMP" => fixture(COMPRESSION).display().to_string(),
            other => other.to_string(),
        })
        .collect()
}

/// The valid inputs and, per input, the undamaged command's exit code and output.
struct Fixtures {
    dir: TempDir,
    codes: Vec<(Input, i32)>,
}

impl Fixtures {
    /// The valid tree of `input` (a data directory, a directory of shards `1…N`, or the
    /// `--plan-from` shard).
    fn src(&self, input: Input) -> PathBuf {
        self.dir.join(&format!("src/{}", input.label()))
    }

    /// The tree in which the undamaged command of `input` ran; its `out` is the earlier
    /// report of every case on `input`.
    fn baseline(&self, input: Input) -> PathBuf {
        self.dir.join(&format!("baseline/{}", input.label()))
    }

    /// The undamaged command's exit code.
    fn code(&self, input: Input) -> i32 {
        self.codes
            .iter()
            .find(|(i, _)| *i == input)
            .map(|(_, c)| *c)
            .expect("a baseline per input")
    }

    /// The fixtures, made once and shared by the tests of this process that run at the
    /// same time (removed when the last of them drops its handle; a test running later
    /// makes them again).
    fn get() -> Arc<Fixtures> {
        static CACHE: Mutex<Weak<Fixtures>> = Mutex::new(Weak::new());
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(f) = cache.upgrade() {
            return f;
        }
        let f = Arc::new(Fixtures::build());
        *cache = Arc::downgrade(&f);
        f
    }

    fn build() -> Fixtures {
        let dir = TempDir::new("damaged-fixtures");
        let src = |i: Input| {
            dir.join(&format!("src/{}", i.label()))
                .display()
                .to_string()
        };
        let lin = fixture(LINEAR).display().to_string();
        let comp = fixture(COMPRESSION).display().to_string();
        let owned = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<String>>();
        // Whole runs and the --plan-from shard, concurrently.
        let jobs: Vec<Vec<String>> = vec![
            owned(&["run", "-q", "-s", &lin, "-o", &src(Input::LinNpy)]),
            owned(&[
                "run",
                "-q",
                "-s",
                &lin,
                "--format",
                "csv",
                "-o",
                &src(Input::LinCsv),
            ]),
            owned(&[
                "run",
                "-q",
                "-s",
                &comp,
                "--duration-tau1",
                "5",
                "--format",
                "csv",
                "-o",
                &src(Input::CompCsv),
            ]),
            owned(&[
                "run",
                "-q",
                "-s",
                &comp,
                "--duration-tau1",
                "5",
                "-o",
                &src(Input::CompNpy),
            ]),
            owned(&[
                "verify",
                "-q",
                "-s",
                &comp,
                "--shard",
                "1/3",
                "-o",
                &src(Input::PlanFrom),
            ]),
        ];
        let children: Vec<_> = jobs
            .iter()
            .map(|a| {
                let child = common::command()
                    .args(a)
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .expect("start a fixture");
                (a, child)
            })
            .collect();
        for (a, child) in children {
            let o = child.wait_with_output().expect("run a fixture");
            assert_eq!(
                o.status.code(),
                Some(0),
                "fixture `langevin-fem {}`: {}",
                a.join(" "),
                String::from_utf8_lossy(&o.stderr)
            );
        }
        // The shard sets (each set's shards concurrently).
        shards_of(
            Path::new(&src(Input::VerifySet)),
            3,
            &owned(&["verify", "-q", "-s", &lin, "-s", &comp]),
        );
        shards_of(
            Path::new(&src(Input::RunSet)),
            2,
            &owned(&["run", "-q", "-s", &lin]),
        );
        shards_of(
            Path::new(&src(Input::ConvergeSet)),
            2,
            &owned(&[
                "converge",
                "-q",
                "-s",
                &lin,
                "--over",
                "dt",
                "--values",
                "0.02,0.01",
            ]),
        );
        // The undamaged command of every input, concurrently two at a time.
        let mut fx = Fixtures {
            dir,
            codes: Vec::new(),
        };
        let logs = fx.dir.join("baseline-logs");
        std::fs::create_dir_all(&logs).expect("logs");
        let codes = Mutex::new(Vec::new());
        let next = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| {
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        let Some(&input) = Input::ALL.get(k) else {
                            break;
                        };
                        let root = fx.baseline(input);
                        copy_tree(&fx.src(input), &root.join(input.place()));
                        let argv = input.argv();
                        let o = execute(&root, &argv, &logs.join(input.label()));
                        assert!(
                            matches!(o.code, Some(0 | 1)),
                            "the undamaged `langevin-fem {}` of {} exits {:?}: {}",
                            argv.join(" "),
                            input.label(),
                            o.code,
                            o.stderr
                        );
                        assert!(
                            root.join("out").is_dir(),
                            "the undamaged command of {} wrote no out/",
                            input.label()
                        );
                        codes.lock().unwrap().push((input, o.code.unwrap_or(-1)));
                    }
                });
            }
        });
        fx.codes = codes.into_inner().unwrap();
        fx
    }
}

// ---------------------------------------------------------------------------------------
// Cases
// ---------------------------------------------------------------------------------------

/// The kind of damage, for the counts.
#[derive(Clone, Copy, PartialEq, Eq, Debug, PartialOrd, Ord)]
enum Kind {
    /// The sidecar `data.json`.
    Sidecar,
    /// A `.npy` trajectory file.
    Npy,
    /// A CSV trajectory file.
    Csv,
    /// A shard manifest or record file (merge).
    Manifest,
    /// The shard given to `verify --plan-from`.
    PlanFrom,
    /// An output directory misused.
    OutDir,
}

/// What a case must give.
enum Expect {
    /// Exit 2; stderr holds every string of `expect` (`a|b`: either) and none of `forbid`.
    Refused {
        expect: Vec<String>,
        forbid: Vec<String>,
    },
    /// The exit code of the same command on the undamaged input.
    Unchanged,
}

/// One damage applied to a case's tree (the fixtures at hand, the tree's root).
type Damage = Box<dyn Fn(&Fixtures, &Path) + Send + Sync>;

/// One damaged input.
struct Case {
    name: String,
    kind: Kind,
    input: Input,
    damage: Damage,
    /// The command, if not the input's ([`Input::argv`]; `LIN`, `COMP` expanded).
    argv: Option<Vec<String>>,
    expect: Expect,
}

impl Case {
    fn argv(mut self, a: &[&str]) -> Case {
        self.argv = Some(expand(a));
        self
    }

    fn forbid(mut self, f: &[&str]) -> Case {
        if let Expect::Refused { forbid, .. } = &mut self.expect {
            forbid.extend(f.iter().map(|s| s.to_string()));
        }
        self
    }

    fn command(&self) -> Vec<String> {
        self.argv.clone().unwrap_or_else(|| self.input.argv())
    }
}

/// A case that must be refused naming every string of `expect`.
fn refused(
    kind: Kind,
    input: Input,
    name: &str,
    expect: &[&str],
    damage: impl Fn(&Fixtures, &Path) + Send + Sync + 'static,
) -> Case {
    Case {
        name: name.to_string(),
        kind,
        input,
        damage: Box::new(damage),
        argv: None,
        expect: Expect::Refused {
            expect: expect.iter().map(|s| s.to_string()).collect(),
            forbid: Vec::new(),
        },
    }
}

/// A case whose exit code must be the undamaged input's.
fn unchanged(
    kind: Kind,
    input: Input,
    name: &str,
    damage: impl Fn(&Fixtures, &Path) + Send + Sync + 'static,
) -> Case {
    Case {
        name: name.to_string(),
        kind,
        input,
        damage: Box::new(damage),
        argv: None,
        expect: Expect::Unchanged,
    }
}

// --- Damage helpers: each takes paths relative to the case's root ----------------------

fn read(root: &Path, rel: &str) -> Vec<u8> {
    std::fs::read(root.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn write(root: &Path, rel: &str, bytes: impl AsRef<[u8]>) {
    std::fs::write(root.join(rel), bytes).unwrap_or_else(|e| panic!("{rel}: {e}"));
}

fn read_json(root: &Path, rel: &str) -> Value {
    serde_json::from_slice(&read(root, rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn write_json(root: &Path, rel: &str, v: &Value) {
    write(root, rel, serde_json::to_string_pretty(v).expect("JSON"));
}

/// The JSON file `rel` edited by `f`.
fn edit_json(root: &Path, rel: &str, f: impl FnOnce(&mut Value)) {
    let mut v = read_json(root, rel);
    f(&mut v);
    write_json(root, rel, &v);
}

const PLACEHOLDER: &str = "@@RAW-VALUE@@";

/// The JSON file `rel` with the value at `pointer` (an existing value, or a new key of
/// an existing object) replaced by the raw text `raw` (which need not be JSON: `NaN`).
fn set_raw(root: &Path, rel: &str, pointer: &str, raw: &str) {
    let mut v = read_json(root, rel);
    let (parent, key) = pointer.rsplit_once('/').expect("a pointer");
    let slot = v
        .pointer_mut(parent)
        .unwrap_or_else(|| panic!("{rel} has no {parent}"));
    let placeholder = Value::String(PLACEHOLDER.into());
    match slot {
        Value::Object(m) => {
            m.insert(key.to_string(), placeholder);
        }
        Value::Array(a) => {
            let k: usize = key.parse().expect("an index");
            a[k] = placeholder;
        }
        _ => panic!("{rel}: {parent} is not an object or array"),
    }
    let text = serde_json::to_string_pretty(&v).expect("JSON");
    write(root, rel, text.replace(&format!("\"{PLACEHOLDER}\""), raw));
}

/// The JSON file `rel` without the value at `pointer`.
fn remove_key(root: &Path, rel: &str, pointer: &str) {
    edit_json(root, rel, |v| {
        let (parent, key) = pointer.rsplit_once('/').expect("a pointer");
        match v.pointer_mut(parent) {
            Some(Value::Object(m)) => {
                m.remove(key)
                    .unwrap_or_else(|| panic!("{rel} has no {pointer}"));
            }
            Some(Value::Array(a)) => {
                a.remove(key.parse::<usize>().expect("an index"));
            }
            _ => panic!("{rel} has no {parent}"),
        }
    });
}

/// The text file `rel` mapped by `f`.
fn edit_text(root: &Path, rel: &str, f: impl FnOnce(String) -> String) {
    let text = String::from_utf8(read(root, rel)).expect("UTF-8");
    write(root, rel, f(text));
}

/// `rel` replaced by a FIFO (named pipe).
fn make_fifo(root: &Path, rel: &str) {
    let p = root.join(rel);
    let _ = std::fs::remove_file(&p);
    let ok = Command::new("mkfifo")
        .arg(&p)
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mkfifo {}", p.display());
}

/// `rel` replaced by a symbolic link to `target`.
fn make_link(root: &Path, rel: &str, target: &str) {
    let p = root.join(rel);
    let _ = std::fs::remove_file(&p);
    std::os::unix::fs::symlink(target, &p).expect("symlink");
}

/// `rel` replaced by a directory.
fn make_dir(root: &Path, rel: &str) {
    let p = root.join(rel);
    let _ = std::fs::remove_file(&p);
    std::fs::create_dir_all(p.join("inside")).expect("create dir");
}

fn remove(root: &Path, rel: &str) {
    std::fs::remove_file(root.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The record `rel` of the shard in `shard` mapped by `f`, and the shard's manifest
/// updated to the new size and SHA-256 (so that only decoding can find the damage).
fn replace_record(root: &Path, shard: &str, rel: &str, f: impl FnOnce(Vec<u8>) -> Vec<u8>) {
    let path = format!("{shard}/{rel}");
    let bytes = f(read(root, &path));
    write(root, &path, &bytes);
    edit_json(root, &format!("{shard}/shard.json"), |m| {
        let entry = m["files"]
            .as_array_mut()
            .expect("files")
            .iter_mut()
            .find(|e| e["path"] == rel)
            .unwrap_or_else(|| panic!("no entry {rel}"));
        entry["bytes"] = Value::from(bytes.len() as u64);
        entry["sha256"] = Value::from(sha256_hex(&bytes));
    });
}

/// The entry of run `run` in the manifest `rel`, edited by `f`.
fn edit_entry(root: &Path, rel: &str, run: &str, f: impl FnOnce(&mut Value)) {
    edit_json(root, rel, |m| {
        let entry = m["files"]
            .as_array_mut()
            .expect("files")
            .iter_mut()
            .find(|e| e["run"] == run)
            .unwrap_or_else(|| panic!("{rel}: no run {run}"));
        f(entry);
    });
}

/// The index of the entry of run `run` in the manifest `rel`.
fn entry_index(root: &Path, rel: &str, run: &str) -> usize {
    read_json(root, rel)["files"]
        .as_array()
        .expect("files")
        .iter()
        .position(|e| e["run"] == run)
        .unwrap_or_else(|| panic!("{rel}: no run {run}"))
}

/// The header length and the offset of the body of a version-1 `.npy` file.
fn npy_body(bytes: &[u8]) -> usize {
    10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize
}

/// The `.npy` file `rel` with its header dictionary replaced by `dict` (padded to keep
/// the body 64-byte aligned).
fn npy_dict(root: &Path, rel: &str, dict: &str) {
    let bytes = read(root, rel);
    let body = bytes[npy_body(&bytes)..].to_vec();
    let mut len = dict.len() + 1;
    while !(10 + len).is_multiple_of(64) {
        len += 1;
    }
    let header = format!("{dict}{}\n", " ".repeat(len - dict.len() - 1));
    let mut out = bytes[..8].to_vec();
    out.extend((header.len() as u16).to_le_bytes());
    out.extend(header.as_bytes());
    out.extend(body);
    write(root, rel, out);
}

/// The shape `(rows, columns)` of the `.npy` file `rel` (from its header).
fn npy_shape(root: &Path, rel: &str) -> (usize, usize) {
    let bytes = read(root, rel);
    let header = String::from_utf8_lossy(&bytes[10..npy_body(&bytes)]).into_owned();
    let at = header.find("'shape': (").expect("a shape") + "'shape': (".len();
    let inner: Vec<usize> = header[at..]
        .split(')')
        .next()
        .unwrap()
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    (inner[0], inner[1])
}

/// The `.npy` file `rel` with the value at (row, column) set to `v`.
fn npy_set(root: &Path, rel: &str, row: usize, col: usize, v: f64) {
    let (_, cols) = npy_shape(root, rel);
    let mut bytes = read(root, rel);
    let at = npy_body(&bytes) + (row * cols + col) * 8;
    bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
    write(root, rel, bytes);
}

/// The `.npy` file `rel` with every value of column `col` mapped by `f(row, value)`.
fn npy_column(root: &Path, rel: &str, col: usize, f: impl Fn(usize, f64) -> f64) {
    let (rows, cols) = npy_shape(root, rel);
    let mut bytes = read(root, rel);
    let body = npy_body(&bytes);
    for r in 0..rows {
        let at = body + (r * cols + col) * 8;
        let v = f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
        bytes[at..at + 8].copy_from_slice(&f(r, v).to_le_bytes());
    }
    write(root, rel, bytes);
}

/// The CSV file `rel` as lines (header first), edited by `f` and written back with `\n`
/// line ends.
fn edit_csv(root: &Path, rel: &str, f: impl FnOnce(&mut Vec<String>)) {
    edit_text(root, rel, |text| {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        f(&mut lines);
        lines.join("\n") + "\n"
    });
}

/// The field of column `name` in data row `row` (1-based: line `row` after the header)
/// set to `value`.
fn set_field(lines: &mut [String], row: usize, name: &str, value: &str) {
    let col = lines[0]
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    let mut fields: Vec<String> = lines[row].split(',').map(str::to_string).collect();
    fields[col] = value.to_string();
    lines[row] = fields.join(",");
}

/// Every data row's field of column `name` mapped by `f(row, field)`.
fn map_column(lines: &mut [String], name: &str, f: impl Fn(usize, &str) -> String) {
    let col = lines[0]
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    for (r, line) in lines.iter_mut().enumerate().skip(1) {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        fields[col] = f(r, &fields[col]);
        *line = fields.join(",");
    }
}

/// Column `name` removed (header and every row).
fn drop_column(lines: &mut [String], name: &str) {
    let col = lines[0]
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    for line in lines.iter_mut() {
        let mut fields: Vec<&str> = line.split(',').collect();
        fields.remove(col);
        *line = fields.join(",");
    }
}

/// A column appended: `name` in the header and `value(row)` in every row.
fn add_column(lines: &mut [String], name: &str, value: impl Fn(usize) -> String) {
    for (r, line) in lines.iter_mut().enumerate() {
        let v = if r == 0 { name.to_string() } else { value(r) };
        line.push(',');
        line.push_str(&v);
    }
}

// ---------------------------------------------------------------------------------------
// The corpus
// ---------------------------------------------------------------------------------------

/// Files of the valid inputs that the cases damage.
const SIDECAR: &str = "data/data.json";
/// The second file (`runs[0].files[1]`) of the linear run.
const LIN_NPY: &str = "data/crank-nicolson/trajectory-0001.npy";
const LIN_CSV: &str = "data/crank-nicolson/trajectory-0001.csv";
/// `runs[1].files[2]` of the compression run: strain 2 of `metropolis`.
const COMP_CSV: &str = "data/metropolis/strain-01/trajectory-0002.csv";
const COMP_NPY: &str = "data/metropolis/strain-01/trajectory-0002.npy";
/// Shard 2's manifest.
const M2: &str = "shards/2/shard.json";
const PLAN: &str = "plan/shard.json";

/// Sidecar cases on `input` (a linear data directory unless said): `set_raw` at a
/// pointer of `data.json`.
fn sidecar_raw(
    input: Input,
    name: &str,
    pointer: &'static str,
    raw: &'static str,
    expect: &[&str],
) -> Case {
    refused(Kind::Sidecar, input, name, expect, move |_, r| {
        set_raw(r, SIDECAR, pointer, raw)
    })
}

/// A sidecar case: the key at `pointer` removed; stderr must name the key.
fn sidecar_missing(name: &str, pointer: &'static str, key: &str) -> Case {
    refused(
        Kind::Sidecar,
        Input::LinNpy,
        name,
        &["data.json", key],
        move |_, r| remove_key(r, SIDECAR, pointer),
    )
}

/// Sidecar edits: (case, input, JSON pointer in `data.json`, raw text put there, what
/// stderr must name). The raw text need not be JSON: `NaN`,
/// `Infinity` and `-Infinity` are what Python's `json.dump` writes for non-finite floats.
#[rustfmt::skip]
const SIDECAR_EDITS: &[(&str, Input, &str, &str, &[&str])] = &[
    ("sidecar-length-nan", Input::LinNpy, "/filament/length", "NaN", &["data.json", "filament.length", "NaN"]),
    // Inside [1e-30, 1e30] but outside the exact compression theory's domain (S/P² in
    // [1e-2, 1e12], P in [1e-3, 1e6]): the theory exhausted memory at EA = 1e-6, ran for
    // minutes at 50 and failed as a "run" (exit 3) at 1e30.
    ("sidecar-comp-ea-below-theory", Input::CompCsv, "/filament/stretch_rigidity", "1e-6", &["data.json", "filament.stretch_rigidity", "S/P²", "1e-6"]),
    ("sidecar-comp-ea-just-below-theory", Input::CompCsv, "/filament/stretch_rigidity", "50.0", &["data.json", "filament.stretch_rigidity", "S/P²", "5e1"]),
    ("sidecar-comp-ea-above-theory", Input::CompNpy, "/filament/stretch_rigidity", "1e30", &["data.json", "filament.stretch_rigidity", "S/P²", "1e30"]),
    ("sidecar-comp-ei-above-theory", Input::CompCsv, "/filament/bending_rigidity", "1e7", &["data.json", "filament.bending_rigidity", "P = EI/(kT L)", "1e7"]),
    ("sidecar-kt-infinity", Input::LinNpy, "/filament/kt", "Infinity", &["data.json", "filament.kt", "Infinity|inf"]),
    ("sidecar-drag-minus-infinity", Input::LinNpy, "/filament/drag", "-Infinity", &["data.json", "filament.drag", "-Infinity|-inf"]),
    ("sidecar-ei-nan", Input::LinNpy, "/filament/bending_rigidity", "NaN", &["data.json", "filament.bending_rigidity", "NaN"]),
    ("sidecar-dt-sample-nan", Input::LinNpy, "/runs/0/dt_sample", "NaN", &["data.json", "runs[0].dt_sample", "NaN"]),
    ("sidecar-burn-in-infinity", Input::LinNpy, "/runs/0/burn_in", "Infinity", &["data.json", "runs[0].burn_in", "Infinity|inf"]),
    ("sidecar-position-nan", Input::LinNpy, "/runs/0/positions/2", "NaN", &["data.json", "runs[0].positions[2]", "NaN"]),
    ("sidecar-discretization-dt-nan", Input::LinNpy, "/runs/0/discretization/dt", "NaN", &["data.json", "runs[0].discretization.dt", "NaN"]),
    ("sidecar-discretization-dt-infinity", Input::LinNpy, "/runs/0/discretization/dt", "Infinity", &["data.json", "runs[0].discretization.dt", "Infinity|inf"]),
    ("sidecar-modes-nan", Input::LinNpy, "/runs/0/modes", "NaN", &["data.json", "runs[0].modes", "NaN"]),
    ("sidecar-length-null", Input::LinNpy, "/filament/length", "null", &["data.json", "filament.length", "null"]),
    ("sidecar-dt-sample-null", Input::LinNpy, "/runs/0/dt_sample", "null", &["data.json", "runs[0].dt_sample", "null"]),
    ("sidecar-dims-null", Input::LinNpy, "/dims", "null", &["data.json", "dims", "null"]),
    ("sidecar-modes-null", Input::LinNpy, "/runs/0/modes", "null", &["data.json", "runs[0].modes", "null"]),
    ("sidecar-burn-in-null", Input::LinNpy, "/runs/0/burn_in", "null", &["data.json", "runs[0].burn_in", "null"]),
    ("sidecar-dims-string", Input::LinNpy, "/dims", "\"2\"", &["data.json", "dims", "\"2\""]),
    ("sidecar-dims-float", Input::LinNpy, "/dims", "2.5", &["data.json", "dims", "2.5"]),
    ("sidecar-version-string", Input::LinNpy, "/version", "\"1\"", &["data.json", "version", "\"1\""]),
    ("sidecar-length-string", Input::LinNpy, "/filament/length", "\"1.0\"", &["data.json", "filament.length", "\"1.0\""]),
    ("sidecar-length-bool", Input::LinNpy, "/filament/length", "true", &["data.json", "filament.length", "true"]),
    ("sidecar-filament-array", Input::LinNpy, "/filament", "[1, 2]", &["data.json", "filament", "array|[1, 2]"]),
    ("sidecar-runs-object", Input::LinNpy, "/runs", "{}", &["data.json", "runs", "{}|map|object"]),
    ("sidecar-run-string", Input::LinNpy, "/runs/0", "\"crank-nicolson\"", &["data.json", "runs[0]", "\"crank-nicolson\""]),
    ("sidecar-name-number", Input::LinNpy, "/runs/0/name", "7", &["data.json", "runs[0].name", "7"]),
    ("sidecar-positions-scalar", Input::LinNpy, "/runs/0/positions", "0.5", &["data.json", "runs[0].positions", "0.5"]),
    ("sidecar-files-string", Input::LinNpy, "/runs/0/files", "\"x.npy\"", &["data.json", "runs[0].files", "x.npy"]),
    ("sidecar-file-number", Input::LinNpy, "/runs/0/files/1", "7", &["data.json", "runs[0].files[1]", "7"]),
    ("sidecar-modes-float", Input::LinNpy, "/runs/0/modes", "2.5", &["data.json", "runs[0].modes", "2.5"]),
    ("sidecar-modes-negative", Input::LinNpy, "/runs/0/modes", "-1", &["data.json", "runs[0].modes", "-1"]),
    ("sidecar-start-unknown", Input::LinNpy, "/runs/0/start", "\"moving\"", &["data.json", "runs[0].start", "moving"]),
    ("sidecar-start-number", Input::LinNpy, "/runs/0/start", "0", &["data.json", "runs[0].start", "0"]),
    ("sidecar-elements-string", Input::LinNpy, "/runs/0/discretization/elements", "\"4\"", &["data.json", "runs[0].discretization.elements", "\"4\""]),
    ("sidecar-filament-elements-y", Input::LinNpy, "/runs/0/discretization/elements_y", "4", &["data.json", "runs[0].discretization.elements_y", "filament", "got 4"]),
    ("sidecar-integrator-number", Input::LinNpy, "/runs/0/discretization/integrator", "5", &["data.json", "runs[0].discretization.integrator", "5"]),
    ("sidecar-unknown-top-key", Input::LinNpy, "/extra", "1", &["data.json", "extra"]),
    ("sidecar-unknown-filament-key", Input::LinNpy, "/filament/temperature", "300.0", &["data.json", "filament.temperature"]),
    ("sidecar-unknown-run-key", Input::LinNpy, "/runs/0/dt", "0.001", &["data.json", "runs[0].dt"]),
    ("sidecar-unknown-discretization-key", Input::LinNpy, "/runs/0/discretization/order", "3", &["data.json", "runs[0].discretization.order"]),
    ("sidecar-format-other", Input::LinNpy, "/format", "\"langevin-fem-trajectorie\"", &["data.json", "format", "langevin-fem-trajectorie"]),
    ("sidecar-version-2", Input::LinNpy, "/version", "2", &["data.json", "version", "2"]),
    ("sidecar-version-negative", Input::LinNpy, "/version", "-1", &["data.json", "version", "-1"]),
    ("sidecar-dims-4", Input::LinNpy, "/dims", "4", &["data.json", "dims", "4"]),
    ("sidecar-dims-0", Input::LinNpy, "/dims", "0", &["data.json", "dims", "0"]),
    ("sidecar-dims-1", Input::LinNpy, "/dims", "1", &["data.json", "dims", "1"]),
    ("sidecar-dims-huge", Input::LinNpy, "/dims", "18446744073709551616", &["data.json", "dims", "18446744073709551616"]),
    ("sidecar-length-negative", Input::LinNpy, "/filament/length", "-1.0", &["data.json", "filament.length", "-1"]),
    ("sidecar-length-zero", Input::LinNpy, "/filament/length", "0", &["data.json", "filament.length", "0"]),
    ("sidecar-length-huge", Input::LinNpy, "/filament/length", "1e31", &["data.json", "filament.length", "1e31|10000000000000000000000000000000"]),
    ("sidecar-length-overflow", Input::LinNpy, "/filament/length", "1e999", &["data.json", "filament.length", "1e999|inf"]),
    ("sidecar-ei-zero", Input::LinNpy, "/filament/bending_rigidity", "0", &["data.json", "filament.bending_rigidity", "0"]),
    ("sidecar-ei-negative", Input::LinNpy, "/filament/bending_rigidity", "-5", &["data.json", "filament.bending_rigidity", "-5"]),
    ("sidecar-drag-zero", Input::LinNpy, "/filament/drag", "0", &["data.json", "filament.drag", "0"]),
    ("sidecar-kt-negative", Input::LinNpy, "/filament/kt", "-1", &["data.json", "filament.kt", "-1"]),
    ("sidecar-kt-tiny", Input::LinNpy, "/filament/kt", "1e-31", &["data.json", "filament.kt", "1e-31|0.0000000000000000000000000000001"]),
    ("sidecar-ea-zero-on-linear", Input::LinNpy, "/filament/stretch_rigidity", "0", &["data.json", "filament.stretch_rigidity", "0"]),
    ("sidecar-runs-empty", Input::LinNpy, "/runs", "[]", &["data.json", "runs", "[]|at least one|empty"]),
    ("sidecar-name-traversal", Input::LinNpy, "/runs/0/name", "\"../evil\"", &["data.json", "runs[0].name", "../evil"]),
    ("sidecar-name-slash", Input::LinNpy, "/runs/0/name", "\"a/b\"", &["data.json", "runs[0].name", "a/b"]),
    ("sidecar-name-empty", Input::LinNpy, "/runs/0/name", "\"\"", &["data.json", "runs[0].name", "\"\""]),
    ("sidecar-files-empty", Input::LinNpy, "/runs/0/files", "[]", &["data.json", "runs[0].files", "[]|at least one|empty"]),
    ("sidecar-file-parent", Input::LinNpy, "/runs/0/files/1", "\"../x.csv\"", &["data.json", "runs[0].files[1]", "../x.csv"]),
    ("sidecar-file-absolute", Input::LinNpy, "/runs/0/files/1", "\"/tmp/x.npy\"", &["data.json", "runs[0].files[1]", "/tmp/x.npy"]),
    ("sidecar-file-dotdot-inside", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson/../../x.npy\"", &["data.json", "runs[0].files[1]", "crank-nicolson/../../x.npy"]),
    ("sidecar-file-dev-zero", Input::LinNpy, "/runs/0/files/1", "\"/dev/zero\"", &["data.json", "runs[0].files[1]", "/dev/zero"]),
    ("sidecar-file-not-listed-missing", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson/trajectory-9999.npy\"", &["data.json", "runs[0].files[1]", "trajectory-9999.npy"]),
    ("sidecar-file-is-the-run-dir", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson\"", &["data.json", "runs[0].files[1]", "crank-nicolson"]),
    ("sidecar-file-txt", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson/trajectory-0001.txt\"", &["data.json", "runs[0].files[1]", "trajectory-0001.txt"]),
    ("sidecar-file-listed-twice", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson/trajectory-0000.npy\"", &["data.json", "runs[0].files[1]", "trajectory-0000.npy"]),
    ("sidecar-file-listed-twice-spelled-apart", Input::LinNpy, "/runs/0/files/1", "\"crank-nicolson/.//trajectory-0000.npy\"", &["data.json", "runs[0].files[1]", "trajectory-0000.npy", "again"]),
    ("sidecar-elements-zero", Input::LinNpy, "/runs/0/discretization/elements", "0", &["data.json", "runs[0].discretization.elements", "0"]),
    ("sidecar-elements-1e8", Input::LinNpy, "/runs/0/discretization/elements", "100000000", &["data.json", "runs[0].discretization.elements", "100000000"]),
    ("sidecar-elements-u64-max", Input::LinNpy, "/runs/0/discretization/elements", "18446744073709551615", &["data.json", "runs[0].discretization.elements", "18446744073709551615"]),
    ("sidecar-dt-huge", Input::LinNpy, "/runs/0/discretization/dt", "1e10", &["data.json", "runs[0].discretization.dt", "1e10|10000000000"]),
    ("sidecar-dt-tiny", Input::LinNpy, "/runs/0/discretization/dt", "1e-300", &["data.json", "runs[0].discretization.dt", "1e-300|0.000000000000000"]),
    ("sidecar-dt-zero", Input::LinNpy, "/runs/0/discretization/dt", "0", &["data.json", "runs[0].discretization.dt", "0"]),
    ("sidecar-dt-negative", Input::LinNpy, "/runs/0/discretization/dt", "-0.0001", &["data.json", "runs[0].discretization.dt", "-0.0001"]),
    ("sidecar-integrator-unknown", Input::LinNpy, "/runs/0/discretization/integrator", "\"rk4\"", &["data.json", "runs[0].discretization.integrator", "rk4"]),
    ("sidecar-noise-unknown", Input::LinNpy, "/runs/0/discretization/noise", "\"white\"", &["data.json", "runs[0].discretization.noise", "white"]),
    ("sidecar-burn-in-beyond-data", Input::LinNpy, "/runs/0/burn_in", "1000", &["data.json", "burn_in", "1000"]),
    ("sidecar-burn-in-negative", Input::LinNpy, "/runs/0/burn_in", "-1", &["data.json", "runs[0].burn_in", "-1"]),
    ("sidecar-dt-sample-wrong", Input::LinNpy, "/runs/0/dt_sample", "0.0003", &["data.json|trajectory-0000", "dt_sample", "0.0003"]),
    ("sidecar-dt-sample-wrong-csv", Input::LinCsv, "/runs/0/dt_sample", "0.0003", &["data.json|trajectory-0000", "dt_sample", "0.0003"]),
    ("sidecar-dt-sample-zero", Input::LinNpy, "/runs/0/dt_sample", "0", &["data.json", "runs[0].dt_sample", "0"]),
    ("sidecar-dt-sample-tiny", Input::LinNpy, "/runs/0/dt_sample", "1e-300", &["data.json", "runs[0].dt_sample", "1e-300|0.000000000000000"]),
    ("sidecar-position-beyond-l", Input::LinNpy, "/runs/0/positions/2", "1.5", &["data.json", "runs[0].positions[2]", "1.5"]),
    ("sidecar-position-negative", Input::LinNpy, "/runs/0/positions/1", "-0.25", &["data.json", "runs[0].positions[1]", "-0.25"]),
    ("sidecar-modes-1e6", Input::LinNpy, "/runs/0/modes", "1000000", &["data.json", "runs[0].modes", "1000000"]),
    ("sidecar-strain-ratio-on-linear", Input::LinNpy, "/runs/0/strain_ratio", "2.0", &["data.json", "runs[0].strain_ratio", "2"]),
    ("sidecar-comp-strain-ratio-nan", Input::CompCsv, "/runs/1/strain_ratio", "NaN", &["data.json", "runs[1].strain_ratio", "NaN"]),
    ("sidecar-comp-strain-ratio-huge", Input::CompCsv, "/runs/1/strain_ratio", "1e7", &["data.json", "runs[1].strain_ratio", "1e7|10000000"]),
    ("sidecar-comp-strain-ratio-string", Input::CompCsv, "/runs/1/strain_ratio", "\"2\"", &["data.json", "runs[1].strain_ratio", "\"2\""]),
    ("sidecar-comp-strain-duplicated", Input::CompCsv, "/runs/1/strain_ratio", "0.0", &["data.json", "runs[1]", "metropolis", "0"]),
    ("sidecar-comp-ea-zero", Input::CompCsv, "/filament/stretch_rigidity", "0", &["data.json", "filament.stretch_rigidity", "0"]),
    ("sidecar-comp-ea-nan", Input::CompCsv, "/filament/stretch_rigidity", "NaN", &["data.json", "filament.stretch_rigidity", "NaN"]),
    ("sidecar-comp-ea-negative", Input::CompCsv, "/filament/stretch_rigidity", "-1e6", &["data.json", "filament.stretch_rigidity", "-1e6|-1000000"]),
    ("sidecar-comp-burn-in-beyond-data", Input::CompCsv, "/runs/0/burn_in", "1000", &["data.json", "burn_in", "1000"]),
    ("sidecar-comp-modes-1e6", Input::CompCsv, "/runs/0/modes", "1000000", &["data.json", "runs[0].modes", "1000000"]),
    ("sidecar-comp-elements-zero", Input::CompCsv, "/runs/0/discretization/elements", "0", &["data.json", "runs[0].discretization.elements", "0"]),
    ("sidecar-comp-elements-1e8", Input::CompCsv, "/runs/0/discretization/elements", "100000000", &["data.json", "runs[0].discretization.elements", "100000000"]),
    ("sidecar-comp-integrator-unknown", Input::CompCsv, "/runs/0/discretization/integrator", "\"rk4\"", &["data.json", "runs[0].discretization.integrator", "rk4"]),
    ("sidecar-comp-dt-tiny", Input::CompCsv, "/runs/0/discretization/dt", "1e-300", &["data.json", "runs[0].discretization.dt", "1e-300|0.000000000000000"]),
    ("sidecar-comp-dt-sample-nan", Input::CompCsv, "/runs/2/dt_sample", "NaN", &["data.json", "runs[2].dt_sample", "NaN"]),
    ("sidecar-comp-file-parent", Input::CompCsv, "/runs/1/files/2", "\"../../x.csv\"", &["data.json", "runs[1].files[2]", "../../x.csv"]),
];

/// Sidecar keys removed: (case, JSON pointer, the key stderr must name).
#[rustfmt::skip]
const SIDECAR_MISSING: &[(&str, &str, &str)] = &[
    ("sidecar-missing-format", "/format", "format"),
    ("sidecar-missing-version", "/version", "version"),
    ("sidecar-missing-dims", "/dims", "dims"),
    ("sidecar-missing-filament", "/filament", "filament"),
    ("sidecar-missing-length", "/filament/length", "filament.length"),
    ("sidecar-missing-kt", "/filament/kt", "filament.kt"),
    ("sidecar-missing-runs", "/runs", "runs"),
    ("sidecar-missing-run-name", "/runs/0/name", "runs[0].name"),
    ("sidecar-missing-dt-sample", "/runs/0/dt_sample", "runs[0].dt_sample"),
    ("sidecar-missing-start", "/runs/0/start", "runs[0].start"),
    ("sidecar-missing-burn-in", "/runs/0/burn_in", "runs[0].burn_in"),
    ("sidecar-missing-positions", "/runs/0/positions", "runs[0].positions"),
    ("sidecar-missing-modes", "/runs/0/modes", "runs[0].modes"),
    ("sidecar-missing-files", "/runs/0/files", "runs[0].files"),
    ("sidecar-missing-model", "/runs/0/discretization/model", "runs[0].discretization.model"),
];

fn sidecar_cases() -> Vec<Case> {
    use Input::{CompCsv, LinCsv, LinNpy};
    use Kind::Sidecar as S;
    let mut v = vec![
        // --- Not JSON, cut, encodings --------------------------------------------------
        refused(
            S,
            LinNpy,
            "sidecar-not-json",
            &["data.json", "line 1"],
            |_, r| write(r, SIDECAR, "this is not JSON\n"),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-truncated",
            &["data.json", "line"],
            |_, r| {
                let b = read(r, SIDECAR);
                write(r, SIDECAR, &b[..b.len() / 2])
            },
        ),
        refused(
            S,
            LinNpy,
            "sidecar-empty",
            &["data.json", "empty|line 1|EOF|0 bytes"],
            |_, r| write(r, SIDECAR, ""),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-trailing-garbage",
            &["data.json", "line"],
            |_, r| {
                let mut b = read(r, SIDECAR);
                b.extend(b"\n}\n");
                write(r, SIDECAR, b)
            },
        ),
        refused(
            S,
            LinNpy,
            "sidecar-not-utf8",
            &["data.json", "UTF-8"],
            |_, r| {
                edit_text(r, SIDECAR, |t| {
                    t.replace("langevin-fem 0.1.0", "langevin-fem \u{1}X")
                });
                let b = read(r, SIDECAR);
                let at = b.iter().position(|&c| c == 1).expect("marker");
                let mut b = b;
                b[at] = 0xff;
                write(r, SIDECAR, b)
            },
        ),
        refused(
            S,
            LinNpy,
            "sidecar-utf16",
            &["data.json", "UTF-8|UTF-16"],
            |_, r| {
                let text = String::from_utf8(read(r, SIDECAR)).unwrap();
                let mut b = vec![0xff, 0xfe];
                for u in text.encode_utf16() {
                    b.extend(u.to_le_bytes());
                }
                write(r, SIDECAR, b)
            },
        ),
        unchanged(S, LinNpy, "sidecar-bom", |_, r| {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend(read(r, SIDECAR));
            write(r, SIDECAR, b)
        }),
        unchanged(S, LinNpy, "sidecar-crlf", |_, r| {
            edit_text(r, SIDECAR, |t| t.replace('\n', "\r\n"))
        }),
        unchanged(S, LinNpy, "sidecar-minified", |_, r| {
            let v = read_json(r, SIDECAR);
            write(r, SIDECAR, serde_json::to_string(&v).unwrap())
        }),
        unchanged(S, LinNpy, "sidecar-keys-reordered", |_, r| {
            // serde_json's maps are sorted: every object's keys in another order.
            let v = read_json(r, SIDECAR);
            write_json(r, SIDECAR, &v)
        }),
        unchanged(S, LinNpy, "sidecar-producer-edited", |_, r| {
            set_raw(
                r,
                SIDECAR,
                "/producer",
                "\"my-simulator 2.1 (édition spéciale)\"",
            )
        }),
        unchanged(S, LinNpy, "sidecar-producer-missing", |_, r| {
            remove_key(r, SIDECAR, "/producer")
        }),
        unchanged(S, LinNpy, "sidecar-provenance-missing", |_, r| {
            remove_key(r, SIDECAR, "/provenance")
        }),
        unchanged(S, LinNpy, "sidecar-columns-missing", |_, r| {
            remove_key(r, SIDECAR, "/columns")
        }),
        unchanged(S, CompCsv, "sidecar-comp-producer-edited", |_, r| {
            set_raw(r, SIDECAR, "/producer", "\"another producer\"")
        }),
        // --- The file itself is not a regular file, or too large ---------------------
        refused(S, LinNpy, "sidecar-fifo", &["data.json", "FIFO"], |_, r| {
            make_fifo(r, SIDECAR)
        }),
        refused(
            S,
            LinNpy,
            "sidecar-dev-zero",
            &["data.json", "device"],
            |_, r| make_link(r, SIDECAR, "/dev/zero"),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-directory",
            &["data.json", "directory"],
            |_, r| make_dir(r, SIDECAR),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-missing",
            &["data.json", "data"],
            |_, r| remove(r, SIDECAR),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-300-mib",
            &["data.json", "bytes|MiB"],
            |_, r| {
                let f = std::fs::OpenOptions::new()
                    .append(true)
                    .open(r.join(SIDECAR))
                    .unwrap();
                f.set_len(300 << 20).unwrap();
            },
        ),
        // --- Non-finite literals as Python's json.dump writes them ----------------------
        // --- null for a number ----------------------------------------------------------
        // --- Wrong types ------------------------------------------------------------------
        // --- Missing and unknown keys -------------------------------------------------------
        // --- Format, version, dims ------------------------------------------------------------
        refused(
            S,
            LinNpy,
            "sidecar-dims-3-on-2d-npy",
            &["data.json|trajectory-0000.npy", "dims|columns|v_0", "3"],
            |_, r| set_raw(r, SIDECAR, "/dims", "3"),
        ),
        refused(
            S,
            LinCsv,
            "sidecar-dims-3-on-2d-csv",
            &["data.json|trajectory-0000.csv", "dims|v_0", "3"],
            |_, r| set_raw(r, SIDECAR, "/dims", "3"),
        ),
        // --- Filament values ------------------------------------------------------------------
        // --- Runs ------------------------------------------------------------------------------
        refused(
            S,
            LinNpy,
            "sidecar-runs-duplicated",
            &["data.json", "runs[1].name", "crank-nicolson"],
            |_, r| {
                edit_json(r, SIDECAR, |v| {
                    let run = v["runs"][0].clone();
                    v["runs"].as_array_mut().unwrap().push(run);
                })
            },
        ),
        refused(
            S,
            LinNpy,
            "sidecar-npy-bytes-named-csv",
            &["trajectory-0001.csv", "header|column|UTF-8"],
            |_, r| {
                std::fs::rename(
                    r.join(LIN_NPY),
                    r.join("data/crank-nicolson/trajectory-0001.csv"),
                )
                .unwrap();
                set_raw(
                    r,
                    SIDECAR,
                    "/runs/0/files/1",
                    "\"crank-nicolson/trajectory-0001.csv\"",
                )
            },
        ),
        // --- The listed file is missing, a directory, a FIFO, a device -----------------------
        refused(
            S,
            LinNpy,
            "file-missing",
            &["trajectory-0001.npy", "runs[0].files[1]"],
            |_, r| remove(r, LIN_NPY),
        ),
        refused(
            S,
            LinNpy,
            "file-is-directory",
            &["trajectory-0001.npy", "runs[0].files[1]", "directory"],
            |_, r| make_dir(r, LIN_NPY),
        ),
        refused(
            S,
            LinNpy,
            "file-is-fifo",
            &["trajectory-0001.npy", "runs[0].files[1]", "FIFO"],
            |_, r| make_fifo(r, LIN_NPY),
        ),
        refused(
            S,
            LinCsv,
            "csv-file-is-fifo",
            &["trajectory-0001.csv", "runs[0].files[1]", "FIFO"],
            |_, r| make_fifo(r, LIN_CSV),
        ),
        refused(
            S,
            LinNpy,
            "file-links-to-dev-zero",
            &["trajectory-0001.npy", "runs[0].files[1]", "device"],
            |_, r| make_link(r, LIN_NPY, "/dev/zero"),
        ),
        refused(
            S,
            LinNpy,
            "file-links-to-another-listed-file",
            &[
                "data.json",
                "runs[0].files[1]",
                "runs[0].files[0]",
                "same file",
            ],
            |_, r| make_link(r, LIN_NPY, "trajectory-0000.npy"),
        ),
        refused(
            S,
            LinCsv,
            "csv-file-links-to-dev-zero",
            &["trajectory-0001.csv", "runs[0].files[1]", "device"],
            |_, r| make_link(r, LIN_CSV, "/dev/zero"),
        ),
        refused(
            S,
            LinNpy,
            "file-dangling-link",
            &["trajectory-0001.npy", "runs[0].files[1]"],
            |_, r| make_link(r, LIN_NPY, "nowhere.npy"),
        ),
        // --- Discretization --------------------------------------------------------------------
        // --- Times, positions, modes --------------------------------------------------------------
        refused(
            S,
            LinNpy,
            "sidecar-modes-more-than-columns",
            &["trajectory-0000.npy", "columns|aw_3", "9"],
            |_, r| set_raw(r, SIDECAR, "/runs/0/modes", "3"),
        ),
        refused(
            S,
            LinCsv,
            "sidecar-modes-more-than-columns-csv",
            &["trajectory-0000.csv", "aw_3"],
            |_, r| set_raw(r, SIDECAR, "/runs/0/modes", "3"),
        ),
        refused(
            S,
            LinNpy,
            "sidecar-positions-10001",
            &["data.json", "runs[0].positions", "10001"],
            |_, r| {
                edit_json(r, SIDECAR, |v| {
                    v["runs"][0]["positions"] = Value::from(vec![0.5; 10_001]);
                })
            },
        ),
        // --- Linear and compression data mixed up ------------------------------------------------
        refused(
            S,
            LinNpy,
            "linear-data-compression-scene",
            &["data.json", "strain_ratio", "tiny-compression"],
            |_, _| {},
        )
        .argv(&["check", "-q", "-s", "COMP", "-d", "data", "-o", "out"]),
        refused(
            S,
            CompCsv,
            "compression-data-linear-scene",
            &["data.json", "strain_ratio", "tiny-linear"],
            |_, _| {},
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "out"]),
        refused(
            S,
            CompCsv,
            "sidecar-comp-strain-ratio-removed",
            &[
                "data.json",
                "strain_ratio|runs[1].name",
                "tiny-compression|metropolis",
            ],
            |_, r| {
                edit_json(r, SIDECAR, |v| {
                    for run in v["runs"].as_array_mut().unwrap() {
                        run.as_object_mut().unwrap().remove("strain_ratio");
                    }
                })
            },
        ),
        // --- Compression sidecars ---------------------------------------------------------------------
        refused(
            S,
            CompCsv,
            "sidecar-comp-ea-missing",
            &["data.json", "filament.stretch_rigidity"],
            |_, r| remove_key(r, SIDECAR, "/filament/stretch_rigidity"),
        ),
    ];
    v.extend(
        SIDECAR_EDITS
            .iter()
            .map(|&(name, input, pointer, raw, expect)| {
                sidecar_raw(input, name, pointer, raw, expect)
            }),
    );
    v.extend(
        SIDECAR_MISSING
            .iter()
            .map(|&(name, pointer, key)| sidecar_missing(name, pointer, key)),
    );
    v.push(refused(
        S,
        CompCsv,
        "comp-file-is-fifo",
        &["trajectory-0002.csv", "runs[1].files[2]", "FIFO"],
        |_, r| make_fifo(r, COMP_CSV),
    ));
    v
}

fn npy_cases() -> Vec<Case> {
    use Input::{CompNpy, LinNpy};
    use Kind::Npy as N;
    let dict =
        |shape: &str| format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    let shaped = move |name: &str, shape: &'static str, expect: &[&str]| {
        let d = dict(shape);
        let mut e = vec!["trajectory-0001.npy"];
        e.extend(expect);
        refused(N, LinNpy, name, &e, move |_, r| npy_dict(r, LIN_NPY, &d))
    };
    vec![
        shaped(
            "npy-shape-2-pow-61",
            "(2305843009213693952, 1)",
            &["shape", "2305843009213693952"],
        ),
        shaped(
            "npy-shape-2-pow-61-by-8",
            "(2305843009213693952, 8)",
            &["shape", "2305843009213693952"],
        ),
        shaped(
            "npy-shape-bytes-wrap-to-zero",
            "(1152921504606846976, 2)",
            &["shape", "1152921504606846976"],
        ),
        shaped(
            "npy-shape-u64-max",
            "(18446744073709551615, 8)",
            &["shape", "18446744073709551615"],
        ),
        shaped(
            "npy-shape-larger-than-body",
            "(2102, 8)",
            &["shape", "2102"],
        ),
        shaped(
            "npy-shape-smaller-than-body",
            "(2100, 8)",
            &["shape", "2100"],
        ),
        shaped("npy-shape-fewer-columns", "(2101, 7)", &["shape", "7"]),
        shaped("npy-shape-1d", "(16808,)", &["shape|columns", "16808|1"]),
        shaped("npy-shape-3d", "(2101, 8, 1)", &["shape", "2101, 8, 1"]),
        shaped("npy-shape-negative", "(-2101, 8)", &["shape", "-2101"]),
        shaped("npy-shape-empty", "()", &["shape", "()"]),
        shaped("npy-shape-zero-rows", "(0, 8)", &["shape|rows", "0"]),
        refused(
            N,
            LinNpy,
            "npy-dtype-f4",
            &["trajectory-0001.npy", "descr|dtype", "<f4"],
            |_, r| {
                npy_dict(
                    r,
                    LIN_NPY,
                    "{'descr': '<f4', 'fortran_order': False, 'shape': (2101, 16), }",
                )
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-dtype-i8",
            &["trajectory-0001.npy", "descr|dtype", "<i8"],
            |_, r| {
                npy_dict(
                    r,
                    LIN_NPY,
                    "{'descr': '<i8', 'fortran_order': False, 'shape': (2101, 8), }",
                )
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-dtype-structured",
            &["trajectory-0001.npy", "descr|dtype", "[('t', '<f8')]"],
            |_, r| {
                npy_dict(
                    r,
                    LIN_NPY,
                    "{'descr': [('t', '<f8')], 'fortran_order': False, 'shape': (2101, 8), }",
                )
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-fortran-order",
            &[
                "trajectory-0001.npy",
                "fortran_order|Fortran",
                "True|Fortran order",
            ],
            |_, r| {
                npy_dict(
                    r,
                    LIN_NPY,
                    "{'descr': '<f8', 'fortran_order': True, 'shape': (2101, 8), }",
                )
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-header-no-shape",
            &["trajectory-0001.npy", "shape"],
            |_, r| npy_dict(r, LIN_NPY, "{'descr': '<f8', 'fortran_order': False, }"),
        ),
        refused(
            N,
            LinNpy,
            "npy-header-garbage",
            &["trajectory-0001.npy", "header"],
            |_, r| npy_dict(r, LIN_NPY, "garbage, not a dictionary"),
        ),
        unchanged(N, LinNpy, "npy-big-endian", |_, r| {
            let mut b = read(r, LIN_NPY);
            let body = npy_body(&b);
            for chunk in b[body..].chunks_exact_mut(8) {
                chunk.reverse();
            }
            write(r, LIN_NPY, b);
            npy_dict(
                r,
                LIN_NPY,
                "{'descr': '>f8', 'fortran_order': False, 'shape': (2101, 8), }",
            )
        }),
        unchanged(N, LinNpy, "npy-header-reformatted", |_, r| {
            npy_dict(
                r,
                LIN_NPY,
                "{'shape': (2101, 8), 'fortran_order': False, 'descr': '<f8'}",
            )
        }),
        refused(
            N,
            LinNpy,
            "npy-header-length-past-eof",
            &["trajectory-0001.npy", "header", "65535"],
            |_, r| {
                let mut b = read(r, LIN_NPY);
                b[8] = 0xff;
                b[9] = 0xff;
                b.truncate(1000);
                write(r, LIN_NPY, b)
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-v2-header-length-u32-max",
            &["trajectory-0001.npy", "header", "4294967295"],
            |_, r| {
                let b = read(r, LIN_NPY);
                let mut out = b[..6].to_vec();
                out.extend([2, 0, 0xff, 0xff, 0xff, 0xff]);
                out.extend(&b[10..]);
                write(r, LIN_NPY, out)
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-bad-magic",
            &["trajectory-0001.npy", "NUMPY|magic"],
            |_, r| {
                let mut b = read(r, LIN_NPY);
                b[5] = b'Z';
                write(r, LIN_NPY, b)
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-version-9",
            &["trajectory-0001.npy", "version", "9"],
            |_, r| {
                let mut b = read(r, LIN_NPY);
                b[6] = 9;
                write(r, LIN_NPY, b)
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-truncated-body",
            &["trajectory-0001.npy", "2101", "bytes"],
            |_, r| {
                let b = read(r, LIN_NPY);
                write(r, LIN_NPY, &b[..b.len() - 8])
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-truncated-mid-value",
            &["trajectory-0001.npy", "2101", "bytes"],
            |_, r| {
                let b = read(r, LIN_NPY);
                write(r, LIN_NPY, &b[..b.len() - 3])
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-truncated-in-header",
            &["trajectory-0001.npy", "header"],
            |_, r| {
                let b = read(r, LIN_NPY);
                write(r, LIN_NPY, &b[..50])
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-five-bytes",
            &["trajectory-0001.npy", "NUMPY|magic|5 bytes"],
            |_, r| write(r, LIN_NPY, b"\x93NUMP"),
        ),
        refused(
            N,
            LinNpy,
            "npy-empty-file",
            &["trajectory-0001.npy", "NUMPY|magic|0 bytes|empty"],
            |_, r| write(r, LIN_NPY, b""),
        ),
        refused(
            N,
            LinNpy,
            "npy-extra-bytes",
            &["trajectory-0001.npy", "2101", "bytes"],
            |_, r| {
                let mut b = read(r, LIN_NPY);
                b.extend([0u8; 8]);
                write(r, LIN_NPY, b)
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-csv-text-in-npy",
            &["trajectory-0001.npy", "NUMPY|magic"],
            |_, r| write(r, LIN_NPY, "t,w_0\n0,0\n"),
        ),
        // Values: the columns are t, w_0 … w_4 (x = 0, L/4, L/2, 3L/4, L), aw_1, aw_2; the
        // checks read w_2 (the profile and two-time point L/2) and aw_1, aw_2.
        refused(
            N,
            LinNpy,
            "npy-nan-in-aw-1",
            &["trajectory-0001.npy", "aw_1", "NaN", "row"],
            |_, r| npy_set(r, LIN_NPY, 1500, 6, f64::NAN),
        ),
        // Finite but beyond 1e60 (at 1e99 the fourth powers of a pooled variance's
        // error overflowed, and the estimator failed as if the data were too few).
        refused(
            N,
            LinNpy,
            "npy-1e99-in-aw-1",
            &["trajectory-0001.npy", "aw_1", "1e99", "row", "at most"],
            |_, r| npy_set(r, LIN_NPY, 1500, 6, 1e99),
        ),
        refused(
            N,
            LinNpy,
            "npy-inf-in-w-2",
            &["trajectory-0001.npy", "w_2", "inf", "row"],
            |_, r| npy_set(r, LIN_NPY, 1500, 3, f64::INFINITY),
        ),
        refused(
            N,
            LinNpy,
            "npy-minus-inf-in-aw-2",
            &["trajectory-0001.npy", "aw_2", "-inf", "row"],
            |_, r| npy_set(r, LIN_NPY, 2000, 7, f64::NEG_INFINITY),
        ),
        refused(
            N,
            LinNpy,
            "npy-nan-in-unread-w-1",
            &["trajectory-0001.npy", "w_1", "NaN", "row"],
            |_, r| npy_set(r, LIN_NPY, 1500, 2, f64::NAN),
        ),
        refused(
            N,
            LinNpy,
            "npy-nan-in-hinge-w-0",
            &["trajectory-0001.npy", "w_0", "NaN", "row"],
            |_, r| npy_set(r, LIN_NPY, 10, 1, f64::NAN),
        ),
        refused(
            N,
            LinNpy,
            "npy-nan-in-t",
            &["trajectory-0001.npy", "t", "NaN", "row"],
            |_, r| npy_set(r, LIN_NPY, 1500, 0, f64::NAN),
        ),
        refused(
            N,
            LinNpy,
            "npy-nan-before-burn-in",
            &["trajectory-0001.npy", "aw_1", "NaN", "row"],
            |_, r| npy_set(r, LIN_NPY, 3, 6, f64::NAN),
        ),
        refused(
            N,
            LinNpy,
            "npy-t-not-increasing",
            &["trajectory-0001.npy", "t", "row"],
            |_, r| {
                let (a, b) = (100, 101);
                let bytes = read(r, LIN_NPY);
                let (_, cols) = npy_shape(r, LIN_NPY);
                let body = npy_body(&bytes);
                let get = |row: usize| {
                    let at = body + row * cols * 8;
                    f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
                };
                let (ta, tb) = (get(a), get(b));
                npy_set(r, LIN_NPY, a, 0, tb);
                npy_set(r, LIN_NPY, b, 0, ta);
            },
        ),
        refused(
            N,
            LinNpy,
            "npy-t-wrong-cadence",
            &["trajectory-0001.npy", "t", "dt_sample"],
            |_, r| npy_column(r, LIN_NPY, 0, |_, t| 2.0 * t),
        ),
        // Compression .npy: t, force, stored_length.
        refused(
            N,
            CompNpy,
            "comp-npy-nan-force",
            &["trajectory-0002.npy", "force", "NaN", "row"],
            |_, r| npy_set(r, COMP_NPY, 10, 1, f64::NAN),
        ),
        refused(
            N,
            CompNpy,
            "comp-npy-inf-stored-length",
            &["trajectory-0002.npy", "stored_length", "inf", "row"],
            |_, r| npy_set(r, COMP_NPY, 10, 2, f64::INFINITY),
        ),
        refused(
            N,
            CompNpy,
            "comp-npy-every-t-equal",
            &["trajectory-0002.npy", "t", "row"],
            |_, r| {
                let first = {
                    let b = read(r, COMP_NPY);
                    let at = npy_body(&b);
                    f64::from_le_bytes(b[at..at + 8].try_into().unwrap())
                };
                npy_column(r, COMP_NPY, 0, |_, _| first)
            },
        ),
        refused(
            N,
            CompNpy,
            "comp-npy-shape-2-pow-61",
            &["trajectory-0002.npy", "shape", "2305843009213693952"],
            |_, r| {
                npy_dict(
                    r,
                    COMP_NPY,
                    "{'descr': '<f8', 'fortran_order': False, 'shape': (2305843009213693952, 1), }",
                )
            },
        ),
        refused(
            N,
            CompNpy,
            "comp-npy-shape-smaller",
            &["trajectory-0002.npy", "shape", "(10, 3)"],
            |_, r| {
                npy_dict(
                    r,
                    COMP_NPY,
                    "{'descr': '<f8', 'fortran_order': False, 'shape': (10, 3), }",
                )
            },
        ),
        refused(
            N,
            CompNpy,
            "comp-npy-two-columns",
            &["trajectory-0002.npy", "columns|shape", "2"],
            |_, r| {
                let (rows, _) = npy_shape(r, COMP_NPY);
                let b = read(r, COMP_NPY);
                let body = npy_body(&b);
                let mut out = b[..body].to_vec();
                for row in b[body..].chunks_exact(24) {
                    out.extend(&row[..16]);
                }
                write(r, COMP_NPY, out);
                npy_dict(
                    r,
                    COMP_NPY,
                    &format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, 2), }}"),
                )
            },
        ),
    ]
}

fn csv_cases() -> Vec<Case> {
    use Input::{CompCsv, LinCsv};
    use Kind::Csv as C;
    const T_COLUMN: &str = "\"t\"|`t`|column t|'t'| t = ";
    vec![
        refused(
            C,
            LinCsv,
            "csv-missing-header",
            &["trajectory-0001.csv", "header|\"t\""],
            |_, r| {
                edit_csv(r, LIN_CSV, |l| {
                    l.remove(0);
                })
            },
        ),
        refused(
            C,
            LinCsv,
            "csv-duplicate-column",
            &[
                "trajectory-0001.csv",
                "w_2",
                "twice|duplicate|more than once",
            ],
            |_, r| edit_csv(r, LIN_CSV, |l| add_column(l, "w_2", |_| "0.5".into())),
        ),
        refused(
            C,
            LinCsv,
            "csv-duplicate-column-replacing",
            &[
                "trajectory-0001.csv",
                "aw_1|aw_2",
                "twice|duplicate|more than once|column",
            ],
            |_, r| edit_csv(r, LIN_CSV, |l| l[0] = l[0].replace("aw_2", "aw_1")),
        ),
        refused(
            C,
            LinCsv,
            "csv-missing-column-aw-2",
            &["trajectory-0001.csv", "aw_2", "column"],
            |_, r| edit_csv(r, LIN_CSV, |l| drop_column(l, "aw_2")),
        ),
        refused(
            C,
            LinCsv,
            "csv-missing-column-t",
            &["trajectory-0001.csv", T_COLUMN],
            |_, r| edit_csv(r, LIN_CSV, |l| drop_column(l, "t")),
        ),
        refused(
            C,
            LinCsv,
            "csv-renamed-column",
            &["trajectory-0001.csv", "w_2"],
            |_, r| edit_csv(r, LIN_CSV, |l| l[0] = l[0].replace("w_2", "W_2")),
        ),
        refused(
            C,
            LinCsv,
            "csv-semicolons",
            &["trajectory-0001.csv", "column|header"],
            |_, r| edit_text(r, LIN_CSV, |t| t.replace(',', ";")),
        ),
        refused(
            C,
            LinCsv,
            "csv-non-number",
            &["trajectory-0001.csv", "aw_1", "abc", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "aw_1", "abc")),
        ),
        refused(
            C,
            LinCsv,
            "csv-nan",
            &["trajectory-0001.csv", "aw_1", "NaN", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "aw_1", "NaN")),
        ),
        refused(
            C,
            LinCsv,
            "csv-nan-lowercase",
            &["trajectory-0001.csv", "aw_2", "nan", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 1800, "aw_2", "nan")),
        ),
        refused(
            C,
            LinCsv,
            "csv-inf",
            &["trajectory-0001.csv", "w_2", "inf", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "w_2", "inf")),
        ),
        refused(
            C,
            LinCsv,
            "csv-minus-infinity",
            &["trajectory-0001.csv", "aw_2", "-infinity", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "aw_2", "-infinity")),
        ),
        refused(
            C,
            LinCsv,
            "csv-overflow-to-inf",
            &["trajectory-0001.csv", "aw_1", "1e400", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "aw_1", "1e400")),
        ),
        refused(
            C,
            LinCsv,
            "csv-empty-field",
            &["trajectory-0001.csv", "aw_1", "row", "\"\"|empty"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "aw_1", "")),
        ),
        refused(
            C,
            LinCsv,
            "csv-nan-in-unread-w-1",
            &["trajectory-0001.csv", "w_1", "NaN", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "w_1", "NaN")),
        ),
        refused(
            C,
            LinCsv,
            "csv-nan-in-t",
            &["trajectory-0001.csv", T_COLUMN, "NaN", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| set_field(l, 100, "t", "NaN")),
        ),
        refused(
            C,
            LinCsv,
            "csv-ragged-short-row",
            &["trajectory-0001.csv", "row"],
            |_, r| {
                edit_csv(r, LIN_CSV, |l| {
                    let cut = l[50].rfind(',').unwrap();
                    l[50].truncate(cut);
                })
            },
        ),
        refused(
            C,
            LinCsv,
            "csv-ragged-long-row",
            &["trajectory-0001.csv", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| l[50].push_str(",0.1")),
        ),
        refused(
            C,
            LinCsv,
            "csv-t-not-increasing",
            &["trajectory-0001.csv", T_COLUMN, "row"],
            |_, r| {
                edit_csv(r, LIN_CSV, |l| {
                    let t = |line: &str| line.split(',').next().unwrap().to_string();
                    let (a, b) = (t(&l[100]), t(&l[101]));
                    set_field(l, 100, "t", &b);
                    set_field(l, 101, "t", &a);
                })
            },
        ),
        refused(
            C,
            LinCsv,
            "csv-t-every-equal",
            &["trajectory-0001.csv", T_COLUMN, "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| map_column(l, "t", |_, _| "0.001".into())),
        ),
        refused(
            C,
            LinCsv,
            "csv-wrong-cadence",
            &["trajectory-0001.csv", T_COLUMN, "dt_sample"],
            |_, r| {
                edit_csv(r, LIN_CSV, |l| {
                    map_column(l, "t", |_, f| (2.0 * f.parse::<f64>().unwrap()).to_string())
                })
            },
        ),
        refused(
            C,
            LinCsv,
            "csv-row-missing",
            &["trajectory-0001.csv", T_COLUMN, "row"],
            |_, r| {
                edit_csv(r, LIN_CSV, |l| {
                    l.remove(1000);
                })
            },
        ),
        refused(
            C,
            LinCsv,
            "csv-empty-file",
            &["trajectory-0001.csv", "header|empty|0 bytes"],
            |_, r| write(r, LIN_CSV, ""),
        ),
        refused(
            C,
            LinCsv,
            "csv-header-only",
            &["trajectory-0001.csv", "row"],
            |_, r| edit_csv(r, LIN_CSV, |l| l.truncate(1)),
        ),
        refused(
            C,
            LinCsv,
            "csv-not-utf8",
            &["trajectory-0001.csv", "UTF-8", "row"],
            |_, r| {
                let mut b = read(r, LIN_CSV);
                let at = b.len() / 2;
                let at = at + b[at..].iter().position(|&c| c.is_ascii_digit()).unwrap();
                b[at] = 0xff;
                write(r, LIN_CSV, b)
            },
        ),
        unchanged(C, LinCsv, "csv-crlf", |_, r| {
            edit_text(r, LIN_CSV, |t| t.replace('\n', "\r\n"))
        }),
        unchanged(C, LinCsv, "csv-bom", |_, r| {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend(read(r, LIN_CSV));
            write(r, LIN_CSV, b)
        }),
        unchanged(C, LinCsv, "csv-extra-column", |_, r| {
            edit_csv(r, LIN_CSV, |l| {
                add_column(l, "temperature", |_| "300".into())
            })
        }),
        unchanged(C, LinCsv, "csv-columns-reordered", |_, r| {
            edit_csv(r, LIN_CSV, |l| {
                for line in l.iter_mut() {
                    let mut f: Vec<&str> = line.split(',').collect();
                    f.reverse();
                    *line = f.join(",");
                }
            })
        }),
        unchanged(C, LinCsv, "csv-quoted-header", |_, r| {
            edit_csv(r, LIN_CSV, |l| {
                l[0] = l[0]
                    .split(',')
                    .map(|h| format!("\"{h}\""))
                    .collect::<Vec<_>>()
                    .join(",")
            })
        }),
        unchanged(C, LinCsv, "csv-no-final-newline", |_, r| {
            edit_text(r, LIN_CSV, |t| t.trim_end().to_string())
        }),
        // Compression CSV: t, force, stored_length.
        refused(
            C,
            CompCsv,
            "comp-csv-every-t-equal",
            &["trajectory-0002.csv", T_COLUMN, "row"],
            |_, r| {
                edit_csv(r, COMP_CSV, |l| {
                    let first = l[1].split(',').next().unwrap().to_string();
                    map_column(l, "t", |_, _| first.clone())
                })
            },
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-empty-file",
            &["trajectory-0002.csv", "header|empty|0 bytes"],
            |_, r| write(r, COMP_CSV, ""),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-header-only",
            &["trajectory-0002.csv", "row"],
            |_, r| edit_csv(r, COMP_CSV, |l| l.truncate(1)),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-nan-force",
            &["trajectory-0002.csv", "force", "NaN", "row"],
            |_, r| edit_csv(r, COMP_CSV, |l| set_field(l, 10, "force", "NaN")),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-inf-stored-length",
            &["trajectory-0002.csv", "stored_length", "inf", "row"],
            |_, r| edit_csv(r, COMP_CSV, |l| set_field(l, 10, "stored_length", "inf")),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-non-number-force",
            &["trajectory-0002.csv", "force", "abc", "row"],
            |_, r| edit_csv(r, COMP_CSV, |l| set_field(l, 10, "force", "abc")),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-missing-force",
            &["trajectory-0002.csv", "force", "column"],
            |_, r| edit_csv(r, COMP_CSV, |l| drop_column(l, "force")),
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-t-decreasing",
            &["trajectory-0002.csv", T_COLUMN, "row"],
            |_, r| {
                edit_csv(r, COMP_CSV, |l| {
                    let n = l.len();
                    map_column(l, "t", |row, _| format!("{}", (n - row) as f64 * 1e-5))
                })
            },
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-wrong-cadence",
            &["trajectory-0002.csv", T_COLUMN, "dt_sample"],
            |_, r| {
                edit_csv(r, COMP_CSV, |l| {
                    map_column(l, "t", |_, f| (3.0 * f.parse::<f64>().unwrap()).to_string())
                })
            },
        ),
        refused(
            C,
            CompCsv,
            "comp-csv-ragged-row",
            &["trajectory-0002.csv", "row"],
            |_, r| edit_csv(r, COMP_CSV, |l| l[5].push_str(",1,2")),
        ),
        unchanged(C, CompCsv, "comp-csv-extra-column", |_, r| {
            edit_csv(r, COMP_CSV, |l| add_column(l, "note", |_| "x".into()))
        }),
        unchanged(C, CompCsv, "comp-csv-crlf", |_, r| {
            edit_text(r, COMP_CSV, |t| t.replace('\n', "\r\n"))
        }),
        unchanged(C, CompCsv, "comp-csv-bom", |_, r| {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend(read(r, COMP_CSV));
            write(r, COMP_CSV, b)
        }),
    ]
}

/// A case on every shard manifest of a set (`shards/1` … `shards/n`).
fn on_every_manifest(n: usize, f: impl Fn(&mut Value)) -> impl Fn(&Fixtures, &Path) {
    move |_, r| {
        for i in 1..=n {
            edit_json(r, &format!("shards/{i}/shard.json"), &f);
        }
    }
}

fn manifest_cases() -> Vec<Case> {
    use Input::{ConvergeSet, RunSet, VerifySet};
    use Kind::Manifest as M;
    const LIN_REC: &str = "records/tiny-linear/crank-nicolson.lin";
    const FRC_REC: &str = "records/tiny-compression/metropolis.frc";
    const SHA: &str = "SHA-256|sha256";
    const LIN_KEY: &str = "files[0]|files[tiny-linear/crank-nicolson]";
    vec![
        // --- The manifest as a file -------------------------------------------------------
        refused(
            M,
            VerifySet,
            "manifest-not-json",
            &[M2, "line 1"],
            |_, r| write(r, M2, "not JSON at all"),
        ),
        refused(
            M,
            VerifySet,
            "manifest-truncated",
            &[M2, "line|EOF"],
            |_, r| {
                let b = read(r, M2);
                write(r, M2, &b[..b.len() / 3])
            },
        ),
        refused(
            M,
            VerifySet,
            "manifest-empty",
            &[M2, "empty|EOF|0 bytes|line 1"],
            |_, r| write(r, M2, ""),
        ),
        refused(M, VerifySet, "manifest-fifo", &[M2, "FIFO"], |_, r| {
            make_fifo(r, M2)
        }),
        refused(
            M,
            VerifySet,
            "manifest-dev-zero",
            &[M2, "device"],
            |_, r| make_link(r, M2, "/dev/zero"),
        ),
        refused(
            M,
            VerifySet,
            "manifest-directory",
            &[M2, "directory"],
            |_, r| make_dir(r, M2),
        ),
        unchanged(M, VerifySet, "manifest-bom", |_, r| {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend(read(r, M2));
            write(r, M2, b)
        }),
        unchanged(M, VerifySet, "manifest-minified", |_, r| {
            let v = read_json(r, M2);
            write(r, M2, serde_json::to_string(&v).unwrap())
        }),
        unchanged(M, VerifySet, "manifest-provenance-edited", |_, r| {
            edit_json(r, M2, |m| {
                m["provenance"]["wall_seconds"] = Value::from(12345.0)
            })
        }),
        unchanged(M, VerifySet, "manifest-extra-file-in-shard", |_, r| {
            write(r, "shards/2/notes.txt", "a note of the user's")
        }),
        // --- Format, build, shard index ---------------------------------------------------
        refused(
            M,
            VerifySet,
            "manifest-format-other",
            &[M2, "format", "langevin-fem shards"],
            |_, r| edit_json(r, M2, |m| m["format"] = Value::from("langevin-fem shards")),
        ),
        refused(
            M,
            VerifySet,
            "manifest-format-version-2",
            &[M2, "format_version", "2"],
            |_, r| edit_json(r, M2, |m| m["format_version"] = Value::from(2)),
        ),
        refused(
            M,
            VerifySet,
            "manifest-format-version-string",
            &[M2, "format_version", "\"1\""],
            |_, r| edit_json(r, M2, |m| m["format_version"] = Value::from("1")),
        ),
        refused(
            M,
            VerifySet,
            "manifest-build-other",
            &[M2, "build", "9.9.9"],
            |_, r| {
                edit_json(r, M2, |m| {
                    m["build"] = Value::from("9.9.9 (commit 000000000000)")
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "manifest-index-0",
            &[M2, "shard", "0/3"],
            |_, r| edit_json(r, M2, |m| m["shard"]["index"] = Value::from(0)),
        ),
        refused(
            M,
            VerifySet,
            "manifest-index-4",
            &[M2, "shard", "4/3"],
            |_, r| edit_json(r, M2, |m| m["shard"]["index"] = Value::from(4)),
        ),
        refused(
            M,
            VerifySet,
            "manifest-index-negative",
            &[M2, "shard", "-1"],
            |_, r| set_raw(r, M2, "/shard/index", "-1"),
        ),
        refused(
            M,
            VerifySet,
            "manifest-count-0",
            &[M2, "shard", "2/0"],
            |_, r| edit_json(r, M2, |m| m["shard"]["count"] = Value::from(0)),
        ),
        refused(
            M,
            VerifySet,
            "manifest-count-huge",
            &[M2, "shard", "1000000000000"],
            |_, r| {
                edit_json(r, M2, |m| {
                    m["shard"]["count"] = Value::from(1_000_000_000_000u64)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "manifest-missing-files",
            &[M2, "files"],
            |_, r| remove_key(r, M2, "/files"),
        ),
        refused(
            M,
            VerifySet,
            "manifest-command-other-everywhere",
            &["shard.json", "command", "stability"],
            on_every_manifest(3, |m| m["command"] = Value::from("stability")),
        ),
        // --- Records against the manifest ----------------------------------------------------
        refused(
            M,
            VerifySet,
            "record-sha256-changed",
            &[M2, LIN_KEY, SHA],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    let s = e["sha256"].as_str().unwrap().to_string();
                    let flipped = if s.starts_with('0') { "1" } else { "0" };
                    e["sha256"] = Value::from(format!("{flipped}{}", &s[1..]));
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-size-changed",
            &[M2, LIN_KEY, "bytes"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["bytes"] = Value::from(e["bytes"].as_u64().unwrap() + 1)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-byte-flipped",
            &["shards/2", "crank-nicolson.lin", SHA],
            |_, r| {
                let rel = format!("shards/2/{LIN_REC}");
                let mut b = read(r, &rel);
                let mid = b.len() / 2;
                b[mid] ^= 1;
                write(r, &rel, b)
            },
        ),
        refused(
            M,
            VerifySet,
            "record-missing",
            &["shards/2", "crank-nicolson.lin"],
            |_, r| remove(r, &format!("shards/2/{LIN_REC}")),
        ),
        refused(
            M,
            VerifySet,
            "record-fifo",
            &["shards/2", "crank-nicolson.lin", "FIFO"],
            |_, r| make_fifo(r, &format!("shards/2/{LIN_REC}")),
        ),
        refused(
            M,
            VerifySet,
            "record-dev-zero",
            &["shards/2", "crank-nicolson.lin", "device"],
            |_, r| make_link(r, &format!("shards/2/{LIN_REC}"), "/dev/zero"),
        ),
        refused(
            M,
            VerifySet,
            "record-path-parent",
            &[M2, "../../../etc/passwd"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["path"] = Value::from("../../../etc/passwd")
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-path-absolute",
            &[M2, "/etc/passwd"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["path"] = Value::from("/etc/passwd")
                })
            },
        ),
        // Valid hash, undecodable content: only decoding can find these.
        refused(
            M,
            VerifySet,
            "record-undecodable-truncated",
            &["shards/2", "crank-nicolson.lin", "byte|offset|truncated"],
            |_, r| replace_record(r, "shards/2", LIN_REC, |b| b[..b.len() / 2].to_vec()),
        ),
        refused(
            M,
            VerifySet,
            "record-undecodable-magic",
            &["shards/2", "metropolis.frc", "LFEMFRC2|magic"],
            |_, r| {
                replace_record(r, "shards/2", FRC_REC, |mut b| {
                    b[..8].copy_from_slice(b"LFEMXXX9");
                    b
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-undecodable-trailing",
            &["shards/2", "crank-nicolson.lin", "byte|offset|trailing"],
            |_, r| {
                replace_record(r, "shards/2", LIN_REC, |mut b| {
                    b.extend([7u8; 13]);
                    b
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-undecodable-huge-count",
            &["shards/2", "crank-nicolson.lin", "1152921504606846976"],
            |_, r| {
                replace_record(r, "shards/2", LIN_REC, |mut b| {
                    b[8..16].copy_from_slice(&(1u64 << 60).to_le_bytes());
                    b
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-undecodable-huge-strains",
            &["shards/2", "metropolis.frc", "18446744073709551615"],
            |_, r| {
                replace_record(r, "shards/2", FRC_REC, |mut b| {
                    b[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
                    b
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "record-undecodable-zeros",
            &["shards/2", "crank-nicolson.lin", "LFEMLIN1|magic"],
            |_, r| replace_record(r, "shards/2", LIN_REC, |b| vec![0u8; b.len()]),
        ),
        refused(
            M,
            VerifySet,
            "record-of-another-kind",
            &["shards/2", "crank-nicolson.lin", "LFEMLIN1|magic"],
            |_, r| {
                let frc = read(r, &format!("shards/2/{FRC_REC}"));
                replace_record(r, "shards/2", LIN_REC, |_| frc)
            },
        ),
        // --- Ranges, runs, plans ------------------------------------------------------------------
        refused(
            M,
            VerifySet,
            "ranges-overlap",
            &[M2, "crank-nicolson", "first|0..1|overlap"],
            |_, r| edit_entry(r, M2, "crank-nicolson", |e| e["first"] = Value::from(0)),
        ),
        refused(
            M,
            VerifySet,
            "ranges-gap",
            &["shards/3/shard.json", "crank-nicolson", "first|3..|gap"],
            |_, r| {
                edit_entry(r, "shards/3/shard.json", "crank-nicolson", |e| {
                    e["first"] = Value::from(e["first"].as_u64().unwrap() + 1)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "range-count-edited",
            &[M2, "crank-nicolson", "count|2"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["count"] = Value::from(e["count"].as_u64().unwrap() + 1)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "range-count-1e12",
            &[M2, "crank-nicolson", "1000000000000"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["count"] = Value::from(1_000_000_000_000u64)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "range-first-u64-max",
            &[M2, "crank-nicolson", "18446744073709551615"],
            |_, r| {
                edit_entry(r, M2, "crank-nicolson", |e| {
                    e["first"] = Value::from(u64::MAX)
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "run-missing-from-one-manifest",
            &[M2, "crank-nicolson", "tiny-linear"],
            |_, r| {
                edit_json(r, M2, |m| {
                    m["files"]
                        .as_array_mut()
                        .unwrap()
                        .retain(|e| e["run"] != "crank-nicolson")
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "plans-differ",
            &[M2, "metropolis", "plan"],
            |_, r| {
                edit_entry(r, M2, "metropolis", |e| {
                    let s = e["common"]["main_steps"][0].as_u64().unwrap();
                    e["common"]["main_steps"][0] = Value::from(s + 1);
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "plans-nan-everywhere",
            &["shard.json", "main_tau1", "NaN|9221120237041090560"],
            move |_, r| {
                for i in 1..=3 {
                    let rel = format!("shards/{i}/shard.json");
                    let k = entry_index(r, &rel, "metropolis");
                    set_raw(r, &rel, &format!("/files/{k}/common/main_tau1/0"), NAN_BITS);
                }
            },
        ),
        refused(
            M,
            VerifySet,
            "plans-huge-steps-everywhere",
            &["shard.json", "main_steps", "1000000000000000000"],
            on_every_manifest(3, |m| {
                for e in m["files"].as_array_mut().unwrap() {
                    if e["run"] == "metropolis" {
                        e["common"]["main_steps"][0] = Value::from(1_000_000_000_000_000_000u64);
                    }
                }
            }),
        ),
        refused(
            M,
            VerifySet,
            "plans-garbage-everywhere",
            &["shard.json", "metropolis", "plan|common"],
            on_every_manifest(3, |m| {
                for e in m["files"].as_array_mut().unwrap() {
                    if e["run"] == "metropolis" {
                        e["common"] = Value::from("x");
                    }
                }
            }),
        ),
        // --- Scenes and settings -------------------------------------------------------------------
        refused(
            M,
            VerifySet,
            "scene-text-edited-everywhere",
            &["shard.json", "scenes[0]", SHA],
            on_every_manifest(3, |m| {
                let t = m["scenes"][0]["text"]
                    .as_str()
                    .unwrap()
                    .replace("elements = 4", "elements = 8");
                m["scenes"][0]["text"] = Value::from(t);
            }),
        ),
        refused(
            M,
            VerifySet,
            "scene-text-edited-in-one",
            &[M2, "scenes[0]", SHA],
            |_, r| {
                edit_json(r, M2, |m| {
                    let t = m["scenes"][0]["text"]
                        .as_str()
                        .unwrap()
                        .replace("elements = 4", "elements = 8");
                    m["scenes"][0]["text"] = Value::from(t);
                })
            },
        ),
        refused(
            M,
            VerifySet,
            "scene-sha256-edited-everywhere",
            &["shard.json", "scenes[1]", SHA],
            on_every_manifest(3, |m| {
                m["scenes"][1]["sha256"] = Value::from("0".repeat(64));
            }),
        ),
        refused(
            M,
            VerifySet,
            "scene-text-not-toml-everywhere",
            &["shard.json", "scenes[0]", SHA],
            on_every_manifest(3, |m| {
                m["scenes"][0]["text"] = Value::from("this is = = not TOML");
            }),
        ),
        // The text and its SHA-256 edited together: the text's own key is named, under
        // the manifest's, not the scene's original file or built-in label.
        refused(
            M,
            VerifySet,
            "scene-text-and-sha256-edited-everywhere",
            &[
                "shard.json",
                "scenes[0].text: ",
                "bogus_key",
                "rerun the shards",
            ],
            on_every_manifest(3, |m| {
                let t = m["scenes"][0]["text"].as_str().unwrap().replacen(
                    "[filament]",
                    "[filament]\nbogus_key = 3",
                    1,
                );
                m["scenes"][0]["sha256"] = Value::from(sha256_hex(t.as_bytes()));
                m["scenes"][0]["text"] = Value::from(t);
            }),
        ),
        refused(
            M,
            VerifySet,
            "settings-budget-unknown-everywhere",
            &["shard.json", "budget", "huge"],
            on_every_manifest(3, |m| {
                m["settings"]["budget"] = Value::from("huge");
            }),
        ),
        refused(
            M,
            VerifySet,
            "settings-alpha-out-of-range-everywhere",
            &["shard.json", "alpha", "0.9"],
            on_every_manifest(3, |m| {
                m["settings"]["alpha"] = Value::from(0.9);
            }),
        ),
        refused(
            M,
            VerifySet,
            "settings-alpha-differs",
            &[M2, "settings", "0.05"],
            |_, r| edit_json(r, M2, |m| m["settings"]["alpha"] = Value::from(0.05)),
        ),
        // --- Missing and duplicated shards ------------------------------------------------------------
        refused(
            M,
            VerifySet,
            "shard-missing",
            &["2/3", "missing"],
            |_, _| {},
        )
        .argv(&["merge", "-q", "shards/1", "shards/3", "-o", "out"]),
        refused(
            M,
            VerifySet,
            "shard-given-twice",
            &["shards/1", "1/3", "twice|duplicate"],
            |_, _| {},
        )
        .argv(&[
            "merge", "-q", "shards/1", "shards/1", "shards/2", "shards/3", "-o", "out",
        ]),
        refused(
            M,
            VerifySet,
            "shard-copied",
            &["shards/copy", "1/3", "twice|duplicate"],
            |f, r| copy_tree(&f.src(Input::VerifySet).join("1"), &r.join("shards/copy")),
        )
        .argv(&[
            "merge",
            "-q",
            "shards/1",
            "shards/copy",
            "shards/2",
            "shards/3",
            "-o",
            "out",
        ]),
        refused(
            M,
            VerifySet,
            "shard-directory-empty",
            &["shards/2", "shard.json"],
            |_, r| {
                std::fs::remove_dir_all(r.join("shards/2")).unwrap();
                std::fs::create_dir_all(r.join("shards/2")).unwrap();
            },
        ),
        refused(
            M,
            VerifySet,
            "shard-directory-missing",
            &["shards/9", "not|no such|does not exist|cannot"],
            |_, _| {},
        )
        .argv(&[
            "merge", "-q", "shards/1", "shards/2", "shards/9", "-o", "out",
        ]),
        refused(
            M,
            VerifySet,
            "shard-of-another-set",
            &["shards/2", "command|set of 2|2 shards", "run"],
            |f, r| {
                std::fs::remove_dir_all(r.join("shards/2")).unwrap();
                copy_tree(&f.src(Input::RunSet).join("2"), &r.join("shards/2"))
            },
        ),
        // --- run shards ---------------------------------------------------------------------------------
        refused(
            M,
            RunSet,
            "run-settings-trajectories-1e12",
            &["shard.json", "trajectories", "1000000000000"],
            on_every_manifest(2, |m| {
                m["settings"]["trajectories"] = Value::from(1_000_000_000_000u64);
            }),
        ),
        refused(
            M,
            RunSet,
            "run-settings-every-0",
            &["shard.json", "every", "0"],
            on_every_manifest(2, |m| {
                m["settings"]["every"] = Value::from(0);
            }),
        ),
        refused(
            M,
            RunSet,
            "run-settings-duration-huge",
            &["shard.json", "duration_tau1", "1e300|100000000000000000000"],
            on_every_manifest(2, |m| {
                m["settings"]["duration_tau1"] = Value::from(1e300);
            }),
        ),
        refused(
            M,
            RunSet,
            "run-settings-format-unknown",
            &["shard.json", "format", "xls"],
            on_every_manifest(2, |m| {
                m["settings"]["format"] = Value::from("xls");
            }),
        ),
        refused(
            M,
            RunSet,
            "run-settings-run-unknown",
            &["shard.json", "runs", "nope"],
            on_every_manifest(2, |m| {
                m["settings"]["runs"] = Value::from(vec!["nope"]);
            }),
        ),
        refused(
            M,
            RunSet,
            "run-trajectory-byte-flipped",
            &["shards/2", "trajectory-0002.npy", SHA],
            |_, r| {
                let rel = "shards/2/crank-nicolson/trajectory-0002.npy";
                let mut b = read(r, rel);
                let at = b.len() - 100;
                b[at] ^= 0x10;
                write(r, rel, b)
            },
        ),
        refused(
            M,
            RunSet,
            "run-trajectory-undecodable",
            &["shards/2", "trajectory-0002.npy", "2101|bytes|shape"],
            |_, r| {
                replace_record(r, "shards/2", "crank-nicolson/trajectory-0002.npy", |b| {
                    b[..b.len() - 800].to_vec()
                })
            },
        ),
        refused(
            M,
            RunSet,
            "run-trajectory-nan-rehashed",
            &["shards/2", "trajectory-0002.npy", "NaN"],
            |_, r| {
                replace_record(
                    r,
                    "shards/2",
                    "crank-nicolson/trajectory-0002.npy",
                    |mut b| {
                        let at = npy_body(&b) + (1000 * 8 + 6) * 8;
                        b[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
                        b
                    },
                )
            },
        ),
        refused(
            M,
            RunSet,
            "run-entry-missing",
            &[M2, "trajectory-0003.npy|trajectory 3"],
            |_, r| {
                edit_json(r, M2, |m| {
                    m["files"].as_array_mut().unwrap().pop();
                })
            },
        ),
        refused(
            M,
            RunSet,
            "run-entry-overlap",
            &[M2, "trajectory 1|trajectories 1|first", "1"],
            |_, r| edit_json(r, M2, |m| m["files"][0]["first"] = Value::from(1)),
        ),
        refused(
            M,
            RunSet,
            "run-path-escapes-to-other-shard",
            &[M2, "../1/crank-nicolson/trajectory-0000.npy"],
            |_, r| {
                let other = read(r, "shards/1/crank-nicolson/trajectory-0000.npy");
                edit_json(r, M2, |m| {
                    m["files"][0]["path"] = Value::from("../1/crank-nicolson/trajectory-0000.npy");
                    m["files"][0]["bytes"] = Value::from(other.len() as u64);
                    m["files"][0]["sha256"] = Value::from(sha256_hex(&other));
                })
            },
        ),
        refused(
            M,
            RunSet,
            "run-manifest-not-json",
            &[M2, "line 1"],
            |_, r| write(r, M2, "{]"),
        ),
        refused(
            M,
            RunSet,
            "run-shard-count-0",
            &[M2, "shard", "2/0"],
            |_, r| edit_json(r, M2, |m| m["shard"]["count"] = Value::from(0)),
        ),
        unchanged(M, RunSet, "run-provenance-edited", |_, r| {
            edit_json(r, M2, |m| {
                m["provenance"]["wall_seconds"] = Value::from(1.5)
            })
        }),
        // --- converge shards ------------------------------------------------------------------------------
        refused(
            M,
            ConvergeSet,
            "converge-settings-values-tiny",
            &["shard.json", "values", "1e-300|0.000000000000000"],
            on_every_manifest(2, |m| {
                m["settings"]["values"] = Value::from(vec![0.02, 1e-300]);
            }),
        ),
        refused(
            M,
            ConvergeSet,
            "converge-settings-over-unknown",
            &["shard.json", "over|settings", "mass"],
            on_every_manifest(2, |m| {
                m["settings"]["over"] = Value::from("mass");
            }),
        ),
        refused(
            M,
            ConvergeSet,
            "converge-record-byte-flipped",
            &["shards/2", "dt=0.02.lin", SHA],
            |_, r| {
                let rel = "shards/2/records/tiny-linear/crank-nicolson/dt=0.02.lin";
                let mut b = read(r, rel);
                let mid = b.len() / 2;
                b[mid] ^= 4;
                write(r, rel, b)
            },
        ),
        refused(
            M,
            ConvergeSet,
            "converge-record-undecodable",
            &["shards/2", "dt=0.02.lin", "byte|offset|truncated"],
            |_, r| {
                replace_record(
                    r,
                    "shards/2",
                    "records/tiny-linear/crank-nicolson/dt=0.02.lin",
                    |b| b[..b.len() - 5].to_vec(),
                )
            },
        ),
        refused(
            M,
            ConvergeSet,
            "converge-record-huge-count",
            &["shards/2", "dt=0.01.lin", "1152921504606846976"],
            |_, r| {
                replace_record(
                    r,
                    "shards/2",
                    "records/tiny-linear/crank-nicolson/dt=0.01.lin",
                    |mut b| {
                        b[8..16].copy_from_slice(&(1u64 << 60).to_le_bytes());
                        b
                    },
                )
            },
        ),
        refused(
            M,
            ConvergeSet,
            "converge-run-missing",
            &[M2, "dt=0.01"],
            |_, r| {
                edit_json(r, M2, |m| {
                    m["files"].as_array_mut().unwrap().pop();
                })
            },
        ),
        refused(
            M,
            ConvergeSet,
            "converge-ranges-overlap",
            &[M2, "crank-nicolson/dt=0.02", "first|overlap|0.."],
            |_, r| edit_json(r, M2, |m| m["files"][0]["first"] = Value::from(0)),
        ),
        refused(
            M,
            ConvergeSet,
            "converge-manifest-truncated",
            &[M2, "line|EOF"],
            |_, r| {
                let b = read(r, M2);
                write(r, M2, &b[..b.len() - 10])
            },
        ),
        unchanged(M, ConvergeSet, "converge-provenance-edited", |_, r| {
            edit_json(r, M2, |m| {
                m["provenance"]["wall_seconds"] = Value::from(2.5)
            })
        }),
    ]
}

/// A `--plan-from` case: the entry of run `metropolis` in `plan/shard.json` edited.
fn plan_case(name: &str, expect: &[&str], f: impl Fn(&mut Value) + Send + Sync + 'static) -> Case {
    let mut e = vec!["plan/shard.json", "--plan-from"];
    e.extend(expect);
    refused(Kind::PlanFrom, Input::PlanFrom, name, &e, move |_, r| {
        edit_entry(r, PLAN, "metropolis", |entry| f(&mut entry["common"]))
    })
}

/// A `--plan-from` case: a raw value at `field` of the plan of run `metropolis`.
fn plan_raw(name: &str, field: &'static str, raw: &'static str, expect: &[&str]) -> Case {
    let mut e = vec!["plan/shard.json", "--plan-from"];
    e.extend(expect);
    refused(Kind::PlanFrom, Input::PlanFrom, name, &e, move |_, r| {
        let k = entry_index(r, PLAN, "metropolis");
        set_raw(r, PLAN, &format!("/files/{k}/common/{field}"), raw)
    })
}

/// `--plan-from` plan edits: (case, field of the plan of run `metropolis` in
/// `plan/shard.json` (a JSON pointer below `common`), raw value put there, what stderr must
/// name besides `plan/shard.json` and `--plan-from`). Plans store floats as their IEEE-754
/// bits.
#[rustfmt::skip]
const PLAN_EDITS: &[(&str, &str, &str, &[&str])] = &[
    ("plan-main-steps-1e18", "main_steps/0", "1000000000000000000", &["main_steps", "1000000000000000000"]),
    ("plan-main-steps-zero", "main_steps/0", "0", &["main_steps", "0"]),
    ("plan-main-steps-negative", "main_steps/0", "-5", &["main_steps", "-5"]),
    ("plan-main-tau1-nan", "main_tau1/0", NAN_BITS, &["main_tau1", "NaN|9221120237041090560"]),
    ("plan-main-tau1-inf", "main_tau1/1", INF_BITS, &["main_tau1", "inf|9218868437227405312"]),
    ("plan-main-tau1-negative", "main_tau1/0", MINUS_ONE_BITS, &["main_tau1", "-1|13830554455654793216"]),
    ("plan-main-tau1-zero", "main_tau1/0", "0", &["main_tau1", "0"]),
    ("plan-main-tau1-float", "main_tau1/0", "4.5", &["main_tau1", "4.5"]),
    ("plan-pilot-tau1-nan", "pilot_tau1", NAN_BITS, &["pilot_tau1", "NaN|9221120237041090560"]),
    ("plan-pilot-std-error-inf", "pilot_std_error/0", INF_BITS, &["pilot_std_error", "inf|9218868437227405312"]),
    ("plan-search-dt-nan", "search/0/0", NAN_BITS, &["search", "NaN|9221120237041090560"]),
    ("plan-search-dt-zero", "search/0/0", "0", &["search", "0"]),
];

fn plan_from_cases() -> Vec<Case> {
    use Input::PlanFrom as P;
    use Kind::PlanFrom as K;
    const NOT_OUT: &[&str] = &["out/shard.json"];
    let mut v: Vec<Case> = PLAN_EDITS
        .iter()
        .map(|&(name, field, raw, expect)| plan_raw(name, field, raw, expect))
        .collect();
    v.extend(vec![
        plan_case("plan-main-steps-short", &["main_steps", "3"], |c| {
            c["main_steps"].as_array_mut().unwrap().pop();
        }),
        plan_case("plan-common-null", &["metropolis", "plan"], |c| {
            *c = Value::Null
        }),
        plan_case("plan-common-garbage", &["metropolis", "plan|common"], |c| {
            *c = Value::from("x")
        }),
        plan_case("plan-search-garbage", &["search"], |c| {
            c["search"] = Value::from(vec![1, 2, 3])
        }),
        refused(
            K,
            P,
            "plan-from-not-a-shard",
            &["--plan-from", "plan"],
            |_, r| {
                std::fs::remove_dir_all(r.join("plan")).unwrap();
                std::fs::create_dir_all(r.join("plan")).unwrap();
            },
        ),
        refused(
            K,
            P,
            "plan-from-run-data",
            &["--plan-from", "plan"],
            |f, r| {
                std::fs::remove_dir_all(r.join("plan")).unwrap();
                copy_tree(&f.src(Input::CompCsv), &r.join("plan"));
            },
        ),
        refused(
            K,
            P,
            "plan-from-nonexistent",
            &["--plan-from", "nowhere"],
            |_, _| {},
        )
        .argv(&[
            "verify",
            "-q",
            "-s",
            "COMP",
            "--shard",
            "2/3",
            "--plan-from",
            "nowhere",
            "-o",
            "out",
        ]),
        refused(
            K,
            P,
            "plan-from-a-file",
            &["--plan-from", "data.json"],
            |f, r| {
                copy_tree(&f.src(Input::CompCsv), &r.join("other"));
            },
        )
        .argv(&[
            "verify",
            "-q",
            "-s",
            "COMP",
            "--shard",
            "2/3",
            "--plan-from",
            "other/data.json",
            "-o",
            "out",
        ]),
        refused(
            K,
            P,
            "plan-manifest-not-json",
            &["--plan-from", PLAN, "line 1"],
            |_, r| write(r, PLAN, "not JSON"),
        ),
        refused(
            K,
            P,
            "plan-manifest-fifo",
            &["--plan-from", PLAN, "FIFO"],
            |_, r| make_fifo(r, PLAN),
        ),
        refused(
            K,
            P,
            "plan-manifest-dev-zero",
            &["--plan-from", PLAN, "device"],
            |_, r| make_link(r, PLAN, "/dev/zero"),
        ),
        refused(
            K,
            P,
            "plan-format-version-9",
            &["--plan-from", PLAN, "format_version", "9"],
            |_, r| edit_json(r, PLAN, |m| m["format_version"] = Value::from(9)),
        ),
        refused(
            K,
            P,
            "plan-index-0",
            &["--plan-from", PLAN, "shard", "0/3"],
            |_, r| edit_json(r, PLAN, |m| m["shard"]["index"] = Value::from(0)),
        ),
        refused(
            K,
            P,
            "plan-seed-other",
            &["--plan-from", PLAN, "seed", "7"],
            |_, r| edit_json(r, PLAN, |m| m["scenes"][0]["seed"] = Value::from(7)),
        ),
        refused(
            K,
            P,
            "plan-scene-text-edited",
            &["--plan-from", PLAN, "scenes[0]", "SHA-256|sha256"],
            |_, r| {
                edit_json(r, PLAN, |m| {
                    let t = m["scenes"][0]["text"]
                        .as_str()
                        .unwrap()
                        .replace("elements = 4", "elements = 8");
                    m["scenes"][0]["text"] = Value::from(t);
                })
            },
        ),
        refused(
            K,
            P,
            "plan-from-a-run-shard",
            &["--plan-from", PLAN, "`run`|run"],
            |f, r| {
                std::fs::remove_dir_all(r.join("plan")).unwrap();
                copy_tree(&f.src(Input::RunSet).join("1"), &r.join("plan"));
            },
        ),
        refused(
            K,
            P,
            "plan-from-other-scenes",
            &["--plan-from", PLAN, "tiny-linear"],
            |f, r| {
                std::fs::remove_dir_all(r.join("plan")).unwrap();
                copy_tree(&f.src(Input::VerifySet).join("1"), &r.join("plan"));
            },
        ),
        refused(
            K,
            P,
            "plan-run-missing",
            &["--plan-from", PLAN, "metropolis"],
            |_, r| {
                edit_json(r, PLAN, |m| {
                    m["files"]
                        .as_array_mut()
                        .unwrap()
                        .retain(|e| e["run"] != "metropolis")
                })
            },
        ),
        unchanged(K, P, "plan-provenance-edited", |_, r| {
            edit_json(r, PLAN, |m| {
                m["provenance"]["wall_seconds"] = Value::from(99.0)
            })
        }),
        unchanged(K, P, "plan-record-files-removed", |_, r| {
            // --plan-from reads the plans of the manifest, not the records.
            std::fs::remove_dir_all(r.join("plan/records")).unwrap();
        }),
    ]);
    // A refusal of the --plan-from shard names it, never the shard being written in --out.
    v.into_iter().map(|c| c.forbid(NOT_OUT)).collect()
}

fn out_dir_cases() -> Vec<Case> {
    use Input::{LinCsv, LinNpy, PlanFrom, RunSet, VerifySet};
    use Kind::OutDir as O;
    vec![
        refused(
            O,
            LinNpy,
            "check-out-is-the-data-dir",
            &["--out", "data"],
            |_, _| {},
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "data"]),
        refused(
            O,
            LinNpy,
            "check-out-is-the-data-dir-spelled-otherwise",
            &["--out", "data/."],
            |_, _| {},
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "data/."]),
        refused(
            O,
            LinNpy,
            "check-out-inside-the-data-dir",
            &["--out", "data/crank-nicolson"],
            |_, _| {},
        )
        .argv(&[
            "check",
            "-q",
            "-s",
            "LIN",
            "-d",
            "data",
            "-o",
            "data/crank-nicolson",
        ]),
        refused(
            O,
            LinNpy,
            "check-out-holds-run-output",
            &["--out", "other", "data.json"],
            |f, r| copy_tree(&f.src(Input::LinCsv), &r.join("other")),
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "other"]),
        refused(
            O,
            LinNpy,
            "check-out-holds-a-shard",
            &["--out", "other", "shard.json"],
            |f, r| copy_tree(&f.src(Input::VerifySet).join("1"), &r.join("other")),
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "other"]),
        refused(
            O,
            LinCsv,
            "check-out-is-a-file",
            &["--out", "data.json"],
            |_, _| {},
        )
        .argv(&[
            "check",
            "-q",
            "-s",
            "LIN",
            "-d",
            "data",
            "-o",
            "data/data.json",
        ]),
        refused(
            O,
            LinCsv,
            "check-data-is-a-file",
            &["--data", "data.json"],
            |_, _| {},
        )
        .argv(&[
            "check",
            "-q",
            "-s",
            "LIN",
            "-d",
            "data/data.json",
            "-o",
            "out",
        ]),
        refused(
            O,
            VerifySet,
            "merge-out-is-a-shard",
            &["--out", "shards/2"],
            |_, _| {},
        )
        .argv(&[
            "merge", "-q", "shards/1", "shards/2", "shards/3", "-o", "shards/2",
        ]),
        refused(
            O,
            VerifySet,
            "merge-out-is-the-shards-parent",
            &["--out", "shards"],
            |_, _| {},
        )
        .argv(&["merge", "-q", "shards", "-o", "shards"]),
        refused(
            O,
            RunSet,
            "merge-run-out-is-a-shard",
            &["--out", "shards/1"],
            |_, _| {},
        )
        .argv(&["merge", "-q", "shards/1", "shards/2", "-o", "shards/1"]),
        refused(
            O,
            RunSet,
            "merge-run-out-holds-a-check-report",
            &["--out", "other", "summary.json|check"],
            |f, r| copy_tree(&f.baseline(Input::LinNpy).join("out"), &r.join("other")),
        )
        .argv(&["merge", "-q", "shards/1", "shards/2", "-o", "other"]),
        refused(
            O,
            VerifySet,
            "merge-verify-out-holds-run-data",
            &["--out", "other", "data.json|run"],
            |f, r| copy_tree(&f.src(Input::LinNpy), &r.join("other")),
        )
        .argv(&[
            "merge", "-q", "shards/1", "shards/2", "shards/3", "-o", "other",
        ]),
        refused(
            O,
            LinNpy,
            "check-out-holds-a-verify-report",
            &["--out", "other", "verify|summary.json"],
            |f, r| copy_tree(&f.baseline(Input::VerifySet).join("out"), &r.join("other")),
        )
        .argv(&["check", "-q", "-s", "LIN", "-d", "data", "-o", "other"]),
        refused(
            O,
            PlanFrom,
            "verify-out-is-the-plan-from-shard",
            &["--out", "--plan-from", "plan"],
            |_, _| {},
        )
        .argv(&[
            "verify",
            "-q",
            "-s",
            "COMP",
            "--shard",
            "2/3",
            "--plan-from",
            "plan",
            "-o",
            "plan",
        ]),
    ]
}

/// The corpus.
fn corpus() -> Vec<Case> {
    let mut v = sidecar_cases();
    v.extend(npy_cases());
    v.extend(csv_cases());
    v.extend(manifest_cases());
    v.extend(plan_from_cases());
    v.extend(out_dir_cases());
    v
}

// ---------------------------------------------------------------------------------------
// Running a case
// ---------------------------------------------------------------------------------------

/// What a child did.
struct Run {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
    timed_out: bool,
}

/// Runs the binary with `argv` in `cwd` (one rayon thread, address space capped at
/// [`MEMORY_LIMIT_KIB`], stdin closed, stderr to `log`); kills it after [`TIMEOUT`].
fn execute(cwd: &Path, argv: &[String], log: &Path) -> Run {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {MEMORY_LIMIT_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(BIN)
        .args(argv)
        .current_dir(cwd)
        .env("RAYON_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(log).expect("log"))
        .spawn()
        .expect("the binary runs");
    let status = common::wait_or_kill(&mut child, TIMEOUT);
    Run {
        code: status.and_then(|s| s.code()),
        stderr: std::fs::read_to_string(log).unwrap_or_default(),
        seconds: start.elapsed().as_secs_f64(),
        timed_out: status.is_none(),
    }
}

/// One node of a tree, compared without following links or opening special files.
#[derive(Debug, PartialEq)]
enum Node {
    Dir,
    File(String),
    Link(PathBuf),
    Special,
}

/// Every node under `dir` by relative path (top-level names in `skip` left out).
fn snapshot(dir: &Path, skip: &[&str]) -> BTreeMap<String, Node> {
    fn walk(root: &Path, dir: &Path, skip: &[&str], out: &mut BTreeMap<String, Node>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            let rel = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
            if dir == root && skip.contains(&rel.as_str()) {
                continue;
            }
            let Ok(meta) = std::fs::symlink_metadata(&p) else {
                continue;
            };
            let t = meta.file_type();
            let node = if t.is_symlink() {
                Node::Link(std::fs::read_link(&p).unwrap_or_default())
            } else if t.is_dir() {
                walk(root, &p, skip, out);
                Node::Dir
            } else if t.is_file() {
                Node::File(hash_file(&p))
            } else {
                Node::Special
            };
            out.insert(rel, node);
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, skip, &mut out);
    out
}

/// SHA-256 of a regular file, read in chunks (a sparse file of hundreds of MiB is fine).
fn hash_file(p: &Path) -> String {
    let mut h = Sha256::new();
    let mut f = std::fs::File::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf).expect("read");
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The differences between two snapshots: (changed or missing, added).
fn diff(
    before: &BTreeMap<String, Node>,
    after: &BTreeMap<String, Node>,
) -> (Vec<String>, Vec<String>) {
    let mut lost = Vec::new();
    for (k, v) in before {
        match after.get(k) {
            None => lost.push(format!("{k} missing")),
            Some(w) if w != v => lost.push(format!("{k} changed")),
            _ => {}
        }
    }
    let added = after
        .keys()
        .filter(|k| !before.contains_key(*k))
        .cloned()
        .collect();
    (lost, added)
}

/// What a case did and what is wrong with it, by class.
struct Outcome {
    run: Run,
    argv: Vec<String>,
    /// Panic, signal, hang, data loss.
    unsafe_: Vec<String>,
    /// A wrong exit code, writing into an input.
    wrong: Vec<String>,
    /// Expected strings missing from stderr, forbidden ones present.
    unnamed: Vec<String>,
}

impl Outcome {
    fn passed(&self) -> bool {
        self.unsafe_.is_empty() && self.wrong.is_empty() && self.unnamed.is_empty()
    }

    /// The first line of stderr that is not a warning (or the first line).
    fn first_line(&self) -> String {
        let lines: Vec<&str> = self
            .run
            .stderr
            .lines()
            .filter(|l| !l.trim().is_empty())
            .collect();
        let line = lines
            .iter()
            .find(|l| !l.starts_with("warning"))
            .or(lines.first())
            .copied()
            .unwrap_or("(no stderr)");
        let mut s: String = line.chars().take(220).collect();
        if line.chars().count() > 220 {
            s.push('…');
        }
        s
    }

    fn got(&self) -> String {
        if self.run.timed_out {
            "killed after the timeout".into()
        } else {
            match self.run.code {
                Some(c) => format!("exit {c}"),
                None => "killed by a signal".into(),
            }
        }
    }
}

/// Whether `stderr` holds one of the `|`-separated alternatives of `expected`.
fn names(stderr: &str, expected: &str) -> bool {
    expected.split('|').any(|alt| stderr.contains(alt))
}

/// Runs the command `argv` in a fresh tree holding `input` (with the earlier report in
/// `out`), after `damage`; judges safety and returns the outcome with its exit-code and
/// naming problems left for the caller (`expect`).
fn run_damaged(
    fx: &Fixtures,
    input: Input,
    damage: &dyn Fn(&Fixtures, &Path),
    argv: &[String],
    log: &Path,
) -> Outcome {
    let tree = TempDir::new("damaged");
    let root = tree.path();
    copy_tree(&fx.src(input), &root.join(input.place()));
    copy_tree(&fx.baseline(input).join("out"), &root.join("out"));
    damage(fx, root);
    let (inputs, earlier) = (snapshot(root, &["out"]), snapshot(&root.join("out"), &[]));
    let run = execute(root, argv, log);
    let mut o = Outcome {
        run,
        argv: argv.to_vec(),
        unsafe_: Vec::new(),
        wrong: Vec::new(),
        unnamed: Vec::new(),
    };
    if o.run.timed_out {
        o.unsafe_
            .push(format!("hang: no answer within {TIMEOUT:?} (killed)"));
    } else if o.run.code.is_none() {
        o.unsafe_.push("killed by a signal (abort?)".into());
    }
    if o.run.code == Some(101) || o.run.stderr.contains("panicked") {
        o.unsafe_.push("panicked".into());
    }
    let (lost, added) = diff(&inputs, &snapshot(root, &["out"]));
    if !lost.is_empty() {
        o.unsafe_
            .push(format!("data loss in the input: {}", lost.join(", ")));
    }
    if !added.is_empty() {
        o.wrong.push(format!(
            "wrote into an input directory: {}",
            added.join(", ")
        ));
    }
    if !matches!(o.run.code, Some(0 | 1)) {
        let (lost, _) = diff(&earlier, &snapshot(&root.join("out"), &[]));
        if !lost.is_empty() {
            o.unsafe_.push(format!(
                "the earlier report in --out lost: {}",
                lost.join(", ")
            ));
        }
    }
    o
}

/// Runs one case and judges it.
fn run_case(fx: &Fixtures, case: &Case, logs: &Path) -> Outcome {
    let argv = case.command();
    let mut o = run_damaged(
        fx,
        case.input,
        &case.damage,
        &argv,
        &logs.join(format!("{}.err", case.name)),
    );
    if o.run.timed_out || o.run.code.is_none() {
        return o;
    }
    match &case.expect {
        Expect::Refused { expect, forbid } => {
            if o.run.code != Some(2) {
                o.wrong.push(format!("exit {:?}, expected 2", o.run.code));
            }
            for e in expect {
                if !names(&o.run.stderr, e) {
                    o.unnamed.push(format!("lacks {e:?}"));
                }
            }
            for f in forbid {
                if o.run.stderr.contains(f.as_str()) {
                    o.unnamed.push(format!("names {f:?}"));
                }
            }
        }
        Expect::Unchanged => {
            let want = fx.code(case.input);
            if o.run.code != Some(want) {
                o.wrong.push(format!(
                    "exit {:?}, expected {want} (the undamaged input's)",
                    o.run.code
                ));
            }
        }
    }
    o
}

/// Runs `jobs` on two worker threads; returns the results in job order.
fn on_two_threads<T: Sync, R: Send>(jobs: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(job) = jobs.get(i) else { break };
                    let r = f(job);
                    results.lock().unwrap().push((i, r));
                }
            });
        }
    });
    let mut r = results.into_inner().unwrap();
    r.sort_by_key(|(i, _)| *i);
    r.into_iter().map(|(_, r)| r).collect()
}

// ---------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------

/// What: the corpus has at least 150 cases with distinct names, covering every kind of
/// damage.
#[test]
fn corpus_is_large_and_names_are_distinct() {
    let c = corpus();
    assert!(c.len() >= 150, "{} cases", c.len());
    let mut names: Vec<&str> = c.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    let n = names.len();
    names.dedup();
    assert_eq!(names.len(), n, "case names must be distinct");
    for kind in [
        Kind::Sidecar,
        Kind::Npy,
        Kind::Csv,
        Kind::Manifest,
        Kind::PlanFrom,
        Kind::OutDir,
    ] {
        assert!(
            c.iter().filter(|c| c.kind == kind).count() >= 10,
            "{kind:?}"
        );
    }
}

/// What: every damaged input is safe (no panic, signal, hang or data loss) and gives its
/// expected outcome (see the module docs).
/// Reference: the guide, docs/src/reference/exit-codes-and-limits.md; issue #25.
/// Tolerance: 100 % safe, 100 % with the expected exit code, ≥ 95 % of the refusals
/// naming file, key and value.
#[test]
fn every_damaged_input_is_safe_and_refused_or_unchanged() {
    let fx = Fixtures::get();
    let cases = corpus();
    let logs = TempDir::new("damaged-logs");
    let start = Instant::now();
    let outcomes = on_two_threads(&cases, |case| run_case(&fx, case, logs.path()));
    let elapsed = start.elapsed().as_secs_f64();

    let n = cases.len();
    let safe = outcomes.iter().filter(|o| o.unsafe_.is_empty()).count();
    let exit_ok = outcomes
        .iter()
        .filter(|o| o.wrong.is_empty() && o.unsafe_.is_empty())
        .count();
    let refusals: Vec<(&Case, &Outcome)> = cases
        .iter()
        .zip(&outcomes)
        .filter(|(c, _)| matches!(c.expect, Expect::Refused { .. }))
        .collect();
    let named = refusals
        .iter()
        .filter(|(_, o)| o.run.code == Some(2) && o.unnamed.is_empty() && o.unsafe_.is_empty())
        .count();
    let mut per_kind: BTreeMap<Kind, (usize, usize)> = BTreeMap::new();
    for (c, o) in cases.iter().zip(&outcomes) {
        let e = per_kind.entry(c.kind).or_default();
        e.0 += 1;
        if o.passed() {
            e.1 += 1;
        }
    }
    let passed = outcomes.iter().filter(|o| o.passed()).count();
    println!("damaged-data corpus: {n} cases in {elapsed:.1} s");
    for (k, (total, ok)) in &per_kind {
        println!("  {k:?}: {ok} of {total} pass");
    }
    let pct = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
    println!(
        "  safe (no panic, signal, hang, data loss): {safe} of {n} ({:.1} %)",
        pct(safe, n)
    );
    println!(
        "  expected exit code: {exit_ok} of {n} ({:.1} %)",
        pct(exit_ok, n)
    );
    println!(
        "  refused naming file, key and value: {named} of {} ({:.1} %, {:.0} % required)",
        refusals.len(),
        pct(named, refusals.len()),
        100.0 * NAMED_FRACTION
    );
    println!(
        "  every check passed: {passed} of {n} ({:.1} %)",
        pct(passed, n)
    );
    let slowest = cases
        .iter()
        .zip(&outcomes)
        .max_by(|a, b| a.1.run.seconds.total_cmp(&b.1.run.seconds))
        .map(|(c, o)| format!("{} {:.2} s", c.name, o.run.seconds))
        .unwrap_or_default();
    println!("  slowest: {slowest}");

    let mut table = Vec::new();
    for (c, o) in cases.iter().zip(&outcomes) {
        if o.passed() {
            continue;
        }
        let expected = match &c.expect {
            Expect::Refused { expect, .. } => format!("2 naming {}", expect.join(" + ")),
            Expect::Unchanged => format!("{} (unchanged)", fx.code(c.input)),
        };
        let problems: Vec<String> = o
            .unsafe_
            .iter()
            .map(|p| format!("UNSAFE: {p}"))
            .chain(o.wrong.iter().cloned())
            .chain(o.unnamed.iter().cloned())
            .collect();
        table.push(format!(
            "| {} | {expected} | {} | {} | {} |\n    `langevin-fem {}`",
            c.name,
            o.got(),
            o.first_line().replace('|', "\\|"),
            problems.join("; ").replace('|', "\\|"),
            o.argv.join(" ")
        ));
    }
    if !table.is_empty() {
        println!(
            "\n{} failing cases:\n| case | expected | got | first line of stderr | problems |\n|---|---|---|---|---|\n{}",
            table.len(),
            table.join("\n")
        );
    }
    assert!(
        safe == n && exit_ok == n && named as f64 >= NAMED_FRACTION * refusals.len() as f64,
        "{} of {n} cases unsafe, {} with another exit code, {named} of {} refusals named (the table above)",
        n - safe,
        n - exit_ok,
        refusals.len()
    );
}

/// One byte mutation; positions are fractions of the region they fall in (`head`: the
/// `.npy` header or the CSV header line; otherwise the whole file).
#[derive(Debug, Clone)]
enum Mutation {
    Flip { at: f64, head: bool, mask: u8 },
    Delete { at: f64, head: bool, len: usize },
    Insert { at: f64, head: bool, bytes: Vec<u8> },
    Truncate { at: f64 },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (0.0..1.0f64, any::<bool>(), 1..=255u8).prop_map(|(at, head, mask)| Mutation::Flip {
            at,
            head,
            mask
        }),
        (0.0..1.0f64, any::<bool>(), 1..16usize).prop_map(|(at, head, len)| Mutation::Delete {
            at,
            head,
            len
        }),
        (
            0.0..1.0f64,
            any::<bool>(),
            proptest::collection::vec(any::<u8>(), 1..8)
        )
            .prop_map(|(at, head, bytes)| Mutation::Insert { at, head, bytes }),
        (0.0..1.0f64).prop_map(|at| Mutation::Truncate { at }),
    ]
}

/// The file kinds the property test mutates.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Npy,
    Csv,
    Sidecar,
    Manifest,
}

impl Target {
    fn input(self) -> Input {
        match self {
            Target::Npy | Target::Sidecar => Input::LinNpy,
            Target::Csv => Input::LinCsv,
            Target::Manifest => Input::RunSet,
        }
    }

    fn file(self) -> &'static str {
        match self {
            Target::Npy => LIN_NPY,
            Target::Csv => LIN_CSV,
            Target::Sidecar => SIDECAR,
            Target::Manifest => M2,
        }
    }

    /// The length of the structural head of `bytes` (the `.npy` header, the CSV header
    /// line with its newline; none for JSON).
    fn head(self, bytes: &[u8]) -> usize {
        match self {
            Target::Npy => npy_body(bytes).min(bytes.len()),
            Target::Csv => bytes
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |p| p + 1),
            Target::Sidecar | Target::Manifest => 0,
        }
    }
}

/// `bytes` with `m` applied, and whether the mutant must exit 2 or with the undamaged
/// verdict (`strict`; otherwise 0, 1 or 2 — see the module docs).
fn mutate(target: Target, bytes: &[u8], m: &Mutation) -> (Vec<u8>, bool) {
    let head = target.head(bytes);
    let at = |f: f64, in_head: bool| -> usize {
        let span = if in_head && head > 0 {
            head
        } else {
            bytes.len()
        };
        ((f * span as f64) as usize).min(bytes.len().saturating_sub(1))
    };
    let mut b = bytes.to_vec();
    let strict = match m {
        Mutation::Flip {
            at: f,
            head: h,
            mask,
        } => {
            let p = at(*f, *h);
            b[p] ^= mask;
            match target {
                Target::Npy | Target::Csv => p < head,
                Target::Sidecar => false,
                Target::Manifest => true,
            }
        }
        Mutation::Delete {
            at: f,
            head: h,
            len,
        } => {
            let p = at(*f, *h);
            let end = (p + len).min(b.len());
            b.drain(p..end);
            match target {
                Target::Npy | Target::Manifest => true,
                Target::Csv => end <= head,
                Target::Sidecar => false,
            }
        }
        Mutation::Insert {
            at: f,
            head: h,
            bytes: ins,
        } => {
            let p = at(*f, *h);
            b.splice(p..p, ins.iter().copied());
            match target {
                Target::Npy | Target::Manifest => true,
                Target::Csv => p < head,
                Target::Sidecar => false,
            }
        }
        Mutation::Truncate { at: f } => {
            let p = at(*f, false);
            b.truncate(p);
            match target {
                Target::Npy | Target::Manifest => true,
                Target::Csv => p < head,
                Target::Sidecar => false,
            }
        }
    };
    (b, strict)
}

/// What: random byte mutations of a valid `.npy`, CSV, `data.json` and run shard
/// manifest are safe and give an allowed exit code (see the module docs).
/// Reference: the guide, docs/src/reference/exit-codes-and-limits.md; issue #25.
/// Set-up: 64 mutants per file kind (proptest, ChaCha, `SEED_DAMAGED_DATA`), each one
/// edit of one file of a fresh copy of the valid input; `check` (data) or `merge` (shards).
/// Tolerance: none: every mutant must pass.
#[test]
fn random_byte_mutations_are_safe() {
    let fx = Fixtures::get();
    let mut runner = TestRunner::new(Config {
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(SEED_DAMAGED_DATA),
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = mutation();
    let mut jobs: Vec<(Target, usize, Mutation)> = Vec::new();
    for target in [Target::Npy, Target::Csv, Target::Sidecar, Target::Manifest] {
        for k in 0..MUTANTS {
            let m = strategy.new_tree(&mut runner).expect("a mutant").current();
            jobs.push((target, k, m));
        }
    }
    let logs = TempDir::new("damaged-mutants");
    let start = Instant::now();
    let results = on_two_threads(&jobs, |(target, k, m)| {
        let strict = Mutex::new(true);
        let file = target.file();
        let damage = |_: &Fixtures, r: &Path| {
            if matches!(target, Target::Sidecar | Target::Manifest) {
                // Neither `check` nor the merge reads this provenance (a case of the corpus
                // each): fixed, so that the mutants' bytes do not move with timestamps.
                edit_json(r, file, |v| v["provenance"] = Value::from(NORMALIZED));
            }
            let bytes = read(r, file);
            let (mutant, s) = mutate(*target, &bytes, m);
            write(r, file, mutant);
            *strict.lock().unwrap() = s;
        };
        let input = target.input();
        let log = logs.join(&format!("{target:?}-{k}.err"));
        let mut o = run_damaged(&fx, input, &damage, &input.argv(), &log);
        let strict = *strict.lock().unwrap();
        if !o.run.timed_out && o.run.code.is_some() {
            let base = fx.code(input);
            let allowed = if strict {
                o.run.code == Some(2) || o.run.code == Some(base)
            } else {
                matches!(o.run.code, Some(0..=2))
            };
            if !allowed {
                o.wrong.push(format!(
                    "exit {:?}, allowed {}",
                    o.run.code,
                    if strict {
                        format!("2 or {base} (structure)")
                    } else {
                        "0, 1 or 2 (numbers may have changed)".to_string()
                    }
                ));
            }
        }
        (strict, o)
    });
    let elapsed = start.elapsed().as_secs_f64();
    let mut failures = Vec::new();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for ((target, k, m), (strict, o)) in jobs.iter().zip(&results) {
        *counts.entry(format!("{target:?} {}", o.got())).or_default() += 1;
        if !(o.unsafe_.is_empty() && o.wrong.is_empty()) {
            let problems: Vec<String> = o
                .unsafe_
                .iter()
                .map(|p| format!("UNSAFE: {p}"))
                .chain(o.wrong.iter().cloned())
                .collect();
            failures.push(format!(
                "| {target:?} #{k} | {m:?} | {} | {} | {} |",
                if *strict { "strict" } else { "loose" },
                o.got(),
                format!("{}; {}", problems.join("; "), o.first_line()).replace('|', "\\|")
            ));
        }
    }
    println!(
        "damaged-data mutants: {} in {elapsed:.1} s; outcomes: {counts:?}",
        jobs.len()
    );
    if !failures.is_empty() {
        println!(
            "\n{} failing mutants:\n| mutant | mutation | rule | got | problems; first line of stderr |\n|---|---|---|---|---|\n{}",
            failures.len(),
            failures.join("\n")
        );
    }
    assert!(
        failures.is_empty(),
        "{} of {} mutants failed (the table above)",
        failures.len(),
        jobs.len()
    );
}

/// What: the mutator does what it says (an oracle for the property test: a broken
/// operator would leave every mutant equal to its base).
#[test]
fn mutations_edit_the_bytes() {
    let csv = b"t,w\n0,1\n";
    let (b, strict) = mutate(
        Target::Csv,
        csv,
        &Mutation::Flip {
            at: 0.0,
            head: true,
            mask: 1,
        },
    );
    assert_eq!((b.as_slice(), strict), (&b"u,w\n0,1\n"[..], true));
    let (b, strict) = mutate(
        Target::Csv,
        csv,
        &Mutation::Delete {
            at: 0.9,
            head: false,
            len: 1,
        },
    );
    assert_eq!((b.as_slice(), strict), (&b"t,w\n0,1"[..], false));
    let (b, strict) = mutate(
        Target::Csv,
        csv,
        &Mutation::Insert {
            at: 0.5,
            head: true,
            bytes: vec![b'x'],
        },
    );
    assert_eq!((b.as_slice(), strict), (&b"t,xw\n0,1\n"[..], true));
    let (b, strict) = mutate(Target::Sidecar, b"{}", &Mutation::Truncate { at: 0.5 });
    assert_eq!((b.as_slice(), strict), (&b"{"[..], false));
    let (b, strict) = mutate(Target::Manifest, b"{}", &Mutation::Truncate { at: 0.0 });
    assert_eq!((b.as_slice(), strict), (&b""[..], true));
}
