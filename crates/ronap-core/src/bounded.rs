//! Reading the files a user hands ronap with a bound, so that a device or a runaway file
//! (`/dev/zero`, a log with no line break in gigabytes) ends in an error naming the bound instead
//! of a hang that eats the machine's memory.

use std::io::{self, Read};
use std::path::Path;

/// Largest configuration, scenario, map YAML or run manifest read: 64 MiB.
pub const TEXT_LIMIT: u64 = 64 << 20;

/// Largest weights file read: 1 GiB.
pub const WEIGHTS_LIMIT: u64 = 1 << 30;

/// Longest line of a CSV file read row by row (data logs, step logs, episodes): 1 MiB.
pub const LINE_LIMIT: usize = 1 << 20;

/// The whole of `path`, refused (an [`io::ErrorKind::InvalidData`] error) above `limit` bytes.
pub fn read(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("larger than {}: not a file ronap reads", size(limit)),
        ));
    }
    Ok(bytes)
}

/// The whole of `path` as UTF-8 text, refused above `limit` bytes.
pub fn read_to_string(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read(path, limit)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

/// `path` opened for reading row by row, refusing a line longer than [`LINE_LIMIT`].
pub fn open_lines(path: &Path) -> io::Result<LineLimited<io::BufReader<std::fs::File>>> {
    Ok(LineLimited::new(io::BufReader::new(std::fs::File::open(
        path,
    )?)))
}

/// A reader that fails (an [`io::ErrorKind::InvalidData`] error) once a line runs past
/// [`LINE_LIMIT`] bytes without a line break.
#[derive(Debug)]
pub struct LineLimited<R> {
    inner: R,
    run: usize,
    limit: usize,
}

impl<R: Read> LineLimited<R> {
    /// `inner`, limited to lines of [`LINE_LIMIT`] bytes.
    pub fn new(inner: R) -> Self {
        Self::with_limit(inner, LINE_LIMIT)
    }

    /// `inner`, limited to lines of `limit` bytes.
    pub fn with_limit(inner: R, limit: usize) -> Self {
        Self {
            inner,
            run: 0,
            limit,
        }
    }
}

impl<R: Read> Read for LineLimited<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut longest = 0;
        for line in buf[..n].split_inclusive(|&b| b == b'\n') {
            let ends = line.last() == Some(&b'\n');
            self.run += line.len() - usize::from(ends);
            longest = longest.max(self.run);
            if ends {
                self.run = 0;
            }
        }
        if longest > self.limit {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "a line longer than {}: not a text file ronap reads",
                    size(self.limit as u64)
                ),
            ));
        }
        Ok(n)
    }
}

/// `bytes` in the largest whole binary unit.
fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_over_the_limit_is_refused_and_one_at_it_read() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("f");
        std::fs::write(&path, b"12345").expect("write");
        assert_eq!(read(&path, 5).expect("at the limit"), b"12345");
        let e = read(&path, 4).expect_err("over the limit");
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert!(e.to_string().contains("larger than 4 bytes"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn an_endless_device_ends_in_an_error() {
        let e = read(Path::new("/dev/zero"), TEXT_LIMIT).expect_err("endless");
        assert!(e.to_string().contains("larger than 64 MiB"), "{e}");
        let mut text = String::new();
        let e = open_lines(Path::new("/dev/zero"))
            .expect("open")
            .read_to_string(&mut text)
            .expect_err("no line break");
        assert!(e.to_string().contains("a line longer than 1 MiB"), "{e}");
    }

    #[test]
    fn long_files_of_short_lines_pass() {
        let text = "abc,def\n".repeat(10_000);
        let mut out = String::new();
        LineLimited::with_limit(text.as_bytes(), 8)
            .read_to_string(&mut out)
            .expect("short lines");
        assert_eq!(out, text);
        let e = LineLimited::with_limit("abcdefghij\n".as_bytes(), 8)
            .read_to_string(&mut out)
            .expect_err("long line");
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
    }
}
