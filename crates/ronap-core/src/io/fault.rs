//! A fault-injection hook for crash-consistency tests: with `RONAP_FAULT=KIND:N` in the
//! environment, the `N`-th file operation of `KIND` a process makes fails, as the world can make
//! it fail: `create` (a read-only directory), `write` (a full disk), `rename` (a failed rename)
//! or `remove`. Every write boundary of a run directory (files made, rows flushed, files renamed
//! into place, files removed) passes through [`check`], so a test can fail each one in turn and
//! see that the run stops cleanly and resumes to the same bytes. Without the variable, a check
//! costs one relaxed load.

use std::io::{Error, ErrorKind};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// A kind of file operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Op {
    /// A file or directory made.
    Create,
    /// Bytes written to a file.
    Write,
    /// A file renamed into place.
    Rename,
    /// A file removed.
    Remove,
}

impl Op {
    fn name(self) -> &'static str {
        match self {
            Self::Create => "create",
            Self::Write => "write",
            Self::Rename => "rename",
            Self::Remove => "remove",
        }
    }
}

/// The fault asked for: the operation and which of them fails.
fn fault() -> Option<(&'static str, u64)> {
    static FAULT: OnceLock<Option<(&'static str, u64)>> = OnceLock::new();
    *FAULT.get_or_init(|| {
        let spec = std::env::var("RONAP_FAULT").ok()?;
        let (kind, n) = spec.split_once(':')?;
        let kind = [Op::Create, Op::Write, Op::Rename, Op::Remove]
            .into_iter()
            .find(|op| op.name() == kind)?
            .name();
        Some((kind, n.parse().ok()?))
    })
}

/// Counts an operation of kind `op`, failing it when it is the one `RONAP_FAULT` names.
pub(crate) fn check(op: Op) -> std::io::Result<()> {
    static COUNTS: [AtomicU64; 4] = [const { AtomicU64::new(0) }; 4];
    let Some((kind, n)) = fault() else {
        return Ok(());
    };
    if kind != op.name() {
        return Ok(());
    }
    let count = COUNTS[op as usize].fetch_add(1, Ordering::Relaxed) + 1;
    if count != n {
        return Ok(());
    }
    Err(match op {
        Op::Create => Error::new(
            ErrorKind::ReadOnlyFilesystem,
            "read-only file system (injected)",
        ),
        Op::Write => Error::new(ErrorKind::StorageFull, "no space left on device (injected)"),
        Op::Rename => Error::other("rename failed (injected)"),
        Op::Remove => Error::new(ErrorKind::PermissionDenied, "permission denied (injected)"),
    })
}

/// A writer whose writes pass [`check`].
#[derive(Debug)]
pub(crate) struct Checked<W>(pub W);

impl<W: std::io::Write> std::io::Write for Checked<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        check(Op::Write)?;
        self.0.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}
