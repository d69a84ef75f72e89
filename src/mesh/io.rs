//! Reading and writing animations in every form the tool takes: OBJ sequences, PC2 + base OBJ, glTF.

use super::AnimatedMesh;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Options that apply to reading any input form.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// Rate at which glTF animations are baked (default: the animation's keyframe rate, or 30).
    pub fps: Option<f64>,
    /// glTF animation to bake, by name or index (default: the first).
    pub clip: Option<String>,
    /// Base OBJ with the connectivity of a PC2 point cache (default: the .obj beside the .pc2).
    pub base: Option<PathBuf>,
}

/// Reads an animation: a folder or glob of `.obj` files, a `.pc2` point cache, or a `.gltf`/`.glb`.
pub fn read_animation(input: &str, _opts: &ReadOptions) -> Result<AnimatedMesh> {
    Err(Error::Usage(format!(
        "{input}: reading animations is not available yet"
    )))
}

/// Writes one OBJ per frame into `dir` as `frame_0000.obj`, … (created if missing).
pub fn write_obj_sequence(_mesh: &AnimatedMesh, dir: &Path) -> Result<()> {
    Err(Error::Usage(format!(
        "{}: writing OBJ is not available yet",
        dir.display()
    )))
}

/// Writes the animation's positions as a PC2 point cache.
pub fn write_pc2(_mesh: &AnimatedMesh, path: &Path) -> Result<()> {
    Err(Error::Usage(format!(
        "{}: writing PC2 is not available yet",
        path.display()
    )))
}
