//! glTF 2.0 output: a decoded animation as one mesh with morph targets, ready for three.js, Blender
//! or any glTF viewer.
//!
//! Frame 0 is the base mesh (positions, recomputed `normals`, every texture-coordinate set); each
//! later frame is one morph target holding its position and normal differences from frame 0. One
//! animation, "frames", sets the weights with STEP interpolation: at time `f / fps` target `f` has
//! weight 1 and every other 0, so a viewer shows exactly the decoded frames. One primitive per
//! triangle group (per source primitive for glTF inputs) shares the vertex data. The JSON is built as `gltf::json::Value`s and serialised by
//! `gltf-json` (the `gltf` crate's own JSON layer), so the library needs no JSON crate of its own.

mod buffer;
mod like;
mod normals;

use super::{AnimatedMesh, Attributes, Point};
use crate::error::{Error, Result};
use crate::output::write_atomic;
use buffer::{object, BufferBuilder, ARRAY_BUFFER};
use gltf::json::Value;
use like::Look;
use normals::{vertex_normals, Welding};
use std::path::{Path, PathBuf};

/// Morph targets beyond which a writer should warn: each target stores `V` positions and normals,
/// and the weights animation grows as frames × targets. three.js and Blender import more, slowly;
/// decoding a range of frames keeps files small.
pub const MANY_MORPH_TARGETS: usize = 256;

/// How to write a glTF file.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfOptions {
    /// Frames per second of the weights animation (the CLI passes the source's, which the mesh and
    /// the stream record for glTF inputs, else [`crate::mesh::DEFAULT_FPS`]).
    pub fps: f64,
    /// Name of the node holding the mesh (default: the `like` source's, else "mcgv-video").
    pub node_name: Option<String>,
    /// A glTF file (the encoded source) whose materials, textures, samplers, images and node name
    /// the output copies; triangles take the source material of the same name.
    pub like: Option<PathBuf>,
}

impl Default for GltfOptions {
    fn default() -> Self {
        Self {
            fps: crate::mesh::DEFAULT_FPS,
            node_name: None,
            like: None,
        }
    }
}

/// Whether `path` names a glTF output (`.glb` or `.gltf`, any case).
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// Writes `mesh` (with its `attributes`, if any) to `path`: a binary `.glb`, or a `.gltf` with its
/// buffer embedded. The file is written atomically.
pub fn write_gltf(
    mesh: &AnimatedMesh,
    attributes: Option<&Attributes>,
    path: &Path,
    options: &GltfOptions,
) -> Result<()> {
    let binary = match path.extension().map(|e| e.to_ascii_lowercase()) {
        Some(e) if e == "glb" => true,
        Some(e) if e == "gltf" => false,
        _ => {
            return Err(Error::Usage(format!(
                "{}: a glTF output ends in .glb or .gltf",
                path.display()
            )))
        }
    };
    write_atomic(path, &gltf_bytes(mesh, attributes, options, binary)?)
}

/// The bytes of the glTF file [`write_gltf`] writes (`binary`: GLB, else `.gltf` JSON).
pub fn gltf_bytes(
    mesh: &AnimatedMesh,
    attributes: Option<&Attributes>,
    options: &GltfOptions,
    binary: bool,
) -> Result<Vec<u8>> {
    if !(options.fps.is_finite() && options.fps > 0.0) {
        return Err(Error::option(
            "fps",
            format!("{}: the frame rate must be a positive number", options.fps),
        ));
    }
    let empty = Attributes::default();
    let attributes = attributes.unwrap_or(&empty);
    attributes.check(mesh.vertex_count(), mesh.triangles().len())?;
    let look = options.like.as_deref().map(Look::read).transpose()?;
    let mut buf = BufferBuilder::default();
    let mut root = document(mesh, attributes, options, look.as_ref(), &mut buf);
    let json = if binary {
        set(
            &mut root,
            "buffers",
            vec![object([("byteLength", buf.bin.len().into())])],
        );
        serialise(&root)?
    } else {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            buffer::base64(&buf.bin)
        );
        let entry = object([("byteLength", buf.bin.len().into()), ("uri", uri.into())]);
        set(&mut root, "buffers", vec![entry]);
        return serialise(&root);
    };
    Ok(buffer::glb(&json, &buf.bin))
}

fn serialise(root: &Value) -> Result<Vec<u8>> {
    gltf::json::serialize::to_vec(root)
        .map_err(|e| Error::Mesh(format!("serialising the glTF JSON: {e}")))
}

/// Sets `key` of a JSON object.
fn set(target: &mut Value, key: &str, value: impl Into<Value>) {
    if let Value::Object(map) = target {
        map.insert(key.into(), value.into());
    }
}

/// The glTF JSON of the whole asset; the binary data goes into `buf`.
fn document(
    mesh: &AnimatedMesh,
    attributes: &Attributes,
    options: &GltfOptions,
    look: Option<&Look>,
    buf: &mut BufferBuilder,
) -> Value {
    let welding = Welding::new(mesh.frame(0));
    let base_normals = vertex_normals(mesh.triangles(), mesh.frame(0), &welding);
    let mut vertex = object([
        (
            "POSITION",
            buf.floats(mesh.frame(0), Some(ARRAY_BUFFER), true).into(),
        ),
        (
            "NORMAL",
            buf.floats(&base_normals, Some(ARRAY_BUFFER), false).into(),
        ),
    ]);
    for (s, set_uv) in attributes.texcoords.iter().enumerate() {
        let accessor = buf.floats(set_uv, Some(ARRAY_BUFFER), false);
        set(&mut vertex, &format!("TEXCOORD_{s}"), accessor);
    }
    let targets = morph_targets(mesh, &welding, &base_normals, buf);
    // Groups (one per source primitive) may share a material name: each distinct name is one
    // material, the source's of that name when there is a source to look like.
    let names = distinct_names(&attributes.material_names);
    let gltf_mesh = mesh_object(mesh, attributes, (&names, look), (&vertex, &targets), buf);
    let node_name = (options.node_name.as_deref())
        .or(look.and_then(Look::node_name))
        .unwrap_or("mcgv-video");
    let mut root = object([
        (
            "asset",
            object([
                ("version", "2.0".into()),
                ("generator", "mcgv-video".into()),
            ]),
        ),
        ("scene", 0.into()),
        ("scenes", vec![object([("nodes", vec![0].into())])].into()),
        (
            "nodes",
            vec![object([("mesh", 0.into()), ("name", node_name.into())])].into(),
        ),
        ("meshes", vec![gltf_mesh].into()),
    ]);
    if let Some(look) = look {
        look.apply(&mut root, buf);
    } else if !names.is_empty() {
        let materials: Vec<Value> = names
            .iter()
            .map(|n| object([("name", n.as_str().into())]))
            .collect();
        set(&mut root, "materials", materials);
    }
    if !targets.is_empty() {
        set(
            &mut root,
            "animations",
            vec![weights_animation(mesh.frame_count(), options.fps, buf)],
        );
    }
    set(&mut root, "bufferViews", std::mem::take(&mut buf.views));
    set(&mut root, "accessors", std::mem::take(&mut buf.accessors));
    root
}

/// The glTF mesh: one primitive per material group, each with the `vertex` attributes and the
/// morph `targets`; `names` the distinct material names, in the order of the materials written
/// when there is no source `look`.
fn mesh_object(
    mesh: &AnimatedMesh,
    attributes: &Attributes,
    (names, look): (&[&String], Option<&Look>),
    (vertex, targets): (&Value, &[Value]),
    buf: &mut BufferBuilder,
) -> Value {
    let groups = material_groups(mesh, attributes);
    let material_of = |m: u32| {
        let name = attributes.material_names.get(m as usize)?;
        match look {
            Some(look) => look.material_index(name),
            None => names.iter().position(|n| *n == name),
        }
    };
    let primitives: Vec<Value> = groups
        .iter()
        .map(|(material, indices)| {
            let mut p = object([
                ("attributes", vertex.clone()),
                ("indices", buf.indices(indices).into()),
                ("mode", 4.into()),
            ]);
            if let Some(m) = material.and_then(material_of) {
                set(&mut p, "material", m);
            }
            if !targets.is_empty() {
                set(&mut p, "targets", targets.to_vec());
            }
            p
        })
        .collect();
    let mut gltf_mesh = object([("primitives", primitives.into())]);
    if !targets.is_empty() {
        let names: Vec<Value> = (1..mesh.frame_count())
            .map(|f| format!("frame_{f:04}").into())
            .collect();
        set(&mut gltf_mesh, "weights", vec![0.0f32; targets.len()]);
        set(
            &mut gltf_mesh,
            "extras",
            object([("targetNames", names.into())]),
        );
    }
    gltf_mesh
}

/// One morph target per frame after the first: position and normal differences from frame 0.
fn morph_targets(
    mesh: &AnimatedMesh,
    welding: &Welding,
    base_normals: &[Point],
    buf: &mut BufferBuilder,
) -> Vec<Value> {
    let base = mesh.frame(0);
    let delta = |a: &[Point], b: &[Point]| -> Vec<Point> {
        a.iter()
            .zip(b)
            .map(|(p, q)| [p[0] - q[0], p[1] - q[1], p[2] - q[2]])
            .collect()
    };
    mesh.frames()[1..]
        .iter()
        .map(|frame| {
            let normals = vertex_normals(mesh.triangles(), frame, welding);
            let position = buf.floats(&delta(frame, base), Some(ARRAY_BUFFER), true);
            let normal = buf.floats(&delta(&normals, base_normals), Some(ARRAY_BUFFER), false);
            object([("POSITION", position.into()), ("NORMAL", normal.into())])
        })
        .collect()
}

/// Each name once, in order of first appearance.
fn distinct_names(names: &[String]) -> Vec<&String> {
    let mut out: Vec<&String> = Vec::new();
    for name in names {
        if !out.contains(&name) {
            out.push(name);
        }
    }
    out
}

/// Triangle indices per group (one primitive each, in group order), or all triangles with no groups.
fn material_groups(mesh: &AnimatedMesh, attributes: &Attributes) -> Vec<(Option<u32>, Vec<u32>)> {
    if attributes.materials.is_empty() {
        return vec![(None, mesh.triangles().iter().flatten().copied().collect())];
    }
    let mut groups = vec![Vec::new(); attributes.material_names.len()];
    for (t, &m) in mesh.triangles().iter().zip(&attributes.materials) {
        groups[m as usize].extend_from_slice(t);
    }
    groups
        .into_iter()
        .enumerate()
        .filter(|(_, g)| !g.is_empty())
        .map(|(m, g)| (Some(m as u32), g))
        .collect()
}

/// The "frames" animation: at time `f / fps`, weight 1 on frame `f`'s target (none for frame 0).
fn weights_animation(frames: usize, fps: f64, buf: &mut BufferBuilder) -> Value {
    let times: Vec<[f32; 1]> = (0..frames).map(|f| [(f as f64 / fps) as f32]).collect();
    let targets = frames - 1;
    let mut weights = vec![[0.0f32]; frames * targets];
    for f in 1..frames {
        weights[f * targets + (f - 1)] = [1.0];
    }
    let input = buf.floats(&times, None, true);
    let output = buf.floats(&weights, None, false);
    object([
        ("name", "frames".into()),
        (
            "samplers",
            vec![object([
                ("input", input.into()),
                ("output", output.into()),
                ("interpolation", "STEP".into()),
            ])]
            .into(),
        ),
        (
            "channels",
            vec![object([
                ("sampler", 0.into()),
                (
                    "target",
                    object([("node", 0.into()), ("path", "weights".into())]),
                ),
            ])]
            .into(),
        ),
    ])
}
