//! The guide runs as shown (issue #26): every command line of `README.md` and
//! `docs/src/**/*.md` is executed and its output and exit code checked, so that a page
//! that drifts from the program fails `make test`; the generated page of scene keys
//! equals its generator's output; and the README's figure of the filament from tension
//! through buckling is the full-budget run's.
//!
//! What: the runner itself first (the matcher on known input, the parser, fixture pages
//! under `tests/docs-fixtures/` that must pass or must be rejected, a timeout), then every
//! page: `console` blocks run, the other blocks checked by two static rules.
//! Reference: the page syntax, in the spirit of trycmd/snapbox:
//! - A fenced block whose info string is `console` (tags after commas: `console,numpy`) is
//!   run. A line starting with `$ ` is a command (`sh -c`, so pipes and `&&` work); a
//!   line ending in `\` continues it on the next line. The lines up to the next `$ ` line
//!   or the end of the block are its expected output: stdout, then stderr.
//! - Lines compare after trimming each line's trailing whitespace and the trailing empty
//!   lines. A line `...` matches zero or more lines; `[..]` in a line matches any run of
//!   characters within the line; everything else is literal.
//! - A last expected line `? N` is the expected exit code (default 0).
//! - Each page runs in a fresh temporary directory shared by its blocks, in order, with
//!   links `examples`, `verification` and `scenes` (`tests/scenes`) to the repository;
//!   `langevin-fem` is the binary under test (first on `PATH`); `RAYON_NUM_THREADS` is
//!   unset, stdin closed, `NO_COLOR=1`; a command is killed after [`COMMAND_TIMEOUT`].
//! - Blocks tagged `numpy` run only in [`numpy_blocks_run_as_shown`] (ignored; `make
//!   docs-check`), where `python3` is the Python of `LANGEVIN_FEM_PYTHON`; with them, every
//!   other block of their page runs too, in order. A block without the tag must not read
//!   what a NumPy block writes.
//! - Rule (a): a line of another block (`sh`, `toml`, untagged, …) whose first word is
//!   `langevin-fem` or a path to it (after an optional `$ `) is refused: put it in a
//!   console block so it is run. Exempt: blocks whose info string is `text`, and a block
//!   preceded (on the line just before its fence) by `<!-- not-run: REASON -->`.
//! - Rule (b): every `make TARGET` shown, in any block or inline code span, names a
//!   target of the Makefile.
//! - `docs/src/SUMMARY.md` links only to pages that exist.
//!
//! Set-up: the built binary; fast commands in the fixtures (a second or less each).
//! Tolerance: exact, but for the wildcards the page writes.

mod common;
#[path = "docs/exec.rs"]
mod exec;
#[path = "docs/matcher.rs"]
mod matcher;
#[path = "docs/page.rs"]
mod page;

use common::{BIN, describe, manifest_dir, run, stdout_of};
use exec::{Mode, PageRun, Sandbox, run_page};
use matcher::{Mismatch, compare, line_matches, normalize};
use page::{Page, make_targets, makefile_targets, parse, runs_langevin_fem, summary_links};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longest run of one command of a page; the pages shorten long runs with flags.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(120);

/// The generated page of scene keys and its generator's arguments.
const SCENE_KEYS_PAGE: &str = "docs/src/reference/scene-keys.md";
const SCENE_KEYS_ARGS: &[&str] = &["scene", "keys", "--format", "markdown"];

/// The README's figure of the filament from tension through buckling, and the run that
/// writes it (as `tension-2d/force-strain.svg` under `--out`; `make docs` copies it).
const TENSION_IMAGE: &str = "docs/src/images/tension-2d.svg";
const TENSION_ARGS: &[&str] = &["verify", "-q", "--scene", "tension-2d", "--budget", "full"];

/// The environment variable naming a Python with NumPy, for the `numpy` blocks.
const PYTHON_VAR: &str = "LANGEVIN_FEM_PYTHON";

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

/// Lines as owned strings.
fn lines(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// The Makefile's targets.
fn targets() -> BTreeSet<String> {
    let text = std::fs::read_to_string(manifest_dir().join("Makefile")).expect("Makefile");
    makefile_targets(&text)
}

/// The page at `rel` (from the crate root), parsed; a `SUMMARY.md` also has its links
/// checked.
fn load(rel: &str) -> Page {
    let path = manifest_dir().join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let mut page = parse(rel, &text, &targets());
    if path.file_name().is_some_and(|n| n == "SUMMARY.md") {
        page.problems
            .extend(summary_links(&text, path.parent().expect("a directory")));
    }
    page
}

/// `README.md` and every `.md` file under `docs/src/` (relative to the crate root,
/// sorted): the pages `SUMMARY.md` lists are there, and so are any it forgets.
fn doc_pages() -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    let mut found = Vec::new();
    walk(&manifest_dir().join("docs/src"), &mut found);
    let mut pages: Vec<String> = found
        .iter()
        .map(|p| {
            let rel = p.strip_prefix(manifest_dir()).expect("under the crate");
            rel.to_string_lossy().replace('\\', "/")
        })
        .collect();
    pages.sort();
    pages.insert(0, "README.md".to_string());
    pages
}

/// The sandbox of these tests, with `python` as the pages' `python3`.
fn sandbox(python: Option<PathBuf>, timeout: Duration) -> Sandbox {
    Sandbox {
        bin: PathBuf::from(BIN),
        repo: manifest_dir().to_path_buf(),
        timeout,
        python,
    }
}

/// Writes a line to the real stderr, past the test harness's capture (the time per page
/// shows in `make test`).
fn log(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Runs `pages` in `mode`, logging a line per page and the total.
fn run_logged(pages: &[String], mode: Mode, sandbox: &Sandbox) -> Vec<PageRun> {
    let start = Instant::now();
    let runs: Vec<PageRun> = pages
        .iter()
        .map(|p| {
            let r = run_page(&load(p), sandbox, mode);
            log(&r.summary());
            r
        })
        .collect();
    let commands: usize = runs.iter().map(|r| r.commands).sum();
    log(&format!(
        "docs: {} page(s), {commands} command(s) in {:.1} s",
        runs.len(),
        start.elapsed().as_secs_f64()
    ));
    runs
}

/// Every failure of `runs`, one after the other.
fn failures(runs: &[PageRun]) -> Vec<String> {
    runs.iter().flat_map(|r| r.failures.clone()).collect()
}

// ---------------------------------------------------------------------------------------
// The matcher on known input
// ---------------------------------------------------------------------------------------

/// What: `...` matches zero or more lines at the start, the middle and the end of the
/// expected output, and several `...` in one output; it does not match lines that are
/// not there between two literal lines in the wrong order.
#[test]
fn any_lines_matches_zero_or_more_lines_anywhere() {
    let actual = lines(&["a", "b", "c", "d"]);
    for expected in [
        &["...", "d"][..],
        &["...", "a", "b", "c", "d"],
        &["a", "...", "d"],
        &["a", "b", "...", "c", "d"],
        &["a", "..."],
        &["a", "b", "c", "d", "..."],
        &["..."],
        &["...", "b", "...", "d", "..."],
    ] {
        assert_eq!(compare(&lines(expected), &actual), Ok(()), "{expected:?}");
    }
    for expected in [
        &["...", "c", "b", "..."][..],
        &["a", "...", "e"],
        &["...", "a", "..."][..0],
    ] {
        assert!(compare(&lines(expected), &actual).is_err(), "{expected:?}");
    }
    assert_eq!(
        compare(&lines(&["..."]), &[]),
        Ok(()),
        "`...` matches no line"
    );
}

/// What: `[..]` matches any run of characters (also none) within one line, several per
/// line; the parts between them are literal, in order, anchored at both ends; it never
/// matches across lines.
#[test]
fn any_text_matches_within_a_line() {
    for (e, a) in [
        ("x = [..]", "x = 1.5"),
        ("x = [..]", "x = "),
        ("[..] tau1", "4.0 tau1"),
        (
            "{\"n\":1,\"rate\":97.4[..],\"v\":0.02[..]}",
            "{\"n\":1,\"rate\":97.409,\"v\":0.0205}",
        ),
        ("[..]", ""),
        ("a[..]b[..]c", "abc"),
        ("a[..]a", "aba"),
        ("[..][..]", "anything"),
    ] {
        assert!(line_matches(e, a), "{e:?} should match {a:?}");
    }
    for (e, a) in [
        ("x = [..]", "y = 1"),
        ("[..] tau1", "4.0 tau2"),
        ("a[..]b[..]c", "acb"),
        ("a[..]a", "a"),
        ("abc", "abcd"),
        ("[.]", "x"),
    ] {
        assert!(!line_matches(e, a), "{e:?} should not match {a:?}");
    }
    let expected = lines(&["a[..]"]);
    assert!(
        compare(&expected, &lines(&["ab", "c"])).is_err(),
        "across lines"
    );
}

/// What: an empty expected output matches only an empty actual output (whitespace-only
/// lines at the end count as empty); trailing whitespace of a line is ignored on both
/// sides, leading whitespace is not; an expected output that is a prefix of the actual
/// one is a mismatch (no pass on shorter output).
#[test]
fn empty_output_and_whitespace() {
    assert_eq!(compare(&[], &normalize("")), Ok(()));
    assert_eq!(compare(&[], &normalize("\n  \n\t\n")), Ok(()));
    assert!(compare(&[], &normalize("x\n")).is_err());
    assert_eq!(normalize("a  \nb\t\n\n  \n"), lines(&["a", "b"]));
    assert_eq!(
        compare(&lines(&["a", "b"]), &normalize("a \t\nb\n\n")),
        Ok(())
    );
    assert!(compare(&lines(&["a"]), &normalize("  a")).is_err());
    assert!(compare(&lines(&["a"]), &normalize("a\nb")).is_err());
    assert!(compare(&lines(&["a", "b"]), &normalize("a")).is_err());
}

/// What: a mismatch names the first expected line no alignment gets past and the actual
/// line it meets, or says which output ends first.
#[test]
fn mismatch_names_the_first_differing_line() {
    let m = |e: &[&str], a: &[&str]| compare(&lines(e), &lines(a)).unwrap_err();
    let at = |i, e: Option<&str>, j, a: Option<&str>, after_any| Mismatch {
        expected_line: i,
        expected: e.map(str::to_string),
        actual_line: j,
        actual: a.map(str::to_string),
        after_any,
    };
    assert_eq!(
        m(&["a", "b", "c"], &["a", "B", "c"]),
        at(1, Some("b"), 1, Some("B"), false)
    );
    assert_eq!(m(&["a", "b"], &["a"]), at(1, Some("b"), 1, None, false));
    assert_eq!(
        m(&["a"], &["a", "extra"]),
        at(1, None, 1, Some("extra"), false)
    );
    assert_eq!(
        m(&["a", "...", "z"], &["a", "b", "c"]),
        at(2, Some("z"), 1, Some("b"), true)
    );
    assert_eq!(
        m(&[], &["x"]).to_string(),
        "no output expected, the actual output has line 1 `x`"
    );
    let text = m(&["a", "b"], &["a", "B"]).to_string();
    assert_eq!(text, "expected line 2 `b`, actual line 2 `B`");
    let text = m(&["a"], &["a", "extra"]).to_string();
    assert!(
        text.contains("ends after line 1") && text.contains("line 2 `extra`"),
        "{text}"
    );
}

// ---------------------------------------------------------------------------------------
// The parser and the static rules on known input
// ---------------------------------------------------------------------------------------

/// What: commands, continuation lines, expected output and exit-code lines are read as
/// the syntax says: `? N` only as the last expected line; the fence's indentation is
/// removed; `numpy` blocks are tagged.
#[test]
fn console_blocks_parse_into_commands() {
    let text = "intro\n\n  ```console\n  $ a \\\n    --flag\n  out [..]  \n\n  ? 2\n  $ b\n  ? 1\n  more\n\n  $ c\n  ```\n\n```console,numpy\n$ python3 x.py\n```\n";
    let page = parse("p.md", text, &BTreeSet::new());
    assert!(page.problems.is_empty(), "{:?}", page.problems);
    assert_eq!(page.blocks.len(), 2);
    let (b, n) = (&page.blocks[0], &page.blocks[1]);
    assert_eq!((b.line, b.numpy, n.line, n.numpy), (3, false, 16, true));
    let c: Vec<(usize, &str, Vec<String>, i32)> = b
        .cmds
        .iter()
        .map(|c| (c.line, c.text.as_str(), c.expected.clone(), c.code))
        .collect();
    assert_eq!(
        c,
        [
            (4, "a \\\n  --flag", lines(&["out [..]"]), 2),
            (9, "b", lines(&["? 1", "more"]), 0),
            (13, "c", vec![], 0),
        ]
    );
}

/// What: rule (a) finds `langevin-fem` (or a path to it) as the first word of a line,
/// with or without a `$ ` prompt, not elsewhere; rule (b) finds the targets of `make`
/// invocations (after assignments, among options and assignments, before redirections,
/// in `&&` chains), `all` for none, and skips `make -C`; the Makefile's targets are its
/// rules, not its variables or `.PHONY`.
#[test]
fn static_rules_find_commands_and_targets() {
    for l in [
        "langevin-fem verify",
        "  $ langevin-fem list",
        "./target/release/langevin-fem run",
    ] {
        assert!(runs_langevin_fem(l), "{l}");
    }
    for l in [
        "# langevin-fem verify",
        "cargo install langevin-fem",
        "langevin-fem-x y",
        "",
    ] {
        assert!(!runs_langevin_fem(l), "{l}");
    }
    let t = |l: &str| make_targets(l);
    assert_eq!(t("make test"), ["test"]);
    assert_eq!(
        t("$ BUDGET=full make -j2 verify OUT=x fig2 2>&1 | tee log"),
        ["verify", "fig2"]
    );
    assert_eq!(t("cargo build && make check; make"), ["check", "all"]);
    assert_eq!(t("make \\"), ["all"]);
    assert!(t("make -C docs html").is_empty());
    assert!(t("# make test: runs everything").is_empty());
    assert!(t("cmake --build .").is_empty());
    let ts = targets();
    for needed in [
        "all",
        "test",
        "check",
        "verify",
        "docs",
        "docs-check",
        "example-check",
    ] {
        assert!(
            ts.contains(needed),
            "Makefile target {needed} not found in {ts:?}"
        );
    }
    for not in ["PHONY", ".PHONY", "CARGO", "BUDGET", "SUDO", "PEERS_VENV"] {
        assert!(!ts.contains(not), "{not} read as a target");
    }
}

/// What: inline code spans are found across the lines of a paragraph, with double
/// backticks, never across a blank line or in text between spans (so prose words such as
/// "make it cheap" are not read as a `make` command).
#[test]
fn code_spans_follow_paragraphs() {
    let prose: Vec<(usize, String)> = [
        "run `make test` then `make",
        "verify` and ``a ` b``; make it cheap",
        "`unclosed make it",
        "",
        "make it `cheap`",
    ]
    .iter()
    .enumerate()
    .map(|(i, l)| (i + 1, l.to_string()))
    .collect();
    let spans = page::code_spans(&prose);
    let want = [
        (1, "make test"),
        (1, "make verify"),
        (2, "a ` b"),
        (5, "cheap"),
    ];
    let want: Vec<(usize, String)> = want.iter().map(|(n, s)| (*n, s.to_string())).collect();
    assert_eq!(spans, want);
}

/// What: the fixture page breaking every static rule is refused at exactly the lines it
/// lists: `make` with an unknown target (prose and block), `langevin-fem` outside a
/// console block (plain and as a path, prompted), a marker without a reason, a stray
/// marker, an unknown tag, output before any command, a console block without commands.
#[test]
fn static_rules_reject_the_rules_fixture() {
    let page = load("tests/docs-fixtures/rules.md");
    let found: Vec<usize> = page.problems.iter().map(|p| p.line).collect();
    let all: String = page
        .problems
        .iter()
        .map(|p| format!("{}: {}\n", p.line, p.message))
        .collect();
    assert_eq!(found, [5, 8, 9, 10, 13, 18, 20, 21, 25], "{all}");
    for needle in [
        "no target \"no-such-target\"",
        "put it in a console block",
        "malformed marker",
        "must be just before a fenced block",
        "unknown tag \"nunpy\"",
        "comes before any command",
        "console block without a command",
    ] {
        assert!(all.contains(needle), "no problem {needle:?}: {all}");
    }
}

// ---------------------------------------------------------------------------------------
// The runner on fixture pages
// ---------------------------------------------------------------------------------------

/// What: the passing fixture (every rule of the syntax, used as documented) passes:
/// all its 12 commands run, its NumPy block is skipped and counted, no problem is found.
#[test]
fn runner_passes_the_passing_fixture() {
    let page = load("tests/docs-fixtures/pass.md");
    let run = run_page(&page, &sandbox(None, COMMAND_TIMEOUT), Mode::Default);
    assert!(run.failures.is_empty(), "{}", run.failures.join("\n"));
    assert_eq!(
        (run.commands, run.skipped_numpy),
        (12, 1),
        "{}",
        run.summary()
    );
}

/// What: a page with a deliberately wrong expected output fails, at its command's line,
/// naming the first differing line and showing both outputs and the exit codes; its
/// right command does not fail.
#[test]
fn runner_rejects_a_wrong_output() {
    let page = load("tests/docs-fixtures/wrong-output.md");
    let run = run_page(&page, &sandbox(None, COMMAND_TIMEOUT), Mode::Default);
    assert_eq!(run.failures.len(), 1, "{}", run.failures.join("\n"));
    let f = &run.failures[0];
    for needle in [
        "tests/docs-fixtures/wrong-output.md:9: $ printf",
        "exit code: expected 0, got 0\n",
        "output differs: expected line 2 `TWO`, actual line 2 `two`",
        "--- expected output ---",
        "   2 | TWO",
        "--- actual output (stdout, then stderr) ---",
        "   2 | two",
    ] {
        assert!(f.contains(needle), "no {needle:?} in:\n{f}");
    }
}

/// What: wrong exit codes fail, both ways (an error where the page expects success, the
/// default 0; success where it expects `? 3`), each named with the expected and the actual
/// code.
#[test]
fn runner_rejects_a_wrong_exit_code() {
    let page = load("tests/docs-fixtures/wrong-exit.md");
    let run = run_page(&page, &sandbox(None, COMMAND_TIMEOUT), Mode::Default);
    let all = run.failures.join("\n");
    assert_eq!(run.failures.len(), 2, "{all}");
    assert!(
        run.failures[0].contains("wrong-exit.md:7: $ langevin-fem scene show nope"),
        "{all}"
    );
    assert!(
        run.failures[0].contains("exit code: expected 0, got 2  <- WRONG"),
        "{all}"
    );
    assert!(run.failures[0].contains("output: as expected"), "{all}");
    assert!(run.failures[1].contains("wrong-exit.md:9: $ true"), "{all}");
    assert!(
        run.failures[1].contains("exit code: expected 3, got 0  <- WRONG"),
        "{all}"
    );
}

/// What: a command running past the timeout is killed with its process group (`sh` and
/// its `sleep`), reported as timed out, and the page stops there.
/// Set-up: a 1 s timeout and a 30 s sleep.
#[test]
fn runner_kills_and_reports_a_timeout() {
    let text = "```console\n$ sleep 30; echo late\nlate\n$ echo never\nnever\n```\n";
    let page = parse("timeout.md", text, &BTreeSet::new());
    let start = Instant::now();
    let run = run_page(&page, &sandbox(None, Duration::from_secs(1)), Mode::Default);
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "not killed in time"
    );
    assert_eq!(run.commands, 1, "the page should stop at the timeout");
    let all = run.failures.join("\n");
    assert_eq!(run.failures.len(), 1, "{all}");
    assert!(
        all.contains("timeout.md:2: $ sleep 30; echo late") && all.contains("timed out"),
        "{all}"
    );
}

/// What: the failures of every page are collected and reported together, each under its
/// page and line (the wrong-output and wrong-exit fixtures run as one set).
#[test]
fn failures_of_all_pages_are_reported_together() {
    let sb = sandbox(None, COMMAND_TIMEOUT);
    let runs: Vec<PageRun> = [
        "tests/docs-fixtures/wrong-output.md",
        "tests/docs-fixtures/wrong-exit.md",
    ]
    .iter()
    .map(|p| run_page(&load(p), &sb, Mode::Default))
    .collect();
    let all = failures(&runs);
    assert_eq!(all.len(), 3, "{}", all.join("\n"));
    assert!(all[0].starts_with("tests/docs-fixtures/wrong-output.md:9:"));
    assert!(all[2].starts_with("tests/docs-fixtures/wrong-exit.md:9:"));
}

// ---------------------------------------------------------------------------------------
// The pages
// ---------------------------------------------------------------------------------------

/// What: every console block of README.md and docs/src/ (but those tagged `numpy`) runs
/// as shown, and the static rules hold on every page.
/// Reference: the syntax in this file's header.
#[test]
fn readme_and_guide_run_as_shown() {
    let pages = doc_pages();
    let runs = run_logged(&pages, Mode::Default, &sandbox(None, COMMAND_TIMEOUT));
    let all = failures(&runs);
    assert!(
        all.is_empty(),
        "{} failure(s) in README.md and docs/src/ (their console blocks run as shown; the \
         syntax is in the header of tests/docs.rs):\n\n{}",
        all.len(),
        all.join("\n")
    );
}

/// The Python of `LANGEVIN_FEM_PYTHON` as an absolute path (a bare name looked up on
/// `PATH`; links not resolved: a venv's `python` is one), checked to import NumPy.
fn python_with_numpy() -> PathBuf {
    let python = std::env::var_os(PYTHON_VAR).unwrap_or_else(|| {
        panic!(
            "{PYTHON_VAR} is not set: the numpy blocks need a Python with NumPy. Run `make \
             docs-check`, or set {PYTHON_VAR}=/path/to/python and run `cargo test --release \
             --test docs -- --ignored`"
        )
    });
    let python = PathBuf::from(python);
    let python = if python.components().count() == 1 {
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())
            .map(|d| d.join(&python))
            .find(|p| p.is_file())
            .unwrap_or_else(|| panic!("{PYTHON_VAR}={}: not found on PATH", python.display()))
    } else {
        std::path::absolute(&python).expect("an absolute path")
    };
    let o = std::process::Command::new(&python)
        .args(["-c", "import numpy"])
        .output()
        .unwrap_or_else(|e| panic!("{PYTHON_VAR}={}: cannot run it: {e}", python.display()));
    assert!(
        o.status.success(),
        "{PYTHON_VAR}={}: cannot import numpy: {}",
        python.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    python
}

/// What: the console blocks tagged `numpy` run as shown, with the Python of
/// `LANGEVIN_FEM_PYTHON` as `python3` (each such page runs all its blocks, in order);
/// first the NumPy fixture, whose block reads what its first block wrote.
/// Set-up: `make docs-check` (the venv of `make example-check`).
#[test]
#[ignore = "needs LANGEVIN_FEM_PYTHON, a Python with NumPy: make docs-check"]
fn numpy_blocks_run_as_shown() {
    let sb = sandbox(Some(python_with_numpy()), COMMAND_TIMEOUT);
    let fixture = run_page(&load("tests/docs-fixtures/numpy.md"), &sb, Mode::Numpy);
    assert!(
        fixture.failures.is_empty(),
        "{}",
        fixture.failures.join("\n")
    );
    assert_eq!(
        (fixture.commands, fixture.numpy_run),
        (2, 1),
        "{}",
        fixture.summary()
    );
    let runs = run_logged(&doc_pages(), Mode::Numpy, &sb);
    let all = failures(&runs);
    assert!(
        all.is_empty(),
        "{} failure(s) in the numpy blocks of README.md and docs/src/:\n\n{}",
        all.len(),
        all.join("\n")
    );
}

/// What: the committed page of scene keys is byte for byte what `langevin-fem scene keys
/// --format markdown` prints (the table in src/scene/keys.rs); else `make docs` is the fix.
#[test]
fn scene_key_page_is_generated() {
    let o = run(SCENE_KEYS_ARGS);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        describe(SCENE_KEYS_ARGS, &o)
    );
    let generated = stdout_of(&o);
    let committed = std::fs::read_to_string(manifest_dir().join(SCENE_KEYS_PAGE))
        .unwrap_or_else(|e| panic!("{SCENE_KEYS_PAGE}: {e}: run `make docs` to write it"));
    if committed != generated {
        let (c, g): (Vec<&str>, Vec<&str>) =
            (committed.lines().collect(), generated.lines().collect());
        let i = (0..c.len().max(g.len()))
            .find(|&i| c.get(i) != g.get(i))
            .unwrap_or(c.len());
        panic!(
            "{SCENE_KEYS_PAGE} differs from `langevin-fem {}` (the table in \
             src/scene/keys.rs) at line {}:\n  committed: {:?}\n  generated: {:?}\nRun `make \
             docs` to regenerate it; do not edit it by hand.",
            SCENE_KEYS_ARGS.join(" "),
            i + 1,
            c.get(i),
            g.get(i)
        );
    }
}

/// What: the committed figure of the filament from tension through buckling (README,
/// `docs/src/images/tension-2d.svg`) is byte for byte the figure that `langevin-fem verify
/// --scene tension-2d --budget full` writes (about 2 s), as `fig2-shards` holds Fig. 2 to
/// its run; else `make docs` is the fix.
#[test]
fn tension_figure_is_the_full_budget_run() {
    let dir = common::TempDir::new("docs-tension");
    let out = dir.path().display().to_string();
    let mut args = TENSION_ARGS.to_vec();
    args.extend(["--out", &out]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let generated = std::fs::read(dir.join("tension-2d/force-strain.svg")).unwrap();
    let committed = std::fs::read(manifest_dir().join(TENSION_IMAGE))
        .unwrap_or_else(|e| panic!("{TENSION_IMAGE}: {e}: run `make docs` to write it"));
    assert!(
        committed == generated,
        "{TENSION_IMAGE} differs from the figure of `langevin-fem {}`: run `make docs` and \
         commit it",
        TENSION_ARGS.join(" ")
    );
}
