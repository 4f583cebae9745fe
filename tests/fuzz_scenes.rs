//! Fuzz test of the scene parser and validator (issue #12, Deliver 6): 1600 mutants of
//! the shipped scene files, read through the library API as `verify` reads them
//! ([`Scene::load`]: size and UTF-8 checks, TOML, validation; no simulation).
//!
//! What: no mutant panics, and each is either
//! - refused with an [`Error::Scene`] (exit 2) whose message names the file and uses no
//!   Rust type name (`usize`, `f64`, `struct ...`), or
//! - accepted as a scene whose work is bounded the way validation documents it: names are
//!   path components of at most 64 characters, at most 100 profile points, two-time
//!   points and strains, at most 100000 trajectories (and two-time trajectories) per
//!   budget, at most 1e10 steps per trajectory, a membrane's mesh of at most 256 elements
//!   a side and 4096 in all (uniform, in 3 dims, never compression, with a finite τ1 above
//!   the buckling tension), and validation accepts it again.
//!
//! Mutations (one to four per mutant, on the bytes of a base file): delete, duplicate or
//! swap lines; replace a number by an extreme one (0, negative, ±1e308, 1e-300, NaN, ±inf,
//! integers at and beyond the 64-bit limits); replace a value by one of another type;
//! truncate; insert garbage bytes (TOML punctuation, unicode, control characters and
//! bytes that are not UTF-8).
//!
//! Bases: `verification/*.toml`, `verification/extreme/*.toml` and
//! `tests/scenes/good/*.toml`.
//! Determinism: a fixed seed (`SEED_SCENE_FUZZ` in `tests/common/seeds.rs`) and the ChaCha generator, no failure
//! persistence, so CI runs the same 1600 mutants every time.
//! Tolerance: none (every mutant must satisfy the rules); the run must take less than
//! [`TIME_LIMIT`] (about 2 s on the 2-core CI machine).

mod common;

use common::seeds::SEED_SCENE_FUZZ;
use common::{TempDir, fixture, toml_files};
use langevin_fem::error::Error;
use langevin_fem::scene::{Budget, ModelKind, Scene};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed, TestCaseError, TestRunner};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Mutants per run.
const CASES: u32 = 1600;
/// Longest time the 1600 mutants may take.
const TIME_LIMIT: Duration = Duration::from_secs(30);

/// Numbers a mutant may put in place of a number.
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "0.0",
    "-1",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-300",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "4294967296",
    "100001",
    "1e10",
    "3.5",
    "1",
    "2",
];

/// Values of other types a mutant may put in place of a value.
const OTHER_TYPES: &[&str] = &[
    "\"x\"",
    "\"\"",
    "true",
    "[]",
    "{}",
    "[[1, 2]]",
    "{ a = 1 }",
    "1979-05-27",
    "'../..'",
];

/// Garbage a mutant may insert.
const GARBAGE: &[&[u8]] = &[
    b"[",
    b"]",
    b"=",
    b"\"",
    b"{",
    b"}",
    b"\n[mesh]\n",
    b"\n[[runs]]\n",
    b"\nname = \"../x\"\n",
    b"#",
    b",",
    b"\\",
    b"\x00",
    b"\x7f",
    b"\xff\xfe",
    b"\xc3",
    "\u{e9}\u{2603}".as_bytes(),
    b"\r\n",
    b"\t",
    b"'''",
];

/// One edit of a scene file's bytes; the `f64`s in [0, 1) pick a position, whatever the
/// file's length.
#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(f64),
    DuplicateLine(f64),
    SwapLines(f64, f64),
    ReplaceNumber(f64, usize),
    ReplaceValue(f64, usize),
    Truncate(f64),
    InsertGarbage(f64, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let f = || 0.0..1.0f64;
    prop_oneof![
        f().prop_map(Mutation::DeleteLine),
        f().prop_map(Mutation::DuplicateLine),
        (f(), f()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (f(), 0..EXTREME_NUMBERS.len()).prop_map(|(a, k)| Mutation::ReplaceNumber(a, k)),
        (f(), 0..OTHER_TYPES.len()).prop_map(|(a, k)| Mutation::ReplaceValue(a, k)),
        f().prop_map(Mutation::Truncate),
        (f(), 0..GARBAGE.len()).prop_map(|(a, k)| Mutation::InsertGarbage(a, k)),
    ]
}

/// The index in `0..n` picked by `f` in [0, 1) (0 if `n` is 0).
fn pick(f: f64, n: usize) -> usize {
    ((f * n as f64) as usize).min(n.saturating_sub(1))
}

/// Byte ranges of the numbers (a digit run, with sign, point and exponent) in `text`.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() {
            let start = if i > 0 && text[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            let mut j = i;
            while j < text.len()
                && (text[j].is_ascii_digit() || matches!(text[j], b'.' | b'e' | b'E' | b'_'))
            {
                j += 1;
            }
            out.push((start, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the values of `key = value` lines (up to the end of the line).
fn values(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for line in text.split(|&b| b == b'\n') {
        if let Some(eq) = line.iter().position(|&b| b == b'=')
            && !line.starts_with(b"#")
        {
            out.push((start + eq + 1, start + line.len()));
        }
        start += line.len() + 1;
    }
    out
}

/// `text` with mutation `m` applied.
fn apply(text: &[u8], m: &Mutation) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = text.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let join = |lines: &[Vec<u8>]| lines.join(&b'\n');
    let splice = |(a, b): (usize, usize), with: &[u8]| {
        let mut t = text[..a].to_vec();
        t.extend_from_slice(with);
        t.extend_from_slice(&text[b..]);
        t
    };
    match *m {
        Mutation::DeleteLine(f) => {
            lines.remove(pick(f, lines.len()));
            join(&lines)
        }
        Mutation::DuplicateLine(f) => {
            let i = pick(f, lines.len());
            lines.insert(i, lines[i].clone());
            join(&lines)
        }
        Mutation::SwapLines(a, b) => {
            let (i, j) = (pick(a, lines.len()), pick(b, lines.len()));
            lines.swap(i, j);
            join(&lines)
        }
        Mutation::ReplaceNumber(f, k) => {
            let n = numbers(text);
            if n.is_empty() {
                return text.to_vec();
            }
            splice(n[pick(f, n.len())], EXTREME_NUMBERS[k].as_bytes())
        }
        Mutation::ReplaceValue(f, k) => {
            let v = values(text);
            if v.is_empty() {
                return text.to_vec();
            }
            let with = format!(" {}", OTHER_TYPES[k]);
            splice(v[pick(f, v.len())], with.as_bytes())
        }
        Mutation::Truncate(f) => text[..pick(f, text.len() + 1)].to_vec(),
        Mutation::InsertGarbage(f, k) => {
            let at = pick(f, text.len() + 1);
            splice((at, at), GARBAGE[k])
        }
    }
}

/// The rules an accepted scene must satisfy (see the module docs); `Err` says which one
/// it breaks.
fn check_bounded(scene: &Scene) -> Result<(), String> {
    let name_ok = |n: &str| {
        !n.is_empty()
            && n.chars().count() <= 64
            && n.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    };
    if !name_ok(&scene.name) {
        return Err(format!("scene name {:?}", scene.name));
    }
    if let Some(m) = &scene.membrane {
        let (nx, ny) = (scene.mesh.elements, scene.mesh.elements_along_y());
        if nx > 256 || ny > 256 || nx * ny > 4096 || scene.mesh.grading != 1.0 {
            return Err(format!(
                "membrane mesh {nx} x {ny}, grading {}",
                scene.mesh.grading
            ));
        }
        let area = scene.compression.as_ref().and_then(|c| c.area_modulus);
        let area_ok = match scene.model {
            // the membrane under imposed projected area (issue #28)
            ModelKind::Compression => {
                area.is_some_and(|k| (1e-30..=1e30).contains(&k)) && m.tension == 0.0
            }
            ModelKind::Fem | ModelKind::Spectral => area.is_none(),
        };
        if scene.dims != 3 || !area_ok {
            return Err(format!(
                "membrane in {} dims, model {:?}, area modulus {area:?}, tension {}",
                scene.dims, scene.model, m.tension
            ));
        }
        let tau1 = scene.tau1();
        if !(tau1.is_finite() && tau1 > 0.0 && m.tension > m.buckling_tension()) {
            return Err(format!("membrane tau1 {tau1:e}, {m:?}"));
        }
    } else if scene.mesh.elements_y.is_some() {
        return Err("a filament with mesh.elements_y".into());
    }
    let s = &scene.sampling;
    if s.profile_points.len() > 100 || s.two_time.len() > 100 {
        return Err("more than 100 profile or two-time points".into());
    }
    let burn_in = match (&scene.compression, scene.model) {
        (Some(c), ModelKind::Compression) => {
            if c.strain_ratios.len() > 100 {
                return Err("more than 100 strains".into());
            }
            c.burn_in_tau1
        }
        (None, ModelKind::Fem | ModelKind::Spectral) => s.burn_in_tau1,
        _ => return Err("model and [compression] table disagree".into()),
    };
    for run in &scene.runs {
        if !name_ok(&run.name) {
            return Err(format!("run name {:?}", run.name));
        }
        for b in [Budget::Quick, Budget::Standard, Budget::Full] {
            let e = run.ensemble(b);
            if !(2..=100_000).contains(&e.trajectories) || e.two_time_trajectories > 100_000 {
                return Err(format!("run {} {}: {e:?}", run.name, b.name()));
            }
            let longest = match e.precision_target() {
                Some(t) => t.max_duration_tau1,
                None => e.duration_tau1,
            };
            let steps = (burn_in + longest) / run.dt_tau1;
            if !(steps.is_finite() && steps <= 1e10 && longest <= 1e6) {
                return Err(format!(
                    "run {} {}: {steps:e} steps per trajectory",
                    run.name,
                    b.name()
                ));
            }
        }
    }
    scene
        .validate()
        .map_err(|e| format!("accepted, then refused: {e}"))
}

/// What: 1600 mutants of the shipped scenes never panic, are refused naming the file
/// (exit 2) or accepted with bounded work (see the module docs), in bounded time.
#[test]
fn mutated_scenes_are_refused_or_bounded() {
    let mut bases: Vec<(String, Vec<u8>)> = Vec::new();
    for dir in ["verification", "verification/extreme", "tests/scenes/good"] {
        for p in toml_files(&fixture(dir)) {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            bases.push((name, std::fs::read(&p).expect("readable scene")));
        }
    }
    assert!(bases.len() >= 6, "expected the shipped scenes");
    // The bases are valid, so that a mutant differs from a valid scene by its mutations.
    for (name, _) in &bases {
        let base = ["verification", "verification/extreme", "tests/scenes/good"]
            .iter()
            .map(|d| fixture(d).join(name))
            .find(|p| p.is_file())
            .expect("base file");
        if let Err(e) = Scene::load(&base) {
            panic!("base scene {name} is invalid: {e}");
        }
    }
    let dir = TempDir::new("fuzz");
    let (accepted, refused) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let mut runner = TestRunner::new(Config {
        cases: CASES,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(SEED_SCENE_FUZZ),
        failure_persistence: None,
        max_shrink_iters: 200,
        ..Config::default()
    });
    let strategy = (0..bases.len(), proptest::collection::vec(mutation(), 1..=4));
    let start = Instant::now();
    let result = runner.run(&strategy, |(base, mutations)| {
        let (name, text) = &bases[base];
        let mutant = mutations.iter().fold(text.clone(), |t, m| apply(&t, m));
        let path: PathBuf = dir.join(name);
        std::fs::write(&path, &mutant).expect("write mutant");
        let loaded = catch_unwind(AssertUnwindSafe(|| Scene::load(&path)));
        let shown = String::from_utf8_lossy(&mutant).into_owned();
        match loaded {
            Err(_) => Err(TestCaseError::fail(format!("panic on:\n{shown}"))),
            Ok(Err(e)) => {
                refused.fetch_add(1, Ordering::Relaxed);
                let message = e.to_string();
                prop_assert!(
                    matches!(e, Error::Scene { .. }) && e.exit_code() == 2,
                    "not a scene error (exit {}): {message}\n{shown}",
                    e.exit_code()
                );
                prop_assert!(
                    message.contains(&path.display().to_string()),
                    "message does not name the file: {message}"
                );
                for internal in ["usize", "u64", "f64", "struct "] {
                    prop_assert!(
                        !message.contains(internal),
                        "message uses the Rust name {internal:?}: {message}"
                    );
                }
                Ok(())
            }
            Ok(Ok(scene)) => {
                accepted.fetch_add(1, Ordering::Relaxed);
                check_bounded(&scene).map_err(|why| TestCaseError::fail(format!("{why}\n{shown}")))
            }
        }
    });
    let elapsed = start.elapsed();
    println!(
        "fuzz: {} mutants accepted, {} refused, in {:.2} s",
        accepted.load(Ordering::Relaxed),
        refused.load(Ordering::Relaxed),
        elapsed.as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(
        elapsed < TIME_LIMIT,
        "{CASES} mutants took {elapsed:?} (limit {TIME_LIMIT:?})"
    );
}

/// What: the mutation operators do what they say on a tiny text (an oracle for the
/// fuzzer itself: a broken operator would leave every mutant equal to its base).
#[test]
fn mutations_edit_the_text() {
    let t = b"a = 1\nb = 2.5\n[c]\nd = -3e4";
    assert_eq!(
        apply(t, &Mutation::DeleteLine(0.0)),
        b"b = 2.5\n[c]\nd = -3e4"
    );
    assert_eq!(
        apply(t, &Mutation::DuplicateLine(0.3)),
        b"a = 1\nb = 2.5\nb = 2.5\n[c]\nd = -3e4"
    );
    assert_eq!(
        apply(t, &Mutation::SwapLines(0.0, 0.99)),
        b"d = -3e4\nb = 2.5\n[c]\na = 1"
    );
    assert_eq!(numbers(t), vec![(4, 5), (10, 13), (22, 26)]);
    assert_eq!(
        apply(t, &Mutation::ReplaceNumber(0.99, 7)),
        b"a = 1\nb = 2.5\n[c]\nd = nan"
    );
    assert_eq!(
        apply(t, &Mutation::ReplaceValue(0.0, 2)),
        b"a = true\nb = 2.5\n[c]\nd = -3e4"
    );
    assert_eq!(apply(t, &Mutation::Truncate(0.0)), b"");
    assert_eq!(
        apply(t, &Mutation::InsertGarbage(0.0, 0)),
        b"[a = 1\nb = 2.5\n[c]\nd = -3e4"
    );
}
