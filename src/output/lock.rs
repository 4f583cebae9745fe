//! One writer per output directory: [`OutputLock`] holds an exclusive advisory lock
//! (`flock`) on the directory itself for the life of a command, so a second command
//! pointed at the same `--out` while the first runs is refused at once (exit 2) instead of
//! removing or overwriting the first one's files as it goes (two `calibrate` runs into
//! one folder share its scratch directory; two report runs' journals would interleave).
//!
//! The lock belongs to the open directory handle: the system releases it when the process
//! ends, however it ends, so a killed run leaves no stale lock behind and no lock file is
//! ever written. A missing output directory is created to be locked, and removed again
//! (with the ancestors created for it) if the command leaves it empty. Where a directory
//! cannot be opened as a file (not on Linux or macOS) the command runs unlocked.

use std::fs::{self, File, TryLockError};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// An exclusive lock on an output directory (see the [module docs](self)); released on
/// drop.
#[derive(Debug)]
pub struct OutputLock {
    /// The locked directory.
    dir: PathBuf,
    /// The open directory that holds the lock (`None`: the platform cannot lock it).
    handle: Option<File>,
    /// The topmost directory created for the lock (the directory or an ancestor), removed
    /// on drop if left empty.
    created: Option<PathBuf>,
}

impl OutputLock {
    /// Creates `dir` if missing and locks it against every other process.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for `name` (the flag, e.g. `--out`) if another process
    /// holds the lock; [`Error::Io`] naming a directory that cannot be created.
    pub fn acquire(name: &str, dir: &Path) -> Result<OutputLock> {
        let created = super::staging::first_missing(dir);
        fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let mut lock = OutputLock {
            dir: dir.to_path_buf(),
            handle: None,
            created,
        };
        let Ok(handle) = File::open(dir) else {
            return Ok(lock);
        };
        match handle.try_lock() {
            Ok(()) => {
                lock.handle = Some(handle);
                Ok(lock)
            }
            Err(TryLockError::WouldBlock) => Err(Error::invalid(
                name,
                dir.display(),
                "a directory no other running langevin-fem command is writing to (one is \
                 writing there now: wait for it to finish, or choose another directory)",
            )),
            // A file system without locks: run unlocked, as on other platforms.
            Err(TryLockError::Error(_)) => Ok(lock),
        }
    }
}

impl Drop for OutputLock {
    /// Releases the lock, then removes the directories created for it if they are empty.
    fn drop(&mut self) {
        drop(self.handle.take());
        super::staging::remove_created_if_empty(&self.dir, self.created.as_deref());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_until_the_first_is_dropped() {
        let root = std::env::temp_dir().join(format!("lf-lock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&root);
        fs::create_dir_all(&root).unwrap();
        let dir = root.join("a/out");
        let first = OutputLock::acquire("--out", &dir).unwrap();
        assert!(dir.is_dir());
        let err = OutputLock::acquire("--out", &dir).unwrap_err().to_string();
        assert!(
            err.contains("--out") && err.contains("no other running"),
            "{err}"
        );
        // Another directory is not affected.
        drop(OutputLock::acquire("--out", &root.join("b")).unwrap());
        drop(first);
        // Dropped: the directories created for it are gone again (left empty).
        assert!(!root.join("a").exists() && !root.join("b").exists());
        assert!(root.is_dir());
        // A directory that holds a file is kept, and can be locked again.
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("keep.txt"), b"x").unwrap();
        drop(OutputLock::acquire("--out", &dir).unwrap());
        assert!(dir.join("keep.txt").is_file());
        fs::remove_dir_all(&root).unwrap();
    }
}
