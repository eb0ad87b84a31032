//! A run directory's lock: one run writes into a directory at a time.
//!
//! The lock is the operating system's advisory lock (`flock` on Unix) on `DIR/.ronap.lock`,
//! held while the file is open, so a killed run never leaves a stale lock. The file holds the
//! holder's process id for the refusal message; it is never removed, since removing a lock file
//! lets two runs each lock a different file of the same name.

use crate::io::atomic::OutputError;
use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The lock file's name inside a run directory.
pub const LOCK_FILE: &str = ".ronap.lock";

/// A held run-directory lock; dropping it releases the lock.
#[derive(Debug)]
pub struct RunLock {
    _file: File,
}

impl RunLock {
    /// Locks `dir` (which must exist), or says which process holds it.
    pub fn take(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(LOCK_FILE);
        let io = |source| OutputError::Io {
            path: path.clone(),
            source,
        };
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
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        writeln!(file, "{}", std::process::id()).map_err(io)?;
        Ok(Self { _file: file })
    }
}

/// The path of `dir`'s lock file.
pub fn lock_path(dir: &Path) -> PathBuf {
    dir.join(LOCK_FILE)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        RunLock::take(dir.path()).expect("free again");
        assert!(lock_path(dir.path()).exists());
    }
}
