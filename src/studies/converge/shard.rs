//! A convergence study split into shards and merged (issue #15; the format and the
//! checks of a shard set are [`crate::shard`]'s).
//!
//! At every value of the study, shard `I/N` simulates its share of the trajectories
//! ([`Shard::range`]; every strain's for a compression study) and writes their records
//! (`records/<scene>/<run>/<over>=<value>.lin|frc`), or, if its share diverged, the
//! failure (`….failed`, the [`FailedValue`] as JSON). The merge
//! reads every shard's records of a value in trajectory order, or takes the first
//! shard's failure in shard order, which is the failure of the smallest failing
//! trajectory, as the whole study records it; everything else is the whole study's code.

use super::{ConvergeOptions, FailedValue, Over};
use crate::dynamics::IntegratorKind;
use crate::error::{Error, Result};
use crate::scene::compression::{CompressionRun, ForceRecord};
use crate::scene::linear::{LinearRun, TrajectoryRecord};
use crate::scene::records::{decode_force, decode_linear, encode_force, encode_linear};
use crate::scene::{Budget, Ensemble, Scene};
use crate::shard::{Shard, ShardSet, ShardWriter, files_key};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// The name of the command in a convergence shard's manifest.
pub const COMMAND: &str = "converge";
/// Extension of the file of a value whose share failed.
const FAILED_EXT: &str = "failed";

/// The options of a study that shape its results, as a shard's manifest keeps them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergeSettings {
    /// [`ConvergeOptions::run`].
    pub run: Option<String>,
    /// [`ConvergeOptions::over`].
    pub over: Over,
    /// [`ConvergeOptions::values`].
    pub values: Option<Vec<f64>>,
    /// [`ConvergeOptions::integrator`], by name.
    pub integrator: Option<String>,
    /// [`ConvergeOptions::strain_ratios`].
    pub strain_ratios: Option<Vec<f64>>,
    /// [`ConvergeOptions::budget`].
    pub budget: Budget,
    /// [`ConvergeOptions::trajectories`].
    pub trajectories: Option<usize>,
    /// [`ConvergeOptions::duration_tau1`].
    pub duration_tau1: Option<f64>,
}

impl ConvergeSettings {
    /// The settings of `opts`.
    pub fn of(opts: &ConvergeOptions) -> ConvergeSettings {
        ConvergeSettings {
            run: opts.run.clone(),
            over: opts.over,
            values: opts.values.clone(),
            integrator: opts.integrator.map(|k| k.name().to_string()),
            strain_ratios: opts.strain_ratios.clone(),
            budget: opts.budget,
            trajectories: opts.trajectories,
            duration_tau1: opts.duration_tau1,
        }
    }

    /// These settings as JSON (floats round-trip exactly: serde_json's `float_roundtrip`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a value is not finite (not representable in JSON).
    pub fn to_json(&self) -> Result<serde_json::Value> {
        serde_json::to_value(self)
            .map_err(|e| Error::invalid("convergence settings", "not JSON", e.to_string()))
    }

    /// The settings of a converge shard set.
    ///
    /// # Errors
    /// [`Error::Scene`] naming the first manifest if they do not parse.
    pub fn of_set(set: &ShardSet) -> Result<ConvergeSettings> {
        serde_json::from_value(set.manifest().settings.clone()).map_err(|e| {
            set.refuse(
                "settings",
                format!("not the settings of a convergence study: {e}"),
            )
        })
    }

    /// Applies these settings to `opts` (whose scene, output and limits are kept).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an unknown integrator name.
    pub fn apply(&self, opts: &mut ConvergeOptions) -> Result<()> {
        opts.run = self.run.clone();
        opts.over = self.over;
        opts.values = self.values.clone();
        opts.integrator = self
            .integrator
            .as_deref()
            .map(|n| {
                IntegratorKind::ALL
                    .into_iter()
                    .find(|k| k.name() == n)
                    .ok_or_else(|| Error::invalid("settings.integrator", n, "an integrator name"))
            })
            .transpose()?;
        opts.strain_ratios = self.strain_ratios.clone();
        opts.budget = self.budget;
        opts.trajectories = self.trajectories;
        opts.duration_tau1 = self.duration_tau1;
        Ok(())
    }
}

/// What one value of a study got from its [`Source`].
pub(super) enum Outcome<T> {
    /// Every trajectory's records.
    Records(T),
    /// This shard's records were written: nothing to estimate here.
    Written,
    /// The value failed (a divergence or an estimator failure).
    Failed(FailedValue),
}

/// Where a study's trajectories come from.
pub(super) enum Source<'a> {
    /// Every trajectory simulated here.
    Simulate,
    /// This shard's share simulated and written.
    Shard(Box<ShardWriter>),
    /// Every shard's records read.
    Merge(&'a ShardSet),
}

/// The key of one value of a study in a shard: `<run>/<over>=<value>`.
fn value_key(run: &str, over: Over, v: f64) -> String {
    format!("{run}/{}={v}", over.name())
}

impl Source<'_> {
    /// The trajectories `range` of value `v` by `simulate(range)`, handled as the source
    /// says: all simulated, this shard's written with `encode`, or every shard's read
    /// with `decode` and joined with `join`.
    fn value<T>(
        &mut self,
        (scene, key, v): (&Scene, &str, f64),
        total: u64,
        simulate: impl FnOnce(Range<u64>) -> Result<T>,
        (encode, ext): (impl Fn(&T) -> Vec<u8>, &str),
        merged: impl FnOnce(&ShardSet) -> Result<Outcome<T>>,
    ) -> Result<Outcome<T>> {
        match self {
            Source::Simulate => match simulate(0..total) {
                Ok(r) => Ok(Outcome::Records(r)),
                Err(e) => Ok(Outcome::Failed(FailedValue::record(v, e)?)),
            },
            Source::Shard(writer) => {
                let range = writer.shard().range(total);
                let (bytes, ext) = match simulate(range.clone()) {
                    Ok(r) => (encode(&r), ext),
                    Err(e) => {
                        let f = FailedValue::record(v, e)?;
                        let text = serde_json::to_vec(&f)
                            .map_err(|e| Error::io(writer.dir(), std::io::Error::other(e)))?;
                        (text, FAILED_EXT)
                    }
                };
                writer.write(
                    (&scene.name, key, ext),
                    range,
                    &bytes,
                    serde_json::Value::Null,
                )?;
                Ok(Outcome::Written)
            }
            Source::Merge(set) => merged(set),
        }
    }

    /// The records of value `v` of a linear study (`simulate(first, count)` simulates
    /// trajectories `first..first + count` of `e`).
    pub(super) fn linear(
        &mut self,
        (scene, run, over, v): (&Scene, &str, Over, f64),
        (e, lr): (&Ensemble, &LinearRun),
        simulate: impl FnOnce(u64, u64) -> Result<Vec<TrajectoryRecord>>,
    ) -> Result<Outcome<Vec<TrajectoryRecord>>> {
        let key = value_key(run, over, v);
        let total = e.trajectories as u64;
        self.value(
            (scene, &key, v),
            total,
            |r| simulate(r.start, r.end - r.start),
            (|r: &Vec<TrajectoryRecord>| encode_linear(r, &[]), "lin"),
            |set| {
                let mut all = Vec::new();
                for part in read_value(set, scene, &key)? {
                    match part {
                        Part::Failed(f) => return Ok(Outcome::Failed(f)),
                        Part::Bytes(source, bytes) => {
                            all.extend(decode_linear(&bytes, &source)?.0);
                        }
                    }
                }
                counted(set, scene, &key, all.len(), e.trajectories)?;
                if let Some(why) = lr.records_shape_error(&all, &[]) {
                    return Err(refuse(set, scene, &key, why));
                }
                Ok(Outcome::Records(all))
            },
        )
    }

    /// The records per strain of value `v` of a compression study (`simulate(range)`
    /// simulates trajectories `range` at every strain).
    pub(super) fn force(
        &mut self,
        (scene, run, over, v): (&Scene, &str, Over, f64),
        (e, cr): (&Ensemble, &CompressionRun),
        simulate: impl FnOnce(Range<u64>) -> Result<Vec<Vec<ForceRecord>>>,
    ) -> Result<Outcome<Vec<Vec<ForceRecord>>>> {
        let strains = cr.points();
        let key = value_key(run, over, v);
        let total = e.trajectories.max(1) as u64;
        self.value(
            (scene, &key, v),
            total,
            simulate,
            (|r: &Vec<Vec<ForceRecord>>| encode_force(r), "frc"),
            |set| {
                let mut all: Vec<Vec<ForceRecord>> = vec![Vec::new(); strains];
                for part in read_value(set, scene, &key)? {
                    match part {
                        Part::Failed(f) => return Ok(Outcome::Failed(f)),
                        Part::Bytes(source, bytes) => {
                            let share = decode_force(&bytes, &source)?;
                            counted(set, scene, &key, share.len(), strains)?;
                            for (a, p) in all.iter_mut().zip(share) {
                                a.extend(p);
                            }
                        }
                    }
                }
                for a in &all {
                    counted(set, scene, &key, a.len(), total as usize)?;
                }
                if let Some(why) = cr.records_shape_error(&all) {
                    return Err(refuse(set, scene, &key, why));
                }
                Ok(Outcome::Records(all))
            },
        )
    }

    /// The fraction of the trajectories this source simulates: 1/N for a shard, 1 for a
    /// whole study, 0 for a merge.
    pub(super) fn fraction(&self) -> f64 {
        match self {
            Source::Simulate => 1.0,
            Source::Shard(w) => w.shard().fraction(),
            Source::Merge(_) => 0.0,
        }
    }

    /// Finishes a shard's manifest, if this is a shard.
    ///
    /// # Errors
    /// I/O errors writing it.
    pub(super) fn finish(self) -> Result<Option<crate::shard::ShardManifest>> {
        match self {
            Source::Shard(w) => w.finish().map(Some),
            _ => Ok(None),
        }
    }
}

/// One shard's part of a value: its records' bytes (with the file's path and shard, in
/// words) or its failure.
enum Part {
    Bytes(String, Vec<u8>),
    Failed(FailedValue),
}

/// Every shard's part of value `key`, in shard order.
fn read_value(set: &ShardSet, scene: &Scene, key: &str) -> Result<Vec<Part>> {
    set.read(&scene.name, key)?
        .into_iter()
        .map(|r| {
            if r.file.path.ends_with(&format!(".{FAILED_EXT}")) {
                serde_json::from_slice(&r.bytes)
                    .map(Part::Failed)
                    .map_err(|e| refuse(set, scene, key, format!("{}: {e}", r.source)))
            } else {
                Ok(Part::Bytes(r.source, r.bytes))
            }
        })
        .collect()
}

/// Refuses a merge whose shards do not hold value `key` as the study needs it (exit 2).
fn refuse(set: &ShardSet, scene: &Scene, key: &str, message: String) -> Error {
    set.refuse(&files_key(&scene.name, key), message)
}

/// Refuses `got` records where the study needs `want`.
fn counted(set: &ShardSet, scene: &Scene, key: &str, got: usize, want: usize) -> Result<()> {
    if got == want {
        return Ok(());
    }
    Err(refuse(
        set,
        scene,
        key,
        format!("the shards hold {got} where the study needs {want} (trajectories or strains)"),
    ))
}

/// Shard `shard` of the study `opts`: the check of the input and every value's share
/// of trajectories written to `opts.out` with the manifest; `seed_note` is kept for the
/// merge.
///
/// # Errors
/// As [`super::run_convergence`] before and while it simulates; I/O errors.
pub fn write_convergence_shard(
    opts: &ConvergeOptions,
    shard: Shard,
    seed_note: &str,
) -> Result<crate::shard::ShardManifest> {
    let setup = super::setup(opts)?;
    let writer = ShardWriter::begin(
        &opts.out,
        COMMAND,
        shard,
        ConvergeSettings::of(opts).to_json()?,
        vec![crate::shard::ShardScene::of(&opts.scene, seed_note)],
        setup.provenance.clone(),
    )?;
    let mut source = Source::Shard(Box::new(writer));
    super::study_of(opts, &setup, &mut source)?;
    source
        .finish()?
        .ok_or_else(|| Error::invalid("--shard", shard, "a shard"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::Provenance;
    use crate::shard::ShardScene;

    /// A value whose trajectories 5 and 7 diverge, in 3 shards of 9 trajectories (ranges
    /// 0..3, 3..6, 6..9): each failing shard writes its own smallest failure, and the
    /// merge takes shard 2's, trajectory 5's, which is the whole study's failure (the
    /// error of the smallest failing trajectory); a value without failure reads back
    /// every trajectory in order.
    #[test]
    fn merge_takes_the_failure_of_the_smallest_failing_trajectory() {
        let scene = crate::scene::builtin::find("hinged-linear-2d")
            .expect("built-in scene")
            .load()
            .expect("loads");
        let root = std::env::temp_dir().join(format!(
            "langevin-fem-converge-shard-{}",
            std::process::id()
        ));
        let diverged = |j: u64| Error::Diverged {
            step: 100 + j,
            time: 0.5,
            detail: format!("trajectory {j}"),
        };
        // "Simulates" `range`: the indices, or the error of the first failing one.
        let simulate = |fail: &[u64], r: Range<u64>| -> Result<Vec<u64>> {
            match r.clone().find(|j| fail.contains(j)) {
                Some(j) => Err(diverged(j)),
                None => Ok(r.collect()),
            }
        };
        let encode = |v: &Vec<u64>| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let mut dirs = Vec::new();
        for index in 1..=3 {
            let dir = root.join(index.to_string());
            let writer = ShardWriter::begin(
                &dir,
                COMMAND,
                Shard { index, count: 3 },
                serde_json::json!({}),
                vec![ShardScene::of(&scene, "")],
                Provenance::begin(&[&scene]),
            )
            .unwrap();
            let mut source = Source::Shard(Box::new(writer));
            for (key, fail) in [("run/dt=1", &[5u64, 7][..]), ("run/dt=2", &[][..])] {
                let out = source
                    .value(
                        (&scene, key, 1.0),
                        9,
                        |r| simulate(fail, r),
                        (encode, "bin"),
                        |_| unreachable!(),
                    )
                    .unwrap();
                assert!(matches!(out, Outcome::Written));
            }
            source.finish().unwrap();
            dirs.push(dir);
        }
        let set = ShardSet::open(&dirs, 1 << 30).unwrap();
        let parts = read_value(&set, &scene, "run/dt=1").unwrap();
        let first_failure = parts.into_iter().find_map(|p| match p {
            Part::Failed(f) => Some(f),
            Part::Bytes(..) => None,
        });
        let whole = FailedValue::record(1.0, simulate(&[5, 7], 0..9).unwrap_err()).unwrap();
        assert_eq!(first_failure.map(|f| f.error), Some(whole.error));
        let mut all = Vec::new();
        for p in read_value(&set, &scene, "run/dt=2").unwrap() {
            match p {
                Part::Bytes(_, b) => all.extend(
                    b.chunks(8)
                        .map(|c| u64::from_le_bytes(c.try_into().unwrap())),
                ),
                Part::Failed(f) => panic!("no failure expected: {}", f.error),
            }
        }
        assert_eq!(all, (0..9).collect::<Vec<u64>>());
        let _ = std::fs::remove_dir_all(&root);
    }
}
