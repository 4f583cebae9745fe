//! Running a page's `console` blocks: each page in a fresh temporary working directory
//! (shared by its blocks, in order) with links to the repository's `examples/`,
//! `verification/` and `tests/scenes/` (as `examples`, `verification`, `scenes`), the
//! binary under test first on `PATH` (after the `python3` shim of NumPy pages), each
//! command through `sh -c` with stdin closed, `NO_COLOR=1`, `RAYON_NUM_THREADS` unset
//! and a timeout; then its output and exit code against the page's.

use crate::common::TempDir;
use crate::matcher::{Mismatch, compare, normalize};
use crate::page::{Cmd, Page};
use std::ffi::{OsStr, OsString};
use std::fs::File;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Which blocks a run executes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    /// Every `console` block but those tagged `numpy` (counted as skipped); the page's
    /// problems (rules (a), (b), syntax) are failures.
    Default,
    /// Only pages with a `numpy` block, all their `console` blocks in order (a NumPy
    /// block may read what an earlier block wrote); the page's problems are left to
    /// [`Mode::Default`].
    Numpy,
}

/// Where and how pages run.
#[derive(Debug, Clone)]
pub struct Sandbox {
    /// The `langevin-fem` binary under test (its directory goes first on `PATH`).
    pub bin: PathBuf,
    /// The repository, whose `examples/`, `verification/` and `tests/scenes/` are linked.
    pub repo: PathBuf,
    /// Longest run of one command before it is killed (with its process group).
    pub timeout: Duration,
    /// A Python with NumPy, run by the pages as `python3` (and `python`).
    pub python: Option<PathBuf>,
}

/// The result of running one page.
#[derive(Debug, Clone, Default)]
pub struct PageRun {
    /// The page's name.
    pub name: String,
    /// Each failure, ready to print: page and line, command, what differs.
    pub failures: Vec<String>,
    /// Commands run.
    pub commands: usize,
    /// `numpy` blocks skipped ([`Mode::Default`]).
    pub skipped_numpy: usize,
    /// `numpy` blocks run ([`Mode::Numpy`]).
    pub numpy_run: usize,
    /// Wall time of the page.
    pub elapsed: Duration,
}

impl PageRun {
    /// One line for the log: the page, what ran, how long it took.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "docs: {}: {} command(s) in {:.1} s",
            self.name,
            self.commands,
            self.elapsed.as_secs_f64()
        );
        if self.skipped_numpy > 0 {
            s.push_str(&format!(
                ", {} numpy block(s) skipped (run by `make docs-check`)",
                self.skipped_numpy
            ));
        }
        if self.numpy_run > 0 {
            s.push_str(&format!(", {} numpy block(s) run", self.numpy_run));
        }
        if !self.failures.is_empty() {
            s.push_str(&format!(", {} FAILURE(S)", self.failures.len()));
        }
        s
    }
}

/// What one command did.
struct Outcome {
    /// Exit code, `None` if killed by a signal or by the timeout.
    code: Option<i32>,
    /// How it ended, when not by itself with a code.
    killed: Option<String>,
    /// Whether it was killed by the timeout.
    timed_out: bool,
    /// Stdout then stderr.
    output: String,
}

/// A shell-quoted path.
fn quoted(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', r"'\''"))
}

/// Creates the page's working directory `root/work` with its links, and the `python3`
/// shim in `root/shim` if `sandbox.python` is set; returns the working directory and the
/// `PATH` of its commands.
fn prepare(root: &Path, sandbox: &Sandbox) -> std::io::Result<(PathBuf, OsString)> {
    let work = root.join("work");
    std::fs::create_dir_all(&work)?;
    for (link, target) in [
        ("examples", "examples"),
        ("verification", "verification"),
        ("scenes", "tests/scenes"),
    ] {
        std::os::unix::fs::symlink(sandbox.repo.join(target), work.join(link))?;
    }
    let mut dirs = Vec::new();
    if let Some(python) = &sandbox.python {
        use std::os::unix::fs::PermissionsExt;
        let shim = root.join("shim");
        std::fs::create_dir_all(&shim)?;
        for name in ["python3", "python"] {
            let p = shim.join(name);
            std::fs::write(&p, format!("#!/bin/sh\nexec {} \"$@\"\n", quoted(python)))?;
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755))?;
        }
        dirs.push(shim);
    }
    dirs.push(
        sandbox
            .bin
            .parent()
            .expect("binary in a directory")
            .to_path_buf(),
    );
    dirs.extend(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    ));
    let path = std::env::join_paths(dirs).expect("PATH entries without ':'");
    Ok((work, path))
}

/// Runs `text` through `sh -c` in `work`, capturing into files under `root`, killing its
/// process group after `timeout`.
fn execute(text: &str, work: &Path, root: &Path, path: &OsStr, timeout: Duration) -> Outcome {
    let (out_path, err_path) = (root.join("stdout"), root.join("stderr"));
    let failed = |e: std::io::Error| Outcome {
        code: None,
        killed: Some(format!("could not run it: {e}")),
        timed_out: false,
        output: String::new(),
    };
    let (out, err) = match (File::create(&out_path), File::create(&err_path)) {
        (Ok(o), Ok(e)) => (o, e),
        (Err(e), _) | (_, Err(e)) => return failed(e),
    };
    let spawned = Command::new("sh")
        .arg("-c")
        .arg(text)
        .current_dir(work)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .env_remove("RAYON_NUM_THREADS")
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .process_group(0)
        .spawn();
    let mut child = match spawned {
        Ok(c) => c,
        Err(e) => return failed(e),
    };
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Some(s),
            Ok(None) if start.elapsed() > timeout => break None,
            Ok(None) => std::thread::sleep(Duration::from_millis(10)),
            Err(e) => return failed(e),
        }
    };
    if status.is_none() {
        // The whole group: `sh` and whatever it started.
        let group = format!("-{}", child.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = child.wait();
    }
    let read =
        |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
    let (stdout, stderr) = (read(&out_path), read(&err_path));
    let mut output = stdout;
    if !output.is_empty() && !output.ends_with('\n') {
        output.push('\n');
    }
    output.push_str(&stderr);
    let killed = match status {
        None => Some(format!(
            "timed out: killed after {} s",
            timeout.as_secs_f64()
        )),
        Some(s) => s.signal().map(|sig| format!("killed by signal {sig}")),
    };
    Outcome {
        code: status.and_then(|s| s.code()),
        killed,
        timed_out: status.is_none(),
        output,
    }
}

/// Lines `lines` with their numbers, each indented, at most about 60 around `center`.
fn excerpt(lines: &[String], center: usize) -> String {
    const BEFORE: usize = 20;
    const AFTER: usize = 40;
    let from = center.saturating_sub(BEFORE);
    let to = (center + AFTER).min(lines.len());
    let mut s = String::new();
    if from > 0 {
        s.push_str(&format!("      … {from} line(s) before\n"));
    }
    for (k, l) in lines.iter().enumerate().take(to).skip(from) {
        s.push_str(&format!("  {:>4} | {l}\n", k + 1));
    }
    if to < lines.len() {
        s.push_str(&format!("      … {} more line(s)\n", lines.len() - to));
    }
    if lines.is_empty() {
        s.push_str("       (nothing)\n");
    }
    s
}

/// The failure of `cmd` on page `page`, or `None` if it did what the page says.
fn judge(page: &str, cmd: &Cmd, outcome: &Outcome) -> Option<String> {
    let actual = normalize(&outcome.output);
    let mismatch: Option<Mismatch> = compare(&cmd.expected, &actual).err();
    let code_ok = outcome.killed.is_none() && outcome.code == Some(cmd.code);
    if code_ok && mismatch.is_none() {
        return None;
    }
    let got = match (&outcome.killed, outcome.code) {
        (Some(k), _) => k.clone(),
        (None, Some(c)) => c.to_string(),
        (None, None) => "none".to_string(),
    };
    let mut s = format!(
        "{page}:{}: $ {}\n",
        cmd.line,
        cmd.text.replace('\n', "\n  ")
    );
    s.push_str(&format!(
        "  exit code: expected {}, got {got}{}\n",
        cmd.code,
        if code_ok { "" } else { "  <- WRONG" }
    ));
    let (e_at, a_at) = match &mismatch {
        Some(m) => {
            s.push_str(&format!("  output differs: {m}\n"));
            (m.expected_line, m.actual_line)
        }
        None => {
            s.push_str("  output: as expected\n");
            (0, 0)
        }
    };
    s.push_str("  --- expected output ---\n");
    s.push_str(&excerpt(&cmd.expected, e_at));
    s.push_str("  --- actual output (stdout, then stderr) ---\n");
    s.push_str(&excerpt(&actual, a_at));
    Some(s)
}

/// Runs `page` in `mode` in a fresh sandbox (see the module docs).
pub fn run_page(page: &Page, sandbox: &Sandbox, mode: Mode) -> PageRun {
    let start = Instant::now();
    let mut run = PageRun {
        name: page.name.clone(),
        ..PageRun::default()
    };
    if mode == Mode::Default {
        run.failures.extend(
            page.problems
                .iter()
                .map(|p| format!("{}:{}: {}", page.name, p.line, p.message)),
        );
    }
    let has_numpy = page.blocks.iter().any(|b| b.numpy);
    if mode == Mode::Numpy && !has_numpy {
        return run;
    }
    let root = TempDir::new("docs");
    let (work, path) = match prepare(root.path(), sandbox) {
        Ok(x) => x,
        Err(e) => {
            run.failures
                .push(format!("{}: cannot prepare its directory: {e}", page.name));
            return run;
        }
    };
    'blocks: for block in &page.blocks {
        if block.numpy && mode == Mode::Default {
            run.skipped_numpy += 1;
            continue;
        }
        run.numpy_run += usize::from(block.numpy);
        for cmd in &block.cmds {
            let outcome = execute(&cmd.text, &work, root.path(), &path, sandbox.timeout);
            run.commands += 1;
            run.failures.extend(judge(&page.name, cmd, &outcome));
            if outcome.timed_out {
                // The page's later commands would likely wait as long.
                break 'blocks;
            }
        }
    }
    run.elapsed = start.elapsed();
    run
}
