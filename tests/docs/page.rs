//! A Markdown page as the docs runner reads it: its fenced blocks, the commands of its
//! `console` blocks with their expected output and exit code, and the problems of the
//! page that need no command to be run (rules (a) and (b) of `tests/docs.rs`, a stray
//! or malformed `not-run` marker, an unterminated fence, an unknown tag).

use std::collections::BTreeSet;

/// The tags a `console` block may carry after a comma (```` ```console,numpy ````).
pub const TAGS: &[&str] = &["numpy"];

/// The marker that exempts the next fenced block from rule (a), with its reason:
/// `<!-- not-run: REASON -->` on the line just before the opening fence.
pub const NOT_RUN: &str = "<!-- not-run:";

/// One command of a `console` block.
#[derive(Debug, Clone, PartialEq)]
pub struct Cmd {
    /// Line of its `$ ` in the page (1-based).
    pub line: usize,
    /// The command as given to `sh -c` (continued lines joined by newlines, each `\`
    /// kept, which `sh` reads as a continuation).
    pub text: String,
    /// Expected output lines (stdout then stderr), trailing whitespace trimmed, trailing
    /// empty lines and the exit-code line removed.
    pub expected: Vec<String>,
    /// Expected exit code (`? N`, default 0).
    pub code: i32,
}

/// A `console` block.
#[derive(Debug, Clone, PartialEq)]
pub struct ConsoleBlock {
    /// Line of its opening fence (1-based).
    pub line: usize,
    /// Whether it is tagged `numpy` (run only with `LANGEVIN_FEM_PYTHON`).
    pub numpy: bool,
    /// Its commands, in order.
    pub cmds: Vec<Cmd>,
}

/// A problem found without running anything: where and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Line in the page (1-based).
    pub line: usize,
    /// What is wrong and how to fix it.
    pub message: String,
}

/// A page, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct Page {
    /// Its name in messages (path relative to the repository).
    pub name: String,
    /// Its `console` blocks, in order.
    pub blocks: Vec<ConsoleBlock>,
    /// Its problems (rules (a), (b) and syntax), in page order.
    pub problems: Vec<Problem>,
}

/// A fenced block before interpretation.
struct Fence {
    /// Line of the opening fence (1-based).
    line: usize,
    /// The info string, trimmed.
    info: String,
    /// Whether a `not-run` marker precedes it.
    not_run: bool,
    /// Its lines (indentation of the fence removed), with their line numbers.
    lines: Vec<(usize, String)>,
}

/// The opening fence on `raw`, if any: (indentation, fence character, length, info).
fn opening(raw: &str) -> Option<(usize, char, usize, String)> {
    let trimmed = raw.trim_start();
    let ch = trimmed.chars().next().filter(|c| *c == '`' || *c == '~')?;
    let len = trimmed.chars().take_while(|c| *c == ch).count();
    let info = trimmed[len..].trim();
    // A backtick fence's info string has no backtick (CommonMark): "```x```" is code.
    (len >= 3 && !(ch == '`' && info.contains('`')))
        .then(|| (raw.len() - trimmed.len(), ch, len, info.to_string()))
}

/// Whether `raw` closes a fence of `len` characters `ch`.
fn closing(raw: &str, ch: char, len: usize) -> bool {
    let t = raw.trim();
    t.chars().count() >= len && t.chars().all(|c| c == ch)
}

/// Removes up to `indent` leading spaces.
fn dedent(raw: &str, indent: usize) -> String {
    let spaces = raw.len() - raw.trim_start_matches(' ').len();
    raw[spaces.min(indent)..].to_string()
}

/// The reason of a `not-run` marker line, `Err` if the line is a malformed marker, `None`
/// if it is not a marker.
fn marker(raw: &str) -> Option<Result<String, String>> {
    let t = raw.trim();
    let rest = t.strip_prefix(NOT_RUN)?;
    Some(match rest.strip_suffix("-->").map(str::trim) {
        Some(reason) if !reason.is_empty() => Ok(reason.to_string()),
        _ => Err(format!(
            "malformed marker {t:?}: write `{NOT_RUN} REASON -->` (a non-empty reason) on \
             the line just before the fence"
        )),
    })
}

/// The fenced blocks of `text`, and the prose lines (outside fences) with their numbers;
/// syntax problems (markers, unterminated fences) go to `problems`.
fn split(text: &str, problems: &mut Vec<Problem>) -> (Vec<Fence>, Vec<(usize, String)>) {
    let (mut fences, mut prose) = (Vec::new(), Vec::new());
    let mut open: Option<(usize, char, usize, Fence)> = None;
    let mut pending_marker: Option<usize> = None;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        if let Some((indent, ch, len, mut fence)) = open.take() {
            if closing(raw, ch, len) {
                fences.push(fence);
            } else {
                fence.lines.push((n, dedent(raw, indent)));
                open = Some((indent, ch, len, fence));
            }
            continue;
        }
        let marked = pending_marker.take();
        if let Some((indent, ch, len, info)) = opening(raw) {
            let fence = Fence {
                line: n,
                info,
                not_run: marked.is_some(),
                lines: Vec::new(),
            };
            open = Some((indent, ch, len, fence));
            continue;
        }
        if let Some(m) = marked {
            problems.push(Problem {
                line: m,
                message: format!("`{NOT_RUN} … -->` must be just before a fenced block"),
            });
        }
        match marker(raw) {
            Some(Ok(_)) => pending_marker = Some(n),
            Some(Err(message)) => problems.push(Problem { line: n, message }),
            None => prose.push((n, raw.to_string())),
        }
    }
    if let Some((_, _, _, fence)) = open {
        problems.push(Problem {
            line: fence.line,
            message: "fence never closed".to_string(),
        });
        fences.push(fence);
    }
    if let Some(m) = pending_marker {
        problems.push(Problem {
            line: m,
            message: format!("`{NOT_RUN} … -->` must be just before a fenced block"),
        });
    }
    (fences, prose)
}

/// Whether the line `l` ends in a continuation backslash.
fn continues(l: &str) -> bool {
    l.trim_end().ends_with('\\')
}

/// The exit code of an expected-output line `? N`.
fn exit_line(l: &str) -> Option<i32> {
    l.strip_prefix("? ")?.trim().parse().ok()
}

/// Finishes a command: trims its expected output and takes its exit-code line.
fn finish(mut cmd: Cmd) -> Cmd {
    for l in &mut cmd.expected {
        *l = l.trim_end().to_string();
    }
    let trim = |v: &mut Vec<String>| {
        while v.last().is_some_and(String::is_empty) {
            v.pop();
        }
    };
    trim(&mut cmd.expected);
    if let Some(code) = cmd.expected.last().and_then(|l| exit_line(l)) {
        cmd.code = code;
        cmd.expected.pop();
        trim(&mut cmd.expected);
    }
    cmd
}

/// The commands of a `console` block's lines.
fn commands(lines: &[(usize, String)], problems: &mut Vec<Problem>) -> Vec<Cmd> {
    let mut cmds = Vec::new();
    let mut cur: Option<Cmd> = None;
    let mut it = lines.iter();
    while let Some((n, l)) = it.next() {
        if let Some(first) = l.strip_prefix("$ ") {
            cmds.extend(cur.take().map(finish));
            let mut text = first.trim_end().to_string();
            while continues(&text) {
                let Some((_, next)) = it.next() else { break };
                text.push('\n');
                text.push_str(next.trim_end());
            }
            cur = Some(Cmd {
                line: *n,
                text,
                expected: Vec::new(),
                code: 0,
            });
        } else if let Some(c) = cur.as_mut() {
            c.expected.push(l.clone());
        } else if !l.trim().is_empty() {
            problems.push(Problem {
                line: *n,
                message: format!(
                    "console block: {l:?} comes before any command (a command line starts \
                     with `$ `)"
                ),
            });
        }
    }
    cmds.extend(cur.map(finish));
    cmds
}

/// The `console` block of a fence whose info string's first word is `console`, or
/// `None` for any other fence.
fn console_block(fence: &Fence, problems: &mut Vec<Problem>) -> Option<ConsoleBlock> {
    let mut words = fence.info.split(',').map(str::trim);
    if words.next() != Some("console") {
        return None;
    }
    let mut numpy = false;
    for tag in words {
        match tag {
            "numpy" => numpy = true,
            _ => problems.push(Problem {
                line: fence.line,
                message: format!("unknown tag {tag:?} of a console block (known: {TAGS:?})"),
            }),
        }
    }
    if fence.not_run {
        problems.push(Problem {
            line: fence.line,
            message: format!(
                "a console block is always run: to show commands that are not run, use \
                 ```sh with `{NOT_RUN} REASON -->` before it"
            ),
        });
    }
    let cmds = commands(&fence.lines, problems);
    if cmds.is_empty() {
        problems.push(Problem {
            line: fence.line,
            message: "console block without a command (`$ ` line)".to_string(),
        });
    }
    Some(ConsoleBlock {
        line: fence.line,
        numpy,
        cmds,
    })
}

/// Parses the page `name` (text `text`), checking the `make` targets it shows against
/// `targets` (the Makefile's, [`makefile_targets`]).
pub fn parse(name: &str, text: &str, targets: &BTreeSet<String>) -> Page {
    let mut problems = Vec::new();
    let (fences, prose) = split(text, &mut problems);
    let mut blocks = Vec::new();
    for fence in &fences {
        let console = console_block(fence, &mut problems);
        let exempt = console.is_some() || fence.not_run || fence.info == "text";
        for (n, l) in &fence.lines {
            if !exempt && runs_langevin_fem(l) {
                problems.push(Problem {
                    line: *n,
                    message: format!(
                        "{:?} in a ```{} block is not run: put it in a console block so it \
                         is run (or, if it must not run, use ```text or `{NOT_RUN} REASON -->`)",
                        l.trim(),
                        fence.info
                    ),
                });
            }
            problems.extend(unknown_make_targets(*n, l, targets));
        }
        blocks.extend(console);
    }
    for (n, span) in code_spans(&prose) {
        problems.extend(unknown_make_targets(n, &span, targets));
    }
    problems.sort_by_key(|p| p.line);
    Page {
        name: name.to_string(),
        blocks,
        problems,
    }
}

/// The inline code spans of the prose lines (numbered, outside fences), each with the
/// line where it starts and its text (line breaks as spaces): a run of N backticks opens
/// a span that the next run of exactly N closes, within a paragraph (a blank line or a
/// fenced block ends it, and an unclosed span with it).
pub fn code_spans(prose: &[(usize, String)]) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    // The open span: its opening run's length, start line and text so far.
    let mut open: Option<(usize, usize, String)> = None;
    let mut last_line = 0;
    for (n, l) in prose {
        if l.trim().is_empty() || *n != last_line + 1 {
            open = None;
        }
        last_line = *n;
        if let Some((_, _, text)) = open.as_mut() {
            text.push(' ');
        }
        let mut chars = l.chars().peekable();
        while let Some(c) = chars.next() {
            if c != '`' {
                if let Some((_, _, text)) = open.as_mut() {
                    text.push(c);
                }
                continue;
            }
            let mut run = 1;
            while chars.next_if_eq(&'`').is_some() {
                run += 1;
            }
            match open.take() {
                None => open = Some((run, *n, String::new())),
                Some((len, start, text)) if len == run => {
                    out.push((start, text.trim().to_string()))
                }
                Some((len, start, mut text)) => {
                    text.push_str(&"`".repeat(run));
                    open = Some((len, start, text));
                }
            }
        }
    }
    out
}

/// Rule (a): whether a line of a block runs the program: its first word (after optional
/// indentation and an optional `$ ` prompt) is `langevin-fem` or a path to it
/// (`target/release/langevin-fem`).
pub fn runs_langevin_fem(line: &str) -> bool {
    let t = line.trim_start();
    let t = t.strip_prefix("$ ").unwrap_or(t);
    let first = t.split_whitespace().next().unwrap_or("");
    first == "langevin-fem" || first.ends_with("/langevin-fem")
}

/// The simple commands of a shell line: split at `&&`, `||`, `;`, `|`, `(`, `)`, each
/// without a leading `$ ` prompt.
fn simple_commands(line: &str) -> Vec<&str> {
    line.split(['|', '&', ';', '(', ')'])
        .map(|s| {
            let s = s.trim();
            s.strip_prefix("$ ").unwrap_or(s)
        })
        .collect()
}

/// The targets of the `make` invocations in `line` (`VAR=value make [options]
/// [VAR=value] TARGET…`); a `make -C DIR` or `make -f FILE` (another Makefile) is not
/// checked. An invocation without a target names the default one, `all`.
pub fn make_targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    for cmd in simple_commands(line) {
        let mut words = cmd.split_whitespace().skip_while(|w| w.contains('='));
        if words.next() != Some("make") {
            continue;
        }
        let args: Vec<&str> = words.collect();
        if args
            .iter()
            .any(|a| a.starts_with("-C") || a.starts_with("-f"))
        {
            continue;
        }
        // Up to a redirection or a comment; not options, assignments or a continuation.
        let targets: Vec<String> = args
            .iter()
            .take_while(|a| !a.starts_with('#') && !a.contains(['>', '<']))
            .filter(|a| !a.starts_with('-') && !a.contains('=') && **a != "\\")
            .map(|a| a.trim_matches(['"', '\'']).to_string())
            .collect();
        if targets.is_empty() {
            out.push("all".to_string());
        }
        out.extend(targets);
    }
    out
}

/// Rule (b): a problem for each `make` target of `line` that the Makefile lacks.
fn unknown_make_targets(n: usize, line: &str, targets: &BTreeSet<String>) -> Vec<Problem> {
    make_targets(line)
        .into_iter()
        .filter(|t| !targets.contains(t))
        .map(|t| Problem {
            line: n,
            message: format!(
                "`make {t}`: the Makefile has no target {t:?} (targets: {})",
                targets.iter().cloned().collect::<Vec<_>>().join(", ")
            ),
        })
        .collect()
}

/// The targets of a Makefile's text: the names before `:` of its rules (not variable
/// assignments, special targets such as `.PHONY`, or pattern rules).
pub fn makefile_targets(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines() {
        if line.starts_with(['\t', ' ', '#']) {
            continue;
        }
        let Some((lhs, rhs)) = line.split_once(':') else {
            continue;
        };
        if lhs.contains('=') || rhs.starts_with('=') || rhs.starts_with(":=") {
            continue;
        }
        out.extend(
            lhs.split_whitespace()
                .filter(|t| !t.starts_with('.') && !t.contains(['%', '$']))
                .map(str::to_string),
        );
    }
    out
}

/// Problems of an mdBook `SUMMARY.md` (`text`, in `dir`): a chapter link to a file that
/// does not exist (draft chapters, `[Title]()`, and external links are not checked).
pub fn summary_links(text: &str, dir: &std::path::Path) -> Vec<Problem> {
    let mut out = Vec::new();
    for (i, l) in text.lines().enumerate() {
        for part in l.split("](").skip(1) {
            let target = part.split(')').next().unwrap_or("");
            let target = target.split('#').next().unwrap_or("");
            if target.is_empty() || target.contains("://") {
                continue;
            }
            if !dir.join(target).is_file() {
                out.push(Problem {
                    line: i + 1,
                    message: format!("chapter {target} does not exist"),
                });
            }
        }
    }
    out
}
