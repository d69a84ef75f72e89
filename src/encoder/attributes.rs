//! The attributes part from the encoder's side: the mesh's texture coordinates and materials put in
//! the order the decoder will see (its vertex order, and the first-frame coder's triangle order,
//! which does not keep the input's).

use crate::error::{Error, Result};
use crate::first_frame;
use crate::mesh::{AnimatedMesh, Attributes, Triangle};
use crate::stream::attributes::encode_attributes;
use std::collections::HashMap;

fn sorted(t: Triangle) -> Triangle {
    let mut k = t;
    k.sort_unstable();
    k
}

/// The `ATTR` part of `mesh` (already in the decoder's vertex order), whose first frame was coded as
/// `first_frame` (the `MESH` part's bytes).
pub(super) fn encode(mesh: &AnimatedMesh, first_frame: &[u8], uv_bits: u8) -> Result<Vec<u8>> {
    let (decoded, positions) = first_frame::decode(first_frame)?;
    let source = mesh.attributes();
    let mut materials = Vec::new();
    if !source.materials.is_empty() {
        // The input triangles with each vertex set, in input order: the decoder's triangle takes the
        // material of the first input triangle on the same vertices not yet taken.
        let mut by_vertices: HashMap<Triangle, Vec<u32>> = HashMap::new();
        for (t, &m) in mesh.triangles().iter().zip(&source.materials).rev() {
            by_vertices.entry(sorted(*t)).or_default().push(m);
        }
        for t in &decoded {
            let m = by_vertices
                .get_mut(&sorted(*t))
                .and_then(Vec::pop)
                .ok_or_else(|| {
                    Error::Mesh("a decoded triangle matches no input triangle".into())
                })?;
            materials.push(m);
        }
    }
    let in_order = Attributes {
        texcoords: source.texcoords.clone(),
        materials,
        material_names: source.material_names.clone(),
    };
    encode_attributes(&in_order, &decoded, &positions, uv_bits)
}
