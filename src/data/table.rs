//! Trajectory files: one table of float64 columns per trajectory, CSV or `.npy`
//! (see the [format](super)), written by streaming and read whole.

use super::npy::{NpyWriter, npy_error, parse_npy};
use crate::error::{Error, Result};
use crate::input::{read_bytes, refused};
use crate::output::AtomicFile;
use crate::output::io::CsvWriter;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A trajectory file being written row by row; the format follows the extension
/// (`.csv` or `.npy`). Nothing is visible at the path before [`Self::commit`].
#[derive(Debug)]
pub struct TrajectoryFile {
    path: PathBuf,
    out: Writer,
    columns: usize,
}

#[derive(Debug)]
enum Writer {
    Csv(Box<CsvWriter<AtomicFile>>),
    Npy(NpyWriter<AtomicFile>),
}

impl TrajectoryFile {
    /// Starts the file `path` with `columns` and, for `.npy`, exactly `rows` rows.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for another extension; [`Error::Io`] naming the path.
    pub fn create(path: &Path, columns: &[String], rows: u64) -> Result<TrajectoryFile> {
        let io_err = |e: std::io::Error| Error::io(path, e);
        let file = AtomicFile::create(path)?;
        let out = match path.extension().and_then(|e| e.to_str()) {
            Some("csv") => {
                let header: Vec<&str> = columns.iter().map(String::as_str).collect();
                Writer::Csv(Box::new(CsvWriter::new(file, path, &header)?))
            }
            Some("npy") => Writer::Npy(NpyWriter::new(file, rows, columns.len()).map_err(io_err)?),
            _ => {
                return Err(Error::invalid(
                    "trajectory file",
                    path.display(),
                    "a name ending in .csv or .npy",
                ));
            }
        };
        Ok(TrajectoryFile {
            path: path.to_path_buf(),
            out,
            columns: columns.len(),
        })
    }

    /// Appends one row (one value per column).
    ///
    /// # Errors
    /// [`Error::Io`] naming the path (a row of the wrong length included).
    pub fn push_row(&mut self, row: &[f64]) -> Result<()> {
        let io_err = |e: std::io::Error| Error::io(&self.path, e);
        match &mut self.out {
            Writer::Csv(_) if row.len() != self.columns => Err(io_err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("row of {} values for {} columns", row.len(), self.columns),
            ))),
            Writer::Csv(table) => table.numbers(row),
            Writer::Npy(w) => w.push_row(row).map_err(io_err),
        }
    }

    /// Completes the file and makes it visible at its path.
    ///
    /// # Errors
    /// [`Error::Io`] naming the path (for `.npy`, rows missing included).
    pub fn commit(self) -> Result<()> {
        let file = match self.out {
            Writer::Csv(table) => table.into_inner()?,
            Writer::Npy(w) => w.finish().map_err(|e| Error::io(&self.path, e))?,
        };
        file.commit()
    }
}

/// A trajectory read whole: named columns, row-major values.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Column names, in the order asked for.
    pub columns: Vec<String>,
    /// Number of rows.
    pub rows: usize,
    /// Values, row-major: `values[r * columns.len() + c]`.
    pub values: Vec<f64>,
}

impl Table {
    /// Column `c` as a vector.
    pub fn column(&self, c: usize) -> Vec<f64> {
        let n = self.columns.len();
        (0..self.rows).map(|r| self.values[r * n + c]).collect()
    }

    /// The value at row `r`, column `c`.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        self.values[r * self.columns.len() + c]
    }
}

/// The column names for a message: all of them up to 16, else the first 12, "…" and
/// the last 3 (with the count), so that a wide sidecar does not fill the terminal.
fn column_list(columns: &[String]) -> String {
    if columns.len() <= 16 {
        return columns.join(", ");
    }
    format!(
        "{}, … {} more …, {}",
        columns[..12].join(", "),
        columns.len() - 15,
        columns[columns.len() - 3..].join(", ")
    )
}

/// Reads trajectory file `path` (listed at sidecar key `key`, e.g. `runs[0].files[3]`)
/// and returns its `columns`, in that order. The file is read as a regular file of at
/// most `max_bytes` ([`crate::input::read_bytes`]). A CSV file maps its header names to
/// `columns` (any order; other columns ignored, a column of `columns` named twice
/// refused); it is read as RFC 4180 text with the `csv` crate (quoted fields, `\r\n`
/// line ends and a UTF-8 byte-order mark accepted, fields trimmed, blank lines skipped).
/// A `.npy` file must have exactly these columns, in this order. Every value read must
/// be finite, and the file must hold at least one data row.
///
/// # Errors
/// [`Error::Scene`] naming the file and `key`: unreadable, not a regular file, larger
/// than `max_bytes`, no data rows, a missing or doubled column, a field that is not a
/// finite number (with its column, data row, counted from 1, and value).
pub fn read_table(path: &Path, key: &str, columns: &[String], max_bytes: u64) -> Result<Table> {
    let bytes = read_bytes(path, key, max_bytes)?;
    let bad = |what: String| refused(path, key, what);
    if bytes.is_empty() {
        return Err(bad("has no data rows (the file is empty, 0 bytes)".into()));
    }
    let table = if path.extension().is_some_and(|e| e == "npy") {
        let (rows, cols, values) = parse_npy(&bytes).map_err(|why| npy_error(path, key, &why))?;
        if cols != columns.len() {
            return Err(bad(format!(
                "must have {} columns ({}), as the sidecar implies; the file has {cols}",
                columns.len(),
                column_list(columns)
            )));
        }
        Table {
            columns: columns.to_vec(),
            rows,
            values,
        }
    } else {
        csv_table(&bytes, columns, max_bytes).map_err(bad)?
    };
    if table.rows == 0 {
        return Err(bad(format!(
            "has no data rows (its columns {} are there, no row of values)",
            columns.join(", ")
        )));
    }
    table.require_finite().map_err(bad)?;
    Ok(table)
}

impl Table {
    /// Checks every value is finite; on failure, which is not (column, data row counted
    /// from 1, value).
    fn require_finite(&self) -> std::result::Result<(), String> {
        let n = self.columns.len();
        match self.values.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(i) => Err(format!(
                "column {:?}, data row {}: every value must be a finite number, got {}",
                self.columns[i % n],
                i / n + 1,
                self.values[i]
            )),
        }
    }
}

/// The `columns` of the CSV text `bytes` (see [`read_table`]), holding at most
/// `max_bytes` of values; on failure, what is wrong.
fn csv_table(
    bytes: &[u8],
    columns: &[String],
    max_bytes: u64,
) -> std::result::Result<Table, String> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(bytes);
    let unreadable = |e: csv::Error| match e.position() {
        Some(p) => format!(
            "must be CSV text (UTF-8): data row {} (line {}) cannot be read: {e}",
            p.record(),
            p.line()
        ),
        None => format!("must be CSV text (UTF-8): {e}"),
    };
    let header = reader.headers().map_err(unreadable)?.clone();
    if header.iter().all(str::is_empty) {
        return Err("has no data rows (not even a header line of column names)".into());
    }
    // Positions of each name: a map, as a file may hold tens of thousands of columns.
    let mut positions: HashMap<&str, Vec<usize>> = HashMap::new();
    for (i, h) in header.iter().enumerate() {
        positions.entry(h).or_default().push(i);
    }
    let index = columns
        .iter()
        .map(|c| {
            let at = positions.get(c.as_str()).map_or(&[][..], Vec::as_slice);
            match *at {
                [i] => Ok(i),
                [i, j, ..] => Err(format!(
                    "names column {c:?} twice, at positions {} and {} of its header (counted from 1): which one holds the data is ambiguous",
                    i + 1,
                    j + 1
                )),
                [] => Err(format!(
                    "must have a column {c:?} (the sidecar's runs imply columns {})",
                    columns.join(", ")
                )),
            }
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    // Short fields make more float64 bytes than text bytes: the values are capped too.
    let max_values = usize::try_from(max_bytes / 8).unwrap_or(usize::MAX);
    let mut values = Vec::new();
    let mut rows = 0;
    let mut record = csv::StringRecord::new();
    while reader.read_record(&mut record).map_err(unreadable)? {
        if record.iter().all(str::is_empty) {
            continue;
        }
        let r = rows + 1;
        if values.len().saturating_add(index.len()) > max_values {
            return Err(format!(
                "holds more than {max_values} values at data row {r}, more than the {max_bytes} bytes (float64) a check may hold"
            ));
        }
        if record.len() != header.len() {
            return Err(format!(
                "must have {} fields in data row {r} (as many as header columns), got {}",
                header.len(),
                record.len()
            ));
        }
        for &i in &index {
            let f = &record[i];
            let v = f.parse::<f64>().map_err(|_| {
                format!(
                    "column {:?}, data row {r}: must be a number, got {f:?}",
                    &header[i]
                )
            })?;
            if !v.is_finite() {
                // Named as written (`nan`, `-Infinity`, `1e400`), not as parsed.
                return Err(format!(
                    "column {:?}, data row {r}: every value must be a finite number, got {f} (read as {v})",
                    &header[i]
                ));
            }
            values.push(v);
        }
        rows += 1;
    }
    Ok(Table {
        columns: columns.to_vec(),
        rows,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const KEY: &str = "runs[0].files[1]";
    const CAP: u64 = 1 << 20;

    fn read(path: &Path, cols: &[String]) -> Result<Table> {
        read_table(path, KEY, cols, CAP)
    }

    fn names(c: &[&str]) -> Vec<String> {
        c.iter().map(|s| s.to_string()).collect()
    }

    /// A refusal of `path` by [`read_table`]: exit 2, naming the file and the key and
    /// holding every string of `named`.
    fn refused_naming(path: &Path, cols: &[String], named: &[&str]) {
        let e = read(path, cols).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
        let text = e.to_string();
        let file = path.file_name().unwrap().to_str().unwrap();
        assert!(text.contains(file) && text.contains(KEY), "{text}");
        for n in named {
            assert!(text.contains(n), "{n:?} not in {text}");
        }
    }

    /// Both formats give back exactly what was written; a CSV with its columns in
    /// another order and an extra column reads the same.
    #[test]
    fn csv_and_npy_round_trip() {
        let dir = std::env::temp_dir().join(format!("lfem-table-{}", std::process::id()));
        let cols = names(&["t", "w_0", "aw_1"]);
        let rows = [
            [0.0, 0.0, 0.0],
            [1e-5, -1.25e-7, 0.1 + 0.2],
            [2e-5, 3.0, f64::MAX],
        ];
        for ext in ["csv", "npy"] {
            let path = dir.join(format!("run/t.{ext}"));
            let mut f = TrajectoryFile::create(&path, &cols, 3).unwrap();
            assert!(!path.exists());
            for r in &rows {
                f.push_row(r).unwrap();
            }
            f.commit().unwrap();
            let t = read(&path, &cols).unwrap();
            assert_eq!(t.rows, 3);
            for (r, row) in rows.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    assert_eq!(t.get(r, c).to_bits(), v.to_bits());
                }
            }
        }
        let path = dir.join("other.csv");
        std::fs::write(&path, "aw_1,extra,t,w_0\n0.5,9,1,2\n").unwrap();
        let t = read(&path, &cols).unwrap();
        assert_eq!(t.values, vec![1.0, 2.0, 0.5]);
        // As other programs write it: a byte-order mark, quoted names (one holding a
        // comma and a doubled quote), CRLF line ends, a blank line.
        std::fs::write(
            &path,
            "\u{feff}\"aw_1\",\"a \"\"b\"\", c\",\"t\", w_0\r\n0.5,x,1,2\r\n\r\n",
        )
        .unwrap();
        let t = read(&path, &cols).unwrap();
        assert_eq!((t.rows, t.values.clone()), (1, vec![1.0, 2.0, 0.5]));
        std::fs::write(&path, "t,w_0\n1,2\n").unwrap();
        refused_naming(&path, &cols, &["\"aw_1\""]);
        std::fs::write(&path, "t,w_0,aw_1\n1,x,2\n").unwrap();
        refused_naming(&path, &cols, &["\"w_0\"", "data row 1", "\"x\""]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Values that are not finite (NaN, inf, written as text or as float64) in a column
    /// of the format are refused naming the column, the data row and the value; an extra
    /// CSV column is not read, so its NaN passes.
    #[test]
    fn non_finite_values_are_refused_where_they_are() {
        let dir = std::env::temp_dir().join(format!("lfem-table-nan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cols = names(&["t", "w_0"]);
        let path = dir.join("a.csv");
        std::fs::write(&path, "t,w_0,note\n0,1,NaN\n\n1,2,x\n2,NaN,y\n").unwrap();
        refused_naming(&path, &cols, &["column \"w_0\"", "data row 3", "NaN"]);
        std::fs::write(&path, "t,w_0,note\n0,1,NaN\n1,-inf,x\n").unwrap();
        refused_naming(&path, &cols, &["column \"w_0\"", "data row 2", "-inf"]);
        std::fs::write(&path, "t,w_0,note\n0,1,NaN\n").unwrap();
        assert_eq!(read(&path, &cols).unwrap().values, vec![0.0, 1.0]);
        let npy = dir.join("b.npy");
        let mut f = TrajectoryFile::create(&npy, &cols, 2).unwrap();
        f.push_row(&[0.0, 1.0]).unwrap();
        f.push_row(&[f64::INFINITY, 1.0]).unwrap();
        f.commit().unwrap();
        refused_naming(&npy, &cols, &["column \"t\"", "data row 2", "inf"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Files without data rows (empty, blank, a header only, a (0, n) array) and a CSV
    /// naming a column twice are refused; so is a file larger than the cap, unread.
    #[test]
    fn empty_files_and_doubled_columns_are_refused() {
        let dir = std::env::temp_dir().join(format!("lfem-table-empty-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cols = names(&["t", "w_0"]);
        let path = dir.join("a.csv");
        for text in ["", "\n\n", "t,w_0\n", "\u{feff}t,w_0\r\n\r\n"] {
            std::fs::write(&path, text).unwrap();
            refused_naming(&path, &cols, &["no data rows"]);
        }
        let npy = dir.join("b.npy");
        TrajectoryFile::create(&npy, &cols, 0)
            .unwrap()
            .commit()
            .unwrap();
        refused_naming(&npy, &cols, &["no data rows"]);
        std::fs::write(&npy, "").unwrap();
        refused_naming(&npy, &cols, &["no data rows", "0 bytes"]);
        std::fs::write(&path, "t,w_0,x,w_0\n0,1,2,3\n").unwrap();
        refused_naming(&path, &cols, &["\"w_0\" twice", "positions 2 and 4"]);
        std::fs::write(&path, "t,w_0,x,x\n0,1,2,3\n").unwrap();
        assert_eq!(read(&path, &cols).unwrap().rows, 1);
        let e = read_table(&path, KEY, &cols, 4).unwrap_err().to_string();
        assert!(
            e.contains(KEY) && e.contains("more than the 4 bytes"),
            "{e}"
        );
        // 14 bytes of text, 2 values of 8 bytes per row: the values outgrow a 24-byte cap.
        std::fs::write(&path, "t,w_0\n0,1\n1,2\n").unwrap();
        let e = read_table(&path, KEY, &cols, 24).unwrap_err().to_string();
        assert!(e.contains("more than 3 values at data row 2"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A FIFO or a device listed as a trajectory file is refused at once, naming the
    /// sidecar key.
    #[cfg(target_os = "linux")]
    #[test]
    fn fifos_and_devices_are_refused_naming_the_key() {
        let cols = names(&["t"]);
        let e = read(Path::new("/dev/zero"), &cols).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(
            e.to_string().contains(KEY) && e.to_string().contains("device"),
            "{e}"
        );
        let dir = std::env::temp_dir().join(format!("lfem-table-fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("t.csv");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if made {
            refused_naming(&fifo, &cols, &["FIFO"]);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
