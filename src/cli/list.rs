//! `langevin-fem list`: the scenes, one line each: the built-in ones first, then (with
//! `--scene-dir`) the files of a directory.

use clap::Args;
use langevin_fem::error::{Error, Result};
use langevin_fem::scene::{BUILTIN, ModelKind, Scene, SceneSource};
use serde::Serialize;
use std::path::PathBuf;

/// Command-line arguments of `langevin-fem list`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  langevin-fem list
  langevin-fem list --scene-dir my-scenes
  langevin-fem list --json | python3 -m json.tool")]
pub struct ListArgs {
    /// Also list the scene files (*.toml) of this directory, after the built-in scenes.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Print a JSON array (one object per scene) instead of the table.
    #[arg(long)]
    json: bool,
}

/// One scene of the list.
#[derive(Debug, Serialize)]
struct Entry {
    /// The name `--scene` takes (a file's stem for a file of --scene-dir).
    name: String,
    /// `built-in`, `built-in (extreme)`, or the file's path.
    source: String,
    /// `fem`, `spectral` or `compression`; empty for an invalid file.
    model: String,
    /// 2 or 3 (0 for an invalid file).
    dims: usize,
    /// Elements (modes for the spectral model).
    elements: usize,
    /// The names of its runs.
    runs: Vec<String>,
    /// The description's first sentence.
    summary: String,
    /// The whole description.
    description: String,
    /// Why a file of --scene-dir could not be read (absent for a valid scene).
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
}

impl Entry {
    /// The entry of a loaded scene.
    fn new(scene: &Scene, source: String) -> Entry {
        Entry {
            name: scene.name.clone(),
            source,
            model: match scene.model {
                ModelKind::Fem => "fem",
                ModelKind::Spectral => "spectral",
                ModelKind::Compression => "compression",
            }
            .to_string(),
            dims: scene.dims,
            elements: scene.mesh.elements,
            runs: scene.runs.iter().map(|r| r.name.clone()).collect(),
            summary: first_sentence(&scene.description),
            description: scene.description.clone(),
            error: None,
        }
    }
}

/// The first sentence of `text`: up to the first `.`, `!` or `?` followed by a space and
/// a capital letter (so "eq. (2)" does not end it), or all of it.
fn first_sentence(text: &str) -> String {
    let chars: Vec<char> = text.trim().chars().collect();
    for i in 0..chars.len() {
        if matches!(chars[i], '.' | '!' | '?')
            && chars.get(i + 1) == Some(&' ')
            && chars.get(i + 2).is_some_and(|c| c.is_uppercase())
        {
            return chars[..=i].iter().collect();
        }
    }
    chars.iter().collect()
}

/// Lists the scenes on stdout; exit code 0, or 2 (after listing the others) if a file of
/// `--scene-dir` is not a valid scene.
pub fn run(args: ListArgs) -> Result<i32> {
    let mut entries = Vec::new();
    for b in BUILTIN {
        let scene = b.load()?;
        let source = if b.is_extreme() {
            "built-in (extreme)"
        } else {
            "built-in"
        };
        entries.push(Entry::new(&scene, source.to_string()));
    }
    let mut invalid = Vec::new();
    if let Some(dir) = &args.scene_dir {
        for path in Scene::discover(dir)? {
            let source = path.display().to_string();
            match SceneSource::File(path.clone()).load() {
                Ok(scene) => entries.push(Entry::new(&scene, source)),
                Err(e) => {
                    entries.push(Entry {
                        name: path
                            .file_stem()
                            .map(|s| s.to_string_lossy().into_owned())
                            .unwrap_or_default(),
                        source,
                        model: String::new(),
                        dims: 0,
                        elements: 0,
                        runs: Vec::new(),
                        summary: "(not a valid scene: see the error)".to_string(),
                        description: String::new(),
                        error: Some(e.to_string()),
                    });
                    invalid.push(e);
                }
            }
        }
    }
    if args.json {
        let text = serde_json::to_string_pretty(&entries).map_err(|e| Error::Numerical {
            routine: "list as JSON".to_string(),
            detail: e.to_string(),
        })?;
        println!("{text}");
    } else {
        print!("{}", table(&entries));
    }
    for e in &invalid {
        eprintln!("error: {e}");
    }
    Ok(if invalid.is_empty() { 0 } else { 2 })
}

/// The entries as an aligned table with a header line.
fn table(entries: &[Entry]) -> String {
    let rows: Vec<[String; 6]> = entries
        .iter()
        .map(|e| {
            let model = if e.model.is_empty() {
                "-".to_string()
            } else {
                format!("{} {}D", e.model, e.dims)
            };
            [
                e.name.clone(),
                e.source.clone(),
                model,
                e.elements.to_string(),
                e.runs.len().to_string(),
                e.summary.clone(),
            ]
        })
        .collect();
    let header = ["NAME", "SOURCE", "MODEL", "ELEMENTS", "RUNS", "DESCRIPTION"].map(str::to_string);
    let mut width = [0usize; 5];
    for row in std::iter::once(&header).chain(&rows) {
        for (w, cell) in width.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let mut out = String::new();
    for row in std::iter::once(&header).chain(&rows) {
        for (i, cell) in row.iter().enumerate() {
            if i < 5 {
                let pad = width[i] - cell.chars().count();
                // Counts right-aligned, text left-aligned.
                if i == 3 || i == 4 {
                    out.push_str(&" ".repeat(pad));
                    out.push_str(cell);
                } else {
                    out.push_str(cell);
                    out.push_str(&" ".repeat(pad));
                }
                out.push_str("  ");
            } else {
                out.push_str(cell);
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::first_sentence;

    #[test]
    fn first_sentence_ends_at_a_full_stop_before_a_capital() {
        assert_eq!(first_sentence("One. Two."), "One.");
        assert_eq!(
            first_sentence("Simulator of eq. (2) (64 modes). More"),
            "Simulator of eq. (2) (64 modes)."
        );
        assert_eq!(first_sentence("No stop: all of it"), "No stop: all of it");
    }
}
