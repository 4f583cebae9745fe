//! A verification split into shards and merged (issue #15; the format and the checks of
//! a shard set are [`crate::shard`]'s).
//!
//! [`write_shard`] is `verify --shard I/N`: it checks the input as a whole run does
//! (every scene, every run's set-up, the samples each check will get), then simulates
//! shard `I`'s share of every run that a whole run simulates, and writes each run's
//! per-trajectory records — no checks, no report. A budget by target precision runs its
//! step search and pilot in full in every shard (they depend on the scene alone, and
//! every shard gets the same plan, which the merge checks) and shares the main stage.
//!
//! `merge` is [`super::run_verification`] with [`super::runner::Ensembles::Merge`]: the
//! records of every run are read here (`merged_linear`, `merged_compression`) in
//! trajectory order, and everything else — references, checks, the family-wise
//! correction, tables, figures, the report — is the whole run's code on the whole run's
//! records, so the outputs are the whole run's.

use super::runner::{
    Prepared, TargetedPlan, VerifyOptions, begin_run, for_compression_runs, prepare_all,
    projected_work, simulate_compression, simulate_linear,
};
use crate::error::{Error, Result};
use crate::output::Provenance;
use crate::progress::Progress;
use crate::scene::compression::{CompressionRun, ForceRecord, StepChoice};
use crate::scene::linear::{LinearRun, TrajectoryRecord};
use crate::scene::records::{decode_force, decode_linear, encode_force, encode_linear};
use crate::scene::{Ensemble, Scene};
use crate::shard::{Shard, ShardManifest, ShardScene, ShardSet, ShardWriter, files_key, refuse};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The name of the command in a verification shard's manifest.
pub const COMMAND: &str = "verify";
/// Extension of a linear run's record file ([`encode_linear`]).
const LINEAR_EXT: &str = "lin";
/// Extension of a compression run's record file ([`encode_force`]).
const FORCE_EXT: &str = "frc";

/// The settings of a verification that shape its results: equal in every shard of a set,
/// and the merge's.
fn settings(opts: &VerifyOptions) -> serde_json::Value {
    serde_json::json!({
        "budget": opts.budget.name(),
        "alpha": opts.alpha,
    })
}

/// The budget and α of a verification shard set (its manifest's settings).
///
/// # Errors
/// [`Error::Scene`] naming the first shard's manifest if they are missing or invalid.
pub fn settings_of(set: &ShardSet) -> Result<(crate::scene::Budget, f64)> {
    let s = &set.manifest().settings;
    let budget: Option<crate::scene::Budget> = serde_json::from_value(s["budget"].clone()).ok();
    let alpha = s["alpha"].as_f64();
    match (budget, alpha) {
        (Some(b), Some(a)) => Ok((b, a)),
        _ => Err(set.refuse(
            "settings",
            format!("{s}: a budget name and a number alpha are required"),
        )),
    }
}

/// Runs shard `shard` of the verification `opts` (see the [module docs](self)) into
/// `opts.out`; `seed_notes` are the reports' notes on each scene's seed, kept for the
/// merge. With `plan_from`, a finished shard of the same set, a budget by target
/// precision takes that shard's plans instead of running its step search and pilot
/// again (`verify --plan-from`). Returns the manifest written.
///
/// # Errors
/// As [`super::run_verification`] before and while it simulates (input: exit 2; a run
/// failure: exit 3); `plan_from` not a shard of the same set, or without a run's plan
/// (exit 2); I/O errors writing the shard.
pub fn write_shard(
    opts: &VerifyOptions,
    shard: Shard,
    seed_notes: &[String],
    plan_from: Option<&Path>,
) -> Result<ShardManifest> {
    let scenes = &opts.scenes;
    let provenance = Provenance::begin(&scenes.iter().collect::<Vec<_>>());
    let work = projected_work(scenes, opts.budget).scaled(shard.fraction());
    opts.limits.check(&work)?;
    let prepared = prepare_all(scenes, opts.budget)?;
    let described = scenes
        .iter()
        .zip(seed_notes)
        .map(|(s, n)| ShardScene::of(s, n))
        .collect();
    let writer = ShardWriter::new(
        &opts.out,
        COMMAND,
        shard,
        settings(opts),
        described,
        provenance,
    );
    // The shard of --plan-from is input: checked before the earlier shard in opts.out is
    // touched.
    let plans = plan_from
        .map(|dir| -> Result<(PathBuf, ShardManifest)> {
            let m = ShardManifest::read(dir).map_err(|e| plan_from_error(dir, e))?;
            m.check_same_set(dir, writer.manifest(), &opts.out)
                .map_err(|e| plan_from_error(dir, e))?;
            Ok((dir.to_path_buf(), m))
        })
        .transpose()?;
    let mut writer = writer.start()?;
    let bar = Progress::new(opts.progress, work.dof_steps(), "DOF-steps");
    for (scene, prepared) in scenes.iter().zip(&prepared) {
        match prepared {
            Prepared::Linear(runs, oracles) => {
                for (k, run) in runs.iter().enumerate() {
                    // As in a whole run: a run whose references fail the oracle is not
                    // simulated.
                    if oracles[k].passed() {
                        begin_run(&bar, scene, k, opts.budget, shard.fraction());
                        write_linear(opts, scene, k, run, &bar, &mut writer)?;
                    }
                }
            }
            Prepared::Compression(_, oracle, runs) if oracle.passed() => {
                for_compression_runs(scene, runs, |k, run| {
                    begin_run(&bar, scene, k, opts.budget, shard.fraction());
                    write_compression(opts, (scene, k, run), plans.as_ref(), &bar, &mut writer)
                })?;
            }
            Prepared::Compression(..) => {}
        }
    }
    bar.finish();
    writer.finish()
}

/// The refusal of `verify --plan-from DIR` (exit 2): names the flag and the directory
/// given, with what is wrong (`e`: the manifest, its key and why).
fn plan_from_error(dir: &Path, e: Error) -> Error {
    Error::invalid(
        "--plan-from",
        dir.display(),
        format!(
            "a finished shard of the same set (the same build, settings, scenes, seeds and shard count), holding the plan of every run with a budget by target precision; {e}"
        ),
    )
}

/// Simulates and writes the writer's share of linear run `k`.
fn write_linear(
    opts: &VerifyOptions,
    scene: &Scene,
    k: usize,
    run: &LinearRun,
    bar: &Progress,
    writer: &mut ShardWriter,
) -> Result<()> {
    let e = run.spec.ensemble(opts.budget);
    let (records, extra) = simulate_linear(scene, k, run, &e, bar, writer.shard())?;
    writer.write(
        (&scene.name, &run.spec.name, LINEAR_EXT),
        writer.shard().range(e.trajectories as u64),
        &encode_linear(&records, &extra),
        serde_json::Value::Null,
    )
}

/// Simulates and writes the writer's share of compression run `k`, with its plan (that
/// of the shard `plans`, if given); returns the steps its step search chose, if any (for
/// the Δt-halving pair).
fn write_compression(
    opts: &VerifyOptions,
    (scene, k, run): (&Scene, usize, &CompressionRun),
    plans: Option<&(PathBuf, ShardManifest)>,
    bar: &Progress,
    writer: &mut ShardWriter,
) -> Result<Option<Vec<f64>>> {
    let e = run.spec.ensemble(opts.budget);
    let known = match (plans, e.precision_target()) {
        (Some((dir, m)), Some(target)) => {
            let entry = m
                .files
                .iter()
                .find(|f| f.scene == scene.name && f.run == run.spec.name);
            let refuse = |message: String| {
                let key = files_key(&scene.name, &run.spec.name);
                plan_from_error(dir, refuse(dir, &key, message))
            };
            let common = entry
                .map(|f| &f.common)
                .ok_or_else(|| refuse("no plan of this run".to_string()))?;
            let tau1 = scene.tau1();
            Some(decode_plan(common, target, run, tau1).map_err(refuse)?)
        }
        _ => None,
    };
    let (records, plan) =
        simulate_compression(scene, k, run, &e, opts.budget, bar, (writer.shard(), known))?;
    let common = match &plan {
        Some(p) => serde_json::to_value(PlanBits::of(p))
            .map_err(|e| Error::io(&opts.out, std::io::Error::other(e)))?,
        None => serde_json::Value::Null,
    };
    writer.write(
        (&scene.name, &run.spec.name, FORCE_EXT),
        writer.shard().range(e.trajectories.max(1) as u64),
        &encode_force(&records),
        common,
    )?;
    Ok(plan
        .and_then(|p| p.search)
        .map(|s| s.iter().map(|c| c.dt_tau1).collect()))
}

/// The refusal of a merge whose shards do not hold what run `run` of `scene` needs.
fn incomplete(set: &ShardSet, scene: &Scene, run: &str, message: String) -> Error {
    set.refuse(&files_key(&scene.name, run), message)
}

/// The records of linear run `run` of `scene` from every shard, in trajectory order:
/// the full trajectories' records and the extra two-time trajectories' products, as
/// [`simulate_linear`] returns them for the whole ensemble `e`.
///
/// # Errors
/// [`Error::Scene`] (exit 2): a shard's file is missing, damaged ([`ShardSet::read`],
/// [`decode_linear`]) or the shards together do not hold `e`'s trajectories.
pub(super) fn merged_linear(
    set: &ShardSet,
    scene: &Scene,
    run: &LinearRun,
    e: &Ensemble,
) -> Result<(Vec<TrajectoryRecord>, Vec<Vec<f64>>)> {
    let (mut records, mut extra) = (Vec::new(), Vec::new());
    for file in set.read(&scene.name, &run.spec.name)? {
        let (r, x) = decode_linear(&file.bytes, &file.source)?;
        records.extend(r);
        extra.extend(x);
    }
    if let Some(why) = run.records_shape_error(&records, &extra) {
        return Err(incomplete(set, scene, &run.spec.name, why));
    }
    if records.len() != e.trajectories || extra.len() != e.two_time_trajectories {
        return Err(incomplete(
            set,
            scene,
            &run.spec.name,
            format!(
                "the shards hold {} trajectories and {} two-time trajectories, the budget {} and {}",
                records.len(),
                extra.len(),
                e.trajectories,
                e.two_time_trajectories
            ),
        ));
    }
    Ok((records, extra))
}

/// The records per strain of compression run `run` of `scene` from every shard, in
/// trajectory order, and its plan (every shard's, checked equal by [`ShardSet::read`]),
/// as [`simulate_compression`] returns them for the whole ensemble `e`.
///
/// # Errors
/// [`Error::Scene`] (exit 2): a shard's file is missing or damaged, the shards together
/// do not hold `e`'s trajectories at every strain, or the plan is unreadable.
pub(super) fn merged_compression(
    set: &ShardSet,
    scene: &Scene,
    run: &CompressionRun,
    e: &Ensemble,
) -> Result<(Vec<Vec<ForceRecord>>, Option<TargetedPlan>)> {
    let name = &run.spec.name;
    let files = set.read(&scene.name, name)?;
    let mut records: Vec<Vec<ForceRecord>> = vec![Vec::new(); run.points()];
    for file in &files {
        let share = decode_force(&file.bytes, &file.source)?;
        if share.len() != run.points() {
            return Err(incomplete(
                set,
                scene,
                name,
                format!(
                    "{} has {} strains, the scene {}",
                    file.source,
                    share.len(),
                    run.points()
                ),
            ));
        }
        for (all, part) in records.iter_mut().zip(share) {
            all.extend(part);
        }
    }
    let want = e.trajectories.max(1);
    if let Some(n) = records.iter().map(Vec::len).find(|&n| n != want) {
        return Err(incomplete(
            set,
            scene,
            name,
            format!("the shards hold {n} trajectories at a strain, the budget {want}"),
        ));
    }
    let plan = match e.precision_target() {
        None => None,
        Some(target) => Some(
            decode_plan(&files[0].file.common, target, run, scene.tau1())
                .map_err(|m| incomplete(set, scene, name, m))?,
        ),
    };
    // The records' shapes: those of the run the plan's steps give.
    let adapted = match plan.as_ref().and_then(|p| p.search.as_ref()) {
        Some(s) => Some(run.with_steps(&s.iter().map(|c| c.dt_tau1).collect::<Vec<_>>())?),
        None => None,
    };
    if let Some(why) = adapted
        .as_ref()
        .unwrap_or(run)
        .records_shape_error(&records)
    {
        return Err(incomplete(set, scene, name, why));
    }
    Ok((records, plan))
}

/// The plan a shard manifest lists for compression run `run` (a file's `common`), checked
/// to be one this build could have chosen for it (τ1 = `tau1`): one value per strain;
/// every duration finite, positive and at most the target's longest; the main stage's
/// steps those of its duration (so that the work stays the scene's projected work); the
/// steps of a step search finite, positive and at most its largest step. The error says
/// what is wrong.
fn decode_plan(
    common: &serde_json::Value,
    target: crate::scene::PrecisionTarget,
    run: &CompressionRun,
    tau1: f64,
) -> std::result::Result<TargetedPlan, String> {
    let points = run.points();
    let bits: PlanBits = serde_path_to_error::deserialize(common.clone()).map_err(|e| {
        format!(
            "no readable plan: common.{}: {} (the plan's floats are written as their bits, u64)",
            e.path(),
            e.inner()
        )
    })?;
    let plan = bits.plan(target);
    for (key, len) in [
        ("pilot_std_error", plan.pilot_std_error.len()),
        ("main_tau1", plan.main_tau1.len()),
        ("main_steps", plan.main_steps.len()),
        ("search", plan.search.as_ref().map_or(points, Vec::len)),
    ] {
        if len != points {
            return Err(format!(
                "common.{key} holds {len} values, but the plan needs one per strain ({points})"
            ));
        }
    }
    let longest = target.max_duration_tau1 * (1.0 + 1e-9);
    let duration = |key: String, d: f64| {
        if d.is_finite() && d > 0.0 && d <= longest {
            Ok(())
        } else {
            Err(format!(
                "common.{key} = {d} tau1, but a duration in (0, {}] tau1 (the budget's max_duration_tau1) is required",
                target.max_duration_tau1
            ))
        }
    };
    duration("pilot_tau1".into(), plan.pilot_tau1)?;
    if let Some((i, se)) = plan
        .pilot_std_error
        .iter()
        .enumerate()
        .find(|(_, s)| !(s.is_finite() && **s >= 0.0))
    {
        return Err(format!(
            "common.pilot_std_error[{i}] = {se}, but a finite standard error >= 0 is required"
        ));
    }
    if let (Some(search), Some(rule)) = (&plan.search, target.step_search)
        && let Some((i, c)) = search.iter().enumerate().find(|(_, c)| {
            !(c.dt_tau1.is_finite() && c.dt_tau1 > 0.0 && c.dt_tau1 <= rule.max_dt_tau1)
        })
    {
        return Err(format!(
            "common.search[{i}] chose dt = {} tau1, but a step in (0, {}] tau1 (the budget's max_dt_tau1) is required",
            c.dt_tau1, rule.max_dt_tau1
        ));
    }
    let adapted = match &plan.search {
        Some(s) => Some(
            run.with_steps(&s.iter().map(|c| c.dt_tau1).collect::<Vec<_>>())
                .map_err(|e| format!("common.search: {e}"))?,
        ),
        None => None,
    };
    let stepped = adapted.as_ref().unwrap_or(run);
    for (i, (&d, &n)) in plan.main_tau1.iter().zip(&plan.main_steps).enumerate() {
        duration(format!("main_tau1[{i}]"), d)?;
        let want = stepped.sampled_steps_at(i, d * tau1);
        if n != want {
            return Err(format!(
                "common.main_steps[{i}] = {n}, but its duration common.main_tau1[{i}] = {d} tau1 is {want} steps"
            ));
        }
    }
    Ok(plan)
}

/// A [`TargetedPlan`] in JSON with every float as its bits (exact), for the manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct PlanBits {
    pilot_tau1: u64,
    pilot_std_error: Vec<u64>,
    main_tau1: Vec<u64>,
    main_steps: Vec<u64>,
    /// Per strain: the chosen step and the candidates tried (step, acceptance).
    search: Option<Vec<ChoiceBits>>,
}

/// A [`StepChoice`] as bits: the chosen step and the candidates (step, acceptance).
type ChoiceBits = (u64, Vec<(u64, u64)>);

impl PlanBits {
    fn of(p: &TargetedPlan) -> PlanBits {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect();
        PlanBits {
            pilot_tau1: p.pilot_tau1.to_bits(),
            pilot_std_error: bits(&p.pilot_std_error),
            main_tau1: bits(&p.main_tau1),
            main_steps: p.main_steps.clone(),
            search: p.search.as_ref().map(|s| {
                s.iter()
                    .map(|c| {
                        let tried = c.tried.iter().map(|t| (t.0.to_bits(), t.1.to_bits()));
                        (c.dt_tau1.to_bits(), tried.collect())
                    })
                    .collect()
            }),
        }
    }

    fn plan(&self, target: crate::scene::PrecisionTarget) -> TargetedPlan {
        let floats = |v: &[u64]| v.iter().map(|&b| f64::from_bits(b)).collect();
        TargetedPlan {
            target,
            pilot_tau1: f64::from_bits(self.pilot_tau1),
            pilot_std_error: floats(&self.pilot_std_error),
            main_tau1: floats(&self.main_tau1),
            main_steps: self.main_steps.clone(),
            search: self.search.as_ref().map(|s| {
                s.iter()
                    .map(|(dt, tried)| StepChoice {
                        dt_tau1: f64::from_bits(*dt),
                        tried: tried
                            .iter()
                            .map(|&(a, b)| (f64::from_bits(a), f64::from_bits(b)))
                            .collect(),
                    })
                    .collect()
            }),
        }
    }
}
