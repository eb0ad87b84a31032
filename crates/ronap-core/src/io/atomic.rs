//! Writing files atomically: a temporary file beside the target, renamed into place only once
//! complete, so an error or an interrupt never leaves a half-written file.

use crate::io::fault::{self, Checked, Op};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The directory to write into does not exist.
    #[error("cannot write {}: directory {} does not exist", path.display(), dir.display())]
    NoDirectory {
        /// The file.
        path: PathBuf,
        /// Its directory.
        dir: PathBuf,
    },
    /// Writing failed.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// Some episodes' own files (pictures, step logs) could not be written.
    #[error("{count} output file(s) could not be written; first: {first}")]
    Episodes {
        /// How many failed.
        count: usize,
        /// The first failure.
        first: String,
    },
    /// Another run is writing into the directory.
    #[error(
        "{} is in use by another ronap run{}: wait for it to finish or choose another output directory",
        dir.display(),
        pid.map_or(String::new(), |p| format!(" (pid {p})"))
    )]
    Busy {
        /// The directory.
        dir: PathBuf,
        /// The process holding it, when it said.
        pid: Option<u32>,
    },
    /// The directory holds a run stopped short (killed or interrupted), whose finished episodes
    /// starting a new run there would throw away.
    #[error("{} holds a run that stopped short ({why})", dir.display())]
    StoppedShort {
        /// The directory.
        dir: PathBuf,
        /// How it shows.
        why: String,
    },
    /// The directory holds a finished run, which a new run there would replace.
    #[error("{} holds a finished run (its {file})", dir.display())]
    Finished {
        /// The directory.
        dir: PathBuf,
        /// The file that shows it.
        file: &'static str,
    },
    /// The directory holds files of no run (or of another kind of output: a comparison where a
    /// run would go, or a run where a comparison would), among which its files would be mixed.
    #[error("{}", not_this_output(dir, file))]
    NotARun {
        /// The directory.
        dir: PathBuf,
        /// An entry found there.
        file: String,
    },
    /// The file name has an extension no writer knows.
    #[error("cannot write {}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// The start and end of the name of every temporary file [`write_atomic`] makes beside its
/// target (`.ronap-XXXXXX.partial`): renamed into place when whole, left behind only by a process
/// killed while writing.
const TEMP_PREFIX: &str = ".ronap-";
const TEMP_SUFFIX: &str = ".partial";

/// Whether `name` is one of [`write_atomic`]'s temporary files.
pub(crate) fn is_temporary(name: &str) -> bool {
    name.starts_with(TEMP_PREFIX) && name.ends_with(TEMP_SUFFIX)
}

/// Removes the temporary files that processes killed in [`write_atomic`] left in `dir` (never a
/// whole file: a target is only ever written by the rename). For a run that holds `dir`'s lock.
pub(crate) fn remove_temporaries(dir: &Path) -> Result<(), OutputError> {
    remove_files_in(dir, is_temporary)
}

/// Removes every file in `dir` whose name `matches` (none when `dir` cannot be read), each
/// through the test hook's `remove` fault point.
pub(crate) fn remove_files_in(
    dir: &Path,
    matches: impl Fn(&str) -> bool,
) -> Result<(), OutputError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        if matches(&entry.file_name().to_string_lossy()) {
            let removed =
                fault::check(Op::Remove).and_then(|()| std::fs::remove_file(entry.path()));
            removed.map_err(|source| OutputError::Io {
                path: entry.path(),
                source,
            })?;
        }
    }
    Ok(())
}

/// Whether files can be written in `dir` the way [`write_atomic`] writes them (through a
/// temporary file there), tried with an empty temporary file that is removed at once: for checks
/// before a long job whose results would otherwise be lost at the end.
pub fn check_writable(dir: &Path) -> Result<(), OutputError> {
    tempfile::Builder::new()
        .prefix(TEMP_PREFIX)
        .suffix(TEMP_SUFFIX)
        .tempfile_in(dir)
        .map(drop)
        .map_err(|source| OutputError::Io {
            path: dir.to_path_buf(),
            source,
        })
}

/// Writes `path` through `write`, atomically; the file gets mode 0644 on Unix.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(OutputError::NoDirectory {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(TEMP_PREFIX).suffix(TEMP_SUFFIX);
    // Temporary files are private (0600); the finished output gets the usual 0644.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    // tempfile's own error names its temporary path; the target path says more to a user.
    fault::check(Op::Create).map_err(io)?;
    let mut temp = builder.tempfile_in(dir).map_err(|e| {
        let message = e.to_string();
        let message = message
            .split(" at path ")
            .next()
            .unwrap_or(&message)
            .to_string();
        io(std::io::Error::new(e.kind(), message))
    })?;
    {
        let mut out = BufWriter::new(Checked(temp.as_file_mut()));
        write(&mut out).map_err(io)?;
        out.flush().map_err(io)?;
    }
    fault::check(Op::Rename).map_err(io)?;
    temp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Saves a network as ronap's weights file (safetensors), atomically.
pub fn save_network(path: &Path, mlp: &crate::policy::Mlp) -> Result<(), OutputError> {
    let bytes = mlp.to_bytes().map_err(|message| OutputError::Format {
        path: path.to_path_buf(),
        message,
    })?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Saves an image as PNG (or binary PGM/PPM, `P5`/`P6`, for a `.pgm`/`.ppm` path, as map
/// servers read them), atomically.
pub fn save_image(path: &Path, image: &image::RgbImage) -> Result<(), OutputError> {
    use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
    use image::{ExtendedColorType, ImageEncoder};
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mut buffer = std::io::Cursor::new(Vec::new());
    let (w, h) = image.dimensions();
    let encoded = match ext.as_deref() {
        Some("png") => image.write_to(&mut buffer, image::ImageFormat::Png),
        Some("pgm") => {
            let gray = image::DynamicImage::ImageRgb8(image.clone()).to_luma8();
            PnmEncoder::new(&mut buffer)
                .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
                .write_image(gray.as_raw(), w, h, ExtendedColorType::L8)
        }
        Some("ppm") => PnmEncoder::new(&mut buffer)
            .with_subtype(PnmSubtype::Pixmap(SampleEncoding::Binary))
            .write_image(image.as_raw(), w, h, ExtendedColorType::Rgb8),
        _ => {
            return Err(OutputError::Format {
                path: path.to_path_buf(),
                message: "unknown picture type (use a .png, .pgm or .ppm file name)".into(),
            })
        }
    };
    encoded.map_err(|e| OutputError::Format {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomic(path, |out| out.write_all(buffer.get_ref()))
}

/// [`OutputError::NotARun`]'s message: what `dir` holds, by the entry `file` found there.
fn not_this_output(dir: &Path, file: &str) -> String {
    let dir = dir.display();
    match file {
        "summary.json" => format!("{dir} holds a ronap run (its summary.json), not a comparison"),
        "compare.json" => format!("{dir} holds a comparison (its compare.json), not a run"),
        _ => format!("{dir} is not empty and holds no ronap run (it holds {file})"),
    }
}
