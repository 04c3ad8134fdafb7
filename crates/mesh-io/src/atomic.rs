//! Atomic file output: write a temporary file beside the target, then rename it over.
//!
//! A failure at any point (an error from the writer, a full disk, a panic) leaves the
//! target untouched and no temporary file behind.

use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::MeshError;

/// Write `path` atomically with `fill`, which receives a buffered writer.
///
/// # Errors
/// [`crate::ErrorKind::Write`] naming `path` if the temporary file cannot be created,
/// written, synced or renamed.
pub fn atomic_write(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), MeshError> {
    let tmp = prepare(path, fill)?;
    tmp.persist(path).map_err(|e| MeshError::write(path, e.error))?;
    Ok(())
}

/// Write a temporary file beside `path` without renaming it yet; used where several
/// files must appear together (glTF + .bin).
pub(crate) fn prepare(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<tempfile::NamedTempFile, MeshError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // Temporary files are created 0600; the output is an ordinary file, so give it the
    // usual 0644 before it is renamed into place.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(|e| MeshError::write(path, e))?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        fill(&mut w).map_err(|e| MeshError::write(path, e))?;
        w.flush().map_err(|e| MeshError::write(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| MeshError::write(path, e))?;
    Ok(tmp)
}
