//! Where results go: stdout that ends quietly when its reader goes away, and output paths whose
//! kind is read from their names (the way ffmpeg and gltfpack read them).
//!
//! One rule for parent folders everywhere: a missing parent folder of `-o` is created.

use mcgv_video::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prints to stdout like `print!`, but a failed write (a closed pipe) is returned as an error of
/// `stdout` that `main` turns into a quiet exit instead of a panic.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!($($arg)*))
    };
}

/// Prints a line to stdout like `println!`; see [`out!`].
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes formatted text to stdout; an error names `stdout`.
pub fn write_stdout(args: std::fmt::Arguments) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(args)
        .and_then(|()| stdout.flush())
        .map_err(|e| Error::io("stdout", e))
}

/// Whether an error is stdout's reader having gone away (`mcgv-video info x | head -1`): a normal
/// end for a Unix filter, not a failure.
pub fn is_closed_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
}

/// What an output path asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// A folder of OBJ frames (`DIR/`, an existing folder, or a name without extension).
    ObjFolder,
    /// One OBJ file (`X.obj`, one frame only).
    ObjFile,
    /// A PC2 point cache with its base OBJ beside it.
    Pc2,
    /// A glTF 2.0 asset (`.glb` binary or `.gltf` with the buffer embedded): morph targets.
    Gltf,
}

/// The kind of animation output `path` names; `one_frame` when a single frame is written
/// (`decode --frame`). Anything else is an error naming the choices.
pub fn animation_output(path: &Path, one_frame: bool) -> Result<OutputKind> {
    let text = path.to_string_lossy();
    if text == "-" {
        return Err(Error::option(
            "output",
            "-: an animation is several files (frames, or a PC2 and its base OBJ) and cannot go \
             to stdout; name a folder DIR/, a X.pc2 or (with --frame) a X.obj",
        ));
    }
    if text.ends_with('/') || path.is_dir() {
        return Ok(OutputKind::ObjFolder);
    }
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        None => Ok(OutputKind::ObjFolder),
        Some("pc2") => Ok(OutputKind::Pc2),
        Some("obj") if one_frame => Ok(OutputKind::ObjFile),
        Some("obj") => Err(Error::option(
            "output",
            format!(
                "{}: one .obj holds one frame; add --frame N, or name a folder ({}/) or a .pc2",
                path.display(),
                path.with_extension("").display()
            ),
        )),
        Some("glb" | "gltf") => gltf_output(path),
        Some(other) => Err(Error::option(
            "output",
            format!(
                "{}: .{other} is not an animation format this tool writes; name a folder DIR/, \
                 a X.pc2 (with its base X.obj){}",
                path.display(),
                if one_frame { " or a X.obj" } else { "" }
            ),
        )),
    }
}

/// glTF output (the one place that decides whether it is written).
fn gltf_output(_path: &Path) -> Result<OutputKind> {
    Ok(OutputKind::Gltf)
}

/// Creates the missing parent folders of an output file.
pub fn create_parent(path: &Path) -> Result<()> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => {
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))
        }
        _ => Ok(()),
    }
}

/// Writes an animation as a PC2 point cache and, beside it with the same stem, the base OBJ that
/// holds its faces (what `--base` defaults to), so that the tool can read its own output back.
/// `input` (when given) must not be that base OBJ.
pub fn write_pc2_with_base(
    mesh: &mcgv_video::AnimatedMesh,
    path: &Path,
    input: Option<&str>,
) -> Result<PathBuf> {
    let base = path.with_extension("obj");
    if input.is_some_and(|i| Path::new(i) == base) {
        return Err(Error::Usage(format!(
            "{}: writing the base OBJ would overwrite the input; name the .pc2 differently",
            base.display()
        )));
    }
    create_parent(path)?;
    mcgv_video::mesh::write_obj_mesh_frame(mesh, 0, &base)?;
    mcgv_video::mesh::write_pc2(mesh, path)?;
    Ok(base)
}

/// Whether a file name is one of the frames an OBJ-folder output writes (`frame_0012.obj`).
fn is_frame_file(name: &str) -> bool {
    name.strip_prefix("frame_")
        .and_then(|rest| rest.strip_suffix(".obj"))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// Makes `dir` ready for a fresh set of OBJ frames: created when missing; when it already holds
/// files, refused unless `force`, and with `force` the frames of an earlier run are removed so
/// that none of them is mistaken for part of the new animation (other files are left alone).
pub fn prepare_frame_folder(dir: &Path, force: bool) -> Result<()> {
    if !dir.exists() {
        return std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e));
    }
    let entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    if entries.is_empty() {
        return Ok(());
    }
    if !force {
        return Err(Error::Usage(format!(
            "{}: the folder is not empty ({} files); new frames would mix with old ones. Give \
             --force (-y) to remove its frame_*.obj first, or name another folder",
            dir.display(),
            entries.len()
        )));
    }
    for path in entries {
        let frame = path
            .file_name()
            .is_some_and(|n| is_frame_file(&n.to_string_lossy()));
        if frame && path.is_file() {
            std::fs::remove_file(&path).map_err(|e| Error::io(&path, e))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_kind_comes_from_the_name() {
        let kind = |p: &str, one| animation_output(Path::new(p), one);
        assert_eq!(kind("out/", false).unwrap(), OutputKind::ObjFolder);
        assert_eq!(kind("out", false).unwrap(), OutputKind::ObjFolder);
        assert_eq!(kind("x.PC2", false).unwrap(), OutputKind::Pc2);
        assert_eq!(kind("f.obj", true).unwrap(), OutputKind::ObjFile);
        assert_eq!(kind("x.glb", false).unwrap(), OutputKind::Gltf);
        assert_eq!(kind("x.GLTF", true).unwrap(), OutputKind::Gltf);
        for bad in ["f.obj", "x.txt", "-"] {
            assert!(kind(bad, false).is_err(), "{bad}");
        }
    }

    #[test]
    fn frame_files_are_told_from_others() {
        assert!(is_frame_file("frame_0012.obj"));
        assert!(!is_frame_file("frame_.obj"));
        assert!(!is_frame_file("notes.txt"));
        assert!(!is_frame_file("frame_01.obj.bak"));
    }
}
