//! Writing output files so that a failure never leaves a half-written file at the target path.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to a temporary file in `path`'s folder and renames it over `path`: readers see the
/// old file or the whole new one, and a failed or interrupted run leaves no partial file behind
/// (the temporary file is removed when dropped).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if path.is_dir() {
        return Err(Error::Usage(format!(
            "{} is a folder, not a file",
            path.display()
        )));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".mcgv-partial-");
    // Temporary files are private (0600) by default; the output should get the permissions any new
    // file gets (0666 less the umask), as it would if written directly.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // The temporary file's name is an internal detail: errors name the target (and, when it is
    // missing, its folder) with the bare reason, not tempfile's "at path .mcgv-partial-…".
    let bare = |e: std::io::Error| match e.kind() {
        std::io::ErrorKind::NotFound => Error::io(
            path,
            std::io::Error::new(
                e.kind(),
                format!("the folder {} does not exist", dir.display()),
            ),
        ),
        kind => Error::io(path, std::io::Error::from(kind)),
    };
    let mut tmp = builder.tempfile_in(dir).map_err(bare)?;
    tmp.write_all(bytes).map_err(bare)?;
    tmp.persist(path).map_err(|e| bare(e.error))?;
    Ok(())
}
