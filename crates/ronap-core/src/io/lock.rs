//! A run directory's lock: one run writes into a directory at a time.
//!
//! The lock is the operating system's advisory lock (`flock` on Unix) on `DIR/.ronap.lock`,
//! held while the file is open, so a killed run never leaves a stale lock (only its file, which
//! the next run there takes over). The file holds the holder's process id for the refusal
//! message. A run that ends cleanly removes the file while still holding its lock; a run taking
//! the lock then checks that the file it locked is still the one under the name (else it locked a
//! removed file, and tries again), so two runs never each hold a different file of one name.

use crate::io::atomic::OutputError;
use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The lock file's name inside a run directory.
pub const LOCK_FILE: &str = ".ronap.lock";

/// A held run-directory lock; dropping it releases the lock, and removes the lock file when
/// this lock made it ([`RunLock::release`] removes it in any case).
#[derive(Debug)]
pub struct RunLock {
    file: File,
    path: PathBuf,
    made: bool,
    /// What the file held before (a killed run's pid), put back if it is left.
    before: String,
}

impl RunLock {
    /// Locks `dir` (which must exist), or says which process holds it.
    pub fn take(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(LOCK_FILE);
        let io = |source| OutputError::Io {
            path: path.clone(),
            source,
        };
        // A holder removing the file between our open and our lock leaves us a removed file:
        // then the name is tried again (a few times; a directory is not that busy).
        for _ in 0..100 {
            let made = !path.exists();
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match fs4::FileExt::try_lock(&file) {
                Ok(()) => {}
                Err(fs4::TryLockError::WouldBlock) => {
                    let mut text = String::new();
                    let _ = file.read_to_string(&mut text);
                    return Err(OutputError::Busy {
                        dir: dir.to_path_buf(),
                        pid: text.trim().parse().ok(),
                    });
                }
                Err(fs4::TryLockError::Error(e)) => return Err(io(e)),
            }
            if !still_named(&file, &path) {
                continue;
            }
            let mut before = String::new();
            let _ = file.read_to_string(&mut before);
            file.set_len(0).map_err(io)?;
            file.rewind().map_err(io)?;
            writeln!(file, "{}", std::process::id()).map_err(io)?;
            return Ok(Self {
                file,
                path,
                made,
                before,
            });
        }
        Err(io(std::io::Error::other(
            "the lock file kept being removed by other runs",
        )))
    }

    /// Releases the lock at a run's clean end, removing the lock file.
    pub fn release(mut self) {
        self.made = true;
    }
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // Removed while still held, so no one locks the file between removal and release.
        if !still_named(&self.file, &self.path) {
            return;
        }
        if self.made {
            let _ = std::fs::remove_file(&self.path);
        } else if self.file.set_len(0).is_ok() && self.file.rewind().is_ok() {
            let _ = self.file.write_all(self.before.as_bytes());
        }
    }
}

/// Whether `path` still names the open `file`.
fn still_named(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        path.exists()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The path of `dir`'s lock file.
    fn lock_path(dir: &Path) -> PathBuf {
        dir.join(LOCK_FILE)
    }

    #[test]
    fn a_locked_directory_is_refused_with_the_holders_pid_until_released() {
        let dir = tempfile::tempdir().expect("tempdir");
        let first = RunLock::take(dir.path()).expect("first lock");
        match RunLock::take(dir.path()) {
            Err(e @ OutputError::Busy { pid, .. }) => {
                assert_eq!(pid, Some(std::process::id()));
                let text = e.to_string();
                assert!(text.contains(&dir.path().display().to_string()), "{text}");
            }
            other => panic!("expected Busy, got {other:?}"),
        }
        drop(first);
        // The lock that made the file removes it.
        assert!(!lock_path(dir.path()).exists());
        let second = RunLock::take(dir.path()).expect("free again");
        assert!(lock_path(dir.path()).exists());
        second.release();
        assert!(!lock_path(dir.path()).exists());
    }

    #[test]
    fn a_lock_file_left_by_a_killed_run_stays_unless_released() {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(lock_path(dir.path()), "12345\n").unwrap();
        drop(RunLock::take(dir.path()).expect("taken over"));
        let left = std::fs::read_to_string(lock_path(dir.path())).unwrap();
        assert_eq!(left, "12345\n", "a failed resume leaves it as it was");
        RunLock::take(dir.path()).expect("taken over").release();
        assert!(!lock_path(dir.path()).exists(), "a clean end removes it");
    }
}
