//! `langevin-fem merge` of `run` shards (issue #15): the whole run's directory assembled
//! from the shards' trajectory files.
//!
//! The job is rebuilt from the first shard's manifest (the scene text, the seed as run and
//! the [`RunSettings`]); the merge then checks, before it writes anything, that the
//! shards' files cover every trajectory of every chosen run (per strain for a
//! compression run) exactly once under the whole run's relative names, and copies each
//! file — checked against the manifest's size and SHA-256 — to the same relative path,
//! listed in the journal as the whole run lists it. `data.json` is the whole run's, built
//! by the same code from the same prepared runs. Since trajectory `j`'s file depends only
//! on the seed, `j` and the settings, the merged directory is the whole run's byte for
//! byte, apart from the run id and the provenance in `data.json` and `manifest.json`.

use super::{
    Job, RunSettings, Sink, Verbosity, compression_data_runs, compression_file, compression_what,
    linear_data_run, linear_file, linear_what, prepare_compression, prepare_linear, strain_key,
};
use langevin_fem::data::{COMPRESSION_COLUMNS, read_table};
use langevin_fem::error::{Error, Result};
use langevin_fem::output::io::write_atomic;
use langevin_fem::shard::{Shard, ShardFile, ShardSet, files_key, refuse};
use langevin_fem::work::WorkLimits;
use std::path::Path;

/// One run's files in the whole run: the shard-manifest key (`<run>` or
/// `<run>/strain-NN`), the relative name of each trajectory's file, in order, and what
/// each file must hold: its columns and, where known, its rows.
type Expected = (String, Vec<String>, Layout);

/// What each trajectory file of a run holds: the columns of the data format, in order,
/// and the rows (for a linear run; a compression run's rows depend on its strain's plan).
#[derive(Clone)]
struct Layout {
    columns: Vec<String>,
    rows: Option<u64>,
}

/// Where each file of one run comes from: the shard (0-based, in shard order) and its
/// manifest entry, in trajectory order.
type Sources<'a> = Vec<(usize, &'a ShardFile)>;

/// Merges the shards of one `run` into `out` (see the [module docs](self)); exit code 0.
///
/// # Errors
/// [`Error::Scene`] (exit 2) naming a shard's manifest: settings that are not a run's,
/// not exactly one scene, a trajectory file missing, given twice, misnamed or foreign, a
/// file damaged; as `run` for a scene that no longer prepares; I/O errors writing `out`.
pub fn merge(set: ShardSet, out: &Path, verbosity: Verbosity) -> Result<i32> {
    let first = set.shards[0].0.clone();
    let manifest = set.manifest();
    let settings: RunSettings = serde_json::from_value(manifest.settings.clone()).map_err(|e| {
        refuse(
            &first,
            "settings",
            format!("{}: not the settings of a run ({e})", manifest.settings),
        )
    })?;
    let mut scenes = set.scenes()?;
    if scenes.len() != 1 {
        return Err(refuse(
            &first,
            "scenes",
            format!("{} scenes, but a run shard holds exactly one", scenes.len()),
        ));
    }
    let (scene, seed_note) = scenes.remove(0);
    if verbosity.shows_progress() {
        eprintln!(
            "merging {} shards of run (scene {}, budget {}, {} run(s))",
            set.shards.len(),
            scene.name,
            settings.budget.name(),
            settings.runs.len()
        );
    }
    // The settings were checked when the shards ran: a value the run refuses now is a
    // damaged manifest (named as such by `settings_error`).
    let job = Job::new(
        settings,
        scene,
        seed_note,
        out.to_path_buf(),
        verbosity,
        (None, WorkLimits::default()),
    )
    .map_err(|e| set.settings_error(e))?;
    if job.scene.compression.is_some() {
        merge_compression(&set, &job)
    } else {
        merge_linear(&set, &job)
    }
    .map_err(|e| set.settings_error(e))
}

/// The merge of a linear scene's run shards.
fn merge_linear(set: &ShardSet, job: &Job) -> Result<i32> {
    let (runs, plans) = prepare_linear(job)?;
    let expected: Vec<Expected> = job
        .chosen
        .iter()
        .zip(&plans)
        .map(|(&k, plan)| {
            let name = &job.scene.runs[k].name;
            let count = job.ensemble(k).0 as u64;
            let files = (0..count)
                .map(|j| linear_file(name, j, job.ext()))
                .collect();
            let layout = Layout {
                columns: plan.columns.clone(),
                rows: Some(plan.rows),
            };
            (name.clone(), files, layout)
        })
        .collect();
    let sink = copy_files(set, job, &expected)?;
    let data_runs = job
        .chosen
        .iter()
        .zip(&runs)
        .zip(&plans)
        .zip(expected)
        .map(|(((&k, run), plan), (_, files, _))| linear_data_run(job, k, run, plan, files))
        .collect();
    job.finish(sink, data_runs, None, linear_what(job))
}

/// The merge of a compression scene's run shards.
fn merge_compression(set: &ShardSet, job: &Job) -> Result<i32> {
    let runs = prepare_compression(job)?;
    let mut expected: Vec<Expected> = Vec::new();
    for (&k, run) in job.chosen.iter().zip(&runs) {
        let name = &job.scene.runs[k].name;
        let count = job.ensemble(k).0 as u64;
        for i in 0..run.points() {
            let files = (0..count)
                .map(|j| compression_file(name, i, j, job.ext()))
                .collect();
            let layout = Layout {
                columns: COMPRESSION_COLUMNS.iter().map(|c| c.to_string()).collect(),
                rows: None,
            };
            expected.push((strain_key(name, i), files, layout));
        }
    }
    let sink = copy_files(set, job, &expected)?;
    let data_runs = job
        .chosen
        .iter()
        .zip(&runs)
        .flat_map(|(&k, run)| compression_data_runs(job, k, run, job.ensemble(k).0 as u64))
        .collect();
    let ea = Some(job.scene.filament.stretch_rigidity);
    job.finish(sink, data_runs, ea, compression_what(job))
}

/// Checks that the shards cover `expected` exactly, then starts the whole run's
/// directory and copies every file there (checked, atomically, listed in the journal).
fn copy_files(set: &ShardSet, job: &Job, expected: &[Expected]) -> Result<Sink> {
    let scene = &job.scene.name;
    refuse_foreign(set, scene, expected)?;
    let sources = expected
        .iter()
        .map(|(key, files, _)| cover(set, scene, key, files))
        .collect::<Result<Vec<_>>>()?;
    let sink = job.begin()?;
    for ((_, files, layout), sources) in expected.iter().zip(&sources) {
        for (rel, &(k, entry)) in files.iter().zip(sources) {
            let bytes = set.read_file(k, entry)?;
            check_trajectory(set, (k, entry), layout)?;
            write_atomic(&sink.record(&job.out, rel)?, &bytes)?;
        }
    }
    Ok(sink)
}

/// Refuses the trajectory file `entry` of shard `k` unless it holds what `run` writes:
/// the data format's columns, every value finite ([`read_table`]), and the run's rows.
/// Its hash only says that it is the file the shard listed: a manifest edited to match a
/// damaged file is caught here, before the file is copied.
fn check_trajectory(
    set: &ShardSet,
    (k, entry): (usize, &ShardFile),
    layout: &Layout,
) -> Result<()> {
    let dir = &set.shards[k].0;
    let key = files_key(&entry.scene, &entry.run);
    let path = dir.join(&entry.path);
    let table = read_table(&path, &key, &layout.columns, set.max_bytes())?;
    match layout.rows {
        Some(rows) if table.rows as u64 != rows => Err(refuse(
            dir,
            &key,
            format!(
                "{} holds {} rows, but run {} writes {rows} rows per trajectory: damaged or not this run's",
                path.display(),
                table.rows,
                entry.run
            ),
        )),
        _ => Ok(()),
    }
}

/// Refuses a file of a shard that belongs to no run of `expected` (another scene, or a
/// run the settings do not choose).
fn refuse_foreign(set: &ShardSet, scene: &str, expected: &[Expected]) -> Result<()> {
    for (dir, m) in &set.shards {
        if let Some(f) = m
            .files
            .iter()
            .find(|f| f.scene != scene || !expected.iter().any(|(key, ..)| *key == f.run))
        {
            let keys: Vec<&str> = expected.iter().map(|(key, ..)| key.as_str()).collect();
            return Err(refuse(
                dir,
                &files_key(&f.scene, &f.run),
                format!(
                    "{} is of {}/{}, which this run does not write (its runs: {scene}/{{{}}}): not a shard of this run",
                    f.path,
                    f.scene,
                    f.run,
                    keys.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The source of each of `files` (run `key` of `scene`, trajectory `j` in `files[j]`):
/// exactly one shard file each, one trajectory long, under the whole run's name.
///
/// # Errors
/// [`Error::Scene`] (exit 2) naming the shard: a file of another range or name, a
/// trajectory given twice (naming both shards), a trajectory in no shard (naming the
/// shard whose share it is).
fn cover<'a>(
    set: &'a ShardSet,
    scene: &'a str,
    key: &'a str,
    files: &[String],
) -> Result<Sources<'a>> {
    let what = files_key(scene, key);
    let total = files.len() as u64;
    let mut slots: Vec<Option<(usize, &ShardFile)>> = vec![None; files.len()];
    for (k, f) in set.files(scene, key) {
        let dir = &set.shards[k].0;
        let j = f.first;
        if f.count != 1 || j >= total || f.path != files[j as usize] {
            return Err(refuse(
                dir,
                &what,
                format!(
                    "{} holds trajectories {}..{}, but run {key} has trajectories 0..{total}, one file each named as in the whole run ({})",
                    f.path,
                    j,
                    j.saturating_add(f.count),
                    files.first().map_or("none", String::as_str)
                ),
            ));
        }
        if let Some((other, _)) = slots[j as usize] {
            return Err(refuse(
                dir,
                &what,
                format!(
                    "trajectory {j} of {scene}/{key} ({}) given twice: by shard {} ({}) and by shard {} ({})",
                    f.path,
                    set.shards[other].1.shard,
                    set.shards[other].0.display(),
                    set.shards[k].1.shard,
                    dir.display()
                ),
            ));
        }
        slots[j as usize] = Some((k, f));
    }
    slots
        .iter()
        .enumerate()
        .map(|(j, slot)| slot.ok_or_else(|| missing(set, scene, key, files, j as u64)))
        .collect()
}

/// The refusal of trajectory `j` of run `key` in no shard: names the shard whose share
/// it is.
fn missing(set: &ShardSet, scene: &str, key: &str, files: &[String], j: u64) -> Error {
    let count = set.shards[0].1.shard.count;
    let total = files.len() as u64;
    let owner = (1..=count)
        .map(|index| Shard { index, count })
        .find(|s| s.range(total).contains(&j))
        .unwrap_or(Shard { index: 1, count });
    let dir = set
        .shards
        .iter()
        .find(|(_, m)| m.shard == owner)
        .map_or(&set.shards[0].0, |(d, _)| d);
    refuse(
        dir,
        &files_key(scene, key),
        format!(
            "trajectory {j} of {scene}/{key} ({}) is in no shard, but it is shard {owner}'s share of 0..{total}: rerun shard {owner}",
            files[j as usize]
        ),
    )
}
