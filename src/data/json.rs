//! The JSON layer of the sidecar: what `serde_json` alone would report as "expected value
//! at line L column C" is said in words here. Non-finite literals (`NaN`, `Infinity`,
//! `-Infinity`, as Python's `json.dump` writes by default) are named with their line,
//! column and key, and `null` at a numeric key is refused naming the key (see the
//! [format](super)).

use crate::error::Result;
use crate::input::refused;
use serde_json::Value;
use std::path::Path;

/// The sidecar keys whose values are numbers (`[]` stands for any index): `null` is
/// refused at these.
const NUMERIC_KEYS: [&str; 14] = [
    "version",
    "dims",
    "filament.length",
    "filament.bending_rigidity",
    "filament.drag",
    "filament.kt",
    "filament.stretch_rigidity",
    "runs[].dt_sample",
    "runs[].burn_in",
    "runs[].positions[]",
    "runs[].modes",
    "runs[].strain_ratio",
    "runs[].discretization.elements",
    "runs[].discretization.dt",
];

/// Non-finite literals some writers put in JSON, longest first (matched ignoring case).
const NON_FINITE: [&str; 9] = [
    "-infinity",
    "+infinity",
    "infinity",
    "-inf",
    "+inf",
    "inf",
    "-nan",
    "+nan",
    "nan",
];

/// Parses the sidecar text read from `path` as JSON and refuses `null` at a numeric key.
///
/// # Errors
/// [`crate::error::Error::Scene`] naming `path`: a non-finite literal (its line, column
/// and key), another syntax error (its line and column), or `null` at a numeric key.
pub(super) fn parse(path: &Path, text: &str) -> Result<Value> {
    let value: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => {
            if let Some(&(at, len)) = non_finite_literals(text).first() {
                let literal = &text[at..at + len];
                let (line, column) = line_column(text, at);
                let key = key_at(text, at).unwrap_or_else(|| "-".to_string());
                return Err(refused(
                    path,
                    &key,
                    format!(
                        "{literal} at line {line}, column {column} is not JSON (JSON has no NaN or infinity): write finite numbers (in Python, json.dump(..., allow_nan=False) raises on them instead of writing them)"
                    ),
                ));
            }
            return Err(refused(
                path,
                "-",
                format!("not a {} sidecar: {e}", super::FORMAT),
            ));
        }
    };
    if let Some(key) = null_number(&value, String::new()) {
        return Err(refused(
            path,
            &key,
            "must be a number, got null (JSON null is not a number; leave an optional key out instead)",
        ));
    }
    Ok(value)
}

/// The byte offsets and lengths of the non-finite literals outside strings in `text`.
fn non_finite_literals(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut found = Vec::new();
    let (mut i, mut in_string) = (0, false);
    'scan: while i < b.len() {
        let c = b[i];
        if in_string {
            match c {
                b'\\' => i += 2,
                b'"' => {
                    in_string = false;
                    i += 1;
                }
                _ => i += 1,
            }
            continue;
        }
        if c == b'"' {
            in_string = true;
            i += 1;
            continue;
        }
        for lit in NON_FINITE {
            if b.len() - i >= lit.len() && b[i..i + lit.len()].eq_ignore_ascii_case(lit.as_bytes())
            {
                found.push((i, lit.len()));
                i += lit.len();
                continue 'scan;
            }
        }
        i += 1;
    }
    found
}

/// The 1-based line and column (in characters) of byte offset `at` of `text`.
fn line_column(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |p| p + 1);
    (line, before[line_start..].chars().count() + 1)
}

/// The key (`runs[0].dt_sample`) of the non-finite literal at byte offset `at` of `text`:
/// that literal is replaced by a marker string and every other by `0`, and the marker is
/// looked up in the parsed value. `None` if the text has another syntax error.
fn key_at(text: &str, at: usize) -> Option<String> {
    const MARKER: &str = r#""\u0001non-finite\u0001""#;
    let mut patched = String::with_capacity(text.len() + MARKER.len());
    let mut from = 0;
    for (i, len) in non_finite_literals(text) {
        patched.push_str(&text[from..i]);
        patched.push_str(if i == at { MARKER } else { "0" });
        from = i + len;
    }
    patched.push_str(&text[from..]);
    let value: Value = serde_json::from_str(&patched).ok()?;
    let marker: Value = serde_json::from_str(MARKER).ok()?;
    path_of(&value, &marker, String::new())
}

/// The key of the first value equal to `target` in `v` (at key `path`).
fn path_of(v: &Value, target: &Value, path: String) -> Option<String> {
    if v == target {
        return Some(path);
    }
    children(v, &path).find_map(|(p, c)| path_of(c, target, p))
}

/// The key of the first `null` at a numeric key ([`NUMERIC_KEYS`]) in `v` (at `path`).
fn null_number(v: &Value, path: String) -> Option<String> {
    if v.is_null() && NUMERIC_KEYS.contains(&pattern(&path).as_str()) {
        return Some(path);
    }
    children(v, &path).find_map(|(p, c)| null_number(c, p))
}

/// The children of `v` (at key `path`) with their keys: `a.b` in objects, `a[3]` in
/// arrays.
fn children<'a>(v: &'a Value, path: &str) -> Box<dyn Iterator<Item = (String, &'a Value)> + 'a> {
    let path = path.to_string();
    match v {
        Value::Object(map) => Box::new(map.iter().map(move |(k, c)| {
            let key = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            (key, c)
        })),
        Value::Array(items) => Box::new(
            items
                .iter()
                .enumerate()
                .map(move |(i, c)| (format!("{path}[{i}]"), c)),
        ),
        _ => Box::new(std::iter::empty()),
    }
}

/// `key` with its indices dropped: `runs[2].positions[0]` → `runs[].positions[]`.
fn pattern(key: &str) -> String {
    let mut out = String::with_capacity(key.len());
    let mut in_index = false;
    for c in key.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push(c);
            }
            ']' => {
                in_index = false;
                out.push(c);
            }
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal(text: &str) -> (i32, String) {
        let e = parse(Path::new("dir/data.json"), text).unwrap_err();
        (e.exit_code(), e.to_string())
    }

    /// NaN and infinities (as Python writes them) are named with line, column and key,
    /// inside strings they are text; a null at a numeric key is refused, elsewhere kept.
    #[test]
    fn non_finite_literals_and_nulls_are_named() {
        let text = "{\"a\": \"NaN\",\n \"runs\": [{\"dt_sample\": 1}, {\"dt_sample\": NaN}]}";
        let (code, e) = refusal(text);
        assert_eq!(code, 2);
        assert!(
            e.contains("dir/data.json")
                && e.contains("`runs[1].dt_sample`")
                && e.contains("NaN at line 2, column 43")
                && e.contains("allow_nan=False"),
            "{e}"
        );
        let (_, e) = refusal("{\"filament\": {\"kt\": -Infinity, \"drag\": Infinity}}");
        assert!(
            e.contains("`filament.kt`") && e.contains("-Infinity at line 1"),
            "{e}"
        );
        let (_, e) = refusal("{\"x\": [1, inf");
        assert!(
            e.contains("key `-`") && e.contains("inf at line 1, column 11"),
            "{e}"
        );
        let (_, e) = refusal("{\"x\": [1, 2");
        assert!(e.contains("not a langevin-fem-trajectories sidecar"), "{e}");
        let (code, e) = refusal("{\"runs\": [{\"positions\": [0.5, null]}]}");
        assert_eq!(code, 2);
        assert!(
            e.contains("`runs[0].positions[1]`") && e.contains("must be a number, got null"),
            "{e}"
        );
        let (_, e) = refusal("{\"runs\": [{\"discretization\": {\"dt\": null}}]}");
        assert!(e.contains("`runs[0].discretization.dt`"), "{e}");
        let ok = "{\"provenance\": {\"seed\": null}, \"runs\": [{\"discretization\": {\"noise\": null}}]}";
        assert!(parse(Path::new("d.json"), ok).is_ok());
    }

    #[test]
    fn keys_drop_their_indices() {
        assert_eq!(pattern("runs[12].positions[0]"), "runs[].positions[]");
        assert_eq!(pattern("dims"), "dims");
        assert_eq!(line_column("ab\ncdé f", 9), (2, 6));
    }
}
