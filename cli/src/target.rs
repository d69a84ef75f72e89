//! The animation outputs of `decode` and `convert`, checked before any work ([`Target::prepare`])
//! and put in place whole once written ([`crate::staging`]'s rules).

use crate::output::OutputKind;
use crate::staging::{check_file, create_parent, Inputs, StagedFolder};
use mcgv_video::mesh::{obj_frame_names, write_obj_mesh_frame, AnimatedMesh};
use mcgv_video::{Error, Result};
use std::path::{Path, PathBuf};

/// An animation output whose files may be written.
pub enum Target {
    /// OBJ frames staged for a folder; `last` is the number of the clip's last frame, which sets
    /// the digits of every name.
    Folder {
        /// The staged folder.
        staged: StagedFolder,
        /// The clip's last frame number.
        last: usize,
    },
    /// One OBJ file.
    ObjFile(PathBuf),
    /// A PC2 point cache and its base OBJ (frame 0 with the faces), same stem.
    Pc2 {
        /// The cache.
        cache: PathBuf,
        /// The base OBJ.
        base: PathBuf,
    },
    /// A glTF asset.
    Gltf(PathBuf),
}

impl Target {
    /// Checks the output `path` of kind `kind` for the frames numbered `frames` of a clip whose
    /// last frame is numbered `last`, before any work: existing files only with `force`, a folder that takes
    /// files, and no file of `inputs`, even with `force` (a PC2's base OBJ is written beside it;
    /// `decode --like` reads the glTF it is told to write).
    pub fn prepare(
        path: &Path,
        kind: OutputKind,
        (frames, last): (Vec<usize>, usize),
        force: bool,
        inputs: &Inputs,
    ) -> Result<Self> {
        match kind {
            OutputKind::ObjFolder => {
                let names = obj_frame_names(frames, last);
                for name in &names {
                    inputs.refuse(&path.join(name))?;
                }
                let staged = StagedFolder::prepare(path, names, force)?;
                Ok(Target::Folder { staged, last })
            }
            OutputKind::ObjFile => {
                inputs.refuse(path)?;
                check_file(path, force).map(|()| Target::ObjFile(path.into()))
            }
            OutputKind::Pc2 => {
                let base = path.with_extension("obj");
                if inputs.refuse(&base).is_err() {
                    return Err(Error::Usage(format!(
                        "{}: writing the base OBJ would overwrite the input; name the .pc2 \
                         differently",
                        base.display()
                    )));
                }
                inputs.refuse(path)?;
                check_file(path, force)?;
                check_file(&base, force)?;
                Ok(Target::Pc2 {
                    cache: path.into(),
                    base,
                })
            }
            OutputKind::Gltf => {
                inputs.refuse(path)?;
                check_file(path, force).map(|()| Target::Gltf(path.into()))
            }
        }
    }
}

/// Writes the base OBJ `base` (frame 0 of `first`) and then puts the cache in place with
/// `finish`: both appear, or neither that was not there before.
pub fn finish_pc2_pair(
    first: &AnimatedMesh,
    base: &Path,
    finish: impl FnOnce() -> Result<()>,
) -> Result<()> {
    let had_base = base.exists();
    create_parent(base)?;
    write_obj_mesh_frame(first, 0, base)?;
    finish().inspect_err(|_| {
        if !had_base {
            let _ = std::fs::remove_file(base);
        }
    })
}
