//! The per-trajectory records of a run as bytes: what a shard of an ensemble hands to the
//! merge (issue #15), so that the checks, tables and figures of the merged ensemble are
//! computed by the same code from the same numbers, in the same order, as in one process.
//!
//! Format (little-endian throughout): an 8-byte magic naming the record kind
//! (`LFEMLIN1` for linear runs, `LFEMFRC1` for compression runs), then the records. A
//! count or length is a `u64`; a sequence of numbers is its length then the numbers'
//! IEEE-754 bits, so every value (NaN payloads, −0.0, infinities) reads back bit for bit;
//! an optional number is a byte (0 absent, 1 present) then the number if present.
//!
//! - linear: the number of full trajectories, each [`TrajectoryRecord`] (modes, profile,
//!   rigid and tangent-angle series, two-time products, slope squares and their count), then the two-time products of the
//!   extra from-rest trajectories (a count, then one sequence each);
//! - compression: the number of strains, then per strain the number of trajectories and
//!   each [`ForceRecord`] (F/F_c0, proposals, acceptances, slope squares and their count,
//!   the axial residual and its number of states).
//!
//! Reading refuses a wrong magic, a truncated file or trailing bytes, naming the source
//! and the byte offset.

use crate::error::{Error, Result};
use crate::scene::compression::ForceRecord;
use crate::scene::linear::TrajectoryRecord;

/// The magic of linear-run records.
/// Version 2 (issue #29) adds the rigid-mode series after the profile, version 3 the
/// tangent-angle cosine series after them.
pub const LINEAR_MAGIC: &[u8; 8] = b"LFEMLIN3";
/// The magic of compression-run records.
/// Version 2 (issue #30) adds the proposal-drift residual after the axial residual.
pub const FORCE_MAGIC: &[u8; 8] = b"LFEMFRC2";

/// Appends values to a byte buffer.
struct Encoder(Vec<u8>);

impl Encoder {
    fn new(magic: &[u8; 8]) -> Self {
        Encoder(magic.to_vec())
    }

    fn count(&mut self, n: usize) {
        self.0.extend_from_slice(&(n as u64).to_le_bytes());
    }

    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }

    fn numbers(&mut self, v: &[f64]) {
        self.count(v.len());
        self.0.reserve(8 * v.len());
        for &x in v {
            self.f64(x);
        }
    }

    fn series(&mut self, v: &[Vec<f64>]) {
        self.count(v.len());
        for s in v {
            self.numbers(s);
        }
    }

    fn optional(&mut self, v: Option<f64>) {
        match v {
            Some(x) => {
                self.0.push(1);
                self.f64(x);
            }
            None => self.0.push(0),
        }
    }
}

/// Reads values back from bytes, naming `source` and the offset in its errors.
struct Decoder<'a> {
    bytes: &'a [u8],
    at: usize,
    source: &'a str,
}

impl<'a> Decoder<'a> {
    fn new(bytes: &'a [u8], magic: &[u8; 8], source: &'a str) -> Result<Self> {
        if bytes.get(..8) != Some(magic.as_slice()) {
            return Err(Error::invalid(
                format!("records {source}"),
                format!(
                    "a file starting {:?}",
                    String::from_utf8_lossy(&bytes[..bytes.len().min(8)])
                ),
                format!(
                    "records starting with {:?} (written by this version)",
                    String::from_utf8_lossy(magic)
                ),
            ));
        }
        Ok(Decoder {
            bytes,
            at: 8,
            source,
        })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(Error::invalid(
                format!("records {}", self.source),
                format!(
                    "truncated at byte {} of {} (needs {n} more)",
                    self.at,
                    self.bytes.len()
                ),
                "a complete file",
            ));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u64(&mut self) -> Result<u64> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    /// A count, refused if the rest of the file cannot hold `min_bytes` per item.
    fn count(&mut self, min_bytes: usize) -> Result<usize> {
        let at = self.at;
        let n = self.u64()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(min_bytes as u64) > left {
            return Err(Error::invalid(
                format!("records {}", self.source),
                format!("a count of {n} at byte {at}, with {left} bytes left"),
                "a count the file can hold",
            ));
        }
        Ok(n as usize)
    }

    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(self.u64()?))
    }

    fn numbers(&mut self) -> Result<Vec<f64>> {
        let n = self.count(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    fn series(&mut self) -> Result<Vec<Vec<f64>>> {
        let n = self.count(8)?;
        (0..n).map(|_| self.numbers()).collect()
    }

    fn optional(&mut self) -> Result<Option<f64>> {
        let at = self.at;
        match self.take(1)?[0] {
            0 => Ok(None),
            1 => self.f64().map(Some),
            b => Err(Error::invalid(
                format!("records {}", self.source),
                format!("byte {b} at offset {at}"),
                "0 (absent) or 1 (present)",
            )),
        }
    }

    fn finish(self) -> Result<()> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err(Error::invalid(
                format!("records {}", self.source),
                format!(
                    "{} bytes after the last record (at byte {})",
                    self.bytes.len() - self.at,
                    self.at
                ),
                "nothing after the last record",
            ))
        }
    }
}

/// The bytes of a linear run's records: the full trajectories' `records` and the extra
/// from-rest trajectories' two-time products `extra`.
pub fn encode_linear(records: &[TrajectoryRecord], extra: &[Vec<f64>]) -> Vec<u8> {
    let mut e = Encoder::new(LINEAR_MAGIC);
    e.count(records.len());
    for r in records {
        e.series(&r.modes);
        e.series(&r.profile);
        e.series(&r.rigid);
        e.series(&r.tangent);
        e.numbers(&r.two_time);
        e.numbers(&r.slope_squares);
        e.count(r.slope_samples);
    }
    e.series(extra);
    e.0
}

/// Reads [`encode_linear`]'s bytes back (`source` names them in errors).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `source` and the offset: a wrong magic, a truncated
/// file, an impossible count or trailing bytes.
pub fn decode_linear(bytes: &[u8], source: &str) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let mut d = Decoder::new(bytes, LINEAR_MAGIC, source)?;
    let n = d.count(40)?;
    let mut records = Vec::with_capacity(n);
    for _ in 0..n {
        records.push(TrajectoryRecord {
            modes: d.series()?,
            profile: d.series()?,
            rigid: d.series()?,
            tangent: d.series()?,
            two_time: d.numbers()?,
            slope_squares: d.numbers()?,
            slope_samples: d.u64()? as usize,
        });
    }
    let extra = d.series()?;
    d.finish()?;
    Ok((records, extra))
}

/// The bytes of a compression run's records, per strain per trajectory.
pub fn encode_force(records: &[Vec<ForceRecord>]) -> Vec<u8> {
    let mut e = Encoder::new(FORCE_MAGIC);
    e.count(records.len());
    for point in records {
        e.count(point.len());
        for r in point {
            e.numbers(&r.force_ratio);
            e.u64(r.proposed);
            e.u64(r.accepted);
            e.numbers(&r.slope_squares);
            e.count(r.slope_samples);
            e.optional(r.axial_residual);
            e.u64(r.axial_states);
            e.optional(r.drift_residual);
            e.u64(r.drift_states);
        }
    }
    e.0
}

/// Reads [`encode_force`]'s bytes back (`source` names them in errors).
///
/// # Errors
/// As [`decode_linear`].
pub fn decode_force(bytes: &[u8], source: &str) -> Result<Vec<Vec<ForceRecord>>> {
    let mut d = Decoder::new(bytes, FORCE_MAGIC, source)?;
    let points = d.count(8)?;
    let mut out = Vec::with_capacity(points);
    for _ in 0..points {
        let n = d.count(49)?;
        let mut point = Vec::with_capacity(n);
        for _ in 0..n {
            point.push(ForceRecord {
                force_ratio: d.numbers()?,
                proposed: d.u64()?,
                accepted: d.u64()?,
                slope_squares: d.numbers()?,
                slope_samples: d.u64()? as usize,
                axial_residual: d.optional()?,
                axial_states: d.u64()?,
                drift_residual: d.optional()?,
                drift_states: d.u64()?,
                buckled_mode: Vec::new(),
            });
        }
        out.push(point);
    }
    d.finish()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::noise::standard_normal;
    use crate::rng::trajectory_rng;

    /// Values whose bits a lossy codec would change: NaN with a payload, −0.0, the
    /// infinities, subnormals, and random normals.
    fn awkward(k: u64, n: usize) -> Vec<f64> {
        let mut rng = trajectory_rng(20261202, k);
        let mut v = vec![
            f64::from_bits(0x7ff8_0000_dead_beef),
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE / 3.0,
        ];
        v.extend((0..n).map(|_| standard_normal(&mut rng)));
        v
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn linear_sample() -> (Vec<TrajectoryRecord>, Vec<Vec<f64>>) {
        let records = (0..3)
            .map(|j| TrajectoryRecord {
                modes: vec![awkward(j, 10), awkward(j + 10, 3), vec![]],
                profile: vec![awkward(j + 20, 7)],
                rigid: vec![awkward(j + 60, 5)],
                tangent: vec![awkward(j + 70, 4)],
                two_time: awkward(j + 30, 2),
                slope_squares: awkward(j + 40, 4),
                slope_samples: 17 + j as usize,
            })
            .collect();
        (records, vec![awkward(50, 2), vec![]])
    }

    /// Linear and compression records read back bit for bit (every field, NaN payloads
    /// and −0.0 included), and re-encoding gives the same bytes.
    #[test]
    fn records_round_trip_bit_for_bit() {
        let (records, extra) = linear_sample();
        let bytes = encode_linear(&records, &extra);
        let (back, back_extra) = decode_linear(&bytes, "test").unwrap();
        assert_eq!(back.len(), records.len());
        for (a, b) in records.iter().zip(&back) {
            let series = |s: &[Vec<f64>]| s.iter().map(|v| bits(v)).collect::<Vec<_>>();
            assert_eq!(series(&a.modes), series(&b.modes));
            assert_eq!(series(&a.profile), series(&b.profile));
            assert_eq!(bits(&a.two_time), bits(&b.two_time));
            assert_eq!(bits(&a.slope_squares), bits(&b.slope_squares));
            assert_eq!(a.slope_samples, b.slope_samples);
        }
        assert_eq!(extra.len(), back_extra.len());
        assert_eq!(bits(&extra[0]), bits(&back_extra[0]));
        assert_eq!(encode_linear(&back, &back_extra), bytes);

        let force: Vec<Vec<ForceRecord>> = (0..2)
            .map(|i| {
                (0..3)
                    .map(|j| ForceRecord {
                        force_ratio: awkward(100 + 10 * i + j, 20),
                        proposed: 1000 + j,
                        accepted: 900 + j,
                        slope_squares: awkward(200 + j, 3),
                        slope_samples: 20,
                        axial_residual: (j != 1).then_some(2.5e-15 * j as f64),
                        axial_states: 40 * j,
                        drift_residual: (j != 2).then_some(3.5e-9 * j as f64),
                        drift_states: j,
                        buckled_mode: Vec::new(),
                    })
                    .collect()
            })
            .collect();
        let bytes = encode_force(&force);
        let back = decode_force(&bytes, "test").unwrap();
        for (pa, pb) in force.iter().zip(&back) {
            assert_eq!(pa.len(), pb.len());
            for (a, b) in pa.iter().zip(pb) {
                assert_eq!(bits(&a.force_ratio), bits(&b.force_ratio));
                assert_eq!((a.proposed, a.accepted), (b.proposed, b.accepted));
                assert_eq!(bits(&a.slope_squares), bits(&b.slope_squares));
                assert_eq!(a.slope_samples, b.slope_samples);
                assert_eq!(
                    a.axial_residual.map(f64::to_bits),
                    b.axial_residual.map(f64::to_bits)
                );
                assert_eq!(a.axial_states, b.axial_states);
            }
        }
        assert_eq!(encode_force(&back), bytes);
    }

    /// Damaged input is refused, naming the source and what is wrong: the other kind's
    /// magic, every truncation of a valid file, trailing bytes, an impossible count, a bad
    /// presence byte. Never a panic.
    #[test]
    fn damaged_records_are_refused_with_the_offset() {
        let (records, extra) = linear_sample();
        let bytes = encode_linear(&records, &extra);
        let e = decode_force(&bytes, "shard-2/run.records")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("shard-2/run.records") && e.contains("LFEMFRC2"),
            "{e}"
        );
        for cut in (0..bytes.len()).step_by(7) {
            let e = decode_linear(&bytes[..cut], "cut").unwrap_err().to_string();
            assert!(e.contains("records cut"), "cut {cut}: {e}");
        }
        let mut long = bytes.clone();
        long.push(0);
        let e = decode_linear(&long, "long").unwrap_err().to_string();
        assert!(e.contains("1 bytes after the last record"), "{e}");
        let mut huge = bytes.clone();
        huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
        let e = decode_linear(&huge, "huge").unwrap_err().to_string();
        assert!(
            e.contains("a count of 18446744073709551615 at byte 8"),
            "{e}"
        );
        let force = vec![vec![ForceRecord {
            axial_residual: Some(1e-15),
            ..ForceRecord::default()
        }]];
        let mut bad = encode_force(&force);
        // The axial flag: before its value and states, the drift flag (none) and states.
        let flag = bad.len() - 8 - 1 - 8 - 8 - 1;
        assert_eq!(bad[flag], 1);
        bad[flag] = 7;
        let e = decode_force(&bad, "flag").unwrap_err().to_string();
        assert!(e.contains("byte 7 at offset"), "{e}");
    }
}
