//! NumPy `.npy` files (format version 1.0) of float64 tables: a streaming writer and a
//! reader. The format is NumPy's own (`numpy.lib.format`): the magic string `\x93NUMPY`,
//! the version, a little-endian header length, a Python-literal header padded with
//! spaces to a multiple of 64 bytes and ending in a newline, then the data.
//!
//! Written by hand rather than with a crate: the maintained crates (npyz) parse headers
//! with a PEG parser generator and big integers, which would add their compile time to
//! every fresh build for a header this module reads and writes in a few lines. Files are
//! cross-checked with NumPy itself by the example simulator in `examples/` (it reads
//! what `run` writes and writes what `check` reads).

use crate::error::{Error, Result};
use std::io::{self, Read, Write};
use std::path::Path;

const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// A streaming writer of a 2-D float64 `.npy` array of a shape known in advance.
#[derive(Debug)]
pub struct NpyWriter<W: Write> {
    out: W,
    columns: usize,
    rows: u64,
    written: u64,
}

impl<W: Write> NpyWriter<W> {
    /// Starts an array of `rows` × `columns` float64 values on `out` (writes the header).
    ///
    /// # Errors
    /// The writer's I/O errors.
    pub fn new(mut out: W, rows: u64, columns: usize) -> io::Result<Self> {
        let dict =
            format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {columns}), }}");
        // Magic (6) + version (2) + length (2) + dict + padding + '\n' ≡ 0 (mod 64).
        let unpadded = 10 + dict.len() + 1;
        let pad = (64 - unpadded % 64) % 64;
        let header = format!("{dict}{}\n", " ".repeat(pad));
        out.write_all(MAGIC)?;
        out.write_all(&[1, 0])?;
        let len = u16::try_from(header.len())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "npy header too long"))?;
        out.write_all(&len.to_le_bytes())?;
        out.write_all(header.as_bytes())?;
        Ok(NpyWriter {
            out,
            columns,
            rows,
            written: 0,
        })
    }

    /// Appends one row of `columns` values.
    ///
    /// # Errors
    /// [`io::ErrorKind::InvalidInput`] for a row of the wrong length or beyond the
    /// announced rows; the writer's I/O errors.
    pub fn push_row(&mut self, row: &[f64]) -> io::Result<()> {
        if row.len() != self.columns || self.written >= self.rows {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "npy row {} of length {} (array of {} x {})",
                    self.written,
                    row.len(),
                    self.rows,
                    self.columns
                ),
            ));
        }
        for v in row {
            self.out.write_all(&v.to_le_bytes())?;
        }
        self.written += 1;
        Ok(())
    }

    /// Checks every announced row was written and returns the inner writer.
    ///
    /// # Errors
    /// [`io::ErrorKind::InvalidData`] if rows are missing.
    pub fn finish(self) -> io::Result<W> {
        if self.written != self.rows {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "npy array announced {} rows, {} written",
                    self.rows, self.written
                ),
            ));
        }
        Ok(self.out)
    }
}

/// Reads a float64 `.npy` file (versions 1–3, C order, little- or big-endian `f8`) of
/// one or two dimensions: returns (rows, columns, row-major values); a 1-D array is one
/// column.
///
/// # Errors
/// [`Error::Io`] if unreadable; [`Error::InvalidParameter`] naming the file if it is not
/// such an array (another dtype, Fortran order, more dimensions, a truncated body).
pub fn read_npy(path: &Path) -> Result<(usize, usize, Vec<f64>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_npy(&bytes).map_err(|why| {
        Error::invalid(
            "trajectory file",
            path.display(),
            format!("a float64 .npy array of 1 or 2 dimensions in C order ({why})"),
        )
    })
}

/// Parses the bytes of a `.npy` file (see [`read_npy`]); on failure, why.
fn parse_npy(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f64>), String> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("no NumPy magic string".into());
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(format!("format version {v}")),
    };
    let header = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or("truncated header")?;
    let field = |name: &str| -> std::result::Result<&str, String> {
        let at = header
            .find(&format!("'{name}'"))
            .ok_or(format!("no '{name}' in the header"))?;
        let rest = &header[at + name.len() + 2..];
        let colon = rest.find(':').ok_or("malformed header")?;
        Ok(rest[colon + 1..].trim_start())
    };
    let descr = field("descr")?;
    let big = if descr.starts_with("'<f8'") {
        false
    } else if descr.starts_with("'>f8'") {
        true
    } else {
        return Err(format!(
            "dtype {} (float64 needed)",
            descr.split(',').next().unwrap_or("")
        ));
    };
    if !field("fortran_order")?.starts_with("False") {
        return Err("Fortran order".into());
    }
    let shape = field("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or("malformed shape")?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("shape ({inner})"))?;
    let (rows, cols) = match dims.as_slice() {
        [r] => (*r, 1),
        [r, c] => (*r, *c),
        _ => return Err(format!("{} dimensions", dims.len())),
    };
    let n = rows.checked_mul(cols).ok_or("shape overflows")?;
    let body = &bytes[start + len..];
    if body.len() != n * 8 {
        return Err(format!(
            "{} data bytes for shape ({rows}, {cols}), {} expected",
            body.len(),
            n * 8
        ));
    }
    let mut values = Vec::with_capacity(n);
    let mut chunk = [0u8; 8];
    let mut reader = body;
    for _ in 0..n {
        reader.read_exact(&mut chunk).map_err(|e| e.to_string())?;
        values.push(if big {
            f64::from_be_bytes(chunk)
        } else {
            f64::from_le_bytes(chunk)
        });
    }
    Ok((rows, cols, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_alignment() {
        let mut w = NpyWriter::new(Vec::new(), 3, 2).unwrap();
        for r in 0..3 {
            w.push_row(&[r as f64, -0.1 * r as f64]).unwrap();
        }
        let bytes = w.finish().unwrap();
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        assert_eq!(bytes[10 + header_len - 1], b'\n');
        let (r, c, v) = parse_npy(&bytes).unwrap();
        assert_eq!((r, c), (3, 2));
        assert_eq!(v, vec![0.0, -0.0, 1.0, -0.1, 2.0, -0.2]);
    }

    #[test]
    fn refuses_wrong_rows_dtype_and_truncation() {
        let mut w = NpyWriter::new(Vec::new(), 1, 2).unwrap();
        assert!(w.push_row(&[1.0]).is_err());
        w.push_row(&[1.0, 2.0]).unwrap();
        assert!(w.push_row(&[1.0, 2.0]).is_err());
        let bytes = w.finish().unwrap();
        assert!(parse_npy(&bytes[..bytes.len() - 1]).is_err());
        let mut f4 = bytes.clone();
        let at = f4.windows(3).position(|w| w == b"<f8").unwrap();
        f4[at + 2] = b'4';
        assert!(parse_npy(&f4).unwrap_err().contains("dtype"));
        assert!(NpyWriter::new(Vec::new(), 2, 1).unwrap().finish().is_err());
    }

    #[test]
    fn reads_one_dimension_and_big_endian() {
        // A 1-D big-endian array as NumPy writes it: np.array([1.5, -2.0], dtype='>f8').
        let dict = "{'descr': '>f8', 'fortran_order': False, 'shape': (2,), }";
        let pad = 64 - (10 + dict.len() + 1) % 64;
        let header = format!("{dict}{}\n", " ".repeat(pad));
        let mut bytes = MAGIC.to_vec();
        bytes.extend([1, 0]);
        bytes.extend((header.len() as u16).to_le_bytes());
        bytes.extend(header.as_bytes());
        bytes.extend(1.5f64.to_be_bytes());
        bytes.extend((-2.0f64).to_be_bytes());
        assert_eq!(parse_npy(&bytes).unwrap(), (2, 1, vec![1.5, -2.0]));
    }
}
