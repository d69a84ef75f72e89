//! Where results go: stdout that ends quietly when its reader goes away, and output paths whose
//! kind is read from their names (the way ffmpeg and gltfpack read them). How files are written
//! safely is [`crate::staging`]'s.

use mcgv_video::{Error, Result};
use std::io::Write;
use std::path::Path;

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
            "-: an animation is written to files (frames, a PC2 and its base OBJ, or glTF), not to \
             stdout; name a folder DIR/, a X.pc2, a X.glb or X.gltf, or (with --frame) a X.obj",
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
                "{}: one .obj holds one frame; add --frame N, or name a folder ({}/), a .pc2 or \
                 a .glb",
                path.display(),
                path.with_extension("").display()
            ),
        )),
        Some("glb" | "gltf") => gltf_output(path),
        Some(other) => Err(Error::option(
            "output",
            format!(
                "{}: .{other} is not an animation format this tool writes; name a folder DIR/, \
                 a X.pc2 (with its base X.obj), a X.glb or X.gltf{}",
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

/// `1 frame`, `2 frames`: a count with its noun in the right number (`word` is the singular).
pub fn count(n: impl Into<u64>, word: &str) -> String {
    match n.into() {
        1 => format!("1 {word}"),
        n => format!("{n} {word}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_name_one_thing_in_the_singular() {
        assert_eq!(count(1u32, "frame"), "1 frame");
        assert_eq!(count(0u32, "cluster"), "0 clusters");
        assert_eq!(count(49u32, "frame"), "49 frames");
    }

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
}
