//! Names that become path components of the outputs (the scene name, from the file stem,
//! and run names) are checked by one validator for linear and compression scenes: a name
//! that would write outside `--out` is refused with exit 2 and a message naming the file,
//! the key and the value, and nothing is written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

const BIN: &str = env!("CARGO_BIN_EXE_langevin-fem");

/// A compression scene whose single run is named `RUN`.
const COMPRESSION: &str = r#"description = "compression scene"
seed = 3
dims = 2
model = "compression"
checks = ["force-strain"]

[mesh]
elements = 4

[compression]
strain_ratios = [0.0, 1.0]
burn_in_tau1 = 1.0
sample_every_tau1 = 0.05

[[runs]]
name = "RUN"
integrator = "crank-nicolson"
dt_tau1 = 0.01
quick = { trajectories = 2, duration_tau1 = 1.0 }
standard = { trajectories = 2, duration_tau1 = 1.0 }
full = { trajectories = 2, duration_tau1 = 1.0 }
"#;

/// A fresh, empty directory under the system temporary directory.
fn temp_dir(tag: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "langevin-fem-scene-paths-{tag}-{}-{n}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// Runs `verify` on `scene` with `--out <dir>/sub/out`.
fn verify(dir: &Path, scene: &Path) -> Output {
    Command::new(BIN)
        .arg("verify")
        .arg("--scene")
        .arg(scene)
        .arg("--out")
        .arg(dir.join("sub/out"))
        .arg("--scene-dir")
        .arg(dir)
        .output()
        .expect("binary runs")
}

/// Asserts exit 2, a message containing every needle, and nothing written.
fn assert_refused(dir: &Path, o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "message lacks {n:?}: {err}");
    }
    assert!(!dir.join("sub").exists(), "wrote under {}", dir.display());
    let _ = std::fs::remove_dir_all(dir);
}

/// What: a compression scene with a run named "../x" is refused (exit 2) like a linear
/// one, naming the file, the key and the value; nothing is written.
/// Reference: `src/scene/validate.rs` (one per-run check for every model).
#[test]
fn compression_run_name_outside_out_is_refused() {
    let dir = temp_dir("run");
    let scene = dir.join("comp.toml");
    std::fs::write(&scene, COMPRESSION.replace("RUN", "../x")).expect("write scene");
    let o = verify(&dir, &scene);
    assert_refused(
        &dir,
        &o,
        &[
            "comp.toml",
            "key `runs[0].name`",
            "must be non-empty [A-Za-z0-9_-], got \"../x\"",
        ],
    );
}

/// What: a scene file whose stem is ".." (file `...toml`) is refused (exit 2): the scene
/// name is the output subdirectory and must not leave `--out`.
/// Reference: `src/scene/validate.rs`.
#[test]
fn scene_name_outside_out_is_refused() {
    let dir = temp_dir("scene");
    let scene = dir.join("...toml");
    std::fs::write(&scene, COMPRESSION.replace("RUN", "cn")).expect("write scene");
    let o = verify(&dir, &scene);
    assert_refused(
        &dir,
        &o,
        &["...toml", "key `name (the scene file stem)`", "got \"..\""],
    );
}
