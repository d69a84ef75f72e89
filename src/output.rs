//! Writing output files so that a failure never leaves a half-written file at the target path.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to a temporary file in `path`'s folder and renames it over `path`: readers see the
/// old file or the whole new one, and a failed or interrupted run leaves no partial file behind
/// (the temporary file is removed when dropped).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// A file written under a temporary name beside its target and renamed into place by
/// [`AtomicFile::commit`]: dropped uncommitted (an error part-way), it leaves the target as it was.
pub struct AtomicFile<'a> {
    tmp: tempfile::NamedTempFile,
    path: &'a Path,
}

impl<'a> AtomicFile<'a> {
    /// Starts the file that will be `path`.
    pub fn create(path: &'a Path) -> Result<Self> {
        if path.is_dir() {
            return Err(Error::Usage(format!(
                "{} is a folder, not a file",
                path.display()
            )));
        }
        let mut builder = tempfile::Builder::new();
        builder.prefix(".mcgv-partial-");
        // Temporary files are private (0600) by default; the output should get the permissions any
        // new file gets (0666 less the umask), as it would if written directly.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder
            .tempfile_in(folder(path))
            .map_err(|e| bare(path, e))?;
        Ok(Self { tmp, path })
    }

    /// Appends `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        self.tmp.write_all(bytes).map_err(|e| bare(self.path, e))
    }

    /// Renames the file into place.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        self.tmp.persist(path).map_err(|e| bare(path, e.error))?;
        Ok(())
    }
}

/// The folder a file is written in.
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The temporary file's name is an internal detail: errors name the target (and, when it is
/// missing, its folder) with the bare reason, not tempfile's "at path .mcgv-partial-…".
fn bare(path: &Path, e: std::io::Error) -> Error {
    let dir = folder(path);
    match e.kind() {
        // A folder that exists can still refuse files with "not found" (/proc, /sys).
        std::io::ErrorKind::NotFound if dir.is_dir() => Error::io(
            path,
            std::io::Error::new(
                e.kind(),
                format!("the folder {} does not take new files", dir.display()),
            ),
        ),
        std::io::ErrorKind::NotFound => Error::io(
            path,
            std::io::Error::new(
                e.kind(),
                format!("the folder {} does not exist", dir.display()),
            ),
        ),
        kind => Error::io(path, std::io::Error::from(kind)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_folder_and_one_that_takes_no_files_are_told_apart() {
        let missing = std::env::temp_dir().join("mcgv-no-such-folder/out.mcgv");
        let e = write_atomic(&missing, b"x")
            .expect_err("no folder")
            .to_string();
        assert!(e.contains("does not exist"), "{e}");
        // procfs answers "not found" to a new file in a folder that exists.
        let proc = Path::new("/proc/mcgv-out.mcgv");
        if proc.parent().is_some_and(Path::is_dir) {
            let e = write_atomic(proc, b"x").expect_err("procfs").to_string();
            assert!(e.contains("/proc does not take new files"), "{e}");
        }
    }
}
