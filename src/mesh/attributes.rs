//! What a renderable asset has beside positions and triangles, coded once for the whole animation:
//! texture coordinates per vertex (every set) and the material of each triangle.

use crate::error::{Error, Result};

/// Static per-vertex and per-triangle attributes of an animated mesh.
///
/// `texcoords[s][v]` is vertex `v`'s coordinate in set `s` (glTF `TEXCOORD_s`, OBJ `vt` as set 0).
/// `materials[t]` is triangle `t`'s group, which indexes `material_names`: one group per glTF
/// primitive (so a glTF output gets one primitive per source primitive, and groups may share a
/// name) or per OBJ `usemtl` name; empty when the source has no materials. [`Attributes::is_empty`] is true for inputs with neither (they add nothing to a stream).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes {
    /// Texture-coordinate sets, each one `[u, v]` per vertex.
    pub texcoords: Vec<Vec<[f32; 2]>>,
    /// Group of each triangle (empty: no groups).
    pub materials: Vec<u32>,
    /// Each group's material name (OBJ `usemtl`, glTF material name or `material_N`).
    pub material_names: Vec<String>,
}

impl Attributes {
    /// True when there is nothing to store.
    pub fn is_empty(&self) -> bool {
        self.texcoords.is_empty() && self.materials.is_empty()
    }

    /// Checks the attributes against a mesh of `vertices` vertices and `triangles` triangles.
    pub fn check(&self, vertices: usize, triangles: usize) -> Result<()> {
        for (s, set) in self.texcoords.iter().enumerate() {
            if set.len() != vertices {
                return Err(Error::Mesh(format!(
                    "texture coordinate set {s} has {} entries for {vertices} vertices",
                    set.len()
                )));
            }
            if set.iter().any(|uv| uv.iter().any(|c| !c.is_finite())) {
                return Err(Error::Mesh(format!(
                    "texture coordinate set {s} has a coordinate that is not a finite number"
                )));
            }
        }
        if !self.materials.is_empty() {
            if self.materials.len() != triangles {
                return Err(Error::Mesh(format!(
                    "{} material indices for {triangles} triangles",
                    self.materials.len()
                )));
            }
            if let Some(&m) = self
                .materials
                .iter()
                .find(|&&m| m as usize >= self.material_names.len())
            {
                return Err(Error::Mesh(format!(
                    "material {m} of {} named materials",
                    self.material_names.len()
                )));
            }
        }
        Ok(())
    }
}
