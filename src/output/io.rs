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
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes).map_err(|e| Error::io(path, e))?;
    file.commit()
}

/// A file written by streaming and made visible atomically: the bytes go to a temporary
/// file in the destination directory, `.<name>.tmp.<pid>.<n>` (so
/// [`remove_stale_temporaries`] removes it after an interruption), and
/// [`AtomicFile::commit`] syncs it and renames it over the destination. Dropped without
/// a commit, the temporary file is removed.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    temp: PathBuf,
    file: Option<io::BufWriter<File>>,
}

impl AtomicFile {
    /// Creates the temporary file of `path` (and missing parent directories).
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` if the directory or the file cannot be created.
    pub fn create(path: &Path) -> Result<AtomicFile> {
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
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(|e| Error::io(path, e))?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            temp,
            file: Some(io::BufWriter::with_capacity(1 << 16, file)),
        })
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file over its destination.
    ///
    /// # Errors
    /// [`Error::Io`] naming the destination.
    pub fn commit(mut self) -> Result<()> {
        let file = self.file.take().expect("an AtomicFile commits once");
        let result = file
            .into_inner()
            .map_err(io::IntoInnerError::into_error)
            .and_then(|f| f.sync_all())
            .and_then(|()| fs::rename(&self.temp, &self.path));
        if let Err(e) = result {
            let _ = fs::remove_file(&self.temp);
            return Err(Error::io(&self.path, e));
        }
        if let Some(dir) = self.path.parent() {
            sync_dir(if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            });
        }
        Ok(())
    }
}

impl io::Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file.as_mut().map_or(Ok(0), |f| f.write(buf))
    }
    fn flush(&mut self) -> io::Result<()> {
        self.file.as_mut().map_or(Ok(()), io::Write::flush)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = fs::remove_file(&self.temp);
        }
    }
}

/// Removes the temporary files that interrupted runs left in `dir` and its
/// subdirectories (two levels down): files named like those of [`write_atomic`],
/// `.<name>.tmp.<pid>.<n>`, and staging directories ([`super::staging`],
/// `.langevin-fem-staging.<pid>.<n>`, each counted as one), whose process is gone (on Linux: no `/proc/<pid>`; elsewhere:
/// older than a day). Files of this process and of running processes are kept. Returns
/// the number removed; errors are ignored (best effort, like the files themselves).
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    fn walk(dir: &Path, depth: usize, removed: &mut usize) {
        let Ok(entries) = fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            let name = entry.file_name();
            if kind.is_dir() && super::staging::is_stale_staging(&name.to_string_lossy()) {
                if fs::remove_dir_all(&path).is_ok() {
                    *removed += 1;
                }
            } else if kind.is_dir() && depth > 0 {
                walk(&path, depth - 1, removed);
            } else if kind.is_file() && is_stale_temporary(&path) && fs::remove_file(&path).is_ok()
            {
                *removed += 1;
            }
        }
    }
    let mut removed = 0;
    walk(dir, 2, &mut removed);
    removed
}

/// Whether `path` is a temporary file of [`write_atomic`] whose writer is gone.
fn is_stale_temporary(path: &Path) -> bool {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let mut parts = name.rsplitn(4, '.');
    let (Some(n), Some(pid), Some("tmp"), Some(rest)) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return false;
    };
    let (Ok(_), Ok(pid)) = (n.parse::<u64>(), pid.parse::<u32>()) else {
        return false;
    };
    if !rest.starts_with('.') || rest.len() < 2 || pid == std::process::id() {
        return false;
    }
    let proc_dir = Path::new("/proc");
    if proc_dir.is_dir() {
        !proc_dir.join(pid.to_string()).exists()
    } else {
        fs::metadata(path)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age.as_secs() > 86_400)
    }
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
    write_atomic(path, csv_text(path, header, rows)?.as_bytes())
}

/// The text [`write_csv`] writes to `path` (named in its errors).
///
/// # Errors
/// As [`write_csv`], apart from writing.
pub(crate) fn csv_text(path: &Path, header: &[&str], rows: &[Vec<f64>]) -> Result<String> {
    let mut table = CsvWriter::new(Vec::new(), path, header)?;
    for row in rows {
        table.numbers(row)?;
    }
    table.into_string()
}

/// A CSV table written record by record with the `csv` crate, the one CSV writer of
/// every table this program writes: fields holding a comma, quote or line break are
/// quoted and their quotes doubled (RFC 4180), other fields are written as they are;
/// lines end in `\n`; every record has as many fields as the header. Numbers are written
/// as [`write_csv`] describes ([`CsvWriter::numbers`], [`csv_number`]).
pub struct CsvWriter<W: io::Write> {
    inner: csv::Writer<W>,
    path: PathBuf,
    columns: usize,
    rows: usize,
    field: String,
}

impl<W: io::Write> std::fmt::Debug for CsvWriter<W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvWriter")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

impl<W: io::Write> CsvWriter<W> {
    /// Starts the table of file `path` (named in errors) on `out` with its `header`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the header is empty; [`Error::Io`] naming `path` if
    /// writing fails.
    pub fn new(out: W, path: &Path, header: &[&str]) -> Result<Self> {
        if header.is_empty() {
            return Err(Error::invalid(
                format!("CSV header of {}", path.display()),
                "an empty list",
                "at least one column",
            ));
        }
        let mut table = CsvWriter {
            inner: csv::WriterBuilder::new()
                .terminator(csv::Terminator::Any(b'\n'))
                .from_writer(out),
            path: path.to_path_buf(),
            columns: header.len(),
            rows: 0,
            field: String::new(),
        };
        let written = table.inner.write_record(header);
        written.map_err(|e| table.error(e))?;
        Ok(table)
    }

    /// Appends one record of text fields, as many as the header's.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the row (counted from 0 after the header) for a
    /// record of another length, nothing of which is written then; [`Error::Io`] naming
    /// the path if writing fails.
    pub fn record<I, T>(&mut self, fields: I) -> Result<()>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<str>,
    {
        let fields: Vec<T> = fields.into_iter().collect();
        self.check_length(fields.len())?;
        let written = self
            .inner
            .write_record(fields.iter().map(|f| f.as_ref().as_bytes()));
        written.map_err(|e| self.error(e))
    }

    /// Appends one record of numbers, as many as the header's, each with round-trip
    /// precision (see [`write_csv`]).
    ///
    /// # Errors
    /// As [`Self::record`].
    pub fn numbers(&mut self, row: &[f64]) -> Result<()> {
        self.check_length(row.len())?;
        let mut written = Ok(());
        for &v in row {
            self.field.clear();
            push_csv_number(&mut self.field, v);
            written = self.inner.write_field(&self.field);
            if written.is_err() {
                break;
            }
        }
        if written.is_ok() {
            written = self.inner.write_record(None::<&[u8]>);
        }
        written.map_err(|e| self.error(e))
    }

    fn check_length(&mut self, len: usize) -> Result<()> {
        if len != self.columns {
            return Err(Error::invalid(
                format!(
                    "length of row {} of CSV table {}",
                    self.rows,
                    self.path.display()
                ),
                len,
                format!("{} (the number of header columns)", self.columns),
            ));
        }
        self.rows += 1;
        Ok(())
    }

    /// Flushes the table and returns the writer it was written to.
    ///
    /// # Errors
    /// [`Error::Io`] naming the path if flushing fails.
    pub fn into_inner(self) -> Result<W> {
        let path = self.path;
        self.inner.into_inner().map_err(|e| {
            Error::io(
                path,
                io::Error::new(e.error().kind(), e.error().to_string()),
            )
        })
    }

    fn error(&self, e: csv::Error) -> Error {
        let source = match e.into_kind() {
            csv::ErrorKind::Io(e) => e,
            other => io::Error::other(format!("{other:?}")),
        };
        Error::io(&self.path, source)
    }
}

impl CsvWriter<Vec<u8>> {
    /// The finished table as text.
    ///
    /// # Errors
    /// As [`Self::into_inner`]; [`Error::Io`] naming the path if a field was not UTF-8.
    pub fn into_string(self) -> Result<String> {
        let path = self.path.clone();
        String::from_utf8(self.into_inner()?).map_err(|e| Error::io(path, io::Error::other(e)))
    }
}

/// `v` with round-trip precision, as [`write_csv`] writes it; `None` as an empty field.
pub fn csv_number(v: impl Into<Option<f64>>) -> String {
    let mut out = String::new();
    if let Some(v) = v.into() {
        push_csv_number(&mut out, v);
    }
    out
}

/// Appends `v` with round-trip precision (see [`write_csv`]).
pub(crate) fn push_csv_number(out: &mut String, v: f64) {
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
    write_atomic(path, json_text(path, value)?.as_bytes())
}

/// The text [`write_json`] writes to `path` (named in its errors).
///
/// # Errors
/// [`Error::Io`] naming `path` if serialization fails.
pub(crate) fn json_text<T: serde::Serialize>(path: &Path, value: &T) -> Result<String> {
    let mut text = serde_json::to_string_pretty(value).map_err(|e| Error::io(path, e.into()))?;
    text.push('\n');
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one CSV writer: text quoted only where RFC 4180 needs it (a comma, a quote,
    /// a line break), quotes doubled, numbers as `write_csv` documents, `\n` line ends,
    /// and a record of the wrong length refused without writing any of it.
    #[test]
    fn csv_writer_quotes_only_where_needed() {
        let path = Path::new("t.csv");
        let mut t = CsvWriter::new(Vec::new(), path, &["name", "a,b", "x"]).unwrap();
        t.record(["plain", "say \"hi\"", "two\nlines"]).unwrap();
        t.numbers(&[1e-7, 0.5, f64::NEG_INFINITY]).unwrap();
        let e = t.record(["one", "two"]).unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("t.csv"), "{e}");
        assert!(t.numbers(&[1.0]).is_err());
        t.record(["", &csv_number(None), &csv_number(2.0)]).unwrap();
        assert_eq!(
            t.into_string().unwrap(),
            "name,\"a,b\",x\nplain,\"say \"\"hi\"\"\",\"two\nlines\"\n1e-7,0.5,-inf\n,,2\n"
        );
        assert!(CsvWriter::new(Vec::new(), path, &[]).is_err());
    }

    /// Stale temporaries of a dead process are removed, down to two directory levels;
    /// this process's, other names and deeper files are kept.
    #[test]
    fn stale_temporaries_are_removed() {
        let root = std::env::temp_dir().join(format!("lfem-stale-{}", std::process::id()));
        let sub = root.join("scene");
        fs::create_dir_all(&sub).unwrap();
        let dead = 4_000_000_000u32; // above any Linux pid_max
        let stale = [
            root.join(format!(".summary.json.tmp.{dead}.0")),
            sub.join(format!(".force-strain.csv.tmp.{dead}.17")),
        ];
        let kept = [
            root.join(format!(".summary.json.tmp.{}.3", std::process::id())),
            root.join("summary.json"),
            root.join(".summary.json.tmp.x.0"),
        ];
        for p in stale.iter().chain(&kept) {
            fs::write(p, b"x").unwrap();
        }
        if Path::new("/proc").is_dir() {
            assert_eq!(remove_stale_temporaries(&root), 2);
            assert!(stale.iter().all(|p| !p.exists()));
        }
        assert!(kept.iter().all(|p| p.exists()));
        fs::remove_dir_all(&root).unwrap();
    }
}
