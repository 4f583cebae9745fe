//! Domain-free input: every file a command reads as data (a data directory's sidecar and
//! trajectory files, shard manifests and records, a `--plan-from` shard) is opened here,
//! so that a damaged or hostile file is refused as input (exit 2) and never blocks, never
//! sizes an allocation by a number it claims, and is never written to.
//!
//! - Only **regular files** are read. A file is opened without blocking
//!   (`O_NONBLOCK` on Linux, so that opening a FIFO returns at once) and its type is then
//!   taken from the open handle: a FIFO, socket, device or directory is refused, naming
//!   the path. A symbolic link is followed (reading through it harms nothing); what it
//!   points to must be a regular file.
//! - Every read is **capped** before it starts: the caller states the largest size it
//!   accepts, and a larger file is refused with its size and the cap, never read.
//! - **Text** is UTF-8; a UTF-8 byte-order mark (as some Windows editors and Excel write)
//!   is accepted and dropped ([`read_text`]).
//!
//! Errors are [`Error::Scene`] naming the file, the key that led to it (e.g.
//! `runs[0].files[3]`) and what is wrong, so the message says what to fix.

use std::fs::{File, OpenOptions};
use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The largest metadata file (a sidecar, a shard manifest) read whole: 256 MiB.
pub const MAX_METADATA_BYTES: u64 = 256 << 20;

/// The error of input file `path` at `key`: `message` says what is wrong and what is
/// allowed.
pub fn refused(path: &Path, key: &str, message: impl Into<String>) -> Error {
    Error::Scene {
        file: path.to_path_buf(),
        key: key.to_string(),
        message: message.into(),
    }
}

/// Opens `path` for reading as a regular file (see the [module docs](self)); returns the
/// handle and the file's size in bytes. `key` names what led to the file in the
/// messages.
///
/// # Errors
/// [`Error::Scene`] naming `path` and `key` if it does not exist, cannot be opened or is
/// not a regular file (a directory, FIFO, socket or device).
pub fn open_regular(path: &Path, key: &str) -> Result<(File, u64)> {
    let mut options = OpenOptions::new();
    options.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // O_NONBLOCK: opening a FIFO without a writer returns at once instead of blocking.
        options.custom_flags(0o4000);
    }
    let file = options
        .open(path)
        .map_err(|e| refused(path, key, format!("cannot be opened: {e}")))?;
    let meta = file
        .metadata()
        .map_err(|e| refused(path, key, format!("cannot be read: {e}")))?;
    if !meta.is_file() {
        return Err(refused(
            path,
            key,
            format!(
                "must be a regular file, but it is {}",
                kind_of(&meta.file_type())
            ),
        ));
    }
    Ok((file, meta.len()))
}

/// What a file type is, in words.
fn kind_of(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "not a regular file"
    }
}

/// Reads the regular file `path` whole, refusing it unread if it is larger than
/// `max_bytes` (`key` names what led to it).
///
/// # Errors
/// As [`open_regular`]; [`Error::Scene`] if the file is larger than `max_bytes` or a read
/// fails.
pub fn read_bytes(path: &Path, key: &str, max_bytes: u64) -> Result<Vec<u8>> {
    let (file, len) = open_regular(path, key)?;
    if len > max_bytes {
        return Err(refused(
            path,
            key,
            format!(
                "is {len} bytes, more than the {max_bytes} bytes this file may hold ({})",
                human_bytes(max_bytes)
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    // `take`: a file that grows while it is read still stops at the cap.
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| refused(path, key, format!("cannot be read: {e}")))?;
    if bytes.len() as u64 > max_bytes {
        return Err(refused(
            path,
            key,
            format!("grew beyond {max_bytes} bytes while it was read"),
        ));
    }
    Ok(bytes)
}

/// Reads the regular file `path` whole as UTF-8 text (a leading byte-order mark
/// dropped), refusing it unread above `max_bytes`.
///
/// # Errors
/// As [`read_bytes`]; [`Error::Scene`] if the bytes are not UTF-8 (naming the offset).
pub fn read_text(path: &Path, key: &str, max_bytes: u64) -> Result<String> {
    let bytes = read_bytes(path, key, max_bytes)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        refused(
            path,
            key,
            format!(
                "must be UTF-8 text, but byte {} is not ({e})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// Parses `text`, read from `path`, as JSON of type `T` (`what` names the kind of file in
/// messages, e.g. `a shard manifest`). A refusal names the key where the parser stopped
/// (`runs[0].dt_sample`, as serde_path_to_error tracks it; `-` at the top), the line and
/// column, and what is wrong; the literals `NaN`, `Infinity`, `inf` and their signed
/// forms (which Python's `json.dump` and other writers emit for non-finite floats, but
/// which are not JSON) are named as such, with how to avoid them, and `null` where a value
/// is required is named as a missing value. (`null` at an optional key reads as the key
/// left out.)
///
/// # Errors
/// [`Error::Scene`] naming `path` and the key.
pub fn parse_json<T: serde::de::DeserializeOwned>(
    path: &Path,
    text: &str,
    what: &str,
) -> Result<T> {
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed: std::result::Result<T, _> = serde_path_to_error::deserialize(&mut de);
    let value = parsed.map_err(|e| {
        let at = match e.path().to_string() {
            p if p == "." => String::new(),
            p => p,
        };
        let inner = e.inner();
        let (line, column) = (inner.line(), inner.column());
        let said = inner.to_string();
        // A missing field is named with its parent's path: name the field. An unknown
        // field's path already ends with it (serde_path_to_error has entered the key).
        let field = ["missing field `", "unknown field `"]
            .iter()
            .find_map(|p| said.strip_prefix(p))
            .and_then(|rest| rest.split('`').next());
        let key = match (at.as_str(), field) {
            ("", None) => "-".to_string(),
            ("", Some(f)) => f.to_string(),
            (p, Some(f)) if p == f || p.ends_with(&format!(".{f}")) => p.to_string(),
            (p, Some(f)) => format!("{p}.{f}"),
            (p, None) => p.to_string(),
        };
        let message = if let Some(literal) = non_json_literal(text, line, column) {
            format!(
                "{literal} at line {line}, column {column} is not JSON (JSON has no NaN or infinity): write finite numbers (in Python, json.dump(..., allow_nan=False) raises on them instead of writing them)"
            )
        } else if said.starts_with("invalid type: null") {
            format!(
                "must be given, got null at line {line}, column {column} (JSON null stands for a missing value: give the value, or leave an optional key out)"
            )
        } else if field.is_none() && !at.is_empty() {
            let got = number_before(text, line, column)
                .or_else(|| value_at(text, &at))
                .map_or(String::new(), |v| format!(" (got {v})"));
            format!("not {what}: {said}{got}")
        } else {
            format!("not {what}: {said}")
        };
        refused(path, &key, message)
    })?;
    de.end()
        .map_err(|e| refused(path, "-", format!("not {what}: {e}")))?;
    Ok(value)
}

/// The value at `path` (`runs[0].dt_sample`) of `text`, if the text is JSON, as JSON text
/// (at most 80 characters).
fn value_at(text: &str, path: &str) -> Option<String> {
    let mut v: &serde_json::Value = &serde_json::from_str(text).ok()?;
    for part in path.split('.') {
        let (name, indices) = part.split_once('[').map_or((part, ""), |(n, i)| (n, i));
        if !name.is_empty() {
            v = v.get(name)?;
        }
        for i in indices.split('[') {
            if let Some(i) = i.strip_suffix(']') {
                v = v.get(i.parse::<usize>().ok()?)?;
            }
        }
    }
    let owned = v.to_string();
    let mut shown: String = owned.chars().take(80).collect();
    if shown.len() < owned.len() {
        shown.push('…');
    }
    let kind = match v {
        serde_json::Value::Array(_) => "an array ",
        serde_json::Value::Object(_) => "an object ",
        serde_json::Value::String(_) => "a string ",
        _ => "",
    };
    Some(format!("{kind}{shown}"))
}

/// The number written just before (`line`, `column`) of `text` (where serde_json stops on
/// a number out of range), if any.
fn number_before(text: &str, line: usize, column: usize) -> Option<String> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let end = column.min(row.len());
    let head = row.get(..end)?;
    let start = head
        .rfind(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
        .map_or(0, |i| i + 1);
    let number = &head[start..];
    (!number.is_empty()).then(|| crate::error::shown_value(number))
}

/// The literals some writers put in JSON for non-finite floats, longest first (matched
/// ignoring case).
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

/// The non-JSON literal (`NaN`, `Infinity`, `-inf`, …, as written) at which the parser
/// stopped, at (`line`, `column`) of `text` (1-based, as serde_json reports them: on the
/// literal's first character, or just after a sign), if any.
fn non_json_literal(text: &str, line: usize, column: usize) -> Option<&str> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let at = column.saturating_sub(1).min(row.len());
    // Back to the start of the token: after a separator or at the line's start.
    let start = row
        .get(..=at.min(row.len().saturating_sub(1)))?
        .rfind([' ', ':', '[', ',', '\t'])
        .map_or(0, |i| i + 1);
    let rest = row.get(start..)?.trim_start();
    NON_FINITE
        .into_iter()
        .find(|l| {
            rest.get(..l.len())
                .is_some_and(|head| head.eq_ignore_ascii_case(l))
        })
        .map(|l| &rest[..l.len()])
}

/// Refuses an output directory `out` (`--out`) that is the input directory `input`
/// (given by `input_flag`, e.g. `--data`), holds it or lies inside it: the command would
/// write its output among its own input (issue #25: the input is left exactly as it was,
/// nothing added, replaced or removed).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `--out`, both directories and the flag.
pub fn refuse_input_in_output(out: &Path, input: &Path, input_flag: &str) -> Result<()> {
    let (o, i) = (resolved(out), resolved(input));
    let relation = if i == o {
        "is"
    } else if i.starts_with(&o) {
        "holds"
    } else if o.starts_with(&i) {
        "lies inside"
    } else {
        return Ok(());
    };
    Err(Error::invalid(
        "--out",
        out.display(),
        format!(
            "a directory apart from the input: it {relation} the input directory {} given by {input_flag}, which is left exactly as it was; choose an output directory outside it",
            input.display()
        ),
    ))
}

/// `path` made absolute with its existing part's symbolic links resolved (the rest, not
/// yet created, appended as given).
fn resolved(path: &Path) -> std::path::PathBuf {
    let mut missing = Vec::new();
    let mut p = path.to_path_buf();
    loop {
        if let Ok(c) = p.canonicalize() {
            return missing.iter().rev().fold(c, |acc, m| acc.join(m));
        }
        match (p.file_name().map(|n| n.to_os_string()), p.parent()) {
            (Some(name), Some(parent)) => {
                missing.push(name);
                p = if parent.as_os_str().is_empty() {
                    std::path::PathBuf::from(".")
                } else {
                    parent.to_path_buf()
                };
            }
            _ => return path.to_path_buf(),
        }
    }
}

/// `bytes` in words: `4.0 GiB`, `256 MiB`, `12 kiB`, `100 bytes`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("kiB", 1 << 10)];
    for (unit, size) in UNITS {
        if bytes >= size {
            let v = bytes as f64 / size as f64;
            return if v.fract() == 0.0 {
                format!("{v:.0} {unit}")
            } else {
                format!("{v:.1} {unit}")
            };
        }
    }
    format!("{bytes} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("lfem-input-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Regular files are read (a byte-order mark dropped from text); directories,
    /// missing files and files above the cap are refused naming the path and the key.
    #[test]
    fn reads_regular_files_and_refuses_the_rest() {
        let d = dir("regular");
        let f = d.join("a.json");
        std::fs::write(&f, "\u{feff}{}").unwrap();
        assert_eq!(read_text(&f, "k", 100).unwrap(), "{}");
        assert_eq!(read_bytes(&f, "k", 5).unwrap().len(), 5);
        // No cap at all: the whole file (the cap + 1 of `take` must not wrap to 0).
        assert_eq!(read_bytes(&f, "k", u64::MAX).unwrap().len(), 5);
        let e = read_bytes(&f, "runs[0]", 4).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let text = e.to_string();
        assert!(text.contains("a.json") && text.contains("runs[0]") && text.contains("5 bytes"));
        let e = read_bytes(&d, "k", 100).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = read_bytes(&d.join("missing"), "k", 100).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
        std::fs::write(&f, [0x66, 0xff, 0x66]).unwrap();
        let e = read_text(&f, "k", 100).unwrap_err().to_string();
        assert!(e.contains("UTF-8") && e.contains("byte 1"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A FIFO is refused at once (opening does not wait for a writer), and a symbolic
    /// link to a regular file is followed.
    #[cfg(target_os = "linux")]
    #[test]
    fn fifos_are_refused_without_blocking_and_links_followed() {
        let d = dir("fifo");
        let fifo = d.join("data.json");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if made {
            let start = std::time::Instant::now();
            let e = read_text(&fifo, "-", 100).unwrap_err().to_string();
            assert!(e.contains("FIFO"), "{e}");
            assert!(start.elapsed().as_secs() < 5);
        }
        let target = d.join("t.csv");
        std::fs::write(&target, "t\n0\n").unwrap();
        let link = d.join("l.csv");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert_eq!(read_text(&link, "-", 100).unwrap(), "t\n0\n");
        let dev = read_bytes(Path::new("/dev/zero"), "-", 100).unwrap_err();
        assert!(dev.to_string().contains("device"), "{dev}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// The output may not be the input directory, hold it or lie inside it.
    #[test]
    fn output_apart_from_input() {
        let d = dir("overlap");
        let data = d.join("data");
        std::fs::create_dir_all(&data).unwrap();
        for out in [data.clone(), d.clone(), data.join("..")] {
            let e = refuse_input_in_output(&out, &data, "--data").unwrap_err();
            assert_eq!(e.exit_code(), 2);
            assert!(e.to_string().contains("--data"), "{e}");
        }
        let e = refuse_input_in_output(&data.join("report"), &data, "--data").unwrap_err();
        assert!(e.to_string().contains("lies inside"), "{e}");
        refuse_input_in_output(&d.join("report/new"), &data, "--data").unwrap();
        refuse_input_in_output(&d.join("data-report"), &data, "--data").unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// JSON refusals name the key path, and NaN or Infinity literals as such.
    #[test]
    fn json_errors_name_the_key_and_non_json_literals() {
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct Run {
            dt: f64,
        }
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct Top {
            runs: Vec<Run>,
        }
        let p = Path::new("d/data.json");
        let ok: Top = parse_json(p, "{\"runs\": [{\"dt\": 1.5}]}", "a sidecar").unwrap();
        assert_eq!(ok.runs.len(), 1);
        for (text, key, says) in [
            (
                "{\"runs\": [{\"dt\": \"x\"}]}",
                "runs[0].dt",
                "invalid type",
            ),
            ("{\"runs\": [{\"dt\": null}]}", "runs[0].dt", "got null"),
            ("{\"runs\": [{\"dt\": nan}]}", "runs[0].dt", "nan at line 1"),
            (
                "{\"runs\": [{\"dt\": +inf}]}",
                "runs[0].dt",
                "+inf at line 1",
            ),
            ("{\"runs\": [{\"dt\": NaN}]}", "runs[0].dt", "NaN at line 1"),
            (
                "{\"runs\": [{\"dt\": -Infinity}]}",
                "runs[0].dt",
                "-Infinity at line 1",
            ),
            (
                "{\"runs\": [\n  {\"dt\": Infinity}]}",
                "runs[0].dt",
                "Infinity at line 2",
            ),
            ("{\"runs\": []} x", "-", "trailing"),
            ("{\"runs\": [{}]}", "runs[0].dt", "missing field"),
            // An unknown key is named once (its path already ends with it).
            (
                "{\"runs\": [{\"dt\": 1, \"dtt\": 2}]}",
                "runs[0].dtt",
                "unknown field",
            ),
            ("{\"runs\": [], \"run\": 2}", "run", "unknown field"),
            (
                "{\"runs\": [{\"dt\": [1, 2]}]}",
                "runs[0].dt",
                "(got an array [1,2])",
            ),
            ("{\"runs\": [{\"dt\": 1e999}]}", "runs[0].dt", "(got 1e999)"),
        ] {
            let e = parse_json::<Top>(p, text, "a sidecar").unwrap_err();
            assert_eq!(e.exit_code(), 2);
            let m = e.to_string();
            assert!(
                m.contains(&format!("key `{key}`")) && m.contains(says),
                "{text}: {m}"
            );
        }
    }

    #[test]
    fn bytes_in_words() {
        assert_eq!(human_bytes(100), "100 bytes");
        assert_eq!(human_bytes(256 << 20), "256 MiB");
        assert_eq!(human_bytes(3 << 29), "1.5 GiB");
    }
}
