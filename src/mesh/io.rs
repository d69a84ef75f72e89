//! Reading and writing animations in every form the tool takes: OBJ sequences, PC2 + base OBJ, glTF.
//!
//! The formats themselves live in `super::obj`, `super::pc2` and `super::gltf`; this
//! module picks one from the input's name and writes files so that a failure never leaves half of one.

use super::{gltf, obj, obj_files, pc2, AnimatedMesh};
use crate::error::{Error, Result};
use crate::limits::DEFAULT_MAX_POSITIONS;
use crate::output::write_atomic;
use std::path::{Path, PathBuf};

/// Options that apply to reading any input form.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Rate at which glTF animations are baked (default: the animation's keyframe rate, or 30).
    pub fps: Option<f64>,
    /// glTF animation to bake, by name or index (default: the first).
    pub clip: Option<String>,
    /// Base OBJ with the connectivity of a PC2 point cache (default: the .obj beside the .pc2).
    pub base: Option<PathBuf>,
    /// glTF: refuse a clip that bakes to more positions (frames × vertices) than this, before baking
    /// (default [`DEFAULT_MAX_POSITIONS`]).
    pub max_positions: u64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            fps: None,
            clip: None,
            base: None,
            max_positions: DEFAULT_MAX_POSITIONS,
        }
    }
}

/// Reads an animation: a folder or glob of `.obj` files, a `.pc2` point cache, or a `.gltf`/`.glb`.
///
/// - OBJ: a folder's `.obj` files, a glob such as `dir/*.obj`, or one `.obj` (one frame). Frames are
///   ordered by the last number in their file names; every frame must have the first one's vertex
///   count and faces. Vertices keep the file's order, unused ones included.
/// - PC2: the triangles come from [`ReadOptions::base`], by default the `.obj` of the same stem.
/// - glTF: the clip [`ReadOptions::clip`] of the default scene, baked at [`ReadOptions::fps`]; a
///   file without animations is an error (the tool compresses animations).
pub fn read_animation(input: &str, opts: &ReadOptions) -> Result<AnimatedMesh> {
    let path = Path::new(input);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if let Some(fps) = opts.fps {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::option(
                "fps",
                format!("{fps}: the frame rate must be a positive number"),
            ));
        }
    }
    check_clip(input, extension.as_deref(), opts)?;
    match extension.as_deref() {
        Some("pc2") => pc2::read_pc2_animation(path, opts.base.as_deref()),
        Some("gltf") | Some("glb") => {
            gltf::read_gltf(path, opts.fps, opts.clip.as_deref(), opts.max_positions)
        }
        _ => obj::read_sequence(&obj_files::frame_files(input)?),
    }
}

/// Refuses [`ReadOptions::clip`] for an input that is not glTF (of lowercase `extension`): only
/// glTF has clips, and a `--clip` silently ignored would encode something the user did not ask for.
pub(crate) fn check_clip(input: &str, extension: Option<&str>, opts: &ReadOptions) -> Result<()> {
    match (&opts.clip, extension) {
        (Some(clip), ext) if !matches!(ext, Some("gltf" | "glb")) => Err(Error::option(
            "clip",
            format!("{clip}: applies to glTF inputs (.glb, .gltf) only, and {input} is not one"),
        )),
        _ => Ok(()),
    }
}

/// Every file [`read_animation`] would read for `input`: the OBJ frames of a folder or glob, a PC2
/// cache and its base OBJ, or the glTF file itself (with its external buffers, when they resolve).
pub fn input_files(input: &str, opts: &ReadOptions) -> Result<Vec<PathBuf>> {
    let path = Path::new(input);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("pc2") => Ok(vec![
            path.to_path_buf(),
            opts.base
                .clone()
                .unwrap_or_else(|| path.with_extension("obj")),
        ]),
        Some("gltf") | Some("glb") => Ok(gltf::files(path)),
        _ => obj_files::frame_files(input),
    }
}

/// The clips (animations) of a `.gltf`/`.glb` file with their frame counts and rates at `fps`
/// (default: each clip's keyframe rate, else 30); an empty list for the other input forms.
pub fn clips(input: &str, fps: Option<f64>) -> Result<Vec<gltf::Clip>> {
    let path = Path::new(input);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("gltf") | Some("glb") => gltf::clips(path, fps),
        _ => Ok(Vec::new()),
    }
}

/// Parses one OBJ held in memory as a one-frame animation; `name` only labels errors.
pub fn parse_obj(text: &str, name: &Path) -> Result<AnimatedMesh> {
    let frame = obj::parse_obj(text, name)?;
    AnimatedMesh::new(frame.triangles, vec![frame.positions])?.with_attributes(frame.attributes)
}

/// Parses a PC2 point cache held in memory, with the triangles of `base_obj` (an OBJ's text);
/// `name` only labels errors.
pub fn parse_pc2(bytes: &[u8], base_obj: &str, name: &Path) -> Result<AnimatedMesh> {
    pc2::parse_pc2_animation(bytes, base_obj, name, &name.with_extension("obj"))
}

/// Parses and bakes a `.gltf`/`.glb` held in memory as [`read_animation`] would; `name` only labels
/// errors. Nothing is read from disk, so its buffers must be embedded (GLB chunk or `data:` URI).
pub fn parse_gltf(
    bytes: &[u8],
    name: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
) -> Result<AnimatedMesh> {
    gltf::parse_gltf(bytes, name, fps, clip, DEFAULT_MAX_POSITIONS)
}

/// Writes one OBJ per frame into `dir` as `frame_0000.obj`, … (created if missing).
///
/// Numbers have at least four digits, more when the frame count needs them, so the files sort by
/// name too. Files of the same names are replaced; other files in `dir` are left alone.
pub fn write_obj_sequence(mesh: &AnimatedMesh, dir: &Path) -> Result<()> {
    write_obj_sequence_from(mesh, dir, 0)
}

/// Like [`write_obj_sequence`], numbering the files from `first` (e.g. `decode --frame 57` writes
/// `frame_0057.obj`).
pub fn write_obj_sequence_from(mesh: &AnimatedMesh, dir: &Path, first: usize) -> Result<()> {
    let last = first + mesh.frame_count().saturating_sub(1);
    let writer = ObjFrameWriter::new(dir, last, mesh.triangles(), mesh.attributes())?;
    for (f, frame) in mesh.frames().iter().enumerate() {
        writer.write(first + f, frame)?;
    }
    Ok(())
}

/// The file names of OBJ frames `frames` in a sequence whose last frame is numbered `last`, as
/// [`write_obj_sequence`] and [`ObjFrameWriter`] name them (`frame_0012.obj`): what a caller checks
/// before writing them, so that no other file is touched.
pub fn obj_frame_names(frames: impl IntoIterator<Item = usize>, last: usize) -> Vec<String> {
    let digits = frame_digits(last);
    frames.into_iter().map(|f| frame_name(f, digits)).collect()
}

/// Digits of frame numbers up to `last`: at least four, so that the files sort by name too.
fn frame_digits(last: usize) -> usize {
    last.to_string().len().max(4)
}

fn frame_name(f: usize, digits: usize) -> String {
    format!("frame_{f:0digits$}.obj")
}

/// Writes frames of one connectivity as they come (a decoder's, one at a time), named as
/// [`write_obj_sequence`] names them: no frame needs to wait for the others.
pub struct ObjFrameWriter<'a> {
    dir: &'a Path,
    digits: usize,
    triangles: &'a [super::Triangle],
    attributes: &'a super::Attributes,
}

impl<'a> ObjFrameWriter<'a> {
    /// A writer into `dir` (created if missing) for frames numbered up to `last`.
    pub fn new(
        dir: &'a Path,
        last: usize,
        triangles: &'a [super::Triangle],
        attributes: &'a super::Attributes,
    ) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        Ok(Self {
            dir,
            digits: frame_digits(last),
            triangles,
            attributes,
        })
    }

    /// Writes frame number `f`.
    pub fn write(&self, f: usize, positions: &[super::Point]) -> Result<()> {
        let path = self.dir.join(frame_name(f, self.digits));
        let text = obj::obj_text(self.triangles, positions, self.attributes);
        write_atomic(&path, text.as_bytes())
    }
}

/// Writes one frame as an OBJ file (`v` lines in vertex order, then the triangles). Rust prints an
/// `f32` with the fewest digits that read back to the same value, so the file is lossless.
pub fn write_obj_frame(
    triangles: &[super::Triangle],
    positions: &[super::Point],
    path: &Path,
) -> Result<()> {
    let text = obj::obj_text(triangles, positions, &super::Attributes::default());
    write_atomic(path, text.as_bytes())
}

/// Writes frame `frame` of `mesh` as an OBJ file with its texture coordinates (`vt`) and materials
/// (`usemtl`), like the files of [`write_obj_sequence`].
pub fn write_obj_mesh_frame(mesh: &AnimatedMesh, frame: usize, path: &Path) -> Result<()> {
    let positions = mesh
        .frames()
        .get(frame)
        .ok_or_else(|| Error::Usage(format!("frame {frame} of {}", mesh.frame_count())))?;
    let text = obj::obj_text(mesh.triangles(), positions, mesh.attributes());
    write_atomic(path, text.as_bytes())
}

/// Writes a PC2 point cache a frame at a time (a decoder's, as they come), under a temporary name
/// renamed into place by [`Pc2Writer::finish`] once every frame is written.
pub struct Pc2Writer<'a> {
    file: crate::output::AtomicFile<'a>,
    points: usize,
    left: usize,
}

impl<'a> Pc2Writer<'a> {
    /// A cache of `frames` frames of `points` positions at `path`.
    pub fn create(path: &'a Path, points: usize, frames: usize) -> Result<Self> {
        let header = pc2::header_bytes(points, frames)?;
        let mut file = crate::output::AtomicFile::create(path)?;
        file.write_all(&header)?;
        Ok(Self {
            file,
            points,
            left: frames,
        })
    }

    /// Appends the next frame.
    pub fn write(&mut self, positions: &[super::Point]) -> Result<()> {
        if positions.len() != self.points || self.left == 0 {
            return Err(Error::Usage(format!(
                "a PC2 frame of {} positions, expected {} ({} frames left)",
                positions.len(),
                self.points,
                self.left
            )));
        }
        self.left -= 1;
        let mut bytes = Vec::with_capacity(positions.len() * 12);
        pc2::push_frame(&mut bytes, positions);
        self.file.write_all(&bytes)
    }

    /// Puts the cache in place; every frame must have been written.
    pub fn finish(self) -> Result<()> {
        if self.left > 0 {
            return Err(Error::Usage(format!(
                "the PC2 cache misses its last {} frames",
                self.left
            )));
        }
        self.file.commit()
    }
}

/// Writes the animation's positions as a PC2 point cache (start frame 0, one sample per frame).
pub fn write_pc2(mesh: &AnimatedMesh, path: &Path) -> Result<()> {
    let bytes =
        pc2::pc2_bytes(mesh).map_err(|e| Error::Usage(format!("{}: {e}", path.display())))?;
    write_atomic(path, &bytes)
}
