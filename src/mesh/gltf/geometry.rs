//! The scene's geometry: every primitive the scene draws gathered into one vertex list and one
//! triangle list (primitives of a node that share vertex data share vertices), and the baking of
//! world-space positions for one pose (morphing, then skinning or the node's transform).

use super::nodes::Posed;
use super::primitive::{Part, MAX_INFLUENCE_SETS};
use super::skin::{blend, Skin};
use super::validate::check_accessor;
use super::{buffer_data, Buffers};
use crate::mesh::{Attributes, Point, Triangle};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;

/// The scene's triangles and, per part (a node's primitive with its own vertices), what moves them.
pub(super) struct Geometry {
    pub(super) triangles: Vec<Triangle>,
    pub(super) parts: Vec<Part>,
    pub(super) vertex_count: usize,
    /// Per part, its texture-coordinate sets (TEXCOORD_0, TEXCOORD_1, …).
    texcoords: Vec<Vec<Vec<[f32; 2]>>>,
    /// The drawn primitive each triangle comes from (an index into `group_materials`).
    groups: Vec<u32>,
    /// Each drawn primitive's glTF material (`None`: it has none).
    group_materials: Vec<Option<usize>>,
}

/// A node and the accessors that feed a primitive's vertices (see [`vertex_accessors`]).
type VertexSource = (usize, Vec<Option<usize>>);

/// First vertex and count of the vertex data already read, to share it between primitives.
type SharedVertices = HashMap<VertexSource, (usize, usize)>;

impl Geometry {
    /// Every triangle primitive of the scene's nodes, depth first in scene order.
    pub(super) fn gather<'a>(
        document: &'a gltf::Document,
        scene: &gltf::Scene<'a>,
        data: Buffers,
    ) -> Result<Self, String> {
        let mut geometry = Geometry {
            triangles: Vec::new(),
            parts: Vec::new(),
            vertex_count: 0,
            texcoords: Vec::new(),
            groups: Vec::new(),
            group_materials: Vec::new(),
        };
        let mut first_vertex = SharedVertices::new();
        let mut stack: Vec<gltf::Node> = scene.nodes().collect();
        stack.reverse();
        let mut visited = vec![false; document.nodes().count()];
        while let Some(node) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                continue;
            }
            let children: Vec<gltf::Node> = node.children().collect();
            stack.extend(children.into_iter().rev());
            let Some(mesh) = node.mesh() else { continue };
            for primitive in mesh.primitives() {
                geometry.add_primitive(&node, &mesh, &primitive, data, &mut first_vertex)?;
            }
        }
        if geometry.vertex_count == 0 {
            return Err("the scene draws no triangles".into());
        }
        Ok(geometry)
    }

    /// Adds a primitive's triangles, reading its vertices unless the node already has them.
    fn add_primitive<'a>(
        &mut self,
        node: &gltf::Node<'a>,
        mesh: &gltf::Mesh<'a>,
        primitive: &gltf::Primitive<'a>,
        data: Buffers,
        first_vertex: &mut SharedVertices,
    ) -> Result<(), String> {
        let name = format!("mesh {} primitive {}", mesh.index(), primitive.index());
        let key = (node.index(), vertex_accessors(primitive));
        let (first, count) = match first_vertex.get(&key) {
            Some(&range) => range,
            None => {
                let Some(part) = Part::read(node, primitive, data, &name)? else {
                    return Ok(());
                };
                let range = (self.vertex_count, part.positions.len());
                self.texcoords
                    .push(read_texcoords(primitive, data, range.1, &name)?);
                self.vertex_count += part.positions.len();
                self.parts.push(part);
                first_vertex.insert(key, range);
                range
            }
        };
        let indices = read_indices(primitive, data, count, &name)?;
        let offset = first as u32;
        let shifted = triangles_of(primitive.mode(), &indices)
            .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]);
        let before = self.triangles.len();
        self.triangles.extend(shifted);
        if self.triangles.len() > before {
            // One group per drawn primitive, not per material: primitives that share a material
            // come back as primitives of their own.
            let group = self.group_materials.len() as u32;
            self.group_materials.push(primitive.material().index());
            self.groups.resize(self.triangles.len(), group);
        }
        Ok(())
    }

    /// The texture coordinates of every vertex (a part without set `s` gets (0, 0) there) and the
    /// triangle groups: one per drawn primitive, named after its material (`default` for none), so
    /// two groups may share a name. A scene whose primitives have no material gets no groups.
    pub(super) fn attributes(&self, document: &gltf::Document) -> Attributes {
        let sets = self.texcoords.iter().map(Vec::len).max().unwrap_or(0);
        let texcoords = (0..sets)
            .map(|s| {
                let parts = self.texcoords.iter().zip(&self.parts);
                parts
                    .flat_map(|(part_sets, part)| match part_sets.get(s) {
                        Some(set) => set.clone(),
                        None => vec![[0.0; 2]; part.positions.len()],
                    })
                    .collect()
            })
            .collect();
        if self.group_materials.iter().all(Option::is_none) {
            return Attributes {
                texcoords,
                ..Attributes::default()
            };
        }
        let name = |m: &Option<usize>| match m.and_then(|i| document.materials().nth(i)) {
            Some(material) => super::material_name(&material),
            None => "default".to_string(),
        };
        Attributes {
            texcoords,
            materials: self.groups.clone(),
            material_names: self.group_materials.iter().map(name).collect(),
        }
    }

    /// World-space positions of every vertex in one pose.
    pub(super) fn bake(&self, posed: &Posed, skins: &[Skin]) -> Vec<Point> {
        let mut out = Vec::with_capacity(self.vertex_count);
        for part in &self.parts {
            let weights = posed.weights.get(part.node).map_or(&[][..], Vec::as_slice);
            let joint_matrices = part
                .skin
                .and_then(|s| skins.get(s))
                .map(|skin| skin.joint_matrices(posed));
            let node_world = posed.world_of(part.node);
            for v in 0..part.positions.len() {
                let p = part.morphed(v, weights);
                let skinning = joint_matrices
                    .as_ref()
                    .and_then(|jm| blend(part.influences(v), jm));
                let q = skinning.unwrap_or(node_world) * p;
                out.push([q.x as f32, q.y as f32, q.z as f32]);
            }
        }
        out
    }
}

/// Every TEXCOORD_n set of a primitive, as floats (normalised integers are converted).
fn read_texcoords(
    primitive: &gltf::Primitive,
    data: Buffers,
    count: usize,
    name: &str,
) -> Result<Vec<Vec<[f32; 2]>>, String> {
    let reader = primitive.reader(|b| buffer_data(data, b));
    let mut sets = Vec::new();
    while let Some(coords) = reader.read_tex_coords(sets.len() as u32) {
        let set: Vec<[f32; 2]> = coords.into_f32().collect();
        if set.len() != count || set.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!(
                "{name}: TEXCOORD_{} has {} finite entries for {count} vertices",
                sets.len(),
                set.len()
            ));
        }
        sets.push(set);
    }
    Ok(sets)
}

/// A primitive's vertex indices (`0..count` when it has none), each checked against `count`.
fn read_indices(
    primitive: &gltf::Primitive,
    data: Buffers,
    count: usize,
    name: &str,
) -> Result<Vec<u32>, String> {
    check_accessor(
        primitive.indices(),
        &format!("{name} indices"),
        Dimensions::Scalar,
        &[DataType::U8, DataType::U16, DataType::U32],
    )?;
    let reader = primitive.reader(|b| buffer_data(data, b));
    let indices: Vec<u32> = match reader.read_indices() {
        Some(it) => it.into_u32().collect(),
        None => (0..count as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
        return Err(format!("{name}: index {bad} but {count} vertices"));
    }
    Ok(indices)
}

/// Indices of every accessor that feeds a primitive's vertices: equal lists mean shared vertices.
fn vertex_accessors(primitive: &gltf::Primitive) -> Vec<Option<usize>> {
    use gltf::Semantic;
    let mut keys = vec![primitive.get(&Semantic::Positions).map(|a| a.index())];
    for set in 0..MAX_INFLUENCE_SETS {
        keys.push(primitive.get(&Semantic::Joints(set)).map(|a| a.index()));
        keys.push(primitive.get(&Semantic::Weights(set)).map(|a| a.index()));
    }
    keys.extend(
        primitive
            .morph_targets()
            .map(|t| t.positions().map(|a| a.index())),
    );
    keys
}

/// The triangles of a primitive's index list; nothing for points and lines.
fn triangles_of(
    mode: gltf::mesh::Mode,
    indices: &[u32],
) -> Box<dyn Iterator<Item = Triangle> + '_> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => Box::new(indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
        Mode::TriangleStrip => Box::new(indices.windows(3).enumerate().map(|(i, w)| {
            // Every other strip triangle is flipped back to keep one orientation.
            if i % 2 == 0 {
                [w[0], w[1], w[2]]
            } else {
                [w[1], w[0], w[2]]
            }
        })),
        Mode::TriangleFan => match indices.split_first() {
            Some((&hub, rest)) => Box::new(rest.windows(2).map(move |w| [hub, w[0], w[1]])),
            None => Box::new(std::iter::empty()),
        },
        _ => Box::new(std::iter::empty()),
    }
}
