//! Expected output against actual output, line by line, with two wildcards: a line `...`
//! matches zero or more lines, `[..]` inside a line matches any run of characters within
//! that line; everything else is literal. Both sides are compared after trimming the
//! trailing whitespace of each line and the trailing empty lines.

use std::fmt;

/// The expected line that matches any number of lines.
pub const ANY_LINES: &str = "...";
/// The wildcard within a line.
pub const ANY_TEXT: &str = "[..]";

/// `text` as lines: trailing whitespace of each line trimmed, trailing empty lines
/// dropped.
pub fn normalize(text: &str) -> Vec<String> {
    let mut lines: Vec<String> = text.lines().map(|l| l.trim_end().to_string()).collect();
    while lines.last().is_some_and(String::is_empty) {
        lines.pop();
    }
    lines
}

/// Whether `actual` matches the expected line `expected` (literal but for `[..]`).
pub fn line_matches(expected: &str, actual: &str) -> bool {
    let parts: Vec<&str> = expected.split(ANY_TEXT).collect();
    let [first, middle @ .., last] = parts.as_slice() else {
        return expected == actual;
    };
    let Some(mut rest) = actual.strip_prefix(first) else {
        return false;
    };
    // The leftmost occurrence of each middle part leaves the most room for the rest.
    for part in middle {
        match rest.find(part) {
            Some(i) => rest = &rest[i + part.len()..],
            None => return false,
        }
    }
    rest.ends_with(last)
}

/// Where expected and actual output first differ.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    /// The first expected line (0-based) no alignment gets past, or `expected.len()` if
    /// the expected lines all match but actual output remains.
    pub expected_line: usize,
    /// The expected line there, `None` at the end of the expected output.
    pub expected: Option<String>,
    /// The first actual line (0-based) it is compared with.
    pub actual_line: usize,
    /// The actual line there, `None` at the end of the actual output.
    pub actual: Option<String>,
    /// Whether the expected line follows a `...` (then no later actual line matches it
    /// either).
    pub after_any: bool,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (e, a) = (self.expected_line + 1, self.actual_line + 1);
        match (&self.expected, &self.actual) {
            (None, Some(act)) if self.expected_line == 0 => write!(
                f,
                "no output expected, the actual output has line {a} `{act}`"
            ),
            (None, Some(act)) => write!(
                f,
                "the expected output ends after line {}, the actual output goes on: line \
                 {a} `{act}`",
                self.expected_line
            ),
            (Some(exp), None) if self.after_any => write!(
                f,
                "expected line {e} `{exp}` matches no actual line from line {a} on"
            ),
            (Some(exp), None) => write!(
                f,
                "expected line {e} `{exp}`, but the actual output ends after line {}",
                self.actual_line
            ),
            (Some(exp), Some(act)) if self.after_any => write!(
                f,
                "expected line {e} `{exp}` matches no actual line from line {a} (`{act}`) on"
            ),
            (Some(exp), Some(act)) => {
                write!(f, "expected line {e} `{exp}`, actual line {a} `{act}`")
            }
            (None, None) => write!(f, "no difference"),
        }
    }
}

/// Matches the normalized `actual` lines against the `expected` lines: `Ok` if they
/// match, else where they first differ.
///
/// `reach[i][j]`: the first `i` expected lines can match the first `j` actual lines.
/// The furthest expected line reached is reported, with the first actual line it is
/// compared with.
pub fn compare(expected: &[String], actual: &[String]) -> Result<(), Mismatch> {
    let (n, m) = (expected.len(), actual.len());
    let mut reach = vec![vec![false; m + 1]; n + 1];
    reach[0][0] = true;
    for (i, e) in expected.iter().enumerate() {
        let mut next = vec![false; m + 1];
        if e == ANY_LINES {
            let mut seen = false;
            for (r, out) in reach[i].iter().zip(next.iter_mut()) {
                seen |= r;
                *out = seen;
            }
        } else {
            for (j, a) in actual.iter().enumerate() {
                next[j + 1] = reach[i][j] && line_matches(e, a);
            }
        }
        reach[i + 1] = next;
    }
    if reach[n][m] {
        return Ok(());
    }
    let i = (0..=n)
        .rev()
        .find(|&i| reach[i].contains(&true))
        .unwrap_or(0);
    let j = reach[i].iter().position(|r| *r).unwrap_or(0);
    let j = if i == n {
        // Every expected line matched; the first actual line left over.
        reach[n].iter().rposition(|r| *r).unwrap_or(0)
    } else {
        j
    };
    Err(Mismatch {
        expected_line: i,
        expected: expected.get(i).cloned(),
        actual_line: j,
        actual: actual.get(j).cloned(),
        after_any: i > 0 && expected[i - 1] == ANY_LINES,
    })
}
