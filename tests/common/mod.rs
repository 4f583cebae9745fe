//! Fixtures shared by the integration tests: each `tests/*.rs` file declares `mod common;`
//! and uses what it needs.
//!
//! - [`seeds`]: every fixed seed of the suite, as named constants in one place;
//! - [`schema`]: the JSON Schema of `summary.json` and a validator of its subset;
//! - [`svg`]: the texts and elements of the SVG figures the program writes;
//! - [`shards`]: a command run as shards, merged, and compared with the whole run;
//! - [`filament`]: the filament parameter sets the tests are written for;
//! - paths into the crate ([`manifest_dir`], [`fixture`], [`scene`]);
//! - [`TempDir`], a unique temporary directory removed on drop, and [`write_scene`];
//! - running the binary the way a user does ([`command`], [`run`]) and describing what it
//!   did in a failure message ([`describe`], [`assert_no_panic`]);
//! - closed forms used by more than one file ([`hinged_profile_variance`]) and the number
//!   of standard errors of the statistical checks ([`Z`]).

// Every test crate includes this module and uses only part of it.
#![allow(dead_code)]

use langevin_fem::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

pub mod filament;
pub mod schema;
pub mod seeds;
pub mod shards;
pub mod svg;

/// The `langevin-fem` binary built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_langevin-fem");

/// Standard errors allowed in each Monte Carlo check of the theory and spectral suites
/// (two-sided false-alarm probability 6.3·10⁻⁵ per check; the family-wise rates are in
/// the headers of `tests/compression_theory.rs` and `tests/spectral_reference.rs`).
pub const Z: f64 = 4.0;

// ---------------------------------------------------------------------------------------
// Paths
// ---------------------------------------------------------------------------------------

/// The crate root.
pub fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A path relative to the crate root.
pub fn fixture(rel: &str) -> PathBuf {
    manifest_dir().join(rel)
}

/// The scene file at `rel` (relative to the crate root), loaded and validated.
pub fn scene(rel: &str) -> Scene {
    Scene::load(&fixture(rel)).expect("scene loads")
}

/// The shipped scene `verification/<name>.toml`.
pub fn verification_scene(name: &str) -> Scene {
    scene(&format!("verification/{name}.toml"))
}

/// The `*.toml` files in `dir`, sorted.
pub fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------------------------------
// Temporary directories and scene files
// ---------------------------------------------------------------------------------------

/// A unique temporary directory under `std::env::temp_dir()` (tag, process, counter and
/// time in its name), created on construction and removed on drop.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let path = std::env::temp_dir().join(format!(
            "langevin-fem-test-{tag}-{}-{n}-{nanos}",
            std::process::id()
        ));
        std::fs::create_dir_all(&path)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", path.display()));
        TempDir(path)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    pub fn join(&self, rel: &str) -> PathBuf {
        self.0.join(rel)
    }

    pub fn join_str(&self, rel: &str) -> String {
        self.join(rel).display().to_string()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Writes `text` as `<dir>/<name>.toml` and returns its path.
pub fn write_scene(dir: &TempDir, name: &str, text: &[u8]) -> PathBuf {
    let p = dir.join(&format!("{name}.toml"));
    std::fs::write(&p, text).expect("write scene");
    p
}

// ---------------------------------------------------------------------------------------
// Running the binary
// ---------------------------------------------------------------------------------------

/// The binary, run from the crate root, with the thread count left to rayon.
pub fn command() -> Command {
    let mut c = Command::new(BIN);
    c.current_dir(manifest_dir());
    c.env_remove("RAYON_NUM_THREADS");
    c
}

/// Runs the binary with `args` (see [`command`]) and returns its output.
pub fn run(args: &[&str]) -> Output {
    command()
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {BIN}: {e}"))
}

pub fn stderr_of(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout_of(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The command line, exit code, stdout and stderr, for a failure message.
pub fn describe(args: &[&str], o: &Output) -> String {
    format!(
        "`langevin-fem {}`: exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
        args.join(" "),
        o.status.code(),
        stdout_of(o),
        stderr_of(o)
    )
}

/// Asserts exit 2 (bad input) and every needle in stderr.
pub fn assert_refused(o: &Output, args: &[&str], needles: &[&str]) {
    assert_eq!(o.status.code(), Some(2), "{}", describe(args, o));
    let err = stderr_of(o);
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}: {}", describe(args, o));
    }
}

/// The process ended by itself (not by a signal) and did not panic.
pub fn assert_no_panic(args: &[&str], o: &Output) {
    assert!(
        o.status.code().is_some(),
        "killed by a signal: {}",
        describe(args, o)
    );
    assert!(
        !stderr_of(o).contains("panicked"),
        "panicked: {}",
        describe(args, o)
    );
    assert_ne!(
        o.status.code(),
        Some(101),
        "exit 101 (Rust panic): {}",
        describe(args, o)
    );
}

// ---------------------------------------------------------------------------------------
// Closed forms
// ---------------------------------------------------------------------------------------

/// Equilibrium variance ⟨w²(x)⟩ = kT x²(L−x)²/(3 EI L) of the hinged filament (the
/// equipartition sum of eq. (4) in closed form).
pub fn hinged_profile_variance(x: f64, l: f64, ei: f64, kt: f64) -> f64 {
    kt * x * x * (l - x) * (l - x) / (3.0 * ei * l)
}

/// Every regular file under `dir`, relative with `/` separators, sorted.
pub fn all_files(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).expect("read dir") {
            let p = entry.expect("entry").path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).expect("under root");
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// A JSON file, parsed (panics naming the file if it is unreadable or not JSON).
pub fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON array of strings.
pub fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|s| s.as_str().expect("string").to_string())
        .collect()
}

/// Copies the tree `from` (directories and regular files) to `to`, creating `to`.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    for f in all_files(from) {
        let target = to.join(&f);
        std::fs::create_dir_all(target.parent().expect("a parent")).expect("create dir");
        std::fs::copy(from.join(&f), &target)
            .unwrap_or_else(|e| panic!("copy {f} to {}: {e}", target.display()));
    }
}

/// Waits for `child` at most `timeout`: its exit status, or `None` if it had to be killed
/// (a hang, for the corpora of bad and damaged input: `tests/bad_inputs.rs`,
/// `tests/damaged_data.rs`).
pub fn wait_or_kill(
    child: &mut std::process::Child,
    timeout: std::time::Duration,
) -> Option<std::process::ExitStatus> {
    let start = std::time::Instant::now();
    loop {
        if let Some(s) = child.try_wait().expect("wait") {
            return Some(s);
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Whether `f` (a path relative to an output directory) is a file the next run removes:
/// a temporary file of an atomic write, or a file in the staging folder where a killed
/// run's files waited (issue #25).
pub fn transient(f: &str) -> bool {
    f.contains(".tmp.") || f.starts_with(".langevin-fem-staging.")
}
