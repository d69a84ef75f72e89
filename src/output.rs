//! Writing output files so that a failure never leaves a half-written file at the target path,
//! and never replaces a pipe, device or symbolic link with a regular file.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to a temporary file in `path`'s folder and renames it over `path`: readers see the
/// old file or the whole new one, and a failed or interrupted run leaves no partial file behind
/// (the temporary file is removed when dropped). A FIFO or device at `path` is written to, and a
/// symbolic link's target is written (see [`AtomicFile::create`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// A file written under a temporary name beside its target and renamed into place by
/// [`AtomicFile::commit`]: dropped uncommitted (an error part-way), it leaves the target as it was.
pub struct AtomicFile<'a> {
    sink: Sink,
    /// The path asked for, named in errors.
    path: &'a Path,
}

/// Where the bytes go.
enum Sink {
    /// A temporary file renamed over the target (a regular file's path, or a new one).
    Staged(tempfile::NamedTempFile, PathBuf),
    /// An existing FIFO or device, opened and written in place: renaming over it would replace
    /// the pipe or device node with a regular file, and its reader would get nothing.
    Through(std::fs::File),
}

impl<'a> AtomicFile<'a> {
    /// Starts the file that will be `path`. A symbolic link is followed: its target (made beside
    /// the target, renamed over it) is what gets written, and the link stays a link. A FIFO or a
    /// device (`/dev/stdout`) that exists is written through, the way a shell's `>` writes it.
    pub fn create(path: &'a Path) -> Result<Self> {
        if path.is_dir() {
            return Err(Error::Usage(format!(
                "{} is a folder, not a file",
                path.display()
            )));
        }
        let target = link_target(path);
        let special = std::fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir());
        if special {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(|e| Error::io(path, e))?;
            return Ok(Self {
                sink: Sink::Through(file),
                path,
            });
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
            .tempfile_in(folder(&target))
            .map_err(|e| bare(&target, e))?;
        Ok(Self {
            sink: Sink::Staged(tmp, target),
            path,
        })
    }

    /// Appends `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        match &mut self.sink {
            Sink::Staged(tmp, _) => tmp.write_all(bytes),
            Sink::Through(file) => file.write_all(bytes),
        }
        .map_err(|e| bare(self.path, e))
    }

    /// Renames the file into place (flushes a FIFO or device written through).
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        match self.sink {
            Sink::Staged(tmp, target) => tmp.persist(&target).map(drop).map_err(|e| e.error),
            Sink::Through(mut file) => file.flush(),
        }
        .map_err(|e| bare(path, e))
    }
}

/// What writing `path` should replace: `path` itself, or for a symbolic link the path it
/// points to (followed through every link; a dangling link's target, made relative to the
/// link's folder, is created).
fn link_target(path: &Path) -> PathBuf {
    let mut at = path.to_path_buf();
    // A loop of links ends after as many steps as the system allows (40 on Linux).
    for _ in 0..40 {
        if !std::fs::symlink_metadata(&at).is_ok_and(|m| m.file_type().is_symlink()) {
            break;
        }
        match std::fs::read_link(&at) {
            Ok(to) => at = folder(&at).join(to),
            Err(_) => break,
        }
    }
    at
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

    /// `--force` onto a symbolic link replaced the link with a regular file: the link stays and
    /// its target gets the bytes, written atomically beside it (a dangling link's target is made).
    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_keeps_pointing_and_its_target_is_written() {
        let d = tempfile::tempdir().unwrap();
        let (target, link) = (d.path().join("target.bin"), d.path().join("link.bin"));
        std::fs::write(&target, b"old").unwrap();
        std::os::unix::fs::symlink("target.bin", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let dangling = d.path().join("dangling.bin");
        std::os::unix::fs::symlink("made.bin", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert!(std::fs::symlink_metadata(&dangling).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(d.path().join("made.bin")).unwrap(), b"made");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 4, "no temporary file left");
    }

    /// `--force` onto a FIFO replaced the pipe with a regular file and its reader got nothing.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_through_and_stays_a_fifo() {
        use std::os::unix::fs::FileTypeExt;
        let d = tempfile::tempdir().unwrap();
        let fifo = d.path().join("pipe.bin");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        // The reader hands over what it read, and the test fails rather than hangs should nothing
        // ever open the FIFO for writing (the path replaced by a regular file).
        let (sent, read) = std::sync::mpsc::channel();
        let reader = fifo.clone();
        std::thread::spawn(move || sent.send(std::fs::read(reader).unwrap()));
        write_atomic(&fifo, b"through the pipe").unwrap();
        let bytes = read.recv_timeout(std::time::Duration::from_secs(20));
        assert_eq!(bytes.expect("nothing written to the FIFO"), b"through the pipe");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    }

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
