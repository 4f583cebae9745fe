//! Atomic file output: raw bytes, CSV tables and JSON documents.
//!
//! Every writer goes through [`write_atomic`]: the content is written to a temporary file
//! in the destination directory, flushed to disk and renamed over the destination, so a
//! reader (or an interrupted run) never sees a half-written report file.

use std::fmt::Write as _;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Distinguishes temporary files of concurrent writers within one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically.
///
/// Missing parent directories are created. The bytes are written to a temporary file in
/// the same directory (`.<name>.tmp.<pid>.<n>`), synced to disk and renamed over `path`,
/// which replaces any existing file. On failure the temporary file is removed.
///
/// # Errors
/// [`Error::Io`] naming `path` if a directory cannot be created or the file cannot be
/// written or renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let file_name = path.file_name().ok_or_else(|| {
        Error::io(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
        )
    })?;
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;

    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(file_name);
    temp_name.push(format!(".tmp.{}.{n}", std::process::id()));
    let temp = dir.join(temp_name);

    let result = write_and_sync(&temp, bytes).and_then(|()| fs::rename(&temp, path));
    if let Err(e) = result {
        let _ = fs::remove_file(&temp);
        return Err(Error::io(path, e));
    }
    sync_dir(&dir);
    Ok(())
}

fn write_and_sync(temp: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = OpenOptions::new().write(true).create_new(true).open(temp)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// Makes the rename durable where the platform allows it (best effort: a failure here
/// does not affect the content of the file that was written).
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Writes a CSV table atomically: one header line, then one line per row.
///
/// Numbers are printed with full round-trip precision (the shortest representation that
/// parses back to the same `f64`): plain decimal notation for magnitudes in
/// `[1e-4, 1e15)` and zero, scientific notation (`1.25e-7`) otherwise. Non-finite values
/// are written as `nan`, `inf` and `-inf`; all of them parse back with `str::parse::<f64>`.
/// Header fields containing a comma, quote or line break are quoted as in RFC 4180.
///
/// # Errors
/// [`Error::InvalidParameter`] if the header is empty or a row's length differs from the
/// header's (nothing is written then); [`Error::Io`] naming `path` if writing fails.
pub fn write_csv(path: &Path, header: &[&str], rows: &[Vec<f64>]) -> Result<()> {
    if header.is_empty() {
        return Err(Error::invalid(
            format!("CSV header of {}", path.display()),
            "an empty list",
            "at least one column",
        ));
    }
    if let Some((i, row)) = rows
        .iter()
        .enumerate()
        .find(|(_, row)| row.len() != header.len())
    {
        return Err(Error::invalid(
            format!("length of row {i} of CSV table {}", path.display()),
            row.len(),
            format!("{} (the number of header columns)", header.len()),
        ));
    }

    let mut out = String::with_capacity(16 * header.len() * (rows.len() + 1));
    for (j, name) in header.iter().enumerate() {
        if j > 0 {
            out.push(',');
        }
        push_csv_field(&mut out, name);
    }
    out.push('\n');
    for row in rows {
        for (j, &v) in row.iter().enumerate() {
            if j > 0 {
                out.push(',');
            }
            push_csv_number(&mut out, v);
        }
        out.push('\n');
    }
    write_atomic(path, out.as_bytes())
}

fn push_csv_field(out: &mut String, field: &str) {
    if field.contains([',', '"', '\n', '\r']) {
        out.push('"');
        out.push_str(&field.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(field);
    }
}

/// Appends `v` with round-trip precision (see [`write_csv`]).
fn push_csv_number(out: &mut String, v: f64) {
    if v.is_nan() {
        out.push_str("nan");
    } else if v.is_infinite() {
        out.push_str(if v > 0.0 { "inf" } else { "-inf" });
    } else if v == 0.0 || (1e-4..1e15).contains(&v.abs()) {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// Writes `value` as pretty-printed JSON with a trailing newline, atomically.
///
/// Note that `serde_json` writes non-finite floating-point numbers as `null`.
///
/// # Errors
/// [`Error::Io`] naming `path` if serialization or writing fails.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| Error::io(path, e.into()))?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}
