//! The outputs of a run, checked before any work and put in place whole or not at all.
//!
//! Rules, for every command that writes: a file that exists is replaced only with `--force`
//! (`-y`); a folder that holds files takes new ones only with `--force`, and then only the files
//! of the names the run writes are replaced, every other file is left as it was and counted; an
//! output that cannot be written (a folder that takes no files, a parent that is a file) is found
//! before the work starts. Files are written to a hidden staging place beside their target and
//! moved into place once every one of them is complete, so a failed run leaves nothing behind.

use mcgv_video::mesh::{input_files, ReadOptions};
use mcgv_video::{Error, Result};
use std::path::{Path, PathBuf};

/// Prefix of the staging files and folders (hidden, removed when a run fails).
const STAGING_PREFIX: &str = ".mcgv-partial-";

/// Checks, before any work, that the file `path` may be written: it is not a folder, it does not
/// exist unless `force`, and its folder (or the nearest existing one above it, when missing
/// folders are to be created) takes new files.
pub fn check_file(path: &Path, force: bool) -> Result<()> {
    if path.is_dir() {
        return Err(Error::Usage(format!(
            "{} is a folder, not a file",
            path.display()
        )));
    }
    if path.exists() && !force {
        return Err(Error::Usage(format!(
            "{} exists; give --force (-y) to replace it, or name another file",
            path.display()
        )));
    }
    probe(path)
}

/// The files a run reads: its inputs and the files each is read from (a frame of an OBJ folder
/// or glob, the base OBJ of a PC2 cache, a glTF's buffer), by canonical path so that links and
/// `./` spellings cannot sneak past. No output may be one of them, whatever `--force` says.
pub struct Inputs(std::collections::HashSet<PathBuf>);

impl Inputs {
    /// The files `inputs` are read from with `read`.
    pub fn of<P: AsRef<Path>>(inputs: &[P], read: &ReadOptions) -> Self {
        let mut files = std::collections::HashSet::new();
        for input in inputs.iter().map(AsRef::as_ref) {
            // Listing fails for inputs that do not exist or are not readable; reading reports that.
            let listed = input_files(&input.to_string_lossy(), read).unwrap_or_default();
            let all = std::iter::once(input.to_path_buf()).chain(listed);
            files.extend(all.filter_map(|p| p.canonicalize().ok()));
        }
        Self(files)
    }

    /// Refuses `output` when it is one of the inputs (an output that does not exist yet is none).
    pub fn refuse(&self, output: &Path) -> Result<()> {
        match output.canonicalize() {
            Ok(target) if self.0.contains(&target) => Err(Error::Usage(format!(
                "refusing to overwrite the input {}",
                output.display()
            ))),
            _ => Ok(()),
        }
    }
}

/// The folder `path` is written in: its parent, `.` for a bare name.
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The nearest folder at or above `dir` that exists; an error when a file stands in the way.
fn existing_ancestor(path: &Path, dir: &Path) -> Result<PathBuf> {
    let mut at = dir.to_path_buf();
    loop {
        if at.is_dir() {
            return Ok(at);
        }
        if at.exists() {
            return Err(Error::Usage(format!(
                "{}: {} is a file, not a folder",
                path.display(),
                at.display()
            )));
        }
        match at.parent() {
            Some(p) if !p.as_os_str().is_empty() => at = p.to_path_buf(),
            _ => return Ok(PathBuf::from(".")),
        }
    }
}

/// Checks that `path`'s folder (or the nearest existing one above it) takes new files, by
/// creating a staging file there and removing it.
fn probe(path: &Path) -> Result<()> {
    let dir = existing_ancestor(path, folder(path))?;
    tempfile::Builder::new()
        .prefix(STAGING_PREFIX)
        .tempfile_in(&dir)
        .map(drop)
        .map_err(|e| refused(path, &dir, e))
}

/// The error of a folder that takes no new file, naming the output and the folder with the bare
/// reason (not the staging file's name).
fn refused(path: &Path, dir: &Path, e: std::io::Error) -> Error {
    let reason = std::io::Error::from(e.kind());
    Error::io(
        path,
        std::io::Error::new(
            e.kind(),
            format!(
                "the folder {} does not take new files ({reason})",
                dir.display()
            ),
        ),
    )
}

/// Creates the missing folders above `path` (none when its folder exists).
pub fn create_parent(path: &Path) -> Result<()> {
    let dir = folder(path);
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))
}

/// Runs `write` with the missing folders above `path` created; should it fail, the folders it
/// created are removed again (deepest first, each only if empty), so that a failed run leaves no
/// new empty folders behind, as a failed folder output or encode leaves none.
pub fn in_new_parent<T>(path: &Path, write: impl FnOnce() -> Result<T>) -> Result<T> {
    let mut missing = Vec::new();
    let mut at = Some(folder(path));
    while let Some(dir) = at.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
        missing.push(dir.to_path_buf());
        at = dir.parent();
    }
    let undo = || {
        for dir in &missing {
            let _ = std::fs::remove_dir(dir);
        }
    };
    create_parent(path).inspect_err(|_| undo())?;
    write().inspect_err(|_| undo())
}

/// A folder output: the files of the names the run writes, staged in a hidden folder and moved
/// into the target by [`StagedFolder::commit`]; dropped uncommitted, it leaves the target as it
/// was.
pub struct StagedFolder {
    target: PathBuf,
    staging: tempfile::TempDir,
    names: Vec<String>,
    /// Files already in the target that the run does not write.
    others: usize,
    /// Whether the target exists (files move into it) or not (the staging folder becomes it).
    exists: bool,
}

impl StagedFolder {
    /// Checks `dir` for a run that writes the files `names`, before any work: a folder holding
    /// files is refused unless `force` (new files would mix with old ones), and stages the run's
    /// files in a hidden folder inside it (or beside it, when it does not exist yet).
    pub fn prepare(dir: &Path, names: Vec<String>, force: bool) -> Result<Self> {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::Usage(format!(
                "{} is a file, not a folder",
                dir.display()
            )));
        }
        let exists = dir.is_dir();
        let present = if exists { listing(dir)? } else { Vec::new() };
        let replaced = present.iter().filter(|n| names.contains(n)).count();
        if !present.is_empty() && !force {
            return Err(Error::Usage(format!(
                "{}: the folder holds {} files ({replaced} of them of the names this run writes); \
                 new files would mix with them. Give --force (-y) to write among them (only files \
                 of the same names are replaced), or name another folder",
                dir.display(),
                present.len()
            )));
        }
        let place = match exists {
            true => dir.to_path_buf(),
            false => existing_ancestor(dir, dir)?,
        };
        let mut builder = tempfile::Builder::new();
        builder.prefix(STAGING_PREFIX);
        // A new folder becomes the target: it gets the permissions any new folder gets (0777
        // less the umask), not a temporary folder's private 0700.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o777));
        }
        let staging = builder
            .tempdir_in(&place)
            .map_err(|e| refused(dir, &place, e))?;
        Ok(Self {
            target: dir.to_path_buf(),
            staging,
            others: present.len() - replaced,
            names,
            exists,
        })
    }

    /// Where the run writes its files.
    pub fn path(&self) -> &Path {
        self.staging.path()
    }

    /// Moves every staged file into the target (the staging folder becomes the target when it
    /// did not exist); returns how many other files the target holds, which it left alone. Every
    /// name given to [`StagedFolder::prepare`] must have been written.
    pub fn commit(self) -> Result<usize> {
        for name in &self.names {
            let staged = self.staging.path().join(name);
            if !staged.is_file() {
                return Err(Error::Usage(format!(
                    "{}: {name} was not written",
                    self.target.display()
                )));
            }
        }
        if !self.exists {
            create_parent(&self.target)?;
            let staging = self.staging.keep();
            return std::fs::rename(&staging, &self.target)
                .map(|()| 0)
                .map_err(|e| {
                    let _ = std::fs::remove_dir_all(&staging);
                    Error::io(&self.target, e)
                });
        }
        for name in &self.names {
            let to = self.target.join(name);
            std::fs::rename(self.staging.path().join(name), &to).map_err(|e| Error::io(&to, e))?;
        }
        Ok(self.others)
    }

    /// Says on stderr (unless `quiet`) how many other files the folder holds, left as they were.
    pub fn commit_and_tell(self, quiet: bool) -> Result<()> {
        let target = self.target.clone();
        let others = self.commit()?;
        if others > 0 && !quiet {
            eprintln!(
                "mcgv-video: {}: left {} there as they were",
                target.display(),
                crate::output::count(others as u64, "other file")
            );
        }
        Ok(())
    }
}

/// The names of the entries of `dir`, hidden staging leftovers excluded.
fn listing(dir: &Path) -> Result<Vec<String>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut names = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.starts_with(STAGING_PREFIX) {
            names.push(name);
        }
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_in_the_way_of_a_folder_is_found_before_any_work() {
        let d = tempfile::tempdir().unwrap();
        let file = d.path().join("plain");
        std::fs::write(&file, b"x").unwrap();
        let e = check_file(&file.join("sub/out.mcgv"), true).unwrap_err();
        assert!(e.to_string().contains("is a file, not a folder"), "{e}");
        assert!(check_file(&file, false).is_err());
        assert!(check_file(&file, true).is_ok());
        assert!(check_file(d.path(), true).is_err());
    }

    #[test]
    fn folders_made_for_a_failed_write_are_removed_and_others_kept() {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("new/sub/x.glb");
        let failed: Result<()> = in_new_parent(&path, || {
            assert!(path.parent().unwrap().is_dir());
            Err(Error::Usage("failed".into()))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
        in_new_parent(&path, || {
            std::fs::write(&path, b"x").map_err(|e| Error::io(&path, e))
        })
        .unwrap();
        assert!(path.is_file());
    }

    #[test]
    fn a_staged_folder_replaces_its_own_names_only() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path().join("out");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join("a"), b"old").unwrap();
        std::fs::write(dir.join("notes"), b"mine").unwrap();
        assert!(StagedFolder::prepare(&dir, vec!["a".into()], false).is_err());
        let staged = StagedFolder::prepare(&dir, vec!["a".into(), "b".into()], true).unwrap();
        std::fs::write(staged.path().join("a"), b"new").unwrap();
        std::fs::write(staged.path().join("b"), b"new").unwrap();
        assert_eq!(staged.commit().unwrap(), 1);
        assert_eq!(std::fs::read(dir.join("a")).unwrap(), b"new");
        assert_eq!(std::fs::read(dir.join("notes")).unwrap(), b"mine");
        assert_eq!(listing(&dir).unwrap().len(), 3);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
    }

    #[test]
    fn a_new_folder_appears_whole_or_not_at_all() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path().join("new/frames");
        let staged = StagedFolder::prepare(&dir, vec!["a".into()], false).unwrap();
        std::fs::write(staged.path().join("a"), b"x").unwrap();
        drop(staged);
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
        let staged = StagedFolder::prepare(&dir, vec!["a".into()], false).unwrap();
        std::fs::write(staged.path().join("a"), b"x").unwrap();
        assert_eq!(staged.commit().unwrap(), 0);
        assert_eq!(std::fs::read(dir.join("a")).unwrap(), b"x");
    }
}
