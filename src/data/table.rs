//! Trajectory files: one table of float64 columns per trajectory, CSV or `.npy`
//! (see the [format](super)), written by streaming and read whole.

use super::npy::{NpyWriter, read_npy};
use crate::error::{Error, Result};
use crate::output::AtomicFile;
use crate::output::io::CsvWriter;
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

/// Reads trajectory file `path` and returns its `columns`, in that order. A CSV file
/// maps its header names to `columns` (any order; other columns ignored); it is read as
/// RFC 4180 text with the `csv` crate (quoted fields, `\r\n` line ends and a UTF-8
/// byte-order mark accepted, fields trimmed, blank lines skipped). A `.npy` file must
/// have exactly these columns, in this order.
///
/// # Errors
/// [`Error::Io`] if unreadable; [`Error::InvalidParameter`] naming the file and the
/// missing column, row or value otherwise.
pub fn read_table(path: &Path, columns: &[String]) -> Result<Table> {
    let bad = |what: String| Error::invalid("trajectory file", path.display(), what);
    let (rows, values) = if path.extension().is_some_and(|e| e == "npy") {
        let (rows, cols, values) = read_npy(path)?;
        if cols != columns.len() {
            return Err(bad(format!(
                "{} columns ({}), as the sidecar implies; the file has {cols}",
                columns.len(),
                columns.join(", ")
            )));
        }
        (rows, values)
    } else {
        let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .flexible(true)
            .from_reader(std::io::BufReader::new(file));
        let unreadable = |e: csv::Error| match e.into_kind() {
            csv::ErrorKind::Io(e) => Error::io(path, e),
            other => bad(format!("CSV text ({other:?})")),
        };
        let header = reader.headers().map_err(unreadable)?.clone();
        if header.iter().all(str::is_empty) {
            return Err(bad("a header line".into()));
        }
        let index = columns
            .iter()
            .map(|c| {
                header.iter().position(|h| h == c).ok_or_else(|| {
                    bad(format!(
                        "a column {c:?} (the sidecar's runs imply columns {})",
                        columns.join(", ")
                    ))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut values = Vec::new();
        let mut rows = 0;
        let mut record = csv::StringRecord::new();
        while reader.read_record(&mut record).map_err(unreadable)? {
            if record.iter().all(str::is_empty) {
                continue;
            }
            let r = rows + 1;
            if record.len() != header.len() {
                return Err(bad(format!(
                    "{} fields in data row {r} (as many as header columns), got {}",
                    header.len(),
                    record.len()
                )));
            }
            for &i in &index {
                let f = &record[i];
                values.push(f.parse::<f64>().map_err(|_| {
                    bad(format!(
                        "numbers in column {:?}; data row {r} holds {f:?}",
                        &header[i]
                    ))
                })?);
            }
            rows += 1;
        }
        (rows, values)
    };
    Ok(Table {
        columns: columns.to_vec(),
        rows,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both formats give back exactly what was written; a CSV with its columns in
    /// another order and an extra column reads the same.
    #[test]
    fn csv_and_npy_round_trip() {
        let dir = std::env::temp_dir().join(format!("lfem-table-{}", std::process::id()));
        let cols: Vec<String> = ["t", "w_0", "aw_1"].iter().map(|s| s.to_string()).collect();
        let rows = [
            [0.0, 0.0, 0.0],
            [1e-5, -1.25e-7, 0.1 + 0.2],
            [2e-5, 3.0, f64::NAN],
        ];
        for ext in ["csv", "npy"] {
            let path = dir.join(format!("run/t.{ext}"));
            let mut f = TrajectoryFile::create(&path, &cols, 3).unwrap();
            assert!(!path.exists());
            for r in &rows {
                f.push_row(r).unwrap();
            }
            f.commit().unwrap();
            let t = read_table(&path, &cols).unwrap();
            assert_eq!(t.rows, 3);
            for (r, row) in rows.iter().enumerate() {
                for (c, v) in row.iter().enumerate() {
                    assert!(t.get(r, c) == *v || (v.is_nan() && t.get(r, c).is_nan()));
                }
            }
        }
        let path = dir.join("other.csv");
        std::fs::write(&path, "aw_1,extra,t,w_0\n0.5,9,1,2\n").unwrap();
        let t = read_table(&path, &cols).unwrap();
        assert_eq!(t.values, vec![1.0, 2.0, 0.5]);
        // As other programs write it: a byte-order mark, quoted names (one holding a
        // comma and a doubled quote), CRLF line ends, a blank line.
        std::fs::write(
            &path,
            "\u{feff}\"aw_1\",\"a \"\"b\"\", c\",\"t\", w_0\r\n0.5,x,1,2\r\n\r\n",
        )
        .unwrap();
        let t = read_table(&path, &cols).unwrap();
        assert_eq!((t.rows, t.values.clone()), (1, vec![1.0, 2.0, 0.5]));
        std::fs::write(&path, "t,w_0\n1,2\n").unwrap();
        let e = read_table(&path, &cols).unwrap_err().to_string();
        assert!(e.contains("aw_1") && e.contains("other.csv"), "{e}");
        std::fs::write(&path, "t,w_0,aw_1\n1,x,2\n").unwrap();
        let e = read_table(&path, &cols).unwrap_err().to_string();
        assert!(e.contains("\"w_0\"") && e.contains("row 1"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
