//! A run's new files, kept out of sight until the run has succeeded (issue #25): every
//! file a report run or a shard writes goes first to a hidden staging directory inside
//! its output directory, `.langevin-fem-staging.<pid>.<n>/`, under its final relative
//! name. Only [`Staging::publish`], called once everything has been computed and
//! written, moves the files into place (one rename each, within one file system). A
//! refusal or failure at any point before that — bad data found late, an estimator that
//! finds no answer, a divergence, a full disk — drops the staging directory
//! ([`Drop`]) and leaves the output directory exactly as it was, earlier report included,
//! and removes the directories the run created if they are left empty.
//!
//! A staging directory left by a killed process is removed by the next command that
//! writes into the output directory ([`super::remove_stale_temporaries`]: its name
//! carries the pid).

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// How the name of a staging directory starts (then `<pid>.<n>`).
pub const STAGING_PREFIX: &str = ".langevin-fem-staging.";

/// Distinguishes the staging directories of one process.
static STAGING_COUNTER: AtomicU64 = AtomicU64::new(0);

/// The staging directory of one run in an output directory (see the
/// [module docs](self)).
#[derive(Debug)]
pub struct Staging {
    /// The output directory.
    dir: PathBuf,
    /// The hidden staging directory inside it.
    staging: PathBuf,
    /// The topmost directory this run created (the output directory or an ancestor),
    /// removed on drop if left empty.
    created: Option<PathBuf>,
    /// Whether [`Self::publish`] has moved the files into place.
    published: bool,
}

impl Staging {
    /// Creates the output directory `dir` if missing and a fresh staging directory
    /// inside it.
    ///
    /// # Errors
    /// [`Error::Io`] naming the directory that cannot be created.
    pub fn new(dir: &Path) -> Result<Staging> {
        let created = first_missing(dir);
        fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let n = STAGING_COUNTER.fetch_add(1, Ordering::Relaxed);
        let staging = dir.join(format!("{STAGING_PREFIX}{}.{n}", std::process::id()));
        let staged = Staging {
            dir: dir.to_path_buf(),
            staging,
            created,
            published: false,
        };
        fs::create_dir(&staged.staging).map_err(|e| Error::io(&staged.staging, e))?;
        Ok(staged)
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Where the file of relative name `rel` (a plain relative path) is written while the
    /// run goes on.
    pub fn path(&self, rel: &str) -> PathBuf {
        self.staging.join(rel)
    }

    /// Moves the staged files `rels` (relative names; those never written are skipped)
    /// to their places in the output directory, each by one rename that replaces an
    /// earlier file of that name, then removes the staging directory.
    ///
    /// # Errors
    /// [`Error::Io`] naming a file that cannot be moved (e.g. a directory stands at its
    /// place); the files moved before it stay moved.
    pub fn publish<'a>(&mut self, rels: impl IntoIterator<Item = &'a str>) -> Result<()> {
        for rel in rels {
            let from = self.staging.join(rel);
            if fs::symlink_metadata(&from).is_err() {
                continue;
            }
            let to = self.dir.join(rel);
            if let Some(parent) = to.parent() {
                fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
            }
            fs::rename(&from, &to).map_err(|e| Error::io(&to, e))?;
        }
        self.published = true;
        let _ = fs::remove_dir_all(&self.staging);
        Ok(())
    }

    /// The first place that [`Self::publish`] of the staged files `rels` would take from
    /// something the run does not own, relative to the output directory: an existing
    /// entry at a file's name that `may_replace` does not allow (an earlier run's file of
    /// the same command is allowed by its caller; a directory never is), or an entry that
    /// is not a directory where a file's parent directory must go. `None` if every staged
    /// file can be moved into place replacing only what the run may replace. Files never
    /// staged are skipped, as [`Self::publish`] skips them.
    pub fn taken<'a>(
        &self,
        rels: impl IntoIterator<Item = &'a str>,
        may_replace: impl Fn(&str) -> bool,
    ) -> Option<String> {
        for rel in rels {
            if fs::symlink_metadata(self.staging.join(rel)).is_err() {
                continue;
            }
            let parts: Vec<&str> = rel.split('/').collect();
            for i in 1..parts.len() {
                let parent = parts[..i].join("/");
                // Followed: a symbolic link to a directory is a directory to write into.
                if fs::symlink_metadata(self.dir.join(&parent)).is_ok()
                    && !self.dir.join(&parent).is_dir()
                {
                    return Some(parent);
                }
            }
            match fs::symlink_metadata(self.dir.join(rel)) {
                Ok(m) if m.is_dir() || !may_replace(rel) => return Some(rel.to_string()),
                _ => {}
            }
        }
        None
    }
}

impl Drop for Staging {
    /// Without [`Staging::publish`]: removes the staging directory, then the directories
    /// the run created if they are empty (nothing else is touched).
    fn drop(&mut self) {
        if self.published {
            return;
        }
        let _ = fs::remove_dir_all(&self.staging);
        remove_created_if_empty(&self.dir, self.created.as_deref());
    }
}

/// Removes `dir` and its ancestors up to `top` (the topmost directory a run created, as
/// [`first_missing`] found it) while they are empty; nothing if `top` is `None`.
pub(crate) fn remove_created_if_empty(dir: &Path, top: Option<&Path>) {
    let Some(top) = top else {
        return;
    };
    let mut d = dir;
    while fs::remove_dir(d).is_ok() && d != top {
        let Some(parent) = d.parent() else { break };
        d = parent;
    }
}

/// The topmost ancestor of `dir` (or `dir` itself) that does not exist yet, if any.
pub(crate) fn first_missing(dir: &Path) -> Option<PathBuf> {
    let mut missing = None;
    let mut d = Some(dir);
    while let Some(p) = d.filter(|p| !p.as_os_str().is_empty()) {
        if fs::symlink_metadata(p).is_ok() {
            break;
        }
        missing = Some(p.to_path_buf());
        d = p.parent();
    }
    missing
}

/// Whether the entry `name` of a directory is a staging directory of a process that is
/// gone (on Linux: no `/proc/<pid>`; elsewhere: never, it is left).
pub(crate) fn is_stale_staging(name: &str) -> bool {
    let Some(rest) = name.strip_prefix(STAGING_PREFIX) else {
        return false;
    };
    let Some((pid, n)) = rest.split_once('.') else {
        return false;
    };
    let (Ok(pid), Ok(_)) = (pid.parse::<u32>(), n.parse::<u64>()) else {
        return false;
    };
    let proc_dir = Path::new("/proc");
    pid != std::process::id() && proc_dir.is_dir() && !proc_dir.join(pid.to_string()).exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("lfem-staging-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        d
    }

    /// Dropped unpublished, a staging leaves the directory as it was and removes the
    /// directories it created; published, the files are in place and the staging gone.
    #[test]
    fn dropped_leaves_nothing_published_moves_everything() {
        let top = root("drop");
        let dir = top.join("a/b");
        {
            let s = Staging::new(&dir).unwrap();
            fs::create_dir_all(s.path("x")).unwrap();
            fs::write(s.path("x/f.csv"), b"new").unwrap();
        }
        assert!(!top.exists(), "created directories removed");
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("old.csv"), b"old").unwrap();
        {
            let s = Staging::new(&dir).unwrap();
            fs::write(s.path("old.csv"), b"new").unwrap();
        }
        assert_eq!(fs::read(dir.join("old.csv")).unwrap(), b"old");
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        let mut s = Staging::new(&dir).unwrap();
        fs::create_dir_all(s.path("x")).unwrap();
        fs::write(s.path("x/f.csv"), b"f").unwrap();
        fs::write(s.path("old.csv"), b"new").unwrap();
        s.publish(["x/f.csv", "old.csv", "never-written.csv"])
            .unwrap();
        drop(s);
        assert_eq!(fs::read(dir.join("old.csv")).unwrap(), b"new");
        assert_eq!(fs::read(dir.join("x/f.csv")).unwrap(), b"f");
        let names: Vec<String> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(
            names.iter().all(|n| !n.starts_with(STAGING_PREFIX)),
            "{names:?}"
        );
        fs::remove_dir_all(&top).unwrap();
    }

    #[test]
    fn stale_staging_names() {
        assert!(
            is_stale_staging(&format!("{STAGING_PREFIX}4000000000.0"))
                == Path::new("/proc").is_dir()
        );
        assert!(!is_stale_staging(&format!(
            "{STAGING_PREFIX}{}.0",
            std::process::id()
        )));
        assert!(!is_stale_staging(".langevin-fem-staging.x.0"));
        assert!(!is_stale_staging("reports"));
    }
}
