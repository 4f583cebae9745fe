//! The total work of a command, projected from its input before anything is allocated or
//! run, and the caps on it.
//!
//! Every command that simulates (`verify`, `converge`, `stability`, `work-precision`)
//! first projects its work from the scene files and flags alone — [`Scene::projected_work`]
//! for the runs of a scene at a budget, the study modules for their options — and refuses
//! it (exit 2) when it exceeds the caps of [`WorkLimits`], with the projected figures, the
//! keys or flags that drive them, the caps and how to raise them. Per-trajectory bounds
//! (at most 1e10 steps, list lengths, trajectory counts) are checked by the validators;
//! this is the bound on their product.
//!
//! **Work** is counted in *DOF-steps*: every time step of every trajectory counts the
//! unknowns it updates, `components × n` (n = 2·elements for the finite elements, the
//! number of modes for the spectral model), and `components × n²` for the dense exact
//! modal update (two n × n products per step). The banded θ-schemes and the modal
//! Metropolis chain cost O(n) per step, so DOF-steps are proportional to CPU time; the
//! message converts them to a wall time at [`NOMINAL_DOF_STEPS_PER_SECOND`]. `run` adds
//! the rows it writes, each deflection value at its model's cost
//! (`LinearRun::deflection_cost`). A scene's finite-element run adds the O(n³) set-up
//! of its exact discrete references ([`Scene::setup_cost`]); `run`, whose preparation
//! skips them and is done before it projects, counts its steps and rows only.
//!
//! **Memory** is that of the samples held at once: runs (or study values, or map cells)
//! run one after the other and drop their samples, so the peak is that of the largest
//! part, 8 bytes a sample (an upper bound: a series is counted at one sample per step up
//! to its cap [`MAX_SAMPLES`](crate::scene::linear::MAX_SAMPLES)).
//!
//! The defaults ([`DEFAULT_MAX_WORK`], [`DEFAULT_MAX_MEMORY_GIB`]) admit every shipped
//! scene and study at every budget with a margin (see `tests/work_caps.rs`); `--max-work`
//! and `--max-memory-gib` raise (or lower) them for one command.
//!
//! [`Scene::projected_work`]: crate::scene::Scene::projected_work
//! [`Scene::setup_cost`]: crate::scene::Scene::setup_cost

use crate::error::{Error, Result};
use std::path::PathBuf;

/// Default cap on the projected work of one command, in DOF-steps (`--max-work`): about
/// 11 times the largest shipped command, `converge --scene hinged-linear-3d --run
/// exact-modal --over elements --budget full` of `make converge BUDGET=full` (4.4e12
/// DOF-steps: the dense exact modal update at 40 elements), about 12 days at
/// [`NOMINAL_DOF_STEPS_PER_SECOND`]. The largest `verify` is that of the extreme scenes
/// at the full budget (7.4e11).
pub const DEFAULT_MAX_WORK: f64 = 5e13;

/// Default cap on the samples held in memory at once, in GiB (`--max-memory-gib`); the
/// largest shipped run holds at most 1.1 GiB (`hinged-linear-3d`, full budget).
pub const DEFAULT_MAX_MEMORY_GIB: f64 = 4.0;

/// The throughput used to turn DOF-steps into a wall time in messages: measured on the
/// 2-core reference machine, `verify --budget quick` ran 2e7 DOF-steps per second
/// (`hinged-1000-2d`, its preparation included), 5e7 (`hinged-linear-2d`) and 1.3e8
/// (`hinged-linear-3d`).
pub const NOMINAL_DOF_STEPS_PER_SECOND: f64 = 5e7;

/// Bytes of one stored sample (an `f64`).
pub const BYTES_PER_SAMPLE: f64 = 8.0;

/// Bytes in a GiB.
const GIB: f64 = 1_073_741_824.0;

/// The work of one run (or study value, or map) in numbers.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunWork {
    /// Time steps summed over every trajectory (burn-in, probes and pilots included).
    pub trajectory_steps: f64,
    /// [`Self::trajectory_steps`] weighted by the unknowns each step updates (see the
    /// [module docs](self)).
    pub dof_steps: f64,
    /// Samples held at once (an upper bound).
    pub samples: f64,
}

/// Where the input that drives a part of the work was given: the error names it.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// A scene file and its key (e.g. `runs[1].full`).
    Scene {
        /// The scene file.
        file: PathBuf,
        /// The key (dotted path) of the ensemble that drives the work.
        key: String,
    },
    /// Command-line flags, e.g. `--values, --trajectories, --duration-tau1`.
    Flags(String),
}

/// One part of a command's work: a run of a scene at a budget, one value of a study, a
/// stability map.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// What it is, e.g. `hinged-linear-2d runs[1] (element-uniform)`.
    pub label: String,
    /// The keys or flags that drive it, with their values.
    pub drivers: String,
    /// Where they were given.
    pub origin: Origin,
    /// Its work.
    pub work: RunWork,
}

/// The projected work of a command: its parts, which run one after the other.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkProjection {
    /// The command, e.g. `verify --budget full`.
    pub command: String,
    /// Its parts.
    pub parts: Vec<Part>,
}

impl WorkProjection {
    /// This projection with every part's steps times `fraction` (the share of one shard
    /// of the trajectories, [`crate::shard`]); the samples held at once are unchanged.
    pub fn scaled(mut self, fraction: f64) -> WorkProjection {
        for part in &mut self.parts {
            part.work.trajectory_steps *= fraction;
            part.work.dof_steps *= fraction;
        }
        self
    }

    /// Total trajectory steps.
    pub fn trajectory_steps(&self) -> f64 {
        self.parts.iter().map(|p| p.work.trajectory_steps).sum()
    }

    /// Total DOF-steps.
    pub fn dof_steps(&self) -> f64 {
        self.parts.iter().map(|p| p.work.dof_steps).sum()
    }

    /// Samples held at once: the largest part's (parts run one after the other).
    pub fn peak_samples(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| p.work.samples)
            .fold(0.0, f64::max)
    }

    /// Bytes of [`Self::peak_samples`].
    pub fn peak_bytes(&self) -> f64 {
        self.peak_samples() * BYTES_PER_SAMPLE
    }

    /// The part with the most work (a NaN counts as the most).
    fn largest_by(&self, key: impl Fn(&Part) -> f64) -> Option<&Part> {
        self.parts.iter().max_by(|a, b| {
            let (x, y) = (key(a), key(b));
            x.is_nan().cmp(&y.is_nan()).then(x.total_cmp(&y))
        })
    }
}

/// The caps on a command's projected work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkLimits {
    /// Most DOF-steps (`--max-work`).
    pub max_work: f64,
    /// Most GiB of samples held at once (`--max-memory-gib`).
    pub max_memory_gib: f64,
}

impl Default for WorkLimits {
    fn default() -> Self {
        WorkLimits {
            max_work: DEFAULT_MAX_WORK,
            max_memory_gib: DEFAULT_MAX_MEMORY_GIB,
        }
    }
}

impl WorkLimits {
    /// Refuses `projection` if its DOF-steps exceed [`Self::max_work`] or its samples held
    /// at once [`Self::max_memory_gib`] (a NaN or infinite projection is refused too).
    ///
    /// # Errors
    /// Exit 2: [`Error::Scene`] naming the file and the key of the largest part when a
    /// scene drives it, else [`Error::InvalidParameter`] naming the flags; the message
    /// gives the projected DOF-steps, trajectory steps, wall time and memory, the caps
    /// and the flags that raise them.
    pub fn check(&self, projection: &WorkProjection) -> Result<()> {
        let work = projection.dof_steps();
        let bytes = projection.peak_bytes();
        // A NaN projection is over its cap too.
        let within = |x: f64, cap: f64| x.is_finite() && x <= cap;
        let over_work = !within(work, self.max_work);
        let over_memory = !within(bytes, self.max_memory_gib * GIB);
        if !over_work && !over_memory {
            return Ok(());
        }
        let part = if over_work {
            projection.largest_by(|p| p.work.dof_steps)
        } else {
            projection.largest_by(|p| p.work.samples)
        };
        let Some(part) = part else {
            return Ok(());
        };
        let cap = format!(
            "at most {} DOF-steps (--max-work) and {} of samples held at once (--max-memory-gib {})",
            count(self.max_work),
            size(self.max_memory_gib * GIB),
            count(self.max_memory_gib)
        );
        let got = format!(
            "{} DOF-steps ({} trajectory steps; about {} at {} DOF-steps/s) and {} of samples (at most {} samples of {} bytes held at once)",
            count(work),
            count(projection.trajectory_steps()),
            duration(work / NOMINAL_DOF_STEPS_PER_SECOND),
            count(NOMINAL_DOF_STEPS_PER_SECOND),
            size(bytes),
            count(projection.peak_samples()),
            BYTES_PER_SAMPLE
        );
        let largest = if projection.parts.len() > 1 {
            format!(
                "the largest of its {} parts by {}: {} ({} DOF-steps, {} of samples) from {}",
                projection.parts.len(),
                if over_work { "work" } else { "memory" },
                part.label,
                count(part.work.dof_steps),
                size(part.work.samples * BYTES_PER_SAMPLE),
                part.drivers
            )
        } else {
            format!("{} from {}", part.label, part.drivers)
        };
        let mut raise = Vec::new();
        if over_work {
            raise.push(format!("--max-work {}", round_up(work)));
        }
        if over_memory {
            raise.push(format!("--max-memory-gib {}", round_up(bytes / GIB)));
        }
        let how = format!(
            "lower those, or raise the cap deliberately with {} (the guide, docs/src/reference/exit-codes-and-limits.md, \"Limits\")",
            raise.join(" ")
        );
        let what = format!("the projected work of `{}`", projection.command);
        Err(match &part.origin {
            Origin::Scene { file, key } => Error::Scene {
                file: file.clone(),
                key: key.clone(),
                message: format!("{what} must be {cap}, got {got}; {largest}; {how}"),
            },
            Origin::Flags(flags) => Error::InvalidParameter {
                name: format!("{what} ({flags})"),
                value: format!("{got}; {largest}; {how}"),
                allowed: cap,
            },
        })
    }
}

/// A number for messages: whole numbers below 1e6 as they are, others to three
/// significant digits, in exponent form from 1e6 and below 1e-2 (`3.21e13`, `1e13`,
/// `4.4`, `2.9e-4`).
pub fn count(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    if (1e-2..1e6).contains(&x.abs()) {
        let r = x.round();
        return if (x - r).abs() < 1e-9 * x.abs().max(1.0) {
            format!("{r}")
        } else {
            let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
            let s = format!("{x:.decimals$}");
            if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                s
            }
        };
    }
    let s = format!("{x:.2e}");
    match s.split_once('e') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{e}")
        }
        None => s,
    }
}

/// `x` rounded up to two significant digits (a cap that admits it), as text.
fn round_up(x: f64) -> String {
    if !(x.is_finite() && x > 0.0) {
        return count(x);
    }
    let unit = 10f64.powi(x.log10().floor() as i32 - 1);
    let mut r = (x / unit).ceil() * unit;
    // Guard against the rounding of `unit` leaving r below x.
    if r < x {
        r += unit;
    }
    count(r)
}

/// A duration in seconds for messages: `40 s`, `12 min`, `3.2 h`, `9.1 days`,
/// `2.3 years`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "forever".to_string();
    }
    if seconds < 1.0 {
        return "under 1 s".to_string();
    }
    let (v, unit) = if seconds < 120.0 {
        (seconds, "s")
    } else if seconds < 7200.0 {
        (seconds / 60.0, "min")
    } else if seconds < 2.0 * 86_400.0 {
        (seconds / 3600.0, "h")
    } else if seconds < 2.0 * 365.25 * 86_400.0 {
        (seconds / 86_400.0, "days")
    } else {
        (seconds / (365.25 * 86_400.0), "years")
    };
    if v < 10.0 {
        format!("{v:.1} {unit}")
    } else {
        format!("{} {unit}", count(v.round()))
    }
}

/// A size in bytes for messages, in binary units: `512 B`, `1.5 MiB`, `4.1 GiB`.
pub fn size(bytes: f64) -> String {
    if !bytes.is_finite() {
        return format!("{bytes} B");
    }
    const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{} B", v.round())
    } else if v < 10.0 {
        format!("{v:.1} {}", UNITS[u])
    } else {
        format!("{} {}", count(v.round()), UNITS[u])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn projection(parts: &[(f64, f64)]) -> WorkProjection {
        WorkProjection {
            command: "verify --budget full".to_string(),
            parts: parts
                .iter()
                .enumerate()
                .map(|(i, &(dof_steps, samples))| Part {
                    label: format!("s runs[{i}] (r{i})"),
                    drivers: format!("runs[{i}].full.trajectories = 16"),
                    origin: Origin::Scene {
                        file: PathBuf::from("s.toml"),
                        key: format!("runs[{i}].full"),
                    },
                    work: RunWork {
                        trajectory_steps: dof_steps / 20.0,
                        dof_steps,
                        samples,
                    },
                })
                .collect(),
        }
    }

    #[test]
    fn numbers_read_as_people_write_them() {
        assert_eq!(count(1e13), "1e13");
        assert_eq!(count(3.2149e13), "3.21e13");
        assert_eq!(count(20.0), "20");
        assert_eq!(count(0.5), "0.5");
        assert_eq!(count(4.39), "4.39");
        assert_eq!(count(146.48), "146");
        assert_eq!(count(2.9e-4), "2.9e-4");
        assert_eq!(round_up(2.861e-4), "2.9e-4");
        assert_eq!(duration(0.01), "under 1 s");
        assert_eq!(round_up(3.2149e13), "3.3e13");
        assert_eq!(round_up(4.0), "4");
        assert_eq!(round_up(4.01), "4.1");
        assert_eq!(duration(30.0), "30 s");
        assert_eq!(duration(9.0 * 86_400.0), "9.0 days");
        assert_eq!(duration(5e13 / 5e7), "12 days");
        assert_eq!(size(512.0), "512 B");
        assert_eq!(size(4.1 * GIB), "4.1 GiB");
        assert_eq!(size(1536.0), "1.5 KiB");
    }

    #[test]
    fn totals_add_work_and_take_the_largest_memory() {
        let p = projection(&[(1e9, 100.0), (2e9, 300.0), (5e8, 200.0)]);
        assert_eq!(p.dof_steps(), 3.5e9);
        assert_eq!(p.trajectory_steps(), 3.5e9 / 20.0);
        assert_eq!(p.peak_samples(), 300.0);
        assert_eq!(p.peak_bytes(), 2400.0);
    }

    #[test]
    fn the_cap_admits_up_to_its_value_and_refuses_above() {
        let p = projection(&[(6e12, 1e6), (4e12, 1e6)]);
        assert!(WorkLimits::default().check(&p).is_ok());
        let at_cap = WorkLimits {
            max_work: 1e13,
            ..WorkLimits::default()
        };
        assert!(at_cap.check(&p).is_ok());
        let m = WorkLimits {
            max_work: 9.99e12,
            ..WorkLimits::default()
        }
        .check(&p)
        .expect_err("above the cap")
        .to_string();
        assert!(m.starts_with("s.toml: key `runs[0].full`: "), "{m}");
        assert!(
            m.contains("must be at most 9.99e12 DOF-steps (--max-work)"),
            "{m}"
        );
        assert!(
            m.contains("got 1e13 DOF-steps (5e11 trajectory steps"),
            "{m}"
        );
        assert!(
            m.contains("the largest of its 2 parts by work: s runs[0] (r0)"),
            "{m}"
        );
        assert!(m.contains("--max-work 1e13"), "{m}");
        assert!(!m.contains("--max-memory-gib 0"), "{m}");
    }

    #[test]
    fn memory_above_its_cap_is_refused_naming_the_largest_part() {
        let p = projection(&[(1e9, 1e6), (1e9, 1e9)]);
        let e = WorkLimits::default()
            .check(&p)
            .expect_err("8 GB of samples");
        assert_eq!(e.exit_code(), 2);
        let m = e.to_string();
        assert!(m.contains("key `runs[1].full`"), "{m}");
        assert!(m.contains("7.5 GiB of samples"), "{m}");
        assert!(m.contains("--max-memory-gib 7.5"), "{m}");
        assert!(!m.contains("--max-work 2"), "{m}");
    }

    #[test]
    fn a_non_finite_projection_is_refused() {
        let p = projection(&[(f64::NAN, 1.0), (1.0, 1.0)]);
        assert!(WorkLimits::default().check(&p).is_err());
        let p = projection(&[(f64::INFINITY, 1.0)]);
        assert!(WorkLimits::default().check(&p).is_err());
    }
}
