//! The project's scenes compiled into the binary, and the one resolver of `--scene
//! NAME|PATH` that every command uses.
//!
//! Every scene file of the project (`verification/*.toml` and
//! `verification/extreme/*.toml`) is in [`BUILTIN`], so that the binary works from any
//! directory: `langevin-fem verify --scene hinged-linear-2d` needs no scene directory. A
//! test holds the table to the files on disk, so a new scene file cannot be forgotten.
//!
//! Resolution ([`resolve`]): `--scene` names a **file** if it ends in `.toml` or names an
//! existing file (not a directory), else a **built-in** scene. With an explicit
//! `--scene-dir DIR`, names resolve in DIR instead (`DIR/<name>.toml`), as before built-in
//! scenes existed. Messages name a built-in scene as `hinged-linear-2d (built in)` where
//! they name a file's path.

use super::spec::Scene;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// One scene compiled into the binary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuiltinScene {
    /// The scene's name: its file stem, also the name of its output directory.
    pub name: &'static str,
    /// The file it was compiled from, relative to the crate root (e.g.
    /// `verification/extreme/hinged-1000-2d.toml`).
    pub file: &'static str,
    /// The file's text.
    pub text: &'static str,
}

impl BuiltinScene {
    /// Whether the scene is one of the extreme cases (`verification/extreme/`), which
    /// `verify` without `--scene` leaves out (`make converge` runs them).
    pub fn is_extreme(&self) -> bool {
        self.file.starts_with("verification/extreme/")
    }

    /// How messages name the scene where they would print a file's path:
    /// `hinged-linear-2d (built in)`.
    pub fn label(&self) -> PathBuf {
        PathBuf::from(format!("{} (built in)", self.name))
    }

    /// Parses and validates the scene.
    ///
    /// # Errors
    /// [`Error::Scene`] naming the scene (built in) and the key; never for a scene of
    /// [`BUILTIN`] (a test parses every one).
    pub fn load(&self) -> Result<Scene> {
        Scene::parse_named(self.text, &self.label(), self.name)
    }
}

/// One row of [`BUILTIN`]: `builtin!("name")` for `verification/name.toml`,
/// `builtin!(extreme "name")` for `verification/extreme/name.toml`.
macro_rules! builtin {
    ($name:literal) => {
        BuiltinScene {
            name: $name,
            file: concat!("verification/", $name, ".toml"),
            text: include_str!(concat!("../../verification/", $name, ".toml")),
        }
    };
    (extreme $name:literal) => {
        BuiltinScene {
            name: $name,
            file: concat!("verification/extreme/", $name, ".toml"),
            text: include_str!(concat!("../../verification/extreme/", $name, ".toml")),
        }
    };
}

/// Every scene file of the project, top-level scenes first, each group sorted by name.
pub const BUILTIN: &[BuiltinScene] = &[
    builtin!("actin-10um"),
    builtin!("clamped-clamped-3d"),
    builtin!("compression-2d"),
    builtin!("compression-3d"),
    builtin!("fig2-paper-2d"),
    builtin!("fig2-paper-3d"),
    builtin!("grafted-clamped-free"),
    builtin!("hinged-linear-2d"),
    builtin!("hinged-linear-3d"),
    builtin!("membrane-area-paper"),
    builtin!("membrane-area-soft"),
    builtin!("membrane-area-stiff"),
    builtin!("membrane-bilayer"),
    builtin!("membrane-hinged"),
    builtin!("membrane-periodic"),
    builtin!("membrane-spectral"),
    builtin!("microtubule-free-free"),
    builtin!("pinned-free-2d"),
    builtin!("spectral-reference"),
    builtin!("tension-2d"),
    builtin!(extreme "compression-floppy-2d"),
    builtin!(extreme "compression-stiff-ea-2d"),
    builtin!(extreme "compression-stiff-ea-explicit-2d"),
    builtin!(extreme "hinged-1000-2d"),
    builtin!(extreme "hinged-floppy-2d"),
    builtin!(extreme "hinged-stiff-2d"),
    builtin!(extreme "membrane-fine"),
    builtin!(extreme "membrane-near-buckling"),
    builtin!(extreme "membrane-stiff"),
    builtin!(extreme "membrane-tension-dominated"),
];

/// The built-in scene called `name`, if any.
pub fn find(name: &str) -> Option<&'static BuiltinScene> {
    BUILTIN.iter().find(|b| b.name == name)
}

/// The names of the built-in scenes, comma-separated, for messages.
pub fn names() -> String {
    BUILTIN
        .iter()
        .map(|b| b.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where a scene comes from: a file, or the binary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SceneSource {
    /// A scene file.
    File(PathBuf),
    /// A scene compiled into the binary.
    Builtin(&'static BuiltinScene),
}

impl SceneSource {
    /// Reads, parses and validates the scene.
    ///
    /// # Errors
    /// As [`Scene::load`] for a file; see [`BuiltinScene::load`].
    pub fn load(&self) -> Result<Scene> {
        match self {
            SceneSource::File(path) => Scene::load(path),
            SceneSource::Builtin(b) => b.load(),
        }
    }

    /// The scene's TOML text as written (the file read, or the compiled-in text).
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be read.
    pub fn text(&self) -> Result<String> {
        match self {
            SceneSource::File(path) => {
                std::fs::read_to_string(path).map_err(|e| Error::io(path, e))
            }
            SceneSource::Builtin(b) => Ok(b.text.to_string()),
        }
    }

    /// How the scene is named in messages: the file's path, or `NAME (built in)`.
    pub fn label(&self) -> String {
        match self {
            SceneSource::File(path) => path.display().to_string(),
            SceneSource::Builtin(b) => b.label().display().to_string(),
        }
    }
}

/// Whether `--scene` text is a path rather than a name: it ends in `.toml`, or it names
/// something that exists and is not a directory.
fn is_path(text: &str) -> bool {
    let p = Path::new(text);
    p.extension().is_some_and(|x| x == "toml") || (p.exists() && !p.is_dir())
}

/// The scene names `--scene` takes, for messages: those of `scene_dir` if given, else
/// the built-in ones, saying which.
fn available(scene_dir: Option<&Path>) -> Result<String> {
    Ok(match scene_dir {
        Some(dir) => {
            let names: Vec<String> = Scene::discover(dir)?
                .iter()
                .filter_map(|k| k.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect();
            format!(
                "{} (the scenes of --scene-dir {})",
                names.join(", "),
                dir.display()
            )
        }
        None => format!("{} (the built-in scenes)", names()),
    })
}

/// Resolves one `--scene` value: a path (it ends in `.toml` or names an existing file
/// that is not a directory), else a name in `scene_dir` when it is given, else a
/// built-in name.
///
/// # Errors
/// [`Error::InvalidParameter`] (exit 2) for a `.toml` path that does not exist, or an
/// unknown name, listing the names available (those of `scene_dir`, or the built-in
/// ones); for an unreadable `scene_dir`, naming `--scene-dir`.
pub fn resolve(name_or_path: &str, scene_dir: Option<&Path>) -> Result<SceneSource> {
    if is_path(name_or_path) {
        let path = PathBuf::from(name_or_path);
        if path.exists() {
            return Ok(SceneSource::File(path));
        }
        // There, but leading nowhere: a dangling symbolic link or a loop of links.
        let why = if std::fs::symlink_metadata(&path).is_ok() {
            format!(
                "{} is a symbolic link that leads to no file (dangling, or a loop)",
                path.display()
            )
        } else {
            format!("there is no file {}", path.display())
        };
        return Err(Error::invalid(
            "--scene",
            name_or_path,
            format!(
                "an existing scene file ({why}) or a scene name, one of: {}",
                available(scene_dir)?
            ),
        ));
    }
    let found = match scene_dir {
        Some(dir) => Scene::discover(dir)?
            .into_iter()
            .find(|k| k.file_stem().is_some_and(|s| s == name_or_path))
            .map(SceneSource::File),
        None => find(name_or_path).map(SceneSource::Builtin),
    };
    found.ok_or_else(|| {
        // The names first: "--scene must be one of: a, b, ...".
        match available(scene_dir) {
            Ok(names) => Error::invalid(
                "--scene",
                name_or_path,
                format!("one of: {names}, or a path to a .toml file"),
            ),
            Err(e) => e,
        }
    })
}

/// Resolves the `--scene` values of a command that runs several scenes: each as
/// [`resolve`]; none given: every scene file of `scene_dir` if it is given, else every
/// built-in top-level scene (those of `verification/*.toml`, not the extreme ones).
///
/// # Errors
/// As [`resolve`]; an unreadable `scene_dir` names `--scene-dir`.
pub fn resolve_scenes(names: &[String], scene_dir: Option<&Path>) -> Result<Vec<SceneSource>> {
    if names.is_empty() {
        return Ok(match scene_dir {
            Some(dir) => Scene::discover(dir)?
                .into_iter()
                .map(SceneSource::File)
                .collect(),
            None => BUILTIN
                .iter()
                .filter(|b| !b.is_extreme())
                .map(SceneSource::Builtin)
                .collect(),
        });
    }
    names.iter().map(|n| resolve(n, scene_dir)).collect()
}

/// Loads one scene given by name or path (see the [module docs](self)): the one entry
/// point of every command that runs a scene.
///
/// # Errors
/// As [`resolve`], then as [`SceneSource::load`] (exit 2 naming the scene and key).
pub fn load_scene(name_or_path: &str, scene_dir: Option<&Path>) -> Result<Scene> {
    resolve(name_or_path, scene_dir)?.load()
}

/// Loads the scenes of [`resolve_scenes`].
///
/// # Errors
/// As [`resolve_scenes`] and [`SceneSource::load`].
pub fn load_scenes(names: &[String], scene_dir: Option<&Path>) -> Result<Vec<Scene>> {
    let scenes: Vec<Scene> = resolve_scenes(names, scene_dir)?
        .iter()
        .map(SceneSource::load)
        .collect::<Result<_>>()?;
    // A scene's name is its file stem, and its outputs go to `<name>/`: two scenes of one
    // name would write over each other's tables, and one scene given twice would be
    // counted twice.
    for (i, s) in scenes.iter().enumerate() {
        if let Some(first) = scenes[..i].iter().find(|t| t.name == s.name) {
            let what = if first.path == s.path {
                format!("{} is given twice", s.path.display())
            } else {
                format!(
                    "{} and {} are both named {:?} (the file stem) and would write the same {}/ folder",
                    first.path.display(),
                    s.path.display(),
                    s.name,
                    s.name
                )
            };
            return Err(Error::invalid(
                "--scene",
                s.path.display(),
                format!(
                    "scenes of distinct names, each once: {what}; rename one file or give it once"
                ),
            ));
        }
    }
    Ok(scenes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// The `*.toml` files under `verification/` and `verification/extreme/`, relative to
    /// the crate root.
    fn files_on_disk() -> BTreeSet<String> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = BTreeSet::new();
        for dir in ["verification", "verification/extreme"] {
            for entry in std::fs::read_dir(root.join(dir)).expect("scene directory") {
                let path = entry.expect("entry").path();
                if path.extension().is_some_and(|x| x == "toml") {
                    let name = path.file_name().unwrap().to_string_lossy().into_owned();
                    files.insert(format!("{dir}/{name}"));
                }
            }
        }
        files
    }

    /// The table lists exactly the scene files of the project: a new file under
    /// `verification/` must be added to [`BUILTIN`] (and a removed one taken out).
    #[test]
    fn table_lists_exactly_the_files_on_disk() {
        let table: BTreeSet<String> = BUILTIN.iter().map(|b| b.file.to_string()).collect();
        assert_eq!(table.len(), BUILTIN.len(), "a file listed twice");
        assert_eq!(table, files_on_disk(), "BUILTIN against verification/");
    }

    /// Every built-in scene is its file's text, parses, validates, is named by its file
    /// stem (names are unique), and messages name it as built in.
    #[test]
    fn every_builtin_scene_loads_as_its_file() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut seen = BTreeSet::new();
        for b in BUILTIN {
            assert!(seen.insert(b.name), "{} twice", b.name);
            let on_disk = std::fs::read_to_string(root.join(b.file)).expect("file");
            assert_eq!(b.text, on_disk, "{}", b.file);
            let stem = Path::new(b.file).file_stem().unwrap().to_string_lossy();
            assert_eq!(b.name, stem, "{}", b.file);
            let scene = b.load().unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert_eq!(scene.name, b.name);
            assert_eq!(scene.path, PathBuf::from(format!("{} (built in)", b.name)));
            let from_file = Scene::load(&root.join(b.file)).expect("file loads");
            assert_eq!(
                toml::to_string(&scene).unwrap(),
                toml::to_string(&from_file).unwrap()
            );
        }
    }

    /// Without `--scene` and `--scene-dir`, the top-level scenes run, in order.
    #[test]
    fn default_set_is_the_top_level_scenes() {
        let names: Vec<&str> = resolve_scenes(&[], None)
            .unwrap()
            .into_iter()
            .map(|s| match s {
                SceneSource::Builtin(b) => b.name,
                SceneSource::File(p) => panic!("file {}", p.display()),
            })
            .collect();
        assert_eq!(
            names,
            [
                "actin-10um",
                "clamped-clamped-3d",
                "compression-2d",
                "compression-3d",
                "fig2-paper-2d",
                "fig2-paper-3d",
                "grafted-clamped-free",
                "hinged-linear-2d",
                "hinged-linear-3d",
                "membrane-area-paper",
                "membrane-area-soft",
                "membrane-area-stiff",
                "membrane-bilayer",
                "membrane-hinged",
                "membrane-periodic",
                "membrane-spectral",
                "microtubule-free-free",
                "pinned-free-2d",
                "spectral-reference",
                "tension-2d"
            ]
        );
    }

    /// A name resolves to the built-in scene, an unknown one is refused listing every
    /// name, and a missing `.toml` path is refused as a path (all exit 2).
    #[test]
    fn names_and_paths() {
        assert_eq!(
            resolve("hinged-1000-2d", None).unwrap(),
            SceneSource::Builtin(find("hinged-1000-2d").unwrap())
        );
        let e = resolve("no-such-scene", None).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let m = e.to_string();
        assert!(
            m.starts_with(
                "--scene must be one of: actin-10um, clamped-clamped-3d, compression-2d, "
            ),
            "{m}"
        );
        assert!(
            m.contains("membrane-tension-dominated (the built-in scenes)"),
            "{m}"
        );
        assert!(m.ends_with("got no-such-scene"), "{m}");
        let e = resolve("no/such/file.toml", None).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("no file no/such/file.toml"), "{e}");
        assert!(
            e.to_string()
                .contains("one of: actin-10um, clamped-clamped-3d, compression-2d, "),
            "{e}"
        );
        let bad = Scene::parse_named("seed = 1", &find("compression-2d").unwrap().label(), "x");
        let m = bad.unwrap_err().to_string();
        assert!(m.starts_with("compression-2d (built in): key "), "{m}");
    }
}
