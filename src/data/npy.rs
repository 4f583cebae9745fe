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

use crate::error::{Error, Result, shown_text};
use std::io::{self, Write};
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
/// column. The file is read as a regular file of at most `max_bytes`
/// ([`crate::input::read_bytes`]; `key` names what led to it), and its declared shape is
/// compared with its size before anything is allocated.
///
/// # Errors
/// [`Error::Scene`] naming the file and `key` if it cannot be read or is not such an
/// array (another dtype, Fortran order, more dimensions, a shape that does not match the
/// size of the file).
pub fn read_npy(path: &Path, key: &str, max_bytes: u64) -> Result<(usize, usize, Vec<f64>)> {
    let bytes = crate::input::read_bytes(path, key, max_bytes)?;
    parse_npy(&bytes).map_err(|why| npy_error(path, key, &why))
}

/// The error of `.npy` file `path` (at `key`) that is not a float64 array: `why`.
pub(super) fn npy_error(path: &Path, key: &str, why: &str) -> Error {
    crate::input::refused(
        path,
        key,
        format!("must be a float64 .npy array of 1 or 2 dimensions in C order: {why}"),
    )
}

/// Parses the bytes of a `.npy` file (see [`read_npy`]); on failure, why. Never panics
/// and never allocates more than the file's size, whatever the header says.
pub(super) fn parse_npy(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f64>), String> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("no NumPy magic string".into());
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(format!("format version {v} (1, 2 or 3 expected)")),
    };
    let data_start = start
        .checked_add(len)
        .filter(|&end| end <= bytes.len())
        .ok_or_else(|| {
            format!(
                "truncated header: it declares {len} bytes, the file holds {} after the preamble",
                bytes.len() - start
            )
        })?;
    let header = std::str::from_utf8(&bytes[start..data_start])
        .map_err(|_| "header is not text".to_string())?;
    let (big, rows, cols) = parse_header(header)?;
    let body = &bytes[data_start..];
    let declared = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(8).map(|b| (n, b)));
    let Some((n, _)) = declared.filter(|&(_, b)| b == body.len()) else {
        return Err(format!(
            "its header declares shape ({rows}, {cols}), {} bytes of float64 data, but the file holds {} bytes of data after its {data_start}-byte header",
            declared.map_or("more than 2^64".to_string(), |(_, b)| b.to_string()),
            body.len()
        ));
    };
    let mut values = Vec::with_capacity(n);
    for chunk in body.chunks_exact(8) {
        let b: [u8; 8] = chunk.try_into().map_err(|_| "short value".to_string())?;
        values.push(if big {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        });
    }
    Ok((rows, cols, values))
}

/// The keys of a `.npy` header dictionary, each once, nothing else (as NumPy requires).
const HEADER_KEYS: [&str; 3] = ["descr", "fortran_order", "shape"];

/// The entries (key, value text) of a `.npy` header: one Python dictionary literal,
/// padded with whitespace, whose keys are quoted strings and whose values hold no
/// top-level comma. NumPy evaluates the header with `ast.literal_eval` and refuses a
/// header that is not such a literal (unterminated, a NUL byte) or whose keys are not
/// exactly [`HEADER_KEYS`]; so does this reader, rather than guess at what the file holds.
fn header_entries(header: &str) -> std::result::Result<Vec<(&str, &str)>, String> {
    if let Some((i, c)) = header
        .char_indices()
        .find(|&(_, c)| c.is_control() && !c.is_ascii_whitespace())
    {
        return Err(format!(
            "the header holds a control character (U+{:04X} at byte {i}): not a Python dictionary literal",
            c as u32
        ));
    }
    let literal = header.trim();
    let inner = literal
        .strip_prefix('{')
        .and_then(|s| s.strip_suffix('}'))
        .ok_or_else(|| {
            format!(
                "the header {:?} is not a complete Python dictionary literal {{...}}",
                shown_text(literal, 80)
            )
        })?;
    let mut entries = Vec::new();
    let (mut depth, mut quote, mut from) = (0i32, None::<char>, 0usize);
    let mut push = |part| -> std::result::Result<(), String> {
        entries.extend(header_entry(part)?);
        Ok(())
    };
    for (i, c) in inner.char_indices() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '\'' | '"') => quote = Some(c),
            (None, '(' | '[' | '{') => depth += 1,
            (None, ')' | ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                push(&inner[from..i])?;
                from = i + 1;
            }
            _ => {}
        }
        if depth < 0 {
            return Err("the header's brackets do not balance".into());
        }
    }
    if quote.is_some() || depth != 0 {
        return Err("the header's quotes or brackets do not balance".into());
    }
    push(&inner[from..])?;
    for (k, (key, _)) in entries.iter().enumerate() {
        if !HEADER_KEYS.contains(key) {
            return Err(format!(
                "the header has the key '{key}' besides 'descr', 'fortran_order' and 'shape' (NumPy refuses it too): write those three only"
            ));
        }
        // NumPy's parser keeps the last of a repeated key, a first-match reader the
        // first: the file's meaning would depend on the reader.
        if entries[..k].iter().any(|(other, _)| other == key) {
            return Err(format!(
                "the header gives '{key}' twice (NumPy would read the last, so what the file holds is ambiguous): write each key once"
            ));
        }
    }
    Ok(entries)
}

/// One entry `'key': value` of a header dictionary (None if blank, after a trailing comma).
fn header_entry(part: &str) -> std::result::Result<Option<(&str, &str)>, String> {
    let part = part.trim();
    if part.is_empty() {
        return Ok(None);
    }
    let q = part
        .chars()
        .next()
        .filter(|&c| c == '\'' || c == '"')
        .ok_or_else(|| format!("header entry {part:?} has no quoted key"))?;
    let close = part[1..]
        .find(q)
        .ok_or_else(|| format!("header entry {part:?} has an unterminated key"))?;
    let value = part[2 + close..]
        .trim_start()
        .strip_prefix(':')
        .ok_or_else(|| format!("header entry {part:?} has no ':' after its key"))?;
    Ok(Some((&part[1..1 + close], value.trim())))
}

/// The dtype's byte order (big-endian?) and the shape (rows, columns) of a `.npy`
/// header ([`header_entries`]); on failure, why.
fn parse_header(header: &str) -> std::result::Result<(bool, usize, usize), String> {
    let entries = header_entries(header)?;
    let field = |name: &str| -> std::result::Result<&str, String> {
        entries
            .iter()
            .find(|(key, _)| *key == name)
            .map(|&(_, value)| value)
            .ok_or(format!("no '{name}' in the header"))
    };
    let descr = field("descr")?;
    let big = if matches!(descr, "'<f8'" | "\"<f8\"") {
        false
    } else if matches!(descr, "'>f8'" | "\">f8\"") {
        true
    } else {
        // A structured dtype is a list: shown whole, up to its closing bracket.
        let shown = match descr.strip_prefix('[') {
            Some(rest) => format!("[{}]", rest.split(']').next().unwrap_or("")),
            None => shown_text(descr, 40),
        };
        return Err(format!(
            "descr (dtype) {shown}: float64 ('<f8' or '>f8') needed"
        ));
    };
    match field("fortran_order")? {
        "False" => {}
        "True" => return Err("Fortran order".into()),
        other => return Err(format!("fortran_order {other}: False or True expected")),
    }
    let shape = field("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.strip_suffix(')'))
        .ok_or("malformed shape")?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("shape ({})", shown_text(inner, 40)))?;
    match dims.as_slice() {
        [r] => Ok((big, *r, 1)),
        [r, c] => Ok((big, *r, *c)),
        _ => Err(format!(
            "shape has {} dimensions (1 or 2 expected)",
            dims.len()
        )),
    }
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

    /// A valid file of `rows` × `cols` values `0, 1, 2, …`.
    fn sample(rows: u64, cols: usize) -> Vec<u8> {
        let mut w = NpyWriter::new(Vec::new(), rows, cols).unwrap();
        for r in 0..rows {
            let row: Vec<f64> = (0..cols).map(|c| (r as usize * cols + c) as f64).collect();
            w.push_row(&row).unwrap();
        }
        w.finish().unwrap()
    }

    /// `bytes` with the header's shape replaced by `shape` (the header length kept by
    /// padding, so only the shape changes).
    fn with_shape(bytes: &[u8], shape: &str) -> Vec<u8> {
        let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
        let open = header.find("'shape': (").unwrap() + 9;
        let close = open + header[open..].find(')').unwrap() + 1;
        let mut h = format!("{}{shape}{}", &header[..open], &header[close..]);
        h = format!("{:<width$}\n", h.trim_end(), width = len - 1);
        assert_eq!(h.len(), len, "{h}");
        let mut out = bytes[..10].to_vec();
        out.extend(h.as_bytes());
        out.extend(&bytes[10 + len..]);
        out
    }

    /// Headers declaring more data than the file holds (2^61 values, a product that
    /// overflows, more rows) are refused with the shape and the byte counts, before any
    /// allocation; a header length beyond the file is a truncated header.
    #[test]
    fn declared_shapes_are_compared_with_the_file_size() {
        let bytes = sample(2, 3);
        assert_eq!(parse_npy(&bytes).unwrap().0, 2);
        let e = parse_npy(&with_shape(&bytes, "(2305843009213693952, 1)")).unwrap_err();
        assert!(
            e.contains("shape (2305843009213693952, 1)")
                && e.contains("more than 2^64")
                && e.contains("48 bytes of data"),
            "{e}"
        );
        let e = parse_npy(&with_shape(&bytes, "(3, 3)")).unwrap_err();
        assert!(
            e.contains("shape (3, 3), 72 bytes") && e.contains("holds 48 bytes"),
            "{e}"
        );
        let e = parse_npy(&with_shape(&bytes, "(4294967296, 4294967296)")).unwrap_err();
        assert!(e.contains("more than 2^64"), "{e}");
        let mut long = bytes.clone();
        long[8..10].copy_from_slice(&u16::MAX.to_le_bytes());
        assert!(parse_npy(&long).unwrap_err().contains("truncated header"));
        let mut v2 = bytes.clone();
        v2[6] = 2;
        assert!(parse_npy(&v2).is_err());
        v2[6] = 9;
        assert!(parse_npy(&v2).unwrap_err().contains("version 9"));
    }

    /// Random damage to a valid file (bytes overwritten, the file cut, bytes inserted,
    /// header fields and lengths rewritten) never panics: each copy is read or refused.
    #[test]
    fn damaged_files_never_panic() {
        let valid = sample(5, 4);
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let specials: [&[u8]; 8] = [
            b"(18446744073709551615, 2)",
            b"(9223372036854775807,)",
            b"()",
            b"(1, 2, 3)",
            b"(-1, 2)",
            b"'<f4'",
            b"\xff\xff",
            b"True",
        ];
        for _ in 0..20_000 {
            let mut b = valid.clone();
            for _ in 0..(1 + next() % 4) {
                let at = (next() as usize) % b.len().max(1);
                match next() % 6 {
                    0 => b[at] = next() as u8,
                    1 => b.truncate(at),
                    2 => b.insert(at, next() as u8),
                    3 if at < 10 => b[at] = [0, 1, 2, 3, 0xff][next() as usize % 5],
                    4 => {
                        let s = specials[next() as usize % specials.len()];
                        let end = (at + s.len()).min(b.len());
                        b.splice(at..end, s.iter().copied());
                    }
                    _ => {
                        if b.len() > 11 {
                            b[8] = next() as u8;
                            b[9] = next() as u8;
                        }
                    }
                }
                if b.is_empty() {
                    break;
                }
            }
            let _ = parse_npy(&b);
        }
    }

    /// A version-1 `.npy` file of header dictionary `dict` (padded as NumPy pads it) and
    /// data bytes `data`.
    fn npy_file(dict: &str, data: &[u8]) -> Vec<u8> {
        let pad = 64 - (10 + dict.len() + 1) % 64;
        let header = format!("{dict}{}\n", " ".repeat(pad));
        let mut bytes = MAGIC.to_vec();
        bytes.extend([1, 0]);
        bytes.extend((header.len() as u16).to_le_bytes());
        bytes.extend(header.as_bytes());
        bytes.extend(data);
        bytes
    }

    #[test]
    fn reads_one_dimension_and_big_endian() {
        // A 1-D big-endian array as NumPy writes it: np.array([1.5, -2.0], dtype='>f8').
        let dict = "{'descr': '>f8', 'fortran_order': False, 'shape': (2,), }";
        let data = [1.5f64.to_be_bytes(), (-2.0f64).to_be_bytes()].concat();
        let bytes = npy_file(dict, &data);
        assert_eq!(parse_npy(&bytes).unwrap(), (2, 1, vec![1.5, -2.0]));
    }

    /// A header that gives a key twice is refused, naming the key: NumPy reads the last
    /// value (here float32), a first-match reader the first (float64). Once, it is read.
    #[test]
    fn a_repeated_header_key_is_refused() {
        let file = |dict: &str| npy_file(dict, &1.5f64.to_le_bytes());
        let twice = "{'descr': '<f8', 'descr': '<f4', 'fortran_order': False, 'shape': (1,), }";
        let err = parse_npy(&file(twice)).unwrap_err();
        assert!(err.contains("'descr' twice"), "{err}");
        let once = "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }";
        assert_eq!(parse_npy(&file(once)).unwrap(), (1, 1, vec![1.5]));
    }

    /// Headers that NumPy's `ast.literal_eval` refuses are refused, and why is said: cut
    /// off, a NUL byte, a key besides the three, an unquoted key, unbalanced brackets.
    /// NumPy's own spellings (double quotes, no trailing comma, spaces) are read.
    #[test]
    fn malformed_headers_are_refused() {
        let file = |dict: &str| npy_file(dict, &1.5f64.to_le_bytes());
        for (dict, says) in [
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (1,",
                "complete",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }}",
                "balance",
            ),
            (
                "{'descr': '<f8',\0 'fortran_order': False, 'shape': (1,), }",
                "control",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'x': 1}",
                "'x' besides",
            ),
            (
                "{descr: '<f8', 'fortran_order': False, 'shape': (1,)}",
                "no quoted key",
            ),
            (
                "{'descr' '<f8', 'fortran_order': False, 'shape': (1,)}",
                "no ':'",
            ),
            (
                "{'descr': '<f8', 'fortran_order': Fals, 'shape': (1,)}",
                "fortran_order Fals",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (1,) 2}",
                "malformed shape",
            ),
            ("{'descr': '<f8', 'fortran_order': False}", "no 'shape'"),
            (
                "{'descr': '<f4', 'fortran_order': False, 'shape': (1,)}",
                "'<f4'",
            ),
        ] {
            let err = parse_npy(&file(dict)).unwrap_err();
            assert!(err.contains(says), "{dict}: {err}");
        }
        for dict in [
            "{\"descr\": \"<f8\", \"fortran_order\": False, \"shape\": (1, 1)}",
            "{ 'shape' : (1,) , 'fortran_order' : False , 'descr' : '<f8' }",
        ] {
            assert_eq!(parse_npy(&file(dict)).unwrap(), (1, 1, vec![1.5]), "{dict}");
        }
    }
}
