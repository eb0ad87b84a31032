//! Writing output files atomically: a temporary file beside the target, renamed into place only
//! once complete, so an error or an interrupt never leaves a half-written file.

use anyhow::{bail, Context, Result};
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `path` through `write`, atomically.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!(
            "cannot write {}: directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".ronap-").suffix(".partial");
    // Temporary files are private (0600); the finished output gets the usual 0644.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let mut temp = builder
        .tempfile_in(dir)
        .with_context(|| format!("cannot write {}", path.display()))?;
    {
        let mut out = BufWriter::new(temp.as_file_mut());
        write(&mut out).with_context(|| format!("cannot write {}", path.display()))?;
        out.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    temp.persist(path)
        .map_err(|e| e.error)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// Saves an image as PNG (or PGM/PPM for a `.pgm`/`.ppm` path), atomically.
pub fn save_image(path: &Path, image: &image::RgbImage) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => image::ImageFormat::Png,
        Some("pgm") | Some("ppm") => image::ImageFormat::Pnm,
        _ => bail!(
            "cannot write {}: unknown picture type (use a .png, .pgm or .ppm file name)",
            path.display()
        ),
    };
    write_atomic(path, |out| {
        let mut buffer = std::io::Cursor::new(Vec::new());
        if ext.as_deref() == Some("pgm") {
            image::DynamicImage::ImageRgb8(image.clone())
                .to_luma8()
                .write_to(&mut buffer, format)?;
        } else {
            image.write_to(&mut buffer, format)?;
        }
        out.write_all(buffer.get_ref())?;
        Ok(())
    })
}

/// Whether `e` comes from writing to a closed pipe (`ronap ... | head`), which is not an error.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
