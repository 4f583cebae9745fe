//! Bakes the git commit of the build into the binary (issue #13, provenance): every
//! report names the exact source that produced it.
//!
//! Sets, for `env!` in the crate:
//!
//! - `LANGEVIN_FEM_COMMIT`: `git rev-parse HEAD`, or `unknown` without git or `.git`
//!   (e.g. a source tarball);
//! - `LANGEVIN_FEM_DIRTY`: `true` if a tracked file differs from the commit (`git status
//!   --porcelain --untracked-files=no`), `false` if none does, `unknown` without git;
//! - `LANGEVIN_FEM_VERSION_LINE`: what `--version` prints after the name, e.g.
//!   `0.1.0 (commit 5bcc9b5…, dirty)`.
//!
//! The script reruns when HEAD moves (`HEAD`, the branch ref it points to, `packed-refs`),
//! when the index changes, and when the sources change (for the dirty flag), so that a
//! new commit is picked up without rebuilding the dependencies. Git is run with
//! `--no-optional-locks`, so the script never rewrites the index it watches.

use std::path::PathBuf;
use std::process::Command;

/// The trimmed standard output of `git args`, if git ran and succeeded.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("--no-optional-locks")
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let manifest_dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    for watched in ["build.rs", "Cargo.toml", "Cargo.lock", "src"] {
        println!(
            "cargo:rerun-if-changed={}",
            manifest_dir.join(watched).display()
        );
    }
    // Only the repository of this package counts: a tarball unpacked inside some other
    // git repository is not that repository's commit.
    let top = git(&["rev-parse", "--show-toplevel"]).map(PathBuf::from);
    let ours =
        top.as_ref()
            .is_some_and(|t| match (t.canonicalize(), manifest_dir.canonicalize()) {
                (Ok(a), Ok(b)) => a == b,
                _ => false,
            });
    let commit = ours
        .then(|| git(&["rev-parse", "HEAD"]))
        .flatten()
        .filter(|c| !c.is_empty() && c.chars().all(|ch| ch.is_ascii_hexdigit()));
    let (commit, dirty) = match commit {
        Some(commit) => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .map_or("unknown", |s| if s.is_empty() { "false" } else { "true" });
            watch_git();
            (commit, dirty)
        }
        None => ("unknown".to_string(), "unknown"),
    };
    let short: String = commit.chars().take(12).collect();
    let line = format!(
        "{} (commit {short}{})",
        env_version(),
        if dirty == "true" { ", dirty" } else { "" }
    );
    println!("cargo:rustc-env=LANGEVIN_FEM_COMMIT={commit}");
    println!("cargo:rustc-env=LANGEVIN_FEM_DIRTY={dirty}");
    println!("cargo:rustc-env=LANGEVIN_FEM_VERSION_LINE={line}");
}

/// The package version.
fn env_version() -> String {
    std::env::var("CARGO_PKG_VERSION").unwrap_or_default()
}

/// `rerun-if-changed` on the files that move with a commit or a staged change: `HEAD` and
/// `index` in the git directory (per worktree), the branch ref HEAD points to and
/// `packed-refs` in the common directory.
fn watch_git() {
    let abs = |p: String| {
        let p = PathBuf::from(p);
        if p.is_absolute() {
            p
        } else {
            std::env::current_dir().unwrap_or_default().join(p)
        }
    };
    let Some(git_dir) = git(&["rev-parse", "--git-dir"]).map(abs) else {
        return;
    };
    let common = git(&["rev-parse", "--git-common-dir"]).map_or_else(|| git_dir.clone(), abs);
    let mut watched = vec![
        git_dir.join("HEAD"),
        git_dir.join("index"),
        common.join("packed-refs"),
    ];
    if let Some(head_ref) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watched.push(common.join(head_ref));
    }
    // A missing file would make cargo rerun the script on every build.
    for path in watched.iter().filter(|p| p.exists()) {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}
