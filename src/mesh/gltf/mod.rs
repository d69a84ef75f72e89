//! glTF 2.0 animations baked to frames: node (TRS) animation, morph targets and skinning.
//!
//! Every mesh primitive drawn by the scene becomes part of one animated mesh, in world space, in
//! scene order. Primitives of one node that share their vertex data (the same position, joint,
//! weight and morph accessors, as multi-material meshes do) share their vertices too. Point and
//! line primitives are skipped. The `gltf` crate parses and validates; the posing (sampling the
//! channels, node hierarchy, morphing, linear blend skinning) is the glTF 2.0 specification's, written
//! out here because no maintained crate bakes glTF animation without a renderer attached.
//!
//! This module holds the entry points ([`read_gltf`], [`parse_gltf`], [`files`]) and the pipeline
//! that runs the steps in order: [`validate`] the document, read the clip's [`channels`], gather the
//! scene's [`geometry`] (each part read by [`primitive`]) and its [`skin`]s, then for every frame time
//! ([`sample`]) pose the [`nodes`] and bake the positions.

mod channels;
mod geometry;
mod nodes;
mod primitive;
mod sample;
mod skin;
mod validate;

use super::AnimatedMesh;
use crate::error::{Error, Result};
use crate::limits::DEFAULT_MAX_POSITIONS;
use std::path::{Path, PathBuf};

/// The file's buffers, loaded.
type Buffers<'d> = &'d [gltf::buffer::Data];

/// The bytes of one buffer, for the gltf crate's readers.
fn buffer_data<'d>(buffers: Buffers<'d>, buffer: gltf::Buffer) -> Option<&'d [u8]> {
    buffers.get(buffer.index()).map(|d| &d.0[..])
}

/// Reads `path` and bakes the chosen clip (name or index, default the first) at `fps` (default the
/// clip's keyframe rate if plausible, else 30), refusing one of more than `max_positions` positions.
pub(crate) fn read_gltf(
    path: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
    max_positions: u64,
) -> Result<AnimatedMesh> {
    // Read whole and parsed from memory: gltf's own reader allocates what a GLB header claims (up to
    // 4 GB for a 12-byte file) before reading it.
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let gltf = validate::from_slice(&bytes, path)?;
    bake(gltf, path.parent(), path, fps, clip, max_positions)
}

/// The parsed document of a glTF file and its loaded buffers (for [`clips`] and the writer's
/// `like` option).
pub(crate) fn load_document(path: &Path) -> Result<(gltf::Document, Vec<gltf::buffer::Data>)> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let gltf::Gltf { document, blob } = validate::from_slice(&bytes, path)?;
    validate::check_buffer_uris(&document).map_err(fail)?;
    let buffers = gltf::import_buffers(&document, path.parent(), blob)
        .map_err(|e| fail(format!("buffer: {e}")))?;
    Ok((document, buffers))
}

/// The name [`read_gltf`] gives a triangle's material in the attributes: the material's name, else
/// `material_N`, or `default` for a primitive without one.
pub(crate) fn material_name(material: &gltf::Material) -> String {
    match (material.index(), material.name()) {
        (None, _) => "default".to_string(),
        (Some(_), Some(name)) => name.to_string(),
        (Some(i), None) => format!("material_{i}"),
    }
}

/// One animation (clip) of a glTF file, as [`super::read_animation`] would bake it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Clip {
    /// Its index in the file (what `ReadOptions::clip` takes besides the name).
    pub index: usize,
    /// Its name (empty when it has none).
    pub name: String,
    /// Frames baked at `fps`.
    pub frames: usize,
    /// The frame rate: the one asked for, else the clip's keyframe rate if plausible, else 30.
    pub fps: f64,
    /// Seconds from its first key to its last.
    pub seconds: f64,
}

/// The clips of a glTF file with the frames each bakes to at `fps` (default: each clip's own rate).
pub(crate) fn clips(path: &Path, fps: Option<f64>) -> Result<Vec<Clip>> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    let (document, buffers) = load_document(path)?;
    let mut clips = Vec::new();
    for animation in document.animations() {
        let channels = channels::read_channels(&animation, &buffers).map_err(fail)?;
        let times = sample::FrameTimes::new(&channels, fps, 1, DEFAULT_MAX_POSITIONS, path)?;
        clips.push(Clip {
            index: animation.index(),
            name: animation.name().unwrap_or("").to_string(),
            frames: times.frame_count(),
            fps: times.rate(),
            seconds: times.seconds(),
        });
    }
    Ok(clips)
}

/// The glTF file and the buffer files beside it that it refers to (those that can be told without
/// reading them); an unreadable file is just itself, reading it reports the error.
pub(crate) fn files(path: &Path) -> Vec<PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let gltf = std::fs::read(path)
        .ok()
        .and_then(|bytes| validate::from_slice(&bytes, path).ok());
    if let (Some(gltf), Some(folder)) = (gltf, path.parent()) {
        for buffer in gltf.document.buffers() {
            if let gltf::buffer::Source::Uri(uri) = buffer.source() {
                if !uri.contains(':') {
                    out.push(folder.join(uri));
                }
            }
        }
    }
    out
}

/// Parses a `.gltf` or `.glb` held in memory and bakes it like [`read_gltf`]; `path` only names
/// errors. Nothing is read from disk, so buffers must be embedded (GLB chunk or `data:` URI).
pub(crate) fn parse_gltf(
    bytes: &[u8],
    path: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
    max_positions: u64,
) -> Result<AnimatedMesh> {
    let gltf = validate::from_slice(bytes, path)?;
    bake(gltf, None, path, fps, clip, max_positions)
}

/// Bakes a parsed glTF's `clip` at `fps`; buffer files are looked up in `folder` (none: only
/// embedded buffers).
fn bake(
    gltf: gltf::Gltf,
    folder: Option<&Path>,
    path: &Path,
    fps: Option<f64>,
    clip: Option<&str>,
    max_positions: u64,
) -> Result<AnimatedMesh> {
    let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
    let gltf::Gltf { document, blob } = gltf;
    validate::check_buffer_uris(&document).map_err(fail)?;
    let buffers =
        gltf::import_buffers(&document, folder, blob).map_err(|e| fail(format!("buffer: {e}")))?;
    let data = buffers.as_slice();

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("no scene".into()))?;
    let animation = channels::pick_clip(&document, clip).map_err(fail)?;
    let channels = channels::read_channels(&animation, data).map_err(fail)?;
    let geometry = geometry::Geometry::gather(&document, &scene, data).map_err(fail)?;
    let skins = skin::read_skins(&document, data).map_err(fail)?;

    let times =
        sample::FrameTimes::new(&channels, fps, geometry.vertex_count, max_positions, path)?;
    let pose = nodes::Pose::new(&document);
    let rate = times.rate();
    let frames = times
        .map(|time| geometry.bake(&pose.at(time, &channels), &skins))
        .collect();
    let attributes = geometry.attributes(&document);
    AnimatedMesh::new(geometry.triangles, frames)
        .and_then(|mesh| mesh.with_attributes(attributes))
        .map(|mesh| mesh.with_frame_rate(Some(rate)))
        .map_err(|e| fail(e.to_string()))
}
