//! CSV files written row by row while a run goes on: `NAME.partial` beside the final `NAME`,
//! flushed regularly and renamed into place once the run is done, so a file under its final name
//! is always whole. After a crash the partial file's whole rows are what the run finished; a row
//! torn by the crash is dropped when the file is reopened.

use crate::io::atomic::OutputError;
use crate::io::fault::{self, Checked, Op};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// `NAME.partial`, where `path`'s rows go until the run is done.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".partial");
    path.with_file_name(name)
}

/// A CSV file being written row by row under its partial name.
#[derive(Debug)]
pub struct PartialCsv {
    path: PathBuf,
    partial: PathBuf,
    writer: csv::Writer<Checked<File>>,
}

impl PartialCsv {
    /// Starts `path` (as `NAME.partial`, replacing any) with `header`.
    pub fn create(path: &Path, header: &[&str]) -> Result<Self, OutputError> {
        let partial = partial_path(path);
        let file = fault::check(Op::Create)
            .and_then(|()| File::create(&partial))
            .map_err(|source| OutputError::Io {
                path: partial.clone(),
                source,
            })?;
        let mut this = Self::over(path, partial, file);
        this.row(header)?;
        Ok(this)
    }

    /// Reopens `path` to add rows after its first `rows` data rows (dropping any after them):
    /// its partial file, else the file under its final name (a run stopped short writes its
    /// files there), else a new file with `header`.
    pub fn reopen(path: &Path, header: &[&str], rows: usize) -> Result<Self, OutputError> {
        let partial = partial_path(path);
        let io = |p: &Path| {
            let p = p.to_path_buf();
            move |source| OutputError::Io { path: p, source }
        };
        if !partial.exists() {
            if !path.exists() {
                return Self::create(path, header);
            }
            fault::check(Op::Rename)
                .and_then(|()| std::fs::rename(path, &partial))
                .map_err(io(path))?;
        }
        let end = row_end(&partial, rows + 1)?;
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .open(&partial)
            .map_err(io(&partial))?;
        file.set_len(end).map_err(io(&partial))?;
        file.seek(SeekFrom::End(0)).map_err(io(&partial))?;
        let mut this = Self::over(path, partial, file);
        if end == 0 {
            this.row(header)?;
        }
        Ok(this)
    }

    fn over(path: &Path, partial: PathBuf, file: File) -> Self {
        Self {
            path: path.to_path_buf(),
            partial,
            writer: csv::WriterBuilder::new()
                .buffer_capacity(64 * 1024)
                .from_writer(Checked(file)),
        }
    }

    fn fail(&self, e: csv::Error) -> OutputError {
        // The operating system's own error when there is one (its kind says "disk full").
        let source = if e.is_io_error() {
            match e.into_kind() {
                csv::ErrorKind::Io(io) => io,
                other => std::io::Error::other(format!("{other:?}")),
            }
        } else {
            std::io::Error::other(e)
        };
        OutputError::Io {
            path: self.partial.clone(),
            source,
        }
    }

    /// Adds a row.
    pub fn row<I, T>(&mut self, fields: I) -> Result<(), OutputError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        self.writer.write_record(fields).map_err(|e| self.fail(e))
    }

    /// Writes what is buffered to the file.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.writer.flush().map_err(|source| OutputError::Io {
            path: self.partial.clone(),
            source,
        })
    }

    /// Flushes, syncs and renames the file to its final name.
    pub fn finish(mut self) -> Result<(), OutputError> {
        self.flush()?;
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| OutputError::Io { path, source }
        };
        let Checked(file) = self
            .writer
            .into_inner()
            .map_err(|e| io(&self.partial)(e.into_error()))?;
        file.sync_data().map_err(io(&self.partial))?;
        drop(file);
        fault::check(Op::Rename)
            .and_then(|()| std::fs::rename(&self.partial, &self.path))
            .map_err(io(&self.path))
    }
}

/// The whole rows at the start of `path` (its header included), as a list would count them:
/// the rows with as many fields as the first, up to the first that has not, and not a last row
/// the file does not end after (torn by a crash). 0 for a missing file.
pub fn whole_rows(path: &Path) -> Result<usize, OutputError> {
    let (rows, _) = scan(path, usize::MAX)?;
    Ok(rows)
}

/// The byte offset just after the first `rows` whole rows of `path` (fewer if it has fewer).
fn row_end(path: &Path, rows: usize) -> Result<u64, OutputError> {
    let (_, end) = scan(path, rows)?;
    Ok(end)
}

/// Whole rows of `path`, up to `limit`, and the byte offset just after the last of them.
fn scan(path: &Path, limit: usize) -> Result<(usize, u64), OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((0, 0)),
        Err(e) => return Err(io(e)),
    };
    let len = file.metadata().map_err(io)?.len();
    let ends_whole = len > 0 && {
        let mut last = [0u8];
        file.seek(SeekFrom::End(-1)).map_err(io)?;
        file.read_exact(&mut last).map_err(io)?;
        file.rewind().map_err(io)?;
        last[0] == b'\n'
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(std::io::BufReader::new(file));
    let mut record = csv::ByteRecord::new();
    let (mut rows, mut end, mut width) = (0, 0, None);
    while rows < limit {
        match reader.read_byte_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            // Invalid text is a torn row: nothing from it on counts.
            Err(_) => break,
        }
        let at = reader.position().byte();
        let mut whole =
            (at < len || ends_whole) && *width.get_or_insert(record.len()) == record.len();
        // A last row cut inside a quoted field that held a line break ends with one, but leaves
        // its quotes unbalanced.
        if whole && at >= len {
            whole = quotes_balanced(path, end, len)?;
        }
        if !whole {
            break;
        }
        rows += 1;
        end = at;
    }
    Ok((rows, end))
}

/// Whether the bytes `from..to` of `path` hold an even number of double quotes.
fn quotes_balanced(path: &Path, from: u64, to: u64) -> Result<bool, OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = File::open(path).map_err(io)?;
    file.seek(SeekFrom::Start(from)).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(to - from).read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes.iter().filter(|&&b| b == b'"').count() % 2 == 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torn_rows_are_dropped_and_whole_ones_kept() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.csv");
        let partial = partial_path(&path);
        assert!(partial.ends_with("t.csv.partial"));
        let mut f = PartialCsv::create(&path, &["a", "b"]).expect("create");
        for i in 0..5 {
            f.row([i.to_string(), format!("x,\"{i}\"\ny")])
                .expect("row");
        }
        f.flush().expect("flush");
        drop(f);
        assert_eq!(whole_rows(&partial).expect("scan"), 6);
        // A crash mid-row: the torn row does not count, and reopening drops it and later rows.
        let text = std::fs::read(&partial).expect("read");
        std::fs::write(&partial, &text[..text.len() - 3]).expect("tear");
        assert_eq!(whole_rows(&partial).expect("scan"), 5);
        let mut f = PartialCsv::reopen(&path, &["a", "b"], 3).expect("reopen");
        f.row(["9", "z"]).expect("row");
        f.finish().expect("finish");
        assert!(!partial.exists());
        let rows: Vec<Vec<String>> = csv::Reader::from_path(&path)
            .expect("open")
            .records()
            .map(|r| r.expect("row").iter().map(String::from).collect())
            .collect();
        assert_eq!(rows.len(), 4);
        assert_eq!(rows[2], ["2", "x,\"2\"\ny"]);
        assert_eq!(rows[3], ["9", "z"]);
        // A file under its final name (a run stopped short) is picked up again.
        let mut f = PartialCsv::reopen(&path, &["a", "b"], 4).expect("reopen final");
        f.row(["10", "w"]).expect("row");
        f.finish().expect("finish");
        assert_eq!(whole_rows(&path).expect("scan"), 6);
        // No file at all: a new one with its header; a torn header is written again.
        let other = dir.path().join("o.csv");
        PartialCsv::reopen(&other, &["h"], 0)
            .expect("new")
            .finish()
            .expect("finish");
        assert_eq!(std::fs::read_to_string(&other).expect("read"), "h\n");
        std::fs::write(partial_path(&other), "hea").expect("torn header");
        PartialCsv::reopen(&other, &["h"], 0)
            .expect("reopen")
            .finish()
            .expect("finish");
        assert_eq!(std::fs::read_to_string(&other).expect("read"), "h\n");
    }
}
