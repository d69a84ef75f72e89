//! The `like` option: the look of the source glTF carried over to a decoded asset — its materials,
//! textures, samplers and images (embedded in the output's buffer) and the name of the node that
//! draws its mesh — so that the decoded animation renders as the source did. The stream keeps only
//! material names (see [`crate::mesh::Attributes`]); the pictures, often most of a `.glb`, stay in
//! the source file.

use super::buffer::BufferBuilder;
use super::set;
use crate::error::{Error, Result};
use crate::mesh::gltf::{load_document, material_name};
use gltf::json::Value;
use std::path::Path;

/// What is copied from the source.
pub(super) struct Look {
    /// The source's materials as JSON, and each one's name as the attributes know it.
    materials: Vec<(Value, String)>,
    textures: Vec<Value>,
    samplers: Vec<Value>,
    /// Each image's JSON without its data reference, and its bytes (or a `data:` URI kept as is).
    images: Vec<(Value, Image)>,
    node_name: Option<String>,
    /// Material and texture extensions the copied JSON may use.
    extensions: Vec<String>,
}

enum Image {
    Bytes(Vec<u8>),
    Uri(String),
}

fn to_value<T: serde::Serialize>(item: &T) -> Result<Value> {
    gltf::json::serialize::to_value(item)
        .map_err(|e| Error::Mesh(format!("copying the source's glTF JSON: {e}")))
}

fn remove(value: &mut Value, key: &str) {
    if let Value::Object(map) = value {
        map.remove(key);
    }
}

impl Look {
    /// Reads the look of the glTF file at `path`.
    pub(super) fn read(path: &Path) -> Result<Self> {
        let (document, buffers) = load_document(path)?;
        let fail = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
        let root = document.clone().into_json();
        let materials = document
            .materials()
            .zip(&root.materials)
            .map(|(m, json)| Ok((to_value(json)?, material_name(&m))))
            .collect::<Result<_>>()?;
        let mut images = Vec::new();
        for (image, json) in document.images().zip(&root.images) {
            let mut value = to_value(json)?;
            let data = match image.source() {
                gltf::image::Source::View { view, mime_type } => {
                    let buffer = buffers.get(view.buffer().index()).map(|d| &d.0[..]);
                    let range = view.offset()..view.offset() + view.length();
                    let bytes = buffer.and_then(|b| b.get(range)).ok_or_else(|| {
                        fail(format!("image {} lies outside its buffer", image.index()))
                    })?;
                    set(&mut value, "mimeType", mime_type);
                    Image::Bytes(bytes.to_vec())
                }
                gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                    Image::Uri(uri.to_string())
                }
                gltf::image::Source::Uri { uri, mime_type } => {
                    // A file beside the source: embedded, so the output stands alone.
                    let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                    let bytes = std::fs::read(&file).map_err(|e| Error::io(&file, e))?;
                    let mime = mime_type.unwrap_or(match uri.to_ascii_lowercase() {
                        u if u.ends_with(".png") => "image/png",
                        _ => "image/jpeg",
                    });
                    set(&mut value, "mimeType", mime);
                    Image::Bytes(bytes)
                }
            };
            remove(&mut value, "uri");
            remove(&mut value, "bufferView");
            images.push((value, data));
        }
        let node_name = document
            .nodes()
            .find(|n| n.mesh().is_some())
            .and_then(|n| n.name().map(str::to_string));
        let extensions = document
            .extensions_used()
            .filter(|e| e.starts_with("KHR_materials_") || e.starts_with("KHR_texture_"))
            .map(str::to_string)
            .collect();
        Ok(Self {
            materials,
            textures: root.textures.iter().map(to_value).collect::<Result<_>>()?,
            samplers: root.samplers.iter().map(to_value).collect::<Result<_>>()?,
            images,
            node_name,
            extensions,
        })
    }

    /// The source material of each of the attributes' material names (by name), if any.
    pub(super) fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|(_, n)| n == name)
    }

    /// The source's node name, if it has one.
    pub(super) fn node_name(&self) -> Option<&str> {
        self.node_name.as_deref()
    }

    /// Puts the materials, textures, samplers and images into `root`, image bytes into `buf`.
    pub(super) fn apply(&self, root: &mut Value, buf: &mut BufferBuilder) {
        let materials: Vec<Value> = self.materials.iter().map(|(m, _)| m.clone()).collect();
        if !materials.is_empty() {
            set(root, "materials", materials);
        }
        if !self.textures.is_empty() {
            set(root, "textures", self.textures.clone());
        }
        if !self.samplers.is_empty() {
            set(root, "samplers", self.samplers.clone());
        }
        let images: Vec<Value> = self
            .images
            .iter()
            .map(|(json, data)| {
                let mut image = json.clone();
                match data {
                    Image::Bytes(bytes) => set(&mut image, "bufferView", buf.raw(bytes)),
                    Image::Uri(uri) => set(&mut image, "uri", uri.as_str()),
                }
                image
            })
            .collect();
        if !images.is_empty() {
            set(root, "images", images);
        }
        if !self.extensions.is_empty() {
            let used: Vec<Value> = self.extensions.iter().map(|e| e.as_str().into()).collect();
            set(root, "extensionsUsed", used);
        }
    }
}
